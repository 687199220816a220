"""A small call's fixed cost, third round (issue 23): the stepper's rows written into arrays
numpy made (``system_advance_into``, no zero-fill by f2py), the scene reader's Namelists
made without f90nml's __init__ and its groups read as the dicts' own items.

References: the old ways (``KernelSystem.ROWS_INTO``, ``scene.FAST_NAMELIST``,
``scene.FAST_ITEMS`` False): whole runs' series bit for bit, rows handed over full of NaN
and garbage counts (the kernel writes every entry), f90nml's own ``Namelist()`` (its
attributes), the namelists' texts and the typed values of every shipped scene."""
from __future__ import annotations

import pickle
from pathlib import Path

import f90nml
import numpy as np
import pytest

import ancfdrv
import ancfdrv.io.scene as scene_module
import ancfdrv.kernel as kernel
from ancfdrv.errors import InputError
from conftest import INPUTS

ROOT = Path(__file__).resolve().parents[1]
PENDULUM = ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy", "solver.dt=1e-3",
            "solver.t_end=0.2"]
SCENES = sorted(p for d in ("inputs", "tests", "examples") for p in (ROOT / d).rglob("*.nml"))


def _series(scene, overrides):
    sim = ancfdrv.simulate(INPUTS / scene, overrides, progress=False)
    assert sim.status == "ok"
    return {k: np.asarray(sim.series(k)) for k in sim.names}


@pytest.mark.parametrize("scene, overrides", [
    ("hard/pendulum.nml", PENDULUM),
    ("hard/spinup.nml", ["solver.t_end=0.05", "output.xdmf=.false.", "output.q=.true."]),
    ("boom_luffing.nml", ["solver.t_end=0.05", "output.xdmf=.false.",
                          "solver.step='adaptive'"]),
])
def test_rows_into_numpy_arrays_the_same_run(monkeypatch, scene, overrides):
    """The rows and statistics handed to system_advance_into full of NaN and -7 (what
    numpy.empty may hold): the run is bit for bit the run of system_advance, whose
    outputs f2py zero-filled."""
    calls = []
    real = kernel._kernel.system_advance_into

    def dirty(handle, h, state, counts, rows, stats, nsteps):
        rows[...] = np.nan
        stats[...] = -7
        calls.append(nsteps)
        return real(handle, h, state, counts, rows, stats, nsteps)
    monkeypatch.setattr(kernel._kernel, "system_advance_into", dirty)
    into = _series(scene, overrides)
    assert calls
    monkeypatch.setattr(kernel.KernelSystem, "ROWS_INTO", False)
    monkeypatch.setattr(kernel._kernel, "system_advance_into", None)   # not called
    fresh = _series(scene, overrides)
    assert into.keys() == fresh.keys()
    for key in into:
        assert into[key].dtype == fresh[key].dtype and \
            into[key].tobytes() == fresh[key].tobytes(), key


def test_a_new_namelist_is_f90nml_s_new_namelist(monkeypatch):
    made, reference = scene_module._new_namelist(), f90nml.Namelist()
    assert type(made) is f90nml.Namelist and len(made) == 0
    assert vars(made) == vars(reference) and repr(made) == repr(reference)
    other = scene_module._new_namelist()
    for key, value in vars(made).items():     # each dict its own, as __init__ makes them
        if isinstance(value, dict):
            assert value is not vars(other)[key]
    made["x"] = 1
    made.start_index["x"] = [1]
    assert "x" not in other and other.start_index == {} and made.start_index == {"x": [1]}
    assert pickle.loads(pickle.dumps(made)) == made
    monkeypatch.setattr(scene_module, "FAST_NAMELIST", False)
    assert vars(scene_module._new_namelist()) == vars(reference)


def _state(nml):
    """Everything of a namelist: each (group) Namelist's attributes and items, in order."""
    if isinstance(nml, f90nml.Namelist):
        return (type(nml).__name__, vars(nml),
                [(type(k).__name__, str(k), _state(v)) for k, v in dict.items(nml)])
    if isinstance(nml, list):
        return [_state(v) for v in nml]
    return type(nml).__name__, nml


COGROUPS = "&b name = 'a', k = 1 /\n&B name = 'b' /\n&c /\n&b name = 'c' /"


@pytest.mark.parametrize("text", [p.read_text() for p in SCENES] + [COGROUPS],
                         ids=[str(p.relative_to(ROOT)) for p in SCENES] + ["cogroups"])
def test_fast_namelists_are_f90nml_s(monkeypatch, text):
    """fast_reads with its own Namelists and group filing against f90nml's Namelist(),
    ``in`` and item setting (and f90nml.reads): the same groups, cogroups, attributes,
    items and written text."""
    fast = scene_module.fast_reads(text)
    monkeypatch.setattr(scene_module, "FAST_NAMELIST", False)
    slow = scene_module.fast_reads(text)
    reference = f90nml.reads(text)
    assert fast is not None and slow is not None
    assert _state(fast) == _state(slow)
    assert repr(fast) == repr(reference) and str(fast) == str(reference)
    assert fast._cogroups == reference._cogroups
    assert scene_module.namelist_text(fast) == scene_module.namelist_text(reference)


TEMPLATES = [p for p in sorted((ROOT / "inputs").rglob("*.nml"))
             if not scene_module.is_general(f90nml.read(p))]


