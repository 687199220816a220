"""Smooth drives (issue 22 item 5, SPEC 8.1 "Loads and drives"): tables that interpolate
'cubic' (C2 spline) or 'pchip' (monotone piecewise cubic) and the 'ramp' to a constant rate,
evaluated by the kernel (fortran/src/system/drives.f90 kinds 10 and 11).

References: scipy's CubicSpline with clamped ends (bc_type='clamped': zero end slopes) for
the spline's values and both derivatives; the Fritsch-Butland slopes that scipy's
PchipInterpolator uses at inner points for PCHIP; the closed form of the ramp; central
differences of the kernel's values for its phi' and phi''. Plus the invariants: C2
continuity of the spline at its points, monotonicity of PCHIP on monotone data (no
overshoot where the spline does overshoot), the ramp's rate and continuous acceleration;
and the namelist door takes the same parameters as the Python one.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline, PchipInterpolator

from ancfdrv import System
from ancfdrv.errors import InputError
from ancfdrv.io.scene import load_scene
from ancfdrv.builders import build_system

TIMES = [0.0, 0.4, 1.0, 1.3, 2.5]
VALUES = [0.0, 0.2, 1.5, 1.6, 1.6]      # monotone, with a flat end


def _central(drive, t, h=1e-6):
    phi_p, rate_p, _ = drive.values(t + h)
    phi_m, rate_m, _ = drive.values(t - h)
    return (phi_p - phi_m) / (2 * h), (rate_p - rate_m) / (2 * h)


def test_cubic_table_is_the_clamped_spline_and_c2():
    drive = System().drive("c", "table", times=TIMES, values=VALUES, interpolation="cubic")
    reference = CubicSpline(TIMES, VALUES, bc_type="clamped")
    t = np.linspace(0.0, 2.5, 251)[1:-1]
    phi, rate, acc = drive.values(t)
    np.testing.assert_allclose(phi, reference(t), rtol=0, atol=1e-13)
    np.testing.assert_allclose(rate, reference(t, 1), rtol=0, atol=1e-12)
    np.testing.assert_allclose(acc, reference(t, 2), rtol=0, atol=1e-10)
    # C2 at the inner points: value, rate and acceleration agree from both sides
    knots = np.array(TIMES[1:-1])
    left, right = drive.values(knots - 1e-12), drive.values(knots + 1e-12)
    for k, tol in ((0, 1e-10), (1, 1e-9), (2, 1e-8)):
        np.testing.assert_allclose(left[k], right[k], rtol=0, atol=tol)
    # held outside, with a continuous (zero) rate where it starts and stops holding
    phi, rate, _ = drive.values(np.array([-1.0, 0.0, 2.5, 9.0]))
    np.testing.assert_allclose(phi, [0.0, 0.0, 1.6, 1.6], atol=1e-15)
    np.testing.assert_array_equal(rate, 0.0)
    assert abs(drive.values([1e-9])[1][0]) < 1e-7
    fd_rate, fd_acc = _central(drive, t[2:-2:7])
    np.testing.assert_allclose(drive.values(t[2:-2:7])[1], fd_rate, atol=1e-7)
    np.testing.assert_allclose(drive.values(t[2:-2:7])[2], fd_acc, atol=1e-5)


def test_pchip_table_is_monotone_where_the_spline_overshoots():
    drive = System().drive("p", "table", times=TIMES, values=VALUES, interpolation="pchip")
    spline = System().drive("c", "table", times=TIMES, values=VALUES, interpolation="cubic")
    t = np.linspace(0.0, 2.5, 2501)
    phi, rate, _ = drive.values(t)
    assert np.all(np.diff(phi) >= -1e-15) and np.all(rate >= -1e-14)   # monotone
    assert phi.max() <= 1.6 + 1e-15                                     # no overshoot
    assert spline.values(t)[0].max() > 1.6 + 1e-3                       # the spline does
    # the points' slopes are the Fritsch-Butland ones of scipy's PCHIP (inner points; the
    # ends are zero here by design)
    inner = np.array(TIMES[1:-1])
    np.testing.assert_allclose(drive.values(inner)[1],
                               PchipInterpolator(TIMES, VALUES)(inner, 1), atol=1e-12)
    np.testing.assert_allclose(drive.values(np.array(TIMES))[0], VALUES, atol=1e-15)
    # C1: the rate is continuous at the points, phi'' by central differences
    left, right = drive.values(inner - 1e-12), drive.values(inner + 1e-12)
    np.testing.assert_allclose(left[1], right[1], atol=1e-9)
    probe = np.array([0.2, 0.7, 1.15, 1.9])
    fd_rate, fd_acc = _central(drive, probe)
    np.testing.assert_allclose(drive.values(probe)[1], fd_rate, atol=1e-7)
    np.testing.assert_allclose(drive.values(probe)[2], fd_acc, atol=1e-5)


def test_ramp_reaches_its_rate_smoothly():
    rate, t_ramp, start, t0 = 0.15, 0.5, 1.8, 0.2
    drive = System().drive("r", "ramp", rate=rate, t_ramp=t_ramp, start=start, t0=t0)
    t = np.array([0.0, 0.2, 0.3, 0.45, 0.69, 0.7, 1.0, 3.0])
    tau = np.clip(t - t0, 0.0, None)
    w = 2 * np.pi / t_ramp
    inside = tau < t_ramp
    expected = np.where(inside, start + rate / t_ramp * (tau**2 / 2 + (np.cos(w * tau) - 1)
                                                          / w**2),
                        start + rate * (tau - t_ramp / 2))
    phi, velocity, acc = drive.values(t)
    np.testing.assert_allclose(phi, expected, rtol=0, atol=1e-15)
    assert velocity[0] == 0.0 and velocity[1] == 0.0
    np.testing.assert_allclose(velocity[t >= t0 + t_ramp], rate, rtol=1e-15)
    # continuous acceleration: zero at both ends of the ramp, its mean over it rate/t_ramp
    ends = np.array([t0, t0 + t_ramp])
    for side in (-1e-9, 1e-9):
        assert np.abs(drive.values(ends + side)[2]).max() < 1e-6
    assert drive.values([t0 + t_ramp / 2])[2][0] == pytest.approx(2 * rate / t_ramp)
    probe = np.array([0.25, 0.4, 0.6, 1.5])
    fd_rate, fd_acc = _central(drive, probe)
    np.testing.assert_allclose(drive.values(probe)[1], fd_rate, atol=1e-9)
    np.testing.assert_allclose(drive.values(probe)[2], fd_acc, atol=1e-6)
    with pytest.raises(InputError, match="t_ramp"):
        System().drive("bad", "ramp", rate=1.0, t_ramp=-1.0)


SCENE = """
&scene  title = 'drives', analysis = 'dynamic', formulation = 'nonlinear' /
&rigid_body  name = 'b', mass = 1.0, inertia = 1.0, 1.0, 1.0, 0.0, 0.0, 0.0,
             position = 0.0, 0.0, 0.0 /
