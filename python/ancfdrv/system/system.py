"""The :class:`System`: a user's structure composed of named materials, bodies, drives,
joints, loads, contact pairs, force elements (spring-dampers, bushings, compliant
cylinders) and probes, in a Python script or from a namelist (each group one call). Names are unique per kind of item; the body name 'ground' is reserved. A joint,
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
    res = s.static()                      # or s.simulate(t_end=1.0, dt=1e-3)
    res.deflection["tip"], res.counters   # by name (ancfdrv.results.Results)
    res.save("results/cantilever.h5")     # the file `ancf run` writes; ancfdrv.open reads it
    model = s.assemble()                  # the model alone, for the solvers' own API
"""
from __future__ import annotations

import copy
import inspect
import re
from typing import Any, Callable, Iterable

import numpy as np

from .. import _lazy
from ..errors import InputError
from ..io import validate
from ..io.schema import (EFFECTS_AVAILABLE, REQUIRED, check_call, plain_value,
                         short_repr, title_problem)
from . import kinds as _kinds  # noqa: F401  (registers the kinds)
from .bodies import Body, Ground, Material, points_of
from .contact import ContactPair
from .drives import DRIVE_TYPES, Drive, Table
from .ffr_checks import ffr_speed_warnings
from .kinds.force_element import ForceElement
from .joints import Joint
from .loads import LOAD_TYPES, Load
from .probes import Probe
from .planar import check_setting as check_planar
from .registry import kind, kind_of, kinds
from .sections import Section

#: effects an item may belong to, with the default of each load type (SPEC section 8)
LOAD_EFFECTS = {"gravity": "gravity", "force": "point_loads", "moment": "point_loads",
                "point_mass": "tip_mass", "pressure": "pressure"}
#: the parameters each load type needs (besides name, type, effect; 'force' also takes a
#: drive), as :meth:`System.load` checks them (and docs/scenes.md lists them)
LOAD_PARAMETERS = {"gravity": ("vector",), "force": ("body", "point", "vector"),
                   "moment": ("body", "point", "vector"), "point_mass": ("body", "point", "mass"),
                   "pressure": ("body", "value")}


#: a control character (ord < 32) in a name
_CONTROL = re.compile("[\x00-\x1f]")


def _api(method):
    """A System method of the API door: whatever a value the checks did not foresee makes
    numpy or a constructor raise (TypeError, ValueError, ...) becomes an InputError naming
    the call and the item, so that the API raises only the documented exceptions."""
    import functools

    @functools.wraps(method)
    def call(self, *args, **kwargs):
        try:
            return method(self, *args, **kwargs)
        except (TypeError, ValueError, ZeroDivisionError, OverflowError,
                FloatingPointError) as exc:
            item = args[0] if args and isinstance(args[0], str) else ""
            label = f"{method.__name__}[{item}]" if item else method.__name__
            text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise InputError(f"{text[:200]}", group=label) from None
        except MemoryError:
            raise InputError("not enough memory to build this item: use a coarser mesh",
                             group=method.__name__) from None
    return call


#: the annotation of a namelist key's value in the typed methods' signatures, by Key.kind
_KEY_ANNOTATIONS = {"float": "float", "int": "int", "str": "str", "bool": "bool",
                    "floats": "float | Sequence[float]", "strs": "Sequence[str]"}
#: what the Python API also takes, besides a name, for a key a kind lists in Kind.objects
_OBJECT_ANNOTATIONS = {"material": "str | Material", "section": "str | Section",
                       "drive": "str | Drive", "frame_drive": "str | Drive",
                       "body1": "str | Body", "body2": "str | Body"}


def _fill(line: str, width: int = 88, indent: str = "  ") -> str:
    """``line`` broken at spaces into lines of at most ``width`` characters (a word longer
    than that alone on its line), the continuation lines indented: what
    ``textwrap.fill(line, width, subsequent_indent=indent)`` gives, except that a word is
    never split at a hyphen, at a tenth of its cost (textwrap was 85 % of the making of the
    typed methods' ~90 key lines, at every import of the system)."""
    out: list[str] = []
    current = ""
    for word in line.split():
        if current and len(current) + 1 + len(word) > width:
            out.append(current)
            current = indent + word
        else:
            current = f"{current} {word}" if current else word
    out.append(current)
    return "\n".join(out)


