"""Parameter sweeps: every combination of ``--vary`` values, run in parallel processes (or
on a Dask distributed scheduler), one HDF5 per case, and the accuracy-versus-time report:
``summary.csv``, ``summary.md`` and plots.

Error is taken against the finest case of the sweep with the same non-resolution
parameters (most ``beam.nodes``, smallest ``solver.dt``); the report names that reference
and says when it is not the finest requested case (because that one failed). For boom
scenes the error against the closed-form small-deflection solution
(docs/boom_closed_form.md) is reported too.

Robustness (how the cases run: :mod:`ancfdrv.sweep_exec`): a case that fails in any way -
an ancfdrv error, any other exception, a worker process killed by a signal - is that case's
row (status, message, exit code), and the sweep goes on; Ctrl-C writes the report of what
finished and raises :class:`SweepInterrupted`. Case files are named from sanitized values
and always land in the sweep directory, and every one carries the root attribute
``sweep_id`` of the sweep that wrote it: the tables read only this sweep's files.
"""
from __future__ import annotations

import csv
import hashlib
import itertools
import os
import re
import sys
import uuid
from collections import Counter
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from tqdm import tqdm

from .records import record
from .errors import InputError
from .results.lock import OutputLock
from .io.safe_write import replace_atomically, write_bytes, write_text
from .sweep_keys import Response, is_resolution, resolution_rank, row_response, static_value
from .io.scene import GENERAL_SCHEMA, SCHEMA, load_scene, parse_address
from .sweep_exec import (CONNECT_TIMEOUT_S, INTERRUPTED_EXIT, Case, connect, eigen_values,
                         failure, remove_quietly, response_of, run_dask, run_inline,
                         run_processes, static_response, worker_cap)

#: Case file names: these characters only, at most this long (before the hash suffix).
_UNSAFE = re.compile(r"[^A-Za-z0-9._+-]")
MAX_NAME_CHARS = 96


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a sweep; the report of what finished is written. ``rows`` are all
    cases ('ok', 'failed', 'interrupted' or 'cancelled'), ``outdir`` the sweep directory,
    ``signum`` the signal that stopped it (SIGINT or SIGTERM, when known)."""

    def __init__(self, rows: list[dict], outdir: Path, signum: int | None = None) -> None:
        super().__init__("sweep interrupted")
        self.rows, self.outdir, self.signum = rows, outdir, signum

    @property
    def exit_code(self) -> int:
        """128 + the signal (130 for SIGINT, 143 for SIGTERM)."""
        import signal
        if self.signum is not None:
            return 128 + self.signum
        codes = [r.get("exit_code") for r in self.rows if r.get("status") == "interrupted"]
        return 128 + signal.SIGTERM if 128 + signal.SIGTERM in codes else 128 + signal.SIGINT


class ParentSignals:
    """SIGINT and SIGTERM sent to the sweep's parent process (``kill -INT PID``, not only a
    terminal's Ctrl-C to the whole process group, and even when the shell started it with
    SIGINT ignored) stop the sweep like Ctrl-C: the first one raises KeyboardInterrupt in
    the executor (running cases stopped, queued ones cancelled, the report of the finished
    ones written); later ones are only recorded. A worker process forked while the handler
    is in place gets the default behaviour back."""

    def __init__(self) -> None:
        import signal
        self.signals = (signal.SIGINT, signal.SIGTERM)
        self.signum: int | None = None
        self.armed = True
        self._saved: dict[int, Any] = {}
        self._pid = os.getpid()

    def __enter__(self) -> "ParentSignals":
        import signal
        import threading
        if threading.current_thread() is threading.main_thread():
            for signum in self.signals:
                self._saved[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        import signal
        for signum, previous in self._saved.items():
            signal.signal(signum, previous)
        self._saved.clear()

    def _handle(self, signum: int, frame: object) -> None:
        import signal
        if os.getpid() != self._pid:  # a forked worker before it set its own handlers
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
            return
        if self.signum is None:
            self.signum = signum
        if self.armed:
            self.armed = False
            raise KeyboardInterrupt


def expand(params: dict[str, str]) -> list[str]:
    """Overrides of a case; a tied key 'a.x+a.y' sets every key it names."""
    return [f"{part}={v}" for k, v in params.items() for part in k.split("+")]


def parse_vary(items: list[str], scene_file: str) -> list[tuple[str, list[str]]]:
    """``GROUP.KEY=V1,V2,...`` or ``GROUP[NAME].KEY=...`` (a named group of a general scene)
    -> (dotted key, values); keys are checked against the schema (every case is validated
    with its scene before any runs; ``parameters.NAME`` moves every key whose expression
    uses the parameter). Keys joined by '+' vary together (``plate.nx+plate.ny=2,4,8``:
    2x2, 4x4, 8x8)."""
    out = []
    for item in items:
        if "=" not in item or "." not in item.split("=", 1)[0]:
            raise InputError(f"--vary {item!r} is not of the form GROUP.KEY=V1,V2,...",
                             file=scene_file)
        dotted, values = item.split("=", 1)
        parts = []
        for part in dotted.split("+"):
            try:
                group, name, key = parse_address(part)
            except ValueError:
                raise InputError(f"--vary names {part.strip()!r}, not GROUP.KEY or "
                                 "GROUP[NAME].KEY", file=scene_file) from None
            schema = GENERAL_SCHEMA.get(group, {}) if name is not None else \
                {**SCHEMA.get(group, {}), **GENERAL_SCHEMA.get(group, {})}
            # (a scene's own parameters: checked when each case's scene is read)
            if key not in schema and not (group == "parameters" and name is None):
                raise InputError(f"--vary names an unknown key {part.strip()!r}",
                                 file=scene_file, group=group, key=key)
            parts.append(f"{group}.{key}" if name is None else f"{group}[{name}].{key}")
        dotted = "+".join(parts)
        vals = [v.strip() for v in values.split(",") if v.strip()]
        if not vals:
            raise InputError(f"--vary {dotted} has no values", file=scene_file, group=group,
                             key=key)
        repeated = [v for v, n in Counter(_unquote(v) for v in vals).items() if n > 1]
        if repeated:
            raise InputError(f"--vary {dotted} gives the value {repeated[0]!r} more than once",
                             file=scene_file, group=group, key=key)
        out.append((dotted, vals))
    return out


def _short_key(key: str) -> str:
    return "+".join(part.rpartition(".")[2] for part in key.split("+"))


def _unquote(value: str) -> str:
    return value.strip().strip("'\"").strip()


def _digest(params: dict[str, str]) -> str:
    text = "\n".join(f"{k}={v}" for k, v in params.items())
    return hashlib.sha256(text.encode()).hexdigest()[:8]


def _plain_name(params: dict[str, str]) -> tuple[str, bool]:
    """The readable name ``key-value_key-value`` with unsafe characters replaced and the
    length bounded, and whether that changed anything."""
    raw = "_".join(f"{_short_key(k)}-{_unquote(v)}" for k, v in params.items())
    safe = _UNSAFE.sub("_", raw)[:MAX_NAME_CHARS]
    return safe, safe != raw


def case_name(params: dict[str, str]) -> str:
    """File stem of a case: ``nodes-28_dt-0.001``; only ``[A-Za-z0-9._+-]``, at most
    MAX_NAME_CHARS, and a short hash of the values appended when sanitizing changed them
    (``title-.._.._escape_1f2e3d4c``). A single path component: never a directory."""
    safe, changed = _plain_name(params)
    return f"{safe}_{_digest(params)}" if changed else safe


def case_names(combos: list[dict[str, str]]) -> list[str]:
    """:func:`case_name` of every case, with the hash appended also where two cases would
    otherwise share a name (values equal after sanitizing, or differing only in letter
    case, which some filesystems do not distinguish)."""
    names = [case_name(p) for p in combos]
    count = Counter(n.lower() for n in names)
    return [f"{name}_{_digest(params)}" if count[name.lower()] > 1 and not _plain_name(params)[1]
            else name for name, params in zip(names, combos)]


def _history(h5: h5py.File, response: Response | None = None) -> tuple[np.ndarray, np.ndarray]:
    probe, component = response or response_of(h5.attrs)
    name = f"dynamic/deflection_support/{probe}"  # general scenes (supports' motion off)
    if name not in h5:
        name = f"dynamic/deflection/{probe}"
    return h5["dynamic/time"][()], h5[name][:, component]


def _tip_history(row: dict) -> tuple[np.ndarray, np.ndarray]:
    """Time and the compared history of a case (the tip sag for beams)."""
    with h5py.File(row["file"], "r") as h5:
        return _history(h5, row_response(row))


def _static_deflection(h5: h5py.File, probe: str) -> np.ndarray:
    """A probe's static deflection as a sweep row has it: relative to the supports' rigid
    motion when the file has it (general scenes), else to the rigid frame."""
    name = f"static/deflection_support/{probe}"
    return h5[name][()] if name in h5 else h5[f"static/deflection/{probe}"][()]


def _probe_and_size(row: dict) -> tuple[str, float]:
    """The compared probe of a case and its model's size (m)."""
    with h5py.File(row["file"], "r") as h5:
        return (row_response(row) or response_of(h5.attrs))[0], \
            float(h5["model"].attrs.get("length_scale", 0.0))


