#!/usr/bin/env python
"""Cost of the thin plate element (seed 003), plain against completed, and the plate
pendulum's wall time against its accuracy.

Part 1, cost per element. On flat square meshes of ``--flat`` elements per side (8 and 16;
0.3 m x 0.3 m, h = 0.01 m) and on a curved leaf (``arc_mesh``: arc length 0.8 m, radius
1.986 m, width 0.07 m, h = 0.014 m, ``--leaf`` x 1 elements, 64), the coordinates are the
initial ones plus a random perturbation, uniform in [-1e-2, 1e-2] (seeded; the same for
both variants of a mesh), so membrane and bending strains are all non-zero. For each
variant, 'plain' and 'completed', this times with ``time.perf_counter`` the f2py entry
points the Python side calls (arrays prepared once in Fortran order, no conversion timed):

* ``force``: elastic force and strain energy alone,
  ``_kernel.plate_elastic_forces(..., want_tangent=0)`` at the 16-point Gauss rule of
  ``_kernel.plate_rule()``;
* ``force + tangent``: the same with the element tangents (36 x 36 per element),
  ``want_tangent=1`` (what each Newton iteration of the dynamics calls);
* ``setup``: the reference data at the Gauss points, ``_kernel.plate_reference``
  (shape derivatives, frame maps K, reference curvatures c0, weights), once per model.

Cost per element = call time / elements; the price of completion is the ratio completed /
plain. Note that the element loop does the same arithmetic for both variants (the plain
variant runs with K = I and c0 = 0; plate_element.f90), so the force ratios are expected
at 1 within timing noise: the variants differ in the set-up only. A sample is a loop of
calls lasting at least ``--min-time`` (0.2 s); the time is the best of ``--repeats``
samples (3; 2 with ``--quick``) in each of ``--rounds`` rounds (2; 1 with ``--quick``),
where a round runs every mesh, variant and thread count once, so slow phases of the
machine hit both variants alike (``time_call`` of ``element_cost.py``). The kernel's
OpenMP element loop is run at each of ``--threads`` (1 2; 1 with ``--quick``), set in this
process with ``omp_set_num_threads`` of the mapped OpenMP runtime (ancfdrv defaults to one
thread); the set-up is timed at the first thread count only (it has no OpenMP loop).
Checks recorded per mesh: the force alone equals the force of the force + tangent call,
the tangents' asymmetry, the plain - completed force difference (zero for the flat plate,
whose reference frame is the identity), and both variants' energy at the undeformed
configuration (zero for completed; for plain, the leaf's curvature counted as strain).

Part 2, the plate pendulum (``inputs/plate_pendulum.nml``, SPEC section 6: 0.3 m square
plate held at a corner by a spherical joint, released under gravity, 0 to 0.3 s) at
nx = ny in ``--meshes`` (2 4 6 8 12; 2 4 8 with ``--quick``), generalized-alpha with
``solver.dt = --dt`` (2e-3) for all meshes, so their output times coincide. Each mesh runs
through the library (``load_scene``, ``build_model``, ``integrate``; no HDF5 output, no
command-line start-up); its wall time is ``DynamicResult.wall_time_s`` (set-up of the
integrator, initial acceleration and stepping; ``build_model`` is timed apart), best of
``--pendulum-repeats`` runs (3), fewer when the runs of a mesh already took 5 s. Next to
it, the accuracy: the corner probe at t = 0.3 s, the largest distance over the whole
history to the finest mesh's corner (the finest mesh that completed, interpolated on the
common times), and the energy drift max|E_total - E_total(0)| relative to the largest
change of the gravity potential. A run that raises ``SolverError`` is recorded with its
message (and the history up to the failure) and the next mesh runs. The 4 x 4 mesh also
runs with variant 'plain': for the flat plate both variants must give the same history to
round-off.

Ported to the general-system model layer: the meshes come from ``ancfdrv.system.meshes``
and the kernel arrays of part 1 from ``ancfdrv.kernel.PlateReference`` on the element
coordinates (as the assembly builds a plate set), so no model is built there; the
pendulum's model is ``ancfdrv.builders.build_model`` (released after each run). The
stepper of the new kernel decides its factorizations itself (``jacobian`` policy 'step'
for the scene), so 'factorizations' and the Newton counts come from its per-step
statistics. Records and keys are unchanged.

Results: tables on stdout and JSON in ``benchmarks/results/plate_cost.json``
(``plate_cost_quick.json`` with ``--quick``). Run from the repository root::

    python benchmarks/plate_cost.py            # about 65 s on 2 cores
    python benchmarks/plate_cost.py --quick    # smaller meshes, one round, about 15 s
"""
from __future__ import annotations

