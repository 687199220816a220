#!/usr/bin/env python
"""What a small ``ancf`` command costs beyond its computing (issue 38 item 2, "small calls
cost what they compute"): the interpreter's start with the package's imports, the run's
fixed cost outside the stepping, and the same from the shell against the peer's script.

Every copy of the package is measured as a user has it after ``pip install .`` /
``make install``: a copy of the package (its Python files, the built ``_kernel*.so`` and
the build's record ``_build_info.py``) in a temporary directory, byte-compiled
(``compileall``), run with ``python -S`` and PYTHONPATH (the copy, then this venv's
site-packages). Not an editable install: its loader runs ninja on every start, and where
PYTHONDONTWRITEBYTECODE is set (this workplace) an uncompiled package is compiled from
source on every start (~0.2 s of CPU for ancfdrv alone). The commands run as the ``ancf``
console script does (``from ancfdrv.cli import main; sys.exit(main())``).

Cold commands, each a new process, interleaved command by command and copy by copy:

* ``baseline``: ``python -c 'import numpy, h5py'``, the floor any command pays;
* ``help``: ``ancf --help``; ``run_help``: ``ancf run --help``;
* ``run``: ``ancf run`` of the luffing boom (4 nodes, dt 2e-3, 10 s: 5000 steps, the
  default 250 XDMF frames);
* ``boom_matched``: issue 38's accuracy-matched boom (nonlinear planar cable, 7 nodes,
  dt 2e-3, Newton statics, no XDMF, m = 50 kg: 0.011 % of the sag range, the peer
  harness's level table), ``ancf run ... --set ...`` as a user types it;
* ``exudyn_matched`` (when Exudyn imports): the peer's script at the same accuracy
  (``peer_harness.EXUDYN_SCRIPT``: Exudyn's ``ANCFCable2D``, 6 elements, dt 2e-3,
  tolerances 1e-2 / 1e-5, dense LU; 0.014 %), its modules byte-compiled as well.

Warm calls, in one process per copy after warm-up calls: ``ancfdrv.runner.run_scene`` of
the 5000-step boom with ``output.xdmf`` on and off (the difference is what the XDMF
description costs), and the phase split of the peer harness's 3 % pick (cable, 4 nodes,
dt 2e-2, 500 steps) and of the matched boom: per phase the median thread CPU time
(``time.thread_time``) of ``--repeats`` calls, each interval counted to the innermost
phase running (``fixed_cost.PHASES``, grouped: scene, model, static solve, answers,
HDF5, stepping, the rest "glue": output path and lock checks, initial acceleration,
stepper set-up, plausibility checks, stage summary), and the whole call's best.

Per cold command the best of ``--repeats`` wall times and the best child CPU time (user +
system, from ``os.wait4``: less sensitive to other processes on a shared machine). The
copies: ``--this DIR`` (default: a copy of this checkout's package with the kernel this
interpreter imports), ``--compare DIR`` (a directory holding ``ancfdrv/``) or
``--compare-commit SHA`` (``git archive SHA python/ancfdrv`` with this build's kernel: only
when ``fortran/`` is unchanged since SHA). The machine's load average is recorded before
and after.

``--instructions``: also the instructions of the baseline and the matched boom per copy
and of the peer's script, each one cold command under valgrind's callgrind with every
process it starts (exact: the figure a loaded machine cannot distort).

Output: ``benchmarks/results/command_cost.json`` and ``.md`` (the table, also printed).
Run from the repository root::

    python benchmarks/command_cost.py --compare-commit 79ddcfa   # ~1 minute
    python benchmarks/command_cost.py --compare-commit 79ddcfa --repeats 9 --instructions
"""
from __future__ import annotations

