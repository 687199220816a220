"""The static Newton assembled in Python: the reference the kernel's static Newton
(``ancfdrv.solvers.static.solve_newton``, fortran/src/solvers/static_solver.f90) is tested
against (tests/test_static_kernel.py, tests/test_static_small_loads.py) and compared with
by ``benchmarks/static_kernel_gate.py``.

Unlike the other modules here it is not written apart from ancfdrv: it is the package's
former Python Newton (issue 25 item 4 moved the iteration into the kernel), kept with the
tests because it assembles the same saddle-point system from separate pieces - the
kernel's force and tangent evaluations, Python's constraint Jacobians and Hessians, the
moments' and point loads' Jacobians - so a wrong sum or a missing term in the kernel's
one-call assembly shows as a difference. It shares the package's convergence test
(``static.converged``) and residual (``static.residuals``), which the split iteration uses
too. Never imported by a run.
"""
from __future__ import annotations

import time

import numpy as np

from ancfdrv.errors import SolverError
from ancfdrv.io.validate import check_arguments
from ancfdrv.kernel import DirectSolver
from ancfdrv.solvers.assumptions import check_ffr
from ancfdrv.solvers.static import StaticResult, converged, residuals
from ancfdrv.system.model import Model

__all__ = ["solve_newton_python", "residual_floor"]


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

    The Python implementation of the static Newton, the reference the kernel's
    (``ancfdrv.solvers.static.solve_newton``) is tested against: the same residual,
    saddle-point matrix and convergence test, assembled here from the kernel's force
    evaluations."""
    check_arguments("solve_newton", tol=tol, max_iter=max_iter, load_steps=load_steps,
                    loads=loads)
    model.require_runnable()
    start = time.perf_counter()
    timing = {"assembly": 0.0, "factorization": 0.0, "solve": 0.0}
    n, ncon = model.ndof, len(model.constraints)
    d, lam = np.zeros(n), np.zeros(ncon)
    t0 = time.perf_counter()
    h_con, h_rows, h_cols, h_vals = model.constraints.hessian_triplets(model.e0)
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