import argparse
import ctypes
import datetime as _dt
import gc
import math
import resource
import sys
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any, Callable

import numpy as np

from _common import load_average, machine_info, print_table, write_report
from element_cost import Sample, openmp_runtime, time_call

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
SCENE = REPO / "inputs" / "plate_pendulum.nml"
VARIANTS = ("plain", "completed")
KERNELS = ("force", "force_tangent", "setup")
LABELS = {"force": "force", "force_tangent": "force+tangent", "setup": "setup"}
#: Meshes of part 1 (elements per side of the flat plate, elements along the leaf).
FLAT, FLAT_QUICK = (8, 16), (4, 8)
LEAF, LEAF_QUICK = 64, 16
#: The pendulum's plate and material (SPEC section 6) and the leaf of inputs/curved_leaf.nml;
#: the values do not change the cost of a call.
PLATE_SIDE, PLATE_THICKNESS = 0.3, 0.01
LEAF_GEOMETRY = dict(arc_length=0.8, radius=1.986, width=0.07)
LEAF_THICKNESS = 0.014
YOUNGS, DENSITY, POISSON = 1.0e5, 7810.0, 0.3
PERTURBATION = 1.0e-2
SEED = 3
#: Pendulum meshes (nx = ny), the finest used as the reference of the others.
MESHES, MESHES_QUICK = (2, 4, 6, 8, 12), (2, 4, 8)
PLAIN_MESH = 4
#: Stop repeating a pendulum mesh once its runs took this long.
PENDULUM_BUDGET_S = 5.0
#: Times at which the corner position is kept in the JSON.
KEEP_TIMES = np.linspace(0.0, 0.3, 7)


# -- OpenMP thread count, set in this process ------------------------------------------
class OpenMP:
    """omp_get_max_threads / omp_set_num_threads of the OpenMP runtime mapped into the
    process (after ``import ancfdrv._kernel``); inert when the kernel has none."""

    def __init__(self) -> None:
        self.libraries = openmp_runtime()
        self.lib = None
        if self.libraries:
            try:
                self.lib = ctypes.CDLL(self.libraries[0])
                self.lib.omp_get_max_threads()
            except (OSError, AttributeError):
                self.lib = None
        self.default = self.get()

    def get(self) -> int | None:
        return int(self.lib.omp_get_max_threads()) if self.lib else None

    def set(self, threads: int) -> None:
        if self.lib:
            self.lib.omp_set_num_threads(ctypes.c_int(threads))


# -- part 1: cost per element ------------------------------------------------------------
def element_meshes(args: argparse.Namespace) -> list[dict[str, Any]]:
    """The meshes of part 1: label, mesh and thickness."""
    from ancfdrv.system.meshes import arc_mesh, rectangle_mesh

    meshes = [{"label": f"flat {n}x{n}", "kind": "flat", "mesh":
               rectangle_mesh(PLATE_SIDE, PLATE_SIDE, n, n), "thickness": PLATE_THICKNESS}
              for n in args.flat]
    if args.leaf > 0:
        meshes.append({"label": f"leaf {args.leaf}x1", "kind": "leaf",
                       "mesh": arc_mesh(nx=args.leaf, ny=1, **LEAF_GEOMETRY),
                       "thickness": LEAF_THICKNESS})
    return meshes


