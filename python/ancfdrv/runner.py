"""One scene, start to finish: namelist -> Scene -> Model -> solve -> HDF5.

This is the path every command takes; read it top to bottom to follow a run:
``static`` solves the equilibrium; ``dynamic`` integrates from the rigid configuration at
rest; ``static+dynamic`` integrates from the static equilibrium (SPEC section 5).

A run never loses or mislabels data:

* the output path is checked before anything is computed (:func:`check_output_path`:
  not a directory, not below a regular file, writable, never an input file);
* the run holds an exclusive lock on the output (:class:`~ancfdrv.results.lock.OutputLock`):
  a second run writing the same file is refused, naming the first one;
* SIGINT and SIGTERM stop the run at the next step boundary (:mod:`ancfdrv.interrupt`):
  what was computed is flushed and the file says status = 'interrupted';
* whatever ends the run (success, bad input found late, solver failure, interrupt,
  unexpected exception), the file's final status says so.

:func:`run_in_memory` runs the same path with the output kept in memory (a
:class:`~ancfdrv.results.memory.MemoryOutput` stands where the file is: it takes the same
writer calls and replays them into a file when asked): :func:`ancfdrv.simulate`.
"""
from __future__ import annotations

import time
from dataclasses import field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from .records import record
from .errors import AncfError, InputError, Interrupted, SolverError, UnstableError
from .io.safe_write import disk_full
from .history import stage_summary
from .interrupt import StopRequest, signal_name
from .results import hdf5 as results
from .builders.general import locate_error
from .results.lock import OutputLock
from .results.plausibility import check_dynamic, check_static
from .results.output_path import check_output_path
from .builders import build_model, settle_mode, stage_bounds
from .io.scene import Scene, load_scene
from .system import Model
from .solvers.dynamic import DynamicResult, DynamicSettings, integrate
from .solvers.path import solve_static_path, unstable_static_message
from .solvers.static import StaticResult, solve_newton

if TYPE_CHECKING:
    from .results.memory import MemoryOutput
    from .system.answers import Answers


def _io(out: "Path | MemoryOutput") -> Any:
    """Where a run's output goes: the HDF5 writer (:mod:`ancfdrv.results.hdf5`) for a file,
    or, for a run kept in memory (:func:`run_in_memory`), its
    :class:`~ancfdrv.results.memory.MemoryOutput`, which takes the same calls (the path
    argument being itself), keeps what they carry and replays them into a file on
    ``save``."""
    return results if isinstance(out, Path) else out


@record(eq=False)
class RunOutcome:
    """What a run produced: the output file (or the
    :class:`~ancfdrv.results.memory.MemoryOutput` of a run kept in memory) and the results
    of each analysis."""

    scene: Scene
    output: "Path | MemoryOutput"
    static: StaticResult | None
    dynamic: DynamicResult | None
    warnings: list[str]
    stages: dict[str, float] = field(default_factory=dict)
    #: what the ``after`` step of :func:`run_scene` returned (the plot's path for ``ancf run``)
    after: Any = None


def run_scene(path: str | Path, overrides: list[str] | None = None,
              output: str | Path | None = None, *, progress: bool | None = None,
              after: Callable[[RunOutcome], Any] | None = None) -> RunOutcome:
    """Run a scene file. Raises InputError (bad input, output path refused or in use),
    SolverError (solver failure) or Interrupted (SIGINT/SIGTERM); in the last two cases
    the output file already holds everything computed until then. ``after(outcome)``
    runs while the output is still locked (the plot of ``ancf run``: a second run on the
    same output is refused until it is written); its result is ``outcome.after``."""
    start = time.perf_counter()
    scene = load_scene(path, overrides)
    return run_loaded(scene, output, start=start, progress=progress, after=after)


def input_files(scene: Scene) -> list[Path]:
    """The files a scene reads: the scene file and any file it names
    (``Scene.input_files`` when the scene layer lists some)."""
    return [Path(scene.path), *(Path(p) for p in getattr(scene, "input_files", ()) or ())]


def writes_xdmf(scene: Scene) -> bool:
    """Whether a run of the scene writes the XDMF description (output.xdmf, the default:
    every analysis; a static one shows its state, a modal or buckling one its shapes)."""
    return bool(scene["output"].get("xdmf", True))


