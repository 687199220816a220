"""Modal reduction of an FFR model in one prescribed frame (issue 23, item 2; docs/theory.md,
"Modal reduction of FFR bodies"). A prototype beside the kernel's stepper: Python, the
luffing boom's class of models, not wired to scenes.

Scope (refused otherwise, :class:`~ancfdrv.errors.SolverError`): every element set 'ffr' in
one frame turned by a drive about a fixed axis k through a pivot p (A(t) = Rot(k, psi(t))
A(0), psi = phi - phi(0)), constraints that the rigidly turned static state keeps (they
are fixed in the frame: the boom's arm and driven A2), dead moments about k, constant
loads, no material damping, no eliminated joints.

In the coordinates of the frame at t = 0, x (e = p^ + U(psi) (x - p^), U = Rot(k, psi) on
every nodal 3-vector, p^ the pivot on the position slots), with W = [k x] per 3-vector,
U^T M U = M and the FFR forces equivariant, the equations of motion are

    M (x'' + 2 psi' W x' + (psi'' W + psi'^2 W^2)(x - p^)) + F(x) = U^T Q + G^T lambda,
    U^T Q = Q - sin psi W Q + (1 - cos psi) W^2 Q.

About the static state (x*, lambda*) at psi = 0, F(x*) = Q + G^T lambda*, they are
linearized (K: the static Newton block, with the constraints' Hessians and the moments'
load stiffness; the P-delta part N* G too when the beams have it) on the null space of the
constraint gradients G, and x = x* + Psi eta with Psi = [component modes, static
corrections], made M-orthonormal and K-diagonal by a Rayleigh-Ritz step: the lowest `modes`
constrained modes of (K, M) and the static responses K^-1 f (on the null space) to the
frame's load patterns W Q, W^2 Q, M W (x* - p^), M W^2 (x* - p^). The Ritz values contain
the kept modes' omega^2 exactly. Reduced equations, all matrices constant:

    eta'' + 2 psi' Gam eta' + (Lam + psi'' Gam + psi'^2 C2) eta + R(eta) = g(t),
    Gam = Psi^T M W Psi,  C2 = Psi^T M W^2 Psi,
    g = -psi'' Psi^T M W (x* - p^) - psi'^2 Psi^T M W^2 (x* - p^)
        - sin psi Psi^T W Q + (1 - cos psi) Psi^T W^2 Q,

R the P-delta remainder beyond K's N* G (beams with geometric_stiffness): per element
N = n* + d . eta, force (n* + d . eta)(c + B eta) with B = P^T G P, c = P^T G u*, so
R = C eta + T(eta, eta), C = sum c d^T, T_ijk = sum B_ij d_k (constant). Newmark
(beta, gamma) with Newton on the r x r system (full Jacobian, LU).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .. import kernel
from ..errors import SolverError
from ..system.drives import Drive
from ..system.model import Model
from .modal import linearize, null_space
from .static import StaticResult
from .._lazy import LazyModule

# imported on first use (ancfdrv._lazy): ~10 MB most runs never need
la = LazyModule("scipy.linalg")


@dataclass
class ReducedFFR:
    """Constant reduced matrices of an FFR model in one prescribed frame (module doc)."""

    basis: np.ndarray            # Psi (ndof, r), M-orthonormal
    omega_squared: np.ndarray    # Ritz values (r,), ascending; the kept modes' exactly
    kept_omega_squared: np.ndarray  # the full model's constrained omega^2 of the kept modes
    gyroscopic: np.ndarray       # Gam (r, r)
    centrifugal: np.ndarray      # C2 (r, r)
    euler_load: np.ndarray       # Psi^T M W (x* - p^)
    centrifugal_load: np.ndarray  # Psi^T M W^2 (x* - p^)
    gravity_sin: np.ndarray      # Psi^T W Q
    gravity_cos: np.ndarray      # Psi^T W^2 Q
    drive: Drive
    start_angle: float
    probe_static: dict[str, np.ndarray]   # deflection at x*
    probe_basis: dict[str, np.ndarray]    # (3, r) deflection per unit eta
    pdelta_linear: np.ndarray | None = None   # C (r, r)
    pdelta_quadratic: np.ndarray | None = None  # T (r, r, r)
    modes: int = 0
    timing: dict[str, float] = field(default_factory=dict)
    #: the expansion back to the full coordinates (:func:`expand`): x*, the pivot on the
    #: position slots p^, the frame's unit axis k
    static_state: np.ndarray | None = None
    pivot_vector: np.ndarray | None = None
    axis: np.ndarray | None = None

    @property
    def size(self) -> int:
        return self.basis.shape[1]


def _blocks(vectors: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """matrix applied to every 3-vector of vectors (n,) or (n, m)."""
    shaped = vectors.reshape(-1, 3, *vectors.shape[1:])
    return np.einsum("ij,bj...->bi...", matrix, shaped).reshape(vectors.shape)


def reduce_ffr(model: Model, static: StaticResult, modes: int, *,
               static_correction: bool = True) -> ReducedFFR:
    """The reduced model with the lowest ``modes`` constrained modes about ``static`` (the
    equilibrium at t = 0) plus the static correction modes (module doc)."""
    t0 = time.perf_counter()
    _check_scope(model, static)
    frame = model.frames[0]
    k = frame.axis / np.linalg.norm(frame.axis)
    skew = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    n = model.ndof
    x_star = static.e
    pivot = np.zeros(n)
    pivot.reshape(-1, 4, 3)[:, 0, :] = frame.pivot
    lin = linearize(model, x_star, static.lam, 0.0)
    stiffness, mass = lin.stiffness.toarray(), lin.mass.toarray()
    null = null_space(lin.constraints, n)
    k_c, m_c = null.T @ stiffness @ null, null.T @ mass @ null
    w2, vectors = la.eigh(k_c, m_c)
    if modes < 1 or modes > len(w2):
        raise SolverError(f"reduce_ffr: modes = {modes} outside 1..{len(w2)}")
    columns = [null @ vectors[:, :modes]]
    load = model.constant_force()
    w_load, w2_load = _blocks(load, skew), _blocks(load, skew @ skew)
    arm = x_star - pivot
    euler, centrifugal = mass @ _blocks(arm, skew), mass @ _blocks(arm, skew @ skew)
    if static_correction:
        patterns = np.column_stack([w_load, w2_load, euler, centrifugal])
        corrections = null @ la.solve(k_c, null.T @ patterns, assume_a="sym")
        columns.append(corrections)
        # P-delta: the axial forces of those responses acting on the static slopes
        pdelta = _pdelta_patterns(model, x_star, corrections)
        if pdelta is not None:
            columns.append(null @ la.solve(k_c, null.T @ pdelta, assume_a="sym"))
    basis = np.column_stack(columns)
    # Rayleigh-Ritz: M-orthonormal, K-diagonal; drop directions the basis repeats
    m_r = basis.T @ mass @ basis
    s, u = la.eigh(m_r)
    keep = s > 1e-12 * s.max()
    basis = basis @ (u[:, keep] / np.sqrt(s[keep]))
    ritz, z = la.eigh(basis.T @ stiffness @ basis)
    basis = basis @ z
    reduced = ReducedFFR(
        basis=basis, omega_squared=ritz, kept_omega_squared=w2[:modes],
        gyroscopic=basis.T @ mass @ _blocks(basis, skew),
        centrifugal=basis.T @ mass @ _blocks(basis, skew @ skew),
        euler_load=basis.T @ euler, centrifugal_load=basis.T @ centrifugal,
        gravity_sin=basis.T @ w_load, gravity_cos=basis.T @ w2_load,
        drive=frame.drive_obj, start_angle=frame.drive_obj.value(0.0),
        probe_static={}, probe_basis={}, modes=modes, static_state=x_star.copy(),
        pivot_vector=pivot, axis=k)
    static_defl = model.deflections_at(x_star, 0.0)
    for name, value in static_defl.items():
        reduced.probe_static[name] = value
        reduced.probe_basis[name] = np.column_stack([
            model.deflections_at(x_star + basis[:, i], 0.0)[name] - value
            for i in range(basis.shape[1])])
    _pdelta_terms(model, reduced, x_star)
    reduced.timing["reduce"] = time.perf_counter() - t0
    return reduced


def _check_scope(model: Model, static: StaticResult) -> None:
    if len(model.frames) != 1 or model.frames[0].drive_obj is None:
        raise SolverError("reduce_ffr: the model needs exactly one frame, turned by a drive")
    if any(s.kind != "ffr" or s.frame != 1 for s in model.sets):
        raise SolverError("reduce_ffr: every element set must be 'ffr' in the driven frame")
    if model.reduction is not None or model.damped or model.vector_loads or \
            model.contact_pairs or model.driven_forces:
        raise SolverError("reduce_ffr: eliminated joints, damping, driven or follower loads "
                          "and contact are outside its scope")
    frame = model.frames[0]
    k = frame.axis / np.linalg.norm(frame.axis)
    for m in model.moments:
        if abs(abs(np.dot(m.axis, k)) - np.linalg.norm(m.axis)) > 1e-12 * np.linalg.norm(m.axis):
            raise SolverError(f"reduce_ffr: moment {m.name!r} is not about the frame's axis")
    # the constraints must hold on the rigidly turned static state (fixed in the frame)
    n = model.ndof
    pivot = np.zeros(n)
    pivot.reshape(-1, 4, 3)[:, 0, :] = frame.pivot
    start = frame.drive_obj.value(0.0)
    from ..system.bodies import rotation_about
    for t in (0.37, 1.9, 4.1, 1e3):
        turn = rotation_about(k, frame.drive_obj.value(t) - start)
        e = pivot + _blocks(static.e - pivot, turn)
        phi = model.constraints.jacobian(e, n, t)[0]
        if len(phi) and np.max(np.abs(phi)) > 1e-9 * max(model.length_scale, 1.0) ** 2:
            raise SolverError("reduce_ffr: the constraints are not fixed in the frame (the "
                              f"turned static state violates them by {np.max(np.abs(phi)):.2e} "
                              f"at t = {t})")


def _pdelta_elements(model: Model, x_star: np.ndarray, basis: np.ndarray):
    """Per element of the sets with second_order: its coordinates, the frame displacement
    u* = A0^T x* - reference, the basis columns in the frame P = A0^T basis, G (x) I3 and
    the axial force per column dN = EA (chord . P) / L."""
    rotation = model.frames[0].rotation(0.0)
    for s in model.sets:
        if s.second_order is None:
            continue
        rigidity, axis, length, gram = s.second_order
        for el in range(s.nel):
            dofs = s.dofs[:, el]
            u_star = _blocks(x_star[dofs], rotation.T) - s.reference[:, el]
            p = _blocks(basis[dofs], rotation.T)
            d_n = rigidity[el] * (axis[:, el] @ (p[12:15] - p[0:3])) / length[el]
            yield dofs, u_star, p, np.kron(gram[:, :, el], np.eye(3)), d_n


def _pdelta_patterns(model: Model, x_star: np.ndarray, responses: np.ndarray
                     ) -> np.ndarray | None:
    """Per response column delta: the P-delta force of its axial forces on the static
    state's slopes, sum over elements dN(delta) A0 (G (x) I3) u* (None: no P-delta)."""
    rotation = model.frames[0].rotation(0.0)
    out = np.zeros((model.ndof, responses.shape[1]))
    found = False
    for dofs, u_star, _, g24, d_n in _pdelta_elements(model, x_star, responses):
        found = True
        np.add.at(out, dofs, np.outer(_blocks(g24 @ u_star, rotation), d_n))
    return out if found else None


