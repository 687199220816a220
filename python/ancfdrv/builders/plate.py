"""A flat rectangular plate in the r1-r2 plane with its first corner at the origin (SPEC
section 6 for the pendulum); supports: a spherical joint at the corner (0, 0, 0), a
clamped edge x = 0, or simple supports; probes 'corner' (the corner opposite the origin) and
'centre'."""
from __future__ import annotations

import numpy as np

from ..system import System
from .common import BuiltSystem, material


def build(scene) -> BuiltSystem:
    plate, loads, effects = scene["plate"], scene["loads"], scene.effects
    s = System(scene["scene"]["title"], effects=effects)
    lx, ly = plate["length_x"], plate["length_y"]
    p = s.plate("plate", material=material(s, scene), thickness=plate["thickness"],
                corner=(0.0, 0.0, 0.0), edge_x=(lx, 0.0, 0.0), edge_y=(0.0, ly, 0.0),
                nx=plate["nx"], ny=plate["ny"], variant=plate["variant"])
    sets = p.mesh.node_sets
    position = p.mesh.coords[:, :3]

    def at(nodes) -> np.ndarray:
        return position[np.asarray(nodes)].ravel()
    support = plate["support"]
    e1, e2, e3 = np.eye(3)
    if support == "corner_spherical":
        s.joint("corner", "spherical", "ground", "plate", point=(0.0, 0.0, 0.0))
    elif support == "clamped_edge":
        edge = sets["edge_x0"]
        s.joint("clamped edge r", "fix", "ground", "plate", point=at(edge), vector="r")
        s.joint("clamped edge r_y", "fix", "ground", "plate", point=at(edge), vector="r_y")
        s.joint("clamped edge slope", "fix", "ground", "plate", point=at(edge), vector="r_x",
                axis=e3)
    else:  # simply supported: w = 0 on the boundary, in-plane rigid motion removed
        s.joint("support w", "fix", "ground", "plate", point=at(sets["boundary"]), axis=e3)
        s.joint("support dw/dx", "fix", "ground", "plate", vector="r_x", axis=e3,
                point=at(np.union1d(sets["edge_y0"], sets["edge_y1"])))
        s.joint("support dw/dy", "fix", "ground", "plate", vector="r_y", axis=e3,
                point=at(np.union1d(sets["edge_x0"], sets["edge_x1"])))
        s.joint("in-plane pin x", "fix", "ground", "plate", point=at(sets["corner_00"]), axis=e1)
        s.joint("in-plane pin y", "fix", "ground", "plate", point=at(sets["corner_00"]), axis=e2)
        s.joint("in-plane roller", "fix", "ground", "plate", point=at(sets["corner_10"]),
                axis=e2)
    if "gravity" in effects:
        s.load("gravity", "gravity", vector=(0.0, 0.0, -loads["gravity"]))
    if "pressure" in effects:
        s.load("pressure", "pressure", body="plate", value=loads["pressure"])
    s.probe("corner", "plate", (lx, ly, 0.0))
    s.probe("centre", "plate", (0.5 * lx, 0.5 * ly, 0.0))
    # sweeps compare the displacement along r3: of the corner (pendulum), else the centre
    response = ("corner", 2) if support == "corner_spherical" else ("centre", 2)
    return BuiltSystem(s, response)


def closed_form_error(scene, row: dict) -> float | None:
    """The sweep hook of the plate: a simply supported plate under pressure alone, the
    relative error of a static case's centre deflection (``row['response']``) against
    Navier's series (Timoshenko, Theory of Plates and Shells: 0.00406 q a^4 / D for the
    square plate), which it records in ``row['response_closed_form']``; None for other
    supports or loads."""
    from ..reference.analytic import navier_plate_centre_deflection
    plate, material = scene["plate"], scene["material"]
    if plate["support"] != "simply_supported" or set(scene.effects) != {"pressure"}:
        return None
    reference = -navier_plate_centre_deflection(
        scene["loads"]["pressure"], plate["length_x"], plate["length_y"],
        material["youngs_modulus"], material["poisson_ratio"], plate["thickness"])
    row["response_closed_form"] = reference
    return abs(row["response"] - reference) / max(abs(reference), 1e-300)
