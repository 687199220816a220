"""The :class:`System`: a user's structure composed of named materials, bodies, drives,
joints, loads, contact pairs and probes, in a Python script or from a namelist (each group
one call). Names are unique per kind of item; the body name 'ground' is reserved. A joint,
load, contact or probe naming an unknown body (or drive, or material) is an
:class:`~ancfdrv.errors.InputError` naming the item. :meth:`System.assemble` turns it into
the model the solvers run (``ancfdrv.system.assembly``).

Example (a cantilever with a tip mass)::

    from ancfdrv import System, Rectangle
    s = System("cantilever")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(2, 0, 0), nodes=9,
           section=Rectangle(0.05, 0.1), height_axis=(0, 1, 0), formulation="nonlinear")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -9.81, 0))
    s.load("payload", "point_mass", body="arm", point=(2, 0, 0), mass=10.0)
    s.probe("tip", "arm", (2, 0, 0))
    model = s.assemble()
"""
from __future__ import annotations

from typing import Iterable

import numpy as np

from ..errors import InputError
from .bodies import Beam, Body, Ground, Leaf, Material, Plate, RigidBody
from .contact import ContactPair
from .drives import DRIVE_TYPES, Drive, Table
from .joints import Joint
from .loads import LOAD_TYPES, Load
from .probes import Probe
from .sections import Section

#: effects an item may belong to, with the default of each load type (SPEC section 8)
LOAD_EFFECTS = {"gravity": "gravity", "force": "point_loads", "moment": "point_loads",
                "point_mass": "tip_mass", "pressure": "pressure"}


def _points(value) -> list[np.ndarray]:
    """One point (3 numbers) or several (a multiple of 3)."""
    a = np.asarray(value, dtype=float).ravel()
    if a.size == 0 or a.size % 3:
        raise ValueError(f"expected x,y,z (or several points: a multiple of 3 numbers), got "
                         f"{a.size} numbers")
    return [a[i:i + 3].copy() for i in range(0, a.size, 3)]


