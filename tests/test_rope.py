"""The hoist rope: an ANCF cable with ``tension_only=True`` (fortran/src/elements/
cable_element.f90, python/ancfdrv/system/kinds/cable.py) carrying a payload.

Element checks: the rope's law against the cable's (taut: the same force; compressed: no
axial force at all, only bending), the analytic tangent against central differences on
both sides of the kink and in an element that is partly slack, rigid motions without energy
at a large rotation, the unstrained reference keeping its axial stiffness, and the axial
Kelvin-Voigt damping (tangent against differences, its power, tension only, never
compressive). System checks: a hanging payload's static stretch against the closed form of
the element's law, the top reaction against the weight; a payload thrown up by the rope
itself (released from a pre-stretch) flies free while the rope is slack, the energy at
rho_inf = 1 across the slack/taut cycle converges with the step; the pendulum period of a
rigid-body payload on a rope against the compound pendulum of rope and payload.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from ancfdrv import Circle, System, kernel

DOFS = np.arange(12).reshape(12, 1)
GRAVITY = 9.81


def _rotation(axis, angle: float) -> np.ndarray:
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    skew = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * skew + (1.0 - np.cos(angle)) * skew @ skew


def _element(length: float, stretch_start: float, stretch_end: float, bend: float = 0.0,
             seed: int = 0) -> np.ndarray:
    """One element's nodal vectors [r1, r1', r2, r2'] along x with the slopes' lengths
    stretch_start and stretch_end (so r'.r' and the Green strain vary along it), a bend
    of the slopes and a small random twist of the centre line."""
    rng = np.random.default_rng(seed)
    q = np.concatenate([[0.0, 0.0, 0.0], [stretch_start, bend, 0.0],
                        [0.5 * (stretch_start + stretch_end) * length, 0.0, 0.0],
                        [stretch_end, -bend, 0.0]])
    return q + 1e-3 * rng.standard_normal(12)


def _gauss_strains(q: np.ndarray, length: float) -> np.ndarray:
    x, _ = np.polynomial.legendre.leggauss(5)
    out = []
    for xi in 0.5 * (x + 1.0):
        _, slope, _ = kernel.cable_shape(xi, length)
        a = q.reshape(4, 3).T @ slope
        out.append(0.5 * (a @ a - 1.0))
    return np.array(out)


def _central_tangent(q, length, ea, ei, tension_only=True, h=1e-7):
    numeric = np.zeros((12, 12))
    for j in range(12):
        dq = np.zeros(12)
        dq[j] = h
        fp, _, _, _ = kernel.cable_forces(DOFS, q + dq, [length], ea, ei, False, tension_only)
        fm, _, _, _ = kernel.cable_forces(DOFS, q - dq, [length], ea, ei, False, tension_only)
        numeric[:, j] = (fp - fm) / (2 * h)
    return numeric


def _bending_energy(q: np.ndarray, length: float, ei: float) -> float:
    """The rope's bending energy EI/2 int |r' x r''|^2 dx by a 6-point Gauss rule on the
    kernel's shape rows (exact: the integrand is a polynomial of degree 6)."""
    x, w = np.polynomial.legendre.leggauss(6)
    nodal = q.reshape(4, 3).T
    energy = 0.0
    for xi, wi in zip(0.5 * (x + 1.0), 0.5 * w * length):
        _, slope, second = kernel.cable_shape(xi, length)
        energy += wi * 0.5 * ei * float(np.sum(np.cross(nodal @ slope, nodal @ second) ** 2))
    return energy


