"""The ANCF cable element (fortran/src/elements/cable_element.f90, python/ancfdrv/system/
cable.py): gradient-deficient, r and r_x per node, axial Green strain and the exact
curvature |r' x r''| / |r'|^3 (Gerstmayr and Shabana 2006).

Element checks (the standard four of every element routine): the mass against its closed
form kron(Mbar, I3) and a Gauss integration of the shape functions, zero strain energy and
force in rigid motions (translation, a large rotation), the analytic tangent against central
differences of the force (and the force against differences of the energy), objectivity
under a large rotation of a deformed state. System checks through the System API: the tip
deflection of a cantilever against Euler-Bernoulli P L^3 / (3 E I), the large-deflection
elastica (Mattiasson 1981: k = P L^2 / EI = 1 gives w/L = 0.30172, u/L = 0.05643) and the first
bending frequencies against the closed form beta_n L = 1.87510, 4.69409, 7.85476.
"""
from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

from ancfdrv import Circle, System, kernel
from ancfdrv.errors import InputError
from ancfdrv.solvers.static import solve_newton

E, RHO, D = 2.1e11, 7850.0, 0.02
AREA, INERTIA = np.pi * D**2 / 4.0, np.pi * D**4 / 64.0
DOFS = np.arange(12).reshape(12, 1)


def _rotation(axis, angle: float) -> np.ndarray:
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    skew = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * skew + (1.0 - np.cos(angle)) * skew @ skew


def _straight(length: float) -> np.ndarray:
    return np.concatenate([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [length, 0.0, 0.0], [1.0, 0.0, 0.0]])


def _deformed(length: float, seed: int = 3) -> np.ndarray:
    return _straight(length) + 0.15 * np.random.default_rng(seed).standard_normal(12)


def test_mass_closed_form_and_quadrature():
    """Mbar = rho A L / 420 [156 22L 54 -13L; ...] (the Hermite cubic's consistent mass),
    symmetric, equal to a 6-point Gauss integration of S S^T from the kernel's shape rows,
    and a rigid translation (nodal r = c, slopes 0) carries the whole mass rho A L."""
    length, mpl = 0.7, 2.5
    mass, load = kernel.cable_element_arrays([length], mpl, np.array([0.0, 0.0, -9.81]))
    l_ = length
    closed = mpl * length / 420.0 * np.array([[156, 22 * l_, 54, -13 * l_],
                                              [22 * l_, 4 * l_**2, 13 * l_, -3 * l_**2],
                                              [54, 13 * l_, 156, -22 * l_],
                                              [-13 * l_, -3 * l_**2, -22 * l_, 4 * l_**2]])
    assert np.allclose(mass[:, :, 0], closed, rtol=1e-14, atol=0.0)
    assert np.array_equal(mass[:, :, 0], mass[:, :, 0].T)
    x, w = np.polynomial.legendre.leggauss(6)
    numeric = np.zeros((4, 4))
    for xi, wi in zip(0.5 * (x + 1.0), 0.5 * w * length):
        shape, _, _ = kernel.cable_shape(xi, length)
        numeric += wi * mpl * np.outer(shape, shape)
    assert np.allclose(mass[:, :, 0], numeric, rtol=1e-13, atol=1e-15)
    translation = np.array([1.0, 0.0, 1.0, 0.0])
    assert translation @ mass[:, :, 0] @ translation == pytest.approx(mpl * length, rel=1e-14)
    # the uniform load's generalized force: its resultant on the positions is load * L
    assert load[[2, 8], 0].sum() == pytest.approx(-9.81 * length, rel=1e-14)


@pytest.mark.parametrize("angle", [0.0, 0.4, 2.3])
def test_rigid_motions_have_no_strain_energy(angle):
    """Translate and rotate the straight reference by up to 2.3 rad about a skew axis: the
    energy and force vanish to rounding (energy against the bending energy of a unit
    curvature over the element, EI L / 2; force against the rounding of the stretch, a few
    eps, times the axial stiffness over the length, 4 eps EA / L = 1.2e-7 N here, plus
    1e-12 EI / L^2: measured up to 0.34 eps EA / L, which moves with the machine's
    arithmetic; a real strain under a rigid turn would give forces of order EA)."""
    length = 0.5
    rot = _rotation([0.3, -1.0, 0.6], angle)
    q = _straight(length).reshape(4, 3) @ rot.T
    q[[0, 2]] += np.array([1.2, -0.4, 3.0])
    force, energy, _, _ = kernel.cable_forces(DOFS, q.ravel(), [length], E * AREA, E * INERTIA,
                                           False)
    assert abs(energy) <= 1e-13 * E * INERTIA * length / 2.0
    assert np.abs(force).max() <= (4 * np.finfo(float).eps * E * AREA / length
                                   + 1e-12 * E * INERTIA / length**2)


