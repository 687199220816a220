"""The dynamic reactions read only the full coordinates they need: the expansion of those
columns (``Reduction.expand_columns``) against the whole expansion ``Reduction.expand``,
and the columns named against what the reactions read."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import INPUTS
from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.system import answers

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