def dynamic_settings(scene: Scene) -> DynamicSettings:
    """Newmark with the scene's beta and gamma, generalized-alpha from rho_inf, or the
    energy-momentum midpoint rule."""
    solver, output = scene["solver"], scene["output"]
    common = dict(tol=solver["newton_tol"], max_newton=solver["max_newton"],
                  chunk_steps=output["chunk_steps"], store_q=output["q"],
                  jacobian=solver["jacobian"], contraction=solver["contraction"],
                  dt_min=solver.get("dt_min", 0.0), step=solver.get("step", "fixed"),
                  tolerance=solver.get("tolerance", 1e-6),
                  carry=solver.get("carry", "rotation"),
                  energy_tolerance=solver.get("energy_tolerance", 0.01))
    if solver["integrator"] == "generalized_alpha":
        return DynamicSettings.generalized_alpha(solver["dt"], solver["t_end"],
                                                 solver["rho_inf"], **common)
    if solver["integrator"] == "energy_momentum":
        return DynamicSettings(dt=solver["dt"], t_end=solver["t_end"],
                               integrator="energy_momentum", **common)
    return DynamicSettings(dt=solver["dt"], t_end=solver["t_end"], beta=solver["beta"],
                           gamma=solver["gamma"], **common)


def _settle(scene: Scene, model: Model, out: Path | MemoryOutput, settle: str,
            timing: dict[str, Any], stop: StopRequest) -> StaticResult:
    """The static equilibrium a settled dynamic run starts from (Newton, loads scaled by
    0 or 1), written to /static with the attribute settle."""
    solver = scene["solver"]
    with _io(out).released(out), stop.immediate():
        result = solve_newton(model, tol=solver["tol"], max_iter=solver["max_iter"],
                              load_steps=solver["load_steps"],
                              loads=0.0 if settle == "unloaded" else 1.0)
    result.extra["settle"] = settle
    for phase, seconds in result.timing.items():
        timing[f"settle_{phase}"] = seconds
    _io(out).write_static(out, model, result)
    _write_static_supports(out, model, result)
    _write_static_answers(scene, model, out, result)
    return result


def _write_static_supports(out: Path | MemoryOutput, model: Model, static: StaticResult) -> None:
    """/static/deflection_support of a general scene (:mod:`ancfdrv.system.supports`)."""
    frames = model.support_frames
    if not frames:
        return
    from .system.supports import (DISPLACEMENT_REFERENCE, SUPPORT_REFERENCE,
                                  support_deflections)
    values = {k: v[0] for k, v in support_deflections(model, frames,
                                                      model.expand(static.e)).items()}
    _io(out).write_support_deflections(
        out, "static", values, {n: frames[model.probes[n].body].describe() for n in values},
        SUPPORT_REFERENCE, DISPLACEMENT_REFERENCE)


class SupportRecorder:
    """Collects the support deflections of a dynamic run from each chunk's q (written at
    the end, also after a failure or an interrupt)."""

    def __init__(self, model: Model, frames: dict) -> None:
        self.model, self.frames = model, frames
        self.rows: list[dict[str, np.ndarray]] = []

    @classmethod
    def of(cls, model: Model) -> "SupportRecorder | None":
        frames = model.support_frames
        if not frames or not any(p.body in frames for p in model.probes.values()):
            return None
        return cls(model, frames)

    def wrap(self, writer):
        def sink(chunk) -> None:
            if chunk.q is not None:
                from .system.supports import support_deflections
                self.rows.append(support_deflections(self.model, self.frames,
                                                     self.model.expand(chunk.q)))
            writer(chunk)
        return sink

    def write(self, out: Path | MemoryOutput, rows: int) -> None:
        from .system.supports import DISPLACEMENT_REFERENCE, SUPPORT_REFERENCE
        if not self.rows:
            return
        values = {name: np.concatenate([r[name] for r in self.rows])[:rows]
                  for name in self.rows[0]}
        _io(out).write_support_deflections(
            out, "dynamic", values,
            {n: self.frames[self.model.probes[n].body].describe() for n in values},
            SUPPORT_REFERENCE, DISPLACEMENT_REFERENCE)


def _write_static_answers(scene: Scene, model: Model, out: Path | MemoryOutput,
                          result: StaticResult) -> "Answers":
    """Reactions, section forces and stresses of the static state (SPEC section 10),
    written and returned (:class:`~ancfdrv.system.answers.Answers`)."""
    from .system.answers import static_answers
    stations = scene["output"].get("stations", 3)
    # the loads' scale the state balances (an 'unloaded' settle: 0)
    answers = static_answers(model, result.e, result.lam, stations,
                             result.extra.get("load_factor", 1.0))
    _io(out).write_static_answers(out, model, result.e, result.lam, stations, answers=answers)
    return answers