def test_tangent_matches_central_differences():
    """The analytic tangent against central differences of the force (step 1e-6 on unit-size
    coordinates) at a strongly deformed state with stretch, bending and twist of the centre
    line, and the force against central differences of the energy; the tangent is
    symmetric (a Hessian) to rounding. Stiffnesses of comparable size so both terms count."""
    length, ea, ei = 0.7, 3.0, 0.2
    q = _deformed(length)
    force, _, tangent, _ = kernel.cable_forces(DOFS, q, [length], ea, ei, True)
    h = 1e-6
    numeric, gradient = np.zeros((12, 12)), np.zeros(12)
    for j in range(12):
        dq = np.zeros(12)
        dq[j] = h
        fp, up, _, _ = kernel.cable_forces(DOFS, q + dq, [length], ea, ei, False)
        fm, um, _, _ = kernel.cable_forces(DOFS, q - dq, [length], ea, ei, False)
        numeric[:, j] = (fp - fm) / (2 * h)
        gradient[j] = (up - um) / (2 * h)
    assert np.abs(tangent[:, :, 0] - numeric).max() <= 1e-8 * np.abs(numeric).max()
    assert np.abs(force - gradient).max() <= 1e-8 * np.abs(force).max()
    assert np.abs(tangent[:, :, 0] - tangent[:, :, 0].T).max() <= 1e-13 * np.abs(tangent).max()


def test_large_rotation_of_a_deformed_state_is_objective():
    """Rotate a deformed state by 2.0 rad: the energy is unchanged, the force turns with the
    rotation (Q(R q) = R Q(q)) and the tangent is R K R^T (to rounding)."""
    length, ea, ei = 0.7, 3.0, 0.2
    q = _deformed(length, seed=7)
    rot = _rotation([1.0, 2.0, -0.5], 2.0)
    big = np.kron(np.eye(4), rot)
    f0, u0, k0, _ = kernel.cable_forces(DOFS, q, [length], ea, ei, True)
    f1, u1, k1, _ = kernel.cable_forces(DOFS, big @ q, [length], ea, ei, True)
    assert u1 == pytest.approx(u0, rel=1e-12)
    assert np.abs(f1 - big @ f0).max() <= 1e-12 * np.abs(f0).max()
    assert np.abs(k1[:, :, 0] - big @ k0[:, :, 0] @ big.T).max() <= 1e-12 * np.abs(k0).max()


def _cantilever(nodes: int, force: float, length: float = 2.0, load_steps: int = 1):
    """Tip displacement of a steel cable (d = 20 mm) along x clamped at the origin (a weld
    to the ground holds r and r_x), under a dead tip force -force along y."""
    s = System("cable cantilever")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.cable("cable", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=nodes,
            section=Circle(D))
    s.joint("root", "weld", "ground", "cable", point=(0, 0, 0))
    s.load("tip force", "force", body="cable", point=(length, 0, 0), vector=(0, -force, 0))
    s.probe("tip", "cable", (length, 0, 0))
    model = s.assemble()
    try:
        result = solve_newton(model, tol=1e-12, load_steps=load_steps)
        return model.probe_positions(result.e)["tip"] - np.array([length, 0.0, 0.0])
    finally:
        model.close()


def test_cantilever_tip_deflection_euler_bernoulli():
    """P = 1 N on a 2 m steel cable: tip deflection P L^3 / (3 E I) (Euler-Bernoulli). The
    cubic Hermite interpolation holds the linear solution; what remains is the geometric
    nonlinearity of a deflection ratio 8e-4 (order (w/L)^2 ~ 1e-6) and, on one element, the
    coupling of the quadratic axial strain (2.6e-4): 4 elements within 2e-6."""
    length, force = 2.0, 1.0
    expected = force * length**3 / (3.0 * E * INERTIA)
    one = _cantilever(2, force)[1]
    four = _cantilever(5, force)[1]
    assert abs(-four / expected - 1.0) < 2e-6
    assert abs(-one / expected - 1.0) > abs(-four / expected - 1.0)


