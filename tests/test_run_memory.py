"""A dynamic run's peak memory (issue 23, benchmarks/peer_cantilever.py): what it no longer
holds or loads must leave every number as it was.

* A kernel call returns at most solvers.dynamic.ROW_BUFFER_BYTES of output rows
  (``call_rows``); a run whose calls are cut that short writes the same file, bit for bit,
  as one whose calls are only limited by time (reference: that run).
* A cantilever run loads neither numpy.ma (numpy >= 2.3 imports it for a plain
  ``np.unique``) nor numpy's least squares (a weld to the ground: its axes are the
  identity), socket or csv; the replacements give numpy's own results (references:
  ``np.unique``, ``np.linalg.lstsq``) and the host name socket.gethostname() gives.
* A large Pattern keeps no per-entry arrays besides its columns; its rows and the
  positions of entries are those of a dense enumeration of the pattern (reference: brute
  force).
"""
from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv.builders import build_model
from ancfdrv.csr import sorted_unique
from ancfdrv.io.scene import load_scene
from ancfdrv.runner import run_scene
from ancfdrv.solvers import dynamic
from ancfdrv.system.joints import _express
from ancfdrv.system.patterns import Pattern

ROOT = Path(__file__).resolve().parents[1]
CANTILEVER = ROOT / "inputs" / "hard" / "cantilever_drop.nml"
#: 16 planar cable elements, 60 steps: rows of 68 unknowns plus the run's outputs
SETS = ["beam.nodes=17", "beam.bending=cable", "scene.planar=xy", "solver.t_end=0.06"]


def _datasets(path: Path) -> dict[str, bytes]:
    """Every dataset outside /timing: dtype, shape and bytes."""
    found: dict[str, bytes] = {}
    with h5py.File(path, "r") as h5:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and not name.startswith("timing"):
                value = obj[()]
                found[name] = (str(value.dtype), np.shape(value), np.asarray(value).tobytes())
        h5.visititems(visit)
    return found


