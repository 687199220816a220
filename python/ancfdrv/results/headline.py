"""The answers of a result file at a glance (issue 37 item 5, SPEC section 2): what
``ancf run`` prints when it ends, what ``ancf info`` prints after the file's figures and
what ``ancf info --json`` writes for scripts, all from :func:`read_answers`.

- static: every reaction (joints and force elements: force, moment, axial force), the
  largest von Mises stress and where (beam, s), the largest probe displacement (and, in
  general scenes, the largest deflection relative to the beam's supports);
- dynamic: the time reached and the steps, each reaction's peak |F| and |M| and when, the
  von Mises envelope's largest value, where and when, the energy balance;
- modal: every frequency (Hz, with the damping ratios when the file has them);
- buckling: every load factor.

Only what the file holds is read (small groups and attributes; the dynamic energies and
reactions are one series per name), so a run's headline costs milliseconds.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import h5py
import numpy as np

from .hdf5 import open_result


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _floats(values: Any) -> list[float]:
    return [float(v) for v in np.ravel(values)]


#: the /buckling attributes of a 'linear' run's check (solvers.buckling._check_linear)
LINEAR_CHECK = ("linear_check", "checked_load_factor", "relinearized_load_factor")


def _scalar(value: Any) -> str | float:
    """An attribute as text or a float (the JSON's and the printed table's)."""
    return _text(value) if isinstance(value, (bytes, str)) else float(value)


def _reaction_groups(group: h5py.Group, prefix: str = "") -> list[tuple[str, h5py.Group]]:
    """The reactions under /<phase>/reactions by name, in file order: a name with '/'
    (a plate's 'support dw/dx') is a nested group in HDF5."""
    out = []
    for name, sub in group.items():
        if not isinstance(sub, h5py.Group):
            continue
        if "force" in sub:
            out.append((prefix + name, sub))
        else:
            out += _reaction_groups(sub, f"{prefix}{name}/")
    return out


def _static_reactions(group: h5py.Group) -> dict[str, dict[str, Any]]:
    out = {}
    for name, sub in _reaction_groups(group):
        out[name] = {"kind": _text(sub.attrs.get("kind", "joint")),
                     "force": _floats(sub["force"][()]), "moment": _floats(sub["moment"][()]),
                     "axial": float(sub["axial"][()]) if "axial" in sub else None}
    return out


def _peak(series: np.ndarray, time: np.ndarray) -> tuple[float, float]:
    """The largest norm of a (nt, 3) series and its time."""
    size = np.linalg.norm(np.atleast_2d(series), axis=1)
    k = int(np.argmax(size))
    return float(size[k]), float(time[k]) if k < len(time) else float("nan")


def _dynamic_reactions(group: h5py.Group, time: np.ndarray) -> dict[str, dict[str, Any]]:
    out = {}
    for name, sub in _reaction_groups(group):
        force, when_force = _peak(sub["force"][()], time)
        moment, when_moment = _peak(sub["moment"][()], time)
        entry = {"kind": _text(sub.attrs.get("kind", "joint")), "force_max": force,
                 "t_force_max": when_force, "moment_max": moment, "t_moment_max": when_moment}
        if "axial" in sub:
            axial = np.asarray(sub["axial"][()], dtype=float)
            k = int(np.argmax(np.abs(axial)))
            entry["axial_extreme"] = float(axial[k])
            entry["t_axial_extreme"] = float(time[k]) if k < len(time) else float("nan")
        out[name] = entry
    return out


def _largest_stress(group: h5py.Group) -> dict[str, Any] | None:
    best = None
    for name, sub in group.items():
        if "max" not in sub.attrs:
            continue
        peak = float(sub.attrs["max"])
        if best is None or peak > best["value"]:
            best = {"value": peak, "beam": name, "s": float(sub.attrs.get("s_max", 0.0))}
            if "t_max" in sub.attrs:
                best["t"] = float(sub.attrs["t_max"])
    return best


def _largest_displacement(group: h5py.Group, reference: str) -> dict[str, Any] | None:
    best = None
    for name, data in group.items():
        vector = np.asarray(data[()], dtype=float)
        if vector.shape != (3,):
            continue
        size = float(np.linalg.norm(vector))
        if best is None or size > best["value"]:
            best = {"probe": name, "value": size, "vector": _floats(vector)}
    if best is not None:
        best["reference"] = reference
    return best


def _energy_balance(group: h5py.Group) -> dict[str, float] | None:
    """The largest and the final |E - E0 - W| (J: total energy against its start and the
    work of drives, moving frames, damping and friction) and the scale it is measured
    against: the largest kinetic or strain energy or gravity's range over the run."""
    if "balance" not in group or not len(group["balance"]):
        return None
    balance = np.asarray(group["balance"][()], dtype=float)
    k = int(np.argmax(np.abs(balance)))
    scale = 0.0
    for name in ("kinetic", "strain"):
        if name in group and len(group[name]):
            scale = max(scale, float(np.max(np.abs(group[name][()]))))
    if "gravity" in group and len(group["gravity"]):
        scale = max(scale, float(np.ptp(group["gravity"][()])))
    return {"largest": float(balance[k]), "final": float(balance[-1]), "scale": scale}


def read_answers(path: str | Path) -> dict[str, Any]:
    """The answers of a result file as a JSON-ready dict (module docstring): keys
    'static', 'dynamic', 'modal', 'buckling' for the analyses the file holds. Raises
    InputError when the file is missing, not HDF5 or not an ancfdrv result."""
    with open_result(Path(path)) as h5:
        return answers_of(h5)


def answers_of(h5: h5py.File) -> dict[str, Any]:
    """:func:`read_answers` of a result file already open (``ancf run`` reads its
    figures and its answers in one opening)."""
    out: dict[str, Any] = {}
    if "static" in h5:
        group = h5["static"]
        static: dict[str, Any] = {}
        if "reactions" in group:
            static["reactions"] = _static_reactions(group["reactions"])
        if "stress" in group:
            static["largest_von_mises"] = _largest_stress(group["stress"])
        if "deflection" in group:
            reference = _text(group["deflection"].attrs.get(
                "reference", "displacement from the rigid configuration"))
            static["largest_displacement"] = _largest_displacement(group["deflection"],
                                                                   reference)
        if "deflection_support" in group and len(group["deflection_support"]):
            static["largest_support_deflection"] = _largest_displacement(
                group["deflection_support"], "relative to the rigid motion of the "
                "beam's supports")
        out["static"] = static
    if "dynamic" in h5 and "time" in h5["dynamic"] and len(h5["dynamic/time"]):
        group = h5["dynamic"]
        time = np.asarray(group["time"][()], dtype=float)
        dynamic: dict[str, Any] = {"t_reached": float(time[-1]),
                                   "steps": int(group.attrs.get("steps", len(time) - 1))}
        if "reactions" in group:
            dynamic["reactions"] = _dynamic_reactions(group["reactions"], time)
        if "stress" in group:
            dynamic["largest_von_mises"] = _largest_stress(group["stress"])
        if "energy" in group:
            dynamic["energy_balance"] = _energy_balance(group["energy"])
        out["dynamic"] = dynamic
    for name, key in (("modal", "frequency"), ("buckling", "load_factor")):
        if name in h5 and key in h5[name]:
            entry = {key: _floats(h5[name][key][()])}
            if "damping_ratio" in h5[name]:
                entry["damping_ratio"] = _floats(h5[name]["damping_ratio"][()])
            if "linear_check" in h5[name].attrs:
                entry["linear_check"] = {k: _scalar(h5[name].attrs[k]) for k in LINEAR_CHECK
                                         if k in h5[name].attrs}
            out[name] = entry
    return out


#: the columns of the static reaction table: (heading, what, component)
REACTION_COLUMNS = (("Fx", "force", 0), ("Fy", "force", 1), ("Fz", "force", 2),
                    ("Mx", "moment", 0), ("My", "moment", 1), ("Mz", "moment", 2))
#: values per line of a frequency or load-factor list
VALUES_PER_LINE = 6


#: printed values smaller than this share of their table's (or vector's) largest value are
#: round-off and print as 0 (the JSON keeps every value as the file holds it)
ROUND_OFF = 1e-10


def _number(value: float | None, scale: float = 0.0) -> str:
    if value is None:
        return f" {'-':>12s}"
    return f" {0.0 if abs(value) <= ROUND_OFF * scale else value:>12.6g}"


def _name_width(names: list[str]) -> int:
    return max([4, *(len(repr(n)) for n in names)])


def _reaction_table(reactions: dict[str, dict[str, Any]]) -> list[str]:
    width = _name_width(list(reactions))
    scale = max(abs(v) for r in reactions.values() for v in (*r["force"], *r["moment"]))
    lines = ["  reactions    what body1 exerts on body2, global axes: F (N), M (N m) about "
             "the joint's point; axial (N): tension positive",
             f"    {'name':{width}s}  {'kind':13s}"
             + "".join(f" {h:>12s}" for h, _, _ in REACTION_COLUMNS) + f" {'axial':>12s}"]
    for name, r in reactions.items():
        lines.append(f"    {name!r:{width}s}  {r['kind']:13s}"
                     + "".join(_number(r[what][k], scale) for _, what, k in REACTION_COLUMNS)
                     + _number(r["axial"], scale))
    return lines


def _peak_table(reactions: dict[str, dict[str, Any]]) -> list[str]:
    width = _name_width(list(reactions))
    scale = max(max(r["force_max"], r["moment_max"]) for r in reactions.values())
    lines = ["  reaction peaks over the run: largest |F| (N), |M| (N m), axial force of "
             "largest size (N), each with its time t (s)",
             f"    {'name':{width}s}  {'kind':13s} {'max |F|':>12s} {'t':>9s} {'max |M|':>12s}"
             f" {'t':>9s} {'axial':>12s} {'t':>9s}"]
    for name, r in reactions.items():
        axial = r.get("axial_extreme")
        lines.append(f"    {name!r:{width}s}  {r['kind']:13s}" + _number(r["force_max"], scale)
                     + f" {r['t_force_max']:>9.6g}" + _number(r["moment_max"], scale)
                     + f" {r['t_moment_max']:>9.6g}" + _number(axial, scale)
                     + (f" {'-':>9s}" if axial is None else f" {r['t_axial_extreme']:>9.6g}"))
    return lines


def _stress_line(stress: dict[str, Any] | None) -> list[str]:
    if stress is None:
        return []
    when = f", t = {stress['t']:.6g} s" if "t" in stress else ""
    return [f"  largest von Mises stress {stress['value'] / 1e6:.6g} MPa in beam "
            f"{stress['beam']!r} at s = {stress['s']:.6g} m{when}"]


def _displacement_line(what: str, entry: dict[str, Any] | None) -> list[str]:
    if entry is None:
        return []
    vector = ", ".join(f"{1e3 * v if abs(v) > ROUND_OFF * entry['value'] else 0.0:+.6g}"
                       for v in entry["vector"])
    basis = entry["reference"].split(", ", 1)[0]  # the file's words, their first clause
    return [f"  largest {what} {1e3 * entry['value']:.6g} mm at probe {entry['probe']!r} "
            f"({vector}) mm, {basis}"]


def _value_lines(label: str, values: list[float]) -> list[str]:
    if not values:
        return [f"  {label}: none"]
    rows = [values[k:k + VALUES_PER_LINE] for k in range(0, len(values), VALUES_PER_LINE)]
    head = f"  {label}:"
    return [(head if k == 0 else " " * len(head)) + "".join(f" {v:.6g}" for v in row)
            for k, row in enumerate(rows)]


def answer_lines(answers: dict[str, Any]) -> list[str]:
    """The answers of :func:`read_answers` as aligned text: every reaction, every
    frequency and load factor, nothing cut."""
    lines: list[str] = []
    static = answers.get("static")
    if static:
        lines.append("static answers")
        if static.get("reactions"):
            lines += _reaction_table(static["reactions"])
        lines += _stress_line(static.get("largest_von_mises"))
        lines += _displacement_line("probe displacement", static.get("largest_displacement"))
        lines += _displacement_line("probe deflection",
                                    static.get("largest_support_deflection"))
    dynamic = answers.get("dynamic")
    if dynamic:
        lines.append("dynamic answers")
        lines.append(f"  reached t = {dynamic['t_reached']:.6g} s in {dynamic['steps']} steps")
        if dynamic.get("reactions"):
            lines += _peak_table(dynamic["reactions"])
        lines += _stress_line(dynamic.get("largest_von_mises"))
        energy = dynamic.get("energy_balance")
        if energy is not None:
            share = (f" ({abs(energy['largest']) / energy['scale']:.3g} of the largest "
                     f"energy, {energy['scale']:.6g} J)") if energy["scale"] > 0 else ""
            lines.append(f"  energy balance E - E0 - W: largest {energy['largest']:+.6g} J"
                         f"{share}, final {energy['final']:+.6g} J")
    modal = answers.get("modal")
    if modal:
        lines.append(f"modal answers ({len(modal['frequency'])} modes)")
        lines += _value_lines("frequencies (Hz)", modal["frequency"])
        if "damping_ratio" in modal:
            lines += _value_lines("damping ratios", modal["damping_ratio"])
    buckling = answers.get("buckling")
    if buckling:
        lines.append(f"buckling answers ({len(buckling['load_factor'])} modes)")
        lines += _value_lines("load factors", buckling["load_factor"])
        check = buckling.get("linear_check")
        if check:
            lines.append(
                f"  'linear' check ({check['linear_check']}): the static path carries "
                f"{check['checked_load_factor']:.6g} times the loads stably; the estimate "
                f"about that state gives {check['relinearized_load_factor']:.6g}")
            if check["linear_check"] == "conservative":
                lines.append("  so the stability limit lies above the classical factor "
                             "(buckling.method = 'nonlinear' gives it)")
    return lines
