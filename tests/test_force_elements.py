"""Force elements (SPEC 8.1, kernel module force_elements.f90, system/kinds/force_element.py):
spring-damper, bushing and compliant hydraulic cylinder. Every number is checked against an
independent reference: the closed forms of a mass on a spring (equilibrium, period, damping
ratio), central differences of the kernel's force and energy, invariants (energy balance,
zero force under a common rigid rotation) and the rigid 'distance' joint as the stiff
cylinder's limit."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import System
from ancfdrv.errors import InputError
from ancfdrv.system.kinds.force_element import (FE_BUSHING, FE_CYLINDER, FE_SPRING_DAMPER,
                                           ForceElementInfo, evaluate)
from ancfdrv.system.drives import Table

M, K = 2.0, 800.0                      # kg, N/m: omega = 20 rad/s, period 0.314 s
OMEGA = np.sqrt(K / M)


def rotation(axis, angle: float) -> np.ndarray:
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    s = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * s + (1 - np.cos(angle)) * s @ s


def guided_mass(*, stiffness=K, damping=0.0, free_length=0.9, preload=None, start=-1.0,
                gravity=0.0, table=None, mass=M) -> System:
    """A rigid body under the ground point (0, 0, 0), guided along z (its axes and x, y held
    by 'fix' joints), hung on a spring-damper."""
    s = System("guided mass")
    s.rigid_body("box", mass=mass, inertia=(0.1, 0.1, 0.1, 0, 0, 0), position=(0, 0, start))
    kw = dict(deflections=table[0], forces=table[1], interpolation=table[2]) if table else \
        dict(stiffness=stiffness, preload=preload)
    s.force_element("spring", "spring_damper", "ground", "box", point1=(0, 0, 0),
                    point2=(0, 0, start), damping=damping, free_length=free_length, **kw)
    _guide(s, start)
    if gravity:
        s.load("g", "gravity", vector=(0, 0, -gravity))
    s.probe("c", "box", (0, 0, start))
    return s


def _guide(s: System, z: float) -> None:
    for v in ("r_x", "r_y", "r_z"):
        s.joint(f"hold_{v}", "fix", "ground", "box", point=(0, 0, z), vector=v)
    s.joint("gx", "fix", "ground", "box", point=(0, 0, z), vector="r", axis=(1, 0, 0))
    s.joint("gy", "fix", "ground", "box", point=(0, 0, z), vector="r", axis=(0, 1, 0))


# -- the kernel routine: tangent and energy against central differences ------------------------
def _check_derivatives(info: ForceElementInfo, x, xd, length=0.0, rate=0.0, tol=1e-6):
    """dF/dx and dF/dxd of the kernel against central differences of its force, and the
    force without rates against the central differences of its energy."""
    out = evaluate(info, x, xd, length, rate)
    ns = x.shape[1]
    h = 1e-6
    fd_k = np.zeros((3, ns, 3, ns))
    fd_c = np.zeros((3, ns, 3, ns))
    fd_e = np.zeros((3, ns))
    for j in range(3):
        for w in range(ns):
            dx = np.zeros_like(x)
            dx[j, w] = h
            fd_k[:, :, j, w] = (evaluate(info, x + dx, xd, length, rate)["force"]
                                - evaluate(info, x - dx, xd, length, rate)["force"]) / (2 * h)
            fd_c[:, :, j, w] = (evaluate(info, x, xd + dx, length, rate)["force"]
                                - evaluate(info, x, xd - dx, length, rate)["force"]) / (2 * h)
            fd_e[j, w] = (evaluate(info, x + dx, None, length)["energy"]
                          - evaluate(info, x - dx, None, length)["energy"]) / (2 * h)
    scale = np.abs(out["stiffness"]).max()
    assert np.abs(out["stiffness"] - fd_k).max() <= tol * scale
    assert np.abs(out["damping"] - fd_c).max() <= tol * max(np.abs(out["damping"]).max(), 1e-30)
    static = evaluate(info, x, None, length)["force"]
    assert np.abs(static - fd_e).max() <= tol * np.abs(static).max()
    return out


def _info(kind, params, slots=2, table=None):
    tk, tp = (0, np.zeros(0)) if table is None else (table.kind, np.array(table.params()))
    return ForceElementInfo("x", kind, -1, np.asarray(params, float), tk, tp, [None] * slots)


def test_spring_damper_tangent_matches_central_differences_at_a_large_rotation():
    """A preloaded spring-damper whose line has turned by 2 rad from z, moving in every
    direction: K, C and the conservative force (minus dV/dx) exact to 1e-6."""
    rng = np.random.default_rng(1)
    line = rotation((1, 2, 0.5), 2.0) @ np.array([0, 0, 1.3])
    x = np.column_stack([[0.1, -0.2, 0.3], np.array([0.1, -0.2, 0.3]) + line])
    xd = rng.normal(size=(3, 2))
    out = _check_derivatives(_info(FE_SPRING_DAMPER, [K, 7.0, 1.0, 50.0]), x, xd)
    # the force along the line: preload + k (L - L0) + c L'
    unit = line / np.linalg.norm(line)
    rate = unit @ (xd[:, 1] - xd[:, 0])
    f = 50.0 + K * 0.3 + 7.0 * rate
    assert out["reaction"][6] == pytest.approx(f, rel=1e-12)
    assert np.allclose(out["force"][:, 1], f * unit, rtol=1e-12)
    assert out["dissipation"] == pytest.approx(7.0 * rate**2, rel=1e-12)


@pytest.mark.parametrize("interpolation", ["linear", "cubic", "pchip"])
def test_table_spring_tangent_and_energy(interpolation):
    """A force-deflection table (a hardening spring): the force and stiffness follow the
    drive table's interpolation (its slope), the energy is its integral (central
    differences, within a piece and across breakpoints)."""
    table = Table("t", (-0.2, 0.0, 0.1, 0.3), (-100.0, 0.0, 120.0, 600.0), interpolation)
    info = _info(FE_SPRING_DAMPER, [0.0, 2.0, 1.0, 0.0], table=table)
    for stretch in (1.05, 1.17, 0.93, 1.45):
        line = rotation((0, 1, 1), 1.2) @ np.array([stretch, 0, 0])
        x = np.column_stack([[0, 0, 0], line])
        _check_derivatives(info, x, np.array([[0.1, 0.3], [0.0, -0.2], [0.2, 0.1]]), tol=2e-6)
        value = table.value(stretch - 1.0)
        assert evaluate(info, x)["reaction"][6] == pytest.approx(value, rel=1e-12, abs=1e-9)


def test_cylinder_tangent_and_drive_power():
    """The compliant cylinder: f = k (L - l) + c (L' - l'); its tangent against central
    differences and the drive's power -f l'."""
    x = np.column_stack([[0.0, 0.0, 0.0], rotation((1, 0, 1), 2.5) @ np.array([1.2, 0, 0])])
    xd = np.array([[0.0, 0.2], [0.0, -0.1], [0.0, 0.4]])
    info = _info(FE_CYLINDER, [5e5, 2e3])
    out = _check_derivatives(info, x, xd, length=1.1, rate=0.05)
    unit = x[:, 1] / 1.2
    f = 5e5 * (1.2 - 1.1) + 2e3 * (unit @ xd[:, 1] - 0.05)
    assert out["reaction"][6] == pytest.approx(f, rel=1e-12)
    assert out["drive_power"] == pytest.approx(-f * 0.05, rel=1e-12)
    assert out["energy"] == pytest.approx(0.5 * 5e5 * 0.1**2, rel=1e-12)


def _bushing_slots(turn: np.ndarray, relative: np.ndarray, shift=np.zeros(3)):
    """Slots (p1, p2, g1..g3, h1..h3) of two frames turned together by ``turn``, body2
    further by ``relative`` (in body1's axes) and shifted by ``shift``."""
    p = np.array([0.3, -0.1, 0.7])
    g = turn
    h = turn @ relative
    return np.column_stack([turn @ p, turn @ p + shift, *g.T, *h.T])


def test_bushing_tangent_and_common_rotation():
    """The bushing: its tangent against central differences at a large common rotation
    with a small relative one; a common rotation alone (any angle) gives exactly no force,
    and small relative translations and rotations give k u and k_r theta in body1's axes."""
    k = [1e5, 2e5, 3e5]
    kr = [4e3, 5e3, 6e3]
    c = [10.0, 20.0, 30.0]
    cr = [1.0, 2.0, 3.0]
    info = _info(FE_BUSHING, k + kr + c + cr, slots=8)
    turn = rotation((0.3, -1.0, 0.6), 2.2)
    x = _bushing_slots(turn, rotation((1, 1, 0), 0.02), np.array([1e-3, -2e-3, 5e-4]))
    rng = np.random.default_rng(4)
    _check_derivatives(info, x, rng.normal(size=(3, 8)), tol=2e-6)
    rest = evaluate(info, _bushing_slots(turn, np.eye(3)))
    assert np.abs(rest["force"]).max() == 0.0 or np.abs(rest["force"]).max() < 1e-10
    assert rest["energy"] < 1e-20
    # a small relative state: u = 1e-6 m along body1's axes, theta = 1e-6 rad about them
    u = np.array([1.0, -2.0, 3.0]) * 1e-6
    theta = np.array([-1.0, 2.0, 0.5]) * 1e-6
    out = evaluate(info, _bushing_slots(turn, rotation(theta, np.linalg.norm(theta)),
                                        turn @ u))
    force_on_2 = out["reaction"][0:3]
    moment_on_2 = out["reaction"][3:6]
    assert np.allclose(turn.T @ force_on_2, -np.array(k) * u, rtol=1e-5)
    assert np.allclose(turn.T @ moment_on_2, -np.array(kr) * theta, rtol=1e-5)


# -- the system: mass on a spring --------------------------------------------------------------
def test_static_equilibrium_with_preload_and_free_length():
    """m g = F0 + k (L - L0): the hanging length and the spring's reaction (axial = m g,
    the force on the box upwards)."""
    g, f0 = 9.81, 5.0
    s = guided_mass(free_length=0.9, preload=f0, gravity=g)
    res = s.static(static_method="newton")
    length = 0.9 + (M * g - f0) / K
    assert res.probes["c"][2] == pytest.approx(-length, abs=1e-12)
    r = res.reactions["spring"]
    assert float(r["axial"]) == pytest.approx(M * g, rel=1e-12)
    assert np.allclose(r["force"], [0, 0, M * g], rtol=1e-12)
    assert res.counters["force_elements"] == 1


@pytest.mark.parametrize("interpolation", ["linear", "pchip"])
def test_table_spring_hangs_where_its_table_says(interpolation):
    """A hardening force-deflection table (-10, 0, 10, 40 mm -> -8, 0, 8, 60 N; a table
    spans the deflections the element sees: beyond its ends its stiffness is 0, and at the
    first point Newton's start would have none): the 19.62 N weight
    hangs at the deflection where the table reaches it: between the points linear
    interpolation 10 + 30 (19.62 - 8) / 52 mm, and the monotone PCHIP curve's inverse (by
    bisection on the drive's own values)."""
    table = ((-0.01, 0.0, 0.01, 0.04), (-8.0, 0.0, 8.0, 60.0), interpolation)
    s = guided_mass(table=table, free_length=0.9, start=-0.9, gravity=9.81)
    res = s.static(static_method="newton")
    weight = M * 9.81
    if interpolation == "linear":
        expected = 0.01 + 0.03 * (weight - 8.0) / 52.0
    else:
        curve = Table("t", table[0], table[1], interpolation)
        lo, hi = 0.01, 0.04
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if curve.value(mid) < weight else (lo, mid)
        expected = 0.5 * (lo + hi)
    assert -res.probes["c"][2] - 0.9 == pytest.approx(expected, rel=1e-9)
    assert float(res.reactions["spring"]["axial"]) == pytest.approx(weight, rel=1e-9)


def _zero_crossings(t, y):
    idx = np.nonzero(np.diff(np.sign(y)) != 0)[0]
    return t[idx] - y[idx] * (t[idx + 1] - t[idx]) / (y[idx + 1] - y[idx])


def test_period_and_energy_of_the_undamped_oscillator():
    """Released 0.1 m from its free length: the period is 2 pi sqrt(m/k) (trapezoidal
    Newmark's period error (omega h)^2 / 12 = 3e-5 at h = 1 ms) and the energy (kinetic +
    spring) stays constant."""
    s = guided_mass(free_length=0.9, start=-1.0)
    res = s.simulate(t_end=0.7, dt=1e-3)
    t = np.asarray(res.time)
    z = np.asarray(res.probes["c"])[:, 2] + 0.9
    crossings = _zero_crossings(t, z)
    period = 2 * np.mean(np.diff(crossings))
    # the trapezoidal rule lengthens the period by (omega h)^2 / 12 (measured 3.332e-5)
    elongation = period / (2 * np.pi * np.sqrt(M / K)) - 1
    assert elongation == pytest.approx((OMEGA * 1e-3)**2 / 12, rel=1e-2)
    energy = np.asarray(res.energy["kinetic"]) + np.asarray(res.energy["strain"])
    assert energy[0] == pytest.approx(0.5 * K * 0.1**2, rel=1e-12)
    assert np.abs(energy - energy[0]).max() <= 1e-12 * energy[0]   # measured 1.5e-14


def test_damping_ratio_and_dissipated_work():
    """c = 0.1 sqrt(k m) gives zeta = c / (2 sqrt(k m)) = 0.05: the logarithmic decrement of
    the peaks; the work lost equals the integral of c v^2 (from the probe's motion), and
    kinetic + spring + lost work stays the initial energy."""
    zeta = 0.05
    c = 2 * zeta * np.sqrt(K * M)
    s = guided_mass(damping=c, free_length=0.9, start=-1.0)
    res = s.simulate(t_end=1.0, dt=5e-4)
    t = np.asarray(res.time)
    z = np.asarray(res.probes["c"])[:, 2] + 0.9
    peaks = [i for i in range(1, len(z) - 1) if z[i] > z[i - 1] and z[i] >= z[i + 1]
             and z[i] > 0]
    ratio = np.log(z[peaks[0]] / z[peaks[2]]) / 2   # two periods
    measured = ratio / np.sqrt(4 * np.pi**2 + ratio**2)
    assert measured == pytest.approx(zeta, rel=2e-4)                  # measured 2.8e-5
    lost = -np.asarray(res.energy["material_damping_work"])
    v = np.gradient(z, t)
    integral = np.concatenate([[0], np.cumsum(0.5 * (c * v[1:]**2 + c * v[:-1]**2)
                                              * np.diff(t))])
    assert lost[-1] == pytest.approx(integral[-1], rel=5e-4)          # measured 5.1e-5
    # kinetic + spring + lost work: constant up to the trapezoidal rule the stepper
    # integrates the power with (c (v_n^2 + v_n+1^2) / 2 against the scheme's own
    # c ((v_n + v_n+1) / 2)^2: O((omega h)^2)); halving h quarters the drift
    drift = []
    for run in (res, guided_mass(damping=c, free_length=0.9, start=-1.0).simulate(
            t_end=1.0, dt=1e-3)):
        total = (np.asarray(run.energy["kinetic"]) + np.asarray(run.energy["strain"])
                 - np.asarray(run.energy["material_damping_work"]))
        drift.append(np.abs(total - total[0]).max() / total[0])
    assert drift[0] <= (OMEGA * 5e-4)**2
    assert drift[1] / drift[0] == pytest.approx(4.0, rel=0.05)
    # the dynamic reaction: axial = k (L - L0) + c L' at every row
    axial = np.asarray(res.reactions["spring"]["axial"])
    assert axial.shape == t.shape
    assert np.abs(axial - (K * (-z) + c * (-v))).max() <= 1e-3 * K * 0.1


def test_modal_frequency_and_damping_ratio():
    """Modal analysis about the equilibrium: sqrt(k/m) / 2 pi and zeta = c / (2 sqrt(k m))
    (the damper enters C = dQ/de')."""
    c = 2 * 0.05 * np.sqrt(K * M)
    modes = guided_mass(damping=c, free_length=0.9, start=-1.0).modes(1)
    assert modes.frequency[0] == pytest.approx(OMEGA / (2 * np.pi), rel=1e-12)
    assert modes.damping_ratio[0] == pytest.approx(0.05, rel=1e-12)


# -- the system tangent and the rigid-rotation invariant ----------------------------------------
def _two_bodies(kind: str, beam: bool = False) -> System:
    """Two rigid bodies, or (beam) a 3-node nonlinear beam and a rigid body, joined by a
    force element; the beam's points lie between its nodes and off its axis."""
    s = System("pair")
    if beam:
        s.material("steel", youngs_modulus=2.1e11, density=7850.0)
        from ancfdrv import Rectangle
        s.beam("a", material="steel", start=(0, 0, 0), end=(1.0, 0, 0), nodes=3,
               section=Rectangle(0.04, 0.06), formulation="nonlinear", bending="cubic")
    else:
        s.rigid_body("a", mass=1.0, inertia=(0.1, 0.2, 0.3, 0, 0, 0), position=(0, 0, 0))
    s.rigid_body("b", mass=1.0, inertia=(0.1, 0.2, 0.3, 0, 0, 0), position=(1, 0.2, 0))
    if kind == "bushing":
        s.force_element("bu", "bushing", "a", "b", point=(0.35, 0.01, 0.02),
                        stiffness=[1e4, 2e4, 3e4], damping=[1, 2, 3],
                        rotational_stiffness=[1e3, 2e3, 3e3], rotational_damping=[0.1, 0.2, 0.3])
    else:
        s.force_element("sd", "spring_damper", "a", "b", point1=(0.1, 0.01, 0.02),
                        point2=(0.9, 0.3, 0.1), stiffness=1e4, damping=30.0, free_length=0.6)
    return s


@pytest.mark.parametrize("kind, beam", [("spring_damper", False), ("bushing", False),
                                        ("spring_damper", True), ("bushing", True)])
def test_system_tangent_matches_central_differences(kind, beam):
    """The assembled tangent dQ/de + c_v dQ/de' (the kernel's scatter into the sparse
    pattern, coupling the two bodies) against central differences of the internal force, at
    a state turned by 1.5 rad with a velocity; with a beam its elastic force is in both."""
    model = _two_bodies(kind, beam).assemble(effects=())
    rng = np.random.default_rng(2)
    turn = rotation((1, -1, 2), 1.5)
    q = model.q0.reshape(-1, 3) @ turn.T
    e = q.ravel() + 1e-3 * rng.normal(size=model.ndof)
    v = rng.normal(size=model.ndof)
    cv = 250.0
    out = model.forces(e, 0.0, v, velocity_factor=cv, want_tangent=True)
    tangent = model.pattern.to_scipy(out["tangent"]).toarray()
    h = 1e-6
    fd = np.zeros_like(tangent)
    for j in range(model.ndof):
        d = np.zeros(model.ndof)
        d[j] = h
        fd[:, j] = (model.forces(e + d, 0.0, v)["internal"]
                    - model.forces(e - d, 0.0, v)["internal"]) / (2 * h)
        fd[:, j] += cv * (model.forces(e, 0.0, v + d)["internal"]
                          - model.forces(e, 0.0, v - d)["internal"]) / (2 * h)
    assert np.abs(tangent - fd).max() <= 1e-6 * np.abs(fd).max()
    if beam:
        return
    # a common rigid motion of both bodies from t = 0: the bushing has no force (any
    # rotation angle); the preloaded spring (free length 0.6 m, 0.83 m long) the same
    # energy and its force turned with the bodies
    rest = model.forces(model.q0, 0.0)
    rigid = model.forces(q.ravel() + np.tile([0.3, -0.2, 0.1, 0, 0, 0, 0, 0, 0, 0, 0, 0], 2),
                         0.0)
    turned = (rest["internal"].reshape(-1, 3) @ turn.T).ravel()
    assert np.abs(rigid["internal"] - turned).max() <= 1e-9 * np.abs(out["internal"]).max()
    assert rigid["strain"] == pytest.approx(rest["strain"], rel=1e-12, abs=1e-12)
    if kind == "bushing":
        # at rest: round-off only (the two bodies' positions of the point, 1e-16 m, times k)
        assert np.abs(rest["internal"]).max() <= 1e-15 * 3e4 and rest["strain"] <= 1e-25


def test_bushing_static_deflection_under_force_and_moment():
    """A rigid body held at its centre by a bushing to the ground: F/k along each axis and
    M/k_r about each (small loads: the measure's second-order terms are 1e-6 relative)."""
    k = np.array([1e6, 2e6, 3e6])
    kr = np.array([1e5, 2e5, 3e5])
    f = np.array([3.0, -5.0, 2.0])
    m = np.array([0.4, 0.3, -0.6])
    s = System("bushing")
    s.rigid_body("box", mass=1.0, inertia=(0.1, 0.1, 0.1, 0, 0, 0), position=(0, 0, 0))
    s.force_element("mount", "bushing", "ground", "box", point=(0, 0, 0), stiffness=k,
                    rotational_stiffness=kr)
    s.load("f", "force", body="box", point=(0, 0, 0), vector=f)
    for i, axis in enumerate("xyz"):  # one load per axis (see the report on general vectors)
        s.load(f"m{axis}", "moment", body="box", point=(0, 0, 0), vector=np.eye(3)[i] * m[i])
    s.probe("c", "box", (0, 0, 0))
    s.probe("x", "box", (1, 0, 0))
    s.probe("y", "box", (0, 1, 0))
    res = s.static(static_method="newton")
    assert np.allclose(res.probes["c"], f / k, rtol=1e-6, atol=0)
    x, y = res.probes["x"] - res.probes["c"], res.probes["y"] - res.probes["c"]
    theta = np.array([y[2], -x[2], x[1]])        # small rotation from the turned axes
    assert np.allclose(theta, m / kr, rtol=1e-5)
    r = res.reactions["mount"]
    assert np.allclose(r["force"], -f, rtol=1e-9)
    assert np.allclose(r["moment"], -m, rtol=1e-5)


# -- the cylinder ----------------------------------------------------------------------------
def _lifted(kind: str, stiffness: float = 2e5, damping: float = 4e3, t_end: float = 0.0):
    """A 50 kg body on a vertical cylinder from the ground (guided along z), extending at
    0.1 m/s after a smooth start, under gravity."""
    s = System("cylinder")
    s.drive("stroke", "ramp", start=1.0, rate=0.1, t_ramp=0.2, t0=0.0)
    s.rigid_body("box", mass=50.0, inertia=(1, 1, 1, 0, 0, 0), position=(0, 0, 1.0))
    if kind == "cylinder":
        s.force_element("cyl", "cylinder", "ground", "box", point1=(0, 0, 0), point2=(0, 0, 1.0),
                        drive="stroke", stiffness=stiffness, damping=damping)
    else:
        s.joint("cyl", "distance", "ground", "box", point1=(0, 0, 0), point2=(0, 0, 1.0),
                drive="stroke")
    _guide(s, 1.0)
    s.load("g", "gravity", vector=(0, 0, -9.81))
    s.probe("c", "box", (0, 0, 1.0))
    return s


def test_cylinder_quasi_static_force_and_rigid_limit():
    """Extending slowly under a 490.5 N weight: the oil column's force k (L - l) carries the
    weight (axial = -m g, compression) once the start transient has decayed; a stiff column
    (k = 1e9 N/m) moves the body as the rigid 'distance' joint does, offset by m g / k."""
    res = _lifted("cylinder").simulate(t_end=0.6, dt=2e-3)
    t = np.asarray(res.time)
    z = np.asarray(res.probes["c"])[:, 2]
    weight = 50.0 * 9.81
    late = t > 0.45
    axial = np.asarray(res.reactions["cyl"]["axial"])[late]
    assert np.allclose(axial, -weight, rtol=1e-5)                      # measured 3.7e-7
    # L - l = -m g / k (the drive at the same times: ramp of 0.1 m/s)
    from ancfdrv.system.drives import Ramp
    length = np.array([Ramp("r", start=1.0, rate=0.1, t_ramp=0.2, t0=0.0).value(x) for x in t])
    assert np.allclose(z[late] - length[late], -weight / 2e5, rtol=1e-5)  # measured 6.8e-7
    stiff = _lifted("cylinder", stiffness=1e9, damping=1e5).simulate(t_end=0.4, dt=2e-3)
    rigid = _lifted("distance").simulate(t_end=0.4, dt=2e-3)
    gap = np.asarray(stiff.probes["c"])[:, 2] - np.asarray(rigid.probes["c"])[:, 2]
    assert np.abs(gap[len(gap) // 2:] + weight / 1e9).max() <= 1e-3 * weight / 1e9  # 8.4e-5


# -- the two doors -----------------------------------------------------------------------------
def test_namelist_and_python_give_the_same_model(tmp_path):
    text = """
&scene title = 'spring', analysis = 'static' /
&solver static_method = 'newton' /
&rigid_body name = 'box', mass = 2.0, inertia = 0.1, 0.1, 0.1, 0, 0, 0, position = 0, 0, -1.0 /
&force_element name = 'spring', type = 'spring_damper', body1 = 'ground', body2 = 'box',
  point1 = 0, 0, 0, point2 = 0, 0, -1.0, stiffness = 800.0, free_length = 0.9, preload = 5.0 /
&joint name = 'hold_r_x', type = 'fix', body2 = 'box', point = 0, 0, -1.0, vector = 'r_x' /
&joint name = 'hold_r_y', type = 'fix', body2 = 'box', point = 0, 0, -1.0, vector = 'r_y' /
&joint name = 'hold_r_z', type = 'fix', body2 = 'box', point = 0, 0, -1.0, vector = 'r_z' /
&joint name = 'gx', type = 'fix', body2 = 'box', point = 0, 0, -1.0, vector = 'r', axis = 1, 0, 0 /
&joint name = 'gy', type = 'fix', body2 = 'box', point = 0, 0, -1.0, vector = 'r', axis = 0, 1, 0 /
&load name = 'g', type = 'gravity', vector = 0, 0, -9.81 /
&probe name = 'c', body = 'box', point = 0, 0, -1.0 /
"""
    path = tmp_path / "spring.nml"
    path.write_text(text)
    from ancfdrv.io.scene import load_scene
    from ancfdrv.builders.general import build_general
    built = build_general(load_scene(path))
    fe = built.system.force_elements["spring"]
    python = guided_mass(free_length=0.9, preload=5.0, gravity=9.81)
    assert fe.stiffness.tolist() == python.force_elements["spring"].stiffness.tolist()
    assert fe.preload == 5.0 and fe.free_length == 0.9
    a = built.system.static(static_method="newton")
    b = python.static(static_method="newton")
    assert np.array_equal(a.probes["c"], b.probes["c"])


def test_bushing_on_a_plate_is_refused():
    s = System("bad")
    s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.plate("p", material="steel", thickness=0.01, corner=(0, 0, 0), edge_x=(1, 0, 0),
            edge_y=(0, 1, 0), nx=2, ny=2)
    with pytest.raises(InputError, match="three direction vectors"):
        s.force_element("fe", "bushing", "ground", "p", point=(0.5, 0.5, 0), stiffness=[1, 1, 1])


@pytest.mark.parametrize("call, message", [
    (dict(type="spring_damper", point1=(0, 0, 0), point2=(0, 0, -1.0)), "needs stiffness"),
    (dict(type="spring_damper", point1=(0, 0, 0), point2=(0, 0, -1.0), stiffness=-1.0),
     "must not be negative"),
    (dict(type="bushing", point=(0, 0, -1.0), stiffness=1.0), "takes 3 values"),
    (dict(type="cylinder", point1=(0, 0, 0), point2=(0, 0, -1.0), stiffness=1.0), "needs drive"),
    (dict(type="spring_damper", point1=(0, 0, 0), point2=(0, 0, -1.0), stiffness=1.0,
          deflections=[0, 1], forces=[0, 1]), "replaces stiffness"),
    (dict(type="spring_damper", point1=(0, 0, 0), point2=(0, 0, -1.0), deflections=[0, 1],
          forces=[0, 1], interpolation="spline"), "must be one of"),
])
def test_bad_input_names_the_item(call, message):
    s = System("bad")
    s.rigid_body("box", mass=1.0, inertia=(0.1, 0.1, 0.1, 0, 0, 0), position=(0, 0, -1.0))
    with pytest.raises(InputError, match=message) as exc:
        s.force_element("fe", body1="ground", body2="box", **call)
    assert "fe" in str(exc.value)


# -- the example --------------------------------------------------------------------------------
def test_boom_mounts_example_matches_the_rigid_moment_balance(tmp_path):
    """examples/boom_mounts.py --quick: the static strut forces within 0.2 % of the rigid
    moment balance about the hinge (the rest: the boom's bending), the cylinder force during
    the constant-rate lift within 1 % of the balance at the angle and rate reached (the
    rest: the start's vibration), the oil column's compression the force over its
    stiffness, and the energy balance closed to 1e-6 of the drive's work."""
    import sys
    from pathlib import Path
    folder = str(Path(__file__).resolve().parents[1] / "examples")
    if folder not in sys.path:   # as tests/test_examples.py imports the scripts
        sys.path.insert(0, folder)
    import boom_mounts
    out = boom_mounts.run(True, tmp_path)
    assert out["cylinder"] == pytest.approx(out["rigid_cylinder"], rel=2e-3)
    assert out["gas"] == pytest.approx(out["rigid_gas"], rel=2e-3)
    assert out["end_force"] == pytest.approx(out["rigid_end"], rel=1e-2)
    assert out["column"] == pytest.approx(out["end_force"] / out["boom"].oil_stiffness,
                                          rel=2e-3)
    energy = out["lift"].energy
    assert abs(np.asarray(energy["balance"])[-1]) <= 1e-6 * np.asarray(energy["drive_work"])[-1]
    assert (tmp_path / "boom_mounts_lift.h5").is_file()
