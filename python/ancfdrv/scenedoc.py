"""The scene reference ``docs/scenes.md``, generated from the schema (:mod:`ancfdrv.io.schema`)
and the general scenes' type tables: every group and key with its type, unit, default and
meaning, and which drive, joint and load type takes which parameters.

Regenerate after changing the schema (``tests/test_scenedoc.py`` fails until you do)::

    python -m ancfdrv.scenedoc -o docs/scenes.md
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path
from typing import Any

from .builders.general import _DRIVE_KEYS, _REQUIRED_DRIVE
from .io.parameters import FUNCTIONS, POINT_KEYS
from .io.schema import GENERAL_SCHEMA, MODEL_GROUPS, POINT_SCHEMA, REQUIRED, SCHEMA, Key
from .system.drives import DRIVE_TYPES
from .system.kinds.force_element import FORCE_ELEMENT_MEANING, FORCE_ELEMENT_PARAMETERS
from .system.joints import JOINT_TYPES
from .system.system import LOAD_EFFECTS, LOAD_PARAMETERS

#: the parameters each joint type takes (besides name, type, body1, body2), as
#: :class:`~ancfdrv.system.joints.Joint` checks them: (required, optional)
JOINT_PARAMETERS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "weld": (("point",), ()),
    "revolute": (("point", "axis"), ()),
    "spherical": (("point",), ()),
    "distance": (("point1", "point2"), ("drive",)),
    "prescribed": (("point", "drive", "axis"), ("pivot",)),
    "fix": (("point",), ("vector", "axis")),
    "arm": (("point", "axis", "pivot"), ()),
    "hub": (("point", "axis", "pivot", "drive"), ()),
    "prismatic": (("point", "axis"), ("drive",)),
    "cylindrical": (("point", "axis"), ()),
    "universal": (("point", "axis", "axis2"), ()),
}
JOINT_MEANING = {
    "weld": "positions coincide; body2's section or axes follow body1's at the point",
    "revolute": "positions coincide; relative rotation only about axis",
    "spherical": "positions coincide",
    "distance": "|p2 - p1| held, or following drive (a hydraulic cylinder's length)",
    "prescribed": "body2's point follows a rotation about pivot and axis by the drive's angle, "
                  "or without pivot a translation along axis by its value (body1: ground)",
    "fix": "body2's nodal vector (vector = 'r', 'r_x', 'r_y', 'r_z') held, or only its "
           "component along axis (body1: ground)",
    "arm": "the boom's support: the node on a massless arm hinged at pivot about axis",
    "hub": "a driven clamp: node and section turn with the drive about axis through pivot",
    "prismatic": "no relative rotation; body2's point slides along axis (carried by body1) "
                 "through point; with drive, the slide (p2 - p1) . axis follows the drive's "
                 "value minus its value at t = 0 (an actuator)",
    "cylindrical": "body2's point slides along axis through point and turns about it (axis "
                   "carried by body1)",
    "universal": "positions coincide; axis (on body1) stays normal to axis2 (on body2): a "
                 "Cardan joint's cross",
}
DRIVE_MEANING = {
    "constant": "phi = value",
    "luffing": "SPEC section 5's profile: smooth start (t_start), constant rate omega, smooth "
               "braking (t_brake); in degrees (start_deg, end_deg) or, as the Python API, in "
               "any unit (sweep, start; e.g. metres of a cylinder)",
    "spinup": "Simo & Vu-Quoc's spin-up to the rate omega in period s, from start",
    "cycle": "amplitude (1 - cos(2 pi (t - t0)/period))/2 on one period, 0 outside",
    "sine": "offset + amplitude r(t) sin(2 pi frequency (t - t0) + phase), r rising over ramp s",
    "table": "through (times, values) or a CSV file, held outside; interpolation 'linear' "
             "(default), 'cubic' (C2 spline) or 'pchip' (monotone), the cubic kinds with zero "
             "rate at both ends",
    "ramp": "from start (held until t0) the rate rises smoothly to rate over t_ramp s, then "
            "stays (continuous acceleration)",
}
#: the heading suffix of a template scene's group that general scenes also have
TEMPLATE_SUFFIX = " (template scenes)"
#: unit-looking parenthesised text in a key's meaning
_UNIT = re.compile(r"\(((?:[a-zA-Z]{1,3}(?:\^-?\d)?(?:[ /*][a-zA-Z]{1,3}(?:\^-?\d)?)*)|1)"
                   r"(?:[,;][^()]*)?\)")
_UNITS = {"m", "s", "Pa", "kg", "N", "J", "Hz", "rad", "deg", "W"}


def unit_of(key: Key) -> str:
    """The SI unit a key's meaning states in parentheses, e.g. '(m)', '(kg/m^3)'; '' when
    none (numbers without a unit, names, switches)."""
    for match in _UNIT.finditer(key.doc):
        text = match.group(1)
        symbols = re.findall(r"[a-zA-Z]+", text)
        if symbols and all(s in _UNITS for s in symbols):
            return text
    return ""


def _default(key: Key) -> str:
    if key.default is REQUIRED:
        return "**required**"
    if key.default is None:
        return "-"
    value = key.default
    if isinstance(value, bool):
        return ".true." if value else ".false."
    if isinstance(value, str):
        return f"'{value}'"
    if isinstance(value, list):
        return ", ".join(_default(Key(key.kind, v)) for v in value) if value else "(none)"
    return f"{value:g}" if isinstance(value, float) else str(value)


def _type(key: Key) -> str:
    kinds = {"float": "real", "int": "integer", "str": "string", "bool": "logical",
             "floats": "reals", "strs": "strings"}
    text = kinds[key.kind]
    if key.size:
        text += f" [{key.size}]"
    return text


def _cell(text: Any) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _meaning(spec: Key) -> str:
    """The key's meaning, with its choices when it takes one of a few words."""
    choices = getattr(spec.check, "choices", None)
    if choices:
        return f"{spec.doc}; one of {', '.join(repr(c) for c in choices)}"
    return spec.doc


