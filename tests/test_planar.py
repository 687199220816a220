"""Planar reduction (issue 23, python/ancfdrv/system/planar.py): a scene whose motion stays in
a coordinate plane solves only the in-plane coordinates, eliminated like fixed coordinates.

The reference of every comparison is the same scene unreduced (planar = 'off'): by the
mirror symmetry about the plane the unreduced solution keeps the eliminated coordinates at
their initial values, so the two histories agree to the Newton tolerance (runs at
newton_tol = 1e-12 agree to ~1e-14 of the probe's range; the bound is 1e-8). The counts of
unknowns are closed forms: a beam node keeps 12 - 5 = 7 coordinates, a cable node 6 - 2 = 4,
a planar rigid body 12 - 6 = 6.
"""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv import Circle, System
from ancfdrv.errors import InputError
from ancfdrv.runner import run_scene

ROOT = Path(__file__).resolve().parents[1]


def _tip(path: Path) -> tuple[np.ndarray, dict]:
    with h5py.File(path) as f:
        return f["dynamic/probes/tip"][()], dict(f["model"].attrs)


def _compare(tmp_path: Path, scene: str, overrides: list[str]) -> tuple[dict, dict, float]:
    rows, attrs = {}, {}
    for planar in ("off", "xy"):
        out = tmp_path / f"{planar}.h5"
        run_scene(ROOT / scene, overrides + [f"scene.planar={planar}", "solver.newton_tol=1e-12",
                                             "output.xdmf=.false."], out, progress=False)
        rows[planar], attrs[planar] = _tip(out)
    diff = np.abs(rows["off"] - rows["xy"]).max() / np.ptp(rows["off"], axis=0).max()
    return attrs["off"], attrs["xy"], float(diff)


@pytest.mark.parametrize("bending", ["cubic", "continuum"])
def test_boom_luffing_reduced_equals_unreduced(tmp_path, bending):
    """The nonlinear boom luffing (4 nodes, the first 1.2 s: start and luffing stages) with
    the tip mass and the moment at A2, reduced to the r1-r2 plane."""
    off, xy, diff = _compare(tmp_path, "inputs/boom_luffing.nml", [
        "scene.formulation=nonlinear", f"beam.bending={bending}", "beam.nodes=4",
        "solver.static_method=newton", "solver.t_end=1.2"])
    assert diff < 1e-8
    assert (off["ndof"], off["nplanar_fixed"], off["planar"]) == (48, 0, "")
    assert (xy["ndof"], xy["nplanar_fixed"], xy["planar"]) == (4 * 7, 4 * 5, "xy")
    # the arm's plane and A2's r3 are held by the fixes: their multipliers are gone
    assert xy["nunknowns"] == xy["ndof"] + xy["nconstraints"] < off["nunknowns"]
    assert xy["nconstraints"] == off["nconstraints"] - 3


def test_flexible_pendulum_reduced_equals_unreduced(tmp_path):
    """The flexible pendulum (inputs/hard/pendulum.nml, 5 nodes, 0.3 s of its swing)."""
    off, xy, diff = _compare(tmp_path, "inputs/hard/pendulum.nml", [
        "beam.nodes=5", "solver.t_end=0.3", "solver.dt=1e-3"])
    assert diff < 1e-8
    assert (off["ndof"], xy["ndof"]) == (60, 35)


def test_general_boom_with_rigid_arm(tmp_path):
    """The boom's general twin (rigid arm, weld, linear joints eliminated) nonlinear: the
    scene's own planar fixes and the rigid arm's (6 of its 12 coordinates) are eliminated."""
    off, xy, diff = _compare(tmp_path, "inputs/general/boom_luffing.nml", [
        "scene.formulation=nonlinear", "beam[boom].nodes=4", "beam[boom].bending=cubic",
        "solver.static_method=newton", "solver.t_end=1.2"])
    assert diff < 1e-8
    assert xy["nplanar_fixed"] == 4 * 5 + 6
    assert xy["ndof"] < off["ndof"]


