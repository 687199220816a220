"""Static equilibrium K (e - e0) = Q(e) + Phi_e^T lambda, Phi(e) = 0 (seed 000, eq. 37).

Two solvers share one convergence test (:func:`residuals`):

* :func:`solve_newton` - Newton-Raphson on the symmetric saddle-point system
  [[K - dQ/de - sum lambda_k H_k, -Phi_e^T], [-Phi_e, 0]] with MUMPS (pattern analysed once).
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
import scipy.sparse as sp

from .errors import SolverError
from .kernel import DirectSolver
from .model import BeamModel


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


#: A correction smaller than this relative to the displacement is at round-off level: the
#: state can no longer improve, so the solve stops there (and reports its residual).
STEP_FLOOR = 1e-13


def converged(force_res: float, con_res: float, step: float, size: float, tol: float) -> str:
    """'' while iterating; 'residual' or 'step' (round-off floor reached) when converged."""
    if force_res <= tol and con_res <= tol:
        return "residual"
    if step <= STEP_FLOOR * size and force_res <= 1e3 * tol and con_res <= 1e3 * tol:
        return "step"
    return ""


def residuals(model: BeamModel, d: np.ndarray, lam: np.ndarray, stiffness: sp.csr_matrix):
    """Relative force residual |K d - Q - Phi_e^T lam| / scale and max |Phi| / length at the
    displacement d = e - e0 (carried instead of e so K d loses no digits)."""
    e = model.e0 + d
    values, rows, cols, grads = model.constraints.jacobian(e, model.ndof)
    reaction = np.zeros(model.ndof)
    np.add.at(reaction, cols, grads * lam[rows])
    elastic = stiffness @ d
    external = model.external_force(e)
    residual = elastic - external - reaction
    scale = max(np.linalg.norm(external), np.linalg.norm(reaction), np.linalg.norm(elastic),
                1e-300)
    length = model.node_s[-1] - model.node_s[0]
    return np.linalg.norm(residual) / scale, np.max(np.abs(values), initial=0.0) / length


def _hessian_triplets(model: BeamModel, e: np.ndarray):
    """Constant constraint Hessians as (constraint, row, col, value) over used dofs."""
    _, _, hessians, *_ = model.constraints.evaluate(e)
    table = model.constraints.dof_table()
    c_idx, a_idx, b_idx = np.nonzero(np.transpose(hessians, (2, 0, 1)))
    keep = (table[a_idx, c_idx] >= 0) & (table[b_idx, c_idx] >= 0)
    c_idx, a_idx, b_idx = c_idx[keep], a_idx[keep], b_idx[keep]
    return c_idx, table[a_idx, c_idx], table[b_idx, c_idx], hessians[a_idx, b_idx, c_idx]


def solve_newton(model: BeamModel, *, tol: float = 1e-10, max_iter: int = 50) -> StaticResult:
    """Full Newton-Raphson on (e, lambda) from the rigid configuration."""
    start = time.perf_counter()
    timing = {"assembly": 0.0, "factorization": 0.0, "solve": 0.0}
    n, ncon = model.ndof, len(model.constraints)
    d, lam = np.zeros(n), np.zeros(ncon)
    t0 = time.perf_counter()
    k_values = model.stiffness_values()
    stiffness = model.pattern.to_scipy(k_values)
    h_con, h_rows, h_cols, h_vals = _hessian_triplets(model, model.e0)
    _, j_rows, j_cols, _ = model.constraints.jacobian(model.e0, n)
    m_rows = [np.repeat(m.dofs, 3) for m in model.moments]
    m_cols = [np.tile(m.dofs, 3) for m in model.moments]
    rows = np.concatenate([model.pattern.rows, h_rows, *m_rows, n + j_rows, j_cols])
    cols = np.concatenate([model.pattern.col_index, h_cols, *m_cols, j_cols, n + j_rows])
    timing["assembly"] += time.perf_counter() - t0
    history = []
    with DirectSolver(n + ncon, rows, cols, what="static Newton saddle-point matrix") as solver:
        try:
            for iteration in range(1, max_iter + 1):
                t0 = time.perf_counter()
                e = model.e0 + d
                phi, _, _, grads = model.constraints.jacobian(e, n)
                reaction = np.zeros(n)
                np.add.at(reaction, j_cols, grads * lam[j_rows])
                moments = model.moment_terms(e)
                external = model.constant_force()
                for dofs, f, _, _ in moments:
                    external[dofs] += f
                residual = stiffness @ d - external - reaction
                values = np.concatenate([k_values, -lam[h_con] * h_vals,
                                         *[-j.ravel() for _, _, j, _ in moments], -grads, -grads])
                timing["assembly"] += time.perf_counter() - t0
                t0 = time.perf_counter()
                solver.factorize(values)
                timing["factorization"] += time.perf_counter() - t0
                t0 = time.perf_counter()
                step = solver.solve(np.concatenate([-residual, phi]))
                timing["solve"] += time.perf_counter() - t0
                if not np.all(np.isfinite(step)):
                    raise SolverError(f"static Newton: non-finite step at iteration {iteration}")
                d += step[:n]
                lam += step[n:]
                force_res, con_res = residuals(model, d, lam, stiffness)
                history.append(force_res)
                how = converged(force_res, con_res, np.linalg.norm(step[:n]), np.linalg.norm(d), tol)
                if how:
                    break
            else:
                raise SolverError(f"static Newton did not converge in {max_iter} iterations "
                                  f"(relative residual {force_res:.3e}, constraint {con_res:.3e})")
        finally:
            model.counters["factorizations"] += solver.factorizations
            model.counters["solves"] += solver.solves
    wall = time.perf_counter() - start
    timing["total"] = wall
    return StaticResult(model.e0 + d, lam, "newton", iteration, force_res, con_res, wall, history,
                        timing, extra={"converged_by": how})


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

    @classmethod
    def unstack(cls, columns: np.ndarray, m: int) -> "Jet":
        n = columns.shape[0]
        return cls(columns[:, 0], columns[:, 1:1 + m], columns[:, 1 + m:].reshape(n, m, m))

    def combine(self, a: float, other: "Jet", b: float) -> "Jet":
        return Jet(a * self.value + b * other.value, a * self.grad + b * other.grad,
                   a * self.hess + b * other.hess)

    def evaluate(self, d: np.ndarray) -> np.ndarray:
        return self.value + self.grad @ d + 0.5 * np.einsum("nab,a,b->n", self.hess, d, d)

    def distance(self, other: "Jet") -> float:
        return max(np.max(np.abs(self.value - other.value), initial=0.0),
                   np.max(np.abs(self.grad - other.grad), initial=0.0),
                   np.max(np.abs(self.hess - other.hess), initial=0.0))


def _force_jet(model: BeamModel, d: Jet, lam: np.ndarray, nd: int) -> Jet:
    """Jet of F = Q(e0 + d) + Phi_e(e0 + d)^T lambda for the jet d of the displacement and
    lambda = lam + delta_lambda (variables nd..). Constant loads enter the value only."""
    n, m = d.grad.shape
    e = model.e0 + d.value
    out = Jet.zeros(n, m)
    out.value += model.constant_force()
    for dofs, f, j, h in model.moment_terms(e):
        gx, hx = d.grad[dofs], d.hess[dofs]
        out.value[dofs] += f
        out.grad[dofs] += j @ gx
        out.hess[dofs] += np.einsum("ij,jab->iab", j, hx) + np.einsum("ijl,ja,lb->iab", h, gx, gx)
    _, gradients, hessians, *_ = model.constraints.evaluate(e)
    table = model.constraints.dof_table()
    for c in range(len(model.constraints)):
        used = table[:, c] >= 0
        dofs = table[used, c]
        hc = hessians[np.ix_(used, used, [c])][:, :, 0]
        g_val, g_grad, g_hess = gradients[used, c], hc @ d.grad[dofs], np.einsum(
            "ij,jab->iab", hc, d.hess[dofs])
        unit = np.zeros(m)
        unit[nd + c] = 1.0
        out.value[dofs] += lam[c] * g_val
        out.grad[dofs] += lam[c] * g_grad + np.outer(g_val, unit)
        cross = np.einsum("ia,b->iab", g_grad, unit)
        out.hess[dofs] += lam[c] * g_hess + cross + np.transpose(cross, (0, 2, 1))
    return out


def solve_split(model: BeamModel, *, tol: float = 1e-10, max_iter: int = 50, p: float = 0.0,
                inner_tol: float = 1e-13, max_inner: int = 200) -> StaticResult:
    """The split iteration of seed 000 with re-expansion until convergence (module doc)."""
    if not 0.0 <= p < 1.0:
        raise SolverError(f"split iteration: p = {p} outside [0, 1)")
    start = time.perf_counter()
    timing = {"assembly": 0.0, "factorization": 0.0, "solve": 0.0}
    n, ncon = model.ndof, len(model.constraints)
    dep = np.array(model.constraints.dependent)
    if len(set(dep.tolist())) != ncon:
        raise SolverError("split iteration: two constraints share a dependent coordinate")
    rest = np.setdiff1d(np.arange(n), dep)
    nd, m = len(dep), len(dep) + ncon
    t0 = time.perf_counter()
    stiffness = model.stiffness_matrix()
    k_rr = stiffness[rest][:, rest].tocoo()
    k_rd = stiffness[rest][:, dep]
    k_dr = stiffness[dep][:, rest]
    k_dd = stiffness[dep][:, dep].toarray()
    timing["assembly"] += time.perf_counter() - t0
    d_r, d_d, lam = np.zeros(len(rest)), np.zeros(nd), np.zeros(ncon)
    disp = np.zeros(n)
    history, inner_total = [], 0
    scale_length = model.node_s[-1] - model.node_s[0]
    with DirectSolver(len(rest), k_rr.row, k_rr.col, what="split iteration K_RR") as solver:
        t0 = time.perf_counter()
        solver.factorize(k_rr.data)
        timing["factorization"] += time.perf_counter() - t0
        dd_grad = np.zeros((nd, m))
        dd_grad[:, :nd] = np.eye(nd)
        d_d_jet = Jet(d_d, dd_grad, np.zeros((nd, m, m)))
        try:
            for outer in range(1, max_iter + 1):
                d_d_jet.value = d_d
                d_r_jet = Jet(d_r.copy(), np.zeros((len(rest), m)), np.zeros((len(rest), m, m)))
                for inner in range(1, max_inner + 1):
                    t0 = time.perf_counter()
                    d = Jet.zeros(n, m)
                    d.value[rest], d.grad[rest], d.hess[rest] = d_r_jet.value, d_r_jet.grad, d_r_jet.hess
                    d.value[dep], d.grad[dep] = d_d_jet.value, d_d_jet.grad
                    force = _force_jet(model, d, lam, nd)[rest]
                    rhs = force.stack()
                    rhs[:, :1 + m] -= np.hstack([(k_rd @ d_d)[:, None], k_rd @ dd_grad])
                    timing["assembly"] += time.perf_counter() - t0
                    t0 = time.perf_counter()
                    solved = Jet.unstack(solver.solve(rhs), m)
                    timing["solve"] += time.perf_counter() - t0
                    new = d_r_jet.combine(p, solved, 1.0 - p)
                    change = new.distance(d_r_jet)
                    d_r_jet = new
                    if change <= inner_tol * max(scale_length, 1.0):
                        break
                inner_total += inner
                # linearized D-equations and constraints in delta = (delta e_D, delta lambda)
                d = Jet.zeros(n, m)
                d.value[rest], d.grad[rest] = d_r_jet.value, d_r_jet.grad
                d.value[dep], d.grad[dep] = d_d, dd_grad
                force = _force_jet(model, d, lam, nd)[dep]
                r_value = k_dr @ d_r_jet.value + k_dd @ d_d - force.value
                r_grad = k_dr @ d_r_jet.grad + k_dd @ dd_grad - force.grad
                phi, rows, cols, grads = model.constraints.jacobian(model.e0 + d.value, n)
                phi_grad = np.zeros((ncon, m))
                np.add.at(phi_grad, rows, grads[:, None] * d.grad[cols])
                system = np.vstack([r_grad, phi_grad])
                try:
                    delta = np.linalg.solve(system, -np.concatenate([r_value, phi]))
                except np.linalg.LinAlgError:
                    raise SolverError("split iteration: the reduced system in (e_D, lambda) is "
                                      "singular; the dependent coordinates do not fit the "
                                      "constraints") from None
                d_r = d_r_jet.evaluate(delta)
                d_d = d_d + delta[:nd]
                lam = lam + delta[nd:]
                previous = disp
                disp = np.zeros(n)
                disp[rest], disp[dep] = d_r, d_d
                force_res, con_res = residuals(model, disp, lam, stiffness)
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
        finally:
            model.counters["factorizations"] += solver.factorizations
            model.counters["solves"] += solver.solves
    wall = time.perf_counter() - start
    timing["total"] = wall
    return StaticResult(model.e0 + disp, lam, "split", outer, force_res, con_res, wall, history, timing,
                        extra={"inner_iterations": inner_total, "p": p, "converged_by": how})


def solve_static(model: BeamModel, method: str, *, tol: float, max_iter: int,
                 p: float = 0.0) -> StaticResult:
    """Dispatch on ``solver.static_method``."""
    if method == "newton":
        return solve_newton(model, tol=tol, max_iter=max_iter)
    if method == "split":
        return solve_split(model, tol=tol, max_iter=max_iter, p=p)
    raise SolverError(f"unknown static method {method!r}")
