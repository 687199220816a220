"""Rigid-flexible assemblies of seed 003: thin-plate meshes, rigid bodies as ANCF reference
nodes (eqs. 29-32), linear constraints eliminated by a constant matrix B (eqs. 34-37) and
leaf-to-leaf contact (eqs. 17-28, ``fortran/src/leaf_contact.f90``).

Coordinates. The *full* vector q holds the plate mesh's nodal coordinates [r, r_x, r_y] per
node, then 12 per rigid body [r, r_x, r_y, r_z] (r: the body's reference point, J = [r_x r_y
r_z] its orientation, a point at body coordinates u is at r + J u). Linear constraints
(hinges to a body, eq. 29 without its rotational part; fixed or guided coordinates) give
q = B q_i + q0 with the independent coordinates q_i; the solvers work on q_i with
M_ii = B^T M B and Q_ii = B^T Q (eq. 37), and the nonlinear orthonormality constraints of
the bodies (eq. 30) keep their Lagrange multipliers (eq. 38).

:class:`AssemblyModel` has the interface the dynamic solver uses (see ``dynamic.py``) in the
independent coordinates, plus ``expand`` (q_i -> q) for output.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from . import kernel
from .constraints import KIND_DOT, ConstraintSet
from .errors import InputError
from .plate import PLATE_NODE_DOFS, PlateModel

RIGID_DOFS = 12


@dataclass
class RigidBody:
    """A rigid body as an ANCF reference node: mass, centre of mass and inertia tensor about
    it (body frame), initial reference point and orientation. ``planar``: kept in the r1-r3
    plane (r2 translation, roll and yaw fixed): r_y = e2 and the r2 components of r, r_x, r_z
    are eliminated, and only the three in-plane orthonormality constraints remain."""

    name: str
    mass: float
    inertia: np.ndarray
    position: np.ndarray
    centre: np.ndarray = field(default_factory=lambda: np.zeros(3))
    orientation: np.ndarray = field(default_factory=lambda: np.eye(3))
    planar: bool = False
    first: int = -1   # its first full coordinate (set by the assembly)

    def coordinates(self) -> np.ndarray:
        return np.concatenate([self.position, *self.orientation.T])

    def dof(self, part: int, component: int) -> int:
        """Full index of component (0..2) of part 0 (r) or 1..3 (r_x, r_y, r_z)."""
        return self.first + 3 * part + component


@dataclass
class LinearRelation:
    """q[dependent] = constant + sum coef * q[j] over terms {j: coef} (full indices)."""

    dependent: int
    terms: dict[int, float]
    constant: float = 0.0
    name: str = ""


@dataclass
class Reduction:
    """q = B q_i + q0 (eqs. 34-35) and the plan that forms B^T S B on the reduced pattern."""

    matrix: sp.csr_matrix          # B (nfull x nred)
    offset: np.ndarray             # q0 (nfull)
    independent: np.ndarray        # full index of each reduced coordinate
    full_pattern: kernel.SparsePattern
    pattern: "CsrPattern"
    plan_source: np.ndarray        # 0-based positions in the full pattern
    plan_target: np.ndarray        # 0-based positions in the reduced pattern
    plan_coef: np.ndarray

    def expand(self, x: np.ndarray, with_offset: bool = True) -> np.ndarray:
        """Full coordinates (or, without the offset, velocities) from reduced ones; x may
        be (nred,) or (nt, nred)."""
        full = (self.matrix @ np.asarray(x).T).T
        return full + self.offset if with_offset else full

    def reduce(self, full: np.ndarray) -> np.ndarray:
        """B^T Q (eq. 37)."""
        return self.matrix.T @ full


@dataclass
class CsrPattern:
    """A CSR pattern (sorted columns) with the attributes the solvers read."""

    n: int
    row_ptr: np.ndarray
    col_index: np.ndarray

    def __post_init__(self) -> None:
        self.nnz = len(self.col_index)
        self.rows = np.repeat(np.arange(self.n), np.diff(self.row_ptr))

    def values_of(self, matrix: sp.spmatrix) -> np.ndarray:
        """Values of ``matrix`` on this pattern (entries outside it must be zero)."""
        m = sp.csr_matrix(matrix)
        return np.asarray(m[self.rows, self.col_index]).ravel()

    def to_scipy(self, values: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((values.copy(), self.col_index.copy(), self.row_ptr.copy()),
                             shape=(self.n, self.n))

    def positions(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Positions of entries (rows, cols) in the values array (-1 when absent)."""
        keys = self.rows.astype(np.int64) * self.n + self.col_index
        wanted = np.asarray(rows, dtype=np.int64) * self.n + np.asarray(cols)
        pos = np.searchsorted(keys, wanted)
        pos = np.minimum(pos, len(keys) - 1)
        return np.where(keys[pos] == wanted, pos, -1)


