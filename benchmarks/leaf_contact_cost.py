#!/usr/bin/env python
"""What leaf-to-leaf contact costs in the two-leaf spring (``inputs/leaf_spring.nml``, SPEC
section 7): the contact search and forces per call against the number of contact points,
and the wall time of a run with gravity only, with contact, and with contact and friction.

Part 1, cost per call. For ``spring.contact_points`` in ``--points`` (2 3 5 9 17 per end
edge of the lower leaf, so 4 6 10 18 34 points in all) the scene's model is built
(``load_scene`` with the override, ``build_model``) and the contact forces of its kernel
handle (``KernelSystem.contact_forces``, ``_kernel.system_contact_forces``: the
search of each point's closest point on the main leaf, penalty normal force with damping,
smooth Coulomb friction, and their assembly into the full force vector) is timed at one
fixed state: the assembled configuration with the lower leaf raised by 0.5 mm along r3 (so
every point penetrates by 0.49 mm) and moving along r1 at 0.02 m/s (every point slips, below
the critical slip velocity V_t = 0.08 m/s: the smooth friction branch). Four calls:

* ``wrapper``: ``KernelSystem.contact_forces`` as the Python side calls it (it stacks the
  coordinates and rates on every call), without the Jacobian;
* ``wrapper + Jacobian``: the same with ``pattern=model.full_pattern`` (the contact
  Jacobian's values on the full pattern, 30744 entries, which the call zeroes and fills);
* ``raw``, ``raw + Jacobian``: the f2py entry point ``_kernel.system_contact_forces`` with every
  array prepared once, what the Fortran stepper itself pays per evaluation (it calls the
  same ``contact_assemble``: once per Newton iteration with the Jacobian, once per step
  without it for the energies).

The closest-point guesses are updated in place by each call (as in the stepper, which starts
each search from the last one). Per point = time per call / points; the marginal cost per
point and the fixed cost per call are the slope and intercept of a least-squares line of
time per call against points. A sample is a loop of calls lasting at least ``--min-time``
(0.2 s); the samples of the four calls alternate (``time_interleaved`` of plate_cost.py) and
the time is the best of ``--repeats`` samples (5) over ``--rounds`` rounds (3) of all point
counts, so slow phases of the machine hit every call and count alike. Checks per count: all
points active, the force equal with and without the Jacobian, the projection iterations per
point and call.

Part 2, wall time of a run: ``inputs/leaf_spring.nml`` for ``--t-end`` seconds (1 s; the
scene's 0..5 s run takes about 5 times as long: the steps cost about the same over the run)
through the library (``load_scene``, ``build_model``, ``integrate``; no HDF5 output, no
command-line start-up), generalized-alpha dt = 1e-3 as in the scene, in four cases:

* ``gravity``: effects 'gravity' only, leaf.prestress off: no contact, the lower leaf is
  held by the axle clamp only and sags through the main leaf (the leaves go through each
  other), the chassis rests on the main leaf alone;
* ``gravity+contact``: 'gravity', 'contact' (penalty with damping, no friction), prestress
  off;
* ``gravity+contact+friction``: 'gravity', 'contact', 'friction', prestress off;
* ``scene``: the scene as written: 'gravity', 'contact', 'friction', 'prestress' with the
  lower leaf's free radius 1.5 m. (The prestressed leaf without contact has nothing to bear
  against: 'gravity', 'prestress' fails in its first step, so gravity-only runs without
  prestress.)

For each: wall time of ``integrate`` (``DynamicResult.wall_time_s``: integrator set-up,
initial acceleration and stepping; ``build_model`` apart), steps, Newton iterations per
step, factorizations, seconds per step, milliseconds per Newton iteration, the contact
counters, and the chassis's vertical displacement at the end. The cases run one after the
other in each of ``--run-repeats`` rounds (2), the best run of each case is kept, and the
ratios to ``gravity`` are taken between runs of the same invocation. Estimated contact share
of a step: the stepper evaluates the contact with its Jacobian once per factorization and
without it for every other residual and for the energies; with the evaluations per step from
the contact counters and the raw times of part 1 at the scene's 3 points per edge,
(factorizations x raw + Jacobian + (evaluations - factorizations) x raw) per step over the
seconds per step.

Ported to the general-system model layer: the contact data are the model's contact pair
(``model.contact_pairs[0]``: element coordinates of both leaves, sizes, grid, points,
parameters, guesses; the lower leaf is the body 'lower'), the Jacobian's pattern is
``model.full_pattern``, and the runs build with ``ancfdrv.builders.build_model`` (released
after each run). The stepper of the new kernel evaluates the contact inside
``system_evaluate``/``system_advance`` (the same ``contact_assemble``), so the raw calls
remain the per-evaluation cost; the share estimate keeps its formula. Records and keys are
unchanged.

Results: tables on stdout and JSON in ``benchmarks/results/leaf_contact_cost.json``
(``leaf_contact_cost_quick.json`` with ``--quick``). Run from the repository root::

    python benchmarks/leaf_contact_cost.py            # about 2 min on 2 cores
    python benchmarks/leaf_contact_cost.py --quick    # 2 3 5 points, 0.2 s runs, ~20 s
"""
from __future__ import annotations

