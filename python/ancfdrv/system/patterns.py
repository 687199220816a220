"""Sparse patterns of the assembled matrices and the elimination of linear constraints.

:class:`Pattern` is a CSR pattern (sorted columns) built once from coupling blocks (element
dofs, rigid bodies, contact pairs) with the scatter map of element matrices into it.
:func:`eliminate` turns time-independent linear equations into q = B e + q0 (seed 003 eqs.
34-37), choosing a dependent coordinate per equation after substituting the earlier ones, so
chains and closed loops need no special case and an equation the others already imply is
recognised as redundant. :func:`reduction_plan` forms the plan of B^T S B on the reduced
pattern, which the kernel applies to every assembled matrix. Sparse matrices here are
:class:`~ancfdrv.csr.Csr` (numpy arrays, scipy's arithmetic): a dynamic run never imports
scipy.sparse (issue 23, a run's memory).
"""
from __future__ import annotations

import math

from dataclasses import field

import numpy as np

from ..records import record
from ..csr import Csr
from ..errors import InputError
from .expressions import Scalar


class Pattern:
    """CSR pattern of an n x n matrix (0-based, sorted columns)."""

    #: a pattern of at most this many entries keeps its entries' rows and sorted keys once
    #: formed (a small model's build reads them several times: ~20 us of the 5-node
    #: pendulum's 1.2 ms); a larger one forms them on each use. A model keeps its patterns
    #: for its whole life, and these two arrays are 8 bytes per entry each (1.3 MB of the
    #: 512-element cantilever's peak memory; issue 23), read only while the model is built
    #: and by a static solve.
    KEEP_ENTRIES = 4096

    def __init__(self, n: int, row_ptr: np.ndarray, col_index: np.ndarray) -> None:
        self.n = n
        self.row_ptr = np.asarray(row_ptr, dtype=np.int64)
        self.col_index = np.asarray(col_index, dtype=np.int64)
        self.nnz = len(self.col_index)
        self._rows: np.ndarray | None = None
        self._keys: np.ndarray | None = None

    @property
    def rows(self) -> np.ndarray:
        """The row of every entry (see :data:`KEEP_ENTRIES`)."""
        rows = self._rows
        if rows is None:
            rows = np.repeat(np.arange(self.n), self.row_ptr[1:] - self.row_ptr[:-1])
            if self.nnz <= self.KEEP_ENTRIES:
                self._rows = rows
        return rows

    def _sorted_keys(self) -> np.ndarray:
        """row * n + col of every entry, ascending (see :data:`KEEP_ENTRIES`)."""
        keys = self._keys
        if keys is None:
            keys = self.rows * self.n + self.col_index
            if self.nnz <= self.KEEP_ENTRIES:
                self._keys = keys
        return keys

    @classmethod
    def from_blocks(cls, n: int, blocks: list[np.ndarray]) -> "Pattern":
        """Every pair of dofs within a block (an array of dofs, or of columns of dofs) is
        coupled; the diagonal is always present."""
        rows, cols = [np.arange(n)], [np.arange(n)]
        for block in blocks:
            b = np.asarray(block)
            if b.ndim == 1:
                b = b[:, None]
            b = b[:, (b >= 0).all(axis=0)] if b.size else b
            k = b.shape[0]
            rows.append(np.repeat(b, k, axis=0).T.ravel())
            cols.append(np.concatenate([b] * k).T.ravel())   # (np.tile(b, (k, 1)))
        structure = Csr.structure(n, np.concatenate(rows), np.concatenate(cols))
        return cls(n, structure.indptr, structure.indices)

    def positions(self, rows, cols) -> np.ndarray:
        """Positions of entries (rows, cols) in the values array (-1 when absent)."""
        wanted = np.asarray(rows, dtype=np.int64) * self.n + np.asarray(cols, dtype=np.int64)
        keys = self._sorted_keys()
        pos = np.minimum(keys.searchsorted(wanted), len(keys) - 1)
        return np.where(keys[pos] == wanted, pos, -1)

    def scatter(self, dofs: np.ndarray) -> np.ndarray:
        """(nde, nde, nel) positions of element-matrix entries (a, b) of elements with dofs
        (nde, nel), 1-based (the kernel's layout; 0 = absent)."""
        nde, nel = dofs.shape
        rows = np.empty((nde, nde, nel), dtype=dofs.dtype)   # (np.broadcast_to's values)
        rows[...] = dofs[:, None, :]
        cols = np.empty((nde, nde, nel), dtype=dofs.dtype)
        cols[...] = dofs[None, :, :]
        pos = self.positions(rows.ravel(), cols.ravel()).reshape(nde, nde, nel)
        if (pos < 0).any():
            raise AssertionError("an element entry is missing from the pattern")
        return pos + 1

    def values_of(self, matrix) -> np.ndarray:
        """Values of ``matrix`` (a :class:`~ancfdrv.csr.Csr` or scipy sparse matrix) on this
        pattern (entries outside it must be zero)."""
        m = matrix if isinstance(matrix, Csr) else Csr.from_scipy(matrix)
        return m.values_at(self.rows, self.col_index)

    def to_csr(self, values: np.ndarray) -> Csr:
        """The matrix of ``values`` on this pattern, with its own copy of the pattern."""
        return Csr(np.array(values, dtype=float), self.col_index.copy(), self.row_ptr.copy(),
                   (self.n, self.n))

    def to_scipy(self, values: np.ndarray):
        """A scipy CSR matrix with its own copy of the pattern (imports scipy.sparse)."""
        import scipy.sparse as sp
        return sp.csr_matrix((np.array(values, dtype=float), self.col_index.copy(),
                              self.row_ptr.copy()), shape=(self.n, self.n))

    def bandwidth(self) -> int:
        return int(np.abs(self.rows - self.col_index).max(initial=0))


