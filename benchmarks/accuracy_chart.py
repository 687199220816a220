#!/usr/bin/env python
"""The README's accuracy/time (Pareto) chart of the luffing boom (issue 23, item 5): every
accuracy knob against one converged reference, from `ancf sweep` runs.

``inputs/boom_luffing.nml`` (10 s, dt = 1 ms, m = 50 kg, static start by Newton). The
reference: the large-deformation model, 'cubic' bending, 28 nodes (benchmarks/ffr_pdelta.py
and peer_harness.py use the same). Families, one ``ancf sweep`` each (run_sweep with
``reference=``, one worker so that the cases do not share the cores):

* FFR 'continuum' (the paper's element), beam.nodes = 4, 10, 16, 28
* FFR 'cubic', beam.nodes = 4, 7, 10, 16
* FFR 'cubic' + P-delta (beam.geometric_stiffness), beam.nodes = 4, 7, 10, 16
* FFR 'cubic' + P-delta, 10 nodes, modal reduction beam.modes = 1, 2, 4, 8 (0: full)
* nonlinear 'continuum', beam.nodes = 4, 10, 16
* nonlinear 'cubic', beam.nodes = 4, 7, 10, 16
* nonlinear 'cable' in the plane (scene.planar = 'xy'), beam.nodes = 4, 7, 10, 16

Error: max |sag(t) - sag_ref(t)| over the run / the reference's sag range (err vs
reference); time: the case's wall time (model, static, dynamics, output) and the dynamics
alone. The machine's load is not controlled: the load average is printed and written.

    .venv/bin/python benchmarks/accuracy_chart.py -o benchmarks/results/accuracy_chart
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
from pathlib import Path

from ancfdrv.plots import pareto_chart
from ancfdrv.runner import run_scene
from ancfdrv.sweep import run_sweep

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "inputs" / "boom_luffing.nml"
COMMON = ["loads.tip_mass=50", "solver.static_method=newton", "output.xdmf=false",
          "output.answers=false"]
FAMILIES = [
    ("FFR continuum", ["scene.formulation=ffr", "beam.bending=continuum"],
     "beam.nodes=4,10,16,28"),
    ("FFR cubic", ["scene.formulation=ffr", "beam.bending=cubic"], "beam.nodes=4,7,10,16"),
    ("FFR cubic + P-delta", ["scene.formulation=ffr", "beam.bending=cubic",
                             "beam.geometric_stiffness=true"], "beam.nodes=4,7,10,16"),
    ("FFR cubic + P-delta, 10 nodes, modes", ["scene.formulation=ffr", "beam.bending=cubic",
                                              "beam.geometric_stiffness=true", "beam.nodes=10"],
     "beam.modes=1,2,4,8,0"),
    ("nonlinear continuum", ["scene.formulation=nonlinear", "beam.bending=continuum"],
     "beam.nodes=4,10,16"),
    ("nonlinear cubic", ["scene.formulation=nonlinear", "beam.bending=cubic"],
     "beam.nodes=4,7,10,16"),
    ("nonlinear cable, planar xy", ["scene.formulation=nonlinear", "beam.bending=cable",
                                    "scene.planar=xy"], "beam.nodes=4,7,10,16"),
]


def draw(rows: list[dict], chart: Path) -> None:
    """The chart of the rows (the machine's load average over the runs in its title)."""
    loads = [r["load_average"] for r in rows]
    pareto_chart(rows, lambda r: r["family"],
                 lambda r: ("full" if r["knob"] == "beam.modes" and r["value"] == "0" else
                            f"{r['value']}{' m' if r['knob'] == 'beam.modes' else ''}"),
                 "err_vs_reference", chart, common_reference=True,
                 title="luffing boom, 10 s, 50 kg: error against the nonlinear cubic 28-node "
                       "model vs computing time per case\n(labels: nodes, or modes 'm'; 2-core "
                       f"machine at load average {min(loads):.1f}-{max(loads):.1f})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=REPO / "benchmarks" / "results"
                        / "accuracy_chart")
    parser.add_argument("--chart", type=Path, default=REPO / "docs" / "images"
                        / "boom_accuracy_vs_time.png")
    parser.add_argument("--keep", action="store_true", help="keep the sweeps' HDF5 files")
    args = parser.parse_args()
    work = args.output
    work.mkdir(parents=True, exist_ok=True)
    reference = work / "reference_nonlinear_cubic_28.h5"
    run_scene(SCENE, [*COMMON, "scene.formulation=nonlinear", "beam.bending=cubic",
                      "beam.nodes=28"], reference, progress=False)
    rows = []
    for i, (label, fixed, vary) in enumerate(FAMILIES):
        outdir = work / f"sweep_{i}"
        if outdir.exists():
            shutil.rmtree(outdir)
        for row in run_sweep(str(SCENE), [vary], outdir, base=[*COMMON, *fixed], workers=1,
                             progress=False, reference=reference):
            if row["status"] != "ok":
                print(f"{label}: {row['case']} {row['status']}: {row.get('message')}")
                continue
            key = vary.split("=")[0]
            rows.append({"family": label, "knob": key, "value": row[key],
                         "err_vs_reference": row["err_vs_reference"],
                         "total_time_s": row["total_time_s"],
                         "compute_time_s": row["compute_time_s"],
                         "dynamic_time_s": row["dynamic_time_s"],
                         "load_average": os.getloadavg()[0]})
            print(f"{label:38s} {key}={row[key]:>3s}: err {100 * row['err_vs_reference']:.4f}% "
                  f"case {row['total_time_s']:.3f} s, dynamics {row['dynamic_time_s']:.3f} s "
                  f"(load {os.getloadavg()[0]:.1f})", flush=True)
        if not args.keep:
            for h5 in outdir.glob("*.h5"):
                h5.unlink()
    (work / "rows.json").write_text(json.dumps(rows, indent=1) + "\n")
    args.chart.parent.mkdir(parents=True, exist_ok=True)
    draw(rows, args.chart)
    lines = ["| family | knob | error vs reference (% of sag range) | case time (s) | "
             "dynamics (s) |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['family']} | {r['knob']} = {r['value']} | "
                     f"{100 * r['err_vs_reference']:.4f} | {r['total_time_s']:.3f} | "
                     f"{r['dynamic_time_s']:.3f} |")
    (work / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
