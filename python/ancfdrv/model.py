"""Models built over the Fortran kernel: the multi-node ANCF-FFR beam of seed 000.

A :class:`BeamModel` holds the mesh, the constant element arrays (mass, K0 in the
floating frame), the constraints, the loads of the effects the scene lists (and only
those), the probes, and counters of every kernel evaluation. Builders:
:func:`build_boom` (SPEC section 5) and :func:`build_cantilever`; :func:`build_model`
picks the one the scene asks for.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from scipy.spatial.transform import Rotation

from . import kernel
from .constraints import DRIVE_CONSTANT, DRIVE_LUFFING, DRIVE_SPINUP, ConstraintSet
from .io.scene import EFFECTS_AVAILABLE, Scene

NODE_DOFS = 12
#: Offsets of a node's r, r_x, r_y, r_z within its 12 coordinates.
R, RX, RY, RZ = 0, 3, 6, 9


def node_dofs(node: int, part: int = R, count: int = 3) -> list[int]:
    """0-based global indices of ``count`` coordinates of ``part`` of ``node``."""
    start = NODE_DOFS * node + part
    return list(range(start, start + count))


def rotation_z(angle: float) -> np.ndarray:
    """Rotation matrix about +r3."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@dataclass
class Moment:
    """Dead moment ``magnitude`` about ``axis`` on the section of a node (director r_y)."""

    node: int
    axis: np.ndarray
    magnitude: float
    effect: str

    @property
    def dofs(self) -> list[int]:
        return node_dofs(self.node, RY)


@dataclass
class Probe:
    """A material point: element, xi in [0, 1], section coordinates y, z."""

    element: int
    xi: float
    y: float = 0.0
    z: float = 0.0


class DeadMomentLoads:
    """External loads shared by the models: the constant loads of ``constant_force()`` plus
    dead moments on nodal direction vectors (``moments``: dofs, axis, magnitude, effect),
    all scaled by ``load_factor``; each moment evaluation is counted under its effect."""

    def moment_terms(self, e: np.ndarray):
        """Per moment: (dofs, force, Jacobian, Hessian) at e."""
        out = []
        for moment in self.moments:
            self.counters[moment.effect] += 1
            f, j, h = kernel.moment_force(e[moment.dofs], moment.axis,
                                          self.load_factor * moment.magnitude)
            out.append((moment.dofs, f, j, h))
        return out

    def external_force(self, e: np.ndarray) -> np.ndarray:
        """Constant loads plus the dead moments at e."""
        force = self.constant_force()
        for dofs, f, _, _ in self.moment_terms(e):
            force[dofs] += f
        return force


