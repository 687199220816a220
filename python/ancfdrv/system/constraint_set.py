"""The constraints that keep Lagrange multipliers, in the kernel's layout over the
independent coordinates e (``fortran/src/system/constraints.f90``): per constraint a kind,
a drive, eight parameters and six operands x_s = c_s + sum a_k e[d_k].

Evaluation (values, gradients and Hessians with respect to the operands, Phi_t, Phi_tt,
gamma) is the kernel's; :meth:`ConstraintSet.jacobian` and :meth:`hessian_triplets` map
them to the coordinates for the static solvers.
"""
from __future__ import annotations

from dataclasses import field

import numpy as np

from ..records import record
from ..csr import sorted_unique
from ..errors import InputError
from ..kernel import _kernel, _state, constraint_arrays


@record(eq=False)
class ConstraintSet:
    """Constraints in the kernel's layout; ``dependent`` holds per constraint the coordinate
    the split iteration treats as dependent (the set N1 of seed 000, eq. 40)."""

    kinds: list[int] = field(default_factory=list)
    drives: list[int] = field(default_factory=list)        # 0-based drive index, -1: none
    params: list[list[float]] = field(default_factory=list)
    operand_const: list[list[float]] = field(default_factory=list)
    terms: list[list[list[tuple[int, float]]]] = field(default_factory=list)  # [c][s] -> terms
    names: list[str] = field(default_factory=list)
    dependent: list[int] = field(default_factory=list)
    drive_kinds: list[int] = field(default_factory=list)
    drive_params: list[list[float]] = field(default_factory=list)
    evaluations: int = 0

    def __len__(self) -> int:
        return len(self.kinds)

    def add(self, kind: int, operands: list[tuple[dict[int, float], float]], params, drive: int,
            name: str) -> None:
        """A constraint with up to six operands (terms {dof: coef}, constant)."""
        operands = list(operands) + [({}, 0.0)] * (6 - len(operands))
        self.kinds.append(kind)
        self.drives.append(drive)
        self.params.append(list(params) + [0.0] * (8 - len(params)))
        self.operand_const.append([float(c) for _, c in operands])
        self.terms.append([sorted(t.items()) for t, _ in operands])
        self.names.append(name)

    def select(self, keep: list[int]) -> "ConstraintSet":
        """The constraints at the indices ``keep`` (same drives). Keeping all of them in
        order, the kernel arguments made for this set go with the copy (checked against its
        lists at every use as any set's: :meth:`_kernel_inputs`)."""
        out = ConstraintSet(drive_kinds=self.drive_kinds, drive_params=self.drive_params)
        if list(keep) == list(range(len(self))) and "_inputs" in self.__dict__:
            out.__dict__["_inputs"] = self.__dict__["_inputs"]
        for c in keep:
            out.kinds.append(self.kinds[c])
            out.drives.append(self.drives[c])
            out.params.append(self.params[c])
            out.operand_const.append(self.operand_const[c])
            out.terms.append(self.terms[c])
            out.names.append(self.names[c])
            if self.dependent:
                out.dependent.append(self.dependent[c])
        return out

    # -- the kernel layout ----------------------------------------------------------------
    @property
    def term_ptr(self) -> np.ndarray:
        counts = [len(t) for per in self.terms for t in per]
        return np.concatenate([[0], np.asarray(counts).cumsum()]).astype(np.int64)

    @property
    def term_dof(self) -> np.ndarray:
        return np.array([d for per in self.terms for t in per for d, _ in t], dtype=np.int64)

    @property
    def term_coef(self) -> np.ndarray:
        return np.array([c for per in self.terms for t in per for _, c in t], dtype=float)

    @property
    def params_array(self) -> np.ndarray:
        return np.array(self.params, dtype=float).T.reshape(8, -1)

    @property
    def operand_const_array(self) -> np.ndarray:
        return np.array(self.operand_const, dtype=float).T.reshape(6, -1)

    def layout(self) -> "ConstraintLayout":
        return ConstraintLayout(np.array(self.kinds, dtype=np.int32).reshape(-1),
                                np.array(self.drives, dtype=np.int32).reshape(-1),
                                self.params_array, self.operand_const_array, self.term_ptr,
                                self.term_dof, self.term_coef)

    # -- evaluation -----------------------------------------------------------------------
    def evaluate(self, e: np.ndarray, t: float = 0.0, e_dot: np.ndarray | None = None):
        """Values, operand gradients (6, ncon), operand Hessians (6, 6, ncon), Phi_t,
        Phi_tt, gamma at (e, e_dot, t)."""
        self.evaluations += 1
        n = len(self)
        if n == 0:
            empty = np.zeros(0)
            return empty, np.zeros((6, 0)), np.zeros((6, 6, 0)), empty, empty, empty
        e_dot = np.zeros_like(e) if e_dot is None else e_dot
        out = _kernel.constraint_evaluate(*self._kernel_inputs(), _state(e, e_dot), t)
        values, gradients, hessians, phi_t, phi_tt, gamma, info = out
        if info > 0:
            raise InputError(f"constraint {self.names[info - 1]!r} is malformed")
        if info < 0:
            raise InputError(f"the drive of constraint {self.names[-info - 1]!r} failed")
        return values, gradients, hessians, phi_t, phi_tt, gamma

    def _snapshot(self) -> tuple:
        """Everything the kernel's layout is made of, copied (compared with ==)."""
        return (list(self.kinds), list(self.drives), [list(p) for p in self.params],
                [list(c) for c in self.operand_const],
                [[list(t) for t in per] for per in self.terms], list(self.drive_kinds),
                [[float(x) for x in p] for p in self.drive_params])

    def _kernel_inputs(self) -> tuple:
        """The kernel's arguments of the set (its layout and drives as Fortran arrays),
        made once and made again whenever any of the set's lists changed (their contents
        are compared with a copy taken when the arguments were made, so a changed set never
        gets old arguments)."""
        snapshot = self._snapshot()
        cached = self.__dict__.get("_inputs")
        if cached is not None and cached[0] == snapshot:
            return cached[1]
        lay = self.layout()
        ptr = np.concatenate([[0], np.asarray([len(p) for p in self.drive_params]).cumsum()]) + 1
        data = np.concatenate([np.asarray(p, dtype=float) for p in self.drive_params]) \
            if self.drive_params else np.zeros(1)
        kinds = np.array(self.drive_kinds or [0], dtype=np.int32)
        packed = constraint_arrays(
            lay.kinds, lay.drives + 1, lay.params, lay.operand_const, lay.term_ptr + 1,
            lay.term_dof + 1 if len(lay.term_dof) else np.ones(1),
            lay.term_coef if len(lay.term_coef) else np.zeros(1),
            kinds, ptr if len(self.drive_kinds) else np.ones(2), data)
        for array in packed:   # shared by the calls: read only
            array.flags.writeable = False
        args = (*packed, len(lay.kinds))
        self.__dict__["_inputs"] = (snapshot, args)
        return args

    def jacobian(self, e: np.ndarray, ndof: int | None = None, t: float = 0.0,
                 evaluated: tuple | None = None):
        """Values and Phi_e as COO triplets (rows, cols, values; duplicates add up).
        ``evaluated``: what :meth:`evaluate` returned at (e, t), when the caller has it."""
        values, gradients, *_ = self.evaluate(e, t) if evaluated is None else evaluated
        rows, cols, vals = [], [], []
        for c, per in enumerate(self.terms):
            for s, terms in enumerate(per):
                for d, a in terms:
                    rows.append(c)
                    cols.append(d)
                    vals.append(a * gradients[s, c])
        return (values, np.array(rows, dtype=np.int64), np.array(cols, dtype=np.int64),
                np.array(vals, dtype=float))

    def gradient_rows(self, e: np.ndarray, ndof: int, t: float = 0.0,
                      evaluated: tuple | None = None) -> np.ndarray:
        """Dense Phi_e (ncon, ndof) (``evaluated``: see :meth:`jacobian`)."""
        _, rows, cols, vals = self.jacobian(e, ndof, t, evaluated)
        out = np.zeros((len(self), ndof))
        np.add.at(out, (rows, cols), vals)
        return out

    def hessian_triplets(self, e: np.ndarray):
        """The constant Hessians as (constraint, row, col, value) in the coordinates."""
        _, _, hessians, *_ = self.evaluate(e)
        cons, rows, cols, vals = [], [], [], []
        for c, per in enumerate(self.terms):
            h = hessians[:, :, c]
            for s in range(6):
                for u in range(6):
                    if h[s, u] == 0.0:
                        continue
                    for d1, a1 in per[s]:
                        for d2, a2 in per[u]:
                            cons.append(c)
                            rows.append(d1)
                            cols.append(d2)
                            vals.append(h[s, u] * a1 * a2)
        return (np.array(cons, dtype=np.int64), np.array(rows, dtype=np.int64),
                np.array(cols, dtype=np.int64), np.array(vals, dtype=float))

    def touched(self) -> np.ndarray:
        """Every coordinate some constraint depends on."""
        return sorted_unique(self.term_dof) if len(self) else np.zeros(0, dtype=np.int64)

    def operand_map(self, c: int, coordinates: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(6, len(coordinates)) d operands / d coordinates and the operand constants of
        constraint c, over the listed coordinates (which must hold all its terms)."""
        where = {d: i for i, d in enumerate(coordinates)}
        matrix = np.zeros((6, len(coordinates)))
        for s, terms in enumerate(self.terms[c]):
            for d, a in terms:
                matrix[s, where[d]] += a
        return matrix, np.asarray(self.operand_const[c])


@record(eq=False, repr=False)
class ConstraintLayout:
    """The arrays system_set_constraints takes (0-based indices)."""

    kinds: np.ndarray
    drives: np.ndarray
    params: np.ndarray
    operand_const: np.ndarray
    term_ptr: np.ndarray
    term_dof: np.ndarray
    term_coef: np.ndarray
