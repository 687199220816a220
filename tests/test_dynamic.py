"""Newmark dynamics of the boom and of a cantilever (issue 3), against invariants and
independent references:

* energy: with phi held the total energy is conserved (trapezoidal rule on a conservative
  system); while luffing, energy - drive work - frame work balances to O(dt^2);
* time convergence: observed order 2 against a run with dt/4 of the finest;
* constraints: |Phi| <= 1e-10 at every step;
* statics: started off equilibrium the boom oscillates about the static solution;
* Euler-Bernoulli: the clamped cantilever's first frequency (beta_1 L = 1.8751041...);
* mesh: 22 and 28 nodes agree closely, 4 nodes clearly differ (the paper's finding).
"""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from ancfdrv.reference import analytic
from ancfdrv.cli import main
from ancfdrv.solvers.dynamic import DynamicSettings, integrate
from ancfdrv.history import crossing_frequency, dominant_frequency, fast_length
from ancfdrv.builders import build_model
from ancfdrv.runner import run_scene
from ancfdrv.io.scene import load_scene
from ancfdrv.solvers.static import solve_newton

from conftest import INPUTS

LUFFING = INPUTS / "boom_luffing.nml"


def history(path, *names):
    with h5py.File(path) as h5:
        return [h5[f"dynamic/{n}"][()] for n in names]


def test_energy_conserved_with_angle_held(tmp_path):
    """10^4 steps from the rigid configuration at rest (off equilibrium), phi held."""
    out = tmp_path / "held.h5"
    outcome = run_scene(LUFFING, ["beam.nodes=10", "boom.omega=0", "scene.analysis=dynamic",
                                  "solver.t_end=10"], out)
    assert outcome.dynamic.steps == 10_000
    total, kinetic, violation = history(out, "energy/total", "energy/kinetic",
                                        "constraint_violation")
    drift = np.abs(total - total[0]).max() / kinetic.max()
    print(f"\nenergy drift over 1e4 steps: {drift:.2e} of the peak kinetic energy")
    assert drift < 1e-6
    assert violation.max() < 1e-10


def test_oscillates_about_static_solution(tmp_path):
    run_scene(INPUTS / "boom_static.nml", ["beam.nodes=10"], tmp_path / "s.h5")
    with h5py.File(tmp_path / "s.h5") as h5:
        static_sag = h5["static/deflection/tip"][1]
    out = tmp_path / "held.h5"
    run_scene(LUFFING, ["beam.nodes=10", "boom.omega=0", "scene.analysis=dynamic",
                        "solver.t_end=6"], out)
    (deflection,) = history(out, "deflection/tip")
    sag = deflection[:, 1]
    centre = 0.5 * (sag.max() + sag.min())
    assert centre == pytest.approx(static_sag, rel=0.01)
    assert sag.mean() == pytest.approx(static_sag, rel=0.02)
    # released from the rigid configuration, it swings to about twice the static sag
    assert sag.min() == pytest.approx(2 * static_sag, rel=0.03)


def test_luffing_energy_balance_is_second_order_and_constraints_hold(tmp_path):
    errors = []
    for dt in (2e-3, 1e-3):
        out = tmp_path / f"b{dt}.h5"
        run_scene(LUFFING, ["beam.nodes=10", f"solver.dt={dt}"], out)
        balance, drive, violation, time = history(out, "energy/balance", "energy/drive_work",
                                                  "constraint_violation", "time")
        assert time[-1] == pytest.approx(10.0)
        assert violation.max() < 1e-10
        errors.append(np.abs(balance).max() / np.abs(drive).max())
    print(f"\nenergy balance error relative to the drive work: {errors}")
    assert errors[-1] < 1e-7
    assert np.log2(errors[0] / errors[1]) == pytest.approx(2.0, abs=0.1)


def test_second_order_in_time(tmp_path):
    runs = {}
    for dt in (8e-3, 4e-3, 2e-3, 1e-3, 2.5e-4):
        out = tmp_path / f"o{dt}.h5"
        run_scene(LUFFING, ["beam.nodes=10", f"solver.dt={dt}", "solver.t_end=2.0"], out)
        (deflection,) = history(out, "deflection/tip")
        runs[dt] = deflection[::int(round(8e-3 / dt)), 1]
    reference = runs.pop(2.5e-4)
    errors = np.array([np.abs(y - reference).max() for y in runs.values()])
    orders = np.log2(errors[:-1] / errors[1:])
    print(f"\ntip history errors {errors}, observed orders {orders}")
    assert np.all(orders > 1.8) and orders[-1] == pytest.approx(2.0, abs=0.15)


@pytest.mark.parametrize("nodes,tolerance", [(9, 5e-3), (17, 5e-3)])
def test_cantilever_first_frequency(nodes, tolerance):
    """Released from its static deflection under a tip load, the tip vibrates at the first
    bending frequency (beta_1 L)^2 sqrt(EI / (rho A L^4)) / (2 pi)."""
    cantilever = INPUTS / "cantilever.nml"
    loaded = build_model(load_scene(cantilever, [f"beam.nodes={nodes}"]))
    start = solve_newton(loaded).e
    free = build_model(load_scene(cantilever, [f"beam.nodes={nodes}", "scene.effects="]))
    chunks = []
    integrate(free, DynamicSettings(dt=1e-4, t_end=1.0), start, sink=chunks.append)
    t = np.concatenate([c.time for c in chunks])
    sag = np.concatenate([c.deflections[:, 0, 1] for c in chunks])
    b = 0.05
    omega = analytic.cantilever_frequencies(2.0, 2.1e11, b**4 / 12, 7850.0, b * b, n=1)[0]
    measured = crossing_frequency(t, sag)
    print(f"\n{nodes} nodes: f1 = {measured:.5f} Hz, reference {omega / (2 * np.pi):.5f} Hz")
    assert measured == pytest.approx(omega / (2 * np.pi), rel=tolerance)


