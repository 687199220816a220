#!/usr/bin/env python
"""The FFR boom's error against the converged large-deformation model, with and without the
geometric stiffness (P-delta) of `beam.geometric_stiffness` (issue 23, item 2).

The luffing boom ``inputs/boom_luffing.nml`` (10 s, dt = 1 ms) at m = 0 and 50 kg, 28 nodes,
in four FFR configurations: bending 'continuum' / 'cubic', P-delta off / on (on needs the
static start by Newton: ``solver.static_method=newton``). The reference is the
large-deformation model (``scene.formulation=nonlinear``, ``beam.bending=cubic``) at
``--reference-nodes`` (28; 40 differs from it by 6e-5 / 2e-4 of the sag range at m = 50 / 0,
printed with ``--check-reference``). Errors: max |sag - sag_ref| over the history (the
transverse tip deflection in the rotating frame, ``/dynamic/deflection/tip`` component y),
in % of the reference's sag range max - min (the measure of peer_harness.py). Each FFR run
is also judged against the large-deformation model with its own bending option on its own
mesh ('same mesh': what the FFR approximation and P-delta cost, apart from the mesh's error),
and ``--mesh-check N`` runs that model on N nodes too ('mesh error': how far the 28-node
mesh of each bending option is from a finer one). Also printed:
the solve time (``/dynamic`` wall_time_s; the machine's load is not controlled: compare
within one run), Newton corrections per step and factorizations. JSON to ``-o``.

    .venv/bin/python benchmarks/ffr_pdelta.py -o benchmarks/results/ffr_pdelta.json
"""
from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import h5py
import numpy as np

from ancfdrv.runner import run_scene

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "inputs" / "boom_luffing.nml"
CONFIGS = {
    "ffr continuum": [],
    "ffr continuum + P-delta": ["beam.geometric_stiffness=true", "solver.static_method=newton"],
    "ffr cubic": ["beam.bending=cubic"],
    "ffr cubic + P-delta": ["beam.bending=cubic", "beam.geometric_stiffness=true",
                            "solver.static_method=newton"],
}
REFERENCE = ["scene.formulation=nonlinear", "solver.static_method=newton", "beam.bending=cubic"]


def run(overrides: list[str], work: Path) -> dict:
    out = work / "run.h5"
    run_scene(SCENE, [*overrides, "output.xdmf=false"], out, progress=False)
    with h5py.File(out) as h5:
        a = h5["dynamic"].attrs
        return {"t": h5["dynamic/time"][()], "sag": h5["dynamic/deflection/tip"][()][:, 1],
                "solve_s": float(a["wall_time_s"]),
                "corrections_per_step": float(a["newton_iterations"]) / float(a["steps"]),
                "factorizations": int(a["factorizations"])}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path)
    parser.add_argument("--nodes", type=int, default=28)
    parser.add_argument("--reference-nodes", type=int, default=28)
    parser.add_argument("--check-reference", type=int, default=0,
                        help="also run the reference at this many nodes and print the gap")
    parser.add_argument("--t-end", type=float, default=None)
    parser.add_argument("--mesh-check", type=int, default=0,
                        help="also run the large-deformation model of each bending option on "
                             "this many nodes and print its gap to the --nodes mesh")
    args = parser.parse_args()
    common = [f"beam.nodes={args.nodes}"]  # solver.t_end, when given, is in every run's base
    record: dict = {"scene": str(SCENE.relative_to(REPO)), "nodes": args.nodes,
                    "reference": f"nonlinear cubic {args.reference_nodes} nodes", "cases": []}
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for mass in (0.0, 50.0):
            base = [f"loads.tip_mass={mass}"] + ([f"solver.t_end={args.t_end}"] if args.t_end
                                                else [])
            ref = run([*base, *REFERENCE, f"beam.nodes={args.reference_nodes}"], work)
            sag_range = float(np.ptp(ref["sag"]))
            case = {"tip_mass": mass, "sag_range_m": sag_range, "runs": {}}
            if args.check_reference:
                fine = run([*base, *REFERENCE, f"beam.nodes={args.check_reference}"], work)
                gap = float(np.max(np.abs(np.interp(fine["t"], ref["t"], ref["sag"])
                                          - fine["sag"])))
                case["reference_gap_percent"] = 100.0 * gap / sag_range
                print(f"m = {mass:g}: reference {args.reference_nodes} vs "
                      f"{args.check_reference} nodes: {case['reference_gap_percent']:.4f}%")
            same: dict[str, dict] = {}
            for bending in ("continuum", "cubic"):
                nonlinear = ["scene.formulation=nonlinear", "solver.static_method=newton",
                             f"beam.bending={bending}"]
                same[bending] = run([*base, *common, *nonlinear], work)
                if args.mesh_check:
                    fine = run([*base, *nonlinear, f"beam.nodes={args.mesh_check}"], work)
                    gap = float(np.max(np.abs(np.interp(fine["t"], same[bending]["t"],
                                                        same[bending]["sag"]) - fine["sag"])))
                    case.setdefault("mesh_error_percent", {})[bending] = \
                        100.0 * gap / float(np.ptp(fine["sag"]))
                    print(f"m = {mass:g}: nonlinear {bending} {args.nodes} vs {args.mesh_check} "
                          f"nodes: {case['mesh_error_percent'][bending]:.4f}%")
            for label, overrides in CONFIGS.items():
                r = run([*base, *common, *overrides], work)
                err = float(np.max(np.abs(np.interp(ref["t"], r["t"], r["sag"]) - ref["sag"])))
                own = same["cubic" if "cubic" in label else "continuum"]
                err_same = float(np.max(np.abs(np.interp(own["t"], r["t"], r["sag"])
                                               - own["sag"])))
                row = {"error_m": err, "error_percent": 100.0 * err / sag_range,
                       "error_same_mesh_percent": 100.0 * err_same / float(np.ptp(own["sag"])),
                       **{k: r[k] for k in ("solve_s", "corrections_per_step",
                                            "factorizations")}}
                case["runs"][label] = row
                print(f"m = {mass:4g} kg  {label:26s} error {row['error_percent']:7.3f}% of "
                      f"{sag_range:.4f} m, {row['error_same_mesh_percent']:6.3f}% against the "
                      f"same element and mesh   solve {row['solve_s']:.3f} s   "
                      f"{row['corrections_per_step']:.2f} corrections/step", flush=True)
            record["cases"].append(case)
    if args.output:
        args.output.write_text(json.dumps(record, indent=1) + "\n")


if __name__ == "__main__":
    main()
