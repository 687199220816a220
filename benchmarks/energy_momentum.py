"""The energy-momentum integrator against generalized-alpha (issue 39 item 4) on the
conservative hard cases: the flexible pendulum (inputs/hard/pendulum.nml), a 100 kg payload
on a steel rope released horizontally (a scene of this script: the rope goes slack and taut
as it rings axially) and the flexible double pendulum (inputs/hard/double_pendulum.nml).

For each case and step: solver.integrator = 'energy_momentum' and 'generalized_alpha' at
rho_inf = 1 and 0.8, each run classified by its status ('ok', 'unstable', 'failed'), the
probe's error against a converged reference over time (the largest distance so far at
twenty times, and its largest), the energy drift (max |E - E0| over the largest kinetic
energy), the wall time per step and the Newton corrections per step. The reference is the
energy-momentum run at the finest step (ref_dt); the same step with generalized-alpha at
rho_inf 0.8 is reported beside it (reference_spread: how far the two references lie apart,
the reference's own uncertainty).

Writes results/energy_momentum.json (or --output) and, with --charts DIR, one chart a case
of the probe's largest error against the run's wall time (DIR/energy_momentum_<case>.png;
the runs that ended 'ok', labelled by their step). --quick: coarser meshes, shorter runs.
Usage: python benchmarks/energy_momentum.py [--quick] [--only pendulum,rope,double]
                                            [--output JSON] [--charts DIR]
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))
from _common import json_ready, machine_info  # noqa: E402

from ancfdrv.errors import SolverError  # noqa: E402
from ancfdrv.simulation import simulate  # noqa: E402

ROPE = """! a 100 kg payload on a 2 m steel rope (d = 10 mm, EI = 1 N m^2), hinged at its top,
! released horizontally at rest under gravity: it swings down and rings axially, Gauss
! points of the rope going slack and taut (tension-only law)
&scene  title = 'Payload on a rope', analysis = 'dynamic' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&cable  name = 'rope', material = 'steel', start = 0.0, 0.0, 0.0, end = 2.0, 0.0, 0.0,
        nodes = {nodes}, section = 'circle', diameter = 0.01, tension_only = .true.,
        bending_stiffness = 1.0 /
&joint  name = 'top', type = 'spherical', body1 = 'ground', body2 = 'rope',
        point = 0.0, 0.0, 0.0 /
&load  name = 'g', type = 'gravity', vector = 0.0, -9.81, 0.0 /
&load  name = 'payload', type = 'point_mass', body = 'rope', point = 2.0, 0.0, 0.0,
       mass = 100.0 /
&probe  name = 'hook', body = 'rope', point = 2.0, 0.0, 0.0 /
&solver  newton_tol = 1e-10, max_newton = 20 /
&output  xdmf = .false., answers = .false. /
"""

METHODS = {
    "energy_momentum": ["solver.integrator=energy_momentum"],
    "generalized_alpha_rho1": ["solver.integrator=generalized_alpha", "solver.rho_inf=1.0"],
    "generalized_alpha_rho0.8": ["solver.integrator=generalized_alpha", "solver.rho_inf=0.8"],
}


@dataclass
class Case:
    """A model (scene file and overrides), its probe, its run's end and the steps."""

    name: str
    scene: Path
    overrides: list[str]
    probe: str
    t_end: float
    steps: list[float]
    ref_dt: float


def cases(quick: bool, only: set[str], tmp: Path) -> list[Case]:
    out = []
    if "pendulum" in only:
        out.append(Case("pendulum", REPO / "inputs" / "hard" / "pendulum.nml",
                        [f"beam.nodes={5 if quick else 9}"], "tip", 0.5 if quick else 2.0,
                        [1e-2, 5e-3, 2e-3] if quick else [1e-2, 5e-3, 2e-3, 1e-3],
                        1e-3 if quick else 2.5e-4))
    if "rope" in only:
        rope = tmp / "rope.nml"
        rope.write_text(ROPE.format(nodes=3 if quick else 5))
        out.append(Case("rope", rope, [], "hook", 0.5 if quick else 1.0,
                        [1e-2, 4e-3, 1e-3], 5e-4 if quick else 2.5e-4))
    if "double" in only:
        nodes = 5 if quick else 17
        out.append(Case("double_pendulum", REPO / "inputs" / "hard" / "double_pendulum.nml",
                        [f"beam[upper].nodes={nodes}", f"beam[lower].nodes={nodes}"], "tip",
                        0.25 if quick else 1.0,
                        [1e-2, 5e-3, 2e-3] if quick else [1e-2, 5e-3, 2e-3, 1e-3],
                        1e-3 if quick else 2.5e-4))
    return out


