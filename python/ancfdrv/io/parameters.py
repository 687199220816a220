"""Scene parameters: arithmetic expressions over named numbers, parsed by a small recursive
descent parser (never ``eval``), and the ``&parameters`` and ``&point`` groups that define
them (SPEC section 8.2).

An expression is a quoted string in a numeric key: ``end = 0.0, '$h + $L*sind($phi)', 0.0``.
It knows numbers (``2``, ``1.5``, ``.5``, ``1e-3``, ``1.0d0``), parameters written ``$name``
(case-insensitive, as namelist keys are), the constant ``pi``, ``+ - * /``, ``**`` (binds
tighter than unary minus on its left and is right-associative: ``-2**2 = -4``,
``2**3**2 = 512``), parentheses and the functions of :data:`FUNCTIONS` (``sin``, ``cos``,
``tan`` in radians, ``sind``, ``cosd``, ``tand`` in degrees, ``sqrt``, ``abs``). Any other
name, call, attribute or character is refused with :class:`ExpressionError`; so are a
division by zero, a square root of a negative number and a value that is not finite.

A point named once (``&point name = 'lug1', at = x, y, z /``) stands for its three
coordinates in every point-valued key (:data:`POINT_KEYS`): ``point = 'lug1'``.
"""
from __future__ import annotations

import math
import re
from dataclasses import field
from typing import Any, Callable
from ..records import record

__all__ = ["ExpressionError", "FUNCTIONS", "POINT_KEYS", "Definitions", "evaluate"]


class ExpressionError(Exception):
    """An expression that cannot be evaluated; the message says why (without the place,
    which the scene reader adds)."""


def _sqrt(x: float) -> float:
    if x < 0:
        raise ExpressionError(f"sqrt of the negative number {x:g}")
    return math.sqrt(x)


#: the functions an expression may call: one argument each
FUNCTIONS: dict[str, Callable[[float], float]] = {
    "sqrt": _sqrt, "abs": abs,
    "sin": math.sin, "cos": math.cos, "tan": math.tan,
    "sind": lambda x: math.sin(math.radians(x)),
    "cosd": lambda x: math.cos(math.radians(x)),
    "tand": lambda x: math.tan(math.radians(x)),
}
#: the named constants
CONSTANTS = {"pi": math.pi}
#: keys whose value is a point (three coordinates, or several points for a joint's
#: ``point``): a string there that names a ``&point`` stands for its coordinates
POINT_KEYS = frozenset(("start", "end", "point", "point1", "point2", "pivot", "frame_pivot",
                        "corner", "centre", "position", "spin_centre", "at"))
#: the longest expression and the deepest nesting accepted
MAX_CHARACTERS = 1000
MAX_DEPTH = 50

_TOKEN = re.compile(r"""\s*(?:
    (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?)
  | \$(?P<parameter>[A-Za-z_]\w*)
  | (?P<name>[A-Za-z_]\w*)
  | (?P<op>\*\*|[-+*/()])
  | (?P<other>\S)
)""", re.VERBOSE)


def _tokens(text: str) -> list[tuple[str, str, int]]:
    """(kind, text, position) of each token; ('end', '', len) last."""
    out = []
    position = 0
    while True:
        match = _TOKEN.match(text, position)
        if match is None or match.lastgroup is None:   # only spaces are left
            out.append(("end", "", len(text)))
            return out
        kind = match.lastgroup
        out.append((kind, match.group(kind), match.start(kind)))
        position = match.end()


