"""Rigid-limit planar mechanisms (reference for the tests, pure numpy/scipy).

Rigid bodies moving in the x-y plane; equations of motion written out by hand
(Lagrange) and integrated with ``scipy.integrate.solve_ivp`` (DOP853, rtol 1e-10 by
default), or kinematics and quasi-static equilibrium in closed form. A small-deflection
superposition formula gives the sag of the flexible knuckle boom.

Conventions
-----------
* SI units (m, kg, s, N, N m, rad).
* Every rod is a uniform slender rod: mass m, length L, centre of mass at L/2, rotary
  inertia m L^2/12 about it (m L^2/3 about an end).
* Angles are *absolute*: the angle of a rod's direction (from its hinge toward its
  other end) measured from the +x axis, counter-clockwise positive. A rod hanging
  straight down under gravity (0, -g) has angle -pi/2.
* Moments and torques are positive counter-clockwise (about +z).
* ``gravity`` is the 2-vector of the gravitational acceleration, e.g. (0, -9.81).
* A point on a rod is given in the rod's frame as (s, n): s along the rod from its hinge,
  n along the left normal (rotated +90 degrees): position = hinge + s e + n e_perp with
  e = (cos a, sin a), e_perp = (-sin a, cos a).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import solve_ivp
from scipy.linalg import eigh

__all__ = [
    "PendulumSolution",
    "pendulum",
    "pendulum_small_amplitude_period",
    "DoublePendulumSolution",
    "double_pendulum",
    "double_pendulum_mass_matrix",
    "double_pendulum_linear_frequencies",
    "SliderCrankSolution",
    "slider_crank",
    "KnuckleBoomStatics",
    "knuckle_boom_jib_angle",
    "knuckle_boom_statics",
    "KnuckleBoomSag",
    "knuckle_boom_flexible_sag",
]

_RTOL = 1e-10
_ATOL = 1e-12


def _unit(angle) -> NDArray[np.float64]:
    """(..., 2) unit vectors (cos a, sin a)."""
    a = np.asarray(angle, dtype=float)
    return np.stack([np.cos(a), np.sin(a)], axis=-1)


def _perp(v: NDArray) -> NDArray[np.float64]:
    """Left normal (-v_y, v_x) of (..., 2) vectors."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _cross(a: NDArray, b: NDArray) -> NDArray[np.float64]:
    """z component of the cross product of (..., 2) vectors."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _vec2(v: ArrayLike, name: str) -> NDArray[np.float64]:
    a = np.asarray(v, dtype=float)
    if a.shape != (2,):
        raise ValueError(f"{name} must be a 2-vector, got shape {a.shape}")
    return a


def _integrate(rhs, t: ArrayLike, y0: NDArray, rtol: float, atol: float):
    """Integrate y' = rhs(t, y) from t[0] and sample at the times t (increasing)."""
    t = np.asarray(t, dtype=float)
    sol = solve_ivp(rhs, (t[0], t[-1]), y0, method="DOP853", t_eval=t, rtol=rtol, atol=atol)
    if not sol.success:  # pragma: no cover - DOP853 does not fail on these smooth problems
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    return sol.y.T


# ------------------------------------------------------------------------- (a) pendulum
@dataclass(frozen=True)
class PendulumSolution:
    """Pendulum history: ``t`` (n,), ``angle`` and ``rate`` (n,) [rad, rad/s], ``tip``
    (n, 2) the rod's free end [m], ``energy`` (n,) kinetic + potential [J] (potential
    -m g . r_c, zero at the pivot)."""

    t: NDArray[np.float64]
    angle: NDArray[np.float64]
    rate: NDArray[np.float64]
    tip: NDArray[np.float64]
    energy: NDArray[np.float64]


def _pendulum_constants(
    length: float, rod_mass: float, point_mass: float, point_mass_distance: Optional[float]
) -> tuple[float, float]:
    """Inertia about the pivot I_O = m L^2/3 + M d^2 and first moment S = m L/2 + M d."""
    d = length if point_mass_distance is None else point_mass_distance
    return rod_mass * length**2 / 3.0 + point_mass * d**2, rod_mass * length / 2.0 + point_mass * d


