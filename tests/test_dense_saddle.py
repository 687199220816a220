"""The dense solve of small saddle systems (the consistent initial acceleration of a model
with at most ``dynamic.DENSE_SADDLE_MAX`` coordinates and multipliers, issue 23's fixed
cost; off by default, set to 160 here): LAPACK's LU of the dense matrix in the kernel
(``kernel.dense_solve``) in place of MUMPS.

References: MUMPS's solution of the same system (the path of larger systems, forced by
``DENSE_SADDLE_MAX = 0``), the equations of motion M a - Phi_e^T lambda = f and the
constraints' acceleration equation Phi_e a = gamma, and numpy's dense solve of random
systems with repeated triplets."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import INPUTS
from ancfdrv.builders import build_model
from ancfdrv.errors import SolverError
from ancfdrv.io.scene import load_scene
from ancfdrv.kernel import dense_solve
from ancfdrv.solvers import dynamic

CASES = [
    ("hard/pendulum.nml", ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy"]),
    ("hard/pendulum.nml", ["beam.nodes=9"]),
    ("hard/spinup.nml", []),
    ("boom_luffing.nml", ["beam.nodes=4"]),
    ("general/cardan_shaft.nml", []),
]


def _residuals(model, e, v, t, a, lam):
    """The residuals of the equations of motion and of Phi_e a = gamma (largest entries)
    and the sizes of their terms."""
    forces = model.forces(e, t, v)
    evaluated = model.constraints.evaluate(e, t, v)
    _, rows, cols, grads = model.constraints.jacobian(e, model.ndof, t, evaluated)
    phi_e = np.zeros((len(model.constraints), model.ndof))
    np.add.at(phi_e, (rows, cols), grads)
    f = forces["external"] - forces["internal"]
    ma = model.mass.toarray() @ a
    motion = np.abs(ma - phi_e.T @ lam - f).max()
    motion_scale = np.abs(ma).max() + np.abs(phi_e.T @ lam).max() + np.abs(f).max()
    gamma = evaluated[-1]
    acceleration = np.abs(phi_e @ a - gamma).max(initial=0.0)
    acceleration_scale = np.abs(phi_e).max(initial=0.0) * np.abs(a).max() + \
        np.abs(gamma).max(initial=0.0)
    return motion, motion_scale, acceleration, acceleration_scale


@pytest.mark.parametrize("scene,overrides", CASES)
def test_dense_saddle_solve_equals_mumps(scene, overrides, monkeypatch):
    """At the initial state and at a perturbed moving one (t = 0.1 s): the dense solve's
    acceleration and multipliers equal MUMPS's to 1e-12 of their largest entry, and both
    satisfy the equations of motion and the constraints' accelerations to round-off."""
    model = build_model(load_scene(INPUTS / scene, overrides))
    try:
        monkeypatch.setattr(dynamic, "DENSE_SADDLE_MAX", 160)   # (off by default)
        n = model.ndof + len(model.constraints)
        assert n <= dynamic.DENSE_SADDLE_MAX   # the dense path is the one taken
        rng = np.random.default_rng(7)
        states = [(model.e0, np.zeros(model.ndof), 0.0),
                  (model.e0 + 1e-4 * rng.standard_normal(model.ndof),
                   1e-2 * rng.standard_normal(model.ndof), 0.1)]
        for e, v, t in states:
            dense = dynamic.initial_acceleration(model, e, v, t)
            with monkeypatch.context() as patch:
                patch.setattr(dynamic, "DENSE_SADDLE_MAX", 0)
                sparse = dynamic.initial_acceleration(model, e, v, t)
            for x, y in zip(dense, sparse):
                assert x.shape == y.shape
                if len(y):
                    assert np.abs(x - y).max() <= 1e-12 * max(np.abs(y).max(), 1e-300)
            for a, lam in (dense, sparse):
                motion, motion_scale, acceleration, scale = _residuals(model, e, v, t, a,
                                                                       lam)
                assert motion <= 1e-13 * motion_scale and acceleration <= 1e-13 * scale
    finally:
        model.close()


def test_dense_solve_adds_repeated_triplets():
    """Triplets at the same place add up (as MUMPS's do); several right-hand sides."""
    rng = np.random.default_rng(11)
    n = 9
    matrix = rng.standard_normal((n, n)) + n * np.eye(n)
    rows, cols = np.nonzero(np.ones((n, n)))
    split = rng.random(len(rows))       # every entry given as two triplets
    values = np.concatenate([split * matrix[rows, cols], (1 - split) * matrix[rows, cols]])
    order = rng.permutation(2 * len(rows))
    rhs = rng.standard_normal((n, 3))
    x = dense_solve(n, np.tile(rows, 2)[order], np.tile(cols, 2)[order], values[order], rhs)
    assert np.abs(x - np.linalg.solve(matrix, rhs)).max() <= 1e-13 * np.abs(x).max()
    single = dense_solve(n, rows, cols, matrix[rows, cols], rhs[:, 0])
    assert single.shape == (n,)
    assert np.abs(matrix @ single - rhs[:, 0]).max() <= 1e-13 * np.abs(rhs).max() * n


def test_dense_solve_refuses_singular_and_bad_input():
    """A singular matrix (a zero column) and an index outside the matrix raise SolverError
    naming the system."""
    rows, cols = np.array([0, 1, 2]), np.array([0, 0, 2])
    with pytest.raises(SolverError, match="test system: factorization failed: .*singular"):
        dense_solve(3, rows, cols, np.ones(3), np.ones(3), what="test system")
    with pytest.raises(SolverError, match="test system: a coordinate index"):
        dense_solve(3, np.array([0, 3]), np.array([0, 1]), np.ones(2), np.ones(3),
                    what="test system")


def test_large_saddle_systems_keep_mumps(monkeypatch):
    """A system above DENSE_SADDLE_MAX goes to MUMPS (its instance joins the free list)."""
    model = build_model(load_scene(INPUTS / "hard/pendulum.nml",
                                   ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy"]))
    try:
        monkeypatch.setattr(dynamic, "DENSE_SADDLE_MAX", 160)   # (off by default)
        calls = []
        real = dynamic.dense_solve
        monkeypatch.setattr(dynamic, "dense_solve", lambda *a, **k: calls.append(1) or
                            real(*a, **k))
        dynamic.initial_acceleration(model, model.e0, np.zeros(model.ndof), 0.0)
        assert calls == [1]
        monkeypatch.setattr(dynamic, "DENSE_SADDLE_MAX", model.ndof + len(model.constraints) - 1)
        dynamic.initial_acceleration(model, model.e0, np.zeros(model.ndof), 0.0)
        assert calls == [1] and dynamic._SADDLE_SOLVERS
    finally:
        model.close()
