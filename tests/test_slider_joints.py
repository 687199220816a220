"""The joint types 'prismatic', 'cylindrical' and 'universal' (SPEC 8.1, issue 22).

References, each independent of the code under test:

* closed forms of rigid-body mechanics: a block on a frictionless incline slides by
  g sin(theta) t^2 / 2 and the guide pushes with m g cos(theta) along the incline's normal;
  a driven slide carries m (s'' - g . a) along the axis; an axisymmetric rotor on a
  cylindrical joint gains the spin T P / (2 I_a) and the axial speed F P / (2 m) from a
  force and a torque pulse amplitude (1 - cos(2 pi t / P)) / 2 and keeps both afterwards
  (no torque about, no force along the axis: invariants), while the joint carries its weight
  and the weight's moment about the joint's point;
* the Cardan joint's speed ratio w2 / w1 = cos(beta) / (1 - sin^2(beta) sin^2(theta1))
  (theta1 from the input yoke normal to the shafts' plane; derived from the cross's
  condition u1 . v2 = 0, i.e. tan(theta2) = tan(theta1) / cos(beta));
* central differences of the joint equations (values -> Jacobian -> Hessian) at a state with
  large rotations of every body;
* global equilibrium of a beam held at a point between its nodes (reaction = weight, moment
  = weight times its lever arm) and Newton's second law for its centre of mass.
"""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import Rectangle, System
from ancfdrv.errors import InputError
from ancfdrv.solvers.dynamic import DynamicSettings, integrate
from ancfdrv.solvers.static import solve_newton
from ancfdrv.system import RigidBody

G = 9.81


# ------------------------------------------------------------------------- prismatic
@pytest.mark.parametrize("ground_first", [True, False], ids=["ground-block", "block-ground"])
def test_block_slides_down_a_frictionless_incline(ground_first):
    """A 3 kg block on a prismatic guide inclined 30 degrees, gravity -z, from rest: its
    displacement along the guide is g sin(theta) t^2 / 2 (1e-12 m over 1 s), the guide's
    reaction on the block is m g cos(theta) along the incline's normal with no moment about
    the block's centre (1e-9 relative); named the other way round (block, ground) the
    reaction is what the block exerts on the ground: the opposite."""
    theta, m = np.radians(30.0), 3.0
    axis = np.array([np.cos(theta), 0.0, -np.sin(theta)])
    normal = np.array([np.sin(theta), 0.0, np.cos(theta)])
    s = System("incline")
    s.rigid_body("block", mass=m, inertia=(0.1, 0.2, 0.3, 0, 0, 0), position=(1, 0, 2))
    bodies = ("ground", "block") if ground_first else ("block", "ground")
    s.joint("guide", "prismatic", *bodies, point=(1, 0, 2), axis=axis)
    s.load("g", "gravity", vector=(0, 0, -G))
    s.probe("c", "block", (1, 0, 2))
    res = s.simulate(t_end=1.0, dt=0.01)
    assert res.status == "ok"
    t, p = res.time, res.probes["c"]
    slide = (p - p[0]) @ axis
    np.testing.assert_allclose(slide, G * np.sin(theta) * t**2 / 2, rtol=0, atol=1e-12)
    np.testing.assert_allclose(p - p[0] - np.outer(slide, axis), 0.0, atol=1e-12)
    sign = 1.0 if ground_first else -1.0
    reaction = res.reactions["guide"]
    np.testing.assert_allclose(reaction["force"], sign * m * G * np.cos(theta) * np.tile(
        normal, (len(t), 1)), rtol=0, atol=1e-9 * m * G)
    np.testing.assert_allclose(reaction["moment"], 0.0, atol=1e-9 * m * G)