def _pdelta_terms(model: Model, reduced: ReducedFFR, x_star: np.ndarray) -> None:
    """C and T of the P-delta remainder (module doc) for sets with second_order."""
    r = reduced.size
    linear, quadratic = np.zeros((r, r)), np.zeros((r, r, r))
    found = False
    for _, u_star, p, g24, d in _pdelta_elements(model, x_star, reduced.basis):
        found = True
        linear += np.outer(p.T @ g24 @ u_star, d)
        quadratic += (p.T @ g24 @ p)[:, :, None] * d[None, None, :]
    if found:
        reduced.pdelta_linear, reduced.pdelta_quadratic = linear, quadratic


def simulate(reduced: ReducedFFR, t_end: float, dt: float, *, beta: float = 0.25,
             gamma: float = 0.5, tol: float = 1e-9, max_newton: int = 10,
             engine: str = "kernel") -> dict[str, np.ndarray]:
    """Newmark (beta, gamma) from the static state at rest (the start's acceleration the
    consistent one, eta''(0) = g(0)); returns 'time', 'eta', 'velocity' (eta'), each
    probe's deflection in the frame (name -> (steps + 1, 3)) and, from the kernel, per step
    'corrections' (Newton) and 'factorized' (0 or 1). engine 'kernel': the Fortran
    loop (kernel.reduced_ffr_newmark); 'python': the same steps in numpy with full Newton
    (the reference of the test). tol: P-delta's Newton ends on a correction below tol times
    max(1, max |eta|) (the linear model's one solve is exact); on the boom 1e-9 moves the
    tip by 4e-12 m from 1e-14, 1e-6 by 1.1e-9 m (measured)."""
    t0 = time.perf_counter()
    steps = int(round(t_end / dt))
    times = np.arange(steps + 1) * dt
    phi, rate, accel = reduced.drive.values(times)
    psi = phi - reduced.start_angle
    r = reduced.size
    lam = np.diag(reduced.omega_squared)
    gam, c2 = reduced.gyroscopic, reduced.centrifugal
    force = (-accel[:, None] * reduced.euler_load - rate[:, None] ** 2 * reduced.centrifugal_load
             - np.sin(psi)[:, None] * reduced.gravity_sin
             + (1.0 - np.cos(psi))[:, None] * reduced.gravity_cos)
    pd_lin, pd_quad = reduced.pdelta_linear, reduced.pdelta_quadratic
    if engine == "kernel":
        steps_out = kernel.reduced_ffr_newmark(dt, beta, gamma, reduced.omega_squared, gam,
                                               c2, pd_lin, pd_quad, force, rate, accel, tol,
                                               max_newton)
        return _finish(reduced, times, steps_out["eta"], t0, steps_out)
    if engine != "python":
        raise SolverError(f"simulate: engine {engine!r} must be 'kernel' or 'python'")
    # at rest in the static state: eta'' = g(0) (the kernel's start too)
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
    return _finish(reduced, times, eta, t0, {"velocity": velocity})


