"""`ancf sweep` of every analysis kind and its references (issue 35, item 3): modal and
buckling sweeps tabulate their headline (first elastic frequency, first load factor) and the
error against the finest case; `--reference` is read and checked before the first case runs
(a readable ancfdrv result, status ok, the cases' analysis, the same model: title, kind of
scene, bodies, probes, compared probe); a relative error against a deflection that is zero
to round-off is n/a with a note naming the probe, never a huge number with status ok.

The models are a 2 m steel cantilever of 3 to 5 nodes (cubic bending): the numbers are
checked against runs of the same cases outside the sweep and against Euler's column and
the loaded cantilever's first frequency."""
from __future__ import annotations

import csv
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv.cli import main
from ancfdrv.errors import InputError
from ancfdrv.runner import run_scene
from ancfdrv.sweep import ZERO_DEFLECTION, run_sweep

COLUMN = """
&scene  title = 'steel column', analysis = '{analysis}', formulation = 'nonlinear' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&beam  name = '{beam}', material = 'steel', start = 0, 0, 0, end = 2.0, 0, 0, nodes = 5,
       section = 'rectangle', width = 0.02, height = 0.03, height_axis = 0, 1, 0,
       bending = 'cubic' /
&joint  name = 'root', type = 'weld', body1 = 'ground', body2 = '{beam}', point = 0, 0, 0 /
&load  name = 'push', type = 'force', body = '{beam}', point = 2.0, 0, 0,
       vector = {push}, 0, 0 /
&probe  name = 'tip', body = '{beam}', point = 2.0, 0, 0 /
&probe  name = 'root', body = '{beam}', point = 0, 0, 0 /
&modal  modes = 3 /
&buckling  modes = 2, method = 'linear' /
&solver  static_method = 'newton' /
"""
EI = 2.1e11 * 0.03 * 0.02**3 / 12  # bending about the weak axis (N m^2)
EULER = np.pi**2 * EI / (4 * 2.0**2)  # clamped-free column (N)
NODES = ["beam.nodes=3,4,5"]


def scene(tmp_path: Path, analysis: str, *, beam: str = "arm", push: float = -100.0,
          title: str | None = None, name: str | None = None) -> Path:
    text = COLUMN.format(analysis=analysis, beam=beam, push=push)
    if title is not None:
        text = text.replace("'steel column'", repr(title))
    path = tmp_path / (name or f"{analysis}.nml")
    path.write_text(text)
    return path


def rows_of(path: Path) -> dict[str, dict]:
    return {r["case"]: r for r in csv.DictReader(open(path))}


def values(path: str | Path, analysis: str) -> np.ndarray:
    with h5py.File(path, "r") as h5:
        return h5[f"{analysis}/{'frequency' if analysis == 'modal' else 'load_factor'}"][()]


# --- modal and buckling sweeps ----------------------------------------------------------

@pytest.mark.parametrize("analysis,headline", [("modal", "first_frequency_hz"),
                                               ("buckling", "first_load_factor")])
def test_eigen_sweep_tabulates_the_headline_and_the_error_against_the_finest(
        tmp_path, analysis, headline):
    # was: KeyError 'response' and no summary
    push = -100.0 if analysis == "modal" else -1000.0
    path = scene(tmp_path, analysis, push=push)
    out = tmp_path / "sweep"
    rows = run_sweep(str(path), NODES, out, workers=1, progress=False)
    assert [r["status"] for r in rows] == ["ok"] * 3
    finest = values(tmp_path / "sweep" / "nodes-5.h5", analysis)
    for row in rows:
        # the same case run outside the sweep (same machine, same computation)
        alone = tmp_path / f"alone-{row['beam.nodes']}.h5"
        run_scene(path, [f"beam.nodes={row['beam.nodes']}"], alone, progress=False)
        mine = values(alone, analysis)
        assert row[headline] == pytest.approx(mine[0], rel=1e-9)
        assert row["analysis"] == analysis and row["err_reference"] == "nodes-5"
        expected = np.max(np.abs(mine - finest) / finest)  # every eigenvalue, ascending
        assert row["err_vs_finest"] == pytest.approx(expected, rel=1e-6, abs=1e-12)
    assert rows[2]["err_vs_finest"] == 0.0 and rows[0]["err_vs_finest"] > 0
    if analysis == "buckling":  # Euler's column: P_cr = pi^2 EI / (4 L^2)
        assert rows[2][headline] * 1000.0 == pytest.approx(EULER, rel=1e-3)
    else:  # Galef (1968): f^2 = f0^2 (1 - P/P_cr), within ~0.3 % at this load
        f0 = 1.875104069**2 / (2 * np.pi * 4.0) * np.sqrt(EI / (7850 * 6e-4))
        assert rows[2][headline] == pytest.approx(f0 * np.sqrt(1 - 100 / EULER), rel=3e-3)
    table = (out / "summary.md").read_text()
    label = "f1 (Hz)" if analysis == "modal" else "load factor 1"
    assert f"| beam.nodes | {label} | err vs finest |" in table
    assert "largest relative difference" in table
    assert "err vs finest: reference nodes-5 (the finest case)" in table
    csv_rows = rows_of(out / "summary.csv")
    assert float(csv_rows["nodes-3"][headline]) == pytest.approx(rows[0][headline], rel=1e-12)
    assert (out / "error_vs_time.png").stat().st_size > 0