@dataclass
class BeamModel(DeadMomentLoads):
    """A straight multi-node ANCF beam with the FFR elastic model."""

    node_s: np.ndarray            # arc length of every node (m)
    width: float
    height: float
    density: float
    youngs: float
    poisson: float
    rotation: np.ndarray          # floating frame A at t = 0 (3 x 3)
    origin_offset: np.ndarray     # frame position of the neutral axis start (3,)
    effects: tuple[str, ...]
    frame_drive: int = 0          # drive of the frame angle (0: the frame is fixed)
    frame_axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    frame_base: np.ndarray | None = None  # A(t) = Rot(axis, phi(t)) frame_base
    formulation: str = "ffr"      # 'ffr' (small strain in the frame) or 'nonlinear'
    bending: str = "continuum"    # 'continuum' (the paper's element) or 'cubic' (r_xx)
    load_factor: float = 1.0      # scales every external load (load stepping)
    constraints: ConstraintSet = field(default_factory=ConstraintSet)
    moments: list[Moment] = field(default_factory=list)
    point_masses: list[tuple[int, float]] = field(default_factory=list)
    probes: dict[str, Probe] = field(default_factory=dict)
    counters: Counter = field(default_factory=Counter)
    warnings: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        for effect in EFFECTS_AVAILABLE:
            self.counters[effect] += 0
        self.nnodes = len(self.node_s)
        self.nel = self.nnodes - 1
        self.ndof = NODE_DOFS * self.nnodes
        self.lengths = np.diff(self.node_s)
        self.dofs = np.array([np.arange(24) + NODE_DOFS * el for el in range(self.nel)]).T
        # reference (rigid) configuration in the frame: straight along x
        e0 = np.zeros((self.nnodes, NODE_DOFS))
        e0[:, 0:3] = self.origin_offset
        e0[:, 0] += self.node_s
        e0[:, 3:12] = np.eye(3).ravel()
        self.e0_frame = e0.ravel()
        reference = self.e0_frame[self.dofs].reshape(3, 8, self.nel, order="F")
        self.mass_compact, self.stiffness0 = kernel.beam_element_arrays(
            self.lengths, self.width, self.height, self.density, self.youngs, self.poisson,
            reference)
        self.counters["element_arrays"] += self.nel
        self.structural: kernel.StructuralBeam | None = None
        if self.bending == "cubic":
            # FFR: K0 is the structural tangent at the reference in the frame; nonlinear:
            # the forms from the reference in the global frame (only what the scene runs)
            frame_reference = self.formulation == "ffr"
            self.structural = kernel.StructuralBeam(
                (self.e0_frame if frame_reference else self.to_global(self.e0_frame))[
                    self.dofs].reshape(3, 8, self.nel, order="F"),
                self.lengths, self.width, self.height, self.youngs, self.poisson)
            if frame_reference:
                *_, self.stiffness0 = self.structural.forces(self.dofs, self.e0_frame, True)
                self.structural = None
        elif self.formulation == "nonlinear":
            self.gauss_gradients, self.gauss_weights = kernel.beam_nonlinear_setup(
                self.to_global(self.e0_frame)[self.dofs].reshape(3, 8, self.nel, order="F"),
                self.lengths, self.width, self.height)
        self.pattern = kernel.SparsePattern(self.ndof, self.dofs)
        self._gravity_force: np.ndarray | None = None
        self._point_force = np.zeros(self.ndof)
        if self.frame_base is None:
            self.frame_base = self.rotation.copy()
        self.length_scale = float(self.node_s[-1] - self.node_s[0])

    # -- configuration ---------------------------------------------------------------
    @property
    def e0(self) -> np.ndarray:
        """Rigid configuration in the global frame, T(A) e0_frame."""
        return self.to_global(self.e0_frame)

    def to_global(self, v: np.ndarray) -> np.ndarray:
        """T(A) v: rotate every 3-vector of a coordinate vector into the global frame."""
        return (v.reshape(-1, 3) @ self.rotation.T).ravel()

    def to_frame(self, v: np.ndarray) -> np.ndarray:
        """T(A)^T v."""
        return (v.reshape(-1, 3) @ self.rotation).ravel()

    def frame_at(self, t: float) -> np.ndarray:
        """The floating frame A(t) = Rot(axis, phi(t)) A_base (A_base when not driven)."""
        if not self.frame_drive:
            return self.frame_base
        phi, _, _ = kernel.drive_values(self.constraints.drive_kinds[self.frame_drive - 1],
                                        self.constraints.drive_params[self.frame_drive - 1], t)
        axis = self.frame_axis / np.linalg.norm(self.frame_axis)
        return Rotation.from_rotvec(phi[0] * axis).as_matrix() @ self.frame_base

    # -- matrices --------------------------------------------------------------------
    def mass_matrix(self) -> sp.csr_matrix:
        """Constant mass matrix: kron(compact, I3) per element plus point masses."""
        return self.pattern.to_scipy(self.mass_values())

    def mass_values(self) -> np.ndarray:
        """CSR values of the mass matrix on ``pattern`` (point masses on the diagonal)."""
        element = np.einsum("abe,ij->aibje", self.mass_compact, np.eye(3)).reshape(24, 24, -1)
        values = self.pattern.assemble(element)
        for node, m in self.point_masses:
            for d in node_dofs(node, R):
                row = self.pattern.col_index[self.pattern.row_ptr[d]:self.pattern.row_ptr[d + 1]]
                values[self.pattern.row_ptr[d] + np.searchsorted(row, d)] += m
        return values

    def stiffness_values(self, t: float = 0.0) -> np.ndarray:
        """CSR values (on ``pattern``) of the FFR stiffness K = T K0 T^T in the frame A(t)."""
        self.counters["stiffness_assembly"] += 1
        return self.pattern.assemble(kernel.ffr_element_stiffness(self.stiffness0,
                                                                  self.frame_at(t)))

    def stiffness_matrix(self) -> sp.csr_matrix:
        return self.pattern.to_scipy(self.stiffness_values())

    # -- forces ----------------------------------------------------------------------
    def internal_force(self, e: np.ndarray, t: float = 0.0,
                       want_tangent: bool = False) -> tuple[np.ndarray, float, np.ndarray | None]:
        """Elastic force, strain energy and, on request, the CSR values of the tangent, for
        the scene's formulation (FFR: T K0 (T^T e - e0) in the frame A(t))."""
        self.counters["elastic_force"] += 1
        if self.formulation == "ffr":
            force, energy = kernel.ffr_force(self.dofs, self.stiffness0, self.frame_at(t), e,
                                             self.e0_frame)
            return force, energy, self.stiffness_values(t) if want_tangent else None
        if self.structural is not None:
            force, energy, tangent = self.structural.forces(self.dofs, e, want_tangent)
        else:
            force, energy, tangent = kernel.beam_nonlinear_forces(
                self.dofs, e, self.gauss_gradients, self.gauss_weights, self.youngs,
                self.poisson, want_tangent)
        if want_tangent:
            self.counters["stiffness_assembly"] += 1
            return force, energy, self.pattern.assemble(tangent)
        return force, energy, None

    def constant_force(self) -> np.ndarray:
        """Configuration-independent loads of the listed effects (gravity, tip loads),
        times the load factor."""
        force = self._point_force.copy()
        if self._gravity_force is not None:
            force += self._gravity_force
        return self.load_factor * force

    # -- loads set-up (only for listed effects) ----------------------------------------
    def add_gravity(self, g: np.ndarray) -> None:
        elements = kernel.beam_gravity(self.lengths, self.width, self.height, self.density, g)
        force = np.zeros(self.ndof)
        np.add.at(force, self.dofs.reshape(-1, order="F"), elements.reshape(-1, order="F"))
        for node, m in self.point_masses:
            force[node_dofs(node, R)] += m * g
        self._gravity_force = force
        self.counters["gravity"] += 1

    def add_point_force(self, node: int, force: np.ndarray, effect: str) -> None:
        self._point_force[node_dofs(node, R)] += force
        self.counters[effect] += 1

    # -- output quantities --------------------------------------------------------------
    def probe_positions(self, e: np.ndarray) -> dict[str, np.ndarray]:
        out = {}
        for name, probe in self.probes.items():
            shape, *_ = kernel.beam_shape([probe.xi], [probe.y], [probe.z],
                                          [self.lengths[probe.element]])
            q = e[self.dofs[:, probe.element]].reshape(8, 3)
            out[name] = shape[:, 0] @ q
        return out

    def deflections(self, e: np.ndarray) -> dict[str, np.ndarray]:
        """Probe displacement from the rigid configuration, in frame components (t = 0)."""
        return self.deflections_at(e, 0.0)

    def deflections_at(self, e: np.ndarray, t: float) -> dict[str, np.ndarray]:
        """Probe displacement from the rigid configuration at t, in the frame A(t)."""
        rigid = self.probe_positions(self.e0_frame)
        frame = self.frame_at(t)
        return {name: frame.T @ p - rigid[name] for name, p in self.probe_positions(e).items()}

    def stepper_arrays(self) -> dict:
        """The element part of the kernel stepper's arguments (formulation 0 FFR, 1 large
        deformation, 3 large deformation with 'cubic' bending)."""
        shapes, references, probe_dofs = [], [], []
        for probe in self.probes.values():
            shape, *_ = kernel.beam_shape([probe.xi], [probe.y], [probe.z],
                                          [self.lengths[probe.element]])
            shapes.append(shape[:, 0])
            dofs = self.dofs[:, probe.element]
            references.append(shape[:, 0] @ self.e0_frame[dofs].reshape(8, 3))
            probe_dofs.append(dofs + 1)
        nonlinear = self.formulation == "nonlinear" and self.structural is None
        structural = self.structural
        f = np.asfortranarray
        return dict(
            formulation=3 if structural is not None else 1 if nonlinear else 0,
            dofs=f(self.dofs + 1, dtype=np.int32),
            structural_forms=structural.forms if structural is not None
            else np.zeros((8, 8, 1, 1), order="F"),
            structural_strain0=structural.strain0 if structural is not None
            else np.zeros((1, 1), order="F"),
            structural_stiffness=structural.stiffness if structural is not None
            else np.zeros((1, 1), order="F"),
            stiffness0=self.stiffness0, e0_frame=f(self.e0_frame),
            youngs=self.youngs, poisson=self.poisson,
            gauss_gradients=self.gauss_gradients if nonlinear
            else np.zeros((8, 3, 1, 1), order="F"),
            gauss_weights=self.gauss_weights if nonlinear else np.zeros((1, 1), order="F"),
            frame_drive=self.frame_drive, frame_axis=f(self.frame_axis, dtype=float),
            frame_base=f(self.frame_base, dtype=float),
            probe_dofs=f(np.array(probe_dofs, dtype=np.int32).reshape(-1, 24).T),
            probe_shape=f(np.array(shapes).reshape(-1, 8).T),
            probe_reference=f(np.array(references).reshape(-1, 3).T),
        )

    def summary(self) -> dict[str, int]:
        return {"ndof": self.ndof, "nnodes": self.nnodes, "nelements": self.nel,
                "nconstraints": len(self.constraints)}


