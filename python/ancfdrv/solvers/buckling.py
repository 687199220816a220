"""Buckling about the scene's static state (SPEC section 10, docs/theory.md "Buckling").

The loads are split into fixed loads F (kept at their value, e.g. gravity; flagged in the
model by System.assemble's ``fixed_loads``, so the kernel's load factor leaves them alone)
and the reference loads R (the others); the structure carries F + P R, P the load factor,
and every static state on the path is the kernel's static Newton's (:class:`LoadPath`: by
load control; :class:`_ArcSteps`: by arc length, the load factor an unknown). Both
methods start from the scene's own static state, P = 1 (solved as the scene's static
solve does, :func:`~.static.solve_newton`), never from P = 0: a rope that hangs a payload,
a mechanism held by its loads or a cylinder's preload has no stiffness without its loads.
With K_T(P) the tangent of the linearized equations at the static state under F + P R
(:func:`~.modal.linearize`: elastic tangent with its initial-stress part, the dead moments'
and follower loads' load stiffness and the constraint Hessians times the multipliers):

* 'linear': K_g = (K_T(1 + s) - K_T(1)) / s (s = ``reference_factor``, default 1), with
  every load-proportional term of that difference taken at the scene's configuration
  (:func:`stress_correction`: the beams' and cables' initial-stress stiffness of the exact
  stress increment, the force elements' force increment times their measures' Hessians,
  the loads' and joints' parts with the increment's loads and multipliers), and

      (K_1 + nu K_g) phi = 0  on  G_1 phi = 0,    K_1 = K_T(1),    P = 1 + nu  (nu > 0);

  the classical linear buckling about the static state: exact where K_T is affine in P
  (small pre-buckling deformation). Reported only where the static path carries 0.98 of
  the first factor stably, so never above the model's limit by more than 2 %
  (:func:`_check_linear`: 'confirmed', or 'conservative' where the limit lies above).
* 'nonlinear': the lowest omega^2 of (K_T(P), M) on the constraints' null space of each
  state, followed along the static path from P = 1 by arc length (the kernel's
  Crisfield step, as static_method = 'arc_length') until it changes sign: at a limit point
  of the load (P passes a maximum along the arc, a snap-through) or at a bifurcation (P
  still rises); the zero is then located on the arc by regula falsi to rtol: the
  stability limit of the model, pre-buckling deformation included. Further factors: the
  classical linear buckling about a state below that limit.

Directions with no stiffness at the static state (a mechanism's free motion, a rigid body's
free rotation) are not buckling: both methods work on the constrained coordinates where
K_1 is positive definite (the null space of G with K_1's zero-stiffness directions
removed); a negative stiffness there means the scene's own state is unstable (refused).
Solved densely (eigh on the reduced matrices) up to :data:`DENSE_LIMIT` free coordinates,
else by ARPACK on the multiplier form with [[K_1, G^T], [G, 0]] factorized once by MUMPS
(no zero-stiffness direction allowed there). Only factors above 1 are buckling (a factor
below 1 belongs to unloading, e.g. a pendulum that loses its gravity stiffness); attribute
``negative_load_factor`` gives the smallest reversed-load factor.
"""
from __future__ import annotations

import time
from dataclasses import field

import numpy as np

from ..records import record
from ..errors import InputError, SolverError
from ..io.schema import check_keywords
from .. import kernel
from ..kernel import DirectSolver
from ..system.model import Model
from ..system.kinds.force_element import evaluate, slot_values
from ..system.registry import kind_of
from .modal import DENSE_LIMIT as MODAL_DENSE_LIMIT
from .modal import arpack_start, check_free, linearize, null_space
from .static import ARC_STEP, LOAD_TANGENT, StaticResult, kernel_static, solve_newton
from .._lazy import LazyModule

# imported on first use (ancfdrv._lazy): ~10 MB most runs never need; scipy.sparse (~19 MB
# with its import chain) too: a dynamic run imports this module but never solves here
sp = LazyModule("scipy.sparse")
la = LazyModule("scipy.linalg")
spla = LazyModule("scipy.sparse.linalg")

#: free coordinates up to which the eigenproblems are solved densely (a 600 x 600 eigh takes
#: some 0.1 s; the dense form removes zero-stiffness directions, the sparse one cannot)
DENSE_LIMIT = 600
#: eigenvalues of K_1 on the constrained coordinates below this fraction of the largest in
#: size are zero-stiffness directions (mechanisms, free rotations), not structure
ZERO_STIFFNESS = 1e-11


@record
class BucklingResult:
    """The lowest positive load factors and their mode shapes (plain record; HDF5:
    /buckling). ``shapes`` (N, ndof) in the solver coordinates, scaled to a largest
    displacement component of 1; ``full_shapes`` in the full coordinates."""

    load_factor: np.ndarray
    shapes: np.ndarray
    method: str
    fixed_loads: tuple[str, ...] = ()
    full_shapes: np.ndarray | None = None
    base: StaticResult | None = None        # state 0 (fixed loads)
    reference: StaticResult | None = None   # state 1 (fixed + reference loads)
    wall_time_s: float = 0.0
    timing: dict[str, float] = field(default_factory=dict)
    extra: dict[str, object] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.load_factor)