import argparse
import datetime as _dt
import sys
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any, Callable

import numpy as np

from _common import load_average, machine_info, print_table, write_report
from plate_cost import time_interleaved

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
SCENE = REPO / "inputs" / "leaf_spring.nml"
POINTS, POINTS_QUICK = (2, 3, 5, 9, 17), (2, 3, 5)
#: the state of part 1: lower leaf raised (m) and moving along r1 (m/s)
RAISE, SLIDE = 5.0e-4, 0.02
#: the cases of part 2: overrides of inputs/leaf_spring.nml
CASES = {
    "gravity": ["scene.effects=gravity", "leaf.prestress=.false."],
    "gravity+contact": ["scene.effects=gravity,contact", "leaf.prestress=.false."],
    "gravity+contact+friction": ["scene.effects=gravity,contact,friction",
                                 "leaf.prestress=.false."],
    "scene": [],
}
CALLS = ("wrapper", "wrapper_jacobian", "raw", "raw_jacobian")
LABELS = {"wrapper": "wrapper", "wrapper_jacobian": "wrapper+J", "raw": "raw",
          "raw_jacobian": "raw+J"}


# -- part 1: contact search and forces per call ------------------------------------------------
def contact_setup(points: int) -> dict[str, Any]:
    """Model with ``points`` contact points per edge, the timed state and the four calls."""
    from ancfdrv import _kernel
    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    from ancfdrv.system.meshes import PLATE_NODE_DOFS
    P_R = 0  # r is the first vector of a plate node's [r, r_x, r_y]

    scene = load_scene(SCENE, [f"spring.contact_points={points}"])
    model = build_model(scene)
    pair = model.contact_pairs[0]
    lower = next(b for b in model.bodies if b.name == "lower")
    e = model.expand(model.e0).copy()   # contact works on the full coordinates
    rates = np.zeros_like(e)
    for node in range(lower.mesh.nnodes):
        first = lower.first + PLATE_NODE_DOFS * node + P_R
        e[first + 2] += RAISE
        rates[first] = SLIDE
    sizes = np.asfortranarray(pair["sizes"], dtype=np.float64)
    guesses = np.asfortranarray(pair["guesses"], dtype=np.float64).copy(order="F")
    counts = np.zeros(6, np.int32)
    pattern = model.full_pattern

    system = model.kernel   # its contact pair and the full pattern

    def wrapper(jacobian: bool) -> Callable[[], Any]:
        return lambda: system.contact_forces(e, rates, guesses, counts, want_jacobian=jacobian)

    state = np.asfortranarray(np.column_stack([e, rates]))
    npoint = len(pair["point_element"])

    def raw(jacobian: bool) -> Callable[[], Any]:
        nnz = len(pattern.col_index) if jacobian else 1
        return lambda: _kernel.system_contact_forces(system.handle, nnz, npoint, state, 0.0,
                                                     int(jacobian), guesses, counts)

    calls = {"wrapper": wrapper(False), "wrapper_jacobian": wrapper(True),
             "raw": raw(False), "raw_jacobian": raw(True)}
    return {"points_per_edge": points, "points": len(pair["point_element"]),
            "nfull": model.nfull, "ndof": model.ndof, "nnz_full": len(pattern.col_index),
            "calls": calls, "counts": counts}