def kernel_arrays(mesh_info: dict[str, Any], variant: str, e: np.ndarray) -> dict[str, Any]:
    """Kernel-ready arrays of one mesh and variant at the configuration e."""
    from ancfdrv.kernel import PLATE_VARIANTS, PlateReference
    from ancfdrv.system.meshes import PLATE_NODE_DOFS

    mesh = mesh_info["mesh"]
    # (36, nel) element coordinates, as Plate.element_dofs numbers them (first = 0)
    dofs = (PLATE_NODE_DOFS * mesh.elements[:, :, None]
            + np.arange(PLATE_NODE_DOFS)).reshape(mesh.nel, 36).T
    e0 = mesh.coords.ravel()
    f = np.asfortranarray
    reference = f(e0[dofs].reshape(3, 12, mesh.nel, order="F"))
    ref = PlateReference(reference, mesh.a, mesh.b, variant)
    return {"nel": mesh.nel, "ndof": len(e0),
            "dofs": f(dofs + 1, dtype=np.int32), "e": f(e, dtype=np.float64),
            "e0": f(e0, dtype=np.float64),
            "derivs": ref.derivs, "frame": ref.frame, "curvature0": ref.curvature0,
            "weights": ref.weights, "reference": reference,
            "a": f(mesh.a, dtype=np.float64), "b": f(mesh.b, dtype=np.float64),
            "variant": PLATE_VARIANTS[variant], "thickness": mesh_info["thickness"]}


def kernel_calls(kernel: Any, a: dict[str, Any]) -> dict[str, Callable[[], Any]]:
    """The timed calls of one mesh and variant."""
    npts = int(kernel.plate_rule())

    def forces(want_tangent: int, e: np.ndarray | None = None) -> Callable[[], Any]:
        x = a["e"] if e is None else e
        return lambda: kernel.plate_elastic_forces(a["dofs"], x, a["derivs"], a["frame"],
                                                   a["curvature0"], a["weights"], YOUNGS,
                                                   POISSON, a["thickness"], want_tangent)
    return {"force": forces(0), "force_tangent": forces(1),
            "setup": lambda: kernel.plate_reference(npts, a["reference"], a["a"], a["b"],
                                                    a["variant"]),
            "force_at_e0": forces(0, a["e0"])}


def check_mesh(calls: dict[str, dict[str, Callable[[], Any]]], label: str) -> dict[str, Any]:
    """Consistency of the calls before they are timed."""
    out: dict[str, Any] = {}
    forces = {}
    for variant in VARIANTS:
        force, energy, _, info = calls[variant]["force"]()
        force_t, energy_t, tangent, info_t = calls[variant]["force_tangent"]()
        _, energy0, _, info0 = calls[variant]["force_at_e0"]()
        if (info or info_t or info0 or not np.all(np.isfinite(force))
                or not np.abs(force).max() > 0):
            raise RuntimeError(f"{label}, {variant}: kernel failed (info {info}, {info_t}, "
                               f"{info0}) or the force is not finite and non-zero")
        scale = np.abs(force).max()
        asym = np.abs(tangent - tangent.transpose(1, 0, 2)).max() / np.abs(tangent).max()
        out[variant] = {"force_max": float(scale), "energy": float(energy),
                        "force_vs_force_tangent": float(np.abs(force - force_t).max() / scale),
                        "tangent_asymmetry": float(asym), "energy_at_initial": float(energy0)}
        forces[variant] = force
    scale = max(np.abs(f).max() for f in forces.values())
    out["plain_vs_completed_force"] = float(np.abs(forces["plain"]
                                                   - forces["completed"]).max() / scale)
    return out


