"""Force elements between two bodies (SPEC 8.1; kernel module
``fortran/src/elements/force_elements.f90``): a spring-damper, a bushing, a compliant
hydraulic cylinder and a torsion spring. The family's whole Python side: the items a
:class:`~.system.System` holds, their assembly into slots (material points and direction
vectors of the two bodies, affine in the full coordinates, the ground's as constants) and
their reactions.

``spring_damper``  body1, point1, body2, point2; force along the line p2 - p1, tension
                   positive: f = preload + stiffness (L - free_length) + damping L', or
                   f = table(L - free_length) + damping L' (a force-deflection table through
                   (deflections, forces), interpolated 'linear', 'cubic' or 'pchip' as the
                   drive tables are, constant beyond its ends). free_length defaults to the
                   distance at t = 0. Potential: preload d + stiffness d^2 / 2 (d = L - L0),
                   or the table's integral from 0 to d.
``bushing``        body1, body2 and one point on both; diagonal stiffness and damping: three
                   translational (stiffness, damping: N/m, N s/m) along body1's direction
                   vectors at the point and three rotational (rotational_stiffness,
                   rotational_damping: N m/rad, N m s/rad) about them. Direction vectors: a
                   rigid body's axes r_x, r_y, r_z (the global axes at t = 0), a beam's slope
                   r_x and section directors r_y, r_z at the point, the ground's global axes
                   (plates and cables carry fewer than three: refused). The rotation measure:
                   theta_i = (g_k . h_j - g_j . h_k) / 2 for (i, j, k) cyclic, with g body1's
                   vectors and h body2's mapped so that h = g at t = 0: the relative rotation
                   vector's components on body1's axes to first order (small relative
                   rotations), exactly zero when both bodies turn together by any angle.
``cylinder``       body1, point1, body2, point2 and a drive: the nominal length l(t) of a rigid
                   actuator in series with the oil column's stiffness and damping, f = k (L -
                   l(t)) + c (L' - l'(t)) along the line (tension positive); the rigid,
                   massless cylinder is the 'distance' joint with a drive.
``torsion``        body1, body2, one point on both and an axis: a linear torsion spring, the
                   moment -(rotational_stiffness theta + rotational_damping theta') about
                   the axis on body2 (N m/rad, N m s/rad; one value each), theta the relative
                   rotation of body2 about the axis carried by body1: atan2(g2 . h1, g1 . h1)
                   with g1, g2 body1's unit vectors normal to the axis at t = 0 and h1 body2's
                   equal to g1 at t = 0 (exact for any angle in (-pi, pi) while the relative
                   turn is about the axis, e.g. on a revolute joint; theta = 0 at t = 0).
                   Direction vectors as for the bushing.

Energy: the potentials enter the strain energy; the dissipated power c m'^2 is a lost work
counted with the material damping's (energy row ``work_material_damping``), and a
cylinder's drive puts in the power -f l' (``work_drive``, with the driven joints').
Reactions (``/static/reactions/<name>``, ``/dynamic/reactions/<name>``): the force and
moment body1 exerts on body2 (global axes) and ``axial`` (the line's tension; 0 for a
bushing). A system without force elements hands the kernel none and computes what it did
before.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import field

import numpy as np

from ...records import record
from ... import kernel
from ...errors import InputError
from ...io.schema import Key, name_key, non_negative, one_of, positive, short_repr, vector3
from ..bodies import Body, points_of
from ..drives import Drive, Table
from ..expressions import Vec3, combination
from ..registry import Kind, checked_values, register

#: kinds of the kernel module force_elements (fe_*)
FE_SPRING_DAMPER, FE_BUSHING, FE_CYLINDER, FE_TORSION = 1, 2, 3, 4
FORCE_ELEMENT_KINDS = {"spring_damper": FE_SPRING_DAMPER, "bushing": FE_BUSHING,
                       "cylinder": FE_CYLINDER, "torsion": FE_TORSION}
#: the parameters each type takes besides name, type, body1, body2: (required, optional)
#: (a spring_damper needs stiffness or the table deflections and forces)
FORCE_ELEMENT_PARAMETERS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "spring_damper": (("point1", "point2"), ("stiffness", "damping", "free_length", "preload",
                                             "deflections", "forces", "interpolation")),
    "bushing": (("point", "stiffness"), ("damping", "rotational_stiffness",
                                         "rotational_damping")),
    "cylinder": (("point1", "point2", "drive", "stiffness"), ("damping",)),
    "torsion": (("point", "axis", "rotational_stiffness"), ("rotational_damping",)),
}
FORCE_ELEMENT_MEANING = {
    "spring_damper": "along the line point1-point2, tension positive: preload + stiffness "
                     "(L - free_length) + damping L', or the table's force of L - free_length "
                     "+ damping L'",
    "bushing": "at point: stiffness/damping along and rotational_* about body1's three axes "
               "(small relative rotations)",
    "cylinder": "a rigid actuator of driven length l(t) in series with the oil column: "
                "stiffness (L - l) + damping (L' - l')",
    "torsion": "at point: the moment -(rotational_stiffness theta + rotational_damping "
               "theta') about axis, theta body2's turn about it relative to body1",
}


@record
class ForceElement:
    """A force element as the user gave it (see the module documentation); vector
    parameters of a bushing have 3 entries, the others 1."""

    name: str
    type: str
    body1: Body
    body2: Body
    point1: np.ndarray
    point2: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    rotational_stiffness: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotational_damping: np.ndarray = field(default_factory=lambda: np.zeros(3))
    free_length: float | None = None
    preload: float = 0.0
    table: Table | None = None
    drive: Drive | None = None
    axis: np.ndarray | None = None

    @property
    def kind(self) -> int:
        return FORCE_ELEMENT_KINDS[self.type]


@record(eq=False, repr=False)
class ForceElementInfo:
    """A force element as assembled: kernel kind, 0-based drive (-1: none), parameters,
    table (kind 0: none), and its slots (Vec3 on the full coordinates)."""

    name: str
    kind: int
    drive: int
    params: np.ndarray
    table_kind: int
    table: np.ndarray
    slots: list[Vec3]

    @property
    def damped(self) -> bool:
        """Whether it has a damper (its force depends on the rates)."""
        damping = self.params[6:12] if self.kind == FE_BUSHING else self.params[1:2]
        return bool(np.any(damping != 0.0))

    def dofs(self) -> np.ndarray:
        """Every full coordinate its slots touch (one block of the sparse pattern)."""
        firsts = sorted({d for slot in self.slots for d in slot.terms})
        return np.array([d + i for d in firsts for i in range(3)], dtype=np.int64)


def _where(fe: ForceElement) -> str:
    return f"force element {fe.name!r}"


def _directions(body: Body, at, what: str) -> list[Vec3]:
    basis = body.basis(at)
    if len(basis) != 3:
        raise InputError(f"{what}: a bushing or a torsion needs three direction vectors at "
                         "its point; "
                         f"{type(body).__name__.lower()} {body.name!r} carries {len(basis)} "
                         "(use a beam, a rigid body or the ground)")
    return basis


def assemble_force_element(fe: ForceElement, q0: np.ndarray, drive_index: dict) -> \
        ForceElementInfo:
    """The kernel's data of one force element at the configuration q0 of t = 0."""
    what = _where(fe)
    at1 = fe.body1.locate(fe.point1, node=False, what=what)
    at2 = fe.body2.locate(fe.point2, node=False, what=what)
    p1, p2 = fe.body1.position(at1), fe.body2.position(at2)
    slots = [p1, p2]
    table_kind, table = 0, np.zeros(0)
    drive = -1
    if fe.type == "bushing":
        g, b = _directions(fe.body1, at1, what), _directions(fe.body2, at2, what)
        d1 = np.column_stack([v.value(q0) for v in g])
        d2 = np.column_stack([v.value(q0) for v in b])
        if abs(np.linalg.det(d2)) < 1e-9 * np.prod(np.linalg.norm(d2, axis=0)):
            raise InputError(f"{what}: the direction vectors of {fe.body2.name!r} at the point "
                             "are not independent")
        mapping = np.linalg.solve(d2, d1)       # h_i = sum_j b_j R_ji equals g_i at t = 0
        h = [combination(b, mapping[:, i]) for i in range(3)]
        slots += list(g) + h
        params = np.concatenate([fe.stiffness, fe.rotational_stiffness, fe.damping,
                                 fe.rotational_damping])
    elif fe.type == "torsion":
        g, b = _directions(fe.body1, at1, what), _directions(fe.body2, at2, what)
        axis = fe.axis / np.linalg.norm(fe.axis)
        u1 = np.cross(axis, np.eye(3)[int(np.argmin(np.abs(axis)))])
        u1 /= np.linalg.norm(u1)
        u2 = np.cross(axis, u1)                  # u1 x u2 = axis
        d1 = np.column_stack([v.value(q0) for v in g])
        d2 = np.column_stack([v.value(q0) for v in b])
        for d, body in ((d1, fe.body1), (d2, fe.body2)):
            if abs(np.linalg.det(d)) < 1e-9 * np.prod(np.linalg.norm(d, axis=0)):
                raise InputError(f"{what}: the direction vectors of {body.name!r} at the "
                                 "point are not independent")
        # vectors carried by the bodies that equal u1, u2 (body1) and u1 (body2) at t = 0
        slots += [combination(g, np.linalg.solve(d1, u1)),
                  combination(g, np.linalg.solve(d1, u2)), combination(b, np.linalg.solve(d2, u1))]
        params = np.array([fe.rotational_stiffness[0], fe.rotational_damping[0]])
    else:
        length0 = float(np.linalg.norm(p2.value(q0) - p1.value(q0)))
        if length0 <= 1e-12 * max(1.0, float(np.abs(p1.value(q0)).max())):
            raise InputError(f"{what}: point1 and point2 coincide (the line of action is "
                             "undefined)")
        if fe.type == "spring_damper":
            free = length0 if fe.free_length is None else fe.free_length
            params = np.array([fe.stiffness[0], fe.damping[0], free, fe.preload])
            if fe.table is not None:
                table_kind, table = fe.table.kind, np.array(fe.table.params(), dtype=float)
        else:
            params = np.array([fe.stiffness[0], fe.damping[0]])
            drive = drive_index[id(fe.drive)]
    return ForceElementInfo(fe.name, fe.kind, drive, params.astype(float), table_kind, table,
                            slots)