def pendulum(
    t: ArrayLike,
    angle0: float,
    rate0: float,
    length: float,
    rod_mass: float,
    gravity: ArrayLike = (0.0, -9.81),
    point_mass: float = 0.0,
    point_mass_distance: Optional[float] = None,
    pivot: ArrayLike = (0.0, 0.0),
    rtol: float = _RTOL,
    atol: float = _ATOL,
) -> PendulumSolution:
    """Rigid physical pendulum: a uniform rod (``length`` L, ``rod_mass`` m) hinged at
    one end to ground at ``pivot``, optionally carrying a point mass M at distance d
    (``point_mass_distance``, default L: at the tip) along the rod.

    Equation: I_O a'' = S (e_perp(a) . g), I_O = m L^2/3 + M d^2, S = m L/2 + M d, with
    a the absolute rod angle (``angle0`` [rad], ``rate0`` [rad/s] at t[0]). rod_mass = 0
    with a point mass gives the simple pendulum. Sampled at the times ``t``.
    """
    g = _vec2(gravity, "gravity")
    I_O, S = _pendulum_constants(length, rod_mass, point_mass, point_mass_distance)
    if I_O <= 0.0:
        raise ValueError("the pendulum has no inertia about its pivot")

    gx, gy = float(g[0]), float(g[1])

    def rhs(_t, y):
        return [y[1], S * (-math.sin(y[0]) * gx + math.cos(y[0]) * gy) / I_O]

    y = _integrate(rhs, t, np.array([angle0, rate0], dtype=float), rtol, atol)
    e = _unit(y[:, 0])
    energy = 0.5 * I_O * y[:, 1] ** 2 - S * (e @ g)
    return PendulumSolution(
        np.asarray(t, dtype=float), y[:, 0], y[:, 1], _vec2(pivot, "pivot") + length * e, energy
    )


def pendulum_small_amplitude_period(
    length: float,
    rod_mass: float,
    g: float,
    point_mass: float = 0.0,
    point_mass_distance: Optional[float] = None,
) -> float:
    """Small-amplitude period 2 pi sqrt(I_O / (S g)) of ``pendulum`` (g the magnitude of
    gravity); 2 pi sqrt(2L/(3g)) for the bare rod."""
    I_O, S = _pendulum_constants(length, rod_mass, point_mass, point_mass_distance)
    return 2.0 * np.pi * np.sqrt(I_O / (S * g))


# ------------------------------------------------------------------ (b) double pendulum
@dataclass(frozen=True)
class DoublePendulumSolution:
    """Double-pendulum history: ``angles`` and ``rates`` (n, 2) of rods 1 and 2,
    ``knee`` (n, 2) the hinge between them, ``tip`` (n, 2) the free end of rod 2,
    ``energy`` (n,) kinetic + potential [J]."""

    t: NDArray[np.float64]
    angles: NDArray[np.float64]
    rates: NDArray[np.float64]
    knee: NDArray[np.float64]
    tip: NDArray[np.float64]
    energy: NDArray[np.float64]


def double_pendulum_mass_matrix(
    angles: ArrayLike, lengths: Sequence[float], masses: Sequence[float]
) -> NDArray:
    """Mass matrix of two uniform rods hinged in series (rod 1 to ground at one end,
    rod 2 to the free end of rod 1), in the absolute angles (a1, a2):

        [[m1 L1^2/3 + m2 L1^2,          m2 L1 L2/2 cos(a1 - a2)],
         [m2 L1 L2/2 cos(a1 - a2),      m2 L2^2/3              ]]

    ``angles`` (..., 2); returns (..., 2, 2).
    """
    (L1, L2), (m1, m2) = lengths, masses
    a = np.asarray(angles, dtype=float)
    c = 0.5 * m2 * L1 * L2 * np.cos(a[..., 0] - a[..., 1])
    M = np.empty(a.shape[:-1] + (2, 2))
    M[..., 0, 0] = m1 * L1**2 / 3.0 + m2 * L1**2
    M[..., 1, 1] = m2 * L2**2 / 3.0
    M[..., 0, 1] = M[..., 1, 0] = c
    return M


