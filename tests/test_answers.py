"""Engineering answers (SPEC section 10, issue 21 items 1-3): joint reactions by name, section
forces along beams and stresses at the outer fibres, against independent references:

* equilibrium of every body (the reactions and the loads on it add up to zero: forces and
  moments), in both ways the assembly keeps joints (multipliers; linear joints eliminated);
* the knuckle crane's cylinder force against its multiplier (F = -2 lambda L, the
  example's hand formula) and against the moment balance of the rigid jib;
* the support forces of a stiff boom on a hinge and a cylinder against rigid-body statics;
* dynamic reactions against m a of a rigid body (a driven slider, a swinging pendulum);
* section forces of a cantilever and an L-frame against statics (the resultant of the loads
  beyond the section), for both bending options and both formulations; the continuum
  option's root moment converging linearly with the element length;
* a spinning beam's axial force against the centrifugal closed form rho A w^2 (L^2 - s^2)/2;
* stresses at the root of a cantilever: N / A + M c / I for every section kind; Bredt's
  T / (2 A_m t) in a twisted box.
"""
from __future__ import annotations

import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv import Box, Circle, Rectangle, System, Tube
from ancfdrv.solvers.dynamic import DynamicSettings, integrate
from ancfdrv.solvers.static import solve_newton
from ancfdrv.system.answers import (DynamicAnswers, beam_stress, reactions, section_forces,
                                    stresses)

ROOT = Path(__file__).resolve().parents[1]
G = 9.81
STEEL = dict(youngs_modulus=2.1e11, density=7850.0)


def _solve(system: System):
    model = system.assemble()
    result = solve_newton(model, tol=1e-11)
    return model, result


def _resultant_beyond(loads: list[tuple[np.ndarray, np.ndarray]], point: np.ndarray,
                      beyond) -> tuple[np.ndarray, np.ndarray]:
    """Force and moment about ``point`` of the point loads (position, force) for which
    beyond(position) holds: what the part beyond a section exerts on the part before it."""
    force, moment = np.zeros(3), np.zeros(3)
    for where, f in loads:
        if beyond(where):
            force += f
            moment += np.cross(where - point, f)
    return force, moment


# -- reactions -------------------------------------------------------------------------------
def _knuckle():
    sys.path.insert(0, str(ROOT / "examples"))
    try:
        import knuckle_boom
    finally:
        sys.path.pop(0)
    return knuckle_boom


def test_knuckle_crane_reactions_balance_every_body_and_the_cylinder_force():
    """The knuckle crane (examples/knuckle_boom.py, joints kept with multipliers): the jib's
    reactions (knuckle, cylinder) balance its weight and the payload's, forces and moments
    about the knuckle (loads at the deformed positions); the boom's (pivot, and minus the
    jib's) balance its weight; the cylinder's axial force is the example's -2 lambda L, and
    within 0.5 % of the moment balance of the rigid jib (the elastic deflection moves the
    lines of action by about 0.1 %)."""
    kb = _knuckle()
    p = kb.KnuckleBoom()
    stroke = 1.8
    model = kb.build(p, stroke, kb.Mesh()).assemble()
    try:
        result = solve_newton(model, tol=1e-11)
        found = reactions(model, result.e, result.lam)
        lam = result.lam[model.constraints.names.index("cylinder: length")]
        assert found["cylinder"].axial == pytest.approx(kb.cylinder_force(lam, stroke), rel=1e-9)
        assert found["cylinder"].axial == pytest.approx(p.rigid_cylinder_force(stroke),
                                                        rel=5e-3)
        assert found["cylinder"].axial < 0  # the cylinder pushes (compression)
        q = model.expand(result.e)
        boom_mass, jib_mass = p.masses()
        # the jib: its weight acts on its nodes; the deformed centroid from the nodes' mean
        jib = next(b for b in model.bodies if b.name == "jib")
        nodes = q[jib.first:jib.first + jib.ncoordinates].reshape(jib.nodes, 12)[:, :3]
        centroid = np.trapezoid(nodes, jib.stations, axis=0) / jib.length
        tip = model.probe_positions(result.e)["tip"]
        weight_jib, weight_payload = np.array([0, -G * jib_mass, 0]), np.array([0, -G * p.payload, 0])
        knuckle, cylinder = found["knuckle"], found["cylinder"]
        total = knuckle.force + cylinder.force + weight_jib + weight_payload
        assert np.abs(total).max() <= 1e-8 * np.abs(cylinder.force).max()
        about = knuckle.point
        moment = (knuckle.moment + cylinder.moment + np.cross(cylinder.point - about, cylinder.force)
                  + np.cross(centroid - about, weight_jib) + np.cross(tip - about, weight_payload))
        # the centroid of the cubic centre line from the nodes (trapezoid): 1e-5 of the arm
        assert abs(moment[2]) <= 1e-4 * abs(np.cross(tip - about, weight_payload)[2])
        # the boom: the pivot's reaction and minus the jib's joints' balance the boom's weight
        total_boom = found["pivot"].force - knuckle.force - cylinder.force + \
            np.array([0, -G * boom_mass, 0])
        assert np.abs(total_boom).max() <= 1e-8 * np.abs(cylinder.force).max()
    finally:
        model.close()


