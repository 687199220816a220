"""The input rules a scene and its command line pass before anything is built.

:func:`ancfdrv.io.scene.load_scene` applies them in this order; each failure is an
:class:`~ancfdrv.errors.InputError` (exit status 2) naming the file, the group (``beam[boom]``
for a named group of a general scene) and the key:

1. **Groups and repeats in the text** (:func:`check_ended`, :func:`check_repeats`). f90nml
   silently drops a group that starts before the previous one ended (a missing ``/``), keeps
   the last of a repeated key and merges repeated groups, so the text itself is scanned (a
   small tokenizer of group and key names, :func:`scan_groups`; strings and comments are
   skipped, ``/``, ``&``, ``$``, ``&end`` and ``$end`` end a group as they do for f90nml): a
   group that starts inside another is an error naming both groups and the line, so is a
   group the text ends inside; a key given twice in one group is an error (with both line
   numbers), so is a group given twice, except the named, repeatable groups of general
   scenes (``&beam``, ``&joint``, ...).
2. **Command-line values** (:func:`parse_value`): ``--set GROUP.KEY=VALUE`` and each value
   of ``--vary`` must be ONE value of the key's type, written as in a namelist: a number, an
   integer, ``.true.``/``.false.``, a string (quoted, or unquoted without quotes, ``&``,
   ``=`` and ``!``; an unquoted string is taken literally, so ``output.file=runs/a.h5``
   works), or for list keys a comma-separated list of such items. Anything that would be
   namelist text (``7.791 / &beam nodes=7``) is refused. The same key given twice on the
   command line is refused (:func:`check_unique_overrides`).
3. **Types and ranges** (the schema, :mod:`ancfdrv.io.schema`): every integer must fit the
   kernel's 32-bit integers (:data:`INT32_MAX`), every real must be finite and at most
   :data:`MAX_MAGNITUDE` in magnitude (SI units), names of general scenes must be usable as
   HDF5 names and command-line addresses (:func:`check_name`).
4. **Time settings** of dynamic analyses (:func:`check_time`): ``t_end > 0``,
   ``MIN_DT <= dt <= t_end`` and ``t_end`` a whole number of steps (within a relative
   :data:`STEP_TOLERANCE`); otherwise the message names the nearest ``t_end`` values that
   fit. At most :data:`MAX_STEPS` steps.
5. **Size** (:func:`estimate_template`, :func:`estimate_general`, :func:`check_resources`):
   before anything is allocated, the model's memory is estimated from its coordinates and
   the sparse pattern's nonzeros per coordinate of each body type (beams 36, plates and
   leaves 81, rigid bodies 12) at :data:`BYTES_PER_NONZERO` bytes each (measured: 190 to 240
   bytes per nonzero through assembly, factorization and the first steps, for beams of 3,000
   and 12,000 nodes and plates of 30 x 30 and 60 x 60 elements), plus the contact points.
   It must stay below :data:`MEMORY_FRACTION` of the memory the machine has available
   (``/proc/meminfo`` MemAvailable, else ``os.sysconf``). A dynamic run is also refused when
   a lower bound of its time (:data:`SECONDS_PER_COORDINATE_STEP` per coordinate and step
   of each body type, several times faster than any run measured) exceeds
   :data:`MAX_RUN_SECONDS` (30 days).
"""
from __future__ import annotations

import math
import os
import re
from dataclasses import field
from pathlib import Path
from typing import Any, Iterable

from ..records import record
from ..errors import InputError

#: the kernel's integers are 32-bit (f2py passes Python ints as C int)
INT32_MAX = 2**31 - 1
#: the smallest time step accepted (s): 1 / (beta dt^2) must stay finite
MIN_DT = 1e-12
#: t_end must be a whole number of steps of dt within this relative tolerance
STEP_TOLERANCE = 1e-9
#: at most this many time steps in one run (well below the kernel's 32-bit counters)
MAX_STEPS = 10**8
#: lower bounds of the cost of one step per coordinate of each body type (s), a third to
#: a fifth of the fastest rates measured (the boom's beam with its constant FFR iteration
#: matrix: 3.1e-7 s; the plate pendulum and the leaf spring: 1.4e-5 and 2.4e-5 s)
SECONDS_PER_COORDINATE_STEP = {"beam": 1e-7, "plate": 3e-6, "leaf": 3e-6, "rigid_body": 1e-7}
#: runs whose lower-bound time estimate exceeds this are refused (30 days)
MAX_RUN_SECONDS = 30 * 86400.0
#: sparse-pattern nonzeros per coordinate of each body type (a beam node couples with its
#: two neighbours: 3 x 12; a plate node with its 8 neighbours: 9 x 9; a rigid body: 12)
NONZEROS_PER_COORDINATE = {"beam": 36, "plate": 81, "leaf": 81, "rigid_body": 12}
#: memory of the assembled model per pattern nonzero (bytes): the measured 190-240 bytes
#: rounded up
BYTES_PER_NONZERO = 300
#: memory per contact point (bytes): kernel state and the per-step output buffers
BYTES_PER_CONTACT_POINT = 4096
#: the interpreter, libraries and kernel before any model (bytes)
BASE_BYTES = 150 * 2**20
#: a run may use at most this fraction of the memory available now
MEMORY_FRACTION = 0.5


