"""Scenes: Fortran namelist files, parsed with f90nml and validated against a schema.

Every group and key a scene may use is declared in :data:`SCHEMA` with its type, default,
physical range and a one-line meaning. Unknown groups or keys, missing required keys,
wrong sizes and non-physical values raise :class:`~ancfdrv.errors.InputError` naming the
file, the group and the key (exit status 2 on the command line).
"""
from __future__ import annotations

import io
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import f90nml

from ..errors import InputError

REQUIRED = object()

#: Effects a scene may list in ``&scene effects``; what is not listed is never computed.
EFFECTS_AVAILABLE = ("gravity", "tip_mass", "bending_moment", "tip_force", "end_moment",
                     "pressure", "prestress", "contact", "friction", "load_cycle")
#: Effects of later capabilities, recognised so the message can say so.
EFFECTS_PLANNED = ("damping",)


@dataclass(frozen=True)
class Key:
    """One namelist key: its type, default (or REQUIRED), check and meaning."""

    kind: str  # 'float', 'int', 'str', 'bool', 'floats', 'strs'
    default: Any = REQUIRED
    check: Callable[[Any], str | None] | None = None
    doc: str = ""
    size: int | None = None  # exact length for list kinds


def positive(v: Any) -> str | None:
    return None if v > 0 else "must be positive"


def non_negative(v: Any) -> str | None:
    return None if v >= 0 else "must not be negative"


def one_of(*choices: str) -> Callable[[Any], str | None]:
    def check(v: Any) -> str | None:
        return None if v in choices else f"must be one of {', '.join(repr(c) for c in choices)}"
    return check


def within(lo: float, hi: float, *, open_hi: bool = False) -> Callable[[Any], str | None]:
    def check(v: Any) -> str | None:
        ok = lo <= v < hi if open_hi else lo <= v <= hi
        return None if ok else f"must lie in [{lo}, {hi}{')' if open_hi else ']'}"
    return check


