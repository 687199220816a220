"""Verification of the general-system API (issue 12): joints between beams, rigid bodies and the
ground, against independent references, and the joint equations themselves.

References (tests/reference, written without looking at ancfdrv):

* ``frames``: linear 3D frame FE (Timoshenko elements, exact for nodal loads, with hinges:
  revolute about an axis or spherical, rigid joints, supports);
* ``beam_formulas``: unit-load closed forms of the L-frame and the L-grillage, the simply
  supported beam;
* central differences of the constraint values (the Jacobians), the initial configuration
  (every joint holds there), exact expectations for the errors and the effects switch.

The project's beams use shear coefficient 1 and J = I_h + I_w (frames.py does the same), G = E/2.
'cubic' bending is exact for nodal loads like the frames.py elements, so FFR 'cubic' results
agree to rounding; 'nonlinear' beams add their geometric nonlinearity (loads are kept small:
rotations below 1e-5 rad, so it stays below 1e-6 relative), and 'continuum' beams converge at
order 2, so the Richardson extrapolation of two meshes meets the reference.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from ancfdrv import Box, Rectangle, System
from ancfdrv.errors import InputError
from ancfdrv.solvers.static import solve_newton
from ancfdrv.system.joints import LinearEquation

sys.path.insert(0, str(Path(__file__).resolve().parent))
from reference import beam_formulas as bf  # noqa: E402  (tests/reference: never used by a run)
from reference import frames  # noqa: E402

E, RHO, G = 2.1e11, 7850.0, 2.1e11 / 2.0
SECTION, REF = Rectangle(0.05, 0.1), frames.rectangle(0.05, 0.1)   # width 0.05, height 0.1
I_H, I_W, AREA = REF.Iy, REF.Iz, REF.A     # frames: Iy = int (height)^2 dA


def _solve_probes(s: System, tol: float = 1e-12) -> dict[str, np.ndarray]:
    """Static solution of a system: the displacement of every probe."""
    model = s.assemble()
    try:
        e = solve_newton(model, tol=tol).e
        return {k: v - model.probe_positions(model.e0)[k]
                for k, v in model.probe_positions(e).items()}
    finally:
        model.close()


def _frame_line(frame, start, end, n, height_axis, start_node=None):
    return frame.add_beam_line(start, end, n, E, G, REF, theory="timoshenko",
                               height_axis=height_axis, start_node=start_node)


# ------------------------------------------------------------------------------- welds
def _knee(angle_deg: float, formulation: str, bending: str, nodes: int, force):
    """Column (0,0,0)-(0,H,0) welded to the ground, arm welded to the column's top at the
    given angle from +x in the x-y plane; a tip force. Returns the tip displacement."""
    h, length = 1.5, 2.0
    a = np.radians(angle_deg)
    top = np.array([0.0, h, 0.0])
    tip = top + length * np.array([np.cos(a), np.sin(a), 0.0])
    s = System("knee")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("column", material=steel, start=(0, 0, 0), end=top, nodes=nodes, section=SECTION,
           height_axis=(1, 0, 0), formulation=formulation, bending=bending)
    s.beam("arm", material=steel, start=top, end=tip, nodes=nodes, section=SECTION,
           height_axis=(-np.sin(a), np.cos(a), 0), formulation=formulation, bending=bending)
    s.joint("base", "weld", "ground", "column", point=(0, 0, 0))
    s.joint("corner", "weld", "column", "arm", point=top)
    s.load("F", "force", body="arm", point=tip, vector=force)
    s.probe("tip", "arm", tip)
    return _solve_probes(s)["tip"]


def _knee_frame(angle_deg: float, force) -> np.ndarray:
    """frames.py model of the same knee (rigid joint: the two members share a node)."""
    h, length = 1.5, 2.0
    a = np.radians(angle_deg)
    top = np.array([0.0, h, 0.0])
    frame = frames.Frame()
    column = _frame_line(frame, (0, 0, 0), top, 3, (1, 0, 0))
    arm = _frame_line(frame, top, top + length * np.array([np.cos(a), np.sin(a), 0.0]), 4,
                      (-np.sin(a), np.cos(a), 0), start_node=column[-1])
    frame.fix(column[0])
    frame.add_nodal_load(arm[-1], force=force)
    return frame.solve_static().displacements[arm[-1], :3]


@pytest.mark.parametrize("force", [(300.0, -500.0, 0.0), (0.0, 0.0, 200.0)],
                         ids=["in-plane", "out-of-plane"])
def test_l_frame_weld_closed_form_and_frames(force):
    """L-frame: column H = 1.5 m clamped at its base, arm L = 2 m welded at the corner at 90
    degrees, tip load. FFR 'cubic' on 2 and 4 elements per member against the unit-load
    closed forms (beam_formulas.l_frame_tip_displacement: M, N and V of both members;
    l_grillage_tip_deflection: bending of both and torsion G J of the column, J the
    Saint-Venant constant of the 50 x 100 mm rectangle)
    and frames.py, to 1e-9. The weld passes the moment through the sections, so the result
    does not depend on the mesh (a weld to the column's sheared tangent did: 0.1 % on 2
    elements, 1.4 % on 16)."""
    fx, fy, fz = force
    dx, dy = bf.l_frame_tip_displacement(1.5, 2.0, fx, fy, E * AREA, E * I_H, E * AREA, E * I_H,
                                         G * AREA, G * AREA)
    dz = bf.l_grillage_tip_deflection(fz, 1.5, 2.0, E * I_W, G * REF.J, E * I_W,
                                      G * AREA, G * AREA)
    closed = np.array([dx, dy, dz])
    reference = _knee_frame(0.0, force)
    np.testing.assert_allclose(reference, closed, rtol=1e-12, atol=1e-15)
    for nodes in (3, 5):
        tip = _knee(0.0, "ffr", "cubic", nodes, force)
        np.testing.assert_allclose(tip, closed, rtol=1e-9, atol=1e-9 * np.abs(closed).max())


@pytest.mark.parametrize("angle", [0.0, 45.0, 110.0])
@pytest.mark.parametrize("formulation,bending", [("ffr", "cubic"), ("nonlinear", "cubic"),
                                                 ("ffr", "continuum")])
def test_welded_knee_any_angle_against_frames(angle, formulation, bending):
    """Column and arm welded at 0, 45 and 110 degrees (oblique welds keep the sections' angle),
    a tip load in the plane and out of it, against frames.py (rigid joint).

    * FFR 'cubic' (2 elements per member): 1e-9 of the largest displacement;
    * 'nonlinear' 'cubic': its geometric nonlinearity makes the deviation from the linear
      reference proportional to the load (below 2e-5 at a load of 0.5 N, tip rotation
      3e-6 rad, 10 times less at a tenth of it), so the result extrapolated to zero load from
      the two, (10 u(P/10)/(P/10) - u(P)/P) / 9 per unit load, meets it to 1e-7;
    * FFR 'continuum': order-2 Richardson of 4 and 8 elements per member within 1e-6."""
    force = np.array([300.0, -500.0, 200.0])
    if formulation == "nonlinear":
        small = 1e-2 * force
        reference = _knee_frame(angle, small)
        scale = np.abs(reference).max()
        big, tenth = _knee(angle, formulation, bending, 3, small), \
            _knee(angle, formulation, bending, 3, 0.1 * small)
        assert np.abs(big - reference).max() < 2e-4 * scale
        assert np.abs(10 * tenth - reference).max() < 0.15 * np.abs(big - reference).max()
        np.testing.assert_allclose((100 * tenth - big) / 9, reference, rtol=0, atol=1e-8 * scale)
        return
    reference = _knee_frame(angle, force)
    scale = np.abs(reference).max()
    if bending == "cubic":
        tip = _knee(angle, formulation, bending, 3, force)
        np.testing.assert_allclose(tip, reference, rtol=0, atol=1e-9 * scale)
    else:
        coarse = _knee(angle, formulation, bending, 5, force)
        fine = _knee(angle, formulation, bending, 9, force)
        np.testing.assert_allclose((4 * fine - coarse) / 3, reference, rtol=0, atol=1e-6 * scale)


def test_space_frame_welds_of_three_orientations():
    """A space frame of three members along z, x and y (a column and two arms welded end to
    end, each height axis different), FFR 'cubic', a 3D load at the free end and another at
    the first corner: displacements of the two corners and the tip against frames.py to
    1e-9 (bending, torsion and axial force in every member)."""
    h, a, b = 1.2, 1.5, 1.0
    p1, p2, p3 = np.array([0, 0, h]), np.array([a, 0, h]), np.array([a, b, h])
    f_tip, f_corner = np.array([40.0, -70.0, 90.0]), np.array([-30.0, 50.0, 20.0])
    s = System("space frame")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    members = [("column", (0, 0, 0), p1, (1, 0, 0)), ("arm x", p1, p2, (0, 1, 0)),
               ("arm y", p2, p3, (0, 0, 1))]
    for name, start, end, height in members:
        s.beam(name, material=steel, start=start, end=end, nodes=3, section=SECTION,
               height_axis=height, formulation="ffr", bending="cubic")
    s.joint("base", "weld", "ground", "column", point=(0, 0, 0))
    s.joint("knee 1", "weld", "column", "arm x", point=p1)
    s.joint("knee 2", "weld", "arm y", "arm x", point=p2)      # either order of the bodies
    s.load("F tip", "force", body="arm y", point=p3, vector=f_tip)
    s.load("F corner", "force", body="arm x", point=p1, vector=f_corner)
    for name, point in (("p1", p1), ("p2", p2), ("p3", p3)):
        s.probe(name, "arm x" if name != "p3" else "arm y", point)
    got = _solve_probes(s)
    frame = frames.Frame()
    nodes, previous = [], None
    for _, start, end, height in members:
        line = _frame_line(frame, start, end, 2, height, start_node=previous)
        nodes.append(line)
        previous = line[-1]
    frame.fix(nodes[0][0])
    frame.add_nodal_load(nodes[2][-1], force=f_tip)
    frame.add_nodal_load(nodes[0][-1], force=f_corner)
    u = frame.solve_static().displacements
    expected = {"p1": u[nodes[0][-1], :3], "p2": u[nodes[1][-1], :3], "p3": u[nodes[2][-1], :3]}
    scale = max(np.abs(v).max() for v in expected.values())
    for name in expected:
        np.testing.assert_allclose(got[name], expected[name], rtol=0, atol=1e-9 * scale)


# ----------------------------------------------------------- a rigid body welded to a beam
BOOM = dict(length=8.0, section=Box(0.25, 0.30, 0.006), ref=frames.box(0.25, 0.30, 0.006))


def _welded_tip_body(nodes: int, body_first: bool, loads, probes, *, mass=1.0,
                     inertia=(1.0, 1.0, 1.0, 0.0, 0.0, 0.0), centre=(0.0, 0.0, 0.0)):
    """The 8 m box cantilever of BOOM along x (height along z), FFR 'cubic', clamped at
    x = 0, a rigid body welded at its tip node (centre of mass at tip + centre), named first
    or second in the weld; loads (type, point, vector; gravity: vector only) on the body;
    probes {name: (body, point)}. Returns the probe displacements and the model's notes."""
    length = BOOM["length"]
    tip = np.array([length, 0.0, 0.0])
    s = System("welded tip body")
    steel = s.material("steel", youngs_modulus=E, density=RHO, poisson_ratio=0.0)
    s.beam("beam", material=steel, start=(0, 0, 0), end=tip, nodes=nodes,
           section=BOOM["section"], height_axis=(0, 0, 1), formulation="ffr", bending="cubic")
    s.joint("clamp", "weld", "ground", "beam", point=(0, 0, 0))
    s.rigid_body("body", mass=mass, inertia=inertia, position=tip + np.asarray(centre))
    pair = ("body", "beam") if body_first else ("beam", "body")
    s.joint("mount", "weld", *pair, point=tip)
    for k, (kind, point, vector) in enumerate(loads):
        if kind == "gravity":
            s.load(f"load {k}", kind, vector=vector)
        else:
            s.load(f"load {k}", kind, body="body", point=point, vector=vector)
    for name, (body, point) in probes.items():
        s.probe(name, body, point)
    model = s.assemble()
    try:
        e = solve_newton(model, tol=1e-12).e
        initial, final = model.probe_positions(model.e0), model.probe_positions(e)
        return {k: final[k] - initial[k] for k in final}, list(model.notes)
    finally:
        model.close()


@pytest.mark.parametrize("body_first", [True, False], ids=["body first", "beam first"])
@pytest.mark.parametrize("nodes", [3, 9, 17])
@pytest.mark.parametrize("case", ["transverse", "axial", "torque"])
def test_rigid_body_welded_to_ffr_tip_closed_form(case, nodes, body_first):
    """A rigid body welded at the tip of the 8 m FFR 'cubic' box cantilever, loaded on the
    body: a 1 kN force across the beam 1 m beyond the tip, or 100 kN along the beam's axis
    there, or a torque of 20 kN m about the axis (a couple of forces on the body).
    Displacements of the beam's tip, of the body's point 1 m beyond it and of a body point
    0.5 m off the axis against the Timoshenko closed forms (beam_formulas: tip force plus
    the moment P * 1 m; N L / (E A); twist T L / (G J), J the Saint-Venant constant) on 2, 8 and 16
    elements, whichever body the weld names first.

    Tolerance 1e-9 of the largest displacement: FFR 'cubic' is linear and exact for end
    loads on any mesh, and the body's axes follow the tip section's small turn linearly, so
    only rounding remains (observed below 1e-11; a displacement is a difference of positions
    near 8 m). A weld that held the FFR directors at unit length through the turn made the
    beam too stiff by an error growing with the element length and the square of the turn:
    2.2e-3 on 2 elements, 2.8e-4 on 16 in the transverse case (tip turn 2e-3 rad), 9.4e-2 on
    2 elements in the torque case (twist 1e-2 rad)."""
    length, ref = BOOM["length"], BOOM["ref"]
    ei, ea, ga, gj = E * ref.Iy, E * ref.A, G * ref.A, G * ref.J
    arm, side = np.array([length + 1.0, 0.0, 0.0]), np.array([length, 0.5, 0.0])
    probes = {"tip": ("beam", (length, 0.0, 0.0)), "arm": ("body", arm), "side": ("body", side)}
    expected = {name: np.zeros(3) for name in probes}
    if case == "transverse":
        p = 1000.0
        loads = [("force", arm, (0.0, 0.0, -p))]
        w_force, t_force = bf.cantilever_tip_load(p, length, ei, ga)
        w_moment, t_moment = bf.cantilever_end_moment(p * 1.0, length, ei)
        w, turn = w_force + w_moment, t_force + t_moment     # down; the tip turns about +y
        expected["tip"][2] = expected["side"][2] = -w
        expected["arm"][2] = -w - turn * 1.0
    elif case == "axial":
        n = 1e5
        loads = [("force", arm, (n, 0.0, 0.0))]
        for name in expected:
            expected[name][0] = n * length / ea
    else:
        torque, half = 2e4, 0.5                               # forces +-T / (2 half) along z
        loads = [("force", side, (0.0, 0.0, torque / (2 * half))),
                 ("force", side - [0.0, 2 * half, 0.0], (0.0, 0.0, -torque / (2 * half)))]
        expected["side"][2] = half * torque * length / gj
    got, notes = _welded_tip_body(nodes, body_first, loads, probes)
    assert any("rigid body 'body'" in n and "orthonormality not imposed" in n for n in notes), \
        notes
    scale = max(np.abs(v).max() for v in expected.values())
    for name in expected:
        np.testing.assert_allclose(got[name], expected[name], rtol=0, atol=1e-9 * scale,
                                   err_msg=name)


@pytest.mark.parametrize("body_first", [True, False], ids=["body first", "beam first"])
def test_welded_tip_body_weight_against_frames(body_first):
    """The weight of the beam and of a 200 kg body welded at its tip with its centre of mass
    off the tip (0.3, 0.1, -0.2) m (its weight also bends and twists the beam),
    FFR 'cubic' on 2 and 8 elements, against frames.py (Timoshenko elements, self weight,
    rigid body at an offset: exact for these loads) to 1e-9: the tip and the body's centre
    of mass (1.4e-2 off on 2 elements when the weld held the FFR directors at unit length)."""
    length, ref, centre, mass = BOOM["length"], BOOM["ref"], np.array([0.3, 0.1, -0.2]), 200.0
    gravity = np.array([0.0, 0.0, -9.81])
    frame = frames.Frame()
    line = frame.add_beam_line((0, 0, 0), (length, 0, 0), 4, E, G, ref, rho=RHO,
                               theory="timoshenko", height_axis=(0, 0, 1))
    frame.fix(line[0])
    frame.add_rigid_body(line[-1], mass, (5.0, 6.0, 7.0), centre)
    u = frame.solve_static(gravity=gravity).displacements[line[-1]]
    expected = {"tip": u[:3], "centre": u[:3] + np.cross(u[3:], centre)}
    scale = max(np.abs(v).max() for v in expected.values())
    tip = np.array([length, 0.0, 0.0])
    probes = {"tip": ("beam", tip), "centre": ("body", tip + centre)}
    for nodes in (3, 9):
        got, _ = _welded_tip_body(nodes, body_first, [("gravity", None, gravity)], probes,
                                  mass=mass, inertia=(5.0, 6.0, 7.0, 0.0, 0.0, 0.0),
                                  centre=centre)
        for name in expected:
            np.testing.assert_allclose(got[name], expected[name], rtol=0, atol=1e-9 * scale,
                                       err_msg=f"{name}, {nodes} nodes")


@pytest.mark.parametrize("order", ["A B", "B A"])
def test_rigid_bodies_welded_to_a_skew_ffr_beam_against_frames(order):
    """A chain of two rigid bodies (A welded to the tip of an oblique FFR 'cubic' cantilever,
    B welded to A, named in either order) carrying a 3D force on B away from the tip: the
    tip's displacement against frames.py under the force and its moment about the tip, to
    1e-9 (both linear, exact for end loads). Both bodies' axes are linearized (noted): B's
    follow A's through the weld between them."""
    direction = np.array([1.0, 0.5, 0.3]) / np.linalg.norm([1.0, 0.5, 0.3])
    tip = 8.0 * direction
    force, point = np.array([300.0, -500.0, 800.0]), tip + np.array([0.7, -0.2, 0.4])
    s = System("skew")
    steel = s.material("steel", youngs_modulus=E, density=RHO, poisson_ratio=0.0)
    s.beam("beam", material=steel, start=(0, 0, 0), end=tip, nodes=5, section=BOOM["section"],
           height_axis=(0, 0, 1), formulation="ffr", bending="cubic")
    s.joint("clamp", "weld", "ground", "beam", point=(0, 0, 0))
    s.rigid_body("A", mass=1.0, inertia=(1, 1, 1, 0, 0, 0), position=tip + [0.1, 0.0, 0.0])
    s.rigid_body("B", mass=2.0, inertia=(1, 2, 3, 0, 0, 0), position=tip + [0.5, 0.2, 0.1])
    s.joint("mount", "weld", "A", "beam", point=tip)
    s.joint("A-B", "weld", *order.split(), point=tip + [0.5, 0.0, 0.0])
    s.load("F", "force", body="B", point=point, vector=force)
    s.probe("tip", "beam", tip)
    model = s.assemble()
    try:
        got = model.probe_positions(solve_newton(model, tol=1e-12).e)["tip"] - tip
        constraints, notes, warnings = list(model.constraints.names), model.notes, model.warnings
    finally:
        model.close()
    frame = frames.Frame()
    line = frame.add_beam_line((0, 0, 0), tip, 2, E, G, BOOM["ref"], theory="timoshenko",
                               height_axis=(0, 0, 1))
    frame.fix(line[0])
    frame.add_nodal_load(line[-1], force=force, moment=np.cross(point - tip, force))
    expected = frame.solve_static().displacements[line[-1], :3]
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * np.abs(expected).max())
    assert not constraints and not warnings, (constraints, warnings)
    assert sum("orthonormality not imposed" in n for n in notes) == 2, notes


