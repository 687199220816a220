"""Luffing boom on compliant mounts: a box boom hinged on a bushing, lifted by a hydraulic
cylinder whose oil column is compliant, balanced by a preloaded gas spring, carrying a
payload at its tip (the three force elements of SPEC 8.1).

The model (gravity along -z, the boom in the x-z plane):

* the boom: a 5 m steel box girder (200 mm wide, 300 mm high, 8 mm wall) along x,
  formulation 'nonlinear' with 'cubic' bending, 9 nodes; a 300 kg payload (point mass) at
  its tip;
* the root mount: a 'bushing' between the ground and the boom at the root (0, 0, 0): 5e8 N/m
  along the three axes, 5e7 N m/rad about x and z, nothing about y (a hinge whose pin and
  bearings give);
* the luffing cylinder: a 'cylinder' from the ground point (0.8, 0, -1.2) to the boom point
  (2, 0, 0) (between nodes): its nominal length follows the drive 'lift' (held for 0.5 s,
  then extending at up to 0.08 m/s after a smooth 0.5 s start), in series with the oil
  column's 2e7 N/m and 5e4 N s/m;
* the gas spring: a 'spring_damper' from the ground point (2.5, 0, -1.5) to the boom point
  (3.5, 0, 0), free length 2.3 m, 5 kN/m, a preload of -2 kN (compression) at the free
  length, 1 kN s/m.

What it computes and prints:

1. statics at t = 0: the cylinder and gas spring forces (the elements' ``axial``: tension
   positive) and the root reaction, next to the rigid moment balance about the hinge
   (the boom's weight and the payload against the two struts at the computed boom angle);
   the run starts from this equilibrium;
2. the lift: 3 s (1.5 s with --quick); the cylinder force, the oil column's compression
   L - l and the boom angle over time (``boom_mounts_lift.png``); at the end of the
   constant-rate phase the force is compared with the rigid moment balance at the angle
   and rate reached (a quasi-static lift: the gas spring's damper resists the turn), and
   the oil column's compression L - l with the force over its stiffness.

Files in results/examples/: boom_mounts.{md,csv}, boom_mounts_lift.png,
boom_mounts_static.h5, boom_mounts_lift.h5.

    python examples/boom_mounts.py [--quick] [--out DIR]
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from example_utils import arguments, relative, write_table

from ancfdrv import Box, System

GRAVITY = 9.81


@dataclass(frozen=True)
class Boom:
    """Dimensions [m], masses [kg], stiffnesses and the struts' attachment points."""

    length: float = 5.0
    section: Box = Box(width=0.2, height=0.3, wall=0.008)
    density: float = 7850.0
    youngs_modulus: float = 2.1e11
    payload: float = 300.0
    cylinder_ground: tuple[float, float, float] = (0.8, 0.0, -1.2)
    cylinder_boom: tuple[float, float, float] = (2.0, 0.0, 0.0)
    oil_stiffness: float = 2e7
    oil_damping: float = 5e4
    lift_rate: float = 0.08
    spring_ground: tuple[float, float, float] = (2.5, 0.0, -1.5)
    spring_boom: tuple[float, float, float] = (3.5, 0.0, 0.0)
    spring_free_length: float = 2.3
    spring_stiffness: float = 5e3
    spring_preload: float = -2e3
    spring_damping: float = 1e3

    @property
    def mass_per_length(self) -> float:
        return self.density * self.section.data.area

    @property
    def initial_length(self) -> float:
        return float(np.linalg.norm(np.subtract(self.cylinder_boom, self.cylinder_ground)))


def build(boom: Boom) -> System:
    s = System("luffing boom on compliant mounts")
    s.material("steel", youngs_modulus=boom.youngs_modulus, density=boom.density)
    s.beam("boom", material="steel", start=(0, 0, 0), end=(boom.length, 0, 0), nodes=9,
           section=boom.section, formulation="nonlinear", bending="cubic")
    s.drive("lift", "ramp", start=boom.initial_length, rate=boom.lift_rate, t_ramp=0.5, t0=0.5)
    s.force_element("root", "bushing", "ground", "boom", point=(0, 0, 0),
                    stiffness=[5e8, 5e8, 5e8], rotational_stiffness=[5e7, 0.0, 5e7])
    s.force_element("cylinder", "cylinder", "ground", "boom", point1=boom.cylinder_ground,
                    point2=boom.cylinder_boom, drive="lift", stiffness=boom.oil_stiffness,
                    damping=boom.oil_damping)
    s.force_element("gas spring", "spring_damper", "ground", "boom", point1=boom.spring_ground,
                    point2=boom.spring_boom, stiffness=boom.spring_stiffness,
                    free_length=boom.spring_free_length, preload=boom.spring_preload,
                    damping=boom.spring_damping)
    s.load("gravity", "gravity", vector=(0, 0, -GRAVITY))
    s.load("payload", "point_mass", body="boom", point=(boom.length, 0, 0), mass=boom.payload)
    s.probe("tip", "boom", (boom.length, 0, 0))
    s.probe("cylinder end", "boom", boom.cylinder_boom)
    return s


