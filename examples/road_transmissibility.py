"""Road transmissibility of the two-leaf spring: how much of a sinusoidal road input at the
axle reaches the chassis, against the road's frequency, with the friction between the
leaves on and off (issue 15).

The model is the shipped scene ``inputs/leaf_spring_road.nml``: the two-leaf spring of
SPEC section 7 (thin-plate leaves, the lower one prestressed, penalty contact with
regularized Coulomb friction at its tips), the 500 kg chassis on the front eye and the
shackle, started at rest in its static equilibrium under gravity (``spring.settle =
'gravity'``); the axle clamp follows z(t) = a sin(2 pi f t), raised smoothly over
``road_ramp`` s, and Kelvin-Voigt material damping (``damping_time``) stands in for the
suspension's other damping.

What it computes:

1. **The static stiffness and the frequencies it predicts**, from static solves of the same
   model (no time integration): the chassis's deflection under its weight plus and minus
   ``DELTA_FORCE`` gives the incremental stiffness k = dF/dz, which includes the shackle's
   tilt and the spring's geometric nonlinearity, and the static deflection shape phi (all
   coordinates per metre of chassis drop). Three frequencies follow:
   ``f_chassis = sqrt(k / m) / 2 pi`` with the chassis mass m (what issue 15 calls the
   frequency of the static stiffness), ``f_secant`` with W / sag instead of k, and
   Rayleigh's quotient with the static deflection shape, ``f_rayleigh = sqrt(k / m_eff) / 2
   pi`` with m_eff = phi^T M phi: the chassis also moves sideways (it follows the front eye,
   ``dx_dz`` per unit drop) and the leaves and the shackle move with it, all of which
   carries kinetic energy.
2. **A one-degree-of-freedom reference** for the base-excited spring in the shape phi:
   m_eff x'' + c x' + k x = -m_c y'' with the chassis's motion z = y + x, m_c = phi^T M u
   (u: a rigid vertical translation of everything) and c = tau k (Kelvin-Voigt), so
   T(f) = |1 + (m_c / m_eff) r^2 / (1 - r^2 + i tau omega)|, r = f / f_rayleigh. Friction
   is not in it. It holds below and at the resonance (0.04 % at 2 Hz, measured over 12 s);
   above it the chassis's fore-and-aft motion grows (its horizontal over vertical steady
   amplitude: 0.08 at 2 Hz, 0.28 at 3.5 Hz, 0.68 at 4.5 Hz, against 0.156 / T in the static
   shape), a second shape the model does not have: it overestimates the transmissibility
   by 1.5 % at 3.5 Hz and 5.6 % at 4.5 Hz (0.6285 against 0.5954, steady to 4e-5) and
   underestimates it by 3 % at 5 Hz and 6 % at 6 Hz. The full sweep (``--full``):
   peak 18.3 at 2.833 Hz friction off, 16.9 at 2.833 Hz friction on (fitted damping ratios
   0.0267 and 0.0289: friction adds 0.002), against the Rayleigh frequency 2.837 Hz.
3. **The sweep**: one run per road frequency and friction setting, in parallel processes;
   the chassis amplitude is the least-squares sine at the road frequency over the last
   ``window`` s (a whole number of periods), its transmissibility that amplitude over the
   road's; ``settling`` is the change of that amplitude against the window ending
   ``shift`` s earlier (a measure of how steady the response is). Runs near the
   resonance last longer (the transient decays as exp(-zeta omega t), zeta = 0.027).
4. **The peaks**: the largest measured point and the peak of the one-degree-of-freedom
   curve fitted (f_n, damping, m_c / m_eff free) to the points within 12 % of it.

Files in results/examples/ (``--out``): road_transmissibility.{json,csv,md,png} and, with
``--keep-runs``, road_transmissibility_runs/*.h5 (one result file per run, ``ancf plot``
reads them; 0.8 MB per simulated second, 280 MB for the full sweep).

    python examples/road_transmissibility.py [--quick | --full] [--out DIR] [--jobs N] [--keep-runs]

Three extents of the sweep (``Study``; friction off and on in each):

* the default (``DEFAULT``): 8 frequencies from 1.5 to 5 Hz, five of them around the
  resonance, 8 s runs and 12 s near it: 16 runs, 155 s of CPU (within 2 minutes on 2
  cores). It shows the study's point: the peak at the Rayleigh frequency, its height with
  friction off and on, the isolation above it. Measured: peak 18.17 at 2.832 Hz friction
  off, 16.83 at 2.832 Hz friction on (fitted damping ratios 0.0270 and 0.0292), against
  the full sweep's 18.3 and 16.9 at 2.833 Hz; near the resonance the amplitude still changes
  by 1-3 % between the last two windows (the ``settling`` column; below 0.3 % elsewhere);
* ``--full`` (``FULL``): the full study, 19 frequencies from 1 to 6 Hz, denser near the
  resonance, 10 s runs and 16 s near it: 38 runs, about 7 minutes of CPU (estimated from
  the default's cost per simulated second; some 4 minutes on 2 idle cores);
* ``--quick`` (``QUICK``, the tests): two frequencies below the resonance for 8 s each,
  compared with the reference curve.
"""
from __future__ import annotations

