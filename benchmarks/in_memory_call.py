#!/usr/bin/env python
"""What the HDF5 file costs a whole call: ``ancfdrv.simulate`` (results kept in memory)
against ``ancfdrv.runner.run_scene`` (the SPEC section-4 file) on the flexible pendulum as
``peer_exudyn.py`` runs it (cable, planar, dt = 1 ms, 1 s: 1000 steps) at 5, 9 and 17
nodes.

A call is what the peer harness times: the run, then the tip history read (from the
``Simulation``, or from the file). Both calls compute the same history (checked bit for
bit here). Wall times: ``--repeats`` pairs of calls in this process after two warm-up
pairs, interleaved (memory, file, memory, file, ...: both meet the same machine state);
best and median of each, and the median of the per-pair ratios. The load average is
recorded before and after: on a loaded machine the best times are the meaningful ones.

``--instructions``: also count, with valgrind's callgrind (exact and independent of the
load), the instructions of ``INSTRUCTION_CALLS`` calls of each kind after two warm-up
calls (collection switched on and off around them by callgrind's client request, from a
tiny C helper compiled with the system's ``cc``), each kind in its own process. As in
``fixed_cost.py``: the writer's flush deadline is raised under valgrind (a run lasts ~50
times longer there and would flush by the clock) and the stepper's clock advances 1 us per
reading (the kernel calls sized as on a quiet machine, the same in every count).

Output: ``benchmarks/results/in_memory_call.json`` and ``.md``. Run from the repository
root::

    python benchmarks/in_memory_call.py [--repeats 40] [--instructions] [--nodes 5 9 17]
"""
from __future__ import annotations

import argparse
import datetime as _dt
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "inputs" / "hard" / "pendulum.nml"
RESULTS = REPO / "benchmarks" / "results"
#: the calls counted per kind by ``--instructions`` (after two warm-up calls)
INSTRUCTION_CALLS = 2
_TOGGLE_C = ("#include <valgrind/callgrind.h>\n"
             "void callgrind_toggle(void) { CALLGRIND_TOGGLE_COLLECT; }\n")


def overrides(nodes: int) -> list[str]:
    return [f"beam.nodes={nodes}", "beam.bending=cable", "scene.planar=xy", "solver.dt=1e-3",
            "solver.t_end=1.0"]


def in_memory(nodes: int, out: Path) -> tuple[np.ndarray, np.ndarray]:
    """One in-memory call: the run and the tip history (time, global y)."""
    import ancfdrv
    sim = ancfdrv.simulate(SCENE, overrides(nodes), progress=False)
    return sim.time, sim.probe("tip")[:, 1]


def with_file(nodes: int, out: Path) -> tuple[np.ndarray, np.ndarray]:
    """One call writing the file: the run and the tip history read back."""
    import h5py
    from ancfdrv.runner import run_scene
    run_scene(SCENE, overrides(nodes), out, progress=False)
    with h5py.File(out, "r") as h5:
        return h5["dynamic/time"][()], h5["dynamic/probes/tip"][:, 1]


KINDS = {"memory": in_memory, "file": with_file}


def wall_times(nodes: int, repeats: int, out: Path) -> dict[str, Any]:
    """Interleaved pairs of calls (after two warm-up pairs): best, median, ratios."""
    for _ in range(2):
        first, second = in_memory(nodes, out), with_file(nodes, out)
    same = all(np.array_equal(a, b) for a, b in zip(first, second))
    times: dict[str, list[float]] = {"memory": [], "file": []}
    for _ in range(repeats):
        for kind, call in KINDS.items():
            t0 = time.perf_counter()
            call(nodes, out)
            times[kind].append(time.perf_counter() - t0)
    ratios = [m / f for m, f in zip(times["memory"], times["file"])]
    return {"nodes": nodes, "repeats": repeats, "histories_bitwise_equal": same,
            **{f"{kind}_best_ms": 1e3 * min(t) for kind, t in times.items()},
            **{f"{kind}_median_ms": 1e3 * statistics.median(t) for kind, t in times.items()},
            "memory_over_file_median_of_pairs": statistics.median(ratios)}


def counted_calls(kind: str, nodes: int, helper: str) -> None:
    """The child of :func:`instructions`: two warm-up calls, then INSTRUCTION_CALLS calls
    with callgrind's collection on (fixed_cost.py's quiet clock and flush settings)."""
    import ctypes
    from fixed_cost import quiet_clock
    quiet_clock()
    toggle = ctypes.CDLL(helper).callgrind_toggle
    out = Path(tempfile.mkdtemp()) / "run.h5"
    for _ in range(2):
        KINDS[kind](nodes, out)
    toggle()
    for _ in range(INSTRUCTION_CALLS):
        KINDS[kind](nodes, out)
    toggle()