@record(eq=False, repr=False)
class Reduction:
    """q = B e + q0 and the plan of B^T S B (source: full-pattern positions, target: reduced
    pattern positions, coefficient)."""

    matrix: Csr                    # B (nfull x nred; .to_scipy() for a scipy matrix)
    offset: np.ndarray             # q0 (nfull)
    independent: np.ndarray        # full index of each reduced coordinate
    pattern: Pattern               # of B^T S B
    plan_source: np.ndarray
    plan_target: np.ndarray
    plan_coef: np.ndarray
    relations: dict[int, Scalar] = field(default_factory=dict)
    #: the full index of each reduced coordinate when B only selects them (every relation
    #: a constant: :func:`_selection_plan`), else None
    selects: np.ndarray | None = None

    def expand(self, x: np.ndarray, with_offset: bool = True) -> np.ndarray:
        """Full coordinates (or, without the offset, velocities) from reduced ones; x may be
        (nred,) or (nt, nred)."""
        if self.selects is not None:
            # B x placed directly: each selected row's sum 0 + 1 x (as the product forms
            # it: a -0.0 becomes 0.0), the others 0, then the offset
            x = np.asarray(x)
            if x.shape[-1] != len(self.selects):
                raise ValueError(f"dimension mismatch: {self.matrix.shape} @ {x.T.shape}")
            full = np.zeros(x.shape[:-1] + (len(self.offset),),
                            dtype=np.result_type(self.matrix.data, x))
            full[..., self.selects] = x
            full += self.offset if with_offset else 0.0
            return full
        full = self.matrix.matvec(np.asarray(x).T).T
        return full + self.offset if with_offset else full

    def expand_columns(self, x: np.ndarray, columns: np.ndarray) -> np.ndarray:
        """``expand(x)[..., columns]`` (with the offset) without forming the other full
        coordinates: the same operations on the columns asked for, so bit for bit the same
        values (the selected ones x + q0, the others 0 + q0; with a general B the rows
        ``columns`` of B, each summed from 0 in storage order as :meth:`Csr.matvec` sums
        it, plus q0), column-major. For readers of a few full coordinates at every row (the joints'
        reactions): an expansion of every row costs ~15 instructions per entry."""
        x = np.asarray(x)
        columns = np.asarray(columns, dtype=np.int64)
        if x.shape[-1] != self.matrix.shape[1]:
            raise ValueError(f"dimension mismatch: {self.matrix.shape} @ {x.T.shape}")
        if self.selects is not None:
            where = np.full(len(self.offset), -1, dtype=np.int64)
            where[self.selects] = np.arange(len(self.selects))
            source = where[columns]
            chosen = np.flatnonzero(source >= 0)
            # column-major (its transpose contiguous: readers take whole columns)
            out = np.zeros((len(columns),) + x.shape[:-1][::-1],
                           dtype=np.result_type(self.matrix.data, x)).T
            out[..., chosen] = x[..., source[chosen]]
            out += self.offset[columns]
            return out
        b = self.matrix
        starts, stops = b.indptr[columns], b.indptr[columns + 1]
        counts = stops - starts
        take = np.repeat(starts - np.concatenate([[0], np.cumsum(counts)[:-1]]), counts) \
            + np.arange(int(counts.sum()))
        indptr = np.concatenate([[0], np.cumsum(counts)])
        rows = Csr(b.data[take], b.indices[take], indptr, (len(columns), b.shape[1]))
        return rows.matvec(x.T).T + self.offset[columns]

    def reduce(self, full: np.ndarray) -> np.ndarray:
        """B^T Q (eq. 37)."""
        return self.matrix.rmatvec(full)


