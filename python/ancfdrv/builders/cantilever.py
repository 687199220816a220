"""A beam along +r1 from the origin with its root node clamped (``cantilever.clamp``:
'section' holds r, r_y, r_z; 'full' also r_x; 'pin' r and r_z, a hinge about r3); frame A = I."""
from __future__ import annotations

from ..system import System
from .common import BuiltSystem, beam_loads, material, rectangle

CLAMPS = {"section": ("r", "r_y", "r_z"), "full": ("r", "r_x", "r_y", "r_z"), "pin": ("r", "r_z")}


def build(scene) -> BuiltSystem:
    beam = scene["beam"]
    s = System(scene["scene"]["title"], effects=scene.effects)
    built = BuiltSystem(s, ("tip", 1))
    tip = (beam["length"], 0.0, 0.0)
    b = s.beam("beam", material=material(s, scene), start=(0.0, 0.0, 0.0), end=tip,
               nodes=beam["nodes"], section=rectangle(scene), height_axis=(0.0, 1.0, 0.0),
               formulation=scene["scene"]["formulation"], bending=beam["bending"],
               segments=beam["segments"], geometric_stiffness=beam["geometric_stiffness"])
    for vector in CLAMPS[scene["cantilever"]["clamp"]]:
        s.joint(f"clamp {vector}", "fix", "ground", "beam", point=(0.0, 0.0, 0.0), vector=vector)
    beam_loads(built, scene, b, tip)
    return built
