#!/usr/bin/env python
"""Scaling of the luffing-boom dynamics with the mesh size, and how far a Newmark step is
from the floor of one forward/back substitution.

For every node count (3k+1) of the boom of ``inputs/boom_luffing.nml`` this prepares a run
as :func:`ancfdrv.runner.run_scene` does for this scene (``build_model``, static start with
``solve_split``, :class:`ancfdrv.solvers.dynamic.TimeIntegrator`, consistent initial
acceleration, the initial output row), integrates through the smooth start to the
beginning of the luffing stage (:func:`ancfdrv.builders.stage_bounds`, t = 1 s) and measures
there, with ``time.perf_counter``:

* the wall time per Newmark step: ``integrator.advance(state, nsteps)`` from a copy of the
  state at the start of the luffing stage, so every sample integrates the same steps
  (nsteps at most the length of the luffing stage; when those steps take less than
  ``--min-time``, a sample is several such calls, each from a fresh copy), best of
  ``--repeats`` samples of at least ``--min-time`` seconds each; with the Newton
  corrections per step (``chunk.newton``);
* the floor: one forward/back substitution with the step's own factor (LAPACK banded
  Cholesky of S = beta' M + K0 in the solver frame, factorized by the kernel on its first
  step), ``model.solver.solve(rhs)`` (the DirectSolver whose handle the kernel system
  uses) called from Python one right-hand side at a time (includes the f2py call and the
  copy in ``DirectSolver.solve``) and in bulk, ``solve(np.ones((n, k))) / k`` (the
  substitution alone, nearly);
* the overhead of one ``advance`` call (``advance(state, 1)`` minus one step): the model
  lives in the kernel behind a handle, so a call passes only the state and settings and
  unpacks the step outputs into a ``Chunk``;
* once, the time to build the model (which also hands it to the kernel), the static
  solve, the integrator's set-up, the initial acceleration, and the per-step time of the
  start stage (one pass, from the warm-up);

and, for one mesh (``--run-nodes``, 28), the whole 10 s luffing through
:func:`ancfdrv.runner.run_scene` (model, static solve, dynamics, HDF5 output), best of
``--run-repeats``: wall time of the call and ``outcome.dynamic.wall_time_s``.

Ported to the general-system model layer: the kernel factorizes S (and the flexibility
S^-1 E_c, ``setup.integrator_setup_solves`` right-hand sides) inside the first ``advance``
call of a model, not in the integrator's constructor, so ``setup.integrator_setup_s`` is the
first one-step call minus a later one-step call from the window start
(``call.one_step_call_s``; ``setup.first_step_call_s`` and
``setup.integrator_init_s``, the constructor alone, are recorded too). The kernel keeps the
factor and the contraction estimate of the constant policy (Hairer's theta) in the system
between calls, so a replay from a copied state may take a few Newton corrections more or
less than the first pass (``newton_min``/``newton_max``). JSON keys are unchanged, with
``jacobian_policy`` added per record.

The tables give per-step time / floor, per Newton correction / floor, and the growth
exponents d log t / d log ndof between consecutive meshes (1 = linear). Results: a table
on stdout and JSON (machine info, one record per node count, growth exponents) in
``benchmarks/results/``. Run from the repository root::

    python benchmarks/dynamic_scaling.py            # 4 ... 2002 nodes, about 1.5 min
    python benchmarks/dynamic_scaling.py --quick    # up to 100 nodes, 3 short samples,
                                                    # one run_scene: a smoke run, ~30 s
"""
from __future__ import annotations

import argparse
import datetime as _dt
import gc
import math
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from _common import load_average, machine_info, print_table, write_report
from ancfdrv.builders import build_model
from ancfdrv.io.scene import Scene, load_scene
from ancfdrv.builders import stage_bounds
from ancfdrv.runner import dynamic_settings, run_scene
from ancfdrv.solvers.dynamic import (DynamicSettings, TimeIntegrator, initial_acceleration,
                                     initial_row)