def _mesh(scene: Scene) -> np.ndarray:
    beam = scene["beam"]
    per_segment = (beam["nodes"] - 1) // len(beam["segments"])
    edges = np.concatenate([[0.0], np.cumsum(beam["segments"])])
    s = [np.linspace(a, b, per_segment + 1)[:-1] for a, b in zip(edges[:-1], edges[1:])]
    return np.concatenate(s + [[edges[-1]]])


def _model(scene: Scene, rotation: np.ndarray, offset: np.ndarray) -> BeamModel:
    beam, material = scene["beam"], scene["material"]
    return BeamModel(node_s=_mesh(scene), width=beam["width"], height=beam["height"],
                     density=material["density"], youngs=material["youngs_modulus"],
                     poisson=material["poisson_ratio"], rotation=rotation,
                     origin_offset=offset, effects=scene.effects,
                     formulation=scene["scene"]["formulation"], bending=beam["bending"])


def _apply_loads(model: BeamModel, scene: Scene) -> None:
    loads, effects = scene["loads"], scene.effects
    tip = model.nnodes - 1
    model.probes["tip"] = Probe(element=model.nel - 1, xi=1.0)
    if "tip_mass" in effects:
        model.point_masses.append((tip, loads["tip_mass"]))
        model.counters["tip_mass"] += 1
    elif loads["tip_mass"] > 0:
        model.warnings.append("loads.tip_mass is set but 'tip_mass' is not in scene.effects: "
                              "not applied")
    if "gravity" in effects:
        model.add_gravity(np.array([0.0, -loads["gravity"], 0.0]))
    if "tip_force" in effects:
        model.add_point_force(tip, np.asarray(loads["tip_force"]), "tip_force")
    if "end_moment" in effects:
        model.moments.append(Moment(tip, np.array([0.0, 0.0, 1.0]), loads["end_moment"],
                                    "end_moment"))
    for key, effect in (("tip_force", "tip_force"), ("end_moment", "end_moment"),
                        ("moment", "bending_moment")):
        if effect not in effects and np.any(np.asarray(loads[key]) != 0):
            model.warnings.append(f"loads.{key} is set but {effect!r} is not in scene.effects: "
                                  "not applied")


