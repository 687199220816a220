"""The ANCF cable: a gradient-deficient Euler-Bernoulli beam element in 3D (kernel module
``fortran/src/elements/cable_element.f90``; Gerstmayr and Shabana 2006, Exudyn's
ANCFCable). Per node the position r and the slope r_x (6 coordinates, half a beam node's
12): axial strain (r'.r' - 1)/2 and the exact curvature |r' x r''| / |r'|^3 with the
section's EA and EI; no shear, no torsion, no section frame. The element family's whole
Python side: the body, its set builder and kernel adder (registered in
:mod:`..registry`).

Joints act on nodes: a 'weld' holds r and r_x (a clamp), 'spherical' the position, 'fix'
one nodal vector ('r' or 'r_x'). Loads and probes act at any point of the axis. Material
damping (the material's damping_time with the effect 'damping') is Kelvin-Voigt damping of
the axial strain only.

A rope is a cable with ``tension_only=True``: its axial law carries no compression (EA
max(eps, 0) at every Gauss point, exact and piecewise; the kernel module's header says how
the kink is treated), its axial damping acts only in tension and never makes the force
compressive, and its bending stiffness is usually given apart (``bending_stiffness``, N m^2:
a wire rope bends far more easily than a solid bar of its diameter; it keeps a slack rope's
Newton matrix regular and may be 0 in dynamics, where the mass does that).
"""
from __future__ import annotations

import functools

import numpy as np

from ... import kernel
from ...errors import InputError
from ...gauss import leggauss
from ...io.schema import Key, at_least, name_key, non_negative, one_of, positive, vector3
from ..bodies import Attachment, Body, Material, _vec, axis_stations, check_axis_dimensions
from ..expressions import Vec3
from ..model import SetInfo
from ..registry import Kind, SetContext, checked_values, register
from ..sections import Rectangle, Section, section_of

CABLE_NODE_DOFS = 6
#: offsets of the nodal vectors within a node's coordinates
CABLE_OFFSETS = {"r": 0, "r_x": 3}


@functools.lru_cache(maxsize=64)
def _gauss_slopes(lengths: tuple[float, ...]) -> np.ndarray:
    """The slope shape rows of elements of these lengths at the 5 points of the Gauss rule
    (the kernel's ``cable_shape``; a pure function of the point and the length: made once
    per mesh of a process, read only), (4, nel, 5, 1): [j, i, g, 0] is shape function j's
    slope in element i at point g, laid out to broadcast against an element's nodal
    vectors (:meth:`Cable.strains`)."""
    xg, _ = leggauss(5)
    slopes = np.array([[kernel.cable_shape(x, length)[1] for x in 0.5 * (xg + 1.0)]
                       for length in lengths])             # (nel, 5, 4)
    out = np.ascontiguousarray(slopes.transpose(2, 0, 1))[..., None]
    out.flags.writeable = False
    return out


