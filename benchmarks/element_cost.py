#!/usr/bin/env python
"""Cost per element of the beam's elastic forces in the Fortran kernel, with and without
OpenMP threads.

For straight beams of ``--elements`` elements (10, 100, 1000) in a bent and stretched
configuration this times, with ``time.perf_counter``, the f2py entry points that the
Python side calls (arrays prepared once in Fortran order, so no conversion is timed):

* ``nonlinear force``: the large-deformation internal force and strain energy alone,
  ``_kernel.beam_nonlinear_forces(..., want_tangent=0)`` (Green-Lagrange strain, St.
  Venant-Kirchhoff law, at the Gauss rule of ``_kernel.beam_nonlinear_points(nsec)``);
* ``nonlinear force + tangent``: the same with the element tangents (24 x 24 per element),
  ``want_tangent=1``;
* ``cubic force`` and ``cubic force + tangent``: the same for ``beam.bending = 'cubic'``
  (``_kernel.beam_cubic_forces``: 21 strain forms per element, docs/theory.md
  section 12);
* ``FFR force``: the floating-frame elastic force T K0 (T^T e - e0),
  ``_kernel.ffr_elastic_force``;
* ``FFR stiffness``: the element matrices T K0 T^T, ``_kernel.ffr_element_stiffness`` (what
  the FFR model uses where the large-deformation model needs its tangent);
* ``system ... force`` and ``system ... force + tangent`` for each of the three (nonlinear,
  cubic, FFR): the same beam as a one-body model of the general-system layer, evaluated
  through its kernel handle (``model.kernel.evaluate``, ``_kernel.system_evaluate``): the
  element loop the solvers and the stepper actually run, with the assembly of the force
  vector and, with the tangent, of the matrix on the model's sparse pattern;
* the floor of an f2py call, ``_kernel.beam_nonlinear_points(4)``, which every per-call
  time above includes once (it matters at 10 elements only).

Cost per element = call time / elements. A sample is a loop of calls lasting at least
``--min-time`` (0.2 s); the time is the best of all samples: ``--repeats`` samples (3; 2
with ``--quick``) in each of ``--rounds`` rounds (2), where a round runs every thread
count once, so slow phases of the machine (this VM's timings drift by 20-40 % over
seconds) hit all thread counts alike. Minor page faults per call are recorded too: the
f2py wrapper allocates the (24, 24, nel) tangent output on every call, also when no
tangent is asked for, and the kernel zeroes it.

The large-deformation rule has volume points (axial x section) plus neutral-axis points
that carry the Poisson part of the law (splitting against Poisson locking); with
``poisson = 0`` the kernel skips the neutral-axis points, so both ``--poisson`` 0 (as in
``inputs/hard/*.nml``) and 0.3 are measured and the cost per active Gauss point is given.

OpenMP: the kernel may be built with OpenMP, whose runtime reads ``OMP_NUM_THREADS`` when
the module is loaded. Each thread count of ``--threads`` (1 2) therefore runs the whole
measurement in a fresh subprocess with that ``OMP_NUM_THREADS``; the subprocess also
reports whether an OpenMP runtime (libgomp, libomp, libiomp) is mapped into the process
after ``import ancfdrv._kernel``. Without one, the thread counts must agree within the
timing noise, and the table says so.

Ported to the general-system model layer: the element arrays (material gradients and
weights, strain forms, K0 and the frame reference) come from the element sets of a
``System`` with one beam along x (``model.sets[0]``), the standalone entry points take the
new argument lists (``beam_nonlinear_forces`` the number of volume points first,
``ffr_elastic_force`` the reference before the rotation), and the ``system_*`` kernels are
new. The JSON keeps its layout; the new kernels appear beside the old ones in
``records[].kernels`` and in the speed-ups.

Results: tables on stdout and JSON in ``benchmarks/results/element_cost.json``
(``element_cost_quick.json`` with ``--quick``). Run from the repository root::

    python benchmarks/element_cost.py            # 10, 100, 1000 elements, about 2 min
    python benchmarks/element_cost.py --quick    # 1 round, 0.05 s samples, nu = 0, ~20 s
"""
from __future__ import annotations

