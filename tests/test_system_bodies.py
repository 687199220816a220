"""Verification of the general-system API (issue 12): sections, beams, rigid bodies carried by
beams, and the loads, each against an independent reference.

References (tests/reference, written without looking at ancfdrv):

* ``beam_formulas``: closed forms of the Timoshenko cantilever (shear coefficient 1, the
  project's beams, SPEC / docs/theory.md sections 2 and 12);
* ``frames``: a linear 3D frame FE code (Timoshenko elements exact for nodal loads, rigid
  bodies with the exact 6 x 6 small-motion mass about a node);
* textbook section formulas written out below; virtual-work identities (the generalized
  force of a load does the load's work in every rigid motion).

Every number asserted says in its test where it comes from. Conventions: a beam's section
height runs along its ``height_axis`` (the director r_y), its width along r_z; I_h = int y^2 dA
(bending along the height), I_w = int z^2 dA (bending along the width); G = E / 2 (nu = 0).
"""
from __future__ import annotations

import functools
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from ancfdrv import Box, Circle, Rectangle, System, Tube
from ancfdrv.solvers.static import solve_newton
from ancfdrv.system import Beam, Plate, RigidBody

sys.path.insert(0, str(Path(__file__).resolve().parent))
from reference import beam_formulas as bf  # noqa: E402  (tests/reference: never used by a run)
from reference import frames  # noqa: E402

E, RHO, G = 2.1e11, 7850.0, 2.1e11 / 2.0
GRAVITY = 9.81


# ------------------------------------------------------------------------------ sections
def _rect(w: float, h: float) -> tuple[float, float, float]:
    """A, I_h = w h^3/12, I_w = h w^3/12 of a solid w x h rectangle."""
    return w * h, w * h**3 / 12.0, h * w**3 / 12.0


def _textbook(kind: str) -> tuple[object, float, float, float]:
    """(section, A, I_h, I_w) from the textbook formulas: box = outer minus inner rectangle,
    tube = pi (D^2 - d^2)/4 and pi (D^4 - d^4)/64, circle pi D^2/4 and pi D^4/64."""
    if kind == "rectangle":
        return (Rectangle(0.05, 0.1), *_rect(0.05, 0.1))
    if kind == "box":
        w, h, t = 0.08, 0.12, 0.01
        outer, inner = _rect(w, h), _rect(w - 2 * t, h - 2 * t)
        return (Box(w, h, t), *(a - b for a, b in zip(outer, inner)))
    if kind == "tube":
        d_out, t = 0.1, 0.01
        d_in = d_out - 2 * t
        i = np.pi * (d_out**4 - d_in**4) / 64.0
        return Tube(d_out, t), np.pi * (d_out**2 - d_in**2) / 4.0, i, i
    d = 0.06
    return Circle(d), np.pi * d**2 / 4.0, np.pi * d**4 / 64.0, np.pi * d**4 / 64.0


KINDS = ("rectangle", "box", "tube", "circle")
VARIANTS = [(f, b) for f in ("ffr", "nonlinear") for b in ("cubic", "continuum")]


@pytest.mark.parametrize("kind", KINDS)
def test_section_properties_match_textbook(kind):
    """A, I_h = int y^2 dA, I_w = int z^2 dA and the polar moment I_h + I_w of the kernel's
    quadrature equal the textbook formulas (to rounding: every rule integrates second
    moments exactly)."""
    section, area, i_h, i_w = _textbook(kind)
    data = section.data
    assert data.area == pytest.approx(area, rel=1e-12)
    assert data.inertia_z == pytest.approx(i_h, rel=1e-12)   # int y^2 dA, y along the height
    assert data.inertia_y == pytest.approx(i_w, rel=1e-12)   # int z^2 dA, z along the width
    assert data.polar == pytest.approx(i_h + i_w, rel=1e-12)
    assert np.sum(data.weights) == pytest.approx(area, rel=1e-12)


