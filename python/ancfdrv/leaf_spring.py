"""The two-leaf spring of seed 003 (Fig. 11) with the geometry of SPEC section 7: a main
leaf and a shorter lower leaf (thin plate meshes, completed element), the axle clamp, the
chassis and the shackle as ANCF reference nodes, hinges eliminated by B, and contact points
on the lower leaf's end edges searched on the main leaf.

Geometry note: the leaves are concave up (centre of curvature above), so a leaf concentric
with the main leaf (R = 2.0 m) and 0.014 m *below* it has the mid-surface radius
R + 0.014 = 2.014 m (SPEC section 7 writes 1.986 m, which would put a concentric leaf above
the main leaf); ``spring.lower_radius`` defaults to 2.014 m, so the leaves touch along the
lower leaf without gap or overlap in the assembled state.
"""
from __future__ import annotations

import numpy as np

from . import kernel
from .assembly import AssemblyModel, BodyProbe, ContactSet, LinearRelation, RigidBody
from .solvers.dynamic import CONTACT_COUNTERS
from .plate import (P_R, P_RX, PlateMesh, PlateModel, PlateProbe, arc_mesh, arc_point,
                    plate_node_dofs)


def _combine(main: PlateMesh, lower: PlateMesh) -> PlateMesh:
    """One mesh of both leaves (lower leaf's nodes and elements after the main leaf's);
    node sets prefixed 'main_' and 'lower_'."""
    shift = main.nnodes
    sets = {f"main_{k}": v for k, v in main.node_sets.items()}
    sets.update({f"lower_{k}": v + shift for k, v in lower.node_sets.items()})
    return PlateMesh(np.vstack([main.coords, lower.coords]),
                     np.vstack([main.elements, lower.elements + shift]),
                     np.concatenate([main.a, lower.a]), np.concatenate([main.b, lower.b]),
                     main.grid, sets)


def _element_grid(nx: int, ny: int, first: int = 0) -> np.ndarray:
    """(nx, ny) element ids of a structured leaf mesh (elements run along x fastest)."""
    return first + np.arange(nx * ny).reshape(ny, nx).T