def test_rope_law_taut_like_the_cable_compressed_without_axial_force():
    """The axial part: where every Gauss point is stretched the rope's force, energy and
    tangent are the cable's (EI = 0 in both; to rounding), where every one is compressed
    they vanish: the rope carries no compression. The bending part is the linear
    EI/2 r''.r'' (defined where r' = 0): force and energy against a Gauss integration of
    the shape rows, taut and slack alike."""
    length, ea, ei = 0.6, 50.0, 0.3
    taut = _element(length, 1.02, 1.03, bend=0.1)
    slack = _element(length, 0.97, 0.95, bend=0.1, seed=1)
    assert _gauss_strains(taut, length).min() > 1e-3
    assert _gauss_strains(slack, length).max() < -1e-3
    f_rope, u_rope, k_rope, _ = kernel.cable_forces(DOFS, taut, [length], ea, 0.0, True, True)
    f_ref, u_ref, k_ref, _ = kernel.cable_forces(DOFS, taut, [length], ea, 0.0, True)
    assert np.abs(f_rope - f_ref).max() <= 1e-13 * np.abs(f_ref).max()
    assert u_rope == pytest.approx(u_ref, rel=1e-13)
    assert np.abs(k_rope - k_ref).max() <= 1e-13 * np.abs(k_ref).max()
    f_slack, u_slack, k_slack, _ = kernel.cable_forces(DOFS, slack, [length], ea, 0.0, True, True)
    assert u_slack == 0.0 and not f_slack.any() and not k_slack.any()
    h = 1e-6
    for q in (taut, slack):
        f_bend, u_bend, _, _ = kernel.cable_forces(DOFS, q, [length], 0.0, ei, True, True)
        assert u_bend == pytest.approx(_bending_energy(q, length, ei), rel=1e-12)
        gradient = np.array([(_bending_energy(q + h * np.eye(12)[j], length, ei)
                              - _bending_energy(q - h * np.eye(12)[j], length, ei)) / (2 * h)
                             for j in range(12)])
        assert np.abs(f_bend - gradient).max() <= 1e-7 * np.abs(f_bend).max()
    # a straight rope stretched unevenly (r'' along r') has no bending force
    uneven = np.concatenate([[0, 0, 0], [1.0, 0, 0], [0.65, 0, 0], [1.2, 0, 0]])
    f_line, u_line, _, _ = kernel.cable_forces(DOFS, uneven, [length], 0.0, ei, False, True)
    assert abs(u_line) <= 1e-14 * ei and np.abs(f_line).max() <= 1e-13 * ei  # rounding
    # r' = 0 at a Gauss point (a folded rope): defined, the plain cable refuses it
    folded = np.concatenate([[0, 0, 0], [0.0, 0.3, 0], [0, 0, 0], [0.0, -0.3, 0]])
    kernel.cable_forces(DOFS, folded, [length], ea, ei, True, True)


@pytest.mark.parametrize("case", ["taut", "slack", "partly slack"])
def test_rope_tangent_matches_central_differences(case):
    """The analytic tangent against central differences (h = 1e-7) on each side of the kink
    and in an element whose strain changes sign along it (Gauss points between -2e-2 and
    +2e-2, none within 1e-4 of zero, so no difference step crosses the kink); symmetric."""
    length, ea, ei = 0.6, 50.0, 0.3
    q = {"taut": _element(length, 1.02, 1.03, bend=0.2),
         "slack": _element(length, 0.97, 0.95, bend=0.2, seed=1),
         "partly slack": _element(length, 0.98, 1.02, bend=0.2, seed=2)}[case]
    strains = _gauss_strains(q, length)
    assert np.abs(strains).min() > 1e-4
    if case == "partly slack":
        assert strains.min() < 0.0 < strains.max()
    _, _, tangent, _ = kernel.cable_forces(DOFS, q, [length], ea, ei, True, True)
    numeric = _central_tangent(q, length, ea, ei)
    assert np.abs(tangent[:, :, 0] - numeric).max() <= 1e-6 * np.abs(numeric).max()
    assert np.abs(tangent[:, :, 0] - tangent[:, :, 0].T).max() <= 1e-13 * np.abs(tangent).max()


