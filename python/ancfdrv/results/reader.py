"""From a :class:`~ancfdrv.system.System` to results in one call, and any result file back
(SPEC section 10, "Python").

    from ancfdrv import System, Rectangle, open
    s = System("cantilever")
    ...
    res = s.static()                         # or s.simulate(t_end=1.0, dt=1e-3)
    res.probes["tip"], res.deflection["tip"], res.counters, res.status
    res.save("results/cantilever.h5")        # the file `ancf run` writes (plot, XDMF beside)
    again = open("results/cantilever.h5")    # the same object from any result file

A run from Python goes through the very path of ``ancf run`` (:func:`ancfdrv.runner.run_loaded`:
the same solvers, settings, writer and status handling), with the CLI's defaults: every key
of the scene groups ``&solver`` and ``&output`` is a keyword with the schema's default
(``docs/scenes.md``), e.g. ``jacobian='reuse'``, ``integrator='newmark'``,
``static_method='split'``. The run writes its HDF5 file to a temporary directory (or to
``output=``); the :class:`Results` object is read back from that file, so an object from a
run and one from :func:`open_results` (``ancfdrv.open``) are the same by construction.

Result groups other modules add (``reactions``, ``sections``, ``stress`` under /static and
/dynamic, and the root groups ``modal`` and ``buckling``) are read generically: every group
becomes a :class:`Record` (a dict of arrays and sub-records with the HDF5 attributes in
``.attrs``), so new groups appear without changes here.
"""
from __future__ import annotations

import shutil
import sys
import tempfile
import weakref
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from .errors import InputError
from .io import hdf5
from .io.scene import Scene, _typed
from .io.schema import SCHEMA
from .io import validate

#: the analyses a System runs from Python (scene.analysis)
ANALYSES = ("static", "dynamic", "static+dynamic")


class Record(dict):
    """A group of a result file: datasets as numpy arrays, sub-groups as Records, the
    group's HDF5 attributes in :attr:`attrs` (strings decoded)."""

    def __init__(self, *args: Any, attrs: dict[str, Any] | None = None, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.attrs: dict[str, Any] = dict(attrs or {})

    def __repr__(self) -> str:
        return f"Record({', '.join(self)})"


def _value(value: Any) -> Any:
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.generic):
        return value.item()
    return value


def _read_group(group: h5py.Group) -> Record:
    out = Record(attrs={k: _value(v) for k, v in group.attrs.items()})
    for name, item in group.items():
        if isinstance(item, h5py.Group):
            out[name] = _read_group(item)
        elif isinstance(item, h5py.Dataset):
            data = item[()]
            out[name] = data.decode() if isinstance(data, bytes) else data
    return out


class Analysis:
    """One analysis of a result file (/static or /dynamic): probe positions and deflections
    by probe name, energies, multipliers, solver statistics (:attr:`attrs`) and every other
    group the file holds (reactions, sections, stress, contact, ...) by name.

    Static values have shape (3,) per probe; dynamic ones (nt, 3), with :attr:`time` (nt,)."""

    def __init__(self, name: str, record: Record, constraint_names: list[str] | None = None
                 ) -> None:
        self.name = name
        self.record = record
        #: the joint equations, in the order of the multipliers ``lambda``
        self.constraint_names = list(constraint_names or [])

    @property
    def attrs(self) -> dict[str, Any]:
        """Solver statistics and settings (method, iterations, steps, dt, status, ...)."""
        return self.record.attrs

    def _group(self, key: str) -> Record:
        value = self.record.get(key)
        return value if isinstance(value, Record) else Record()

    @property
    def probes(self) -> Record:
        """Global positions of the probes (m), by name."""
        return self._group("probes")

    @property
    def deflection(self) -> Record:
        """Deflections of the probes (m), by name; what they are relative to is stated in
        ``deflection.attrs['reference']`` when the file says it (SPEC section 4 otherwise:
        the displacement from the rigid configuration, beams in their frame)."""
        return self._group("deflection")

    @property
    def deflection_support(self) -> Record:
        """General scenes: the deflections of the probes on beams relative to the rigid
        motion of their beam's supports (m), by name (:mod:`ancfdrv.system.supports`;
        ``.attrs['reference']`` says so)."""
        return self._group("deflection_support")

    @property
    def reactions(self) -> Record:
        """Joint and force-element reactions by name (SPEC section 10), when present."""
        return self._group("reactions")

    @property
    def sections(self) -> Record:
        """Section forces by beam (SPEC section 10), when present."""
        return self._group("sections")

    @property
    def stress(self) -> Record:
        """Stresses by beam (SPEC section 10), when present."""
        return self._group("stress")

    @property
    def energy(self) -> Record:
        """Energies (J) by name (dynamic runs: kinetic, strain, gravity, total, ...)."""
        return self._group("energy")

    @property
    def time(self) -> np.ndarray | None:
        """Output times (s) of a dynamic analysis, None for a static one."""
        value = self.record.get("time")
        return None if value is None else np.asarray(value)

    @property
    def q(self) -> np.ndarray | None:
        """The coordinates: static solution, or every step's when output.q was set."""
        value = self.record.get("q")
        return None if value is None else np.asarray(value)

    def multiplier(self, constraint: str) -> np.ndarray | float:
        """The Lagrange multiplier of a named joint equation (``/model`` attribute
        constraint_names, e.g. 'cylinder: length'): a force (N) for position equations, a
        moment (N m) for gradient ones; (nt,) for a dynamic analysis."""
        names = self.constraint_names
        if constraint not in names:
            raise KeyError(f"no joint equation {constraint!r} (equations: {', '.join(names)})")
        lam = np.asarray(self.record["lambda"])
        return lam[..., names.index(constraint)]

    def __getitem__(self, key: str) -> Any:
        return self.record[key]

    def __contains__(self, key: str) -> bool:
        return key in self.record

    def __repr__(self) -> str:
        return f"Analysis({self.name!r}: {', '.join(self.record)})"


