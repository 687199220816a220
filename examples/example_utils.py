"""Small helpers the example scripts share: the command line, result files (HDF5 in the
layout of SPEC section 4, so ``ancf info`` and ``ancf plot`` read them), Markdown/CSV
tables and the optional comparison with the repository's independent references.

Copy this file along with an example when you take the example elsewhere.
"""
from __future__ import annotations

import argparse
import csv
import importlib.util
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any, Sequence

import matplotlib

matplotlib.use("Agg")  # files only: the examples run without a display

import numpy as np  # noqa: E402

from ancfdrv.io import hdf5  # noqa: E402
from ancfdrv.io.scene import Scene  # noqa: E402
from ancfdrv.solvers.dynamic import Chunk, DynamicResult, DynamicSettings  # noqa: E402
from ancfdrv.solvers.static import StaticResult  # noqa: E402
from ancfdrv.system import Model  # noqa: E402

#: where the examples write, relative to the working directory (the repository root)
RESULTS = Path("results") / "examples"
#: the repository's test references (pure numpy/scipy), when the script runs in a checkout
REFERENCE_DIR = Path(__file__).resolve().parents[1] / "tests" / "reference"


def arguments(description: str, argv: Sequence[str] | None = None) -> argparse.Namespace:
    """--quick (a coarse, short run: seconds) and --out (the result folder)."""
    parser = argparse.ArgumentParser(description=description.strip().splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="coarser meshes and shorter runs (a few seconds)")
    parser.add_argument("--out", type=Path, default=RESULTS,
                        help=f"result folder (default {RESULTS})")
    return parser.parse_args(argv)


def reference(name: str) -> ModuleType | None:
    """The independent reference module ``tests/reference/<name>.py`` of the repository
    (pure numpy/scipy, written without looking at ancfdrv), or None outside a checkout."""
    path = REFERENCE_DIR / f"{name}.py"
    if not path.is_file():
        return None
    module_name = f"_example_reference_{name}"
    if module_name in sys.modules:
        return sys.modules[module_name]
    spec = importlib.util.spec_from_file_location(module_name, path)
    if spec is None or spec.loader is None:
        return None
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module  # dataclasses look their module up while it loads
    spec.loader.exec_module(module)
    return module


# -- dynamic runs --------------------------------------------------------------------------
class Recorder:
    """A sink for :func:`ancfdrv.solvers.dynamic.integrate`: keeps every output row in
    memory and, given a result file, appends it there too (``/dynamic`` of SPEC section 4).

    The integrator hands over arrays it may reuse for the next steps, so each chunk is
    copied when it arrives."""

    def __init__(self, model: Model, path: Path | None = None, store_q: bool = False) -> None:
        self.model = model
        self.chunks: list[Chunk] = []
        self.writer = hdf5.DynamicWriter(path, model, store_q) if path is not None else None

    def __call__(self, chunk: Chunk) -> None:
        copy = Chunk(**{k: (None if v is None else np.array(v, copy=True))
                        for k, v in vars(chunk).items()})
        self.chunks.append(copy)
        if self.writer is not None:
            self.writer(copy)

    def close(self, settings: DynamicSettings, result: DynamicResult) -> None:
        """Flush the result file and record the integrator's settings and statistics."""
        if self.writer is None:
            return
        self.writer.flush()
        hdf5.write_dynamic_attrs(self.writer.path, {
            "integrator": "generalized_alpha" if settings.alpha_m or settings.alpha_f
            else "newmark", "dt": settings.dt, "t_end": settings.t_end,
            "beta": settings.beta, "gamma": settings.gamma, "alpha_m": settings.alpha_m,
            "alpha_f": settings.alpha_f, "steps": result.steps,
            "newton_iterations": result.newton_iterations,
            "factorizations": result.factorizations, "wall_time_s": result.wall_time_s,
            "status": "ok"}, {})

    def _stack(self, attribute: str) -> np.ndarray:
        return np.concatenate([getattr(c, attribute) for c in self.chunks])

    @property
    def time(self) -> np.ndarray:
        """(nt,) output times [s]."""
        return self._stack("time")

    def probe(self, name: str) -> np.ndarray:
        """(nt, 3) global positions of a probe [m]."""
        return self._stack("probes")[:, list(self.model.probes).index(name)]

    def multiplier(self, constraint: str) -> np.ndarray:
        """(nt,) Lagrange multiplier of the named joint equation (``model.constraints``)."""
        return self._stack("lam")[:, self.model.constraints.names.index(constraint)]

    def energy(self, name: str) -> np.ndarray:
        """(nt,) one of ``ancfdrv.codes.ENERGY_NAMES`` [J]."""
        from ancfdrv.codes import ENERGY_NAMES
        return self._stack("energy")[:, ENERGY_NAMES.index(name)]

    def energy_balance(self) -> np.ndarray:
        """(nt,) total energy change minus the work of drives, moving frames, contact
        damping, friction and material damping (the HDF5 ``energy/balance``): zero for an
        exact integration."""
        e = self._stack("energy")
        return e[:, 4] - e[0, 4] - e[:, 5] - e[:, 6] - e[:, 8] - e[:, 9] - e[:, 10]

    def contact(self, field_name: str) -> np.ndarray:
        """(nt, npoints) a contact record field (``ancfdrv.codes.CONTACT_RECORD``)."""
        from ancfdrv.codes import CONTACT_RECORD
        return self._stack("contact")[:, :, CONTACT_RECORD.index(field_name)]


