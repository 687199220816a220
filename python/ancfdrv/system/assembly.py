"""From a :class:`~.system.System` to the :class:`~.model.Model` the solvers run: numbering,
element sets, mass, the loads of the listed effects (and only those), joint equations
(linear ones eliminated by B or kept with multipliers), redundancy, contact pairs, probes,
the sparse patterns, the iteration matrix's policy and solver, and the kernel handle that
holds it all (SPEC section 9: System -> Assembly -> Solver).
"""
from __future__ import annotations

from collections import Counter
from typing import Iterable

import numpy as np

from ..records import record
from .. import kernel
from ..codes import (CONSTRAINT_COORDINATE, CONSTRAINT_CROSS, CONSTRAINT_DISTANCE,
                     CONTACT_COUNTERS, POLICY_CONSTANT, POLICY_REFACTOR)
from ..csr import Csr
from ..errors import InputError
from .bodies import Body, Ground, rotation_about
from .constraint_set import ConstraintSet
from .drives import Constant
from .registry import SetContext, set_builder
from .expressions import Scalar
from .kinds.force_element import assemble_force_elements
from .joints import Constraint, LinearEquation, orthonormality, planar_fixes, small_turn
from .loads import DeadMoment, Gravity, PointForce, PointMass, Pressure
from .model import (VLOAD_DEAD_MOMENT, VLOAD_FOLLOWER_FORCE, VLOAD_FOLLOWER_MOMENT, FrameInfo,
                    MomentInfo, Model, ProbeInfo, SetInfo, VectorLoadInfo)
from .patterns import Elimination, Pattern, eliminate, reduction_plan
from .supports import support_frames
from .planar import planar_equations
from .planar import resolve as resolve_planar

PLANE_NAMES = {2: "xy", 0: "yz", 1: "zx"}

#: effects every model reports (a zero count proves an effect was not computed)
EFFECTS_AVAILABLE = ("gravity", "tip_mass", "bending_moment", "tip_force", "end_moment",
                     "point_loads", "pressure", "prestress", "contact", "friction",
                     "load_cycle", "damping")
LINEAR_JOINTS = ("auto", "eliminate", "multipliers")


@record(eq=False)
class _Active:
    """The items of the listed effects."""

    gravity: list[Gravity]
    forces: list[PointForce]
    moments: list[DeadMoment]
    masses: list[PointMass]
    pressures: list[Pressure]
    contacts: list


def _norm(v: np.ndarray) -> np.floating:
    """np.linalg.norm(v) of a float array, its own operations (sqrt of the dot product of
    the array raveled in memory order) without its generic checks."""
    x = v.ravel(order="K")
    return np.sqrt(x.dot(x))