SCHEMA: dict[str, dict[str, Key]] = {
    "scene": {
        "title": Key("str", doc="a line describing the scene"),
        "analysis": Key("str", "static", one_of("static", "dynamic", "static+dynamic"),
                        "which analysis runs"),
        "formulation": Key("str", "ffr", one_of("ffr", "nonlinear"), "elastic model"),
        "effects": Key("strs", [], doc="force effects to compute; nothing else is computed"),
    },
    "beam": {
        "length": Key("float", check=positive, doc="length of the neutral axis (m)"),
        "width": Key("float", check=positive, doc="section width w, along z (m)"),
        "height": Key("float", check=positive, doc="section height h, along y (m)"),
        "nodes": Key("int", check=lambda v: None if v >= 2 else "must be at least 2",
                     doc="total nodes on the beam"),
        "segments": Key("floats", None, doc="segment lengths between fixed nodes (m); "
                        "each is split into equal elements"),
        "bending": Key("str", "continuum", one_of("continuum", "cubic"),
                       "'continuum': the paper's element (curvature constant per element); "
                       "'cubic': curvature from the cubic centre line r_xx, higher accuracy "
                       "(docs/theory.md section 12)"),
    },
    "material": {
        "youngs_modulus": Key("float", check=positive, doc="E (Pa)"),
        "density": Key("float", check=positive, doc="rho (kg/m^3)"),
        "poisson_ratio": Key("float", 0.0, within(0.0, 0.5, open_hi=True),
                             doc="nu in the elastic law; 0 avoids Poisson locking"),
    },
    "boom": {
        "pivot_offset": Key("float", 0.295, positive, "H = |O A1| (m)"),
        "angle_deg": Key("float", 0.0, within(-180.0, 180.0),
                         "luffing angle phi of the rigid configuration at t = 0 (deg)"),
        "omega": Key("float", 0.2, non_negative, "luffing rate (rad/s); 0 holds phi fixed"),
        "t_start": Key("float", 1.0, positive, "t_s: duration of the smooth start (s)"),
        "t_brake": Key("float", 1.0, positive, "t_b: duration of the smooth braking (s)"),
        "angle_end_deg": Key("float", 60.0, within(-180.0, 180.0),
                             "luffing angle reached at the end of braking (deg)"),
    },
    "cantilever": {
        "clamp": Key("str", "section", one_of("section", "full", "pin"),
                     "'section' fixes r, r_y, r_z of the root node; 'full' also r_x; 'pin' "
                     "fixes r and r_z (a hinge about r3)"),
    },
    "spinup": {
        "omega": Key("float", 6.0, positive, "final hub speed W (rad/s)"),
        "period": Key("float", 15.0, positive, "spin-up time T (s)"),
    },
    "plate": {
        "length_x": Key("float", check=positive, doc="side along r1 (m)"),
        "length_y": Key("float", check=positive, doc="side along r2 (m)"),
        "thickness": Key("float", check=positive, doc="plate thickness h (m)"),
        "nx": Key("int", 4, positive, "elements along r1"),
        "ny": Key("int", 4, positive, "elements along r2"),
        "variant": Key("str", "completed", one_of("plain", "completed"),
                       "thin plate element (seed 003): 'plain' (Dufva-Shabana) or "
                       "'completed' (unit normal as third gradient)"),
        "support": Key("str", "corner_spherical",
                       one_of("corner_spherical", "simply_supported", "clamped_edge"),
                       "'corner_spherical': spherical joint at the corner (0, 0, 0); "
                       "'simply_supported': w = 0 on all edges; 'clamped_edge': edge x = 0 "
                       "clamped"),
    },
    "leaf": {
        "arc_length": Key("float", None, positive, "mid-surface arc length (m); required "
                          "in &leaf scenes (in &spring scenes the leaves' lengths are in &spring)"),
        "radius": Key("float", None, positive, "mid-surface radius of the initial "
                      "(assembled) shape (m); concave up, symmetric about r1 = 0; required in "
                      "&leaf scenes"),
        "prestress": Key("bool", False, doc="&spring scenes: the lower leaf's stress-free "
                         "radius is free_radius (needs the effect 'prestress'); off: it is "
                         "stress-free as assembled"),
        "free_radius": Key("float", None, positive, "radius of the stress-free shape (m); "
                           "differs from radius only with the effect 'prestress' "
                           "(default: radius)"),
        "width": Key("float", check=positive, doc="leaf width along r2 (m)"),
        "thickness": Key("float", check=positive, doc="leaf thickness (m)"),
        "nx": Key("int", 8, lambda v: None if v >= 2 and v % 2 == 0 else
                  "must be even (the middle of the leaf is a node line)",
                  "elements along the arc"),
        "ny": Key("int", 1, positive, "elements across the width"),
        "variant": Key("str", "completed", one_of("plain", "completed"),
                       "'completed' removes the initial strain of the curved reference; "
                       "'plain' springs back toward flat (seed 003's motivation)"),
        "support": Key("str", "middle_clamp", one_of("middle_clamp", "free"),
                       "'middle_clamp': r and r_x of the middle node line fixed (the "
                       "axle's U-bolts, seed 003); 'free': unsupported"),
    },
    "spring": {
        "main_arc_length": Key("float", 1.2, positive, "main (upper) leaf arc length (m)"),
        "main_radius": Key("float", 2.0, positive, "main leaf mid-surface radius (m)"),
        "main_nx": Key("int", 12, lambda v: None if v >= 2 and v % 2 == 0 else
                       "must be even (the middle of the leaf is a node line)",
                       "main leaf elements along the arc"),
        "lower_arc_length": Key("float", 0.8, positive, "lower leaf arc length (m)"),
        "lower_radius": Key("float", None, positive, "lower leaf mid-surface radius as "
                            "assembled (m); default main_radius + thickness (concentric, "
                            "touching)"),
        "lower_nx": Key("int", 8, lambda v: None if v >= 2 and v % 2 == 0 else
                        "must be even (the middle of the leaf is a node line)",
                        "lower leaf elements along the arc"),
        "chassis_mass": Key("float", 500.0, positive, "chassis mass (kg)"),
        "chassis_inertia": Key("float", 50.0, positive, "chassis inertia about r2 (kg m^2)"),
        "shackle_length": Key("float", 0.1, positive, "shackle length, eye to chassis (m)"),
        "shackle_mass": Key("float", 2.0, positive, "shackle mass (kg)"),
        "guide": Key("str", "planar", one_of("planar", "vertical"),
                     "'planar': chassis free in the r1-r3 plane; 'vertical': it translates "
                     "without turning (load cycle; its horizontal drift stays free, as the "
                     "axle and the front eye are both held along r1)"),
        "contact_stiffness": Key("float", 1.0e6, positive, "penalty stiffness K (N/m)"),
        "contact_damping": Key("float", 1.0e4, non_negative,
                               "contact damping C in F_n = K d - C d' d"),
        "friction_coefficient": Key("float", 0.3, non_negative, "Coulomb coefficient mu"),
        "slip_velocity": Key("float", 0.08, positive, "critical slip velocity V_t (m/s)"),
        "contact_points": Key("int", 3, lambda v: None if v >= 2 else "must be at least 2",
                              "contact points per end edge of the lower leaf"),
        "cycle_force": Key("float", 0.0, non_negative, "effect 'load_cycle': peak downward "
                           "force on the chassis (N)"),
        "cycle_period": Key("float", 4.0, positive, "effect 'load_cycle': duration of the "
                            "cycle 0 -> peak -> 0 (s)"),
    },
    "loads": {
        "gravity": Key("float", 9.81, non_negative, "gravitational acceleration (m/s^2)"),
        "tip_mass": Key("float", 0.0, non_negative, "lumped mass at the tip (kg)"),
        "moment": Key("float", 0.0, doc="boom: moment M_B about +r3 on the section at A2 (N m)"),
        "tip_force": Key("floats", [0.0, 0.0, 0.0], size=3, doc="force at the tip (N)"),
        "end_moment": Key("float", 0.0, doc="moment about +r3 on the tip section (N m)"),
        "pressure": Key("float", 0.0, doc="plate: dead pressure along -r3 (Pa)"),
    },
    "solver": {
        "static_method": Key("str", "split", one_of("split", "newton"),
                             "static solver: split iteration or Newton-Raphson"),
        "tol": Key("float", 1e-10, lambda v: None if 0 < v < 1 else "must lie in (0, 1)",
                   "relative tolerance of the static solve"),
        "max_iter": Key("int", 50, positive, "iteration limit of the static solve"),
        "load_steps": Key("int", 1, positive, "load increments of the static Newton solve "
                          "(large deformation)"),
        "split_p": Key("float", 0.0, within(0.0, 1.0, open_hi=True),
                       "splitting parameter p of K_RR = K_RR1 + K_RR2, in [0, 1)"),
        "dt": Key("float", 1e-3, positive, "time step (s), dynamic analyses"),
        "t_end": Key("float", 10.0, non_negative, "end time (s), dynamic analyses"),
        "integrator": Key("str", "newmark", one_of("newmark", "generalized_alpha"),
                          "time integrator"),
        "rho_inf": Key("float", 0.9, within(0.0, 1.0),
                       "generalized-alpha: spectral radius at infinite frequency (1: no "
                       "numerical damping)"),
        "beta": Key("float", 0.25, lambda v: None if 0 < v <= 0.5 else "must lie in (0, 0.5]",
                    "Newmark beta (1/4: average acceleration, the paper's choice)"),
        "gamma": Key("float", 0.5, within(0.5, 1.0), "Newmark gamma (1/2: no damping)"),
        "newton_tol": Key("float", 1e-10, lambda v: None if 0 < v < 1 else "must lie in (0, 1)",
                          "a step ends when its Newton correction is below newton_tol * length"),
        "max_newton": Key("int", 10, positive, "Newton iterations allowed per step"),
        "jacobian": Key("str", "step", one_of("step", "iteration", "reuse"),
                        "when a refactorized model's iteration matrix is refreshed: 'step' (at "
                        "each step, and when a correction does not halve), 'iteration' (full "
                        "Newton), 'reuse' (modified Newton across steps); pure FFR systems "
                        "factorize once whatever this says"),
        "contraction": Key("float", 0.5, lambda v: None if 0 < v < 1 else "must lie in (0, 1)",
                           "jacobian = 'reuse': refresh when a correction exceeds this fraction "
                           "of the previous one"),
        "linear_joints": Key("str", "auto", one_of("auto", "eliminate", "multipliers"),
                             "linear joint equations: eliminated (q = B e + q0, seed 003) or "
                             "kept with multipliers (seed 000); 'auto' eliminates when the "
                             "system has rigid bodies"),
    },
    "output": {
        "file": Key("str", None, doc="HDF5 result file (default results/<scene>.h5)"),
        "q": Key("bool", False, doc="store the coordinates q at every step"),
        "chunk_steps": Key("int", 1000, positive,
                           "steps per kernel call; each chunk is flushed to the file"),
    },
}

