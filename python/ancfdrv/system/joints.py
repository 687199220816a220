"""Joints between two bodies (one may be the ground), written as equations in the full
coordinates q. Time-independent linear equations (:class:`LinearEquation`) are eliminated
by the assembly (q = B e + q0, seed 003 eqs. 34-37) or kept with a multiplier, as its
``linear_joints`` setting says; the others (:class:`Constraint`: nonlinear or driven) always
keep a Lagrange multiplier (seed 000 eqs. 30-36, 58).

Types (SPEC section 8, plus what the template scenes need):

- ``weld``: the positions coincide and body2's section or orientation (beam: r_y, r_z;
  plate: r_x, r_y; rigid body: its three axes) follows body1's directions at the point
  (a constant combination of body1's nodal vectors or axes);
- ``revolute``: positions coincide and the two bodies' vectors along ``axis`` coincide;
- ``spherical``: positions coincide;
- ``distance``: |p2 - p1| is held at its initial value, or follows ``drive`` (a hydraulic
  cylinder whose length is the drive's value);
- ``prescribed``: the point of body2 follows a rotation about ``pivot`` about ``axis`` by the
  drive's angle (from its value at t = 0), or without a pivot a translation along ``axis``
  by the drive's value (body1 is the ground);
- ``fix``: body2's nodal vector ``vector`` ('r', 'r_x', 'r_y', 'r_z'; a rigid body's 'r' is
  the point) keeps its initial value, all components or only the one along ``axis``;
- ``arm``: the boom's support (seed 000 eqs. 30-33): the node is held by a massless arm
  hinged at ``pivot`` about ``axis``: its distance to the pivot and its plane are kept and
  its section's height direction r_y stays along the arm;
- ``hub``: a driven clamp: body2's node and section turn with the drive's angle about
  ``axis`` through ``pivot`` (the spin-up beam's root).

Points of joints must be nodes of beams, plates and leaves (any point of a rigid body).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..codes import CONSTRAINT_COORDINATE, CONSTRAINT_CROSS, CONSTRAINT_DISTANCE, CONSTRAINT_DOT
from ..errors import InputError
from .bodies import Attachment, Body, Ground, RigidBody, rotation_about
from .drives import Drive
from .expressions import Scalar, Vec3, combination

JOINT_TYPES = ("weld", "revolute", "spherical", "distance", "prescribed", "fix", "arm", "hub")


@dataclass
class LinearEquation:
    """expr(q) = 0, time-independent; ``prefer``: full coordinates to make dependent when it
    is eliminated, best first."""

    expr: Scalar
    name: str
    prefer: list[int] = field(default_factory=list)


@dataclass
class Constraint:
    """A constraint of the kernel's kinds (constraints.f90) over six scalar operands affine
    in q; ``prefer``: the coordinate the split iteration should take as dependent."""

    kind: int
    operands: list[Scalar]
    params: list[float]
    drive: Drive | None
    name: str
    prefer: list[int] = field(default_factory=list)


Equation = LinearEquation | Constraint


def _dofs(v: Vec3, component: int) -> list[int]:
    return [d + component for d in v.terms]


def vector_equations(v2: Vec3, v1: Vec3, name: str) -> list[LinearEquation]:
    """v2 - v1 = 0 component by component, body2's coordinates preferred as dependents."""
    diff = v2 - v1
    return [LinearEquation(diff.component(i), f"{name} [{'xyz'[i]}]", _dofs(v2, i))
            for i in range(3)]


def _express(basis: list[Vec3], initial: list[np.ndarray], target: np.ndarray, what: str
             ) -> np.ndarray:
    """Coefficients c with sum c_k basis_k(0) = target (exact, else InputError)."""
    matrix = np.column_stack(initial)
    coef, *_ = np.linalg.lstsq(matrix, target, rcond=None)
    if np.linalg.norm(matrix @ coef - target) > 1e-9 * max(1.0, np.linalg.norm(target)):
        raise InputError(f"{what}: the direction {list(np.round(target, 12))} cannot be written "
                         "in the body's nodal directions there (a plate or leaf holds directions "
                         "in its own plane only)")
    coef[np.abs(coef) < 1e-14 * np.abs(coef).max(initial=1.0)] = 0.0
    return coef


