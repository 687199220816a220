#!/usr/bin/env python
"""Nonlinear cantilever, 8 to 512 elements: time per step and peak memory of ancfdrv's
planar ANCF cable against Exudyn's ObjectANCFCable2D on the same physics (issue 23:
"time per step <= Exudyn's, memory <= 1.5x" at 128 and 512 elements).

The problem (``inputs/hard/cantilever_drop.nml``; both codes read its data): a 1 m steel
strip of 1 mm x 1 mm section (E = 2.1e11 Pa, rho = 7850 kg/m^3), clamped at the root,
straight and horizontal at rest, released under gravity g = 9.81 m/s^2 in -y
(q L^3 / EI = 4.4: large rotation, the tip falls by about half the length and swings
back; axial strains ~1e-6, so the two codes' different axial strain measures, Green's
(r'.r' - 1)/2 and |r'| - 1, and curvature measures agree to far below the compared
differences). 0 ... ``--t-end`` (1 s) with fixed steps ``--dt`` (1 ms), generalized-alpha
with the scene's rho_inf = 0.8, the same in both codes.

* ancfdrv: :func:`ancfdrv.runner.run_loaded` on the scene with ``beam.nodes = n + 1``:
  ``beam.bending = 'cable'`` (r and r_x per node) with ``scene.planar = 'xy'`` (4 unknowns
  per node), the clamp a weld of r and r_x at the root; newton_tol 1e-10 (a step ends when
  its correction is below 1e-10 m); one OpenMP thread (ancfdrv's default); HDF5 output to
  a temporary directory. The cubic option (``beam.bending = 'cubic'``, planar: 7 unknowns
  per node) is timed too, for reference (``--options``).
* Exudyn: ``ObjectANCFCable2D`` elements (EA, EI = E w h^3 / 12, rho A from the scene)
  from ``exudyn.beams.GenerateBeamElementsAlongLine`` with gravity on every element and
  ``groundConstraintsStart = [1, 1, 1, 1]`` (position and slope of the root fixed: the
  same weld), a tip ``SensorNode`` stored every step, its generalized-alpha solver with
  the same rho_inf and step, fixed steps, index-3 constraints, Newton relative tolerance
  1e-8 and absolute 1e-10 (its defaults; benchmarks/peer_exudyn.py's fallbacks 1e-8 ...
  1e-4 where it fails), its sparse LU (EigenSparse), one thread, no solution file.

Time per step: the dynamic solve / steps (ancfdrv: the ``/dynamic`` ``wall_time_s`` of the
result file, stepping and per-chunk output; ``stepping_s`` is its ``timing/dynamic_stepping``
alone; Exudyn: ``mbs.SolveDynamic``). Every configuration runs ``--repeats`` (3) times in
one process, interleaved (round r runs every configuration once before round r + 1
starts), and keeps its best; the whole call (scene, model, solve, output; Exudyn: system,
assembly, solve, sensor) is kept too. Ratios: Exudyn's time / ancfdrv's (> 1: ancfdrv is
faster).

Peak memory: every configuration runs once more in a fresh interpreter
(``--worker``), which reports ``ru_maxrss`` (the peak resident set, MB) before any import,
after the imports (ancfdrv: ``ancfdrv.runner``; Exudyn: ``exudyn``, ``exudyn.beams``,
``exudyn.itemInterface``; the scene's data come from the harness, ancfdrv is not
imported), after building the model (ancfdrv: scene and
``build_model``; Exudyn: items and ``Assemble``) and at the end of the solve. ``peak_mb``
is the last; ``increment_mb`` = peak - after imports (what the model and the solve add,
comparable between the two codes whatever their imports cost); both are reported and
compared. Two readings of ancfdrv: as shipped (``run_loaded``: the HDF5 file with its
defaults, XDMF frames for ParaView and the answers: reactions, cable tension) and like for
like with Exudyn's run, which keeps one sensor in memory and writes nothing (``--memory``
row ``ancfdrv/cable in memory``: :func:`ancfdrv.simulate`, results in memory, without
``output.xdmf`` and ``output.answers``; h5py is still imported by the package). ancfdrv's
modules are byte-compiled first (``compileall``, as ``pip install`` does and as Exudyn's
are): an editable install under PYTHONDONTWRITEBYTECODE compiled every module at import
(~3 MB of the peak).

Same physics: the tip's (x, y) histories of ancfdrv's cable and Exudyn at the same mesh
are compared on a uniform grid (every ``--sample-dt``, 10 ms), as max |difference| in m
and relative to the range of the tip's y; each code's mesh convergence is reported as the
difference to its own finest mesh.

Output: ``benchmarks/results/peer_cantilever.json`` and ``.md`` (``--quick``:
``peer_cantilever_quick.json``, ignored by git, Markdown only inside the JSON). Run from the
repository root::

    python benchmarks/peer_cantilever.py              # 8, 32, 128, 512 elements, ~5 min
    python benchmarks/peer_cantilever.py --quick      # 8 and 32 elements, 0.1 s: ~20 s
    python benchmarks/peer_cantilever.py --elements 512 --options cable --repeats 1

When Exudyn cannot be imported (``pip install exudyn``), its runs are skipped and the
ratios are null.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
SCENE = REPO / "inputs" / "hard" / "cantilever_drop.nml"
#: Exudyn's Newton: its default tolerances first, then peer_exudyn.py's fallbacks.
EXUDYN_RELATIVE_TOL = 1e-8
EXUDYN_ABSOLUTE_TOLS = (1e-10, 1e-8, 1e-6, 1e-4)
#: ancfdrv's options: 'cable' (the comparison) and 'cubic' (for reference), both planar.
OPTIONS = ("cable", "cubic")
#: the like-for-like memory configuration (fresh interpreter only): the cable in memory
IN_MEMORY = "ancfdrv/cable in memory"


def rss_mb() -> float:
    """Peak resident set size of this process image so far, MB: ``VmHWM`` of
    /proc/self/status where there is one, else ``ru_maxrss`` (KiB on Linux). The two are
    the same high-water mark, except that Linux carries ``ru_maxrss`` over an exec: a
    worker started from the harness would report the harness's own peak."""
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


