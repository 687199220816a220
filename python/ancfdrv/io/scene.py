"""Scenes: Fortran namelist files, parsed with f90nml and validated against a schema.

Every group and key a scene may use is declared in :data:`SCHEMA` with its type, default,
physical range and a one-line meaning. Unknown groups or keys, missing required keys,
wrong sizes and non-physical values raise :class:`~ancfdrv.errors.InputError` naming the
file, the group and the key (exit status 2 on the command line).
"""
from __future__ import annotations

import errno
import io
import math
import os
import re
import stat
from collections import Counter, OrderedDict
from dataclasses import field
from functools import partial
from pathlib import Path
from typing import Any, Callable

import f90nml

from ..records import record
from .. import _lazy
from ..errors import InputError
from . import validate
from .parameters import CONSTANTS, POINT_KEYS, Definitions, ExpressionError
from .schema import (COMMON_GROUPS, DEFINITION_GROUPS, EFFECTS_AVAILABLE, EFFECTS_PLANNED,
                     GENERAL_ONLY_GROUPS, GENERAL_SCHEMA, GENERAL_SINGLE_GROUPS, MODEL_GROUPS,
                     PLATE_KINDS, POINT_SCHEMA, REQUIRED, SCHEMA, Key, checked_value)

__all__ = ["Scene", "load_scene", "parse_address", "is_general", "SCHEMA", "GENERAL_SCHEMA",
           "EFFECTS_AVAILABLE", "MODEL_GROUPS", "PLATE_KINDS"]


@record
class Scene:
    """A validated scene: typed values per group, the source path and namelist text."""

    path: Path
    values: dict[str, dict[str, Any]]
    text: str
    overrides: list[str] = field(default_factory=list)
    #: general scenes: the named groups in file order (group, typed values)
    items: list[tuple[str, dict[str, Any]]] | None = None
    #: general scenes: what the builder returned when :func:`load_scene` checked the scene
    #: (a :class:`~ancfdrv.builders.common.BuiltSystem`), taken by the first
    #: :func:`ancfdrv.builders.build_system` so that a scene is built once
    built: Any = field(default=None, repr=False, compare=False)
    #: the &parameters' values (lower-case names), overrides applied
    parameters: dict[str, float] = field(default_factory=dict)
    #: each key given by an expression or a point name: 'address = as written => value'
    expressions: list[str] = field(default_factory=list)

    @property
    def kind(self) -> str:
        """The model the scene builds: one of MODEL_GROUPS, or 'general'."""
        if self.items is not None:
            return "general"
        if "spring" in self.values:  # its &leaf group describes the leaf pack
            return "spring"
        return next(g for g in MODEL_GROUPS if g in self.values)

    @property
    def input_files(self) -> list[Path]:
        """Files the scene reads besides itself (the CSV files of table drives)."""
        out = []
        for group, values in self.items or []:
            if group == "drive" and values.get("file"):
                out.append(self.resolve(values["file"]))
        if self.kind == "spring" and self.values["spring"]["road"] == "table":
            out.append(self.resolve(self.values["spring"]["road_file"]))
        return out

    def resolve(self, name: str | Path) -> Path:
        """A file named in the scene: absolute, or relative to the scene file."""
        path = Path(name)
        return path if path.is_absolute() else self.path.parent / path

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


def _scene_text(scene: Scene) -> str:
    """The namelist text (a str; given as a function of no arguments it is written at the
    first read: :func:`load_scene` hands over its namelist's writer, so a run kept in
    memory that never saves a file does not write the text, ~0.1 ms)."""
    text = scene.__dict__["_text"]
    if callable(text):
        text = scene.__dict__["_text"] = text()
    return text


def _set_scene_text(scene: Scene, text: str | Callable[[], str]) -> None:
    scene.__dict__["_text"] = text


# the dataclass's field `text` read and set through the property (__init__, ==, repr and
# dataclasses.replace all read the text)
Scene.text = property(_scene_text, _set_scene_text)  # type: ignore[assignment]