def warns_implausible(scene: Scene) -> bool:
    """Whether implausible results are warned of (``scene.bounds = 'check'``, the
    default; :mod:`ancfdrv.results.plausibility`)."""
    return scene["scene"].get("bounds", "check") == "check"


def _check_dynamic_plausibility(scene: Scene, model: Model, out: Path | MemoryOutput,
                                envelope: dict) -> None:
    """The plausibility of a completed dynamic run (its probes' deflections read back,
    the answers' stress envelope): warnings in ``model.warnings``, SolverError for a
    result that is not finite or absurdly displaced."""
    with _io(out).reading(out) as h5:
        deflection = {name: h5[f"dynamic/deflection/{name}"][()] for name in model.probes
                      if f"dynamic/deflection/{name}" in h5}
    model.warnings.extend(check_dynamic(model, deflection, envelope,
                                        warn=warns_implausible(scene)))


def _answers_recorder(scene: Scene, model: Model):
    """The recorder of the dynamic reactions, section forces, stress envelope and cable
    tension (None when the model has no joints, beams, force elements or cables)."""
    from .system.answers import DynamicAnswers, reaction_map
    from .system.registry import axial_forces, reports_sections
    if not scene["output"].get("answers", True):
        return None
    if not reaction_map(model).joints and not model.force_elements and not any(
            reports_sections(b) or axial_forces(b) is not None for b in model.bodies):
        return None
    return DynamicAnswers(model, stations=scene["output"].get("stations", 3),
                          keep_sections=bool(scene["output"].get("sections", False)))


def _warn_large_ffr_deflection(model: Model, out: Path | MemoryOutput) -> None:
    """The warning of an 'ffr' run whose tip deflects by more than 5% of the length."""
    if any(s.floating for s in model.sets) and "tip" in model.probes:
        with _io(out).reading(out) as h5:
            deflection = h5["dynamic/deflection/tip"][()]
        ratio = np.abs(deflection).max() / model.length_scale
        if ratio > 0.05:
            model.warnings.append(
                f"formulation 'ffr' outside its assumptions: the tip deflects by {ratio:.2%} of "
                "the length (small deformation assumed); compare with formulation = "
                "'nonlinear'")


# -- FFR modal reduction (&beam modes = N; solvers/ffr_reduced.py) --------------------------
def modal_beam(model: Model):
    """The beam whose ``modes`` asks for the modal reduction (None: the full model)."""
    beams = [b for b in model.bodies if b.modes]
    return beams[0] if beams else None


def _reduction_error(scene: Scene, beam, message: str) -> InputError:
    group = "beam" if scene.kind != "general" else f"beam[{beam.name}]"
    return InputError(f"beam {beam.name!r}: modes = {beam.modes}: {message}",
                      file=str(scene.path), group=group, key="modes")


def check_reduction(scene: Scene, model: Model) -> None:
    """Refuse, before anything is computed, a reduced run outside the reduction's scope
    (InputError naming the beam; the scope messages are ffr_reduced's)."""
    beam = modal_beam(model)
    if beam is None:
        return
    from types import SimpleNamespace
    from .builders import settle_mode
    from .solvers.ffr_reduced import check_scope
    analysis = scene["scene"]["analysis"]
    if analysis not in ("static+dynamic", "dynamic") or (
            analysis == "dynamic" and settle_mode(scene) == "none"):
        raise _reduction_error(scene, beam, "the modal reduction is of a dynamic run from the "
                               "static equilibrium at t = 0 (scene.analysis = "
                               "'static+dynamic')")
    solver = scene["solver"]
    if solver["integrator"] != "newmark" or solver.get("step", "fixed") != "fixed":
        raise _reduction_error(scene, beam, "the reduced stepper is Newmark with fixed steps "
                               "(solver.integrator = 'newmark', solver.step = 'fixed')")
    others = [b.name for b in model.bodies if b is not beam]
    if others:
        raise _reduction_error(scene, beam, "the beam must be the model's only body (also "
                               f"found: {', '.join(others)})")
    try:
        check_scope(model, SimpleNamespace(e=model.e0))
    except SolverError as exc:
        raise _reduction_error(scene, beam, str(exc)) from None