def time_interleaved(calls: dict[str, Callable[[], Any]], min_time: float,
                     repeats: int) -> tuple[dict[str, Sample], dict[str, list[float]]]:
    """``time_call`` of element_cost.py for several calls whose samples alternate (plain,
    completed, plain, ...), so a drift of the machine's speed hits them alike. Returns the
    best sample of each call and all its per-call times (in the order taken)."""
    counts = {}
    for name, call in calls.items():
        call()  # warm-up: first-touch of outputs
        n, spent = 0, 0.0
        t0 = time.perf_counter()
        while spent < min(0.05, min_time):
            call()
            n += 1
            spent = time.perf_counter() - t0
        counts[name] = max(1, math.ceil(n * min_time / spent))
    per_call: dict[str, list[float]] = {name: [] for name in calls}
    faults: dict[str, list[float]] = {name: [] for name in calls}
    gc.collect()
    gc.disable()
    try:
        for _ in range(repeats):
            for name, call in calls.items():
                r0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
                t0 = time.perf_counter()
                for _ in range(counts[name]):
                    call()
                elapsed = time.perf_counter() - t0
                r1 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
                per_call[name].append(elapsed / counts[name])
                faults[name].append((r1 - r0) / counts[name])
    finally:
        gc.enable()
    best = {}
    for name, times in per_call.items():
        i = int(np.argmin(times))
        best[name] = Sample(times[i], float(np.median(times)), counts[name], repeats,
                            faults[name][i])
    return best, per_call


def measure_elements(kernel: Any, omp: OpenMP, args: argparse.Namespace) -> dict[str, Any]:
    """All kernels, meshes, variants and thread counts, in interleaved rounds."""
    rng = np.random.default_rng(SEED)
    meshes = element_meshes(args)
    calls: list[dict[str, dict[str, Callable[[], Any]]]] = []
    records: list[dict[str, Any]] = []
    for info in meshes:
        ndof = 9 * info["mesh"].nnodes
        e = info["mesh"].coords.ravel() + PERTURBATION * rng.uniform(-1.0, 1.0, ndof)
        arrays = {v: kernel_arrays(info, v, e) for v in VARIANTS}
        calls.append({v: kernel_calls(kernel, arrays[v]) for v in VARIANTS})
        records.append({"mesh": info["label"], "kind": info["kind"],
                        "elements": arrays["plain"]["nel"], "ndof": ndof,
                        "thickness": info["thickness"],
                        "checks": check_mesh(calls[-1], info["label"]), "samples": {}})
    threads_list = args.threads if omp.lib else [omp.default or 1]
    samples: dict[tuple, list] = {}
    times: dict[tuple, dict[str, list[float]]] = {}
    for round_ in range(args.rounds):
        t0 = time.perf_counter()
        for threads in threads_list:
            omp.set(threads)
            for i in range(len(records)):
                for name in KERNELS:
                    if name == "setup" and threads != threads_list[0]:
                        continue
                    best, per_call = time_interleaved(
                        {v: calls[i][v][name] for v in VARIANTS}, args.min_time, args.repeats)
                    for variant in VARIANTS:
                        samples.setdefault((i, threads, variant, name), []).append(best[variant])
                        times.setdefault((i, threads, name), {}).setdefault(
                            variant, []).extend(per_call[variant])
        print(f"  part 1, round {round_ + 1}: {time.perf_counter() - t0:5.1f} s",
              file=sys.stderr, flush=True)
    omp.set(omp.default or 1)
    for (i, threads, variant, name), runs in samples.items():
        rec = records[i]
        best = min(runs, key=lambda s: s.per_call_s)
        rec["samples"].setdefault(str(threads), {}).setdefault(variant, {})[name] = {
            **asdict(best), "samples": sum(s.samples for s in runs),
            "per_element_us": 1e6 * best.per_call_s / rec["elements"],
            "rounds_per_element_us": [1e6 * s.per_call_s / rec["elements"] for s in runs]}
    for (i, threads, name), by_variant in times.items():
        # the ratio of each completed sample to the plain sample taken just before it
        pairs = np.array(by_variant["completed"]) / np.array(by_variant["plain"])
        by_name = records[i].setdefault("completed_over_plain", {}).setdefault(str(threads), {})
        s = records[i]["samples"][str(threads)]
        by_name[name] = {"best": s["completed"][name]["per_call_s"]
                         / s["plain"][name]["per_call_s"],
                         "paired_median": float(np.median(pairs)),
                         "paired_min": float(pairs.min()), "paired_max": float(pairs.max())}
    floor = time_call(kernel.plate_rule, args.min_time, args.repeats)
    return {"gauss_points": int(kernel.plate_rule()), "threads": threads_list,
            "f2py_call_floor_s": floor.per_call_s, "perturbation": PERTURBATION,
            "seed": SEED, "records": records}