# -- 1. repeated groups and keys ---------------------------------------------------------

@record(eq=False)
class KeyText:
    """One ``key = `` of a group in the text."""

    name: str            # lower case, without an index
    index: str | None    # '(2)' of ``x(2) = ...``, normalized, or None
    line: int


@record(eq=False)
class GroupText:
    """One ``&group ... /`` of the text: its keys in order and the value of its ``name``."""

    name: str
    line: int
    keys: list[KeyText] = field(default_factory=list)
    item: str | None = None
    #: ended by '/', '&', '$', '&end' or '$end' (False: the next group or the end of the
    #: text came first)
    ended: bool = False

    @property
    def label(self) -> str:
        return f"{self.name}[{self.item}]" if self.item else self.name


_TOKEN = re.compile(r"""
    (?P<comment>![^\n]*)
  | (?P<string>'(?:[^']|'')*'|"(?:[^"]|"")*")
  | (?P<group>[&$][A-Za-z_]\w*)
  | (?P<end>/|[&$])
  | (?P<key>[A-Za-z_][\w%]*\s*(?:\([^()'"\n]*\))?\s*=(?!=))
  | (?P<newline>\n)
  | (?P<space>[ \t\r\f\v]+)
  | (?P<other>[^\s'"!/&$=]+|\S)
""", re.VERBOSE)


def _unquote(token: str) -> str:
    quote = token[0]
    return token[1:-1].replace(quote * 2, quote)


def scan_groups(text: str) -> list[GroupText]:
    """The groups of a namelist text with their keys (names and lines), in order.

    Text outside groups (comments, blank lines) is skipped; strings and comments never
    start or end a group. ``&end`` and ``$end`` end a group like ``/``."""
    groups: list[GroupText] = []
    current: GroupText | None = None
    line = 1
    expect_name = False
    for match in _TOKEN.finditer(text):
        kind, token = match.lastgroup, match.group()
        if kind == "newline":
            line += 1
            continue
        if kind == "comment" or kind == "space":
            continue
        if kind == "string":
            line += token.count("\n")
        if current is None:
            if kind == "group" and token[1:].lower() != "end":
                current = GroupText(token[1:].lower(), line)
                groups.append(current)
            continue
        if kind == "end" or (kind == "group" and token[1:].lower() == "end"):
            current.ended = True
            current, expect_name = None, False
            continue
        if kind == "group":  # a new group before the '/' of this one (check_ended)
            current = GroupText(token[1:].lower(), line)
            groups.append(current)
            continue
        if kind == "key":
            head = token[:-1].strip()
            name, _, rest = head.partition("(")
            index = "(" + re.sub(r"\s+", "", rest) if rest else None
            current.keys.append(KeyText(name.strip().lower(), index, line))
            expect_name = name.strip().lower() == "name" and index is None
            continue
        if expect_name and current.item is None:
            current.item = _unquote(token) if kind == "string" else token
        expect_name = False
    return groups


def check_ended(file: str, groups: list[GroupText]) -> None:
    """A group that starts before the previous one ended (f90nml drops the later group
    without a word), or a group the text ends inside, raises InputError naming the groups
    and the lines."""
    for group, after in zip(groups, groups[1:] + [None]):
        if group.ended:
            continue
        if after is None:
            raise InputError(f"line {group.line}: group &{group.name} has no '/' before the "
                             "end of the file (missing '/')", file=file)
        raise InputError(f"line {after.line}: group &{after.name} starts before group "
                         f"&{group.name} (line {group.line}) ended (missing '/'): a namelist "
                         f"reader would drop &{after.name} silently; end &{group.name} with "
                         "'/'", file=file)