def check_integrator(scene: Scene, model: Model) -> None:
    """Refuse, before anything is computed, ``solver.integrator = 'energy_momentum'`` on a
    scene it does not support (InputError naming the key and the item: the kernel's list,
    ``fortran/src/solvers/energy_momentum.f90``) or with ``solver.step = 'adaptive'`` (its
    steps are fixed, cut only where Newton fails)."""
    solver = scene["solver"]
    if scene["scene"]["analysis"] not in ("dynamic", "static+dynamic") \
            or solver["integrator"] != "energy_momentum":
        return
    if solver.get("step", "fixed") != "fixed":
        raise InputError("solver.integrator = 'energy_momentum' takes fixed steps (solver.step "
                         "= 'fixed'); its energy does not drift, and it has no local error "
                         "estimate to size steps by", file=str(scene.path), group="solver",
                         key="step")
    obstacle = model.kernel.energy_momentum_obstacle()
    if obstacle:
        raise InputError(f"solver.integrator = 'energy_momentum' does not support {obstacle} "
                         "(it conserves the energy of undamped, undriven systems of nonlinear "
                         "beams, cables and ropes with masses, gravity, pins and revolute "
                         "joints); take 'generalized_alpha'", file=str(scene.path),
                         group="solver", key="integrator")


def check_static_method(scene: Scene, model: Model) -> None:
    """Refuse, before anything is computed, ``solver.static_method = 'split'`` on a scene
    the split iteration cannot solve (InputError naming the key and why; 'auto', the
    default, takes Newton there)."""
    if scene["scene"]["analysis"] not in ("static", "static+dynamic") \
            or scene["solver"]["static_method"] != "split":
        return
    from .solvers.static import split_obstacle
    why = split_obstacle(model)
    if why is not None:
        raise InputError(f"'split' cannot solve this scene: {why}; use 'newton' or 'auto' "
                         "(the default: 'split' where it applies, else 'newton')",
                         file=str(scene.path), group="solver", key="static_method")


def _run_reduced(scene: Scene, model: Model, out: Path | MemoryOutput, static: StaticResult,
                 timing: dict[str, Any], progress: bool | None,
                 stop: StopRequest) -> tuple[DynamicResult, dict]:
    """The dynamic run of the modally reduced model (&beam modes = N): the layout of the
    full run's /dynamic, the full coordinates expanded from the reduced ones; /dynamic
    attributes reduction, modes, reduced_coordinates, kept_frequencies_hz, not_provided."""
    from .solvers.ffr_reduced import NOT_PROVIDED, integrate_reduced, reduce_ffr
    beam = modal_beam(model)
    settings = dynamic_settings(scene)
    xdmf = scene["output"].get("xdmf", True)
    write_q = settings.store_q
    supports = SupportRecorder.of(model)  # general scenes: deflections from q, as the full run
    # the chunks carry the expanded coordinates
    settings.store_q = bool(xdmf or write_q or supports is not None)
    try:
        with _io(out).released(out), stop.immediate():
            reduced = reduce_ffr(model, static, beam.modes)
    except SolverError as exc:  # e.g. more modes than the constrained model has
        raise _reduction_error(scene, beam, str(exc)) from None
    writer = _io(out).DynamicWriter(
        out, model, settings.store_q, settings.chunk_steps, xdmf=xdmf,
        total_rows=int(round(settings.t_end / settings.dt)) + 1,
        frames=scene["output"]["xdmf_frames"], write_q=write_q)
    attrs: dict[str, Any] = {
        "integrator": "newmark", "dt": settings.dt, "beta": settings.beta,
        "gamma": settings.gamma, "alpha_m": 0.0, "alpha_f": 0.0, "rho_inf": 1.0,
        "t_end": settings.t_end, "reduction": "modal", "modes": beam.modes,
        "reduced_beam": beam.name, "reduced_coordinates": reduced.size,
        "kept_frequencies_hz": np.sqrt(np.abs(reduced.kept_omega_squared)) / (2 * np.pi),
        "not_provided": NOT_PROVIDED}
    sink = writer if supports is None else supports.wrap(writer)
    try:
        with _io(out).released(out):  # the file is closed between the writes of the run
            dyn = integrate_reduced(model, reduced, settings, sink=sink, progress=progress,
                                    should_stop=stop)
    finally:
        writer.flush_last()
        if supports is not None:
            supports.write(out, writer.rows)
        _io(out).write_dynamic_attrs(out, {**attrs, "steps": max(writer.rows - 1, 0)}, {})
    for phase, seconds in dyn.timing.items():
        timing[f"dynamic_{phase}"] = seconds
    _warn_large_ffr_deflection(model, out)
    _check_dynamic_plausibility(scene, model, out, {})
    bounds = stage_bounds(scene)
    stages: dict[str, float] = {}
    if bounds:
        with _io(out).reading(out) as h5:
            stages = stage_summary(h5["dynamic/time"][()], h5["dynamic/deflection/tip"][:, 1],
                                   bounds)
    _io(out).write_dynamic_attrs(out, {
        **attrs, "steps": dyn.steps, "newton_iterations": dyn.newton_iterations,
        "factorizations": dyn.factorizations, "jacobian_evaluations": dyn.jacobians,
        "jacobian_policy": "constant", "wall_time_s": dyn.wall_time_s, "status": "ok",
        "step_control": "fixed", "dt_min": settings.dt, "step_cuts": 0,
        "steps_rejected": 0, "steps_taken": dyn.steps_taken,
        "smallest_step": dyn.smallest_step, "newton_floor_accepts": 0}, stages)
    return dyn, stages


