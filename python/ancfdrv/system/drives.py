"""Drives: prescribed functions of time phi(t) (with phi', phi'' in closed form, evaluated
by the kernel, ``fortran/src/system/drives.f90``) that move joints, turn floating frames and
scale loads.

- :class:`Constant` phi = value;
- :class:`Luffing` the luffing profile of SPEC section 5 (smooth start, constant rate,
  smooth braking) from ``start`` by ``sweep`` radians at ``omega`` rad/s;
- :class:`SpinUp` the spin-up of Simo & Vu-Quoc to the speed ``omega`` in ``period`` s;
- :class:`Cycle` a load cycle amplitude (1 - cos(2 pi (t - t0) / period)) / 2 on one period;
- :class:`Sine` offset + amplitude r(t) sin(2 pi f (t - t0) + phase) with a smooth ramp-in r
  over ``ramp`` seconds;
- :class:`Table` (t, value) pairs, linear in between, constant outside (from a CSV file with
  :meth:`Table.from_csv`); its rate jumps at the points, so prefer smooth drives for
  prescribed motion.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import kernel
from ..codes import DRIVE_CONSTANT, DRIVE_CYCLE, DRIVE_LUFFING, DRIVE_SINE, DRIVE_SPINUP, DRIVE_TABLE
from ..errors import InputError


class Drive:
    """Base of the drives: a name, the kernel kind and its parameters."""

    name: str
    kind: int

    def params(self) -> list[float]:
        raise NotImplementedError

    def values(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """phi, phi', phi'' at the times t (the kernel's evaluation)."""
        return kernel.drive_values(self.kind, self.params(), np.atleast_1d(t))

    def value(self, t: float) -> float:
        return float(self.values([t])[0][0])

    def check(self) -> None:
        """Raise InputError when the parameters are not physical (the kernel's test)."""
        try:
            self.values([0.0])
        except InputError as exc:
            raise InputError(f"drive {self.name!r}: {exc}") from None


@dataclass
class Constant(Drive):
    name: str
    value_: float = 0.0
    kind = DRIVE_CONSTANT

    def params(self) -> list[float]:
        return [float(self.value_)]


@dataclass
class Luffing(Drive):
    """SPEC section 5: rate omega (rad/s, sign gives the direction), smooth start over
    t_start, braking over t_brake, total ``sweep`` (rad) from the angle ``start``."""

    name: str
    omega: float
    t_start: float
    t_brake: float
    sweep: float
    start: float = 0.0
    kind = DRIVE_LUFFING

    def params(self) -> list[float]:
        return [self.omega, self.t_start, self.t_brake, self.sweep, self.start]

    def check(self) -> None:
        if self.omega == 0 or self.t_start <= 0 or self.t_brake <= 0 or self.sweep == 0:
            raise InputError(f"drive {self.name!r}: luffing needs omega, t_start, t_brake and "
                             "sweep non-zero (times positive)")
        if self.sweep / self.omega < 0.5 * (self.t_start + self.t_brake):
            raise InputError(f"drive {self.name!r}: omega = {self.omega} rad/s sweeps the "
                             f"{math.degrees(self.sweep):g} deg before start and braking are "
                             "over; lower omega or shorten t_start/t_brake")
        super().check()


@dataclass
class SpinUp(Drive):
    """phi = (W/T) (t^2/2 + (T/(2 pi))^2 (cos(2 pi t/T) - 1)) for t < T, W t - W T/2 after,
    plus ``start``."""

    name: str
    omega: float
    period: float
    start: float = 0.0
    kind = DRIVE_SPINUP

    def params(self) -> list[float]:
        return [self.omega, self.period, self.start]


@dataclass
class Cycle(Drive):
    """amplitude (1 - cos(2 pi (t - t0)/period))/2 on [t0, t0 + period], 0 outside."""

    name: str
    amplitude: float
    period: float
    t0: float = 0.0
    kind = DRIVE_CYCLE

    def params(self) -> list[float]:
        return [self.amplitude, self.period, self.t0]


@dataclass
class Sine(Drive):
    """offset + amplitude r(t) sin(2 pi frequency (t - t0) + phase), r rising smoothly from 0
    to 1 over ``ramp`` seconds (0: at once)."""

    name: str
    amplitude: float
    frequency: float
    phase: float = 0.0
    offset: float = 0.0
    t0: float = 0.0
    ramp: float = 0.0
    kind = DRIVE_SINE

    def params(self) -> list[float]:
        return [self.amplitude, self.frequency, self.phase, self.offset, self.t0, self.ramp]

    def check(self) -> None:
        if self.frequency < 0 or self.ramp < 0:
            raise InputError(f"drive {self.name!r}: frequency and ramp must not be negative")
        super().check()


@dataclass
class Table(Drive):
    """Piecewise linear through (times, values); times strictly increasing."""

    name: str
    times: tuple[float, ...]
    values_: tuple[float, ...]
    kind = DRIVE_TABLE

    def params(self) -> list[float]:
        return [float(t) for t in self.times] + [float(v) for v in self.values_]

    def check(self) -> None:
        t = np.asarray(self.times, dtype=float)
        if len(t) < 1 or len(t) != len(self.values_):
            raise InputError(f"drive {self.name!r}: a table needs as many values as times "
                             "(at least one)")
        if not np.all(np.isfinite(t)) or not np.all(np.isfinite(self.values_)):
            raise InputError(f"drive {self.name!r}: table entries must be finite")
        if np.any(np.diff(t) <= 0):
            raise InputError(f"drive {self.name!r}: table times must increase strictly")
        super().check()

    @classmethod
    def from_csv(cls, name: str, path: str | Path, *, time_column: int = 0,
                 value_column: int = 1) -> "Table":
        """A table from a CSV file of (time, value) rows; a first row that is not numeric is
        a header."""
        path = Path(path)
        if not path.is_file():
            raise InputError(f"drive {name!r}: table file {str(path)!r} not found")
        times, values = [], []
        with open(path, newline="") as fh:
            for number, row in enumerate(csv.reader(fh), start=1):
                if not row or all(not c.strip() for c in row) or row[0].lstrip().startswith("#"):
                    continue
                try:
                    times.append(float(row[time_column]))
                    values.append(float(row[value_column]))
                except (ValueError, IndexError):
                    if number == 1 and not times:
                        continue  # header
                    raise InputError(f"drive {name!r}: {path}, line {number}: expected numbers "
                                     f"in columns {time_column + 1} and {value_column + 1}, got "
                                     f"{_token(row)}") from None
        table = cls(name, tuple(times), tuple(values))
        table.check()
        return table


def _token(row: list[str]) -> str:
    """The first cell of a row that is not a number, quoted and cut to a few characters: a
    message never echoes the content of a file it could not parse."""
    import re
    cells = [c.strip() for c in row if c.strip()]
    if not cells:
        return "an empty row"
    bad = next((c for c in cells if not _is_number(c)), cells[0])
    token = re.match(r"[^\s:;,=/|'\"]*", bad).group()[:12]
    return f"{token!r}" + (" ..." if token != bad else "")


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


DRIVE_TYPES = {"constant": Constant, "luffing": Luffing, "spinup": SpinUp, "cycle": Cycle,
               "sine": Sine, "table": Table}
