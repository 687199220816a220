"""The two-leaf spring as a suspension (issue 15): the chassis's bounce against the static
stiffness, the road input's transmissibility against a one-degree-of-freedom model built
from static solves, and the stability matrix of the drop (rho_inf x step x prestress).

References, each independent of the time integration it checks:

* the static stiffness k = dF/dz of the chassis and the static deflection shape, from two
  static Newton solves of the same model with the chassis weight plus and minus 200 N
  (``examples/road_transmissibility.linearize``), and Rayleigh's quotient with that shape;
* the base-excited one-degree-of-freedom model in that shape (same module);
* the numerical frequency of the generalized-alpha method for an undamped oscillator, from
  the eigenvalues of its amplification matrix (Chung and Hulbert 1993), which sets how far
  histories at different steps may drift apart.
"""
from __future__ import annotations

import sys

import h5py
import numpy as np
import pytest

from ancfdrv.results.hdf5 import read_summary
from ancfdrv.runner import run_scene

from conftest import INPUTS, ROOT

sys.path.insert(0, str(ROOT / "examples"))
import road_transmissibility as rt  # noqa: E402

SPRING = INPUTS / "leaf_spring.nml"
WEIGHT = 500.0 * 9.81
THICKNESS = 0.014


def _crossing_frequency(t: np.ndarray, y: np.ndarray) -> float:
    """Frequency from the zero crossings of y (linear interpolation between samples):
    half a period between neighbours, averaged from the first to the last crossing."""
    i = np.nonzero(np.sign(y[1:]) != np.sign(y[:-1]))[0]
    crossings = t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i])
    return (len(crossings) - 1) / 2 / (crossings[-1] - crossings[0])


# -- 1. the bounce resonance and the static stiffness ---------------------------------------
@pytest.mark.parametrize("prestress", [True, False], ids=["prestress", "no_prestress"])
def test_bounce_frequency_is_the_static_stiffness_frequency(prestress, tmp_path):
    """Issue 15, item 3: with friction off and a small amplitude, the resonance lies at the
    frequency of the static stiffness within 2 %.

    The spring is settled under gravity (spring.settle = 'gravity'), friction off, and a
    smooth 0.5 mm road bump (inputs/road/bump.csv, 40 ms) starts a free bounce of 0.18 mm,
    undamped enough to keep its amplitude for the 4 s measured (contact damping only); its
    frequency comes from the zero crossings over 0.3 .. 4 s (10 periods).

    'Static stiffness' is the incremental stiffness k = dF/dz from static solves of the same
    model at the weight +- 200 N: it includes the shackle's tilt and the geometric
    nonlinearity (164.1 kN/m with prestress; the secant W / sag, 167.5 kN/m, is 2 % stiffer
    because the spring softens as it sags, and small oscillations feel the tangent).
    sqrt(k / m) / 2 pi with the chassis's 500 kg is 2.8835 Hz: the bounce (2.8362 Hz) is
    1.6 % lower, within the issue's 2 %. The rest is mass: the static deflection shape moves
    the chassis sideways too (it follows the front eye, 0.156 per unit drop: 500 (1 + 0.156^2)
    = 512 kg) and the leaves and the shackle with it. Rayleigh's quotient with that shape,
    k / phi^T M phi (m_eff = 516.4 kg), gives 2.8373 Hz, 0.04 % above the bounce (an upper
    bound, as Rayleigh's quotient must be: the static shape is not the mode's, and the
    integrator lengthens the period by 3e-5). Asserted: within 2 % of sqrt(k / m) and within
    0.2 % (and not below) of the Rayleigh frequency. The secant frequency sqrt(W / sag / m),
    2.913 Hz with prestress (2.7 % above the bounce), is printed, not asserted: it is not the
    small-amplitude stiffness."""
    overrides = [] if prestress else ["leaf.prestress=.false."]
    lin = rt.linearize(SPRING, overrides)
    effects = "gravity,contact,prestress" if prestress else "gravity,contact"
    out = tmp_path / "bounce.h5"
    run_scene(SPRING, overrides + [f"scene.effects={effects}", "spring.settle=gravity",
                                   "spring.road=table", "spring.road_file=road/bump.csv",
                                   "solver.t_end=4.0", "output.xdmf=.false."],
              out, progress=False)
    with h5py.File(out) as h5:
        t = h5["dynamic/time"][()]
        z = h5["dynamic/deflection/chassis"][:, 2] - h5["static/deflection/chassis"][2]
    late = t >= 0.3
    amplitude = np.abs(z[late]).max()
    bounce = _crossing_frequency(t[late], z[late])
    print(f"\nbounce {bounce:.4f} Hz (amplitude {amplitude * 1e3:.3f} mm); static stiffness "
          f"{lin.stiffness / 1e3:.2f} kN/m: chassis mass {lin.f_chassis:.4f} Hz "
          f"({bounce / lin.f_chassis - 1:+.2%}), Rayleigh (m_eff {lin.effective_mass:.1f} "
          f"kg) {lin.f_rayleigh:.4f} Hz ({bounce / lin.f_rayleigh - 1:+.3%}); secant "
          f"W / sag = {lin.weight / lin.sag / 1e3:.2f} kN/m: {lin.f_secant:.4f} Hz "
          f"({bounce / lin.f_secant - 1:+.2%})")
    assert 1e-4 < amplitude < 1e-3                   # small, and really bouncing
    assert lin.effective_mass > lin.chassis_mass * (1 + lin.dx_dz**2)   # the sideways motion
    assert abs(bounce / lin.f_chassis - 1) < 0.02   # issue 15's criterion
    assert 0.0 < 1 - bounce / lin.f_rayleigh < 2e-3


