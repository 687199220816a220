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
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import SolverError
from ..kernel import DirectSolver
from ..system.model import Model
from .modal import DENSE_LIMIT, linearize, null_space
from .static import StaticResult, solve_newton


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
        theta, z = spla.eigs(op, k=k, which="LR", tol=tol)
    except spla.ArpackNoConvergence as exc:
        raise SolverError(f"buckling: ARPACK did not converge ({exc})") from None
    finally:
        solver.close()
    keep = np.abs(theta.imag) <= 1e-8 * np.abs(theta).max(initial=1.0)
    return theta[keep].real, z[:n, keep].real


def buckling_analysis(model: Model, base_model: Model, count: int, *,
                      fixed_loads: tuple[str, ...] = (), base: StaticResult | None = None,
                      reference: StaticResult | None = None, solver: str = "auto",
                      tol: float = 1e-10, max_iter: int = 50, load_steps: int = 1,
                      reference_factor: float = 1.0, eigen_tol: float = 0.0) -> BucklingResult:
    """The ``count`` lowest positive load factors of ``model``'s loads beyond those of
    ``base_model`` (the same system with the fixed loads alone; pass ``model`` itself
    when nothing is fixed and no load is kept: then state 0 is the unloaded one, solved
    with the load factor 0)."""
    if count < 1:
        raise SolverError(f"buckling: modes = {count} must be at least 1")
    if model.ndof != base_model.ndof or not np.array_equal(model.e0, base_model.e0):
        raise SolverError("buckling: the model with and without the reference loads differ "
                          "in their coordinates")
    if all(s.kind == "ffr" for s in model.sets):
        raise SolverError("buckling: every beam has the 'ffr' formulation, whose constant "
                          "small-strain stiffness has no geometric (initial-stress) part; "
                          "use formulation = 'nonlinear'")
    start = time.perf_counter()
    timing: dict[str, float] = {}
    if base is None:
        base = solve_newton(base_model, tol=tol, max_iter=max_iter, load_steps=load_steps,
                            loads=0.0 if base_model is model else 1.0)
    if reference is None:
        reference = solve_newton(model, tol=tol, max_iter=max_iter, load_steps=load_steps,
                                 loads=reference_factor) if base_model is not model or \
            reference_factor != 1.0 else solve_newton(model, tol=tol, max_iter=max_iter,
                                                      load_steps=load_steps)
    timing["static"] = base.wall_time_s + reference.wall_time_s
    t0 = time.perf_counter()
    lf0 = 0.0 if base_model is model else 1.0
    lin0 = linearize(base_model, base.e, base.lam, load_factor=lf0)
    lin1 = linearize(model, reference.e, reference.lam, load_factor=reference_factor)
    kg = ((lin1.stiffness - lin0.stiffness) / reference_factor).tocsr()
    timing["assembly"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    free = model.ndof - lin0.constraints.shape[0]
    method = solver if solver != "auto" else ("dense" if free <= DENSE_LIMIT else "sparse")
    if method == "dense":
        theta, vectors = _dense(lin0.stiffness, kg, lin0.constraints, count)
    else:
        theta, vectors = _sparse(lin0.stiffness, kg, lin0.constraints, count, eigen_tol)
    timing["eigen"] = time.perf_counter() - t0
    scale = np.abs(theta).max(initial=0.0)
    positive = theta > 1e-12 * max(scale, 1e-300)
    mu = 1.0 / theta[positive]
    order = np.argsort(mu)[:count]
    shapes = vectors[:, positive][:, order].T.copy()
    for i, x in enumerate(shapes):
        peak = x[np.argmax(np.abs(x))]
        shapes[i] = x / peak if peak else x
    negative = theta < -1e-12 * max(scale, 1e-300)
    result = BucklingResult(mu[order], shapes, method, tuple(fixed_loads),
                            model.expand(shapes, with_offset=False), base, reference,
                            timing=timing,
                            extra={"reference_factor": reference_factor,
                                   "negative_load_factor": float(1.0 / theta[negative].min())
                                   if negative.any() else 0.0,
                                   "asymmetry": max(lin0.asymmetry, lin1.asymmetry)})
    model.counters["buckling_analyses"] += 1
    result.wall_time_s = time.perf_counter() - start
    timing["total"] = result.wall_time_s
    return result