def double_pendulum(
    t: ArrayLike,
    angles0: Sequence[float],
    rates0: Sequence[float],
    lengths: Sequence[float],
    masses: Sequence[float],
    gravity: ArrayLike = (0.0, -9.81),
    pivot: ArrayLike = (0.0, 0.0),
    rtol: float = _RTOL,
    atol: float = _ATOL,
) -> DoublePendulumSolution:
    """Planar double pendulum of two uniform rods (lengths L1, L2, masses m1, m2) hinged
    in series, rod 1 hinged to ground at ``pivot``, under ``gravity``.

    Lagrange's equations in the absolute angles a1, a2 (D = a1 - a2, c = m2 L1 L2/2):

        M11 a1'' + c cos D a2'' + c sin D a2'^2 = (m1 L1/2 + m2 L1) e1_perp . g
        c cos D a1'' + M22 a2'' - c sin D a1'^2 = (m2 L2/2) e2_perp . g

    with M11 = m1 L1^2/3 + m2 L1^2, M22 = m2 L2^2/3. Released from ``angles0`` with
    ``rates0`` at t[0] and sampled at the times ``t``.
    """
    g = _vec2(gravity, "gravity")
    (L1, L2), (m1, m2) = lengths, masses
    c = 0.5 * m2 * L1 * L2
    s1, s2 = m1 * L1 / 2.0 + m2 * L1, m2 * L2 / 2.0

    m11, m22 = m1 * L1**2 / 3.0 + m2 * L1**2, m2 * L2**2 / 3.0
    gx, gy = float(g[0]), float(g[1])

    def rhs(_t, y):
        a1, a2, w1, w2 = y
        sD, cD = math.sin(a1 - a2), math.cos(a1 - a2)
        m12 = c * cD
        q1 = s1 * (-math.sin(a1) * gx + math.cos(a1) * gy) - c * sD * w2**2
        q2 = s2 * (-math.sin(a2) * gx + math.cos(a2) * gy) + c * sD * w1**2
        det = m11 * m22 - m12**2  # the 2x2 solve by Cramer's rule
        return [w1, w2, (m22 * q1 - m12 * q2) / det, (m11 * q2 - m12 * q1) / det]

    y = _integrate(rhs, t, np.array([*angles0, *rates0], dtype=float), rtol, atol)
    angles, rates = y[:, :2], y[:, 2:]
    M = double_pendulum_mass_matrix(angles, lengths, masses)
    kinetic = 0.5 * np.einsum("ni,nij,nj->n", rates, M, rates)
    e1, e2 = _unit(angles[:, 0]), _unit(angles[:, 1])
    potential = -(s1 * (e1 @ g) + s2 * (e2 @ g))
    p0 = _vec2(pivot, "pivot")
    knee = p0 + L1 * e1
    return DoublePendulumSolution(
        np.asarray(t, dtype=float), angles, rates, knee, knee + L2 * e2, kinetic + potential
    )


def double_pendulum_linear_frequencies(
    lengths: Sequence[float], masses: Sequence[float], g: float
) -> tuple[NDArray, NDArray]:
    """Angular frequencies [rad/s] (ascending) and mode shapes of small oscillations of
    ``double_pendulum`` about the hanging equilibrium (g = |gravity|): the generalized
    eigenproblem K v = w^2 M0 v with M0 the mass matrix at a1 = a2 and
    K = g diag(m1 L1/2 + m2 L1, m2 L2/2). Returns (omega (2,), shapes (2, 2) columns).
    For equal rods, w^2 = (3 -/+ 6/sqrt 7) g / L."""
    (L1, L2), (m1, m2) = lengths, masses
    M0 = double_pendulum_mass_matrix((0.0, 0.0), lengths, masses)
    K = g * np.diag([m1 * L1 / 2.0 + m2 * L1, m2 * L2 / 2.0])
    w2, v = eigh(K, M0)
    return np.sqrt(w2), v