def _cantilever(section, formulation: str, bending: str, nodes: int, length: float, *,
                force=None, gravity=None):
    """Tip displacement, total mass u^T M u (u: unit rigid translation along x) and the
    resultant of the gravity loads of a cantilever along x, height along y, clamped by a
    weld to the ground."""
    s = System("cantilever")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("beam", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=nodes,
           section=section, height_axis=(0, 1, 0), formulation=formulation, bending=bending)
    s.joint("root", "weld", "ground", "beam", point=(0, 0, 0))
    if force is not None:
        s.load("tip force", "force", body="beam", point=(length, 0, 0), vector=force)
    if gravity is not None:
        s.load("weight", "gravity", vector=gravity)
    s.probe("tip", "beam", (length, 0, 0))
    model = s.assemble()
    try:
        result = solve_newton(model, tol=1e-12)
        tip = model.probe_positions(result.e)["tip"] - np.array([length, 0.0, 0.0])
        u = np.zeros(model.ndof)
        u[model.bodies[0].first + 12 * np.arange(nodes)] = 1.0   # r_1 of every node
        mass = float(u @ (model.mass_matrix() @ u))
        weight = model.constant_force().reshape(-1, 4, 3)[:, 0, :].sum(axis=0)
    finally:
        model.close()
    return tip, mass, weight


@pytest.mark.parametrize("formulation,bending", VARIANTS)
@pytest.mark.parametrize("kind", KINDS)
def test_cantilever_tip_force(kind, formulation, bending):
    """Tip deflection under a 1 N tip force along the section height against the Timoshenko
    closed form P L^3/(3 E I_h) + P L/(G A) (beam_formulas.cantilever_tip_load).

    'cubic': 2 elements reproduce it to 1e-9 (the structural element is exact for a tip
    force; 'nonlinear' adds the geometric nonlinearity of a 1e-6 deflection ratio, < 1e-10).
    'continuum': second-order convergence (docs/theory.md section 2), so the error of 4
    elements is 4 times that of 8 (observed order 2), and the Richardson extrapolation
    (4 w_8 - w_4)/3 meets the closed form to 1e-7; 8 elements are within 0.5 %."""
    section, area, i_h, _ = _textbook(kind)
    length, force = 2.0, 1.0
    expected, _ = bf.cantilever_tip_load(force, length, E * i_h, G * area)
    if bending == "cubic":
        tip, _, _ = _cantilever(section, formulation, bending, 3, length, force=(0, force, 0))
        assert tip[1] == pytest.approx(expected, rel=1e-9)
        assert abs(tip[2]) <= 1e-12 * expected
        return
    w4 = _cantilever(section, formulation, bending, 5, length, force=(0, force, 0))[0][1]
    w8 = _cantilever(section, formulation, bending, 9, length, force=(0, force, 0))[0][1]
    assert (w4 - expected) / (w8 - expected) == pytest.approx(4.0, rel=1e-3)
    assert abs(w8 / expected - 1.0) < 5e-3
    assert (4.0 * w8 - w4) / 3.0 == pytest.approx(expected, rel=1e-7)


@pytest.mark.parametrize("formulation,bending", VARIANTS)
@pytest.mark.parametrize("kind", KINDS)
def test_cantilever_own_weight_and_mass(kind, formulation, bending):
    """A 1 m cantilever under its own weight along minus its width direction (-z).

    * total mass u^T M u = rho A L and the gravity resultant = rho A L g (exact);
    * tip deflection against q L^4/(8 E I_w) + q L^2/(2 G A) with q = rho A g
      (beam_formulas.cantilever_uniform_load): 'cubic' on 2 elements to 1e-9 (FFR; the
      'nonlinear' beam adds its geometric nonlinearity, of the order (w/L)^2 < 1e-7, so
      1e-6), 'continuum' by the same order-2 Richardson argument as the tip force."""
    section, area, _, i_w = _textbook(kind)
    length = 1.0
    q = RHO * area * GRAVITY
    expected, _ = bf.cantilever_uniform_load(-q, length, E * i_w, G * area)
    tol = 1e-9 if formulation == "ffr" else 1e-6
    if bending == "cubic":
        tip, mass, weight = _cantilever(section, formulation, bending, 3, length,
                                        gravity=(0, 0, -GRAVITY))
        assert tip[2] == pytest.approx(expected, rel=tol)
    else:
        w4 = _cantilever(section, formulation, bending, 5, length, gravity=(0, 0, -GRAVITY))[0][2]
        tip, mass, weight = _cantilever(section, formulation, bending, 9, length,
                                        gravity=(0, 0, -GRAVITY))
        w8 = tip[2]
        assert (w4 - expected) / (w8 - expected) == pytest.approx(4.0, rel=2e-3)
        assert (4.0 * w8 - w4) / 3.0 == pytest.approx(expected, rel=max(tol, 1e-7))
    assert abs(tip[1]) <= 1e-9 * abs(expected)
    assert mass == pytest.approx(RHO * area * length, rel=1e-12)
    np.testing.assert_allclose(weight, [0.0, 0.0, -q * length], rtol=1e-12, atol=1e-12 * q)


