"""Self-tests of the independent references in tests/reference (frames.py,
beam_formulas.py, mechanisms.py) against textbook closed forms, so that the
references the project is tested against are themselves trustworthy.

Where each expected number comes from is stated in the test. The references use only
numpy/scipy; the compiled package is not needed here.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.special import ellipk

sys.path.insert(0, str(Path(__file__).resolve().parent))
from reference import beam_formulas as bf  # noqa: E402  (tests/reference: never imported by a run)
from reference import frames as fr  # noqa: E402
from reference import mechanisms as mc  # noqa: E402

E = 2.1e11
G = E / 2.6  # nu = 0.3
RHO = 7850.0
THEORIES = ("euler-bernoulli", "timoshenko")


def _rel(a, b) -> float:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def _cantilever(
    n_el: int,
    L: float,
    section: fr.Section,
    theory: str = "euler-bernoulli",
    planar: bool = True,
    rho: float = RHO,
) -> tuple[fr.Frame, list[int]]:
    """A cantilever along +x clamped at the origin."""
    frame = fr.Frame(planar=planar)
    nodes = frame.add_beam_line((0.0, 0.0, 0.0), (L, 0.0, 0.0), n_el, E, G, section, rho, theory=theory)
    frame.fix(nodes[0])
    return frame, nodes


# =============================================================== frames.py: sections
def test_section_helpers_match_hand_formulas():
    r = fr.rectangle(0.2, 0.3)
    assert (r.A, r.Iy, r.Iz) == pytest.approx((0.06, 0.2 * 0.3**3 / 12, 0.3 * 0.2**3 / 12), rel=1e-14)
    # Saint-Venant: beta(h/b = 1.5) = 0.196 (Timoshenko & Goodier's table)
    assert r.J == pytest.approx(0.196 * 0.2**3 * 0.3, rel=2e-3) and r.shear_area == r.A
    assert r.Ip == pytest.approx(r.Iy + r.Iz, rel=1e-14)
    b = fr.box(0.2, 0.3, 0.01)  # outer minus inner 0.18 x 0.28
    assert b.A == pytest.approx(0.06 - 0.18 * 0.28, rel=1e-13)
    assert b.Iy == pytest.approx((0.2 * 0.3**3 - 0.18 * 0.28**3) / 12, rel=1e-13)
    assert b.Iz == pytest.approx((0.3 * 0.2**3 - 0.28 * 0.18**3) / 12, rel=1e-13)
    # Bredt-Batho on the midline 0.19 x 0.29 (plus the walls' share p t^3 / 3)
    assert b.J == pytest.approx(4 * (0.19 * 0.29)**2 * 0.01 / 0.96 + 0.96 * 1e-6 / 3, rel=1e-12)
    t = fr.tube(0.1, 0.005)
    assert t.A == pytest.approx(math.pi * (0.1**2 - 0.09**2) / 4, rel=1e-14)
    assert t.Iy == t.Iz == pytest.approx(math.pi * (0.1**4 - 0.09**4) / 64, rel=1e-14)
    assert t.J == pytest.approx(math.pi * (0.1**4 - 0.09**4) / 32, rel=1e-14)
    c = fr.circle(0.1)
    assert (c.A, c.Iy, c.J) == pytest.approx(
        (math.pi * 0.01 / 4, math.pi * 1e-4 / 64, math.pi * 1e-4 / 32), rel=1e-14
    )
    with pytest.raises(ValueError, match="wall"):
        fr.box(0.2, 0.3, 0.1)
    with pytest.raises(ValueError, match="diameter"):
        fr.circle(-1.0)


# ====================================================== frames.py: static cantilevers
@pytest.mark.parametrize("theory", THEORIES)
def test_cantilever_tip_load_and_reactions(theory):
    """Tip load: P L^3/(3EI) (+ P L/(k G A), k = 1), rotation P L^2/(2EI), support
    reactions -P and -P L (nodal values of both elements are exact)."""
    sec, L, P = fr.rectangle(0.1, 0.2), 2.0, -1000.0
    frame, nodes = _cantilever(3, L, sec, theory)
    frame.add_nodal_load(nodes[-1], (0.0, P))
    res = frame.solve_static()
    GAs = G * sec.A if theory == "timoshenko" else None
    w, rot = bf.cantilever_tip_load(P, L, E * sec.Iz, GAs)
    assert res.displacements[nodes[-1], 1] == pytest.approx(w, rel=1e-11)
    assert res.displacements[nodes[-1], 5] == pytest.approx(rot, rel=1e-11)
    assert res.reactions[nodes[0], [0, 1, 5]] == pytest.approx([0.0, -P, -P * L], rel=1e-11, abs=1e-8)
    if theory == "timoshenko":  # the shear term is really there: 1.6% of the bending term here
        assert abs(w - bf.cantilever_tip_load(P, L, E * sec.Iz)[0]) > 1e-3 * abs(w)


@pytest.mark.parametrize("theory", THEORIES)
def test_cantilever_uniform_load_and_self_weight(theory):
    """Uniform load: q L^4/(8EI) (+ q L^2/(2GA)), rotation q L^3/(6EI); self weight is the
    same uniform load q = rho A g (consistent load vectors give exact nodal values)."""
    sec, L, q = fr.rectangle(0.1, 0.1), 3.0, -2500.0
    GAs = G * sec.A if theory == "timoshenko" else None
    w, rot = bf.cantilever_uniform_load(q, L, E * sec.Iz, GAs)
    frame, nodes = _cantilever(4, L, sec, theory, rho=0.0)
    for e in range(4):
        frame.add_distributed_load(e, (0.0, q))
    res = frame.solve_static()
    assert res.displacements[nodes[-1], 1] == pytest.approx(w, rel=1e-11)
    assert res.displacements[nodes[-1], 5] == pytest.approx(rot, rel=1e-11)
    assert res.reactions[nodes[0], 1] == pytest.approx(-q * L, rel=1e-12)
    g = 9.81
    frame, nodes = _cantilever(4, L, sec, theory, rho=RHO)
    res = frame.solve_static(gravity=(0.0, -g))
    w, _ = bf.cantilever_uniform_load(-RHO * sec.A * g, L, E * sec.Iz, GAs)
    assert res.displacements[nodes[-1], 1] == pytest.approx(w, rel=1e-11)


def test_cantilever_end_moment_axial_and_torsion_3d():
    """End moment M L^2/(2EI), M L/EI in both bending planes (Iy for deflection along the
    height z, Iz along the width y); axial P L/(EA); torsion T L/(GJ) with J = Iy + Iz."""
    sec, L = fr.rectangle(0.1, 0.25), 2.5
    frame, nodes = _cantilever(2, L, sec, planar=False)
    tip = nodes[-1]
    frame.add_nodal_load(tip, force=(5.0e4, 0.0, 0.0), moment=(300.0, 700.0, 1100.0))
    u = frame.solve_static().displacements[tip]
    assert u[0] == pytest.approx(5.0e4 * L / (E * sec.A), rel=1e-12)
    assert u[3] == pytest.approx(300.0 * L / (G * sec.J), rel=1e-12)
    w_z, r_z = bf.cantilever_end_moment(1100.0, L, E * sec.Iz)  # moment about z: deflection +y
    assert (u[1], u[5]) == pytest.approx((w_z, r_z), rel=1e-11)
    w_y, r_y = bf.cantilever_end_moment(700.0, L, E * sec.Iy)  # moment about y: deflection -z
    assert (u[2], u[4]) == pytest.approx((-w_y, r_y), rel=1e-11)


# ===================================================== frames.py: frequencies
def test_clamped_free_roots():
    assert bf.clamped_free_beta_l(3) == pytest.approx(bf.CLAMPED_FREE_BETA_L, rel=1e-14)


def test_clamped_free_frequencies_converge():
    """Cantilever frequencies (beta_n L)^2 sqrt(EI/(rho A L^4)), beta_n L = 1.8751, 4.6941,
    7.8548: the consistent-mass Hermite element converges as h^4 (ratio 16 per halving);
    with 32 elements the third mode is within 2.6e-6 (observed 2.51e-6)."""
    sec, L = fr.rectangle(0.05, 0.1), 2.0
    expected = bf.euler_bernoulli_frequency(bf.CLAMPED_FREE_BETA_L, L, E * sec.Iz, RHO * sec.A)
    errors = []
    for n_el in (8, 16, 32):
        omega = _cantilever(n_el, L, sec)[0].solve_modes(3).omega
        assert np.all(omega >= expected)  # consistent mass: upper bounds
        errors.append(_rel(omega, expected))
    assert errors[0] / errors[1] > 14.0 and errors[1] / errors[2] > 14.0
    assert errors[2] < 2.6e-6


def test_3d_bending_planes_use_iz_and_iy():
    """A 3D cantilever of a 0.05 x 0.1 rectangle (height along global z): its modes
    polarized along y (the width) have the frequencies of the planar model bending with
    Iz, those along z (the height) the frequencies of the planar model whose height axis
    lies in the plane (bending with Iy), to rounding, on the same mesh."""
    sec, L, n_el = fr.rectangle(0.05, 0.1), 2.0, 8
    modes = _cantilever(n_el, L, sec, planar=False)[0].solve_modes(8)
    along_y = np.abs(modes.modes[:, -1, 1]) > np.abs(modes.modes[:, -1, 2])
    bending = np.abs(modes.modes[:, -1, 1:3]).max(axis=1) > 1e-6 * np.abs(modes.modes[:, -1]).max(axis=1)
    width = _cantilever(n_el, L, sec)[0].solve_modes(3).omega
    frame = fr.Frame(planar=True)
    nodes = frame.add_beam_line((0.0, 0.0), (L, 0.0), n_el, E, G, sec, RHO, height_axis=(0.0, 1.0, 0.0))
    frame.fix(nodes[0])
    height = frame.solve_modes(3).omega
    assert width[0] < height[0]  # Iz < Iy for this section
    assert modes.omega[bending & along_y][:3] == pytest.approx(width, rel=1e-10)
    assert modes.omega[bending & ~along_y][:3] == pytest.approx(height, rel=1e-10)
    assert height == pytest.approx(width * math.sqrt(sec.Iy / sec.Iz), rel=1e-10)


def _simply_supported(n_el: int, L: float, sec: fr.Section, theory: str) -> tuple[fr.Frame, list[int]]:
    """Pinned (ux, uy fixed) at x = 0, roller (uy fixed) at x = L."""
    frame = fr.Frame(planar=True)
    nodes = frame.add_beam_line((0.0, 0.0), (L, 0.0), n_el, E, G, sec, RHO, theory=theory)
    frame.fix(nodes[0], ("ux", "uy"))
    frame.fix(nodes[-1], ("uy",))
    return frame, nodes


@pytest.mark.parametrize("theory", THEORIES)
def test_simply_supported_beam_statics_and_frequencies(theory):
    """Pinned-roller span: mid-span 5 q L^4/(384 EI) (+ q L^2/(8 GA)), reactions q L/2
    (exact at the nodes); frequencies: Euler-Bernoulli (n pi)^2 sqrt(EI/(rho A L^4)),
    Timoshenko (shear and rotary inertia) the lower root of the simply supported
    Timoshenko quadratic. Convergence: h^4 for Hermite elements; h^2 for the Timoshenko
    element on this deep beam (its consistent mass comes from static shape functions and
    phi = 12 EI/(GA h^2) grows as the mesh is refined: 4.1 per halving observed). The
    matrices of that element are checked against their published closed forms below."""
    sec, L, q = fr.rectangle(0.2, 0.3), 4.0, -1.0e4  # deep beam: L/w = 20, so shear matters
    timo = theory == "timoshenko"
    EI, GAs = E * sec.Iz, G * sec.A
    frame, nodes = _simply_supported(8, L, sec, theory)
    for e in range(8):
        frame.add_distributed_load(e, (0.0, q))
    res = frame.solve_static()
    assert res.displacements[nodes[4], 1] == pytest.approx(
        bf.simply_supported_uniform_load(q, L, EI, GAs if timo else None), rel=1e-11
    )
    assert res.reactions[[nodes[0], nodes[-1]], 1] == pytest.approx([-q * L / 2] * 2, rel=1e-11)
    if timo:
        expected = bf.simply_supported_timoshenko_frequencies(L, EI, GAs, RHO * sec.A, RHO * sec.Iz, 3)
        plain = bf.euler_bernoulli_frequency(bf.simply_supported_beta_l(3), L, EI, RHO * sec.A)
        assert np.all(plain - expected > 3e-3 * expected)  # shear + rotary inertia matter here
    else:
        expected = bf.euler_bernoulli_frequency(bf.simply_supported_beta_l(3), L, EI, RHO * sec.A)
    errors = [
        _rel(_simply_supported(n, L, sec, theory)[0].solve_modes(3).omega, expected) for n in (8, 16, 32)
    ]
    rate, final = (3.8, 1.8e-4) if timo else (14.0, 5.5e-6)  # observed: 1.66e-4, 5.2e-6
    assert errors[0] / errors[1] > rate and errors[1] / errors[2] > rate
    assert errors[2] < final


def test_timoshenko_element_matrices_match_published_closed_forms():
    """The quadrature-built bending matrices of one element equal the closed forms of
    Przemieniecki (1968) / Friedman & Kosmatka (1993), phi = 12 EI/(GA L^2): stiffness
    EI/((1+phi) L^3) [[12, 6L, -12, 6L], [., (4+phi) L^2, -6L, (2-phi) L^2], ...];
    translational mass rho A L/(210 (1+phi)^2) [[70 phi^2 + 147 phi + 78, ...]]; rotary
    mass rho I/(30 (1+phi)^2 L) [[36, -(15 phi - 3) L, ...]]."""
    l, p, EI = 1.3, 0.7, 2.0
    GAs = 12 * EI / (p * l**2)
    sym = lambda a: np.triu(a) + np.triu(a, 1).T  # noqa: E731
    K_ref = (
        EI
        / ((1 + p) * l**3)
        * np.array(
            [
                [12, 6 * l, -12, 6 * l],
                [6 * l, (4 + p) * l**2, -6 * l, (2 - p) * l**2],
                [-12, -6 * l, 12, -6 * l],
                [6 * l, (2 - p) * l**2, -6 * l, (4 + p) * l**2],
            ]
        )
    )
    a, b, c = 70 * p**2 + 147 * p + 78, (35 * p**2 + 77 * p + 44) * l / 4, 35 * p**2 + 63 * p + 27
    d, e_, f = (
        (35 * p**2 + 63 * p + 26) * l / 4,
        (7 * p**2 + 14 * p + 8) * l**2 / 4,
        (7 * p**2 + 14 * p + 6) * l**2 / 4,
    )
    M_ref = (
        l
        / (210 * (1 + p) ** 2)
        * sym(np.array([[a, b, c, -d], [0, e_, d, -f], [0, 0, a, -b], [0, 0, 0, e_]]))
    )
    g_, h_, k_ = (15 * p - 3) * l, (10 * p**2 + 5 * p + 4) * l**2, (5 * p**2 - 5 * p - 1) * l**2
    R_ref = (
        1
        / (30 * (1 + p) ** 2 * l)
        * sym(np.array([[36, -g_, -36, -g_], [0, h_, g_, k_], [0, 0, 36, g_], [0, 0, 0, h_]]))
    )
    one = np.ones(1)
    Kt, Mt, _ = fr.beam_local_matrices(
        one * l, one * EI, one * GAs, one, one * 0, one, one * 0, one, [True], [False], one
    )
    _, Mr, _ = fr.beam_local_matrices(
        one * l, one * EI, one * GAs, one, one * 0, one, one * 0, one, [True], [True], one
    )
    xy = np.ix_([1, 5, 7, 11], [1, 5, 7, 11])
    assert Kt[0][xy] == pytest.approx(K_ref, rel=1e-14, abs=1e-14 * np.abs(K_ref).max())
    assert Mt[0][xy] == pytest.approx(M_ref, rel=1e-14, abs=1e-15)
    assert (Mr - Mt)[0][xy] == pytest.approx(R_ref, rel=1e-13, abs=1e-15)


def test_timoshenko_closed_form_limits():
    """The Timoshenko quadratic tends to the Euler-Bernoulli value when GA -> inf and
    rho I -> 0, and without rotary inertia equals w_EB / sqrt(1 + EI k^2/GA)."""
    L, EI, rhoA = 3.0, 2.0e6, 40.0
    eb = bf.euler_bernoulli_frequency(bf.simply_supported_beta_l(3), L, EI, rhoA)
    assert bf.simply_supported_timoshenko_frequencies(L, EI, 1e16, rhoA, 1e-12, 3) == pytest.approx(
        eb, rel=1e-9
    )
    k = np.pi * np.arange(1, 4) / L
    assert bf.simply_supported_timoshenko_frequencies(L, EI, 5e7, rhoA, 0.0, 3) == pytest.approx(
        eb / np.sqrt(1 + EI * k**2 / 5e7), rel=1e-13
    )


def test_tip_mass_frequency_equation_against_tables():
    """Clamped-free beam with a tip mass (no rotary inertia): beta L = 1.24792 for
    M/(rho A L) = 1 and 1.41996 for 0.5 (Blevins, Formulas for natural frequency and mode
    shape, table 8-8); for a heavy mass the spring-mass estimate
    w^2 = 3EI/(L^3 (M + 33/140 m)) (Rayleigh) is approached from above."""
    assert bf.tip_mass_beta_l(1.0)[0] == pytest.approx(1.24792, abs=1e-5)
    assert bf.tip_mass_beta_l(0.5)[0] == pytest.approx(1.41996, abs=1e-5)
    assert bf.tip_mass_beta_l(0.0, n_modes=3) == pytest.approx(bf.CLAMPED_FREE_BETA_L, rel=1e-13)
    lam4 = bf.tip_mass_beta_l(100.0)[0] ** 4
    rayleigh = 3.0 / (100.0 + 33.0 / 140.0)
    assert 0.0 < rayleigh - lam4 < 1e-5 * rayleigh
    # rotary inertia and an offset centre of mass both lower the frequency
    assert bf.tip_mass_beta_l(1.0, 0.05)[0] < bf.tip_mass_beta_l(1.0)[0]
    assert bf.tip_mass_beta_l(1.0, 0.0, 0.1)[0] < bf.tip_mass_beta_l(1.0)[0]


def test_cantilever_with_tip_body_against_frequency_equation():
    """A rigid body at the tip (mass, rotary inertia, centre of mass offset along the
    axis) on an Euler-Bernoulli cantilever: the lowest two frequencies against the
    transcendental frequency equation (brentq), converging with the mesh; and the same
    body as a point mass on a stiff massless extension (an independent model of the
    offset)."""
    sec, L = fr.rectangle(0.08, 0.08), 2.0
    rhoA = RHO * sec.A
    M, J, e = 0.8 * rhoA * L, 0.05 * rhoA * L**3, 0.1 * L
    expected = bf.tip_mass_frequencies(L, E * sec.Iz, rhoA, M, J, e, n_modes=2)
    errors = []
    for n_el in (4, 16):
        frame, nodes = _cantilever(n_el, L, sec)
        frame.add_rigid_body(nodes[-1], M, (0.0, 0.0, J), offset=(e, 0.0))
        errors.append(_rel(frame.solve_modes(2).omega, expected))
    assert errors[1] < errors[0] / 10 and errors[1] < 1e-6
    # The offset body (J = 0) as a point mass on a rigid massless arm (a rigid link):
    # an independent model of the offset; same beam mesh, so the two agree to rounding.
    expected0 = bf.tip_mass_frequencies(L, E * sec.Iz, rhoA, M, 0.0, e, n_modes=2)
    offset_body, nodes = _cantilever(16, L, sec)
    offset_body.add_rigid_body(nodes[-1], M, 0.0, offset=(e, 0.0))
    frame, nodes = _cantilever(16, L, sec)
    arm = frame.add_node((L + e, 0.0))
    frame.add_rigid_link(nodes[-1], arm)
    frame.add_point_mass(arm, M)
    omega_arm, omega_body = frame.solve_modes(2).omega, offset_body.solve_modes(2).omega
    assert _rel(omega_arm, omega_body) < 1e-10
    assert omega_body[0] == pytest.approx(expected0[0], rel=1e-7)


def test_massless_cantilever_with_point_mass():
    """Massless beam + tip point mass: w = sqrt(3EI/(M L^3)) exactly; only the two tip
    translations carry mass, so only two (finite-frequency) modes exist."""
    sec, L, M = fr.tube(0.06, 0.004), 1.5, 20.0
    frame, nodes = _cantilever(3, L, sec, rho=0.0)
    frame.add_point_mass(nodes[-1], M)
    modes = frame.solve_modes(5)
    assert modes.omega.shape == (2,)  # ux and uy of the tip: the only masses
    assert modes.omega[0] == pytest.approx(math.sqrt(3 * E * sec.Iz / (M * L**3)), rel=1e-12)


def test_rigid_body_offset_static_weight():
    """A body of mass m whose centre of mass is offset by c from the tip node: its
    weight loads the tip with m g and the moment c x m g, so the tip deflection is
    P L^3/(3EI) + M L^2/(2EI)."""
    sec, L, m, c, g = fr.rectangle(0.1, 0.1), 2.0, 150.0, 0.4, 9.81
    frame, nodes = _cantilever(2, L, sec, rho=0.0)
    frame.add_rigid_body(nodes[-1], m, (1.0, 2.0, 3.0), offset=(c, 0.0))
    u = frame.solve_static(gravity=(0.0, -g)).displacements[nodes[-1]]
    EI = E * sec.Iz
    w = bf.cantilever_tip_load(-m * g, L, EI)[0] + bf.cantilever_end_moment(-m * g * c, L, EI)[0]
    assert u[1] == pytest.approx(w, rel=1e-11)


# ===================================================== frames.py: frames and hinges
@pytest.mark.parametrize("theory", THEORIES)
def test_l_frame_against_unit_load_method(theory):
    """Planar L-frame (column H, beam L, different sections), clamped base, tip load
    (Fx, Fy): displacements by the unit-load method with bending, axial and shear."""
    H, L, Fx, Fy = 3.0, 2.0, 400.0, -1500.0
    col, beam = fr.box(0.2, 0.2, 0.01), fr.rectangle(0.1, 0.15)
    frame = fr.Frame(planar=True)
    base = frame.add_node((0.0, 0.0))
    column = frame.add_beam_line((0.0, 0.0), (0.0, H), 3, E, G, col, 0.0, start_node=base, theory=theory)
    arm = frame.add_beam_line((0.0, H), (L, H), 2, E, G, beam, 0.0, start_node=column[-1], theory=theory)
    frame.fix(base)
    frame.add_nodal_load(arm[-1], (Fx, Fy))
    res = frame.solve_static()
    timo = theory == "timoshenko"
    dx, dy = bf.l_frame_tip_displacement(
        H,
        L,
        Fx,
        Fy,
        E * col.A,
        E * col.Iz,
        E * beam.A,
        E * beam.Iz,
        G * col.A if timo else None,
        G * beam.A if timo else None,
    )
    assert res.displacements[arm[-1], :2] == pytest.approx([dx, dy], rel=1e-11)
    assert res.reactions[base, [0, 1, 5]] == pytest.approx([-Fx, -Fy, Fx * H - Fy * L], rel=1e-11)


def test_l_grillage_3d_bending_and_torsion():
    """3D: an L in the horizontal x-y plane, clamped at the root, out-of-plane tip load:
    bending of both members about their height axis (Iy) plus torsion of the first
    (G J, J = Iy + Iz)."""
    L1, L2, P = 2.0, 1.2, -800.0
    s1, s2 = fr.rectangle(0.08, 0.12), fr.tube(0.1, 0.006)
    frame = fr.Frame()
    m1 = frame.add_beam_line((0, 0, 0), (L1, 0, 0), 2, E, G, s1)
    m2 = frame.add_beam_line((L1, 0, 0), (L1, L2, 0), 2, E, G, s2, start_node=m1[-1])
    frame.fix(m1[0])
    frame.add_nodal_load(m2[-1], (0.0, 0.0, P))
    w = frame.solve_static().displacements[m2[-1], 2]
    assert w == pytest.approx(
        bf.l_grillage_tip_deflection(P, L1, L2, E * s1.Iy, G * s1.J, E * s2.Iy), rel=1e-11
    )


def test_internal_hinge_planar_and_oblique_3d():
    """A beam clamped at both ends with a hinge at mid-span and a load P at the hinge:
    each half is a cantilever carrying P/2, w = (P/2)(L/2)^3/(3EI), and the rotations on
    the two sides of the hinge are opposite. The same beam tilted in 3D with the hinge
    axis along the (oblique) normal of its plane of bending gives the same answer."""
    sec, L, P = fr.circle(0.08), 3.0, -2000.0
    expected = bf.cantilever_tip_load(P / 2, L / 2, E * sec.Iz)
    frame = fr.Frame(planar=True)
    left = frame.add_beam_line((0.0, 0.0), (L / 2, 0.0), 2, E, G, sec)
    right_start = frame.add_node((L / 2, 0.0))
    right = frame.add_beam_line((L / 2, 0.0), (L, 0.0), 2, E, G, sec, start_node=right_start)
    frame.add_hinge(left[-1], right_start, axis=(0, 0, 1))
    frame.fix(left[0]), frame.fix(right[-1])
    frame.add_nodal_load(left[-1], (0.0, P))
    u = frame.solve_static().displacements
    assert u[left[-1], 1] == pytest.approx(expected[0], rel=1e-11)
    assert u[right_start, 1] == pytest.approx(expected[0], rel=1e-11)
    assert u[left[-1], 5] == pytest.approx(expected[1], rel=1e-11)
    assert u[right_start, 5] == pytest.approx(-expected[1], rel=1e-11)
    # 3D: beam along d, load along p (normal to d), hinge axis n = d x p (oblique)
    d = np.array([1.0, 2.0, 2.0]) / 3.0
    p = np.array([2.0, 1.0, -2.0]) / 3.0
    n = np.cross(d, p)
    frame = fr.Frame()
    left = frame.add_beam_line((0, 0, 0), L / 2 * d, 2, E, G, sec)
    right_start = frame.add_node(L / 2 * d)
    right = frame.add_beam_line(L / 2 * d, L * d, 2, E, G, sec, start_node=right_start)
    frame.add_hinge(left[-1], right_start, axis=n)
    frame.fix(left[0]), frame.fix(right[-1])
    frame.add_nodal_load(left[-1], P * p)
    u = frame.solve_static().displacements
    assert u[left[-1], :3] == pytest.approx(expected[0] * p, rel=1e-10, abs=1e-12 * abs(expected[0]))
    assert u[left[-1], 3:] @ n == pytest.approx(expected[1], rel=1e-10)
    assert u[right_start, 3:] @ n == pytest.approx(-expected[1], rel=1e-10)


def test_frame_rejects_bad_input():
    frame = fr.Frame(planar=True)
    a = frame.add_node((0.0, 0.0))
    with pytest.raises(ValueError, match="z = 0"):
        frame.add_node((0.0, 0.0, 1.0))
    b = frame.add_node((1.0, 0.0))
    with pytest.raises(ValueError, match="theory"):
        frame.add_beam(a, b, E, G, fr.circle(0.1), theory="bernoulli")
    with pytest.raises(ValueError, match="no node"):
        frame.add_beam(a, 7, E, G, fr.circle(0.1))
    frame.add_beam(a, b, E, G, fr.circle(0.1))
    with pytest.raises(ValueError, match="singular"):
        frame.solve_static()  # nothing fixed: a free body
    with pytest.raises(ValueError, match="is not at"):
        frame.add_hinge(a, b)


# ================================================================ mechanisms: pendulums
def test_pendulum_small_amplitude_period_and_energy():
    """Uniform rod hinged at one end: T = 2 pi sqrt(2L/(3g)) for small amplitude; the
    motion is A cos(2 pi t / T) about the hanging position; energy is conserved."""
    L, m, g, A = 1.3, 2.0, 9.81, 1e-4
    T = mc.pendulum_small_amplitude_period(L, m, g)
    assert T == pytest.approx(2 * math.pi * math.sqrt(2 * L / (3 * g)), rel=1e-15)
    t = np.linspace(0.0, 2 * T, 9)
    sol = mc.pendulum(t, -math.pi / 2 + A, 0.0, L, m, gravity=(0.0, -g))
    assert sol.angle + math.pi / 2 == pytest.approx(A * np.cos(2 * math.pi * t / T), abs=1e-5 * A)
    assert np.all(np.abs(sol.energy - sol.energy[0]) < 1e-10 * m * g * L)
    assert sol.tip[0] == pytest.approx([L * math.sin(A), -L * math.cos(A)], rel=1e-14)


def test_physical_pendulum_large_amplitude_elliptic_period():
    """Rod plus a point mass, released at rest from 2 rad off the vertical: the exact
    quarter period sqrt(I_O/(S g)) K(sin^2(a0/2)) (complete elliptic integral) brings it
    to the vertical, the half period to the mirror position."""
    L, m, Mp, d, g, a0 = 1.0, 1.5, 0.7, 0.8, 9.81, 2.0
    I_O, S = m * L**2 / 3 + Mp * d**2, m * L / 2 + Mp * d
    quarter = math.sqrt(I_O / (S * g)) * ellipk(math.sin(a0 / 2) ** 2)
    sol = mc.pendulum(
        [0.0, quarter, 2 * quarter],
        -math.pi / 2 + a0,
        0.0,
        L,
        m,
        (0.0, -g),
        point_mass=Mp,
        point_mass_distance=d,
    )
    assert sol.angle[1] == pytest.approx(-math.pi / 2, abs=1e-8)
    assert sol.angle[2] == pytest.approx(-math.pi / 2 - a0, abs=1e-8)
    assert sol.rate[1] == pytest.approx(-math.sqrt(2 * S * g * (1 - math.cos(a0)) / I_O), rel=1e-9)


def test_double_pendulum_energy_and_linear_modes():
    """Two equal uniform rods: the linearized frequencies are w^2 = (3 -/+ 6/sqrt 7) g/L
    (det(K - w^2 M) = 0 by hand); released in the first mode shape with a small amplitude
    it oscillates as that mode; a large release conserves energy."""
    L, m, g = 0.9, 1.2, 9.81
    omega, shapes = mc.double_pendulum_linear_frequencies((L, L), (m, m), g)
    assert omega**2 == pytest.approx(
        np.array([3 - 6 / math.sqrt(7), 3 + 6 / math.sqrt(7)]) * g / L, rel=1e-13
    )
    A = 1e-4 * shapes[:, 0] / np.max(np.abs(shapes[:, 0]))
    T = 2 * math.pi / omega[0]
    t = np.linspace(0.0, T, 5)
    sol = mc.double_pendulum(t, -math.pi / 2 + A, (0.0, 0.0), (L, L), (m, m), (0.0, -g))
    assert sol.angles + math.pi / 2 == pytest.approx(np.outer(np.cos(omega[0] * t), A), abs=1e-4 * 1e-4)
    t = np.linspace(0.0, 5.0, 201)
    sol = mc.double_pendulum(t, (0.3, -1.0), (0.0, 2.0), (L, 0.6), (m, 0.8), (0.0, -g))
    assert np.max(np.abs(sol.energy - sol.energy[0])) < 1e-9 * m * g * L
    assert np.linalg.norm(sol.tip - sol.knee, axis=1) == pytest.approx(0.6, rel=1e-14)


# ================================================================ mechanisms: slider-crank
def test_slider_crank_kinematics_and_power_balance():
    """Kinematics: x = r cos(theta) + sqrt(l^2 - r^2 sin^2 theta), the rod joins the crank
    pin to the slider, velocities are the time derivatives (central differences). Torque:
    the power balance tau omega = d(T + V)/dt (central differences of the energies)."""
    r, l, omega, th0 = 0.15, 0.5, 12.0, 0.3
    args = dict(
        crank_length=r,
        rod_length=l,
        crank_mass=2.0,
        rod_mass=3.0,
        slider_mass=4.0,
        omega=omega,
        theta0=th0,
        gravity=(0.0, -9.81),
    )
    t = np.linspace(0.0, 1.0, 37)
    sol = mc.slider_crank(t, **args)
    th = th0 + omega * t
    assert sol.slider_x == pytest.approx(
        r * np.cos(th) + np.sqrt(l**2 - r**2 * np.sin(th) ** 2), rel=1e-14
    )
    B = np.stack([sol.slider_x, np.zeros_like(t)], axis=1)
    assert np.linalg.norm(B - sol.crank_pin, axis=1) == pytest.approx(l, rel=1e-14)
    assert np.allclose(
        sol.crank_pin + l * np.stack([np.cos(sol.rod_angle), np.sin(sol.rod_angle)], 1), B, atol=1e-15
    )
    h = 1e-5
    up, down = mc.slider_crank(t + h, **args), mc.slider_crank(t - h, **args)
    scale = r * omega
    assert np.max(np.abs((up.slider_x - down.slider_x) / (2 * h) - sol.slider_velocity)) < 1e-8 * scale
    assert (
        np.max(np.abs((up.slider_velocity - down.slider_velocity) / (2 * h) - sol.slider_acceleration))
        < 1e-7 * scale * omega
    )
    assert (
        np.max(np.abs((up.rod_rate - down.rod_rate) / (2 * h) - sol.rod_acceleration)) < 1e-7 * omega**2
    )
    power = ((up.kinetic + up.potential) - (down.kinetic + down.potential)) / (2 * h)
    assert np.max(np.abs(sol.torque * omega - power)) < 1e-7 * np.max(np.abs(power))
    # spinning up: theta = theta0 + omega t + alpha t^2/2, the power is tau * theta'
    args["angular_acceleration"] = -7.0
    sol, up, down = (mc.slider_crank(t + dt, **args) for dt in (0.0, h, -h))
    power = ((up.kinetic + up.potential) - (down.kinetic + down.potential)) / (2 * h)
    assert np.max(np.abs(sol.torque * (omega - 7.0 * t) - power)) < 1e-7 * np.max(np.abs(power))
    assert sol.crank_angle == pytest.approx(th0 + omega * t - 3.5 * t**2, rel=1e-15)


def test_slider_crank_static_crank_torque():
    """Massless rod and slider: the torque only lifts the crank's own weight, m1 g (r/2)
    cos(theta) (the centripetal acceleration of its centre does no virtual work)."""
    r, m1, g = 0.2, 3.0, 9.81
    t = np.linspace(0.0, 2.0, 11)
    sol = mc.slider_crank(t, r, 0.7, m1, 0.0, 0.0, omega=5.0, theta0=0.1, gravity=(0.0, -g))
    assert sol.torque == pytest.approx(m1 * g * r / 2 * np.cos(sol.crank_angle), rel=1e-12, abs=1e-12)
    with pytest.raises(ValueError, match="rod_length"):
        mc.slider_crank(t, 0.5, 0.4, 1.0, 1.0, 1.0, omega=1.0)


# ================================================================ mechanisms: knuckle boom
KB = dict(
    boom_length=3.0,
    boom_mass=300.0,
    jib_length=2.5,
    jib_mass=150.0,
    boom_angle=math.radians(40.0),
    boom_point=(1.0, 0.15),
    jib_point=(0.6, 0.12),
    gravity=(0.0, -9.81),
    tip_load=(200.0, -500.0),
)


def _potential(boom_angle: float, actuator_length: float, branch: int) -> float:
    """Potential of gravity and the (constant) tip load for the knuckle boom."""
    st = mc.knuckle_boom_statics(
        **{**KB, "boom_angle": boom_angle}, actuator_length=actuator_length, branch=branch
    )
    g, F = np.array(KB["gravity"]), np.array(KB["tip_load"])
    c1 = 0.5 * (st.pivot + st.knuckle)
    c2 = 0.5 * (st.knuckle + st.tip)
    return float(-(KB["boom_mass"] * g @ c1 + KB["jib_mass"] * g @ c2 + F @ st.tip))


@pytest.mark.parametrize("branch", (1, -1))
def test_knuckle_boom_statics_equilibrium_and_virtual_work(branch):
    """Each rod is in equilibrium (forces and moments), the actuator has the prescribed
    length, and the forces agree with virtual work: actuator tension f = -dPi/dL and
    holding moment M_O = dPi/d(boom angle) (central differences of the potential Pi)."""
    lengths = np.array([1.8, 2.0, 2.2])
    st = mc.knuckle_boom_statics(**KB, actuator_length=lengths, branch=branch)
    assert np.linalg.norm(st.jib_point - st.boom_point, axis=1) == pytest.approx(lengths, rel=1e-13)
    g, F = np.array(KB["gravity"]), np.array(KB["tip_load"])
    m1, m2 = KB["boom_mass"], KB["jib_mass"]
    fu = st.actuator_force[:, None] * st.actuator_direction
    cross = lambda a, b: a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]  # noqa: E731
    c1 = 0.5 * (st.pivot + st.knuckle)
    c2 = 0.5 * (st.knuckle + st.tip)
    scale = (m1 + m2) * 9.81 * 5.0
    # jib: knuckle force, actuator push/pull -f u at Q, weight, tip load
    jib_f = st.knuckle_force - fu + m2 * g + F
    jib_m = (
        cross(st.knuckle, st.knuckle_force)
        + cross(st.jib_point, -fu)
        + cross(c2, m2 * g)
        + cross(st.tip, F)
    )
    # boom: ground force and moment, -knuckle force at B, +f u at P, weight
    boom_f = st.pivot_force - st.knuckle_force + fu + m1 * g
    boom_m = (
        st.pivot_moment
        + cross(st.knuckle, -st.knuckle_force)
        + cross(st.boom_point, fu)
        + cross(c1, m1 * g)
    )
    for residual in (jib_f, boom_f):
        assert np.max(np.abs(residual)) < 1e-12 * scale
    for residual in (jib_m, boom_m):
        assert np.max(np.abs(residual)) < 1e-12 * scale
    h = 1e-6
    for i, L in enumerate(lengths):
        dPi_dL = (
            _potential(KB["boom_angle"], L + h, branch) - _potential(KB["boom_angle"], L - h, branch)
        ) / (2 * h)
        dPi_da = (
            _potential(KB["boom_angle"] + h, L, branch) - _potential(KB["boom_angle"] - h, L, branch)
        ) / (2 * h)
        assert st.actuator_force[i] == pytest.approx(-dPi_dL, rel=1e-6)
        assert st.pivot_moment[i] == pytest.approx(dPi_da, rel=1e-6)
    with pytest.raises(ValueError, match="out of reach"):
        mc.knuckle_boom_statics(**KB, actuator_length=5.0)


def test_knuckle_boom_with_lift_cylinder():
    """With a lift cylinder the ground moment vanishes and the boom is in equilibrium
    under pivot force, lift force, knuckle force, actuator force and weight; the lift
    force equals the held moment divided by its moment arm, and agrees with virtual
    work: f_lift = -dPi/dL_lift with the boom angle moving with the lift length."""
    ground, lug = (0.5, -0.4), (1.2, -0.1)
    lengths = np.array([1.9, 2.1])
    st = mc.knuckle_boom_statics(
        **KB, actuator_length=lengths, branch=-1, lift_ground_point=ground, lift_boom_point=lug
    )
    held = mc.knuckle_boom_statics(**KB, actuator_length=lengths, branch=-1)
    cross = lambda a, b: a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]  # noqa: E731
    g, m1 = np.array(KB["gravity"]), KB["boom_mass"]
    fl = st.lift_force[:, None] * st.lift_direction
    fu = st.actuator_force[:, None] * st.actuator_direction
    c1 = 0.5 * (st.pivot + st.knuckle)
    scale = 450.0 * 9.81 * 5.0
    assert np.all(st.pivot_moment == 0.0) and st.knuckle_force == pytest.approx(
        held.knuckle_force, rel=1e-14
    )
    assert np.max(np.abs(st.pivot_force + fl - st.knuckle_force + fu + m1 * g)) < 1e-12 * scale
    moments = (
        cross(st.lift_boom_point, fl)
        + cross(st.knuckle, -st.knuckle_force)
        + cross(st.boom_point, fu)
        + cross(c1, m1 * g)
    )
    assert np.max(np.abs(moments)) < 1e-12 * scale
    # virtual work: the boom angle as a function of the lift length (|G - P2(a)| = L_lift)
    lug_vec = np.array(lug)

    def lift_length(angle: float) -> float:
        e = np.array([math.cos(angle), math.sin(angle)])
        return float(
            np.linalg.norm(np.array(ground) - (lug_vec[0] * e + lug_vec[1] * np.array([-e[1], e[0]])))
        )

    h = 1e-6
    a0 = KB["boom_angle"]
    dL_da = (lift_length(a0 + h) - lift_length(a0 - h)) / (2 * h)
    for i, L in enumerate(lengths):
        dPi_da = (_potential(a0 + h, L, -1) - _potential(a0 - h, L, -1)) / (2 * h)
        assert st.lift_force[i] == pytest.approx(-dPi_da / dL_da, rel=1e-6)


def _knuckle_frame(p: dict, n_el: int, theory: str, actuator_EA: float):
    """frames.py model of the flexible knuckle boom: boom clamped at O, jib hinged at B
    (coincident nodes, translations tied), the actuator an axial bar P-Q."""
    frame = fr.Frame(planar=True)
    e1 = np.array([math.cos(p["boom_angle"]), math.sin(p["boom_angle"])])
    st = mc.knuckle_boom_statics(
        p["L1"],
        p["m1"],
        p["L2"],
        p["m2"],
        p["boom_angle"],
        (p["sP"], 0.0),
        (p["sQ"], 0.0),
        p["L"],
        p["g"],
        p["F"],
        p["branch"],
    )
    e2 = np.array([math.cos(st.jib_angle), math.sin(st.jib_angle)])
    B = p["L1"] * e1
    boom = frame.add_beam_line(
        (0.0, 0.0),
        B,
        n_el,
        E,
        G,
        p["s1"],
        p["m1"] / (p["s1"].A * p["L1"]),
        interior=[p["sP"] / p["L1"]],
        theory=theory,
    )
    jib = frame.add_beam_line(
        B,
        B + p["L2"] * e2,
        n_el,
        E,
        G,
        p["s2"],
        p["m2"] / (p["s2"].A * p["L2"]),
        interior=[p["sQ"] / p["L2"]],
        theory=theory,
    )
    frame.fix(boom[0])
    frame.add_hinge(boom[-1], jib[0])
    nodes = frame.nodes
    P_node = boom[int(np.argmin(np.linalg.norm(nodes[boom, :2] - p["sP"] * e1, axis=1)))]
    Q_node = jib[int(np.argmin(np.linalg.norm(nodes[jib, :2] - (B + p["sQ"] * e2), axis=1)))]
    frame.add_bar(P_node, Q_node, actuator_EA)
    frame.add_nodal_load(jib[-1], p["F"])
    return frame.solve_static(gravity=p["g"]).displacements, boom, jib, P_node, Q_node


@pytest.mark.parametrize("theory", THEORIES)
@pytest.mark.parametrize("actuator_EA", (2.0e8, 2.0e11))
def test_knuckle_boom_flexible_sag_against_frames(theory, actuator_EA):
    """The superposition formula for the flexible knuckle boom against frames.py built
    for the same structure (boom clamped, jib hinged, actuator a bar): displacements of
    the tip, the knuckle and both actuator ends agree to rounding (both are exact for
    this statically determinate structure under point and uniform loads)."""
    p = dict(
        L1=3.0,
        m1=300.0,
        L2=2.5,
        m2=150.0,
        boom_angle=math.radians(40.0),
        sP=1.0,
        sQ=0.6,
        L=2.45,
        g=(0.0, -9.81),
        F=(150.0, -2000.0),
        branch=-1,
        s1=fr.box(0.2, 0.12, 0.008),
        s2=fr.box(0.15, 0.1, 0.006),
    )
    timo = theory == "timoshenko"
    sag = mc.knuckle_boom_flexible_sag(
        p["L1"],
        p["m1"],
        p["L2"],
        p["m2"],
        p["boom_angle"],
        p["sP"],
        p["sQ"],
        p["L"],
        boom_EA=E * p["s1"].A,
        boom_EI=E * p["s1"].Iz,
        jib_EA=E * p["s2"].A,
        jib_EI=E * p["s2"].Iz,
        boom_GAs=G * p["s1"].A if timo else None,
        jib_GAs=G * p["s2"].A if timo else None,
        actuator_EA=actuator_EA,
        gravity=p["g"],
        tip_load=p["F"],
        branch=p["branch"],
    )
    assert -math.pi / 2 < sag.statics.jib_angle < 0.0  # the jib points out and down
    u, boom, jib, P_node, Q_node = _knuckle_frame(p, 3, theory, actuator_EA)
    scale = np.linalg.norm(sag.tip)
    for got, ref in (
        (u[jib[-1], :2], sag.tip),
        (u[boom[-1], :2], sag.knuckle),
        (u[P_node, :2], sag.boom_point),
        (u[Q_node, :2], sag.jib_point),
    ):
        assert np.max(np.abs(got - ref)) < 1e-9 * scale
    e2 = np.array([math.cos(sag.statics.jib_angle), math.sin(sag.statics.jib_angle)])
    assert sag.tip_transverse == pytest.approx(u[jib[-1], :2] @ np.array([-e2[1], e2[0]]), rel=1e-9)
    assert sag.tip_transverse < 0.0  # it sags
