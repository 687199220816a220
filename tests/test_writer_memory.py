"""The dynamic writer keeps no coordinates of every step while rows wait for the next flush
unless /dynamic/q is written (results/hdf5.py DynamicWriter._thinned, issue 23: a run's
peak memory): the XDMF frames' points are computed when a chunk arrives and only the last
row's q is kept. The file is the same as when the frames come from q at every step."""
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