@pytest.mark.parametrize("angle", [0.0, 2.3])
def test_rope_rigid_motions_and_reference_stiffness(angle):
    """A straight, unstrained rope translated and turned by up to 2.3 rad has no energy and
    no force (to rounding), and its axial tangent there is the cable's: the reference, unstrained
    to rounding, keeps the axial stiffness EA a a^T (the taut side's, module header), so a
    static Newton step from it is regular."""
    length, ea, ei = 0.5, 7.0e6, 2.0
    rot = _rotation([0.3, -1.0, 0.6], angle)
    q = np.concatenate([[0, 0, 0], [1, 0, 0], [length, 0, 0], [1, 0, 0]]).reshape(4, 3) @ rot.T
    q[[0, 2]] += np.array([1.2, -0.4, 3.0])
    force, energy, tangent, _ = kernel.cable_forces(DOFS, q.ravel(), [length], ea, ei, True, True)
    assert abs(energy) <= 1e-13 * ea * length
    assert np.abs(force).max() <= 1e-9 * ea
    _, _, cable, _ = kernel.cable_forces(DOFS, q.ravel(), [length], ea, 0.0, True, False)
    _, _, bending, _ = kernel.cable_forces(DOFS, q.ravel(), [length], 0.0, ei, True, True)
    assert np.abs(tangent - bending - cable).max() <= 1e-9 * np.abs(cable).max()
    # a uniform stretch u (r' grows by u along the axis everywhere): u^T K u = EA L
    axis = rot @ np.array([1.0, 0.0, 0.0])
    stretch = np.concatenate([0 * axis, axis, length * axis, axis])
    assert stretch @ tangent[:, :, 0] @ stretch == pytest.approx(ea * length, rel=1e-9)


@pytest.mark.parametrize("case", ["taut", "clipped"])
def test_rope_damping_tangent_power_and_clipping(case):
    """The axial Kelvin-Voigt damping N_d = EA tau eps' (tension only): the combined tangent
    dQ/dq + c dQ/dq' against central differences in q and in q' (c = 37), the dissipation
    equal to the damping force's power (Q_damped - Q) . q' >= 0; when the rope unloads
    faster than the damping allows (EA eps + N_d < 0: 'clipped') its axial force is zero,
    the force is the bending alone (EA = 0). In a slack element damping adds nothing."""
    length, ea, ei, tau, c = 0.6, 50.0, 0.3, 0.02, 37.0
    q = _element(length, 1.02, 1.03, bend=0.1)
    rng = np.random.default_rng(5)
    v = 0.1 * rng.standard_normal(12)
    if case == "clipped":  # shorten fast: eps' ~ -3/s, tau eps' ~ -0.06 below -eps ~ -0.03
        v = v - 3.0 * np.concatenate([[0, 0, 0], [1, 0, 0], [length, 0, 0], [1, 0, 0]])

    def damped(q, v):
        return kernel.cable_forces(DOFS, q, [length], ea, ei, True, True, rates=v,
                                   damping_time=tau, rate_factor=c)
    f, u, k, power = damped(q, v)
    f0, u0, _, _ = kernel.cable_forces(DOFS, q, [length], ea, ei, False, True)
    assert u == pytest.approx(u0, rel=1e-14)
    assert power == pytest.approx((f - f0) @ v, rel=1e-12)
    assert power > 0.0
    if case == "clipped":
        fb, _, _, _ = kernel.cable_forces(DOFS, q, [length], 0.0, ei, False, True)
        assert np.abs(f - fb).max() <= 1e-13 * np.abs(f0).max()
    h = 1e-7
    numeric = np.zeros((12, 12))
    for j in range(12):
        dq = np.zeros(12)
        dq[j] = h
        fp = damped(q + dq, v)[0]
        fm = damped(q - dq, v)[0]
        gp = damped(q, v + dq)[0]
        gm = damped(q, v - dq)[0]
        numeric[:, j] = (fp - fm) / (2 * h) + c * (gp - gm) / (2 * h)
    assert np.abs(k[:, :, 0] - numeric).max() <= 1e-6 * np.abs(numeric).max()
    slack = _element(length, 0.97, 0.95, bend=0.1, seed=1)
    fs, _, _, ps = damped(slack, v)
    assert ps == 0.0
    assert np.array_equal(fs, kernel.cable_forces(DOFS, slack, [length], ea, ei, False, True)[0])


# -- a rope with a payload ----------------------------------------------------------------------
STEEL_E, STEEL_RHO = 1.0e11, 7850.0           # a wire rope's effective modulus, steel density