#: the builder of general scenes: ``effects_of(items)`` (the effects the items belong to)
#: and ``build(scene)`` (the System, built dry: every name, reference and value checked).
#: :mod:`ancfdrv.builders.general` registers them; it sits above this reader, which imports
#: nothing of the layers above it (``import ancfdrv`` always loads the builders).
GENERAL_BUILDER: dict[str, Callable[..., Any]] = {}


#: the tokens of the namelists :func:`fast_reads` reads (anything else: f90nml)
#: (spaces and comments before a token are skipped by the expression itself: one match,
#: one turn of the reader's loop, per token; a match of them alone, at the end of the
#: text, has no group)
_FAST_TOKEN = re.compile(r"""
    (?:\s+|![^\n]*)*
    (?:
        (?P<string>'(?:[^'\n]|'')*'|"(?:[^"\n]|"")*")
      | (?P<group>&[A-Za-z_]\w*)
      | (?P<end>/)
      | (?P<key>[A-Za-z_]\w*)[ \t]*=(?!=)
      | (?P<comma>,)
      | (?P<word>[^\s'"!/&$=,()*%]+)
      | (?P<other>.)
    )?
""", re.VERBOSE | re.DOTALL)
_FAST_INT = re.compile(r"[+-]?\d+\Z")
_FAST_FLOAT = re.compile(r"[+-]?(?:\d+\.\d*|\.\d+|\d+(?=[eEdD]))(?:[eEdD][+-]?\d+)?\Z")
_FAST_LOGICAL = {".true.": True, ".t.": True, ".false.": False, ".f.": False}
_DICT_CONTAINS, _DICT_SET = OrderedDict.__contains__, OrderedDict.__setitem__
#: a new f90nml Namelist's attributes (what its __init__ sets: output settings, cogroups,
#: start indices), taken from one made at import
_NAMELIST_STATE = dict(vars(f90nml.Namelist()))
#: those of its attributes that are dicts (each Namelist has its own)
_NAMELIST_DICTS = tuple(k for k, v in _NAMELIST_STATE.items() if type(v) is dict)


def _new_namelist() -> f90nml.Namelist:
    """An empty ``f90nml.Namelist()``: the same type and attributes (each dict of them a
    new one, as __init__ makes them), without __init__'s work (platform look-ups, property
    setters; a scene has one Namelist per group)."""
    nml = OrderedDict.__new__(f90nml.Namelist)
    OrderedDict.__init__(nml)
    state = nml.__dict__
    state.update(_NAMELIST_STATE)
    for key in _NAMELIST_DICTS:
        state[key] = dict(_NAMELIST_STATE[key])
    return nml


def _fast_value(kind: str, token: str) -> Any:
    """A value token as f90nml's parser converts it (int, float, logical, string); a
    token outside these plain forms raises ValueError."""
    if kind == "string":
        return token[1:-1].replace(token[0] * 2, token[0])
    if _FAST_INT.match(token):
        return int(token)
    if _FAST_FLOAT.match(token):
        return float(token.lower().replace("d", "e"))
    logical = _FAST_LOGICAL.get(token.lower())
    if logical is None:
        raise ValueError(token)
    return logical