#: Groups that define what is built; a scene has exactly one of them.
MODEL_GROUPS = ("boom", "cantilever", "spinup", "plate", "leaf", "spring")
#: Models built from thin plate elements (seed 003); the others are beams (seed 000).
PLATE_KINDS = ("plate", "leaf", "spring")
COMMON_GROUPS = ("scene", "material", "loads", "solver", "output")


@dataclass
class Scene:
    """A validated scene: typed values per group, the source path and namelist text."""

    path: Path
    values: dict[str, dict[str, Any]]
    text: str
    overrides: list[str] = field(default_factory=list)

    @property
    def kind(self) -> str:
        """The model the scene builds: one of MODEL_GROUPS."""
        if "spring" in self.values:  # its &leaf group describes the leaf pack
            return "spring"
        return next(g for g in MODEL_GROUPS if g in self.values)

    @property
    def effects(self) -> tuple[str, ...]:
        return tuple(self.values["scene"]["effects"])

    def get(self, dotted: str) -> Any:
        group, key = dotted.split(".")
        return self.values[group][key]

    def __getitem__(self, group: str) -> dict[str, Any]:
        return self.values[group]

    @property
    def output_file(self) -> Path:
        name = self.values.get("output", {}).get("file")
        return Path(name) if name else Path("results") / (self.path.stem + ".h5")


