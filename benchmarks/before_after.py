#!/usr/bin/env python
"""Two ancfdrv versions on the same scenes: solver time, step statistics and histories,
before against after (e.g. the BeamModel layer against the general-system rewrite).

Each version is a Python interpreter whose environment holds that version's ancfdrv
(``--before``, ``--after``) and its checkout directory (``--before-dir``, ``--after-dir``):
every case runs in a fresh subprocess of that interpreter, started in that directory, on
that checkout's own scene file, through ``ancfdrv.runner.run_scene`` (which both versions
have), with the HDF5 result written to a temporary directory (never into a checkout;
``PYTHONDONTWRITEBYTECODE`` keeps the checkouts free of byte code, and both sides get
``OMP_NUM_THREADS=1`` and ``OPENBLAS_NUM_THREADS=1``). Cases (``--cases``; the template
scenes shipped in ``inputs/``):

* ``boom_static``: ``inputs/boom_static.nml`` (FFR, 28 nodes, split iteration at 0 deg);
* ``boom_luffing``: ``inputs/boom_luffing.nml`` (FFR, 28 nodes, static start, Newmark,
  10 s);
* ``boom_cubic``: the same with ``scene.formulation=nonlinear``, ``beam.bending=cubic``,
  ``beam.nodes=4`` (and ``solver.static_method=newton``, which the large-deformation
  formulation needs for its static start);
* ``spinup``, ``pendulum``: ``inputs/hard/spinup.nml`` (W = 6 rad/s, 20 s) and
  ``inputs/hard/pendulum.nml`` (1 s);
* ``plate_pendulum``: ``inputs/plate_pendulum.nml`` (4 x 4, 0.3 s);
* ``curved_leaf``: ``inputs/curved_leaf.nml`` (completed element: it must not move, so its
  history difference is a difference of round-off; ``curved_leaf_plain`` with
  ``leaf.variant=plain``, which springs back, is available as an extra case);
* ``leaf_spring``: ``inputs/leaf_spring.nml`` (5 s).

``--quick`` shortens every dynamic case (``solver.t_end``, see ``CASES``) and repeats once;
``--t-scale`` scales the shipped end times instead. Timing: the runs are interleaved
(for each repeat, every case runs before and after back to back, the order alternating) so
that the load of this shared machine hits both versions alike, and each case's time is the
minimum over ``--repeats`` (3). Read from each result file (SPEC section 4):

* ``solve s``: ``/static`` ``wall_time_s`` + ``/dynamic`` ``wall_time_s`` (the solvers,
  including the dynamic output sink; the model build and file creation apart), and the
  whole ``run_scene`` call as measured in the subprocess (imports apart);
* steps, Newton corrections and factorizations (``/dynamic`` attributes; the static
  iterations for a static case) and the ``/counters``;
* the history difference: the scene's response probe and component (root attributes
  ``response_probe``, ``response_component``; ``/dynamic/deflection/<probe>``, or
  ``/static/deflection/<probe>`` for a static case), max |after - before| over the common
  times (after is interpolated on before's times when they differ), absolute and relative
  to before's range over the run (to |before| for a static case).

Dispatch overhead (``--dispatch-steps``, 2000; 0 skips it): in each environment, the FFR
boom (``boom_luffing`` as shipped) from t = 1 s, the same steps advanced by one
``TimeIntegrator.advance`` call, by calls of 10 steps and by calls of 1 step (after: also
the raw ``KernelSystem.advance`` of the handle API without the Python Chunk); every sample
from a freshly built model, best of ``--dispatch-repeats`` (3) interleaved samples. The
overhead per kernel call is (time of the 1-step calls - time of the one call) / calls,
in microseconds; the final states of the ways are compared (splitting must not change a
run).

Results: a table on stdout, JSON in ``benchmarks/results/before_after.json`` and the same
table as Markdown next to it (``before_after_quick.*`` with ``--quick``)::

    python benchmarks/before_after.py --before /work/baseline/.venv/bin/python \\
        --before-dir /work/baseline --after .venv/bin/python --after-dir .
    python benchmarks/before_after.py ... --quick          # short runs, once: ~30 s
    python benchmarks/before_after.py ... --cases boom_luffing spinup --repeats 5
"""
from __future__ import annotations