def test_eliminated_welds_carry_the_rigid_block_and_the_beam():
    """A cantilever (linear joints eliminated because of the rigid body) carrying a rigid
    block of 10 kg whose centre lies 0.5 m beyond the beam's tip: the tip weld's force on
    the block is its weight's reaction, its moment about the tip the weight's lever arm at
    the deformed position; the root carries everything: the weight of block and beam and
    the moment about the root."""
    s = System("block")
    steel = s.material("steel", **STEEL)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(2, 0, 0), nodes=5,
           section=Rectangle(0.05, 0.1), height_axis=(0, 1, 0), formulation="nonlinear",
           bending="cubic")
    s.rigid_body("block", mass=10.0, inertia=(1, 1, 1, 0, 0, 0), position=(2.5, 0, 0))
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.joint("tip", "weld", "arm", "block", point=(2, 0, 0))
    s.load("g", "gravity", vector=(0, -G, 0))
    model, result = _solve(s)
    assert model.reduction is not None   # the welds are eliminated, not multipliers
    found = reactions(model, result.e, result.lam)
    q = model.expand(result.e)
    block = next(b for b in model.bodies if b.name == "block")
    centre = q[block.first:block.first + 3]
    weight = np.array([0.0, -10.0 * G, 0.0])
    tip = found["tip"]
    assert tip.force == pytest.approx(-weight, abs=1e-6)   # 98.1 N
    assert tip.moment == pytest.approx(-np.cross(centre - tip.point, weight), abs=1e-6)
    beam_weight = np.array([0.0, -7850 * 0.05 * 0.1 * 2.0 * G, 0.0])
    root = found["root"]
    # to the static solver's tolerance (a relative force residual of 1e-11)
    assert root.force == pytest.approx(-(weight + beam_weight), rel=1e-9, abs=1e-8 * 868.0)
    # beam weight at its (nearly undeformed) centre, block at its deformed centre
    assert root.moment[2] == pytest.approx(-(centre[0] * weight[1] + 1.0 * beam_weight[1]),
                                           rel=1e-5)
    model.close()


