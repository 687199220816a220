"""A small linear 3D frame finite-element code (reference for the tests, pure numpy/scipy).

What it models
--------------
Straight two-node beam elements (axial + torsion + bending in two planes) with either
Euler-Bernoulli or Timoshenko bending, consistent mass, on nodes placed anywhere in
space; axial bars (pin-ended two-force members); rigid bodies and point masses lumped at
nodes; supports (fixed degrees of freedom); hinges and other homogeneous linear ties
between nodes; nodal forces and moments; uniform distributed loads and self weight.
Outputs: static displacements and support reactions, the lowest natural frequencies
and mode shapes.

Units are SI (m, N, kg, s, Pa), angular frequencies in rad/s. Small displacements and
rotations, linear elastic material; loads act on the undeformed configuration.

Degrees of freedom
------------------
Six per node, in the global axes: ``ux, uy, uz`` (translations) and ``rx, ry, rz``
(small rotations about the global axes, right-handed). A *planar* frame
(``Frame(planar=True)``) lies in the x-y plane: ``uz, rx, ry`` are fixed at every node,
leaving ``ux, uy, rz``.

Beam element
------------
Local axes: x along the element (node 1 -> node 2); z along the section's *height*
axis (``height_axis``, default global z, or global y for an element parallel to z; its
component along x is removed); y = z cross x (the *width* direction). Section
properties (see the helpers ``rectangle``, ``box``, ``tube``, ``circle``):

* ``Iy = integral z^2 dA`` resists bending in the local x-z plane (deflection along the
  height), ``Iz = integral y^2 dA`` bending in the local x-y plane (deflection along the
  width). In a planar frame with the default height axis (global z), the in-plane
  bending stiffness is therefore E * Iz; give an in-plane ``height_axis`` (normal to
  the element) to bend with E * Iy instead.
* ``J`` is the Saint-Venant torsion constant used for the torsional stiffness G J:
  rectangles by the series solution (Timoshenko & Goodier, ch. 10), boxes by Bredt-Batho
  on the wall's midline plus the walls' own share p t^3 / 3, circles and tubes the polar
  moment (exact). The torsional mass rho Ip uses the polar moment ``Ip = Iy + Iz``, the
  exact polar mass moment per length for any section.
* The Timoshenko shear area is ``k A`` in both planes, with the shear coefficient
  ``k`` given per element (default 1.0, i.e. shear area = A, the project's choice).

Bending uses the "interdependent interpolation" element (Friedman & Kosmatka 1993):
cubic deflection and quadratic rotation fields that solve the homogeneous Timoshenko
equations exactly, with phi = 12 E I / (k G A L^2); phi = 0 is the Hermite
Euler-Bernoulli element. Stiffness, consistent mass and consistent load vectors are
integrated from these shape functions with 4-point Gauss quadrature (exact for the
polynomial integrands). Nodal displacements are exact (to rounding) for point loads at
nodes and uniform distributed loads, for both theories. Translational consistent mass
rho A; rotary inertia (rho Iy, rho Iz in bending) is included for Timoshenko elements and
left out for Euler-Bernoulli ones by default (``rotary_inertia`` overrides); torsional
mass rho Ip always.

Other members
-------------
* ``add_bar``: axial stiffness EA/L only, between the translations of two nodes (a
  pin-ended link, e.g. a hydraulic cylinder); consistent (rigid-body exact) mass.
* ``add_rigid_body``: exact small-motion mass matrix of a rigid body attached at a node
  with its centre of mass at an ``offset`` c from the node: the centre of mass moves by
  u + theta x c, so M = [[m I, -m [c]x], [m [c]x, J_c - m [c]x [c]x]] (the parallel-axis
  theorem in the rotational block). ``add_point_mass`` is a rigid body with no inertia
  at the node.
* ``add_hinge`` ties two coincident nodes: equal translations, and equal rotations
  except about ``axis`` (a revolute joint), or free rotations (``axis=None``, a spherical
  joint). ``add_rigid_link`` makes a node follow another rigidly (a massless rigid arm);
  ``add_tie`` / ``add_constraint`` state general homogeneous linear ties.

Constraints are imposed exactly: fixed dofs are removed, ties are eliminated with an
orthonormal null-space basis of the tie equations on the dofs they involve. A node
touched by no beam element and no rigid body gets its three rotations fixed
automatically (they carry no stiffness and no mass), unless a tie involves them.
Natural modes are solved in inverse form (see ``Frame.solve_modes``), so massless dofs
need no special treatment.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Mapping, Optional, Sequence

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "DOF_NAMES",
    "Section",
    "rectangle",
    "box",
    "tube",
    "circle",
    "Frame",
    "StaticResult",
    "ModalResult",
    "beam_local_matrices",
]

DOF_NAMES: tuple[str, ...] = ("ux", "uy", "uz", "rx", "ry", "rz")
_DOF_INDEX = {name: i for i, name in enumerate(DOF_NAMES)}
_PLANAR_FIXED = ("uz", "rx", "ry")
Theory = str  # "euler-bernoulli" | "timoshenko"
_THEORIES = ("euler-bernoulli", "timoshenko")


# ----------------------------------------------------------------------------- sections
@dataclass(frozen=True)
class Section:
    """Cross-section properties [m^2, m^4].

    ``Iy = integral z^2 dA`` (z along the height), ``Iz = integral y^2 dA`` (y along the
    width), ``J`` the Saint-Venant torsion constant, ``Ip = Iy + Iz`` the polar moment
    (torsional mass). The Timoshenko shear area is ``shear_area = A`` (shear coefficient
    1); an element may scale it with its own shear coefficient.
    """

    A: float
    Iy: float
    Iz: float
    J: float

    @property
    def Ip(self) -> float:
        """Polar second moment Iy + Iz (the torsional mass per length is rho Ip)."""
        return self.Iy + self.Iz

    @property
    def shear_area(self) -> float:
        """Timoshenko shear area with coefficient 1: the full area A."""
        return self.A


def _rectangle_torsion(width: float, height: float) -> float:
    """Saint-Venant J of a solid rectangle, t <= s its sides: the series of Timoshenko &
    Goodier (Theory of Elasticity, ch. 10), J = t^3 s (1/3 - (64 t / (pi^5 s))
    sum_{k >= 0} tanh((2k+1) pi s / (2t)) / (2k+1)^5), 60 terms."""
    t, s = sorted((width, height))
    total = sum(np.tanh((2 * k + 1) * np.pi * s / (2 * t)) / (2 * k + 1) ** 5 for k in range(60))
    return t**3 * s * (1.0 / 3.0 - 64.0 * t / (np.pi**5 * s) * total)


def rectangle(width: float, height: float) -> Section:
    """Solid rectangle: A = w h, Iy = w h^3/12, Iz = h w^3/12, J by the series."""
    _positive(width=width, height=height)
    iy, iz = width * height**3 / 12.0, height * width**3 / 12.0
    return Section(width * height, iy, iz, _rectangle_torsion(width, height))


def box(width: float, height: float, wall: float) -> Section:
    """Thin- or thick-walled rectangular box (outer width x height, uniform wall):
    outer rectangle minus the inner (w - 2t) x (h - 2t) one; J by Bredt-Batho on the
    midline, 4 A_m^2 t / p, plus the walls' open-section share p t^3 / 3."""
    _positive(width=width, height=height, wall=wall)
    if 2.0 * wall >= min(width, height):
        raise ValueError(
            f"box wall {wall} must be less than half of min(width, height) = {min(width, height)}"
        )
    outer, inner = rectangle(width, height), rectangle(width - 2 * wall, height - 2 * wall)
    perimeter = 2.0 * (width - wall + height - wall)
    mid_area = (width - wall) * (height - wall)
    j = 4.0 * mid_area**2 * wall / perimeter + perimeter * wall**3 / 3.0
    return Section(outer.A - inner.A, outer.Iy - inner.Iy, outer.Iz - inner.Iz, j)


