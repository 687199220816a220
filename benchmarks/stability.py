"""Long-run stability suite (issue 26): completion, step cuts and the energy balance of hard
cases over long times, with the step control (solver.dt_min, solver.step) of
ancfdrv.solvers.dynamic.

Cases (each reports completion, the step cuts, the steps taken, Newton corrections and the
energy balance: the drift of total - total(0) - the works of drives, frames, contact
damping, friction and material damping, i.e. the energy the method created or dissipated):

* ``double``: the flexible double pendulum (benchmarks/_stability_models.py) to 10 s over
  dt in {2.5e-4, 1e-3, 2e-3, 5e-3, 1e-2} x rho_inf in {1, 0.8, 0.5}, with the first second's
  tip error against a converged reference (the same model at dt = 2.5e-5, rho_inf = 1);
* ``adaptive``: the double pendulum with step = 'adaptive' at several tolerances, its error
  and cost next to the fixed steps';
* ``pendulum``: the flexible pendulum (inputs/hard/pendulum.nml) to 10 s at dt in
  {1e-3, 2e-3, 5e-3} x rho_inf in {1, 0.8, 0.5};
* ``spinup``: the spin-up (inputs/hard/spinup.nml) to 100 s, and fixed against adaptive over
  its first 20 s against a reference at dt = 1e-3;
* ``luffing``: the luffing boom (inputs/hard/long_luffing.nml, dt 1e-3) to 1000 s (one
  luffing, then held);
* ``luffing_cycle``: the general luffing boom luffed 0 -> 60 -> 0 deg every 20 s for 1000 s
  (dt 1e-2), through the command line;
* ``spring``: the two-leaf spring (inputs/leaf_spring.nml) to 60 s.

Usage: python benchmarks/stability.py [--cases double,pendulum,...] [--quick] [--tag before]
Results: benchmarks/results/stability[_tag].json and .md. The machine was shared (load in the
JSON): wall times are indicative only; the costs compared are steps and Newton corrections.
Runs with an older ancfdrv (no step control) are allowed: they report where they stopped.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _common import json_ready, machine_info  # noqa: E402
from _stability_models import double_pendulum  # noqa: E402

from ancfdrv.builders import build_model  # noqa: E402
from ancfdrv.errors import SolverError  # noqa: E402
from ancfdrv.io.scene import load_scene  # noqa: E402
from ancfdrv.solvers.dynamic import DynamicSettings, integrate  # noqa: E402

ROOT = HERE.parent
WORKS = (5, 6, 8, 9, 10)  # ENERGY_NAMES: drive, frame, damping, friction, material damping


def _settings(dt, t_end, rho, **kw):
    fields = DynamicSettings.__dataclass_fields__
    kw = {k: v for k, v in kw.items() if k in fields}  # an older ancfdrv: fixed steps only
    return DynamicSettings.generalized_alpha(dt, t_end, rho, **kw)


def run(model, settings, e0, probe: str, v0=None):
    """Integrate; returns the record of the run (completion, counts, energy balance) and
    the probe's history."""
    rows = []
    start = time.perf_counter()
    try:
        integrate(model, settings, e0, v0, sink=rows.append, progress=False)
        message = ""
    except SolverError as exc:
        message = str(exc)
    wall = time.perf_counter() - start
    t = np.concatenate([r.time for r in rows])
    energy = np.concatenate([r.energy for r in rows])
    tip = np.concatenate([r.probes for r in rows])[:, list(model.probes).index(probe), :]
    balance = energy[:, 4] - energy[0, 4] - energy[:, list(WORKS)].sum(axis=1)
    scale = max(np.abs(energy[:, 0]).max(), np.abs(energy[:, 1:3].sum(axis=1)
                                                   - energy[0, 1:3].sum()).max(), 1e-300)
    c = model.counters
    record = {"completed": not message, "t_reached": float(t[-1]), "message": message[:300],
              "steps": int(c["time_steps"]), "steps_taken": int(c.get("steps_taken",
                                                                       c["time_steps"])),
              "step_cuts": int(c.get("step_cuts", 0)),
              "steps_rejected": int(c.get("steps_rejected", 0)),
              "newton": int(c["newton_iterations"]),
              "factorizations": int(c["factorizations"]),
              "energy_scale_J": float(scale),
              "energy_drift_end": float(balance[-1] / scale),
              "energy_drift_max": float(np.abs(balance).max() / scale),
              "dissipated_work_J": float(-energy[-1, list(WORKS)].sum()),
              "total_drift_max": float(np.abs(energy[:, 4] - energy[0, 4]).max() / scale),
              "wall_s": round(wall, 2)}
    return record, t, tip