class Cable(Body):
    """A straight ANCF cable from ``start`` to ``end`` with ``nodes`` equally spaced nodes
    and the cross-section ``section`` (its area and bending inertia: a cable bends alike
    about every axis, so the section must have I_y = I_z: circle, tube, square).

    ``tension_only``: a rope (the axial force is never compressive: it goes slack).
    ``bending_stiffness`` (N m^2, >= 0): EI given directly instead of E times the section's
    I (a rope's effective bending stiffness)."""

    flexible = True

    @property
    def nnodes(self) -> int:
        return self.nodes

    @property
    def mesh_nodes(self) -> int:
        return self.nodes

    @property
    def extent(self) -> float:
        return self.length

    def __init__(self, name: str, material: Material, start, end, nodes: int,
                 section: Section | None = None, segments=None, *,
                 tension_only: bool = False, bending_stiffness: float | None = None,
                 bending_inertia: float | None = None) -> None:
        self.name = name
        where = f"cable {name!r}"
        self.material = material
        self.start, self.end = _vec(start, "start", where), _vec(end, "end", where)
        axis = self.end - self.start
        self.length = float(np.sqrt(axis.dot(axis)))   # (np.linalg.norm of a float vector)
        if self.length <= 0.0:
            raise InputError(f"{where}: start and end coincide")
        if not isinstance(nodes, (int, np.integer)) or nodes < 2:
            raise InputError(f"{where}: nodes = {nodes!r} must be an integer >= 2")
        self.nodes = int(nodes)
        self.section = section if section is not None else Rectangle(0.1, 0.1)
        data = self.section.data
        unequal = abs(data.inertia_y - data.inertia_z) > 1e-9 * max(data.inertia_y,
                                                                     data.inertia_z)
        if unequal and bending_inertia is None:
            raise InputError(f"{where}: a cable has one bending stiffness; its section has "
                             f"I_y = {data.inertia_y:g} and I_z = {data.inertia_z:g} m^4 (use "
                             "a circle, a tube or a square, or give bending_inertia for a "
                             "cable kept in a plane)")
        if bending_inertia is not None and not (np.isfinite(bending_inertia)
                                                and bending_inertia > 0):
            raise InputError(f"{where}: bending_inertia {bending_inertia!r} must be positive")
        #: the bending inertia used (None: the section's, I_y = I_z); a cable given one for
        #: an unequal section bends in one plane only: the assembly then requires the
        #: system's planar reduction (system/planar.py), which keeps it in that plane
        self.bending_inertia = None if bending_inertia is None else float(bending_inertia)
        self.planar_bending = bool(unequal)
        if not isinstance(tension_only, (bool, np.bool_)):
            raise InputError(f"{where}: tension_only = {tension_only!r} must be True or False")
        self.tension_only = bool(tension_only)
        if bending_stiffness is not None and not (
                isinstance(bending_stiffness, (int, float, np.floating))
                and np.isfinite(bending_stiffness) and bending_stiffness >= 0.0):
            raise InputError(f"{where}: bending_stiffness = {bending_stiffness!r} must be a "
                             "finite number >= 0 (N m^2)")
        self._bending_stiffness = None if bending_stiffness is None else float(bending_stiffness)
        self.tangent = axis / self.length
        # segments: lengths between fixed nodes, each split equally (as a beam's)
        self.stations = axis_stations(self.length, self.nodes, segments, where)
        self.lengths = self.stations[1:] - self.stations[:-1]   # (np.diff's values)

    # -- geometry ---------------------------------------------------------------------------
    @property
    def nel(self) -> int:
        return self.nodes - 1

    @property
    def ncoordinates(self) -> int:
        return CABLE_NODE_DOFS * self.nodes

    @property
    def axial_stiffness(self) -> float:
        return self.material.youngs_modulus * self.section.data.area

    @property
    def bending_stiffness(self) -> float:
        """EI (N m^2): the given ``bending_stiffness``, else E times the section's I (or the
        given ``bending_inertia``)."""
        if self._bending_stiffness is not None:
            return self._bending_stiffness
        inertia = self.section.data.inertia_y if self.bending_inertia is None else \
            self.bending_inertia
        return self.material.youngs_modulus * inertia

    def strains(self, e) -> np.ndarray:
        """The axial Green strain eps = (r'.r' - 1)/2 at every element's 5 Gauss points
        (nel, 5), from the full coordinates e (one state (ndof,) or a history (nt, ndof):
        then (nt, nel, 5)); signed (negative: compressed, for a rope: slack)."""
        e = np.asarray(e, dtype=float)
        q = e[..., self.element_dofs()]                            # (..., 12, nel)
        q = np.moveaxis(q.reshape(*q.shape[:-2], 4, 3, self.nel), -1, -3)  # (..., nel, 4, 3)
        q = q[..., None, :, :]                                     # (..., nel, 1, 4, 3)
        slopes = _gauss_slopes(tuple(self.lengths.tolist()))       # (4, nel, 5, 1)
        # r' at every point at once (..., nel, 5, 3): the shape functions' terms added in
        # their order, as einsum("ij,...ijk->...ik") added them point by point (the same
        # values, bit for bit, in 5 times fewer numpy calls)
        a = slopes[0] * q[..., 0, :]
        for j in range(1, 4):
            a += slopes[j] * q[..., j, :]
        return 0.5 * (np.einsum("...k,...k->...", a, a) - 1.0)

    def axial_forces(self, e) -> np.ndarray:
        """The axial force (N, tension positive) at the Gauss points of :meth:`strains`:
        T = EA eps |r'| (the force dw/dr' of the element's law, its magnitude along r'); a
        rope's is EA max(eps, 0) |r'| (never compressive)."""
        strain = self.strains(e)
        force = strain if not self.tension_only else np.maximum(strain, 0.0)
        return self.axial_stiffness * force * np.sqrt(1.0 + 2.0 * strain)

    def node_positions(self) -> np.ndarray:
        return self.start + self.stations[:, None] * self.tangent[None, :]   # (np.outer)

    def coordinates(self) -> np.ndarray:
        q = np.zeros((self.nodes, CABLE_NODE_DOFS))
        q[:, 0:3] = self.node_positions()
        q[:, 3:6] = self.tangent
        return q.ravel()

    def element_dofs(self) -> np.ndarray:
        """(12, nel) full coordinates of every element (after numbering)."""
        return self.first + np.array([np.arange(12) + CABLE_NODE_DOFS * el
                                      for el in range(self.nel)]).T

    def node_first(self, node: int, which: str = "r") -> int:
        return self.first + CABLE_NODE_DOFS * node + CABLE_OFFSETS[which]

    # -- attachments ------------------------------------------------------------------------
    def locate(self, point, *, node: bool, what: str) -> Attachment:
        p = _vec(point, "point", what)
        rel = p - self.start
        s = float(rel @ self.tangent)
        tol = 1e-6 * self.length
        off = rel - s * self.tangent   # (its np.linalg.norm: sqrt of its dot product)
        if s < -tol or s > self.length + tol or np.sqrt(off.dot(off)) > tol:
            raise InputError(f"{what}: point {list(p)} is not on the axis of cable "
                             f"{self.name!r} (from {list(self.start)} to {list(self.end)})")
        nearest = int(np.abs(self.stations - s).argmin())
        at_node = abs(self.stations[nearest] - s) <= tol
        if node and not at_node:
            raise InputError(f"{what}: point {list(p)} is not a node of cable {self.name!r} "
                             f"(nearest node at {list(self.node_positions()[nearest])}); "
                             "joints act on nodes of cables")
        s = min(max(s, 0.0), self.length)
        element = min(int(self.stations.searchsorted(s, side="right")) - 1, self.nel - 1)
        xi = (s - self.stations[element]) / self.lengths[element]
        return Attachment(nearest if at_node else None, element, (xi,))

    def shape_row(self, at: Attachment) -> np.ndarray:
        """The position's shape row (4,) on the element's [r_1, r_1,x, r_2, r_2,x]."""
        shape, _, _ = kernel.cable_shape(at.local[0], self.lengths[at.element])
        return shape

    def position(self, at: Attachment) -> Vec3:
        if at.node is not None:
            return Vec3.of(self.node_first(at.node))
        shape = self.shape_row(at)
        first = self.first + CABLE_NODE_DOFS * at.element
        return Vec3({first + 3 * a: float(shape[a]) for a in range(4) if shape[a] != 0.0})

    def vector(self, at: Attachment, which: str) -> Vec3:
        if at.node is None:
            raise InputError(f"cable {self.name!r}: nodal vectors exist at nodes only")
        if which not in CABLE_OFFSETS:
            raise InputError(f"cable {self.name!r}: a cable node has the vectors r and r_x, "
                             f"not {which!r}")
        return Vec3.of(self.node_first(at.node, which))

    def basis(self, at: Attachment) -> list[Vec3]:
        return [self.vector(at, "r_x")]

    def held_vectors(self, at: Attachment) -> list[str]:
        return ["r_x"]  # a clamp holds the slope (the cable has no section to hold)

    def directors(self, at: Attachment) -> list[str]:
        return []

    # -- what the assembly asks of a flexible body besides its set ---------------------------
    def point_mass(self, at: Attachment, mass: float) -> np.ndarray:
        """A point mass's share (4, 4) of its element's compact mass matrix."""
        shape = self.shape_row(at)
        return mass * np.outer(shape, shape)

    def gravity_forces(self, g: np.ndarray) -> np.ndarray:
        """Generalized gravity forces per element (12, nel) of the acceleration g (3,): the
        uniform load rho A g per length."""
        _, forces = kernel.cable_element_arrays(self.lengths, self.mass_per_length,
                                                self.mass_per_length * np.asarray(g, float))
        return forces

    @property
    def mass_per_length(self) -> float:
        return self.material.density * self.section.data.area


