#!/usr/bin/env python
"""One comparison harness: ancfdrv and the peer code Exudyn on the same problems, timed in
one run; the ratios go to JSON and Markdown (issue 13, item 4).

Problems (``--only`` names; the physical data are read from the ancfdrv scenes, so both
codes solve the same model):

``boom_ffr``
    The luffing boom, ``inputs/boom_luffing.nml`` as shipped (FFR, 28 nodes, 50 kg tip
    mass, Newmark beta = 1/4, gamma = 1/2, dt = 1 ms, 0 ... 10 s, from the static
    equilibrium at phi = 0), against Exudyn's ``ObjectANCFCable2D`` with 27 elements (9 per
    segment, so A1 ... A4 are nodes). Exudyn's model: planar cable, EA, EI = E w h^3 / 12
    and rho A from the scene; the root A1 on a massless arm of length H about the pivot with
    the section along the arm (a ``MarkerBodyPosition`` at the section point -H on the
    cable's normal at A1, pinned to the ground at O by a ``RevoluteJoint2D``: |O A1| = H and
    the normal at A1 along O A1); A2 driven on the luffing circle (``CoordinateConstraint``
    on its x and y with offset user functions, the profile of SPEC section 5); the tip mass
    on the tip node (``MassPoint2D``) with its weight; the moment M_B about +z on the section
    at A2 (``LoadTorqueVector`` on a ``MarkerBodyRigid``); gravity on every element; the same
    Newmark parameters (``generalizedAlpha.useNewmark``), index-3 constraints; the start is
    Exudyn's static equilibrium at phi = 0 with the drive held. Exudyn's cable is
    geometrically exact (large deformation), ancfdrv's FFR model linear in the elastic
    coordinates: the sag histories (transverse tip deflection in the rotating frame
    R(phi(t)), SPEC section 4) are compared with each other and with ancfdrv's converged
    reference (``boom_nonlinear``'s), and the cheapest Exudyn run at least as accurate as
    ancfdrv's gives the ratio at equal accuracy. Exudyn runs in four configurations at 27
    elements: the drive as a symbolic user function (evaluated in C++) or a Python one, and
    modified Newton (Exudyn's default) or full Newton; the fastest gives the headline ratio.
``boom_nonlinear``
    The same boom with ``scene.formulation = nonlinear``, ``beam.bending = cubic``:
    ancfdrv at 4 nodes (and 10) against Exudyn at 9 elements (and 3, 27); the converged
    reference is ancfdrv at 28 nodes. Errors: max |sag - sag_ref| over the history, also in
    % of the reference's sag range (max - min), against ancfdrv's reference and against
    each code's own finest run (the two converged models differ: the gap is reported).
``plate``
    The plate pendulum, ``inputs/plate_pendulum.nml`` (4 x 4, completed variant),
    dt = 1e-4 s, 0 ... 0.3 s, against Exudyn's ``ObjectANCFThinPlate`` (Kirchhoff ANCF
    plate with ``NodePointSlope12`` nodes: the same 36 coordinates per element) on the
    same mesh and step, made by Exudyn's ``exudyn.shells.ShellMesh`` with the plane-stress
    membrane and bending matrices of E, nu and h, spherical joint at the corner (0, 0, 0),
    gravity on every element, generalized-alpha with the scene's rho_inf. Exudyn's element
    integrates with 5 x 5 Gauss points by default (ancfdrv: 4 x 4); its option
    ``useReducedOrderIntegration = 1`` (Lobatto 3 x 3 membrane, Gauss 2 x 2 bending, against
    membrane locking) runs too, as a second, faster but different model. Compared: the
    corner probe (0.3, 0.3, 0): distance between the codes' histories and to ancfdrv's
    finer reference mesh.
``spinup``, ``pendulum``
    ``peer_exudyn.py``'s error-against-time curves with ancfdrv's option of
    ``--hard-bending`` (spin-up; 'cubic-planar' by default, 'cable-planar' the ANCF cable
    clamped to the hub by r and r_x) and ``--pendulum-bending`` ('cable-planar'):
    the spin-up at W = 4 rad/s and at the scene's W = 6 rad/s, the flexible pendulum; for
    each, whether ancfdrv's curve dominates Exudyn's (for every Exudyn run an ancfdrv run
    at least as accurate in no more time), judged against each code's own finest run and
    against ancfdrv's. The spin-up's hub drive in Exudyn is a symbolic user function.
``leaf``
    The two-leaf spring, ``inputs/leaf_spring.nml`` (0 ... 5 s, dt = 1 ms), ancfdrv
    alone: its dynamic wall time, Newton corrections and factorizations per step against
    the earlier figure of the README (32.6 s, 3.67 corrections per step: stored numbers,
    reported as such, not measured here), and the chassis history, stored every 5 ms; a
    later run compares its history with the stored one (to 1e-4 of each component's range).

Timing: every timed solve runs ``--repeats`` times (3) and keeps the best; repeats stop
early once the samples of one measurement took ``--budget`` seconds (30). ancfdrv runs
through :func:`ancfdrv.runner.run_scene` (HDF5 to a temporary directory): ``solve`` is the
dynamic solve's ``wall_time_s`` from the file's ``/dynamic`` attributes, ``whole`` the whole
call (scene, model, static start, dynamics, output). Exudyn: ``solve`` is
``mbs.SolveDynamic``, ``whole`` builds the system, assembles it, solves the static start and
the dynamics and reads the sensor. Interpreter start-up and imports are excluded (``levels``
also times the command line: a fresh interpreter per call, each code installed and
byte-compiled as a user has it, see :func:`command_line`). Ratios are Exudyn's time /
ancfdrv's, both measured in this run (> 1: ancfdrv is faster).

Exudyn runs as a user tuning it would run it (issue 38): its ``exudynCPPfast`` module, one
thread, no solution file, sensors every 0.01 s; the boom with Newton tolerances 1e-2
(absolute) / 1e-5 (relative) and contractivity 0.05, its dense LU below 6 elements
(``levels``: both LUs below 10 elements); the spin-up updating its Jacobian at most once a
step. ancfdrv runs with its defaults (one OpenMP thread, ``newton_tol = 1e-10``) without the
XDMF file. In ``levels``, ``spinup`` and ``pendulum`` both codes' Newton tolerances are
chosen in the run by one rule (``_peer.loosest_keeping``, issue 38): per timed
configuration, the loosest of a fixed list whose history stays within 0.004 % of its range
of the same configuration at a tight setting (ancfdrv: ``newton_tol`` 1e-4, 1e-6, 1e-8,
1e-10 against 1e-12; Exudyn: the boom's 1e-2/1e-5 or 1e-3/1e-6 against its defaults, the
pendulum's and the spin-up's lists in ``peer_exudyn.EXUDYN_TOLERANCES``); the references
keep each code's default (the spin-up's Exudyn: its first tolerances that work).

``levels``
    Each accuracy level's (3, 1, 0.3, 0.1, 0.03 % of the sag range) fastest configuration
    of each code on the luffing boom (m = 50 and 0 kg, ``--masses``), chosen from a grid over
    the mesh and the time step (5e-4 ... 2e-2 s) for both codes, against ancfdrv's cable
    converged in space and time (55 nodes, dt 2.5e-4 s, checked against half the mesh and
    twice the step) and against each code's own converged run; whole-call (in memory, like
    Exudyn's: ``ancfdrv.simulate``; the call writing the HDF5 file beside it), solve and
    command-line times. ``spinup`` and ``pendulum`` get the same level table from their
    grids (coarse steps included).

Output: ``benchmarks/results/peer_harness.json`` and ``peer_harness.md`` (with ``--quick``:
``peer_harness_quick.json``, ignored by git, and the Markdown inside the JSON only).
Run from the repository root::

    python benchmarks/peer_harness.py             # all problems, about 6 minutes on 2 cores
    python benchmarks/peer_harness.py --quick     # short runs and coarse grids, ~30 s smoke run
    python benchmarks/peer_harness.py --only boom_ffr,plate --repeats 5
    python benchmarks/peer_harness.py --no-exudyn # ancfdrv only

When Exudyn cannot be imported (``pip install exudyn``), its runs are skipped and the
ratios are null.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import importlib
import json
import math
import os
import sys
import tempfile
import time
import warnings
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

if TYPE_CHECKING:
    import h5py

from _peer import (HISTORY_KEEP, exudyn_build, exudyn_version, import_exudyn,
                   loosest_keeping, quiet_settings, run_quietly, set_setting)

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
PROBLEM_NAMES = ("boom_ffr", "boom_nonlinear", "plate", "spinup", "pendulum", "leaf",
                 "levels")

#: The figures of issue 13 and of the README, reported next to the measured ones; never
#: used in a ratio.
STORED_FIGURES: dict[str, dict[str, Any]] = {
    "boom_ffr": {"source": "issue 13", "ancfdrv_s": 0.94, "exudyn_s": 5.4,
                 "exudyn_over_ancfdrv": 5.7},
    "boom_nonlinear": {"source": "issue 13", "ancfdrv_s": 0.93,
                       "ancfdrv_error_percent_of_range": 0.07, "exudyn_elements": 9,
                       "exudyn_error_percent_of_range": 0.03, "exudyn_s": [1.3, 2.0]},
    "plate": {"source": "issue 13", "exudyn_over_ancfdrv": [1.1, 1.3]},
    "leaf": {"source": "benchmarks/README.md (leaf_contact_cost.py, the scene's 0..5 s run "
                       "with `ancf run`)", "dynamic_wall_time_s": 32.6, "steps": 5000,
             "newton_per_step": 3.67, "ms_per_step": 6.52},
}
#: The leaf spring's histories are compared to this fraction of each component's range.
LEAF_HISTORY_TOLERANCE = 1e-4


@dataclass(frozen=True)
class Plan:
    """What one invocation runs (full or ``--quick``)."""

    boom_t_end: float | None              # None: the scene's
    boom_cubic_nodes: tuple[int, ...]     # ancfdrv 'nonlinear' runs, bending 'cubic'
    boom_reference_nodes: int             # ancfdrv's converged reference
    boom_headline_nodes: int              # boom_nonlinear's ancfdrv run of the ratio
    boom_exudyn_per_segment: tuple[int, ...]
    boom_headline_per_segment: dict[str, int]   # boom_ffr / boom_nonlinear: Exudyn's run
    boom_variants: bool                   # the four Exudyn configurations at boom_ffr's mesh
    plate_t_end: float
    plate_dt: float
    plate_reference: tuple[int, float]    # ancfdrv's reference mesh (nx = ny) and dt
    plate_sample_dt: float
    leaf_t_end: float | None
    leaf_store_dt: float
    hard_quick: bool


FULL = Plan(boom_t_end=None, boom_cubic_nodes=(4, 10), boom_reference_nodes=28,
            boom_headline_nodes=4, boom_exudyn_per_segment=(1, 3, 9),
            boom_headline_per_segment={"boom_ffr": 9, "boom_nonlinear": 3},
            boom_variants=True, plate_t_end=0.3, plate_dt=1e-4, plate_reference=(12, 2e-3),
            plate_sample_dt=0.01, leaf_t_end=None, leaf_store_dt=5e-3, hard_quick=False)
QUICK = Plan(boom_t_end=2.0, boom_cubic_nodes=(4,), boom_reference_nodes=10,
             boom_headline_nodes=4, boom_exudyn_per_segment=(1, 3),
             boom_headline_per_segment={"boom_ffr": 3, "boom_nonlinear": 3},
             boom_variants=False, plate_t_end=0.03, plate_dt=1e-4, plate_reference=(8, 1e-3),
             plate_sample_dt=0.01, leaf_t_end=0.2, leaf_store_dt=5e-3, hard_quick=True)


# -- timing ------------------------------------------------------------------------------------
@dataclass
class Timed:
    """One timed solve of one code: settings, best times, counts and the compared history."""

    code: str                       # 'ancfdrv' or 'exudyn'
    label: str
    settings: dict[str, Any]
    ok: bool = False
    message: str = ""
    solve_s: float = math.nan       # best of the repeats
    whole_s: float = math.nan
    solve_samples: list[float] = field(default_factory=list)
    whole_samples: list[float] = field(default_factory=list)
    counts: dict[str, Any] = field(default_factory=dict)
    time: np.ndarray | None = None      # the history's times (the problem's sample grid)
    values: np.ndarray | None = None    # the compared quantity at those times
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def history(self) -> np.ndarray:
        if self.values is None:
            raise ValueError(f"{self.code} {self.label} has no history: {self.message}")
        return self.values

    def summary(self) -> dict[str, Any]:
        out = asdict(self)
        out.pop("time")
        out.pop("values")
        return out


Once = Callable[[], tuple[float, float, dict[str, Any]]]


def best_of(timed: Timed, once: Once, repeats: int, budget_s: float,
            errors: tuple[type[BaseException], ...]) -> Timed:
    """Run ``once`` (returns solve s, whole s, payload) up to ``repeats`` times, fewer once
    the samples took ``budget_s``; keep the best times and the last payload. An exception of
    ``errors`` is recorded as the run's failure."""
    payload: dict[str, Any] = {}
    started = time.perf_counter()
    try:
        while len(timed.whole_samples) < max(repeats, 1):
            solve_s, whole_s, payload = once()
            timed.solve_samples.append(solve_s)
            timed.whole_samples.append(whole_s)
            if sum(timed.whole_samples) >= budget_s:
                break
    except errors as exc:
        timed.message = f"{type(exc).__name__}: {exc}"
        timed.extra["time_to_failure_s"] = time.perf_counter() - started
        return timed
    timed.ok = True
    timed.solve_s, timed.whole_s = min(timed.solve_samples), min(timed.whole_samples)
    timed.counts = payload.pop("counts", {})
    timed.time, timed.values = payload.pop("time", None), payload.pop("values", None)
    timed.extra.update(payload)
    return timed


def progress(problem: str, run: Timed) -> None:
    state = (f"solve {run.solve_s:7.3f} s, whole {run.whole_s:7.3f} s, {len(run.whole_samples)}x"
             if run.ok else f"FAILED: {run.message[:120]}")
    print(f"  {problem:>14} {run.code:>7} {run.label:<34} {state}", file=sys.stderr, flush=True)


def ancfdrv_errors() -> tuple[type[BaseException], ...]:
    from ancfdrv.errors import AncfError
    return (AncfError, ValueError)


