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
from dataclasses import field

import numpy as np

from ..records import record
from .. import kernel
from ..codes import KERNEL_LAYOUTS
from ..errors import SolverError
from ..system.drives import Drive
from ..system.model import Model
from .modal import linearize, null_space
from .static import StaticResult
from .._lazy import LazyModule

# imported on first use (ancfdrv._lazy): ~10 MB most runs never need
la = LazyModule("scipy.linalg")


@record
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
    #: the constant maps of the output rows (:class:`RowMaps`; None: the row by row path)
    row_maps: "RowMaps | None" = None

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
    if RowMaps.supported(model):   # constants of the reduced model, like probe_basis
        reduced.row_maps = RowMaps(model, reduced)
    reduced.timing["reduce"] = time.perf_counter() - t0
    return reduced


def _check_scope(model: Model, static: StaticResult) -> None:
    if len(model.frames) != 1 or model.frames[0].drive_obj is None:
        raise SolverError("reduce_ffr: the model needs exactly one frame, turned by a drive")
    if any(not s.floating or s.frame != 1 for s in model.sets):
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
             frame: dict | None = None) -> dict[str, np.ndarray]:
    """Newmark (beta, gamma) from the static state at rest (the start's acceleration the
    consistent one, eta''(0) = g(0)); returns 'time', 'eta', 'velocity' (eta'), each
    probe's deflection in the frame (name -> (steps + 1, 3)) and, from the kernel, per step
    'corrections' (Newton) and 'factorized' (0 or 1): the Fortran loop
    (kernel.reduced_ffr_newmark; tests/reference/reduced_ffr_newmark.py takes the same steps
    in numpy with full Newton, the reference of its test). tol: P-delta's Newton ends on a
    correction below tol times max(1, max |eta|) (the linear model's one solve is exact); on
    the boom 1e-9 moves the tip by 4e-12 m from 1e-14, 1e-6 by 1.1e-9 m (measured). ``frame``: a dict that
    receives the frame's values at the times, 'angle' (phi), 'rate', 'sin' and
    'one_minus_cos' (of psi = phi - phi(0)), for the output rows (RowMaps.rows)."""
    t0 = time.perf_counter()
    steps = int(round(t_end / dt))
    times = np.arange(steps + 1) * dt
    phi, rate, accel = reduced.drive.values(times)
    psi = phi - reduced.start_angle
    gam, c2 = reduced.gyroscopic, reduced.centrifugal
    sin, cos1 = np.sin(psi), 1.0 - np.cos(psi)
    if frame is not None:
        frame.update(angle=phi, rate=rate, sin=sin, one_minus_cos=cos1)
    pd_lin, pd_quad = reduced.pdelta_linear, reduced.pdelta_quadratic
    # the load g(t) formed in the stepper, step by step, from its four constant patterns
    patterns = np.column_stack([reduced.euler_load, reduced.centrifugal_load,
                                reduced.gravity_sin, reduced.gravity_cos])
    steps_out = kernel.reduced_ffr_newmark(dt, beta, gamma, reduced.omega_squared, gam,
                                           c2, pd_lin, pd_quad, patterns, rate, accel,
                                           sin, cos1, tol, max_newton)
    return _finish(reduced, times, steps_out["eta"], t0, steps_out)


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
    skew = _skew(axis)
    return _turned(vectors, np.sin(angle), 1.0 - np.cos(angle), skew.T, (skew @ skew).T)


def _turned(vectors: np.ndarray, sin: np.ndarray, one_minus_cos: np.ndarray,
            skew_t: np.ndarray, skew2_t: np.ndarray) -> np.ndarray:
    """Rodrigues per row, (I + sin W + (1 - cos) W^2) v = v + sin W v + (1 - cos) W^2 v on
    every 3-vector v of row i of vectors (nt, n): W^T and (W^2)^T each applied to all the
    rows' vectors in one product (a 3 x 3 product per row cost ~3,500 instructions each).
    The one arithmetic of expand() and RowMaps' needed coordinates."""
    nt = len(vectors)
    flat = vectors.reshape(-1, 3)
    return vectors + ((flat @ skew_t).reshape(nt, -1) * sin[:, None]
                      + (flat @ skew2_t).reshape(nt, -1) * one_minus_cos[:, None])


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


def _skew(k: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])