def test_hanging_payload_stretch_and_top_tension():
    """A 2 m rope (d = 10 mm, E = 100 GPa, 4 elements) with 100 kg at its end, statics: the
    end sinks by the closed form of the element's law, int_0^L (lambda(s) - 1) ds with
    EA (lambda^2 - 1) lambda / 2 = m g + rho A g s (the tension at s above the end; Green
    strain, lambda the stretch), within 1e-9 (measured 2e-12); the linear estimate
    (m g + rho A g L / 2) L / (E A) differs from it by 1.9e-4 (the strain's own size) and
    is not met at that tolerance. The top joint's reaction is the weight m g + rho A g L
    (equilibrium), 1e-10."""
    length, mass, d = 2.0, 100.0, 0.01
    area = np.pi * d**2 / 4.0
    ea, w = STEEL_E * area, STEEL_RHO * area * GRAVITY
    s = System("hanging payload")
    wire = s.material("wire rope", youngs_modulus=STEEL_E, density=STEEL_RHO)
    s.cable("rope", material=wire, start=(0, 0, 0), end=(0, -length, 0), nodes=5,
            section=Circle(d), tension_only=True, bending_stiffness=1.0)
    s.joint("top", "spherical", "ground", "rope", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -GRAVITY, 0))
    s.load("payload", "point_mass", body="rope", point=(0, -length, 0), mass=mass)
    s.probe("hook", "rope", (0, -length, 0))
    res = s.static(static_method="newton", tol=1e-12)
    sink = -(res.static.probes["hook"][1] + length)
    x, wx = np.polynomial.legendre.leggauss(20)
    stations, weights = 0.5 * length * (x + 1.0), 0.5 * length * wx

    def stretch(tension: float) -> float:  # the root near 1 of lambda^3 - lambda - 2T/EA
        lam = 1.0
        for _ in range(50):
            lam -= (lam**3 - lam - 2.0 * tension / ea) / (3.0 * lam**2 - 1.0)
        return lam
    exact = sum(wt * (stretch(mass * GRAVITY + w * st) - 1.0)
                for st, wt in zip(stations, weights))
    linear = (mass * GRAVITY + w * length / 2.0) * length / ea
    assert sink == pytest.approx(exact, rel=1e-9)
    assert abs(linear / exact - 1.0) > 1e-4
    top = res.static.reactions["top"]["force"]
    assert np.allclose(top, [0.0, mass * GRAVITY + w * length, 0.0], rtol=1e-10, atol=1e-8)


def _thrown_payload(dt: float, t_end: float = 0.5, pull: float = 3.0):
    """A nylon rope (2 m, d = 10 mm, E = 1.25 GPa: static stretch 20 mm under 100 kg; one
    element, EI = 0.1 N m^2) hanging from the ground with 100 kg at its end, pulled down by
    pull x m g in the static start and released within the first step: the rope throws the
    payload up past its unstretched length, goes slack, and catches it again."""
    length, mass = 2.0, 100.0
    s = System("thrown payload")
    nylon = s.material("nylon", youngs_modulus=1.25e9, density=1140.0)
    rope = s.cable("rope", material=nylon, start=(0, 0, 0), end=(0, -length, 0), nodes=2,
                   section=Circle(0.01), tension_only=True, bending_stiffness=0.1)
    s.joint("top", "spherical", "ground", "rope", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -GRAVITY, 0))
    s.load("payload", "point_mass", body="rope", point=(0, -length, 0), mass=mass)
    s.probe("hook", "rope", (0, -length, 0))
    free_model = s.assemble()          # the system without the pull: its free accelerations
    try:
        m_full, f_free = free_model.mass_matrix().toarray(), free_model.constant_force()
        if free_model.reduction is None:
            free = np.setdiff1d(np.arange(free_model.ndof), rope.node_first(0) + np.arange(3))
            accel = np.zeros(free_model.ndof)
            accel[free] = np.linalg.solve(m_full[np.ix_(free, free)], f_free[free])
        else:
            accel = free_model.expand(np.linalg.solve(m_full, f_free), with_offset=False)
        free_accel = float(accel[rope.node_first(1) + 1])
    finally:
        free_model.close()
    s.drive("release", "table", times=(0.0, dt), values=(1.0, 0.0))
    s.load("pull", "force", body="rope", point=(0, -length, 0),
           vector=(0, -pull * mass * GRAVITY, 0), drive="release")
    res = s.simulate(t_end, dt, from_static=True, tol=1e-12, newton_tol=1e-10, q=True,
                     xdmf=False)
    return rope, res, free_accel