def elastic_basis(k1: sp.spmatrix, g: sp.spmatrix) -> np.ndarray:
    """An orthonormal basis of the constrained coordinates (the null space of G) without the
    directions in which K_1 has no stiffness (eigenvalues of N^T K_1 N below
    :data:`ZERO_STIFFNESS` times the largest in size): a mechanism's or a free body's
    motion, which no load factor buckles. SolverError when K_1 has a negative stiffness
    there (the scene's own static state is unstable)."""
    n = k1.shape[0]
    basis = null_space(g, n)
    reduced = basis.T @ (k1 @ basis)
    w, v = la.eigh(0.5 * (reduced + reduced.T))
    floor = ZERO_STIFFNESS * max(np.abs(w).max(initial=0.0), 1e-300)
    if np.any(w < -floor):
        raise SolverError(
            f"buckling: the scene's static state is unstable ({int(np.sum(w < -floor))} "
            "negative eigenvalue(s) of the tangent on the constrained coordinates): it "
            "buckles under the scene's own loads; lower them (or run the static path with "
            "solver.static_method = 'arc_length' to see where it loses stability)")
    keep = w > floor
    if not keep.any():
        raise SolverError("buckling: the structure has no stiffness at its static state "
                          "(every constrained direction is a free motion)")
    return basis @ v[:, keep]


def stress_correction(model: Model, state1: tuple[np.ndarray, np.ndarray, float],
                      state2: tuple[np.ndarray, np.ndarray, float], scale: float
                      ) -> sp.csr_matrix:
    """What turns the difference of tangents (K_T(state2) - K_T(state1)) / scale (states
    (e, lambda, load factor) on the static path) into the geometric stiffness of classical
    linear buckling about state1: every load-proportional term of the tangent with its
    stress, force, multiplier or load scaled by the increment and its configuration held at
    state1, on the solver coordinates (B^T K B where reduced). Term by term:

    * element sets whose kind splits its tangent (K_T = K_material(q) + K_sigma(stress):
      the large-deformation beams, the cables and ropes): K_sigma((q2 - q1) / scale) -
      (K_set(q2) - K_set(q1)) / scale. The difference of a set's tangents also holds the
      change of its material stiffness by the displacement (the initial-displacement
      matrix), first order in the load like K_sigma and large where stiff section or shear
      moduli turn with the sections (docs/theory.md section 23). The stress increment is the
      exact one, (S(q2) - S(q1)) / scale: the kinds' strains are quadratic in q and their
      stresses linear in the strains, so the strain's derivative at the middle state
      (q1 + q2) / 2 along dq is the exact difference. Taken at q1 it would add the strain of
      the increment's own rotation, (dq . C dq) scale / 2: a section that turns by 0.075 rad
      between the states reads ~3e-3 of spurious strain, which took the crane boom's
      (inputs/crane_boom_modes.nml) classical factor to 1.006 where it is 5.98.
    * force elements (a cylinder, a spring, a bushing, a torsion spring): their measures'
      force increment times the measures' Hessians at state1 (for a line (f2 - f1) (I - n
      n^T) / L on its attachment points, kernel.force_element_initial_stress), in place of
      their tangents' difference, which holds the turn of the line's material stiffness
      k n n^T (the knuckle crane's classical factor: 170.4 with it, 297.7 without).
    * the dead moments' and driven or follower point loads' Jacobians and the constraints'
      Hessians times the multipliers: at state1's configuration with state2's loads and
      multipliers (the loads are linear in the load factor, the joints' reactions scale
      with it), in place of the same at state2's configuration.

    Other sets (plates, rigid bodies, contact) keep their tangents' difference."""
    (e1, lam1, factor1), (e2, lam2, factor2) = state1, state2
    q1, q2 = model.expand(e1), model.expand(e2)
    dq = (q2 - q1) / scale
    middle = 0.5 * (q1 + q2)
    rows, cols, vals = [], [], []
    for info in model.sets:
        split = kind_of(info.body).stress_stiffness
        first = split(info, q1, dq) if split is not None else None
        if first is None:
            continue
        tangent1 = first[0]
        stress = split(info, middle, dq)[1]
        tangent2 = split(info, q2, dq)[0]
        local = stress - (tangent2 - tangent1) / scale
        for el in range(info.nel):
            dofs = info.dofs[:, el]
            rows.append(np.repeat(dofs, len(dofs)))
            cols.append(np.tile(dofs, len(dofs)))
            vals.append(local[:, :, el].ravel())
    for info in model.force_elements:
        length = model.drives[info.drive].value(0.0) if info.drive >= 0 else 0.0
        x1, x2 = slot_values(info, q1), slot_values(info, q2)
        still = np.zeros_like(x1)
        geometric = [kernel.force_element_initial_stress(
            info.kind, info.params, info.table_kind, info.table, x, still, x1, length)
            for x in (x1, x2)]
        tangents = [evaluate(info, x, length=length)["stiffness"] for x in (x1, x2)]
        local = ((geometric[1] - geometric[0]) - (tangents[1] - tangents[0])) / scale
        ns = local.shape[1]
        local = local.reshape(3 * ns, 3 * ns, order="F")
        # slot s's point is sum c q[d:d + 3]: d x_s / d q[d + i] = c e_i
        where = [(3 * s + i, d + i, c) for s, slot in enumerate(info.slots)
                 for d, c in slot.terms.items() for i in range(3)]
        at = np.array([w[0] for w in where], dtype=np.int64)
        dofs = np.array([w[1] for w in where], dtype=np.int64)
        coef = np.array([w[2] for w in where])
        rows.append(np.repeat(dofs, len(dofs)))
        cols.append(np.tile(dofs, len(dofs)))
        vals.append((coef[:, None] * coef[None, :] * local[np.ix_(at, at)]).ravel())
    if rows:
        full = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                     np.concatenate(cols))),
                             shape=(model.nfull, model.nfull))
        if model.reduction is not None:
            b = model.reduction.matrix.to_scipy()
            full = b.T @ full @ b
    else:
        full = sp.csr_matrix((model.ndof, model.ndof))
    # loads and joints: [X(e1, lambda2, P2) - X(e2, lambda2, P2)] / scale, X their part of
    # the tangent (stiffness_triplets without the elements' tangent)
    return (full + (_loads_and_joints(model, e1, lam2, factor2) -
                    _loads_and_joints(model, e2, lam2, factor2)) / scale).tocsr()