class _Parser:
    """expr := term (('+' | '-') term)*;  term := unary (('*' | '/') unary)*;
    unary := ('+' | '-') unary | power;  power := atom ('**' unary)?;
    atom := number | $name | pi | function '(' expr ')' | '(' expr ')'."""

    def __init__(self, text: str, parameters: dict[str, float]) -> None:
        self.text, self.parameters = text, parameters
        self.tokens = _tokens(text)
        self.index = 0
        self.depth = 0

    def peek(self) -> tuple[str, str, int]:
        return self.tokens[self.index]

    def take(self) -> tuple[str, str, int]:
        token = self.tokens[self.index]
        self.index += 1
        return token

    def fail(self, token: tuple[str, str, int], expected: str) -> ExpressionError:
        kind, text, position = token
        got = "the end" if kind == "end" else repr(text)
        return ExpressionError(f"syntax error at character {position + 1}: expected "
                               f"{expected}, found {got}")

    def parse(self) -> float:
        value = self.expr()
        if self.peek()[0] != "end":
            raise self.fail(self.peek(), "an operator")
        return value

    def expr(self) -> float:
        value = self.term()
        while self.peek()[1] in ("+", "-") and self.peek()[0] == "op":
            op = self.take()[1]
            right = self.term()
            value = value + right if op == "+" else value - right
        return value

    def term(self) -> float:
        value = self.unary()
        while self.peek()[1] in ("*", "/") and self.peek()[0] == "op":
            op = self.take()[1]
            right = self.unary()
            if op == "*":
                value = value * right
            elif right == 0:
                raise ExpressionError("division by zero")
            else:
                value = value / right
        return value

    def unary(self) -> float:
        if self.peek()[0] == "op" and self.peek()[1] in ("+", "-"):
            op = self.take()[1]
            value = self.nested(self.unary)
            return -value if op == "-" else value
        return self.power()

    def power(self) -> float:
        base = self.atom()
        if self.peek()[0] == "op" and self.peek()[1] == "**":
            self.take()
            exponent = self.nested(self.unary)
            try:
                return _finite(math.pow(base, exponent))
            except OverflowError:
                raise ExpressionError(f"({base:g})**({exponent:g}) overflows") from None
            except ValueError:   # (math.pow: a negative base to a fractional power)
                raise ExpressionError(f"({base:g})**({exponent:g}) is not a real number") \
                    from None
        return base

    def nested(self, rule: Callable[[], float]) -> float:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ExpressionError(f"nested more than {MAX_DEPTH} deep")
        try:
            return rule()
        finally:
            self.depth -= 1

    def atom(self) -> float:
        token = self.take()
        kind, text, _ = token
        if kind == "number":
            return float(text.lower().replace("d", "e"))
        if kind == "parameter":
            name = text.lower()
            if name not in self.parameters:
                known = ", ".join(sorted(self.parameters)) or "none defined"
                raise ExpressionError(f"unknown parameter ${name} (parameters: {known})")
            return self.parameters[name]
        if kind == "name":
            name = text.lower()
            if name in CONSTANTS:
                return CONSTANTS[name]
            if name not in FUNCTIONS:
                raise ExpressionError(
                    f"unknown name {text!r} (a parameter is written $name; the functions are "
                    f"{', '.join(FUNCTIONS)}; the constant is pi)")
            if self.peek()[1] != "(":
                raise self.fail(self.peek(), f"'(' after the function {name}")
            self.take()
            argument = self.nested(self.expr)
            if self.peek()[1] != ")":
                raise self.fail(self.peek(), "')'")
            self.take()
            try:
                return _finite(FUNCTIONS[name](argument))
            except (ValueError, OverflowError):   # (math's domain errors)
                raise ExpressionError(f"{name}({argument:g}) is not defined") from None
        if kind == "op" and text == "(":
            value = self.nested(self.expr)
            if self.peek()[1] != ")":
                raise self.fail(self.peek(), "')'")
            self.take()
            return value
        raise self.fail(token, "a number, a $parameter, pi, a function or '('")


def _finite(value: float) -> float:
    if not math.isfinite(value):
        raise ExpressionError(f"the value {value} is not finite")
    return value


def evaluate(text: str, parameters: dict[str, float]) -> float:
    """The value of an expression over ``parameters`` (lower-case names -> values); raises
    :class:`ExpressionError` on a syntax error, an unknown name, a division by zero or a
    value that is not finite."""
    if len(text) > MAX_CHARACTERS:
        raise ExpressionError(f"longer than {MAX_CHARACTERS} characters")
    if not text.strip():
        raise ExpressionError("empty expression")
    try:
        return _finite(_Parser(text, parameters).parse())
    except OverflowError:   # (a product or sum beyond the largest float: inf, caught above)
        raise ExpressionError("the value overflows") from None


def _written(value: Any) -> str:
    """A key's value as written in the namelist (strings quoted)."""
    items = value if isinstance(value, list) else [value]
    return ", ".join(repr(x) if isinstance(x, str) else str(x) for x in items)


@record(eq=False)
class Definitions:
    """A scene's parameters and named points, and a record of every key whose value used
    them (what the result file stores)."""

    parameters: dict[str, float] = field(default_factory=dict)
    points: dict[str, list[float]] = field(default_factory=dict)
    #: 'address = written => value' of each key given by an expression or a point name
    record: list[str] = field(default_factory=list)

    def number(self, text: str) -> float:
        """One expression's value (ExpressionError on any problem)."""
        return evaluate(text, self.parameters)

    def resolve(self, address: str, key: str, raw: Any) -> Any:
        """A key's raw namelist value with each expression replaced by its value and, in a
        point key, each point name by its coordinates; the value as it came when it holds
        neither. Raises ExpressionError naming the expression."""
        items = raw if isinstance(raw, list) else [raw]
        if not any(type(x) is str for x in items):
            return raw
        out: list[Any] = []
        for item in items:
            if type(item) is not str:
                out.append(item)
            elif key in POINT_KEYS and item.strip() in self.points:
                out.extend(self.points[item.strip()])
            else:
                try:
                    out.append(self.number(item))
                except ExpressionError as exc:
                    raise ExpressionError(f"expression {item!r}: {exc}") from None
        resolved = out if isinstance(raw, list) or len(out) != 1 else out[0]
        self.record.append(f"{address} = {_written(raw)} => {_written(resolved)}")
        return resolved
