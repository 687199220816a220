"""Aerial work platform: a box boom cantilevered from a turntable carrying a basket, a rigid
body welded to the boom tip with its centre of mass below and beyond the tip.

The model (gravity along -z):

* the boom: 8 m steel box girder (250 mm wide, 300 mm high, 6 mm wall) along x, section
  height along z, formulation 'nonlinear' with 'cubic' bending; its frame turns with the
  slewing drive, so the beam's probe deflections come in the turning frame. (Not 'ffr':
  welded to a rigid body, whose axes stay unit vectors, an FFR section that turns is
  shortened to second order, which its linear strain resists: the tip would come out
  0.7 % too stiff on 9 nodes, an error proportional to the element length);
* the turntable: a 'hub' joint clamps the boom root and turns it about the vertical axis by
  the angle of the drive 'slew' (a constant for the statics and the free vibration);
* the basket: a rigid body of 300 kg (a 1.2 x 0.8 x 1.1 m box's inertia), its centre of mass
  0.6 m beyond and 0.5 m below the tip, welded to the tip: the boom's end section follows
  the basket's axes (body1 = basket, body2 = boom: the section is clamped to the basket).

What it computes and prints:

1. statics under gravity: the tip deflection, the basket's drop and its tilt (the rotation
   of its axes about y), next to a linear Timoshenko frame model
   (``tests/reference/frames.py``, 40 elements) when the script runs in a checkout;
2. free vibration: a sideways push on the basket (a 2 kN, 0.2 s force pulse, drive
   'cycle'), then the basket sways; the first natural frequency is fitted to its sideways
   motion and compared with the frame model's first eigenvalue;
3. a slewing start: the turntable turns the boom by 45 degrees (drive 'luffing': a cosine
   start over 1 s, 0.3 rad/s, a cosine stop over 1 s), then stops; the basket's sideways
   sway (in the turning frame) and its height are plotted (``aerial_platform_slew.png``).

Files in results/examples/: aerial_platform.{md,csv}, aerial_platform_slew.png,
aerial_platform_push.h5, aerial_platform_slew.h5 (static equilibrium + the run).

    python examples/aerial_platform.py [--quick] [--out DIR]
"""
from __future__ import annotations

import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import numpy as np
from scipy.optimize import curve_fit

from example_utils import arguments, reference, relative, write_table

from ancfdrv import Box, System
from ancfdrv.solvers.static import solve_newton

GRAVITY = 9.81


@dataclass(frozen=True)
class Platform:
    """Dimensions [m], masses [kg] and material (steel) of the aerial platform."""

    boom_length: float = 8.0
    section: Box = Box(width=0.25, height=0.30, wall=0.006)
    basket_mass: float = 300.0
    basket_size: tuple[float, float, float] = (1.2, 0.8, 1.1)
    basket_offset: tuple[float, float, float] = (0.6, 0.0, -0.5)   # centre of mass from the tip
    youngs_modulus: float = 2.1e11
    density: float = 7850.0
    poisson_ratio: float = 0.3

    @property
    def tip(self) -> np.ndarray:
        return np.array([self.boom_length, 0.0, 0.0])

    @property
    def basket_centre(self) -> np.ndarray:
        return self.tip + np.asarray(self.basket_offset)

    @property
    def basket_inertia(self) -> np.ndarray:
        """Principal moments of a uniform box [kg m^2] (Ixx, Iyy, Izz)."""
        a, b, c = self.basket_size
        m = self.basket_mass / 12.0
        return np.array([m * (b * b + c * c), m * (a * a + c * c), m * (a * a + b * b)])


@dataclass(frozen=True)
class Slew:
    """The slewing profile (drive 'luffing'): rate [rad/s], start and stop times [s],
    sweep [rad]."""

    omega: float = 0.3
    t_start: float = 1.0
    t_brake: float = 1.0
    sweep: float = np.radians(45.0)

    @property
    def end(self) -> float:
        """When the boom stops: sweep / omega + (t_start + t_brake) / 2."""
        return self.sweep / self.omega + 0.5 * (self.t_start + self.t_brake)