def test_rigid_body_between_ffr_and_nonlinear_beams_is_warned():
    """A rigid body welded to an FFR beam (its axes linearized) and to a 'nonlinear' beam:
    the weld to the nonlinear beam ties its directors to axes that are orthonormal to first
    order only; a warning names that weld, the body and the beam."""
    s = System("mixed")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    for name, start, end, formulation in (("ffr beam", (0, 0, 0), (1, 0, 0), "ffr"),
                                          ("nl beam", (1, 0, 0), (2, 0, 0), "nonlinear")):
        s.beam(name, material=steel, start=start, end=end, nodes=3, section=SECTION,
               formulation=formulation, bending="cubic")
    s.rigid_body("body", mass=1.0, inertia=(1, 1, 1, 0, 0, 0), position=(1, 0, 0))
    s.joint("clamp", "weld", "ground", "ffr beam", point=(0, 0, 0))
    s.joint("mount", "weld", "ffr beam", "body", point=(1, 0, 0))
    s.joint("joint 2", "weld", "body", "nl beam", point=(1, 0, 0))
    model = s.assemble()
    try:
        assert len(model.warnings) == 1, model.warnings
        assert all(w in model.warnings[0] for w in ("'joint 2'", "'body'", "'nl beam'",
                                                   "'mount'")), model.warnings
    finally:
        model.close()