@record(eq=False)
class Elimination:
    """The outcome of :func:`eliminate`: relations q_d = c + sum a_j q_j over independent
    coordinates, the dropped (redundant) equations' names."""

    relations: dict[int, Scalar]
    redundant: list[str]

    def substitute(self, expr: Scalar) -> Scalar:
        """expr over independent coordinates only."""
        out = Scalar({}, expr.const)
        for dof, coef in expr.terms.items():
            if dof in self.relations:
                out = out + self.relations[dof].scaled(coef)
            else:
                out = out + Scalar({dof: coef}, 0.0)
        return out


def eliminate(equations, q0: np.ndarray) -> Elimination:
    """Relations from linear equations (in their order): each equation, written over the
    coordinates still independent, makes one of them dependent (its preferred ones first,
    else the largest coefficient). An equation that reduces to a constant is redundant when
    the constant vanishes and contradicts the others otherwise (InputError naming it)."""
    scale = max(1.0, float(np.abs(q0).max(initial=0.0)))
    result = Elimination({}, [])
    users: dict[int, set[int]] = {}   # independent dof -> dependents whose relation uses it
    for eq in equations:
        violation = eq.expr.value(q0)
        if abs(violation) > 1e-9 * scale:
            raise InputError(f"{eq.name}: the initial configuration violates this joint "
                             f"equation by {violation:.3e} (check the points and bodies)")
        if len(eq.expr.terms) == 1:
            # a · q_d + c = 0 (a planar fix) on a coordinate still independent that no
            # relation uses: the steps below give q_d = -(c + 0) / a (the substitution
            # adds c to 0), made directly
            (dof, a), = eq.expr.terms.items()
            if dof not in result.relations and dof not in users and a != 0.0 \
                    and math.isfinite(a):
                result.relations[dof] = Scalar({}, -(eq.expr.const + 0.0) / a)
                continue
        s = result.substitute(eq.expr)
        big = max((abs(c) for c in s.terms.values()), default=0.0)
        s = Scalar({d: c for d, c in s.terms.items() if abs(c) > 1e-12 * big}, s.const)
        if not s.terms:
            if abs(s.const) <= 1e-9 * scale:
                result.redundant.append(eq.name)
                continue
            raise InputError(f"{eq.name}: contradicts the other joint equations (off by "
                             f"{s.const:.3e})")
        choice = next((d for d in eq.prefer if d in s.terms and abs(s.terms[d]) >= 1e-6 * big),
                      None)
        if choice is None:
            choice = max(s.terms, key=lambda d: (abs(s.terms[d]), -d))
        coef = s.terms[choice]
        relation = Scalar({d: -c / coef for d, c in s.terms.items() if d != choice},
                          -s.const / coef)
        for dependent in users.pop(choice, set()):  # substitute into the relations using it
            old = result.relations[dependent]
            terms = dict(old.terms)
            a = terms.pop(choice, 0.0)  # (0: a substitution cancelled the term)
            if a == 0.0:
                continue
            new = Scalar(terms, old.const) + relation.scaled(a)
            result.relations[dependent] = new
            for d in new.terms:
                users.setdefault(d, set()).add(dependent)
        result.relations[choice] = relation
        for d in relation.terms:
            users.setdefault(d, set()).add(choice)
    return result


def _entry_pairs(entries: np.ndarray, f_rows: np.ndarray, f_cols: np.ndarray, ptr: np.ndarray,
                 counts: np.ndarray, cols: np.ndarray, vals: np.ndarray):
    """For the full entries (i, j) = (f_rows[k], f_cols[k]), k in ``entries`` (in that order):
    every pair of a B entry (a) in row i and one (c) in row j, a-major, as (k, column of a,
    column of c, B_ia B_jc); B's rows given by ptr, counts, cols, vals."""
    per = counts[f_rows[entries]] * counts[f_cols[entries]]
    source = np.repeat(entries, per)
    local = np.arange(len(source)) - np.repeat(np.cumsum(per) - per, per)
    width = counts[f_cols[source]]
    at_a = ptr[f_rows[source]] + local // np.maximum(width, 1)
    at_c = ptr[f_cols[source]] + local % np.maximum(width, 1)
    return source, cols[at_a], cols[at_c], vals[at_a] * vals[at_c]


def reduction_plan(nfull: int, elimination: Elimination, q0: np.ndarray,
                   full_pattern: Pattern) -> Reduction:
    """B, q0 (checked against the initial configuration), the reduced pattern (structure of
    B^T P B plus the diagonal) and the plan forming B^T S B on it."""
    if all(not relation.terms for relation in elimination.relations.values()):
        return _selection_plan(nfull, elimination, q0, full_pattern)
    return _general_plan(nfull, elimination, q0, full_pattern)


