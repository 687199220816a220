"""Static equilibrium K (e - e0) = Q(e) + Phi_e^T lambda, Phi(e) = 0 (seed 000, eq. 37).

Two solvers share one convergence test (:func:`residuals`):

* :func:`solve_newton` - Newton-Raphson on the symmetric saddle-point system
  [[K - dQ/de - sum lambda_k H_k, -Phi_e^T], [-Phi_e, 0]] (banded LU or MUMPS by the
  cost rule, one solver per model across load steps), in the kernel
  (fortran/src/solvers/static_solver.f90: the stepper's residual with the inertia off, one
  call per load step, the load factor an argument; with the load factor an unknown the
  same kernel Newton takes the steps of an arc-length path, solvers/path.py); the same
  Newton assembled in Python, the reference it is tested against, lives with the tests
  (tests/reference/static_newton.py).
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
from dataclasses import field

import numpy as np

from ..records import record
from ..errors import InputError, SolverError
from ..io.validate import check_arguments
from ..kernel import DirectSolver
from ..system.model import Model
from .assumptions import check_ffr


@record(eq=False, repr=False)
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
    #: the arc-length path (solvers/path.StaticPath) of static_method = 'arc_length'
    path: object = None


#: the kernel's static failures (fortran/src/solvers/static_solver.f90, info) that say nothing
#: about the load path: a stall at the round-off floor (the tolerance is beyond double
#: precision), a non-finite step, a failed linear solve; these are reported as they are,
#: never diagnosed as a limit point
NOT_A_LOAD_FAILURE = (12, 2, 3)


class LoadStepFailure(SolverError):
    """A load step of :func:`solve_newton` did not converge: the kernel's text, with the
    last converged state (``e``, ``lam`` at ``last_factor``) and the load factor
    ``factor`` that failed, from which solvers/path.diagnose_stall tells a limit point."""

    def __init__(self, message: str, *, e: np.ndarray, lam: np.ndarray, last_factor: float,
                 factor: float) -> None:
        super().__init__(message)
        self.e, self.lam, self.last_factor, self.factor = e, lam, last_factor, factor


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
    (above tol; static_solver.f90's residual_floor, eps || |K| |e| || / scale) and the
    correction that reached it was below sqrt(tol) relative to the displacement: Newton's
    error after it is of the order of its square, below tol, so the state is converged and
    another iteration would only solve round-off noise.
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


#: static_solver.f90's converged_by codes
_CONVERGED_BY = {1: "residual", 2: "roundoff", 3: "step", 4: "floor", 5: "unloaded start",
                 6: "tangent only"}

#: the modes of a kernel static call (system_static_solve's controls 'mode'): Newton at a
#: given load factor, one arc-length step (the load factor an unknown), the tangent along
#: the loads at a state
NEWTON, ARC_STEP, LOAD_TANGENT = 0, 1, 2


def kernel_static(model: Model, e: np.ndarray, lam: np.ndarray, load_factor: float, *,
                  tol: float, max_iter: int, force_scale: float = -1.0, mode: int = NEWTON,
                  check_start: bool = False, load_step: int = 1, load_steps: int = 1,
                  arc: float = 0.0, direction: float = 1.0,
                  previous: np.ndarray | None = None, account: bool = True) -> dict:
    """One call of the kernel's static Newton (:meth:`~ancfdrv.kernel.KernelSystem.
    static_solve`, fortran/src/solvers/static_solver.f90) from (e, lam) at ``load_factor``
    in ``mode`` (:data:`NEWTON`, :data:`ARC_STEP`, :data:`LOAD_TANGENT`), from the model's
    contact guesses. ``account``: carry the contact guesses on and count the force
    evaluations, assemblies and factorizations on the model (False: a look that leaves the
    model as it was, the diagnosis of a failed solve). Returns the kernel's dict (info /= 0
    with its message: the caller decides what a failure means)."""
    out = model.kernel.static_solve(
        t=0.0, load_factor=load_factor, e0=model.e0, rows=model.pattern.rows,
        cols=model.pattern.col_index, e=e, lam=lam, guesses=model.contact_guesses,
        counts=model.contact_counts, tol=tol, length_scale=model.length_scale,
        max_iter=max_iter, check_start=check_start, force_scale=force_scale,
        load_step=load_step, load_steps=load_steps, mode=mode, arc=arc, direction=direction,
        previous=previous)
    if not account:
        return out
    model.contact_guesses, model.contact_counts = out["guesses"], out["counts"]
    evaluations = out["iterations"] + 1
    # an arc-length call evaluates the forces once more per iteration for the load vector
    model.counters["elastic_force"] += (3 if mode != NEWTON else 2) * evaluations
    model.counters["stiffness_assembly"] += evaluations
    for item in (*model.moments, *model.vector_loads):
        model.counters[item.effect] += evaluations
    model.counters["factorizations"] += out["factorizations"]
    model.counters["solves"] += out["factorizations"]
    return out


def solve_newton(model: Model, *, tol: float = 1e-10, max_iter: int = 50,
                 load_steps: int = 1, loads: float = 1.0) -> StaticResult:
    """Full Newton-Raphson on (e, lambda) from the rigid configuration, in the kernel
    (``fortran/src/solvers/static_solver.f90``, issue 25 item 4): the stepper's residual with
    the inertia terms off, the saddle-point matrix [[K - dQ/de - sum lambda_k H_k,
    -Phi_e^T], [-Phi_e, 0]] factorized by the cost rule's solver, the convergence test of :func:`converged`
    with the residual's round-off floor eps || |K| |e| || / scale. The loads are applied in ``load_steps`` equal increments
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
    total, force_scale = 0, -1.0
    how, force_res, con_res = "", np.inf, np.inf
    for load_step in range(1, load_steps + 1):
        out = kernel_static(model, e, lam, loads * load_step / load_steps, tol=tol,
                            max_iter=max_iter, force_scale=force_scale,
                            check_start=load_step == 1 and load_steps == 1,
                            load_step=load_step, load_steps=load_steps)
        if out["info"] in NOT_A_LOAD_FAILURE:  # the tolerance or the numbers, not the path
            raise SolverError(out["message"])
        if out["info"]:
            raise LoadStepFailure(out["message"], e=e.copy(), lam=lam.copy(),
                                  last_factor=loads * (load_step - 1) / load_steps,
                                  factor=loads * load_step / load_steps)
        e, lam, force_scale = out["e"], out["lam"], out["force_scale"]
        history += out["history"].tolist()
        total += out["iterations"]
        how, force_res, con_res = (_CONVERGED_BY[out["converged_by"]], out["force_res"],
                                   out["con_res"])
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
    is_rest = np.ones(n, dtype=bool)
    is_rest[dep] = False
    rest = np.flatnonzero(is_rest)   # np.setdiff1d(np.arange(n), dep) without numpy.ma
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
        with DirectSolver.by_cost(len(rest), k_rr.row_index(), k_rr.indices,
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