def test_support_forces_of_a_stiff_boom_match_rigid_statics():
    """A boom (4 m, hinged at the ground at O, lifted by a cylinder from a ground point C to
    a lug at 1.5 m) with a 200 kg payload at its tip, at 30 degrees; a stiff material (E =
    2.1e14 Pa) makes it rigid to 1e-6. Rigid statics: moments about O give the cylinder
    force, the force balance the hinge force."""
    angle = np.radians(30.0)
    e1 = np.array([np.cos(angle), np.sin(angle), 0.0])
    length, lug, payload = 4.0, 1.5, 200.0
    section = Box(0.2, 0.3, 0.01)
    base = np.array([0.8, -0.6, 0.0])
    s = System("boom")
    stiff = s.material("stiff", youngs_modulus=2.1e14, density=7850.0)
    s.beam("boom", material=stiff, start=(0, 0, 0), end=length * e1, nodes=9,
           segments=(lug, length - lug), section=section,
           height_axis=(-e1[1], e1[0], 0.0), formulation="nonlinear", bending="cubic")
    s.joint("hinge", "revolute", "ground", "boom", point=(0, 0, 0), axis=(0, 0, 1))
    s.joint("cylinder", "distance", "ground", "boom", point1=base, point2=lug * e1)
    s.load("g", "gravity", vector=(0, -G, 0))
    s.load("payload", "point_mass", body="boom", point=length * e1, mass=payload)
    model, result = _solve(s)
    found = reactions(model, result.e, result.lam)
    mass = 7850.0 * section.data.area * length
    weight_moment = -G * (mass * length / 2 + payload * length) * e1[0]
    u = (lug * e1 - base) / np.linalg.norm(lug * e1 - base)
    # the cylinder pushes the lug along u with -axial (tension positive): moment about O
    arm = np.cross(lug * e1, u)[2]
    axial = weight_moment / arm
    assert found["cylinder"].axial == pytest.approx(axial, rel=1e-5)
    hinge = -(-axial * u) - np.array([0.0, -G * (mass + payload), 0.0])
    assert found["hinge"].force == pytest.approx(hinge, rel=1e-5, abs=1e-6 * abs(axial))
    assert abs(found["hinge"].moment[2]) <= 1e-6 * abs(weight_moment)  # a hinge: no moment
    model.close()


def _dynamic(model, t_end: float, dt: float):
    """Run (generalized-alpha, rho_inf = 0.8: the trapezoidal rule's multipliers of
    driven constraints alternate from step to step) and record the answers of every
    step."""
    settings = DynamicSettings.generalized_alpha(dt, t_end, 0.8, store_q=True, answers=True)
    recorder = DynamicAnswers(model)
    positions = []

    def sink(chunk):
        recorder(chunk)
        positions.extend(chunk.probes[:, 0, :])
    integrate(model, settings, model.e0, sink=sink, progress=False)
    return recorder, np.array(positions)


def test_dynamic_reaction_of_a_driven_slider_is_m_a():
    """A rigid body of 3 kg whose centre is driven along x by x(t) = 0.1 cos(2 pi t) (a
    'prescribed' translation, kept with multipliers; it starts at rest, as the run), under
    gravity: the joint's force on it is m a - m g = (-m 0.1 (2 pi)^2 cos(2 pi t), m g, 0)
    at every step."""
    s = System("slider")
    s.rigid_body("slider", mass=3.0, inertia=(0.1, 0.1, 0.1, 0, 0, 0), position=(0, 0, 0))
    s.drive("stroke", "sine", amplitude=0.1, frequency=1.0, phase=np.pi / 2)
    s.joint("guide", "prescribed", "ground", "slider", point=(0, 0, 0), axis=(1, 0, 0),
            drive="stroke")
    s.load("g", "gravity", vector=(0, -G, 0))
    s.probe("centre", "slider", (0, 0, 0))
    model = s.assemble(linear_joints="multipliers")
    recorder, _ = _dynamic(model, 0.5, 2e-3)
    t = np.array(recorder.time)
    force = np.concatenate([c[0] for c in recorder.reactions["guide"]])
    expected = np.column_stack([-3.0 * 0.1 * (2 * np.pi) ** 2 * np.cos(2 * np.pi * t),
                                np.full_like(t, 3.0 * G), np.zeros_like(t)])
    # the trapezoidal rule's constraint accelerations: O(dt^2) of 12 N
    assert np.abs(force - expected).max() <= 2e-3 * 3.0 * 0.1 * (2 * np.pi) ** 2
    model.close()