def assemble(system, effects: tuple[str, ...] | None, *, linear_joints: str = "auto",
             check_frames: bool = True, warnings: Iterable[str] = (),
             response: tuple[str, int] | None = None, supports: bool = False,
             fixed_loads: Iterable[str] = ()) -> Model:
    """The model of ``system`` with the listed effects (None: every effect it uses).
    ``check_frames=False`` assembles an 'ffr' beam whose frame nothing holds (for checks of
    joint equations alone); the solvers refuse to run such a model. ``warnings``,
    ``response``, ``supports``, ``fixed_loads``: see
    :meth:`~ancfdrv.system.System.assemble`."""
    prefix = list(warnings)
    if linear_joints not in LINEAR_JOINTS:
        raise InputError(f"linear_joints {linear_joints!r} must be one of {LINEAR_JOINTS}")
    if not any(b.flexible or b.rigid for b in system.bodies.values()):
        raise InputError("the system has no body")
    active_effects = set(_effects_used(system) if effects is None else effects)
    counters: Counter = Counter({name: 0 for name in EFFECTS_AVAILABLE + CONTACT_COUNTERS})
    for name in active_effects:
        counters[name] += 0
    warnings: list[str] = prefix
    notes: list[str] = []
    act = _select(system, active_effects, warnings)
    fixed_loads = tuple(fixed_loads)
    named = frozenset(fixed_loads)

    def fixed(load) -> bool:
        return load.name in named or load.effect in named

    bodies = list(system.bodies.values())
    first = 0
    for body in bodies:
        body.first = first
        first += body.ncoordinates
    nfull = first
    q0 = np.concatenate([b.coordinates() for b in bodies])
    drives = list(system.drives.values())
    drive_index = {id(d): i for i, d in enumerate(drives)}

    frame_problems = ffr_frame_problems(system)
    if frame_problems and check_frames:
        raise InputError(frame_problems[0])
    frames, beam_frame = _frames(bodies, drive_index)
    sets, set_blocks = _element_sets(bodies, frames, beam_frame, act, active_effects, counters,
                                     warnings)
    contact_pairs, contact_blocks = _contact(act.contacts, q0, active_effects, counters)
    rigid_blocks = [np.arange(b.first, b.first + b.ncoordinates) for b in bodies if b.rigid]
    force_elements, force_blocks = assemble_force_elements(
        getattr(system, "force_elements", {}).values(), q0, drive_index, counters)
    full_pattern = Pattern.from_blocks(nfull, set_blocks + rigid_blocks + contact_blocks
                                       + force_blocks)
    for info in sets:
        info.scatter = full_pattern.scatter(info.dofs)

    # mass and loads in full coordinates
    mass_full = _mass(bodies, sets, act.masses, full_pattern, counters)
    vector_loads = _vector_loads(act, q0, drive_index, counters, fixed)
    gravity, constant, driven, fixed_full = _loads(bodies, sets, act, drive_index, counters,
                                                   nfull, fixed)
    moments = _moments(act.moments, q0, counters, fixed)

    # joints: eliminate or keep with multipliers
    has_rigid = any(b.rigid for b in bodies)
    mode = linear_joints if linear_joints != "auto" else ("eliminate" if has_rigid else
                                                          "multipliers")
    plane, planar_eqs = _planar(system, act, q0, notes)
    owners: dict[str, str] = {}
    equations = _equations(system, bodies, q0, notes, warnings, owners)
    linear = [eq for eq in equations if isinstance(eq, LinearEquation)]
    elimination, reduction, constraints_eq, dropped = _linear_joints(
        mode, equations, linear, planar_eqs, q0, full_pattern)
    if reduction is not None and not len(reduction.independent) and mode == "eliminate":
        # the joints hold every coordinate (a locked body): the kernel solves no system of
        # size 0, so the linear joints are kept with multipliers (their reactions follow)
        mode = "multipliers"
        notes.append("the joints hold every coordinate: linear joints kept with multipliers")
        elimination, reduction, constraints_eq, dropped = _linear_joints(
            mode, equations, linear, planar_eqs, q0, full_pattern)
    notes += dropped
    ndof = nfull if reduction is None else len(reduction.independent)
    column = np.arange(nfull) if reduction is None else _columns(nfull, reduction)
    e0 = q0 if reduction is None else q0[reduction.independent].copy()
    constraints = _constraint_set(constraints_eq, elimination, column, drives, drive_index, e0,
                                  ndof, notes)

    pattern = full_pattern if reduction is None else reduction.pattern
    if reduction is None:
        mass = mass_full
    else:
        mass = reduction.matrix.congruence(mass_full)   # B^T M B, scipy's arithmetic
    mass.sort_indices()

    def reduce(v: np.ndarray) -> np.ndarray:
        return v if reduction is None else reduction.reduce(v)
    probes = _probes(system, frames, beam_frame, q0)
    model = Model(
        title=system.title, effects=tuple(sorted(active_effects)), counters=counters,
        warnings=warnings, notes=notes, bodies=bodies, sets=sets, frames=frames, drives=drives,
        q0=q0, e0=e0, reduction=reduction, full_pattern=full_pattern, pattern=pattern, mass=mass,
        constant_force=reduce(constant + gravity),
        driven_forces=[(i, reduce(v)) for (i, _), v in driven],
        moments=moments, constraints=constraints, contact_pairs=contact_pairs, probes=probes,
        point_masses=[(m.name, m.body.name, m.point, m.mass) for m in act.masses],
        linear_joints=mode, response=response,
        support_frames=support_frames(system) if supports else None)
    model.vector_loads = vector_loads
    model.force_elements = force_elements
    if named:
        model.fixed_loads = fixed_loads
        model.fixed_force = reduce(fixed_full)
        model.driven_fixed = [held for (_, held), _ in driven]
    # the uniform gravity (m/s^2) the beams' section forces integrate between nodes
    model.gravity = sum((load.vector for load in act.gravity), np.zeros(3))
    model.frame_problems = frame_problems
    _answer_inputs(model, system, owners, equations, elimination, reduction, mass_full,
                   constant + gravity, [(i, v) for (i, _), v in driven])
    if planar_eqs:  # the rows eliminated are the planar fixes (+ the linear joints)
        kept = planar_eqs + (linear if mode == "eliminate" else [])
        model.eliminated = [eq for eq in kept if eq.name not in set(elimination.redundant)]
    model.planar = "" if plane is None else PLANE_NAMES[plane]
    model.nplanar_fixed = sum(eq.name not in set(elimination.redundant) for eq in planar_eqs)
    _policy(model)
    model.build_kernel()
    return model


def _answer_inputs(model: Model, system, owners: dict[str, str], equations: list,
                   elimination: Elimination, reduction, mass_full: Csr,
                   constant_full: np.ndarray, driven_full: list) -> None:
    """What the joint reactions need besides the solution (``ancfdrv.system.answers``):
    the joints and the owner of every joint equation (by its name: ``owners``, from
    :func:`_equations`), the equations in the full coordinates q, the eliminated linear
    equations kept (not redundant), and the mass and loads in the full coordinates (the
    residual of the eliminated rows is formed there)."""
    model.joint_items = dict(system.joints)
    model.equation_owner = owners
    model.full_equations = {eq.name: eq for eq in equations}
    model.eliminated = [] if reduction is None else \
        [eq for eq in equations if isinstance(eq, LinearEquation)
         and eq.name not in set(elimination.redundant)]
    model.mass_full = mass_full
    model.full_loads = (constant_full, driven_full)


# -- effects ---------------------------------------------------------------------------------
def _effects_used(system) -> set[str]:
    """Every effect an item of the system belongs to: its loads', contacts' and leaves'
    (System.effects_used) and 'damping' when a flexible body's material has a damping time."""
    used = set(system.effects_used())
    if any(b.flexible and b.material.damping_time > 0 for b in system.bodies.values()):
        used.add("damping")
    return used


def _select(system, active: set[str], warnings: list[str]) -> _Active:
    loads = list(system.loads.values())
    for load in loads:
        if load.effect not in active:
            warnings.append(f"load {load.name!r} belongs to the effect {load.effect!r}, which is "
                            "not listed: not applied")
    on = [load for load in loads if load.effect in active]
    contacts = list(system.contacts.values()) if "contact" in active else []
    if system.contacts and "contact" not in active:
        warnings.append("contact pairs are defined but the effect 'contact' is not listed: no "
                        "contact is computed")
    return _Active([x for x in on if isinstance(x, Gravity)],
                   [x for x in on if isinstance(x, PointForce)],
                   [x for x in on if isinstance(x, DeadMoment)],
                   [x for x in on if isinstance(x, PointMass)],
                   [x for x in on if isinstance(x, Pressure)], contacts)