import argparse
import datetime as _dt
import hashlib
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from _common import load_average, machine_info, print_table, write_report

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
WORKER = Path(__file__).resolve().parent / "_before_after_worker.py"


@dataclass(frozen=True)
class Case:
    """A scene of both checkouts (path relative to the checkout), its overrides, its
    shipped end time (None: static) and the end time of ``--quick``."""

    name: str
    scene: str
    overrides: tuple[str, ...] = ()
    t_end: float | None = None
    quick_t_end: float | None = None


CASES: dict[str, Case] = {c.name: c for c in (
    Case("boom_static", "inputs/boom_static.nml"),
    Case("boom_luffing", "inputs/boom_luffing.nml", (), 10.0, 2.0),
    Case("boom_cubic", "inputs/boom_luffing.nml",
         ("scene.formulation=nonlinear", "beam.bending=cubic", "beam.nodes=4",
          "solver.static_method=newton"), 10.0, 2.0),
    Case("spinup", "inputs/hard/spinup.nml", (), 20.0, 2.0),
    Case("pendulum", "inputs/hard/pendulum.nml", (), 1.0, 0.2),
    Case("plate_pendulum", "inputs/plate_pendulum.nml", (), 0.3, 0.05),
    Case("curved_leaf", "inputs/curved_leaf.nml", (), 0.05, 0.01),
    Case("leaf_spring", "inputs/leaf_spring.nml", ("solver.t_end=5.0",), 5.0, 0.2),
    Case("curved_leaf_plain", "inputs/curved_leaf.nml", ("leaf.variant=plain",), 0.05, 0.01),
)}
#: a response range below this (m) is round-off: no relative history difference
MOTION_FLOOR = 1e-12
DEFAULT_CASES = ("boom_static", "boom_luffing", "boom_cubic", "spinup", "pendulum",
                 "plate_pendulum", "curved_leaf", "leaf_spring")
DISPATCH_SCENE = "inputs/boom_luffing.nml"
SIDES = ("before", "after")


@dataclass
class Side:
    """One version: interpreter and checkout."""

    name: str
    python: Path
    directory: Path
    info: dict[str, Any] = field(default_factory=dict)


# -- subprocesses ------------------------------------------------------------------------------
def worker_env() -> dict[str, str]:
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", "OMP_NUM_THREADS": "1",
           "OPENBLAS_NUM_THREADS": "1"}
    env.pop("PYTHONPATH", None)  # each interpreter imports its own ancfdrv
    return env


def call_worker(side: Side, args: list[str], timeout: float) -> dict[str, Any]:
    """Run the worker in the side's interpreter and directory; its JSON (with 'error' on
    failure) and the subprocess's wall time."""
    t0 = time.perf_counter()
    try:
        done = subprocess.run([str(side.python), str(WORKER), *args], cwd=side.directory,
                              env=worker_env(), capture_output=True, text=True,
                              timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"error": f"timed out after {timeout:g} s", "process_s": timeout}
    elapsed = time.perf_counter() - t0
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if not lines:
        return {"error": f"exit {done.returncode}, no result: {done.stderr[-2000:]}",
                "process_s": elapsed}
    out = json.loads(lines[-1])
    out["process_s"] = elapsed
    return out


def git_state(directory: Path) -> dict[str, Any]:
    """Commit and whether the checkout has local changes (tracked files)."""
    def git(*a: str) -> str:
        done = subprocess.run(["git", "-C", str(directory), *a], capture_output=True,
                              text=True)
        return done.stdout.strip() if done.returncode == 0 else ""
    return {"commit": git("rev-parse", "HEAD") or None,
            "dirty": bool(git("status", "--porcelain", "--untracked-files=no"))}