# ------------------------------------------------------------------- hinges and supports
def test_gerber_beam_revolute_hinge():
    """Gerber beam: member A (0..1.5 m) clamped at x = 0, member B (1.5..3.5 m) joined to it by
    a 'revolute' about z (an internal hinge), B's far end on a roller ('fix' of r along y
    only). B is made of two beams welded end to end at its midpoint, where the load (in
    the plane and out of it) acts: a 'cubic' beam is exact for loads at its ends (its nodal
    shear cannot jump inside a beam, docs/theory.md section 12). The displacements of A's
    midpoint, the hinge, B's midpoint and B's end, and the rotations about z of the two
    sections at the hinge (different: the hinge opens), against frames.py (add_hinge with
    axis z, uy fixed at the roller) to 1e-9. FFR 'cubic'."""
    a, b = 1.5, 2.0
    load = np.array([0.0, -800.0, 150.0])
    s = System("gerber")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    for name, start, end in (("A", 0.0, a), ("B1", a, a + b / 2), ("B2", a + b / 2, a + b)):
        s.beam(name, material=steel, start=(start, 0, 0), end=(end, 0, 0), nodes=3,
               section=SECTION, height_axis=(0, 1, 0), bending="cubic")
    s.joint("clamp", "weld", "ground", "A", point=(0, 0, 0))
    s.joint("hinge", "revolute", "A", "B1", point=(a, 0, 0), axis=(0, 0, 1))
    s.joint("splice", "weld", "B1", "B2", point=(a + b / 2, 0, 0))
    s.joint("roller", "fix", "ground", "B2", point=(a + b, 0, 0), axis=(0, 1, 0))
    s.load("F", "force", body="B1", point=(a + b / 2, 0, 0), vector=load)
    model = s.assemble()
    try:
        q = model.expand(solve_newton(model, tol=1e-12).e)
    finally:
        model.close()
    first = {body.name: body.first for body in model.bodies}

    def node(name: str, k: int) -> np.ndarray:
        return q[first[name] + 12 * k: first[name] + 12 * k + 12].reshape(4, 3)
    got = [node("A", 1)[0] - (a / 2, 0, 0), node("A", 2)[0] - (a, 0, 0),
           node("B1", 2)[0] - (a + b / 2, 0, 0), node("B2", 2)[0] - (a + b, 0, 0)]
    turn = [np.arctan2(-node(*at)[2, 0], node(*at)[2, 1]) for at in (("A", 2), ("B1", 0))]

    frame = frames.Frame()
    na = _frame_line(frame, (0, 0, 0), (a, 0, 0), 2, (0, 1, 0))
    nb = _frame_line(frame, (a, 0, 0), (a + b, 0, 0), 2, (0, 1, 0))
    frame.fix(na[0])
    frame.add_hinge(na[-1], nb[0], axis=(0, 0, 1))
    frame.fix(nb[-1], ["uy"])
    frame.add_nodal_load(nb[1], force=load)
    u = frame.solve_static().displacements
    expected = [u[na[1], :3], u[na[2], :3], u[nb[1], :3], u[nb[2], :3]]
    scale = np.abs(expected).max()
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(turn, [u[na[2], 5], u[nb[0], 5]], rtol=1e-7)
    assert abs(turn[0] - turn[1]) > 0.1 * abs(turn[1])   # the hinge opens


