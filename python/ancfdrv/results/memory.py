"""A run's output kept in memory (:func:`ancfdrv.simulate`): no file is written unless asked.

:class:`MemoryOutput` stands where the runner (:mod:`ancfdrv.runner`) puts its output file:
it takes the very calls the runner makes to the HDF5 writer (:mod:`.hdf5`: ``create``,
``write_static``, ``DynamicWriter``, ``write_dynamic_answers``, ``finish``, ...), with the
same arguments, and instead of writing it keeps what they carry:

* the stepper's chunks (:class:`MemoryWriter`): every row field the file stores, q only
  when ``output.q`` asks for it (else the last row's and the rows the XDMF frames show,
  as the file's writer keeps them);
* the static result, the answers recorder, the support deflections, the /dynamic
  attributes, the final status, message and timings.

The time series are made from the chunks by the writer's own function
(:func:`.hdf5.row_series`), so they equal the file's bit for bit. :meth:`MemoryOutput.save`
replays the recorded calls, in their order, into the HDF5 writer: the file ``run_scene``
would have written (same datasets, values and attributes; only wall times, timings and
the provenance's time stamps differ). The layout of the file is written in one place,
:mod:`.hdf5`, for both.

Only what must be computed while the model's kernel is alive is computed at once (the
static answers, the answers recorder's last waiting rows); what the file alone needs (the
XDMF frames' point positions, the file's attributes) is made when the file is saved.
"""
from __future__ import annotations

import contextlib
import weakref
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Callable, Iterator

import numpy as np



