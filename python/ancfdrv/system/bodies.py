"""Bodies: ANCF beams (floating-frame or large-deformation, continuum or 'cubic' bending),
thin plates and curved leaves (plain or completed element, optional prestress), rigid bodies
as ANCF reference nodes, and the ground.

A body knows its geometry at t = 0 (global coordinates, metres), its coordinates (once the
assembly has given it its first index ``first`` in the full vector q) and how any of its
material points is written in them (:class:`~.expressions.Vec3`): joints, loads and probes
are built from these attachments.

Coordinates per node: beams [r, r_x, r_y, r_z] (12; r_x along the axis, r_y along the
section height, r_z along its width), plates and leaves [r, r_x, r_y] (9), rigid bodies
[r, r_x, r_y, r_z] (12; r the centre of mass, J = [r_x r_y r_z] the orientation, a point at
body coordinates u is at r + J u; J = I at t = 0, the body axes are the global axes).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import kernel
from ..errors import InputError
from .expressions import Vec3
from .meshes import PlateMesh, arc_mesh, flat_mesh
from .sections import Rectangle, Section

BEAM_NODE_DOFS = 12
PLATE_NODE_DOFS = 9
RIGID_DOFS = 12
#: offsets of the nodal vectors within a node's coordinates
VECTOR_OFFSETS = {"r": 0, "r_x": 3, "r_y": 6, "r_z": 9}
FORMULATIONS = ("ffr", "nonlinear")
BENDING = ("continuum", "cubic")
VARIANTS = ("plain", "completed")


def linspace(start: float, stop: float, num: int) -> np.ndarray:
    """``np.linspace(start, stop, num)`` for float ends, bit for bit, with numpy's own
    arithmetic written out (arange(num) * ((stop - start) / (num - 1)) + start, the last
    point stop) without its generic machinery (~10 us a call); the cases that take numpy's
    other branches (num < 2, a zero step) go to np.linspace."""
    start, stop = float(start), float(stop)
    if num < 2:
        return np.linspace(start, stop, num)
    step = (stop - start) / (num - 1)
    if step == 0.0:
        return np.linspace(start, stop, num)
    out = np.arange(num, dtype=float)
    out *= step
    out += start
    out[-1] = stop
    return out


def _vec(value, what: str, name: str) -> np.ndarray:
    v = np.asarray(value, dtype=float).ravel()
    if v.shape != (3,) or not all(map(math.isfinite, v.tolist())):   # (np.isfinite(v).all())
        raise InputError(f"{name}: {what} must be three finite numbers, got {value!r}")
    return v


def _positive(value: float, what: str, name: str) -> float:
    if not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
        raise InputError(f"{name}: {what} must be a positive number, got {value!r}")
    return float(value)


def rotation_about(axis, angle: float) -> np.ndarray:
    """Rodrigues' rotation matrix about a unit axis."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    skew = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * skew + (1.0 - np.cos(angle)) * skew @ skew


@dataclass(frozen=True)
class Material:
    """Isotropic elastic material, with optional Kelvin-Voigt damping: the stress is
    D (strain + damping_time * strain rate) for every strain the elements use (applied only
    when the effect 'damping' is listed; a linear structure then has the stiffness-
    proportional damping C = damping_time K, modal damping ratios damping_time omega_n / 2)."""

    name: str
    youngs_modulus: float
    density: float
    poisson_ratio: float = 0.0
    damping_time: float = 0.0

    def __post_init__(self) -> None:
        _positive(self.youngs_modulus, "youngs_modulus", f"material {self.name!r}")
        _positive(self.density, "density", f"material {self.name!r}")
        if not 0.0 <= self.poisson_ratio < 0.5:
            raise InputError(f"material {self.name!r}: poisson_ratio {self.poisson_ratio} must "
                             "lie in [0, 0.5)")
        if not (isinstance(self.damping_time, (int, float)) and np.isfinite(self.damping_time)
                and self.damping_time >= 0):
            raise InputError(f"material {self.name!r}: damping_time {self.damping_time!r} must "
                             "be a finite number >= 0 (s)")


@dataclass
class Attachment:
    """Where a joint, load or probe acts on a body: a node (flexible bodies) and/or the
    material point's element and local coordinates."""

    node: int | None = None
    element: int | None = None
    local: tuple[float, ...] = ()