def tube(diameter: float, wall: float) -> Section:
    """Circular tube (outer diameter D, wall t, inner d = D - 2t): A = pi (D^2 - d^2)/4,
    Iy = Iz = pi (D^4 - d^4)/64, J = Iy + Iz = pi (D^4 - d^4)/32."""
    _positive(diameter=diameter, wall=wall)
    if 2.0 * wall > diameter:
        raise ValueError(f"tube wall {wall} exceeds half the diameter {diameter}")
    inner = diameter - 2.0 * wall
    i = np.pi * (diameter**4 - inner**4) / 64.0
    return Section(np.pi * (diameter**2 - inner**2) / 4.0, i, i, 2.0 * i)


def circle(diameter: float) -> Section:
    """Solid circle: A = pi D^2/4, Iy = Iz = pi D^4/64, J = pi D^4/32."""
    _positive(diameter=diameter)
    i = np.pi * diameter**4 / 64.0
    return Section(np.pi * diameter**2 / 4.0, i, i, 2.0 * i)


def _positive(**values: float) -> None:
    for name, value in values.items():
        if not (np.isfinite(value) and value > 0.0):
            raise ValueError(f"{name} must be a positive number, got {value!r}")


# ------------------------------------------------------------------- element matrices
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(4)
_GAUSS_XI = 0.5 * (_GAUSS_X + 1.0)  # points on [0, 1]
_GAUSS_WXI = 0.5 * _GAUSS_W  # weights on [0, 1]

# local dof order: u1 v1 w1 rx1 ry1 rz1 u2 v2 w2 rx2 ry2 rz2
_AXIAL = np.array([0, 6])
_TORSION = np.array([3, 9])
_PLANE_XY = np.array([1, 5, 7, 11])  # (v, rz): rz = +dv/dx
_PLANE_XZ = np.array([2, 4, 8, 10])  # (w, ry): ry = -dw/dx
_SIGN_XZ = np.array([1.0, -1.0, 1.0, -1.0])