def fast_reads(text: str) -> f90nml.Namelist | None:
    """The namelist ``f90nml.reads(text)`` returns, for the plain namelists scenes are
    written in (groups ``&name ... /``; ``key = value`` or ``key = v1, v2, ...`` with
    integer, real, logical and quoted string values; comments), built with f90nml's own
    Namelist the way its parser builds it, in a single regular-expression pass (f90nml's
    parser took ~0.4 ms of each scene load). None for anything else (indexed or derived
    keys, repeat counts, complex or null values, unquoted strings, a key given twice,
    text outside the groups, ...): the caller then reads the text with f90nml."""
    nml = _new_namelist()
    group: f90nml.Namelist | None = None
    name = key = None
    values: list[Any] = []
    after_value = False   # the last token was a value (a comma may follow)

    def close_key() -> bool:
        if key is None:
            return True
        lower = key.lower()
        # f90nml's `lower in group` and `group[key] = value` for a group's plain values
        # (no cogroups inside a group; a scalar or a list of scalars is stored as it is,
        # under the lower-case key), without their per-call type checks
        if not values or _DICT_CONTAINS(group, lower):
            return False
        _DICT_SET(group, lower, values[0] if len(values) == 1 else list(values))
        return True
    for match in _FAST_TOKEN.finditer(text):
        kind = match.lastgroup
        if kind is None:   # spaces and comments at the end of the text
            continue
        token = match.group(kind)
        if group is None:
            if kind != "group":
                return None
            name, group = token[1:], _new_namelist()
            if name.lower() == "end":
                return None
            key, values, after_value = None, [], False
            continue
        if kind == "key":   # (null values, 'a = 1, , b = 2', end at the comma branch)
            if not close_key():
                return None
            key, values, after_value = match.group("key"), [], False
        elif kind == "end":
            if (key is not None and not after_value) or not close_key():
                return None
            lower = name.lower()
            # f90nml's `name in nml` and `nml[name] = group` for a Namelist value (stored
            # under the lower-case name), without their per-call type checks
            if _DICT_CONTAINS(nml, lower) or lower in nml._cogroups:
                nml.add_cogroup(name, group)
            else:
                _DICT_SET(nml, lower, group)
            group = key = None
        elif kind == "comma":
            if not after_value:
                return None
            after_value = False
        elif kind in ("string", "word"):
            if key is None or after_value:
                return None
            try:
                values.append(_fast_value(kind, token))
            except ValueError:
                return None
            after_value = True
        else:
            return None
    return nml if group is None else None


#: f90nml's output settings that :func:`namelist_text` reproduces (its defaults)
_PLAIN_OUTPUT = dict(_column_width=72, _indent="    ", _end_comma=False, _uppercase=False,
                     _float_format="", _index_spacing=False, _assign_spacing=True,
                     _repeat_counter=False, _split_strings=False)
_PLAIN_LOGICAL = {False: ".false.", True: ".true."}


def _plain_text(nml: f90nml.Namelist) -> str | None:
    """What ``nml.write`` writes, for namelists of plain groups (scalars and one-line
    lists of logicals, integers, reals and strings; f90nml's default output settings),
    built directly (f90nml's writer took a quarter of a scene load); None otherwise."""
    if any(getattr(nml, k, v) != v for k, v in _PLAIN_OUTPUT.items()) or \
            nml.logical_repr != _PLAIN_LOGICAL or nml.default_start_index is not None:
        return None
    lines: list[str] = []
    for key, group in OrderedDict.items(nml):
        if not isinstance(group, f90nml.Namelist) or group.start_index:
            return None
        if lines:
            lines.append("")
        lines.append("&" + _cogroup_name(key))
        for name, value in OrderedDict.items(group):
            values = value if type(value) is list else (value,)
            texts = []
            for item in values:
                kind = type(item)
                if kind is bool:
                    texts.append(_PLAIN_LOGICAL[item])
                elif kind is int or kind is float:
                    texts.append(str(item))    # f90nml: str() and format(x, '')
                elif kind is str:
                    texts.append(f90nml.Namelist._f90str(nml, item))
                else:
                    return None
            if not texts:
                return None
            line = "    " + name + " = " + ", ".join(texts)
            if len(texts) > 1 and len(line) >= 72:   # f90nml wraps such a list
                return None
            lines.append(line.rstrip())
        lines.append("/")
    return "\n".join(lines) + "\n" if lines else ""


def _cogroup_name(key: str) -> str:
    """A group's name from f90nml's key (a repeated group's keys are _grp_<name>_<i>)."""
    return key[5:].rsplit("_", 1)[0] if key.startswith("_grp_") else key


def namelist_text(nml: f90nml.Namelist) -> str:
    """The namelist as f90nml writes it (:func:`_plain_text` where it applies)."""
    text = _plain_text(nml)
    if text is None:
        buffer = io.StringIO()
        nml.write(buffer)
        text = buffer.getvalue()
    return text


def _parse_override_value(kind: str, text: str, where: dict) -> Any:
    """Parse the VALUE of --set GROUP.KEY=VALUE: one value of the key's type, written as
    in a namelist (:func:`ancfdrv.io.validate.parse_value`)."""
    return validate.parse_value(kind, text, where)


