"""Helpers shared by the benchmark scripts: machine description, load, JSON-ready
conversion and plain-text tables."""
from __future__ import annotations

import math
import os
import platform
import sys
from typing import Any

import numpy as np
import scipy

import ancfdrv


def load_average() -> list[float] | None:
    """The 1, 5 and 15 minute load averages (other processes distort timings)."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None


def machine_info() -> dict[str, Any]:
    """Platform, CPUs, library versions, thread settings and the current load."""
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        usable = os.cpu_count()
    threads = {k: os.environ[k] for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                                          "MKL_NUM_THREADS") if k in os.environ}
    return {"platform": platform.platform(), "machine": platform.machine(),
            "processor": platform.processor(), "python": sys.version.split()[0],
            "cpu_count": os.cpu_count(), "cpus_usable": usable, "numpy": np.__version__,
            "scipy": scipy.__version__, "ancfdrv": getattr(ancfdrv, "__version__", None),
            "thread_env": threads, "load_average_at_start": load_average()}


def json_ready(value: Any) -> Any:
    """JSON-ready copy: numpy scalars and arrays to Python, NaN and inf to None."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_ready(v) for v in value]
    return value


def print_table(head: list[tuple[str, int]], rows: list[list[str]]) -> None:
    """Right-aligned columns of the given widths under a rule."""
    print(" ".join(f"{h:>{w}}" for h, w in head))
    print("-" * (sum(w for _, w in head) + len(head) - 1))
    for row in rows:
        print(" ".join(f"{c:>{w}}" for c, (_, w) in zip(row, head)))


def write_report(path, report: dict[str, Any]) -> None:
    """Write the JSON report (NaN and inf as null) and say where."""
    import json
    from pathlib import Path
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(json_ready(report), indent=1, allow_nan=False) + "\n")
    print(f"\nwrote {path} in {report['wall_time_s']:.1f} s")
