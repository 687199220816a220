"""Step-size control, error-controlled steps and round-off-aware convergence (issue 26),
and the stagnation and divergence test of every Newton loop (issue 24 item 2).

References:
* the rigid pendulum's Lagrange equation integrated by DOP853 at rtol 1e-10
  (tests/reference/mechanisms.py, written without ancfdrv);
* the flexible double pendulum (benchmarks/_stability_models.py) at a step ten times finer
  (a converged reference in time: at dt = 1e-3 it is within 6.6e-5 m of one at 1e-4,
  benchmarks/results/stability_after_double.md);
* invariants: the energy balance of generalized-alpha at rho_inf = 1 (no numerical damping),
  the user's time grid, the counts in /dynamic and /counters;
* the boom statics by the split iteration (seed 000, a different method) and by Newton's
  third iteration.
"""
from __future__ import annotations

import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv import System
from ancfdrv.builders import build_model
from ancfdrv.cli import main
from ancfdrv.errors import SolverError
from ancfdrv.io.scene import load_scene
from ancfdrv.solvers.dynamic import DynamicSettings, integrate
from ancfdrv.solvers.static import solve_newton, solve_split

from conftest import INPUTS

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from _stability_models import double_pendulum  # noqa: E402
from reference import mechanisms as mech  # noqa: E402

G = 9.81


def _run(model, settings):
    rows = []
    try:
        integrate(model, settings, model.e0, sink=rows.append, progress=False)
        failure = ""
    except SolverError as exc:
        failure = str(exc)
    cat = {name: np.concatenate([getattr(r, name) for r in rows])
           for name in ("time", "probes", "energy")}
    return cat, failure, dict(model.counters), rows


def _double(dt, t_end, rho, **kw):
    # the Jacobian policy these figures were measured with ('step'; the default is 'reuse'
    # since issue 25, with which the uncut run fails at t = 0.45 s instead)
    model = double_pendulum().assemble()
    try:
        return _run(model, DynamicSettings.generalized_alpha(dt, t_end, rho, tol=1e-10,
                                                             max_newton=10, jacobian="step",
                                                             **kw))
    finally:
        model.close()


@pytest.fixture(scope="module")
def double_reference():
    out, failure, _, _ = _double(1e-3, 1.0, 1.0)
    assert not failure
    return out


def test_cut_steps_carry_the_double_pendulum_through(double_reference):
    """The flexible double pendulum at dt = 1e-2, rho_inf = 1 (no cuts allowed: Newton fails
    at t = 0.43 s) completes its first second with cut steps: the cuts are counted in the
    counters and in the rows, the rows stay on the grid k dt, the tip stays within 5e-3 m
    of the run at dt = 1e-3 (measured 2.8e-3 m against dt = 2.5e-5; a second-order method at
    ten times the step), and the energy balance holds to 2e-3 of the largest kinetic energy
    (rho_inf = 1 conserves it; measured 7.8e-4)."""
    _, failure, _, _ = _double(1e-2, 1.0, 1.0, dt_min=1e-2)
    assert "t = 0.43 s" in failure
    out, failure, counters, rows = _double(1e-2, 1.0, 1.0)
    assert not failure
    t = out["time"]
    np.testing.assert_allclose(t, np.arange(101) * 1e-2, rtol=0, atol=1e-12)
    cuts = sum(int(r.cuts.sum()) for r in rows if r.cuts is not None)
    assert counters["step_cuts"] == cuts > 0
    assert counters["steps_taken"] > 100
    ref = double_reference
    tip = out["probes"][:, 1, :]
    ref_tip = np.stack([np.interp(t, ref["time"], ref["probes"][:, 1, k]) for k in range(3)], 1)
    assert np.abs(tip - ref_tip).max() < 5e-3
    energy = out["energy"]
    balance = energy[:, 4] - energy[0, 4]
    assert np.abs(balance).max() < 2e-3 * energy[:, 0].max()


