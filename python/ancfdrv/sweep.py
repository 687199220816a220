"""Parameter sweeps: every combination of ``--vary`` values, run in parallel processes (or
on a Dask distributed scheduler), one HDF5 per case, and the accuracy-versus-time report:
``summary.csv``, ``summary.md`` and plots.

Error is taken against the finest case of the sweep with the same non-resolution
parameters (most ``beam.nodes``, smallest ``solver.dt``); for boom scenes the error against
the closed-form small-deflection solution (docs/boom_closed_form.md) is reported too.
"""
from __future__ import annotations

import csv
import itertools
import os
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from tqdm import tqdm

from .errors import AncfError, InputError
from .io.scene import SCHEMA, load_scene

#: Parameters that refine a model; the finest value is the reference of the others.
RESOLUTION_KEYS = {"beam.nodes": max, "solver.dt": min, "plate.nx": max, "plate.ny": max,
                   "leaf.nx": max, "leaf.ny": max}


def is_resolution(key: str) -> bool:
    """A refining key, or keys tied with '+' that all refine (plate.nx+plate.ny)."""
    return all(part in RESOLUTION_KEYS for part in key.split("+"))


def resolution_sense(key: str):
    return RESOLUTION_KEYS[key.split("+")[0]]


def expand(params: dict[str, str]) -> list[str]:
    """Overrides of a case; a tied key 'a.x+a.y' sets every key it names."""
    return [f"{part}={v}" for k, v in params.items() for part in k.split("+")]


def parse_vary(items: list[str], scene_file: str) -> list[tuple[str, list[str]]]:
    """``GROUP.KEY=V1,V2,...`` -> (dotted key, values); keys are checked against the schema.
    Keys joined by '+' vary together (``plate.nx+plate.ny=2,4,8``: 2x2, 4x4, 8x8)."""
    out = []
    for item in items:
        if "=" not in item or "." not in item.split("=", 1)[0]:
            raise InputError(f"--vary {item!r} is not of the form GROUP.KEY=V1,V2,...",
                             file=scene_file)
        dotted, values = item.split("=", 1)
        dotted = dotted.strip().lower()
        for part in dotted.split("+"):
            if "." not in part:
                raise InputError(f"--vary names {part!r}, not GROUP.KEY", file=scene_file)
            group, key = part.split(".", 1)
            if group not in SCHEMA or key not in SCHEMA[group]:
                raise InputError(f"--vary names an unknown key {part!r}", file=scene_file,
                                 group=group, key=key)
        vals = [v.strip() for v in values.split(",") if v.strip()]
        if not vals:
            raise InputError(f"--vary {dotted} has no values", file=scene_file, group=group,
                             key=key)
        out.append((dotted, vals))
    return out


def case_name(params: dict[str, str]) -> str:
    def short(key: str) -> str:
        return "+".join(part.split(".")[1] for part in key.split("+"))
    return "_".join(f"{short(k)}-{v}" for k, v in params.items()).replace("'", "")


def run_case(scene_file: str, params: dict[str, str], base: list[str], output: str) -> dict:
    """Run one case in a worker; never raises (failures become a row with a message)."""
    from .runner import run_scene
    row: dict[str, Any] = dict(params)
    row["file"] = output
    try:
        outcome = run_scene(scene_file, base + expand(params), output)
    except AncfError as exc:
        row.update(status="failed", message=str(exc), exit_code=exc.exit_code)
        return row
    from .io.hdf5 import read_summary
    summary = read_summary(Path(output))
    row.update(status="ok", message="", exit_code=0, total_time_s=summary["timing.total"],
               ndof=summary["model.ndof"])
    static, dynamic = outcome.static, outcome.dynamic
    if static is not None:
        row.update(iterations=static.iterations, residual=static.residual_norm,
                   solve_time_s=static.wall_time_s)
        if "static.deflection.tip" in summary:
            axial, transverse, lateral = summary["static.deflection.tip"]
            row.update(tip_axial=axial, tip_transverse=transverse, tip_lateral=lateral)
        else:
            probe, component = _response_of(summary)
            row["response"] = float(summary[f"static.deflection.{probe}"][component])
    if dynamic is not None:
        row.update(dynamic=True, steps=dynamic.steps, newton_iterations=dynamic.newton_iterations,
                   factorizations=dynamic.factorizations, dynamic_time_s=dynamic.wall_time_s,
                   **{f"stage_{k}": v for k, v in outcome.stages.items()})
    return row