#: A deflection at most this fraction of the model's size is zero to the precision of a
#: solve (a nanometre on a metre: the Newton tolerances are relative to the model's size)
ZERO_DEFLECTION = 1e-9


def relative_error(absolute: float, scale: float, size: float, probe: str,
                   reference_file: str | None = None) -> float | str:
    """``absolute / scale``, the error relative to the reference's deflection; or, when
    that deflection is zero to round-off (at most ZERO_DEFLECTION times the model's size
    ``size``, m), the note saying why a relative error is undefined there (the absolute
    error stays meaningful) and, from ``reference_file``, which probe would serve
    (:func:`moving_probe`)."""
    if scale == 0.0 or scale <= ZERO_DEFLECTION * size:
        hint = moving_probe(reference_file, size) if reference_file else ""
        return (f"undefined: the reference deflection of probe {probe!r} is zero to "
                f"round-off ({scale:.1e} m, model size {size:.3g} m); see the absolute "
                f"error{hint}")
    return absolute / scale


def largest_motion(path: str | Path) -> tuple[float, str, int, str]:
    """The probe and component that move most in a result file, as a sweep compares them
    (relative to the supports where the file has that, else from the rigid configuration
    or t = 0): (how much, m; probe; component; what was measured). A dynamic run's
    motion is the range of each component over its history, a static run's the
    magnitude of its deflection; (0, '', 0, ...) when the file has no probe."""
    best = (0.0, "", 0)
    with h5py.File(path, "r") as h5:
        group = "dynamic" if "dynamic/deflection" in h5 else "static"
        measure = "its range over the run" if group == "dynamic" else "its static deflection"
        for probe in h5.get(f"{group}/deflection", {}):
            name = f"{group}/deflection_support/{probe}"
            data = h5[name] if name in h5 else h5[f"{group}/deflection/{probe}"]
            values = np.asarray(data[()], dtype=float).reshape(-1, 3)
            moved = np.ptp(values, axis=0) if group == "dynamic" else np.abs(values[0])
            k = int(np.argmax(moved))
            if moved[k] > best[0]:
                best = (float(moved[k]), probe, k)
    return (*best, measure)


