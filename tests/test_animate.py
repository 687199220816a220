"""`ancf animate` (SPEC section 2; issue 37 item 4): an animation of a dynamic run (the whole
mesh, a time stamp per frame) or of a mode shape, as a GIF (Pillow) or an MP4 (ffmpeg);
refusals name the problem. The frames are checked against the file they come from (the
last frame is the run's last mesh row; a mode's frames are the static mesh plus the
scaled shape, a sine over one period), the written GIF by its frame count."""
from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from PIL import Image

from ancfdrv.animate import MODE_FRAMES, _frames, animate
from ancfdrv.cli import main
from ancfdrv.errors import InputError
from ancfdrv.runner import run_scene

SCENE = """
&scene  title = 'rod on a pin', analysis = '{analysis}', formulation = 'nonlinear',
        effects = 'gravity', planar = 'xy' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&cable  name = 'rod', material = 'steel', start = 0, 0, 0, end = {end}, nodes = 3,
        section = 'circle', diameter = 0.02 /
&joint  name = 'pin', type = 'spherical', body1 = 'ground', body2 = 'rod', point = 0, 0, 0 /
&load  name = 'g', type = 'gravity', vector = 0.0, -9.81, 0.0 /
&modal  modes = 2 /
&solver  dt = 1e-2, t_end = 0.2 /
"""


def result(tmp_path: Path, analysis: str) -> Path:
    scene = tmp_path / f"{analysis}.nml"
    # released at an angle; hanging straight down for the modes (its static state)
    end = "0.5, -0.8, 0" if analysis == "dynamic" else "0, -1, 0"
    scene.write_text(SCENE.format(analysis=analysis, end=end))
    out = tmp_path / f"{analysis}.h5"
    run_scene(scene, [], out, progress=False)
    return out


def test_a_dynamic_run_animates_every_row(tmp_path):
    out = result(tmp_path, "dynamic")
    with h5py.File(out, "r") as h5:
        frames, labels, _ = _frames(h5, out, None)
        last = h5["dynamic/mesh_nodes"][-1]
        rows = h5["dynamic/mesh_rows"][()]
        t_end = h5["dynamic/time"][rows[-1]]
    assert len(frames) == len(rows) == 21
    assert np.array_equal(frames[-1], last)
    assert labels[-1] == f"t = {t_end:.3f} s"
    gif = animate(out, tmp_path / "run.gif")
    with Image.open(gif) as image:
        assert image.n_frames == len(frames)


def test_a_mode_oscillates_about_its_static_state(tmp_path):
    out = result(tmp_path, "modal")
    with h5py.File(out, "r") as h5:
        frames, labels, _ = _frames(h5, out, 1)
        static = h5["modal/mesh_static"][()]
        shape = h5["modal/mesh_shapes"][0]
        frequency = h5["modal/frequency"][0]
    size = np.ptp(static, axis=0).max()
    quarter = MODE_FRAMES // 4  # sin = 1: the largest excursion, a tenth of the model
    assert frames[quarter] == pytest.approx(static + 0.1 * size * shape, abs=1e-12 * size)
    assert frames[0] == pytest.approx(static, abs=1e-12 * size)
    assert f"{frequency:.4g} Hz" in labels[0]
    assert main(["animate", str(out), "--mode", "1", "-o", str(tmp_path / "m.gif")]) == 0
    with Image.open(tmp_path / "m.gif") as image:
        assert image.n_frames == MODE_FRAMES


def test_refusals_name_the_problem(tmp_path, capsys):
    modal = result(tmp_path, "modal")
    with pytest.raises(InputError, match="no dynamic run to animate .* --mode N"):
        animate(modal, tmp_path / "a.gif")
    with pytest.raises(InputError, match="the file holds modes 1 to 2"):
        animate(modal, tmp_path / "a.gif", mode=3)
    with pytest.raises(InputError, match="a .gif or an .mp4"):
        animate(modal, tmp_path / "a.png", mode=1)
    if shutil.which("ffmpeg") is None:
        with pytest.raises(InputError, match="needs ffmpeg"):
            animate(modal, tmp_path / "a.mp4", mode=1)
    assert main(["animate", str(tmp_path / "missing.h5")]) == 2
    assert "result file not found" in capsys.readouterr().err
    assert not list(tmp_path.glob("*.gif")) and not list(tmp_path.glob(".*partial*"))


def test_the_crane_with_its_rope_animates_and_opens_in_meshio(tmp_path):
    """The shipped knuckle crane (inputs/knuckle_crane_rope.nml), its static state and four
    steps: the GIF has a frame per mesh row; the dynamic XDMF opens with meshio's time-series
    reader with every point of the machine (beams, rope, cylinder, payload, joints) and one
    step per frame; the rope's tension at t = 0 (the static state) is the 500 kg payload's
    weight plus the rope below its lowest and highest Gauss points (w s, w (L - s): 16 mm,
    5000 kg/m^3, 2.5 m in five elements), within 1e-9 of the weight."""
    import meshio
    out = tmp_path / "crane.h5"
    run_scene(Path(__file__).resolve().parents[1] / "inputs" / "knuckle_crane_rope.nml",
              ["solver.t_end=0.02"], out, progress=False)
    gif = animate(out, tmp_path / "crane.gif")
    with h5py.File(out, "r") as h5:
        rows = h5["dynamic/mesh_rows"][()]
        npoints = len(h5["model/mesh/points"])
        bodies = str(h5["model/mesh"].attrs["bodies"])
        low, high = h5["dynamic/tension/rope/min"][0], h5["dynamic/tension/rope/max"][0]
    with Image.open(gif) as image:
        assert image.n_frames == len(rows) == 5
    assert gif.stat().st_size > 10_000
    for part in ("rope: cable", "payload: point mass", "jib cylinder: force element"):
        assert part in bodies
    with meshio.xdmf.TimeSeriesReader(out.with_suffix(".xdmf")) as reader:
        points, cells = reader.read_points_cells()
        assert reader.num_steps == len(rows)
        t, point_data, _ = reader.read_data(reader.num_steps - 1)
    assert points.shape == (npoints, 3) and t == pytest.approx(0.02, abs=1e-12)
    assert point_data["displacement"].shape == (npoints, 3)
    assert sum(len(c.data) for c in cells) == 8 + 12 + 5 + 2 + 4
    weight = 500.0 * 9.81
    w = 5000.0 * np.pi * 0.016**2 / 4 * 9.81
    s = 0.5 * 0.5 * (np.polynomial.legendre.leggauss(5)[0][0] + 1.0)
    assert low == pytest.approx(weight + w * s, abs=1e-9 * weight)
    assert high == pytest.approx(weight + w * (2.5 - s), abs=1e-9 * weight)
