#!/usr/bin/env python
"""Accuracy against wall time: ancfdrv's large-deformation beam and Exudyn's ANCFCable2D on
the two hard cases of docs/hard-cases.md.

Problems (the physical data are read from the ancfdrv scenes, so both codes solve the
same beam):

* ``pendulum``: the flexible pendulum (Berzeri & Shabana 2000), ``inputs/hard/pendulum.nml``;
  hinged at the root, released horizontal under gravity; compared quantity: the tip's
  global y over 0 ... 1 s;
* ``spinup``: the spin-up beam (Simo & Vu-Quoc 1986) at W = 4 rad/s,
  ``inputs/hard/spinup.nml`` with ``spinup.omega=4``; compared quantity: the tip's
  transverse deflection in the rotating hub frame over 0 ... 20 s.

ancfdrv runs the scene with ``--set``-style overrides (``beam.nodes``, ``solver.dt``,
``solver.t_end``, ``beam.bending``: one curve for each bending option, 'cubic' and
'continuum', by default): the scene's generalized-alpha integrator, rho_inf and Newton
tolerance. Its compared time (``wall_s``) is the whole in-memory call
:func:`ancfdrv.simulate` (load the scene, build, solve, the answers the scene asks for, the
results kept in memory; the compared history read from it), the equal of Exudyn's call,
whose sensor keeps its data in memory; its repeats run back to back, as Exudyn's do. After
them the whole call with the SPEC HDF5 file (:func:`ancfdrv.runner.run_scene` writing to a temporary
directory, the history read back from the file) is timed too (``wall_file_s``), so what
the file costs stays visible; both calls compute the same history (checked bit for bit:
``file_history_equal``). Exudyn
builds the same beam from ``ObjectANCFCable2D`` elements (2D Euler-Bernoulli cable, EA
and EI from the scene's section) and integrates with its generalized-alpha solver
(index-3 constraints, the scene's rho_inf, fixed step, sparse LU). Constraints:

* pendulum: ancfdrv fixes r and r_z of the root node (a hinge about r3); Exudyn fixes the
  root's position, the slope stays free;
* spin-up: ancfdrv prescribes r = 0, r_y = (-sin phi, cos phi, 0), r_z = e3 at the root;
  Exudyn prescribes r = 0 and the slope r' = (cos phi, sin phi) (``CoordinateConstraint``
  with an offset user function), which also fixes the axial stretch of the root point
  (strains there are ~3e-5: no visible effect). phi(t) is the profile of Simo & Vu-Quoc 1986,
  checked against ancfdrv's drive (``kernel.drive_values``).

Each code runs a grid of meshes and steps; its finest run is its converged reference.
For every run this records the wall time (model build, solve and output of one call,
best of repeats until ``--min-time``; interpreter start-up and imports excluded; for
ancfdrv the in-memory call, and the call with the file beside it) and the
error of the tip history, max_k |y_k - y_ref(t_k)| on a uniform grid of sample times
(every ``sample_dt``; every step size divides it):

* ``error``: against ancfdrv's reference (the common reference of the brief);
* ``self_error``: against the run's own code's reference (discretization error of its
  own model).

The references are compared with each other: where they differ by more than the
discretization errors, the codes solve different continuum models and ``error`` of the
Exudyn runs measures the model difference, not their accuracy. For the pendulum (axial
strains of several percent: EA = 1260 N carries the weight and the centrifugal force) this
is the case: ancfdrv's continuum element uses the Green-Lagrange strain with a St.
Venant-Kirchhoff law (axial force EA lambda (lambda^2 - 1) / 2 at stretch lambda), Exudyn's
cable EA (lambda - 1). A third run of Exudyn at its reference resolution with that
St. Venant-Kirchhoff axial force (Python user functions: slow, not timed against ancfdrv)
tests this explanation.

Dominance (for each bending option): ancfdrv's curve dominates when for every Exudyn run some ancfdrv run reaches
the same error or smaller in the same time or less; for each Exudyn run the table gives
the time of the cheapest ancfdrv run at least as accurate (and vice versa). It is judged
on ``self_error`` (each code against its own converged model) and on ``error`` (common
reference).

Where ancfdrv's time goes: per ancfdrv run, the phases run_scene reports (model, set-up,
stepping, output) and an estimate of the stepping from kernel costs measured in this
process at the run's mesh: force evaluations of the whole model through its kernel handle
(``model.kernel.evaluate``: element loop, loads and assembly; one force + tangent per
factorization, at the predicted state, whose force is the step's first residual, then one
force per further Newton correction and one for the step's energy: about one force per
correction), the banded Cholesky factorization of beta' M + K_t (per factorization the
run's file reports), and the substitutions (the flexibility S^-1 E_c, 3 per constrained
3-vector, per factorization, and one per Newton correction).

Ported to the general-system model layer: the kernel costs come from a model built by
``ancfdrv.builders.build_model`` (released after the measurement) and the spin-up drive
check from ``ancfdrv.codes.DRIVE_SPINUP``; the breakdown counts factorizations from the
run (``DynamicResult.factorizations``) instead of one per step.

Results: tables on stdout and JSON in ``benchmarks/results/peer_exudyn.json``
(``peer_exudyn_quick.json`` with ``--quick``). Run from the repository root::

    python benchmarks/peer_exudyn.py            # about 2.5 min on 2 cores
    python benchmarks/peer_exudyn.py --quick    # coarser grids, 'cubic' only, one repeat:
                                                # a smoke run, ~25 s on an idle machine
    python benchmarks/peer_exudyn.py --omp-threads 2 --no-exudyn   # ancfdrv on 2 threads

When Exudyn cannot be imported (``pip install exudyn``), its runs are skipped and
ancfdrv's curve is still reported.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import importlib
import math
import os
import sys
import tempfile
import time
import warnings
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Callable

import h5py
import numpy as np
from _peer import (HISTORY_KEEP, exudyn_version, import_exudyn, loosest_keeping,
                   quiet_settings, run_quietly)

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
#: Another engineer reinstalls ancfdrv from time to time: how long to wait before retrying.
#: Exudyn's Newton: (absolute, relative) tolerances, tightest first. The first that works is
#: the run's tight setting (Exudyn's default absolute tolerance, 1e-10, lies below the
#: round-off floor of the spin-up's residual, EA = 2.8e7 N: Newton then never converges and
#: the fixed-step solve stops); of the looser ones, the timed run takes the loosest that keeps
#: its history within HISTORY_KEEP of the range of the tight run's (_peer.loosest_keeping,
#: the rule ancfdrv's newton_tol is chosen by). The code's reference (a grid's last run)
#: runs at the tight setting.
EXUDYN_TOLERANCES: dict[str, tuple[tuple[float, float], ...]] = {
    "pendulum": ((1e-10, 1e-8), (1e-6, 1e-6), (1e-3, 1e-6), (1e-2, 1e-5)),
    "spinup": ((1e-10, 1e-8), (1e-8, 1e-8), (1e-6, 1e-8), (1e-4, 1e-8))}
#: ancfdrv's newton_tol: the candidates (loosest first) and the tight setting of the same
#: rule; the code's reference runs at the scene's newton_tol (1e-10).
ANCFDRV_NEWTON_TOLS = (1e-4, 1e-6, 1e-8, 1e-10)
ANCFDRV_TIGHT_TOL = 1e-12
#: Problems whose Exudyn runs update the modified Newton's Jacobian at most once a step.
EXUDYN_JACOBIAN_PER_STEP = frozenset({"spinup"})
#: Exudyn's sensors store every 0.01 s (or every step if that is longer).
EXUDYN_SENSOR_PERIOD = 0.01

Grid = tuple[tuple[int, float], ...]


@dataclass(frozen=True)
class Problem:
    """One comparison: the scene, the compared history and the run grids.

    ``ancfdrv_runs`` are (nodes, dt), ``exudyn_runs`` (elements, dt); the last entry of
    each grid is that code's reference and should be its finest run."""

    name: str
    scene: str
    overrides: tuple[str, ...]
    t_end: float
    sample_dt: float
    quantity: str
    ancfdrv_runs: Grid
    exudyn_runs: Grid
    svk_check: tuple[int, float] | None = None