def _bending_shapes(L: NDArray, phi: NDArray):
    """Interdependent Timoshenko shape functions at the Gauss points.

    Generic plane dofs (v1, t1, v2, t2) with t the section rotation (t = dv/dx for
    phi = 0). Returns Nv, dNv/dx, Nt, dNt/dx, each of shape (n_elements, n_gauss, 4).
    """
    x = _GAUSS_XI[None, :]
    L = L[:, None]
    p = phi[:, None]
    d = 1.0 + p
    nv = np.stack(
        [
            (2 * x**3 - 3 * x**2 - p * x + 1 + p) / d,
            L * (x**3 - (2 + p / 2) * x**2 + (1 + p / 2) * x) / d,
            -(2 * x**3 - 3 * x**2 - p * x) / d,
            L * (x**3 - (1 - p / 2) * x**2 - (p / 2) * x) / d,
        ],
        axis=-1,
    )
    dnv = np.stack(
        [
            (6 * x**2 - 6 * x - p) / (d * L),
            (3 * x**2 - (4 + p) * x + 1 + p / 2) / d,
            -(6 * x**2 - 6 * x - p) / (d * L),
            (3 * x**2 - (2 - p) * x - p / 2) / d,
        ],
        axis=-1,
    )
    nt = np.stack(
        [
            6 * (x**2 - x) / (d * L),
            (3 * x**2 - (4 + p) * x + 1 + p) / d,
            -6 * (x**2 - x) / (d * L),
            (3 * x**2 - (2 - p) * x) / d,
        ],
        axis=-1,
    )
    dnt = np.stack(
        [
            6 * (2 * x - 1) / (d * L**2),
            (6 * x - (4 + p)) / (d * L),
            -6 * (2 * x - 1) / (d * L**2),
            (6 * x - (2 - p)) / (d * L),
        ],
        axis=-1,
    )
    return nv, dnv, nt, dnt


def _plane_matrices(L, EI, GAs, rhoA, rhoI, timoshenko):
    """4x4 bending stiffness, mass and unit-load vectors of one bending plane for all
    elements: K = int EI t'^2 + GAs (v' - t)^2, M = int rhoA v^2 + rhoI t^2, f = int Nv."""
    phi = np.where(timoshenko, 12.0 * EI / (GAs * L**2), 0.0)
    nv, dnv, nt, dnt = _bending_shapes(L, phi)
    wl = _GAUSS_WXI[None, :] * L[:, None]  # (ne, ng) weights * L
    gamma = dnv - nt
    shear = np.where(timoshenko, GAs, 0.0)
    K = np.einsum("eg,egi,egj->eij", wl * EI[:, None], dnt, dnt) + np.einsum(
        "eg,egi,egj->eij", wl * shear[:, None], gamma, gamma
    )
    M = np.einsum("eg,egi,egj->eij", wl * rhoA[:, None], nv, nv) + np.einsum(
        "eg,egi,egj->eij", wl * rhoI[:, None], nt, nt
    )
    f = np.einsum("eg,egi->ei", wl, nv)
    return K, M, f


def beam_local_matrices(L, E, G, A, Iy, Iz, J, rho, timoshenko, rotary_inertia, shear_coefficient):
    """Local 12x12 stiffness and consistent mass matrices and the 12x3 consistent load
    operator (local uniform load per length q -> nodal loads) of straight beam elements.

    All arguments are arrays of shape (n_elements,) (``timoshenko`` and
    ``rotary_inertia`` boolean). Returns K (ne, 12, 12), M (ne, 12, 12), Q (ne, 12, 3)
    with f_local = Q @ q_local. Local dof order u1 v1 w1 rx1 ry1 rz1 u2 ... rz2.
    """
    L, E, G, A, Iy, Iz, J, rho, k = (
        np.asarray(a, dtype=float) for a in (L, E, G, A, Iy, Iz, J, rho, shear_coefficient)
    )
    timoshenko = np.asarray(timoshenko, dtype=bool)
    rot = np.asarray(rotary_inertia, dtype=bool)
    ne = L.shape[0]
    K = np.zeros((ne, 12, 12))
    M = np.zeros((ne, 12, 12))
    Q = np.zeros((ne, 12, 3))
    two = np.array([[1.0, -1.0], [-1.0, 1.0]])
    lumped = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0
    Ip = Iy + Iz
    for idx, stiff, mass in ((_AXIAL, E * A, rho * A), (_TORSION, G * J, rho * Ip)):
        K[:, idx[:, None], idx[None, :]] = (stiff / L)[:, None, None] * two
        M[:, idx[:, None], idx[None, :]] = (mass * L)[:, None, None] * lumped
    Q[:, _AXIAL, 0] = 0.5 * L[:, None]
    GAs = G * k * A
    for idx, sign, inertia, axis in ((_PLANE_XY, np.ones(4), Iz, 1), (_PLANE_XZ, _SIGN_XZ, Iy, 2)):
        Kp, Mp, fp = _plane_matrices(
            L, E * inertia, GAs, rho * A, np.where(rot, rho * inertia, 0.0), timoshenko
        )
        s = np.outer(sign, sign)
        K[:, idx[:, None], idx[None, :]] = Kp * s
        M[:, idx[:, None], idx[None, :]] = Mp * s
        Q[:, idx, axis] = fp * sign
    return K, M, Q


