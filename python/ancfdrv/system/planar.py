"""Planar reduction (issue 23): a scene whose motion stays in a coordinate plane solves
only the in-plane coordinates.

Setting: ``System(planar=...)`` / ``&scene planar = ...``:

* ``'off'`` (the default): every coordinate is solved (the history of a scene without the
  setting is bitwise the one it had before);
* ``'xy'``, ``'yz'``, ``'zx'``: declared; the motion stays in planes parallel to that
  coordinate plane (normal z, x, y). Data that would leave the plane are refused
  (:class:`~ancfdrv.errors.InputError` naming the item, :func:`planar_problems`);
* ``'auto'``: the first of the normals z, x, y for which :func:`planar_problems` finds
  nothing; none: the run stays 3D and a note says why (the first item that leaves each
  plane).

What keeps the motion in the plane with normal e_j (every item is checked, each active load
of the listed effects):

* nonlinear beams (continuum, cubic) and cables: the axis lies in a plane normal to e_j
  (every node has the same r_j, r_x normal to e_j), and a beam's section has one director
  along e_j (height or width axis; the sections are symmetric about it). FFR beams are not
  reduced (their constant iteration matrix turns whole nodal 3-vectors with the frame);
* rigid bodies: the products of inertia that couple a turn about e_j with the other two
  vanish (I_jk = 0 for k != j); a rigid body already ``planar`` has the same normal;
* plates and leaves are not reduced (refused: their membrane/bending split has no planar
  form here);
* joints: 'revolute', 'arm', 'hub' and a rotating 'prescribed' turn about e_j; a
  translating 'prescribed' moves normal to e_j; 'weld', 'spherical', 'distance', 'fix'
  hold any in-plane motion; other types are refused. Every joint point lies in the plane
  of the bodies it joins (an off-plane reaction would twist the body out of it);
* loads: gravity and forces have no component along e_j and act in their body's plane,
  moments are along e_j, point masses sit in their body's plane; pressures belong to
  plates (refused);
* contacts act between plates (refused); the System API has no initial velocities, so
  every body starts at rest or with the in-plane motion of its drives.

By the mirror symmetry about the plane, such a system's solution has, at every node,
r_j, r_x,j and the in-plane director's j-component at their initial values, and the normal
director's two in-plane components zero (each kind's rule: the ``plane``, ``planar_problems``
and ``planar_fixed`` of its :class:`~.registry.Kind`).
These are linear equations that the assembly eliminates like fixed coordinates
(q = B e + q0, :mod:`.patterns`): a beam node keeps 7 unknowns of 12, a cable node 4 of 6,
a rigid body 6 of 12 (its orthonormality then drops the equations the fixes satisfy).
The /model attributes ``planar`` (the plane, '' when off), ``nplanar_fixed`` (coordinates
the planar reduction eliminated) and ``ndof`` (unknowns solved besides multipliers) say
what was solved.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from .bodies import along_axis
from .expressions import Scalar
from .joints import LinearEquation
from .registry import kind_of

#: the settings and each declared plane's normal axis (0, 1, 2 = x, y, z)
PLANES = {"xy": 2, "yz": 0, "zx": 1}
SETTINGS = ("off", "auto") + tuple(PLANES)
_AUTO_ORDER = (2, 0, 1)
_NAME = {2: "xy", 0: "yz", 1: "zx"}
_TOL = 1e-9


def check_setting(value) -> str:
    """The setting (InputError naming scene.planar otherwise)."""
    if value not in SETTINGS:
        raise InputError(f"planar must be one of {SETTINGS}, got {value!r}", group="scene",
                         key="planar")
    return value


def _along(v: np.ndarray, j: int) -> bool:
    """v is parallel to e_j."""
    return along_axis(v, j, _TOL)


def _normal_to(v: np.ndarray, j: int) -> bool:
    v = np.asarray(v, dtype=float)
    return abs(float(v[j])) <= _TOL * max(1.0, float(np.linalg.norm(v)))


def body_plane(body, j: int) -> float | None:
    """The j-coordinate of a body's plane (None: the ground, anything; a kind without a
    planar rule, which is not reduced and refused as such by :func:`planar_problems`)."""
    kind = kind_of(body)
    return None if kind is None or kind.plane is None else kind.plane(body, j)


def planar_problems(system, j: int, loads=None) -> list[str]:
    """What in ``system`` leaves planes normal to e_j (empty: the motion stays in them).
    ``loads``: the loads to check (default: all of the system's)."""
    out: list[str] = []
    plane = "xyz"[j]
    scale = max([1.0] + [float(np.abs(b.coordinates()).max(initial=0.0))
                         for b in system.bodies.values()])
    tol = _TOL * scale

    def off_plane(body, point, what: str) -> None:
        c = body_plane(body, j)
        if c is not None and point is not None and abs(float(point[j]) - c) > tol:
            out.append(f"{what}: its point {list(np.asarray(point, float))} is off the plane "
                       f"{plane} = {c:g} of body {body.name!r}")

    for body in system.bodies.values():
        where = f"body {body.name!r}"
        kind = kind_of(body)
        if kind is not None and kind.planar_problems is not None:
            out += [f"{where}: {text}" for text in kind.planar_problems(body, j, tol)]
        elif kind is not None:
            word = kind.group
            out.append(f"{where}: {'leaves' if word == 'leaf' else word + 's'} cannot be "
                       "reduced to a plane (the planar reduction covers beams, cables and "
                       f"rigid bodies): remove scene.planar or the {word} {body.name!r}")
    for joint in system.joints.values():
        where = f"joint {joint.name!r}"
        turning = joint.type in ("revolute", "arm", "hub") or (
            joint.type == "prescribed" and joint.pivot is not None)
        if turning and (joint.axis is None or not _along(joint.axis, j)):
            out.append(f"{where}: its axis {joint.axis if joint.axis is None else list(joint.axis)}"
                       f" is not along {plane}")
        elif joint.type == "prescribed" and joint.pivot is None and \
                (joint.axis is None or not _normal_to(joint.axis, j)):
            out.append(f"{where}: it translates along {list(joint.axis)}, out of the plane")
        elif joint.type not in ("revolute", "arm", "hub", "prescribed", "weld", "spherical",
                                "distance", "fix"):
            out.append(f"{where}: type {joint.type!r} is not covered by the planar reduction")
        for point in joint.points:
            off_plane(joint.body1, point, where)
            off_plane(joint.body2, point, where)
        if joint.type == "distance":
            off_plane(joint.body1, joint.point1, where)
            off_plane(joint.body2, joint.point2, where)
    for load in (system.loads.values() if loads is None else loads):
        where = f"load {load.name!r}"
        kind = type(load).__name__
        if kind in ("Gravity", "PointForce") and not _normal_to(load.vector, j):
            out.append(f"{where}: its vector {list(load.vector)} has a component along {plane}")
        if kind == "DeadMoment" and not _along(load.vector, j):
            out.append(f"{where}: its moment {list(load.vector)} is not along {plane}")
        if kind == "Pressure":
            out.append(f"{where}: a pressure acts on a plate, which is not reduced")
        if kind in ("PointForce", "PointMass"):
            off_plane(load.body, load.point, where)
    for contact in system.contacts.values():
        out.append(f"contact {contact.name!r}: contacts act between plates, which are not "
                   "reduced")
    return out


def resolve(system, setting: str, loads=None) -> tuple[int | None, list[str]]:
    """The plane's normal axis for ``setting`` (None: no reduction) and notes. A declared
    plane whose data leave it is refused (InputError naming the first item)."""
    check_setting(setting)
    if setting == "off":
        return None, []
    if setting != "auto":
        j = PLANES[setting]
        problems = planar_problems(system, j, loads)
        if problems:
            raise InputError(f"planar = '{setting}': {problems[0]}"
                             + (f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""),
                             group="scene", key="planar")
        return j, [f"planar reduction: motion in the {setting} plane (declared)"]
    why = []
    for j in _AUTO_ORDER:
        problems = planar_problems(system, j, loads)
        if not problems:
            return j, [f"planar reduction: motion in the {_NAME[j]} plane (detected)"]
        why.append(f"{_NAME[j]}: {problems[0]}")
    return None, ["planar = 'auto': no plane found, every coordinate solved (" +
                  "; ".join(why) + ")"]


def _fix(dof: int, q0: np.ndarray, name: str) -> LinearEquation:
    return LinearEquation(Scalar({dof: 1.0}, -float(q0[dof])), name, [dof])


def planar_equations(system, j: int, q0: np.ndarray) -> list[LinearEquation]:
    """The coordinates that stay at their initial values in planar motion with normal e_j
    (see the module documentation), as linear equations to eliminate."""
    out: list[LinearEquation] = []
    for body in system.bodies.values():
        kind = kind_of(body)
        if kind is not None and kind.planar_fixed is not None:
            out += [_fix(dof, q0, label) for dof, label in kind.planar_fixed(body, j, q0)]
    return out


__all__ = ["PLANES", "SETTINGS", "check_setting", "planar_problems", "resolve",
           "planar_equations"]