import argparse
import datetime as _dt
import gc
import json
import math
import os
import resource
import subprocess
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
ELEMENTS = (10, 100, 1000)
THREADS = (1, 2)
#: Section and material of the measured beam (values do not change the cost; a square
#: section and steel-like numbers keep the configuration well conditioned).
LENGTH, WIDTH, HEIGHT = 10.0, 0.1, 0.1
YOUNGS, DENSITY = 2.1e11, 7850.0
OPENMP_RUNTIMES = ("libgomp", "libomp", "libiomp")
#: Another engineer reinstalls ancfdrv from time to time: how long to wait before retrying.
ELEMENT_KERNELS = ("nonlinear_force", "nonlinear_force_tangent", "cubic_force",
                   "cubic_force_tangent", "ffr_force", "ffr_stiffness")
SYSTEM_KERNELS = ("system_nonlinear_force", "system_nonlinear_force_tangent",
                  "system_cubic_force", "system_cubic_force_tangent", "system_ffr_force",
                  "system_ffr_force_tangent")
KERNELS = ELEMENT_KERNELS + SYSTEM_KERNELS
LABELS = {"nonlinear_force": "(a) force", "nonlinear_force_tangent": "(b) force+tangent",
          "cubic_force": "cubic force", "cubic_force_tangent": "cubic force+tan",
          "ffr_force": "(c) FFR force", "ffr_stiffness": "FFR K",
          "system_nonlinear_force": "sys force", "system_nonlinear_force_tangent": "sys f+tangent",
          "system_cubic_force": "sys cubic f", "system_cubic_force_tangent": "sys cubic f+K",
          "system_ffr_force": "sys FFR f", "system_ffr_force_tangent": "sys FFR f+K"}
#: the section rule's points (a rectangle: 2 x 2), the argument of beam_nonlinear_points
SECTION_POINTS = 4


# -- worker: runs inside a subprocess with OMP_NUM_THREADS set ----------------------------
@dataclass
class Sample:
    """Best-of-N time of one kernel call and what the best sample saw."""

    per_call_s: float
    median_per_call_s: float
    calls_per_sample: int
    samples: int
    minor_faults_per_call: float


def import_kernel() -> Any:
    """The compiled kernel (checked to be the build with the large-deformation beam)."""
    from ancfdrv import _kernel
    _kernel.beam_nonlinear_points(SECTION_POINTS)
    return _kernel


def openmp_runtime() -> list[str]:
    """OpenMP runtime libraries mapped into this process (Linux: /proc/self/maps)."""
    try:
        maps = Path("/proc/self/maps").read_text()
    except OSError:
        return []
    found = {line.split()[-1] for line in maps.splitlines()
             if any(name in line for name in OPENMP_RUNTIMES)}
    return sorted(found)


def omp_max_threads(libraries: list[str]) -> int | None:
    """omp_get_max_threads() of the mapped runtime, None when there is none."""
    if not libraries:
        return None
    import ctypes
    try:
        return int(ctypes.CDLL(libraries[0]).omp_get_max_threads())
    except (OSError, AttributeError):
        return None


def time_call(call: Callable[[], object], min_time: float, repeats: int) -> Sample:
    """Best of ``repeats`` samples; a sample is as many calls as take ``min_time`` (the
    count is calibrated on a first, untimed sample)."""
    call()  # warm-up: first-touch of outputs, lazy set-up
    calls, spent = 0, 0.0
    t0 = time.perf_counter()
    while spent < min(0.05, min_time):
        call()
        calls += 1
        spent = time.perf_counter() - t0
    calls = max(1, math.ceil(calls * min_time / spent))
    per_call, faults = [], []
    gc.collect()
    gc.disable()
    try:
        for _ in range(repeats):
            r0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
            t0 = time.perf_counter()
            for _ in range(calls):
                call()
            elapsed = time.perf_counter() - t0
            r1 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
            per_call.append(elapsed / calls)
            faults.append((r1 - r0) / calls)
    finally:
        gc.enable()
    best = int(np.argmin(per_call))
    return Sample(per_call[best], float(np.median(per_call)), calls, repeats, faults[best])


def beam_model(nel: int, poisson: float, formulation: str, bending: str) -> Any:
    """A one-beam model of the general-system layer: straight along x, section height along
    y, no supports and no loads (only its element set and kernel handle are used)."""
    from ancfdrv import Rectangle, System

    system = System(f"element cost {formulation} {bending}", effects=())
    steel = system.material("steel", youngs_modulus=YOUNGS, density=DENSITY,
                            poisson_ratio=poisson)
    system.beam("beam", material=steel, start=(0.0, 0.0, 0.0), end=(LENGTH, 0.0, 0.0),
                nodes=nel + 1, section=Rectangle(WIDTH, HEIGHT), height_axis=(0.0, 1.0, 0.0),
                formulation=formulation, bending=bending)
    return system.assemble(effects=())