def _typed(group: str):
    """Makes a System method the typed door of a registered kind: a thin wrapper over
    ``System.add(group, ...)`` whose signature (``__signature__``: what ``help`` and IDEs
    show) and docstring are made from the kind's keys and API keywords (``Kind.keys``,
    ``Kind.api_keys``), so a key added to the kind is a keyword of its method. The method's
    own parameters (those the API takes positionally) come first, as written; the other keys
    follow as keyword-only, required where the key is, with the default the call gets (None
    where the builder chooses: an object key's, a scene-default key's)."""
    found = kind(group)
    if found is None:
        raise ValueError(f"no kind {group!r} is registered")

    def make(method):
        if method.__name__ != found.api:
            raise ValueError(f"kind {group!r} names {found.api!r} as its API entry, not "
                             f"{method.__name__!r}")
        own = inspect.signature(method)
        params = [p for p in own.parameters.values() if p.kind is not p.VAR_KEYWORD]
        taken = {p.name for p in params}
        lines = []
        for k, key in found.keys.items():
            text = _OBJECT_ANNOTATIONS.get(k, _KEY_ANNOTATIONS[key.kind]) \
                if k in found.objects else _KEY_ANNOTATIONS[key.kind]
            required = key.default is REQUIRED and k not in found.scene_defaults
            default = inspect.Parameter.empty if required else \
                None if k in found.objects or k in found.scene_defaults else key.default
            if default is None:
                text += " | None"
            if k not in taken:
                params.append(inspect.Parameter(k, inspect.Parameter.KEYWORD_ONLY,
                                                default=default, annotation=text))
            lines.append(f"- ``{k}`` ({text}; "
                         f"{'required' if required else f'default {default!r}'}): {key.doc}")
        for k in found.api_keys:
            params.append(inspect.Parameter(k, inspect.Parameter.KEYWORD_ONLY, default=None))
            lines.append(f"- ``{k}`` (default None): the Python API's own keyword (above)")
        method.__signature__ = own.replace(parameters=params)
        method.__doc__ = "\n".join([
            inspect.cleandoc(method.__doc__ or ""), "",
            f"Keywords (the keys of &{group}, docs/scenes.md; an unknown one is refused):", "",
            *(_fill(line) for line in lines)])
        return method
    return make


