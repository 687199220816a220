"""The independent reference path of Lee's frame for tests/test_arc_length.py: the load point
pulled down by displacement control through a stiff spring, with ordinary Newton (no arc
length), written to tests/reference/lee_frame_displacement.json.

The frame is tests/test_arc_length.py's (``lee_members``) without its load. A 'cylinder'
force element (a rigid actuator of driven length l(t) in series with a spring of stiffness
k) joins a ground point H = 1e4 m straight below the load point to the load point; its
length l(t) = H - w_max t follows a 'table' drive, so the support moves down by
w = w_max t. Each increment of t is one equilibrium solve of the kernel's static Newton at
that time (``Kernel.static_solve``, the System's static solve at t = 0 only), started from
the previous one; an increment that does not converge is halved (down to 1/64 of it).
Under the moving support the path passes the limit in load without difficulty; it ends
where the load point's vertical displacement v would turn back (the snap-back, reached
where the path's slope dP/dv falls to -k): there Newton no longer converges or jumps to
another branch (an increment whose spring stretch changes by more than the support's
travel is such a jump), both refused. Recorded:
v and u (the load point's vertical and horizontal displacement, m), the spring's pull on
the load point, vertical (P L^2 / EI) and horizontal (H L^2 / EI: the spring's tilt
u / H, a load the frame does not have, recorded to show it is negligible), and the support
displacement w (m), and the limit load (the largest load, refined by a parabola), for the
test's mesh (31 nodes per member) and a finer one (81: the mesh's share of the limit
load's distance to 18.56).

    .venv/bin/python benchmarks/lee_frame_displacement.py [--nodes 31] [--fine 81]
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
import test_arc_length as lee  # noqa: E402
from _common import json_ready, machine_info  # noqa: E402

DEPTH = 1.0e4          # m: the ground point below the load point (tilt u / DEPTH)
STIFFNESS = 1.0e3      # N/m: 1e4 times the frame's EI / L^3
W_MAX = 1.0            # m: the support's travel over t in [0, 1]
STEP = 0.004           # the increment of t (4 mm of support travel)
HALVINGS = 6


def pulled_frame(nodes: int):
    """Lee's frame (``nodes`` per member) with the stiff spring from the moving support."""
    s = lee.lee_members(nodes)
    x, y = 0.2 * lee.L_FRAME, lee.L_FRAME
    s.drive("support", "table", times=(0.0, 1.0), values=(DEPTH, DEPTH - W_MAX))
    s.force_element("spring", "cylinder", body1="ground", point1=(x, y - DEPTH, 0.0),
                    body2="beam", point2=(x, y, 0.0), drive="support", stiffness=STIFFNESS)
    return s


def follow(nodes: int) -> dict[str, np.ndarray]:
    """The equilibrium path under the support's travel, until Newton stops converging."""
    model = pulled_frame(nodes).assemble()
    ground = np.array([0.2 * lee.L_FRAME, lee.L_FRAME - DEPTH, 0.0])
    start = ground + np.array([0.0, DEPTH, 0.0])
    e, lam = model.e0.copy(), np.zeros(len(model.constraints))
    guesses, counts = model.contact_guesses, model.contact_counts
    rows: list[tuple[float, ...]] = []
    t, step = 0.0, STEP
    try:
        while t + step <= 1.0:
            out = model.kernel.static_solve(
                t=t + step, load_factor=1.0, e0=model.e0, rows=model.pattern.rows,
                cols=model.pattern.col_index, e=e, lam=lam, guesses=guesses, counts=counts,
                tol=1e-10, length_scale=model.length_scale, max_iter=25, check_start=False,
                force_scale=lee.LIMIT_REFERENCE * lee.P_UNIT, load_step=1, load_steps=1)
            p = model.probe_positions(out["e"])["load_point"]
            moved = p[1] - start[1] - (rows[-1][2] if rows else 0.0)
            if out["info"] or abs(moved + W_MAX * step) > W_MAX * step:
                # not converged, or jumped to another branch (the spring's stretch changed
                # by more than the support's travel): past the snap-back
                if step < STEP / 2**HALVINGS:
                    break
                step /= 2
                continue
            t += step
            e, lam = out["e"], out["lam"]
            guesses, counts = out["guesses"], out["counts"]
            chord = p - ground
            length = float(np.linalg.norm(chord))
            force = STIFFNESS * (length - (DEPTH - W_MAX * t))        # tension
            pull = -force * chord / length / lee.P_UNIT                 # on the load point
            rows.append((W_MAX * t, *(p - start)[:2], -pull[1], pull[0]))
            step = min(STEP, 2 * step)
    finally:
        model.close()
    w, u, v, load, side = np.array(rows).T
    return {"w": w, "u": u, "v": v, "load": load, "horizontal": side}


def limit(path: dict[str, np.ndarray]) -> float:
    """The largest load on the path, refined by the parabola through it and its
    neighbours in v."""
    i = int(np.argmax(path["load"]))
    v, p = path["v"][i - 1:i + 2], path["load"][i - 1:i + 2]
    a, b, c = np.polyfit(v, p, 2)
    return float(c - b * b / (4 * a))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=31)
    parser.add_argument("--fine", type=int, default=81)
    args = parser.parse_args()
    paths, limits = {}, {}
    for nodes in (args.nodes, args.fine):
        begin = time.perf_counter()
        paths[nodes] = follow(nodes)
        limits[nodes] = limit(paths[nodes])
        print(f"{nodes} nodes: limit {limits[nodes]:.4f} EI/L^2 "
              f"({limits[nodes] / lee.LIMIT_REFERENCE - 1:+.3%} of 18.56), "
              f"{len(paths[nodes]['v'])} points to v = {paths[nodes]['v'][-1]:.4f} m, "
              f"largest horizontal pull {np.abs(paths[nodes]['horizontal']).max():.2e} "
              f"EI/L^2 ({time.perf_counter() - begin:.1f} s)")
    out = {"model": "Lee's frame, tests/test_arc_length.py lee_members, 'cubic' bending, "
                    "pulled by displacement control through a stiff spring",
           "depth": DEPTH, "stiffness": STIFFNESS, "step": STEP * W_MAX,
           "paths": {str(nodes): {"limit_load": limits[nodes], **path}
                     for nodes, path in paths.items()},
           "machine": machine_info()}
    target = HERE.parent / "tests" / "reference" / "lee_frame_displacement.json"
    target.write_text(json.dumps(json_ready(out), indent=1) + "\n")
    print(f"wrote {target}")


if __name__ == "__main__":
    main()