def check_contact(setup: dict[str, Any]) -> dict[str, Any]:
    """Every point active; the force with and without the Jacobian; raw = wrapper; the
    projection iterations of one (warm) call per point."""
    calls, counts = setup["calls"], setup["counts"]
    calls["wrapper"]()  # the guesses converge at the timed state
    before = counts.copy()
    plain = calls["wrapper"]()
    after = counts.copy()
    with_j = calls["wrapper_jacobian"]()
    raw_force = calls["raw"]()[2]
    n = setup["points"]
    records = plain["records"]
    scale = np.abs(plain["force"]).max()
    out = {"active_points": int(np.count_nonzero(records[0] > 0)),
           "penetration_m": [float(records[0].min()), float(records[0].max())],
           "slip_speed_m_s": [float(records[3].min()), float(records[3].max())],
           "normal_force_total_n": float(records[1].sum()),
           "force_max": float(scale),
           "force_with_vs_without_jacobian": float(np.abs(with_j["force"] - plain["force"]).max()
                                                   / scale),
           "raw_vs_wrapper_force": float(np.abs(raw_force - plain["force"]).max() / scale),
           "jacobian_nonzeros": int(np.count_nonzero(with_j["values"])),
           "projection_iterations_per_point_warm": float((after[3] - before[3]) / n)}
    if out["active_points"] != n:
        raise RuntimeError(f"{n} contact points: only {out['active_points']} active at the "
                           "timed state")
    return out


def measure_contact(args: argparse.Namespace) -> dict[str, Any]:
    """All point counts and calls, in rounds."""
    setups = [contact_setup(p) for p in args.points]
    records = []
    for s in setups:
        records.append({k: s[k] for k in ("points_per_edge", "points", "nfull", "ndof",
                                          "nnz_full")}
                       | {"checks": check_contact(s), "rounds": {c: [] for c in CALLS}})
    for r in range(args.rounds):
        for s, rec in zip(setups, records):
            best, _ = time_interleaved({name: s["calls"][name] for name in CALLS},
                                       args.min_time, args.repeats)
            for name in CALLS:
                rec["rounds"][name].append(asdict(best[name]))
        print(f"  part 1, round {r + 1}/{args.rounds} done", file=sys.stderr, flush=True)
    for rec in records:
        rec["per_call_us"], rec["per_point_us"] = {}, {}
        for name in CALLS:
            best = min(x["per_call_s"] for x in rec["rounds"][name])
            rec["per_call_us"][name] = 1e6 * best
            rec["per_point_us"][name] = 1e6 * best / rec["points"]
    fits = {}
    npts = np.array([rec["points"] for rec in records], float)
    for name in CALLS:
        t = np.array([rec["per_call_us"][name] for rec in records])
        if len(npts) >= 2:
            slope, intercept = np.polyfit(npts, t, 1)
            fits[name] = {"per_point_us": float(slope), "fixed_us": float(intercept),
                          "max_relative_residual": float(np.abs(t - (slope * npts + intercept)
                                                                ).max() / t.max())}
    return {"scene": str(SCENE.relative_to(REPO)), "state": {"raise_m": RAISE,
            "slide_m_s": SLIDE}, "records": records, "linear_fit": fits}