def _response_of(attrs) -> tuple[str, int]:
    """The probe and component a sweep compares: the beam's tip sag (tip, transverse), or
    what the model names in the result file's 'response_probe' attributes."""
    probe = attrs.get("response_probe", "tip")
    return (probe.decode() if isinstance(probe, bytes) else str(probe),
            int(attrs.get("response_component", 1)))


def static_value(row: dict) -> float:
    """The static quantity a sweep compares (tip sag for beams)."""
    return row["tip_transverse"] if "tip_transverse" in row else row["response"]


def _tip_history(path: str) -> tuple[np.ndarray, np.ndarray]:
    """Time and the compared history (the tip sag for beams)."""
    with h5py.File(path, "r") as h5:
        probe, component = _response_of(h5.attrs)
        return h5["dynamic/time"][()], h5[f"dynamic/deflection/{probe}"][:, component]


def add_history_errors(rows: list[dict], varied: list[str]) -> None:
    """Dynamic cases: against the finest case with the same other keys, the amplitude
    error max|y - y_ref| / max|y_ref| of the tip sag history, and the phase error
    accumulated over the vibration stage, 360 (f - f_ref) T_vib in degrees, from
    zero-crossing frequencies."""
    from .history import crossing_frequency
    for members, finest in _reference_groups(rows, varied):
        t_ref, y_ref = _tip_history(finest["file"])
        scale = max(np.abs(y_ref).max(), 1e-300)
        t0, t1 = finest.get("stage_vibration_t0"), finest.get("stage_vibration_t1")
        f_ref = None
        if t0 is not None:
            mask = t_ref >= t0
            f_ref = crossing_frequency(t_ref[mask], y_ref[mask])
        for row in members:
            t, y = _tip_history(row["file"])
            common = t_ref <= t[-1]
            row["err_vs_finest"] = float(np.abs(np.interp(t_ref[common], t, y)
                                                - y_ref[common]).max() / scale)
            if f_ref is not None:
                mask = t >= t0
                f = crossing_frequency(t[mask], y[mask])
                row["vibration_frequency_hz"] = f
                row["phase_err_deg"] = float(360.0 * (f - f_ref) * (t1 - t0))


def closed_form_error(scene_file: str, row: dict, base: list[str]) -> float | None:
    """Relative error of the tip sag against the boom's closed form (None if not a boom)."""
    from .reference.analytic import boom_static_tip_deflection
    params = expand({k: row[k] for k in row if "." in k})
    scene = load_scene(scene_file, base + params)
    if row.get("status") != "ok":
        return None
    if scene.kind == "plate":
        return _navier_error(scene, row)
    if scene.kind != "boom":
        return None
    effects, loads = scene.effects, scene["loads"]
    beam, material = scene["beam"], scene["material"]
    _, reference = boom_static_tip_deflection(
        scene["boom"]["angle_deg"], loads["tip_mass"] if "tip_mass" in effects else 0.0,
        length=beam["length"], a=beam["segments"][0], H=scene["boom"]["pivot_offset"],
        width=beam["width"], height=beam["height"], youngs=material["youngs_modulus"],
        density=material["density"], poisson=material["poisson_ratio"],
        gravity=loads["gravity"] if "gravity" in effects else 0.0,
        moment=loads["moment"] if "bending_moment" in effects else 0.0, shear=True)
    row["tip_transverse_closed_form"] = reference
    return abs(row["tip_transverse"] - reference) / max(abs(reference), 1e-300)


