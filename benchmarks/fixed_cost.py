#!/usr/bin/env python
"""The fixed cost of one run outside the kernel's stepping (issue 23 item 4, "lean output"):
whole ``ancfdrv.runner.run_scene`` calls of the flexible pendulum (cable, planar, 5 and 17
nodes, dt = 1 ms, 1 s) and of the luffing boom (nonlinear cable, planar, 4 and 7 nodes,
10 s, 10000 rows, no XDMF), split into their phases.

Per case: the whole call's wall time (best of ``--repeats``), and per phase the median
thread CPU time (``time.thread_time``: what this thread computed, not what other processes
took from it, so the split stays meaningful on a loaded machine): scene load, model build,
result file creation, static solve and its output, the dynamic writer's set-up, the
answers recorder per chunk, the kernel's stepping (``advance_rows``), the final flush, the
dynamic answers and attributes, finish, the output lock. "non-stepping" is the whole
call's thread CPU time minus the stepping's.

``--compare PATH``: run the same cases with another copy of the package (a directory
holding ``ancfdrv/``, e.g. ``git archive <commit> python/ancfdrv`` unpacked, with the
built ``_kernel*.so`` copied in) in a subprocess, interleaved case by case, so both are
measured under the same load (the subprocess runs without the site hook, ``-S``, this
interpreter's site-packages behind the copy on PYTHONPATH: an editable install's finder
would load this worktree's package before anything on PYTHONPATH).

``--instructions``: also count, with valgrind's callgrind (exact and independent of the
machine's load), the instructions of ``INSTRUCTION_CALLS`` whole calls of each case after
two warm-up calls (collection switched on and off around them by callgrind's client
request, from a tiny C helper compiled with the system's ``cc``): per call the total, the
kernel's stepping (``system_advance_``, inclusive) and the rest ("non-stepping"); needs
valgrind and its headers. A call here is what ``benchmarks/peer_exudyn.py`` times: the
run, then the tip history read back. ``FLUSH_SECONDS`` is raised in the counted process (a
run lasts ~50 times longer under valgrind and would flush by the clock where a quiet
machine's run ends before its first flush deadline), and the stepper's clock there
advances 1 us per reading (it sizes the kernel calls by their elapsed time: the chunks of
a quiet machine, the same in every count). Caveat: callgrind counts every iteration of a
``rep stos`` as an instruction, so large ``memset``s (HDF5 zeroes its caches) weigh more
than their time.

``--phases``: per case (the four above, ``PHASE_CASES``: the pendulum's 9 nodes, the
hard spin-up, a general scene, and ``MEMORY_CASES``: the boom's whole in-memory call at the
peer harness's 3 % level, ``ancfdrv.simulate`` as the harness times it) the instructions of one whole call (after a warm-up call)
split by phase: callgrind dumps at the entries and exits of the ``PHASES`` functions
(scene load, model build and its parts, lock and path checks, answers, initial
acceleration, dynamic set-up, static solves, HDF5, the kernel's stepping), each interval
counted to the innermost phase running, the rest "glue"; and the best wall time of
``--repeats`` whole calls (``--one``). ``--cases a,b`` selects cases; ``--compare`` as
above; ``--fine`` also counts the phases' parts apart (``FINE_PHASES``: the namelist text,
the joint equations, the reactions' gradient rows, the cables' tension, ...). Output
``benchmarks/results/fixed_cost_phases.json``.

Output: ``benchmarks/results/fixed_cost.json`` (``--quick``: ``fixed_cost_quick.json``,
ignored by git). Run from the repository root::

    python benchmarks/fixed_cost.py                   # ~1 minute
    python benchmarks/fixed_cost.py --compare /tmp/old --repeats 20
    python benchmarks/fixed_cost.py --phases --compare /tmp/old   # ~15 minutes
"""
from __future__ import annotations

import argparse
import functools
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