# -- part 2: runs ---------------------------------------------------------------------------
def run_case(name: str, t_end: float) -> dict[str, Any]:
    """One run of a case through the library; a SolverError is recorded."""
    from ancfdrv.builders import build_model
    from ancfdrv.errors import SolverError
    from ancfdrv.io.scene import load_scene
    from ancfdrv.runner import dynamic_settings
    from ancfdrv.solvers.dynamic import integrate

    scene = load_scene(SCENE, CASES[name] + [f"solver.t_end={t_end!r}"])
    t0 = time.perf_counter()
    model = build_model(scene)
    build_s = time.perf_counter() - t0
    settings = dynamic_settings(scene)
    chunks: list[Any] = []
    out: dict[str, Any] = {"effects": list(scene.effects),
                           "prestress": bool(scene["leaf"]["prestress"]),
                           "ndof": model.ndof, "dt": settings.dt, "t_end": settings.t_end,
                           "build_model_s": build_s, "error": None}
    t0 = time.perf_counter()
    try:
        result = integrate(model, settings, model.e0.copy(), sink=chunks.append,
                           progress=False)
    except SolverError as exc:
        out.update(error=str(exc), failed_after_s=time.perf_counter() - t0)
        result = None
    finally:
        model.close()
    if chunks:
        t = np.concatenate([c.time for c in chunks])
        chassis = np.concatenate([c.deflections for c in chunks])[:, list(model.probes).index(
            "chassis")]
        out.update(t_reached=float(t[-1]), chassis_vertical_end_m=float(chassis[-1, 2]),
                   chassis_vertical_min_m=float(chassis[:, 2].min()))
    if result is None:
        return out
    steps = max(result.steps, 1)
    out.update(wall_time_s=result.wall_time_s, steps=result.steps,
               newton_iterations=result.newton_iterations,
               factorizations=result.factorizations, timing=result.timing,
               newton_per_step=result.newton_iterations / steps,
               s_per_step=result.wall_time_s / steps,
               ms_per_newton=1e3 * result.timing.get("stepping", result.wall_time_s)
               / max(result.newton_iterations, 1),
               counters={k: int(model.counters[k]) for k in (
                   "contact_points", "contact_active", "friction_evaluations",
                   "contact_projection_iterations", "contact_projection_fallbacks",
                   "contact_jacobian_dropped") if k in model.counters})
    return out


def measure_runs(args: argparse.Namespace, contact: dict[str, Any]) -> dict[str, Any]:
    """Each case in each round; the best run of each; ratios to 'gravity'."""
    runs: dict[str, list[dict[str, Any]]] = {name: [] for name in args.cases}
    for r in range(args.run_repeats):
        for name in args.cases:
            t0 = time.perf_counter()
            runs[name].append(run_case(name, args.t_end))
            status = runs[name][-1]["error"] or "done"
            print(f"  part 2, round {r + 1}/{args.run_repeats}, {name}: "
                  f"{time.perf_counter() - t0:5.1f} s, {status}", file=sys.stderr, flush=True)
    best = {}
    for name, rs in runs.items():
        done = [x for x in rs if x["error"] is None]
        best[name] = dict(min(done, key=lambda x: x["wall_time_s"]) if done else rs[0])
        best[name]["wall_times_s"] = [x.get("wall_time_s") for x in rs]
    base = best.get("gravity")
    if base is not None and base["error"] is None:
        for name, rec in best.items():
            if rec["error"] is None:
                rec["ratio_to_gravity"] = {
                    "wall_time": rec["wall_time_s"] / base["wall_time_s"],
                    "s_per_step": rec["s_per_step"] / base["s_per_step"],
                    "newton_per_step": rec["newton_per_step"] / base["newton_per_step"],
                    "ms_per_newton": rec["ms_per_newton"] / base["ms_per_newton"]}
    # contact share of a step, from part 1 at the scene's points per edge: the stepper
    # evaluates the contact with its Jacobian once per factorization, without it for every
    # residual and the energies (the counters give the evaluations per point)
    scene_points = 3
    rec3 = next((r for r in contact["records"] if r["points_per_edge"] == scene_points), None)
    for name, rec in best.items():
        if rec3 is None or rec["error"] is not None or "contact" not in rec["effects"]:
            continue
        steps = max(rec["steps"], 1)
        calls = rec["counters"]["contact_points"] / rec3["points"] / steps
        with_j = rec["factorizations"] / steps
        per_step = 1e-6 * (with_j * rec3["per_call_us"]["raw_jacobian"]
                           + max(calls - with_j, 0.0) * rec3["per_call_us"]["raw"])
        rec["contact_calls_per_step"] = calls
        rec["contact_s_per_step_estimate"] = per_step
        rec["contact_share_estimate"] = per_step / rec["s_per_step"]
    return {"scene": str(SCENE.relative_to(REPO)), "t_end": args.t_end,
            "cases": {name: CASES[name] for name in args.cases}, "best": best,
            "all_runs": runs}


