"""Closed-form (small-deflection, linear beam theory) reference solutions.

These are independent references that tests compare the ANCF finite-element model
against. Nothing here uses finite elements: every result is either a textbook
formula or an exact piecewise-polynomial solution of the beam ODEs whose
integration constants come from a small dense linear system (``numpy.linalg.solve``).

Contents
--------
Crane boom (seed 000, linearized about the rigid configuration):
    :func:`boom_static_solution`, :func:`boom_static_tip_deflection`,
    :func:`boom_static_table`. The derivation is in ``docs/boom_closed_form.md``.

Cantilever (clamped at x = 0, free at x = L):
    :func:`cantilever_tip_load`, :func:`cantilever_uniform_load`,
    :func:`cantilever_end_moment`, :func:`cantilever_axial`,
    :func:`cantilever_frequencies`.

Shear deformation, where offered, is Timoshenko's with shear correction factor
k = 1 and G = E / (2 (1 + nu)): the continuum (fully parameterized ANCF) beam
element has a shear strain that is constant over the section, so its converged
limit is the Timoshenko beam with k = 1.

Units are SI throughout (m, kg, s, N, Pa).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from ..records import record

__all__ = [
    "BoomSolution",
    "boom_static_solution",
    "boom_static_tip_deflection",
    "boom_static_table",
    "cantilever_tip_load",
    "cantilever_uniform_load",
    "cantilever_end_moment",
    "cantilever_axial",
    "cantilever_frequencies",
    "CANTILEVER_BETA_L",
]

FloatArray = NDArray[np.float64]

# ---------------------------------------------------------------------------
# Crane boom
# ---------------------------------------------------------------------------
#
# Per segment s (s = 0: 0 <= x <= a, s = 1: a <= x <= L) the six integration
# constants c = (C1, C2, C3, C4, D1, D2) parameterize the exact solution of
#
#     N' = -q_x,  N = EA u'                     (axial)
#     Q' = -q_y,  M' = -Q,  M = EI theta',      (bending)
#     Q = GA (v' - theta)   (Timoshenko)  or  v' = theta  (Euler-Bernoulli)
#
# as (x is the global coordinate along the beam, the same in both segments)
#
#     Q     = C1 - q_y x
#     M     = C2 - C1 x + q_y x^2 / 2
#     theta = (C3 + C2 x - C1 x^2/2 + q_y x^3/6) / EI
#     v     = C4 + (C3 x + C2 x^2/2 - C1 x^3/6 + q_y x^4/24) / EI + f (C1 x - q_y x^2/2)
#     u     = D1 + D2 x - q_x x^2 / (2 EA)
#     N     = EA D2 - q_x x
#
# with f = 1/GA (Timoshenko) or f = 0 (Euler-Bernoulli). Each field is affine in
# c: field(x) = row(x) . c + particular(x).

_NCONST = 6  # constants per segment
_FIELDS = ("u", "v", "slope", "theta", "N", "M", "Q")


@record(frozen=True)
class _BoomParams:
    EA: float
    EI: float
    flex_shear: float  # 1/GA, or 0 for Euler-Bernoulli
    qx: float
    qy: float


def _field_row(name: str, x: float, p: _BoomParams) -> tuple[FloatArray, float]:
    """Coefficient row over one segment's constants and the particular part of a field at x."""
    row = np.zeros(_NCONST)
    EI, EA, f, qx, qy = p.EI, p.EA, p.flex_shear, p.qx, p.qy
    if name == "Q":
        row[0] = 1.0
        part = -qy * x
    elif name == "M":
        row[0], row[1] = -x, 1.0
        part = qy * x**2 / 2.0
    elif name == "theta":
        row[0], row[1], row[2] = -(x**2) / 2.0 / EI, x / EI, 1.0 / EI
        part = qy * x**3 / 6.0 / EI
    elif name == "slope":  # v' = theta + Q / GA
        row[0] = -(x**2) / 2.0 / EI + f
        row[1], row[2] = x / EI, 1.0 / EI
        part = qy * x**3 / 6.0 / EI - f * qy * x
    elif name == "v":
        row[0] = -(x**3) / 6.0 / EI + f * x
        row[1] = x**2 / 2.0 / EI
        row[2] = x / EI
        row[3] = 1.0
        part = qy * x**4 / 24.0 / EI - f * qy * x**2 / 2.0
    elif name == "u":
        row[4], row[5] = 1.0, x
        part = -qx * x**2 / (2.0 * EA)
    elif name == "N":
        row[5] = EA
        part = -qx * x
    else:  # pragma: no cover - internal misuse
        raise ValueError(f"unknown field {name!r}")
    return row, part


