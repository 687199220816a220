"""Regression gate of the kernel's static Newton (issue 25 item 4): every scene's static
solve (analysis 'static', 'static+dynamic', settled starts, the modal analysis's static
state) through the kernel's Newton (solvers/static.py solve_newton) and through the Python
reference (tests/reference/static_newton.py solve_newton_python), compared: the largest difference of the coordinates
relative to the largest displacement |e - e0|, of the multipliers relative to the
largest multiplier (counted when that is above 1e-9), and the iteration counts. The run stops after the (first) static
solve; nothing is written but a temporary result file.

    .venv/bin/python benchmarks/static_kernel_gate.py [scene.nml ...]
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

import ancfdrv.runner as runner
import ancfdrv.solvers.modal as modal
import ancfdrv.solvers.static as static
from ancfdrv import cli

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from reference.static_newton import solve_newton_python  # noqa: E402  (the tests' reference)

KERNEL, PYTHON = static.solve_newton, solve_newton_python
INTEGRATE = runner.integrate


class _Stop(BaseException):
    """Ends a run after its static solve."""


def _static_of(scene: Path, solver) -> tuple | str:
    """(e, lam, e0, iterations) of the scene's first static Newton solve with the given
    solver, 'none' when the scene has none, or the error text."""
    captured = {}

    def wrapped(model, **kwargs):
        result = solver(model, **kwargs)
        captured["out"] = (result.e.copy(), result.lam.copy(), model.e0.copy(),
                           result.iterations)
        raise _Stop

    def no_dynamics(*args, **kwargs):
        raise _Stop

    for module in (static, runner, modal):
        module.solve_newton = wrapped
    runner.integrate = no_dynamics
    try:
        with tempfile.TemporaryDirectory() as tmp:
            try:
                code = cli.main(["run", str(scene), "-o", str(Path(tmp) / "out.h5")])
            except _Stop:
                return captured.get("out", "none")
            except SystemExit as stop:
                code = stop.code
        return "none" if code == 0 else f"exit {code}"
    finally:
        for module in (static, runner, modal):
            module.solve_newton = KERNEL
        runner.integrate = INTEGRATE


def main(paths: list[str]) -> int:
    scenes = [Path(p) for p in paths] or sorted(
        [*ROOT.glob("inputs/*.nml"), *ROOT.glob("inputs/general/*.nml"),
         *ROOT.glob("inputs/hard/*.nml")])
    print(f"{'scene':42s} {'de/|d|':>10s} {'dlam/|lam|':>10s} {'max|lam|':>10s} {'it py':>6s} "
          f"{'it kernel':>9s}")
    worst = 0.0
    for scene in scenes:
        old = _static_of(scene, PYTHON)
        new = _static_of(scene, KERNEL)
        name = str(scene.relative_to(ROOT)) if scene.is_relative_to(ROOT) else str(scene)
        if isinstance(old, str) or isinstance(new, str):
            print(f"{name:42s} python: {old if isinstance(old, str) else 'ok'}, "
                  f"kernel: {new if isinstance(new, str) else 'ok'}")
            continue
        (e1, l1, e0, i1), (e2, l2, _, i2) = old, new
        de = np.max(np.abs(e2 - e1)) / max(np.max(np.abs(e1 - e0)), 1e-300)
        dl = np.max(np.abs(l2 - l1), initial=0.0) / max(np.max(np.abs(l1), initial=0.0), 1e-300)
        size = np.max(np.abs(l1), initial=0.0)
        # (multipliers of round-off size, e.g. the unloaded prestress's, are compared in
        # absolute terms only: printed, not counted in the largest difference)
        worst = max(worst, de, dl if size > 1e-9 else 0.0)
        print(f"{name:42s} {de:10.2e} {dl:10.2e} {size:10.2e} {i1:6d} {i2:9d}")
    print(f"largest relative difference {worst:.2e}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