import argparse
import concurrent.futures
import json
import multiprocessing
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Sequence

import h5py
import numpy as np

from example_utils import RESULTS, write_table

from ancfdrv.builders import build_system
from ancfdrv.io.scene import load_scene
from ancfdrv.runner import run_scene
from ancfdrv.solvers.static import solve_newton
from ancfdrv.sweep_exec import end_with_parent
from ancfdrv.system import RigidBody

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "inputs" / "leaf_spring_road.nml"
#: extra vertical force on the chassis for the incremental stiffness (N): small against the
#: 4905 N weight (the stiffness changes by 2 % over the 29 mm sag), large against rounding
DELTA_FORCE = 200.0
#: effects of the friction-off runs (the scene's list without 'friction')
NO_FRICTION = "gravity,contact,prestress,damping"
#: runs with |f / f_rayleigh - 1| < NEAR last longer (the transient decays as exp(-zeta omega t))
NEAR = 0.1


@dataclass(frozen=True)
class Study:
    """The sweep's extent: road frequencies (Hz), run lengths (s; ``near_duration`` for
    the runs within NEAR of the resonance), the amplitude window and its shift (s) and the
    road's ramp (s; None: the scene's ``road_ramp``)."""

    frequencies: tuple[float, ...]
    duration: float
    near_duration: float
    window: float
    shift: float
    ramp: float | None


#: the full study (``--full``): 19 frequencies, denser near the resonance (2.84 Hz), 10 s
#: runs and 16 s near it; 38 runs, 452 simulated seconds (about 7 min of CPU, estimated from
#: the default's 0.92 s of CPU per simulated second)
FULL = Study((1.0, 1.5, 2.0, 2.3, 2.5, 2.65, 2.75, 2.8, 2.825, 2.85, 2.875, 2.9, 2.95,
              3.05, 3.2, 3.5, 4.0, 5.0, 6.0), 10.0, 16.0, 4.0, 2.0, None)
#: the default: 8 frequencies, five of them within NEAR of the resonance (at least 4 points
#: within 12 % of the peak for its fit), 8 s runs and 12 s near it; 16 runs, 168 simulated
#: seconds (155 s of CPU measured: some 80 s on 2 idle cores)
DEFAULT = Study((1.5, 2.65, 2.75, 2.85, 2.95, 3.05, 3.5, 5.0), 8.0, 12.0, 4.0, 2.0, None)
#: ``--quick`` (the tests): two frequencies below the resonance, 8 s each, a 1 s ramp
QUICK = Study((1.5, 2.0), 8.0, 8.0, 2.0, 1.0, 1.0)
STUDIES = {"quick": QUICK, "default": DEFAULT, "full": FULL}