def _cable_pendulum(planar: str) -> System:
    s = System("cable pendulum", planar=planar)
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.cable("rope", material=steel, start=(0, 0, 0), end=(1.0, 0, 0), nodes=5,
            section=Circle(0.05))
    s.joint("pin", "spherical", "ground", "rope", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -9.81, 0))
    s.probe("tip", "rope", (1.0, 0, 0))
    return s


def test_cable_keeps_four_unknowns_per_node():
    """A pinned cable swinging in the x-y plane: 4 unknowns per node (Exudyn's 2D cable's
    count), the same swing as the unreduced cable."""
    runs = {}
    for planar in ("off", "auto"):
        s = _cable_pendulum(planar)
        model = s.assemble()
        runs[planar] = (model.ndof, s.simulate(0.2, 2e-3, newton_tol=1e-12, xdmf=False)
                        .probes["tip"])
        model.close()
    assert runs["off"][0] == 30 and runs["auto"][0] == 5 * 4
    a, b = runs["off"][1], runs["auto"][1]
    assert np.abs(a - b).max() < 1e-8 * np.ptp(a, axis=0).max()


def test_declared_plane_refuses_data_that_leave_it():
    """Each item that would take the motion out of the declared plane is named."""
    s = _cable_pendulum("xy")
    s.load("push", "force", body="rope", point=(1.0, 0, 0), vector=(0, 0, 1.0))
    with pytest.raises(InputError, match="load 'push'.*component along z"):
        s.assemble()
    s = _cable_pendulum("zx")   # gravity along -y lies along the normal of the z-x plane
    with pytest.raises(InputError, match="planar = 'zx'.*load 'g'"):
        s.assemble()
    s = _cable_pendulum("xy")
    s.rigid_body("bob", mass=1.0, inertia=(1, 1, 1, 0, 0, 0.1), position=(2, 0, 0))
    with pytest.raises(InputError, match="body 'bob'.*products of inertia"):
        s.assemble()
    s = _cable_pendulum("xy")
    s.rigid_body("bob", mass=1.0, inertia=(1, 1, 1, 0, 0, 0), position=(2, 0, 0))
    s.joint("hinge", "revolute", "ground", "bob", point=(2.0, 0, 0), axis=(0, 1, 0))
    with pytest.raises(InputError, match="joint 'hinge'.*not along z"):
        s.assemble()
    with pytest.raises(InputError, match="planar"):
        System("x", planar="xz-plane")


def test_auto_keeps_a_spatial_scene_unreduced():
    """'auto' on a cable pushed out of every coordinate plane solves every coordinate and
    says why; 'off' adds no fixes."""
    s = _cable_pendulum("auto")
    s.load("push", "force", body="rope", point=(1.0, 0, 0), vector=(1.0, 0, 1.0))
    model = s.assemble(effects=("gravity", "point_loads"))
    try:
        assert model.ndof == 30 and model.nplanar_fixed == 0 and model.planar == ""
        assert any("no plane found" in n for n in model.notes)
    finally:
        model.close()