REPO = Path(__file__).resolve().parents[1]
CASES: dict[str, tuple[str, list[str]]] = {
    "pendulum_cable_5": ("inputs/hard/pendulum.nml", [
        "beam.nodes=5", "solver.dt=1e-3", "beam.bending=cable", "scene.planar=xy"]),
    "pendulum_cable_17": ("inputs/hard/pendulum.nml", [
        "beam.nodes=17", "solver.dt=1e-3", "beam.bending=cable", "scene.planar=xy"]),
    "boom_cable_4": ("inputs/boom_luffing.nml", [
        "scene.formulation=nonlinear", "solver.static_method=newton", "output.xdmf=.false.",
        "beam.bending=cable", "beam.nodes=4", "scene.planar=xy"]),
    "boom_cable_7": ("inputs/boom_luffing.nml", [
        "scene.formulation=nonlinear", "solver.static_method=newton", "output.xdmf=.false.",
        "beam.bending=cable", "beam.nodes=7", "scene.planar=xy"]),
}
#: further cases of ``--phases`` (with the ones above): the pendulum's middle mesh, the
#: hard spin-up (2 s of its 20) and a general scene (the cardan shaft, 0.2 s)
PHASE_CASES: dict[str, tuple[str, list[str]]] = {
    "pendulum_cable_9": ("inputs/hard/pendulum.nml", [
        "beam.nodes=9", "solver.dt=1e-3", "beam.bending=cable", "scene.planar=xy"]),
    "spinup_2s": ("inputs/hard/spinup.nml", ["solver.t_end=2.0", "output.xdmf=.false."]),
    "general_cardan_shaft": ("inputs/general/cardan_shaft.nml", [
        "solver.t_end=0.2", "output.xdmf=.false."]),
}
#: whole calls kept in memory (``ancfdrv.simulate``, no file: as ``peer_harness.py``'s boom
#: levels time them, like Exudyn's run with no solution file), then the tip history read from
#: the ``Simulation``: the boom and the flexible pendulum at the harness's 3 % level (issue
#: 38, "a model build and output path whose fixed cost is at most Exudyn's"); ``--phases
#: --cases boom_memory_3pct,pendulum_memory_3pct``
MEMORY_CASES: dict[str, tuple[str, list[str]]] = {
    "boom_memory_3pct": ("inputs/boom_luffing.nml", [
        "scene.formulation=nonlinear", "solver.static_method=newton", "output.xdmf=.false.",
        "beam.bending=cable", "scene.planar=xy", "beam.nodes=4", "solver.dt=0.02"]),
    "pendulum_memory_3pct": ("inputs/hard/pendulum.nml", [
        "beam.nodes=5", "solver.dt=0.01", "solver.t_end=1.0", "beam.bending=cable",
        "scene.planar=xy"]),
}
QUICK = {"pendulum_cable_5": CASES["pendulum_cable_5"]}
#: the whole calls counted per case by ``--instructions`` (after two warm-up calls)
INSTRUCTION_CALLS = 2
_TOGGLE_C = ("#include <valgrind/callgrind.h>\n"
             "void callgrind_toggle(void) { CALLGRIND_TOGGLE_COLLECT; }\n"
             "void callgrind_dump(const char *label) { CALLGRIND_DUMP_STATS_AT(label); }\n")