def _run_dynamic(scene: Scene, model: Model, out: Path | MemoryOutput, e_start: np.ndarray,
                 timing: dict[str, Any], progress: bool | None,
                 stop: StopRequest, static: StaticResult | None = None
                 ) -> tuple[DynamicResult, dict]:
    if modal_beam(model) is not None:
        return _run_reduced(scene, model, out, static, timing, progress, stop)
    settings = dynamic_settings(scene)
    xdmf = scene["output"].get("xdmf", True)
    write_q = settings.store_q  # output.q: /dynamic/q at every step
    if xdmf:
        # the node positions for ParaView (XDMF) come from q: the kernel returns it, the
        # file keeps the frames only (storing every step cost a third of the FFR boom's
        # solver time and 27 MB)
        settings.store_q = True
    supports = SupportRecorder.of(model)
    if supports is not None:  # the support deflections come from q at every step
        settings.store_q = True
    recorder = _answers_recorder(scene, model)
    if recorder is not None:
        settings.store_q = True  # the answers need every step's coordinates (not written)
        settings.answers = recorder.needs_answers   # and the kernel's part of each row's
    # rows are written at least once a second (FLUSH_SECONDS) and whenever ~16 MB wait:
    # each write of a series costs ~0.2 ms whatever its rows, so writing every kernel call
    # (chunk_steps rows) took a third of a small model's run
    row_bytes = 8 * (16 + 6 * len(model.probes) + len(model.constraints)
                     + 6 * model.npoint + (model.ndof if settings.store_q else 0))
    writer = _io(out).DynamicWriter(
        out, model, settings.store_q, max(settings.chunk_steps, (16 << 20) // row_bytes),
        xdmf=xdmf,
        total_rows=int(round(settings.t_end / settings.dt)) + 1,
        frames=scene["output"]["xdmf_frames"], write_q=write_q)
    base_sink = writer if supports is None else supports.wrap(writer)
    attrs: dict[str, Any] = {
        "integrator": scene["solver"]["integrator"], "dt": settings.dt, "beta": settings.beta,
        "gamma": settings.gamma, "alpha_m": settings.alpha_m, "alpha_f": settings.alpha_f,
        "rho_inf": scene["solver"]["rho_inf"] if scene["solver"]["integrator"] ==
        "generalized_alpha" else 1.0, "t_end": settings.t_end}
    sink = base_sink
    # q carried for the answers only: the writer keeps its last row (/dynamic/q_last), so
    # it gets that row alone (not 27 MB of rows to merge per flush on the 28-node FFR boom)
    last_q_only = not write_q and not xdmf and supports is None
    if recorder is not None:
        def sink(chunk) -> None:
            nonlocal recorder
            if recorder is not None:
                try:
                    recorder(chunk)
                except (AncfError, ValueError, FloatingPointError) as exc:
                    # the answers never fail a run: the file keeps everything else
                    model.warnings.append(f"dynamic reactions, section forces and stresses "
                                          f"not recorded: {exc}")
                    recorder = None
            if last_q_only and chunk.q is not None and len(chunk.q) > 1:
                chunk = replace(chunk, q=chunk.q[-1:])
            base_sink(chunk)
    done = False  # the attributes are written once: the full set after a completed run
    try:
        with _io(out).released(out):  # the file is closed between the writes of the run
            dyn = integrate(model, settings, e_start, sink=sink, progress=progress,
                            should_stop=stop)
        writer.flush_last()
        if supports is not None:
            supports.write(out, writer.rows)
        if recorder is not None:
            _io(out).write_dynamic_answers(out, recorder)
        for phase, seconds in dyn.timing.items():
            timing[f"dynamic_{phase}"] = seconds
        stages: dict[str, float] = {}
        _warn_large_ffr_deflection(model, out)
        _check_dynamic_plausibility(scene, model, out,
                                    recorder.envelope if recorder is not None else {})
        bounds = stage_bounds(scene)
        if bounds:
            with _io(out).reading(out) as h5:
                t = h5["dynamic/time"][()]
                transverse = h5["dynamic/deflection/tip"][:, 1]
            stages = stage_summary(t, transverse, bounds)
        done = True
    finally:  # also after a failure or an interrupt: every computed step goes to the file
        if not done:
            _io(out).drop(out)  # the held file may be in any state after an error
            writer.flush_last()
            if supports is not None:
                supports.write(out, writer.rows)
            if recorder is not None:
                _io(out).write_dynamic_answers(out, recorder)
            _io(out).write_dynamic_attrs(out, {**attrs, "steps": max(writer.rows - 1, 0)},
                                        {})
    _io(out).write_dynamic_attrs(out, {
        **attrs, "steps": dyn.steps, "newton_iterations": dyn.newton_iterations,
        "factorizations": dyn.factorizations, "jacobian_evaluations": dyn.jacobians,
        "jacobian_policy": "constant" if model.constant_policy else settings.jacobian,
        "wall_time_s": dyn.wall_time_s, "status": "ok",
        "step_control": settings.step, "dt_min": settings.smallest_step,
        "step_cuts": dyn.step_cuts, "steps_rejected": dyn.steps_rejected,
        "steps_taken": dyn.steps_taken, "smallest_step": dyn.smallest_step,
        "newton_floor_accepts": dyn.floor_accepts}, stages)
    return dyn, stages


def run_loaded(scene: Scene, output: str | Path | None = None, *,
               start: float | None = None, progress: bool | None = None,
               after: Callable[[RunOutcome], Any] | None = None,
               model: Model | None = None) -> RunOutcome:
    """Run a loaded scene (see :func:`run_scene`). ``model``: the model to run instead of
    the one the scene builds (a System assembled in Python, :mod:`ancfdrv.results`; the
    scene then carries only the analysis, solver and output settings). ``after``: called
    with the outcome while the output is still locked (plots), its value in
    ``outcome.after``."""
    start = time.perf_counter() if start is None else start
    out = Path(output) if output else scene.output_file
    check_output_path(out, input_files(scene), xdmf=writes_xdmf(scene))
    made = [p for p in (out.parent, *out.parent.parents) if not p.exists()]
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create the output directory {out.parent}: {exc.strerror}",
                         file=str(out)) from None
    try:
        with OutputLock(out), StopRequest() as stop:
            outcome = _run_locked(scene, out, start, progress, stop, model)
            if after is not None and stop.signum is None:
                try:
                    outcome.after = after(outcome)
                except OSError as exc:
                    if not disk_full(exc):
                        raise
                    raise SolverError(f"the run completed ({out} is complete, status 'ok') "
                                      f"but its plot could not be written: {exc}") from None
    except BaseException:
        if not out.exists():  # refused before writing (bad input found late): leave no trace
            for directory in made:
                try:
                    directory.rmdir()
                except OSError:
                    break
        raise
    if stop.signum is not None:  # after the last step: the file is complete, the process stops
        raise Interrupted(f"interrupted by {signal_name(stop.signum)} after the run completed; "
                          f"{out} is complete (status 'ok')", signum=stop.signum)
    return outcome


