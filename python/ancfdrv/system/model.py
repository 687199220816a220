"""The assembled :class:`Model`: what the static and dynamic solvers and the result writers
use (the one Model protocol of the package), over a kernel handle that holds the system
(:class:`~ancfdrv.kernel.KernelSystem`).

Coordinates: the solvers' unknowns are the independent coordinates e (with linear joints
eliminated, q = B e + q0; otherwise e = q). Forces, tangents and output rows come from the
kernel; the constraints are a :class:`~.constraint_set.ConstraintSet`.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import field

import numpy as np

from ..records import record
from .. import kernel
from ..codes import POLICY_CONSTANT, POLICY_REFACTOR
from ..csr import Csr, sorted_unique, unique_keys
from ..errors import InputError, SolverError
from .bodies import Body, rotation_about
from .constraint_set import ConstraintSet
from .drives import Drive
from .registry import add_to_kernel
from .patterns import Pattern, Reduction


@record(eq=False, repr=False)
class FrameInfo:
    """A beam's frame: A(t) = Rot(axis, phi(t)) base about pivot (drive -1: A = base)."""

    drive: int
    axis: np.ndarray
    base: np.ndarray
    pivot: np.ndarray
    drive_obj: Drive | None = None

    def rotation(self, t: float) -> np.ndarray:
        if self.drive_obj is None:
            return self.base
        return rotation_about(self.axis, self.drive_obj.value(t)) @ self.base


@record(eq=False, repr=False)
class SetInfo:
    """An element set as assembled (one per flexible body)."""

    body: Body
    kind: str                 # 'ffr', 'continuum', 'cubic', 'plate', 'cable'
    dofs: np.ndarray          # (nde, nel) full coordinates, 0-based
    nel: int
    frame: int                # 1-based frame id (0: none)
    mass_compact: np.ndarray
    scatter: np.ndarray | None = None
    stiffness0: np.ndarray | None = None
    reference: np.ndarray | None = None
    gradients: np.ndarray | None = None
    weights: np.ndarray | None = None
    nvolume: int = 0
    #: the continuum beam's torsion and shear correction [c, d_y, d_z] (Section.shear_scales)
    shear_scales: tuple[float, float, float] = (1.0, 0.0, 0.0)
    cubic: kernel.CubicBeam | None = None
    plate_reference: kernel.PlateReference | None = None
    #: Kelvin-Voigt retardation time (s) handed to the kernel: the material's with the
    #: effect 'damping' listed, else 0 (no damping code runs)
    damping_time: float = 0.0
    #: 'ffr' with geometric stiffness (P-delta): per element EA (nel,), the unit axis in
    #: the frame (3, nel), the length (nel,), the slope Gram matrix (8, 8, nel); else None
    second_order: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None
    #: the set's elastic forces are a constant stiffness (stiffness0) turned with its
    #: floating frame (the ANCF-FFR set): what the FFR-only solvers and checks ask
    floating: bool = False
    #: the set's 1-based index in the kernel's system (0 until handed to it)
    index: int = 0


@record(eq=False, repr=False)
class MomentInfo:
    """A dead moment on the nodal director q[dofs] (full coordinates)."""

    name: str
    dofs: np.ndarray
    axis: np.ndarray
    magnitude: float
    effect: str
    reference: np.ndarray
    #: kept at its value whatever the load factor (buckling's fixed loads)
    fixed: bool = False


#: kinds of the driven and follower point loads (fortran/src/system/vector_loads.f90)
VLOAD_DEAD_MOMENT, VLOAD_FOLLOWER_MOMENT, VLOAD_FOLLOWER_FORCE = 1, 2, 3


@record(eq=False, repr=False)
class VectorLoadInfo:
    """A driven or follower point load (kernel module vector_loads): kind, 0-based drive
    (-1: none), vector (a dead moment's global vector, or a follower's components on the
    body's directions a, b, a x b), torsion shares, and per slot (a, b, p) the terms
    (first full coordinate of a 3-vector, coefficient)."""

    name: str
    kind: int
    drive: int
    vector: np.ndarray
    shares: np.ndarray
    slots: list[list[tuple[int, float]]]
    effect: str
    #: kept at its value whatever the load factor (buckling's fixed loads)
    fixed: bool = False


