"""The scene reader's own pass over plain namelists and its quick checks.

References: f90nml's own ``Namelist()`` (its attributes) and ``reads`` (groups, cogroups,
written text) for every shipped scene, schema.coerce for the quick list check, the plain
rule for control characters in names."""
from __future__ import annotations

import pickle
from pathlib import Path

import f90nml
import numpy as np
import pytest

import ancfdrv
import ancfdrv.io.scene as scene_module
from ancfdrv.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
SCENES = sorted(p for d in ("inputs", "tests", "examples") for p in (ROOT / d).rglob("*.nml"))


def test_a_new_namelist_is_f90nml_s_new_namelist():
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


COGROUPS = "&b name = 'a', k = 1 /\n&B name = 'b' /\n&c /\n&b name = 'c' /"


@pytest.mark.parametrize("text", [p.read_text() for p in SCENES] + [COGROUPS],
                         ids=[str(p.relative_to(ROOT)) for p in SCENES] + ["cogroups"])
def test_fast_namelists_are_f90nml_s(text):
    """fast_reads against f90nml.reads: the same groups, cogroups, items and written
    text."""
    fast = scene_module.fast_reads(text)
    reference = f90nml.reads(text)
    assert fast is not None
    assert repr(fast) == repr(reference) and str(fast) == str(reference)
    assert fast._cogroups == reference._cogroups
    assert scene_module.namelist_text(fast) == scene_module.namelist_text(reference)


@pytest.mark.parametrize("path", SCENES, ids=lambda p: str(p.relative_to(ROOT)))
def test_group_names_as_f90nml_s_keys_view(path):
    """is_general and the group check read the keys' cogroup names: the names f90nml's
    keys and items views give, for every shipped scene (template or general, repeated
    groups included)."""
    nml = f90nml.read(path)
    names = list(map(scene_module._cogroup_name, dict.keys(nml)))
    assert names == [str(k) for k in nml.keys()] == [str(k) for k, _ in nml.items()]


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
