"""The spin-up beam of Simo & Vu-Quoc (J. Appl. Mech. 53, 1986): the root section clamped to a hub
turning about r3 with the prescribed angle phi(t) (joint 'hub'); the beam's frame is the
hub's, A(t) = R(phi(t)), in which the probe deflections are resolved. ``beam.bending =
'cable'`` (formulation 'nonlinear'; issue 23) builds the beam as an ANCF cable whose root
position and slope r_x turn with the hub (Exudyn's clamp of ANCFCable2D to a hub)."""
from __future__ import annotations

import numpy as np

from ..system import System
from .common import BuiltSystem, beam_loads, material, rectangle, template_cable


def build(scene) -> BuiltSystem:
    beam, spin = scene["beam"], scene["spinup"]
    s = System(scene["scene"]["title"], effects=scene.effects)
    built = BuiltSystem(s, ("tip", 1))
    drive = s.drive("hub", "spinup", omega=spin["omega"], period=spin["period"], start=0.0)
    tip = (beam["length"], 0.0, 0.0)
    if beam["bending"] == "cable":
        return _cable(scene, built, drive, tip)
    b = s.beam("beam", material=material(s, scene), start=(0.0, 0.0, 0.0), end=tip,
               nodes=beam["nodes"], section=rectangle(scene), height_axis=(0.0, 1.0, 0.0),
               formulation=scene["scene"]["formulation"], bending=beam["bending"],
               segments=beam["segments"], frame_drive=drive, frame_axis=(0.0, 0.0, 1.0),
               frame_pivot=(0.0, 0.0, 0.0), geometric_stiffness=beam["geometric_stiffness"],
               modes=beam["modes"])
    s.joint("hub", "hub", "ground", "beam", point=(0.0, 0.0, 0.0), pivot=(0.0, 0.0, 0.0),
            axis=(0.0, 0.0, 1.0), drive=drive)
    beam_loads(built, scene, b, tip)
    return built


def _cable(scene, built: BuiltSystem, drive, tip) -> BuiltSystem:
    """The spin-up beam as an ANCF cable (r, r_x per node, Euler-Bernoulli; the section
    must have I_y = I_z unless the scene is planar 'xy', where it bends with I_z): the hub
    joint holds the root's r and r_x on the turning hub, the cable carries the hub's frame
    R(phi(t)) for its probe's deflection."""
    s = built.system
    c = template_cable(scene, s, "beam", material(s, scene), (0.0, 0.0, 0.0), tip)
    c.frame_drive, c.frame_axis, c.frame_pivot = drive, np.array([0.0, 0.0, 1.0]), np.zeros(3)
    c.orientation = np.eye(3)   # the frame's axes at phi = 0: along the cable, r2, r3
    s.joint("hub", "hub", "ground", "beam", point=(0.0, 0.0, 0.0), pivot=(0.0, 0.0, 0.0),
            axis=(0.0, 0.0, 1.0), drive=drive)
    beam_loads(built, scene, c, tip)
    return built