def group_table(name: str, keys: dict[str, Key], suffix: str = "") -> list[str]:
    lines = [f"### `&{name}`{suffix}", "", "| key | type | unit | default | meaning |",
             "|---|---|---|---|---|"]
    for key, spec in keys.items():
        lines.append(f"| `{key}` | {_type(spec)} | {_cell(unit_of(spec)) or '-'} | "
                     f"{_cell(_default(spec))} | {_cell(_meaning(spec))} |")
    return lines + [""]


def drive_parameters() -> dict[str, tuple[tuple[str, ...], tuple[str, ...]]]:
    """(required, optional) parameters of each drive type, as the namelist reader
    (:mod:`ancfdrv.builders.general`) checks them."""
    out = {}
    for kind in DRIVE_TYPES:
        required = tuple(_REQUIRED_DRIVE.get(kind, ()))
        if kind == "table":
            out[kind] = (("times, values (or file)",), ("interpolation",))
        elif kind == "luffing":
            out[kind] = (("omega", "t_start", "t_brake", "start_deg, end_deg (or sweep)"),
                         ("start (with sweep)",))
        else:
            optional = tuple(k for k in _DRIVE_KEYS[kind] if k not in required)
            out[kind] = (required, optional)
    return out


def _type_table(title: str, parameters: dict, meaning: dict, extra: str = "") -> list[str]:
    lines = [f"### {title}", "", "| type | required | optional | meaning |",
             "|---|---|---|---|"]
    for kind, (required, optional) in parameters.items():
        lines.append(f"| `{kind}` | {_cell(', '.join(required)) or '-'} | "
                     f"{_cell(', '.join(optional)) or '-'} | {_cell(meaning.get(kind, ''))} |")
    return lines + ([""] + [extra] if extra else []) + [""]


def definitions() -> list[str]:
    """The section on ``&parameters``, expressions and ``&point`` (any scene)."""
    return [
        "## Parameters, expressions and named points (SPEC section 8.2)",
        "",
        "Any scene may define named numbers in `&parameters` groups (several allowed; each "
        "name once) and give any numeric key as a quoted expression over them: "
        "`end = 0.0, '$h + $L*sind($phi)', 0.0`. A parameter is written `$name` "
        "(case-insensitive) and may itself be an expression over the parameters defined "
        "before it. Expressions know numbers, `+ - * /`, `**` (right-associative, binding "
        "tighter than a unary minus on its left: `-2**2` is -4), parentheses, the constant "
        "`pi` and the functions " + ", ".join(f"`{f}`" for f in FUNCTIONS) + " (`sin`, "
        "`cos`, `tan` in radians, `sind`, `cosd`, `tand` in degrees). They are read by a "
        "small parser, never evaluated as code: any other name or character, a division by "
        "zero or a value that is not finite is an error (exit 2) naming file, group, key "
        "and the expression. `--set parameters.NAME=VALUE` and `ancf sweep --vary "
        "parameters.NAME=V1,V2,...` move every key that uses the parameter. The result "
        "file's root attributes `parameters` and `expressions` record each parameter's "
        "value and each key given by an expression or a point name, as written and as "
        "evaluated.",
        "",
        "`&parameters  L = 4.0, phi = 40.0, tip_x = '$L*cosd($phi)' /`",
        "",
        "A `&point` names a point once; a point key (" +
        ", ".join(f"`{k}`" for k in sorted(POINT_KEYS)) + ") of any group may give its "
        "name instead of x, y, z: `point = 'lug1'` (a joint's `point` may list several).",
        "",
        *group_table("point", POINT_SCHEMA),
    ]