@dataclass(frozen=True)
class Linearization:
    """The spring about its static equilibrium under gravity, from static solves."""

    stiffness: float       # k = dF/dz at the chassis (N/m), incremental, with the shackle
    sag: float             # chassis drop from the unloaded to the loaded equilibrium (m)
    weight: float          # chassis weight m g (N)
    chassis_mass: float    # m (kg)
    dx_dz: float           # chassis's horizontal motion per unit vertical (static shape)
    effective_mass: float  # m_eff = phi^T M phi, phi normalized to a unit chassis drop (kg)
    coupled_mass: float    # m_c = phi^T M u, u a rigid vertical translation (kg)
    total_mass: float      # u^T M u: everything that moves with the road (kg)
    damping_time: float    # tau of the scene's material (s)

    @property
    def f_chassis(self) -> float:
        """sqrt(k / m) / 2 pi: the static stiffness with the chassis mass (Hz)."""
        return float(np.sqrt(self.stiffness / self.chassis_mass) / (2 * np.pi))

    @property
    def f_secant(self) -> float:
        """sqrt((W / sag) / m) / 2 pi: the secant stiffness weight over sag (Hz)."""
        return float(np.sqrt(self.weight / self.sag / self.chassis_mass) / (2 * np.pi))

    @property
    def f_rayleigh(self) -> float:
        """sqrt(k / m_eff) / 2 pi: Rayleigh's quotient with the static shape (Hz)."""
        return float(np.sqrt(self.stiffness / self.effective_mass) / (2 * np.pi))

    def transmissibility(self, f: np.ndarray, damping_time: float | None = None,
                         f_n: float | None = None, ratio: float | None = None) -> np.ndarray:
        """|z / y| of the one-degree-of-freedom model (module docstring, item 2); the
        optional arguments replace tau, f_rayleigh and m_c / m_eff (for fits)."""
        tau = self.damping_time if damping_time is None else damping_time
        fn = self.f_rayleigh if f_n is None else f_n
        mu = self.coupled_mass / self.effective_mass if ratio is None else ratio
        r = np.asarray(f, dtype=float) / fn
        return np.abs(1 + mu * r**2 / (1 - r**2 + 1j * tau * 2 * np.pi * np.asarray(f)))


def _solve(scene_path: Path, overrides: list[str], extra_force: float, loads: float = 1.0):
    """The model of the scene (frictionless statics; the road's clamp kept as a prescribed
    joint, so that a rigid translation is representable) and its static equilibrium with an
    extra downward force on the chassis."""
    scene = load_scene(scene_path, overrides)
    system = build_system(scene).system
    effects = tuple(scene.effects)
    if extra_force:
        system.load("extra", "force", body="chassis", point=system.probes["chassis"].point,
                    vector=(0.0, 0.0, -extra_force))
        effects += ("point_loads",)
    model = system.assemble(effects=effects)
    return scene, model, solve_newton(model, tol=1e-12, max_iter=50, loads=loads)


def linearize(scene_path: Path = SCENE, overrides: Sequence[str] = ()) -> Linearization:
    """Static stiffness, static deflection shape and its masses (module docstring, item 1)."""
    base = list(overrides) + ["spring.road=sine", "spring.road_amplitude=1e-4"]
    scene, model, rest = _solve(scene_path, base, 0.0)
    _, _, unloaded = _solve(scene_path, base, 0.0, loads=0.0)
    plus = _solve(scene_path, base, DELTA_FORCE)
    minus = _solve(scene_path, base, -DELTA_FORCE)
    def chassis(m, r) -> np.ndarray:
        return m.probe_positions(r.e)["chassis"]
    dz = (chassis(*plus[1:]) - chassis(*minus[1:])) / (2 * DELTA_FORCE)  # per N downward
    phi = (plus[2].e - minus[2].e) / (2 * DELTA_FORCE) / -dz[2]         # per m of drop
    mass = model.mass_matrix()
    translation = np.zeros(model.nfull)
    for body in model.bodies:   # nodal positions' r3 (plates: 9 per node; rigid: r first)
        stride = 12 if isinstance(body, RigidBody) else 9
        translation[body.first + 2:body.first + body.ncoordinates:stride] = 1.0
    u = np.linalg.lstsq(model.reduction.matrix.toarray(), translation, rcond=None)[0] \
        if model.reduction is not None else translation
    spring, g = scene["spring"], scene["loads"]["gravity"]
    damping = scene["material"]["damping_time"] if "damping" in scene.effects else 0.0
    return Linearization(
        stiffness=float(-1.0 / dz[2]),
        sag=float(chassis(model, unloaded)[2] - chassis(model, rest)[2]),
        weight=spring["chassis_mass"] * g, chassis_mass=spring["chassis_mass"],
        dx_dz=float(dz[0] / dz[2]), effective_mass=float(phi @ (mass @ phi)),
        coupled_mass=float(-(phi @ (mass @ u))), total_mass=float(u @ (mass @ u)),
        damping_time=float(damping))


