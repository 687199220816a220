"""Knuckle boom: a boom held at its angle, a jib hinged to its tip and lifted by a hydraulic
cylinder whose length follows a drive.

The model (planar, in the x-y plane, gravity along -y; steel box girders):

* the boom (4 m, box 250 x 350 x 10 mm) is hinged to the ground at the pivot O and held at
  40 degrees by a 'hub' joint: a clamp that turns about z by the angle of its drive, here a
  constant (the boom's luffing drive at rest). Formulation 'ffr' (small strain in its frame,
  which stays put) with 'cubic' bending;
* the jib (3 m, box 200 x 250 x 8 mm) is joined to the boom tip B by a 'revolute' knuckle
  about z. Formulation 'nonlinear' with 'cubic' bending: it swings through large angles;
* the cylinder is a 'distance' joint between a lug P on the boom axis (2.4 m from O) and a
  lug Q on the jib axis (0.75 m from B): |PQ| equals the value of its drive (a rigid,
  massless cylinder; its Lagrange multiplier lambda gives its force, F = -2 lambda L,
  compression negative);
* a 150 kg payload hangs at the jib tip (a point mass: weight and inertia).

What it computes and prints:

1. statics at two cylinder lengths (1.8 m and 2.1 m): the jib angle against the rigid
   geometry (the triangle P-B-Q), the tip sag perpendicular to the jib and the cylinder
   force, next to the small-deflection closed form (``tests/reference/mechanisms.py``:
   cantilever boom + jib on two supports, superposed) when the script runs in a checkout;
2. a dynamic lift: the cylinder extends from 1.8 m to 2.1 m on a smooth profile (the
   'luffing' drive: a cosine start, a constant rate of 0.15 m/s, a cosine stop), then holds.
   It plots the tip path and the cylinder force against the quasi-static force of the
   rigid jib (``knuckle_boom_lift.png``) and tabulates the run.

Files in results/examples/: knuckle_boom_statics.{md,csv}, knuckle_boom_lift.{md,csv,png},
knuckle_boom_L1.8.h5 (static equilibrium + the lift), knuckle_boom_L2.1.h5 (statics).

    python examples/knuckle_boom.py [--quick] [--out DIR]
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from example_utils import arguments, reference, relative, write_table

from ancfdrv import Box, System

GRAVITY = 9.81


@dataclass(frozen=True)
class KnuckleBoom:
    """Dimensions [m], masses [kg] and the material (steel) of the knuckle boom."""

    boom_length: float = 4.0
    boom_angle: float = np.radians(40.0)
    boom_section: Box = Box(width=0.25, height=0.35, wall=0.010)
    jib_length: float = 3.0
    jib_section: Box = Box(width=0.20, height=0.25, wall=0.008)
    boom_lug: float = 2.4      # arc length of P on the boom axis from O
    jib_lug: float = 0.75      # arc length of Q on the jib axis from B (a quarter: a node)
    payload: float = 150.0
    youngs_modulus: float = 2.1e11
    density: float = 7850.0
    poisson_ratio: float = 0.3

    def jib_angle(self, stroke: float) -> float:
        """Absolute angle of the rigid jib when |PQ| = stroke: the law of cosines in the
        triangle P-B-Q (|PB| = boom_length - boom_lug, |BQ| = jib_lug), jib below the boom
        line (the knuckle opens as the cylinder extends)."""
        pb, bq = self.boom_length - self.boom_lug, self.jib_lug
        cos_bend = (stroke**2 - pb**2 - bq**2) / (2.0 * pb * bq)
        if abs(cos_bend) > 1.0:
            raise ValueError(f"stroke {stroke} m out of reach [{abs(pb - bq)}, {pb + bq}]")
        return self.boom_angle - float(np.arccos(cos_bend))

    def points(self, stroke: float) -> dict[str, np.ndarray]:
        """The rigid configuration at a stroke: pivot O, lugs P and Q, knuckle B, tip T
        (3-vectors) and the jib's direction e2 and normal n2."""
        e1, e2 = _unit(self.boom_angle), _unit(self.jib_angle(stroke))
        knuckle = self.boom_length * e1
        return {"O": np.zeros(3), "P": self.boom_lug * e1, "B": knuckle,
                "Q": knuckle + self.jib_lug * e2, "T": knuckle + self.jib_length * e2,
                "e2": e2, "n2": np.array([-e2[1], e2[0], 0.0])}

    def masses(self) -> tuple[float, float]:
        """Boom and jib masses [kg] (density x section area x length)."""
        return (self.density * self.boom_section.data.area * self.boom_length,
                self.density * self.jib_section.data.area * self.jib_length)

    def rigid_cylinder_force(self, stroke) -> np.ndarray:
        """Cylinder force of the rigid jib [N] (tension positive): the moments about the
        knuckle B of the jib's weight, the payload's weight and the cylinder's force on Q
        balance. Accepts an array of strokes."""
        strokes = np.atleast_1d(np.asarray(stroke, dtype=float))
        _, jib_mass = self.masses()
        out = np.empty_like(strokes)
        for k, s in enumerate(strokes):
            p = self.points(float(s))
            u = (p["Q"] - p["P"]) / np.linalg.norm(p["Q"] - p["P"])
            weight_moment = -GRAVITY * (jib_mass * 0.5 * self.jib_length + self.payload
                                        * self.jib_length) * p["e2"][0]
            arm = _cross(p["Q"] - p["B"], u)    # moment of a unit pull -u on Q is -arm
            out[k] = weight_moment / arm
        return out if np.ndim(stroke) else out[0]


