"""Verification of the general-system API (issue 12): rigid bodies and joints in the rigid
limit, driven joints, the drives themselves, and a redundant flexible closed loop.

References (tests/reference, written without looking at ancfdrv):

* ``mechanisms``: the rigid pendulum and double pendulum (Lagrange equations integrated by
  DOP853 at rtol 1e-10) and the slider-crank's closed-form kinematics;
* closed-form geometry (a hinged boom lifted by a cylinder of prescribed length, rotations
  and translations of rigid bodies) and closed forms of the drives (SPEC section 5 for the
  luffing profile, the formulas of the drives' documentation), central differences of the
  drives' values, energy conservation.

Dynamics use generalized-alpha with rho_inf = 1 (no numerical damping; second order). The
tolerances follow from the step: the pendulum's error at dt = 1e-3 s is 2.5e-5 m and falls by
4 when dt halves (checked), and positions that the constraints fix are exact to the Newton
tolerance.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from ancfdrv import Rectangle, System
from ancfdrv.codes import ENERGY_NAMES
from ancfdrv.errors import InputError
from ancfdrv.solvers.dynamic import DynamicSettings, integrate
from ancfdrv.system.bodies import rotation_about

sys.path.insert(0, str(Path(__file__).resolve().parent))
from reference import mechanisms as mech  # noqa: E402  (tests/reference: never used by a run)

G = 9.81
TOTAL = ENERGY_NAMES.index("total")


def _run(model, t_end: float, dt: float = 1e-3):
    """Integrate from e0 at rest: times (nt,), probes (nt, nprobe, 3), energy (nt, 11)."""
    rows = []
    settings = DynamicSettings.generalized_alpha(dt, t_end, 1.0, tol=1e-10, max_newton=20)
    integrate(model, settings, model.e0, sink=rows.append, progress=False)
    return (np.concatenate([r.time for r in rows]), np.concatenate([r.probes for r in rows]),
            np.concatenate([r.energy for r in rows]))


def _rod_inertia(mass: float, length: float, angle: float) -> np.ndarray:
    """Inertia about the centre of a slender rod in the x-y plane at ``angle`` from x: m L^2/12
    about the two axes normal to it, a small value about its own axis (a rigid body needs a
    physical tensor)."""
    e = np.array([np.cos(angle), np.sin(angle), 0.0])
    transverse = mass * length**2 / 12.0
    return transverse * (np.eye(3) - np.outer(e, e)) + 1e-4 * transverse * np.outer(e, e)


def _pendulum(dt: float, t_end: float, planar: bool = False, side_force: float = 0.0):
    mass, length = 3.0, 1.2
    s = System("pendulum")
    s.rigid_body("rod", mass=mass, inertia=_rod_inertia(mass, length, 0.0),
                 position=(length / 2, 0, 0), planar=planar, plane_normal=(0, 0, 1))
    s.joint("pin", "revolute", "ground", "rod", point=(0, 0, 0), axis=(0, 0, 1))
    s.load("g", "gravity", vector=(0, -G, 0))
    if side_force:
        s.load("push", "force", body="rod", point=(length, 0, 0), vector=(0, 0, side_force))
    s.probe("tip", "rod", (length, 0, 0))
    model = s.assemble()
    try:
        t, probes, energy = _run(model, t_end, dt)
    finally:
        model.close()
    reference = mech.pendulum(t, 0.0, 0.0, length, mass, gravity=(0.0, -G))
    return t, probes[:, 0, :], energy, reference, mass * G * length


def test_rigid_pendulum_against_ode_and_energy():
    """A rigid rod (rigid body, inertia m L^2/12 about its centre) hinged to the ground by a
    'revolute' about z, released horizontally under gravity: its tip follows
    mechanisms.pendulum (the ODE I_O a'' = S e_perp . g) within 3e-5 m over 1.2 s at
    dt = 1e-3 s (observed 1.3e-5), the error falls by 3.5 to 4.5 when dt halves (order 2),
    the motion stays in its plane, and the total energy (kinetic + potential) stays within
    1e-5 of m g L."""
    t, tip, energy, ref, scale = _pendulum(1e-3, 1.2)
    error = np.abs(tip[:, :2] - ref.tip).max()
    assert error < 3e-5
    assert np.abs(tip[:, 2]).max() < 1e-12
    assert np.abs(energy[:, TOTAL] - energy[0, TOTAL]).max() < 1e-5 * scale
    _, tip2, _, ref2, _ = _pendulum(5e-4, 1.2)
    assert 3.5 < error / np.abs(tip2[:, :2] - ref2.tip).max() < 4.5


def test_planar_rigid_body_stays_in_its_plane():
    """The same pendulum as a planar rigid body (plane normal z; its revolute's axis
    equations repeat the planar guide and are dropped), pushed by a force along z at its
    tip: it stays in its plane (z = 0 to rounding) and moves exactly as the free pendulum
    (the same history to 1e-9 m), which follows mechanisms.pendulum within 3e-5 m."""
    _, free, _, ref, _ = _pendulum(1e-3, 0.6)
    _, planar, _, _, _ = _pendulum(1e-3, 0.6, planar=True, side_force=50.0)
    assert np.abs(planar[:, 2]).max() < 1e-12
    np.testing.assert_allclose(planar, free, rtol=0, atol=1e-9)
    assert np.abs(planar[:, :2] - ref.tip).max() < 3e-5


def test_double_pendulum_against_ode_and_energy():
    """Two rigid rods (1.0 m, 2 kg and 0.8 m, 1.5 kg) hinged in series by 'revolute' joints
    about z, released at rest from the absolute angles (-0.3, 0.6) rad: the knee and the tip
    follow mechanisms.double_pendulum within 1e-4 m over 1 s (dt = 1e-3 s; observed 2.8e-5),
    and the total
    energy stays within 2e-5 of m g L (generalized-alpha with rho_inf = 1 conserves it to
    second order)."""
    lengths, masses, angles = (1.0, 0.8), (2.0, 1.5), (-0.3, 0.6)
    e1 = np.array([np.cos(angles[0]), np.sin(angles[0]), 0.0])
    e2 = np.array([np.cos(angles[1]), np.sin(angles[1]), 0.0])
    knee, tip = lengths[0] * e1, lengths[0] * e1 + lengths[1] * e2
    s = System("double pendulum")
    s.rigid_body("upper", mass=masses[0], inertia=_rod_inertia(masses[0], lengths[0], angles[0]),
                 position=0.5 * knee)
    s.rigid_body("lower", mass=masses[1], inertia=_rod_inertia(masses[1], lengths[1], angles[1]),
                 position=0.5 * (knee + tip))
    s.joint("shoulder", "revolute", "ground", "upper", point=(0, 0, 0), axis=(0, 0, 1))
    s.joint("elbow", "revolute", "upper", "lower", point=knee, axis=(0, 0, 1))
    s.load("g", "gravity", vector=(0, -G, 0))
    s.probe("knee", "upper", knee)
    s.probe("tip", "lower", tip)
    model = s.assemble()
    try:
        t, probes, energy = _run(model, 1.0)
    finally:
        model.close()
    ref = mech.double_pendulum(t, angles, (0.0, 0.0), lengths, masses, gravity=(0.0, -G))
    assert np.abs(probes[:, 0, :2] - ref.knee).max() < 1e-4
    assert np.abs(probes[:, 1, :2] - ref.tip).max() < 1e-4
    scale = sum(masses) * G * sum(lengths)
    assert np.abs(energy[:, TOTAL] - energy[0, TOTAL]).max() < 2e-5 * scale


def test_cylinder_of_driven_length_lifts_a_hinged_boom():
    """A rigid boom hinged to the ground at O = 0 about z, lifted by a 'distance' joint (a
    hydraulic cylinder) from the ground point C = (0.4, -0.6, 0) to the boom point P at
    s = 1.0 m along it, whose length follows a sine drive (offset = the initial length,
    amplitude 0.15 m, 1 Hz, ramp 0.25 s). The boom has no freedom left, so its angle is the
    closed-form geometry |P(a) - C| = L(t): c_x cos a + c_y sin a = (s^2 + |C|^2 - L^2)/(2 s)
    on the branch of a(0) = 0; its tip (2 m) follows it to 1e-8 m over 0.6 s."""
    s_p, tip_length = 1.0, 2.0
    ground_point = np.array([0.4, -0.6, 0.0])
    length0 = float(np.linalg.norm([s_p, 0.0, 0.0] - ground_point))
    s = System("cylinder")
    s.drive("stroke", "sine", amplitude=0.15, frequency=1.0, offset=length0, ramp=0.25)
    s.rigid_body("boom", mass=40.0, inertia=_rod_inertia(40.0, tip_length, 0.0),
                 position=(tip_length / 2, 0, 0))
    s.joint("pivot", "revolute", "ground", "boom", point=(0, 0, 0), axis=(0, 0, 1))
    s.joint("cylinder", "distance", "ground", "boom", point1=ground_point, point2=(s_p, 0, 0),
            drive="stroke")
    s.load("g", "gravity", vector=(0, -G, 0))
    s.probe("tip", "boom", (tip_length, 0, 0))
    model = s.assemble()
    try:
        t, probes, _ = _run(model, 0.6)
        stroke = model.drives[0].values(t)[0]
    finally:
        model.close()
    c2 = ground_point[:2]
    rhs = (s_p**2 + c2 @ c2 - stroke**2) / (2.0 * s_p)
    base = np.arctan2(c2[1], c2[0])
    branch = np.arccos(np.clip(rhs[0] / np.hypot(*c2), -1, 1))
    sign = 1.0 if abs(base + branch) < abs(base - branch) else -1.0
    angle = base + sign * np.arccos(rhs / np.hypot(*c2))
    assert abs(angle[0]) < 1e-12
    expected = tip_length * np.stack([np.cos(angle), np.sin(angle)], axis=1)
    assert np.ptp(angle) > 0.1                    # the boom really moves
    np.testing.assert_allclose(probes[:, 0, :2], expected, rtol=0, atol=1e-8)


def _moved_body(joints, t_end: float = 0.4):
    """A free rigid body (centre (1, 0.5, 0.2)) moved by the given joints; its probe at
    (1.6, 0.9, -0.1) and the drive 'angle' (spin-up to 3 rad/s in 0.2 s from 0.3 rad)."""
    s = System("moved body")
    s.drive("angle", "spinup", omega=3.0, period=0.2, start=0.3)
    s.rigid_body("body", mass=2.0, inertia=(0.2, 0.25, 0.3, 0.01, 0.0, 0.02),
                 position=(1.0, 0.5, 0.2))
    joints(s)
    s.probe("Q", "body", (1.6, 0.9, -0.1))
    model = s.assemble()
    try:
        t, probes, _ = _run(model, t_end)
        phi = model.drives[0].values(t)[0]
    finally:
        model.close()
    return t, probes[:, 0, :], phi - phi[0], model


def test_prescribed_rotation_turns_a_hinged_body():
    """A rigid body hinged to the ground by a 'revolute' about z through O = (0.2, -0.1, 0.2)
    whose point P follows a 'prescribed' rotation about O by the drive's angle: every point
    turns about the hinge, Q(t) = O + R_z(phi(t) - phi(0)) (Q0 - O), to 1e-9 m."""
    pivot = np.array([0.2, -0.1, 0.2])

    def joints(s):
        s.joint("hinge", "revolute", "ground", "body", point=pivot, axis=(0, 0, 1))
        s.joint("turn", "prescribed", "ground", "body", point=(1.0, 0.5, 0.2), pivot=pivot,
                axis=(0, 0, 1), drive="angle")
    _, q, turn, _ = _moved_body(joints)
    q0 = np.array([1.6, 0.9, -0.1])
    expected = np.array([pivot + rotation_about((0, 0, 1), a) @ (q0 - pivot) for a in turn])
    assert np.ptp(turn) > 0.5
    np.testing.assert_allclose(q, expected, rtol=0, atol=1e-9)


def test_prescribed_translation_moves_a_held_body():
    """A rigid body whose orientation is held ('fix' of its axes r_x and r_y) and whose
    centre follows a 'prescribed' translation along a = (1, 2, 2)/3 by the drive's value:
    every point moves by a (phi(t) - phi(0)), to 1e-9 m."""
    axis = np.array([1.0, 2.0, 2.0]) / 3.0

    def joints(s):
        s.joint("slide", "prescribed", "ground", "body", point=(1.0, 0.5, 0.2), axis=axis,
                drive="angle")
        s.joint("hold x", "fix", "ground", "body", point=(1.0, 0.5, 0.2), vector="r_x")
        s.joint("hold y", "fix", "ground", "body", point=(1.0, 0.5, 0.2), vector="r_y")
    _, q, shift, _ = _moved_body(joints)
    expected = np.array([1.6, 0.9, -0.1]) + np.outer(shift, axis)
    np.testing.assert_allclose(q, expected, rtol=0, atol=1e-9)


def test_hub_turns_a_rigid_body_about_any_axis():
    """A 'hub' (a driven clamp) turning a rigid body about the axis (1, 1, 1)/sqrt 3 through
    (0, 0.3, 0) by the drive's angle: Q(t) = pivot + R(phi(t) - phi(0)) (Q0 - pivot) to 1e-9 m;
    the hub's equations that the body's own orthonormality repeats are dropped (notes)."""
    pivot, axis = np.array([0.0, 0.3, 0.0]), np.ones(3) / np.sqrt(3.0)

    def joints(s):
        s.joint("hub", "hub", "ground", "body", point=(1.0, 0.5, 0.2), pivot=pivot, axis=axis,
                drive="angle")
    _, q, turn, model = _moved_body(joints)
    q0 = np.array([1.6, 0.9, -0.1])
    expected = np.array([pivot + rotation_about(axis, a) @ (q0 - pivot) for a in turn])
    np.testing.assert_allclose(q, expected, rtol=0, atol=1e-9)
    assert any("redundant joint equation dropped" in n for n in model.notes)


# ------------------------------------------------------------------------------ drives
def _central(drive, t: np.ndarray, h: float = 1e-5):
    """Central differences of the drive's values: first and second derivative."""
    plus, mid, minus = (drive.values(t + d)[0] for d in (h, 0.0, -h))
    return (plus - minus) / (2 * h), (plus - 2 * mid + minus) / h**2