def _hinged_corner(formulation: str, scale: float) -> np.ndarray:
    """Column clamped at its base, arm hinged to its top by a 'revolute' about z (an in-plane
    pin at the corner), the arm's tip on a roller ('fix' along y), a 3D tip load."""
    h, length = 1.5, 2.0
    s = System("hinged corner")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("column", material=steel, start=(0, 0, 0), end=(0, h, 0), nodes=3, section=SECTION,
           height_axis=(1, 0, 0), formulation=formulation, bending="cubic")
    s.beam("arm", material=steel, start=(0, h, 0), end=(length, h, 0), nodes=3,
           section=SECTION, height_axis=(0, 1, 0), formulation=formulation, bending="cubic")
    s.joint("base", "weld", "ground", "column", point=(0, 0, 0))
    s.joint("pin", "revolute", "column", "arm", point=(0, h, 0), axis=(0, 0, 1))
    s.joint("roller", "fix", "ground", "arm", point=(length, h, 0), axis=(0, 1, 0))
    s.load("F", "force", body="arm", point=(length, h, 0),
           vector=scale * np.array([300.0, -500.0, 200.0]))
    s.probe("tip", "arm", (length, h, 0))
    return _solve_probes(s)["tip"]


@pytest.mark.parametrize("formulation", ["ffr", "nonlinear"])
def test_revolute_at_a_corner_passes_torsion(formulation):
    """An L of two beams with a 'revolute' about z at the corner (the in-plane moment is
    released, the out-of-plane one passes: it twists the column) and a roller under the
    arm's tip, against frames.py (add_hinge about z, uy fixed). FFR 'cubic': 1e-9 of the
    largest displacement on 2 elements per member (the hinge axis follows the section's
    turn: tied to the column's r_z alone, the torque sheared the column's end section and
    the error grew with the mesh, 1.8e-4 on 2 elements, 1.4e-3 on 16). 'nonlinear': its
    deviation is proportional to the load (geometric nonlinearity), so the extrapolation to
    zero load from loads 1e-2 and 1e-3 of the FFR one meets frames.py to 1e-8."""
    h, length = 1.5, 2.0
    force = np.array([300.0, -500.0, 200.0])
    frame = frames.Frame()
    column = _frame_line(frame, (0, 0, 0), (0, h, 0), 2, (1, 0, 0))
    arm = _frame_line(frame, (0, h, 0), (length, h, 0), 2, (0, 1, 0))
    frame.fix(column[0])
    frame.add_hinge(column[-1], arm[0], axis=(0, 0, 1))
    frame.fix(arm[-1], ["uy"])
    frame.add_nodal_load(arm[-1], force=force)
    reference = frame.solve_static().displacements[arm[-1], :3]
    scale = np.abs(reference).max()
    if formulation == "ffr":
        np.testing.assert_allclose(_hinged_corner("ffr", 1.0), reference, rtol=0,
                                   atol=1e-9 * scale)
        return
    big, small = _hinged_corner("nonlinear", 1e-2), _hinged_corner("nonlinear", 1e-3)
    assert np.abs(big / 1e-2 - reference).max() < 1e-4 * scale
    np.testing.assert_allclose((1e4 * small - 1e2 * big) / 9, reference, rtol=0,
                               atol=1e-8 * scale)