def build_reduction(nfull: int, relations: list[LinearRelation], q_full: np.ndarray,
                    full_pattern: kernel.SparsePattern) -> Reduction:
    """B and q0 from linear relations (chains allowed: a relation may use coordinates that
    are themselves dependent); checks that the initial q satisfies them."""
    by_dependent: dict[int, LinearRelation] = {}
    for rel in relations:
        if rel.dependent in by_dependent:
            raise InputError(f"coordinate {rel.dependent} is made dependent twice "
                             f"({by_dependent[rel.dependent].name!r} and {rel.name!r})")
        by_dependent[rel.dependent] = rel
    resolved: dict[int, tuple[dict[int, float], float]] = {}

    def resolve(dof: int, depth: int = 0) -> tuple[dict[int, float], float]:
        if dof not in by_dependent:
            return {dof: 1.0}, 0.0
        if dof in resolved:
            return resolved[dof]
        if depth > 50:
            raise InputError(f"linear constraints form a cycle through coordinate {dof}")
        rel = by_dependent[dof]
        terms: dict[int, float] = {}
        constant = rel.constant
        for j, c in rel.terms.items():
            sub_terms, sub_constant = resolve(j, depth + 1)
            constant += c * sub_constant
            for k, ck in sub_terms.items():
                terms[k] = terms.get(k, 0.0) + c * ck
        terms = {k: v for k, v in terms.items() if v != 0.0}
        resolved[dof] = (terms, constant)
        return resolved[dof]

    independent = np.array([i for i in range(nfull) if i not in by_dependent])
    column = -np.ones(nfull, dtype=int)
    column[independent] = np.arange(len(independent))
    rows, cols, vals = [], [], []
    offset = np.zeros(nfull)
    for i in range(nfull):
        terms, constant = resolve(i)
        offset[i] = constant
        for k, c in terms.items():
            rows.append(i)
            cols.append(column[k])
            vals.append(c)
    b = sp.csr_matrix((vals, (rows, cols)), shape=(nfull, len(independent)))
    b.sort_indices()
    mismatch = np.abs(b @ q_full[independent] + offset - q_full)
    if mismatch.max() > 1e-9 * max(1.0, np.abs(q_full).max()):
        worst = int(mismatch.argmax())
        name = by_dependent[worst].name if worst in by_dependent else "?"
        raise InputError(f"the initial configuration violates the linear constraint "
                         f"{name!r} by {mismatch.max():.3e}")
    # reduced pattern: structure of B^T P B (plus the diagonal)
    p = sp.csr_matrix((np.ones(full_pattern.nnz), full_pattern.col_index, full_pattern.row_ptr),
                      shape=(nfull, nfull))
    babs = abs(b)
    reduced = (babs.T @ p @ babs + sp.identity(b.shape[1])).tocsr()
    reduced.sort_indices()
    pattern = CsrPattern(b.shape[1], reduced.indptr.astype(np.int64),
                         reduced.indices.astype(np.int64))
    # plan: every full entry (i, j) and every pair of B entries in rows i and j
    counts = np.diff(b.indptr)
    f_rows, f_cols = full_pattern.rows, full_pattern.col_index
    sources, targets, coefs = [], [], []
    simple = (counts[f_rows] == 1) & (counts[f_cols] == 1)
    k = np.nonzero(simple)[0]
    a = b.indices[b.indptr[f_rows[k]]]
    c = b.indices[b.indptr[f_cols[k]]]
    sources.append(k)
    targets.append(pattern.positions(a, c))
    coefs.append(b.data[b.indptr[f_rows[k]]] * b.data[b.indptr[f_cols[k]]])
    for kk in np.nonzero(~simple & (counts[f_rows] > 0) & (counts[f_cols] > 0))[0]:
        i, j = f_rows[kk], f_cols[kk]
        ra = slice(b.indptr[i], b.indptr[i + 1])
        rc = slice(b.indptr[j], b.indptr[j + 1])
        for a_col, a_val in zip(b.indices[ra], b.data[ra]):
            for c_col, c_val in zip(b.indices[rc], b.data[rc]):
                sources.append(np.array([kk]))
                targets.append(pattern.positions(np.array([a_col]), np.array([c_col])))
                coefs.append(np.array([a_val * c_val]))
    source = np.concatenate(sources)
    target = np.concatenate(targets)
    coef = np.concatenate(coefs)
    if (target < 0).any():
        raise AssertionError("reduced pattern misses an entry of B^T S B")
    return Reduction(b, offset, independent, full_pattern, pattern, source, target, coef)