def beam_arrays(kernel: Any, nel: int, poisson: float) -> dict[str, Any]:
    """Kernel-ready arrays of a straight beam along x (the reference) and a deformed
    configuration: bent into an arc of 90 degrees, stretched by 1 %, sections sheared a
    little, so every strain and stress component is non-zero; with the three one-beam
    models (close them with ``model.close()``)."""
    models = {"nonlinear": beam_model(nel, poisson, "nonlinear", "continuum"),
              "cubic": beam_model(nel, poisson, "nonlinear", "cubic"),
              "ffr": beam_model(nel, poisson, "ffr", "continuum")}
    continuum, cubic, ffr = (models[k].sets[0] for k in ("nonlinear", "cubic", "ffr"))
    s = continuum.body.stations
    radius = LENGTH / (0.5 * math.pi)
    angle = s / radius
    e = np.zeros((nel + 1, 12))
    e[:, 0] = 1.01 * radius * np.sin(angle)
    e[:, 1] = 1.01 * radius * (1.0 - np.cos(angle))
    e[:, 3:6] = 1.01 * np.column_stack([np.cos(angle), np.sin(angle), 0.0 * s])
    e[:, 6:9] = np.column_stack([-np.sin(angle) + 0.01, np.cos(angle), 0.0 * s])
    e[:, 9:12] = [0.0, 0.0, 1.0]
    return {"npts": int(continuum.weights.shape[0]), "nvolume": continuum.nvolume,
            "ndof": models["nonlinear"].ndof, "cubic": cubic.cubic.tables(), "models": models,
            "dofs": np.asfortranarray(continuum.dofs + 1, dtype=np.int32),
            "e": np.asfortranarray(e.ravel()), "reference": ffr.reference,
            "gradients": continuum.gradients, "weights": continuum.weights,
            "stiffness0": ffr.stiffness0, "rotation": np.asfortranarray(np.eye(3)),
            "shear_scales": np.asarray(continuum.shear_scales, dtype=float),
            "youngs": YOUNGS, "poisson": poisson}


def system_call(model: Any, e: np.ndarray, want_tangent: bool) -> Callable[[], Any]:
    """One force (+ tangent) evaluation of a model through its kernel handle, as the
    solvers call it (``KernelSystem.evaluate``)."""
    v = np.zeros(model.ndof)
    guesses, counts = model.contact_guesses, model.contact_counts
    return lambda: model.kernel.evaluate(0.0, e, v, guesses, counts, want_tangent=want_tangent)


def measure_mesh(kernel: Any, nel: int, poisson: float, min_time: float,
                 repeats: int) -> dict[str, Any]:
    """All kernels at one mesh and Poisson ratio."""
    a = beam_arrays(kernel, nel, poisson)

    def nonlinear(want_tangent: int) -> Callable[[], Any]:
        return lambda: kernel.beam_nonlinear_forces(a["nvolume"], a["dofs"], a["e"],
                                                    a["gradients"], a["weights"], a["youngs"],
                                                    a["poisson"], a["shear_scales"], want_tangent)

    calls: dict[str, Callable[[], Any]] = {
        "nonlinear_force": nonlinear(0),
        "nonlinear_force_tangent": nonlinear(1),
        "cubic_force": lambda: kernel.beam_cubic_forces(
            a["dofs"], a["e"], *a["cubic"], 0),
        "cubic_force_tangent": lambda: kernel.beam_cubic_forces(
            a["dofs"], a["e"], *a["cubic"], 1),
        "ffr_force": lambda: kernel.ffr_elastic_force(a["dofs"], a["stiffness0"],
                                                      a["reference"], a["rotation"], a["e"]),
        "ffr_stiffness": lambda: kernel.ffr_element_stiffness(a["stiffness0"], a["rotation"]),
    }
    for name, model in a["models"].items():
        calls[f"system_{name}_force"] = system_call(model, a["e"], False)
        calls[f"system_{name}_force_tangent"] = system_call(model, a["e"], True)
    # sanity: the force of the deformed beam is finite and non-zero, the tangent symmetric
    force, _, tangent = calls["nonlinear_force_tangent"]()
    force_only, _, _ = calls["nonlinear_force"]()
    if not (np.all(np.isfinite(force)) and np.abs(force).max() > 0
            and np.allclose(force, force_only, rtol=1e-12, atol=0.0)):
        raise RuntimeError(f"kernel force check failed at {nel} elements")
    asym = np.abs(tangent - tangent.transpose(1, 0, 2)).max() / np.abs(tangent).max()
    # the system's internal force of the large-deformation beam is the element force
    system_force = calls["system_nonlinear_force"]()["internal"]
    system_difference = float(np.abs(system_force - force).max() / np.abs(force).max())
    if system_difference > 1e-12:
        raise RuntimeError(f"system and element force differ by {system_difference:.2e} "
                           f"at {nel} elements")
    record: dict[str, Any] = {"elements": nel, "poisson": poisson, "ndof": a["ndof"],
                              "tangent_asymmetry": float(asym),
                              "system_vs_element_force": system_difference, "kernels": {}}
    try:
        for name, call in calls.items():
            sample = time_call(call, min_time, repeats)
            record["kernels"][name] = {**asdict(sample), "per_element_us":
                                       1e6 * sample.per_call_s / nel}
    finally:
        for model in a["models"].values():
            model.close()
    return record