def _check_rates(drive, t: np.ndarray, scale: float) -> None:
    """phi' and phi'' of the drive against central differences of its phi (away from the
    kinks of the profile); scale: the size of phi'' for the tolerance."""
    _, rate, acceleration = drive.values(t)
    fd_rate, fd_acceleration = _central(drive, t)
    np.testing.assert_allclose(rate, fd_rate, rtol=0, atol=1e-7 * max(scale, 1.0))
    np.testing.assert_allclose(acceleration, fd_acceleration, rtol=0, atol=1e-3 * max(scale, 1.0))


def test_constant_drive():
    """Constant: phi = value, phi' = phi'' = 0 at any time."""
    drive = System().drive("c", "constant", value=-2.5)
    phi, rate, acceleration = drive.values(np.array([-1.0, 0.0, 3.7, 1e3]))
    np.testing.assert_array_equal(phi, -2.5)
    np.testing.assert_array_equal(rate, 0.0)
    np.testing.assert_array_equal(acceleration, 0.0)


def test_sine_drive_with_ramp():
    """Sine: phi = offset + A r(tau) sin(2 pi f tau + phase), tau = t - t0, with the ramp
    r = (1 - cos(pi tau / T_r))/2 for tau < T_r, 1 after, 0 before t0 (the drive's documented
    formula) to 1e-14; phi' and phi'' against central differences before, inside and after
    the ramp."""
    a, f, phase, offset, t0, ramp = 0.7, 1.3, 0.4, 2.0, 0.1, 0.5
    drive = System().drive("s", "sine", amplitude=a, frequency=f, phase=phase, offset=offset,
                           t0=t0, ramp=ramp)
    t = np.concatenate([np.linspace(-0.3, 0.09, 5), np.linspace(0.12, 0.58, 9),
                        np.linspace(0.62, 3.0, 13)])
    tau = t - t0
    envelope = np.where(tau < 0, 0.0, np.where(tau < ramp, 0.5 * (1 - np.cos(np.pi * tau / ramp)),
                                               1.0))
    expected = offset + a * envelope * np.sin(2 * np.pi * f * tau + phase)
    np.testing.assert_allclose(drive.values(t)[0], expected, rtol=0, atol=1e-14)
    _check_rates(drive, t, a * (2 * np.pi * f) ** 2)