def is_general(nml: f90nml.Namelist) -> bool:
    """A general scene (SPEC section 8): no template model group; &beam, &plate, &leaf and
    &material then carry names."""
    # (the names of f90nml's keys view: each key's cogroup name)
    groups = set(map(_cogroup_name, OrderedDict.keys(nml)))
    if groups & {"boom", "cantilever", "spinup", "spring", "loads"}:
        return False
    if groups & set(GENERAL_ONLY_GROUPS):
        return True
    return any(_has_name(nml[g]) for g in ("beam", "plate", "leaf", "material") if g in nml)


def _has_name(entries) -> bool:
    items = entries if isinstance(entries, list) else [entries]
    return any("name" in e for e in items)


def parse_address(dotted: str) -> tuple[str, str | None, str]:
    """'group.key' or 'group[name].key' -> (group, name or None, key) (lower-case group and
    key; the name as written)."""
    head, _, key = dotted.strip().rpartition(".")
    if not head or not key:
        raise ValueError(f"{dotted!r} is not GROUP.KEY or GROUP[NAME].KEY")
    name = None
    if head.endswith("]") and "[" in head:
        head, _, rest = head.partition("[")
        name = rest[:-1].strip().strip("'\"")
        if not name:
            raise ValueError(f"{dotted!r}: empty name in GROUP[NAME]")
    return head.strip().lower(), name, key.strip().lower()


def _instances(nml: f90nml.Namelist, group: str) -> list:
    if group not in nml:
        return []
    entries = nml[group]
    return list(entries) if isinstance(entries, list) else [entries]


def _apply_override(nml: f90nml.Namelist, item: str, general: bool, file: str) -> str:
    """Apply --set GROUP.KEY=VALUE or GROUP[NAME].KEY=VALUE to the namelist."""
    if "=" not in item:
        raise InputError(f"override {item!r} is not of the form GROUP.KEY=VALUE", file=file)
    dotted, value = item.split("=", 1)
    try:
        group, name, key = parse_address(dotted)
    except ValueError as exc:
        raise InputError(f"override {item!r}: {exc}", file=file) from None
    if group == "parameters":
        _override_parameter(nml, item, name, key, value, file)
        return f"{dotted.strip()}={value.strip()}"
    schema = _schema_of(group, general)
    label = group if name is None else f"{group}[{name}]"
    where = dict(file=file, group=label, key=key)
    if schema is None:
        raise InputError(f"unknown group in override {item!r}", file=file, group=group)
    if key not in schema:
        raise InputError(f"unknown key in override {item!r}; known keys: {', '.join(schema)}",
                         **where)
    parsed = _parse_override_value(schema[key].kind, value, where)
    instances = _instances(nml, group)
    if name is not None:
        if not general or group in GENERAL_SINGLE_GROUPS:
            raise InputError(f"override {item!r}: only the repeated groups of general scenes "
                             "are addressed by name", **where)
        matches = [e for e in instances if str(e.get("name", "")).strip() == name]
        if not matches:
            known = ", ".join(repr(str(e.get("name"))) for e in instances) or "none"
            raise InputError(f"override {item!r}: no &{group} named {name!r} (names: {known})",
                             **where)
        matches[0][key] = parsed
    elif len(instances) > 1:
        raise InputError(f"override {item!r}: &{group} occurs {len(instances)} times; address "
                         f"one by name, e.g. {group}[NAME].{key}", **where)
    elif instances:
        instances[0][key] = parsed
    else:
        nml[group] = f90nml.Namelist({key: parsed})
    return f"{dotted.strip()}={value.strip()}"


def _override_parameter(nml: f90nml.Namelist, item: str, name: str | None, key: str,
                        value: str, file: str) -> None:
    """--set parameters.NAME=VALUE: the &parameters group that defines NAME takes the
    number (every key whose expression uses it follows)."""
    where = dict(file=file, group="parameters", key=key)
    if name is not None:
        raise InputError(f"override {item!r}: a parameter is addressed as parameters.NAME",
                         **where)
    parsed = validate.parse_value("float", value, where)
    instances = _instances(nml, "parameters")
    for instance in instances:
        if key in instance:
            instance[key] = parsed
            return
    known = ", ".join(k for i in instances for k in i) or "none"
    raise InputError(f"override {item!r}: the scene defines no parameter {key!r} "
                     f"(parameters: {known})", **where)