# -- part 2: the plate pendulum ----------------------------------------------------------
def pendulum_run(n: int, variant: str, args: argparse.Namespace) -> dict[str, Any]:
    """One mesh of the pendulum, best wall time of up to ``args.pendulum_repeats`` runs,
    with the histories of the first run."""
    from ancfdrv.builders import build_model
    from ancfdrv.errors import SolverError
    from ancfdrv.io.scene import load_scene
    from ancfdrv.runner import dynamic_settings
    from ancfdrv.solvers.dynamic import integrate

    overrides = [f"plate.nx={n}", f"plate.ny={n}", f"plate.variant={variant}",
                 f"solver.dt={args.dt!r}"]
    record: dict[str, Any] = {"mesh": n, "variant": variant, "overrides": overrides,
                              "error": None, "runs": []}
    spent, first = 0.0, None
    for _ in range(args.pendulum_repeats):
        scene = load_scene(SCENE, overrides)
        t0 = time.perf_counter()
        model = build_model(scene)
        build_s = time.perf_counter() - t0
        settings = dynamic_settings(scene)
        chunks: list[Any] = []
        t0 = time.perf_counter()
        try:
            result = integrate(model, settings, model.e0.copy(), sink=chunks.append,
                               progress=False)
        except SolverError as exc:
            record["error"] = str(exc)
            result = None
        finally:
            model.close()
        spent += time.perf_counter() - t0 + build_s
        history = {"time": np.concatenate([c.time for c in chunks]),
                   "corner": np.concatenate([c.probes for c in chunks])[
                       :, list(model.probes).index("corner")],
                   "energy": np.concatenate([c.energy for c in chunks])}
        if first is None:
            first = history
            record.update(ndof=model.ndof, elements=sum(s.nel for s in model.sets),
                          t_end=settings.t_end,
                          dt=settings.dt)
        else:
            record["reproducible"] = bool(np.array_equal(first["corner"], history["corner"]))
        if result is None:
            break
        record["runs"].append({"wall_time_s": result.wall_time_s, "build_model_s": build_s,
                               "steps": result.steps,
                               "newton_iterations": result.newton_iterations,
                               "factorizations": result.factorizations,
                               "timing": result.timing})
        if spent > PENDULUM_BUDGET_S:
            break
    record["history"] = first
    if record["runs"]:
        best = min(record["runs"], key=lambda r: r["wall_time_s"])
        record.update({k: best[k] for k in ("wall_time_s", "build_model_s", "steps",
                                            "newton_iterations", "factorizations")})
        record["stepping_s"] = best["timing"].get("stepping")
        record["newton_per_step"] = best["newton_iterations"] / max(best["steps"], 1)
        record["ms_per_step"] = 1e3 * best["wall_time_s"] / max(best["steps"], 1)
    return record


def corner_distance(history: dict[str, np.ndarray], reference: dict[str, np.ndarray]) -> float:
    """Largest distance between two corner histories on the first one's times within the
    reference's range (the times coincide when both ran with the same dt)."""
    t, ref_t = history["time"], reference["time"]
    if np.array_equal(t, ref_t[:len(t)]):
        other = reference["corner"][:len(t)]
        mine = history["corner"]
    else:
        keep = (t >= ref_t[0]) & (t <= ref_t[-1])
        mine = history["corner"][keep]
        other = np.column_stack([np.interp(t[keep], ref_t, reference["corner"][:, k])
                                 for k in range(3)])
    return float(np.linalg.norm(mine - other, axis=1).max())


