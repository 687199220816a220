"""Three-leaf spring: the two-leaf spring of inputs/general/leaf_spring.nml with a third,
shorter leaf below, built with the Python API and compared with the two-leaf spring.

The model (the r1-r3 plane is the spring's plane, gravity along -r3):

* leaves: curved plates (radius 2 m, concave up, 70 x 14 mm spring steel), stacked
  concentrically 14 mm apart: the main leaf (1.2 m, with the eyes), a second leaf (0.8 m,
  stress-free radius 1.5 m: prestressed against the main leaf) and a third leaf (0.4 m,
  stress-free radius 1.2 m);
* the axle clamp: 'fix' joints hold the position and the slope along the arc (r, r_x) of
  each leaf's middle node line;
* contact: a pair between neighbouring leaves (the lower leaf's end edges pressing on the
  leaf above), each with its own penalty stiffness K, damping C and friction mu;
* the chassis (500 kg) and the shackle (2 kg): rigid bodies kept in the r1-r3 plane, the
  front eye hinged to the chassis, the rear eye to the shackle, the shackle to the chassis
  ('spherical' joints at the two edge nodes of an eye: a hinge about r2).

What it computes and prints, for the two-leaf and the three-leaf spring built the same way:
the equilibrium of the prestressed spring without weight, the static equilibrium under
gravity (its sag: the chassis drop between the two; the third leaf makes the spring
stiffer), and a drop: gravity switched on at t = 0 from the unloaded equilibrium, with
the energy balance (energy change minus the work of contact damping and friction) as a
check of the integration. The two-leaf spring's drop from the assembled state is compared
with the curved-beam reference (``tests/reference/leaf_reference.py``) when the script
runs in a checkout. Plot: chassis height and contact forces (``three_leaf_spring.png``).

Files in results/examples/: three_leaf_spring.{md,csv,png}, three_leaf_spring_2.h5,
three_leaf_spring_3.h5 (the unloaded equilibrium as /static, then the drop).

    python examples/three_leaf_spring.py [--quick] [--out DIR]
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from example_utils import arguments, reference, write_table

from ancfdrv import System
from ancfdrv.solvers.static import solve_newton

GRAVITY = 9.81
THICKNESS, WIDTH, RADIUS = 0.014, 0.07, 2.0
CHASSIS_MASS = 500.0


@dataclass(frozen=True)
class LeafSpec:
    name: str
    arc_length: float
    nx: int                      # elements along the arc (even: the axle is a node line)
    free_radius: float | None    # stress-free radius (prestress), None: stress-free as built


@dataclass(frozen=True)
class ContactSpec:
    stiffness: float   # N/m per contact point
    damping: float     # N s/m
    friction: float


LEAVES = (LeafSpec("main", 1.2, 12, None), LeafSpec("second", 0.8, 8, 1.5),
          LeafSpec("third", 0.4, 4, 1.2))
#: between main and second, between second and third
CONTACTS = (ContactSpec(1.0e6, 1.0e4, 0.3), ContactSpec(2.0e6, 1.0e4, 0.2))


def build(leaves: int) -> System:
    """The spring with the first ``leaves`` leaves of LEAVES."""
    s = System(f"{leaves}-leaf spring")
    steel = s.material("spring steel", youngs_modulus=2.1e11, density=7810.0, poisson_ratio=0.3)
    for k, leaf in enumerate(LEAVES[:leaves]):
        z = -k * THICKNESS  # concentric: 14 mm below the leaf above, radius 14 mm larger
        s.leaf(leaf.name, material=steel, thickness=THICKNESS, width=WIDTH,
               arc_length=leaf.arc_length, radius=RADIUS + k * THICKNESS, centre=(0, 0, z),
               nx=leaf.nx, ny=1, free_radius=leaf.free_radius)
        axle_line = [0, -WIDTH / 2, z, 0, WIDTH / 2, z]   # the middle node line (two nodes)
        s.joint(f"axle {leaf.name} r", "fix", "ground", leaf.name, point=axle_line, vector="r")
        s.joint(f"axle {leaf.name} r_x", "fix", "ground", leaf.name, point=axle_line,
                vector="r_x")
        if k:
            upper, c = LEAVES[k - 1].name, CONTACTS[k - 1]
            s.contact(f"{upper}-{leaf.name}", upper, leaf.name, stiffness=c.stiffness,
                      damping=c.damping, friction=c.friction, slip_speed=0.08, points=3)
    main = s.bodies["main"]
    half = LEAVES[0].arc_length / 2
    front, rear = main.material_point(-half, 0.0), main.material_point(half, 0.0)
    height = rear[2] + 0.05        # chassis centre and shackle centre: 50 mm above the eyes
    s.rigid_body("chassis", mass=CHASSIS_MASS, inertia=(50, 50, 50, 0, 0, 0),
                 position=(0, 0, height), planar=True)
    s.rigid_body("shackle", mass=2.0, inertia=(1.6993e-3, 1.7333e-3, 9.9333e-5, 0, 0, 0),
                 position=(rear[0], 0, height), planar=True)
    s.joint("shackle top", "spherical", "chassis", "shackle", point=(rear[0], 0, height + 0.05))
    for name, body, eye in (("front eye", "chassis", front), ("rear eye", "shackle", rear)):
        s.joint(name, "spherical", body, "main",
                point=[eye[0], -WIDTH / 2, eye[2], eye[0], WIDTH / 2, eye[2]])
    s.load("gravity", "gravity", vector=(0, 0, -GRAVITY))
    s.probe("chassis", "chassis", (0, 0, height))
    return s


@dataclass
class Spring:
    leaves: int
    built: float       # chassis height as assembled [m]
    unloaded: float    # ... at the equilibrium without weight (prestress and contact only)
    loaded: float      # ... at the static equilibrium under gravity
    time: np.ndarray
    chassis: np.ndarray            # chassis height during the drop [m]
    pair_forces: dict[str, np.ndarray]   # total normal force of each contact pair [N]
    balance: np.ndarray            # energy balance [J]
    dissipated: np.ndarray         # work of contact damping and friction (< 0) [J]
    ndof: int

    @property
    def sag(self) -> float:
        """Static chassis drop under the weight, from the unloaded equilibrium [m]."""
        return self.unloaded - self.loaded


def simulate(leaves: int, t_end: float, dt: float = 1e-3, out: Path | None = None) -> Spring:
    system = build(leaves)
    model = system.assemble()  # every effect, gravity included
    try:
        built = model.probe_positions(model.e0)["chassis"][2]
        loaded = solve_newton(model, tol=1e-8, max_iter=60, load_steps=5)
        final = model.probe_positions(loaded.e)["chassis"][2]
        ndof = model.ndof
    finally:
        model.close()
    # the drop from the unloaded equilibrium (prestress carried by contact, the loads off:
    # the scene key solver.settle = 'unloaded'), which the run writes to /static
    res = system.simulate(t_end, dt, settle="unloaded", static_method="newton", tol=1e-10,
                          max_iter=60, load_steps=2, integrator="generalized_alpha",
                          rho_inf=0.8, newton_tol=1e-8, max_newton=25, output=out)
    start = res.static.probes["chassis"][2]
    contact = res.dynamic["contact"]
    normal = contact["normal_force"]
    points = str(contact.attrs.get("points", "")).split("\n")
    pairs = {}
    for name in system.contacts:
        columns = [k for k, point in enumerate(points) if point.startswith(f"{name}:")]
        pairs[name] = normal[:, columns].sum(axis=1)
    return Spring(leaves, built, start, final, res.time, res.probes["chassis"][:, 2], pairs,
                  res.energy["balance"],
                  res.energy["damping_work"] + res.energy["friction_work"], ndof)


def two_leaf_reference() -> dict | None:
    """Static chassis drop of the two-leaf spring from its assembled state by curved-beam
    theory (tests/reference/leaf_reference.py, 3 contact points of 1e6 N/m per tip, shackle
    tilt included) for the beam (E w h^3/12) and plate (/(1 - nu^2)) bending stiffness."""
    leaf = reference("leaf_reference")
    if leaf is None:
        return None
    return {name: leaf.chassis_static_drop(ei, prestress=True, contact_stiffness=3.0e6,
                                           shackle_tilt=True)["drop"]
            for name, ei in (("beam", leaf.BEAM_EI), ("plate", leaf.PLATE_DW))}


def plot(springs: list[Spring], path: Path) -> None:
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for spring, colour in zip(springs, ("tab:blue", "tab:red")):
        label = f"{spring.leaves} leaves"
        ax1.plot(spring.time, 1e3 * spring.chassis, color=colour, label=label)
        ax1.axhline(1e3 * spring.loaded, color=colour, ls="--", lw=0.8)
        for (name, force), style in zip(spring.pair_forces.items(), ("-", ":")):
            ax2.plot(spring.time, force / 1e3, color=colour, ls=style, label=f"{label}: {name}")
    ax1.set(ylabel="chassis height [mm]",
            title="drop under gravity from the unloaded equilibrium (dashed: static)")
    ax2.set(xlabel="time [s]", ylabel="contact normal force [kN]\n(sum over the pair)")
    ax1.legend()
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


@dataclass
class Report:
    springs: list[Spring]
    reference: dict | None
    files: list[Path]


def run(quick: bool, out: Path) -> Report:
    out.mkdir(parents=True, exist_ok=True)
    t_end = 0.2 if quick else 0.6
    springs = [simulate(n, t_end, out=out / f"three_leaf_spring_{n}.h5") for n in (2, 3)]
    ref = two_leaf_reference()
    rows = []
    for s in springs:
        drop = s.unloaded - s.chassis.min()
        rows.append([s.leaves, s.ndof, 1e3 * (s.built - s.loaded), 1e3 * s.sag,
                     CHASSIS_MASS * GRAVITY / s.sag / 1e3, 1e3 * drop,
                     np.abs(s.balance).max() / (CHASSIS_MASS * GRAVITY * drop),
                     -s.dissipated[-1]])
    if ref:
        rows.append(["2 (curved beams)", "", 1e3 * ref["beam"], "", "", "", "", ""])
        rows.append(["2 (curved plates)", "", 1e3 * ref["plate"], "", "", "", "", ""])
    print(write_table(out / "three_leaf_spring",
                      ["leaves", "ndof", "static drop from the assembled state [mm]",
                       "sag under the weight [mm]", "secant stiffness m g / sag [kN/m]",
                       f"max drop in {t_end:g} s [mm]",
                       "max |energy balance| / (m g max drop)", "dissipated [J]"], rows,
                      "Two- and three-leaf spring under a 500 kg chassis",
                      "Sag: from the equilibrium of the prestressed spring without weight to "
                      "the one with it. Reference rows: tests/reference/leaf_reference."
                      "chassis_static_drop (linear curved-beam theory, beam and plate bending "
                      "stiffness)."))
    plot(springs, out / "three_leaf_spring.png")
    return Report(springs, ref, [out / "three_leaf_spring_2.h5", out / "three_leaf_spring_3.h5",
                                 out / "three_leaf_spring.png", out / "three_leaf_spring.md"])


def main(argv: Sequence[str] | None = None) -> int:
    args = arguments(__doc__, argv)
    run(args.quick, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