def _navier_error(scene, row: dict) -> float | None:
    """Simply supported plate under pressure alone: error of the centre deflection against
    Navier's series (REFERENCES.md: 0.00406 q a^4 / D for the square plate)."""
    from .reference.analytic import navier_plate_centre_deflection
    plate, material = scene["plate"], scene["material"]
    if plate["support"] != "simply_supported" or set(scene.effects) != {"pressure"}:
        return None
    reference = -navier_plate_centre_deflection(
        scene["loads"]["pressure"], plate["length_x"], plate["length_y"],
        material["youngs_modulus"], material["poisson_ratio"], plate["thickness"])
    row["response_closed_form"] = reference
    return abs(row["response"] - reference) / max(abs(reference), 1e-300)


def _reference_groups(rows: list[dict], varied: list[str]):
    """(members, finest) per group of successful rows equal in the non-resolution keys."""
    resolution = [k for k in varied if is_resolution(k)]
    others = [k for k in varied if not is_resolution(k)]
    groups: dict[tuple, list[dict]] = {}
    for row in rows:
        if row["status"] == "ok":
            groups.setdefault(tuple(row[k] for k in others), []).append(row)
    for members in groups.values():
        def rank(row: dict) -> tuple:
            return tuple((-1 if resolution_sense(k) is max else 1) * float(row[k])
                         for k in resolution)
        yield members, min(members, key=rank)


def add_formulation_difference(rows: list[dict], varied: list[str]) -> None:
    """When scene.formulation is varied: each row's difference from the large-deformation
    ('nonlinear') case with the same other keys - what the FFR model's assumptions cost,
    next to what they save in time (static: relative tip sag; dynamic: max |sag(t) -
    sag_nl(t)| / max |sag_nl|)."""
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
        if row.get("dynamic"):
            t_ref, y_ref = _tip_history(ref["file"])
            t, y = _tip_history(row["file"])
            common = t_ref <= t[-1]
            row["diff_vs_nonlinear"] = float(np.abs(np.interp(t_ref[common], t, y) - y_ref[common])
                                             .max() / max(np.abs(y_ref).max(), 1e-300))
        else:
            row["diff_vs_nonlinear"] = abs(static_value(row) - static_value(ref)) / max(
                abs(static_value(ref)), 1e-300)


def add_errors(rows: list[dict], varied: list[str]) -> None:
    """err_vs_finest per row: against the finest resolution with the other keys equal."""
    if any(r.get("dynamic") for r in rows):
        add_history_errors(rows, varied)
        return
    for members, finest in _reference_groups(rows, varied):
        for row in members:
            ref = static_value(finest)
            row["err_vs_finest"] = abs(static_value(row) - ref) / max(abs(ref), 1e-300)


def run_sweep(scene_file: str, vary: list[str], outdir: str | Path, *, base: list[str] | None = None,
              workers: int | None = None, scheduler: str | None = None,
              progress: bool | None = None) -> list[dict]:
    """Run every combination and write the report into ``outdir``. Returns the rows."""
    base = base or []
    load_scene(scene_file, base)  # fail early on a bad scene or override
    grid = parse_vary(vary, scene_file)
    keys = [k for k, _ in grid]
    combos = [dict(zip(keys, values)) for values in itertools.product(*[v for _, v in grid])]
    for params in combos:  # validate every case before spending time on any
        load_scene(scene_file, base + expand(params))
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    jobs = [(scene_file, p, base, str(outdir / f"{case_name(p)}.h5")) for p in combos]
    show = sys.stderr.isatty() if progress is None else progress
    rows: list[dict] = []
    bar = tqdm(total=len(jobs), desc="sweep", unit="case", disable=not show)
    if scheduler:
        try:
            from dask.distributed import Client, as_completed as dask_completed
        except ImportError:
            raise InputError("--scheduler needs dask[distributed]: pip install 'dask[distributed]'")
        with Client(scheduler) as client:
            futures = [client.submit(run_case, *job, pure=False) for job in jobs]
            for future in dask_completed(futures):
                rows.append(future.result())
                bar.update()
    elif (workers or os.cpu_count() or 1) > 1 and len(jobs) > 1:
        with ProcessPoolExecutor(max_workers=workers or os.cpu_count()) as pool:
            futures = [pool.submit(run_case, *job) for job in jobs]
            for future in as_completed(futures):
                rows.append(future.result())
                bar.update()
    else:
        for job in jobs:
            rows.append(run_case(*job))
            bar.update()
    bar.close()
    order = {case_name(p): i for i, p in enumerate(combos)}
    rows.sort(key=lambda r: order[case_name({k: r[k] for k in keys})])
    add_errors(rows, keys)
    add_formulation_difference(rows, keys)
    for row in rows:
        if row["status"] == "ok" and not row.get("dynamic"):
            err = closed_form_error(scene_file, row, base)
            if err is not None:
                row["err_vs_closed_form"] = err
    write_report(rows, keys, outdir)
    from .plots import plot_sweep
    plot_sweep(rows, keys, outdir)
    return rows


