"""The ancf command: run/sweep/info/plot, HDF5 layout (SPEC section 4), and bad input
(exit 2 naming file, group and key) and solver failure (exit 3, file kept)."""
from __future__ import annotations

import csv
from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv.cli import main

BOOM = """
&scene title = 'test boom', analysis = 'static', formulation = 'ffr',
       effects = 'gravity', 'tip_mass', 'bending_moment' /
&beam length = 7.791, width = 0.1, height = 0.1, nodes = 10, segments = 1.791, 3.0, 3.0 /
&material youngs_modulus = 2.1e11, density = 7850.0 /
&boom angle_deg = 15 /
&loads tip_mass = 50.0, moment = 1000.0 /
&solver static_method = 'split' /
"""


def test_run_writes_spec_layout_and_plot(boom_scene, tmp_path, capsys):
    out = tmp_path / "boom.h5"
    code = main(["run", str(boom_scene), "-o", str(out), "--set", "beam.nodes=10",
                 "--set", "solver.static_method='newton'", "--set", "loads.tip_mass=50",
                 "--plot"])
    assert code == 0
    assert "tip" in capsys.readouterr().out
    with h5py.File(out) as h5:
        for key in ("ancfdrv_version", "created", "scene", "formulation", "effects"):
            assert key in h5.attrs
        assert "nodes = 10" in h5.attrs["scene"]
        assert h5["model"].attrs["ndof"] == 120 and h5["model"].attrs["nnodes"] == 10
        assert h5["model"].attrs["nconstraints"] == 7
        static = h5["static"]
        assert static["q"].shape == (120,) and static["lambda"].shape == (7,)
        assert static["probes/tip"].shape == (3,) and static["deflection/tip"].shape == (3,)
        assert static.attrs["method"] == "newton"
        for key in ("iterations", "residual_norm", "wall_time_s"):
            assert key in static.attrs
        assert static["deflection/tip"][1] < 0  # sags
        assert h5["counters"].attrs["gravity"] == 1
        assert h5["counters"].attrs["end_moment"] == 0
        assert {"assembly", "factorization", "solve", "contact", "output", "total"} <= set(
            h5["timing"].attrs)  # SPEC section 4
        assert h5["timing"].attrs["contact"] == 0.0
        assert h5.attrs["status"] == "ok"
    assert out.with_suffix(".png").stat().st_size > 1000
    assert main(["info", str(out)]) == 0
    assert "static.iterations" in capsys.readouterr().out
    png = tmp_path / "x.png"
    assert main(["plot", str(out), "-o", str(png)]) == 0 and png.exists()


def test_sweep_table_errors_and_plots(write_scene, tmp_path, capsys):
    scene = write_scene(BOOM)
    out = tmp_path / "sweep"
    code = main(["sweep", str(scene), "--vary", "boom.angle_deg=0,30", "--vary",
                 "beam.nodes=4,10", "-o", str(out), "--workers", "2"])
    assert code == 0
    rows = list(csv.DictReader(open(out / "summary.csv")))
    assert len(rows) == 4 and all(r["status"] == "ok" for r in rows)
    fine = [r for r in rows if r["beam.nodes"] == "10"]
    assert all(float(r["err_vs_finest"]) == 0 for r in fine)
    coarse = [r for r in rows if r["beam.nodes"] == "4"]
    assert all(float(r["err_vs_closed_form"]) > float(f["err_vs_closed_form"])
               for r, f in zip(coarse, fine))
    assert (out / "summary.md").read_text().count("|") > 20
    assert (out / "tip_deflection.png").exists() and (out / "error_vs_time.png").exists()
    assert len(list(out.glob("*.h5"))) == 4
    assert "err vs closed form" in capsys.readouterr().out


def expect_input_error(args, capsys, *fragments):
    assert main(args) == 2
    err = capsys.readouterr().err
    for fragment in fragments:
        assert fragment in err, err
    return err


def test_unknown_group(write_scene, capsys):
    path = write_scene(BOOM + "&wind speed = 3.0 /\n")
    expect_input_error(["run", str(path)], capsys, str(path), "&wind", "unknown group")


def test_unknown_key(write_scene, capsys):
    path = write_scene(BOOM.replace("angle_deg = 15", "angle_deg = 15, angel = 3"))
    expect_input_error(["run", str(path)], capsys, str(path), "&boom angel", "unknown key")


