"""Regression gate of a kernel refactoring: run the dynamic scenes (inputs/, inputs/general/,
inputs/hard/) for a short t_end with each Jacobian policy and step control, on two builds,
and compare the HDF5 histories bitwise.

    python benchmarks/history_gate.py run <outdir> [<site>]   # this python, ancfdrv from <site>
    python benchmarks/history_gate.py examples <outdir> [<site>]   # examples/ --quick
    python benchmarks/history_gate.py diff <outdir_a> <outdir_b>
    python benchmarks/history_gate.py change <outdir_a> <outdir_b>   # how far (not bitwise)

A baseline build goes beside the working one, e.g.
    git archive <commit> | tar -x -C /tmp/base && cd /tmp/base &&
    pip install --no-build-isolation --no-deps --target /tmp/base_site .
(the scenes are read from this checkout's inputs/ in both runs).

Every dataset outside /timing is compared byte for byte (values, dtype and shape), and the
counters and the root attributes status and message; wall times, dates, commits and paths
are not compared."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

#: (scene, short t_end in s)
SCENES = [
    ("inputs/boom_luffing.nml", 0.3), ("inputs/boom_luffing_cable.nml", 0.3),
    ("inputs/curved_leaf.nml", 0.005),
    ("inputs/leaf_spring.nml", 0.15), ("inputs/leaf_spring_cycle.nml", 0.1),
    ("inputs/leaf_spring_road.nml", 0.1), ("inputs/plate_pendulum.nml", 0.1),
    ("inputs/general/boom_luffing.nml", 0.3), ("inputs/general/curved_leaf.nml", 0.005),
    ("inputs/general/leaf_spring.nml", 0.1), ("inputs/general/plate_pendulum.nml", 0.1),
    ("inputs/general/spinup.nml", 2.0),
    ("inputs/hard/long_luffing.nml", 0.05), ("inputs/hard/newton_failure.nml", 0.3),
    ("inputs/hard/pendulum.nml", 0.2), ("inputs/hard/spinup.nml", 2.0),
    ("inputs/hard/stiff_boom.nml", 1.0),
]
#: (name, overrides): the scene's own policy, then each Jacobian policy, adaptive steps
VARIANTS = [
    ("scene", []),
    ("step", ["solver.jacobian='step'"]),
    ("iteration", ["solver.jacobian='iteration'"]),
    ("reuse", ["solver.jacobian='reuse'"]),
    ("adaptive", ["solver.step='adaptive'"]),
    ("galpha", ["solver.integrator='generalized_alpha'", "solver.rho_inf=0.8"]),
]
#: variants run on every scene; the others on the first scene of each kind below
EVERY = ("scene", "step", "reuse")
EXTRA_ON = {"inputs/plate_pendulum.nml", "inputs/general/boom_luffing.nml",
            "inputs/leaf_spring.nml", "inputs/hard/pendulum.nml", "inputs/general/spinup.nml"}


def name_of(scene: str, variant: str) -> str:
    return scene.replace("inputs/", "").replace("/", "_").replace(".nml", "") + f"-{variant}"


def run(out: Path, site: str | None) -> None:
    out.mkdir(parents=True, exist_ok=True)
    repo = Path(__file__).resolve().parents[1]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    if site:
        env["PYTHONPATH"] = site
    for scene, t_end in SCENES:
        for variant, sets in VARIANTS:
            if variant not in EVERY and scene not in EXTRA_ON:
                continue
            target = out / (name_of(scene, variant) + ".h5")
            args = [sys.executable, "-c", "import sys; from ancfdrv.cli import main; "
                    "sys.exit(main())", "run", scene, "--set", f"solver.t_end={t_end}",
                    "--set", "output.q=.true.", "--set", "output.xdmf=.false."]
            for s in sets:
                args += ["--set", s]
            done = subprocess.run(args + ["-o", str(target)], cwd=repo, capture_output=True,
                                  text=True, env=env)
            (out / (name_of(scene, variant) + ".rc")).write_text(
                f"{done.returncode}\n{done.stderr[-2000:]}")
            print(f"{name_of(scene, variant)}: exit {done.returncode}", flush=True)


EXAMPLES = {"aerial_platform": [], "knuckle_boom": [], "slider_crank": [],
            "sweep_from_python": [], "three_leaf_spring": [],
            "road_transmissibility": ["--jobs", "1", "--keep-runs"]}


def examples(out: Path, site: str | None) -> None:
    """Each example with --quick, its result files in out/examples/<name>/."""
    repo = Path(__file__).resolve().parents[1]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    if site:
        env["PYTHONPATH"] = site
    for name, extra in EXAMPLES.items():
        target = out / "examples" / name
        target.mkdir(parents=True, exist_ok=True)
        done = subprocess.run([sys.executable, str(repo / "examples" / f"{name}.py"), "--quick",
                               "--out", str(target), *extra], cwd=repo, capture_output=True,
                              text=True, env=env)
        (target / "exit.rc").write_text(f"{done.returncode}\n{done.stderr[-2000:]}")
        print(f"{name}: exit {done.returncode}", flush=True)


def _datasets(f: h5py.File) -> dict:
    found = {}

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and not name.startswith("timing"):
            found[name] = obj[()]
    f.visititems(visit)
    return found


def diff(a: Path, b: Path) -> int:
    bad = 0
    files = sorted(str(p.relative_to(a)) for p in a.rglob("*.h5"))
    for name in files:
        rc = name.replace(".h5", ".rc")
        parent = Path(name).parent
        while not (a / rc).exists() and parent != Path("."):   # an example's: its exit.rc
            rc, parent = str(parent / "exit.rc"), parent.parent
        rc_a = (a / rc).read_text().split("\n")[0]
        rc_b = (b / rc).read_text().split("\n")[0] if (b / rc).exists() else "missing"
        problems = [] if rc_a == rc_b else [f"exit {rc_a} vs {rc_b}"]
        rows = 0
        if not (b / name).exists():
            problems.append("no file")
        else:
            with h5py.File(a / name) as fa, h5py.File(b / name) as fb:
                da, db = _datasets(fa), _datasets(fb)
                if set(da) != set(db):
                    problems.append(f"datasets differ: {sorted(set(da) ^ set(db))}")
                for key in sorted(set(da) & set(db)):
                    x, y = np.asarray(da[key]), np.asarray(db[key])
                    if x.dtype != y.dtype or x.shape != y.shape or x.tobytes() != y.tobytes():
                        problems.append(f"{key} differs")
                ca = {k: v for k, v in fa["counters"].attrs.items()} if "counters" in fa else {}
                cb = {k: v for k, v in fb["counters"].attrs.items()} if "counters" in fb else {}
                if {k: str(v) for k, v in ca.items()} != {k: str(v) for k, v in cb.items()}:
                    keys = sorted(k for k in set(ca) | set(cb) if str(ca.get(k)) != str(cb.get(k)))
                    problems.append(f"counters differ: {keys}")
                for attr in ("status", "message"):
                    if str(fa.attrs.get(attr)) != str(fb.attrs.get(attr)):
                        problems.append(f"attr {attr}: {fa.attrs.get(attr)!r} vs "
                                        f"{fb.attrs.get(attr)!r}")
                rows = len(fa["dynamic/time"]) if "dynamic/time" in fa else 0
        print(f"{name}: {'bitwise equal' if not problems else '; '.join(problems)}"
              f" ({rows} rows)")
        bad += bool(problems)
    print(f"{len(files) - bad} of {len(files)} histories bitwise equal")
    return 1 if bad else 0


def change(a: Path, b: Path) -> int:
    """How far each history of b moved from a's where they are not bitwise equal (a change
    of the Newton iterates: issue 26): the largest change of the coordinates (/dynamic/q),
    the probes and the deflections, each over its own range (the widest component; at
    least 1e-6 of its magnitude and 1e-9), and the Newton corrections (totals). Rows compared up
    to the shorter history."""
    files = sorted(str(p.relative_to(a)) for p in a.rglob("*.h5"))
    worst = 0.0
    for name in files:
        if not (b / name).exists():
            print(f"{name}: no file in {b}")
            continue
        with h5py.File(a / name) as fa, h5py.File(b / name) as fb:
            if "dynamic/time" not in fa or "dynamic/time" not in fb:
                print(f"{name}: no dynamic history")
                continue
            parts = []
            largest = 0.0
            for group in ("q", "probes", "deflection"):
                key = f"dynamic/{group}"
                if key not in fa or key not in fb:
                    continue
                items = [(key, fa[key], fb[key])] if isinstance(fa[key], h5py.Dataset) else \
                    [(f"{key}/{k}", fa[key][k], fb[key][k]) for k in fa[key] if k in fb[key]]
                for label, x, y in items:
                    x, y = np.asarray(x[()], dtype=float), np.asarray(y[()], dtype=float)
                    rows = min(len(x), len(y))
                    x, y = x[:rows].reshape(rows, -1), y[:rows].reshape(rows, -1)
                    # (a history at rest has no range: then 1e-6 of its magnitude, at
                    # least 1e-9)
                    span = max(np.ptp(x, axis=0).max(), 1e-6 * np.abs(x).max(), 1e-9) \
                        if rows else 0.0
                    moved = np.abs(x - y).max() / span if span > 0 else 0.0
                    largest = max(largest, moved)
                    if group != "q":
                        parts.append(f"{label.split('/', 1)[1]} {moved:.1e}")
            newton = [int(np.asarray(f["dynamic/newton_iterations"][()]).sum())
                      for f in (fa, fb)] if "dynamic/newton_iterations" in fa else [0, 0]
            worst = max(worst, largest)
            print(f"{name}: largest change {largest:.2e} of the range ({', '.join(parts)}); "
                  f"corrections {newton[0]} -> {newton[1]}")
    print(f"largest change over all histories: {worst:.2e} of the range")
    return 0


if __name__ == "__main__":
    if sys.argv[1] in ("run", "examples"):
        (run if sys.argv[1] == "run" else examples)(Path(sys.argv[2]).resolve(),
                                                     sys.argv[3] if len(sys.argv) > 3 else None)
    elif sys.argv[1] == "change":
        sys.exit(change(Path(sys.argv[2]), Path(sys.argv[3])))
    else:
        sys.exit(diff(Path(sys.argv[2]), Path(sys.argv[3])))