def _local_axes(x1: NDArray, x2: NDArray, height_axis: Optional[ArrayLike]) -> tuple[float, NDArray]:
    """Length and rotation matrix (rows: local x, y, z in global components) of an element."""
    d = x2 - x1
    L = float(np.linalg.norm(d))
    if L == 0.0:
        raise ValueError("element has zero length (its two nodes coincide)")
    ex = d / L
    if height_axis is None:
        h = np.array([0.0, 0.0, 1.0]) if abs(ex[2]) < 1.0 - 1e-12 else np.array([0.0, 1.0, 0.0])
    else:
        h = np.asarray(height_axis, dtype=float)
    ez = h - np.dot(h, ex) * ex
    nz = np.linalg.norm(ez)
    if nz < 1e-9 * max(1.0, np.linalg.norm(h)):
        raise ValueError(f"height_axis {h} is parallel to the element axis {ex}")
    ez /= nz
    ey = np.cross(ez, ex)
    return L, np.vstack([ex, ey, ez])


def _skew(c: NDArray) -> NDArray:
    """Cross-product matrix [c]x with [c]x v = c x v."""
    return np.array([[0.0, -c[2], c[1]], [c[2], 0.0, -c[0]], [-c[1], c[0], 0.0]])


# ------------------------------------------------------------------------ the model
@dataclass
class _Beam:
    n1: int
    n2: int
    E: float
    G: float
    section: Section
    rho: float
    timoshenko: bool
    rotary_inertia: bool
    shear_coefficient: float
    height_axis: Optional[NDArray]


@dataclass
class _Bar:
    n1: int
    n2: int
    EA: float
    rho_A: float


@dataclass(frozen=True)
class StaticResult:
    """Static solution.

    ``displacements`` (n_nodes, 6): ux, uy, uz [m], rx, ry, rz [rad] per node (global).
    ``reactions`` (n_nodes, 6): support forces [N] and moments [N m] at the fixed dofs
    (K u - f there, i.e. what the support applies to the structure), zero elsewhere.
    ``load`` (n_nodes, 6): the assembled external load vector f (nodal equivalents).
    """

    displacements: NDArray[np.float64]
    reactions: NDArray[np.float64]
    load: NDArray[np.float64]


@dataclass(frozen=True)
class ModalResult:
    """Natural modes: ``omega`` (n,) angular frequencies [rad/s], ascending;
    ``frequency_hz`` = omega / 2 pi; ``modes`` (n, n_nodes, 6) mass-normalized shapes."""

    omega: NDArray[np.float64]
    modes: NDArray[np.float64]

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        return self.omega / (2.0 * np.pi)