def test_unknown_override_key(boom_scene, capsys):
    expect_input_error(["run", str(boom_scene), "--set", "beam.nodez=10"], capsys,
                       "&beam nodez", "unknown key")


def test_nodes_not_3k_plus_1(write_scene, capsys):
    path = write_scene(BOOM.replace("nodes = 10", "nodes = 12"))
    expect_input_error(["run", str(path)], capsys, str(path), "&beam nodes", "3j+1")


@pytest.mark.parametrize("group,key,text,bad", [
    ("material", "youngs_modulus", "youngs_modulus = 2.1e11", "youngs_modulus = -2.1e11"),
    ("material", "density", "density = 7850.0", "density = 0.0"),
    ("beam", "width", "width = 0.1", "width = 0.0"),
    ("beam", "height", "height = 0.1", "height = -0.1"),
    ("beam", "length", "length = 7.791", "length = -7.791"),
])
def test_non_physical_values(write_scene, capsys, group, key, text, bad):
    path = write_scene(BOOM.replace(text, bad, 1))
    expect_input_error(["run", str(path)], capsys, str(path), f"&{group} {key}")


def test_missing_file(tmp_path, capsys):
    missing = tmp_path / "nope.nml"
    expect_input_error(["run", str(missing)], capsys, str(missing), "not found")
    expect_input_error(["info", str(tmp_path / "nope.h5")], capsys, "not found")


def test_missing_required_key(write_scene, capsys):
    path = write_scene(BOOM.replace("density = 7850.0", ""))
    expect_input_error(["run", str(path)], capsys, "&material density", "required")


def test_wrong_size_and_type(write_scene, capsys):
    path = write_scene(BOOM.replace("moment = 1000.0", "moment = 1000.0, tip_force = 1, 2"))
    expect_input_error(["run", str(path)], capsys, "&loads tip_force", "expected 3 values")
    path = write_scene(BOOM.replace("nodes = 10", "nodes = 'ten'"), "b.nml")
    expect_input_error(["run", str(path)], capsys, "&beam nodes", "integer")


def test_unknown_effect_and_formulation_conflicts(write_scene, capsys):
    path = write_scene(BOOM.replace("'bending_moment'", "'wind'"))
    expect_input_error(["run", str(path)], capsys, "&scene effects", "unknown effect 'wind'")
    nonlinear = BOOM.replace("formulation = 'ffr'", "formulation = 'nonlinear'")
    path = write_scene(nonlinear, "d.nml")
    expect_input_error(["run", str(path)], capsys, "&solver static_method", "needs")
    path = write_scene(nonlinear.replace("static_method = 'split'", "static_method = 'newton', "
                                         "integrator = 'rk4'"), "e.nml")
    expect_input_error(["run", str(path)], capsys, "&solver integrator", "must be one of")


def test_solver_failure_exit_3_keeps_file(write_scene, tmp_path, capsys):
    path = write_scene(BOOM.replace("static_method = 'split'",
                                    "static_method = 'newton', max_iter = 1, tol = 1e-14"))
    out = tmp_path / "fail.h5"
    assert main(["run", str(path), "-o", str(out)]) == 3
    err = capsys.readouterr().err
    assert "did not converge in 1 iterations" in err
    with h5py.File(out) as h5:
        assert h5.attrs["status"] == "failed"
        assert "did not converge" in h5.attrs["message"]
        assert h5["model"].attrs["ndof"] == 120
        assert h5["counters"].attrs["factorizations"] == 1  # the one iteration it made


def test_override_strings_with_or_without_quotes(boom_scene, tmp_path):
    for value in ("newton", "'newton'", '"newton"'):
        out = tmp_path / "q.h5"
        assert main(["run", str(boom_scene), "-o", str(out), "--set", "beam.nodes=4",
                     "--set", f"solver.static_method={value}"]) == 0
        with h5py.File(out) as h5:
            assert h5["static"].attrs["method"] == "newton"


LUFFING_SHORT = ["solver.t_end=8.0", "solver.dt=2e-3"]  # 1.8 s of vibration