@pytest.mark.parametrize("ground_first", [True, False], ids=["ground-block", "block-ground"])
def test_driven_prismatic_follows_its_drive_and_carries_the_actuator_force(ground_first):
    """A prismatic actuator along a 30 degree incline moves the block by
    s(t) = A (1 - cos(2 pi f t)) (a 'sine' drive with offset A, phase -pi/2: at rest at
    t = 0): the block's displacement along the axis equals s(t) - s(0) (1e-12 m), and the
    reaction is m g cos(theta) along the normal (1e-12 relative) plus the actuator's force
    m (s'' - g . a) along the axis: within 1.5e-4 of its amplitude m A (2 pi f)^2 at
    dt = 2 ms (the trapezoidal rule's accelerations of a prescribed motion alternate about
    the exact ones: measured 1.03e-4, and 2.6e-5 at dt = 1 ms, second order). The
    multiplier of 'ram: slide(t)' is that force along the axis. Named (block, ground) the
    drive moves p2 - p1 = ground - block: the block moves by -s(t), and the reaction is what
    the block exerts on the ground."""
    theta, m, amp, freq = np.radians(30.0), 2.0, 0.2, 1.5
    axis = np.array([np.cos(theta), 0.0, -np.sin(theta)])
    normal = np.array([np.sin(theta), 0.0, np.cos(theta)])
    s = System("actuator")
    s.drive("stroke", "sine", amplitude=amp, frequency=freq, phase=-np.pi / 2, offset=amp)
    s.rigid_body("block", mass=m, inertia=(0.1, 0.1, 0.1, 0, 0, 0), position=(0, 0, 0))
    bodies = ("ground", "block") if ground_first else ("block", "ground")
    sign = 1.0 if ground_first else -1.0
    s.joint("ram", "prismatic", *bodies, point=(0, 0, 0), axis=axis, drive="stroke")
    s.load("g", "gravity", vector=(0, 0, -G))
    s.probe("c", "block", (0, 0, 0))
    res = s.simulate(t_end=1.0, dt=0.002)
    assert res.status == "ok"
    t, p = res.time, res.probes["c"]
    stroke = sign * amp * (1 - np.cos(2 * np.pi * freq * t))
    np.testing.assert_allclose(p @ axis, stroke, rtol=0, atol=1e-12)
    np.testing.assert_allclose(p - np.outer(p @ axis, axis), 0.0, atol=1e-12)
    accel = sign * amp * (2 * np.pi * freq)**2 * np.cos(2 * np.pi * freq * t)
    gravity_along = np.array([0.0, 0.0, -G]) @ axis
    expected = sign * (np.outer(m * (accel - gravity_along), axis)
                       + m * G * np.cos(theta) * normal)
    error = res.reactions["ram"]["force"] - expected
    actuator = res.multiplier("ram: slide(t)")   # the force on the block along the axis
    np.testing.assert_allclose(actuator, m * (accel - gravity_along), rtol=0,
                               atol=1.5e-4 * m * amp * (2 * np.pi * freq)**2)
    np.testing.assert_allclose(error @ normal, 0.0, atol=1e-12 * m * G)
    np.testing.assert_allclose(error - np.outer(error @ axis, axis), 0.0, atol=1e-12 * m * G)
    assert np.abs(error @ axis).max() <= 1.5e-4 * m * amp * (2 * np.pi * freq)**2


def test_contradictory_driven_slides_are_refused_and_consistent_ones_dropped():
    """A driven prismatic and a 'prescribed' translation of the same point along the same
    axis: with two different drives the model is refused naming both joints (the redundancy
    check of SPEC 8.1), with the same drive the repeated equation is dropped and noted."""
    def build(second: str) -> System:
        s = System("two actuators")
        s.drive("a", "sine", amplitude=0.1, frequency=1.0)
        s.drive("b", "sine", amplitude=0.2, frequency=1.0)
        s.rigid_body("block", mass=1.0, inertia=(0.1, 0.1, 0.1, 0, 0, 0), position=(0, 0, 0))
        s.joint("ram", "prismatic", "ground", "block", point=(0, 0, 0), axis=(1, 0, 0),
                drive="a")
        s.joint("push", "prescribed", "ground", "block", point=(0, 0, 0), axis=(1, 0, 0),
                drive=second)
        return s
    with pytest.raises(InputError, match="contradicts") as info:
        build("b").assemble()
    assert "push" in str(info.value) and "ram" in str(info.value)
    model = build("a").assemble()
    try:
        assert any("push: x(t) (implied by the others)" in n for n in model.notes), model.notes
    finally:
        model.close()