#: ``--phases``: the functions whose instructions are counted apart (module, owner, name,
#: phase); the instructions between two of their entries and exits go to the innermost
#: phase running, "glue" outside all (the runner, the stepper's Python side, checks)
PHASES = (
    ("ancfdrv.runner", None, "load_scene", "scene"),
    ("ancfdrv.simulation", None, "load_scene", "scene"),
    ("ancfdrv.runner", None, "build_model", "model"),
    ("ancfdrv.builders", None, "build_system", "model: build_system"),
    ("ancfdrv.system.system", "System", "assemble", "model: assemble"),
    ("ancfdrv.system.model", "Model", "build_kernel", "model: build_kernel"),
    ("ancfdrv.runner", None, "check_output_path", "lock and path checks"),
    ("ancfdrv.runner", "OutputLock", "__enter__", "lock and path checks"),
    ("ancfdrv.runner", "OutputLock", "__exit__", "lock and path checks"),
    ("ancfdrv.runner", None, "solve_static_path", "static solve"),
    ("ancfdrv.runner", None, "solve_newton", "static solve"),
    ("ancfdrv.solvers.path", None, "stability_index", "static stability"),
    ("ancfdrv.runner", None, "_check_dynamic_plausibility", "plausibility"),
    ("ancfdrv.results.plausibility", None, "check_static", "plausibility"),
    ("ancfdrv.runner", None, "_answers_recorder", "answers"),
    ("ancfdrv.system.answers", None, "static_answers", "answers"),
    ("ancfdrv.system.answers", "DynamicAnswers", "__call__", "answers"),
    ("ancfdrv.system.answers", "DynamicAnswers", "complete", "answers"),
    ("ancfdrv.solvers.dynamic", None, "initial_acceleration", "initial acceleration"),
    ("ancfdrv.solvers.dynamic", "TimeIntegrator", "__init__", "dynamic set-up"),
    ("ancfdrv.solvers.dynamic", "TimeIntegrator", "state", "dynamic set-up"),
    ("ancfdrv.solvers.dynamic", None, "initial_row", "dynamic set-up"),
    ("ancfdrv.results.hdf5", None, "create", "HDF5"),
    ("ancfdrv.results.hdf5", None, "write_static", "HDF5"),
    ("ancfdrv.results.hdf5", None, "write_static_answers", "HDF5 (with the static answers)"),
    ("ancfdrv.results.hdf5", None, "write_support_deflections", "HDF5"),
    ("ancfdrv.results.hdf5", None, "write_dynamic_attrs", "HDF5"),
    ("ancfdrv.results.hdf5", None, "write_dynamic_answers", "HDF5"),
    ("ancfdrv.results.hdf5", None, "finish", "HDF5"),
    ("ancfdrv.results.hdf5", None, "drop", "HDF5"),
    ("ancfdrv.results.hdf5", None, "reading", "HDF5"),
    ("ancfdrv.results.hdf5", "DynamicWriter", "__init__", "HDF5"),
    ("ancfdrv.results.hdf5", "DynamicWriter", "__call__", "HDF5"),
    ("ancfdrv.results.hdf5", "DynamicWriter", "flush", "HDF5"),
    ("ancfdrv.results.hdf5", "DynamicWriter", "flush_last", "HDF5"),
)
#: ``MEMORY_CASES``: the in-memory output's calls (what the file's HDF5 calls are to a file)
MEMORY_PHASES = tuple(("ancfdrv.results.memory", "MemoryOutput", name, "output (memory)")
                      for name in ("create", "write_static", "write_static_answers",
                                   "write_support_deflections", "write_dynamic_answers",
                                   "write_dynamic_attrs", "finish", "DynamicWriter")) + tuple(
    ("ancfdrv.results.memory", "MemoryWriter", name, "output (memory)")
    for name in ("__call__", "flush", "flush_last")) + (
    ("ancfdrv.simulation", "Simulation", "__init__", "output (memory)"),
    ("ancfdrv.simulation", "Simulation", "probe", "output (memory)"))
#: context managers of the HDF5 layer (their entries and exits are HDF5's)
PHASE_CONTEXTS = (("ancfdrv.results.hdf5", "holding"), ("ancfdrv.results.hdf5", "released"))
#: ``--phases --fine``: the parts of the phases above, each counted apart (the instructions
#: go to the innermost part running; the phases' sums "non-stepping" and "outside HDF5, the
#: stepping and static solves" are the same): where a small call's fixed cost sits
FINE_PHASES = (
    ("ancfdrv.io.scene", None, "fast_reads", "scene: namelist text"),
    ("ancfdrv.io.scene", None, "_typed", "scene: typed values"),
    ("ancfdrv.io.scene", None, "_apply_override", "scene: overrides"),
    ("ancfdrv.io.validate", None, "available_memory", "scene and model: available memory"),
    ("ancfdrv.system.system", "System", "check_bounds", "model: check bounds"),
    ("ancfdrv.system.assembly", None, "_element_sets", "model: element sets"),
    ("ancfdrv.system.patterns", "Pattern", "from_blocks", "model: pattern"),
    ("ancfdrv.system.assembly", None, "_mass", "model: mass"),
    ("ancfdrv.system.assembly", None, "_planar", "model: planar"),
    ("ancfdrv.system.assembly", None, "_equations", "model: joint equations"),
    ("ancfdrv.system.assembly", None, "_linear_joints", "model: linear joints"),
    ("ancfdrv.system.assembly", None, "_constraint_set", "model: constraint set"),
    ("ancfdrv.system.assembly", None, "_probes", "model: probes"),
    ("ancfdrv.solvers.path", None, "_reduced_tangent", "static stability: reduced tangent"),
    ("ancfdrv.system.model", "Model", "stiffness_triplets", "static stability: K triplets"),
    ("ancfdrv.system.answers", "ReactionMap", "__init__", "answers: reaction map"),
    ("ancfdrv.system.answers", "ReactionMap", "_term_arrays", "answers: term arrays"),
    ("ancfdrv.system.answers", "ReactionMap", "_gradient_rows", "answers: gradient rows"),
    ("ancfdrv.system.answers", None, "_reduce_components", "answers: force and moment"),
    ("ancfdrv.system.answers", "DynamicAnswers", "_record_tension", "answers: cable tension"),
    ("ancfdrv.system.answers", None, "static_section_forces", "answers: static sections"),
    ("ancfdrv.runner", None, "integrate", "dynamic: integrate (Python)"),
    ("ancfdrv.solvers.dynamic", "EnergyWatch", "measure", "dynamic: energy watch"),
    ("ancfdrv.results.memory", "MemoryWriter", "series_parts", "output (memory): series"),
    ("ancfdrv.runner", None, "stage_summary", "stage summary"),
)