def _rigid_pendulum(**kw):
    mass, length = 3.0, 1.2
    s = System("pendulum")
    e = np.array([1.0, 0.0, 0.0])
    transverse = mass * length**2 / 12.0
    s.rigid_body("rod", mass=mass, inertia=transverse * (np.eye(3) - np.outer(e, e))
                 + 1e-4 * transverse * np.outer(e, e), position=(length / 2, 0, 0))
    s.joint("pin", "revolute", "ground", "rod", point=(0, 0, 0), axis=(0, 0, 1))
    s.load("g", "gravity", vector=(0, -G, 0))
    s.probe("tip", "rod", (length, 0, 0))
    model = s.assemble()
    try:
        out, failure, counters, _ = _run(model, DynamicSettings.generalized_alpha(
            0.05, 1.2, 0.8, tol=1e-10, max_newton=20, **kw))
    finally:
        model.close()
    assert not failure
    ref = mech.pendulum(out["time"], 0.0, 0.0, length, mass, gravity=(0.0, -G))
    return np.abs(out["probes"][:, 0, :2] - ref.tip).max(), counters["steps_taken"]


def test_adaptive_steps_meet_the_tolerance_they_are_given():
    """step = 'adaptive' on the rigid pendulum (output every 0.05 s, the largest step; steps
    dt / 2^k): the error against the ODE falls with the tolerance (a local error ~ h^3 held
    at tol gives a global error ~ tol^(2/3), 21.5 for a factor 100; measured 15: 5.1e-4 m at
    1e-5, 3.3e-5 m at 1e-7), the steps rise as tol^(-1/3) (4.6; measured 219 -> 772), and
    at 1e-7 the tip is within 4e-5 m. On this uniform motion the cost is about that of fixed
    steps of the same accuracy (dt = 5e-3: 3.4e-4 m in 240 steps; dt = 2e-3: 5.5e-5 m in
    600)."""
    coarse, coarse_steps = _rigid_pendulum(step="adaptive", tolerance=1e-5)
    fine, fine_steps = _rigid_pendulum(step="adaptive", tolerance=1e-7)
    assert 8.0 < coarse / fine < 50.0
    assert 2.5 < fine_steps / coarse_steps < 8.0
    assert fine < 4e-5


def test_unreachable_tolerances_end_with_exit_3(tmp_path, capsys):
    """newton_tol = 1e-300 with a practically unlimited iteration count (issue 24 item 2):
    dynamics and statics end with exit 3 and say that Newton stalled at the round-off
    floor; the file keeps the rows computed (here the initial row) and says 'failed'."""
    out = tmp_path / "p.h5"
    code = main(["run", str(INPUTS / "hard" / "pendulum.nml"), "--set", "solver.newton_tol=1e-300",
                 "--set", "solver.max_newton=100000000", "--set", "solver.t_end=0.01",
                 "-o", str(out)])
    assert code == 3
    assert "stalled at the round-off floor" in capsys.readouterr().err
    with h5py.File(out) as h5:
        assert h5["dynamic/time"].shape == (1,) and h5["dynamic"].attrs["status"] == "failed"
    code = main(["run", str(INPUTS / "boom_static.nml"), "--set", "solver.static_method=newton",
                 "--set", "solver.tol=1e-300", "--set", "solver.max_iter=100000000",
                 "-o", str(tmp_path / "s.h5")])
    assert code == 3
    assert "stalled at the round-off floor" in capsys.readouterr().err


