"""Static path-following by arc length (SPEC section 8.2 "Static paths", issue 34 item 2).

``solver.static_method = 'arc_length'``: the load factor P is an unknown beside the
coordinates e and the multipliers lambda. With the residual R(e, lambda, P) = r(e, P) -
Phi_e^T lambda, r = internal - external linear in P (the kernel's load factor), and the
load vector q = -dr/dP, each step of the cylindrical arc-length method of Crisfield (1981)
solves R = 0, Phi = 0 and ||Delta e|| = Delta l, where Delta e is the step's increment
from the last converged point. The step's predictor and corrector are the kernel's static
Newton (fortran/src/solvers/static_solver.f90, its arc-length request: the same residual,
tangent and MUMPS factorization as a load step, issue 36 item 4 "one static Newton"); this
module drives the path:

* predictor: Delta P = +-Delta l / ||du_q|| along the tangent du_q = K_T^{-1} q, the sign
  that keeps the direction of the previous increment (Feng's criterion: passes limit
  points, where P turns, and snap-backs, where the displacement turns);
* corrector: each Newton iteration solves the saddle-point system twice with one
  factorization, du = du_r + dP du_q, and dP is the root of the quadratic constraint whose
  new increment makes the smaller angle with the previous one (Crisfield's choice); no real
  root, or no convergence in ``max_iter`` iterations, halves the arc from the last point;
* a point whose stability index differs from the last one's is tried again at half the arc
  (up to CONFIRM_CUTS times): a long arc near a bifurcation can converge onto the other
  branch (a strip with a lateral imperfection, past its lateral-torsional buckling load,
  onto the nearly plane, unstable branch), a true limit or bifurcation point stays;
* the arc adapts to the iteration count (the corrections): times sqrt(5 / iterations),
  within [1/2, 2] per step and at most 4 times the first arc.

At every converged point the number of negative eigenvalues of the tangent on the
constrained coordinates (the stability index: 0 on a stable branch) is counted from the
eigenvalues of N^T K_T N (N a basis of the constraints' null space) for small models, else
from the lowest few of (K_T, M) by shift-invert. A point where P has an extremum is a limit
point (its load factor refined by a parabola in the path length through the three points
about it); a change of the count with no extremum of P is a bifurcation point.

The path ends at the first crossing of ``target_load_factor`` (the state there solved by
the kernel's Newton at that load factor: the static result), or after ``max_steps`` steps
(then the last point, with ``reached = False`` and a message: the run fails with exit 3
after writing it).

A load-controlled solve ('newton', 'split') converges onto any equilibrium, stable or not:
a perfect column above its Euler load stays straight, a strip loaded past its
lateral-torsional buckling load in large steps lands on the nearly plane branch (issue 39,
"right or refused"). :func:`stability_index` counts the negative eigenvalues of the
tangent on the constraints' null space at its converged state (a shifted Cholesky proves
0 in milliseconds); :func:`solve_static_path` records it, and the run refuses a state
with a count > 0 (:func:`unstable_static_message`).

:func:`diagnose_stall` reads a failed load-controlled Newton solve: cut back from the last
converged load step, it tells a limit point (the tangent stiffness along the loads falls
toward zero, or a negative eigenvalue appears) from other failures and says so, naming
``static_method = 'arc_length'``.
"""
from __future__ import annotations

import time
from dataclasses import field

import numpy as np

from ..records import record
from ..errors import InputError, SolverError
from ..system.model import Model
from .._lazy import LazyModule
from ..csr import sorted_unique
from .static import (ARC_STEP, LOAD_TANGENT, LoadStepFailure, StaticResult, kernel_static,
                     solve_static)

la = LazyModule("scipy.linalg")
# the stability index (buckling.negative_eigenvalues) on first use: a Newton solve imports
# no modal or buckling code
buckling = LazyModule("ancfdrv.solvers.buckling")

#: iterations per step the arc adapts to
DESIRED_ITERATIONS = 5
#: halvings of the arc from one point before the path is given up
MAX_CUTS = 12