def _definitions(nml: f90nml.Namelist, file: str) -> Definitions:
    """The scene's &parameters (in file order: each a number or an expression over the
    earlier ones) and named &point groups."""
    defs = Definitions()
    for instance in _instances(nml, "parameters"):
        for key, raw in instance.items():
            where = dict(file=file, group="parameters", key=key)
            if key in defs.parameters:
                raise InputError("the parameter is defined twice (each name once, in any "
                                 "&parameters group)", **where)
            if type(raw) is str:
                try:
                    value = defs.number(raw)
                except ExpressionError as exc:
                    raise InputError(f"expression {raw!r}: {exc}", **where) from None
            else:
                value = checked_value(Key("float"), raw, where)
            defs.parameters[key] = value
    for instance in _instances(nml, "point"):
        name = str(instance.get("name", "")).strip()
        label = f"point[{name}]" if name else "point"
        typed = _typed("point", label, instance, POINT_SCHEMA, file, defs=defs)
        if typed["name"] in defs.points:
            raise InputError(f"the name {typed['name']!r} is used twice", file=file,
                             group=label, key="name")
        defs.points[typed["name"]] = typed["at"]
    return defs


#: the key kinds whose values may be expressions
_NUMERIC_KINDS = frozenset(("float", "floats", "int"))
#: a bare word: in a key that is not a point key not an expression but a wrong value (the
#: type's message: 'expected a number')
_WORD = re.compile(r"\s*([A-Za-z_]\w*)\s*\Z")


def _resolved(defs: Definitions, spec: Key, label: str, key: str, raw: Any,
              where: dict[str, Any]) -> Any:
    """A numeric key's raw value with its expressions and point names replaced (the value
    as it came where it holds neither)."""
    if spec.kind not in _NUMERIC_KINDS:
        return raw
    if type(raw) is str:
        word = _WORD.match(raw)
        if word and key not in POINT_KEYS and word.group(1).lower() not in CONSTANTS:
            return raw   # (refused by the type's check)
    elif type(raw) is not list or str not in map(type, raw):
        return raw
    if key in POINT_KEYS:
        for item in (raw if type(raw) is list else [raw]):
            word = _WORD.match(item) if type(item) is str else None
            if word and item.strip() not in defs.points and \
                    word.group(1).lower() not in CONSTANTS:
                known = ", ".join(map(repr, defs.points)) or "none"
                raise InputError(f"unknown point {item.strip()!r} (named points: {known})",
                                 **where)
    try:
        return defs.resolve(f"{label}.{key}", key, raw)
    except ExpressionError as exc:
        raise InputError(str(exc), **where) from None


def _schema_of(group: str, general: bool) -> dict[str, Key] | None:
    if general:
        if group in GENERAL_SINGLE_GROUPS:
            return SCHEMA[group]
        return GENERAL_SCHEMA.get(group)
    return SCHEMA.get(group)


def _typed(group: str, label: str, entries, schema: dict[str, Key], file: str,
           plain: bool = False, defs: Definitions | None = None) -> dict[str, Any]:
    """Coerce and check one group's entries against its schema; fill the defaults.
    ``plain``: a group of a namelist :func:`fast_reads` read (lower-case keys that are no
    cogroup keys): its items read as the dict's own (f90nml's items view makes an NmlKey
    and calls Namelist.__getitem__ per key: the same keys as str, the same values).
    ``defs``: the scene's parameters and points, which the numeric keys' expressions and
    point names are evaluated with (recorded in ``defs.record``)."""
    typed: dict[str, Any] = {}
    for key, raw in (OrderedDict.items(entries) if plain else entries.items()):
        where = dict(file=file, group=label, key=key)
        if key not in schema:
            raise InputError(f"unknown key; known keys of &{group}: {', '.join(schema)}", **where)
        spec = schema[key]
        if defs is not None:
            raw = _resolved(defs, spec, label, key, raw, where)
        typed[key] = checked_value(spec, raw, where)
    for key, spec in schema.items():
        if key not in typed:
            if spec.default is REQUIRED:
                raise InputError("required key is missing", file=file, group=label, key=key)
            typed[key] = spec.default
    return typed