def _compare_path(path: str) -> str:
    """PYTHONPATH of a child running ``--compare``'s copy: the copy, then this
    interpreter's site-packages (numpy, h5py; the child runs without the site hook:
    :func:`_python`)."""
    import site
    return os.pathsep.join([str(Path(path).resolve()), *site.getsitepackages()])


def _python() -> list[str]:
    """A child's interpreter: with ``--compare``'s copy on PYTHONPATH (FIXED_COST_COMPARE
    set), without the site hook (-S), since an editable install's finder would load this
    worktree's package before anything on PYTHONPATH."""
    return [sys.executable, "-S"] if os.environ.get("FIXED_COST_COMPARE") else [sys.executable]


def _call(case: str, out: Path) -> None:
    """One whole call as the peer harness makes it: run, then read the tip history."""
    import h5py
    import ancfdrv.runner as runner
    if case in MEMORY_CASES:
        import ancfdrv
        scene, overrides = MEMORY_CASES[case]
        ancfdrv.simulate(REPO / scene, overrides, progress=False).probe("tip")
        return
    scene, overrides = {**CASES, **PHASE_CASES}[case]
    runner.run_scene(REPO / scene, overrides, out, progress=False)
    with h5py.File(out, "r") as h5:
        h5["dynamic/time"][()]
        probes = h5["dynamic/probes"]
        probes["tip" if "tip" in probes else next(iter(probes))][()]


def counted_calls(case: str, helper: str) -> None:
    """The child of :func:`instructions`: warm-up calls, then INSTRUCTION_CALLS calls with
    callgrind's collection on."""
    import ctypes
    quiet_clock()
    toggle = ctypes.CDLL(helper).callgrind_toggle
    out = Path(tempfile.mkdtemp()) / "run.h5"
    for _ in range(2):
        _call(case, out)
    toggle()
    for _ in range(INSTRUCTION_CALLS):
        _call(case, out)
    toggle()


def quiet_clock() -> None:
    """The counted processes' settings (also ``in_memory_call.py``'s). Under valgrind a run
    lasts ~50 times longer and its writer would flush by the clock (FLUSH_SECONDS) where a
    quiet machine's run ends first: the rows wait for the end. The stepper sizes its kernel
    calls by the elapsed time of the first (~0.25 s each): a clock that advances 1 us per
    reading sizes them as a quiet machine does (up to output.chunk_steps), the same in
    every count (valgrind's slow and load-dependent clock gave other chunks, other answers
    passes: +-30 M instructions on the boom)."""
    import types
    import ancfdrv.results.hdf5 as h5
    import ancfdrv.solvers.dynamic as dynamic
    h5.FLUSH_SECONDS = 1e9
    ticks = iter(range(1, 1 << 62))
    dynamic.time = types.SimpleNamespace(perf_counter=lambda: 1e-6 * next(ticks),
                                         monotonic=time.monotonic, time=time.time)