def _finish(reduced: ReducedFFR, times: np.ndarray, eta: np.ndarray, t0: float,
            extra: dict[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {"time": times, "eta": eta}
    for key in ("velocity", "corrections", "factorized"):
        if extra is not None and key in extra:
            out[key] = extra[key]
    for name, value in reduced.probe_static.items():
        out[name] = value + eta @ reduced.probe_basis[name].T
    reduced.timing["simulate"] = time.perf_counter() - t0
    return out


# -- the scene path: &beam modes = N (runner, System.simulate) -------------------------------
#: what a reduced run's file cannot hold (the reduced model has no multipliers): the
#: /dynamic attribute ``not_provided`` and the README say so
NOT_PROVIDED = ("lambda (NaN: the reduced model has no multipliers), energy/drive_work and "
                "energy/balance (NaN: the drive's power needs the multipliers), reactions, "
                "section forces and stresses (/dynamic/reactions, sections, stress not "
                "written)")


def check_scope(model: Model, static: StaticResult) -> None:
    """The prototype's scope checks (SolverError with its messages) on a state the
    constraints hold at t = 0 (the static start, or the assembled configuration before the
    static solve)."""
    _check_scope(model, static)


def _turn(vectors: np.ndarray, axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rot(axis, angle[i]) applied to every 3-vector of row i of vectors (nt, n)."""
    y = vectors.reshape(len(vectors), -1, 3)
    skew = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]],
                     [-axis[1], axis[0], 0.0]])
    # Rodrigues per row: I + sin W + (1 - cos) W^2, applied to every 3-vector at once
    turn = (np.eye(3)[None] + np.sin(angle)[:, None, None] * skew[None]
            + (1.0 - np.cos(angle))[:, None, None] * (skew @ skew)[None])
    return np.matmul(y, np.transpose(turn, (0, 2, 1))).reshape(vectors.shape)


def expand(reduced: ReducedFFR, times: np.ndarray, eta: np.ndarray, velocity: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """The full coordinates and their rates of reduced states (rows of eta, eta'):
    e = p^ + U(psi) (x* + Psi eta - p^), e' = psi' k x (e - p^) + U(psi) Psi eta'."""
    phi, rate, _ = reduced.drive.values(times)
    psi = phi - reduced.start_angle
    k = reduced.axis
    arm = _turn((reduced.static_state - reduced.pivot_vector)[None, :] + eta @ reduced.basis.T,
                k, psi)
    e = reduced.pivot_vector[None, :] + arm
    v = _turn(velocity @ reduced.basis.T, k, psi)
    skew = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    v += rate[:, None] * (arm.reshape(len(arm), -1, 3) @ skew.T).reshape(arm.shape)
    return e, v


def integrate_reduced(model: Model, reduced: ReducedFFR, settings, *, sink=None,
                      progress: bool | None = None, should_stop=None):
    """A dynamic run of the reduced model with the output of the full one: the reduced
    history from the kernel's stepper (:func:`simulate`, Newmark with settings' beta,
    gamma, tol, max_newton), then, per output chunk of settings.chunk_steps rows, the full
    coordinates (:func:`expand`) and each row's probes, deflections, energies and
    constraint violation from the kernel's output row (the full run's definitions), sent to
    ``sink`` as :class:`~.dynamic.Chunk` (with q when settings.store_q: the XDMF frames,
    output.q; the small-strain check then looks at every row, else at each chunk's last
    state, as the full run does). The frame's work is the trapezoidal integral of
    its power (as the kernel's stepper integrates it); lambda, the drive's work and the
    energy balance are NaN (:data:`NOT_PROVIDED`). Returns a
    :class:`~.dynamic.DynamicResult`; an 'ffr' beam leaving its small-strain assumption
    ends the run as the full one does."""
    from ..errors import Interrupted
    from .dynamic import Chunk, DynamicResult, _check_assumptions
    start = time.perf_counter()
    timing = {"setup": reduced.timing.get("reduce", 0.0), "stepping": 0.0, "output": 0.0}
    out = simulate(reduced, settings.t_end, settings.dt, beta=settings.beta,
                   gamma=settings.gamma, tol=settings.tol, max_newton=settings.max_newton)
    timing["stepping"] = reduced.timing["simulate"]
    times, eta, velocity = out["time"], out["eta"], out["velocity"]
    stats = np.column_stack([out["corrections"], out["factorized"], out["factorized"]])
    ncon, nrows = len(model.constraints), len(times)
    no_work = np.zeros(5)
    guesses = model.contact_guesses.copy()
    counts = np.zeros(6, dtype=np.int32)
    frame_work, last_power = 0.0, None
    rows_done = 0
    step = max(1, int(settings.chunk_steps))
    try:
        for first in range(0, nrows, step):
            t1 = time.perf_counter()
            rows = slice(first, min(first + step, nrows))
            e, v = expand(reduced, times[rows], eta[rows], velocity[rows])
            n = len(e)
            probes = np.zeros((n, model.kernel.nprobe, 3))
            deflections = np.zeros_like(probes)
            energy = np.zeros((n, 11))
            violation, power = np.zeros(n), np.zeros(n)
            for i in range(n):
                row = model.kernel.output_row(float(times[first + i]), e[i], v[i],
                                              np.zeros(ncon), no_work, guesses, counts)
                probes[i], deflections[i] = row["probes"], row["deflections"]
                energy[i], violation[i] = row["energy"], row["violation"]
                power[i] = row["powers"][1]
            # frame work: the trapezoidal rule over the rows (the stepper's rule)
            previous = power[0] if last_power is None else last_power
            increments = 0.5 * settings.dt * (np.concatenate([[previous], power[:-1]]) + power)
            if last_power is None:
                increments[0] = 0.0
            work = frame_work + np.cumsum(increments)
            frame_work, last_power = float(work[-1]), float(power[-1])
            energy[:, 6] = work
            energy[:, 5] = np.nan
            chunk = Chunk(time=times[rows].copy(), probes=probes, deflections=deflections,
                          lam=np.full((n, ncon), np.nan), energy=energy, constraint=violation,
                          stats=stats[rows].copy(), q=e if settings.store_q else None)
            chunk, outside = _check_assumptions(model, chunk,
                                                {"e": e[-1], "t": float(times[rows][-1])},
                                                False)
            if sink is not None and len(chunk.time):
                sink(chunk)
            rows_done += len(chunk.time)
            timing["output"] += time.perf_counter() - t1
            if outside:
                raise SolverError(outside)
            if should_stop is not None and should_stop() and rows_done < nrows:
                raise Interrupted(f"stopped at t = {times[rows_done - 1]:.6g} s after "
                                  f"{rows_done - 1} steps")
    finally:
        steps = max(rows_done - 1, 0)
        newton = int(stats[:rows_done, 0].sum())
        factorizations = int(stats[:rows_done, 1].sum())
        model.counters["time_steps"] += steps
        model.counters["newton_iterations"] += newton
        model.counters["solves"] += newton
        model.counters["factorizations"] += factorizations
        model.counters["jacobian_evaluations"] += factorizations
        model.counters["steps_taken"] = model.counters.get("steps_taken", 0) + steps
        model.counters["reduced_coordinates"] = reduced.size
    wall = time.perf_counter() - start
    timing["total"] = wall
    return DynamicResult(steps=steps, newton_iterations=newton, factorizations=factorizations,
                         wall_time_s=wall, timing=timing, jacobians=factorizations,
                         steps_taken=steps, smallest_step=settings.dt if steps else 0.0)
