#!/usr/bin/env python
"""Scaling of the boom statics with the mesh size, and how far the solvers are from the floor.

For every node count (3k+1) of the boom of ``inputs/boom_static.nml`` this measures the
wall clock (``time.perf_counter``), best of N repeats; N is chosen so that the repeats of
one measurement take at least ``--min-time`` seconds and number at least
``--min-repeats``, unless they already took ``--max-time`` (see :class:`Budget`):

* ``build_model`` (element arrays, sparse pattern, constraints, loads);
* one stiffness assembly ``model.stiffness_values()``;
* MUMPS (:class:`ancfdrv.kernel.DirectSolver`) analyse + factorization + one solve of

  - the Newton saddle-point matrix [[K - dQ/de - lambda.H, -Phi_e^T], [-Phi_e, 0]] at the
    rigid configuration, assembled exactly as the first iteration of
    :func:`ancfdrv.solvers.static.solve_newton` assembles it;
  - K_RR, the stiffness without the split's dependent coordinates (what
    :func:`ancfdrv.solvers.static.solve_split` factorizes once);
  - K itself (singular: the floating-frame stiffness has six rigid-body modes; timed for
    its size only, its solution is meaningless);

* ``scipy.sparse.linalg.spsolve`` (SuperLU) of the same saddle-point system, as a second
  reference, with the difference between both solutions as a sanity check;
* the full static solves ``solve_newton`` and ``solve_split`` (iterations, phases).

"The floor" of a static solve is the cost of a single linear solve from scratch of the
matrix it works with: analyse + one factorization + one solve of the saddle-point matrix
(MUMPS), or ``spsolve`` of it. The ratios static time / floor say how much a full
nonlinear solve costs over one linear solve of the same size.

Each static solve is first timed at ``--tol``; when it does not converge there (the
relative residual of fine meshes stagnates at a round-off floor that grows with the mesh),
the failure is recorded and the solve is timed at ``--fallback-tol``, so a converged time
is always reported with the tolerance it was reached at and how the solver stopped
(``converged_by``, from the solvers' shared test :func:`ancfdrv.solvers.static.converged`:
residual, or step at the round-off floor with the residual below sqrt(tol)).
Process CPU time (user/system) and minor page faults of the best repeat are recorded too:
a large system share means time spent page-faulting freshly allocated memory.

Ported to the general-system model layer (``ancfdrv.builders.build_model`` returns an
``ancfdrv.system.model.Model`` whose forces come from a kernel handle): ``build_model`` now
also hands the system to the kernel and analyses the iteration matrix's pattern, and each
timed build is closed again (``model.close()``: the kernel holds at most 256 systems); the
stiffness assembly is ``model.stiffness_values()``, a force + tangent evaluation of the
kernel system; the Newton saddle-point system is assembled as the new
:func:`ancfdrv.solvers.static.solve_newton` assembles its first iteration (right-hand side
[-(Q_int - Q), Phi] from ``model.forces``). Records, keys and tables are unchanged.

Results: a table on stdout and JSON (machine info, one record per node count, growth
exponents) in ``benchmarks/results/``. Run from the repository root::

    python benchmarks/static_scaling.py            # 4 ... 2002 nodes
    python benchmarks/static_scaling.py --quick    # up to 301 nodes
"""
from __future__ import annotations

import argparse
import datetime as _dt
import gc
import math
import resource
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from _common import load_average, machine_info, print_table, write_report
from ancfdrv.errors import SolverError
from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.kernel import DirectSolver
from ancfdrv.solvers.static import StaticResult, solve_newton, solve_split
from ancfdrv.system.model import Model

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "inputs" / "boom_static.nml"
RESULTS = REPO / "benchmarks" / "results"
NODES = (4, 10, 16, 22, 28, 100, 301, 1000, 2002)
QUICK_MAX_NODES = 301

StaticSolver = Callable[..., StaticResult]
SOLVERS: dict[str, StaticSolver] = {"newton": solve_newton, "split": solve_split}


# -- timing ----------------------------------------------------------------------------
@dataclass(frozen=True)
class Budget:
    """How often a measurement is repeated: until the repeats took ``min_time`` seconds
    together and there were ``min_repeats`` of them, unless they already took
    ``max_time`` seconds; never more than ``max_repeats``; always at least once."""

    min_time: float = 0.2
    min_repeats: int = 3
    max_time: float = 5.0
    max_repeats: int = 10_000

    def done(self, spent: float, calls: int) -> bool:
        if calls == 0:
            return False
        if calls >= self.max_repeats or spent >= self.max_time:
            return True
        return spent >= self.min_time and calls >= self.min_repeats