from ancfdrv.solvers.static import solve_split
from ancfdrv.system.model import Model

Integrator = TimeIntegrator

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "inputs" / "boom_luffing.nml"
RESULTS = REPO / "benchmarks" / "results"
NODES = (4, 10, 16, 22, 28, 100, 301, 1000, 2002)
QUICK_MAX_NODES = 100
WINDOW_STAGE = "luffing"

State = dict[str, Any]


# -- timing ----------------------------------------------------------------------------
@dataclass
class Timing:
    """Best and median of ``repeats`` samples; ``per`` is how many operations (steps,
    solves, calls) one sample holds, so ``best_s / per`` is the time per operation."""

    best_s: float
    median_s: float
    repeats: int
    per: int

    @property
    def each_s(self) -> float:
        return self.best_s / self.per


def best_of(sample: Callable[[int], float], repeats: int, min_time: float) -> Timing:
    """Time ``sample(count)``, which does ``count`` operations and returns the seconds they
    took (it times itself, so set-up such as copying a state stays out). ``count`` is first
    raised from 1 until one sample takes ``min_time``; then ``repeats`` samples are taken
    and the fastest kept."""
    count = 1
    gc.collect()
    while True:
        elapsed = sample(count)
        if elapsed >= min_time:
            break
        # aim 20 % above min_time; at most 100x per round when elapsed is tiny
        count = max(count + 1, math.ceil(count * min(100.0, 1.2 * min_time
                                                    / max(elapsed, 1e-9))))
    samples = [elapsed] + [sample(count) for _ in range(repeats - 1)]
    return Timing(min(samples), float(np.median(samples)), len(samples), count)


def copy_state(state: State) -> State:
    """Deep copy of an integrator state (t, e, v, a, accel, lam, work, powers, contact
    guesses and counters)."""
    return {k: v.copy() if isinstance(v, np.ndarray) else v for k, v in state.items()}


def advance_checked(integrator: Integrator, state: State, nsteps: int) -> np.ndarray:
    """``integrator.advance`` that raises on a kernel failure; returns Newton counts."""
    chunk, info, detail = integrator.advance(state, nsteps)
    if info:
        raise RuntimeError(integrator.failure_message(info, detail, state["t"]))
    return chunk.newton


# -- one mesh --------------------------------------------------------------------------
@dataclass
class Prepared:
    """A mesh ready to be measured: the integrator and the state at the window start."""

    nodes: int
    scene: Scene
    model: Model
    settings: DynamicSettings
    integrator: Integrator
    start: State
    window: tuple[float, float]
    window_steps: int
    setup: dict[str, Any] = field(default_factory=dict)


def bandwidth(model: Model) -> int:
    """Half bandwidth kd of the iteration matrix (M and K0 share the element pattern)."""
    return model.pattern.bandwidth()