def _coerce(kind: str, raw: Any, where: dict) -> Any:
    def bad(expected: str) -> InputError:
        return InputError(f"expected {expected}, got {raw!r}", **where)

    def as_float(x: Any) -> float:
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            raise bad("a number")
        if not math.isfinite(float(x)):
            raise bad("a finite number")
        return float(x)

    if kind == "float":
        return as_float(raw)
    if kind == "int":
        if isinstance(raw, bool) or not isinstance(raw, int):
            if isinstance(raw, float) and raw.is_integer():
                return int(raw)
            raise bad("an integer")
        return raw
    if kind == "str":
        if not isinstance(raw, str):
            raise bad("a string")
        return raw.strip()
    if kind == "bool":
        if not isinstance(raw, bool):
            raise bad(".true. or .false.")
        return raw
    if kind == "floats":
        items = raw if isinstance(raw, list) else [raw]
        return [as_float(x) for x in items]
    if kind == "strs":
        items = raw if isinstance(raw, list) else [raw]
        if not all(isinstance(x, str) for x in items):
            raise bad("a list of strings")
        return [x.strip() for x in items if x is not None and x.strip()]  # '' = none
    raise AssertionError(kind)


def _parse_override_value(kind: str, text: str, where: dict) -> Any:
    """Parse the VALUE of --set GROUP.KEY=VALUE, typed like the namelist entry."""
    text = text.strip()
    if kind == "strs":  # an empty value is the empty list
        return [t.strip().strip("'\"") for t in text.split(",") if t.strip().strip("'\"")]
    if kind == "str":
        return text.strip("'\"")
    try:
        parsed = f90nml.reads(f"&x v = {text} /")["x"]["v"]
    except Exception as exc:  # f90nml raises several types
        raise InputError(f"cannot parse override value {text!r}: {exc}", **where) from None
    return parsed