@record(frozen=True)
class BoomSolution:
    """Exact linear static solution of the boom, in the frame rotated by the boom angle.

    Attributes
    ----------
    length, a, H:
        Beam length, position of the driven pin, arm length of the support at x = 0.
    shear:
        True for Timoshenko (k = 1), False for Euler-Bernoulli.
    constants:
        Array (2, 6): integration constants (C1, C2, C3, C4, D1, D2) of the segments
        [0, a] and [a, L] (see the module source for their meaning).
    """

    length: float
    a: float
    H: float
    shear: bool
    constants: FloatArray
    _params: _BoomParams

    def _segment(self, x: float) -> int:
        if x < -1e-12 * self.length or x > self.length * (1.0 + 1e-12):
            raise ValueError(f"x = {x} outside [0, {self.length}]")
        return 0 if x <= self.a else 1

    def field(self, name: str, x: ArrayLike, *, side: str = "left") -> FloatArray:
        """Evaluate a field at x (scalar or array).

        ``name`` is one of ``u`` (axial displacement), ``v`` (transverse
        displacement), ``slope`` (v', the centreline slope), ``theta`` (section
        rotation, counterclockwise positive), ``N`` (axial force, tension
        positive), ``M`` (bending moment, EI theta') or ``Q`` (transverse shear
        force). At x = a, where N, M, Q (and for
        Timoshenko v') jump, ``side`` selects the segment: "left" or "right".
        """
        if name not in _FIELDS:
            raise ValueError(f"field must be one of {_FIELDS}, got {name!r}")
        if side not in ("left", "right"):
            raise ValueError("side must be 'left' or 'right'")
        xs = np.asarray(x, dtype=float)
        out = np.empty(xs.shape)
        for idx, xi in np.ndenumerate(xs):
            seg = self._segment(float(xi))
            if side == "right" and float(xi) == self.a:
                seg = 1
            row, part = _field_row(name, float(xi), self._params)
            out[idx] = row @ self.constants[seg] + part
        return out

    def tip(self) -> tuple[float, float]:
        """(axial, transverse) displacement of the neutral-axis end point x = L."""
        u = float(self.field("u", self.length))
        v = float(self.field("v", self.length))
        return u, v

    def tip_foreshortening(self) -> float:
        """Second-order axial tip shift -1/2 int_a^L v'(x)^2 dx of the linear solution (m, <= 0).

        NOT part of the linear reference. A geometrically nonlinear model puts the
        tip at x(L) = a + int_a^L (1 + eps) cos(psi) ds with psi ~ v' the centreline
        angle, so its axial tip displacement is about u(L) + tip_foreshortening().
        For the default boom this term (0.2 - 1.2 mm) is two orders of magnitude
        larger than the linear u(L) (a few micrometres), so compare an axial tip
        displacement from a nonlinear model with the sum, not with u(L) alone.
        (Exact for the polynomial v': 4-point Gauss-Legendre on the degree-6 v'^2.)
        """
        xg, wg = np.polynomial.legendre.leggauss(4)
        half = 0.5 * (self.length - self.a)
        xs = self.a + half * (xg + 1.0)
        slope = self.field("slope", xs, side="right")
        return float(-0.5 * half * np.sum(wg * slope**2))


