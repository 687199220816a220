"""Joints between two bodies (one may be the ground), written as equations in the full
coordinates q. Time-independent linear equations (:class:`LinearEquation`) are eliminated
by the assembly (q = B e + q0, seed 003 eqs. 34-37) or kept with a multiplier, as its
``linear_joints`` setting says; the others (:class:`Constraint`: nonlinear or driven) always
keep a Lagrange multiplier (seed 000 eqs. 30-36, 58).

Types (SPEC section 8, plus what the template scenes need):

- ``weld``: the positions coincide and body2's section or orientation (beam: r_y, r_z;
  plate: r_x, r_y; rigid body: its three axes) follows body1's directions at the point
  (a constant combination of body1's nodal vectors or axes; a rigid body's axes carry a
  flexible body's section whichever is body1, except that an FFR beam in a fixed frame
  carries a rigid body's axes by its section's small turn, linearly: see
  :func:`_weld_roles`; a direction along a beam's axis is its section normal, not the
  sheared tangent r_x: see :func:`_section_ties`);
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
  ``axis`` through ``pivot`` (the spin-up beam's root);
- ``prismatic``: body2's section or axes follow body1's directions (as a weld's) and its
  point stays on the line through body1's point along ``axis`` (carried by body1): relative
  translation along the axis only; with ``drive`` the translation (p2 - p1) . axis is the
  drive's value minus its value at t = 0 (an actuator);
- ``cylindrical``: the bodies' vectors along ``axis`` coincide (as a revolute's) and body2's
  point stays on body1's line along the axis: translation along and rotation about it;
- ``universal``: positions coincide and ``axis`` (carried by body1) stays normal to
  ``axis2`` (carried by body2; normal to ``axis`` at t = 0): a Cardan joint's cross.

The guide of 'prismatic' and 'cylindrical' is the line body1's section carries at the
joint's point (a rigid guide fixed there) and p2 one material point of body2: a carriage on
a flexible rail does not follow the rail's deflection along its length.

The new types reuse the equations of the old ones (:meth:`Joint._orientation` of the weld,
:meth:`Joint._axis_tie` of the revolute) and add dot products of carried directions
(:func:`_product`), each linear when one factor is constant (the ground's) and a kernel
'dot' constraint otherwise (its value x . y - p1 - p2 phi carries the prismatic drive).

A joint's point may be any material point of a body (SPEC 8.1): between the nodes of a beam,
plate or leaf its position and directions come from the element's shape functions, and off a
beam's axis the point is carried by the section directors r_y, r_z (a plate's points lie on
its mid-surface).
"""
from __future__ import annotations

from dataclasses import field

import numpy as np

from ..records import record
from ..codes import CONSTRAINT_COORDINATE, CONSTRAINT_CROSS, CONSTRAINT_DISTANCE, CONSTRAINT_DOT
from ..errors import InputError
from .bodies import Attachment, Body, Ground, rotation_about
from .kinds import Beam, RigidBody
from .drives import Drive
from .expressions import Scalar, Vec3, combination

JOINT_TYPES = ("weld", "revolute", "spherical", "distance", "prescribed", "fix", "arm", "hub",
               "prismatic", "cylindrical", "universal")
#: plate and leaf edges a joint can hold whole: x0 / x1 the ends along edge_x (a leaf's arc),
#: y0 / y1 the sides along edge_y
EDGES = ("x0", "x1", "y0", "y1")


@record
class LinearEquation:
    """expr(q) = 0, time-independent; ``prefer``: full coordinates to make dependent when it
    is eliminated, best first."""

    expr: Scalar
    name: str
    prefer: list[int] = field(default_factory=list)


@record
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
    if matrix.shape == (3, 3) and (matrix == _IDENTITY).all():
        # the axes of the ground (a weld to it): c = target, as least squares finds it bit
        # for bit, without numpy's LAPACK call (its first call loads ~1 MB of BLAS code and
        # work space; issue 23: a run's peak memory)
        coef = np.array(target, dtype=float)
    else:
        coef = _least_squares(matrix, target, what)
    coef[np.abs(coef) < 1e-14 * np.abs(coef).max(initial=1.0)] = 0.0
    return coef


_IDENTITY = np.eye(3)


