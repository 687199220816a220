"""The plate kind and the leaf kind: thin plates (flat) and curved leaves (plain or completed
element, optional prestress), the namelist groups &plate and &leaf and ``System.plate``,
``System.leaf``. Their whole Python side: the bodies, their keys, their element set (kernel
set kind 'plate') and its kernel adder, their registrations (:mod:`..registry`).
"""
from __future__ import annotations

import numpy as np

from ... import kernel
from ...errors import InputError
from ...io import validate
from ...io.schema import Key, name_key, one_of, positive, vector3
from ..bodies import VECTOR_OFFSETS, Attachment, Body, Material, _positive, _vec, linspace
from ..expressions import Vec3
from ..meshes import arc_mesh, flat_mesh
from ..model import SetInfo
from ..registry import Kind, SetContext, checked_values, register

PLATE_NODE_DOFS = 9
VARIANTS = ("plain", "completed")


class Plate(Body):
    """A thin plate (seed 003): flat rectangle from ``corner`` along the orthogonal edge
    vectors ``edge_x``, ``edge_y``, nx x ny elements, thickness, variant 'plain' or
    'completed'. Leaves (:class:`Leaf`) are curved plates."""

    flexible = True
    surface = True

    @property
    def nnodes(self) -> int:
        return self.mesh.nnodes

    @property
    def mesh_nodes(self) -> int:
        return self.mesh.nnodes

    @property
    def extent(self) -> float:
        return float(np.ptp(self.mesh.coords[:, :3], axis=0).max())

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

    # -- what the assembly asks of a flexible body besides its set ---------------------------
    def point_mass(self, at: Attachment, mass: float) -> np.ndarray:
        """A point mass's share of its element's compact mass matrix."""
        shape, _ = kernel.plate_shape(*at.local, self.mesh.a[at.element],
                                      self.mesh.b[at.element])
        return mass * np.outer(shape, shape)

    def gravity_forces(self, g: np.ndarray) -> np.ndarray:
        """Generalized gravity forces per element of the acceleration g (3,)."""
        _, elements = kernel.plate_element_arrays(
            self.mesh.a, self.mesh.b, self.thickness, self.material.density,
            self.material.density * self.thickness * g)
        return elements

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


PLATE_KEYS: dict[str, Key] = {
    "name": name_key(),
    "material": Key("str", doc="name of a &material"),
    "thickness": Key("float", check=positive, doc="thickness (m)"),
    "corner": Key("floats", check=vector3, doc="first corner (m)"),
    "edge_x": Key("floats", check=vector3, doc="edge vector along the length (m)"),
    "edge_y": Key("floats", check=vector3, doc="edge vector across, orthogonal (m)"),
    "nx": Key("int", check=positive, doc="elements along edge_x"),
    "ny": Key("int", check=positive, doc="elements along edge_y"),
    "variant": Key("str", "completed", one_of("plain", "completed"), "thin plate variant"),
}

LEAF_KEYS: dict[str, Key] = {
    "name": name_key(),
    "material": Key("str", doc="name of a &material"),
    "thickness": Key("float", check=positive, doc="thickness (m)"),
    "width": Key("float", check=positive, doc="width along r2 (m)"),
    "arc_length": Key("float", check=positive, doc="mid-surface arc length (m)"),
    "radius": Key("float", check=positive, doc="mid-surface radius, concave up (m)"),
    "centre": Key("floats", check=vector3, doc="midpoint (lowest point) of the arc (m)"),
    "nx": Key("int", check=positive, doc="elements along the arc (even)"),
    "ny": Key("int", 1, positive, "elements across the width"),
    "variant": Key("str", "completed", one_of("plain", "completed"), "thin plate variant"),
    "free_radius": Key("float", None, positive, "stress-free radius (prestress; needs the "
                       "effect 'prestress')"),
}


def part_of(group: str, name: str, nodes: int) -> validate.Part:
    """A plate's or leaf's share of the memory estimate."""
    return validate.Part(f"{group}[{name}]", "nx", group, nodes, PLATE_NODE_DOFS)