def test_spherical_joint_between_two_cantilevers():
    """Two cantilevers clamped at x = 0 and x = 3.5 m meet at x = 1.5 m in a 'spherical'
    joint (forces pass, moments do not). A 3D force and a torque about x (a dead moment of
    50 N m) at A's end, the joint: displacements of A's midpoint and of the joint and the
    twist of A's end against frames.py (add_hinge without an axis) to 1e-9 (FFR 'cubic';
    the twist is 1e-4 rad, so second-order terms stay below 1e-8), and A alone twists:
    T a / (G J) with J the Saint-Venant constant."""
    a, b = 1.5, 2.0
    force, torque = np.array([60.0, -900.0, 400.0]), 50.0
    s = System("spherical")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("A", material=steel, start=(0, 0, 0), end=(a, 0, 0), nodes=3, section=SECTION,
           height_axis=(0, 1, 0), bending="cubic")
    s.beam("B", material=steel, start=(a, 0, 0), end=(a + b, 0, 0), nodes=3, section=SECTION,
           height_axis=(0, 1, 0), bending="cubic")
    s.joint("clamp A", "weld", "ground", "A", point=(0, 0, 0))
    s.joint("clamp B", "weld", "ground", "B", point=(a + b, 0, 0))
    s.joint("ball", "spherical", "A", "B", point=(a, 0, 0))
    s.load("F", "force", body="A", point=(a, 0, 0), vector=force)
    s.load("T", "moment", body="A", point=(a, 0, 0), vector=(torque, 0, 0))
    model = s.assemble()
    try:
        q = model.expand(solve_newton(model, tol=1e-12).e)
    finally:
        model.close()
    node = lambda k: q[12 * k: 12 * k + 12].reshape(4, 3)   # noqa: E731  (body A comes first)
    twist = [np.arctan2(node(2)[2, 2], node(2)[2, 1]),        # r_y turns towards z
             np.arctan2(-node(2)[3, 1], node(2)[3, 2])]       # r_z towards -y
    frame = frames.Frame()
    na = _frame_line(frame, (0, 0, 0), (a, 0, 0), 2, (0, 1, 0))
    nb = _frame_line(frame, (a, 0, 0), (a + b, 0, 0), 2, (0, 1, 0))
    frame.fix(na[0])
    frame.fix(nb[-1])
    frame.add_hinge(na[-1], nb[0], axis=None)
    frame.add_nodal_load(na[-1], force=force, moment=(torque, 0, 0))
    u = frame.solve_static().displacements
    scale = np.abs(u[:, :3]).max()
    np.testing.assert_allclose(node(1)[0] - (a / 2, 0, 0), u[na[1], :3], atol=1e-9 * scale, rtol=0)
    np.testing.assert_allclose(node(2)[0] - (a, 0, 0), u[na[2], :3], atol=1e-9 * scale, rtol=0)
    np.testing.assert_allclose(twist, u[na[2], 3], rtol=1e-7)
    assert twist[0] == pytest.approx(torque * a / (G * SECTION.torsion_constant), rel=1e-7)


def _simply_supported(length: float, nodes: int) -> dict[str, np.ndarray]:
    s = System("simply supported")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("beam", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=nodes,
           section=SECTION, height_axis=(0, 1, 0), bending="cubic")
    s.joint("pin", "fix", "ground", "beam", point=(0, 0, 0))
    s.joint("roller y", "fix", "ground", "beam", point=(length, 0, 0), axis=(0, 1, 0))
    s.joint("roller z", "fix", "ground", "beam", point=(length, 0, 0), axis=(0, 0, 1))
    s.joint("twist", "fix", "ground", "beam", point=(0, 0, 0), vector="r_z", axis=(0, 1, 0))
    s.load("g", "gravity", vector=(0, -9.81, 0))
    s.probe("mid", "beam", (length / 2, 0, 0))
    s.probe("end", "beam", (length, 0, 0))
    return _solve_probes(s)