def load_scene(path: str | Path, overrides: list[str] | None = None) -> Scene:
    """Read, override and validate a scene file. Raises InputError on any problem."""
    path = Path(path)
    file = str(path)
    if not path.is_file():
        raise InputError("scene file not found", file=file)
    try:
        nml = f90nml.read(str(path))
    except Exception as exc:
        raise InputError(f"not a valid Fortran namelist: {exc}", file=file) from None
    for group, entries in nml.items():
        if group not in SCHEMA:
            raise InputError(f"unknown group; known groups: {', '.join(SCHEMA)}", file=file,
                             group=group)
        if isinstance(entries, list):
            raise InputError("group given more than once", file=file, group=group)

    applied = []
    for item in overrides or []:
        if "=" not in item or "." not in item.split("=", 1)[0]:
            raise InputError(f"override {item!r} is not of the form GROUP.KEY=VALUE", file=file)
        dotted, value = item.split("=", 1)
        group, key = (s.strip().lower() for s in dotted.split(".", 1))
        where = dict(file=file, group=group, key=key)
        if group not in SCHEMA:
            raise InputError(f"unknown group in override {item!r}", file=file, group=group)
        if key not in SCHEMA[group]:
            raise InputError(f"unknown key in override {item!r}; known keys: "
                             f"{', '.join(SCHEMA[group])}", **where)
        if group not in nml:
            nml[group] = f90nml.Namelist()
        nml[group][key] = _parse_override_value(SCHEMA[group][key].kind, value, where)
        applied.append(f"{group}.{key}={value}")

    values: dict[str, dict[str, Any]] = {}
    for group, entries in nml.items():
        typed: dict[str, Any] = {}
        for key, raw in entries.items():
            where = dict(file=file, group=group, key=key)
            if key not in SCHEMA[group]:
                raise InputError(f"unknown key; known keys of &{group}: "
                                 f"{', '.join(SCHEMA[group])}", **where)
            spec = SCHEMA[group][key]
            value = _coerce(spec.kind, raw, where)
            if spec.size is not None and len(value) != spec.size:
                raise InputError(f"expected {spec.size} values, got {len(value)}", **where)
            if spec.check is not None:
                items = value if spec.kind in ("floats",) else [value]
                for item in items:
                    message = spec.check(item)
                    if message:
                        raise InputError(f"{value!r} {message}", **where)
            typed[key] = value
        for key, spec in SCHEMA[group].items():
            if key not in typed:
                if spec.default is REQUIRED:
                    raise InputError("required key is missing", file=file, group=group, key=key)
                typed[key] = spec.default
        values[group] = typed

    models = [g for g in MODEL_GROUPS if g in values]
    if "spring" in models and "leaf" in models:  # &leaf: the spring's leaf pack
        models.remove("leaf")
    if len(models) != 1:
        raise InputError(f"a scene needs exactly one of the groups "
                         f"{', '.join('&' + g for g in MODEL_GROUPS)} (found "
                         f"{', '.join('&' + g for g in models) or 'none'})", file=file)
    kind = models[0]
    if kind in PLATE_KINDS and "beam" in values:
        raise InputError(f"&beam does not apply to a &{kind} scene", file=file, group="beam")
    for group in COMMON_GROUPS + (() if kind in PLATE_KINDS else ("beam",)):
        if group not in values:
            if any(spec.default is REQUIRED for spec in SCHEMA[group].values()):
                raise InputError("required group is missing", file=file, group=group)
            values[group] = {k: s.default for k, s in SCHEMA[group].items()}
    _check_consistency(values, file, kind)
    buffer = io.StringIO()
    nml.write(buffer)
    return Scene(path=path, values=values, text=buffer.getvalue(), overrides=applied)