def accuracy(record: dict[str, Any], finest: dict[str, Any] | None) -> None:
    """Corner at t_end, distance to the finest mesh, energy drift (added to record)."""
    h = record["history"]
    complete = record["error"] is None
    record["t_last"] = float(h["time"][-1])
    record["corner_end"] = h["corner"][-1] if complete else None
    energy = h["energy"]
    total, gravity = energy[:, 4], energy[:, 2]
    record["energy_drift"] = float(np.abs(total - total[0]).max())
    record["gravity_change"] = float(np.abs(gravity - gravity[0]).max())
    record["energy_drift_relative"] = (record["energy_drift"] / record["gravity_change"]
                                       if record["gravity_change"] > 0 else None)
    record["corner_kept"] = {"time": KEEP_TIMES, "corner": np.column_stack(
        [np.interp(KEEP_TIMES, h["time"], h["corner"][:, k], right=np.nan)
         for k in range(3)])}
    if finest is None or finest is record:
        record["distance_to_finest_max"] = 0.0 if finest is record else None
        record["distance_to_finest_end"] = 0.0 if finest is record else None
        return
    record["distance_to_finest_max"] = corner_distance(h, finest["history"])
    record["distance_to_finest_end"] = (
        float(np.linalg.norm(h["corner"][-1] - finest["history"]["corner"][-1]))
        if complete else None)


def measure_pendulum(args: argparse.Namespace, omp: OpenMP) -> dict[str, Any]:
    """All meshes with the completed variant, and the plain one at PLAIN_MESH."""
    runs = []
    for n in args.meshes:
        t0 = time.perf_counter()
        runs.append(pendulum_run(n, "completed", args))
        status = "failed: " + runs[-1]["error"] if runs[-1]["error"] else "done"
        print(f"  part 2, {n}x{n} completed: {len(runs[-1]['runs'])} run(s) in "
              f"{time.perf_counter() - t0:5.1f} s, {status}", file=sys.stderr, flush=True)
    done = [r for r in runs if r["error"] is None]
    finest = max(done, key=lambda r: r["mesh"]) if done else None
    for r in runs:
        accuracy(r, finest)
    plain = pendulum_run(PLAIN_MESH, "plain", args)
    accuracy(plain, finest)
    completed = next((r for r in runs if r["mesh"] == PLAIN_MESH), None)
    if completed is None:
        completed = pendulum_run(PLAIN_MESH, "completed", args)
        accuracy(completed, finest)
    comparison = {"mesh": PLAIN_MESH, "plain_error": plain["error"],
                  "completed_error": completed["error"],
                  "corner_max_difference": corner_distance(plain["history"],
                                                           completed["history"]),
                  "energy_max_difference": float(np.abs(
                      plain["history"]["energy"][:len(completed["history"]["energy"])]
                      - completed["history"]["energy"][:len(plain["history"]["energy"])]).max()),
                  "wall_time_plain_s": plain.get("wall_time_s"),
                  "wall_time_completed_s": completed.get("wall_time_s")}
    print(f"  part 2, {PLAIN_MESH}x{PLAIN_MESH} plain: done", file=sys.stderr, flush=True)
    for r in runs + [plain]:
        r.pop("history")
    return {"scene": str(SCENE.relative_to(REPO)), "dt": args.dt,
            "omp_max_threads": omp.get(), "finest_mesh": finest["mesh"] if finest else None,
            "runs": runs, "plain": plain, "plain_vs_completed": comparison}


# -- output --------------------------------------------------------------------------------
def fmt(x: Any, spec: str) -> str:
    return "-" if x is None else format(x, spec)


