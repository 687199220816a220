#!/usr/bin/env python
"""The luffing boom's error-against-time front over time step, mesh, Newton tolerance and
output (issue 38, item 7): where the shipped scene's settings sit, and each accuracy
level's fastest configuration across formulations.

``benchmarks/accuracy_chart.py`` varies the mesh and the element at dt = 1 ms against a
reference at the same step; this grid adds the time step, the Newton tolerance and the
output (XDMF, answers), and judges every run against references converged in space and
time:

* 'cubic': the large-deformation model, 'cubic' bending, 28 nodes, dt = 0.25 ms (the
  accuracy chart's model, shear deformation included);
* 'cable': the planar ANCF cable, 55 nodes, dt = 0.25 ms (peer_levels' common reference,
  Euler-Bernoulli; the two models differ by about 0.3 % of the sag range);
* 'ffr': the shipped scene itself at dt = 0.25 ms (the paper's FFR model, 28 continuum nodes:
  the time-step error alone of the shipped scene's dt).

Error: max |sag(t) - sag_ref(t)| at every 0.02 s in % of the reference's sag range (sag:
the tip's transverse deflection). Cost: CPU time (``time.process_time``) of the whole
``run_scene`` call writing the HDF5 file, best of ``--repeats``, so that a loaded machine
distorts it less than wall time; the counters (steps, Newton corrections,
factorizations) are written beside it.

    .venv/bin/python benchmarks/boom_front.py            # results/boom_front.{json,md}
"""
from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

from _common import load_average, machine_info
from ancfdrv.runner import run_scene

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "inputs" / "boom_luffing.nml"
BASE = ["loads.tip_mass=50"]
FFR = ["scene.formulation=ffr"]
CABLE = ["scene.formulation=nonlinear", "solver.static_method=newton",
         "beam.bending=cable", "scene.planar=xy"]
CUBIC = ["scene.formulation=nonlinear", "solver.static_method=newton", "beam.bending=cubic",
         "scene.planar=xy"]
PDELTA_MODES = ["scene.formulation=ffr", "solver.static_method=newton", "beam.bending=cubic",
                "beam.geometric_stiffness=true", "beam.nodes=10", "beam.modes=2"]
LEAN = ["output.xdmf=false", "output.answers=false"]
REFERENCES = {"cubic": [*CUBIC, "beam.nodes=28", "solver.dt=2.5e-4"],
              "cable": [*CABLE, "beam.nodes=55", "solver.dt=2.5e-4"],
              "ffr": ["solver.dt=2.5e-4"]}


def grid() -> list[tuple[str, list[str]]]:
    """(label, overrides) of every run: the shipped FFR scene's free settings, then the
    other formulations' candidates for each level."""
    runs = [("shipped", []), ("shipped, lean output", LEAN),
            ("shipped, no XDMF", ["output.xdmf=false"]),
            ("shipped, no answers", ["output.answers=false"])]
    for nodes in (16, 22, 28):
        for dt in ("1e-3", "2e-3", "5e-3", "1e-2", "2e-2"):
            runs.append((f"FFR continuum {nodes} nodes, dt {dt}",
                         [f"beam.nodes={nodes}", f"solver.dt={dt}"]))
    runs.append(("FFR continuum 28 nodes, dt 1e-3, newton_tol 1e-6", ["solver.newton_tol=1e-6"]))
    for nodes in (4, 7, 10):
        for dt in ("1e-3", "5e-3", "1e-2", "2e-2"):
            runs.append((f"FFR cubic {nodes} nodes, dt {dt}",
                         [*FFR, "beam.bending=cubic", f"beam.nodes={nodes}", f"solver.dt={dt}"]))
    for dt in ("1e-3", "2e-3", "5e-3", "1e-2"):
        runs.append((f"FFR cubic + P-delta, 10 nodes, 2 modes, dt {dt}",
                     [*PDELTA_MODES, f"solver.dt={dt}"]))
    for nodes in (4, 7, 10):
        for dt in ("2e-3", "5e-3", "1e-2", "2e-2"):
            runs.append((f"cable {nodes} nodes, dt {dt}",
                         [*CABLE, f"beam.nodes={nodes}", f"solver.dt={dt}"]))
            runs.append((f"cable {nodes} nodes, dt {dt}, lean output",
                         [*CABLE, f"beam.nodes={nodes}", f"solver.dt={dt}", *LEAN]))
    for nodes in (4, 7):
        for dt in ("1e-3", "2e-3", "5e-3", "1e-2"):
            runs.append((f"nonlinear cubic {nodes} nodes, dt {dt}",
                         [*CUBIC, f"beam.nodes={nodes}", f"solver.dt={dt}"]))
    return runs