PROBLEMS: dict[str, Problem] = {
    "pendulum": Problem(
        name="pendulum", scene="inputs/hard/pendulum.nml", overrides=(), t_end=1.0,
        sample_dt=0.01, quantity="tip y (m), global",
        ancfdrv_runs=((5, 1e-2), (5, 5e-3), (5, 2e-3), (9, 1e-2), (9, 5e-3), (9, 2e-3),
                      (5, 1e-3), (9, 1e-3), (9, 5e-4), (17, 2e-3), (17, 1e-3), (17, 5e-4),
                      (33, 5e-4), (33, 2.5e-4), (65, 1.25e-4)),
        exudyn_runs=((4, 1e-2), (4, 5e-3), (4, 2e-3), (8, 1e-2), (8, 5e-3), (8, 2e-3),
                     (4, 1e-3), (8, 1e-3), (8, 5e-4), (16, 2e-3), (16, 1e-3), (16, 5e-4),
                     (32, 5e-4), (32, 2.5e-4), (64, 1.25e-4)),
        svk_check=(32, 2.5e-4)),
    "spinup": Problem(
        name="spinup", scene="inputs/hard/spinup.nml", overrides=("spinup.omega=4",),
        t_end=20.0, sample_dt=0.05, quantity="tip deflection (m), transverse, hub frame",
        ancfdrv_runs=((6, 2.5e-2), (11, 2.5e-2), (6, 1e-2), (6, 5e-3), (11, 1e-2), (11, 5e-3),
                      (21, 1e-2), (21, 5e-3), (41, 5e-3), (41, 2.5e-3), (81, 1.25e-3)),
        exudyn_runs=((5, 2.5e-2), (10, 2.5e-2), (5, 1e-2), (5, 5e-3), (10, 1e-2), (10, 5e-3),
                     (20, 1e-2), (20, 5e-3), (40, 5e-3), (40, 2.5e-3), (80, 1.25e-3))),
}
#: --quick: coarser grids and references, the same problems.
QUICK_PROBLEMS: dict[str, Problem] = {
    "pendulum": replace(
        PROBLEMS["pendulum"],
        ancfdrv_runs=((5, 1e-3), (9, 1e-3), (17, 1e-3), (17, 5e-4), (33, 5e-4)),
        exudyn_runs=((4, 1e-3), (8, 1e-3), (16, 1e-3), (16, 5e-4), (32, 5e-4)),
        svk_check=(16, 5e-4)),
    "spinup": replace(
        PROBLEMS["spinup"],
        ancfdrv_runs=((6, 1e-2), (11, 1e-2), (11, 5e-3), (21, 5e-3)),
        exudyn_runs=((5, 1e-2), (10, 1e-2), (10, 5e-3), (20, 5e-3))),
}


# -- results of one run --------------------------------------------------------------------
@dataclass
class Run:
    """One solve of one code: its settings, cost and sampled tip history."""

    code: str
    mesh: int                      # ancfdrv: nodes; Exudyn: elements
    elements: int
    dt: float
    bending: str = ""              # ancfdrv's beam.bending ('' for Exudyn)
    ok: bool = False
    message: str = ""
    wall_s: float = math.nan       # best of the repeats (ancfdrv: the in-memory call)
    wall_file_s: float = math.nan  # ancfdrv: best of the same call writing the HDF5 file
    repeats: int = 0
    steps: int = 0
    newton_iterations: int = 0
    details: dict[str, Any] = field(default_factory=dict)
    history: np.ndarray | None = None   # samples on the problem's grid
    error: float = math.nan        # max |y - y_ref(ancfdrv)|
    self_error: float = math.nan   # max |y - y_ref(own code)|
    reference: bool = False

    @property
    def samples(self) -> np.ndarray:
        """The sampled history of a successful run."""
        if self.history is None:
            raise ValueError(f"{self.code} mesh {self.mesh} dt {self.dt:g} has no history")
        return self.history

    def summary(self) -> dict[str, Any]:
        out = asdict(self)
        out.pop("history")
        return out


def max_difference(a: Run, b: Run) -> float:
    """max_k |y_a(t_k) - y_b(t_k)| over the sample times."""
    return float(np.max(np.abs(a.samples - b.samples)))


def sample_grid(problem: Problem) -> np.ndarray:
    count = int(round(problem.t_end / problem.sample_dt))
    return problem.sample_dt * np.arange(count + 1)


def resample(problem: Problem, time_: np.ndarray, values: np.ndarray) -> np.ndarray:
    """The history at the sample times (every step size divides sample_dt, so this picks
    computed values; interpolation only absorbs round-off in the time column)."""
    grid = sample_grid(problem)
    if time_[-1] < grid[-1] - 1e-6 * problem.sample_dt:
        raise ValueError(f"the history ends at t = {time_[-1]:g} s, before {grid[-1]:g} s")
    return np.interp(grid, time_, values)


def best_of(solve: Callable[[], tuple[np.ndarray, dict[str, Any]]], min_time: float,
            max_repeats: int) -> tuple[float, int, np.ndarray, dict[str, Any]]:
    """Repeat ``solve`` until the repeats took ``min_time`` (at most ``max_repeats``);
    the fastest repeat's time, the count and the last result."""
    times: list[float] = []
    history: np.ndarray = np.empty(0)
    details: dict[str, Any] = {}
    while not times or (sum(times) < min_time and len(times) < max_repeats):
        t0 = time.perf_counter()
        history, details = solve()
        times.append(time.perf_counter() - t0)
    return min(times), len(times), history, details