def _error(t, tip, ref_t, ref_tip, t_max=1.0):
    """max |tip - reference| over the rows with t <= t_max (reference interpolated)."""
    keep = t <= t_max + 1e-12
    if keep.sum() < 2:
        return None
    ref = np.stack([np.interp(t[keep], ref_t, ref_tip[:, k]) for k in range(3)], axis=1)
    return float(np.abs(tip[keep] - ref).max())


def case_double(quick: bool, adaptive_only: bool = False) -> dict:
    t_end = 1.0 if quick else 10.0
    dts = [1e-3, 1e-2] if quick else [2.5e-4, 1e-3, 2e-3, 5e-3, 1e-2]
    rhos = [1.0, 0.5] if quick else [1.0, 0.8, 0.5]
    model = double_pendulum().assemble()
    try:
        ref, ref_t, ref_tip = run(model, _settings(2.5e-5 if not quick else 1e-4, 1.0, 1.0,
                                                   tol=1e-10, max_newton=10), model.e0, "tip")
    finally:
        model.close()
    out = {"reference": ref, "grid": [], "adaptive": []}
    if not adaptive_only:
        for dt in dts:
            for rho in rhos:
                model = double_pendulum().assemble()
                try:
                    rec, t, tip = run(model, _settings(dt, t_end, rho, tol=1e-10,
                                                       max_newton=10), model.e0, "tip")
                finally:
                    model.close()
                rec.update(dt=dt, rho_inf=rho, error_1s_m=_error(t, tip, ref_t, ref_tip))
                out["grid"].append(rec)
                print("double", dt, rho, rec["completed"], rec["t_reached"], rec["step_cuts"],
                      rec["error_1s_m"], flush=True)
    for tol in ([1e-5] if quick else [1e-4, 1e-5, 1e-6]):
        model = double_pendulum().assemble()
        try:
            rec, t, tip = run(model, _settings(1e-2, t_end, 0.8, tol=1e-10, max_newton=10,
                                               step="adaptive", tolerance=tol),
                              model.e0, "tip")
        finally:
            model.close()
        rec.update(dt=1e-2, rho_inf=0.8, tolerance=tol,
                   error_1s_m=_error(t, tip, ref_t, ref_tip))
        out["adaptive"].append(rec)
        print("double adaptive", tol, rec["completed"], rec["steps_taken"], rec["newton"],
              rec["error_1s_m"], flush=True)
    return out


def _scene_run(path: str, overrides: list[str], probe: str = "tip", **kw) -> tuple:
    scene = load_scene(ROOT / path, overrides)
    model = build_model(scene)
    solver = scene["solver"]
    try:
        s = _settings(solver["dt"], solver["t_end"], solver["rho_inf"], tol=solver["newton_tol"],
                      max_newton=solver["max_newton"], jacobian=solver["jacobian"],
                      contraction=solver["contraction"], **kw)
        e0 = model.e0
        if scene.kind == "boom" and scene["solver"].get("settle", "none") == "none" and \
                "static" in scene["scene"]["analysis"]:
            from ancfdrv.solvers.static import solve_newton
            e0 = solve_newton(model, tol=scene["solver"]["tol"],
                              max_iter=scene["solver"]["max_iter"]).e
        return run(model, s, e0, probe)
    finally:
        model.close()


def case_pendulum(quick: bool) -> list:
    out = []
    for dt in ([5e-3] if quick else [1e-3, 2e-3, 5e-3]):
        for rho in ([1.0] if quick else [1.0, 0.8, 0.5]):
            rec, _, _ = _scene_run("inputs/hard/pendulum.nml",
                                   [f"solver.dt={dt}", f"solver.rho_inf={rho}",
                                    f"solver.t_end={1.0 if quick else 10.0}"])
            rec.update(dt=dt, rho_inf=rho)
            out.append(rec)
            print("pendulum", dt, rho, rec["completed"], rec["step_cuts"],
                  rec["energy_drift_max"], flush=True)
    return out


def case_spinup(quick: bool) -> dict:
    t_long = 2.0 if quick else 100.0
    rec, _, _ = _scene_run("inputs/hard/spinup.nml", [f"solver.t_end={t_long}"])
    out = {"long": rec, "accuracy": []}
    print("spinup long", rec["completed"], rec["step_cuts"], flush=True)
    t_acc = 2.0 if quick else 20.0
    _, ref_t, ref_tip = _scene_run("inputs/hard/spinup.nml",
                                   [f"solver.t_end={t_acc}", "solver.dt=1e-3"])
    for label, over, kw in [("fixed 5e-3", [], {}), ("fixed 2e-2", ["solver.dt=2e-2"], {}),
                            *[(f"adaptive {tol:g}", ["solver.dt=5e-2"],
                               {"step": "adaptive", "tolerance": tol})
                              for tol in ([1e-5] if quick else [1e-4, 1e-5, 1e-6])]]:
        r, t, tip = _scene_run("inputs/hard/spinup.nml", [f"solver.t_end={t_acc}", *over], **kw)
        r.update(label=label, error_m=_error(t, tip, ref_t, ref_tip, t_acc))
        out["accuracy"].append(r)
        print("spinup", label, r["completed"], r["steps_taken"], r["newton"], r["error_m"],
              flush=True)
    return out


