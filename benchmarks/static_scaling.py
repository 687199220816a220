#!/usr/bin/env python
"""Scaling of the boom statics with the mesh size, and how far the solvers are from the floor.

For every node count (3k+1) of the boom of ``inputs/boom_static.nml`` this measures, wall
clock (``time.perf_counter``), best of N repeats where N is chosen so that the repeats of
one measurement take at least ``--min-time`` seconds together:

* ``build_model`` (element arrays, sparse pattern, constraints, loads);
* one stiffness assembly ``model.stiffness_values()``;
* MUMPS (:class:`ancfdrv.kernel.DirectSolver`) analyse + factorization + one solve of

  - the Newton saddle-point matrix [[K - dQ/de - lambda.H, -Phi_e^T], [-Phi_e, 0]] at the
    rigid configuration, assembled exactly as the first iteration of
    :func:`ancfdrv.static.solve_newton` assembles it;
  - K_RR, the stiffness without the split's dependent coordinates (what
    :func:`ancfdrv.static.solve_split` factorizes once);
  - K itself (singular: the floating-frame stiffness has six rigid-body modes; timed for
    its size only, its solution is meaningless);

* ``scipy.sparse.linalg.spsolve`` (SuperLU) of the same saddle-point system, as a second
  reference, with the difference between both solutions as a sanity check;
* the full static solves ``solve_newton`` and ``solve_split`` (iterations, phases).

"The floor" of a static solve is the cost of a single linear solve from scratch of the
matrix it works with: analyse + one factorization + one solve of the saddle-point matrix
(MUMPS), or ``spsolve`` of it. The ratios static time / floor say how much a full
nonlinear solve costs over one linear solve of the same size.

Each static solve is first tried at ``--tol``; when it does not converge (the relative
residual of the fine meshes stagnates above a floor that grows with the mesh), the failure
is recorded and the solve is timed again at ``--fallback-tol``, so that a converged time
is always reported together with the tolerance it was reached at.

Results: a table on stdout and JSON (machine info, one record per node count, growth
exponents) in ``benchmarks/results/``. Run from the repository root::

    python benchmarks/static_scaling.py            # 4 ... 2002 nodes
    python benchmarks/static_scaling.py --quick    # up to 301 nodes
"""
from __future__ import annotations

import argparse
import datetime as _dt
import gc
import json
import math
import os
import platform
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
import scipy
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import ancfdrv
from ancfdrv.errors import SolverError
from ancfdrv.kernel import DirectSolver
from ancfdrv.model import BeamModel, build_model
from ancfdrv.scene import load_scene
from ancfdrv.static import StaticResult, _hessian_triplets, solve_newton, solve_split

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "inputs" / "boom_static.nml"
RESULTS = REPO / "benchmarks" / "results"
NODES = (4, 10, 16, 22, 28, 100, 301, 1000, 2002)
QUICK_MAX_NODES = 301

StaticSolver = Callable[..., StaticResult]
SOLVERS: dict[str, StaticSolver] = {"newton": solve_newton, "split": solve_split}


# -- timing ----------------------------------------------------------------------------
@dataclass
class Timing:
    """Best-of-N wall time of one measurement.

    ``phases`` are the sub-timings (seconds) the measured call reported in its best
    repeat, e.g. analyse / factorize / solve, or a static solve's ``timing`` dict.
    """

    best_s: float
    median_s: float
    repeats: int
    phases: dict[str, float] = field(default_factory=dict)
    discarded: int = 0


class Discard(Exception):
    """Raised by a measured call whose sample must not count (e.g. a solve that did not
    converge this time although it did before)."""


