"""What jacobian_reuse's Newton acceptance leaves unconverged (issue 26): a step accepted
on the error estimate (after its second correction on the contraction bound learned from
earlier steps, after a later one on the step's own ratios) must leave an error below
``newton_tol x L`` in every coordinate.

The reference is the exact solution of the same step: from the same state (t, e, e', a,
e'', lambda, contact guesses) a second model of the same scene takes the step with full
Newton (``jacobian = 'iteration'``, a new tangent at every iterate) to newton_tol = 1e-13,
three orders below the tolerance checked, so the difference of the two step results is the
accepted state's true remaining error (a local quantity: each step starts from the state
the reuse run itself reached). And the acceptance must pay: the corrections per step are
counted (not timed) against the figures before it (``benchmarks/step_instructions.py``:
the 5-node cable pendulum 2.816 corrections per step)."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.runner import dynamic_settings, run_scene
from ancfdrv.solvers.dynamic import TimeIntegrator, initial_acceleration

from conftest import INPUTS

PENDULUM = ["beam.bending=cable", "scene.planar=xy", "solver.dt=1e-3", "output.xdmf=.false."]
CASES = {
    # the flexible pendulum at the peer harness's 5-node level (its ringing e'' is what the
    # recurrence predictor follows) for 0.7 s: the swing through the bottom, where the
    # steps take 2 and 3 corrections
    "pendulum5": (INPUTS / "hard" / "pendulum.nml", PENDULUM + ["beam.nodes=5",
                                                                "solver.t_end=0.7"]),
    # the luffing boom (a drive: the prescribed luffing angle, a pin and a driven frame;
    # the reuse matrix carried through a large rotation), large-deformation cable
    "boom_drive": (INPUTS / "boom_luffing.nml",
                   ["scene.formulation=nonlinear", "solver.static_method=newton",
                    "beam.bending=cable", "scene.planar=xy", "beam.nodes=4",
                    "loads.tip_mass=50", "output.xdmf=.false.", "solver.t_end=0.6"]),
    # the W = 4 rad/s spin-up (a prescribed frame rotation), 11 nodes, dt 5e-3, through
    # the end of the spin-up (4 s: from 2 s on its steps take two corrections and more)
    "spinup": (INPUTS / "hard" / "spinup.nml",
               ["spinup.omega=4", "beam.bending=cable", "scene.planar=xy", "beam.nodes=11",
                "output.xdmf=.false.", "solver.t_end=4.0"]),
}
REFERENCE_TOL = 1e-13


def remaining_errors(scene_path, overrides) -> tuple[np.ndarray, np.ndarray, float]:
    """Each step of the scene's own run (jacobian 'reuse') against the exact solution of
    the same step from the same state: the max |e - e_exact| of each step, the step's
    Newton corrections and the tolerance newton_tol x L."""
    scene = load_scene(scene_path, overrides)
    settings = dynamic_settings(scene)
    assert settings.jacobian == "reuse"
    model, exact_model = build_model(scene), build_model(scene)
    try:
        integrator = TimeIntegrator(model, settings)
        exact_settings = dynamic_settings(scene)
        exact_settings.jacobian, exact_settings.tol = "iteration", REFERENCE_TOL
        exact_integrator = TimeIntegrator(exact_model, exact_settings)
        v0 = np.zeros(model.ndof)
        a0, lam0 = initial_acceleration(model, model.e0, v0, 0.0)
        state = integrator.state(0.0, model.e0, v0, a0, lam0)
        nsteps = int(round(settings.t_end / settings.dt))
        errors, corrections = np.zeros(nsteps), np.zeros(nsteps, dtype=int)
        for step in range(nsteps):
            start = {key: np.array(state[key]) for key in ("e", "v", "a", "accel", "lam")}
            t0 = state["t"]
            chunk, info, _ = integrator.advance(state, 1)
            assert info == 0
            exact = exact_integrator.state(t0, start["e"], start["v"], start["a"],
                                           start["lam"])
            exact["accel"] = start["accel"]
            _, exact_info, _ = exact_integrator.advance(exact, 1)
            assert exact_info == 0
            errors[step] = np.abs(state["e"] - exact["e"]).max()
            corrections[step] = chunk.stats[0, 0]
        return errors, corrections, settings.tol * model.length_scale
    finally:
        model.close()
        exact_model.close()


@pytest.mark.parametrize("case", list(CASES))
def test_accepted_steps_leave_less_than_the_tolerance(case):
    """Every step's true remaining error is below newton_tol x L, the steps the estimate
    ends after two corrections among them (measured, largest / (newton_tol L): pendulum
    0.40 (295 of 700 steps end after 2 corrections), the boom 0.39 (83 of 600), the
    spin-up 0.31 (149 of 800)). It fails
    where the bound does not hold: before the steadiness condition the boom's irregular
    contraction (ratios from 1e-3 to 0.3 between steps) left up to 4.6 x newton_tol L in 9
    steps accepted after two corrections on the bound."""
    errors, corrections, limit = remaining_errors(*CASES[case])
    worst = int(np.argmax(errors))
    print(f"\n{case}: {len(errors)} steps, {corrections.mean():.3f} corrections per step, "
          f"{(corrections == 2).sum()} ended after 2; largest remaining error "
          f"{errors[worst]:.2e} = {errors[worst] / limit:.3f} x newton_tol L (step {worst + 1}, "
          f"{corrections[worst]} corrections)")
    assert errors.max() < limit


def test_the_pendulum_ends_its_steps_in_fewer_corrections(tmp_path):
    """The 5-node cable pendulum, 1 s at dt 1e-3 (the peer harness's level; counts, not
    times): 2816 corrections before issue 26, 2187 with the recurrence predictor alone,
    1843 with the acceptance at the second correction too; the single factorization of
    the run stays single, and the swing is the same (the tip at 1 s within 1e-8 m of the
    run before issue 26, measured 2.0e-9: both are converged to 1.2e-10 m per step; the
    5-node model's own discretization error is of the order of centimetres)."""
    out = tmp_path / "pendulum.h5"
    run_scene(INPUTS / "hard" / "pendulum.nml", PENDULUM + ["beam.nodes=5", "solver.t_end=1.0"],
              out, progress=False)
    with h5py.File(out) as h5:
        corrections = h5["dynamic/newton_iterations"][1:]
        factorizations = int(h5["dynamic/factorizations"][()].sum())
        tip = h5["dynamic/probes/tip"][-1]
    print(f"\n{corrections.sum()} corrections for {len(corrections)} steps, "
          f"{factorizations} factorization(s), tip {tip}")
    assert len(corrections) == 1000
    assert corrections.sum() <= 1900
    assert factorizations == 1
    # the tip at 1 s of main 72ffb4d (before issue 26)
    np.testing.assert_allclose(tip[:2], [-1.1841736990161862, -0.12987473172600178], atol=1e-8)