def boom_static_solution(
    angle_deg: float,
    tip_mass: float,
    *,
    length: float = 7.791,
    a: float = 1.791,
    H: float = 0.295,
    width: float = 0.1,
    height: float = 0.1,
    youngs: float = 2.1e11,
    density: float = 7850.0,
    poisson: float = 0.0,
    gravity: float = 9.81,
    moment: float = 1000.0,
    shear: bool = True,
) -> BoomSolution:
    """Exact linear static solution of the crane boom of seed 000.

    Frame: rotated by phi = ``angle_deg`` about +z; x along the beam (0 <= x <= L),
    y transverse. Section A = width * height, I = width * height**3 / 12 (bending
    in the x-y plane). Loads: self weight rho A g along global -y, i.e.
    q_x = -rho A g sin(phi), q_y = -rho A g cos(phi); tip point mass at x = L,
    P_x = -m g sin(phi), P_y = -m g cos(phi); concentrated moment ``moment`` about
    +z at x = a (work moment * theta(a)).

    Linearized supports: v(0) = 0 and u(0) = -H theta(0) (beam end on a rigid arm
    of length H from the pin at (0, -H)); u(a) = v(a) = 0 (driven pin).

    Parameters
    ----------
    angle_deg, tip_mass:
        Boom angle phi in degrees and tip point mass in kg.
    length, a, H:
        Beam length, driven-pin position, support arm length (m).
    width, height:
        Rectangular section (m); ``height`` is along the transverse y axis.
    youngs, density, poisson:
        E (Pa), rho (kg/m^3), nu (G = E / (2 (1 + nu)), shear factor k = 1).
    gravity:
        g (m/s^2).
    moment:
        Concentrated moment at x = a, N m, positive about +z.
    shear:
        True: Timoshenko (k = 1). False: Euler-Bernoulli.

    Returns
    -------
    BoomSolution
        Evaluate fields with :meth:`BoomSolution.field`, tip with :meth:`BoomSolution.tip`.
    """
    if not (0.0 < a < length):
        raise ValueError("need 0 < a < length")
    if width <= 0 or height <= 0 or youngs <= 0:
        raise ValueError("width, height and youngs must be positive")
    phi = math.radians(angle_deg)
    area = width * height
    inertia = width * height**3 / 12.0
    EA = youngs * area
    EI = youngs * inertia
    G = youngs / (2.0 * (1.0 + poisson))
    flex = 1.0 / (G * area) if shear else 0.0
    w = density * area * gravity
    qx, qy = -w * math.sin(phi), -w * math.cos(phi)
    Px, Py = -tip_mass * gravity * math.sin(phi), -tip_mass * gravity * math.cos(phi)
    p = _BoomParams(EA=EA, EI=EI, flex_shear=flex, qx=qx, qy=qy)

    n = 2 * _NCONST
    K = np.zeros((n, n))
    rhs = np.zeros(n)
    eq = 0

    def add(terms: list[tuple[int, str, float, float]], value: float) -> None:
        """Add sum(coef * field_seg(x)) = value as one equation."""
        nonlocal eq
        for seg, name, x, coef in terms:
            row, part = _field_row(name, x, p)
            K[eq, seg * _NCONST:(seg + 1) * _NCONST] += coef * row
            value -= coef * part
        rhs[eq] = value
        eq += 1

    L = length
    # x = 0: essential v(0) = 0, u(0) + H theta(0) = 0; natural M(0) = H N(0).
    add([(0, "v", 0.0, 1.0)], 0.0)
    add([(0, "u", 0.0, 1.0), (0, "theta", 0.0, H)], 0.0)
    add([(0, "M", 0.0, 1.0), (0, "N", 0.0, -H)], 0.0)
    # x = a: u = v = 0 on both sides, theta continuous, M(a-) - M(a+) = moment.
    add([(0, "u", a, 1.0)], 0.0)
    add([(1, "u", a, 1.0)], 0.0)
    add([(0, "v", a, 1.0)], 0.0)
    add([(1, "v", a, 1.0)], 0.0)
    add([(0, "theta", a, 1.0), (1, "theta", a, -1.0)], 0.0)
    add([(0, "M", a, 1.0), (1, "M", a, -1.0)], moment)
    # x = L: N(L) = P_x, Q(L) = P_y, M(L) = 0.
    add([(1, "N", L, 1.0)], Px)
    add([(1, "Q", L, 1.0)], Py)
    add([(1, "M", L, 1.0)], 0.0)
    assert eq == n

    c = np.linalg.solve(K, rhs).reshape(2, _NCONST)
    return BoomSolution(length=L, a=a, H=H, shear=shear, constants=c, _params=p)


def boom_static_tip_deflection(
    angle_deg: float,
    tip_mass: float,
    *,
    length: float = 7.791,
    a: float = 1.791,
    H: float = 0.295,
    width: float = 0.1,
    height: float = 0.1,
    youngs: float = 2.1e11,
    density: float = 7850.0,
    poisson: float = 0.0,
    gravity: float = 9.81,
    moment: float = 1000.0,
    shear: bool = True,
) -> tuple[float, float]:
    """(axial, transverse) static tip displacement of the boom's neutral-axis end point.

    Components are in the frame rotated by the boom angle (x along the beam, y
    transverse); the transverse one is negative when the boom sags. Linear,
    small-deflection theory; see :func:`boom_static_solution` for the model and
    parameters.
    """
    sol = boom_static_solution(
        angle_deg, tip_mass, length=length, a=a, H=H, width=width, height=height,
        youngs=youngs, density=density, poisson=poisson, gravity=gravity,
        moment=moment, shear=shear,
    )
    return sol.tip()


