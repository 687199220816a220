#!/usr/bin/env python
"""What the default answers cost (issue 38, item 4): the reactions, section forces and
stress envelope a dynamic run records at its output rows (``output.answers``, default on),
as the share they add to a whole run, and the FFR boom's step with them against one banded
back-substitution.

Per case, whole ``ancfdrv.runner.run_scene`` calls with ``output.answers = true`` and
``false`` alternately, each timed by the process's CPU time (``time.process_time``: what
this process computed, not what other processes took from it on a shared machine), best
of ``--repeats``; "added" = on / off - 1. Cases: the shipped luffing boom
(``inputs/boom_luffing.nml``: 'ffr', 28 nodes, 10000 rows; as shipped, with its XDMF, and
without it), its general twin (``inputs/general/boom_luffing.nml``), the knuckle crane with
its hoist rope (``inputs/knuckle_crane_rope.nml``: large-deformation beams, joints and a
rope) and the 'ffr' cantilever run dynamically for 1 s (``inputs/cantilever.nml``).

The FFR step's measure (as ``benchmarks/dynamic_scaling.py`` defines the floor): the CPU
time of the dynamic solve (``ancfdrv.solvers.dynamic.integrate`` with the run's sink: the
stepping, the answers recorder and the rows' output) per step of the shipped boom without
XDMF, with the answers and without, over one forward/back substitution with the step's own
factor (the LAPACK banded Cholesky of the kernel's system, ``model.solver.solve`` of
``--bulk-rhs`` right-hand sides at once, divided by their number; CPU time, best of
``--repeats``).

Several builds are compared interleaved: ``--python`` names each build's interpreter (e.g.
main's ``/work/main/.venv/bin/python`` and this worktree's); every round runs each build
once, in a fresh process, and the best over ``--rounds`` is kept. The load average is
recorded before and after.

    .venv/bin/python benchmarks/answers_cost.py --python /work/main/.venv/bin/python \\
        .venv/bin/python -o benchmarks/results/answers_cost.json
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

#: (name, scene, overrides)
CASES = [
    ("boom (shipped)", "inputs/boom_luffing.nml", []),
    ("boom, no XDMF", "inputs/boom_luffing.nml", ["output.xdmf=false"]),
    ("general boom", "inputs/general/boom_luffing.nml", []),
    ("knuckle crane rope", "inputs/knuckle_crane_rope.nml", []),
    ("cantilever 1 s", "inputs/cantilever.nml",
     ["scene.analysis=static+dynamic", "solver.t_end=1.0"]),
]


def _runs(repeats: int, work: Path) -> dict[str, dict[str, float]]:
    """Per case the best CPU time (s) of whole runs with the answers on and off."""
    from ancfdrv.runner import run_scene
    out = {}
    for name, scene, over in CASES:
        path = work / "run.h5"
        run_scene(REPO / scene, over, path, progress=False)   # warm (imports, caches)
        best = {"on": float("inf"), "off": float("inf")}
        for _ in range(repeats):
            for key, flag in (("on", "true"), ("off", "false")):
                start = time.process_time()
                run_scene(REPO / scene, over + [f"output.answers={flag}"], path,
                          progress=False)
                best[key] = min(best[key], time.process_time() - start)
        out[name] = best
    return out


def _boom_step(repeats: int, bulk: int, work: Path) -> dict[str, float]:
    """The shipped boom's dynamic solve per step (CPU s) with and without the answers
    (no XDMF), and one back-substitution with the step's factor (CPU s)."""
    import numpy as np
    from ancfdrv import runner
    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    from ancfdrv.solvers.dynamic import integrate

    seen: dict[str, float] = {}
    models = []

    def timed(model, settings, *args, **kwargs):
        start = time.process_time()
        result = integrate(model, settings, *args, **kwargs)
        seen["cpu"], seen["steps"] = time.process_time() - start, result.steps
        models.append(model)
        return result

    scene = REPO / "inputs/boom_luffing.nml"
    best = {"on": float("inf"), "off": float("inf")}
    runner.integrate = timed
    try:
        for _ in range(repeats):
            for key, flag in (("on", "true"), ("off", "false")):
                runner.run_scene(scene, ["output.xdmf=false", f"output.answers={flag}"],
                                 work / "step.h5", progress=False)
                best[key] = min(best[key], seen["cpu"] / seen["steps"])
    finally:
        runner.integrate = integrate
    # the floor: the kernel's factor of the step's system (built by a short run's first
    # step and kept in the model's solver)
    model = build_model(load_scene(scene, ["solver.t_end=0.002"]))
    from ancfdrv.solvers.static import solve_newton
    static = solve_newton(model, tol=1e-10, max_iter=50)
    from ancfdrv.runner import dynamic_settings
    integrate(model, dynamic_settings(load_scene(scene, ["solver.t_end=0.002"])), static.e)
    rhs = np.ones((model.ndof, bulk))
    floor = float("inf")
    for _ in range(repeats):
        calls, start = 0, time.process_time()
        while time.process_time() - start < 0.05:
            model.solver.solve(rhs)
            calls += 1
        floor = min(floor, (time.process_time() - start) / (calls * bulk))
    model.close()
    return {"step_on_s": best["on"], "step_off_s": best["off"], "floor_s": floor}


