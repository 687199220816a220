"""The dynamic reactions' shortcuts (issue 23, a small call's fixed cost): the expansion of
only the full coordinates the reactions read (``Reduction.expand_columns``) and the
component-major reduction of the generalized forces (``answers._reduce_components``) give
bit for bit what the general way gives.

References: the whole expansion ``Reduction.expand`` (its columns), the row-major
reduction ``answers._reduce_rows`` (random forces, coordinates with negative zeros, one
to eight slots, positions and other vectors, swapped joints, distance joints), and whole
runs with both shortcuts switched off (``EXPAND_COLUMNS``, ``COMPONENT_MAJOR``)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import ancfdrv
from conftest import INPUTS
from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.system import answers
from ancfdrv.system.expressions import Vec3

PENDULUM = ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy", "solver.dt=1e-3",
            "solver.t_end=0.05"]


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and a.shape == b.shape and \
        np.ascontiguousarray(a).tobytes() == np.ascontiguousarray(b).tobytes()


@pytest.mark.parametrize("scene, overrides, kind", [
    ("hard/pendulum.nml", PENDULUM, "selects"),
    ("leaf_spring.nml", [], "matrix"),
])
def test_expand_columns_are_the_expansions_columns(scene, overrides, kind):
    """A selecting B (the planar cable: every relation a constant) and a general B (the
    leaf spring's eliminated joints): random reduced rows with negative zeros, random
    sets of columns (sorted, unsorted, repeated), rows of states and a single state."""
    reduction = build_model(load_scene(INPUTS / scene, overrides)).reduction
    assert (reduction.selects is not None) == (kind == "selects")
    rng = np.random.default_rng(11)
    nred, nfull = reduction.matrix.shape[1], len(reduction.offset)
    for trial in range(20):
        x = rng.standard_normal((int(rng.integers(1, 30)), nred)) \
            * 10.0 ** rng.integers(-8, 8, nred)
        x[rng.random(x.shape) < 0.2] = -0.0
        columns = rng.choice(nfull, int(rng.integers(1, nfull + 1)), replace=trial % 3 == 0)
        if trial % 2:
            columns = np.sort(columns)
        assert _same(reduction.expand_columns(x, columns), reduction.expand(x)[:, columns])
        assert _same(reduction.expand_columns(x[0], columns), reduction.expand(x[0])[columns])
    with pytest.raises(ValueError, match="dimension mismatch"):
        reduction.expand_columns(np.zeros((2, nred + 1)), [0])


def test_component_major_reduction_is_row_major_bit_for_bit(monkeypatch):
    """300 random joints: force, moment, point and axial force the same bits."""
    rng = np.random.default_rng(3)
    per, nodes = 12, 4
    monkeypatch.setattr(answers, "_vector_blocks", lambda body: (per, nodes))
    for trial in range(300):
        nt, first = int(rng.integers(1, 40)), int(rng.integers(0, 6))
        nfull = first + per * nodes + 5
        slots = np.sort(rng.choice(per // 3 * nodes, int(rng.integers(1, 9)), replace=False))
        q = rng.standard_normal((nt, nfull)) * rng.choice([1.0, 1e-8, 1e8], (nt, nfull))
        q[rng.random(q.shape) < 0.1] = -0.0
        generalized = rng.standard_normal((nt, 3 * len(slots)))
        generalized[rng.random(generalized.shape) < 0.1] = -0.0
        p2 = Vec3({int(first + 3 * rng.integers(0, 16)): float(rng.standard_normal())
                   for _ in range(int(rng.integers(0, 3)))}, rng.standard_normal(3))
        p1 = Vec3({int(first + 3 * rng.integers(0, 16)): 1.0}, rng.standard_normal(3)) \
            if trial % 3 == 0 else None
        joint = SimpleNamespace(body2=SimpleNamespace(first=first), swapped=bool(trial % 2))
        layouts = [q, np.asfortranarray(q)]   # C rows, and column-major (expand_columns')
        rows = answers._reduce_rows(joint, generalized, slots, q, (p2, p1))
        for layout in layouts:
            mine = answers._reduce_components(joint, generalized, slots, layout, (p2, p1))
            for a, b in zip(rows, mine):
                assert (a is None) == (b is None)
                assert a is None or _same(a, b), trial


@pytest.mark.parametrize("scene, overrides", [
    ("hard/pendulum.nml", PENDULUM),                              # columns of a selecting B
    ("hard/cantilever_drop.nml", ["solver.t_end=0.02"]),          # a weld, columns
    ("knuckle_crane_rope.nml", ["solver.t_end=0.01", "output.xdmf=.false."]),  # distance
    ("leaf_spring.nml", ["solver.t_end=0.01", "output.xdmf=.false."]),  # eliminated joints
])
def test_runs_reactions_are_those_of_the_general_way(monkeypatch, scene, overrides):
    """Whole runs: every recorded reaction (force, moment, axial) with both shortcuts the
    same bits as with neither."""
    def reactions() -> dict[str, dict[str, np.ndarray]]:
        sim = ancfdrv.simulate(INPUTS / scene, overrides, progress=False)
        assert sim.status == "ok" and sim.reactions
        return {name: sim.reaction(name) for name in sim.reactions}
    fast = reactions()
    monkeypatch.setattr(answers, "EXPAND_COLUMNS", False)
    monkeypatch.setattr(answers, "COMPONENT_MAJOR", False)
    general = reactions()
    assert fast.keys() == general.keys()
    for name in fast:
        assert fast[name].keys() == general[name].keys()
        for key in fast[name]:
            assert _same(fast[name][key], general[name][key]), (name, key)


def test_row_columns_name_what_the_reactions_read():
    """The pendulum's pin at the root: the root node's position (its 3-vector the force
    acts on, and the joint's point), nothing else; a map whose gradients come from the
    kernel reads every coordinate (None)."""
    model = build_model(load_scene(INPUTS / "hard/pendulum.nml", PENDULUM))
    columns = answers.reaction_map(model).row_columns()
    first = next(iter(answers.reaction_map(model).joints.values())).body2.first
    assert columns.tolist() == [first, first + 1, first + 2]
    leaf = build_model(load_scene(INPUTS / "leaf_spring.nml"))
    assert answers.reaction_map(leaf).row_columns() is None