def build(p: Platform, nodes: int, slew: Slew | None = None,
          push: tuple[float, float] | None = None) -> System:
    """The platform; ``slew``: the turntable's profile (else it holds), ``push``: a sideways
    force pulse (peak N, duration s) on the basket's centre of mass."""
    s = System("Aerial work platform")
    steel = s.material("steel", youngs_modulus=p.youngs_modulus, density=p.density,
                       poisson_ratio=p.poisson_ratio)
    if slew is None:
        s.drive("slew", "constant", value=0.0)
    else:
        s.drive("slew", "luffing", omega=slew.omega, t_start=slew.t_start,
                t_brake=slew.t_brake, sweep=slew.sweep)
    s.beam("boom", material=steel, start=(0, 0, 0), end=p.tip, nodes=nodes, section=p.section,
           height_axis=(0, 0, 1), formulation="nonlinear", bending="cubic",
           frame_drive="slew", frame_axis=(0, 0, 1), frame_pivot=(0, 0, 0))
    s.rigid_body("basket", mass=p.basket_mass, inertia=(*p.basket_inertia, 0, 0, 0),
                 position=p.basket_centre)
    s.joint("turntable", "hub", "ground", "boom", point=(0, 0, 0), pivot=(0, 0, 0),
            axis=(0, 0, 1), drive="slew")
    s.joint("basket mount", "weld", "basket", "boom", point=p.tip)
    s.load("gravity", "gravity", vector=(0, 0, -GRAVITY))
    if push is not None:
        s.drive("pulse", "cycle", amplitude=1.0, period=push[1])
        s.load("push", "force", body="basket", point=p.basket_centre, vector=(0, push[0], 0),
               drive="pulse")
    s.probe("basket", "basket", p.basket_centre)
    s.probe("tip", "boom", p.tip)
    return s


def basket_axes(model, e: np.ndarray) -> np.ndarray:
    """The basket's orientation J = [r_x r_y r_z] (columns) at the coordinates e."""
    basket = next(b for b in model.bodies if b.name == "basket")
    q = model.expand(e)
    return q[basket.first + 3:basket.first + 12].reshape(3, 3).T


@dataclass
class Statics:
    tip: np.ndarray        # tip displacement [m]
    basket: np.ndarray     # basket centre of mass displacement [m]
    tilt: float            # basket rotation about y [rad] (nose down positive)
    e: np.ndarray


def statics(p: Platform, nodes: int) -> Statics:
    model = build(p, nodes).assemble()
    try:
        result = solve_newton(model, tol=1e-10)
        at = model.probe_positions(result.e)
        axes = basket_axes(model, result.e)
        return Statics(at["tip"] - p.tip, at["basket"] - p.basket_centre,
                       float(np.arctan2(-axes[2, 0], axes[0, 0])), result.e)
    finally:
        model.close()


def fit_frequency(t: np.ndarray, y: np.ndarray) -> float:
    """Frequency [Hz] of the sinusoid a cos(2 pi f t) + b sin(2 pi f t) + c fitted to y(t)
    (least squares, started from the mean zero-crossing period)."""
    centred = y - y.mean()
    k = np.flatnonzero(np.sign(centred[:-1]) != np.sign(centred[1:]))
    crossings = t[k] - centred[k] * (t[k + 1] - t[k]) / (centred[k + 1] - centred[k])
    guess = 0.5 * (len(crossings) - 1) / (crossings[-1] - crossings[0])

    def wave(t, a, b, c, f):
        return a * np.cos(2 * np.pi * f * t) + b * np.sin(2 * np.pi * f * t) + c
    params, _ = curve_fit(wave, t, y, p0=(np.ptp(y) / 2, 0.0, y.mean(), guess))
    return float(params[3])


@dataclass
class Run:
    """A dynamic run: times, basket and tip positions, energies."""

    time: np.ndarray
    basket: np.ndarray
    tip: np.ndarray
    balance: np.ndarray
    kinetic: np.ndarray
    angle: np.ndarray = field(default_factory=lambda: np.zeros(0))


def dynamic(p: Platform, nodes: int, dt: float, t_end: float, slew: Slew | None = None,
            push: tuple[float, float] | None = None, out: Path | None = None,
            title: str = "") -> Run:
    """From the static equilibrium (turntable at rest), integrate to t_end
    (generalized-alpha, rho_inf = 0.9: hardly any numerical damping at the sway)."""
    system = build(p, nodes, slew, push)
    t_end = dt * np.ceil(t_end / dt - 1e-9)  # a whole number of steps (as scenes require)
    res = system.simulate(t_end, dt, from_static=True, static_method="newton", tol=1e-10,
                          integrator="generalized_alpha", rho_inf=0.9, newton_tol=1e-10,
                          max_newton=20, output=out)
    t = res.time
    return Run(t, res.probes["basket"], res.probes["tip"], res.energy["balance"],
               res.energy["kinetic"], system.drives["slew"].values(t)[0])