def _check_consistency(values: dict[str, dict[str, Any]], file: str, kind: str) -> None:
    scene = values["scene"]
    for effect in scene["effects"]:
        if effect in EFFECTS_PLANNED:
            raise InputError(f"effect {effect!r} is not available in this version (available: "
                             f"{', '.join(EFFECTS_AVAILABLE)})", file=file, group="scene",
                             key="effects")
        if effect not in EFFECTS_AVAILABLE:
            raise InputError(f"unknown effect {effect!r}; known effects: "
                             f"{', '.join(EFFECTS_AVAILABLE)}", file=file, group="scene",
                             key="effects")
    if scene["formulation"] == "nonlinear" and scene["analysis"] != "dynamic":
        if values["solver"]["static_method"] != "newton":
            raise InputError("formulation 'nonlinear' needs static_method = 'newton' (the split "
                             "iteration relies on the constant FFR stiffness)", file=file,
                             group="solver", key="static_method")
    if kind in PLATE_KINDS:
        _check_plate(values, file, kind)
        return
    for effect in ("pressure", "prestress"):
        if effect in scene["effects"]:
            raise InputError(f"effect {effect!r} applies to plate and leaf scenes only",
                             file=file, group="scene", key="effects")
    beam = values["beam"]
    if beam["segments"] is None:
        beam["segments"] = [beam["length"]]
    segments = beam["segments"]
    if any(s <= 0 for s in segments):
        raise InputError("segment lengths must be positive", file=file, group="beam",
                         key="segments")
    if abs(sum(segments) - beam["length"]) > 1e-9 * beam["length"]:
        raise InputError(f"segments add up to {sum(segments):g} m, not beam.length = "
                         f"{beam['length']:g} m", file=file, group="beam", key="segments")
    k = len(segments)
    if (beam["nodes"] - 1) % k:
        raise InputError(f"nodes = {beam['nodes']}: with {k} segments the beam needs "
                         f"{k}j+1 nodes ({', '.join(str(k * j + 1) for j in range(1, 5))}, ...)",
                         file=file, group="beam", key="nodes")
    if "boom" in values and k != 3:
        raise InputError("the boom needs three segments A1-A2, A2-A3, A3-A4", file=file,
                         group="beam", key="segments")
    boom = values.get("boom")
    if boom and scene["analysis"] != "static" and boom["omega"] > 0:
        sweep = math.radians(boom["angle_end_deg"] - boom["angle_deg"])
        if sweep <= 0:
            raise InputError("luffing needs angle_end_deg > angle_deg (or omega = 0 to hold "
                             "the angle)", file=file, group="boom", key="angle_end_deg")
        if sweep / boom["omega"] < 0.5 * (boom["t_start"] + boom["t_brake"]):
            raise InputError(f"omega = {boom['omega']} rad/s sweeps the {math.degrees(sweep):g} "
                             "deg before start and braking are over; lower omega or shorten "
                             "t_start/t_brake", file=file, group="boom", key="omega")