def _least_squares(matrix: np.ndarray, target: np.ndarray, what: str) -> np.ndarray:
    """The exact coefficients of target in the columns of matrix (else InputError)."""
    coef, *_ = np.linalg.lstsq(matrix, target, rcond=None)
    if np.linalg.norm(matrix @ coef - target) > 1e-9 * max(1.0, np.linalg.norm(target)):
        raise InputError(f"{what}: the direction {list(np.round(target, 12))} cannot be written "
                         "in the body's nodal directions there (a plate or leaf holds directions "
                         "in its own plane only)")
    return coef


def _rotation_terms(v: np.ndarray, axis: np.ndarray, pivot: np.ndarray) -> np.ndarray:
    """(3, 4) parameters [c1, c2, c3, c4] per component of pivot + Rot(k, phi) v =
    pivot + k (k.v) + (v - k (k.v)) cos phi + (k x v) sin phi."""
    k = axis / np.linalg.norm(axis)
    along = k * (k @ v)
    return np.column_stack([pivot + along, v - along, np.cross(k, v), np.zeros(3)])


@record
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
    #: a plate or leaf edge ('x0', 'x1', 'y0', 'y1') whose every node the joint holds
    edge: str | None = None
    #: a box (x0, y0, z0, x1, y1, z1) whose every node of the flexible body the joint holds
    box: np.ndarray | None = None
    #: 'universal': the cross's second axis, carried by body2 (normal to ``axis`` at t = 0)
    axis2: np.ndarray | None = None

    def __post_init__(self) -> None:
        where = f"joint {self.name!r}"
        if self.edge is not None and self.edge not in EDGES:
            raise InputError(f"{where}: edge {self.edge!r} must be one of {EDGES}")
        if self.box is not None:
            self.box = np.asarray(self.box, dtype=float).ravel()
            if self.box.shape != (6,) or not np.all(np.isfinite(self.box)) or \
                    np.any(self.box[3:] < self.box[:3]):
                raise InputError(f"{where}: box must be six finite numbers x0, y0, z0, x1, y1, "
                                 "z1 with x1 >= x0, y1 >= y0, z1 >= z0")
        if (self.edge is not None or self.box is not None) and (
                self.points or self.type == "distance"):
            raise InputError(f"{where}: give either point, or edge/box (not both; 'distance' "
                             "takes point1 and point2)")
        if self.edge is not None and self.box is not None:
            raise InputError(f"{where}: give edge or box, not both")
        if self.edge is not None or self.box is not None:
            self.points = self._selected_points(where)
        if self.type not in JOINT_TYPES:
            raise InputError(f"{where}: type {self.type!r} must be one of {JOINT_TYPES}")
        if self.body1 is self.body2:
            raise InputError(f"{where}: body1 and body2 are the same body")
        #: the user named the ground as body2: the bodies were swapped (reactions say what
        #: the user's body1 exerts on the user's body2, so their sign turns back)
        self.swapped = isinstance(self.body2, Ground)
        if isinstance(self.body2, Ground):  # the ground is always body1
            self.body1, self.body2 = self.body2, self.body1
            if self.type == "universal":   # each axis stays with its body
                self.axis, self.axis2 = self.axis2, self.axis
        if self.axis2 is not None:
            if self.type != "universal":
                raise InputError(f"{where}: axis2 applies to type 'universal' only")
            self.axis2 = np.asarray(self.axis2, dtype=float)
            if self.axis2.shape != (3,) or np.linalg.norm(self.axis2) == 0.0:
                raise InputError(f"{where}: axis2 must be a non-zero 3-vector")
            self.axis2 = self.axis2 / np.linalg.norm(self.axis2)
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
        if self.type in ("revolute", "arm", "hub", "prismatic", "cylindrical",
                         "universal") and self.axis is None:
            raise InputError(f"{where}: type {self.type!r} needs an axis")
        if self.type == "universal":
            if self.axis2 is None:
                raise InputError(f"{where}: type 'universal' needs axis2 (the cross's axis on "
                                 "body2, normal to axis)")
            if abs(float(self.axis @ self.axis2)) > 1e-9:
                raise InputError(f"{where}: axis and axis2 must be normal to each other at "
                                 f"t = 0 (their cosine is {float(self.axis @ self.axis2):.3g})")
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
        if self.drive is not None and self.type not in ("distance", "prescribed", "hub",
                                                        "prismatic"):
            raise InputError(f"{where}: a drive applies to types 'distance', 'prescribed', "
                             "'hub' and 'prismatic'")

    def _selected_points(self, where: str) -> list[np.ndarray]:
        """The nodes of the joint's flexible body on its edge or in its box (at t = 0): a
        selection that follows the mesh, so refining it leaves no part of a support free."""
        body = self.body2 if self.body2.flexible else self.body1
        if not body.flexible:
            raise InputError(f"{where}: edge and box select nodes of a beam, plate or leaf; "
                             f"neither {self.body1.name!r} nor {self.body2.name!r} is one")
        if self.edge is not None:
            if not body.surface:
                raise InputError(f"{where}: edge selects a side of a plate or leaf, and "
                                 f"{body.name!r} is not one (use box)")
            grid = body.mesh.grid
            nodes = {"x0": grid[0, :], "x1": grid[-1, :], "y0": grid[:, 0],
                     "y1": grid[:, -1]}[self.edge]
            positions = body.mesh.coords[nodes, 0:3]
        else:
            allnodes = body.mesh.coords[:, 0:3] if body.surface else \
                body.node_positions()
            size = float(np.ptp(allnodes, axis=0).max())
            tol = 1e-9 * max(size, 1.0)
            inside = np.all((allnodes >= self.box[:3] - tol) & (allnodes <= self.box[3:] + tol),
                            axis=1)
            positions = allnodes[inside]
        if not len(positions):
            raise InputError(f"{where}: the box {list(self.box)} holds no node of "
                             f"{body.name!r}")
        return [np.array(p, dtype=float) for p in positions]

    @property
    def bodies(self) -> tuple[Body, Body]:
        return self.body1, self.body2

    def _locate(self, body: Body, point) -> Attachment:
        return body.locate(point, node=False, what=f"joint {self.name!r}")

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

    def linearized_body(self) -> RigidBody | None:
        """The rigid body whose axes this weld ties linearly to an FFR beam's small section
        turn (:func:`_weld_roles`), else None. Its axes are then I + [w]x, orthonormal to
        first order only, like the beam's own kinematics: the assembly does not impose its
        orthonormality (it would hold w at zero)."""
        if self.type not in ("weld", "prismatic"):
            return None
        base, held = self.body1, self.body2
        if base.rigid:
            base, held = held, base
        if held.rigid and small_turn(base):
            return held
        return None

    def _weld(self, at1, at2, q0, name) -> list[Equation]:
        return self._spherical(at1, at2, q0, name) + self._orientation(at1, at2, q0, name)

    def _orientation(self, at1, at2, q0, name) -> list[Equation]:
        """A weld's orientation ties: body2's section or axes follow body1's directions at
        the point (see :func:`_weld_roles`, :func:`_section_ties`)."""
        out: list[Equation] = []
        base, at_b, held, at_h = _weld_roles(self.body1, at1, self.body2, at2)
        basis = base.basis(at_b)
        initial = [b.value(q0) for b in basis]
        ties = []
        for which in held.held_vectors(at_h):
            v = held.vector(at_h, which)
            ties.append((which, v, _express(basis, initial, v.value(q0), f"joint {name!r}")))
        if base.section_directors and any(coef[0] != 0.0 for *_, coef in ties):
            return out + _section_ties(base, at_b, held, at_h, ties, q0, name)
        for which, v, coef in ties:
            out += vector_equations(v, combination(basis, coef), f"{name}: {which}")
        return out

    def _revolute(self, at1, at2, q0, name) -> list[Equation]:
        return self._spherical(at1, at2, q0, name) + self._axis_tie(at1, at2, q0, name)

    def _axis_tie(self, at1, at2, q0, name) -> list[Equation]:
        """A revolute's axis equations: the two bodies' vectors along ``axis`` coincide."""
        out: list[Equation] = []
        axes = []
        for body, at in ((self.body1, at1), (self.body2, at2)):
            components, kept = _carried(body, at, self.axis, q0, name)
            axes.append(components)
            out += kept
        return out + [LinearEquation(axes[1][i] - axes[0][i], f"{name}: axis [{'xyz'[i]}]",
                                     list(axes[1][i].terms)) for i in range(3)]

    def _across(self, at1, at2, q0, name) -> list[Equation]:
        """Body2's point stays on the line through body1's point along ``axis`` (carried by
        body1): (p2 - p1) . n = 0 for two normals n of the axis as body1 carries them."""
        gap = (self.body2.position(at2) - self.body1.position(at1))
        normals, kept = _carried_all(self.body1, at1, _normals(self.axis), q0, name)
        out: list[Equation] = []
        for k, n in enumerate(normals):
            prefer = _prefer(gap, n, q0)
            out.append(_product(gap.components(), n, 0.0, f"{name}: across {k + 1}", prefer))
        return out + kept

    def _prismatic(self, at1, at2, q0, name) -> list[Equation]:
        out = self._orientation(at1, at2, q0, name) + self._across(at1, at2, q0, name)
        if self.drive is not None:
            # the user's (p2 - p1) . axis follows phi(t) - phi(0); with the bodies swapped
            # (the ground named as body2) the internal p2 - p1 is its opposite
            sign = -1.0 if self.swapped else 1.0
            gap = self.body2.position(at2) - self.body1.position(at1)
            (along,), kept = _carried_all(self.body1, at1, [self.axis], q0, name)
            phi0 = self.drive.value(0.0)
            out.append(_product(gap.components(), along, -sign * phi0, f"{name}: slide(t)",
                                _prefer(gap, along, q0), self.drive, sign))
            out += kept
        return _unique(out)

    def _cylindrical(self, at1, at2, q0, name) -> list[Equation]:
        return _unique(self._axis_tie(at1, at2, q0, name) + self._across(at1, at2, q0, name))

    def _universal(self, at1, at2, q0, name) -> list[Equation]:
        out = self._spherical(at1, at2, q0, name)
        (a1,), kept1 = _carried_all(self.body1, at1, [self.axis], q0, name)
        (a2,), kept2 = _carried_all(self.body2, at2, [self.axis2], q0, name)
        prefer = [d for s in a2 for d in s.terms]
        out.append(_product(a1, a2, 0.0, f"{name}: cross", prefer))
        return _unique(out + kept1 + kept2)

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
        if "r_y" not in self.body2.held_vectors(at2):
            return self._arm_on_slope(at2, q0, name)
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

    def _arm_on_slope(self, at2, q0, name) -> list[Equation]:
        """The arm holding a node of a body without a section (a cable: r and r_x): as
        :meth:`_arm`, with the section's r_y along the arm written as the slope r_x normal
        to it (Euler-Bernoulli: the section stays normal to the axis), r_x . (p - O) = 0."""
        k, pivot = self.axis, self.pivot
        p = self.body2.position(at2)
        slope = self.body2.vector(at2, "r_x")
        arm = p - Vec3.constant(pivot)
        length = float(np.linalg.norm(arm.value(q0)))
        if length == 0.0:
            raise InputError(f"joint {name!r}: the node lies on the pivot (the arm has no length)")
        if abs(k @ arm.value(q0)) > 1e-9 * length or \
                abs(float(slope.value(q0) @ arm.value(q0))) > 1e-9 * length * float(
                    np.linalg.norm(slope.value(q0))):
            raise InputError(f"joint {name!r}: the node is not in the plane through the pivot "
                             "normal to the axis, or its slope is not normal to the arm")
        order = np.argsort(np.abs(k), kind="stable")
        plane, axial = [int(i) for i in order[:2]], int(order[2])
        const = Scalar({}, 0.0)
        return [
            Constraint(CONSTRAINT_DOT, arm.components() + slope.components(), [0.0], None,
                       f"{name}: r_x normal to the arm", _dofs(p, plane[0])),
            Constraint(CONSTRAINT_DISTANCE, p.components() + [const + Scalar({}, float(c))
                                                              for c in pivot], [length, 0.0],
                       None, f"{name}: arm length", _dofs(p, plane[1])),
            LinearEquation(arm.along(k), f"{name}: in the plane", _dofs(p, axial)),
            LinearEquation(slope.along(k), f"{name}: slope in the plane", _dofs(slope, axial)),
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


def _dot(u: Vec3, v: Vec3, q0: np.ndarray, name: str, prefer: list[int]) -> Constraint:
    """u . v kept at its initial value."""
    return Constraint(CONSTRAINT_DOT, u.components() + v.components(),
                      [float(u.value(q0) @ v.value(q0))], None, name, prefer)


def _normals(axis: np.ndarray) -> list[np.ndarray]:
    """Two unit vectors normal to the unit vector axis and to each other."""
    trial = np.eye(3)[int(np.argmin(np.abs(axis)))]
    b = np.cross(axis, trial)
    b /= np.linalg.norm(b)
    return [b, np.cross(axis, b)]


def _carried_all(body: Body, at: Attachment, directions: list[np.ndarray], q0: np.ndarray,
                 name: str) -> tuple[list[list[Scalar]], list[Equation]]:
    """:func:`_carried` for several directions; their section-keeping equations once."""
    out, kept = [], []
    for k0 in directions:
        components, more = _carried(body, at, k0, q0, name)
        out.append(components)
        kept += more
    return out, _unique(kept)


def _unique(equations: list[Equation]) -> list[Equation]:
    """The equations without repeats of a name (a section kept rigid by two ties)."""
    seen: set[str] = set()
    out = []
    for eq in equations:
        if eq.name not in seen:
            seen.add(eq.name)
            out.append(eq)
    return out


def _prefer(v: Vec3, direction: list[Scalar], q0: np.ndarray) -> list[int]:
    """v's coordinates along the direction's largest components (at t = 0) first."""
    k = np.array([s.value(q0) for s in direction])
    order = np.argsort(-np.abs(k), kind="stable")
    return [d for i in order if abs(k[i]) > 1e-12 for d in _dofs(v, int(i))]


def _product(u: list[Scalar], v: list[Scalar], value: float, name: str, prefer: list[int],
             drive: Drive | None = None, rate: float = 0.0) -> Equation:
    """u . v = value + rate phi(t) for affine 3-vectors u, v (components): linear when one
    of them is constant (a :class:`LinearEquation`, or a driven 'coordinate' constraint),
    else a 'dot' constraint (x . y - p1 - p2 phi = 0)."""
    if all(not s.terms for s in u):
        u, v = v, u
    if all(not s.terms for s in v):
        expr = Scalar({}, 0.0)
        for a, b in zip(u, v):
            expr = expr + a.scaled(b.const)
        if drive is None:
            return LinearEquation(expr - Scalar({}, value), name, prefer)
        return Constraint(CONSTRAINT_COORDINATE, [expr], [value, 0.0, 0.0, rate], drive, name,
                          prefer)
    return Constraint(CONSTRAINT_DOT, list(u) + list(v), [value, rate], drive, name, prefer)


def small_turn(body: Body) -> bool:
    """Whether the body's section turns are small and its kinematics linear (a floating
    body in a fixed frame: an FFR beam without a frame drive): then directions it carries
    are linear in its coordinates (:func:`_turned`)."""
    return body.floating and body.frame_drive is None


def _weld_roles(body1: Body, at1: Attachment, body2: Body, at2: Attachment
                ) -> tuple[Body, Attachment, Body, Attachment]:
    """(base, its attachment, held, its attachment) of a weld: the held body's vectors
    follow the base's directions. A rigid body welded to a flexible body, whatever the
    order the joint names them in:

    * to an FFR beam in a fixed frame (:func:`small_turn`): the beam is the base and the
      body's axes follow its section's small turn v0 + w x v0 (:func:`_turned`, linear).
      Tying the beam's directors to the body's orthonormal axes instead would hold them at
      unit length through a finite turn: the FFR element's linear section strains would
      read the (cos t - 1) of every component as a stretch and resist the turn with the
      section stiffness E A L_e / 2 of the joint's node (a spurious moment E A L_e t^3 / 4:
      the tip of an 8 m FFR 'cubic' cantilever 2.1e-3 too stiff on 2 elements, 2.6e-4 on
      16);
    * otherwise the body is the base: its axes carry the flexible body's section (they
      neither shear nor stretch). This includes an FFR beam in a moving frame, whose
      linear tie would have time-dependent coefficients: there the stiffening above remains.
    """
    if body2.rigid and body1.flexible:
        body1, at1, body2, at2 = body2, at2, body1, at1
    if body1.rigid and small_turn(body2):
        body1, at1, body2, at2 = body2, at2, body1, at1
    return body1, at1, body2, at2


def _turned(beam: Beam, at: Attachment, v0: np.ndarray) -> list[Scalar]:
    """The components of v0 + w x v0: the direction v0 (at t = 0) turned with the small
    rotation w of the beam's section, from its directors d_y, d_z (e: their initial
    directions): w_x = s_y d_y . e_z - s_z d_z . e_y (s: the beam's torsion shares),
    w_y = d_z . e_x, w_z = -d_y . e_x. Free of the section's stretch and shear, and of the
    centre line's slope r_x (which also turns with the shear strain)."""
    e = beam.orientation.T   # rows e_x, e_y, e_z
    d_y, d_z = (beam.vector(at, w) for w in beam.section_directors)
    s_y, s_z = beam.torsion_shares()
    rotation = [d_y.along(e[2]).scaled(s_y) - d_z.along(e[1]).scaled(s_z), d_z.along(e[0]),
                d_y.along(e[0]).scaled(-1.0)]
    out = []
    for i in range(3):
        expr = Scalar({}, float(v0[i]))
        for k in range(3):
            expr = expr + rotation[k].scaled(float(np.cross(e[k], v0)[i]))
        out.append(expr)
    return out


def _kept(body: Body, at: Attachment, names: list[str], q0: np.ndarray, name: str
          ) -> list[Constraint]:
    """The lengths and mutual angles of the body's nodal vectors ``names`` at the attachment
    kept as built (dot products): a rigid section, so that ties to one of its directors
    turn it as a whole instead of shearing it."""
    vectors = [body.vector(at, n) for n in names]
    return [_dot(vectors[i], vectors[j], q0, f"{name}: {body.name}'s {names[i]} . {names[j]} "
                 "kept", []) for i in range(len(names)) for j in range(i, len(names))]


def _carried(body: Body, at: Attachment, k0: np.ndarray, q0: np.ndarray, name: str
             ) -> tuple[list[Scalar], list[Constraint]]:
    """The direction k0 (at t = 0) as the body carries it at the attachment (components),
    and the equations that make it turn with the body's section: a beam's section turn
    (:func:`_turned`) for an FFR beam in a fixed frame; otherwise its section directors with
    the section kept rigid there (:func:`_kept`); for other bodies a constant combination of
    their directions (the ground's are fixed)."""
    if isinstance(body, Ground):
        return [Scalar({}, float(c)) for c in k0], []
    basis = body.basis(at)
    coef = _express(basis, [b.value(q0) for b in basis], k0, f"joint {name!r}")
    if body.section_directors:
        if small_turn(body):
            return _turned(body, at, k0), []
        if coef[0] == 0.0:
            names = list(body.section_directors)
            directors = [body.vector(at, w) for w in names]
            return combination(directors, coef[1:]).components(), \
                _kept(body, at, names, q0, name)
    return combination(basis, coef).components(), []


def _section_ties(base: Beam, at_b: Attachment, held: Body, at_h: Attachment, ties: list,
                  q0: np.ndarray, name: str) -> list[Equation]:
    """Weld ties of the held vectors v0 = a n + b d_y + c d_z when some have a component a
    along the beam's axis n (d_y, d_z: its section directors r_y, r_z at the joint).

    The beam's r_x is the tangent of its centre line, which also turns with the shear strain
    and stretches; and a single director turns with the section's own shear. Tying v to
    either would pass the joint's moments through the beam's shear at one node, an error
    that grows as the mesh is refined. The held vectors follow the section's rotation:

    * an FFR beam in a fixed frame (small rotations, linear kinematics): v = v0 + w x v0
      (:func:`_turned`), linear equations consistent with the beam's kinematics;
    * otherwise (large rotations) v - b d_y - c d_z stays normal to both directors (two dot
      products) where a is not zero, v = b d_y + c d_z where it is, and the sections at the
      joint (the directors' lengths and angles, on both bodies) are kept as built, so that
      these ties measure rotations only (a rigid connector at the joint).
    """
    out: list[Equation] = []
    if small_turn(base):
        for which, v, _ in ties:
            turned = _turned(base, at_b, v.value(q0))
            out += [LinearEquation(v.component(i) - turned[i],
                                   f"{name}: {which} [{'xyz'[i]}] (section turn)", _dofs(v, i))
                    for i in range(3)]
        return out
    names = list(base.section_directors)
    directors = [base.vector(at_b, w) for w in names]
    for which, v, coef in ties:
        if coef[0] == 0.0:
            out += vector_equations(v, combination(directors, coef[1:]), f"{name}: {which}")
            continue
        w = v - combination(directors, coef[1:])
        prefer = [d for i in range(3) for d in _dofs(v, i)]
        out += [_dot(w, d, q0, f"{name}: {which} normal to {base.name}'s {dn}", prefer)
                for d, dn in zip(directors, names)]
    return out + _kept(base, at_b, names, q0, name) + \
        _kept(held, at_h, held.held_vectors(at_h), q0, name)


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