# ---------------------------------------------------------------------- (c) slider-crank
@dataclass(frozen=True)
class SliderCrankSolution:
    """Slider-crank history (all arrays (n,) unless noted).

    ``crank_angle`` theta [rad]; ``crank_pin`` (n, 2) the crank tip A; ``slider_x``,
    ``slider_velocity``, ``slider_acceleration`` of the slider B = (x, 0);
    ``rod_angle`` psi, ``rod_rate``, ``rod_acceleration`` of the connecting rod (absolute
    angle of A -> B); ``torque`` [N m] the driving torque on the crank (counter-clockwise
    positive) that keeps the prescribed crank motion; ``kinetic`` and ``potential`` [J]
    energies of the three bodies (potential -sum m g . r_c).
    """

    t: NDArray[np.float64]
    crank_angle: NDArray[np.float64]
    crank_pin: NDArray[np.float64]
    slider_x: NDArray[np.float64]
    slider_velocity: NDArray[np.float64]
    slider_acceleration: NDArray[np.float64]
    rod_angle: NDArray[np.float64]
    rod_rate: NDArray[np.float64]
    rod_acceleration: NDArray[np.float64]
    torque: NDArray[np.float64]
    kinetic: NDArray[np.float64]
    potential: NDArray[np.float64]


def slider_crank(
    t: ArrayLike,
    crank_length: float,
    rod_length: float,
    crank_mass: float,
    rod_mass: float,
    slider_mass: float,
    omega: float,
    theta0: float = 0.0,
    gravity: ArrayLike = (0.0, 0.0),
    angular_acceleration: float = 0.0,
) -> SliderCrankSolution:
    """Planar in-line slider-crank with a prescribed crank motion (constant speed by
    default).

    Crank: uniform rod (length r = ``crank_length``, mass m1) hinged to ground at the
    origin, angle theta(t) = ``theta0`` + ``omega`` t + ``angular_acceleration`` t^2/2
    (prescribed; ``omega`` [rad/s] is the speed at t = 0). Connecting rod:
    uniform rod (length l = ``rod_length`` > r, mass m2) hinged to the crank tip
    A = r (cos theta, sin theta) and to the slider B = (x, 0) (point mass m3) that slides
    without friction along the x axis, on the side x > 0. Closed-form kinematics:

        sin psi = -(r/l) sin theta,   x = r cos theta + l cos psi,

    and their time derivatives. The driving torque follows from the principle of virtual
    work with the single coordinate theta (the guide and hinge forces do no work):

        tau = sum_i [m_i (a_ci - g) . dr_ci/dtheta + I_ci alpha_i dphi_i/dtheta],

    with the body accelerations a_ci, alpha_i from the closed-form kinematics.
    """
    r, l = float(crank_length), float(rod_length)
    if not l > r > 0.0:
        raise ValueError(f"need rod_length > crank_length > 0, got l = {l}, r = {r}")
    g = _vec2(gravity, "gravity")
    t = np.atleast_1d(np.asarray(t, dtype=float))
    th = theta0 + omega * t + 0.5 * angular_acceleration * t**2
    thd, thdd = omega + angular_acceleration * t, np.full_like(t, float(angular_acceleration))
    st, ct = np.sin(th), np.cos(th)
    sp = -(r / l) * st
    cp = np.sqrt(1.0 - sp**2)
    psi = np.arctan2(sp, cp)
    dpsi = -(r / l) * ct / cp  # d psi / d theta
    psid = dpsi * thd
    psidd = ((r / l) * (st * thd**2 - ct * thdd) + sp * psid**2) / cp
    # positions, Jacobians d/dtheta, accelerations of the centres of mass
    A = r * np.stack([ct, st], axis=-1)
    dA = r * np.stack([-st, ct], axis=-1)
    aA = r * np.stack([-ct * thd**2 - st * thdd, -st * thd**2 + ct * thdd], axis=-1)
    u = np.stack([cp, sp], axis=-1)
    du = _perp(u)  # d u / d psi
    x = A[:, 0] + l * cp
    dx = dA[:, 0] + l * du[:, 0] * dpsi
    xd = dx * thd
    xdd = aA[:, 0] + l * (du[:, 0] * psidd - u[:, 0] * psid**2)
    c1, dc1, ac1 = 0.5 * A, 0.5 * dA, 0.5 * aA
    c2 = A + 0.5 * l * u
    dc2 = dA + 0.5 * l * du * dpsi[:, None]
    ac2 = aA + 0.5 * l * (du * psidd[:, None] - u * (psid**2)[:, None])
    m1, m2, m3 = crank_mass, rod_mass, slider_mass
    I1, I2 = m1 * r**2 / 12.0, m2 * l**2 / 12.0
    torque = (
        m1 * np.einsum("ni,ni->n", ac1 - g, dc1)
        + I1 * thdd
        + m2 * np.einsum("ni,ni->n", ac2 - g, dc2)
        + I2 * psidd * dpsi
        + m3 * (xdd - g[0]) * dx
    )
    v1, v2 = dc1 * thd[:, None], dc2 * thd[:, None]
    kinetic = 0.5 * (
        m1 * np.sum(v1**2, axis=1) + I1 * thd**2 + m2 * np.sum(v2**2, axis=1) + I2 * psid**2 + m3 * xd**2
    )
    potential = -(m1 * c1 @ g + m2 * c2 @ g + m3 * x * g[0])
    return SliderCrankSolution(t, th, A, x, xd, xdd, psi, psid, psidd, torque, kinetic, potential)


