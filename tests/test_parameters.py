"""Scene parameters (issue 37 item 7, SPEC section 8.2): the expression parser on its own,
the &parameters and &point groups, --set and --vary of a parameter, the record in the result
file, and the knuckle crane written with parameters against its absolute-coordinate scene."""
from __future__ import annotations

import math
from pathlib import Path

import h5py
import numpy as np
import pytest

import ancfdrv  # noqa: F401  (registers the general-scene builder)
from ancfdrv.cli import main
from ancfdrv.errors import InputError
from ancfdrv.io.parameters import ExpressionError, evaluate
from ancfdrv.io.scene import load_scene
from ancfdrv.runner import run_scene
from ancfdrv.sweep import run_sweep

ROOT = Path(__file__).resolve().parents[1]
INPUTS = ROOT / "inputs"

# -- 1. the parser -----------------------------------------------------------------------------


@pytest.mark.parametrize("text, value", [
    ("1 + 2*3", 7.0),                 # * before +
    ("(1 + 2)*3", 9.0),
    ("8/2/2", 2.0),                   # / left-associative
    ("10 - 4 - 3", 3.0),              # - left-associative
    ("2**3**2", 512.0),               # ** right-associative: 2**(3**2)
    ("-2**2", -4.0),                  # ** binds tighter than a unary minus on its left
    ("2**-1", 0.5),                   # a unary minus in the exponent
    ("-(-3)", 3.0), ("+5", 5.0), ("--2", 2.0),
    ("2*3**2", 18.0),
    ("1.5e1 + .5 + 2.", 17.5), ("1.0d0 + 1D1", 11.0),   # Fortran's d exponent too
    ("sqrt(16) + abs(-3)", 7.0),
    ("sind(30)", 0.5), ("cosd(0)", 1.0), ("tand(45)", 1.0),
    ("sin(pi/6)", 0.5), ("cos(pi)", -1.0), ("tan(pi/4)", 1.0),
    ("$h + $L*sind($phi)", 2.0 + 4.0 * 0.5),
    ("$l*2", 8.0),                    # names are case-insensitive, as namelist keys
    ("  ( $h )  ", 2.0),
])
def test_expression_values(text, value):
    assert evaluate(text, {"h": 2.0, "l": 4.0, "phi": 30.0}) == pytest.approx(value,
                                                                             rel=1e-15)


@pytest.mark.parametrize("text, words", [
    ("__import__('os')", "unknown name '__import__'"),
    ("open", "unknown name 'open'"),
    ("exp(1)", "unknown name 'exp'"),
    ("$h.real", "found '.'"),
    ("lambda: 1", "unknown name 'lambda'"),
    ("[1]", "found '['"),
    ("1 if 1 else 2", "found 'if'"),
    ("sin 1", "expected '(' after the function sin"),
    ("abs(1, 2)", "expected ')', found ','"),
    ("(1 + 2", "expected ')', found the end"),
    ("1 2", "expected an operator, found '2'"),
    ("1 +", "found the end"),
    ("", "empty expression"),
    ("$x + 1", "unknown parameter $x (parameters: h)"),
    ("1/0", "division by zero"),
    ("1/($h - 2)", "division by zero"),
    ("sqrt(-1)", "sqrt of the negative number"),
    ("10**400", "overflows"),
    ("1e308*10", "not finite"),
    ("(-8)**(1/3)", "not a real number"),
    ("(" * 60 + "1" + ")" * 60, "nested more than"),
    ("-" * 60 + "1", "nested more than"),
])
def test_expression_refusals(text, words):
    with pytest.raises(ExpressionError) as info:
        evaluate(text, {"h": 2.0})
    assert words in str(info.value)


# -- 2. in a scene -----------------------------------------------------------------------------

#: a cantilever of length boom_length along x with a tip force: every point from parameters
CANTILEVER = """&parameters  boom_length = 2.0, force = 100.0 /
&parameters  half = '$boom_length/2' /
&point  name = 'tip', at = '$boom_length', 0.0, 0.0 /
&scene  title = 'cantilever', analysis = 'static', formulation = 'nonlinear',
        effects = 'point_loads', response = 'tip', response_component = 1 /
&material  name = 'steel', youngs_modulus = 2.0e11, density = 7850.0 /
&beam  name = 'arm', material = 'steel', start = 0.0, 0.0, 0.0, end = 'tip', nodes = 5,
       section = 'rectangle', width = 0.05, height = 0.05, height_axis = 0.0, 1.0, 0.0,
       bending = 'cubic' /
&joint  name = 'root', type = 'weld', body1 = 'ground', body2 = 'arm', point = 0, 0, 0 /
&load  name = 'f', type = 'force', body = 'arm', point = 'tip', vector = 0.0, '-$force', 0.0 /
&probe  name = 'tip', body = 'arm', point = 'tip' /
&probe  name = 'middle', body = 'arm', point = '$half', 0.0, 0.0 /
&solver  static_method = 'newton' /
"""


