"""Reporting helpers the example scripts share: the command line (--quick, --out),
Markdown/CSV tables and the optional comparison with the repository's independent
references (tests/reference). Running a model and writing its result file needs none of
this: ``System.static()`` / ``System.simulate()`` return the results and ``.save()`` (or
``output=``) writes the file ``ancf run`` writes (``ancfdrv.results``).
"""
from __future__ import annotations

import argparse
import csv
import importlib.util
import sys
from pathlib import Path
from types import ModuleType
from typing import Any, Sequence

import matplotlib

matplotlib.use("Agg")  # files only: the examples run without a display

import numpy as np  # noqa: E402


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