def test_table_drive_from_csv(tmp_path):
    """Table from a CSV file (a header row, a comment, then time,value rows): linear between
    the points, constant outside [t_1, t_n], phi' the segment's slope, phi'' = 0; the same
    values as the table given inline."""
    times, values = [0.0, 0.5, 1.2, 2.0], [0.0, 1.0, 0.3, 0.3]
    path = tmp_path / "stroke.csv"
    rows = "".join(f"{t},{v}\n" for t, v in zip(times, values))
    path.write_text("time,value\n# a comment\n" + rows)
    s = System()
    drive = s.drive("from file", "table", file=path)
    inline = s.drive("inline", "table", times=times, values=values)
    t = np.array([-1.0, 0.0, 0.25, 0.49, 0.8, 1.1, 1.6, 2.0, 5.0])
    phi, rate, acceleration = drive.values(t)
    np.testing.assert_allclose(phi, np.interp(t, times, values), rtol=0, atol=1e-15)
    slope = np.diff(values) / np.diff(times)
    inside = (t > times[0]) & (t < times[-1])
    segment = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(slope) - 1)
    np.testing.assert_allclose(rate[inside], slope[segment[inside]], rtol=1e-14)
    np.testing.assert_array_equal(rate[~inside], 0.0)
    np.testing.assert_array_equal(acceleration, 0.0)
    for got, want in zip(drive.values(t), inline.values(t)):
        np.testing.assert_array_equal(got, want)


