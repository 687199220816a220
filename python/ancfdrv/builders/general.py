"""General scenes (SPEC section 8): a thin reader over the System API. Every named group
is one call, in file order: a kind's group (``&beam``, ``&cable``, ...; system/kinds/) ->
``System.add(group, **values)``, ``&material`` -> System.material, ``&joint`` -> System.joint, ...
Errors of a call (an unknown body in a joint, a non-physical value) are reported with the
file and the group, e.g. ``scene.nml: &joint[lift]: unknown body 'jib'``.
"""
from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from .common import BuiltSystem
from ..errors import InputError
from ..io.scene import GENERAL_BUILDER
from ..system import System
from ..system.registry import kind, kinds
from ..system.system import LOAD_EFFECTS

#: drive parameters per type: namelist key -> API keyword (with a conversion)
_DRIVE_KEYS: dict[str, dict[str, str]] = {
    "constant": {"value": "value"},
    "spinup": {"omega": "omega", "period": "period", "start": "start"},
    "cycle": {"amplitude": "amplitude", "period": "period", "t0": "t0"},
    "sine": {"amplitude": "amplitude", "frequency": "frequency", "phase": "phase",
             "offset": "offset", "t0": "t0", "ramp": "ramp"},
    "ramp": {"rate": "rate", "t_ramp": "t_ramp", "start": "start", "t0": "t0"},
}
_REQUIRED_DRIVE = {"constant": ("value",), "luffing": ("omega", "t_start", "t_brake", "start_deg",
                                                       "end_deg"),
                   "spinup": ("omega", "period"), "cycle": ("amplitude", "period"),
                   "sine": ("amplitude", "frequency"), "table": (),
                   "ramp": ("rate", "t_ramp")}


def effects_of(items: list[tuple[str, dict[str, Any]]]) -> set[str]:
    """The effects the items of a general scene belong to."""
    out = set()
    for group, v in items:
        if group == "load":
            out.add(v["effect"] or LOAD_EFFECTS[v["type"]])
        elif group == "contact":
            out.add("contact")
            if v["friction"] > 0:
                out.add("friction")
        elif group == "leaf" and v["free_radius"] is not None:
            out.add("prestress")
        elif group == "material" and v["damping_time"] > 0:
            out.add("damping")
    return out


def _drive(s: System, v: dict[str, Any], scene_dir: Path) -> None:
    kind = v["type"]
    given = {k for k, x in v.items() if x is not None and k not in ("name", "type")}
    missing = [k for k in _REQUIRED_DRIVE[kind] if v[k] is None]
    python_luffing = kind == "luffing" and v["sweep"] is not None
    if python_luffing:  # the Python API's parameters: omega, t_start, t_brake, sweep, start
        missing = [k for k in ("omega", "t_start", "t_brake") if v[k] is None]
    if kind == "table":
        if (v["file"] is None) == (v["times"] is None):
            raise InputError("a 'table' drive needs either file or times and values")
        allowed = ({"file"} if v["file"] is not None else {"times", "values"}) | \
            {"interpolation"}
    elif python_luffing:
        allowed = {"omega", "t_start", "t_brake", "sweep", "start"}
    elif kind == "luffing":
        allowed = {"omega", "t_start", "t_brake", "start_deg", "end_deg"}
    else:
        allowed = set(_DRIVE_KEYS[kind])
    if missing:
        raise InputError(f"type {kind!r} needs {', '.join(missing)}")
    extra = sorted(given - allowed)
    if extra:
        raise InputError(f"type {kind!r} does not take {', '.join(extra)}")
    if python_luffing:
        s.drive(v["name"], "luffing", omega=abs(v["omega"]) * np.sign(v["sweep"]),
                t_start=v["t_start"], t_brake=v["t_brake"], sweep=v["sweep"],
                start=v["start"] or 0.0)
    elif kind == "luffing":
        start, end = math.radians(v["start_deg"]), math.radians(v["end_deg"])
        s.drive(v["name"], "luffing", omega=abs(v["omega"]) * np.sign(end - start),
                t_start=v["t_start"], t_brake=v["t_brake"], sweep=end - start, start=start)
    elif kind == "table":
        if v["file"] is not None:
            path = Path(v["file"])
            path = path if path.is_absolute() else scene_dir / path
            _check_text_file(path)
            s.drive(v["name"], "table", file=path,
                    interpolation=v["interpolation"] or "linear")
        else:
            s.drive(v["name"], "table", times=v["times"], values=v["values"] or [],
                    interpolation=v["interpolation"] or "linear")
    else:
        s.drive(v["name"], kind, **{_DRIVE_KEYS[kind][k]: v[k] for k in given})