COLUMNS = [("tip_transverse", "static sag (mm)", 1e3, "{:.4f}"),
           ("response", "static response (mm)", 1e3, "{:.5f}"),
           ("response_closed_form", "closed form (mm)", 1e3, "{:.5f}"),
           ("tip_transverse_closed_form", "closed form (mm)", 1e3, "{:.4f}"),
           ("err_vs_closed_form", "err vs closed form", 1.0, "{:.2e}"),
           ("err_vs_finest", "err vs finest", 1.0, "{:.2e}"),
           ("phase_err_deg", "phase err (deg)", 1.0, "{:+.2f}"),
           ("diff_vs_nonlinear", "diff vs nonlinear", 1.0, "{:.2e}"),
           ("vibration_frequency_hz", "f vib (Hz)", 1.0, "{:.4f}"),
           ("iterations", "iterations", 1, "{}"),
           ("solve_time_s", "solve time (ms)", 1e3, "{:.2f}"),
           ("steps", "steps", 1, "{}"),
           ("newton_iterations", "Newton", 1, "{}"),
           ("factorizations", "factor.", 1, "{}"),
           ("dynamic_time_s", "dynamic (s)", 1.0, "{:.3f}"),
           ("total_time_s", "case time (s)", 1.0, "{:.3f}"),
           ("status", "status", None, "{}")]


def table_lines(rows: list[dict], keys: list[str]) -> list[str]:
    """The Markdown table of a sweep (what `make demo` prints)."""
    cols = [c for c in COLUMNS if any(c[0] in r for r in rows)]
    header = keys + [c[1] for c in cols]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for row in rows:
        cells = [str(row[k]) for k in keys]
        for key, _, scale, fmt in cols:
            value = row.get(key)
            if value is None or value == "":
                cells.append("-")
            else:
                cells.append(fmt.format(value * scale if scale not in (None, 1) else value))
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def write_report(rows: list[dict], keys: list[str], outdir: Path) -> None:
    fields = keys + sorted({k for r in rows for k in r} - set(keys))
    with open(outdir / "summary.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=fields)
        writer.writeheader()
        for row in rows:
            writer.writerow(row)
    failed = [r for r in rows if r["status"] != "ok"]
    dynamic = any(r.get("dynamic") for r in rows)
    what = ("max |sag(t) - sag_ref(t)| / max |sag_ref| over the history; the phase error is "
            "accumulated over the vibration stage" if dynamic else
            "the relative difference of the tip sag")
    lines = ["# Sweep summary", "", f"{len(rows)} cases, {len(failed)} failed. Error against "
             f"the finest case: {what} (beams: tip sag = transverse tip deflection in the rigid "
             "frame; plates and leaves: the r3 displacement of the corner, centre or end probe). "
             "Times are wall-clock seconds of this machine.", ""]
    lines += table_lines(rows, keys)
    for row in failed:
        lines += ["", f"- {case_name({k: row[k] for k in keys})}: {row['message']}"]
    (outdir / "summary.md").write_text("\n".join(lines) + "\n")