def test_cycle_drive():
    """Cycle: phi = A (1 - cos(2 pi (t - t0)/T))/2 on [t0, t0 + T], 0 outside, with its
    closed-form derivatives A pi/T sin(...) and 2 A (pi/T)^2 cos(...) (inside) to 1e-12 and
    central differences of phi."""
    a, period, t0 = 4.0, 0.8, 0.3
    drive = System().drive("c", "cycle", amplitude=a, period=period, t0=t0)
    t = np.concatenate([np.linspace(-0.5, 0.29, 4), np.linspace(0.31, 1.09, 11),
                        np.linspace(1.11, 2.0, 4)])
    w = 2 * np.pi * (t - t0) / period
    inside = (t > t0) & (t < t0 + period)
    phi, rate, acceleration = drive.values(t)
    np.testing.assert_allclose(phi, np.where(inside, 0.5 * a * (1 - np.cos(w)), 0.0), atol=1e-12)
    np.testing.assert_allclose(rate, np.where(inside, a * np.pi / period * np.sin(w), 0.0),
                               atol=1e-12)
    np.testing.assert_allclose(acceleration, np.where(
        inside, 2 * a * (np.pi / period) ** 2 * np.cos(w), 0.0), atol=1e-12)
    _check_rates(drive, t, 2 * a * (np.pi / period) ** 2)