@dataclass(frozen=True)
class Case:
    frequency: float   # Hz
    friction: bool
    duration: float    # s
    window: float      # s
    shift: float       # s
    ramp: float        # s
    output: Path
    keep: bool         # keep the result file (about 0.8 MB per simulated second)


def steady_amplitude(t: np.ndarray, z: np.ndarray, frequency: float, end: float,
                     window: float) -> float:
    """Amplitude of the least-squares sine (with a constant) at ``frequency`` over the last
    whole number of periods that fits in ``window`` before ``end``."""
    periods = max(1, int(np.floor(window * frequency)))
    inside = (t >= end - periods / frequency - 1e-9) & (t <= end + 1e-9)
    w = 2 * np.pi * frequency * t[inside]
    basis = np.column_stack([np.ones(w.size), np.cos(w), np.sin(w)])
    coef = np.linalg.lstsq(basis, z[inside], rcond=None)[0]
    return float(np.hypot(coef[1], coef[2]))


def run_case(case: Case) -> dict:
    """One road frequency: run the scene, measure the chassis's steady amplitude."""
    overrides = [f"spring.road_frequency={case.frequency!r}", f"solver.t_end={case.duration!r}",
                 f"spring.road_ramp={case.ramp!r}", "output.xdmf=.false."]
    if not case.friction:
        overrides.append(f"scene.effects={NO_FRICTION}")
    start = time.perf_counter()
    outcome = run_scene(SCENE, overrides, case.output, progress=False)
    wall = time.perf_counter() - start
    amplitude = outcome.scene["spring"]["road_amplitude"]
    with h5py.File(case.output, "r") as h5:
        t = h5["dynamic/time"][()]
        z = h5["dynamic/deflection/chassis"][:, 2]
        newton = float(h5["dynamic/newton_iterations"][()].mean())
        balance = float(np.abs(h5["dynamic/energy/balance"][()]).max())
        friction = float(-h5["dynamic/energy/friction_work"][-1])
        material = float(-h5["dynamic/energy/material_damping_work"][-1])
    if not case.keep:
        case.output.unlink()
    last = steady_amplitude(t, z, case.frequency, t[-1], case.window)
    earlier = steady_amplitude(t, z, case.frequency, t[-1] - case.shift, case.window)
    return {"frequency": case.frequency, "friction": case.friction,
            "duration": case.duration, "transmissibility": last / amplitude,
            "chassis_amplitude": last, "settling": (last - earlier) / last,
            "friction_work": friction, "material_damping_work": material,
            "energy_balance": balance, "newton_per_step": newton, "wall_time_s": wall,
            "file": str(case.output) if case.keep else ""}


def fit_peak(lin: Linearization, rows: list[dict]) -> dict:
    """The largest measured point and the peak of the one-degree-of-freedom curve fitted to
    the points within 12 % of its frequency (f_n, tau, m_c / m_eff free)."""
    from scipy.optimize import least_squares
    f = np.array([r["frequency"] for r in rows])
    t = np.array([r["transmissibility"] for r in rows])
    top = int(np.argmax(t))
    near = np.abs(f / f[top] - 1) < 0.12
    start = [f[top], max(lin.damping_time, 1e-4), lin.coupled_mass / lin.effective_mass]
    fit = least_squares(lambda p: np.log(lin.transmissibility(f[near], p[1], p[0], p[2])) -
                        np.log(t[near]), start, x_scale=[1.0, 1e-3, 1.0])
    fn, tau, ratio = fit.x
    fine = np.linspace(f[near].min(), f[near].max(), 4001)
    curve = lin.transmissibility(fine, tau, fn, ratio)
    k = int(np.argmax(curve))
    return {"grid_frequency": float(f[top]), "grid_transmissibility": float(t[top]),
            "frequency": float(fine[k]), "transmissibility": float(curve[k]),
            "fit_f_n": float(fn), "fit_damping_time": float(tau), "fit_ratio": float(ratio),
            "fit_zeta": float(tau * np.pi * fn), "points": int(near.sum()),
            "fit_rms_log": float(np.sqrt(np.mean(fit.fun**2)))}