import argparse
import datetime as _dt
import importlib.util
import json
import os
import shutil
import statistics
import subprocess
import sys
import sysconfig
import tempfile
import textwrap
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
SCENE = "inputs/boom_luffing.nml"
SETS = ["beam.nodes=4", "solver.dt=2e-3"]
#: the peer harness's level configurations (``peer_harness.CABLE`` and its m = 50 kg base)
CABLE = ["loads.tip_mass=50.0", "scene.formulation=nonlinear", "solver.static_method=newton",
         "output.xdmf=.false.", "beam.bending=cable", "scene.planar=xy"]
#: issue 38's accuracy-matched boom (0.011 % of the sag range) and the 3 % pick
MATCHED = CABLE + ["beam.nodes=7", "solver.dt=0.002"]
LEVEL_PICK = CABLE + ["beam.nodes=4", "solver.dt=0.02"]
#: the ``ancf`` console script's code
ENTRY = "import sys; from ancfdrv.cli import main; sys.exit(main())"


def _sets(sets: list[str]) -> list[str]:
    return [a for s in sets for a in ("--set", s)]


COLD = {
    "baseline": ["-c", "import numpy, h5py"],
    "help": ["-c", ENTRY, "--help"],
    "run_help": ["-c", ENTRY, "run", "--help"],
    "run": ["-c", ENTRY, "run", SCENE, "-o", "{out}", *_sets(SETS)],
    "boom_matched": ["-c", ENTRY, "run", SCENE, *_sets(MATCHED), "-o", "{out}"],
}
#: phase groups of the warm split (``fixed_cost.PHASES`` labels -> group)
GROUPS = {"scene": "scene", "model": "model", "static solve": "static solve",
          "answers": "answers", "stepping": "stepping"}
WARM = textwrap.dedent("""
    import json, os, statistics, sys, tempfile, time
    sys.path.insert(0, sys.argv[5])   # benchmarks/: fixed_cost's phase table
    from fixed_cost import instrument   # the phase table and its wrappers
    from ancfdrv import runner
    scene, repeats = sys.argv[1], int(sys.argv[4])
    sets, cases = json.loads(sys.argv[2]), json.loads(sys.argv[3])
    groups = json.loads(sys.argv[6])
    spent, stack = {}, ["glue"]
    mark = [time.thread_time()]
    def switch(label):
        now = time.thread_time()
        spent[stack[-1]] = spent.get(stack[-1], 0.0) + now - mark[0]
        mark[0] = now
    def enter(label):
        switch(label)
        stack.append(label)
    def leave():
        switch(None)
        stack.pop()
    def group(label):
        head = label.split(":")[0]
        return groups.get(head, "HDF5" if head.startswith("HDF5") else "glue")
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for label, extra in (("xdmf", []), ("no_xdmf", ["output.xdmf=.false."])):
            runner.run_scene(scene, sets + extra, os.path.join(tmp, "warm.h5"), progress=False)
            best = None
            for i in range(repeats):
                w, c = time.perf_counter(), time.thread_time()
                runner.run_scene(scene, sets + extra, os.path.join(tmp, f"{label}{i}.h5"),
                                 progress=False)
                row = (time.perf_counter() - w, time.thread_time() - c)
                best = row if best is None or row[0] < best[0] else best
            out[label] = dict(zip(("wall_s", "thread_cpu_s"), best))
        instrument(enter, leave, group)
        for case, case_sets in cases.items():
            rows, walls = [], []
            for i in range(repeats + 2):   # two warm-up calls
                spent.clear()
                mark[0] = time.thread_time()
                w = time.perf_counter()
                runner.run_scene(scene, case_sets, os.path.join(tmp, f"{case}{i}.h5"),
                                 progress=False)
                walls.append(time.perf_counter() - w)
                switch(None)
                rows.append(dict(spent))
            rows, walls = rows[2:], walls[2:]
            names = sorted({k for r in rows for k in r})
            phases = {k: statistics.median(r.get(k, 0.0) for r in rows) for k in names}
            out[case] = {"wall_best_s": min(walls),
                         "thread_cpu_median_s": statistics.median(sum(r.values()) for r in rows),
                         "phases_median_s": phases}
    print(json.dumps(out))
""")


