"""Modal analysis about a static equilibrium (SPEC section 10, docs/theory.md "Modes").

The equations of motion M e'' + Q_int(e, e') - Q_ext - Phi_e^T lambda = 0, Phi(e) = 0 are
linearized about a static state (e*, lambda*) of the scene's loads:

    M x'' + C x' + K x - G^T mu = 0,   G x = 0,
    K = dQ_int/de - dQ_M/de - sum_k lambda*_k Phi_k,ee   (the static Newton matrix's block),
    C = dQ_int/de' (material damping, force elements' dampers),  G = Phi_e(e*),

so K holds the elastic tangent at the loaded state (for the large-deformation beams, plates
and leaves its initial-stress part is the geometric stiffness of that state), the dead
moments' load stiffness and the constraint Hessian term. Linear joints are already
eliminated in the coordinates e (q = B e + q0), the other constraints are kept.

Two solvers:

* ``dense`` (null-space form): N spans the null space of G (an orthonormal basis from the
  SVD), then N^T K N y = omega^2 N^T M N y by LAPACK (all modes; fine up to a few thousand
  coordinates);
* ``sparse`` (multiplier form, shift-invert Lanczos through ARPACK/scipy ``eigsh``):
  [[K, G^T], [G, 0]] z = omega^2 [[M, 0], [0, 0]] z with the shifted matrix factorized once
  by MUMPS (the kernel's direct solver); the multiplier rows carry infinite eigenvalues,
  which shift-invert maps to 0, so they are never returned. The shift is slightly negative,
  so rigid-body modes (omega^2 = 0) do not make the factorized matrix singular.

Damped and gyroscopic modes solve the quadratic problem (s^2 M + s C + K) x = 0 in state
space (dense: on the whole null space; sparse: on the span of the lowest undamped modes,
a projection). Each mode's natural frequency is |s| / 2 pi and its damping ratio
-Re(s) / |s|; overdamped modes (two real roots s1, s2) have omega = sqrt(s1 s2).

Rigid-body modes (|omega^2| below ``rigid_tol`` times the model's stiffness-to-mass
scale) are reported at exactly 0 Hz; a negative omega^2 (a static state past a stability
limit) is reported as a negative frequency -sqrt(-omega^2) / 2 pi.
"""
from __future__ import annotations

import inspect
import time
from collections.abc import Callable
from dataclasses import field

import numpy as np

from ..records import record
from ..errors import InputError, SolverError
from ..io.schema import check_keywords
from ..kernel import DirectSolver
from ..system.model import Model
from .static import StaticResult, solve_newton
from .._lazy import LazyModule

# imported on first use (ancfdrv._lazy): ~10 MB most runs never need; scipy.sparse (~19 MB
# with its import chain) too: a dynamic run imports this module but never solves here
sp = LazyModule("scipy.sparse")
la = LazyModule("scipy.linalg")
spla = LazyModule("scipy.sparse.linalg")

#: largest number of coordinates minus constraints solved densely by ``solver='auto'``
DENSE_LIMIT = 150


@record
class Linearization:
    """The matrices of the linearized equations at a state (coordinates e of the solvers)."""

    stiffness: sp.csr_matrix      # K (symmetrized; see ``asymmetry``)
    mass: sp.csr_matrix           # M
    damping: sp.csr_matrix | None  # C (material damping, force elements' dampers), None without damping
    constraints: sp.csr_matrix    # G = Phi_e (ncon x ndof)
    asymmetry: float = 0.0        # |K - K^T|_max / |K|_max before symmetrizing


@record
class ModalResult:
    """The lowest modes of a linearized model (plain record; HDF5: /modal).

    ``shapes`` are mass-normalized (x^T M x = 1) in the solver coordinates e (rows: modes);
    ``full_shapes`` the same in the full coordinates q (linear joints expanded).
    """

    frequency: np.ndarray                 # Hz, ascending (rigid-body modes exactly 0)
    shapes: np.ndarray                    # (N, ndof)
    omega_squared: np.ndarray             # eigenvalues (rad^2/s^2) as solved
    rigid: np.ndarray                     # bool (N,): rigid-body modes
    method: str                           # 'dense' | 'sparse'
    damping_ratio: np.ndarray | None = None    # when damping (or spin) is on
    damped_frequency: np.ndarray | None = None  # Im(s) / 2 pi, Hz
    full_shapes: np.ndarray | None = None
    static: StaticResult | None = None
    wall_time_s: float = 0.0
    timing: dict[str, float] = field(default_factory=dict)
    extra: dict[str, object] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.frequency)