def _progress(done: int, total: int, row: dict, started: float) -> None:
    """One line per finished run (the full sweep takes several minutes)."""
    print(f"[{done}/{total}] {row['frequency']:g} Hz, friction "
          f"{'on' if row['friction'] else 'off'}: transmissibility "
          f"{row['transmissibility']:.3f} ({row['wall_time_s']:.1f} s; "
          f"{time.perf_counter() - started:.0f} s elapsed)", flush=True)


def sweep(cases: list[Case], jobs: int, progress: bool = True) -> list[dict]:
    """Run the cases in ``jobs`` processes (spawned: each imports ancfdrv afresh), printing
    a line per finished run when ``progress``; the rows come back in the cases' order. The
    workers end with this process, however it ends (a timeout's SIGTERM, SIGKILL):
    :func:`ancfdrv.sweep_exec.end_with_parent`."""
    started = time.perf_counter()
    rows: list[dict | None] = [None] * len(cases)
    if jobs <= 1:
        for i, case in enumerate(cases):
            rows[i] = run_case(case)
            if progress:
                _progress(i + 1, len(cases), rows[i], started)
        return rows
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(max_workers=jobs, mp_context=context,
                                                initializer=end_with_parent) as pool:
        futures = {pool.submit(run_case, case): i for i, case in enumerate(cases)}
        for done, future in enumerate(concurrent.futures.as_completed(futures), start=1):
            rows[futures[future]] = future.result()
            if progress:
                _progress(done, len(cases), rows[futures[future]], started)
    return rows


def plan(lin: Linearization, study: Study, runs: Path, keep: bool) -> list[Case]:
    """The runs: the longest first, so that two processes finish together."""
    ramp = float(load_scene(SCENE)["spring"]["road_ramp"]) if study.ramp is None else study.ramp
    cases = []
    for friction in (False, True):
        for f in study.frequencies:
            near = abs(f / lin.f_rayleigh - 1) < NEAR
            cases.append(Case(f, friction, study.near_duration if near else study.duration,
                              study.window, study.shift, ramp,
                              runs / f"road_{f:g}Hz_{'friction' if friction else 'frictionless'}.h5",
                              keep))
    return sorted(cases, key=lambda c: -c.duration)


