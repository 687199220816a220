#!/usr/bin/env python
"""CPU time of the two-leaf spring's 5 s run (``inputs/leaf_spring.nml``: penalty contact,
smooth Coulomb friction, prestress; issue 38 item 6), this build against a baseline build,
and what the scene's own settings (``solver.dt``, ``solver.newton_tol``) buy in time
against the accuracy they cost.

Part 1, old against new. Each run is a fresh process (``--worker``) of one build's Python
(``--baseline``: e.g. ``/work/main/.venv/bin/python``, whose editable install is the
baseline's ancfdrv; ``--current``: this checkout's, by default the running interpreter):
``load_scene``, ``build_model``, the settled start as ``ancf run`` computes it
(``solve_newton`` with the loads scaled by 0 for spring.settle = 'prestress', the scene's
'unloaded' settle), then ``integrate`` over the scene's 0..5 s with no output file. Times:
the CPU time of ``integrate`` (``time.process_time``: set-up, initial acceleration,
stepping; the process is single-threaded) and of the whole process (``os.wait4``
rusage, start-up and imports included). The two builds alternate, baseline first, for
``--rounds`` rounds (A B A B ...), so slow phases of the shared machine hit both; the best
and the median of each side are reported, with the load average at the start and the end.
Checks: both builds' steps, Newton iterations and factorizations, and the chassis's
displacement history compared value for value (``history_max_abs_diff``, 0 when the
builds compute the same numbers; ``history_max_diff_over_range``: the largest difference of
x and of z over the baseline's range of each, round-off when the arithmetic order
changed). The integrate's wall time (best) is reported beside its CPU time, and each
build's iteration-matrix solver. ``--answers``: the rows carry the kernel's part of the
engineering answers (row_answers.f90), as ``ancf run`` computes them; ``integrate`` alone
(the library call) does not.

Part 2 (``--accuracy``), accuracy against time: the current build at (dt, newton_tol) in
``--grid`` (default: 5e-4/1e-8, the shipped 1e-3/1e-8, 2e-3/1e-8, 4e-3/1e-8, 1e-3/1e-6,
2e-3/1e-6) against a converged reference, dt = 1.25e-4 and newton_tol = 1e-10 (a
second-order method: its time discretization error is 1/64 of the shipped step's; the
reference at 2.5e-4 differs from it by 5e-5 of the range). Error: max |z(t) - z_ref(t)| of
the chassis's vertical displacement at t = k 4 ms (every step size's output times), over
the reference's range of z (58.6 mm: the drop and its bounces); the horizontal
displacement's likewise. Writes a chart (error against CPU time of ``integrate``) beside
the JSON.

    .venv/bin/python benchmarks/leaf_spring_time.py --baseline /work/main/.venv/bin/python \\
        -o benchmarks/results/leaf_spring_time [--rounds 3] [--accuracy]
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from _common import json_ready, load_average, machine_info, print_table

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "inputs" / "leaf_spring.nml"
#: (dt, newton_tol) of the accuracy grid; the shipped scene's first among equals
GRID = [(1e-3, 1e-8), (5e-4, 1e-8), (2e-3, 1e-8), (4e-3, 1e-8), (1e-3, 1e-6), (2e-3, 1e-6)]
REFERENCE = (1.25e-4, 1e-10)
SAMPLE = 4e-3   # s: the comparison times, a multiple of every step of the grid


# -- one run (a worker process) -------------------------------------------------------------
def one_run(history: Path, t_end: float,
            setting: tuple[float, float] | None = None, answers: bool = False) -> dict[str, Any]:
    """One run in this process at the scene's (dt, newton_tol) or ``setting``: its record;
    writes the chassis history (t, x, z) to ``history`` (.npz). ``answers``: the rows carry
    the kernel's part of the answers, as in ``ancf run`` (DynamicSettings.answers)."""
    from ancfdrv.builders import build_model, settle_mode
    from ancfdrv.io.scene import load_scene
    from ancfdrv.runner import dynamic_settings
    from ancfdrv.solvers.dynamic import integrate
    from ancfdrv.solvers.static import solve_newton

    overrides = [f"solver.t_end={t_end!r}"]
    if setting is not None:
        overrides += [f"solver.dt={setting[0]!r}", f"solver.newton_tol={setting[1]!r}"]
    scene = load_scene(SCENE, overrides)
    model = build_model(scene)
    solver = scene["solver"]
    settle = settle_mode(scene)
    start = solve_newton(model, tol=solver["tol"], max_iter=solver["max_iter"],
                         load_steps=solver["load_steps"],
                         loads=0.0 if settle == "unloaded" else 1.0).e
    settings = dynamic_settings(scene)
    settings.answers = answers
    chunks: list[Any] = []
    cpu0 = time.process_time()
    result = integrate(model, settings, start, sink=chunks.append, progress=False)
    cpu = time.process_time() - cpu0
    t = np.concatenate([c.time for c in chunks])
    chassis = np.concatenate([c.deflections for c in chunks])[:, list(model.probes).index(
        "chassis")]
    np.savez(history, t=t, x=chassis[:, 0], z=chassis[:, 2])
    model.close()
    return {"dt": settings.dt, "newton_tol": solver["newton_tol"], "t_end": settings.t_end,
            "settle": settle, "answers": answers, "integrate_cpu_s": cpu, "integrate_wall_s": result.wall_time_s,
            "steps": result.steps, "newton_iterations": result.newton_iterations,
            "factorizations": result.factorizations,
            "solver": model.solver.what, "fallbacks": getattr(model.solver, "fallbacks", 0),
            "chassis_z_end_m": float(chassis[-1, 2]),
            "chassis_z_min_m": float(chassis[:, 2].min())}


