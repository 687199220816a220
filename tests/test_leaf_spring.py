"""Reference nodes, B-elimination, leaf contact with friction and the two-leaf spring
(seed 003, eqs. 17-38; SPEC section 7). Each test says where its reference comes from."""
from __future__ import annotations

import h5py
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ancfdrv import kernel
from ancfdrv.io.scene import EFFECTS_AVAILABLE
from ancfdrv.runner import run_scene
from ancfdrv.solvers.dynamic import DynamicSettings, integrate
from ancfdrv.system import System
from ancfdrv.system.meshes import rectangle_mesh

from conftest import INPUTS
from reference import leaf_reference as lr  # noqa: E402  (tests/reference: never imported by a run)

STEEL = dict(density=7810.0, youngs_modulus=2.1e11, poisson_ratio=0.3)


class Rows:
    """Collects the chunks of a run (the sink of ``integrate``)."""

    def __init__(self) -> None:
        self.chunks = []

    def __call__(self, chunk) -> None:
        self.chunks.append(chunk)

    def stack(self, name: str) -> np.ndarray:
        return np.concatenate([getattr(c, name) for c in self.chunks])


def _element_grid(nx: int, ny: int, first: int = 0) -> np.ndarray:
    """(nx, ny) element ids of a structured plate mesh (elements run along x fastest)."""
    return first + np.arange(nx * ny).reshape(ny, nx).T


