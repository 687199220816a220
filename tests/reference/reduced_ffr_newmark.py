"""The reduced FFR model's Newmark steps in numpy with full Newton: the reference the
kernel's loop (``kernel.reduced_ffr_newmark``, fortran/src/solvers/reduced_ffr_stepper.f90,
behind ``ancfdrv.solvers.ffr_reduced.simulate``: one LU while the frame's rate and
acceleration stay, simplified Newton for P-delta) is tested against
(tests/test_ffr_reduced.py).

The reduced equations (docs/theory.md, "Modal reduction of FFR bodies"),

    eta'' + 2 psi' Gam eta' + (Lam + psi'' Gam + psi'^2 C2) eta + R(eta) = g(t),
    g = -psi'' euler_load - psi'^2 centrifugal_load - sin psi gravity_sin
        + (1 - cos psi) gravity_cos,
    R = pdelta_linear eta + (pdelta_quadratic eta) eta,

are stepped here directly from their matrices, each step's Newton on the full Jacobian with
``numpy.linalg.solve``; only the reduced model's constant matrices (``ReducedFFR``) come
from the package. Never imported by a run.
"""
from __future__ import annotations

import numpy as np

from ancfdrv.errors import SolverError
from ancfdrv.solvers.ffr_reduced import ReducedFFR

__all__ = ["newmark_python"]


def newmark_python(reduced: ReducedFFR, t_end: float, dt: float, *, beta: float = 0.25,
                   gamma: float = 0.5, tol: float = 1e-9,
                   max_newton: int = 10) -> dict[str, np.ndarray]:
    """Newmark (beta, gamma) from the static state at rest (eta''(0) = g(0), the kernel's
    start too); returns 'time', 'eta', 'velocity' and each probe's deflection in the frame
    (name -> (steps + 1, 3)), as ``simulate`` does. Newton ends on a correction below tol
    times max(1, max |eta|)."""
    steps = int(round(t_end / dt))
    times = np.arange(steps + 1) * dt
    phi, rate, accel = reduced.drive.values(times)
    psi = phi - reduced.start_angle
    r = reduced.size
    lam = np.diag(reduced.omega_squared)
    gam, c2 = reduced.gyroscopic, reduced.centrifugal
    sin, cos1 = np.sin(psi), 1.0 - np.cos(psi)
    pd_lin, pd_quad = reduced.pdelta_linear, reduced.pdelta_quadratic
    force = (-accel[:, None] * reduced.euler_load - rate[:, None] ** 2 * reduced.centrifugal_load
             - sin[:, None] * reduced.gravity_sin + cos1[:, None] * reduced.gravity_cos)
    eta, vel, acc = np.zeros((steps + 1, r)), np.zeros(r), force[0].copy()
    velocity = np.zeros((steps + 1, r))
    a_fac, v_fac = 1.0 / (beta * dt * dt), gamma / (beta * dt)
    eye = np.eye(r)
    for n in range(steps):
        stiff = lam + accel[n + 1] * gam + rate[n + 1] ** 2 * c2
        damp = 2.0 * rate[n + 1] * gam
        base = eta[n] + dt * vel + dt * dt * (0.5 - beta) * acc
        vbase = vel + dt * (1.0 - gamma) * acc
        x = base + dt * dt * beta * acc  # predictor: the same acceleration
        jac_lin = a_fac * eye + v_fac * damp + stiff
        for _ in range(max_newton):
            a_new = (x - base) * a_fac
            v_new = vbase + dt * gamma * a_new
            res = a_new + damp @ v_new + stiff @ x - force[n + 1]
            jac = jac_lin
            if pd_lin is not None:
                tq = pd_quad @ x
                res = res + pd_lin @ x + tq @ x
                jac = jac_lin + pd_lin + tq + np.einsum("ijk,j->ik", pd_quad, x)
            dx = np.linalg.solve(jac, -res)
            x = x + dx
            if np.max(np.abs(dx)) <= tol * max(1.0, np.max(np.abs(x))):
                break
        else:
            raise SolverError(f"reduced FFR: Newton did not converge at t = {times[n + 1]:g}")
        acc = (x - base) * a_fac
        vel = vbase + dt * gamma * acc
        eta[n + 1] = x
        velocity[n + 1] = vel
    out: dict[str, np.ndarray] = {"time": times, "eta": eta, "velocity": velocity}
    for name, value in reduced.probe_static.items():
        out[name] = value + eta @ reduced.probe_basis[name].T
    return out