# -------------------------------------------------------------- (d) knuckle boom, statics
@dataclass(frozen=True)
class KnuckleBoomStatics:
    """Quasi-static state of the rigid knuckle boom (arrays broadcast over the actuator
    length; vectors have a trailing axis of 2).

    Points [m]: ``pivot`` O (boom hinge to ground), ``knuckle`` B (boom tip = jib hinge),
    ``boom_point`` P and ``jib_point`` Q (actuator ends), ``tip`` T (jib free end).
    ``jib_angle`` [rad] absolute angle of the jib. ``actuator_direction`` unit vector
    from P to Q; ``actuator_force`` [N] its axial force, tension positive (it pulls P and
    Q together). ``pivot_force`` [N] force of the ground on the boom at O;
    ``pivot_moment`` [N m] moment of the ground on the boom (what holds the boom angle,
    e.g. a prescribed-rotation drive or a clamp; 0 with a lift cylinder);
    ``knuckle_force`` [N] force of the boom on the jib at B. With a lift cylinder:
    ``lift_boom_point`` (its end on the boom), ``lift_direction`` (unit vector from there
    to its ground point), ``lift_force`` [N] (tension positive); otherwise None.
    """

    boom_angle: float
    jib_angle: NDArray[np.float64]
    pivot: NDArray[np.float64]
    knuckle: NDArray[np.float64]
    boom_point: NDArray[np.float64]
    jib_point: NDArray[np.float64]
    tip: NDArray[np.float64]
    actuator_direction: NDArray[np.float64]
    actuator_force: NDArray[np.float64]
    pivot_force: NDArray[np.float64]
    pivot_moment: NDArray[np.float64]
    knuckle_force: NDArray[np.float64]
    lift_boom_point: Optional[NDArray[np.float64]] = None
    lift_direction: Optional[NDArray[np.float64]] = None
    lift_force: Optional[NDArray[np.float64]] = None


def knuckle_boom_jib_angle(
    boom_length: float,
    boom_angle: float,
    boom_point: Sequence[float],
    jib_point: Sequence[float],
    actuator_length: ArrayLike,
    branch: int = 1,
) -> NDArray:
    """Jib angle [rad] for which the actuator between P (``boom_point`` (s, n) in the
    boom frame) and Q (``jib_point`` (s, n) in the jib frame) has length
    ``actuator_length`` (scalar or array).

    With d = B - P and q = (s_j, n_j) rotated by the jib angle a2:
    |d + R(a2) q|^2 = L^2 gives a2 = atan2(d) - atan2(q) +/- arccos((L^2 - |d|^2 - |q|^2)
    / (2 |d| |q|)); ``branch`` = +1 or -1 picks the sign. Result wrapped to (-pi, pi].
    Raises ValueError if the length cannot be reached.
    """
    if branch not in (1, -1):
        raise ValueError("branch must be +1 or -1")
    e1 = _unit(boom_angle)
    P = boom_point[0] * e1 + boom_point[1] * _perp(e1)
    d = boom_length * e1 - P
    q = np.asarray(jib_point, dtype=float)
    nd, nq = np.hypot(*d), np.hypot(*q)
    L = np.asarray(actuator_length, dtype=float)
    c = (L**2 - nd**2 - nq**2) / (2.0 * nd * nq)
    if np.any(np.abs(c) > 1.0):
        raise ValueError(
            f"actuator length out of reach: needs |P B| - |B Q| <= L <= |P B| + |B Q| "
            f"= [{abs(nd - nq)}, {nd + nq}]"
        )
    a2 = np.arctan2(d[1], d[0]) - np.arctan2(q[1], q[0]) + branch * np.arccos(c)
    return np.angle(np.exp(1j * a2))