# -- 2. the road input: transmissibility off the resonance ------------------------------------
@pytest.fixture(scope="module")
def quick_sweep(tmp_path_factory):
    return rt.run("quick", out=tmp_path_factory.mktemp("road"), jobs=2, keep_runs=True)


def test_road_transmissibility_quick_sweep_matches_one_dof_model(quick_sweep):
    """examples/road_transmissibility.py --quick: the shipped road scene
    (inputs/leaf_spring_road.nml) at two road frequencies below the resonance, friction off
    and on, 8 s each (two processes). The chassis's steady amplitude over the road's matches
    the base-excited one-degree-of-freedom model in the static deflection shape with
    Kelvin-Voigt damping c = tau k, |1 + (m_c / m_eff) r^2 / (1 - r^2 + i tau omega)|, within
    1 % (measured 0.03 % at 1.5 Hz, 0.13 % at 2 Hz; above the resonance the model does
    not hold, see the example's docstring); the steady-state amplitude changes by less than
    1 % between the last two windows; friction changes it by less than 1 % at these slip speeds
    (about 0.1 mm/s, where the regularized friction is a weak viscous damper); the energy
    balance (with the drive's and the material damping's work) closes to 1e-3 of the
    chassis's vibration energy."""
    report = quick_sweep
    for path in report.files:
        assert path.is_file() and path.stat().st_size > 0, path
        if path.suffix == ".h5":
            assert read_summary(path)["status"] == "ok"
    lin = report.linearization
    rows = {(r["frequency"], r["friction"]): r for r in report.rows}
    assert len(rows) == 2 * len(rt.QUICK.frequencies)
    for f in rt.QUICK.frequencies:
        off, on = rows[(f, False)], rows[(f, True)]
        expected = float(lin.transmissibility(f))
        print(f"\n{f} Hz: transmissibility {off['transmissibility']:.4f} (friction on "
              f"{on['transmissibility']:.4f}), one-DOF model {expected:.4f}, settling "
              f"{off['settling']:+.1e}")
        assert off["transmissibility"] == pytest.approx(expected, rel=0.01)
        assert on["transmissibility"] == pytest.approx(off["transmissibility"], rel=0.01)
        for row in (off, on):
            assert abs(row["settling"]) < 0.01
            vibration = 0.5 * lin.stiffness * row["chassis_amplitude"] ** 2
            assert row["energy_balance"] < 1e-3 * vibration
        assert off["friction_work"] == 0.0 < on["friction_work"]


# -- 3. the stability matrix --------------------------------------------------------------------
#: 2.5 s: the drop's first impact (0.175 s, the deepest penetration) and seven bounces, so
#: the phase drift the histories are compared on (linear in t) is measured over as many
#: periods as a reader needs (issue 15 asked for 5 s; the half keeps the suite's time)
RHO, STEPS, T_END = (0.8, 1.0), (1e-3, 5e-4), 2.5


def _alpha_frequency(rho: float, h: float, omega: float) -> float:
    """Numerical angular frequency of the generalized-alpha method (Chung-Hulbert parameters
    of ``DynamicSettings.generalized_alpha``) for x'' + omega^2 x = 0: the argument of the
    principal eigenvalue of its amplification matrix over h."""
    am, af = (2 * rho - 1) / (rho + 1), rho / (rho + 1)
    gamma = 0.5 - am + af
    beta = 0.25 * (gamma + 0.5) ** 2
    w2 = omega * omega
    # unknowns (x, v, a) at n+1 from those at n: the equation of motion at the alpha
    # points and Newmark's two updates
    lhs = np.array([[w2 * (1 - af), 0.0, 1 - am], [1.0, 0.0, -beta * h * h],
                    [0.0, 1.0, -gamma * h]])
    rhs = np.array([[-w2 * af, 0.0, -am], [1.0, h, h * h * (0.5 - beta)],
                    [0.0, 1.0, h * (1 - gamma)]])
    eig = np.linalg.eigvals(np.linalg.solve(lhs, rhs))
    return float(np.abs(np.angle(eig[np.argmax(np.abs(eig.imag))])) / h)