def import_ancfdrv() -> None:
    """Import the package up front, so import time stays out of the first measurement."""
    importlib.import_module("ancfdrv.runner")
    importlib.import_module("ancfdrv.simulation")


def ancfdrv_overrides(problem: Problem, nodes: int, dt: float, bending: str,
                      newton_tol: float | None = None) -> list[str]:
    """``bending``: 'cubic' or 'continuum', with '-planar' the scene reduced to its plane
    (``scene.planar = 'xy'``, issue 23); 'cable-planar': the pendulum or the spin-up as an
    ANCF cable (bending about the plane's normal; the spin-up's hub holds r and r_x),
    reduced. ``newton_tol`` None: the scene's."""
    option, _, planar = bending.partition("-")
    return [*problem.overrides, f"beam.nodes={nodes}", f"solver.dt={dt!r}",
            f"solver.t_end={problem.t_end!r}", f"beam.bending={option}"] + \
        (["scene.planar=xy"] if planar == "planar" else []) + \
        ([f"solver.newton_tol={newton_tol!r}"] if newton_tol is not None else [])


def tip_history(problem: Problem, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Time and the compared tip quantity from an ancfdrv result file."""
    with h5py.File(path, "r") as h5:
        t = h5["dynamic/time"][()]
        if problem.name == "pendulum":
            return t, h5["dynamic/probes/tip"][:, 1]
        return t, h5["dynamic/deflection/tip"][:, 1]


def run_ancfdrv(problem: Problem, nodes: int, dt: float, bending: str, workdir: Path,
                args: argparse.Namespace, choose_tol: bool = False) -> Run:
    """The in-memory call (:func:`ancfdrv.simulate`, the compared time ``wall_s``) repeated
    back to back as Exudyn's call is (:func:`best_of`), then the
    :func:`ancfdrv.runner.run_scene` call writing the HDF5 file (``wall_file_s``) repeated
    the same way; a SolverError is recorded, not raised. (Until the sixth wave the file call
    ran after each in-memory repeat: every in-memory repeat then started on the caches the
    file's writer left, a condition Exudyn's back-to-back repeats never saw; on the sixth
    wave's code the difference measured within noise, benchmarks/README.md.) ``choose_tol``:
    the run's newton_tol is the loosest of ANCFDRV_NEWTON_TOLS that keeps the history (one
    untimed run per setting tried, :func:`_peer.loosest_keeping`), else the scene's."""
    from ancfdrv.errors import AncfError
    from ancfdrv.runner import run_scene
    from ancfdrv.simulation import simulate

    run = Run(f"ancfdrv/{bending}", nodes, nodes - 1, dt, bending)
    out = workdir / f"{problem.name}_{bending}_{nodes}_{dt:g}.h5"
    scene = REPO / problem.scene
    newton_tol: float | None = None
    if choose_tol:
        def history_at(tol: float) -> np.ndarray:
            sim = simulate(scene, ancfdrv_overrides(problem, nodes, dt, bending, tol),
                           progress=False)
            tip = sim.probe("tip") if problem.name == "pendulum" else sim.deflection("tip")
            return resample(problem, sim.time, tip[:, 1])
        try:
            newton_tol, tried = loosest_keeping(history_at, ANCFDRV_NEWTON_TOLS,
                                                ANCFDRV_TIGHT_TOL, errors=(AncfError, ValueError))
        except (AncfError, ValueError) as exc:
            run.message = f"newton_tol {ANCFDRV_TIGHT_TOL:g}: {exc}"
            return run
        run.details["newton_tol"] = newton_tol
        run.details["newton_tol_tried"] = tried
    overrides = ancfdrv_overrides(problem, nodes, dt, bending, newton_tol)

    def solve() -> tuple[np.ndarray, dict[str, Any]]:
        # timed: the run and the compared history read from it (as Exudyn's call ends
        # with its sensor's history, kept in memory)
        sim = simulate(scene, overrides, progress=False)
        dyn = sim.dynamic
        assert dyn is not None
        tip = sim.probe("tip") if problem.name == "pendulum" else sim.deflection("tip")
        return resample(problem, sim.time, tip[:, 1]), {
            "steps": dyn.steps, "newton": dyn.newton_iterations,
            "factorizations": dyn.factorizations, "warnings": sim.warnings}

    def solve_file() -> tuple[np.ndarray, dict[str, Any]]:
        # timed: the run writing the file, and the compared history read back from it;
        # the file's /timing diagnostics are read after the timing
        run_scene(scene, overrides, out, progress=False)
        t, y = tip_history(problem, out)
        return resample(problem, t, y), {}

    t0 = time.perf_counter()
    try:
        run.wall_s, run.repeats, run.history, details = best_of(solve, args.min_time,
                                                                args.max_repeats)
        run.wall_file_s, _, file_history, _ = best_of(solve_file, args.min_time,
                                                      args.max_repeats)
    except (AncfError, ValueError) as exc:
        run.message = str(exc)
        run.details["time_to_failure_s"] = time.perf_counter() - t0
        return run
    details["file_history_equal"] = bool(np.array_equal(run.history, file_history))
    with h5py.File(out, "r") as h5:   # the last repeat's phases
        details["timing"] = {k: float(v) for k, v in h5["timing"].attrs.items()}
    run.ok = True
    run.steps, run.newton_iterations = details.pop("steps"), details.pop("newton")
    run.details.update(details)
    return run


_KERNEL_COSTS: dict[tuple[str, str, int], dict[str, float]] = {}


def kernel_costs(problem: Problem, run: Run, args: argparse.Namespace) -> dict[str, float]:
    """Per-call times (s) of the kernel operations of one step at the run's mesh, measured
    once per problem and mesh: force and force + tangent of the model through its kernel
    handle, banded factorization of beta' M + K (the pattern and band of the iteration
    matrix), one substitution, and the substitutions of the flexibility S^-1 E_c."""
    key = (problem.name, run.bending, run.mesh)
    if key in _KERNEL_COSTS:
        return _KERNEL_COSTS[key]
    from element_cost import time_call

    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    from ancfdrv.kernel import DirectSolver
    from ancfdrv.runner import dynamic_settings
    from ancfdrv.solvers.dynamic import DynamicSettings

    scene = load_scene(REPO / problem.scene,
                       ancfdrv_overrides(problem, run.mesh, run.dt, run.bending))
    model = build_model(scene)
    try:
        settings: DynamicSettings = dynamic_settings(scene)
        e, v = model.e0.copy(), np.zeros(model.ndof)

        def forces(want_tangent: bool) -> Callable[[], object]:
            return lambda: model.kernel.evaluate(0.0, e, v, model.contact_guesses,
                                                 model.contact_counts,
                                                 want_tangent=want_tangent)

        force = time_call(forces(False), args.kernel_min_time, 3).per_call_s
        tangent = time_call(forces(True), args.kernel_min_time, 3).per_call_s
        values = settings.beta_prime * model.mass_values() + model.stiffness_values()
        flexibility_rhs = 3 * len(model.touched_blocks())
        with DirectSolver(model.ndof, model.pattern.rows, model.pattern.col_index,
                          banded_spd=True, what="beta' M + K") as solver:
            factorize = time_call(lambda: solver.factorize(values), args.kernel_min_time,
                                  3).per_call_s
            rhs1 = np.ones(model.ndof)
            rhs_flex = np.ones((model.ndof, max(flexibility_rhs, 1)))
            solve1 = time_call(lambda: solver.solve(rhs1), args.kernel_min_time, 3).per_call_s
            solve_flex = time_call(lambda: solver.solve(rhs_flex), args.kernel_min_time,
                                   3).per_call_s
    finally:
        model.close()
    costs = {"force": force, "force_tangent": tangent, "factorize": factorize,
             "solve_1rhs": solve1, "solve_flexibility": solve_flex,
             "flexibility_rhs": float(flexibility_rhs)}
    _KERNEL_COSTS[key] = costs
    return costs


def ancfdrv_breakdown(problem: Problem, run: Run, args: argparse.Namespace) -> dict[str, float]:
    """Estimated split of ancfdrv's stepping time (see the module docstring) from the kernel
    costs at the run's mesh; the shares are of the stepping time run_scene measured."""
    c = kernel_costs(problem, run, args)
    stepping = run.details["timing"].get("dynamic_stepping", math.nan)
    steps, newton = run.steps, run.newton_iterations
    factorizations = run.details.get("factorizations", steps)
    parts = {"elements": factorizations * c["force_tangent"] + newton * c["force"],
             "factorization": factorizations * c["factorize"],
             "substitutions": factorizations * c["solve_flexibility"]
             + newton * c["solve_1rhs"]}
    shares = {f"{k}_share": v / stepping for k, v in parts.items()}
    return {"stepping_s": stepping, "per_step_ms": 1e3 * stepping / max(steps, 1),
            "newton_per_step": newton / max(steps, 1),
            **{f"{k}_us": 1e6 * v for k, v in c.items() if k != "flexibility_rhs"},
            "flexibility_rhs": int(c["flexibility_rhs"]),
            **{f"{k}_s": v for k, v in parts.items()}, **shares,
            "rest_share": 1.0 - sum(shares.values())}


# -- Exudyn ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Beam:
    """What the cable needs, from the ancfdrv scene."""

    length: float
    mass_per_length: float
    axial_stiffness: float
    bending_stiffness: float
    gravity: float
    rho_inf: float
    omega: float = 0.0
    period: float = 1.0


def beam_from_scene(problem: Problem) -> Beam:
    from ancfdrv.io.scene import load_scene

    scene = load_scene(REPO / problem.scene, list(problem.overrides))
    beam, material, solver = scene["beam"], scene["material"], scene["solver"]
    area = beam["width"] * beam["height"]
    inertia = beam["width"] * beam["height"] ** 3 / 12.0  # bending in the x-y plane
    gravity = scene["loads"]["gravity"] if "gravity" in scene.effects else 0.0
    spin = scene.values.get("spinup", {})
    return Beam(length=beam["length"], mass_per_length=material["density"] * area,
                axial_stiffness=material["youngs_modulus"] * area,
                bending_stiffness=material["youngs_modulus"] * inertia, gravity=gravity,
                rho_inf=solver["rho_inf"], omega=spin.get("omega", 0.0),
                period=spin.get("period", 1.0))


def spinup_angle(beam: Beam, t: float) -> float:
    """Hub angle of Simo & Vu-Quoc 1986: (W/T)[t^2/2 + (T/2pi)^2 (cos(2 pi t/T) - 1)] for t < T,
    W t - W T/2 after."""
    w, period = beam.omega, beam.period
    if t < period:
        return w / period * (0.5 * t * t + (period / (2.0 * math.pi)) ** 2
                             * (math.cos(2.0 * math.pi * t / period) - 1.0))
    return w * t - 0.5 * w * period


def check_spinup_angle(beam: Beam) -> float:
    """Largest difference between :func:`spinup_angle` and ancfdrv's drive."""
    from ancfdrv.codes import DRIVE_SPINUP
    from ancfdrv.kernel import drive_values

    t = np.linspace(0.0, 2.0 * beam.period, 301)
    phi, _, _ = drive_values(DRIVE_SPINUP, [beam.omega, beam.period, 0.0], t)
    return float(np.max(np.abs(phi - [spinup_angle(beam, x) for x in t])))


def symbolic_slope_offsets(exu: Any, mbs: Any, beam: Beam) -> dict[int, Any]:
    """The spin-up's root slope offsets (cos phi - 1, sin phi) as Exudyn symbolic user
    functions, which Exudyn evaluates without calling Python; the same values as
    :func:`spinup_angle`. Keep them alive as long as the system uses them."""
    from exudyn.advancedUtilities import CreateSymbolicUserFunction

    esym = exu.symbolic
    w, period = beam.omega, beam.period

    def angle(t: Any) -> Any:
        start = w / period * (0.5 * t * t + (period / (2.0 * math.pi)) ** 2
                              * (esym.cos(2.0 * math.pi * t / period) - 1.0))
        return esym.IfThenElse(t < period, start, w * t - esym.Real(0.5 * w * period))

    def cos_offset(mbs_: Any, t: Any, item: int, offset: Any) -> Any:
        return esym.cos(angle(t)) - 1.0

    def sin_offset(mbs_: Any, t: Any, item: int, offset: Any) -> Any:
        return esym.sin(angle(t))

    return {coordinate: CreateSymbolicUserFunction(
        mbs, function, "offsetUserFunction", itemTypeName="ObjectConnectorCoordinate")
        for coordinate, function in ((2, cos_offset), (3, sin_offset))}


def exudyn_model(exu: Any, problem: Problem, beam: Beam, nel: int,
                 svk_axial: bool = False, symbolic_drive: bool = False) -> tuple[Any, Any, int]:
    """The cable on a fresh system: (system container, mbs, tip sensor). The spin-up's
    drive is a Python user function, or with ``symbolic_drive`` a symbolic one."""
    from exudyn.beams import GenerateBeamElementsAlongLine
    from exudyn.itemInterface import (CoordinateConstraint, MarkerNodeCoordinate,
                                      NodePointGround, ObjectANCFCable2D, SensorNode)

    container = exu.SystemContainer()
    mbs = container.AddSystem()
    user: dict[str, Any] = {}
    if svk_axial:
        def axial_force(mbs_: Any, t: float, item: int, x: float, strain: float,
                        strain_t: float, strain_ref: float, stiffness: float,
                        damping: float, curvature: float, curvature_t: float,
                        curvature_ref: float) -> float:
            stretch = 1.0 + strain
            return stiffness * stretch * (stretch * stretch - 1.0) * 0.5

        def bending_moment(mbs_: Any, t: float, item: int, x: float, curvature: float,
                           curvature_t: float, curvature_ref: float, stiffness: float,
                           damping: float, strain: float, strain_t: float,
                           strain_ref: float) -> float:
            return stiffness * (curvature - curvature_ref)

        # Exudyn calls the user functions only when both are given
        user = {"axialForceUserFunction": axial_force,
                "bendingMomentUserFunction": bending_moment}
    template = ObjectANCFCable2D(physicsMassPerLength=beam.mass_per_length,
                                 physicsBendingStiffness=beam.bending_stiffness,
                                 physicsAxialStiffness=beam.axial_stiffness, **user)
    pinned = problem.name == "pendulum"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        items = GenerateBeamElementsAlongLine(
            mbs, positionStart=[0.0, 0.0, 0.0], positionEnd=[beam.length, 0.0, 0.0],
            numberOfElements=nel, beamTemplate=template,
            gravity=[0.0, -beam.gravity, 0.0], groundConstraintsStart=[1, 1, 0, 0])
    if not pinned:  # clamp the slope to the hub: r' = (cos phi, sin phi), as displacements
        root = items["nodes"][0]
        ground = mbs.AddNode(NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
        ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
        slopes: dict[int, Any] = {2: lambda m, t, i, o: math.cos(spinup_angle(beam, t)) - 1.0,
                                  3: lambda m, t, i, o: math.sin(spinup_angle(beam, t))}
        if symbolic_drive:
            slopes = symbolic_slope_offsets(exu, mbs, beam)
            mbs.variables["symbolic_user_functions"] = list(slopes.values())  # keep alive
        for coordinate, offset in slopes.items():
            marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=root, coordinate=coordinate))
            mbs.AddObject(CoordinateConstraint(markerNumbers=[ground_marker, marker],
                                               offsetUserFunction=offset))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=items["nodes"][-1], storeInternal=True,
                                      outputVariableType=exu.OutputVariableType.Position))
    mbs.Assemble()
    return container, mbs, sensor


