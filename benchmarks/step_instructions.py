"""Instructions per time step of the kernel's stepping (callgrind; exact and independent of
the machine's load), with the Newton corrections per step, for the small systems of
issue 23 items 3-4: the luffing boom with the planar ANCF cable (4 and 7 nodes, 50 kg) and
the flexible pendulum with the planar cable (5 and 17 nodes, dt = 1e-3), and the peer
harness's levels in full (pend5full, pend9full, pend17full: the pendulum's 1 s; spin11: the W = 4
cable spin-up, 11 nodes, dt = 5e-3, 20 s).

    python benchmarks/step_instructions.py [--site DIR] [--cases boom4,pend5] [--output F]

Each case runs under ``valgrind --tool=callgrind --toggle-collect=system_advance_`` (only
the kernel's stepping calls are counted: no Python, no model build, no static solution,
no HDF5), shortened to 2 s (boom) and 0.5 s (pendulum); instructions per step = the
counted instructions / the steps taken. ``--site``: measure the ancfdrv installed in DIR
instead (PYTHONPATH; e.g. a baseline build, see history_gate.py). Results go to
results/step_instructions.json and .md (or --output, its .md beside). Needs valgrind;
about a minute per case."""
from __future__ import annotations

import argparse
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

REPO = Path(__file__).resolve().parents[1]
BOOM = ["inputs/boom_luffing.nml", "scene.formulation=nonlinear", "solver.static_method=newton",
        "output.xdmf=.false.", "beam.bending=cable", "scene.planar=xy", "solver.t_end=2.0"]
PENDULUM = ["inputs/hard/pendulum.nml", "beam.bending=cable", "scene.planar=xy",
            "solver.dt=1e-3", "output.xdmf=.false.", "solver.t_end=0.5"]
CASES = {
    "boom4": BOOM + ["beam.nodes=4", "loads.tip_mass=50"],
    "boom7": BOOM + ["beam.nodes=7", "loads.tip_mass=50"],
    "pend5": PENDULUM + ["beam.nodes=5"],
    "pend17": PENDULUM + ["beam.nodes=17"],
    # the peer harness's levels in full (issue 23: the pendulum 1 s, the spin-up W = 4 20 s)
    "pend5full": PENDULUM[:-1] + ["beam.nodes=5", "solver.t_end=1.0"],
    "pend9full": PENDULUM[:-1] + ["beam.nodes=9", "solver.t_end=1.0"],
    "pend17full": PENDULUM[:-1] + ["beam.nodes=17", "solver.t_end=1.0"],
    "spin11": ["inputs/hard/spinup.nml", "spinup.omega=4", "beam.bending=cable",
               "scene.planar=xy", "beam.nodes=11", "solver.dt=5e-3", "output.xdmf=.false."],
}
RUN = ("import sys; from ancfdrv.runner import run_scene; "
       "run_scene(sys.argv[1], sys.argv[3:], sys.argv[2], progress=False)")


def measure(name: str, site: str | None, work: Path) -> dict:
    scene, *sets = CASES[name]
    out, profile = work / f"{name}.h5", work / f"{name}.callgrind"
    env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    if site:
        env["PYTHONPATH"] = site
    subprocess.run(["valgrind", "--tool=callgrind", "--toggle-collect=system_advance_",
                    f"--callgrind-out-file={profile}", sys.executable, "-c", RUN, scene,
                    str(out), *sets], cwd=REPO, env=env, check=True, capture_output=True)
    totals = subprocess.run(["callgrind_annotate", str(profile)], capture_output=True,
                            text=True, check=True).stdout
    instructions = int(re.search(r"([\d,]+)\s+(?:\([^)]*\)\s+)?PROGRAM TOTALS", totals)
                       .group(1).replace(",", ""))
    with h5py.File(out) as h5:
        newton = h5["dynamic/newton_iterations"][()][1:]   # the first row: the initial state
        factorizations = int(h5["dynamic/factorizations"][()].sum())
    steps = len(newton)
    return {"case": name, "settings": CASES[name], "steps": steps,
            "instructions": instructions, "instructions_per_step": instructions / steps,
            "corrections_per_step": float(np.mean(newton)), "factorizations": factorizations}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--site", default=None, help="measure the ancfdrv installed in DIR")
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated cases")
    parser.add_argument("--output", default=str(REPO / "benchmarks/results/step_instructions.json"))
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.cases.split(","):
            rows.append(measure(name, args.site, Path(tmp)))
            print(f"{name}: {rows[-1]['instructions_per_step']:.0f} instructions per step, "
                  f"{rows[-1]['corrections_per_step']:.3f} Newton corrections per step",
                  flush=True)
    result = {"benchmark": "step_instructions", "site": args.site or "installed",
              "conditions": "valgrind callgrind, --toggle-collect=system_advance_ (the "
                            "kernel's stepping only), OMP_NUM_THREADS=1, "
                            f"{platform.machine()}, Python {platform.python_version()}",
              "cases": rows}
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps(result, indent=1) + "\n")
    lines = ["# Instructions per time step (callgrind)", "", result["conditions"], "",
             "| case | steps | instructions / step | Newton corrections / step | "
             "factorizations |", "|---|---|---|---|---|"]
    lines += [f"| {r['case']} | {r['steps']} | {r['instructions_per_step']:.0f} | "
              f"{r['corrections_per_step']:.3f} | {r['factorizations']} |" for r in rows]
    output.with_suffix(".md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
