"""Modal reduction of an FFR model in a prescribed frame (ancfdrv.solvers.ffr_reduced;
issue 23, item 2). References: the full model's constrained modes (ancfdrv.solvers.modal,
an independent eigen-solution on the whole null space) and the kernel's full FFR run of the
same scene (Newmark, the same step)."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from ancfdrv.builders import build_model
from ancfdrv.errors import SolverError
from ancfdrv.io.scene import load_scene
from ancfdrv.runner import run_scene
from ancfdrv.solvers.ffr_reduced import reduce_ffr, simulate
from ancfdrv.solvers.modal import modal_analysis
from ancfdrv.solvers.static import solve_newton

from conftest import INPUTS

BOOM = INPUTS / "boom_luffing.nml"
BASE = ["beam.nodes=10", "solver.t_end=3.0", "solver.static_method=newton",
        "output.xdmf=false"]


def model_and_static(*extra: str):
    model = build_model(load_scene(BOOM, [*BASE, *extra]))
    return model, solve_newton(model, tol=1e-12, max_iter=50)


def full_history(tmp_path, *extra: str) -> tuple[np.ndarray, np.ndarray]:
    out = tmp_path / "full.h5"
    run_scene(BOOM, [*BASE, *extra], out, progress=False)
    with h5py.File(out) as h5:
        return h5["dynamic/time"][()], h5["dynamic/deflection/tip"][()][:, 1]


def test_kept_modes_are_exact():
    model, static = model_and_static()
    full = modal_analysis(model, 6, static=static)
    for modes in (2, 5):
        reduced = reduce_ffr(model, static, modes)
        ritz = np.sort(reduced.omega_squared)[:modes]
        frequency = np.sqrt(ritz) / (2.0 * np.pi)
        # measured: 1e-9 relative (the eigen-solutions' round-off)
        assert frequency == pytest.approx(full.frequency[:modes], rel=1e-7)
        # the Ritz values above the kept modes bound the full model's from above
        assert np.sort(reduced.omega_squared)[modes] >= reduced.kept_omega_squared[-1]


@pytest.mark.parametrize("extra", [(), ("beam.geometric_stiffness=true",)])
def test_reduced_history_converges_to_the_full_ffr_run(tmp_path, extra):
    # m = 50 kg, 10 nodes, 3 s (start and luffing): error of the reduced tip sag against the
    # kernel's full FFR run, in % of its sag range; measured without P-delta 0.0124% (1 mode),
    # 2e-4% (4 modes) on the 28-node 10 s run; here 2.7e-4 and 3.8e-6 of the range without
    # P-delta, 1.6e-3 and 7.1e-5 with it (its axial-force patterns among the corrections)
    t, full = full_history(tmp_path, *extra)
    model, static = model_and_static(*extra)
    errors = []
    for modes in (1, 4):
        out = simulate(reduce_ffr(model, static, modes), 3.0, 1e-3)
        assert np.allclose(out["time"], t)
        errors.append(np.max(np.abs(out["tip"][:, 1] - full)) / np.ptp(full))
    print("\nerrors (fraction of the sag range), modes 1 and 4:", errors)
    assert errors[1] < errors[0]
    assert errors[1] < 2e-4


def test_refuses_a_frame_that_does_not_turn():
    model = build_model(load_scene(INPUTS / "cantilever.nml", []))
    with pytest.raises(SolverError, match="one frame, turned by a drive"):
        reduce_ffr(model, solve_newton(model), 2)


@pytest.mark.parametrize("extra", [(), ("beam.geometric_stiffness=true",)])
def test_kernel_stepper_matches_the_python_steps(extra):
    # the Fortran loop (one LU while the frame's rate and acceleration stay, simplified Newton
    # for P-delta) against the plain numpy steps (full Newton); measured 2e-16 m (linear) and
    # 8e-14 m (P-delta, converged to 1e-12)
    model, static = model_and_static(*extra)
    reduced = reduce_ffr(model, static, 3)
    fast = simulate(reduced, 3.0, 1e-3, tol=1e-12)
    slow = simulate(reduced, 3.0, 1e-3, tol=1e-12, engine="python")
    assert np.max(np.abs(fast["tip"] - slow["tip"])) < 1e-11