def knuckle_boom_statics(
    boom_length: float,
    boom_mass: float,
    jib_length: float,
    jib_mass: float,
    boom_angle: float,
    boom_point: Sequence[float],
    jib_point: Sequence[float],
    actuator_length: ArrayLike,
    gravity: ArrayLike = (0.0, -9.81),
    tip_load: ArrayLike = (0.0, 0.0),
    branch: int = 1,
    pivot: ArrayLike = (0.0, 0.0),
    lift_ground_point: Optional[Sequence[float]] = None,
    lift_boom_point: Optional[Sequence[float]] = None,
) -> KnuckleBoomStatics:
    """Rigid knuckle boom in quasi-static equilibrium.

    Boom: uniform rod (length L1 = ``boom_length``, mass m1) hinged to ground at ``pivot``
    O, held at the absolute angle ``boom_angle`` by a ground moment at O. Jib: uniform rod
    (L2, m2) hinged to the boom tip B. A massless actuator (a two-force member) joins P on
    the boom to Q on the jib; its length ``actuator_length`` (scalar or array, e.g. L(t)
    sampled in time) fixes the jib angle (``knuckle_boom_jib_angle``). Loads: gravity on
    both rods at their centres, ``tip_load`` at the jib's free end T. No inertia forces
    (quasi-static: valid when the drive is slow).

    Jib, moments about B: (Q - B) x (-f u) + (C2 - B) x m2 g + (T - B) x F = 0 gives the
    actuator tension f (u from P to Q); jib forces give the knuckle force
    R_B = f u - m2 g - F. Boom: R_O = R_B - f u - m1 g and, moments about O,
    M_O = -[(B - O) x (-R_B) + (P - O) x f u + (C1 - O) x m1 g].

    Optional lift cylinder (a second massless two-force member) from
    ``lift_ground_point`` G (global) to ``lift_boom_point`` P2 ((s, n) in the boom frame):
    it carries M_O instead of the ground, f_lift = M_O / ((P2 - O) x u_l) with u_l from P2
    toward G, and the pivot force becomes R_O - f_lift u_l (the boom angle is still the
    input: it fixes the lift cylinder's length |G - P2|).
    """
    g = _vec2(gravity, "gravity")
    F = _vec2(tip_load, "tip_load")
    O = _vec2(pivot, "pivot")
    a2 = knuckle_boom_jib_angle(boom_length, boom_angle, boom_point, jib_point, actuator_length, branch)
    e1 = _unit(boom_angle)
    e2 = _unit(a2)
    B = O + boom_length * e1
    P = O + boom_point[0] * e1 + boom_point[1] * _perp(e1)
    Q = B + jib_point[0] * e2 + jib_point[1] * _perp(e2)
    T = B + jib_length * e2
    C1 = O + 0.5 * boom_length * e1
    C2 = B + 0.5 * jib_length * e2
    u = (Q - P) / np.linalg.norm(Q - P, axis=-1, keepdims=True)
    # jib: moment of the loads about B, divided by the moment arm of the actuator force
    load_moment = _cross(C2 - B, jib_mass * g) + _cross(T - B, F)
    arm = _cross(Q - B, u)
    if np.any(np.abs(arm) < 1e-12 * jib_length):
        raise ValueError("the actuator line passes through the knuckle: no moment arm")
    f = load_moment / arm
    R_B = f[..., None] * u - jib_mass * g - F
    R_O = R_B - f[..., None] * u - boom_mass * g
    M_O = -(_cross(B - O, -R_B) + _cross(P - O, f[..., None] * u) + _cross(C1 - O, boom_mass * g))
    if (lift_ground_point is None) != (lift_boom_point is None):
        raise ValueError("a lift cylinder needs both lift_ground_point and lift_boom_point")
    if lift_ground_point is None:
        return KnuckleBoomStatics(float(boom_angle), a2, O, B, P, Q, T, u, f, R_O, M_O, R_B)
    P2 = O + lift_boom_point[0] * e1 + lift_boom_point[1] * _perp(e1)
    d_l = _vec2(lift_ground_point, "lift_ground_point") - P2
    u_l = d_l / np.linalg.norm(d_l)
    lift_arm = _cross(P2 - O, u_l)
    if abs(lift_arm) < 1e-12 * boom_length:
        raise ValueError("the lift cylinder line passes through the pivot: no moment arm")
    f_l = M_O / lift_arm
    return KnuckleBoomStatics(
        float(boom_angle),
        a2,
        O,
        B,
        P,
        Q,
        T,
        u,
        f,
        R_O - f_l[..., None] * u_l,
        np.zeros_like(M_O),
        R_B,
        P2,
        u_l,
        f_l,
    )