def _check_text_file(path: Path) -> None:
    """A table's CSV file must be UTF-8 text (the CSV reader would fail on the bytes)."""
    if not path.is_file():
        return  # the drive reports the missing file
    try:
        path.read_bytes().decode("utf-8")
    except OSError as exc:
        raise InputError(f"cannot read the table file {str(path)!r}: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"the table file {str(path)!r} is not a text file (byte {exc.start} "
                         "is not UTF-8)") from None


def _check_joint_points(s: System, scene) -> None:
    """Every joint point is a node of the beams, plates and leaves it joins (a material
    point of rigid bodies), checked now so that the message names the file and the joint;
    the assembly makes the same check when it writes the joint's equations."""
    for joint in s.joints.values():
        points = [joint.point1, joint.point2] if joint.type == "distance" else joint.points
        bodies = [joint.body1, joint.body2] if joint.type == "distance" else None
        try:
            for k, point in enumerate(points):
                for body in (bodies[k],) if bodies else joint.bodies:
                    if body.name != "ground":
                        joint._locate(body, point)
        except InputError as exc:
            raise InputError(str(exc), file=str(scene.path),
                             group=f"joint[{joint.name}]") from None


def _call(s: System, group: str, v: dict[str, Any], scene, scene_dir: Path) -> None:
    """One namelist group, one call of the System API."""
    found = kind(group)
    if found is not None:   # a kind's group (system/kinds/): System.add
        values = dict(v)
        for key, scene_key in found.scene_defaults.items():
            if values.get(key) is None:
                values[key] = scene["scene"][scene_key]
        s.add(group, **values)
    elif group == "material":
        s.material(v["name"], youngs_modulus=v["youngs_modulus"], density=v["density"],
                   poisson_ratio=v["poisson_ratio"], damping_time=v["damping_time"])
    elif group == "drive":
        _drive(s, v, scene_dir)
    elif group == "joint":
        s.joint(v["name"], v["type"], v["body1"], v["body2"], point=v["point"], axis=v["axis"],
                drive=v["drive"], point1=v["point1"], point2=v["point2"], pivot=v["pivot"],
                vector=v["vector"], edge=v["edge"], box=v["box"], axis2=v["axis2"])
    elif group == "load":
        s.load(v["name"], v["type"], body=v["body"], point=v["point"], vector=v["vector"],
               mass=v["mass"], value=v["value"], drive=v["drive"], effect=v["effect"],
               follower=v["follower"])
    elif group == "contact":
        s.contact(v["name"], v["body1"], v["body2"], stiffness=v["stiffness"],
                  damping=v["damping"], friction=v["friction"], slip_speed=v["slip_speed"],
                  points=v["points"])
    elif group == "probe":
        s.probe(v["name"], v["body"], v["point"])
    else:  # the schema admits no other group
        raise AssertionError(group)


_ITEM_WORDS = {"joint": "joint", "drive": "drive", "load": "load", "probe": "probe",
               "contact": "contact", "beam": "beam", "cable": "cable", "plate": "plate",
               "leaf": "leaf", "force element": "force_element",
               "rigid body": "rigid_body", "material": "material", "body": None}
_ITEM_PREFIX = re.compile(r"^(%s) '([^']*)'" % "|".join(_ITEM_WORDS))


def locate_error(exc: InputError, scene) -> InputError:
    """An InputError raised while a scene's model is assembled (a joint equation the
    initial configuration violates, coinciding points, ...) with the scene file and, for
    general scenes, the group[name] of the item its message starts with (``joint 'lift':
    ...`` or an equation name ``lift: position``, ``lift #2: ...``)."""
    if exc.file is not None:
        return exc
    if exc.group is not None:  # placed by whoever raised it (e.g. &solver static_method)
        return InputError(exc.reason, file=str(scene.path), group=exc.group, key=exc.key)
    message = str(exc)
    group = None
    if scene.kind == "general":
        names = {(g, v["name"]) for g, v in scene.items}
        match = _ITEM_PREFIX.match(message)
        if match:
            word, name = match.group(1), re.sub(r" #\d+$", "", match.group(2))
            groups = [_ITEM_WORDS[word]] if _ITEM_WORDS[word] else \
                [k.group for k in kinds() if k.table == "bodies"]
            group = next((f"{g}[{name}]" for g in groups if (g, name) in names), None)
        else:
            head = re.sub(r" #\d+$", "", message.split(":", 1)[0])
            group = next((f"{g}[{n}]" for g, n in sorted(names) if n == head), None)
    return InputError(message, file=str(scene.path), group=group,
                      key=exc.key if group is not None and exc.group is None else None)


def build_general(scene) -> BuiltSystem:
    """The System of a general scene (its groups in file order)."""
    s = System(scene["scene"]["title"], effects=scene.effects)
    # materials and drives first, then the bodies (numbered in file order), then what refers
    # to them: a scene may list its groups in any order
    rank = {"material": 0, "drive": 1, **{k.group: 2 for k in kinds() if k.table == "bodies"}}
    order = sorted(scene.items, key=lambda item: rank.get(item[0], 3))
    for group, values in order:
        try:
            _call(s, group, values, scene, scene.path.parent)
        except InputError as exc:
            raise InputError(str(exc), file=str(scene.path),
                             group=f"{group}[{values['name']}]") from None
    _check_joint_points(s, scene)
    if scene["scene"].get("bounds", "check") == "check":  # before any case of a sweep runs
        try:
            s.check_bounds()
        except InputError as exc:
            raise locate_error(exc, scene) from None
    response = None
    if scene["scene"].get("response"):
        name = scene["scene"]["response"]
        if name not in s.probes:
            raise InputError(f"response {name!r} is not a probe (probes: "
                             f"{', '.join(s.probes) or 'none'})", file=str(scene.path),
                             group="scene", key="response")
        response = (name, scene["scene"]["response_component"])
    return BuiltSystem(s, response)


GENERAL_BUILDER.update(effects_of=effects_of, build=build_general)  # for io.scene.load_scene