def instrument(enter: Callable[[str], None], leave: Callable[[], None],
               label: Callable[[str], str] = lambda phase: phase, fine: bool = False) -> None:
    """Wrap every :data:`PHASES` and :data:`MEMORY_PHASES` function (``fine``: and the
    :data:`FINE_PHASES` parts), the
    :data:`PHASE_CONTEXTS` (as "HDF5") and the kernel's ``advance_rows`` (as "stepping") so
    that each call runs between ``enter(label(phase))`` and ``leave()``: what a phase
    split counts at those boundaries (callgrind dumps here, thread time in
    ``command_cost.py``'s warm worker) is the caller's."""
    import contextlib
    import importlib

    def wrap(owner: Any, name: str, phase: str) -> None:
        real = getattr(owner, name)

        @functools.wraps(real)
        def counted(*args: Any, **kwargs: Any) -> Any:
            enter(phase)
            try:
                return real(*args, **kwargs)
            finally:
                leave()
        setattr(owner, name, counted)

    def wrap_context(owner: Any, name: str) -> None:
        real = getattr(owner, name)

        @contextlib.contextmanager
        def counted(*args: Any, **kwargs: Any):
            enter("HDF5")
            try:
                manager = real(*args, **kwargs)
                manager.__enter__()
            finally:
                leave()
            try:
                yield
            except BaseException as exc:
                enter("HDF5")
                try:
                    if not manager.__exit__(type(exc), exc, exc.__traceback__):
                        raise
                finally:
                    leave()
            else:
                enter("HDF5")
                try:
                    manager.__exit__(None, None, None)
                finally:
                    leave()
        setattr(owner, name, counted)
    for module, owner, name, phase in PHASES + MEMORY_PHASES + (FINE_PHASES if fine else ()):
        target = importlib.import_module(module)
        target = target if owner is None else getattr(target, owner)
        if hasattr(target, name):   # (a copy to compare may lack a later function)
            wrap(target, name, label(phase))
    for module, name in PHASE_CONTEXTS:
        wrap_context(importlib.import_module(module), name)
    import ancfdrv.kernel as kernel
    for value in vars(kernel).values():
        if isinstance(value, type) and "advance_rows" in vars(value):
            wrap(value, "advance_rows", "stepping")


def phase_calls(case: str, helper: str, fine: bool = False) -> None:
    """The child of :func:`phase_instructions`: one warm-up call, then one counted call
    with a callgrind dump at every entry and exit of a :data:`PHASES` function (each dump
    named after the phase whose instructions it holds)."""
    import ctypes
    quiet_clock()
    lib = ctypes.CDLL(helper)
    stack, on = ["glue"], [False]

    def boundary() -> None:
        if on[0]:
            lib.callgrind_dump(stack[-1].encode())

    def enter(label: str) -> None:
        boundary()
        stack.append(label)

    def leave() -> None:
        boundary()
        stack.pop()

    instrument(enter, leave, fine=fine)
    import ancfdrv.runner as runner

    def call(out: Path) -> None:   # _call, its read-back of the tip history as HDF5's
        import h5py
        if case in MEMORY_CASES:
            import ancfdrv
            scene, overrides = MEMORY_CASES[case]
            sim = ancfdrv.simulate(REPO / scene, overrides, progress=False)
            sim.probe("tip")
            return
        scene, overrides = {**CASES, **PHASE_CASES}[case]
        runner.run_scene(REPO / scene, overrides, out, progress=False)
        enter("HDF5 (the read-back)")
        try:
            with h5py.File(out, "r") as h5:
                h5["dynamic/time"][()]
                probes = h5["dynamic/probes"]
                probes["tip" if "tip" in probes else next(iter(probes))][()]
        finally:
            leave()
    out = Path(tempfile.mkdtemp()) / "run.h5"
    call(out)
    lib.callgrind_toggle()
    on[0] = True
    call(out)
    boundary()
    on[0] = False
    lib.callgrind_toggle()


