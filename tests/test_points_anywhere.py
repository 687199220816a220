"""Joints, loads and probes at any material point (SPEC 8.1): between nodes (through the
shape functions) and off a beam's axis (through its section directors), and plate supports
named by an edge or a box so that refining the mesh never leaves part of them free.

References: the Euler-Bernoulli closed form of a propped cantilever with an overhang
(superposition of cantilever deflections, below), the same model with a node at every
point, and the plate-strip closed form w = q L^4 / (8 D) (Kirchhoff; nu = 0, where the
free-sided strip and the beam agree)."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import Rectangle, System
from ancfdrv.errors import InputError
from ancfdrv.solvers.static import solve_newton

E, WIDTH, HEIGHT, LENGTH = 2.0e11, 0.02, 0.01, 1.0
EI = E * WIDTH * HEIGHT**3 / 12
SUPPORT, PROBE_X, LOAD_P, LOAD_N = 0.6, 0.3, 20.0, 400.0


def _cantilever_w(x: float, c: float) -> float:
    """Downward deflection at x of a cantilever (clamped at 0) under a unit downward force
    at c (Euler-Bernoulli)."""
    return (x**2 * (3 * c - x) if x <= c else c**2 * (3 * x - c)) / (6 * EI)


def _propped_reference(x: float) -> float:
    """Downward deflection at x of the beam clamped at 0, held vertically at SUPPORT, under
    a downward tip force P and the moment N h/2 of an axial tip force N acting on the top
    fibre (it bends the beam down: w = M x^2 / (2 EI) on a cantilever)."""
    moment = LOAD_N * HEIGHT / 2

    def free(at: float) -> float:   # the cantilever without the support
        return LOAD_P * _cantilever_w(at, LENGTH) + moment * at**2 / (2 * EI)
    reaction = -free(SUPPORT) / _cantilever_w(SUPPORT, SUPPORT)   # downward positive
    return free(x) + reaction * _cantilever_w(x, SUPPORT)


def _propped(nodes: int, segments=None) -> float:
    """The propped cantilever: a roller under the bottom fibre at x = SUPPORT (a 'fix' of
    the point's z), the loads on the top fibre at the tip, the probe on the top fibre at
    PROBE_X; returns the probe's downward displacement."""
    s = System("propped cantilever")
    s.material("steel", youngs_modulus=E, density=7800.0)
    s.beam("b", material="steel", start=(0, 0, 0), end=(LENGTH, 0, 0), nodes=nodes,
           section=Rectangle(WIDTH, HEIGHT), formulation="ffr", bending="cubic",
           segments=segments)
    s.joint("clamp", "weld", "ground", "b", point=(0, 0, 0))
    s.joint("roller", "fix", "ground", "b", point=(SUPPORT, 0, -HEIGHT / 2), axis=(0, 0, 1))
    s.load("tip", "force", body="b", point=(LENGTH, 0, HEIGHT / 2), vector=(LOAD_N, 0, -LOAD_P))
    s.probe("p", "b", (PROBE_X, 0, HEIGHT / 2))
    model = s.assemble()
    try:
        result = solve_newton(model)
        q = model.expand(result.e)
        z = sum(c * q[d + 2] for d, c in model.probes["p"].terms)
        return -(z - HEIGHT / 2)
    finally:
        model.close()


def test_joint_load_and_probe_between_nodes_and_off_the_axis():
    """The roller at x = 0.6 under the bottom fibre, the tip loads on the top fibre and the
    probe at x = 0.3 on the top fibre: with 9 equal nodes (0.6 and 0.3 between nodes) the
    probe's deflection equals that of the mesh with nodes there (segments 0.3, 0.3, 0.4) to
    the discretization error, and both match the Euler-Bernoulli closed form (the cubic
    element is exact for point loads at nodes; between nodes its error falls with h)."""
    reference = _propped_reference(PROBE_X)
    with_nodes = _propped(7, segments=[0.3, 0.3, 0.4])
    between_9, between_17 = _propped(9), _propped(17)
    assert with_nodes == pytest.approx(reference, rel=2e-3)
    assert between_9 == pytest.approx(with_nodes, rel=2e-2)
    assert abs(between_17 - with_nodes) < 0.5 * abs(between_9 - with_nodes) + 1e-6 * abs(reference)
    assert between_17 == pytest.approx(reference, rel=5e-3)


def _welded_arm(nodes: int, bending: str, at: float = 0.7) -> float:
    """A rigid arm welded to a cantilever at x = ``at`` (between nodes for the meshes used),
    pushed down by 2 N at 0.2 m beyond the weld; the beam's deflection at the weld."""
    s = System("weld between nodes")
    s.material("steel", youngs_modulus=E, density=7800.0)
    s.beam("b", material="steel", start=(0, 0, 0), end=(LENGTH, 0, 0), nodes=nodes,
           section=Rectangle(WIDTH, HEIGHT), formulation="ffr", bending=bending)
    s.joint("clamp", "weld", "ground", "b", point=(0, 0, 0))
    s.rigid_body("arm", mass=1.0, inertia=(1e-3, 1e-3, 1e-3, 0, 0, 0), position=(at + 0.1, 0, 0))
    s.joint("lug", "weld", "b", "arm", point=(at, 0, 0))
    s.load("push", "force", body="arm", point=(at + 0.2, 0, 0), vector=(0, 0, -2.0))
    s.probe("lug", "b", (at, 0, 0))
    model = s.assemble()
    try:
        q = model.expand(solve_newton(model).e)
    finally:
        model.close()
    return -sum(c * q[d + 2] for d, c in model.probes["lug"].terms)


@pytest.mark.parametrize("bending, errors", [("cubic", (2e-2, 6e-3, 1e-4)),
                                             ("continuum", (0.1, 3e-2, 2e-3))])
def test_weld_between_nodes_carries_the_section(bending, errors):
    """The weld at x = 0.7 (never a node of 3, 5 or 17 equal nodes) passes the arm's force
    F and moment 0.2 F to the beam through the interpolated section: the deflection there
    converges to the cantilever's closed form F a^3/(3 EI) + M a^2/(2 EI) as the mesh is
    refined (measured: cubic -1.8%, -0.50%, -0.0009%; continuum -9.0%, -2.7%, -0.14%)."""
    a = 0.7
    expected = 2.0 * a**3 / (3 * EI) + 0.4 * a**2 / (2 * EI)
    got = [abs(_welded_arm(n, bending) / expected - 1) for n in (3, 5, 17)]
    assert all(g < bound for g, bound in zip(got, errors))
    assert got[0] > got[1] > got[2]


def _plate_strip(nx: int, ny: int, **support) -> float:
    """A steel strip 1 m x 0.2 m x 5 mm (nu = 0), clamped at x = 0 by a weld with the given
    selector, under a pressure of 100 Pa; returns the mean tip deflection (the tip corners)."""
    s = System("plate strip")
    s.material("steel", youngs_modulus=E, density=7800.0, poisson_ratio=0.0)
    s.plate("p", material="steel", thickness=0.005, corner=(0, 0, 0), edge_x=(1.0, 0, 0),
            edge_y=(0, 0.2, 0), nx=nx, ny=ny)
    s.joint("clamp", "weld", "ground", "p", **support)
    s.load("q", "pressure", body="p", value=100.0)
    s.probe("a", "p", (1.0, 0.0, 0))
    s.probe("b", "p", (1.0, 0.2, 0))
    model = s.assemble()
    try:
        q = model.expand(solve_newton(model).e)
    finally:
        model.close()
    return -np.mean([sum(c * q[d + 2] for d, c in model.probes[n].terms) for n in "ab"])


def test_plate_edge_clamp_survives_refinement():
    """edge = 'x0' holds every node of the clamped side at every mesh: the tip deflection
    converges to the plate-strip closed form q L^4 / (8 D) (D = E t^3 / 12, nu = 0) as nx
    and ny grow. Listing the coarse mesh's edge nodes instead leaves the refined mesh's new
    edge node free, and the tip then deflects 18% more (measured: edge clamp 0.99990, 0.99995,
    0.99997 of the closed form at 4 x 1, 8 x 2, 16 x 4 elements; the listed nodes 1.182)."""
    reference = 100.0 * 1.0**4 / (8 * E * 0.005**3 / 12)
    coarse = _plate_strip(4, 1, edge="x0")
    fine = _plate_strip(8, 2, edge="x0")
    boxed = _plate_strip(8, 2, box=(-0.01, -0.01, -0.01, 0.01, 0.21, 0.01))
    assert fine == pytest.approx(reference, rel=1e-2)
    assert abs(fine - reference) <= abs(coarse - reference) + 1e-6 * reference
    assert boxed == pytest.approx(fine, rel=1e-12)
    listed = _plate_strip(8, 2, point=[(0, 0, 0), (0, 0.2, 0)])   # the coarse mesh's nodes
    assert listed > fine * 1.1   # measured: 1.182 times the closed form (the free middle node)


def test_edge_and_box_refusals():
    s = System("x")
    s.material("steel", youngs_modulus=E, density=7800.0)
    s.beam("b", material="steel", start=(0, 0, 0), end=(1, 0, 0), nodes=3)
    with pytest.raises(InputError, match="joint 'c'.*edge selects a side of a plate"):
        s.joint("c", "weld", "ground", "b", edge="x0")
    with pytest.raises(InputError, match="joint 'd'.*holds no node"):
        s.joint("d", "weld", "ground", "b", box=(2, 2, 2, 3, 3, 3))
    with pytest.raises(InputError, match="joint 'e'.*edge 'z0' must be one of"):
        s.joint("e", "weld", "ground", "b", edge="z0")
    with pytest.raises(InputError, match="joint 'f'.*either point, or edge/box"):
        s.joint("f", "weld", "ground", "b", point=(0, 0, 0), box=(0, 0, 0, 1, 1, 1))


PLATE_SCENE = """
&scene  title = 'clamped strip', analysis = 'static', formulation = 'nonlinear',
        effects = 'pressure' /
&material  name = 'steel', youngs_modulus = 2.0e11, density = 7800.0, poisson_ratio = 0.0 /
&plate  name = 'p', material = 'steel', thickness = 0.005, corner = 0, 0, 0,
        edge_x = 1, 0, 0, edge_y = 0, 0.2, 0, nx = 4, ny = 1 /
&joint  name = 'clamp', type = 'weld', body1 = 'ground', body2 = 'p', edge = 'x0' /
&load  name = 'q', type = 'pressure', body = 'p', value = 100.0 /
&probe  name = 'tip', body = 'p', point = 1.0, 0.1, 0.0 /
&solver  static_method = 'newton' /
"""


def test_namelist_edge_clamp_refined_with_set(write_scene, tmp_path):
    """The namelist door: a plate clamped by edge = 'x0', refined from the command line
    (--set plate[p].ny=4): the whole edge stays clamped, the tip on the closed form."""
    import h5py

    from ancfdrv.cli import main
    scene = write_scene(PLATE_SCENE)
    out = tmp_path / "strip.h5"
    assert main(["run", str(scene), "-o", str(out), "--set", "plate[p].nx=8",
                 "--set", "plate[p].ny=4"]) == 0
    with h5py.File(out) as h5:
        tip = h5["static/probes/tip"][()]
    reference = 100.0 / (8 * E * 0.005**3 / 12)
    assert -tip[2] == pytest.approx(reference, rel=1e-3)


def _rotated(q: np.ndarray, rotation: np.ndarray, shift: np.ndarray, positions) -> np.ndarray:
    """q after the rigid motion x -> R x + shift: positions turned and shifted, gradients
    (every other 3-vector) turned."""
    out = q.reshape(-1, 3) @ rotation.T
    out[positions] += shift
    return out.ravel()


@pytest.mark.parametrize("kind", ["beam", "plate"])
def test_points_between_nodes_follow_a_rigid_motion_exactly(kind):
    """A material point between nodes (off the axis for the beam) and its directions, as a
    joint writes them: at t = 0 they are the point and the body's axes; after a rigid motion
    of the body's coordinates (a 1.1 rad turn about a skew axis and a shift) they are the
    turned point and axes, to round-off (the interpolation is exact for rigid motions)."""
    from ancfdrv.system.bodies import rotation_about
    s = System("x")
    s.material("steel", youngs_modulus=E, density=7800.0)
    if kind == "beam":
        body = s.beam("b", material="steel", start=(0, 0, 0), end=(2, 0, 0), nodes=4,
                      section=Rectangle(0.1, 0.2), height_axis=(0, 0, 1))
        point, names, axes = np.array([0.9, 0.03, -0.07]), ("r_x", "r_y", "r_z"), np.eye(3)[
            [0, 2, 1]] * [[1], [1], [-1]]
        positions = slice(None, None, 4)   # r of every node (r, r_x, r_y, r_z)
    else:
        body = s.plate("p", material="steel", thickness=0.01, corner=(0, 0, 0),
                       edge_x=(1, 0, 0), edge_y=(0, 0.5, 0), nx=3, ny=2)
        point, names, axes = np.array([0.45, 0.3, 0.0]), ("r_x", "r_y"), np.eye(3)[:2]
        positions = slice(None, None, 3)   # r of every node (r, r_x, r_y)
    body.first = 0
    q0 = body.coordinates()
    at = body.locate(point, node=False, what="test")
    assert at.node is None
    assert np.allclose(body.position(at).value(q0), point, atol=1e-14)
    for name, axis in zip(names, axes):
        assert np.allclose(body.vector(at, name).value(q0), axis, atol=1e-12)
    rotation = rotation_about((1.0, -2.0, 0.5), 1.1)
    shift = np.array([0.3, -1.0, 2.0])
    q1 = _rotated(q0, rotation, shift, positions)
    assert np.allclose(body.position(at).value(q1), rotation @ point + shift, atol=1e-12)
    for name, axis in zip(names, axes):
        assert np.allclose(body.vector(at, name).value(q1), rotation @ axis, atol=1e-12)
