#!/usr/bin/env python
"""The planar reduction's effect (issue 23, ``scene.planar``): the same scene solved with
every coordinate (``planar = 'off'``) and with the in-plane coordinates only (``'xy'``).

Cases: the nonlinear luffing boom (``inputs/boom_luffing.nml`` with
``scene.formulation = nonlinear``, ``solver.static_method = newton``), cubic bending at 4, 10,
16, 22 and 28 nodes and continuum bending at 10 nodes, over ``--t-end`` seconds (default
2: the start and part of the luffing stage); the flexible pendulum
(``inputs/hard/pendulum.nml``, 9 and 17 nodes, 0.5 s). Each case runs off and xy
interleaved, ``--repeats`` times (best kept), through ``ancfdrv.runner.run_scene`` without
XDMF. Recorded per run: unknowns (``/model`` ndof, nconstraints, nunknowns, nplanar_fixed),
steps, Newton corrections, factorizations, the dynamic solve's wall time
(``/dynamic`` ``wall_time_s``) and its stepping part (``/timing`` ``dynamic_stepping``),
steps per second of each, and the largest tip difference between off and xy in the tip's
range. The machine is shared: the load average is recorded; ratios are the same-run
off / xy times.

    python benchmarks/planar_reduction.py            # about 2 minutes on a loaded machine
    python benchmarks/planar_reduction.py --quick    # 4 and 10 nodes, one repeat
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

import h5py
import numpy as np

REPO = Path(__file__).resolve().parents[1]


def cases(quick: bool, t_end: float) -> list[tuple[str, str, list[str]]]:
    boom = ["scene.formulation=nonlinear", "solver.static_method=newton",
            f"solver.t_end={t_end!r}"]
    out = [(f"boom cubic {n}", "inputs/boom_luffing.nml",
            boom + ["beam.bending=cubic", f"beam.nodes={n}"])
           for n in ((4, 10) if quick else (4, 10, 16, 22, 28))]
    if not quick:
        out.append(("boom continuum 10", "inputs/boom_luffing.nml",
                    boom + ["beam.bending=continuum", "beam.nodes=10"]))
    out += [(f"pendulum {n}", "inputs/hard/pendulum.nml",
             [f"beam.nodes={n}", "solver.t_end=0.5", "solver.dt=1e-3"])
            for n in ((9,) if quick else (9, 17))]
    return out


def run_once(scene: str, overrides: list[str], out: Path) -> dict:
    from ancfdrv.runner import run_scene
    t0 = time.perf_counter()
    run_scene(REPO / scene, overrides + ["output.xdmf=.false."], out, progress=False)
    whole = time.perf_counter() - t0
    with h5py.File(out) as f:
        m, d, timing = f["model"].attrs, f["dynamic"].attrs, f["timing"].attrs
        return {"whole_s": whole, "solve_s": float(d["wall_time_s"]),
                "stepping_s": float(timing["dynamic_stepping"]),
                "steps": int(d["steps"]), "newton_iterations": int(d["newton_iterations"]),
                "factorizations": int(d["factorizations"]),
                "ndof": int(m["ndof"]), "nfull": int(m["nfull"]),
                "nconstraints": int(m["nconstraints"]), "nunknowns": int(m["nunknowns"]),
                "nplanar_fixed": int(m["nplanar_fixed"]),
                "tip": f["dynamic/probes/tip"][()]}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--output", type=Path)
    args = parser.parse_args(argv)
    repeats = 1 if args.quick else args.repeats
    output = args.output or REPO / "benchmarks" / "results" / (
        "planar_reduction_quick.json" if args.quick else "planar_reduction.json")
    report = {"created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
              "machine": platform.platform(), "cpus": os.cpu_count(),
              "load_start": list(os.getloadavg()), "repeats": repeats, "cases": []}
    with tempfile.TemporaryDirectory() as tmp:
        for label, scene, overrides in cases(args.quick, args.t_end):
            best: dict[str, dict] = {}
            for _ in range(repeats):   # interleaved: off, xy, off, xy, ...
                for planar in ("off", "xy"):
                    r = run_once(scene, overrides + [f"scene.planar={planar}"],
                                 Path(tmp) / f"{planar}.h5")
                    keep = best.setdefault(planar, r)
                    for key in ("whole_s", "solve_s", "stepping_s"):
                        keep[key] = min(keep[key], r[key])
            tip_off, tip_xy = best["off"].pop("tip"), best["xy"].pop("tip")
            diff = float(np.abs(tip_off - tip_xy).max() / np.ptp(tip_off, axis=0).max())
            for r in best.values():
                r["steps_per_s_solve"] = r["steps"] / r["solve_s"]
                r["steps_per_s_stepping"] = r["steps"] / r["stepping_s"]
            row = {"case": label, "scene": scene, "overrides": overrides, "off": best["off"],
                   "xy": best["xy"], "tip_difference_of_range": diff,
                   "stepping_ratio_off_over_xy": best["off"]["stepping_s"] /
                   best["xy"]["stepping_s"],
                   "solve_ratio_off_over_xy": best["off"]["solve_s"] / best["xy"]["solve_s"]}
            report["cases"].append(row)
            print(f"{label:>20}: unknowns {best['off']['nunknowns']} -> "
                  f"{best['xy']['nunknowns']}, stepping {best['off']['stepping_s']:.3f} -> "
                  f"{best['xy']['stepping_s']:.3f} s, solve {best['off']['solve_s']:.3f} -> "
                  f"{best['xy']['solve_s']:.3f} s, factorizations "
                  f"{best['off']['factorizations']} -> {best['xy']['factorizations']}, "
                  f"diff {diff:.1e}", file=sys.stderr, flush=True)
    report["load_end"] = list(os.getloadavg())
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps(report, indent=1) + "\n")
    print(f"wrote {output}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