def phase_instructions(case: str, work: Path, fine: bool = False) -> dict[str, float]:
    """Instructions of one whole call of ``case`` per phase (callgrind; after a warm-up
    call, so imports and reused MUMPS instances are those of a process's later calls;
    ``fine``: the :data:`FINE_PHASES` parts apart)."""
    import re
    helper = _helper(work)
    target = work / case
    target.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", PYTHONHASHSEED="0")
    subprocess.run(["valgrind", "--tool=callgrind", "--collect-atstart=no",
                    f"--callgrind-out-file={target / 'cg'}", *_python(), __file__,
                    "--phase-counted", case, "--helper", str(helper),
                    *(["--fine"] if fine else [])], env=env, check=True,
                   capture_output=True)
    found: dict[str, float] = {}
    for dump in target.glob("cg*"):
        text = dump.read_text(errors="replace")
        label = re.search(r"^desc: Trigger: Client Request: (.+)$", text, re.M)
        total = re.search(r"^(?:summary|totals): (\d+)", text, re.M)
        if label and total:
            found[label.group(1)] = found.get(label.group(1), 0) + int(total.group(1))
    found["outside HDF5, the stepping and static solves"] = sum(
        v for k, v in found.items() if k not in ("stepping", "static solve")
        and not k.startswith("HDF5"))
    found["non-stepping"] = sum(v for k, v in found.items() if k not in (
        "stepping", "outside HDF5, the stepping and static solves"))
    return found


def _helper(work: Path) -> Path:
    """The callgrind client-request helper (compiled once per work directory)."""
    helper = work / "callgrind_toggle.so"
    if not helper.exists():
        source = work / "callgrind_toggle.c"
        source.write_text(_TOGGLE_C)
        subprocess.run(["cc", "-O1", "-shared", "-fPIC", "-o", str(helper), str(source)],
                       check=True)
    return helper


def instructions(case: str, work: Path) -> dict[str, Any]:

    """Instructions per whole call of ``case`` (total, stepping, non-stepping; callgrind)."""
    import re
    helper = _helper(work)
    profile = work / f"{case}.callgrind"
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", PYTHONHASHSEED="0")
    subprocess.run(["valgrind", "--tool=callgrind", "--collect-atstart=no",
                    f"--callgrind-out-file={profile}", *_python(), __file__,
                    "--counted", case, "--helper", str(helper)], env=env, check=True,
                   capture_output=True)
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100",
                           str(profile)], capture_output=True, text=True, check=True).stdout

    def count(pattern: str) -> int:
        found = re.search(r"^\s*([\d,]+)\s+(?:\([^)]*\)\s+)?" + pattern, text, re.M)
        return int(found.group(1).replace(",", "")) if found else 0
    total = count(r"PROGRAM TOTALS")
    stepping = count(r"\S*:system_advance_ ")
    return {"calls": INSTRUCTION_CALLS,
            "whole_per_call": total / INSTRUCTION_CALLS,
            "stepping_per_call": stepping / INSTRUCTION_CALLS,
            "non_stepping_per_call": (total - stepping) / INSTRUCTION_CALLS}