def worker(args: argparse.Namespace) -> dict[str, Any]:
    """The whole measurement in this process (its OMP_NUM_THREADS is fixed already)."""
    kernel = import_kernel()
    libraries = openmp_runtime()
    so_path = Path(kernel.__file__)
    floor = time_call(lambda: kernel.beam_nonlinear_points(SECTION_POINTS), args.min_time,
                      args.repeats)
    records = [measure_mesh(kernel, nel, nu, args.min_time, args.repeats)
               for nu in args.poisson for nel in args.elements]
    return {"omp_num_threads_env": os.environ.get("OMP_NUM_THREADS"),
            "openmp_runtime": libraries, "omp_get_max_threads": omp_max_threads(libraries),
            "kernel_module": str(so_path), "kernel_mtime": so_path.stat().st_mtime,
            "gauss_points": int(kernel.beam_nonlinear_points(SECTION_POINTS)),
            "f2py_call_floor_s": floor.per_call_s, "records": records}


# -- parent: one subprocess per thread count ----------------------------------------------
def run_worker(threads: int, args: argparse.Namespace) -> dict[str, Any]:
    """Run the measurement in a subprocess with OMP_NUM_THREADS = threads (retried once
    after a pause when it fails, e.g. during a reinstall of ancfdrv)."""
    env = {**os.environ, "OMP_NUM_THREADS": str(threads)}
    command = [sys.executable, str(Path(__file__).resolve()), "--worker",
               "--elements", *map(str, args.elements), "--poisson", *map(str, args.poisson),
               "--min-time", str(args.min_time), "--repeats", str(args.repeats)]
    done = subprocess.run(command, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"the measurement with OMP_NUM_THREADS={threads} failed:\n"
                           f"{done.stderr[-2000:]}")
    return json.loads(done.stdout)


def merge_rounds(rounds: list[dict[str, Any]]) -> dict[str, Any]:
    """One worker result from several rounds of the same thread count: per kernel and
    mesh the fastest sample, with the samples of all rounds counted."""
    merged = json.loads(json.dumps(rounds[0]))
    merged["f2py_call_floor_s"] = min(r["f2py_call_floor_s"] for r in rounds)
    merged["kernel_mtimes"] = sorted({r["kernel_mtime"] for r in rounds})
    for i, record in enumerate(merged["records"]):
        for name in record["kernels"]:
            samples = [r["records"][i]["kernels"][name] for r in rounds]
            best = dict(min(samples, key=lambda x: x["per_call_s"]))
            best["samples"] = sum(x["samples"] for x in samples)
            best["median_per_call_s"] = float(np.median([x["median_per_call_s"]
                                                         for x in samples]))
            best["rounds_per_element_us"] = [x["per_element_us"] for x in samples]
            record["kernels"][name] = best
    return merged


def active_points(record: dict[str, Any], gauss_points: int, axis_points: int) -> int:
    """Gauss points the kernel evaluates: the neutral-axis points only when nu > 0."""
    return gauss_points if record["poisson"] > 0 else gauss_points - axis_points