# -- frames and element sets -----------------------------------------------------------------
def _frames(bodies: list[Body], drive_index: dict) -> tuple[list[FrameInfo], dict[str, int]]:
    """One frame per framed body (``Body.framed``: a beam's body frame, turned by its frame
    drive): 1-based ids."""
    frames, beam_frame = [], {}
    for body in bodies:
        if not body.framed:
            continue  # (a cable may carry a frame for its probes' deflection: builders/boom.py)
        drive = body.frame_drive
        base = body.orientation
        if drive is not None:
            base = rotation_about(body.frame_axis, -drive.value(0.0)) @ body.orientation
        frames.append(FrameInfo(-1 if drive is None else drive_index[id(drive)],
                                body.frame_axis / np.linalg.norm(body.frame_axis), base,
                                body.frame_pivot, drive))
        beam_frame[body.name] = len(frames)
    return frames, beam_frame


def _element_sets(bodies, frames, beam_frame, act: _Active, active: set[str], counters: Counter,
                  warnings: list[str]) -> tuple[list[SetInfo], list[np.ndarray]]:
    sets, blocks = [], []
    for body in bodies:
        build = set_builder(body)
        if build is None:
            continue
        frame_id = beam_frame.get(body.name, 0)
        context = SetContext(frames[frame_id - 1] if frame_id else None, frame_id, active,
                             counters, warnings)
        info = build(body, context)
        counters["element_arrays"] += info.nel
        _damping(info, body, active, counters, warnings)
        sets.append(info)
        blocks.append(info.dofs)
    return sets, blocks


def _damping(info: SetInfo, body: Body, active: set[str], counters: Counter,
             warnings: list[str]) -> None:
    """The set's Kelvin-Voigt retardation time: its material's with the effect 'damping'
    listed (one count per damped set), else 0 with a warning when the material has one."""
    tau = body.material.damping_time
    if tau <= 0:
        return
    if "damping" in active:
        info.damping_time = float(tau)
        counters["damping"] += 1
        return
    message = (f"material {body.material.name!r} has damping_time = {tau:g} s but the effect "
               "'damping' is not listed: not applied")
    if message not in warnings:
        warnings.append(message)


# -- mass and loads --------------------------------------------------------------------------
def _mass(bodies, sets: list[SetInfo], masses: list[PointMass], pattern: Pattern,
          counters: Counter) -> Csr:
    """M in full coordinates: element masses, rigid bodies, point masses."""
    values = np.zeros(pattern.nnz)
    for info in sets:
        compact = info.mass_compact.copy()
        for pm in masses:
            if pm.body is info.body:
                at = pm.body.locate(pm.point, node=False, what=f"load {pm.name!r}")
                compact[:, :, at.element] += info.body.point_mass(at, pm.mass)
        n = compact.shape[0]
        element = np.einsum("abe,ij->aibje", compact, np.eye(3)).reshape(3 * n, 3 * n, -1)
        np.add.at(values, info.scatter.ravel() - 1, element.ravel())
    for body in bodies:
        if not body.rigid:
            continue
        block = body.mass_matrix.copy()
        for pm in masses:
            if pm.body is body:
                u = pm.point - body.centre
                compact = pm.mass * np.outer(np.concatenate([[1.0], u]), np.concatenate([[1.0], u]))
                block += np.kron(compact, np.eye(3))
        dofs = np.arange(body.first, body.first + 12)
        rows, cols = np.meshgrid(dofs, dofs, indexing="ij")
        np.add.at(values, pattern.positions(rows.ravel(), cols.ravel()), block.ravel())
    for pm in masses:
        counters[pm.effect] += 1
    return pattern.to_csr(values)


def _weight(bodies, sets: list[SetInfo], masses: list[PointMass], g: np.ndarray,
            nfull: int) -> np.ndarray:
    """The weight under the gravity g of the bodies and the point masses ``masses``."""
    weight = np.zeros(nfull)
    for info in sets:
        np.add.at(weight, info.dofs.reshape(-1, order="F"),
                  info.body.gravity_forces(g).reshape(-1, order="F"))
    for body in bodies:
        if body.rigid:
            weight[body.first:body.first + 3] += body.mass * g
    for pm in masses:
        _add_point_vector(weight, pm.body, pm.point, pm.mass * g, pm.name)
    return weight


def _loads(bodies, sets: list[SetInfo], act: _Active, drive_index: dict, counters: Counter,
           nfull: int, fixed):
    """Gravity, constant point forces and pressures, the driven forces (per drive and
    whether they are ``fixed``: {(drive, fixed): vector}) and the fixed loads' share of
    the constant ones, in full coordinates. A weight is fixed when its gravity is and, for
    a point mass, the point mass too."""
    gravity = np.zeros(nfull)
    held = np.zeros(nfull)
    g = sum((load.vector for load in act.gravity), np.zeros(3))
    if act.gravity:
        gravity = _weight(bodies, sets, act.masses, g, nfull)
        g_fixed = sum((load.vector for load in act.gravity if fixed(load)), np.zeros(3))
        if g_fixed.any():
            held += _weight(bodies, sets, [pm for pm in act.masses if fixed(pm)], g_fixed,
                            nfull)
        for load in act.gravity:
            counters[load.effect] += 1
    constant = np.zeros(nfull)
    driven: dict[tuple[int, bool], np.ndarray] = {}
    for load in act.forces:
        target = constant if load.drive is None else \
            driven.setdefault((drive_index[id(load.drive)], fixed(load)), np.zeros(nfull))
        _add_point_vector(target, load.body, load.point, load.vector, load.name)
        if load.drive is None and fixed(load):
            _add_point_vector(held, load.body, load.point, load.vector, load.name)
        counters[load.effect] += 1
    for load in act.pressures:
        plate = load.body
        dofs = next(s.dofs for s in sets if s.body is plate)
        for el in range(plate.nel):
            _, element = kernel.plate_element_arrays(
                plate.mesh.a[el:el + 1], plate.mesh.b[el:el + 1], plate.thickness,
                plate.material.density, -load.value * plate.initial_normal(el))
            np.add.at(constant, dofs[:, el], element[:, :, 0].reshape(-1, order="F"))
            if fixed(load):
                np.add.at(held, dofs[:, el], element[:, :, 0].reshape(-1, order="F"))
        counters[load.effect] += 1
    return gravity, constant, sorted(driven.items()), held


