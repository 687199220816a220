"""Run a scene and keep its results in memory: :func:`simulate` -> :class:`Simulation`.

    import ancfdrv
    sim = ancfdrv.simulate("inputs/hard/pendulum.nml",
                           ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy"])
    sim.time                  # (n,) s
    sim.probe("tip")          # (n, 3) m, global positions
    sim.deflection("tip")     # (n, 3) m, in the probe's frame
    sim.series("energy/balance"), sim.dynamic.newton_iterations, sim.timing["total"]
    sim.save("results/pendulum.h5")   # the file `ancf run` would have written

:func:`simulate` runs exactly what :func:`ancfdrv.runner.run_scene` runs (the same model,
static start or settling, dynamics, modal or buckling analysis, engineering answers, status
handling: :func:`ancfdrv.runner.run_in_memory`) and writes no file: parameter studies and
optimisation loops pay for no file nobody reads. The series are the file's
(:mod:`ancfdrv.results.memory`: made by the file writer's own function), bit for bit;
:meth:`Simulation.save` writes the file ``run_scene`` would have written (SPEC section 4;
only wall times, timings and the provenance's time stamps differ).

Errors are those of ``run_scene``: InputError (bad input, naming the file, group and key),
SolverError (a solve failed) and Interrupted (SIGINT/SIGTERM). Once the run has started
computing, the exception carries what was computed until then as ``exc.simulation`` (a
:class:`Simulation` whose ``status`` is 'failed', 'unstable' or 'interrupted', every
completed step in its series; ``exc.simulation.save(path)`` writes the file ``run_scene``
would have left).
"""
from __future__ import annotations

import time as _time
from pathlib import Path
from typing import Any

import numpy as np

from .errors import AncfError, InputError
from .io.scene import Scene, load_scene
from .results.memory import MemoryOutput