class Frame:
    """A linear frame model, built by method calls, then solved.

    ``planar=True``: the frame lies in the x-y plane; the out-of-plane dofs uz, rx, ry
    of every node are fixed. Node and element indices are 0-based integers returned by
    the ``add_*`` methods.
    """

    def __init__(self, planar: bool = False) -> None:
        self.planar = bool(planar)
        self._nodes: list[NDArray[np.float64]] = []
        self._beams: list[_Beam] = []
        self._bars: list[_Bar] = []
        self._masses: list[tuple] = []  # (node, 6x6 mass, mass, offset, has rotary inertia)
        self._fixed: set[int] = set()  # global dof indices
        self._ties: list[dict[int, float]] = []  # rows {global dof: coefficient}, sum = 0
        self._nodal: dict[int, NDArray[np.float64]] = {}
        self._distributed: list[tuple[int, NDArray[np.float64]]] = []  # (beam, global q)

    # --- geometry and members -------------------------------------------------------
    def add_node(self, position: ArrayLike) -> int:
        """Add a node at ``position`` (2 or 3 coordinates [m]; z = 0 if 2). Returns its index."""
        p = np.zeros(3)
        q = np.asarray(position, dtype=float).ravel()
        if q.size not in (2, 3):
            raise ValueError(f"node position needs 2 or 3 coordinates, got {q.size}")
        p[: q.size] = q
        if self.planar and p[2] != 0.0:
            raise ValueError(f"planar frame: node {len(self._nodes)} must have z = 0, got {p[2]}")
        self._nodes.append(p)
        return len(self._nodes) - 1

    def add_beam(
        self,
        n1: int,
        n2: int,
        E: float,
        G: float,
        section: Section,
        rho: float = 0.0,
        theory: Theory = "euler-bernoulli",
        shear_coefficient: float = 1.0,
        rotary_inertia: Optional[bool] = None,
        height_axis: Optional[ArrayLike] = None,
    ) -> int:
        """Add a beam element between nodes ``n1`` and ``n2``.

        ``E``, ``G`` [Pa]; ``section`` (A, Iy, Iz, J); ``rho`` [kg/m^3] (0: massless);
        ``theory`` 'euler-bernoulli' or 'timoshenko' (shear area ``shear_coefficient * A``);
        ``rotary_inertia`` defaults to True for Timoshenko, False for Euler-Bernoulli;
        ``height_axis`` sets the local z axis (see the module docstring). Returns the
        element index.
        """
        self._check_node(n1), self._check_node(n2)
        if theory not in _THEORIES:
            raise ValueError(f"theory must be one of {_THEORIES}, got {theory!r}")
        _positive(E=E, G=G, shear_coefficient=shear_coefficient)
        timo = theory == "timoshenko"
        rot = timo if rotary_inertia is None else bool(rotary_inertia)
        axis = None if height_axis is None else np.asarray(height_axis, dtype=float)
        _local_axes(self._nodes[n1], self._nodes[n2], axis)  # validates now
        self._beams.append(
            _Beam(
                n1, n2, float(E), float(G), section, float(rho), timo, rot, float(shear_coefficient), axis
            )
        )
        return len(self._beams) - 1

    def add_beam_line(
        self,
        start: ArrayLike,
        end: ArrayLike,
        n_elements: int,
        E: float,
        G: float,
        section: Section,
        rho: float = 0.0,
        start_node: Optional[int] = None,
        end_node: Optional[int] = None,
        interior: Sequence[float] = (),
        **options,
    ) -> list[int]:
        """Mesh a straight member from ``start`` to ``end`` into ``n_elements`` equal
        elements per segment, returning the list of its node indices in order.

        ``start_node`` / ``end_node`` reuse existing nodes at the ends (their positions
        must match). ``interior`` lists fractions in (0, 1) of the member length where a
        node must lie (e.g. a lug): the member is split there first and every segment
        gets ``n_elements`` elements. ``options`` go to ``add_beam``.
        """
        a, b = np.zeros(3), np.zeros(3)
        a[: len(start)] = start
        b[: len(end)] = end
        cuts = np.unique(np.concatenate([[0.0], np.asarray(interior, dtype=float), [1.0]]))
        if cuts[0] < 0.0 or cuts[-1] > 1.0:
            raise ValueError("interior fractions must lie in (0, 1)")
        fractions = np.unique(
            np.concatenate([np.linspace(c0, c1, n_elements + 1) for c0, c1 in zip(cuts[:-1], cuts[1:])])
        )
        nodes: list[int] = []
        for i, t in enumerate(fractions):
            pos = a + t * (b - a)
            if i == 0 and start_node is not None:
                self._check_position(start_node, pos)
                nodes.append(start_node)
            elif i == len(fractions) - 1 and end_node is not None:
                self._check_position(end_node, pos)
                nodes.append(end_node)
            else:
                nodes.append(self.add_node(pos))
        for n1, n2 in zip(nodes[:-1], nodes[1:]):
            self.add_beam(n1, n2, E, G, section, rho, **options)
        return nodes

    def add_bar(self, n1: int, n2: int, EA: float, rho_A: float = 0.0) -> int:
        """Add an axial bar (pin-ended link) of stiffness ``EA`` [N] and mass per length
        ``rho_A`` [kg/m] between the translations of nodes ``n1`` and ``n2``."""
        self._check_node(n1), self._check_node(n2)
        _positive(EA=EA)
        if np.linalg.norm(self._nodes[n2] - self._nodes[n1]) == 0.0:
            raise ValueError("bar has zero length")
        self._bars.append(_Bar(n1, n2, float(EA), float(rho_A)))
        return len(self._bars) - 1

    def add_rigid_body(
        self, node: int, mass: float, inertia: ArrayLike = 0.0, offset: ArrayLike = (0.0, 0.0, 0.0)
    ) -> None:
        """Attach a rigid body to ``node``: ``mass`` [kg], ``inertia`` [kg m^2] about its
        centre of mass in global axes (3x3, or 3 principal values, or one scalar used for
        all three), centre of mass at ``offset`` [m] from the node (2 or 3 components).
        Uses the exact small-motion 6x6 mass matrix about the node (module docstring)."""
        self._check_node(node)
        J = np.asarray(inertia, dtype=float)
        J = np.diag(np.broadcast_to(J, (3,))) if J.ndim <= 1 else J
        if J.shape != (3, 3) or not np.allclose(J, J.T):
            raise ValueError("rigid-body inertia must be symmetric 3x3, 3 values or a scalar")
        c = np.zeros(3)
        off = np.asarray(offset, dtype=float).ravel()
        c[: off.size] = off
        C = _skew(c)
        Mb = np.zeros((6, 6))
        Mb[:3, :3] = mass * np.eye(3)
        Mb[:3, 3:] = -mass * C
        Mb[3:, :3] = mass * C
        Mb[3:, 3:] = J - mass * C @ C
        self._masses.append((node, Mb, float(mass), c, bool(np.any(J != 0.0) or np.any(c != 0.0))))

    def add_point_mass(self, node: int, mass: float) -> None:
        """Attach a point mass [kg] at ``node`` (translational inertia only)."""
        self.add_rigid_body(node, mass, 0.0, (0.0, 0.0, 0.0))

    # --- supports and ties -------------------------------------------------------------
    def fix(self, node: int, dofs: Iterable[str] = DOF_NAMES) -> None:
        """Fix the named dofs (from ``DOF_NAMES``) of ``node``; default: all six (a clamp)."""
        self._check_node(node)
        for name in dofs:
            self._fixed.add(6 * node + self._dof(name))

    def add_constraint(self, coefficients: Mapping[tuple[int, str], float]) -> None:
        """Add one homogeneous linear tie: sum of coefficient * dof = 0, the dofs given
        as (node, dof name) keys."""
        row = {}
        for (node, name), value in coefficients.items():
            self._check_node(node)
            row[6 * node + self._dof(name)] = row.get(6 * node + self._dof(name), 0.0) + float(value)
        self._ties.append(row)

    def add_tie(self, node_a: int, node_b: int, dofs: Iterable[str] = DOF_NAMES) -> None:
        """Make the named dofs of ``node_b`` equal to those of ``node_a`` (all six: a weld)."""
        for name in dofs:
            self.add_constraint({(node_a, name): 1.0, (node_b, name): -1.0})

    def add_hinge(self, node_a: int, node_b: int, axis: Optional[ArrayLike] = None) -> None:
        """Join two coincident nodes by a hinge: equal translations; rotations equal
        except about ``axis`` (revolute joint) or independent (``axis=None``: spherical
        joint). In a planar frame the hinge axis is z (either choice gives it)."""
        self._check_position(node_b, self._nodes[node_a])
        self.add_tie(node_a, node_b, ("ux", "uy", "uz"))
        if axis is None:
            return
        a = np.asarray(axis, dtype=float)
        a = a / np.linalg.norm(a)
        # two unit vectors normal to the axis: the relative rotation has no component along them
        basis = scipy.linalg.null_space(a[None, :]).T
        for p in basis:
            self.add_constraint(
                {(node_a, r): p[i] for i, r in enumerate(("rx", "ry", "rz"))}
                | {(node_b, r): -p[i] for i, r in enumerate(("rx", "ry", "rz"))}
            )

    def add_rigid_link(self, master: int, slave: int) -> None:
        """Tie ``slave`` rigidly to ``master`` (a massless rigid arm, e.g. a lug offset):
        u_s = u_m + theta_m x (x_s - x_m), theta_s = theta_m (small rotations)."""
        self._check_node(master), self._check_node(slave)
        d = self._nodes[slave] - self._nodes[master]
        # rows of theta x d = [d]x^T theta = -[d]x theta
        rot = -_skew(d)
        for i, name in enumerate(("ux", "uy", "uz")):
            row = {(slave, name): 1.0, (master, name): -1.0}
            for j, r in enumerate(("rx", "ry", "rz")):
                if rot[i, j] != 0.0:
                    row[(master, r)] = -rot[i, j]
            self.add_constraint(row)
        self.add_tie(master, slave, ("rx", "ry", "rz"))

    # --- loads -------------------------------------------------------------------------
    def add_nodal_load(
        self, node: int, force: ArrayLike = (0.0, 0.0, 0.0), moment: ArrayLike = (0.0, 0.0, 0.0)
    ) -> None:
        """Add a point ``force`` [N] (2 or 3 components) and ``moment`` [N m] (3 components,
        or one scalar = moment about z) at ``node``, global axes."""
        self._check_node(node)
        f = np.zeros(6)
        fv = np.asarray(force, dtype=float).ravel()
        f[: fv.size] = fv
        mv = np.asarray(moment, dtype=float).ravel()
        if mv.size == 1:
            f[5] = mv[0]
        else:
            f[3:6] = mv
        self._nodal[node] = self._nodal.get(node, np.zeros(6)) + f

    def add_distributed_load(self, element: int, q: ArrayLike) -> None:
        """Add a uniform load ``q`` [N/m] (global force per unit length, 2 or 3
        components) on beam ``element``; consistent nodal loads."""
        if not 0 <= element < len(self._beams):
            raise ValueError(f"no beam element {element}")
        v = np.zeros(3)
        qv = np.asarray(q, dtype=float).ravel()
        v[: qv.size] = qv
        self._distributed.append((element, v))

    # --- assembly ------------------------------------------------------------------------
    @property
    def n_nodes(self) -> int:
        return len(self._nodes)

    @property
    def nodes(self) -> NDArray[np.float64]:
        """Node positions (n_nodes, 3) [m]."""
        return np.array(self._nodes).reshape(-1, 3)

    def _beam_arrays(self):
        """Global 12x12 K, M, the 12x3 global load operator and the dof maps of all beams."""
        ne = len(self._beams)
        if ne == 0:
            return (
                np.zeros((0, 12, 12)),
                np.zeros((0, 12, 12)),
                np.zeros((0, 12, 3)),
                np.zeros((0, 12), int),
                np.zeros(0),
            )
        L = np.empty(ne)
        R = np.empty((ne, 3, 3))
        for e, b in enumerate(self._beams):
            L[e], R[e] = _local_axes(self._nodes[b.n1], self._nodes[b.n2], b.height_axis)
        get = lambda attr: np.array([getattr(b, attr) for b in self._beams])  # noqa: E731
        sec = lambda attr: np.array([getattr(b.section, attr) for b in self._beams])  # noqa: E731
        Kl, Ml, Ql = beam_local_matrices(
            L,
            get("E"),
            get("G"),
            sec("A"),
            sec("Iy"),
            sec("Iz"),
            sec("J"),
            get("rho"),
            get("timoshenko"),
            get("rotary_inertia"),
            get("shear_coefficient"),
        )
        T = np.zeros((ne, 12, 12))
        for k in range(4):
            T[:, 3 * k : 3 * k + 3, 3 * k : 3 * k + 3] = R
        Kg = np.einsum("eai,eab,ebj->eij", T, Kl, T)
        Mg = np.einsum("eai,eab,ebj->eij", T, Ml, T)
        Qg = np.einsum("eai,eab,ebj->eij", T, Ql, R)  # global q -> global nodal loads
        n1, n2 = get("n1"), get("n2")
        dofs = np.concatenate([6 * n1[:, None] + np.arange(6), 6 * n2[:, None] + np.arange(6)], axis=1)
        return Kg, Mg, Qg, dofs, sec("A") * get("rho")

    def assemble(self, gravity: Optional[ArrayLike] = None):
        """Global stiffness K, mass M (6 n_nodes square) and load vector f.

        ``gravity`` [m/s^2] (2 or 3 components) adds the self weight of beams (uniform
        rho A g, consistent), bars, point masses and rigid bodies (m g at the centre of
        mass: a force at the node and the moment offset x m g).
        """
        n = 6 * self.n_nodes
        K, M, f = np.zeros((n, n)), np.zeros((n, n)), np.zeros(n)
        Kg, Mg, Qg, dofs, rhoA = self._beam_arrays()
        np.add.at(K, (dofs[:, :, None], dofs[:, None, :]), Kg)
        np.add.at(M, (dofs[:, :, None], dofs[:, None, :]), Mg)
        g = np.zeros(3)
        if gravity is not None:
            gv = np.asarray(gravity, dtype=float).ravel()
            g[: gv.size] = gv
        for e, q in self._distributed:
            np.add.at(f, dofs[e], Qg[e] @ q)
        if len(self._beams):
            np.add.at(f, dofs, np.einsum("eij,j->ei", Qg, g) * rhoA[:, None])
        for bar in self._bars:
            d = self._nodes[bar.n2] - self._nodes[bar.n1]
            L = np.linalg.norm(d)
            e = d / L
            k = bar.EA / L * np.outer(e, e)
            idx = np.concatenate([6 * bar.n1 + np.arange(3), 6 * bar.n2 + np.arange(3)])
            K[np.ix_(idx, idx)] += np.block([[k, -k], [-k, k]])
            M[np.ix_(idx, idx)] += (
                bar.rho_A * L / 6.0 * np.kron(np.array([[2.0, 1.0], [1.0, 2.0]]), np.eye(3))
            )
            f[idx] += np.tile(0.5 * bar.rho_A * L * g, 2)
        for node, Mb, mass, c, _ in self._masses:
            idx = 6 * node + np.arange(6)
            M[np.ix_(idx, idx)] += Mb
            f[idx] += np.concatenate([mass * g, np.cross(c, mass * g)])
        for node, load in self._nodal.items():
            f[6 * node : 6 * node + 6] += load
        return K, M, f

    def _basis(self):
        """Fixed dofs and the basis T (n_dof x n_reduced) of admissible displacements u = T a."""
        n = 6 * self.n_nodes
        fixed = set(self._fixed)
        if self.planar:
            fixed |= {6 * i + _DOF_INDEX[d] for i in range(self.n_nodes) for d in _PLANAR_FIXED}
        rotating = (
            {b.n1 for b in self._beams}
            | {b.n2 for b in self._beams}
            | {m[0] for m in self._masses if m[4]}
            | {d // 6 for row in self._ties for d in row if d % 6 >= 3}
        )
        fixed |= {6 * i + r for i in range(self.n_nodes) if i not in rotating for r in (3, 4, 5)}
        free = np.array([i for i in range(n) if i not in fixed], dtype=int)
        col = {d: j for j, d in enumerate(free)}
        if self._ties:
            C = np.zeros((len(self._ties), free.size))
            for r, row in enumerate(self._ties):
                for d, v in row.items():
                    if d in col:
                        C[r, col[d]] += v
            involved = np.flatnonzero(np.any(C != 0.0, axis=0))
            N = scipy.linalg.null_space(C[:, involved])
        else:
            involved, N = np.zeros(0, dtype=int), np.zeros((0, 0))
        untouched = np.setdiff1d(np.arange(free.size), involved)
        T = np.zeros((n, untouched.size + N.shape[1]))
        T[free[untouched], np.arange(untouched.size)] = 1.0
        T[np.ix_(free[involved], untouched.size + np.arange(N.shape[1]))] = N
        return np.array(sorted(fixed), dtype=int), T

    # --- solutions -----------------------------------------------------------------------
    def solve_static(self, gravity: Optional[ArrayLike] = None) -> StaticResult:
        """Linear static solution under the nodal and distributed loads (and the self
        weight if ``gravity`` is given). Raises ValueError if the constrained stiffness is
        singular (a mechanism or an unsupported structure)."""
        K, _, f = self.assemble(gravity)
        fixed, T = self._basis()
        Kr = T.T @ K @ T
        try:
            cho = scipy.linalg.cho_factor(Kr)
        except np.linalg.LinAlgError as exc:
            raise ValueError(
                "the constrained stiffness matrix is singular: the frame is a mechanism "
                "or is not supported enough"
            ) from exc
        u = T @ scipy.linalg.cho_solve(cho, T.T @ f)
        reactions = np.zeros_like(f)
        reactions[fixed] = (K @ u - f)[fixed]
        shape = (self.n_nodes, 6)
        return StaticResult(u.reshape(shape), reactions.reshape(shape), f.reshape(shape))

    def solve_modes(self, n_modes: int) -> ModalResult:
        """The ``n_modes`` lowest natural frequencies and mass-normalized mode shapes.

        Solved in inverse form, ``scipy.linalg.eigh(M_r, K_r + sigma M_r)`` on the
        constrained matrices, keeping the largest eigenvalues mu = 1/(omega^2 + sigma):
        the low modes then have full relative precision (the direct form K v = w^2 M v
        loses eps * w_max^2 / w^2), and massless dofs need no condensation (they give
        mu = 0, infinite frequency). sigma = 0 when K_r is positive definite; otherwise
        (rigid-body modes) a small positive shift. Fewer than ``n_modes`` are returned if
        the model has fewer dofs with mass.
        """
        K, M, _ = self.assemble()
        _, T = self._basis()
        Kr, Mr = T.T @ K @ T, T.T @ M @ T
        sigma = 0.0
        try:
            scipy.linalg.cho_factor(Kr)
        except np.linalg.LinAlgError:
            sigma = 1e-6 * np.trace(Kr) / max(np.trace(Mr), np.finfo(float).tiny)
        n = Kr.shape[0]
        n_modes = min(n_modes, n)
        mu, vec = scipy.linalg.eigh(Mr, Kr + sigma * Mr, subset_by_index=[n - n_modes, n - 1])
        mu, vec = mu[::-1], vec[:, ::-1]
        keep = mu > 1e-12 * mu[0]
        mu, vec = mu[keep], vec[:, keep]
        vec = vec / np.sqrt(np.einsum("ik,ij,jk->k", vec, Mr, vec))
        omega = np.sqrt(np.clip(1.0 / mu - sigma, 0.0, None))
        modes = (T @ vec).T.reshape(mu.size, self.n_nodes, 6)
        return ModalResult(omega, modes)

    # --- checks ----------------------------------------------------------------------------
    def _check_node(self, node: int) -> None:
        if not (isinstance(node, (int, np.integer)) and 0 <= node < len(self._nodes)):
            raise ValueError(f"no node {node!r} (the frame has {len(self._nodes)} nodes)")

    def _check_position(self, node: int, position: NDArray) -> None:
        self._check_node(node)
        if not np.allclose(
            self._nodes[node], position, rtol=0.0, atol=1e-12 * max(1.0, np.abs(position).max())
        ):
            raise ValueError(f"node {node} at {self._nodes[node]} is not at {position}")

    @staticmethod
    def _dof(name: str) -> int:
        if name not in _DOF_INDEX:
            raise ValueError(f"unknown dof {name!r}; expected one of {DOF_NAMES}")
        return _DOF_INDEX[name]