#: the errors of os.stat that Path.exists and Path.is_file take for "no such file"
_MISSING = (errno.ENOENT, errno.ENOTDIR, errno.EBADF, errno.ELOOP)


def _read_text(path: Path, file: str) -> str:
    # one stat (as Path.exists then Path.is_file decided: missing, then not regular)
    try:
        status = os.stat(path)
    except OSError as exc:
        if exc.errno not in _MISSING:
            raise
        raise InputError("scene file not found", file=file) from None
    except ValueError:   # (an embedded null byte: Path.exists says False)
        raise InputError("scene file not found", file=file) from None
    if not stat.S_ISREG(status.st_mode):
        raise InputError("the scene is not a regular file", file=file)
    try:
        with open(path, "rb") as handle:   # (Path.read_bytes without pathlib's layers)
            data = handle.read()
    except OSError as exc:
        raise InputError(f"cannot read the scene file: {exc.strerror}", file=file) from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"not a text file (byte {exc.start} is not UTF-8)", file=file) from None


def _override_addresses(overrides: list[str], file: str) -> None:
    """The same GROUP.KEY (or GROUP[NAME].KEY) given twice on the command line."""
    addresses = []
    for item in overrides:
        dotted = item.split("=", 1)[0]
        try:
            group, name, key = parse_address(dotted)
        except ValueError:
            continue  # reported when the override is applied
        addresses.append((group, name, key, item))
    validate.check_unique_overrides(addresses, file)


def load_scene(path: str | Path, overrides: list[str] | None = None) -> Scene:
    """Read, override and validate a scene file (template or general). Raises InputError
    on any problem; every rule is applied before anything is built (the rules:
    :mod:`ancfdrv.io.validate`)."""
    path = path if type(path) is str else validate.check_path(path, "scene")
    path = Path(path)
    file = str(path)
    text = _read_text(path, file)
    # a plain namelist (fast_reads) has every group ended before the next one starts and no
    # key twice in a group (fast_reads declines both): any other text is scanned
    groups = None
    nml = plain = fast_reads(text)  # ours: None for what it does not read, never raises
    if nml is None:  # not one of the plain forms fast_reads reads
        groups = validate.scan_groups(text)
        try:
            nml = f90nml.reads(text)
        except Exception as exc:  # f90nml raises several types
            if groups and all(g.ended for g in groups[:-1]) and not groups[-1].ended:
                validate.check_ended(file, groups)  # the text ends inside its last group
            message = str(exc).strip().splitlines()[0] if str(exc).strip() else \
                type(exc).__name__
            raise InputError(f"not a valid Fortran namelist: {message}", file=file) from None
        validate.check_ended(file, groups)
    general = is_general(nml)
    if general and not GENERAL_BUILDER:
        # the kinds' groups (GENERAL_SCHEMA) and the builder register themselves when
        # imported: a reader used before anything imported them loads them by name
        _lazy.load("general_builder")
    repeatable = (*GENERAL_SCHEMA, *DEFINITION_GROUPS) if general else DEFINITION_GROUPS
    # (in a plain namelist the text is scanned for its lines only when a group that may not
    # repeat does)
    if plain is None or any(count > 1 and name not in repeatable for name, count in
                            Counter(map(_cogroup_name, OrderedDict.keys(nml))).items()):
        validate.check_repeats(file, groups if groups is not None else validate.scan_groups(text),
                               repeatable)
    _override_addresses(overrides or [], file)
    seen: Counter = Counter()
    # a repeated group comes once per occurrence (f90nml's items view: each key's cogroup
    # name)
    for group in map(_cogroup_name, OrderedDict.keys(nml)):
        if group in DEFINITION_GROUPS:
            continue
        if _schema_of(group, general) is None:
            known = [*GENERAL_SCHEMA, *GENERAL_SINGLE_GROUPS] if general else [*SCHEMA]
            known += DEFINITION_GROUPS
            raise InputError(f"unknown group in a {'general' if general else 'template'} scene; "
                             f"known groups: {', '.join(known)}", file=file, group=group)
        seen[group] += 1
        repeatable = general and group not in GENERAL_SINGLE_GROUPS
        if seen[group] > 1 and not repeatable:
            raise InputError("group given more than once (merge the two into one)", file=file,
                             group=group)

    applied = [_apply_override(nml, item, general, file) for item in overrides or []]
    defs = _definitions(nml, file)
    if general:
        return _general_scene(path, nml, applied, defs)

    values: dict[str, dict[str, Any]] = {}
    # (no group repeats here but the definitions': refused above; a plain namelist's groups
    # read as its dict's)
    fast = plain is not None
    for group, entries in (OrderedDict.items(nml) if fast else nml.items()):
        if _cogroup_name(group) in DEFINITION_GROUPS:
            continue
        values[group] = _typed(group, group, entries, SCHEMA[group], file, fast, defs)

    models = [g for g in MODEL_GROUPS if g in values]
    if "spring" in models and "leaf" in models:  # &leaf: the spring's leaf pack
        models.remove("leaf")
    if len(models) != 1:
        raise InputError(f"a scene needs exactly one of the groups "
                         f"{', '.join('&' + g for g in MODEL_GROUPS)} (found "
                         f"{', '.join('&' + g for g in models) or 'none'}), or is a general scene "
                         "(named &beam, &plate, &leaf, &rigid_body, &joint, ... groups; SPEC "
                         "section 8)", file=file)
    kind = models[0]
    if kind in PLATE_KINDS and "beam" in values:
        raise InputError(f"&beam does not apply to a &{kind} scene", file=file, group="beam")
    for group in COMMON_GROUPS + (() if kind in PLATE_KINDS else ("beam",)):
        if group not in values:
            if any(spec.default is REQUIRED for spec in SCHEMA[group].values()):
                raise InputError("required group is missing", file=file, group=group)
            values[group] = {k: s.default for k, s in SCHEMA[group].items()}
    _check_consistency(values, file, kind)
    validate.check_time(values["solver"], values["scene"]["analysis"], file)
    _check_template_sizes(values, file)
    estimate = validate.estimate_template(values, kind)
    validate.check_resources(estimate, file, values["solver"], values["scene"]["analysis"])
    validate.check_output_memory(estimate, values["output"], file, values["solver"],
                                 values["scene"]["analysis"])
    _check_eigen_bounds(values, file)
    return Scene(path=path, values=values, text=partial(namelist_text, nml), overrides=applied,
                 parameters=defs.parameters, expressions=defs.record)