# ------------------------------------------------------------ (e) flexible knuckle boom
@dataclass(frozen=True)
class KnuckleBoomSag:
    """Small static displacements [m] of the flexible knuckle boom (global x, y), and
    the tip displacement resolved in the jib frame: ``tip_transverse`` along e2_perp
    (negative when the jib sags below its rigid line for a jib pointing right),
    ``tip_axial`` along e2. ``statics`` is the rigid-limit equilibrium used as loads."""

    tip: NDArray[np.float64]
    tip_transverse: float
    tip_axial: float
    knuckle: NDArray[np.float64]
    boom_point: NDArray[np.float64]
    jib_point: NDArray[np.float64]
    jib_chord_rotation: float
    statics: KnuckleBoomStatics


def _cantilever_point(
    s: float, a: float, P_t: float, P_a: float, EI: float, EA: float, GAs: Optional[float]
) -> tuple[float, float]:
    """(axial, transverse) displacement at s of a cantilever clamped at 0 under point
    loads P_a (axial) and P_t (transverse) at a: u = P_a min(s, a)/EA;
    v = P_t s^2 (3a - s)/(6EI) for s <= a, P_t a^2 (3s - a)/(6EI) beyond, + P_t min(s, a)/GAs."""
    m = min(s, a)
    v = P_t * (s**2 * (3 * a - s) if s <= a else a**2 * (3 * s - a)) / (6.0 * EI)
    if GAs is not None:
        v += P_t * m / GAs
    return P_a * m / EA, v


def _cantilever_uniform(
    s: float, L: float, q_t: float, q_a: float, EI: float, EA: float, GAs: Optional[float]
) -> tuple[float, float]:
    """(axial, transverse) displacement at s of a cantilever (clamped at 0, length L)
    under uniform loads q_a, q_t per length: u = q_a (L s - s^2/2)/EA,
    v = q_t s^2 (6L^2 - 4Ls + s^2)/(24EI) + q_t (L s - s^2/2)/GAs."""
    v = q_t * s**2 * (6 * L**2 - 4 * L * s + s**2) / (24.0 * EI)
    if GAs is not None:
        v += q_t * (L * s - s**2 / 2.0) / GAs
    return q_a * (L * s - s**2 / 2.0) / EA, v