&drive  name = 'stroke', type = 'luffing', omega = 0.15, t_start = 0.5, t_brake = 0.5,
        sweep = 0.3, start = 1.8 /
&drive  name = 'table', type = 'table', times = 0.0, 0.4, 1.0, 1.3, 2.5,
        values = 0.0, 0.2, 1.5, 1.6, 1.6, interpolation = 'pchip' /
&drive  name = 'ramp', type = 'ramp', rate = 0.15, t_ramp = 0.5, start = 1.8, t0 = 0.2 /
&joint  name = 'hold', type = 'weld', body1 = 'ground', body2 = 'b', point = 0.0, 0.0, 0.0 /
&solver  t_end = 0.01 /
"""


def test_namelist_drives_take_the_python_parameters(tmp_path):
    """A luffing drive of a cylinder length in metres (sweep, start: the Python API's
    parameters, no degrees), a pchip table and a ramp, from a namelist: the same functions
    as the same calls in Python."""
    path = tmp_path / "drives.nml"
    path.write_text(SCENE)
    system = build_system(load_scene(path)).system
    python = System()
    python.drive("stroke", "luffing", omega=0.15, t_start=0.5, t_brake=0.5, sweep=0.3,
                 start=1.8)
    python.drive("table", "table", times=TIMES, values=VALUES, interpolation="pchip")
    python.drive("ramp", "ramp", rate=0.15, t_ramp=0.5, start=1.8, t0=0.2)
    t = np.linspace(-0.1, 3.0, 32)
    for name in ("stroke", "table", "ramp"):
        for got, want in zip(system.drives[name].values(t), python.drives[name].values(t)):
            np.testing.assert_array_equal(got, want)
    assert system.drives["stroke"].value(3.0) == pytest.approx(2.1)   # metres, not degrees
    path.write_text(SCENE.replace("sweep = 0.3, start = 1.8", "sweep = 0.3, start_deg = 3.0"))
    with pytest.raises(InputError, match="does not take start_deg"):
        load_scene(path)


def test_cylinder_on_a_spline_table_lifts_a_boom_by_the_closed_form_geometry():
    """A rigid boom hinged at O = 0 about z, lifted by a 'distance' joint (a cylinder from
    the ground point C to the boom point P at s = 1 m) whose length follows a 'cubic'
    table: its angle is the closed-form geometry |P(a) - C| = L(t) on the branch of a(0) = 0
    (as tests/test_system_mechanisms.py does for a sine drive), through System.simulate."""
    ground_point = np.array([0.4, -0.6, 0.0])
    length0 = float(np.linalg.norm([1.0, 0.0, 0.0] - ground_point))
    s = System("cylinder on a table")
    s.drive("stroke", "table", times=[0.0, 0.1, 0.3, 0.4],
            values=[length0, length0 + 0.02, length0 + 0.12, length0 + 0.15],
            interpolation="cubic")
    inertia = 40.0 * 4.0 / 12.0
    s.rigid_body("boom", mass=40.0, inertia=(1e-3, inertia, inertia, 0, 0, 0),
                 position=(1.0, 0, 0))
    s.joint("pivot", "revolute", "ground", "boom", point=(0, 0, 0), axis=(0, 0, 1))
    s.joint("cylinder", "distance", "ground", "boom", point1=ground_point, point2=(1, 0, 0),
            drive="stroke")
    s.load("g", "gravity", vector=(0, -9.81, 0))
    s.probe("end", "boom", (2.0, 0, 0))
    res = s.simulate(0.4, 2e-3, integrator="generalized_alpha", rho_inf=1.0, xdmf=False)
    stroke = s.drives["stroke"].values(res.time)[0]
    c2 = ground_point[:2]
    base = np.arctan2(c2[1], c2[0])
    angle = base + np.arccos((1.0 + c2 @ c2 - stroke**2) / (2.0 * np.hypot(*c2)))
    angle -= angle[0]                                 # the branch through a(0) = 0
    expected = 2.0 * np.stack([np.cos(angle), np.sin(angle)], axis=1)
    assert np.ptp(angle) > 0.1
    np.testing.assert_allclose(res.probes["end"][:, :2], expected, rtol=0, atol=1e-8)
