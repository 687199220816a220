"""``ancf show SCENE.nml [-o PNG]`` and ``System.show()`` (issue 37, item 2): a picture of the
undeformed model, nothing solved.

The command is run in-process with every solver replaced by one that fails the test, in
an empty working directory that must hold no result file afterwards. The PNG's pixel size
is read from its header. The drawn geometry of each body (the artists the preview tags
``body:<name>``) is compared with the body as the scene gives it: a straight beam or cable
spans its start and end, a flat plate its corner and corner + edge_x + edge_y, a rigid body
its centre, the tips of its axes at the radius of gyration sqrt(tr(I) / 2m) and the corners
of its inertia box, half-sizes a, b, c from Ixx = m (b^2 + c^2) / 3, ... (the XDMF layout's,
results/xdmf.py).
"""
from __future__ import annotations

import shutil
import struct
from pathlib import Path

import numpy as np
import pytest

from conftest import INPUTS
import ancfdrv
from ancfdrv import preview
from ancfdrv.cli import main
from ancfdrv.io.scene import load_scene

CRANE = INPUTS / "knuckle_crane_rope.nml"
CARDAN = INPUTS / "general" / "cardan_shaft.nml"
PLATE = INPUTS / "general" / "plate_pendulum.nml"


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) from the PNG's IHDR chunk."""
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR"
    return struct.unpack(">II", head[16:24])


@pytest.fixture
def no_solver(monkeypatch, tmp_path):
    """Every solve fails the test; the working directory is an empty one."""
    def refuse(*args, **kwargs):
        raise AssertionError("ancf show solved something")
    import ancfdrv.runner
    import ancfdrv.solvers.static
    import ancfdrv.solvers.dynamic
    for module, name in ((ancfdrv.runner, "solve_static_path"), (ancfdrv.runner, "solve_newton"),
                         (ancfdrv.runner, "integrate"), (ancfdrv.solvers.static, "solve_static"),
                         (ancfdrv.solvers.static, "solve_newton"),
                         (ancfdrv.solvers.dynamic, "integrate")):
        monkeypatch.setattr(module, name, refuse)
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    return work


@pytest.mark.parametrize("scene", [CRANE, CARDAN], ids=["crane", "cardan"])
def test_show_writes_a_picture_and_solves_nothing(no_solver, scene, capsys):
    png = no_solver / "preview.png"
    assert main(["show", str(scene), "-o", str(png)]) == 0
    assert f"written {png}" in capsys.readouterr().out
    assert png.stat().st_size > 20_000
    assert png_size(png) == (round(preview.FIGSIZE[0] * preview.DPI),
                             round(preview.FIGSIZE[1] * preview.DPI))
    assert sorted(p.name for p in no_solver.rglob("*")) == ["preview.png"]  # no HDF5


def test_default_output_is_beside_the_scene(no_solver, capsys):
    scene = no_solver / "crane.nml"
    shutil.copy(CRANE, scene)
    assert main(["show", str(scene), "--set", "beam[jib].nodes=4"]) == 0
    assert (no_solver / "crane.png").stat().st_size > 20_000
    assert not list(no_solver.rglob("*.h5"))


