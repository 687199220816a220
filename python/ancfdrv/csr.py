"""Compressed sparse row matrices in plain numpy arrays: what the model build, a dynamic run
and its output need of sparse matrices (the patterns, the reduction q = B e + q0, the mass
matrix, the XDMF point map) without importing scipy.sparse, whose import chain (numpy.testing,
unittest, numpy.f2py, ...) is ~19 MB of a run's peak memory and ~0.1 s (issue 23).

The arithmetic repeats scipy's sparsetools loops term by term: each product is formed from
the same two factors and every sum starts from 0 and adds its terms in the order scipy adds
them (``numpy.add.at`` and the per-position loops below are sequential). Results are
therefore bitwise scipy.sparse's; ``tests/test_csr.py`` checks that against scipy.sparse
itself. :meth:`Csr.to_scipy` gives a scipy matrix (scipy imported then), for the public
functions that return one (``Model.mass_matrix``, ``Model.stiffness_matrix``).
"""
from __future__ import annotations

import numpy as np


def unique_keys(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """np.unique(keys, return_index=True, return_inverse=True) by one stable sort (numpy's
    default sort and np.unique measured 10-30x slower on the assembly's nearly sorted keys)."""
    keys = np.asarray(keys, dtype=np.int64)
    perm = keys.argsort(kind="stable")
    ordered = keys[perm]
    new = np.empty(len(keys), dtype=bool)
    new[:1] = True
    np.not_equal(ordered[1:], ordered[:-1], out=new[1:])
    starts = new.nonzero()[0]
    inverse = np.empty(len(keys), dtype=np.int64)
    inverse[perm] = new.cumsum() - 1
    return ordered[starts], perm[starts], inverse


def sorted_unique(keys: np.ndarray) -> np.ndarray:
    """np.unique(keys) of integers (flattened, as int64) by a stable sort. Also where speed
    does not matter: numpy >= 2.3 imports numpy.ma for a plain ``np.unique(x)`` (to ask
    whether x is masked), 1.3 MB of a run's peak memory (issue 23)."""
    ordered = np.asarray(keys, dtype=np.int64).ravel().copy()   # (np.sort: a copy, sorted)
    ordered.sort(kind="stable")
    keep = np.empty(len(ordered), dtype=bool)
    keep[:1] = True
    np.not_equal(ordered[1:], ordered[:-1], out=keep[1:])
    return ordered[keep]


class Csr:
    """A sparse matrix in CSR form: ``indptr`` (nrow + 1), ``indices`` and ``data`` (nnz),
    0-based, int64 indices. Column order within a row is whatever the producing operation
    left (sorted after :meth:`from_coo`, :meth:`transpose` and :meth:`sort_indices`)."""

    __slots__ = ("shape", "indptr", "indices", "data", "_term_plan")

    def __init__(self, data, indices, indptr, shape: tuple[int, int]) -> None:
        self.data = np.asarray(data, dtype=float)
        self.indices = np.asarray(indices, dtype=np.int64)
        self.indptr = np.asarray(indptr, dtype=np.int64)
        self.shape = (int(shape[0]), int(shape[1]))
        self._term_plan: tuple | None = None
        if len(self.indptr) != self.shape[0] + 1 or len(self.indices) != len(self.data) \
                or (len(self.indptr) and self.indptr[-1] != len(self.data)):
            raise ValueError(f"inconsistent CSR arrays for shape {self.shape}: indptr "
                             f"{len(self.indptr)}, indices {len(self.indices)}, data "
                             f"{len(self.data)}")

    # -- construction ----------------------------------------------------------------------
    @classmethod
    def from_coo(cls, rows, cols, vals, shape: tuple[int, int]) -> "Csr":
        """From triplets: columns sorted within each row, duplicates summed in the order
        given (scipy's ``csr_matrix((vals, (rows, cols)))`` with ``sort_indices``; scipy's own
        order of summing duplicates is unspecified, so build from unique entries where bits
        matter)."""
        n, m = int(shape[0]), int(shape[1])
        r = np.asarray(rows, dtype=np.int64).ravel()
        c = np.asarray(cols, dtype=np.int64).ravel()
        v = np.asarray(vals, dtype=float).ravel()
        if len(r) and (r.min() < 0 or r.max() >= n or c.min() < 0 or c.max() >= m):
            raise ValueError(f"an entry lies outside the {n} x {m} matrix")
        keys = r * m + c
        unique, first, inverse = unique_keys(keys)
        if len(unique) == len(keys):   # no duplicates: the values in key order
            data = v[first]
        else:
            data = np.zeros(len(unique))
            np.add.at(data, inverse, v)
        indptr = np.zeros(n + 1, dtype=np.int64)
        np.bincount(unique // m if m else unique, minlength=n).cumsum(out=indptr[1:])
        return cls(data, unique % m if m else unique, indptr, (n, m))

    @classmethod
    def structure(cls, n: int, rows, cols) -> "Csr":
        """The n x n pattern of entries (rows, cols) (duplicates merged, columns sorted) with
        values 1."""
        m = int(n)
        keys = sorted_unique(np.asarray(rows, dtype=np.int64) * m + np.asarray(cols, dtype=np.int64))
        indptr = np.zeros(m + 1, dtype=np.int64)
        np.bincount(keys // m, minlength=m).cumsum(out=indptr[1:])
        return cls(np.ones(len(keys)), keys % m, indptr, (m, m))

    @classmethod
    def from_scipy(cls, matrix) -> "Csr":
        """The CSR arrays of a scipy sparse matrix (converted to CSR, duplicates summed and
        columns sorted as scipy does)."""
        m = matrix.tocsr(copy=True)
        m.sum_duplicates()
        m.sort_indices()
        return cls(m.data, m.indices, m.indptr, m.shape)

    # -- properties --------------------------------------------------------------------------
    @property
    def nnz(self) -> int:
        return len(self.data)

    def row_index(self) -> np.ndarray:
        """The row of every stored entry."""
        indptr = self.indptr   # (indptr[1:] - indptr[:-1]: np.diff without its overhead)
        return np.arange(self.shape[0], dtype=np.int64).repeat(indptr[1:] - indptr[:-1])

    def copy(self) -> "Csr":
        return Csr(self.data.copy(), self.indices.copy(), self.indptr.copy(), self.shape)

    def toarray(self) -> np.ndarray:
        out = np.zeros(self.shape)
        np.add.at(out, (self.row_index(), self.indices), self.data)
        return out

    def to_scipy(self):
        """A scipy ``csr_matrix`` with its own copy of the arrays (imports scipy.sparse)."""
        import scipy.sparse as sp
        return sp.csr_matrix((self.data.copy(), self.indices.copy(), self.indptr.copy()),
                             shape=self.shape)

    def __repr__(self) -> str:
        return f"<Csr {self.shape[0]} x {self.shape[1]}, {self.nnz} stored entries>"

    # -- in-place clean-up (scipy's eliminate_zeros and sort_indices) ---------------------------
    def eliminate_zeros(self) -> None:
        """Drop stored zeros, keeping the order of the others."""
        keep = self.data != 0
        if keep.all():
            return
        counts = np.bincount(self.row_index()[keep], minlength=self.shape[0])
        self.indptr = np.concatenate([[0], counts.cumsum()]).astype(np.int64)
        self.indices, self.data = self.indices[keep], self.data[keep]

    def sort_indices(self) -> None:
        """Columns ascending within each row (stable)."""
        keys = self.row_index() * self.shape[1] + self.indices
        if (keys[1:] < keys[:-1]).any():
            order = keys.argsort(kind="stable")
            self.indices, self.data = self.indices[order], self.data[order]

    # -- selection ---------------------------------------------------------------------------
    def take_rows(self, rows) -> "Csr":
        """The matrix of rows ``rows`` (in that order; scipy's ``A[rows]``)."""
        rows = np.asarray(rows, dtype=np.int64)
        start, stop = self.indptr[rows], self.indptr[rows + 1]
        counts = stop - start
        indptr = np.concatenate([[0], counts.cumsum()]).astype(np.int64)
        at = np.repeat(start - indptr[:-1], counts) + np.arange(indptr[-1])
        return Csr(self.data[at], self.indices[at], indptr, (len(rows), self.shape[1]))

    def take_columns(self, cols) -> "Csr":
        """The matrix of the distinct columns ``cols`` (renumbered in that order; each row's
        entries in storage order: scipy's ``A[:, cols]``)."""
        cols = np.asarray(cols, dtype=np.int64)
        where = np.full(self.shape[1], -1, dtype=np.int64)
        where[cols] = np.arange(len(cols))
        if len(sorted_unique(cols)) != len(cols):
            raise ValueError("take_columns: the columns must be distinct")
        new = where[self.indices]
        keep = new >= 0
        counts = np.bincount(self.row_index()[keep], minlength=self.shape[0])
        indptr = np.concatenate([[0], counts.cumsum()]).astype(np.int64)
        return Csr(self.data[keep], new[keep], indptr, (self.shape[0], len(cols)))

    def values_at(self, rows, cols) -> np.ndarray:
        """Entries (rows, cols), 0 where none is stored (scipy's ``A[rows, cols]`` for a matrix
        with sorted columns and no duplicates)."""
        ncol = self.shape[1]
        keys = self.row_index() * ncol + self.indices
        wanted = np.asarray(rows, dtype=np.int64) * ncol + np.asarray(cols, dtype=np.int64)
        if not len(keys):
            return np.zeros(wanted.shape)
        pos = np.minimum(keys.searchsorted(wanted), len(keys) - 1)
        return np.where(keys[pos] == wanted, self.data[pos], 0.0)

    # -- products (scipy's loops) ---------------------------------------------------------------
    def transpose(self) -> "Csr":
        """A^T in CSR: scipy's csr_tocsc (each column's entries in storage order)."""
        order = self.indices.argsort(kind="stable")
        indptr = np.zeros(self.shape[1] + 1, dtype=np.int64)
        np.bincount(self.indices, minlength=self.shape[1]).cumsum(out=indptr[1:])
        return Csr(self.data[order], self.row_index()[order], indptr,
                   (self.shape[1], self.shape[0]))

    @property
    def T(self) -> "Csr":  # noqa: N802 - numpy's and scipy's name
        return self.transpose()

    def __matmul__(self, other):
        if isinstance(other, Csr):
            return self.matmat(other)
        return self.matvec(other)

    def matvec(self, x) -> np.ndarray:
        """A x for x (ncol,) or (ncol, k): scipy's csr_matvec / csr_matvecs (each row's terms
        added to 0 in storage order)."""
        x = np.asarray(x)
        if x.shape[0] != self.shape[1]:
            raise ValueError(f"dimension mismatch: {self.shape} @ {x.shape}")
        dtype = np.result_type(self.data, x)
        out = np.zeros((self.shape[0],) + x.shape[1:], dtype=dtype)
        if not self.nnz:
            return out
        products = (self.data.reshape((-1,) + (1,) * (x.ndim - 1)) * x[self.indices])
        rows, order, bounds = self.term_plan()
        for k in range(len(bounds) - 1):   # the k-th term of every row that has one
            at = order[bounds[k]:bounds[k + 1]]
            out[rows[at]] += products[at]
        return out

    def term_plan(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(row of every entry, entries grouped by their place k in their row, where each k's
        group starts): the order in which :meth:`matvec` adds the terms, so each row's sum is
        formed in storage order in O(nnz) work. Kept while the structure arrays are the same
        objects (every method that changes the structure assigns new arrays)."""
        plan = self._term_plan
        if plan is not None and plan[0] is self.indptr and plan[1] is self.indices:
            return plan[2]
        rows = self.row_index()
        local = np.arange(self.nnz) - self.indptr[rows]
        order = local.argsort(kind="stable")
        bounds = np.zeros(int(local.max(initial=-1)) + 2, dtype=np.int64)
        np.bincount(local, minlength=len(bounds) - 1).cumsum(out=bounds[1:])
        self._term_plan = (self.indptr, self.indices, (rows, order, bounds))
        return rows, order, bounds

    def rmatvec(self, x) -> np.ndarray:
        """A^T x for x (nrow,) or (nrow, k): scipy's ``A.T @ x`` (csc_matvec: rows of A in
        order, each entry added to its column's sum)."""
        x = np.asarray(x)
        if x.shape[0] != self.shape[0]:
            raise ValueError(f"dimension mismatch: {self.shape}^T @ {x.shape}")
        out = np.zeros((self.shape[1],) + x.shape[1:], dtype=np.result_type(self.data, x))
        products = self.data.reshape((-1,) + (1,) * (x.ndim - 1)) * x[self.row_index()]
        np.add.at(out, self.indices, products)
        return out

    def matmat(self, other: "Csr") -> "Csr":
        """A B: scipy's csr_matmat. Row i's sums run over A's row i in storage order (each
        term A_ij B_jk over B's row j in storage order), start from 0, and sums that end at 0
        are dropped; a row's columns come in the reverse order of their first touch (scipy's
        linked list: unsorted)."""
        if self.shape[1] != other.shape[0]:
            raise ValueError(f"dimension mismatch: {self.shape} @ {other.shape}")
        n, m = self.shape[0], other.shape[1]
        counts = np.diff(other.indptr)[self.indices]          # terms of each A entry
        total = int(counts.sum())
        if total == 0:
            return Csr(np.zeros(0), np.zeros(0, np.int64), np.zeros(n + 1, np.int64), (n, m))
        entry = np.repeat(np.arange(self.nnz), counts)          # the A entry of each term
        at = np.arange(total) + np.repeat(other.indptr[self.indices] - (np.cumsum(counts) - counts),
                                          counts)              # its B entry
        products = self.data[entry] * other.data[at]
        keys = self.row_index()[entry] * m + other.indices[at]
        # terms grouped by output entry (stable: each group in scipy's order of the terms)
        unique, first, group = unique_keys(keys)
        sums = np.zeros(len(unique))
        np.add.at(sums, group, products)                      # sequential: scipy's order
        rows = unique // m
        # per row: the last touched column first (scipy's linked list); then drop zero sums
        order = (rows * (total + 1) + (total - first)).argsort(kind="stable")
        order = order[sums[order] != 0]
        indptr = np.zeros(n + 1, dtype=np.int64)
        np.bincount(rows[order], minlength=n).cumsum(out=indptr[1:])
        return Csr(sums[order], unique[order] % m, indptr, (n, m))

    def congruence(self, inner: "Csr") -> "Csr":
        """B^T S B with B = self (scipy's ``(B.T @ S @ B).tocsr()``: the same two products in
        the same orders, columns sorted)."""
        selection = self.selection_columns()
        if selection is not None:
            # every sum is one exact term 1 S_ij 1: S on the selected rows and columns,
            # without its zeros (scipy drops sums that are 0)
            rows, cols = selection[inner.row_index()], selection[inner.indices]
            keep = (rows >= 0) & (cols >= 0) & (inner.data != 0)
            if inner.canonical():
                return Csr.from_coo(rows[keep], cols[keep], inner.data[keep],
                                    (self.shape[1], self.shape[1]))
        # B.T is B's arrays as CSC; scipy multiplies CSC matrices as the CSR products of
        # their transposes: (B^T S)^T = S^T B, then (B^T S B)^T = B^T (S^T B)
        left = inner.transpose().matmat(self)
        return self.transpose().matmat(left).transpose()

    def canonical(self) -> bool:
        """Columns strictly ascending within every row (sorted, no duplicates)."""
        indices, rows = self.indices, self.row_index()
        steps = indices[1:] - indices[:-1]
        return bool((steps[rows[1:] == rows[:-1]] > 0).all())

    def selection_columns(self) -> np.ndarray | None:
        """When this matrix selects (every column one stored 1, every row at most one entry):
        the column of each row (-1: none); else None."""
        indptr = self.indptr
        if (self.data != 1.0).any() or (indptr[1:] - indptr[:-1] > 1).any() \
                or (np.bincount(self.indices, minlength=self.shape[1]) != 1).any():
            return None
        column = np.full(self.shape[0], -1, dtype=np.int64)
        column[self.row_index()] = self.indices
        return column

    def max_abs(self) -> float:
        return float(np.abs(self.data).max(initial=0.0))

    def max_abs_difference(self, other: "Csr") -> float:
        """max |A - B| over the entries (no duplicates in either)."""
        ncol = self.shape[1]
        keys = np.concatenate([self.row_index() * ncol + self.indices,
                               other.row_index() * ncol + other.indices])
        unique, _, inverse = unique_keys(keys)
        difference = np.zeros(len(unique))
        np.add.at(difference, inverse, np.concatenate([self.data, -other.data]))
        return float(np.abs(difference).max(initial=0.0))


def block_diagonal(blocks: list[np.ndarray]) -> Csr:
    """The block-diagonal matrix of dense square blocks, every entry of a block stored
    (scipy's ``block_diag(blocks, format='csr')``)."""
    rows, cols, vals, at = [], [], [], 0
    for block in blocks:
        r, c = np.indices(block.shape)
        rows.append(r.ravel() + at)
        cols.append(c.ravel() + at)
        vals.append(np.asarray(block, dtype=float).ravel())
        at += block.shape[0]
    if not blocks:
        return Csr(np.zeros(0), np.zeros(0, np.int64), np.zeros(1, np.int64), (0, 0))
    return Csr.from_coo(np.concatenate(rows), np.concatenate(cols), np.concatenate(vals),
                        (at, at))