def test_cantilever_elastica():
    """k = P L^2 / (E I) = 1, 16 elements, 5 load steps: w/L = 0.30172, u/L = 0.05643
    (the elastica; Mattiasson 1981) to the 5 digits given."""
    length = 2.0
    tip = _cantilever(17, E * INERTIA / length**2, length, load_steps=5)
    assert -tip[1] / length == pytest.approx(0.30172, abs=1e-5)
    assert -tip[0] / length == pytest.approx(0.05643, abs=1e-5)


def test_cantilever_frequencies():
    """The first three bending frequencies of a clamped-free cable (8 elements, M and the
    tangent K at the reference from the kernel, clamped node removed) against Euler-
    Bernoulli omega_n = (beta_n L)^2 sqrt(E I / (rho A L^4)), beta_n L = 1.87510, 4.69409,
    7.85476: within 1e-5, 1e-4, 1e-3 (the Hermite cubic's h^4 convergence). Each bending
    frequency appears twice (the two bending planes)."""
    length, nel = 2.0, 8
    lengths = np.full(nel, length / nel)
    n = 6 * (nel + 1)
    dofs = np.array([np.arange(12) + 6 * el for el in range(nel)]).T
    q = np.zeros((nel + 1, 6))
    q[:, 0] = np.linspace(0.0, length, nel + 1)
    q[:, 3] = 1.0
    _, _, tangents, _ = kernel.cable_forces(dofs, q.ravel(), lengths, E * AREA, E * INERTIA, True)
    mbar, _ = kernel.cable_element_arrays(lengths, RHO * AREA, np.zeros(3))
    stiffness, mass = np.zeros((n, n)), np.zeros((n, n))
    for el in range(nel):
        idx = np.ix_(dofs[:, el], dofs[:, el])
        stiffness[idx] += tangents[:, :, el]
        mass[idx] += np.kron(mbar[:, :, el], np.eye(3))
    free = np.arange(6, n)
    omega2 = sla.eigh(stiffness[np.ix_(free, free)], mass[np.ix_(free, free)],
                      eigvals_only=True)
    omega = np.sqrt(np.clip(omega2, 0.0, None))
    bending = omega[omega < 0.2 * np.sqrt(E / RHO) / length]   # below the axial modes
    scale = np.sqrt(E * INERTIA / (RHO * AREA * length**4))
    for k, (beta, tol) in enumerate(zip((1.87510407, 4.69409113, 7.85475744),
                                        (1e-5, 1e-4, 1e-3))):
        exact = beta**2 * scale
        assert bending[2 * k] == pytest.approx(exact, rel=tol)
        assert bending[2 * k + 1] == pytest.approx(exact, rel=tol)


def test_cable_refusals():
    """Bad input names the item: a section with I_y != I_z, a negative bending stiffness
    and a tension_only flag that is not a bool. (Material damping, refused before the rope,
    is now the axial Kelvin-Voigt damping: tests/test_rope.py.)"""
    from ancfdrv import Rectangle
    s = System("bad")
    steel = s.material("steel", youngs_modulus=E, density=RHO, damping_time=1e-3)
    with pytest.raises(InputError, match="cable 'flat'.*one bending stiffness"):
        s.cable("flat", material=steel, start=(0, 0, 0), end=(1, 0, 0), nodes=3,
                section=Rectangle(0.02, 0.01))
    # (the namelist's rule and message through the Python door: System.add checks with the
    # kind's keys)
    with pytest.raises(InputError, match=r"cable\[soft\] bending_stiffness: -1.0 must not be "
                       "negative"):
        s.cable("soft", material=steel, start=(0, 0, 0), end=(1, 0, 0), nodes=3,
                section=Circle(D), bending_stiffness=-1.0)
    with pytest.raises(InputError, match=r"cable\[r\] tension_only: expected .true. or "
                       ".false., got 'yes'"):
        s.cable("r", material=steel, start=(0, 0, 0), end=(1, 0, 0), nodes=3,
                section=Circle(D), tension_only="yes")


