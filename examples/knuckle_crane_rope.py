"""Knuckle crane with a hoist rope: a main boom held by its cylinder, a jib lifted by a
hydraulic cylinder, and a payload hanging on a wire rope from the jib tip; the scene
``inputs/knuckle_crane_rope.nml`` built with the Python API.

The model (planar layout in the x-y plane, gravity along -y; steel box girders):

* the boom (4 m at 40 deg, box 250 x 350 x 10 mm) is hinged to a column at O = (0, 2, 0)
  and held by the main cylinder, a 'distance' joint of constant length between a ground
  lug and the boom (s = 1.5 m);
* the jib (3 m at -10 deg, box 200 x 250 x 8 mm) is hinged to the boom tip (the knuckle)
  and lifted by the jib cylinder (boom s = 2.5 m to jib s = 0.75 m), a compliant 'cylinder'
  force element: a rigid actuator whose length l(t) follows a 'luffing' drive, in series
  with its oil column, f = k (L - l) + c (L' - l'). The column's stiffness is
  k = A^2 K / V = A K / l_oil for the bore's area A (80 mm: A = 5.03e-3 m^2), the oil's
  bulk modulus K = 1.5e9 Pa (mineral oil without air; hoses and entrained air make a real
  column softer) and an oil column of l_oil = 0.8 m (the piston side at this extension plus
  the dead volume up to the holding valve): k = 9.42e6 N/m. Its damping c = 8e4 N s/m is a
  viscous stand-in for the valve and seal losses, sized for about 5 % of critical for the
  payload's bounce on the column (2.4 Hz: the payload and jib turning about the knuckle on
  k a^2, a = 0.42 m the cylinder's lever arm; the measured decay of the cylinder's force
  gives the ratio, see the table);
* the rope: an ANCF cable with ``tension_only=True`` (a rope: it goes slack instead of
  carrying compression), 2.5 m of 16 mm wire rope (E = 100 GPa and 5000 kg/m^3 on the
  circle's area, bending stiffness 5 N m^2), 5 elements, hung from the jib tip by a
  'spherical' joint;
* the payload: a 500 kg point mass at the rope's lower end (the hook).

What it computes and prints:

1. statics: the rope's tension at the top (the 'rope top' joint's reaction) against the
   weight it carries, m g + rho A g L, and the hook's depth below the jib tip against the
   rope's length stretched by that load; the jib cylinder's force (its ``axial``, negative:
   it pushes) against the moment balance of the jib about the knuckle (its weight and the
   rope's pull against the cylinder, a rigid jib turned to the static state's chord), and
   the oil column's compression l - L against |f| / k;
2. the lift: from the static equilibrium the jib cylinder extends by 0.05 m (a cosine start
   and stop of 0.3 s each, 0.1 m/s between) and holds; the payload swings. It tabulates
   the swing amplitude and period (a least-squares sinusoid, against the pendulum
   2 pi sqrt(L / g) corrected for the rope's mass), the jib cylinder's force range, the
   rope's tension range over all its Gauss points and steps, whether it went slack, and the
   step counts; it plots the swing, the tension and the paths
   (``knuckle_crane_rope.png``).

Files in results/examples/: knuckle_crane_rope.{md,csv,png,h5}.

    python examples/knuckle_crane_rope.py [--quick] [--out DIR]
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from example_utils import arguments, write_table

from ancfdrv import Box, Circle, System

GRAVITY = 9.81


def _unit(angle_deg: float) -> np.ndarray:
    a = np.radians(angle_deg)
    return np.array([np.cos(a), np.sin(a), 0.0])


@dataclass(frozen=True)
class KnuckleCrane:
    """Dimensions [m], masses [kg] and materials of the crane, its rope and payload."""

    pivot: tuple = (0.0, 2.0, 0.0)
    boom_length: float = 4.0
    boom_angle: float = 40.0          # deg
    boom_section: Box = Box(width=0.25, height=0.35, wall=0.010)
    jib_length: float = 3.0
    jib_angle: float = -10.0          # deg, at t = 0
    jib_section: Box = Box(width=0.20, height=0.25, wall=0.008)
    ground_lug: tuple = (1.2, 1.7, 0.0)
    main_lug: float = 1.5             # boom arc length of the main cylinder's lug
    boom_lug: float = 2.5             # boom arc length of the jib cylinder's lug
    jib_lug: float = 0.75             # jib arc length of the jib cylinder's lug
    rope_length: float = 2.5
    rope_diameter: float = 0.016
    rope_modulus: float = 1.0e11      # a wire rope's effective E on the circle's area
    rope_density: float = 5000.0      # steel times a fill factor of about 0.64
    rope_bending: float = 5.0         # N m^2
    payload: float = 500.0
    stroke: float = 0.05              # the jib cylinder's extension [m]
    stroke_rate: float = 0.1          # m/s
    stroke_ramp: float = 0.3          # s, the cosine start and stop each
    bore: float = 0.080               # the jib cylinder's bore [m]
    oil_bulk_modulus: float = 1.5e9   # Pa, mineral oil
    oil_column: float = 0.8           # m, the oil column's length (piston side + dead volume)
    oil_damping: float = 8e4          # N s/m: ~5 % of critical for the payload's bounce

    @property
    def oil_stiffness(self) -> float:
        """k = A^2 K / V with V = A l_oil: the oil column's axial stiffness, N/m."""
        area = np.pi * self.bore**2 / 4.0
        return area * self.oil_bulk_modulus / self.oil_column

    def points(self) -> dict[str, np.ndarray]:
        """Pivot O, knuckle B, the lugs, the jib tip T and the hook H at t = 0."""
        o = np.array(self.pivot)
        e1, e2 = _unit(self.boom_angle), _unit(self.jib_angle)
        b = o + self.boom_length * e1
        t = b + self.jib_length * e2
        return {"O": o, "B": b, "G": np.array(self.ground_lug), "P1": o + self.main_lug * e1,
                "P": o + self.boom_lug * e1, "Q": b + self.jib_lug * e2, "T": t,
                "H": t - np.array([0.0, self.rope_length, 0.0])}

    @property
    def rope_area(self) -> float:
        return np.pi * self.rope_diameter**2 / 4.0

    @property
    def rope_mass(self) -> float:
        return self.rope_density * self.rope_area * self.rope_length