def check_repeats(file: str, groups: list[GroupText], repeatable: Iterable[str]) -> None:
    """A key given twice in a group, or a group given twice that is not one of the
    ``repeatable`` groups, raises InputError with the lines of both."""
    repeatable = set(repeatable)
    first_line: dict[str, int] = {}
    for group in groups:
        seen: dict[tuple[str, str | None], int] = {}
        bare: dict[str, int] = {}
        indexed: dict[str, int] = {}
        for key in group.keys:
            clash = seen.get((key.name, key.index))
            if clash is None and key.index is None:
                clash = indexed.get(key.name)
            if clash is None and key.index is not None:
                clash = bare.get(key.name)
            if clash is not None:
                raise InputError(f"given twice in this group (lines {clash} and {key.line}); "
                                 "a namelist reader would silently keep the last: give it "
                                 "once", file=file, group=group.label, key=key.name)
            seen[(key.name, key.index)] = key.line
            (bare if key.index is None else indexed).setdefault(key.name, key.line)
        if group.name in repeatable:
            continue
        if group.name in first_line:
            raise InputError(f"group given twice (lines {first_line[group.name]} and "
                             f"{group.line}); a namelist reader would merge or drop values "
                             "silently: merge the two into one", file=file, group=group.name)
        first_line[group.name] = group.line


# -- 2. command-line values --------------------------------------------------------------

_REAL = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?")
_INTEGER = re.compile(r"[+-]?\d+")
_LOGICAL = {".true.": True, ".t.": True, "t": True, "true": True,
            ".false.": False, ".f.": False, "f": False, "false": False}
_QUOTED = re.compile(r"'(?:[^']|'')*'|\"(?:[^\"]|\"\")*\"")
_FORBIDDEN_UNQUOTED = set("'\"&=!")
_KIND_NAMES = {"float": "a number", "int": "an integer", "bool": ".true. or .false.",
               "str": "a string", "floats": "numbers separated by commas",
               "strs": "names separated by commas"}


def _bad(text: str, kind: str, where: dict, why: str = "") -> InputError:
    return InputError(f"the value {text!r} is not {_KIND_NAMES[kind]}"
                      + (f" ({why})" if why else "") + "; give one value of the key's type",
                      **where)


def _number(item: str, kind: str, text: str, where: dict) -> float:
    if not _REAL.fullmatch(item):
        raise _bad(text, kind, where)
    value = float(item.replace("d", "e").replace("D", "e"))
    if not math.isfinite(value):
        raise _bad(text, kind, where, "not finite")
    return value


def _string(item: str, kind: str, text: str, where: dict) -> str:
    if item[:1] in ("'", '"'):
        if not _QUOTED.fullmatch(item):
            raise _bad(text, kind, where, "a quoted string must be one string with nothing "
                       "after its closing quote")
        return _unquote(item)
    if _FORBIDDEN_UNQUOTED & set(item):
        raise _bad(text, kind, where, "an unquoted string must not contain quotes, '&', '=' "
                   "or '!': quote it")
    return item


def _split_list(text: str) -> list[str]:
    """Comma-separated items; commas inside quotes do not split."""
    items, start, quote = [], 0, ""
    for k, char in enumerate(text):
        if quote:
            if char == quote:
                quote = ""
        elif char in ("'", '"'):
            quote = char
        elif char == ",":
            items.append(text[start:k])
            start = k + 1
    items.append(text[start:])
    return [item.strip() for item in items]


def parse_value(kind: str, text: str, where: dict) -> Any:
    """One value of a key of the given kind ('float', 'int', 'bool', 'str', 'floats',
    'strs') from the command line, or InputError naming the key (see the module notes)."""
    raw = text
    text = text.strip()
    if any(ord(c) < 32 for c in text):
        raise _bad(raw, kind, where, "control characters")
    if kind == "float":
        return _number(text, kind, raw, where)
    if kind == "int":
        if _INTEGER.fullmatch(text):
            value = int(text)
        else:
            number = _number(text, kind, raw, where)
            if not number.is_integer():
                raise _bad(raw, kind, where)
            value = int(number)
        if abs(value) > INT32_MAX:
            raise InputError(f"{value} does not fit the kernel's 32-bit integers (at most "
                             f"{INT32_MAX})", **where)
        return value
    if kind == "bool":
        if text.lower() not in _LOGICAL:
            raise _bad(raw, kind, where)
        return _LOGICAL[text.lower()]
    if kind == "str":
        return _string(text, kind, raw, where)
    if kind == "floats":
        items = _split_list(text) if text else []
        if not items or any(not item for item in items):
            raise _bad(raw, kind, where)
        return [_number(item, kind, raw, where) for item in items]
    if kind == "strs":  # an empty value is the empty list ('effects=')
        items = [_string(item, kind, raw, where) for item in _split_list(text)] if text else []
        return [item.strip() for item in items if item.strip()]
    raise AssertionError(kind)