def _add_point_vector(target: np.ndarray, body: Body, point, vector, name: str) -> None:
    """Generalized force of a dead force at a material point (its shape functions)."""
    at = body.locate(point, node=False, what=f"load {name!r}")
    position = body.position(at)
    for first, coef in position.terms.items():
        target[first:first + 3] += coef * np.asarray(vector)


def _moments(loads: list[DeadMoment], q0: np.ndarray, counters: Counter,
             fixed) -> list[MomentInfo]:
    """A dead moment acts on the nodal directors that measure the rotation about its axis.

    A rigid body's dead moments do not come here (:func:`_vector_loads`: exact at any
    rotation). A beam or plate section with
    the two directors d1, d2 (beam r_y, r_z; plate r_x, r_y) and the normal n = d1 x d2 at
    t = 0: the moment's components about d1 and d2 act on d2 and d1, its component about n
    on both, in the shares that turn the section without shearing it (Beam.torsion_shares;
    halves on a plate): a single director would also load the section's shear, an error of
    the order M / (G A h) that grows as the mesh is refined."""
    out = []
    for load in loads:
        body = load.body
        axis = load.vector / np.linalg.norm(load.vector)
        for at, share in body.moment_attachments(load.point, f"load {load.name!r}"):
            out += _moment_parts(body, at, load, axis, share * float(np.linalg.norm(load.vector)),
                                 q0, fixed(load))
        counters[load.effect] += 1
    return out


def _moment_parts(body: Body, at, load, axis: np.ndarray, magnitude: float,
                  q0: np.ndarray, fixed: bool) -> list[MomentInfo]:
    """The dead moment's parts on the directors of one node (see :func:`_moments`)."""
    out = []
    firsts = {which: next(iter(body.vector(at, which).terms))
              for which in body.directors(at)}
    if not firsts and hasattr(body, "node_first"):  # a cable: no section, the slope turns
        firsts = {"r_x": _slope_for_moment(body, at, load, axis, q0)}
    if len(firsts) == 1:  # a cable's slope (normal to the axis: _slope_for_moment)
        parts = [(next(iter(firsts.values())), axis, magnitude)]
    else:
        f1, f2 = firsts.values()
        u1 = q0[f1:f1 + 3] / np.linalg.norm(q0[f1:f1 + 3])
        u2 = q0[f2:f2 + 3] / np.linalg.norm(q0[f2:f2 + 3])
        normal = np.cross(u1, u2)
        normal /= np.linalg.norm(normal)
        m_n, m_1, m_2 = (float(magnitude * axis @ u) for u in (normal, u1, u2))
        w1, w2 = body.torsion_shares()
        parts = [(f1, normal, w1 * m_n), (f2, normal, w2 * m_n), (f2, u1, m_1),
                 (f1, u2, m_2)]
        parts = [(f, np.sign(m) * k, abs(m)) for f, k, m in parts
                 if abs(m) > 1e-14 * magnitude]
    for first, k, m in parts:
        out.append(MomentInfo(load.name, np.arange(first, first + 3), k, m, load.effect,
                              q0[first:first + 3].copy(), fixed))
    return out


def _slope_for_moment(body: Body, at, load, axis: np.ndarray, q0: np.ndarray) -> int:
    """A dead moment on a cable node acts on its slope r_x (Euler-Bernoulli: the section
    turns with the axis; seed 000 eq. 26 with the director r_x, the rotation about the
    moment's fixed axis measured on it). A cable has no torsion: the moment must be normal
    to the slope at t = 0 (InputError naming the load otherwise)."""
    first = next(iter(body.vector(at, "r_x").terms))
    slope = q0[first:first + 3] / np.linalg.norm(q0[first:first + 3])
    if abs(float(slope @ axis)) > 1e-9:
        raise InputError(f"load {load.name!r}: a cable carries no torsion; its moment must be "
                         f"normal to the cable's axis {list(np.round(slope, 12))} at the point")
    return first


def _vector_loads(act: _Active, q0: np.ndarray, drive_index: dict,
                  counters: Counter, fixed) -> list[VectorLoadInfo]:
    """The driven and follower point loads (kernel module vector_loads), taken out of the
    dead forces and moments: a follower force, a moment with a drive or a follower moment,
    and every dead moment on a rigid body (its components on the body's current
    orthonormal directors give exactly the fixed moment at any rotation; the director
    potential of :func:`_moments` drops the component along the director it measures and
    scales the rest when that director leaves the plane normal to the axis). Each acts
    through the two directions a, b of the body at its point (beam: r_y, r_z;
    plate, leaf, rigid body: r_x, r_y; interpolated between nodes) and its position p; a
    follower's vector is kept as its components on (a, b, a x b) at t = 0."""
    out = []
    def vector(x) -> bool:
        return x.follower or x.drive is not None or x.body.rigid

    chosen = [x for x in act.forces if x.follower] + [x for x in act.moments if vector(x)]
    act.forces[:] = [x for x in act.forces if not x.follower]
    act.moments[:] = [x for x in act.moments if not vector(x)]
    for load in chosen:
        body = load.body
        at = body.locate(load.point, node=False, what=f"load {load.name!r}")
        names = body.section_directors or ("r_x", "r_y")
        a, b = (body.vector(at, w) for w in names)
        p = body.position(at)
        a0, b0 = a.value(q0), b.value(q0)
        frame = np.column_stack([a0, b0, np.cross(a0, b0)])
        force = isinstance(load, PointForce)
        if load.follower:
            kind = VLOAD_FOLLOWER_FORCE if force else VLOAD_FOLLOWER_MOMENT
            vector = np.linalg.solve(frame, load.vector)
        else:
            kind, vector = VLOAD_DEAD_MOMENT, load.vector.copy()
        shares = body.torsion_shares()
        slots = [sorted(a.terms.items()), sorted(b.terms.items()),
                 sorted(p.terms.items()) if force else []]
        drive = -1 if load.drive is None else drive_index[id(load.drive)]
        out.append(VectorLoadInfo(load.name, kind, drive, vector, np.array(shares, float),
                                  slots, load.effect, fixed(load)))
        counters[load.effect] += 1
    return out