# ----------------------------------------------------------------------- cylindrical
def test_cylindrical_rotor_keeps_spin_and_axial_momentum_and_carries_its_weight():
    """A rotor (m = 4 kg, I_a = 0.05, I_t = 0.3 kg m^2) on a cylindrical joint along x whose
    point lies d = 0.3 m from its centre along the axis, gravity -z, a force F = 8 N along
    and a torque T = 2 N m about the axis as a pulse of P = 0.2 s (integral P / 2).

    * After the pulse the axial speed is F P / (2 m) = 0.2 m/s (1e-12: a force along a
      translation integrates exactly) and stays (the centre's x is linear in t to 1e-12 m);
    * the spin rate (from a rim point's angle) is T P / (2 I_a) = 4 rad/s within 5e-5
      (trapezoidal rule on rotating vectors: 5.3e-4 at dt = 5 ms, 1.33e-4 at 2.5 ms, second
      order) and stays constant to 1e-9 (the invariant; 4e-11 measured with the Newton
      tolerance 1e-13 used here, 4e-7 with the default 1e-10, which ends a step's
      iteration before the spin has converged to that level);
    * the centre never leaves the axis, and the joint's reaction is the weight m g up and,
      about the joint's point, the weight's moment m g d along +y (1e-9)."""
    m, ia, it, t0, f0, period, d = 4.0, 0.05, 0.3, 2.0, 8.0, 0.2, 0.3
    s = System("spin and slide")
    s.drive("pulse", "cycle", amplitude=1.0, period=period, t0=0.0)
    s.rigid_body("rotor", mass=m, inertia=(ia, it, it, 0, 0, 0), position=(0, 0, 1))
    s.joint("sleeve", "cylindrical", "ground", "rotor", point=(d, 0, 1), axis=(1, 0, 0))
    s.load("g", "gravity", vector=(0, 0, -G))
    s.load("torque", "moment", body="rotor", point=(0, 0, 1), vector=(t0, 0, 0), drive="pulse")
    s.load("push", "force", body="rotor", point=(0, 0, 1), vector=(f0, 0, 0), drive="pulse")
    s.probe("c", "rotor", (0, 0, 1))
    s.probe("rim", "rotor", (0, 0.1, 1))
    dt = 0.0025
    res = s.simulate(t_end=0.6, dt=dt, newton_tol=1e-13)
    assert res.status == "ok"
    t, c = res.time, res.probes["c"]
    rim = res.probes["rim"] - c
    after = t >= period + 0.5 * dt
    np.testing.assert_allclose(c[:, 1:] - c[0, 1:], 0.0, rtol=0, atol=1e-12)
    speed = np.diff(c[after, 0]) / np.diff(t[after])
    np.testing.assert_allclose(speed, f0 * period / (2 * m), rtol=1e-12)
    angle = np.unwrap(np.arctan2(rim[:, 2], rim[:, 1]))
    spin = np.diff(angle[after]) / np.diff(t[after])
    expected = t0 * period / (2 * ia)
    assert np.abs(spin - expected).max() <= 5e-5 * expected
    assert np.ptp(spin) <= 1e-9 * expected
    reaction = res.reactions["sleeve"]
    np.testing.assert_allclose(reaction["force"], np.tile([0, 0, m * G], (len(t), 1)),
                               rtol=0, atol=1e-9 * m * G)
    np.testing.assert_allclose(reaction["moment"], np.tile([0, m * G * d, 0], (len(t), 1)),
                               rtol=0, atol=1e-9 * m * G)


# ------------------------------------------------------------------------- universal
def _omega(body: RigidBody, q: np.ndarray, q_dot: np.ndarray) -> np.ndarray:
    """A rigid body's angular velocity from its axes J and their rates: J' = [w]x J, so
    w = 1/2 sum_i J_i x J'_i."""
    f = body.first
    return 0.5 * sum(np.cross(q[f + 3 * k:f + 3 * k + 3], q_dot[f + 3 * k:f + 3 * k + 3])
                     for k in (1, 2, 3))