def measure(case: str, repeats: int) -> dict[str, Any]:
    """Phases of ``repeats`` whole calls of one case in this process (after one warm-up)."""
    if case in MEMORY_CASES:   # the whole in-memory call only (its phases: --phases)
        out = Path(tempfile.mkdtemp()) / "run.h5"
        _call(case, out)
        walls, cpus = [], []
        for _ in range(repeats):
            w0, c0 = time.perf_counter(), time.thread_time()
            _call(case, out)
            cpus.append(time.thread_time() - c0)
            walls.append(time.perf_counter() - w0)
        return {"whole_wall_best_ms": 1e3 * min(walls),
                "phases_thread_cpu_median_ms": {"whole (thread CPU)":
                                                1e3 * statistics.median(cpus)},
                "repeats": repeats}
    import ancfdrv.kernel as kernel
    import ancfdrv.results.hdf5 as h5
    import ancfdrv.runner as runner
    import ancfdrv.system.answers as answers
    spent: dict[str, float] = {}

    def wrap(owner: Any, attr: str, label: str) -> None:
        real = getattr(owner, attr)

        @functools.wraps(real)
        def timed(*args: Any, **kwargs: Any) -> Any:
            t0 = time.thread_time()
            try:
                return real(*args, **kwargs)
            finally:
                spent[label] = spent.get(label, 0.0) + time.thread_time() - t0
        setattr(owner, attr, timed)
    for owner, attr, label in (
            (runner, "load_scene", "scene"), (runner, "build_model", "model"),
            (runner, "check_output_path", "output path check"),
            (runner.OutputLock, "__enter__", "lock"), (runner.OutputLock, "__exit__", "unlock"),
            (h5, "create", "h5 create"), (runner, "solve_static_path", "static solve"),
            (h5, "write_static", "h5 static"), (h5, "write_static_answers", "h5 static answers"),
            (h5.DynamicWriter, "__init__", "h5 writer set-up"),
            (answers.DynamicAnswers, "__call__", "answers per chunk"),
            (h5.DynamicWriter, "flush", "h5 flush"),
            (h5, "write_dynamic_answers", "h5 dynamic answers"),
            (h5, "write_dynamic_attrs", "h5 dynamic attributes"), (h5, "finish", "h5 finish")):
        if hasattr(owner, attr):   # (a copy to compare may lack a later function)
            wrap(owner, attr, label)
    for value in vars(kernel).values():
        if isinstance(value, type) and "advance_rows" in vars(value):
            wrap(value, "advance_rows", "kernel stepping")
    scene, overrides = {**CASES, **PHASE_CASES}[case]
    out = Path(tempfile.mkdtemp()) / "run.h5"
    runner.run_scene(REPO / scene, overrides, out, progress=False)
    rows, walls = [], []
    for _ in range(repeats):
        spent.clear()
        w0, c0 = time.perf_counter(), time.thread_time()
        runner.run_scene(REPO / scene, overrides, out, progress=False)
        spent["whole (thread CPU)"] = time.thread_time() - c0
        walls.append(time.perf_counter() - w0)
        spent["non-stepping (thread CPU)"] = (spent["whole (thread CPU)"]
                                              - spent.get("kernel stepping", 0.0))
        rows.append(dict(spent))
    labels = list(dict.fromkeys(k for r in rows for k in r))
    return {"whole_wall_best_ms": 1e3 * min(walls),
            "phases_thread_cpu_median_ms": {k: 1e3 * statistics.median(r.get(k, 0.0)
                                                                        for r in rows)
                                            for k in labels},
            "repeats": repeats}