# -- joints ----------------------------------------------------------------------------------
def _equations(system, bodies, q0: np.ndarray, notes: list[str], warnings: list[str],
               owners: dict[str, str]) -> list:
    """Every joint's equations in the order of the joints, then each rigid body's planar
    guide and orthonormality, except for linearized bodies (:func:`_linearized`: noted).
    ``owners`` gets the joint of each joint equation (by its name; the answers' map)."""
    out = []
    for joint in system.joints.values():
        joint_equations = joint.equations(q0)
        for eq in joint_equations:
            owners[eq.name] = joint.name
        out += joint_equations
    linearized = _linearized(system, warnings)
    for body in bodies:
        if body.rigid:
            if body.planar:
                out += planar_fixes(body, q0)
            if body.name in linearized:
                via = system.joints[linearized[body.name]].type
                notes.append(f"rigid body {body.name!r}: its axes follow the small section turn "
                             f"of an FFR beam ({via} {linearized[body.name]!r}), linearized; "
                             "orthonormality not imposed")
                continue
            out += orthonormality(body)
    return out


def _planar(system, act: _Active, q0: np.ndarray, notes: list[str]
            ) -> tuple[int | None, list[LinearEquation]]:
    """The planar reduction's plane (normal axis, None: off) and the coordinates it fixes
    (:mod:`.planar`), checked against the bodies, joints and the loads of the listed
    effects."""
    setting = getattr(system, "planar", "off")
    plane, planar_notes = (None, []) if setting == "off" else resolve_planar(
        system, setting, act.gravity + act.forces + act.moments + act.masses + act.pressures)
    for body in system.bodies.values():
        if getattr(body, "planar_bending", False) and plane is None:
            raise InputError(f"cable {body.name!r}: its section bends with two stiffnesses and "
                             "it was given the one of a single plane (bending_inertia): the "
                             "system must keep it in that plane (scene.planar, System(planar="
                             "...))", group="scene", key="planar")
    if setting == "off":
        return None, []
    notes += planar_notes
    return plane, ([] if plane is None else planar_equations(system, plane, q0))


def _linearized(system, warnings: list[str]) -> dict[str, str]:
    """Rigid bodies whose axes are linear in the coordinates, name -> the weld that makes them
    so: welded to an FFR beam in a fixed frame (Joint.linearized_body), or to such a body
    through welds between rigid bodies ('prismatic' joints count as welds: they tie the
    orientation alike). Their axes are orthonormal to first order only, as
    the beam's kinematics: imposing J^T J = I would hold the turn at zero. A warning names
    the welds and revolutes that tie such axes to a body with finite rotations (a nonlinear
    beam, a plate or leaf, an FFR beam in a moving frame): its directions then follow them
    to first order only (they stretch by the square of the turn)."""
    joints = list(system.joints.values())
    out = {}
    for joint in joints:
        body = joint.linearized_body()
        if body is not None:
            out.setdefault(body.name, joint.name)
    grown = True
    while grown:
        grown = False
        for joint in joints:
            a, b = joint.bodies
            # (a prismatic's orientation ties are a weld's)
            if joint.type in ("weld", "prismatic") and a.rigid and b.rigid:
                for body, other in ((a, b), (b, a)):
                    if other.name in out and body.name not in out:
                        out[body.name], grown = out[other.name], True
    for joint in (j for j in joints if j.type in ("weld", "revolute", "prismatic",
                                                  "cylindrical", "universal")):
        for body, other in (joint.bodies, joint.bodies[::-1]):
            if body.name in out and other.flexible and not small_turn(other):
                warnings.append(
                    f"joint {joint.name!r} ties the axes of rigid body {body.name!r}, linearized "
                    f"by the FFR weld {out[body.name]!r}, to {other.name!r}, which turns without "
                    "that linearization: its directions there follow the body to first order "
                    "only (use one formulation for the beams on a rigid body)")
    return out


def _as_constraint(eq: LinearEquation) -> Constraint:
    """A linear equation kept with a multiplier: x1 = sum a q, x1 - (-c) = 0."""
    return Constraint(CONSTRAINT_COORDINATE, [Scalar(eq.expr.terms, 0.0)], [-eq.expr.const],
                      None, eq.name, eq.prefer)


def _columns(nfull: int, reduction) -> np.ndarray:
    column = -np.ones(nfull, dtype=np.int64)
    column[reduction.independent] = np.arange(len(reduction.independent))
    return column