def _general_scene(path: Path, nml: f90nml.Namelist, applied: list[str],
                   defs: Definitions) -> Scene:
    """Validate a general scene: the single groups, then every named item in file order
    (their expressions and point names evaluated with ``defs``); the System is built once
    (dry) so that every name and value is checked now."""
    file = str(path)
    values: dict[str, dict[str, Any]] = {}
    items: list[tuple[str, dict[str, Any]]] = []
    names: dict[str, set[str]] = {}
    for group, entries in nml.items():
        if group in DEFINITION_GROUPS:
            continue
        for instance in (entries if isinstance(entries, list) else [entries]):
            if group in GENERAL_SINGLE_GROUPS:
                values[group] = _typed(group, group, instance, SCHEMA[group], file, defs=defs)
                continue
            name = str(instance.get("name", "")).strip()
            label = f"{group}[{name}]" if name else group
            typed = _typed(group, label, instance, GENERAL_SCHEMA[group], file, defs=defs)
            if typed["name"] in names.setdefault(group, set()):
                raise InputError(f"the name {typed['name']!r} is used twice", file=file,
                                 group=label, key="name")
            names[group].add(typed["name"])
            items.append((group, typed))
    for group in GENERAL_SINGLE_GROUPS:
        if group not in values:
            values[group] = {k: s.default for k, s in SCHEMA[group].items()}
    if not any(g in ("beam", "cable", "plate", "leaf", "rigid_body") for g, _ in items):
        raise InputError("a general scene needs at least one body (&beam, &cable, &plate, "
                         "&leaf or &rigid_body)", file=file)
    listed = "effects" in nml.get("scene", {})
    scene = Scene(path=path, values=values, text=partial(namelist_text, nml),
                  overrides=applied, items=items, parameters=defs.parameters,
                  expressions=defs.record)
    if not GENERAL_BUILDER and not _lazy.load("general_builder"):
        raise RuntimeError("no general scene builder: import ancfdrv (the package)")
    effects_of = GENERAL_BUILDER["effects_of"]
    if not listed:
        values["scene"]["effects"] = sorted(effects_of(items))
    _check_general(values, file, {e for e in effects_of(items)})
    validate.check_time(values["solver"], values["scene"]["analysis"], file)
    estimate = validate.estimate_general(items)
    validate.check_resources(estimate, file, values["solver"], values["scene"]["analysis"])
    validate.check_output_memory(estimate, values["output"], file, values["solver"],
                                 values["scene"]["analysis"])
    _check_eigen_bounds(values, file)
    scene.built = GENERAL_BUILDER["build"](scene)  # every name, reference and value checked
    return scene