@pytest.mark.parametrize("mass", [0, 50])
def test_histories_converge_with_nodes(tmp_path, mass):
    sags = {}
    for nodes in (4, 22, 28):
        out = tmp_path / f"n{nodes}.h5"
        run_scene(LUFFING, [f"beam.nodes={nodes}", f"loads.tip_mass={mass}"], out)
        (deflection,) = history(out, "deflection/tip")
        sags[nodes] = deflection[:, 1]
    scale = np.abs(sags[28]).max()
    close = np.abs(sags[22] - sags[28]).max() / scale
    far = np.abs(sags[4] - sags[28]).max() / scale
    print(f"\nm = {mass}: max |22 - 28| = {close:.4f}, max |4 - 28| = {far:.4f} of peak sag")
    assert close < 0.02
    assert far > 0.25


def test_stage_summary_and_layout(tmp_path):
    out = tmp_path / "l.h5"
    outcome = run_scene(LUFFING, ["beam.nodes=10"], out)
    with h5py.File(out) as h5:
        dyn = h5["dynamic"]
        nt = len(dyn["time"])
        assert nt == 10_001 and dyn["time"][0] == 0.0
        assert dyn["deflection/tip"].shape == (nt, 3) and dyn["probes/tip"].shape == (nt, 3)
        assert dyn["lambda"].shape == (nt, 7)
        for name in ("kinetic", "strain", "gravity", "total", "drive_work"):
            assert dyn[f"energy/{name}"].shape == (nt,)
        for key in ("integrator", "dt", "steps", "newton_iterations", "factorizations",
                    "wall_time_s"):
            assert key in dyn.attrs
        assert dyn.attrs["factorizations"] == 1
        stages = dict(dyn["stages"].attrs)
        # the end angle is reached exactly: the probe sits at R(pi/3) of its rigid place
        tip = dyn["probes/tip"][-1]
        assert np.degrees(np.arctan2(tip[1], tip[0])) == pytest.approx(60 + 2.17, abs=0.5)
    assert stages == pytest.approx(outcome.stages)
    assert 1.0 < stages["vibration_frequency_hz"] < 3.0
    # SPEC section 5: t_c = phi_end/omega - (t_s + t_b)/2, t1 = t_s + t_c, t2 = t1 + t_b
    assert stages["luffing_t1"] == pytest.approx(np.pi / 3 / 0.2, rel=1e-12)
    assert stages["vibration_t0"] == pytest.approx(np.pi / 3 / 0.2 + 1.0, rel=1e-12)


def test_fast_length_is_the_next_5_smooth_number():
    def smooth(n: int) -> bool:
        for p in (2, 3, 5):
            while n % p == 0:
                n //= p
        return n == 1
    for n in range(1, 5000):
        m = fast_length(n)
        assert m >= n and smooth(m) and not any(smooth(k) for k in range(n, m))
    # the boom's vibration stage at dt = 1 ms pads 3765 samples: 8 * 3765 = 30120 = 2^3 3 5 251
    assert fast_length(30120) == 30375


@pytest.mark.parametrize("samples", [188, 941, 1883])   # 8 n: prime factors 47, 941, 269
def test_dominant_frequency_of_a_sine(samples):
    dt, f = 0.02, 1.7
    t = dt * np.arange(samples)
    freq, amplitude = dominant_frequency(t, 0.1 + 0.3 * np.sin(2 * np.pi * f * t + 0.4))
    # within a tenth of the padded spectrum's bin, 1 / (8 n dt)
    assert abs(freq - f) < 0.1 / (8 * samples * dt)
    assert amplitude == pytest.approx(0.3, rel=1e-3)


@pytest.mark.parametrize("override,key", [("solver.dt=0", "&solver dt"),
                                          ("solver.dt=-1e-3", "&solver dt"),
                                          ("solver.t_end=-1", "&solver t_end"),
                                          ("solver.integrator=rk4", "&solver integrator")])
def test_bad_dynamic_input_exit_2(capsys, tmp_path, override, key):
    assert main(["run", str(LUFFING), "-o", str(tmp_path / "x.h5"), "--set", override]) == 2
    assert key in capsys.readouterr().err


def test_newton_failure_exit_3_keeps_finished_chunks(capsys, tmp_path):
    out = tmp_path / "fail.h5"
    # one Newton correction per step suffices at rest, not once the drive accelerates
    code = main(["run", str(LUFFING), "-o", str(out), "--set", "beam.nodes=4",
                 "--set", "solver.max_newton=1", "--set", "solver.newton_tol=1e-7",
                 "--set", "output.chunk_steps=50",
                 "--set", "solver.dt_min=1e-3"])  # = dt: no step cuts (they would rescue it)
    assert code == 3
    err = capsys.readouterr().err
    assert "time step from t = " in err and "did not converge within 1 iterations" in err
    assert "last correction" in err
    with h5py.File(out) as h5:
        assert h5.attrs["status"] == "failed" and h5["dynamic"].attrs["status"] == "failed"
        rows = len(h5["dynamic/time"])
        assert rows > 51  # the initial row, the finished chunks and the failing chunk's
        # completed steps: every step before the failure is kept
        failed_at = float(err.split("t = ")[1].split(" s")[0])
        assert h5["dynamic/time"][-1] == pytest.approx(failed_at)
        assert rows == 1 + round(failed_at / 1e-3)
        assert np.all(np.isfinite(h5["dynamic/deflection/tip"][()]))
        assert h5["static/q"].shape == (48,)
