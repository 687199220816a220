"""The spatial slider-crank of issue 20 (tests/test_spatial_mechanism.py builds it): the
rod's mid-span deflection from its chord for both bending options, nu = 0 and 0.3, on 9, 17
and 33 nodes (and the cubic reference on 65), against the cubic option on 33 nodes.

    python benchmarks/spatial_mechanism.py [--quick] [--t-end 0.6] [--output FILE]

JSON (benchmarks/results/spatial_mechanism.json): per run the bending, nodes, nu, peak
deflection, its time, the largest history difference and the peak difference relative to
the reference's peak, and the wall time (the machine may be shared: see 'machine').
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
import test_spatial_mechanism as mechanism  # noqa: E402
from _common import json_ready, machine_info  # noqa: E402

RESULTS = HERE / "results"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="9 and 17 nodes, 0.3 s")
    parser.add_argument("--t-end", type=float, default=None, help="end time (s; default 0.6)")
    parser.add_argument("--output", type=Path, default=None)
    args = parser.parse_args()
    mechanism.T_END = args.t_end or (0.3 if args.quick else 0.6)
    meshes = (9, 17) if args.quick else (9, 17, 33)
    output = args.output or RESULTS / ("spatial_mechanism_quick.json" if args.quick
                                       else "spatial_mechanism.json")
    runs, references = [], {}
    for nu in (0.0, 0.3):
        start = time.perf_counter()
        references[nu] = mechanism.deflection("cubic", 33 if not args.quick else 17, nu)
        wall = time.perf_counter() - start
        ref = references[nu]
        runs.append({"bending": "cubic", "nodes": 33 if not args.quick else 17, "nu": nu,
                     "reference": True, "peak": ref.max(),
                     "t_peak": ref.argmax() * mechanism.DT, "wall_s": wall})
        for bending in ("cubic", "continuum"):
            for nodes in meshes + ((65,) if bending == "cubic" and not args.quick else ()):
                start = time.perf_counter()
                d = mechanism.deflection(bending, nodes, nu)
                wall = time.perf_counter() - start
                row = {"bending": bending, "nodes": nodes, "nu": nu, "peak": d.max(),
                       "t_peak": d.argmax() * mechanism.DT,
                       "history_error": np.abs(d - ref).max() / ref.max(),
                       "peak_error": (d.max() - ref.max()) / ref.max(), "wall_s": wall}
                runs.append(row)
                print(f"{bending:9s} {nodes:3d} nodes nu = {nu}: peak {1e3 * d.max():.4f} mm, "
                      f"history error {100 * row['history_error']:.3f}%, peak "
                      f"{100 * row['peak_error']:+.3f}%, {wall:.1f} s", flush=True)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps(json_ready({
        "benchmark": "spatial slider-crank (issue 20)", "dt": mechanism.DT,
        "t_end": mechanism.T_END, "runs": runs, "machine": machine_info()}), indent=1))
    print(f"wrote {output}")


if __name__ == "__main__":
    main()