def moving_probe(path: str, size: float) -> str:
    """A hint naming the probe and component that move most in a result file
    (:func:`largest_motion`), as the scene keys that would compare it; '' when none moves
    beyond round-off."""
    amount, probe, component, _ = largest_motion(path)
    if amount <= ZERO_DEFLECTION * size:
        return ""
    return (f"; probe {probe!r} moves {1e3 * amount:.4g} mm along its component "
            f"{component}: compare it with &scene response = {probe!r}, "
            f"response_component = {component}")


def response_named(scene, varied: list[str]) -> bool:
    """Whether a general scene's sweep compares a response the user named (&scene
    response, by the scene, --set or --vary); a template scene's is its builder's."""
    return scene.kind != "general" or bool(scene["scene"].get("response")) or \
        "scene.response" in varied


def pick_response(path: str | Path, case: str) -> tuple[Response, str] | None:
    """The response a general scene's sweep compares when the user named none: the probe
    and component that move most (:func:`largest_motion`) in the result file ``path`` (the
    reference, or the sweep's first case, named ``case``), with the sentence saying so;
    None when nothing moves beyond round-off (the files' own response is compared)."""
    amount, probe, component, measure = largest_motion(path)
    with h5py.File(path, "r") as h5:
        size = float(h5["model"].attrs.get("length_scale", 0.0))
    if not probe or amount <= ZERO_DEFLECTION * size:
        return None
    return (probe, component), (
        f"compared: probe {probe!r} component {component}, picked because no &scene "
        f"response is named: of every probe's deflection components it moves most in "
        f"{case} ({1e3 * amount:.4g} mm, {measure})")


def eigen_error(values: np.ndarray, reference: np.ndarray) -> float | str:
    """The largest relative difference of the first frequencies (load factors) both runs
    computed, in ascending order; a note when there are none to compare."""
    n = min(len(values), len(reference))
    if n == 0:
        return "undefined: no elastic frequency or load factor to compare"
    return float(np.max(np.abs(values[:n] - reference[:n]) / np.abs(reference[:n])))


def _set_error(row: dict, key: str, err: float | str) -> None:
    """row[key] = the error, or row[key + '_undefined'] = why there is none."""
    if isinstance(err, str):
        row[f"{key}_undefined"] = err
    else:
        row[key] = err


def add_history_errors(rows: list[dict], varied: list[str]) -> None:
    """Dynamic cases: against the finest case with the same other keys, the amplitude
    error max|y - y_ref| / max|y_ref| of the tip sag history (undefined when y_ref is zero
    to round-off), and the phase error accumulated over the vibration stage,
    360 (f - f_ref) T_vib in degrees, from zero-crossing frequencies."""
    from .history import crossing_frequency
    for members, finest in _reference_groups(rows, varied):
        t_ref, y_ref = _tip_history(finest)
        probe, size = _probe_and_size(finest)
        scale = float(np.abs(y_ref).max())
        t0, t1 = finest.get("stage_vibration_t0"), finest.get("stage_vibration_t1")
        f_ref = None
        if t0 is not None:
            mask = t_ref >= t0
            f_ref = crossing_frequency(t_ref[mask], y_ref[mask])
        for row in members:
            t, y = _tip_history(row)
            common = t_ref <= t[-1]
            absolute = float(np.abs(np.interp(t_ref[common], t, y) - y_ref[common]).max())
            _set_error(row, "err_vs_finest", relative_error(absolute, scale, size, probe,
                                                            finest["file"]))
            row["err_abs_vs_finest"] = absolute  # m (the table shows mm)
            if f_ref is not None:
                mask = t >= t0
                f = crossing_frequency(t[mask], y[mask])
                row["vibration_frequency_hz"] = f
                row["phase_err_deg"] = float(360.0 * (f - f_ref) * (t1 - t0))


def closed_form_error(scene_file: str, row: dict, base: list[str]) -> float | None:
    """Relative error of a successful case's response against its template's closed form
    (:func:`ancfdrv.builders.closed_form_error`; None if the template has none)."""
    from .builders import closed_form_error as template_error
    params = expand({k: row[k] for k in row if "." in k})
    scene = load_scene(scene_file, base + params)
    if row.get("status") != "ok":
        return None
    return template_error(scene, row)


def _reference_groups(rows: list[dict], varied: list[str]):
    """(successful members, reference) per group of rows equal in the non-resolution keys.
    The reference is the finest successful case of the group; each member records its name
    in 'err_reference', and 'err_reference_is_finest' says whether it is the finest case
    requested (False when that one failed: 'err_finest_requested' names it)."""
    resolution = [k for k in varied if is_resolution(k)]
    others = [k for k in varied if not is_resolution(k)]
    groups: dict[tuple, list[dict]] = {}
    for row in rows:
        groups.setdefault(tuple(row[k] for k in others), []).append(row)

    def rank(row: dict) -> tuple:
        return tuple(resolution_rank(k, row[k]) for k in resolution)
    for members in groups.values():
        ok = [r for r in members if r["status"] == "ok"]
        if not ok:
            continue
        requested, reference = min(members, key=rank), min(ok, key=rank)
        for row in ok:
            row["err_reference"] = reference["case"]
            row["err_reference_is_finest"] = reference is requested
            if reference is not requested:
                row["err_finest_requested"] = requested["case"]
        yield ok, reference