def case_luffing(quick: bool) -> dict:
    rec, _, _ = _scene_run("inputs/hard/long_luffing.nml",
                           ["solver.dt=1e-3", f"solver.t_end={5.0 if quick else 1000.0}"])
    print("luffing", rec["completed"], rec["step_cuts"], rec["energy_drift_max"], flush=True)
    return rec


def case_luffing_cycle(quick: bool, tmp: Path | None = None) -> dict:
    """The general luffing boom (inputs/general/boom_luffing.nml: FFR boom, Newmark) with
    its luffing drive replaced by a repeated one, 0 -> 60 -> 0 deg every 20 s (a sine drive,
    smooth at t = 0), for 1000 s at dt = 1e-2 (1e5 rows), run by the command line: exit
    code, rows, /counters and /dynamic/energy/balance."""
    import subprocess
    import tempfile

    import h5py
    text = (ROOT / "inputs/general/boom_luffing.nml").read_text()
    start = text.index("&drive")
    end = text.index("/", text.index("end_deg", start)) + 1
    half = np.pi / 6.0
    text = (text[:start] + f"&drive  name = 'luffing', type = 'sine', amplitude = {half!r}, "
            f"frequency = 0.05, phase = {-np.pi / 2!r}, offset = {half!r} /" + text[end:])
    t_end = 20.0 if quick else 1000.0
    with tempfile.TemporaryDirectory() as tmpdir:
        scene = Path(tmpdir) / "luffing_cycle.nml"
        scene.write_text(text)
        out = Path(tmpdir) / "luffing_cycle.h5"
        ancf = Path(sys.executable).parent / "ancf"
        begin = time.perf_counter()
        proc = subprocess.run([str(ancf), "run", str(scene), "--set", "solver.dt=1e-2",
                               "--set", f"solver.t_end={t_end}", "--set", "output.xdmf=.false.",
                               "-o", str(out)], capture_output=True, text=True)
        wall = time.perf_counter() - begin
        with h5py.File(out) as h5:
            d = h5["dynamic"]
            t = d["time"][()]
            balance = d["energy/balance"][()]
            kinetic = d["energy/kinetic"][()]
            potential = d["energy/gravity"][()] + d["energy/strain"][()]
            counters = dict(h5["counters"].attrs)
            drive = d["energy/drive_work"][()]
    scale = max(np.abs(kinetic).max(), np.abs(potential - potential[0]).max())
    rec = {"completed": proc.returncode == 0, "exit_code": proc.returncode,
           "t_reached": float(t[-1]), "message": proc.stderr[-300:],
           "steps": int(counters["time_steps"]),
           "steps_taken": int(counters.get("steps_taken", counters["time_steps"])),
           "step_cuts": int(counters.get("step_cuts", 0)),
           "steps_rejected": int(counters.get("steps_rejected", 0)),
           "newton": int(counters["newton_iterations"]),
           "factorizations": int(counters["factorizations"]), "energy_scale_J": float(scale),
           "energy_drift_end": float(balance[-1] / scale),
           "energy_drift_max": float(np.abs(balance).max() / scale),
           "drive_work_J": float(drive[-1]), "dt": 1e-2, "rho_inf": 1.0,
           "wall_s": round(wall, 2)}
    print("luffing cycle", rec["completed"], rec["step_cuts"], rec["energy_drift_max"],
          flush=True)
    return rec


def case_spring(quick: bool) -> dict:
    return _spring(quick)


def _spring(quick: bool) -> dict:
    scene = load_scene(ROOT / "inputs/leaf_spring.nml",
                       [f"solver.t_end={0.2 if quick else 60.0}"])
    from ancfdrv.builders import settle_mode
    from ancfdrv.runner import dynamic_settings
    model = build_model(scene)
    try:
        e0 = model.e0
        mode = settle_mode(scene)
        if mode != "none":
            from ancfdrv.solvers.static import solve_newton
            e0 = solve_newton(model, tol=scene["solver"]["tol"],
                              max_iter=scene["solver"]["max_iter"],
                              load_steps=scene["solver"]["load_steps"],
                              loads=0.0 if mode == "unloaded" else 1.0).e
        rec, _, _ = run(model, dynamic_settings(scene), e0, list(model.probes)[0])
    finally:
        model.close()
    print("spring", rec["completed"], rec["step_cuts"], rec["energy_drift_max"], flush=True)
    return rec