def run_ancfdrv(label: str, scene: str, overrides: list[str], out: Path,
                read: Callable[[h5py.File], dict[str, Any]], repeats: int,
                budget_s: float) -> Timed:
    """run_scene on ``scene`` with ``overrides``; ``read`` takes the compared history
    (keys 'time', 'values' and any extras) from the result file."""
    import h5py

    from ancfdrv.runner import run_scene

    timed = Timed("ancfdrv", label, {"scene": scene, "overrides": list(overrides)})

    def once() -> tuple[float, float, dict[str, Any]]:
        t0 = time.perf_counter()
        outcome = run_scene(REPO / scene, overrides, out, progress=False)
        whole = time.perf_counter() - t0
        with h5py.File(out, "r") as h5:
            attrs = h5["dynamic"].attrs
            counts = {k: int(attrs[k]) for k in ("steps", "newton_iterations",
                                                 "factorizations") if k in attrs}
            payload = read(h5)
            payload["timing"] = {k: float(v) for k, v in h5["timing"].attrs.items()}
            solve = float(attrs["wall_time_s"])
        payload.update(counts=counts, warnings=list(outcome.warnings))
        return solve, whole, payload

    return best_of(timed, once, repeats, budget_s, ancfdrv_errors())


def resample(grid: np.ndarray, t: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` (rows at times ``t``) at the grid's times; the grid's times are computed
    times (every step divides the sample interval), so this only absorbs round-off."""
    if t[-1] < grid[-1] - 1e-9 * max(1.0, grid[-1]):
        raise ValueError(f"the history ends at t = {t[-1]:g} s, before {grid[-1]:g} s")
    if values.ndim == 1:
        return np.interp(grid, t, values)
    return np.column_stack([np.interp(grid, t, values[:, k]) for k in range(values.shape[1])])


def uniform_grid(t_end: float, step: float) -> np.ndarray:
    return step * np.arange(int(round(t_end / step)) + 1)


def max_difference(a: np.ndarray, b: np.ndarray) -> float:
    """max_k |a_k - b_k| (Euclidean norm per row for vector histories)."""
    d = np.asarray(a) - np.asarray(b)
    return float(np.max(np.abs(d) if d.ndim == 1 else np.linalg.norm(d, axis=1)))


def ratio(num: float, den: float) -> float:
    return num / den if math.isfinite(num) and math.isfinite(den) and den > 0 else math.nan


# -- the boom ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class Boom:
    """The boom of SPEC section 5 as the scene gives it."""

    length: float
    segments: tuple[float, ...]
    width: float
    height: float
    youngs: float
    density: float
    pivot: float                 # H
    phi0: float                  # rad
    sweep: float                 # rad, phi_end - phi0
    omega: float
    t_start: float
    t_brake: float
    gravity: float
    tip_mass: float
    moment: float
    dt: float
    t_end: float
    integrator: str
    beta: float
    gamma: float
    rho_inf: float

    @property
    def t_luff_end(self) -> float:
        """t1: end of the constant-rate stage."""
        t_const = abs(self.sweep) / self.omega - 0.5 * (self.t_start + self.t_brake)
        return self.t_start + t_const

    @property
    def area(self) -> float:
        return self.width * self.height

    @property
    def inertia(self) -> float:
        return self.width * self.height ** 3 / 12.0   # bending in the r1-r2 plane


def boom_from_scene(scene_path: str, overrides: list[str]) -> Boom:
    from ancfdrv.io.scene import load_scene

    scene = load_scene(REPO / scene_path, overrides)
    beam, material, boom, loads, solver = (scene[g] for g in ("beam", "material", "boom",
                                                              "loads", "solver"))
    if boom["omega"] <= 0 or len(beam["segments"]) != 3:
        raise ValueError(f"{scene_path}: the harness needs a luffing boom with 3 segments")
    effects = scene.effects
    return Boom(length=beam["length"], segments=tuple(beam["segments"]), width=beam["width"],
                height=beam["height"], youngs=material["youngs_modulus"],
                density=material["density"], pivot=boom["pivot_offset"],
                phi0=math.radians(boom["angle_deg"]),
                sweep=math.radians(boom["angle_end_deg"] - boom["angle_deg"]),
                omega=boom["omega"], t_start=boom["t_start"], t_brake=boom["t_brake"],
                gravity=loads["gravity"] if "gravity" in effects else 0.0,
                tip_mass=loads["tip_mass"] if "tip_mass" in effects else 0.0,
                moment=loads["moment"] if "bending_moment" in effects else 0.0,
                dt=solver["dt"], t_end=solver["t_end"], integrator=solver["integrator"],
                beta=solver["beta"], gamma=solver["gamma"], rho_inf=solver["rho_inf"])


def _select(condition: Any, if_true: Any, if_false: Any) -> Any:
    return if_true if condition else if_false


def luffing_angle(boom: Boom, t: Any, sin: Callable[[Any], Any] = math.sin,
                  select: Callable[[Any, Any, Any], Any] = _select,
                  constant: Callable[[float], Any] = float) -> Any:
    """phi(t) of SPEC section 5 in closed form: the integral of the smooth start, constant
    rate and smooth braking. With Exudyn's symbolic ``sin``, ``IfThenElse`` and ``Real`` it
    builds the same expression for C++ evaluation."""
    w, ts, tb, t1 = boom.omega, boom.t_start, boom.t_brake, boom.t_luff_end
    t2 = t1 + tb
    start = 0.5 * w * (t - ts / math.pi * sin(math.pi * t / ts))
    steady = 0.5 * w * ts + w * (t - ts)
    brake = 0.5 * w * ts + w * (t1 - ts) + 0.5 * w * (
        (t - t1) + tb / math.pi * sin(math.pi * (t - t1) / tb))
    rise = select(t < ts, start, select(t < t1, steady, select(
        t < t2, brake, constant(abs(boom.sweep)))))
    return boom.phi0 + math.copysign(1.0, boom.sweep) * rise


def angle_from_file(boom: Boom, tip: np.ndarray, deflection: np.ndarray) -> np.ndarray:
    """The frame angle an ancfdrv boom file implies: tip = R(phi) ((L, H) + deflection)."""
    local = deflection[:, :2] + [boom.length, boom.pivot]
    return np.arctan2(tip[:, 1], tip[:, 0]) - np.arctan2(local[:, 1], local[:, 0])


def boom_reader(boom: Boom, grid: np.ndarray) -> Callable[[h5py.File], dict[str, Any]]:
    """The transverse tip deflection on the grid, and how far the file's frame angle is
    from :func:`luffing_angle`."""
    def read(h5: h5py.File) -> dict[str, Any]:
        t = h5["dynamic/time"][()]
        deflection = h5["dynamic/deflection/tip"][()]
        tip = h5["dynamic/probes/tip"][()]
        phi = np.array([luffing_angle(boom, s) for s in t])
        angle_gap = float(np.max(np.abs(angle_from_file(boom, tip, deflection) - phi)))
        return {"time": grid, "values": resample(grid, t, deflection[:, 1]),
                "luffing_angle_vs_file_max_abs": angle_gap}
    return read


def exudyn_boom(exu: Any, boom: Boom, per_segment: int) -> dict[str, Any]:
    """The boom on a fresh Exudyn system (see the module docstring), assembled, without
    its drive: A2 is held at its reference position until :func:`attach_drive`."""
    from exudyn.itemInterface import (CoordinateConstraint, LoadForceVector,
                                      LoadMassProportional, LoadTorqueVector, MarkerBodyMass,
                                      MarkerBodyPosition, MarkerBodyRigid, MarkerNodeCoordinate,
                                      MarkerNodePosition, MassPoint2D, NodePoint2DSlope1,
                                      NodePointGround, ObjectANCFCable2D, ObjectGround,
                                      RevoluteJoint2D, SensorNode)

    container = exu.SystemContainer()
    mbs = container.AddSystem()
    edges = np.concatenate([[0.0], np.cumsum(boom.segments)])
    s = np.concatenate([np.linspace(a, b, per_segment + 1)[:-1]
                        for a, b in zip(edges[:-1], edges[1:])] + [[edges[-1]]])
    c, si = math.cos(boom.phi0), math.sin(boom.phi0)
    nodes = [mbs.AddNode(NodePoint2DSlope1(referenceCoordinates=[
        c * x - si * boom.pivot, si * x + c * boom.pivot, c, si])) for x in s]
    elements = []
    for k in range(len(s) - 1):
        element = mbs.AddObject(ObjectANCFCable2D(
            length=s[k + 1] - s[k], massPerLength=boom.density * boom.area,
            bendingStiffness=boom.youngs * boom.inertia, axialStiffness=boom.youngs * boom.area,
            nodeNumbers=[nodes[k], nodes[k + 1]]))
        elements.append(element)
        if boom.gravity:
            mass = mbs.AddMarker(MarkerBodyMass(bodyNumber=element))
            mbs.AddLoad(LoadMassProportional(markerNumber=mass,
                                             loadVector=[0.0, -boom.gravity, 0.0]))
    # A1 on the arm: the section point at -H on the normal is pinned at the pivot O
    ground = mbs.AddObject(ObjectGround())
    pivot = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))
    arm_end = mbs.AddMarker(MarkerBodyPosition(bodyNumber=elements[0],
                                               localPosition=[0.0, -boom.pivot, 0.0]))
    mbs.AddObject(RevoluteJoint2D(markerNumbers=[pivot, arm_end]))
    # A2 on the luffing circle: its displacement from the reference (offsets set later)
    a2 = nodes[per_segment]
    ground_node = mbs.AddNode(NodePointGround())
    ground_coordinate = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground_node, coordinate=0))
    drive = [mbs.AddObject(CoordinateConstraint(markerNumbers=[
        ground_coordinate, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=a2, coordinate=k))]))
        for k in (0, 1)]
    if boom.moment:
        section = mbs.AddMarker(MarkerBodyRigid(bodyNumber=elements[per_segment],
                                                localPosition=[0.0, 0.0, 0.0]))
        mbs.AddLoad(LoadTorqueVector(markerNumber=section, loadVector=[0.0, 0.0, boom.moment]))
    tip = nodes[-1]
    if boom.tip_mass:
        mbs.AddObject(MassPoint2D(mass=boom.tip_mass, nodeNumber=tip))
        if boom.gravity:
            mbs.AddLoad(LoadForceVector(markerNumber=mbs.AddMarker(MarkerNodePosition(
                nodeNumber=tip)), loadVector=[0.0, -boom.tip_mass * boom.gravity, 0.0]))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=tip, storeInternal=True,
                                      outputVariableType=exu.OutputVariableType.Position))
    mbs.Assemble()
    return {"container": container, "mbs": mbs, "sensor": sensor, "drive": drive,
            "a2_reference": (c * edges[1] - si * boom.pivot, si * edges[1] + c * boom.pivot)}


def attach_drive(exu: Any, model: dict[str, Any], boom: Boom, symbolic: bool) -> None:
    """A2's x and y follow R(phi(t)) (a, H): offsets from A2's reference position, as
    Python or symbolic user functions."""
    mbs, (x0, y0) = model["mbs"], model["a2_reference"]
    a, h = boom.segments[0], boom.pivot
    if symbolic:
        from exudyn.advancedUtilities import CreateSymbolicUserFunction
        esym = exu.symbolic

        def angle(t: Any) -> Any:
            return luffing_angle(boom, t, esym.sin, esym.IfThenElse, esym.Real)

        def x_offset(mbs_: Any, t: Any, item: int, offset: Any) -> Any:
            phi = angle(t)
            return a * esym.cos(phi) - h * esym.sin(phi) - x0

        def y_offset(mbs_: Any, t: Any, item: int, offset: Any) -> Any:
            phi = angle(t)
            return a * esym.sin(phi) + h * esym.cos(phi) - y0

        functions = [CreateSymbolicUserFunction(mbs, f, "offsetUserFunction",
                                                itemTypeName="ObjectConnectorCoordinate")
                     for f in (x_offset, y_offset)]
        mbs.variables["symbolic_user_functions"] = functions  # keep them alive
    else:
        def x_python(mbs_: Any, t: float, item: int, offset: float) -> float:
            phi = luffing_angle(boom, t)
            return a * math.cos(phi) - h * math.sin(phi) - x0

        def y_python(mbs_: Any, t: float, item: int, offset: float) -> float:
            phi = luffing_angle(boom, t)
            return a * math.sin(phi) + h * math.cos(phi) - y0

        functions = [x_python, y_python]
    for constraint, function in zip(model["drive"], functions):
        mbs.SetObjectParameter(constraint, "offsetUserFunction", function)


#: Exudyn's sensors store every 0.01 s (not every step: a sensor row costs time).
EXUDYN_SENSOR_PERIOD = 0.01
#: Exudyn's dense LU is the faster below about 6 elements, its sparse LU above.
DENSE_BELOW_ELEMENTS = 6


@dataclass(frozen=True)
class ExudynNewton:
    """Exudyn's Newton settings of one run; None keeps Exudyn's default."""

    label: str
    absolute: float | None = None
    relative: float | None = None
    contractivity: float | None = None
    jacobian_update_per_step: bool = False

    def apply(self, newton: Any) -> None:
        """Set these values on ``settings.timeIntegration.newton``."""
        for name, value in (("absoluteTolerance", self.absolute),
                            ("relativeTolerance", self.relative),
                            ("modifiedNewtonContractivity", self.contractivity)):
            if value is not None:
                setattr(newton, name, value)
        if self.jacobian_update_per_step:
            newton.modifiedNewtonJacUpdatePerStep = True


#: The boom's Newton settings of issue 38 (the loosest that kept Exudyn's history there) and
#: the tighter ones it was re-timed at; the converged reference runs at Exudyn's defaults.
#: ``levels`` chooses among them per configuration (LEVEL_EXUDYN_NEWTON).
BOOM_NEWTON = ExudynNewton("tol 1e-2/1e-5", 1e-2, 1e-5, 0.05)
BOOM_NEWTON_TIGHT = ExudynNewton("tol 1e-3/1e-6", 1e-3, 1e-6, 0.05)
DEFAULT_NEWTON = ExudynNewton("default tol")


def boom_settings(exu: Any, boom: Boom, full_newton: bool, dense: bool,
                  newton: ExudynNewton = BOOM_NEWTON) -> Any:
    """Exudyn's dynamic settings for the boom: fixed steps of ``boom.dt``, the scene's
    integrator, one thread, sensors every EXUDYN_SENSOR_PERIOD, no solution file, the given
    Newton tolerances and its dense or sparse LU."""
    settings = exu.SimulationSettings()
    integration = settings.timeIntegration
    integration.numberOfSteps = int(round(boom.t_end / boom.dt))
    integration.endTime = boom.t_end
    integration.adaptiveStep = False
    integration.verboseMode = 0
    alpha = integration.generalizedAlpha
    if boom.integrator == "newmark":
        alpha.useNewmark = True
        alpha.newmarkBeta, alpha.newmarkGamma = boom.beta, boom.gamma
    else:
        alpha.spectralRadius = boom.rho_inf
    integration.newton.useModifiedNewton = not full_newton
    newton.apply(integration.newton)
    quiet_settings(exu, settings, EXUDYN_SENSOR_PERIOD)
    if dense:
        set_setting(settings, "linearSolver.solverType", exu.LinearSolverType.EigenDense)
    return settings


def run_exudyn_boom(exu: Any, boom: Boom, per_segment: int, symbolic: bool, full_newton: bool,
                    grid: np.ndarray, repeats: int, budget_s: float,
                    newton: ExudynNewton = BOOM_NEWTON, dense: bool | None = None) -> Timed:
    """Exudyn's boom (``3 per_segment`` elements, steps of ``boom.dt``), timed: ``solve`` is
    ``SolveDynamic``, ``whole`` the build, static start, dynamics and sensor read. ``dense``
    None: the dense LU below DENSE_BELOW_ELEMENTS elements."""
    elements = 3 * per_segment
    dense = elements < DENSE_BELOW_ELEMENTS if dense is None else dense
    config = (f"{'symbolic' if symbolic else 'Python'} drive, "
              f"{'full' if full_newton else 'modified'} Newton")
    timed = Timed("exudyn", f"{elements} el, {config}",
                  {"elements": elements, "drive": "symbolic" if symbolic else "python",
                   "newton": "full" if full_newton else "modified", "dt": boom.dt,
                   "tolerances": asdict(newton), "solver": "dense" if dense else "sparse"})

    def once() -> tuple[float, float, dict[str, Any]]:
        t0 = time.perf_counter()
        model = exudyn_boom(exu, boom, per_segment)
        mbs = model["mbs"]
        static = exu.SimulationSettings()
        static.staticSolver.verboseMode = 0
        quiet_settings(exu, static, EXUDYN_SENSOR_PERIOD)
        run_quietly(lambda: mbs.SolveStatic(static))
        mbs.systemData.SetODE2Coordinates(mbs.systemData.GetODE2Coordinates(),
                                          configuration=exu.ConfigurationType.Initial)
        attach_drive(exu, model, boom, symbolic)
        settings = boom_settings(exu, boom, full_newton, dense, newton)
        t1 = time.perf_counter()
        run_quietly(lambda: mbs.SolveDynamic(
            settings, solverType=exu.DynamicSolverType.GeneralizedAlpha))
        solve = time.perf_counter() - t1
        data = mbs.GetSensorStoredData(model["sensor"])
        whole = time.perf_counter() - t0
        phi = np.array([luffing_angle(boom, s) for s in data[:, 0]])
        sag = -np.sin(phi) * data[:, 1] + np.cos(phi) * data[:, 2] - boom.pivot
        it = mbs.sys["dynamicSolver"].it
        counts = {"steps": int(settings.timeIntegration.numberOfSteps),
                  "newton_iterations": int(it.newtonStepsCount),
                  "jacobians": int(it.newtonJacobiCount)}
        return solve, whole, {"counts": counts, "time": grid,
                              "values": resample(grid, data[:, 0], sag)}

    return best_of(timed, once, repeats, budget_s, (RuntimeError, ValueError))


def boom_error(run: Timed, reference: Timed, sag_range: float) -> dict[str, float]:
    if not (run.ok and reference.ok):
        return {"max_abs_m": math.nan, "percent_of_range": math.nan}
    err = max_difference(run.history, reference.history)
    return {"max_abs_m": err, "percent_of_range": 100.0 * err / sag_range}


def static_closed_form(boom: Boom) -> dict[str, float]:
    """The linear closed-form static sag at phi0 (Euler-Bernoulli; Timoshenko, k = 1)."""
    try:
        from ancfdrv.reference.analytic import boom_static_tip_deflection
    except ImportError as exc:  # the reference module may move
        return {"unavailable": str(exc)}  # type: ignore[dict-item]
    kwargs = dict(length=boom.length, a=boom.segments[0], H=boom.pivot, width=boom.width,
                  height=boom.height, youngs=boom.youngs, density=boom.density, poisson=0.0,
                  gravity=boom.gravity, moment=boom.moment)
    return {"euler_bernoulli_m": boom_static_tip_deflection(
                math.degrees(boom.phi0), boom.tip_mass, shear=False, **kwargs)[1],
            "timoshenko_k1_m": boom_static_tip_deflection(
                math.degrees(boom.phi0), boom.tip_mass, shear=True, **kwargs)[1]}


class BoomRuns:
    """The boom's runs, made once per invocation and shared by boom_ffr and
    boom_nonlinear (Exudyn's cable is the same model for both)."""

    def __init__(self, plan: Plan, exu: Any, workdir: Path, args: argparse.Namespace) -> None:
        self.plan, self.exu, self.workdir, self.args = plan, exu, workdir, args
        self.scene = "inputs/boom_luffing.nml"
        self.base = ([f"solver.t_end={plan.boom_t_end!r}"] if plan.boom_t_end else [])
        self.boom = boom_from_scene(self.scene, self.base)
        self.grid = uniform_grid(self.boom.t_end, EXUDYN_SENSOR_PERIOD)
        self.runs: dict[tuple[Any, ...], Timed] = {}

    def _get(self, key: tuple[Any, ...], make: Callable[[], Timed]) -> Timed:
        if key not in self.runs:
            self.runs[key] = make()
            progress("boom", self.runs[key])
        return self.runs[key]

    def ancfdrv(self, formulation: str, nodes: int, repeats: int | None = None) -> Timed:
        overrides = [*self.base, f"beam.nodes={nodes}"]
        if formulation == "nonlinear":
            overrides += ["scene.formulation=nonlinear", "solver.static_method=newton",
                          "beam.bending=cubic"]
        label = f"{'FFR' if formulation == 'ffr' else 'nonlinear cubic'} {nodes} nodes"
        return self._get(("ancfdrv", formulation, nodes), lambda: run_ancfdrv(
            label, self.scene, overrides, self.workdir / f"boom_{formulation}_{nodes}.h5",
            boom_reader(self.boom, self.grid), repeats or self.args.repeats, self.args.budget))

    def reference(self) -> Timed:
        run = self.ancfdrv("nonlinear", self.plan.boom_reference_nodes, repeats=1)
        if not run.ok:
            raise RuntimeError(f"ancfdrv's boom reference failed: {run.message}")
        return run

    def exudyn(self, per_segment: int, symbolic: bool = True, full_newton: bool = False) -> Timed:
        return self._get(("exudyn", per_segment, symbolic, full_newton), lambda: run_exudyn_boom(
            self.exu, self.boom, per_segment, symbolic, full_newton, self.grid,
            self.args.repeats, self.args.budget))

    def record(self) -> dict[str, Any]:
        return {"boom": asdict(self.boom), "sample_dt": EXUDYN_SENSOR_PERIOD,
                "static_sag_closed_form": static_closed_form(self.boom)}


def fastest(runs: list[Timed], key: str = "solve_s") -> Timed | None:
    good = [r for r in runs if r.ok]
    return min(good, key=lambda r: getattr(r, key)) if good else None


def run_row(run: Timed, errors: dict[str, Any] | None = None) -> dict[str, Any]:
    row = {"code": run.code, "label": run.label, "ok": run.ok, "solve_s": run.solve_s,
           "whole_s": run.whole_s, "repeats": len(run.whole_samples), **run.counts}
    if run.values is not None and run.values.ndim == 1:
        row["static_sag_m"] = float(run.values[0])
    if errors:
        row.update(errors)
    if not run.ok:
        row["message"] = run.message
    return row


def compare_boom_ffr(runs: BoomRuns) -> dict[str, Any]:
    plan, exu = runs.plan, runs.exu
    ffr = runs.ancfdrv("ffr", 28)
    reference = runs.reference()
    sag_range = float(np.ptp(reference.history))
    record: dict[str, Any] = {"reference": reference.label, "reference_sag_range_m": sag_range,
                              "ancfdrv": run_row(ffr, {"error_vs_reference": boom_error(
                                  ffr, reference, sag_range)})}
    if ffr.ok:
        record["luffing_angle_vs_ancfdrv_file_max_abs_rad"] = ffr.extra[
            "luffing_angle_vs_file_max_abs"]
    if exu is None:
        return record
    headline_k = plan.boom_headline_per_segment["boom_ffr"]
    configs = ([(True, False), (False, False), (True, True), (False, True)]
               if plan.boom_variants else [(True, False)])
    variants = [runs.exudyn(headline_k, sym, full) for sym, full in configs]
    curve = [runs.exudyn(k) for k in plan.boom_exudyn_per_segment]
    best = fastest(variants)
    rows = []
    for run in variants:
        rows.append(run_row(run, {
            "error_vs_reference": boom_error(run, reference, sag_range),
            "error_vs_ancfdrv_ffr": boom_error(run, ffr, sag_range),
            "exudyn_over_ancfdrv_solve": ratio(run.solve_s, ffr.solve_s),
            "exudyn_over_ancfdrv_whole": ratio(run.whole_s, ffr.whole_s)}))
    record["exudyn_variants"] = rows
    # the curve's other meshes (the headline mesh is already among the variants)
    record["exudyn_curve"] = [run_row(run, {"error_vs_reference": boom_error(
        run, reference, sag_range)}) for run in curve if all(run is not v for v in variants)]
    if best is not None and ffr.ok:
        record["headline"] = {
            "ancfdrv": ffr.label, "exudyn": best.label,
            "ancfdrv_solve_s": ffr.solve_s, "exudyn_solve_s": best.solve_s,
            "ancfdrv_whole_s": ffr.whole_s, "exudyn_whole_s": best.whole_s,
            "exudyn_over_ancfdrv_solve": ratio(best.solve_s, ffr.solve_s),
            "exudyn_over_ancfdrv_whole": ratio(best.whole_s, ffr.whole_s),
            "ancfdrv_error_percent": boom_error(ffr, reference, sag_range)["percent_of_range"],
            "exudyn_error_percent": boom_error(best, reference, sag_range)["percent_of_range"],
            "difference_between_codes_percent": 100.0 * max_difference(
                ffr.history, best.history) / sag_range}
        target = boom_error(ffr, reference, sag_range)["max_abs_m"]
        as_good = [r for r in curve + variants if r.ok
                   and boom_error(r, reference, sag_range)["max_abs_m"] <= target]
        cheapest = fastest(as_good)
        record["equal_accuracy"] = {
            "ancfdrv_error_m": target,
            "cheapest_exudyn_as_accurate": cheapest.label if cheapest else None,
            "exudyn_error_m": boom_error(cheapest, reference, sag_range)["max_abs_m"]
            if cheapest else None,
            "exudyn_solve_s": cheapest.solve_s if cheapest else None,
            "exudyn_over_ancfdrv_solve": ratio(cheapest.solve_s, ffr.solve_s)
            if cheapest else None}
    record["histories"] = histories(runs.grid, {"reference": reference, "ancfdrv_ffr": ffr,
                                                "exudyn": best}, 0.02)
    return record


def as_peer_run(run: Timed, mesh: int, dt: float, error: float, self_error: float) -> Any:
    """A ``peer_exudyn.Run`` for its dominance machinery (time: the dynamic solve)."""
    import peer_exudyn as pe
    return pe.Run(run.code, mesh, mesh - 1 if run.code == "ancfdrv" else mesh, dt,
                  ok=run.ok, wall_s=run.solve_s, error=error, self_error=self_error)


def compare_boom_nonlinear(runs: BoomRuns) -> dict[str, Any]:
    import peer_exudyn as pe

    plan, exu = runs.plan, runs.exu
    reference = runs.reference()
    sag_range = float(np.ptp(reference.history))
    ours = [runs.ancfdrv("nonlinear", n) for n in plan.boom_cubic_nodes]
    headline = runs.ancfdrv("nonlinear", plan.boom_headline_nodes)
    record: dict[str, Any] = {"reference": reference.label, "reference_sag_range_m": sag_range,
                              "reference_run": run_row(reference)}
    record["ancfdrv"] = [run_row(r, {"error_vs_reference": boom_error(r, reference, sag_range)})
                         for r in ours]
    if exu is None:
        return record
    peer = [runs.exudyn(k) for k in plan.boom_exudyn_per_segment]
    finest = peer[-1]
    for row, run in zip(record["ancfdrv"], ours):
        row["error_vs_exudyn_finest"] = boom_error(run, finest, sag_range)
    record["exudyn"] = [run_row(r, {
        "error_vs_reference": boom_error(r, reference, sag_range),
        "error_vs_exudyn_finest": boom_error(r, finest, sag_range)}) for r in peer]
    record["model_gap"] = {"finest_runs": [reference.label, finest.label],
                           **boom_error(finest, reference, sag_range)}
    exu_headline = runs.exudyn(plan.boom_headline_per_segment["boom_nonlinear"])
    if headline.ok and exu_headline.ok:
        record["headline"] = {
            "ancfdrv": headline.label, "exudyn": exu_headline.label,
            "ancfdrv_solve_s": headline.solve_s, "exudyn_solve_s": exu_headline.solve_s,
            "ancfdrv_whole_s": headline.whole_s, "exudyn_whole_s": exu_headline.whole_s,
            "exudyn_over_ancfdrv_solve": ratio(exu_headline.solve_s, headline.solve_s),
            "exudyn_over_ancfdrv_whole": ratio(exu_headline.whole_s, headline.whole_s),
            "ancfdrv_error_percent": boom_error(headline, reference,
                                                sag_range)["percent_of_range"],
            "exudyn_error_percent": boom_error(exu_headline, reference,
                                               sag_range)["percent_of_range"],
            "exudyn_error_vs_own_finest_percent": boom_error(
                exu_headline, finest, sag_range)["percent_of_range"],
            "difference_between_codes_percent": 100.0 * max_difference(
                headline.history, exu_headline.history) / sag_range}
    mine = [as_peer_run(r, n, runs.boom.dt, boom_error(r, reference, sag_range)["max_abs_m"],
                        boom_error(r, reference, sag_range)["max_abs_m"])
            for r, n in zip(ours, plan.boom_cubic_nodes)]
    theirs = [as_peer_run(r, 3 * k, runs.boom.dt,
                          boom_error(r, reference, sag_range)["max_abs_m"],
                          boom_error(r, finest, sag_range)["max_abs_m"])
              for r, k in zip(peer, plan.boom_exudyn_per_segment)]
    record["dominance"] = {
        "self_error": pe.dominance(mine, [r for r in theirs if r is not theirs[-1]],
                                   "self_error"),
        "error": pe.dominance(mine, theirs, "error")}
    record["histories"] = histories(runs.grid, {"reference": reference, "ancfdrv": headline,
                                                "exudyn": exu_headline, "exudyn_finest": finest},
                                    0.02)
    return record


def compact(values: np.ndarray, digits: int = 10) -> list[Any]:
    """Values rounded to ``digits`` significant digits, for the JSON (far finer than any
    difference the reports compare)."""
    array = np.asarray(values, dtype=float)
    rounded = [float(f"{x:.{digits}g}") for x in array.ravel()]
    return np.array(rounded).reshape(array.shape).tolist()


def histories(grid: np.ndarray, runs: dict[str, Timed | None], every: float) -> dict[str, Any]:
    """The runs' histories every ``every`` seconds (a multiple of the grid's step)."""
    step = max(1, int(round(every / (grid[1] - grid[0]))))
    out: dict[str, Any] = {"time": compact(grid[::step])}
    for name, run in runs.items():
        if run is not None and run.ok and run.values is not None:
            out[name] = compact(run.values[::step])
    return out


# -- the plate pendulum ------------------------------------------------------------------------
@dataclass(frozen=True)
class Plate:
    length_x: float
    length_y: float
    thickness: float
    youngs: float
    poisson: float
    density: float
    gravity: float
    rho_inf: float
    nx: int
    ny: int
    dt: float
    t_end: float


PLATE_SCENE = "inputs/plate_pendulum.nml"


def plate_from_scene(overrides: list[str]) -> Plate:
    from ancfdrv.io.scene import load_scene

    scene = load_scene(REPO / PLATE_SCENE, overrides)
    plate, material, solver = scene["plate"], scene["material"], scene["solver"]
    if plate["support"] != "corner_spherical" or solver["integrator"] != "generalized_alpha":
        raise ValueError(f"{PLATE_SCENE}: the harness needs the corner-supported pendulum "
                         "with generalized-alpha")
    return Plate(length_x=plate["length_x"], length_y=plate["length_y"],
                 thickness=plate["thickness"], youngs=material["youngs_modulus"],
                 poisson=material["poisson_ratio"], density=material["density"],
                 gravity=scene["loads"]["gravity"] if "gravity" in scene.effects else 0.0,
                 rho_inf=solver["rho_inf"], nx=plate["nx"], ny=plate["ny"], dt=solver["dt"],
                 t_end=solver["t_end"])


def plate_reader(grid: np.ndarray) -> Callable[[h5py.File], dict[str, Any]]:
    def read(h5: h5py.File) -> dict[str, Any]:
        return {"time": grid, "values": resample(grid, h5["dynamic/time"][()],
                                                 h5["dynamic/probes/corner"][()])}
    return read


def run_exudyn_plate(exu: Any, plate: Plate, integration: int, grid: np.ndarray,
                     repeats: int, budget_s: float) -> Timed:
    from exudyn.itemInterface import LoadMassProportional, MarkerBodyMass, SensorNode
    from exudyn.shells import AddSphericalJointToGround, ShellMesh

    names = {0: "5x5 Gauss (default)", 1: "Lobatto/Gauss SRI"}
    timed = Timed("exudyn", f"{plate.nx}x{plate.ny}, {names.get(integration, integration)}",
                  {"nx": plate.nx, "ny": plate.ny, "dt": plate.dt,
                   "useReducedOrderIntegration": integration})

    def once() -> tuple[float, float, dict[str, Any]]:
        t0 = time.perf_counter()
        container = exu.SystemContainer()
        mbs = container.AddSystem()
        mesh = ShellMesh(vertices=[[0.0, 0.0, 0.0], [plate.length_x, 0.0, 0.0],
                                   [plate.length_x, plate.length_y, 0.0],
                                   [0.0, plate.length_y, 0.0]],
                         numberOfElementsX=plate.nx, numberOfElementsY=plate.ny,
                         youngsModulus=plate.youngs, poissonsRatio=plate.poisson,
                         density=plate.density, thickness=plate.thickness)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            mesh.CreateANCFThinPlateElements(mbs, useReducedOrderIntegration=integration)
        for element in mesh.elementNumbers:
            mbs.AddLoad(LoadMassProportional(
                markerNumber=mbs.AddMarker(MarkerBodyMass(bodyNumber=element)),
                loadVector=[0.0, 0.0, -plate.gravity]))
        AddSphericalJointToGround(mbs, mesh.vertexNodeNumbers[0])
        sensor = mbs.AddSensor(SensorNode(nodeNumber=mesh.vertexNodeNumbers[2],
                                          storeInternal=True,
                                          outputVariableType=exu.OutputVariableType.Position))
        mbs.Assemble()
        settings = exu.SimulationSettings()
        integration_settings = settings.timeIntegration
        integration_settings.numberOfSteps = int(round(plate.t_end / plate.dt))
        integration_settings.endTime = plate.t_end
        integration_settings.adaptiveStep = False
        integration_settings.verboseMode = 0
        integration_settings.generalizedAlpha.spectralRadius = plate.rho_inf
        quiet_settings(exu, settings, plate.dt)
        t1 = time.perf_counter()
        run_quietly(lambda: mbs.SolveDynamic(
            settings, solverType=exu.DynamicSolverType.GeneralizedAlpha))
        solve = time.perf_counter() - t1
        data = mbs.GetSensorStoredData(sensor)
        whole = time.perf_counter() - t0
        it = mbs.sys["dynamicSolver"].it
        counts = {"steps": int(integration_settings.numberOfSteps),
                  "newton_iterations": int(it.newtonStepsCount),
                  "jacobians": int(it.newtonJacobiCount)}
        return solve, whole, {"counts": counts, "time": grid,
                              "values": resample(grid, data[:, 0], data[:, 1:4])}

    return best_of(timed, once, repeats, budget_s, (RuntimeError, ValueError))


def compare_plate(plan: Plan, exu: Any, workdir: Path, args: argparse.Namespace) -> dict[str, Any]:
    overrides = [f"solver.dt={plan.plate_dt!r}", f"solver.t_end={plan.plate_t_end!r}"]
    plate = plate_from_scene(overrides)
    grid = uniform_grid(plate.t_end, plan.plate_sample_dt)
    ours = run_ancfdrv(f"{plate.nx}x{plate.ny}, completed, dt {plate.dt:g}", PLATE_SCENE,
                       overrides, workdir / "plate.h5", plate_reader(grid), args.repeats,
                       args.budget)
    progress("plate", ours)
    n_ref, dt_ref = plan.plate_reference
    reference = run_ancfdrv(f"{n_ref}x{n_ref}, completed, dt {dt_ref:g}", PLATE_SCENE,
                            [f"solver.dt={dt_ref!r}", f"solver.t_end={plan.plate_t_end!r}",
                             f"plate.nx={n_ref}", f"plate.ny={n_ref}"],
                            workdir / "plate_reference.h5", plate_reader(grid), 1, args.budget)
    progress("plate", reference)
    scale = (float(np.max(np.linalg.norm(reference.history - reference.history[0], axis=1)))
             if reference.ok else math.nan)

    def errors(run: Timed) -> dict[str, Any]:
        out = {"distance_to_reference_m": max_difference(run.history, reference.history)
               if run.ok and reference.ok else math.nan}
        if run is not ours:
            out["distance_to_ancfdrv_m"] = (max_difference(run.history, ours.history)
                                            if run.ok and ours.ok else math.nan)
        return out

    record: dict[str, Any] = {
        "plate": asdict(plate), "sample_dt": plan.plate_sample_dt,
        "reference": reference.label, "reference_corner_travel_m": scale,
        "ancfdrv": run_row(ours, errors(ours)), "reference_run": run_row(reference)}
    if exu is None:
        return record
    peers = []
    for integration in (0, 1):
        run = run_exudyn_plate(exu, plate, integration, grid, args.repeats, args.budget)
        progress("plate", run)
        peers.append(run)
    record["exudyn"] = [run_row(r, {**errors(r),
                                    "exudyn_over_ancfdrv_solve": ratio(r.solve_s, ours.solve_s),
                                    "exudyn_over_ancfdrv_whole": ratio(r.whole_s, ours.whole_s)})
                        for r in peers]
    for key, peer in (("headline", peers[0]), ("headline_reduced_integration", peers[1])):
        if peer.ok and ours.ok:
            record[key] = {
                "ancfdrv": ours.label, "exudyn": peer.label,
                "ancfdrv_solve_s": ours.solve_s, "exudyn_solve_s": peer.solve_s,
                "ancfdrv_whole_s": ours.whole_s, "exudyn_whole_s": peer.whole_s,
                "exudyn_over_ancfdrv_solve": ratio(peer.solve_s, ours.solve_s),
                "exudyn_over_ancfdrv_whole": ratio(peer.whole_s, ours.whole_s),
                "distance_between_codes_m": max_difference(peer.history, ours.history),
                "ancfdrv_distance_to_reference_m": errors(ours)["distance_to_reference_m"],
                "exudyn_distance_to_reference_m": errors(peer)["distance_to_reference_m"]}
    record["histories"] = histories(grid, {"ancfdrv": ours, "reference": reference,
                                           "exudyn": peers[0], "exudyn_sri": peers[1]},
                                    plan.plate_sample_dt)
    return record


# -- spin-up and pendulum: peer_exudyn's curves ------------------------------------------------
def hard_problems(plan: Plan, names: list[str]) -> dict[str, Any]:
    import peer_exudyn as pe

    grids = pe.QUICK_PROBLEMS if plan.hard_quick else pe.PROBLEMS
    out: dict[str, Any] = {}
    if "spinup" in names:
        out["spinup_w4"] = grids["spinup"]
        out["spinup_w6"] = replace(grids["spinup"], name="spinup_w6", overrides=())
    if "pendulum" in names:
        out["pendulum"] = grids["pendulum"]
    return out


def compare_hard(problem: Any, exu: Any, workdir: Path, args: argparse.Namespace) -> dict[str, Any]:
    """peer_exudyn's comparison of one problem with ancfdrv's cubic option."""
    import peer_exudyn as pe

    bendings = ([args.pendulum_bending] if problem.name == "pendulum"
                else list(args.hard_bending))
    bending = bendings[0]
    pe_args = argparse.Namespace(min_time=args.hard_min_time, max_repeats=args.repeats,
                                 breakdown=False, kernel_min_time=0.05, svk_check=False,
                                 bending=bendings, exudyn_symbolic_drive=True,
                                 choose_tol=True)
    record = pe.compare_problem(problem, exu, workdir, pe_args)
    if problem.name.startswith("spinup"):
        try:
            record["spinup_angle_vs_ancfdrv_drive_max_abs"] = pe.check_spinup_angle(
                pe.beam_from_scene(problem))
        except (ImportError, AttributeError) as exc:  # ancfdrv's drive API may move
            record["spinup_angle_vs_ancfdrv_drive_max_abs"] = f"unavailable: {exc}"
    summary: dict[str, Any] = {"overrides": list(problem.overrides)}
    summary["ancfdrv_bending"] = bending
    for key, dom in record.get("dominance", {}).get(bending, {}).items():
        ratios = [p["time_ratio_ancfdrv_over_exudyn"] for p in dom["for_each_exudyn_run"]
                  if p["time_ratio_ancfdrv_over_exudyn"] is not None]
        # the same matched ancfdrv runs' calls writing the HDF5 file (shown, not compared)
        with_file = [p.get("time_ratio_ancfdrv_with_file_over_exudyn")
                     for p in dom["for_each_exudyn_run"]]
        with_file = [r for r in with_file if r is not None and math.isfinite(r)]
        summary[key] = {"ancfdrv_dominates": dom["ancfdrv_dominates"],
                        "exudyn_dominates": dom["exudyn_dominates"],
                        "exudyn_runs": len(dom["for_each_exudyn_run"]),
                        "exudyn_runs_matched": len(ratios),
                        "ancfdrv_over_exudyn_time_min": min(ratios, default=None),
                        "ancfdrv_over_exudyn_time_max": max(ratios, default=None),
                        "ancfdrv_with_file_over_exudyn_time_min": min(with_file, default=None),
                        "ancfdrv_with_file_over_exudyn_time_max": max(with_file, default=None)}
    record["summary"] = summary
    record["levels"] = hard_levels(record, bendings)
    return record


def hard_levels(record: dict[str, Any], bendings: list[str]) -> list[dict[str, Any]]:
    """Per accuracy level (in % of the range of ancfdrv's reference history) and error kind
    ('common': against ancfdrv's reference; 'own': against each code's own finest run): each
    code's fastest run (whole in-memory call) within the level, and the ratio."""
    runs = [r for r in record["runs"] if not r["reference"] and r["ok"]
            and (r["code"] == "exudyn" or r["bending"] in bendings)]
    ref = next(r for r in record["runs"] if r["reference"] and r["code"] != "exudyn"
               and r["bending"] == bendings[0])
    size = float(np.ptp(record["histories"][f"{ref['code']}_{ref['mesh']}_{ref['dt']:g}"]))
    table = []
    for level in LEVELS:
        entry: dict[str, Any] = {"level_percent": level, "range": size}
        for key, field_name in (("common", "error"), ("own", "self_error")):
            best = {}
            for code in ("ancfdrv", "exudyn"):
                ok = [r for r in runs if (r["code"] == "exudyn") == (code == "exudyn")
                      and 100.0 * r[field_name] / size <= level]
                pick = min(ok, key=lambda r: r["wall_s"]) if ok else None
                best[code] = None if pick is None else {
                    "mesh": pick["mesh"], "dt": pick["dt"], "bending": pick["bending"],
                    "newton": newton_setting(pick),
                    "whole_s": pick["wall_s"],
                    "whole_with_file_s": pick["wall_file_s"],
                    "error_percent": 100.0 * pick[field_name] / size}
            a, x = best["ancfdrv"], best["exudyn"]
            entry[key] = {**best, "exudyn_over_ancfdrv": ratio(x["whole_s"], a["whole_s"])
                          if a and x else None}
        table.append(entry)
    return table


def newton_setting(run: dict[str, Any]) -> str:
    """A peer_exudyn run's Newton tolerance as a short text (ancfdrv: newton_tol, 'scene'
    when the scene's; Exudyn: absolute/relative)."""
    d = run.get("details", {})
    if run["code"] == "exudyn":
        return f"{d.get('absolute_tol', math.nan):g}/{d.get('relative_tol', math.nan):g}"
    return f"{d['newton_tol']:g}" if d.get("newton_tol") is not None else "scene"


def tolerance_rows(record: dict[str, Any]) -> list[dict[str, Any]]:
    """Each run's chosen Newton tolerance and what each tried gave (change of the history /
    its range against the tight run; None: that run failed)."""
    rows = []
    for r in record["runs"]:
        tried = r["details"].get("newton_tol_tried") or r["details"].get("tolerances_tried")
        if tried:
            rows.append({"code": r["code"], "mesh": r["mesh"], "dt": r["dt"],
                         "chosen": newton_setting(r), "tried": tried})
    return rows


def tolerance_markdown(rows: list[dict[str, Any]], title: str) -> list[str]:
    """The table of chosen tolerances (tight setting first in each 'tried' list)."""
    def setting(value: Any) -> str:
        if isinstance(value, (list, tuple)):
            return "/".join(f"{v:g}" for v in value)
        return f"{value:g}" if isinstance(value, float) else str(value)

    out = [f"{title}: each timed run's Newton tolerance, the loosest that keeps its history "
           f"within {100 * HISTORY_KEEP:g} % of the range of the same run at the tight "
           "setting (listed first); the history change each setting tried gave, in % of the "
           "range (failed: the run failed).", "",
           "| code | run | chosen | tight | tried: change % |", "|---|---|---|---|---|"]
    for r in rows:
        tight, *rest = r["tried"]
        tried = ", ".join(f"{setting(t['setting'])}: "
                          + ("failed" if t["change"] is None else f"{100 * t['change']:.2g}")
                          for t in rest)
        out.append(f"| {r['code']} | {r['run']} | {setting(r['chosen'])} | {setting(tight['setting'])} "
                   f"| {tried} |")
    return out + [""]


def hard_levels_markdown(problems: dict[str, Any]) -> list[str]:
    out: list[str] = []
    for name, rec in problems.items():
        if "levels" not in rec or name == "levels":
            continue
        out += [f"## {name}: each accuracy level's fastest run", "",
                "Error: max |y - y_ref| in % of the range of ancfdrv's reference history "
                "('common': against ancfdrv's reference; 'own': against each code's finest "
                "run). Time: the whole in-memory call (ancfdrv: `simulate`, with the HDF5 "
                "file beside it; Exudyn: build and `SolveDynamic` with a sensor every 0.01 s), "
                "best of the repeats. Ratio: Exudyn / ancfdrv.", "",
                "| level | against | ancfdrv option nodes, dt, newton_tol | s | with file s | "
                "error % | Exudyn elements, dt, tolerances | s | error % | Exudyn / ancfdrv |",
                "|---|---|---|---:|---:|---:|---|---:|---:|---:|"]
        for entry in rec["levels"]:
            for key in ("common", "own"):
                e = entry[key]
                a, x = e["ancfdrv"], e["exudyn"]
                ac = (f"{a['bending']} {a['mesh']}, {a['dt']:g}, {a.get('newton', '-')} | "
                      f"{_f(a['whole_s'])} | "
                      f"{_f(a['whole_with_file_s'])} | {_f(a['error_percent'])}"
                      if a else "none | - | - | -")
                xc = (f"{x['mesh']}, {x['dt']:g}, {x.get('newton', '-')} | {_f(x['whole_s'])} | "
                      f"{_f(x['error_percent'])}" if x else "none | - | -")
                out.append(f"| {entry['level_percent']:g} % | {key} | {ac} | {xc} | "
                           f"{_ratio(e['exudyn_over_ancfdrv'])} |")
        out.append("")
        rows = [{**r, "run": f"{r['mesh']}, dt {r['dt']:g}"} for r in tolerance_rows(rec)]
        if rows:
            out += tolerance_markdown(rows, f"{name}, Newton tolerances")
    return out


# -- the leaf spring ---------------------------------------------------------------------------
LEAF_SCENE = "inputs/leaf_spring.nml"


def compare_leaf(plan: Plan, workdir: Path, args: argparse.Namespace,
                 previous: dict[str, Any] | None) -> dict[str, Any]:
    overrides = [f"solver.t_end={plan.leaf_t_end!r}"] if plan.leaf_t_end else []
    from ancfdrv.io.scene import load_scene
    solver = load_scene(REPO / LEAF_SCENE, overrides)["solver"]
    grid = uniform_grid(solver["t_end"], plan.leaf_store_dt)

    def read(h5: h5py.File) -> dict[str, Any]:
        return {"time": grid, "values": resample(grid, h5["dynamic/time"][()],
                                                 h5["dynamic/probes/chassis"][()])}

    run = run_ancfdrv(f"scene, dt {solver['dt']:g}, 0..{solver['t_end']:g} s", LEAF_SCENE,
                      overrides, workdir / "leaf.h5", read, args.repeats, args.budget)
    progress("leaf", run)
    record: dict[str, Any] = {"run": run_row(run), "earlier": STORED_FIGURES["leaf"],
                              "t_end": solver["t_end"], "dt": solver["dt"]}
    if not run.ok:
        return record
    steps = run.counts.get("steps", 0)
    record.update({
        "dynamic_wall_time_s": run.solve_s,
        "ms_per_step": 1e3 * run.solve_s / max(steps, 1),
        "newton_per_step": run.counts.get("newton_iterations", 0) / max(steps, 1),
        "factorizations_per_step": run.counts.get("factorizations", 0) / max(steps, 1),
        "history": {"time": compact(grid), "chassis": compact(run.history),
                    "store_dt": plan.leaf_store_dt}})
    if plan.leaf_t_end is None:
        earlier = STORED_FIGURES["leaf"]
        record["now_over_earlier_wall"] = ratio(run.solve_s, earlier["dynamic_wall_time_s"])
    record["history_vs_previous"] = compare_leaf_history(record["history"], previous)
    return record


def compare_leaf_history(now: dict[str, Any], previous: dict[str, Any] | None) -> dict[str, Any]:
    """Per component of the chassis: max |now - previous| / range of previous (absolute for
    a component that does not move), on the stored times."""
    if not previous or "history" not in previous:
        return {"compared": False, "why": "no stored history"}
    t_old = np.asarray(previous["history"]["time"], dtype=float)
    old = np.asarray(previous["history"]["chassis"], dtype=float)
    t_new, new = np.asarray(now["time"]), np.asarray(now["chassis"])
    if t_old.shape != t_new.shape or not np.allclose(t_old, t_new, rtol=0, atol=1e-9):
        return {"compared": False, "why": "the stored history has other sample times"}
    components = []
    for k, axis in enumerate("xyz"):
        span = float(np.ptp(old[:, k]))
        diff = float(np.max(np.abs(new[:, k] - old[:, k])))
        moves = span > 1e-9
        components.append({"axis": axis, "range_m": span, "max_abs_difference_m": diff,
                           "relative": diff / span if moves else None})
    worst = max((c["relative"] for c in components if c["relative"] is not None), default=0.0)
    return {"compared": True, "previous_created": previous.get("created"),
            "components": components, "max_relative": worst,
            "within_tolerance": bool(worst <= LEAF_HISTORY_TOLERANCE
                                     and all(c["relative"] is not None
                                             or c["max_abs_difference_m"] <= 1e-9
                                             for c in components)),
            "tolerance": LEAF_HISTORY_TOLERANCE}


# -- reporting ---------------------------------------------------------------------------------
def _f(value: Any, fmt: str = ".3f") -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return format(value, fmt)


def ratio_rows(problems: dict[str, Any]) -> list[dict[str, Any]]:
    """One row per headline comparison: the times and the ratio."""
    rows: list[dict[str, Any]] = []
    for name, key, label in (("boom_ffr", "headline", "boom_ffr"),
                             ("boom_nonlinear", "headline", "boom_nonlinear"),
                             ("plate", "headline", "plate"),
                             ("plate", "headline_reduced_integration", "plate (Exudyn SRI)")):
        head = problems.get(name, {}).get(key)
        if head:
            rows.append({"problem": label, **head,
                         "stored": STORED_FIGURES.get(name) if key == "headline" else None})
    for name in ("spinup_w4", "spinup_w6", "pendulum"):
        rec = problems.get(name)
        if rec and "summary" in rec:
            rows.append({"problem": name, "dominance": rec["summary"]})
    leaf = problems.get("leaf")
    if leaf and leaf["run"]["ok"]:
        rows.append({"problem": "leaf", "ancfdrv_solve_s": leaf["dynamic_wall_time_s"],
                     "earlier_s": STORED_FIGURES["leaf"]["dynamic_wall_time_s"],
                     "now_over_earlier": leaf.get("now_over_earlier_wall"),
                     "newton_per_step": leaf["newton_per_step"],
                     "ms_per_step": leaf["ms_per_step"]})
    return rows


def markdown(report: dict[str, Any]) -> str:
    m, problems = report["machine"], report["problems"]
    lines = [
        "# Peer harness: ancfdrv and Exudyn, timed in one run",
        "",
        f"Created {report['created']} by `benchmarks/peer_harness.py`"
        f"{' --quick' if report['settings']['quick'] else ''}; "
        f"{report['wall_time_s']:.0f} s. Machine: {m['platform']}, {m['cpus_usable']} usable "
        f"CPUs, Python {m['python']}; load average {m['load_average_at_start']} at the start, "
        f"{m.get('load_average_at_end')} at the end (a shared machine: other processes "
        "distort the timings). Exudyn "
        + (f"{report['exudyn']['version']} ({report['exudyn']['build']}), 1 thread"
           if report["exudyn"]["available"] else f"skipped ({report['exudyn']['skipped_because']})")
        + f"; best of {report['settings']['repeats']} repeats (fewer once a measurement took "
        f"{report['settings']['budget_s']:g} s).",
        "",
        "Ratios are Exudyn's time / ancfdrv's (> 1: ancfdrv is faster), measured in this run. "
        "solve: the dynamic solve (ancfdrv: `/dynamic` `wall_time_s`; Exudyn: `SolveDynamic`); "
        "whole: model, static start, dynamics and output of one call.",
        "",
    ]
    headlines = [row for row in report["ratios"]
                 if "dominance" not in row and row["problem"] != "leaf"]
    if headlines:
        lines += ["| problem | ancfdrv | solve s | whole s | Exudyn | solve s | whole s | "
                  "ratio solve | ratio whole | error ancfdrv | error Exudyn | stored figure |",
                  "|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---|"]
    for row in headlines:
        if row["problem"].startswith("plate"):
            errs = (f"{_f(1e3 * row['ancfdrv_distance_to_reference_m'], '.1f')} mm",
                    f"{_f(1e3 * row['exudyn_distance_to_reference_m'], '.1f')} mm")
        else:
            errs = (f"{_f(row['ancfdrv_error_percent'], '.3f')} %",
                    f"{_f(row['exudyn_error_percent'], '.3f')} %")
        stored = row.get("stored") or {}
        stored_text = ", ".join(f"{k} {v}" for k, v in stored.items() if k != "source")
        lines.append(f"| {row['problem']} | {row['ancfdrv']} | {_f(row['ancfdrv_solve_s'])} | "
                     f"{_f(row['ancfdrv_whole_s'])} | {row['exudyn']} | "
                     f"{_f(row['exudyn_solve_s'])} | {_f(row['exudyn_whole_s'])} | "
                     f"{_f(row['exudyn_over_ancfdrv_solve'], '.2f')} | "
                     f"{_f(row['exudyn_over_ancfdrv_whole'], '.2f')} | {errs[0]} | {errs[1]} | "
                     + (f"{stored.get('source', '')}: {stored_text}" if stored else "-") + " |")
    if headlines:
        lines += ["", "Errors: boom: max |sag - sag_ref| over the history in % of the reference's "
                  "sag range, against ancfdrv's converged reference; plate: largest distance of "
                  "the corner from ancfdrv's finer reference mesh. Stored figures are quoted, not "
                  "measured here.", ""]
    curves = [row for row in report["ratios"] if "dominance" in row
              and ("self_error" in row["dominance"] or "error" in row["dominance"])]
    if curves:
        lines += ["Error-against-time curves (whole-call times; for each Exudyn run the cheapest "
                  "ancfdrv run at least as accurate; ratio = ancfdrv's time / Exudyn's):", "",
                  "| problem | judged against | ancfdrv dominates | Exudyn dominates | "
                  "Exudyn accuracies reached by ancfdrv | ancfdrv / Exudyn time |",
                  "|---|---|---|---|---:|---|"]
        for row in curves:
            for key, label in (("self_error", "each code's own finest run"),
                               ("error", "ancfdrv's finest run")):
                d = row["dominance"].get(key)
                if d:
                    lines.append(
                        f"| {row['problem']} | {label} | {'yes' if d['ancfdrv_dominates'] else 'no'}"
                        f" | {'yes' if d['exudyn_dominates'] else 'no'} | "
                        f"{d['exudyn_runs_matched']} of {d['exudyn_runs']} | "
                        f"{_f(d['ancfdrv_over_exudyn_time_min'], '.2f')} to "
                        f"{_f(d['ancfdrv_over_exudyn_time_max'], '.2f')} |")
        lines.append("")
    leaf_row = next((row for row in report["ratios"] if row["problem"] == "leaf"), None)
    if leaf_row:
        lines += [f"Leaf spring (ancfdrv alone): dynamic solve {_f(leaf_row['ancfdrv_solve_s'], '.2f')}"
                  f" s, {_f(leaf_row['ms_per_step'], '.2f')} ms and "
                  f"{_f(leaf_row['newton_per_step'], '.2f')} Newton corrections per step; the "
                  f"README's earlier figure {leaf_row['earlier_s']} s (stored, not measured here)"
                  + (f": now / earlier = {_f(leaf_row['now_over_earlier'], '.2f')}."
                     if leaf_row.get("now_over_earlier") is not None else
                     " (a shorter run: not comparable)."), ""]
    lines += _boom_ffr_md(problems.get("boom_ffr"))
    lines += _boom_nonlinear_md(problems.get("boom_nonlinear"))
    lines += _plate_md(problems.get("plate"))
    lines += _hard_md(problems)
    lines += _leaf_md(problems.get("leaf"))
    return "\n".join(lines) + "\n"


def _run_table(rows: list[dict[str, Any]], extra: list[tuple[str, Callable[[dict], str]]]
               ) -> list[str]:
    head = "| code | run | solve s | whole s | repeats | steps | Newton/step | " + " | ".join(
        h for h, _ in extra) + " |"
    out = [head, "|" + "---|" * (7 + len(extra))]
    for r in rows:
        steps = r.get("steps")
        newton = (f"{r['newton_iterations'] / steps:.2f}" if steps and "newton_iterations" in r
                  else "-")
        cells = [fn(r) for _, fn in extra]
        out.append(f"| {r['code']} | {r['label']} | {_f(r['solve_s'])} | {_f(r['whole_s'])} | "
                   f"{r['repeats']} | {steps if steps else '-'} | {newton} | "
                   + " | ".join(cells) + " |")
    return out


def _pct(key: str) -> Callable[[dict], str]:
    return lambda r: _f(r.get(key, {}).get("percent_of_range"), ".3f")


def _boom_ffr_md(rec: dict[str, Any] | None) -> list[str]:
    if not rec:
        return []
    out = ["## boom_ffr: the luffing boom as shipped (FFR) against Exudyn's cable", "",
           f"Reference: ancfdrv {rec['reference']}; sag range {rec['reference_sag_range_m']:.4f} m. "
           f"Luffing angle used for Exudyn against the angle in ancfdrv's file: "
           f"{_f(rec.get('luffing_angle_vs_ancfdrv_file_max_abs_rad'), '.1e')} rad.", ""]
    rows = [rec["ancfdrv"]] + rec.get("exudyn_variants", []) + rec.get("exudyn_curve", [])
    out += _run_table(rows, [("error vs reference %", _pct("error_vs_reference")),
                             ("vs ancfdrv FFR %", _pct("error_vs_ancfdrv_ffr")),
                             ("jacobians", lambda r: str(r.get("jacobians", "-")))])
    eq = rec.get("equal_accuracy")
    if eq:
        out += ["", f"Equal accuracy: ancfdrv FFR's error against the reference is "
                f"{_f(eq['ancfdrv_error_m'], '.2e')} m; the cheapest Exudyn run at least as "
                f"accurate is {eq['cheapest_exudyn_as_accurate']} "
                f"({_f(eq['exudyn_error_m'], '.2e')} m) in {_f(eq['exudyn_solve_s'])} s: "
                f"Exudyn / ancfdrv = {_f(eq['exudyn_over_ancfdrv_solve'], '.2f')}."]
    return out + [""]


def _boom_nonlinear_md(rec: dict[str, Any] | None) -> list[str]:
    if not rec:
        return []
    out = ["## boom_nonlinear: large-deformation boom, ancfdrv's cubic option against "
           "Exudyn's cable", "",
           f"Reference: ancfdrv {rec['reference']} (solve {_f(rec['reference_run']['solve_s'])} s); "
           f"sag range {rec['reference_sag_range_m']:.4f} m.", ""]
    rows = rec["ancfdrv"] + rec.get("exudyn", [])
    out += _run_table(rows, [("error vs reference %", _pct("error_vs_reference")),
                             ("vs Exudyn finest %", _pct("error_vs_exudyn_finest"))])
    gap = rec.get("model_gap")
    if gap:
        out += ["", f"The converged models differ: {gap['finest_runs'][0]} against "
                f"{gap['finest_runs'][1]}: {_f(gap['max_abs_m'], '.2e')} m "
                f"({_f(gap['percent_of_range'], '.3f')} % of the range). Against ancfdrv's "
                "reference Exudyn's error cannot fall below this gap."]
        closed = rec.get("static_sag_closed_form", {})
        if "euler_bernoulli_m" in closed:
            out += ["", f"Static sag at t = 0 (m): ancfdrv {_f(rec['reference_run'].get('static_sag_m'), '.6f')}"
                    f", Exudyn {_f(rec['exudyn'][-1].get('static_sag_m'), '.6f')}; linear closed "
                    f"form (`ancfdrv.reference.analytic`) {closed['euler_bernoulli_m']:.6f} "
                    f"(Euler-Bernoulli), {closed['timoshenko_k1_m']:.6f} (Timoshenko, k = 1)."]
    for key, dom in rec.get("dominance", {}).items():
        out += ["", f"Dominance ({key}; time = dynamic solve): ancfdrv dominates: "
                f"{'yes' if dom['ancfdrv_dominates'] else 'no'}; Exudyn dominates: "
                f"{'yes' if dom['exudyn_dominates'] else 'no'}."]
        for p in dom["for_each_exudyn_run"]:
            out.append(f"- Exudyn {p['exudyn'][0]} el: error {_f(p['exudyn_error'], '.2e')} m in "
                       f"{_f(p['exudyn_wall_s'])} s; cheapest ancfdrv as accurate: "
                       + (f"{p['ancfdrv'][0]} nodes, {_f(p['ancfdrv_wall_s'])} s "
                          f"(ratio ancfdrv/Exudyn {_f(p['time_ratio_ancfdrv_over_exudyn'], '.2f')})"
                          if p["ancfdrv"] else "none"))
    return out + [""]


def _plate_md(rec: dict[str, Any] | None) -> list[str]:
    if not rec:
        return []
    out = ["## plate: the plate pendulum against Exudyn's ANCFThinPlate", "",
           f"Reference: ancfdrv {rec['reference']}; the corner travels up to "
           f"{_f(rec['reference_corner_travel_m'], '.3f')} m.", ""]
    rows = [rec["ancfdrv"]] + rec.get("exudyn", [])
    mm = lambda key: (lambda r: _f(1e3 * r[key] if key in r else None, ".3f"))  # noqa: E731
    out += _run_table(rows, [("corner to reference mm", mm("distance_to_reference_m")),
                             ("corner to ancfdrv mm", mm("distance_to_ancfdrv_m")),
                             ("jacobians / factorizations",
                              lambda r: str(r.get("jacobians", r.get("factorizations", "-"))))])
    return out + [""]


def _hard_md(problems: dict[str, Any]) -> list[str]:
    out: list[str] = []
    for name in ("spinup_w4", "spinup_w6", "pendulum"):
        rec = problems.get(name)
        if not rec:
            continue
        if not out:
            out = ["## spinup, pendulum: error against time (peer_exudyn.py; ancfdrv's option "
                   "in each problem's runs table)", ""]
        refs = rec["references"]
        out.append(f"**{name}** ({rec['problem']['quantity']}, overrides "
                   f"{rec['summary']['overrides']}): ancfdrv reference {refs['ancfdrv']} "
                   f"(nodes, dt)" + (f", Exudyn reference {refs['exudyn']}, references "
                                    f"{_f(refs.get('max_abs_difference'), '.2e')} m apart"
                                    if "exudyn" in refs else "") + ".")
        if refs.get("model_gap_dominates"):
            out.append("- the references differ by more than any Exudyn run from its own: the "
                       "codes converge to different solutions (different continuum models), so "
                       "'error' of the Exudyn runs is that gap, not their accuracy")
        for key in ("self_error", "error"):
            s = rec["summary"].get(key)
            if s:
                out.append(f"- {key}: ancfdrv dominates {'yes' if s['ancfdrv_dominates'] else 'no'}"
                           f", Exudyn dominates {'yes' if s['exudyn_dominates'] else 'no'}; "
                           f"{s['exudyn_runs_matched']} of {s['exudyn_runs']} Exudyn accuracies "
                           f"reached by ancfdrv in {_f(s['ancfdrv_over_exudyn_time_min'], '.2f')}"
                           f" to {_f(s['ancfdrv_over_exudyn_time_max'], '.2f')} times Exudyn's "
                           "time (in memory; with the HDF5 file "
                           f"{_f(s.get('ancfdrv_with_file_over_exudyn_time_min'), '.2f')} to "
                           f"{_f(s.get('ancfdrv_with_file_over_exudyn_time_max'), '.2f')})")
        rows = ["| code | mesh | dt | wall s | with file s | error | self error |",
                "|---|---:|---:|---:|---:|---:|---:|"]
        for r in rec["runs"]:
            rows.append(f"| {r['code']}{'*' if r['reference'] else ''} | {r['mesh']} | "
                        f"{r['dt']:g} | {_f(r['wall_s']) if r['ok'] else 'FAIL'} | "
                        f"{_f(r.get('wall_file_s')) if r['ok'] else '-'} | "
                        f"{_f(r['error'], '.2e')} | {_f(r['self_error'], '.2e')} |")
        out += [""] + rows + [""]
    if out:
        out.append("mesh: ancfdrv nodes, Exudyn elements; * = reference; wall: the whole call "
                   "(ancfdrv's in memory, `ancfdrv.simulate`: the compared time, as Exudyn's "
                   "sensor keeps its data in memory); with file: ancfdrv's same call writing "
                   "the SPEC HDF5 file (`run_scene`), repeated after the in-memory call's repeats "
                   "(not compared); error: against ancfdrv's reference; self error: against "
                   "the code's own.")
        out.append("")
    return out


def _leaf_md(rec: dict[str, Any] | None) -> list[str]:
    if not rec:
        return []
    out = ["## leaf: the two-leaf spring, ancfdrv alone", ""]
    if not rec["run"]["ok"]:
        return out + [f"FAILED: {rec['run'].get('message')}", ""]
    earlier = rec["earlier"]
    out.append(f"0 ... {rec['t_end']:g} s at dt {rec['dt']:g} s: dynamic solve "
               f"{_f(rec['dynamic_wall_time_s'], '.2f')} s ({_f(rec['ms_per_step'], '.2f')} "
               f"ms/step, {_f(rec['newton_per_step'], '.2f')} Newton corrections and "
               f"{_f(rec['factorizations_per_step'], '.3f')} factorizations per step); whole "
               f"call {_f(rec['run']['whole_s'], '.2f')} s. Earlier figure ({earlier['source']}): "
               f"{earlier['dynamic_wall_time_s']} s, {earlier['newton_per_step']} corrections per "
               f"step" + (f"; now / earlier = {_f(rec['now_over_earlier_wall'], '.2f')}."
                          if "now_over_earlier_wall" in rec else "."))
    cmp_ = rec.get("history_vs_previous", {})
    if cmp_.get("compared"):
        parts = ", ".join(f"{c['axis']}: {_f(c['relative'], '.1e') if c['relative'] is not None else _f(c['max_abs_difference_m'], '.1e') + ' m'}"
                          for c in cmp_["components"])
        out.append(f"Chassis history against the stored one ({cmp_['previous_created']}): "
                   f"{parts} (max difference / range); within {cmp_['tolerance']:g}: "
                   f"{'yes' if cmp_['within_tolerance'] else 'NO'}.")
    else:
        out.append(f"Chassis history not compared: {cmp_.get('why')}; stored in the JSON every "
                   f"{rec['history']['store_dt'] * 1e3:g} ms for the next run.")
    return out + [""]


# -- accuracy levels (issues 23, 38) ------------------------------------------------------------
#: the accuracy levels: error in % of the reference's sag range
LEVELS = (3.0, 1.0, 0.3, 0.1, 0.03)
#: the time steps each code is tried at (every one divides LEVEL_SAMPLE_DT)
LEVEL_DTS = (5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2)
#: histories are compared at these times (s): a step time of every dt of LEVEL_DTS
LEVEL_SAMPLE_DT = 0.02
#: the converged references' time step (s): 1/4 of the finest timed step
REFERENCE_DT = 2.5e-4
#: ancfdrv's overrides of a level run: the nonlinear cable reduced to the boom's plane
CABLE = ("scene.formulation=nonlinear", "solver.static_method=newton", "output.xdmf=.false.",
         "beam.bending=cable", "scene.planar=xy")


#: The Newton settings each code's level runs choose from, loosest first, and the tight
#: setting their histories are compared with (:func:`choose_level_tolerances`, one rule for
#: both: the loosest that keeps the history within HISTORY_KEEP of its range).
LEVEL_ANCFDRV_TOLS = (1e-4, 1e-6, 1e-8, 1e-10)
LEVEL_ANCFDRV_TIGHT = 1e-12
LEVEL_EXUDYN_NEWTON = (BOOM_NEWTON, BOOM_NEWTON_TIGHT)
LEVEL_EXUDYN_TIGHT = DEFAULT_NEWTON


@dataclass(frozen=True)
class LevelConfig:
    """One configuration of the level study: code, mesh (ancfdrv nodes or Exudyn elements
    per segment), time step and the Newton tolerance (ancfdrv: ``newton_tol``, None the
    scene's; Exudyn: its tolerances) and, for Exudyn, its linear solver."""

    code: str
    nodes: int = 0                   # ancfdrv
    per_segment: int = 0             # Exudyn
    dt: float = 1e-3
    newton: ExudynNewton = BOOM_NEWTON
    dense: bool = False
    newton_tol: float | None = None  # ancfdrv

    @property
    def label(self) -> str:
        if self.code == "ancfdrv":
            tol = "" if self.newton_tol is None else f", tol {self.newton_tol:g}"
            return f"cable {self.nodes} nodes, dt {self.dt:g}{tol}"
        solver = "dense" if self.dense else "sparse"
        return (f"{3 * self.per_segment} el, dt {self.dt:g}, {self.newton.label}, {solver}")

    @property
    def overrides(self) -> list[str]:
        """ancfdrv's overrides (beyond the mass and the end time)."""
        tol = [] if self.newton_tol is None else [f"solver.newton_tol={self.newton_tol!r}"]
        return [*CABLE, f"beam.nodes={self.nodes}", f"solver.dt={self.dt!r}", *tol]


def level_configs(quick: bool) -> tuple[list[LevelConfig], dict[str, LevelConfig],
                                        dict[str, LevelConfig]]:
    """The timed grid (mesh x dt for both codes; Exudyn below 10 elements with both LU
    solvers; the Newton settings are chosen later, :func:`choose_level_tolerances`), the
    converged references (code -> config, at each code's default Newton) and the checks of
    ancfdrv's reference (half its mesh, twice its step)."""
    def a(nodes: int, dt: float) -> LevelConfig:
        return LevelConfig("ancfdrv", nodes=nodes, dt=dt)

    def e(per_segment: int, dt: float, newton: ExudynNewton, dense: bool) -> LevelConfig:
        return LevelConfig("exudyn", per_segment=per_segment, dt=dt, newton=newton, dense=dense)

    if quick:
        timed = [a(4, 1e-3), a(4, 1e-2), e(1, 1e-2, BOOM_NEWTON, True)]
        refs = {"ancfdrv": a(10, 5e-4), "exudyn": e(2, 5e-4, DEFAULT_NEWTON, False)}
        return timed, refs, {}
    timed = [a(n, dt) for n in (4, 7, 10, 16) for dt in LEVEL_DTS]
    timed += [e(ps, dt, BOOM_NEWTON, dense) for ps in (1, 2, 3, 6) for dt in LEVEL_DTS
              for dense in ((True, False) if 3 * ps < 10 else (False,))]
    refs = {"ancfdrv": a(55, REFERENCE_DT), "exudyn": e(18, REFERENCE_DT, DEFAULT_NEWTON, False)}
    checks = {"half mesh": a(28, REFERENCE_DT), "twice the step": a(55, 2 * REFERENCE_DT)}
    return timed, refs, checks


def _level_once(config: LevelConfig, boom: Boom, base: list[str], grid: np.ndarray,
                exu: Any, out: Path, file_call: bool = True
                ) -> Callable[[], tuple[float, float, dict[str, Any]]]:
    """One timed run of a configuration (solve s, whole s, payload with 'values');
    ``file_call`` False: ancfdrv's in-memory call alone (its payload only 'values')."""
    boom = replace(boom, dt=config.dt)
    if config.code == "exudyn":
        def once() -> tuple[float, float, dict[str, Any]]:
            t = run_exudyn_boom(exu, boom, config.per_segment, True, False, grid, 1, 0.0,
                                config.newton, config.dense)
            if not t.ok:
                raise RuntimeError(t.message)
            return t.solve_s, t.whole_s, {"counts": t.counts, "values": t.values}
        return once
    import h5py

    import ancfdrv
    from ancfdrv.runner import run_scene
    read = boom_reader(boom, grid)
    scene, overrides = REPO / "inputs/boom_luffing.nml", base + config.overrides

    def once() -> tuple[float, float, dict[str, Any]]:
        # the like-for-like whole call: results kept in memory, as Exudyn's run keeps its
        # sensors (no solution file); the call writing the HDF5 file is timed beside it
        t0 = time.perf_counter()
        sim = ancfdrv.simulate(scene, overrides, progress=False)
        whole = time.perf_counter() - t0
        if not file_call:
            if sim.status != "ok":
                raise RuntimeError(sim.message)
            return sim.dynamic.wall_time_s, whole, {"values": resample(
                grid, sim.time, sim.deflection("tip")[:, 1])}
        t0 = time.perf_counter()
        run_scene(scene, overrides, out, progress=False)
        with_file = time.perf_counter() - t0
        if sim.status != "ok":
            raise RuntimeError(sim.message)
        with h5py.File(out, "r") as h5:
            model = h5["model"].attrs
            counts = {k: int(h5["dynamic"].attrs[k])
                      for k in ("steps", "newton_iterations", "factorizations")}
            counts.update({k: int(model[k]) for k in ("ndof", "nconstraints", "nunknowns",
                                                     "nplanar_fixed") if k in model})
            payload = read(h5)
        memory_values = resample(grid, sim.time, sim.deflection("tip")[:, 1])
        if not np.array_equal(memory_values, payload["values"]):
            raise RuntimeError("the in-memory run's tip history differs from the file's")
        phases = {k: float(v) for k, v in sim.timing.items()}
        return sim.dynamic.wall_time_s, whole, {
            "counts": counts, "values": payload["values"],
            "stepping_s": phases.get("dynamic_stepping", math.nan), "phases_s": phases,
            "with_file_s": with_file}
    return once


def choose_level_tolerances(configs: list[LevelConfig], boom: Boom, base: list[str],
                            grid: np.ndarray, exu: Any, out: Path
                            ) -> tuple[list[LevelConfig], dict[str, list[dict[str, Any]]]]:
    """Each timed configuration with its code's Newton setting chosen by one rule
    (:func:`_peer.loosest_keeping`): the loosest of LEVEL_ANCFDRV_TOLS (ancfdrv's
    ``newton_tol``) or LEVEL_EXUDYN_NEWTON (Exudyn's tolerances) whose sag history stays
    within HISTORY_KEEP of its range of the same configuration's at LEVEL_ANCFDRV_TIGHT or
    LEVEL_EXUDYN_TIGHT (untimed runs; Exudyn's chosen once per mesh and step on its sparse
    LU, for both LUs). Also what each setting tried gave, per chosen label."""
    errors = (RuntimeError, ValueError) + ancfdrv_errors()
    chosen: dict[tuple[Any, ...], Any] = {}
    tried: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for c in configs:
        key = (c.code, c.nodes, c.per_segment, c.dt)
        if key in chosen:
            continue
        if c.code == "ancfdrv":
            def history_at(tol: float, c: LevelConfig = c) -> np.ndarray:
                return _level_once(replace(c, newton_tol=tol), boom, base, grid, exu, out,
                                   file_call=False)()[2]["values"]
            setting, record = loosest_keeping(history_at, LEVEL_ANCFDRV_TOLS,
                                              LEVEL_ANCFDRV_TIGHT, errors=errors)
        else:
            def history_at(newton: ExudynNewton, c: LevelConfig = c) -> np.ndarray:
                return _level_once(replace(c, newton=newton, dense=False), boom, base, grid,
                                   exu, out)()[2]["values"]
            setting, record = loosest_keeping(history_at, LEVEL_EXUDYN_NEWTON,
                                              LEVEL_EXUDYN_TIGHT, errors=errors)
        chosen[key] = setting
        tried[key] = [{**t, "setting": t["setting"] if c.code == "ancfdrv"
                       else t["setting"].label} for t in record]
        change = next(t["change"] for t in record if t["setting"] == setting)
        name = f"{setting:g}" if c.code == "ancfdrv" else setting.label
        where = (f"cable {c.nodes} nodes" if c.code == "ancfdrv"
                 else f"{3 * c.per_segment} el") + f", dt {c.dt:g}"
        print(f"  tolerance {c.code:>7} {where:<24} -> {name} (history change "
              f"{change:.2e} of the range)", flush=True)
    result, by_label = [], {}
    for c in configs:
        key = (c.code, c.nodes, c.per_segment, c.dt)
        c = (replace(c, newton_tol=chosen[key]) if c.code == "ancfdrv"
             else replace(c, newton=chosen[key]))
        result.append(c)
        by_label[c.label] = tried[key]
    return result, by_label


def _level_rounds(configs: list[LevelConfig], once_runs: set[str], onces: dict[str, Callable],
                  runs: dict[str, Timed], repeats: int, tag: str) -> None:
    """Interleaved rounds: every configuration once per round (those in ``once_runs`` only in
    the first), the best time kept; a configuration that fails is not run again."""
    errors = (RuntimeError, ValueError) + ancfdrv_errors()
    for round_ in range(repeats):
        for c in configs:
            run = runs[c.label]
            if (round_ and c.label in once_runs) or (run.message and not run.ok):
                continue
            try:
                solve_s, whole_s, payload = onces[c.label]()
            except errors as exc:
                run.message = " ".join(f"{type(exc).__name__}: {exc}".split())
                continue
            run.solve_samples.append(solve_s)
            run.whole_samples.append(whole_s)
            run.ok, run.solve_s, run.whole_s = True, min(run.solve_samples), \
                min(run.whole_samples)
            run.counts = payload["counts"]
            run.values = payload["values"]
            if "with_file_s" in payload:
                run.extra["with_file_s"] = min(run.extra.get("with_file_s", math.inf),
                                               payload["with_file_s"])
            if "stepping_s" in payload:
                run.extra["stepping_s"] = min(run.extra.get("stepping_s", math.inf),
                                              payload["stepping_s"])
            if "phases_s" in payload and whole_s == run.whole_s:   # the best call's phases
                run.extra["phases_s"] = payload["phases_s"]
            if round_ == repeats - 1 or c.label in once_runs:
                progress(tag, run)


def boom_levels(plan: Plan, exu: Any, workdir: Path, args: argparse.Namespace) -> dict[str, Any]:
    """Each accuracy level's fastest configuration of each code on the luffing boom (m = 50
    and 0 kg), chosen from a grid over mesh and time step, against each code's own converged
    model and against a common reference (ancfdrv's cable converged in space and time: the
    Euler-Bernoulli model both codes' cables converge to). Timed runs are interleaved (every
    configuration once per round, ``--repeats`` rounds, the best kept) so that a change of
    the machine's load hits all alike; then the chosen configurations are timed from the
    command line (a fresh interpreter each, interleaved too)."""
    timed_cfg, ref_cfg, check_cfg = level_configs(args.quick)
    if exu is None:
        timed_cfg = [c for c in timed_cfg if c.code != "exudyn"]
        ref_cfg = {k: v for k, v in ref_cfg.items() if v.code != "exudyn"}
    out: dict[str, Any] = {"levels_percent": list(LEVELS), "dts": list(LEVEL_DTS),
                           "sample_dt": LEVEL_SAMPLE_DT, "reference_dt": REFERENCE_DT,
                           "exudyn_sensor_period": EXUDYN_SENSOR_PERIOD,
                           "history_keep": HISTORY_KEEP,
                           "ancfdrv_newton_tols": [*LEVEL_ANCFDRV_TOLS, LEVEL_ANCFDRV_TIGHT],
                           "exudyn_newton": [n.label for n in (*LEVEL_EXUDYN_NEWTON,
                                                               LEVEL_EXUDYN_TIGHT)],
                           "masses": {}}
    masses = (50.0,) if args.quick else tuple(args.masses)
    for mass in masses:
        base = ([f"solver.t_end={plan.boom_t_end!r}"] if plan.boom_t_end else []) + \
            [f"loads.tip_mass={mass!r}"]
        boom = boom_from_scene("inputs/boom_luffing.nml", base)
        grid = uniform_grid(boom.t_end, LEVEL_SAMPLE_DT)
        once_cfg = list(ref_cfg.values()) + list(check_cfg.values())
        mass_cfg, tolerances = choose_level_tolerances(timed_cfg, boom, base, grid, exu,
                                                       workdir / "level_tolerance.h5")
        runs: dict[str, Timed] = {}
        onces: dict[str, Callable] = {}
        for k, c in enumerate(once_cfg + mass_cfg):
            runs[c.label] = Timed(c.code, c.label, asdict(c))
            onces[c.label] = _level_once(c, boom, base, grid, exu, workdir / f"level_{k}.h5")
        tag = f"levels m={mass:g}"
        _level_rounds(once_cfg, {c.label for c in once_cfg}, onces, runs, 1, tag)
        _level_rounds(mass_cfg, set(), onces, runs, args.repeats, tag)
        common = runs[ref_cfg["ancfdrv"].label]
        if not common.ok:
            raise RuntimeError(f"ancfdrv's level reference failed: {common.message}")
        sag_range = float(np.ptp(common.history))

        def error(run: Timed, ref: Timed) -> float:
            return (100.0 * max_difference(run.history, ref.history) / float(np.ptp(ref.history))
                    if run.ok and ref.ok else math.nan)

        rows = []
        for c in mass_cfg:
            run = runs[c.label]
            own = runs[ref_cfg[c.code].label]
            rows.append({"code": c.code, "label": c.label, "config": asdict(c), "ok": run.ok,
                         "message": run.message, "solve_s": run.solve_s,
                         "whole_s": run.whole_s, "with_file_s": run.extra.get("with_file_s"),
                         "stepping_s": run.extra.get("stepping_s"),
                         "phases_s": run.extra.get("phases_s"),
                         "repeats": len(run.solve_samples), "counts": run.counts,
                         "newton_tried": tolerances[c.label],
                         "own_reference": own.label, "error_own_percent": error(run, own),
                         "error_common_percent": error(run, common)})
        refs = {code: {"label": c.label, "ok": runs[c.label].ok, "message": runs[c.label].message,
                       "solve_s": runs[c.label].solve_s, "whole_s": runs[c.label].whole_s,
                       "error_common_percent": error(runs[c.label], common)}
                for code, c in ref_cfg.items()}
        checks = {name: {"label": c.label, "ok": runs[c.label].ok,
                         "error_common_percent": error(runs[c.label], common)}
                  for name, c in check_cfg.items()}
        table = level_table(rows)
        command_line(table, {c.label: c for c in mass_cfg}, boom, base, workdir, args)
        out["masses"][f"{mass:g}"] = {"sag_range_m": sag_range, "references": refs,
                                      "reference_checks": checks, "runs": rows,
                                      "levels": table}
    return out


def level_table(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per level and error kind ('own', 'common'): each code's fastest run within the level
    by whole call ('whole', the headline) and by solve alone ('solve'), and the ratios."""
    table = []
    for level in LEVELS:
        entry: dict[str, Any] = {"level_percent": level}
        for key in ("own", "common"):
            part: dict[str, Any] = {}
            for time_key in ("whole_s", "solve_s"):
                best = {}
                for code in ("ancfdrv", "exudyn"):
                    ok = [r for r in rows if r["code"] == code and r["ok"]
                          and r[f"error_{key}_percent"] <= level]
                    pick = min(ok, key=lambda r: r[time_key]) if ok else None
                    best[code] = None if pick is None else {
                        "label": pick["label"], "whole_s": pick["whole_s"],
                        "solve_s": pick["solve_s"], "with_file_s": pick.get("with_file_s"),
                        "error_percent": pick[f"error_{key}_percent"]}
                a, x = best["ancfdrv"], best["exudyn"]
                part[time_key.removesuffix("_s")] = {
                    **best, "exudyn_over_ancfdrv": x[time_key] / a[time_key] if a and x else None}
                if time_key == "whole_s":
                    part["whole"]["exudyn_over_ancfdrv_with_file"] = (
                        x["whole_s"] / a["with_file_s"] if a and x and a.get("with_file_s")
                        else None)
            entry[key] = part
        table.append(entry)
    return table


EXUDYN_SCRIPT = ("import sys; sys.path.insert(0, {bench!r}); import peer_harness as p; "
                 "p.exudyn_script(sys.argv[1])")


def exudyn_script(spec: str) -> None:
    """What a user's Exudyn script does for one level configuration (run by
    :func:`command_line` in a fresh interpreter): import Exudyn (its fast module), build the
    boom, solve the static start and the dynamics, print the final sag."""
    data = json.loads(spec)
    exu, note = import_exudyn(fast=True)
    if exu is None:
        raise SystemExit(f"exudyn: {note}")
    boom = Boom(**data["boom"])
    c = data["config"]
    newton = ExudynNewton(**c["newton"])
    run = run_exudyn_boom(exu, boom, c["per_segment"], True, False,
                          uniform_grid(boom.t_end, LEVEL_SAMPLE_DT), 1, 0.0, newton, c["dense"])
    if not run.ok:
        raise SystemExit(run.message)
    print(f"final sag {run.history[-1]:.6e} m")


def command_line(table: list[dict[str, Any]], configs: dict[str, LevelConfig], boom: Boom,
                 base: list[str], workdir: Path, args: argparse.Namespace) -> None:
    """Time each code's fastest configuration per level (common reference, by whole call)
    from the command line: ``ancf run`` of the scene with the configuration's overrides, and
    a Python script that builds and runs Exudyn's boom; a fresh interpreter per call, the
    calls interleaved, best of ``--repeats``. Adds 'command_s' to the level table's picks.

    Both run as installed, byte-compiled code (``command_cost.installed_copy``): ancfdrv as
    ``pip install .`` leaves it (not this workplace's editable install, whose loader runs
    ninja on every start, nor uncompiled sources where PYTHONDONTWRITEBYTECODE is set), run
    as its console script does, and the peer's script from a byte-compiled copy of this
    harness; each with ``python -S`` and PYTHONPATH (the copy, then the site-packages)."""
    import subprocess

    from command_cost import ENTRY, installed_copy, installed_env

    picks = {entry["common"]["whole"][code]["label"]
             for entry in table for code in ("ancfdrv", "exudyn")
             if entry["common"]["whole"][code]}
    package = workdir / "installed"
    if not (package / "ancfdrv").exists():
        installed_copy(package)
    peer = workdir / "peer_script"
    if not (peer / "peer_harness.py").exists():
        peer.mkdir(parents=True, exist_ok=True)
        for name in ("peer_harness.py", "_peer.py"):
            (peer / name).write_bytes((REPO / "benchmarks" / name).read_bytes())
        subprocess.run([sys.executable, "-m", "compileall", "-q", str(peer)], check=True)
    commands: dict[str, tuple[list[str], dict[str, str]]] = {}
    for label in sorted(picks):
        c = configs[label]
        if c.code == "ancfdrv":
            sets = [x for o in base + c.overrides for x in ("--set", o)]
            commands[label] = ([sys.executable, "-S", "-c", ENTRY, "run",
                                str(REPO / "inputs/boom_luffing.nml"), *sets,
                                "-o", str(workdir / "command.h5")], installed_env(package))
        else:
            spec = json.dumps({"boom": asdict(replace(boom, dt=c.dt)), "config": asdict(c)})
            commands[label] = ([sys.executable, "-S", "-c",
                                EXUDYN_SCRIPT.format(bench=str(peer)), spec],
                               installed_env(peer))
    best: dict[str, float] = {}
    for _ in range(args.repeats):
        for label, command in commands.items():
            if label in best and math.isnan(best[label]):
                continue
            t0 = time.perf_counter()
            done = subprocess.run(command[0], capture_output=True, text=True, cwd=workdir,
                                  env=command[1])
            elapsed = time.perf_counter() - t0
            if done.returncode != 0:
                print(f"  command line {label}: exit {done.returncode}: {done.stderr[-300:]}",
                      file=sys.stderr, flush=True)
                best[label] = math.nan
                continue
            best[label] = min(best.get(label, math.inf), elapsed)
    for entry in table:
        part = entry["common"]["whole"]
        for code in ("ancfdrv", "exudyn"):
            if part[code]:
                part[code]["command_s"] = best.get(part[code]["label"], math.nan)
        a, x = part["ancfdrv"], part["exudyn"]
        part["command_exudyn_over_ancfdrv"] = (ratio(x["command_s"], a["command_s"])
                                               if a and x else None)


def _ratio(value: float | None) -> str:
    return _f(value, ".2f") if value is not None and math.isfinite(value) else "-"


def levels_markdown(rec: dict[str, Any]) -> list[str]:
    out = ["## levels: each accuracy level's fastest configuration (luffing boom, 10 s)", "",
           "Each code's configuration per level is its fastest (by whole call) that meets the "
           f"level, from a grid over mesh and time step (dt {', '.join(f'{d:g}' for d in rec['dts'])} s): "
           "ancfdrv's nonlinear cable reduced to the plane (`beam.bending = cable`, "
           "`scene.planar = xy`) at 4, 7, 10, 16 nodes, output and answers (no XDMF); "
           "Exudyn's `ObjectANCFCable2D` at 3, 6, 9, 18 "
           "elements in its `exudynCPPfast` module on one thread, modified Newton, its dense "
           "and its sparse LU below 10 elements, sensors every "
           f"{rec['exudyn_sensor_period']:g} s, no solution file. Newton tolerances, one rule "
           "for both codes (each configuration's loosest that keeps its sag history within "
           f"{100 * rec['history_keep']:g} % of the range of the same configuration at a "
           "tight setting, chosen in this run; the table after each mass's runs): ancfdrv's "
           f"`newton_tol` of {', '.join(f'{t:g}' for t in rec['ancfdrv_newton_tols'][:-1])} "
           f"against {rec['ancfdrv_newton_tols'][-1]:g}; Exudyn's absolute/relative "
           f"tolerances {' or '.join(rec['exudyn_newton'][:-1])} (contractivity 0.05) against "
           f"its defaults. "
           "Error: max |sag - sag_ref| at every "
           f"{rec['sample_dt']:g} s in % of the reference's sag range; 'common': against "
           "ancfdrv's cable at 55 nodes and dt "
           f"{rec['reference_dt']:g} s (converged in space and time: see the checks), the "
           "Euler-Bernoulli model both cables converge to; 'own': each code against its own "
           f"finest run (Exudyn: 54 elements, dt {rec['reference_dt']:g} s, its default "
           "tolerances). Times, best of the interleaved rounds: 'whole' the whole in-process "
           "call with the results kept in memory, like for like (ancfdrv: `ancfdrv.simulate`; "
           "Exudyn: build, static start, `SolveDynamic`, sensor read, no solution file), "
           "'with file' ancfdrv's call writing its HDF5 file (`run_scene`; ratio against "
           "Exudyn's whole call), 'solve' the dynamic solve alone (ancfdrv: `/dynamic` "
           "`wall_time_s`; Exudyn: `SolveDynamic`), 'command' from the shell in a fresh "
           "interpreter (`ancf run` with `--set`; a Python script building and running "
           "Exudyn's model; both installed and byte-compiled as `pip install .` leaves them, "
           "run with `python -S`, not from an editable install). Ratio: Exudyn's time / "
           "ancfdrv's (> 1: ancfdrv faster).", ""]
    for mass, m in rec["masses"].items():
        checks = "; ".join(f"{name} ({c['label']}) {_f(c['error_common_percent'], '.4f')} %"
                           for name, c in m["reference_checks"].items())
        refs = "; ".join(f"{code}: {r['label']}, {_f(r['error_common_percent'], '.4f')} % from "
                         "the common reference" for code, r in m["references"].items())
        out += [f"### tip mass {mass} kg (sag range {m['sag_range_m']:.4f} m)", "",
                f"References: {refs}. Checks of the common reference (distance from it): "
                f"{checks or 'none'}.", "",
                "| level | against | ancfdrv fastest | whole s | with file s | solve s | command s "
                "| error % | Exudyn fastest | whole s | with file s | solve s | command s | error % "
                "| ratio whole | ratio with file | ratio solve | ratio command |",
                "|---|---|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:"
                "|---:|"]
        for entry in m["levels"]:
            for key in ("common", "own"):
                w, s = entry[key]["whole"], entry[key]["solve"]

                def cells(p: dict[str, Any] | None) -> str:
                    if p is None:
                        return "none | - | - | - | - | -"
                    file_s = _f(p["with_file_s"]) if p.get("with_file_s") else "-"
                    return (f"{p['label']} | {_f(p['whole_s'])} | {file_s} | {_f(p['solve_s'])} | "
                            f"{_f(p['command_s']) if 'command_s' in p else '-'} | "
                            f"{_f(p['error_percent'], '.4f')}")
                out.append(f"| {entry['level_percent']:g} % | {key} | {cells(w['ancfdrv'])} | "
                           f"{cells(w['exudyn'])} | {_ratio(w['exudyn_over_ancfdrv'])} | "
                           f"{_ratio(w.get('exudyn_over_ancfdrv_with_file'))} | "
                           f"{_ratio(s['exudyn_over_ancfdrv'])} | "
                           f"{_ratio(w.get('command_exudyn_over_ancfdrv'))} |")
        out += ["", "| code | run | whole s | solve s | steps | Newton | factorizations | "
                "error own % | error common % |",
                "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
        for r in m["runs"]:
            c = r["counts"]
            state = "" if r["ok"] else f" (failed: {r['message'][:80]})"
            out.append(f"| {r['code']} | {r['label']}{state} | {_f(r['whole_s'])} | "
                       f"{_f(r['solve_s'])} | {c.get('steps', '-')} | "
                       f"{c.get('newton_iterations', '-')} | "
                       f"{c.get('factorizations', c.get('jacobians', '-'))} | "
                       f"{_f(r['error_own_percent'], '.4f')} | "
                       f"{_f(r['error_common_percent'], '.4f')} |")
        out.append("")
        rows = [{"code": r["code"], "run": r["label"], "tried": r["newton_tried"],
                 "chosen": r["config"]["newton_tol"] if r["code"] == "ancfdrv"
                 else r["config"]["newton"]["label"]}
                for r in m["runs"] if r.get("newton_tried")]
        out += tolerance_markdown(rows, f"Tip mass {mass} kg, Newton tolerances (Exudyn's "
                                  "chosen on its sparse LU, for both LUs)")
    return out


# -- command line ------------------------------------------------------------------------------
def parse_only(text: str) -> list[str]:
    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in PROBLEM_NAMES]
    if unknown:
        raise argparse.ArgumentTypeError(f"unknown problem(s) {', '.join(unknown)}; choose from "
                                         f"{', '.join(PROBLEM_NAMES)}")
    return names


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="short runs and coarse grids (a smoke run; the numbers mean little)")
    parser.add_argument("--only", type=parse_only, action="append", default=None,
                        metavar="PROBLEM[,PROBLEM]",
                        help=f"problems to run (default all): {', '.join(PROBLEM_NAMES)}")
    parser.add_argument("--repeats", type=int, default=3,
                        help="repeats of each timed solve, the best is kept (default 3)")
    parser.add_argument("--budget", type=float, default=30.0,
                        help="stop repeating a measurement once its samples took this many "
                             "seconds (default 30)")
    parser.add_argument("--hard-min-time", type=float, default=1.0,
                        help="spinup/pendulum: repeat a run until it took this long in all, at "
                             "most --repeats times (peer_exudyn.py's rule; default 1 s)")
    parser.add_argument("--hard-bending", choices=("cubic", "cubic-planar", "cable-planar"),
                        nargs="+", default=["cubic-planar", "cable-planar"],
                        help="spinup: ancfdrv's options, the first gives the reference and the "
                             "dominance, the level table takes each level's fastest of all "
                             "(default 'cubic-planar' 'cable-planar': the cubic option with "
                             "scene.planar = 'xy', issue 23, and the ANCF cable reduced to its "
                             "plane, clamped to the hub by r and r_x, as Exudyn's ANCFCable2D)")
    parser.add_argument("--pendulum-bending", choices=("cubic", "cubic-planar", "cable-planar"),
                        default="cable-planar",
                        help="pendulum: ancfdrv's option (default 'cable-planar': the ANCF "
                             "cable reduced to its plane, issue 23)")
    parser.add_argument("--no-exudyn", action="store_true", help="ancfdrv only")
    parser.add_argument("--masses", type=float, nargs="+", default=[50.0, 0.0],
                        help="levels: the tip masses (kg; default 50 0)")
    parser.add_argument("--leaf-previous", type=Path, default=None,
                        help="JSON of an earlier harness run whose leaf-spring history to "
                             "compare with (default: the output file, before it is replaced)")
    parser.add_argument("--output", type=Path, default=None,
                        help="JSON file (default benchmarks/results/peer_harness.json, "
                             "peer_harness_quick.json with --quick); the Markdown goes next to "
                             "it with the suffix .md (not with --quick)")
    args = parser.parse_args(argv)
    args.only = [n for group in args.only for n in group] if args.only else list(PROBLEM_NAMES)
    if args.output is None:
        args.output = RESULTS / ("peer_harness_quick.json" if args.quick else "peer_harness.json")
    if args.repeats < 1:
        parser.error("--repeats must be at least 1")
    return args


def load_previous(path: Path) -> dict[str, Any] | None:
    """The leaf record of an earlier harness JSON, if there is one."""
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    leaf = data.get("problems", {}).get("leaf")
    if leaf is not None:
        leaf = dict(leaf, created=data.get("created"))
    return leaf


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    start = time.perf_counter()
    from _common import load_average, machine_info, write_report

    importlib.import_module("ancfdrv.runner")  # import time stays out of the first measurement
    from ancfdrv import _kernel

    exu, exudyn_note = ((None, "--no-exudyn") if args.no_exudyn
                        else import_exudyn(fast=True))
    plan = QUICK if args.quick else FULL
    machine = machine_info()
    kernel_file = Path(_kernel.__file__)
    kernel_mtime = kernel_file.stat().st_mtime
    previous = load_previous(args.leaf_previous or args.output)
    problems: dict[str, Any] = {}
    load_per_problem: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="peer_harness_") as tmp:
        workdir = Path(tmp)
        boom_runs = BoomRuns(plan, exu, workdir, args) if {"boom_ffr", "boom_nonlinear"} & set(
            args.only) else None
        for name in args.only:
            load_per_problem[name] = load_average()
            print(f"[{name}] load average {load_per_problem[name]}", file=sys.stderr, flush=True)
            if name == "boom_ffr" and boom_runs is not None:
                problems[name] = {**boom_runs.record(), **compare_boom_ffr(boom_runs)}
            elif name == "boom_nonlinear" and boom_runs is not None:
                problems[name] = {**boom_runs.record(), **compare_boom_nonlinear(boom_runs)}
            elif name == "plate":
                problems[name] = compare_plate(plan, exu, workdir, args)
            elif name in ("spinup", "pendulum"):
                for key, problem in hard_problems(plan, [name]).items():
                    problems[key] = compare_hard(problem, exu, workdir, args)
            elif name == "leaf":
                problems[name] = compare_leaf(plan, workdir, args, previous)
            elif name == "levels":
                problems[name] = boom_levels(plan, exu, workdir, args)
    machine["load_average_at_end"] = load_average()
    machine["load_average_per_problem"] = load_per_problem
    reinstalled = kernel_file.stat().st_mtime != kernel_mtime
    report: dict[str, Any] = {
        "benchmark": "peer_harness",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "settings": {"quick": args.quick, "only": args.only, "repeats": args.repeats,
                     "budget_s": args.budget, "hard_min_time_s": args.hard_min_time,
                     "plan": asdict(plan), "omp_num_threads": os.environ.get("OMP_NUM_THREADS")},
        "units": "seconds, metres; ratios: Exudyn time / ancfdrv time",
        "machine": machine,
        "ancfdrv_kernel": {"module": str(kernel_file), "reinstalled_during_run": reinstalled},
        "exudyn": {"available": exu is not None, "skipped_because": exudyn_note,
                   "version": exudyn_version(exu) if exu is not None else None,
                   "build": exudyn_build(exu) if exu is not None else None},
        "stored_figures": STORED_FIGURES,
        "problems": problems,
    }
    report["ratios"] = ratio_rows(problems)
    report["wall_time_s"] = time.perf_counter() - start
    text = markdown(report)
    if "levels" in problems:
        text += "\n".join(levels_markdown(problems["levels"])) + "\n"
    text += "\n".join(hard_levels_markdown(problems)) + "\n"
    if reinstalled:
        text += ("\nWARNING: ancfdrv's kernel module changed during the run (a reinstall): the "
                 "runs may mix two builds.\n")
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