def _loads_and_joints(model: Model, e: np.ndarray, lam: np.ndarray, factor: float
                      ) -> sp.csr_matrix:
    """The loads' and joints' part of the tangent at (e, lambda, load factor): the static
    Newton matrix's stiffness block without the elements' tangent."""
    n = model.ndof
    rows, cols, vals = model.stiffness_triplets(e, lam, 0.0, factor,
                                                np.zeros(model.pattern.nnz))
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


def _dense(basis: np.ndarray, k1: sp.spmatrix, kg: sp.spmatrix):
    a = basis.T @ (k1 @ basis)
    b = basis.T @ (kg @ basis)
    a, b = 0.5 * (a + a.T), 0.5 * (b + b.T)
    theta, y = la.eigh(-b, a)
    return theta, basis @ y


def _sparse(k0: sp.spmatrix, kg: sp.spmatrix, g: sp.spmatrix, count: int, tol: float):
    n, ncon = k0.shape[0], g.shape[0]
    aug = sp.bmat([[k0, g.T], [g, None]], format="coo")
    solver = DirectSolver.by_cost(n + ncon, aug.row, aug.col,
                                  what="buckling matrix [[K_0, G^T], [G, 0]]")
    try:
        solver.factorize(aug.data)

        def matvec(x):
            y = np.zeros(n + ncon)
            y[:n] = -(kg @ x[:n])
            return solver.solve(y)
        op = spla.LinearOperator((n + ncon, n + ncon), matvec=matvec, dtype=float)
        k = min(count + 4, n + ncon - 2)
        theta, z = spla.eigs(op, k=k, which="LR", tol=tol, **arpack_start(matvec, n + ncon, 1))
    except spla.ArpackNoConvergence as exc:
        raise SolverError(f"buckling: ARPACK did not converge ({exc})") from None
    finally:
        solver.close()
    keep = np.abs(theta.imag) <= 1e-8 * np.abs(theta).max(initial=1.0)
    return theta[keep].real, z[:n, keep].real