def build_plate(system, v: dict) -> Plate:
    """A plate from the values of ``System.add('plate', ...)``."""
    name = system._body_name(v["name"])
    v = checked_values(PLATE, f"plate[{name}]", v)
    system._check_size(part_of("plate", name, (v["nx"] + 1) * (v["ny"] + 1)))
    return system._add_body(Plate(name, system._material(v["material"], f"plate {name!r}"),
                                  v["thickness"], v["corner"], v["edge_x"], v["edge_y"],
                                  v["nx"], v["ny"], variant=v["variant"]))


def build_leaf(system, v: dict) -> Leaf:
    """A leaf from the values of ``System.add('leaf', ...)``."""
    name = system._body_name(v["name"])
    v = checked_values(LEAF, f"leaf[{name}]", v)
    system._check_size(part_of("leaf", name, (v["nx"] + 1) * (v["ny"] + 1)))
    return system._add_body(Leaf(name, system._material(v["material"], f"leaf {name!r}"),
                                 v["thickness"], v["width"], v["arc_length"], v["radius"],
                                 v["centre"], v["nx"], v["ny"], variant=v["variant"],
                                 free_radius=v["free_radius"]))


def check_dimensions(body: Plate, word: str, length_key: str) -> None:
    """A plate's or leaf's largest extent and thickness within the physical minima."""
    where = f"{word} {body.name!r}"
    extent = float(np.ptp(body.mesh.coords[:, :3], axis=0).max())
    validate.check_minimum("length", extent, f"{where}: the largest extent", key=length_key)
    validate.check_minimum("section", body.thickness, f"{where}: thickness", key="thickness")


def _plate_set(plate: Plate, context: SetContext) -> SetInfo:
    active, counters, warnings = context.active, context.counters, context.warnings
    mesh = plate.mesh
    dofs = plate.element_dofs()
    local = dofs - plate.first
    reference = mesh.coords
    if getattr(plate, "prestressed", False):
        if "prestress" in active:
            reference = plate.reference_coords
            counters["prestress"] += 1
        else:
            warnings.append(f"leaf {plate.name!r} has a free radius but the effect 'prestress' is "
                            "not listed: it is stress-free as built")
    ref = kernel.PlateReference(reference.ravel()[local].reshape(3, 12, mesh.nel, order="F"),
                                mesh.a, mesh.b, plate.variant)
    mass_compact, _ = kernel.plate_element_arrays(mesh.a, mesh.b, plate.thickness,
                                                  plate.material.density, np.zeros(3))
    return SetInfo(body=plate, kind="plate", dofs=dofs, nel=mesh.nel, frame=0,
                   mass_compact=mass_compact, plate_reference=ref)



def _add_plate(ks: kernel.KernelSystem, s: SetInfo) -> int:
    return ks.add_plate_set(s.dofs, s.scatter, s.plate_reference, s.body.material.youngs_modulus,
                            s.body.material.poisson_ratio, s.body.thickness, s.damping_time)



def _mesh(body: Plate, rows) -> None:
    """XDMF: the elements as quadrilaterals through the corner nodes."""
    base = rows.node_points(body.first, body.mesh.nnodes, 9)
    rows.quads.append(body.mesh.elements + base)


PLATE = register(Kind(
    group="plate", body_class=Plate, keys=PLATE_KEYS, build=build_plate, api="plate",
    word="plate", objects=("material",), set_builder=_plate_set, adders={"plate": _add_plate},
    part=lambda body: part_of("plate", body.name, body.mesh.nnodes),
    check_dimensions=lambda body: check_dimensions(body, "plate", "edge_x"), mesh=_mesh))
LEAF = register(Kind(
    group="leaf", body_class=Leaf, keys=LEAF_KEYS, build=build_leaf, api="leaf", word="leaf",
    objects=("material",), set_builder=_plate_set,
    part=lambda body: part_of("leaf", body.name, body.mesh.nnodes),
    check_dimensions=lambda body: check_dimensions(body, "leaf", "arc_length"),
    effects=lambda body: {"prestress"} if body.prestressed else set(), mesh=_mesh))