# -- result files ----------------------------------------------------------------------------
@dataclass
class ResultFile:
    """One HDF5 result file of a model built in Python (SPEC section 4): root attributes
    with the script as the 'scene', /model, then /static and /dynamic as they come, and
    /counters and /timing with the status 'ok' at :meth:`finish`."""

    path: Path
    model: Model
    title: str
    script: Path
    started: float = field(default_factory=time.perf_counter)

    def __post_init__(self) -> None:
        scene = Scene(path=self.script, values={"scene": {
            "title": self.title, "formulation": _formulation(self.model),
            "effects": list(self.model.effects)}}, text=self.script.read_text(), items=[])
        hdf5.create(self.path, scene, self.model)

    def static(self, result: StaticResult) -> None:
        hdf5.write_static(self.path, self.model, result)
        # reactions by joint name, section forces and stresses (SPEC section 10)
        hdf5.write_static_answers(self.path, self.model, result.e, result.lam)

    def recorder(self, store_q: bool = False) -> Recorder:
        return Recorder(self.model, self.path, store_q)

    def finish(self) -> None:
        hdf5.finish(self.path, self.model, {"total": time.perf_counter() - self.started}, "ok")


def _formulation(model: Model) -> str:
    kinds = sorted({s.kind for s in model.sets})
    return ",".join(kinds) if kinds else "rigid"


# -- tables ------------------------------------------------------------------------------------
def fmt(value: Any, digits: int = 6) -> str:
    """A table cell: numbers with ``digits`` significant digits, text as it is."""
    if isinstance(value, (float, np.floating)):
        return "" if not np.isfinite(value) else f"{value:.{digits}g}"
    return str(value)


def write_table(path: Path, headers: Sequence[str], rows: Sequence[Sequence[Any]],
                title: str = "", note: str = "") -> str:
    """Write ``path``.md (a Markdown table under an optional title and note) and
    ``path``.csv (full precision); returns the Markdown text."""
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = [f"## {title}", ""] if title else []
    def cells(values: Sequence[str]) -> str:  # a '|' inside a cell must be escaped
        return "| " + " | ".join(v.replace("|", "\\|") for v in values) + " |"
    lines += [cells(headers), "|" + "---|" * len(headers)]
    lines += [cells([fmt(v) for v in row]) for row in rows]
    if note:
        lines += ["", note]
    text = "\n".join(lines) + "\n"
    path.with_suffix(".md").write_text(text)
    with open(path.with_suffix(".csv"), "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(headers)
        writer.writerows([[repr(float(v)) if isinstance(v, (float, np.floating)) else v
                           for v in row] for row in rows])
    return text


def relative(value: float, reference_value: float) -> float:
    """(value - reference) / |reference|."""
    return (value - reference_value) / abs(reference_value)