def test_spinup_drive():
    """Spin-up (Simo & Vu-Quoc): phi = start + (W/T)(t^2/2 + (T/2pi)^2 (cos(2 pi t/T) - 1)) for
    t < T, start + W t - W T/2 after (to 1e-12); phi' rises smoothly from 0 to W (phi'(T) = W,
    phi''(0) = phi''(T) = 0) and phi', phi'' match central differences."""
    w, period, start = 6.0, 15.0, 0.2
    drive = System().drive("s", "spinup", omega=w, period=period, start=start)
    t = np.concatenate([np.linspace(0.01, 14.9, 12), np.linspace(15.1, 20.0, 5)])
    expected = np.where(t < period, w / period * (t**2 / 2 + (period / (2 * np.pi)) ** 2
                                                  * (np.cos(2 * np.pi * t / period) - 1)),
                        w * t - w * period / 2) + start
    np.testing.assert_allclose(drive.values(t)[0], expected, rtol=0, atol=1e-12)
    _, rate, acceleration = drive.values(np.array([0.0, period, 30.0]))
    np.testing.assert_allclose(rate, [0.0, w, w], atol=1e-12)
    np.testing.assert_allclose(acceleration, [0.0, 0.0, 0.0], atol=1e-12)
    _check_rates(drive, t, w / period)