def render() -> str:
    """The text of docs/scenes.md."""
    lines = [
        "# Scene reference",
        "",
        "<!-- generated by `python -m ancfdrv.scenedoc -o docs/scenes.md` from "
        "python/ancfdrv/io/schema.py and the kinds' keys (python/ancfdrv/system/kinds/); do not "
        "edit (tests/test_scenedoc.py compares) -->",
        "",
        "A scene is one Fortran namelist file (SPEC section 3). Unknown groups or keys, "
        "missing required keys and non-physical values are errors (exit 2) naming file, "
        "group and key. Units are SI. Lists are comma-separated (`start = 0.0, 1.0, 0.0`); "
        "strings are quoted; logicals are `.true.` / `.false.`. `--set GROUP.KEY=VALUE` "
        "overrides a key, `--set 'GROUP[name].KEY=VALUE'` a key of a named item.",
        "",
        "The `&solver` and `&output` keys are also the keywords of `System.static()` and "
        "`System.simulate()` in Python, with the same defaults.",
        "",
        *definitions(),
        "## General scenes (SPEC section 8)",
        "",
        "A scene without a template group is a general scene: `&scene`, `&solver`, "
        "`&output` once each, and any number of the named groups below, each one call of "
        "the Python `System` API (`System.material`, `.beam`, `.plate`, `.leaf`, "
        "`.rigid_body`, `.drive`, `.joint`, `.load`, `.contact`, `.probe`, `.force_element`) "
        "with the same "
        "parameters.",
        "",
    ]
    for group in ("scene", "solver", "output"):
        lines += group_table(group, SCHEMA[group])
    for group, keys in GENERAL_SCHEMA.items():
        lines += group_table(group, keys)
    lines += ["## Which type takes which parameters", ""]
    lines += _type_table("Drives (`&drive type = ...`)", drive_parameters(), DRIVE_MEANING)
    lines += _type_table("Joints (`&joint type = ...`; besides body1, body2)",
                         {k: JOINT_PARAMETERS[k] for k in JOINT_TYPES}, JOINT_MEANING,
                         "`point` may list several points (a multiple of 3 numbers): the "
                         "joint acts at each.")
    loads = {kind: (needs, ("drive",) if kind == "force" else ())
             for kind, needs in LOAD_PARAMETERS.items()}
    effects = {kind: f"effect default: '{LOAD_EFFECTS[kind]}'" for kind in LOAD_PARAMETERS}
    lines += _type_table("Loads (`&load type = ...`; optional `effect`)", loads, effects)
    lines += _type_table("Force elements (`&force_element type = ...`; besides body1, body2; "
                         "`System.force_element`)", FORCE_ELEMENT_PARAMETERS,
                         FORCE_ELEMENT_MEANING,
                         "A `spring_damper` takes `stiffness` (with `preload`) or the table "
                         "`deflections`, `forces` (with `interpolation`). Reactions are "
                         "stored under the element's name with the joints': force and moment "
                         "body1 exerts on body2, `axial` (tension positive).")
    lines += ["## Template scenes (SPEC section 3)", "",
              "A template scene has exactly one model group (" +
              ", ".join(f"`&{g}`" for g in MODEL_GROUPS) + ") and the common groups "
              "`&scene`, `&beam`/`&material`/`&loads` where the model uses them, `&solver`, "
              "`&output`.", ""]
    for group, keys in SCHEMA.items():
        if group in ("scene", "solver", "output"):
            continue
        lines += group_table(group, keys, TEMPLATE_SUFFIX if group in GENERAL_SCHEMA else "")
    return "\n".join(lines).rstrip() + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="write the scene reference (docs/scenes.md)")
    parser.add_argument("-o", "--output", help="file to write (default: standard output)")
    args = parser.parse_args(argv)
    text = render()
    if args.output:
        Path(args.output).write_text(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
