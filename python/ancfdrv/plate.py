"""Thin-plate models (seed 003): meshes of rectangular plates and curved leaves, and
:class:`PlateModel` over the kernel's plate element (``fortran/src/plate_element.f90``).

A node carries 9 coordinates [r, r_x, r_y]; an element 4 nodes (36 coordinates),
counter-clockwise from its (x0, y0) corner. ``x`` runs along the plate's length (for a
leaf: the arc length), ``y`` along its width. The model has the interface the static and
dynamic solvers use (``internal_force``, ``constant_force``, ``moment_terms``,
``mass_values``, ``pattern``, ``constraints``, ``probes``, ``stepper_arrays``), with
``formulation = 'plate'``.

Prestress (seed 003, section on the leaf spring): the completed element's reference
(stress-free) configuration may differ from the initial one; a leaf built at its assembled
radius with a reference at its free radius starts with the assembly bending moment.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from . import kernel
from .constraints import ConstraintSet
from .errors import InputError
from .model import DeadMomentLoads

PLATE_NODE_DOFS = 9
#: Offsets of a node's r, r_x, r_y within its 9 coordinates.
P_R, P_RX, P_RY = 0, 3, 6


def plate_node_dofs(node: int, part: int = P_R) -> list[int]:
    """0-based global indices of the 3 coordinates of ``part`` of ``node``."""
    start = PLATE_NODE_DOFS * node + part
    return list(range(start, start + 3))


@dataclass
class PlateMesh:
    """Nodes (initial configuration), connectivity, element sizes and named node sets.

    ``coords`` is (nnodes, 9): r, r_x, r_y per node. ``grid[i, j]`` is the node at the
    i-th station along x and the j-th across y. Node numbering runs fastest across the
    shorter side, which keeps the banded solver's bandwidth small.
    """

    coords: np.ndarray
    elements: np.ndarray          # (nel, 4) node ids
    a: np.ndarray                 # (nel,) element length along x (parent coordinate)
    b: np.ndarray                 # (nel,) element width along y
    grid: np.ndarray              # (nx + 1, ny + 1) node ids
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def nnodes(self) -> int:
        return len(self.coords)

    @property
    def nel(self) -> int:
        return len(self.elements)

    def element_at(self, xi_global: float, eta_global: float) -> tuple[int, float, float]:
        """Element and local (xi, eta) in [0, 1]^2 of the point at fractions (xi_global,
        eta_global) of the plate's length and width."""
        nx, ny = self.grid.shape[0] - 1, self.grid.shape[1] - 1
        i = min(int(xi_global * nx), nx - 1)
        j = min(int(eta_global * ny), ny - 1)
        return j * nx + i, xi_global * nx - i, eta_global * ny - j