def assemble_force_elements(items, q0: np.ndarray, drive_index: dict, counters: Counter) -> \
        tuple[list[ForceElementInfo], list[np.ndarray]]:
    """The force elements' kernel data and their pattern blocks (one per element)."""
    out = [assemble_force_element(fe, q0, drive_index) for fe in items]
    if out:
        counters["force_elements"] += len(out)
    return out, [info.dofs() for info in out if len(info.dofs())]


def tangent_positions(info: ForceElementInfo, pattern) -> np.ndarray:
    """The positions (0-based; -1: absent) in the full pattern's values of the element's
    tangent entries, in the kernel's loop order: slot s, slot w, term k of s, term m of w,
    component i, component j (row: k's coordinate + i, column: m's + j)."""
    terms = [sorted(slot.terms.items()) for slot in info.slots]
    rows, cols = [], []
    offsets = np.arange(3)
    for first in terms:
        for second in terms:
            if not first or not second:
                continue
            a = np.array([d for d, _ in first])[:, None, None, None] + offsets[None, None, :, None]
            b = np.array([d for d, _ in second])[None, :, None, None] + offsets[None, None, None, :]
            a, b = np.broadcast_arrays(a, b)
            rows.append(a.ravel())
            cols.append(b.ravel())
    if not rows:
        return np.zeros(0, dtype=np.int64)
    return pattern.positions(np.concatenate(rows), np.concatenate(cols))