def test_dynamic_sweep_reports_amplitude_and_phase_errors(tmp_path, capsys):
    from conftest import INPUTS
    out = tmp_path / "dyn"
    code = main(["sweep", str(INPUTS / "boom_luffing.nml"), "--vary", "beam.nodes=4,10",
                 *sum((["--set", s] for s in LUFFING_SHORT), []), "-o", str(out)])
    assert code == 0
    rows = {r["beam.nodes"]: r for r in csv.DictReader(open(out / "summary.csv"))}
    assert float(rows["10"]["err_vs_finest"]) == 0.0
    assert float(rows["4"]["err_vs_finest"]) > 0.1  # 4 nodes clearly differ
    assert abs(float(rows["4"]["phase_err_deg"])) > 10
    assert int(rows["4"]["steps"]) == 4000 and int(rows["4"]["factorizations"]) == 1
    assert (out / "histories.png").exists() and (out / "error_vs_time.png").exists()
    assert "phase err (deg)" in capsys.readouterr().out


def test_sweep_on_a_dask_scheduler(write_scene, tmp_path):
    """--scheduler sends the cases to a Dask distributed scheduler (here an in-process
    LocalCluster); the results equal those of the local process pool."""
    distributed = pytest.importorskip("distributed")
    from ancfdrv.sweep import run_sweep
    scene = str(write_scene(BOOM))
    vary = ["beam.nodes=4,10"]
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        remote = run_sweep(scene, vary, tmp_path / "dask", scheduler=cluster.scheduler_address,
                           progress=False)
    local = run_sweep(scene, vary, tmp_path / "local", workers=1, progress=False)
    assert [r["status"] for r in remote] == ["ok", "ok"]
    for a, b in zip(remote, local):
        assert a["tip_transverse"] == pytest.approx(b["tip_transverse"], rel=1e-12)


def test_sweep_compares_formulations_side_by_side(tmp_path):
    """--vary scene.formulation=ffr,nonlinear: each case's difference from the
    large-deformation model with the same other keys (a luffing history here)."""
    from conftest import INPUTS
    out = tmp_path / "side"
    code = main(["sweep", str(INPUTS / "boom_luffing.nml"), "--vary",
                 "scene.formulation=ffr,nonlinear", "--set", "beam.nodes=4", "--set",
                 "solver.static_method=newton", "--set", "solver.t_end=2.0", "--set",
                 "solver.dt=2e-3", "-o", str(out), "--workers", "1"])
    assert code == 0
    rows = {r["scene.formulation"]: r for r in csv.DictReader(open(out / "summary.csv"))}
    assert float(rows["nonlinear"]["diff_vs_nonlinear"]) == 0.0
    assert 1e-4 < float(rows["ffr"]["diff_vs_nonlinear"]) < 0.2
    # refactorizable, but reused across steps (jacobian = 'reuse'; 'step' made 1000) and
    # carried with the boom's luffing turn (solver.carry: one matrix serves the run; 13
    # without the carry)
    assert 1 <= int(rows["nonlinear"]["factorizations"]) < 50
    assert int(rows["ffr"]["factorizations"]) == 1  # one per run


@pytest.mark.parametrize("line", [
    ["run", "scene.nml", "-o", "out.h5", "--set", "beam.nodes=4", "--set", "solver.dt=2e-3",
     "--plot"],
    ["--debug", "run", "scene.nml", "--force"],
    ["sweep", "s.nml", "--vary", "beam.nodes=4,7", "--workers", "2", "--reference", "r.h5"],
    ["info", "out.h5", "--json"], ["plot", "a.h5", "b.h5", "-o", "c.png"],
    ["show", "s.nml", "--set", "scene.planar=xy"],
    ["animate", "out.h5", "--mode", "2", "--view", "xy"]])
def test_the_parser_of_the_named_command_parses_as_the_whole_parser(line):
    """ancf builds only the named command's arguments (cli._named_command): the line parses
    to the same namespace as with every command's arguments, and its help is the same."""
    from ancfdrv.cli import _named_command, build_parser
    named = _named_command(line)
    assert named == next(w for w in line if not w.startswith("-"))
    assert vars(build_parser(named).parse_args(line)) == vars(build_parser().parse_args(line))
    helps = []
    for parser in (build_parser(named), build_parser()):
        sub = next(a for a in parser._actions if a.dest == "command")
        helps.append(sub.choices[named].format_help())
    assert helps[0] == helps[1] and "usage: ancf " + named in helps[0]


def test_a_line_without_a_command_gets_every_command():
    """``ancf --help``, ``ancf --version`` and an unknown command name no command: the
    parser then has every command's arguments (argparse's own messages)."""
    from ancfdrv.cli import _named_command
    assert _named_command(["--help"]) is None and _named_command([]) is None
    assert _named_command(["--debug", "bogus", "run"]) is None
    assert _named_command(["--debug", "info", "run"]) == "info"