def test_dynamic_hinge_force_of_a_pendulum_is_m_a_of_its_centre():
    """A rigid pendulum (2 kg, centre 0.5 m from a revolute hinge, released horizontal;
    the hinge is eliminated, its reaction comes from the residual the kernel writes with
    each row from the stepper's accelerations): the hinge force equals m a_c - m g with a_c from the centre's
    recorded path (central differences, O(dt^2))."""
    s = System("pendulum")
    s.rigid_body("bob", mass=2.0, inertia=(0.01, 0.01, 0.02, 0, 0, 0), position=(0.5, 0, 0),
                 planar=True, plane_normal=(0, 0, 1))
    s.joint("hinge", "revolute", "ground", "bob", point=(0, 0, 0), axis=(0, 0, 1))
    s.load("g", "gravity", vector=(0, -G, 0))
    s.probe("centre", "bob", (0.5, 0, 0))
    model = s.assemble()
    assert model.reduction is not None
    dt = 1e-3
    recorder, path = _dynamic(model, 0.6, dt)
    force = np.concatenate([c[0] for c in recorder.reactions["hinge"]])
    accel = (path[2:] - 2 * path[1:-1] + path[:-2]) / dt**2
    expected = 2.0 * accel - 2.0 * np.array([0.0, -G, 0.0])
    scale = 2.0 * G * 3   # the hinge force reaches 3 m g at the bottom
    assert np.abs(force[1:-1] - expected).max() <= 2e-3 * scale
    assert np.abs(force[1:-1]).max() > 2.0 * 2.0 * G   # the swing was reached
    model.close()