# -- one run of each code ----------------------------------------------------------------------
def ancfdrv_overrides(option: str, elements: int, dt: float, t_end: float) -> list[str]:
    """--set-style overrides of the scene: the mesh, the step, the end and the option."""
    return [f"beam.nodes={elements + 1}", f"solver.dt={dt!r}", f"solver.t_end={t_end!r}",
            f"beam.bending={option}", "scene.planar=xy"]


def run_ancfdrv(option: str, elements: int, dt: float, t_end: float, out: Path,
                checkpoints: dict[str, float] | None = None) -> dict[str, Any]:
    """One whole call: scene, model, dynamic solve and HDF5 output. Returns times, counts
    and the tip history (t, x, y); ``checkpoints`` gets ru_maxrss after the build and at
    the end."""
    import h5py

    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    from ancfdrv.runner import run_loaded

    t0 = time.perf_counter()
    scene = load_scene(SCENE, ancfdrv_overrides(option, elements, dt, t_end))
    model = build_model(scene)
    ndof = int(model.ndof)
    if checkpoints is not None:
        checkpoints["after_build"] = rss_mb()
    outcome = run_loaded(scene, out, model=model, progress=False)
    whole = time.perf_counter() - t0
    if checkpoints is not None:
        checkpoints["after_solve"] = rss_mb()
    dyn = outcome.dynamic
    assert dyn is not None
    with h5py.File(out, "r") as h5:
        attrs = h5["dynamic"].attrs
        timing = h5["timing"].attrs
        tip = h5["dynamic/probes/tip"][()]
        t = h5["dynamic/time"][()]
        record = {"solve_s": float(attrs["wall_time_s"]),
                  "stepping_s": float(timing["dynamic_stepping"]),
                  "output_s": float(timing.get("dynamic_output", float("nan"))),
                  "model_s": float(timing["model"]),
                  "steps": int(attrs["steps"]),
                  "newton_iterations": int(attrs["newton_iterations"]),
                  "factorizations": int(attrs["factorizations"])}
    out.unlink()
    record.update(whole_s=whole, unknowns=ndof, t=t.tolist(), x=tip[:, 0].tolist(),
                  y=tip[:, 1].tolist())
    return record


def scene_data() -> dict[str, float]:
    """The beam, load and integrator data of the scene (for Exudyn)."""
    from ancfdrv.io.scene import load_scene

    scene = load_scene(SCENE, [])
    beam, material, solver = scene["beam"], scene["material"], scene["solver"]
    area = beam["width"] * beam["height"]
    return {"length": beam["length"], "mass_per_length": material["density"] * area,
            "axial_stiffness": material["youngs_modulus"] * area,
            "bending_stiffness": material["youngs_modulus"] * beam["width"]
            * beam["height"] ** 3 / 12.0,
            "gravity": scene["loads"]["gravity"], "rho_inf": solver["rho_inf"]}


