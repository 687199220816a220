"""Closed-form results of linear beam theory (textbook formulas), used to check the
finite-element reference ``frames.py`` and, directly, the project's beams.

Every function is a hand formula (or the root of a classical frequency equation found
with ``scipy.optimize.brentq``); nothing here is a discretization.

Conventions
-----------
* SI units throughout (m, N, kg, s, Pa); angular frequencies in rad/s.
* ``EI`` bending stiffness [N m^2], ``EA`` axial stiffness [N], ``GJ`` torsional
  stiffness [N m^2], ``GAs`` shear stiffness G * k * A [N] with the shear coefficient k
  folded in (the project uses k = 1, i.e. shear area = A). ``GAs=None`` means
  Euler-Bernoulli (shear-rigid); a number adds the Timoshenko shear term.
* Loads and displacements are positive in the same direction (a deflection has the
  sign of the load that causes it). Rotations are positive in the sense that turns the
  beam axis toward the positive deflection.
* Small deflections, linear elastic material, straight prismatic members.
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

__all__ = [
    "CLAMPED_FREE_BETA_L",
    "cantilever_tip_load",
    "cantilever_uniform_load",
    "cantilever_end_moment",
    "simply_supported_uniform_load",
    "clamped_free_beta_l",
    "simply_supported_beta_l",
    "euler_bernoulli_frequency",
    "tip_mass_beta_l",
    "tip_mass_frequencies",
    "simply_supported_timoshenko_frequencies",
    "l_frame_tip_displacement",
    "l_grillage_tip_deflection",
]

#: Roots beta_n L of the clamped-free frequency equation 1 + cos(bL) cosh(bL) = 0.
CLAMPED_FREE_BETA_L: tuple[float, ...] = (1.875104068711961, 4.694091132974175, 7.854757438237613)


def _shear_term(value: float, GAs: Optional[float]) -> float:
    """``value / GAs`` for a Timoshenko beam, 0 for Euler-Bernoulli (``GAs`` None)."""
    return 0.0 if GAs is None else value / GAs


def cantilever_tip_load(
    P: float, L: float, EI: float, GAs: Optional[float] = None
) -> tuple[float, float]:
    """Cantilever of length ``L`` clamped at one end, transverse point load ``P`` at the
    free end: returns (tip deflection, tip rotation) = (P L^3/(3EI) + P L/GAs, P L^2/(2EI)).

    The rotation is the bending rotation of the cross-section (for Timoshenko it is not
    the slope of the axis, which also carries the shear angle P/GAs).
    """
    return P * L**3 / (3.0 * EI) + _shear_term(P * L, GAs), P * L**2 / (2.0 * EI)


def cantilever_uniform_load(
    q: float, L: float, EI: float, GAs: Optional[float] = None
) -> tuple[float, float]:
    """Cantilever of length ``L`` under a uniform transverse load ``q`` [N/m]: returns
    (tip deflection, tip section rotation) = (q L^4/(8EI) + q L^2/(2 GAs), q L^3/(6EI))."""
    return q * L**4 / (8.0 * EI) + _shear_term(q * L**2 / 2.0, GAs), q * L**3 / (6.0 * EI)


def cantilever_end_moment(M: float, L: float, EI: float) -> tuple[float, float]:
    """Cantilever of length ``L`` with an end moment ``M`` [N m] at the free end: returns
    (tip deflection, tip rotation) = (M L^2/(2EI), M L/EI). No shear (the shear force is 0)."""
    return M * L**2 / (2.0 * EI), M * L / EI


def simply_supported_uniform_load(q: float, L: float, EI: float, GAs: Optional[float] = None) -> float:
    """Simply supported span ``L`` under a uniform load ``q``: mid-span deflection
    5 q L^4/(384 EI) + q L^2/(8 GAs)."""
    return 5.0 * q * L**4 / (384.0 * EI) + _shear_term(q * L**2 / 8.0, GAs)


def _bracketed_roots(f, lo: float, hi: float, n_roots: int, step: float) -> NDArray[np.float64]:
    """First ``n_roots`` roots of the continuous function ``f`` on (lo, hi): sign changes on
    a grid of spacing ``step`` (``f`` is evaluated on the whole grid at once, so it must
    accept arrays), each refined by brentq to machine precision."""
    grid = np.arange(lo, hi + step, step)
    values = f(grid)
    roots: list[float] = []
    for i in np.flatnonzero(values[:-1] * values[1:] <= 0.0):
        a, b = float(grid[i]), float(grid[i + 1])
        if values[i] == 0.0:
            roots.append(a)
        else:
            roots.append(
                brentq(lambda x: float(f(x)), a, b, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
            )
        if len(roots) == n_roots:
            return np.array(roots)
    raise ValueError(f"found only {len(roots)} of {n_roots} roots below {hi}")


def clamped_free_beta_l(n_modes: int = 3) -> NDArray[np.float64]:
    """Roots beta_n L of 1 + cos(x) cosh(x) = 0 (clamped-free Euler-Bernoulli beam),
    computed with brentq; the first three equal ``CLAMPED_FREE_BETA_L``."""
    return _bracketed_roots(
        lambda x: np.cos(x) + 1.0 / np.cosh(x), 0.5, 4.0 * n_modes + 4.0, n_modes, 0.05
    )


def simply_supported_beta_l(n_modes: int = 3) -> NDArray[np.float64]:
    """beta_n L = n pi for a simply supported (pinned-pinned) Euler-Bernoulli beam."""
    return np.pi * np.arange(1, n_modes + 1, dtype=float)


def euler_bernoulli_frequency(beta_l, L: float, EI: float, rho_A: float):
    """Angular frequency [rad/s] omega = (beta L)^2 sqrt(EI / (rho A L^4)) of an
    Euler-Bernoulli beam of length ``L`` and mass per length ``rho_A`` [kg/m], for the
    eigenvalue(s) ``beta_l`` of its boundary conditions (no rotary inertia)."""
    return np.asarray(beta_l, dtype=float) ** 2 * math.sqrt(EI / (rho_A * L**4))


def _tip_mass_determinant(lam, mu: float, j: float, eps: float):
    """Determinant of the two tip conditions of a clamped-free beam with a tip body
    (``lam`` a scalar or an array).

    Mode shape W(xi) = A (cosh lam xi - cos lam xi) + B (sinh lam xi - sin lam xi),
    xi = x/L (clamped at xi = 0). The tip body (mass ratio mu = M/(rho A L), rotary
    inertia ratio j = J_c/(rho A L^3) about its centre of mass, centre of mass at the
    axial offset eps = e/L beyond the tip) moves with the tip: its centre of mass
    translates by W + eps W'. From the Lagrangian, at xi = 1:

        W'''  = -mu lam^4 (W + eps W')                       (shear balances its inertia)
        W''   =  lam^4 [mu eps (W + eps W') + j W']          (moment balances its inertia)

    The row coefficients are divided by cosh(lam) to keep them O(1).
    """
    lam = np.asarray(lam, dtype=float)
    ch, sh, c, s = np.cosh(lam), np.sinh(lam), np.cos(lam), np.sin(lam)
    w = np.array([ch - c, sh - s])
    w1 = lam * np.array([sh + s, ch - c])
    w2 = lam**2 * np.array([ch + c, sh + s])
    w3 = lam**3 * np.array([sh - s, ch + c])
    l4 = lam**4
    tip = w + eps * w1
    row1 = w3 + mu * l4 * tip
    row2 = w2 - l4 * (mu * eps * tip + j * w1)
    return (row1[0] * row2[1] - row1[1] * row2[0]) / ch**2


def tip_mass_beta_l(
    mass_ratio: float, inertia_ratio: float = 0.0, offset_ratio: float = 0.0, n_modes: int = 1
) -> NDArray[np.float64]:
    """Eigenvalues lambda_n = beta_n L of an Euler-Bernoulli clamped-free beam carrying a
    rigid tip body.

    Parameters (dimensionless): ``mass_ratio`` mu = M / (rho A L); ``inertia_ratio``
    j = J_c / (rho A L^3) with J_c the body's rotary inertia about its own centre of mass
    (about the bending axis); ``offset_ratio`` eps = e / L, the body's centre of mass lying
    on the beam axis a distance e beyond the tip. Frequencies follow from
    ``euler_bernoulli_frequency``. mu = j = 0 gives the plain clamped-free roots
    (1.8751, 4.6941, ...); mu = 1, j = 0 gives 1.24792 (classical tables).
    """
    f = lambda lam: _tip_mass_determinant(lam, mass_ratio, inertia_ratio, offset_ratio)  # noqa: E731
    return _bracketed_roots(f, 1e-3, 4.0 * n_modes + 8.0, n_modes, 0.01)


def tip_mass_frequencies(
    L: float,
    EI: float,
    rho_A: float,
    tip_mass: float,
    tip_inertia: float = 0.0,
    offset: float = 0.0,
    n_modes: int = 1,
) -> NDArray[np.float64]:
    """Lowest angular frequencies [rad/s] of a clamped-free Euler-Bernoulli beam (length
    ``L``, bending stiffness ``EI``, mass per length ``rho_A``) with a rigid body at its
    free end: mass ``tip_mass`` [kg], rotary inertia ``tip_inertia`` [kg m^2] about its
    centre of mass, centre of mass ``offset`` [m] beyond the tip along the beam axis.
    Solves the classical transcendental frequency equation (``tip_mass_beta_l``)."""
    lam = tip_mass_beta_l(tip_mass / (rho_A * L), tip_inertia / (rho_A * L**3), offset / L, n_modes)
    return euler_bernoulli_frequency(lam, L, EI, rho_A)


def simply_supported_timoshenko_frequencies(
    L: float, EI: float, GAs: float, rho_A: float, rho_I: float, n_modes: int = 3
) -> NDArray[np.float64]:
    """Flexural angular frequencies [rad/s] of a simply supported Timoshenko beam.

    Equations rho_A w_tt = GAs (w'' - theta'), rho_I theta_tt = EI theta'' + GAs (w' - theta)
    with w = W sin(k x), theta = T cos(k x), k = n pi / L give for each n the quadratic
    rho_A rho_I w^4 - [rho_A (EI k^2 + GAs) + rho_I GAs k^2] w^2 + EI GAs k^4 = 0; the
    lower root is the flexural mode n. ``rho_I`` [kg m] is the rotary inertia per length
    (rho times the second moment); 0 drops rotary inertia (then w^2 = EI k^4 / rho_A /
    (1 + EI k^2 / GAs)).
    """
    k = np.pi * np.arange(1, n_modes + 1, dtype=float) / L
    b = rho_A * (EI * k**2 + GAs) + rho_I * GAs * k**2
    c = EI * GAs * k**4
    if rho_I == 0.0:
        return np.sqrt(c / b)
    a = rho_A * rho_I
    # Lower root written without cancellation: 2c / (b + sqrt(b^2 - 4ac)).
    return np.sqrt(2.0 * c / (b + np.sqrt(b**2 - 4.0 * a * c)))


def l_frame_tip_displacement(
    H: float,
    L: float,
    Fx: float,
    Fy: float,
    column_EA: float,
    column_EI: float,
    beam_EA: float,
    beam_EI: float,
    column_GAs: Optional[float] = None,
    beam_GAs: Optional[float] = None,
) -> tuple[float, float]:
    """Planar L-frame by the unit-load method (virtual work with M, N and V).

    The column runs from the clamped base (0, 0) up to the corner (0, H); the beam runs
    from the corner to the free tip (L, H); a point load (Fx, Fy) acts at the tip.
    Internal forces: beam M = (L - s) Fy, N = Fx, V = Fy; column M = L Fy - (H - y) Fx,
    N = Fy, V = Fx. Returns the tip displacement (dx, dy):

        dx = Fx L/EA_b + (Fx H^3/3 - Fy L H^2/2)/EI_c + Fx H/GAs_c
        dy = Fy L^3/(3 EI_b) + L (Fy L H - Fx H^2/2)/EI_c + Fy H/EA_c + Fy L/GAs_b
    """
    dx = (
        Fx * L / beam_EA
        + (Fx * H**3 / 3.0 - Fy * L * H**2 / 2.0) / column_EI
        + _shear_term(Fx * H, column_GAs)
    )
    dy = (
        Fy * L**3 / (3.0 * beam_EI)
        + L * (Fy * L * H - Fx * H**2 / 2.0) / column_EI
        + Fy * H / column_EA
        + _shear_term(Fy * L, beam_GAs)
    )
    return dx, dy


def l_grillage_tip_deflection(
    P: float,
    L1: float,
    L2: float,
    EI1: float,
    GJ1: float,
    EI2: float,
    GAs1: Optional[float] = None,
    GAs2: Optional[float] = None,
) -> float:
    """Out-of-plane deflection of a horizontal L (grillage): member 1 (length ``L1``)
    clamped at its root, member 2 (length ``L2``) rigidly joined at right angles to its
    end, load ``P`` normal to the plane of the L at the free end of member 2.

    Member 2 bends as a cantilever, member 1 bends under P and twists under the torque
    P L2 (the twist swings member 2 through L2 * angle):
    d = P [L1^3/(3 EI1) + L2^3/(3 EI2) + L1 L2^2/GJ1] (+ P L1/GAs1 + P L2/GAs2).
    ``EI1``, ``EI2`` are the stiffnesses for bending out of the plane of the L.
    """
    return (
        P * (L1**3 / (3.0 * EI1) + L2**3 / (3.0 * EI2) + L1 * L2**2 / GJ1)
        + _shear_term(P * L1, GAs1)
        + _shear_term(P * L2, GAs2)
    )