SCENE = """&scene  title = 'cable elastica', analysis = 'static', effects = 'tip_force' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&cable  name = 'rope', material = 'steel', start = 0.0, 0.0, 0.0, end = 2.0, 0.0, 0.0,
        nodes = 17, section = 'circle', diameter = 0.02 /
&joint  name = 'clamp', type = 'weld', body1 = 'ground', body2 = 'rope', point = 0, 0, 0 /
&load  name = 'tip force', type = 'force', body = 'rope', point = 2.0, 0.0, 0.0,
       vector = 0.0, -{force!r}, 0.0, effect = 'tip_force' /
&probe  name = 'tip', body = 'rope', point = 2.0, 0.0, 0.0 /
&solver  static_method = 'newton', load_steps = 5 /
"""


def test_cable_from_a_namelist(tmp_path):
    """The &cable group of a general scene builds the same cable: the elastica k = 1 from a
    scene file, tip displacement in the result file (Mattiasson 1981's values)."""
    import h5py

    from ancfdrv.runner import run_scene
    scene = tmp_path / "cable.nml"
    scene.write_text(SCENE.format(force=E * INERTIA / 4.0))
    run_scene(scene, output=tmp_path / "cable.h5", progress=False)
    with h5py.File(tmp_path / "cable.h5") as h5:
        tip = h5["static/deflection/tip"][()].ravel()
        assert h5["model"].attrs["bodies"] == "rope: cable"
    assert -tip[1] / 2.0 == pytest.approx(0.30172, abs=1e-5)
    assert -tip[0] / 2.0 == pytest.approx(0.05643, abs=1e-5)


def test_cable_mass_and_weight_through_the_assembly():
    """The assembled model of a 2 m cable: u^T M u = rho A L for a unit translation of every
    nodal position (r, slopes 0) and the gravity resultant rho A L g (exact)."""
    s = System("weight")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.cable("cable", material=steel, start=(0, 0, 0), end=(2.0, 0, 0), nodes=6,
            section=Circle(D))
    s.load("weight", "gravity", vector=(0, 0, -9.81))
    model = s.assemble()
    try:
        u = np.zeros(model.ndof)
        u[6 * np.arange(6)] = 1.0
        assert u @ (model.mass_matrix() @ u) == pytest.approx(RHO * AREA * 2.0, rel=1e-13)
        weight = model.constant_force().reshape(-1, 2, 3)[:, 0, :].sum(axis=0)
        assert np.allclose(weight, [0.0, 0.0, -9.81 * RHO * AREA * 2.0], rtol=1e-13, atol=1e-12)
    finally:
        model.close()


def test_stiff_cable_pendulum_swings_like_a_rigid_rod():
    """A 1 m cable of 50 mm diameter (bending stiffness 800 times its weight's moment)
    pinned at one end by a 'spherical' joint and released horizontally: its tip passes below
    the pin at the rigid rod's quarter period sqrt(2L / 3g) K(sin^2 45 deg) = 0.48332 s
    (complete elliptic integral, scipy.special.ellipk), within 1e-4 (measured 3.2e-6: the
    bending and dt), and
    the total energy (generalized-alpha with rho_inf = 1) stays within 1e-4 of m g L / 2."""
    from scipy.special import ellipk

    from ancfdrv.codes import ENERGY_NAMES
    from ancfdrv.solvers.dynamic import DynamicSettings, integrate
    d, length, g = 0.05, 1.0, 9.81
    s = System("cable pendulum")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.cable("rope", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=9,
            section=Circle(d))
    s.joint("pin", "spherical", "ground", "rope", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -g, 0))
    s.probe("tip", "rope", (length, 0, 0))
    model = s.assemble()
    rows = []
    try:
        settings = DynamicSettings.generalized_alpha(1e-3, 0.55, 1.0, tol=1e-10, max_newton=20)
        integrate(model, settings, model.e0, sink=rows.append, progress=False)
    finally:
        model.close()
    t = np.concatenate([r.time for r in rows])
    x = np.concatenate([r.probes for r in rows])[:, 0, 0]
    total = np.concatenate([r.energy for r in rows])[:, ENERGY_NAMES.index("total")]
    k = int(np.argmax(x < 0.0))
    crossing = t[k - 1] + (t[k] - t[k - 1]) * x[k - 1] / (x[k - 1] - x[k])
    quarter = np.sqrt(2.0 * length / (3.0 * g)) * ellipk(0.5)
    assert crossing == pytest.approx(quarter, rel=1e-4)
    mass = RHO * np.pi * d**2 / 4.0 * length
    assert np.abs(total - total[0]).max() < 1e-4 * mass * g * length / 2.0