#: the lengths of template scenes held to ``validate.PHYSICAL_MINIMA`` (group, key, quantity)
TEMPLATE_SIZES = (("beam", "length", "length"), ("beam", "width", "section"),
                  ("beam", "height", "section"), ("plate", "length_x", "length"),
                  ("plate", "length_y", "length"), ("plate", "thickness", "section"),
                  ("leaf", "arc_length", "length"), ("leaf", "width", "section"),
                  ("leaf", "thickness", "section"))


def _check_template_sizes(values: dict[str, dict[str, Any]], file: str) -> None:
    """A template scene's lengths and sections above the physical minima
    (``validate.PHYSICAL_MINIMA``; lifted by ``scene.bounds = 'off'``)."""
    if values["scene"].get("bounds", "check") != "check":
        return
    for group, key, quantity in TEMPLATE_SIZES:
        value = (values.get(group) or {}).get(key)
        if value is None:
            continue
        try:
            validate.check_minimum(quantity, value, key)
        except InputError as exc:
            raise InputError(str(exc), file=file, group=group, key=key) from None


def _check_eigen_bounds(values: dict[str, dict[str, Any]], file: str) -> None:
    """``modal.spin_rate`` within the physical bound of an angular rate
    (``validate.PHYSICAL_BOUNDS``; lifted by ``scene.bounds = 'off'``)."""
    if values["scene"].get("bounds", "check") != "check" or "modal" not in values:
        return
    try:
        validate.check_bound("angular_rate", values["modal"].get("spin_rate", 0.0),
                             "spin_rate")
    except InputError as exc:
        raise InputError(str(exc), file=file, group="modal", key="spin_rate") from None


def _check_general(values: dict[str, dict[str, Any]], file: str, used: set[str]) -> None:
    scene = values["scene"]
    for effect in scene["effects"]:
        if effect in EFFECTS_PLANNED:
            raise InputError(f"effect {effect!r} is not available in this version", file=file,
                             group="scene", key="effects")
        if effect not in EFFECTS_AVAILABLE and effect not in used:
            raise InputError(f"unknown effect {effect!r}: neither a known effect "
                             f"({', '.join(EFFECTS_AVAILABLE)}) nor one an item of the scene "
                             "belongs to", file=file, group="scene", key="effects")


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
    if scene["formulation"] == "nonlinear" and scene["analysis"] in ("static", "static+dynamic"):
        if values["solver"]["static_method"] == "split":
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
    if boom and scene["analysis"] in ("dynamic", "static+dynamic") and boom["omega"] > 0:
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
    if scene["analysis"] not in ("dynamic", "modal"):
        raise InputError("the leaf spring runs dynamics only, or analysis = 'modal' (use a "
                         "slow 'load_cycle' for quasi-static loading)", file=file,
                         group="scene", key="analysis")
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
    if spring["road"] == "sine" and spring["road_amplitude"] <= 0:
        raise InputError("road = 'sine' needs road_amplitude > 0 (m)", file=file,
                         group="spring", key="road_amplitude")
    if spring["road"] == "table" and not spring["road_file"]:
        raise InputError("road = 'table' needs road_file (a CSV of t, z rows)", file=file,
                         group="spring", key="road_file")
    if spring["road"] != "none" and spring["guide"] == "vertical" and cycle:
        raise InputError("a road input and a load cycle are separate experiments: set one",
                         file=file, group="spring", key="road")