def exudyn_model(exu: Any, data: dict[str, float], elements: int) -> tuple[Any, Any, int]:
    """The clamped cable on a fresh system: (system container, mbs, tip sensor)."""
    import warnings

    from exudyn.beams import GenerateBeamElementsAlongLine
    from exudyn.itemInterface import ObjectANCFCable2D, SensorNode

    container = exu.SystemContainer()
    mbs = container.AddSystem()
    template = ObjectANCFCable2D(physicsMassPerLength=data["mass_per_length"],
                                 physicsBendingStiffness=data["bending_stiffness"],
                                 physicsAxialStiffness=data["axial_stiffness"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        items = GenerateBeamElementsAlongLine(
            mbs, positionStart=[0.0, 0.0, 0.0], positionEnd=[data["length"], 0.0, 0.0],
            numberOfElements=elements, beamTemplate=template,
            gravity=[0.0, -data["gravity"], 0.0], groundConstraintsStart=[1, 1, 1, 1])
    sensor = mbs.AddSensor(SensorNode(nodeNumber=items["nodes"][-1], storeInternal=True,
                                      outputVariableType=exu.OutputVariableType.Position))
    mbs.Assemble()
    return container, mbs, sensor


def exudyn_settings(exu: Any, data: dict[str, float], dt: float, t_end: float,
                    absolute_tol: float) -> Any:
    from _peer import quiet_settings

    settings = exu.SimulationSettings()
    integration = settings.timeIntegration
    integration.numberOfSteps = int(round(t_end / dt))
    integration.endTime = t_end
    integration.generalizedAlpha.spectralRadius = data["rho_inf"]
    integration.adaptiveStep = False
    integration.verboseMode = 0
    integration.newton.relativeTolerance = EXUDYN_RELATIVE_TOL
    integration.newton.absoluteTolerance = absolute_tol
    quiet_settings(exu, settings, dt)
    return settings


def run_exudyn(exu: Any, data: dict[str, float], elements: int, dt: float, t_end: float,
               checkpoints: dict[str, float] | None = None,
               tols: tuple[float, ...] = EXUDYN_ABSOLUTE_TOLS) -> dict[str, Any]:
    """One whole call at the first absolute tolerance that works."""
    from _peer import run_quietly

    failures = []
    for tol in tols:
        t0 = time.perf_counter()
        container, mbs, sensor = exudyn_model(exu, data, elements)
        if checkpoints is not None:
            checkpoints["after_build"] = rss_mb()
        settings = exudyn_settings(exu, data, dt, t_end, tol)
        t1 = time.perf_counter()
        try:
            run_quietly(lambda: mbs.SolveDynamic(
                settings, solverType=exu.DynamicSolverType.GeneralizedAlpha))
        except RuntimeError as exc:
            failures.append(f"absolute tol {tol:g}: {exc}")
            continue
        solve = time.perf_counter() - t1
        if checkpoints is not None:
            checkpoints["after_solve"] = rss_mb()
        it = mbs.sys["dynamicSolver"].it
        rows = mbs.GetSensorStoredData(sensor)
        whole = time.perf_counter() - t0
        del container
        return {"solve_s": solve, "whole_s": whole, "steps": int(it.currentStepIndex) - 1,
                "newton_iterations": int(it.newtonStepsCount),
                "factorizations": int(it.newtonJacobiCount), "absolute_tol": tol,
                "failed_attempts": failures, "unknowns": 4 * (elements + 1),
                "t": rows[:, 0].tolist(), "x": rows[:, 1].tolist(), "y": rows[:, 2].tolist()}
    raise RuntimeError("; ".join(failures))


# -- memory: one configuration in a fresh interpreter --------------------------------------------
def worker(spec: dict[str, Any]) -> dict[str, Any]:
    """Run one configuration; ru_maxrss before and after the imports, after the build and
    at the end (MB)."""
    import tempfile

    marks = {"start": rss_mb()}
    if spec["code"] == "exudyn":
        sys.path.insert(0, str(REPO / "benchmarks"))
        from _peer import import_exudyn

        exu, note = import_exudyn()
        if exu is None:
            raise RuntimeError(f"Exudyn unavailable: {note}")
        marks["after_imports"] = rss_mb()
        # the scene's data come with the spec: ancfdrv is never imported here
        run = run_exudyn(exu, spec["physics"], spec["elements"], spec["dt"], spec["t_end"],
                         marks)
    elif spec["code"] == IN_MEMORY:
        import ancfdrv.runner  # noqa: F401
        from ancfdrv.builders import build_model
        from ancfdrv.io.scene import load_scene
        from ancfdrv.results.memory import MemoryOutput
        from ancfdrv.runner import run_in_memory

        marks["after_imports"] = rss_mb()
        # ancfdrv.simulate's run (results in memory) on the model built here
        scene = load_scene(SCENE, ancfdrv_overrides("cable", spec["elements"], spec["dt"],
                                                    spec["t_end"])
                           + ["output.xdmf=false", "output.answers=false"])
        model = build_model(scene)
        marks["after_build"] = rss_mb()
        outcome = run_in_memory(scene, MemoryOutput(), progress=False, model=model)
        marks["after_solve"] = rss_mb()
        assert outcome.dynamic is not None
        run = {"steps": int(outcome.dynamic.steps), "unknowns": int(model.ndof)}
    else:
        import ancfdrv.runner  # noqa: F401

        marks["after_imports"] = rss_mb()
        with tempfile.TemporaryDirectory(prefix="peer_cantilever_") as tmp:
            run = run_ancfdrv(spec["code"].split("/")[1], spec["elements"], spec["dt"],
                              spec["t_end"], Path(tmp) / "run.h5", marks)
    return {"marks_mb": marks, "steps": run["steps"], "unknowns": run["unknowns"]}


def compile_package(package: Path) -> None:
    """Byte-compile ancfdrv's modules (their __pycache__, ignored by git) as ``pip install``
    does: the workers then load them as an installed ancfdrv (and Exudyn) is loaded, not
    compiled at every import (an editable install under PYTHONDONTWRITEBYTECODE)."""
    import compileall

    compileall.compile_dir(str(package), quiet=1)


def measure_memory(spec: dict[str, Any]) -> dict[str, Any]:
    """:func:`worker` in a fresh interpreter; its marks, peak and increment over imports."""
    done = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--worker",
                           json.dumps(spec)], cwd=REPO, capture_output=True, text=True,
                          timeout=1800)
    if done.returncode != 0:
        return {"ok": False, "message": done.stderr.strip()[-500:]}
    result = json.loads(done.stdout.strip().splitlines()[-1])
    marks = result["marks_mb"]
    return {"ok": True, **result, "peak_mb": marks["after_solve"],
            "imports_mb": marks["after_imports"],
            "increment_mb": marks["after_solve"] - marks["after_imports"]}