def test_luffing_drive_follows_spec_section_5():
    """Luffing (SPEC section 5): phi' = omega (1 - cos(pi t/t_s))/2 on [0, t_s), omega on
    [t_s, t1), omega (1 + cos(pi (t - t1)/t_b))/2 on [t1, t2), 0 after, with
    t_c = sweep/omega - (t_s + t_b)/2, t1 = t_s + t_c, t2 = t1 + t_b; phi = start + the
    integral of phi' from 0 (by quadrature) to 1e-10, phi(t2) = start + sweep exactly, and
    phi'' against central differences of phi."""
    omega, t_s, t_b, sweep, start = 0.2, 1.0, 1.0, np.pi / 3, 0.1
    drive = System().drive("l", "luffing", omega=omega, t_start=t_s, t_brake=t_b, sweep=sweep,
                           start=start)
    t_c = sweep / omega - 0.5 * (t_s + t_b)
    t1, t2 = t_s + t_c, t_s + t_c + t_b

    def rate(t: float) -> float:
        if t < 0:
            return 0.0
        if t < t_s:
            return omega * (1 - np.cos(np.pi * t / t_s)) / 2
        if t < t1:
            return omega
        if t < t2:
            return omega * (1 + np.cos(np.pi * (t - t1) / t_b)) / 2
        return 0.0
    t = np.array([0.3, 0.99, 1.5, 3.0, 5.0, t1 + 0.2, t1 + 0.7, t2, t2 + 3.0])
    phi, phi_rate, _ = drive.values(t)
    np.testing.assert_allclose(phi_rate, [rate(x) for x in t], rtol=0, atol=1e-14)
    integral = [quad(rate, 0.0, x, points=[t_s, t1], limit=200, epsabs=1e-13)[0] for x in t]
    np.testing.assert_allclose(phi, start + np.array(integral), rtol=0, atol=1e-10)
    assert drive.value(t2) == pytest.approx(start + sweep, abs=1e-14)
    smooth = np.array([0.3, 0.7, 1.5, 3.0, t1 + 0.2, t1 + 0.7])
    _check_rates(drive, smooth, omega * np.pi / t_s)


def test_luffing_drive_downwards_mirrors_upwards():
    """A downward luffing (omega = -0.2 rad/s, sweep = -60 degrees, from 60 degrees) is the
    mirror image of the upward one: phi_down(t) = 2 start - phi_up(t) with the same start."""
    s = System()
    up = s.drive("up", "luffing", omega=0.2, t_start=1.0, t_brake=1.0, sweep=np.pi / 3,
                 start=np.pi / 3)
    down = s.drive("down", "luffing", omega=-0.2, t_start=1.0, t_brake=1.0, sweep=-np.pi / 3,
                   start=np.pi / 3)
    t = np.linspace(0.0, 8.0, 17)
    np.testing.assert_allclose(down.values(t)[0], 2 * np.pi / 3 - up.values(t)[0], atol=1e-14)