@pytest.mark.parametrize("beta_deg", [20.0, 45.0])
def test_cardan_joint_speed_ratio_against_the_closed_form(beta_deg):
    """Input shaft along x turned by a 'hub' drive (ramp to 2 pi rad/s over 0.2 s, 1.1 turns
    in 1.2 s), output shaft in a bearing along (cos beta, sin beta, 0), a 'universal' joint
    between them with the input yoke along z and the output yoke in the shafts' plane. At
    every step of the dynamic run the velocities that satisfy the joint equations
    (Phi_e v = -Phi_t) give w2 / w1 = cos(beta) / (1 - sin^2(beta) sin^2(theta1)) to 1e-12,
    theta1 the drive's angle."""
    beta = np.radians(beta_deg)
    a2 = np.array([np.cos(beta), np.sin(beta), 0.0])
    s = System("cardan")
    s.drive("spin", "ramp", rate=2 * np.pi, t_ramp=0.2)
    s.rigid_body("in", mass=1.0, inertia=(0.01, 0.02, 0.02, 0, 0, 0), position=(0, 0, 0))
    s.rigid_body("out", mass=1.0, inertia=(0.01, 0.02, 0.02, 0, 0, 0), position=0.5 * a2)
    s.joint("motor", "hub", "ground", "in", point=(0, 0, 0), pivot=(0, 0, 0), axis=(1, 0, 0),
            drive="spin")
    s.joint("bearing", "revolute", "ground", "out", point=0.5 * a2, axis=a2)
    s.joint("cross", "universal", "in", "out", point=(0, 0, 0), axis=(0, 0, 1),
            axis2=(-np.sin(beta), np.cos(beta), 0))
    model = s.assemble()
    rows = []
    try:
        settings = DynamicSettings.generalized_alpha(0.01, 1.2, 0.9, tol=1e-10, max_newton=30)
        settings.store_q = True
        integrate(model, settings, model.e0, sink=rows.append, progress=False)
        states = np.concatenate([r.q for r in rows])
        times = np.concatenate([r.time for r in rows])
        cs = model.constraints
        assert len(cs) == model.ndof   # the input drives everything: no free coordinate
        ratios, expected = [], []
        for e, t in zip(states, times):
            phi_t = cs.evaluate(e, t)[3]
            v = np.linalg.solve(cs.gradient_rows(e, model.ndof, t), -phi_t)
            q, q_dot = model.expand(e), model.expand(v, with_offset=False)
            w1 = _omega(s.bodies["in"], q, q_dot) @ np.array([1.0, 0.0, 0.0])
            w2 = _omega(s.bodies["out"], q, q_dot) @ a2
            if t > 0.0:
                theta1 = s.drives["spin"].value(t)
                ratios.append(w2 / w1)
                expected.append(np.cos(beta) / (1 - np.sin(beta)**2 * np.sin(theta1)**2))
        assert times[-1] == pytest.approx(1.2) and s.drives["spin"].value(1.2) > 2 * np.pi
        np.testing.assert_allclose(ratios, expected, rtol=1e-12)
        assert max(expected) / min(expected) > 1.0 / np.cos(beta)**2 - 1e-6  # the full swing
    finally:
        model.close()


def test_cardan_cross_carries_the_output_shafts_inertia_torque():
    """The same Cardan joint (beta = 30 deg) run by System.simulate: the reaction of the
    'universal' on the output shaft, about the shaft's axis a2, is the torque that speeds
    the shaft up and down, I_22 alpha_2 with alpha_2 = d/dt [w1 cos(beta) / (1 - sin^2(beta)
    sin^2(theta1))] from the drive's angle, rate and acceleration (the bearing takes no
    moment about a2); within 4e-3 of its peak at dt = 2.5 ms (the trapezoidal rule's
    accelerations: 9.2e-3 at 5 ms, 2.5e-3 at 2.5 ms, second order). The cross's and the
    bearing's forces on the shaft add up to zero (its centre does not move: 1e-12)."""
    beta = np.radians(30.0)
    a2 = np.array([np.cos(beta), np.sin(beta), 0.0])
    inertia = (0.01, 0.02, 0.02, 0, 0, 0)
    s = System("cardan")
    s.drive("spin", "ramp", rate=2 * np.pi, t_ramp=0.2)
    s.rigid_body("in", mass=1.0, inertia=inertia, position=(0, 0, 0))
    s.rigid_body("out", mass=1.0, inertia=inertia, position=0.5 * a2)
    s.joint("motor", "hub", "ground", "in", point=(0, 0, 0), pivot=(0, 0, 0), axis=(1, 0, 0),
            drive="spin")
    s.joint("bearing", "revolute", "ground", "out", point=0.5 * a2, axis=a2)
    s.joint("cross", "universal", "in", "out", point=(0, 0, 0), axis=(0, 0, 1),
            axis2=(-np.sin(beta), np.cos(beta), 0))
    res = s.simulate(t_end=1.2, dt=0.0025)
    assert res.status == "ok"
    theta, w1, a1 = s.drives["spin"].values(res.time)
    sb2 = np.sin(beta)**2
    den = 1 - sb2 * np.sin(theta)**2
    alpha2 = a1 * np.cos(beta) / den + w1**2 * np.cos(beta) * sb2 * np.sin(2 * theta) / den**2
    torque = (a2 @ np.diag(inertia[:3]) @ a2) * alpha2
    moment = res.reactions["cross"]["moment"] @ a2
    assert np.abs(moment - torque).max() <= 4e-3 * np.abs(torque).max()
    total = res.reactions["cross"]["force"] + res.reactions["bearing"]["force"]
    np.testing.assert_allclose(total, 0.0, atol=1e-12)


def test_universal_refuses_axes_that_are_not_normal():
    s = System("bad cross")
    s.rigid_body("a", mass=1.0, inertia=(1, 1, 1, 0, 0, 0), position=(0, 0, 0))
    with pytest.raises(InputError, match="normal to each other"):
        s.joint("x", "universal", "ground", "a", point=(0, 0, 0), axis=(0, 0, 1),
                axis2=(0, 1, 1))
    with pytest.raises(InputError, match="axis2"):
        s.joint("y", "universal", "ground", "a", point=(0, 0, 0), axis=(0, 0, 1))
    with pytest.raises(InputError, match="axis2 applies"):
        s.joint("z", "revolute", "ground", "a", point=(0, 0, 0), axis=(0, 0, 1),
                axis2=(1, 0, 0))