def case_overrides(case: Case, args: argparse.Namespace) -> list[str]:
    overrides = list(case.overrides)
    if case.t_end is not None:
        t_end = case.quick_t_end if args.quick else case.t_end * args.t_scale
        if args.quick or args.t_scale != 1.0:
            overrides = [o for o in overrides if not o.startswith("solver.t_end=")]
            overrides.append(f"solver.t_end={t_end!r}")
    return overrides


# -- result files ------------------------------------------------------------------------------
def _attrs(group: Any) -> dict[str, Any]:
    out = {}
    for key, value in group.attrs.items():
        if isinstance(value, bytes):
            value = value.decode()
        if isinstance(value, np.generic):
            value = value.item()
        if isinstance(value, (int, float, str, bool)):
            out[key] = value
    return out


def read_result(path: Path) -> dict[str, Any]:
    """Times, counts and the response history of one result file."""
    with h5py.File(path, "r") as h5:
        root = _attrs(h5)
        probe, component = root.get("response_probe"), int(root.get("response_component", 1))
        out: dict[str, Any] = {"status": root.get("status"), "probe": probe,
                               "component": component,
                               "timing": _attrs(h5["timing"]) if "timing" in h5 else {},
                               "counters": _attrs(h5["counters"]) if "counters" in h5 else {}}
        solve = 0.0
        if "static" in h5:
            st = _attrs(h5["static"])
            out["static"] = {k: st.get(k) for k in ("method", "iterations", "residual_norm",
                                                     "wall_time_s")}
            solve += float(st.get("wall_time_s", 0.0))
            if probe is not None and f"static/deflection/{probe}" in h5:
                out["static_deflection"] = h5[f"static/deflection/{probe}"][()]
        if "dynamic" in h5 and "time" in h5["dynamic"]:
            dyn = _attrs(h5["dynamic"])
            out["dynamic"] = {k: dyn.get(k) for k in (
                "integrator", "dt", "steps", "newton_iterations", "factorizations",
                "jacobian_evaluations", "jacobian_policy", "setup_solves", "wall_time_s",
                "status")}
            solve += float(dyn.get("wall_time_s", 0.0))
            out["time"] = h5["dynamic/time"][()]
            if probe is not None and f"dynamic/deflection/{probe}" in h5:
                out["history"] = h5[f"dynamic/deflection/{probe}"][:, component]
        out["solve_s"] = solve
    return out


def compare(before: dict[str, Any], after: dict[str, Any]) -> dict[str, Any]:
    """History difference of the response: max |after - before| and relative to before's
    range (dynamic) or |before| (static)."""
    out: dict[str, Any] = {"response": [before["probe"], before["component"]]}
    if (after["probe"], after["component"]) != (before["probe"], before["component"]):
        out["response_after"] = [after["probe"], after["component"]]
        out["warning"] = "the versions name different responses; after's is read at before's"
        if f"{before['probe']}" != f"{after['probe']}":
            return out
    if "history" in before and "history" in after:
        tb, ta = before["time"], after["time"]
        yb, ya = before["history"], after["history"]
        same_times = len(tb) == len(ta) and np.allclose(tb, ta, rtol=0.0, atol=1e-9)
        if not same_times:
            keep = (tb >= ta[0]) & (tb <= ta[-1])
            tb, yb = tb[keep], yb[keep]
            ya = np.interp(tb, ta, ya)
        difference = float(np.abs(ya - yb).max()) if len(yb) else math.nan
        scale = float(np.ptp(yb)) if len(yb) else math.nan
        # a response that does not move (range at round-off) has no relative difference
        moving = scale > MOTION_FLOOR
        out.update(kind="dynamic", same_times=bool(same_times), samples=int(len(yb)),
                   max_abs_difference=difference, range=scale, moving=bool(moving),
                   relative_to_range=difference / scale if moving else math.nan,
                   t_end=[float(before["time"][-1]), float(after["time"][-1])])
    elif "static_deflection" in before and "static_deflection" in after:
        c = before["component"]
        b, a = before["static_deflection"], after["static_deflection"]
        difference = float(abs(a[c] - b[c]))
        out.update(kind="static", before=float(b[c]), after=float(a[c]),
                   max_abs_difference=difference,
                   vector_difference=float(np.abs(a - b).max()),
                   relative_to_range=difference / abs(b[c]) if b[c] else math.nan)
    return out


