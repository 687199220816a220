"""From a :class:`~ancfdrv.system.System` to results in one call (SPEC section 10, "Python").

    from ancfdrv import System, Rectangle, open
    s = System("cantilever")
    ...
    res = s.static()                         # or s.simulate(t_end=1.0, dt=1e-3)
    res.probes["tip"], res.deflection["tip"], res.counters, res.status
    res.save("results/cantilever.h5")        # the file `ancf run` writes (plot, XDMF beside)
    modes = s.modes(6); factors = s.buckling(3)

A run from Python goes through the very path of ``ancf run`` (:func:`ancfdrv.runner.run_loaded`:
the same solvers, settings, writer and status handling), with the CLI's defaults: every key
of the scene groups ``&solver`` and ``&output`` is a keyword with the schema's default
(``docs/scenes.md``), e.g. ``jacobian='reuse'``, ``integrator='newmark'``,
``static_method='auto'``. The run writes its HDF5 file to a temporary directory (or to
``output=``); the :class:`~ancfdrv.results.Results` object is read back from that file
(:func:`ancfdrv.results.open_results`).

The system layer sits below the solvers and the writers, so :class:`System` does not import
them: this module registers the analyses (``System.static``, ``simulate``, ``modes``,
``buckling``) when it is imported, which the first analysis of a System does (the package's
``__init__`` names this module to it, :func:`ancfdrv._lazy.provide`).
"""
from __future__ import annotations

import sys
import tempfile
import warnings
import weakref
from pathlib import Path
from typing import Any

import numpy as np

from .errors import InputError
from .io import validate
from .io.scene import Scene, _typed
from .io.schema import SCHEMA, check_keywords
from .results.plausibility import IMPLAUSIBLE
from .results.reader import Results, open_results
from .runner import run_loaded
from .solvers.buckling import BUCKLING_KEYWORDS, buckling_analysis
from .solvers.modal import MODAL_KEYWORDS, modal_analysis
from .system.system import System

#: the analyses a System runs from Python (scene.analysis)
ANALYSES = ("static", "dynamic", "static+dynamic")


def _settings(options: dict[str, Any], where: str) -> tuple[dict, dict]:
    """The &solver and &output values of a run from Python: the schema's defaults (the
    CLI's) with the keyword options; unknown keys and bad values raise InputError."""
    # output.plot is ancf run's (from Python: Results.save(path, plot=True))
    solver_keys = set(SCHEMA["solver"])
    output_keys = set(SCHEMA["output"]) - {"file", "plot"}
    unknown = sorted(set(options) - solver_keys - output_keys)
    if unknown:
        raise InputError(f"{where}: unknown option {', '.join(map(repr, unknown))}; options: "
                         f"the &solver keys ({', '.join(sorted(solver_keys))}) and the "
                         f"&output keys ({', '.join(sorted(output_keys))}), see docs/scenes.md")
    solver = {k: v for k, v in options.items() if k in solver_keys}
    output = {k: v for k, v in options.items() if k in output_keys}
    for key, value in list(solver.items()) + list(output.items()):
        if isinstance(value, (tuple, list, np.ndarray)):
            raise InputError(f"{where}: option {key!r} takes one value, got {value!r}")
    if "dt" in solver and isinstance(solver["dt"], int) and not isinstance(solver["dt"], bool):
        solver["dt"] = float(solver["dt"])
    for key in ("t_end", "tol", "newton_tol", "split_p", "rho_inf", "beta", "gamma",
                "contraction"):
        if isinstance(solver.get(key), int) and not isinstance(solver[key], bool):
            solver[key] = float(solver[key])
    return (_typed("solver", "solver", solver, SCHEMA["solver"], where),
            _typed("output", "output", output, SCHEMA["output"], where))


def _script_text(system) -> tuple[Path, str]:
    """What the file's 'scene' attribute holds for a System built in Python: the running
    script's text when there is one, else a listing of the system's items."""
    main = sys.modules.get("__main__")
    script = Path(getattr(main, "__file__", "") or "")
    if script.suffix == ".py" and script.is_file() and "site-packages" not in script.parts:
        try:
            return script.resolve(), script.read_text()
        except (OSError, UnicodeDecodeError):
            pass
    lines = [f"# ancfdrv System {system.title!r} built in Python"]
    for kind in ("materials", "bodies", "drives", "joints", "loads", "contacts", "probes"):
        items = getattr(system, kind, {})
        if items:
            lines.append(f"# {kind}: {', '.join(items)}")
    return Path("<python>"), "\n".join(lines) + "\n"