# --------------------------------------------- the joint equations at large rotations
SECTION = Rectangle(0.05, 0.1)
AXIS, AXIS2 = np.array([0.6, 0.8, 0.0]), np.array([0.0, 0.0, 1.0])
#: body pairs (body1, body2, point): beams 'a' along x (nodes at 0, 0.5, 1) and 'b' along
#: y from (0.6, 0, 0); rigid bodies 'r', 'r2'; points between nodes and off a beam's axis
PAIRS = {
    "rigid-rigid": ("r", "r2", (2.5, 0.5, 0.3)),
    "ground-rigid": ("ground", "r", (2.1, 0.4, 0.3)),
    "beam-rigid (between nodes)": ("a", "r", (0.37, 0.0, 0.0)),
    "rigid-beam (off the axis)": ("r", "a", (0.37, 0.02, 0.01)),
    "ground-beam (between nodes)": ("ground", "a", (0.37, 0.0, 0.0)),
    "beam-beam": ("a", "b", (0.6, 0.0, 0.0)),
}
TYPES = {
    "prismatic": dict(axis=AXIS),
    "prismatic driven": dict(axis=AXIS, drive="stroke"),
    "cylindrical": dict(axis=AXIS),
    "universal": dict(axis=AXIS2, axis2=np.array([0.8, -0.6, 0.0])),
}


def _pair_system(kind: str, pair: str, formulation: str = "nonlinear") -> System:
    body1, body2, point = PAIRS[pair]
    s = System(f"{kind} {pair}")
    s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.drive("stroke", "spinup", omega=2.0, period=0.5, start=0.1)
    s.beam("a", material="steel", start=(0, 0, 0), end=(1, 0, 0), nodes=3, section=SECTION,
           height_axis=(0, 1, 0), formulation=formulation, bending="cubic")
    s.beam("b", material="steel", start=(0.6, 0, 0), end=(0.6, 1, 0), nodes=3,
           section=SECTION, height_axis=(-1, 0, 0), formulation=formulation, bending="cubic")
    s.rigid_body("r", mass=2.0, inertia=(0.2, 0.25, 0.3, 0.01, 0.0, 0.02),
                 position=(2, 0.5, 0.3))
    s.rigid_body("r2", mass=1.0, inertia=(0.1, 0.1, 0.1, 0, 0, 0), position=(3, 0.5, 0.3))
    s.joint("j", kind.split()[0], body1, body2, point=point, **TYPES[kind])
    return s


def _moved(model, motions: dict[str, tuple[np.ndarray, np.ndarray]], q: np.ndarray
           ) -> np.ndarray:
    """q with each named body's nodal vectors moved rigidly: positions x -> R x + c,
    directions d -> R d (motions: name -> (R, c))."""
    q = q.copy()
    for body in model.bodies:
        if body.name not in motions or body.ncoordinates == 0:
            continue
        rotation, shift = motions[body.name]
        block = q[body.first:body.first + body.ncoordinates].reshape(-1, 4, 3)
        block[:] = block @ rotation.T
        block[:, 0, :] += shift
        q[body.first:body.first + body.ncoordinates] = block.ravel()
    return q


def _rotation(axis, angle: float) -> np.ndarray:
    from ancfdrv.system.bodies import rotation_about
    return rotation_about(np.asarray(axis, dtype=float), angle)


