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
- :class:`Table` (t, value) pairs, constant outside (from a CSV file with
  :meth:`Table.from_csv`), with ``interpolation`` 'linear' (the default: its rate jumps at
  the points), 'cubic' (a C2 cubic spline) or 'pchip' (piecewise cubic, C1, monotone
  between monotone points: no overshoot); both cubic kinds have zero rate at the first and
  last points, so the rate is continuous where the table starts and stops holding;
- :class:`Ramp` a rate reached smoothly: from ``start`` at ``t0`` the rate rises to
  ``rate`` over ``t_ramp`` seconds (the acceleration (rate/t_ramp) (1 - cos 2 pi tau/t_ramp)
  is continuous and zero at both ends), then stays.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..records import record
from .. import kernel
from ..codes import DRIVE_CONSTANT, DRIVE_CYCLE, DRIVE_LUFFING, DRIVE_SINE, DRIVE_SPINUP, DRIVE_TABLE
from ..codes import DRIVE_HERMITE, DRIVE_RAMP
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


@record
class Constant(Drive):
    name: str
    value_: float = 0.0
    kind = DRIVE_CONSTANT

    def params(self) -> list[float]:
        return [float(self.value_)]


@record
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


@record
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


@record
class Cycle(Drive):
    """amplitude (1 - cos(2 pi (t - t0)/period))/2 on [t0, t0 + period], 0 outside."""

    name: str
    amplitude: float
    period: float
    t0: float = 0.0
    kind = DRIVE_CYCLE

    def params(self) -> list[float]:
        return [self.amplitude, self.period, self.t0]


@record
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


#: how a table interpolates between its points
INTERPOLATIONS = ("linear", "cubic", "pchip")


def spline_slopes(t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Slopes at the points of the C2 cubic spline through (t, v) with zero slope at both
    ends (clamped): continuity of the second derivative at every inner point gives
    h_k s_{k-1} + 2 (h_{k-1} + h_k) s_k + h_{k-1} s_{k+1} = 3 (h_k d_{k-1} + h_{k-1} d_k)
    with h_k = t_{k+1} - t_k and d_k = (v_{k+1} - v_k)/h_k (a tridiagonal system)."""
    n = len(t)
    slopes = np.zeros(n)
    if n < 3:
        return slopes
    h = np.diff(t)
    d = np.diff(v) / h
    lower, diag, upper = h[1:], 2.0 * (h[:-1] + h[1:]), h[:-1]
    rhs = 3.0 * (h[1:] * d[:-1] + h[:-1] * d[1:])
    # Thomas algorithm on the inner points (the end slopes are zero)
    m = n - 2
    c, r = np.zeros(m), np.zeros(m)
    c[0], r[0] = upper[0] / diag[0], rhs[0] / diag[0]
    for k in range(1, m):
        denom = diag[k] - lower[k] * c[k - 1]
        c[k] = upper[k] / denom if k < m - 1 else 0.0
        r[k] = (rhs[k] - lower[k] * r[k - 1]) / denom
    inner = np.zeros(m)
    inner[-1] = r[-1]
    for k in range(m - 2, -1, -1):
        inner[k] = r[k] - c[k] * inner[k + 1]
    slopes[1:-1] = inner
    return slopes


def pchip_slopes(t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Slopes of the monotone piecewise cubic (Fritsch & Carlson 1980, with the weighted
    harmonic mean of Fritsch & Butland 1984 at inner points): zero where the neighbouring
    secants differ in sign or one is zero (a local extremum stays at the point), zero at
    both ends. Between monotone points the interpolant is monotone."""
    n = len(t)
    slopes = np.zeros(n)
    if n < 3:
        return slopes
    h = np.diff(t)
    d = np.diff(v) / h
    for k in range(1, n - 1):
        if d[k - 1] * d[k] <= 0.0:
            continue
        w1, w2 = 2.0 * h[k] + h[k - 1], h[k] + 2.0 * h[k - 1]
        slopes[k] = (w1 + w2) / (w1 / d[k - 1] + w2 / d[k])
    return slopes


@record
class Table(Drive):
    """Through (times, values), times strictly increasing, constant outside;
    ``interpolation`` 'linear' (default), 'cubic' (C2 spline, zero end slopes) or 'pchip'
    (monotone piecewise cubic, zero end slopes)."""

    name: str
    times: tuple[float, ...]
    values_: tuple[float, ...]
    interpolation: str = "linear"

    @property
    def kind(self) -> int:  # type: ignore[override]
        return DRIVE_TABLE if self.interpolation == "linear" else DRIVE_HERMITE

    def slopes(self) -> np.ndarray:
        """The rate at each point ('cubic', 'pchip'; 'linear' has none: zeros)."""
        t = np.asarray(self.times, dtype=float)
        v = np.asarray(self.values_, dtype=float)
        if self.interpolation == "cubic":
            return spline_slopes(t, v)
        if self.interpolation == "pchip":
            return pchip_slopes(t, v)
        return np.zeros(len(t))

    def params(self) -> list[float]:
        out = [float(t) for t in self.times] + [float(v) for v in self.values_]
        if self.interpolation != "linear":
            out += [float(s) for s in self.slopes()]
        return out

    def check(self) -> None:
        t = np.asarray(self.times, dtype=float)
        if len(t) < 1 or len(t) != len(self.values_):
            raise InputError(f"drive {self.name!r}: a table needs as many values as times "
                             "(at least one)")
        if not np.all(np.isfinite(t)) or not np.all(np.isfinite(self.values_)):
            raise InputError(f"drive {self.name!r}: table entries must be finite")
        if np.any(np.diff(t) <= 0):
            raise InputError(f"drive {self.name!r}: table times must increase strictly")
        if self.interpolation not in INTERPOLATIONS:
            raise InputError(f"drive {self.name!r}: interpolation {self.interpolation!r} must "
                             f"be one of {', '.join(INTERPOLATIONS)}")
        super().check()

    @classmethod
    def from_csv(cls, name: str, path: str | Path, *, time_column: int = 0,
                 value_column: int = 1, interpolation: str = "linear") -> "Table":
        """A table from a CSV file of (time, value) rows; a first row that is not numeric is
        a header."""
        import csv   # here: most runs read no table (issue 23: the modules a run loads)
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
        table = cls(name, tuple(times), tuple(values), interpolation)
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


@record
class Ramp(Drive):
    """From ``start`` (held until ``t0``) the rate rises smoothly to ``rate`` (units/s)
    over ``t_ramp`` seconds, then stays: phi = start + (rate/T) (tau^2/2 + (T/(2 pi))^2
    (cos(2 pi tau/T) - 1)) for tau = t - t0 < T = t_ramp, start + rate (tau - T/2) after;
    phi'' = (rate/T) (1 - cos(2 pi tau/T)) is continuous (zero at both ends of the ramp).
    ``t_ramp = 0``: the rate at once from t0."""

    name: str
    rate: float
    t_ramp: float
    start: float = 0.0
    t0: float = 0.0
    kind = DRIVE_RAMP

    def params(self) -> list[float]:
        return [float(self.rate), float(self.t_ramp), float(self.start), float(self.t0)]

    def check(self) -> None:
        if self.t_ramp < 0:
            raise InputError(f"drive {self.name!r}: t_ramp must not be negative")
        super().check()


DRIVE_TYPES = {"constant": Constant, "luffing": Luffing, "spinup": SpinUp, "cycle": Cycle,
               "sine": Sine, "table": Table, "ramp": Ramp}