def check_unique_overrides(addresses: list[tuple[str, str | None, str, str]],
                           file: str) -> None:
    """(group, name, key, item) of each --set: the same key twice is refused."""
    seen: dict[tuple[str, str | None, str], str] = {}
    for group, name, key, item in addresses:
        address = (group, name, key)
        if address in seen:
            label = group if name is None else f"{group}[{name}]"
            raise InputError(f"given twice on the command line ({seen[address]!r} and "
                             f"{item!r}): give it once", file=file, group=label, key=key)
        seen[address] = item


# -- 3. integers -------------------------------------------------------------------------

def check_int32(value: int, where: dict) -> int:
    """An integer the kernel can take (32-bit), else InputError."""
    if abs(value) > INT32_MAX:
        raise InputError(f"{value} does not fit the kernel's 32-bit integers (at most "
                         f"{INT32_MAX})", **where)
    return value


#: the largest magnitude of a real input (SI units): beyond it products such as E I or a
#: squared length overflow; nothing the model describes comes near it
MAX_MAGNITUDE = 1e20


def check_magnitude(value: float, where: dict) -> float:
    """A real whose magnitude the model can handle, else InputError."""
    if abs(value) > MAX_MAGNITUDE:
        raise InputError(f"{value:g} is beyond the largest magnitude accepted "
                         f"({MAX_MAGNITUDE:g}; values are in SI units)", **where)
    return value


_NAME_FORBIDDEN = set("/[]")


def check_name(name: str) -> str | None:
    """Names of general scenes become HDF5 dataset names (probes) and command-line
    addresses (``beam[NAME].nodes``): no '/', '[' or ']', no control characters, not '.'
    or '..'. Returns the problem or None (a schema check)."""
    if not name:
        return "must not be empty"
    if _NAME_FORBIDDEN & set(name) or any(ord(c) < 32 for c in name) or name in (".", ".."):
        return "must not contain '/', '[', ']' or control characters, nor be '.' or '..'"
    return None


# -- 4. time settings --------------------------------------------------------------------

def _g(x: float) -> str:
    return f"{x:.12g}"


def steps_of(dt: float, t_end: float) -> int:
    """The number of steps of a run (t_end a whole number of steps, after check_time)."""
    return int(round(t_end / dt))


def _dt_min_problem(dt_min: float, dt: float) -> str:
    return (f"dt_min = {_g(dt_min)} s is longer than dt = {_g(dt)} s: the smallest step a "
            "step is cut to cannot exceed the step (dt_min = dt: no cuts; 0: dt / 1024)")


def check_time(solver: dict[str, Any], analysis: str, file: str) -> None:
    """t_end > 0, MIN_DT <= dt <= t_end, dt_min <= dt, t_end a whole number of steps, at
    most MAX_STEPS steps (dynamic analyses only)."""
    if analysis not in ("dynamic", "static+dynamic"):
        return
    dt, t_end = solver["dt"], solver["t_end"]
    where = dict(file=file, group="solver")
    if t_end <= 0:
        raise InputError(f"t_end = {_g(t_end)} s: a {analysis} analysis needs t_end > 0",
                         **where, key="t_end")
    if dt < MIN_DT:
        raise InputError(f"dt = {dt:g} s is below the smallest step accepted ({MIN_DT:g} s)",
                         **where, key="dt")
    if dt > t_end:
        raise InputError(f"dt = {_g(dt)} s is longer than t_end = {_g(t_end)} s: the run "
                         "would make no step", **where, key="dt")
    if solver.get("dt_min", 0.0) > dt:
        raise InputError(_dt_min_problem(solver["dt_min"], dt), **where, key="dt_min")
    ratio = t_end / dt
    if ratio > MAX_STEPS:
        raise InputError(f"t_end / dt = {ratio:.3g} steps; at most {MAX_STEPS:.0e} steps are "
                         "accepted: raise dt or shorten t_end", **where, key="dt")
    n = round(ratio)
    if abs(n * dt - t_end) > STEP_TOLERANCE * t_end:
        below, above = math.floor(ratio) * dt, math.ceil(ratio) * dt
        raise InputError(f"t_end = {_g(t_end)} s is not a whole number of steps of dt = "
                         f"{_g(dt)} s ({ratio:.6g} steps): use t_end = {_g(below)} or "
                         f"{_g(above)} s, or a dt that divides t_end (t_end / "
                         f"{math.ceil(ratio)} = {_g(t_end / math.ceil(ratio))} s)",
                         **where, key="t_end")