def test_thrown_payload_flies_free_while_the_rope_is_slack():
    """While every Gauss point of the rope is slack the payload's positions are a parabola
    (the average-acceleration stepper integrates a constant acceleration exactly) to 1e-10 m,
    its acceleration that of the system without rope forces, M^-1 Q_gravity with the top
    held (1e-7: Newton's tolerance over h^2; measured 5e-13), which is -g to 1.1e-4
    (measured 3.0e-5: the consistent mass couples the end to the held top; rope mass
    0.18 kg, 1.8e-3 of the payload's). The rope is compressed (strain down to < -1e-2)
    and still carries
    no compression (axial force >= 0 at every Gauss point). (The top joint's reaction is
    not the rope's tension: it also carries the inertia the consistent mass couples to the
    held node, and dips to -38 N when the rope snaps taut, against 220 N of tension.)"""
    dt = 2e-4
    rope, res, free_accel = _thrown_payload(dt)
    t, y = res.time, res.probes["hook"][:, 1]
    forces = rope.axial_forces(res.dynamic.q).reshape(len(t), -1)
    strains = rope.strains(res.dynamic.q)
    assert forces.min() >= 0.0
    recorded = res.dynamic.tension["rope"]   # the run's series, recorded chunk by chunk
    assert np.array_equal(recorded["max"], forces.max(axis=1))
    assert np.array_equal(recorded["min"], forces.min(axis=1))
    assert strains.min() < -1e-2
    slack = np.flatnonzero(forces.max(axis=1) == 0.0)
    runs = np.split(slack, np.flatnonzero(np.diff(slack) > 1) + 1)
    run = max(runs, key=len)
    tt, yy = t[run], y[run]
    fit = np.polyfit(tt - tt[0], yy, 2)
    assert np.abs(np.polyval(fit, tt - tt[0]) - yy).max() < 1e-10
    assert 2.0 * fit[0] == pytest.approx(free_accel, rel=1e-7)
    assert free_accel == pytest.approx(-GRAVITY, rel=1.1e-4)
    assert len(run) > 100       # 43 ms: the longest stretch of the flight with no force
    # above its unstretched length the payload flies 0.24 s; within that the rope's own
    # axial vibration (one element, 0.18 kg) re-tautens Gauss points for 7 % of the steps


def test_thrown_payload_energy_across_slack_and_taut_converges():
    """Generalized-alpha with rho_inf = 1 (average acceleration, no numerical damping), no
    material damping: through a slack flight and the catch the total energy after the
    release stays within 2e-5 of the peak kinetic energy at dt = 1e-4, and the error at
    dt = 2e-4 is at least four times larger (second order; the kink is crossed within a
    step). The dt = 2e-4 figure itself moves with round-off-level differences of the
    iteration where Gauss points cross the kink (over Newton tolerances 1e-10 to 2e-12,
    start accelerations by MUMPS or a dense LU, BLAS kernels and math libraries: 0.7e-4 to
    2.1e-4), so it is not bounded on its own; dt = 1e-4 gave 1.0e-5 to 1.3e-5 in every
    case (a ratio of at least 5.4). Halving further is irregular: 5e-5 gave 0.86e-5 to
    0.90e-5, 2.5e-5 8.1e-7, 1.25e-5 2.4e-7. (A rope whose own axial modes the step does not
    resolve, e.g. 100 times lighter, gains energy without bound at rho_inf = 1: take
    rho_inf < 1 or damping; docs/theory.md.)"""
    errors = []
    for dt in (2e-4, 1e-4):
        _, res, _ = _thrown_payload(dt, t_end=0.45)
        keep = res.time > 2 * dt
        total = res.energy["total"][keep]
        errors.append(np.ptp(total) / res.energy["kinetic"].max())
    assert errors[1] < 2e-5
    assert errors[1] < errors[0] / 4.0