def test_fix_supports_simply_supported_beam():
    """A simply supported beam made of 'fix' joints: a pin ('fix' of r, all components), a
    roller ('fix' of r along y and along z) and a twist stop ('fix' of r_z along y) under its
    own weight, FFR 'cubic': the mid-span deflection converges at order 2 in the shear part
    (-4/3 of it over the number of elements squared, observed), so the Richardson
    extrapolation of 4 and 8 elements equals 5 q L^4/(384 E I_h) + q L^2/(8 G A)
    (beam_formulas.simply_supported_uniform_load) to 1e-9, and the roller end does not
    move along y; a clamp made of 'fix' joints (r, r_y, r_z held) gives the weld's
    cantilever (tip force: P L^3/(3 E I_h) + P L/(G A), to 1e-9)."""
    length = 3.0
    q = RHO * AREA * 9.81
    expected = bf.simply_supported_uniform_load(-q, length, E * I_H, G * AREA)
    coarse, fine = _simply_supported(length, 5), _simply_supported(length, 9)
    assert (4 * fine["mid"][1] - coarse["mid"][1]) / 3 == pytest.approx(expected, rel=1e-9)
    assert abs(fine["mid"][1] / expected - 1) < 1e-4
    assert abs(fine["end"][1]) < 1e-12
    tips = []
    for clamp in ("weld", "fix"):
        c = System(clamp)
        steel = c.material("steel", youngs_modulus=E, density=RHO)
        c.beam("beam", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=3,
               section=SECTION, height_axis=(0, 1, 0), bending="cubic")
        if clamp == "weld":
            c.joint("clamp", "weld", "ground", "beam", point=(0, 0, 0))
        else:
            for vector in ("r", "r_y", "r_z"):
                c.joint(f"clamp {vector}", "fix", "ground", "beam", point=(0, 0, 0),
                        vector=vector)
        c.load("F", "force", body="beam", point=(length, 0, 0), vector=(20.0, -300.0, 100.0))
        c.probe("tip", "beam", (length, 0, 0))
        tips.append(_solve_probes(c)["tip"])
    np.testing.assert_allclose(tips[1], tips[0], rtol=1e-12, atol=1e-18)
    assert tips[0][1] == pytest.approx(bf.cantilever_tip_load(-300.0, length, E * I_H,
                                                              G * AREA)[0], rel=1e-9)


# ------------------------------------------------------- the joint equations themselves
JOINTS = {
    "weld beams": lambda s: s.joint("j", "weld", "a", "b", point=(1, 0, 0)),
    "weld beam-body": lambda s: s.joint("j", "weld", "b", "r", point=(1, 1, 0)),
    "weld body-body": lambda s: s.joint("j", "weld", "r", "r2", point=(2.5, 0.5, 0.3)),
    "revolute beams": lambda s: s.joint("j", "revolute", "a", "b", point=(1, 0, 0),
                                        axis=(0, 0, 1)),
    "revolute body-beam": lambda s: s.joint("j", "revolute", "r", "b", point=(1, 1, 0),
                                            axis=(0, 0, 1)),
    "spherical": lambda s: s.joint("j", "spherical", "r", "a", point=(1, 0, 0)),
    "distance": lambda s: s.joint("j", "distance", "a", "r", point1=(1, 0, 0),
                                  point2=(2.2, 0.6, 0.1)),
    "distance driven": lambda s: s.joint("j", "distance", "ground", "a", point1=(0.5, -1, 0),
                                         point2=(1, 0, 0), drive="length"),
    "prescribed rotation": lambda s: s.joint("j", "prescribed", "ground", "r",
                                             point=(2.1, 0.5, 0.3), pivot=(0, 0, 0),
                                             axis=(0, 0, 1), drive="angle"),
    "prescribed translation": lambda s: s.joint("j", "prescribed", "ground", "r",
                                                point=(2.1, 0.5, 0.3), axis=(0, 1, 0),
                                                drive="angle"),
    "fix": lambda s: s.joint("j", "fix", "ground", "a", point=(0, 0, 0), vector="r_y"),
    "fix along axis": lambda s: s.joint("j", "fix", "ground", "a", point=(0, 0, 0),
                                        axis=(0, 1, 1)),
    "arm": lambda s: s.joint("j", "arm", "ground", "a", point=(0, 0, 0), pivot=(0, -0.5, 0),
                             axis=(0, 0, 1)),
    "hub beam": lambda s: s.joint("j", "hub", "ground", "a", point=(0, 0, 0), pivot=(0, 0, 0),
                                  axis=(0, 0, 1), drive="angle"),
    "hub body": lambda s: s.joint("j", "hub", "ground", "r", point=(2, 0.5, 0.3),
                                  pivot=(0, 0, 0), axis=(0, 0, 1), drive="angle"),
    # issue 22 (tests/test_slider_joints.py checks them at large rotations)
    "prismatic beam-body": lambda s: s.joint("j", "prismatic", "b", "r", point=(1, 0.4, 0),
                                             axis=(0.6, 0.8, 0)),
    "prismatic driven": lambda s: s.joint("j", "prismatic", "ground", "a", point=(0.3, 0, 0),
                                          axis=(1, 0, 0), drive="length"),
    "cylindrical beams": lambda s: s.joint("j", "cylindrical", "a", "b", point=(1, 0, 0),
                                           axis=(0, 1, 0)),
    "universal body-beam": lambda s: s.joint("j", "universal", "r", "a", point=(0.7, 0, 0),
                                             axis=(0, 0, 1), axis2=(0, 1, 0)),
}


def _joint_system(kind: str, formulation: str) -> System:
    """Two beams meeting at a right angle at (1, 0, 0), two rigid bodies and drives; only the
    joint under test (named 'j')."""
    s = System(kind)
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.drive("angle", "spinup", omega=2.0, period=0.5, start=0.1)
    s.drive("length", "sine", amplitude=0.1, frequency=1.0, offset=np.sqrt(1.25), ramp=0.2)
    s.beam("a", material=steel, start=(0, 0, 0), end=(1, 0, 0), nodes=3, section=SECTION,
           height_axis=(0, 1, 0), formulation=formulation, bending="cubic")
    s.beam("b", material=steel, start=(1, 0, 0), end=(1, 1, 0), nodes=3, section=SECTION,
           height_axis=(-1, 0, 0), formulation=formulation, bending="cubic")
    s.rigid_body("r", mass=2.0, inertia=(0.2, 0.25, 0.3, 0.01, 0.0, 0.02), position=(2, 0.5, 0.3))
    s.rigid_body("r2", mass=1.0, inertia=(0.1, 0.1, 0.1, 0, 0, 0), position=(3, 0.5, 0.3))
    JOINTS[kind](s)
    return s


def _joint_rows(model) -> list[int]:
    return [i for i, name in enumerate(model.constraints.names) if name.startswith("j")]


