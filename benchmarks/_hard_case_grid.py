"""The hard-case suite of record (issue 39 item 5), shared by tests/test_hard_case_suite.py
(a fast subset) and benchmarks/hard_case_suite.py (the grid): each run of a shipped hard
scene is classified

* 'correct': exit 0, its probe within the stated tolerance of a converged reference of the
  same model (the same mesh at a quarter of the step, rho_inf 0.8) up to the case's
  horizon, and the energy it creates (the balance total - total(0) - works at its
  highest) within 1 % of the run's energy scale over the whole run (numerical dissipation,
  rho_inf < 1, is reported as the balance at its lowest, not judged) (beyond the horizon a swinging flexible pendulum's
  trajectory is sensitive: at 10 s runs at dt and dt / 4 differ by 0.5 m at every step
  size, so the balance, not the trajectory, tells a right run from a wrong one there);
* 'refused': exit 3 (a solver failure or the energy audit's 'unstable'), the rows kept;
* 'ok and wrong': exit 0 and the probe beyond the tolerance: never acceptable;
* anything else ('error'): a bug.
"""
from __future__ import annotations

import contextlib
import io
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from ancfdrv.cli import main

INPUTS = Path(__file__).resolve().parent.parent / "inputs" / "hard"


@dataclass(frozen=True)
class Case:
    """One run: a scene under inputs/hard/, its --set overrides, the probe compared and the
    tolerance (m) on its largest distance from the reference over the run."""
    name: str
    scene: str
    sets: tuple[str, ...]
    probe: str
    tolerance: float
    dt: float
    horizon: float = 1.0
    reference_sets: tuple[str, ...] = field(default=())

#: the energy balance a correct run keeps, relative to its energy scale
BALANCE_TOLERANCE = 0.01


def run_scene(scene: str, sets: tuple[str, ...], out: Path) -> tuple[int, np.ndarray, dict]:
    """Runs the scene (CLI, output silenced); returns the exit code, and the time and probe
    histories (empty when no file was written)."""
    args = ["run", str(INPUTS / scene), "-o", str(out), "--set", "output.xdmf=.false.",
            "--set", "output.answers=.false."]
    for s in sets:
        args += ["--set", s]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = main(args)
    probes = {}
    if out.exists():
        with h5py.File(out) as h:
            d = h["dynamic"]
            energy = d["energy"]
            scale = max(np.abs(energy["kinetic"][:]).max(),
                        np.abs(energy["gravity"][:] - energy["gravity"][0]).max(),
                        np.abs(energy["strain"][:]).max(), 1e-300)
            probes = {"time": d["time"][:], "status": str(d.attrs.get("status", "")),
                      "corrections": int(d.attrs.get("newton_iterations", 0)),
                      "cuts": int(d.attrs.get("step_cuts", 0)),
                      "balance": float(energy["balance"][:].max() / scale),
                      "dissipated": float(-energy["balance"][:].min() / scale)}
            for name in d["probes"]:
                probes[name] = d["probes"][name][:]
    return code, probes.get("time", np.zeros(0)), probes


def classify(case: Case, workdir: Path, references: dict | None = None) -> dict:
    """The record of one run of case: its class, error against the reference (m), exit
    code, status and counts. references: the reference runs made so far, by their
    overrides (run_scene's probes; updated)."""
    references = {} if references is None else references
    extra = (f"solver.dt={case.dt / 4:g}", "solver.rho_inf=0.8") + case.reference_sets
    keys = {s.split("=")[0] for s in extra}
    ref_sets = tuple(sorted(s for s in case.sets if s.split("=")[0] not in keys)) + extra
    if (case.scene, ref_sets) not in references:
        code, _, made = run_scene(case.scene, ref_sets,
                                  workdir / f"ref{len(references)}.h5")
        if code != 0:
            raise RuntimeError(f"{case.name}: the reference run ended with exit {code}")
        references[(case.scene, ref_sets)] = made
    reference = references[(case.scene, ref_sets)]
    code, t, got = run_scene(case.scene, case.sets + (f"solver.dt={case.dt:g}",),
                             workdir / f"{case.name}.h5")
    record = {"case": case.name, "exit": code, "status": got.get("status", ""),
              "corrections": got.get("corrections", 0), "cuts": got.get("cuts", 0),
              "tolerance_m": case.tolerance, "horizon_s": case.horizon, "error_m": None,
              "balance": got.get("balance"), "dissipated": got.get("dissipated")}
    if code == 0:
        ref_t, ref_p = reference["time"], reference[case.probe]
        keep = t <= case.horizon + 1e-9
        p = got[case.probe][keep]
        ref = np.stack([np.interp(t[keep], ref_t, ref_p[:, k]) for k in range(3)], axis=1)
        record["error_m"] = float(np.abs(p - ref).max())
        right = record["error_m"] <= case.tolerance and record["balance"] <= BALANCE_TOLERANCE
        record["class"] = "correct" if right else "ok and wrong"
    elif code == 3:
        record["class"] = "refused"
    else:
        record["class"] = "error"
    return record