def cable_set(cable: Cable, context: SetContext) -> SetInfo:
    """The cable's element set: dofs, the scalar element masses (closed form) and the
    kernel data (lengths, EA, EI, the rope's tension-only law)."""
    mass, _ = kernel.cable_element_arrays(cable.lengths, cable.mass_per_length, np.zeros(3))
    return SetInfo(body=cable, kind="cable", dofs=cable.element_dofs(), nel=cable.nel, frame=0,
                   mass_compact=mass)


def _add_cable(ks: kernel.KernelSystem, s: SetInfo) -> int:
    return ks.add_cable_set(s.dofs, s.scatter, s.body.lengths, s.body.axial_stiffness,
                            s.body.bending_stiffness, s.damping_time, s.body.tension_only)


KEYS: dict[str, Key] = {
    "name": name_key(),
    "material": Key("str", doc="name of a &material"),
    "start": Key("floats", check=vector3, doc="start of the axis (m)"),
    "end": Key("floats", check=vector3, doc="end of the axis (m)"),
    "nodes": Key("int", check=at_least(2), doc="nodes on the cable (>= 2)"),
    "segments": Key("floats", None, doc="segment lengths between fixed nodes (m), each "
                    "split into equal elements (as a beam's; nodes = k j + 1 for k "
                    "segments)"),
    "section": Key("str", "circle", one_of("rectangle", "box", "tube", "circle"),
                   "cross-section (its area and bending inertia; I_y = I_z required): "
                   "'circle' (diameter), 'tube' (diameter, wall), a square 'rectangle' "
                   "or 'box'"),
    "width": Key("float", None, positive, "section width (m)"),
    "height": Key("float", None, positive, "section height (m)"),
    "wall": Key("float", None, positive, "wall thickness of 'box' and 'tube' (m)"),
    "diameter": Key("float", None, positive, "outer diameter of 'tube' and 'circle' (m)"),
    "tension_only": Key("bool", False, doc="a rope: the axial force is never "
                        "compressive (the cable goes slack); with the effect 'damping' "
                        "its axial damping acts in tension only"),
    "bending_stiffness": Key("float", None, non_negative, "EI (N m^2) in place of E "
                             "times the section's I (a rope's effective bending "
                             "stiffness; 0 only in dynamics)"),
}