def test_bad_scene_exits_2_naming_the_key(no_solver, capsys):
    bad = no_solver / "bad.nml"
    bad.write_text(CARDAN.read_text().replace("&probe", "&probe  colour = 'red',", 1))
    assert main(["show", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("ancf show: error:") and "bad.nml" in err and "colour" in err
    assert "Traceback" not in err
    assert not (no_solver / "bad.png").exists()


def test_bad_override_exits_2(no_solver, capsys):
    assert main(["show", str(CRANE), "--set", "beam[jib].nodes=zero"]) == 2
    err = capsys.readouterr().err
    assert "ancf show: error:" in err and "nodes" in err


def expected_boxes(scene: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """(low, high) of each body from the scene's own values (see the module docstring)."""
    out = {}
    for group, v in load_scene(scene).items:
        if group in ("beam", "cable"):
            ends = np.array([v["start"], v["end"]], dtype=float)
        elif group == "plate":
            corner = np.asarray(v["corner"], float)
            ends = np.array([corner, corner + v["edge_x"] + np.asarray(v["edge_y"])])
        elif group == "rigid_body":
            centre = np.asarray(v["position"], float)
            moments = np.asarray(v["inertia"][:3], float)
            assert not any(v["inertia"][3:])  # principal axes along x, y, z
            size = np.sqrt(moments.sum() / (2.0 * v["mass"]))
            half = np.sqrt(3.0 * (moments.sum() - 2.0 * moments) / (2.0 * v["mass"]))
            ends = np.vstack([centre, centre + size * np.eye(3), centre - half,
                              centre + half])
        else:
            continue
        out[v["name"]] = (ends.min(axis=0), ends.max(axis=0))
    return out


def drawn_boxes(fig, view: int) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """(low, high) in the view's two axes of the lines tagged body:<name>."""
    found: dict[str, list[np.ndarray]] = {}
    for line in fig.axes[view].get_lines():
        gid = line.get_gid() or ""
        if gid.startswith("body:"):
            found.setdefault(gid[5:], []).append(np.asarray(line.get_xydata(), float))
    return {name: (np.nanmin(np.vstack(xy), axis=0), np.nanmax(np.vstack(xy), axis=0))
            for name, xy in found.items()}


@pytest.mark.parametrize("scene", [CRANE, CARDAN, PLATE], ids=["crane", "cardan", "plate"])
def test_every_body_is_drawn_where_the_scene_puts_it(scene):
    from ancfdrv.builders import build_model, build_system
    import matplotlib.pyplot as plt
    loaded = load_scene(scene)
    built = build_system(loaded)
    loaded.built = built
    model = build_model(loaded)
    try:
        fig = preview.figure(built.system, model, "test")
    finally:
        model.close()
    try:
        expected = expected_boxes(scene)
        size = max(float(np.max(hi - lo)) for lo, hi in expected.values())
        every = np.array([b for lo_hi in expected.values() for b in lo_hi])
        for view, (_, pair) in enumerate(preview.VIEWS):
            drawn = drawn_boxes(fig, view)
            assert set(drawn) == set(expected)  # every body, nothing else tagged as one
            for name, (lo, hi) in expected.items():
                np.testing.assert_allclose(drawn[name][0], lo[list(pair)], rtol=0,
                                           atol=1e-9 * size, err_msg=name)
                np.testing.assert_allclose(drawn[name][1], hi[list(pair)], rtol=0,
                                           atol=1e-9 * size, err_msg=name)
            union = np.vstack([np.vstack(b) for b in drawn.values()])
            np.testing.assert_allclose(union.min(axis=0), every.min(axis=0)[list(pair)],
                                       rtol=0, atol=1e-9 * size)
            np.testing.assert_allclose(union.max(axis=0), every.max(axis=0)[list(pair)],
                                       rtol=0, atol=1e-9 * size)
        texts = {t.get_text().strip() for ax in fig.axes for t in ax.texts}
        system = built.system
        for name in [*system.bodies, *system.probes]:
            assert any(t.startswith(name) for t in texts), name
        for joint in system.joints.values():
            assert any(t.startswith(joint.name) for t in texts), joint.name
    finally:
        plt.close(fig)


def test_system_show_from_python(tmp_path, monkeypatch):
    """System.show(path) writes the picture and returns its path; without a path, a new
    temporary PNG."""
    s = ancfdrv.System("cantilever")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(2, 0, 0), nodes=4,
           section=ancfdrv.Rectangle(0.05, 0.1), height_axis=(0, 1, 0),
           formulation="nonlinear")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("push", "force", body="arm", point=(2, 0, 0), vector=(0, -100.0, 0))
    s.probe("tip", "arm", (2, 0, 0))
    out = s.show(tmp_path / "arm.png")
    assert out == tmp_path / "arm.png" and out.stat().st_size > 20_000
    temporary = s.show()
    try:
        assert temporary.suffix == ".png" and temporary.stat().st_size > 20_000
    finally:
        temporary.unlink()