def exudyn_settings(exu: Any, problem: Problem, beam: Beam, dt: float,
                    tolerances: tuple[float, float]) -> Any:
    settings = exu.SimulationSettings()
    integration = settings.timeIntegration
    integration.numberOfSteps = int(round(problem.t_end / dt))
    integration.endTime = problem.t_end
    integration.generalizedAlpha.spectralRadius = beam.rho_inf
    integration.adaptiveStep = False  # fixed steps, as ancfdrv
    integration.verboseMode = 0
    integration.newton.absoluteTolerance, integration.newton.relativeTolerance = tolerances
    if problem.name.split("_")[0] in EXUDYN_JACOBIAN_PER_STEP:
        integration.newton.modifiedNewtonJacUpdatePerStep = True
    quiet_settings(exu, settings, max(dt, EXUDYN_SENSOR_PERIOD))
    return settings


def exudyn_history(problem: Problem, beam: Beam, data: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Time and the compared tip quantity from the sensor's (t, x, y, z) rows."""
    t, x, y = data[:, 0], data[:, 1], data[:, 2]
    if problem.name == "pendulum":
        return t, y
    phi = np.array([spinup_angle(beam, s) for s in t])
    return t, -np.sin(phi) * x + np.cos(phi) * y   # (A(t)^T p - (L, 0))_y


def run_exudyn(exu: Any, problem: Problem, beam: Beam, nel: int, dt: float,
               args: argparse.Namespace, svk_axial: bool = False,
               choose_tol: bool = False) -> Run:
    """One Exudyn solve (repeated for timing) at the first tolerances that work; with
    ``choose_tol``, at the loosest of the looser ones that keeps the history of that first
    (:func:`_peer.loosest_keeping`, one untimed run per setting tried)."""
    run = Run("exudyn-svk" if svk_axial else "exudyn", nel, nel, dt)
    symbolic = bool(getattr(args, "exudyn_symbolic_drive", False))
    failures: list[str] = []
    failed_s = 0.0
    def solve_at(tol: tuple[float, float]) -> tuple[np.ndarray, dict[str, Any]]:
        _, mbs, sensor = exudyn_model(exu, problem, beam, nel, svk_axial,
                                      symbolic_drive=symbolic)
        settings = exudyn_settings(exu, problem, beam, dt, tol)
        run_quietly(lambda: mbs.SolveDynamic(
            settings, solverType=exu.DynamicSolverType.GeneralizedAlpha))
        it = mbs.sys["dynamicSolver"].it
        t, y = exudyn_history(problem, beam, mbs.GetSensorStoredData(sensor))
        return resample(problem, t, y), {"steps": int(it.currentStepIndex) - 1,
                                         "newton": int(it.newtonStepsCount),
                                         "jacobians": int(it.newtonJacobiCount)}

    tolerances = EXUDYN_TOLERANCES[problem.name.split("_")[0]]
    for k, tol in enumerate(tolerances):
        if choose_tol:
            try:
                tol, tried = loosest_keeping(lambda t: solve_at(t)[0], tolerances[:k:-1], tol)
            except (RuntimeError, ValueError) as exc:
                failures.append(f"tolerances {tol[0]:g}/{tol[1]:g}: {exc}")
                continue
            run.details["tolerances_tried"] = [{**t, "setting": list(t["setting"])}
                                               for t in tried]

        def solve(tol: tuple[float, float] = tol) -> tuple[np.ndarray, dict[str, Any]]:
            return solve_at(tol)
        t0 = time.perf_counter()
        try:
            run.wall_s, run.repeats, run.history, details = best_of(solve, args.min_time,
                                                                    args.max_repeats)
        except (RuntimeError, ValueError) as exc:
            failed_s += time.perf_counter() - t0
            failures.append(f"tolerances {tol[0]:g}/{tol[1]:g}: {exc}")
            continue
        run.ok = True
        run.steps, run.newton_iterations = details.pop("steps"), details.pop("newton")
        run.details.update(details, absolute_tol=tol[0], relative_tol=tol[1],
                           jacobian_update_per_step=problem.name.split("_")[0] in
                           EXUDYN_JACOBIAN_PER_STEP,
                           drive="symbolic" if symbolic else "python")
        break
    run.details.update(failed_attempts=failures, failed_attempts_s=failed_s)
    if not run.ok:
        run.message = "; ".join(failures)
    return run


# -- comparison ----------------------------------------------------------------------------------
def assign_errors(runs: list[Run], reference: Run, field_name: str) -> None:
    for run in runs:
        if run.ok and reference.ok:
            setattr(run, field_name, max_difference(run, reference))


def cheapest_as_accurate(point: Run, others: list[Run], key: str) -> Run | None:
    """The fastest run of ``others`` whose error (``key``) is at most ``point``'s."""
    target = getattr(point, key)
    good = [r for r in others if r.ok and getattr(r, key) <= target]
    return min(good, key=lambda r: r.wall_s) if good else None


def pareto(runs: list[Run], key: str) -> list[Run]:
    """Runs not beaten by another run of the same code in both time and error."""
    front, best = [], math.inf
    for run in sorted((r for r in runs if r.ok), key=lambda r: (r.wall_s, getattr(r, key))):
        if getattr(run, key) < best:
            front.append(run)
            best = getattr(run, key)
    return front


def dominance(ours: list[Run], peer: list[Run], key: str) -> dict[str, Any]:
    """Does ``ours`` reach every error of ``peer`` in at most the time (and vice versa)?"""
    ours = [r for r in ours if r.ok and math.isfinite(getattr(r, key))]
    peer = [r for r in peer if r.ok and math.isfinite(getattr(r, key))]
    pairs = []
    for run in peer:
        match = cheapest_as_accurate(run, ours, key)
        pairs.append({"exudyn": [run.mesh, run.dt], "exudyn_error": getattr(run, key),
                      "exudyn_wall_s": run.wall_s,
                      "ancfdrv": [match.mesh, match.dt] if match else None,
                      "ancfdrv_wall_s": match.wall_s if match else None,
                      "time_ratio_ancfdrv_over_exudyn":
                          match.wall_s / run.wall_s if match else None,
                      # the same ancfdrv run's call writing the HDF5 file (not compared)
                      "ancfdrv_wall_file_s": match.wall_file_s if match else None,
                      "time_ratio_ancfdrv_with_file_over_exudyn":
                          match.wall_file_s / run.wall_s if match else None})
    reverse = []
    for run in ours:
        match = cheapest_as_accurate(run, peer, key)
        reverse.append({"ancfdrv": [run.mesh, run.dt], "ancfdrv_error": getattr(run, key),
                        "ancfdrv_wall_s": run.wall_s,
                        "exudyn": [match.mesh, match.dt] if match else None,
                        "exudyn_wall_s": match.wall_s if match else None})
    ancfdrv_dominates = bool(peer) and all(
        p["ancfdrv_wall_s"] is not None and p["ancfdrv_wall_s"] <= p["exudyn_wall_s"]
        for p in pairs)
    exudyn_dominates = bool(ours) and all(
        p["exudyn_wall_s"] is not None and p["exudyn_wall_s"] <= p["ancfdrv_wall_s"]
        for p in reverse)
    return {"key": key, "ancfdrv_dominates": ancfdrv_dominates,
            "exudyn_dominates": exudyn_dominates, "for_each_exudyn_run": pairs,
            "for_each_ancfdrv_run": reverse,
            "pareto_ancfdrv": [[r.mesh, r.dt, r.wall_s, getattr(r, key)] for r in pareto(ours, key)],
            "pareto_exudyn": [[r.mesh, r.dt, r.wall_s, getattr(r, key)] for r in pareto(peer, key)]}


def compare_problem(problem: Problem, exu: Any, workdir: Path,
                    args: argparse.Namespace) -> dict[str, Any]:
    """All runs of one problem, the references and the comparisons."""
    beam = beam_from_scene(problem)
    record: dict[str, Any] = {"problem": asdict(problem), "beam": asdict(beam),
                              "sample_times": sample_grid(problem)}
    if problem.name == "spinup":
        record["spinup_angle_vs_ancfdrv_drive_max_abs"] = check_spinup_angle(beam)

    groups: dict[str, list[Run]] = {}
    for bending in args.bending:
        groups[bending] = []
        for k, (nodes, dt) in enumerate(problem.ancfdrv_runs):
            run = run_ancfdrv(problem, nodes, dt, bending, workdir, args,
                              choose_tol=getattr(args, "choose_tol", False)
                              and k < len(problem.ancfdrv_runs) - 1)
            if run.ok and args.breakdown:
                run.details["breakdown"] = ancfdrv_breakdown(problem, run, args)
            groups[bending].append(run)
            _progress(problem, run)
    ancfdrv_runs = [run for runs in groups.values() for run in runs]
    exudyn_runs: list[Run] = []
    svk: Run | None = None
    if exu is not None:
        for k, (nel, dt) in enumerate(problem.exudyn_runs):
            exudyn_runs.append(run_exudyn(exu, problem, beam, nel, dt, args,
                                          choose_tol=getattr(args, "choose_tol", False)
                                          and k < len(problem.exudyn_runs) - 1))
            _progress(problem, exudyn_runs[-1])
        if problem.svk_check and args.svk_check:
            svk = run_exudyn(exu, problem, beam, *problem.svk_check, args, svk_axial=True)
            _progress(problem, svk)

    # the common reference: the finest run of the first bending option listed
    for bending, runs in groups.items():
        runs[-1].reference = True
        if not runs[-1].ok:
            raise RuntimeError(f"{problem.name}: ancfdrv's reference run ({bending}) failed: "
                               f"{runs[-1].message}")
        assign_errors(runs, runs[-1], "self_error")
    reference = groups[args.bending[0]][-1]
    peer_reference = exudyn_runs[-1] if exudyn_runs else None
    assign_errors(ancfdrv_runs + exudyn_runs + ([svk] if svk else []), reference, "error")
    references: dict[str, Any] = {
        "ancfdrv": [reference.mesh, reference.dt],
        "ancfdrv_bending": reference.bending,
        "ancfdrv_amplitude": float(np.max(np.abs(reference.samples))),
        "ancfdrv_closest_other_run": min((r.self_error for r in groups[args.bending[0]]
                                          if r.ok and not r.reference), default=math.nan),
        "bending_references_max_abs_difference": {
            bending: runs[-1].error for bending, runs in groups.items()}}
    if peer_reference is not None:
        peer_reference.reference = True
        if peer_reference.ok:
            assign_errors(exudyn_runs, peer_reference, "self_error")
            references.update({
                "exudyn": [peer_reference.mesh, peer_reference.dt],
                "exudyn_closest_other_run": min((r.self_error for r in exudyn_runs
                                                 if r.ok and not r.reference),
                                                default=math.nan),
                "max_abs_difference": peer_reference.error,
                # the gap between the references exceeds every Exudyn run's own error: the
                # codes converge to different solutions, ``error`` of Exudyn is the gap
                "model_gap_dominates": peer_reference.error > max(
                    (r.self_error for r in exudyn_runs if r.ok and not r.reference),
                    default=math.inf),
                "max_abs_difference_time": float(sample_grid(problem)[np.argmax(np.abs(
                    peer_reference.samples - reference.samples))])})
    if svk is not None and svk.ok:
        references["exudyn_svk_axial"] = [svk.mesh, svk.dt]
        references["svk_max_abs_difference_to_ancfdrv"] = svk.error
        if peer_reference is not None and peer_reference.ok:
            references["svk_max_abs_difference_to_exudyn"] = max_difference(
                svk, peer_reference)
    record["references"] = references
    # the references themselves are not points of the curves they define
    peer_self = [r for r in exudyn_runs if not r.reference]
    record["dominance"] = {
        bending: {"self_error": dominance([r for r in runs if not r.reference], peer_self,
                                          "self_error"),
                  "error": dominance([r for r in runs if not r.reference], exudyn_runs,
                                     "error")}
        for bending, runs in groups.items()} if exudyn_runs else {}
    record["runs"] = [r.summary() for r in ancfdrv_runs + exudyn_runs + ([svk] if svk else [])]
    record["histories"] = {f"{r.code}_{r.mesh}_{r.dt:g}": r.samples
                           for r in ancfdrv_runs + exudyn_runs + ([svk] if svk else [])
                           if r.ok and (r.reference or r.code == "exudyn-svk")}
    return record


def _progress(problem: Problem, run: Run) -> None:
    state = f"{run.wall_s:7.2f} s" if run.ok else "FAILED"
    print(f"  {problem.name:>8} {run.code:>17} mesh {run.mesh:>3} dt {run.dt:<8g} {state}",
          file=sys.stderr, flush=True)


# -- reporting -------------------------------------------------------------------------------
def _g(value: float | None, fmt: str = ".2e") -> str:
    return "-" if value is None or not math.isfinite(value) else format(value, fmt)


def print_tables(records: dict[str, dict[str, Any]], exudyn_note: str | None) -> None:
    from _common import print_table

    for name, rec in records.items():
        problem = rec["problem"]
        refs = rec["references"]
        print(f"\n== {name}: {problem['quantity']} over 0 ... {problem['t_end']:g} s, sampled "
              f"every {problem['sample_dt']:g} s; error = max |y - y_ref|, m")
        print(f"   references: ancfdrv {refs['ancfdrv'][0]} nodes, dt {refs['ancfdrv'][1]:g} "
              f"(|y| up to {refs['ancfdrv_amplitude']:.3g} m; its closest other run differs by "
              f"{_g(refs['ancfdrv_closest_other_run'])})"
              + (f"; Exudyn {refs['exudyn'][0]} elements, dt {refs['exudyn'][1]:g} (closest "
                 f"other run {_g(refs['exudyn_closest_other_run'])})" if "exudyn" in refs else ""))
        if "max_abs_difference" in refs:
            print(f"   ancfdrv reference vs Exudyn reference: max |difference| "
                  f"{_g(refs['max_abs_difference'])} m (at t = {refs['max_abs_difference_time']:g} s)")
        if refs.get("model_gap_dominates"):
            print("   NOTE: the references differ by more than any Exudyn run from its own "
                  "reference: the codes converge to different solutions (different continuum "
                  "models), so 'error' of the Exudyn runs is that gap, not their accuracy")
        if "svk_max_abs_difference_to_ancfdrv" in refs:
            print(f"   Exudyn with the St. Venant-Kirchhoff axial force EA l (l^2 - 1)/2 "
                  f"({refs['exudyn_svk_axial'][0]} elements, dt {refs['exudyn_svk_axial'][1]:g}):"
                  f" {_g(refs['svk_max_abs_difference_to_ancfdrv'])} m from ancfdrv's reference, "
                  f"{_g(refs.get('svk_max_abs_difference_to_exudyn'))} m from Exudyn's")
        if "spinup_angle_vs_ancfdrv_drive_max_abs" in rec:
            print(f"   hub angle used for Exudyn vs ancfdrv's drive: max |difference| "
                  f"{rec['spinup_angle_vs_ancfdrv_drive_max_abs']:.1e} rad")
        rows = []
        for r in rec["runs"]:
            b = r["details"].get("breakdown", {})
            extra = (f"tol {r['details']['absolute_tol']:g}, jac {r['details']['jacobians']}"
                     if r["code"].startswith("exudyn") and r["ok"] else "")
            if b:
                extra = (f"{b['per_step_ms']:.3f} ms/step: elem {100 * b['elements_share']:.0f}% "
                         f"fact {100 * b['factorization_share']:.0f}% "
                         f"subst {100 * b['substitutions_share']:.0f}% "
                         f"rest {100 * b['rest_share']:.0f}%")
            rows.append([r["code"] + ("*" if r["reference"] else ""), str(r["mesh"]),
                         str(r["elements"]), f"{r['dt']:g}",
                         _g(r["wall_s"], ".3f") if r["ok"] else "FAIL",
                         _g(r.get("wall_file_s", math.nan), ".3f"),
                         str(r["steps"]) if r["ok"] else "-",
                         f"{r['newton_iterations'] / max(r['steps'], 1):.2f}" if r["ok"] else "-",
                         _g(r["error"]), _g(r["self_error"]), extra])
        print_table([("code", 17), ("mesh", 4), ("nel", 4), ("dt", 7), ("wall s", 8),
                     ("w/ file s", 9), ("steps", 6), ("newt/st", 7), ("error", 9), ("self err", 9),
                     ("", 1)], rows)
        print("   wall s: the whole call, ancfdrv's in memory (ancfdrv.simulate; the compared "
              "time, as Exudyn's sensor keeps its data in memory); w/ file s: ancfdrv's same call "
              "writing the SPEC HDF5 file (run_scene), repeated after the in-memory call's repeats")
        print("   mesh: ancfdrv nodes, Exudyn elements; * = the code's reference; error: against "
              "ancfdrv's reference; self err: against the own code's reference; ms/step and % "
              "(ancfdrv): stepping time per step and its estimated split (element evaluations, "
              "banded factorization, substitutions; rest = the remainder, negative where the "
              "estimate from separately timed kernel calls overshoots); tol, jac (Exudyn): "
              "Newton absolute tolerance used, Jacobian updates")
        failed = [r for r in rec["runs"] if not r["ok"]]
        for r in failed:
            print(f"   FAILED {r['code']} mesh {r['mesh']} dt {r['dt']:g}: {r['message'][:300]}")
        for bending, key, dom in ((b, k, d) for b, doms in rec["dominance"].items()
                                  for k, d in doms.items()):
            label = ("each code against its own reference" if key == "self_error"
                     else "both against ancfdrv's reference")
            print(f"\n   [ancfdrv bending '{bending}', {key}: {label}] ancfdrv dominates: "
                  f"{'yes' if dom['ancfdrv_dominates'] else 'no'}; Exudyn dominates: "
                  f"{'yes' if dom['exudyn_dominates'] else 'no'}")
            rows = []
            for p in dom["for_each_exudyn_run"]:
                rows.append([f"{p['exudyn'][0]} / {p['exudyn'][1]:g}", _g(p["exudyn_error"]),
                             _g(p["exudyn_wall_s"], ".3f"),
                             f"{p['ancfdrv'][0]} / {p['ancfdrv'][1]:g}" if p["ancfdrv"] else "none",
                             _g(p["ancfdrv_wall_s"], ".3f"),
                             _g(p["time_ratio_ancfdrv_over_exudyn"], ".2f"),
                             _g(p.get("time_ratio_ancfdrv_with_file_over_exudyn"), ".2f")])
            print_table([("Exudyn nel/dt", 16), ("error", 9), ("wall s", 8),
                         ("ancfdrv as good", 16), ("wall s", 8), ("t ratio", 7),
                         ("w/ file", 7)], rows)
    if exudyn_note:
        print(f"\nExudyn was skipped: {exudyn_note}")


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="coarser grids and references, one repeat per run, "
                             "bending 'cubic' only unless --bending is given")
    parser.add_argument("--problems", nargs="+", choices=sorted(PROBLEMS),
                        default=sorted(PROBLEMS), help="which problems (default both)")
    parser.add_argument("--min-time", type=float, default=None,
                        help="repeat a run until the repeats took this long (default 1 s; 0 "
                             "with --quick)")
    parser.add_argument("--max-repeats", type=int, default=3,
                        help="repeats of one run at most (default 3)")
    parser.add_argument("--kernel-min-time", type=float, default=0.05,
                        help="sample length of the kernel timings of the breakdown")
    parser.add_argument("--no-breakdown", dest="breakdown", action="store_false",
                        help="skip the estimate of where ancfdrv's stepping time goes")
    parser.add_argument("--no-svk-check", dest="svk_check", action="store_false",
                        help="skip Exudyn with the St. Venant-Kirchhoff axial force")
    parser.add_argument("--no-exudyn", action="store_true", help="ancfdrv only")
    parser.add_argument("--choose-tol", action="store_true",
                        help="each code's Newton tolerance per run (not the references): the "
                             "loosest that keeps the history within 0.004 %% of the range of "
                             "a tight run's (ancfdrv: 1e-4 ... 1e-10 against 1e-12; Exudyn: "
                             "EXUDYN_TOLERANCES against their first that works)")
    parser.add_argument("--exudyn-symbolic-drive", action="store_true",
                        help="the spin-up's hub drive in Exudyn as a symbolic user function "
                             "(evaluated in C++) instead of a Python one")
    parser.add_argument("--bending", nargs="+", choices=("cubic", "continuum", "cubic-planar",
                                                          "continuum-planar", "cable-planar"),
                        default=None,
                        help="ancfdrv's beam.bending options to run, one curve each; the "
                             "first one's finest run is the common reference (default both; "
                             "cubic with --quick)")
    parser.add_argument("--omp-threads", type=int, default=None,
                        help="OMP_NUM_THREADS for ancfdrv's kernel (default: the environment's, "
                             "else ancfdrv's own default of 1); Exudyn runs on 1 thread")
    parser.add_argument("--output", type=Path, default=None,
                        help="JSON file (default benchmarks/results/peer_exudyn.json, "
                             "peer_exudyn_quick.json with --quick)")
    args = parser.parse_args(argv)
    if args.min_time is None:
        args.min_time = 0.0 if args.quick else 1.0
    if args.bending is None:
        args.bending = ["cubic"] if args.quick else ["cubic", "continuum"]
    if args.output is None:
        args.output = RESULTS / ("peer_exudyn_quick.json" if args.quick else "peer_exudyn.json")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    start = time.perf_counter()
    if args.omp_threads is not None:  # read when the kernel is loaded: set it before
        os.environ["OMP_NUM_THREADS"] = str(args.omp_threads)
    import_ancfdrv()
    from _common import load_average, machine_info, write_report
    from element_cost import omp_max_threads, openmp_runtime

    from ancfdrv import _kernel

    exu, exudyn_note = (None, "--no-exudyn") if args.no_exudyn else import_exudyn(fast=True)
    machine = machine_info()
    kernel_file = Path(_kernel.__file__)
    kernel_mtime = kernel_file.stat().st_mtime
    problems = QUICK_PROBLEMS if args.quick else PROBLEMS
    records: dict[str, dict[str, Any]] = {}
    with tempfile.TemporaryDirectory(prefix="peer_exudyn_") as tmp:
        for name in args.problems:
            records[name] = compare_problem(problems[name], exu, Path(tmp), args)
    machine["load_average_at_end"] = load_average()
    threads = omp_max_threads(openmp_runtime())
    print(f"\nancfdrv kernel: OpenMP {'threads: %d' % threads if threads else 'not loaded'}"
          f" (OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS')}); Exudyn: "
          + (f"{exudyn_version(exu)}, 1 thread" if exu is not None else "skipped"))
    print_tables(records, exudyn_note)
    reinstalled = kernel_file.stat().st_mtime != kernel_mtime
    if reinstalled:
        print("\nWARNING: ancfdrv's kernel module changed during the run (a reinstall): "
              "the runs may mix two builds.")
    report = {
        "benchmark": "peer_exudyn",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "settings": {"quick": args.quick, "min_time_s": args.min_time,
                     "max_repeats": args.max_repeats, "breakdown": args.breakdown,
                     "svk_check": args.svk_check, "bending": args.bending,
                     "exudyn_symbolic_drive": args.exudyn_symbolic_drive,
                     "exudyn_tolerances_tried": EXUDYN_TOLERANCES,
                     "choose_tol": args.choose_tol, "history_keep": HISTORY_KEEP},
        "units": "seconds, metres",
        "machine": machine,
        "ancfdrv_kernel": {"module": str(kernel_file), "reinstalled_during_run": reinstalled,
                           "omp_num_threads_env": os.environ.get("OMP_NUM_THREADS"),
                           "openmp_runtime": openmp_runtime(),
                           "omp_get_max_threads": omp_max_threads(openmp_runtime())},
        "exudyn": {"available": exu is not None, "skipped_because": exudyn_note,
                   "version": exudyn_version(exu) if exu is not None else None},
        "problems": records,
        "wall_time_s": time.perf_counter() - start,
    }
    write_report(args.output, report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
