"""Shared fixtures: paths to the shipped scenes and a writer for scene variants."""
from __future__ import annotations

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