def linearize(model: Model, e: np.ndarray, lam: np.ndarray, t: float = 0.0,
              load_factor: float | None = None) -> Linearization:
    """K, M, C and G at the state (e, lambda); K is the static Newton matrix's block
    (elastic and contact tangent, minus the dead moments' and point loads' Jacobians, minus
    the constraint Hessians times the multipliers)."""
    n = model.ndof
    out = model.forces(e, t, want_tangent=True, load_factor=load_factor)
    rows, cols, vals = model.stiffness_triplets(e, lam, t, load_factor, out["tangent"])
    stiffness = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    scale = max(abs(stiffness).max(), 1e-300)
    asymmetry = float(abs(stiffness - stiffness.T).max() / scale) if stiffness.nnz else 0.0
    stiffness = ((stiffness + stiffness.T) * 0.5).tocsr()
    damping = None
    if model.damped or any(f.damped for f in model.force_elements):  # C = dQ/de'
        rate = model.forces(e, t, want_tangent=True, velocity_factor=1.0,
                            load_factor=load_factor)["tangent"]
        damping = model.pattern.to_scipy(rate - out["tangent"])
        damping = ((damping + damping.T) * 0.5).tocsr()
    if len(model.constraints):
        _, g_rows, g_cols, grads = model.constraints.jacobian(e, n, t)
        g = sp.csr_matrix((grads, (g_rows, g_cols)), shape=(len(model.constraints), n))
    else:
        g = sp.csr_matrix((0, n))
    return Linearization(stiffness, model.mass_matrix().tocsr(), damping, g, asymmetry)


def null_space(g: sp.spmatrix, n: int, tol: float = 1e-10) -> np.ndarray:
    """Orthonormal basis (n, n - rank) of the null space of G (dense SVD); redundant
    constraint rows are tolerated (rank by singular values above tol times the largest)."""
    if g.shape[0] == 0:
        return np.eye(n)
    dense = g.toarray()
    norms = np.abs(dense).max(axis=1)
    dense = dense[norms > 0] / norms[norms > 0, None]  # rows scaled to unit size
    _, s, vt = la.svd(dense, full_matrices=True)
    rank = int(np.sum(s > tol * max(s.max(initial=0.0), 1e-300)))
    return vt[rank:].T.copy()


def stiffness_scale(lin: Linearization) -> float:
    """A stiffness-to-mass ratio of the model (rad^2/s^2): max diag K / max diag M; the
    rigid-body test is relative to it."""
    dk = np.abs(lin.stiffness.diagonal()).max(initial=0.0)
    dm = np.abs(lin.mass.diagonal()).max(initial=0.0)
    return dk / dm if dm > 0 else 1.0