@dataclass
class ContactSet:
    """Points on the lower leaf (element, local xi, eta) against the upper leaf's element
    grid (n_l, n_w), with the kernel's parameter vector and the projections' warm starts."""

    grid: np.ndarray
    point_element: np.ndarray
    point_local: np.ndarray       # (2, npoints)
    params: np.ndarray
    guesses: np.ndarray           # (2, npoints) leaf-level coordinates on the upper leaf
    names: list[str] = field(default_factory=list)


@dataclass
class BodyProbe:
    """The reference point of a rigid body."""

    body: RigidBody


class AssemblyModel:
    """Plates + rigid bodies + eliminated linear constraints + contact, in independent
    coordinates (the interface of ``dynamic.integrate``)."""

    formulation = "plate"
    solver_kind = "general"
    moments: list = []

    def __init__(self, plates: PlateModel, bodies: list[RigidBody], gravity: np.ndarray | None,
                 effects: tuple[str, ...]) -> None:
        self.plates, self.bodies, self.effects = plates, bodies, effects
        self.mesh = plates.mesh
        self.nplate = plates.ndof
        first = self.nplate
        for body in bodies:
            body.first = first
            first += RIGID_DOFS
        self.nfull = first
        self.e_full0 = np.concatenate([plates.e0] + [b.coordinates() for b in bodies])
        self.relations: list[LinearRelation] = []
        self.constraints = ConstraintSet()
        self.counters: Counter = plates.counters
        self.warnings: list[str] = plates.warnings
        self.probes: dict[str, object] = {}
        self.contact: ContactSet | None = None
        self.force_drive = None
        self.response = ("chassis", 2)
        self._body_mass = [kernel.reference_node_mass(b.mass, b.centre, b.inertia) for b in bodies]
        self._gravity = np.zeros(self.nfull)
        self._gravity[:self.nplate] = plates.constant_force()
        if gravity is not None:
            for body in bodies:
                compact = np.concatenate([[body.mass], body.mass * body.centre])
                self._gravity[body.first:body.first + RIGID_DOFS] += np.kron(compact, gravity)
        self._load_pattern = np.zeros(self.nfull)
        self.length_scale = plates.length_scale
        self.reduction: Reduction | None = None

    # -- building -------------------------------------------------------------------------
    def fix(self, dof: int, name: str) -> None:
        """Eliminate a coordinate at its initial value (no-op when a relation already
        determines it, e.g. the r2 of a planar body hinged to another planar body)."""
        if any(rel.dependent == dof for rel in self.relations):
            return
        self.relations.append(LinearRelation(dof, {}, float(self.e_full0[dof]), name))

    def hinge_point(self, point_dofs: list[int], body: RigidBody, name: str) -> None:
        """r_point = r_body + J_body u (eq. 29, position part only: the point's gradients
        stay free, so two points on a line make a revolute joint about it)."""
        j0 = body.orientation
        u = np.linalg.solve(j0, self.e_full0[point_dofs] - body.position)
        for i, dof in enumerate(point_dofs):
            terms = {body.dof(0, i): 1.0}
            for k in range(3):
                if u[k] != 0.0:
                    terms[body.dof(1 + k, i)] = u[k]
            self.relations.append(LinearRelation(dof, terms, 0.0, f"{name} [{i}]"))

    def add_body_constraints(self, body: RigidBody) -> None:
        """Planar guide (eliminated) and the orthonormality constraints (eq. 30) that are not
        identically satisfied."""
        if body.planar:
            self.fix(body.dof(0, 1), f"{body.name}: planar r2")
            for part in (1, 2, 3):
                for comp in range(3):
                    if part == 2 or comp == 1:
                        self.fix(body.dof(part, comp), f"{body.name}: planar gradient")
            pairs = [(1, 1), (3, 3), (1, 3)]
        else:
            pairs = [(1, 1), (2, 2), (3, 3), (1, 2), (1, 3), (2, 3)]
        self._orthonormal_pairs = getattr(self, "_orthonormal_pairs", []) + [(body, pairs)]

    def guide_vertically(self, body: RigidBody) -> None:
        """Load-cycle guide: the body translates in the r1-r3 plane without turning. Its
        horizontal drift stays free: with the axle and the front eye both held along r1 the
        front half-leaf could not flatten without stretching (a far stiffer, different
        spring)."""
        for part in range(4):
            for comp in range(3):
                if not (part == 0 and comp in (0, 2)):
                    self.fix(body.dof(part, comp), f"{body.name}: vertical guide")
        self._orthonormal_pairs = [(b, p) for b, p in getattr(self, "_orthonormal_pairs", [])
                                   if b is not body]

    def finish(self, contact: ContactSet | None, couplings: list[tuple[int, int]]) -> None:
        """Build the full pattern (plate elements, bodies, contact couplings), B, the reduced
        mass and the constraints in independent coordinates."""
        plates = self.plates
        blocks = [np.vstack([plates.dofs, -np.ones_like(plates.dofs)])]
        for body in self.bodies:
            block = -np.ones((72, 1), dtype=int)
            block[:RIGID_DOFS, 0] = np.arange(body.first, body.first + RIGID_DOFS)
            blocks.append(block)
        for upper, lower in couplings:
            blocks.append(np.concatenate([plates.dofs[:, upper], plates.dofs[:, lower]])[:, None])
        dofs = np.hstack(blocks)
        self.full_pattern = kernel.SparsePattern(self.nfull, dofs)
        self.reduction = build_reduction(self.nfull, self.relations, self.e_full0,
                                         self.full_pattern)
        red = self.reduction
        self.ndof = red.matrix.shape[1]
        self.e0 = self.e_full0[red.independent].copy()
        self.pattern = red.pattern
        self.contact = contact
        # mass: plates on their pattern, bodies as dense 12 x 12 blocks; M_ii = B^T M B
        plate_mass = plates.mass_matrix().tocoo()
        mass = sp.coo_matrix((plate_mass.data, (plate_mass.row, plate_mass.col)),
                             shape=(self.nfull, self.nfull)).tocsr()
        for body, block in zip(self.bodies, self._body_mass):
            idx = np.arange(body.first, body.first + RIGID_DOFS)
            rows, cols = np.meshgrid(idx, idx, indexing="ij")
            mass = mass + sp.csr_matrix((block.ravel(), (rows.ravel(), cols.ravel())),
                                        shape=(self.nfull, self.nfull))
        self.mass_full = mass.tocsr()
        for body in self.bodies:  # every body's reference point is a probe
            self.probes.setdefault(body.name, BodyProbe(body))
        self._mass = (red.matrix.T @ self.mass_full @ red.matrix).tocsr()
        # orthonormality (eq. 30) as dot constraints on independent coordinates
        column = -np.ones(self.nfull, dtype=int)
        column[red.independent] = np.arange(self.ndof)
        for body, pairs in getattr(self, "_orthonormal_pairs", []):
            for p, q in pairs:
                a = [body.dof(p, c) for c in range(3)]
                b = [body.dof(q, c) for c in range(3)]
                for dof in a + b:
                    if column[dof] < 0 and red.offset[dof] != 0.0:
                        raise AssertionError("an orthonormality constraint touches a "
                                             "non-zero eliminated coordinate")
                dofs6 = [int(column[d]) for d in a + b]
                self.constraints._add(KIND_DOT, 0, dofs6, [1.0 if p == q else 0.0],
                                      dofs6[0], f"{body.name}: r_{'xyz'[p - 1]} . "
                                      f"r_{'xyz'[q - 1]} = {1 if p == q else 0}")

    # -- interface of the solvers (independent coordinates) ------------------------------
    def expand(self, x: np.ndarray, with_offset: bool = True) -> np.ndarray:
        return self.reduction.expand(x, with_offset)

    def mass_matrix(self) -> sp.csr_matrix:
        return self._mass.copy()

    def mass_values(self) -> np.ndarray:
        return self.pattern.values_of(self._mass)

    def internal_force(self, e: np.ndarray, t: float = 0.0, want_tangent: bool = False):
        if want_tangent:
            raise InputError("assemblies have no static analysis (use analysis = 'dynamic')")
        full = self.expand(e)
        force = np.zeros(self.nfull)
        force[:self.nplate], energy, _ = self.plates.internal_force(full[:self.nplate], t)
        return self.reduction.reduce(force), energy, None

    def constant_force(self) -> np.ndarray:
        return self.reduction.reduce(self._gravity)

    def external_force(self, e: np.ndarray, v: np.ndarray | None = None) -> np.ndarray:
        """Constant loads and, with contact, the contact forces at (e, v) (v = 0: at rest,
        as at the start of a run)."""
        force = self.constant_force()
        if self.contact is not None:
            contact, *_ = self.contact_forces(e, np.zeros(self.ndof) if v is None else v)
            force = force + contact
        return force

    def contact_forces(self, e: np.ndarray, v: np.ndarray):
        """Reduced contact force, records (6, npoints), penalty potential, powers."""
        c = self.contact
        out = kernel.contact_evaluate(self.expand(e), self.expand(v, False), self.plates.dofs,
                                      self.element_sizes(), c.grid, c.point_element,
                                      c.point_local, c.params, c.guesses.copy(),
                                      np.zeros(6, np.int32))
        return self.reduction.reduce(out["force"]), out["records"], out["potential"], \
            out["powers"]

    def element_sizes(self) -> np.ndarray:
        return np.vstack([self.mesh.a, self.mesh.b])

    def load_factor(self, t: float) -> float:
        kind, params = self.force_drive
        return float(kernel.drive_values(kind, params, np.array([t]))[0][0])

    def set_load_cycle(self, dof: int, amplitude: float, period: float) -> None:
        """A force amplitude (1 - cos(2 pi t / T))/2 on full coordinate ``dof`` (0 -> peak
        -> 0 over one period)."""
        self._load_pattern[dof] = 1.0
        self.drive_force = self.reduction.reduce(self._load_pattern)
        params = [amplitude, period, 0.0]
        self.force_drive = (3, params)
        self.force_drive_index = self.constraints.add_drive(3, params) - 1

    # -- output -------------------------------------------------------------------------
    def probe_positions(self, e: np.ndarray) -> dict[str, np.ndarray]:
        full = self.expand(e)
        return {name: full[probe.body.first:probe.body.first + 3] if isinstance(probe, BodyProbe)
                else self.plates.point_position(probe, full[:self.nplate])
                for name, probe in self.probes.items()}

    def deflections(self, e: np.ndarray) -> dict[str, np.ndarray]:
        initial = self.probe_positions(self.e0)
        return {name: p - initial[name] for name, p in self.probe_positions(e).items()}

    def deflections_at(self, e: np.ndarray, t: float) -> dict[str, np.ndarray]:
        return self.deflections(e)

    def node_positions(self, q: np.ndarray) -> np.ndarray:
        """Mesh node positions (nt, nnodes, 3) from reduced coordinates (nt, ndof)."""
        full = self.expand(q)
        return full[:, :self.nplate].reshape(len(q), self.mesh.nnodes, PLATE_NODE_DOFS)[:, :, :3]

    def summary(self) -> dict[str, int]:
        return {"ndof": self.ndof, "nfull": self.nfull, "nnodes": self.mesh.nnodes,
                "nelements": self.mesh.nel, "nbodies": len(self.bodies),
                "nconstraints": len(self.constraints),
                "nlinear_eliminated": len(self.relations),
                "ncontact_points": 0 if self.contact is None else len(self.contact.point_element)}

    def stepper_arrays(self) -> dict:
        arrays = self.plates.stepper_arrays()
        shapes, dofs, refs = [], [], []
        initial = self.probe_positions(self.e0)
        for name, probe in self.probes.items():
            if isinstance(probe, BodyProbe):
                shape = np.zeros(12)
                shape[0] = 1.0
                d = np.zeros(36, dtype=int)
                d[:3] = np.arange(probe.body.first, probe.body.first + 3)
            else:
                p = probe
                shape, _ = kernel.plate_shape(p.xi, p.eta, self.mesh.a[p.element],
                                              self.mesh.b[p.element])
                d = self.plates.dofs[:, p.element]
            shapes.append(shape)
            dofs.append(d + 1)
            refs.append(initial[name])
        f = np.asfortranarray
        arrays.update(
            e0_frame=f(self.e0),
            scatter_map=f(self.full_pattern.scatter_map[:36, :36, :self.plates.nel]),
            probe_dofs=f(np.array(dofs, dtype=np.int32).T),
            probe_shape=f(np.array(shapes).T),
            probe_reference=f(np.array(refs).reshape(-1, 3).T))
        return arrays