def test_newton_failure_scene_completes_with_cut_steps(tmp_path):
    """inputs/hard/newton_failure.nml (one Newton correction per step) without its
    dt_min = dt: the steps that fail at 0.949 s are cut and the run completes its first
    second on the grid; /dynamic/step_cuts, /counters and the attributes agree, and every
    row reached through cuts has a smaller step_size than dt."""
    out = tmp_path / "nf.h5"
    assert main(["run", str(INPUTS / "hard" / "newton_failure.nml"), "--set",
                 "solver.dt_min=0", "--set", "solver.t_end=1.0", "-o", str(out)]) == 0
    with h5py.File(out) as h5:
        t = h5["dynamic/time"][()]
        size, cuts = h5["dynamic/step_size"][()], h5["dynamic/step_cuts"][()]
        substeps = h5["dynamic/substeps"][()]
        total = int(h5["counters"].attrs["step_cuts"])
        attrs = dict(h5["dynamic"].attrs)
    np.testing.assert_allclose(t, np.arange(1001) * 1e-3, rtol=0, atol=1e-12)
    assert cuts.sum() == total == attrs["step_cuts"] > 0
    assert np.all(size[cuts > 0] < 1e-3) and np.all(substeps[cuts > 0] > 1)
    assert attrs["smallest_step"] == size[1:].min()


def test_boom_statics_converge_without_the_round_off_iteration():
    """The 28-node FFR boom statics (inputs/boom_static.nml): Newton stops after 2
    iterations ('roundoff': its relative residual 3.0e-10 lies below the floor estimate
    eps |||K| |e||| / scale = 3.5e-9 and its second correction was below sqrt(tol)); a third
    iteration (before issue 26) gave a residual of 5.9e-10, no better; the split iteration
    (another method) agrees to 1e-9 m."""
    scene = load_scene(INPUTS / "boom_static.nml", [])
    model = build_model(scene)
    try:
        newton = solve_newton(model, tol=1e-10, max_iter=50)
        assert newton.iterations == 2 and newton.extra["converged_by"] == "roundoff"
        split = solve_split(model, tol=1e-10, max_iter=50)
    finally:
        model.close()
    assert np.abs(newton.e - split.e).max() < 1e-9


