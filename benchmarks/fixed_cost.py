#!/usr/bin/env python
"""The fixed cost of one run outside the kernel's stepping (issue 23 item 4, "lean output"):
whole ``ancfdrv.runner.run_scene`` calls of the flexible pendulum (cable, planar, 5 and 17
nodes, dt = 1 ms, 1 s) and of the luffing boom (nonlinear cable, planar, 4 and 7 nodes,
10 s, 10000 rows, no XDMF), split into their phases.

Per case: the whole call's wall time (best of ``--repeats``), and per phase the median
thread CPU time (``time.thread_time``: what this thread computed, not what other processes
took from it, so the split stays meaningful on a loaded machine): scene load, model build,
result file creation, static solve and its output, the dynamic writer's set-up, the
answers recorder per chunk, the kernel's stepping (``advance_rows``), the final flush, the
dynamic answers and attributes, finish, the output lock. "non-stepping" is the whole
call's thread CPU time minus the stepping's.

``--compare PATH``: run the same cases with another copy of the package (a directory
holding ``ancfdrv/``, e.g. ``git archive <commit> python/ancfdrv`` unpacked, with the
built ``_kernel*.so`` copied in) in a subprocess, interleaved case by case, so both are
measured under the same load.

``--instructions``: also count, with valgrind's callgrind (exact and independent of the
machine's load), the instructions of ``INSTRUCTION_CALLS`` whole calls of each case after
two warm-up calls (collection switched on and off around them by callgrind's client
request, from a tiny C helper compiled with the system's ``cc``): per call the total, the
kernel's stepping (``system_advance_``, inclusive) and the rest ("non-stepping"); needs
valgrind and its headers. A call here is what ``benchmarks/peer_exudyn.py`` times: the
run, then the tip history read back. ``FLUSH_SECONDS`` is raised in the counted process (a
run lasts ~50 times longer under valgrind and would flush by the clock where a quiet
machine's run ends before its first flush deadline), and the stepper's clock there
advances 1 us per reading (it sizes the kernel calls by their elapsed time: the chunks of
a quiet machine, the same in every count). Caveat: callgrind counts every iteration of a
``rep stos`` as an instruction, so large ``memset``s (HDF5 zeroes its caches) weigh more
than their time.

Output: ``benchmarks/results/fixed_cost.json`` (``--quick``: ``fixed_cost_quick.json``,
ignored by git). Run from the repository root::

    python benchmarks/fixed_cost.py                   # ~1 minute
    python benchmarks/fixed_cost.py --compare /tmp/old --repeats 20
"""
from __future__ import annotations

import argparse
import functools
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
CASES: dict[str, tuple[str, list[str]]] = {
    "pendulum_cable_5": ("inputs/hard/pendulum.nml", [
        "beam.nodes=5", "solver.dt=1e-3", "beam.bending=cable", "scene.planar=xy"]),
    "pendulum_cable_17": ("inputs/hard/pendulum.nml", [
        "beam.nodes=17", "solver.dt=1e-3", "beam.bending=cable", "scene.planar=xy"]),
    "boom_cable_4": ("inputs/boom_luffing.nml", [
        "scene.formulation=nonlinear", "solver.static_method=newton", "output.xdmf=.false.",
        "beam.bending=cable", "beam.nodes=4", "scene.planar=xy"]),
    "boom_cable_7": ("inputs/boom_luffing.nml", [
        "scene.formulation=nonlinear", "solver.static_method=newton", "output.xdmf=.false.",
        "beam.bending=cable", "beam.nodes=7", "scene.planar=xy"]),
}
QUICK = {"pendulum_cable_5": CASES["pendulum_cable_5"]}
#: the whole calls counted per case by ``--instructions`` (after two warm-up calls)
INSTRUCTION_CALLS = 2
_TOGGLE_C = ("#include <valgrind/callgrind.h>\n"
             "void callgrind_toggle(void) { CALLGRIND_TOGGLE_COLLECT; }\n")


def _call(case: str, out: Path) -> None:
    """One whole call as the peer harness makes it: run, then read the tip history."""
    import h5py
    import ancfdrv.runner as runner
    scene, overrides = CASES[case]
    runner.run_scene(REPO / scene, overrides, out, progress=False)
    with h5py.File(out, "r") as h5:
        h5["dynamic/time"][()]
        h5["dynamic/probes/tip"][()]