@pytest.mark.parametrize("formulation", ["ffr", "nonlinear"])
@pytest.mark.parametrize("kind", sorted(JOINTS))
def test_joint_residual_and_jacobian(kind, formulation):
    """Every joint type, kept with multipliers (linear_joints='multipliers'): its equations
    vanish in the initial configuration (at t = 0), and at a random state (e0 + 0.05 N(0, 1),
    t = 0.37 s) the gradient rows equal central differences of the values (step 1e-6; the
    equations are at most quadratic, so the differences are exact to rounding: 1e-7 of the
    largest entry); Phi_t and Phi_tt equal central differences in time, and gamma the
    second derivative along the path (e + s e_dot, t + s): d2 Phi/ds2 = -gamma."""
    model = _joint_system(kind, formulation).assemble(linear_joints="multipliers",
                                                      check_frames=False)
    try:
        cs = model.constraints
        rows = _joint_rows(model)
        assert rows, "the joint has no equation"
        values0 = cs.evaluate(model.e0, 0.0)[0][rows]
        assert np.abs(values0).max() <= 1e-12
        rng = np.random.default_rng(12)
        e = model.e0 + 0.05 * rng.standard_normal(model.ndof)
        e_dot = rng.standard_normal(model.ndof)
        t, h = 0.37, 1e-6
        jac = cs.gradient_rows(e, model.ndof, t)[rows]
        fd = np.zeros_like(jac)
        for k in range(model.ndof):
            step = np.zeros(model.ndof)
            step[k] = h
            fd[:, k] = (cs.evaluate(e + step, t)[0][rows] - cs.evaluate(e - step, t)[0][rows]) \
                / (2 * h)
        assert np.abs(jac - fd).max() <= 1e-7 * max(np.abs(jac).max(), 1.0)
        _, _, _, phi_t, phi_tt, gamma = cs.evaluate(e, t, e_dot)
        dt = 1e-4
        value = lambda ee, tt: cs.evaluate(ee, tt)[0][rows]   # noqa: E731
        np.testing.assert_allclose(phi_t[rows], (value(e, t + dt) - value(e, t - dt)) / (2 * dt),
                                   rtol=0, atol=1e-6)
        np.testing.assert_allclose(phi_tt[rows], (value(e, t + dt) - 2 * value(e, t)
                                                  + value(e, t - dt)) / dt**2, rtol=0, atol=1e-4)
        path = (value(e + dt * e_dot, t + dt) - 2 * value(e, t) + value(e - dt * e_dot, t - dt)) \
            / dt**2
        np.testing.assert_allclose(-gamma[rows], path, rtol=0,
                                   atol=1e-4 * max(1.0, np.abs(gamma).max()))
    finally:
        model.close()


@pytest.mark.parametrize("formulation", ["ffr", "nonlinear"])
@pytest.mark.parametrize("kind", sorted(JOINTS))
def test_eliminated_joints_hold_for_any_coordinates(kind, formulation):
    """With the linear joint equations eliminated (q = B e + q0), every linear equation of the
    joint holds for any independent coordinates e (random, 1e-10 of the coordinate scale),
    and the multiplier constraints that remain vanish at e0."""
    s = _joint_system(kind, formulation)
    model = s.assemble(linear_joints="eliminate", check_frames=False)
    try:
        equations = [eq for eq in s.joints["j"].equations(model.q0)
                     if isinstance(eq, LinearEquation)]
        rng = np.random.default_rng(3)
        q = model.expand(model.e0 + rng.standard_normal(model.ndof))
        for eq in equations:
            assert abs(eq.expr.value(q)) <= 1e-10 * max(1.0, np.abs(q).max()), eq.name
        rows = _joint_rows(model)
        if rows:
            assert np.abs(model.constraints.evaluate(model.e0, 0.0)[0][rows]).max() <= 1e-12
        assert model.ndof < model.nfull or not equations
    finally:
        model.close()


@pytest.mark.parametrize("linear_joints", ["eliminate", "multipliers"])
def test_redundant_planar_revolute_is_dropped_and_reported(linear_joints):
    """A planar rigid body (normal z) hinged to the ground by a 'revolute' about z: the
    revolute's axis equations repeat the planar guide. The model assembles, the dropped
    equations are named in model.notes, the constraint gradients kept have full row rank,
    and exactly one degree of freedom remains (ndof minus the kept constraints = 1: the
    pendulum's angle)."""
    s = System("redundant pendulum")
    s.rigid_body("pendulum", mass=2.0, inertia=(0.1, 0.1, 0.1, 0, 0, 0), position=(0, -0.5, 0),
                 planar=True, plane_normal=(0, 0, 1))
    s.joint("pin", "revolute", "ground", "pendulum", point=(0, 0, 0), axis=(0, 0, 1))
    model = s.assemble(linear_joints=linear_joints)
    try:
        dropped = [n for n in model.notes if n.startswith("redundant joint equation dropped")]
        assert any("pin" in n or "pendulum: planar" in n for n in dropped), model.notes
        phi_e = model.constraints.gradient_rows(model.e0, model.ndof)
        assert np.linalg.matrix_rank(phi_e) == len(phi_e)
        assert model.ndof - len(phi_e) == 1
    finally:
        model.close()


@pytest.mark.parametrize("linear_joints", ["eliminate", "multipliers"])
def test_two_welds_of_the_same_beams(linear_joints):
    """Two beams welded twice at the same point (once in each order): the second weld's
    equations are dropped as redundant and named in model.notes, and the two beams bend as
    one 2 m cantilever under their own weight: q L^4/(8 E I_h) + q L^2/(2 G A)
    (beam_formulas.cantilever_uniform_load; FFR 'cubic' is exact for it) to 1e-9."""
    s = System("two welds")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("a", material=steel, start=(0, 0, 0), end=(1, 0, 0), nodes=3, section=SECTION,
           height_axis=(0, 1, 0), bending="cubic")
    s.beam("b", material=steel, start=(1, 0, 0), end=(2, 0, 0), nodes=3, section=SECTION,
           height_axis=(0, 1, 0), bending="cubic")
    s.joint("root", "weld", "ground", "a", point=(0, 0, 0))
    s.joint("weld 1", "weld", "a", "b", point=(1, 0, 0))
    s.joint("weld 2", "weld", "b", "a", point=(1, 0, 0))
    s.load("g", "gravity", vector=(0, -9.81, 0))
    s.probe("tip", "b", (2, 0, 0))
    model = s.assemble(linear_joints=linear_joints)
    try:
        dropped = [n for n in model.notes if n.startswith("redundant joint equation dropped")]
        assert sum("weld 2" in n for n in dropped) == 9, model.notes   # position, r_y, r_z
        phi_e = model.constraints.gradient_rows(model.e0, model.ndof)
        if len(phi_e):
            assert np.linalg.matrix_rank(phi_e) == len(phi_e)
        tip = model.probe_positions(solve_newton(model, tol=1e-12).e)["tip"] - (2, 0, 0)
    finally:
        model.close()
    expected, _ = bf.cantilever_uniform_load(-RHO * AREA * 9.81, 2.0, E * I_H, G * AREA)
    assert tip[1] == pytest.approx(expected, rel=1e-9)