def build(system, v: dict) -> Cable:
    """A cable from the values of ``System.add('cable', ...)`` (besides the namelist's
    keys the API's ``bending_inertia``)."""
    section = section_of(v, f"cable[{v['name']}]")
    name = system._body_name(v["name"])
    v = checked_values(KIND, f"cable[{name}]", v)
    return system._add_body(Cable(name, system._material(v["material"], f"cable {name!r}"),
                                  v["start"], v["end"], v["nodes"], section,
                                  tension_only=v["tension_only"],
                                  bending_stiffness=v["bending_stiffness"],
                                  segments=v["segments"],
                                  bending_inertia=v.get("bending_inertia")))


def _planar_problems(body: Cable, j: int, tol: float) -> list[str]:
    """The planar rule (system/planar.py): the axis in a plane normal to e_j."""
    if abs(float(body.start[j] - body.end[j])) > tol:
        return [f"its axis leaves the plane normal to {'xyz'[j]}"]
    return []


def _planar_fixed(body: Cable, j: int, q0) -> list[tuple[int, str]]:
    """In planar motion normal to e_j every node keeps r_j and r_x,j."""
    return [(body.node_first(node, which) + j, f"{body.name}: planar node {node + 1} {which}")
            for node in range(body.nodes) for which in ("r", "r_x")]



def _stress_stiffness(info: SetInfo, q: np.ndarray, dq: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
    """The elements' tangents at the full coordinates q and the initial-stress stiffness of
    the axial force increment along dq (each (12, 12, nel); kernel.cable_stress_stiffness)."""
    body = info.body
    own = np.arange(12 * info.nel).reshape(info.nel, 12).T
    e, de = q[info.dofs].reshape(-1, order="F"), dq[info.dofs].reshape(-1, order="F")
    tangent = kernel.cable_forces(own, e, body.lengths, body.axial_stiffness,
                                  body.bending_stiffness, True, body.tension_only)[2]
    return tangent, kernel.cable_stress_stiffness(own, e, de, body.lengths,
                                                  body.axial_stiffness, body.tension_only)

def _mesh(body: Cable, rows) -> None:
    """XDMF: a 2-node line per element through the node positions r (a polyline)."""
    nodes = rows.node_points(body.first, body.nodes, CABLE_NODE_DOFS) + np.arange(body.nodes)
    rows.lines.append(np.column_stack([nodes[:-1], nodes[1:]]))


KIND = register(Kind(
    group="cable", body_class=Cable, keys=KEYS, build=build, api="cable", word="cable",
    api_keys=("bending_inertia",), objects=("material", "section"), set_builder=cable_set,
    adders={"cable": _add_cable},
    check_dimensions=lambda body: check_axis_dimensions(body, "cable"),
    plane=lambda body, j: float(body.start[j]), planar_problems=_planar_problems,
    planar_fixed=_planar_fixed, mesh=_mesh, mesh_order=1,
    axial_forces=lambda body, e_rows: body.axial_forces(e_rows).reshape(len(e_rows), -1),
    stress_stiffness=_stress_stiffness))