def print_elements(part: dict[str, Any], args: argparse.Namespace) -> None:
    print(f"\nThin plate element: cost per element in microseconds (call time / elements), "
          f"best of {args.rounds} round(s) x {args.repeats} samples of >= {args.min_time:g} s")
    print(f"Gauss rule: plate_rule() = {part['gauss_points']} points per element; "
          f"deformed configuration: initial + uniform(-{PERTURBATION:g}, {PERTURBATION:g}); "
          f"f2py call floor {1e6 * part['f2py_call_floor_s']:.2f} us per call")
    rows = []
    for threads in map(str, part["threads"]):
        for rec in part["records"]:
            s = rec["samples"][threads]
            p, c = s["plain"], s["completed"]
            ratio = rec["completed_over_plain"][threads]
            row = [threads, rec["mesh"], str(rec["elements"])]
            for name in KERNELS:
                if name not in p:
                    row += ["", "", "", ""]
                    continue
                row += [f"{p[name]['per_element_us']:.2f}", f"{c[name]['per_element_us']:.2f}",
                        f"{ratio[name]['best']:.3f}", f"{ratio[name]['paired_median']:.3f}"]
            tangent_share = c["force_tangent"]["per_element_us"] / c["force"]["per_element_us"]
            row.append(f"{tangent_share:.1f}")
            rows.append(row)
    head = [("thr", 3), ("mesh", 10), ("nel", 4)]
    for short in ("force", "f+K", "setup"):
        head += [(f"{short} P", 8), (f"{short} C", 8), ("C/P", 5), ("pair", 5)]
    print_table(head + [("f+K/f", 5)], rows)
    print("P = plain, C = completed, f+K = force + tangent (us per element); C/P = the price "
          "of completion,\nratio of the best times; pair = median ratio of each completed "
          "sample to the plain one just before it")
    rows = []
    for rec in part["records"]:
        ch = rec["checks"]
        rows.append([rec["mesh"], f"{ch['plain_vs_completed_force']:.1e}",
                     f"{max(ch[v]['force_vs_force_tangent'] for v in VARIANTS):.1e}",
                     f"{max(ch[v]['tangent_asymmetry'] for v in VARIANTS):.1e}",
                     f"{ch['plain']['energy_at_initial']:.3e}",
                     f"{ch['completed']['energy_at_initial']:.3e}"])
    print("\nchecks (relative differences; strain energy in J at the undeformed mesh)")
    print_table([("mesh", 10), ("|fP-fC|", 8), ("|f-f(K)|", 8), ("K asym", 8),
                 ("U0 plain", 10), ("U0 compl", 10)], rows)