def add_formulation_difference(rows: list[dict], varied: list[str]) -> None:
    """When scene.formulation is varied: each row's difference from the large-deformation
    ('nonlinear') case with the same other keys - what the FFR model's assumptions cost,
    next to what they save in time (static: relative tip sag; dynamic: max |sag(t) -
    sag_nl(t)| / max |sag_nl|; modal and buckling: as err_vs_finest)."""
    key = "scene.formulation"
    if key not in varied:
        return
    others = [k for k in varied if k != key]
    reference = {tuple(r[k] for k in others): r for r in rows
                 if r["status"] == "ok" and r[key].strip("'\"") == "nonlinear"}
    for row in rows:
        ref = reference.get(tuple(row[k] for k in others))
        if row["status"] != "ok" or ref is None:
            continue
        if "analysis" in row:  # modal or buckling
            diff = eigen_error(eigen_values(row["file"])[1], eigen_values(ref["file"])[1])
        elif row.get("dynamic"):
            t_ref, y_ref = _tip_history(ref)
            t, y = _tip_history(row)
            common = t_ref <= t[-1]
            diff = relative_error(float(np.abs(np.interp(t_ref[common], t, y)
                                               - y_ref[common]).max()),
                                  float(np.abs(y_ref).max()), *_probe_and_size(ref)[::-1])
        else:
            diff = relative_error(abs(static_value(row) - static_value(ref)),
                                  abs(static_value(ref)), *_probe_and_size(ref)[::-1])
        _set_error(row, "diff_vs_nonlinear", diff)


#: The analyses a sweep compares, by family: a static+dynamic case compares its history.
ANALYSIS_FAMILY = {"static": "static", "dynamic": "dynamic", "static+dynamic": "dynamic",
                   "modal": "modal", "buckling": "buckling"}


@record(frozen=True)
class Reference:
    """A result file every case of a sweep is compared with (``--reference``), read and
    checked before the first case runs (:func:`load_reference`)."""

    path: Path
    family: str  # 'static', 'dynamic', 'modal' or 'buckling'
    values: np.ndarray  # static: [value]; dynamic: the history; modal/buckling: eigenvalues
    time: np.ndarray | None  # dynamic: the times of ``values``
    probe: str  # the compared probe (static and dynamic)
    length_scale: float  # the model's size (m)
    #: the response picked in it (:func:`pick_response`) and why; None: the files' own
    picked: tuple[Response, str] | None = None


def _file_family(h5: h5py.File) -> str | None:
    for group in ("modal", "buckling", "dynamic", "static"):
        if group in h5:
            return group
    return None


def _file_probes(h5: h5py.File) -> set[str]:
    names: set[str] = set()
    for group in ("static/deflection", "dynamic/deflection"):
        if group in h5:
            names.update(h5[group])
    return names


def _expected_model(scene) -> tuple[list[str], list[str], tuple[str, int] | None]:
    """What a run of ``scene`` records of its model: the body names, the probe names and
    the compared (probe, component)."""
    from .builders import build_system
    from .system.model import default_response
    built = build_system(scene)
    bodies = list(built.system.bodies.values())
    probes = built.system.probes
    response = built.response or default_response(probes, bodies)
    return [b.name for b in bodies], list(probes), response


def load_reference(reference: str | Path, scene, families: set[str], *,
                   pick: bool = False) -> Reference:
    """Read ``--reference`` and check that it can stand for the sweep's cases; InputError
    (exit 2) naming the file and the mismatch otherwise. It must be

    - a readable ancfdrv result file of a run that finished (status 'ok');
    - of the analysis the cases run ('static', 'dynamic' (or 'static+dynamic': a history),
      'modal' or 'buckling'), the same for every case;
    - of the same model. The rule: the same scene title, the same kind of scene (the
      template, or 'general'), the same bodies (by name), and for static and dynamic
      sweeps the same probes and the same compared probe and component (``pick``: the
      user named no response in a general scene: the sweep compares the one that moves
      most in the reference, :func:`pick_response`). What resolves or
      approximates the model (nodes, modes, the formulation, the element kind of a body -
      beam or cable -, dt, the solver) may differ: that is what a reference is for. The
      physical values (lengths, materials, loads) are not compared: a reference of the
      same scene run with other values is the user's choice and is named in the report
      (err_reference_file)."""
    path = Path(reference)
    where = str(path)
    if not path.is_file():
        raise InputError("--reference: no such result file", file=where)
    from .results.hdf5 import read_summary
    try:
        summary = read_summary(path)
    except InputError as exc:
        raise InputError(f"--reference: {str(exc).removeprefix(where + ': ')}",
                         file=where) from None
    except Exception as exc:  # a damaged file (truncated HDF5, missing datasets)
        raise InputError(f"--reference: cannot read it as an ancfdrv result file "
                         f"({type(exc).__name__})", file=where) from None
    status = summary.get("status", "")
    if status != "ok":
        message = str(summary.get("message", "")).splitlines()
        raise InputError(f"--reference: the reference run did not succeed (status "
                         f"{status!r}{': ' + message[0] if message else ''}); only a "
                         "finished run can be a reference", file=where)
    if len(families) > 1:
        raise InputError(f"--reference: the sweep's cases run different analyses "
                         f"({', '.join(sorted(families))}); one reference cannot stand for "
                         "all of them", file=where)
    family = next(iter(families))
    try:
        with h5py.File(path, "r") as h5:
            found = _file_family(h5)
            if found != family:
                raise InputError(f"--reference: a {found or 'empty'} result, but the sweep's "
                                 f"cases are {family} runs", file=where)
            length = float(h5["model"].attrs.get("length_scale", 0.0))
            probes = _file_probes(h5)
            picked = pick_response(path, f"the reference {path.name}") \
                if pick and family in ("static", "dynamic") else None
            probe, component = picked[0] if picked else response_of(h5.attrs)
            time = None
            if family == "static":
                values = np.array([_static_deflection(h5, probe)[component]])
            elif family == "dynamic":
                time, values = _history(h5, (probe, component))
            else:
                values = eigen_values(path)[1]
    except InputError:
        raise
    except Exception as exc:  # opened, but a dataset it needs is missing or damaged
        raise InputError(f"--reference: cannot read its {family} results ({type(exc).__name__}"
                         f"{': ' + str(exc).splitlines()[0] if str(exc) else ''})",
                         file=where) from None
    bodies, scene_probes, response = _expected_model(scene)
    mismatch = []
    title = scene["scene"]["title"]
    if summary.get("title") != title:
        mismatch.append(f"its title is {summary.get('title')!r}, the sweep's scene's {title!r}")
    if summary.get("kind") != scene.kind:
        mismatch.append(f"it is a {summary.get('kind')!r} scene, the sweep's a {scene.kind!r}")
    theirs = [b.rpartition(":")[0] for b in str(summary.get("model.bodies", "")).split("\n")
              if b]  # 'name: type' lines
    if sorted(theirs) != sorted(bodies):
        mismatch.append(f"its bodies are {', '.join(theirs) or 'none'}, the sweep's "
                        f"{', '.join(bodies)}")
    if family in ("static", "dynamic"):
        if probes != set(scene_probes):
            mismatch.append(f"its probes are {', '.join(sorted(probes)) or 'none'}, the "
                            f"sweep's {', '.join(scene_probes) or 'none'}")
        elif not pick and response is not None and (probe, component) != tuple(response):
            mismatch.append(f"it compares probe {probe!r} component {component}, the sweep "
                            f"probe {response[0]!r} component {response[1]}")
    if mismatch:
        raise InputError("--reference is a run of another model: " + "; ".join(mismatch),
                         file=where)
    return Reference(path, family, values, time, probe, length, picked)