def run(case: Case, method: str, dt: float) -> dict:
    """One run: its status, rows and costs (a failed or unstable run: its rows so far)."""
    overrides = case.overrides + METHODS[method] + [f"solver.dt={dt}",
                                                    f"solver.t_end={case.t_end}"]
    start = time.perf_counter()
    status, message = "ok", ""
    try:
        sim = simulate(case.scene, overrides, progress=False)
    except SolverError as exc:
        sim = getattr(exc, "simulation", None)
        status, message = getattr(sim, "status", "failed") if sim else "failed", str(exc)
    wall = time.perf_counter() - start
    if sim is None:
        return {"status": status, "message": message, "wall_s": wall}
    time_rows = sim.time
    steps = max(len(time_rows) - 1, 1)
    corrections = float(np.sum(sim.series("newton_iterations")))
    return {"status": status, "message": message, "wall_s": wall, "time": time_rows,
            "probe": sim.probe(case.probe), "total": sim.energy("total"),
            "kinetic": sim.energy("kinetic"), "steps": steps,
            "ms_per_step": 1e3 * wall / steps, "corrections_per_step": corrections / steps}


def compare(record: dict, reference: dict, t_end: float) -> dict:
    """The probe's error against the reference over time and the energy drift."""
    if "time" not in record or len(record["time"]) < 2:
        return {}
    t = record["time"]
    ref = np.column_stack([np.interp(t, reference["time"], reference["probe"][:, k])
                           for k in range(3)])
    error = np.linalg.norm(record["probe"] - ref, axis=1)
    envelope = np.maximum.accumulate(error)
    samples = np.linspace(0.0, t_end, 21)[1:]
    reached = samples[samples <= t[-1] + 1e-12]
    scale = max(float(record["kinetic"].max()), 1e-300)
    return {"max_error_m": float(error.max()),
            "error_vs_time": [[float(s), float(np.interp(s, t, envelope))] for s in reached],
            "energy_drift": float(np.abs(record["total"] - record["total"][0]).max() / scale),
            "t_reached": float(t[-1])}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--only", default="pendulum,rope,double")
    parser.add_argument("--output", type=Path,
                        default=HERE / "results" / "energy_momentum.json")
    parser.add_argument("--charts", type=Path, default=None)
    args = parser.parse_args()
    report: dict = {"machine": machine_info(), "quick": args.quick, "cases": {}}
    print("| case | method | dt | status | max error (m) | energy drift | ms/step | "
          "corrections/step |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for case in cases(args.quick, set(args.only.split(",")), Path(tmp)):
            reference = run(case, "energy_momentum", case.ref_dt)
            check = run(case, "generalized_alpha_rho0.8", case.ref_dt)
            spread = compare(check, reference, case.t_end).get("max_error_m")
            runs = []
            for method in METHODS:
                for dt in case.steps:
                    record = run(case, method, dt)
                    measured = compare(record, reference, case.t_end)
                    row = {"method": method, "dt": dt, "status": record["status"],
                           "message": record["message"], "wall_s": record["wall_s"],
                           "steps": record.get("steps"),
                           "ms_per_step": record.get("ms_per_step"),
                           "corrections_per_step": record.get("corrections_per_step"),
                           **measured}
                    runs.append(row)
                    fmt = (lambda v, f: "-" if v is None else format(v, f))
                    print(f"| {case.name} | {method} | {dt:g} | {row['status']} | "
                          f"{fmt(row.get('max_error_m'), '.2e')} | "
                          f"{fmt(row.get('energy_drift'), '.1e')} | "
                          f"{fmt(row.get('ms_per_step'), '.2f')} | "
                          f"{fmt(row.get('corrections_per_step'), '.2f')} |", flush=True)
            report["cases"][case.name] = {
                "scene": case.scene.name if case.name != "rope" else ROPE,
                "overrides": case.overrides, "probe": case.probe, "t_end": case.t_end,
                "reference": {"method": "energy_momentum", "dt": case.ref_dt,
                              "status": reference["status"],
                              "energy_drift": compare(reference, reference, case.t_end)
                              .get("energy_drift"),
                              "reference_spread_m": spread},
                "runs": runs}
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(json.dumps(json_ready(report), indent=1))
    print(f"written {args.output}")
    if args.charts is not None:
        draw(report, args.charts)


def draw(report: dict, folder: Path) -> None:
    """The accuracy-against-time chart of each case (the runs that ended 'ok')."""
    from ancfdrv.plots import pareto_chart
    folder.mkdir(parents=True, exist_ok=True)
    for name, case in report["cases"].items():
        rows = [r for r in case["runs"] if r["status"] == "ok" and r.get("max_error_m")]
        if not rows:
            continue
        path = folder / f"energy_momentum_{name}.png"
        pareto_chart(rows, lambda r: r["method"], lambda r: f"{r['dt']:g}", "max_error_m",
                     path, time_key="wall_s", common_reference=True,
                     title=f"{name}, {case['t_end']:g} s: the probe's largest error against "
                           "the energy-momentum run at dt = "
                           f"{case['reference']['dt']:g}\nvs wall time (labels: dt; "
                           "runs that ended 'ok')")
        print(f"written {path}")


if __name__ == "__main__":
    main()