def instructions(kind: str, nodes: int, work: Path) -> dict[str, float]:
    """Instructions per call of one kind (total, the kernel's stepping, the rest)."""
    helper = work / "callgrind_toggle.so"
    if not helper.exists():
        source = work / "callgrind_toggle.c"
        source.write_text(_TOGGLE_C)
        subprocess.run(["cc", "-O1", "-shared", "-fPIC", "-o", str(helper), str(source)],
                       check=True)
    profile = work / f"{kind}_{nodes}.callgrind"
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", PYTHONHASHSEED="0")
    subprocess.run(["valgrind", "--tool=callgrind", "--collect-atstart=no",
                    f"--callgrind-out-file={profile}", sys.executable, __file__,
                    "--counted", kind, "--nodes", str(nodes), "--helper", str(helper)],
                   env=env, check=True, capture_output=True)
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100",
                           str(profile)], capture_output=True, text=True, check=True).stdout

    def count(pattern: str) -> int:
        found = re.search(r"^\s*([\d,]+)\s+(?:\([^)]*\)\s+)?" + pattern, text, re.M)
        return int(found.group(1).replace(",", "")) if found else 0
    total, stepping = count(r"PROGRAM TOTALS"), count(r"\S*:system_advance_ ")
    return {"whole_per_call": total / INSTRUCTION_CALLS,
            "stepping_per_call": stepping / INSTRUCTION_CALLS,
            "non_stepping_per_call": (total - stepping) / INSTRUCTION_CALLS}


def markdown(report: dict[str, Any]) -> str:
    load = report["load_average"]
    lines = ["# The whole call in memory against the call writing the HDF5 file", "",
             f"{report['created']}; flexible pendulum, cable, planar, dt = 1 ms, 1 s (1000 "
             f"steps); load average before {load['before']}, after {load['after']} (2 cores).",
             "A call: the run and the tip history read (`ancfdrv.simulate` / `run_scene` and "
             "the file read back); interleaved pairs, best and median.", "",
             "| nodes | in memory best / median ms | with file best / median ms | "
             "memory / file (median of pairs) | histories equal |",
             "|---:|---:|---:|---:|---|"]
    for r in report["wall"]:
        lines.append(f"| {r['nodes']} | {r['memory_best_ms']:.2f} / {r['memory_median_ms']:.2f} "
                     f"| {r['file_best_ms']:.2f} / {r['file_median_ms']:.2f} | "
                     f"{r['memory_over_file_median_of_pairs']:.3f} | "
                     f"{'bitwise' if r['histories_bitwise_equal'] else 'NO'} |")
    if report.get("instructions"):
        lines += ["", "Instructions per call (callgrind, exact; after two warm-up calls):", "",
                  "| nodes | kind | whole | stepping | outside the stepping |",
                  "|---:|---|---:|---:|---:|"]
        for r in report["instructions"]:
            lines.append(f"| {r['nodes']} | {r['kind']} | {r['whole_per_call'] / 1e6:.2f} M | "
                         f"{r['stepping_per_call'] / 1e6:.2f} M | "
                         f"{r['non_stepping_per_call'] / 1e6:.2f} M |")
    return "\n".join(lines) + "\n"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=40)
    parser.add_argument("--nodes", type=int, nargs="+", default=[5, 9, 17])
    parser.add_argument("--instructions", action="store_true")
    parser.add_argument("--output", type=Path, default=RESULTS / "in_memory_call.json")
    parser.add_argument("--counted", help=argparse.SUPPRESS)
    parser.add_argument("--helper", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.counted:
        counted_calls(args.counted, args.nodes[0], args.helper)
        return 0
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _common import load_average, machine_info, write_report
    start = time.perf_counter()
    import ancfdrv.runner  # noqa: F401 - imports stay out of the timings
    import ancfdrv.simulation  # noqa: F401
    report: dict[str, Any] = {
        "benchmark": "in_memory_call",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "machine": machine_info(), "load_average": {"before": load_average()},
        "scene": str(SCENE.relative_to(REPO)), "wall": [], "instructions": []}
    with tempfile.TemporaryDirectory(prefix="in_memory_call_") as tmp:
        for nodes in args.nodes:
            row = wall_times(nodes, args.repeats, Path(tmp) / "run.h5")
            report["wall"].append(row)
            print(f"{nodes:3d} nodes: in memory {row['memory_best_ms']:.2f} ms best "
                  f"({row['memory_median_ms']:.2f} median), with file "
                  f"{row['file_best_ms']:.2f} ms ({row['file_median_ms']:.2f}); memory/file "
                  f"{row['memory_over_file_median_of_pairs']:.3f}", flush=True)
        report["load_average"]["after"] = load_average()
        if args.instructions:
            for nodes in args.nodes:
                for kind in KINDS:
                    row = {"nodes": nodes, "kind": kind,
                           **instructions(kind, nodes, Path(tmp))}
                    report["instructions"].append(row)
                    print(f"{nodes:3d} nodes {kind:6s}: {row['whole_per_call'] / 1e6:.2f} M "
                          f"instructions per call ({row['stepping_per_call'] / 1e6:.2f} M "
                          "stepping)", flush=True)
    report["wall_time_s"] = time.perf_counter() - start
    report["markdown"] = markdown(report)
    write_report(args.output, report)
    args.output.with_suffix(".md").write_text(report["markdown"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