def _rotation_terms(v: np.ndarray, axis: np.ndarray, pivot: np.ndarray) -> np.ndarray:
    """(3, 4) parameters [c1, c2, c3, c4] per component of pivot + Rot(k, phi) v =
    pivot + k (k.v) + (v - k (k.v)) cos phi + (k x v) sin phi."""
    k = axis / np.linalg.norm(axis)
    along = k * (k @ v)
    return np.column_stack([pivot + along, v - along, np.cross(k, v), np.zeros(3)])


@dataclass
class Joint:
    """A joint; see the module documentation for the types and their keys."""

    name: str
    type: str
    body1: Body
    body2: Body
    points: list[np.ndarray] = field(default_factory=list)
    axis: np.ndarray | None = None
    drive: Drive | None = None
    point1: np.ndarray | None = None
    point2: np.ndarray | None = None
    pivot: np.ndarray | None = None
    vector: str = "r"

    def __post_init__(self) -> None:
        where = f"joint {self.name!r}"
        if self.type not in JOINT_TYPES:
            raise InputError(f"{where}: type {self.type!r} must be one of {JOINT_TYPES}")
        if self.body1 is self.body2:
            raise InputError(f"{where}: body1 and body2 are the same body")
        if isinstance(self.body2, Ground):  # the ground is always body1
            self.body1, self.body2 = self.body2, self.body1
        if self.axis is not None:
            self.axis = np.asarray(self.axis, dtype=float)
            if self.axis.shape != (3,) or np.linalg.norm(self.axis) == 0.0:
                raise InputError(f"{where}: axis must be a non-zero 3-vector")
            self.axis = self.axis / np.linalg.norm(self.axis)
        needs_points = self.type != "distance"
        if needs_points and not self.points:
            raise InputError(f"{where}: point is required for type {self.type!r}")
        if self.type == "distance" and (self.point1 is None or self.point2 is None):
            raise InputError(f"{where}: type 'distance' needs point1 (on body1) and point2 (on "
                             "body2)")
        if self.type in ("revolute", "arm", "hub") and self.axis is None:
            raise InputError(f"{where}: type {self.type!r} needs an axis")
        if self.type in ("prescribed", "fix", "arm", "hub") and not isinstance(self.body1, Ground):
            raise InputError(f"{where}: type {self.type!r} acts between the ground and a body "
                             f"(body1 = {self.body1.name!r} is not the ground)")
        if self.type in ("prescribed", "hub") and self.drive is None:
            raise InputError(f"{where}: type {self.type!r} needs a drive")
        if self.type == "prescribed" and self.pivot is None and self.axis is None:
            raise InputError(f"{where}: 'prescribed' needs a pivot and an axis (rotation) or an "
                             "axis (translation)")
        if self.type in ("arm", "hub") and self.pivot is None:
            raise InputError(f"{where}: type {self.type!r} needs a pivot")
        if self.vector not in ("r", "r_x", "r_y", "r_z"):
            raise InputError(f"{where}: vector {self.vector!r} must be 'r', 'r_x', 'r_y' or 'r_z'")
        if self.drive is not None and self.type not in ("distance", "prescribed", "hub"):
            raise InputError(f"{where}: a drive applies to types 'distance', 'prescribed' and "
                             "'hub'")

    @property
    def bodies(self) -> tuple[Body, Body]:
        return self.body1, self.body2

    def _locate(self, body: Body, point) -> Attachment:
        return body.locate(point, node=not isinstance(body, RigidBody), what=f"joint {self.name!r}")

    def equations(self, q0: np.ndarray) -> list[Equation]:
        """The joint's equations in the order the assembly keeps them."""
        out: list[Equation] = []
        if self.type == "distance":
            return self._distance(q0)
        for k, point in enumerate(self.points):
            name = self.name if len(self.points) == 1 else f"{self.name} #{k + 1}"
            at1, at2 = self._locate(self.body1, point), self._locate(self.body2, point)
            out += getattr(self, f"_{self.type}")(at1, at2, q0, name)
        return out

    # -- the types ------------------------------------------------------------------------
    def _spherical(self, at1, at2, q0, name) -> list[Equation]:
        return vector_equations(self.body2.position(at2), self.body1.position(at1),
                                f"{name}: position")

    def _weld(self, at1, at2, q0, name) -> list[Equation]:
        out = self._spherical(at1, at2, q0, name)
        basis = self.body1.basis(at1)
        initial = [b.value(q0) for b in basis]
        for which in self.body2.held_vectors(at2):
            v2 = self.body2.vector(at2, which)
            coef = _express(basis, initial, v2.value(q0), f"joint {name!r}")
            out += vector_equations(v2, combination(basis, coef), f"{name}: {which}")
        return out

    def _revolute(self, at1, at2, q0, name) -> list[Equation]:
        out = self._spherical(at1, at2, q0, name)
        axes = []
        for body, at in ((self.body1, at1), (self.body2, at2)):
            basis = body.basis(at)
            coef = _express(basis, [b.value(q0) for b in basis], self.axis, f"joint {name!r}")
            axes.append(combination(basis, coef) if basis else Vec3.constant(self.axis))
        return out + vector_equations(axes[1], axes[0], f"{name}: axis")

    def _fix(self, at1, at2, q0, name) -> list[Equation]:
        v = self.body2.vector(at2, self.vector)
        value = Vec3.constant(v.value(q0))
        if self.axis is None:
            return vector_equations(v, value, f"{name}: {self.vector}")
        k = self.axis
        order = np.argsort(-np.abs(k))
        prefer = [d for i in order if k[i] != 0.0 for d in _dofs(v, int(i))]
        return [LinearEquation((v - value).along(k), f"{name}: {self.vector} along axis", prefer)]

    def _prescribed(self, at1, at2, q0, name) -> list[Equation]:
        p = self.body2.position(at2)
        p0 = p.value(q0)
        phi0 = self.drive.value(0.0)
        if self.pivot is not None:
            axis = self.axis if self.axis is not None else np.array([0.0, 0.0, 1.0])
            v = rotation_about(axis, -phi0) @ (p0 - self.pivot)
            params = _rotation_terms(v, axis, self.pivot)
        else:
            params = np.column_stack([p0 - phi0 * self.axis, np.zeros(3), np.zeros(3), self.axis])
        return [Constraint(CONSTRAINT_COORDINATE, [p.component(i)], list(params[i]), self.drive,
                           f"{name}: {'xyz'[i]}(t)", _dofs(p, i)) for i in range(3)]

    def _hub(self, at1, at2, q0, name) -> list[Equation]:
        out = []
        phi0 = self.drive.value(0.0)
        turn_back = rotation_about(self.axis, -phi0)
        p = self.body2.position(at2)
        params = _rotation_terms(turn_back @ (p.value(q0) - self.pivot), self.axis, self.pivot)
        out += [Constraint(CONSTRAINT_COORDINATE, [p.component(i)], list(params[i]), self.drive,
                           f"{name}: position {'xyz'[i]}(t)", _dofs(p, i)) for i in range(3)]
        for which in self.body2.held_vectors(at2):
            v = self.body2.vector(at2, which)
            params = _rotation_terms(turn_back @ v.value(q0), self.axis, np.zeros(3))
            out += [Constraint(CONSTRAINT_COORDINATE, [v.component(i)], list(params[i]),
                               self.drive, f"{name}: {which} {'xyz'[i]}(t)", _dofs(v, i))
                    for i in range(3)]
        return out

    def _arm(self, at1, at2, q0, name) -> list[Equation]:
        """Seed 000 eqs. 30-33 for an arm about axis k through pivot O holding node p."""
        k, pivot = self.axis, self.pivot
        p = self.body2.position(at2)
        director = self.body2.vector(at2, "r_y")
        arm = p - Vec3.constant(pivot)
        length = float(np.linalg.norm(arm.value(q0)))
        if length == 0.0:
            raise InputError(f"joint {name!r}: the node lies on the pivot (the arm has no length)")
        if abs(k @ arm.value(q0)) > 1e-9 * length:
            raise InputError(f"joint {name!r}: the node is not in the plane through the pivot "
                             "normal to the axis")
        order = np.argsort(np.abs(k), kind="stable")  # two in-plane components, then the axial
        plane, axial = [int(i) for i in order[:2]], int(order[2])
        const = Scalar({}, 0.0)
        return [
            Constraint(CONSTRAINT_CROSS, arm.components() + director.components(), list(k),
                       None, f"{name}: r_y along the arm", _dofs(p, plane[0])),
            Constraint(CONSTRAINT_DISTANCE, p.components() + [const + Scalar({}, float(c))
                                                              for c in pivot], [length, 0.0],
                       None, f"{name}: arm length", _dofs(p, plane[1])),
            LinearEquation(arm.along(k), f"{name}: in the plane", _dofs(p, axial)),
            LinearEquation(director.along(k), f"{name}: section in the plane",
                           _dofs(director, axial)),
        ]

    def _distance(self, q0) -> list[Equation]:
        at1 = self._locate(self.body1, self.point1)
        at2 = self._locate(self.body2, self.point2)
        p1, p2 = self.body1.position(at1), self.body2.position(at2)
        length = float(np.linalg.norm(p2.value(q0) - p1.value(q0)))
        if length == 0.0:
            raise InputError(f"joint {self.name!r}: point1 and point2 coincide (use 'spherical')")
        params = [length, 0.0]
        if self.drive is not None:
            start = self.drive.value(0.0)
            if abs(start - length) > 1e-6 * length:
                raise InputError(f"joint {self.name!r}: the drive {self.drive.name!r} gives the "
                                 f"length {start:g} m at t = 0, the points are {length:g} m "
                                 "apart")
            params = [0.0, 1.0]
        return [Constraint(CONSTRAINT_DISTANCE, p2.components() + p1.components(), params,
                           self.drive, f"{self.name}: length")]


