"""ancfdrv.csr (the numpy CSR matrices a dynamic run uses instead of scipy.sparse, issue 23)
against scipy.sparse as the independent reference: every operation gives scipy's result
bit for bit (values, column order, stored entries), including the products whose sums
cancel to zero (scipy drops those) and the unsorted column order of a product."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from ancfdrv.csr import Csr, block_diagonal


def _random(rng, n, m, density, *, integer=False) -> sp.csr_matrix:
    mask = rng.random((n, m)) < density
    values = rng.integers(-2, 3, (n, m)).astype(float) if integer else rng.normal(size=(n, m))
    a = sp.csr_matrix(np.where(mask, values, 0.0))
    a.sort_indices()
    return a


def _ours(a: sp.csr_matrix) -> Csr:
    return Csr(a.data.copy(), a.indices.copy(), a.indptr.copy(), a.shape)


def _same(ours: Csr, ref) -> None:
    """Bitwise the same stored entries in the same order."""
    ref = ref.tocsr() if ref.format != "csr" else ref
    assert ours.shape == ref.shape
    np.testing.assert_array_equal(ours.indptr, ref.indptr)
    np.testing.assert_array_equal(ours.indices, ref.indices)
    assert ours.data.tobytes() == np.asarray(ref.data, dtype=float).tobytes()


@pytest.mark.parametrize("seed", range(4))
def test_products_bitwise_scipy(seed):
    rng = np.random.default_rng(seed)
    a, b = _random(rng, 23, 17, 0.3), _random(rng, 17, 29, 0.25)
    # integer values: many sums cancel to exactly 0, which scipy's product drops
    ai, bi = _random(rng, 23, 17, 0.4, integer=True), _random(rng, 17, 29, 0.4, integer=True)
    for x, y in ((a, b), (ai, bi)):
        product = _ours(x).matmat(_ours(y))
        _same(product, x @ y)   # scipy's csr @ csr: unsorted columns, same order
        assert product.nnz == (x @ y).nnz
    # a product with an unsorted left factor (scipy's intermediate of B^T S B)
    left = _ours(a).matmat(_ours(b))
    c = _random(rng, 29, 7, 0.3)
    _same(left.matmat(_ours(c)), (a @ b) @ c)
    x1, x2 = rng.normal(size=17), rng.normal(size=(17, 5))
    assert (_ours(a) @ x1).tobytes() == (a @ x1).tobytes()
    assert (_ours(a) @ x2).tobytes() == (a @ x2).tobytes()
    y1, y2 = rng.normal(size=23), rng.normal(size=(23, 4))
    assert _ours(a).rmatvec(y1).tobytes() == (a.T @ y1).tobytes()
    assert _ours(a).rmatvec(y2).tobytes() == (a.T @ y2).tobytes()
    _same(_ours(a).transpose(), a.T.tocsr())
    _same(left.transpose(), (a @ b).T.tocsr())   # from unsorted storage


@pytest.mark.parametrize("seed", range(4))
def test_congruence_bitwise_scipy(seed):
    """B^T S B as the assembly forms the reduced mass (scipy: (B.T @ S @ B).tocsr()), with
    B a reduction-like matrix (selections and relations with general coefficients)."""
    rng = np.random.default_rng(seed)
    nfull, nred = 40, 26
    s = _random(rng, nfull, nfull, 0.2)
    s = (s + s.T).tocsr()
    s.sort_indices()
    rows, cols, vals = [], [], []
    for i in range(nfull):
        for c in rng.choice(nred, size=rng.integers(1, 4), replace=False):
            rows.append(i)
            cols.append(c)
            vals.append(1.0 if rng.random() < 0.5 else rng.normal())
    b = sp.csr_matrix((vals, (rows, cols)), shape=(nfull, nred))
    b.sort_indices()
    reference = (b.T @ s @ b).tocsr()
    reference.sort_indices()
    ours = Csr.from_coo(rows, cols, vals, (nfull, nred))
    _same(ours, b)
    assert ours.selection_columns() is None
    _same(ours.congruence(_ours(s)), reference)
    # a selection (fixed coordinates dropped: each kept one a column of its own), the
    # shortcut of the congruence; S with stored zeros, which scipy's product drops
    kept = np.sort(rng.choice(nfull, size=nred, replace=False))
    select = sp.csr_matrix((np.ones(nred), (kept, np.arange(nred))), shape=(nfull, nred))
    s.data[::5] = 0.0
    reference = (select.T @ s @ select).tocsr()
    reference.sort_indices()
    ours = _ours(select)
    np.testing.assert_array_equal(ours.selection_columns()[kept], np.arange(nred))
    _same(ours.congruence(_ours(s)), reference)


def test_construction_selection_and_cleanup():
    rng = np.random.default_rng(7)
    rows, cols = rng.integers(0, 9, 60), rng.integers(0, 11, 60)
    keys = np.unique(rows * 11 + cols)
    r, c = keys // 11, keys % 11
    vals = rng.normal(size=len(keys))
    order = rng.permutation(len(keys))
    ref = sp.csr_matrix((vals[order], (r[order], c[order])), shape=(9, 11))
    ref.sort_indices()
    ours = Csr.from_coo(r[order], c[order], vals[order], (9, 11))
    _same(ours, ref)
    np.testing.assert_array_equal(ours.toarray(), ref.toarray())
    # duplicates summed (integers: any order gives the same sum)
    dup = Csr.from_coo(rows, cols, np.arange(60.0), (9, 11))
    np.testing.assert_array_equal(dup.toarray(),
                                  sp.csr_matrix((np.arange(60.0), (rows, cols)),
                                                shape=(9, 11)).toarray())
    pick = [4, 0, 4, 8]
    _same(ours.take_rows(pick), ref[pick])
    for columns in ([1, 2, 5, 6, 9, 10], [7, 0, 3]):   # sorted, and in any order
        picked = ours.take_columns(columns)
        np.testing.assert_array_equal(picked.indptr, ref[:, columns].indptr)
        np.testing.assert_array_equal(picked.indices, ref[:, columns].indices)
        assert picked.data.tobytes() == ref[:, columns].data.tobytes()
    ask_r, ask_c = rng.integers(0, 9, 30), rng.integers(0, 11, 30)
    np.testing.assert_array_equal(ours.values_at(ask_r, ask_c),
                                  np.asarray(ref[ask_r, ask_c]).ravel())
    zeroed = ours.copy()
    zeroed.data[::3] = 0.0
    ref_zeroed = _ours(ref).to_scipy()
    ref_zeroed.data[::3] = 0.0
    ref_zeroed.eliminate_zeros()
    zeroed.eliminate_zeros()
    _same(zeroed, ref_zeroed)
    pattern = Csr.structure(11, cols, rows % 11)
    ref_pattern = sp.csr_matrix((np.ones(60), (cols, rows % 11)), shape=(11, 11))
    ref_pattern.sum_duplicates()
    np.testing.assert_array_equal(pattern.indptr, ref_pattern.indptr)
    np.testing.assert_array_equal(pattern.indices, ref_pattern.indices)
    blocks = [np.eye(3), np.array([[0.0, 2.0], [3.0, 0.0]]), rng.normal(size=(3, 3))]
    _same(block_diagonal(blocks), sp.block_diag(blocks, format="csr"))
    a, b = _ours(ref), _ours(_random(rng, 9, 11, 0.3))
    assert a.max_abs_difference(b) == abs(a.to_scipy() - b.to_scipy()).max()
    assert a.max_abs() == abs(ref).max()
    with pytest.raises(ValueError, match="outside"):
        Csr.from_coo([0, 9], [0, 1], [1.0, 2.0], (9, 11))


def test_kron_scalar_against_scipy_kron():
    """Model.kron_scalar finds Mbar with M = kron(Mbar, I3) (scipy's kron builds M) and
    refuses a matrix that is not of that form."""
    from ancfdrv.system.model import kron_scalar

    rng = np.random.default_rng(3)
    mbar = _random(rng, 7, 7, 0.4)
    mbar = (mbar + mbar.T).tocsr()
    mbar.sort_indices()
    mass = sp.kron(mbar, sp.identity(3), format="csr")
    mass.sort_indices()
    found = kron_scalar(_ours(mass))
    expected = mbar.copy()
    expected.eliminate_zeros()
    _same(found, expected)
    _same(kron_scalar(mass), expected)   # a scipy matrix too (the modal analysis')
    broken = mass.tolil()
    broken[4, 4] += 1e-12                # one diagonal of a block differs
    assert kron_scalar(_ours(broken.tocsr())) is None
    coupled = mass.tolil()
    coupled[0, 1] = 1.0                  # x couples to y
    assert kron_scalar(_ours(coupled.tocsr())) is None
    assert kron_scalar(_ours(_random(rng, 8, 8, 0.5))) is None   # not 3-vectors


def test_turned_difference_against_dense():
    """The solver-frame check's max |A - U B U^T| (U block-diagonal 3 x 3 rotations)
    against the dense product."""
    from ancfdrv.system.model import _turned_difference

    rng = np.random.default_rng(5)
    nvec = 6
    u = np.array([np.linalg.qr(rng.normal(size=(3, 3)))[0] for _ in range(nvec)])
    b = _random(rng, 3 * nvec, 3 * nvec, 0.3)
    dense_u = sp.block_diag(list(u)).toarray()
    turned = dense_u @ b.toarray() @ dense_u.T
    a = sp.csr_matrix(np.where(np.abs(turned) > 0.5, turned, 0.0))   # part of U B U^T
    expected = np.abs(a.toarray() - turned).max()
    assert expected > 0.1
    assert _turned_difference(_ours(a), _ours(b), u) == pytest.approx(expected, rel=1e-12)
    exact = sp.csr_matrix(turned)
    assert _turned_difference(_ours(exact), _ours(b), u) < 1e-14 * np.abs(turned).max()
