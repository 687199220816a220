"""One scene, start to finish: namelist -> Scene -> Model -> solve -> HDF5.

This is the path every command takes; read it top to bottom to follow a run:
``static`` solves the equilibrium; ``dynamic`` integrates from the rigid configuration at
rest; ``static+dynamic`` integrates from the static equilibrium (SPEC section 5).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from .io import hdf5 as results
from .solvers.dynamic import DynamicResult, DynamicSettings, integrate
from .errors import AncfError
from .history import luffing_stage_bounds, stage_summary
from .builders import build_model
from .io.scene import Scene, load_scene
from .system import Model
from .solvers.static import StaticResult, solve_static


@dataclass
class RunOutcome:
    """What a run produced: the output file and the results of each analysis."""

    scene: Scene
    output: Path
    static: StaticResult | None
    dynamic: DynamicResult | None
    warnings: list[str]
    stages: dict[str, float] = field(default_factory=dict)


def run_scene(path: str | Path, overrides: list[str] | None = None,
              output: str | Path | None = None, *, progress: bool | None = None) -> RunOutcome:
    """Run a scene file. Raises InputError (bad input) or SolverError (solver failure);
    in the latter case the output file already holds everything computed until then."""
    start = time.perf_counter()
    scene = load_scene(path, overrides)
    return run_loaded(scene, output, start=start, progress=progress)


def dynamic_settings(scene: Scene) -> DynamicSettings:
    """Newmark with the scene's beta and gamma, or generalized-alpha from rho_inf."""
    solver, output = scene["solver"], scene["output"]
    common = dict(tol=solver["newton_tol"], max_newton=solver["max_newton"],
                  chunk_steps=output["chunk_steps"], store_q=output["q"],
                  jacobian=solver["jacobian"], contraction=solver["contraction"])
    if solver["integrator"] == "generalized_alpha":
        return DynamicSettings.generalized_alpha(solver["dt"], solver["t_end"],
                                                 solver["rho_inf"], **common)
    return DynamicSettings(dt=solver["dt"], t_end=solver["t_end"], beta=solver["beta"],
                           gamma=solver["gamma"], **common)


def boom_stages(scene: Scene) -> dict[str, tuple[float, float]] | None:
    """Stage bounds of a luffing boom scene (None when the boom does not luff)."""
    if scene.kind != "boom" or scene["boom"]["omega"] <= 0:
        return None
    boom = scene["boom"]
    sweep = np.radians(boom["angle_end_deg"] - boom["angle_deg"])
    return luffing_stage_bounds(boom["omega"], boom["t_start"], boom["t_brake"], sweep,
                                scene["solver"]["t_end"])


def _run_dynamic(scene: Scene, model: Model, out: Path, e_start: np.ndarray,
                 timing: dict[str, Any], progress: bool | None) -> tuple[DynamicResult, dict]:
    settings = dynamic_settings(scene)
    if model.plate_bodies():
        settings.store_q = True  # the node positions for ParaView (XDMF) come from q
    writer = results.DynamicWriter(out, model, settings.store_q)
    dyn = integrate(model, settings, e_start, sink=writer, progress=progress)
    for phase, seconds in dyn.timing.items():
        timing[f"dynamic_{phase}"] = seconds
    stages: dict[str, float] = {}
    if any(s.kind == "ffr" for s in model.sets) and "tip" in model.probes:
        with h5py.File(out, "r") as h5:
            deflection = h5["dynamic/deflection/tip"][()]
        ratio = np.abs(deflection).max() / model.length_scale
        if ratio > 0.05:
            model.warnings.append(
                f"formulation 'ffr' outside its assumptions: the tip deflects by {ratio:.2%} of "
                "the length (small deformation assumed); compare with formulation = "
                "'nonlinear'")
    bounds = boom_stages(scene)
    if bounds:
        with h5py.File(out, "r") as h5:
            t = h5["dynamic/time"][()]
            transverse = h5["dynamic/deflection/tip"][:, 1]
        stages = stage_summary(t, transverse, bounds)
    results.write_dynamic_attrs(out, {
        "integrator": scene["solver"]["integrator"], "dt": settings.dt, "beta": settings.beta,
        "gamma": settings.gamma, "alpha_m": settings.alpha_m, "alpha_f": settings.alpha_f,
        "rho_inf": scene["solver"]["rho_inf"] if scene["solver"]["integrator"] ==
        "generalized_alpha" else 1.0, "steps": dyn.steps, "newton_iterations": dyn.newton_iterations,
        "factorizations": dyn.factorizations, "jacobian_evaluations": dyn.jacobians,
        "jacobian_policy": "constant" if model.constant_policy else settings.jacobian,
        "wall_time_s": dyn.wall_time_s, "status": "ok"}, stages)
    return dyn, stages


def run_loaded(scene: Scene, output: str | Path | None = None, *,
               start: float | None = None, progress: bool | None = None) -> RunOutcome:
    start = time.perf_counter() if start is None else start
    out = Path(output) if output else scene.output_file
    t0 = time.perf_counter()
    model = build_model(scene)
    timing: dict[str, Any] = {"model": time.perf_counter() - t0}
    try:
        return _run_model(scene, model, out, timing, start, progress)
    finally:
        model.close()


def _run_model(scene: Scene, model: Model, out: Path, timing: dict, start: float,
               progress: bool | None) -> RunOutcome:
    analysis = scene["scene"]["analysis"]
    results.create(out, scene, model)
    static = dynamic = None
    stages: dict[str, float] = {}
    try:
        e_start = model.e0
        if analysis in ("static", "static+dynamic"):
            solver = scene["solver"]
            static = solve_static(model, solver["static_method"], tol=solver["tol"],
                                  max_iter=solver["max_iter"], p=solver["split_p"],
                                  load_steps=solver["load_steps"])
            for phase, seconds in static.timing.items():
                timing[f"static_{phase}"] = seconds
            t0 = time.perf_counter()
            results.write_static(out, model, static)
            timing["output"] = time.perf_counter() - t0
            e_start = static.e
        if analysis in ("dynamic", "static+dynamic"):
            dynamic, stages = _run_dynamic(scene, model, out, e_start, timing, progress)
    except AncfError as exc:
        timing["total"] = time.perf_counter() - start
        results.finish(out, model, timing, "failed", str(exc))
        raise
    timing["total"] = time.perf_counter() - start
    results.finish(out, model, timing, "ok")
    return RunOutcome(scene, out, static, dynamic, model.warnings, stages)