def prepare(nodes: int) -> Prepared:
    """Build, solve the statics, set up the integrator and integrate to the window start,
    timing each phase once."""
    setup: dict[str, Any] = {}
    scene = load_scene(SCENE, [f"beam.nodes={nodes}"])
    stages = stage_bounds(scene)
    if stages is None:
        raise RuntimeError(f"{SCENE} does not luff: no {WINDOW_STAGE} stage to measure")
    t_first, t_last = (float(x) for x in stages[WINDOW_STAGE])
    t0 = time.perf_counter()
    model = build_model(scene)
    setup["build_model_s"] = time.perf_counter() - t0

    solver = scene["solver"]
    static = solve_split(model, tol=solver["tol"], max_iter=solver["max_iter"],
                         p=solver["split_p"])
    setup["static"] = {"wall_s": static.wall_time_s, "iterations": static.iterations,
                       "residual_norm": static.residual_norm,
                       "converged_by": static.extra.get("converged_by"),
                       "nonlinear_coordinates": static.extra.get("nonlinear_coordinates")}

    settings = dynamic_settings(scene)
    t0 = time.perf_counter()
    integrator = Integrator(model, settings)
    setup["integrator_init_s"] = time.perf_counter() - t0
    # the constant policy's set-up solves: S^-1 E_c, 3 per constrained 3-vector
    setup["integrator_setup_solves"] = (3 * len(model.touched_blocks())
                                        if model.constant_policy else 0)
    setup["jacobian_policy"] = "constant" if model.constant_policy else settings.jacobian
    t0 = time.perf_counter()
    v0 = np.zeros(model.ndof)
    a0, lam0 = initial_acceleration(model, static.e, v0, 0.0)
    setup["initial_acceleration_s"] = time.perf_counter() - t0
    # as integrate() builds it, with the powers of the initial output row
    state: State = integrator.state(0.0, static.e, v0, a0, lam0)
    initial_row(model, state)

    # warm-up through the start stage, in the run's chunks: one pass, also a measurement;
    # the first call of one step holds the kernel's factorization of S
    warm_steps = int(round((t_first - state["t"]) / settings.dt))
    t0 = time.perf_counter()
    newton: list[np.ndarray] = [advance_checked(integrator, state, 1)]
    first_call = time.perf_counter() - t0
    t0 = time.perf_counter()
    done = 1
    while done < warm_steps:
        n = min(settings.chunk_steps, warm_steps - done)
        newton.append(advance_checked(integrator, state, n))
        done += n
    elapsed = time.perf_counter() - t0
    counts = np.concatenate(newton) if newton else np.zeros(0)
    step_s = elapsed / (warm_steps - 1) if warm_steps > 1 else math.nan
    setup["first_step_call_s"] = first_call  # integrator_setup_s: in measure()
    setup["start_stage"] = {"t": [0.0, state["t"]], "steps": warm_steps,
                            "step_s": step_s,
                            "newton_mean": float(counts.mean()) if counts.size else math.nan}
    window_steps = int(math.floor((t_last - state["t"]) / settings.dt + 1e-9))
    return Prepared(nodes, scene, model, settings, integrator, copy_state(state),
                    (state["t"], t_last), window_steps, setup)


def time_steps(prep: Prepared, args: argparse.Namespace) -> dict[str, Any]:
    """Wall time per step in the window: samples of ``calls`` x ``advance(copy, nsteps)``
    from the window start, nsteps chosen so one call takes ``--min-time`` where the
    window is long enough, else the whole window and several calls per sample."""
    integrator = prep.integrator
    probe_steps = min(prep.window_steps, args.probe_steps)
    state = copy_state(prep.start)
    t0 = time.perf_counter()
    advance_checked(integrator, state, probe_steps)
    estimate = (time.perf_counter() - t0) / probe_steps
    nsteps = max(1, min(prep.window_steps, math.ceil(1.2 * args.min_time / estimate)))
    newton: list[np.ndarray] = []

    def sample(calls: int) -> float:
        spent = 0.0
        newton.clear()
        for _ in range(calls):
            run_state = copy_state(prep.start)
            t0 = time.perf_counter()
            newton.append(advance_checked(integrator, run_state, nsteps))
            spent += time.perf_counter() - t0
        return spent

    timing = best_of(sample, args.repeats, args.min_time)
    counts = np.concatenate(newton)
    step = timing.best_s / (timing.per * nsteps)
    t_end = prep.start["t"] + nsteps * prep.settings.dt
    return {"nsteps": nsteps, "calls": timing.per, "t": [prep.start["t"], t_end],
            "step_s": step, "step_median_s": timing.median_s / (timing.per * nsteps),
            "repeats": timing.repeats, "newton_mean": float(counts.mean()),
            "newton_min": int(counts.min()), "newton_max": int(counts.max()),
            "probe_step_s": estimate}