# -- 5. size -------------------------------------------------------------------------------

@record(eq=False)
class Part:
    """A part of the model for the estimate: where it is given and its size."""

    label: str            # 'beam', 'plate[p]'
    key: str              # the key that sets its size ('nodes', 'nx')
    kind: str             # a key of NONZEROS_PER_COORDINATE
    nodes: int
    per_node: int         # coordinates per node
    #: its elements keep section forces and stresses at output.stations (a beam's): the
    #: output memory (:func:`output_bytes`)
    sections: bool = False


@record(eq=False)
class Estimate:
    """The size of a model before it is built."""

    parts: list[Part]
    contact_points: int = 0

    @property
    def coordinates(self) -> int:
        return sum(p.nodes * p.per_node for p in self.parts)

    @property
    def nonzeros(self) -> int:
        return sum(p.nodes * p.per_node * NONZEROS_PER_COORDINATE[p.kind] for p in self.parts)

    @property
    def seconds_per_step(self) -> float:
        """A lower bound of the time of one step (s)."""
        return sum(p.nodes * p.per_node * SECONDS_PER_COORDINATE_STEP[p.kind]
                   for p in self.parts)

    @property
    def memory_bytes(self) -> int:
        return (BASE_BYTES + BYTES_PER_NONZERO * self.nonzeros
                + BYTES_PER_CONTACT_POINT * self.contact_points)

    def largest(self) -> Part:
        return max(self.parts, key=lambda p: p.nodes * p.per_node)


def _grid(nx: int, ny: int) -> int:
    return (nx + 1) * (ny + 1)


def estimate_template(values: dict[str, dict[str, Any]], kind: str) -> Estimate:
    """The size of a template scene's model (after the schema checks)."""
    if kind in ("boom", "cantilever", "spinup"):
        return Estimate([Part("beam", "nodes", "beam", values["beam"]["nodes"], 12, True)])
    if kind in ("plate", "leaf"):
        v = values[kind]
        return Estimate([Part(kind, "nx", "plate", _grid(v["nx"], v["ny"]), 9)])
    if kind == "spring":
        spring, leaf = values["spring"], values["leaf"]
        ny = leaf["ny"]
        return Estimate([Part("spring", "main_nx", "leaf", _grid(spring["main_nx"], ny), 9),
                         Part("spring", "lower_nx", "leaf", _grid(spring["lower_nx"], ny), 9),
                         Part("spring", "chassis", "rigid_body", 2, 12)],
                        contact_points=2 * spring["contact_points"])
    raise AssertionError(kind)


def estimate_general(items: list[tuple[str, dict[str, Any]]]) -> Estimate:
    """The size of a general scene's model from its typed items."""
    parts, points = [], 0
    for group, v in items:
        label = f"{group}[{v['name']}]"
        if group == "beam":
            parts.append(Part(label, "nodes", "beam", v["nodes"], 12, True))
        elif group == "cable":  # half a beam node's coordinates, a beam's coupling (and, as
            # a beam's, its elements' share of the section output memory)
            parts.append(Part(label, "nodes", "beam", v["nodes"], 6, True))
        elif group in ("plate", "leaf"):
            parts.append(Part(label, "nx", group, _grid(v["nx"], v["ny"]), 9))
        elif group == "rigid_body":
            parts.append(Part(label, "mass", "rigid_body", 1, 12))
        elif group == "contact":
            points += 2 * v["points"]  # on the two end edges of body2
    return Estimate(parts, contact_points=points)


def available_memory() -> int:
    """Memory available to a new process now (bytes): MemAvailable of /proc/meminfo (free
    plus reclaimable caches), else the free physical pages (os.sysconf); at most what the
    process's own limits leave (:func:`limit_memory`: ``ulimit -v``, a cgroup)."""
    return min(_machine_memory(), limit_memory())


def limit_memory() -> int:
    """Memory the process may still take under its address-space limit (RLIMIT_AS, less
    what it maps now) and its cgroup's memory.max (less the cgroup's current use); a very
    large number when neither is set."""
    room = 2**63 - 1
    try:
        import resource
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY:
            mapped = 0
            with open("/proc/self/status") as status:
                for line in status:
                    if line.startswith("VmSize:"):
                        mapped = int(line.split()[1]) * 1024
            room = min(room, max(soft - mapped, 0))
    except (OSError, ValueError, ImportError):
        pass
    try:
        with open("/sys/fs/cgroup/memory.max") as f:
            text = f.read().strip()
        if text != "max":  # the cgroup's whole budget (its page cache is reclaimable)
            room = min(room, int(text))
    except (OSError, ValueError):
        pass
    return room


