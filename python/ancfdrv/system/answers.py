"""Engineering answers from a solved state (SPEC section 10): joint reactions by name,
section forces along beams and stresses at the sections' outer fibres or walls.

Reactions
    The constraint forces in the full coordinates q are Phi_q^T lambda (the constraints
    kept with multipliers; the solvers' convention M e'' + Q_int - Q - Phi_e^T lambda = 0
    makes Phi^T lambda the force the constraints apply) plus A^T mu for the linear joint
    equations A q = b that the assembly eliminated (q = B e + q0). Their multipliers mu are
    recovered from the residual of the equations of motion in the full coordinates,
    r = M q'' + Q_int(q, q') - Q(t) = Phi_q^T lambda + A^T mu, by least squares
    (A A^T) mu = A (r - Phi_q^T lambda): r - Phi_q^T lambda lies in the range of A^T
    because B^T (r - Phi_q^T lambda) = 0 is the solved (reduced) equation and B spans the
    null space of A. Each joint owns its equations' rows; its generalized force on body2's
    coordinates is reduced to a force (the sum over the position vectors r) and a moment
    about the joint's point p, M = sum (r_i - p) x Q_r,i + sum d_j x Q_d,j over the
    position vectors r_i and the direction vectors d_j (a rigid rotation delta theta moves
    every vector v by delta theta x v: the virtual work is delta theta . M). Global axes;
    what body1 exerts on body2 (as the user named them). A distance joint's ``axial`` is
    the tension: minus the force on body2 along p2 - p1.

Section forces
    At ``stations`` points per element (equally spaced, both ends included: a node appears
    twice, left then right). A static state's (:func:`static_section_forces`, what
    :func:`static_answers` returns) from each element's own equilibrium: exact where the
    loads are, N and Q jump at the nodes that carry a load, a joint or a force element
    (:func:`beam_equilibrium_forces`). A dynamic state's (:func:`section_forces`) is what
    the beam's element family reports through the kernel's element interface (its
    section_forces: ``fortran/src/elements/beam_stations.f90``), for all rows of a chunk in
    one call, from its own strain measures and the section's stiffness, relative to the
    reference configuration (an 'ffr' beam: their linear part in its frame): axial Green strain
    (r_x . r_x - 1)/2, bending strains b_y = -r_y,x . r_x (+ r_xx . r_y - mean(r_xx . r_y)
    with 'cubic' bending), b_z likewise with r_z, twist 1/2 (r_y,x . r_z - r_z,x . r_y)
    ('cubic'; the continuum element's (I_z r_y,x . r_z - I_y r_z,x . r_y) / I_p), shear
    gamma_y = r_x . r_y (nodal values interpolated linearly with 'cubic'). Sign convention:
    what the part of the beam beyond s (larger arc length) exerts on the part before it,
    on the section at s: N = E A eps (tension positive), T = G J twist, Q = k G A gamma
    along the section's height and width, M = (-E I_y b_z, E I_z b_y) along the height and
    width axes (the moment vector's components; a cantilever along x with a tip load P
    along +y has M_width = P (L - s) and Q_height = P).

Stresses
    sigma_x(y, z) = N / A - M_width y / I_z + M_height z / I_y at the section's outer
    fibre points (Section.fibre_points), the shear stress of torsion (rectangle:
    Saint-Venant, its maximum at the middle of the long sides from the series solution;
    box: Bredt T / (2 A_m t); tube and circle: T r / J) and of the shear forces
    (Jourawski: rectangle 3/2 Q / A (1 - (2y/h)^2), circle 4/3 Q / A (1 - (y/r)^2), tube and
    box the thin-walled shear flow), their magnitudes added (conservative), and von Mises
    sqrt(sigma^2 + 3 tau^2). ``sigma_x`` is the normal stress of largest magnitude over the
    fibres (signed), ``von_mises`` the largest von Mises stress.
"""
from __future__ import annotations

import weakref
from types import SimpleNamespace

import numpy as np

from ..records import record
from .. import kernel
from ..codes import CONSTRAINT_COORDINATE
from ..csr import sorted_unique
from ..gauss import leggauss
from .kinds import Beam
from .constraint_set import ConstraintSet
from .expressions import Scalar
from .joints import Constraint, LinearEquation
from .model import Model, SetInfo
from .registry import axial_forces, kind_of, reports_sections
from .sections import Box, Circle, Rectangle, Tube
from .._lazy import LazyModule

# imported on first use (ancfdrv._lazy): ~10 MB most runs never need; scipy.sparse (~19 MB)
# only for the eliminated joints' reactions
sp = LazyModule("scipy.sparse")
spla = LazyModule("scipy.sparse.linalg")

#: output.stations default: points per element where section forces are evaluated
DEFAULT_STATIONS = 3


@record(eq=False, repr=False)
class Reaction:
    """What body1 exerts on body2 at a joint (global axes, N and N m about ``point``)."""

    force: np.ndarray
    moment: np.ndarray
    point: np.ndarray
    axial: float | None = None   # distance joints: tension positive (N)


@record(eq=False, repr=False)
class SectionForces:
    """Section forces along a beam: arc length s (m), N, T, Q (ns, 2) and M (ns, 2)
    (components along the section's height and width axes); N, N m."""

    s: np.ndarray
    N: np.ndarray
    T: np.ndarray
    Q: np.ndarray
    M: np.ndarray


@record(eq=False, repr=False)
class Stress:
    """Stresses at the outer fibres along a beam (Pa): the signed normal stress of largest
    magnitude and the largest von Mises stress per station."""

    s: np.ndarray
    sigma_x: np.ndarray
    von_mises: np.ndarray


