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

import numpy as np

from ..records import record
from ..errors import InputError
from ..io import validate
from .expressions import Vec3

#: offsets of the nodal vectors within a node's coordinates
VECTOR_OFFSETS = {"r": 0, "r_x": 3, "r_y": 6, "r_z": 9}


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


def axis_stations(length: float, nodes: int, segments, where: str) -> np.ndarray:
    """The nodes' stations (m from the start) along a straight axis of ``length``: equally
    spaced, or equally within each of ``segments`` (lengths adding up to the axis's; nodes =
    k j + 1 for k segments)."""
    if segments is None:
        return linspace(0.0, length, nodes)
    segments = [float(s) for s in segments]
    if any(s <= 0 for s in segments):
        raise InputError(f"{where}: segment lengths must be positive")
    if abs(sum(segments) - length) > 1e-9 * length:
        raise InputError(f"{where}: segments add up to {sum(segments):g} m, not the beam's "
                         f"length {length:g} m")
    k = len(segments)
    if (nodes - 1) % k:
        raise InputError(f"{where}: nodes = {nodes}: with {k} segments the beam needs "
                         f"{k}j+1 nodes ({', '.join(str(k * j + 1) for j in range(1, 5))}, ...)")
    per = (nodes - 1) // k
    edges = np.concatenate([[0.0], np.asarray(segments).cumsum()])
    parts = [linspace(a, b, per + 1)[:-1] for a, b in zip(edges[:-1].tolist(),
                                                          edges[1:].tolist())]
    return np.concatenate(parts + [[edges[-1]]])


def check_axis_dimensions(body, word: str) -> None:
    """A beam's or cable's length and section within the physical minima
    (``validate.PHYSICAL_MINIMA``: 'length', 'section')."""
    where = f"{word} {body.name!r}"
    validate.check_minimum("length", body.length, f"{where}: length", key="end")
    validate.check_minimum("section", float(np.sqrt(body.section.area)),
                           f"{where}: the side of a square of its section's area",
                           key="section")


def points_of(value) -> list[np.ndarray]:
    """One point (3 numbers) or several (a multiple of 3)."""
    a = np.asarray(value, dtype=float).ravel()
    if a.size == 0 or a.size % 3:
        raise ValueError(f"expected x,y,z (or several points: a multiple of 3 numbers), got "
                         f"{a.size} numbers")
    return [a[i:i + 3].copy() for i in range(0, a.size, 3)]


def _vec(value, what: str, name: str) -> np.ndarray:
    v = np.asarray(value, dtype=float).ravel()
    if v.shape != (3,) or not all(map(math.isfinite, v.tolist())):   # (np.isfinite(v).all())
        raise InputError(f"{name}: {what} must be three finite numbers, got {value!r}")
    return v


def _positive(value: float, what: str, name: str) -> float:
    if not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
        raise InputError(f"{name}: {what} must be a positive number, got {value!r}")
    return float(value)


def along_axis(v, j: int, tol: float = 1e-9) -> bool:
    """v is parallel to the coordinate axis e_j (within ``tol`` of its length, at least 1)."""
    v = np.asarray(v, dtype=float)
    return float(np.linalg.norm(np.delete(v, j))) <= tol * max(1.0, float(np.linalg.norm(v)))


def rotation_about(axis, angle: float) -> np.ndarray:
    """Rodrigues' rotation matrix about a unit axis."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    skew = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * skew + (1.0 - np.cos(angle)) * skew @ skew


@record(frozen=True)
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


@record
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
    #: a mid-surface mesh of 9-coordinate nodes (plates and leaves: contact, pressure)
    surface = False
    #: the component of a probe's deflection a sweep compares by default (r3; a beam r2)
    response_component = 2
    #: its elastic model lives in a floating frame, with small strain (an 'ffr' beam): the
    #: FFR checks and solvers
    floating = False
    #: the drive turning its own frame about a fixed axis (None: the frame, if it has one,
    #: keeps its t = 0 orientation): a beam's ``frame_drive``; a cable may carry one for its
    #: probes' deflection (builders/boom.py)
    frame_drive = None
    #: the directors of its cross-section, a section that turns apart from the tangent r_x
    #: (a beam's r_y, r_z; empty: none): welds and hinge axes hold the section, a moment
    #: between nodes acts on the element's two sections, a beam with joints gets a support
    #: frame (supports.py), a driven or follower load is resolved on them (others: r_x, r_y)
    section_directors: tuple[str, ...] = ()
    #: its elements' bending option ('continuum' or 'cubic' for a beam; None: no option)
    bending: str | None = None
    #: modes of the modal reduction of its coordinates (0: every coordinate integrated; a
    #: beam's ``modes``, solvers/ffr_reduced.py)
    modes = 0

    @property
    def framed(self) -> bool:
        """It has a frame of its own (the assembly's FrameInfo): a body with a frame drive;
        a beam always (its body frame)."""
        return self.frame_drive is not None

    @property
    def nnodes(self) -> int:
        """Nodes carrying its coordinates (a rigid body: its reference node)."""
        return 0

    @property
    def mesh_nodes(self) -> int:
        """Nodes of its mesh in the result files' geometry (/model nnodes, XDMF)."""
        return 0

    @property
    def extent(self) -> float | None:
        """Its size (m) for the Newton tolerances' length scale (flexible bodies)."""
        return None

    @property
    def rigid(self) -> bool:
        """A rigid body (coordinates of its own, no deformation)."""
        return not self.flexible and self.ncoordinates > 0

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

    def point_mass(self, at: Attachment, mass: float) -> np.ndarray:
        """A flexible body: a point mass's share of its element's compact mass matrix
        (n, n) (the element at.element)."""
        raise NotImplementedError

    def gravity_forces(self, g: np.ndarray) -> np.ndarray:
        """A flexible body: its generalized gravity forces per element (nde, nel) of the
        acceleration g (3,)."""
        raise NotImplementedError

    def torsion_shares(self) -> tuple[float, float]:
        """How a moment about the normal of its two directors divides between them: halves
        (a beam's section: by its shear and bending rule)."""
        return 0.5, 0.5

    def moment_attachments(self, point, what: str) -> list[tuple[Attachment, float]]:
        """Where a moment at the point acts, each attachment with its share of it: a rigid
        body at the point, a flexible body at its node there (a beam also between nodes)."""
        return [(self.locate(point, node=not self.rigid, what=what), 1.0)]


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


__all__ = ["Material", "Body", "Ground", "Attachment", "axis_stations", "check_axis_dimensions", "points_of",
           "linspace",
           "rotation_about", "VECTOR_OFFSETS"]
