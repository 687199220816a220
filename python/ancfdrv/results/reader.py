"""The result object: any result file read back (SPEC section 10, "Python"); the runs from
Python that produce one are :mod:`ancfdrv.analyses`.

    from ancfdrv import System, Rectangle, open
    s = System("cantilever")
    ...
    res = s.static()                         # or s.simulate(t_end=1.0, dt=1e-3)
    res.probes["tip"], res.deflection["tip"], res.counters, res.status
    res.save("results/cantilever.h5")        # the file `ancf run` writes (plot, XDMF beside)
    again = open("results/cantilever.h5")    # the same object from any result file

A run from Python writes its HDF5 file as ``ancf run`` does, and the :class:`Results`
object is read back from that file, so an object from a run and one from
:func:`open_results` (``ancfdrv.open``) are the same by construction.

Result groups other modules add (``reactions``, ``sections``, ``stress`` under /static and
/dynamic, and the root groups ``modal`` and ``buckling``) are read generically: every group
becomes a :class:`Record` (a dict of arrays and sub-records with the HDF5 attributes in
``.attrs``), so new groups appear without changes here.
"""
from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from ..errors import InputError
from . import hdf5


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
    def tension(self) -> Record:
        """Dynamic runs: each cable's (rope's) axial force by name, 'min' and 'max' (nt,) N
        along it (tension positive; docs/results.md), when present."""
        return self._group("tension")

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
        """'ok', 'failed', 'unstable', 'interrupted' or 'running' (root attribute)."""
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
        XDMF description (when the run wrote one: output.xdmf) and the plot (``plot``)
        beside it as ``ancf run`` writes them. A plot that fails is a warning, never an error.
        Refuses (InputError) what ``ancf run`` refuses: a directory, a non-HDF5 file, ..."""
        from ..errors import SolverError
        from ..io.safe_write import disk_full, write_with
        from ..io.validate import check_path
        from .output_path import check_output_path
        target = check_path(path, "Results.save(path)")
        if target.exists() and target.resolve() == self.path.resolve():
            raise InputError("save: the target is this result's own file", file=str(target))
        check_output_path(target)
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            # atomically and never through a link planted at the target (io.safe_write): a
            # write that fails leaves what the target held
            write_with(target, lambda temp: shutil.copyfile(self.path, temp))
        except OSError as exc:
            reason = exc.strerror or str(exc)
            if disk_full(exc):
                raise SolverError(f"save: cannot write {target}: the disk or the file-size "
                                  f"limit is full ({reason}); {target} is left as it "
                                  "was") from None
            raise InputError(f"save: cannot write a file in {target.parent}: {reason}; "
                             f"{target.name} is left as it was", file=str(target)) from None
        if self.path.with_suffix(".xdmf").exists():
            from .xdmf import write_any_xdmf
            write_any_xdmf(target)
        if plot:
            import warnings
            from ..plots import plot_result
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
    from ..io.validate import check_path
    path = check_path(path, "open(path)")
    with hdf5.open_result(path) as h5:
        if not isinstance(h5.get("model"), h5py.Group):
            raise InputError("not an ancfdrv result file (no /model group)", file=str(path))
        record = _read_group(h5)
    return Results(path, record)