def _machine_memory() -> int:
    try:   # the file's bytes in one read (a text file read line by line took 3x longer)
        descriptor = os.open("/proc/meminfo", os.O_RDONLY)
        try:
            data = os.read(descriptor, 1 << 16)
        finally:
            os.close(descriptor)
        for line in data.splitlines():
            if line.startswith(b"MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return 2**63 - 1  # unknown: no memory limit


def _bytes(n: float) -> str:
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n / 1e3:.3g} kB"


def check_resources(estimate: Estimate, file: str, solver: dict[str, Any] | None,
                    analysis: str, available: int | None = None) -> None:
    """Refuse a model whose estimated memory exceeds MEMORY_FRACTION of the available
    memory, or a dynamic run whose lower-bound time estimate exceeds MAX_RUN_SECONDS; the
    message names the part, the key, the estimate and the limit."""
    if not estimate.parts:
        return
    part = estimate.largest()
    for p in estimate.parts:  # the kernel numbers coordinates with 32-bit integers
        if p.nodes * p.per_node > INT32_MAX:
            raise InputError(f"{p.nodes:,} nodes ({p.nodes * p.per_node:,} coordinates) "
                             f"exceed the kernel's 32-bit numbering", file=file,
                             group=p.label, key=p.key)
    available = available_memory() if available is None else available
    limit = MEMORY_FRACTION * available
    need = estimate.memory_bytes
    if need > limit:
        raise InputError(
            f"the model is too large for this machine: about {_bytes(need)} of memory "
            f"({estimate.coordinates:,} coordinates, {estimate.nonzeros:,} matrix nonzeros, "
            f"{part.label} the largest part with {part.nodes:,} nodes), the limit is "
            f"{_bytes(limit)} ({MEMORY_FRACTION:.0%} of the {_bytes(available)} available): "
            "use a coarser mesh", file=file, group=part.label, key=part.key)
    if solver is None or analysis not in ("dynamic", "static+dynamic"):
        return
    steps = steps_of(solver["dt"], solver["t_end"])
    seconds = steps * estimate.seconds_per_step
    if seconds > MAX_RUN_SECONDS:
        raise InputError(
            f"{steps:,} steps of {estimate.coordinates:,} coordinates would take at least "
            f"{seconds / 86400:.3g} days (at {estimate.seconds_per_step:.3g} s per step, "
            "several times faster than any run measured); the limit is "
            f"{MAX_RUN_SECONDS / 86400:.3g} days: raise dt, shorten t_end or use a coarser "
            "mesh", file=file, group="solver", key="dt")


#: memory of the section forces and stresses per beam element and output station (bytes):
#: measured 1.2 to 2.4 kB at the peak of the static answers of a 9-element beam with 100
#: and 1000 stations, either formulation, rounded up
BYTES_PER_STATION = 4096
#: memory of one dynamic row of output.sections per element and station: N, T, Q, M
#: (12 doubles), kept until the run ends and joined once (twice that)
BYTES_PER_SECTION_ROW = 2 * 12 * 8


def output_bytes(estimate: Estimate, output: dict[str, Any], solver: dict[str, Any] | None,
                 analysis: str) -> int:
    """The memory the beams' section forces and stresses take (``output.stations`` points
    per element, and with ``output.sections`` every row of a dynamic run): bytes."""
    elements = sum(max(p.nodes - 1, 1) for p in estimate.parts if p.sections)
    stations = int(output.get("stations", 3))
    need = BYTES_PER_STATION * elements * stations
    if (output.get("sections") and solver is not None
            and analysis in ("dynamic", "static+dynamic")):
        rows = steps_of(solver["dt"], solver["t_end"]) + 1
        need += BYTES_PER_SECTION_ROW * elements * stations * rows
    return need


def check_output_memory(estimate: Estimate, output: dict[str, Any], file: str,
                        solver: dict[str, Any] | None, analysis: str,
                        available: int | None = None) -> None:
    """Refuse, before anything is allocated, output whose memory (:func:`output_bytes`)
    with the model's (:attr:`Estimate.memory_bytes`) exceeds MEMORY_FRACTION of the
    available memory; the message names output.stations, the estimate and the limit."""
    need = output_bytes(estimate, output, solver, analysis)
    if not need:
        return
    available = available_memory() if available is None else available
    limit = MEMORY_FRACTION * available
    if need + estimate.memory_bytes > limit:
        stations = int(output.get("stations", 3))
        rows = (" and output.sections at every step" if output.get("sections")
                and analysis in ("dynamic", "static+dynamic") else "")
        raise InputError(
            f"{stations:,} stations per beam element{rows} need about {_bytes(need)} of "
            f"memory for the section forces and stresses (with the model's "
            f"{_bytes(estimate.memory_bytes)}), the limit is {_bytes(limit)} "
            f"({MEMORY_FRACTION:.0%} of the {_bytes(available)} available): use fewer "
            "stations (3, the default, gives both ends and the middle of each element)",
            file=file, group="output", key="stations")