def _pair_roots(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Natural frequency (rad/s), damping ratio and damped frequency (rad/s) per mode from
    the 2m roots of a real quadratic eigenproblem: one per complex pair; real roots
    (overdamped or rigid modes) paired in ascending order of |s|."""
    tol = 1e-9 * max(np.abs(s).max(initial=0.0), 1e-300)
    complex_roots = s[s.imag > tol]
    real_roots = s[np.abs(s.imag) <= tol].real
    real_roots = real_roots[np.argsort(np.abs(real_roots), kind="stable")]
    omega = list(np.abs(complex_roots))
    zeta = list(-complex_roots.real / np.maximum(np.abs(complex_roots), 1e-300))
    damped = list(complex_roots.imag)
    for a, b in zip(real_roots[0::2], real_roots[1::2]):
        w = np.sqrt(max(a * b, 0.0))
        omega.append(w)
        zeta.append(-(a + b) / (2 * w) if w > 0 else 0.0)
        damped.append(0.0)
    order = np.argsort(omega, kind="stable")
    return np.array(omega)[order], np.array(zeta)[order], np.array(damped)[order]


def _quadratic_modes(k: np.ndarray, c: np.ndarray, m: np.ndarray):
    """Roots s and right vectors x of (s^2 m + s c + k) x = 0 (dense, state space)."""
    nr = k.shape[0]
    minv_k = la.solve(m, k, assume_a="pos")
    minv_c = la.solve(m, c, assume_a="pos")
    a = np.block([[np.zeros((nr, nr)), np.eye(nr)], [-minv_k, -minv_c]])
    s, vec = la.eig(a)
    return s, vec[:nr]


def _dense_modes(lin: Linearization, count: int, spin_gyro: sp.spmatrix | None):
    n = lin.stiffness.shape[0]
    basis = null_space(lin.constraints, n)
    kr = basis.T @ (lin.stiffness @ basis)
    mr = basis.T @ (lin.mass @ basis)
    kr, mr = 0.5 * (kr + kr.T), 0.5 * (mr + mr.T)
    try:
        w2, y = la.eigh(kr, mr)
    except la.LinAlgError:
        raise SolverError("modal analysis: the mass matrix on the constrained coordinates "
                          "is not positive definite (a massless coordinate)") from None
    count = min(count, len(w2))
    shapes = (basis @ y[:, :count]).T
    result = dict(omega_squared=w2[:count], shapes=shapes, all_omega_squared=w2)
    if lin.damping is not None or spin_gyro is not None:
        cr = np.zeros_like(kr)
        if lin.damping is not None:
            cr += basis.T @ (lin.damping @ basis)
        if spin_gyro is not None:
            cr += basis.T @ (spin_gyro @ basis)
        s, _ = _quadratic_modes(kr, cr, mr)
        omega, zeta, damped = _pair_roots(s)
        result.update(quadratic=(omega[:count], zeta[:count], damped[:count]))
    return result


def arpack_start(apply: Callable[[np.ndarray], np.ndarray], size: int,
                 seed: int) -> dict[str, object]:
    """ARPACK's start, the same in every run: ``v0 = apply(r)`` for a normal vector r of a
    generator seeded with ``seed`` (``apply`` the operator: v0 in its range, e.g. no
    component along the multipliers' infinite eigenvalues; a random r is orthogonal to no
    mode, unlike a vector of ones to a symmetric structure's antisymmetric modes), and that
    generator for ARPACK's restarts. scipy >= 1.17 (ARPACK in C) takes it as ``rng`` and
    without it draws both from OS entropy, so the eigenvalues differed in their last digits
    from run to run; the Fortran ARPACK of older scipy restarts from its own fixed seed."""
    rng = np.random.default_rng(seed)
    start: dict[str, object] = {"v0": apply(rng.standard_normal(size))}
    if "rng" in inspect.signature(spla.eigs).parameters:
        start["rng"] = rng
    return start


def _sparse_modes(lin: Linearization, count: int, shift: float, tol: float):
    """Shift-invert Lanczos on the multiplier form (module doc)."""
    n, ncon = lin.stiffness.shape[0], lin.constraints.shape[0]
    g = lin.constraints
    shifted = sp.bmat([[lin.stiffness - shift * lin.mass, g.T], [g, None]], format="coo")
    b = sp.bmat([[lin.mass, None], [None, sp.csr_matrix((ncon, ncon))]], format="csr")
    a = sp.bmat([[lin.stiffness, g.T], [g, None]], format="csr")
    solver = DirectSolver.by_cost(n + ncon, shifted.row, shifted.col,
                                  what="modal shift-invert matrix [[K - sigma M, G^T], [G, 0]]")
    try:
        solver.factorize(shifted.data)
        op = spla.LinearOperator((n + ncon, n + ncon), matvec=lambda x: solver.solve(x),
                                 dtype=float)
        count = min(count, n - ncon - 1)  # ARPACK needs k below the free dimension
        # and its Lanczos basis within the free dimension: scipy's default 2k + 1 vectors
        # (up to n + ncon) failed to build (ARPACK error -9999) beyond half of it, where the
        # basis meets the multipliers' directions, which B = diag(M, 0) does not see
        basis = min(n - ncon, max(2 * count + 1, 20))
        w2, z = spla.eigsh(a, k=count, M=b, sigma=shift, OPinv=op, which="LM", tol=tol,
                           ncv=basis,
                           **arpack_start(lambda r: solver.solve(b @ r), n + ncon, 12345))
        factorizations = solver.factorizations
    except spla.ArpackNoConvergence as exc:
        raise SolverError(f"modal analysis: ARPACK did not converge ({exc})") from None
    finally:
        solver.close()
    order = np.argsort(w2)
    return dict(omega_squared=w2[order], shapes=z[:n, order].T, factorizations=factorizations)


def steady_rotation_matrices(model: Model, rate: float, axis) -> tuple[sp.csr_matrix,
                                                                       sp.csr_matrix]:
    """For a steady rotation at ``rate`` (rad/s) about ``axis``: the centrifugal matrix
    rate^2 Mbar (x) P (P = I - a a^T: the centrifugal force on the coordinates is this times
    (e - the axis point), its stiffness minus it) and the Coriolis matrix 2 rate Mbar (x) [a]x,
    from a mass matrix M = Mbar (x) I3 (every body kind's, in full and reduced form)."""
    from ..system.model import kron_scalar
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    mbar = kron_scalar(model.mass)
    if mbar is None:
        raise InputError("modal analysis about a steady rotation needs a mass matrix of "
                         "3 x 3 blocks c I3 (the coordinates of every body are position "
                         "vectors); this model's is not", group="modal", key="spin_rate")
    mbar = mbar.to_scipy()
    proj = np.eye(3) - np.outer(a, a)
    skew = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return (sp.kron(mbar, rate**2 * proj, format="csr"),
            sp.kron(mbar, 2.0 * rate * skew, format="csr"))


#: the arguments of :func:`modal_analysis` that are namelist keys (argument -> its group;
#: ``modes`` is ``count``): checked with the namelist's rules, and the keywords
#: ``System.modes`` takes besides ``n``
MODAL_KEYWORDS = {"modes": "modal", "solver": "modal", "rigid_tol": "modal",
                  "spin_rate": "modal", "spin_axis": "modal", "spin_centre": "modal",
                  "tol": "solver", "max_iter": "solver", "load_steps": "solver"}


def check_free(what: str, free: int) -> None:
    """Refuse an eigenproblem without a free coordinate (the joints hold every one: no
    mode), an InputError naming scene.analysis."""
    if free < 1:
        raise InputError(f"{what}: the joints hold every coordinate of the model, so nothing "
                         "can move and there is no mode; analyse it statically "
                         "(scene.analysis = 'static') for its reactions", group="scene",
                         key="analysis")


def modal_analysis(model: Model, count: int, *, static: StaticResult | None = None,
                   solver: str = "auto", tol: float = 1e-10, max_iter: int = 50,
                   load_steps: int = 1, rigid_tol: float = 1e-9, shift: float | None = None,
                   eigen_tol: float = 0.0, spin_rate: float = 0.0,
                   spin_axis=(0.0, 0.0, 1.0), spin_centre=(0.0, 0.0, 0.0)) -> ModalResult:
    """The ``count`` lowest modes about the static equilibrium of the model's loads.

    ``static``: the equilibrium to linearize about (default: solved here by Newton with
    ``tol``, ``max_iter``, ``load_steps``). ``solver``: 'dense', 'sparse' or 'auto' (dense
    up to :data:`DENSE_LIMIT` free coordinates). ``spin_rate`` > 0: modes in a frame turning
    steadily about ``spin_axis`` through ``spin_centre`` (every body turning with it: the
    static state includes the centrifugal forces, K their softening, and the Coriolis
    forces make the problem gyroscopic; see docs/theory.md). The arguments of
    :data:`MODAL_KEYWORDS` pass the rules of their namelist keys (InputError).
    """
    args = check_keywords("modal analysis", dict(
        modes=count, solver=solver, rigid_tol=rigid_tol, spin_rate=spin_rate,
        spin_axis=spin_axis, spin_centre=spin_centre, tol=tol, max_iter=max_iter,
        load_steps=load_steps), MODAL_KEYWORDS)
    count, solver, rigid_tol, spin_rate = (args["modes"], args["solver"], args["rigid_tol"],
                                           args["spin_rate"])
    spin_axis, spin_centre = args["spin_axis"], args["spin_centre"]
    tol, max_iter, load_steps = args["tol"], args["max_iter"], args["load_steps"]
    start = time.perf_counter()
    timing: dict[str, float] = {}
    centrifugal = coriolis = None
    centre_q = None
    if spin_rate:
        centrifugal, coriolis = steady_rotation_matrices(model, spin_rate, spin_axis)
        centre_q = np.tile(np.asarray(spin_centre, dtype=float), model.ndof // 3)
    if static is None:
        if spin_rate:
            static = solve_steady_rotation(model, centrifugal, centre_q, tol=tol,
                                           max_iter=max_iter, load_steps=load_steps)
        else:
            static = solve_newton(model, tol=tol, max_iter=max_iter, load_steps=load_steps)
    timing["static"] = static.wall_time_s
    t0 = time.perf_counter()
    lin = linearize(model, static.e, static.lam)
    if centrifugal is not None:
        lin.stiffness = (lin.stiffness - centrifugal).tocsr()
    timing["assembly"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    free = model.ndof - lin.constraints.shape[0]
    check_free("modal analysis", free)
    if solver == "sparse" and free < 2:  # ARPACK finds at most free - 1 modes
        raise InputError("modal analysis: the model has 1 free coordinate, too few for the "
                         "sparse eigensolver (ARPACK); use solver = 'dense' (or 'auto')",
                         group="modal", key="solver")
    method = solver if solver != "auto" else ("dense" if free <= DENSE_LIMIT else "sparse")
    scale = stiffness_scale(lin)
    quadratic = None
    if method == "dense":
        out = _dense_modes(lin, count, coriolis)
        quadratic = out.get("quadratic")
    else:
        sigma = -1e-8 * scale if shift is None else shift
        want = count if lin.damping is None and coriolis is None else \
            min(max(2 * count, count + 10), free - 1)
        out = _sparse_modes(lin, want, sigma, eigen_tol)
        if lin.damping is not None or coriolis is not None:
            basis = out["shapes"].T  # mass-orthonormal undamped modes: a projection
            kr = basis.T @ (lin.stiffness @ basis)
            mr = basis.T @ (lin.mass @ basis)
            cr = np.zeros_like(kr)
            if lin.damping is not None:
                cr += basis.T @ (lin.damping @ basis)
            if coriolis is not None:
                cr += basis.T @ (coriolis @ basis)
            s, _ = _quadratic_modes(0.5 * (kr + kr.T), cr, 0.5 * (mr + mr.T))
            quadratic = tuple(x[:count] for x in _pair_roots(s))
        out["omega_squared"] = out["omega_squared"][:count]
        out["shapes"] = out["shapes"][:count]
    timing["eigen"] = time.perf_counter() - t0
    w2 = np.asarray(out["omega_squared"], dtype=float)
    shapes = np.asarray(out["shapes"], dtype=float)
    for i, x in enumerate(shapes):  # mass-normalized, largest component positive
        norm = np.sqrt(abs(x @ (lin.mass @ x)))
        x = x / norm if norm > 0 else x
        shapes[i] = x if x[np.argmax(np.abs(x))] >= 0 else -x
    rigid = np.abs(w2) <= rigid_tol * scale
    frequency = np.where(rigid, 0.0, np.sign(w2) * np.sqrt(np.abs(w2)) / (2 * np.pi))
    result = ModalResult(frequency, shapes, w2, rigid, method, static=static,
                         full_shapes=model.expand(shapes, with_offset=False), timing=timing,
                         extra={"asymmetry": lin.asymmetry, "stiffness_scale": scale,
                                "rigid_tol": rigid_tol, "spin_rate": spin_rate,
                                "nconstraints": lin.constraints.shape[0],
                                "free_coordinates": free})
    if quadratic is not None:
        omega, zeta, damped = quadratic
        small = omega <= np.sqrt(rigid_tol * scale)
        result.frequency = np.where(small, 0.0, omega / (2 * np.pi))
        result.damping_ratio = np.where(small, 0.0, zeta)
        result.damped_frequency = np.where(small, 0.0, damped / (2 * np.pi))
        result.rigid = small
    model.counters["modal_analyses"] += 1
    result.wall_time_s = time.perf_counter() - start
    timing["total"] = result.wall_time_s
    return result


def solve_steady_rotation(model: Model, centrifugal: sp.csr_matrix, centre_q: np.ndarray, *,
                          tol: float = 1e-10, max_iter: int = 50,
                          load_steps: int = 1) -> StaticResult:
    """Relative equilibrium in a frame turning steadily: Q_int(e) - Q_ext - C_f (e - c)
    - Phi_e^T lambda = 0, Phi = 0, by Newton on the saddle-point system (dense matrices
    through scipy's sparse LU; the rotating test models are small)."""
    start = time.perf_counter()
    n, ncon = model.ndof, len(model.constraints)
    e, lam = model.e0.copy(), np.zeros(ncon)
    history: list[float] = []
    for step in range(1, load_steps + 1):
        factor = step / load_steps
        for iteration in range(1, max_iter + 1):
            out = model.forces(e, load_factor=factor)
            phi = model.constraints.jacobian(e, n)[0] if ncon else np.zeros(0)
            lin = linearize(model, e, lam, load_factor=factor)
            g = lin.constraints
            residual = (out["internal"] - out["external"] - factor * (centrifugal @ (e - centre_q))
                        - g.T @ lam)
            k = lin.stiffness - factor * centrifugal
            mat = sp.bmat([[k, -g.T], [-g, None]], format="csc") if ncon else k.tocsc()
            rhs = np.concatenate([-residual, phi]) if ncon else -residual
            dz = spla.spsolve(mat, rhs)
            e = e + dz[:n]
            lam = lam + dz[n:]
            size = max(np.linalg.norm(out["internal"]), np.linalg.norm(out["external"]),
                       np.linalg.norm(centrifugal @ (e - centre_q)), 1e-300)
            history.append(float(np.linalg.norm(residual) / size))
            if np.linalg.norm(dz[:n]) <= tol * model.length_scale:
                break
        else:
            raise SolverError(f"steady rotation: Newton did not converge in {max_iter} "
                              "iterations")
    wall = time.perf_counter() - start
    return StaticResult(e, lam, "newton (steady rotation)", len(history), history[-1], 0.0,
                        wall, history)