@dataclass
class Timing:
    """Best-of-N wall time of one measurement, with what the best repeat reported.

    ``phases`` are the sub-timings (seconds) the measured call returned, e.g. analyse /
    factorize / solve, or a static solve's ``timing`` dict; ``cpu_user_s``, ``cpu_sys_s``
    and ``minor_faults`` are the process's resource usage during the best repeat (all
    threads; system time and page faults reveal allocation of fresh memory).
    """

    best_s: float
    median_s: float
    repeats: int
    phases: dict[str, float] = field(default_factory=dict)
    cpu_user_s: float = math.nan
    cpu_sys_s: float = math.nan
    minor_faults: int = 0
    discarded: int = 0


class Discard(Exception):
    """Raised by a measured call whose sample must not count (e.g. a solve that did not
    converge this time although it did before)."""


def best_of(run: Callable[[], object], budget: Budget) -> Timing:
    """Call ``run`` as often as ``budget`` says and keep the fastest call. When ``run``
    returns a dict, it is taken as the phase timings of that call; when it raises
    :class:`Discard`, the call is not a sample (but its time counts against the budget);
    any other exception propagates."""
    samples: list[Timing] = []
    spent, calls, discarded = 0.0, 0, 0
    gc.collect()
    while not samples or not budget.done(spent, calls):
        r0 = resource.getrusage(resource.RUSAGE_SELF)
        t0 = time.perf_counter()
        try:
            out = run()
        except Discard:
            out = Discard
        elapsed = time.perf_counter() - t0
        r1 = resource.getrusage(resource.RUSAGE_SELF)
        spent, calls = spent + elapsed, calls + 1
        if out is Discard:
            discarded += 1
            if discarded > max(3, calls // 2):
                raise RuntimeError("best_of: most repeats were discarded")
            continue
        samples.append(Timing(best_s=elapsed, median_s=elapsed, repeats=1,
                              phases=dict(out) if isinstance(out, dict) else {},
                              cpu_user_s=r1.ru_utime - r0.ru_utime,
                              cpu_sys_s=r1.ru_stime - r0.ru_stime,
                              minor_faults=r1.ru_minflt - r0.ru_minflt))
    best = min(samples, key=lambda t: t.best_s)
    best.median_s = float(np.median([t.best_s for t in samples]))
    best.repeats, best.discarded = len(samples), discarded
    return best


# -- matrices ----------------------------------------------------------------------------
@dataclass
class LinearSystem:
    """A square system in coordinate form (duplicates are summed) and a right-hand side."""

    n: int
    rows: np.ndarray
    cols: np.ndarray
    values: np.ndarray
    rhs: np.ndarray

    def to_csc(self) -> sp.csc_matrix:
        return sp.coo_matrix((self.values, (self.rows, self.cols)),
                             shape=(self.n, self.n)).tocsc()


def newton_saddle_system(model: Model) -> LinearSystem:
    """The saddle-point system of the first Newton iteration (d = 0, lambda = 0), with the
    same triplet pattern and values as :func:`ancfdrv.solvers.static.solve_newton`."""
    n, ncon = model.ndof, len(model.constraints)
    e = model.e0
    lam = np.zeros(ncon)
    h_con, h_rows, h_cols, h_vals = model.constraints.hessian_triplets(e)
    phi, j_rows, j_cols, grads = model.constraints.jacobian(e, n)
    moments = model.moment_terms(e)
    m_rows = [np.repeat(cols, len(cols)) for cols, *_ in moments]
    m_cols = [np.tile(cols, len(cols)) for cols, *_ in moments]
    forces = model.forces(e, 0.0, want_tangent=True)
    rows = np.concatenate([model.pattern.rows, h_rows, *m_rows, n + j_rows, j_cols])
    cols = np.concatenate([model.pattern.col_index, h_cols, *m_cols, j_cols, n + j_rows])
    values = np.concatenate([forces["tangent"], -lam[h_con] * h_vals,
                             *[-j.ravel() for _, _, j, _ in moments], -grads, -grads])
    residual = forces["internal"] - forces["external"]  # the reactions vanish at lambda = 0
    return LinearSystem(n + ncon, rows, cols, values, np.concatenate([-residual, phi]))


def stiffness_system(model: Model, *, reduced: bool) -> LinearSystem:
    """K (``reduced=False``) or K_RR, K without the split's dependent coordinates, with
    the constant load as right-hand side."""
    stiffness = model.stiffness_matrix()
    force = model.constant_force()
    if reduced:
        rest = np.setdiff1d(np.arange(model.ndof), np.asarray(model.constraints.dependent))
        stiffness, force = stiffness[rest][:, rest], force[rest]
    coo = stiffness.tocoo()
    return LinearSystem(coo.shape[0], coo.row, coo.col, coo.data, force)


def relative_residual(system: LinearSystem, x: np.ndarray) -> float:
    """|A x - b| / |b| (2-norms)."""
    return float(np.linalg.norm(system.to_csc() @ x - system.rhs)
                 / np.linalg.norm(system.rhs))


# -- measurements -------------------------------------------------------------------------
def time_mumps(system: LinearSystem, what: str,
               budget: Budget) -> tuple[Timing, np.ndarray | None, str | None]:
    """Create + analyse + factorize + one solve + destroy with DirectSolver (phases
    analyse, factorize, solve). Returns the timing, the solution and, when MUMPS refused
    the matrix, its error message (the timing is then empty)."""
    solution: list[np.ndarray] = []

    def run() -> dict[str, float]:
        rhs = system.rhs.copy()  # DirectSolver.solve copies rhs now; kept for older builds
        t0 = time.perf_counter()
        with DirectSolver(system.n, system.rows, system.cols, what=what) as solver:
            t1 = time.perf_counter()
            solver.factorize(system.values)
            t2 = time.perf_counter()
            x = solver.solve(rhs)
            t3 = time.perf_counter()
        solution[:] = [x]
        return {"analyse": t1 - t0, "factorize": t2 - t1, "solve": t3 - t2}

    try:
        timing = best_of(run, budget)
    except SolverError as exc:
        return Timing(math.nan, math.nan, 0), None, str(exc)
    return timing, solution[0], None


def time_spsolve(system: LinearSystem, budget: Budget) -> tuple[Timing, np.ndarray]:
    """scipy's spsolve (SuperLU) of the system; the CSC conversion is not timed."""
    matrix = system.to_csc()
    solution: list[np.ndarray] = []

    def run() -> None:
        solution[:] = [spla.spsolve(matrix, system.rhs)]

    return best_of(run, budget), solution[0]


def time_static(model: Model, method: str, tols: list[float], *, max_iter: int,
                budget: Budget) -> dict[str, Any]:
    """A static solve timed at the first tolerance of ``tols`` it reaches. A solve that
    fails on its first call at a tolerance is recorded (message, time to failure) and the
    next tolerance is tried; one that fails on a later repeat is dropped from the samples
    and recorded too (near the round-off floor convergence may flicker)."""
    solve = SOLVERS[method]
    failures: list[dict[str, Any]] = []
    for tol in tols:
        results: list[StaticResult] = []

        def run() -> dict[str, float]:
            try:
                results.append(solve(model, tol=tol, max_iter=max_iter))
            except SolverError as exc:
                if not results:
                    raise
                failures.append({"tol": tol, "error": f"on a repeat: {exc}",
                                 "time_to_failure_s": math.nan})
                raise Discard from exc
            return results[-1].timing

        t0 = time.perf_counter()
        try:
            timing = best_of(run, budget)
        except SolverError as exc:
            failures.append({"tol": tol, "error": str(exc),
                             "time_to_failure_s": time.perf_counter() - t0})
            continue
        phases = timing.phases
        phases["other"] = phases["total"] - sum(phases[k] for k in
                                                ("assembly", "factorization", "solve"))
        result = results[0]
        return {"method": method, "converged": True, "tol": tol,
                "converged_at_requested_tol": tol == tols[0],
                "converged_by": result.extra.get("converged_by", "residual"),
                "failures": failures, "iterations": result.iterations,
                "residual_norm": result.residual_norm,
                "constraint_norm": result.constraint_norm, "history": result.history,
                "extra": result.extra, "timing": asdict(timing)}
    return {"method": method, "converged": False, "failures": failures}


def measure(nodes: int, args: argparse.Namespace) -> dict[str, Any]:
    """All measurements of one node count."""
    budget = args.budget
    scene = load_scene(SCENE, [f"beam.nodes={nodes}", f"boom.angle_deg={args.angle}"])
    def build_and_release() -> None:
        build_model(scene).close()  # the kernel holds at most 256 systems alive

    build = best_of(build_and_release, budget)
    model = build_model(scene)
    try:
        return _measure_model(model, nodes, build, args)
    finally:
        model.close()


def _measure_model(model: Model, nodes: int, build: Timing,
                   args: argparse.Namespace) -> dict[str, Any]:
    """The measurements on a built model (``build``: the timing of ``build_model``)."""
    budget = args.budget
    assembly = best_of(model.stiffness_values, budget)

    saddle = newton_saddle_system(model)
    systems = {"saddle": saddle, "K_RR": stiffness_system(model, reduced=True),
               "K": stiffness_system(model, reduced=False)}
    mumps: dict[str, Any] = {}
    solutions: dict[str, np.ndarray | None] = {}
    for name, system in systems.items():
        timing, solutions[name], error = time_mumps(system, f"benchmark {name}", budget)
        mumps[name] = {"n": system.n, "nnz_triplets": len(system.values),
                       "timing": asdict(timing), "error": error}
    scipy_timing, scipy_x = time_spsolve(saddle, budget)
    mumps_x = solutions["saddle"]
    check = {"relative_difference": math.nan, "residual_mumps": math.nan,
             "residual_spsolve": relative_residual(saddle, scipy_x)}
    if mumps_x is not None:
        check["relative_difference"] = float(np.linalg.norm(scipy_x - mumps_x)
                                             / np.linalg.norm(scipy_x))
        check["residual_mumps"] = relative_residual(saddle, mumps_x)

    static = {method: time_static(model, method, [args.tol, args.fallback_tol],
                                  max_iter=args.max_iter, budget=budget)
              for method in SOLVERS}

    saddle_timing = mumps["saddle"]["timing"]
    floor_mumps = saddle_timing["best_s"]
    floor_mumps_no_analyse = (saddle_timing["phases"].get("factorize", math.nan)
                              + saddle_timing["phases"].get("solve", math.nan))
    floor_scipy = scipy_timing.best_s
    ratios: dict[str, float] = {}
    for method, rec in static.items():
        total = _static_best(rec)
        ratios[f"{method}_over_mumps_floor"] = total / floor_mumps
        ratios[f"{method}_over_mumps_factorize_solve"] = total / floor_mumps_no_analyse
        ratios[f"{method}_over_spsolve"] = total / floor_scipy
    return {
        "nodes": nodes, "ndof": model.ndof, "nconstraints": len(model.constraints),
        "nnz_K": model.pattern.nnz,
        "build_model": asdict(build), "stiffness_assembly": asdict(assembly),
        "mumps": mumps,
        "spsolve_saddle": {"timing": asdict(scipy_timing)},
        "saddle_solution_check": check,
        "floor": {"mumps_analyse_factorize_solve_s": floor_mumps,
                  "mumps_factorize_solve_s": floor_mumps_no_analyse,
                  "spsolve_s": floor_scipy},
        "static": static, "ratios": ratios,
    }


# -- reporting ----------------------------------------------------------------------------




def _static_best(rec: dict[str, Any]) -> float:
    return rec["timing"]["best_s"] if rec["converged"] else math.nan


def growth_exponents(records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Local exponents d log(time) / d log(ndof) between consecutive node counts."""
    series: dict[str, Callable[[dict[str, Any]], float]] = {
        "build_model": lambda r: r["build_model"]["best_s"],
        "assembly": lambda r: r["stiffness_assembly"]["best_s"],
        "mumps_saddle": lambda r: r["floor"]["mumps_analyse_factorize_solve_s"],
        "mumps_K_RR": lambda r: r["mumps"]["K_RR"]["timing"]["best_s"],
        "spsolve": lambda r: r["floor"]["spsolve_s"],
        "newton": lambda r: _static_best(r["static"]["newton"]),
        "split": lambda r: _static_best(r["static"]["split"]),
    }
    out = []
    for a, b in zip(records[:-1], records[1:]):
        scale = math.log(b["ndof"] / a["ndof"])
        out.append({"nodes": [a["nodes"], b["nodes"]],
                    **{k: math.log(f(b) / f(a)) / scale for k, f in series.items()}})
    return out


def _ms(seconds: float, width: int = 9) -> str:
    return f"{'-':>{width}}" if not math.isfinite(seconds) else f"{1e3 * seconds:{width}.3f}"


def _iterations(rec: dict[str, Any]) -> str:
    """Iterations with how the solve stopped (:func:`ancfdrv.solvers.static.converged`): r
    residual <= tol, s step <= tol |d| at round-off (residual up to sqrt(tol)), * only at
    the fallback tolerance."""
    if not rec["converged"]:
        return "FAIL"
    how = {"residual": "r", "step": "s"}.get(rec["converged_by"], "?")
    return f"{rec['iterations']}{how}{'' if rec['converged_at_requested_tol'] else '*'}"




def print_tables(records: list[dict[str, Any]], exponents: list[dict[str, Any]],
                 args: argparse.Namespace) -> None:
    """Readable tables of the records (times in ms, best of N)."""
    b = args.budget
    print(f"\nBoom statics at {args.angle:g} deg; times in ms, best of N repeats (N >= "
          f"{b.min_repeats} and >= {b.min_time:g} s per measurement, unless one took "
          f">= {b.max_time:g} s)")

    print("\n[1] model, assembly, MUMPS create+analyse+factorize (a+f); "
          "K is singular (6 rigid-body modes), timed for its size only")
    rows = []
    for r in records:
        af = {name: (m["timing"]["phases"].get("analyse", math.nan)
                     + m["timing"]["phases"].get("factorize", math.nan))
              for name, m in r["mumps"].items()}
        rows.append([str(r["nodes"]), str(r["ndof"]), str(r["nnz_K"]),
                     _ms(r["build_model"]["best_s"]), _ms(r["stiffness_assembly"]["best_s"]),
                     _ms(af["saddle"]), _ms(af["K_RR"]), _ms(af["K"])])
    print_table([("nodes", 5), ("ndof", 6), ("nnz K", 7), ("build", 9), ("assemble", 9),
            ("saddle a+f", 10), ("K_RR a+f", 9), ("K a+f", 9)], rows)

    print("\n[2] static solves against the floor = one create+analyse+factorize+solve of "
          "the Newton saddle-point matrix (MUMPS), or spsolve of it")
    print(f"    it: iterations (split: passes); r = residual <= --tol {args.tol:g}, s = "
          "stopped at the round-off step floor, * = only at --fallback-tol "
          f"{args.fallback_tol:g}; res = final relative residual")
    nonlinear = sorted({r["static"]["split"]["extra"].get("nonlinear_coordinates")
                        for r in records if r["static"]["split"]["converged"]} - {None})
    if nonlinear:
        print("    split: jets on " + "/".join(map(str, nonlinear))
              + " nonlinear coordinates (extra['nonlinear_coordinates'])")
    rows = []
    for r in records:
        row = [str(r["nodes"]), _ms(r["floor"]["mumps_analyse_factorize_solve_s"]),
               _ms(r["floor"]["spsolve_s"])]
        for method in ("newton", "split"):
            rec, ratios = r["static"][method], r["ratios"]
            row += [_ms(_static_best(rec), 10), _iterations(rec),
                    f"{rec['residual_norm']:.1e}" if rec["converged"] else "-",
                    f"{ratios[f'{method}_over_mumps_floor']:.2f}",
                    f"{ratios[f'{method}_over_spsolve']:.2f}"]
        rows.append(row)
    print_table([("nodes", 5), ("floor", 9), ("spsolve", 9), ("newton", 10), ("it", 4),
            ("res", 7), ("N/floor", 7), ("N/spsol", 7), ("split", 10), ("it", 4),
            ("res", 7), ("S/floor", 7), ("S/spsol", 7)], rows)

    print("\n[3] where the static time goes: phases of the best repeat (ms); other = "
          "analyse, residuals, set-up, Python; S asm = K assembly + the split's passes (jets, "
          "reduced system, residuals: solve_split books its pass loop as 'assembly'); sys = "
          "share of CPU time in the kernel, mflt = minor page faults (thousands)")
    rows = []
    for r in records:
        row = [str(r["nodes"])]
        for method in ("newton", "split"):
            rec = r["static"][method]
            t = rec["timing"] if rec["converged"] else {"phases": {}}
            ph = t["phases"]
            cpu = t.get("cpu_user_s", math.nan) + t.get("cpu_sys_s", math.nan)
            row += [_ms(ph.get(k, math.nan)) for k in ("assembly", "factorization", "solve",
                                                       "other")]
            row += [f"{100 * t.get('cpu_sys_s', math.nan) / cpu:.0f}%" if cpu > 0 else "-",
                    f"{t.get('minor_faults', 0) / 1e3:.1f}"]
        rows.append(row)
    print_table([("nodes", 5), ("N asm", 8), ("N fact", 8), ("N solve", 8), ("N other", 8),
            ("sys", 4), ("mflt", 6), ("S asm", 9), ("S fact", 8), ("S solve", 9),
            ("S other", 9), ("sys", 4), ("mflt", 6)], rows)

    print("\n[4] growth exponents d log t / d log ndof between consecutive meshes "
          "(1 = linear)")
    keys = [k for k in (exponents[0] if exponents else {}) if k != "nodes"]
    print_table([("nodes", 10)] + [(k, max(8, len(k))) for k in keys],
           [[f"{g['nodes'][0]}->{g['nodes'][1]}"] + [f"{g[k]:.2f}" for k in keys]
            for g in exponents])

    failures = [(r["nodes"], m, f) for r in records for m, rec in r["static"].items()
                for f in rec["failures"]]
    if failures:
        print("\n[5] static solves that did not converge")
        for nodes, method, f in failures:
            print(f"  {nodes:>5} nodes {method:>6} tol {f['tol']:g}: {f['error']} "
                  f"(after {f['time_to_failure_s']:.2f} s)")
    print("\n[6] saddle-point solution check: |x_mumps - x_spsolve| / |x_spsolve| and "
          "residuals |Ax - b| / |b|")
    print_table([("nodes", 5), ("difference", 10), ("MUMPS res", 10), ("spsolve res", 11)],
           [[str(r["nodes"])] + [f"{r['saddle_solution_check'][k]:.2e}" for k in
                                 ("relative_difference", "residual_mumps", "residual_spsolve")]
            for r in records])




def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help=f"only node counts up to {QUICK_MAX_NODES}")
    parser.add_argument("--nodes", type=int, nargs="+", default=None,
                        help=f"node counts, each 3k+1 (default {' '.join(map(str, NODES))})")
    parser.add_argument("--angle", type=float, default=30.0, help="luffing angle (deg)")
    parser.add_argument("--tol", type=float, default=1e-10,
                        help="static tolerance tried first (default 1e-10, the scene's)")
    parser.add_argument("--fallback-tol", type=float, default=1e-8,
                        help="tolerance timed when --tol is not reached (default 1e-8)")
    parser.add_argument("--max-iter", type=int, default=10,
                        help="static iteration limit (default 10: both solvers converge in "
                             "2-3 iterations where they converge at all, and a solve "
                             "stagnating at the round-off floor runs all of them)")
    defaults = Budget()
    parser.add_argument("--min-time", type=float, default=defaults.min_time,
                        help="seconds the repeats of one measurement take at least")
    parser.add_argument("--min-repeats", type=int, default=defaults.min_repeats,
                        help="repeats of one measurement at least ...")
    parser.add_argument("--max-time", type=float, default=defaults.max_time,
                        help="... unless they already took this many seconds")
    parser.add_argument("--max-repeats", type=int, default=defaults.max_repeats,
                        help="repeats of one measurement at most")
    parser.add_argument("--output", type=Path, default=None,
                        help="JSON file (default benchmarks/results/static_scaling.json, "
                             "static_scaling_quick.json with --quick)")
    args = parser.parse_args(argv)
    nodes = args.nodes or [n for n in NODES if not args.quick or n <= QUICK_MAX_NODES]
    if any(n < 4 or (n - 1) % 3 for n in nodes):
        parser.error("every node count must be 3k+1 with k >= 1")
    args.nodes = nodes
    args.budget = Budget(args.min_time, args.min_repeats, args.max_time, args.max_repeats)
    if args.output is None:
        args.output = RESULTS / ("static_scaling_quick.json" if args.quick
                                 else "static_scaling.json")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    start = time.perf_counter()
    machine = machine_info()
    records = []
    for nodes in args.nodes:
        t0 = time.perf_counter()
        records.append(measure(nodes, args))
        print(f"  {nodes:>5} nodes measured in {time.perf_counter() - t0:6.1f} s",
              file=sys.stderr, flush=True)
    machine["load_average_at_end"] = load_average()
    exponents = growth_exponents(records)
    print_tables(records, exponents, args)
    report = {
        "benchmark": "static_scaling", "scene": str(SCENE.relative_to(REPO)),
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "settings": {"nodes": args.nodes, "angle_deg": args.angle, "tol": args.tol,
                     "fallback_tol": args.fallback_tol, "max_iter": args.max_iter,
                     "budget": asdict(args.budget), "quick": args.quick},
        "units": "seconds; ratios are static solve time / floor time",
        "machine": machine, "records": records, "growth_exponents": exponents,
        "wall_time_s": time.perf_counter() - start,
    }
    write_report(args.output, report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