def knuckle_boom_flexible_sag(
    boom_length: float,
    boom_mass: float,
    jib_length: float,
    jib_mass: float,
    boom_angle: float,
    boom_point_s: float,
    jib_point_s: float,
    actuator_length: float,
    boom_EA: float,
    boom_EI: float,
    jib_EA: float,
    jib_EI: float,
    boom_GAs: Optional[float] = None,
    jib_GAs: Optional[float] = None,
    actuator_EA: float = np.inf,
    gravity: ArrayLike = (0.0, -9.81),
    tip_load: ArrayLike = (0.0, 0.0),
    branch: int = 1,
    pivot: ArrayLike = (0.0, 0.0),
) -> KnuckleBoomSag:
    """Static sag of the knuckle boom of ``knuckle_boom_statics`` made of two flexible
    straight beams, by superposition (small deflections, loads on the undeformed shape).

    Structure: boom clamped at O (the held boom angle), jib pinned to the boom tip B,
    actuator a pin-ended bar of stiffness ``actuator_EA`` (inf: rigid) between P on the
    boom axis (arc length ``boom_point_s``) and Q on the jib axis (``jib_point_s``). It is
    statically determinate, so the rigid-limit forces are the member forces. ``*_EI`` is
    the in-plane bending stiffness, ``*_EA`` the axial one, ``*_GAs`` the shear stiffness
    (None: Euler-Bernoulli). Weight acts as a uniform load m g / L on each rod.

    1. Boom = cantilever from O under its weight, the actuator pull f u at P and the jib's
       push -R_B at B: displacements d_P, d_B (axial + bending + shear formulas).
    2. Jib relative to its chord B-Q = beam simply supported at B and Q (span a = s_Q)
       with an overhang c = L2 - a, under the transverse weight q and tip load P_t:
       M_Q = P_t c + q c^2/2; section rotation at Q theta_Q = -q a^3/(24EI) + M_Q a/(3EI);
       tip offset w_e = c theta_Q + P_t c^3/(3EI) + q c^4/(8EI) + M_Q L2/(a GAs).
       Axial stretch of B-Q and B-T from the jib's axial force.
    3. The chord rotation alpha follows from the actuator's elongation f L_act/EA_act:
       (d_Q - d_P) . u = f L_act / EA_act with d_Q = d_B + u_e(a) e2 + alpha a e2_perp.
    4. d_T = d_B + u_e(L2) e2 + (alpha L2 + w_e) e2_perp.
    """
    st = knuckle_boom_statics(
        boom_length,
        boom_mass,
        jib_length,
        jib_mass,
        boom_angle,
        (boom_point_s, 0.0),
        (jib_point_s, 0.0),
        actuator_length,
        gravity,
        tip_load,
        branch,
        pivot,
    )
    if np.ndim(st.jib_angle) != 0:
        raise ValueError("knuckle_boom_flexible_sag takes one actuator length at a time")
    if not (0.0 < boom_point_s <= boom_length and 0.0 < jib_point_s <= jib_length):
        raise ValueError("the actuator ends must lie on the rods: 0 < s <= length")
    g = _vec2(gravity, "gravity")
    F = _vec2(tip_load, "tip_load")
    f, u = float(st.actuator_force), st.actuator_direction
    e1, e2 = _unit(boom_angle), _unit(float(st.jib_angle))
    n1, n2 = _perp(e1), _perp(e2)
    L1, L2, a = boom_length, jib_length, jib_point_s

    # 1. boom cantilever
    boom_loads = ((boom_point_s, f * u), (L1, -st.knuckle_force))
    w1 = boom_mass * g / L1

    def boom_displacement(s: float) -> NDArray:
        ua, va = _cantilever_uniform(s, L1, w1 @ n1, w1 @ e1, boom_EI, boom_EA, boom_GAs)
        for pos, load in boom_loads:
            du, dv = _cantilever_point(s, pos, load @ n1, load @ e1, boom_EI, boom_EA, boom_GAs)
            ua, va = ua + du, va + dv
        return ua * e1 + va * n1

    dP, dB = boom_displacement(boom_point_s), boom_displacement(L1)

    # 2. jib relative to its chord
    w2 = jib_mass * g / L2
    q, p = w2 @ n2, w2 @ e2
    Pt, Pa = F @ n2, F @ e2
    c = L2 - a
    M_Q = Pt * c + q * c**2 / 2.0
    theta_Q = -q * a**3 / (24.0 * jib_EI) + M_Q * a / (3.0 * jib_EI)
    w_e = c * theta_Q + Pt * c**3 / (3.0 * jib_EI) + q * c**4 / (8.0 * jib_EI)
    if jib_GAs is not None:
        w_e += M_Q * L2 / (a * jib_GAs)
    u_Q = (p * (L2 * a - a**2 / 2.0) + (Pa - f * (u @ e2)) * a) / jib_EA
    u_T = u_Q + (p * c**2 / 2.0 + Pa * c) / jib_EA

    # 3. actuator compatibility -> chord rotation
    L_act = float(np.linalg.norm(st.jib_point - st.boom_point))
    stretch = f * L_act / actuator_EA
    alpha = (stretch - (dB - dP) @ u - u_Q * (e2 @ u)) / (a * (n2 @ u))

    # 4. tip
    dQ = dB + u_Q * e2 + alpha * a * n2
    dT = dB + u_T * e2 + (alpha * L2 + w_e) * n2
    return KnuckleBoomSag(dT, float(dT @ n2), float(dT @ e2), dB, dP, dQ, float(alpha), st)