def _rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def _angular_momentum(body, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """L about the origin from the natural coordinates: int rho (r + J u) x (r' + J' u) dV
    with the body's mass, first and second moments (independent of the kernel)."""
    m, c = body.mass, np.zeros(3)  # the reference point is the centre of mass
    second = m * np.outer(c, c) + 0.5 * np.trace(body.inertia) * np.eye(3) - body.inertia
    r, rd = q[:3], v[:3]
    j, jd = q[3:].reshape(3, 3).T, v[3:].reshape(3, 3).T
    out = m * np.cross(r, rd) + m * (np.cross(r, jd @ c) + np.cross(j @ c, rd))
    for a in range(3):
        for b in range(3):
            out += second[a, b] * np.cross(j[:, a], jd[:, b])
    return out


# -- reference nodes ----------------------------------------------------------------------
def test_reference_node_mass_matches_integrated_box():
    """Eq. 32 against a direct quadrature of rho [I, xI, yI, zI]^T [I, xI, yI, zI] over a
    box 0.3 x 0.2 x 0.1 m whose reference point is off its centre."""
    size, m, offset = np.array([0.3, 0.2, 0.1]), 6.0, np.array([0.05, -0.02, 0.01])
    inertia = m / 12 * np.diag([size[1]**2 + size[2]**2, size[0]**2 + size[2]**2,
                                size[0]**2 + size[1]**2])
    matrix = kernel.reference_node_mass(m, offset, inertia)
    g, w = np.polynomial.legendre.leggauss(3)
    expected = np.zeros((12, 12))
    for xi, wx in zip(g, w):
        for yi, wy in zip(g, w):
            for zi, wz in zip(g, w):
                u = offset + 0.5 * size * np.array([xi, yi, zi])
                shape = np.hstack([np.eye(3), u[0] * np.eye(3), u[1] * np.eye(3), u[2] * np.eye(3)])
                expected += m / 8 * wx * wy * wz * shape.T @ shape
    assert np.abs(matrix - matrix.T).max() == 0.0
    assert np.abs(matrix - expected).max() < 1e-12 * m
    with pytest.raises(Exception, match="triangle"):
        kernel.reference_node_mass(1.0, np.zeros(3), np.diag([1.0, 1.0, 3.0]))


def _tumble(dt: float):
    """A free body (principal inertia 2, 3, 4 kg m^2 about the axes of j0, the body axes
    global at t = 0) spinning near its unstable middle axis."""
    j0 = _rotation([1.0, 1.0, 0.0], 0.4)
    inertia = j0 @ np.diag([2.0, 3.0, 4.0]) @ j0.T
    s = System("tumbling body")
    body = s.rigid_body("body", mass=5.0, inertia=inertia, position=(0.2, -0.1, 0.3))
    model = s.assemble()
    omega = np.array([0.3, 5.0, 0.4])
    v0 = np.zeros(model.ndof)
    v0[body.first:body.first + 3] = [0.1, 0.0, -0.2]
    v0[body.first + 3:body.first + 12] = np.cross(omega, np.eye(3)).ravel()
    rows = Rows()
    settings = DynamicSettings.generalized_alpha(dt, 2.0, 1.0, tol=1e-12, max_newton=20,
                                                 store_q=True)
    integrate(model, settings, model.e0, v0, sink=rows, progress=False)
    q = model.expand(rows.stack("q"))[:, body.first:body.first + 12]
    t = rows.stack("time")
    qd = np.gradient(q, t, axis=0, edge_order=2)
    momenta = np.array([_angular_momentum(body, q[k], qd[k]) for k in range(len(t))])
    energy = rows.stack("energy")[:, 0]
    return body, j0, q, energy, momenta


def test_free_rigid_body_tumbles_with_constant_energy_and_momentum():
    """A free body tumbling under no load (seed 003 eqs. 30-32): J stays orthonormal to
    1e-10 at every step; kinetic energy and the angular momentum (computed independently
    from the natural coordinates, velocities by central differences) are conserved up to
    the integrator's second-order error: halving the step divides their drift by ~4."""
    drifts = []
    for dt in (2e-3, 1e-3):
        body, j0, q, energy, momenta = _tumble(dt)
        j = q[:, 3:].reshape(-1, 3, 3)
        gram = np.einsum("kia,kib->kab", j, j)
        assert np.abs(gram - np.eye(3)).max() < 1e-10
        assert np.abs(j[-1] - np.eye(3)).max() > 0.5   # it really tumbled
        drifts.append((np.abs(energy - energy[0]).max() / energy[0],
                       np.abs(momenta - momenta[0]).max() / np.linalg.norm(momenta[0])))
    assert drifts[1][0] < 1e-3 and drifts[1][1] < 1e-3   # measured 4.7e-4 (energy)
    assert drifts[1][0] < 0.3 * drifts[0][0] and drifts[1][1] < 0.3 * drifts[0][1]


def test_reference_node_pendulum_matches_rigid_pendulum_ode():
    """A planar rod (1 m, 2 kg, reference point at its centre) hinged at its top through a
    B-eliminated hinge (eq. 29 without rotation) against the pendulum ODE
    I_O phi'' = -m g d sin(phi), d = 0.5 m, I_O = m L^2/3 (scipy solve_ivp)."""
    length, m = 1.0, 2.0
    start = np.radians(60.0)
    rot = _rotation([0.0, 1.0, 0.0], start)  # about r2: planar in r1-r3
    top = np.array([0.0, 0.0, 0.0])
    centre = top + rot @ np.array([0.0, 0.0, -length / 2])
    inertia = m / 12 * np.diag([length**2, length**2, 1e-4])
    s = System("rigid pendulum")
    rod = s.rigid_body("rod", mass=m, inertia=rot @ inertia @ rot.T, position=centre,
                       planar=True)
    s.joint("hinge", "spherical", "ground", "rod", point=top)  # eliminated (eq. 29)
    s.load("gravity", "gravity", vector=(0.0, 0.0, -9.81))
    model = s.assemble()
    assert model.reduction is not None
    rows = Rows()
    settings = DynamicSettings.generalized_alpha(1e-3, 1.5, 1.0, tol=1e-12, store_q=True)
    integrate(model, settings, model.e0, sink=rows, progress=False)
    q = model.expand(rows.stack("q"))[:, rod.first:rod.first + 12]
    t = rows.stack("time")
    # angle of the rod axis (J rot e3) from the downward vertical, about +r2
    axis = np.einsum("kij,j->ki", q[:, 3:].reshape(-1, 3, 3).transpose(0, 2, 1), rot[:, 2])
    phi = np.arctan2(-axis[:, 0], axis[:, 2])
    i_o, d = m * length**2 / 3, length / 2
    ref = solve_ivp(lambda _, y: [y[1], -m * 9.81 * d * np.sin(y[0]) / i_o], (0, t[-1]),
                    [-start, 0.0], t_eval=t, rtol=1e-11, atol=1e-12)
    assert np.abs(phi - ref.y[0]).max() < 2e-4
    energy = rows.stack("energy")
    assert np.abs(energy[:, 4] - energy[0, 4]).max() < 1e-5 * m * 9.81 * d  # measured 2.8e-6


# -- contact ------------------------------------------------------------------------------
def _plate_on_plate(k=1e5, c=0.0, mu=0.0, v_t=0.08, push=0.0, friction=False):
    """A 0.4 x 0.1 x 0.01 m steel plate (4 x 1 elements, upper, free) resting on a fixed
    0.2 x 0.1 m one centred under it (lower, 2 x 1 elements, contact points: 3 on each end
    edge), so the upper plate can slide without leaving the points."""
    h = 0.01
    effects = ("gravity", "contact") + (("friction",) if friction else ()) + \
        (("point_loads",) if push else ())
    s = System("plate on plate", effects=effects)
    steel = s.material("steel", **STEEL)
    upper = s.plate("upper", material=steel, thickness=h, corner=(0.0, 0.0, h),
                    edge_x=(0.4, 0, 0), edge_y=(0, 0.1, 0), nx=4, ny=1)
    lower = s.plate("lower", material=steel, thickness=h, corner=(0.1, 0.0, 0.0),
                    edge_x=(0.2, 0, 0), edge_y=(0, 0.1, 0), nx=2, ny=1)
    s.load("gravity", "gravity", vector=(0.0, 0.0, -9.81))
    if push:
        for k_, node in enumerate(upper.mesh.node_sets["edge_x0"]):
            s.load(f"push {k_}", "force", body="upper", point=upper.mesh.coords[node, :3],
                   vector=(push / 2, 0.0, 0.0))
    nodes = lower.mesh.coords[:, :3].ravel()
    for vector in ("r", "r_x", "r_y"):
        s.joint(f"fixed lower plate {vector}", "fix", "ground", "lower", point=nodes,
                vector=vector)
    s.contact("plates", "upper", "lower", stiffness=k, damping=c, friction=mu, slip_speed=v_t,
              points=3)
    s.probe("centre", "upper", (0.2, 0.05, h))
    model = s.assemble(linear_joints="eliminate")
    weight = STEEL["density"] * h * 0.4 * 0.1 * 9.81
    return model, weight


def test_contact_iteration_matrix_by_envelope_lu():
    """The contact Jacobian is unsymmetric, so no banded Cholesky; a model this small (4 n
    kd^2 flops within the banded LU's budget) takes the kernel's envelope LU without
    pivoting (beta' M keeps every pivot positive: no fallback to the pivoted banded LU; its
    solves against LAPACK's: tests/test_envelope_lu.py) and drops the plate (51 rows over
    0.1 s, the centre moving)."""
    banded, _ = _plate_on_plate(k=1e5, c=2e3)
    assert "(envelope LU)" in banded.solver.what
    rows = Rows()
    integrate(banded, DynamicSettings.generalized_alpha(2e-3, 0.1, 0.0, tol=1e-10,
                                                        max_newton=40), banded.e0,
              sink=rows, progress=False)
    history = rows.stack("deflections")[:, 0, 2]
    assert len(history) == 51
    assert np.ptp(history) > 1e-6                    # it moves
    assert banded.solver.fallbacks == 0


def test_plate_dropped_on_plate_rests_at_mg_over_k():
    """Static check: resting, the penalty forces carry the weight, so the mean penetration
    over the bounce is m g / (n K) (n = 6 points), whatever the bounce."""
    model, weight = _plate_on_plate(k=1e5, c=2e3)
    rows = Rows()
    # rho_inf = 0 at a step near the bounce period damps the bounce (the contact damping
    # C d' d is weak at these penetrations)
    integrate(model, DynamicSettings.generalized_alpha(2e-3, 0.5, 0.0, tol=1e-10,
                                                       max_newton=40), model.e0,
              sink=rows, progress=False)
    contact = rows.stack("contact")
    late = contact[int(0.8 * len(contact)):]
    total = late[:, :, 1].sum(axis=1).mean()
    assert abs(total - weight) < 0.01 * weight
    assert abs(late[:, :, 0].mean() - weight / (6 * 1e5)) < 0.02 * weight / (6 * 1e5)
    assert np.ptp(late[:, :, 0].mean(axis=1)) < 0.01 * weight / (6 * 1e5)   # at rest


@pytest.mark.parametrize("ratio", [0.5, 1.5])
def test_pushed_plate_sticks_below_mu_n_and_slides_above(ratio):
    """Friction (our regularized law, eq. 26): a tangential push P = ratio mu m g on the
    upper plate. Below mu m g the slip speed settles below the critical V_t at the creep
    speed of f(s) = P/(mu m g); above it the plate accelerates at (P - mu m g)/m."""
    mu, v_t = 0.3, 0.01
    _, weight = _plate_on_plate()
    push = ratio * mu * weight
    model, weight = _plate_on_plate(k=1e6, c=1e3, mu=mu, v_t=v_t, push=push, friction=True)
    rows = Rows()
    # rho_inf = 0: the push and the friction couple pitching vibrations, which the weak
    # contact damping leaves ringing; they would bias the creep (f is concave)
    integrate(model, DynamicSettings.generalized_alpha(1e-3, 0.3, 0.0, tol=1e-10,
                                                       max_newton=40),
              model.e0, sink=rows, progress=False)
    x = rows.stack("probes")[:, 0, 0]   # the upper plate's centre along r1
    t = rows.stack("time")
    late = slice(len(t) // 2, None)
    if ratio < 1:
        s = 1 - np.sqrt(1 - ratio)   # f(s) = s (2 - s) = ratio
        creep = np.polyfit(t[late], x[late], 1)[0]
        assert abs(creep - s * v_t) < 0.02 * s * v_t
        assert creep < v_t
    else:
        accel = 2 * np.polyfit(t[late], x[late], 2)[0]
        mass = weight / 9.81
        assert abs(accel - (push - mu * weight) / mass) < 0.02 * (push - mu * weight) / mass


def test_projection_crosses_element_boundaries():
    """Eq. 18: from a start in the first element the search finds a point two elements on
    (flat plate: the closest point of p is (p1, p2); on a 2 m arc it is at angle atan)."""
    s = System("flat")
    steel = s.material("steel", **STEEL)
    s.plate("plate", material=steel, thickness=0.01, corner=(0, 0, 0), edge_x=(0.4, 0, 0),
            edge_y=(0, 0.1, 0), nx=4, ny=1)
    plates = s.assemble()
    mesh = plates.bodies[0].mesh
    sizes = np.vstack([mesh.a, mesh.b])
    grid = _element_grid(4, 1)
    point = np.array([0.263, 0.031, -0.02])
    found, iterations, fallbacks = kernel.contact_projection(
        plates.q0, plates.sets[0].dofs, sizes, grid, point, np.array([0.3, 0.5]))
    assert abs(found[0] - 2.63) < 1e-10 and abs(found[1] - 0.31) < 1e-10
    assert fallbacks == 0
    s = System("arc")
    steel = s.material("steel", **STEEL)
    s.leaf("leaf", material=steel, thickness=0.014, width=0.07, arc_length=1.2, radius=2.0,
           centre=(0, 0, 0), nx=12, ny=1)
    leaf = s.assemble()
    arc = leaf.bodies[0].mesh
    angle = 0.17
    point = np.array([2.05 * np.sin(angle), 0.0, 2.0 - 2.05 * np.cos(angle)])  # below the leaf
    found, *_ = kernel.contact_projection(leaf.q0, leaf.sets[0].dofs, np.vstack([arc.a, arc.b]),
                                          _element_grid(12, 1), point, np.array([6.0, 0.5]))
    # the ACM element interpolates the arc: 1e-6 of an element
    assert abs(found[0] - (0.6 + 2.0 * angle) / 0.1) < 1e-4


def test_contact_gap_gradient_and_surface_velocity_against_finite_differences():
    """G = dg/de (the normal force's direction) is exact for parallel normals; the surface
    velocity V_rel = A e' includes the normals' rates (eq. 22): both against central
    differences of the kernel's own gap and surface points."""
    up = rectangle_mesh(0.1, 0.07, 1, 1, origin=(0.0, 0.0, 0.0135)).coords
    lo = rectangle_mesh(0.1, 0.07, 1, 1).coords  # noqa: E501
    rot = _rotation([0.3, -0.5, 0.8], 1.1)

    def coords(nodes):
        c = nodes.reshape(4, 3, 3) @ rot.T
        return c.reshape(12, 3).T.copy()
    upper, lower = coords(up), coords(lo)
    params = kernel.contact_params(1e6, 0.0, 0.0, 0.08, 0.014, 0.014, False)
    zero = np.zeros((3, 12))
    base = kernel.contact_pair(upper, zero, 0.1, 0.07, 0.4, 0.6, lower, zero, 0.1, 0.07, 0.4,
                               0.6, params)
    delta = base["record"][0]
    assert abs(delta - 0.0005) < 1e-12       # rigidly rotated: the gap is exact
    gradient = np.concatenate([base["force_upper"], base["force_lower"]]) / (1e6 * delta)
    numeric = np.zeros(72)
    eps = 1e-7
    for k in range(72):
        for sign in (1, -1):
            u, lw = upper.copy(), lower.copy()
            target = u if k < 36 else lw
            target[(k % 36) % 3, (k % 36) // 3] += sign * eps
            r = kernel.contact_pair(u, zero, 0.1, 0.07, 0.4, 0.6, lw, zero, 0.1, 0.07, 0.4, 0.6,
                                    params)
            numeric[k] += sign * (-r["record"][0]) / (2 * eps)   # g = -delta
    assert np.abs(gradient - numeric).max() < 1e-6 * np.abs(numeric).max()


def test_contact_and_friction_dissipate_never_create_energy():
    """A plate sliding and bouncing on a plate with damping and friction: the work of
    damping and of friction never increases, and the energy balance (energy + dissipated
    work) closes as the step shrinks (first order: contacts open and close within steps),
    so contact creates no energy."""
    errors = []
    for dt in (5e-4, 2.5e-4):
        model, weight = _plate_on_plate(k=1e5, c=1e3, mu=0.3, v_t=0.05, friction=True)
        v0 = np.zeros(model.ndof)
        v0[0:90:9] = 0.2       # the upper plate's 10 nodes (independent, first) slide along r1
        v0[2:90:9] = -0.05     # and fall onto the lower plate
        rows = Rows()
        integrate(model, DynamicSettings.generalized_alpha(dt, 0.3, 1.0, tol=1e-10,
                                                           max_newton=40),
                  model.e0, v0, sink=rows, progress=False)
        energy = rows.stack("energy")
        damping, friction = energy[:, 8], energy[:, 9]
        assert np.all(np.diff(friction) <= 1e-15) and np.all(np.diff(damping) <= 1e-15)
        assert friction[-1] < -0.5 * energy[0, 0]  # friction stopped most of the sliding
        balance = energy[:, 4] - energy[0, 4] - damping - friction
        errors.append(np.abs(balance).max() / energy[0, 0])
    assert errors[0] < 0.01                    # measured 0.66 % and 0.34 % of the motion
    assert errors[1] < 0.6 * errors[0]


# -- the leaf spring ----------------------------------------------------------------------
@pytest.fixture(scope="module")
def spring_runs(tmp_path_factory):
    """Short runs of inputs/leaf_spring.nml (0.8 s: a full bounce) with and without prestress,
    without friction, and without contact, each started at rest from the equilibrium
    without gravity (spring.settle = 'prestress')."""
    out = tmp_path_factory.mktemp("spring")
    runs = {}
    cases = {"on": [], "off": ["leaf.prestress=.false."],
             "no_friction": ["scene.effects=gravity,contact,prestress"],
             "no_contact": ["scene.effects=gravity", "leaf.prestress=.false."]}
    for name, extra in cases.items():
        run_scene(INPUTS / "leaf_spring.nml", ["solver.t_end=0.8"] + extra, out / f"{name}.h5",
                  progress=False)
        with h5py.File(out / f"{name}.h5") as h5:
            runs[name] = dict(z=h5["dynamic/deflection/chassis"][:, 2],
                              settled=h5["static/deflection/chassis"][2]
                              if "static" in h5 else 0.0,
                              t=h5["dynamic/time"][()],
                              counters=dict(h5["counters"].attrs),
                              penetration=h5["dynamic/contact/penetration"][()]
                              if "dynamic/contact" in h5 else None,
                              energy={k: h5[f"dynamic/energy/{k}"][()] for k in h5["dynamic/energy"]})
    return runs


def test_spring_computes_only_listed_effects(spring_runs):
    """Without 'contact' no search or contact force is computed, without 'friction' no
    friction (HDF5 counters prove it)."""
    none, no_friction, full = (spring_runs[k]["counters"] for k in ("no_contact", "no_friction", "on"))
    assert none["contact_points"] == 0 and none["contact_projection_iterations"] == 0
    assert none["contact"] == 0 and none["friction"] == 0
    assert no_friction["contact_points"] > 0 and no_friction["friction_evaluations"] == 0
    assert full["friction_evaluations"] > 0
    assert {"contact", "friction", "load_cycle"} <= set(EFFECTS_AVAILABLE)


def test_prestress_preloads_the_settled_spring(spring_runs):
    """Seed Fig. 12 from a settled start (spring.settle = 'prestress', the default): the
    prestressed lower leaf, carried by contact, lifts the eyes before gravity acts by the
    reference's eye lift (tests/reference/leaf_reference.py, prestress_preload: 11.38 mm for
    the beam stiffness, 11.35 mm for the plate's, with the penalty of 3 points x 1e6 N/m per
    edge; measured 11.30 mm), and the chassis then drops by about the same sag as without
    prestress (linear theory: the preload shifts the spring, its stiffness with the contact
    closed is the same; measured 29.3 and 29.7 mm): a pre-loaded spring, not an impact."""
    lifts = [lr.prestress_preload(ei, contact_stiffness=3e6)["eye_lift"]
             for ei in lr.bending_stiffness_bounds().values()]
    on, off = spring_runs["on"], spring_runs["off"]
    assert on["settled"] == pytest.approx(np.mean(lifts), rel=0.02)
    assert off["settled"] == 0.0
    drop_on, drop_off = on["settled"] - on["z"].min(), -off["z"].min()
    print(f"\nsettled lift {on['settled'] * 1e3:.3f} mm (reference {min(lifts) * 1e3:.3f}.."
          f"{max(lifts) * 1e3:.3f}); drops {drop_on * 1e3:.2f} / {drop_off * 1e3:.2f} mm")
    assert drop_on == pytest.approx(drop_off, rel=0.03)
    # no release impact: from the assembled state friction took 146 J and contact damping
    # 134 J in the first 0.1 s; from the settled state they take 0.46 J and 4e-4 J
    first = np.searchsorted(on["t"], 0.1)
    lost = -(on["energy"]["friction_work"][first] + on["energy"]["damping_work"][first])
    assert 0.0 < lost < 1.0


@pytest.mark.parametrize("case", ["on", "off"])
def test_settled_spring_conserves_energy_balance(spring_runs, case):
    """From a settled start, prestress on and off, energy + contact damping and friction
    work balance to 1e-5 of the chassis's potential drop (m g times its drop; issue 15
    asks < 1 %); measured 2e-3 J and 9e-4 J against about 145 J. Penetration stays far
    below the 15 % of the thickness the stability matrix allows."""
    run = spring_runs[case]
    scale = 500 * 9.81 * (run["settled"] - run["z"].min())
    assert np.abs(run["energy"]["balance"]).max() < 1e-5 * scale
    assert run["penetration"].max() < 0.15 * 0.014


# -- the load cycle from the settled state (issue 15, item 4) -------------------------------
CYCLE_FORCE, CYCLE_PERIOD = 9810.0, 8.0       # inputs/leaf_spring_cycle.nml
#: everything that moves with the chassis: chassis, shackle, both leaves (kg)
MOVING_MASS = 500.0 + 2.0 + 7810.0 * 0.07 * 0.014 * (1.2 + 0.8)


def _static_cycle_curve(prestress: bool, forces: np.ndarray) -> np.ndarray:
    """The chassis's vertical displacement (from the assembled spring) in the frictionless
    static equilibrium under a constant downward force on the chassis, for each force: the
    quasi-static curve a loop without friction and inertia would follow. Static Newton on the
    cycle scene's model, the load cycle's drive replaced by a dead force scaled by the load
    factor."""
    from ancfdrv.builders import build_system
    from ancfdrv.io.scene import load_scene
    from ancfdrv.solvers.static import solve_newton
    scene = load_scene(INPUTS / "leaf_spring_cycle.nml",
                       [] if prestress else ["leaf.prestress=.false."])
    system = build_system(scene).system
    system.load("static force", "force", body="chassis", point=system.probes["chassis"].point,
                vector=(0.0, 0.0, -forces.max()))
    effects = tuple(e for e in scene.effects if e not in ("load_cycle", "friction"))
    model = system.assemble(effects=effects + ("point_loads",))
    z0 = model.probe_positions(model.e0)["chassis"][2]
    out = []
    for force in forces:
        result = solve_newton(model, tol=1e-12, loads=force / forces.max())
        out.append(model.probe_positions(result.e)["chassis"][2] - z0)
    return np.array(out)


def _cycle_run(path, overrides):
    from ancfdrv.plots import load_cycle_summary, read_spring
    run_scene(INPUTS / "leaf_spring_cycle.nml", ["output.xdmf=.false."] + overrides, path,
              progress=False)
    run = read_spring(path)
    return run, load_cycle_summary(run)


@pytest.fixture(scope="module")
def cycle_runs(tmp_path_factory):
    """inputs/leaf_spring_cycle.nml as shipped (8 s cycle, settled start), prestress on and
    off, with the frictionless static curve of each."""
    from scipy.interpolate import CubicSpline
    out = tmp_path_factory.mktemp("cycle")
    runs = {}
    for name, extra in (("on", []), ("off", ["leaf.prestress=.false."])):
        run, summary = _cycle_run(out / f"{name}.h5", extra)
        forces = np.linspace(0.0, CYCLE_FORCE, 11)
        static = _static_cycle_curve(name == "on", forces)
        runs[name] = dict(run=run, summary=summary, forces=forces, static=static,
                          deviation=run.chassis - CubicSpline(forces, static)(summary["force"]))
    return runs


@pytest.mark.parametrize("case", ["on", "off"])
def test_load_cycle_loop_area_equals_friction_and_damping_work(cycle_runs, case):
    """The loop of the shipped load cycle, started from the settled state, prestress on and
    off: its area (the work of the applied force around the closed force-deflection loop,
    plots.load_cycle_summary) equals the friction + contact damping work (material damping
    is off) within what the cycle leaves in the spring.

    What may be left is the bounce the force's onset and end excite: F = F_c (1 - cos Omega
    t) / 2 steps its second derivative at both ends, so an undamped oscillator of stiffness k
    and frequency omega keeps a free vibration of amplitude a = F_c r^2 / (2 k (1 - r^2)),
    r = Omega / omega, from each end (closed form), at most 2 a after the cycle, which holds
    the energy k (2 a)^2 / 2. With k the static curve's secant and the mass of everything
    that moves (517 kg: an upper bound of the effective mass, hence of r) this bound is
    1.2e-3 J: 1.3 % (on) and 2 % (off) of the dissipated work. Measured: area 0.09212 J
    against 0.09201 J dissipated (on) and 0.0581 against 0.0579 J (off); the energy books
    (area = dissipated + left) close to 3e-5 J."""
    s = cycle_runs[case]["summary"]
    forces, static = cycle_runs[case]["forces"], cycle_runs[case]["static"]
    k = forces[-1] / (static[0] - static[-1])
    omega = np.sqrt(k / MOVING_MASS)
    r2 = (2 * np.pi / CYCLE_PERIOD / omega) ** 2
    a = CYCLE_FORCE * r2 / (2 * k * (1 - r2))
    bound = 0.5 * k * (2 * a) ** 2
    print(f"\nprestress {case}: area {s['area']:.5f} J, friction {-s['friction_work']:.5f} J, "
          f"contact damping {-s['damping_work']:.2e} J, left {s['left']:.2e} J (bound "
          f"{bound:.2e} J), books {s['residual']:.1e} J")
    assert s["dissipated"] > 0 and s["area"] > 0
    assert s["material_damping_work"] == 0.0
    assert abs(s["residual"]) < 1e-3 * s["dissipated"]          # the energy books close
    assert abs(s["left"]) < bound < 0.025 * s["dissipated"]
    assert s["area"] == pytest.approx(s["dissipated"], rel=0.025)


@pytest.mark.parametrize("case", ["on", "off"])
def test_load_cycle_from_settled_state_does_not_ring(cycle_runs, case, tmp_path):
    """Without ringing: the chassis follows the frictionless static curve z_static(F(t))
    (static Newton solves of the same model at 11 forces, spline-interpolated) to within
    0.5 % of the loop's deflection range at every output step; the rest is the friction band
    and the bounce of amplitude a (previous test's closed form, 0.06 mm). Measured: 0.10 mm
    of 59 mm (0.17 %), both cases. The old start from the assembled spring (spring.settle =
    'none', prestress on) rang at 2.8 Hz by +-20 mm: between 0.25 and 1 s it leaves the static
    curve by more than ten times the tolerance (measured 11.6 mm, 20 % of the range)."""
    runs = cycle_runs[case]
    span = np.ptp(runs["static"])
    deviation = np.abs(runs["deviation"]).max()
    print(f"\nprestress {case}: max |z - z_static(F)| {deviation * 1e3:.3f} mm of "
          f"{span * 1e3:.1f} mm")
    assert deviation < 0.005 * span
    assert runs["run"].chassis[0] == pytest.approx(runs["static"][0], abs=1e-6)  # settled
    if case == "on":
        from scipy.interpolate import CubicSpline
        # the unsettled start's first step makes 261 J (9.8 times the run's energy scale)
        # where the prestressed leaves engage: refused as 'unstable' by default (issue 39),
        # run here with the tolerance opened to show the ringing it leaves
        run, summary = _cycle_run(tmp_path / "none.h5", ["spring.settle=none",
                                                         "solver.t_end=1.0",
                                                         "solver.energy_tolerance=20"])
        released = run.chassis - CubicSpline(runs["forces"], runs["static"])(summary["force"])
        later = run.time >= 0.25   # after the release itself: the ringing it leaves
        assert np.abs(released[later]).max() > 10 * 0.005 * span


def test_load_cycle_plot_shows_the_friction_band(cycle_runs, tmp_path):
    """`ancf plot` of the two shipped cycles writes its figure, and the magnified loop's
    bounce averaging (plots._bounce_average) takes a free bounce off a slow curve: a
    0.06 mm, 2.84 Hz sine on a 0.01 mm band over the 8 s cycle comes back to the band within
    3 % of the bounce's amplitude away from the ends (one period at each end averages what
    there is)."""
    from ancfdrv.cli import main
    from ancfdrv.plots import _bounce_average
    png = tmp_path / "cycle.png"
    paths = [str(cycle_runs[c]["run"].path) for c in ("on", "off")]
    assert main(["plot", *paths, "-o", str(png)]) == 0 and png.stat().st_size > 0
    t = np.arange(0.0, 8.0 + 1e-9, 1e-3)
    band = 1e-5 * np.sin(np.pi * t / 8.0)
    bounce = 6e-5 * np.sin(2 * np.pi * 2.84 * t + 0.3)
    smooth = _bounce_average(t, band + bounce)
    inner = (t > 0.5) & (t < 7.5)
    assert np.abs(smooth - band)[inner].max() < 0.03 * 6e-5