def best_of(run: Callable[[], object], *, min_time: float, max_repeats: int,
            first: tuple[float, dict[str, float]] | None = None) -> Timing:
    """Call ``run`` until the calls took ``min_time`` seconds together (at least once, at
    most ``max_repeats`` times) and keep the fastest. When ``run`` returns a dict, it is
    taken as the phase timings of that call. ``first`` is an already measured sample
    (wall time, phases) counted as a repeat."""
    samples: list[tuple[float, dict[str, float]]] = [first] if first else []
    spent, calls, discarded = sum(s for s, _ in samples), len(samples), 0
    gc.collect()
    while not samples or (spent < min_time and calls < max_repeats):
        t0 = time.perf_counter()
        try:
            out = run()
        except Discard:
            out = Discard
        elapsed = time.perf_counter() - t0
        spent, calls = spent + elapsed, calls + 1
        if out is Discard:
            discarded += 1
            if discarded > max(3, calls // 2):
                raise RuntimeError("best_of: most repeats were discarded")
            continue
        samples.append((elapsed, dict(out) if isinstance(out, dict) else {}))
    best = min(samples, key=lambda s: s[0])
    return Timing(best_s=best[0], median_s=float(np.median([s for s, _ in samples])),
                  repeats=len(samples), phases=best[1], discarded=discarded)


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


def newton_saddle_system(model: BeamModel) -> LinearSystem:
    """The saddle-point system of the first Newton iteration (d = 0, lambda = 0), with the
    same triplet pattern as :func:`ancfdrv.static.solve_newton`."""
    n, ncon = model.ndof, len(model.constraints)
    e = model.e0
    lam = np.zeros(ncon)
    k_values = model.stiffness_values()
    h_con, h_rows, h_cols, h_vals = _hessian_triplets(model, e)
    phi, j_rows, j_cols, grads = model.constraints.jacobian(e, n)
    moments = model.moment_terms(e)
    rows = np.concatenate([model.pattern.rows, h_rows, *[np.repeat(m.dofs, 3) for m in
                                                         model.moments], n + j_rows, j_cols])
    cols = np.concatenate([model.pattern.col_index, h_cols, *[np.tile(m.dofs, 3) for m in
                                                              model.moments], j_cols, n + j_rows])
    values = np.concatenate([k_values, -lam[h_con] * h_vals,
                             *[-j.ravel() for _, _, j, _ in moments], -grads, -grads])
    external = model.constant_force()
    for dofs, f, _, _ in moments:
        external[dofs] += f
    # residual at d = 0, lambda = 0 is -external; Newton solves A step = [-residual, phi]
    return LinearSystem(n + ncon, rows, cols, values, np.concatenate([external, phi]))


def stiffness_system(model: BeamModel, *, reduced: bool) -> LinearSystem:
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
def time_mumps(system: LinearSystem, what: str, *, min_time: float,
               max_repeats: int) -> tuple[Timing, np.ndarray | None, str | None]:
    """Analyse + factorize + one solve with DirectSolver; phases analyse/factorize/solve.
    Returns the timing, the solution and the solver's error message (then no timing)."""
    solution: list[np.ndarray] = []

    def run() -> dict[str, float]:
        rhs = system.rhs.copy()  # DirectSolver.solve overwrites a contiguous rhs in place
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
        timing = best_of(run, min_time=min_time, max_repeats=max_repeats)
    except SolverError as exc:
        return Timing(math.nan, math.nan, 0), None, str(exc)
    return timing, solution[0], None


def time_spsolve(system: LinearSystem, *, min_time: float,
                 max_repeats: int) -> tuple[Timing, np.ndarray]:
    """scipy's spsolve (SuperLU) of the system; the CSC conversion is not timed."""
    matrix = system.to_csc()
    solution: list[np.ndarray] = []

    def run() -> None:
        solution[:] = [spla.spsolve(matrix, system.rhs)]


    return best_of(run, min_time=min_time, max_repeats=max_repeats), solution[0]


def time_static(model: BeamModel, method: str, tols: list[float], *, max_iter: int,
                min_time: float, max_repeats: int) -> dict[str, Any]:
    """A static solve at the first tolerance of ``tols`` that converges; failed attempts
    are recorded with their message and time to failure."""
    solve = SOLVERS[method]
    failures: list[dict[str, Any]] = []
    for tol in tols:
        t0 = time.perf_counter()
        try:
            result = solve(model, tol=tol, max_iter=max_iter)
        except SolverError as exc:
            failures.append({"tol": tol, "error": str(exc),
                             "time_to_failure_s": time.perf_counter() - t0})
            continue
        first = (time.perf_counter() - t0, dict(result.timing))
        results = [result]

        def run() -> dict[str, float]:
            try:
                results.append(solve(model, tol=tol, max_iter=max_iter))
            except SolverError as exc:  # near the residual floor, convergence may flicker
                failures.append({"tol": tol, "error": f"repeat: {exc}",
                                 "time_to_failure_s": math.nan})
                raise Discard from exc
            return results[-1].timing

        timing = best_of(run, min_time=min_time, max_repeats=max_repeats, first=first)
        phases = timing.phases
        phases["other"] = phases["total"] - sum(phases[k] for k in
                                                ("assembly", "factorization", "solve"))
        return {"method": method, "converged": True, "tol": tol,
                "converged_at_requested_tol": tol == tols[0], "failures": failures,
                "iterations": result.iterations, "residual_norm": result.residual_norm,
                "constraint_norm": result.constraint_norm, "history": result.history,
                "extra": result.extra, "timing": asdict(timing)}
    return {"method": method, "converged": False, "failures": failures}


def measure(nodes: int, args: argparse.Namespace) -> dict[str, Any]:
    """All measurements of one node count."""
    opts = {"min_time": args.min_time, "max_repeats": args.max_repeats}
    scene = load_scene(SCENE, [f"beam.nodes={nodes}", f"boom.angle_deg={args.angle}"])
    build = best_of(lambda: build_model(scene), **opts)
    model = build_model(scene)
    assembly = best_of(model.stiffness_values, **opts)

    saddle = newton_saddle_system(model)
    k_rr = stiffness_system(model, reduced=True)
    k_full = stiffness_system(model, reduced=False)
    mumps: dict[str, Any] = {}
    saddle_x = None
    for name, system in (("saddle", saddle), ("K_RR", k_rr), ("K", k_full)):
        timing, x, error = time_mumps(system, f"benchmark {name}", **opts)
        mumps[name] = {"n": system.n, "nnz_triplets": len(system.values),
                       "timing": asdict(timing), "error": error}
        if name == "saddle":
            saddle_x = x
    scipy_timing, scipy_x = time_spsolve(saddle, **opts)
    check = {"relative_difference": math.nan, "residual_mumps": math.nan,
             "residual_spsolve": relative_residual(saddle, scipy_x)}
    if saddle_x is not None:
        check["relative_difference"] = float(np.linalg.norm(scipy_x - saddle_x)
                                             / np.linalg.norm(scipy_x))
        check["residual_mumps"] = relative_residual(saddle, saddle_x)

    static = {method: time_static(model, method, [args.tol, args.fallback_tol],
                                  max_iter=args.max_iter, **opts) for method in SOLVERS}

    phases = mumps["saddle"]["timing"]["phases"]
    floor_mumps = sum(phases.get(k, math.nan) for k in ("analyse", "factorize", "solve"))
    floor_mumps_no_analyse = phases.get("factorize", math.nan) + phases.get("solve", math.nan)
    floor_scipy = scipy_timing.best_s
    ratios: dict[str, float] = {}
    for method, rec in static.items():
        total = rec["timing"]["best_s"] if rec["converged"] else math.nan
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
def machine_info() -> dict[str, Any]:
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        usable = os.cpu_count()
    threads = {k: os.environ[k] for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                                          "MKL_NUM_THREADS") if k in os.environ}
    return {"platform": platform.platform(), "machine": platform.machine(),
            "processor": platform.processor(), "python": sys.version.split()[0],
            "cpu_count": os.cpu_count(), "cpus_usable": usable, "numpy": np.__version__,
            "scipy": scipy.__version__, "ancfdrv": getattr(ancfdrv, "__version__", None),
            "thread_env": threads}