def run_system(system, analysis: str, *, output: str | Path | None = None,
               effects=None, progress: bool | None = None, **options: Any) -> Results:
    """Run a System the way ``ancf run`` runs a scene and return its :class:`Results`.

    ``analysis``: 'static', 'dynamic' or 'static+dynamic'; ``options``: any key of the
    scene groups &solver and &output (docs/scenes.md), with their defaults; ``output``:
    the HDF5 file to write (default: a temporary file that lives as long as the results;
    :meth:`Results.save` copies it); ``effects``: the effects to compute (default: the
    system's list, else every effect its items belong to). Raises InputError (bad input,
    exit 2 in the CLI) or SolverError (the file keeps the rows computed)."""
    where = f"System {system.title!r}"
    if analysis not in ANALYSES:
        raise InputError(f"{where}: analysis {analysis!r} must be one of {', '.join(ANALYSES)}")
    solver, out_values = _settings(options, where)
    validate.check_time(solver, analysis, where)
    target = None if output is None else validate.check_path(output, f"{where}: output")
    validate.check_output_memory(validate.Estimate(system._parts()), out_values, where,
                                 solver, analysis)
    chosen = effects if effects is not None else system.effects
    model = system.assemble(effects=tuple(chosen) if chosen is not None else None,
                            linear_joints=solver["linear_joints"], supports=True)
    try:
        formulations = sorted({getattr(b, "formulation", "") for b in system.bodies.values()
                               if getattr(b, "formulation", "")})
        path, text = _script_text(system)
        values = {"scene": {"title": system.title or "System", "analysis": analysis,
                            "formulation": ",".join(formulations) or "rigid",
                            "effects": list(model.effects), "response": None,
                            "response_component": 2, "bounds": system.bounds},
                  "solver": solver, "output": out_values}
        scene = Scene(path=path, values=values, text=text, items=[])
    except BaseException:
        model.close()
        raise
    owner = None
    if target is None:
        owner = tempfile.TemporaryDirectory(prefix="ancfdrv-")
        weakref.finalize(owner, owner.cleanup)
        target = Path(owner.name) / "result.h5"
    outcome = run_loaded(scene, target, progress=progress, model=model)
    for note in outcome.warnings:   # a script sees them as the terminal does
        if IMPLAUSIBLE in note:
            warnings.warn(note, UserWarning, stacklevel=3)
    result = open_results(target)
    result._owner = owner
    return result


def static(system, *, output: str | Path | None = None, effects=None,
           progress: bool | None = None, **options: Any) -> Results:
    """:meth:`System.static`: the static equilibrium (``ancf run`` of an 'static' scene)."""
    return run_system(system, "static", output=output, effects=effects, progress=progress,
                      **options)


def simulate(system, t_end: float, dt: float | None = None, *, from_static: bool = False,
             output: str | Path | None = None, effects=None, progress: bool | None = None,
             **options: Any) -> Results:
    """:meth:`System.simulate`: dynamics to ``t_end`` with step ``dt`` (default: the
    CLI's, 1e-3 s), from rest in the assembled configuration, or from the static
    equilibrium (``from_static``: analysis 'static+dynamic')."""
    if dt is not None:
        options["dt"] = dt
    options["t_end"] = t_end
    return run_system(system, "static+dynamic" if from_static else "dynamic", output=output,
                      effects=effects, progress=progress, **options)


def _eigen_door(system, call: str, keywords: dict[str, str], n: Any, linear_joints: Any,
                options: dict[str, Any], **named: Any) -> tuple[int, str, dict[str, Any]]:
    """The arguments of System.modes or System.buckling checked before anything is
    assembled, with the rules and messages of their namelist keys (``n`` is &modal or
    &buckling ``modes``, ``linear_joints`` &solver's, the options those of ``keywords``)."""
    where = f"System {system.title!r}: {call}()"
    options = check_keywords(where, options, {k: g for k, g in keywords.items()
                                              if k != "modes" and k not in named})
    first = check_keywords(where, {"modes": n, **named}, keywords)
    joints = check_keywords(where, {"linear_joints": linear_joints},
                            {"linear_joints": "solver"})["linear_joints"]
    return first.pop("modes"), joints, {**options, **first}


def modes(system, n: int = 10, *, effects=None, linear_joints: str = "auto", **options: Any):
    """:meth:`System.modes`: the ``n`` lowest modes about the static equilibrium of the
    system's loads (:func:`ancfdrv.solvers.modal.modal_analysis`)."""
    n, linear_joints, options = _eigen_door(system, "modes", MODAL_KEYWORDS, n, linear_joints,
                                            options)
    model = system.assemble(effects=effects, linear_joints=linear_joints)
    try:
        return modal_analysis(model, n, **options)
    finally:
        model.close()


def buckling(system, n: int = 3, *, fixed_loads=(), effects=None,
             linear_joints: str = "auto", **options: Any):
    """:meth:`System.buckling`: the ``n`` lowest positive load factors of the system's
    loads about their static state (:func:`ancfdrv.solvers.buckling.buckling_analysis`),
    the loads named in ``fixed_loads`` (load names or effects) kept at their value."""
    n, linear_joints, options = _eigen_door(system, "buckling", BUCKLING_KEYWORDS, n,
                                            linear_joints, options, fixed_loads=fixed_loads)
    fixed = tuple(options.pop("fixed_loads"))
    known = set(system.loads) | {load.effect for load in system.loads.values()}
    unknown = [name for name in fixed if name not in known]
    if unknown:
        raise InputError(f"buckling: fixed_loads names unknown load(s) or effect(s) "
                         f"{', '.join(map(repr, unknown))} (loads: "
                         f"{', '.join(system.loads) or 'none'})")
    model = system.assemble(effects=effects, linear_joints=linear_joints, fixed_loads=fixed)
    try:
        return buckling_analysis(model, n, **options)
    finally:
        model.close()


def show(system: System, path=None):
    """System.show: the preview of the undeformed model (:mod:`ancfdrv.preview`)."""
    from .preview import show_system
    return show_system(system, path)


def _register() -> None:
    """Give System its analyses (the system layer sits below this module: it runs the
    solvers and writes the result file)."""
    System._ANALYSES.update(static=static, simulate=simulate, modes=modes, buckling=buckling,
                             show=show)


_register()