# -- reactions -------------------------------------------------------------------------------
class ReactionMap:
    """The data of a model's reactions, built once: the multiplier constraints in the full
    coordinates, the eliminated linear rows A with a factorization of A A^T, the joints'
    rows and the coordinates of their body2."""

    def __init__(self, model: Model) -> None:
        # the model keeps its map (reaction_map): the map refers to it weakly, so the two
        # make no reference cycle and a run's model is freed as soon as it is dropped (a
        # cycle left each run's objects to the garbage collector: ~0.15 ms per small run)
        self._model = weakref.ref(model)
        self.joints = getattr(model, "joint_items", {})
        owner = getattr(model, "equation_owner", {})
        equations = getattr(model, "full_equations", {})
        cs = model.constraints
        full = ConstraintSet(drive_kinds=cs.drive_kinds, drive_params=cs.drive_params)
        for c, name in enumerate(cs.names):
            eq = equations.get(name)
            if isinstance(eq, LinearEquation):
                # kept with a multiplier as the assembly keeps it (assembly._as_constraint)
                eq = Constraint(CONSTRAINT_COORDINATE, [Scalar(eq.expr.terms, 0.0)],
                                [-eq.expr.const], None, eq.name)
            if eq is None:  # not a joint's or body's equation: no force on the coordinates
                full.add(cs.kinds[c], [({}, 0.0)], cs.params[c], cs.drives[c], name)
                continue
            full.add(eq.kind, [(dict(op.terms), op.const) for op in eq.operands], eq.params,
                     cs.drives[c], name)
        self.full = full
        self.multiplier_owner = [owner.get(n) for n in cs.names]
        eliminated = getattr(model, "eliminated", [])
        self.linear_owner = [owner.get(eq.name) for eq in eliminated]
        self.factor = None
        # rows no joint owns (a planar reduction's fixes, system/planar.py) need no mu: their
        # force is on no joint, so without owned rows the residual is not formed at all
        if eliminated and any(o is not None for o in self.linear_owner):
            rows, cols, vals = [], [], []
            for i, eq in enumerate(eliminated):
                for d, a in eq.expr.terms.items():
                    rows.append(i)
                    cols.append(d)
                    vals.append(a)
            self.a = sp.csr_matrix((vals, (rows, cols)), shape=(len(eliminated), model.nfull))
            self.factor = spla.splu(sp.csc_matrix(self.a @ self.a.T))
            #: the full coordinates the eliminated rows touch: the residual is needed there
            #: alone (the kernel's rows carry it there: row_answers.f90)
            self.columns = sorted_unique(np.asarray(self.a.indices, dtype=np.int64))
            self.a_columns = sp.csr_matrix(self.a[:, self.columns])
        if self.factor is None:
            self.columns = np.zeros(0, dtype=np.int64)
        self.wanted = any(o is not None for o in self.multiplier_owner + self.linear_owner)
        self.a_coo = self.a.tocoo() if self.factor is not None else None
        self.points = {name: _joint_points(joint) for name, joint in self.joints.items()}

    @property
    def model(self) -> Model:
        """The model of these reactions (it holds the map; a map outlives it only when
        kept apart, and then has no model: ReferenceError)."""
        model = self._model()
        if model is None:
            raise ReferenceError("the model of this reaction map was released")
        return model

    def residual(self, e: np.ndarray, v: np.ndarray, a: np.ndarray | None, t: float,
                 load_factor: float, guesses: np.ndarray | None = None) -> np.ndarray:
        """r = M q'' + Q_int(q, q') - Q(t) in the full coordinates at the solvers' state
        (e, e', e''); ``guesses``: the contact points' projections at that state (default:
        the model's)."""
        m = self.model
        internal = m.kernel.full_forces(t, e, v, m.contact_guesses if guesses is None
                                        else guesses, load_factor=load_factor)
        constant, driven = m.full_loads
        external = constant.copy()
        for index, vector in driven:
            external += m.drives[index].value(t) * vector
        r = internal - load_factor * external
        if a is not None:
            r += self._mass_full() @ m.expand(a, with_offset=False)
        return r

    def _mass_full(self):
        """The full mass matrix for the residual's M q'': scipy's compiled product where the
        eliminated joints' factorization has imported scipy anyway (the residual is formed on
        every row there), else the model's numpy CSR; the two are bitwise equal."""
        if self.factor is None:
            return self.model.mass_full
        if not hasattr(self, "_mass_full_scipy"):
            self._mass_full_scipy = self.model.mass_full.to_scipy()
        return self._mass_full_scipy

    def _term_arrays(self) -> None:
        """Flat arrays of the multiplier constraints' terms (constraint, operand slot, dof,
        coefficient) and, per joint, which terms and eliminated-row entries fall on body2's
        coordinates (built once)."""
        con, slot, dof, coef = [], [], [], []
        for c, per in enumerate(self.full.terms):
            for k, terms in enumerate(per):
                for d, a in terms:
                    con.append(c)
                    slot.append(k)
                    dof.append(d)
                    coef.append(a)
        self.t_con, self.t_slot = np.array(con, dtype=np.int64), np.array(slot, dtype=np.int64)
        self.t_dof, self.t_coef = np.array(dof, dtype=np.int64), np.array(coef, dtype=float)
        owner_of_con = np.array([o or "" for o in self.multiplier_owner], dtype=object)
        owner_of_row = np.array([o or "" for o in self.linear_owner], dtype=object)
        self.selection = {}
        for name, joint in self.joints.items():
            first = joint.body2.first
            size = joint.body2.ncoordinates
            terms = np.flatnonzero((owner_of_con[self.t_con] == name) if len(self.t_con)
                                   else np.zeros(0, dtype=bool))
            terms = terms[(self.t_dof[terms] >= first) & (self.t_dof[terms] < first + size)]
            entries = np.zeros(0, dtype=np.int64)
            if self.a_coo is not None:
                entries = np.flatnonzero(owner_of_row[self.a_coo.row] == name)
                cols = self.a_coo.col[entries]
                entries = entries[(cols >= first) & (cols < first + size)]
            # the 3-vectors of body2 the joint's force acts on (the rest are exactly zero):
            # the force and moment sum over these only
            touched = self.t_dof[terms] - first
            if len(entries):
                touched = np.concatenate([touched, self.a_coo.col[entries] - first])
            slots = sorted_unique(touched // 3)
            self.selection[name] = (terms, entries, first, size, slots)

    def _layout_args(self) -> tuple:
        """The multiplier constraints' packed layout for the kernel's constraint calls
        (constraint_arrays and the count; built once)."""
        if not hasattr(self, "_args"):
            from ..kernel import _kernel, constraint_arrays
            full = self.full
            lay = full.layout()
            ptr = np.concatenate([[0], np.cumsum([len(p) for p in full.drive_params])]) + 1
            data = np.concatenate([np.asarray(p, dtype=float) for p in full.drive_params]) \
                if full.drive_params else np.zeros(1)
            kinds = np.array(full.drive_kinds or [0], dtype=np.int32)
            self._kernel = _kernel
            self._args = (*constraint_arrays(
                lay.kinds, lay.drives + 1, lay.params, lay.operand_const, lay.term_ptr + 1,
                lay.term_dof + 1 if len(lay.term_dof) else np.ones(1),
                lay.term_coef if len(lay.term_coef) else np.zeros(1), kinds,
                ptr if len(full.drive_kinds) else np.ones(2), data), len(lay.kinds))
        return self._args

    def _gradient_rows(self, q_rows: np.ndarray, times: np.ndarray) -> np.ndarray:
        """The multiplier constraints' operand gradients (6, ncon, nt) at every row of
        q_rows (nt, nfull) and times (nt,), in one kernel call (the gradients of
        ConstraintSet.evaluate's full evaluation, with no drive evaluated: they depend on
        none)."""
        args = self._layout_args()
        out = self._kernel.constraint_gradient_rows(
            *args, np.asfortranarray(np.asarray(q_rows, dtype=float).T),
            np.asarray(times, dtype=float))
        if out[-1]:
            raise ValueError(f"constraint evaluation failed (code {out[-1]})")
        return out[0]

    def constant_gradients(self) -> np.ndarray | None:
        """The operand gradients (6, ncon) when they are the same at every state: every
        multiplier constraint of the coordinate kind (x_1 - value), without a drive and
        with a coordinate in its first operand (what the kernel's evaluation checks), so
        that the kernel (constraints.f90: gradients(1, c) = 1 exactly) returns e_1 per
        constraint whatever q and t. None otherwise (the kernel evaluates every row)."""
        if not hasattr(self, "_constant_gradients"):
            full, constant = self.full, None
            if len(full) and all(
                    kind == CONSTRAINT_COORDINATE and drive < 0 and terms[0]
                    and all(0 <= d < self.model.nfull for per in terms for d, _ in per)
                    for kind, drive, terms in zip(full.kinds, full.drives, full.terms)):
                constant = np.zeros((6, len(full)))
                constant[0] = 1.0
            self._constant_gradients = constant
        return self._constant_gradients

    def generalized_rows(self, q_rows: np.ndarray, lam_rows: np.ndarray, times: np.ndarray,
                         residual_rows: np.ndarray | None) -> dict[str, np.ndarray]:
        """Each joint's constraint force on body2's coordinates, (nt, body2.ncoordinates),
        for rows of states; ``residual_rows`` (nt, len(columns)): the residual at
        :attr:`columns`."""
        if not hasattr(self, "selection"):
            self._term_arrays()
        nt = len(q_rows)
        nterm = len(self.t_coef)
        constant = self.constant_gradients() if len(self.full) and nterm else None
        if constant is not None:
            # the kernel's gradients without the kernel (the same values and products:
            # g * (coef * lambda), bitwise what the rows' evaluation gives)
            contrib = (self.t_coef * lam_rows[:, self.t_con]) * constant[self.t_slot,
                                                                         self.t_con]
        else:
            contrib = np.zeros((nt, nterm))
        if len(self.full) and nterm and constant is None:
            gradients = self._gradient_rows(q_rows, times)   # (6, ncon, nt): one kernel call
            contrib[:] = gradients[self.t_slot, self.t_con, :].T
            contrib *= self.t_coef * lam_rows[:, self.t_con]
        mu = None
        if self.factor is not None and residual_rows is not None:
            if not hasattr(self, "_scatter_columns"):
                # the terms on the columns, each added into its column's place
                place = np.searchsorted(self.columns, self.t_dof)
                place = np.minimum(place, max(len(self.columns) - 1, 0))
                on = self.columns[place] == self.t_dof if len(self.columns) else \
                    np.zeros(nterm, dtype=bool)
                self._scatter_columns = sp.csr_matrix(
                    (np.ones(int(on.sum())), (np.flatnonzero(on), place[on])),
                    shape=(nterm, len(self.columns)))
            total = (self._scatter_columns.T @ contrib.T).T
            rhs = self.a_columns @ (residual_rows - total).T
            mu = np.atleast_2d(self.factor.solve(rhs).T.reshape(nt, -1))
        out = {}
        for name, (terms, entries, first, size, slots) in self.selection.items():
            on_terms, on_entries = self._joint_scatter(name)
            vec = contrib[:, terms] @ on_terms
            if mu is not None and len(entries):
                a = self.a_coo
                vec = vec + (mu[:, a.row[entries]] * a.data[entries]) @ on_entries
            out[name] = (vec, slots)
        return out

    def _joint_scatter(self, name: str) -> tuple[np.ndarray, np.ndarray | None]:
        """The 0/1 matrices adding a joint's terms (and its eliminated-row entries) into
        the touched 3-vectors of its body2 (column 3 k + j: component j of slot k), made
        once per joint (the static state's and the dynamic rows' reactions share them)."""
        made = self.__dict__.setdefault("_scatters", {})
        if name not in made:
            terms, entries, first, size, slots = self.selection[name]
            compact = 3 * len(slots)

            def column(dofs: np.ndarray) -> np.ndarray:
                return 3 * np.searchsorted(slots, dofs // 3) + dofs % 3
            on_entries = None
            if self.a_coo is not None and len(entries):
                on_entries = _scatter(column(self.a_coo.col[entries] - first), compact)
            made[name] = (_scatter(column(self.t_dof[terms] - first), compact), on_entries)
        return made[name]

    def reaction_rows(self, q_rows: np.ndarray, lam_rows: np.ndarray, times: np.ndarray,
                      residual_rows: np.ndarray | None = None, *,
                      columns: np.ndarray | None = None) -> dict[str, tuple]:
        """Per joint (force (nt, 3), moment (nt, 3), point (nt, 3), axial (nt,) or None)
        for rows of full coordinates and multipliers. ``columns``: q_rows holds only the
        full coordinates :meth:`row_columns` names, in that order (column k of q_rows is
        coordinate columns[k])."""
        if columns is not None and self.row_columns() is None:
            raise ValueError("these reactions read every full coordinate (the kernel's "
                             "gradients): q_rows must hold them all")
        gen = self.generalized_rows(q_rows, lam_rows, times, residual_rows)
        place = None
        if columns is not None:
            place = np.full(self.model.nfull, -1, dtype=np.int64)
            place[columns] = np.arange(len(columns))
        return {name: _reduce_components(joint, *gen[name], q_rows, self.points[name], place)
                for name, joint in self.joints.items()}

    def row_columns(self) -> np.ndarray | None:
        """The full coordinates :meth:`reaction_rows` reads at each row (sorted): body2's
        3-vectors the joints' forces act on and the coordinates of the joints' points;
        None when the operand gradients come from the kernel at every row (it reads every
        coordinate). A reader that holds only reduced coordinates expands these alone
        (:meth:`~ancfdrv.system.patterns.Reduction.expand_columns`)."""
        if not hasattr(self, "selection"):
            self._term_arrays()
        if len(self.full) and len(self.t_coef) and self.constant_gradients() is None:
            return None
        if not hasattr(self, "_row_columns"):
            wanted = [np.zeros(0, dtype=np.int64)]
            for name, joint in self.joints.items():
                slots = self.selection[name][4]
                if _vector_blocks(joint.body2)[0] and len(slots):
                    wanted.append((joint.body2.first + 3 * slots[:, None]
                                   + np.arange(3)).ravel())
                for expr in self.points[name]:
                    if expr is not None:
                        wanted += [np.arange(d, d + 3) for d in expr.terms]
            self._row_columns = sorted_unique(np.concatenate(wanted).astype(np.int64))
        return self._row_columns

    def reactions(self, q_full: np.ndarray, lam: np.ndarray, t: float = 0.0,
                  residual: np.ndarray | None = None) -> dict[str, Reaction]:
        """The reactions of one state (full coordinates, multipliers, time; ``residual``:
        the residual at :attr:`columns`, needed with eliminated joints)."""
        rows = self.reaction_rows(q_full[None], np.asarray(lam, dtype=float)[None],
                                  np.array([t]), None if residual is None else residual[None])
        return {name: Reaction(f[0], m[0], p[0], None if a is None else float(a[0]))
                for name, (f, m, p, a) in rows.items()}


def _scatter(index: np.ndarray, size: int) -> np.ndarray:
    """(len(index), size) 0/1 matrix adding entry k into column index[k]."""
    out = np.zeros((len(index), size))
    out[np.arange(len(index)), index] = 1.0
    return out


def _vector_blocks(body) -> tuple[int, int]:
    """(coordinates per node, number of nodes) of a body's coordinates; the first vector
    of each node is its position."""
    nodes = body.nnodes   # (a rigid body: one node of 12; the ground: none)
    return (body.ncoordinates // nodes, nodes) if nodes else (0, 0)


def _joint_points(joint) -> tuple:
    """The joint's point on body2 (and for a distance joint point1 on body1) as
    expressions in the full coordinates."""
    where = f"joint {joint.name!r}"
    body = joint.body2
    point = joint.point2 if joint.type == "distance" else joint.points[0]
    p2 = body.position(body.locate(point, node=False, what=where))
    p1 = None
    if joint.type == "distance":
        p1 = joint.body1.position(joint.body1.locate(joint.point1, node=False, what=where))
    return p2, p1


def _vec_components(expr, q_rows: np.ndarray, place: np.ndarray | None = None) -> np.ndarray:
    """A Vec3 expression at rows of coordinates, component-major: (3, nt). ``place``: the
    column of q_rows holding each full coordinate (None: q_rows holds them all, in
    order)."""
    out = np.empty((3, len(q_rows)))
    out[:] = expr.const[:, None]
    columns = q_rows.T
    for d, c in expr.terms.items():
        k = d if place is None else int(place[d])
        out += c * columns[k:k + 3]
    return out


def _reduce_components(joint, generalized: np.ndarray, slots: np.ndarray,
                       q_rows: np.ndarray, points: tuple, place: np.ndarray | None = None):
    """Force and moment about the joint's point of the generalized forces on body2 (nt
    rows; on the 3-vectors ``slots`` of body2's coordinates, column 3 k + j component j of
    slots[k]: every other vector carries no force), the point and a distance joint's axial
    force (tension positive). ``place``: as for :func:`_vec_components`. The arrays are
    component-major ((3, slots, nt)), so each numpy operation runs over rows of nt values.
    Returns (nt, 3) views."""
    body = joint.body2
    per, nodes = _vector_blocks(body)
    p2, p1 = points
    point = _vec_components(p2, q_rows, place)
    nt = len(q_rows)
    if per and len(slots):
        ns = len(slots)
        block = np.ascontiguousarray(generalized.T).reshape(ns, 3, nt).transpose(1, 0, 2)
        index = (body.first + 3 * slots[:, None] + np.arange(3)).ravel()
        if place is not None:
            index = place[index]
        values = q_rows.T[index].reshape(ns, 3, nt).transpose(1, 0, 2)
        position = slots % (per // 3) == 0          # a node's first vector: its position
        if position.all():
            on_block, on_values = block, values
        else:
            on_block, on_values = block[:, position], values[:, position]
        force = on_block.sum(axis=1)
        arm = on_values - point[:, None, :]
        moment = _cross_components(arm, on_block).sum(axis=1)
        if position.all():   # no other vector: the sum over none, +0.0 each
            moment += 0.0
        else:
            moment += _cross_components(values[:, ~position], block[:, ~position]).sum(axis=1)
    else:
        force, moment = np.zeros((3, nt)), np.zeros((3, nt))
    swapped = getattr(joint, "swapped", False)
    if swapped:
        force, moment = -force, -moment
    axial = None
    rows = point.T
    if p1 is not None:
        rows = np.ascontiguousarray(rows)
        u = rows - np.ascontiguousarray(_vec_components(p1, q_rows, place).T)
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        f = np.ascontiguousarray(force.T)
        axial = np.einsum("ti,ti->t", f if swapped else -f, u)
    return force.T, moment.T, rows, axial


def _cross_components(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b along the first axis (component-major arrays of one shape)."""
    out = np.empty(a.shape, dtype=np.result_type(a, b))
    np.subtract(a[1] * b[2], a[2] * b[1], out=out[0])
    np.subtract(a[2] * b[0], a[0] * b[2], out=out[1])
    np.subtract(a[0] * b[1], a[1] * b[0], out=out[2])
    return out


def reaction_map(model: Model) -> ReactionMap:
    """The model's reaction data (built once, kept on the model)."""
    cached = getattr(model, "_reaction_map", None)
    if cached is None:
        cached = ReactionMap(model)
        model._reaction_map = cached
    return cached


def reactions(model: Model, e: np.ndarray, lam: np.ndarray, *, t: float = 0.0,
              v: np.ndarray | None = None, a: np.ndarray | None = None,
              load_factor: float | None = None) -> dict[str, Reaction]:
    """Reactions of every joint by name at the solved state (e: the solvers' coordinates,
    lam: the multipliers; for a dynamic state its velocities v and accelerations a = e'').
    Static states need neither v nor a."""
    rm = reaction_map(model)
    q = model.expand(e)
    residual = None
    if rm.factor is not None:
        lf = 1.0 if load_factor is None else load_factor
        v = np.zeros(model.ndof) if v is None else v
        residual = rm.residual(np.asarray(e, dtype=float), v, a, t, lf)[rm.columns]
    out = rm.reactions(q, np.asarray(lam, dtype=float), t, residual)
    out.update(force_element_reactions(model, e, v, t))
    return out


def force_element_reactions(model: Model, e: np.ndarray, v: np.ndarray | None = None,
                            t: float = 0.0) -> dict[str, Reaction]:
    """Per force element (``ancfdrv.system.kinds.force_element``) the force and moment body1
    exerts on body2 (global axes; the moment about the element's point on body2) and the
    axial force (tension positive; 0 for a bushing) at (e, e', t), from the kernel."""
    items = list(getattr(model, "force_elements", ()))
    if not items:
        return {}
    v = np.zeros(model.ndof) if v is None else np.asarray(v, dtype=float)
    rows = model.kernel.force_element_reactions(float(t), np.asarray(e, dtype=float), v)
    q = model.expand(e)
    return {info.name: Reaction(rows[0:3, i].copy(), rows[3:6, i].copy(),
                                info.slots[1].value(q), float(rows[6, i]))
            for i, info in enumerate(items)}


# -- section forces --------------------------------------------------------------------------
def _stations(beam: Beam, stations: int) -> tuple[np.ndarray, np.ndarray]:
    """The stations' places xi in every element (both ends included) and their arc lengths
    s (nel * stations,)."""
    if stations < 2:
        raise ValueError("stations must be at least 2 (both ends of each element)")
    xi = np.linspace(0.0, 1.0, stations)
    return xi, (beam.stations[:-1, None] + np.outer(beam.lengths, xi)).ravel()


def beam_section_forces(model: Model, info: SetInfo, e_rows: np.ndarray, times: np.ndarray,
                        stations: int = DEFAULT_STATIONS) -> SectionForces:
    """Section forces of one beam (its element set ``info``) at ``stations`` points per
    element for the states e_rows (nt, ndof) at the times (nt,) (where an 'ffr' beam's
    frame is), each array with a leading time axis: what the beam's element family
    reports from its own strain measures and the section's stiffness (the kernel's
    element_sets section_forces, ``fortran/src/elements/beam_stations.f90``; the module
    documentation gives the measures and the sign convention), all rows in one call."""
    return _section_rows(model, info, e_rows, times, stations)[0]


def _section_rows(model: Model, info: SetInfo, e_rows: np.ndarray, times: np.ndarray,
                  stations: int) -> tuple[SectionForces, np.ndarray]:
    """:func:`beam_section_forces` and each force's largest magnitude over the rows (6, ns)
    [N, T, Q_height, Q_width, M_height, M_width] (the kernel's, for :func:`peak_rows`)."""
    xi, s = _stations(info.body, stations)
    f, largest = model.kernel.section_forces(info.index, times, e_rows, xi)
    # Q and M (nt, ns, 2) as views of the kernel's array (its components' planes), not copies
    return SectionForces(s=s, N=f[0], T=f[1], Q=np.moveaxis(f[2:4], 0, -1),
                         M=np.moveaxis(f[4:6], 0, -1)), largest


def section_forces(model: Model, e: np.ndarray, stations: int = DEFAULT_STATIONS, *,
                   t: float | np.ndarray = 0.0) -> dict[str, SectionForces]:
    """Section forces of every beam of the model by name at the state e (time t: where an
    'ffr' beam's frame is); e may hold rows of states (nt, ndof) at the times t (nt,):
    the arrays then have a leading time axis."""
    e = np.asarray(e, dtype=float)
    rows = np.atleast_2d(e)
    times = np.broadcast_to(np.asarray(t, dtype=float), (len(rows),))
    out = {}
    for info in model.sets:
        if reports_sections(info.body):
            f = beam_section_forces(model, info, rows, times, stations)
            if e.ndim == 1:
                f = SectionForces(f.s, f.N[0], f.T[0], f.Q[0], f.M[0])
            out[info.body.name] = f
    return out


def _centreline(xi: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """(nel, n, 8) coefficients of the centre line r(xi) on each element's eight nodal
    vectors (cubic Hermite on r1, r1_x, r2, r2_x; ``lengths`` (nel,))."""
    z = np.zeros_like(xi)
    shape = np.stack([1 - 3 * xi**2 + 2 * xi**3, xi - 2 * xi**2 + xi**3, z, z,
                      3 * xi**2 - 2 * xi**3, xi**3 - xi**2, z, z], axis=-1)
    slope_scale = np.ones((len(lengths), 1, 8))
    slope_scale[:, 0, [1, 5]] = np.asarray(lengths)[:, None]
    return shape[None] * slope_scale


def beam_equilibrium_forces(model: Model, info: SetInfo, q: np.ndarray, gravity: np.ndarray,
                            stations: int = DEFAULT_STATIONS, t: float = 0.0) -> SectionForces:
    """Section forces of one beam at a static state from each element's own equilibrium
    (SPEC section 10), at ``stations`` points per element with both ends: at an element's
    end the part of the structure beyond it exerts on the element its elastic force there
    less its share of the element's distributed load (gravity), f_e - g_e, on the end's
    four nodal vectors, reduced to a force F and a moment M = sum v x F_v about the end's
    centre-line point (the virtual work of a rigid turn of the end's directors and slope);
    at the start the same with the sign turned (what the element exerts on the part
    before it). Between the ends the distributed load p is integrated from the start:
    F(s) = F(A) - p (s - s_A), M(s) = M(A) + (r_A - r(s)) x F(A) - int_A^s (r - r(s)) x p.
    The two elements at a node give its two sides (left, then right): they differ by the
    load, joint or force element the node carries, and agree elsewhere. N, T are the
    components along the section normal n = r_y x r_z, Q and M along the section's height
    (r_y) and width (n x r_y) axes; sign convention as :func:`beam_section_forces`. An
    'ffr' beam is in equilibrium on its reference geometry in the frame (small strain),
    unless it has geometric stiffness: then, like the large-deformation beams, on its
    current one. Loads and joints between nodes act through the element's nodal shares."""
    beam = info.body
    if stations < 2:
        raise ValueError("stations must be at least 2 (both ends of each element)")
    nel = info.nel
    rotation = model.frames[info.frame - 1].rotation(t) if info.frame else np.eye(3)
    force, vectors = kind_of(beam).end_forces(info, q, rotation)
    mass_rule, density = beam.section.mass_rule(beam.material.density)
    load = np.moveaxis(np.asarray(kernel.beam_gravity(beam.lengths, mass_rule, density,
                                                      gravity)), -1, 0)
    load = np.swapaxes(load, 1, 2)                                     # (nel, 8, 3)
    ends = force - load
    # at the start (right side of node A) and the end (left side of node B)
    f_a = -ends[:, 0]
    m_a = -np.cross(vectors[:, 1:4], ends[:, 1:4]).sum(axis=1)
    f_b = ends[:, 4]
    m_b = np.cross(vectors[:, 5:8], ends[:, 5:8]).sum(axis=1)
    lengths = np.asarray(beam.lengths, dtype=float)
    per_length = (load[:, 0] + load[:, 4]) / lengths[:, None]          # p (nel, 3)
    xi = np.linspace(0.0, 1.0, stations)
    points, weights = leggauss(3)   # exact: r(x) is cubic
    r_s = _centreline(xi, lengths) @ vectors                          # (nel, nxi, 3)
    # int_0^xi r dx per station: Gauss on [0, xi]
    nodes = (0.5 * xi[:, None] * (points[None, :] + 1.0)).ravel()
    r_gauss = (_centreline(nodes, lengths) @ vectors).reshape(nel, stations, len(points), 3)
    r_int = (0.5 * np.outer(lengths, xi))[:, :, None] * np.einsum("q,epqk->epk", weights,
                                                                     r_gauss)
    run = np.outer(lengths, xi)[:, :, None]                            # (nel, nxi, 1)
    force_s = f_a[:, None] - run * per_length[:, None]
    moment_s = (m_a[:, None] + np.cross(vectors[:, None, 0] - r_s, f_a[:, None])
                - np.cross(r_int - run * r_s, per_length[:, None]))
    force_s[:, -1], moment_s[:, -1] = f_b, m_b   # the end from its own forces (the same
    #                                               up to round-off where the loads are gravity)
    dir_y = (1 - xi)[None, :, None] * vectors[:, None, 2] + xi[None, :, None] * vectors[:, None, 6]
    dir_z = (1 - xi)[None, :, None] * vectors[:, None, 3] + xi[None, :, None] * vectors[:, None, 7]
    normal = np.cross(dir_y, dir_z)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    height = dir_y / np.linalg.norm(dir_y, axis=-1, keepdims=True)
    width = np.cross(normal, height)

    def along(x: np.ndarray, axis: np.ndarray) -> np.ndarray:
        return (x * axis).sum(axis=-1).reshape(-1)
    ns = nel * stations
    return SectionForces(
        s=(beam.stations[:-1, None] + np.outer(lengths, xi)).ravel(),
        N=along(force_s, normal), T=along(moment_s, normal),
        Q=np.stack([along(force_s, height), along(force_s, width)], axis=-1).reshape(ns, 2),
        M=np.stack([along(moment_s, height), along(moment_s, width)], axis=-1).reshape(ns, 2))


def static_section_forces(model: Model, e: np.ndarray, stations: int = DEFAULT_STATIONS,
                          load_factor: float = 1.0) -> dict[str, SectionForces]:
    """Section forces of every beam by name at a static state e (the solved equilibrium
    of the scene's loads scaled by ``load_factor``) from the elements' equilibrium
    (:func:`beam_equilibrium_forces`): exact where the loads are, with both sides of every
    node. :func:`section_forces` (the strains times the section's stiffness) serves the
    states that are not in static equilibrium (the rows of a dynamic run)."""
    q = model.expand(np.asarray(e, dtype=float))
    gravity = load_factor * np.asarray(model.gravity, dtype=float)
    return {info.body.name: beam_equilibrium_forces(model, info, q, gravity, stations)
            for info in model.sets if getattr(kind_of(info.body), "end_forces", None)}


# -- stresses --------------------------------------------------------------------------------
def _rectangle_torsion(long: float, short: float) -> tuple[float, float]:
    """Saint-Venant torsion of a solid rectangle (Timoshenko & Goodier, Theory of
    Elasticity, sec. 109): J = beta a b^3 (a the long, b the short side) and k in the
    largest shear stress tau = T b k / J, at the middle of the long sides (square:
    beta = 0.1406, k = 0.675, tau = T / (0.208 a^3))."""
    ratio = long / short
    n = np.arange(1, 60, 2, dtype=float)
    beta = (1.0 - 192.0 / np.pi**5 / ratio * np.sum(np.tanh(n * np.pi * ratio / 2) / n**5)) / 3
    with np.errstate(over="ignore"):
        k = 1.0 - 8.0 / np.pi**2 * np.sum(1.0 / (n**2 * np.cosh(n * np.pi * ratio / 2)))
    return beta * long * short**3, k


def fibre_stresses(section, forces: SectionForces) -> tuple[np.ndarray, np.ndarray]:
    """(sigma_x, tau) at the section's fibre points for every station: (..., ns, npoints)."""
    data = section.data
    points = _outline_points(section)
    y, z = points[:, 0], points[:, 1]
    n, t = forces.N[..., None], forces.T[..., None]
    q_h, q_w = forces.Q[..., 0:1], forces.Q[..., 1:2]
    m_h, m_w = forces.M[..., 0:1], forces.M[..., 1:2]
    sigma = n / data.area - m_w * y / data.inertia_z + m_h * z / data.inertia_y
    half_y, half_z = section.extent
    if isinstance(section, Rectangle):
        long, short = max(section.height, section.width), min(section.height, section.width)
        j_sv, k_long = _rectangle_torsion(long, short)
        tau_max = np.abs(t) * short * k_long / j_sv
        # along each side parabolic from zero at the corners to the largest value in its
        # middle (on the short sides an overestimate: conservative)
        on_y_side = np.isclose(np.abs(y), half_y)     # top and bottom (along the width)
        u = np.where(on_y_side, z / half_z, y / half_y)
        tau_t = tau_max * (1.0 - u**2)
        tau_q = 1.5 * (np.abs(q_h) * (1 - (y / half_y) ** 2)
                       + np.abs(q_w) * (1 - (z / half_z) ** 2)) / data.area
    elif isinstance(section, Box):
        wall = section.wall
        h_m, w_m = section.height - wall, section.width - wall
        tau_t = np.abs(t) / (2.0 * h_m * w_m * wall) * np.ones_like(y)
        tau_q = (np.abs(q_h) * _box_flow(y, z, h_m, w_m, wall, data.inertia_z)
                 + np.abs(q_w) * _box_flow(z, y, w_m, h_m, wall, data.inertia_y)) / wall
    elif isinstance(section, (Tube, Circle)):
        r_o = 0.5 * section.diameter
        r_i = r_o - section.wall if isinstance(section, Tube) else 0.0
        tau_t = np.abs(t) * r_o / section.torsion_constant * np.ones_like(y)
        first = 2.0 / 3.0 * (r_o**3 - r_i**3)        # first moment of half the section
        peak = first / (data.inertia_z * 2.0 * (r_o - r_i))   # tau at the neutral axis per Q
        tau_q = peak * (np.abs(q_h) * (1 - (y / r_o) ** 2) + np.abs(q_w) * (1 - (z / r_o) ** 2))
    else:  # a general section: torsion T r / J at the fibre's distance, mean shear
        r = np.hypot(y, z)
        tau_t = np.abs(t) * r / section.torsion_constant
        tau_q = (np.abs(q_h) + np.abs(q_w)) / data.area * np.ones_like(y)
    return sigma, tau_t + tau_q


def _outline_points(section) -> np.ndarray:
    """(n, 2) points (y along the height, z along the width; m) where the stresses are
    evaluated: a rectangle's or box's outline (corners, quarters and middles of the edges:
    torsion and shear peak in the middles, bending at the corners), 48 points around a
    circle or tube, else the section's own fibre points (a general section's)."""
    half_y, half_z = section.extent
    if isinstance(section, (Tube, Circle)):
        angle = np.linspace(0.0, 2.0 * np.pi, 48, endpoint=False)
        return np.column_stack([half_y * np.cos(angle), half_y * np.sin(angle)])
    if isinstance(section, (Rectangle, Box)):
        edge = np.linspace(-1.0, 1.0, 5)
        ones = np.ones_like(edge)
        outline = np.vstack([np.column_stack([half_y * ones, half_z * edge]),
                             np.column_stack([-half_y * ones, half_z * edge]),
                             np.column_stack([half_y * edge, half_z * ones]),
                             np.column_stack([half_y * edge, -half_z * ones])])
        return np.unique(outline, axis=0)
    return np.asarray(section.fibre_points(), dtype=float)


def _box_flow(y, z, h_m, w_m, wall, inertia) -> np.ndarray:
    """Shear flow per unit shear force (1/m) of a thin-walled box under a shear force
    along y (midline height h_m, width w_m): zero in the middle of the flanges, growing
    linearly to the corners and parabolically down the webs; at an outline point (y, z)."""
    on_flange = np.abs(np.abs(y) - (h_m + wall) / 2) < 1e-12 + 1e-9 * h_m
    zz = np.minimum(np.abs(z), w_m / 2)
    yy = np.minimum(np.abs(y), h_m / 2)
    flange = wall * (h_m / 2) * zz / inertia
    corner = wall * h_m * w_m / 4 / inertia
    web = corner + wall * (h_m**2 / 4 - yy**2) / 2 / inertia
    return np.where(on_flange, flange, web)


def beam_stress(section, forces: SectionForces) -> Stress:
    """Stresses along a beam from its section forces."""
    sigma, tau = fibre_stresses(section, forces)
    worst = np.argmax(np.abs(sigma), axis=-1)[..., None]
    return Stress(s=forces.s, sigma_x=np.take_along_axis(sigma, worst, axis=-1)[..., 0],
                  von_mises=np.sqrt(sigma**2 + 3.0 * tau**2).max(axis=-1))


#: fibre values per block of rows in :func:`von_mises_peak` (temporaries of ~1 MB)
STRESS_BLOCK = 131072


def von_mises_peak(section, forces: SectionForces) -> np.ndarray:
    """The largest von Mises stress over the fibre points at every station (..., ns):
    ``beam_stress(section, forces).von_mises`` without sigma_x's worst fibre, the square
    root taken after the maximum (it is monotonic and correctly rounded: bitwise the same
    values) and the sums in place; rows of a time axis in blocks of ~32,000 fibre values,
    whose temporaries stay in the cache (the dynamic envelope's cost: every value is
    computed by the same operations as :func:`beam_stress`'s)."""
    n_fibres = len(_outline_points(section))
    if forces.N.ndim < 2:
        return _von_mises_block(section, forces)
    per_row = max(1, forces.N[0].size * n_fibres)
    block = max(1, STRESS_BLOCK // per_row)
    out = np.empty(forces.N.shape)
    for a in range(0, len(forces.N), block):
        b = a + block
        out[a:b] = _von_mises_block(section, SectionForces(
            s=forces.s, N=forces.N[a:b], T=forces.T[a:b], Q=forces.Q[a:b], M=forces.M[a:b]))
    return out


def _von_mises_block(section, forces: SectionForces) -> np.ndarray:
    sigma, tau = fibre_stresses(section, forces)
    np.square(sigma, out=sigma)
    np.square(tau, out=tau)
    tau *= 3.0
    sigma += tau
    return np.sqrt(sigma.max(axis=-1))


def _stress_bounds(section) -> tuple[np.ndarray, np.ndarray]:
    """(normal, shear): per-unit coefficients with |sigma| <= normal . |(N, M_width,
    M_height)| and tau <= shear . |(T, Q_height, Q_width)| at every fibre point of
    :func:`fibre_stresses` (sigma is linear in N and the moments, tau linear in |T| and the
    |Q| with coefficients >= 0 for every section kind): the largest magnitude of each
    force's stress per unit force over the fibres, so von Mises <= sqrt(bound)."""
    cache = section.__dict__.setdefault("_stress_bounds", None) \
        if hasattr(section, "__dict__") else None
    if cache is not None:
        return cache
    unit = np.eye(6)
    forces = SectionForces(s=np.zeros(6), N=unit[0], T=unit[1],
                           Q=np.column_stack([unit[2], unit[3]]),
                           M=np.column_stack([unit[4], unit[5]]))
    sigma, tau = fibre_stresses(section, forces)          # (6 unit cases, npoints)
    normal = np.abs(sigma).max(axis=-1)[[0, 5, 4]]         # N, M_width, M_height
    shear = np.abs(tau).max(axis=-1)[[1, 2, 3]]            # T, Q_height, Q_width
    found = (normal, shear)
    if hasattr(section, "__dict__"):
        section.__dict__["_stress_bounds"] = found
    return found


#: the bound's safety margin against rounding (it and the stresses are computed apart)
BOUND_MARGIN = 1e-9


def peak_rows(section, forces: SectionForces, floor: np.ndarray | None = None,
              largest: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(row, peak) per station of rows of section forces (nt, ns): the first row of the
    largest von Mises stress and that stress, as ``argmax`` of :func:`von_mises_peak`
    gives them (every value computed by the same operations: bitwise the same), without
    evaluating the fibres of rows that cannot hold the peak: a bound from
    :func:`_stress_bounds` (a few operations per row and station, against 16 fibres)
    skips every row below the stress found at the row of the largest bound, or below
    ``floor`` (ns,) (the envelope of earlier rows: a station whose rows all stay below it
    may return any row with peak <= floor, -inf when a bound over all rows, from each
    force's largest magnitude, lies below the floor). ``largest`` (6, ns): those largest
    magnitudes [N, T, Q_height, Q_width, M_height, M_width] when the caller has them (the
    kernel's, with the section forces); found here otherwise."""
    nt, ns = forces.N.shape
    normal, shear = _stress_bounds(section)
    if floor is not None and nt > 1:
        # the block's bound per station from each force's largest magnitude over the rows
        # (reductions, no temporaries): stations that stay below the floor are done
        if largest is None:
            largest = np.array([np.maximum(x.max(axis=0), -x.min(axis=0)) for x in (
                forces.N, forces.T, forces.Q[..., 0], forces.Q[..., 1], forces.M[..., 0],
                forces.M[..., 1])])
        top_sig = (largest[0] * normal[0] + largest[5] * normal[1] + largest[4] * normal[2])
        top_tau = (largest[1] * shear[0] + largest[2] * shear[1] + largest[3] * shear[2])
        live = ~(np.sqrt(top_sig**2 + 3.0 * top_tau**2) * (1.0 + BOUND_MARGIN) < floor)
        if not live.all():
            row, peak = np.zeros(ns, dtype=np.int64), np.full(ns, -np.inf)
            if live.any():
                row[live], peak[live] = peak_rows(section, SectionForces(
                    s=forces.s[live], N=forces.N[:, live], T=forces.T[:, live],
                    Q=forces.Q[:, live], M=forces.M[:, live]), floor[live], largest[:, live])
            return row, peak
    sig = np.abs(forces.N) * normal[0]
    sig += np.abs(forces.M[..., 1]) * normal[1]
    sig += np.abs(forces.M[..., 0]) * normal[2]
    tau = np.abs(forces.T) * shear[0]
    tau += np.abs(forces.Q[..., 0]) * shear[1]
    tau += np.abs(forces.Q[..., 1]) * shear[2]
    np.square(sig, out=sig)
    np.square(tau, out=tau)
    tau *= 3.0
    sig += tau
    bound = np.sqrt(sig, out=sig)
    bound *= 1.0 + BOUND_MARGIN
    if not np.isfinite(bound).all():   # not a number somewhere: every fibre, as before
        vm = von_mises_peak(section, forces)
        row = np.argmax(vm, axis=0)
        return row, vm[row, np.arange(ns)]
    stations = np.arange(ns)

    def exact(rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        return _von_mises_block(section, SectionForces(
            s=forces.s, N=forces.N[rows, cols], T=forces.T[rows, cols],
            Q=forces.Q[rows, cols], M=forces.M[rows, cols]))
    top = np.argmax(bound, axis=0)
    found = exact(top, stations)                 # a lower bound of each station's peak
    level = found if floor is None else np.maximum(found, floor)
    cols, rows = np.nonzero((bound >= level).T)  # by station, rows ascending
    row, peak = top.copy(), found.copy()
    if len(rows):
        values = exact(rows, cols)
        starts = np.flatnonzero(np.r_[True, cols[1:] != cols[:-1]])
        best = np.maximum.reduceat(values, starts)
        owner = cols[starts]
        hit = values == np.repeat(best, np.diff(np.r_[starts, len(cols)]))
        first = np.flatnonzero(hit)
        station_of_first, at = np.unique(cols[first], return_index=True)
        row[station_of_first] = rows[first[at]]
        peak[owner] = best
    return row, peak


def stresses(model: Model, forces: dict[str, SectionForces]) -> dict[str, Stress]:
    """Stresses of every beam by name from its section forces."""
    beams = {b.name: b for b in model.bodies if reports_sections(b)}
    return {name: beam_stress(beams[name].section, f) for name, f in forces.items()}


@record(eq=False)
class Answers:
    """Everything SPEC section 10 asks of one state, by name."""

    reactions: dict[str, Reaction]
    sections: dict[str, SectionForces]
    stress: dict[str, Stress]


def static_answers(model: Model, e: np.ndarray, lam: np.ndarray,
                   stations: int = DEFAULT_STATIONS, load_factor: float = 1.0) -> Answers:
    """Reactions, section forces and stresses of a static state (e, lambda) of the loads
    scaled by ``load_factor``: what the result writers store under /static and the results
    object exposes."""
    forces = static_section_forces(model, e, stations, load_factor)
    return Answers(reactions(model, e, lam), forces, stresses(model, forces))


def constraint_joints(model: Model) -> list[str]:
    """The joint each multiplier (row of lambda) belongs to ('' for a body's own
    constraints: a rigid body's orthonormality, a planar guide)."""
    owner = getattr(model, "equation_owner", {})
    return [owner.get(name, "") for name in model.constraints.names]


def answer_inputs(model: Model) -> tuple[np.ndarray, object, np.ndarray, np.ndarray]:
    """What the kernel's rows need to answer (``Kernel.answer_setup``,
    ``fortran/src/solvers/row_answers.f90``): the full coordinates the eliminated joints'
    rows touch (:attr:`ReactionMap.columns`; none without eliminated joints a joint owns),
    the full mass's rows there (scipy CSR), the constant loads (gravity included) and the
    driven loads there (one column per driven load, in the order of the model's)."""
    columns = reaction_map(model).columns
    constant, driven = model.full_loads
    mass_rows = model.mass_full.to_scipy()[columns] if len(columns) else \
        sp.csr_matrix((0, model.nfull))
    loads = np.column_stack([vector[columns] for _, vector in driven]) if driven else \
        np.zeros((len(columns), 0))
    return columns, mass_rows, np.asarray(constant, dtype=float)[columns], loads


class DynamicAnswers:
    """Reactions, section forces, the stress envelope and the cables' (ropes') tension of a
    dynamic run, from the chunks
    of the stepper (a sink: ``recorder(chunk)``; the chunks carry q and, when the model has
    force elements or eliminated joints, the rows' answers: a run with
    ``DynamicSettings.answers``). The kernel writes each row's force-element reactions and
    the residual of the equations of motion at the eliminated joints' coordinates from the
    state it reached (``fortran/src/solvers/row_answers.f90``); the joints' reactions, the
    beams' section forces and the cables' axial forces (their kind's law,
    ``Kind.axial_forces``) are formed over all rows of a chunk at once."""

    def __init__(self, model: Model, *, stations: int = DEFAULT_STATIONS,
                 keep_sections: bool = False) -> None:
        self.model, self.stations, self.keep_sections = model, stations, keep_sections
        self.map = reaction_map(model)
        #: the eliminated joints' reactions need the residual at the rows (the rows' answers)
        self.need_residual = self.map.factor is not None
        #: the times of the chunks recorded (arrays; :attr:`time` joins them)
        self._time_blocks: list[np.ndarray] = []
        #: per joint, per chunk: (force (nt, 3), moment (nt, 3), axial (nt,) or None)
        self.reactions: dict[str, list[tuple]] = {name: [] for name in self.map.joints}
        #: force elements: their reactions are the rows' answers' first 7 values each
        self.force_elements = list(getattr(model, "force_elements", ()))
        for info in self.force_elements:
            self.reactions[info.name] = []
        self.sections: dict[str, list[SectionForces]] = {}
        self.envelope: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self.beams = {b.name: b for b in model.bodies if reports_sections(b)}
        #: the beams' element sets (their section forces: the kernel's, per chunk)
        self.section_sets = [info for info in model.sets if reports_sections(info.body)]
        #: the bodies whose kind carries an axial force (cables, ropes: ``Kind.axial_forces``)
        self._axial = {b.name: (b, law) for b in model.bodies
                       if (law := axial_forces(b)) is not None}
        #: per cable, per chunk: the smallest and the largest axial force along it (N,
        #: tension positive) at each row, (nt,) each
        self.tension: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {
            name: [] for name in self._axial}

    @property
    def needs_answers(self) -> bool:
        """Whether the chunks must carry the rows' answers (``DynamicSettings.answers``)."""
        return self.need_residual or bool(self.force_elements)

    @property
    def time(self) -> list[float]:
        """The times (s) of the rows recorded, in order."""
        return [t for block in self._time_blocks for t in block.tolist()]

    #: a chunk of 2 to WAIT_ROWS rows (the stepper's first call, which measures a step's
    #: cost: 10 steps) waits and is recorded with the next chunk; so does the initial row
    #: (a single row before anything is recorded), joined with a next chunk that would wait
    #: itself: the initial row, the first call and the rest are one pass over the rows
    #: instead of three (a pass costs ~0.1-0.3 ms on a tiny system). Single rows after it
    #: (the intervals of adaptive steps) do not wait, and the initial row followed by a
    #: single row is recorded on its own as before: rows grouped otherwise are not always
    #: bitwise the same (the adaptive boom's stresses batched 17 rows at a time moved by
    #: 7e-14). :meth:`complete` records a chunk still waiting.
    WAIT_ROWS = 16

    _waiting = None

    def complete(self) -> None:
        """Record the chunk still waiting (:data:`WAIT_ROWS`): before the answers are read."""
        waiting, self._waiting = self._waiting, None
        if waiting is not None:
            self._record(waiting)

    def __call__(self, chunk) -> None:
        """Record a chunk of rows (bounded by the kernel's row buffer: dynamic.py
        ``call_rows``); a short chunk waits for the next one (:data:`WAIT_ROWS`)."""
        if chunk.q is None:
            raise ValueError("DynamicAnswers needs the coordinates of every step (store_q)")
        answers = getattr(chunk, "answers", None) if self.needs_answers else None
        if self.needs_answers and answers is None:
            raise ValueError("DynamicAnswers needs the rows' answers (DynamicSettings.answers)")
        rows = len(chunk.time)
        if self._waiting is not None:
            held, self._waiting = self._waiting, None
            if rows == 1 and len(held.time) == 1:   # the initial row, then a single row
                self._record(held)
                self._record(chunk)
                return
            chunk = SimpleNamespace(
                time=np.concatenate([held.time, chunk.time]),
                q=np.concatenate([held.q, chunk.q]), lam=np.concatenate([held.lam, chunk.lam]),
                answers=None if answers is None else np.concatenate([held.answers, answers]))
            if len(held.time) == 1 and 1 < rows and len(chunk.time) <= self.WAIT_ROWS:
                self._waiting = chunk   # the initial row and a short chunk: new arrays
                return
        elif (1 < rows or (rows == 1 and not self._time_blocks)) and rows <= self.WAIT_ROWS:
            self._waiting = SimpleNamespace(   # copies: the chunk's arrays may be reused
                time=np.array(chunk.time), q=np.array(chunk.q), lam=np.array(chunk.lam),
                answers=None if answers is None else np.array(answers))
            return
        self._record(chunk)

    def _record(self, chunk) -> None:
        """Record a chunk's rows: the reactions from the rows' states and answers, the beams'
        section forces in one kernel call per beam."""
        times = np.asarray(chunk.time, dtype=float)
        if not len(times):
            return
        e_rows = np.asarray(chunk.q, dtype=float)
        answers = getattr(chunk, "answers", None) if self.needs_answers else None
        if answers is not None and not np.all(np.isfinite(answers)):
            raise ValueError("the kernel could not evaluate the forces of a row's reactions")
        nfel = len(self.force_elements)
        for i, info in enumerate(self.force_elements):
            values = answers[:, 7 * i:7 * i + 7]
            self.reactions[info.name].append((values[:, 0:3].copy(), values[:, 3:6].copy(),
                                              values[:, 6].copy()))
        full = None   # every row expanded to the full coordinates (made once, when needed)
        if self.map.joints:
            # read only: without eliminated joints q is e (no copy of every row); with them,
            # when the reactions need no kernel gradients, only the full coordinates they
            # read (the same values: the expansion's own operations on those columns)
            columns = None
            if self.model.reduction is None:
                q_rows = e_rows
            elif (columns := self.map.row_columns()) is not None:
                q_rows = self.model.reduction.expand_columns(e_rows, columns)
            else:
                q_rows = full = self.model.expand(e_rows)
            residual = answers[:, 7 * nfel:] if self.need_residual else None
            found = self.map.reaction_rows(q_rows, np.asarray(chunk.lam, dtype=float), times,
                                           residual, columns=columns)
            for name, (force, moment, _, axial) in found.items():
                self.reactions[name].append((force, moment, axial))
        self._time_blocks.append(np.array(times))   # (a list of floats made on request)
        if self._axial:
            self._record_tension(e_rows, full)
        for info in self.section_sets:
            self._record_sections(info.body.name, *_section_rows(
                self.model, info, e_rows, times, self.stations), times)

    #: the most bytes of full coordinates the cables' tension is formed from at once: a
    #: chunk's rows (up to dynamic.ROW_BUFFER_BYTES of reduced rows) in blocks, since the
    #: law's temporaries are several times its input (a cable's gathered element
    #: coordinates twice, its strains, r' at a Gauss point: 4.5 MB of the 512-element
    #: cantilever's peak). Each row's values are its own: the same in any block.
    TENSION_BLOCK_BYTES = 1 << 17

    def _record_tension(self, e_rows: np.ndarray, full: np.ndarray | None) -> None:
        """The smallest and largest axial force along every cable at each row of e_rows
        (independent coordinates; ``full``: their full coordinates when the reactions
        expanded them already, else None), formed a block of rows at a time."""
        nt = len(e_rows)
        step = max(1, self.TENSION_BLOCK_BYTES // (8 * self.model.nfull))
        lows = {name: np.empty(nt) for name in self._axial}
        highs = {name: np.empty(nt) for name in self._axial}
        for first in range(0, nt, step):
            block = e_rows[first:first + step]
            if full is not None:
                block = full[first:first + step]
            elif self.model.reduction is not None:
                block = self.model.expand(block)
            for name, (body, law) in self._axial.items():
                forces = law(body, block)
                forces.min(axis=1, out=lows[name][first:first + step])
                forces.max(axis=1, out=highs[name][first:first + step])
        for name in self._axial:
            self.tension[name].append((lows[name], highs[name]))

    def _record_sections(self, name: str, f: SectionForces, largest: np.ndarray,
                         times: np.ndarray) -> None:
        """Keep a block's section forces (output.sections) and lift the envelope
        (``largest``: each force's largest magnitude over the block's rows, (6, ns))."""
        if self.keep_sections:
            self.sections.setdefault(name, []).append(f)
        floor = self.envelope[name][1] if name in self.envelope else None
        row, peak = peak_rows(self.beams[name].section, f, floor, largest)   # (ns,) each
        if name not in self.envelope:
            self.envelope[name] = (f.s, peak.copy(), times[row].copy())
        else:
            _, best, when = self.envelope[name]
            higher = peak > best
            best[higher] = peak[higher]
            when[higher] = times[row][higher]


__all__ = ["Answers", "static_answers", "Reaction", "SectionForces", "Stress", "reactions",
           "section_forces", "static_section_forces", "beam_equilibrium_forces", "force_element_reactions",
           "beam_section_forces", "stresses", "beam_stress", "fibre_stresses", "reaction_map",
           "DEFAULT_STATIONS", "answer_inputs",
           "DynamicAnswers", "constraint_joints"]
