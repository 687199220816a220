"""The crane boom of seed 000 with the supports of eqs. 30-36 (SPEC section 5).

Frame A = R(phi) about the pivot O at the origin; rigid configuration: A1 = R(phi)(0, H, 0),
axis R(phi)(1, 0, 0), section height along R(phi)(0, 1, 0). A1 hangs on the massless arm O-A1
(joint 'arm': eqs. 30-33), A2 (the end of the first segment) is driven on its circle
(joint 'prescribed': eqs. 34-36) by the luffing profile or held at the angle.
"""
from __future__ import annotations

import numpy as np

from ..history import luffing_stage_bounds
from ..errors import InputError
from ..system import System
from ..system.bodies import rotation_about
from .common import BuiltSystem, beam_loads, material, rectangle, template_cable


def build(scene) -> BuiltSystem:
    boom, beam, loads = scene["boom"], scene["beam"], scene["loads"]
    effects = scene.effects
    s = System(scene["scene"]["title"], effects=effects)
    built = BuiltSystem(s, ("tip", 1))
    steel = material(s, scene)
    phi = np.radians(boom["angle_deg"])
    height_h = boom["pivot_offset"]
    if scene["scene"]["analysis"] in ("dynamic", "static+dynamic") and boom["omega"] > 0:
        sweep = np.radians(boom["angle_end_deg"] - boom["angle_deg"])
        drive = s.drive("luffing", "luffing", omega=boom["omega"] * np.sign(sweep),
                        t_start=boom["t_start"], t_brake=boom["t_brake"], sweep=sweep, start=phi)
    else:
        drive = s.drive("angle", "constant", value=phi)
    turn = rotation_about((0.0, 0.0, 1.0), phi)
    a1 = turn @ np.array([0.0, height_h, 0.0])
    tangent, height = turn @ np.array([1.0, 0.0, 0.0]), turn @ np.array([0.0, 1.0, 0.0])
    tip = a1 + beam["length"] * tangent
    if beam["bending"] == "cable":
        if beam["modes"]:
            raise InputError("beam 'boom': modes = {} reduces an 'ffr' beam; the cable "
                             "(bending = 'cable') is a large-deformation body".format(
                                 beam["modes"]), file=str(scene.path), group="beam",
                             key="modes")
        return _cable_boom(scene, built, steel, drive, a1, tangent, height, tip)
    b = s.beam("boom", material=steel, start=a1, end=tip, nodes=beam["nodes"],
               section=rectangle(scene), height_axis=height,
               formulation=scene["scene"]["formulation"], bending=beam["bending"],
               segments=beam["segments"], frame_drive=drive, frame_axis=(0.0, 0.0, 1.0),
               frame_pivot=(0.0, 0.0, 0.0), geometric_stiffness=beam["geometric_stiffness"],
               modes=beam["modes"])
    s.joint("A1", "arm", "ground", "boom", point=a1, pivot=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0))
    a2 = a1 + beam["segments"][0] * tangent
    s.joint("A2", "prescribed", "ground", "boom", point=a2, pivot=(0.0, 0.0, 0.0),
            axis=(0.0, 0.0, 1.0), drive=drive)
    beam_loads(built, scene, b, tip)
    if "bending_moment" in effects and loads["moment"] != 0.0:
        s.load("moment", "moment", body="boom", point=a2, vector=(0.0, 0.0, loads["moment"]),
               effect="bending_moment")
    return built


def stage_bounds(scene) -> dict[str, tuple[float, float]] | None:
    """The run hook of the boom: the bounds of the luffing stages (acceleration, constant
    speed, braking, after), over which the run summarizes the tip's transverse deflection
    (None when the boom does not luff)."""
    boom = scene["boom"]
    if boom["omega"] <= 0:
        return None
    sweep = np.radians(boom["angle_end_deg"] - boom["angle_deg"])
    return luffing_stage_bounds(boom["omega"], boom["t_start"], boom["t_brake"], sweep,
                                scene["solver"]["t_end"])


def closed_form_error(scene, row: dict) -> float:
    """The sweep hook of the boom: the relative error of a static case's tip sag
    (``row['tip_transverse']``) against the boom's closed form (shear included), which it
    records in ``row['tip_transverse_closed_form']``."""
    from ..reference.analytic import boom_static_tip_deflection
    effects, loads = scene.effects, scene["loads"]
    beam, material = scene["beam"], scene["material"]
    _, reference = boom_static_tip_deflection(
        scene["boom"]["angle_deg"], loads["tip_mass"] if "tip_mass" in effects else 0.0,
        length=beam["length"], a=beam["segments"][0], H=scene["boom"]["pivot_offset"],
        width=beam["width"], height=beam["height"], youngs=material["youngs_modulus"],
        density=material["density"], poisson=material["poisson_ratio"],
        gravity=loads["gravity"] if "gravity" in effects else 0.0,
        moment=loads["moment"] if "bending_moment" in effects else 0.0, shear=True)
    row["tip_transverse_closed_form"] = reference
    return abs(row["tip_transverse"] - reference) / max(abs(reference), 1e-300)


def _cable_boom(scene, built: BuiltSystem, steel, drive, a1, tangent, height, tip
                ) -> BuiltSystem:
    """``beam.bending = 'cable'`` (issue 23): the boom as an ANCF cable (r and r_x per node,
    Euler-Bernoulli, EA and EI = E w h^3 / 12 of the section; ``system/kinds/cable.py``), the
    'nonlinear' formulation only. A1 hangs on the arm with the slope r_x normal to it (the
    section along the arm), A2 is driven on its circle, the moment M_B acts on the slope at
    A2 (the section turns with the axis). The cable carries the boom's frame R(phi(t)) for
    its probe's deflection, as the beam does."""
    s, beam, loads, effects = built.system, scene["beam"], scene["loads"], scene.effects
    c = template_cable(scene, s, "boom", steel, a1, tip)
    c.frame_drive, c.frame_axis, c.frame_pivot = drive, np.array([0.0, 0.0, 1.0]), np.zeros(3)
    c.orientation = np.column_stack([tangent, height, np.cross(tangent, height)])
    s.joint("A1", "arm", "ground", "boom", point=a1, pivot=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0))
    a2 = a1 + beam["segments"][0] * tangent
    s.joint("A2", "prescribed", "ground", "boom", point=a2, pivot=(0.0, 0.0, 0.0),
            axis=(0.0, 0.0, 1.0), drive=drive)
    beam_loads(built, scene, c, tip)
    if "bending_moment" in effects and loads["moment"] != 0.0:
        s.load("moment", "moment", body="boom", point=a2, vector=(0.0, 0.0, loads["moment"]),
               effect="bending_moment")
    return built