@record(eq=False, repr=False)
class StaticPath:
    """The converged points of an arc-length path (HDF5: /static/path). ``displacement``
    (npoints, 3): the control probe's displacement from the assembled configuration
    (global axes);
    ``negative_eigenvalues``: the stability index of the tangent at each point;
    ``limit_points``/``bifurcation_points``: indices of the points, ``limit_load_factors``
    the limit points' load factors refined between the points."""

    load_factor: np.ndarray
    displacement: np.ndarray
    negative_eigenvalues: np.ndarray
    probe: str
    limit_points: list[int] = field(default_factory=list)
    limit_load_factors: list[float] = field(default_factory=list)
    bifurcation_points: list[int] = field(default_factory=list)
    target_load_factor: float = 1.0
    reached: bool = True
    message: str = ""


#: free coordinates up to which a load-controlled static state's stability index is
#: counted where its reduced tangent has no narrow band (dense, O(n^3)), and up to which an
#: unstable state's count is taken from all the eigenvalues (above: the lowest eight, as
#: :func:`~.buckling.negative_eigenvalues`); a wide-banded model above it is not checked (the check
#: would cost more than a fifth of the solve)
STABILITY_LIMIT = 1500
#: eigenvalues of the reduced tangent above -STABILITY_TOL times its scale count as zero
#: (a mechanism's zero-stiffness direction is round-off, not instability; as
#: :func:`~.buckling.negative_eigenvalues`)
STABILITY_TOL = 1e-10