def add_reference_errors(rows: list[dict], reference: Reference) -> None:
    """err_vs_reference per successful row against the reference (checked by
    :func:`load_reference` to be of the cases' analysis and model): dynamic cases
    max |y(t) - y_ref(t)| over the reference's times within the case's / the range of y_ref
    (the tip sag's range for beams: the measure of benchmarks/peer_harness.py); static
    cases |y - y_ref| / |y_ref|; modal and buckling cases the largest relative difference
    of the frequencies (load factors) both computed. A reference value that is zero to
    round-off leaves the error undefined (:func:`relative_error`). The file is named in
    err_reference_file."""
    for row in rows:
        if row["status"] != "ok":
            continue
        row["err_reference_file"] = str(reference.path)
        if reference.family == "dynamic":
            t, y = _tip_history(row)
            common = reference.time <= t[-1] + 1e-12
            absolute = float(np.abs(np.interp(reference.time[common], t, y)
                                    - reference.values[common]).max())
            err = relative_error(absolute, float(np.ptp(reference.values)),
                                 reference.length_scale, reference.probe, str(reference.path))
        elif reference.family == "static":
            err = relative_error(abs(static_value(row) - reference.values[0]),
                                 abs(float(reference.values[0])), reference.length_scale,
                                 reference.probe, str(reference.path))
        else:
            err = eigen_error(eigen_values(row["file"])[1], reference.values)
        _set_error(row, "err_vs_reference", err)


def add_errors(rows: list[dict], varied: list[str]) -> None:
    """err_vs_finest per row: against the finest resolution with the other keys equal."""
    if any(r.get("dynamic") for r in rows):
        add_history_errors(rows, varied)
        return
    for members, finest in _reference_groups(rows, varied):
        if "analysis" in finest:  # modal or buckling: the eigenvalues both computed
            reference = eigen_values(finest["file"])[1]
            for row in members:
                _set_error(row, "err_vs_finest",
                           eigen_error(eigen_values(row["file"])[1], reference))
            continue
        ref = static_value(finest)
        probe, size = _probe_and_size(finest)
        for row in members:
            absolute = abs(static_value(row) - ref)
            _set_error(row, "err_vs_finest", relative_error(absolute, abs(ref), size, probe,
                                                            finest["file"]))
            row["err_abs_vs_finest"] = absolute  # m (the table: mm)


