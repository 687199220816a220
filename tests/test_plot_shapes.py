"""What the plots draw (issue 37 item 3). The deformed shape of a static result:
/static/mesh_nodes holds the mesh points at the static state, and `ancf plot` draws it over a
grey ghost of the undeformed mesh with the scale in the title. The default dynamic plot
draws what moves, with each rope's swing angle and tension.

Checked against an independent path: the tip point of a cantilever's mesh moves by the
tip probe's deflection (the probe is evaluated from the element's shape functions, the
mesh from the XDMF layout's map), and by the Euler-Bernoulli tip deflection P L^3 / 3 EI."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv.plots import plot_result, shape_scale
from ancfdrv.runner import run_scene

SCENE = """
&scene  title = 'cantilever', analysis = 'static', formulation = 'nonlinear' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&beam  name = 'arm', material = 'steel', start = 0, 0, 0, end = 2.0, 0, 0, nodes = 5,
       section = 'rectangle', width = 0.02, height = 0.03, height_axis = 0, 1, 0,
       bending = 'cubic' /
&joint  name = 'root', type = 'weld', body1 = 'ground', body2 = 'arm', point = 0, 0, 0 /
&load  name = 'tip load', type = 'force', body = 'arm', point = 2.0, 0, 0, vector = 0, -{p}, 0 /
&probe  name = 'tip', body = 'arm', point = 2.0, 0, 0 /
&solver  static_method = 'newton' /
"""
E, WIDTH, HEIGHT, LENGTH = 2.1e11, 0.02, 0.03, 2.0


def test_the_static_mesh_moves_with_the_probes_and_the_closed_form(tmp_path):
    p = 20.0
    scene = tmp_path / "cantilever.nml"
    scene.write_text(SCENE.format(p=p))
    out = tmp_path / "cantilever.h5"
    run_scene(scene, [], out, progress=False)
    with h5py.File(out, "r") as h5:
        ghost = h5["model/mesh/points"][()]
        moved = h5["static/mesh_nodes"][()]
        probe = h5["static/probes/tip"][()]
    tip = int(np.argmin(np.linalg.norm(ghost - [LENGTH, 0.0, 0.0], axis=1)))
    # round-off of the two evaluations of one state: a few eps of the beam's length
    assert moved[tip] == pytest.approx(probe, abs=16 * np.finfo(float).eps * LENGTH)
    inertia = WIDTH * HEIGHT**3 / 12  # bending in the height's plane (y)
    euler = p * LENGTH**3 / (3 * E * inertia)
    assert moved[tip, 1] - ghost[tip, 1] == pytest.approx(-euler, rel=2e-3)  # shear: ~1e-4
    root = int(np.argmin(np.linalg.norm(ghost, axis=1)))
    assert np.abs(moved[root] - ghost[root]).max() < 1e-12


def test_the_static_plot_draws_the_shape(tmp_path):
    scene = tmp_path / "cantilever.nml"
    scene.write_text(SCENE.format(p=20.0))
    out = tmp_path / "cantilever.h5"
    run_scene(scene, [], out, progress=False)
    png = plot_result(out, tmp_path / "shape.png")
    assert png.stat().st_size > 20_000  # two panels, not an empty figure


def test_the_shape_scale_shows_a_tenth_of_the_size():
    base = np.array([[0.0, 0, 0], [2.0, 0, 0]])
    small = np.array([[0.0, 0, 0], [0.0, -0.002, 0]])
    assert shape_scale(base, small) == pytest.approx(0.1 * 2.0 / 0.002)
    assert shape_scale(base, 200 * small) == 1.0  # already visible: true scale
    assert shape_scale(base, 0 * small) == 1.0


PENDULUM = """
&scene  title = 'rod on a pin', analysis = 'dynamic', formulation = 'nonlinear', effects = 'gravity',
        planar = 'xy' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&cable  name = 'rod', material = 'steel', start = 0, 0, 0, end = {x!r}, {y!r}, 0, nodes = 3,
        section = 'circle', diameter = 0.02 /