def installed_copy(dest: Path, commit: str | None = None) -> Path:
    """``dest/ancfdrv``: the package as ``pip install .`` leaves it (Python files, the built
    kernel, the build's record ``_build_info.py``), byte-compiled; from the package this
    interpreter imports (an editable install: its sources and its build directory), or
    ``git archive commit python/ancfdrv`` with this build's kernel (refused when
    ``fortran/`` changed since). Returns ``dest``."""
    import ancfdrv   # (light: its names load on first use)
    package = Path(ancfdrv.__file__).resolve().parent
    kernel = importlib.util.find_spec("ancfdrv._kernel")
    built = [Path(kernel.origin)]
    record = Path(kernel.origin).parent / "_build_info.py"
    if record.is_file():
        built.append(record)
    target = dest / "ancfdrv"
    if commit is None:
        shutil.copytree(package, target, ignore=shutil.ignore_patterns("__pycache__"))
    else:
        changed = subprocess.run(["git", "diff", "--quiet", commit, "--", "fortran"], cwd=REPO)
        if changed.returncode != 0:
            raise SystemExit(f"fortran/ changed since {commit}: its kernel must be built "
                             "(use --compare DIR with that build's package)")
        dest.mkdir(parents=True, exist_ok=True)
        archive = subprocess.run(["git", "archive", commit, "python/ancfdrv"], cwd=REPO,
                                 check=True, capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", str(dest), "--strip-components=1"], input=archive,
                       check=True)
    for path in built:
        if not (target / path.name).exists():
            shutil.copy2(path, target / path.name)
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(dest)], check=True)
    return dest


def installed_env(copy: str | Path | None) -> dict[str, str]:
    """The environment of a command run from ``copy`` (PYTHONPATH: the copy, then this
    interpreter's site-packages), to be started with ``python -S``."""
    env = dict(os.environ)
    if copy is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(Path(copy).resolve()),
                                             sysconfig.get_paths()["purelib"],
                                             sysconfig.get_paths()["platlib"]])
    return env


def exudyn_command(dest: Path) -> list[str] | None:
    """The peer's script for the matched boom, from a byte-compiled copy of the harness's
    modules in ``dest`` (None when Exudyn does not import)."""
    sys.path.insert(0, str(REPO / "benchmarks"))
    import peer_harness as p
    exu, _ = p.import_exudyn(fast=True)
    if exu is None:
        return None
    dest.mkdir(parents=True, exist_ok=True)
    for name in ("peer_harness.py", "_peer.py"):
        shutil.copy2(REPO / "benchmarks" / name, dest / name)
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(dest)], check=True)
    base = ["loads.tip_mass=50.0"]
    boom = p.boom_from_scene(SCENE, base)
    config = p.LevelConfig("exudyn", per_segment=2, dt=0.002, newton=p.BOOM_NEWTON, dense=True)
    spec = json.dumps({"boom": p.asdict(p.replace(boom, dt=config.dt)),
                       "config": p.asdict(config)})
    return ["-c", p.EXUDYN_SCRIPT.format(bench=str(dest)), spec]


def _cold(copy: str | Path | None, args: list[str], out_dir: str) -> tuple[float, float]:
    """(wall s, child CPU s) of one command in a new process."""
    command = [sys.executable, "-S", *[a.replace("{out}", os.path.join(out_dir, "cold.h5"))
                                       for a in args]]
    start = time.perf_counter()
    proc = subprocess.Popen(command, cwd=REPO, env=installed_env(copy),
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"{command} exited {proc.returncode}: "
                           f"{proc.stderr.read().decode()[-2000:]}")
    proc.stderr.close()
    return wall, usage.ru_utime + usage.ru_stime