def test_cable_end_moment_bends_into_a_circle():
    """A dead end moment M about z on a cable cantilever (weld at the root): pure bending,
    the exact solution is a circle of radius EI / M (zero axial force: the axis keeps its
    length). M = EI / L turns the tip by 1 rad: tip at (R sin 1, R (1 - cos 1)). 16
    elements, reduced to the x-y plane (4 unknowns per node), within 1e-5 L; the moment
    acts on the slope r_x at the node (assembly._slope_for_moment)."""
    from ancfdrv.solvers.static import solve_newton
    length, d = 2.0, 0.02
    s = System("cable moment", planar="xy")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.cable("c", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=17,
            section=Circle(d))
    ei = 2.1e11 * np.pi * d**4 / 64.0
    s.joint("root", "weld", "ground", "c", point=(0, 0, 0))
    s.load("M", "moment", body="c", point=(length, 0, 0), vector=(0, 0, ei / length))
    s.probe("tip", "c", (length, 0, 0))
    model = s.assemble()
    try:
        # 4 unknowns per node; the weld keeps the root's in-plane r and r_x with multipliers
        assert (model.ndof, len(model.constraints)) == (17 * 4, 4)
        result = solve_newton(model, tol=1e-12, load_steps=4)
        tip = model.probe_positions(result.e)["tip"]
    finally:
        model.close()
    radius = length
    expected = [radius * np.sin(1.0), radius * (1.0 - np.cos(1.0)), 0.0]
    assert np.abs(tip - expected).max() < 1e-5 * length
    s = System("torsion")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.cable("c", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=3,
            section=Circle(d))
    s.joint("root", "weld", "ground", "c", point=(0, 0, 0))
    s.load("T", "moment", body="c", point=(length, 0, 0), vector=(1.0, 0, 0))
    with pytest.raises(InputError, match="load 'T'.*no torsion"):
        s.assemble()


def test_boom_as_cable_static_sag(tmp_path):
    """beam.bending = 'cable' on the boom (50 kg, M_B = 1000 N m at A2, phi = 0): the
    static sag against the linear Euler-Bernoulli closed form
    (ancfdrv.reference.analytic.boom_static_tip_deflection, shear=False): -0.115632 m; the
    cable at 10 and 28 nodes within 0.15 % of it (the remainder is the geometric
    nonlinearity: measured 0.08 %, and Exudyn's ANCFCable2D at 27 elements gives the same
    -0.11554 m, benchmarks/results/peer_harness.md), and mesh convergence towards 28 nodes:
    10 nodes within 1e-4 of it (measured 2.9e-5) and at least 4 times closer than 4 nodes
    (the cubic interpolation converges as h^4 away from the kinks of the point loads). The
    reduced cable has 4 unknowns per node."""
    from ancfdrv.reference.analytic import boom_static_tip_deflection
    closed = boom_static_tip_deflection(0.0, 50.0, shear=False)[1]
    sag = {}
    for nodes in (4, 10, 28):
        out = tmp_path / f"cable{nodes}.h5"
        run_scene(ROOT / "inputs/boom_static.nml", [
            "scene.formulation=nonlinear", "beam.bending=cable", f"beam.nodes={nodes}",
            "solver.static_method=newton", "scene.planar=xy", "boom.angle_deg=0",
            "loads.tip_mass=50"], out, progress=False)
        with h5py.File(out) as f:
            sag[nodes] = float(f["static/deflection/tip"][1])
            assert f["model"].attrs["ndof"] == 4 * nodes
    assert abs(sag[28] / closed - 1.0) < 1.5e-3
    assert abs(sag[10] / closed - 1.0) < 1.5e-3
    err4, err10 = abs(sag[4] / sag[28] - 1.0), abs(sag[10] / sag[28] - 1.0)
    assert err10 < 1e-4 and err10 < err4 / 4.0


def test_general_cable_boom_matches_the_template(tmp_path):
    """inputs/general/boom_luffing_cable.nml (a cable welded to the rigid arm) against the
    template's cable boom (the arm holds the slope's direction): 4 nodes, the first 1.2 s,
    tip histories within 0.02 % of the boom's sag range 0.12 m (benchmarks/results/
    peer_levels.md), 2.4e-5 m (measured 1.3e-5 m at 10 nodes over 2 s: the weld also holds
    the slope's length at A1)."""
    runs = {}
    for name, scene, overrides in (
            ("general", "inputs/general/boom_luffing_cable.nml",
             ["cable[boom].nodes=4", "solver.t_end=1.2", "output.xdmf=.false."]),
            ("template", "inputs/boom_luffing.nml",
             ["scene.formulation=nonlinear", "beam.bending=cable", "beam.nodes=4",
              "solver.static_method=newton", "solver.t_end=1.2", "scene.planar=xy",
              "output.xdmf=.false."])):
        out = tmp_path / f"{name}.h5"
        run_scene(ROOT / scene, overrides, out, progress=False)
        runs[name] = _tip(out)
    (a, attrs), (b, _) = runs["general"], runs["template"]
    # 4 unknowns per cable node; the weld makes the planar arm's 6 coordinates dependent
    assert attrs["planar"] == "xy" and attrs["ndof"] == 4 * 4
    assert np.abs(a - b).max() < 2e-4 * 0.12