class Body:
    """Base of every body: a unique name and, after numbering, the first full coordinate."""

    name: str
    first: int = -1
    flexible = False

    @property
    def ncoordinates(self) -> int:
        raise NotImplementedError

    def coordinates(self) -> np.ndarray:
        """Initial coordinates (ncoordinates,)."""
        raise NotImplementedError

    def locate(self, point, *, node: bool, what: str) -> Attachment:
        raise NotImplementedError

    def position(self, at: Attachment) -> Vec3:
        """The material point's position."""
        raise NotImplementedError

    def vector(self, at: Attachment, which: str) -> Vec3:
        """A nodal vector ('r', 'r_x', 'r_y', 'r_z') at a node (rigid body: of the body)."""
        raise NotImplementedError

    def basis(self, at: Attachment) -> list[Vec3]:
        """Direction vectors at the attachment that welds and hinge axes are written in."""
        raise NotImplementedError

    def held_vectors(self, at: Attachment) -> list[str]:
        """The nodal vectors a weld holds on this body (its section or orientation)."""
        raise NotImplementedError

    def directors(self, at: Attachment) -> list[str]:
        """Nodal vectors a dead moment can act on (the rotation is measured on them)."""
        raise NotImplementedError


class Ground(Body):
    """The fixed world; its name 'ground' is reserved."""

    def __init__(self) -> None:
        self.name = "ground"

    @property
    def ncoordinates(self) -> int:
        return 0

    def coordinates(self) -> np.ndarray:
        return np.zeros(0)

    def locate(self, point, *, node: bool, what: str) -> Attachment:
        return Attachment(local=tuple(np.asarray(point, dtype=float)))

    def position(self, at: Attachment) -> Vec3:
        return Vec3.constant(at.local)

    def vector(self, at: Attachment, which: str) -> Vec3:
        if which == "r":
            return Vec3.constant(at.local)
        return Vec3.constant(np.eye(3)[VECTOR_OFFSETS[which] // 3 - 1])

    def basis(self, at: Attachment) -> list[Vec3]:
        return [Vec3.constant(row) for row in np.eye(3)]

    def held_vectors(self, at: Attachment) -> list[str]:
        return []

    def directors(self, at: Attachment) -> list[str]:
        return []


class Beam(Body):
    """A straight ANCF beam from ``start`` to ``end`` with ``nodes`` nodes (equally spaced, or
    equally within each of ``segments``, whose lengths add up to the beam's), section
    height along ``height_axis`` (default global z; y for a beam along z), formulation
    'ffr' (small strain in a floating frame) or 'nonlinear' (large deformation), bending
    'continuum' or 'cubic'. Its frame is the body frame (axis, height, width directions) at
    t = 0, turned by ``frame_drive`` about ``frame_axis`` through ``frame_pivot`` (default:
    the start) when given: for 'ffr' the elastic model lives in it, for either formulation
    probe deflections are resolved in it. ``geometric_stiffness`` (for 'ffr'): the
    geometric stiffness of the current axial force (P-delta, docs/theory.md, 'FFR geometric stiffness').
    ``modes`` (for 'ffr', dynamic runs): 0 integrates every coordinate, N > 0 the modal
    reduction with N modes (:mod:`ancfdrv.solvers.ffr_reduced`)."""

    flexible = True

    def __init__(self, name: str, material: Material, start, end, nodes: int,
                 section: Section | None = None, *, height_axis=None, formulation: str = "ffr",
                 bending: str = "continuum", segments=None, frame_drive=None,
                 frame_axis=(0.0, 0.0, 1.0), frame_pivot=None,
                 geometric_stiffness: bool = False, modes: int = 0) -> None:
        self.name = name
        self.geometric_stiffness = bool(geometric_stiffness)
        if not isinstance(modes, (int, np.integer)) or isinstance(modes, bool) or modes < 0:
            raise InputError(f"beam {name!r}: modes = {modes!r} must be an integer >= 0")
        self.modes = int(modes)
        where = f"beam {name!r}"
        self.material = material
        self.start, self.end = _vec(start, "start", where), _vec(end, "end", where)
        axis = self.end - self.start
        self.length = float(np.linalg.norm(axis))
        if self.length <= 0.0:
            raise InputError(f"{where}: start and end coincide")
        if not isinstance(nodes, (int, np.integer)) or nodes < 2:
            raise InputError(f"{where}: nodes = {nodes!r} must be an integer >= 2")
        if formulation not in FORMULATIONS:
            raise InputError(f"{where}: formulation {formulation!r} must be one of {FORMULATIONS}")
        if bending not in BENDING:
            raise InputError(f"{where}: bending {bending!r} must be one of {BENDING}")
        self.nodes, self.formulation, self.bending = int(nodes), formulation, bending
        self.section = section if section is not None else Rectangle(0.1, 0.1)
        self.section.data  # validates the dimensions now  # noqa: B018
        tangent = axis / self.length
        if height_axis is None:
            height_axis = (0.0, 1.0, 0.0) if abs(tangent[2]) > 1.0 - 1e-12 else (0.0, 0.0, 1.0)
        h = _vec(height_axis, "height_axis", where)
        h = h - (h @ tangent) * tangent
        if np.linalg.norm(h) < 1e-9:
            raise InputError(f"{where}: height_axis is parallel to the beam axis")
        h /= np.linalg.norm(h)
        self.orientation = np.column_stack([tangent, h, np.cross(tangent, h)])
        self.stations = self._stations(segments, where)
        self.lengths = self.stations[1:] - self.stations[:-1]   # (np.diff's values)
        self.frame_drive = frame_drive
        self.frame_axis = _vec(frame_axis, "frame_axis", where)
        if np.linalg.norm(self.frame_axis) == 0.0:
            raise InputError(f"{where}: frame_axis must not vanish")
        self.frame_pivot = self.start.copy() if frame_pivot is None else \
            _vec(frame_pivot, "frame_pivot", where)

    def _stations(self, segments, where: str) -> np.ndarray:
        if segments is None:
            return linspace(0.0, self.length, self.nodes)
        segments = [float(s) for s in segments]
        if any(s <= 0 for s in segments):
            raise InputError(f"{where}: segment lengths must be positive")
        if abs(sum(segments) - self.length) > 1e-9 * self.length:
            raise InputError(f"{where}: segments add up to {sum(segments):g} m, not the beam's "
                             f"length {self.length:g} m")
        k = len(segments)
        if (self.nodes - 1) % k:
            raise InputError(f"{where}: nodes = {self.nodes}: with {k} segments the beam needs "
                             f"{k}j+1 nodes ({', '.join(str(k * j + 1) for j in range(1, 5))}, ...)")
        per = (self.nodes - 1) // k
        edges = np.concatenate([[0.0], np.asarray(segments).cumsum()])
        parts = [linspace(a, b, per + 1)[:-1] for a, b in zip(edges[:-1].tolist(),
                                                              edges[1:].tolist())]
        return np.concatenate(parts + [[edges[-1]]])

    # -- geometry ---------------------------------------------------------------------------
    @property
    def nel(self) -> int:
        return self.nodes - 1

    @property
    def ncoordinates(self) -> int:
        return BEAM_NODE_DOFS * self.nodes

    def node_positions(self) -> np.ndarray:
        return self.start + np.outer(self.stations, self.orientation[:, 0])

    def coordinates(self) -> np.ndarray:
        q = np.zeros((self.nodes, BEAM_NODE_DOFS))
        q[:, 0:3] = self.node_positions()
        q[:, 3:12] = self.orientation.T.ravel()
        return q.ravel()

    def element_dofs(self) -> np.ndarray:
        """(24, nel) full coordinates of every element (after numbering)."""
        return self.first + np.array([np.arange(24) + BEAM_NODE_DOFS * el
                                      for el in range(self.nel)]).T

    def node_first(self, node: int, which: str = "r") -> int:
        return self.first + BEAM_NODE_DOFS * node + VECTOR_OFFSETS[which]

    # -- attachments ------------------------------------------------------------------------
    def locate(self, point, *, node: bool, what: str) -> Attachment:
        p = _vec(point, "point", what)
        rel = p - self.start
        s = float(rel @ self.orientation[:, 0])
        y = float(rel @ self.orientation[:, 1])
        z = float(rel @ self.orientation[:, 2])
        tol = 1e-6 * self.length
        half_y, half_z = self.section.extent
        if s < -tol or s > self.length + tol or abs(y) > half_y + tol or abs(z) > half_z + tol:
            raise InputError(f"{what}: point {list(p)} is not a material point of beam "
                             f"{self.name!r} (axis from {list(self.start)} to {list(self.end)})")
        nearest = int(np.argmin(np.abs(self.stations - s)))
        at_node = abs(self.stations[nearest] - s) <= tol and abs(y) <= tol and abs(z) <= tol
        if node and not at_node:
            raise InputError(f"{what}: point {list(p)} is not a node of beam {self.name!r} "
                             f"(nearest node at {list(self.node_positions()[nearest])})")
        s = min(max(s, 0.0), self.length)
        element = min(int(np.searchsorted(self.stations, s, side="right")) - 1, self.nel - 1)
        xi = (s - self.stations[element]) / self.lengths[element]
        return Attachment(nearest if at_node else None, element, (xi, y, z))

    def position(self, at: Attachment) -> Vec3:
        if at.node is not None:
            return Vec3.of(self.node_first(at.node))
        xi, y, z = at.local
        shape, *_ = kernel.beam_shape([xi], [y], [z], [self.lengths[at.element]])
        first = self.first + BEAM_NODE_DOFS * at.element
        return Vec3({first + 3 * a: float(shape[a, 0]) for a in range(8) if shape[a, 0] != 0.0})

    def vector(self, at: Attachment, which: str) -> Vec3:
        """A nodal vector at a node; between nodes or off the axis the same gradient of the
        position field at the material point (through the shape functions: r_x = dr/dx,
        r_y = dr/dy, r_z = dr/dz there; r_y and r_z interpolate the two nodes' directors)."""
        if at.node is not None:
            return Vec3.of(self.node_first(at.node, which))
        if which == "r":
            return self.position(at)
        xi, y, z = at.local
        derivs = kernel.beam_shape([xi], [y], [z], [self.lengths[at.element]])
        weights = derivs[VECTOR_OFFSETS[which] // 3][:, 0]
        first = self.first + BEAM_NODE_DOFS * at.element
        return Vec3({first + 3 * a: float(weights[a]) for a in range(8) if weights[a] != 0.0})

    def basis(self, at: Attachment) -> list[Vec3]:
        return [self.vector(at, w) for w in ("r_x", "r_y", "r_z")]

    def held_vectors(self, at: Attachment) -> list[str]:
        return ["r_y", "r_z"]  # the cross-section (a section clamp); r_x may shear and stretch

    def directors(self, at: Attachment) -> list[str]:
        return ["r_y", "r_z"]

    def torsion_shares(self) -> tuple[float, float]:
        """How a torque about the axis divides between the directors r_y and r_z when the
        section turns without shearing: halves with 'cubic' bending (its twist is
        (r_y,x . r_z - r_z,x . r_y)/2); in the continuum element r_y's turn shears the fibres
        at distance y (along the height) and r_z's those at distance z, so int y^2 dA / J
        and int z^2 dA / J."""
        if self.bending == "cubic":
            return 0.5, 0.5
        data = self.section.data
        return data.inertia_z / data.polar, data.inertia_y / data.polar


class Plate(Body):
    """A thin plate (seed 003): flat rectangle from ``corner`` along the orthogonal edge
    vectors ``edge_x``, ``edge_y``, nx x ny elements, thickness, variant 'plain' or
    'completed'. Leaves (:class:`Leaf`) are curved plates."""

    flexible = True

    def __init__(self, name: str, material: Material, thickness: float, corner, edge_x, edge_y,
                 nx: int, ny: int, *, variant: str = "completed") -> None:
        self.name = name
        where = f"plate {name!r}"
        self.material = material
        self.thickness = _positive(thickness, "thickness", where)
        self._check_mesh(nx, ny, where)
        if variant not in VARIANTS:
            raise InputError(f"{where}: variant {variant!r} must be one of {VARIANTS}")
        self.variant = variant
        self.corner = _vec(corner, "corner", where)
        self.edge_x, self.edge_y = _vec(edge_x, "edge_x", where), _vec(edge_y, "edge_y", where)
        try:
            self.mesh = flat_mesh(self.corner, self.edge_x, self.edge_y, nx, ny)
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None
        self.reference_coords: np.ndarray | None = None   # stress-free shape (prestress)

    @staticmethod
    def _check_mesh(nx, ny, where: str) -> None:
        for key, n in (("nx", nx), ("ny", ny)):
            if not isinstance(n, (int, np.integer)) or n < 1:
                raise InputError(f"{where}: {key} = {n!r} must be a positive integer")

    @property
    def nx(self) -> int:
        return self.mesh.grid.shape[0] - 1

    @property
    def ny(self) -> int:
        return self.mesh.grid.shape[1] - 1

    @property
    def nel(self) -> int:
        return self.mesh.nel

    @property
    def ncoordinates(self) -> int:
        return PLATE_NODE_DOFS * self.mesh.nnodes

    def coordinates(self) -> np.ndarray:
        return self.mesh.coords.ravel().copy()

    def element_dofs(self) -> np.ndarray:
        """(36, nel) full coordinates of every element (after numbering)."""
        m = self.mesh
        return self.first + (PLATE_NODE_DOFS * m.elements[:, :, None]
                             + np.arange(PLATE_NODE_DOFS)).reshape(m.nel, 36).T

    def node_first(self, node: int, which: str = "r") -> int:
        if which == "r_z":
            raise InputError(f"plate {self.name!r}: nodes carry r, r_x, r_y (no r_z)")
        return self.first + PLATE_NODE_DOFS * node + VECTOR_OFFSETS[which]

    def surface_coordinates(self, p: np.ndarray) -> tuple[float, float, float]:
        """(x along the length, y across, distance from the mid-surface) of a point."""
        rel = p - self.corner
        ux = self.edge_x / np.linalg.norm(self.edge_x)
        uy = self.edge_y / np.linalg.norm(self.edge_y)
        return float(rel @ ux), float(rel @ uy), float(rel @ np.cross(ux, uy))

    def length_stations(self) -> tuple[np.ndarray, np.ndarray]:
        """Node stations along x and y in the surface coordinates."""
        nx, ny = self.nx, self.ny
        return (np.linspace(0.0, np.linalg.norm(self.edge_x), nx + 1),
                np.linspace(0.0, np.linalg.norm(self.edge_y), ny + 1))

    def locate(self, point, *, node: bool, what: str) -> Attachment:
        p = _vec(point, "point", what)
        x, y, offset = self.surface_coordinates(p)
        sx, sy = self.length_stations()
        size = max(sx[-1] - sx[0], sy[-1] - sy[0])
        tol = 1e-6 * size
        if (x < sx[0] - tol or x > sx[-1] + tol or y < sy[0] - tol or y > sy[-1] + tol
                or abs(offset) > tol):
            raise InputError(f"{what}: point {list(p)} is not on the mid-surface of "
                             f"{type(self).__name__.lower()} {self.name!r}")
        i = int(np.argmin(np.abs(sx - x)))
        j = int(np.argmin(np.abs(sy - y)))
        at_node = abs(sx[i] - x) <= tol and abs(sy[j] - y) <= tol
        if node and not at_node:
            raise InputError(f"{what}: point {list(p)} is not a node of "
                             f"{type(self).__name__.lower()} {self.name!r}; a dead moment "
                             "acts on a node of a plate or leaf (one with a drive or "
                             "follower acts anywhere)")
        x = min(max(x, sx[0]), sx[-1])
        y = min(max(y, sy[0]), sy[-1])
        ei = min(int(np.searchsorted(sx, x, side="right")) - 1, self.nx - 1)
        ej = min(int(np.searchsorted(sy, y, side="right")) - 1, self.ny - 1)
        element = ej * self.nx + ei
        xi = (x - sx[ei]) / (sx[ei + 1] - sx[ei])
        eta = (y - sy[ej]) / (sy[ej + 1] - sy[ej])
        return Attachment(int(self.mesh.grid[i, j]) if at_node else None, element, (xi, eta))

    def position(self, at: Attachment) -> Vec3:
        if at.node is not None:
            return Vec3.of(self.node_first(at.node))
        xi, eta = at.local
        shape, _ = kernel.plate_shape(xi, eta, self.mesh.a[at.element], self.mesh.b[at.element])
        dofs = self.element_dofs()[:, at.element]
        return Vec3({int(dofs[3 * a]): float(shape[a]) for a in range(12) if shape[a] != 0.0})

    def vector(self, at: Attachment, which: str) -> Vec3:
        """A nodal vector at a node; elsewhere the gradient of the mid-surface at the point
        (r_x = dr/dx, r_y = dr/dy through the shape functions)."""
        if at.node is not None:
            return Vec3.of(self.node_first(at.node, which))
        if which == "r":
            return self.position(at)
        if which == "r_z":
            raise InputError(f"{type(self).__name__.lower()} {self.name!r}: points carry r, "
                             "r_x, r_y (no r_z)")
        xi, eta = at.local
        _, derivs = kernel.plate_shape(xi, eta, self.mesh.a[at.element], self.mesh.b[at.element])
        weights = derivs[:, 0 if which == "r_x" else 1]
        dofs = self.element_dofs()[:, at.element]
        return Vec3({int(dofs[3 * a]): float(weights[a]) for a in range(12)
                     if weights[a] != 0.0})

    def basis(self, at: Attachment) -> list[Vec3]:
        return [self.vector(at, "r_x"), self.vector(at, "r_y")]

    def held_vectors(self, at: Attachment) -> list[str]:
        return ["r_x", "r_y"]

    def directors(self, at: Attachment) -> list[str]:
        return ["r_x", "r_y"]

    def initial_normal(self, element: int) -> np.ndarray:
        """Unit normal r_x x r_y at the element's centre in the initial shape."""
        shape, derivs = kernel.plate_shape(0.5, 0.5, self.mesh.a[element], self.mesh.b[element])
        coords = self.mesh.coords.ravel()[self.element_dofs()[:, element] - self.first]
        coords = coords.reshape(12, 3)
        n = np.cross(derivs[:, 0] @ coords, derivs[:, 1] @ coords)
        return n / np.linalg.norm(n)


class Leaf(Plate):
    """A curved leaf: a cylindrical strip (circular arc of ``radius``, concave up, bent
    about r2) of ``arc_length`` and ``width``, its arc in the r1-r3 plane with the lowest
    point (the middle of the arc) at ``centre``, width along r2; nx (even: the middle is a
    node line) x ny elements. ``free_radius`` (prestress) is the radius of its stress-free
    shape (needs the 'completed' variant and the effect 'prestress')."""

    def __init__(self, name: str, material: Material, thickness: float, width: float,
                 arc_length: float, radius: float, centre, nx: int, ny: int, *,
                 variant: str = "completed", free_radius: float | None = None) -> None:
        self.name = name
        where = f"leaf {name!r}"
        self.material = material
        self.thickness = _positive(thickness, "thickness", where)
        self.width = _positive(width, "width", where)
        self.arc_length = _positive(arc_length, "arc_length", where)
        self.radius = _positive(radius, "radius", where)
        self._check_mesh(nx, ny, where)
        if nx % 2:
            raise InputError(f"{where}: nx = {nx} must be even (the middle is a node line)")
        if variant not in VARIANTS:
            raise InputError(f"{where}: variant {variant!r} must be one of {VARIANTS}")
        self.variant = variant
        self.centre = _vec(centre, "centre", where)
        if arc_length >= 2 * np.pi * radius:
            raise InputError(f"{where}: arc_length must be shorter than the circle of radius")
        self.mesh = arc_mesh(arc_length, radius, width, nx, ny, centre=self.centre)
        self.free_radius = None if free_radius is None else \
            _positive(free_radius, "free_radius", where)
        self.reference_coords = None
        if self.free_radius is not None and abs(self.free_radius - radius) > 1e-12 * radius:
            if variant != "completed":
                raise InputError(f"{where}: prestress (free_radius) needs variant 'completed'")
            if arc_length >= 2 * np.pi * self.free_radius:
                raise InputError(f"{where}: arc_length must be shorter than the circle of "
                                 "free_radius")
            self.reference_coords = arc_mesh(arc_length, self.free_radius, width, nx, ny).coords

    @property
    def prestressed(self) -> bool:
        return self.reference_coords is not None

    def surface_coordinates(self, p: np.ndarray) -> tuple[float, float, float]:
        rel = p - self.centre
        theta = float(np.arctan2(rel[0], self.radius - rel[2]))
        distance = float(np.hypot(rel[0], self.radius - rel[2]))
        return (self.radius * theta + 0.5 * self.arc_length, rel[1] + 0.5 * self.width,
                self.radius - distance)

    def length_stations(self) -> tuple[np.ndarray, np.ndarray]:
        return (np.linspace(0.0, self.arc_length, self.nx + 1),
                np.linspace(0.0, self.width, self.ny + 1))

    def material_point(self, s: float, y: float) -> np.ndarray:
        """The point at arc length s from the middle and y across the width."""
        theta = s / self.radius
        return self.centre + np.array([self.radius * np.sin(theta), y,
                                       self.radius * (1.0 - np.cos(theta))])


class RigidBody(Body):
    """A rigid body as an ANCF reference node (seed 003 eqs. 29-32): mass, inertia tensor
    about the centre of mass (global axes at t = 0; 3 x 3 or Ixx, Iyy, Izz, Ixy, Iyz, Ixz),
    centre of mass ``position``. ``planar``: kept in the plane through its centre normal to
    ``plane_normal`` (a coordinate axis; translation along it and rotations about the two
    in-plane axes fixed)."""

    def __init__(self, name: str, mass: float, inertia, position, *, planar: bool = False,
                 plane_normal=(0.0, 1.0, 0.0)) -> None:
        self.name = name
        where = f"rigid body {name!r}"
        self.mass = _positive(mass, "mass", where)
        inertia = np.asarray(inertia, dtype=float)
        if inertia.shape == (6,):
            ixx, iyy, izz, ixy, iyz, ixz = inertia
            inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        if inertia.shape != (3, 3) or not np.all(np.isfinite(inertia)):
            raise InputError(f"{where}: inertia must be 6 numbers (Ixx, Iyy, Izz, Ixy, Iyz, "
                             "Ixz) or a 3 x 3 tensor")
        self.inertia = inertia
        self.centre = _vec(position, "position", where)  # centre of mass, the reference point
        self.planar = bool(planar)
        normal = _vec(plane_normal, "plane_normal", where)
        axis = int(np.argmax(np.abs(normal)))
        if self.planar and (np.count_nonzero(normal) != 1):
            raise InputError(f"{where}: plane_normal {list(normal)} must be a coordinate axis")
        self.plane_axis = axis
        try:
            self.mass_matrix = kernel.reference_node_mass(self.mass, np.zeros(3), self.inertia)
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None

    @property
    def ncoordinates(self) -> int:
        return RIGID_DOFS

    def coordinates(self) -> np.ndarray:
        return np.concatenate([self.centre, *np.eye(3)])

    def vector_first(self, which: str) -> int:
        return self.first + VECTOR_OFFSETS[which]

    def locate(self, point, *, node: bool, what: str) -> Attachment:
        p = _vec(point, "point", what)
        return Attachment(local=tuple(p - self.centre))

    def position_of_offset(self, u) -> Vec3:
        v = Vec3.of(self.vector_first("r"))
        for k, which in enumerate(("r_x", "r_y", "r_z")):
            if u[k] != 0.0:
                v = v + Vec3.of(self.vector_first(which), float(u[k]))
        return v

    def position(self, at: Attachment) -> Vec3:
        return self.position_of_offset(at.local)

    def vector(self, at: Attachment, which: str) -> Vec3:
        if which == "r":
            return self.position(at)
        return Vec3.of(self.vector_first(which))

    def basis(self, at: Attachment) -> list[Vec3]:
        return [Vec3.of(self.vector_first(w)) for w in ("r_x", "r_y", "r_z")]

    def held_vectors(self, at: Attachment) -> list[str]:
        return ["r_x", "r_y", "r_z"]

    def directors(self, at: Attachment) -> list[str]:
        return ["r_x", "r_y", "r_z"]


BODY_TYPES = (Beam, Plate, Leaf, RigidBody)
__all__ = ["Material", "Body", "Ground", "Beam", "Plate", "Leaf", "RigidBody", "Attachment",
           "rotation_about", "BEAM_NODE_DOFS", "PLATE_NODE_DOFS", "RIGID_DOFS", "PlateMesh"]
