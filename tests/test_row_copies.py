"""A writer's copies of a chunk's rows: the XDMF frame rows picked by index are those a
mask over every row picks (rows % stride == 0 or the last row), and a kept chunk holds
no view of the kernel's rows."""
from __future__ import annotations

from types import SimpleNamespace

import h5py
import numpy as np

import ancfdrv
from conftest import INPUTS
from ancfdrv.results import hdf5

PENDULUM = ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy", "solver.dt=1e-3",
            "solver.t_end=0.3"]


def test_frame_rows_by_index_are_the_masks():
    """Random chunks of a run: first row, rows, stride and last row (in the chunk, before
    it, after it, on the stride and off it)."""
    rng = np.random.default_rng(7)
    for _ in range(2000):
        n, first, stride = int(rng.integers(1, 40)), int(rng.integers(0, 100)), \
            int(rng.integers(1, 9))
        last = int(rng.integers(-1, 150))
        q = rng.standard_normal((n, 3))
        chunk = SimpleNamespace(time=np.arange(n, dtype=float), q=q)
        _, frame = hdf5.thinned_chunk(chunk, first, stride, last, True)
        rows = first + np.arange(n)
        pick = (rows % stride == 0) | (rows == last)
        if not pick.any():
            assert frame is None
            continue
        assert frame[0].dtype == rows.dtype and np.array_equal(frame[0], rows[pick])
        assert frame[1].tobytes() == q[pick].tobytes() and frame[1].shape == q[pick].shape


def _kept(scene: str, overrides: list[str], tmp_path, name: str):
    sim = ancfdrv.simulate(INPUTS / scene, overrides, progress=False)
    assert sim.status == "ok"
    series = {k: np.asarray(sim.series(k)) for k in sim.names}
    path = sim.save(tmp_path / f"{name}.h5")
    found = {}
    with h5py.File(path, "r") as h5:
        def visit(key, obj):
            if isinstance(obj, h5py.Dataset) and not key.startswith("timing"):
                found[key] = obj[()]
        h5.visititems(visit)
    return series, found


def test_a_kept_chunk_holds_no_view_of_the_kernels_rows(monkeypatch):
    """The copy is the point of thinning: the kernel's row buffer (mostly q) is released,
    so no kept field may be a view of it."""
    kept: list = []
    real = hdf5.thinned_chunk

    def spy(chunk, *args):
        out, frame = real(chunk, *args)
        kept.append((getattr(chunk, "rows", None), out))
        return out, frame
    monkeypatch.setattr(hdf5, "thinned_chunk", spy)
    ancfdrv.simulate(INPUTS / "hard/pendulum.nml", PENDULUM, progress=False)
    assert any(rows is not None for rows, _ in kept)
    for rows, out in kept:
        if rows is None:
            continue
        for f in hdf5.ROW_FIELDS:
            value = getattr(out, f)
            assert value is None or not np.shares_memory(value, rows[0]), f