def _unit(angle: float) -> np.ndarray:
    return np.array([np.cos(angle), np.sin(angle), 0.0])


def _cross(a: np.ndarray, b: np.ndarray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


@dataclass(frozen=True)
class Mesh:
    """Nodes of the boom (2k + 1: the lug P ends the first of two segments) and of the
    jib (4k + 1: the lug Q is the quarter node)."""

    boom_nodes: int = 9
    jib_nodes: int = 13


def build(p: KnuckleBoom, stroke: float, mesh: Mesh, lift: dict | None = None) -> System:
    """The knuckle boom built at the rigid configuration of ``stroke``. ``lift``: the
    parameters of a 'luffing' drive for the cylinder (start = stroke), else its length
    is held."""
    pts = p.points(stroke)
    jib_angle = p.jib_angle(stroke)
    s = System("Knuckle boom")
    steel = s.material("steel", youngs_modulus=p.youngs_modulus, density=p.density,
                       poisson_ratio=p.poisson_ratio)
    # the boom: FFR, its section height in the plane (bending about z)
    s.beam("boom", material=steel, start=pts["O"], end=pts["B"], nodes=mesh.boom_nodes,
           segments=(p.boom_lug, p.boom_length - p.boom_lug), section=p.boom_section,
           height_axis=_unit(p.boom_angle + np.pi / 2), formulation="ffr", bending="cubic")
    # the jib: large rotations, so the nonlinear formulation
    s.beam("jib", material=steel, start=pts["B"], end=pts["T"], nodes=mesh.jib_nodes,
           section=p.jib_section, height_axis=_unit(jib_angle + np.pi / 2),
           formulation="nonlinear", bending="cubic")
    # hinge at O held at the boom angle: a 'hub' clamp turned by a constant drive
    s.drive("boom angle", "constant", value=p.boom_angle)
    s.joint("pivot", "hub", "ground", "boom", point=pts["O"], pivot=pts["O"], axis=(0, 0, 1),
            drive="boom angle")
    s.joint("knuckle", "revolute", "boom", "jib", point=pts["B"], axis=(0, 0, 1))
    if lift is not None:
        s.drive("stroke", "luffing", start=stroke, **lift)
    s.joint("cylinder", "distance", "boom", "jib", point1=pts["P"], point2=pts["Q"],
            drive="stroke" if lift is not None else None)
    s.load("gravity", "gravity", vector=(0.0, -GRAVITY, 0.0))
    s.load("payload", "point_mass", body="jib", point=pts["T"], mass=p.payload)
    for name, body, point in (("tip", "jib", "T"), ("knuckle", "boom", "B"),
                              ("jib lug", "jib", "Q"), ("boom lug", "boom", "P")):
        s.probe(name, body, pts[point])
    return s


def cylinder_force(multiplier, length) -> np.ndarray:
    """Axial force [N] of a distance joint, tension positive, from its multiplier: the
    joint equation is |p2 - p1|^2 - L^2 = 0, so it pushes p2 with 2 lambda (p2 - p1)."""
    return -2.0 * np.asarray(multiplier) * np.asarray(length)


@dataclass
class StaticCase:
    """The static equilibrium at one cylinder length."""

    stroke: float
    rigid_angle: float           # jib angle of the rigid geometry [rad]
    chord_angle: float           # angle of the deformed jib chord B-Q [rad]
    tip_displacement: np.ndarray  # tip from its rigid position [m]
    tip_sag: float               # ... along the jib's normal n2 (negative: below) [m]
    force: float                 # cylinder force, tension positive [N]
    ndof: int


def solve_statics(p: KnuckleBoom, stroke: float, mesh: Mesh,
                  out: Path | None = None) -> StaticCase:
    """Static equilibrium at a cylinder length (optionally written to ``out``)."""
    res = build(p, stroke, mesh).static(static_method="newton", tol=1e-10, output=out)
    return _static_case(p, stroke, res)


def _static_case(p: KnuckleBoom, stroke: float, res) -> StaticCase:
    """The figures of a static result (``res.static``: probes, multipliers)."""
    pts = p.points(stroke)
    at = res.static.probes
    chord = at["jib lug"] - at["knuckle"]
    tip = at["tip"] - pts["T"]
    # the cylinder's axial force by the joint's name (SPEC section 10; the same as
    # -2 lambda L of cylinder_force, which tests/test_answers.py checks)
    force = float(np.asarray(res.static.reactions["cylinder"]["axial"]))
    return StaticCase(stroke, p.jib_angle(stroke), float(np.arctan2(chord[1], chord[0])), tip,
                      float(tip @ pts["n2"]), float(force), int(res.model.attrs["ndof"]))


@dataclass
class Lift:
    """The dynamic lift: histories and the static start."""

    time: np.ndarray
    stroke: np.ndarray
    tip: np.ndarray               # (nt, 3) [m]
    force: np.ndarray             # cylinder force, tension positive [N]
    quasi_static: np.ndarray      # rigid jib's force at the same strokes [N]
    energy_balance: np.ndarray    # [J]
    drive_work: np.ndarray        # [J]
    start: StaticCase
    ramp_end: float               # the stroke stops changing [s]


def lift(p: KnuckleBoom, strokes: tuple[float, float], mesh: Mesh, dt: float, hold: float,
         rate: float = 0.15, ramp: float = 0.5, out: Path | None = None) -> Lift:
    """From the static equilibrium at strokes[0] the cylinder extends to strokes[1] at
    ``rate`` m/s (cosine start and stop of ``ramp`` s each), then holds for ``hold`` s."""
    travel = strokes[1] - strokes[0]
    profile = dict(omega=rate, t_start=ramp, t_brake=ramp, sweep=travel)
    ramp_end = travel / rate + ramp  # start and stop each take ramp/2 longer than at rate
    system = build(p, strokes[0], mesh, lift=profile)
    res = system.simulate(ramp_end + hold, dt, from_static=True, static_method="newton",
                          tol=1e-10, integrator="generalized_alpha", rho_inf=0.8,
                          newton_tol=1e-10, max_newton=20, output=out)
    t = res.time
    stroke = system.drives["stroke"].values(t)[0]
    return Lift(t, stroke, res.probes["tip"],
                cylinder_force(res.multiplier("cylinder: length"), stroke),
                p.rigid_cylinder_force(stroke), res.energy["balance"],
                res.energy["drive_work"], _static_case(p, strokes[0], res), ramp_end)


def plot(p: KnuckleBoom, run: Lift, path: Path) -> None:
    """Tip path, the tip's sag below the rigid jib's line and the cylinder force."""
    import matplotlib.pyplot as plt
    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(15, 4.5))
    rigid = [p.points(s) for s in run.stroke]
    rigid_tip = np.array([r["T"] for r in rigid])
    sag = np.einsum("ij,ij->i", run.tip - rigid_tip, np.array([r["n2"] for r in rigid]))
    ax1.plot(rigid_tip[:, 0], rigid_tip[:, 1], "k--", lw=1, label="rigid jib")
    ax1.plot(run.tip[:, 0], run.tip[:, 1], lw=1.5, label="model (flexible)")
    ax1.set(xlabel="x [m]", ylabel="y [m]", title="jib tip path during the lift")
    ax1.set_aspect("equal", adjustable="datalim")
    ax1.legend()
    ax2.plot(run.time, 1e3 * sag, lw=1.2)
    ax2.axvline(run.ramp_end, color="0.7", lw=0.8)
    ax2.set(xlabel="time [s]", ylabel="tip offset along the jib normal [mm]",
            title="tip sag below the rigid jib's line")
    ax3.plot(run.time, -run.force / 1e3, lw=1.2, label="model (multiplier of 'cylinder')")
    ax3.plot(run.time, -run.quasi_static / 1e3, "k--", lw=1, label="quasi-static, rigid jib")
    ax3.axvline(run.ramp_end, color="0.7", lw=0.8)
    ax3.set(xlabel="time [s]", ylabel="cylinder compression [kN]",
            title="cylinder force (stroke 1.8 -> 2.1 m)")
    ax3.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


