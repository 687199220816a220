"""The subprocess side of ``before_after.py``: runs in the Python environment of one ancfdrv
version (the interpreter given on before_after's command line, from that version's checkout
directory), imports whichever ancfdrv that environment holds and prints one JSON object on
stdout. Nothing here may import the benchmarks' other modules or assume one version's
internals beyond what the two versions share (``ancfdrv.runner.run_scene``); the dispatch
measurement reaches the integrator through the import paths of either version.

    python _before_after_worker.py run SCENE OUT.h5 [OVERRIDE ...]
    python _before_after_worker.py dispatch SCENE STEPS REPEATS [OVERRIDE ...]
"""
from __future__ import annotations

import json
import os
import sys
import time
import traceback


def _ancfdrv_info() -> dict:
    import ancfdrv
    return {"ancfdrv_file": ancfdrv.__file__,
            "ancfdrv_version": getattr(ancfdrv, "__version__", None),
            "python": sys.version.split()[0], "executable": sys.executable, "cwd": os.getcwd(),
            "threads": {k: os.environ.get(k) for k in ("OMP_NUM_THREADS",
                                                         "OPENBLAS_NUM_THREADS")}}


def run(scene: str, out: str, overrides: list[str]) -> dict:
    """One ``run_scene`` call; its wall time (imports apart) and the import time."""
    t0 = time.perf_counter()
    from ancfdrv.runner import run_scene
    import_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    outcome = run_scene(scene, overrides, out, progress=False)
    wall = time.perf_counter() - t0
    return {"import_s": import_s, "run_scene_s": wall, "warnings": list(outcome.warnings),
            **_ancfdrv_info()}


# -- dispatch overhead of the stepper's kernel call ---------------------------------------------
def _api():
    """(build_model, load_scene, solve_split, TimeIntegrator, initial_acceleration,
    initial_row or None, new) of this environment's ancfdrv."""
    try:  # the general-system layer (after the rewrite)
        from ancfdrv.builders import build_model
        from ancfdrv.io.scene import load_scene
        from ancfdrv.solvers.dynamic import TimeIntegrator, initial_acceleration, initial_row
        from ancfdrv.solvers.static import solve_split
        return build_model, load_scene, solve_split, TimeIntegrator, initial_acceleration, \
            initial_row, True
    except ImportError:  # the BeamModel layer (before)
        from ancfdrv.dynamic import TimeIntegrator, initial_acceleration
        from ancfdrv.model import build_model
        from ancfdrv.scene import load_scene
        from ancfdrv.static import solve_split
        return build_model, load_scene, solve_split, TimeIntegrator, initial_acceleration, \
            None, False


def _copy(state: dict) -> dict:
    return {k: v.copy() if hasattr(v, "copy") else v for k, v in state.items()}