@record(eq=False, repr=False)
class ProbeInfo:
    """p = sum coef q[first:first+3]; deflection A_f(t)^T (p - pivot) - reference."""

    name: str
    body: str
    terms: list[tuple[int, float]]
    frame: int
    reference: np.ndarray
    attachment: object = None


def kron_scalar(mass) -> Csr | None:
    """Mbar when M = kron(Mbar, I3) exactly (every 3 x 3 block a scalar times I3 over whole
    3-vectors), else None. ``mass``: a :class:`~ancfdrv.csr.Csr` or scipy sparse matrix;
    Mbar without stored zeros, columns sorted."""
    m = mass if isinstance(mass, Csr) else Csr.from_scipy(mass)
    n = m.shape[0]
    if n % 3:
        return None
    rows, cols, vals = m.row_index(), m.indices, m.data
    keep = vals != 0
    rows, cols, vals = rows[keep], cols[keep], vals[keep]
    corner = (rows % 3 == 0) & (cols % 3 == 0)
    scalar = Csr.from_coo(rows[corner] // 3, cols[corner] // 3, vals[corner], (n // 3, n // 3))
    # kron(Mbar, I3)'s nonzeros against M's: the same entries with the same values
    s_rows, s_cols = scalar.row_index(), scalar.indices
    kron_keys = ((3 * s_rows[:, None] + np.arange(3)) * n
                 + 3 * s_cols[:, None] + np.arange(3)).ravel()
    kron_vals = np.repeat(scalar.data, 3)
    order = np.argsort(kron_keys, kind="stable")
    keys = rows * n + cols
    key_order = np.argsort(keys, kind="stable")
    if len(keys) != len(kron_keys) or np.any(keys[key_order] != kron_keys[order]) \
            or np.any(vals[key_order] != kron_vals[order]):
        return None
    return scalar


def _turned_difference(a: Csr, b: Csr, u: np.ndarray) -> float:
    """max |A - U B U^T| for U block-diagonal with the 3 x 3 blocks u (one per 3-vector),
    over the 3 x 3 blocks of A and B."""
    nvec = len(u)
    rows = np.concatenate([a.row_index(), b.row_index()])
    cols = np.concatenate([a.indices, b.indices])
    keys, _, block = unique_keys(rows // 3 * nvec + cols // 3)
    part = np.repeat([0, 1], [a.nnz, b.nnz])
    flat = ((part * len(keys) + block) * 3 + rows % 3) * 3 + cols % 3
    dense = np.bincount(flat, weights=np.concatenate([a.data, b.data]),
                        minlength=2 * 9 * len(keys)).reshape(2, len(keys), 3, 3)
    turned = u[keys // nvec] @ dense[1] @ u[keys % nvec].transpose(0, 2, 1)
    return float(np.abs(dense[0] - turned).max(initial=0.0))


def default_response(probes: dict, bodies: list[Body]) -> tuple[str, int] | None:
    """The probe and component a sweep compares when the builder names none: the first
    probe, its transverse component (1) on a beam, else r3 (2); None without probes.
    ``probes``: the model's (each names its body) or a System's (each holds its body)."""
    if not probes:
        return None
    first = next(iter(probes.values()))
    name = getattr(first.body, "name", first.body)
    body = next(b for b in bodies if b.name == name)
    return first.name, body.response_component


def length_scale(bodies: list[Body]) -> float:
    """The length the Newton tolerances are relative to: the largest flexible body's size
    (a beam's length, the largest extent of a plate's or leaf's nodes along a coordinate
    axis), else the spread of the rigid bodies' centres (1 m when they coincide)."""
    sizes = [body.extent for body in bodies if body.extent is not None]
    if sizes:
        return max(sizes)
    centres = np.array([b.centre for b in bodies if b.rigid])
    spread = float(np.linalg.norm(np.ptp(centres, axis=0))) if len(centres) else 0.0
    return spread if spread > 0 else 1.0


class Model:
    """An assembled system (built by ``ancfdrv.system.assembly.assemble``): the interface
    the solvers and the result writers use."""

    #: driven and follower point loads (set by the assembly; empty: none)
    vector_loads: tuple | list = ()
    #: force elements (system/force_elements.ForceElementInfo; set by the assembly)
    force_elements: tuple | list = ()
    #: the uniform gravity of the active gravity loads (m/s^2; set by the assembly)
    gravity: tuple | np.ndarray = (0.0, 0.0, 0.0)
    #: the fixed loads (System.assemble's ``fixed_loads``: kept at their value whatever the
    #: load factor, buckling's F beside the reference loads): the share of the constant
    #: force they make (None: no load is fixed) and per driven force whether it is fixed
    #: (the moments and vector loads carry their own flag); set by the assembly
    fixed_force: np.ndarray | None = None
    #: the names (loads or effects) System.assemble was given as fixed
    fixed_loads: tuple[str, ...] = ()
    driven_fixed: tuple | list = ()

    def __init__(self, *, title: str, effects: tuple[str, ...], counters: Counter,
                 warnings: list[str], notes: list[str], bodies: list[Body], sets: list[SetInfo],
                 frames: list[FrameInfo], drives: list[Drive], q0: np.ndarray, e0: np.ndarray,
                 reduction: Reduction | None, full_pattern: Pattern, pattern: Pattern,
                 mass: Csr, constant_force: np.ndarray, driven_forces: list,
                 moments: list[MomentInfo], constraints: ConstraintSet, contact_pairs: list[dict],
                 probes: dict[str, ProbeInfo], point_masses: list, linear_joints: str,
                 response: tuple[str, int] | None = None,
                 support_frames: dict | None = None) -> None:
        self.title, self.effects, self.counters = title, effects, counters
        self.warnings, self.notes = warnings, notes
        self.bodies, self.sets, self.frames, self.drives = bodies, sets, frames, drives
        self.q0, self.e0, self.reduction = q0, e0, reduction
        self.full_pattern, self.pattern, self.mass = full_pattern, pattern, mass
        self.constant_force_vector = constant_force
        self.driven_forces, self.moments, self.constraints = driven_forces, moments, constraints
        #: the active point masses: (load name, body name, point at t = 0, mass) each
        self.contact_pairs, self.probes, self.point_masses = contact_pairs, probes, point_masses
        self.linear_joints = linear_joints
        self.policy = POLICY_REFACTOR
        self.vector_frame = np.zeros(0, dtype=np.int64)
        self.ndof, self.nfull = len(e0), len(q0)
        self.kernel: kernel.KernelSystem | None = None
        self.solver: kernel.DirectSolver | None = None
        self.contact_guesses = np.hstack([p["guesses"] for p in contact_pairs]) \
            if contact_pairs else np.zeros((2, 1))
        self.contact_counts = np.zeros(6, dtype=np.int32)
        self.length_scale = length_scale(bodies)
        #: why the model must not be run (assembled with check_frames=False)
        self.frame_problems: list[str] = []
        #: the probe and component sweeps compare (a builder's choice, else the first probe's)
        self.response: tuple[str, int] | None = response
        #: the rigid motion of each beam's supports (general scenes and Python runs:
        #: deflections relative to it, :mod:`ancfdrv.system.supports`), else None
        self.support_frames = support_frames
        if response is None:
            self.response = default_response(probes, bodies)

    def require_runnable(self) -> None:
        """Refuse a model assembled for checks alone (an 'ffr' frame nothing holds)."""
        if self.frame_problems:
            raise InputError(self.frame_problems[0])

    # -- identity ---------------------------------------------------------------------------
    @property
    def damped(self) -> bool:
        """Whether any element set carries material damping (the effect 'damping' listed and
        a material with damping_time > 0)."""
        return any(s.damping_time > 0 for s in self.sets)

    @property
    def npoint(self) -> int:
        return sum(len(p["point_element"]) for p in self.contact_pairs)

    @property
    def contact_point_names(self) -> list[str]:
        return [n for p in self.contact_pairs for n in p["point_names"]]

    def summary(self) -> dict[str, int | str | float]:
        """The /model attributes of a result file."""
        nodes = sum(b.mesh_nodes for b in self.bodies)
        return {"ndof": self.ndof, "nfull": self.nfull, "nnodes": nodes,
                "nelements": sum(s.nel for s in self.sets),
                "nbodies": len(self.bodies), "nrigid_bodies":
                    sum(b.rigid for b in self.bodies),
                "nconstraints": len(self.constraints),
                "nlinear_eliminated": 0 if self.reduction is None else
                    len(self.reduction.relations),
                "ncontact_points": self.npoint,
                # planar reduction (system/planar.py): the plane ('' off), the coordinates
                # it fixed, and the unknowns solved (coordinates + multipliers)
                "planar": getattr(self, "planar", ""),
                "nplanar_fixed": getattr(self, "nplanar_fixed", 0),
                "nunknowns": self.ndof + len(self.constraints),
                # the model's size (m): what a deflection is small or zero against (sweeps)
                "length_scale": float(self.length_scale)}

    # -- coordinates --------------------------------------------------------------------------
    def expand(self, e: np.ndarray, with_offset: bool = True) -> np.ndarray:
        """Full coordinates q (rows of e may be time steps)."""
        if self.reduction is None:
            return np.array(e, dtype=float, copy=True)
        return self.reduction.expand(e, with_offset)

    def reduce(self, full: np.ndarray) -> np.ndarray:
        return full if self.reduction is None else self.reduction.reduce(full)

    # -- matrices ---------------------------------------------------------------------------
    def mass_matrix(self):
        """M on the independent coordinates, a scipy CSR matrix (a copy; imports
        scipy.sparse; the run itself uses :attr:`mass`, a :class:`~ancfdrv.csr.Csr`)."""
        return self.mass.to_scipy()

    def mass_values(self) -> np.ndarray:
        """M on the solvers' pattern."""
        return self.pattern.values_of(self.mass)

    def stiffness_values(self, t: float = 0.0, e: np.ndarray | None = None) -> np.ndarray:
        """The tangent (global coordinates) on the pattern at e (default e0) and t."""
        return self.forces(self.e0 if e is None else e, t, want_tangent=True)["tangent"]

    def stiffness_matrix(self, t: float = 0.0):
        """The tangent at e0 and t, a scipy CSR matrix (imports scipy.sparse)."""
        return self.pattern.to_scipy(self.stiffness_values(t))

    # -- forces -----------------------------------------------------------------------------
    def forces(self, e: np.ndarray, t: float = 0.0, v: np.ndarray | None = None, *,
               load_factor: float | None = None, velocity_factor: float = 0.0,
               want_tangent: bool = False) -> dict:
        """From the kernel: internal = B^T (Q_el - Q_contact - lf Q_M), external = lf Q(t),
        strain energy, contact potential and records, and on request the tangent (sets plus
        velocity_factor times the contact Jacobian) on :attr:`pattern`."""
        lf = 1.0 if load_factor is None else load_factor
        out = self.kernel.evaluate(t, e, np.zeros(self.ndof) if v is None else v,
                                   self.contact_guesses, self.contact_counts, load_factor=lf,
                                   velocity_factor=velocity_factor, want_tangent=want_tangent)
        self._count_force_evaluations(1)
        if want_tangent:
            self.counters["stiffness_assembly"] += 1
        self.contact_guesses, self.contact_counts = out["guesses"], out["counts"]
        return out

    def _count_force_evaluations(self, n: int) -> None:
        """Count n evaluations of the forces in the kernel (elastic, damping, moments)."""
        self.counters["elastic_force"] += n
        if self.damped:
            self.counters["damping"] += n
        for m in self.moments or ():
            self.counters[m.effect] += n

    def count_consistent_accelerations(self, n: int) -> None:
        """Count n consistent accelerations solved in the kernel (the start of a run and
        its restarts: each evaluates the forces and the constraints once)."""
        self._count_force_evaluations(n)
        self.constraints.evaluations += n

    def internal_force(self, e: np.ndarray, t: float = 0.0, want_tangent: bool = False):
        """B^T (Q_el - Q_contact - Q_M), strain energy and (on request) the tangent values."""
        out = self.forces(e, t, want_tangent=want_tangent)
        return out["internal"], out["strain"], out["tangent"]

    def constant_force(self) -> np.ndarray:
        """Configuration-independent loads of the listed effects (at t = 0) at load factor 1
        (the static Newton passes its load factors to the kernel as arguments)."""
        force = self.constant_force_vector.copy()
        for index, vector in self.driven_forces:
            force += self.drives[index].value(0.0) * vector
        return force

    def moment_terms(self, e: np.ndarray, load_factor: float | None = None, *,
                     hessians: bool = True):
        """Per dead moment: (coordinates, force, Jacobian, Hessian) over the coordinates its
        director depends on (through B when reduced); ``hessians=False``: None for the
        Hessian (its four-operand product not formed where only the Jacobian is used)."""
        lf = 1.0 if load_factor is None else load_factor
        q = self.expand(e)
        out = []
        for m in self.moments:
            self.counters[m.effect] += 1
            f, j, h = kernel.moment_force(q[m.dofs], m.axis, (1.0 if m.fixed else lf) * m.magnitude)
            cols, b = self._director_map(m.dofs)
            out.append((cols, b.T @ f, b.T @ j @ b,
                        np.einsum("ijl,ia,jb,lc->abc", h, b, b, b) if hessians else None))
        return out

    def stiffness_triplets(self, e: np.ndarray, lam: np.ndarray, t: float = 0.0,
                           load_factor: float | None = None,
                           tangent: np.ndarray | None = None):
        """The static Newton matrix's stiffness block at (e, lambda) as triplets (rows,
        cols, values; duplicates add up): the elements' and contact tangent (``tangent``,
        the pattern's values of ``forces(want_tangent=True)``, evaluated when not given),
        minus the dead moments' and the driven and follower point loads' Jacobians (their
        exact, unsymmetric load stiffness), minus the constraint Hessians times the
        multipliers."""
        if tangent is None:
            tangent = self.forces(e, t, want_tangent=True, load_factor=load_factor)["tangent"]
        k = self.pattern.to_csr(tangent)
        rows, cols, vals = [k.row_index()], [k.indices], [k.data]
        moments = self.moment_terms(e, load_factor=load_factor, hessians=False)
        for dofs, _, jac, *_ in (*moments, *self.vector_load_terms(e, t,
                                                                    load_factor=load_factor)):
            dofs = np.asarray(dofs)
            rows.append(np.repeat(dofs, len(dofs)))
            cols.append(np.tile(dofs, len(dofs)))
            vals.append(-np.asarray(jac).ravel())
        if len(self.constraints):
            h_con, h_rows, h_cols, h_vals = self.constraints.hessian_triplets(e)
            rows.append(h_rows)
            cols.append(h_cols)
            vals.append(-lam[h_con] * h_vals)
        return (np.concatenate(rows).astype(np.int64), np.concatenate(cols).astype(np.int64),
                np.concatenate(vals))

    def vector_load_terms(self, e: np.ndarray, t: float = 0.0,
                          load_factor: float | None = None):
        """Per driven or follower point load: (coordinates e, generalized force, its
        Jacobian d force / d e) over the coordinates its directions and point depend on
        (through B when reduced); the force is external (it enters the residual with a
        minus sign)."""
        lf = 1.0 if load_factor is None else load_factor
        q = self.expand(e)
        out = []
        for load in self.vector_loads:
            self.counters[load.effect] += 1
            phi = 1.0 if load.drive < 0 else self.drives[load.drive].value(t)
            x = [sum((c * q[d:d + 3] for d, c in slot), np.zeros(3)) for slot in load.slots[:2]]
            scale = 1.0 if load.fixed else lf
            force, jac = kernel.vector_load_force(load.kind, scale * phi * load.vector,
                                                  load.shares, x[0], x[1])
            dofs = sorted({d + i for slot in load.slots for d, _ in slot for i in range(3)})
            where = {d: k for k, d in enumerate(dofs)}
            f = np.zeros(len(dofs))
            j = np.zeros((len(dofs), len(dofs)))
            for s, slot in enumerate(load.slots):
                for d, c in slot:
                    rows = [where[d + i] for i in range(3)]
                    f[rows] += c * force[:, s]
                    for w in range(2):
                        for d2, c2 in load.slots[w]:
                            cols = [where[d2 + i] for i in range(3)]
                            j[np.ix_(rows, cols)] += c * c2 * jac[:, s, :, w]
            cols, b = self._director_map(np.array(dofs))
            out.append((cols, b.T @ f, b.T @ j @ b))
        return out

    def _director_map(self, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Coordinates e the full coordinates q[dofs] depend on, and dq[dofs]/de there."""
        if self.reduction is None:
            return np.asarray(dofs), np.eye(len(dofs))
        rows = self.reduction.matrix.take_rows(dofs)
        cols = sorted_unique(rows.indices)
        b = np.zeros((len(dofs), len(cols)))
        b[rows.row_index(), np.searchsorted(cols, rows.indices)] = rows.data
        return cols, b

    # -- probes -----------------------------------------------------------------------------
    def probe_positions(self, e: np.ndarray) -> dict[str, np.ndarray]:
        q = self.expand(e)
        return {name: sum((coef * q[first:first + 3] for first, coef in p.terms), np.zeros(3))
                for name, p in self.probes.items()}

    def frame_rotation(self, frame: int, t: float) -> np.ndarray:
        return np.eye(3) if frame == 0 else self.frames[frame - 1].rotation(t)

    def deflections_at(self, e: np.ndarray, t: float) -> dict[str, np.ndarray]:
        """Probe displacements from the rigid configuration in each probe's frame at t
        (beams: their frame; other bodies: global components)."""
        out = {}
        for name, position in self.probe_positions(e).items():
            p = self.probes[name]
            pivot = np.zeros(3) if p.frame == 0 else self.frames[p.frame - 1].pivot
            out[name] = self.frame_rotation(p.frame, t).T @ (position - pivot) - p.reference
        return out

    def deflections(self, e: np.ndarray) -> dict[str, np.ndarray]:
        return self.deflections_at(e, 0.0)

    # -- geometry for the result files ---------------------------------------------------------
    def plate_bodies(self) -> list[Body]:
        """The bodies with a mid-surface mesh (plates and leaves)."""
        return [b for b in self.bodies if b.surface]

    def node_positions(self, q_reduced: np.ndarray) -> np.ndarray:
        """Plate and leaf node positions (nt, nnodes, 3) from coordinates (nt, ndof)."""
        full = self.expand(np.atleast_2d(q_reduced))
        parts = []
        for plate in self.plate_bodies():
            block = full[:, plate.first:plate.first + plate.ncoordinates]
            parts.append(block.reshape(len(full), plate.mesh.nnodes, 9)[:, :, :3])
        return np.concatenate(parts, axis=1)

    def plate_geometry(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Initial node positions and quadrilaterals (global node numbering) of every plate
        and leaf, or None without plates."""
        plates = self.plate_bodies()
        if not plates:
            return None
        nodes, elements, offset = [], [], 0
        for plate in plates:
            nodes.append(plate.mesh.coords[:, :3])
            elements.append(plate.mesh.elements + offset)
            offset += plate.mesh.nnodes
        return np.vstack(nodes), np.vstack(elements)

    # -- the kernel ---------------------------------------------------------------------------
    def solver_frame_exact(self) -> bool:
        """Whether S in the solver frame is constant: B^T (M + K(phi)) B = U (B^T (M + K_c) B)
        U^T for a test turn of every moving frame (U: each reduced 3-vector's frame)."""
        def reduced(values_full: np.ndarray) -> Csr:
            m = self.full_pattern.to_csr(values_full)
            if self.reduction is not None:
                m = self.reduction.matrix.congruence(m)
            return m

        def stiffness(turn: float) -> np.ndarray:
            values = np.zeros(self.full_pattern.nnz)
            for s in self.sets:
                frame = self.frames[s.frame - 1]
                rotation = frame.base
                if frame.drive >= 0:
                    rotation = rotation_about(frame.axis, turn) @ frame.base if turn else \
                        np.eye(3)
                element = kernel.ffr_element_stiffness(s.stiffness0, np.asfortranarray(rotation))
                np.add.at(values, s.scatter.ravel() - 1, element.ravel())
            return values
        turn = 0.9
        k_c, k_t = reduced(stiffness(0.0)), reduced(stiffness(turn))
        turned = {f: rotation_about(self.frames[f - 1].axis, turn) @ self.frames[f - 1].base
                  for f in set(self.vector_frame.tolist()) - {0}}
        rotations = np.array([np.eye(3)] + [turned.get(f, np.eye(3))
                                            for f in range(1, len(self.frames) + 1)])
        u = rotations[self.vector_frame]          # (nvectors, 3, 3): U's diagonal blocks
        scale = max(k_c.max_abs(), 1e-300)
        mass = self.mass
        ok_k = _turned_difference(k_t, k_c, u) <= 1e-9 * scale
        ok_m = _turned_difference(mass, mass, u) <= 1e-12 * max(mass.max_abs(), 1e-300)
        return bool(ok_k and ok_m)

    def carry_vectors(self) -> tuple[np.ndarray, ...] | None:
        """:meth:`made_carry_vectors`, made once per state of what they depend on (the
        policy, the length scale, the contact pairs, sets, bodies and reduction; read-only
        arrays): the kernel's hand-over (:meth:`touched_blocks`) and each run's start ask
        for them (~0.1 M instructions each on a 5-node cable)."""
        key = (self.policy, self.length_scale, self.nfull, len(self.contact_pairs),
               len(self.sets), len(self.bodies))
        kept = self.__dict__.get("_carry_vectors")
        if kept is not None and kept[0] == key and kept[1] is self.reduction:
            return kept[2]
        made = self.made_carry_vectors()
        if made is not None:
            for array in made:
                array.flags.writeable = False
        self.__dict__["_carry_vectors"] = (key, self.reduction, made)
        return made

    def made_carry_vectors(self) -> tuple[np.ndarray, ...] | None:
        """The 3-vectors the stepper fits the bodies' rotations to when it carries its
        iteration matrix under rotation (``solver.carry``, docs/theory.md "The iteration
        matrix carried with the rotation"): (first full coordinate of each vector, weight,
        1 for a position / 0 for a gradient or director, its body's group), or None where
        turning the matrix does not follow the system: FFR sets (their frames already carry
        theirs), contact, bodies whose coordinates are not all global 3-vectors, a
        reduction that mixes coordinates (a row of B with more than one entry). Positions
        weigh 1, the unit-size gradients and directors the model's length squared, so both
        shares compare. Each body is a group, fitted its own rotation; the flexible bodies
        are listed first, so a coordinate the reduction shares between a flexible and a
        rigid body (an eliminated joint) turns with the flexible one's stiffness (the rigid
        body's mass turns exactly with any rotation; fortran/src/system/system_carry.f90)."""
        if self.policy != POLICY_REFACTOR or self.contact_pairs or self.nfull % 3:
            return None
        if any(s.floating for s in self.sets):   # (other kinds ignore their frame)
            return None
        if self.reduction is not None and self.reduction.selects is None:
            rows = self.reduction.matrix.indptr
            if len(rows) > 1 and (rows[1:] - rows[:-1]).max() > 1:
                return None
        first, weight, position, group = [], [], [], []
        bodies = [b for b in self.bodies if b.ncoordinates]   # (not the ground)
        for index, body in enumerate(sorted(bodies, key=lambda b: not b.flexible)):
            nodes = body.nnodes
            if not nodes:
                return None
            per_node, rest = divmod(body.ncoordinates, 3 * nodes)
            if rest or per_node not in (2, 3, 4):
                return None
            for node in range(nodes):
                for k in range(per_node):
                    first.append(body.first + 3 * (per_node * node + k))
                    position.append(1 if k == 0 else 0)
                    weight.append(1.0 if k == 0 else self.length_scale**2)
                    group.append(index)
        if not first:
            return None
        return (np.array(first, dtype=np.int64), np.array(weight),
                np.array(position, dtype=np.int64), np.array(group, dtype=np.int64))

    def touched_blocks(self) -> np.ndarray:
        """First coordinates (0-based) of the 3-vector blocks holding every constrained
        coordinate (the last block kept inside the vector)."""
        used = self.constraints.touched()
        if not len(used):
            return np.zeros(0, dtype=np.int64)
        if self.carry_vectors() is not None:
            # a carried matrix turns each constrained 3-vector whole (carried_rotation): its
            # other reduced components join the blocks, so the turned gradients stay within
            # the factorization's flexibility (no solves per step)
            index = self.reduction.independent if self.reduction is not None else \
                np.arange(self.nfull)
            reduced_of = np.full(self.nfull, -1)
            reduced_of[index] = np.arange(len(index))
            full = index[used]
            partners = reduced_of[(full - full % 3)[:, None] + np.arange(3)].ravel()
            used = sorted_unique(np.concatenate([used, partners[partners >= 0]]))
        # (a model of fewer than 3 unknowns, e.g. a body on a slide: one block at 0, whose
        # rows past the last unknown the kernel leaves out)
        return sorted_unique(np.maximum(np.minimum(used - used % 3, self.ndof - 3), 0))

    def banded(self) -> bool:
        """The banded Cholesky (with LU fallback) for symmetric matrices with a narrow band:
        no contact (its Jacobian is unsymmetric) and half-bandwidth <= max(64, n / 4).
        Material damping makes a refactorized model's tangent unsymmetric too (the strain
        rate's dependence on e, tau B(e)^T D B(e'), and an FFR frame's omega term), and not
        small against beta' M along the rigid modes (a steel plate swinging at 10 rad/s with
        tau = 2e-3 s: Newton with the Cholesky's upper triangle diverged), so MUMPS factorizes
        it; the constant policy's beta' M + (1 + c tau) K0 stays symmetric. Driven and
        follower point loads add their unsymmetric Jacobian to a refactorized tangent: MUMPS
        too."""
        if self.damped and self.policy != POLICY_CONSTANT:
            return False
        if self.vector_loads and self.policy != POLICY_CONSTANT:
            return False
        if self.force_elements:  # a damper's tangent is unsymmetric (c dm/dq (d2m/dq2 q')^T)
            return False
        return not self.contact_pairs and self.pattern.bandwidth() <= max(64, self.ndof // 4)

    def build_kernel(self) -> None:
        """Hand the system to the kernel (once) and analyse the iteration matrix's pattern."""
        ks = kernel.KernelSystem(self.ndof, self.nfull)
        for s in self.sets:  # each kind's adder (the registry's; declared by its kind)
            s.index = add_to_kernel(ks, s)
        ks.set_frames([f.drive for f in self.frames], [f.axis for f in self.frames],
                      [f.base for f in self.frames], [f.pivot for f in self.frames])
        ks.set_drives([d.kind for d in self.drives], [d.params() for d in self.drives])
        what = "iteration matrix beta' M + K "
        if self.banded():
            self.solver = kernel.DirectSolver(self.ndof, self.pattern.rows,
                                              self.pattern.col_index, banded_spd=True,
                                              what=what + "(banded Cholesky)")
        else:   # the kernel's cost rule, as for every other system the model factorizes
            # (beta' M keeps the symmetric part positive definite: the envelope LU may
            # replace the banded LU)
            self.solver = kernel.DirectSolver.by_cost(self.ndof, self.pattern.rows,
                                                      self.pattern.col_index, what=what,
                                                      positive=True)
            self.solver.what += f"({self.solver.kind})"
        mass = self.mass.copy()
        mass.eliminate_zeros()  # the x, y, z blocks of M are decoupled: 2/3 of it is 0
        mass.sort_indices()
        ks.set_matrices(mass, (self.full_pattern.row_ptr, self.full_pattern.col_index),
                        self.solver.handle, self.policy, self.mass_values(), self.vector_frame,
                        self.touched_blocks(), self.mass)
        scalar = kron_scalar(mass)
        if scalar is not None:
            ks.set_kron_mass(scalar)
        if self.reduction is not None:
            r = self.reduction
            ks.set_reduction(r.matrix, r.offset, r.plan_source, r.plan_target, r.plan_coef)
        ks.set_loads(self.constant_force_vector, [i for i, _ in self.driven_forces],
                     np.array([v for _, v in self.driven_forces]).T.reshape(self.ndof, -1),
                     [m.dofs for m in self.moments], [m.axis for m in self.moments],
                     [m.magnitude for m in self.moments], [m.reference for m in self.moments])
        if self.vector_loads:
            ks.set_vector_loads(self.vector_loads)
        if self.fixed_force is not None:
            ks.set_fixed_loads(self.fixed_force, self.driven_fixed,
                               [m.fixed for m in self.moments],
                               [x.fixed for x in self.vector_loads])
        if self.force_elements:
            from .kinds.force_element import kernel_layout
            ks.set_force_elements(kernel_layout(self.force_elements, self.full_pattern))
        ks.set_constraints(self.constraints.layout())
        for pair in self.contact_pairs:
            ks.add_contact_pair(pair["dofs"], pair["sizes"], pair["grid"], pair["point_element"],
                                pair["point_local"], pair["params"])
        ptr = np.concatenate([[0], np.asarray([len(p.terms) for p in self.probes.values()])
                              .cumsum()])
        ks.set_probes(ptr, [d for p in self.probes.values() for d, _ in p.terms],
                      [c for p in self.probes.values() for _, c in p.terms],
                      [p.frame for p in self.probes.values()],
                      [p.reference for p in self.probes.values()])
        self.kernel = ks

    @property
    def constant_policy(self) -> bool:
        return self.policy == POLICY_CONSTANT

    def close(self) -> None:
        """Release the kernel's system and solver."""
        if self.kernel is not None:
            self.kernel.close()
        if self.solver is not None:
            self.solver.close()

    def check_alive(self) -> None:
        if self.kernel is None or not self.kernel.handle:
            raise SolverError("the model's kernel system was released (model.close())")
