"""What the template builders share: the built system with the builder's choices and the
loads of the beam templates."""
from __future__ import annotations

from dataclasses import field

import numpy as np

from ..records import record
from ..errors import InputError
from ..system import Beam, System
from ..system.sections import Rectangle


@record(eq=False)
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


def template_cable(scene, system: System, name: str, material_, start, end):
    """``beam.bending = 'cable'`` in a beam template (issue 23): the beam as an ANCF cable
    (r and r_x per node, Euler-Bernoulli, ``system/kinds/cable.py``), the 'nonlinear' formulation
    only. A section with I_y != I_z bends in the r1-r2 plane with I_z = int y^2 dA and needs
    ``scene.planar = 'xy'``."""
    if scene["scene"]["formulation"] != "nonlinear":
        raise InputError("bending = 'cable' is a large-deformation element: it needs "
                         "scene.formulation = 'nonlinear'", group="beam", key="bending")
    section = rectangle(scene)
    square = abs(section.iy - section.iz) <= 1e-9 * max(section.iy, section.iz)
    if not square and scene["scene"].get("planar", "off") != "xy":
        raise InputError("bending = 'cable' with a section of two bending stiffnesses "
                         f"(I_y = {section.iy:g}, I_z = {section.iz:g} m^4) bends in the r1-r2 "
                         "plane only: it needs scene.planar = 'xy'", group="beam",
                         key="bending")
    beam = scene["beam"]
    return system.cable(name, material=material_, start=start, end=end, nodes=beam["nodes"],
                        section=section, segments=beam["segments"],
                        bending_inertia=None if square else section.iz)


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
        if effect not in effects and (np.asarray(loads[key]) != 0).any():
            built.warnings.append(f"loads.{key} is set but {effect!r} is not in scene.effects: "
                                  "not applied")