def run_in_memory(scene: Scene, output: MemoryOutput, *, start: float | None = None,
                  progress: bool | None = None, model: Model | None = None) -> RunOutcome:
    """Run a loaded scene as :func:`run_loaded` does (the same model, solvers, settings and
    status handling) with its output kept in ``output`` instead of a file: no output path,
    no lock, no file. Raises as :func:`run_loaded` (InputError, SolverError, Interrupted);
    what was computed before a failure or an interrupt stays in ``output``, its status
    'failed' or 'interrupted'. :func:`ancfdrv.simulate` is the public door."""
    start = time.perf_counter() if start is None else start
    output.input_files, output.writes_xdmf = input_files(scene), writes_xdmf(scene)
    with StopRequest() as stop:
        outcome = _run_locked(scene, output, start, progress, stop, model)
    if stop.signum is not None:  # after the last step: the results are complete
        raise Interrupted(f"interrupted by {signal_name(stop.signum)} after the run completed; "
                          f"{output} are complete (status 'ok')", signum=stop.signum)
    return outcome


def _interrupt_message(out: Path | MemoryOutput, signum: int | None) -> str:
    """What an interrupted run left in its output file, in one line."""
    what = f"interrupted by {signal_name(signum)}"
    try:
        summary = _io(out).read_summary(out)
    except AncfError:
        return f"{what}; see {out}"
    if "dynamic.t_reached" in summary:
        kept = (f" at t = {summary['dynamic.t_reached']:.6g} s; "
                f"{summary.get('dynamic.steps', 0)} steps kept in {out}")
    elif "static.iterations" in summary:
        kept = f" after the static solve; its solution is kept in {out}"
    else:
        kept = f" before any result; {out} holds the model only"
    return f"{what}{kept} (status 'interrupted')"