def _grid_mesh(stations_x: np.ndarray, stations_y: np.ndarray, node_vectors) -> PlateMesh:
    """A structured mesh; node_vectors(s, y) -> (r, r_x, r_y) of the point at parent
    coordinates (s, y)."""
    nx, ny = len(stations_x) - 1, len(stations_y) - 1
    if nx < 1 or ny < 1:
        raise InputError("a plate mesh needs at least one element in each direction")
    grid = np.zeros((nx + 1, ny + 1), dtype=int)
    for i in range(nx + 1):
        for j in range(ny + 1):
            grid[i, j] = i * (ny + 1) + j if ny <= nx else j * (nx + 1) + i
    coords = np.zeros((grid.size, PLATE_NODE_DOFS))
    for i, s in enumerate(stations_x):
        for j, y in enumerate(stations_y):
            coords[grid[i, j]] = np.concatenate(node_vectors(s, y))
    elements, a, b = [], [], []
    for j in range(ny):
        for i in range(nx):
            elements.append([grid[i, j], grid[i + 1, j], grid[i + 1, j + 1], grid[i, j + 1]])
            a.append(stations_x[i + 1] - stations_x[i])
            b.append(stations_y[j + 1] - stations_y[j])
    sets = {
        "edge_x0": grid[0, :], "edge_x1": grid[-1, :], "edge_y0": grid[:, 0],
        "edge_y1": grid[:, -1], "corner_00": grid[:1, 0], "corner_10": grid[-1:, 0],
        "corner_11": grid[-1:, -1], "corner_01": grid[:1, -1],
    }
    if nx % 2 == 0:
        sets["middle_x"] = grid[nx // 2, :]
    sets["boundary"] = np.unique(np.concatenate([grid[0, :], grid[-1, :], grid[:, 0],
                                                 grid[:, -1]]))
    return PlateMesh(coords, np.array(elements), np.array(a), np.array(b), grid, sets)


def rectangle_mesh(length_x: float, length_y: float, nx: int, ny: int,
                   origin=(0.0, 0.0, 0.0)) -> PlateMesh:
    """A flat rectangular plate in the r1-r2 plane with corner (0, 0) at ``origin``."""
    origin = np.asarray(origin, dtype=float)

    def vectors(s: float, y: float):
        return origin + [s, y, 0.0], np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    return _grid_mesh(np.linspace(0.0, length_x, nx + 1), np.linspace(0.0, length_y, ny + 1),
                      vectors)


def arc_point(s: float, radius: float, z_offset: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Point and unit tangent at arc length s from the middle of a circular arc in the
    r1-r3 plane, concave up (its centre above the middle point), lowest point at r3 =
    z_offset; radius = inf gives the straight line."""
    if not np.isfinite(radius):
        return np.array([s, 0.0, z_offset]), np.array([1.0, 0.0, 0.0])
    theta = s / radius
    return (np.array([radius * np.sin(theta), 0.0, z_offset + radius * (1.0 - np.cos(theta))]),
            np.array([np.cos(theta), 0.0, np.sin(theta)]))


def arc_mesh(arc_length: float, radius: float, width: float, nx: int, ny: int,
             z_offset: float = 0.0) -> PlateMesh:
    """A leaf: a cylindrical strip bent about r2, symmetric about r1 = 0, concave up, its
    mid-surface given by arc length x in [-L/2, L/2] and width y in [-w/2, w/2]. The
    nodal gradients are exact (unit tangent, r_y = e2), so the parent coordinates measure
    reference length."""
    if np.isfinite(radius) and arc_length > 2 * np.pi * radius:
        raise InputError(f"leaf arc length {arc_length} m exceeds the circle of radius "
                         f"{radius} m")

    def vectors(s: float, y: float):
        point, tangent = arc_point(s, radius, z_offset)
        return point + [0.0, y, 0.0], tangent, np.array([0.0, 1.0, 0.0])
    return _grid_mesh(np.linspace(-arc_length / 2, arc_length / 2, nx + 1),
                      np.linspace(-width / 2, width / 2, ny + 1), vectors)


@dataclass
class DirectorMoment:
    """Dead moment ``magnitude`` about ``axis`` on a nodal direction vector (e.g. the r_x
    of an edge node: the edge's rotation about the axis does the work)."""

    dofs: list[int]
    axis: np.ndarray
    magnitude: float
    effect: str


@dataclass
class PlateProbe:
    """A material point of the mid-surface: element and local (xi, eta) in [0, 1]^2."""

    element: int
    xi: float
    eta: float


@dataclass
class PlateModel(DeadMomentLoads):
    """A thin-plate mesh with the plain or completed element (seed 003)."""

    mesh: PlateMesh
    thickness: float
    density: float
    youngs: float
    poisson: float
    variant: str                              # 'plain' | 'completed'
    effects: tuple[str, ...]
    reference: np.ndarray | None = None       # stress-free coords (nnodes, 9); None: initial
    load_factor: float = 1.0
    constraints: ConstraintSet = field(default_factory=ConstraintSet)
    moments: list[DirectorMoment] = field(default_factory=list)
    probes: dict[str, PlateProbe] = field(default_factory=dict)
    counters: Counter = field(default_factory=Counter)
    warnings: list[str] = field(default_factory=list)
    formulation: str = "plate"
    #: the probe and component sweeps compare (set by the builders)
    response: tuple[str, int] = ("corner", 2)

    def __post_init__(self) -> None:
        from .io.scene import EFFECTS_AVAILABLE
        for effect in EFFECTS_AVAILABLE:
            self.counters[effect] += 0
        if self.reference is not None and self.variant != "completed":
            raise InputError("a stress-free reference different from the initial shape "
                             "(prestress) needs plate variant 'completed'")
        mesh = self.mesh
        self.nnodes, self.nel = mesh.nnodes, mesh.nel
        self.ndof = PLATE_NODE_DOFS * self.nnodes
        self.dofs = (PLATE_NODE_DOFS * mesh.elements[:, :, None]
                     + np.arange(PLATE_NODE_DOFS)).reshape(self.nel, 36).T
        self.e0 = mesh.coords.ravel().copy()
        reference = mesh.coords if self.reference is None else self.reference
        self.reference_data = kernel.PlateReference(
            reference.ravel()[self.dofs].reshape(3, 12, self.nel, order="F"), mesh.a, mesh.b,
            self.variant)
        self.counters["element_arrays"] += self.nel
        self.mass_compact, _ = kernel.plate_element_arrays(mesh.a, mesh.b, self.thickness,
                                                           self.density, np.zeros(3))
        self.pattern = kernel.SparsePattern(self.ndof, self.dofs)
        self._surface_force = np.zeros(self.ndof)
        self._point_force = np.zeros(self.ndof)
        positions = mesh.coords[:, :3]
        self.length_scale = float(np.ptp(positions, axis=0).max())

    # -- matrices -----------------------------------------------------------------------
    def mass_values(self) -> np.ndarray:
        """CSR values of the constant mass matrix on ``pattern``."""
        element = np.einsum("abe,ij->aibje", self.mass_compact, np.eye(3)).reshape(36, 36, -1)
        return self.pattern.assemble(element)

    def mass_matrix(self) -> sp.csr_matrix:
        return self.pattern.to_scipy(self.mass_values())

    # -- forces -------------------------------------------------------------------------
    def internal_force(self, e: np.ndarray, t: float = 0.0,
                       want_tangent: bool = False) -> tuple[np.ndarray, float, np.ndarray | None]:
        """Elastic force, strain energy and, on request, the CSR values of the tangent."""
        self.counters["elastic_force"] += 1
        force, energy, tangent = kernel.plate_forces(
            self.dofs, e, self.reference_data, self.youngs, self.poisson, self.thickness,
            want_tangent)
        if want_tangent:
            self.counters["stiffness_assembly"] += 1
            return force, energy, self.pattern.assemble(tangent)
        return force, energy, None

    def constant_force(self) -> np.ndarray:
        """Configuration-independent loads of the listed effects, times the load factor."""
        return self.load_factor * (self._surface_force + self._point_force)

    # -- loads set-up (only for listed effects) -------------------------------------------
    def add_surface_load(self, load_per_area: np.ndarray, effect: str) -> None:
        """A constant load per unit area (gravity: rho h g; a dead pressure: q n0)."""
        _, element = kernel.plate_element_arrays(self.mesh.a, self.mesh.b, self.thickness,
                                                 self.density, load_per_area)
        np.add.at(self._surface_force, self.dofs.reshape(-1, order="F"),
                  element.reshape(-1, order="F"))
        self.counters[effect] += 1

    def add_gravity(self, g: np.ndarray) -> None:
        self.add_surface_load(self.density * self.thickness * np.asarray(g, dtype=float),
                              "gravity")

    def add_point_force(self, node: int, force: np.ndarray, effect: str) -> None:
        self._point_force[plate_node_dofs(node)] += force
        self.counters[effect] += 1

    def add_edge_moment(self, nodes: np.ndarray, axis: np.ndarray, total: float,
                        effect: str) -> None:
        """A dead moment ``total`` about ``axis`` on an edge x = const, shared by the edge
        nodes' r_x in proportion to their tributary width (trapezoidal rule)."""
        y = self.mesh.coords[nodes, 1]
        order = np.argsort(y)
        nodes, y = np.asarray(nodes)[order], y[order]
        widths = np.zeros(len(nodes))
        widths[:-1] += 0.5 * np.diff(y)
        widths[1:] += 0.5 * np.diff(y)
        for node, w in zip(nodes, widths):
            self.moments.append(DirectorMoment(plate_node_dofs(node, P_RX), np.asarray(axis),
                                               total * w / widths.sum(), effect))

    # -- constraints ----------------------------------------------------------------------
    def fix(self, nodes, part: int = P_R, components=(0, 1, 2), name: str = "") -> None:
        """Fix components of a nodal vector at their initial values."""
        for node in np.atleast_1d(nodes):
            for c in components:
                dof = PLATE_NODE_DOFS * int(node) + part + c
                self.constraints.coordinate(dof, float(self.e0[dof]),
                                            name=f"{name or 'fixed'}: node {node} e[{dof}]")

    # -- output quantities --------------------------------------------------------------
    def point_position(self, probe: PlateProbe, e: np.ndarray) -> np.ndarray:
        """Position of a mid-surface material point at coordinates e."""
        shape, _ = kernel.plate_shape(probe.xi, probe.eta, self.mesh.a[probe.element],
                                      self.mesh.b[probe.element])
        return shape @ e[self.dofs[:, probe.element]].reshape(12, 3)

    def probe_positions(self, e: np.ndarray) -> dict[str, np.ndarray]:
        return {name: self.point_position(probe, e) for name, probe in self.probes.items()}

    def deflections(self, e: np.ndarray) -> dict[str, np.ndarray]:
        """Probe displacement from the initial configuration (global components)."""
        initial = self.probe_positions(self.e0)
        return {name: p - initial[name] for name, p in self.probe_positions(e).items()}

    def deflections_at(self, e: np.ndarray, t: float) -> dict[str, np.ndarray]:
        return self.deflections(e)

    def summary(self) -> dict[str, int]:
        return {"ndof": self.ndof, "nnodes": self.nnodes, "nelements": self.nel,
                "nconstraints": len(self.constraints)}

    def stepper_arrays(self) -> dict:
        """The element part of the kernel stepper's arguments (formulation 2: plate)."""
        shapes, references, probe_dofs = [], [], []
        initial = self.probe_positions(self.e0)
        for name, probe in self.probes.items():
            shape, _ = kernel.plate_shape(probe.xi, probe.eta, self.mesh.a[probe.element],
                                          self.mesh.b[probe.element])
            shapes.append(shape)
            references.append(initial[name])
            probe_dofs.append(self.dofs[:, probe.element] + 1)
        ref = self.reference_data
        f = np.asfortranarray
        return dict(
            formulation=2, dofs=f(self.dofs + 1, dtype=np.int32),
            stiffness0=np.zeros((36, 36, 1), order="F"), e0_frame=f(self.e0),
            youngs=self.youngs, poisson=self.poisson,
            gauss_gradients=np.zeros((8, 3, 1, 1), order="F"),
            gauss_weights=np.zeros((1, 1), order="F"),
            plate_derivs=ref.derivs, plate_frame=ref.frame, plate_curvature0=ref.curvature0,
            plate_weights=ref.weights, thickness=self.thickness,
            frame_drive=0, frame_axis=np.array([0.0, 0.0, 1.0]), frame_base=f(np.eye(3)),
            probe_dofs=f(np.array(probe_dofs, dtype=np.int32).reshape(-1, 36).T),
            probe_shape=f(np.array(shapes).reshape(-1, 12).T),
            probe_reference=f(np.array(references).reshape(-1, 3).T),
        )


# -- builders ---------------------------------------------------------------------------
def _material(scene) -> dict:
    material = scene["material"]
    return dict(density=material["density"], youngs=material["youngs_modulus"],
                poisson=material["poisson_ratio"])


def build_plate(scene) -> PlateModel:
    """A flat rectangular plate in the r1-r2 plane (SPEC section 6 for the pendulum); probe
    ``corner`` at (length_x, length_y, 0) and ``centre``."""
    plate, loads, effects = scene["plate"], scene["loads"], scene.effects
    mesh = rectangle_mesh(plate["length_x"], plate["length_y"], plate["nx"], plate["ny"])
    model = PlateModel(mesh, plate["thickness"], variant=plate["variant"], effects=effects,
                       **_material(scene))
    support = plate["support"]
    if support == "corner_spherical":
        model.fix(mesh.node_sets["corner_00"], P_R, name="spherical joint")
    elif support == "clamped_edge":
        edge = mesh.node_sets["edge_x0"]
        model.fix(edge, P_R, name="clamped edge")
        model.fix(edge, P_RY, name="clamped edge")
        model.fix(edge, P_RX, components=(2,), name="clamped edge slope")
    else:  # simply supported: w = 0 on the boundary, in-plane rigid motion removed
        boundary = mesh.node_sets["boundary"]
        model.fix(boundary, P_R, components=(2,), name="simple support w = 0")
        model.fix(np.union1d(mesh.node_sets["edge_y0"], mesh.node_sets["edge_y1"]), P_RX,
                  components=(2,), name="simple support dw/dx = 0 along the edge")
        model.fix(np.union1d(mesh.node_sets["edge_x0"], mesh.node_sets["edge_x1"]), P_RY,
                  components=(2,), name="simple support dw/dy = 0 along the edge")
        corner = mesh.node_sets["corner_00"]
        model.fix(corner, P_R, components=(0, 1), name="in-plane pin")
        model.fix(mesh.node_sets["corner_10"], P_R, components=(1,), name="in-plane roller")
    if "gravity" in effects:
        model.add_gravity(np.array([0.0, 0.0, -loads["gravity"]]))
    if "pressure" in effects:
        model.add_surface_load(np.array([0.0, 0.0, -loads["pressure"]]), "pressure")
    model.probes["corner"] = PlateProbe(*mesh.element_at(1.0, 1.0))
    model.probes["centre"] = PlateProbe(*mesh.element_at(0.5, 0.5))
    # sweeps compare the displacement along r3: of the corner (pendulum), else the centre
    model.response = ("corner", 2) if support == "corner_spherical" else ("centre", 2)
    return model


def build_leaf(scene) -> PlateModel:
    """A curved leaf (circular arc, concave up) in its assembled shape; with 'prestress'
    its stress-free reference is the arc of free_radius with the same middle line. Probes
    ``end`` (middle of the edge at r1 > 0) and ``middle``."""
    leaf, loads, effects = scene["leaf"], scene["loads"], scene.effects
    mesh = arc_mesh(leaf["arc_length"], leaf["radius"], leaf["width"], leaf["nx"], leaf["ny"])
    reference = None
    if "prestress" in effects:
        reference = arc_mesh(leaf["arc_length"], leaf["free_radius"], leaf["width"],
                             leaf["nx"], leaf["ny"]).coords
        model_counter = "prestress"
    model = PlateModel(mesh, leaf["thickness"], variant=leaf["variant"], effects=effects,
                       reference=reference, **_material(scene))
    if reference is not None:
        model.counters[model_counter] += 1
    if leaf["support"] == "middle_clamp":
        middle = mesh.node_sets["middle_x"]
        model.fix(middle, P_R, name="axle clamp r")
        model.fix(middle, P_RX, name="axle clamp r_x")
    if "gravity" in effects:
        model.add_gravity(np.array([0.0, 0.0, -loads["gravity"]]))
    model.probes["end"] = PlateProbe(*mesh.element_at(1.0, 0.5))
    model.probes["middle"] = PlateProbe(*mesh.element_at(0.5, 0.5))
    model.response = ("end", 2)  # what sweeps compare: the end's displacement along r3
    return model
