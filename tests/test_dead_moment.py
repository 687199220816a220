"""A dead (spatially fixed) moment whose vector is not along a body axis.

Until this fix a rigid body's dead moment acted through one director's potential (the
director least parallel to the moment): its moment d x Q = M k_perp / |k_perp|^2 dropped the
component along that director and scaled up the rest (docs/theory.md section 'Dead moments
on a rigid body'). Each test checks a closed form or finite differences."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ancfdrv import Rectangle, System
from ancfdrv import kernel
from ancfdrv.codes import ENERGY_NAMES
from ancfdrv.solvers.dynamic import DynamicSettings, integrate
from ancfdrv.solvers.static import solve_newton

MOMENT = np.array([0.4, 0.3, -0.6])   # N m, along no axis of the body


def _tumble(inertia: float, t_end: float, dt: float):
    """A free rigid body with the isotropic inertia I under MOMENT from rest: Euler's
    equations give omega' = M / I (omega x I omega = 0), so it turns about the fixed axis of M
    by the angle |M| t^2 / (2 I), the rotation vector M t^2 / (2 I)."""
    s = System("tumble")
    s.rigid_body("body", mass=1.0, inertia=(inertia, inertia, inertia, 0, 0, 0),
                 position=(0, 0, 0))
    s.load("m", "moment", body="body", point=(0, 0, 0), vector=tuple(MOMENT))
    for name, point in (("o", (0, 0, 0)), ("x", (1, 0, 0)), ("y", (0, 1, 0)), ("z", (0, 0, 1))):
        s.probe(name, "body", point)
    model = s.assemble()
    chunks = []
    try:
        integrate(model, DynamicSettings.generalized_alpha(dt, t_end, rho_inf=1.0), model.e0,
                  None, sink=lambda c: chunks.append((np.array(c.probes), np.array(c.energy))),
                  progress=False)
    finally:
        model.close()
    probes = np.concatenate([c[0] for c in chunks])[-1]
    energy = np.concatenate([c[1] for c in chunks])[-1]
    frame = np.column_stack([probes[k] - probes[0] for k in (1, 2, 3)])
    return Rotation.from_matrix(frame).as_rotvec(), dict(zip(ENERGY_NAMES, energy))


def test_rigid_body_dead_moment_small_time_closed_form():
    """Unit inertia, t = 0.01 s: rotation M t^2 / 2 = (2.0, 1.5, -3.0) e-5 (before the fix
    (2.35e-5, 4e-10, -3.52e-5)); measured to 1e-15. The kinetic energy |M|^2 t^2 / 2 equals
    the moment's work (the kernel books it as drive work)."""
    t = 0.01
    rotation, energy = _tumble(1.0, t, 1e-3)
    exact = MOMENT * t**2 / 2
    assert np.abs(rotation - exact).max() < 1e-6 * np.linalg.norm(exact)
    assert energy["kinetic"] == pytest.approx(MOMENT @ MOMENT * t**2 / 2, rel=1e-8)
    assert energy["drive_work"] == pytest.approx(energy["kinetic"], rel=1e-8)


def test_rigid_body_dead_moment_large_rotation_about_its_fixed_axis():
    """I = 0.5 kg m^2 over 2 s: 3.12 rad about the fixed axis of M (rotation vector
    (1.6, 1.2, -2.4)); the generalized-alpha method's O(dt^2) error at dt = 1e-3 is 2.5e-6
    rad (measured). The energy balance closes to the trapezoidal rule's error (2.4e-6 of the
    kinetic energy |M|^2 t^2 / (2 I) = 2.44 J)."""
    t, inertia = 2.0, 0.5
    rotation, energy = _tumble(inertia, t, 1e-3)
    exact = MOMENT * t**2 / (2 * inertia)
    assert np.linalg.norm(exact) > 3.0
    assert np.abs(rotation - exact).max() < 2e-5
    assert energy["kinetic"] == pytest.approx(MOMENT @ MOMENT * t**2 / (2 * inertia), rel=2e-5)
    assert energy["total"] - energy["drive_work"] == pytest.approx(0.0, abs=2e-5)


def _rectangle_torsion(a: float, b: float, terms: int = 60) -> float:
    """Saint-Venant's series for a solid rectangle a >= b (Timoshenko and Goodier)."""
    n = np.arange(1, 2 * terms, 2)
    return a * b**3 / 3 * (1 - 192 * b / (np.pi**5 * a) * np.sum(np.tanh(n * np.pi * a
                                                                          / (2 * b)) / n**5))


