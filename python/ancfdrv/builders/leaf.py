"""A curved leaf (circular arc, concave up) in its assembled shape; with the effect
'prestress' its stress-free reference is the arc of free_radius with the same middle line.
Support: the axle clamp (r and r_x of the middle node line) or none. Probes 'end' (middle of
the edge at r1 > 0) and 'middle'."""
from __future__ import annotations


from ..system import System
from .common import BuiltSystem, material


def build(scene) -> BuiltSystem:
    leaf, loads, effects = scene["leaf"], scene["loads"], scene.effects
    s = System(scene["scene"]["title"], effects=effects)
    free = leaf["free_radius"] if "prestress" in effects else None
    body = s.leaf("leaf", material=material(s, scene), thickness=leaf["thickness"],
                  width=leaf["width"], arc_length=leaf["arc_length"], radius=leaf["radius"],
                  centre=(0.0, 0.0, 0.0), nx=leaf["nx"], ny=leaf["ny"], variant=leaf["variant"],
                  free_radius=free)
    if leaf["support"] == "middle_clamp":
        middle = body.mesh.coords[body.mesh.node_sets["middle_x"], :3].ravel()
        s.joint("axle clamp r", "fix", "ground", "leaf", point=middle, vector="r")
        s.joint("axle clamp r_x", "fix", "ground", "leaf", point=middle, vector="r_x")
    if "gravity" in effects:
        s.load("gravity", "gravity", vector=(0.0, 0.0, -loads["gravity"]))
    s.probe("end", "leaf", body.material_point(0.5 * leaf["arc_length"], 0.0))
    s.probe("middle", "leaf", body.material_point(0.0, 0.0))
    return BuiltSystem(s, ("end", 2))