def build(p: KnuckleCrane, rope_nodes: int = 6) -> System:
    """The crane at its t = 0 configuration, the jib cylinder on its drive."""
    pts = p.points()
    s = System("Knuckle crane with a hoist rope")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0, poisson_ratio=0.3)
    wire = s.material("wire rope", youngs_modulus=p.rope_modulus, density=p.rope_density)
    stroke0 = float(np.linalg.norm(pts["Q"] - pts["P"]))
    s.drive("jib stroke", "luffing", omega=p.stroke_rate, t_start=p.stroke_ramp,
            t_brake=p.stroke_ramp, start=stroke0, sweep=p.stroke)
    s.beam("boom", material=steel, start=pts["O"], end=pts["B"], nodes=9,
           section=p.boom_section, height_axis=_unit(p.boom_angle + 90.0), bending="cubic",
           formulation="nonlinear")
    s.beam("jib", material=steel, start=pts["B"], end=pts["T"], nodes=13,
           section=p.jib_section, height_axis=_unit(p.jib_angle + 90.0), bending="cubic",
           formulation="nonlinear")
    # the rope: tension only, with a wire rope's small bending stiffness
    s.cable("rope", material=wire, start=pts["T"], end=pts["H"], nodes=rope_nodes,
            section=Circle(p.rope_diameter), tension_only=True,
            bending_stiffness=p.rope_bending)
    s.joint("column pin", "revolute", "ground", "boom", point=pts["O"], axis=(0, 0, 1))
    s.joint("main cylinder", "distance", "ground", "boom", point1=pts["G"], point2=pts["P1"])
    s.joint("knuckle", "revolute", "boom", "jib", point=pts["B"], axis=(0, 0, 1))
    # the jib cylinder: its drive's length in series with the compliant oil column
    s.force_element("jib cylinder", "cylinder", "boom", "jib", point1=pts["P"],
                    point2=pts["Q"], drive="jib stroke", stiffness=p.oil_stiffness,
                    damping=p.oil_damping)
    s.joint("rope top", "spherical", "jib", "rope", point=pts["T"])
    s.load("g", "gravity", vector=(0.0, -GRAVITY, 0.0))
    s.load("payload", "point_mass", body="rope", point=pts["H"], mass=p.payload)
    s.probe("jib tip", "jib", pts["T"])
    s.probe("hook", "rope", pts["H"])
    s.probe("knuckle", "jib", pts["B"])
    s.probe("jib lug", "jib", pts["Q"])
    s.probe("boom lug", "boom", pts["P"])
    return s


