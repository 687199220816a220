"""The fixed cost of a small in-memory call (issue 23): the shortcuts of the set-up give
what the general way gives, and a call leaves no reference cycles behind.

References: numpy's own functions (np.linspace bit for bit), the recorder's times against
the rows it was given, the garbage collector (an invariant: a dropped result is freed by
reference counting, no object of a run waits for the collector), the history of a run
(unchanged by the weak references)."""
from __future__ import annotations

import gc

import numpy as np
import pytest

import ancfdrv
from conftest import INPUTS
from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.results.memory import MemoryOutput
from ancfdrv.system import answers
from ancfdrv.system.bodies import linspace

PENDULUM = ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy", "solver.dt=1e-3",
            "solver.t_end=0.05"]


def test_linspace_is_numpys_bit_for_bit():
    """Random ends over ten decades, zero starts, 0 to 40 points (the branches of numpy's
    own: fewer than two points, a zero step)."""
    rng = np.random.default_rng(5)
    cases = [(0.0, 1.2, 5), (0.0, 0.0, 4), (1.0, 1.0, 3), (2.0, 3.0, 1), (2.0, 3.0, 0),
             (-1e-300, 1e-300, 7)]
    for k in range(3000):
        a, b = rng.standard_normal(2) * 10.0 ** rng.integers(-5, 5, 2)
        cases.append((0.0 if k % 5 == 0 else a, b, int(rng.integers(0, 41))))
    for a, b, n in cases:
        mine, numpys = linspace(a, b, n), np.linspace(a, b, n)
        assert mine.dtype == numpys.dtype and mine.shape == numpys.shape
        assert np.array_equal(mine.view(np.int64), numpys.view(np.int64)), (a, b, n)


@pytest.mark.parametrize("scene,overrides", [
    ("hard/pendulum.nml", PENDULUM),
    ("hard/spinup.nml", ["solver.t_end=0.05"]),
    ("general/cardan_shaft.nml", ["solver.t_end=0.01"]),
])
def test_a_call_leaves_no_reference_cycles(scene, overrides):
    """After a call and its result dropped, the collector finds nothing of it: the model,
    the answers' map, the in-memory writer and the scene are freed by reference counting
    (the model and its reaction map, and the output and its writer, refer to each other
    one way weakly)."""
    ancfdrv.simulate(INPUTS / scene, overrides, progress=False)   # imports, caches
    gc.collect()
    saved = gc.get_debug()
    gc.set_debug(gc.DEBUG_SAVEALL)
    try:
        sim = ancfdrv.simulate(INPUTS / scene, overrides, progress=False)
        assert sim.status == "ok" and len(sim.time) > 1
        del sim
        gc.collect()
        ours = [type(o).__module__ + "." + type(o).__qualname__ for o in gc.garbage
                if type(o).__module__.startswith(("ancfdrv", "f90nml"))]
        assert ours == []
    finally:
        gc.set_debug(saved)
        gc.garbage.clear()


def test_reaction_map_and_memory_writer_reach_their_owners():
    """The map reaches its model and the writer its output while they live; a map kept
    apart from a released model says so (ReferenceError), never a wrong model."""
    model = build_model(load_scene(INPUTS / "hard/pendulum.nml", PENDULUM))
    rmap = answers.reaction_map(model)
    assert rmap.model is model and answers.reaction_map(model) is rmap
    output = MemoryOutput()
    writer = output.DynamicWriter(None, model, False)
    assert writer.output is output
    writer.flush_last()
    assert output.journal[-1][:2] == ("flush_last", writer)
    del output
    with pytest.raises(ReferenceError):
        writer.output  # noqa: B018
    model.close()
    del model, writer   # (the writer held the model)
    with pytest.raises(ReferenceError):
        rmap.model  # noqa: B018


def test_recorder_times_are_the_rows_times():
    """The answers recorder's times (kept as arrays, joined on request) are the times of
    the rows it recorded, in order, as plain floats; the reactions have one row each."""
    scene = load_scene(INPUTS / "hard/pendulum.nml", PENDULUM)
    sim = ancfdrv.simulate(scene, progress=False)
    recorder = sim._output.recorder
    assert recorder is not None
    times = recorder.time
    assert all(type(t) is float for t in times)
    assert np.array_equal(np.array(times), sim.time)
    force = sim.series("time")
    assert len(force) == len(times)