def _about(rotation: np.ndarray, point: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(R, c) of the rotation R about a point: x -> R (x - point) + point."""
    return rotation, point - rotation @ point


def _compose(outer, inner):
    """(R, c) of x -> outer(inner(x))."""
    return outer[0] @ inner[0], outer[0] @ inner[1] + outer[1]


@pytest.mark.parametrize("pair", sorted(PAIRS))
@pytest.mark.parametrize("kind", sorted(TYPES))
def test_joint_equations_jacobian_and_hessian_at_large_rotations(kind, pair):
    """Each new joint between each pair of bodies, kept with multipliers:

    * its equations vanish at t = 0, after a common rigid motion of both bodies by a large
      rotation (2.2 rad about an oblique axis: 1e-12; none when body1 is the ground), and
      after the relative motion the joint allows (prismatic: a slide along the carried axis; cylindrical: a slide and a
      1.3 rad turn about it; universal: turns about both cross axes) on top of it, while a
      motion it forbids violates them;
    * at a state of large rotations (each body 1.0-2.5 rad about its own axis, plus noise
      0.02) the Jacobian equals central differences of the values and each Hessian (the
      matrices the static Newton iteration and the tangent use: hessian_triplets) central
      differences of the Jacobian rows (step 1e-6; the equations are quadratic, so the
      differences are exact to rounding: 1e-7 relative); for the driven prismatic Phi_t and
      Phi_tt equal differences in time."""
    s = _pair_system(kind, pair)
    model = s.assemble(linear_joints="multipliers")
    try:
        cs = model.constraints
        rows = [i for i, n in enumerate(cs.names) if n.startswith("j")]
        assert rows

        def values(e, t=0.0):
            return cs.evaluate(e, t)[0][rows]
        assert np.abs(values(model.e0)).max() <= 1e-12
        body1, body2, point = PAIRS[pair]
        point = np.asarray(point, dtype=float)
        common = _about(_rotation((1.0, -2.0, 0.5), 2.2), point)
        common = (common[0], common[1] + np.array([0.3, -0.2, 0.5]))
        if body1 == "ground":   # the ground does not move: the relative motions from rest
            common = (np.eye(3), np.zeros(3))
        both = {body1: common, body2: common}
        q_common = _moved(model, both, model.q0)
        assert np.abs(values(q_common)).max() <= 1e-12
        turn, moved_point = common[0], common[0] @ point + common[1]
        if kind.startswith("prismatic"):
            allowed = (np.eye(3), 0.35 * turn @ AXIS)
        elif kind == "cylindrical":
            allowed = _about(_rotation(turn @ AXIS, 1.3), moved_point)
            allowed = (allowed[0], allowed[1] + 0.35 * turn @ AXIS)
        else:
            allowed = _compose(_about(_rotation(turn @ AXIS2, 0.9), moved_point),
                               _about(_rotation(turn @ TYPES[kind]["axis2"], 1.1),
                                      moved_point))
        if body2 != "ground":
            q_allowed = _moved(model, {body1: common, body2: _compose(allowed, common)},
                               model.q0)
            forbidden = _about(_rotation(turn @ np.cross(AXIS, AXIS2) if kind != "universal"
                                         else turn @ np.cross(AXIS2, TYPES[kind]["axis2"]),
                                         0.5), moved_point)
            q_forbidden = _moved(model, {body1: common, body2: _compose(forbidden, common)},
                                 model.q0)
            if kind == "prismatic driven":   # the slide is the drive's: not free at t = 0
                assert abs(values(q_allowed)).max() > 1e-3
            else:
                assert np.abs(values(q_allowed)).max() <= 1e-12
            assert np.abs(values(q_forbidden)).max() > 1e-3
        rng = np.random.default_rng(7)
        motions = {}
        for k, name in enumerate((body1, body2)):
            centre = point + rng.standard_normal(3) * 0.2
            motions[name] = _about(_rotation(rng.standard_normal(3), 1.0 + 1.5 * k), centre)
        e = _moved(model, motions, model.q0) + 0.02 * rng.standard_normal(model.ndof)
        t, h = 0.37, 1e-6
        jac = cs.gradient_rows(e, model.ndof, t)[rows]
        fd = np.zeros_like(jac)
        hess = np.zeros((len(cs), model.ndof, model.ndof))
        con, r_, c_, v_ = cs.hessian_triplets(e)
        np.add.at(hess, (con, r_, c_), v_)
        hess_fd = np.zeros_like(hess)
        for k in range(model.ndof):
            step = np.zeros(model.ndof)
            step[k] = h
            fd[:, k] = (values(e + step, t) - values(e - step, t)) / (2 * h)
            hess_fd[:, :, k] = (cs.gradient_rows(e + step, model.ndof, t)
                                - cs.gradient_rows(e - step, model.ndof, t)) / (2 * h)
        scale = max(np.abs(jac).max(), 1.0)
        assert np.abs(jac - fd).max() <= 1e-7 * scale
        assert np.abs(hess[rows] - hess_fd[rows]).max() <= 1e-7 * max(np.abs(hess).max(), 1.0)
        if body1 != "ground":   # quadratic equations (with the ground they are linear)
            assert np.abs(hess[rows]).max() > 0.5
        if "driven" in kind:
            _, _, _, phi_t, phi_tt, _ = cs.evaluate(e, t)
            dt = 1e-4
            np.testing.assert_allclose(phi_t[rows], (values(e, t + dt) - values(e, t - dt))
                                       / (2 * dt), rtol=0, atol=1e-7)
            np.testing.assert_allclose(phi_tt[rows], (values(e, t + dt) - 2 * values(e, t)
                                                      + values(e, t - dt)) / dt**2,
                                       rtol=0, atol=1e-4)
            assert np.abs(phi_t[rows]).max() > 0.1
    finally:
        model.close()


# ------------------------------------------------ a beam on a guide between its nodes
BEAM_L, BEAM_RHO, BEAM_W, BEAM_H = 2.0, 7850.0, 0.04, 0.06


def _guided_beam(formulation: str, axis, point, bodies=("ground", "rod"), drive=None
                 ) -> System:
    """A 2 m steel beam (40 x 60 mm, 4 nodes: at 0, 2/3, 4/3, 2 m) from the origin along
    ``axis`` on a prismatic guide at ``point`` (between nodes), gravity -z."""
    axis = np.asarray(axis, dtype=float)
    height = np.cross(axis, (0.0, 1.0, 0.0))
    s = System("beam on a guide")
    s.material("steel", youngs_modulus=2.1e11, density=BEAM_RHO)
    s.drive("hold", "constant", value=0.0)
    s.beam("rod", material="steel", start=(0, 0, 0), end=BEAM_L * axis, nodes=4,
           section=Rectangle(BEAM_W, BEAM_H), height_axis=height, formulation=formulation)
    s.joint("guide", "prismatic", *bodies, point=point, axis=axis, drive=drive)
    s.load("g", "gravity", vector=(0, 0, -G))
    s.probe("p", "rod", point)
    return s


@pytest.mark.parametrize("formulation", ["ffr", "nonlinear"])
def test_beam_held_by_a_locked_guide_between_nodes_carries_its_weight(formulation):
    """Statics: the horizontal beam on a guide along x at x = 0.5 m, 1 cm above its axis
    (between nodes, off the axis), the slide locked by a constant drive; named (rod, ground)
    the reaction is what the beam exerts on the ground: its weight m g down and, about the
    guide's point, the weight's moment (c - p) x W with c the centre of mass (global
    equilibrium): FFR 1e-9 relative, 'nonlinear' 1e-6 (the deflected beam's lever arm:
    5e-8 measured)."""
    point = np.array([0.5, 0.0, 0.01])
    s = _guided_beam(formulation, (1, 0, 0), point, bodies=("rod", "ground"), drive="hold")
    res = s.static()
    assert res.status == "ok"
    weight = np.array([0.0, 0.0, -BEAM_RHO * BEAM_W * BEAM_H * BEAM_L * G])
    moment = np.cross(np.array([BEAM_L / 2, 0, 0]) - point, weight)
    tol = (1e-9 if formulation == "ffr" else 1e-6) * np.linalg.norm(weight)
    np.testing.assert_allclose(res.reactions["guide"]["force"], weight, rtol=0, atol=tol)
    np.testing.assert_allclose(res.reactions["guide"]["moment"], moment, rtol=0, atol=tol)


@pytest.mark.parametrize("formulation", ["ffr", "nonlinear"])
def test_beam_slides_on_a_guide_between_its_nodes(formulation):
    """Dynamics: the beam along a 30 degree incline on a frictionless guide at 0.5 m
    (between nodes): the guide's point stays on its line (1e-12 m) and slides by
    g sin(theta) t^2 / 2 (Newton's law for the centre of mass: the guide takes no force
    along it), FFR to 1e-12 m; the 'nonlinear' beam's bending vibration shortens it
    axially by second-order amounts: 1.0e-7 m measured over 0.22 m, 1e-6 relative allowed."""
    theta = np.radians(30.0)
    axis = np.array([np.cos(theta), 0.0, -np.sin(theta)])
    s = _guided_beam(formulation, axis, 0.5 * axis)
    res = s.simulate(t_end=0.3, dt=0.001)
    assert res.status == "ok"
    t, p = res.time, res.probes["p"]
    slide = (p - p[0]) @ axis
    expected = G * np.sin(theta) * t**2 / 2
    np.testing.assert_allclose(p - p[0] - np.outer(slide, axis), 0.0, rtol=0, atol=1e-12)
    tol = 1e-12 if formulation == "ffr" else 1e-6 * expected[-1]
    np.testing.assert_allclose(slide, expected, rtol=0, atol=tol)


# ----------------------------------------------------- the shipped double Cardan shaft
def test_double_cardan_scene_is_homokinetic_and_its_tube_fluctuates(tmp_path):
    """inputs/general/cardan_shaft.nml (namelist keys axis / axis2 as in Python), run for
    0.5 s (0.75 turn): with the tube's yokes in phase the output turns with the input
    (rigid shafts: exactly; here within 1e-3 rad, the flexible tube's twist under the
    flywheel's start-up torque, T L / (G J) = 1e-4 rad, and its vibration: 2.4e-4 measured),
    and the tube's angle obeys the single joint's closed form tan(theta_tube) =
    cos(beta) tan(theta_in) (5e-4 rad; 1.1e-4 measured) and its speed ratio cos(beta) /
    (1 - sin^2(beta) sin^2(theta_in)) after the ramp (1e-4, from central differences of the
    probe angles: (w dt)^2 / 6 = 3e-5; 1.0e-5 measured)."""
    from ancfdrv import open as open_results
    from ancfdrv.runner import run_scene
    from conftest import INPUTS
    out = tmp_path / "cardan.h5"
    run_scene(INPUTS / "general" / "cardan_shaft.nml", ["solver.t_end=0.5"], out,
              progress=False)
    res = open_results(out)
    assert res.status == "ok"
    beta = np.radians(20.0)
    tube_axis, x, z = np.array([np.cos(beta), np.sin(beta), 0.0]), np.eye(3)[0], np.eye(3)[2]

    def angle(v, axis):   # the turn about axis of a vector that was along +z
        return np.unwrap(np.arctan2(v @ np.cross(axis, z), v @ z))
    p = res.probes
    t = res.time
    theta_in = angle(p["input yoke"] - p["input yoke"][0] + (0, 0, 0.1), x)
    theta_out = angle(p["output yoke"] - p["output yoke"][0] + (0, 0, 0.1), x)
    theta_tube = angle(p["tube yoke"] - p["tube mid"], tube_axis)
    assert theta_in[-1] > 0.7 * 2 * np.pi
    assert np.abs(theta_out - theta_in).max() < 1e-3
    closed = np.unwrap(np.arctan2(np.cos(beta) * np.sin(theta_in), np.cos(theta_in)))
    assert np.abs(theta_tube - closed).max() < 5e-4
    steady = t > 0.3
    ratio = np.gradient(theta_tube, t)[steady] / np.gradient(theta_in, t)[steady]
    expected = np.cos(beta) / (1 - np.sin(beta)**2 * np.sin(theta_in[steady])**2)
    assert np.abs(ratio - expected).max() < 1e-4
    assert expected.max() - expected.min() > 0.1   # the fluctuation is there to be seen


@pytest.mark.parametrize("formulation", ["ffr", "nonlinear"])
@pytest.mark.parametrize("order", [("beam", "tip"), ("tip", "beam")], ids=["beam-body",
                                                                          "body-beam"])
def test_locked_prismatic_is_a_weld(formulation, order):
    """A prismatic joint whose slide a constant drive holds is a weld: a rigid body on the
    tip of a 2 m cantilever (FFR, whose section turn carries the body's axes linearly, or
    nonlinear), a force and a moment on the body: the body's displacement is the welded
    model's to 1e-10 (measured 2e-12), whichever body is named first; with FFR the note
    names the prismatic joint that linearizes the body's axes."""
    tips = []
    for kind in ("weld", "prismatic"):
        s = System(kind)
        s.material("steel", youngs_modulus=2.1e11, density=7850.0)
        s.drive("hold", "constant", value=0.0)
        s.beam("beam", material="steel", start=(0, 0, 0), end=(2, 0, 0), nodes=3,
               section=Rectangle(0.05, 0.1), height_axis=(0, 1, 0), formulation=formulation)
        s.rigid_body("tip", mass=10.0, inertia=(0.1, 0.2, 0.3, 0, 0, 0),
                     position=(2.2, 0, 0.1))
        s.joint("clamp", "weld", "ground", "beam", point=(0, 0, 0))
        extra = dict(axis=(0.6, 0.8, 0), drive="hold") if kind == "prismatic" else {}
        s.joint("j", kind, *order, point=(2.0, 0, 0), **extra)
        s.load("F", "force", body="tip", point=(2.4, 0.05, 0.1), vector=(300.0, -500.0, 200.0))
        s.load("M", "moment", body="tip", point=(2.4, 0.05, 0.1), vector=(50.0, 20.0, -30.0))
        s.probe("p", "tip", (2.4, 0.05, 0.1))
        model = s.assemble()
        try:
            e = solve_newton(model, tol=1e-12).e
            tips.append(model.probe_positions(e)["p"] - model.probe_positions(model.e0)["p"])
            if formulation == "ffr":
                assert any(f"({kind} 'j'), linearized" in n for n in model.notes), model.notes
        finally:
            model.close()
    assert np.abs(tips[0]).max() > 1e-3
    np.testing.assert_allclose(tips[1], tips[0], rtol=0, atol=1e-10 * np.abs(tips[0]).max())