class Results:
    """A result file's content (SPEC sections 4 and 10), from :meth:`System.static`,
    :meth:`System.simulate` or :func:`open_results` (``ancfdrv.open``).

    :attr:`probes`, :attr:`deflection`, :attr:`reactions`, :attr:`sections`,
    :attr:`stress`, :attr:`energy` and :attr:`time` are those of the dynamic analysis when
    there is one, else of the static one (:attr:`static` and :attr:`dynamic` give each);
    :attr:`counters`, :attr:`timing` and :attr:`status` are the run's;
    :attr:`modes` and :attr:`buckling` the root groups ``/modal`` and ``/buckling`` when
    the file holds them (None otherwise)."""

    def __init__(self, path: Path, record: Record, *, owner: Any = None) -> None:
        self.path = Path(path)
        self.record = record
        self._owner = owner  # keeps a run's temporary directory alive with the object
        names = [n for n in str(record.get("model", Record()).attrs.get(
            "constraint_names", "")).split("\n") if n]
        self.static = Analysis("static", record["static"], names) if "static" in record \
            else None
        self.dynamic = Analysis("dynamic", record["dynamic"], names) if "dynamic" in record \
            else None

    # -- the run --------------------------------------------------------------------------
    @property
    def attrs(self) -> dict[str, Any]:
        """Root attributes: provenance, scene text, title, kind, effects, status, ..."""
        return self.record.attrs

    @property
    def status(self) -> str:
        """'ok', 'failed', 'interrupted' or 'running' (root attribute)."""
        return str(self.attrs.get("status", ""))

    @property
    def message(self) -> str:
        return str(self.attrs.get("message", ""))

    @property
    def title(self) -> str:
        return str(self.attrs.get("title", ""))

    @property
    def counters(self) -> dict[str, int]:
        """Evaluations per effect and kernel (zero: not computed)."""
        return dict(self.record.get("counters", Record()).attrs)

    @property
    def timing(self) -> dict[str, float]:
        """Seconds per phase (assembly, factorization, solve, contact, output, total, ...)."""
        return dict(self.record.get("timing", Record()).attrs)

    @property
    def model(self) -> Record:
        """/model: sizes (attrs ndof, nnodes, ...), e0 and the geometry the file holds."""
        return self.record.get("model", Record())

    @property
    def modes(self) -> Record | None:
        """/modal (frequency, shapes, ...) when the file holds it."""
        return self.record.get("modal")

    @property
    def buckling(self) -> Record | None:
        """/buckling (load_factor, shapes) when the file holds it."""
        return self.record.get("buckling")

    # -- the main analysis ------------------------------------------------------------------
    @property
    def main(self) -> Analysis:
        """The dynamic analysis when there is one, else the static one."""
        main = self.dynamic or self.static
        if main is None:
            raise InputError("the result file holds no analysis (neither /static nor "
                             f"/dynamic; status {self.status!r})", file=str(self.path))
        return main

    @property
    def probes(self) -> Record:
        return self.main.probes

    @property
    def deflection(self) -> Record:
        return self.main.deflection

    @property
    def deflection_support(self) -> Record:
        return self.main.deflection_support

    @property
    def reactions(self) -> Record:
        return self.main.reactions

    @property
    def sections(self) -> Record:
        return self.main.sections

    @property
    def stress(self) -> Record:
        return self.main.stress

    @property
    def energy(self) -> Record:
        return self.main.energy

    @property
    def time(self) -> np.ndarray | None:
        return self.main.time

    def multiplier(self, constraint: str) -> np.ndarray | float:
        """:meth:`Analysis.multiplier` of the main analysis."""
        return self.main.multiplier(constraint)

    # -- files --------------------------------------------------------------------------------
    def save(self, path: str | Path, *, plot: bool = True) -> Path:
        """Write the result file ``ancf run`` writes, byte for byte the run's HDF5, with the
        XDMF description (dynamic runs with output.xdmf) and the plot (``plot``) beside it
        as ``ancf run`` writes them. A plot that fails is a warning, never an error.
        Refuses (InputError) what ``ancf run`` refuses: a directory, a non-HDF5 file, ..."""
        from .io.safe_write import write_with
        from .runner import check_output_path
        target = Path(path)
        if target.exists() and target.resolve() == self.path.resolve():
            raise InputError("save: the target is this result's own file", file=str(target))
        check_output_path(target)
        target.parent.mkdir(parents=True, exist_ok=True)
        # atomically and never through a link planted at the target (io.safe_write)
        write_with(target, lambda temp: shutil.copyfile(self.path, temp))
        if self.path.with_suffix(".xdmf").exists():
            from .io.xdmf import write_xdmf
            write_xdmf(target)
        if plot:
            import warnings
            from .plots import plot_result
            try:
                plot_result(target)
            except Exception as exc:  # noqa: BLE001 - an optional output never fails a save
                warnings.warn(f"the plot of {target} was not written: "
                              f"{type(exc).__name__}: {exc}", stacklevel=2)
        return target

    def __repr__(self) -> str:
        parts = [f"{self.title!r}", f"status {self.status!r}"]
        if self.static is not None:
            parts.append("static")
        if self.dynamic is not None and self.time is not None and len(self.time):
            parts.append(f"dynamic to t = {self.time[-1]:g} s")
        parts.append(f"probes: {', '.join(self.probes) if (self.static or self.dynamic) else '-'}")
        return f"Results({'; '.join(parts)}; {self.path})"