CASES = {"double": case_double, "pendulum": case_pendulum, "spinup": case_spinup,
         "luffing": case_luffing, "spring": case_spring, "luffing_cycle": case_luffing_cycle,
         "adaptive": lambda quick: case_double(quick, adaptive_only=True)}


def markdown(results: dict) -> str:
    lines = [f"# Long-run stability suite ({results.get('tag') or 'current'})", "",
             "Completion, step cuts (failed steps retried with half the step), steps taken, "
             "Newton corrections and the energy balance (max |total - total(0) - works| "
             "over the run and its end value, relative to the energy scale: the largest "
             "kinetic energy or change of potential energy), total end = (total - "
             "total(0)) / scale at the end. For the pendulums (no drive) the works hold only "
             "the 'drive' power lambda . Phi_e e' of the joints, which the index-3 method "
             "leaves nonzero (velocity-level violation), so 'total end' is their drift. "
             "Errors: the double pendulum's tip over its first second against dt = 2.5e-5; "
             "the spin-up's tip over 20 s against dt = 1e-3.", ""]
    head = "| case | dt | rho_inf | completed | t reached | cuts | steps taken | Newton | " \
           "balance max | balance end | total end | error (m) |"
    rule = "|" + "---|" * 12

    def row(name, r):
        err = r.get("error_1s_m", r.get("error_m"))
        return (f"| {name} | {r.get('dt', '')} | {r.get('rho_inf', '')} | "
                f"{'yes' if r['completed'] else 'no'} | {r['t_reached']:.3f} | "
                f"{r['step_cuts']} | {r['steps_taken']} | {r['newton']} | "
                f"{r['energy_drift_max']:.2e} | {r['energy_drift_end']:.2e} | "
                f"{total_end(r):.2e} | {'' if err is None else f'{err:.2e}'} |")

    def total_end(r):  # (total - total(0)) / scale at the end: the balance plus the works
        return r["energy_drift_end"] - r.get("dissipated_work_J", 0.0) / r["energy_scale_J"]
    lines += [head, rule]
    c = results["cases"]
    if "double" in c:
        lines += [row("double pendulum", r) for r in c["double"]["grid"]]
        lines += [row(f"double, adaptive tol {r['tolerance']:g}", r)
                  for r in c["double"]["adaptive"]]
    if "adaptive" in c:
        lines += [row(f"double, adaptive tol {r['tolerance']:g}", r)
                  for r in c["adaptive"]["adaptive"]]
    for r in c.get("pendulum", []):
        lines.append(row("flexible pendulum", r))
    if "spinup" in c:
        lines.append(row("spin-up 100 s", c["spinup"]["long"]))
        lines += [row(f"spin-up 20 s, {r['label']}", r) for r in c["spinup"]["accuracy"]]
    if "luffing" in c:
        lines.append(row("luffing boom 1000 s", c["luffing"]))
    if "luffing_cycle" in c:
        lines.append(row("luffing boom, 0-60-0 deg every 20 s, 1000 s", c["luffing_cycle"]))
    if "spring" in c:
        lines.append(row("two-leaf spring 60 s", c["spring"]))
    failed = [r for r in c.get("double", {}).get("grid", []) if not r["completed"]]
    for r in failed:
        lines.append(f"\n- double pendulum dt {r['dt']} rho_inf {r['rho_inf']}: {r['message']}")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", default="double,pendulum,spinup,luffing,spring")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--tag", default="")
    parser.add_argument("--markdown", help="rewrite the .md of an existing JSON and stop")
    args = parser.parse_args()
    if args.markdown:
        path = Path(args.markdown)
        path.with_suffix(".md").write_text(markdown(json.loads(path.read_text())))
        return
    results = {"machine": machine_info(), "tag": args.tag, "quick": args.quick, "cases": {}}
    stem = "stability" + (f"_{args.tag}" if args.tag else "") + ("_quick" if args.quick else "")
    out = HERE / "results"
    out.mkdir(exist_ok=True)
    for name in args.cases.split(","):  # written after each case: a long run keeps the rest
        results["cases"][name] = CASES[name](args.quick)
        (out / f"{stem}.json").write_text(json.dumps(json_ready(results), indent=1))
        (out / f"{stem}.md").write_text(markdown(results))
    print(markdown(results))


if __name__ == "__main__":
    main()
