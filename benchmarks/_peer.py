"""Helpers shared by the benchmarks that run the peer code Exudyn (``peer_exudyn.py``,
``peer_harness.py``): importing it (optional dependency), its version, and its simulation
settings by their current names, and the one rule both codes' Newton tolerances are chosen
by (:func:`loosest_keeping`)."""
from __future__ import annotations

import contextlib
import io
import sys
import warnings
from typing import Any, Callable, Sequence, TypeVar

import numpy as np

T = TypeVar("T")

#: A Newton tolerance keeps the history when the history moves by at most this fraction of
#: its range against the same configuration at a tight tolerance (issue 38: 0.004 %).
HISTORY_KEEP = 4e-5


def loosest_keeping(history_at: Callable[[T], np.ndarray], loosest_first: Sequence[T],
                    tight: T, fraction: float = HISTORY_KEEP,
                    errors: tuple[type[BaseException], ...] = (RuntimeError, ValueError),
                    ) -> tuple[T, list[dict[str, Any]]]:
    """The loosest of ``loosest_first`` whose history (``history_at(setting)``, the compared
    samples of one configuration) differs from ``history_at(tight)`` by at most ``fraction``
    of the tight history's range (max over the samples), and what each setting tried gave:
    ``{"setting", "change" (max difference / range, None if the run failed), "message"}``,
    the tight run first (change 0). Settings are tried loosest first and the first that keeps
    the history is chosen (none: ``tight``). The same rule for both codes; a failure of the
    tight run raises."""
    reference = history_at(tight)
    scale = float(np.ptp(reference))
    tried: list[dict[str, Any]] = [{"setting": tight, "change": 0.0, "message": ""}]
    for setting in loosest_first:
        try:
            change = float(np.max(np.abs(history_at(setting) - reference))) / scale
        except errors as exc:
            tried.append({"setting": setting, "change": None,
                          "message": " ".join(f"{type(exc).__name__}: {exc}".split())})
            continue
        tried.append({"setting": setting, "change": change, "message": ""})
        if change <= fraction:
            return setting, tried
    return tight, tried


def import_exudyn(fast: bool = False) -> tuple[Any, str | None]:
    """The exudyn module, or None and the reason it cannot be used.

    ``fast`` loads Exudyn's ``exudynCPPfast`` build (no range checks; Exudyn reads
    ``sys.exudynFast`` when it is first imported, so this only works before any import)."""
    if fast:
        sys.exudynFast = True  # type: ignore[attr-defined]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import exudyn
            import exudyn.beams  # noqa: F401
            import exudyn.itemInterface  # noqa: F401
        return exudyn, None
    except Exception as exc:  # any import failure means: skip the peer
        return None, f"{type(exc).__name__}: {exc}"


def exudyn_version(exu: Any) -> str:
    """Exudyn's version string."""
    config = getattr(exu, "config", None)
    if config is not None and hasattr(config, "Version"):
        return str(config.Version())
    return str(exu.GetVersionString())


def exudyn_build(exu: Any) -> str:
    """'exudynCPPfast' or 'exudynCPP': which compiled module Exudyn loaded."""
    return "exudynCPPfast" if "exudyn.exudynCPPfast" in sys.modules else "exudynCPP"


#: Exudyn 1.12+ names of settings and the names older versions use (now deprecated).
OLD_SETTING_NAMES = {"linearSolver.solverType": "linearSolverType",
                     "show.statistics": "displayStatistics",
                     "show.computationTime": "displayComputationTime",
                     "solution.file.write": "solutionSettings.writeSolutionToFile",
                     "solution.sensors.writePeriod": "solutionSettings.sensorsWritePeriod"}


def set_setting(settings: Any, path: str, value: Any) -> None:
    """Set a simulation setting by its current dotted name, or its older one."""
    for name in (path, OLD_SETTING_NAMES.get(path, path)):
        *parents, leaf = name.split(".")
        try:
            target = settings
            for parent in parents:
                target = getattr(target, parent)
            getattr(target, leaf)
        except AttributeError:
            continue
        setattr(target, leaf, value)
        return
    raise AttributeError(f"Exudyn has no setting {path!r}")


def quiet_settings(exu: Any, settings: Any, sensor_period: float) -> None:
    """No console statistics, no solution file, sensors stored every ``sensor_period``,
    Exudyn's sparse LU on one thread."""
    for path, value in (("linearSolver.solverType", exu.LinearSolverType.EigenSparse),
                        ("show.statistics", False), ("show.computationTime", False),
                        ("solution.file.write", False),
                        ("solution.sensors.writePeriod", sensor_period)):
        set_setting(settings, path, value)
    settings.parallel.numberOfThreads = 1


def run_quietly(solve: Callable[[], Any]) -> Any:
    """Call one of Exudyn's solvers with its console banner captured; an exception of the
    solver is raised as RuntimeError with the banner's start in the message."""
    with contextlib.redirect_stdout(io.StringIO()) as banner:
        try:
            return solve()
        except Exception as exc:  # Exudyn raises its own SolverError and others
            raise RuntimeError(f"{type(exc).__name__}: {exc} "
                               f"{banner.getvalue().strip()[:200]}") from None