# -- output ---------------------------------------------------------------------------------
def fmt(x: Any, spec: str) -> str:
    return "-" if x is None else format(x, spec)


def print_contact(part: dict[str, Any], args: argparse.Namespace) -> None:
    print(f"\nContact search + forces ({part['scene']}), per call and per point in "
          f"microseconds, best of {args.rounds} round(s) x {args.repeats} samples of >= "
          f"{args.min_time:g} s; lower leaf raised {1e3 * RAISE:g} mm, sliding "
          f"{SLIDE:g} m/s; J = Jacobian on the full pattern")
    rows = []
    for rec in part["records"]:
        c, p = rec["per_call_us"], rec["per_point_us"]
        rows.append([str(rec["points_per_edge"]), str(rec["points"])]
                    + [f"{c[n]:.1f}" for n in CALLS] + [f"{p[n]:.2f}" for n in CALLS]
                    + [f"{rec['checks']['projection_iterations_per_point_warm']:.1f}"])
    head = [("/edge", 5), ("pts", 4)] + [(f"{LABELS[n]} us", 12) for n in CALLS] + \
        [(f"{LABELS[n]}/pt", 10) for n in CALLS] + [("proj", 4)]
    print_table(head, rows)
    print("proj: projection iterations per point and call (warm start)")
    for name, fit in part["linear_fit"].items():
        print(f"  {LABELS[name]:10s} fit: {fit['per_point_us']:6.2f} us per point + "
              f"{fit['fixed_us']:7.1f} us per call (max residual "
              f"{100 * fit['max_relative_residual']:.1f} %)")