# -- 6. arguments of the solver functions (the Python API's door) -------------------------

def _plain_number(value: Any) -> Any:
    try:
        import numpy as np
        if isinstance(value, np.generic):
            return value.item()
    except ImportError:  # pragma: no cover
        pass
    return value


def check_arguments(function: str, **values: Any) -> dict[str, Any]:
    """The keyword arguments of a solver function checked at its entry (InputError naming
    the function and the argument): ``tol`` a finite number > 0, ``max_iter``,
    ``load_steps``, ``max_newton`` and ``chunk_steps`` integers >= 1 within 32 bits,
    ``loads`` and ``p`` finite numbers, ``dt`` at least MIN_DT, ``dt_min`` >= 0 and at most
    ``dt``, ``t_end`` finite and > 0, at most MAX_STEPS steps. Returns the values as
    plain Python numbers."""
    out = {}
    for key, raw in values.items():
        value = _plain_number(raw)
        name = f"{function}: {key}"
        if key in ("max_iter", "load_steps", "max_newton", "chunk_steps", "max_inner"):
            if isinstance(value, bool) or not isinstance(value, int):
                raise InputError(f"{name}: expected an integer >= 1, got {value!r}")
            if value < 1:
                raise InputError(f"{name} = {value} must be at least 1")
            check_int32(value, {})
        else:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise InputError(f"{name}: expected a number, got {value!r}")
            value = float(value)
            if not math.isfinite(value):
                raise InputError(f"{name}: expected a finite number, got {value!r}")
            if key in ("tol", "inner_tol") and value <= 0:
                raise InputError(f"{name} = {value:g} must be positive")
            if key == "dt_min" and value < 0:
                raise InputError(f"{name} = {value:g} s must be 0 (dt / 1024) or positive")
            if key == "dt" and value < MIN_DT:
                raise InputError(f"{function}: dt = {value:g} s is below the smallest step "
                                 f"accepted ({MIN_DT:g} s)")
            if key == "t_end" and value <= 0:
                raise InputError(f"{function}: t_end = {value:g} s must be positive")
        out[key] = value
    if "dt" in out and "dt_min" in out and out["dt_min"] > out["dt"]:
        raise InputError(f"{function}: {_dt_min_problem(out['dt_min'], out['dt'])}")
    if "dt" in out and "t_end" in out and out["t_end"] / out["dt"] > MAX_STEPS:
        raise InputError(f"{function}: t_end / dt = {out['t_end'] / out['dt']:.3g} steps; at "
                         f"most {MAX_STEPS:.0e} steps are accepted")
    return out


def check_path(value: Any, argument: str) -> Path:
    """A file path given to the Python API (a scene, ``output=``, ``Results.save(path)``,
    ``ancfdrv.open(path)``): a str or os.PathLike, else InputError naming the argument
    and what it got (a number, None, bytes, an empty or NUL-bearing name)."""
    def short_repr(thing: Any, limit: int = 60) -> str:   # (schema.short_repr's cut)
        text = repr(thing)
        return text if len(text) <= limit else text[:limit - 4] + "..." + text[-1]
    expected = f"{argument}: expected a file path (a str or pathlib.Path), got"
    if isinstance(value, (bytes, bytearray)):
        raise InputError(f"{expected} bytes {short_repr(bytes(value))} (decode it: "
                         "os.fsdecode(path))")
    if not isinstance(value, (str, os.PathLike)):
        raise InputError(f"{expected} "
                         f"{'None' if value is None else type(value).__name__ + ' '}"
                         f"{'' if value is None else short_repr(value)}")
    try:
        path = Path(value)
    except TypeError:  # an os.PathLike whose __fspath__ gives bytes
        raise InputError(f"{expected} {type(value).__name__} {short_repr(value)}") from None
    if "\x00" in str(path):
        raise InputError(f"{argument}: the file name {short_repr(str(path))} contains a NUL "
                         "character")
    if isinstance(value, str) and not value.strip():
        raise InputError(f"{argument}: the file name is empty")
    return path


