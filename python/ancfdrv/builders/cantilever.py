"""A beam along +r1 from the origin with its root node clamped (``cantilever.clamp``:
'section' holds r, r_y, r_z; 'full' also r_x; 'pin' r and r_z, a hinge about r3); frame A = I."""
from __future__ import annotations

from ..system import System
from .common import BuiltSystem, beam_loads, material, rectangle, template_cable

CLAMPS = {"section": ("r", "r_y", "r_z"), "full": ("r", "r_x", "r_y", "r_z"), "pin": ("r", "r_z")}


def build(scene) -> BuiltSystem:
    beam = scene["beam"]
    s = System(scene["scene"]["title"], effects=scene.effects)
    built = BuiltSystem(s, ("tip", 1))
    tip = (beam["length"], 0.0, 0.0)
    if beam["bending"] == "cable":
        return _cable(scene, built, tip)
    b = s.beam("beam", material=material(s, scene), start=(0.0, 0.0, 0.0), end=tip,
               nodes=beam["nodes"], section=rectangle(scene), height_axis=(0.0, 1.0, 0.0),
               formulation=scene["scene"]["formulation"], bending=beam["bending"],
               segments=beam["segments"], geometric_stiffness=beam["geometric_stiffness"],
               modes=beam["modes"])
    for vector in CLAMPS[scene["cantilever"]["clamp"]]:
        s.joint(f"clamp {vector}", "fix", "ground", "beam", point=(0.0, 0.0, 0.0), vector=vector)
    beam_loads(built, scene, b, tip)
    return built


def _cable(scene, built: BuiltSystem, tip) -> BuiltSystem:
    """``beam.bending = 'cable'`` (issue 23; formulation 'nonlinear'): the beam as an ANCF
    cable (r, r_x per node, Euler-Bernoulli). Clamps: 'pin' holds r (a spherical joint:
    with the planar reduction, the hinge about r3), 'section' and 'full' hold r and r_x (a
    weld). A section with I_y != I_z bends in the r1-r2 plane with I_z = int y^2 dA, and
    needs ``scene.planar = 'xy'``."""
    s = built.system
    c = template_cable(scene, s, "beam", material(s, scene), (0.0, 0.0, 0.0), tip)
    clamp = scene["cantilever"]["clamp"]
    s.joint(f"clamp {clamp}", "spherical" if clamp == "pin" else "weld", "ground", "beam",
            point=(0.0, 0.0, 0.0))
    beam_loads(built, scene, c, tip)
    return built