def test_modal_sweep_against_a_reference(tmp_path):
    path = scene(tmp_path, "modal")
    reference = tmp_path / "fine.h5"
    run_scene(path, ["beam.nodes=7"], reference, progress=False)
    rows = run_sweep(str(path), ["beam.nodes=3,5"], tmp_path / "s", workers=1,
                     progress=False, reference=reference)
    ref = values(reference, "modal")
    for row in rows:
        mine = values(row["file"], "modal")
        assert row["err_vs_reference"] == pytest.approx(np.max(np.abs(mine - ref) / ref),
                                                        rel=1e-6)
        assert row["err_reference_file"] == str(reference)
    assert "err vs reference" in (tmp_path / "s" / "summary.md").read_text()


# --- --reference refused before the first case ----------------------------------------

def refused(tmp_path, capsys, scene_path: Path, reference: Path, *words: str,
            extra: tuple[str, ...] = ()) -> None:
    """exit 2, a message naming the reference file and the mismatch, and nothing run."""
    out = tmp_path / "refused"
    code = main(["sweep", str(scene_path), "--vary", "beam.nodes=3,4", "-o", str(out),
                 "--workers", "1", "--reference", str(reference), *extra])
    err = capsys.readouterr().err
    assert code == 2, err
    assert str(reference) in err and "--reference" in err
    for word in words:
        assert word in err, err
    assert not out.exists()  # checked before the first case: no directory, no case file


@pytest.fixture
def modal_scene(tmp_path):
    return scene(tmp_path, "modal")


@pytest.fixture
def good_modal(tmp_path, modal_scene):
    path = tmp_path / "good.h5"
    run_scene(modal_scene, ["beam.nodes=5"], path, progress=False)
    return path


def test_reference_that_is_not_a_result_file_is_refused(tmp_path, capsys, modal_scene):
    text = tmp_path / "notes.txt"
    text.write_text("frequencies: 1, 2, 3\n")
    refused(tmp_path, capsys, modal_scene, text, "not an HDF5 file")
    passwd = Path("/etc/passwd")
    if passwd.is_file():
        refused(tmp_path, capsys, modal_scene, passwd, "not an HDF5 file")
    refused(tmp_path, capsys, modal_scene, tmp_path / "missing.h5", "no such result file")
    empty = tmp_path / "empty.h5"
    h5py.File(empty, "w").close()  # HDF5, but not written by a run
    refused(tmp_path, capsys, modal_scene, empty, "not an ancfdrv result file")