def time_call_overhead(prep: Prepared, step_s: float,
                       args: argparse.Namespace) -> dict[str, Any]:
    """Wall time of ``advance(copy, 1)`` and its excess over one step of the window."""
    integrator = prep.integrator

    def sample(calls: int) -> float:
        spent = 0.0
        for _ in range(calls):
            run_state = copy_state(prep.start)
            t0 = time.perf_counter()
            advance_checked(integrator, run_state, 1)
            spent += time.perf_counter() - t0
        return spent

    timing = best_of(sample, args.repeats, args.min_time)
    return {"one_step_call_s": timing.each_s, "overhead_s": timing.each_s - step_s,
            "calls": timing.per}


def time_floor(prep: Prepared, args: argparse.Namespace) -> dict[str, Any]:
    """One forward/back substitution with the step's factor: single right-hand sides from
    Python, and ``--bulk-rhs`` of them per call."""
    solver, n, k = prep.model.solver, prep.model.ndof, args.bulk_rhs
    single_rhs, bulk_rhs = np.ones(n), np.ones((n, k))

    def sample_single(calls: int) -> float:
        t0 = time.perf_counter()
        for _ in range(calls):
            solver.solve(single_rhs)
        return time.perf_counter() - t0

    def sample_bulk(calls: int) -> float:
        t0 = time.perf_counter()
        for _ in range(calls):
            solver.solve(bulk_rhs)
        return time.perf_counter() - t0

    single = best_of(sample_single, args.repeats, args.min_time)
    bulk = best_of(sample_bulk, args.repeats, args.min_time)
    kd = bandwidth(prep.model)
    bulk_s = bulk.each_s / k
    return {"bandwidth_kd": kd, "single_s": single.each_s, "single_calls": single.per,
            "bulk_s": bulk_s, "bulk_rhs": k, "bulk_calls": bulk.per,
            "python_overhead_s": single.each_s - bulk_s,
            # dpbtrs: two triangular band solves, about 4 n kd flops per right-hand side
            "bulk_gflops": 4.0 * n * kd / bulk_s / 1e9}


def measure(nodes: int, args: argparse.Namespace) -> dict[str, Any]:
    """All measurements of one node count."""
    prep = prepare(nodes)
    try:
        steps = time_steps(prep, args)
        overhead = time_call_overhead(prep, steps["step_s"], args)
        floor = time_floor(prep, args)
    finally:
        prep.model.close()
    # the first call's excess over a one-step call: the kernel's factorization of S and
    # the flexibility solves
    prep.setup["integrator_setup_s"] = (prep.setup["first_step_call_s"]
                                        - overhead["one_step_call_s"])
    step, newton = steps["step_s"], steps["newton_mean"]
    ratios = {"step_over_floor_bulk": step / floor["bulk_s"],
              "step_over_floor_single": step / floor["single_s"],
              "correction_over_floor_bulk": step / (newton * floor["bulk_s"]),
              "solve_share": newton * floor["bulk_s"] / step}
    return {"nodes": nodes, "ndof": prep.model.ndof,
            "elements": sum(s.nel for s in prep.model.sets),
            "jacobian_policy": prep.setup["jacobian_policy"],
            "dt": prep.settings.dt,
            "nconstraints": len(prep.model.constraints), "window": list(prep.window),
            "window_steps": prep.window_steps, "setup": prep.setup, "steps": steps,
            "call": overhead, "floor": floor, "ratios": ratios}