def counted_calls(case: str, helper: str) -> None:
    """The child of :func:`instructions`: warm-up calls, then INSTRUCTION_CALLS calls with
    callgrind's collection on."""
    import ctypes
    import types
    import ancfdrv.results.hdf5 as h5
    import ancfdrv.solvers.dynamic as dynamic
    # under valgrind a run lasts ~50 times longer and its writer would flush by the clock
    # (FLUSH_SECONDS) where a quiet machine's run ends first: the rows wait for the end
    h5.FLUSH_SECONDS = 1e9
    # the stepper sizes its kernel calls by the elapsed time of the first (~0.25 s each):
    # a clock that advances 1 us per reading sizes them as a quiet machine does (up to
    # output.chunk_steps), the same in every count (valgrind's slow and load-dependent
    # clock gave other chunks, other answers passes: +-30 M instructions on the boom)
    ticks = iter(range(1, 1 << 62))
    dynamic.time = types.SimpleNamespace(perf_counter=lambda: 1e-6 * next(ticks),
                                         monotonic=time.monotonic, time=time.time)
    toggle = ctypes.CDLL(helper).callgrind_toggle
    out = Path(tempfile.mkdtemp()) / "run.h5"
    for _ in range(2):
        _call(case, out)
    toggle()
    for _ in range(INSTRUCTION_CALLS):
        _call(case, out)
    toggle()


def instructions(case: str, work: Path) -> dict[str, Any]:
    """Instructions per whole call of ``case`` (total, stepping, non-stepping; callgrind)."""
    import re
    helper = work / "callgrind_toggle.so"
    if not helper.exists():
        source = work / "callgrind_toggle.c"
        source.write_text(_TOGGLE_C)
        subprocess.run(["cc", "-O1", "-shared", "-fPIC", "-o", str(helper), str(source)],
                       check=True)
    profile = work / f"{case}.callgrind"
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", PYTHONHASHSEED="0")
    subprocess.run(["valgrind", "--tool=callgrind", "--collect-atstart=no",
                    f"--callgrind-out-file={profile}", sys.executable, __file__,
                    "--counted", case, "--helper", str(helper)], env=env, check=True,
                   capture_output=True)
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100",
                           str(profile)], capture_output=True, text=True, check=True).stdout

    def count(pattern: str) -> int:
        found = re.search(r"^\s*([\d,]+)\s+(?:\([^)]*\)\s+)?" + pattern, text, re.M)
        return int(found.group(1).replace(",", "")) if found else 0
    total = count(r"PROGRAM TOTALS")
    stepping = count(r"\S*:system_advance_ ")
    return {"calls": INSTRUCTION_CALLS,
            "whole_per_call": total / INSTRUCTION_CALLS,
            "stepping_per_call": stepping / INSTRUCTION_CALLS,
            "non_stepping_per_call": (total - stepping) / INSTRUCTION_CALLS}