# -- the comparison ------------------------------------------------------------------------------
def sample(run: dict[str, Any], grid: list[float]) -> tuple[Any, Any]:
    """Tip x and y at the grid times (every step divides the sample interval: picks computed
    values, interpolation only absorbs round-off of the time column)."""
    import numpy as np

    t = np.asarray(run["t"])
    if t[-1] < grid[-1] - 1e-9:
        raise ValueError(f"the history ends at t = {t[-1]:g} s, before {grid[-1]:g} s")
    return np.interp(grid, t, run["x"]), np.interp(grid, t, run["y"])


def difference(a: dict[str, Any], b: dict[str, Any], grid: list[float]) -> dict[str, float]:
    """max |tip difference| (x, y, and y relative to b's range of y)."""
    import numpy as np

    ax, ay = sample(a, grid)
    bx, by = sample(b, grid)
    span = float(np.max(by) - np.min(by))
    dy = float(np.max(np.abs(ay - by)))
    return {"max_abs_dx_m": float(np.max(np.abs(ax - bx))), "max_abs_dy_m": dy,
            "tip_y_range_m": span, "relative_dy": dy / span if span > 0 else float("nan")}


def ratio(num: float | None, den: float | None) -> float | None:
    if num is None or den is None or not den > 0:
        return None
    return num / den


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="8 and 32 elements, 0.1 s, one repeat (a smoke run)")
    parser.add_argument("--elements", type=int, nargs="+", default=None,
                        help="meshes (default 8 32 128 512; --quick 8 32)")
    parser.add_argument("--options", nargs="+", choices=OPTIONS, default=list(OPTIONS),
                        help="ancfdrv's bending options (default cable cubic)")
    parser.add_argument("--dt", type=float, default=1e-3, help="time step, s (1e-3)")
    parser.add_argument("--t-end", type=float, default=None,
                        help="end time, s (default 1; --quick 0.1)")
    parser.add_argument("--sample-dt", type=float, default=None,
                        help="interval of the compared tip samples (default 10 dt)")
    parser.add_argument("--repeats", type=int, default=None,
                        help="interleaved rounds, the best is kept (default 3; --quick 1)")
    parser.add_argument("--no-memory", dest="memory", action="store_false",
                        help="skip the fresh-interpreter memory runs")
    parser.add_argument("--no-exudyn", action="store_true", help="ancfdrv only")
    parser.add_argument("--output", type=Path, default=None,
                        help="JSON file (default benchmarks/results/peer_cantilever.json; "
                             "peer_cantilever_quick.json with --quick); the Markdown goes "
                             "next to it (not with --quick)")
    parser.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.elements is None:
        args.elements = [8, 32] if args.quick else [8, 32, 128, 512]
    if args.t_end is None:
        args.t_end = 0.1 if args.quick else 1.0
    if args.sample_dt is None:
        args.sample_dt = 10 * args.dt
    if args.repeats is None:
        args.repeats = 1 if args.quick else 3
    if args.output is None:
        args.output = RESULTS / ("peer_cantilever_quick.json" if args.quick
                                 else "peer_cantilever.json")
    if args.repeats < 1 or min(args.elements) < 1:
        parser.error("--repeats and --elements must be at least 1")
    return args