@dataclass
class Run:
    """What :func:`run` computed (the tests check these numbers)."""

    top_tension_static: float      # the rope top's reaction, N
    weight: float                  # m g + rho A g L, N
    depth_static: float            # hook below the jib tip, m
    depth_expected: float          # L (1 + (m g + rho A g L / 2) / EA), m
    cylinder_static: float         # the jib cylinder's axial force (tension +), N
    cylinder_balance: float        # the same from the jib's moment balance about the knuckle
    compression_static: float      # the oil column's l - L, m
    compression_expected: float    # |f| / k, m
    cylinder_range: tuple          # least and largest axial force in the run, N
    time: np.ndarray
    swing: np.ndarray              # the rope chord's angle from the vertical, rad
    tension: np.ndarray            # (nt, 2): least and largest axial force over the rope
    swing_amplitude: float         # after the stop, rad
    swing_period: float            # s
    pendulum_period: float         # s
    slack_steps: int               # steps with a slack Gauss point
    fully_slack_steps: int         # steps with the whole rope slack
    steps: int
    newton_iterations: int
    factorizations: int
    stop: float                    # the cylinder stops [s]
    files: list[Path]


def _jib_balance(p: KnuckleCrane, stat, rope_top: np.ndarray) -> float:
    """The jib cylinder's axial force (tension positive) from the jib's moment balance about
    the knuckle B in the static state, the jib taken rigid and turned from its t = 0 line to
    the chord from B to its tip: its weight at the middle, the rope's pull at the tip (minus
    what the jib exerts on the rope) and the cylinder's force along the lug line Q - P."""
    b, tip = (np.asarray(stat.probes[k]) for k in ("knuckle", "jib tip"))
    q, lug = (np.asarray(stat.probes[k]) for k in ("jib lug", "boom lug"))
    jib_mass = 7850.0 * p.jib_section.data.area * p.jib_length
    middle = b + 0.5 * (tip - b)        # the rigid jib's centre of mass
    weight = np.array([0.0, -jib_mass * GRAVITY, 0.0])
    n = (q - lug) / np.linalg.norm(q - lug)

    def moment(arm: np.ndarray, force: np.ndarray) -> float:
        return float(arm[0] * force[1] - arm[1] * force[0])
    # tension f pulls the jib lug towards the boom lug: force -f n on the jib
    return (moment(middle - b, weight) + moment(tip - b, -rope_top)) / moment(q - b, n)


def _fitted_period(t: np.ndarray, x: np.ndarray, start: float) -> float:
    """The period of the sinusoid a sin(w t) + b cos(w t) + c nearest x (least squares)."""
    from scipy.optimize import curve_fit

    def sine(tt, a, b, w, c):
        return a * np.sin(w * tt) + b * np.cos(w * tt) + c
    w0 = 2.0 * np.pi / start
    amplitude = 0.5 * float(np.ptp(x))
    fit, _ = curve_fit(sine, t, x, p0=[amplitude * np.sin(0.0), amplitude, w0, float(x.mean())])
    return float(2.0 * np.pi / abs(fit[2]))


def _crossings(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    k = np.flatnonzero(np.sign(x[1:]) != np.sign(x[:-1]))
    return t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])