@pytest.mark.parametrize("path", TEMPLATES, ids=lambda p: str(p.relative_to(ROOT)))
def test_template_values_read_as_the_dicts_items(monkeypatch, path):
    """load_scene's typed values, overrides and text with the groups read as the dicts'
    own items against f90nml's items views."""
    overrides = ["solver.dt=0.002", "output.xdmf=.false."]
    fast = scene_module.load_scene(path, overrides)
    monkeypatch.setattr(scene_module, "FAST_ITEMS", False)
    slow = scene_module.load_scene(path, overrides)
    assert list(fast.values) == list(slow.values)
    for group in fast.values:
        assert list(fast.values[group].items()) == list(slow.values[group].items())
        for key, value in fast.values[group].items():
            assert type(value) is type(slow.values[group][key])
    assert fast.text == slow.text


@pytest.mark.parametrize("text, message", [
    ("&scene title = 'x' /\n&beam lenght = 1.0 /\n&cantilever /", "unknown key"),
    ("&scene title = 'x' /\n&beam length = 'abc' /\n&cantilever /", "expected"),
    ("&scene title = 'x' /\n&beam length = -1.0 /\n&cantilever /", ""),
])
def test_refusals_unchanged(monkeypatch, tmp_path, text, message):
    """A bad key or value: the same InputError (text, group, key) both ways."""
    path = tmp_path / "bad.nml"
    path.write_text(text)
    found = []
    for fast in (True, False):
        monkeypatch.setattr(scene_module, "FAST_ITEMS", fast)
        monkeypatch.setattr(scene_module, "FAST_NAMELIST", fast)
        with pytest.raises(InputError) as caught:
            scene_module.load_scene(path)
        found.append(str(caught.value))
    assert found[0] == found[1] and message in found[0]


@pytest.mark.parametrize("path", SCENES, ids=lambda p: str(p.relative_to(ROOT)))
def test_group_names_as_f90nml_s_keys_view(monkeypatch, path):
    """is_general and the group check read the keys' cogroup names: the names f90nml's
    keys and items views give, the same answer for every shipped scene (template or
    general, repeated groups included)."""
    nml = f90nml.read(path)
    names = list(map(scene_module._cogroup_name, dict.keys(nml)))
    assert names == [str(k) for k in nml.keys()] == [str(k) for k, _ in nml.items()]
    fast = scene_module.is_general(nml)
    monkeypatch.setattr(scene_module, "FAST_ITEMS", False)
    assert scene_module.is_general(nml) == fast


def test_plain_float_lists_checked_as_coerce_checks_them():
    """checked_value takes a list of plain floats within the accepted magnitude at once:
    the same list coerce returns (new, the same floats), and every other list (ints, NaN,
    infinities, too large, numpy scalars, strings) still through coerce, with its
    message."""
    from ancfdrv.io import schema
    from ancfdrv.io.validate import MAX_MAGNITUDE
    spec = schema.Key("floats", [])
    where = dict(group="g", key="k")
    for raw in ([1.5, -2.0, 0.0], [], [MAX_MAGNITUDE, -MAX_MAGNITUDE], [1, 2.5],
                [np.float64(3.0), 1.0]):
        got = schema.checked_value(spec, raw, where)
        expected = schema.coerce("floats", raw, where)
        assert got == expected and got is not raw
        assert [type(x) for x in got] == [type(x) for x in expected] == [float] * len(raw)
    for raw in ([float("nan")], [1.0, float("inf")], [2 * MAX_MAGNITUDE], [1.0, "a"],
                [True]):
        with pytest.raises(InputError) as fast:
            schema.checked_value(spec, raw, where)
        with pytest.raises(InputError) as slow:
            schema.coerce("floats", raw, where)
        assert str(fast.value) == str(slow.value)


def test_control_characters_in_names_as_before():
    """A name with a character below 32 is refused, any other accepted (the rule
    ``any(ord(c) < 32 for c in name)``), for every character up to U+3000."""
    from ancfdrv.system.system import _CONTROL
    for code in range(0x3000):
        name = f"a{chr(code)}b"
        assert (_CONTROL.search(name) is not None) == any(ord(c) < 32 for c in name)
    s = ancfdrv.System()
    with pytest.raises(InputError, match="control characters"):
        s.material("st\teel", youngs_modulus=2e11, density=7850.0)


@pytest.mark.parametrize("value", [(1.0, 2.0, 3.0), (1.0, float("nan"), 0.0),
                                   (float("inf"), 0.0, 0.0), (1.0, 2.0), "abc"])
def test_points_checked_as_before(value):
    """A point or vector of three finite numbers is taken, anything else refused with the
    same message (the finite check by math.isfinite on the values)."""
    from ancfdrv.system.bodies import _vec
    from ancfdrv.system.loads import _vector
    try:
        v = np.asarray(value, dtype=float).ravel()
        ok = v.shape == (3,) and bool(np.all(np.isfinite(v)))
    except ValueError:
        ok = None
    for check in (lambda: _vec(value, "point", "x"), lambda: _vector(value, "vector")):
        if ok:
            assert check().tobytes() == v.tobytes()
        elif ok is None:
            with pytest.raises(ValueError):
                check()
        else:
            with pytest.raises(InputError, match="three finite numbers"):
                check()