class System:
    """A mechanical system under construction (see the module documentation)."""

    def __init__(self, title: str = "", *, effects: Iterable[str] | None = None,
                 bounds: str = "check", planar: str = "off") -> None:
        if not isinstance(title, str):
            raise InputError(f"the title must be a string, got {short_repr(title)}",
                             group="scene", key="title")
        problem = title_problem(title)
        if problem:
            raise InputError(f"the title {problem}", group="scene", key="title")
        self.title = title
        self.effects = None if effects is None else check_effects(effects)
        if bounds not in ("check", "off"):
            raise InputError(f"bounds must be 'check' or 'off', got {short_repr(bounds)}",
                             group="scene", key="bounds")
        #: 'check': drives and loads within validate.PHYSICAL_BOUNDS at assembly; 'off'
        self.bounds = bounds
        #: planar reduction ('off', 'auto', 'xy', 'yz', 'zx'; :mod:`.planar`)
        self.planar = check_planar(planar)
        self.materials: dict[str, Material] = {}
        self.bodies: dict[str, Body] = {}
        self.drives: dict[str, Drive] = {}
        self.joints: dict[str, Joint] = {}
        self.loads: dict[str, Load] = {}
        self.contacts: dict[str, ContactPair] = {}
        self.probes: dict[str, Probe] = {}
        self.force_elements: dict[str, ForceElement] = {}
        self.ground = Ground()
        self.notes: list[str] = []

    # -- look-ups -------------------------------------------------------------------------
    @staticmethod
    def _new_name(name: str, table: dict, what: str) -> str:
        if not isinstance(name, str) or not name.strip():
            raise InputError(f"{what}: a name is required")
        name = name.strip()
        # probe names become HDF5 dataset names: the general scenes' name rule; other
        # items only must not hold control characters (builders use names like 'dw/dx')
        problem = validate.check_name(name) if what == "probe" else \
            ("must not contain control characters" if _CONTROL.search(name) else None)
        if problem:
            raise InputError(f"{what} name {short_repr(name)} {problem}")
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
    @_api
    def material(self, name: str, *, youngs_modulus: float, density: float,
                 poisson_ratio: float = 0.0, damping_time: float = 0.0) -> Material:
        name = self._new_name(name, self.materials, "material")
        v = check_call("material", f"material[{name}]", dict(
            youngs_modulus=youngs_modulus, density=density, poisson_ratio=poisson_ratio,
            damping_time=damping_time))
        youngs_modulus, density = v["youngs_modulus"], v["density"]
        poisson_ratio, damping_time = v["poisson_ratio"], v["damping_time"]
        self.materials[name] = Material(name, youngs_modulus, density, poisson_ratio,
                                        damping_time)
        return self.materials[name]

    def _add_body(self, body: Body) -> Body:
        self.bodies[body.name] = body
        return body

    def add(self, group: str, **values: Any) -> Any:
        """One item of a registered kind (:mod:`.registry`; 'beam', 'cable', 'plate',
        'leaf', 'rigid_body', 'force_element'): the keys of its namelist group (docs/scenes.md,
        the defaults of the omitted ones) checked with the namelist's rules and messages, the
        item built and added. ``System.beam(...)`` is ``System.add('beam', ...)`` with the
        section as a Section object or as the namelist's keys (``section='box', width=...``)."""
        found = kind(group) if isinstance(group, str) else None
        if found is None:
            raise InputError(f"add: unknown group {short_repr(group)} (groups: "
                             f"{', '.join(k.group for k in kinds())})")
        name = values.get("name")
        label = f"{found.api}[{name}]" if isinstance(name, str) and name else found.api
        unknown = sorted(set(values) - set(found.keys) - set(found.api_keys))
        if unknown:
            raise InputError(f"unknown key {', '.join(map(repr, unknown))} (the keys of "
                             f"&{group}: {', '.join(found.keys)})", group=label)
        missing = [k for k, key in found.keys.items() if key.default is REQUIRED and
                   values.get(k) is None and k not in found.scene_defaults]
        if missing:
            raise InputError(f"{', '.join(missing)} {'is' if len(missing) == 1 else 'are'} "
                             "required", group=label)
        # (a key the API may give as an object, e.g. a section, keeps the body's own default)
        given = {k: copy.copy(key.default) for k, key in found.keys.items()
                 if key.default is not REQUIRED and k not in found.objects}
        given.update(values)
        try:
            return found.build(self, given)
        except (TypeError, ValueError, ZeroDivisionError, OverflowError,
                FloatingPointError) as exc:
            text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise InputError(f"{text[:200]}", group=label) from None
        except MemoryError:
            raise InputError("not enough memory to build this item: use a coarser mesh",
                             group=found.api) from None

    @_api
    @_typed("beam")
    def beam(self, name: str, **values: Any) -> Body:
        """An ANCF beam (:class:`~.kinds.beam.Beam`): ``System.add('beam', name=name,
        ...)``. The section is a Section object (default a 0.1 m square) or the namelist's
        form (``section='box', width=..., height=..., wall=...``);
        ``geometric_stiffness=True`` gives an 'ffr' beam the geometric stiffness of its
        current axial force (P-delta); ``modes=N`` (N > 0) runs its dynamics as the modal
        reduction with N modes; ``formulation`` defaults to 'ffr'."""
        return self.add("beam", name=name, **values)

    @_api
    @_typed("cable")
    def cable(self, name: str, **values: Any) -> Body:
        """An ANCF cable (:class:`~.kinds.cable.Cable`: r and r_x per node, Euler-Bernoulli):
        ``System.add('cable', name=name, ...)``. ``tension_only=True`` makes it a rope that
        goes slack instead of carrying compression; ``bending_stiffness`` (N m^2) replaces E
        times the section's I; ``segments``: lengths between fixed nodes, each split equally
        (as a beam's); ``bending_inertia`` (m^4, the Python API's own keyword): the inertia
        of a section with I_y != I_z about the axis a cable kept in a plane bends about (the
        system must then be planar)."""
        return self.add("cable", name=name, **values)

    @_api
    @_typed("plate")
    def plate(self, name: str, **values: Any) -> Body:
        """A flat thin plate (:class:`~.kinds.plate.Plate`): ``System.add('plate',
        name=name, ...)``."""
        return self.add("plate", name=name, **values)

    @_api
    @_typed("leaf")
    def leaf(self, name: str, **values: Any) -> Body:
        """A curved leaf (:class:`~.kinds.plate.Leaf`): ``System.add('leaf', name=name,
        ...)``."""
        return self.add("leaf", name=name, **values)

    @_api
    @_typed("rigid_body")
    def rigid_body(self, name: str, **values: Any) -> Body:
        """A rigid body as an ANCF reference node (:class:`~.kinds.rigid_body.RigidBody`):
        ``System.add('rigid_body', name=name, ...)``."""
        return self.add("rigid_body", name=name, **values)

    def _body_name(self, name: str) -> str:
        if name == "ground":
            raise InputError("the body name 'ground' is reserved")
        return self._new_name(name, self.bodies, "body")

    def _check_size(self, part: "validate.Part") -> None:
        """The memory estimate of the bodies so far and the new one, before it allocates
        anything (the namelist's check, ``validate.check_resources``)."""
        validate.check_resources(validate.Estimate(self._parts() + [part]), None, None,
                                 "static")

    def _parts(self) -> "list[validate.Part]":
        """The bodies' shares of the memory estimate (each kind's)."""
        kinds_of = [(kind_of(body), body) for body in self.bodies.values()]
        return [found.part(body) for found, body in kinds_of
                if found is not None and found.part is not None]

    @_api
    def drive(self, name: str, type: str, **params) -> Drive:
        """A drive (``ancfdrv.system.drives``): type 'constant' (value), 'luffing' (omega,
        t_start, t_brake, sweep, start), 'spinup' (omega, period, start), 'cycle'
        (amplitude, period, t0), 'sine' (amplitude, frequency, phase, offset, t0, ramp),
        'table' (times, values, or file = CSV path; interpolation = 'linear' | 'cubic' |
        'pchip'), 'ramp' (rate, t_ramp, start, t0). The namelist &drive takes the same
        parameters (docs/scenes.md)."""
        name = self._new_name(name, self.drives, "drive")
        where = f"drive {name!r}"
        if not isinstance(type, str) or type not in DRIVE_TYPES:
            raise InputError(f"{where}: type {short_repr(type)} must be one of "
                             f"{', '.join(DRIVE_TYPES)}")
        params = check_drive_params(name, type, params)
        try:
            if type == "table" and "file" in params:
                extra = set(params) - {"file", "interpolation"}
                if extra:
                    raise TypeError(f"unexpected {sorted(extra)}")
                drive = Table.from_csv(name, params["file"],
                                       interpolation=params.get("interpolation", "linear"))
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

    @_api
    def joint(self, name: str, type: str, body1: str | Body, body2: str | Body, *, point=None,
              axis=None, drive: str | Drive | None = None, point1=None, point2=None,
              pivot=None, vector: str = "r", edge: str | None = None, box=None,
              axis2=None) -> Joint:
        """A joint (``ancfdrv.system.joints``); ``point`` may list several points (the joint
        then acts at each), any material points of the bodies (SPEC 8.1). Instead of points,
        ``edge`` ('x0', 'x1', 'y0', 'y1': a side of a plate or leaf) or ``box`` (x0, y0, z0,
        x1, y1, z1) selects every node of the flexible body there, whatever the mesh.
        ``axis2``: a 'universal' joint's second cross axis, on body2 (``axis`` is on body1)."""
        name = self._new_name(name, self.joints, "joint")
        where = f"joint {name!r}"
        if name in getattr(self, "force_elements", {}):
            raise InputError(f"{where}: a force element has that name (reactions are stored "
                             "by name)")
        v = check_call("joint", f"joint[{name}]", dict(
            point=point, axis=axis, point1=point1, point2=point2, pivot=pivot, axis2=axis2))
        axis = v["axis"]
        try:
            points = [] if point is None else points_of(point)
            p1 = None if point1 is None else points_of(point1)[0]
            p2 = None if point2 is None else points_of(point2)[0]
            pv = None if pivot is None else points_of(pivot)[0]
        except ValueError as exc:
            raise InputError(f"{where}: {exc}") from None
        joint = Joint(name, type, self.body(body1, used_by=where), self.body(body2, used_by=where),
                      points, axis, self._drive(drive, where), p1, p2, pv, vector, edge, box,
                      axis2=v["axis2"])
        self.joints[name] = joint
        return joint

    @_api
    def load(self, name: str, type: str, *, body: str | Body | None = None, point=None,
             vector=None, mass: float | None = None, value: float | None = None,
             drive: str | Drive | None = None, effect: str | None = None,
             follower: bool = False) -> Load:
        """A load (``ancfdrv.system.loads``): 'gravity' (vector), 'force' (body, point,
        vector, drive, follower), 'moment' (body, point, vector, drive, follower),
        'point_mass' (body, point, mass), 'pressure' (body, value); ``effect`` defaults by
        type (SPEC section 8). ``follower``: the vector is fixed in the body's material frame
        at the point (given at t = 0) and turns with the body."""
        name = self._new_name(name, self.loads, "load")
        where = f"load {name!r}"
        if not isinstance(type, str) or type not in LOAD_TYPES:
            raise InputError(f"{where}: type {short_repr(type)} must be one of "
                             f"{', '.join(LOAD_TYPES)}")
        v = check_call("load", f"load[{name}]", dict(point=point, vector=vector, mass=mass,
                                                     value=value, effect=effect))
        point, vector, mass, value, effect = (v["point"], v["vector"], v["mass"], v["value"],
                                              v["effect"])
        if effect is not None:
            check_effects([effect], what=f"load[{name}]")
        effect = effect or LOAD_EFFECTS[type]
        needs = LOAD_PARAMETERS[type]
        given = dict(body=body, point=point, vector=vector, mass=mass, value=value)
        missing = [k for k in needs if given[k] is None]
        if missing:
            raise InputError(f"{where}: type {type!r} needs {', '.join(missing)}")
        extra = [k for k, v in given.items() if v is not None and k not in needs]
        if drive is not None and type not in ("force", "moment"):
            extra.append("drive")
        if follower is not False and type not in ("force", "moment"):
            extra.append("follower")
        if extra:
            raise InputError(f"{where}: type {type!r} does not take {', '.join(extra)}")
        target = None if body is None else self.body(body, used_by=where)
        if target is not None and isinstance(target, Ground):
            raise InputError(f"{where}: a load on the ground does nothing")
        cls = LOAD_TYPES[type]
        if type == "gravity":
            load = cls(name, vector, effect)
        elif type == "force":
            load = cls(name, target, point, vector, self._drive(drive, where), effect,
                       follower)
        elif type == "moment":
            load = cls(name, target, point, vector, effect, self._drive(drive, where), follower)
        elif type == "point_mass":
            load = cls(name, target, point, float(mass), effect)
        else:
            load = cls(name, target, float(value), effect)
        if target is not None and point is not None:
            target.locate(load.point, node=False, what=where)  # a material point of the body
        self.loads[name] = load
        return load

    @_api
    def contact(self, name: str, body1: str | Body, body2: str | Body, *, stiffness: float,
                damping: float = 0.0, friction: float = 0.0, slip_speed: float = 0.08,
                points: int = 3) -> ContactPair:
        """A contact pair (``ancfdrv.system.contact``)."""
        name = self._new_name(name, self.contacts, "contact")
        where = f"contact {name!r}"
        v = check_call("contact", f"contact[{name}]", dict(
            stiffness=stiffness, damping=damping, friction=friction, slip_speed=slip_speed,
            points=points))
        stiffness, damping, friction = v["stiffness"], v["damping"], v["friction"]
        slip_speed, points = v["slip_speed"], v["points"]
        pair = ContactPair(name, self.body(body1, used_by=where), self.body(body2, used_by=where),
                           stiffness, damping, friction, slip_speed, points)
        self.contacts[name] = pair
        return pair

    @_api
    @_typed("force_element")
    def force_element(self, name: str, type: str, body1: str | Body = "ground",
                      body2: str | Body | None = None, **values: Any) -> ForceElement:
        """A force element between body1 and body2 (either may be 'ground'; points are any
        material points of the bodies), ``ancfdrv.system.kinds.force_element``:

        - ``'spring_damper'``: point1, point2; stiffness (N/m), damping (N s/m), free_length
          (m; default the distance at t = 0), preload (N at the free length, tension
          positive); or instead of stiffness and preload a force-deflection table
          ``deflections`` (m, increasing), ``forces`` (N) with ``interpolation`` 'linear'
          (default), 'cubic' or 'pchip'.
        - ``'bushing'``: point; stiffness and damping (3 each: along body1's axes at the
          point), rotational_stiffness and rotational_damping (3 each: about them).
        - ``'cylinder'``: point1, point2, drive (the nominal length l(t), m), stiffness and
          damping of the oil column in series: f = k (L - l) + c (L' - l').
        - ``'torsion'``: point, axis; rotational_stiffness (N m/rad) and rotational_damping
          (N m s/rad) about the axis: the moment on body2 is -(k theta + c theta').

        Its reaction (force, moment, axial) is recorded under its name with the joints'."""
        return self.add("force_element", name=name, type=type, body1=body1, body2=body2,
                        **values)

    @_api
    def probe(self, name: str, body: str | Body, point) -> Probe:
        """A probe at a material point of a body."""
        name = self._new_name(name, self.probes, "probe")
        where = f"probe {name!r}"
        point = check_call("probe", f"probe[{name}]", dict(point=point))["point"]
        target = self.body(body, used_by=where)
        if isinstance(target, Ground):
            raise InputError(f"{where}: the ground does not move")
        try:
            p = points_of(point)
        except ValueError as exc:
            raise InputError(f"{where}: {exc}") from None
        target.locate(p[0], node=False, what=where)
        self.probes[name] = Probe(name, target, p[0])
        return self.probes[name]

    # -- the model ------------------------------------------------------------------------
    def check_bounds(self) -> None:
        """Every drive, load and force element within the physical bounds
        (``validate.PHYSICAL_BOUNDS``: rates, frequencies, accelerations, forces, moments,
        masses, pressures, stiffnesses, dampings) and every nonzero stiffness and every
        flexible body's size and section above the physical minima
        (``validate.PHYSICAL_MINIMA``); InputError naming the item, the value and the
        bound otherwise. Lifted by ``bounds='off'``."""
        for drive in self.drives.values():
            where = f"drive {drive.name!r}"
            omega = getattr(drive, "omega", None)
            if omega is not None:
                validate.check_bound("angular_rate", float(omega), f"{where}: omega")
            frequency = getattr(drive, "frequency", None)
            if frequency is not None:
                validate.check_bound("frequency", float(frequency), f"{where}: frequency")
        quantity = {"gravity": ("acceleration", "vector"), "force": ("force", "vector"),
                    "moment": ("moment", "vector"), "point_mass": ("mass", "mass"),
                    "pressure": ("pressure", "value")}
        types = {cls: name for name, cls in LOAD_TYPES.items()}
        for load in self.loads.values():
            kind, attribute = quantity[types[type(load)]]
            value = getattr(load, attribute)
            magnitude = float(np.linalg.norm(value)) if np.ndim(value) else float(value)
            validate.check_bound(kind, magnitude, f"load {load.name!r}: |{attribute}|"
                                 if np.ndim(value) else f"load {load.name!r}: {attribute}")
        for element in self.force_elements.values():
            where = f"force element {element.name!r}"
            for key in ("stiffness", "rotational_stiffness", "damping", "rotational_damping"):
                for value in np.atleast_1d(getattr(element, key)).tolist():
                    validate.check_bound(key, value, f"{where}: {key}", key=key)
                    if key in validate.PHYSICAL_MINIMA:
                        validate.check_minimum(key, value, f"{where}: {key}", key=key)
        for body in self.bodies.values():
            self._check_dimensions(body)

    @staticmethod
    def _check_dimensions(body: Body) -> None:
        """A flexible body's size and section within the physical minima
        (``validate.PHYSICAL_MINIMA``: 'length', 'section'; each kind's check)."""
        found = kind_of(body)
        if found is not None and found.check_dimensions is not None:
            found.check_dimensions(body)

    def check_effects_used(self, effects: Iterable[str]) -> None:
        """Every effect listed is one an item of the system belongs to (an effect that
        nothing uses is a typo or a forgotten item: InputError naming it)."""
        used = self.effects_used()
        if any(b.material.damping_time > 0 for b in self.bodies.values()
               if hasattr(b, "material")):
            used.add("damping")
        unused = [e for e in effects if e not in used]
        if unused:
            raise InputError(f"effect {', '.join(map(repr, unused))} is listed but no item of "
                             f"the system belongs to it (effects used: "
                             f"{', '.join(sorted(used)) or 'none'}): remove it or add the item",
                             group="scene", key="effects")

    def effects_used(self) -> set[str]:
        """Every effect an item of the system belongs to."""
        out = {load.effect for load in self.loads.values()}
        if self.contacts:
            out.add("contact")
            if any(c.friction > 0 for c in self.contacts.values()):
                out.add("friction")
        for body in self.bodies.values():
            found = kind_of(body)
            if found is not None and found.effects is not None:
                out |= found.effects(body)
        return out

    def assemble(self, *, effects: Iterable[str] | None = None, linear_joints: str = "auto",
                 check_frames: bool = True, unused_effects: str | None = None,
                 bounds: str | None = None, warnings: Iterable[str] = (),
                 response: tuple[str, int] | None = None, supports: bool = False,
                 fixed_loads: Iterable[str] = ()):
        """The model of this system (``ancfdrv.system.assembly.assemble``): only the effects
        listed (default: the system's own list, else all it uses) are computed. An 'ffr'
        beam whose floating frame nothing holds is refused (InputError); with
        ``check_frames=False`` it is assembled for checks of the joint equations alone, and
        the solvers refuse to run it. An effect listed that no item belongs to is a warning
        (``model.warnings`` and a UserWarning) with ``unused_effects='warn'``, refused
        (InputError) with 'refuse', passed over with 'allow' (template scenes, whose effects
        switch loads that a value of 0 leaves out); by default the system's own list
        (``System(effects=...)``) gets 'warn', a list given here 'allow' (a caller switching
        effects of a built system). Drives and loads beyond the physical
        bounds are refused (:meth:`check_bounds`) unless ``bounds='off'`` (default: the
        system's own setting). The model is complete when it is returned: ``warnings``
        (a builder's) come first in ``model.warnings``, then the assembly's, then the check
        of 'ffr' frames turning near a bending frequency; ``response`` is the (probe,
        component) a sweep compares (default: the first probe's); ``supports`` records the
        rigid motion of each beam's supports (``model.support_frames``: general scenes and
        Systems run from Python report deflections relative to it). ``fixed_loads``: loads
        (by name, or all loads of an effect) kept at their value whatever the load factor
        (buckling's fixed loads; a weight is fixed with its gravity, a point mass's when the
        point mass is named too); the names are not checked here."""
        from .assembly import assemble
        if effects is not None:
            effects = check_effects(effects)
        chosen = effects if effects is not None else self.effects
        if unused_effects is None:
            unused_effects = "allow" if effects is not None else "warn"
        if unused_effects not in ("refuse", "warn", "allow"):
            raise InputError(f"unused_effects must be 'refuse', 'warn' or 'allow', got "
                             f"{short_repr(unused_effects)}")
        unused_note = None
        if chosen is not None and unused_effects != "allow":
            try:
                self.check_effects_used(chosen)
            except InputError as exc:
                if unused_effects == "refuse":
                    raise
                unused_note = str(exc).split(": ", 1)[1]
        if bounds not in (None, "check", "off"):
            raise InputError(f"bounds must be 'check' or 'off', got {short_repr(bounds)}")
        if isinstance(warnings, str) or not isinstance(warnings, Iterable) or \
                not all(isinstance(w, str) for w in warnings):
            raise InputError(f"warnings must be a list of texts, got {short_repr(warnings)}")
        if response is not None and not (
                isinstance(response, tuple) and len(response) == 2 and
                response[0] in self.probes and response[1] in (0, 1, 2)):
            raise InputError(f"response must be (probe name, component 0, 1 or 2) of a probe "
                             f"of the system, got {short_repr(response)} (probes: "
                             f"{', '.join(self.probes) or 'none'})")
        if (bounds or self.bounds) == "check":
            self.check_bounds()
        validate.check_resources(validate.Estimate(self._parts(), contact_points=sum(
            2 * c.points for c in self.contacts.values())), None, None, "static")
        # no door here: the items passed theirs, so an exception of the assembly other
        # than the package's own is a bug and surfaces as one
        try:
            model = assemble(self, tuple(chosen) if chosen is not None else None,
                             linear_joints=linear_joints, check_frames=check_frames,
                             warnings=list(warnings), response=response, supports=supports,
                             fixed_loads=tuple(fixed_loads))
        except MemoryError:
            raise InputError("not enough memory to assemble this model: use a coarser mesh",
                             group="assemble") from None
        if unused_note:  # not silent: the run prints it, a script sees a UserWarning
            import warnings as _warnings
            model.warnings.append(unused_note)
            _warnings.warn(unused_note, UserWarning, stacklevel=3)
        model.warnings.extend(ffr_speed_warnings(self))
        return model

    # -- analyses (SPEC section 10, "Python") ------------------------------------------------
    #: the analyses, registered by :mod:`ancfdrv.analyses` (which sits above this layer: it
    #: runs the solvers and writes the result file)
    _ANALYSES: dict[str, Callable[..., Any]] = {}

    def _analysis(self, name: str) -> Callable[..., Any]:
        if name not in self._ANALYSES and not _lazy.load("analyses"):
            raise RuntimeError("import ancfdrv (the package) to run analyses")
        return self._ANALYSES[name]

    def static(self, **options: Any):
        """The static equilibrium, run exactly as ``ancf run`` runs a static scene, with
        the CLI's defaults. Keywords: any key of the scene groups &solver and &output
        (``static_method='auto'`` by default as in the CLI: the split iteration where it
        applies, 'newton' otherwise; ``tol``, ``max_iter``,
        ``load_steps``, ...; docs/scenes.md), ``effects`` (default: the system's list, else
        every effect its items belong to), ``output`` (an HDF5 path; default a temporary
        file, see :meth:`~ancfdrv.results.Results.save`), ``progress``.

        Returns :class:`ancfdrv.results.Results`: ``.probes[name]``, ``.deflection[name]``,
        ``.counters``, ``.timing``, ``.status``, ``.save(path)``, ... Raises InputError on
        bad input and SolverError when the solve fails."""
        return self._analysis("static")(self, **options)

    def simulate(self, t_end: float, dt: float | None = None, *, from_static: bool = False,
                 **options: Any):
        """Dynamics from 0 to ``t_end`` (s) with the step ``dt`` (s; default the CLI's,
        1e-3), run exactly as ``ancf run`` runs a dynamic scene, with the CLI's defaults
        (Newmark average acceleration, ``jacobian='reuse'``, ...). ``from_static``: start
        from the static equilibrium (analysis 'static+dynamic'), else at rest in the
        assembled configuration. Other keywords as :meth:`static` (e.g.
        ``integrator='generalized_alpha', rho_inf=0.8``, ``q=True``, ``xdmf=False``).
        Returns :class:`ancfdrv.results.Results` with time histories (``.time``,
        ``.probes[name]`` of shape (nt, 3), ``.energy``)."""
        return self._analysis("simulate")(self, t_end, dt, from_static=from_static, **options)

    def show(self, path=None):
        """A picture of the undeformed model, nothing solved (``ancf show``,
        :mod:`ancfdrv.preview`): three orthographic views and an isometric one with the
        names of bodies, joints, loads and probes, written to ``path`` (a PNG; default a new
        temporary file ``ancf-show-*.png``). Returns the PNG's path."""
        return self._analysis("show")(self, path)

    # -- modal analysis and linear buckling (SPEC section 10) ----------------------------
    def modes(self, n: int = 10, *, effects: Iterable[str] | None = None,
              linear_joints: str = "auto", **options):
        """The ``n`` lowest modes about the static equilibrium of the system's loads
        (:func:`ancfdrv.solvers.modal.modal_analysis`; ``n`` is &modal modes, ``options``
        the other keys of &modal (solver, rigid_tol, spin_rate, spin_axis, spin_centre) and
        &solver's tol, max_iter, load_steps, each checked as in a scene: InputError).
        Returns a :class:`~ancfdrv.solvers.modal.ModalResult` (frequency in Hz ascending,
        rigid-body modes at 0; mass-normalized shapes; damping_ratio with damping on)."""
        return self._analysis("modes")(self, n, effects=effects, linear_joints=linear_joints,
                                       **options)

    def buckling(self, n: int = 3, *, fixed_loads: Iterable[str] = (),
                 effects: Iterable[str] | None = None, linear_joints: str = "auto",
                 **options):
        """The ``n`` lowest positive load factors of the system's loads about their static
        state (:func:`ancfdrv.solvers.buckling.buckling_analysis`): the loads (by name, or
        all loads of an effect) in ``fixed_loads`` keep their value, the others are
        multiplied. ``n`` is &buckling modes, ``options`` the other keys of &buckling
        (method 'nonlinear' | 'linear', solver, rtol, load_steps, reference_factor) and
        &solver's tol, max_iter, each checked as in a scene (InputError). Returns a
        :class:`~ancfdrv.solvers.buckling.BucklingResult`."""
        return self._analysis("buckling")(self, n, fixed_loads=fixed_loads, effects=effects,
                                          linear_joints=linear_joints, **options)


