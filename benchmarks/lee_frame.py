"""The reference path of Lee's frame for tests/test_arc_length.py: the same model on a fine
mesh (default 81 nodes per member, 'cubic' bending) followed by arc length under
20 EI / L^2, written to tests/reference/lee_frame_path.json (u, v: the load point's
displacement, m; load: P L^2 / EI) with its limit load and the coarser meshes' limits
beside it (mesh convergence).

    .venv/bin/python benchmarks/lee_frame.py [--nodes 81]
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE))
import test_arc_length as lee  # noqa: E402
from _common import json_ready, machine_info  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=81)
    args = parser.parse_args()
    limits = {}
    with tempfile.TemporaryDirectory() as work:
        for nodes in (11, 21, 41, args.nodes):
            start = time.perf_counter()
            path = lee.lee_path(nodes, Path(work))
            limits[nodes] = 20.0 * float(path["limit_load_factors"][0])
            print(f"{nodes} nodes: limit {limits[nodes]:.4f} EI/L^2 "
                  f"({time.perf_counter() - start:.1f} s)")
    out = {"model": "Lee's frame, tests/test_arc_length.py lee_frame, 'cubic' bending",
           "nodes": args.nodes, "limit_load": limits[args.nodes],
           "limits_by_nodes": {str(k): v for k, v in limits.items()},
           "u": path["displacement"][:, 0], "v": path["displacement"][:, 1],
           "load": 20.0 * path["load_factor"], "machine": machine_info()}
    target = HERE.parent / "tests" / "reference" / "lee_frame_path.json"
    target.write_text(json.dumps(json_ready(out), indent=1) + "\n")
    print(f"wrote {target}")


if __name__ == "__main__":
    main()