def worker(args: argparse.Namespace) -> None:
    """One run (a worker process); prints its JSON record."""
    setting = None if args.dt is None else (args.dt, args.tol)
    print(json.dumps(one_run(args.history, args.t_end, setting, args.answers)))


def run_worker(python: str, history: Path, t_end: float,
               setting: tuple[float, float] | None = None, answers: bool = False) -> dict[str, Any]:
    """A worker in a fresh process of ``python``; its record plus the process's CPU time."""
    command = [python, str(Path(__file__).resolve()), "--worker", "--history", str(history),
               "--t-end", repr(t_end)]
    if setting is not None:
        command += ["--dt", repr(setting[0]), "--tol", repr(setting[1])]
    if answers:
        command.append("--answers")
    proc = subprocess.Popen(command, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    _, status, usage = os.wait4(proc.pid, 0)
    out, err = proc.stdout.read(), proc.stderr.read()
    proc.stdout.close()
    proc.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{python}: worker failed:\n{err[-3000:]}")
    record = json.loads(out.strip().splitlines()[-1])
    record["process_cpu_s"] = usage.ru_utime + usage.ru_stime
    return record


# -- part 1 ------------------------------------------------------------------------------------
def over_range(difference: float, spread: float) -> float:
    """difference / spread (0 when both are 0, inf for a difference over no spread)."""
    if difference == 0.0:
        return 0.0
    return float(difference / spread) if spread > 0.0 else float("inf")


def compare_builds(args: argparse.Namespace, work: Path) -> dict[str, Any]:
    sides = {"baseline": args.baseline, "current": args.current}
    runs: dict[str, list[dict[str, Any]]] = {side: [] for side in sides}
    load_start = load_average()
    for r in range(args.rounds):
        for side, python in sides.items():
            record = run_worker(python, work / f"{side}_{r}.npz", args.t_end,
                                answers=args.answers)
            runs[side].append(record)
            print(f"round {r + 1}/{args.rounds} {side:8s}: integrate {record['integrate_cpu_s']:.3f} s "
                  f"CPU, process {record['process_cpu_s']:.3f} s", flush=True)
    load_end = load_average()
    a, b = (np.load(work / f"{side}_0.npz") for side in sides)
    same_shape = a["z"].shape == b["z"].shape
    diff = (float(max(np.abs(a["z"] - b["z"]).max(), np.abs(a["x"] - b["x"]).max()))
            if same_shape else None)
    # the largest difference of each coordinate over the baseline's range of it
    relative = ({key: over_range(np.abs(a[key] - b[key]).max(), np.ptp(a[key]))
                 for key in ("x", "z")} if same_shape else None)
    summary = {}
    for side in sides:
        cpu = [r["integrate_cpu_s"] for r in runs[side]]
        proc = [r["process_cpu_s"] for r in runs[side]]
        first = runs[side][0]
        wall = [r["integrate_wall_s"] for r in runs[side]]
        summary[side] = {"python": sides[side], "integrate_cpu_best_s": min(cpu),
                         "integrate_wall_best_s": min(wall), "solver": runs[side][0]["solver"],
                         "integrate_cpu_median_s": statistics.median(cpu),
                         "process_cpu_best_s": min(proc),
                         "process_cpu_median_s": statistics.median(proc),
                         **{k: first[k] for k in ("steps", "newton_iterations",
                                                  "factorizations", "t_end", "dt",
                                                  "newton_tol")}}
    ratio = summary["current"]["integrate_cpu_best_s"] / summary["baseline"]["integrate_cpu_best_s"]
    return {"runs": runs, "summary": summary, "current_over_baseline_best": ratio,
            "history_same_length": same_shape, "history_max_abs_diff_m": diff,
            "history_max_diff_over_range": relative,
            "counters_equal": all(summary["baseline"][k] == summary["current"][k]
                                  for k in ("steps", "newton_iterations", "factorizations")),
            "load_average_start": load_start, "load_average_end": load_end}


# -- part 2 ------------------------------------------------------------------------------------
def sampled(h: Any) -> dict[float, tuple[float, float]]:
    """The history at t = k SAMPLE (k integer), keyed by k."""
    k = np.round(h["t"] / SAMPLE)
    keep = np.abs(h["t"] - k * SAMPLE) < 1e-9
    return {int(kk): (x, z) for kk, x, z in zip(k[keep], h["x"][keep], h["z"][keep])}


def accuracy(args: argparse.Namespace, work: Path) -> dict[str, Any]:
    reference = run_worker(args.current, work / "reference.npz", args.t_end, REFERENCE)
    ref = sampled(np.load(work / "reference.npz"))
    zr = np.array([v[1] for v in ref.values()])
    xr = np.array([v[0] for v in ref.values()])
    z_range, x_range = float(zr.max() - zr.min()), float(xr.max() - xr.min())
    rows = []
    for setting in args.grid:
        path = work / f"grid_{setting[0]:g}_{setting[1]:g}.npz"
        record = run_worker(args.current, path, args.t_end, setting)
        mine = sampled(np.load(path))
        common = sorted(set(mine) & set(ref))
        dz = max(abs(mine[k][1] - ref[k][1]) for k in common)
        dx = max(abs(mine[k][0] - ref[k][0]) for k in common)
        record.update(z_error=dz / z_range, x_error=dx / x_range, compared_times=len(common),
                      shipped=setting == GRID[0])
        rows.append(record)
        print(f"dt {setting[0]:g}, newton_tol {setting[1]:g}: integrate "
              f"{record['integrate_cpu_s']:.2f} s CPU, z error {record['z_error']:.2e} of the "
              f"range", flush=True)
    return {"reference": reference, "z_range_m": z_range, "x_range_m": x_range, "rows": rows}


def chart(part: dict[str, Any], path: Path) -> Path:
    from ancfdrv.plots import pareto_chart
    return pareto_chart(part["rows"], lambda r: f"newton_tol = {r['newton_tol']:g}",
                        lambda r: f"dt {r['dt'] * 1e3:g} ms" + (" (scene)" if r["shipped"] else ""),
                        "z_error", path, time_key="integrate_cpu_s",
                        title="two-leaf spring, 5 s: chassis error against CPU time",
                        common_reference=True)


# -- report ------------------------------------------------------------------------------------
def markdown(report: dict[str, Any]) -> str:
    lines = ["# Two-leaf spring, 5 s run: CPU time (benchmarks/leaf_spring_time.py)", "",
             f"Created {report['created']}; load average at the start "
             f"{report['machine'].get('load_average_at_start')} (2 cores shared)."]
    part = report["builds"]
    if part:
        s = part["summary"]
        lines += ["", f"Load average {part['load_average_start']} at the start of part 1, "
                  f"{part['load_average_end']} at its end. {report['settings']['rounds']} "
                  "rounds, baseline and current alternating, each run a fresh process; "
                  + ("the rows carry the answers (as ancf run)." if report["settings"].get("answers")
                     else "no answers in the rows (integrate alone)."), "",
                  "| build | integrate CPU best [s] | median [s] | integrate wall best [s] | "
                  "process CPU best [s] | steps | Newton iterations | factorizations | "
                  "iteration matrix |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for side in ("baseline", "current"):
            r = s[side]
            lines.append(f"| {side} (`{r['python']}`) | {r['integrate_cpu_best_s']:.3f} | "
                         f"{r['integrate_cpu_median_s']:.3f} | {r['integrate_wall_best_s']:.3f} | "
                         f"{r['process_cpu_best_s']:.3f} | {r['steps']} | "
                         f"{r['newton_iterations']} | {r['factorizations']} | {r['solver']} |")
        lines += ["", f"Current / baseline (best integrate CPU): "
                  f"{part['current_over_baseline_best']:.3f}; counters equal: "
                  f"{part['counters_equal']}; chassis history max |difference| "
                  f"{part['history_max_abs_diff_m']} m (over the baseline's range: "
                  f"{part['history_max_diff_over_range']})."]
    acc = report.get("accuracy")
    if acc:
        lines += ["", f"## Accuracy against CPU time (reference dt = {REFERENCE[0]:g} s, "
                  f"newton_tol = {REFERENCE[1]:g}: integrate {acc['reference']['integrate_cpu_s']:.2f} s "
                  f"CPU; z range {acc['z_range_m'] * 1e3:.2f} mm)", "",
                  "| dt [s] | newton_tol | integrate CPU [s] | Newton per step | "
                  "factorizations | max z error / range | max x error / range |",
                  "|---|---|---|---|---|---|---|"]
        for r in acc["rows"]:
            lines.append(f"| {r['dt']:g}{' (scene)' if r['shipped'] else ''} | "
                         f"{r['newton_tol']:g} | {r['integrate_cpu_s']:.2f} | "
                         f"{r['newton_iterations'] / r['steps']:.2f} | {r['factorizations']} | "
                         f"{r['z_error']:.2e} | {r['x_error']:.2e} |")
    return "\n".join(lines) + "\n"


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    p.add_argument("--baseline", help="the baseline build's Python (part 1)")
    p.add_argument("--current", default=sys.executable,
                   help="this build's Python (default: the running one)")
    p.add_argument("--rounds", type=int, default=3, help="baseline/current pairs (3)")
    p.add_argument("--t-end", type=float, default=5.0, help="simulated time (the scene's 5 s)")
    p.add_argument("--accuracy", action="store_true", help="part 2: accuracy against time")
    p.add_argument("--answers", action="store_true",
                   help="part 1 with the rows' answers, as ancf run computes them")
    p.add_argument("--grid", type=lambda s: tuple(float(v) for v in s.split("/")), nargs="+",
                   default=GRID, help="part 2: dt/newton_tol pairs")
    p.add_argument("-o", "--output", type=Path, default=None,
                   help="report stem: writes STEM.json and STEM.md (and STEM.png, part 2)")
    p.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--history", type=Path, help=argparse.SUPPRESS)
    p.add_argument("--dt", type=float, default=None, help=argparse.SUPPRESS)
    p.add_argument("--tol", type=float, default=None, help=argparse.SUPPRESS)
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if args.worker:
        worker(args)
        return 0
    if args.baseline is None and not args.accuracy:
        sys.exit("give --baseline PYTHON (part 1) and/or --accuracy (part 2)")
    report: dict[str, Any] = {
        "benchmark": "leaf_spring_time",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "scene": str(SCENE.relative_to(REPO)), "machine": machine_info(),
        "settings": {"rounds": args.rounds, "t_end": args.t_end, "answers": args.answers,
                     "grid": args.grid,
                     "reference": REFERENCE},
        "units": "CPU and wall times in s; errors as fractions of the reference's range"}
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        report["builds"] = compare_builds(args, work) if args.baseline else None
        report["accuracy"] = accuracy(args, work) if args.accuracy else None
    if report["builds"]:
        s = report["builds"]["summary"]
        print_table([("build", 9), ("integrate best", 15), ("median", 8), ("process", 8),
                     ("newton", 7), ("fact", 5)],
                    [[side, f"{s[side]['integrate_cpu_best_s']:.3f}",
                      f"{s[side]['integrate_cpu_median_s']:.3f}",
                      f"{s[side]['process_cpu_best_s']:.3f}",
                      str(s[side]['newton_iterations']), str(s[side]['factorizations'])]
                     for side in ("baseline", "current")])
    if args.output is not None:
        args.output.parent.mkdir(parents=True, exist_ok=True)
        if report["accuracy"]:
            report["accuracy"]["chart"] = str(chart(report["accuracy"],
                                                    args.output.with_suffix(".png")))
        args.output.with_suffix(".json").write_text(json.dumps(json_ready(report), indent=1))
        args.output.with_suffix(".md").write_text(markdown(report))
        print(f"wrote {args.output.with_suffix('.json')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