def run_sweep(scene_file: str, vary: list[str], outdir: str | Path, *,
              base: list[str] | None = None, workers: int | None = None,
              scheduler: str | None = None, progress: bool | None = None,
              start_method: str | None = None,
              connect_timeout: float = CONNECT_TIMEOUT_S,
              reference: str | Path | None = None) -> list[dict]:
    """Run every combination and write the report into ``outdir``. Returns the rows, one per
    case in the order of the combinations, each with a 'status' ('ok' or 'failed'), a
    'message' and an 'exit_code'. Bad input raises InputError before any case runs. Ctrl-C
    writes the report of what finished and raises :class:`SweepInterrupted`.

    ``workers``: local processes (default: all cores; 1 runs the cases in this process);
    ``scheduler``: the address of a Dask distributed scheduler instead (no shared
    filesystem needed); ``start_method``: multiprocessing start method of the local
    workers (default: the platform's); ``connect_timeout``: seconds to reach the scheduler.
    ``reference``: a result file (e.g. a converged model of another formulation) each case
    is also compared with: column err_vs_reference (:func:`add_reference_errors`), which
    the error-against-time chart then shows."""
    base = base or []
    if workers is not None and workers < 1:
        raise InputError(f"--workers {workers}: needs at least 1")
    scene = load_scene(scene_file, base)  # fail early on a bad scene or override
    grid = parse_vary(vary, scene_file)
    keys = [k for k, _ in grid]
    combos = [dict(zip(keys, values)) for values in itertools.product(*[v for _, v in grid])]
    families = set()
    for params in combos:  # validate every case before spending time on any
        case_scene = load_scene(scene_file, base + expand(params))
        families.add(ANALYSIS_FAMILY[case_scene["scene"]["analysis"]])
    pick = not response_named(scene, keys) and bool(families & {"static", "dynamic"})
    if reference is not None:  # read and checked before the first case runs
        reference = load_reference(reference, scene, families, pick=pick)
    outdir = Path(outdir)
    check_sweep_dir(outdir, scene_file)
    sweep_id = uuid.uuid4().hex
    cases = _make_cases(combos, outdir, sweep_id)
    if workers is not None:
        workers = worker_cap(workers, len(cases))
    client = connect(scheduler, connect_timeout) if scheduler else None  # before any output
    lock = None
    try:
        try:
            outdir.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"cannot create the sweep directory: {exc.strerror}",
                             file=str(outdir)) from None
        # one sweep per directory, from its first case until its report is written
        lock = OutputLock(outdir / "summary.csv")
        lock.acquire()
        with ParentSignals() as signals:
            rows, interrupted = _run_cases(scene_file, base, cases, sweep_id, client=client,
                                           workers=workers, start_method=start_method,
                                           progress=progress, scene_text=scene.text)
            signals.armed = False  # the report is written whatever comes now
            check_sweep_ids(rows, sweep_id)
            if pick:
                apply_picked_response(rows, reference)
            report(rows, keys, outdir, scene_file, base, reference)
    finally:
        if client is not None:
            client.close()
        if lock is not None:
            lock.release()
    if interrupted or signals.signum is not None:
        raise SweepInterrupted(rows, outdir, signals.signum)
    return rows


def apply_picked_response(rows: list[dict], reference: Reference | None) -> None:
    """A general scene's sweep without a named response compares the probe and component
    that move most in the reference (``--reference``), else in the first successful case
    (:func:`pick_response`): each successful static or dynamic row records them
    (response_probe, response_component, and why in response_picked), and a static row's
    compared value is read again for them. Nothing moves: the files' own response."""
    ok = [r for r in rows if r["status"] == "ok" and "analysis" not in r]
    if not ok:
        return
    picked = reference.picked if reference is not None else \
        pick_response(ok[0]["file"], f"case {ok[0]['case']}")
    if picked is None:
        return
    (probe, component), why = picked
    for row in ok:
        row.update(response_probe=probe, response_component=component, response_picked=why)
        if not row.get("dynamic"):
            for key in ("tip_axial", "tip_transverse", "tip_lateral", "response"):
                row.pop(key, None)
            with h5py.File(row["file"], "r") as h5:
                row.update(static_response(_static_deflection(h5, probe), probe, component))


def check_sweep_dir(outdir: Path, scene_file: str) -> None:
    """The sweep's output must be a directory (or not exist yet): an existing file, the
    scene itself included, is refused before anything runs (InputError, exit 2)."""
    if outdir.is_symlink() and not outdir.exists():
        raise InputError("the sweep directory is a broken symbolic link", file=str(outdir))
    if outdir.exists() and not outdir.is_dir():
        scene = Path(scene_file)
        same = scene.exists() and os.path.samefile(outdir, scene)
        raise InputError("the sweep output is " + ("the scene file itself" if same else
                         "an existing file") + "; -o names a directory for the sweep's files",
                         file=str(outdir))
    parent = outdir
    while not parent.exists() and parent.parent != parent:
        parent = parent.parent
    if parent.exists() and not parent.is_dir():
        raise InputError(f"cannot create the sweep directory: {parent} is not a directory",
                         file=str(outdir))


def _run_cases(scene_file: str, base: list[str], cases: list[Case], sweep_id: str, *,
               client: Any, workers: int | None, start_method: str | None,
               progress: bool | None, scene_text: str) -> tuple[list[dict], bool]:
    """Every case's row (in the order of ``cases``), and whether Ctrl-C stopped the sweep.
    Each file is moved to its final name with this sweep's id as it arrives."""
    rows: dict[int, dict] = {}
    show = sys.stderr.isatty() if progress is None else progress
    bar = tqdm(total=len(cases), desc="sweep", unit="case", disable=not show)
    client_scene = str(Path(scene_file).resolve())

    def record(case: Case, row: dict, data: bytes | None) -> None:
        if case.index in rows:
            return
        row["case"] = case.name
        row["file"] = store_case_file(case, sweep_id, data,
                                      scene_file=client_scene if data is not None else None)
        if row["status"] == "ok" and not row["file"]:
            row.update(status="failed", exit_code=1, message="the case reported success but "
                       "its result file is missing or unreadable")
        rows[case.index] = row
        bar.update()

    try:
        if client is not None:
            interrupted = run_dask(client, scene_text, str(scene_file), cases, record)
        elif (workers or os.cpu_count() or 1) > 1 and len(cases) > 1:
            interrupted = run_processes(scene_file, base, cases, record,
                                        workers=workers or os.cpu_count() or 1,
                                        start_method=start_method)
        else:
            interrupted = run_inline(scene_file, base, cases, record)
    finally:
        bar.close()
    for case in cases:  # a case Ctrl-C caught between two steps
        if case.index not in rows:
            record(case, failure(case.params, "interrupted", "stopped by Ctrl-C",
                                 INTERRUPTED_EXIT), None)
    return [rows[case.index] for case in cases], interrupted


