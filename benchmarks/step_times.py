"""Stepping time (the kernel's time steps as run_scene measures them: HDF5 timing
``dynamic_stepping``) of the small planar cable systems of step_instructions.py, for one or
two builds interleaved: each round runs every case once per build, in a fresh process per
build and case (each process runs the scene ``--repeats`` times and keeps its best), and
the result is the best over the rounds. Timings depend on the machine's load; the load
average (``uptime``) before and after is recorded with them.

    python benchmarks/step_times.py [--site DIR] [--baseline DIR] [--cases pend5full,...]
                                    [--rounds 5] [--repeats 5] [--output F]

``--site``/``--baseline``: the ancfdrv installed in DIR (PYTHONPATH; see history_gate.py
for a baseline build); without ``--site`` the installed one. Output
results/step_times.json and .md (or --output, its .md beside)."""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from step_instructions import CASES, REPO  # noqa: E402

RUN = """
import sys, h5py
from ancfdrv.runner import run_scene
scene, out, repeats, sets = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4:]
best = float('inf')
for _ in range(repeats):
    run_scene(scene, sets, out, progress=False)
    with h5py.File(out) as h5:
        best = min(best, float(h5['timing'].attrs['dynamic_stepping']))
        steps = len(h5['dynamic/time']) - 1
print(best, steps)
"""


def _uptime() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def _time(name: str, site: str | None, repeats: int, work: Path) -> tuple[float, int]:
    scene, *sets = CASES[name]
    env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    if site:
        env["PYTHONPATH"] = site
    done = subprocess.run([sys.executable, "-c", RUN, scene, str(work / f"{name}.h5"),
                           str(repeats), *sets], cwd=REPO, env=env, check=True,
                          capture_output=True, text=True)
    best, steps = done.stdout.split()[-2:]
    return float(best), int(steps)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--site", default=None, help="the ancfdrv installed in DIR")
    parser.add_argument("--baseline", default=None, help="a second build, interleaved")
    parser.add_argument("--cases", default="pend5full,pend9full,pend17full,spin11,boom4,boom7")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--output", default=str(REPO / "benchmarks/results/step_times.json"))
    args = parser.parse_args()
    builds = {"build": args.site} | ({"baseline": args.baseline} if args.baseline else {})
    names = args.cases.split(",")
    best: dict = {b: {n: float("inf") for n in names} for b in builds}
    steps: dict = {}
    load_before = _uptime()
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.rounds):
            for name in names:
                for build, site in builds.items():
                    seconds, steps[name] = _time(name, site, args.repeats, Path(tmp))
                    best[build][name] = min(best[build][name], seconds)
    load_after = _uptime()
    rows = []
    for name in names:
        row = {"case": name, "settings": CASES[name], "steps": steps[name]}
        for build in builds:
            row[f"{build}_stepping_ms"] = 1e3 * best[build][name]
        if "baseline" in builds:
            row["ratio"] = best["build"][name] / best["baseline"][name]
        rows.append(row)
        print(name, {k: round(v, 3) if isinstance(v, float) else v for k, v in row.items()
                     if k != "settings"}, flush=True)
    result = {"benchmark": "step_times", "builds": builds, "rounds": args.rounds,
              "repeats": args.repeats,
              "conditions": f"OMP_NUM_THREADS=1, {platform.machine()}, Python "
                            f"{platform.python_version()}; best of rounds x repeats",
              "load_before": load_before, "load_after": load_after, "cases": rows}
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps(result, indent=1) + "\n")
    head = "| case | steps | " + " | ".join(f"{b} stepping (ms)" for b in builds)
    head += " | ratio |" if "baseline" in builds else " |"
    lines = ["# Stepping time (best of many)", "", result["conditions"], "",
             f"load before: {load_before}", f"load after: {load_after}", "", head,
             "|" + "---|" * (2 + len(builds) + ("baseline" in builds))]
    for r in rows:
        cells = [f"{r[f'{b}_stepping_ms']:.2f}" for b in builds]
        if "baseline" in builds:
            cells.append(f"{r['ratio']:.3f}")
        lines.append(f"| {r['case']} | {r['steps']} | " + " | ".join(cells) + " |")
    output.with_suffix(".md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
