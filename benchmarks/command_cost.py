#!/usr/bin/env python
"""What a small ``ancf`` command costs beyond its computing (issue 38, "Where the time
goes"): the interpreter's start with the package's imports, and a run's XDMF description.

Cold commands, each a new process (``python -S``, the package found through PYTHONPATH as
an installed package would be: an editable install's loader checks the build with ninja
on every start and would be measured instead):

* ``baseline``: ``python -c 'import numpy, h5py'``, the floor any command pays;
* ``help``: ``ancf --help``; ``run_help``: ``ancf run --help``;
* ``run``: ``ancf run`` of the luffing boom (4 nodes, dt 2e-3, 10 s: 5000 steps, the
  default 250 XDMF frames) into a temporary directory.

Warm calls, in one process per copy after a warm-up call: ``ancfdrv.runner.run_scene`` of
the same boom with ``output.xdmf`` on and off (the difference is what the XDMF description
costs: its per-frame HDF5 views and its XML), and the stepping's share of the call.

Per command the best of ``--repeats`` wall times and the best child CPU time (user + system,
from ``os.wait4``: less sensitive to other processes on a shared machine than wall time).
``--compare DIR`` measures another copy of the package too (a directory holding
``ancfdrv/`` with the built ``_kernel*.so`` copied in, e.g. ``git archive <commit>
python/ancfdrv`` unpacked), interleaved command by command with this one (``--this DIR``:
this copy from a directory as well; default: the package this interpreter imports). A copy
in a directory is byte-compiled first (``compileall``), as an installed wheel is: where
PYTHONDONTWRITEBYTECODE is set (this workplace sets it) an uncompiled package is compiled
from source on every start, ~0.2 s of CPU for ancfdrv alone. The machine's load average is
recorded before and after.

Output: ``benchmarks/results/command_cost.json``. Run from the repository root::

    python benchmarks/command_cost.py --this /tmp/new --compare /tmp/old   # ~2 minutes
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import sysconfig
import tempfile
import textwrap
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
SCENE = "inputs/boom_luffing.nml"
SETS = ["beam.nodes=4", "solver.dt=2e-3"]
COLD = {
    "baseline": ["-c", "import numpy, h5py"],
    "help": ["-m", "ancfdrv.cli", "--help"],
    "run_help": ["-m", "ancfdrv.cli", "run", "--help"],
    "run": ["-m", "ancfdrv.cli", "run", SCENE, "-o", "{out}",
            *[a for s in SETS for a in ("--set", s)]],
}
WARM = textwrap.dedent("""
    import json, os, sys, tempfile, time
    from ancfdrv import kernel, runner
    scene, sets, repeats = sys.argv[1], json.loads(sys.argv[2]), int(sys.argv[3])
    stepping = []   # the kernel's stepping (advance_rows) per call
    original = kernel.KernelSystem.advance_rows
    def timed(self, *args, **kwargs):
        t = time.perf_counter()
        try:
            return original(self, *args, **kwargs)
        finally:
            stepping[-1] += time.perf_counter() - t
    kernel.KernelSystem.advance_rows = timed
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for label, extra in (("xdmf", []), ("no_xdmf", ["output.xdmf=.false."])):
            stepping.append(0.0)
            runner.run_scene(scene, sets + extra, os.path.join(tmp, "warm.h5"),
                             progress=False)
            best = None
            for i in range(repeats):
                stepping.append(0.0)
                w, c = time.perf_counter(), time.thread_time()
                runner.run_scene(scene, sets + extra, os.path.join(tmp, f"{label}{i}.h5"),
                                 progress=False)
                row = (time.perf_counter() - w, time.thread_time() - c, stepping[-1])
                best = row if best is None or row[0] < best[0] else best
            out[label] = dict(zip(("wall_s", "thread_cpu_s", "stepping_s"), best))
    print(json.dumps(out))
