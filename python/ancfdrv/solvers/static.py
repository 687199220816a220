"""Static equilibrium K (e - e0) = Q(e) + Phi_e^T lambda, Phi(e) = 0 (seed 000, eq. 37).

Two solvers share one convergence test (:func:`residuals`):

* :func:`solve_newton` - Newton-Raphson on the symmetric saddle-point system
  [[K - dQ/de - sum lambda_k H_k, -Phi_e^T], [-Phi_e, 0]] with MUMPS, in the kernel
  (fortran/src/solvers/static_solver.f90: the stepper's residual with the inertia off, one
  call per load step, the load factor an argument); :func:`solve_newton_python` is the
  same Newton assembled in Python, kept as the reference it is tested against.
* :func:`solve_split` - the split iteration of seed 000 (eqs. 40-57) as implemented in
  docs/theory.md: coordinates split into dependent ones e_D (one per constraint, N1) and
  the rest e_R (N2); the fixed-point iteration
      K_RR1 e_R^{k+1} = -K_RR2 e_R^k - K_RD e_D + F_R(e_R^k, e_D, lambda),
      K_RR1 = K_RR / (1 - p), K_RR2 = -p K_RR / (1 - p),  p in [0, 1),
  is carried out on second-order Taylor polynomials ("jets") in (e_D, lambda) about the
  expansion point, giving e_R(e_D, lambda) (eq. 57); the D-equations and the constraints
  are linearized there and solved for (e_D, lambda) with LAPACK. One pass from the rigid
  configuration is the published method; further passes re-expand about the latest
  (e_D, lambda) until the same tolerance as Newton's is met. K_RR is factorized once.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, SolverError
from ..io.validate import check_arguments
from ..kernel import DirectSolver
from ..system.model import Model
from .assumptions import check_ffr


@dataclass
class StaticResult:
    """Equilibrium state and solver statistics."""

    e: np.ndarray
    lam: np.ndarray
    method: str
    iterations: int
    residual_norm: float
    constraint_norm: float
    wall_time_s: float
    history: list[float] = field(default_factory=list)
    timing: dict[str, float] = field(default_factory=dict)
    extra: dict[str, float] = field(default_factory=dict)


def converged(force_res: float, con_res: float, step: float, size: float, tol: float,
              previous_res: float = np.inf, floor: float = 0.0) -> str:
    """One test for both static solvers: '' while iterating, else why it stopped.

    'residual': relative force residual and constraint violation below tol.
    The residual of absolute ANCF coordinates has a round-off floor that grows with the
    mesh (about 5e-9 at 2000 nodes), so on fine meshes a residual test alone cannot be met
    although the state is converged. With the constraint met and the residual below
    sqrt(tol), the solve also stops when
    'step': the correction is below tol relative to the displacement (the split
    iteration's change between passes goes to zero), or
    'floor': the residual no longer decreases (Newton's corrections are then solves of
    round-off noise, which do not shrink).
    'roundoff' (Newton, issue 26): the residual is below its round-off floor ``floor``
    (:func:`residual_floor`, above tol) and the correction that reached it was below
    sqrt(tol) relative to the displacement: Newton's error after it is of the order of its
    square, below tol, so the state is converged and another iteration would only solve
    round-off noise.
    """
    if con_res > tol:
        return ""
    if force_res <= tol:
        return "residual"
    if force_res <= floor and step <= np.sqrt(tol) * size:
        return "roundoff"
    if force_res <= np.sqrt(tol):
        if step <= tol * size:
            return "step"
        if force_res >= 0.5 * previous_res:
            return "floor"
    return ""


def residuals(model: Model, d: np.ndarray, lam: np.ndarray, internal: np.ndarray,
              external: np.ndarray, scale_floor: float = 0.0):
    """Relative force residual |Q_int - Q - Phi_e^T lam| / scale and max |Phi| / length at
    the displacement d = e - e0, given the internal force Q_int (elastic minus contact minus
    the dead moments; for the split iteration K d minus the moments, so it loses no digits)
    and the external loads Q. ``scale_floor`` keeps the scale of a self-equilibrated problem
    (a prestressed body without loads) at the forces met on the way."""
    e = model.e0 + d
    values, rows, cols, grads = model.constraints.jacobian(e, model.ndof)
    reaction = np.zeros(model.ndof)
    np.add.at(reaction, cols, grads * lam[rows])
    residual = internal - external - reaction
    scale = max(np.linalg.norm(external), np.linalg.norm(reaction), np.linalg.norm(internal),
                scale_floor, 1e-300)
    return (np.linalg.norm(residual) / scale,
            np.max(np.abs(values), initial=0.0) / model.length_scale)


def residual_floor(model: Model, e: np.ndarray, k_values: np.ndarray, scale: float) -> float:
    """The round-off floor of the relative force residual at e: the forward error bound of
    the internal force, eps |||K| |e||| / scale (Higham, Accuracy and Stability of Numerical
    Algorithms, 2nd ed., section 3.5: a matrix-vector product's error is within gamma_n
    |K| |e|), with |K| the tangent's absolute values. The absolute ANCF coordinates carry the
    rigid configuration, so the elastic force is the small difference of large terms: on
    the 28-node FFR boom the bound is 3.5e-9 where the measured floor is 3e-10 to 6e-10, and
    both grow with the mesh."""
    magnitude = model.pattern.to_csr(np.abs(k_values)) @ np.abs(e)
    return float(np.finfo(float).eps * np.linalg.norm(magnitude) / max(scale, 1e-300))


#: iterations in a row without a new smallest residual: the static Newton has stalled, once
#: its residual is small (below STALL_NEAR, or at the floor); far from the solution large
#: rotations make the residual rise for a while before Newton converges (the elastica),
#: so there only FAR_STALL_ITERATIONS without progress count as a stall
STALL_ITERATIONS, FAR_STALL_ITERATIONS, STALL_NEAR = 4, 25, 1e-6


def _stall_message(history: list[float], floor: float, tol: float, load_step: int,
                   load_steps: int) -> str:
    """Why the static Newton stopped early: a stall at (or above) the round-off floor, or a
    divergence (the residual grew three times in a row to 1e3 times its minimum)."""
    last, smallest = history[-1], min(history)
    where = f"at load step {load_step} of {load_steps}"
    if all(b > a for a, b in zip(history[-4:-1], history[-3:])) and last > 1e6 * smallest:
        return (f"static Newton diverged {where}: the relative residual grew three times in a "
                f"row to {last:.3e} (smallest {smallest:.3e}); raise solver.load_steps")
    if smallest <= floor:
        return (f"static Newton stalled at the round-off floor {where}: the relative residual "
                f"stays at {smallest:.3e} (estimated floor {floor:.3e}) above solver.tol = "
                f"{tol:.3e}, which asks for more digits than double precision carries here; "
                "raise solver.tol")
    return (f"static Newton stalled {where}: no smaller residual in the last iterations "
            f"(smallest {smallest:.3e}, tolerance {tol:.3e}); raise solver.load_steps")


def _hessian_triplets(model: Model, e: np.ndarray):
    """Constant constraint Hessians as (constraint, row, col, value) in the coordinates."""
    return model.constraints.hessian_triplets(e)


def _forces(model: Model, d: np.ndarray, want_tangent: bool, load_factor: float = 1.0,
            t: float = 0.0):
    """(internal, external, tangent values or None) at e0 + d and the load factor from the
    kernel."""
    out = model.forces(model.e0 + d, t, want_tangent=want_tangent, load_factor=load_factor)
    return out["internal"], out["external"], out["tangent"]


def solve_newton_python(model: Model, *, tol: float = 1e-10, max_iter: int = 50,
                        load_steps: int = 1, loads: float = 1.0) -> StaticResult:
    """Full Newton-Raphson on (e, lambda) from the rigid configuration; the loads are
    applied in ``load_steps`` equal increments (large deformation), each solved to tol.
    ``loads`` scales the external loads (gravity, forces, moments, pressure) of the last
    increment: 0 gives the equilibrium of the internal forces alone (prestress carried by
    contact), the start of a settled run.

    The Python implementation of the static Newton, kept as the reference the kernel's
    (:func:`solve_newton`) is tested against: the same residual, saddle-point matrix and
    convergence test, assembled here from the kernel's force evaluations."""
    check_arguments("solve_newton", tol=tol, max_iter=max_iter, load_steps=load_steps,
                    loads=loads)
    model.require_runnable()
    start = time.perf_counter()
    timing = {"assembly": 0.0, "factorization": 0.0, "solve": 0.0}
    n, ncon = model.ndof, len(model.constraints)
    d, lam = np.zeros(n), np.zeros(ncon)
    t0 = time.perf_counter()
    h_con, h_rows, h_cols, h_vals = _hessian_triplets(model, model.e0)
    _, j_rows, j_cols, _ = model.constraints.jacobian(model.e0, n)
    moment_cols = [cols for cols, *_ in model.moment_terms(model.e0, load_factor=1.0)]
    m_rows = [np.repeat(cols, len(cols)) for cols in moment_cols]
    m_cols = [np.tile(cols, len(cols)) for cols in moment_cols]
    # driven and follower point loads: their (non-symmetric) Jacobian, with the moments'
    load_cols = [cols for cols, *_ in model.vector_load_terms(model.e0, load_factor=1.0)]
    m_rows += [np.repeat(cols, len(cols)) for cols in load_cols]
    m_cols += [np.tile(cols, len(cols)) for cols in load_cols]
    rows = np.concatenate([model.pattern.rows, h_rows, *m_rows, n + j_rows, j_cols])
    cols = np.concatenate([model.pattern.col_index, h_cols, *m_cols, j_cols, n + j_rows])
    timing["assembly"] += time.perf_counter() - t0
    history, total = [], 0
    force_scale = 0.0
    with DirectSolver(n + ncon, rows, cols, what="static Newton saddle-point matrix") as solver:
        try:
            for load_step in range(1, load_steps + 1):
                factor = loads * load_step / load_steps
                for iteration in range(1, max_iter + 1):
                    t0 = time.perf_counter()
                    e = model.e0 + d
                    phi, _, _, grads = model.constraints.jacobian(e, n)
                    reaction = np.zeros(n)
                    np.add.at(reaction, j_cols, grads * lam[j_rows])
                    moments = model.moment_terms(e, load_factor=factor)
                    moments += [(c, f, j, None) for c, f, j in
                                model.vector_load_terms(e, load_factor=factor)]
                    internal, external, k_values = _forces(model, d, True, factor)
                    residual = internal - external - reaction
                    if load_step == 1 and iteration == 1:  # the start: loads and prestress
                        force_scale = max(np.linalg.norm(internal), np.linalg.norm(external))
                        # no load at all and the internal forces zero to their own round-off
                        # (e.g. settling a spring without prestress and with the loads off):
                        # the start is the equilibrium; a load, however small, is solved for
                        unloaded = not np.any(external) and not any(
                            np.any(f) for _, f, *_ in moments)
                        if (load_steps == 1 and unloaded and np.linalg.norm(residual)
                                <= residual_floor(model, e, k_values, 1.0)
                                and np.abs(phi).max(initial=0.0) <= tol * model.length_scale):
                            how, force_res, con_res = "unloaded start", 0.0, 0.0
                            iteration = 0
                            break
                    values = np.concatenate([k_values, -lam[h_con] * h_vals,
                                             *[-j.ravel() for _, _, j, _ in moments], -grads,
                                             -grads])
                    timing["assembly"] += time.perf_counter() - t0
                    t0 = time.perf_counter()
                    solver.factorize(values)
                    timing["factorization"] += time.perf_counter() - t0
                    t0 = time.perf_counter()
                    step = solver.solve(np.concatenate([-residual, phi]))
                    timing["solve"] += time.perf_counter() - t0
                    if not np.all(np.isfinite(step)):
                        raise SolverError(f"static Newton: non-finite step at iteration "
                                          f"{iteration} of load step {load_step}")
                    d += step[:n]
                    lam += step[n:]
                    internal, external, _ = _forces(model, d, False, factor)
                    force_res, con_res = residuals(model, d, lam, internal, external,
                                                   force_scale)
                    previous = history[-1] if history and iteration > 1 else np.inf
                    history.append(force_res)
                    scale = max(np.linalg.norm(external), np.linalg.norm(internal),
                                force_scale)
                    floor = residual_floor(model, model.e0 + d, k_values, scale)
                    how = converged(force_res, con_res, np.linalg.norm(step[:n]),
                                    np.linalg.norm(d), tol, previous, floor)
                    if how:
                        break
                    # the stagnation and divergence test (issue 24 item 2): no new minimum
                    # in STALL_ITERATIONS iterations near the solution (FAR_STALL_ITERATIONS
                    # far from it), or three rises to 1e6 times it
                    step_history = history[len(history) - iteration:]
                    best = int(np.argmin(step_history))
                    near = step_history[best] <= max(STALL_NEAR, floor)
                    growing = (iteration >= 4 and all(
                        b > a for a, b in zip(step_history[-4:-1], step_history[-3:]))
                        and force_res > 1e6 * step_history[best])
                    since = iteration - 1 - best
                    if since >= (STALL_ITERATIONS if near else FAR_STALL_ITERATIONS) \
                            or growing or not np.isfinite(force_res):
                        raise SolverError(_stall_message(step_history, floor, tol, load_step,
                                                         load_steps))
                else:
                    raise SolverError(
                        f"static Newton did not converge in {max_iter} iterations at load step "
                        f"{load_step} of {load_steps} (relative residual {force_res:.3e}, "
                        f"constraint {con_res:.3e}); raise solver.load_steps or max_iter")
                total += iteration
        finally:
            model.counters["factorizations"] += solver.factorizations
            model.counters["solves"] += solver.solves
    check_ffr(model, model.e0 + d, 0.0, when="in the static equilibrium")
    wall = time.perf_counter() - start
    timing["total"] = wall
    return StaticResult(model.e0 + d, lam, "newton", total, force_res, con_res, wall, history,
                        timing, extra={"converged_by": how, "load_steps": load_steps,
                                       "load_factor": loads})


#: static_solver.f90's converged_by codes
_CONVERGED_BY = {1: "residual", 2: "roundoff", 3: "step", 4: "floor", 5: "unloaded start"}


def solve_newton(model: Model, *, tol: float = 1e-10, max_iter: int = 50,
                 load_steps: int = 1, loads: float = 1.0) -> StaticResult:
    """Full Newton-Raphson on (e, lambda) from the rigid configuration, in the kernel
    (``fortran/src/solvers/static_solver.f90``, issue 25 item 4): the stepper's residual with
    the inertia terms off, the saddle-point matrix [[K - dQ/de - sum lambda_k H_k,
    -Phi_e^T], [-Phi_e, 0]] factorized by MUMPS, the convergence test of :func:`converged`
    and :func:`residual_floor`. The loads are applied in ``load_steps`` equal increments
    (large deformation), each solved to tol by one kernel call with its load factor as an
    argument. ``loads`` scales the external loads (gravity, forces, moments, pressure) of
    the last increment: 0 gives the equilibrium of the internal forces alone (prestress
    carried by contact), the start of a settled run."""
    check_arguments("solve_newton", tol=tol, max_iter=max_iter, load_steps=load_steps,
                    loads=loads)
    model.require_runnable()
    model.check_alive()
    start = time.perf_counter()
    ncon = len(model.constraints)
    e, lam = model.e0.copy(), np.zeros(ncon)
    history: list[float] = []
    total, factorizations, force_scale = 0, 0, -1.0
    how, force_res, con_res = "", np.inf, np.inf
    try:
        for load_step in range(1, load_steps + 1):
            out = model.kernel.static_solve(
                t=0.0, load_factor=loads * load_step / load_steps, e0=model.e0,
                rows=model.pattern.rows, cols=model.pattern.col_index, e=e, lam=lam,
                guesses=model.contact_guesses, counts=model.contact_counts, tol=tol,
                length_scale=model.length_scale, max_iter=max_iter,
                check_start=load_step == 1 and load_steps == 1, force_scale=force_scale,
                load_step=load_step, load_steps=load_steps)
            model.contact_guesses, model.contact_counts = out["guesses"], out["counts"]
            factorizations += out["factorizations"]
            evaluations = out["iterations"] + 1
            model.counters["elastic_force"] += 2 * evaluations
            model.counters["stiffness_assembly"] += evaluations
            for item in (*model.moments, *model.vector_loads):
                model.counters[item.effect] += evaluations
            if out["info"]:
                raise SolverError(out["message"])
            e, lam, force_scale = out["e"], out["lam"], out["force_scale"]
            history += out["history"].tolist()
            total += out["iterations"]
            how, force_res, con_res = (_CONVERGED_BY[out["converged_by"]], out["force_res"],
                                       out["con_res"])
    finally:
        model.counters["factorizations"] += factorizations
        model.counters["solves"] += factorizations
    check_ffr(model, e, 0.0, when="in the static equilibrium")
    wall = time.perf_counter() - start
    return StaticResult(e, lam, "newton", total, force_res, con_res, wall, history,
                        {"assembly": 0.0, "factorization": 0.0, "solve": wall, "total": wall},
                        extra={"converged_by": how, "load_steps": load_steps,
                               "load_factor": loads})


class Jet:
    """Second-order Taylor polynomial v + G d + 1/2 d^T H d of a vector in m variables."""

    def __init__(self, value: np.ndarray, grad: np.ndarray, hess: np.ndarray) -> None:
        self.value, self.grad, self.hess = value, grad, hess

    @classmethod
    def zeros(cls, n: int, m: int) -> "Jet":
        return cls(np.zeros(n), np.zeros((n, m)), np.zeros((n, m, m)))

    def __getitem__(self, idx) -> "Jet":
        return Jet(self.value[idx], self.grad[idx], self.hess[idx])

    def stack(self) -> np.ndarray:
        n, m = self.grad.shape
        return np.hstack([self.value[:, None], self.grad, self.hess.reshape(n, m * m)])

    def combine(self, a: float, other: "Jet", b: float) -> "Jet":
        return Jet(a * self.value + b * other.value, a * self.grad + b * other.grad,
                   a * self.hess + b * other.hess)

    def evaluate(self, d: np.ndarray) -> np.ndarray:
        return self.value + self.grad @ d + 0.5 * np.einsum("nab,a,b->n", self.hess, d, d)

    def distance(self, other: "Jet") -> float:
        return max(np.max(np.abs(self.value - other.value), initial=0.0),
                   np.max(np.abs(self.grad - other.grad), initial=0.0),
                   np.max(np.abs(self.hess - other.hess), initial=0.0))


def _force_jet(model: Model, rel: np.ndarray, d: Jet, lam: np.ndarray, nd: int) -> Jet:
    """Jet of the configuration-dependent forces Q_M(e0 + d) + Phi_e(e0 + d)^T lambda on
    the coordinates ``rel`` (which hold every moment director and constrained coordinate),
    for the jet ``d`` of the displacement on ``rel`` and lambda = lam + delta_lambda
    (variables nd..). Constant loads are not included."""
    n, m = d.grad.shape
    where = {dof: i for i, dof in enumerate(rel)}
    e = model.e0.copy()
    e[rel] += d.value
    out = Jet.zeros(n, m)
    # the moments and constraints act through the forces on rel: -Q_M enters the internal
    # force, so the jet carries Q_M + Phi_e^T lambda
    for cols, f, j, h in model.moment_terms(e):
        idx = [where[k] for k in cols]
        gx, hx = d.grad[idx], d.hess[idx]
        out.value[idx] += f
        out.grad[idx] += j @ gx
        out.hess[idx] += np.einsum("ij,jab->iab", j, hx) + np.einsum("ijl,ja,lb->iab", h, gx, gx)
    _, gradients, hessians, *_ = model.constraints.evaluate(e)
    for c in range(len(model.constraints)):
        operands, _ = model.constraints.operand_map(c, rel)   # (6, n) d x / d e_rel
        g_val = operands.T @ gradients[:, c]
        hc = operands.T @ hessians[:, :, c] @ operands
        g_grad = hc @ d.grad
        g_hess = np.einsum("ij,jab->iab", hc, d.hess)
        unit = np.zeros(m)
        unit[nd + c] = 1.0
        out.value += lam[c] * g_val
        out.grad += lam[c] * g_grad + np.outer(g_val, unit)
        cross = np.einsum("ia,b->iab", g_grad, unit)
        out.hess += lam[c] * g_hess + cross + np.transpose(cross, (0, 2, 1))
    return out


def split_obstacle(model: Model) -> str | None:
    """Why the split iteration cannot solve ``model`` (it needs the constant FFR stiffness
    and dead loads only), or None when it can: what ``static_method = 'auto'`` chooses by,
    and why an explicit 'split' is refused."""
    if any(not s.floating for s in model.sets) or model.contact_pairs:
        return ("the split iteration needs the constant stiffness of the 'ffr' formulation "
                "(every body) without contact")
    if any(s.second_order is not None for s in model.sets):
        return ("the split iteration needs the constant stiffness of the 'ffr' formulation; "
                "beam.geometric_stiffness makes it depend on the axial force")
    if model.vector_loads:
        return ("the split iteration takes dead loads only; driven moments, follower loads "
                "and a rigid body's moments are not")
    if model.force_elements:
        return ("the split iteration needs a constant stiffness; force elements "
                "(spring-dampers, bushings, cylinders) are not")
    dep = np.asarray(model.constraints.dependent, dtype=int)
    if len(set(dep.tolist())) != len(model.constraints):
        return ("the split iteration needs a dependent coordinate of its own per constraint; "
                "two constraints of this model share one")
    return None


def check_split(model: Model) -> None:
    """Refuse a model the split iteration cannot solve (InputError naming
    solver.static_method: a configuration the user chose, not a failed solve)."""
    obstacle = split_obstacle(model)
    if obstacle is not None:
        raise InputError(f"{obstacle}; use solver.static_method = 'newton' or 'auto'",
                         group="solver", key="static_method")


def solve_split(model: Model, *, tol: float = 1e-10, max_iter: int = 50, p: float = 0.0,
                inner_tol: float = 1e-13, max_inner: int = 200) -> StaticResult:
    """The split iteration of seed 000 with re-expansion until convergence (module doc).

    Only a few coordinates N_l of e_R carry configuration-dependent forces (the moment's
    director, the constrained coordinates). With u0 = K_RR^{-1} G_R, Z = K_RR^{-1} E_l and
    Y = K_RR^{-1} K_RD (1 + |N_l| + n_D solves, once), the iteration
        d_R = p d_R + (1 - p) (u0 + Z F_l(d, lambda) - Y d_D)
    needs d_R only on N_l, so the Taylor jets live on those rows and every inner
    iteration is small dense algebra; d_R is rebuilt in full once per pass.
    """
    check_arguments("solve_split", tol=tol, max_iter=max_iter, p=p, inner_tol=inner_tol,
                    max_inner=max_inner)
    if not 0.0 <= p < 1.0:
        raise InputError(f"split iteration: p = {p} outside [0, 1)", group="solver",
                         key="split_p")
    check_split(model)
    model.require_runnable()
    start = time.perf_counter()
    timing = {"assembly": 0.0, "factorization": 0.0, "solve": 0.0}
    n, ncon = model.ndof, len(model.constraints)
    dep = np.array(model.constraints.dependent, dtype=int)
    rest = np.setdiff1d(np.arange(n), dep)
    nd, m = len(dep), len(dep) + ncon
    touched = set(model.constraints.touched().tolist()) | {
        int(k) for cols, *_ in model.moment_terms(model.e0) for k in cols}
    nonlinear = np.array(sorted(touched - set(dep.tolist())), dtype=int)
    local = np.searchsorted(rest, nonlinear)  # rows of N_l within e_R
    rel = np.concatenate([nonlinear, dep])
    nl = len(nonlinear)
    t0 = time.perf_counter()
    stiffness = model.pattern.to_csr(model.stiffness_values(0.0))   # (ancfdrv.csr: no scipy)
    k_r = stiffness.take_rows(rest)
    k_rr, k_rd = k_r.take_columns(rest), k_r.take_columns(dep).toarray()
    k_d = stiffness.take_rows(dep)
    k_dr, k_dd = k_d.take_columns(rest), k_d.take_columns(dep).toarray()
    constant = model.constant_force()
    timing["assembly"] += time.perf_counter() - t0
    solved = np.zeros((0, 1 + nl + nd))  # the constraints hold every coordinate: no e_R
    if len(rest):
        with DirectSolver(len(rest), k_rr.row_index(), k_rr.indices,
                          what="split iteration K_RR") as solver:
            try:
                t0 = time.perf_counter()
                solver.factorize(k_rr.data)
                timing["factorization"] += time.perf_counter() - t0
                t0 = time.perf_counter()
                columns = np.zeros((len(rest), 1 + nl + nd))
                columns[:, 0] = constant[rest]
                columns[local, 1 + np.arange(nl)] = 1.0
                columns[:, 1 + nl:] = k_rd
                solved = solver.solve(columns)
                timing["solve"] += time.perf_counter() - t0
            finally:
                model.counters["factorizations"] += solver.factorizations
                model.counters["solves"] += solver.solves
    u0, z, y = solved[:, 0], solved[:, 1:1 + nl], solved[:, 1 + nl:]
    kdr_u0, kdr_z, kdr_y = k_dr @ u0, k_dr @ z, k_dr @ y
    dd_grad = np.zeros((nd, m))
    dd_grad[:, :nd] = np.eye(nd)
    d_d, lam = np.zeros(nd), np.zeros(ncon)
    disp = np.zeros(n)
    history, inner_total = [], 0
    t0 = time.perf_counter()
    for outer in range(1, max_iter + 1):
        # d_R on N_l as a jet in delta = (delta e_D, delta lambda) about (d_D, lam)
        x = Jet(disp[nonlinear].copy(), np.zeros((nl, m)), np.zeros((nl, m, m)))
        base = Jet(u0[local] - y[local] @ d_d, -y[local] @ dd_grad, np.zeros((nl, m, m)))

        def jet_on_rel(x: Jet) -> Jet:
            return Jet(np.concatenate([x.value, d_d]), np.vstack([x.grad, dd_grad]),
                       np.concatenate([x.hess, np.zeros((nd, m, m))]))
        for inner in range(1, max_inner + 1):
            forces = _force_jet(model, rel, jet_on_rel(x), lam, nd)[slice(0, nl)]
            target = base.combine(1.0, Jet(z[local] @ forces.value, z[local] @ forces.grad,
                                           np.einsum("ij,jab->iab", z[local], forces.hess)), 1.0)
            new = x.combine(p, target, 1.0 - p)
            change = new.distance(x)
            x = new
            if change <= inner_tol * max(model.length_scale, 1.0):
                break
        inner_total += inner
        # linearized D-equations and constraints in delta
        forces = _force_jet(model, rel, jet_on_rel(x), lam, nd)
        f_l, f_d = forces[slice(0, nl)], forces[slice(nl, nl + nd)]
        r_value = (kdr_u0 + kdr_z @ f_l.value - kdr_y @ d_d + k_dd @ d_d - constant[dep]
                   - f_d.value)
        r_grad = kdr_z @ f_l.grad - kdr_y @ dd_grad + k_dd @ dd_grad - f_d.grad
        e = model.e0.copy()
        e[nonlinear] += x.value
        e[dep] += d_d
        phi, rows, cols, grads = model.constraints.jacobian(e, n)
        rel_grad = np.zeros((n, m))
        rel_grad[nonlinear], rel_grad[dep] = x.grad, dd_grad
        phi_grad = np.zeros((ncon, m))
        np.add.at(phi_grad, rows, grads[:, None] * rel_grad[cols])
        try:
            delta = np.linalg.solve(np.vstack([r_grad, phi_grad]),
                                    -np.concatenate([r_value, phi]))
        except np.linalg.LinAlgError:
            raise SolverError("split iteration: the reduced system in (e_D, lambda) is "
                              "singular; the dependent coordinates do not fit the "
                              "constraints") from None
        # e_R from its second-order Taylor polynomial (eq. 57), rebuilt in full
        d_d_new = d_d + delta[:nd]
        d_r = u0 + z @ f_l.evaluate(delta) - y @ d_d_new
        lam = lam + delta[nd:]
        previous = disp
        disp = np.zeros(n)
        disp[rest], disp[dep] = d_r, d_d_new
        d_d = d_d_new
        internal = stiffness @ disp
        for cols, f, _, _ in model.moment_terms(model.e0 + disp):
            internal[cols] -= f
        force_res, con_res = residuals(model, disp, lam, internal, constant)
        history.append(force_res)
        if not np.isfinite(force_res):
            raise SolverError(f"split iteration: non-finite state at pass {outer}")
        how = converged(force_res, con_res, np.linalg.norm(disp - previous),
                        np.linalg.norm(disp), tol)
        if how:
            break
    else:
        raise SolverError(f"split iteration did not converge in {max_iter} passes "
                          f"(relative residual {force_res:.3e}, constraint {con_res:.3e})")
    timing["assembly"] += time.perf_counter() - t0
    wall = time.perf_counter() - start
    timing["total"] = wall
    check_ffr(model, model.e0 + disp, 0.0, when="in the static equilibrium")
    return StaticResult(model.e0 + disp, lam, "split", outer, force_res, con_res, wall, history,
                        timing, extra={"inner_iterations": inner_total, "p": p,
                                       "converged_by": how, "nonlinear_coordinates": nl})


#: the values of ``solver.static_method``: 'auto' (the default) takes the split iteration
#: where it applies (:func:`split_obstacle`), Newton otherwise
STATIC_METHODS = ("auto", "split", "newton")


def static_method_for(model: Model, method: str) -> str:
    """The static method a run uses: ``method`` itself, or for 'auto' the split iteration
    where it applies (the boom's FFR scenes of seed 000) and Newton otherwise."""
    if method == "auto":
        return "split" if split_obstacle(model) is None else "newton"
    return method


def solve_static(model: Model, method: str, *, tol: float, max_iter: int,
                 p: float = 0.0, load_steps: int = 1) -> StaticResult:
    """Dispatch on ``solver.static_method`` ('auto', 'split', 'newton'); the result's
    ``method`` is the one used, ``extra['method_setting']`` the one asked for."""
    if method not in STATIC_METHODS:
        raise InputError(f"static_method {method!r} must be one of {', '.join(STATIC_METHODS)}",
                         group="solver", key="static_method")
    if static_method_for(model, method) == "newton":
        result = solve_newton(model, tol=tol, max_iter=max_iter, load_steps=load_steps)
    else:
        result = solve_split(model, tol=tol, max_iter=max_iter, p=p)
    result.extra["method_setting"] = method
    return result