@pytest.mark.parametrize("bending", ["cubic", "continuum"])
def test_cantilever_tip_moment_about_an_oblique_axis(bending):
    """A steel cantilever (1 m, 20 x 10 mm: I_y = 1.67e-9, I_z = 6.67e-9 m^4, unequal) under
    a tip moment with components about all three axes: linear theory turns the tip section
    by M_x L / (G J), M_y L / (E I_y), M_z L / (E I_z) per component. The moment is small
    (rotations ~1e-5) so the geometric nonlinearity stays below 1e-5; measured errors 4e-6
    and 1e-5 (bending), 4e-7 (torsion against the series J)."""
    E, nu, L, w, h = 2.0e11, 0.3, 1.0, 0.02, 0.01
    M = 0.01 * np.array([0.3, 0.4, -0.5])
    s = System("oblique")
    s.material("steel", youngs_modulus=E, density=7800.0, poisson_ratio=nu)
    s.beam("b", material="steel", start=(0, 0, 0), end=(L, 0, 0), nodes=5,
           section=Rectangle(w, h), formulation="nonlinear", bending=bending)
    s.joint("clamp", "weld", "ground", "b", point=(0, 0, 0))
    s.load("m", "moment", body="b", point=(L, 0, 0), vector=tuple(M))
    c = 1e-3
    for name, point in (("o", (L, 0, 0)), ("y", (L, c, 0)), ("z", (L, 0, c))):
        s.probe(name, "b", point)
    model = s.assemble()
    try:
        e = solve_newton(model).e
        pos, pos0 = model.probe_positions(e), model.probe_positions(model.e0)
    finally:
        model.close()
    d = {k: pos[k] - pos0[k] for k in pos}
    on_y, on_z = d["y"] - d["o"], d["z"] - d["o"]    # theta x r for r = c e_y, c e_z
    turn = np.array([on_y[2], on_z[0], -on_y[0]]) / c
    exact = np.array([M[0] * L / (E / (2 * (1 + nu)) * _rectangle_torsion(w, h)),
                      M[1] * L / (E * w * h**3 / 12), M[2] * L / (E * h * w**3 / 12)])
    assert np.abs(turn / exact - 1).max() < 3e-5