def _f(value: Any, fmt: str = ".3f") -> str:
    return "-" if value is None else format(value, fmt)


def markdown(report: dict[str, Any]) -> str:
    s = report["settings"]
    m = report["machine"]
    lines = [
        "# Nonlinear cantilever: ancfdrv's planar cable against Exudyn's ANCFCable2D",
        "",
        f"Created {report['created']} by `benchmarks/peer_cantilever.py`; "
        f"{report['wall_time_s']:.0f} s. Machine: {m['platform']}, {m['cpus_usable']} usable "
        f"CPUs, Python {m['python']}; load average {m['load_average_at_start']} at the start, "
        f"{m.get('load_average_at_end')} at the end (a shared machine: other processes "
        f"distort the times; the ratios come from interleaved runs). Exudyn "
        f"{report['exudyn']['version']}, 1 thread; ancfdrv 1 OpenMP thread "
        f"({report.get('ancfdrv', {}).get('package', '?')}).",
        "",
        f"Problem: `{s['scene']}` (1 m steel strip, 1 mm x 1 mm, clamped, released under "
        f"gravity; q L^3/EI = 4.4), 0 ... {s['t_end']:g} s, dt = {s['dt']:g} s, "
        f"generalized-alpha rho_inf = {report['physics']['rho_inf']:g} in both codes. "
        f"Best of {s['repeats']} interleaved rounds. per step: the dynamic solve / steps "
        f"(ancfdrv: incl. its HDF5 output per chunk; stepping: without it). Ratio: Exudyn's "
        f"time / ancfdrv's (> 1: ancfdrv faster; target at 128 and 512 elements: >= 1).",
        "",
        "| elements | code | unknowns | per step ms | stepping ms | whole s | Newton/step "
        "| factorizations | Exudyn / ours (per step) |",
        "|---:|---|---:|---:|---:|---:|---:|---:|---:|"]
    for row in report["rows"]:
        for code, run in row["runs"].items():
            if not run.get("ok"):
                lines.append(f"| {row['elements']} | {code} | - | FAILED | | | | | |")
                continue
            lines.append(
                f"| {row['elements']} | {code} | {run['unknowns']} | "
                f"{_f(run['per_step_ms'])} | {_f(run.get('stepping_per_step_ms'))} | "
                f"{_f(run['whole_s'])} | {run['newton_iterations'] / run['steps']:.2f} | "
                f"{run['factorizations']} | "
                f"{_f(row['ratios'].get(code), '.2f') if code != 'exudyn' else ''} |")
    lines += ["", "Peak memory (fresh interpreter per run; VmHWM, the peak resident set that "
              "ru_maxrss reports, without the parent's peak Linux carries over an exec; MB): "
              "after the imports, after the build, at the end (peak); increment = peak - "
              "after imports. Ratio: ours / Exudyn's (target <= 1.2, issue 38). ancfdrv/cable and "
              "/cubic: as shipped (the HDF5 file, its XDMF frames and answers); "
              f"{IN_MEMORY}: like for like with Exudyn's run (results in memory, no file, "
              "no XDMF frames, no answers; h5py imported). ancfdrv's modules byte-compiled "
              "first, as an installed package's.", "",
              "| elements | code | after imports | after build | peak | increment | "
              "peak / Exudyn's | increment / Exudyn's |", "|---:|---|---:|---:|---:|---:|---:|---:|"]
    for row in report["rows"]:
        peer = row["memory"].get("exudyn", {})
        for code, mem in row["memory"].items():
            if not mem.get("ok"):
                lines.append(f"| {row['elements']} | {code} | FAILED | | | | | |")
                continue
            lines.append(
                f"| {row['elements']} | {code} | {mem['imports_mb']:.1f} | "
                f"{mem['marks_mb']['after_build']:.1f} | {mem['peak_mb']:.1f} | "
                f"{mem['increment_mb']:.1f} | "
                f"{_f(ratio(mem['peak_mb'], peer.get('peak_mb')), '.2f')} | "
                f"{_f(ratio(mem['increment_mb'], peer.get('increment_mb')), '.2f')} |")
    lines += ["", "Same physics: tip (x, y) of ancfdrv's cable against Exudyn at the same mesh, "
              f"sampled every {s['sample_dt']:g} s (max |difference|, m; relative: to the range "
              "of the tip's y); convergence: each code against its own finest mesh.", "",
              "| elements | cable vs Exudyn dx | dy | dy / range | cable vs finest cable dy "
              "| Exudyn vs finest Exudyn dy | cubic vs cable dy |", "|---:|---:|---:|---:|---:|---:|---:|"]
    for row in report["rows"]:
        c = row["comparison"]
        lines.append(
            f"| {row['elements']} | {_f(c.get('cable_vs_exudyn', {}).get('max_abs_dx_m'), '.2e')} | "
            f"{_f(c.get('cable_vs_exudyn', {}).get('max_abs_dy_m'), '.2e')} | "
            f"{_f(c.get('cable_vs_exudyn', {}).get('relative_dy'), '.2e')} | "
            f"{_f(c.get('cable_vs_finest_cable', {}).get('max_abs_dy_m'), '.2e')} | "
            f"{_f(c.get('exudyn_vs_finest_exudyn', {}).get('max_abs_dy_m'), '.2e')} | "
            f"{_f(c.get('cubic_vs_cable', {}).get('max_abs_dy_m'), '.2e')} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if args.worker is not None:
        print(json.dumps(worker(json.loads(args.worker))))
        return 0
    start = time.perf_counter()
    import datetime as _dt
    import tempfile

    import numpy as np

    sys.path.insert(0, str(REPO / "benchmarks"))
    import ancfdrv
    import ancfdrv.runner  # import time stays out of the first measurement
    from _common import load_average, machine_info, write_report
    from _peer import exudyn_version, import_exudyn

    exu, note = (None, "--no-exudyn") if args.no_exudyn else import_exudyn()
    machine = machine_info()
    data = scene_data()
    codes = [f"ancfdrv/{o}" for o in args.options] + (["exudyn"] if exu is not None else [])
    best: dict[tuple[int, str], dict[str, Any]] = {}
    samples: dict[tuple[int, str], list[float]] = {}
    failures: dict[tuple[int, str], str] = {}
    with tempfile.TemporaryDirectory(prefix="peer_cantilever_") as tmp:
        for round_ in range(args.repeats):
            for n in args.elements:
                for code in codes:
                    key = (n, code)
                    if key in failures:
                        continue
                    try:
                        if code == "exudyn":
                            tols = (best[key]["absolute_tol"],) if key in best \
                                else EXUDYN_ABSOLUTE_TOLS
                            run = run_exudyn(exu, data, n, args.dt, args.t_end, tols=tols)
                        else:
                            run = run_ancfdrv(code.split("/")[1], n, args.dt, args.t_end,
                                              Path(tmp) / "run.h5")
                    except Exception as exc:  # recorded: one failed configuration
                        failures[key] = f"{type(exc).__name__}: {exc}"[:500]
                        continue
                    samples.setdefault(key, []).append(run["solve_s"])
                    if key not in best or run["solve_s"] < best[key]["solve_s"]:
                        best[key] = run
                    print(f"  round {round_ + 1} {code:>15} {n:>4} elements: solve "
                          f"{run['solve_s']:.3f} s", file=sys.stderr, flush=True)
        memory: dict[tuple[int, str], dict[str, Any]] = {}
        if args.memory:
            compile_package(Path(ancfdrv.__file__).parent)
            for n in args.elements:
                for code in codes + ([IN_MEMORY] if "cable" in args.options else []):
                    memory[(n, code)] = measure_memory(
                        {"code": code, "elements": n, "dt": args.dt, "t_end": args.t_end,
                         "physics": data})
    grid = list(np.round(np.arange(0.0, args.t_end + 0.5 * args.sample_dt, args.sample_dt), 12))
    finest = max(args.elements)
    rows = []
    for n in args.elements:
        runs: dict[str, Any] = {}
        for code in codes:
            key = (n, code)
            if key in failures or key not in best:
                runs[code] = {"ok": False, "message": failures.get(key, "not run")}
                continue
            r = best[key]
            runs[code] = {"ok": True, **{k: v for k, v in r.items() if k not in ("t", "x", "y")},
                          "solve_samples_s": samples[key],
                          "per_step_ms": 1e3 * r["solve_s"] / max(r["steps"], 1)}
            if "stepping_s" in r:
                runs[code]["stepping_per_step_ms"] = 1e3 * r["stepping_s"] / max(r["steps"], 1)
        peer = runs.get("exudyn", {})
        ratios = {code: ratio(peer.get("per_step_ms"), run.get("per_step_ms"))
                  for code, run in runs.items() if code != "exudyn"}
        stepping_ratios = {code: ratio(peer.get("per_step_ms"), run.get("stepping_per_step_ms"))
                           for code, run in runs.items() if code != "exudyn"}
        comparison: dict[str, Any] = {}
        pairs = {"cable_vs_exudyn": ((n, "ancfdrv/cable"), (n, "exudyn")),
                 "cable_vs_finest_cable": ((n, "ancfdrv/cable"), (finest, "ancfdrv/cable")),
                 "exudyn_vs_finest_exudyn": ((n, "exudyn"), (finest, "exudyn")),
                 "cubic_vs_cable": ((n, "ancfdrv/cubic"), (n, "ancfdrv/cable"))}
        for name, (a, b) in pairs.items():
            if a in best and b in best:
                comparison[name] = difference(best[a], best[b], grid)
        mem = {code: memory[(n, code)] for code in codes + [IN_MEMORY] if (n, code) in memory}
        mem_peer = mem.get("exudyn", {})
        memory_ratios = {code: {"peak": ratio(m.get("peak_mb"), mem_peer.get("peak_mb")),
                                "increment": ratio(m.get("increment_mb"),
                                                   mem_peer.get("increment_mb"))}
                         for code, m in mem.items() if code != "exudyn"}
        rows.append({"elements": n, "runs": runs, "ratios": ratios,
                     "stepping_ratios": stepping_ratios, "memory": mem,
                     "memory_ratios": memory_ratios, "comparison": comparison})
    machine["load_average_at_end"] = load_average()
    report: dict[str, Any] = {
        "benchmark": "peer_cantilever",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "settings": {"quick": args.quick, "elements": args.elements, "options": args.options,
                     "dt": args.dt, "t_end": args.t_end, "sample_dt": args.sample_dt,
                     "repeats": args.repeats, "memory": args.memory,
                     "scene": str(SCENE.relative_to(REPO)),
                     "exudyn_relative_tol": EXUDYN_RELATIVE_TOL,
                     "omp_num_threads": os.environ.get("OMP_NUM_THREADS")},
        "units": "seconds, milliseconds per step, MB (ru_maxrss / 1024), metres; ratios: "
                 "Exudyn time / ancfdrv time, ancfdrv memory / Exudyn memory",
        "machine": machine,
        "physics": data,
        "ancfdrv": {"package": str(Path(ancfdrv.runner.__file__).parent),
                    "version": getattr(ancfdrv, "__version__", None)},
        "exudyn": {"available": exu is not None, "skipped_because": note,
                   "version": exudyn_version(exu) if exu is not None else None},
        "rows": rows,
    }
    report["wall_time_s"] = time.perf_counter() - start
    text = markdown(report)
    print(text)
    if args.quick:
        report["markdown"] = text
    else:
        args.output.parent.mkdir(parents=True, exist_ok=True)
        args.output.with_suffix(".md").write_text(text)
    write_report(args.output, report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
