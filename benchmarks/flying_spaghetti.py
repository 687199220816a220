#!/usr/bin/env python
"""The 3D flying spaghetti (Simo & Vu-Quoc 1988, "On the dynamics in space of rods
undergoing large motions", CMAME 66; the 3D twin of the 1986 planar example): a free beam
driven by a force and a torque pulse at one end, against this code's own converged
reference (finer mesh and time step).

Data (as given in the benchmark literature, e.g. the AeroBeams and GXBeam examples): L = 10,
EA = GA = 1e4, EI = GJ = 500, rho A = 1, rho J = diag(20, 10, 10); the beam lies in the x-z
plane from (0, 0, 0) to (6, 0, -8) (turned by atan(4/3) about y); at its end (6, 0, -8) the
dead force (1/10, 0, 0) p(t) and the dead torque (0, 1, 1/2) p(t), p a triangular pulse
from 0 to 200 at t = 2.5 s and back to 0 at t = 5 s. Entered through section = 'general'
(A = 1, I_y = I_z = 0.05, J = 0.1, shear factors 2 with E = 1e4, nu = 0 so G = 5000 and
k G A = 1e4, mass 1 per length, rotary inertia (20, 10, 10) per length). The torque pulse
is a 'moment' load with a drive (acting on the current section about the fixed spatial
vector); the force a 'force' load with the same drive.

Measured: the end point's displacement components over the published span (0 to 10 s) for
a mesh/step sequence; the error of each against the finest run as a fraction of each
component's range (SPEC: below 2% at the mesh the test uses).

    python benchmarks/flying_spaghetti.py [--quick] [--out results/flying_spaghetti.json]
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from _common import json_ready, machine_info, print_table

from ancfdrv import General, System
from ancfdrv.solvers.dynamic import DynamicSettings, integrate

LENGTH = 10.0
END = np.array([6.0, 0.0, -8.0])
PULSE = dict(times=[0.0, 2.5, 5.0, 1e3], values=[0.0, 200.0, 0.0, 0.0])


def build(nodes: int, bending: str = "cubic") -> System:
    """The free beam with its two driven loads and a probe at the loaded end."""
    s = System("flying spaghetti (Simo & Vu-Quoc 1988)")
    s.material("m", youngs_modulus=1.0e4, density=1.0, poisson_ratio=0.0)
    section = General(area=1.0, iy=0.05, iz=0.05, torsion_constant=0.1, shear_factor_y=2.0,
                      shear_factor_z=2.0, mass_per_length=1.0, rotary_inertia=(20.0, 10.0, 10.0))
    s.beam("spaghetti", material="m", start=(0, 0, 0), end=END, nodes=nodes, section=section,
           height_axis=(0.8, 0.0, 0.6), formulation="nonlinear", bending=bending)
    s.drive("p", "table", **PULSE)
    s.load("force", "force", body="spaghetti", point=END, vector=(0.1, 0.0, 0.0), drive="p")
    s.load("torque", "moment", body="spaghetti", point=END, vector=(0.0, 1.0, 0.5), drive="p")
    s.probe("end", "spaghetti", END)
    s.probe("start", "spaghetti", (0.0, 0.0, 0.0))
    return s


def simulate(nodes: int, dt: float, t_end: float, bending: str = "cubic"):
    """(times, end-point displacement (nt, 3), wall seconds, Newton corrections)."""
    model = build(nodes, bending).assemble()
    rows: list = []

    def sink(chunk) -> None:
        rows.append((np.array(chunk.time), np.array(chunk.probes[:, 0, :])))
    start = time.perf_counter()
    try:
        result = integrate(model, DynamicSettings.generalized_alpha(
            dt, t_end, rho_inf=0.8, max_newton=30), model.e0, sink=sink, progress=False)
    finally:
        model.close()
    wall = time.perf_counter() - start
    t = np.concatenate([r[0] for r in rows])
    p = np.concatenate([r[1] for r in rows])
    return t, p - END, wall, result.newton_iterations


def compare(t, u, t_ref, u_ref) -> list[float]:
    """Max error of each component over the common times, as a fraction of its range in the
    reference."""
    out = []
    for i in range(3):
        ref = np.interp(t, t_ref, u_ref[:, i])
        span = np.ptp(u_ref[:, i])
        out.append(float(np.abs(u[:, i] - ref).max() / span))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a short smoke setting")
    parser.add_argument("--out", default=None, help="JSON output")
    args = parser.parse_args()
    t_end = 5.0 if args.quick else 10.0
    cases = [(9, 0.01, "cubic"), (17, 0.01, "cubic")] if args.quick else \
        [(9, 0.01, "cubic"), (13, 0.01, "cubic"), (17, 0.01, "cubic"), (17, 0.005, "cubic"),
         (25, 0.005, "cubic"), (33, 0.005, "cubic"), (17, 0.01, "continuum"),
         (33, 0.005, "continuum"), (49, 0.0025, "cubic")]
    runs = {}
    for nodes, dt, bending in cases:
        runs[(nodes, dt, bending)] = simulate(nodes, dt, t_end, bending)
        t, u, wall, newton = runs[(nodes, dt, bending)]
        print(f"{bending} {nodes} nodes, dt {dt}: {wall:.2f} s (machine shared; not a "
              f"timing), end at t_end {np.round(u[-1], 4)}", flush=True)
    reference = cases[-1]
    t_ref, u_ref, *_ = runs[reference]
    table, records = [], []
    for (nodes, dt, bending), (t, u, wall, newton) in runs.items():
        errors = compare(t, u, t_ref, u_ref)
        pulse = t <= 5.0 + 1e-9
        errors_pulse = compare(t[pulse], u[pulse], t_ref[t_ref <= 5.0 + 1e-9],
                               u_ref[t_ref <= 5.0 + 1e-9])
        records.append({"nodes": nodes, "dt": dt, "bending": bending,
                        "errors_of_range": errors, "errors_of_range_0_5s": errors_pulse,
                        "wall_s": wall, "newton_corrections": newton,
                        "range": np.ptp(u, axis=0), "end_displacement": u[-1]})
        table.append([bending, str(nodes), f"{dt:g}", *(f"{100 * e:.3f}%" for e in errors),
                      f"{wall:.2f}"])
    print_table([("bending", 10), ("nodes", 6), ("dt", 8), ("u1 err", 10), ("u2 err", 10),
                 ("u3 err", 10), ("wall s", 8)], table)
    out = Path(args.out) if args.out else Path(__file__).parent / "results" / (
        "flying_spaghetti_quick.json" if args.quick else "flying_spaghetti.json")
    out.write_text(json.dumps(json_ready({
        "benchmark": "flying spaghetti 3D (Simo & Vu-Quoc 1988)", "t_end": t_end,
        "reference": {"nodes": reference[0], "dt": reference[1]},
        "integrator": "generalized_alpha rho_inf 0.8",
        "runs": records, "machine": machine_info()}), indent=2))
    print(f"written {out}")


if __name__ == "__main__":
    main()