def print_runs(part: dict[str, Any]) -> None:
    print(f"\nRuns of {part['scene']}, 0 to {part['t_end']:g} s, dt from the scene; wall = "
          "integrate(), best of the rounds; ratios to 'gravity'")
    rows = []
    for name, r in part["best"].items():
        ratio = r.get("ratio_to_gravity", {})
        rows.append([name, "on" if r["prestress"] else "off", fmt(r.get("wall_time_s"), ".2f"),
                     str(r.get("steps", "-")), fmt(r.get("newton_per_step"), ".2f"),
                     str(r.get("factorizations", "-")),
                     fmt(None if r.get("s_per_step") is None else 1e3 * r["s_per_step"], ".2f"),
                     fmt(r.get("ms_per_newton"), ".2f"), fmt(ratio.get("wall_time"), ".2f"),
                     fmt(ratio.get("ms_per_newton"), ".2f"),
                     fmt(None if r.get("contact_share_estimate") is None
                         else 100 * r["contact_share_estimate"], ".1f"),
                     fmt(None if r.get("chassis_vertical_end_m") is None
                         else 1e3 * r["chassis_vertical_end_m"], ".2f")])
    print_table([("case", 24), ("pre", 3), ("wall s", 7), ("steps", 5), ("Newt/st", 7),
                 ("fact", 5), ("ms/step", 7), ("ms/Newt", 7), ("wall/g", 6), ("Nwt/g", 6),
                 ("cont %", 6), ("chassis mm", 10)], rows)
    print("pre: leaf.prestress; ms/Newt: stepping time per Newton iteration; cont %: "
          "estimated share of the step in the contact evaluations (part 1, 3 points per edge,\n"
          "with the Jacobian once per factorization, without it for the other evaluations "
          "the counters report); chassis: vertical displacement at the end")
    for name, r in part["best"].items():
        if r.get("contact_calls_per_step") is not None:
            print(f"  {name}: {r['contact_calls_per_step']:.2f} contact evaluations per step, "
                  f"{1e6 * r['contact_s_per_step_estimate']:.0f} us per step estimated")
    for name, r in part["best"].items():
        if r["error"]:
            print(f"  {name} failed at t = {r.get('t_reached', 0.0):g} s: {r['error']}")


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="points 2 3 5, one round of 3 samples, runs of 0.2 s once")
    parser.add_argument("--points", type=int, nargs="+", default=None,
                        help="spring.contact_points (per edge) of part 1 (default 2 3 5 9 17; "
                             "2 3 5 with --quick)")
    parser.add_argument("--min-time", type=float, default=0.2,
                        help="seconds one sample lasts at least (default 0.2)")
    parser.add_argument("--repeats", type=int, default=None,
                        help="samples per call and round (default 5; 3 with --quick)")
    parser.add_argument("--rounds", type=int, default=None,
                        help="rounds over the point counts (default 3; 1 with --quick)")
    parser.add_argument("--t-end", type=float, default=None,
                        help="simulated seconds per run of part 2 (default 1.0, 0.2 with "
                             "--quick; the scene's run is 5 s, about 5 times the 1 s cost)")
    parser.add_argument("--cases", nargs="+", choices=list(CASES), default=None,
                        help="cases of part 2 (default all; ratios need 'gravity')")
    parser.add_argument("--run-repeats", type=int, default=None,
                        help="rounds of runs of part 2, best kept (default 2; 1 with --quick)")
    parser.add_argument("--output", type=Path, default=None,
                        help="JSON file (default benchmarks/results/leaf_contact_cost.json, "
                             "leaf_contact_cost_quick.json with --quick)")
    args = parser.parse_args(argv)
    q = args.quick
    if args.points is None:
        args.points = list(POINTS_QUICK if q else POINTS)
    if args.repeats is None:
        args.repeats = 3 if q else 5
    if args.rounds is None:
        args.rounds = 1 if q else 3
    if args.t_end is None:
        args.t_end = 0.2 if q else 1.0
    if args.cases is None:
        args.cases = list(CASES)
    if args.run_repeats is None:
        args.run_repeats = 1 if q else 2
    if min(args.points) < 2:
        parser.error("spring.contact_points must be at least 2")
    if min(args.repeats, args.rounds, args.run_repeats) < 1 or args.t_end <= 0 \
            or args.min_time <= 0:
        parser.error("repeats, rounds, --t-end and --min-time must be positive")
    if args.output is None:
        args.output = RESULTS / ("leaf_contact_cost_quick.json" if q else
                                 "leaf_contact_cost.json")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    from ancfdrv import _kernel

    start = time.perf_counter()
    machine = machine_info()
    kernel_so = Path(_kernel.__file__)
    contact = measure_contact(args)
    runs = measure_runs(args, contact)
    machine["load_average_at_end"] = load_average()
    print_contact(contact, args)
    print_runs(runs)
    report = {
        "benchmark": "leaf_contact_cost",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "settings": {"points": args.points, "min_time_s": args.min_time,
                     "repeats": args.repeats, "rounds": args.rounds, "t_end": args.t_end,
                     "cases": args.cases, "run_repeats": args.run_repeats,
                     "quick": args.quick},
        "units": "per_call_us, per_point_us, fixed_us in microseconds; wall_time_s, "
                 "s_per_step in seconds; ms_per_newton in milliseconds; lengths in m",
        "machine": machine,
        "kernel_module": str(kernel_so), "kernel_mtime": kernel_so.stat().st_mtime,
        "contact_cost": contact, "runs": runs,
        "wall_time_s": time.perf_counter() - start,
    }
    write_report(args.output, report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
