"""A dynamic run's peak memory (issues 23 and 38), structurally: the dynamic writer keeps no
coordinates of every step while rows wait for the next flush unless /dynamic/q is written
(results/hdf5.py DynamicWriter._thinned): the XDMF frames' points are computed when a chunk
arrives and only the last row's q is kept, and the file is the same as when the frames
come from q at every step; nothing keeps a kernel call's row buffer after its chunk went
on; the cables' tension is formed a bounded block of rows at a time, with the values of
one block; a cable run loads neither numpy.polynomial nor LAPACK's workspace."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from ancfdrv.runner import run_scene

ROOT = Path(__file__).resolve().parents[1]
# the pendulum as a beam (frames of its points for ParaView), 0.1 s, 7 frames
OVERRIDES = ["beam.nodes=5", "solver.t_end=0.1", "solver.dt=1e-3", "output.xdmf_frames=7"]


def test_frames_and_last_coordinates_equal_those_from_every_step(tmp_path):
    thin, full = tmp_path / "thin.h5", tmp_path / "full.h5"
    run_scene(ROOT / "inputs/hard/pendulum.nml", OVERRIDES, thin, progress=False)
    run_scene(ROOT / "inputs/hard/pendulum.nml", OVERRIDES + ["output.q=true"], full,
              progress=False)
    with h5py.File(thin, "r") as a, h5py.File(full, "r") as b:
        assert "q" not in a["dynamic"] and "q" in b["dynamic"]
        rows = a["dynamic/mesh_rows"][()]
        assert list(rows) == [0, 17, 34, 51, 68, 85, 100]   # stride ceil(100 / 6), the last
        for name in ("mesh_rows", "mesh_nodes", "mesh_displacement", "time", "lambda",
                     "probes/tip"):
            assert np.array_equal(a[f"dynamic/{name}"][()], b[f"dynamic/{name}"][()]), name
        assert np.array_equal(a["dynamic/q_last"][()], b["dynamic/q"][-1])
        # the frames show the probe's motion: the tip point of the last frame is the probe
        tip = a["dynamic/probes/tip"][-1]
        assert np.min(np.linalg.norm(a["dynamic/mesh_nodes"][-1] - tip, axis=1)) < 1e-12


def test_waiting_rows_hold_no_coordinates(tmp_path, monkeypatch):
    from ancfdrv.results import hdf5

    seen = []
    original = hdf5.DynamicWriter.flush

    def flush(self):
        seen.extend((getattr(c, "q", None), getattr(c, "q_last", None)) for c in self._pending)
        return original(self)

    monkeypatch.setattr(hdf5.DynamicWriter, "flush", flush)
    run_scene(ROOT / "inputs/hard/pendulum.nml", OVERRIDES, tmp_path / "r.h5", progress=False)
    assert seen and all(q is None for q, _ in seen)
    assert all(last is not None and last.ndim == 1 for _, last in seen)


def test_run_holds_only_the_last_kernel_row_buffer(tmp_path, monkeypatch):
    """Every kernel call returns a fresh row buffer (mostly q); once its chunk went to the
    sinks and the energy watch, nothing may keep it (a view of its time column waiting in
    EnergyWatch kept a whole run's buffers, 16 MB at 2052 unknowns): when a call starts,
    at most the previous call's buffer is alive. One step per call: 100 calls."""
    import weakref

    from ancfdrv import kernel
    from ancfdrv.solvers import dynamic

    monkeypatch.setattr(dynamic, "ROW_BUFFER_BYTES", 8)   # call_rows: one row per call
    buffers: list[weakref.ref] = []
    alive: list[int] = []
    original = kernel.KernelSystem.advance_rows

    def advance_rows(self, *args, **kwargs):
        alive.append(sum(ref() is not None for ref in buffers))
        result = original(self, *args, **kwargs)
        buffers.append(weakref.ref(result[0]))
        return result

    monkeypatch.setattr(kernel.KernelSystem, "advance_rows", advance_rows)
    run_scene(ROOT / "inputs/hard/pendulum.nml", OVERRIDES, tmp_path / "r.h5", progress=False)
    assert len(alive) == 100 and max(alive) == 1


def test_tension_blocks_are_bounded_and_bitwise_one_block(tmp_path, monkeypatch):
    """DynamicAnswers forms the cables' tension from blocks of at most TENSION_BLOCK_BYTES
    of full coordinates; the file is byte for byte that of blocks of a single row and of
    one block per chunk (each row's values are its own)."""
    from ancfdrv.system import answers
    from ancfdrv.system.kinds.cable import Cable

    sizes: list[int] = []
    original = Cable.axial_forces

    def axial_forces(self, e):
        sizes.append(np.asarray(e).nbytes)
        return original(self, e)

    monkeypatch.setattr(Cable, "axial_forces", axial_forces)
    scene = ROOT / "inputs/hard/cantilever_drop.nml"
    overrides = ["beam.nodes=9", "solver.t_end=0.05"]
    files = {}
    for block in (8, answers.DynamicAnswers.TENSION_BLOCK_BYTES, 1 << 30):
        monkeypatch.setattr(answers.DynamicAnswers, "TENSION_BLOCK_BYTES", block)
        sizes.clear()
        files[block] = tmp_path / f"{block}.h5"
        run_scene(scene, overrides, files[block], progress=False)
        # 9 nodes x 6 full coordinates a row: a block of at most max(1, block // 432) rows
        assert sizes and max(sizes) <= max(block, 8 * 54)
    with h5py.File(files[8], "r") as a:
        assert a["dynamic/tension/beam/max"].shape == (51,)
        for other in files.values():
            with h5py.File(other, "r") as b:
                for name in ("dynamic/tension/beam/min", "dynamic/tension/beam/max",
                             "dynamic/time", "dynamic/probes/tip"):
                    assert a[name][()].tobytes() == b[name][()].tobytes(), name


def test_cable_gauss_points_and_no_eigenvalue_solver():
    """A cable run loads no numpy.polynomial (whose leggauss, an eigenvalue solve, started
    LAPACK's workspace: 2.4 MB of the run's peak); the cable takes its Gauss points from
    ancfdrv.gauss (compared with numpy's leggauss in test_gauss.py)."""
    import subprocess
    import sys

    code = ("import sys; from ancfdrv import simulate; "
            f"simulate({str(ROOT / 'inputs/hard/cantilever_drop.nml')!r}, "
            "['beam.nodes=5', 'solver.t_end=0.01']); "
            "print('numpy.polynomial' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split()[-1] == "False"


def test_flush_writes_frames_in_bounded_groups(tmp_path, monkeypatch):
    """A flush writes the waiting chunks' XDMF frames a group of at most FRAME_GROUP_BYTES
    of points at a time (not all joined, with their displacements: three copies of them),
    and the file is the one of a single group."""
    from ancfdrv.results import hdf5
    from ancfdrv.solvers import dynamic

    monkeypatch.setattr(dynamic, "ROW_BUFFER_BYTES", 8)   # one row per chunk
    monkeypatch.setattr(hdf5, "FLUSH_SECONDS", 1e9)   # one flush, at the end
    written: list[int] = []
    original = hdf5.DynamicWriter._write_frames

    def write_frames(self, group, rows, nodes):
        written.append(len(nodes))
        return original(self, group, rows, nodes)

    monkeypatch.setattr(hdf5.DynamicWriter, "_write_frames", write_frames)
    files = []
    for limit in (1, 1 << 30):
        monkeypatch.setattr(hdf5, "FRAME_GROUP_BYTES", limit)
        written.clear()
        files.append(tmp_path / f"{limit}.h5")
        run_scene(ROOT / "inputs/hard/pendulum.nml", OVERRIDES, files[-1], progress=False)
        # the run's 7 frames, all written by its one flush
        assert sum(written) == 7
        assert max(written) == (1 if limit == 1 else 7)
    with h5py.File(files[0], "r") as a, h5py.File(files[1], "r") as b:
        for name in ("mesh_rows", "mesh_nodes", "mesh_displacement", "time", "q_last"):
            assert a[f"dynamic/{name}"][()].tobytes() == b[f"dynamic/{name}"][()].tobytes()


def test_views_are_made_a_bounded_batch_per_opening(tmp_path, monkeypatch):
    """A flush makes the XDMF views (virtual datasets, one per frame) at most
    VIEWS_PER_OPENING in each opening of the file (HDF5 holds each view's memory until the
    file closes): the pendulum's 7 frames as views, 3 an opening, in 3 openings; every view
    reads its frame's row of /dynamic/mesh_displacement (and position/0 the first frame's
    points)."""
    from ancfdrv.results import hdf5, xdmf

    monkeypatch.setattr(xdmf, "INLINE_VALUES", 0)     # views even for 7 small frames
    monkeypatch.setattr(hdf5, "FLUSH_SECONDS", 1e9)   # one flush, at the end
    monkeypatch.setattr(hdf5, "VIEWS_PER_OPENING", 3)
    batches: list[tuple[int, int, object]] = []
    original = xdmf.add_step_views

    def add_step_views(h5, first, stop, **options):
        batches.append((first, stop, h5))
        return original(h5, first, stop, **options)

    monkeypatch.setattr(xdmf, "add_step_views", add_step_views)
    out = tmp_path / "views.h5"
    run_scene(ROOT / "inputs/hard/pendulum.nml", OVERRIDES, out, progress=False)
    made = [(first, stop) for first, stop, _ in batches if stop > first]
    assert made[:3] == [(0, 3), (3, 6), (6, 7)]
    openings = [h5 for first, stop, h5 in batches[:3]]
    assert len({id(h5) for h5 in openings}) == 3 and not any(h5.id.valid for h5 in openings)
    with h5py.File(out, "r") as h5:
        displacement = h5["dynamic/mesh_displacement"][()]
        assert len(h5["dynamic/xdmf/displacement"]) == len(displacement) == 7
        for k in range(7):
            assert np.array_equal(h5[f"dynamic/xdmf/displacement/{k}"][()], displacement[k])
        assert np.array_equal(h5["dynamic/xdmf/position/0"][()], h5["dynamic/mesh_nodes"][0])