def plot(lin: Linearization, rows: list[dict], peaks: dict, path: Path) -> None:
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(9, 5.5))
    f = np.linspace(0.8, 6.2, 2000)
    ax.semilogy(f, lin.transmissibility(f), color="0.5", lw=1.0,
                label=f"one-DOF reference, friction off (k, m_eff = {lin.effective_mass:.0f} kg, "
                      f"tau = {1e3 * lin.damping_time:g} ms)")
    for friction, colour, marker in ((False, "tab:blue", "o"), (True, "tab:red", "s")):
        mine = sorted((r for r in rows if r["friction"] == friction),
                      key=lambda r: r["frequency"])
        if not mine:
            continue
        name = "friction on" if friction else "friction off"
        label = name
        if name in peaks:
            p = peaks[name]
            label += f": peak {p['transmissibility']:.1f} at {p['frequency']:.3f} Hz"
        ax.semilogy([r["frequency"] for r in mine], [r["transmissibility"] for r in mine],
                    marker=marker, ls="-", lw=0.8, color=colour, label=label)
    for value, style, text in ((lin.f_chassis, "--", "static stiffness, chassis mass"),
                               (lin.f_rayleigh, ":", "static stiffness, m_eff (Rayleigh)")):
        ax.axvline(value, color="k", ls=style, lw=0.8, label=f"{text}: {value:.3f} Hz")
    ax.axhline(1.0, color="0.7", lw=0.6)
    ax.set(xlabel="road frequency (Hz)", ylabel="transmissibility: chassis / road amplitude",
           title="Two-leaf spring on a sinusoidal road "
                 f"(amplitude {1e3 * rows[0]['chassis_amplitude'] / rows[0]['transmissibility']:g} mm, "
                 "settled under gravity)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


@dataclass
class Report:
    linearization: Linearization
    rows: list[dict]
    peaks: dict
    files: list[Path]


def run(study: str, out: Path, jobs: int = 2, keep_runs: bool = False) -> Report:
    """The sweep of ``STUDIES[study]`` ('quick', 'default' or 'full'), written to ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    runs = out / "road_transmissibility_runs"
    runs.mkdir(exist_ok=True)
    lin = linearize()
    rows = sorted(sweep(plan(lin, STUDIES[study], runs, keep_runs), jobs),
                  key=lambda r: (r["friction"], r["frequency"]))
    if not keep_runs and not any(runs.iterdir()):
        runs.rmdir()
    peaks = {}
    for friction in (False, True):
        mine = [r for r in rows if r["friction"] == friction]
        if len(mine) >= 4:
            peaks["friction on" if friction else "friction off"] = fit_peak(lin, mine)
    stem = out / "road_transmissibility"
    summary = {"scene": str(SCENE), "study": study,
               "linearization": asdict(lin) | {"f_chassis": lin.f_chassis,
                                               "f_secant": lin.f_secant,
                                               "f_rayleigh": lin.f_rayleigh},
               "peaks": peaks, "runs": rows}
    stem.with_suffix(".json").write_text(json.dumps(summary, indent=1, default=str))
    table = [[r["frequency"], "on" if r["friction"] else "off", r["duration"],
              r["transmissibility"], float(lin.transmissibility(r["frequency"])),
              r["settling"], r["friction_work"], r["material_damping_work"],
              r["energy_balance"], r["wall_time_s"]] for r in rows]
    note = (f"Static stiffness k = {lin.stiffness / 1e3:.2f} kN/m (incremental, +-"
            f"{DELTA_FORCE:g} N), secant W / sag = {lin.weight / lin.sag / 1e3:.2f} kN/m; "
            f"frequencies: chassis mass {lin.f_chassis:.4f} Hz, secant {lin.f_secant:.4f} Hz, "
            f"Rayleigh (m_eff {lin.effective_mass:.1f} kg) {lin.f_rayleigh:.4f} Hz. ")
    for name, p in peaks.items():
        note += (f"Peak, {name}: {p['transmissibility']:.2f} at {p['frequency']:.4f} Hz "
                 f"(fit; measured maximum {p['grid_transmissibility']:.2f} at "
                 f"{p['grid_frequency']:g} Hz; zeta {p['fit_zeta']:.4f}). ")
    print(write_table(stem, ["f [Hz]", "friction", "run [s]", "transmissibility",
                             "one-DOF reference (friction off)", "settling",
                             "friction work [J]", "material damping work [J]",
                             "max |energy balance| [J]", "wall [s]"], table,
                      "Road transmissibility of the two-leaf spring", note))
    plot(lin, rows, peaks, stem.with_suffix(".png"))
    files = [stem.with_suffix(s) for s in (".json", ".csv", ".md", ".png")]
    return Report(lin, rows, peaks, files + [Path(r["file"]) for r in rows if r["file"]])


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    level = parser.add_mutually_exclusive_group()
    level.add_argument("--quick", action="store_const", dest="study", const="quick",
                       help=f"{len(QUICK.frequencies)} frequencies below the resonance, "
                            f"{QUICK.duration:g} s each (about 30 s of CPU)")
    level.add_argument("--full", action="store_const", dest="study", const="full",
                       help=f"the full study: {len(FULL.frequencies)} frequencies, "
                            f"{FULL.duration:g}-{FULL.near_duration:g} s runs (about 7 min of CPU)")
    parser.set_defaults(study="default")
    parser.add_argument("--out", type=Path, default=RESULTS, help=f"result folder ({RESULTS})")
    parser.add_argument("--jobs", type=int, default=2, help="parallel processes (2)")
    parser.add_argument("--keep-runs", action="store_true",
                        help="keep each run's HDF5 file (about 0.8 MB per simulated second)")
    args = parser.parse_args(argv)
    run(args.study, args.out, args.jobs, args.keep_runs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