def open_results(path: str | Path) -> Results:
    """Read any ancfdrv result file (from ``ancf run``, a sweep, :meth:`Results.save`)
    into a :class:`Results`. Raises InputError when the file is missing, not HDF5 or not
    an ancfdrv result."""
    path = Path(path)
    with hdf5.open_result(path) as h5:
        if not isinstance(h5.get("model"), h5py.Group):
            raise InputError("not an ancfdrv result file (no /model group)", file=str(path))
        record = _read_group(h5)
    return Results(path, record)


# -- runs from Python -----------------------------------------------------------------------
def _settings(options: dict[str, Any], where: str) -> tuple[dict, dict]:
    """The &solver and &output values of a run from Python: the schema's defaults (the
    CLI's) with the keyword options; unknown keys and bad values raise InputError."""
    solver_keys, output_keys = set(SCHEMA["solver"]), set(SCHEMA["output"]) - {"file"}
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
    from .builders.common import check_ffr_validity
    from .runner import run_loaded
    where = f"System {system.title!r}"
    if analysis not in ANALYSES:
        raise InputError(f"{where}: analysis {analysis!r} must be one of {', '.join(ANALYSES)}")
    solver, out_values = _settings(options, where)
    validate.check_time(solver, analysis, where)
    chosen = effects if effects is not None else system.effects
    model = system.assemble(effects=tuple(chosen) if chosen is not None else None,
                            linear_joints=solver["linear_joints"])
    model.kind = "general"
    from .system.supports import support_frames
    model.support_frames = support_frames(system)
    if "static_method" not in options and (any(s.kind != "ffr" for s in model.sets)
                                           or model.contact_pairs):
        # the CLI's default 'split' needs every body 'ffr' and no contact: where it cannot
        # run (it would fail with that message), Newton is the only static method
        solver["static_method"] = "newton"
    try:
        check_ffr_validity(model, system)
        formulations = sorted({getattr(b, "formulation", "") for b in system.bodies.values()
                               if getattr(b, "formulation", "")})
        path, text = _script_text(system)
        values = {"scene": {"title": system.title or "System", "analysis": analysis,
                            "formulation": ",".join(formulations) or "rigid",
                            "effects": list(model.effects), "response": None,
                            "response_component": 2},
                  "solver": solver, "output": out_values}
        scene = Scene(path=path, values=values, text=text, items=[])
    except BaseException:
        model.close()
        raise
    owner = None
    if output is None:
        owner = tempfile.TemporaryDirectory(prefix="ancfdrv-")
        weakref.finalize(owner, owner.cleanup)
        target = Path(owner.name) / "result.h5"
    else:
        target = Path(output)
    run_loaded(scene, target, progress=progress, model=model)
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


def _register() -> None:
    """Give System its analyses (the system layer sits below this module)."""
    from .system.system import System
    System._ANALYSES.update(static=static, simulate=simulate)


_register()