# -- section forces ----------------------------------------------------------------------------
@pytest.mark.parametrize("formulation", ["ffr", "nonlinear"])
@pytest.mark.parametrize("bending", ["cubic", "continuum"])
def test_cantilever_section_forces_match_statics(formulation, bending):
    """A cantilever along x (2 m, 4 elements) with a tip force (30, 400, -250) N and a tip
    torque 50 N m: N, Q, T and M at the nodes equal the resultant of the loads beyond the
    section, resolved on the section's axes (large deformation: the deformed node
    positions and directors; FFR: the undeformed ones, its small-strain statics), to 1e-3
    of the largest value. 'cubic' reproduces the moment line inside the elements too; the
    continuum option's bending strain is constant per element: its moment at the element's
    middle is the mean of the nodes' values (the moment line is linear)."""
    L = 2.0
    force, torque = np.array([30.0, 400.0, -250.0]), np.array([50.0, 0.0, 0.0])
    s = System("cantilever")
    steel = s.material("steel", **STEEL)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(L, 0, 0), nodes=5,
           section=Rectangle(0.06, 0.1), height_axis=(0, 1, 0), formulation=formulation,
           bending=bending)
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("tip", "force", body="arm", point=(L, 0, 0), vector=force)
    s.load("twist", "moment", body="arm", point=(L, 0, 0), vector=torque)
    model, result = _solve(s)
    f = section_forces(model, result.e, stations=3)["arm"]
    beam = model.bodies[0]
    q = model.expand(result.e) if formulation == "nonlinear" else model.q0
    nodal = q[beam.first:beam.first + beam.ncoordinates].reshape(beam.nodes, 4, 3)
    tip = nodal[-1, 0]
    big = np.abs(force).max() * L
    # large deformation: the strain measures couple the axial force with the bending
    # moments at second order (M kappa, here ~1e-3 of the shear force; the 'cubic' option's
    # r_xx . r_y term adds its own): N to 1 % of the resultant (the axial stress N / A is
    # then 2e-4 of the bending stress here); FFR's linear strains: 1e-3 (exact)
    axial_tol = (1e-3 if formulation == "ffr" else 1e-2) * np.linalg.norm(force)
    expected = []
    for node in range(beam.nodes):
        e_y = nodal[node, 2] / np.linalg.norm(nodal[node, 2])
        e_z = nodal[node, 3] / np.linalg.norm(nodal[node, 3])
        n = np.cross(e_y, e_z)
        moment = np.cross(tip - nodal[node, 0], force) + torque
        expected.append((force @ n, [force @ e_y, force @ e_z], moment @ n,
                         [moment @ e_y, moment @ e_z]))
    for k in range(len(f.s)):
        element, local = divmod(k, 3)
        if local == 1:   # the element's middle
            if bending == "continuum":
                mean = np.mean([expected[element][3], expected[element + 1][3]], axis=0)
                assert f.M[k] == pytest.approx(mean, abs=1e-3 * big)
            continue
        n_k, q_k, t_k, m_k = expected[element + local // 2]
        assert f.N[k] == pytest.approx(n_k, abs=axial_tol)
        assert f.Q[k] == pytest.approx(q_k, abs=1e-3 * np.abs(force).max())
        assert f.T[k] == pytest.approx(t_k, abs=1e-3 * big)
        if bending == "cubic":
            assert f.M[k] == pytest.approx(m_k, abs=1e-3 * big)
    # the reaction at the root is minus the loads (moment about the root); large
    # deformation: the 'moment' load acts on the section's directors, whose turn (1e-3)
    # turns its vector by as much (5e-2 N m of the 50 N m)
    root = reactions(model, result.e, result.lam)["root"]
    assert root.force == pytest.approx(-force, abs=1e-6 * big)
    assert root.moment == pytest.approx(-(np.cross(tip, force) + torque),
                                        abs=(1e-6 if formulation == "ffr" else 1e-4) * big)
    model.close()


def test_continuum_root_moment_converges_linearly_with_the_mesh():
    """The continuum option's moment is constant per element: at the root it is the
    element's middle value P (L - h/2), so its error P h / 2 halves as the elements do."""
    errors = []
    for nodes in (3, 5, 9):
        s = System("c")
        steel = s.material("steel", **STEEL)
        s.beam("arm", material=steel, start=(0, 0, 0), end=(2, 0, 0), nodes=nodes,
               section=Rectangle(0.06, 0.1), height_axis=(0, 1, 0), formulation="nonlinear",
               bending="continuum")
        s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
        s.load("tip", "force", body="arm", point=(2, 0, 0), vector=(0, 100.0, 0))
        model, result = _solve(s)
        m_root = section_forces(model, result.e)["arm"].M[0, 1]
        errors.append(200.0 - m_root)
        assert errors[-1] == pytest.approx(100.0 * (2.0 / (nodes - 1)) / 2, rel=1e-3)
        model.close()
    assert errors[0] / errors[1] == pytest.approx(2.0, rel=1e-3)
    assert errors[1] / errors[2] == pytest.approx(2.0, rel=1e-3)


def test_l_frame_section_forces_match_statics():
    """An L-frame in the x-y plane: a column from the ground up to (0, 2, 0), welded to a
    beam along x to (1.5, 2, 0) with a tip load (0, -300, 80) N. In both members N, Q, T
    and M equal the resultant of the load about each section (column: compression 300 N,
    bending 450 N m and torsion 120 N m from the out-of-plane component)."""
    load_at, load = np.array([1.5, 2.0, 0.0]), np.array([0.0, -300.0, 80.0])
    s = System("frame")
    steel = s.material("steel", **STEEL)
    s.beam("column", material=steel, start=(0, 0, 0), end=(0, 2, 0), nodes=5,
           section=Box(0.1, 0.1, 0.005), height_axis=(1, 0, 0), formulation="nonlinear",
           bending="cubic")
    s.beam("beam", material=steel, start=(0, 2, 0), end=load_at, nodes=4,
           section=Box(0.1, 0.1, 0.005), height_axis=(0, 1, 0), formulation="nonlinear",
           bending="cubic")
    s.joint("base", "weld", "ground", "column", point=(0, 0, 0))
    s.joint("corner", "weld", "column", "beam", point=(0, 2, 0))
    s.load("tip", "force", body="beam", point=load_at, vector=load)
    model, result = _solve(s)
    forces = section_forces(model, result.e)
    big = np.abs(load).max() * 2.0
    for body in model.bodies:
        f = forces[body.name]
        axes = body.orientation   # columns: axis, height, width (small deflection)
        for k, s_k in enumerate(f.s):
            point = body.start + s_k * axes[:, 0]
            moment = np.cross(load_at - point, load)
            assert f.N[k] == pytest.approx(load @ axes[:, 0], abs=2e-3 * big)
            assert f.Q[k] == pytest.approx(load @ axes[:, 1:], abs=2e-3 * big)
            assert f.T[k] == pytest.approx(moment @ axes[:, 0], abs=2e-3 * big)
            assert f.M[k] == pytest.approx(moment @ axes[:, 1:], abs=2e-3 * big)
    assert forces["column"].N[0] == pytest.approx(-300.0, rel=2e-3)
    model.close()


def test_spinning_beam_axial_force_is_centrifugal():
    """A beam (FFR, its frame turned by the hub) spun up smoothly to w = 8 rad/s in 2 s and
    held: N(s) = rho A w^2 (L^2 - s^2) / 2 along the beam (the cubic displacement field is
    exact for it), within 1 % of the root value (the residual vibration)."""
    L, w = 2.0, 8.0
    s = System("spin")
    steel = s.material("steel", **STEEL)
    s.drive("hub", "spinup", omega=w, period=2.0)
    s.beam("beam", material=steel, start=(0, 0, 0), end=(L, 0, 0), nodes=5,
           section=Rectangle(0.05, 0.05), height_axis=(0, 1, 0), formulation="ffr",
           bending="cubic", frame_drive="hub", frame_axis=(0, 0, 1), frame_pivot=(0, 0, 0))
    s.joint("hub", "hub", "ground", "beam", point=(0, 0, 0), pivot=(0, 0, 0), axis=(0, 0, 1),
            drive="hub")
    s.probe("tip", "beam", (L, 0, 0))
    model = s.assemble()
    settings = DynamicSettings.generalized_alpha(5e-3, 2.5, 0.8, store_q=True)
    last = {}
    integrate(model, settings, model.e0, sink=lambda c: last.update(q=c.q[-1], t=c.time[-1]),
              progress=False)
    f = section_forces(model, last["q"], t=last["t"])["beam"]
    rho_a = 7850.0 * 0.05 * 0.05
    expected = rho_a * w**2 * (L**2 - f.s**2) / 2
    assert np.abs(f.N - expected).max() <= 1e-2 * expected[0]
    assert f.N[0] == pytest.approx(expected[0], rel=1e-2)
    model.close()


# -- stresses --------------------------------------------------------------------------------
@pytest.mark.parametrize("section, c_y", [
    (Rectangle(0.06, 0.1), 0.05), (Box(0.1, 0.16, 0.006), 0.08), (Tube(0.12, 0.008), 0.06),
    (Circle(0.08), 0.04)])
def test_root_stress_is_n_over_a_plus_m_c_over_i(section, c_y):
    """A cantilever (1.5 m, 'cubic') with a tip force of 2 kN along the axis and 3 kN along
    the height: at the root sigma_x = N / A + M c / I (c: the outer fibre) and the von
    Mises stress there is the same (no shear stress at that fibre), for every section
    kind."""
    L, axial, shear = 1.5, 2000.0, 3000.0
    s = System("c")
    steel = s.material("steel", **STEEL)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(L, 0, 0), nodes=4, section=section,
           height_axis=(0, 1, 0), formulation="ffr", bending="cubic")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("tip", "force", body="arm", point=(L, 0, 0), vector=(axial, shear, 0))
    model, result = _solve(s)
    forces = section_forces(model, result.e)
    stress = stresses(model, forces)["arm"]
    data = section.data
    expected = axial / data.area + shear * L * c_y / data.inertia_z
    assert stress.sigma_x[0] == pytest.approx(expected, rel=1e-6)
    if isinstance(section, Box):
        # thin walls: the corner carries the flange's shear flow Q / I_z (h_m / 2)(w_m / 2)
        # t (zero in the flange's middle by symmetry), tau = q / t
        h_m, w_m = section.height - section.wall, section.width - section.wall
        tau = shear / data.inertia_z * (h_m / 2) * (w_m / 2)
        expected = np.sqrt(expected**2 + 3 * tau**2)
    assert stress.von_mises[0] == pytest.approx(expected, rel=1e-6)
    assert stress.von_mises[0] == pytest.approx(stress.von_mises.max())
    model.close()