# ------------------------------------------------------------------ tip body frequencies
TIP_BODY = dict(length=2.0, mass=20.0, inertia=np.diag([0.3, 0.2, 0.4]),
                offset=np.array([0.15, 0.05, 0.0]))


@functools.lru_cache(maxsize=1)
def _frame_tip_body_frequencies() -> np.ndarray:
    """frames.py: 40 Timoshenko elements (rotary inertia on; 80 change mode 4 by 1.4e-6),
    clamped, the rigid body of TIP_BODY at the tip with its exact small-motion mass about
    the tip node: the lowest four angular frequencies."""
    frame = frames.Frame()
    nodes = frame.add_beam_line((0, 0, 0), (TIP_BODY["length"], 0, 0), 40, E, G,
                                frames.rectangle(0.05, 0.1), rho=RHO, theory="timoshenko",
                                height_axis=(0, 1, 0))
    frame.fix(nodes[0])
    frame.add_rigid_body(nodes[-1], TIP_BODY["mass"], TIP_BODY["inertia"], TIP_BODY["offset"])
    return frame.solve_modes(4).omega


def _linearized_frequencies(model, n_modes: int) -> np.ndarray:
    """Lowest angular frequencies of the linearized model about e0: eigh of the stiffness and
    mass matrices projected on the null space of the constraint gradients."""
    k = model.stiffness_matrix().toarray()
    m = model.mass_matrix().toarray()
    phi_e = model.constraints.gradient_rows(model.e0, model.ndof)
    basis = scipy.linalg.null_space(phi_e) if len(phi_e) else np.eye(model.ndof)
    w2 = scipy.linalg.eigh(basis.T @ k @ basis, basis.T @ m @ basis, eigvals_only=True,
                           subset_by_index=[0, n_modes - 1])
    return np.sqrt(w2)


@pytest.mark.parametrize("bending,nodes", [("cubic", 9), ("continuum", 9)])
@pytest.mark.parametrize("formulation", ["ffr", "nonlinear"])
@pytest.mark.parametrize("beam_first", [True, False])
def test_tip_body_frequencies(formulation, bending, nodes, beam_first):
    """First four natural frequencies of a 2 m cantilever carrying a welded rigid body (20 kg,
    centre of mass offset (0.15, 0.05, 0) m from the tip, inertia diag(0.3, 0.2, 0.4) kg m^2)
    from the linearized model (mass matrix, stiffness matrix, null space of the constraints)
    against frames.py (40 Timoshenko elements, exact rigid-body mass). Both orders of the
    weld's bodies give the same structure.

    'cubic', 8 elements: modes 1-2 within 1e-5, modes 3-4 within 3e-4 (the element
    converges at order 2 in frequency; observed 1e-6 / 7e-5 here). 'continuum': order 2, so
    the Richardson extrapolation of 8 and 16 elements meets modes 1-2 within 2e-5."""
    section = Rectangle(0.05, 0.1)
    length, mass, inertia, offset = (TIP_BODY[k] for k in ("length", "mass", "inertia",
                                                           "offset"))
    expected = _frame_tip_body_frequencies()

    def frequencies(n: int) -> np.ndarray:
        s = System("tip body")
        steel = s.material("steel", youngs_modulus=E, density=RHO)
        s.beam("beam", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=n,
               section=section, height_axis=(0, 1, 0), formulation=formulation, bending=bending)
        s.rigid_body("body", mass=mass, inertia=inertia, position=(length + offset[0],
                                                                   offset[1], offset[2]))
        s.joint("root", "weld", "ground", "beam", point=(0, 0, 0))
        pair = ("beam", "body") if beam_first else ("body", "beam")
        s.joint("tip", "weld", *pair, point=(length, 0, 0))
        model = s.assemble()
        try:
            return _linearized_frequencies(model, 4)
        finally:
            model.close()

    if bending == "cubic":
        rel = frequencies(nodes) / expected - 1.0
        assert np.all(np.abs(rel[:2]) < 1e-5), rel
        assert np.all(np.abs(rel[2:]) < 3e-4), rel
    else:
        coarse, fine = frequencies(nodes), frequencies(2 * nodes - 1)
        extrapolated = (4.0 * fine - coarse) / 3.0
        np.testing.assert_allclose(extrapolated[:2], expected[:2], rtol=2e-5)