# ------------------------------------------------------------------ errors and effects
def _cantilever(effects=None, with_force=True):
    s = System("effects")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("beam", material=steel, start=(0, 0, 0), end=(2, 0, 0), nodes=3, section=SECTION,
           height_axis=(0, 1, 0), bending="cubic")
    s.joint("root", "weld", "ground", "beam", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -9.81, 0))
    if with_force:
        s.load("push", "force", body="beam", point=(2, 0, 0), vector=(0, 5000.0, 0))
    s.probe("tip", "beam", (2, 0, 0))
    model = s.assemble(effects=effects)
    try:
        tip = model.probe_positions(solve_newton(model).e)["tip"]
        return tip, model
    finally:
        model.close()


def test_load_of_an_unlisted_effect_is_not_applied():
    """A force of the effect 'point_loads' with effects = ('gravity',): the solution equals the
    one without the force (bitwise), the 'point_loads' counter is 0 while 'gravity' counted
    its load, and a warning names the load and its effect. With both effects listed the
    force acts (the tip moves up by about 5000 L^3/(3 E I_h))."""
    without, _ = _cantilever(effects=("gravity",), with_force=False)
    off, model = _cantilever(effects=("gravity",))
    np.testing.assert_array_equal(off, without)
    assert model.counters["point_loads"] == 0
    assert model.counters["gravity"] == 1
    assert any("'push'" in w and "'point_loads'" in w for w in model.warnings), model.warnings
    on, model_on = _cantilever(effects=("gravity", "point_loads"))
    assert model_on.counters["point_loads"] == 1
    assert (on - without)[1] == pytest.approx(
        bf.cantilever_tip_load(5000.0, 2.0, E * I_H, G * AREA)[0], rel=1e-9)


def _base():
    s = System("errors")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("beam", material=steel, start=(0, 0, 0), end=(2, 0, 0), nodes=3, section=SECTION)
    s.drive("spin", "constant", value=0.0)
    return s


def test_unknown_body_in_a_joint_is_named():
    """A joint naming a body that does not exist: InputError naming the joint and the body."""
    with pytest.raises(InputError, match=r"joint 'hinge'.*unknown body 'bom'"):
        _base().joint("hinge", "revolute", "ground", "bom", point=(0, 0, 0), axis=(0, 0, 1))


def test_unknown_drive_is_named():
    """A joint naming a drive that does not exist: InputError naming the joint and the drive."""
    with pytest.raises(InputError, match=r"joint 'turn'.*unknown drive 'spn'"):
        _base().joint("turn", "hub", "ground", "beam", point=(0, 0, 0), pivot=(0, 0, 0),
                      axis=(0, 0, 1), drive="spn")


@pytest.mark.parametrize("what", ["body", "joint", "drive", "material", "load", "probe"])
def test_duplicate_names_are_named(what):
    """Defining an item twice (same kind, same name): InputError naming the item."""
    s = _base()
    calls = {
        "body": lambda: s.rigid_body("beam", mass=1.0, inertia=(1, 1, 1, 0, 0, 0),
                                     position=(0, 0, 0)),
        "joint": lambda: s.joint("clamp", "weld", "ground", "beam", point=(0, 0, 0)),
        "drive": lambda: s.drive("spin", "constant", value=1.0),
        "material": lambda: s.material("steel", youngs_modulus=E, density=RHO),
        "load": lambda: s.load("w", "gravity", vector=(0, 0, -9.81)),
        "probe": lambda: s.probe("tip", "beam", (2, 0, 0)),
    }
    if what in ("joint", "load", "probe"):
        calls[what]()
    with pytest.raises(InputError, match=rf"{what if what != 'body' else 'body'} "
                                         rf"'(beam|clamp|spin|steel|w|tip)' is defined twice"):
        calls[what]()


def test_joint_point_off_the_body_is_named():
    """A weld at a point beyond the beam's end (x = 2.5 m; the beam ends at 2 m): InputError
    naming the joint and the beam (SPEC 8.1 allows any material point, between nodes too)."""
    s = _base()
    s.joint("clamp", "weld", "ground", "beam", point=(2.5, 0, 0))
    with pytest.raises(InputError, match=r"joint 'clamp'.*not a material point of beam 'beam'"):
        s.assemble()


def test_driven_coordinate_held_by_a_planar_guide_is_refused_by_name():
    """A 'prescribed' translation along z of a rigid body kept in the x-y plane (planar,
    normal z): after elimination the driven equation has no coordinate left and the drive
    would move it, so the assembly raises an InputError naming the joint's equation and the
    drive. The same body turned about z by a 'hub' assembles: the hub's out-of-plane
    equations hold for every angle and are noted as redundant."""
    s = System("contradiction")
    s.drive("lift", "sine", amplitude=0.1, frequency=1.0)
    s.rigid_body("body", mass=1.0, inertia=(1, 1, 1, 0, 0, 0), position=(0, 0, 0), planar=True,
                 plane_normal=(0, 0, 1))
    s.joint("jack", "prescribed", "ground", "body", point=(0, 0, 0), axis=(0, 0, 1),
            drive="lift")
    with pytest.raises(InputError, match=r"jack: z\(t\): .*\b(hold|held)\b"):
        s.assemble()
    s = System("hub on a planar body")
    s.drive("spin", "spinup", omega=1.0, period=1.0)
    s.rigid_body("body", mass=1.0, inertia=(1, 1, 1, 0, 0, 0), position=(0.5, 0, 0),
                 planar=True, plane_normal=(0, 0, 1))
    s.joint("motor", "hub", "ground", "body", point=(0, 0, 0), pivot=(0, 0, 0), axis=(0, 0, 1),
            drive="spin")
    model = s.assemble()
    try:
        notes = " | ".join(model.notes)
        assert "motor: position z(t) (satisfied identically)" in notes
        phi_e = model.constraints.gradient_rows(model.e0, model.ndof)
        assert model.ndof - np.linalg.matrix_rank(phi_e) == 0   # fully driven
    finally:
        model.close()