def test_pendulum_period_of_a_rigid_payload_on_a_rope():
    """A 100 kg rigid payload (a sphere, centre of mass at the rope's end, joined by a
    'spherical' joint) on a 2 m steel rope (d = 10 mm, 1.23 kg, 2 elements) released at
    rest, unstretched, 3 deg from the vertical. Twice the time between the first two
    crossings of the vertical against the compound pendulum of a straight rope and the
    payload, 2 pi sqrt((m L^2 + m_r L^2 / 3) / ((m L + m_r L / 2) g)) (1 + theta0^2 / 16),
    L stretched by the static weight: within 1e-4 (measured 9e-6: the rope is not rigid,
    the start excites its axial mode); the massless-rope period 2 pi sqrt(L / g) is 1.0e-3
    away (the rope's mass effect, m_r / (12 m) of the period), resolved."""
    length, mass, d, theta0 = 2.0, 100.0, 0.01, np.radians(3.0)
    area = np.pi * d**2 / 4.0
    rope_mass = STEEL_RHO * area * length
    end = length * np.array([np.sin(theta0), -np.cos(theta0), 0.0])
    s = System("rope pendulum")
    wire = s.material("wire rope", youngs_modulus=STEEL_E, density=STEEL_RHO)
    s.cable("rope", material=wire, start=(0, 0, 0), end=end, nodes=3, section=Circle(d),
            tension_only=True, bending_stiffness=1.0)
    inertia = 0.4 * mass * 0.15**2
    s.rigid_body("payload", mass=mass, inertia=(inertia, inertia, inertia, 0, 0, 0),
                 position=end)
    s.joint("top", "spherical", "ground", "rope", point=(0, 0, 0))
    s.joint("hook", "spherical", "rope", "payload", point=end)
    s.load("g", "gravity", vector=(0, -GRAVITY, 0))
    s.probe("payload", "payload", end)
    res = s.simulate(2.3, 4e-3, newton_tol=1e-8, xdmf=False)
    t, x = res.time, res.probes["payload"][:, 0]
    k = np.flatnonzero(np.sign(x[1:]) != np.sign(x[:-1]))
    crossings = t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])
    period = 2.0 * (crossings[1] - crossings[0])
    stretched = length * (1.0 + (mass + rope_mass / 2.0) * GRAVITY / (STEEL_E * area))
    compound = 2.0 * np.pi * np.sqrt(
        (mass + rope_mass / 3.0) * stretched / ((mass + rope_mass / 2.0) * GRAVITY))
    compound *= 1.0 + theta0**2 / 16.0
    massless = 2.0 * np.pi * np.sqrt(stretched / GRAVITY) * (1.0 + theta0**2 / 16.0)
    assert period == pytest.approx(compound, rel=1e-4)
    assert abs(period / massless - 1.0) > 5e-4


# -- the example: a knuckle crane with a hoist rope ----------------------------------------------
def test_knuckle_crane_rope_example_and_its_scene(tmp_path):
    """examples/knuckle_crane_rope.py --quick: the rope's static tension at the top is the
    weight it carries, (m + m_rope) g (equilibrium, 1e-9), the hook hangs the rope's length
    stretched by its mean load below the jib tip (1e-6 m), the payload swings after the stop
    with the period of the pendulum of the stretched rope with its mass, 2 pi sqrt(L / g)
    (1 + mu/3)^1/2 / (1 + mu/2)^1/2 (within 2e-3: dt = 10 ms with rho_inf = 0.8 and the
    jib's compliance; measured 5.0e-4 with the compliant cylinder, the period fitted by least
    squares over the payload's bounce on the oil column; 6e-4 from the crossings with the
    rigid one), the rope never goes slack in this lift. The jib cylinder is the compliant
    'cylinder' force element: its static force equals the jib's moment balance about the
    knuckle (a rigid jib on the static chord: its weight and the rope's pull; measured
    7.7e-6, the jib's own bending), and its oil column is shortened by |f| / k (the lug
    probes' distance against the drive's length: the law's consistency, 1e-9). The scene
    inputs/knuckle_crane_rope.nml is the same crane: its static hook position equals the
    example's (1e-9 m)."""
    import h5py

    from ancfdrv.runner import run_scene
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
    import knuckle_crane_rope as example
    r = example.run(quick=True, out=tmp_path / "example")
    assert r.top_tension_static == pytest.approx(r.weight, rel=1e-9)
    assert r.depth_static == pytest.approx(r.depth_expected, abs=1e-6)
    assert r.swing_period == pytest.approx(r.pendulum_period, rel=2e-3)
    assert r.swing_amplitude > np.radians(0.5)
    assert r.slack_steps == 0 and r.tension[:, 0].min() > 0.0
    assert r.cylinder_static < -3e4   # the cylinder pushes
    assert r.cylinder_static == pytest.approx(r.cylinder_balance, rel=5e-5)
    assert r.compression_static == pytest.approx(r.compression_expected, rel=1e-9)
    assert 1e-3 < r.compression_static < 1e-2
    scene = Path(__file__).resolve().parents[1] / "inputs" / "knuckle_crane_rope.nml"
    run_scene(scene, ["scene.analysis=static"], tmp_path / "scene.h5", progress=False)
    with h5py.File(tmp_path / "scene.h5") as h5:
        hook = h5["static/probes/hook"][()].ravel()
    with h5py.File(r.files[0]) as h5:
        assert np.allclose(hook, h5["static/probes/hook"][()].ravel(), rtol=0, atol=1e-9)


