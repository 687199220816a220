"""Shared fixtures: paths to the shipped scenes and a writer for scene variants."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
INPUTS = ROOT / "inputs"


@pytest.fixture
def boom_scene() -> Path:
    return INPUTS / "boom_static.nml"


@pytest.fixture
def cantilever_scene() -> Path:
    return INPUTS / "cantilever.nml"


@pytest.fixture
def write_scene(tmp_path):
    """Write a scene file from text and return its path."""
    def write(text: str, name: str = "scene.nml") -> Path:
        path = tmp_path / name
        path.write_text(text)
        return path
    return write


#: a fresh interpreter's measure of the MUMPS libraries' resident pages around some work
#: (WORK: statements on ``model``, built from the scene argv[1] with the overrides OVERRIDES),
#: then around one MUMPS solve (the measure seeing MUMPS run)
_MUMPS_PAGES = """
import sys
import numpy as np
from ancfdrv import kernel
from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.solvers import dynamic, static


def mumps_kb():
    \"\"\"Resident kB of the MUMPS libraries' mappings (/proc/self/smaps).\"\"\"
    total, inside = 0, False
    with open('/proc/self/smaps') as smaps:
        for line in smaps:
            words = line.split()
            if words and '-' in words[0] and len(words) >= 5:
                inside = len(words) >= 6 and 'mumps' in words[-1]
            elif inside and words[0] == 'Rss:':
                total += int(words[1])
    return total


model = build_model(load_scene(sys.argv[1], overrides=OVERRIDES))
before = mumps_kb()
WORK
work = mumps_kb() - before
with kernel.DirectSolver(2, np.array([0, 1]), np.array([0, 1])) as solver:
    solver.factorize(np.array([2.0, 4.0]))
    solver.solve(np.ones(2))
print(before, work, mumps_kb() - before - work)
"""


def mumps_pages(scene: Path, overrides: list[str], work: str) -> tuple[int, int]:
    """The kB of MUMPS's resident pages that ``work`` (statements on ``model``) adds in a
    fresh interpreter, and what one MUMPS solve adds after it; skips where /proc is
    missing or MUMPS is linked statically (no mapping of its own)."""
    if not Path("/proc/self/smaps").exists():
        pytest.skip("needs Linux's /proc")
    script = _MUMPS_PAGES.replace("OVERRIDES", repr(overrides)).replace("WORK", work)
    done = subprocess.run([sys.executable, "-c", script, str(scene)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    mapped, added, mumps = (int(word) for word in done.stdout.split())
    if not mapped:
        pytest.skip("MUMPS is linked statically (no mapping of its own)")
    return added, mumps