def _run_locked(scene: Scene, out: Path | MemoryOutput, start: float, progress: bool | None,
                stop: StopRequest, model: Model | None = None) -> RunOutcome:
    analysis = scene["scene"]["analysis"]
    t0 = time.perf_counter()
    try:
        with stop.immediate():  # nothing is written yet: a signal ends the run at once
            model = build_model(scene) if model is None else model
    except Interrupted as exc:
        raise Interrupted(f"interrupted by {signal_name(exc.signum)} before the output was "
                          f"written; {out} was not touched", signum=exc.signum) from None
    except InputError as exc:  # found while assembling: name the scene file and the item
        raise locate_error(exc, scene) from None
    timing: dict[str, Any] = {"model": time.perf_counter() - t0}
    try:
        check_reduction(scene, model)
        check_static_method(scene, model)
        check_integrator(scene, model)
    except InputError as exc:
        model.close()
        raise locate_error(exc, scene) from None
    static = dynamic = None
    stages: dict[str, float] = {}

    def finish(status: str, message: str = "", *, after_error: bool = True) -> None:
        timing["total"] = time.perf_counter() - start
        if after_error:  # the held file may be in any state: reopened for the final status
            _io(out).drop(out)
        try:
            _io(out).finish(out, model, timing, status, message)
        except OSError:
            if not after_error:
                raise  # after an error, the error being raised matters more
        finally:
            if after_error:  # closed before anything reads it (the interrupt message)
                _io(out).drop(out)
    # the file stays open between the writes that follow each other without computing
    # (create and the dynamic writer's set-up; the last rows, answers, attributes and
    # status): closed in the solves and the stepping (results.released)
    with _io(out).holding(out):
        try:
            _io(out).create(out, scene, model)
            e_start = model.e0
            if analysis in ("static", "static+dynamic"):
                solver = scene["solver"]
                # the static solvers write nothing while they iterate
                with _io(out).released(out), stop.immediate():
                    static = solve_static_path(
                        model, solver["static_method"], tol=solver["tol"],
                        max_iter=solver["max_iter"], p=solver["split_p"],
                        load_steps=solver["load_steps"], arc_length=solver["arc_length"],
                        max_steps=solver["max_steps"],
                        target_load_factor=solver["target_load_factor"],
                        control_probe=solver["control_probe"])
                for phase, seconds in static.timing.items():
                    timing[f"static_{phase}"] = seconds
                t0 = time.perf_counter()
                _io(out).write_static(out, model, static)
                _write_static_supports(out, model, static)
                answers = _write_static_answers(scene, model, out, static)
                if analysis == "static":
                    with _io(out).released(out):
                        _write_grid_xdmf(scene, model, out, "static")
                timing["output"] = time.perf_counter() - t0
                implausible = check_static(model, static.e, answers.stress,
                                           warn=warns_implausible(scene))
                model.warnings.extend(implausible)
                if static.path is not None and not static.path.reached:
                    raise SolverError(static.path.message)   # the path and state written
                if static.extra.get("stability_index", 0) > 0:   # written, then refused
                    # an implausible state (the units) is named: it may be the cause
                    raise UnstableError("; ".join([unstable_static_message(
                        static.extra["stability_index"]), *implausible]))
                e_start = static.e
                if analysis == "static+dynamic":
                    stop.check()
            settle = settle_mode(scene)
            if analysis == "dynamic" and settle != "none":
                static = _settle(scene, model, out, settle, timing, stop)
                e_start = static.e
                stop.check()
            if analysis in ("dynamic", "static+dynamic"):
                dynamic, stages = _run_dynamic(scene, model, out, e_start, timing, progress, stop,
                                               static)
            if analysis in ("modal", "buckling"):
                with _io(out).released(out), stop.immediate():
                    run_eigen(scene, model, out, timing)
        except Interrupted as exc:
            signum = stop.signum or exc.signum
            finish("interrupted", f"interrupted by {signal_name(signum)}")
            raise Interrupted(_interrupt_message(out, signum), signum=signum) from None
        except KeyboardInterrupt:  # no handler installed (not the main thread)
            finish("interrupted", "interrupted (KeyboardInterrupt)")
            raise
        except InputError as exc:  # found by a solver (e.g. a modal analysis of nothing)
            located = locate_error(exc, scene)
            finish("failed", str(located))
            raise located from None
        except AncfError as exc:  # status 'failed', or 'unstable' (UnstableError)
            finish(getattr(exc, "status", "failed"), str(exc))
            raise
        except OSError as exc:
            if not disk_full(exc):
                finish("failed", f"internal error: {type(exc).__name__}: {exc}")
                raise
            message = (f"cannot write {out}: the disk or the file-size limit is full "
                       f"({str(exc).splitlines()[0][:200]}); the rows written before are kept")
            finish("failed", message)
            raise SolverError(message) from None
        except BaseException as exc:  # a bug: the file must not claim to be running
            finish("failed", f"internal error: {type(exc).__name__}: {exc}")
            raise
        finally:
            model.close()
        finish("ok", after_error=False)
    return RunOutcome(scene, out, static, dynamic, model.warnings, stages)