def print_pendulum(part: dict[str, Any]) -> None:
    n = part["finest_mesh"]
    finest = "none completed" if n is None else f"{n}x{n}"
    print(f"\nPlate pendulum ({part['scene']}), completed element, dt = {part['dt']:g} s, "
          f"0 to 0.3 s, OpenMP threads {part['omp_max_threads']}; wall = integrate(), "
          f"best of the runs; distances to the finest mesh ({finest}) in mm")
    rows = []
    for r in part["runs"] + [part["plain"]]:
        name = f"{r['mesh']}x{r['mesh']}" + (" plain" if r["variant"] == "plain" else "")
        corner = r["corner_end"]
        rows.append([name, str(r.get("ndof", "")), fmt(r.get("wall_time_s"), ".2f"),
                     fmt(r.get("ms_per_step"), ".1f"), str(r.get("steps", "-")),
                     fmt(r.get("newton_per_step"), ".2f"),
                     "-" if corner is None else " ".join(f"{x:+.4f}" for x in corner),
                     fmt(None if r["distance_to_finest_max"] is None
                         else 1e3 * r["distance_to_finest_max"], ".2f"),
                     fmt(None if r["distance_to_finest_end"] is None
                         else 1e3 * r["distance_to_finest_end"], ".2f"),
                     fmt(r["energy_drift_relative"], ".1e")])
    print_table([("mesh", 10), ("ndof", 5), ("wall s", 7), ("ms/step", 7), ("steps", 5),
                 ("Newt/st", 7), ("corner at 0.3 s (m)", 23), ("d max", 7), ("d 0.3", 7),
                 ("E drift", 8)], rows)
    print("d max: max over the history of |corner - corner of the finest mesh|; d 0.3: at "
          "t = 0.3 s; E drift: max|E_total - E_total(0)| / max|gravity potential change|")
    for r in part["runs"] + [part["plain"]]:
        if r["error"]:
            print(f"  {r['mesh']}x{r['mesh']} {r['variant']} failed at t = {r['t_last']:g} s: "
                  f"{r['error']}")
    c = part["plain_vs_completed"]
    print(f"\n{c['mesh']}x{c['mesh']} plain vs completed: max corner difference over the "
          f"history {c['corner_max_difference']:.2e} m, max energy difference "
          f"{c['energy_max_difference']:.2e} J (flat plate: must agree to round-off)")


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="smaller meshes, fewer repeats and rounds, one thread, "
                             "pendulum meshes 2 4 8")
    parser.add_argument("--flat", type=int, nargs="+", default=None,
                        help="flat meshes of part 1, elements per side (default 8 16; "
                             "4 8 with --quick)")
    parser.add_argument("--leaf", type=int, default=None,
                        help="leaf elements along the arc in part 1, 0 for none (default "
                             f"{LEAF}; {LEAF_QUICK} with --quick)")
    parser.add_argument("--threads", type=int, nargs="+", default=None,
                        help="OpenMP threads of part 1 (default 1 2; 1 with --quick)")
    parser.add_argument("--min-time", type=float, default=0.2,
                        help="seconds one sample lasts at least (default 0.2)")
    parser.add_argument("--repeats", type=int, default=None,
                        help="samples per measurement and round (default 3; 2 with --quick)")
    parser.add_argument("--rounds", type=int, default=None,
                        help="rounds over meshes, variants and threads (default 2; 1 with "
                             "--quick)")
    parser.add_argument("--meshes", type=int, nargs="+", default=None,
                        help="pendulum meshes nx = ny (default 2 4 6 8 12; 2 4 8 with "
                             "--quick); the finest is the reference")
    parser.add_argument("--dt", type=float, default=2e-3,
                        help="pendulum time step, all meshes (default 2e-3)")
    parser.add_argument("--pendulum-repeats", type=int, default=None,
                        help="runs per pendulum mesh, fewer once they took "
                             f"{PENDULUM_BUDGET_S:g} s (default 3; 1 with --quick)")
    parser.add_argument("--output", type=Path, default=None,
                        help="JSON file (default benchmarks/results/plate_cost.json, "
                             "plate_cost_quick.json with --quick)")
    args = parser.parse_args(argv)
    q = args.quick
    if args.flat is None:
        args.flat = list(FLAT_QUICK if q else FLAT)
    if args.leaf is None:
        args.leaf = LEAF_QUICK if q else LEAF
    if args.threads is None:
        args.threads = [1] if q else [1, 2]
    if args.repeats is None:
        args.repeats = 2 if q else 3
    if args.rounds is None:
        args.rounds = 1 if q else 2
    if args.meshes is None:
        args.meshes = list(MESHES_QUICK if q else MESHES)
    if args.pendulum_repeats is None:
        args.pendulum_repeats = 1 if q else 3
    if min(args.flat + args.threads + args.meshes
           + [args.repeats, args.rounds, args.pendulum_repeats]) < 1 or args.leaf < 0:
        parser.error("mesh sizes, thread counts, repeats and rounds must be positive")
    if args.dt <= 0:
        parser.error("--dt must be positive")
    if args.output is None:
        args.output = RESULTS / ("plate_cost_quick.json" if q else "plate_cost.json")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    from ancfdrv import _kernel

    start = time.perf_counter()
    machine = machine_info()
    omp = OpenMP()
    kernel_so = Path(_kernel.__file__)
    elements = measure_elements(_kernel, omp, args)
    pendulum = measure_pendulum(args, omp)
    machine["load_average_at_end"] = load_average()
    print_elements(elements, args)
    print_pendulum(pendulum)
    report = {
        "benchmark": "plate_cost",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "settings": {"flat": args.flat, "leaf": args.leaf, "threads": args.threads,
                     "min_time_s": args.min_time, "repeats": args.repeats,
                     "rounds": args.rounds, "meshes": args.meshes, "dt": args.dt,
                     "pendulum_repeats": args.pendulum_repeats, "quick": args.quick,
                     "plate": {"side": PLATE_SIDE, "thickness": PLATE_THICKNESS},
                     "leaf_geometry": {**LEAF_GEOMETRY, "thickness": LEAF_THICKNESS},
                     "material": {"youngs": YOUNGS, "density": DENSITY, "poisson": POISSON}},
        "units": "per_call_s, wall_time_s in seconds; per_element_us in microseconds; "
                 "positions and distances in m; energies in J",
        "machine": machine,
        "openmp": {"runtime": omp.libraries, "default_max_threads": omp.default},
        "kernel_module": str(kernel_so), "kernel_mtime": kernel_so.stat().st_mtime,
        "element_cost": elements, "pendulum": pendulum,
        "wall_time_s": time.perf_counter() - start,
    }
    write_report(args.output, report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
