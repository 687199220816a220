"""Output that never fails a good run (issue 22 item 2): ``ancf run`` on general scenes with
any probe names and any number of bodies (static and dynamic) exits 0 and writes its plot;
``ancf info`` and ``ancf plot`` read those files; a plot that cannot be drawn is a warning,
never a non-zero exit after a correct solve.

Each scene is also checked against an independent figure, so the run is not only 'exit 0':

* the L-frame (tests/scenes/l_frame.nml, gravity off, a slender girder): Euler-Bernoulli
  frame formulas for a column clamped at its foot and a girder welded to its top with an
  end force P (the girder as a cantilever, P a^3 / (3 EI), plus the column's top rotation
  P a h / EI carried over the girder's length a, plus the column's shortening P h / (EA);
  the column top's sway P a h^2 / (2 EI));
* the four-bar (tests/scenes/four_bar.nml): the rigid crank-rocker's closed-form position
  (two circles' intersection) at the drive's crank angle; the steel coupler stretches by
  far less than the 1e-5 m allowed.
"""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv.cli import main

SCENES = Path(__file__).resolve().parent / "scenes"
GENERAL = Path(__file__).resolve().parents[1] / "inputs" / "general"


def _run(scene: Path, out: Path, *sets: str, plot: bool = False) -> int:
    args = ["run", str(scene), "-o", str(out), *(["--plot"] if plot else [])]
    for s in sets:
        args += ["--set", s]
    return main(args)


def _box_inertia(width: float, height: float, wall: float) -> tuple[float, float]:
    """Area and second moment about the width axis of a box section."""
    area = width * height - (width - 2 * wall) * (height - 2 * wall)
    inertia = (width * height**3 - (width - 2 * wall) * (height - 2 * wall)**3) / 12.0
    return area, inertia


#: the girder's section in the L-frame tests: slender (L/h = 37), so that its shear
#: deflection (P a / (G A_s) ~ 1e-3 of the bending one) stays below the tolerances
GIRDER = ("beam[girder].width=0.04", "beam[girder].height=0.04", "beam[girder].wall=0.004")


def test_l_frame_static_two_beams_exit_0_plot_and_frame_formula(tmp_path, capsys):
    out = tmp_path / "l_frame.h5"
    code = _run(SCENES / "l_frame.nml", out, "scene.effects='point_loads'",
                "beam[column].bending='cubic'", "beam[girder].bending='cubic'", *GIRDER,
                plot=True)
    assert code == 0, capsys.readouterr().err
    assert out.with_suffix(".png").stat().st_size > 1000
    with h5py.File(out) as h5:
        assert h5.attrs["status"] == "ok"
        end = h5["static/probes/free end"][()]
        knee = h5["static/probes/knee"][()]
    E, P, a, h = 2.1e11, 500.0, 1.5, 2.0
    area, column = _box_inertia(0.1, 0.1, 0.005)
    _, girder = _box_inertia(0.04, 0.04, 0.004)
    drop = P * a**3 / (3 * E * girder) + P * a * h / (E * column) * a + P * h / (E * area)
    sway = P * a * h**2 / (2 * E * column)    # the column top moves sideways under M = P a
    np.testing.assert_allclose(-(end[1] - 2.0), drop, rtol=5e-3)
    np.testing.assert_allclose(knee[0], sway, rtol=5e-3)
    assert main(["info", str(out)]) == 0
    png = tmp_path / "again.png"
    assert main(["plot", str(out), "-o", str(png)]) == 0 and png.stat().st_size > 1000


def _four_bar_rocker_top(theta: np.ndarray) -> np.ndarray:
    """C of the rigid crank-rocker: |C - B| = coupler, |C - D| = rocker, B on the crank."""
    A, D = np.array([0.0, 0.0]), np.array([0.4, -0.1])
    B0, C0 = np.array([0.1, 0.0]), np.array([0.4, 0.2])
    coupler, rocker = np.linalg.norm(C0 - B0), np.linalg.norm(C0 - D)
    out = []
    for th in theta:
        B = A + 0.1 * np.array([np.cos(th), np.sin(th)])
        d = np.linalg.norm(D - B)
        along = (coupler**2 - rocker**2 + d**2) / (2 * d)
        across = np.sqrt(coupler**2 - along**2)
        u = (D - B) / d
        n = np.array([-u[1], u[0]])
        candidates = [B + along * u + across * n, B + along * u - across * n]
        prev = out[-1] if out else C0
        out.append(min(candidates, key=lambda c: np.linalg.norm(c - prev)))
    return np.array(out)


