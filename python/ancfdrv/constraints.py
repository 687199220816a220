"""Holonomic constraints built from the kernel's general set (see fortran/src/constraints.f90).

Each constraint is a polynomial of degree <= 2 in the coordinates, so its Hessian is
constant. The boom's seven constraints (seed 000, eqs. 30-36) are instances:
``cross`` (eq. 30), ``distance`` (eq. 31), fixed ``coordinate`` (eqs. 32, 33, 36) and
``coordinate`` driven by the luffing angle (eqs. 34, 35).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import kernel

KIND_COORDINATE, KIND_DISTANCE, KIND_CROSS, KIND_DOT = 1, 2, 3, 4
DRIVE_CONSTANT, DRIVE_LUFFING, DRIVE_SPINUP = 0, 1, 2


@dataclass
class ConstraintSet:
    """A list of constraints in the kernel's plain-array layout.

    ``dependent`` holds, per constraint, the coordinate the split iteration treats as
    dependent (the set N1 of seed 000, eq. 40); ``names`` say what each one is.
    """

    ints: list[list[int]] = field(default_factory=list)
    reals: list[list[float]] = field(default_factory=list)
    dependent: list[int] = field(default_factory=list)
    names: list[str] = field(default_factory=list)
    drive_kinds: list[int] = field(default_factory=list)
    drive_params: list[list[float]] = field(default_factory=list)
    evaluations: int = 0

    def __len__(self) -> int:
        return len(self.ints)

    def add_drive(self, kind: int, params: list[float]) -> int:
        """Register a drive phi(t); returns its 1-based id for :meth:`coordinate`."""
        self.drive_kinds.append(kind)
        self.drive_params.append(list(params) + [0.0] * (8 - len(params)))
        return len(self.drive_kinds)

    def _add(self, kind: int, drive: int, dofs: list[int], params: list[float], dependent: int,
             name: str) -> None:
        dofs1 = [d + 1 for d in dofs] + [0] * (6 - len(dofs))
        self.ints.append([kind, drive] + dofs1)
        self.reals.append(list(params) + [0.0] * (8 - len(params)))
        self.dependent.append(dependent)
        self.names.append(name)

    def coordinate(self, dof: int, value: float = 0.0, *, cos_coef: float = 0.0,
                   sin_coef: float = 0.0, drive: int = 0, name: str = "") -> None:
        """e[dof] = value + cos_coef cos(phi) + sin_coef sin(phi), phi from ``drive``."""
        self._add(KIND_COORDINATE, drive, [dof], [value, cos_coef, sin_coef], dof,
                  name or f"e[{dof}] fixed")

    def distance(self, dofs: list[int], point, length: float, *, dependent: int,
                 name: str = "") -> None:
        """|e[dofs] - point|^2 = length^2."""
        self._add(KIND_DISTANCE, 0, dofs, list(point) + [length], dependent,
                  name or "distance")

    def cross(self, position_dofs: list[int], vector_dofs: list[int], point, axis, *,
              dependent: int, name: str = "") -> None:
        """axis . ((e[position] - point) x e[vector]) = 0: vector parallel to the position
        vector from ``point``, within the plane normal to ``axis``."""
        self._add(KIND_CROSS, 0, position_dofs + vector_dofs, list(point) + list(axis),
                  dependent, name or "parallel")

    def arrays(self):
        """Kernel arrays; a dummy constant drive is added when there is none."""
        ints = np.array(self.ints, dtype=np.int32).T.reshape(8, -1)
        reals = np.array(self.reals, dtype=float).T.reshape(8, -1)
        kinds = np.array(self.drive_kinds or [DRIVE_CONSTANT], dtype=np.int32)
        params = np.array(self.drive_params or [[0.0] * 8], dtype=float).T
        return ints, reals, kinds, params

    def evaluate(self, e: np.ndarray, t: float = 0.0, e_dot: np.ndarray | None = None):
        """Values, gradients (6, ncon), Hessians (6, 6, ncon), Phi_t, Phi_tt, gamma."""
        self.evaluations += 1
        if not self.ints:  # an unconstrained model (f2py refuses zero-size arrays)
            empty = np.zeros(0)
            return empty, np.zeros((6, 0)), np.zeros((6, 6, 0)), empty, empty, empty
        ints, reals, kinds, params = self.arrays()
        e_dot = np.zeros_like(e) if e_dot is None else e_dot
        return kernel.constraint_evaluate(ints, reals, kinds, params, e, e_dot, t)

    def dof_table(self) -> np.ndarray:
        """0-based dofs (6, ncon) of each constraint's gradient entries, -1 where unused."""
        return np.array(self.ints, dtype=np.int64).T[2:8].reshape(6, -1) - 1

    def jacobian(self, e: np.ndarray, ndof: int, t: float = 0.0):
        """Values and the dense-free Jacobian as COO triplets (rows, cols, values)."""
        values, gradients, *_ = self.evaluate(e, t)
        table = self.dof_table()
        mask = table >= 0
        rows = np.broadcast_to(np.arange(len(self)), table.shape)[mask]
        return values, rows, table[mask], gradients[mask]
