"""Flexible slider-crank: a rigid crank driven at constant speed, a flexible connecting rod
and a slider guided along x; a closed loop whose joint equations are partly redundant.

The model (in the x-y plane, no gravity):

* the crank: a rigid body (1 kg, 0.15 m, a slender rod's inertia), kept in the x-y plane
  ('planar' rigid body), hinged to the ground at O by a 'revolute' joint about z; a
  'prescribed' joint moves its crank pin A on the circle by the angle of the drive 'crank'
  (drive 'spinup': from rest to 60 rad/s in 0.05 s, then constant speed);
* the connecting rod: a steel circular rod of 0.45 m between A and the wrist pin B,
  formulation 'nonlinear' with 'cubic' bending, hinged to the crank at A and to the
  slider at B by 'revolute' joints about z;
* the slider: a planar rigid body of 0.5 kg; a 'fix' joint holds its y (the guide) and
  another its x axis r_x (it does not turn).

Revolutes about z on bodies kept in their plane repeat equations the planar guides already
impose, and the closed loop adds more: the assembly drops the redundant equations and lists
them in ``model.notes`` (printed).

What it computes and prints: with a stiff rod (40 mm) the slider position and the driving
torque (from the multipliers of the prescribed joint) against the rigid slider-crank
(``tests/reference/mechanisms.py`` when the script runs in a checkout: closed-form
kinematics, torque by virtual work); then the rod's midpoint deflection (from the chord A-B)
against the crank angle for a soft (8 mm) and the stiff rod, plotted in
``slider_crank.png``.

Files in results/examples/: slider_crank.{md,csv,png}, slider_crank_soft.h5,
slider_crank_stiff.h5.

    python examples/slider_crank.py [--quick] [--out DIR]
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from example_utils import arguments, reference, write_table

from ancfdrv import Circle, System


@dataclass(frozen=True)
class SliderCrank:
    """Dimensions [m], masses [kg], crank speed [rad/s] and spin-up time [s]."""

    crank_length: float = 0.15
    rod_length: float = 0.45
    crank_mass: float = 1.0
    slider_mass: float = 0.5
    omega: float = 60.0
    spinup: float = 0.05
    youngs_modulus: float = 2.1e11
    density: float = 7850.0
    poisson_ratio: float = 0.3

    def rod_mass(self, diameter: float) -> float:
        return self.density * np.pi * diameter**2 / 4.0 * self.rod_length

    def slider_x(self, angle: np.ndarray) -> np.ndarray:
        """Rigid kinematics: x = r cos(theta) + sqrt(l^2 - r^2 sin^2(theta))."""
        r, l = self.crank_length, self.rod_length
        return r * np.cos(angle) + np.sqrt(l**2 - (r * np.sin(angle))**2)


def build(p: SliderCrank, diameter: float, nodes: int) -> System:
    """The mechanism at crank angle 0 (A and B on the x axis)."""
    r, l = p.crank_length, p.rod_length
    pin, wrist = np.array([r, 0.0, 0.0]), np.array([r + l, 0.0, 0.0])
    s = System(f"Slider-crank, rod {1e3 * diameter:g} mm")
    steel = s.material("steel", youngs_modulus=p.youngs_modulus, density=p.density,
                       poisson_ratio=p.poisson_ratio)
    s.drive("crank", "spinup", omega=p.omega, period=p.spinup)
    s.rigid_body("crank", mass=p.crank_mass, position=pin / 2, planar=True,
                 plane_normal=(0, 0, 1),
                 inertia=(1e-6, p.crank_mass * r**2 / 12, p.crank_mass * r**2 / 12, 0, 0, 0))
    s.beam("rod", material=steel, start=pin, end=wrist, nodes=nodes, section=Circle(diameter),
           height_axis=(0, 1, 0), formulation="nonlinear", bending="cubic")
    s.rigid_body("slider", mass=p.slider_mass, inertia=(1e-4, 1e-4, 1e-4, 0, 0, 0),
                 position=wrist, planar=True, plane_normal=(0, 0, 1))
    s.joint("main bearing", "revolute", "ground", "crank", point=(0, 0, 0), axis=(0, 0, 1))
    s.joint("crank drive", "prescribed", "ground", "crank", point=pin, pivot=(0, 0, 0),
            axis=(0, 0, 1), drive="crank")
    s.joint("crank pin", "revolute", "crank", "rod", point=pin, axis=(0, 0, 1))
    s.joint("wrist pin", "revolute", "slider", "rod", point=wrist, axis=(0, 0, 1))
    s.joint("guide", "fix", "ground", "slider", point=wrist, axis=(0, 1, 0))
    s.joint("no turn", "fix", "ground", "slider", point=wrist, vector="r_x")
    s.probe("crank pin", "crank", pin)
    s.probe("slider", "slider", wrist)
    s.probe("midpoint", "rod", (pin + wrist) / 2)
    return s


@dataclass
class Run:
    diameter: float
    time: np.ndarray
    angle: np.ndarray          # crank angle [rad] (the drive's)
    slider_x: np.ndarray       # [m]
    deflection: np.ndarray     # rod midpoint from the chord A-B, left normal positive [m]
    torque: np.ndarray         # driving torque on the crank [N m]
    notes: list[str]
    ndof: int


def simulate(p: SliderCrank, diameter: float, nodes: int, dt: float, revolutions: float,
             out: Path | None = None) -> Run:
    """Spin up from rest, then ``revolutions`` turns at constant speed."""
    system = build(p, diameter, nodes)
    t_end = p.spinup + revolutions * 2 * np.pi / p.omega
    t_end = dt * np.ceil(t_end / dt - 1e-9)  # a whole number of steps (as scenes require)
    res = system.simulate(t_end, dt,
                          integrator="generalized_alpha", rho_inf=0.8, max_newton=20,
                          output=out)
    t = res.time
    pin, wrist, mid = (res.probes[n] for n in ("crank pin", "slider", "midpoint"))
    chord = wrist - pin
    normal = np.column_stack([-chord[:, 1], chord[:, 0]]) / np.linalg.norm(
        chord[:, :2], axis=1)[:, None]
    deflection = np.einsum("ij,ij->i", mid[:, :2] - 0.5 * (pin[:, :2] + wrist[:, :2]),
                           normal)
    # the prescribed joint's multipliers are the force on the crank pin: torque A x F
    fx, fy = (res.multiplier(f"crank drive: {c}(t)") for c in "xy")
    torque = pin[:, 0] * fy - pin[:, 1] * fx
    notes = [n for n in str(res.model.attrs.get("notes", "")).split("\n") if n]
    return Run(diameter, t, system.drives["crank"].values(t)[0], wrist[:, 0], deflection,
               torque, notes, int(res.model.attrs["ndof"]))


def rigid_reference(p: SliderCrank, run: Run):
    """mechanisms.slider_crank at the run's times (constant speed after the spin-up:
    theta = omega t - omega T / 2), or None outside a checkout."""
    mech = reference("mechanisms")
    if mech is None:
        return None
    return mech.slider_crank(run.time, p.crank_length, p.rod_length, p.crank_mass,
                             p.rod_mass(run.diameter), p.slider_mass, p.omega,
                             theta0=-0.5 * p.omega * p.spinup)


def plot(p: SliderCrank, soft: Run, stiff: Run, ref, path: Path) -> None:
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    for run, style in ((soft, "-"), (stiff, "-")):
        steady = run.time >= p.spinup
        deg = np.degrees(np.mod(run.angle[steady], 2 * np.pi))
        order = np.argsort(deg, kind="stable")
        label = f"rod {1e3 * run.diameter:g} mm"
        axes[0].plot(deg[order], 1e3 * run.deflection[steady][order], ".", ms=1.5, label=label)
        axes[1].plot(deg[order], 1e6 * (run.slider_x[steady] - p.slider_x(run.angle[steady]))
                     [order], ".", ms=1.5, label=label)
    steady = stiff.time >= p.spinup
    deg = np.degrees(np.mod(stiff.angle[steady], 2 * np.pi))
    order = np.argsort(deg, kind="stable")
    axes[2].plot(deg[order], stiff.torque[steady][order], ".", ms=1.5, label="model, 40 mm rod")
    if ref is not None:
        axes[2].plot(deg[order], ref.torque[steady][order], "k-", lw=0.8, label="rigid mechanism")
    axes[0].set(xlabel="crank angle [deg]", ylabel="midpoint deflection [mm]",
                title="connecting rod: midpoint from the chord A-B")
    axes[1].set(xlabel="crank angle [deg]", ylabel="slider x - rigid kinematics [um]",
                title="slider position against the rigid mechanism")
    axes[2].set(xlabel="crank angle [deg]", ylabel="driving torque [N m]",
                title="torque that keeps 60 rad/s")
    for ax in axes:
        ax.legend(markerscale=6)
        ax.set_xticks(range(0, 361, 90))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


@dataclass
class Report:
    soft: Run
    stiff: Run
    references: list
    files: list[Path]


def run(quick: bool, out: Path) -> Report:
    out.mkdir(parents=True, exist_ok=True)
    p = SliderCrank()
    nodes, dt, turns = (5, 2e-4, 1.0) if quick else (9, 1e-4, 2.0)
    soft = simulate(p, 0.008, nodes, dt, turns, out / "slider_crank_soft.h5")
    stiff = simulate(p, 0.040, nodes, dt, turns, out / "slider_crank_stiff.h5")
    refs = [rigid_reference(p, r) for r in (soft, stiff)]
    print("Redundant joint equations dropped by the assembly:")
    print("\n".join(f"  {note}" for note in stiff.notes) + "\n")
    rows = []
    for run_, ref in zip((soft, stiff), refs):
        steady = run_.time >= p.spinup
        error = run_.slider_x[steady] - p.slider_x(run_.angle[steady])
        torque_error = np.nan
        if ref is not None:
            torque_error = (np.sqrt(np.mean((run_.torque - ref.torque)[steady] ** 2))
                            / np.sqrt(np.mean(ref.torque[steady] ** 2)))
        rows.append([f"{1e3 * run_.diameter:g} mm", run_.ndof,
                     1e3 * np.abs(run_.deflection[steady]).max(), 1e6 * np.abs(error).max(),
                     np.abs(run_.torque[steady]).max(),
                     np.abs(ref.torque[steady]).max() if ref is not None else np.nan,
                     torque_error])
    print(write_table(out / "slider_crank",
                      ["rod", "ndof", "max midpoint deflection [mm]",
                       "max |slider x - rigid| [um]", "max |torque|, model [N m]",
                       "rigid [N m]", "rms torque difference / rms rigid"], rows,
                      "Flexible slider-crank at 60 rad/s (after the spin-up)",
                      "Rigid: the rigid slider-crank with the same masses "
                      "(tests/reference/mechanisms.slider_crank); slider x against "
                      "r cos(theta) + sqrt(l^2 - r^2 sin^2(theta))."))
    ref = refs[1]
    plot(p, soft, stiff, ref, out / "slider_crank.png")
    return Report(soft, stiff, refs, [out / "slider_crank_soft.h5", out / "slider_crank_stiff.h5",
                                     out / "slider_crank.png", out / "slider_crank.md"])


def main(argv: Sequence[str] | None = None) -> int:
    args = arguments(__doc__, argv)
    run(args.quick, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