def _check_plate(values: dict[str, dict[str, Any]], file: str, kind: str) -> None:
    """Plate and leaf scenes: the thin plate is a large-deformation element."""
    scene = values["scene"]
    if scene["formulation"] != "nonlinear":
        raise InputError(f"a &{kind} scene needs formulation = 'nonlinear' (the thin plate "
                         "element has no floating-frame model)", file=file, group="scene",
                         key="formulation")
    effects = scene["effects"]
    for effect in ("contact", "friction", "load_cycle"):
        if effect in effects and kind != "spring":
            raise InputError(f"effect {effect!r} applies to &spring scenes", file=file,
                             group="scene", key="effects")
    if kind == "spring":
        _check_spring(values, file)
        return
    support = values[kind]["support"]
    if scene["analysis"] != "dynamic" and support in ("corner_spherical", "free"):
        raise InputError(f"support '{support}' leaves rigid-body motions free: it has no "
                         "static equilibrium; use analysis = 'dynamic' or another support",
                         file=file, group=kind, key="support")
    for effect in ("tip_mass", "bending_moment", "tip_force", "end_moment"):
        if effect in effects:
            raise InputError(f"effect {effect!r} applies to beam scenes only", file=file,
                             group="scene", key="effects")
    if "pressure" in effects and kind != "plate":
        raise InputError("effect 'pressure' applies to &plate scenes", file=file,
                         group="scene", key="effects")
    if kind == "leaf":
        leaf = values["leaf"]
        for key in ("arc_length", "radius"):
            if leaf[key] is None:
                raise InputError("required key is missing", file=file, group="leaf", key=key)
        if leaf["prestress"]:
            raise InputError("leaf.prestress applies to &spring scenes; a single leaf is "
                             "prestressed by free_radius with the effect 'prestress'",
                             file=file, group="leaf", key="prestress")
        if leaf["free_radius"] is None:
            leaf["free_radius"] = leaf["radius"]
        differs = abs(leaf["free_radius"] - leaf["radius"]) > 1e-12 * leaf["radius"]
        if differs and "prestress" not in effects:
            raise InputError(f"free_radius = {leaf['free_radius']:g} m differs from radius = "
                             f"{leaf['radius']:g} m: list 'prestress' in scene.effects (or "
                             "remove free_radius)", file=file, group="leaf", key="free_radius")
        if "prestress" in effects and not differs:
            raise InputError("effect 'prestress' needs leaf.free_radius different from "
                             "leaf.radius", file=file, group="leaf", key="free_radius")
        if differs and leaf["variant"] != "completed":
            raise InputError("prestress needs variant = 'completed' (the plain element has no "
                             "stress-free reference)", file=file, group="leaf", key="variant")
        if leaf["arc_length"] >= 2 * math.pi * min(leaf["radius"], leaf["free_radius"]):
            raise InputError("arc_length must be shorter than the circle of the radius",
                             file=file, group="leaf", key="arc_length")
    elif "prestress" in effects:
        raise InputError("effect 'prestress' applies to &leaf scenes", file=file,
                         group="scene", key="effects")


def _check_spring(values: dict[str, dict[str, Any]], file: str) -> None:
    """The leaf spring (SPEC section 7): dynamics only, a consistent prestress and contact
    set-up."""
    scene, leaf, spring = values["scene"], values.get("leaf"), values["spring"]
    effects = scene["effects"]
    if leaf is None:
        raise InputError("a &spring scene needs the &leaf group (width, thickness, ...)",
                         file=file, group="leaf")
    for key in ("width", "thickness"):
        if leaf[key] is None:
            raise InputError("required key is missing", file=file, group="leaf", key=key)
    if scene["analysis"] != "dynamic":
        raise InputError("the leaf spring runs dynamics only (use a slow 'load_cycle' for "
                         "quasi-static loading)", file=file, group="scene", key="analysis")
    if leaf["prestress"]:
        if "prestress" not in effects:
            raise InputError("leaf.prestress = .true. needs the effect 'prestress' in "
                             "scene.effects", file=file, group="leaf", key="prestress")
        if leaf["free_radius"] is None:
            raise InputError("leaf.prestress needs leaf.free_radius (the lower leaf's "
                             "stress-free radius)", file=file, group="leaf", key="free_radius")
        if leaf["variant"] != "completed":
            raise InputError("prestress needs variant = 'completed'", file=file, group="leaf",
                             key="variant")
    if "friction" in effects and "contact" not in effects:
        raise InputError("effect 'friction' needs the effect 'contact'", file=file,
                         group="scene", key="effects")
    cycle = "load_cycle" in effects
    if cycle != (spring["cycle_force"] > 0):
        raise InputError("spring.cycle_force > 0 and the effect 'load_cycle' go together",
                         file=file, group="spring", key="cycle_force")
    if spring["lower_arc_length"] >= spring["main_arc_length"]:
        raise InputError("the lower leaf must be shorter than the main leaf", file=file,
                         group="spring", key="lower_arc_length")