def _selection_plan(nfull: int, elimination: Elimination, q0: np.ndarray,
                    full_pattern: Pattern) -> Reduction:
    """:func:`_general_plan` where every relation is a constant (the planar fixes: B
    selects the independent coordinates), its arrays made directly: B's one 1 per
    independent row, the full pattern's entries between independent coordinates (each
    one pair of B entries, coefficient 1) in the full pattern's order."""
    relations = elimination.relations
    dependent = np.zeros(nfull, dtype=bool)
    dependent[list(relations)] = True
    independent = (~dependent).nonzero()[0].astype(np.int64)
    nred = len(independent)
    column = -np.ones(nfull, dtype=np.int64)
    column[independent] = np.arange(nred)
    offset = np.zeros(nfull)
    fixed = np.array(list(relations), dtype=np.int64)
    offset[fixed] = [relations[int(i)].const for i in fixed]
    indptr = np.zeros(nfull + 1, dtype=np.int64)
    (~dependent).cumsum(out=indptr[1:])
    b = Csr(np.ones(nred), np.arange(nred), indptr, (nfull, nred))
    mismatch = np.abs(offset[fixed] - q0[fixed])
    if mismatch.max(initial=0.0) > 1e-9 * max(1.0, np.abs(q0).max(initial=0.0)):
        raise AssertionError(f"the reduction misses the initial configuration by "
                             f"{mismatch.max():.3e}")
    f_rows, f_cols = full_pattern.rows, full_pattern.col_index
    source = (~dependent[f_rows] & ~dependent[f_cols]).nonzero()[0].astype(np.int64)
    pair_a, pair_c = column[f_rows[source]], column[f_cols[source]]
    diagonal = np.arange(nred)
    reduced = Csr.structure(nred, np.concatenate([pair_a, diagonal]),
                            np.concatenate([pair_c, diagonal]))
    pattern = Pattern(nred, reduced.indptr, reduced.indices)
    target = pattern.positions(pair_a, pair_c)
    if (target < 0).any():
        raise AssertionError("reduced pattern misses an entry of B^T S B")
    return Reduction(b, offset, independent, pattern, source, target, np.ones(len(source)),
                     relations, selects=independent)


def _general_plan(nfull: int, elimination: Elimination, q0: np.ndarray,
                  full_pattern: Pattern) -> Reduction:
    """:func:`reduction_plan` for any relations."""
    relations = elimination.relations
    independent = np.array([i for i in range(nfull) if i not in relations], dtype=np.int64)
    column = -np.ones(nfull, dtype=np.int64)
    column[independent] = np.arange(len(independent))
    rows, cols, vals = [], [], []
    offset = np.zeros(nfull)
    for i in range(nfull):
        if i in relations:
            offset[i] = relations[i].const
            for d, c in relations[i].terms.items():
                rows.append(i)
                cols.append(column[d])
                vals.append(c)
        else:
            rows.append(i)
            cols.append(column[i])
            vals.append(1.0)
    b = Csr.from_coo(rows, cols, vals, (nfull, len(independent)))
    mismatch = np.abs(b @ q0[independent] + offset - q0)
    if mismatch.max(initial=0.0) > 1e-9 * max(1.0, np.abs(q0).max(initial=0.0)):
        raise AssertionError(f"the reduction misses the initial configuration by "
                             f"{mismatch.max():.3e}")
    # the reduced pattern: the structure of |B|^T P |B| (every pair of B's nonzeros in rows
    # i and j of a full entry (i, j)) plus the diagonal
    f_rows, f_cols = full_pattern.rows, full_pattern.col_index
    nonzero = b.data != 0
    nz_counts = np.bincount(b.row_index()[nonzero], minlength=nfull)
    _, pair_a, pair_c, _ = _entry_pairs(np.arange(full_pattern.nnz), f_rows, f_cols,
                                        np.concatenate([[0], np.cumsum(nz_counts)]), nz_counts,
                                        b.indices[nonzero], b.data[nonzero])
    nred = len(independent)
    diagonal = np.arange(nred)
    reduced = Csr.structure(nred, np.concatenate([pair_a, diagonal]),
                            np.concatenate([pair_c, diagonal]))
    pattern = Pattern(nred, reduced.indptr, reduced.indices)
    # plan: every full entry (i, j) and every pair of B entries in rows i and j; the entries
    # whose rows hold one B entry each first, then the others (the order the kernel sums in)
    counts = np.diff(b.indptr)
    simple = (counts[f_rows] == 1) & (counts[f_cols] == 1)
    order = np.concatenate([np.nonzero(simple)[0],
                            np.nonzero(~simple & (counts[f_rows] > 0) & (counts[f_cols] > 0))[0]])
    source, pair_a, pair_c, coef = _entry_pairs(order, f_rows, f_cols, b.indptr, counts,
                                                b.indices, b.data)
    target = pattern.positions(pair_a, pair_c)
    if (target < 0).any():
        raise AssertionError("reduced pattern misses an entry of B^T S B")
    return Reduction(b, offset, independent, pattern, source, target, coef, relations)
