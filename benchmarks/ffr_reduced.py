#!/usr/bin/env python
"""Modal reduction of the FFR luffing boom (ancfdrv.solvers.ffr_reduced; issue 23, item 2):
error and time against the number of kept modes.

``inputs/boom_luffing.nml`` (28 nodes, 10 s, dt = 1 ms), m = 0 and 50 kg, bending
'continuum' and 'cubic', P-delta off / on. For each: the kernel's full FFR run (static start
by Newton), its reduced model with 1, 2, 4, 8 modes plus the static corrections (Fortran
stepper, best of 5 timed ``simulate`` calls; the reduction itself is timed once; the whole
``ancf run --set beam.modes=N`` dynamic solve, stepping plus its output rows, /dynamic
wall_time_s, best of --run-repeats (3), without XDMF), errors as
max |sag - sag_ref| in % of the reference's sag range against the full FFR run and against
the converged large-deformation model (28 'cubic' nodes, benchmarks/ffr_pdelta.py). The
machine's load is not controlled: the load average is printed with the times.

    .venv/bin/python benchmarks/ffr_reduced.py -o benchmarks/results/ffr_reduced.json
"""
from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.runner import run_scene
from ancfdrv.solvers.ffr_reduced import reduce_ffr, simulate
from ancfdrv.solvers.static import solve_newton

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "inputs" / "boom_luffing.nml"


def sag_of(path: Path) -> tuple[np.ndarray, np.ndarray, float]:
    with h5py.File(path) as h5:
        return (h5["dynamic/time"][()], h5["dynamic/deflection/tip"][()][:, 1],
                float(h5["dynamic"].attrs["wall_time_s"]))


def reduced_run(work: Path, over: list[str], modes: int, repeats: int) -> dict[str, float]:
    """The reduced run through the scene path: /dynamic wall_time_s (the dynamic solve with
    its output rows) and its stepping / output split (/timing), best of ``repeats``."""
    best: dict[str, float] = {}
    for _ in range(repeats):
        path = work / "reduced.h5"
        run_scene(SCENE, over + [f"beam.modes={modes}"], path, progress=False)
        with h5py.File(path) as h5:
            row = {"run_dynamic_ms": 1e3 * float(h5["dynamic"].attrs["wall_time_s"]),
                   "run_stepping_ms": 1e3 * float(h5["timing"].attrs["dynamic_stepping"]),
                   "run_output_ms": 1e3 * float(h5["timing"].attrs["dynamic_output"])}
        if not best or row["run_dynamic_ms"] < best["run_dynamic_ms"]:
            best = row
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path)
    parser.add_argument("--modes", type=int, nargs="+", default=[1, 2, 4, 8])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--run-repeats", type=int, default=3,
                        help="whole scene-path runs per case (best kept; default 3)")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for mass in (0.0, 50.0):
            ref_path = work / "ref.h5"
            run_scene(SCENE, [f"loads.tip_mass={mass}", "scene.formulation=nonlinear",
                              "beam.bending=cubic", "solver.static_method=newton",
                              "output.xdmf=false"], ref_path, progress=False)
            t_ref, s_ref, _ = sag_of(ref_path)
            ref_range = float(np.ptp(s_ref))
            for bending in ("continuum", "cubic"):
                for pdelta in (False, True):
                    over = [f"loads.tip_mass={mass}", f"beam.bending={bending}",
                            f"beam.geometric_stiffness={str(pdelta).lower()}",
                            "solver.static_method=newton", "output.xdmf=false"]
                    full_path = work / "full.h5"
                    run_scene(SCENE, over, full_path, progress=False)
                    t_full, s_full, full_solve = sag_of(full_path)
                    full_range = float(np.ptp(s_full))
                    model = build_model(load_scene(SCENE, over))
                    static = solve_newton(model, tol=1e-12, max_iter=50)
                    label = f"m={mass:g} {bending}{' + P-delta' if pdelta else ''}"
                    full_vs_ref = float(np.max(np.abs(s_full - s_ref))) / ref_range
                    print(f"{label}: full FFR {100 * full_vs_ref:.3f}% of the reference's "
                          f"range, solve {full_solve * 1e3:.0f} ms", flush=True)
                    for modes in args.modes:
                        t0 = time.perf_counter()
                        reduced = reduce_ffr(model, static, modes)
                        reduce_s = time.perf_counter() - t0
                        best = np.inf
                        for _ in range(args.repeats):
                            out = simulate(reduced, float(t_full[-1]), 1e-3)
                            best = min(best, reduced.timing["simulate"])
                        sag = out["tip"][:, 1]
                        row = {"case": label, "modes": modes, "size": reduced.size,
                               "error_vs_full_percent": 100 * float(
                                   np.max(np.abs(sag - s_full))) / full_range,
                               "error_vs_reference_percent": 100 * float(
                                   np.max(np.abs(sag - s_ref))) / ref_range,
                               "simulate_ms": best * 1e3, "reduce_ms": reduce_s * 1e3,
                               "full_solve_ms": full_solve * 1e3,
                               "full_vs_reference_percent": 100 * full_vs_ref,
                               **reduced_run(work, over, modes, args.run_repeats),
                               "load_average": os.getloadavg()[0]}
                        rows.append(row)
                        print(f"  {modes:2d} modes (r = {reduced.size:2d}): "
                              f"{row['error_vs_full_percent']:.4f}% vs full, "
                              f"{row['error_vs_reference_percent']:.3f}% vs reference, "
                              f"simulate {row['simulate_ms']:.1f} ms, whole dynamic run "
                              f"{row['run_dynamic_ms']:.1f} ms (output "
                              f"{row['run_output_ms']:.1f} ms) (load "
                              f"{row['load_average']:.1f})", flush=True)
    if args.output:
        args.output.write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