def _constraint_groups(g: np.ndarray) -> list[np.ndarray]:
    """The columns of each group of rows of ``g`` that share columns (the constraints
    acting on the same coordinates), each sorted."""
    parent = list(range(len(g)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    owner: dict[int, int] = {}
    for c, row in enumerate(g):
        for col in np.flatnonzero(row).tolist():
            if col in owner:
                parent[root(c)] = root(owner[col])
            else:
                owner[col] = c
    groups: dict[int, list[int]] = {}
    for col, c in owner.items():
        groups.setdefault(root(c), []).append(col)
    return [np.array(sorted(cols), dtype=np.int64) for cols in groups.values()]


def _reduced_tangent(model: Model, e: np.ndarray, lam: np.ndarray, factor: float):
    """The symmetric part of the static tangent (modal.linearize's K: elastic and contact
    tangent, minus the moments' and vector loads' Jacobians and the constraint Hessians
    times the multipliers) on the constraints' null space, as triplets (rows, cols, values,
    size) in an order of narrow band, sparse and in numpy alone (a static run imports no
    scipy): the null space is the identity on the coordinates no constraint touches and,
    per group of constraints sharing coordinates, the SVD's of their Jacobian, placed at
    the group's middle among the coordinates."""
    n, ncon = model.ndof, len(model.constraints)
    r, c, v = model.stiffness_triplets(e, lam, load_factor=factor)
    touched = np.zeros(0, dtype=np.int64)
    basis, where = np.zeros((0, 0)), np.zeros(0)
    if ncon:
        _, g_rows, g_cols, grads = model.constraints.jacobian(e, n)
        grads = np.asarray(grads, dtype=float)
        nonzero = grads != 0
        g_rows = np.asarray(g_rows, dtype=np.int64)[nonzero]
        g_cols = np.asarray(g_cols, dtype=np.int64)[nonzero]
        touched = sorted_unique(g_cols)   # np.unique(g_cols) (which imports numpy.ma: csr)
        g = np.zeros((ncon, len(touched)))
        np.add.at(g, (g_rows, np.searchsorted(touched, g_cols)), grads[nonzero])
        g = g[np.abs(g).max(axis=1, initial=0.0) > 0]
        g /= np.abs(g).max(axis=1)[:, None]   # rows scaled to unit size (modal.null_space)
        parts, positions = [], []
        for group in _constraint_groups(g):
            if len(group) == 1:   # a coordinate fixed alone (a nonzero column: rank 1)
                continue          # adds no direction: nothing to decompose
            block = g[:, group]
            block = block[np.abs(block).max(axis=1) > 0]
            _, sing, vt = np.linalg.svd(block, full_matrices=True)
            rank = int(np.sum(sing > 1e-10 * max(sing.max(initial=0.0), 1e-300)))
            part = np.zeros((len(touched), len(group) - rank))
            part[group] = vt[rank:].T
            parts.append(part)
            positions.append(np.full(len(group) - rank, touched[group].mean()))
        basis = np.hstack(parts) if parts else np.zeros((len(touched), 0))
        where = np.concatenate(positions) if positions else where
    v = 0.5 * v
    r, c, v = np.concatenate([r, c]), np.concatenate([c, r]), np.concatenate([v, v])
    # the symmetric part's triplets (duplicates add up where they are used)
    is_free = np.ones(n, dtype=bool)
    is_free[touched] = False
    free = np.flatnonzero(is_free)   # np.setdiff1d(np.arange(n), touched) without numpy.ma
    nf, size = len(free), len(free) + basis.shape[1]
    rank_of = np.empty(size, dtype=np.int64)
    rank_of[np.argsort(np.concatenate([free.astype(float), where]), kind="stable")] = \
        np.arange(size)
    slot = np.full(n, -1, dtype=np.int64)   # a coordinate's place among free or touched
    slot[free] = np.arange(nf)
    slot[touched] = np.arange(len(touched))
    both = is_free[r] & is_free[c]
    out_r, out_c, out_v = [rank_of[slot[r[both]]]], [rank_of[slot[c[both]]]], [v[both]]
    if basis.shape[1]:
        mixed = is_free[r] & ~is_free[c]
        k_ft = np.zeros((nf, len(touched)))
        np.add.at(k_ft, (slot[r[mixed]], slot[c[mixed]]), v[mixed])
        inner = ~is_free[r] & ~is_free[c]
        k_tt = np.zeros((len(touched), len(touched)))
        np.add.at(k_tt, (slot[r[inner]], slot[c[inner]]), v[inner])
        k_fn = k_ft @ basis
        coupled = np.flatnonzero(np.abs(k_fn).max(axis=1) > 0)
        nn = nf + np.arange(basis.shape[1])
        fr, nc = np.repeat(coupled, len(nn)), np.tile(nn, len(coupled))
        fv = k_fn[coupled].ravel()
        k_nn = basis.T @ k_tt @ basis
        out_r += [rank_of[fr], rank_of[nc], rank_of[np.repeat(nn, len(nn))]]
        out_c += [rank_of[nc], rank_of[fr], rank_of[np.tile(nn, len(nn))]]
        out_v += [fv, fv, k_nn.ravel()]
    return np.concatenate(out_r), np.concatenate(out_c), np.concatenate(out_v), size


def _positive_definite(rows: np.ndarray, cols: np.ndarray, vals: np.ndarray, size: int,
                       band: int) -> bool:
    """Whether the symmetric matrix of the triplets is positive definite: its Cholesky
    factorization, by blocks of the bandwidth ``band`` where it is narrow (the matrix is
    then block tridiagonal: O(n b^2)), else dense."""
    try:
        if band == 0 or 4 * band > size:
            dense = np.zeros((size, size))
            np.add.at(dense, (rows, cols), vals)
            np.linalg.cholesky(dense)
            return True
        count = -(-size // band)
        diagonal = np.zeros((count, band, band))
        below = np.zeros((count, band, band))   # below[i]: block (i + 1, i)
        bi, bj = rows // band, cols // band
        on = bi == bj
        np.add.at(diagonal, (bi[on], rows[on] % band, cols[on] % band), vals[on])
        sub = bi == bj + 1
        np.add.at(below, (bj[sub], rows[sub] % band, cols[sub] % band), vals[sub])
        pad = np.arange(size, count * band) - (count - 1) * band
        diagonal[-1, pad, pad] = 1.0   # the last block's padding: positive, no coupling
        carried = None
        for i in range(count):
            block = diagonal[i] if carried is None else diagonal[i] - carried @ carried.T
            factor = np.linalg.cholesky(block)
            carried = np.linalg.solve(factor, below[i].T).T   # L_{i+1,i} = A_{i+1,i} L_ii^-T
    except np.linalg.LinAlgError:
        return False
    return True


def stability_index(model: Model, e: np.ndarray, lam: np.ndarray, factor: float) -> int | None:
    """The stability index of a converged static state: the number of eigenvalues of the
    tangent on the constraints' null space below -STABILITY_TOL times its largest (0: a
    stable equilibrium, or neutral in a mechanism's zero-stiffness directions). A Cholesky
    factorization of the reduced tangent shifted by the tolerance times its largest
    diagonal proves the count 0 (the usual case; by blocks where the band is narrow); else
    the eigenvalues count it. None: not counted (above STABILITY_LIMIT free coordinates
    with no narrow band)."""
    rows, cols, vals, size = _reduced_tangent(model, e, lam, factor)
    if not size:
        return 0
    band = int(np.abs(rows - cols).max(initial=0))
    if size > STABILITY_LIMIT and 4 * band > size:
        return None
    shift = STABILITY_TOL * max(np.abs(vals[rows == cols]).max(initial=0.0), 1e-300)
    diagonal = np.arange(size)
    if _positive_definite(np.concatenate([rows, diagonal]), np.concatenate([cols, diagonal]),
                          np.concatenate([vals, np.full(size, shift)]), size, band):
        return 0
    if size > STABILITY_LIMIT:
        return buckling.negative_eigenvalues(model, e, lam, factor)
    dense = np.zeros((size, size))
    np.add.at(dense, (rows, cols), vals)
    w = np.linalg.eigvalsh(dense)
    return int(np.sum(w < -STABILITY_TOL * max(np.abs(w).max(), 1e-300)))


def _kernel_newton_at(model: Model, e: np.ndarray, lam: np.ndarray, factor: float,
                      tol: float, max_iter: int, floor: float = -1.0,
                      account: bool = True) -> dict | None:
    """The kernel's Newton at the fixed load factor ``factor`` from (e, lam): its result
    (e, lam, force_res, con_res, ...), or None when it does not converge (the kernel's
    stall test ends a tolerance beyond round-off early). ``floor``: the residual's scale
    floor (< 0: the forces at the start); ``account``: as :func:`~.static.kernel_static`."""
    out = kernel_static(model, e, lam, factor, tol=tol, max_iter=max_iter, force_scale=floor,
                        account=account)
    return None if out["info"] else out


def _load_tangent(model: Model, e: np.ndarray, lam: np.ndarray, factor: float,
                  account: bool = True) -> dict | None:
    """The tangent along the loads at (e, lam, P) from the kernel: load_norm ||q||,
    tangent_norm ||du_q|| and flexibility q . du_q (du_q = K_T^{-1} q on the constraints),
    or None when the tangent cannot be factorized (singular)."""
    out = kernel_static(model, e, lam, factor, tol=1.0, max_iter=1, mode=LOAD_TANGENT,
                        account=account)
    return None if out["info"] else out


def _probe_displacement(model: Model, e: np.ndarray, probe: str) -> np.ndarray:
    """The probe's displacement from the assembled configuration, global axes."""
    return model.probe_positions(e)[probe] - model.probe_positions(model.e0)[probe]


def _marks(factors: np.ndarray, counts: np.ndarray, lengths: np.ndarray):
    """Limit points (extrema of P, refined by a parabola in the path length) and
    bifurcation points (the count changes with no extremum of P next to it)."""
    limits, refined, bifurcations = [], [], []
    for i in range(1, len(factors) - 1):
        if (factors[i] - factors[i - 1]) * (factors[i + 1] - factors[i]) < 0:
            limits.append(i)
            s = lengths[i - 1:i + 2] - lengths[i]
            a, b, c = np.polyfit(s, factors[i - 1:i + 2], 2)
            vertex = -b / (2 * a) if a != 0 else 0.0
            refined.append(float(c - b * b / (4 * a)) if a != 0 and
                           s[0] <= vertex <= s[2] else float(factors[i]))
    for i in range(1, len(factors)):
        if counts[i] != counts[i - 1] and not {i - 1, i} & set(limits):
            bifurcations.append(i)
    return limits, refined, bifurcations


#: shorter arcs tried before a change of the stability index is accepted as the path's: a
#: long arc near a bifurcation can converge onto the other branch (past a strip's
#: lateral-torsional buckling, onto the nearly plane, unstable one), a true change of
#: stability (a limit or bifurcation point on the path) persists at half the arc
CONFIRM_CUTS = 3


@record(eq=False, repr=False)
class _Point:
    """The path's next point (or why there is none: ``message``)."""
    e: np.ndarray | None = None
    lam: np.ndarray | None = None
    factor: float = 0.0
    count: int = 0
    arc: float = 0.0
    iterations: int = 0
    step_residual: float = 0.0
    last: dict = field(default_factory=dict)
    reached: bool = False
    message: str = ""


def _next_point(model: Model, e: np.ndarray, lam: np.ndarray, factor: float, arc: float,
                direction: float, previous: np.ndarray | None, number: int, count: int,
                target: float, *, tol: float, max_iter: int,
                floor: float) -> _Point:
    """One arc-length step from the converged point (e, lam, factor) of stability index
    ``count``: the kernel's corrector, the arc halved where it does not converge (MAX_CUTS
    times at most) or where the index changes (CONFIRM_CUTS times, then the change is the
    path's); a step that crosses ``target`` is landed on it by Newton at that factor."""
    cuts = confirms = 0
    while True:
        step = kernel_static(model, e, lam, factor, tol=tol, max_iter=max_iter,
                             force_scale=floor, mode=ARC_STEP, arc=arc, direction=direction,
                             previous=previous, load_step=number)
        if step["info"]:
            cuts += 1
            if cuts > MAX_CUTS:
                return _Point(message=(
                    f"arc length: no step converged from load factor {factor:.6g} with the "
                    f"arc cut {MAX_CUTS} times (to {arc:.3e}); the path ends there (last: "
                    f"{step['message'].split('; ')[0]})"))
            arc *= 0.5
            continue
        e_new, lam_new, factor_new = step["e"], step["lam"], step["load_factor"]
        last, reached = step, False
        if (factor - target) * (factor_new - target) <= 0 and factor_new != factor:
            w = (target - factor) / (factor_new - factor)
            landed = _kernel_newton_at(model, e + w * (e_new - e), lam + w * (lam_new - lam),
                                       target, tol, max_iter, floor)
            if landed is None:   # too close to a limit: a shorter arc first
                cuts += 1
                if cuts > MAX_CUTS:
                    return _Point(message=(
                        f"arc length: the path crosses target_load_factor = {target:.6g} "
                        f"but Newton at it did not converge with the arc cut {MAX_CUTS} "
                        "times"))
                arc *= 0.5
                continue
            e_new, lam_new, factor_new, last, reached = \
                landed["e"], landed["lam"], target, landed, True
        count_new = buckling.negative_eigenvalues(model, e_new, lam_new, factor_new)
        if count_new != count and confirms < CONFIRM_CUTS:
            confirms += 1
            arc *= 0.5
            continue
        return _Point(e_new, lam_new, factor_new, count_new, arc, step["iterations"] - 1,
                      step["force_res"], last, reached)


def solve_arc_length(model: Model, *, tol: float = 1e-10, max_iter: int = 50,
                     arc_length: float = 0.0, max_steps: int = 200,
                     target_load_factor: float = 1.0, control_probe: str = "") -> StaticResult:
    """The static path from the assembled configuration by cylindrical arc length (module
    doc) up to ``target_load_factor``; the result is the state there (or the last point)
    with ``path`` the :class:`StaticPath`. ``arc_length`` 0: a twentieth of the linear
    response to the target load. ``control_probe`` '' : the model's response probe."""
    model.require_runnable()
    model.check_alive()
    if not model.probes:
        raise InputError("static_method = 'arc_length' records the path at a probe; the "
                         "scene has none: add a &probe (solver.control_probe names it)",
                         group="solver", key="control_probe")
    probe = control_probe or (model.response[0] if model.response else next(iter(model.probes)))
    if probe not in model.probes:
        raise InputError(f"control_probe {probe!r} is no probe of the scene (probes: "
                         f"{', '.join(model.probes)})", group="solver", key="control_probe")
    if target_load_factor == 0.0:
        raise InputError("target_load_factor must not be 0", group="solver",
                         key="target_load_factor")
    start = time.perf_counter()
    e, lam, factor = model.e0.copy(), np.zeros(len(model.constraints)), 0.0
    tangent = _load_tangent(model, e, lam, factor)
    if tangent is None:
        raise SolverError("arc length: the tangent is singular at the start")
    floor = abs(target_load_factor) * tangent["load_norm"]
    # a prestressed start is settled at load factor 0 (an unstressed one ends at once)
    settled = kernel_static(model, e, lam, 0.0, tol=tol, max_iter=max_iter,
                            force_scale=floor, check_start=True)
    if settled["info"]:
        raise SolverError("arc length: the state at load factor 0 did not converge ("
                          f"{settled['message'].split('; raise')[0]})")
    force_res, con_res = settled["force_res"], settled["con_res"]
    if settled["iterations"]:
        e, lam = settled["e"], settled["lam"]
        tangent = _load_tangent(model, e, lam, factor)
        if tangent is None:
            raise SolverError("arc length: the tangent is singular at the settled start")
    direction = np.sign(target_load_factor)
    arc = arc_length if arc_length > 0 else \
        abs(target_load_factor) * tangent["tangent_norm"] / 20
    if not arc > 0:
        raise InputError("arc length: the loads move nothing (zero load vector); nothing to "
                         "follow", group="solver", key="static_method")
    largest = 4.0 * arc
    factors, disps, counts, lengths = [0.0], [_probe_displacement(model, e, probe)], \
        [buckling.negative_eigenvalues(model, e, lam, factor)], [0.0]
    previous: np.ndarray | None = None   # the last step's increment of e
    iterations_total, history = 0, []
    reached, message = False, ""
    for number in range(1, max_steps + 1):
        point = _next_point(model, e, lam, factor, arc, direction, previous, number, counts[-1],
                            target_load_factor, tol=tol, max_iter=max_iter, floor=floor)
        if point.message:
            message = point.message
            break
        arc, last, reached = point.arc, point.last, point.reached
        iterations_total += point.iterations
        history.append(point.step_residual)
        force_res, con_res = last["force_res"], last["con_res"]
        previous = point.e - e
        lengths.append(lengths[-1] + float(np.linalg.norm(previous)))
        e, lam, factor = point.e, point.lam, point.factor
        factors.append(factor)
        disps.append(_probe_displacement(model, e, probe))
        counts.append(point.count)
        if reached:
            break
        arc = min(largest, arc * float(np.clip(
            np.sqrt(DESIRED_ITERATIONS / max(point.iterations, 1)), 0.5, 2.0)))
    else:
        message = (f"arc length: the path did not reach target_load_factor = "
                   f"{target_load_factor:.6g} in max_steps = {max_steps} steps (last load "
                   f"factor {factor:.6g}); raise solver.max_steps or solver.arc_length")
    factors_a, counts_a = np.asarray(factors), np.asarray(counts, dtype=np.int64)
    limits, refined, bifurcations = _marks(factors_a, counts_a, np.asarray(lengths))
    path = StaticPath(factors_a, np.asarray(disps), counts_a, probe, limits, refined,
                      bifurcations, float(target_load_factor), reached, message)
    wall = time.perf_counter() - start
    result = StaticResult(e, lam, "arc_length", iterations_total, force_res, con_res, wall,
                          history,
                          {"assembly": 0.0, "factorization": 0.0, "solve": wall, "total": wall},
                          extra={"load_factor": factor, "path_points": len(factors),
                                 "reached": reached})
    result.path = path
    return result


def diagnose_stall(model: Model, failure: LoadStepFailure, *, tol: float, max_iter: int,
                   cuts: int = 10) -> SolverError:
    """The error to report for a failed load-controlled Newton solve: cut the failing load
    step back from its last converged state (halving up to ``cuts`` times) to the highest
    load factor P* that converges; when there the tangent stiffness along the loads,
    q^T (K_T^{-1} q) at the start over the same at P*, has fallen below 0.1 or the
    tangent has a negative eigenvalue, the loads pass a maximum the structure cannot carry
    under load control: say so and name arc_length. Otherwise the original failure. The
    diagnosis leaves the model as the failed solve left it (its counters and contact
    guesses: the solves it tries are no part of the run's)."""
    e, lam, reached, above = failure.e, failure.lam, failure.last_factor, failure.factor
    for _ in range(cuts):
        middle = 0.5 * (reached + above)
        trial = _kernel_newton_at(model, e, lam, middle, tol, max_iter, account=False)
        if trial is None:
            above = middle
        else:
            e, lam, reached = trial["e"], trial["lam"], middle
    if _kernel_newton_at(model, e, lam, failure.factor, tol, max_iter,
                         account=False) is not None:
        return failure   # the whole step converges from closer: not a limit (load_steps helps)
    start = _load_tangent(model, model.e0, np.zeros(len(model.constraints)), 0.0,
                          account=False)
    at = _load_tangent(model, e, lam, reached, account=False)
    flex0 = start["flexibility"] if start is not None else np.nan
    flex = at["flexibility"] if at is not None else np.inf
    ratio = flex0 / flex if flex != 0 else 0.0
    negative = buckling.negative_eigenvalues(model, e, lam, reached)
    if not (ratio < 0.1 or negative > 0):
        return failure
    head = str(failure).split("; raise")[0]
    return SolverError(
        f"static Newton stalled near a limit point of the load path: the loads converge up "
        f"to {reached:.6g} times their value, not beyond (the step was cut {cuts} times), and "
        f"the tangent stiffness along the loads has fallen to {ratio:.3g} of its start"
        f"{f' with {negative} negative eigenvalue(s)' if negative else ''}; load control "
        f"cannot pass a maximum of the load: use solver.static_method = 'arc_length' "
        f"(the load factor an unknown) to follow the path past it ({head})")


#: the values of ``solver.static_method``
STATIC_METHODS = ("auto", "split", "newton", "arc_length")


def solve_static_path(model: Model, method: str, *, tol: float, max_iter: int,
                      p: float = 0.0, load_steps: int = 1, arc_length: float = 0.0,
                      max_steps: int = 200, target_load_factor: float = 1.0,
                      control_probe: str = "") -> StaticResult:
    """The static solve of a scene: 'arc_length' follows the path
    (:func:`solve_arc_length`), the other methods are :func:`~.static.solve_static`'s; a
    load-controlled Newton that fails is diagnosed (:func:`diagnose_stall`), one that
    converges has its state's :func:`stability_index` in ``extra['stability_index']``
    (absent above STABILITY_LIMIT free coordinates)."""
    if method not in STATIC_METHODS:
        raise InputError(f"static_method {method!r} must be one of {', '.join(STATIC_METHODS)}",
                         group="solver", key="static_method")
    if method == "arc_length":
        result = solve_arc_length(model, tol=tol, max_iter=max_iter, arc_length=arc_length,
                                  max_steps=max_steps, target_load_factor=target_load_factor,
                                  control_probe=control_probe)
        result.extra["method_setting"] = method
        return result
    try:
        result = solve_static(model, method, tol=tol, max_iter=max_iter, p=p,
                              load_steps=load_steps)
    except LoadStepFailure as failure:
        raise diagnose_stall(model, failure, tol=tol, max_iter=max_iter) from None
    # load control converges onto any equilibrium, stable or not (issue 39): count it
    start = time.perf_counter()
    index = stability_index(model, result.e, result.lam, result.extra.get("load_factor", 1.0))
    result.timing["stability"] = time.perf_counter() - start
    if index is not None:
        result.extra["stability_index"] = index
    return result


def unstable_static_message(index: int) -> str:
    """Why a load-controlled static state with stability index ``index`` > 0 is refused,
    and what to do."""
    return (f"the static state found is unstable: its tangent stiffness has {index} "
            f"negative eigenvalue(s) on the constraints' null space ({index} direction(s) in "
            f"which the structure leaves it); a load-controlled solve can pass a bifurcation "
            f"or limit point without seeing it and converge onto an unstable equilibrium "
            f"(e.g. a perfect column above its Euler load stays straight): use "
            f"solver.static_method = 'arc_length' with a small imperfection (a load or "
            f"geometry slightly off the perfect case) to follow the stable branch, or "
            f"analysis = 'buckling' for the critical load; the state found is kept in /static "
            f"(attribute stability_index)")