class MemoryWriter:
    """The stand-in of :class:`.hdf5.DynamicWriter` for a run kept in memory: a sink of the
    stepper's chunks that keeps them (same arguments as the writer, recorded for the
    replay into a file).

    When the chunks carry q that is not to be kept (``store_q`` without ``write_q``: the
    answers or the XDMF frames need it, not the user), a chunk is kept thinned as the
    file's writer keeps it while it waits for a flush: its row fields copied (the kernel's
    row buffer, mostly q, is released), the last row's q, and q at the rows the XDMF
    frames show (their points are computed when the file is saved)."""

    def __init__(self, output: "MemoryOutput", model, store_q: bool, flush_rows: int = 1, *,
                 xdmf: bool | None = None, total_rows: int = 0, frames: int = 1000,
                 write_q: bool | None = None) -> None:
        # the output keeps its writer: the writer refers to it weakly (no reference cycle:
        # a dropped result is freed at once, not left to the garbage collector)
        self._output = weakref.ref(output)
        self.model, self.store_q = model, store_q
        self.arguments = (store_q, flush_rows)
        self.options = dict(xdmf=xdmf, total_rows=total_rows, frames=frames, write_q=write_q)
        self.write_q = store_q if write_q is None else bool(write_q and store_q)
        if xdmf is None:
            xdmf = bool(model.plate_bodies())
        self.keep_frames = bool(xdmf and store_q)
        if self.keep_frames and total_rows > 0:
            from .xdmf import frame_rows
            self.stride, self.last_row = frame_rows(total_rows, frames)
        else:
            self.stride, self.last_row = 1, -1
        self.rows = 0
        self.chunks: list[Any] = []

    @property
    def output(self) -> "MemoryOutput":
        output = self._output()
        if output is None:
            raise ReferenceError("the output of this writer was released")
        return output

    def __call__(self, chunk) -> None:
        q = getattr(chunk, "q", None)
        if self.store_q and not self.write_q and q is not None:
            chunk = self._thinned(chunk)
        self.chunks.append(chunk)
        self.rows += len(chunk.time)

    def _thinned(self, chunk) -> SimpleNamespace:
        """:func:`.hdf5.thinned_chunk`, its frame rows' q kept (``frame_q``: the points
        are computed when the file is saved)."""
        from .hdf5 import thinned_chunk
        out, frame = thinned_chunk(chunk, self.rows, self.stride, self.last_row,
                                   self.keep_frames)
        out.frame_q = frame
        return out

    def flush_last(self) -> None:
        """The run has ended (as the file's writer is told): recorded for the replay."""
        self.output.journal.append(("flush_last", self, (), {}))

    def flush(self) -> None:
        self.output.journal.append(("flush", self, (), {}))

    # -- the series, as the file stores them -------------------------------------------------
    def series_parts(self) -> dict[str, list[np.ndarray]]:
        """Every /dynamic row series (time, probes/<p>, deflection/<p>, lambda,
        energy/<name>, energy/balance, contact/<field>, constraint_violation, the step
        statistics, step_size, substeps, step_cuts, and q when kept) as its chunks' parts,
        each made by the file writer's :func:`.hdf5.row_series`, chunk by chunk as the
        writer makes them (:func:`join` makes a series)."""
        from .hdf5 import row_series
        names = list(self.model.probes)
        parts: dict[str, list[np.ndarray]] = {}
        total0 = before = None
        for chunk in self.chunks:
            if total0 is None and len(chunk.time):
                total0 = chunk.energy[0, 4]
            rows = row_series(chunk, names, self.model.npoint,
                              0.0 if total0 is None else total0,
                              before if getattr(chunk, "step_size", None) is None else None)
            for name, values in rows:
                parts.setdefault(name, []).append(values)
            if self.write_q and chunk.q is not None:
                parts.setdefault("q", []).append(chunk.q)
            if len(chunk.time):
                before = chunk.time[-1]
        return parts

    def q_last(self) -> np.ndarray | None:
        """The coordinates of the last row (None when the chunks did not carry q)."""
        for chunk in reversed(self.chunks):
            if getattr(chunk, "q_last", None) is not None:
                return chunk.q_last
            if getattr(chunk, "q", None) is not None and len(chunk.q):
                return np.array(chunk.q[-1])
        return None

    # -- the replay into a file --------------------------------------------------------------
    def replay(self, path: Path):
        """A :class:`.hdf5.DynamicWriter` on ``path`` fed the kept chunks (the thinned ones
        as the file's writer thins them: the frames' points computed now, chunk by chunk,
        from the same rows of q)."""
        from . import hdf5
        writer = hdf5.DynamicWriter(path, self.model, *self.arguments, **self.options)
        for chunk in self.chunks:
            if hasattr(chunk, "frame_q"):
                thinned = SimpleNamespace(**{f: getattr(chunk, f) for f in hdf5.ROW_FIELDS})
                thinned.q, thinned.q_last, thinned.frames = None, chunk.q_last, None
                if chunk.frame_q is not None and writer.nnodes:
                    rows, q = chunk.frame_q
                    thinned.frames = (rows, writer.layout.positions(self.model, q))
                chunk = thinned
            writer(chunk)
        return writer


def join(parts: list[np.ndarray]) -> np.ndarray:
    """A series from its chunks' parts, with the dtype the file stores (int64 counts,
    float64 otherwise), contiguous."""
    dtype = np.int64 if parts[0].dtype.kind in "iub" else np.float64
    return np.ascontiguousarray(parts[0] if len(parts) == 1 else np.concatenate(parts),
                                dtype=dtype)


class _SeriesView:
    """``h5["dynamic/<series>"]`` of a run kept in memory (what the runner reads back)."""

    def __init__(self, output: "MemoryOutput") -> None:
        self.output = output

    def __getitem__(self, key: str) -> np.ndarray:
        group, _, name = key.partition("/")
        if group != "dynamic":
            raise KeyError(key)
        return self.output.series(name)

    def __contains__(self, key: str) -> bool:
        group, _, name = key.partition("/")
        return group == "dynamic" and name in self.output.series_names()


