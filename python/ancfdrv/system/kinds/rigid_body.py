"""The rigid-body kind: a rigid body as an ANCF reference node, the namelist group
&rigid_body and ``System.rigid_body``. Its whole Python side: the body, its keys and its
registration (:mod:`..registry`); it has no element set (its mass matrix is its own).
"""
from __future__ import annotations

import math

import numpy as np

from ... import kernel
from ...errors import InputError
from ...io import validate
from ...io.schema import Key, coerce, name_key, plain_value, positive, principal_positive, vector3
from ..bodies import VECTOR_OFFSETS, Attachment, Body, _positive, _vec
from ..expressions import Vec3
from ..registry import Kind, checked_values, register

RIGID_DOFS = 12


class RigidBody(Body):
    """A rigid body as an ANCF reference node (seed 003 eqs. 29-32): mass, inertia tensor
    about the centre of mass (global axes at t = 0; 3 x 3 or Ixx, Iyy, Izz, Ixy, Iyz, Ixz),
    centre of mass ``position``. ``planar``: kept in the plane through its centre normal to
    ``plane_normal`` (a coordinate axis; translation along it and rotations about the two
    in-plane axes fixed)."""

    @property
    def nnodes(self) -> int:
        return 1

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


KEYS: dict[str, Key] = {
    "name": name_key(),
    "mass": Key("float", check=positive, doc="mass (kg)"),
    "inertia": Key("floats", size=6, check=principal_positive, doc="Ixx, Iyy, Izz, Ixy, Iyz, Ixz about the centre of "
                   "mass, global axes at t = 0 (kg m^2)"),
    "position": Key("floats", check=vector3, doc="centre of mass at t = 0 (m)"),
    "planar": Key("bool", False, doc="kept in the plane normal to plane_normal"),
    "plane_normal": Key("floats", [0.0, 1.0, 0.0], vector3,
                        "normal of the plane of a planar body (a coordinate axis)"),
}


def build(system, v: dict) -> RigidBody:
    """A rigid body from the values of ``System.add('rigid_body', ...)`` (inertia: Ixx, Iyy,
    Izz, Ixy, Iyz, Ixz, or a 3 x 3 tensor)."""
    name = system._body_name(v["name"])
    flat = plain_value(v["inertia"])
    tensor = isinstance(flat, list) and len(flat) == 9
    checked = checked_values(KIND, f"rigid_body[{name}]", {**v, "inertia": None} if tensor else v)
    if tensor:  # a 3 x 3 tensor: finite numbers
        coerce("floats", flat, dict(group=f"rigid_body[{name}]", key="inertia"))
    return system._add_body(RigidBody(name, checked["mass"], v["inertia"], checked["position"],
                                      planar=checked["planar"],
                                      plane_normal=checked["plane_normal"]))


def _planar_problems(body: RigidBody, j: int, tol: float) -> list[str]:
    """The planar rule (system/planar.py): no product of inertia couples a turn about e_j
    with the other two; a body already planar has the normal e_j."""
    plane, out = "xyz"[j], []
    coupling = np.delete(body.inertia[j], j)
    if np.abs(coupling).max() > 1e-9 * np.abs(body.inertia).max():
        out.append(f"its products of inertia couple a turn about {plane} with the other axes")
    if body.planar and body.plane_axis != j:
        out.append(f"it is planar with the normal {'xyz'[body.plane_axis]}, not {plane}")
    return out


def _planar_fixed(body: RigidBody, j: int, q0) -> list[tuple[int, str]]:
    """In planar motion normal to e_j: its translation along j, its axis j (kept = e_j) and
    the j-components of its other two axes (none when its own guide holds them)."""
    if body.planar and body.plane_axis == j:
        return []
    out = [(body.vector_first("r") + j, f"{body.name}: planar (scene) r{j + 1}")]
    for k, which in enumerate(("r_x", "r_y", "r_z")):
        for comp in range(3):
            if k == j or comp == j:
                out.append((body.vector_first(which) + comp,
                            f"{body.name}: planar (scene) {which}"))
    return out


def inertia_box(body: RigidBody) -> tuple[np.ndarray, np.ndarray]:
    """The uniform box of the body's mass and principal moments of inertia: (half-sizes
    (a, b, c), the principal axes as columns, in the body's axes at t = 0). A box of
    half-sizes a, b, c has I1 = m (b^2 + c^2) / 3 about its first axis, and so on, so
    a^2 = 3 (I2 + I3 - I1) / 2m (0 when the moments do not meet the triangle inequality
    strictly: a flat body)."""
    moments, axes = np.linalg.eigh(body.inertia)
    squares = 3.0 * (moments.sum() - 2.0 * moments) / (2.0 * body.mass)
    return np.sqrt(np.maximum(squares, 0.0)), axes


#: the 12 edges of a box between its corners k = 4 i + 2 j + l (signs (-1)^(1+i), ...)
BOX_EDGES = np.array([[0, 1], [2, 3], [4, 5], [6, 7], [0, 2], [1, 3], [4, 6], [5, 7],
                      [0, 4], [1, 5], [2, 6], [3, 7]])


def _mesh(body: RigidBody, rows) -> None:
    """XDMF: its centre r and three lines along r_x, r_y, r_z as long as its radius of
    gyration about the centre of mass, sqrt(tr(I) / 2m) (the root mean square distance of
    the mass from the centre; 1 when 0), then the 12 edges of its inertia box
    (:func:`inertia_box`) between the corners r + u1 r_x + u2 r_y + u3 r_z, u = V (+-a,
    +-b, +-c): 8 points, each affine in the body's coordinates, moving with it."""
    size = math.sqrt(max(float(np.trace(body.inertia)), 0.0) / (2.0 * body.mass))
    size = size if size > 0 else 1.0
    centre = rows.point([(body.first, 1.0)])
    for k in (1, 2, 3):  # r + size r_x, r + size r_y, r + size r_z
        tip = rows.point([(body.first, 1.0), (body.first + 3 * k, size)])
        rows.lines.append(np.array([[centre, tip]]))
    half, axes = inertia_box(body)
    first = rows.count
    for signs in np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1], indexing="ij")).reshape(3, -1).T:
        rows.expression(body.position_of_offset(axes @ (signs * half)))
    rows.lines.append(BOX_EDGES + first)


KIND = register(Kind(
    group="rigid_body", body_class=RigidBody, keys=KEYS, build=build, api="rigid_body",
    word="rigid body",
    part=lambda body: validate.Part(f"rigid_body[{body.name}]", "mass", "rigid_body", 1,
                                    RIGID_DOFS),
    plane=lambda body, j: float(body.centre[j]), planar_problems=_planar_problems,
    planar_fixed=_planar_fixed, mesh=_mesh, mesh_order=2))