def test_adaptive_step_at_dt_min_ends_the_run_with_exit_3(tmp_path, capsys):
    """Issue 35: a tolerance no step can meet (1e-15 of the length) on the 5-node pendulum.
    The control halves the step down to dt_min; the sub-step that ends an interval there is
    t_target - t and came out 1.9e-11 of a step longer than dt_min (the round-off of the
    sum t), was rejected, cut back to the same remainder, forever (Ctrl-C could not stop
    it). Now it is at dt_min: the run ends with exit 3 saying the tolerance cannot be met
    at solver.dt_min, and the file keeps its rows (the initial one at least, on the grid)
    with status 'failed'."""
    out = tmp_path / "p.h5"
    code = main(["run", str(INPUTS / "hard" / "pendulum.nml"), "--set", "beam.nodes=5",
                 "--set", "solver.t_end=0.05", "--set", "solver.step=adaptive",
                 "--set", "solver.tolerance=1e-15", "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 3, err
    assert "the tolerance cannot be met" in err and "solver.dt_min" in err
    assert "raise solver.tolerance" in err
    with h5py.File(out) as h5:
        t = h5["dynamic/time"][()]
        assert h5["dynamic"].attrs["status"] == "failed"
    assert len(t) >= 1
    np.testing.assert_allclose(t, np.arange(len(t)) * 5e-4, rtol=0, atol=1e-12)


def test_a_budget_ending_inside_an_output_interval_resumes_it_exactly():
    """The kernel's control tries at most a call's budget of steps (so a stop request is
    answered inside a long output interval) and resumes the interval at the next call: an
    adaptive run of the pendulum in calls of one try each gives the rows, statistics and
    state of the run in one call, bit for bit (the same computation), and the rows stay on
    the grid t0 + k dt with more substeps than rows."""
    from ancfdrv.solvers.dynamic import TimeIntegrator, initial_acceleration
    mass, length = 3.0, 1.2
    s = System("pendulum")
    s.rigid_body("rod", mass=mass, inertia=np.diag([1e-4, 1.0, 1.0]) * mass * length**2 / 12,
                 position=(length / 2, 0, 0))
    s.joint("pin", "revolute", "ground", "rod", point=(0, 0, 0), axis=(0, 0, 1))
    s.load("g", "gravity", vector=(0, -G, 0))
    model = s.assemble()
    try:
        runs = []
        for budget in (None, 1):
            settings = DynamicSettings(dt=0.05, t_end=0.2, step="adaptive", tolerance=1e-7)
            integrator = TimeIntegrator(model, settings)
            a0, lam0 = initial_acceleration(model, model.e0, np.zeros(model.ndof), 0.0)
            state = integrator.state(0.0, model.e0, np.zeros(model.ndof), a0, lam0)
            chunks = []
            calls = 0
            while sum(len(c.time) for c in chunks) < 4:
                chunk, info, _ = integrator.advance(state, 4, budget)
                assert info == 0
                chunks.append(chunk)
                calls += 1
            runs.append((np.concatenate([c.time for c in chunks]),
                         np.concatenate([c.energy for c in chunks]),
                         np.concatenate([c.substeps for c in chunks]),
                         np.concatenate([c.stats for c in chunks]), state["e"].copy(), calls))
        (t1, en1, sub1, st1, e1, calls1), (t2, en2, sub2, st2, e2, calls2) = runs
        assert calls1 == 1 and calls2 >= sub1.sum() > 4   # (a call per step tried)
        np.testing.assert_array_equal(t1, np.arange(1, 5) * 0.05)   # t0 + k dt
        for x, y in ((t1, t2), (en1, en2), (sub1, sub2), (st1, st2), (e1, e2)):
            np.testing.assert_array_equal(x, y)
    finally:
        model.close()


def test_dt_min_longer_than_dt_is_refused_by_the_api():
    """solver.dt_min > dt (accepted before issue 35): System.simulate and integrate refuse
    it with an InputError naming both (the namelist's refusal: tests/test_bad_input.py)."""
    from ancfdrv.errors import InputError
    s = System("pendulum")
    s.rigid_body("rod", mass=1.0, inertia=np.eye(3) * 0.1, position=(0.5, 0, 0))
    s.joint("pin", "revolute", "ground", "rod", point=(0, 0, 0), axis=(0, 0, 1))
    with pytest.raises(InputError, match="dt_min = .* is longer than dt ="):
        s.simulate(0.01, 1e-3, dt_min=2e-3)
    model = s.assemble()
    try:
        with pytest.raises(InputError, match="integrate: dt_min = .* is longer than dt ="):
            integrate(model, DynamicSettings(dt=1e-3, t_end=0.01, dt_min=2e-3), model.e0,
                      progress=False)
    finally:
        model.close()


def test_cut_steps_stay_on_the_ladder_of_dt_over_powers_of_two(tmp_path):
    """inputs/hard/pendulum.nml, 17 nodes, dt = 5e-3, rho_inf = 0.8 (issue 39's 'ok and
    wrong' run) cuts its step 70 times by 4.7 s. Each step the control takes is dt / 2^k, or
    such a step stretched by round-off onto its output time (a few ulps of t); a cut halves
    that ladder step, so no step falls below dt_min = dt / 1024. Before, a cut halved the
    stretched step: the control's step left the ladder and the shortfall grew with each cut
    until every output interval from t = 4.655 s ended with a sliver step of 5.6e-12 s."""
    out = tmp_path / "pendulum.h5"
    dt = 5e-3
    assert main(["run", str(INPUTS / "hard" / "pendulum.nml"), "--set", "beam.nodes=17",
                 "--set", f"solver.dt={dt}", "--set", "solver.rho_inf=0.8", "--set",
                 "solver.t_end=4.7", "--set", "output.xdmf=.false.", "--set",
                 "output.answers=.false.", "-o", str(out)]) == 0
    with h5py.File(out) as h5:
        size, cuts = h5["dynamic/step_size"][1:], h5["dynamic/step_cuts"][1:]
    assert cuts.sum() > 20
    assert size.min() >= dt / 1024
    ladder = dt / 2.0 ** np.round(np.log2(dt / size))
    # the stretch onto the grid time: a few ulps of t <= 4.7 s
    np.testing.assert_allclose(size, ladder, rtol=0, atol=8 * np.finfo(float).eps * 4.7)
