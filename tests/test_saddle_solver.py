"""The solver a model's saddle-point systems are factorized by (the static Newton's and the
consistent start's; ``fortran/src/linalg/sparse_direct.f90``'s solver_create_for, reached
through :meth:`ancfdrv.kernel.DirectSolver.by_cost`): LAPACK's banded LU in the reverse
Cuthill-McKee order of the pattern when 4 n kd^2 <= 5e7 (``banded_lu_flops``), else MUMPS.
References: numpy's dense solve, the residual of the system itself, a grid's half-bandwidth
for the one the kernel's order reaches, and the MUMPS libraries' resident pages for which
kind ran."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import INPUTS, mumps_pages
from ancfdrv.errors import SolverError
from ancfdrv.kernel import DirectSolver


def _saddle(n: int, links: list[list[tuple[int, float]]], seed: int,
            symmetric: bool = True) -> np.ndarray:
    """[[K, -G^T], [-G, 0]] with K banded (half-bandwidth 3, diagonally dominant; unsymmetric
    on request) and G's rows the constraints' (dof, coefficient) terms."""
    rng = np.random.default_rng(seed)
    k = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - 3), min(n, i + 4)):
            k[i, j] = rng.normal()
    k = (k + k.T if symmetric else k) + 12.0 * np.eye(n)
    g = np.zeros((len(links), n))
    for c, terms in enumerate(links):
        for dof, coef in terms:
            g[c, dof] = coef
    return np.block([[k, -g.T], [-g, np.zeros((len(links), len(links)))]])


def _solve(a: np.ndarray, b: np.ndarray) -> tuple[DirectSolver, np.ndarray]:
    rows, cols = np.nonzero(a)
    solver = DirectSolver.by_cost(len(a), rows, cols, what="test saddle")
    solver.factorize(a[rows, cols])
    return solver, solver.solve(b)


# constraints: a clamp at the first dofs, a loop closure between the ends (the RCM order
# has to bring them together), a three-term relation in the middle
LINKS = [[(0, 1.0)], [(1, 1.0)], [(2, 0.5), (27, -0.5)], [(12, 1.0), (13, -2.0), (15, 0.3)]]


@pytest.mark.parametrize("symmetric", [True, False])
def test_saddle_systems_match_the_dense_solve(symmetric):
    """A 30-dof banded K with four constraints (one closing a loop across the whole band):
    the banded LU (chosen: 34 unknowns) solves three right-hand sides to numpy's dense
    solution within round-off of the solution's size (cond ~ 1e2)."""
    a = _saddle(30, LINKS, seed=3, symmetric=symmetric)
    b = np.random.default_rng(4).normal(size=(len(a), 3))
    solver, x = _solve(a, b)
    with solver:
        assert solver.banded_lu
        reference = np.linalg.solve(a, b)
        assert np.abs(x - reference).max() <= 1e-12 * np.abs(reference).max()


def test_a_singular_saddle_is_refused_with_its_text():
    """Two constraints on the same dof make the saddle singular: the factorization is
    refused with the words 'numerically singular' and the system's name."""
    a = _saddle(10, [[(0, 1.0)], [(0, 2.0)]], seed=5)
    assert np.linalg.matrix_rank(a) == len(a) - 1
    rows, cols = np.nonzero(a)
    with DirectSolver.by_cost(len(a), rows, cols, what="test saddle") as solver:
        assert solver.banded_lu
        with pytest.raises(SolverError, match="test saddle: factorization failed: the "
                                              "matrix is numerically singular"):
            solver.factorize(a[rows, cols])


def _grid(side: int) -> tuple[int, np.ndarray, np.ndarray]:
    """The 5-point Laplacian's pattern on a side x side grid numbered row by row: RCM
    cannot narrow its band below about side."""
    n = side * side
    index = np.arange(n).reshape(side, side)
    pairs = [(index.ravel(), index.ravel()),
             (index[:, :-1].ravel(), index[:, 1:].ravel()),
             (index[:-1, :].ravel(), index[1:, :].ravel())]
    rows = np.concatenate([p[0] for p in pairs] + [p[1] for p in pairs[1:]])
    cols = np.concatenate([p[1] for p in pairs] + [p[0] for p in pairs[1:]])
    return n, rows, cols


#: the kernel's budget of the banded LU's factorization (sparse_direct's banded_lu_flops)
BANDED_LU_FLOPS = 5.0e7


@pytest.mark.parametrize("side,banded", [(40, True), (80, False)])
def test_the_choice_follows_the_cost_rule(side, banded):
    """The kernel's reverse Cuthill-McKee reaches a side x side grid's half-bandwidth (kd =
    side, the least: a row of the grid lies between a node and its neighbour in the next
    row), and the kind follows 4 n kd^2 <= 5e7: a 40 x 40 grid (1e7 flops) takes the banded
    LU, an 80 x 80 one (1.6e8) MUMPS; both solve the shifted Laplacian to a residual at
    round-off."""
    n, rows, cols = _grid(side)
    assert (4.0 * n * side**2 <= BANDED_LU_FLOPS) == banded
    values = np.where(rows == cols, 4.5, -1.0)
    b = np.sin(np.arange(n))
    with DirectSolver.by_cost(n, rows, cols) as solver:
        assert solver.width == side
        assert solver.banded_lu == banded
        solver.factorize(values)
        x = solver.solve(b)
    residual = np.zeros(n)
    np.add.at(residual, rows, values * x[cols])
    assert np.abs(residual - b).max() <= 1e-13 * np.abs(b).max() * 10


def test_a_small_models_static_solve_and_start_never_run_mumps():
    """The 4-node boom's static Newton (three load steps, a 16-unknown saddle) and its
    consistent start in a fresh interpreter leave the MUMPS libraries' resident pages as
    they were (their saddles take the banded LU); one MUMPS solve afterwards adds hundreds
    of kB of them (the measure sees MUMPS run)."""
    small, mumps = mumps_pages(
        INPUTS / "boom_luffing.nml",
        ["scene.formulation=nonlinear", "solver.static_method=newton", "beam.bending=cable",
         "scene.planar=xy", "beam.nodes=4"],
        "result = static.solve_newton(model, load_steps=3)\n"
        "dynamic.initial_acceleration(model, result.e, np.zeros(model.ndof), 0.0)")
    assert small == 0
    assert mumps >= 256