# -- modal analysis and linear buckling (SPEC section 10) ---------------------------------
def eigen_settings(scene: Scene, group: str) -> dict[str, Any]:
    """The &modal or &buckling values of a scene, with the schema's defaults for a group
    the scene does not give."""
    from .io.schema import SCHEMA
    given = scene.values.get(group) or {}
    return {k: given.get(k, spec.default) for k, spec in SCHEMA[group].items()}


def run_eigen(scene: Scene, model: Model, out: Path | MemoryOutput, timing: dict[str, Any]) -> None:
    """analysis = 'modal' (about the static equilibrium) or 'buckling'; writes /modal or
    /buckling, /static, and the XDMF of the shapes."""
    from .solvers.buckling import buckling_analysis
    from .solvers.modal import modal_analysis
    solver = scene["solver"]
    analysis = scene["scene"]["analysis"]
    t0 = time.perf_counter()
    if analysis == "modal":
        settings = eigen_settings(scene, "modal")
        result = modal_analysis(model, settings["modes"], solver=settings["solver"],
                                tol=solver["tol"], max_iter=solver["max_iter"],
                                load_steps=solver["load_steps"],
                                rigid_tol=settings["rigid_tol"],
                                spin_rate=settings["spin_rate"],
                                spin_axis=settings["spin_axis"],
                                spin_centre=settings["spin_centre"])
        _io(out).write_modal(out, model, result)
    else:
        settings = eigen_settings(scene, "buckling")
        # the fixed loads are flagged in the model (builders.build_model)
        result = buckling_analysis(model, settings["modes"], method=settings["method"],
                                   solver=settings["solver"], tol=solver["tol"],
                                   max_iter=solver["max_iter"],
                                   load_steps=settings["load_steps"], rtol=settings["rtol"],
                                   reference_factor=settings["reference_factor"])
        _io(out).write_buckling(out, model, result)
    timing[f"{analysis}_total"] = time.perf_counter() - t0
    for phase, seconds in result.timing.items():
        timing[f"{analysis}_{phase}"] = seconds
    _write_grid_xdmf(scene, model, out, analysis)


def _write_grid_xdmf(scene: Scene, model: Model, out: Path | MemoryOutput, group: str) -> None:
    """The one-grid XDMF of a static state (``group`` 'static') or of the shapes of a
    modal or buckling analysis, with output.xdmf (the default) and a mesh to show."""
    from .results.xdmf import MeshLayout, write_mode_xdmf, write_static_xdmf
    if not writes_xdmf(scene) or MeshLayout.from_model(model) is None:
        return
    if not isinstance(out, Path):  # a run kept in memory: written by its save()
        out.write_grid_xdmf(out, group)
    elif group == "static":
        write_static_xdmf(out)
    else:
        write_mode_xdmf(out, group)