def _linear_joints(mode: str, equations: list, linear: list[LinearEquation],
                   planar_eqs: list[LinearEquation], q0: np.ndarray, full_pattern: Pattern):
    """The linear joint equations eliminated (mode 'eliminate') or kept as constraints
    with multipliers, the planar fixes eliminated whatever the mode (planar.py): the
    elimination, the reduction (None: nothing eliminated), the equations kept as
    constraints and the notes of the redundant equations dropped."""
    if planar_eqs:
        elimination = eliminate(planar_eqs + (linear if mode == "eliminate" else []), q0)
        notes = [f"redundant joint equation dropped: {name}" for name in elimination.redundant
                 if ": planar" not in name]
        reduction = reduction_plan(len(q0), elimination, q0, full_pattern)
        kept = [eq for eq in equations if isinstance(eq, Constraint)] \
            if mode == "eliminate" else \
            [_as_constraint(eq) if isinstance(eq, LinearEquation) else eq for eq in equations]
        return elimination, reduction, kept, notes
    if mode == "eliminate" and linear:
        elimination = eliminate(linear, q0)
        notes = [f"redundant joint equation dropped: {name}" for name in elimination.redundant]
        reduction = reduction_plan(len(q0), elimination, q0, full_pattern)
        return elimination, reduction, [eq for eq in equations if isinstance(eq, Constraint)], \
            notes
    return Elimination({}, []), None, [_as_constraint(eq) if isinstance(eq, LinearEquation)
                                       else eq for eq in equations], []


def _constraint_set(equations: list[Constraint], elimination: Elimination, column: np.ndarray,
                    drives, drive_index: dict, e0: np.ndarray, ndof: int,
                    notes: list[str]) -> ConstraintSet:
    """The multiplier constraints over the independent coordinates; constant ones (satisfied
    identically through the eliminated coordinates) and redundant ones (their gradient lies
    in the span of the earlier ones at t = 0) are dropped, the split iteration's dependent
    coordinate chosen for each."""
    out = ConstraintSet(drive_kinds=[d.kind for d in drives],
                        drive_params=[d.params() for d in drives])
    prefer = []
    scale = max(1.0, float(np.abs(e0).max(initial=0.0)))
    for eq in equations:
        operands = []
        for operand in eq.operands:
            s = elimination.substitute(operand)
            operands.append(({int(column[d]): c for d, c in s.terms.items()}, s.const))
        if not any(terms for terms, _ in operands):
            _constant_constraint(eq, [c for _, c in operands], 1e-8 * scale ** 2, notes)
            continue
        out.add(eq.kind, operands, eq.params,
                -1 if eq.drive is None else drive_index[id(eq.drive)], eq.name)
        prefer.append([int(column[d]) for d in eq.prefer if column[d] >= 0])
    if not len(out):
        return out
    evaluated = out.evaluate(e0, 0.0)
    values = evaluated[0]
    keep, basis = [], []
    gradients = out.gradient_rows(e0, ndof, 0.0, evaluated)   # (the same evaluation)
    for c in range(len(out)):
        name = out.names[c]
        if abs(values[c]) > 1e-8 * scale ** 2:
            raise InputError(f"{name}: the initial configuration violates this joint equation "
                             f"by {values[c]:.3e} (check the points, the bodies and the drives' "
                             "values at t = 0)")
        g = gradients[c]
        norm = _norm(g)
        if norm == 0.0 or not any(out.terms[c]):
            notes.append(f"redundant joint equation dropped: {name} (satisfied identically)")
            continue
        r = g.copy()
        for b in basis:
            r -= (b @ r) * b
        if _norm(r) <= 1e-8 * norm:
            _check_consistent(out, c, keep, gradients, e0, scale)
            notes.append(f"redundant joint equation dropped: {name} (implied by the others)")
            continue
        basis.append(r / _norm(r))
        keep.append(c)
    out = out.select(keep)
    taken: set[int] = set()
    for k, c in enumerate(keep):
        row = gradients[c]
        choice = next((d for d in prefer[c] if d not in taken and abs(row[d]) > 1e-12), None)
        if choice is None:
            order = np.argsort(-np.abs(row), kind="stable")
            choice = next((int(d) for d in order if int(d) not in taken), int(order[0]))
        taken.add(choice)
        out.dependent.append(choice)
    return out


#: times (s) at which a redundant driven equation is compared with those that imply it
_CONSISTENCY_TIMES = (1e-3, 0.01, 0.05, 0.1, 0.25, 0.5, 1.0, 2.0, 3.0, 5.0, 10.0, 30.0, 100.0)


def _check_consistent(out: ConstraintSet, c: int, keep: list[int], gradients: np.ndarray,
                      e0: np.ndarray, scale: float) -> None:
    """A redundant equation (its gradient g_c = sum a_k g_k of the kept ones at t = 0) may be
    dropped only if it agrees with them: with the configuration held at e0, its value must
    stay sum a_k Phi_k(e0, t) at every sampled time (only driven equations change with t;
    two contradictory 'prescribed' motions of one point differ). Checked where the equation
    and those it combines are linear in the coordinates (coordinate kind: exact); else
    InputError naming both joints."""
    if out.drives[c] < 0 and all(out.drives[k] < 0 for k in keep):
        return
    rows = gradients[keep]
    coef, *_ = np.linalg.lstsq(rows.T, gradients[c], rcond=None)
    used = [k for k, a in zip(keep, coef) if abs(a) > 1e-12]
    if any(out.kinds[k] != CONSTRAINT_COORDINATE for k in used + [c]):
        return   # a nonlinear equation: the combination holds to first order only
    tol = 1e-8 * scale
    for t in _CONSISTENCY_TIMES:
        values, *_ = out.evaluate(e0, t)
        mismatch = float(values[c] - coef @ values[keep])
        if abs(mismatch) > tol:
            other = keep[int(np.argmax(np.abs(coef)))]
            raise InputError(
                f"{out.names[c]}: contradicts {out.names[other]}: the two joints hold the same "
                f"coordinate (the equation is redundant) but prescribe different motions "
                f"(off by {mismatch:.3e} at t = {t:g} s); remove one of them")