def rigid_cylinder_force(boom: Boom, angle: float, rate: float = 0.0) -> tuple[float, float]:
    """The rigid moment balance about the hinge with the boom turned up by ``angle`` (rad)
    and turning at ``rate`` (rad/s; the inertia of a steady turn is neglected): the
    cylinder's and the gas spring's axial forces (tension positive); the gas spring at its
    length and extension rate there."""
    c, s = np.cos(angle), np.sin(angle)
    turn = np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])          # about -y: x up towards z
    weight_arm = 0.5 * boom.length * c
    moment = GRAVITY * (boom.mass_per_length * boom.length * weight_arm
                        + boom.payload * boom.length * c)           # about -y, pulling down

    def strut(ground, point) -> tuple[np.ndarray, np.ndarray]:
        p = turn @ np.asarray(point)
        unit = (p - np.asarray(ground)) / np.linalg.norm(p - np.asarray(ground))
        # moment about -y of a unit tension (force -unit on the boom at p)
        return p, float(-(np.cross(p, -unit))[1])

    p_spring, arm_spring = strut(boom.spring_ground, boom.spring_boom)
    length = float(np.linalg.norm(p_spring - np.asarray(boom.spring_ground)))
    unit_spring = (p_spring - np.asarray(boom.spring_ground)) / length
    velocity = rate * np.array([-s * boom.spring_boom[0], 0.0, c * boom.spring_boom[0]])
    spring = boom.spring_preload + boom.spring_stiffness * (length - boom.spring_free_length) \
        + boom.spring_damping * float(unit_spring @ velocity)
    _, arm_cylinder = strut(boom.cylinder_ground, boom.cylinder_boom)
    # moment of the tensions (about -y) lifts the boom: f_c arm_c + f_s arm_s = moment
    cylinder = (moment - spring * arm_spring) / arm_cylinder
    return cylinder, spring


def boom_angle(tip: np.ndarray, boom: Boom) -> np.ndarray:
    """The chord angle root-tip above the x axis (rad)."""
    tip = np.atleast_2d(tip)
    return np.arctan2(tip[:, 2], tip[:, 0])


def run(quick: bool, out: Path) -> dict:
    boom = Boom()
    out.mkdir(parents=True, exist_ok=True)
    static = build(boom).static(static_method="newton", output=out / "boom_mounts_static.h5")
    angle0 = float(boom_angle(static.probes["tip"], boom)[0])
    rigid_c, rigid_s = rigid_cylinder_force(boom, angle0)
    cyl = float(static.reactions["cylinder"]["axial"])
    gas = float(static.reactions["gas spring"]["axial"])
    root = np.asarray(static.reactions["root"]["force"])
    rows = [["cylinder force [kN]", cyl / 1e3, rigid_c / 1e3, relative(cyl, rigid_c)],
            ["gas spring force [kN]", gas / 1e3, rigid_s / 1e3, relative(gas, rigid_s)],
            ["boom angle [mrad]", 1e3 * angle0, "", ""],
            ["root reaction x, z [kN]", f"{root[0] / 1e3:.4f}, {root[2] / 1e3:.4f}", "", ""]]

    t_end = 1.5 if quick else 3.0
    system = build(boom)
    lift = system.simulate(t_end=t_end, dt=5e-3, from_static=True,
                           output=out / "boom_mounts_lift.h5")
    t = np.asarray(lift.time)
    angle = boom_angle(np.asarray(lift.probes["tip"]), boom)
    force = np.asarray(lift.reactions["cylinder"]["axial"])
    rate = np.gradient(angle, t)
    end = len(t) - 1
    rigid_end, _ = rigid_cylinder_force(boom, float(angle[end]), float(rate[end]))
    stroke = system.drives["lift"].value(float(t[end]))                # l(t)
    column = float(np.linalg.norm(np.asarray(lift.probes["cylinder end"])[end]
                                  - np.asarray(boom.cylinder_ground))) - stroke
    rows += [[f"cylinder force at t = {t[end]:g} s [kN]", force[end] / 1e3, rigid_end / 1e3,
              relative(force[end], rigid_end)],
             ["oil column L - l at the end [mm]", 1e3 * column,
              1e3 * force[end] / boom.oil_stiffness, ""],
             ["boom angle at the end [mrad]", 1e3 * float(angle[end]), "", ""]]
    print(write_table(out / "boom_mounts", ["quantity", "model", "rigid balance / k (L - l)",
                                            "difference"], rows,
                      title="Luffing boom on compliant mounts",
                      note="Rigid balance: the moment of the boom's weight and the payload "
                           "about the hinge against the two struts at the model's boom angle "
                           "and angular rate (the gas spring's damper included); the "
                           "column's compression is the force over the oil stiffness."))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
        axes[0].plot(t, force / 1e3, label="cylinder (model)")
        axes[0].plot(t, [rigid_cylinder_force(boom, float(a), float(w))[0] / 1e3
                         for a, w in zip(angle, rate)], "--",
                     label="rigid moment balance at the angle and rate")
        axes[0].set_ylabel("axial force [kN] (tension +)")
        axes[0].legend()
        axes[1].plot(t, 1e3 * angle)
        axes[1].set_ylabel("boom angle [mrad]")
        axes[1].set_xlabel("t [s]")
        fig.tight_layout()
        fig.savefig(out / "boom_mounts_lift.png", dpi=100)
        plt.close(fig)
    except ImportError:
        pass
    return dict(static=static, lift=lift, boom=boom, cylinder=cyl, rigid_cylinder=rigid_c,
                gas=gas, rigid_gas=rigid_s, end_force=force[end], rigid_end=rigid_end,
                column=column)


def main(argv: Sequence[str] | None = None) -> int:
    args = arguments(__doc__, argv)
    run(args.quick, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