def _make_cases(combos: list[dict[str, str]], outdir: Path, sweep_id: str) -> list[Case]:
    """The cases with their file names; every file is a direct child of ``outdir``."""
    names = case_names(combos)
    if len({n.lower() for n in names}) != len(names):
        raise InputError("two cases of the sweep would share a result file name: "
                         f"{', '.join(sorted(n for n in names if names.count(n) > 1))}")
    cases = []
    for index, (params, name) in enumerate(zip(combos, names)):
        output = outdir / f"{name}.h5"
        if output.resolve().parent != outdir.resolve():  # cannot happen: no separator
            raise InputError(f"case file {output} would leave the sweep directory {outdir}")
        cases.append(Case(index, name, params, expand(params), output,
                          outdir / f".{name}.{sweep_id[:12]}.part.h5"))
    return cases


def store_case_file(case: Case, sweep_id: str, data: bytes | None = None, *,
                    scene_file: str | None = None) -> str:
    """Move a case's file from its part path to its final name in the sweep directory
    (writing ``data`` there first when the case ran remotely), with the root attribute
    ``sweep_id`` (and 'scene_file', the client's scene, for a remote case). Returns the
    final path, or '' when the case left no readable file."""
    if data is not None:
        write_bytes(case.part, data)
    stale = case.part.with_suffix(".xdmf")  # names the part file: rewritten below
    if not case.part.is_file():
        remove_quietly(stale)
        return ""
    try:
        with h5py.File(case.part, "a") as h5:
            h5.attrs["sweep_id"] = sweep_id
            if scene_file:
                h5.attrs["scene_file"] = scene_file
            motion = "dynamic/mesh_nodes" in h5 and len(h5["dynamic/time"]) > 0
    except OSError:  # a file its killed process left half-written
        remove_quietly(case.part)
        remove_quietly(stale)
        return ""
    remove_quietly(stale)
    if motion:  # written for the final name before the file appears there
        from .results.xdmf import write_xdmf
        write_xdmf(case.part, as_name=case.output)
    os.replace(case.part, case.output)
    return str(case.output)


def read_sweep_id(path: str | Path) -> str | None:
    """The 'sweep_id' root attribute of a result file (None when absent or unreadable)."""
    try:
        with h5py.File(path, "r") as h5:
            value = h5.attrs.get("sweep_id")
    except OSError:
        return None
    return value.decode() if isinstance(value, bytes) else (None if value is None else str(value))


def check_sweep_ids(rows: list[dict], sweep_id: str) -> None:
    """Fail every 'ok' row whose file does not carry this sweep's id: the tables never
    read a file another run left under the same name."""
    for row in rows:
        if row["status"] != "ok":
            continue
        found = read_sweep_id(row["file"]) if row.get("file") else None
        if found != sweep_id:
            what = f"sweep_id {found}" if found else "no sweep_id"
            row.update(status="failed", exit_code=1, message=(
                f"{row.get('file') or 'the result file'} has {what}, not this sweep's "
                f"{sweep_id}: a file of another run, not used"))


def report(rows: list[dict], keys: list[str], outdir: Path, scene_file: str,
           base: list[str], reference: Reference | None = None) -> None:
    """Errors, closed-form comparisons, summary.csv, summary.md and the plots."""
    add_errors(rows, keys)
    if reference is not None:
        add_reference_errors(rows, reference)
    add_formulation_difference(rows, keys)
    for row in rows:
        if row["status"] == "ok" and not row.get("dynamic") and "analysis" not in row:
            err = closed_form_error(scene_file, row, base)
            if err is not None:
                row["err_vs_closed_form"] = err
    write_report(rows, keys, outdir)
    if not any(r["status"] == "ok" for r in rows):
        return
    from .plots import plot_sweep
    try:
        plot_sweep(rows, keys, outdir)
    except Exception as exc:  # the tables are written; a plot bug must not lose them
        print(f"warning: sweep plots not written: {type(exc).__name__}: {exc}", file=sys.stderr)


COLUMNS = [("tip_transverse", "static sag (mm)", 1e3, "{:.4f}"),
           ("response", "static response (mm)", 1e3, "{:.5f}"),
           ("response_closed_form", "closed form (mm)", 1e3, "{:.5f}"),
           ("tip_transverse_closed_form", "closed form (mm)", 1e3, "{:.4f}"),
           ("first_frequency_hz", "f1 (Hz)", 1.0, "{:.5g}"),
           ("first_load_factor", "load factor 1", 1.0, "{:.5g}"),
           ("err_vs_closed_form", "err vs closed form", 1.0, "{:.2e}"),
           ("err_vs_finest", "err vs finest", 1.0, "{:.2e}"),
           ("err_abs_vs_finest", "err vs finest (mm)", 1e3, "{:.3e}"),
           ("err_vs_reference", "err vs reference", 1.0, "{:.2e}"),
           ("phase_err_deg", "phase err (deg)", 1.0, "{:+.2f}"),
           ("diff_vs_nonlinear", "diff vs nonlinear", 1.0, "{:.2e}"),
           ("vibration_frequency_hz", "f vib (Hz)", 1.0, "{:.4f}"),
           ("iterations", "iterations", 1, "{}"),
           ("solve_time_s", "solve time (ms)", 1e3, "{:.2f}"),
           ("steps", "steps", 1, "{}"),
           ("newton_iterations", "Newton", 1, "{}"),
           ("factorizations", "factor.", 1, "{}"),
           ("dynamic_time_s", "dynamic (s)", 1.0, "{:.3f}"),
           ("eigen_time_s", "eigen (s)", 1.0, "{:.3f}"),
           ("compute_time_s", "compute (s)", 1.0, "{:.3f}"),
           ("total_time_s", "case time (s)", 1.0, "{:.3f}"),
           ("status", "status", None, "{}")]