def _constant_constraint(eq: Constraint, x: list[float], tol: float, notes: list[str]) -> None:
    """A constraint whose operands the eliminated coordinates make constant (e.g. a driven
    coordinate that a planar guide already holds): it is noted as redundant when it holds
    for every value of its drive, else it contradicts the other joints."""
    x = np.array(list(x) + [0.0] * (6 - len(x)))
    p = np.array(list(eq.params) + [0.0] * (8 - len(eq.params)))
    phi0 = 0.0 if eq.drive is None else eq.drive.value(0.0)
    samples = [phi0] if eq.drive is None or isinstance(eq.drive, Constant) else \
        [phi0, phi0 + 0.3, phi0 - 1.1]
    for phi in samples:
        if eq.kind == CONSTRAINT_COORDINATE:
            value = x[0] - (p[0] + p[1] * np.cos(phi) + p[2] * np.sin(phi) + p[3] * phi)
        elif eq.kind == CONSTRAINT_DISTANCE:
            value = float(np.sum((x[:3] - x[3:]) ** 2)) - (p[0] + p[1] * phi) ** 2
        elif eq.kind == CONSTRAINT_CROSS:
            value = float(p[:3] @ np.cross(x[:3], x[3:]))
        else:
            value = float(x[:3] @ x[3:]) - p[0] - p[1] * phi   # dot (p[1]: driven)
        if abs(value) > tol:
            if eq.drive is None:
                raise InputError(f"{eq.name}: every coordinate of this equation is held by other "
                                 f"joints, which violate it by {value:.3e}")
            raise InputError(f"{eq.name}: the coordinate this drive moves is held by other "
                             f"joints (no free coordinate is left for it; off by {value:.3e} "
                             f"at the value {phi:g} of drive {eq.drive.name!r})")
    notes.append(f"redundant joint equation dropped: {eq.name} (satisfied identically)")


# -- FFR frames ------------------------------------------------------------------------------
_DRIVING = ("prescribed", "hub", "arm")


def _moving(drive) -> str | None:
    """A drive's name, None for no drive or a constant one (it does not move anything)."""
    return None if drive is None or isinstance(drive, Constant) else drive.name


def _anchors(body: Body, joints) -> set:
    """What holds body to the ground: None for a joint that does not move (weld, revolute,
    fix, ...), a drive's name for a joint that moves it by that drive (prescribed, hub,
    arm)."""
    out = set()
    for joint in joints:
        if body not in (joint.body1, joint.body2):
            continue
        if isinstance(joint.body1, Ground) or isinstance(joint.body2, Ground):
            out.add(_moving(joint.drive) if joint.type in _DRIVING else None)
    return out


def _turned_by(beam: Body, component: set, joints) -> str:
    """Why an 'ffr' beam in a fixed frame cannot stay in it ('' when it can): no weld, fixed
    hub or fixed section director clamps it to the ground, and a joint with a moving drive ('distance' as a
    cylinder, 'prescribed', 'hub', 'arm') acts in the assembly it belongs to, so the drive
    can turn it about its hinge (a knuckle crane's boom lifted by its cylinder) while its
    elastic model stays in the frame of t = 0."""
    if beam.frame_drive is not None:
        return ""
    for joint in joints:
        if beam in (joint.body1, joint.body2) and isinstance(joint.body1, Ground) and (
                joint.type == "weld" or (joint.type == "hub" and _moving(joint.drive) is None)
                or (joint.type == "fix" and joint.vector in ("r_y", "r_z"))):
            return ""
    for joint in joints:
        moving = _moving(joint.drive)
        if moving is None or not ({joint.body1, joint.body2} & component):
            continue
        return (f"beam {beam.name!r}: formulation 'ffr' keeps its floating frame fixed, but "
                f"joint {joint.name!r} moves the assembly it belongs to with drive {moving!r} "
                "and no weld or fixed hub clamps the beam to the ground: the drive can turn "
                "it through a large angle, which its frame does not follow; use formulation = "
                "'nonlinear' for it, or a frame_drive that turns its frame with that motion")
    return ""


def ffr_frame_problems(system) -> list[str]:
    """Why an 'ffr' beam is refused (one message per beam; empty: none is): an 'ffr' beam whose floating frame would have to follow moving bodies: the
    kernel moves an FFR frame only by its own drive about a fixed pivot. The bodies joined
    to the beam, directly or through others, must be held to the ground somewhere, and a
    moving frame's drive must be one that moves them ('prescribed', 'hub' or 'arm' to the
    ground). (Large motion about a hinge is not caught here: the run warns when the
    deflection from the frame grows beyond the small-deformation range.)"""
    joints = list(system.joints.values())
    problems = []
    for beam in system.bodies.values():
        if not beam.floating:
            continue
        component, todo = {beam}, [beam]
        while todo:  # the bodies joined to the beam, directly or through others
            body = todo.pop()
            for j in joints:
                if body in (j.body1, j.body2):
                    other = j.body2 if j.body1 is body else j.body1
                    if not isinstance(other, Ground) and other not in component:
                        component.add(other)
                        todo.append(other)
        if len(component) == 1 and not any(beam in (j.body1, j.body2) for j in joints):
            continue  # a beam without joints: nothing to follow (statics says it is free)
        anchors = set().union(*(_anchors(body, joints) for body in component))
        turned = _turned_by(beam, component, joints)
        if turned:
            problems.append(turned)
            continue
        if _moving(beam.frame_drive) in anchors:
            continue
        where = f"beam {beam.name!r}"
        if _moving(beam.frame_drive) is None:
            others = sorted(b.name for b in component if b is not beam)
            problems.append(
                f"{where}: formulation 'ffr' needs its floating frame held, but neither the "
                "beam nor any body joined to it" + (f" ({', '.join(map(repr, others))})"
                                                    if others else "")
                + " is held by a joint to the ground: its frame would have to follow their "
                "motion, which the FFR model cannot do; use formulation = 'nonlinear' for it, "
                "or join the assembly to the ground")
            continue
        problems.append(
            f"{where}: its floating frame turns with drive {beam.frame_drive.name!r}, but no "
            "joint moves the beam or a body joined to it with that drive ('prescribed', 'hub' "
            f"or 'arm' to the ground with drive = {beam.frame_drive.name!r}); use formulation "
            "= 'nonlinear' if something else moves it")
    return problems