def test_truncated_reference_is_refused(tmp_path, capsys, modal_scene, good_modal):
    cut = tmp_path / "cut.h5"
    data = good_modal.read_bytes()
    cut.write_bytes(data[:len(data) // 2])
    refused(tmp_path, capsys, modal_scene, cut, "--reference", "truncated")


def test_reference_of_a_failed_run_is_refused(tmp_path, capsys, modal_scene, good_modal):
    failed = tmp_path / "failed.h5"
    shutil.copy(good_modal, failed)
    with h5py.File(failed, "a") as h5:
        h5.attrs["status"] = "failed"
        h5.attrs["message"] = "Newton did not converge"
    refused(tmp_path, capsys, modal_scene, failed, "did not succeed", "'failed'",
            "Newton did not converge")


def test_reference_of_another_analysis_is_refused(tmp_path, capsys, modal_scene):
    static = tmp_path / "static.h5"
    run_scene(modal_scene, ["scene.analysis=static"], static, progress=False)
    refused(tmp_path, capsys, modal_scene, static,
            "a static result, but the sweep's cases are modal runs")
    buckling = tmp_path / "buckling.h5"
    run_scene(modal_scene, ["scene.analysis=buckling"], buckling, progress=False)
    refused(tmp_path, capsys, modal_scene, buckling,
            "a buckling result, but the sweep's cases are modal runs")


def test_reference_of_another_model_is_refused(tmp_path, capsys, modal_scene):
    other_title = scene(tmp_path, "modal", title="crane jib", name="jib.nml")
    jib = tmp_path / "jib.h5"
    run_scene(other_title, [], jib, progress=False)
    refused(tmp_path, capsys, modal_scene, jib, "run of another model",
            "its title is 'crane jib'")
    renamed = scene(tmp_path, "modal", beam="boom", name="renamed.nml")
    boom = tmp_path / "boom.h5"
    run_scene(renamed, [], boom, progress=False)
    refused(tmp_path, capsys, modal_scene, boom, "run of another model",
            "its bodies are boom, the sweep's arm")
    template = tmp_path / "template.h5"  # a template scene of the same title: another kind
    static = scene(tmp_path, "static", name="static.nml")
    boom_static = Path(__file__).resolve().parents[1] / "inputs" / "cantilever.nml"
    run_scene(boom_static, ["scene.title=steel column"], template, progress=False)
    refused(tmp_path, capsys, static, template, "run of another model",
            "it is a 'cantilever' scene, the sweep's a 'general'")


def test_static_reference_comparing_another_probe_is_refused(tmp_path, capsys):
    # the sweep names its response (tip, transverse); the reference compared tip, lateral.
    # (A sweep that names none compares what moves most in the reference itself:
    # test_a_reference_without_a_named_response_gives_the_compared_probe.)
    static = scene(tmp_path, "static")
    lateral = tmp_path / "lateral.h5"
    run_scene(static, ["scene.response=tip", "scene.response_component=2"], lateral,
              progress=False)
    refused(tmp_path, capsys, static, lateral, "compares probe 'tip' component 2",
            "the sweep probe 'tip' component 1",
            extra=("--set", "scene.response=tip", "--set", "scene.response_component=1"))


def test_reference_when_the_cases_run_different_analyses_is_refused(tmp_path, capsys,
                                                                   modal_scene, good_modal):
    refused(tmp_path, capsys, modal_scene, good_modal, "different analyses",
            extra=("--vary", "scene.analysis=modal,buckling"))


def test_api_refuses_the_reference_before_any_case(tmp_path, modal_scene):
    text = tmp_path / "ref.h5"
    text.write_text("not a result\n")
    with pytest.raises(InputError, match="ref.h5: --reference: not an HDF5 file"):
        run_sweep(str(modal_scene), NODES, tmp_path / "s", workers=1, progress=False,
                  reference=text)
    assert not (tmp_path / "s").exists()


# --- a deflection that is zero by construction -----------------------------------------

def test_error_against_a_zero_deflection_is_undefined_not_huge(tmp_path):
    # the lateral (r3) deflection of a cantilever pushed along its axis and loaded in its
    # r1-r2 plane is zero by construction: the finest case's is round-off (~1e-20 m); the
    # relative error against it was 'err vs finest 2.52e+23', status ok
    static = scene(tmp_path, "static")
    base = ["scene.response=tip", "scene.response_component=2",
            "load[push].vector=-100,-50,0"]
    out = tmp_path / "s"
    rows = run_sweep(str(static), NODES, out, base=base, workers=1, progress=False)
    assert all(r["status"] == "ok" for r in rows)
    for row in rows:
        assert abs(row["response"]) <= ZERO_DEFLECTION * 2.0  # zero to round-off
        assert "err_vs_finest" not in row
        assert "probe 'tip'" in row["err_vs_finest_undefined"]
        assert "zero to round-off" in row["err_vs_finest_undefined"]
        assert row["err_abs_vs_finest"] <= ZERO_DEFLECTION * 2.0  # the absolute error stays
    table = (out / "summary.md").read_text()
    assert table.count("| n/a |") == 3
    assert "n/a: err vs finest of nodes-3, nodes-4, nodes-5: undefined: the reference " \
           "deflection of probe 'tip' is zero to round-off" in table
    for row in rows_of(out / "summary.csv").values():  # no number, the reason instead
        assert row.get("err_vs_finest", "") == ""
        assert "zero to round-off" in row["err_vs_finest_undefined"]
    # the transverse sag of the same cases is not zero: a relative error as before
    sag = run_sweep(str(static), NODES, tmp_path / "sag", base=base[2:], workers=1,
                    progress=False)
    assert [r["err_vs_finest"] > 0 for r in sag] == [True, True, False]
    assert all("err_vs_finest_undefined" not in r for r in sag)
    # and the note names the probe and component that do move (the sag: component 1, by
    # as much as the sag sweep's finest case reads), as the keys that would compare them
    moving = f"probe 'tip' moves {1e3 * abs(sag[2]['tip_transverse']):.4g} mm along its component 1"
    assert moving in rows[0]["err_vs_finest_undefined"]
    assert "&scene response = 'tip', response_component = 1" in table


def test_response_probe_is_the_scenes_not_a_probe_called_tip(tmp_path):
    # scene.response = 'root' (the clamped end: zero deflection) with a probe named 'tip'
    # in the scene: the sweep compares the root, and its error is n/a
    static = scene(tmp_path, "static")
    rows = run_sweep(str(static), ["beam.nodes=3,4"], tmp_path / "s",
                     base=["scene.response=root"], workers=1, progress=False)
    with h5py.File(rows[0]["file"]) as h5:
        root = h5["static/deflection_support/root"][1]
    assert rows[0]["response"] == root and "tip_transverse" not in rows[0]
    assert "probe 'root'" in rows[0]["err_vs_finest_undefined"]


def test_static_reference_of_zero_deflection_is_undefined(tmp_path):
    static = scene(tmp_path, "static")
    base = ["scene.response=tip", "scene.response_component=2"]
    reference = tmp_path / "ref.h5"
    run_scene(static, base + ["beam.nodes=7"], reference, progress=False)
    rows = run_sweep(str(static), ["beam.nodes=3,4"], tmp_path / "s", base=base, workers=1,
                     progress=False, reference=reference)
    for row in rows:
        assert "err_vs_reference" not in row
        assert "probe 'tip' is zero to round-off" in row["err_vs_reference_undefined"]
    assert "n/a: err vs reference of nodes-3, nodes-4" in \
        (tmp_path / "s" / "summary.md").read_text()


def test_reference_of_another_formulation_and_element_kind_is_accepted(tmp_path):
    # what resolves or approximates the model may differ (benchmarks/accuracy_chart.py: a
    # planar cable boom against the nonlinear cubic beam): the boom is the same model
    from ancfdrv.io.scene import load_scene
    from ancfdrv.sweep import load_reference
    boom = Path(__file__).resolve().parents[1] / "inputs" / "boom_static.nml"
    reference = tmp_path / "ref.h5"
    run_scene(boom, ["beam.nodes=7", "scene.formulation=nonlinear", "beam.bending=cubic",
                     "solver.static_method=newton"], reference, progress=False)
    cable = load_scene(boom, ["beam.bending=cable", "scene.planar=xy", "beam.nodes=4",
                              "scene.formulation=nonlinear", "solver.static_method=newton"])
    loaded = load_reference(reference, cable, {"static"})
    with h5py.File(reference) as h5:
        assert loaded.values[0] == h5["static/deflection/tip"][1]
        assert loaded.length_scale == h5["model"].attrs["length_scale"] > 0
    assert loaded.family == "static" and loaded.probe == "tip"


# --- the default response of a general scene: a quantity that moves ----------------------

def test_without_a_named_response_the_sweep_compares_what_moves(tmp_path, capsys):
    # the column pushed along its axis and sideways (-100, -50, 0 N) with the clamped
    # 'root' probe first: the files' own default (the first probe) is zero by construction;
    # the sweep compares instead what moves most in its first case, the tip's transverse
    # sag (14 mm, far above its axial shortening), and says so
    text = COLUMN.format(analysis="static", beam="arm", push=-100.0).replace(
        "vector = -100.0, 0, 0", "vector = -100.0, -50.0, 0")
    first, second = ("&probe  name = 'tip', body = 'arm', point = 2.0, 0, 0 /",
                     "&probe  name = 'root', body = 'arm', point = 0, 0, 0 /")
    path = tmp_path / "root_first.nml"
    path.write_text(text.replace(first, "@").replace(second, first).replace("@", second))
    out = tmp_path / "s"
    assert main(["sweep", str(path), "--vary", "beam.nodes=3,4", "-o", str(out),
                 "--workers", "1"]) == 0
    printed = capsys.readouterr().out
    rows = rows_of(out / "summary.csv")
    why = ("compared: probe 'tip' component 1, picked because no &scene response is named: "
           "of every probe's deflection components it moves most in case nodes-3")
    assert why in printed and why in (out / "summary.md").read_text()
    for case, row in rows.items():
        with h5py.File(out / f"{case}.h5", "r") as h5:
            assert h5.attrs["response_probe"] == "root"           # the file's own default
            sag = h5["static/deflection_support/tip"][1]
        assert (row["response_probe"], row["response_component"]) == ("tip", "1")
        assert float(row["tip_transverse"]) == pytest.approx(sag, rel=1e-12)
        assert why in row["response_picked"]
    # the beam-column's tip deflection F (tan kL - kL) / (k^3 EI), k^2 = P / EI (strong axis)
    ei, k = 2.1e11 * 0.02 * 0.03**3 / 12, np.sqrt(100.0 / (2.1e11 * 0.02 * 0.03**3 / 12))
    beam_column = 50.0 * (np.tan(2 * k) - 2 * k) / (k**3 * ei)
    assert float(rows["nodes-4"]["tip_transverse"]) == pytest.approx(-beam_column, rel=1e-3)
    assert float(rows["nodes-3"]["err_vs_finest"]) > 0.0       # a number, not n/a
    # a response the user names is compared as named: zero by construction, it stays n/a
    # with the hint naming what moves, and nothing is picked
    named = run_sweep(str(path), ["beam.nodes=3,4"], tmp_path / "named", workers=1,
                      progress=False, base=["scene.response=root"])
    for row in named:
        assert "response_picked" not in row and "tip_transverse" not in row
        assert "probe 'root'" in row["err_vs_finest_undefined"]
        assert "compare it with &scene response = 'tip', response_component = 1" in \
            row["err_vs_finest_undefined"]


def test_a_dynamic_sweep_picks_the_probe_whose_history_moves_most(tmp_path):
    # a rod released at 10 degrees on a pin: its 'top' probe (at the pin, the first) stays,
    # its 'end' swings; the picked component is the one with the largest range over the run
    from ancfdrv.sweep import pick_response
    scene_file = tmp_path / "rod.nml"
    scene_file.write_text("""
&scene  title = 'rod on a pin', analysis = 'dynamic', formulation = 'nonlinear',
        effects = 'gravity', planar = 'xy' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&cable  name = 'rod', material = 'steel', start = 0, 0, 0, end = 0.17364817766693033,
        -0.984807753012208, 0, nodes = 3, section = 'circle', diameter = 0.02 /
&joint  name = 'pin', type = 'spherical', body1 = 'ground', body2 = 'rod', point = 0, 0, 0 /
&load  name = 'g', type = 'gravity', vector = 0.0, -9.81, 0.0 /
&probe  name = 'top', body = 'rod', point = 0, 0, 0 /
&probe  name = 'end', body = 'rod', point = 0.17364817766693033, -0.984807753012208, 0 /
&solver  dt = 5e-3, t_end = 0.3 /
""")
    out = tmp_path / "s"
    rows = run_sweep(str(scene_file), ["solver.dt=5e-3,2.5e-3"], out, workers=1,
                     progress=False)
    with h5py.File(rows[0]["file"], "r") as h5:
        assert h5.attrs["response_probe"] == "top"
        end = h5["dynamic/deflection/end"][()]
    ranges = np.ptp(end, axis=0)
    component = int(np.argmax(ranges))
    (probe, picked), why = pick_response(rows[0]["file"], "case x")
    assert (probe, picked) == ("end", component) and component == 0  # swings along x first
    assert f"({1e3 * ranges[0]:.4g} mm, its range over the run)" in why
    assert all((r["response_probe"], r["response_component"]) == ("end", 0) for r in rows)
    assert rows[0]["err_vs_finest"] > 0.0
    assert rows[1]["err_vs_finest"] == 0.0      # the finest case against itself


def test_a_reference_without_a_named_response_gives_the_compared_probe(tmp_path):
    # no response named: the sweep compares what moves most in --reference (the tip's
    # sag under the sideways push), whatever the reference's file compared itself
    static = scene(tmp_path, "static")
    push = ["load[push].vector=-100,-50,0"]
    reference = tmp_path / "ref.h5"
    run_scene(static, push + ["scene.response=tip", "scene.response_component=2",
                              "beam.nodes=7"], reference, progress=False)
    rows = run_sweep(str(static), ["beam.nodes=3,4"], tmp_path / "s", base=push, workers=1,
                     progress=False, reference=reference)
    with h5py.File(reference, "r") as h5:
        sag = h5["static/deflection_support/tip"][1]
    for row in rows:
        assert (row["response_probe"], row["response_component"]) == ("tip", 1)
        assert "moves most in the reference ref.h5" in row["response_picked"]
        assert row["err_vs_reference"] == pytest.approx(
            abs(row["tip_transverse"] - sag) / abs(sag), rel=1e-9)