class Simulation:
    """The results of one run kept in memory (made by :func:`simulate`).

    Attributes: ``scene`` (the :class:`~ancfdrv.io.scene.Scene` run), ``status`` ('ok',
    'failed', 'interrupted') and ``message``, ``static`` (the
    :class:`~ancfdrv.solvers.static.StaticResult` of a static analysis, of the static start
    or of the settling; None without), ``dynamic`` (the
    :class:`~ancfdrv.solvers.dynamic.DynamicResult` statistics and timings of a completed
    dynamic run; None without one or after a failure), ``modal`` / ``buckling`` (the
    :class:`~ancfdrv.solvers.modal.ModalResult` / ``BucklingResult`` of those analyses),
    ``warnings``, ``stages`` (the per-stage summary of staged scenes), ``timing`` (the
    run's phases in seconds, as /timing of the file holds them before the file's own
    output), ``attrs`` (what the file's /dynamic attributes hold: integrator, dt, steps,
    newton_iterations, ...).
    """

    def __init__(self, output: MemoryOutput, scene: Scene, outcome=None) -> None:
        self._output = output
        self.scene = scene
        self.status: str = output.status
        self.message: str = output.message
        self.static = output.static
        self.dynamic = None if outcome is None else outcome.dynamic
        self.modal = output.modal
        self.buckling = output.buckling
        model = output.model
        self.warnings: list[str] = list(model.warnings) if model is not None else []
        self.stages: dict[str, float] = dict(output.stages)
        self.timing: dict[str, float] = dict(output.timing)
        self.attrs: dict[str, Any] = dict(output.dynamic_attrs)

    @property
    def summary(self) -> dict[str, int | str]:
        """The model's figures (the file's /model attributes: ndof, nnodes, nelements,
        nconstraints, ...)."""
        model = self._output.model
        return {} if model is None else dict(model.summary())

    # -- the dynamic series -------------------------------------------------------------------
    @property
    def names(self) -> list[str]:
        """The names of every /dynamic row series kept (``series(name)``)."""
        return self._output.series_names()

    def series(self, name: str) -> np.ndarray:
        """A /dynamic row series by its name in the file (SPEC section 4): 'time',
        'probes/<p>', 'deflection/<p>', 'lambda', 'energy/<kind>' (kinetic, strain,
        potential, ..., total, balance), 'constraint_violation', 'newton_iterations',
        'factorizations', 'jacobian_evaluations', 'step_size', 'substeps', 'step_cuts',
        'contact/<field>', 'q' (with output.q). KeyError names the series kept."""
        names = self._output.series_names()
        if name not in names:
            raise KeyError(f"no series {name!r} in this run (series: "
                           f"{', '.join(names) or 'none: no dynamic run'})")
        return self._output.series(name)

    @property
    def time(self) -> np.ndarray:
        """The output times (s), the initial row first; empty without a dynamic run."""
        if "time" not in self._output.series_names():
            return np.zeros(0)
        return self._output.series("time")

    @property
    def probe_names(self) -> list[str]:
        return list(self._output.model.probes) if self._output.model is not None else []

    def probe(self, name: str) -> np.ndarray:
        """Global position (n, 3) of probe ``name`` at every output time (m)."""
        return self._probe_series("probes", name)

    def deflection(self, name: str) -> np.ndarray:
        """Displacement (n, 3) of probe ``name`` from its rigid configuration, in its frame
        (a beam's frame; other bodies: global axes), at every output time (m)."""
        return self._probe_series("deflection", name)

    def _probe_series(self, kind: str, name: str) -> np.ndarray:
        if name not in self.probe_names:
            raise KeyError(f"no probe {name!r} (probes: {', '.join(self.probe_names)})")
        return self.series(f"{kind}/{name}")

    def energy(self, kind: str = "total") -> np.ndarray:
        """An energy series (J): 'kinetic', 'strain', 'potential', 'total', 'balance'
        (total - total(0) - works: the integrator's energy error), ..."""
        return self.series(f"energy/{kind}")

    @property
    def q(self) -> np.ndarray | None:
        """The coordinates (n, ndof) at every output time when the scene asks for them
        (output.q = .true.), else None (:attr:`q_last` holds the last row's)."""
        return self._output.series("q") if "q" in self._output.series_names() else None

    @property
    def q_last(self) -> np.ndarray | None:
        """The coordinates at the last output time (None without a dynamic run)."""
        writer = self._output.writer
        return None if writer is None else writer.q_last()

    def deflection_support(self, name: str, analysis: str = "dynamic") -> np.ndarray:
        """General scenes: probe ``name``'s deflection relative to the rigid motion of its
        beam's supports (/<analysis>/deflection_support, m)."""
        values = self._output.support.get(analysis, {})
        if name not in values:
            raise KeyError(f"no support deflection {name!r} in the {analysis} results")
        return values[name]

    # -- the static state -----------------------------------------------------------------------
    def static_probe(self, name: str) -> np.ndarray:
        """Global position (3,) of probe ``name`` in the static state (m)."""
        if self.static is None:
            raise KeyError("no static state in this run")
        return self._output.model.probe_positions(self.static.e)[name]

    def static_deflection(self, name: str) -> np.ndarray:
        """Displacement (3,) of probe ``name`` in the static state, in its frame (m)."""
        if self.static is None:
            raise KeyError("no static state in this run")
        return self._output.model.deflections(self.static.e)[name]

    @property
    def static_answers(self):
        """Reactions, section forces and stresses of the static state
        (:class:`~ancfdrv.system.answers.Answers`; None when the run has no static state)."""
        return self._output.static_answers

    # -- the dynamic answers (SPEC section 10) -------------------------------------------------
    def reaction(self, joint: str) -> dict[str, np.ndarray]:
        """The dynamic reaction of a joint (or force element) at every output time: 'force'
        (n, 3) N and 'moment' (n, 3) N m that body1 exerts on body2 (global axes), 'axial'
        (n,) N for distance joints (tension positive)."""
        recorder = self._output.recorder
        chunks = None if recorder is None else recorder.reactions.get(joint)
        if not chunks:
            known = [] if recorder is None else [k for k, v in recorder.reactions.items() if v]
            raise KeyError(f"no dynamic reaction {joint!r} (recorded: "
                           f"{', '.join(known) or 'none'})")
        out = {"force": np.concatenate([c[0] for c in chunks]),
               "moment": np.concatenate([c[1] for c in chunks])}
        if chunks[0][2] is not None:
            out["axial"] = np.concatenate([c[2] for c in chunks])
        return out

    def stress_envelope(self, beam: str) -> dict[str, np.ndarray]:
        """The von Mises envelope of a beam over the run: 's' (stations, m),
        'von_mises_max' (Pa) and 't_max' (s, when each station's maximum occurred)."""
        recorder = self._output.recorder
        if recorder is None or beam not in recorder.envelope:
            raise KeyError(f"no stress envelope of beam {beam!r}")
        s, best, when = recorder.envelope[beam]
        return {"s": s, "von_mises_max": best, "t_max": when}

    @property
    def reactions(self) -> list[str]:
        """The joints (and force elements) whose dynamic reactions were recorded."""
        recorder = self._output.recorder
        return [] if recorder is None else [k for k, v in recorder.reactions.items() if v]

    # -- the file -----------------------------------------------------------------------------
    def save(self, path: str | Path, *, replace: bool = False) -> Path:
        """Write the HDF5 file (and the XDMF description beside it when the scene's run
        writes one) that ``run_scene`` would have written for this run: the same datasets,
        values and attributes (SPEC section 4), except wall times, timings and the
        provenance's time stamps. An existing file is refused (InputError) unless
        ``replace``; an input file of the scene is never overwritten."""
        return self._output.save(path, replace=replace)

    def __repr__(self) -> str:
        rows = len(self.time)
        what = f", {rows} rows to t = {self.time[-1]:.6g} s" if rows else ""
        return (f"<Simulation {self.scene['scene']['title']!r}: {self.status}"
                f"{what}, {len(self.warnings)} warning(s)>")


def simulate(scene: str | Path | Scene, overrides: list[str] | None = None, *,
             progress: bool | None = None) -> Simulation:
    """Run a scene (a namelist file, with ``--set``-style ``overrides`` such as
    ``["beam.nodes=9", "solver.dt=1e-3"]``, or a loaded :class:`~ancfdrv.io.scene.Scene`)
    exactly as :func:`ancfdrv.runner.run_scene` runs it, keeping the results in memory: no
    file is written (``Simulation.save(path)`` writes it on request). ``progress``: the
    progress bar of the dynamic run (None: shown when stderr is a terminal).

    Raises InputError (bad input, naming the file, group and key), SolverError (a solve
    failed) or Interrupted (SIGINT/SIGTERM). Once the model is built, the exception
    carries the results computed until then as ``exc.simulation`` (status 'failed',
    'unstable' or 'interrupted')."""
    from .runner import run_in_memory
    start = _time.perf_counter()
    if isinstance(scene, Scene):
        if overrides:
            raise InputError("overrides apply to a scene file: pass its path, or load it "
                             "with ancfdrv.io.scene.load_scene(path, overrides)",
                             file=str(scene.path))
        loaded = scene
    else:
        loaded = load_scene(scene, overrides)
    output = MemoryOutput()
    try:
        outcome = run_in_memory(loaded, output, start=start, progress=progress)
    except AncfError as exc:
        if output.scene is not None:   # the run had started: what it computed is kept
            exc.simulation = Simulation(output, loaded)
        raise
    return Simulation(output, loaded, outcome)


__all__ = ["Simulation", "simulate"]