def boom_static_table(
    angles: tuple[float, ...] = (0, 15, 30, 45, 60),
    masses: tuple[float, ...] = (0, 50),
    **kwargs: float,
) -> list[dict[str, float]]:
    """Tip displacements for every (angle, mass) pair, Euler-Bernoulli and Timoshenko.

    Extra keyword arguments are passed to :func:`boom_static_tip_deflection`
    (except ``shear``). Each row has keys ``angle_deg``, ``tip_mass``,
    ``axial_eb``, ``transverse_eb``, ``axial_timoshenko``, ``transverse_timoshenko``
    (metres, rotated frame).
    """
    if "shear" in kwargs:
        raise TypeError("boom_static_table computes both shear=False and shear=True")
    rows: list[dict[str, float]] = []
    for ang in angles:
        for m in masses:
            ue, ve = boom_static_tip_deflection(
                ang, m, shear=False, **kwargs)  # type: ignore[arg-type]
            ut, vt = boom_static_tip_deflection(
                ang, m, shear=True, **kwargs)  # type: ignore[arg-type]
            rows.append({
                "angle_deg": float(ang), "tip_mass": float(m),
                "axial_eb": ue, "transverse_eb": ve,
                "axial_timoshenko": ut, "transverse_timoshenko": vt,
            })
    return rows


# ---------------------------------------------------------------------------
# Cantilever (clamped at x = 0, free at x = L)
# ---------------------------------------------------------------------------

#: beta_n L roots of cos(beta L) cosh(beta L) = -1 (clamped-free Euler-Bernoulli beam).
CANTILEVER_BETA_L: tuple[float, ...] = (1.875104068711961, 4.694091132974175, 7.854757438237613)


def _shear_flexibility(E: float, A: float | None, G: float | None, nu: float,
                       shear: bool | None) -> float:
    """1 / (G A) with k = 1 when shear is on, else 0. Shear is on by default iff A is given."""
    if shear is None:
        shear = A is not None
    if not shear:
        return 0.0
    if A is None:
        raise ValueError("the shear term needs the area A")
    if G is None:
        G = E / (2.0 * (1.0 + nu))
    return 1.0 / (G * A)


def cantilever_tip_load(P: float, L: float, E: float, I: float, A: float | None = None,
                        G: float | None = None, *, nu: float = 0.0,
                        shear: bool | None = None) -> float:
    """Tip deflection of a cantilever under a transverse tip force P.

    delta = P L^3 / (3 E I)  [+ P L / (G A) with shear, k = 1].

    The shear term: the shear force is P all along, so the shear strain
    gamma = P / (G A) adds gamma * L at the tip. Shear is included when ``A`` is
    given (or when ``shear=True``); ``G`` defaults to E / (2 (1 + nu)).
    Sign follows P (deflection in the direction of the force).
    """
    return P * L**3 / (3.0 * E * I) + P * L * _shear_flexibility(E, A, G, nu, shear)


def cantilever_uniform_load(q: float, L: float, E: float, I: float, A: float | None = None,
                            G: float | None = None, *, nu: float = 0.0,
                            shear: bool | None = None) -> float:
    """Tip deflection of a cantilever under a uniform transverse load q (force/length).

    delta = q L^4 / (8 E I)  [+ q L^2 / (2 G A) with shear, k = 1].

    The shear term: the shear force is q (L - x), so the extra deflection is
    integral_0^L q (L - x) / (G A) dx = q L^2 / (2 G A). Shear switch and ``G``
    default as in :func:`cantilever_tip_load`.
    """
    return q * L**4 / (8.0 * E * I) + q * L**2 / 2.0 * _shear_flexibility(E, A, G, nu, shear)


def cantilever_end_moment(M: float, L: float, E: float, I: float) -> tuple[float, float]:
    """(tip deflection, tip rotation) of a cantilever under an end moment M.

    delta = M L^2 / (2 E I), rotation = M L / (E I). Pure bending: the shear force
    is zero, so Timoshenko and Euler-Bernoulli agree. A positive moment (about +z)
    gives a positive deflection (towards +y) and a counterclockwise rotation.
    """
    return M * L**2 / (2.0 * E * I), M * L / (E * I)


def cantilever_axial(P: float, L: float, E: float, A: float) -> float:
    """Tip axial displacement under an axial tip force P (tension positive): P L / (E A)."""
    return P * L / (E * A)