@pytest.fixture(scope="module")
def stability_matrix(tmp_path_factory):
    """inputs/leaf_spring.nml (the drop from the settled start, T_END, friction on) for
    rho_inf in {0.8, 1.0} x dt in {1, 0.5} ms x prestress on and off: 8 runs."""
    out = tmp_path_factory.mktemp("matrix")
    runs = {}
    for prestress in (True, False):
        for rho in RHO:
            for dt in STEPS:
                path = out / f"p{int(prestress)}_rho{rho}_dt{dt}.h5"
                run_scene(SPRING, [f"solver.rho_inf={rho}", f"solver.dt={dt}",
                                   f"leaf.prestress={'.true.' if prestress else '.false.'}",
                                   f"solver.t_end={T_END}", "output.xdmf=.false."],
                          path, progress=False)
                with h5py.File(path) as h5:
                    runs[(prestress, rho, dt)] = dict(
                        status=read_summary(path)["status"], t=h5["dynamic/time"][()],
                        z=h5["dynamic/deflection/chassis"][:, 2],
                        settled=h5["static/deflection/chassis"][2],
                        penetration=h5["dynamic/contact/penetration"][()].max(),
                        balance=np.abs(h5["dynamic/energy/balance"][()]).max(),
                        friction=-h5["dynamic/energy/friction_work"][-1])
    return runs


@pytest.mark.parametrize("prestress", [True, False], ids=["prestress", "no_prestress"])
def test_stability_matrix_histories_agree_within_the_time_step_error(stability_matrix,
                                                                      prestress):
    """Issue 15, item 5: every run completes and the chassis histories agree.

    The tolerance is the generalized-alpha method's own phase error: the chassis bounces at
    f = 2.84 Hz with amplitude A (half its range), and a method whose numerical frequency is
    omega_h drifts in phase by (omega_h - omega) t, so two runs differ by up to
    A t_end |omega_h1 - omega_h2| (0.028 mm for rho 0.8, 1 ms against rho 1.0, 0.5 ms over
    2.5 s; the rho difference alone is 0.0005 mm). Each run is compared with the finest (rho 1.0,
    0.5 ms): within 1.25 times that estimate plus 2 um (nonlinearity, friction, Newton's
    tolerance), and the 1 ms runs' difference is at least half of it (the histories converge
    at the method's second order: the difference is the time-step error). Measured over
    2.5 s: 0.023 .. 0.027 mm on a 59 mm range (0.89 .. 0.93 of the estimate; over 5 s
    0.044 .. 0.052 mm, 0.85 .. 0.94); rho 0.8 against 1.0 at 0.5 ms: 0.0005 mm (estimate
    0.0005 mm)."""
    runs = {k[1:]: v for k, v in stability_matrix.items() if k[0] == prestress}
    assert all(r["status"] == "ok" and r["t"][-1] == pytest.approx(T_END) for r in runs.values())
    finest = runs[(1.0, 5e-4)]
    amplitude = 0.5 * np.ptp(finest["z"])
    omega = 2 * np.pi * _crossing_frequency(finest["t"], finest["z"] - finest["z"].mean())
    reference = _alpha_frequency(1.0, 5e-4, omega)
    for (rho, dt), run in runs.items():
        if (rho, dt) == (1.0, 5e-4):
            continue
        difference = np.abs(np.interp(finest["t"], run["t"], run["z"]) - finest["z"]).max()
        estimate = amplitude * T_END * abs(_alpha_frequency(rho, dt, omega) - reference)
        print(f"\nprestress {prestress}, rho {rho}, dt {dt}: {difference * 1e3:.4f} mm "
              f"(estimate {estimate * 1e3:.4f} mm) of a {2e3 * amplitude:.1f} mm range")
        assert difference < 1.25 * estimate + 2e-6
        if dt == 1e-3:
            assert difference > 0.5 * estimate


@pytest.mark.parametrize("prestress", [True, False], ids=["prestress", "no_prestress"])
def test_stability_matrix_penetration_and_energy(stability_matrix, prestress):
    """Issue 15, item 5: penetration stays below 15 % of the leaf thickness (measured 1.86
    mm = 13 % with prestress, 1.51 mm = 11 % without, the same in every run) and the energy
    balance (energy + contact damping and friction work) closes to 2e-5 of the chassis's
    weight times its drop (measured 0.5 .. 2.1e-3 J against 287 J: under 8e-6), while
    friction takes 12.3 J (prestress) and 8.2 J over 2.5 s."""
    for (p, rho, dt), run in stability_matrix.items():
        if p != prestress:
            continue
        drop = run["settled"] - run["z"].min()
        print(f"\nrho {rho}, dt {dt}: penetration {run['penetration'] * 1e3:.3f} mm, "
              f"balance {run['balance']:.1e} J, friction {run['friction']:.2f} J")
        assert run["penetration"] < 0.15 * THICKNESS
        assert run["balance"] < 2e-5 * WEIGHT * drop
        assert run["friction"] > 0.0
