"""The envelope LU without pivoting (``fortran/src/linalg/envelope_lu.f90``) and its orders
(``graph_order.f90``'s Sloan and reverse Cuthill-McKee), reached through
:meth:`ancfdrv.kernel.DirectSolver.by_cost` with ``positive=True`` (the iteration matrix's
path): solutions against LAPACK's dense LU with partial pivoting (numpy.linalg.solve, dgesv)
on random matrices of the two-leaf spring's pattern (n = 370, half-bandwidth 125 in reverse
Cuthill-McKee order), symmetric positive definite and unsymmetric with a positive definite
symmetric part; the fallback to the pivoted banded LU when a pivot is not positive; and the
envelope Sloan's order finds against the band's.

The residual test: a backward-stable solve has ||A x - b|| <= c n eps ||A|| ||x||; the bound
used, 1e3 eps ||A|| ||x|| (n = 370), leaves the small constant c room, and LAPACK's own
residual sits below it too (asserted alongside, so the bound is not looser than the
reference's)."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv.errors import SolverError
from ancfdrv.kernel import DirectSolver

EPS = np.finfo(float).eps


@pytest.fixture(scope="module")
def spring_pattern() -> tuple[int, np.ndarray, np.ndarray]:
    """The two-leaf spring's iteration-matrix pattern (0-based rows, cols)."""
    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    from pathlib import Path
    scene = load_scene(Path(__file__).resolve().parents[1] / "inputs" / "leaf_spring.nml")
    model = build_model(scene)
    try:
        return model.ndof, np.asarray(model.pattern.rows), np.asarray(model.pattern.col_index)
    finally:
        model.close()


def _on_pattern(n: int, rows: np.ndarray, cols: np.ndarray, rng, *, symmetric: bool,
                skew: float = 0.0) -> np.ndarray:
    """A random dense matrix whose nonzeros lie on the pattern: B + B^T + a diagonal that
    makes it positive definite (Gershgorin), plus skew times an unsymmetric part of the
    same pattern (unsymmetric: its symmetric part stays positive definite when skew
    keeps the diagonal dominant)."""
    b = np.zeros((n, n))
    b[rows, cols] = rng.standard_normal(len(rows))
    a = b + b.T
    a += np.diag(np.abs(a).sum(axis=1) + 1.0)
    if not symmetric:
        c = np.zeros((n, n))
        c[rows, cols] = rng.standard_normal(len(rows))
        a += skew * c
    return a


def _relative_residual(a: np.ndarray, x: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a @ x - b) / (np.linalg.norm(a, 2) * np.linalg.norm(x)))


@pytest.mark.parametrize("symmetric", [True, False])
def test_envelope_lu_solves_like_lapack_on_the_spring_pattern(spring_pattern, symmetric):
    """SPD and unsymmetric (positive definite symmetric part) matrices on the spring's
    pattern: the envelope kind is chosen (the banded LU's budget holds, positive = True),
    never falls back, and its solutions of three right-hand sides have a relative residual
    within 1e3 eps (as LAPACK's dgesv) and agree with dgesv's to the condition number's
    reach; a second factorization on the same handle (new values) likewise."""
    n, rows, cols = spring_pattern
    rng = np.random.default_rng(38 + symmetric)
    with DirectSolver.by_cost(n, rows, cols, positive=True, what="spring") as solver:
        assert solver.envelope_lu and solver.kind == "envelope LU"
        assert solver.width == 125  # the reverse Cuthill-McKee band of the fallback
        for _ in range(2):
            a = _on_pattern(n, rows, cols, rng, symmetric=symmetric, skew=0.5)
            b = rng.standard_normal((n, 3))
            solver.factorize(a[rows, cols])
            x = solver.solve(b)
            reference = np.linalg.solve(a, b)
            for k in range(3):
                assert _relative_residual(a, x[:, k], b[:, k]) < 1e3 * EPS
                assert _relative_residual(a, reference[:, k], b[:, k]) < 1e3 * EPS
            condition = np.linalg.cond(a)
            assert np.max(np.abs(x - reference)) <= 1e3 * EPS * condition * np.max(
                np.abs(reference))
        assert solver.fallbacks == 0


