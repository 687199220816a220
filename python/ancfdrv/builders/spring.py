"""The two-leaf spring of seed 003 (Fig. 11) with the geometry of SPEC section 7: a main leaf
and a shorter lower leaf (thin plate meshes), the axle clamp, the chassis and the shackle as
rigid bodies (ANCF reference nodes), hinges (spherical joints at the eye nodes, eliminated
by B), and contact points on the lower leaf's end edges searched on the main leaf.

Geometry note: the leaves are concave up (centre of curvature above), so a leaf concentric
with the main leaf (R = 2.0 m) and 0.014 m *below* it has the mid-surface radius
R + 0.014 = 2.014 m (SPEC section 7 writes 1.986 m, which would put a concentric leaf above
the main leaf); ``spring.lower_radius`` defaults to 2.014 m, so the leaves touch along the
lower leaf without gap or overlap in the assembled state.
"""
from __future__ import annotations

import numpy as np

from ..system import System
from ..system.meshes import arc_point
from .common import BuiltSystem, material


def build(scene) -> BuiltSystem:
    spring, leaf, loads = scene["spring"], scene["leaf"], scene["loads"]
    effects = scene.effects
    s = System(scene["scene"]["title"], effects=effects)
    steel = material(s, scene)
    h, w, ny = leaf["thickness"], leaf["width"], leaf["ny"]
    main_l, main_r = spring["main_arc_length"], spring["main_radius"]
    low_l = spring["lower_arc_length"]
    low_r = spring["lower_radius"] if spring["lower_radius"] is not None else main_r + h
    prestress = bool(leaf["prestress"]) and "prestress" in effects
    main = s.leaf("main", material=steel, thickness=h, width=w, arc_length=main_l, radius=main_r,
                  centre=(0.0, 0.0, 0.0), nx=spring["main_nx"], ny=ny, variant=leaf["variant"])
    lower = s.leaf("lower", material=steel, thickness=h, width=w, arc_length=low_l, radius=low_r,
                   centre=(0.0, 0.0, -(low_r - main_r)), nx=spring["lower_nx"], ny=ny,
                   variant=leaf["variant"], free_radius=leaf["free_radius"] if prestress else None)
    # chassis between the front eye and the shackle's top; the shackle vertical above the
    # rear eye, its reference point at its middle
    eye, _ = arc_point(main_l / 2, main_r)
    front = eye * [-1.0, 1.0, 1.0]
    ls = spring["shackle_length"]
    top = eye + [0.0, 0.0, ls]
    chassis_at = 0.5 * (front + top)
    vertical = spring["guide"] == "vertical"
    inertia = spring["chassis_inertia"]
    s.rigid_body("chassis", mass=spring["chassis_mass"], inertia=np.diag([inertia] * 3),
                 position=chassis_at, planar=not vertical)
    ms, width = spring["shackle_mass"], 0.2 * ls
    s.rigid_body("shackle", mass=ms, inertia=ms / 12 * np.diag([ls**2 + h**2, ls**2 + width**2,
                                                                width**2 + h**2]),
                 position=eye + [0.0, 0.0, ls / 2], planar=True)
    # axle: r and r_x of both middle node lines; with a road input the clamp's position
    # follows it along r3 (the clamp's slope stays held)
    road = road_drive(s, spring, scene)
    for body in (main, lower):
        middle = body.mesh.coords[body.mesh.node_sets["middle_x"], :3].ravel()
        if road is None:
            s.joint(f"axle {body.name} r", "fix", "ground", body.name, point=middle, vector="r")
        else:
            s.joint(f"axle {body.name} r", "prescribed", "ground", body.name, point=middle,
                    axis=(0.0, 0.0, 1.0), drive=road)
        s.joint(f"axle {body.name} r_x", "fix", "ground", body.name, point=middle, vector="r_x")
    # hinges about r2: the shackle's top on the chassis, the eye edges' nodes on the chassis
    # (front) and the shackle (rear): points of two bodies kept together, two per edge
    s.joint("shackle top", "spherical", "chassis", "shackle", point=top)
    edges = main.mesh.node_sets
    s.joint("front eye", "spherical", "chassis", "main",
            point=main.mesh.coords[edges["edge_x0"], :3].ravel())
    s.joint("rear eye", "spherical", "shackle", "main",
            point=main.mesh.coords[edges["edge_x1"], :3].ravel())
    if vertical:  # load-cycle guide: the chassis translates in the r1-r3 plane, unturned
        s.joint("guide r2", "fix", "ground", "chassis", point=chassis_at, axis=(0.0, 1.0, 0.0))
        for vector in ("r_x", "r_y", "r_z"):
            s.joint(f"guide {vector}", "fix", "ground", "chassis", point=chassis_at,
                    vector=vector)
    if "contact" in effects:
        s.contact("leaves", "main", "lower", stiffness=spring["contact_stiffness"],
                  damping=spring["contact_damping"], friction=spring["friction_coefficient"],
                  slip_speed=spring["slip_velocity"], points=spring["contact_points"])
    if "gravity" in effects:
        s.load("gravity", "gravity", vector=(0.0, 0.0, -loads["gravity"]))
    if "load_cycle" in effects:
        s.drive("cycle", "cycle", amplitude=-spring["cycle_force"],
                period=spring["cycle_period"], t0=0.0)
        s.load("cycle", "force", body="chassis", point=chassis_at, vector=(0.0, 0.0, 1.0),
               drive="cycle", effect="load_cycle")
    s.probe("chassis", "chassis", chassis_at)
    s.probe("shackle", "shackle", eye + [0.0, 0.0, ls / 2])
    s.probe("main_tip", "main", main.material_point(0.5 * main_l, 0.0))
    s.probe("lower_tip", "lower", lower.material_point(0.5 * low_l, 0.0))
    return BuiltSystem(s, ("chassis", 2))


def road_drive(s: System, spring, scene) -> str | None:
    """The vertical road input at the axle (``spring.road``): 'sine' (amplitude, frequency,
    raised smoothly over ``road_ramp`` s), 'table' (t, z rows of the CSV ``road_file``,
    linear in between; z relative to its value at t = 0), or None ('none')."""
    kind = spring["road"]
    if kind == "none":
        return None
    if kind == "sine":
        s.drive("road", "sine", amplitude=spring["road_amplitude"],
                frequency=spring["road_frequency"], ramp=spring["road_ramp"])
    else:
        s.drive("road", "table", file=scene.resolve(spring["road_file"]))
    return "road"


def settle_mode(scene) -> str:
    """The run hook of the spring: ``spring.settle`` ('none' | 'prestress' | 'gravity')
    names the start of a dynamic run after what it settles ('none', 'unloaded',
    'loaded'; :func:`ancfdrv.builders.settle_mode`)."""
    return {"none": "none", "prestress": "unloaded",
            "gravity": "loaded"}[scene["spring"]["settle"]]