def run(quick: bool, out: Path) -> Run:
    """Statics, the lift and the hold; tables and the plot."""
    out.mkdir(parents=True, exist_ok=True)
    p = KnuckleCrane()
    system = build(p, rope_nodes=4 if quick else 6)
    rope = system.bodies["rope"]
    dt, t_end = (1e-2, 4.5) if quick else (5e-3, 8.0)
    h5 = out / "knuckle_crane_rope.h5"
    res = system.simulate(t_end, dt, from_static=True, static_method="newton", tol=1e-10,
                          integrator="generalized_alpha", rho_inf=0.8, newton_tol=1e-8,
                          max_newton=25, q=True, output=h5)
    stat = res.static
    top = np.asarray(stat.reactions["rope top"]["force"])
    weight = (p.payload + p.rope_mass) * GRAVITY
    ea = p.rope_modulus * p.rope_area
    depth = float(stat.probes["jib tip"][1] - stat.probes["hook"][1])
    expected = p.rope_length * (1.0 + (p.payload + p.rope_mass / 2.0) * GRAVITY / ea)
    cylinder = float(np.asarray(stat.reactions["jib cylinder"]["axial"]))
    balance = _jib_balance(p, stat, top)
    pts = p.points()
    stroke0 = float(np.linalg.norm(pts["Q"] - pts["P"]))   # l(0): the drive's start
    length = float(np.linalg.norm(np.asarray(stat.probes["jib lug"])
                                  - np.asarray(stat.probes["boom lug"])))
    axial_t = np.asarray(res.dynamic.reactions["jib cylinder"]["axial"]).ravel()

    t = res.time
    chord = res.probes["hook"] - res.probes["jib tip"]
    swing = np.arctan2(chord[:, 0], -chord[:, 1])
    forces = rope.axial_forces(res.dynamic.q).reshape(len(t), -1)
    tension = np.stack([forces.min(axis=1), forces.max(axis=1)], axis=1)
    stop = p.stroke / p.stroke_rate + p.stroke_ramp
    after = t > stop
    # the swing about its mean after the stop; the period from a least-squares sinusoid
    # (started from the mean crossings): the payload's bounce on the oil column (2.4 Hz,
    # decaying) rides on the swing and shifts single crossings, not the fitted period
    centred = swing[after] - 0.5 * (swing[after].max() + swing[after].min())
    crossings = _crossings(t[after], centred)
    period = float(2.0 * np.mean(np.diff(crossings))) if len(crossings) > 1 else np.nan
    if np.isfinite(period):
        period = _fitted_period(t[after], swing[after], period)
    # pendulum of the stretched rope with its own mass (a straight rope: m_r L^2 / 3)
    mu = p.rope_mass / p.payload
    pendulum = 2.0 * np.pi * np.sqrt(expected / GRAVITY * (1 + mu / 3) / (1 + mu / 2))
    attrs = res.dynamic.attrs
    run_ = Run(float(top[1]), weight, depth, expected, cylinder, balance,
               stroke0 - length, abs(cylinder) / p.oil_stiffness,
               (float(axial_t.min()), float(axial_t.max())), t, swing, tension,
               float(0.5 * np.ptp(swing[after])), period, float(pendulum),
               int(np.sum(forces.min(axis=1) == 0.0)), int(np.sum(forces.max(axis=1) == 0.0)),
               int(attrs["steps"]), int(attrs["newton_iterations"]),
               int(attrs["factorizations"]), stop, [h5, out / "knuckle_crane_rope.png"])
    rows = [
        ["rope tension at the top, static [N]", run_.top_tension_static, weight],
        ["hook below the jib tip, static [m]", depth, expected],
        ["jib cylinder's force, static [N] (moment balance about the knuckle)", cylinder,
         balance],
        ["oil column's compression l - L, static [mm] (|f| / k)", 1e3 * (stroke0 - length),
         1e3 * abs(cylinder) / p.oil_stiffness],
        ["jib cylinder's force, least and largest in the run [kN]",
         f"{axial_t.min() / 1e3:.2f} / {axial_t.max() / 1e3:.2f}", ""],
        ["swing amplitude after the stop [deg]", np.degrees(run_.swing_amplitude), np.nan],
        ["swing period [s]", period, pendulum],
        ["rope tension, least over the rope and run [N]", tension[:, 0].min(), np.nan],
        ["rope tension, largest [N]", tension[:, 1].max(), np.nan],
        ["steps with a slack Gauss point", run_.slack_steps, 0],
        ["steps with the whole rope slack", run_.fully_slack_steps, 0],
        ["steps / Newton iterations / factorizations",
         f"{run_.steps} / {run_.newton_iterations} / {run_.factorizations}", ""],
    ]
    print(write_table(out / "knuckle_crane_rope", ["quantity", "model", "reference"], rows,
                      "Knuckle crane with a hoist rope",
                      "References: the weight m g + rho A g L; the rope stretched by its "
                      "mean load (linear); the cylinder's force from the jib's moment "
                      "balance about the knuckle (rigid jib on the static chord), the oil "
                      f"column's compression |f| / k (k = A K / l_oil = "
                      f"{p.oil_stiffness:.3g} N/m); the pendulum 2 pi sqrt(L / g) with the rope's "
                      "mass (a straight rope). The tension is T = EA max(eps, 0) |r'| at the "
                      "rope's Gauss points."))
    plot(p, run_, res, out / "knuckle_crane_rope.png")
    return run_


def plot(p: KnuckleCrane, r: Run, res, path: Path) -> None:
    """The swing angle, the rope's tension range and the paths of jib tip and hook."""
    import matplotlib.pyplot as plt
    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(15, 4.5))
    ax1.plot(r.time, np.degrees(r.swing), lw=1.2)
    ax1.axvline(r.stop, color="0.7", lw=0.8)
    ax1.set(xlabel="time [s]", ylabel="rope angle from the vertical [deg]",
            title="payload swing (cylinder stops at the grey line)")
    ax2.fill_between(r.time, r.tension[:, 0] / 1e3, r.tension[:, 1] / 1e3, alpha=0.4,
                     label="range over the rope's Gauss points")
    ax2.axhline(r.weight / 1e3, color="k", ls="--", lw=1, label="static weight")
    ax2.set(xlabel="time [s]", ylabel="rope tension [kN]", title="rope tension")
    ax2.legend()
    tip, hook = res.probes["jib tip"], res.probes["hook"]
    ax3.plot(tip[:, 0], tip[:, 1], label="jib tip")
    ax3.plot(hook[:, 0], hook[:, 1], label="hook")
    ax3.set(xlabel="x [m]", ylabel="y [m]", title="paths")
    ax3.set_aspect("equal", adjustable="datalim")
    ax3.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> int:
    args = arguments(__doc__, argv)
    run(args.quick, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
