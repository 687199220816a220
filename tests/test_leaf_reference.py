"""The two-leaf spring reference (python/ancfdrv/leaf_reference.py, docs/leaf_spring.md)
against independent references:

* textbook straight-beam formulas (radius -> inf): L^3/3EI, a^2 (3L - a)/6EI, the
  classic two-leaf R = P (3L - a)/(4a), Timoshenko's L/(kGA), the prestress preload;
* an exact Hermite-cubic finite-element model of the straight two-leaf spring (nodal
  values exact for nodal point loads, uniform loads and uniform eigen-curvature);
* scipy.integrate.solve_bvp of the curved-beam equations (u' = theta x t + strains,
  theta' = M/EI + kappa0, M' = -t x F, F' = -q) for the curved two-leaf spring, with
  contact spring, weight, prestress, and eye free or held;
* a direct distance minimization for the contact geometry;
* linearity, superposition, Maxwell reciprocity and scaling properties.

The module imports only numpy, so it is loaded from its file when the installed
package is older than the working tree.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_bvp
from scipy.optimize import minimize_scalar

sys.path.insert(0, str(Path(__file__).resolve().parent))
from reference import leaf_reference as lr  # noqa: E402  (tests/reference: never imported by a run)


SPEC = lr.SPEC
EI = lr.BEAM_EI
L, A = SPEC.main_length, SPEC.lower_length
P = SPEC.chassis_weight / 2.0
INF = math.inf


# ---------------------------------------------------------------------------
# independent reference 1: exact straight-beam Hermite FE of the two-leaf spring
# ---------------------------------------------------------------------------

def _hermite_k(ell: float, ei: float) -> np.ndarray:
    return ei / ell**3 * np.array([[12, 6 * ell, -12, 6 * ell],
                                   [6 * ell, 4 * ell**2, -6 * ell, 2 * ell**2],
                                   [-12, -6 * ell, 12, -6 * ell],
                                   [6 * ell, 2 * ell**2, -6 * ell, 4 * ell**2]])


def straight_two_leaf_fe(P: float, ei: float, L: float, a: float, *, kc: float = INF,
                         q: float = 0.0, kappa0: float = 0.0, g0: float = 0.0,
                         mu: float = 0.0, h: float = SPEC.thickness):
    """Straight leaves, w upward, dofs (w, theta): main nodes 0, a, L (0..5), lower
    nodes 0, a (6..9). The contact force R acts up on the main leaf at a, down on the
    lower tip; friction mu R along +x on the main leaf's lower surface (-x on the lower
    leaf's upper surface) adds the moments +mu R h/2 to both leaves at a.
    Returns (eye deflection down, R, slip of the main leaf's lower surface relative to
    the lower leaf's upper surface along +x)."""
    K = np.zeros((10, 10))
    f = np.zeros(10)

    def element(d0: int, ell: float, eigen: float):
        dofs = [d0, d0 + 1, d0 + 2, d0 + 3]
        K[np.ix_(dofs, dofs)] += _hermite_k(ell, ei)
        f[dofs] += -q * np.array([ell / 2, ell**2 / 12, ell / 2, -ell**2 / 12])
        f[d0 + 1] -= ei * eigen
        f[d0 + 3] += ei * eigen

    element(0, a, 0.0)
    element(2, L - a, 0.0)
    element(6, a, kappa0)
    f[4] -= P
    c = np.zeros(10)       # gap = g0 + c . w
    c[2], c[8] = 1.0, -1.0
    load_r = c.copy()      # nodal forces per unit R: normal force and friction moments
    load_r[3] += mu * h / 2
    load_r[9] += mu * h / 2
    free = [2, 3, 4, 5, 8, 9]
    n = len(free)
    if math.isinf(kc):  # R = -lambda, constraint c . w = -g0
        M = np.zeros((n + 1, n + 1))
        M[:n, :n] = K[np.ix_(free, free)]
        M[:n, n] = load_r[free]
        M[n, :n] = c[free]
        sol = np.linalg.solve(M, np.concatenate([f[free], [-g0]]))
        w = np.zeros(10)
        w[free] = sol[:n]
        R = -sol[n]
    else:  # R = -kc (g0 + c . w)
        Kf = K + kc * np.outer(load_r, c)
        ff = f - kc * load_r * g0
        w = np.zeros(10)
        w[free] = np.linalg.solve(Kf[np.ix_(free, free)], ff[free])
        R = -kc * (g0 + c @ w)
    slip = h / 2 * (w[3] + w[9])
    return -w[4], R, slip


# ---------------------------------------------------------------------------
# independent reference 2: solve_bvp of the curved two-leaf half spring
# ---------------------------------------------------------------------------

def curved_two_leaf_bvp(P, ei, *, L, a, Rm, Rl, s_c, angle, g0, kc, h=SPEC.thickness,
                        q=0.0, kappa0=0.0, eye_fixed=False, ea=INF, gas=INF, mu=0.0):
    """Segments main [0, s_c], main [s_c, L], lower [0, a], each mapped to tau in [0, 1];
    state (ux, uz, theta, M, Fx, Fz), F the external force on the part beyond s.
    Unknown parameter: the contact force R (along n on the main leaf), applied to the
    lower leaf at its tip's upper corner, h/2 along its normal from the mid-surface;
    friction mu R along the tangent t (toward the eye) on the main leaf's lower surface,
    -mu R t on the lower tip's corner."""
    segs = [(0.0, s_c, Rm, 0.0), (s_c, L - s_c, Rm, 0.0), (0.0, a, Rl, kappa0)]
    nx, nz = -math.sin(angle), math.cos(angle)
    dx, dz = -h / 2 * math.sin(a / Rl), h / 2 * math.cos(a / Rl)  # mid -> corner
    tx, tz = nz, -nx
    fx, fz = nx + mu * tx, nz + mu * tz  # force on the main leaf per unit R
    arm = dx * -fz - dz * -fx  # moment of the force on the lower leaf about its mid point
    inv_kc = 0.0 if math.isinf(kc) else 1.0 / kc

    def fun(tau, y, p):
        dy = np.empty_like(y)
        for k, (s0, ell, rad, k0) in enumerate(segs):
            ux, uz, th, M, Fx, Fz = y[6 * k:6 * k + 6]
            phi = (s0 + ell * tau) / rad
            tx, tz = np.cos(phi), np.sin(phi)
            eps = (Fx * tx + Fz * tz) / ea
            gam = (-Fx * tz + Fz * tx) / gas
            dy[6 * k + 0] = ell * (-th * tz + eps * tx - gam * tz)
            dy[6 * k + 1] = ell * (th * tx + eps * tz + gam * tx)
            dy[6 * k + 2] = ell * (M / ei + k0)
            dy[6 * k + 3] = -ell * (tx * Fz - tz * Fx)
            dy[6 * k + 4] = 0.0
            dy[6 * k + 5] = ell * q
        return dy

    def bc(ya, yb, p):
        R = p[0]
        A_, B_, C_ = slice(0, 6), slice(6, 12), slice(12, 18)
        a0, a1, b0, b1, c0, c1 = ya[A_], yb[A_], ya[B_], yb[B_], ya[C_], yb[C_]
        eye = b1[0] if eye_fixed else b1[4]
        corner_x, corner_z = c1[0] - c1[2] * dz, c1[1] + c1[2] * dx  # u + theta x d
        gap = g0 + nx * (a1[0] - corner_x) + nz * (a1[1] - corner_z)
        return np.array([
            a0[0], a0[1], a0[2],
            a1[0] - b0[0], a1[1] - b0[1], a1[2] - b0[2], a1[3] - b0[3] - R * mu * h / 2,
            a1[4] - b0[4] - R * fx, a1[5] - b0[5] - R * fz,
            b1[3], eye, b1[5] + P,
            c0[0], c0[1], c0[2],
            c1[3] - R * arm, c1[4] + R * fx, c1[5] + R * fz,
            R * inv_kc + gap,
        ])

    tau = np.linspace(0.0, 1.0, 9)
    sol = solve_bvp(fun, bc, tau, np.zeros((18, tau.size)), p=[P], tol=1e-9,
                    max_nodes=2000)
    assert sol.success, sol.message
    yb = sol.sol(1.0)
    return {"deflection": -yb[7], "outward": yb[6], "reaction": sol.p[0]}


# ---------------------------------------------------------------------------
# bending stiffness bounds
# ---------------------------------------------------------------------------

def test_bending_stiffness_bounds():
    b = lr.bending_stiffness_bounds()
    assert b["beam"] == pytest.approx(2.1e11 * 0.07 * 0.014**3 / 12, rel=1e-14)
    assert b["plate"] == pytest.approx(b["beam"] / (1 - 0.3**2), rel=1e-14)
    assert lr.BEAM_EI == b["beam"] and lr.PLATE_DW == b["plate"]
    assert lr.plate_bending_stiffness(poisson_ratio=0.0) == pytest.approx(
        lr.beam_bending_stiffness(), rel=1e-15)


# ---------------------------------------------------------------------------
# one cantilever
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("radius", [INF, 1.0e6])
def test_straight_limit_compliances(radius):
    assert lr.curved_cantilever_compliance(L, radius, EI) == pytest.approx(
        L**3 / (3 * EI), rel=1e-10)
    assert lr.curved_cantilever_compliance(L, radius, EI, load_at=A) == pytest.approx(
        A**2 * (3 * L - A) / (6 * EI), rel=1e-10)
    cf = lr.curved_cantilever_tip_compliances_closed_form(L, radius, EI)
    assert cf["zz"] == pytest.approx(L**3 / (3 * EI), rel=1e-10)


def test_straight_limit_shear_and_axial():
    ea, gas = SPEC.axial_stiffness, SPEC.shear_stiffness
    tip_z = lr.curved_cantilever_compliance(L, INF, EI, shear_stiffness=gas,
                                            axial_stiffness=ea)
    assert tip_z == pytest.approx(L**3 / (3 * EI) + L / gas, rel=1e-12)  # Timoshenko
    f = lr.cantilever_flexibility(INF, EI, [lr.UnitLoad(L, 1.0, 0.0)], axial_stiffness=ea)
    assert f[0, 0] == pytest.approx(L / ea, rel=1e-12)
    # curved: shear and axial add less than 1e-3 of the bending compliance
    bend = lr.curved_cantilever_compliance(L, 2.0, EI)
    full = lr.curved_cantilever_compliance(L, 2.0, EI, shear_stiffness=gas, axial_stiffness=ea)
    assert 0.0 < full / bend - 1.0 < 1e-3


def _single_cantilever_bvp(radius, length, force, ei=EI):
    """Tip (ux, uz) of a curved cantilever under a tip force (fx, fz), by solve_bvp."""
    fx, fz = force

    def fun(s, y):
        ux, uz, th, M = y
        tx, tz = np.cos(s / radius), np.sin(s / radius)
        return np.vstack([-th * tz, th * tx, M / ei, -(tx * fz - tz * fx)])

    def bc(ya, yb):
        return np.array([ya[0], ya[1], ya[2], yb[3]])

    s = np.linspace(0.0, length, 7)
    sol = solve_bvp(fun, bc, s, np.zeros((4, s.size)), tol=1e-10)
    assert sol.success
    return sol.sol(length)[:2]


def test_curved_tip_compliances_against_bvp_and_quadrature():
    R = 2.0
    cf = lr.curved_cantilever_tip_compliances_closed_form(L, R, EI)
    ux, uz = _single_cantilever_bvp(R, L, (0.0, -1.0))
    assert -uz == pytest.approx(cf["zz"], rel=1e-7)
    assert ux == pytest.approx(cf["xz"], rel=1e-7)          # outward under a down load
    ux, uz = _single_cantilever_bvp(R, L, (1.0, 0.0))
    assert ux == pytest.approx(cf["xx"], rel=1e-7)
    assert -uz == pytest.approx(cf["xz"], rel=1e-7)         # reciprocity
    assert lr.curved_cantilever_compliance(L, R, EI) == pytest.approx(cf["zz"], rel=1e-12)
    # the small-angle series branch agrees with the closed form at its switch point
    r_switch = L / 0.05
    lo = lr.curved_cantilever_tip_compliances_closed_form(L, r_switch * 1.000001, EI)
    hi = lr.curved_cantilever_tip_compliances_closed_form(L, r_switch * 0.999999, EI)
    for key in ("zz", "xz", "xx"):
        assert lo[key] == pytest.approx(hi[key], rel=1e-5)


def test_maxwell_reciprocity_curved_bvp():
    """Deflection at s = 0.4 under a tip load equals the tip deflection under a load at
    0.4 (solve_bvp for the first, the module's quadrature for the second)."""
    R, s1 = 2.0, 0.4

    def fun(s, y):
        ux, uz, th, M = y
        tx, tz = np.cos(s / R), np.sin(s / R)
        return np.vstack([-th * tz, th * tx, M / EI, -(tx * -1.0)])

    sol = solve_bvp(fun, lambda ya, yb: np.array([ya[0], ya[1], ya[2], yb[3]]),
                    np.linspace(0, L, 7), np.zeros((4, 7)), tol=1e-10)
    assert -sol.sol(s1)[1] == pytest.approx(
        lr.curved_cantilever_compliance(L, R, EI, load_at=s1), rel=1e-7)


# ---------------------------------------------------------------------------
# contact geometry
# ---------------------------------------------------------------------------

def _gap_by_minimization(Rm, Rl, a, h, off):
    al = a / Rl
    corner = np.array([Rl * math.sin(al), -off + Rl * (1 - math.cos(al))]) \
        + h / 2 * np.array([-math.sin(al), math.cos(al)])

    def surface(s):  # main leaf's lower surface
        ph = s / Rm
        return np.array([Rm * math.sin(ph), Rm * (1 - math.cos(ph))]) \
            - h / 2 * np.array([-math.sin(ph), math.cos(ph)])

    res = minimize_scalar(lambda s: np.sum((surface(s) - corner) ** 2),
                          bounds=(0.3, 0.5), method="bounded",
                          options={"xatol": 1e-12})
    ph = res.x / Rm
    n = np.array([-math.sin(ph), math.cos(ph)])
    return res.x, float(np.dot(surface(res.x) - corner, n))


@pytest.mark.parametrize("Rl", [lr.SPEC_LITERAL_LOWER_RADIUS, lr.CONCENTRIC_LOWER_RADIUS, 1.95])
def test_contact_geometry(Rl):
    geo = lr.contact_geometry(SPEC.main_radius, Rl, A, SPEC.thickness, SPEC.lower_offset)
    s_c, gap = _gap_by_minimization(SPEC.main_radius, Rl, A, SPEC.thickness,
                                    SPEC.lower_offset)
    assert geo["arc_length"] == pytest.approx(s_c, abs=1e-8)
    assert geo["gap"] == pytest.approx(gap, abs=1e-9)
    assert geo["normal_angle"] == pytest.approx(s_c / SPEC.main_radius, abs=1e-8)
    if Rl == lr.CONCENTRIC_LOWER_RADIUS:
        assert abs(geo["gap"]) < 1e-14
    straight = lr.contact_geometry(INF, INF, A, SPEC.thickness, SPEC.lower_offset)
    assert straight["arc_length"] == A and straight["gap"] == 0.0


# ---------------------------------------------------------------------------
# two leaves, straight limit
# ---------------------------------------------------------------------------

def test_two_leaf_straight_classic():
    st = lr.two_leaf_half_stiffness(EI, main_radius=INF, lower_radius=INF)
    ratio = (3 * L - A) / (4 * A)
    assert st["reaction_ratio"] == pytest.approx(ratio, rel=1e-12)
    delta = (L**3 / 3 - ratio * A**2 * (3 * L - A) / 6) / EI
    assert st["compliance"] == pytest.approx(delta, rel=1e-12)
    assert st["compliance_main_alone"] == pytest.approx(L**3 / (3 * EI), rel=1e-12)


@pytest.mark.parametrize("kc, q, kappa0, g0", [
    (INF, 0.0, 0.0, 0.0),
    (3.0e6, 0.0, 0.0, 0.0),
    (3.0e6, SPEC.line_weight, 0.0, 0.0),
    (INF, SPEC.line_weight, 1 / 1.5, -2e-4),
    (3.0e6, SPEC.line_weight, 1 / 1.5, 1e-4),
])
def test_two_leaf_straight_against_hermite_fe(kc, q, kappa0, g0):
    free_r = None if kappa0 == 0.0 else 1.0 / kappa0
    st = lr.two_leaf_half(P, EI, main_radius=INF, lower_radius=INF, contact_stiffness=kc,
                          line_weight=q, lower_free_radius=free_r, initial_gap=g0)
    delta, R, slip = straight_two_leaf_fe(P, EI, L, A, kc=kc, q=q, kappa0=kappa0, g0=g0)
    assert R > 0 and not st["contact_open"]
    assert st["reaction"] == pytest.approx(R, rel=1e-9)
    assert st["deflection"] == pytest.approx(delta, rel=1e-9)
    assert st["slip"] == pytest.approx(slip, rel=1e-9)


@pytest.mark.parametrize("mu, kc", [(0.3, INF), (-0.3, 3.0e6)])
def test_two_leaf_straight_friction_against_hermite_fe(mu, kc):
    st = lr.two_leaf_half(P, EI, main_radius=INF, lower_radius=INF, contact_stiffness=kc,
                          lower_free_radius=1.5, friction=mu)
    delta, R, slip = straight_two_leaf_fe(P, EI, L, A, kc=kc, kappa0=1 / 1.5, mu=mu)
    assert st["reaction"] == pytest.approx(R, rel=1e-9)
    assert st["deflection"] == pytest.approx(delta, rel=1e-9)
    assert st["slip"] == pytest.approx(slip, rel=1e-9)
    # loading: the main leaf slides toward the axle, so friction on it points outward
    # (+mu) and stiffens the spring
    _, _, slip0 = straight_two_leaf_fe(P, EI, L, A)
    assert slip0 < 0
    k = {m: lr.two_leaf_half_stiffness(EI, main_radius=INF, lower_radius=INF,
                                       friction=m)["k_half"] for m in (-0.3, 0.0, 0.3)}
    assert k[-0.3] < k[0.0] < k[0.3]


def test_prestress_straight_closed_form():
    kappa0 = 1 / 1.5
    pre = lr.prestress_preload(EI, lower_free_radius=1.5, main_radius=INF, lower_radius=INF)
    r0 = 3 * EI * kappa0 / (4 * A)  # misfit kappa0 a^2/2 over the two a^3/3EI
    assert pre["free_tip_lift"] == pytest.approx(kappa0 * A**2 / 2, rel=1e-12)
    assert pre["R0"] == pytest.approx(r0, rel=1e-12)
    assert pre["eye_lift"] == pytest.approx(r0 * A**2 * (3 * L - A) / (6 * EI), rel=1e-12)
    assert pre["R0_rigid_main"] == pytest.approx(3 * EI * kappa0 / (2 * A), rel=1e-12)


# ---------------------------------------------------------------------------
# two leaves, curved (SPEC): against solve_bvp
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("case", [
    dict(kc=INF, q=0.0, free_r=None, eye_fixed=False, Rl=SPEC.lower_radius),
    dict(kc=3.0e6, q=SPEC.line_weight, free_r=1.5, eye_fixed=False, Rl=SPEC.lower_radius),
    dict(kc=3.0e6, q=SPEC.line_weight, free_r=1.5, eye_fixed=False, Rl=1.986),
    dict(kc=3.0e6, q=SPEC.line_weight, free_r=None, eye_fixed=True, Rl=1.986,
         ea=SPEC.axial_stiffness, gas=SPEC.shear_stiffness),
    dict(kc=3.0e6, q=SPEC.line_weight, free_r=1.5, eye_fixed=False, Rl=1.986, mu=0.3),
    dict(kc=INF, q=0.0, free_r=None, eye_fixed=False, Rl=SPEC.lower_radius, mu=-0.3),
])
def test_two_leaf_curved_against_bvp(case):
    ea, gas = case.get("ea", INF), case.get("gas", INF)
    Rl = case["Rl"]
    geo = lr.contact_geometry(lower_radius=Rl)
    kappa0 = 0.0 if case["free_r"] is None else 1 / case["free_r"] - 1 / Rl
    st = lr.two_leaf_half(P, EI, contact_stiffness=case["kc"], line_weight=case["q"],
                          lower_free_radius=case["free_r"],
                          eye_horizontal_stiffness=INF if case["eye_fixed"] else 0.0,
                          axial_stiffness=ea, shear_stiffness=gas, lower_radius=Rl,
                          friction=case.get("mu", 0.0))
    ref = curved_two_leaf_bvp(P, EI, L=L, a=A, Rm=SPEC.main_radius, Rl=Rl,
                              s_c=geo["arc_length"], angle=geo["normal_angle"],
                              g0=geo["gap"], kc=case["kc"], q=case["q"],
                              kappa0=kappa0, eye_fixed=case["eye_fixed"], ea=ea, gas=gas,
                              mu=case.get("mu", 0.0))
    assert not st["contact_open"]
    assert st["reaction"] == pytest.approx(ref["reaction"], rel=1e-8)
    assert st["deflection"] == pytest.approx(ref["deflection"], rel=1e-8)
    if case["eye_fixed"]:
        assert abs(st["eye_outward"]) < 1e-12
    else:
        assert st["eye_outward"] == pytest.approx(ref["outward"], rel=1e-8)


def test_interleaf_gap_opens_between_axle_and_tip():
    """Straight leaves, rigid contact: the leaves separate by x^2/(6EI) (2R(3a - x) -
    P(3L - x)) >= 0 between the axle and the tip (they touch only at the tip)."""
    x = np.linspace(0.05, A, 8)
    got = lr.interleaf_gap_change(P, EI, x, main_radius=INF, lower_radius=INF)
    R = P * (3 * L - A) / (4 * A)
    assert got == pytest.approx(x**2 / (6 * EI) * (2 * R * (3 * A - x) - P * (3 * L - x)),
                                rel=1e-9, abs=1e-15)
    curved = lr.interleaf_gap_change(P, EI, x[:-1], lower_free_radius=1.5)
    assert np.all(curved > 0)


def test_prestress_linear_tip_lift_close_to_exact_arc():
    """The linearized free-tip lift kappa0 int m ds against the exact arc geometry."""
    pre = lr.prestress_preload(EI)
    al_f, al_a = A / 1.5, A / SPEC.lower_radius
    p_free = np.array([1.5 * math.sin(al_f), 1.5 * (1 - math.cos(al_f))])
    p_asm = np.array([SPEC.lower_radius * math.sin(al_a),
                      SPEC.lower_radius * (1 - math.cos(al_a))])
    ang = lr.contact_geometry()["normal_angle"]
    exact = float(np.dot(p_free - p_asm, [-math.sin(ang), math.cos(ang)]))
    assert pre["free_tip_lift"] == pytest.approx(exact, rel=5e-3)


# ---------------------------------------------------------------------------
# linearity, superposition, scaling, contact opening
# ---------------------------------------------------------------------------

def test_linearity_and_superposition():
    kw = dict(contact_stiffness=3.0e6, initial_gap=0.0)
    d1 = lr.two_leaf_half(P, EI, **kw)
    d2 = lr.two_leaf_half(2.5 * P, EI, **kw)
    assert d2["deflection"] == pytest.approx(2.5 * d1["deflection"], rel=1e-12)
    assert d2["reaction"] == pytest.approx(2.5 * d1["reaction"], rel=1e-12)
    full = lr.two_leaf_half(P, EI, lower_free_radius=1.5, line_weight=SPEC.line_weight, **kw)
    pre = lr.two_leaf_half(0.0, EI, lower_free_radius=1.5, **kw)
    wt = lr.two_leaf_half(0.0, EI, lower_free_radius=1.5, line_weight=SPEC.line_weight,
                          **kw)
    assert full["deflection"] == pytest.approx(
        d1["deflection"] + wt["deflection"], rel=1e-10)
    assert full["deflection"] - pre["deflection"] == pytest.approx(
        d1["deflection"] + wt["deflection"] - pre["deflection"], rel=1e-10)
    k = lr.two_leaf_half_stiffness(EI, contact_stiffness=3.0e6)["k_half"]
    assert P / k == pytest.approx(d1["deflection"], rel=1e-12)


def test_rigid_contact_stiffness_scales_with_bending_stiffness():
    kb = lr.two_leaf_half_stiffness(lr.BEAM_EI)
    kp = lr.two_leaf_half_stiffness(lr.PLATE_DW)
    assert kp["k_half"] / kb["k_half"] == pytest.approx(1 / (1 - 0.3**2), rel=1e-12)
    assert kp["reaction_ratio"] == pytest.approx(kb["reaction_ratio"], rel=1e-12)
    # a softer contact spring: a stiffness between the main leaf alone and rigid contact
    kc = lr.two_leaf_half_stiffness(lr.BEAM_EI, contact_stiffness=3.0e6)
    assert kb["k_main_alone"] < kc["k_half"] < kb["k_half"]


def test_contact_opens_under_upward_pull_only():
    pre = lr.prestress_preload(EI)
    r_ratio = lr.two_leaf_half_stiffness(EI)["reaction_ratio"]
    p_open = -pre["R0"] / r_ratio
    just_closed = lr.two_leaf_half(0.99 * p_open, EI, lower_free_radius=1.5)
    opened = lr.two_leaf_half(1.01 * p_open, EI, lower_free_radius=1.5)
    assert not just_closed["contact_open"] and opened["contact_open"]
    assert opened["reaction"] == 0.0 and opened["gap"] > 0.0
    # an open contact: the main leaf alone carries the eye load
    main = lr.curved_cantilever_compliance(L, SPEC.main_radius, EI)
    up = lr.two_leaf_half(-1000.0, EI, initial_gap=0.0)
    assert up["contact_open"] and up["deflection"] == pytest.approx(-1000.0 * main,
                                                                    rel=1e-12)
    cyc = lr.load_cycle(EI, prestress=True)
    assert cyc["contact_opens"] == 0.0
    assert cyc["opening_force"] == pytest.approx(2 * p_open, rel=1e-9)
    assert cyc["reaction_at_zero"] == pytest.approx(pre["R0"], rel=1e-12)


# ---------------------------------------------------------------------------
# chassis, load cycle, frequency
# ---------------------------------------------------------------------------

def test_chassis_drop_straight_against_hermite_fe():
    spec = lr.LeafSpringSpec(main_radius=INF, lower_radius=INF)
    g = spec.gravity
    W = spec.chassis_weight
    for prestress in (False, True):
        out = lr.chassis_static_drop(EI, prestress=prestress, contact_stiffness=3.0e6,
                                     spec=spec)
        kappa0 = 1 / 1.5 if prestress else 0.0
        front = straight_two_leaf_fe(W / 2, EI, L, A, kc=3.0e6, q=spec.line_weight,
                                     kappa0=kappa0)[0]
        rear = straight_two_leaf_fe(W / 2 + 2.0 * g, EI, L, A, kc=3.0e6,
                                    q=spec.line_weight, kappa0=kappa0)[0]
        assert out["drop"] == pytest.approx(0.5 * (front + rear), rel=1e-9)
        parts = (out["from_chassis"] + out["from_shackle"] + out["from_leaf_weight"]
                 + out["from_overlap"] + out["from_preload"])
        assert parts == pytest.approx(out["drop"], rel=1e-9)


def test_prestress_lowers_the_drop_by_the_eye_lift():
    plain = lr.chassis_static_drop(EI, prestress=False)
    pre = lr.chassis_static_drop(EI, prestress=True)
    lift = lr.prestress_preload(EI)["eye_lift"]
    overlap_lift = lr.prestress_preload(EI, lower_free_radius=None)["eye_lift"]
    assert plain["drop"] - pre["drop"] == pytest.approx(lift - overlap_lift, rel=1e-10)


def test_shackle_tilt_softens_by_a_few_percent():
    lin = lr.chassis_static_drop(EI, prestress=False)
    tilt = lr.chassis_static_drop(EI, prestress=False, shackle_tilt=True)
    assert 1.0 < tilt["drop"] / lin["drop"] < 1.05
    # the horizontal force is S (u_f + u_r) / l at the final eye positions
    S = SPEC.chassis_weight / 2 + SPEC.shackle_mass * SPEC.gravity / 2
    assert tilt["eye_horizontal_force"] == pytest.approx(
        S * (tilt["eye_outward_front"] + tilt["eye_outward_rear"]) / SPEC.shackle_length,
        rel=1e-9)


def test_load_cycle_free_and_prismatic():
    k = lr.two_leaf_half_stiffness(EI)["k_half"]
    free = lr.load_cycle(EI, prestress=False)
    assert free["stiffness"] == pytest.approx(2 * k, rel=1e-12)
    assert free["contact_opens"] == 1.0 and free["reaction_at_zero"] == 0.0  # touching
    fr = lr.load_cycle(EI, prestress=True, friction=0.3)
    for mu, key in ((0.3, "stiffness_loading"), (-0.3, "stiffness_unloading")):
        assert fr[key] == pytest.approx(
            2 * lr.two_leaf_half_stiffness(EI, friction=mu)["k_half"], rel=1e-12)
    assert fr["stiffness_unloading"] < free["stiffness"] < fr["stiffness_loading"]
    assert fr["hysteresis_at_half"] > 0
    # straight leaves: holding the eye horizontally changes nothing (no coupling)
    spec = lr.LeafSpringSpec(main_radius=INF, lower_radius=INF)
    ks = lr.two_leaf_half_stiffness(EI, main_radius=INF, lower_radius=INF)["k_half"]
    pr = lr.load_cycle(EI, prestress=False, guidance="prismatic", spec=spec,
                       axial_stiffness=INF)
    assert pr["stiffness"] == pytest.approx(2 * ks, rel=1e-10)
    # curved, main leaf alone with the eye held: f_EE - f_HE^2 / f_HH (closed form)
    cf = lr.curved_cantilever_tip_compliances_closed_form(L, SPEC.main_radius, EI)
    held = lr.two_leaf_half_stiffness(EI, eye_horizontal_stiffness=INF)
    assert held["compliance_main_alone"] == pytest.approx(
        cf["zz"] - cf["xz"] ** 2 / cf["xx"], rel=1e-9)


def test_bounce_frequency():
    k = 9.0e4
    f = lr.bounce_frequency(k, 500.0)
    assert 500.0 * (2 * math.pi * f) ** 2 == pytest.approx(2 * k, rel=1e-12)
    assert lr.bounce_frequency(k, 500.0, 0.2) == pytest.approx(f / math.sqrt(1.04),
                                                               rel=1e-12)


def test_reference_table_shape():
    rows = lr.reference_table()
    assert len(rows) == 4
    for row in rows:
        assert row["k_main_alone"] < row["k_half"]
        assert 0 < row["drop_prestress"] < row["drop_plain"]
        assert row["R0"] > 0 and row["eye_lift"] > 0
