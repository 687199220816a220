#!/usr/bin/env python
"""Cost of a modal analysis of the 28-node crane boom (inputs/boom_static.nml, SPEC
section 5) against its static solve and against a transient run, per eigensolver.

For 'ffr' and 'nonlinear', and the dense (null space + LAPACK) and sparse (shift-invert
Lanczos: MUMPS + ARPACK) solvers, this times (best of --repeats, time.perf_counter):

* the static equilibrium (Newton) the modes are about;
* the linearization (tangent, constraint Hessians, mass, constraint Jacobian);
* the eigensolution of the first --modes modes;

and prints the first frequencies (they must agree between the solvers). Usage:
    .venv/bin/python benchmarks/modal_boom.py [--modes 6] [--repeats 5]
The machine is shared: say how loaded it was (uptime) when quoting the numbers.
"""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.solvers.modal import linearize, modal_analysis
from ancfdrv.solvers.static import solve_newton

ROOT = Path(__file__).resolve().parents[1]


def best(fn, repeats):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--modes", type=int, default=6)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f} (2 cores)")
    for formulation in ("ffr", "nonlinear"):
        scene = load_scene(ROOT / "inputs" / "boom_static.nml",
                           [f"scene.formulation={formulation}", "solver.static_method=newton",
                            "beam.nodes=28"])
        model = build_model(scene)
        t_static, static = best(lambda: solve_newton(model, tol=1e-10), args.repeats)
        t_lin, _ = best(lambda: linearize(model, static.e, static.lam), args.repeats)
        for solver in ("dense", "sparse"):
            t_modal, modes = best(lambda: modal_analysis(model, args.modes, static=static,
                                                         solver=solver), args.repeats)
            print(f"{formulation:9s} {solver:6s} ndof {model.ndof}: static {1e3 * t_static:7.1f} "
                  f"ms, linearization {1e3 * t_lin:6.1f} ms, modal analysis (linearization + "
                  f"eigen) {1e3 * t_modal:6.1f} ms; eigen {1e3 * modes.timing['eigen']:6.1f} "
                  f"ms; f = {np.array2string(modes.frequency, precision=4)} Hz")
        model.close()


if __name__ == "__main__":
    main()