def turning_frame(points: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Points (nt, 3) in the frame turned by angle(t) about z."""
    c, s = np.cos(angle), np.sin(angle)
    return np.column_stack([c * points[:, 0] + s * points[:, 1],
                            -s * points[:, 0] + c * points[:, 1], points[:, 2]])


def frame_reference(p: Platform) -> dict | None:
    """Static tip deflection, basket tilt and first frequency of the linear Timoshenko
    frame model (tests/reference/frames.py, 40 elements), or None outside a checkout."""
    frames = reference("frames")
    if frames is None:
        return None
    shear_modulus = p.youngs_modulus / (2.0 * (1.0 + p.poisson_ratio))
    frame = frames.Frame()
    nodes = frame.add_beam_line((0, 0, 0), p.tip, 40, p.youngs_modulus, shear_modulus,
                                frames.box(p.section.width, p.section.height, p.section.wall),
                                p.density, theory="timoshenko", height_axis=(0, 0, 1))
    frame.fix(nodes[0])
    frame.add_rigid_body(nodes[-1], p.basket_mass, p.basket_inertia, p.basket_offset)
    static = frame.solve_static(gravity=(0, 0, -GRAVITY)).displacements[nodes[-1]]
    modes = frame.solve_modes(1)
    return {"tip_z": static[2], "tilt": static[4], "frequency": modes.frequency_hz[0]}


def plot(run: Run, slew: Slew, rest: np.ndarray, path: Path) -> None:
    """Slew angle, the basket's sideways sway in the turning frame and its height."""
    import matplotlib.pyplot as plt
    local = turning_frame(run.basket, run.angle) - rest
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    axes[0].plot(run.time, np.degrees(run.angle))
    axes[0].set(ylabel="slew angle [deg]", title="slewing start: turntable 0 -> 45 deg")
    axes[1].plot(run.time, 1e3 * local[:, 1])
    axes[1].set(ylabel="basket sway [mm]\n(sideways, turning frame)")
    axes[2].plot(run.time, 1e3 * local[:, 2])
    axes[2].set(ylabel="basket height [mm]\n(from the static rest)", xlabel="time [s]")
    for ax in axes:
        for t in (slew.t_start, slew.end - slew.t_brake, slew.end):
            ax.axvline(t, color="0.75", lw=0.8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


@dataclass
class Report:
    statics: Statics
    frequency: float
    push: Run
    slew: Run
    slew_profile: Slew
    reference: dict | None
    files: list[Path]


def run(quick: bool, out: Path) -> Report:
    out.mkdir(parents=True, exist_ok=True)
    p, slew = Platform(), Slew()
    nodes = 5 if quick else 9
    rest = statics(p, nodes)
    push = dynamic(p, nodes, dt=4e-3 if quick else 2e-3, t_end=2.0 if quick else 3.0,
                   push=(2000.0, 0.2), out=out / "aerial_platform_push.h5",
                   title="Aerial platform: a sideways push on the basket")
    after = push.time > 0.3
    frequency = fit_frequency(push.time[after], push.basket[after, 1])
    moving = dynamic(p, nodes, dt=1e-2 if quick else 5e-3, t_end=slew.end + (1.0 if quick else 2.4),
                     slew=slew, out=out / "aerial_platform_slew.h5",
                     title="Aerial platform: slewing start")
    ref = frame_reference(p)
    sway = turning_frame(moving.basket, moving.angle)[:, 1] - (p.basket_centre + rest.basket)[1]
    rows = [
        ["tip deflection z [mm]", 1e3 * rest.tip[2], 1e3 * ref["tip_z"] if ref else np.nan],
        ["basket drop z [mm]", 1e3 * rest.basket[2], np.nan],
        ["basket tilt about y [mrad]", 1e3 * rest.tilt, 1e3 * ref["tilt"] if ref else np.nan],
        ["first natural frequency [Hz]", frequency, ref["frequency"] if ref else np.nan],
        ["max sideways sway while slewing [mm]", 1e3 * np.abs(sway).max(), np.nan],
        ["max |energy balance| / max kinetic energy (slew)",
         np.abs(moving.balance).max() / moving.kinetic.max(), np.nan],
    ]
    for row in rows:
        row.append(relative(row[1], row[2]) if np.isfinite(row[2]) else np.nan)
    print(write_table(out / "aerial_platform", ["quantity", "model", "frame model (linear)",
                                               "rel. difference"], rows,
                      "Aerial work platform",
                      f"Boom: {nodes} nodes, nonlinear, cubic bending. Frame model: "
                      "tests/reference/frames.py, 40 Timoshenko elements, the basket as a "
                      "rigid body with its offset centre of mass."))
    plot(moving, slew, p.basket_centre + rest.basket, out / "aerial_platform_slew.png")
    return Report(rest, frequency, push, moving, slew, ref,
                  [out / "aerial_platform_push.h5", out / "aerial_platform_slew.h5",
                   out / "aerial_platform_slew.png", out / "aerial_platform.md"])


def main(argv: Sequence[str] | None = None) -> int:
    args = arguments(__doc__, argv)
    run(args.quick, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