def table_lines(rows: list[dict], keys: list[str]) -> list[str]:
    """The Markdown table of a sweep (what `make demo` prints), followed by the note naming
    the reference of 'err vs finest'. An error against a reference that is not the finest
    case requested (it failed) is marked '*'."""
    cols = [c for c in COLUMNS if any(c[0] in r or f"{c[0]}_undefined" in r for r in rows)]
    header = keys + [c[1] for c in cols]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for row in rows:
        cells = [str(row[k]) for k in keys]
        for key, _, scale, fmt in cols:
            value = row.get(key)
            if f"{key}_undefined" in row:
                cells.append("n/a")
            elif value is None or value == "":
                cells.append("-")
            else:
                cells.append(fmt.format(value * scale if scale not in (None, 1) else value))
                if key in ("err_vs_finest", "err_abs_vs_finest") and \
                        not row.get("err_reference_is_finest", True):
                    cells[-1] += " *"
        lines.append("| " + " | ".join(cells) + " |")
    notes = response_notes(rows) + reference_notes(rows, keys) + undefined_notes(rows)
    return lines + ([""] + notes if notes else [])


def response_notes(rows: list[dict]) -> list[str]:
    """The response the sweep picked and why (:func:`apply_picked_response`), once."""
    return sorted({r["response_picked"] for r in rows if "response_picked" in r})


def undefined_notes(rows: list[dict]) -> list[str]:
    """Why an error shows 'n/a': one line per column and reason, naming the cases."""
    cases: dict[tuple[str, str], list[str]] = {}
    for key, label, _, _ in COLUMNS:
        for row in rows:
            if f"{key}_undefined" in row:
                cases.setdefault((label, row[f"{key}_undefined"]), []).append(
                    str(row.get("case", "?")))
    return [f"n/a: {label} of {', '.join(names)}: {why}"
            for (label, why), names in cases.items()]


def reference_notes(rows: list[dict], keys: list[str]) -> list[str]:
    """Which case each 'err vs finest' is taken against, and where that is not the finest
    case requested because the finest failed: never silently."""
    if not any(is_resolution(k) for k in keys):
        return []
    refs: dict[str, dict] = {}
    for row in rows:
        if "err_reference" in row:
            refs.setdefault(row["err_reference"], row)
    if not refs:
        return []
    finest = [name for name, row in refs.items() if row.get("err_reference_is_finest", True)]
    lines = []
    if finest:
        shown = ", ".join(finest[:4]) + (f" and {len(finest) - 4} more (column err_reference "
                                         "of summary.csv)" if len(finest) > 4 else "")
        lines.append(f"err vs finest: reference {shown} (the finest case"
                     f"{' of each group' if len(finest) > 1 else ''})")
    status = {r.get("case"): r["status"] for r in rows}
    for name, row in refs.items():
        if not row.get("err_reference_is_finest", True):
            requested = row["err_finest_requested"]
            lines.append(f"* err vs finest: reference {name}, NOT the finest case requested "
                         f"({requested}: {status.get(requested, 'failed')})")
    return lines


def write_report(rows: list[dict], keys: list[str], outdir: Path) -> None:
    fields = keys + sorted({k for r in rows for k in r} - set(keys))
    with replace_atomically(outdir / "summary.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=fields)
        writer.writeheader()
        for row in rows:
            writer.writerow(row)
    counts = Counter(r["status"] for r in rows)
    dynamic = any(r.get("dynamic") for r in rows)
    eigen = {r["analysis"] for r in rows if "analysis" in r}
    if dynamic:
        what = ("max |sag(t) - sag_ref(t)| / max |sag_ref| over the history; the phase error "
                "is accumulated over the vibration stage")
    elif eigen:
        what = ("the largest relative difference of the "
                + " and ".join({"modal": "elastic frequencies (Hz; rigid-body modes left out)",
                                "buckling": "load factors"}[a] for a in sorted(eigen))
                + " both cases computed, in ascending order; the headline is the first")
    else:
        what = "the relative difference of the tip sag"
    status = ", ".join(f"{n} {s}" for s, n in counts.items() if s != "ok")
    lines = ["# Sweep summary", "", f"{len(rows)} cases, {counts['ok']} ok"
             f"{', ' + status if status else ''}. Error against "
             f"the finest case: {what}" + ("" if eigen and not dynamic else
             ", relative and in mm (beams: tip sag = transverse tip "
             "deflection in the rigid frame; general scenes: the response probe's deflection "
             "relative to the rigid motion of its beam's supports, /deflection_support; plates "
             "and leaves: the r3 displacement of the corner, centre or end probe); a relative "
             "error against a deflection that is zero to round-off (at most "
             f"{ZERO_DEFLECTION:g} of the model's size) is n/a")
             + ". Times are wall-clock seconds of this machine.", ""]
    lines += table_lines(rows, keys)
    noted = [r for r in rows if r.get("message")]
    if noted:
        lines.append("")
    for row in noted:
        lines.append(f"- {row['case']} ({row['status']}"
                     f"{', exit ' + str(row['exit_code']) if row['status'] != 'ok' else ''}): "
                     f"{row['message']}")
    write_text(outdir / "summary.md", "\n".join(lines) + "\n")