def _vector_slots(dofs) -> np.ndarray:
    """The full coordinates of the 3-vectors holding ``dofs`` (sorted, each vector once)."""
    first = np.unique(np.asarray(dofs, dtype=np.int64) // 3) * 3
    return (first[:, None] + np.arange(3)).reshape(-1)


class ExpandedRows:
    """The full coordinates of rows of a reduced history (:func:`expand`), expanded only
    for the rows asked for: ``rows[-1]``, ``rows[mask]``, ``rows[a:b]`` expand those rows;
    anything else (``np.asarray``) expands all. What the writer needs of a reduced run's q
    (the XDMF frames, every stride-th row, and the last row) costs a few rows, not 10,000
    (the expansion of every row was a third of the 20 ms the 10 s boom may cost)."""

    def __init__(self, reduced: ReducedFFR, times: np.ndarray, eta: np.ndarray) -> None:
        self.reduced, self.times, self.eta = reduced, times, eta
        self.shape = (len(times), reduced.basis.shape[0])
        self.ndim, self.dtype = 2, np.dtype(float)
        self.nbytes = self.times.nbytes + self.eta.nbytes

    def __len__(self) -> int:
        return len(self.times)

    def __getitem__(self, index):
        if isinstance(index, tuple):   # rows and columns: every row expanded
            return np.asarray(self)[index]
        rows = np.arange(len(self.times))[index]
        single = np.ndim(rows) == 0
        rows = np.atleast_1d(rows)
        e, _ = expand(self.reduced, self.times[rows], self.eta[rows],
                      np.zeros_like(self.eta[rows]))
        return e[0] if single else e

    def __array__(self, dtype=None, copy=None):
        e = self[:]
        return e if dtype is None else e.astype(dtype)


class RowMaps:
    """Constant maps from the reduced states (eta, eta') at the frame angle psi to a full
    run's output row (:meth:`rows`), built once per run (docs/theory.md, modal reduction):
    with y = x* - p^ + Psi eta in the frame at t = 0, e = p^ + U(psi) y and
    e' = U(psi) (psi' W y + Psi eta') (U = Rot(k, psi) on every 3-vector, W = [k x]):

    - probes, moment directors, constrained coordinates: e at those coordinates only,
      expanded as :func:`expand` expands every coordinate, then the kernel's formulas;
    - kinetic energy 1/2 e'^T M e' = 1/2 z^T M z (U^T M U = M) with z linear in
      c = (psi', psi' eta, eta'): a Gram matrix of size 1 + 2r;
    - strain energy and the frame's power (the kernel's FFR sets: u = A^T e - u_ref per
      element, 1/2 u^T K0 u and -psi' sum (K0 u) . (k x (u + u_ref))), A = U(psi) A0: u is
      linear in (1, sin psi, 1 - cos psi, eta), so each is a quadratic form of size 3 + r;
    - the loads' potential -Q . e: linear in (1, sin psi, 1 - cos psi) x (1, eta).
    """

    def __init__(self, model: Model, reduced: ReducedFFR) -> None:
        self.model, self.reduced = model, reduced
        basis, n = reduced.basis, reduced.basis.shape[0]
        r = basis.shape[1]
        k = reduced.axis
        skew = _skew(k)
        pivot = reduced.pivot_vector
        a0 = reduced.static_state - pivot
        frame = model.frames[0]
        self.base0 = frame.rotation(0.0)            # A0: the frame at t = 0 (psi = 0)
        # coordinates whose values the output needs one by one
        self.probes = list(model.probes.items())
        probe_dofs = [d + j for _, p in self.probes for d, _ in p.terms for j in range(3)]
        moment_dofs = [d for m in model.moments for d in m.dofs]
        lay = model.constraints.layout()
        constraint_dofs = list(lay.term_dof)
        self.slots = _vector_slots(probe_dofs + moment_dofs + constraint_dofs) \
            if probe_dofs + moment_dofs + constraint_dofs else np.zeros(0, dtype=np.int64)
        self.slot_of = {int(d): i for i, d in enumerate(self.slots)}
        self.sub_a0, self.sub_basis = a0[self.slots], basis[self.slots]
        self.sub_pivot = pivot[self.slots]
        # kinetic energy: z = psi' W a0 + psi' W Psi eta + Psi eta'
        z = np.column_stack([_blocks(a0, skew), _blocks(basis, skew), basis])
        self.kinetic = z.T @ (model.mass @ z)
        # strain energy and frame power of the FFR sets: per element u = L c,
        # c = (1, sin, 1 - cos, eta); x = u + u_ref = X c
        self.strain = np.zeros((3 + r, 3 + r))
        self.power = np.zeros((3 + r, 3 + r))
        # P-delta (sets with second_order): per element N = n . c and the energy
        # N c^T Q c, the power psi' N c^T P c: cubic forms, summed into tensors over c
        cubic_energy = np.zeros((3 + r, 3 + r, 3 + r))
        cubic_power = np.zeros((3 + r, 3 + r, 3 + r))
        self.cubic = None
        a_t = self.base0.T
        k_frame = _skew(frame.axis / np.linalg.norm(frame.axis))

        def per_vector(matrix: np.ndarray, v: np.ndarray) -> np.ndarray:
            """matrix applied to every 3-vector of v (nel, 24, ...)."""
            return np.matmul(matrix, v.reshape(v.shape[0], 8, 3, -1)).reshape(v.shape)
        for info in model.sets:
            dofs = info.dofs.T                                   # (nel, 24)
            ref = info.reference.T                               # (nel, 24)
            # A^T p^ = A0^T U^T p^ = A0^T (p^ - sin W p^ + (1 - cos) W^2 p^)
            p_el = pivot[dofs][:, :, None]
            lin = np.concatenate([
                per_vector(a_t, p_el + a0[dofs][:, :, None]) - ref[:, :, None],
                -per_vector(a_t, per_vector(skew, p_el)),
                per_vector(a_t, per_vector(skew @ skew, p_el)),
                per_vector(a_t, basis[dofs])], axis=2)           # (nel, 24, 3 + r)
            forced = np.matmul(info.stiffness0.transpose(2, 0, 1), lin)      # K0 u per c
            width = lin.shape[2]
            self.strain += 0.5 * lin.reshape(-1, width).T @ forced.reshape(-1, width)
            x = lin.copy()
            x[:, :, 0] += ref
            kx = per_vector(k_frame, x)                          # k x (u + u_ref)
            self.power -= forced.reshape(-1, width).T @ kx.reshape(-1, width)
            if info.second_order is not None:   # ffr_elastic.ffr_second_order
                rigidity, axis, length, gram = info.second_order
                chord = np.zeros((info.nel, 24))
                chord[:, 12:15], chord[:, 0:3] = axis.T, -axis.T
                axial = rigidity[:, None] * np.matmul(chord[:, None, :], lin)[:, 0] \
                    / length[:, None]                            # N = axial . c
                g24 = np.einsum("abe,ij->eaibj", gram, np.eye(3)).reshape(info.nel, 24, 24)
                bent = np.matmul(g24, lin)                       # (G x I3) u per c
                for tensor, left, right, factor in ((cubic_energy, lin, bent, 0.5),
                                                    (cubic_power, bent, kx, -1.0)):
                    pair = np.matmul(left.transpose(0, 2, 1), right)     # (nel, m, m)
                    tensor += factor * (pair.reshape(info.nel, -1).T @ axial).reshape(
                        tensor.shape)
        if any(info.second_order is not None for info in model.sets):
            self.cubic = _cubic_table(cubic_energy, cubic_power)
        # loads' potential: -Q . (p^ + y + sin W y + (1 - cos) W^2 y)
        load = model.constant_force()
        self.load_constant = -float(load @ pivot)
        rows = np.vstack([load, -_blocks(load, skew), _blocks(load, skew @ skew)])  # W^T = -W
        self.load_linear = -np.column_stack([rows @ a0, rows @ basis])       # (3, 1 + r)
        # the turn of the needed coordinates (_block): W^T and (W^2)^T
        self.skew_t, self.skew2_t = skew.T.copy(), (skew @ skew).T.copy()
        # the kernel's reduced_ffr_energy_rows: the forms, Fortran ordered, once
        from ..kernel import _f, _kernel, constraint_arrays
        used, table = self.cubic if self.cubic is not None else \
            (np.zeros(0, dtype=np.int64), np.zeros((1, 2)))
        self._kernel = _kernel
        self._energy_args = (
            _f(self.kinetic), _f(self.strain), _f(self.power),
            _f(np.asarray(used) + 1, np.int32) if len(used) else np.zeros(0, np.int32),
            _f(table), float(self.load_constant), _f(self.load_linear.T))
        # the constraints on the coordinates self.slots (the kernel's layout, renumbered)
        self.ncon = len(model.constraints)
        if self.ncon:
            cs = model.constraints
            ptr = np.concatenate([[0], np.cumsum([len(q) for q in cs.drive_params])]) + 1
            data = np.concatenate([np.asarray(q, dtype=float) for q in cs.drive_params]) \
                if cs.drive_params else np.zeros(1)
            kinds = np.array(cs.drive_kinds or [0], dtype=np.int32)
            local = np.array([self.slot_of[int(d)] for d in lay.term_dof], dtype=np.int64)
            self._constraint_args = (*constraint_arrays(
                lay.kinds, lay.drives + 1, lay.params, lay.operand_const, lay.term_ptr + 1,
                local + 1 if len(local) else np.ones(1),
                lay.term_coef if len(lay.term_coef) else np.zeros(1), kinds,
                ptr if len(cs.drive_kinds) else np.ones(2), data), len(lay.kinds))

    @staticmethod
    def supported(model: Model) -> bool:
        """Whether the maps hold every term of the kernel's output row (else: the row by
        row path): FFR sets (P-delta included) without damping, no force elements, no
        contact, no eliminated joints."""
        return (all(s.floating and s.damping_time == 0.0 for s in model.sets)
                and not getattr(model, "force_elements", ()) and not model.contact_pairs
                and not model.vector_loads and model.reduction is None)

    def rows(self, times: np.ndarray, eta: np.ndarray, velocity: np.ndarray,
             frame: dict | None = None) -> dict:
        """Probes (n, nprobe, 3), deflections, energy (n, 11) without the works, the
        constraint violation (n,) and the frame's power (n,) at the rows: in blocks of
        ROW_BLOCK rows, whose temporaries (~250 kB at most) stay in the cache and are reused
        by the allocator (blocks of 10,000 rows page-faulted a fresh mapping for each).
        ``frame``: the frame's values at these times as :func:`simulate` gives them
        ('angle', 'rate', 'sin', 'one_minus_cos'; None: evaluated here, the same values)."""
        n = len(times)
        out = dict(probes=np.zeros((n, len(self.probes), 3)),
                   deflections=np.zeros((n, len(self.probes), 3)), energy=np.zeros((n, 11)),
                   violation=np.zeros(n), power=np.zeros(n))
        for a in range(0, n, ROW_BLOCK):
            b = slice(a, a + ROW_BLOCK)
            part = None if frame is None else {k: v[b] for k, v in frame.items()}
            for key, value in self._block(times[b], eta[b], velocity[b], part).items():
                out[key][b] = value
        return out

    def _block(self, times: np.ndarray, eta: np.ndarray, velocity: np.ndarray,
               frame: dict | None = None) -> dict:
        """:meth:`rows` of one block."""
        if frame is None:
            phi, rate, _ = self.reduced.drive.values(times)
            psi = phi - self.reduced.start_angle
            sin, cos1 = np.sin(psi), 1.0 - np.cos(psi)
        else:
            phi, rate = frame["angle"], frame["rate"]
            sin, cos1 = frame["sin"], frame["one_minus_cos"]
        n = len(times)
        # e at the needed coordinates, as expand() computes every coordinate
        if len(self.slots):
            sub = self.sub_pivot[None, :] + _turned(self.sub_a0[None, :] + eta @ self.sub_basis.T,
                                                    sin, cos1, self.skew_t, self.skew2_t)
        else:
            sub = np.zeros((n, 0))
        probes = np.zeros((n, len(self.probes), 3))
        deflections = np.zeros_like(probes)
        for i, (_, p) in enumerate(self.probes):
            for d, coef in p.terms:
                j = self.slot_of[int(d)]
                probes[:, i, :] += coef * sub[:, j:j + 3]
            if p.frame:   # A(t)^T v, A = Rot(k, phi) base: base^T (v - sin W v + (1 - cos) W^2 v)
                info = self.model.frames[p.frame - 1]
                angle = phi if info.drive_obj is self.reduced.drive else \
                    info.drive_obj.values(times)[0]
                axis = info.axis / np.linalg.norm(info.axis)
                w = _skew(axis)
                v = probes[:, i, :] - info.pivot
                v = v - np.sin(angle)[:, None] * (v @ w.T) \
                    + (1.0 - np.cos(angle))[:, None] * (v @ (w @ w).T)
                deflections[:, i, :] = v @ info.base - p.reference
            else:
                deflections[:, i, :] = probes[:, i, :] - p.reference
        # kinetic, strain (+ P-delta's cubic form), the frame's power and the loads'
        # potential: the kernel's reduced_ffr_energy_rows, one pass over the rows
        energy = np.zeros((n, 11))
        motion = dict(rate=np.asarray(rate, float), sin_psi=sin, one_minus_cos=cos1)
        frame = np.asfortranarray(np.column_stack([motion[k] for k in KERNEL_LAYOUTS["fm"][:3]]))
        energies = self._kernel.reduced_ffr_energy_rows(frame, eta.T, velocity.T,
                                                        *self._energy_args)
        kinetic, strain, power, load = (energies[:, KERNEL_LAYOUTS["re"].index(k)]
                                        for k in ("kinetic", "strain", "power", "load"))
        energy[:, 0], energy[:, 1], energy[:, 2] = kinetic, strain, load
        for m in self.model.moments:
            director = sub[:, [self.slot_of[int(d)] for d in m.dofs]]
            energy[:, 3] -= m.magnitude * _moment_angle(director, m.axis, m.reference)
        energy[:, 4] = energy[:, 0] + energy[:, 1] + energy[:, 2] + energy[:, 3] + energy[:, 7]
        violation = np.zeros(n)
        if self.ncon:
            out = self._kernel.constraint_violation_rows(
                *self._constraint_args, np.asfortranarray(sub.T), np.asarray(times, float))
            if out[-1]:
                raise SolverError(f"constraint evaluation failed (code {out[-1]})")
            violation = out[0]
        return dict(probes=probes, deflections=deflections, energy=energy,
                    violation=violation, power=power)


def _cubic_table(energy: np.ndarray, power: np.ndarray):
    """sum_ijk c_i c_j c_k T_ijk of the two tensors as sums over the monomials
    c_i c_j c_k, i <= j <= k, of the coefficients summed over the index permutations;
    coefficients of c_i that are zero in every term (sin and 1 - cos with the pivot on the
    frame axis) left out. The pairs (i <= j) ordered by j, the monomials by k: those of a
    given j or k are a prefix (the order the kernel's reduced_ffr_energy_rows walks them).
    Returns (used, (nmono, 2) table)."""
    import itertools
    weight = sum(np.abs(t).sum(axis=tuple(a for a in range(3) if a != axis))
                 for t in (energy, power) for axis in range(3))
    used = np.flatnonzero(weight > 0)
    m = len(used)
    sub = [t[np.ix_(used, used, used)] for t in (energy, power)]
    full = [sum(t.transpose(p) for p in itertools.permutations(range(3))) for t in sub]
    pairs = [(i, j) for j in range(m) for i in range(j + 1)]
    i, j, k = np.array([(i, j, k) for k in range(m) for i, j in pairs if j <= k]).T
    # the distinct orderings of (i, j, k) each appear 6 / repeats times in the full sum
    repeats = np.where(i == k, 6.0, np.where((i == j) | (j == k), 2.0, 1.0))
    return used, np.column_stack([f[i, j, k] / repeats for f in full])


def _moment_angle(director: np.ndarray, axis: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """section_moment.moment_angle at rows of directors (n, 3): the angle about the axis
    from the reference to the director's projection, atan2(k . (q x p), q . p) with
    k . (q x p) = p . (k x q)."""
    k = axis / np.linalg.norm(axis)
    p = director - (director @ k)[:, None] * k
    q = reference - (k @ reference) * k
    return np.arctan2(p @ (_skew(k) @ q), p @ q)


#: rows per output chunk of a reduced run computed in bulk (one write of the file each)
BULK_ROWS = 65536
#: rows per block of RowMaps.rows (2048: 6.1 ms for the 10 s boom's rows, 1024: 6.5, one
#: block of 10,001: 10.7, its temporaries page-faulted afresh)
ROW_BLOCK = 2048


def _departure_bound(model: Model, reduced: ReducedFFR) -> tuple[float, np.ndarray]:
    """(c, n) with c + n . |eta| >= the small-strain measure of every 'ffr' beam at a
    reduced state (solvers.assumptions): a section vector's change in the frame is
    A0^T (x* + Psi eta)_v - r_v0 (the pivot sits on positions only; A = U(psi) A0), at most
    |A0^T x*_v - r_v0| + sum_j |Psi_vj| |eta_j|; c and n_j the largest over the vectors."""
    from .assumptions import _section_vectors
    a0t = model.frames[0].rotation(0.0).T
    c, n = 0.0, np.zeros(reduced.size)
    for info in model.sets:
        if not info.floating:
            continue
        first, reference = _section_vectors(info)
        index = first[:, None] + np.arange(3)
        static = reduced.static_state[index] @ a0t.T - reference
        c = max(c, float(np.linalg.norm(static, axis=1).max(initial=0.0)))
        columns = np.linalg.norm(reduced.basis[index], axis=1)          # (m, r)
        n = np.maximum(n, columns.max(axis=0, initial=0.0))
    return c, n


def _reduced_assumptions(model: Model, reduced: ReducedFFR, chunk, eta: np.ndarray,
                         every_row: bool):
    """dynamic._check_assumptions for a chunk of a reduced run: with every_row (the chunk
    carries q), the first row whose 'ffr' beam leaves its small-strain range ends the run
    (the rows after it dropped), else the chunk's last state is checked; rows whose bound
    (:func:`_departure_bound`) stays below the limit are not expanded."""
    from .assumptions import FFR_LIMIT, ffr_departure_rows
    from .dynamic import Chunk, _outside
    times = chunk.time
    if not every_row:
        e, _ = expand(reduced, times[-1:], eta[-1:], np.zeros_like(eta[-1:]))
        return chunk, _outside(model, e[0], float(times[-1]), "by")
    if not hasattr(reduced, "_departure_bound"):
        reduced._departure_bound = _departure_bound(model, reduced)
    c, n = reduced._departure_bound
    bound = (c + np.abs(eta) @ n) * (1.0 + 1e-9)
    suspect = np.flatnonzero(~(bound <= FFR_LIMIT))          # also not a number
    if not len(suspect):
        return chunk, ""
    e, _ = expand(reduced, times[suspect], eta[suspect], np.zeros_like(eta[suspect]))
    outside = np.zeros(len(suspect), dtype=bool)
    for _, change in ffr_departure_rows(model, e, times[suspect]):
        outside |= ~(change <= FFR_LIMIT)
    if not outside.any():
        return chunk, ""
    k = int(np.argmax(outside))
    row = int(suspect[k])
    why = _outside(model, e[k], float(times[row]), "at")
    kept = {}
    for key, value in vars(chunk).items():
        if value is None or key == "rows":   # (the kernel's rows: not cut)
            kept[key] = None
        elif isinstance(value, ExpandedRows):
            kept[key] = ExpandedRows(reduced, value.times[:row + 1], value.eta[:row + 1])
        else:
            kept[key] = value[:row + 1]
    return Chunk(**kept), why


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
    frame: dict[str, np.ndarray] = {}
    out = simulate(reduced, settings.t_end, settings.dt, beta=settings.beta,
                   gamma=settings.gamma, tol=settings.tol, max_newton=settings.max_newton,
                   frame=frame)
    timing["stepping"] = reduced.timing["simulate"]
    times, eta, velocity = out["time"], out["eta"], out["velocity"]
    stats = np.column_stack([out["corrections"], out["factorized"], out["factorized"]])
    ncon, nrows = len(model.constraints), len(times)
    no_work = np.zeros(5)
    guesses = model.contact_guesses.copy()
    counts = np.zeros(6, dtype=np.int32)
    frame_work, last_power = 0.0, None
    rows_done = 0
    maps = reduced.row_maps
    if maps is None and RowMaps.supported(model):
        maps = reduced.row_maps = RowMaps(model, reduced)
    step = max(1, int(settings.chunk_steps))
    if maps is not None:   # the rows in bulk: chunks of up to BULK_ROWS rows (one write each)
        step = max(step, BULK_ROWS)
    try:
        for first in range(0, nrows, step):
            t1 = time.perf_counter()
            rows = slice(first, min(first + step, nrows))
            if maps is not None:
                found = maps.rows(times[rows], eta[rows], velocity[rows],
                                  {k: v[rows] for k, v in frame.items()})
                probes, deflections = found["probes"], found["deflections"]
                energy, violation, power = found["energy"], found["violation"], found["power"]
                e = ExpandedRows(reduced, times[rows], eta[rows])
                n = len(e)
            else:
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
            if maps is not None:
                chunk, outside = _reduced_assumptions(model, reduced, chunk, eta[rows],
                                                      settings.store_q)
            else:
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