# ------------------------------------------------------------------ the redundant loop
def _slider_crank(youngs: float, drive_joint: str):
    """Crank (a planar rigid body, 0.1 m, 1 kg) turned by a spin-up drive (30 rad/s in 0.1 s)
    through a 'hub' or a 'revolute' plus a 'prescribed' rotation of its pin, a 'nonlinear'
    'cubic' coupler beam (0.3 m, 0.5 kg, 20 x 20 mm), a planar rigid slider (0.4 kg) guided
    along x ('fix' of its point along y, 'fix' of its axis r_x); every joint a 'revolute'
    about z on top of the planar bodies (redundant). Integrated 0.2 s."""
    r, l = 0.1, 0.3
    s = System("slider-crank")
    steel = s.material("steel", youngs_modulus=youngs, density=0.5 / (l * 0.02 * 0.02))
    s.drive("crank", "spinup", omega=30.0, period=0.1)
    s.rigid_body("crank", mass=1.0, inertia=_rod_inertia(1.0, r, 0.0), position=(r / 2, 0, 0),
                 planar=True, plane_normal=(0, 0, 1))
    s.beam("rod", material=steel, start=(r, 0, 0), end=(r + l, 0, 0), nodes=5,
           section=Rectangle(0.02, 0.02), height_axis=(0, 1, 0), formulation="nonlinear",
           bending="cubic")
    s.rigid_body("slider", mass=0.4, inertia=(1e-4, 1e-4, 1e-4, 0, 0, 0),
                 position=(r + l, 0, 0), planar=True, plane_normal=(0, 0, 1))
    if drive_joint == "hub":
        s.joint("motor", "hub", "ground", "crank", point=(0, 0, 0), pivot=(0, 0, 0),
                axis=(0, 0, 1), drive="crank")
    else:
        s.joint("bearing", "revolute", "ground", "crank", point=(0, 0, 0), axis=(0, 0, 1))
        s.joint("motor", "prescribed", "ground", "crank", point=(r, 0, 0), pivot=(0, 0, 0),
                axis=(0, 0, 1), drive="crank")
    s.joint("crank pin", "revolute", "crank", "rod", point=(r, 0, 0), axis=(0, 0, 1))
    s.joint("wrist pin", "revolute", "rod", "slider", point=(r + l, 0, 0), axis=(0, 0, 1))
    s.joint("guide", "fix", "ground", "slider", point=(r + l, 0, 0), axis=(0, 1, 0))
    s.joint("no spin", "fix", "ground", "slider", point=(r + l, 0, 0), vector="r_x")
    s.probe("slider", "slider", (r + l, 0, 0))
    model = s.assemble()
    try:
        t, probes, _ = _run(model, 0.2)
        theta = model.drives[0].values(t)[0]
    finally:
        model.close()
    kinematics = np.array([mech.slider_crank([0.0], r, l, 1.0, 0.5, 0.4, 0.0, theta0=a).slider_x[0]
                           for a in theta])
    return probes[:, 0, :], kinematics, theta, model


@pytest.mark.parametrize("drive_joint", ["hub", "prescribed"])
def test_flexible_slider_crank_with_redundant_joints(drive_joint):
    """The slider-crank with redundant planar constraints assembles (the redundant equations
    are dropped and named in model.notes), runs 0.2 s (the crank turns 4.5 rad), and with a
    steel coupler (E = 2.1e11 Pa) the slider follows the closed-form kinematics of
    mechanisms.slider_crank at the drive's angle within 1e-6 m: the coupler's elastic
    shortening is about F l / (E A) = 60 N * 0.3 m / 8.4e7 N = 2e-7 m (F ~ the slider's and
    rod's inertia at r omega^2 = 90 m/s^2). The slider stays on its guide (y = z = 0)."""
    slider, kinematics, theta, model = _slider_crank(2.1e11, drive_joint)
    assert theta[-1] == pytest.approx(4.5, rel=1e-12)
    assert sum("redundant joint equation dropped" in n for n in model.notes) >= 3
    assert np.abs(slider[:, 1:]).max() < 1e-12
    deviation = np.abs(slider[:, 0] - kinematics).max()
    assert deviation < 1e-6
    assert np.ptp(slider[:, 0]) > 0.15       # a full stroke 2 r = 0.2 m passes


def test_flexible_slider_crank_soft_coupler_deviates():
    """The same loop with a coupler 100 times softer (E = 2.1e9 Pa) deviates from the rigid
    kinematics by about 100 times more (the elastic estimate: 2e-5 m): between 3e-6 and
    1e-4 m, so the stiff-limit tolerance above does measure the coupler's flexibility."""
    slider, kinematics, _, _ = _slider_crank(2.1e9, "hub")
    assert 3e-6 < np.abs(slider[:, 0] - kinematics).max() < 1e-4