def test_twisted_box_bredt_shear():
    """A box girder (200 x 300 x 8 mm, 2 m) twisted by 5 kN m at its tip: T = 5 kN m all
    along, the Bredt shear T / (2 A_m t) with A_m the area inside the wall's midline, and
    von Mises sqrt(3) tau (no normal stress)."""
    section, torque = Box(0.2, 0.3, 0.008), 5000.0
    s = System("box")
    steel = s.material("steel", **STEEL)
    s.beam("girder", material=steel, start=(0, 0, 0), end=(2, 0, 0), nodes=3, section=section,
           height_axis=(0, 1, 0), formulation="nonlinear", bending="cubic")
    s.joint("root", "weld", "ground", "girder", point=(0, 0, 0))
    s.load("twist", "moment", body="girder", point=(2, 0, 0), vector=(torque, 0, 0))
    model, result = _solve(s)
    f = section_forces(model, result.e)["girder"]
    assert f.T == pytest.approx(torque, rel=1e-6)
    tau = torque / (2 * (0.3 - 0.008) * (0.2 - 0.008) * 0.008)
    stress = beam_stress(section, f)
    assert stress.von_mises == pytest.approx(np.sqrt(3.0) * tau, rel=1e-6)
    assert np.abs(stress.sigma_x).max() <= 1e-6 * tau
    model.close()


