"""The README's code runs as printed: the Python example of 'Composing a system' assembles
and solves, and the tip it prints hangs on the rope (its sag is the rope's and the beams'
small elastic stretch: below 0.1 mm for 150 kg on steel)."""
from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parents[1] / "README.md"


def python_blocks(text: str) -> list[str]:
    return [block.split("```", 1)[0] for block in text.split("```python\n")[1:]]


def test_composing_example_runs_as_printed():
    block = next(b for b in python_blocks(README.read_text()) if "System(" in b)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(block, "README.md", "exec"), {})
    tip = np.array([float(x) for x in out.getvalue().strip().strip("[]").split()])
    assert np.abs(tip - [6.0, 0.0, 0.0]).max() < 1e-4
    assert tip[1] < 0.0  # it sags, a little