def _deformed(model, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return model.e0 + 0.05 * rng.standard_normal(model.ndof)


def test_beam_section_moment_parts_match_central_differences():
    """A beam node's dead moment about an oblique axis acts on both section directors (four
    parts): at a deformed state each part's Jacobian equals central differences of its
    force, and at t = 0 the parts' moment sum d x Q on the directors equals M."""
    s = System("parts")
    s.material("steel", youngs_modulus=2.0e11, density=7800.0)
    s.beam("b", material="steel", start=(0, 0, 0), end=(1, 0, 0), nodes=3,
           section=Rectangle(0.02, 0.01), formulation="nonlinear", bending="continuum")
    s.joint("clamp", "weld", "ground", "b", point=(0, 0, 0))
    vector = np.array([3.0, -2.0, 5.0])
    s.load("m", "moment", body="b", point=(1, 0, 0), vector=tuple(vector))
    model = s.assemble()
    try:
        assert len(model.moments) == 4
        q0 = model.expand(model.e0)
        exerted = sum(np.cross(q0[m.dofs], f) for m in model.moments
                      for f in [kernel.moment_force(q0[m.dofs], m.axis, m.magnitude)[0]])
        assert np.abs(exerted - vector).max() < 1e-12 * np.linalg.norm(vector)
        e = _deformed(model, 3)
        for k, (cols, force, jac, _) in enumerate(model.moment_terms(e)):
            numeric = np.zeros_like(jac)
            h = 1e-6
            for j, col in enumerate(cols):
                plus, minus = e.copy(), e.copy()
                plus[col] += h
                minus[col] -= h
                numeric[:, j] = (model.moment_terms(plus)[k][1]
                                 - model.moment_terms(minus)[k][1]) / (2 * h)
            assert np.abs(jac - numeric).max() < 1e-6 * np.abs(jac).max()
    finally:
        model.close()


def test_rigid_body_dead_moment_tangent_and_exerted_moment():
    """The rigid body's dead moment (kernel vector_loads) at a rotated state: the directors'
    forces exert exactly M (r_x x Q_x + r_y x Q_y) and the Jacobian equals central
    differences of the force."""
    s = System("rb")
    s.rigid_body("body", mass=1.0, inertia=(1, 2, 3, 0, 0, 0), position=(0, 0, 0))
    s.load("m", "moment", body="body", point=(0, 0, 0), vector=tuple(MOMENT))
    model = s.assemble()
    try:
        assert not model.moments and len(model.vector_loads) == 1
        e = model.e0.copy()
        turn = Rotation.from_rotvec([0.7, -1.1, 0.4]).as_matrix()
        load = model.vector_loads[0]
        slots = [slot[0][0] for slot in load.slots[:2]]
        q = model.expand(e)
        for first in slots:   # the directors r_x, r_y the load acts through, turned
            q[first:first + 3] = turn @ q[first:first + 3]
        e = model.reduce(q)
        (cols, force, jac), = model.vector_load_terms(e)
        q = model.expand(e)
        where = {c: i for i, c in enumerate(cols)}
        exerted = sum(np.cross(q[f:f + 3], force[[where[f + i] for i in range(3)]])
                      for f in slots)
        assert np.abs(exerted - MOMENT).max() < 1e-13
        numeric = np.zeros_like(jac)
        h = 1e-6
        for j, col in enumerate(cols):
            plus, minus = e.copy(), e.copy()
            plus[col] += h
            minus[col] -= h
            numeric[:, j] = (model.vector_load_terms(plus)[0][1]
                             - model.vector_load_terms(minus)[0][1]) / (2 * h)
        assert np.abs(jac - numeric).max() < 1e-8 * np.abs(jac).max()
    finally:
        model.close()


def test_modal_stiffness_carries_the_rigid_body_moment_load_stiffness():
    """Modal analysis linearizes about the static state with the dead moment's exact load
    stiffness (kernel vector_loads): a rigid body on a bushing (400 N m/rad about each axis)
    turned 0.125 rad by M = (30, 0, 40) N m. The stiffness modal.linearize returns equals
    the central differences of the residual internal - external - Phi_e^T lambda there (the
    rigid body's own constraints, lambda held), symmetrized (the load stiffness is
    unsymmetric; the modal problem takes its symmetric part); without the moment's load
    stiffness the two differ by the order of M."""
    import scipy.sparse as sp

    from ancfdrv.solvers.modal import linearize
    s = System("mounted")
    s.rigid_body("body", mass=2.0, inertia=(1.0, 1.0, 1.0, 0, 0, 0), position=(0, 0, 0))
    s.force_element("mount", "bushing", "ground", "body", point=(0, 0, 0),
                    stiffness=[1e6, 1e6, 1e6], rotational_stiffness=[400.0, 400.0, 400.0])
    s.load("m", "moment", body="body", point=(0, 0, 0), vector=(30.0, 0.0, 40.0))
    model = s.assemble()
    try:
        static = solve_newton(model)
        e, lam, n = static.e, static.lam, model.ndof
        stiffness = linearize(model, e, lam).stiffness.toarray()

        def residual(x):
            out = model.forces(x, 0.0)
            _, rows, cols, grads = model.constraints.jacobian(x, n, 0.0)
            g = sp.csr_matrix((grads, (rows, cols)), shape=(len(model.constraints), n))
            return out["internal"] - out["external"] - g.T @ lam
        numeric = np.zeros((n, n))
        h = 1e-7
        for j in range(n):
            plus, minus = e.copy(), e.copy()
            plus[j] += h
            minus[j] -= h
            numeric[:, j] = (residual(plus) - residual(minus)) / (2 * h)
        numeric = 0.5 * (numeric + numeric.T)
        assert np.abs(residual(e)).max() < 1e-6
        (cols, _, jac), = model.vector_load_terms(e)
        assert np.abs(jac).max() > 10.0     # the load stiffness is of the order of M
        assert np.abs(stiffness - numeric).max() < 1e-4 * np.abs(jac).max()
    finally:
        model.close()


def test_static_rigid_body_moment_runs_with_the_python_default():
    """System.static() with its default method picks Newton for a rigid body's moment (the
    split iteration takes no configuration-dependent load) and turns a body on a bushing
    (k_r = 400 N m/rad about z; its measure theta = sin(phi), potential k_r theta^2 / 2)
    until k_r sin(phi) cos(phi) = M: phi = asin(2 M / k_r) / 2 for M = 40 N m."""
    s = System("turned")
    s.rigid_body("body", mass=2.0, inertia=(1.0, 1.0, 1.0, 0, 0, 0), position=(0, 0, 0))
    s.force_element("mount", "bushing", "ground", "body", point=(0, 0, 0),
                    stiffness=[1e6, 1e6, 1e6], rotational_stiffness=[400.0, 400.0, 400.0])
    s.load("m", "moment", body="body", point=(0, 0, 0), vector=(0.0, 0.0, 40.0))
    s.probe("x", "body", (1.0, 0.0, 0.0))
    res = s.static()
    x = np.asarray(res.probes["x"]).ravel()
    assert np.arctan2(x[1], x[0]) == pytest.approx(0.5 * np.arcsin(2 * 40.0 / 400.0), rel=1e-9)