""")


def _env(copy: str | None) -> dict[str, str]:
    env = dict(os.environ)
    if copy is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(Path(copy).resolve()),
                                             sysconfig.get_paths()["purelib"],
                                             sysconfig.get_paths()["platlib"]])
    return env


def _cold(copy: str | None, args: list[str], out_dir: str) -> tuple[float, float]:
    """(wall s, child CPU s) of one command in a new process."""
    flags = ["-S"] if copy is not None else []
    command = [sys.executable, *flags, *[a.format(out=os.path.join(out_dir, "cold.h5"))
                                         for a in args]]
    start = time.perf_counter()
    proc = subprocess.Popen(command, cwd=REPO, env=_env(copy), stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"{command} exited {proc.returncode}: "
                           f"{proc.stderr.read().decode()[-2000:]}")
    proc.stderr.close()
    return wall, usage.ru_utime + usage.ru_stime


def _warm(copy: str | None, repeats: int) -> dict[str, Any]:
    flags = ["-S"] if copy is not None else []
    done = subprocess.run([sys.executable, *flags, "-c", WARM, SCENE, json.dumps(SETS),
                           str(repeats)], cwd=REPO, env=_env(copy), capture_output=True,
                          text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(done.stderr[-2000:])
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--this", help="directory holding this copy of the package")
    parser.add_argument("--compare", help="directory holding another copy of the package")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    copies = {"this": args.this, **({"compared": args.compare} if args.compare else {})}
    for where in copies.values():
        if where is not None:
            subprocess.run([sys.executable, "-m", "compileall", "-q", str(where)], check=True)
    result: dict[str, Any] = {"load_before": os.getloadavg(), "repeats": args.repeats,
                              "cpus": os.cpu_count(), "scene": SCENE, "sets": SETS,
                              "copies": copies}
    cold: dict[str, dict[str, list[tuple[float, float]]]] = {c: {k: [] for k in COLD}
                                                              for c in copies}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.repeats):
            for name, command in COLD.items():
                for copy, where in copies.items():   # interleaved: the same load for both
                    cold[copy][name].append(_cold(where, command, tmp))
    result["cold"] = {copy: {name: {"wall_s": min(w for w, _ in rows),
                                    "cpu_s": min(c for _, c in rows)}
                             for name, rows in by_name.items()}
                      for copy, by_name in cold.items()}
    result["warm"] = {copy: _warm(where, args.repeats) for copy, where in copies.items()}
    result["load_after"] = os.getloadavg()
    out = REPO / "benchmarks" / "results" / "command_cost.json"
    out.parent.mkdir(exist_ok=True)
    out.write_text(json.dumps(result, indent=2) + "\n")
    print(f"load average {result['load_before'][0]:.1f} -> {result['load_after'][0]:.1f} "
          f"on {result['cpus']} cpus; best of {args.repeats}, ms (wall / CPU)")
    print(f"{'':12s}" + "".join(f"{copy:>22s}" for copy in copies))
    for name in COLD:
        print(f"{name:12s}" + "".join(
            f"{1e3 * result['cold'][c][name]['wall_s']:11.0f} /{1e3 * result['cold'][c][name]['cpu_s']:6.0f}    "
            for c in copies))
    for label in ("xdmf", "no_xdmf"):
        print(f"warm {label:7s}" + "".join(
            f"{1e3 * result['warm'][c][label]['wall_s']:11.0f} /"
            f"{1e3 * result['warm'][c][label]['thread_cpu_s']:6.0f}    " for c in copies))
    for c in copies:
        w = result["warm"][c]
        print(f"{c}: XDMF {1e3 * (w['xdmf']['thread_cpu_s'] - w['no_xdmf']['thread_cpu_s']):.0f}"
              f" ms CPU; stepping {1e3 * w['xdmf']['stepping_s']:.0f} ms of "
              f"{1e3 * w['xdmf']['wall_s']:.0f} ms")
    print(f"-> {out.relative_to(REPO)}")


if __name__ == "__main__":
    main()