def time_run_scene(nodes: int, args: argparse.Namespace) -> dict[str, Any]:
    """The whole scene through ``run_scene`` (best of ``--run-repeats``), HDF5 output to a
    temporary directory."""
    runs = []
    with tempfile.TemporaryDirectory(prefix="dynamic_scaling_") as tmp:
        for i in range(args.run_repeats):
            out = Path(tmp) / f"run{i}.h5"
            t0 = time.perf_counter()
            outcome = run_scene(SCENE, [f"beam.nodes={nodes}"], out, progress=False)
            wall = time.perf_counter() - t0
            dyn = outcome.dynamic
            if dyn is None:
                raise RuntimeError(f"{SCENE} ran no dynamics")
            runs.append({"wall_s": wall, "dynamic_wall_s": dyn.wall_time_s,
                         "dynamic_timing": dict(dyn.timing), "steps": dyn.steps,
                         "newton_iterations": dyn.newton_iterations,
                         "static_wall_s": outcome.static.wall_time_s if outcome.static
                         else math.nan, "output_bytes": out.stat().st_size})
    best = min(runs, key=lambda r: r["wall_s"])
    return {"nodes": nodes, "repeats": len(runs), "best": best,
            "python_import_s": time_import(args.run_repeats),
            "wall_s_all": [r["wall_s"] for r in runs],
            "step_s": best["dynamic_timing"].get("stepping", math.nan) / best["steps"],
            "newton_mean": best["newton_iterations"] / best["steps"]}


def time_import(repeats: int) -> float:
    """Best wall time of a fresh interpreter that imports ``ancfdrv.runner`` (numpy,
    scipy, h5py, the kernel): the start-up a command-line run pays before any work."""
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", "import ancfdrv.runner"], check=True)
        best = min(best, time.perf_counter() - t0)
    return best


# -- reporting ----------------------------------------------------------------------------




SERIES: dict[str, Callable[[dict[str, Any]], float]] = {
    "step": lambda r: r["steps"]["step_s"],
    "floor_bulk": lambda r: r["floor"]["bulk_s"],
    "floor_single": lambda r: r["floor"]["single_s"],
    "call_overhead": lambda r: r["call"]["overhead_s"],
    "integrator_setup": lambda r: r["setup"]["integrator_setup_s"],
    "static": lambda r: r["setup"]["static"]["wall_s"],
}