class LoadPath:
    """Static states under F + P R (the fixed loads F flagged in the model, System.assemble's
    ``fixed_loads``; the reference loads R; the load factor P) by the kernel's static Newton
    (:func:`~.static.kernel_static`, the scene's static solve's) with continuation from the
    last state. The kernel applies the load factor to the reference loads alone, so its
    residual, the tangent of :func:`~.modal.linearize` (the fixed dead moments' and follower
    loads' load stiffness at their value) and the load vector hold F at its value."""

    def __init__(self, model: Model, *, tol: float, max_iter: int, load_steps: int) -> None:
        self.model = model
        self.tol, self.max_iter, self.load_steps = tol, max_iter, load_steps
        self.e = model.e0.copy()
        self.lam = np.zeros(len(model.constraints))
        self.factor = 0.0
        self.solves = 0

    def tangent(self) -> sp.csr_matrix:
        return self.matrices()[0]

    def constraints(self) -> sp.csr_matrix:
        return self.matrices()[1]

    def matrices(self, state: tuple[np.ndarray, np.ndarray, float] | None = None
                 ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """The tangent and the constraints' Jacobian at the current state, or at ``state``
        (e, lambda, load factor) of the path."""
        e, lam, factor = (self.e, self.lam, self.factor) if state is None else state
        lin = linearize(self.model, e, lam, load_factor=factor)
        return lin.stiffness.tocsr(), lin.constraints

    def solve(self, factor: float, max_iter: int | None = None) -> None:
        """Move the state to the load factor ``factor`` (in load_steps increments), each
        in at most ``max_iter`` Newton iterations of the kernel (default: the path's)."""
        start = self.factor
        max_iter = self.max_iter if max_iter is None else max_iter
        for step in range(1, self.load_steps + 1):
            target = start + (factor - start) * step / self.load_steps
            out = kernel_static(self.model, self.e, self.lam, target, tol=self.tol,
                                max_iter=max_iter)
            if out["info"]:
                raise SolverError(f"buckling: no static state found at load factor "
                                  f"{target:.6g} ({out['message']}); raise "
                                  "buckling.load_steps")
            self.e, self.lam, self.factor = out["e"], out["lam"], target
            self.solves += 1


def _pencil(basis: np.ndarray | None, k1: sp.spmatrix, kg: sp.spmatrix, g: sp.spmatrix,
            count: int, eigen_tol: float):
    if basis is not None:
        return _dense(basis, k1, kg)
    return _sparse(k1, kg, g, count, eigen_tol)


def _lowest(k: sp.spmatrix, m: sp.spmatrix, g: sp.spmatrix, method: str,
            count: int = 1, basis: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The ``count`` lowest omega^2 of (K, M) on the null space of G (or on ``basis``, dense)
    and their vectors (columns): the softest modes' stiffness, which reaches 0 where the
    static state loses stability."""
    n, ncon = k.shape[0], g.shape[0]
    if method == "dense":
        basis = null_space(g, n) if basis is None else basis
        kr, mr = basis.T @ (k @ basis), basis.T @ (m @ basis)
        count = min(count, kr.shape[0])
        w, y = la.eigh(0.5 * (kr + kr.T), 0.5 * (mr + mr.T), subset_by_index=[0, count - 1])
        return w, basis @ y
    scale = np.abs(k.diagonal()).max() / np.abs(m.diagonal()).max()
    sigma = -1e-8 * scale
    aug = sp.bmat([[k, g.T], [g, None]], format="csr")
    b = sp.bmat([[m, None], [None, sp.csr_matrix((ncon, ncon))]], format="csr")
    shifted = (aug - sigma * b).tocoo()
    solver = DirectSolver.by_cost(n + ncon, shifted.row, shifted.col,
                                  what="buckling softest modes")
    try:
        solver.factorize(shifted.data)
        op = spla.LinearOperator((n + ncon, n + ncon), matvec=solver.solve, dtype=float)
        w, z = spla.eigsh(aug, k=count, M=b, sigma=sigma, OPinv=op, which="LM",
                          **arpack_start(lambda r: solver.solve(b @ r), n + ncon, 1))
    finally:
        solver.close()
    order = np.argsort(w)
    return w[order], z[:n, order]


def negative_eigenvalues(model: Model, e: np.ndarray, lam: np.ndarray, factor: float) -> int:
    """The number of negative eigenvalues of the tangent at (e, lambda, P) on the
    constraints' null space (the stability index; exact for models up to the modal
    DENSE_LIMIT free coordinates; else among the lowest eight)."""
    lin = linearize(model, e, lam, load_factor=factor)
    return stability_index(model, lin.stiffness, lin.constraints)


def stability_index(model: Model, k: sp.spmatrix, g: sp.spmatrix) -> int:
    """:func:`negative_eigenvalues` of a tangent ``k`` and constraints' Jacobian ``g``
    already linearized."""
    free = model.ndof - g.shape[0]
    if free <= MODAL_DENSE_LIMIT:
        basis = null_space(g, model.ndof)
        reduced = basis.T @ (k @ basis)
        w = la.eigvalsh(0.5 * (reduced + reduced.T))
    else:
        w, _ = _lowest(k, model.mass_matrix(), g, "sparse", min(8, free - 1))
        w = np.asarray(w)
    scale = max(np.abs(k.diagonal()).max(initial=0.0), 1e-300) if free > MODAL_DENSE_LIMIT \
        else max(np.abs(w).max(initial=0.0), 1e-300)
    return int(np.sum(w < -1e-10 * scale))


def _advance(path: "LoadPath", factor: float, tries: int = 6) -> None:
    """Move the path to ``factor``; when Newton fails there, halve the step from the last
    converged state (up to ``tries`` times)."""
    last = (path.e.copy(), path.lam.copy(), path.factor)
    for attempt in range(tries + 1):
        try:
            path.solve(factor)
            return
        except SolverError:
            if attempt == tries:
                raise
            path.e, path.lam, path.factor = last[0].copy(), last[1].copy(), last[2]
            factor = last[2] + 0.5 * (factor - last[2])


def _root(history: list[tuple[float, float]]) -> float | None:
    """The load factor where omega^2(P) = w0 (1 - a x - b x^2), x = P - P0, fitted through
    the first state (P0, w0) and the last two (one: linear), vanishes; None while the
    stiffness does not decrease with the load (no limit in sight)."""
    p0, w0 = history[0]
    p2, w2 = history[-1]
    if w0 <= 0 or w2 >= w0 * (1 - 1e-9):
        return None
    x2 = p2 - p0
    if len(history) < 3:
        return p0 + x2 / (1 - w2 / w0)
    p1, w1 = history[-2]
    x1 = p1 - p0
    try:
        a, b = np.linalg.solve(np.array([[x1, x1**2], [x2, x2**2]]), [1 - w1 / w0, 1 - w2 / w0])
    except np.linalg.LinAlgError:
        return p0 + x2 / (1 - w2 / w0)
    if abs(b) <= 1e-14 * abs(a) * max(x1, x2):
        return p0 + 1.0 / a if a > 0 else None
    disc = a * a + 4 * b
    roots = [(-a + sg * np.sqrt(disc)) / (2 * b) for sg in (1.0, -1.0)] if disc >= 0 else []
    roots = [r for r in roots if r > 0]
    return float(p0 + min(roots, key=lambda r: abs(r - x2))) if roots else None


def _follow_basis(basis: np.ndarray | None, g1: sp.spmatrix, g: sp.spmatrix
                  ) -> np.ndarray | None:
    """The elastic basis of the scene's state (:func:`elastic_basis`) carried to a state
    whose constraints' Jacobian is ``g``: projected on its null space and orthonormalized.
    Joints that turn with the structure (a welded corner of a frame) turn their null space;
    the scene's basis would no longer satisfy the constraints there and would hide the
    direction in which the tangent becomes singular at a limit point. Constraints that do
    not turn (``g`` equal to the scene's ``g1``) keep it."""
    if basis is None or g.shape[0] == 0 or abs(g - g1).max() == 0:
        return basis
    nullity = null_space(g, basis.shape[0])
    if nullity.shape[1] == basis.shape[1]:   # no zero-stiffness direction was removed
        return nullity
    q, _ = np.linalg.qr(nullity.T @ basis)
    return nullity @ q


#: Newton iterations of an arc-length step of the 'nonlinear' path before its arc is halved:
#: a step with an equilibrium at its arc converges in a few
STEP_ITERATIONS = 15
#: halvings of the arc from one point of the 'nonlinear' path before the path is given up
MAX_CUTS = 12
#: secant steps on the arc that locate the zero of the lowest stiffness
MAX_LOCATE = 40


@record
class _Point:
    """A converged point of the 'nonlinear' path: its state, the lowest omega^2 of its
    tangent on the constraints' null space and their vectors (columns), and the increment
    of e that reached it (the path's direction there; None at the scene's state)."""

    e: np.ndarray
    lam: np.ndarray
    factor: float
    w: np.ndarray
    vectors: np.ndarray
    increment: np.ndarray | None = None


class _ArcSteps:
    """Points of the static path at a given arc length ||Delta e|| from a converged point,
    by the kernel's arc-length step (:data:`~.static.ARC_STEP`: Crisfield's cylindrical
    method, the load factor an unknown; forward by Feng's criterion with the point's
    increment, up the loads from the scene's state), each with its lowest stiffness."""

    def __init__(self, path: LoadPath, mass: sp.spmatrix, how: str, track: int,
                 basis: np.ndarray | None, g: sp.spmatrix) -> None:
        self.path, self.mass, self.how, self.track = path, mass, how, track
        self.basis, self.g = basis, g

    def point(self, e: np.ndarray, lam: np.ndarray, factor: float,
              increment: np.ndarray | None = None) -> _Point:
        k, g_t = self.path.matrices((e, lam, factor))
        w, vectors = _lowest(k, self.mass, g_t, self.how, self.track,
                             _follow_basis(self.basis, self.g, g_t))
        return _Point(e, lam, factor, w, vectors, increment)

    def step(self, start: _Point, arc: float) -> _Point | None:
        """The point at ``arc`` from ``start``; None where Newton does not converge."""
        path = self.path
        out = kernel_static(path.model, start.e, start.lam, start.factor, tol=path.tol,
                            max_iter=min(path.max_iter, STEP_ITERATIONS), mode=ARC_STEP,
                            arc=arc, direction=1.0, previous=start.increment)
        path.solves += 1
        if out["info"]:
            return None
        return self.point(out["e"], out["lam"], float(out["load_factor"]), out["e"] - start.e)


def _follow_to_limit(steps: _ArcSteps, first: _Point, reference_factor: float, rtol: float,
                     max_updates: int, max_factor: float
                     ) -> tuple[float, _Point, list[tuple[float, np.ndarray]],
                                dict[float, tuple[np.ndarray, np.ndarray]]]:
    """Follow the static path by arc length from the scene's state ``first`` (P = 1) until
    the lowest stiffness omega^2 on the constraints' null space reaches zero: at a limit
    point of the load (P passes a maximum along the arc; past it the tangent has a negative
    eigenvalue) or at a bifurcation (P still rises, the stability index changes). The first
    arc moves P by about ``reference_factor`` along the tangent; the next ones aim at 0.9
    of the way to the zero of the stiffness fitted through the states (:func:`_root`),
    at most twice the last increment of P (four times P while the stiffness does not fall).
    A step that ends with omega^2 <= 0 brackets the zero on the arc, which
    :func:`_locate_on_arc` finds. Returns the critical factor, the stable point nearest to
    it, and the states (P, omega^2) and (P -> (e, lambda)) of the stable points passed."""
    path = steps.path
    tangent = kernel_static(path.model, first.e, first.lam, first.factor, tol=1.0,
                            max_iter=1, mode=LOAD_TANGENT)
    if tangent["info"]:
        raise SolverError("buckling: the tangent along the loads at the scene's static state "
                          f"cannot be solved ({tangent['message'].split('; ')[0]})")
    if not tangent["tangent_norm"] > 0:
        raise SolverError("buckling: the reference loads (those not in buckling.fixed_loads) "
                          "move nothing at the scene's static state: none is left or they are "
                          "zero; leave the loads the factor multiplies out of fixed_loads")
    arc = reference_factor * tangent["tangent_norm"]
    history = [(first.factor, first.w)]
    saved = {first.factor: (first.e.copy(), first.lam.copy())}
    point, cuts, w0 = first, 0, first.w[0]
    while True:
        trial = steps.step(point, arc)
        # a stable point below the last: the arc jumped past a limit onto a far branch
        retry = trial is None or (trial.factor <= point.factor and trial.w[0] > 0)
        # a rise after a fall that stopped well above zero (near the limit omega^2 ~ 0 is
        # round-off and may rise by noise): a long step may have passed over a limit
        fell_and_rises = (not retry and len(history) >= 2 and
                          1e-3 * w0 < point.w[0] < 0.99 * w0 and
                          point.w[0] < trial.w[0] and trial.factor > point.factor)
        if fell_and_rises and trial.factor / point.factor <= 1.05:
            raise SolverError(
                f"buckling: no stability limit on the static path: the lowest stiffness fell "
                f"to {point.w[0] / w0:.3g} of its start at {point.factor:.6g} times the "
                f"reference loads and rises again at {trial.factor:.6g} (an imperfect "
                "structure: the fixed loads bend what the reference loads compress); "
                "buckling.method = 'linear' gives the classical estimate, docs/theory.md "
                "says when it holds")
        if retry or fell_and_rises:
            cuts += 1
            if cuts > MAX_CUTS:
                raise SolverError(
                    f"buckling: the static path could not be followed beyond {point.factor:.6g}"
                    f" times the reference loads (no arc-length step converged from there "
                    f"with the arc cut {MAX_CUTS} times)")
            arc *= 0.5
            continue
        if trial.w[0] <= 0:
            critical, nearest, passed = _locate_on_arc(steps, point, trial, arc, rtol)
            for stable in passed:
                history.append((stable.factor, stable.w))
                saved[stable.factor] = (stable.e.copy(), stable.lam.copy())
            return critical, nearest, history, saved
        cuts = 0
        history.append((trial.factor, trial.w))
        saved[trial.factor] = (trial.e.copy(), trial.lam.copy())
        if len(history) > max_updates:
            raise SolverError(
                f"buckling: no stability limit found up to {trial.factor:.6g} times the "
                f"reference loads in {max_updates} steps of the static path (the lowest "
                f"stiffness there {trial.w[0] / w0:.3g} of its start)")
        rise = trial.factor - point.factor
        critical = _root([(p, x[0]) for p, x in history])
        if critical is None:  # no softening yet: load further
            if trial.factor * 4.0 > max_factor:
                raise SolverError(
                    f"buckling: no stability limit up to {trial.factor:.6g} times the reference "
                    "loads (the lowest stiffness does not fall as they grow: e.g. a square "
                    "section bent in a plane of symmetry has no lateral-torsional buckling)")
            wanted = min(3.0 * trial.factor, 2.0 * rise)
        else:  # approach the estimate: past it is no harm, the arc is bracketed
            wanted = float(np.clip(0.9 * (critical - trial.factor), 0.25 * rise, 2.0 * rise))
        arc *= wanted / rise
        point = trial


def _locate_on_arc(steps: _ArcSteps, start: _Point, beyond: _Point, arc: float, rtol: float
                   ) -> tuple[float, _Point, list[_Point]]:
    """The zero of the lowest stiffness omega^2 between the stable point ``start`` and the
    point ``beyond`` at ``arc`` from it (omega^2 <= 0): regula falsi (Illinois) on the arc
    length s from ``start``, omega^2 being smooth in s through a limit point (where P(s)
    is not: it turns) and a bifurcation alike. The critical factor is P interpolated
    linearly in omega^2 between the bracket's ends (at a limit point, where P is flat in s,
    its error is the product of their distances from the zero times P's curvature), once
    two estimates agree to ``rtol``. Returns it, the stable end and the stable points
    found."""
    lo, hi, s_lo, s_hi = start, beyond, 0.0, arc
    f_lo, f_hi, side = lo.w[0], hi.w[0], 0
    passed: list[_Point] = []
    previous = None
    for _ in range(MAX_LOCATE):
        estimate = lo.factor + (hi.factor - lo.factor) * lo.w[0] / (lo.w[0] - hi.w[0])
        if previous is not None and abs(estimate - previous) <= rtol * abs(estimate):
            return float(estimate), lo, passed
        previous = estimate
        s = s_lo + (s_hi - s_lo) * f_lo / (f_lo - f_hi)
        if not s_lo < s < s_hi:
            s = 0.5 * (s_lo + s_hi)
        trial = steps.step(start, s)
        if trial is None:   # Newton at the singular point itself: the middle instead
            s = 0.5 * (s_lo + s_hi)
            trial = steps.step(start, s)
            if trial is None:
                break
        if trial.w[0] > 0:
            lo, s_lo, f_lo = trial, s, trial.w[0]
            passed.append(trial)
            if side == -1:
                f_hi *= 0.5
            side = -1
        else:
            hi, s_hi, f_hi = trial, s, trial.w[0]
            if side == 1:
                f_lo *= 0.5
            side = 1
    raise SolverError(
        f"buckling: the zero of the lowest stiffness between {lo.factor:.6g} and "
        f"{hi.factor:.6g} times the reference loads did not settle to rtol = {rtol:g} on the "
        "static path")


#: the state below the first limit about which 'nonlinear' linearizes for the further
#: factors: the last whose lowest stiffness keeps this share of the scene's (its tangent
#: well conditioned, the secant to the limit's state short)
BELOW_LIMIT = 0.05


def _beyond_the_limit(path: LoadPath, model: Model, history, saved, critical: float,
                      basis: np.ndarray | None, g: sp.spmatrix, count: int,
                      eigen_tol: float) -> tuple[np.ndarray, np.ndarray]:
    """The factors after the first limit of the 'nonlinear' path and their shapes
    (columns): the path cannot be followed past that limit, and the i-th lowest
    omega_i^2(P) is a vibration mode's stiffness, no buckling mode's (extrapolated from
    near the limit it read the portal's non-sway factor 17-25% high). So: the classical
    linear buckling (K_A + nu K_g) phi = 0 about the state A below the limit
    (:data:`BELOW_LIMIT`), K_g the secant of the tangents from A to the path's state (the
    stable point nearest the limit, :func:`_follow_to_limit`) with the beams'
    initial-stress part (:func:`stress_correction`); its lowest factor is the limit itself,
    the ones above it are returned."""
    w1 = history[0][1][0]
    below = [p for p, x in history if p < min(critical, path.factor) and
             x[0] >= BELOW_LIMIT * w1 and p in saved]
    if not below:
        return np.zeros(0), np.zeros((model.ndof, 0))
    p_a = max(below)
    e_a, lam_a = saved[p_a]
    k_a, g_a = path.matrices((e_a, lam_a, p_a))
    k_b = path.tangent()
    span = path.factor - p_a
    kg = ((k_b - k_a) / span + stress_correction(
        model, (e_a, lam_a, p_a), (path.e, path.lam, path.factor), span)).tocsr()
    kg = 0.5 * (kg + kg.T)
    theta, vectors = _pencil(_follow_basis(basis, g, g_a), k_a, kg, g_a, count + 1, eigen_tol)
    positive = theta > 1e-12 * max(np.abs(theta).max(initial=0.0), 1e-300)
    factors = p_a + 1.0 / theta[positive]
    order = np.argsort(factors)
    factors, vectors = factors[order], vectors[:, positive][:, order]
    # the lowest is the limit itself (the mode the path found); the rest lie above it
    return factors[1:count], vectors[:, 1:count]


#: the arguments of :func:`buckling_analysis` that are namelist keys (argument -> its
#: group; ``modes`` is ``count``): checked with the namelist's rules, and the keywords
#: ``System.buckling`` takes besides ``n``
BUCKLING_KEYWORDS = {"modes": "buckling", "fixed_loads": "buckling", "method": "buckling",
                     "solver": "buckling", "rtol": "buckling", "load_steps": "buckling",
                     "reference_factor": "buckling", "tol": "solver", "max_iter": "solver"}


#: a 'linear' factor P is reported when the model's static path carries 1 + CONFIRM_AT (P - 1)
#: times the loads stably; it is 'confirmed' when the same estimate about that state
#: reproduces P within CONFIRM_TOL of it, else the stability limit lies above P
CONFIRM_AT, CONFIRM_TOL = 0.98, 0.02


def _check_linear(path: "LoadPath", factor: float, kg: sp.spmatrix, g: sp.spmatrix,
                  basis: np.ndarray | None, eigen_tol: float) -> dict[str, object]:
    """What the model says of a 'linear' factor P, or its refusal. The classical estimate
    extrapolates the tangent of the scene's state linearly in the load, K_T(P) = K_1 +
    (P - 1) K_g; where the pre-buckling deformation changes the structure (a mechanism's arm
    swinging about its pin, a beam bent in its plane before it buckles sideways, a knuckle
    crane's jib folding on its compliant cylinder) the stability limit lies elsewhere
    (docs/theory.md section 23), above P or below it. The check loads the static path to
    P_t = 1 + CONFIRM_AT (P - 1) and counts the negative eigenvalues of the tangent there
    (:func:`stability_index`): a path that carries P_t stably has no stability
    limit below P_t, so P is at most 2 % above the model's limit and is reported; a path
    that cannot be followed to P_t (a limit point below it: Lee's frame loaded near its
    snap-through) or is unstable there (a bifurcation passed) is refused, naming 'nonlinear'
    (SolverError, exit 3): never a factor above the limit with status ok. About the state at
    P_t the same estimate is solved again, (K_T(P_t) + nu K_g) phi = 0: P_t + nu within
    CONFIRM_TOL of P confirms the extrapolation ('confirmed'); above it, the structure
    stiffens on its way and the limit lies above P ('conservative': the classical factor is
    on the safe side; 'nonlinear' gives the limit). Returned as /buckling attributes:
    linear_check, checked_load_factor (P_t), relinearized_load_factor (P_t + nu)."""
    if factor <= 1.0:
        return {}
    target = 1.0 + CONFIRM_AT * (factor - 1.0)
    advice = ("the structure has a stability limit below the estimate (a limit point or a "
              "bifurcation on its static path, docs/theory.md section 23): use "
              "buckling.method = 'nonlinear'")
    try:
        _advance(path, target)
    except SolverError as exc:
        raise SolverError(
            f"buckling: the 'linear' estimate {factor:.6g} is refused: the static path could "
            f"not be followed to {target:.6g} times the loads ({exc}); {advice}") from None
    if path.factor < target:    # _advance halved its step: no state at the target
        raise SolverError(
            f"buckling: the 'linear' estimate {factor:.6g} is refused: the static path ends "
            f"at {path.factor:.6g} times the loads, below {target:.6g}; {advice}")
    k_t, g_t = path.matrices()
    unstable = stability_index(path.model, k_t, g_t)
    if unstable:
        raise SolverError(
            f"buckling: the 'linear' estimate {factor:.6g} is refused: the static state at "
            f"{path.factor:.6g} times the loads is unstable ({unstable} negative "
            f"eigenvalue(s) of its tangent); {advice}")
    theta, _ = _pencil(_follow_basis(basis, g, g_t), k_t, kg, g_t, 1, eigen_tol)
    theta = theta[theta > 1e-12 * max(np.abs(theta).max(initial=0.0), 1e-300)]
    again = path.factor + 1.0 / theta.max() if len(theta) else np.inf
    check = "confirmed" if abs(again - factor) <= CONFIRM_TOL * factor else "conservative"
    return {"linear_check": check, "checked_load_factor": float(path.factor),
            "relinearized_load_factor": float(again)}


def buckling_analysis(model: Model, count: int, *, method: str = "nonlinear",
                      solver: str = "auto", tol: float = 1e-10, max_iter: int = 50,
                      load_steps: int = 1, reference_factor: float = 1.0,
                      rtol: float = 1e-6, max_updates: int = 40, max_factor: float = 1e6,
                      eigen_tol: float = 0.0) -> BucklingResult:
    """The ``count`` lowest positive load factors of ``model``'s reference loads: those
    not flagged fixed (System.assemble's ``fixed_loads``, kept at their value).

    Both start from the scene's static state (load factor 1). ``method``: 'linear' solves
    (K_1 + nu K_g) phi = 0 once, P = 1 + nu, with K_g from the tangents at 1 and at
    1 + ``reference_factor``; 'nonlinear' (default) follows the static path by arc length
    until the lowest stiffness vanishes (:func:`_follow_to_limit`): there the tangent on the
    static path is singular (the stability limit of the model, pre-buckling deformation
    included); its first arc moves the factor by about ``reference_factor``, ``rtol``
    ends the location of the zero, ``max_updates`` bounds the points on the path and
    ``max_factor`` the factor searched. See the module doc and docs/theory.md.
    The arguments of :data:`BUCKLING_KEYWORDS` pass the rules of their namelist keys
    (InputError).
    """
    args = check_keywords("buckling", dict(
        modes=count, method=method, solver=solver, rtol=rtol, load_steps=load_steps,
        reference_factor=reference_factor, tol=tol, max_iter=max_iter), BUCKLING_KEYWORDS)
    count, method, solver = args["modes"], args["method"], args["solver"]
    rtol, load_steps, reference_factor = (args["rtol"], args["load_steps"],
                                          args["reference_factor"])
    tol, max_iter = args["tol"], args["max_iter"]
    if not model.sets:
        raise InputError("buckling: the model has no flexible body (beam, cable, plate or "
                         "leaf); rigid bodies do not buckle", group="scene", key="analysis")
    if all(s.floating for s in model.sets):
        raise InputError("buckling: every beam has the 'ffr' formulation, whose constant "
                         "small-strain stiffness has no geometric (initial-stress) part; "
                         "use formulation = 'nonlinear'", group="scene", key="formulation")
    if not reference_factor > 0:
        raise InputError(f"buckling: reference_factor = {reference_factor} must be positive",
                         group="buckling", key="reference_factor")
    start = time.perf_counter()
    timing: dict[str, float] = {}
    # the scene's own static state (P = 1), solved as the scene's static solve does
    scene_state = solve_newton(model, tol=tol, max_iter=max_iter, load_steps=load_steps)
    path = LoadPath(model, tol=tol, max_iter=max_iter, load_steps=load_steps)
    path.e, path.lam, path.factor = scene_state.e.copy(), scene_state.lam.copy(), 1.0
    base = scene_state
    scene = (scene_state.e.copy(), scene_state.lam.copy(), 1.0)
    k1 = path.tangent()
    g = path.constraints()
    free = model.ndof - g.shape[0]
    check_free("buckling", free)
    how = solver if solver != "auto" else ("dense" if free <= DENSE_LIMIT else "sparse")
    basis = elastic_basis(k1, g) if how == "dense" else None
    if method == "linear":
        _advance(path, 1.0 + reference_factor)
        factor = path.factor
        k_t = path.tangent()
        kg = ((k_t - k1) / (factor - 1.0)
              + stress_correction(model, scene, (path.e, path.lam, factor),
                                  factor - 1.0)).tocsr()
        kg = 0.5 * (kg + kg.T)
        theta, vectors = _pencil(basis, k1, kg, g, count, eigen_tol)
        history: list[tuple[float, np.ndarray | None]] = [(1.0, None), (factor, None)]
    else:
        steps = _ArcSteps(path, model.mass_matrix(), how, max(count, 1), basis, g)
        first = steps.point(path.e, path.lam, 1.0)
        critical, nearest, history, saved = _follow_to_limit(
            steps, first, reference_factor, rtol, max_updates, max_factor)
        path.e, path.lam, path.factor = nearest.e.copy(), nearest.lam.copy(), nearest.factor
        vectors = nearest.vectors
    timing["path"] = time.perf_counter() - start
    reference = StaticResult(path.e.copy(), path.lam.copy(), "newton", path.solves, 0.0, 0.0,
                             0.0)
    if method == "linear":
        # P = 1 + 1 / theta: theta > 0 buckles above the scene's loads; theta in (-1, 0)
        # buckles the reversed loads (P < 0); theta <= -1 is unloading (0 <= P < 1)
        scale = np.abs(theta).max(initial=0.0)
        positive = theta > 1e-12 * max(scale, 1e-300)
        mus = 1.0 + 1.0 / theta[positive]
        order = np.argsort(mus)[:count]
        factors, shapes = mus[order], vectors[:, positive][:, order].T.copy()
        negative = (theta < -1e-12 * max(scale, 1e-300)) & (theta > -1.0)
        negative_factor = float(1.0 + 1.0 / theta[negative].min()) if negative.any() else 0.0
        checked = _check_linear(path, float(factors[0]), kg, g, basis, eigen_tol) \
            if len(factors) else {}
    else:
        # the first: the limit; the others: the classical linear buckling about a state
        # below it (_beyond_the_limit)
        checked = {}
        factors, shapes = np.array([critical]), vectors[:, :1].T.copy()
        if count > 1:
            above, more = _beyond_the_limit(path, model, history, saved, critical, basis, g,
                                            count, eigen_tol)
            factors = np.concatenate([factors, above])
            shapes = np.vstack([shapes, more.T]) if len(above) else shapes
        negative_factor = 0.0
    for i, x in enumerate(shapes):
        peak = x[np.argmax(np.abs(x))]
        shapes[i] = x / peak if peak else x
    result = BucklingResult(np.asarray(factors, dtype=float), shapes, how, model.fixed_loads,
                            model.expand(shapes, with_offset=False), base, reference,
                            timing=timing,
                            extra={"method": method, "updates": len(history),
                                   "reference_factor": history[-1][0],
                                   "static_solves": path.solves,
                                   "negative_load_factor": negative_factor, **checked})
    model.counters["buckling_analyses"] += 1
    result.wall_time_s = time.perf_counter() - start
    timing["total"] = result.wall_time_s
    return result