def _static_best(rec: dict[str, Any], key: str = "best_s") -> float:
    return rec["timing"][key] if rec["converged"] else math.nan


def growth_exponents(records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Local exponents d log(time) / d log(ndof) between consecutive node counts."""
    series: dict[str, Callable[[dict[str, Any]], float]] = {
        "build_model": lambda r: r["build_model"]["best_s"],
        "stiffness_assembly": lambda r: r["stiffness_assembly"]["best_s"],
        "mumps_saddle_floor": lambda r: r["floor"]["mumps_analyse_factorize_solve_s"],
        "mumps_K_RR": lambda r: r["mumps"]["K_RR"]["timing"]["best_s"],
        "spsolve_saddle": lambda r: r["floor"]["spsolve_s"],
        "newton": lambda r: _static_best(r["static"]["newton"]),
        "split": lambda r: _static_best(r["static"]["split"]),
    }
    out = []
    for a, b in zip(records[:-1], records[1:]):
        scale = math.log(b["ndof"] / a["ndof"])
        out.append({"nodes": [a["nodes"], b["nodes"]],
                    **{k: math.log(f(b) / f(a)) / scale for k, f in series.items()}})
    return out


def _ms(seconds: float) -> str:
    return "     -" if not math.isfinite(seconds) else f"{1e3 * seconds:9.3f}"


def _tol_mark(rec: dict[str, Any]) -> str:
    if not rec["converged"]:
        return "FAIL"
    return f"{rec['iterations']}" + ("" if rec["converged_at_requested_tol"] else "*")


def print_tables(records: list[dict[str, Any]], exponents: list[dict[str, Any]],
                 args: argparse.Namespace) -> None:
    """Readable tables of the records (times in ms, best of N)."""
    print(f"\nBoom statics at {args.angle} deg, times in ms (best of N, >= {args.min_time} s "
          "per measurement)")
    print("\n[1] model and MUMPS analyse+factorize (a+f); K is singular (rigid modes)")
    head = (f"{'nodes':>6} {'ndof':>6} {'nnz K':>8} {'build':>9} {'assemble':>9} "
            f"{'saddle a+f':>10} {'K_RR a+f':>9} {'K a+f':>9}")
    print(head)
    print("-" * len(head))
    for r in records:
        af = {name: (m["timing"]["phases"].get("analyse", math.nan)
                     + m["timing"]["phases"].get("factorize", math.nan))
              for name, m in r["mumps"].items()}
        print(f"{r['nodes']:>6} {r['ndof']:>6} {r['nnz_K']:>8} "
              f"{_ms(r['build_model']['best_s'])} {_ms(r['stiffness_assembly']['best_s'])} "
              f"{_ms(af['saddle']):>10} {_ms(af['K_RR'])} {_ms(af['K'])}")

    print("\n[2] static solves vs the floor (one analyse+factorize+solve of the saddle "
          "matrix)")
    print(f"    iterations: * = converged only at --fallback-tol {args.fallback_tol:g} "
          f"(not at --tol {args.tol:g})")
    head = (f"{'nodes':>6} {'floor':>9} {'spsolve':>9} {'newton':>9} {'it':>3} "
            f"{'N/floor':>8} {'N/spsol':>8} {'split':>9} {'it':>3} {'S/floor':>8} "
            f"{'S/spsol':>8} {'S solve%':>8}")
    print(head)
    print("-" * len(head))
    for r in records:
        newton, split, ratios = r["static"]["newton"], r["static"]["split"], r["ratios"]
        split_share = (100 * split["timing"]["phases"]["solve"] / split["timing"]["phases"]
                       ["total"] if split["converged"] else math.nan)
        print(f"{r['nodes']:>6} {_ms(r['floor']['mumps_analyse_factorize_solve_s'])} "
              f"{_ms(r['floor']['spsolve_s'])} {_ms(_static_best(newton))} "
              f"{_tol_mark(newton):>3} {ratios['newton_over_mumps_floor']:8.2f} "
              f"{ratios['newton_over_spsolve']:8.2f} {_ms(_static_best(split))} "
              f"{_tol_mark(split):>3} {ratios['split_over_mumps_floor']:8.2f} "
              f"{ratios['split_over_spsolve']:8.2f} {split_share:8.1f}")

    print("\n[3] where the static time goes (ms, phases of the best repeat; other = "
          "analyse, residuals, jets, Python)")
    head = (f"{'nodes':>6} | {'newton asm':>10} {'fact':>9} {'solve':>9} {'other':>9} | "
            f"{'split asm':>9} {'fact':>9} {'solve':>9} {'other':>9} {'inner':>5}")
    print(head)
    print("-" * len(head))
    for r in records:
        cells = []
        for method in ("newton", "split"):
            rec = r["static"][method]
            ph = rec["timing"]["phases"] if rec["converged"] else {}
            cells.append(" ".join(_ms(ph.get(k, math.nan)) for k in
                                  ("assembly", "factorization", "solve", "other")))
        inner = r["static"]["split"].get("extra", {}).get("inner_iterations", "-")
        print(f"{r['nodes']:>6} | {cells[0]:>41} | {cells[1]:>39} {inner:>5}")

    print("\n[4] growth exponents d log t / d log ndof (1 = linear)")
    keys = list(exponents[0].keys())[1:] if exponents else []
    head = f"{'nodes':>11} " + " ".join(f"{k[:12]:>12}" for k in keys)
    print(head)
    print("-" * len(head))
    for g in exponents:
        span = f"{g['nodes'][0]}->{g['nodes'][1]}"
        print(f"{span:>11} " + " ".join(f"{g[k]:12.2f}" for k in keys))

    failures = [(r["nodes"], m, f) for r in records for m, rec in r["static"].items()
                for f in rec["failures"]]
    if failures:
        print("\nstatic solves that did not converge:")
        for nodes, method, f in failures:
            print(f"  {nodes:>5} nodes {method:>6} tol {f['tol']:g}: {f['error']} "
                  f"({f['time_to_failure_s']:.2f} s)")
    print("\n[5] saddle-point solution check: |x_mumps - x_spsolve| / |x_spsolve| and "
          "residuals |Ax - b| / |b|")
    for r in records:
        c = r["saddle_solution_check"]
        print(f"{r['nodes']:>6} difference {c['relative_difference']:9.2e}   MUMPS "
              f"{c['residual_mumps']:9.2e}   spsolve {c['residual_spsolve']:9.2e}")


def _jsonable(value: Any) -> Any:
    """json.dump default: numpy scalars and arrays; NaN is written as null by the caller."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON serializable: {type(value).__name__}")