def growth_exponents(records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Local exponents d log(time) / d log(ndof) between consecutive node counts (NaN
    where a time is not positive)."""
    out = []
    for a, b in zip(records[:-1], records[1:]):
        scale = math.log(b["ndof"] / a["ndof"])
        row: dict[str, Any] = {"nodes": [a["nodes"], b["nodes"]]}
        for key, f in SERIES.items():
            ta, tb = f(a), f(b)
            row[key] = math.log(tb / ta) / scale if ta > 0 and tb > 0 else math.nan
        out.append(row)
    return out


def _us(seconds: float, width: int = 9) -> str:
    return f"{'-':>{width}}" if not math.isfinite(seconds) else f"{1e6 * seconds:{width}.1f}"


def _ms(seconds: float, width: int = 8) -> str:
    return f"{'-':>{width}}" if not math.isfinite(seconds) else f"{1e3 * seconds:{width}.2f}"




def print_tables(records: list[dict[str, Any]], exponents: list[dict[str, Any]],
                 run: dict[str, Any] | None, args: argparse.Namespace) -> None:
    """Readable tables of the records."""
    if records:
        w = records[0]["window"]
        print(f"\nLuffing boom, Newmark dt = {records[0]['dt']:g} s; "
              f"steps from t = {w[0]:g} s (start of the {WINDOW_STAGE} stage, which ends at "
              f"{w[1]:.3f} s); best of {args.repeats} samples >= {args.min_time:g} s each")

        print("\n[1] per step against the floor = one forward/back substitution with the "
              "banded Cholesky factor of S (us)")
        print(f"    steps x calls: steps per advance call x calls per sample; newton: "
              f"corrections per step; single: solve(rhs) from Python; bulk: "
              f"solve(ones((n, {args.bulk_rhs}))) / {args.bulk_rhs}; "
              "/corr = step / (newton x bulk)")
        rows = []
        for r in records:
            s, f, q = r["steps"], r["floor"], r["ratios"]
            rows.append([str(r["nodes"]), str(r["ndof"]), str(f["bandwidth_kd"]),
                         f"{s['nsteps']}x{s['calls']}", _us(s["step_s"]),
                         f"{s['newton_mean']:.2f}", _us(f["single_s"], 8),
                         _us(f["bulk_s"], 8), f"{q['step_over_floor_single']:.1f}",
                         f"{q['step_over_floor_bulk']:.1f}",
                         f"{q['correction_over_floor_bulk']:.1f}",
                         f"{100 * q['solve_share']:.0f}%", f"{f['bulk_gflops']:.2f}"])
        print_table([("nodes", 5), ("ndof", 6), ("kd", 3), ("steps x calls", 13),
                ("step", 9), ("newton", 6), ("single", 8), ("bulk", 8), ("/single", 8),
                ("/bulk", 6), ("/corr", 6), ("solve", 5), ("GF/s", 5)], rows)

        print("\n[2] once per mesh (ms): model, static split solve (passes, how it stopped), "
              "integrator set-up, initial acceleration; start stage per step (us, one pass "
              "in chunks); advance(1 step) call and its overhead over a step (us)")
        rows = []
        for r in records:
            st, su, c = r["setup"]["static"], r["setup"], r["call"]
            rows.append([str(r["nodes"]), _ms(su["build_model_s"]), _ms(st["wall_s"]),
                         f"{st['iterations']}{(st['converged_by'] or '?')[0]}",
                         _ms(su["integrator_setup_s"]), _ms(su["initial_acceleration_s"]),
                         _us(su["start_stage"]["step_s"]),
                         f"{su['start_stage']['newton_mean']:.2f}",
                         _us(c["one_step_call_s"]), _us(c["overhead_s"])])
        print_table([("nodes", 5), ("build", 8), ("static", 8), ("it", 3), ("setup", 8),
                ("a0", 8), ("start/step", 10), ("newton", 6), ("1-step call", 11),
                ("overhead", 9)], rows)

        print("\n[3] growth exponents d log t / d log ndof between consecutive meshes "
              "(1 = linear)")
        keys = list(SERIES)
        print_table([("nodes", 10)] + [(k, max(8, len(k))) for k in keys],
               [[f"{g['nodes'][0]}->{g['nodes'][1]}"]
                + [f"{g[k]:.2f}" if math.isfinite(g[k]) else "-" for k in keys]
                for g in exponents])

    if run:
        b = run["best"]
        timing = b["dynamic_timing"]
        print(f"\n[4] run_scene({SCENE.relative_to(REPO)}, beam.nodes={run['nodes']}), "
              f"best of {run['repeats']}: wall {b['wall_s']:.3f} s (all: "
              + ", ".join(f"{x:.3f}" for x in run["wall_s_all"]) + ")")
        print(f"    dynamic.wall_time_s {b['dynamic_wall_s']:.3f} s = setup "
              f"{timing.get('setup', math.nan):.3f} + stepping "
              f"{timing.get('stepping', math.nan):.3f} + output "
              f"{timing.get('output', math.nan):.3f} s; {b['steps']} steps, "
              f"{run['newton_mean']:.2f} corrections/step, {1e6 * run['step_s']:.1f} us/step "
              f"stepping; static {b['static_wall_s']:.3f} s; rest (model, files) "
              f"{b['wall_s'] - b['dynamic_wall_s'] - b['static_wall_s']:.3f} s; "
              f"HDF5 {b['output_bytes'] / 1e6:.1f} MB")
        print(f"    a command-line run also pays the interpreter start-up and imports: "
              f"{run['python_import_s']:.3f} s (python -c 'import ancfdrv.runner', best of "
              f"{run['repeats']})")




def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help=f"only node counts up to {QUICK_MAX_NODES}, 3 repeats of "
                             "0.1 s samples, one run_scene")
    parser.add_argument("--nodes", type=int, nargs="*", default=None,
                        help=f"node counts, each 3k+1 (default {' '.join(map(str, NODES))}); "
                             "none: only the run_scene measurement")
    parser.add_argument("--min-time", type=float, default=None,
                        help="seconds one sample takes at least (default 0.3; 0.1 with "
                             "--quick)")
    parser.add_argument("--repeats", type=int, default=None,
                        help="samples per measurement, the fastest is kept (default 5, 3 "
                             "with --quick: the speed of a shared machine drifts over "
                             "seconds)")
    parser.add_argument("--probe-steps", type=int, default=20,
                        help="steps of the probe that sizes a sample (default 20)")
    parser.add_argument("--bulk-rhs", type=int, default=32,
                        help="right-hand sides per bulk floor solve (default 32)")
    parser.add_argument("--run-nodes", type=int, default=28,
                        help="node count of the whole run_scene measurement (default 28; "
                             "0 skips it)")
    parser.add_argument("--run-repeats", type=int, default=None,
                        help="run_scene repeats, the fastest is kept (default 3; 1 with "
                             "--quick)")
    parser.add_argument("--output", type=Path, default=None,
                        help="JSON file (default benchmarks/results/dynamic_scaling.json, "
                             "dynamic_scaling_quick.json with --quick)")
    args = parser.parse_args(argv)
    if args.repeats is None:
        args.repeats = 3 if args.quick else 5
    if args.min_time is None:
        args.min_time = 0.1 if args.quick else 0.3
    if args.run_repeats is None:
        args.run_repeats = 1 if args.quick else 3
    nodes = args.nodes if args.nodes is not None else [
        n for n in NODES if not args.quick or n <= QUICK_MAX_NODES]
    if any(n < 4 or (n - 1) % 3 for n in nodes + ([args.run_nodes] if args.run_nodes else [])):
        parser.error("every node count must be 3k+1 with k >= 1")
    if args.repeats < 1 or args.run_repeats < 1 or args.bulk_rhs < 1 or args.probe_steps < 1:
        parser.error("--repeats, --run-repeats, --bulk-rhs and --probe-steps must be >= 1")
    args.nodes = nodes
    if args.output is None:
        args.output = RESULTS / ("dynamic_scaling_quick.json" if args.quick
                                 else "dynamic_scaling.json")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    start = time.perf_counter()
    machine = machine_info()
    if args.nodes:  # first calls (lazy imports, MUMPS/MPI start-up) stay out of the records
        prepare(min(NODES)).model.close()
    records = []
    for nodes in args.nodes:
        t0 = time.perf_counter()
        records.append(measure(nodes, args))
        print(f"  {nodes:>5} nodes measured in {time.perf_counter() - t0:6.1f} s",
              file=sys.stderr, flush=True)
    run = None
    if args.run_nodes:
        t0 = time.perf_counter()
        run = time_run_scene(args.run_nodes, args)
        print(f"  run_scene at {args.run_nodes} nodes x {args.run_repeats} in "
              f"{time.perf_counter() - t0:6.1f} s", file=sys.stderr, flush=True)
    machine["load_average_at_end"] = load_average()
    exponents = growth_exponents(records)
    print_tables(records, exponents, run, args)
    report = {
        "benchmark": "dynamic_scaling", "scene": str(SCENE.relative_to(REPO)),
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "settings": {"nodes": args.nodes, "window_stage": WINDOW_STAGE,
                     "min_time": args.min_time, "repeats": args.repeats,
                     "probe_steps": args.probe_steps, "bulk_rhs": args.bulk_rhs,
                     "run_nodes": args.run_nodes, "run_repeats": args.run_repeats,
                     "quick": args.quick},
        "units": "seconds; ratios are per-step time / floor time",
        "machine": machine, "records": records, "growth_exponents": exponents,
        "run_scene": run, "wall_time_s": time.perf_counter() - start,
    }
    write_report(args.output, report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
