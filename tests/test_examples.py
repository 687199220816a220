"""The example scripts of examples/ run end to end (their --quick settings) and their numbers
agree with independent references, computed here from the parameters the examples declare:

* knuckle boom: rigid geometry and statics, the small-deflection sag of the flexible boom
  (tests/reference/mechanisms.py); the lift's force against the quasi-static rigid force;
* aerial platform: a linear Timoshenko frame model (tests/reference/frames.py) for the
  static deflection and tilt, the first eigenfrequency and, by modal superposition of its
  modes under the turntable's angular acceleration, the basket's sway while slewing;
* slider-crank: the rigid slider-crank (closed-form kinematics, torque by virtual work) and
  the quasi-static bending of the connecting rod under its own transverse inertia;
* three-leaf spring: the two-leaf spring's static drop by curved-beam theory
  (tests/reference/leaf_reference.py), the step response's overshoot, the energy balance;
* sweep: Mattiasson's (1981) tabulated elastica for k = 10.

Each example runs once per module (about 20 s of CPU for the whole file).
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ancfdrv.results.hdf5 import read_summary

from reference import frames, leaf_reference, mechanisms

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
sys.path.insert(0, str(EXAMPLES))

import aerial_platform  # noqa: E402
import knuckle_boom  # noqa: E402
import slider_crank  # noqa: E402
import sweep_from_python  # noqa: E402
import three_leaf_spring  # noqa: E402


def check_files(report) -> None:
    """Every file the example lists exists; result files are finished ancfdrv results."""
    for path in report.files:
        assert path.is_file() and path.stat().st_size > 0, path
        if path.suffix == ".h5":
            assert read_summary(path)["status"] == "ok"
        if path.suffix == ".md":
            assert "|---|" in path.read_text()


# -- knuckle boom ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def knuckle(tmp_path_factory):
    return knuckle_boom.run(quick=True, out=tmp_path_factory.mktemp("knuckle"))


def knuckle_sag(p: knuckle_boom.KnuckleBoom, stroke: float):
    """mechanisms.knuckle_boom_flexible_sag with the example's data (sections as closed
    forms of a box: frames.box, in-plane bending along the height: Iy there)."""
    boom, jib = (frames.box(s.width, s.height, s.wall) for s in (p.boom_section, p.jib_section))
    e, g = p.youngs_modulus, p.youngs_modulus / (2 * (1 + p.poisson_ratio))
    return mechanisms.knuckle_boom_flexible_sag(
        p.boom_length, p.density * boom.A * p.boom_length, p.jib_length,
        p.density * jib.A * p.jib_length, p.boom_angle, p.boom_lug, p.jib_lug, stroke,
        e * boom.A, e * boom.Iy, e * jib.A, e * jib.Iy, g * boom.A, g * jib.A,
        gravity=(0, -9.81), tip_load=(0, -9.81 * p.payload), branch=-1)


def test_knuckle_boom_rigid_geometry_and_force_match_the_reference():
    p = knuckle_boom.KnuckleBoom()
    strokes = np.linspace(1.2, 2.15, 7)
    angles = mechanisms.knuckle_boom_jib_angle(p.boom_length, p.boom_angle, (p.boom_lug, 0.0),
                                               (p.jib_lug, 0.0), strokes, branch=-1)
    assert [p.jib_angle(s) for s in strokes] == pytest.approx(angles, abs=1e-12)
    boom_mass, jib_mass = p.masses()
    statics = mechanisms.knuckle_boom_statics(
        p.boom_length, boom_mass, p.jib_length, jib_mass, p.boom_angle, (p.boom_lug, 0.0),
        (p.jib_lug, 0.0), strokes, tip_load=(0, -9.81 * p.payload), branch=-1)
    assert p.rigid_cylinder_force(strokes) == pytest.approx(statics.actuator_force, rel=1e-12)


def test_knuckle_boom_statics_match_the_small_deflection_closed_form(knuckle):
    """Measured (quick mesh): sag within 0.21 %, chord rotation 0.12 %, force 0.11 %."""
    check_files(knuckle)
    p = knuckle_boom.KnuckleBoom()
    for case in knuckle.statics:
        ref = knuckle_sag(p, case.stroke)
        assert case.rigid_angle == pytest.approx(float(ref.statics.jib_angle), abs=1e-12)
        assert case.tip_sag == pytest.approx(ref.tip_transverse, rel=0.01)
        assert case.tip_displacement[:2] == pytest.approx(ref.tip, rel=0.02, abs=5e-5)
        assert case.chord_angle - case.rigid_angle == pytest.approx(ref.jib_chord_rotation,
                                                                    rel=0.01)
        assert case.force == pytest.approx(float(ref.statics.actuator_force), rel=5e-3)


def test_knuckle_boom_lift_follows_the_quasi_static_force_and_ends_at_rest(knuckle):
    """At constant stroke rate the force is the rigid quasi-static one plus vibration
    (measured 1.2 %); holding, it averages the static equilibrium at the final length
    (0.1 %) with the tip there (0.1 mm of 5.4 mm sag); the energy balance closes."""
    run, p = knuckle.lift, knuckle_boom.KnuckleBoom()
    boom_mass, jib_mass = p.masses()
    rigid = mechanisms.knuckle_boom_statics(
        p.boom_length, boom_mass, p.jib_length, jib_mass, p.boom_angle, (p.boom_lug, 0.0),
        (p.jib_lug, 0.0), run.stroke, tip_load=(0, -9.81 * p.payload), branch=-1)
    steady = (run.time > 0.75) & (run.time < run.ramp_end - 0.75)
    assert run.force[steady].mean() == pytest.approx(rigid.actuator_force[steady].mean(),
                                                     rel=0.03)
    assert run.stroke[0] == pytest.approx(1.8) and run.stroke[-1] == pytest.approx(2.1)
    hold = run.time > run.ramp_end
    final = knuckle.statics[1]
    assert run.force[hold].mean() == pytest.approx(final.force, rel=0.01)
    tip_rest = p.points(2.1)["T"] + final.tip_displacement
    assert np.linalg.norm(run.tip[hold].mean(axis=0) - tip_rest) < 3e-4
    assert np.abs(run.energy_balance).max() < 1e-4 * np.abs(run.drive_work).max()


# -- aerial platform --------------------------------------------------------------------------
@pytest.fixture(scope="module")
def platform(tmp_path_factory):
    return aerial_platform.run(quick=True, out=tmp_path_factory.mktemp("platform"))


def platform_frame(p: aerial_platform.Platform) -> tuple[frames.Frame, list[int]]:
    """The boom as 40 Timoshenko elements clamped at the root, the basket a rigid body at
    the tip node with its offset centre of mass."""
    frame = frames.Frame()
    nodes = frame.add_beam_line((0, 0, 0), (p.boom_length, 0, 0), 40, p.youngs_modulus,
                                p.youngs_modulus / (2 * (1 + p.poisson_ratio)),
                                frames.box(p.section.width, p.section.height, p.section.wall),
                                p.density, theory="timoshenko", height_axis=(0, 0, 1))
    frame.fix(nodes[0])
    a, b, c = p.basket_size
    m = p.basket_mass
    frame.add_rigid_body(nodes[-1], m, [m * (b * b + c * c) / 12, m * (a * a + c * c) / 12,
                                        m * (a * a + b * b) / 12], p.basket_offset)
    return frame, nodes


def test_aerial_platform_statics_and_frequency_match_the_frame_model(platform):
    """Measured: tip 0.05 %, tilt 0.07 %, first frequency 0.01 % (quick settings)."""
    check_files(platform)
    p = aerial_platform.Platform()
    frame, nodes = platform_frame(p)
    tip = frame.solve_static(gravity=(0, 0, -9.81)).displacements[nodes[-1]]
    assert platform.statics.tip[2] == pytest.approx(tip[2], rel=3e-3)
    assert platform.statics.tilt == pytest.approx(tip[4], rel=3e-3)
    modes = frame.solve_modes(2)
    assert abs(modes.modes[0, nodes[-1], 1]) > 10 * abs(modes.modes[0, nodes[-1], 2])  # sideways
    assert platform.frequency == pytest.approx(modes.frequency_hz[0], rel=5e-3)


def luffing_acceleration(t: float, s: aerial_platform.Slew) -> float:
    """phi'' of the luffing profile, SPEC section 5 (cosine start, constant rate, cosine
    stop)."""
    t1 = s.t_start + s.sweep / s.omega - 0.5 * (s.t_start + s.t_brake)
    if t < s.t_start:
        return s.omega * math.pi / (2 * s.t_start) * math.sin(math.pi * t / s.t_start)
    if t1 <= t < t1 + s.t_brake:
        return -s.omega * math.pi / (2 * s.t_brake) * math.sin(math.pi * (t - t1) / s.t_brake)
    return 0.0


def test_aerial_platform_sway_while_slewing_matches_modal_superposition(platform):
    """The frame model's 6 lowest modes (to 54 Hz) driven by the turntable's angular acceleration
    (base excitation -M r phi'', r the rigid rotation about z; slow slewing: no
    centrifugal terms). Measured: peak sway 41.25 vs 41.23 mm, rms difference 2 %."""
    p, slew, run = aerial_platform.Platform(), platform.slew_profile, platform.slew
    frame, nodes = platform_frame(p)
    _, mass, _ = frame.assemble()
    modes = frame.solve_modes(6)
    x = frame.nodes
    rigid = np.zeros((len(x), 6))
    rigid[:, 0], rigid[:, 1], rigid[:, 5] = -x[:, 1], x[:, 0], 1.0
    participation = np.einsum("kij,ij->k", modes.modes, (mass @ rigid.ravel()).reshape(-1, 6))
    tip = modes.modes[:, nodes[-1]]
    offset = p.basket_offset
    basket_y = tip[:, 1] + tip[:, 5] * offset[0] - tip[:, 3] * offset[2]   # u + theta x c
    w, n = modes.omega, len(modes.omega)

    def rhs(t, y):
        return np.concatenate([y[n:], -w**2 * y[:n] - participation * luffing_acceleration(t, slew)])
    solution = solve_ivp(rhs, (0.0, run.time[-1]), np.zeros(2 * n), t_eval=run.time,
                         method="DOP853", rtol=1e-9, atol=1e-12, max_step=0.01)
    reference_sway = solution.y[:n].T @ basket_y
    rest = p.basket_centre + platform.statics.basket
    sway = aerial_platform.turning_frame(run.basket, run.angle)[:, 1] - rest[1]
    peak = np.abs(reference_sway).max()
    assert np.abs(sway).max() == pytest.approx(peak, rel=0.02)
    assert np.sqrt(np.mean((sway - reference_sway) ** 2)) < 0.05 * np.sqrt(np.mean(reference_sway**2))
    assert run.angle[-1] == pytest.approx(slew.sweep, abs=1e-12)
    assert np.abs(run.balance).max() < 1e-3 * run.kinetic.max()


# -- slider-crank -----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def crank(tmp_path_factory):
    return slider_crank.run(quick=True, out=tmp_path_factory.mktemp("crank"))


def rigid_crank(p: slider_crank.SliderCrank, run: slider_crank.Run):
    return mechanisms.slider_crank(run.time, p.crank_length, p.rod_length, p.crank_mass,
                                   p.rod_mass(run.diameter), p.slider_mass, p.omega,
                                   theta0=-0.5 * p.omega * p.spinup)


def test_slider_crank_assembles_with_redundant_equations_dropped(crank):
    check_files(crank)
    notes = crank.stiff.notes
    assert any("crank drive: z(t) (satisfied identically)" in n for n in notes)
    assert len(notes) >= 5 and all(n.startswith("redundant joint equation dropped") for n in notes)


def test_driving_a_coordinate_a_planar_guide_holds_is_refused():
    """The assembly's check behind the slider-crank's dropped 'crank drive: z(t)': when the
    eliminated joints leave a driven coordinate equation without a coordinate, the joints
    conflict and the message says which equation."""
    from ancfdrv import System
    from ancfdrv.errors import InputError
    s = System("conflict")
    s.drive("lift", "sine", amplitude=0.1, frequency=1.0)
    s.rigid_body("slider", mass=1.0, inertia=(1, 1, 1, 0, 0, 0), position=(0, 0, 0),
                 planar=True, plane_normal=(0, 0, 1))
    s.joint("lift", "prescribed", "ground", "slider", point=(0, 0, 0), axis=(0, 0, 1),
            drive="lift")
    with pytest.raises(InputError, match=r"lift: z\(t\): the coordinate this drive moves is "
                                         r"held by other joints"):
        s.assemble()


def test_stiff_slider_crank_is_the_rigid_mechanism(crank):
    """40 mm rod: slider within 3.1 um of the rigid kinematics (its stretch under the
    slider's inertia), driving torque within 0.08 % rms of the virtual-work torque."""
    p, run = slider_crank.SliderCrank(), crank.stiff
    ref = rigid_crank(p, run)
    steady = run.time >= p.spinup
    assert run.angle[steady] == pytest.approx(ref.crank_angle[steady], abs=1e-9)
    stroke = 2 * p.crank_length
    assert np.abs(run.slider_x - ref.slider_x)[steady].max() < 5e-5 * stroke
    rms = np.sqrt(np.mean(ref.torque[steady] ** 2))
    assert np.sqrt(np.mean((run.torque - ref.torque)[steady] ** 2)) < 5e-3 * rms


def quasi_static_midpoint(p: slider_crank.SliderCrank, run: slider_crank.Run) -> np.ndarray:
    """Midpoint deflection of the rod as a simply supported beam under the transverse
    inertia of its rigid motion: the load is linear along the rod, its antisymmetric part
    leaves the midpoint, so delta = -5 rho A a_perp(mid) l^4 / (384 EI)."""
    ref = rigid_crank(p, run)
    theta, psi = ref.crank_angle, ref.rod_angle
    pin = -p.crank_length * p.omega**2 * np.column_stack([np.cos(theta), np.sin(theta)])
    along = np.column_stack([np.cos(psi), np.sin(psi)])
    normal = np.column_stack([-np.sin(psi), np.cos(psi)])
    mid = pin + 0.5 * p.rod_length * (ref.rod_acceleration[:, None] * normal
                                      - (ref.rod_rate**2)[:, None] * along)
    a_perp = np.einsum("ij,ij->i", mid, normal)
    d = run.diameter
    area, inertia = math.pi * d**2 / 4, math.pi * d**4 / 64
    return -5 * p.density * area * a_perp * p.rod_length**4 / (384 * p.youngs_modulus * inertia)


def test_rod_midpoint_deflection_is_its_transverse_inertia(crank):
    """Soft rod (8 mm): peak 1.41 mm against 1.45 mm quasi-static, the rest is the rod's
    vibration and the slider's axial push; the stiff rod bends 25 times less."""
    p = slider_crank.SliderCrank()
    for run, peak_tol, rms_tol in ((crank.soft, 0.1, 0.15), (crank.stiff, 0.05, 0.15)):
        steady = run.time >= p.spinup
        ref = quasi_static_midpoint(p, run)[steady]
        model = run.deflection[steady]
        assert np.abs(model).max() == pytest.approx(np.abs(ref).max(), rel=peak_tol)
        assert np.sqrt(np.mean((model - ref) ** 2)) < rms_tol * np.sqrt(np.mean(ref**2))
    assert np.abs(crank.soft.deflection).max() > 20 * np.abs(crank.stiff.deflection).max()


# -- three-leaf spring ------------------------------------------------------------------------
@pytest.fixture(scope="module")
def springs(tmp_path_factory):
    return three_leaf_spring.run(quick=True, out=tmp_path_factory.mktemp("springs"))


def test_third_leaf_stiffens_the_spring(springs):
    """Measured: sag 29.3 mm (two leaves) and 24.1 mm (three), drop from the assembled
    state 18.0 and 6.7 mm."""
    check_files(springs)
    two, three = springs.springs
    assert (two.leaves, three.leaves) == (2, 3)
    assert 0 < three.sag < 0.9 * two.sag
    assert three.built - three.loaded < two.built - two.loaded
    assert three.unloaded - three.chassis.min() < two.unloaded - two.chassis.min()
    assert set(three.pair_forces) == {"main-second", "second-third"}
    assert all(f.min() > 0 for s in springs.springs for f in s.pair_forces.values())


def test_two_leaf_static_drop_matches_curved_beam_theory(springs):
    """The two-leaf spring's drop from its assembled state lies within 5 % of the
    curved-beam reference with the beam bending stiffness (measured 1.3 %), and above the
    plate-stiffness one (the leaves bend as strips with free edges)."""
    two = springs.springs[0]
    drop = two.built - two.loaded
    beam = leaf_reference.chassis_static_drop(leaf_reference.BEAM_EI, prestress=True,
                                              contact_stiffness=3.0e6, shackle_tilt=True)
    plate = leaf_reference.chassis_static_drop(leaf_reference.PLATE_DW, prestress=True,
                                               contact_stiffness=3.0e6, shackle_tilt=True)
    assert drop == pytest.approx(beam["drop"], rel=0.05)
    assert drop > plate["drop"]


def test_spring_drop_overshoots_twice_the_sag_and_balances_energy(springs):
    """A step load on a lightly damped spring: the first minimum is twice the static sag
    (measured 58.59/58.58 and 48.17/48.24 mm); the energy balance closes to 1e-4 of the
    chassis's potential drop (measured 5e-6 and 1e-5)."""
    for s in springs.springs:
        drop = s.unloaded - s.chassis.min()
        assert drop == pytest.approx(2 * s.sag, rel=0.05)
        assert s.time[np.argmin(s.chassis)] < s.time[-1]          # the minimum was reached
        scale = three_leaf_spring.CHASSIS_MASS * 9.81 * drop
        assert np.abs(s.balance).max() < 1e-4 * scale
        assert s.dissipated[-1] < 0


# -- sweep --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    return sweep_from_python.run(quick=True, out=tmp_path_factory.mktemp("sweep"))


def test_sweep_converges_to_mattiasson_elastica(sweep):
    """Mattiasson (1981), k = 10: w/L = 0.81061, u/L = 0.55500. Quick meshes 5..17 nodes
    (3 nodes: the 'cubic' state is unstable, refused): both bending options converge;
    cubic bending is within 0.6 % at 17 nodes."""
    check_files(sweep)
    assert sweep.reference == pytest.approx((0.81061, 0.55500), abs=1e-5)
    for bending in ("continuum", "cubic"):
        cases = [c for c in sweep.cases if c.bending == bending]
        assert [c.nodes for c in cases] == [5, 9, 17]
        errors = [max(abs(c.w / 0.81061 - 1), abs(c.u / 0.55500 - 1)) for c in cases]
        assert all(a > b for a, b in zip(errors, errors[1:]))
    finest = [c for c in sweep.cases if c.bending == "cubic"][-1]
    assert max(abs(finest.w / 0.81061 - 1), abs(finest.u / 0.55500 - 1)) < 6e-3