def _nan_to_none(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _nan_to_none(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_nan_to_none(v) for v in value]
    if isinstance(value, np.generic):
        return _nan_to_none(value.item())
    return value


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
                             "2-3 iterations where they converge at all; a stagnating split "
                             "solve costs ~1 s per pass at 2002 nodes)")
    parser.add_argument("--min-time", type=float, default=0.2,
                        help="seconds the repeats of one measurement take together")
    parser.add_argument("--max-repeats", type=int, default=10_000)
    parser.add_argument("--output", type=Path, default=None,
                        help="JSON file (default benchmarks/results/static_scaling.json, "
                             "static_scaling_quick.json with --quick)")
    args = parser.parse_args(argv)
    nodes = args.nodes or [n for n in NODES if not args.quick or n <= QUICK_MAX_NODES]
    if any(n < 4 or (n - 1) % 3 for n in nodes):
        parser.error("every node count must be 3k+1 with k >= 1")
    args.nodes = nodes
    if args.output is None:
        args.output = RESULTS / ("static_scaling_quick.json" if args.quick
                                 else "static_scaling.json")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    start = time.perf_counter()
    records = []
    for nodes in args.nodes:
        t0 = time.perf_counter()
        records.append(measure(nodes, args))
        print(f"  {nodes:>5} nodes measured in {time.perf_counter() - t0:6.1f} s",
              file=sys.stderr, flush=True)
    exponents = growth_exponents(records)
    print_tables(records, exponents, args)
    report = {
        "benchmark": "static_scaling", "scene": str(SCENE.relative_to(REPO)),
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "settings": {"angle_deg": args.angle, "tol": args.tol, "fallback_tol": args.fallback_tol,
                     "max_iter": args.max_iter, "min_time_s": args.min_time,
                     "max_repeats": args.max_repeats, "quick": args.quick},
        "machine": machine_info(), "records": records, "growth_exponents": exponents,
        "wall_time_s": time.perf_counter() - start,
    }
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(json.dumps(_nan_to_none(report), indent=1, default=_jsonable,
                                      allow_nan=False) + "\n")
    print(f"\nwrote {args.output} ({report['wall_time_s']:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