# -------------------------------------------------------------------------------- loads
def _resultant_and_moment(model, force: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Resultant and moment about the origin of a generalized force in full coordinates, by
    virtual work: a rigid translation u moves every position vector r by u and no gradient,
    a small rotation w moves every nodal 3-vector v (positions and gradients) by w x v, so
    F = sum over positions of Q_r and M = sum over all nodal 3-vectors of v x Q_v."""
    q0 = model.q0
    total, moment = np.zeros(3), np.zeros(3)
    for body in model.bodies:
        per_node = 9 if isinstance(body, Plate) else 12
        block = slice(body.first, body.first + body.ncoordinates)
        f = force[block].reshape(-1, per_node // 3, 3)
        v = q0[block].reshape(-1, per_node // 3, 3)
        total += f[:, 0, :].sum(axis=0)
        moment += np.cross(v, f).sum(axis=(0, 1))
    return total, moment


def test_point_forces_resultant_and_moment():
    """Dead forces at material points that are not nodes (inside a beam element, off its
    axis; on a plate's mid-surface between nodes; on a rigid body away from its centre): the
    generalized force's resultant is F and its moment about the origin p x F (virtual work
    in rigid motions), for each load alone (the loads add up)."""
    s = System("point forces")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("beam", material=steel, start=(0, 0, 0), end=(2, 0, 0), nodes=3,
           section=Rectangle(0.05, 0.1), height_axis=(0, 1, 0))
    s.plate("plate", material=steel, thickness=0.01, corner=(0, 1, 0), edge_x=(1, 0, 0),
            edge_y=(0, 0, 0.6), nx=2, ny=2)
    s.rigid_body("body", mass=3.0, inertia=(0.2, 0.25, 0.3, 0, 0, 0), position=(0, -2, 0))
    loads = {"beam": ((0.7, 0.03, -0.01), (3.0, -5.0, 2.0)),
             "plate": ((0.35, 1.0, 0.2), (-1.0, 4.0, 6.0)),
             "body": ((0.4, -1.8, 0.3), (2.0, 1.0, -7.0))}
    for body, (point, vector) in loads.items():
        s.load(f"on {body}", "force", body=body, point=point, vector=vector)
    model = s.assemble()
    try:
        force, moment = _resultant_and_moment(model, model.constant_force())
    finally:
        model.close()
    points = np.array([p for p, _ in loads.values()])
    vectors = np.array([v for _, v in loads.values()])
    np.testing.assert_allclose(force, vectors.sum(axis=0), rtol=0, atol=1e-12)
    np.testing.assert_allclose(moment, np.cross(points, vectors).sum(axis=0), rtol=0, atol=1e-12)


@pytest.mark.parametrize("formulation,bending", VARIANTS)
def test_dead_moment_tip_rotation(formulation, bending):
    """A dead moment M = 100 N m about +z on the tip section of a 2 m cantilever (height
    along y): the section turns by M L / (E I_h) (beam_formulas.cantilever_end_moment; pure
    bending is exact for both elements, docs/theory.md sections 2 and 12) and the tip moves
    by M L^2 / (2 E I_h). The rotation is read from the tip director r_y = (-sin t, cos t, 0).
    Tolerance 1e-6: the rotation is 2.3e-4 rad, so second-order terms are below 1e-7."""
    length, moment = 2.0, 100.0
    _, i_h, _ = _rect(0.05, 0.1)
    deflection, rotation = bf.cantilever_end_moment(moment, length, E * i_h)
    s = System("end moment")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("beam", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=5,
           section=Rectangle(0.05, 0.1), height_axis=(0, 1, 0), formulation=formulation,
           bending=bending)
    s.joint("root", "weld", "ground", "beam", point=(0, 0, 0))
    s.load("M", "moment", body="beam", point=(length, 0, 0), vector=(0, 0, moment))
    model = s.assemble()
    try:
        q = model.expand(solve_newton(model, tol=1e-12).e)
    finally:
        model.close()
    tip = q[12 * 4: 12 * 5].reshape(4, 3)
    assert np.arctan2(-tip[2, 0], tip[2, 1]) == pytest.approx(rotation, rel=1e-6)
    assert tip[0, 1] == pytest.approx(deflection, rel=1e-6)


def test_point_mass_total_mass_and_weight():
    """A 7 kg point mass at a material point inside a beam element: the total mass u^T M u
    (u: unit rigid translation) is rho A L + 7 kg along each axis, and under gravity the
    resultant load is (rho A L + 7) g with its moment about the origin that of the two
    weights at their centres of mass (the beam's at L/2, the point mass's at its point)."""
    length, point, extra = 2.0, np.array([1.3, 0.02, -0.01]), 7.0
    s = System("point mass")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("beam", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=3,
           section=Rectangle(0.05, 0.1), height_axis=(0, 1, 0))
    s.load("g", "gravity", vector=(0, -GRAVITY, 0))
    s.load("payload", "point_mass", body="beam", point=point, mass=extra)
    model = s.assemble()
    try:
        m = model.mass_matrix()
        f = model.constant_force()
    finally:
        model.close()
    beam_mass = RHO * 0.05 * 0.1 * length
    for axis in range(3):
        u = np.zeros(model.ndof)
        u[12 * np.arange(3) + axis] = 1.0
        assert float(u @ (m @ u)) == pytest.approx(beam_mass + extra, rel=1e-12)
    force, moment = _resultant_and_moment(model, f)
    weight = np.array([0.0, -GRAVITY, 0.0])
    np.testing.assert_allclose(force, (beam_mass + extra) * weight, rtol=1e-12)
    expected = np.cross([length / 2, 0, 0], beam_mass * weight) + np.cross(point, extra * weight)
    np.testing.assert_allclose(moment, expected, rtol=1e-12, atol=1e-9)


def test_pressure_on_flat_plate():
    """A pressure p = 2500 Pa on a 1.2 m x 0.8 m plate in a tilted plane: the resultant is
    p A along minus the plate's normal (edge_x x edge_y), and its moment about the origin is
    that of p A at the plate's centre (a uniform pressure)."""
    corner = np.array([0.3, -0.2, 0.5])
    edge_x = 1.2 * np.array([np.cos(0.4), 0.0, np.sin(0.4)])
    edge_y = np.array([0.0, 0.8, 0.0])
    normal = np.cross(edge_x, edge_y) / np.linalg.norm(np.cross(edge_x, edge_y))
    pressure, area = 2500.0, 1.2 * 0.8
    s = System("pressure")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.plate("plate", material=steel, thickness=0.01, corner=corner, edge_x=edge_x,
            edge_y=edge_y, nx=3, ny=2)
    s.load("p", "pressure", body="plate", value=pressure)
    model = s.assemble()
    try:
        force, moment = _resultant_and_moment(model, model.constant_force())
    finally:
        model.close()
    np.testing.assert_allclose(force, -pressure * area * normal, rtol=1e-12, atol=1e-9)
    centre = corner + 0.5 * (edge_x + edge_y)
    np.testing.assert_allclose(moment, np.cross(centre, -pressure * area * normal), rtol=1e-12,
                               atol=1e-9)


def test_gravity_on_every_body_kind():
    """Gravity on a beam (tube), a flat plate, a curved leaf, a rigid body and a point mass on
    the plate: the resultant of the generalized gravity force is the total weight
    (rho V of each flexible body + the masses) times g, and the total mass u^T M u matches."""
    g = np.array([0.0, -GRAVITY, 0.0])
    s = System("gravity")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("beam", material=steel, start=(0, 0, 0), end=(2, 0, 0), nodes=3,
           section=Tube(0.1, 0.01), height_axis=(0, 1, 0), formulation="nonlinear")
    s.plate("plate", material=steel, thickness=0.01, corner=(0, 1, 0), edge_x=(1, 0, 0),
            edge_y=(0, 0, 0.5), nx=2, ny=2)
    s.leaf("leaf", material=steel, thickness=0.008, width=0.2, arc_length=1.0, radius=2.0,
           centre=(0, 3, 0), nx=4, ny=1)
    s.rigid_body("body", mass=5.0, inertia=(0.2, 0.25, 0.3, 0, 0, 0), position=(0, -2, 0))
    s.load("g", "gravity", vector=g)
    s.load("payload", "point_mass", body="plate", point=(0.3, 1.0, 0.1), mass=2.0)
    model = s.assemble()
    try:
        force, _ = _resultant_and_moment(model, model.constant_force())
        m = model.mass_matrix()
    finally:
        model.close()
    tube = np.pi * (0.1**2 - 0.08**2) / 4.0
    total = RHO * (tube * 2.0 + 0.01 * 1.0 * 0.5 + 0.008 * 0.2 * 1.0) + 5.0 + 2.0
    np.testing.assert_allclose(force, total * g, rtol=1e-12)
    u = np.zeros(model.ndof)
    for body in model.bodies:
        per_node = 9 if isinstance(body, Plate) else 12
        if isinstance(body, (Beam, Plate)):
            u[body.first + per_node * np.arange(body.ncoordinates // per_node) + 1] = 1.0
        else:
            assert isinstance(body, RigidBody)
            u[body.first + 1] = 1.0
    assert float(u @ (m @ u)) == pytest.approx(total, rel=1e-12)


@pytest.mark.parametrize("formulation,bending", VARIANTS)
@pytest.mark.parametrize("kind", KINDS)
def test_dead_torque_twist(kind, formulation, bending):
    """A dead moment T = 10 N m about the axis of a 2 m cantilever (4 elements): the tip
    section twists by T L / (G J), J the Saint-Venant constant (before issue 20 the polar
    moment I_h + I_w), read from both directors (r_y turns towards z, r_z towards -y: the section
    turns without shearing). Tolerance 1e-7 (the twist is below 1e-4 rad). A torque applied
    to one director only sheared the section at the loaded node, an error that grew with the
    mesh (2.6e-4 on 2 elements, 1e-3 on 8)."""
    section, area, i_h, i_w = _textbook(kind)
    length, torque = 2.0, 10.0
    s = System("torque")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("beam", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=5,
           section=section, height_axis=(0, 1, 0), formulation=formulation, bending=bending)
    s.joint("root", "weld", "ground", "beam", point=(0, 0, 0))
    s.load("T", "moment", body="beam", point=(length, 0, 0), vector=(torque, 0, 0))
    model = s.assemble()
    try:
        q = model.expand(solve_newton(model, tol=1e-12).e)
    finally:
        model.close()
    tip = q[12 * 4: 12 * 5].reshape(4, 3)
    twist = [np.arctan2(tip[2, 2], tip[2, 1]), np.arctan2(-tip[3, 1], tip[3, 2])]
    np.testing.assert_allclose(twist, torque * length / (G * section.torsion_constant),
                               rtol=1e-7)
