"""Closed-form / quadrature reference for the two-leaf spring of SPEC section 7.

Linear (small-deflection) curved-beam theory, no finite elements: every quantity is a
Castigliano / unit-load integral over a circular arc, evaluated in closed form where
that is short (straight beams, the tip compliances of an arc) and otherwise by
Gauss-Legendre quadrature of a smooth integrand (exact to rounding for these
trigonometric integrands). The statically indeterminate contact reaction of the two
leaves comes from one compatibility equation. The derivation, the assumptions and a
table of the SPEC numbers are in ``docs/leaf_spring.md``.

This module imports only numpy and the standard library, so it can be used (and
tested) as a plain file, without the compiled package.

Frame and signs
---------------
A *half spring* is a cantilever clamped at the axle (the middle of the leaf, arc length
s = 0) and free at the eye. Coordinates are (x, z) in the r1-r3 plane, x along r1 from
the axle toward the eye of the half considered (the half at r1 > 0; the other half is
its mirror image), z along r3 (up). A circular leaf of radius R, concave up, clamped
with zero slope at its lowest point, has its mid-surface at

    x(s) = R sin(s/R),   z(s) = R (1 - cos(s/R)) = 2 R sin^2(s/(2R)),

tangent t = (cos phi, sin phi) and inward (upward) normal n = (-sin phi, cos phi),
phi = s/R. ``radius = inf`` is the straight leaf.

Bending moments are counted positive counterclockwise in the (x, z) drawing (from +x
toward +z); the moment M(s) is the moment that the part (s, L] exerts on [0, s], and the
curvature change is M / EI (a positive change makes the leaf more concave up).

Units are SI (m, N, kg, s, Pa).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "LeafSpringSpec",
    "SPEC",
    "beam_bending_stiffness",
    "plate_bending_stiffness",
    "bending_stiffness_bounds",
    "BEAM_EI",
    "PLATE_DW",
    "CONCENTRIC_LOWER_RADIUS",
    "SPEC_LITERAL_LOWER_RADIUS",
    "arc_point",
    "UnitLoad",
    "cantilever_flexibility",
    "cantilever_displacements",
    "curved_cantilever_compliance",
    "curved_cantilever_tip_compliances_closed_form",
    "contact_geometry",
    "two_leaf_half",
    "interleaf_gap_change",
    "two_leaf_half_stiffness",
    "prestress_preload",
    "chassis_static_drop",
    "load_cycle",
    "bounce_frequency",
    "reference_table",
]

FloatArray = NDArray[np.float64]
INF = math.inf


# ---------------------------------------------------------------------------
# SPEC data (section 7)
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class LeafSpringSpec:
    """The data of SPEC section 7 (the geometry is the project's own choice).

    Geometry of the lower leaf: the SPEC asks for a leaf concentric with the main leaf
    and 0.014 m below it, and writes its radius as 1.986 m. For concave-up leaves (centre
    of curvature above) a concentric leaf 0.014 m *below* has the radius 2.0 + 0.014 =
    2.014 m (1.986 m would put it above). The default here is the concentric 2.014 m
    (:data:`CONCENTRIC_LOWER_RADIUS`, the default of the simulation's
    ``spring.lower_radius``): the leaves touch without gap or overlap when assembled.
    The literal reading, radius 1.986 m with its middle 0.014 m below the main leaf's
    (:data:`SPEC_LITERAL_LOWER_RADIUS`), overlaps the main leaf by 0.56 mm at the tips
    (see :func:`contact_geometry`); pass ``lower_radius=1.986`` to use it.
    """

    thickness: float = 0.014
    width: float = 0.07
    youngs_modulus: float = 2.1e11
    poisson_ratio: float = 0.3
    density: float = 7810.0
    gravity: float = 9.81
    main_arc_length: float = 1.2
    main_radius: float = 2.0
    lower_arc_length: float = 0.8
    lower_radius: float = 2.014
    lower_offset: float = 0.014
    prestress_free_radius: float = 1.5
    chassis_mass: float = 500.0
    shackle_mass: float = 2.0
    shackle_length: float = 0.1
    contact_penalty: float = 1.0e6
    contact_points_per_edge: int = 3

    @property
    def main_length(self) -> float:
        """Half arc length of the main leaf (axle to eye), L = 0.6 m."""
        return self.main_arc_length / 2.0

    @property
    def lower_length(self) -> float:
        """Half arc length of the lower leaf (axle to tip), a = 0.4 m."""
        return self.lower_arc_length / 2.0

    @property
    def line_weight(self) -> float:
        """Weight of a leaf per unit arc length, rho g w h (N/m)."""
        return self.density * self.gravity * self.width * self.thickness

    @property
    def chassis_weight(self) -> float:
        """W = m g of the chassis (N)."""
        return self.chassis_mass * self.gravity

    @property
    def contact_stiffness(self) -> float:
        """Total penalty stiffness per lower-leaf tip, k_c = points per edge x K (N/m)."""
        return self.contact_points_per_edge * self.contact_penalty

    @property
    def axial_stiffness(self) -> float:
        """EA of a leaf (N)."""
        return self.youngs_modulus * self.width * self.thickness

    @property
    def shear_stiffness(self) -> float:
        """k G A of a leaf with k = 5/6 (N); the Kirchhoff plate has no shear strain."""
        g_mod = self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
        return 5.0 / 6.0 * g_mod * self.width * self.thickness


SPEC = LeafSpringSpec()

#: Radius of a lower leaf concentric with the SPEC main leaf, 0.014 m below it (the default).
CONCENTRIC_LOWER_RADIUS: float = SPEC.main_radius + SPEC.lower_offset
#: The lower leaf's radius as the SPEC writes it (middle 0.014 m below: 0.56 mm overlap).
SPEC_LITERAL_LOWER_RADIUS: float = 1.986


def beam_bending_stiffness(youngs_modulus: float = SPEC.youngs_modulus,
                           width: float = SPEC.width,
                           thickness: float = SPEC.thickness) -> float:
    """Beam bending stiffness EI = E w h^3 / 12 (anticlastic curvature free: the lower
    bound, the one a strip with free lateral edges approaches)."""
    return youngs_modulus * width * thickness**3 / 12.0


def plate_bending_stiffness(youngs_modulus: float = SPEC.youngs_modulus,
                            poisson_ratio: float = SPEC.poisson_ratio,
                            width: float = SPEC.width,
                            thickness: float = SPEC.thickness) -> float:
    """Plate strip bending stiffness D w = E w h^3 / (12 (1 - nu^2)) (anticlastic
    curvature suppressed, cylindrical bending: the upper bound)."""
    return youngs_modulus * width * thickness**3 / (12.0 * (1.0 - poisson_ratio**2))


def bending_stiffness_bounds(spec: LeafSpringSpec = SPEC) -> dict[str, float]:
    """{'beam': E w h^3/12, 'plate': E w h^3/(12 (1 - nu^2))} for the leaf of ``spec``."""
    return {
        "beam": beam_bending_stiffness(spec.youngs_modulus, spec.width, spec.thickness),
        "plate": plate_bending_stiffness(spec.youngs_modulus, spec.poisson_ratio,
                                         spec.width, spec.thickness),
    }


#: EI of the SPEC leaf, 3361.4 N m^2.
BEAM_EI: float = bending_stiffness_bounds()["beam"]
#: D w of the SPEC leaf, 3693.8 N m^2.
PLATE_DW: float = bending_stiffness_bounds()["plate"]


# ---------------------------------------------------------------------------
# Arc geometry and quadrature
# ---------------------------------------------------------------------------

def arc_point(s: float | FloatArray, radius: float) -> tuple[FloatArray, FloatArray]:
    """Mid-surface point (x, z) at arc length ``s`` from the clamped lowest point of a
    concave-up circular arc of ``radius`` (inf: straight), in the leaf's own frame."""
    s = np.asarray(s, dtype=float)
    if not math.isfinite(radius):
        return s.copy(), np.zeros_like(s)
    phi = s / radius
    return radius * np.sin(phi), 2.0 * radius * np.sin(phi / 2.0) ** 2


def _tangent(s: FloatArray, radius: float) -> tuple[FloatArray, FloatArray]:
    s = np.asarray(s, dtype=float)
    if not math.isfinite(radius):
        return np.ones_like(s), np.zeros_like(s)
    return np.cos(s / radius), np.sin(s / radius)


@lru_cache(maxsize=8)
def _gauss(n: int) -> tuple[FloatArray, FloatArray]:
    return np.polynomial.legendre.leggauss(n)


_NGAUSS = 32  # the integrands are trigonometric polynomials of s/R: exact to rounding


def _nodes(a: float, b: float, n: int = _NGAUSS) -> tuple[FloatArray, FloatArray]:
    """Gauss-Legendre nodes and weights on [a, b]."""
    x, w = _gauss(n)
    half = 0.5 * (b - a)
    return 0.5 * (a + b) + half * x, half * w


@dataclass(frozen=True)
class UnitLoad:
    """A generalized load on a clamped curved cantilever: force (fx, fz) and moment
    ``moment`` (counterclockwise positive) applied at arc length ``s``.

    Its work-conjugate displacement is fx u_x + fz u_z + moment * theta at that point
    (e.g. ``UnitLoad(L, 0, -1)`` is a downward unit force at the tip and its conjugate
    displacement the downward tip deflection).
    """

    s: float
    fx: float = 0.0
    fz: float = 0.0
    moment: float = 0.0

    def resultants(self, s: FloatArray, radius: float) -> tuple[FloatArray, FloatArray,
                                                                   FloatArray]:
        """(M, N, V) at sections ``s`` (all assumed <= self.s): bending moment, axial
        force (tension positive) and shear force (along the upward normal)."""
        x, z = arc_point(s, radius)
        xj, zj = arc_point(self.s, radius)
        tx, tz = _tangent(s, radius)
        m = (xj - x) * self.fz - (zj - z) * self.fx + self.moment
        n = self.fx * tx + self.fz * tz
        v = -self.fx * tz + self.fz * tx
        return m, n, v


def _energy_product(mi, ni, vi, mj, nj, vj, w, bending_stiffness, axial_stiffness,
                    shear_stiffness) -> float:
    total = np.dot(w, mi * mj) / bending_stiffness
    if math.isfinite(axial_stiffness):
        total += np.dot(w, ni * nj) / axial_stiffness
    if math.isfinite(shear_stiffness):
        total += np.dot(w, vi * vj) / shear_stiffness
    return float(total)


def cantilever_flexibility(radius: float, bending_stiffness: float,
                           loads: Sequence[UnitLoad],
                           axial_stiffness: float = INF,
                           shear_stiffness: float = INF,
                           probes: Sequence[UnitLoad] | None = None) -> FloatArray:
    """Flexibility matrix F[i, j] of a curved cantilever clamped at s = 0 (unit-load
    method / Castigliano): the displacement conjugate to ``probes[i]`` (default: the
    loads themselves) caused by a unit ``loads[j]``,

        F_ij = int_0^min(s_i, s_j) [ M_i M_j / EI + N_i N_j / EA + V_i V_j / (k G A) ] ds.

    The axial and shear terms are left out when their stiffness is inf (the default:
    bending only, which is the thin-leaf theory). Without ``probes`` F is symmetric
    (Maxwell-Betti)."""
    same = probes is None
    probes = loads if probes is None else probes
    flex = np.zeros((len(probes), len(loads)))
    for i, probe in enumerate(probes):
        for j, load in enumerate(loads):
            if same and j < i:
                flex[i, j] = flex[j, i]
                continue
            end = min(probe.s, load.s)
            if end <= 0.0:
                continue
            s, w = _nodes(0.0, end)
            flex[i, j] = _energy_product(*probe.resultants(s, radius),
                                         *load.resultants(s, radius), w,
                                         bending_stiffness, axial_stiffness,
                                         shear_stiffness)
    return flex


def _line_load_resultants(s: FloatArray, radius: float, qx: float, qz: float,
                          load_end: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(M, N, V) at sections s <= load_end of a load (qx, qz) per unit arc length on
    [s, load_end] (inner Gauss rule on each [s, load_end])."""
    m = np.empty_like(s)
    fx_total = qx * (load_end - s)
    fz_total = qz * (load_end - s)
    x, z = arc_point(s, radius)
    for k, sk in enumerate(s):
        t, wt = _nodes(sk, load_end)
        xt, zt = arc_point(t, radius)
        m[k] = np.dot(wt, (xt - x[k]) * qz - (zt - z[k]) * qx)
    tx, tz = _tangent(s, radius)
    return m, fx_total * tx + fz_total * tz, -fx_total * tz + fz_total * tx


def cantilever_displacements(radius: float, bending_stiffness: float,
                             loads: Sequence[UnitLoad], *,
                             line_load: tuple[float, float] = (0.0, 0.0),
                             line_load_length: float = 0.0,
                             eigen_curvature: float = 0.0,
                             eigen_curvature_length: float = 0.0,
                             axial_stiffness: float = INF,
                             shear_stiffness: float = INF) -> FloatArray:
    """Displacements conjugate to each of ``loads`` (used here as unit *probes*) caused
    by a uniform load ``line_load`` = (qx, qz) per unit arc length on [0,
    line_load_length] and by a uniform stress-free ("eigen") curvature change
    ``eigen_curvature`` on [0, eigen_curvature_length] (unit-load theorem with an initial
    strain: d_i = int M_i kappa0 ds; a positive kappa0 makes the leaf more concave up)."""
    out = np.zeros(len(loads))
    qx, qz = line_load
    for i, probe in enumerate(loads):
        end = min(probe.s, line_load_length)
        if end > 0.0 and (qx != 0.0 or qz != 0.0):
            s, w = _nodes(0.0, end)
            ri = probe.resultants(s, radius)
            rq = _line_load_resultants(s, radius, qx, qz, line_load_length)
            out[i] += _energy_product(*ri, *rq, w, bending_stiffness, axial_stiffness,
                                      shear_stiffness)
        end = min(probe.s, eigen_curvature_length)
        if end > 0.0 and eigen_curvature != 0.0:
            s, w = _nodes(0.0, end)
            mi = probe.resultants(s, radius)[0]
            out[i] += eigen_curvature * float(np.dot(w, mi))
    return out


# ---------------------------------------------------------------------------
# 1. One curved cantilever
# ---------------------------------------------------------------------------

def curved_cantilever_compliance(length: float, radius: float, bending_stiffness: float,
                                 load_at: float | None = None,
                                 axial_stiffness: float = INF,
                                 shear_stiffness: float = INF) -> float:
    """Vertical compliance of a concave-up curved cantilever (clamped with zero slope at
    its lowest point, arc length ``length``): the downward deflection of the tip per
    unit downward force at arc length ``load_at`` (default: the tip). By Maxwell's
    reciprocity this is also the deflection at ``load_at`` per unit tip force.

    Bending only unless ``axial_stiffness`` (EA) / ``shear_stiffness`` (k G A) are
    given. Straight limit (radius = inf): L^3/(3 EI), and a^2 (3 L - a)/(6 EI) at a."""
    load_at = length if load_at is None else load_at
    if not 0.0 <= load_at <= length:
        raise ValueError(f"load_at={load_at} outside [0, {length}]")
    flex = cantilever_flexibility(radius, bending_stiffness,
                                  [UnitLoad(length, 0.0, -1.0), UnitLoad(load_at, 0.0, -1.0)],
                                  axial_stiffness, shear_stiffness)
    return float(flex[0, 1])


def curved_cantilever_tip_compliances_closed_form(length: float, radius: float,
                                                  bending_stiffness: float
                                                  ) -> dict[str, float]:
    """Closed-form tip compliances of a concave-up circular cantilever (bending only),
    Phi = L / R:

    * 'zz': downward tip deflection per downward tip force
      R^3/EI [Phi - 2 sin Phi + 3/4 sin 2Phi - Phi/2 cos 2Phi]   (-> L^3/(3 EI))
    * 'xz': outward (away from the axle) tip displacement per downward tip force,
      = downward deflection per outward force,
      R^3/EI [cos Phi - 3/4 cos 2Phi - 1/4 - Phi/2 sin 2Phi]      (-> 5 L^4/(24 R EI))
    * 'xx': outward tip displacement per outward tip force
      R^3/EI [Phi + Phi/2 cos 2Phi - 3/4 sin 2Phi]                (-> 2 L^5/(15 R^2 EI))

    For Phi < 0.05 the Taylor series (to Phi^15) replaces the cancelling closed form."""
    if not math.isfinite(radius):
        return {"zz": length**3 / (3.0 * bending_stiffness), "xz": 0.0, "xx": 0.0}
    p = length / radius
    if p < 0.05:
        zz = (p**3 / 3 - 3 * p**5 / 20 + 13 * p**7 / 504 - 11 * p**9 / 5184
              + 683 * p**11 / 6652800 - 133 * p**13 / 40435200
              + 3781 * p**15 / 50295168000)
        xz = (5 * p**4 / 24 - 49 * p**6 / 720 + 107 * p**8 / 13440
              - 1793 * p**10 / 3628800 + 9217 * p**12 / 479001600
              - 15019 * p**14 / 29059430400)
        xx = (2 * p**5 / 15 - 8 * p**7 / 315 + 2 * p**9 / 945 - 16 * p**11 / 155925
              + 4 * p**13 / 1216215 - 16 * p**15 / 212837625)
    else:
        zz = p - 2 * math.sin(p) + 0.75 * math.sin(2 * p) - 0.5 * p * math.cos(2 * p)
        xz = math.cos(p) - 0.75 * math.cos(2 * p) - 0.25 - 0.5 * p * math.sin(2 * p)
        xx = p + 0.5 * p * math.cos(2 * p) - 0.75 * math.sin(2 * p)
    scale = radius**3 / bending_stiffness
    return {"zz": zz * scale, "xz": xz * scale, "xx": xx * scale}


# ---------------------------------------------------------------------------
# 2. Contact geometry and the two-leaf half spring
# ---------------------------------------------------------------------------

def contact_geometry(main_radius: float = SPEC.main_radius,
                     lower_radius: float = SPEC.lower_radius,
                     lower_length: float = SPEC.lower_length,
                     thickness: float = SPEC.thickness,
                     lower_offset: float = SPEC.lower_offset) -> dict[str, float]:
    """Where the lower leaf's tip (the upper corner of its end edge) meets the main
    leaf's lower surface in the assembled state.

    Both leaves are concave-up arcs with zero slope at their middles; the lower leaf's
    middle is ``lower_offset`` below the main leaf's. Returns

    * 'arc_length': s_c, arc length on the main leaf's mid-surface of the point whose
      lower-surface normal passes through the lower tip;
    * 'normal_angle': angle of the main leaf's upward normal n_c there from r3 (= s_c/R);
    * 'gap': signed normal gap g0 between the lower tip and the main leaf's lower
      surface (negative: overlap). Zero for concentric leaves (lower_radius =
      main_radius + lower_offset, lower_offset = thickness);
    * 'arm': moment arm of a unit force -n_c at the tip's upper corner about the lower
      leaf's mid-surface end point (its moment, counterclockwise positive; ~1e-5 m);
    * 'offset_x', 'offset_z': the vector from the lower tip's mid-surface end point to
      its upper corner (h/2 along the lower leaf's normal).
    """
    if math.isfinite(main_radius) != math.isfinite(lower_radius):
        raise ValueError("both leaves straight or both curved")
    h2 = thickness / 2.0
    if not math.isfinite(main_radius):
        return {"arc_length": lower_length, "normal_angle": 0.0,
                "gap": lower_offset - thickness, "arm": 0.0, "offset_x": 0.0,
                "offset_z": h2}
    alpha = lower_length / lower_radius
    centre_lower_z = lower_radius - lower_offset
    # tip mid-surface point and its upper-surface corner
    mid = np.array([lower_radius * math.sin(alpha),
                    centre_lower_z - lower_radius * math.cos(alpha)])
    corner = np.array([(lower_radius - h2) * math.sin(alpha),
                       centre_lower_z - (lower_radius - h2) * math.cos(alpha)])
    d = corner - np.array([0.0, main_radius])
    dist = float(np.hypot(*d))
    angle = math.atan2(d[0], -d[1])
    n_c = -d / dist
    arm_vec = corner - mid
    arm = float(arm_vec[0] * (-n_c[1]) - arm_vec[1] * (-n_c[0]))
    return {"arc_length": main_radius * angle, "normal_angle": angle,
            "gap": dist - (main_radius + h2), "arm": arm,
            "offset_x": float(arm_vec[0]), "offset_z": float(arm_vec[1])}


def _half_setup(main_length, lower_length, main_radius, lower_radius, lower_offset,
                thickness, contact_angle, bending_stiffness, axial_stiffness,
                shear_stiffness, line_weight, lower_free_radius, friction):
    """Flexibilities and load displacements of one half spring. Generalized loads on the
    main leaf: (H out, P down, R); probes: (eye x, eye -z, normal at s_c, tangential at
    the lower surface); lower tip: load R, probes (normal, tangential) at the corner."""
    geo = contact_geometry(main_radius, lower_radius, lower_length, thickness, lower_offset)
    angle = geo["normal_angle"] if contact_angle is None else contact_angle
    nx, nz = -math.sin(angle), math.cos(angle)
    tx, tz = nz, -nx                                   # tangent at s_c, toward the eye
    s_c = geo["arc_length"]
    if not 0.0 < s_c <= main_length:
        raise ValueError(f"contact point s_c={s_c} not on the main leaf")
    h2 = thickness / 2.0
    dx, dz = geo["offset_x"], geo["offset_z"]           # lower tip: mid -> corner
    mu = friction
    # per unit R: normal force n + friction mu t on the main leaf's lower surface point
    # (-h/2 n from the mid-surface: moment (-h/2 n) x (mu t) = +mu h/2), the opposite on
    # the lower tip's corner (moment d x f)
    fx, fz = nx + mu * tx, nz + mu * tz
    eye_h, eye_p = UnitLoad(main_length, 1.0, 0.0), UnitLoad(main_length, 0.0, -1.0)
    main_loads = [eye_h, eye_p, UnitLoad(s_c, fx, fz, mu * h2)]
    main_probes = [eye_h, eye_p, UnitLoad(s_c, nx, nz),
                   UnitLoad(s_c, tx, tz, h2)]      # tangential motion of the lower surface
    tip_load = UnitLoad(lower_length, -fx, -fz, dx * -fz - dz * -fx)
    tip_probes = [UnitLoad(lower_length, -nx, -nz, dx * -nz - dz * -nx),   # normal (down)
                  UnitLoad(lower_length, tx, tz, dx * tz - dz * tx)]       # tangential
    kw = dict(axial_stiffness=axial_stiffness, shear_stiffness=shear_stiffness)
    f_main = cantilever_flexibility(main_radius, bending_stiffness, main_loads,
                                    probes=main_probes, **kw)
    f_low = cantilever_flexibility(lower_radius, bending_stiffness, [tip_load],
                                   probes=tip_probes, **kw)[:, 0]
    w_main = cantilever_displacements(main_radius, bending_stiffness, main_probes,
                                      line_load=(0.0, -line_weight),
                                      line_load_length=main_length, **kw)
    kappa0 = 0.0
    if lower_free_radius is not None:
        kappa0 = 1.0 / lower_free_radius - (0.0 if not math.isfinite(lower_radius)
                                            else 1.0 / lower_radius)
    w_low = cantilever_displacements(lower_radius, bending_stiffness, tip_probes,
                                     line_load=(0.0, -line_weight),
                                     line_load_length=lower_length, **kw)
    e_low = cantilever_displacements(lower_radius, bending_stiffness, tip_probes,
                                     eigen_curvature=kappa0,
                                     eigen_curvature_length=lower_length, **kw)
    return geo, s_c, angle, f_main, f_low, w_main, w_low, e_low, kappa0


def two_leaf_half(eye_load: float, bending_stiffness: float, *,
                  main_length: float = SPEC.main_length,
                  lower_length: float = SPEC.lower_length,
                  main_radius: float = SPEC.main_radius,
                  lower_radius: float = SPEC.lower_radius,
                  lower_offset: float = SPEC.lower_offset,
                  thickness: float = SPEC.thickness,
                  lower_free_radius: float | None = None,
                  line_weight: float = 0.0,
                  contact_stiffness: float = INF,
                  initial_gap: float | None = None,
                  contact_angle: float | None = None,
                  eye_horizontal_stiffness: float = 0.0,
                  eye_horizontal_force: float = 0.0,
                  axial_stiffness: float = INF,
                  shear_stiffness: float = INF,
                  friction: float = 0.0) -> dict[str, float]:
    """Linear static state of one half spring (axle clamp to eye) of the two-leaf spring.

    Loads: a downward force ``eye_load`` P at the main leaf's eye; the leaves' own
    weight ``line_weight`` q (N per m of arc, 0 = off) on both leaves; a stress-free
    lower leaf of radius ``lower_free_radius`` (None: stress-free as assembled); an
    outward horizontal eye force ``eye_horizontal_force`` plus a horizontal eye spring
    ``eye_horizontal_stiffness`` (0: free eye, inf: eye held horizontally, negative: a
    compressed shackle's destabilizing stiffness).

    The contact force R (>= 0) acts along the main leaf's normal at the point where the
    lower tip touches it (``contact_geometry``; ``contact_angle`` = 0 forces a vertical
    force), through a spring of total stiffness ``contact_stiffness`` k_c per tip (inf:
    rigid). The assembled normal gap is ``initial_gap`` if given, else the geometric gap
    of :func:`contact_geometry` (0 for the default concentric leaves, -0.56 mm for the
    literal SPEC radius 1.986 m).

    Compatibility (closed contact, R = -k_c g) with the gap along the contact normal

        g = g0 + f_HC H - f_EC P + (f_CC + f_TT) R - w_C + w_T - e_T

    (f: flexibilities, see the return values; w_C, w_T: the drops along -n_c of the
    main leaf's contact point and the lower tip under the leaves' weight; e_T: the lift
    of the free lower tip from its eigen-curvature; docs/leaf_spring.md section 4). If
    it gives R < 0 the contact is open and R = 0. The eye drop is
    delta = f_EE P + w_E - f_EC R + f_HE H.

    Returns a dict: 'deflection' (downward eye displacement delta), 'reaction' R,
    'eye_horizontal_force' H (outward), 'eye_outward' (outward eye displacement u),
    'contact_open' (1.0 or 0.0), 'gap' (final normal gap, <= 0 when closed), 'slip'
    (tangential displacement of the main leaf's lower surface relative to the lower
    tip's corner along t_c, from the assembled state), the
    misfit terms 'initial_gap' g0, 'free_tip_lift' e_T, 'eigen_curvature', and the
    flexibilities 'f_EE', 'f_EC', 'f_CC', 'f_TT', 'f_HH', 'f_HE', 'f_HC' and the
    contact location 'contact_arc_length', 'contact_normal_angle'.
    """
    geo, s_c, angle, fm, f_tt, w_main, w_low, e_low, kappa0 = _half_setup(
        main_length, lower_length, main_radius, lower_radius, lower_offset, thickness,
        contact_angle, bending_stiffness, axial_stiffness, shear_stiffness, line_weight,
        lower_free_radius, friction)
    g0 = geo["gap"] if initial_gap is None else initial_gap
    P, H_app, k_h = eye_load, eye_horizontal_force, eye_horizontal_stiffness
    inv_kc = 0.0 if math.isinf(contact_stiffness) else 1.0 / contact_stiffness

    def eye_row() -> tuple[list[float], float]:
        # unknowns (H, R)
        if k_h == 0.0:
            return [1.0, 0.0], H_app
        inv_kh = 0.0 if math.isinf(k_h) else 1.0 / k_h
        return [inv_kh + fm[0, 0], fm[0, 2]], H_app * inv_kh - fm[0, 1] * P - w_main[0]

    a_eye, b_eye = eye_row()
    a_con = [fm[2, 0], fm[2, 2] + f_tt[0] + inv_kc]
    b_con = -g0 - fm[2, 1] * P - w_main[2] - w_low[0] - e_low[0]
    # least squares: a held eye of a straight, axially rigid leaf leaves H undetermined
    # (a zero row); the minimum-norm solution takes H = 0 there
    (H, R), *_ = np.linalg.lstsq(np.array([a_eye, a_con]), np.array([b_eye, b_con]),
                                 rcond=None)
    is_open = R < 0.0
    if is_open:
        R = 0.0
        H = b_eye / a_eye[0] if a_eye[0] != 0.0 else 0.0
    disp = fm @ np.array([H, P, R]) + w_main
    low = f_tt * R + w_low + e_low
    gap = g0 + disp[2] + low[0]
    return {
        "deflection": float(disp[1]),
        "reaction": float(R),
        "eye_horizontal_force": float(H),
        "eye_outward": float(disp[0]),
        "contact_open": float(is_open),
        "gap": float(gap),
        "slip": float(disp[3] - low[1]),
        "initial_gap": float(g0),
        "free_tip_lift": float(-e_low[0]),
        "eigen_curvature": float(kappa0),
        "f_EE": float(fm[1, 1]), "f_EC": float(-fm[1, 2]), "f_CC": float(fm[2, 2]),
        "f_TT": float(f_tt[0]), "f_HH": float(fm[0, 0]), "f_HE": float(fm[0, 1]),
        "f_HC": float(fm[0, 2]),
        "contact_arc_length": float(s_c), "contact_normal_angle": float(angle),
    }


def interleaf_gap_change(eye_load: float, bending_stiffness: float,
                         lower_arc_lengths: Sequence[float] | FloatArray,
                         **kwargs) -> FloatArray:
    """Change of the normal gap between the leaves (main leaf's lower surface minus lower
    leaf's upper surface, along the main leaf's radius) at the lower leaf's arc lengths
    ``lower_arc_lengths`` (< its tip), in the state of :func:`two_leaf_half` with the
    same arguments. Positive: the leaves separate there. Points are paired along the
    main leaf's radius (exact for concentric leaves). Used to check that the leaves
    touch only at the lower tips (the only contact the reference and the simulation
    have); the assembled gap is 0 along concentric leaves."""
    kw = dict(kwargs)
    if kw.get("friction", 0.0) != 0.0:
        raise ValueError("interleaf_gap_change is frictionless")
    st = two_leaf_half(eye_load, bending_stiffness, **kw)
    main_radius = kw.get("main_radius", SPEC.main_radius)
    lower_radius = kw.get("lower_radius", SPEC.lower_radius)
    main_length = kw.get("main_length", SPEC.main_length)
    lower_length = kw.get("lower_length", SPEC.lower_length)
    q = kw.get("line_weight", 0.0)
    geo = contact_geometry(main_radius, lower_radius, lower_length,
                           kw.get("thickness", SPEC.thickness),
                           kw.get("lower_offset", SPEC.lower_offset))
    angle = st["contact_normal_angle"]
    nx, nz = -math.sin(angle), math.cos(angle)
    extra = dict(axial_stiffness=kw.get("axial_stiffness", INF),
                 shear_stiffness=kw.get("shear_stiffness", INF))
    out = []
    for s_l in np.asarray(lower_arc_lengths, dtype=float):
        phi = 0.0 if not math.isfinite(lower_radius) else s_l / lower_radius
        s_m = s_l if not math.isfinite(main_radius) else main_radius * phi
        px, pz = -math.sin(phi), math.cos(phi)
        main_loads = [UnitLoad(s_m, px, pz), UnitLoad(main_length, 1.0, 0.0),
                      UnitLoad(main_length, 0.0, -1.0), UnitLoad(st["contact_arc_length"],
                                                                 nx, nz)]
        fm = cantilever_flexibility(main_radius, bending_stiffness, main_loads, **extra)
        u_main = (fm[0, 1:] @ [st["eye_horizontal_force"], eye_load, st["reaction"]]
                  + cantilever_displacements(main_radius, bending_stiffness, main_loads[:1],
                                             line_load=(0.0, -q),
                                             line_load_length=main_length, **extra)[0])
        low_loads = [UnitLoad(s_l, px, pz), UnitLoad(lower_length, -nx, -nz, geo["arm"])]
        fl = cantilever_flexibility(lower_radius, bending_stiffness, low_loads, **extra)
        u_low = (fl[0, 1] * st["reaction"]
                 + cantilever_displacements(lower_radius, bending_stiffness, low_loads[:1],
                                            line_load=(0.0, -q),
                                            line_load_length=lower_length,
                                            eigen_curvature=st["eigen_curvature"],
                                            eigen_curvature_length=lower_length,
                                            **extra)[0])
        out.append(u_main - u_low)
    return np.array(out)


def two_leaf_half_stiffness(bending_stiffness: float, *,
                            main_length: float = SPEC.main_length,
                            lower_length: float = SPEC.lower_length,
                            main_radius: float = SPEC.main_radius,
                            lower_radius: float = SPEC.lower_radius,
                            lower_offset: float = SPEC.lower_offset,
                            thickness: float = SPEC.thickness,
                            contact_stiffness: float = INF,
                            contact_angle: float | None = None,
                            eye_horizontal_stiffness: float = 0.0,
                            axial_stiffness: float = INF,
                            shear_stiffness: float = INF,
                            friction: float = 0.0) -> dict[str, float]:
    """Vertical eye stiffness of one half spring with the contact closed (linear theory,
    independent of preload and weight, which only shift the state):

        R/P = f_EC / (f_CC + f_TT + 1/k_c),   delta/P = f_EE - f_EC R/P,
        k_half = P / delta = 1 / (f_EE - f_EC^2 / (f_CC + f_TT + 1/k_c))

    (free eye; with ``eye_horizontal_stiffness`` != 0 the horizontal eye force is
    eliminated too; ``friction`` as in :func:`two_leaf_half`: +mu gives the loading
    slope, -mu the unloading slope of a sliding contact). Straight-beam limit:
    R/P = (3L - a)/(4a),
    delta = P/EI (L^3/3 - (R/P) a^2 (3L - a)/6).

    Returns 'k_half', 'compliance' (1/k_half), 'reaction_ratio' R/P,
    'compliance_main_alone' (eye compliance without the lower leaf, same eye condition),
    'k_main_alone', 'outward_ratio' (outward eye displacement per unit deflection) and
    the flexibilities of :func:`two_leaf_half`."""
    kw = dict(main_length=main_length, lower_length=lower_length, main_radius=main_radius,
              lower_radius=lower_radius, lower_offset=lower_offset, thickness=thickness,
              contact_stiffness=contact_stiffness, contact_angle=contact_angle,
              eye_horizontal_stiffness=eye_horizontal_stiffness,
              axial_stiffness=axial_stiffness, shear_stiffness=shear_stiffness,
              friction=friction)
    # unit eye load, no misfit (the gap only shifts the state): the closed-contact slope
    st = two_leaf_half(1.0, bending_stiffness, initial_gap=0.0, **kw)
    if st["contact_open"]:  # pragma: no cover - cannot happen for a downward load
        raise RuntimeError("contact opened under a unit downward eye load")
    # main leaf alone, same eye condition
    f_ee, f_he, f_hh = st["f_EE"], st["f_HE"], st["f_HH"]
    k_h = eye_horizontal_stiffness
    if k_h == 0.0:
        main_alone = f_ee
    else:
        inv_kh = 0.0 if math.isinf(k_h) else 1.0 / k_h
        main_alone = f_ee - (f_he**2 / (f_hh + inv_kh) if f_hh + inv_kh != 0.0 else 0.0)
    out = dict(st)
    out.update({
        "k_half": 1.0 / st["deflection"],
        "compliance": st["deflection"],
        "reaction_ratio": st["reaction"],
        "compliance_main_alone": main_alone,
        "k_main_alone": 1.0 / main_alone,
        "outward_ratio": st["eye_outward"] / st["deflection"],
        "slip_ratio": st["slip"] / st["deflection"],
    })
    for key in ("deflection", "reaction", "eye_horizontal_force", "eye_outward",
                "contact_open", "gap", "slip", "initial_gap", "free_tip_lift",
                "eigen_curvature"):
        out.pop(key)
    return out


# ---------------------------------------------------------------------------
# 4. Prestress
# ---------------------------------------------------------------------------

def prestress_preload(bending_stiffness: float, *,
                      lower_free_radius: float = SPEC.prestress_free_radius,
                      main_length: float = SPEC.main_length,
                      lower_length: float = SPEC.lower_length,
                      main_radius: float = SPEC.main_radius,
                      lower_radius: float = SPEC.lower_radius,
                      lower_offset: float = SPEC.lower_offset,
                      thickness: float = SPEC.thickness,
                      contact_stiffness: float = INF,
                      initial_gap: float | None = None,
                      contact_angle: float | None = None) -> dict[str, float]:
    """Preload of the assembled spring with no eye load and no weight.

    The lower leaf is stress-free at ``lower_free_radius`` (same middle line), i.e. it
    carries the eigen-curvature kappa0 = 1/R_f - 1/R_l in the assembled shape; released,
    its tip would rise by e_T = kappa0 int_0^a m_T ds (straight: kappa0 a^2 / 2) along the
    contact normal. With the geometric gap g0 the misfit is e0 = e_T - g0 and

        R0 = e0 / (f_CC + f_TT + 1/k_c),   eye lift = f_EC R0,

    and ``R0_rigid_main`` = e0 / f_TT is the force that would hold the lower tip at its
    assembled place against a rigid main leaf. ``None`` for the free radius gives the
    preload of the geometric overlap alone. Also returns 'free_tip_lift_exact', the
    normal lift of the tip from the exact arc geometry (a measure of the linearization
    error), and 'moment_at_axle' of the lower leaf when held exactly at R_l
    (EI kappa0; the curvature moment, for orientation)."""
    st = two_leaf_half(0.0, bending_stiffness, main_length=main_length,
                       lower_length=lower_length, main_radius=main_radius,
                       lower_radius=lower_radius, lower_offset=lower_offset,
                       thickness=thickness, lower_free_radius=lower_free_radius,
                       contact_stiffness=contact_stiffness, initial_gap=initial_gap,
                       contact_angle=contact_angle)
    misfit = st["free_tip_lift"] - st["initial_gap"]
    exact = 0.0
    if lower_free_radius is not None and math.isfinite(lower_radius):
        ang = st["contact_normal_angle"]
        n_c = np.array([-math.sin(ang), math.cos(ang)])
        a = lower_length
        p_free = np.array(arc_point(a, lower_free_radius), dtype=float)
        p_asm = np.array(arc_point(a, lower_radius), dtype=float)
        exact = float(np.dot(p_free - p_asm, n_c))
    return {
        "R0": st["reaction"],
        "eye_lift": -st["deflection"],
        "misfit": misfit,
        "free_tip_lift": st["free_tip_lift"],
        "free_tip_lift_exact": exact,
        "initial_gap": st["initial_gap"],
        "R0_rigid_main": max(misfit, 0.0) / st["f_TT"],
        "eigen_curvature": st["eigen_curvature"],
        "moment_at_axle": bending_stiffness * st["eigen_curvature"],
        "eye_outward": st["eye_outward"],
        "contact_open": st["contact_open"],
    }


# ---------------------------------------------------------------------------
# 3. Chassis on the spring; load cycle; frequency
# ---------------------------------------------------------------------------

def _geometry_kwargs(spec: LeafSpringSpec, lower_radius: float | None,
                     lower_offset: float | None) -> dict[str, float]:
    return dict(main_length=spec.main_length, lower_length=spec.lower_length,
                main_radius=spec.main_radius,
                lower_radius=spec.lower_radius if lower_radius is None else lower_radius,
                lower_offset=spec.lower_offset if lower_offset is None else lower_offset,
                thickness=spec.thickness)


def chassis_static_drop(bending_stiffness: float, *, prestress: bool,
                        contact_stiffness: float = INF,
                        self_weight: bool = True,
                        shackle_mass: float | None = None,
                        shackle_tilt: bool = False,
                        lower_radius: float | None = None,
                        lower_offset: float | None = None,
                        initial_gap: float | None = None,
                        spec: LeafSpringSpec = SPEC) -> dict[str, float]:
    """Static equilibrium of the chassis on the spring under gravity, relative to the
    assembled state (the positive 'drop' is downward).

    The chassis (mass m, centre of mass at r1 = 0 midway between the eyes) loads the
    front eye with W/2 and the shackle top with W/2; the shackle (``shackle_mass``,
    default spec's 2 kg; 0 to leave it out) adds its weight to the rear eye: P_front =
    W/2, P_rear = W/2 + m_s g. Each half carries its eye load, the leaves' weight (if
    ``self_weight``) and, with ``prestress``, the preload of the lower leaf (free radius
    spec.prestress_free_radius). 'drop' is the mean of the two eye drops (the chassis
    point at r1 = 0; the chassis pitches by 'pitch' = (drop_rear - drop_front)/span,
    rear down positive).

    ``shackle_tilt`` adds the second-order horizontal force of the tilted shackle (the
    chassis follows the front eye horizontally, the rear eye moves the other way):
    H = S (u_front + u_rear) / l_shackle outward on both eyes, S the shackle force; it
    softens the spring by a few percent and is not part of the linear theory.

    Also returns the eye drops, contact reactions, the parts of the drop ('from_chassis',
    'from_shackle', 'from_leaf_weight', 'from_overlap' (the geometric overlap's lift,
    < 0), 'from_preload' (< 0); they sum to 'drop' without tilt while the contact stays
    closed) and 'k_half'."""
    g = spec.gravity
    m_s = spec.shackle_mass if shackle_mass is None else shackle_mass
    W = spec.chassis_weight
    geo = _geometry_kwargs(spec, lower_radius, lower_offset)
    q = spec.line_weight if self_weight else 0.0
    free_r = spec.prestress_free_radius if prestress else None
    base = dict(geo, contact_stiffness=contact_stiffness, initial_gap=initial_gap)

    def half(P: float, H: float = 0.0, **over) -> dict[str, float]:
        kw = dict(base, line_weight=q, lower_free_radius=free_r)
        kw.update(over)
        return two_leaf_half(P, bending_stiffness, eye_horizontal_force=H, **kw)

    P_f, P_r = W / 2.0, W / 2.0 + m_s * g
    front, rear = half(P_f), half(P_r)
    H = 0.0
    if shackle_tilt:
        S = W / 2.0 + m_s * g / 2.0  # mean compression of the shackle
        l_s = spec.shackle_length
        c_f = half(P_f, 1.0)["eye_outward"] - front["eye_outward"]
        c_r = half(P_r, 1.0)["eye_outward"] - rear["eye_outward"]
        H = S * (front["eye_outward"] + rear["eye_outward"]) / (l_s - S * (c_f + c_r))
        front, rear = half(P_f, H), half(P_r, H)
    # parts of the drop (linear superposition, valid while the contact stays closed)
    k = two_leaf_half_stiffness(bending_stiffness, contact_stiffness=contact_stiffness,
                                **geo)["k_half"]
    overlap_part = half(0.0, line_weight=0.0, lower_free_radius=None)["deflection"]
    weight_part = half(0.0, lower_free_radius=None)["deflection"] - overlap_part
    preload_part = (half(0.0, line_weight=0.0)["deflection"] - overlap_part
                    if prestress else 0.0)
    x_eye = float(arc_point(spec.main_length, spec.main_radius)[0])
    return {
        "drop": 0.5 * (front["deflection"] + rear["deflection"]),
        "drop_front": front["deflection"],
        "drop_rear": rear["deflection"],
        "pitch": (rear["deflection"] - front["deflection"]) / (2.0 * x_eye),
        "reaction_front": front["reaction"],
        "reaction_rear": rear["reaction"],
        "contact_open": max(front["contact_open"], rear["contact_open"]),
        "eye_load_front": P_f,
        "eye_load_rear": P_r,
        "eye_horizontal_force": H,
        "eye_outward_front": front["eye_outward"],
        "eye_outward_rear": rear["eye_outward"],
        "k_half": k,
        "from_chassis": (W / 2.0) / k,
        "from_shackle": 0.5 * m_s * g / k,
        "from_leaf_weight": weight_part,
        "from_overlap": overlap_part,
        "from_preload": preload_part,
    }


def load_cycle(bending_stiffness: float, *, prestress: bool,
               guidance: str = "free",
               max_force: float | None = None,
               contact_stiffness: float = INF,
               friction: float = 0.0,
               lower_radius: float | None = None,
               lower_offset: float | None = None,
               initial_gap: float | None = None,
               axial_stiffness: float | None = None,
               spec: LeafSpringSpec = SPEC) -> dict[str, float]:
    """The quasi-static load cycle 0 -> F_max -> 0 (default F_max = 2 W) of a vertical
    force F on the chassis, gravity off, linear theory. Without friction the force-drop
    curve is one straight line, offset by the preload.

    ``guidance``:
      * 'free': the chassis is free horizontally and in pitch (as in the dynamic run);
        each eye carries F/2 and is horizontally free; stiffness 2 k_half.
      * 'prismatic': the chassis only translates vertically (r1 and pitch held). The
        front eye, hinged to the chassis, is then held horizontally (a much stiffer,
        arch-like half); the rear eye stays free on its shackle (first order). Both eyes
        drop by the same delta: F = k_front (delta - d0_front) + k_rear (delta - d0_rear),
        d0 the unloaded (preloaded) eye positions. The held eye carries a large
        compression (tens of kN at 2 W), so these numbers are linear estimates only.

    ``friction`` mu > 0 adds sliding (Coulomb) friction at the lower tips: the loading
    branch uses +mu, the unloading branch -mu (:func:`two_leaf_half`); both are straight
    lines in the linear theory (a short stick phase at each reversal joins them).

    Drops are downward, relative to the assembled state. Returns 'stiffness' (dF per
    chassis drop, frictionless), 'drop_at_zero' (the preloaded unloaded state: minus
    the eye lift), 'drop_at_max', the smallest contact reaction of the two halves at
    F = 0 and at F_max, 'contact_opens' (1.0 if the smallest reaction is 0 at F = 0 - R
    is affine in F, so that is its minimum; with zero misfit the leaves then touch
    without force and any upward force opens them), 'opening_force' (the chassis force
    below which a contact opens; negative: an upward pull is needed), 'k_front',
    'k_rear', the front eye's horizontal force at F_max (nonzero only for 'prismatic')
    and, with friction, 'stiffness_loading', 'stiffness_unloading' and
    'hysteresis_at_half' (unloading minus loading drop at F_max/2).

    ``axial_stiffness`` None: the leaf's EA for 'prismatic' (the held eye makes the
    leaf an arch whose stiffness depends on EA), bending only (inf) for 'free'."""
    F_max = 2.0 * spec.chassis_weight if max_force is None else max_force
    geo = _geometry_kwargs(spec, lower_radius, lower_offset)
    free_r = spec.prestress_free_radius if prestress else None
    if guidance == "free":
        conds = {"front": 0.0, "rear": 0.0}
    elif guidance == "prismatic":
        conds = {"front": INF, "rear": 0.0}
    else:
        raise ValueError(f"guidance must be 'free' or 'prismatic', not {guidance!r}")
    if axial_stiffness is None:
        axial_stiffness = spec.axial_stiffness if guidance == "prismatic" else INF
    common = dict(contact_stiffness=contact_stiffness, axial_stiffness=axial_stiffness,
                  **geo)

    def branch(mu: float):
        """Drop(F), eye loads and half states along the branch with friction mu."""
        k = {side: two_leaf_half_stiffness(bending_stiffness, eye_horizontal_stiffness=kh,
                                           friction=mu, **common)
             for side, kh in conds.items()}

        def state(side: str, eye_load: float) -> dict[str, float]:
            return two_leaf_half(eye_load, bending_stiffness, initial_gap=initial_gap,
                                 lower_free_radius=free_r, friction=mu,
                                 eye_horizontal_stiffness=conds[side], **common)

        d0 = {side: state(side, 0.0)["deflection"] for side in conds}
        kk = {side: k[side]["k_half"] for side in conds}

        def at(F: float) -> tuple[float, dict[str, float], dict[str, dict[str, float]]]:
            if guidance == "free":
                loads = {side: F / 2.0 for side in conds}
                drop = float(np.mean([d0[side] + loads[side] / kk[side] for side in conds]))
            else:
                drop = (F + sum(kk[s] * d0[s] for s in conds)) / sum(kk.values())
                loads = {side: kk[side] * (drop - d0[side]) for side in conds}
            return drop, loads, {side: state(side, loads[side]) for side in conds}
        return k, at

    k, at = branch(0.0)
    out: dict[str, float] = {"k_front": k["front"]["k_half"], "k_rear": k["rear"]["k_half"]}
    for tag, F in (("zero", 0.0), ("max", F_max)):
        drop, loads, states = at(F)
        out[f"drop_at_{tag}"] = drop
        out[f"reaction_at_{tag}"] = min(st["reaction"] for st in states.values())
        if tag == "max":
            out["front_eye_horizontal_force_at_max"] = states["front"]["eye_horizontal_force"]
    out["stiffness"] = F_max / (out["drop_at_max"] - out["drop_at_zero"])
    # R_side(F) is affine in F while closed: R = R(0) + F dR/dF
    opening = []
    _, loads0, states0 = at(0.0)
    _, loads1, _ = at(1.0)
    for side in conds:
        slope = k[side]["reaction_ratio"] * (loads1[side] - loads0[side])
        opening.append(-states0[side]["reaction"] / slope)
    out["opening_force"] = max(opening)
    out["contact_opens"] = float(out["reaction_at_zero"]
                                 <= 1e-9 * max(out["reaction_at_max"], 1.0))
    if friction:
        _, at_load = branch(+friction)
        _, at_unload = branch(-friction)
        d_l = [at_load(F)[0] for F in (0.0, 0.5 * F_max, F_max)]
        d_u = [at_unload(F)[0] for F in (0.0, 0.5 * F_max, F_max)]
        out["stiffness_loading"] = F_max / (d_l[2] - d_l[0])
        out["stiffness_unloading"] = F_max / (d_u[2] - d_u[0])
        out["hysteresis_at_half"] = d_u[1] - d_l[1]
    return out


def bounce_frequency(k_half: float, mass: float = SPEC.chassis_mass,
                     horizontal_ratio: float = 0.0) -> float:
    """First natural frequency (Hz) of the chassis bouncing on the two half springs in
    parallel: f = sqrt(2 k_half / (m (1 + c^2))) / (2 pi). ``horizontal_ratio`` c is the
    chassis's horizontal displacement per unit drop (it follows the front eye, which
    moves outward by c delta: the 'outward_ratio' of :func:`two_leaf_half_stiffness`);
    0 gives the plain vertical estimate."""
    return math.sqrt(2.0 * k_half / (mass * (1.0 + horizontal_ratio**2))) / (2.0 * math.pi)


# ---------------------------------------------------------------------------
# Table of the SPEC numbers
# ---------------------------------------------------------------------------

def reference_table(spec: LeafSpringSpec = SPEC, lower_radius: float | None = None,
                    lower_offset: float | None = None) -> list[dict[str, float | str]]:
    """One row per (bending-stiffness bound, contact model) with the SPEC numbers:
    k_half, R/P, eye compliance of the main leaf alone, static chassis drop with and
    without prestress (leaf weight and shackle included), preload R0 and eye lift, and
    the bounce frequency. Contact: rigid and spec's K x points per edge."""
    rows: list[dict[str, float | str]] = []
    geo = _geometry_kwargs(spec, lower_radius, lower_offset)
    for name, ei in bending_stiffness_bounds(spec).items():
        for cname, kc in (("rigid", INF), ("penalty", spec.contact_stiffness)):
            st = two_leaf_half_stiffness(ei, contact_stiffness=kc, **geo)
            pre = prestress_preload(ei, contact_stiffness=kc, **geo)
            drops = {p: chassis_static_drop(ei, prestress=p, contact_stiffness=kc,
                                            lower_radius=geo["lower_radius"],
                                            lower_offset=geo["lower_offset"], spec=spec)
                     for p in (False, True)}
            rows.append({
                "bending": name, "bending_stiffness": ei, "contact": cname,
                "contact_stiffness": kc,
                "k_main_alone": st["k_main_alone"],
                "k_half": st["k_half"], "reaction_ratio": st["reaction_ratio"],
                "delta_W2": spec.chassis_weight / 2.0 / st["k_half"],
                "drop_plain": drops[False]["drop"],
                "drop_prestress": drops[True]["drop"],
                "R0": pre["R0"], "eye_lift": pre["eye_lift"],
                "frequency": bounce_frequency(st["k_half"], spec.chassis_mass),
                "frequency_horizontal": bounce_frequency(st["k_half"], spec.chassis_mass,
                                                         st["outward_ratio"]),
            })
    return rows