def kernel_layout(infos: list[ForceElementInfo], pattern=None) -> dict:
    """The packed arrays of system_set_force_elements (0-based; kernel.py adds 1), with the
    tangent's positions in the full ``pattern`` (Pattern) when given."""
    param_ptr, table_ptr, slot_first, term_ptr = [0], [0], [], [0]
    params, table, consts, dofs, coefs = [], [], [], [], []
    for info in infos:
        params += info.params.tolist()
        table += info.table.tolist()
        param_ptr.append(len(params))
        table_ptr.append(len(table))
        slot_first.append(len(consts))
        for slot in info.slots:
            consts.append(np.asarray(slot.const, dtype=float))
            for d, c in sorted(slot.terms.items()):
                dofs.append(d)
                coefs.append(c)
            term_ptr.append(len(dofs))
    positions = [tangent_positions(info, pattern) if pattern is not None
                 else np.zeros(0, dtype=np.int64) for info in infos]
    position_ptr = np.concatenate([[0], np.cumsum([len(x) for x in positions])])
    return dict(positions=np.concatenate(positions) if positions else np.zeros(0, np.int64),
                position_ptr=position_ptr,
                kinds=[i.kind for i in infos], drives=[i.drive for i in infos],
                table_kinds=[i.table_kind for i in infos], param_ptr=param_ptr,
                params=params, table_ptr=table_ptr, table=table, slot_first=slot_first,
                slot_const=np.array(consts, dtype=float).reshape(-1, 3), term_ptr=term_ptr,
                term_dof=dofs, term_coef=coefs)