def measure(case: str, repeats: int) -> dict[str, Any]:
    """Phases of ``repeats`` whole calls of one case in this process (after one warm-up)."""
    import ancfdrv.kernel as kernel
    import ancfdrv.results.hdf5 as h5
    import ancfdrv.runner as runner
    import ancfdrv.system.answers as answers
    spent: dict[str, float] = {}

    def wrap(owner: Any, attr: str, label: str) -> None:
        real = getattr(owner, attr)

        @functools.wraps(real)
        def timed(*args: Any, **kwargs: Any) -> Any:
            t0 = time.thread_time()
            try:
                return real(*args, **kwargs)
            finally:
                spent[label] = spent.get(label, 0.0) + time.thread_time() - t0
        setattr(owner, attr, timed)
    for owner, attr, label in (
            (runner, "load_scene", "scene"), (runner, "build_model", "model"),
            (runner, "check_output_path", "output path check"),
            (runner.OutputLock, "__enter__", "lock"), (runner.OutputLock, "__exit__", "unlock"),
            (h5, "create", "h5 create"), (runner, "solve_static", "static solve"),
            (h5, "write_static", "h5 static"), (h5, "write_static_answers", "h5 static answers"),
            (h5.DynamicWriter, "__init__", "h5 writer set-up"),
            (answers.DynamicAnswers, "__call__", "answers per chunk"),
            (h5.DynamicWriter, "flush", "h5 flush"),
            (h5, "write_dynamic_answers", "h5 dynamic answers"),
            (h5, "write_dynamic_attrs", "h5 dynamic attributes"), (h5, "finish", "h5 finish")):
        wrap(owner, attr, label)
    for value in vars(kernel).values():
        if isinstance(value, type) and "advance_rows" in vars(value):
            wrap(value, "advance_rows", "kernel stepping")
    scene, overrides = CASES[case]
    out = Path(tempfile.mkdtemp()) / "run.h5"
    runner.run_scene(REPO / scene, overrides, out, progress=False)
    rows, walls = [], []
    for _ in range(repeats):
        spent.clear()
        w0, c0 = time.perf_counter(), time.thread_time()
        runner.run_scene(REPO / scene, overrides, out, progress=False)
        spent["whole (thread CPU)"] = time.thread_time() - c0
        walls.append(time.perf_counter() - w0)
        spent["non-stepping (thread CPU)"] = (spent["whole (thread CPU)"]
                                              - spent.get("kernel stepping", 0.0))
        rows.append(dict(spent))
    labels = list(dict.fromkeys(k for r in rows for k in r))
    return {"whole_wall_best_ms": 1e3 * min(walls),
            "phases_thread_cpu_median_ms": {k: 1e3 * statistics.median(r.get(k, 0.0)
                                                                        for r in rows)
                                            for k in labels},
            "repeats": repeats}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--compare", help="directory holding another ancfdrv package")
    parser.add_argument("--instructions", action="store_true",
                        help="also count instructions per call with callgrind")
    parser.add_argument("--one", help=argparse.SUPPRESS)  # a subprocess: one case, JSON out
    parser.add_argument("--counted", help=argparse.SUPPRESS)  # under callgrind
    parser.add_argument("--helper", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        print(json.dumps(measure(args.one, args.repeats)))
        return 0
    if args.counted:
        counted_calls(args.counted, args.helper)
        return 0
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _common import load_average, machine_info
    cases = QUICK if args.quick else CASES
    record: dict[str, Any] = {"machine": machine_info(), "cases": {}}
    for case in cases:
        versions = {"this": None, **({"compared": args.compare} if args.compare else {})}
        for label, path in versions.items():
            env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "1"))
            if path:
                env["PYTHONPATH"] = str(Path(path).resolve())
            done = subprocess.run([sys.executable, __file__, "--one", case, "--repeats",
                                   str(2 if args.quick else args.repeats)], env=env,
                                  capture_output=True, text=True, check=True)
            result = json.loads(done.stdout.strip().splitlines()[-1])
            record["cases"].setdefault(case, {})[label] = result
            phases = result["phases_thread_cpu_median_ms"]
            print(f"{case:18s} {label:8s} whole {result['whole_wall_best_ms']:7.1f} ms wall; "
                  f"stepping {phases.get('kernel stepping', 0):6.1f}, non-stepping "
                  f"{phases['non-stepping (thread CPU)']:6.1f} ms thread CPU")
            if args.instructions:
                with tempfile.TemporaryDirectory() as tmp:
                    if path:
                        env_path = os.environ.get("PYTHONPATH")
                        os.environ["PYTHONPATH"] = str(Path(path).resolve())
                    try:
                        counts = instructions(case, Path(tmp))
                    finally:
                        if path:
                            if env_path is None:
                                os.environ.pop("PYTHONPATH", None)
                            else:
                                os.environ["PYTHONPATH"] = env_path
                result["instructions"] = counts
                print(f"{'':27s} instructions per call: whole "
                      f"{counts['whole_per_call'] / 1e6:7.2f} M, stepping "
                      f"{counts['stepping_per_call'] / 1e6:7.2f} M, non-stepping "
                      f"{counts['non_stepping_per_call'] / 1e6:7.2f} M")
    record["load_average_at_end"] = load_average()
    name = "fixed_cost_quick.json" if args.quick else "fixed_cost.json"
    target = REPO / "benchmarks" / "results" / name
    target.write_text(json.dumps(record, indent=1) + "\n")
    print(f"wrote {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
