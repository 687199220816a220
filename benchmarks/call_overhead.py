#!/usr/bin/env python
"""The fixed cost of a small in-memory call outside the stepping (issue 23): whole
``ancfdrv.simulate`` calls of the 5-node planar cable pendulum (``inputs/hard/pendulum.nml``,
dt = 1 ms, 1 s: the peer harness's call), this package against another copy of it.

Per call: the wall time, the wall time outside the kernel's stepping (``advance_rows``
subtracted), the thread CPU time outside the stepping (``time.thread_time``: what this
thread computed, less distorted by other processes than the wall time) and the garbage
collector's collections and time during the call (``gc.callbacks``). Each copy runs in
its own processes (``--calls`` calls after three warm-up calls), the two alternating
``--rounds`` times, so both meet the same machine state; best and median of every figure.

``--instructions``: also the instructions per call outside the stepping (valgrind's
callgrind, exact and independent of the load: two calls after two warm-up calls, each
copy in its own process; ``fixed_cost.quiet_clock`` sizes the kernel calls as on a quiet
machine).

``--compare DIR``: the other copy, a directory holding ``ancfdrv/`` (``git archive
<commit> python/ancfdrv`` unpacked there, the built ``_kernel*.so`` copied in).

Output: ``benchmarks/results/call_overhead.json`` and ``.md``. Run from the repository
root::

    python benchmarks/call_overhead.py --compare /tmp/old [--rounds 10] [--instructions]
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
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
SCENE = REPO / "inputs" / "hard" / "pendulum.nml"
OVERRIDES = ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy", "solver.dt=0.001",
             "solver.t_end=1.0"]
WARM_UP = 3
FIELDS = ("wall_ms", "outside_wall_ms", "outside_cpu_ms", "gc_collections", "gc_ms")


def child(site: str, calls: int) -> None:
    """Time ``calls`` whole calls with the package at ``site`` ('-': this one); JSON out."""
    import gc
    import time
    if site != "-":
        sys.path.insert(0, site)
    import ancfdrv
    import ancfdrv.kernel as kernel
    stepping = [0.0, 0.0]
    real = kernel.KernelSystem.advance_rows

    def timed(*args, **kwargs):
        wall, cpu = time.perf_counter(), time.thread_time()
        try:
            return real(*args, **kwargs)
        finally:
            stepping[0] += time.perf_counter() - wall
            stepping[1] += time.thread_time() - cpu
    kernel.KernelSystem.advance_rows = timed
    collected = [0, 0.0, 0.0]

    def watch(phase: str, info: dict) -> None:
        if phase == "start":
            collected[2] = time.perf_counter()
        else:
            collected[0] += 1
            collected[1] += time.perf_counter() - collected[2]
    for _ in range(WARM_UP):
        ancfdrv.simulate(SCENE, OVERRIDES, progress=False)
    gc.callbacks.append(watch)
    rows = []
    for _ in range(calls):
        stepping[:] = [0.0, 0.0]
        collected[:2] = [0, 0.0]
        cpu, wall = time.thread_time(), time.perf_counter()
        ancfdrv.simulate(SCENE, OVERRIDES, progress=False)
        wall, cpu = time.perf_counter() - wall, time.thread_time() - cpu
        rows.append([1e3 * wall, 1e3 * (wall - stepping[0]), 1e3 * (cpu - stepping[1]),
                     collected[0], 1e3 * collected[1]])
    print(json.dumps(rows))


def counted(site: str, helper: str) -> None:
    """The child under callgrind: two warm-up calls, two counted calls."""
    import ctypes
    if site != "-":
        sys.path.insert(0, site)
    sys.path.insert(0, str(REPO / "benchmarks"))
    import ancfdrv
    from fixed_cost import quiet_clock
    quiet_clock()
    toggle = ctypes.CDLL(helper).callgrind_toggle
    for _ in range(2):
        ancfdrv.simulate(SCENE, OVERRIDES, progress=False)
    toggle()
    for _ in range(2):
        ancfdrv.simulate(SCENE, OVERRIDES, progress=False)
    toggle()


def instructions(site: str, work: Path, label: str) -> dict[str, float]:
    """Instructions per call (whole, stepping, outside the stepping), callgrind."""
    import re
    sys.path.insert(0, str(REPO / "benchmarks"))
    from fixed_cost import _helper
    helper = _helper(work)
    profile = work / f"{label}.callgrind"
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", PYTHONHASHSEED="0")
    subprocess.run(["valgrind", "--tool=callgrind", "--collect-atstart=no",
                    f"--callgrind-out-file={profile}", sys.executable, __file__,
                    "--counted", site, "--helper", str(helper)], env=env, check=True,
                   capture_output=True, cwd=REPO)
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100",
                           str(profile)], capture_output=True, text=True, check=True).stdout

    def count(pattern: str) -> int:
        found = re.search(r"^\s*([\d,]+)\s+(?:\([^)]*\)\s+)?" + pattern, text, re.M)
        return int(found.group(1).replace(",", "")) if found else 0
    total, stepping = count(r"PROGRAM TOTALS"), count(r"\S*:system_advance_ ")
    return {"whole_M": total / 2e6, "stepping_M": stepping / 2e6,
            "outside_M": (total - stepping) / 2e6}


def summary(rows: list[list[float]]) -> dict[str, dict[str, float]]:
    out = {}
    for k, name in enumerate(FIELDS):
        values = [r[k] for r in rows]
        out[name] = {"best": min(values), "median": statistics.median(values),
                     "mean": statistics.fmean(values)}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--compare", help="directory holding another ancfdrv package")
    parser.add_argument("--rounds", type=int, default=10)
    parser.add_argument("--calls", type=int, default=20)
    parser.add_argument("--instructions", action="store_true")
    parser.add_argument("--output", type=Path, default=RESULTS / "call_overhead.json",
                        help="the JSON report; its Markdown table beside it (.md)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--counted", help=argparse.SUPPRESS)
    parser.add_argument("--helper", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child, args.calls)
        return
    if args.counted:
        counted(args.counted, args.helper)
        return
    copies = {"this": "-"}
    if args.compare:
        copies = {"compared": str(Path(args.compare).resolve()), "this": "-"}
    load_before = os.getloadavg()
    rows: dict[str, list] = {k: [] for k in copies}
    for r in range(args.rounds):
        order = list(copies.items()) if r % 2 == 0 else list(copies.items())[::-1]
        for label, site in order:
            done = subprocess.run([sys.executable, __file__, "--child", site, "--calls",
                                   str(args.calls)], capture_output=True, text=True,
                                  check=True, cwd=REPO)
            rows[label] += json.loads(done.stdout)
    report = {"date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
              "scene": str(SCENE.relative_to(REPO)), "overrides": OVERRIDES,
              "rounds": args.rounds, "calls_per_round": args.calls,
              "compared": copies.get("compared"),
              "load_average_before": [round(x, 2) for x in load_before],
              "load_average_after": [round(x, 2) for x in os.getloadavg()],
              "copies": {k: summary(v) for k, v in rows.items()}}
    if args.instructions:
        with tempfile.TemporaryDirectory() as work:
            for label, site in copies.items():
                report["copies"][label]["instructions"] = instructions(site, Path(work), label)
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(json.dumps(report, indent=1) + "\n")
    lines = [f"# The fixed cost of a small in-memory call ({report['date']})", "",
             f"`ancfdrv.simulate({report['scene']}, {OVERRIDES})`: {args.rounds} rounds of "
             f"{args.calls} calls per copy, alternating; load average "
             f"{report['load_average_before']} before, {report['load_average_after']} after.",
             "", "| copy | wall ms best / median | outside the stepping, wall ms best / median "
             "| outside, thread CPU ms best / median | GC collections / call | GC ms / call "
             "| instructions outside the stepping (M) |", "|---|---|---|---|---|---|---|"]
    for label, s in report["copies"].items():
        ins = s.get("instructions", {}).get("outside_M")
        lines.append(
            f"| {label} | {s['wall_ms']['best']:.3f} / {s['wall_ms']['median']:.3f} "
            f"| {s['outside_wall_ms']['best']:.3f} / {s['outside_wall_ms']['median']:.3f} "
            f"| {s['outside_cpu_ms']['best']:.3f} / {s['outside_cpu_ms']['median']:.3f} "
            f"| {s['gc_collections']['mean']:.2f} | {s['gc_ms']['mean']:.3f} "
            f"| {'' if ins is None else f'{ins:.2f}'} |")
    args.output.with_suffix(".md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