def test_rope_damping_decay_and_energy_balance():
    """Axial Kelvin-Voigt damping of a rope (material damping_time tau = 2 ms, effect
    'damping'): 100 kg hanging on the nylon rope of the throw above (k = EA / L = 49.1 kN/m),
    pulled down by 0.5 m g in the static start and released: it stays taut and its
    oscillation decays with the damping ratio zeta = omega tau / 2 of the stiffness-
    proportional damping c = tau k (omega = sqrt(k / m)): the ratio of successive swings
    (peak to trough) exp(-2 pi zeta / sqrt(1 - zeta^2)) = 0.8700 within 2e-3 (measured
    0.8694: the rope's 0.18 kg, the Green strain's nonlinearity); and thrown (pulled by
    3 m g, slack in between) the energy lost equals
    the damping's work (the balance total - works moves by < 1e-4 of the work; measured
    2.7e-5 of 17.0 J)."""
    length, mass, tau, dt = 2.0, 100.0, 2e-3, 1e-3

    def system(pull: float):
        s = System("damped rope")
        nylon = s.material("nylon", youngs_modulus=1.25e9, density=1140.0, damping_time=tau)
        s.cable("rope", material=nylon, start=(0, 0, 0), end=(0, -length, 0), nodes=2,
                section=Circle(0.01), tension_only=True, bending_stiffness=0.1)
        s.joint("top", "spherical", "ground", "rope", point=(0, 0, 0))
        s.load("g", "gravity", vector=(0, -GRAVITY, 0))
        s.load("payload", "point_mass", body="rope", point=(0, -length, 0), mass=mass)
        s.probe("hook", "rope", (0, -length, 0))
        s.drive("release", "table", times=(0.0, dt), values=(1.0, 0.0))
        s.load("pull", "force", body="rope", point=(0, -length, 0),
               vector=(0, -pull * mass * GRAVITY, 0), drive="release")
        return s
    res = system(0.5).simulate(1.0, dt, from_static=True, tol=1e-12, newton_tol=1e-10,
                               xdmf=False)
    assert res.counters["damping"] > 0
    y = res.probes["hook"][:, 1]
    peaks = [k for k in range(1, len(y) - 1) if y[k] > y[k - 1] and y[k] >= y[k + 1]]
    troughs = [k for k in range(1, len(y) - 1) if y[k] < y[k - 1] and y[k] <= y[k + 1]]
    swings = np.array([y[p] - y[min(q for q in troughs if q > p)] for p in peaks
                       if any(q > p for q in troughs)])      # peak to the next trough
    ratios = swings[1:] / swings[:-1]
    k_rope = 1.25e9 * np.pi * 0.01**2 / 4.0 / length
    zeta = np.sqrt(k_rope / mass) * tau / 2.0
    expected = np.exp(-2.0 * np.pi * zeta / np.sqrt(1.0 - zeta**2))
    assert len(ratios) >= 2
    assert ratios == pytest.approx(expected, rel=2e-3)
    thrown = system(3.0).simulate(0.45, 2e-4, from_static=True, tol=1e-12, newton_tol=1e-10,
                                  xdmf=False)
    keep = thrown.time > 1.5 * dt      # after the release
    work = thrown.energy["material_damping_work"][keep]
    balance = thrown.energy["balance"][keep]
    assert -work[-1] > 10.0       # J: the rope dissipates while taut
    assert np.ptp(balance) < 1e-4 * abs(work[-1])
