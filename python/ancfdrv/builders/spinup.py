"""The spin-up beam of Simo & Vu-Quoc (REFERENCES.md): the root section clamped to a hub
turning about r3 with the prescribed angle phi(t) (joint 'hub'); the beam's frame is the
hub's, A(t) = R(phi(t)), in which the probe deflections are resolved."""
from __future__ import annotations

from ..system import System
from .common import BuiltSystem, beam_loads, material, rectangle


def build(scene) -> BuiltSystem:
    beam, spin = scene["beam"], scene["spinup"]
    s = System(scene["scene"]["title"], effects=scene.effects)
    built = BuiltSystem(s, ("tip", 1))
    drive = s.drive("hub", "spinup", omega=spin["omega"], period=spin["period"], start=0.0)
    tip = (beam["length"], 0.0, 0.0)
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