def check_state(function: str, key: str, value: Any, size: int):
    """A state vector given to a solver (e0, v0): ``size`` finite numbers, else InputError
    (before it reaches the compiled kernel)."""
    import numpy as np
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{function}: {key}: expected {size} numbers, got "
                         f"{type(value).__name__}") from None
    if array.shape != (size,):
        raise InputError(f"{function}: {key}: expected a vector of the model's {size} "
                         f"coordinates, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{function}: {key} must be finite numbers")
    return array


# -- 7. physical bounds of drives and loads (absurd but finite input) ----------------------

#: the largest magnitude accepted for each quantity of a drive or a load (SI units), with
#: what it stands for; beyond it the input is almost surely a typo or a unit slip. A scene
#: lifts them with ``&scene bounds = 'off'`` (``ancf run --force``), the Python API with
#: ``System(..., bounds='off')``.
PHYSICAL_BOUNDS: dict[str, tuple[float, str, str]] = {
    "angular_rate": (1e4, "rad/s", "about 95,000 rpm, beyond the fastest turbines"),
    "frequency": (1e5, "Hz", "far above any structural mode a beam or plate model resolves"),
    "acceleration": (1e4, "m/s^2", "about 1000 g"),
    "force": (1e10, "N", "the weight of a million tonnes"),
    "moment": (1e10, "N m", "a million tonnes on a 1 m arm"),
    "mass": (1e8, "kg", "a hundred thousand tonnes"),
    "pressure": (1e10, "Pa", "10 GPa, beyond the strength of any structural material"),
    "stiffness": (1e12, "N/m", "a steel bar of 1 m^2 section 0.2 m long; stiffer is a joint"),
    "rotational_stiffness": (1e12, "N m/rad", "a steel shaft of 1 m diameter 0.01 m long"),
    "damping": (1e10, "N s/m", "a force of 10 GN at 1 m/s"),
    "rotational_damping": (1e10, "N m s/rad", "a moment of 10 GN m at 1 rad/s"),
}
#: the smallest nonzero magnitude accepted for a quantity (SI units), with what it stands
#: for: a spring softer than this carries nothing a structure weighs (a box of 2 kg on
#: a spring of 1e-300 N/m hung 2e301 m down), a body smaller than this is not one the
#: beam and plate models describe (a 1 nm beam's modes are 8e11 Hz); 0 stays allowed where
#: the key allows it (no spring). Lifted with the other bounds (``scene.bounds = 'off'``).
PHYSICAL_MINIMA: dict[str, tuple[float, str, str]] = {
    "stiffness": (1e-3, "N/m", "1 mN per metre, softer than any spring that carries a load"),
    "rotational_stiffness": (1e-6, "N m/rad", "1 micro-N m per radian"),
    "length": (1e-3, "m", "1 mm; a shorter body's modes pass the frequency bound, 1e5 Hz"),
    "section": (1e-5, "m", "10 micrometres, thinner than kitchen foil"),
}
#: how a bound is lifted (for the messages)
BOUNDS_OVERRIDE = ("scene.bounds = 'off' (ancf run --force) or System(..., bounds='off')")


def check_bound(quantity: str, value: float, what: str, key: str | None = None) -> None:
    """InputError naming ``what``, the value and the bound when |value| exceeds the
    physical bound of ``quantity`` (:data:`PHYSICAL_BOUNDS`); ``key``: the key it is
    given by."""
    limit, unit, meaning = PHYSICAL_BOUNDS[quantity]
    if abs(value) > limit:
        raise InputError(f"{what} = {value:g} {unit} is beyond the physical bound for "
                         f"{quantity.replace('_', ' ')}, {limit:g} {unit} ({meaning}); "
                         f"if this is meant, lift the bounds: {BOUNDS_OVERRIDE}", key=key)


def check_minimum(quantity: str, value: float, what: str, key: str | None = None) -> None:
    """InputError naming ``what``, the value and the bound when 0 < |value| is below the
    smallest physical magnitude of ``quantity`` (:data:`PHYSICAL_MINIMA`); ``key``: the
    key it is given by."""
    limit, unit, meaning = PHYSICAL_MINIMA[quantity]
    if 0.0 < abs(value) < limit:
        raise InputError(f"{what} = {value:g} {unit} is below the smallest physical "
                         f"{quantity.replace('_', ' ')} accepted, {limit:g} {unit} ({meaning}); "
                         f"if this is meant, lift the bounds: {BOUNDS_OVERRIDE}", key=key)