class System:
    """A mechanical system under construction (see the module documentation)."""

    def __init__(self, title: str = "", *, effects: Iterable[str] | None = None) -> None:
        self.title = title
        self.effects = None if effects is None else tuple(effects)
        self.materials: dict[str, Material] = {}
        self.bodies: dict[str, Body] = {}
        self.drives: dict[str, Drive] = {}
        self.joints: dict[str, Joint] = {}
        self.loads: dict[str, Load] = {}
        self.contacts: dict[str, ContactPair] = {}
        self.probes: dict[str, Probe] = {}
        self.ground = Ground()
        self.notes: list[str] = []

    # -- look-ups -------------------------------------------------------------------------
    @staticmethod
    def _new_name(name: str, table: dict, what: str) -> str:
        if not isinstance(name, str) or not name.strip():
            raise InputError(f"{what}: a name is required")
        name = name.strip()
        if name in table:
            raise InputError(f"{what} {name!r} is defined twice")
        return name

    def body(self, name: str | Body, *, used_by: str = "") -> Body:
        """The body of that name ('ground' is the ground)."""
        if isinstance(name, Body):
            return name
        if name == "ground":
            return self.ground
        if name not in self.bodies:
            known = ", ".join(["ground", *self.bodies]) or "none"
            raise InputError(f"{used_by + ': ' if used_by else ''}unknown body {name!r} "
                             f"(bodies: {known})")
        return self.bodies[name]

    def _material(self, name: str | Material, used_by: str) -> Material:
        if isinstance(name, Material):
            return name
        if name not in self.materials:
            raise InputError(f"{used_by}: unknown material {name!r} (materials: "
                             f"{', '.join(self.materials) or 'none'})")
        return self.materials[name]

    def _drive(self, name: str | Drive | None, used_by: str) -> Drive | None:
        if name is None or isinstance(name, Drive):
            return name
        if name not in self.drives:
            raise InputError(f"{used_by}: unknown drive {name!r} (drives: "
                             f"{', '.join(self.drives) or 'none'})")
        return self.drives[name]

    # -- items ----------------------------------------------------------------------------
    def material(self, name: str, *, youngs_modulus: float, density: float,
                 poisson_ratio: float = 0.0, damping_time: float = 0.0) -> Material:
        name = self._new_name(name, self.materials, "material")
        self.materials[name] = Material(name, youngs_modulus, density, poisson_ratio,
                                        damping_time)
        return self.materials[name]

    def _add_body(self, body: Body) -> Body:
        self.bodies[body.name] = body
        return body

    def beam(self, name: str, *, material: str | Material, start, end, nodes: int,
             section: Section | None = None, height_axis=None, formulation: str = "ffr",
             bending: str = "continuum", segments=None, frame_drive: str | Drive | None = None,
             frame_axis=(0.0, 0.0, 1.0), frame_pivot=None) -> Beam:
        """An ANCF beam (:class:`~.bodies.Beam`)."""
        name = self._body_name(name)
        where = f"beam {name!r}"
        return self._add_body(Beam(name, self._material(material, where), start, end, nodes,
                                   section, height_axis=height_axis, formulation=formulation,
                                   bending=bending, segments=segments,
                                   frame_drive=self._drive(frame_drive, where),
                                   frame_axis=frame_axis, frame_pivot=frame_pivot))

    def plate(self, name: str, *, material: str | Material, thickness: float, corner, edge_x,
              edge_y, nx: int, ny: int, variant: str = "completed") -> Plate:
        """A flat thin plate (:class:`~.bodies.Plate`)."""
        name = self._body_name(name)
        return self._add_body(Plate(name, self._material(material, f"plate {name!r}"),
                                    thickness, corner, edge_x, edge_y, nx, ny, variant=variant))

    def leaf(self, name: str, *, material: str | Material, thickness: float, width: float,
             arc_length: float, radius: float, centre, nx: int, ny: int,
             variant: str = "completed", free_radius: float | None = None) -> Leaf:
        """A curved leaf (:class:`~.bodies.Leaf`)."""
        name = self._body_name(name)
        return self._add_body(Leaf(name, self._material(material, f"leaf {name!r}"), thickness,
                                   width, arc_length, radius, centre, nx, ny, variant=variant,
                                   free_radius=free_radius))

    def rigid_body(self, name: str, *, mass: float, inertia, position, planar: bool = False,
                   plane_normal=(0.0, 1.0, 0.0)) -> RigidBody:
        """A rigid body as an ANCF reference node (:class:`~.bodies.RigidBody`)."""
        name = self._body_name(name)
        return self._add_body(RigidBody(name, mass, inertia, position, planar=planar,
                                        plane_normal=plane_normal))

    def _body_name(self, name: str) -> str:
        if name == "ground":
            raise InputError("the body name 'ground' is reserved")
        return self._new_name(name, self.bodies, "body")

    def drive(self, name: str, type: str, **params) -> Drive:
        """A drive (``ancfdrv.system.drives``): type 'constant' (value), 'luffing' (omega,
        t_start, t_brake, sweep, start), 'spinup' (omega, period, start), 'cycle'
        (amplitude, period, t0), 'sine' (amplitude, frequency, phase, offset, t0, ramp),
        'table' (times, values, or file = CSV path)."""
        name = self._new_name(name, self.drives, "drive")
        where = f"drive {name!r}"
        if type not in DRIVE_TYPES:
            raise InputError(f"{where}: type {type!r} must be one of {', '.join(DRIVE_TYPES)}")
        try:
            if type == "table" and "file" in params:
                extra = set(params) - {"file"}
                if extra:
                    raise TypeError(f"unexpected {sorted(extra)}")
                drive = Table.from_csv(name, params["file"])
            elif type == "table":
                drive = Table(name, tuple(params.pop("times")), tuple(params.pop("values")),
                              **params)
            elif type == "constant":
                drive = DRIVE_TYPES[type](name, params.pop("value", 0.0), **params)
            else:
                drive = DRIVE_TYPES[type](name, **params)
        except (TypeError, KeyError) as exc:
            raise InputError(f"{where}: parameters of type {type!r}: {exc}") from None
        drive.check()
        self.drives[name] = drive
        return drive

    def joint(self, name: str, type: str, body1: str | Body, body2: str | Body, *, point=None,
              axis=None, drive: str | Drive | None = None, point1=None, point2=None,
              pivot=None, vector: str = "r") -> Joint:
        """A joint (``ancfdrv.system.joints``); ``point`` may list several points (the joint
        then acts at each)."""
        name = self._new_name(name, self.joints, "joint")
        where = f"joint {name!r}"
        try:
            points = [] if point is None else _points(point)
            p1 = None if point1 is None else _points(point1)[0]
            p2 = None if point2 is None else _points(point2)[0]
            pv = None if pivot is None else _points(pivot)[0]
        except ValueError as exc:
            raise InputError(f"{where}: {exc}") from None
        joint = Joint(name, type, self.body(body1, used_by=where), self.body(body2, used_by=where),
                      points, axis, self._drive(drive, where), p1, p2, pv, vector)
        self.joints[name] = joint
        return joint

    def load(self, name: str, type: str, *, body: str | Body | None = None, point=None,
             vector=None, mass: float | None = None, value: float | None = None,
             drive: str | Drive | None = None, effect: str | None = None) -> Load:
        """A load (``ancfdrv.system.loads``): 'gravity' (vector), 'force' (body, point,
        vector, drive), 'moment' (body, point, vector), 'point_mass' (body, point, mass),
        'pressure' (body, value); ``effect`` defaults by type (SPEC section 8)."""
        name = self._new_name(name, self.loads, "load")
        where = f"load {name!r}"
        if type not in LOAD_TYPES:
            raise InputError(f"{where}: type {type!r} must be one of {', '.join(LOAD_TYPES)}")
        effect = effect or LOAD_EFFECTS[type]
        needs = {"gravity": ("vector",), "force": ("body", "point", "vector"),
                 "moment": ("body", "point", "vector"), "point_mass": ("body", "point", "mass"),
                 "pressure": ("body", "value")}[type]
        given = dict(body=body, point=point, vector=vector, mass=mass, value=value)
        missing = [k for k in needs if given[k] is None]
        if missing:
            raise InputError(f"{where}: type {type!r} needs {', '.join(missing)}")
        extra = [k for k, v in given.items() if v is not None and k not in needs]
        if drive is not None and type != "force":
            extra.append("drive")
        if extra:
            raise InputError(f"{where}: type {type!r} does not take {', '.join(extra)}")
        target = None if body is None else self.body(body, used_by=where)
        if target is not None and isinstance(target, Ground):
            raise InputError(f"{where}: a load on the ground does nothing")
        cls = LOAD_TYPES[type]
        if type == "gravity":
            load = cls(name, vector, effect)
        elif type == "force":
            load = cls(name, target, point, vector, self._drive(drive, where), effect)
        elif type == "moment":
            load = cls(name, target, point, vector, effect)
        elif type == "point_mass":
            load = cls(name, target, point, float(mass), effect)
        else:
            load = cls(name, target, float(value), effect)
        if target is not None and point is not None:
            target.locate(load.point, node=False, what=where)  # a material point of the body
        self.loads[name] = load
        return load

    def contact(self, name: str, body1: str | Body, body2: str | Body, *, stiffness: float,
                damping: float = 0.0, friction: float = 0.0, slip_speed: float = 0.08,
                points: int = 3) -> ContactPair:
        """A contact pair (``ancfdrv.system.contact``)."""
        name = self._new_name(name, self.contacts, "contact")
        where = f"contact {name!r}"
        pair = ContactPair(name, self.body(body1, used_by=where), self.body(body2, used_by=where),
                           stiffness, damping, friction, slip_speed, points)
        self.contacts[name] = pair
        return pair

    def probe(self, name: str, body: str | Body, point) -> Probe:
        """A probe at a material point of a body."""
        name = self._new_name(name, self.probes, "probe")
        where = f"probe {name!r}"
        target = self.body(body, used_by=where)
        if isinstance(target, Ground):
            raise InputError(f"{where}: the ground does not move")
        try:
            p = _points(point)
        except ValueError as exc:
            raise InputError(f"{where}: {exc}") from None
        target.locate(p[0], node=False, what=where)
        self.probes[name] = Probe(name, target, p[0])
        return self.probes[name]

    # -- the model ------------------------------------------------------------------------
    def effects_used(self) -> set[str]:
        """Every effect an item of the system belongs to."""
        out = {load.effect for load in self.loads.values()}
        if self.contacts:
            out.add("contact")
            if any(c.friction > 0 for c in self.contacts.values()):
                out.add("friction")
        if any(isinstance(b, Leaf) and b.prestressed for b in self.bodies.values()):
            out.add("prestress")
        return out

    def assemble(self, *, effects: Iterable[str] | None = None, linear_joints: str = "auto",
                 check_frames: bool = True):
        """The model of this system (``ancfdrv.system.assembly.assemble``): only the effects
        listed (default: the system's own list, else all it uses) are computed. An 'ffr'
        beam whose floating frame nothing holds is refused (InputError); with
        ``check_frames=False`` it is assembled for checks of the joint equations alone, and
        the solvers refuse to run it."""
        from .assembly import assemble
        chosen = effects if effects is not None else self.effects
        return assemble(self, tuple(chosen) if chosen is not None else None,
                        linear_joints=linear_joints, check_frames=check_frames)

    # -- modal analysis and linear buckling (SPEC section 10) ----------------------------
    def modes(self, n: int = 10, *, effects: Iterable[str] | None = None,
              linear_joints: str = "auto", **options):
        """The ``n`` lowest modes about the static equilibrium of the system's loads
        (:func:`ancfdrv.solvers.modal.modal_analysis`; ``options`` are its keywords:
        solver, tol, load_steps, rigid_tol, spin_rate, spin_axis, spin_centre, ...).
        Returns a :class:`~ancfdrv.solvers.modal.ModalResult` (frequency in Hz ascending,
        rigid-body modes at 0; mass-normalized shapes; damping_ratio with damping on)."""
        from ..solvers.modal import modal_analysis
        model = self.assemble(effects=effects, linear_joints=linear_joints)
        try:
            return modal_analysis(model, n, **options)
        finally:
            model.close()

    def buckling(self, n: int = 3, *, fixed_loads: Iterable[str] = (),
                 effects: Iterable[str] | None = None, linear_joints: str = "auto",
                 **options):
        """The ``n`` lowest positive load factors of the system's loads about their static
        state (:func:`ancfdrv.solvers.buckling.buckling_analysis`): the loads (by name, or
        all loads of an effect) in ``fixed_loads`` keep their value, the others are
        multiplied. ``options``: method ('nonlinear' | 'linear'), solver, tol, load_steps,
        rtol, ... Returns a :class:`~ancfdrv.solvers.buckling.BucklingResult`."""
        from ..solvers.buckling import buckling_analysis
        fixed = tuple(fixed_loads)
        known = set(self.loads) | {load.effect for load in self.loads.values()}
        unknown = [name for name in fixed if name not in known]
        if unknown:
            raise InputError(f"buckling: fixed_loads names unknown load(s) or effect(s) "
                             f"{', '.join(map(repr, unknown))} (loads: "
                             f"{', '.join(self.loads) or 'none'})")
        model = self.assemble(effects=effects, linear_joints=linear_joints)
        base = model
        if fixed:
            every = self.loads
            try:
                self.loads = {k: v for k, v in every.items() if k in fixed or v.effect in fixed}
                base = self.assemble(effects=effects, linear_joints=linear_joints)
            finally:
                self.loads = every
        try:
            return buckling_analysis(model, base, n, fixed_loads=fixed, **options)
        finally:
            model.close()
            if base is not model:
                base.close()