def _scene(tmp_path: Path, text: str = CANTILEVER, name: str = "cantilever.nml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _item(scene, group: str, name: str) -> dict:
    return next(v for g, v in scene.items if g == group and v["name"] == name)


def test_parameters_and_points_in_a_scene(tmp_path):
    """Expressions and point names give the values they stand for; --set of a parameter
    moves every key that uses it (the derived parameter and the point too)."""
    scene = load_scene(_scene(tmp_path))
    assert scene.parameters == {"boom_length": 2.0, "force": 100.0, "half": 1.0}
    assert _item(scene, "beam", "arm")["end"] == [2.0, 0.0, 0.0]
    assert _item(scene, "load", "f")["point"] == [2.0, 0.0, 0.0]
    assert _item(scene, "load", "f")["vector"] == [0.0, -100.0, 0.0]
    assert _item(scene, "probe", "middle")["point"] == [1.0, 0.0, 0.0]
    moved = load_scene(_scene(tmp_path), ["parameters.boom_length=3.5"])
    assert moved.parameters["half"] == 1.75
    for group, name in (("beam", "arm"), ("load", "f"), ("probe", "tip")):
        key = "end" if group == "beam" else "point"
        assert _item(moved, group, name)[key] == [3.5, 0.0, 0.0]
    assert _item(moved, "probe", "middle")["point"] == [1.75, 0.0, 0.0]
    # the text kept (what the file stores and a re-run reads) still holds the expressions
    assert "'$boom_length/2'" in moved.text and "&parameters" in moved.text


def test_the_file_stores_parameters_and_expressions(tmp_path):
    out = tmp_path / "out.h5"
    run_scene(_scene(tmp_path), ["parameters.force=200"], out, progress=False)
    with h5py.File(out) as h5:
        parameters = h5.attrs["parameters"].splitlines()
        expressions = h5.attrs["expressions"].splitlines()
        assert h5.attrs["overrides"] == "parameters.force=200"
    assert parameters == ["boom_length = 2.0", "force = 200.0", "half = 1.0"]
    assert "load[f].vector = 0.0, '-$force', 0.0 => 0.0, -200.0, 0.0" in expressions
    assert "probe[tip].point = 'tip' => 2.0, 0.0, 0.0" in expressions
    assert "probe[middle].point = '$half', 0.0, 0.0 => 1.0, 0.0, 0.0" in expressions
    assert "point[tip].at = '$boom_length', 0.0, 0.0 => 2.0, 0.0, 0.0" in expressions


def test_a_sweep_varies_a_parameter(tmp_path):
    """--vary parameters.boom_length: each case's beam, load and probe move together; the
    tip deflection follows the cantilever's P L^3 / (3 E I) (within 2e-3: the continuum
    beam's shear flexibility at L/h = 20 and 40, measured 1.2e-3 and 3e-4), so the two
    lengths' deflections are in the ratio 2^3 (2e-3)."""
    scene = _scene(tmp_path)
    rows = run_sweep(str(scene), ["parameters.boom_length=1.0,2.0"], tmp_path / "sweep",
                     workers=1, progress=False)
    assert [r["status"] for r in rows] == ["ok", "ok"]
    inertia = 0.05 ** 4 / 12.0
    for row, length in zip(rows, (1.0, 2.0)):
        with h5py.File(row["file"]) as h5:
            assert f"boom_length = {length!r}" in h5.attrs["parameters"].splitlines()
        assert row["tip_transverse"] == pytest.approx(
            -100.0 * length**3 / (3 * 2.0e11 * inertia), rel=2e-3)
    assert rows[1]["tip_transverse"] / rows[0]["tip_transverse"] == pytest.approx(8.0,
                                                                                rel=2e-3)


def test_a_sweep_refuses_an_unknown_parameter(tmp_path):
    with pytest.raises(InputError, match="no parameter 'length'"):
        run_sweep(str(_scene(tmp_path)), ["parameters.length=1.0,2.0"], tmp_path / "sweep",
                  workers=1, progress=False)


@pytest.mark.parametrize("edit, place, words", [
    (("'$boom_length/2'", "'$boom_lenght/2'"), "&parameters half",
     "expression '$boom_lenght/2': unknown parameter $boom_lenght"),
    (("'-$force'", "'-$force +'"), "&load[f] vector",
     "expression '-$force +': syntax error at character"),
    (("'$half', 0.0", "'$half/($force - 100)', 0.0"), "&probe[middle] point",
     "expression '$half/($force - 100)': division by zero"),
    (("'-$force'", "'-$force*1e308'"), "&load[f] vector",
     "expression '-$force*1e308': the value -inf is not finite"),
    (("at = '$boom_length'", "at = '$boom_length**1e4'"), "&point[tip] at",
     "expression '$boom_length**1e4': (2)**(10000) overflows"),
    (("'-$force'", "'__import__(\"os\")'"), "&load[f] vector", "unknown name '__import__'"),
    (("end = 'tip'", "end = 'top'"), "&beam[arm] end", "unknown point 'top' (named points: 'tip')"),
    (("half = '$boom_length/2'", "force = 3.0"), "&parameters force", "defined twice"),
    (("name = 'tip', at", "name = 'tip', at = 1, 2, 3 /\n&point name = 'tip', at"),
     "&point[tip] name", "used twice"),
    (("boom_length = 2.0", "boom_length = 'x'"), "&parameters boom_length",
     "unknown name 'x'"),
])
def test_bad_expressions_are_refused_with_the_place(tmp_path, capsys, edit, place, words):
    """Exit 2 and one line naming the file, the group, the key and the expression."""
    path = _scene(tmp_path, CANTILEVER.replace(*edit))
    code = main(["run", str(path), "-o", str(tmp_path / "out.h5")])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert "Traceback" not in err
    assert f"{path}: {place}: " in err and words in err
    assert not (tmp_path / "out.h5").exists()


@pytest.mark.parametrize("override, words", [
    ("parameters.lenght=2", "the scene defines no parameter 'lenght' (parameters: "
                            "boom_length, force, half)"),
    ("parameters.force=abc", "&parameters force"),
    ("parameters[x].force=1", "a parameter is addressed as parameters.NAME"),
])
def test_bad_parameter_overrides(tmp_path, override, words):
    with pytest.raises(InputError) as info:
        load_scene(_scene(tmp_path), [override])
    assert words in str(info.value)


def test_a_word_in_a_numeric_key_is_still_not_a_number(tmp_path):
    """A bare word is not an expression: the type's message, with the place."""
    text = CANTILEVER.replace("youngs_modulus = 2.0e11", "youngs_modulus = 'steel'")
    with pytest.raises(InputError, match=r"&material\[steel\] youngs_modulus: expected a "
                                         r"number, got 'steel'"):
        load_scene(_scene(tmp_path, text))


def test_an_integer_key_from_an_expression(tmp_path):
    scene = load_scene(_scene(tmp_path, CANTILEVER.replace("nodes = 5", "nodes = '2*2 + 1'")))
    assert _item(scene, "beam", "arm")["nodes"] == 5
    with pytest.raises(InputError, match=r"&beam\[arm\] nodes: expected an integer"):
        load_scene(_scene(tmp_path, CANTILEVER.replace("nodes = 5", "nodes = '9/2'")))


# -- 3. the knuckle crane ----------------------------------------------------------------------

def test_the_parametric_knuckle_crane_is_the_absolute_one(tmp_path):
    """inputs/knuckle_crane_rope_parametric.nml (every point from 15 dimensions) builds the
    scene of inputs/knuckle_crane_rope.nml (absolute coordinates): the same items to the
    last bit, and a static start with 10 dynamic steps gives the same datasets (within
    round-off of each dataset's scale; /timing aside)."""
    absolute = load_scene(INPUTS / "knuckle_crane_rope.nml")
    parametric = load_scene(INPUTS / "knuckle_crane_rope_parametric.nml")
    assert parametric.items == absolute.items
    assert parametric.parameters["stroke0"] == _item(absolute, "drive", "jib stroke")["start"]
    files = []
    for scene in ("knuckle_crane_rope.nml", "knuckle_crane_rope_parametric.nml"):
        out = tmp_path / scene.replace(".nml", ".h5")
        run_scene(INPUTS / scene, ["solver.t_end=0.05", "output.xdmf=.false."], out,
                  progress=False)
        files.append(out)
    with h5py.File(files[0]) as a, h5py.File(files[1]) as b:
        names: list[str] = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        others: list[str] = []
        b.visititems(lambda n, o: others.append(n) if isinstance(o, h5py.Dataset) else None)
        assert sorted(names) == sorted(others)
        assert "dynamic/probes/hook" in names and "static/probes/hook" in names
        compared = 0
        for name in names:
            if name.startswith("timing") or a[name].dtype.kind not in "fiu":
                continue
            x, y = np.asarray(a[name][()], float), np.asarray(b[name][()], float)
            scale = max(np.max(np.abs(x), initial=0.0), 1e-300)
            assert x.shape == y.shape, name
            assert np.max(np.abs(x - y), initial=0.0) <= 1e-12 * scale, name
            compared += 1
        assert compared > 50
        assert "boom_length = 4.0" in b.attrs["parameters"].splitlines()
        assert a.attrs["parameters"] == "" and a.attrs["expressions"] == ""


def test_expressions_degrees_against_radians():
    """sind/cosd/tand are sin/cos/tan of the angle in degrees (independent: math)."""
    for deg in (-170.0, -10.0, 0.0, 37.5, 90.0, 400.0):
        rad = math.radians(deg)
        assert evaluate(f"sind({deg})", {}) == pytest.approx(math.sin(rad), abs=1e-15)
        assert evaluate(f"cosd({deg})", {}) == pytest.approx(math.cos(rad), abs=1e-15)
        assert evaluate(f"cosd({deg})**2 + sind({deg})**2", {}) == pytest.approx(1.0,
                                                                                  abs=1e-15)


TEMPLATE = """&parameters  L = 2.0, side = 0.05, P = 100.0 /
&scene  title = 'cantilever', analysis = 'static', formulation = 'ffr', effects = 'tip_force' /
&beam  length = '$L', width = '$side', height = '$side', nodes = 9 /
&material  youngs_modulus = 2.1e11, density = 7850.0 /
&cantilever  clamp = 'section' /
&loads  tip_force = 0.0, '-$P', 0.0 /
&solver  static_method = 'newton' /
"""


def test_a_template_scene_takes_parameters(tmp_path):
    """Template scenes take &parameters too: the beam's length, section and the tip force
    from the parameters, --set moving each."""
    path = _scene(tmp_path, TEMPLATE, "template.nml")
    scene = load_scene(path, ["parameters.L=3.0", "parameters.side=0.04"])
    assert scene.kind == "cantilever"
    assert (scene["beam"]["length"], scene["beam"]["width"], scene["beam"]["height"]) == \
        (3.0, 0.04, 0.04)
    assert scene["loads"]["tip_force"] == [0.0, -100.0, 0.0]
    assert "beam.length = '$L' => 3.0" in scene.expressions


def test_a_sweep_of_the_parametric_crane_moves_its_boom(tmp_path):
    """`ancf sweep inputs/knuckle_crane_rope_parametric.nml --vary parameters.boom_length=
    3.9,4.0` (statics): each case's boom ends at boom_length from the pivot at 40 degrees
    with the jib hung from it (the knuckle joint at the boom's end), the 4.0 m case is the
    absolute-coordinate scene's static state (1e-12 of the hook's deflection), and the
    compared response, which the scene does not name, is the probe that moves most (the
    hook's vertical deflection), said in the table."""
    out = tmp_path / "sweep"
    assert main(["sweep", str(INPUTS / "knuckle_crane_rope_parametric.nml"), "--vary",
                 "parameters.boom_length=3.9,4.0", "--set", "scene.analysis=static",
                 "-o", str(out), "--workers", "1"]) == 0
    table = (out / "summary.md").read_text()
    assert "compared: probe 'hook' component 1, picked because no &scene response is named" \
        in table
    angle = math.radians(40.0)
    hooks = {}
    for length in (3.9, 4.0):
        with h5py.File(out / f"boom_length-{length}.h5", "r") as h5:
            points = h5["model/mesh/points"][()]
            parts = dict(line.split(": ", 1) for line in
                         str(h5["model/mesh"].attrs["bodies"]).splitlines())
            hooks[length] = h5["static/deflection/hook"][()]
        boom_end = int(parts["boom"].rpartition("..")[2])
        knuckle = int(parts["knuckle"].rpartition("..")[2])
        expected = [length * math.cos(angle), 2.0 + length * math.sin(angle), 0.0]
        np.testing.assert_allclose(points[boom_end], expected, rtol=0, atol=1e-12)
        np.testing.assert_allclose(points[knuckle], expected, rtol=0, atol=1e-12)
    absolute = tmp_path / "absolute.h5"
    run_scene(INPUTS / "knuckle_crane_rope.nml", ["scene.analysis=static"], absolute,
              progress=False)
    with h5py.File(absolute, "r") as h5:
        reference = h5["static/deflection/hook"][()]
    scale = np.abs(reference).max()
    np.testing.assert_allclose(hooks[4.0], reference, rtol=0, atol=1e-12 * scale)
    assert abs(hooks[3.9][1] - hooks[4.0][1]) > 1e-3 * scale   # the shorter boom: another state
