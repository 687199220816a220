"""One scene, start to finish: namelist -> Scene -> Model -> solve -> HDF5.

This is the path every command takes; read it top to bottom to follow a run.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from . import results
from .errors import AncfError
from .model import build_model
from .scene import Scene, load_scene
from .static import StaticResult, solve_static


@dataclass
class RunOutcome:
    """What a run produced: the output file and the static result."""

    scene: Scene
    output: Path
    static: StaticResult | None
    warnings: list[str]


def run_scene(path: str | Path, overrides: list[str] | None = None,
              output: str | Path | None = None) -> RunOutcome:
    """Run a scene file. Raises InputError (bad input) or SolverError (solver failure);
    in the latter case the output file already holds the model and the failure message."""
    start = time.perf_counter()
    scene = load_scene(path, overrides)
    return run_loaded(scene, output, start=start)


def run_loaded(scene: Scene, output: str | Path | None = None, *,
               start: float | None = None) -> RunOutcome:
    start = time.perf_counter() if start is None else start
    out = Path(output) if output else scene.output_file
    t0 = time.perf_counter()
    model = build_model(scene)
    timing: dict[str, Any] = {"model": time.perf_counter() - t0}
    results.create(out, scene, model)
    static = None
    try:
        solver = scene["solver"]
        static = solve_static(model, solver["static_method"], tol=solver["tol"],
                              max_iter=solver["max_iter"], p=solver["split_p"])
        for phase, seconds in static.timing.items():
            timing[f"static_{phase}"] = seconds
        t0 = time.perf_counter()
        results.write_static(out, model, static)
        timing["output"] = time.perf_counter() - t0
    except AncfError as exc:
        timing["total"] = time.perf_counter() - start
        results.finish(out, model, timing, "failed", str(exc))
        raise
    timing["total"] = time.perf_counter() - start
    results.finish(out, model, timing, "ok")
    return RunOutcome(scene, out, static, model.warnings)