def build_spring(scene) -> AssemblyModel:
    """The leaf spring scene (&spring with &leaf for the leaf pack)."""
    spring, leaf, loads, material = scene["spring"], scene["leaf"], scene["loads"], scene["material"]
    effects = scene.effects
    h, w, ny = leaf["thickness"], leaf["width"], leaf["ny"]
    main_l, main_r, main_nx = spring["main_arc_length"], spring["main_radius"], spring["main_nx"]
    low_l, low_nx = spring["lower_arc_length"], spring["lower_nx"]
    low_r = spring["lower_radius"] if spring["lower_radius"] is not None else main_r + h
    prestress = bool(leaf["prestress"])
    main = arc_mesh(main_l, main_r, w, main_nx, ny)
    lower = arc_mesh(low_l, low_r, w, low_nx, ny, z_offset=-(low_r - main_r))
    mesh = _combine(main, lower)
    reference = None
    if prestress:  # the lower leaf's stress-free shape has the free radius (seed 003)
        free = arc_mesh(low_l, leaf["free_radius"], w, low_nx, ny)
        reference = np.vstack([main.coords, free.coords])
    plates = PlateModel(mesh, h, variant=leaf["variant"], effects=effects, reference=reference,
                        density=material["density"], youngs=material["youngs_modulus"],
                        poisson=material["poisson_ratio"])
    if prestress:
        plates.counters["prestress"] += 1
    gravity = None
    if "gravity" in effects:
        gravity = np.array([0.0, 0.0, -loads["gravity"]])
        plates.add_gravity(gravity)
    # rigid bodies: chassis between the front hinge and the shackle's top; shackle vertical
    # above the rear eye, reference point at its middle
    eye, _ = arc_point(main_l / 2, main_r)
    front = eye * [-1.0, 1.0, 1.0]
    ls = spring["shackle_length"]
    top = eye + [0.0, 0.0, ls]
    chassis_at = 0.5 * (front + top)
    inertia = spring["chassis_inertia"]
    chassis = RigidBody("chassis", spring["chassis_mass"], np.diag([inertia] * 3), chassis_at,
                        planar=True)
    ms, width = spring["shackle_mass"], 0.2 * ls
    shackle = RigidBody("shackle", ms, ms / 12 * np.diag([ls**2 + h**2, ls**2 + width**2,
                                                           width**2 + h**2]),
                        eye + [0.0, 0.0, ls / 2], planar=True)
    model = AssemblyModel(plates, [chassis, shackle], gravity, effects)
    for name in CONTACT_COUNTERS:
        model.counters[name] += 0
    # axle: r and r_x of both middle node lines (eliminated)
    for prefix in ("main", "lower"):
        for node in mesh.node_sets[f"{prefix}_middle_x"]:
            for part in (P_R, P_RX):
                for dof in plate_node_dofs(int(node), part):
                    model.fix(dof, f"axle clamp ({prefix} leaf)")
    # hinges (revolute about r2): eye edges' positions tied to chassis and shackle, the
    # shackle's top to the chassis (its position becomes dependent)
    u_top = top - chassis_at
    for i in range(3):
        terms = {chassis.dof(0, i): 1.0, shackle.dof(3, i): -ls / 2}
        for k in range(3):
            if u_top[k]:
                terms[chassis.dof(1 + k, i)] = u_top[k]
        model.relations.append(LinearRelation(shackle.dof(0, i), terms, 0.0,
                                              f"shackle top hinge [{i}]"))
    for node in mesh.node_sets["main_edge_x0"]:
        model.hinge_point(plate_node_dofs(int(node)), chassis, f"front eye node {node}")
    for node in mesh.node_sets["main_edge_x1"]:
        model.hinge_point(plate_node_dofs(int(node)), shackle, f"rear eye node {node}")
    model.add_body_constraints(shackle)
    if spring["guide"] == "vertical":
        model.guide_vertically(chassis)
    else:
        model.add_body_constraints(chassis)
    # contact points on the lower leaf's end edges, searched on the main leaf
    contact, couplings = None, []
    if "contact" in effects:
        params = kernel.contact_params(spring["contact_stiffness"], spring["contact_damping"],
                                       spring["friction_coefficient"], spring["slip_velocity"],
                                       h, h, "friction" in effects)
        plates.counters["contact"] += 1
        if "friction" in effects:
            plates.counters["friction"] += 1
        lower_first = main_nx * ny
        lower_grid = _element_grid(low_nx, ny, lower_first)
        upper_grid = _element_grid(main_nx, ny)
        elements, local, names, guesses = [], [], [], []
        sizes = np.vstack([mesh.a, mesh.b])
        for edge, column, xi in (("front", 0, 0.0), ("rear", low_nx - 1, 1.0)):
            for f in np.linspace(0.0, 1.0, spring["contact_points"]):
                j = min(int(f * ny), ny - 1)
                el = lower_grid[column, j]
                elements.append(el)
                local.append([xi, f * ny - j])
                names.append(f"{edge} edge, y = {(f - 0.5) * w:+.4f} m")
                s = -low_l / 2 if xi == 0.0 else low_l / 2
                guess = np.array([(s + main_l / 2) / main_l * main_nx, f * ny])
                shape, _ = kernel.plate_shape(xi, f * ny - j, mesh.a[el], mesh.b[el])
                point = shape @ plates.e0[plates.dofs[:, el]].reshape(12, 3)
                guess, *_ = kernel.contact_projection(plates.e0, plates.dofs, sizes, upper_grid,
                                                      point, guess)
                guesses.append(guess)
                col = int(min(guess[0], main_nx - 1e-9))
                for c in range(max(col - 1, 0), min(col + 2, main_nx)):
                    for row in range(ny):
                        couplings.append((int(upper_grid[c, row]), int(el)))
        contact = ContactSet(upper_grid, np.array(elements), np.array(local, dtype=float).T,
                             params, np.array(guesses).T, names)
    model.finish(contact, sorted(set(couplings)))
    if "load_cycle" in effects:
        model.set_load_cycle(chassis.dof(0, 2), -spring["cycle_force"], spring["cycle_period"])
        plates.counters["load_cycle"] += 1
    # probes: the chassis reference point (SPEC), the leaves' rear tips at mid-width
    model.probes["chassis"] = BodyProbe(chassis)
    el, xi, eta = main.element_at(1.0, 0.5)
    model.probes["main_tip"] = PlateProbe(el, xi, eta)
    el, xi, eta = lower.element_at(1.0, 0.5)
    model.probes["lower_tip"] = PlateProbe(el + main_nx * ny, xi, eta)
    model.response = ("chassis", 2)
    return model