class MemoryOutput:
    """The output of a run kept in memory: the runner's calls to the HDF5 writer, kept
    (``journal``) and replayed into a file by :meth:`save`; what they carry in the
    attributes below. ``str(output)`` names it in the runner's messages."""

    def __init__(self) -> None:
        #: (call, target, args, kwargs) in the order the runner made them
        self.journal: list[tuple[str, Any, tuple, dict]] = []
        self.scene = None
        self.model = None
        #: the files the scene reads (never overwritten by save) and whether its run writes
        #: the XDMF description (set by the runner: :func:`ancfdrv.runner.run_in_memory`)
        self.input_files: list[Path] = []
        self.writes_xdmf = False
        self.static = None              # StaticResult (static, settled or modal start)
        self.static_answers = None      # ancfdrv.system.answers.Answers of the static state
        self.support: dict[str, dict[str, np.ndarray]] = {}   # analysis -> probe -> values
        self.writer: MemoryWriter | None = None
        self.recorder = None            # DynamicAnswers of the dynamic run
        self.dynamic_attrs: dict[str, Any] = {}
        self.stages: dict[str, float] = {}
        self.modal = None
        self.buckling = None
        self.status = "running"
        self.message = ""
        self.timing: dict[str, float] = {}
        self._part_map: dict[str, list[np.ndarray]] = {}
        self._series: dict[str, np.ndarray] = {}
        self._series_rows = -1

    def __str__(self) -> str:
        return "the results in memory"

    def _record(self, call: str, args: tuple = (), kwargs: dict | None = None) -> None:
        self.journal.append((call, None, args, kwargs or {}))

    # -- the HDF5 writer's calls (path first: the output itself, ignored) ----------------------
    def create(self, path, scene, model) -> None:
        self.scene, self.model = scene, model
        self._record("create", (scene, model))

    def write_static(self, path, model, result) -> None:
        self.static = result
        self._record("write_static", (model, result))

    def write_support_deflections(self, path, analysis: str, deflections: dict, frames: dict,
                                  reference: str, displacement: str) -> None:
        self.support[analysis] = dict(deflections)
        self._record("write_support_deflections",
                     (analysis, dict(deflections), dict(frames), reference, displacement))

    def write_static_answers(self, path, model, e, lam, stations: int = 3,
                             answers=None) -> None:
        """The answers computed now (they need the model's kernel, released at the end of
        the run), kept and recorded with the call."""
        if answers is None:
            from ..system.answers import static_answers
            answers = static_answers(model, e, lam, stations)
        self.static_answers = answers
        self._record("write_static_answers", (model, e, lam, stations), {"answers": answers})

    def DynamicWriter(self, path, model, store_q: bool, flush_rows: int = 1,  # noqa: N802
                      **options: Any) -> MemoryWriter:
        self.writer = MemoryWriter(self, model, store_q, flush_rows, **options)
        self._series_rows = -1
        self.journal.append(("DynamicWriter", self.writer, (), {}))
        return self.writer

    def write_dynamic_answers(self, path, recorder) -> None:
        """The recorder's waiting rows recorded now (as the file's writer does first; a
        failure there is a warning and no answers, as in the file)."""
        from .hdf5 import complete_answers
        if not complete_answers(recorder):
            return
        self.recorder = recorder
        self._record("write_dynamic_answers", (recorder,))

    def write_dynamic_attrs(self, path, attrs: dict[str, Any], stages: dict[str, float]) -> None:
        self.dynamic_attrs.update(attrs)
        self.stages = dict(stages) if stages else self.stages
        self._record("write_dynamic_attrs", (dict(attrs), dict(stages)))

    def finish(self, path, model, timing: dict[str, float], status: str,
               message: str = "") -> None:
        self.status, self.message, self.timing = status, message, dict(timing)
        self._record("finish", (model, dict(timing), status, message))

    def write_modal(self, path, model, result) -> None:
        self.modal, self.static = result, result.static
        self._record("write_modal", (model, result))

    def write_buckling(self, path, model, result) -> None:
        self.buckling = result
        if result.base is not None:
            self.static = result.base
        self._record("write_buckling", (model, result))

    def write_grid_xdmf(self, path, group: str) -> None:
        """The XDMF of the static state ('static') or of a modal or buckling analysis's
        shapes, written on save."""
        self._record("write_grid_xdmf", (group,))

    # -- file handling: nothing to hold, release or drop ---------------------------------------
    def holding(self, path) -> contextlib.AbstractContextManager:
        return contextlib.nullcontext()

    def released(self, path) -> contextlib.AbstractContextManager:
        return contextlib.nullcontext()

    def drop(self, path) -> None:
        return None

    def reading(self, path) -> contextlib.AbstractContextManager:
        """``with reading(out) as h5: h5["dynamic/time"][()]``, from memory."""
        return contextlib.nullcontext(_SeriesView(self))

    def read_summary(self, path) -> dict[str, Any]:
        """The figures the runner's interrupt message names."""
        out: dict[str, Any] = {}
        if self.static is not None:
            out["static.iterations"] = self.static.iterations
        time = self.series("time") if "time" in self._parts() else None
        if time is not None and len(time):
            out["dynamic.t_reached"] = float(time[-1])
            out["dynamic.steps"] = self.dynamic_attrs.get("steps", len(time) - 1)
        return out

    # -- what the run kept ----------------------------------------------------------------------
    def _parts(self) -> dict[str, list[np.ndarray]]:
        if self.writer is None:
            return {}
        if self._series_rows != self.writer.rows:   # made again when rows were added
            self._part_map = self.writer.series_parts()
            self._series = {}
            self._series_rows = self.writer.rows
        return self._part_map

    def series_names(self) -> list[str]:
        """The names of the /dynamic row series kept (none without a dynamic run)."""
        return sorted(self._parts())

    def series(self, name: str) -> np.ndarray:
        """The /dynamic row series ``name`` (KeyError when the run has none), as the file
        holds it; made on first use."""
        parts = self._parts()
        if name not in self._series:
            self._series[name] = join(parts[name])
        return self._series[name]

    def save(self, path: str | Path, *, replace: bool = False) -> Path:
        """Write the file ``run_scene`` would have written (SPEC section 4; the XDMF
        description beside it when the run writes one): the recorded calls replayed, in
        their order, into the HDF5 writer. The path is checked as a run's output is
        (never an input file, never through a symbolic link); an existing file is
        refused unless ``replace``."""
        from ..io.validate import check_path
        from .output_path import check_output_path
        path = check_path(path, "Simulation.save(path)")
        if self.scene is None:
            from ..errors import InputError
            raise InputError("nothing to save: the run stopped before its model was built",
                             file=str(path))
        check_output_path(path, self.input_files, xdmf=self.writes_xdmf)
        path.parent.mkdir(parents=True, exist_ok=True)
        if not (path.exists() or path.is_symlink()):
            self._replay(path)
            return path
        if not replace:
            from ..errors import InputError
            raise InputError("the file exists (save(path, replace=True) replaces it)",
                             file=str(path))
        # the new files are written in a staging directory beside the old ones, under the
        # same names (the XDMF names its HDF5 file), and moved over them only once complete:
        # a save that fails leaves the old result as it was
        import os
        import tempfile
        with tempfile.TemporaryDirectory(prefix=f".{path.name}.", dir=path.parent) as staging:
            self._replay(Path(staging) / path.name)
            for made in sorted(Path(staging).iterdir()):
                os.replace(made, path.parent / made.name)
        return path

    def _replay(self, path: Path) -> None:
        """Replay the recorded calls, in their order, into a new file at ``path``."""
        from . import hdf5
        calls: dict[str, Callable[..., Any]] = {
            name: getattr(hdf5, name) for name in (
                "create", "write_static", "write_support_deflections", "write_static_answers",
                "write_dynamic_answers", "write_dynamic_attrs", "finish", "write_modal",
                "write_buckling")}
        writers: dict[int, Any] = {}
        with hdf5.holding(path):
            for call, target, args, kwargs in self.journal:
                if call == "DynamicWriter":
                    writers[id(target)] = target.replay(path)
                elif call in ("flush_last", "flush"):
                    getattr(writers[id(target)], call)()
                elif call == "write_grid_xdmf":
                    from .xdmf import write_mode_xdmf, write_static_xdmf
                    hdf5.drop(path)   # the XDMF writers open the file themselves
                    if args[0] == "static":
                        write_static_xdmf(path)
                    else:
                        write_mode_xdmf(path, *args)
                else:
                    calls[call](path, *args, **kwargs)

    def iter_calls(self) -> Iterator[str]:
        """The names of the recorded calls, in order (for tests and inspection)."""
        return (call for call, *_ in self.journal)