def _beta_l(n: int) -> float:
    """n-th (1-based) root of cos(x) cosh(x) + 1 = 0."""
    if n <= len(CANTILEVER_BETA_L):
        return CANTILEVER_BETA_L[n - 1]
    x = (2 * n - 1) * math.pi / 2.0  # asymptotic root; Newton converges in a few steps
    for _ in range(50):
        # f = cos x + 1/cosh x (same roots, well scaled), f' = -sin x - tanh x / cosh x
        f = math.cos(x) + 1.0 / math.cosh(x)
        df = -math.sin(x) - math.tanh(x) / math.cosh(x)
        dx = f / df
        x -= dx
        if abs(dx) < 1e-15 * x:
            break
    return x


def cantilever_frequencies(L: float, E: float, I: float, rho: float, A: float,
                           n: int = 3) -> FloatArray:
    """First n bending natural circular frequencies (rad/s) of an Euler-Bernoulli cantilever.

    omega_n = (beta_n L)^2 sqrt(E I / (rho A L^4)) with beta_n L = 1.875104068711961,
    4.694091132974175, 7.854757438237613, ... (roots of cos(x) cosh(x) = -1; higher
    ones by Newton iteration). Divide by 2 pi for Hz.
    """
    if n < 1:
        raise ValueError("n must be >= 1")
    scale = math.sqrt(E * I / (rho * A * L**4))
    return np.array([_beta_l(k) ** 2 * scale for k in range(1, n + 1)])


# ---------------------------------------------------------------------------
# Large deflection: the elastica of a cantilever under a dead tip load
# ---------------------------------------------------------------------------

def elastica_tip_load(k: float, *, nodes: int = 2001, tol: float = 1e-10) -> tuple[float, float]:
    """Inextensible, shear-rigid cantilever under a dead transverse tip load, k = P L^2 / EI.

    Solves theta'' = -k cos(theta) on s in [0, 1] (theta: slope angle towards the load,
    theta(0) = 0, theta'(1) = 0: no end moment) with scipy's collocation BVP solver, and
    returns (w/L, u/L): the tip deflection along the load and the shortening along the
    beam. Checked against Mattiasson (1981): k = 1 gives w/L = 0.30172, u/L = 0.05643.
    """
    from scipy.integrate import solve_bvp

    def bc(ya, yb):  # y = [theta, theta', x, w]
        return np.array([ya[0], yb[1], ya[2], ya[3]])

    s = np.linspace(0.0, 1.0, nodes)
    guess = np.zeros((4, s.size))
    guess[2] = s
    # continuation in k: the collocation solver converges from the small-load shape
    solution = None
    for fraction in np.linspace(0.1, 1.0, 10):
        kk = fraction * k

        def rhs_k(s, y, kk=kk):
            return np.vstack([y[1], -kk * np.cos(y[0]), np.cos(y[0]), np.sin(y[0])])
        solution = solve_bvp(rhs_k, bc, s, guess if solution is None else solution.sol(s),
                             tol=tol, max_nodes=200000)
        if not solution.success:
            raise RuntimeError(f"elastica BVP failed at k = {kk}: {solution.message}")
    x_tip, w_tip = solution.sol(1.0)[2:4]
    return float(w_tip), float(1.0 - x_tip)


def navier_plate_centre_deflection(pressure: float, length_x: float, length_y: float,
                                   youngs: float, poisson: float, thickness: float,
                                   terms: int = 199) -> float:
    """Centre deflection of a simply supported rectangular Kirchhoff plate under a uniform
    pressure, by Navier's double series (Timoshenko & Woinowsky-Krieger, section 30):
    w = 16 q / (pi^6 D) sum_{m,n odd} sin(m pi/2) sin(n pi/2) / (m n (m^2/a^2 + n^2/b^2)^2),
    D = E h^3 / (12 (1 - nu^2)); 0.00406 q a^4 / D for a square plate."""
    rigidity = youngs * thickness**3 / (12.0 * (1.0 - poisson**2))
    odd = np.arange(1, terms + 1, 2, dtype=float)
    m, n = np.meshgrid(odd, odd, indexing="ij")
    signs = (-1.0) ** ((m + n) / 2 - 1)
    series = signs / (m * n * (m**2 / length_x**2 + n**2 / length_y**2) ** 2)
    return 16.0 * pressure / (np.pi**6 * rigidity) * float(series.sum())