def test_kernel_calls_stay_within_the_row_buffer_and_write_the_same_file(tmp_path,
                                                                           monkeypatch):
    calls: list[int] = []
    advance = dynamic.TimeIntegrator.advance

    def counted(self, state, nsteps, h=None):
        calls.append(nsteps)
        return advance(self, state, nsteps, h)

    monkeypatch.setattr(dynamic.TimeIntegrator, "advance", counted)
    monkeypatch.setattr(dynamic, "ROW_BUFFER_BYTES", 1 << 40)
    run_scene(CANTILEVER, SETS, tmp_path / "free.h5", progress=False)
    free_calls = list(calls)
    assert sum(free_calls) == 60

    model = build_model(load_scene(CANTILEVER, SETS))
    try:
        row_bytes = 8 * model.kernel.row_size(True)   # the run carries q (answers, XDMF)
    finally:
        model.close()
    # the rows of 7 steps: answers recorded from chunks shorter than their blocks
    monkeypatch.setattr(dynamic, "ROW_BUFFER_BYTES", 7 * row_bytes + row_bytes // 2)
    calls.clear()
    run_scene(CANTILEVER, SETS, tmp_path / "capped.h5", progress=False)
    assert sum(calls) == 60 and max(calls) == 7 and len(calls) >= 9
    assert max(free_calls) > 7   # the reference's calls were not cut
    assert max(calls) * row_bytes <= dynamic.ROW_BUFFER_BYTES

    free, capped = _datasets(tmp_path / "free.h5"), _datasets(tmp_path / "capped.h5")
    assert set(free) == set(capped)
    assert {"dynamic/time", "dynamic/probes/tip", "dynamic/lambda", "dynamic/q_last",
            "dynamic/reactions/clamp section/force",
            "dynamic/reactions/clamp section/moment"} <= set(free)
    for name in free:
        assert free[name] == capped[name], name


def test_wide_rows_wait_in_bounded_buffers_and_write_the_same_file(tmp_path, monkeypatch):
    """/dynamic/q of every step (output.q): the file writer writes once FLUSH_BYTES of rows
    wait (here: a few rows' worth, FLUSH_MIN_SECONDS = 0), and its file is the one a writer
    that waits for the end of the run writes, bit for bit."""
    from ancfdrv.results import hdf5

    sets = SETS + ["output.q=.true."]
    monkeypatch.setattr(hdf5, "FLUSH_SECONDS", 1e9)
    run_scene(CANTILEVER, sets, tmp_path / "whole.h5", progress=False)

    model = build_model(load_scene(CANTILEVER, sets))
    try:
        row_bytes = 8 * model.kernel.row_size(True)
    finally:
        model.close()
    monkeypatch.setattr(dynamic, "ROW_BUFFER_BYTES", 3 * row_bytes)   # 3 steps a call
    monkeypatch.setattr(hdf5, "FLUSH_BYTES", 7 * row_bytes)
    monkeypatch.setattr(hdf5, "FLUSH_MIN_SECONDS", 0.0)
    waiting: list[int] = []
    flushes: list[int] = []
    call, flush = hdf5.DynamicWriter.__call__, hdf5.DynamicWriter.flush

    def called(self, chunk):
        call(self, chunk)
        exact = sum(hdf5._chunk_bytes(c) for c in self._pending)
        assert self._pending_bytes == exact   # fixed steps: one row layout
        waiting.append(exact)

    def flushed(self):
        flushes.append(self._pending_rows)
        flush(self)

    monkeypatch.setattr(hdf5.DynamicWriter, "__call__", called)
    monkeypatch.setattr(hdf5.DynamicWriter, "flush", flushed)
    run_scene(CANTILEVER, sets, tmp_path / "bounded.h5", progress=False)
    assert len(waiting) == 21 and max(waiting) < 7 * row_bytes   # the initial row, 20 calls
    assert len(flushes) >= 8 and max(flushes) <= 9

    whole, bounded = _datasets(tmp_path / "whole.h5"), _datasets(tmp_path / "bounded.h5")
    assert set(whole) == set(bounded) and "dynamic/q" in whole
    assert whole["dynamic/q"][1] == (61, 68)
    for name in whole:
        assert whole[name] == bounded[name], name


def test_call_rows_bounds_the_buffer_at_one_row_at_least():
    class Kernel:
        def __init__(self, size):
            self.size = size

        def row_size(self, store_q):
            return self.size if store_q else 10

    class Model:
        def __init__(self, size):
            self.kernel = Kernel(size)

    settings = dynamic.DynamicSettings(dt=1e-3, t_end=1.0, store_q=True)
    # the 512-element cantilever: 2052 unknowns and its outputs (~2090 numbers a row)
    assert dynamic.call_rows(Model(2090), settings) == dynamic.ROW_BUFFER_BYTES // (8 * 2090)
    assert 8 * 2090 * dynamic.call_rows(Model(2090), settings) <= dynamic.ROW_BUFFER_BYTES
    assert dynamic.call_rows(Model(10 ** 8), settings) == 1
    settings.store_q = False
    assert dynamic.call_rows(Model(10 ** 8), settings) == dynamic.ROW_BUFFER_BYTES // 80


def test_cantilever_run_loads_neither_masked_arrays_nor_least_squares(tmp_path):
    """The clamped cantilever (a weld to the ground) and the planar cable pendulum, with
    answers and XDMF, in a fresh interpreter whose np.linalg.lstsq raises; nor the socket
    module (the output lock's host name is uname's) or csv (table drives only)."""
    runs = [("inputs/hard/cantilever_drop.nml", SETS),
            ("inputs/hard/pendulum.nml", ["beam.nodes=5", "beam.bending=cable",
                                          "scene.planar=xy", "solver.t_end=0.01"])]
    code = textwrap.dedent(f"""
        import sys
        import numpy as np

        def refused(*args, **kwargs):
            raise AssertionError("np.linalg.lstsq called")

        np.linalg.lstsq = refused
        from ancfdrv.runner import run_scene
        for i, (scene, sets) in enumerate({[(str(ROOT / s), o) for s, o in runs]!r}):
            run_scene(scene, sets, {str(tmp_path)!r} + f"/r{{i}}.h5", progress=False)
        print(sorted(m for m in sys.modules
                     if m in ("numpy.ma", "socket", "csv") or m.startswith("numpy.ma.")))
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().splitlines()[-1] == "[]"
    assert all((tmp_path / f"r{i}.h5").exists() for i in range(len(runs)))


def test_ground_axes_give_least_squares_coefficients_bit_for_bit():
    rng = np.random.default_rng(23)
    identity = [np.eye(3)[:, k] for k in range(3)]
    targets = [np.array([1.0, 0.0, 0.0]), np.array([-0.0, 1.0, -0.0]),
               np.array([0.6, 0.8, 0.0]), np.array([1.0, 1e-17, -3e-15])]
    targets += [rng.standard_normal(3) * 10.0 ** rng.uniform(-6, 6, 3) for _ in range(200)]
    for target in targets:
        expected, *_ = np.linalg.lstsq(np.column_stack(identity), target, rcond=None)
        expected[np.abs(expected) < 1e-14 * np.abs(expected).max(initial=1.0)] = 0.0
        got = _express([None] * 3, identity, target, "test")
        assert got.tobytes() == expected.tobytes(), target
    # other axes still go through least squares, and a direction outside them is refused
    turned = [np.array([0.6, 0.8, 0.0]), np.array([-0.8, 0.6, 0.0]), np.array([0, 0, 1.0])]
    coef = _express([None] * 3, turned, np.array([1.0, 0.0, 0.0]), "test")
    np.testing.assert_allclose(coef, [0.6, -0.8, 0.0], atol=1e-15)
    from ancfdrv.errors import InputError
    with pytest.raises(InputError, match="cannot be written"):
        _express([None] * 2, turned[:2], np.array([0.0, 0.0, 1.0]), "joint 'w'")


def test_lock_records_the_host_name_socket_gives(tmp_path):
    import json
    import socket

    from ancfdrv.results.lock import OutputLock, lock_path

    out = tmp_path / "r.h5"
    with OutputLock(out):
        record = json.loads(lock_path(out).read_text())
    assert record["host"] == socket.gethostname() and record["pid"] > 0


def test_sorted_unique_is_numpys_unique():
    rng = np.random.default_rng(5)
    for size in (0, 1, 7, 1000):
        keys = rng.integers(-50, 50, size=size)
        assert sorted_unique(keys).tobytes() == np.unique(keys).astype(np.int64).tobytes()
    grid = rng.integers(0, 9, size=(4, 6))
    assert sorted_unique(grid).tolist() == np.unique(grid).tolist()


@pytest.mark.parametrize("keep", [0, Pattern.KEEP_ENTRIES], ids=["large", "small"])
def test_pattern_finds_every_entry_and_keeps_per_entry_arrays_of_small_ones(keep,
                                                                              monkeypatch):
    """A pattern above KEEP_ENTRIES entries (here: every pattern, KEEP_ENTRIES = 0) keeps
    no per-entry array besides its columns; a small one keeps its rows and keys once
    formed. Either finds every entry where a dense enumeration has it."""
    monkeypatch.setattr(Pattern, "KEEP_ENTRIES", keep)
    blocks = [np.array([0, 1, 2, 3]), np.array([2, 3, 4, 5]), np.array([[6, 7], [1, 8]])]
    pattern = Pattern.from_blocks(9, blocks)
    entries = {(r, c) for r in range(9) for c in (r,)}
    for block in blocks:
        b = block[:, None] if block.ndim == 1 else block
        for column in b.T:
            entries |= {(int(r), int(c)) for r in column for c in column}
    ordered = sorted(entries)
    assert pattern.nnz == len(ordered)
    assert pattern.rows.tolist() == [r for r, _ in ordered]
    assert pattern.col_index.tolist() == [c for _, c in ordered]
    rows = np.array([r for r, _ in ordered] + [0, 8])
    cols = np.array([c for _, c in ordered] + [5, 0])
    for _ in range(2):   # the second time from the kept keys of a small pattern
        assert pattern.positions(rows, cols).tolist() == list(range(len(ordered))) + [-1, -1]
        assert pattern.rows.tolist() == [r for r, _ in ordered]
    held = {name for name, value in vars(pattern).items() if isinstance(value, np.ndarray)}
    assert held == ({"row_ptr", "col_index"} if keep == 0 else
                    {"row_ptr", "col_index", "_rows", "_keys"})


def test_bounded_flushes_keep_the_xdmf_frames_and_file(tmp_path, monkeypatch):
    """The plate pendulum's XDMF frames (node positions at frame rows, per-frame views)
    waiting in buffers of ~4 rows and kernel calls of 3 steps give the file and the .xdmf
    description of a run written at its end, bit for bit. (Its 21 frames of 9 points would
    be carried inline: the inline limit is set to 0 so that the flushes make the views.)"""
    from ancfdrv.results import hdf5, xdmf

    monkeypatch.setattr(xdmf, "INLINE_VALUES", 0)

    scene, sets = ROOT / "inputs" / "plate_pendulum.nml", ["solver.t_end=0.02"]
    monkeypatch.setattr(hdf5, "FLUSH_SECONDS", 1e9)
    run_scene(scene, sets, tmp_path / "whole.h5", progress=False)
    flushes: list[int] = []
    flush = hdf5.DynamicWriter.flush

    def flushed(self):
        flushes.append(self._pending_rows)
        flush(self)

    monkeypatch.setattr(hdf5.DynamicWriter, "flush", flushed)
    model = build_model(load_scene(scene, sets))
    try:
        row_bytes = 8 * model.kernel.row_size(True)
    finally:
        model.close()
    monkeypatch.setattr(hdf5, "FLUSH_BYTES", 3000)   # a waiting row: ~840 bytes
    monkeypatch.setattr(hdf5, "FLUSH_MIN_SECONDS", 0.0)
    monkeypatch.setattr(dynamic, "ROW_BUFFER_BYTES", 3 * row_bytes)
    run_scene(scene, sets, tmp_path / "bounded.h5", progress=False)
    assert len(flushes) >= 5 and max(flushes) <= 6   # the bound and one call's rows
    whole, bounded = _datasets(tmp_path / "whole.h5"), _datasets(tmp_path / "bounded.h5")
    assert set(whole) == set(bounded) and "dynamic/mesh_nodes" in whole
    assert "dynamic/xdmf/displacement/20" in whole
    assert whole["dynamic/mesh_nodes"][1][0] > 3
    for name in whole:
        assert whole[name] == bounded[name], name
    assert (tmp_path / "whole.xdmf").read_text().replace("whole.h5", "bounded.h5") == \
        (tmp_path / "bounded.xdmf").read_text()