#: drive parameters of the API per type (keyword -> schema key of &drive checked against)
DRIVE_PARAMS = {
    "constant": {"value": "value"},
    "luffing": {"omega": "omega", "t_start": "t_start", "t_brake": "t_brake",
                "sweep": "sweep", "start": "start"},
    "spinup": {"omega": "omega", "period": "period", "start": "start"},
    "cycle": {"amplitude": "amplitude", "period": "period", "t0": "t0"},
    "sine": {"amplitude": "amplitude", "frequency": "frequency", "phase": "phase",
             "offset": "offset", "t0": "t0", "ramp": "ramp"},
    "table": {"times": "times", "values": "values", "file": "file",
              "interpolation": "interpolation"},
    "ramp": {"rate": "rate", "t_ramp": "t_ramp", "start": "start", "t0": "t0"},
}


def check_drive_params(name: str, type: str, params: dict) -> dict:
    """A drive's keyword parameters: known for its type, each a finite number (times and
    values lists of them, file a path), with the checks of the namelist's &drive keys."""
    label = f"drive[{name}]"
    if type not in DRIVE_PARAMS:  # a drive type this table does not know: numbers finite
        known = {key: "times" if isinstance(plain_value(raw), list) else "value"
                 for key, raw in params.items() if key not in ("file", "times", "values")}
        known.update({k: k for k in ("file", "times", "values") if k in params})
    else:
        known = DRIVE_PARAMS[type]
    unknown = sorted(set(params) - set(known))
    if unknown:
        raise InputError(f"type {type!r} does not take {', '.join(unknown)} (parameters: "
                         f"{', '.join(known)})", group=label)
    out = {}
    for key, raw in params.items():
        if key == "file":
            if not isinstance(raw, (str, __import__("os").PathLike)):
                raise InputError(f"expected a file path, got {short_repr(raw)}", group=label,
                                 key=key)
            out[key] = raw
            continue
        if raw is None:
            raise InputError("expected a number, got None", group=label, key=key)
        checked = check_call("drive", label, {known[key]: raw})[known[key]]
        out[key] = checked
    return out


def check_effects(effects, *, what: str = "") -> tuple[str, ...]:
    """A list of effect names (strings, each a known effect), else InputError (the
    namelist's &scene effects check)."""
    where = dict(group=what or "scene", key="effects" if not what else "effect")
    if isinstance(effects, str):
        effects = [effects]
    try:
        items = list(effects)
    except TypeError:
        raise InputError(f"expected a list of effect names, got {short_repr(effects)}",
                         **where) from None
    for effect in items:
        if not isinstance(effect, str):
            raise InputError(f"expected effect names (strings), got {short_repr(effect)}",
                             **where)
        if effect not in EFFECTS_AVAILABLE:
            raise InputError(f"unknown effect {short_repr(effect)}; known effects: "
                             f"{', '.join(EFFECTS_AVAILABLE)}", **where)
    return tuple(items)
