"""Every benchmark in one run, one report: the entry point of ``make bench``.

    python benchmarks/run_all.py [--quick] [--only NAME,...] [--out DIR]   # run, then report
    python benchmarks/run_all.py --list [--quick]                          # what would run

Each benchmark script runs in its own process from the repository root, with its JSON
(and Markdown, where the script writes one) sent to ``DIR`` (default ``results/bench``),
its output to ``DIR/<name>.log``; ``DIR/report.md`` lists every benchmark with its
command, status, wall time and files. ``--quick`` passes each script's smoke setting
(``--quick``, or the smallest options it has), so the whole bench takes minutes instead
of hours; the figures of a quick run are not the ones benchmarks/README.md quotes.

Benchmarks that need what the machine may not have are skipped, saying why: the peer
comparisons need Exudyn (``pip install exudyn``), the instruction counts valgrind. The
tools that compare two builds or two solvers (``before_after.py``, ``history_gate.py``,
``h5_compare.py``, ``static_kernel_gate.py``, ``leaf_spring_time.py``) are gates, not benchmarks, and are listed
but not run. Exit status 1 when a benchmark that ran failed.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import importlib.util
import os
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent


@dataclass(frozen=True)
class Bench:
    """One benchmark script: its options for a full and a quick run (``quick`` None: it has
    no smoke setting), how it names its output (``out``: the option taking the JSON path,
    or None when the script prints, or writes to a fixed place under benchmarks/results
    listed in ``fixed``), what it needs, and for a gate why it is not run."""

    name: str
    what: str
    full: tuple[str, ...] = ()
    quick: tuple[str, ...] | None = ("--quick",)
    out: str | None = "--output"
    fixed: tuple[str, ...] = ()
    needs: str = ""
    gate: str = ""


BENCHES = [
    Bench("static_scaling", "boom statics against the mesh size (Newton, split iteration)"),
    Bench("dynamic_scaling", "luffing-boom dynamics per step against the mesh size"),
    Bench("element_cost", "beam element forces and tangents per element, OpenMP threads"),
    Bench("plate_cost", "thin plate element cost; plate pendulum time against accuracy"),
    Bench("leaf_contact_cost", "leaf-to-leaf contact per call and per run of the two-leaf spring"),
    Bench("modal_boom", "modes of the 28-node boom against its static solve, per eigensolver",
          quick=("--repeats", "1"), out=None),
    Bench("ffr_pdelta", "FFR boom against the large-deformation model, P-delta off/on",
          quick=("--t-end", "1.0"), out="-o"),
    Bench("ffr_reduced", "modal reduction of the FFR boom: error and time against modes",
          quick=("--modes", "1", "2", "--repeats", "1", "--run-repeats", "1"), out="-o"),
    Bench("planar_reduction", "planar reduction: all coordinates against the in-plane ones"),
    Bench("fixed_cost", "a run's cost outside the kernel's stepping, phase by phase",
          full=(), out=None, fixed=("fixed_cost.json",)),
    Bench("in_memory_call", "ancfdrv.simulate against run_scene (the HDF5 file's cost)",
          quick=("--repeats", "3", "--nodes", "5")),
    Bench("call_overhead", "fixed cost of a small in-memory call outside the stepping",
          quick=("--rounds", "2", "--calls", "3")),
    Bench("answers_cost", "what the default answers add to whole runs; the FFR step with "
          "them against one back-substitution", quick=("--rounds", "1", "--repeats", "1"),
          out="-o"),
    Bench("step_times", "stepping time of the small planar cable systems",
          quick=("--rounds", "1", "--repeats", "1", "--cases", "pend5full,boom4")),
    Bench("step_instructions", "instructions per time step (callgrind)",
          quick=("--cases", "boom4"), needs="valgrind"),
    Bench("stability", "long-run stability suite: completion, step cuts, energy balance",
          out=None, fixed=("stability.json", "stability.md")),
    Bench("hard_case_suite", "hard cases of record: each run correct, refused or ok and wrong"),
    Bench("energy_momentum", "energy-momentum against generalized-alpha on the pendulum, "
          "a rope and the double pendulum: accuracy, energy drift, cost per step",
          full=("--charts", "{out}")),
    Bench("command_cost", "a small ancf command's cost beyond its computing: start-up, "
          "imports, the XDMF", quick=("--repeats", "1"), out=None,
          fixed=("command_cost.json",)),
    Bench("right_angle_cantilever", "right-angle cantilever (Simo & Vu-Quoc 1986), 0-30 s"),
    Bench("spatial_mechanism", "spatial slider-crank, both bending options, nu = 0 and 0.3"),
    Bench("flying_spaghetti", "3D flying spaghetti (Simo & Vu-Quoc 1988)", out="--out"),
    Bench("accuracy_chart", "every accuracy knob of the luffing boom on one chart",
          full=("--chart", "{out}/boom_accuracy_vs_time.png", "-o", "{out}/accuracy_chart"),
          quick=None, out=None),
    Bench("boom_front", "the luffing boom's error-against-time front over step, mesh, Newton "
          "tolerance and output; each accuracy level's fastest configuration", quick=None),
    Bench("peer_harness", "ancfdrv against Exudyn on the same problems", needs="exudyn"),
    Bench("peer_exudyn", "accuracy against time with Exudyn's ANCFCable2D, hard cases",
          needs="exudyn"),
    Bench("peer_cantilever", "nonlinear cantilever, time per step and memory, with Exudyn",
          needs="exudyn"),
    Bench("before_after", "", gate="compares two ancfdrv versions (--before/--after)"),
    Bench("history_gate", "", gate="compares the histories of two builds bitwise"),
    Bench("newton_tolerance", "", gate="compares two ancfdrv versions' Newton control at "
          "large steps and loose tolerances (--before/--after)"),
    Bench("leaf_spring_time", "", gate="compares two builds' CPU time on the two-leaf "
          "spring's 5 s run (--baseline PYTHON; --accuracy: error against time)"),
    Bench("h5_compare", "", gate="compares two directories of result files"),
    Bench("static_kernel_gate", "", gate="compares the kernel's static Newton with the "
          "Python reference"),
    Bench("lee_frame", "", gate="writes the reference path of tests/test_arc_length.py "
          "(arc length, 81 nodes)"),
    Bench("lee_frame_displacement", "", gate="writes the independent reference path of "
          "tests/test_arc_length.py (displacement control through a stiff spring)"),
]


def missing(need: str) -> str:
    """Why a requirement is not met on this machine ('' when it is)."""
    if need == "exudyn" and importlib.util.find_spec("exudyn") is None:
        return "Exudyn is not installed (pip install exudyn)"
    if need == "valgrind" and shutil.which("valgrind") is None:
        return "valgrind is not installed"
    return ""


def command(bench: Bench, quick: bool, out: Path) -> list[str]:
    """The command line of one benchmark ([] under --quick when it has no smoke setting)."""
    options = bench.quick if quick else bench.full
    if options is None:
        return []
    args = [a.replace("{out}", str(out)) for a in options]
    if bench.out:
        stem = f"{bench.name}_quick" if quick else bench.name
        args += [bench.out, str(out / f"{stem}.json")]
    return [sys.executable, str(HERE / f"{bench.name}.py"), *args]


def plan(quick: bool, only: set[str] | None, out: Path) -> list[tuple[Bench, list[str], str]]:
    """(benchmark, command, reason it is skipped or '') for every benchmark."""
    rows = []
    for bench in BENCHES:
        if only and bench.name not in only:
            continue
        if not (HERE / f"{bench.name}.py").exists():
            rows.append((bench, [], f"benchmarks/{bench.name}.py is not in this checkout"))
        elif bench.gate:
            rows.append((bench, [], f"a gate, not a benchmark: {bench.gate}"))
        elif reason := missing(bench.needs):
            rows.append((bench, [], f"skipped: {reason}"))
        elif not (cmd := command(bench, quick, out)):
            rows.append((bench, [], "skipped with --quick: no smoke setting (full runs only)"))
        else:
            rows.append((bench, cmd, ""))
    return rows


def shown(cmd: list[str]) -> str:
    """A command as a person would type it from the repository root."""
    parts = [os.path.relpath(c, REPO) if c.startswith(str(REPO)) else c for c in cmd]
    parts[0] = ".venv/bin/python" if ".venv" in cmd[0] else "python"
    return " ".join(parts)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="each script's smoke setting")
    parser.add_argument("--list", action="store_true", help="print the plan and stop")
    parser.add_argument("--only", help="comma-separated benchmark names")
    parser.add_argument("--out", type=Path, default=REPO / "results" / "bench")
    args = parser.parse_args()
    only = set(args.only.split(",")) if args.only else None
    if only and (unknown := only - {b.name for b in BENCHES}):
        parser.error(f"unknown benchmark(s): {', '.join(sorted(unknown))}")
    out = args.out.resolve()
    rows = plan(args.quick, only, out)
    if args.list:
        for bench, cmd, reason in rows:
            print(f"{bench.name:24s} {shown(cmd) if cmd else reason}")
        return 0
    out.mkdir(parents=True, exist_ok=True)
    started = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    load = os.getloadavg()
    table, failed = [], 0
    for bench, cmd, reason in rows:
        if not cmd:
            table.append((bench.name, bench.what, "-", reason, "-", "-"))
            continue
        print(f"== {bench.name}: {shown(cmd)}", flush=True)
        log = out / f"{bench.name}.log"
        t0 = time.perf_counter()
        with log.open("w") as sink:
            done = subprocess.run(cmd, cwd=REPO, stdout=sink, stderr=subprocess.STDOUT,
                                  stdin=subprocess.DEVNULL)
        wall = time.perf_counter() - t0
        for name in bench.fixed:  # scripts that write to benchmarks/results only
            stem = Path(name)
            src = HERE / "results" / (f"{stem.stem}_quick{stem.suffix}" if args.quick
                                       else name)
            if src.exists() and src.stat().st_mtime >= time.time() - wall - 1:
                shutil.copy2(src, out / src.name)
        status = "ok" if done.returncode == 0 else f"failed (exit {done.returncode})"
        failed += done.returncode != 0
        files = sorted(p.name for p in out.iterdir()
                       if p.name.startswith(bench.name) and p.suffix in (".json", ".md"))
        table.append((bench.name, bench.what, f"`{shown(cmd)}`", status, f"{wall:.1f}",
                      ", ".join(files + [log.name])))
        print(f"   {status} in {wall:.1f} s", flush=True)
    lines = [f"# Benchmark report ({'quick' if args.quick else 'full'})", "",
             f"Started {started}; load average {[round(x, 2) for x in load]} before, "
             f"{[round(x, 2) for x in os.getloadavg()]} after; {os.cpu_count()} CPUs; "
             f"Python {sys.version.split()[0]}. Figures: the files named below (and "
             "benchmarks/README.md for what each measures).", "",
             "| benchmark | what it measures | command | status | wall s | files |",
             "|---|---|---|---|---|---|"]
    lines += ["| " + " | ".join(row) + " |" for row in table]
    (out / "report.md").write_text("\n".join(lines) + "\n")
    print(f"report: {out / 'report.md'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