def test_ffr_beams_are_not_reduced(tmp_path):
    """An FFR beam keeps its constant iteration matrix by turning whole nodal 3-vectors with
    its frame: a declared plane is refused naming the beam, 'auto' leaves the scene
    unreduced (the shipped FFR boom: 28 x 12 coordinates)."""
    with pytest.raises(InputError, match="body 'boom'.*'ffr'"):
        run_scene(ROOT / "inputs/boom_static.nml", ["scene.planar=xy"], tmp_path / "a.h5",
                  progress=False)
    run_scene(ROOT / "inputs/boom_static.nml", ["scene.planar=auto"], tmp_path / "b.h5",
              progress=False)
    with h5py.File(tmp_path / "b.h5") as f:
        assert (f["model"].attrs["ndof"], f["model"].attrs["nplanar_fixed"]) == (28 * 12, 0)


def test_flexible_pendulum_as_a_planar_cable(tmp_path):
    """The flexible pendulum (inputs/hard/pendulum.nml, a 0.2 x 0.009 m section: I_y != I_z)
    as an ANCF cable bending about r3 (I_z), reduced to the x-y plane: 4 unknowns per node,
    and the total energy of the undamped swing (generalized-alpha, rho_inf = 1) conserved
    within 1e-4 of the range of the gravity energy over 0.5 s (measured 4.4e-5 over 1 s).
    Without the planar reduction the cable's single stiffness would be wrong out of the
    plane: refused."""
    overrides = ["beam.bending=cable", "beam.nodes=9", "solver.dt=5e-4", "solver.t_end=0.5",
                 "output.xdmf=.false."]
    with pytest.raises(InputError, match="scene.planar = 'xy'"):
        run_scene(ROOT / "inputs/hard/pendulum.nml", overrides, tmp_path / "a.h5",
                  progress=False)
    run_scene(ROOT / "inputs/hard/pendulum.nml", overrides + ["scene.planar=xy"],
              tmp_path / "b.h5", progress=False)
    with h5py.File(tmp_path / "b.h5") as f:
        assert f["model"].attrs["ndof"] == 9 * 4
        total, gravity = (f[f"dynamic/energy/{k}"][()] for k in ("total", "gravity"))
    assert np.ptp(gravity) > 10.0   # the pendulum fell
    assert np.abs(total - total[0]).max() < 1e-4 * np.ptp(gravity)


def test_cable_with_one_plane_stiffness_needs_the_plane():
    """System API: a cable given bending_inertia for a section with I_y != I_z is refused
    unless the system is planar; with planar = 'xy' it assembles with 4 unknowns per node."""
    from ancfdrv import Rectangle
    for planar in ("off", "xy"):
        s = System("strip", planar=planar)
        steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
        s.cable("c", material=steel, start=(0, 0, 0), end=(1, 0, 0), nodes=3,
                section=Rectangle(0.2, 0.01), bending_inertia=0.2 * 0.01**3 / 12.0)
        s.joint("pin", "spherical", "ground", "c", point=(0, 0, 0))
        s.load("g", "gravity", vector=(0, -9.81, 0))
        if planar == "off":
            with pytest.raises(InputError, match="cable 'c'.*planar"):
                s.assemble()
        else:
            model = s.assemble()
            assert model.ndof == 3 * 4
            model.close()
