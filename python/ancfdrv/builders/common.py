"""What the template builders share: the built system with the builder's choices, the
loads of the beam templates, and the warning for 'ffr' scenes outside their assumptions."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..codes import DRIVE_LUFFING, DRIVE_SPINUP
from ..system import Beam, System
from ..system.sections import Rectangle


@dataclass
class BuiltSystem:
    """A system, the probe and component sweeps compare, and the builder's warnings."""

    system: System
    response: tuple[str, int] | None = None
    warnings: list[str] = field(default_factory=list)


def material(system: System, scene, name: str = "material"):
    m = scene["material"]
    return system.material(name, youngs_modulus=m["youngs_modulus"], density=m["density"],
                           poisson_ratio=m["poisson_ratio"], damping_time=m["damping_time"])


def rectangle(scene) -> Rectangle:
    return Rectangle(scene["beam"]["width"], scene["beam"]["height"])


def beam_loads(built: BuiltSystem, scene, beam: Beam, tip) -> None:
    """The loads of the beam templates at the tip (the end of the neutral axis): probe
    'tip', tip mass, gravity along -r2, tip force, end moment about +r3; a load that is set
    but whose effect is not listed is a warning."""
    s, loads, effects = built.system, scene["loads"], scene.effects
    s.probe("tip", beam.name, tip)
    if "tip_mass" in effects:
        s.load("tip_mass", "point_mass", body=beam.name, point=tip, mass=loads["tip_mass"],
               effect="tip_mass")
    if "gravity" in effects:
        s.load("gravity", "gravity", vector=(0.0, -loads["gravity"], 0.0))
    if "tip_force" in effects:
        s.load("tip_force", "force", body=beam.name, point=tip, vector=loads["tip_force"],
               effect="tip_force")
    if "end_moment" in effects and loads["end_moment"] != 0.0:
        s.load("end_moment", "moment", body=beam.name, point=tip,
               vector=(0.0, 0.0, loads["end_moment"]), effect="end_moment")
    if "tip_mass" not in effects and loads["tip_mass"] > 0:
        built.warnings.append("loads.tip_mass is set but 'tip_mass' is not in scene.effects: "
                              "not applied")
    for key, effect in (("tip_force", "tip_force"), ("end_moment", "end_moment"),
                        ("moment", "bending_moment")):
        if effect not in effects and np.any(np.asarray(loads[key]) != 0):
            built.warnings.append(f"loads.{key} is set but {effect!r} is not in scene.effects: "
                                  "not applied")


def first_bending_frequency(beam: Beam) -> float:
    """Clamped-free first bending frequency (rad/s) in the weak direction,
    (beta_1 L)^2 sqrt(EI / (rho A L^4))."""
    section = beam.section.data
    inertia = min(section.inertia_y, section.inertia_z)
    return 1.875104068711961**2 * np.sqrt(beam.material.youngs_modulus * inertia / (
        beam.material.density * section.area * beam.length**4))


def check_ffr_validity(model, system: System) -> None:
    """Warn when an 'ffr' beam's frame turns at a speed near or above its first bending
    frequency (FFR has no geometric, centrifugal, stiffening)."""
    for beam in system.bodies.values():
        if not isinstance(beam, Beam) or beam.formulation != "ffr" or beam.frame_drive is None:
            continue
        drive = beam.frame_drive
        params = drive.params()
        rate = {DRIVE_LUFFING: abs(params[0]), DRIVE_SPINUP: abs(params[0])}.get(drive.kind, 0.0)
        omega1 = first_bending_frequency(beam)
        if rate > 0.3 * omega1 and beam.geometric_stiffness:
            model.warnings.append(
                f"formulation 'ffr' outside its assumptions: the frame of beam {beam.name!r} "
                f"turns at {rate:.3g} rad/s, {rate / omega1:.2f} of its first bending frequency "
                f"{omega1:.3g} rad/s; its centrifugal stiffening comes from the P-delta option "
                "(geometric_stiffness), linear in the frame - compare with formulation = "
                "'nonlinear'")
        elif rate > 0.3 * omega1:
            model.warnings.append(
                f"formulation 'ffr' outside its assumptions: the frame of beam {beam.name!r} "
                f"turns at {rate:.3g} rad/s, {rate / omega1:.2f} of its first bending frequency "
                f"{omega1:.3g} rad/s; FFR has no geometric (centrifugal) stiffening and becomes "
                "unstable near and above it - use formulation = 'nonlinear'")
