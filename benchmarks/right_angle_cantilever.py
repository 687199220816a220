"""The right-angle cantilever of Simo & Vu-Quoc (1986) under an out-of-plane pulse
(tests/test_right_angle_cantilever.py builds it): both bending options on 9, 17 and 33 nodes
per leg against the cubic option on 65, over the published 0-30 s.

    python benchmarks/right_angle_cantilever.py [--quick] [--write-reference]

JSON (benchmarks/results/right_angle_cantilever.json): per run the largest difference of
the elbow's and tip's coordinates to the reference, relative to each coordinate's range,
over 0-2.5, 5, 10, 20 and 30 s, and the wall time (the machine may be shared: 'machine').
--write-reference also stores the reference history every 0.05 s in
tests/reference/right_angle_cantilever.json (what the CI test compares against).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE))
import test_right_angle_cantilever as rac  # noqa: E402
from _common import json_ready, machine_info  # noqa: E402

RESULTS = HERE / "results"
WINDOWS = (2.5, 5.0, 10.0, 20.0, 30.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="9 against 17 nodes, 0-5 s")
    parser.add_argument("--write-reference", action="store_true")
    parser.add_argument("--output", type=Path, default=None)
    args = parser.parse_args()
    t_end = 5.0 if args.quick else 30.0
    ref_nodes, meshes = (17, (9,)) if args.quick else (65, (9, 17, 33))
    start = time.perf_counter()
    t_ref, p_ref = rac.simulate("cubic", ref_nodes, t_end)
    runs = [{"bending": "cubic", "nodes_per_leg": ref_nodes, "reference": True,
             "wall_s": time.perf_counter() - start}]
    keep = np.round(t_ref / 0.05, 6) % 1 == 0
    reference = {"t": t_ref[keep], "elbow": p_ref[keep, 0], "tip": p_ref[keep, 1]}
    if args.write_reference and not args.quick:
        rac.REFERENCE.write_text(json.dumps(json_ready({
            "what": "right-angle cantilever (Simo & Vu-Quoc 1986), cubic option, 65 nodes "
                    "per leg, dt = 0.0125, generalized-alpha rho_inf = 0.9; positions of the "
                    "elbow (10, 0, 0) and the tip (10, 10, 0) every 0.05 s",
            "source": "benchmarks/right_angle_cantilever.py --write-reference",
            **{k: np.asarray(v).tolist() for k, v in reference.items()}})))
    full = {"t": t_ref, "elbow": p_ref[:, 0], "tip": p_ref[:, 1]}
    for bending in ("cubic", "continuum"):
        for nodes in meshes:
            start = time.perf_counter()
            t, p = rac.simulate(bending, nodes, t_end)
            wall = time.perf_counter() - start
            errors = {f"{w:g}": rac.error_of_range(t[t <= w + 1e-9], p[t <= w + 1e-9], full)
                      for w in WINDOWS if w <= t_end}
            runs.append({"bending": bending, "nodes_per_leg": nodes, "error_of_range": errors,
                         "wall_s": wall})
            print(f"{bending:9s} {nodes:3d} nodes/leg: " +
                  ", ".join(f"0-{w} s {100 * e:.2f}%" for w, e in errors.items()) +
                  f"  ({wall:.1f} s)", flush=True)
    output = args.output or RESULTS / ("right_angle_cantilever_quick.json" if args.quick
                                       else "right_angle_cantilever.json")
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps(json_ready({
        "benchmark": "right-angle cantilever (Simo & Vu-Quoc 1986)", "dt": rac.DT,
        "t_end": t_end, "runs": runs, "machine": machine_info()}), indent=1))
    print(f"wrote {output}")


if __name__ == "__main__":
    main()
