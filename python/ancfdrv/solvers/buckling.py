"""Linear buckling about a static state (SPEC section 10, docs/theory.md "Buckling").

The loads are split into fixed loads F (kept at their value, e.g. gravity) and the
reference loads P (the others). Two static equilibria are solved: state 0 under F alone and
state 1 under F + P. With K_T(state) the tangent of the linearized equations
(:func:`~.modal.linearize`: elastic tangent with its initial-stress part, the dead moments'
load stiffness and the constraint Hessians times the multipliers), the eigenproblem is

    (K_0 + mu K_g) phi = 0  on  G_0 phi = 0,    K_0 = K_T(state 0),
    K_g = (K_T(state 1) - K_T(state 0)) / s   (s = ``reference_factor``, default 1)

and mu is the load factor: the structure under F + mu P loses stability. K_g by this
difference of tangents is the classical initial-stress (geometric) stiffness of the
reference loads whenever the tangent is affine in the load factor, which holds for the
initial-stress term (linear in the stress, itself linear in the load) as long as the
pre-buckling displacements under s P are small (linear buckling's own assumption). What
it neglects is the change of the tangent by the pre-buckling deformation's geometry
(second order in the load), like every linear buckling analysis. ``reference_factor`` < 1
evaluates the difference at a smaller load when the scene's loads are large.

Solved in null-space form densely (K_0 positive definite on the null space of G:
N^T (-K_g) N y = theta N^T K_0 N y, mu = 1 / theta for the largest positive theta), or for
large models by ARPACK on the multiplier form with [[K_0, G^T], [G, 0]] factorized once by
MUMPS. Only positive load factors are reported (a negative one means the reversed loads
buckle the structure; attribute ``negative_load_factor`` gives the smallest in size).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, SolverError
from ..io.schema import check_keywords
from ..kernel import DirectSolver
from ..system.model import Model
from .modal import DENSE_LIMIT, arpack_start, check_free, linearize, null_space
from .static import StaticResult
from .._lazy import LazyModule

# imported on first use (ancfdrv._lazy): ~10 MB most runs never need; scipy.sparse (~19 MB
# with its import chain) too: a dynamic run imports this module but never solves here
sp = LazyModule("scipy.sparse")
la = LazyModule("scipy.linalg")
spla = LazyModule("scipy.sparse.linalg")


@dataclass
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


def _dense(k0: sp.spmatrix, kg: sp.spmatrix, g: sp.spmatrix, count: int):
    n = k0.shape[0]
    basis = null_space(g, n)
    a = basis.T @ (k0 @ basis)
    b = basis.T @ (kg @ basis)
    a, b = 0.5 * (a + a.T), 0.5 * (b + b.T)
    try:
        theta, y = la.eigh(-b, a)
    except la.LinAlgError:
        raise SolverError("buckling: the stiffness under the fixed loads is not positive "
                          "definite on the constrained coordinates (a rigid-body motion is "
                          "free, or the fixed loads alone already buckle the structure)") \
            from None
    return theta, basis @ y


def _sparse(k0: sp.spmatrix, kg: sp.spmatrix, g: sp.spmatrix, count: int, tol: float):
    n, ncon = k0.shape[0], g.shape[0]
    aug = sp.bmat([[k0, g.T], [g, None]], format="coo")
    solver = DirectSolver(n + ncon, aug.row, aug.col,
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
    """Static states under F + P R (fixed loads F, reference loads R, load factor P) by
    Newton with continuation from the last state. The loads enter linearly with the kernel's
    load factor, so with ``model`` holding F + R and ``base_model`` F alone the residual is
    r_model(e, P) + r_base(e, 1) - r_base(e, P) (the elastic parts cancel); without fixed
    loads (``base_model is model``) it is r_model(e, P)."""

    def __init__(self, model: Model, base_model: Model, *, tol: float, max_iter: int,
                 load_steps: int) -> None:
        self.model, self.base = model, base_model
        self.tol, self.max_iter, self.load_steps = tol, max_iter, load_steps
        self.e = model.e0.copy()
        self.lam = np.zeros(len(model.constraints))
        self.factor = 0.0
        self.solves = 0
        self.k0: sp.csr_matrix | None = None

    def _terms(self, e, lam, factor):
        parts = [(self.model, factor, 1.0)]
        if self.base is not self.model:
            parts += [(self.base, 1.0, 1.0), (self.base, factor, -1.0)]
        residual = np.zeros(self.model.ndof)
        stiffness = None
        lin = None
        for model, lf, sign in parts:
            out = model.forces(e, load_factor=lf)
            residual += sign * (out["internal"] - out["external"])
            lin = linearize(model, e, lam if sign > 0 else np.zeros_like(lam), load_factor=lf)
            stiffness = sign * lin.stiffness if stiffness is None else \
                stiffness + sign * lin.stiffness
        if self.base is not self.model:  # the constraint Hessian term once, not twice
            lin_h = linearize(self.base, e, lam, load_factor=1.0)
            lin_0 = linearize(self.base, e, np.zeros_like(lam), load_factor=1.0)
            stiffness = stiffness - (lin_h.stiffness - lin_0.stiffness)
        return residual, stiffness.tocsr(), lin.constraints

    def tangent(self) -> sp.csr_matrix:
        return self._terms(self.e, self.lam, self.factor)[1]

    def constraints(self) -> sp.csr_matrix:
        return self._terms(self.e, self.lam, self.factor)[2]

    def solve(self, factor: float) -> None:
        """Move the state to the load factor ``factor`` (in load_steps increments)."""
        n = self.model.ndof
        start = self.factor
        for step in range(1, self.load_steps + 1):
            target = start + (factor - start) * step / self.load_steps
            e, lam = self.e.copy(), self.lam.copy()
            for iteration in range(1, self.max_iter + 1):
                residual, k, g = self._terms(e, lam, target)
                phi = self.model.constraints.jacobian(e, n)[0] if g.shape[0] else np.zeros(0)
                residual = residual - g.T @ lam
                mat = sp.bmat([[k, -g.T], [-g, None]], format="csc") if g.shape[0] else \
                    k.tocsc()
                dz = spla.splu(mat).solve(np.concatenate([-residual, phi]))
                e += dz[:n]
                lam += dz[n:]
                if not np.all(np.isfinite(dz)):
                    break
                if np.linalg.norm(dz[:n]) <= self.tol * self.model.length_scale:
                    break
            else:
                raise SolverError(f"buckling: the static state at load factor {target:.6g} "
                                  f"did not converge in {self.max_iter} Newton iterations "
                                  "(raise buckling.load_steps)")
            if not np.all(np.isfinite(e)):
                raise SolverError(f"buckling: non-finite static state at load factor "
                                  f"{target:.6g}")
            self.e, self.lam, self.factor = e, lam, target
            self.solves += 1


def _pencil(k0: sp.spmatrix, kg: sp.spmatrix, g: sp.spmatrix, count: int, method: str,
            eigen_tol: float):
    if method == "dense":
        return _dense(k0, kg, g, count)
    return _sparse(k0, kg, g, count, eigen_tol)


def _lowest(k: sp.spmatrix, m: sp.spmatrix, g: sp.spmatrix, method: str,
            count: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """The ``count`` lowest omega^2 of (K, M) on the null space of G and their vectors
    (columns): the softest modes' stiffness, which reaches 0 where the static state loses
    stability."""
    n, ncon = k.shape[0], g.shape[0]
    if method == "dense":
        basis = null_space(g, n)
        kr, mr = basis.T @ (k @ basis), basis.T @ (m @ basis)
        count = min(count, kr.shape[0])
        w, y = la.eigh(0.5 * (kr + kr.T), 0.5 * (mr + mr.T), subset_by_index=[0, count - 1])
        return w, basis @ y
    scale = np.abs(k.diagonal()).max() / np.abs(m.diagonal()).max()
    sigma = -1e-8 * scale
    aug = sp.bmat([[k, g.T], [g, None]], format="csr")
    b = sp.bmat([[m, None], [None, sp.csr_matrix((ncon, ncon))]], format="csr")
    shifted = (aug - sigma * b).tocoo()
    solver = DirectSolver(n + ncon, shifted.row, shifted.col, what="buckling softest modes")
    try:
        solver.factorize(shifted.data)
        op = spla.LinearOperator((n + ncon, n + ncon), matvec=solver.solve, dtype=float)
        w, z = spla.eigsh(aug, k=count, M=b, sigma=sigma, OPinv=op, which="LM",
                          **arpack_start(lambda r: solver.solve(b @ r), n + ncon, 1))
    finally:
        solver.close()
    order = np.argsort(w)
    return w[order], z[:n, order]


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
    """The load factor where omega^2(P) = w0 (1 - a P - b P^2), fitted through (0, w0) and
    the last two states (one: linear), vanishes; None while the stiffness does not
    decrease with the load (no limit in sight)."""
    w0 = history[0][1]
    p2, w2 = history[-1]
    if w0 <= 0 or w2 >= w0 * (1 - 1e-9):
        return None
    if len(history) < 3:
        return p2 / (1 - w2 / w0)
    p1, w1 = history[-2]
    try:
        a, b = np.linalg.solve(np.array([[p1, p1**2], [p2, p2**2]]), [1 - w1 / w0, 1 - w2 / w0])
    except np.linalg.LinAlgError:
        return p2 / (1 - w2 / w0)
    if abs(b) <= 1e-14 * abs(a) * max(p1, p2):
        return 1.0 / a if a > 0 else None
    disc = a * a + 4 * b
    roots = [(-a + sg * np.sqrt(disc)) / (2 * b) for sg in (1.0, -1.0)] if disc >= 0 else []
    roots = [r for r in roots if r > 0]
    return float(min(roots, key=lambda r: abs(r - p2))) if roots else None


#: the arguments of :func:`buckling_analysis` that are namelist keys (argument -> its
#: group; ``modes`` is ``count``): checked with the namelist's rules, and the keywords
#: ``System.buckling`` takes besides ``n``
BUCKLING_KEYWORDS = {"modes": "buckling", "fixed_loads": "buckling", "method": "buckling",
                     "solver": "buckling", "rtol": "buckling", "load_steps": "buckling",
                     "reference_factor": "buckling", "tol": "solver", "max_iter": "solver"}


def buckling_analysis(model: Model, base_model: Model, count: int, *,
                      fixed_loads: tuple[str, ...] = (), method: str = "nonlinear",
                      solver: str = "auto", tol: float = 1e-10, max_iter: int = 50,
                      load_steps: int = 1, reference_factor: float = 1.0,
                      rtol: float = 1e-6, max_updates: int = 40, max_factor: float = 1e6,
                      eigen_tol: float = 0.0) -> BucklingResult:
    """The ``count`` lowest positive load factors of ``model``'s loads beyond those of
    ``base_model`` (the same system with the fixed loads alone; pass ``model`` itself
    when no load is fixed).

    ``method``: 'linear' solves (K_0 + mu K_g) phi = 0 once with K_g from the difference of
    tangents at ``reference_factor``; 'nonlinear' (default) repeats it with K_g evaluated on
    the static path at the latest estimate until the first load factor reproduces itself:
    then the tangent on the static path is singular there (the stability limit of the
    model, pre-buckling deformation included). See the module doc and docs/theory.md.
    The arguments of :data:`BUCKLING_KEYWORDS` pass the rules of their namelist keys
    (InputError).
    """
    args = check_keywords("buckling", dict(
        modes=count, fixed_loads=fixed_loads, method=method, solver=solver, rtol=rtol,
        load_steps=load_steps, reference_factor=reference_factor, tol=tol,
        max_iter=max_iter), BUCKLING_KEYWORDS)
    count, fixed_loads, method, solver = (args["modes"], tuple(args["fixed_loads"]),
                                          args["method"], args["solver"])
    rtol, load_steps, reference_factor = (args["rtol"], args["load_steps"],
                                          args["reference_factor"])
    tol, max_iter = args["tol"], args["max_iter"]
    if model.ndof != base_model.ndof or not np.array_equal(model.e0, base_model.e0):
        raise SolverError("buckling: the model with and without the reference loads differ "
                          "in their coordinates")
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
    path = LoadPath(model, base_model, tol=tol, max_iter=max_iter, load_steps=load_steps)
    path.solve(0.0)  # state 0: the fixed loads alone
    base = StaticResult(path.e.copy(), path.lam.copy(), "newton", path.solves, 0.0, 0.0, 0.0)
    k0 = path.tangent()
    g = path.constraints()
    free = model.ndof - g.shape[0]
    check_free("buckling", free)
    how = solver if solver != "auto" else ("dense" if free <= DENSE_LIMIT else "sparse")
    mass = model.mass_matrix()
    track = max(count, 1)
    w0, _ = _lowest(k0, mass, g, how, track)
    history = [(0.0, w0)]   # (P, the lowest omega^2 of K_T(P) over M)
    factor, previous, critical = reference_factor, None, None
    saved: dict[float, tuple[np.ndarray, np.ndarray]] = {}  # states on the path
    ceiling = np.inf  # a factor known to lie past a fall and rise of the stiffness
    while True:
        _advance(path, factor)
        factor = path.factor
        k_t = path.tangent()
        if method == "linear":
            kg = ((k_t - k0) / factor).tocsr()
            theta, vectors = _pencil(k0, kg, g, count, how, eigen_tol)
            break
        w, vectors = _lowest(k_t, mass, g, how, track)
        # a rise after a fall that stopped well above zero (near the limit, omega^2 ~ 0 is
        # round-off and may rise by noise): either the step passed over a limit or the path
        # has none; step back to the fallen state and halve the interval (geometrically)
        # until it is narrower than 5%, then refuse
        if len(history) >= 2 and factor > history[-1][0] and \
                1e-3 * history[0][1][0] < history[-1][1][0] < 0.99 * history[0][1][0] and \
                w[0] > history[-1][1][0]:
            low = history[-1][0]
            if factor / low > 1.05 and len(history) <= max_updates:
                ceiling = factor
                path.e, path.lam = saved[low][0].copy(), saved[low][1].copy()
                path.factor = low
                factor = float(np.sqrt(low * ceiling))
                continue
            raise SolverError(
                f"buckling: no stability limit on the static path: the lowest stiffness fell "
                f"to {history[-1][1][0] / history[0][1][0]:.3g} of its start at "
                f"{history[-1][0]:.6g} times the reference loads and rises again at "
                f"{factor:.6g} (an imperfect structure: the fixed loads bend what the "
                "reference loads compress); buckling.method = 'linear' gives the classical "
                "estimate, docs/theory.md says when it holds")
        saved[factor] = (path.e.copy(), path.lam.copy())
        history.append((factor, w))
        critical = _root([(p, x[0]) for p, x in history])
        if critical is not None and previous is not None and \
                abs(critical - previous) <= rtol * critical:
            break
        if len(history) > max_updates:
            raise SolverError(
                f"buckling: no stability limit found up to {factor:.6g} times the reference "
                "loads (the lowest stiffness does not decrease toward zero)" if critical is None
                else f"buckling: the load factor did not settle in {max_updates} updates "
                     f"(last estimates {previous:.6g}, {critical:.6g})")
        previous = critical
        if critical is None:  # no softening yet: load further
            if factor * 4.0 > max_factor:
                raise SolverError(
                    f"buckling: no stability limit up to {factor:.6g} times the reference "
                    "loads (the lowest stiffness does not fall as they grow: e.g. a square "
                    "section bent in a plane of symmetry has no lateral-torsional buckling)")
            factor = min(factor * 4.0, float(np.sqrt(factor * ceiling)))
        else:  # approach the estimate from below: the state at the limit is singular
            factor = float(np.clip(factor + 0.9 * (critical - factor), factor / 8, factor * 8))
            if factor >= ceiling:
                factor = float(np.sqrt(path.factor * ceiling))
    timing["path"] = time.perf_counter() - start
    reference = StaticResult(path.e.copy(), path.lam.copy(), "newton", path.solves, 0.0, 0.0,
                             0.0)
    if method == "linear":
        scale = np.abs(theta).max(initial=0.0)
        positive = theta > 1e-12 * max(scale, 1e-300)
        mus = 1.0 / theta[positive]
        order = np.argsort(mus)[:count]
        factors, shapes = mus[order], vectors[:, positive][:, order].T.copy()
        negative = theta < -1e-12 * max(scale, 1e-300)
        negative_factor = float(1.0 / theta[negative].min()) if negative.any() else 0.0
    else:
        # the first: the limit; the others: each mode's omega^2(P) extrapolated likewise
        factors = [critical]
        for i in range(1, min(count, len(history[-1][1]))):
            root = _root([(p, x[i]) for p, x in history])
            if root is not None:
                factors.append(root)
        keep = np.argsort(factors, kind="stable")
        factors = np.asarray(factors)[keep]
        shapes = vectors[:, keep].T.copy()
        negative_factor = 0.0
    for i, x in enumerate(shapes):
        peak = x[np.argmax(np.abs(x))]
        shapes[i] = x / peak if peak else x
    result = BucklingResult(np.asarray(factors, dtype=float), shapes, how, tuple(fixed_loads),
                            model.expand(shapes, with_offset=False), base, reference,
                            timing=timing,
                            extra={"method": method, "updates": len(history),
                                   "reference_factor": history[-1][0],
                                   "static_solves": path.solves,
                                   "negative_load_factor": negative_factor})
    model.counters["buckling_analyses"] += 1
    result.wall_time_s = time.perf_counter() - start
    timing["total"] = result.wall_time_s
    return result