def test_four_bar_dynamic_exit_0_plot_and_closed_form_kinematics(tmp_path, capsys):
    out = tmp_path / "four_bar.h5"
    assert _run(SCENES / "four_bar.nml", out, plot=True) == 0, capsys.readouterr().err
    assert out.with_suffix(".png").stat().st_size > 1000
    with h5py.File(out) as h5:
        t = h5["dynamic/time"][()]
        top = h5["dynamic/probes/rocker top"][()]
    # the spin-up drive: theta = (W/T) (t^2/2 + (T/2pi)^2 (cos(2 pi t/T) - 1)), W=10, T=0.1
    W, T = 10.0, 0.1
    theta = W / T * (0.5 * t**2 + (T / (2 * np.pi))**2 * (np.cos(2 * np.pi * t / T) - 1))
    expected = _four_bar_rocker_top(theta)
    assert np.ptp(top[:, 0]) > 0.01                      # the rocker really swings
    np.testing.assert_allclose(top[:, :2], expected, atol=1e-5)
    assert main(["info", str(out)]) == 0
    assert main(["plot", str(out), "-o", str(tmp_path / "p.png")]) == 0


def test_knuckle_crane_static_dynamic_exit_0_plot_info(tmp_path, capsys):
    out = tmp_path / "crane.h5"
    assert _run(SCENES / "knuckle_crane.nml", out, "solver.t_end=0.02", plot=True) == 0, \
        capsys.readouterr().err
    assert out.with_suffix(".png").stat().st_size > 1000
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    assert ": ok:" in text.splitlines()[0] and "static.deflection.hook" in text


@pytest.mark.parametrize("name, sets", [
    ("cantilever", ()), ("plate_pendulum", ("solver.t_end=0.01",)),
    ("curved_leaf", ("solver.t_end=0.005",)), ("spinup", ("solver.t_end=0.05",)),
    ("boom_luffing", ("solver.t_end=0.02", "beam[boom].nodes=10")),
    ("leaf_spring", ("solver.t_end=0.01",))])
def test_shipped_general_scenes_exit_0_with_plot(name, sets, tmp_path, capsys):
    out = tmp_path / f"{name}.h5"
    assert _run(GENERAL / f"{name}.nml", out, *sets, plot=True) == 0, capsys.readouterr().err
    assert out.with_suffix(".png").stat().st_size > 1000
    assert main(["plot", str(out), "-o", str(tmp_path / "p.png")]) == 0


def test_renamed_probe_and_failing_plot_are_not_failures(tmp_path, capsys, monkeypatch):
    """A boom whose probe is not called 'tip' plots; a plot that raises is a warning (exit
    0, the result file complete with status 'ok')."""
    scene = tmp_path / "cantilever.nml"
    scene.write_text((GENERAL / "cantilever.nml").read_text().replace("name = 'tip'",
                                                                      "name = 'end point'"))
    out = tmp_path / "c.h5"
    assert _run(scene, out, plot=True) == 0
    assert out.with_suffix(".png").exists()
    from ancfdrv import plots

    def broken(*_args, **_kwargs):
        raise KeyError("node_s")
    monkeypatch.setattr(plots, "plot_result", broken)
    out2 = tmp_path / "c2.h5"
    assert _run(scene, out2, plot=True) == 0
    assert "warning: the plot" in capsys.readouterr().err
    with h5py.File(out2) as h5:
        assert h5.attrs["status"] == "ok"
    assert not out2.with_suffix(".png").exists()


def test_failing_xdmf_is_a_warning(tmp_path, capsys, monkeypatch):
    """The XDMF description is an optional output too: when it cannot be written the run
    still exits 0 with its result complete (status 'ok') and says why on stderr."""
    from ancfdrv.results import xdmf

    def broken(*_args, **_kwargs):
        raise OSError("disk full")
    monkeypatch.setattr(xdmf, "write_series", broken)
    out = tmp_path / "fb.h5"
    assert _run(SCENES / "four_bar.nml", out, "solver.t_end=0.01") == 0
    assert "XDMF description" in capsys.readouterr().err
    with h5py.File(out) as h5:
        assert h5.attrs["status"] == "ok" and len(h5["dynamic/time"]) == 11


def test_extra_plots_of_optional_groups_are_called(tmp_path, monkeypatch):
    """plots.EXTRA_PLOTS: a plot registered for a root group (e.g. 'modal') is drawn beside
    the main plot when the file holds that group, and not otherwise."""
    from ancfdrv import plots
    out = tmp_path / "c.h5"
    assert _run(GENERAL / "cantilever.nml", out) == 0
    calls = []

    def extra(h5_path, png):
        calls.append(Path(png).name)
        return png
    monkeypatch.setitem(plots.EXTRA_PLOTS, "modal", extra)
    plots.plot_result(out)
    assert calls == []
    with h5py.File(out, "a") as h5:
        h5.create_group("modal").create_dataset("frequency", data=[1.0, 2.0])
    plots.plot_result(out)
    assert calls == ["c_modal.png"]