@dataclass
class Report:
    """What :func:`run` computed (the tests check these numbers)."""

    statics: list[StaticCase]
    closed_form: list | None      # mechanisms.knuckle_boom_flexible_sag per stroke
    lift: Lift
    files: list[Path]


def closed_form(p: KnuckleBoom, stroke: float):
    """The small-deflection closed form (tests/reference/mechanisms.py), or None."""
    mech = reference("mechanisms")
    if mech is None:
        return None
    boom_mass, jib_mass = p.masses()
    e, g = p.youngs_modulus, p.youngs_modulus / (2.0 * (1.0 + p.poisson_ratio))
    b, j = p.boom_section.data, p.jib_section.data
    # in-plane bending is along the section height: the second moment inertia_z
    return mech.knuckle_boom_flexible_sag(
        p.boom_length, boom_mass, p.jib_length, jib_mass, p.boom_angle, p.boom_lug,
        p.jib_lug, stroke, e * b.area, e * b.inertia_z, e * j.area, e * j.inertia_z,
        g * b.area, g * j.area, gravity=(0.0, -GRAVITY), tip_load=(0.0, -GRAVITY * p.payload),
        branch=-1)


def run(quick: bool, out: Path) -> Report:
    """Both analyses, the tables and the plot."""
    out.mkdir(parents=True, exist_ok=True)
    p = KnuckleBoom()
    mesh = Mesh(5, 5) if quick else Mesh()
    strokes = (1.8, 2.1)
    files = [out / f"knuckle_boom_L{s}.h5" for s in strokes]
    moving = lift(p, strokes, mesh, dt=4e-3 if quick else 1e-3, hold=0.5 if quick else 1.5,
                  out=files[0])
    statics = [moving.start, solve_statics(p, strokes[1], mesh, files[1])]
    refs = [closed_form(p, s) for s in strokes]
    rows = []
    for case, ref in zip(statics, refs):
        rows.append([case.stroke, np.degrees(case.rigid_angle), np.degrees(case.chord_angle),
                     1e3 * (case.chord_angle - case.rigid_angle),
                     1e3 * ref.jib_chord_rotation if ref else np.nan, 1e3 * case.tip_sag,
                     1e3 * ref.tip_transverse if ref else np.nan,
                     relative(case.tip_sag, ref.tip_transverse) if ref else np.nan,
                     case.force / 1e3, p.rigid_cylinder_force(case.stroke) / 1e3])
    table = write_table(
        out / "knuckle_boom_statics",
        ["L [m]", "jib angle, rigid [deg]", "jib chord B-Q, model [deg]",
         "chord rotation, model [mrad]", "closed form [mrad]", "tip sag, model [mm]",
         "closed form [mm]", "sag rel. error", "cylinder force, model [kN]", "rigid [kN]"],
        rows, "Knuckle boom statics",
        f"Mesh: boom {mesh.boom_nodes} nodes (ffr), jib {mesh.jib_nodes} nodes (nonlinear); "
        "closed form: tests/reference/mechanisms.knuckle_boom_flexible_sag (small "
        "deflections, Timoshenko shear G A); force: tension positive.")
    print(table)
    hold = moving.time > moving.ramp_end
    steady = (moving.time > 0.5 + 0.25) & (moving.time < moving.ramp_end - 0.75)
    lift_rows = [
        ["peak compression [kN]", -moving.force.min() / 1e3, -moving.quasi_static.min() / 1e3],
        ["mean force at constant rate [kN]", moving.force[steady].mean() / 1e3,
         moving.quasi_static[steady].mean() / 1e3],
        ["mean force while holding [kN]", moving.force[hold].mean() / 1e3,
         statics[1].force / 1e3],
        ["tip at the end, x [m]", moving.tip[-1, 0], p.points(strokes[1])["T"][0]
         + statics[1].tip_displacement[0]],
        ["tip at the end, y [m]", moving.tip[-1, 1], p.points(strokes[1])["T"][1]
         + statics[1].tip_displacement[1]],
        ["max |energy balance| / max |drive work|",
         np.abs(moving.energy_balance).max() / np.abs(moving.drive_work).max(), 0.0],
    ]
    print(write_table(out / "knuckle_boom_lift", ["quantity", "dynamic lift", "comparison"],
                      lift_rows, "Knuckle boom lift",
                      "Comparison: the rigid jib's quasi-static force, or the static "
                      f"equilibrium at L = {strokes[1]} m (force, tip)."))
    plot(p, moving, out / "knuckle_boom_lift.png")
    return Report(statics, refs, moving, files + [out / "knuckle_boom_lift.png"])


def main(argv: Sequence[str] | None = None) -> int:
    args = arguments(__doc__, argv)
    run(args.quick, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