def summarize(runs: dict[int, dict[str, Any]]) -> dict[str, Any]:
    """Speed-up of the threaded runs over one thread, per kernel and mesh, and whether the
    kernel has OpenMP at all."""
    base = runs[min(runs)]
    openmp = {t: bool(r["openmp_runtime"]) for t, r in runs.items()}
    speedups = []
    for threads, run in sorted(runs.items()):
        if threads == min(runs):
            continue
        for rec, rec1 in zip(run["records"], base["records"]):
            speedups.append({"threads": threads, "elements": rec["elements"],
                             "poisson": rec["poisson"],
                             **{k: rec1["kernels"][k]["per_call_s"] / rec["kernels"][k]["per_call_s"]
                                for k in KERNELS}})
    mtimes = {m for r in runs.values() for m in r["kernel_mtimes"]}
    return {"openmp_linked": openmp, "speedup_over_1_thread": speedups,
            "kernel_reinstalled_during_run": len(mtimes) > 1}


def axis_point_count(gauss_points: int) -> int:
    """Neutral-axis points of the rule: n_axial, with gauss_points = n_axial (n_s^2 + 1)
    and a 2 x 2 section rule (beam_nonlinear.f90)."""
    return gauss_points // 5


def print_tables(runs: dict[int, dict[str, Any]], summary: dict[str, Any],
                 args: argparse.Namespace) -> None:
    from _common import print_table

    any_run = next(iter(runs.values()))
    npts = any_run["gauss_points"]
    axis = axis_point_count(npts)
    print(f"\nElastic forces of the ANCF beam: cost per element in microseconds (call time / "
          f"elements), best of {args.rounds} rounds x {args.repeats} samples of "
          f">= {args.min_time:g} s")
    print(f"Gauss rule: beam_nonlinear_points() = {npts} per element ({npts - axis} volume + "
          f"{axis} neutral-axis points; with nu = 0 the axis points are skipped)")
    for threads, run in sorted(runs.items()):
        libs = ", ".join(Path(p).name for p in run["openmp_runtime"]) or "none"
        print(f"\n[OMP_NUM_THREADS={threads}] OpenMP runtime loaded: {libs}"
              + (f" (omp_get_max_threads = {run['omp_get_max_threads']})"
                 if run["omp_get_max_threads"] is not None else "")
              + f"; f2py call floor {1e6 * run['f2py_call_floor_s']:.2f} us per call")
        rows = []
        for rec in run["records"]:
            k = rec["kernels"]
            pts = active_points(rec, npts, axis)
            rows.append([str(rec["elements"]), f"{rec['poisson']:g}", str(pts)]
                        + [f"{k[name]['per_element_us']:.3f}" for name in ELEMENT_KERNELS]
                        + [f"{1e3 * k['nonlinear_force']['per_element_us'] / pts:.0f}",
                           f"{1e3 * k['nonlinear_force_tangent']['per_element_us'] / pts:.0f}",
                           f"{k['nonlinear_force_tangent']['per_element_us'] / k['nonlinear_force']['per_element_us']:.1f}",
                           f"{k['nonlinear_force']['per_element_us'] / k['ffr_force']['per_element_us']:.0f}",
                           f"{k['nonlinear_force']['minor_faults_per_call']:.0f}"])
        print_table([("nel", 5), ("nu", 4), ("pts", 4)]
                    + [(LABELS[n], 17) for n in ELEMENT_KERNELS]
                    + [("ns/pt a", 8), ("ns/pt b", 8), ("b/a", 5), ("a/FFR", 6),
                       ("flt/call", 8)], rows)
        print("  through the model's kernel handle (system_evaluate: element loop + assembly "
              "on the pattern), us per element, and / the element entry point's time")
        pairs = {"system_nonlinear_force": "nonlinear_force",
                 "system_nonlinear_force_tangent": "nonlinear_force_tangent",
                 "system_cubic_force": "cubic_force",
                 "system_cubic_force_tangent": "cubic_force_tangent",
                 "system_ffr_force": "ffr_force", "system_ffr_force_tangent": "ffr_stiffness"}
        rows = []
        for rec in run["records"]:
            k = rec["kernels"]
            cells = []
            for name, ref in pairs.items():
                ratio = k[name]["per_call_s"] / k[ref]["per_call_s"]
                cells.append(f"{k[name]['per_element_us']:.3f} ({ratio:.2f})")
            rows.append([str(rec["elements"]), f"{rec['poisson']:g}"] + cells)
        print_table([("nel", 5), ("nu", 4)] + [(LABELS[n], 17) for n in SYSTEM_KERNELS], rows)
    if summary["speedup_over_1_thread"]:
        print("\nspeed-up over OMP_NUM_THREADS=1 (time with 1 thread / time with n threads)")
        rows = [[str(s["threads"]), str(s["elements"]), f"{s['poisson']:g}"]
                + [f"{s[k]:.2f}" for k in KERNELS] for s in summary["speedup_over_1_thread"]]
        print_table([("threads", 7), ("nel", 5), ("nu", 4)]
                    + [(LABELS[n], 17) for n in KERNELS], rows)
    if not any(summary["openmp_linked"].values()):
        print("\nThe kernel is not built with OpenMP (no OpenMP runtime in the process): "
              "OMP_NUM_THREADS has no effect, the thread counts differ by timing noise only.")
    if summary["kernel_reinstalled_during_run"]:
        print("\nWARNING: the kernel module changed between the subprocesses (a reinstall "
              "happened): the thread counts may have measured different builds.")


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="1 round of 2 repeats of 0.05 s samples, nu = 0 only")
    parser.add_argument("--elements", type=int, nargs="+", default=list(ELEMENTS),
                        help=f"element counts (default {' '.join(map(str, ELEMENTS))})")
    parser.add_argument("--poisson", type=float, nargs="+", default=None,
                        help="Poisson ratios (default 0 0.3; 0 with --quick)")
    parser.add_argument("--threads", type=int, nargs="+", default=list(THREADS),
                        help="OMP_NUM_THREADS of the subprocesses (default 1 2)")
    parser.add_argument("--min-time", type=float, default=None,
                        help="seconds one sample lasts at least (default 0.2; 0.05 with "
                             "--quick)")
    parser.add_argument("--repeats", type=int, default=None,
                        help="samples per measurement and round (default 3; 2 with --quick)")
    parser.add_argument("--rounds", type=int, default=None,
                        help="rounds over all thread counts (default 2; 1 with --quick)")
    parser.add_argument("--output", type=Path, default=None,
                        help="JSON file (default benchmarks/results/element_cost.json, "
                             "element_cost_quick.json with --quick)")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.poisson is None:
        args.poisson = [0.0] if args.quick else [0.0, 0.3]
    if args.repeats is None:
        args.repeats = 2 if args.quick else 3
    if args.rounds is None:
        args.rounds = 1 if args.quick else 2
    if args.min_time is None:
        args.min_time = 0.05 if args.quick else 0.2
    if min(args.elements + args.threads + [args.rounds, args.repeats]) < 1:
        parser.error("element and thread counts must be positive")
    if args.output is None:
        args.output = RESULTS / ("element_cost_quick.json" if args.quick else "element_cost.json")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if args.worker:
        json.dump(worker(args), sys.stdout)
        return 0
    from _common import load_average, machine_info, write_report

    start = time.perf_counter()
    machine = machine_info()
    rounds: dict[int, list[dict[str, Any]]] = {t: [] for t in args.threads}
    for round_ in range(args.rounds):
        for threads in args.threads:
            t0 = time.perf_counter()
            rounds[threads].append(run_worker(threads, args))
            print(f"  round {round_ + 1}: OMP_NUM_THREADS={threads} measured in "
                  f"{time.perf_counter() - t0:5.1f} s", file=sys.stderr, flush=True)
    runs = {t: merge_rounds(r) for t, r in rounds.items()}
    machine["load_average_at_end"] = load_average()
    summary = summarize(runs)
    print_tables(runs, summary, args)
    report = {
        "benchmark": "element_cost",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "settings": {"elements": args.elements, "poisson": args.poisson,
                     "threads": args.threads, "min_time_s": args.min_time,
                     "repeats": args.repeats, "rounds": args.rounds, "quick": args.quick,
                     "beam": {"length": LENGTH, "width": WIDTH, "height": HEIGHT,
                              "youngs": YOUNGS}},
        "units": "per_call_s in seconds, per_element_us in microseconds",
        "machine": machine, "summary": summary,
        "runs": {str(t): r for t, r in runs.items()},
        "wall_time_s": time.perf_counter() - start,
    }
    write_report(args.output, report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