def build_boom(scene: Scene) -> BeamModel:
    """The crane boom of seed 000 with the supports of eqs. 30-36 (SPEC section 5).

    Frame A = R(phi) about the pivot O; rigid configuration: A1 = R(phi)(0, H, 0), axis
    R(phi)(1, 0, 0), section y axis R(phi)(0, 1, 0). A2 is the node at the end of the
    first segment, driven to R(phi)(a, H, 0).
    """
    boom, beam = scene["boom"], scene["beam"]
    phi = np.radians(boom["angle_deg"])
    height_h = boom["pivot_offset"]
    model = _model(scene, rotation_z(phi), np.array([0.0, height_h, 0.0]))
    a = beam["segments"][0]
    a2 = (beam["nodes"] - 1) // 3
    c = model.constraints
    r1, ry1, r2 = node_dofs(0, R), node_dofs(0, RY), node_dofs(a2, R)
    c.cross(r1, ry1, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), dependent=r1[0],
            name="eq. 30: r_y(A1) parallel to O A1")
    c.distance(r1, (0.0, 0.0, 0.0), height_h, dependent=r1[1], name="eq. 31: |O A1| = H")
    c.coordinate(r1[2], name="eq. 32: r3(A1) = 0")
    c.coordinate(ry1[2], name="eq. 33: r_y3(A1) = 0")
    if scene["scene"]["analysis"] != "static" and boom["omega"] > 0:
        sweep = np.radians(boom["angle_end_deg"] - boom["angle_deg"])
        drive = c.add_drive(DRIVE_LUFFING, [boom["omega"] * np.sign(sweep), boom["t_start"],
                                            boom["t_brake"], sweep, phi])
    else:
        drive = c.add_drive(DRIVE_CONSTANT, [phi])
    model.frame_drive, model.frame_base = drive, np.eye(3)
    c.coordinate(r2[0], cos_coef=a, sin_coef=-height_h, drive=drive,
                 name="eq. 34: r1(A2) = a cos(phi) - H sin(phi)")
    c.coordinate(r2[1], cos_coef=height_h, sin_coef=a, drive=drive,
                 name="eq. 35: r2(A2) = a sin(phi) + H cos(phi)")
    c.coordinate(r2[2], name="eq. 36: r3(A2) = 0")
    _apply_loads(model, scene)
    if "bending_moment" in scene.effects:
        model.moments.append(Moment(a2, np.array([0.0, 0.0, 1.0]), scene["loads"]["moment"],
                                    "bending_moment"))
    return model