def sag(path: Path) -> tuple[np.ndarray, np.ndarray, dict]:
    """Time, tip sag and the dynamic counters of a result file."""
    with h5py.File(path, "r") as f:
        dyn = f["dynamic"]
        return (dyn["time"][()], dyn["deflection/tip"][:, 1],
                {k: int(dyn.attrs[k]) for k in ("steps", "newton_iterations", "factorizations")})


def error_pct(t: np.ndarray, s: np.ndarray, t_ref: np.ndarray, s_ref: np.ndarray) -> float:
    """max |s - s_ref| at every 0.02 s, in % of the reference's sag range."""
    marks = np.round(np.arange(0.0, t_ref[-1] + 1e-9, 0.02), 9)
    pick = lambda tt: np.searchsorted(np.round(tt, 9), marks)  # noqa: E731
    i, j = pick(t), pick(t_ref)
    assert np.allclose(t[i], marks) and np.allclose(t_ref[j], marks)
    return float(100 * np.max(np.abs(s[i] - s_ref[j])) / np.ptp(s_ref))


def cpu_run(overrides: list[str], out: Path, repeats: int) -> float:
    """The best CPU time of ``repeats`` whole run_scene calls (the file written each time)."""
    best = float("inf")
    for _ in range(repeats):
        out.unlink(missing_ok=True)
        start = time.process_time()
        run_scene(SCENE, [*BASE, *overrides], out, progress=False)
        best = min(best, time.process_time() - start)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path,
                        default=REPO / "benchmarks" / "results" / "boom_front")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="boom_front_"))
    refs = {}
    for name, over in REFERENCES.items():
        path = work / f"ref_{name}.h5"
        run_scene(SCENE, [*BASE, *over, *LEAN], path, progress=False)
        t, s, _ = sag(path)
        refs[name] = (t, s)
    ref_gap = error_pct(*refs["cable"], *refs["cubic"])
    print(f"references: cable vs cubic {ref_gap:.4f} % of the cubic sag range", flush=True)
    rows = []
    load_start = load_average()
    for label, over in grid():
        out = work / "run.h5"
        try:
            cpu = cpu_run(over, out, args.repeats)
        except Exception as exc:  # a failed configuration is a row, not the end of the grid
            rows.append({"label": label, "overrides": over, "status": f"{type(exc).__name__}: {exc}"})
            print(f"{label}: FAILED {exc}", flush=True)
            continue
        t, s, counters = sag(out)
        row = {"label": label, "overrides": over, "status": "ok", "cpu_s": cpu, **counters,
               "err_cubic_pct": error_pct(t, s, *refs["cubic"]),
               "err_cable_pct": error_pct(t, s, *refs["cable"]),
               "err_ffr_pct": error_pct(t, s, *refs["ffr"])}
        rows.append(row)
        print(f"{label:52s} cpu {cpu:.3f} s  err {row['err_cubic_pct']:.4f} % (cubic) "
              f"{row['err_cable_pct']:.4f} % (cable) {row['err_ffr_pct']:.4f} % (ffr)  {counters}",
              flush=True)
    levels = {}
    ok = [r for r in rows if r["status"] == "ok"]
    # the picks keep the scene's default output (what a copied --set line gives)
    default_output = [r for r in ok if not any(o.startswith("output.") for o in r["overrides"])]
    for ref in ("cubic", "cable"):
        for level in (3.0, 1.0, 0.3, 0.1):
            meets = [r for r in default_output if r[f"err_{ref}_pct"] <= level]
            best = min(meets, key=lambda r: r["cpu_s"]) if meets else None
            levels[f"{ref} {level}"] = best and best["label"]
    report = {"machine": machine_info(), "load_average": [load_start, load_average()],
              "reference_gap_pct": ref_gap, "rows": rows, "levels": levels}
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.with_suffix(".json").write_text(json.dumps(report, indent=1) + "\n")
    lines = [f"Load average {load_start} at the start, {load_average()} at the end; CPU time "
             f"of the whole run_scene call (file written), best of {args.repeats}. References "
             f"differ by {ref_gap:.3f} % of the sag range.", "",
             "| configuration | CPU s | steps | Newton corrections | factorizations | "
             "err vs cubic % | err vs cable % | err vs shipped FFR at dt 0.25 ms % |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in ok:
        lines.append(f"| {r['label']} | {r['cpu_s']:.3f} | {r['steps']} | "
                     f"{r['newton_iterations']} | {r['factorizations']} | "
                     f"{r['err_cubic_pct']:.4f} | {r['err_cable_pct']:.4f} | "
                     f"{r['err_ffr_pct']:.4f} |")
    lines += ["", "Each level's fastest configuration with the scene's default output:", "",
              "| level | against | fastest |", "|---|---|---|"]
    for key, label in levels.items():
        ref, level = key.split()
        lines.append(f"| {level} % | {ref} | {label or 'none'} |")
    args.output.with_suffix(".md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
