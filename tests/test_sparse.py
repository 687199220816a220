"""Sparse pattern, scatter assembly and the MUMPS handle against dense references."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv.errors import SolverError
from ancfdrv.kernel import DirectSolver, SparsePattern

RNG = np.random.default_rng(11)


def test_pattern_assembly_equals_dense_sum():
    n, ndofe = 40, 6
    dofs = np.array([RNG.choice(n, ndofe, replace=False) for _ in range(15)]).T
    values = RNG.standard_normal((ndofe, ndofe, 15))
    pattern = SparsePattern(n, dofs)
    dense = np.zeros((n, n))
    for e in range(15):
        dense[np.ix_(dofs[:, e], dofs[:, e])] += values[:, :, e]
    np.testing.assert_allclose(pattern.to_scipy(pattern.assemble(values)).toarray(), dense,
                               atol=1e-14)
    assert pattern.nnz == len({(i, j) for e in range(15) for i in dofs[:, e] for j in dofs[:, e]})


def test_pattern_rejects_out_of_range_dofs():
    from ancfdrv.errors import InputError
    with pytest.raises(InputError):
        SparsePattern(5, np.array([[0], [5]]))


def test_mumps_solves_many_rhs_and_refactorizes():
    n = 60
    a = RNG.standard_normal((n, n)) * (RNG.random((n, n)) < 0.1) + 5 * np.eye(n)
    rows, cols = np.nonzero(a)
    rhs = RNG.standard_normal((n, 7))
    with DirectSolver(n, rows, cols) as solver:
        solver.factorize(a[rows, cols])
        np.testing.assert_allclose(solver.solve(rhs), np.linalg.solve(a, rhs), atol=1e-12)
        b = a.copy()
        b[rows, cols] *= 2.0
        solver.factorize(b[rows, cols])
        np.testing.assert_allclose(solver.solve(rhs[:, 0]), np.linalg.solve(b, rhs[:, 0]),
                                   atol=1e-12)
        assert solver.factorizations == 2 and solver.solves == 8


def test_mumps_duplicate_entries_are_summed():
    rows, cols = np.array([0, 0, 1, 1, 1]), np.array([0, 0, 1, 0, 1])
    with DirectSolver(2, rows, cols) as solver:
        solver.factorize(np.array([1.0, 1.0, 2.0, 1.0, 2.0]))  # [[2, 0], [1, 4]]
        np.testing.assert_allclose(solver.solve(np.array([2.0, 5.0])), [1.0, 1.0])


def test_singular_matrix_raises_clear_error():
    rows, cols = np.array([0, 0, 1, 1]), np.array([0, 1, 0, 1])
    with DirectSolver(2, rows, cols, what="test matrix") as solver:
        with pytest.raises(SolverError, match="test matrix: factorization failed: .*singular"):
            solver.factorize(np.array([1.0, 2.0, 2.0, 4.0]))
        with pytest.raises(SolverError, match="out of sequence"):
            solver.solve(np.ones(2))


def test_scipy_view_owns_its_pattern():
    """Regression: scipy shared the pattern's index arrays, and an in-place
    eliminate_zeros on the matrix corrupted the model's sparsity pattern."""
    dofs = np.array([[0, 1, 2], [1, 2, 3]]).T
    pattern = SparsePattern(4, dofs)
    before = pattern.col_index.copy(), pattern.row_ptr.copy()
    matrix = pattern.to_scipy(np.zeros(pattern.nnz))
    matrix.eliminate_zeros()
    np.testing.assert_array_equal(pattern.col_index, before[0])
    np.testing.assert_array_equal(pattern.row_ptr, before[1])


def test_banded_solver_handles_indefinite_matrices():
    """The banded Cholesky falls back to the pivoted banded LU when the matrix is not
    positive definite (a tangent under compression); reference: numpy's dense solve."""
    n, kd = 30, 3
    a = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - kd), min(n, i + kd + 1)):
            a[i, j] = a[j, i] = RNG.standard_normal()
    a += np.diag(np.linspace(-5.0, 5.0, n))  # symmetric, indefinite
    assert np.linalg.eigvalsh(a).min() < 0
    rows, cols = np.nonzero(a)
    rhs = RNG.standard_normal((n, 2))
    with DirectSolver(n, rows, cols, banded_spd=True) as solver:
        solver.factorize(a[rows, cols])
        np.testing.assert_allclose(solver.solve(rhs), np.linalg.solve(a, rhs), rtol=1e-9,
                                   atol=1e-11)
        spd = a + (abs(np.linalg.eigvalsh(a).min()) + 1.0) * np.eye(n)
        solver.factorize(spd[rows, cols])  # back to the Cholesky path on the same handle
        np.testing.assert_allclose(solver.solve(rhs), np.linalg.solve(spd, rhs), rtol=1e-9)


def _shuffled_band(n: int, kd: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """An unsymmetric matrix of half-bandwidth kd in a random numbering (its band hidden)
    and that numbering's permutation."""
    rng = np.random.default_rng(seed)
    a = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - kd), min(n, i + kd + 1)):
            a[i, j] = rng.standard_normal()
    a += 4.0 * np.eye(n)
    perm = rng.permutation(n)
    return a[np.ix_(perm, perm)], perm


def test_banded_lu_with_an_ordering_solves_in_the_callers_numbering():
    """The general banded kind (LAPACK's pivoted banded LU) in the kernel's ordering of the
    unknowns (DirectSolver.by_cost on a shuffled band): solutions for one and several
    right-hand sides in the original numbering against numpy's dense solve, a
    refactorization on the same handle, and a singular matrix refused with the error's
    words."""
    n = 40
    a, perm = _shuffled_band(n, 2, seed=5)
    rows, cols = np.nonzero(a)
    rhs = RNG.standard_normal((n, 3))
    with DirectSolver.by_cost(n, rows, cols, what="band") as solver:
        assert solver.banded_lu
        solver.factorize(a[rows, cols])
        np.testing.assert_allclose(solver.solve(rhs), np.linalg.solve(a, rhs), rtol=1e-10,
                                   atol=1e-12)
        b = a.copy()
        b[rows, cols] *= RNG.uniform(0.5, 1.5, len(rows))
        solver.factorize(b[rows, cols])
        np.testing.assert_allclose(solver.solve(rhs[:, 1]), np.linalg.solve(b, rhs[:, 1]),
                                   rtol=1e-10, atol=1e-12)
        singular = a.copy()
        singular[:, 7] = 0.0
        with pytest.raises(SolverError, match="band: factorization failed: .*singular"):
            solver.factorize(singular[rows, cols])


def test_band_order_recovers_a_hidden_band():
    """The kernel's reverse Cuthill-McKee on shuffled banded patterns of half-bandwidth 1,
    2 and 3 finds the band again: width kd, the least possible (an inner unknown has 2 kd
    neighbours, so some neighbour lies at least kd places away in any order)."""
    for kd in (1, 2, 3):
        a, _ = _shuffled_band(50, kd, seed=kd)
        rows, cols = np.nonzero(a)
        with DirectSolver.by_cost(50, rows, cols) as solver:
            assert solver.banded_lu and solver.width == kd