def slot_values(info: ForceElementInfo, q_full: np.ndarray) -> np.ndarray:
    """The element's slot vectors (3, ns) at the full coordinates (tests, checks)."""
    return np.column_stack([s.value(q_full) for s in info.slots])


def evaluate(info: ForceElementInfo, x: np.ndarray, xd: np.ndarray | None = None,
             length: float = 0.0, length_rate: float = 0.0) -> dict:
    """One element at slot values x (3, ns) and rates xd through the kernel
    (force_elements.force_element_eval): force (3, ns), stiffness and damping (3, ns, 3, ns),
    energy, dissipation, drive_power, reaction (7)."""
    return kernel.force_element(info.kind, info.params, info.table_kind, info.table, x,
                                np.zeros_like(x) if xd is None else xd, length, length_rate)


__all__ = ["ForceElement", "ForceElementInfo", "FORCE_ELEMENT_KINDS", "FORCE_ELEMENT_PARAMETERS",
           "FORCE_ELEMENT_MEANING",
           "assemble_force_elements", "kernel_layout", "slot_values", "evaluate"]


KEYS: dict[str, Key] = {
    "name": name_key(),
    "type": Key("str", check=one_of("spring_damper", "bushing", "cylinder", "torsion"),
                doc="'spring_damper' (along the line point1-point2), 'bushing' (6 diagonal "
                "stiffnesses and dampings at point), 'cylinder' (a driven length with "
                "oil-column stiffness and damping in series), 'torsion' (a torsion spring "
                "about axis at point)"),
    "body1": Key("str", "ground", doc="first body (or 'ground')"),
    "body2": Key("str", doc="second body (or 'ground')"),
    "point1": Key("floats", None, vector3, "'spring_damper', 'cylinder': point on body1 (m)"),
    "point2": Key("floats", None, vector3, "'spring_damper', 'cylinder': point on body2 (m)"),
    "point": Key("floats", None, vector3, "'bushing', 'torsion': the point on both bodies "
                 "(m)"),
    "axis": Key("floats", None, vector3, "'torsion': the axis of the relative rotation "
                "(any length; carried by body1)"),
    "stiffness": Key("floats", None, non_negative, "stiffness (N/m): one value; a "
                     "'bushing' three, along body1's axes at the point; 0 or within "
                     "[1e-3, 1e12] N/m (scene.bounds: a softer spring carries nothing a "
                     "structure weighs, a stiffer one is a joint)"),
    "damping": Key("floats", None, non_negative, "damping (N s/m): one value; a 'bushing' "
                   "three (default 0; at most 1e10, scene.bounds)"),
    "rotational_stiffness": Key("floats", None, non_negative, "'bushing': stiffness about "
                                "body1's three axes; 'torsion': one, about axis (N m/rad; "
                                "default 0; 0 or within [1e-6, 1e12], scene.bounds)"),
    "rotational_damping": Key("floats", None, non_negative, "'bushing': damping about "
                              "body1's three axes; 'torsion': one, about axis (N m s/rad; "
                              "default 0; at most 1e10, scene.bounds)"),
    "free_length": Key("float", None, positive, "'spring_damper': length at which the "
                       "force is the preload (m; default: the distance at t = 0)"),
    "preload": Key("float", None, doc="'spring_damper': force at the free length (N, "
                   "tension positive; default 0)"),
    "deflections": Key("floats", None, doc="'spring_damper' instead of stiffness and "
                       "preload: a force-deflection table's deflections L - free_length "
                       "(m, increasing)"),
    "forces": Key("floats", None, doc="'spring_damper': the table's forces (N, tension "
                  "positive; constant beyond the ends)"),
    "interpolation": Key("str", None, one_of("linear", "cubic", "pchip"),
                         "'spring_damper': the table's interpolation, as a drive table's "
                         "(default 'linear')"),
    "drive": Key("str", None, doc="'cylinder': the drive of the nominal length l(t) (m)"),
}