def build_cantilever(scene: Scene) -> BeamModel:
    """A beam along +r1 with its root node clamped at the origin or hinged about r3
    (``cantilever.clamp``); frame A = I."""
    model = _model(scene, np.eye(3), np.zeros(3))
    parts = {"section": (R, RY, RZ), "full": (R, RX, RY, RZ), "pin": (R, RZ)}[
        scene["cantilever"]["clamp"]]
    e0 = model.e0
    for part in parts:
        for d in node_dofs(0, part):
            model.constraints.coordinate(d, e0[d], name=f"clamp e[{d}]")
    _apply_loads(model, scene)
    return model


def build_spinup(scene: Scene) -> BeamModel:
    """The spin-up beam of Simo & Vu-Quoc (REFERENCES.md): the root section clamped to a
    hub turning about r3 with the prescribed angle phi(t); the floating frame is the hub's,
    A(t) = R(phi(t)), in which the probe deflections are resolved."""
    spin = scene["spinup"]
    model = _model(scene, np.eye(3), np.zeros(3))
    c = model.constraints
    drive = c.add_drive(DRIVE_SPINUP, [spin["omega"], spin["period"], 0.0])
    model.frame_drive, model.frame_base = drive, np.eye(3)
    for d in node_dofs(0, R):
        c.coordinate(d, name=f"hub: e[{d}] = 0")
    r_y, r_z = node_dofs(0, RY), node_dofs(0, RZ)
    c.coordinate(r_y[0], sin_coef=-1.0, drive=drive, name="hub: r_y1 = -sin(phi)")
    c.coordinate(r_y[1], cos_coef=1.0, drive=drive, name="hub: r_y2 = cos(phi)")
    c.coordinate(r_y[2], name="hub: r_y3 = 0")
    for k, d in enumerate(r_z):
        c.coordinate(d, 1.0 if k == 2 else 0.0, name=f"hub: r_z{k + 1}")
    _apply_loads(model, scene)
    return model


def first_bending_frequency(model: BeamModel) -> float:
    """Clamped-free first bending frequency (rad/s) of the beam in its weak direction,
    (beta_1 L)^2 sqrt(EI / (rho A L^4)): the scale against which FFR's validity is judged."""
    length = model.length_scale
    inertia = model.width * model.height**3 / 12.0
    area = model.width * model.height
    return 1.875104068711961**2 * np.sqrt(model.youngs * inertia
                                          / (model.density * area * length**4))


def check_ffr_validity(model: BeamModel, scene: Scene) -> None:
    """Warn when an 'ffr' scene leaves the model's assumptions: a frame turning at a speed
    near or above the first bending frequency (no geometric stiffening in FFR)."""
    if model.formulation != "ffr" or not model.frame_drive:
        return
    kind = model.constraints.drive_kinds[model.frame_drive - 1]
    params = model.constraints.drive_params[model.frame_drive - 1]
    rate = {DRIVE_LUFFING: params[0], DRIVE_SPINUP: params[0]}.get(kind, 0.0)
    omega1 = first_bending_frequency(model)
    if rate > 0.3 * omega1:
        model.warnings.append(
            f"formulation 'ffr' outside its assumptions: the frame turns at {rate:.3g} rad/s, "
            f"{rate / omega1:.2f} of the first bending frequency {omega1:.3g} rad/s; FFR has no "
            "geometric (centrifugal) stiffening and becomes unstable near and above it - use "
            "formulation = 'nonlinear'")


def build_model(scene: Scene):
    """The model the scene describes."""
    from .leaf_spring import build_spring
    from .plate import build_leaf, build_plate
    builders = {"boom": build_boom, "cantilever": build_cantilever, "spinup": build_spinup,
                "plate": build_plate, "leaf": build_leaf, "spring": build_spring}
    model = builders[scene.kind](scene)
    check_ffr_validity(model, scene)
    return model