def worker(args: argparse.Namespace) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        result = {"runs": _runs(args.repeats, work),
                  "boom_step": _boom_step(args.repeats, args.bulk_rhs, work)}
    print(json.dumps(result))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--python", nargs="+", default=[sys.executable],
                        help="the builds' interpreters, measured interleaved")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--bulk-rhs", type=int, default=64)
    parser.add_argument("-o", "--output", type=Path)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args)
        return
    load_before = os.getloadavg()
    found: dict[str, dict] = {}
    for _ in range(args.rounds):
        for python in args.python:
            text = subprocess.run(
                [python, __file__, "--worker", "--repeats", str(args.repeats),
                 "--bulk-rhs", str(args.bulk_rhs)],
                check=True, capture_output=True, text=True, cwd=REPO).stdout
            new = json.loads(text.strip().splitlines()[-1])
            old = found.setdefault(python, new)
            for name, times in new["runs"].items():
                for key in times:
                    old["runs"][name][key] = min(old["runs"][name][key], times[key])
            for key, value in new["boom_step"].items():
                old["boom_step"][key] = min(old["boom_step"][key], value)
    load_after = os.getloadavg()
    report = {"date": time.strftime("%Y-%m-%d %H:%M"), "load_average_before": load_before,
              "load_average_after": load_after, "rounds": args.rounds,
              "repeats": args.repeats, "builds": {}}
    for python, result in found.items():
        rows = {}
        print(f"{python}:")
        for name, times in result["runs"].items():
            added = times["on"] / times["off"] - 1.0
            rows[name] = {"answers_on_cpu_s": times["on"], "answers_off_cpu_s": times["off"],
                          "added_percent": 100.0 * added}
            print(f"  {name:20s} on {1e3 * times['on']:7.1f} ms  off "
                  f"{1e3 * times['off']:7.1f} ms  answers add {100 * added:5.1f} %")
        step = result["boom_step"]
        ratios = {"step_with_answers_over_floor": step["step_on_s"] / step["floor_s"],
                  "step_without_answers_over_floor": step["step_off_s"] / step["floor_s"]}
        print(f"  FFR boom step: {1e6 * step['step_on_s']:.1f} us with the answers, "
              f"{1e6 * step['step_off_s']:.1f} us without; one back-substitution "
              f"{1e6 * step['floor_s']:.2f} us: {ratios['step_with_answers_over_floor']:.2f}x "
              f"and {ratios['step_without_answers_over_floor']:.2f}x")
        report["builds"][python] = {"runs": rows, "boom_step": {**step, **ratios}}
    print(f"load average before {load_before[0]:.2f}, after {load_after[0]:.2f}")
    if args.output:
        args.output.write_text(json.dumps(report, indent=1) + "\n")


if __name__ == "__main__":
    main()