def _instructions(copy: str | Path, args: list[str], out_dir: str) -> int:
    """The instructions one cold command executes, with every process it starts
    (valgrind's callgrind, ``--trace-children``): exact and independent of the load."""
    with tempfile.TemporaryDirectory() as counts:
        command = ["valgrind", "--tool=callgrind", "--trace-children=yes",
                   f"--callgrind-out-file={counts}/cg.%p", sys.executable, "-S",
                   *[a.replace("{out}", os.path.join(out_dir, "counted.h5")) for a in args]]
        subprocess.run(command, cwd=REPO, env=installed_env(copy), check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        total = 0
        for path in Path(counts).glob("cg.*"):
            for line in path.read_text(errors="replace").splitlines():
                if line.startswith("summary:"):
                    total += int(line.split()[1])
        return total


def _warm(copy: str | Path, repeats: int) -> dict[str, Any]:
    done = subprocess.run([sys.executable, "-S", "-c", WARM, SCENE, json.dumps(SETS),
                           json.dumps({"level_pick": LEVEL_PICK, "boom_matched": MATCHED}),
                           str(repeats), str(REPO / "benchmarks"), json.dumps(GROUPS)],
                          cwd=REPO, env=installed_env(copy), capture_output=True, text=True,
                          check=False)
    if done.returncode != 0:
        raise RuntimeError(done.stderr[-2000:])
    return json.loads(done.stdout.strip().splitlines()[-1])


PHASE_ORDER = ("scene", "model", "static solve", "answers", "HDF5", "stepping", "glue")


def markdown(result: dict[str, Any]) -> list[str]:
    """The tables of a result (also printed)."""
    copies = list(result["copies"])
    load = result["load_before"], result["load_after"]
    out = [f"# A command's cost beyond its computing ({result['date']})", "",
           f"Load average (1, 5, 15 min) {', '.join(f'{x:.2f}' for x in load[0])} before, "
           f"{', '.join(f'{x:.2f}' for x in load[1])} after, on {result['cpus']} CPUs; "
           f"each copy installed and byte-compiled, run with `python -S` "
           f"(copies: {', '.join(f'{c}: {w}' for c, w in result['copies'].items())}); "
           f"best of {result['repeats']} interleaved, ms wall / CPU (user + system).", "",
           "| command | " + " | ".join(copies) + " |", "|---|" + "---|" * len(copies)]
    for name in result["cold"][copies[0]]:
        out.append(f"| {name} | " + " | ".join(
            f"{1e3 * result['cold'][c][name]['wall_s']:.0f} / "
            f"{1e3 * result['cold'][c][name]['cpu_s']:.0f}" for c in copies) + " |")
    if result.get("exudyn"):
        e = result["exudyn"]
        out.append(f"| exudyn_matched (the peer's script) | {1e3 * e['wall_s']:.0f} / "
                   f"{1e3 * e['cpu_s']:.0f} |" + " |" * (len(copies) - 1))
    if result.get("instructions"):
        counted = result["instructions"]
        out += ["", "Instructions of one cold command with every process it starts "
                "(callgrind, exact, independent of the load), millions:", "",
                "| command | " + " | ".join(counted) + " |", "|---|" + "---|" * len(counted)]
        names = sorted({n for c in counted.values() for n in c})
        for name in names:
            out.append(f"| {name} | " + " | ".join(
                f"{c[name] / 1e6:.0f}" if name in c else "" for c in counted.values()) + " |")
    out += ["", "Warm calls (one process per copy, after warm-up calls): the 5000-step boom "
            "with and without XDMF (best wall / its thread CPU, ms), and the phase split "
            "(median thread CPU per phase, ms; 'whole' the best wall time).", "",
            "| warm | " + " | ".join(copies) + " |", "|---|" + "---|" * len(copies)]
    for label in ("xdmf", "no_xdmf"):
        out.append(f"| boom 5000 steps, {label} | " + " | ".join(
            f"{1e3 * result['warm'][c][label]['wall_s']:.0f} / "
            f"{1e3 * result['warm'][c][label]['thread_cpu_s']:.0f}" for c in copies) + " |")
    for case in ("level_pick", "boom_matched"):
        out.append(f"| **{case}**: whole (best wall) | " + " | ".join(
            f"{1e3 * result['warm'][c][case]['wall_best_s']:.2f}" for c in copies) + " |")
        names = [p for p in PHASE_ORDER if any(
            p in result["warm"][c][case]["phases_median_s"] for c in copies)]
        for phase in names:
            out.append(f"| {case}: {phase} | " + " | ".join(
                f"{1e3 * result['warm'][c][case]['phases_median_s'].get(phase, 0.0):.2f}"
                for c in copies) + " |")
        out.append(f"| {case}: outside the stepping (thread CPU) | " + " | ".join(
            f"{1e3 * (result['warm'][c][case]['thread_cpu_median_s'] - result['warm'][c][case]['phases_median_s'].get('stepping', 0.0)):.2f}"
            for c in copies) + " |")
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument("--this", help="directory holding this copy of the package "
                        "(default: a copy of the package this interpreter imports)")
    parser.add_argument("--compare", help="directory holding another copy of the package")
    parser.add_argument("--compare-commit", help="the package of this commit (with this "
                        "build's kernel) as the other copy")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--instructions", action="store_true",
                        help="also count the instructions of the baseline and of the "
                        "matched boom (and the peer's script) under callgrind (~2 minutes)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        copies: dict[str, Path] = {
            "this": Path(args.this) if args.this else installed_copy(work / "this")}
        if args.compare:
            copies["compared"] = Path(args.compare)
        elif args.compare_commit:
            copies[f"compared ({args.compare_commit})"] = installed_copy(
                work / "compared", args.compare_commit)
        for where in copies.values():
            subprocess.run([sys.executable, "-m", "compileall", "-q", str(where)], check=True)
        exudyn = exudyn_command(work / "peer")
        result: dict[str, Any] = {
            "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            "load_before": os.getloadavg(), "repeats": args.repeats, "cpus": os.cpu_count(),
            "scene": SCENE, "sets": SETS, "matched": MATCHED, "level_pick": LEVEL_PICK,
            "copies": {c: (str(w) if args.this or args.compare else
                           ("this checkout" if c == "this" else c)) for c, w in copies.items()}}
        cold: dict[str, dict[str, list[tuple[float, float]]]] = {c: {k: [] for k in COLD}
                                                                  for c in copies}
        peer: list[tuple[float, float]] = []
        for _ in range(args.repeats):
            for name, command in COLD.items():
                for copy, where in copies.items():   # interleaved: the same load for both
                    cold[copy][name].append(_cold(where, command, tmp))
                if name == "boom_matched" and exudyn is not None:
                    peer.append(_cold(work / "peer", exudyn, tmp))
        result["cold"] = {copy: {name: {"wall_s": min(w for w, _ in rows),
                                        "cpu_s": min(c for _, c in rows)}
                                 for name, rows in by_name.items()}
                          for copy, by_name in cold.items()}
        result["exudyn"] = ({"wall_s": min(w for w, _ in peer), "cpu_s": min(c for _, c in peer)}
                            if peer else None)
        result["warm"] = {copy: _warm(where, args.repeats) for copy, where in copies.items()}
        if args.instructions:
            result["instructions"] = {
                copy: {name: _instructions(where, COLD[name], tmp)
                       for name in ("baseline", "boom_matched")}
                for copy, where in copies.items()}
            if exudyn is not None:
                result["instructions"]["exudyn"] = {
                    "exudyn_matched": _instructions(work / "peer", exudyn, tmp)}
    result["load_after"] = os.getloadavg()
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "command_cost.json").write_text(json.dumps(result, indent=2) + "\n")
    lines = markdown(result)
    (RESULTS / "command_cost.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    print(f"-> {(RESULTS / 'command_cost.json').relative_to(REPO)}, command_cost.md")


if __name__ == "__main__":
    main()
