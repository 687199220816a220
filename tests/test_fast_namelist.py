"""The scene reader's own pass over plain namelists (io.scene.fast_reads, issue 23: f90nml's
parser took ~0.4 ms of each run's scene load) must give exactly what f90nml gives.

Reference: f90nml.reads of the same text: the values with their Python types, the groups
(repeated groups as f90nml's cogroups), the start indices and the text f90nml writes back
(the result file's ``scene`` attribute). Every shipped scene takes the fast pass; any form
outside the plain one is left to f90nml (None)."""
from __future__ import annotations

import io
from pathlib import Path

import f90nml
import pytest

from ancfdrv.io.scene import fast_reads, load_scene

ROOT = Path(__file__).resolve().parents[1]
SCENES = sorted(p for d in ("inputs", "tests", "examples") for p in (ROOT / d).rglob("*.nml"))


def _typed(value):
    if isinstance(value, dict):
        return {k: _typed(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_typed(v) for v in value]
    return type(value).__name__, value


def _written(nml) -> str:
    out = io.StringIO()
    nml.write(out)
    return out.getvalue()


def _same_as_f90nml(text: str) -> None:
    fast, reference = fast_reads(text), f90nml.reads(text)
    assert fast is not None
    assert _typed(fast) == _typed(reference)
    assert fast.start_index == reference.start_index
    assert repr(fast) == repr(reference) and _written(fast) == _written(reference)


@pytest.mark.parametrize("path", SCENES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_shipped_scene_reads_as_f90nml_reads_it(path):
    _same_as_f90nml(path.read_text())


PLAIN = {
    "one line": "&a x = 1, y = 'q''s', z = .TRUE., w = .f. /",
    "reals": "&a p = 1.5d-3, q = 1e3, r = -.5, s = +3, t = 3., u = 1E+05, v = 2.D0 /",
    "lists over lines": "&a v = 1.0, 2.0,  ! a comment / with a slash\n     3.0\n  n = 4 /\n",
    "cogroups": "&b name = 'a', k = 1 /\n&b name = 'b' /\n&c /\n&b name = 'c' /",
    "strings": "&a s = 'a/b ! c &d', t = \"it\"\"s\", u = '' /",
    "upper case": "&SCENE Title = 'x'\n  NODES = 9 /",
    "crlf and tabs": "&a\r\n\tx =\t1,\r\n\ty = 'z'\r\n/\r\n",
    "comments around": "! head\n&a ! after the name\n x = 1 ! trailing\n/ ! after\n! tail\n",
    "empty": "",
}


@pytest.mark.parametrize("text", PLAIN.values(), ids=PLAIN.keys())
def test_plain_forms_read_as_f90nml_reads_them(text):
    _same_as_f90nml(text)


OTHER = {
    "indexed": "&a x(2) = 1 /", "derived": "&a x%y = 1 /", "repeat count": "&a x = 3*1.0 /",
    "complex": "&a x = (1.0, 2.0) /", "null value": "&a x = , y = 1 /",
    "null in a list": "&a x = 1, , 2 /", "unquoted string": "&a x = abc /",
    "bare logical": "&a x = T /", "nan": "&a x = nan /", "key twice": "&a x = 1\n x = 2 /",
    "blank separated": "&a x = 1 2 /", "trailing comma": "&a x = 1, /",
    "outside a group": "x = 1\n&a y = 2 /", "end group": "&a x = 1\n&end",
    "dollar": "$a x = 1 $end", "unterminated group": "&a x = 1",
    "unterminated string": "&a x = 'abc\n/", "no value": "&a x = /",
}


@pytest.mark.parametrize("text", OTHER.values(), ids=OTHER.keys())
def test_other_forms_are_left_to_f90nml(text):
    assert fast_reads(text) is None


def test_a_scene_load_takes_the_fast_pass(monkeypatch):
    """load_scene reads a shipped scene without f90nml's parser, and its text (after the
    overrides) is the one f90nml's reading gives."""
    path = ROOT / "inputs/hard/pendulum.nml"
    overrides = ["beam.nodes=5", "beam.bending=cable", "solver.dt=0.001"]
    fast = load_scene(path, overrides)
    calls = []
    real = f90nml.reads

    def counted(text):
        calls.append(text)
        return real(text)
    monkeypatch.setattr(f90nml, "reads", counted)
    load_scene(path, overrides)
    assert calls == []
    import ancfdrv.io.scene as scene_module
    monkeypatch.setattr(scene_module, "fast_reads", lambda text: None)
    slow = load_scene(path, overrides)
    assert len(calls) == 1
    assert fast.text == slow.text and fast.values == slow.values


@pytest.mark.parametrize("name, overrides", [
    ("inputs/hard/pendulum.nml", ["beam.nodes=7", "solver.dt=0.002"]),
    ("inputs/general/cardan_shaft.nml", [])])
def test_the_scene_text_is_written_at_its_first_read(name, overrides):
    """load_scene hands the Scene its namelist's writer, run at the first read of
    ``text`` (a run kept in memory that saves no file never writes it); the text is
    f90nml's writing of f90nml's reading of the file with the overrides set, and the same
    after a copy (dataclasses.replace) and a pickle."""
    import dataclasses
    import pickle
    scene = load_scene(ROOT / name, overrides)
    assert callable(scene.__dict__["_text"])            # not written yet
    copied = pickle.loads(pickle.dumps(scene))
    reference = f90nml.read(ROOT / name)
    for item in overrides:
        address, value = item.split("=")
        group, key = address.split(".")
        reference[group][key] = f90nml.reads(f"&x v = {value} /")["x"]["v"]
    text = scene.text
    assert text == _written(reference) and isinstance(scene.__dict__["_text"], str)
    assert scene.text is text                            # written once
    assert copied.text == text and dataclasses.replace(scene, overrides=[]).text == text