def dispatch(scene_path: str, steps: int, repeats: int, overrides: list[str]) -> dict:
    """The same ``steps`` steps of the scene's dynamics, from the state after its first
    second (static start as run_scene does it), advanced by one ``TimeIntegrator.advance``
    call, by calls of 10 steps and by calls of 1 step (and, in the new version, by the raw
    ``KernelSystem.advance`` of 1 step, without the Chunk the integrator builds); each best
    of ``repeats`` interleaved samples. Every sample starts from a freshly built model
    (the new kernel keeps state of the stepper, such as the constant policy's contraction
    estimate, in the system between calls, so a replay on the same handle is not the same
    computation), and the final states of the ways are compared: the split of a run into
    calls must not change its result. The per-call overhead is the excess of the 1-step
    calls over the one call, per call."""
    import numpy as np
    from ancfdrv.runner import dynamic_settings
    build_model, load_scene, solve_split, Integrator, initial_acceleration, initial_row, new = \
        _api()
    scene = load_scene(scene_path, overrides)
    settings = dynamic_settings(scene)
    solver = scene["solver"]
    warm = int(round(1.0 / settings.dt))

    def prepared():
        """A fresh model, its integrator and the state after the start stage (the first
        call holds the factorization)."""
        model = build_model(scene)
        static = solve_split(model, tol=solver["tol"], max_iter=solver["max_iter"],
                             p=solver["split_p"])
        integrator = Integrator(model, settings)
        v0 = np.zeros(model.ndof)
        a0, lam0 = initial_acceleration(model, static.e, v0, 0.0)
        if new:
            state = integrator.state(0.0, static.e, v0, a0, lam0)
            initial_row(model, state)
        else:  # as the old integrate() builds it for a model without contact
            state = dict(t=0.0, e=static.e.copy(), v=v0.copy(), a=a0.copy(), accel=a0,
                         lam=lam0, work=np.zeros(4), contact_guess=np.zeros((2, 1)),
                         contact_counts=np.zeros(6, dtype=np.int32))
        advance(integrator, state, warm)
        return model, integrator, state

    def advance(integrator, s: dict, n: int) -> None:
        chunk, info, detail = integrator.advance(s, n)
        if info:
            raise RuntimeError(f"step failed at t = {s['t']}: kernel code {info} ({detail})")

    def release(model, integrator) -> None:
        close = getattr(model, "close", None) or getattr(integrator, "close", None)
        if close is not None:
            close()

    ways = {"one_call": (1, steps), "calls_of_10": (max(steps // 10, 1), 10),
            "calls_of_1": (steps, 1)}
    if new:
        ways["raw_calls_of_1"] = (steps, 1)
    best = {name: float("inf") for name in ways}
    finals, t_start, ndof = {}, 0.0, 0
    for _ in range(repeats):
        for name, (calls, per) in ways.items():
            model, integrator, s = prepared()
            t_start, ndof = float(s["t"]), int(model.ndof)
            t0 = time.perf_counter()
            if name == "raw_calls_of_1":
                kernel = model.kernel
                for _ in range(calls):
                    # (the settings go to the kernel once per run since issue 25)
                    # (the step-size control in the kernel since issue 36: rows, not h)
                    out = kernel.advance(1, s, False) \
                        if hasattr(kernel, "consistent_acceleration") else \
                        kernel.advance(1, settings.dt, s, False) \
                        if hasattr(kernel, "stepper_setup") else \
                        kernel.advance(1, settings, s, False)
                    if out["status"][1]:
                        raise RuntimeError(f"kernel step failed: {out['status']}")
            else:
                for _ in range(calls):
                    advance(integrator, s, per)
            best[name] = min(best[name], time.perf_counter() - t0)
            finals[name] = s["e"].copy()
            release(model, integrator)
    per_step = best["one_call"] / steps
    return {"steps": steps, "repeats": repeats, "ndof": ndof, "new_api": new,
            "t_start": t_start, "best_s": best, "per_step_us": 1e6 * per_step,
            "per_call_us": {name: 1e6 * best[name] / calls
                            for name, (calls, _) in ways.items()},
            # the excess of a call over the steps it advances
            "overhead_per_call_us": {
                name: 1e6 * (best[name] - per_step * calls * per) / calls
                for name, (calls, per) in ways.items() if name != "one_call"},
            "final_state_max_difference": {
                name: float(np.abs(finals[name] - finals["one_call"]).max())
                for name, (calls, per) in ways.items() if calls * per == steps},
            **_ancfdrv_info()}


def main(argv: list[str]) -> int:
    try:
        if argv[0] == "run":
            out = run(argv[1], argv[2], argv[3:])
        elif argv[0] == "dispatch":
            out = dispatch(argv[1], int(argv[2]), int(argv[3]), argv[4:])
        else:
            raise SystemExit(f"unknown command {argv[0]!r}")
    except Exception as exc:  # reported to the parent, which records it and goes on
        print(json.dumps({"error": f"{type(exc).__name__}: {exc}",
                          "traceback": traceback.format_exc()[-4000:]}))
        return 1
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