# -- the result file -------------------------------------------------------------------------
def test_run_writes_the_answers_by_name(tmp_path):
    """`ancf run` of the boom (static + a short luffing run) writes /static/reactions/<joint>
    (force, moment), /static/sections/boom, /static/stress/boom, the joint of each multiplier,
    and for the dynamic part reactions over time and the stress envelope. The static
    reactions balance the boom's weight and tip mass (vertical forces)."""
    from ancfdrv.runner import run_scene
    out = tmp_path / "boom.h5"
    run_scene(ROOT / "inputs" / "general" / "boom_luffing.nml",
              ["solver.t_end=0.05", "beam[boom].nodes=10", "output.sections=.true."], out,
              progress=False)
    with h5py.File(out) as h5:
        static = h5["static"]
        assert set(static["reactions"]) == {"pivot", "A1", "A2"}
        weight = 7850 * 0.01 * 7.791 * G + 50 * G
        # the arm (pivot) and A2 hold the boom: the arm's weld A1 passes the pivot's force on
        total = static["reactions/A1/force"][1] + static["reactions/A2/force"][1]
        assert total == pytest.approx(weight, rel=1e-6)
        assert static["sections/boom/M"].shape == (27, 2)
        assert static["stress/boom/von_mises"].attrs["units"] == "Pa"
        # A1 and the pivot are eliminated with the rigid arm (no multiplier rows); the
        # arm's own orthonormality rows belong to no joint
        joints = [n.decode() for n in h5["model/constraint_joints"][()]]
        assert set(joints) == {"A2", ""}
        dynamic = h5["dynamic"]
        nt = len(dynamic["time"])
        assert dynamic["reactions/A2/force"].shape == (nt, 3)
        assert dynamic["sections/boom/N"].shape == (nt, 27)
        env = dynamic["stress/boom"]
        assert env["von_mises_max"].shape == (27,)
        assert env.attrs["max"] == pytest.approx(env["von_mises_max"][()].max())
        peak = float(env["von_mises_max"][()].max())
        # the envelope at the beam's nodes, the field ParaView colours the beam by
        points = h5["dynamic/mesh_von_mises_max"][()]
        assert points.max() == pytest.approx(env.attrs["max"])
    assert "von_mises_max" in out.with_suffix(".xdmf").read_text()
    from ancfdrv.results.headline import read_answers
    from ancfdrv.plots import plot_sections
    answers = read_answers(out)
    reactions = answers["static"]["reactions"]
    assert set(reactions) == {"pivot", "A1", "A2"}  # the boom's joints, no force element
    assert {r["kind"] for r in reactions.values()} == {"joint"}
    assert answers["dynamic"]["largest_von_mises"]["value"] == pytest.approx(peak)
    png = plot_sections(out)
    assert png.exists() and png.stat().st_size > 10_000