# -- the runs ----------------------------------------------------------------------------------
def run_once(side: Side, case: Case, overrides: list[str], out: Path,
             args: argparse.Namespace) -> dict[str, Any]:
    scene = str(side.directory / case.scene)
    load = load_average()
    record = call_worker(side, ["run", scene, str(out), *overrides], args.timeout)
    record["load_before_run"] = load
    if "error" in record:
        return record
    record.update(read_result(out))
    return record


def summarize_side(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Best (minimum) solve time over the repeats, with the counts of that run and
    whether the counts were the same in every repeat."""
    ok = [r for r in runs if "error" not in r]
    if not ok:
        return {"error": runs[0]["error"] if runs else "not run", "runs": len(runs)}
    best = min(ok, key=lambda r: r["solve_s"])
    dyn = best.get("dynamic") or {}
    counts = [(r.get("dynamic") or {}).get("newton_iterations") for r in ok]
    return {"solve_s": best["solve_s"], "solve_s_all": [r["solve_s"] for r in ok],
            "run_scene_s": min(r["run_scene_s"] for r in ok),
            "run_scene_s_all": [r["run_scene_s"] for r in ok],
            "import_s": min(r["import_s"] for r in ok),
            "static": best.get("static"), "dynamic": best.get("dynamic"),
            "steps": dyn.get("steps"), "newton_iterations": dyn.get("newton_iterations"),
            "factorizations": dyn.get("factorizations"),
            "static_iterations": (best.get("static") or {}).get("iterations"),
            "counts_repeatable": len(set(counts)) <= 1, "counters": best.get("counters"),
            "timing": best.get("timing"), "status": best.get("status"),
            "warnings": best.get("warnings"), "runs": len(runs), "failed_runs":
            [r["error"] for r in runs if "error" in r]}


def scene_digest(side: Side, case: Case) -> str | None:
    path = side.directory / case.scene
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16] if path.is_file() else None


def measure_cases(sides: dict[str, Side], args: argparse.Namespace,
                  workdir: Path) -> dict[str, Any]:
    runs: dict[str, dict[str, list[dict[str, Any]]]] = {
        name: {s: [] for s in SIDES} for name in args.cases}
    kept: dict[str, dict[str, dict[str, Any]]] = {name: {} for name in args.cases}
    for repeat in range(args.repeats):
        for index, name in enumerate(args.cases):
            case = CASES[name]
            overrides = case_overrides(case, args)
            order = SIDES if (repeat + index) % 2 == 0 else SIDES[::-1]
            for s in order:
                out = workdir / f"{name}_{s}_{repeat}.h5"
                record = run_once(sides[s], case, overrides, out, args)
                history = {k: record.pop(k) for k in ("time", "history", "static_deflection")
                           if k in record}
                if "error" not in record and s not in kept[name]:
                    kept[name][s] = {**record, **history}
                runs[name][s].append(record)
                for path in (out, out.with_suffix(".xdmf")):
                    path.unlink(missing_ok=True)
                status = record.get("error") or (f"solve {record['solve_s']:.3f} s, "
                                                 f"run_scene {record['run_scene_s']:.3f} s")
                print(f"  [{repeat + 1}/{args.repeats}] {name:16s} {s:6s} {status}",
                      file=sys.stderr, flush=True)
    out: dict[str, Any] = {}
    for name in args.cases:
        case = CASES[name]
        sides_summary = {s: summarize_side(runs[name][s]) for s in SIDES}
        record: dict[str, Any] = {"scene": case.scene, "overrides": case_overrides(case, args),
                                  "scene_sha256": {s: scene_digest(sides[s], case)
                                                   for s in SIDES},
                                  **sides_summary}
        if all(s in kept[name] for s in SIDES):
            record["history"] = compare(kept[name]["before"], kept[name]["after"])
        b, a = sides_summary["before"], sides_summary["after"]
        if "error" not in b and "error" not in a:
            record["speedup"] = b["solve_s"] / a["solve_s"] if a["solve_s"] > 0 else math.nan
            record["speedup_run_scene"] = b["run_scene_s"] / a["run_scene_s"]
        record["runs"] = {s: [{k: v for k, v in r.items() if k not in ("counters", "timing")}
                              for r in runs[name][s]] for s in SIDES}
        out[name] = record
    return out


def measure_dispatch(sides: dict[str, Side], args: argparse.Namespace) -> dict[str, Any]:
    """The dispatch probe in both environments, each ``--dispatch-repeats`` times in
    alternating order; the best per way over the calls."""
    results: dict[str, list[dict[str, Any]]] = {s: [] for s in SIDES}
    for repeat in range(args.dispatch_rounds):
        for s in (SIDES if repeat % 2 == 0 else SIDES[::-1]):
            r = call_worker(sides[s], ["dispatch", str(sides[s].directory / DISPATCH_SCENE),
                                       str(args.dispatch_steps), str(args.dispatch_repeats)],
                            args.timeout)
            results[s].append(r)
            print(f"  dispatch {s:6s} " + (r.get("error") or
                                           f"overhead per 1-step call "
                                           f"{r['overhead_per_call_us']['calls_of_1']:.1f} us, "
                                           f"step {r['per_step_us']:.1f} us"),
                  file=sys.stderr, flush=True)
    out: dict[str, Any] = {"scene": DISPATCH_SCENE, "steps": args.dispatch_steps}
    for s in SIDES:
        ok = [r for r in results[s] if "error" not in r]
        if not ok:
            out[s] = {"error": results[s][0].get("error") if results[s] else "not run"}
            continue
        best = {way: min(r["best_s"][way] for r in ok) for way in ok[0]["best_s"]}
        steps = ok[0]["steps"]
        per_step = best["one_call"] / steps
        calls = {"one_call": 1, "calls_of_10": max(steps // 10, 1), "calls_of_1": steps,
                 "raw_calls_of_1": steps}
        per = {"one_call": steps, "calls_of_10": 10, "calls_of_1": 1, "raw_calls_of_1": 1}
        out[s] = {"new_api": ok[0]["new_api"], "ndof": ok[0]["ndof"], "best_s": best,
                  "per_step_us": 1e6 * per_step,
                  "overhead_per_call_us": {
                      way: 1e6 * (best[way] - per_step * calls[way] * per[way]) / calls[way]
                      for way in best if way != "one_call"},
                  "final_state_max_difference": {
                      way: max(r["final_state_max_difference"].get(way, 0.0) for r in ok)
                      for way in ok[0]["final_state_max_difference"]},
                  "samples": results[s]}
    return out


# -- report --------------------------------------------------------------------------------------
def _f(x: Any, spec: str) -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, spec)


def _pair(b: Any, a: Any) -> str:
    if b is None and a is None:
        return "-"
    return str(b) if b == a else f"{_f(b, '')} / {_f(a, '')}"


def table_rows(cases: dict[str, Any]) -> list[list[str]]:
    rows = []
    for name, r in cases.items():
        b, a = r["before"], r["after"]
        if "error" in b or "error" in a:
            rows.append([name, _f(b.get("solve_s"), ".3f"), _f(a.get("solve_s"), ".3f"), "-",
                         "-", "-", "-", "failed: " + (b.get("error") or a.get("error"))[:60]])
            continue
        static = b.get("steps") is None
        steps = f"static: {_pair(b['static_iterations'], a['static_iterations'])} it" \
            if static else _pair(b["steps"], a["steps"])
        h = r.get("history", {})
        if h.get("kind") == "dynamic" and not h["moving"]:
            diff = f"{h['max_abs_difference']:.2e} (no motion: range {h['range']:.1e})"
        elif h.get("kind") == "dynamic":
            diff = (f"{h['max_abs_difference']:.2e} ({_f(h['relative_to_range'], '.1e')} of "
                    f"range {h['range']:.3g})")
        elif h.get("kind") == "static":
            diff = f"{h['max_abs_difference']:.2e} ({_f(h['relative_to_range'], '.1e')})"
        else:
            diff = "-"
        rows.append([name, f"{b['solve_s']:.3f}", f"{a['solve_s']:.3f}",
                     _f(r.get("speedup"), ".2f"), steps,
                     "-" if static else _pair(b["newton_iterations"], a["newton_iterations"]),
                     "-" if static else _pair(b["factorizations"], a["factorizations"]), diff])
    return rows


PHASE_HEAD = ["case", "stepping before", "stepping after", "before/after", "output before",
              "output after", "rest before", "rest after", "run_scene before",
              "run_scene after"]


def phase_rows(cases: dict[str, Any]) -> list[list[str]]:
    """Stepping, dynamic output and the rest of the whole call, per case and version."""
    rows = []
    for name, r in cases.items():
        b, a = r["before"], r["after"]
        if "error" in b or "error" in a:
            continue
        tb, ta = b.get("timing") or {}, a.get("timing") or {}
        sb, sa = tb.get("dynamic_stepping"), ta.get("dynamic_stepping")
        rows.append([name, _f(sb, ".3f"), _f(sa, ".3f"),
                     _f(sb / sa if sb and sa else None, ".2f"),
                     _f(tb.get("dynamic_output"), ".3f"), _f(ta.get("dynamic_output"), ".3f"),
                     _f(tb.get("total", math.nan) - b["solve_s"], ".3f"),
                     _f(ta.get("total", math.nan) - a["solve_s"], ".3f"),
                     f"{b['run_scene_s']:.3f}", f"{a['run_scene_s']:.3f}"])
    return rows


HEAD = ["case", "before s", "after s", "before/after", "steps", "Newton corrections",
        "factorizations", "history difference (relative)"]


def markdown(report: dict[str, Any]) -> str:
    s = report["settings"]
    ends = "quick end times" if s["quick"] else f"t_end x {s['t_scale']:g}"
    lines = [f"# before_after ({report['created']})", "",
             f"before: `{s['before']['python']}` in `{s['before']['directory']}` (commit "
             f"{(s['before']['git'].get('commit') or '?')[:9]}); after: "
             f"`{s['after']['python']}` in `{s['after']['directory']}` (commit "
             f"{(s['after']['git'].get('commit') or '?')[:9]}"
             + (", local changes" if s['after']['git'].get('dirty') else "") + ")", "",
             f"Best of {s['repeats']} interleaved runs per case and version, "
             f"{ends}; load "
             f"average {report['machine']['load_average_at_start']} at start, "
             f"{report['machine']['load_average_at_end']} at end. Times: /static + /dynamic "
             "wall_time_s of the result file (solvers; model build and file creation apart); "
             "before/after > 1: after is faster. Steps, corrections, factorizations: "
             "before / after where they differ. History difference: max |after - before| of "
             "the response probe's deflection component, relative to before's range "
             "(static: to |before|).", "",
             "| " + " | ".join(HEAD) + " |", "|---|---:|---:|---:|---:|---:|---:|---|"]
    lines += ["| " + " | ".join(row) + " |" for row in table_rows(report["cases"])]
    phases = phase_rows(report["cases"])
    if phases:
        lines += ["", "Where the time goes (seconds, from `/timing` of the run whose solve time "
                  "is given above; the whole `run_scene` call is the best of the repeats): "
                  "stepping = the kernel's steps (`dynamic_stepping`), output = the HDF5 sink "
                  "during the dynamics (`dynamic_output`), rest = the whole call minus the "
                  "static and dynamic solves (model build, file creation, final flush, XDMF, "
                  "provenance).", "", "| " + " | ".join(PHASE_HEAD) + " |",
                  "|---|" + "---:|" * (len(PHASE_HEAD) - 1)]
        lines += ["| " + " | ".join(row) + " |" for row in phases]
    d = report.get("dispatch")
    if d:
        lines += ["", f"## Dispatch overhead per kernel call ({d['scene']}, FFR 28 nodes, "
                  f"{d['steps']} steps from t = 1 s)", "",
                  "| version | per step (us) | overhead per 1-step call (us) | per call of 10 "
                  "(us) | raw KernelSystem.advance per call (us) | split changes the result |",
                  "|---|---:|---:|---:|---:|---|"]
        for s in SIDES:
            r = d.get(s, {})
            if "error" in r:
                lines.append(f"| {s} | failed: {r['error'][:80]} | | | | |")
                continue
            o = r["overhead_per_call_us"]
            diff = max(r["final_state_max_difference"].values(), default=0.0)
            lines.append(f"| {s} | {r['per_step_us']:.1f} | {o['calls_of_1']:.1f} | "
                         f"{o['calls_of_10']:.1f} | {_f(o.get('raw_calls_of_1'), '.1f')} | "
                         f"{'no' if diff == 0 else f'max {diff:.1e}'} |")
    return "\n".join(lines) + "\n"


def print_report(report: dict[str, Any]) -> None:
    print()
    widths = [16, 9, 9, 12, 22, 22, 16, 34]
    print_table(list(zip(HEAD, widths)), table_rows(report["cases"]))
    print("\nwhere the time goes (s): stepping, dynamic output, rest of run_scene; whole call")
    print_table(list(zip(PHASE_HEAD, [16] + [max(9, len(h)) for h in PHASE_HEAD[1:]])),
                phase_rows(report["cases"]))
    d = report.get("dispatch")
    if d:
        print(f"\ndispatch overhead, {d['scene']}, {d['steps']} steps from t = 1 s:")
        for s in SIDES:
            r = d.get(s, {})
            if "error" in r:
                print(f"  {s}: failed: {r['error']}")
                continue
            o = r["overhead_per_call_us"]
            print(f"  {s:6s}: {r['per_step_us']:.1f} us per step; overhead per 1-step call "
                  f"{o['calls_of_1']:.1f} us, per call of 10 {o['calls_of_10']:.1f} us"
                  + (f", raw KernelSystem.advance {o['raw_calls_of_1']:.1f} us"
                     if "raw_calls_of_1" in o else "")
                  + f"; final states of the splits differ by at most "
                  f"{max(r['final_state_max_difference'].values(), default=0.0):.1e}")


# -- command line --------------------------------------------------------------------------------
def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--render", type=Path, default=None, metavar="JSON",
                        help="only write the tables of an earlier run's JSON again (stdout "
                             "and the .md next to it); no runs")
    parser.add_argument("--before", type=Path, default=None,
                        help="Python interpreter of the 'before' version")
    parser.add_argument("--before-dir", type=Path, default=None,
                        help="checkout of the 'before' version (cwd and scene files)")
    parser.add_argument("--after", type=Path, default=None,
                        help="Python interpreter of the 'after' version")
    parser.add_argument("--after-dir", type=Path, default=None,
                        help="checkout of the 'after' version")
    parser.add_argument("--cases", nargs="+", choices=list(CASES), default=None,
                        help=f"cases (default {' '.join(DEFAULT_CASES)})")
    parser.add_argument("--repeats", type=int, default=None,
                        help="interleaved runs per case and version, the fastest kept "
                             "(default 3; 1 with --quick)")
    parser.add_argument("--quick", action="store_true",
                        help="short end times (CASES' quick_t_end), one repeat, a short "
                             "dispatch probe")
    parser.add_argument("--t-scale", type=float, default=1.0,
                        help="scale the shipped end times of the dynamic cases (default 1)")
    parser.add_argument("--dispatch-steps", type=int, default=None,
                        help="steps of the dispatch probe (default 2000, 300 with --quick; "
                             "0 skips it)")
    parser.add_argument("--dispatch-repeats", type=int, default=3,
                        help="samples per way in one dispatch probe (default 3)")
    parser.add_argument("--dispatch-rounds", type=int, default=None,
                        help="dispatch probes per version, alternating (default 2; 1 with "
                             "--quick)")
    parser.add_argument("--timeout", type=float, default=1800.0,
                        help="seconds one subprocess may take (default 1800)")
    parser.add_argument("--output", type=Path, default=None,
                        help="JSON file (default benchmarks/results/before_after.json, "
                             "before_after_quick.json with --quick); the Markdown table goes "
                             "next to it with the suffix .md")
    args = parser.parse_args(argv)
    if args.render is not None:
        if not args.render.is_file():
            parser.error(f"--render {args.render}: no such file")
        return args
    missing = [f"--{flag.replace('_', '-')}" for flag in ("before", "before_dir", "after",
                                                          "after_dir")
               if getattr(args, flag) is None]
    if missing:
        parser.error(f"{', '.join(missing)} required (or --render JSON)")
    q = args.quick
    args.cases = args.cases or list(DEFAULT_CASES)
    if args.repeats is None:
        args.repeats = 1 if q else 3
    if args.dispatch_steps is None:
        args.dispatch_steps = 300 if q else 2000
    if args.dispatch_rounds is None:
        args.dispatch_rounds = 1 if q else 2
    if args.repeats < 1 or args.t_scale <= 0 or args.dispatch_steps < 0 \
            or args.dispatch_repeats < 1 or args.dispatch_rounds < 1:
        parser.error("--repeats, --t-scale, --dispatch-repeats and --dispatch-rounds must be "
                     "positive, --dispatch-steps >= 0")
    for flag in ("before", "after"):
        python, directory = getattr(args, flag), getattr(args, f"{flag}_dir")
        if not python.is_file():
            parser.error(f"--{flag} {python}: no such interpreter")
        if not directory.is_dir():
            parser.error(f"--{flag}-dir {directory}: not a directory")
        # absolute but not resolved: a venv's python is a symbolic link to the base
        # interpreter, and only the link's path selects the venv
        setattr(args, flag, Path(os.path.abspath(python)))
        setattr(args, f"{flag}_dir", directory.resolve())
    if args.output is None:
        args.output = RESULTS / ("before_after_quick.json" if q else "before_after.json")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if args.render is not None:
        report = json.loads(args.render.read_text())
        print_report(report)
        md = args.render.with_suffix(".md")
        md.write_text(markdown(report))
        print(f"wrote {md}")
        return 0
    start = time.perf_counter()
    machine = machine_info()
    sides = {"before": Side("before", args.before, args.before_dir),
             "after": Side("after", args.after, args.after_dir)}
    for side in sides.values():
        side.info = {"python": str(side.python), "directory": str(side.directory),
                     "git": git_state(side.directory)}
    with tempfile.TemporaryDirectory(prefix="before_after_") as tmp:
        cases = measure_cases(sides, args, Path(tmp))
    dispatch = measure_dispatch(sides, args) if args.dispatch_steps else None
    machine["load_average_at_end"] = load_average()
    for s in SIDES:  # what each interpreter imported, from its first successful run
        first = next((r for c in cases.values() for r in c["runs"][s] if "error" not in r),
                     None)
        if first:
            sides[s].info.update(ancfdrv_file=first.get("ancfdrv_file"),
                                 ancfdrv_version=first.get("ancfdrv_version"),
                                 python_version=first.get("python"),
                                 threads=first.get("threads"))
    report = {
        "benchmark": "before_after",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "settings": {"before": sides["before"].info, "after": sides["after"].info,
                     "cases": args.cases, "repeats": args.repeats, "quick": args.quick,
                     "t_scale": args.t_scale, "dispatch_steps": args.dispatch_steps,
                     "dispatch_repeats": args.dispatch_repeats,
                     "dispatch_rounds": args.dispatch_rounds},
        "units": "seconds (solve_s, run_scene_s); microseconds (dispatch *_us); lengths in m",
        "machine": machine, "cases": cases, "dispatch": dispatch,
        "wall_time_s": time.perf_counter() - start,
    }
    print_report(report)
    write_report(args.output, report)
    md = args.output.with_suffix(".md")
    md.write_text(markdown(report))
    print(f"wrote {md}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