def build(system, v: dict) -> ForceElement:
    """A force element from the values of ``System.add('force_element', ...)``."""
    type = v["type"]
    name = system._new_name(v["name"], system.force_elements, "force element")
    where = f"force element {name!r}"
    if name in system.joints:
        raise InputError(f"{where}: a joint has that name (reactions are stored by name)")
    if not isinstance(type, str) or type not in FORCE_ELEMENT_PARAMETERS:
        raise InputError(f"{where}: type {short_repr(type)} must be one of "
                         f"{', '.join(FORCE_ELEMENT_PARAMETERS)}")
    if v["body2"] is None:
        raise InputError(f"{where}: body2 is required")
    v = checked_values(KIND, f"force_element[{name}]", v)
    required, optional = FORCE_ELEMENT_PARAMETERS[type]
    given = {k: v.get(k) for k in ("point1", "point2", "point", "stiffness", "damping",
                               "rotational_stiffness", "rotational_damping",
                               "free_length", "preload", "deflections", "forces",
                               "interpolation", "axis")}
    given["drive"] = v.get("drive")
    missing = [k for k in required if given[k] is None]
    if type == "spring_damper" and given["stiffness"] is None and given["forces"] is None:
        missing.append("stiffness (or deflections and forces)")
    if missing:
        raise InputError(f"{where}: type {type!r} needs {', '.join(missing)}")
    extra = [k for k, x in given.items() if x is not None and k not in required + optional]
    if extra:
        raise InputError(f"{where}: type {type!r} does not take {', '.join(extra)}")
    size = 3 if type == "bushing" else 1

    def values(key: str) -> np.ndarray:
        x = given.get(key)
        if x is None:
            return np.zeros(size)
        x = np.asarray(x, dtype=float).ravel()
        if x.size != size:
            raise InputError(f"{where}: {key} takes {size} value{'s' * (size > 1)} for "
                             f"type {type!r}, got {x.size}")
        return x
    first, second = system.body(v["body1"], used_by=where), system.body(v["body2"], used_by=where)
    if first is second:
        raise InputError(f"{where}: body1 and body2 are the same body")
    table = None
    if given["deflections"] is not None or given["forces"] is not None:
        if given["stiffness"] is not None or given["preload"] is not None:
            raise InputError(f"{where}: a force-deflection table replaces stiffness and "
                             "preload: give one or the other")
        if given["deflections"] is None or given["forces"] is None:
            raise InputError(f"{where}: a force-deflection table needs deflections and "
                             "forces")
        table = Table(f"{name} (force table)", tuple(given["deflections"]),
                      tuple(given["forces"]), given["interpolation"] or "linear")
        try:
            table.check()
        except InputError as exc:
            raise InputError(f"{where}: {str(exc).split(': ', 1)[-1]}".replace(
                "times", "deflections")) from None
    elif v.get("interpolation") is not None:
        raise InputError(f"{where}: interpolation applies to a force-deflection table")
    axis = None
    if type == "torsion":
        axis = np.asarray(given["axis"], dtype=float).ravel()
        if axis.size != 3 or not np.linalg.norm(axis) > 0.0:
            raise InputError(f"{where}: axis must be a nonzero 3-vector")
    if type in ("bushing", "torsion"):
        p1 = p2 = points_of(given["point"])[0]
    else:
        p1, p2 = points_of(given["point1"])[0], points_of(given["point2"])[0]
    at1 = first.locate(p1, node=False, what=where)   # material points of the bodies
    at2 = second.locate(p2, node=False, what=where)
    if type in ("bushing", "torsion"):
        for body, at in ((first, at1), (second, at2)):
            if len(body.basis(at)) != 3:
                raise InputError(f"{where}: a {type} needs three direction vectors at "
                                 f"its point; {body.__class__.__name__.lower()} "
                                 f"{body.name!r} carries {len(body.basis(at))} (use a "
                                 "beam, a rigid body or the ground)")
    fe = ForceElement(name, type, first, second, p1, p2, values("stiffness"),
                      values("damping"), values("rotational_stiffness"),
                      values("rotational_damping"), given["free_length"],
                      float(given["preload"] or 0.0), table,
                      system._drive(given["drive"], where) if type == "cylinder" else None, axis)
    system.force_elements[name] = fe
    return fe


KIND = register(Kind(
    group="force_element", body_class=ForceElement, keys=KEYS, build=build,
    api="force_element", table="force_elements", word="force element",
    objects=("body1", "body2", "drive")))