def test_envelope_smaller_than_the_band(spring_pattern):
    """The order the kernel picks for the envelope (Sloan's, or the reverse Cuthill-McKee
    one when smaller) has at most the band's entries n kd - kd (kd + 1) / 2, and here (a
    ring of leaves closed through the chassis) well under it: its solve is the cheaper of
    the two by that ratio."""
    n, rows, cols = spring_pattern
    with DirectSolver.by_cost(n, rows, cols, positive=True) as solver:
        kd = solver.width
        band = n * kd - kd * (kd + 1) // 2
        assert 0 < solver.envelope < 0.6 * band


def test_sloan_order_recovers_a_shuffled_path():
    """A shuffled tridiagonal matrix (a path graph): Sloan's order from its pseudo-peripheral
    end finds the path again, envelope n - 1 (one entry per row, the least possible for a
    connected graph), and solves like LAPACK."""
    n = 60
    rng = np.random.default_rng(7)
    perm = rng.permutation(n)
    a = np.diag(4.0 + rng.random(n)) + np.diag(rng.standard_normal(n - 1), 1) \
        + np.diag(rng.standard_normal(n - 1), -1)
    a = a[np.ix_(perm, perm)]
    rows, cols = np.nonzero(a)
    with DirectSolver.by_cost(n, rows, cols, positive=True) as solver:
        assert solver.envelope_lu and solver.envelope == n - 1
        solver.factorize(a[rows, cols])
        b = rng.standard_normal(n)
        np.testing.assert_allclose(solver.solve(b), np.linalg.solve(a, b), rtol=1e-12,
                                   atol=1e-14)


def test_pivot_not_positive_falls_back_to_the_pivoted_banded_lu(spring_pattern):
    """A matrix on the same pattern with an indefinite symmetric part (the diagonal's sign
    flipped in a few rows, so some pivot turns negative): the envelope LU stops, the same
    handle factorizes it by the pivoted banded LU (counted), whose solution matches
    LAPACK's; the next positive definite matrix takes the envelope LU again (no new
    fallback, residual within 1e3 eps); a singular matrix fails with the error's words."""
    n, rows, cols = spring_pattern
    rng = np.random.default_rng(3)
    with DirectSolver.by_cost(n, rows, cols, positive=True, what="spring") as solver:
        a = _on_pattern(n, rows, cols, rng, symmetric=False, skew=0.5)
        indefinite = a.copy()
        flip = rng.choice(n, 5, replace=False)
        indefinite[flip, flip] *= -1.0
        b = rng.standard_normal(n)
        solver.factorize(indefinite[rows, cols])
        assert solver.fallbacks == 1
        x = solver.solve(b)
        assert _relative_residual(indefinite, x, b) < 1e3 * EPS
        np.testing.assert_allclose(x, np.linalg.solve(indefinite, b), rtol=1e-8,
                                   atol=1e-10 * np.max(np.abs(x)))
        solver.factorize(a[rows, cols])
        assert solver.fallbacks == 1
        assert _relative_residual(a, solver.solve(b), b) < 1e3 * EPS
        singular = a.copy()
        singular[:, 11] = 0.0
        singular[11, :] = 0.0
        with pytest.raises(SolverError, match="spring: factorization failed: .*singular"):
            solver.factorize(singular[rows, cols])
        assert solver.fallbacks == 2


def test_saddle_patterns_keep_the_banded_lu(spring_pattern):
    """Without positive (a saddle-point system's zero block would stop the envelope LU
    at its first multiplier) the cost rule's banded LU, as before."""
    n, rows, cols = spring_pattern
    with DirectSolver.by_cost(n, rows, cols) as solver:
        assert solver.banded_lu and not solver.envelope_lu and solver.envelope == 0