def phases_main(args: argparse.Namespace, load_average: Any, machine_info: Any) -> int:
    """``--phases``: per case and version, the instructions of one whole call per phase
    and the best wall time of ``--repeats`` whole calls (interleaved case by case)."""
    every = {**CASES, **PHASE_CASES, **MEMORY_CASES}
    cases = [c for c in (args.cases.split(",") if args.cases else every)]
    record: dict[str, Any] = {"machine": machine_info(), "load_average_at_start":
                              load_average(), "cases": {}}
    for case in cases:
        versions = {"this": None, **({"compared": args.compare} if args.compare else {})}
        for label, path in versions.items():
            env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "1"))
            saved = os.environ.get("PYTHONPATH")
            if path:
                env["PYTHONPATH"] = os.environ["PYTHONPATH"] = _compare_path(path)
                env["FIXED_COST_COMPARE"] = os.environ["FIXED_COST_COMPARE"] = "1"
            try:
                with tempfile.TemporaryDirectory() as tmp:
                    counts = phase_instructions(case, Path(tmp), args.fine)
            finally:
                if path:
                    os.environ.pop("FIXED_COST_COMPARE", None)
                    if saved is None:
                        os.environ.pop("PYTHONPATH", None)
                    else:
                        os.environ["PYTHONPATH"] = saved
            done = subprocess.run([*(_python() if not path else [sys.executable, "-S"]),
                                   __file__, "--one", case, "--repeats",
                                   str(args.repeats)], env=env, capture_output=True,
                                  text=True, check=True)
            timed = json.loads(done.stdout.strip().splitlines()[-1])
            record["cases"].setdefault(case, {})[label] = {
                "instructions_per_phase": counts, "load_average": load_average(), **timed}
            mine = counts["outside HDF5, the stepping and static solves"]
            print(f"{case:22s} {label:8s} non-stepping {counts['non-stepping'] / 1e6:7.2f} M Ir, "
                  f"outside HDF5/stepping {mine / 1e6:7.2f} M Ir, "
                  f"stepping {counts.get('stepping', 0) / 1e6:8.2f} M Ir, whole call best "
                  f"{timed['whole_wall_best_ms']:7.1f} ms wall", flush=True)
    record["load_average_at_end"] = load_average()
    target = REPO / "benchmarks" / "results" / args.out
    target.write_text(json.dumps(record, indent=1) + "\n")
    print(f"wrote {target}")
    return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--compare", help="directory holding another ancfdrv package")
    parser.add_argument("--instructions", action="store_true",
                        help="also count instructions per call with callgrind")
    parser.add_argument("--phases", action="store_true",
                        help="instructions per phase (callgrind) and best wall times of "
                             "CASES and PHASE_CASES: results/fixed_cost_phases.json")
    parser.add_argument("--cases", help="--phases: these cases only (comma-separated)")
    parser.add_argument("--fine", action="store_true",
                        help="--phases: the phases' parts (FINE_PHASES) counted apart")
    parser.add_argument("--out", default="fixed_cost_phases.json",
                        help="--phases: the result file's name in benchmarks/results")
    parser.add_argument("--one", help=argparse.SUPPRESS)  # a subprocess: one case, JSON out
    parser.add_argument("--counted", help=argparse.SUPPRESS)  # under callgrind
    parser.add_argument("--phase-counted", help=argparse.SUPPRESS)  # under callgrind
    parser.add_argument("--helper", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        print(json.dumps(measure(args.one, args.repeats)))
        return 0
    if args.counted:
        counted_calls(args.counted, args.helper)
        return 0
    if args.phase_counted:
        phase_calls(args.phase_counted, args.helper, args.fine)
        return 0
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _common import load_average, machine_info
    if args.phases:
        return phases_main(args, load_average, machine_info)
    cases = QUICK if args.quick else CASES
    record: dict[str, Any] = {"machine": machine_info(), "cases": {}}
    for case in cases:
        versions = {"this": None, **({"compared": args.compare} if args.compare else {})}
        for label, path in versions.items():
            env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "1"))
            if path:
                env["PYTHONPATH"] = _compare_path(path)
                env["FIXED_COST_COMPARE"] = "1"
            done = subprocess.run([*([sys.executable, "-S"] if path else [sys.executable]),
                                   __file__, "--one", case, "--repeats",
                                   str(2 if args.quick else args.repeats)], env=env,
                                  capture_output=True, text=True, check=True)
            result = json.loads(done.stdout.strip().splitlines()[-1])
            record["cases"].setdefault(case, {})[label] = result
            phases = result["phases_thread_cpu_median_ms"]
            print(f"{case:18s} {label:8s} whole {result['whole_wall_best_ms']:7.1f} ms wall; "
                  f"stepping {phases.get('kernel stepping', 0):6.1f}, non-stepping "
                  f"{phases['non-stepping (thread CPU)']:6.1f} ms thread CPU")
            if args.instructions:
                with tempfile.TemporaryDirectory() as tmp:
                    if path:
                        env_path = os.environ.get("PYTHONPATH")
                        os.environ["PYTHONPATH"] = _compare_path(path)
                        os.environ["FIXED_COST_COMPARE"] = "1"
                    try:
                        counts = instructions(case, Path(tmp))
                    finally:
                        if path:
                            os.environ.pop("FIXED_COST_COMPARE", None)
                            if env_path is None:
                                os.environ.pop("PYTHONPATH", None)
                            else:
                                os.environ["PYTHONPATH"] = env_path
                result["instructions"] = counts
                print(f"{'':27s} instructions per call: whole "
                      f"{counts['whole_per_call'] / 1e6:7.2f} M, stepping "
                      f"{counts['stepping_per_call'] / 1e6:7.2f} M, non-stepping "
                      f"{counts['non_stepping_per_call'] / 1e6:7.2f} M")
    record["load_average_at_end"] = load_average()
    name = "fixed_cost_quick.json" if args.quick else "fixed_cost.json"
    target = REPO / "benchmarks" / "results" / name
    target.write_text(json.dumps(record, indent=1) + "\n")
    print(f"wrote {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
