"""The kernel hand-over's skipped calls (issue 23, a small call's fixed cost): a system
without frames or drives is not sent the empty lists system_create made already, and the
layouts of the packed state and of the rows are kept per key.

References: the kernel's calls counted (a scene with drives and frames still sends them),
the layouts made anew."""
from __future__ import annotations

import numpy as np
import pytest

import ancfdrv
import ancfdrv.kernel as kernel
from conftest import INPUTS

PENDULUM = ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy", "solver.dt=1e-3",
            "solver.t_end=0.2"]


def _series(scene, overrides):
    sim = ancfdrv.simulate(INPUTS / scene, overrides, progress=False)
    assert sim.status == "ok"
    return {k: np.asarray(sim.series(k)) for k in sim.names}


def test_frames_set_once_are_cleared_by_an_empty_call(monkeypatch):
    """Only a system that never held frames or drives skips the empty call."""
    calls = []
    monkeypatch.setattr(kernel._kernel, "system_set_frames",
                        lambda *args: calls.append(args[1]) or (0, b""))
    monkeypatch.setattr(kernel._kernel, "system_set_drives",
                        lambda *args: calls.append(args[1]) or (0, b""))
    ks = kernel.KernelSystem.__new__(kernel.KernelSystem)
    ks.handle = 1
    ks.set_frames([], [], [], [])
    ks.set_drives([], [])
    assert calls == []
    ks.set_frames([-1], [[0.0, 0.0, 1.0]], [np.eye(3)], [[0.0, 0.0, 0.0]])
    ks.set_frames([], [], [], [])
    ks.set_drives([1], [[0.5]])
    ks.set_drives([], [])
    assert calls == [1, 0, 1, 0]


def test_layouts_kept_per_key_are_the_layouts_made_anew():
    ks = kernel.KernelSystem.__new__(kernel.KernelSystem)
    ks.ndof, ks.ncon, ks.npoint, ks.nprobe = 20, 2, 3, 1
    first = {q: ks._layout(q) for q in (True, False, True)}
    for q in (True, False):
        fresh = kernel.KernelSystem.__new__(kernel.KernelSystem)
        fresh.ndof, fresh.ncon, fresh.npoint, fresh.nprobe = 20, 2, 3, 1
        assert fresh._layout(q) == first[q]
    assert ks.row_size(True) - ks.row_size(False) == 20
    ks.ndof = 21   # another system's sizes: another layout
    assert ks.row_size(True) - ks.row_size(False) == 21


@pytest.mark.parametrize("scene, overrides", [
    ("hard/pendulum.nml", PENDULUM),
    ("plate_pendulum.nml", ["solver.t_end=0.01"]),
])
def test_carry_vectors_kept_are_those_made_anew(scene, overrides):
    """The kept carry vectors (read only) are those made anew, and a changed policy makes
    them again."""
    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    from ancfdrv.system.model import POLICY_CONSTANT
    model = build_model(load_scene(INPUTS / scene, overrides))
    kept, made = model.carry_vectors(), model.made_carry_vectors()
    assert kept is model.carry_vectors()
    assert (kept is None) == (made is None)
    if kept is not None:
        for a, b in zip(kept, made):
            assert a.dtype == b.dtype and np.array_equal(a, b) and not a.flags.writeable
    policy, model.policy = model.policy, POLICY_CONSTANT
    assert model.carry_vectors() is None and model.made_carry_vectors() is None
    model.policy = policy
    again = model.carry_vectors()
    assert (again is None) == (made is None)
    if again is not None:
        assert all(np.array_equal(a, b) for a, b in zip(again, made))