# -- contact, probes -------------------------------------------------------------------------
def _contact(pairs, q0: np.ndarray, active: set[str], counters: Counter):
    """Kernel data of every pair (leaf_contact layout) and the couplings its points add to
    the pattern (the searched elements near each point's projection)."""
    out, blocks = [], []
    for pair in pairs:
        upper, lower = pair.body1, pair.body2
        friction_on = "friction" in active and pair.friction > 0
        params = kernel.contact_params(pair.stiffness, pair.damping, pair.friction,
                                       pair.slip_speed, upper.thickness, lower.thickness,
                                       friction_on)
        counters["contact"] += 1
        if friction_on:
            counters["friction"] += 1
        du, dl = upper.element_dofs(), lower.element_dofs()
        dofs = np.hstack([du, dl])
        sizes = np.vstack([np.concatenate([upper.mesh.a, lower.mesh.a]),
                           np.concatenate([upper.mesh.b, lower.mesh.b])])
        nxu, nyu = upper.nx, upper.ny
        grid = np.arange(nxu * nyu).reshape(nyu, nxu).T
        lower_grid = upper.nel + np.arange(lower.nx * lower.ny).reshape(lower.ny, lower.nx).T
        elements, local, names, guesses = [], [], [], []
        sx, sy = upper.length_stations()
        for edge, column_, xi in (("front", 0, 0.0), ("rear", lower.nx - 1, 1.0)):
            for f in np.linspace(0.0, 1.0, pair.points):
                j = min(int(f * lower.ny), lower.ny - 1)
                el = int(lower_grid[column_, j])
                elements.append(el)
                local.append([xi, f * lower.ny - j])
                width = lower.length_stations()[1][-1]
                names.append(f"{pair.name}: {edge} edge, y = {(f - 0.5) * width:+.4f} m")
                shape, _ = kernel.plate_shape(xi, f * lower.ny - j, lower.mesh.a[el - upper.nel],
                                              lower.mesh.b[el - upper.nel])
                point = shape @ q0[dofs[:, el]].reshape(12, 3)
                x, y, _ = upper.surface_coordinates(point)
                guess = np.array([np.clip(x / sx[-1], 0.0, 1.0) * nxu,
                                  np.clip(y / sy[-1], 0.0, 1.0) * nyu])
                guess, *_ = kernel.contact_projection(q0, dofs, sizes, grid, point, guess)
                guesses.append(guess)
                col = int(min(guess[0], nxu - 1e-9))
                for c in range(max(col - 1, 0), min(col + 2, nxu)):
                    for row in range(nyu):
                        blocks.append(np.concatenate([dofs[:, grid[c, row]], dofs[:, el]]))
        out.append(dict(name=pair.name, dofs=dofs, sizes=sizes, grid=grid,
                        point_element=np.array(elements), point_local=np.array(local, float).T,
                        params=params, guesses=np.array(guesses).T, point_names=names))
    return out, blocks


def _probes(system, frames: list[FrameInfo], beam_frame: dict[str, int],
            q0: np.ndarray) -> dict[str, ProbeInfo]:
    out = {}
    for probe in system.probes.values():
        body = probe.body
        at = body.locate(probe.point, node=False, what=f"probe {probe.name!r}")
        position = body.position(at)
        p0 = position.value(q0)
        frame = beam_frame.get(body.name, 0)
        reference = p0
        if frame:
            info = frames[frame - 1]
            reference = info.rotation(0.0).T @ (p0 - info.pivot)
        out[probe.name] = ProbeInfo(probe.name, body.name, sorted(position.terms.items()), frame,
                                    reference, at)
    return out


# -- the iteration matrix --------------------------------------------------------------------
def _policy(model: Model) -> None:
    """'constant' (factorized once) when every element set is FFR, there is no contact and
    the solver-frame assembly is exact (checked numerically); else 'refactor'."""
    model.policy, model.vector_frame = POLICY_REFACTOR, np.zeros(0, dtype=np.int64)
    if model.contact_pairs or any(not s.floating for s in model.sets):
        return
    if model.force_elements:  # their tangent changes with the configuration
        return
    moving = [i + 1 for i, f in enumerate(model.frames) if f.drive >= 0]
    if not moving:
        model.policy = POLICY_CONSTANT
        return
    if model.ndof % 3:
        return
    frame_of_body = {s.body.name: s.frame for s in model.sets}
    independent = np.arange(model.nfull) if model.reduction is None else \
        model.reduction.independent
    owner = np.empty(model.nfull, dtype=object)
    for body in model.bodies:
        owner[body.first:body.first + body.ncoordinates] = body
    vector_frame = np.zeros(model.ndof // 3, dtype=np.int64)
    for v in range(model.ndof // 3):
        full = independent[3 * v:3 * v + 3]
        if full[0] % 3 or np.any(np.diff(full) != 1):
            return  # a reduced 3-vector that is not one nodal vector
        body = owner[full[0]]
        if body.floating:  # an FFR beam: its own frame's
            f = frame_of_body[body.name]
            vector_frame[v] = f if model.frames[f - 1].drive >= 0 else 0
        elif len(moving) == 1:
            vector_frame[v] = moving[0]
    model.vector_frame = vector_frame
    if model.solver_frame_exact():
        model.policy = POLICY_CONSTANT
    else:
        model.vector_frame = np.zeros(0, dtype=np.int64)