@pytest.mark.parametrize("bending", ["cubic", "continuum"])
def test_large_deformation_root_axial_force_is_the_axial_load(bending):
    """A box cantilever (1.5 m, large deformation) with a tip force of 2 kN along the axis
    and 3 kN across: the root section stays normal to x (the weld), so N there is the axial
    load, 2000 N, to 1e-3 of the resultant. The bending strains' share along the section
    normal (M kappa, about 9 N here) is part of it: without it N is 1991 N."""
    s = System("c")
    steel = s.material("steel", **STEEL)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(1.5, 0, 0), nodes=4,
           section=Box(0.1, 0.16, 0.006), height_axis=(0, 1, 0), formulation="nonlinear",
           bending=bending)
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("tip", "force", body="arm", point=(1.5, 0, 0), vector=(2000.0, 3000.0, 0.0))
    model, result = _solve(s)
    f = section_forces(model, result.e)["arm"]
    assert f.N[0] == pytest.approx(2000.0, abs=1e-3 * np.hypot(2000.0, 3000.0))
    model.close()


@pytest.mark.parametrize("width, height, alpha", [(0.06, 0.06, 0.208), (0.05, 0.1, 0.246),
                                                   (0.025, 0.1, 0.282)])
def test_twisted_rectangle_saint_venant_shear(width, height, alpha):
    """A rectangle twisted by 40 N m: the largest shear stress T / (alpha a b^2) (a the
    long, b the short side; alpha = 0.208, 0.246, 0.282 for a/b = 1, 2, 4: Timoshenko &
    Goodier's table, sec. 109), von Mises sqrt(3) tau, from the section's torque. The twist
    stays small (0.001 rad at 4:1 with the Saint-Venant J): the FFR model's dead moment
    departs from its linear torque by about theta^2/2 (6e-5 at 400 N m)."""
    torque = 40.0
    s = System("bar")
    steel = s.material("steel", **STEEL)
    s.beam("bar", material=steel, start=(0, 0, 0), end=(1, 0, 0), nodes=3,
           section=Rectangle(width, height), height_axis=(0, 1, 0), formulation="ffr",
           bending="cubic")
    s.joint("root", "weld", "ground", "bar", point=(0, 0, 0))
    s.load("twist", "moment", body="bar", point=(1, 0, 0), vector=(torque, 0, 0))
    model, result = _solve(s)
    f = section_forces(model, result.e)["bar"]
    assert f.T == pytest.approx(torque, rel=1e-5)
    long, short = max(width, height), min(width, height)
    tau = torque / (alpha * long * short**2)
    stress = beam_stress(Rectangle(width, height), f)
    assert stress.von_mises == pytest.approx(np.sqrt(3.0) * tau, rel=3e-3)  # 3 digits
    model.close()


def test_static_answers_bundle_the_three(tmp_path):
    """static_answers gives the same records as the three functions, and the file written
    from it holds them under the joint's and the beam's names."""
    from ancfdrv.results import hdf5
    from ancfdrv.system.answers import static_answers
    s = System("c")
    steel = s.material("steel", **STEEL)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(2, 0, 0), nodes=5,
           section=Tube(0.1, 0.005), height_axis=(0, 1, 0), formulation="nonlinear",
           bending="cubic")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("tip", "force", body="arm", point=(2, 0, 0), vector=(0.0, -500.0, 0.0))
    model, result = _solve(s)
    every = static_answers(model, result.e, result.lam)
    assert every.reactions["root"].force == pytest.approx([0.0, 500.0, 0.0], abs=1e-6)
    assert every.sections["arm"].M[0, 1] == pytest.approx(-1000.0, rel=1e-4)
    out = tmp_path / "c.h5"
    with h5py.File(out, "w") as h5:
        h5.create_group("model")
    hdf5.write_static_answers(out, model, result.e, result.lam)
    with h5py.File(out) as h5:
        assert h5["static/reactions/root/force"][()] == pytest.approx([0.0, 500.0, 0.0], abs=1e-6)
        assert h5["static/stress/arm/von_mises"][0] == pytest.approx(
            every.stress["arm"].von_mises[0])
        assert h5["static/stress/arm"].attrs["s_max"] == pytest.approx(0.0)
    model.close()