&joint  name = 'pin', type = 'spherical', body1 = 'ground', body2 = 'rod', point = 0, 0, 0 /
&load  name = 'g', type = 'gravity', vector = 0.0, -9.81, 0.0 /
&probe  name = 'top', body = 'rod', point = 0, 0, 0 /
&probe  name = 'end', body = 'rod', point = {x!r}, {y!r}, 0 /
&solver  dt = 2e-3, t_end = 1.0, rho_inf = 1.0 /
"""


def test_the_dynamic_plot_draws_what_moves_and_the_ropes_swing(tmp_path):
    """A stiff 1 m rod (a cable of bending stiffness 1650 N m^2 weighing 2.5 kg: rigid to
    1e-5) released at 10 degrees on a pin swings through 20 degrees from its start (a
    compound pendulum, period 2 pi sqrt(2 L / 3 g) = 1.64 s); the plot's swing angle
    equals the angle of the chord between the probes at its ends (computed from the
    probes, not the mesh)."""
    from ancfdrv.plots import _cable_swing, plot_general_dynamic
    theta = np.radians(10.0)
    scene = tmp_path / "pendulum.nml"
    scene.write_text(PENDULUM.format(x=float(np.sin(theta)), y=float(-np.cos(theta))))
    out = tmp_path / "pendulum.h5"
    run_scene(scene, [], out, progress=False)
    with h5py.File(out, "r") as h5:
        times, angle = _cable_swing(h5)["rod"]
        rows = h5["dynamic/mesh_rows"][()]
        chord = h5["dynamic/probes/end"][()][rows] - h5["dynamic/probes/top"][()][rows]
    chord /= np.linalg.norm(chord, axis=1, keepdims=True)
    expected = np.degrees(np.arccos(np.clip(chord @ chord[0], -1, 1)))
    # two evaluations of one state (mesh map, probe): round-off of an arccos near 0
    assert angle == pytest.approx(expected, abs=1e-6)
    assert angle.max() == pytest.approx(20.0, rel=1e-2)  # undamped: back to -10 degrees
    png = plot_general_dynamic(out, tmp_path / "pendulum.png")
    assert png.stat().st_size > 20_000


ROPE = """
&scene  title = 'hanging payload', analysis = 'static+dynamic', formulation = 'nonlinear',
        effects = 'gravity', 'tip_mass', planar = 'xy' /
&material  name = 'wire rope', youngs_modulus = 1.0e11, density = 5000.0 /
&cable  name = 'rope', material = 'wire rope', start = 0, 0, 0, end = 0, -2.0, 0, nodes = 3,
        section = 'circle', diameter = 0.004, tension_only = .true., bending_stiffness = 0.5 /
&joint  name = 'top', type = 'spherical', body1 = 'ground', body2 = 'rope', point = 0, 0, 0 /
&load  name = 'g', type = 'gravity', vector = 0.0, -9.81, 0.0 /
&load  name = 'payload', type = 'point_mass', body = 'rope', point = 0, -2.0, 0, mass = 200.0 /
&probe  name = 'hook', body = 'rope', point = 0, -2.0, 0 /
&solver  static_method = 'newton', dt = 5e-3, t_end = 0.05, newton_tol = 1e-10 /
"""


def test_the_dynamic_plot_draws_each_ropes_tension(tmp_path):
    """A 200 kg payload at rest on a 2 m rope of two elements (d = 4 mm: w = 0.62 N/m, its
    weight w L = 1.2 N), dynamics from the static state: the tension the run writes
    (/dynamic/tension/rope, the cable kind's axial force at the rope's Gauss points) is the
    payload's weight m g plus the rope below a point, m g + w s: its smallest at the lowest
    Gauss point (s = the first 5-point Gauss abscissa of a 1 m element), its largest at the
    highest (s = L less that), at every row, within 1e-9 of m g (the Newton tolerance's
    scale; measured 8e-10 N); the plot draws that series (kN), and the PNG exists."""
    from ancfdrv.plots import _rope_tension, plot_general_dynamic
    scene = tmp_path / "payload.nml"
    scene.write_text(ROPE)
    out = tmp_path / "payload.h5"
    run_scene(scene, [], out, progress=False)
    weight = 200.0 * 9.81
    w = 5000.0 * np.pi * 0.004**2 / 4 * 9.81
    s = 0.5 * (np.polynomial.legendre.leggauss(5)[0][0] + 1.0)
    with h5py.File(out, "r") as h5:
        t = h5["dynamic/time"][()]
        low, high = h5["dynamic/tension/rope/min"][()], h5["dynamic/tension/rope/max"][()]
        assert h5["dynamic/tension/rope/max"].attrs["units"] == "N"
        plotted = _rope_tension(h5["dynamic"])
    assert len(low) == len(high) == len(t) > 5
    assert low == pytest.approx(np.full(len(t), weight + w * s), abs=1e-9 * weight)
    assert high == pytest.approx(np.full(len(t), weight + w * (2.0 - s)), abs=1e-9 * weight)
    assert plotted["rope"] == pytest.approx(high / 1e3, rel=1e-15)
    png = plot_general_dynamic(out, tmp_path / "payload.png")
    assert png.stat().st_size > 20_000