def orthonormality(body: RigidBody) -> list[Constraint]:
    """J^T J = I of a rigid body's axes (seed 003 eq. 30) as six dot constraints; those that
    the eliminated coordinates satisfy identically are dropped by the assembly."""
    axes = {w: Vec3.of(body.vector_first(w)) for w in ("r_x", "r_y", "r_z")}
    out = []
    for a, b in (("r_x", "r_x"), ("r_y", "r_y"), ("r_z", "r_z"), ("r_x", "r_y"), ("r_x", "r_z"),
                 ("r_y", "r_z")):
        out.append(Constraint(CONSTRAINT_DOT, axes[a].components() + axes[b].components(),
                              [1.0 if a == b else 0.0], None,
                              f"{body.name}: {a} . {b} = {1 if a == b else 0}"))
    return out


def planar_fixes(body: RigidBody, q0: np.ndarray) -> list[LinearEquation]:
    """A planar body (normal along coordinate axis j): its translation along j, its axis j
    (kept = e_j) and the j-components of its other two axes (kept at 0)."""
    j = body.plane_axis
    out = [LinearEquation(Scalar({body.vector_first("r") + j: 1.0},
                                 -float(q0[body.vector_first("r") + j])),
                          f"{body.name}: planar r{j + 1}", [body.vector_first("r") + j])]
    for k, which in enumerate(("r_x", "r_y", "r_z")):
        for comp in range(3):
            if k == j or comp == j:
                dof = body.vector_first(which) + comp
                out.append(LinearEquation(Scalar({dof: 1.0}, -float(q0[dof])),
                                          f"{body.name}: planar {which}", [dof]))
    return out
