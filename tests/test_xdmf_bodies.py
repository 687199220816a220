"""The XDMF description shows every body (issue 14, item 5): beams as polylines through
their nodes, plates and leaves as quadrilaterals, rigid bodies as their centre and axes.

meshio's TimeSeriesReader reads each file back; the points are checked against quantities
computed another way: the probes the kernel records (a beam's tip, the chassis and shackle
centres), the beam's node stations, and the rigid motion of the rigid bodies' axes. The
Mixed connectivity is also parsed by the rule VTK (ParaView) follows, where a polyline
carries its node count, and must give meshio's cells.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import INPUTS
from ancfdrv.runner import run_scene

meshio = pytest.importorskip("meshio")


def read_series(xdmf: Path):
    """(points at t = 0, cells, [(t, displacement)] per frame) as meshio reads them."""
    with meshio.xdmf.TimeSeriesReader(xdmf) as reader:
        points, cells = reader.read_points_cells()
        frames = []
        for k in range(reader.num_steps):
            t, point_data, _ = reader.read_data(k)
            frames.append((t, point_data["displacement"]))
    return points, cells, frames


def vtk_cells(flat: np.ndarray) -> list[tuple[str, tuple[int, ...]]]:
    """Cells of an XDMF Mixed topology read the way VTK's XDMF 3 reader does: code 5 is a
    quad of 4 nodes; codes 1 (polyvertex), 2 (polyline) and 3 (polygon) give their node
    count first."""
    out, k = [], 0
    while k < len(flat):
        code = int(flat[k])
        k += 1
        if code == 5:
            n, kind = 4, "quad"
        elif code in (1, 2, 3):
            n, kind = int(flat[k]), {1: "vertex", 2: "line", 3: "polygon"}[code]
            k += 1
        else:
            raise AssertionError(f"unexpected cell code {code}")
        out.append((kind, tuple(int(i) for i in flat[k:k + n])))
        k += n
    return out


@pytest.fixture(scope="module")
def beam(tmp_path_factory) -> Path:
    """The luffing boom, 4 nodes, 0.5 s (500 steps), thinned to 11 frames."""
    out = tmp_path_factory.mktemp("beam") / "boom.h5"
    run_scene(INPUTS / "boom_luffing.nml", ["beam.nodes=4", "solver.t_end=0.5",
                                            "output.xdmf_frames=11"], out, progress=False)
    return out


def test_beam_is_a_polyline_through_its_nodes(beam):
    points, cells, frames = read_series(beam.with_suffix(".xdmf"))
    with h5py.File(beam) as h5:
        time = h5["dynamic/time"][()]
        tip = h5["dynamic/probes/tip"][()]
        stations = h5["model/node_s"][()]
        reference = h5["model/mesh/points"][()]
        # output.q is off: the file keeps the frames, not q of every step, and the last
        # row's q (where a run that stops between frames ends): node 3's r is the tip
        assert "q" not in h5["dynamic"]
        np.testing.assert_allclose(h5["dynamic/q_last"][36:39], tip[-1], atol=1e-14)
    # displacements from the rigid configuration at phi = 0: A1 = (0, H, 0), the axis along
    # r1 (SPEC section 5); meshio's points are the first frame's: the static equilibrium
    np.testing.assert_allclose(reference[:4], np.column_stack(
        [stations, np.full(4, 0.295), np.zeros(4)]), atol=1e-12)
    # then the tip mass at the tip, and the two supports: A1 at the root, A2 at node 2
    np.testing.assert_allclose(reference[4:], reference[[3, 0, 1]], atol=0)
    np.testing.assert_allclose(points, reference + frames[0][1], atol=1e-15)
    assert points[3][1] < 0.295 - 0.05  # the tip sags
    assert [c.type for c in cells] == ["line"]
    np.testing.assert_array_equal(cells[0].data, [[0, 1], [1, 2], [2, 3], [4, 4], [5, 5],
                                                  [6, 6]])
    # 500 steps in at most 11 frames: rows 0, 50, ..., 500
    assert [t for t, _ in frames] == pytest.approx(time[::50], abs=0) and len(frames) == 11
    for k, (t, displacement) in enumerate(frames):
        np.testing.assert_allclose(reference[3] + displacement[3], tip[50 * k], atol=1e-12)
        np.testing.assert_allclose(displacement[4], displacement[3], atol=1e-12)  # the mass
    assert np.linalg.norm(frames[-1][1][3] - frames[0][1][3]) > 0.05  # the boom luffed


def test_output_q_stores_every_step_beside_the_frames(tmp_path):
    out = tmp_path / "boom.h5"
    run_scene(INPUTS / "boom_luffing.nml", ["beam.nodes=4", "solver.t_end=0.05",
                                            "output.q=.true.", "output.xdmf_frames=6"], out,
              progress=False)
    with h5py.File(out) as h5:
        q = h5["dynamic/q"][()]
        assert q.shape == (51, h5["model"].attrs["ndof"]) and "q_last" not in h5["dynamic"]
        rows = h5["dynamic/mesh_rows"][()]
        np.testing.assert_array_equal(rows, np.arange(0, 51, 10))
        # the frames' node positions are the stored rows' r
        np.testing.assert_allclose(h5["dynamic/mesh_nodes"][:, 3, :], q[rows, 36:39],
                                   atol=1e-14)


def test_every_step_is_a_frame_up_to_the_limit(tmp_path):
    out = tmp_path / "boom.h5"
    run_scene(INPUTS / "boom_luffing.nml", ["beam.nodes=4", "solver.t_end=0.02",
                                            "scene.analysis=dynamic"], out, progress=False)
    root = ET.parse(out.with_suffix(".xdmf")).getroot()
    assert len(root.findall("./Domain/Grid/Grid")) == 21
    with h5py.File(out) as h5:
        np.testing.assert_array_equal(h5["dynamic/mesh_rows"][()], np.arange(21))


def test_no_xdmf_when_switched_off(tmp_path):
    out = tmp_path / "boom.h5"
    run_scene(INPUTS / "boom_luffing.nml", ["beam.nodes=4", "solver.t_end=0.02",
                                            "output.xdmf=.false."], out, progress=False)
    assert not out.with_suffix(".xdmf").exists()
    with h5py.File(out) as h5:
        assert "mesh_nodes" not in h5["dynamic"] and "q" not in h5["dynamic"]


def test_plate_is_quadrilaterals(tmp_path):
    out = tmp_path / "plate.h5"
    run_scene(INPUTS / "plate_pendulum.nml", ["plate.nx=2", "plate.ny=2", "solver.t_end=0.02"],
              out, progress=False)
    points, cells, frames = read_series(out.with_suffix(".xdmf"))
    with h5py.File(out) as h5:
        corner = h5["dynamic/probes/corner"][()]
        np.testing.assert_array_equal(cells[0].data, h5["model/elements"][()])
        assert h5["model/mesh"].attrs["bodies"].splitlines() == [
            "plate: plate, points 0..8", "corner: joint, points 9..9"]
    # the quads, then the joint at the held corner: a line from its point to itself
    assert [(c.type, len(c.data)) for c in cells] == [("quad", 4), ("line", 1)]
    np.testing.assert_array_equal(cells[1].data, [[9, 9]])
    np.testing.assert_allclose(points[9], 0.0, atol=1e-15)
    assert len(frames) == 21
    at = int(np.argmin(np.linalg.norm(points - [0.3, 0.3, 0.0], axis=1)))
    np.testing.assert_allclose(points[at], [0.3, 0.3, 0.0], atol=1e-15)
    for k, (_, displacement) in enumerate(frames):
        np.testing.assert_allclose(points[at] + displacement[at], corner[k], atol=1e-12)
        np.testing.assert_allclose(displacement[9], 0.0, atol=1e-12)  # the held corner
    assert displacement[at][2] < -1e-4  # it falls


@pytest.fixture(scope="module")
def spring(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("spring") / "spring.h5"
    run_scene(INPUTS / "leaf_spring.nml", ["solver.t_end=0.01"], out, progress=False)
    return out


def test_leaf_spring_shows_leaves_chassis_and_shackle(spring):
    points, cells, frames = read_series(spring.with_suffix(".xdmf"))
    with h5py.File(spring) as h5:
        mesh = h5["model/mesh"]
        assert mesh.attrs["topology_type"] == "Mixed"
        flat = mesh["topology"][()]
        bodies = mesh.attrs["bodies"].splitlines()
        reference = h5["model/mesh/points"][()]
        chassis = h5["dynamic/probes/chassis"][()]
        shackle = h5["dynamic/probes/shackle"][()]
    # leaves 12 x 1 and 8 x 1 elements (13 x 2 and 9 x 2 nodes), two rigid bodies of 12
    # points (centre, 3 axis tips, 8 box corners), then the joints' 13 points
    assert len(points) == 26 + 18 + 24 + 13
    # 3 axes and 12 box edges per rigid body, and a line from each joint point to itself
    assert [(c.type, len(c.data)) for c in cells] == [("quad", 20), ("line", 30 + 13)]
    assert vtk_cells(flat) == [("quad", tuple(c)) for c in cells[0].data] + \
        [("line", tuple(c)) for c in cells[1].data]
    assert [b.split(":")[0] for b in bodies[:4]] == ["main", "lower", "chassis", "shackle"]
    assert all(": joint, points " in b for b in bodies[4:]) and len(bodies) == 11
    lone = cells[1].data[30:]
    np.testing.assert_array_equal(lone[:, 0], lone[:, 1])
    np.testing.assert_array_equal(lone[:, 0], np.arange(68, 81))
    centres = {}
    for line in bodies[2:4]:
        name, rest = line.split(": rigid body, points ")
        centres[name] = int(rest.split("..")[0])
    assert len(frames) == 11
    # the first frame's points: the settled start, displaced from the assembled mesh
    np.testing.assert_allclose(points, reference + frames[0][1], rtol=0, atol=1e-12)
    assert np.abs(frames[0][1]).max() > 1e-3
    for k, (_, displacement) in enumerate(frames):
        now = reference + displacement
        np.testing.assert_allclose(now[centres["chassis"]], chassis[k], atol=1e-12)
        # the shackle probe is its centre (the link's middle)
        np.testing.assert_allclose(now[centres["shackle"]], shackle[k], atol=1e-12)
        for name, c in centres.items():  # the axes move rigidly: orthogonal, same lengths
            axes = now[c + 1:c + 4] - now[c]
            axes0 = points[c + 1:c + 4] - points[c]
            np.testing.assert_allclose(axes @ axes.T, axes0 @ axes0.T, atol=1e-9)
            # and so do the box corners: their distances to each other and to the centre
            box, box0 = now[c:c + 12], points[c:c + 12]
            np.testing.assert_allclose(np.linalg.norm(box[:, None] - box[None], axis=2),
                                       np.linalg.norm(box0[:, None] - box0[None], axis=2),
                                       atol=1e-9)
    # in the assembled mesh the axes are the global axes, as long as the radius of gyration
    # (the settled chassis has pitched by 8e-5 rad)
    axes0 = reference[centres["chassis"] + 1:centres["chassis"] + 4] \
        - reference[centres["chassis"]]
    np.testing.assert_allclose(axes0, np.sqrt(3 * 50.0 / (2 * 500.0)) * np.eye(3), atol=1e-12)
    # its inertia box: a cube (I = 50 kg m^2 about every axis, 500 kg) of half-size a,
    # I = m (a^2 + a^2) / 3: the corners at the centre +- a along the global axes
    a = np.sqrt(3 * 50.0 / (2 * 500.0))
    corners = reference[centres["chassis"] + 4:centres["chassis"] + 12] \
        - reference[centres["chassis"]]
    np.testing.assert_allclose(np.abs(corners), a, atol=1e-12)
    assert len({tuple(np.sign(c)) for c in corners}) == 8
    assert np.abs(frames[-1][1]).max() > 1e-6  # it moved


def test_sweep_cases_have_xdmf_naming_their_final_file(tmp_path):
    """A sweep writes each case to a hidden part file and then moves it: the XDMF beside
    the final file refers to the final file, and no part file remains."""
    from ancfdrv.sweep import run_sweep
    out = tmp_path / "sweep"
    rows = run_sweep(str(INPUTS / "boom_luffing.nml"), ["beam.nodes=4,7"], out,
                     base=["solver.t_end=0.01"], workers=1, progress=False)
    assert [r["status"] for r in rows] == ["ok", "ok"]
    for row in rows:
        h5_path = Path(row["file"])
        root = ET.parse(h5_path.with_suffix(".xdmf")).getroot()
        texts = {item.text.split(":")[0] for item in root.iter("DataItem")
                 if item.get("Format") == "HDF"}
        assert texts == {h5_path.name}
        points, cells, frames = read_series(h5_path.with_suffix(".xdmf"))
        assert len(frames) == 11 and cells[0].type == "line"
    assert not list(out.glob(".*"))


def test_a_failed_run_ends_its_motion_at_the_last_step(tmp_path):
    """A run that fails between frames (exit 3 here) still shows its last computed step."""
    from ancfdrv.errors import SolverError
    out = tmp_path / "failed.h5"
    with pytest.raises(SolverError):
        run_scene(INPUTS / "hard" / "newton_failure.nml",
                  ["output.xdmf_frames=101"], out, progress=False)
    with h5py.File(out) as h5:
        time = h5["dynamic/time"][()]
        rows = h5["dynamic/mesh_rows"][()]
        tip = h5["dynamic/probes/tip"][-1]
        reference = h5["model/mesh/points"][()]
        (_, boom), = [part for part in mesh_parts(h5).values() if part[0] == "beam"]
        assert h5.attrs["status"] == "failed"
    # 10001 rows planned in at most 101 frames: every 100th row; the run failed between two
    assert len(time) % 100 != 1
    np.testing.assert_array_equal(rows, list(range(0, len(time), 100)) + [len(time) - 1])
    _, _, frames = read_series(out.with_suffix(".xdmf"))
    assert frames[-1][0] == time[-1]
    np.testing.assert_allclose(reference[boom[-1]] + frames[-1][1][boom[-1]], tip,
                               atol=1e-12)  # the tip


# -- the whole machine: rope, payload, cylinders, joints, rigid bodies' inertia boxes -------

def mesh_parts(h5: h5py.File) -> dict[str, tuple[str, range]]:
    """/model/mesh's 'bodies' lines 'name: kind, points a..b' as {name: (kind, points)}."""
    out = {}
    for line in str(h5["model/mesh"].attrs["bodies"]).splitlines():
        name, _, rest = line.rpartition(": ")
        kind, _, points = rest.partition(", points ")
        first, last = (int(v) for v in points.split(".."))
        out[name] = (kind, range(first, last + 1))
    return out


@pytest.fixture(scope="module")
def crane(tmp_path_factory) -> Path:
    """The shipped knuckle crane with its rope and payload: four modes about its static
    equilibrium (the same mesh as its dynamic run's)."""
    out = tmp_path_factory.mktemp("crane") / "crane.h5"
    run_scene(INPUTS / "knuckle_crane_rope.nml", ["scene.analysis=modal", "modal.modes=4"],
              out, progress=False)
    return out


def test_crane_shows_rope_payload_cylinders_and_joints(crane):
    with h5py.File(crane) as h5:
        parts = mesh_parts(h5)
        reference = h5["model/mesh/points"][()]
        static = h5["modal/mesh_static"][()]
        shapes = h5["modal/mesh_shapes"][()]
        probes = {name: h5[f"static/probes/{name}"][()] for name in h5["static/probes"]}
        assert h5["model/mesh"].attrs["topology_type"] == "Polyline"
    assert {name: kind for name, (kind, _) in parts.items()} == {
        "boom": "beam", "jib": "beam", "rope": "cable", "jib cylinder": "force element",
        "payload": "point mass", "column pin": "joint", "main cylinder": "joint",
        "knuckle": "joint", "rope top": "joint"}
    size = float(np.ptp(reference, axis=0).max())
    tol = 1e-12 * size

    def at(name: str) -> np.ndarray:
        return static[list(parts[name][1])]

    # the payload hangs at the rope's end: at the static state the hook probe's position
    (payload,) = at("payload")
    assert len(parts["rope"][1]) == 6 and len(parts["payload"][1]) == 1
    np.testing.assert_allclose(payload, probes["hook"], rtol=0, atol=tol)
    np.testing.assert_allclose(payload, static[parts["rope"][1][-1]], rtol=0, atol=tol)
    assert payload[1] < 1.550205906488627 - 0.01  # the rope stretched and the jib sagged
    # the cylinder's line joins its lugs on the boom and on the jib
    np.testing.assert_allclose(at("jib cylinder"), [probes["boom lug"], probes["jib lug"]],
                               rtol=0, atol=tol)
    # the rigid main cylinder (a distance joint) from its ground point keeps its length
    ground, lug = at("main cylinder")
    np.testing.assert_allclose(ground, [1.2, 1.7, 0.0], rtol=0, atol=tol)
    length0 = np.linalg.norm(np.subtract([1.149066664678467, 2.964181414529809, 0.0],
                                         [1.2, 1.7, 0.0]))
    assert np.linalg.norm(lug - ground) == pytest.approx(length0, rel=1e-9)
    # the pins are where the probes on the bodies they hold are
    np.testing.assert_allclose(at("knuckle"), [probes["knuckle"]], rtol=0, atol=tol)
    np.testing.assert_allclose(at("rope top"), [probes["jib tip"]], rtol=0, atol=tol)
    np.testing.assert_allclose(at("column pin"), [[0.0, 2.0, 0.0]], rtol=0, atol=tol)
    # in every mode the payload moves with the rope's end; one mode is the payload's swing
    # (its largest displacement at the payload, the jib tip nearly still)
    end = parts["rope"][1][-1]
    np.testing.assert_allclose(shapes[:, parts["payload"][1][0]], shapes[:, end], atol=1e-12)
    swing = np.abs(shapes[:, end]).max(axis=1)  # shapes: largest component 1
    tip = np.abs(shapes[:, parts["rope top"][1][0]]).max(axis=1)
    k = int(np.argmax(swing - tip))
    assert swing[k] == pytest.approx(1.0, abs=1e-12) and tip[k] < 0.1


def test_crane_xdmf_opens_in_meshio_with_every_part(crane):
    """meshio reads the modes' XDMF: each lone point is a line from a point to itself, the
    force element and the distance joint are lines between their points."""
    mesh = meshio.read(crane.with_suffix(".xdmf"))
    with h5py.File(crane) as h5:
        parts = mesh_parts(h5)
        static = h5["modal/mesh_static"][()]
    np.testing.assert_allclose(mesh.points, static, atol=0)
    assert [c.type for c in mesh.cells] == ["line"]
    cells = {tuple(c) for c in mesh.cells[0].data}
    for name in ("payload", "column pin", "knuckle", "rope top"):
        (point,) = parts[name][1]
        assert (point, point) in cells, name
    for name in ("jib cylinder", "main cylinder"):
        assert tuple(parts[name][1]) in cells, name
    # beams 8 + 12 elements, rope 5, two lines, four lone points
    assert len(cells) == 8 + 12 + 5 + 2 + 4
    assert sorted(mesh.point_data) == ["mode_1", "mode_2", "mode_3", "mode_4"]


def test_crane_mode_plot_and_animation_show_the_payload(crane, tmp_path):
    """The mode plot is a PNG of four panels; the payload and the pins are drawn as
    markers (single-point segments), and the animation's frames move the payload with its
    mode shape."""
    from PIL import Image

    from ancfdrv.animate import _frames
    from ancfdrv.plots import _mesh_segments, plot_modes
    png = plot_modes(crane, tmp_path / "modes.png")
    with Image.open(png) as image:
        width, height = image.size
    assert png.stat().st_size > 20_000
    assert (width, height) == (round(4 * 3.2 * 110), round(3.2 * 110))
    with h5py.File(crane) as h5:
        parts = mesh_parts(h5)
        segments = _mesh_segments(h5)
        frames, labels, _ = _frames(h5, crane, 2)
        static = h5["modal/mesh_static"][()]
        shape = h5["modal/mesh_shapes"][1]
    lone = sorted(int(s[0]) for s in segments if len(s) == 1)
    assert lone == [parts[n][1][0] for n in ("payload", "column pin", "knuckle", "rope top")]
    (payload,) = parts["payload"][1]
    size = float(np.ptp(static, axis=0).max())
    phase = np.sin(2 * np.pi * np.arange(len(frames)) / len(frames))
    np.testing.assert_allclose(frames[:, payload], static[payload]
                               + 0.1 * size * phase[:, None] * shape[payload], atol=1e-12)
    assert np.ptp(frames[:, payload], axis=0).max() > 0.05 * size


def test_rigid_body_box_has_its_inertia_and_moves_rigidly():
    """A rigid body whose inertia is a 0.6 x 0.4 x 0.2 m box's of 12 kg turned by Q: its
    mesh box has those half-sizes along Q's columns; under a large rotation R (2 rad about
    (1, 2, 3)) and a shift the corners are r + R (corner0 - c), their mutual distances
    unchanged, and the axes are R's columns times the radius of gyration."""
    from ancfdrv import System
    from ancfdrv.results.xdmf import MeshLayout
    from ancfdrv.system.bodies import rotation_about
    mass, half = 12.0, np.array([0.3, 0.2, 0.1])
    principal = mass / 3.0 * np.array([half[1] ** 2 + half[2] ** 2, half[0] ** 2 + half[2] ** 2,
                                       half[0] ** 2 + half[1] ** 2])
    turn = rotation_about(np.array([0.0, 0.0, 1.0]), 0.5) @ \
        rotation_about(np.array([1.0, 0.0, 0.0]), 0.3)
    inertia = turn @ np.diag(principal) @ turn.T
    centre = np.array([1.0, -2.0, 0.5])
    s = System("box")
    s.rigid_body("block", mass=mass, inertia=inertia, position=centre)
    model = s.assemble()
    try:
        layout = MeshLayout.from_model(model)
        assert layout.bodies == ["block: rigid body, points 0..11"]
        signs = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)])
        corners0 = layout.points[4:12]
        expected = centre + (signs * half) @ turn.T
        # the same 8 corners (each principal axis's sign is the eigensolver's choice)
        order = [int(np.argmin(np.linalg.norm(expected - c, axis=1))) for c in corners0]
        assert sorted(order) == list(range(8))
        np.testing.assert_allclose(corners0, expected[order], atol=1e-12)
        # its 12 edges join corners one box edge apart
        edges = layout.lines[3:]
        lengths = sorted(np.round(np.linalg.norm(layout.points[edges[:, 0]]
                                                 - layout.points[edges[:, 1]], axis=1), 12))
        assert lengths == sorted(list(2 * half) * 4)
        rotation = rotation_about(np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0), 2.0)
        q = model.q0.copy()
        body = model.bodies[0]
        shift = np.array([0.4, 0.1, -0.7])
        q[body.first:body.first + 3] = centre + shift
        for k in range(3):
            q[body.first + 3 * (k + 1):body.first + 3 * (k + 2)] = rotation[:, k]
        moved = layout.positions(model, model.reduce(q))[0]
        np.testing.assert_allclose(moved[4:12], centre + shift + (corners0 - centre)
                                   @ rotation.T, atol=1e-12)
        distances = np.linalg.norm(moved[:, None] - moved[None], axis=2)
        distances0 = np.linalg.norm(layout.points[:, None] - layout.points[None], axis=2)
        np.testing.assert_allclose(distances, distances0, atol=1e-12)
        gyration = np.sqrt(principal.sum() / (2 * mass))
        np.testing.assert_allclose(moved[1:4] - moved[0], gyration * rotation.T, atol=1e-12)
    finally:
        model.close()


def test_static_run_writes_the_state_as_xdmf(tmp_path):
    """A static run's XDMF: one grid at the static state with its displacement from the
    undeformed mesh; the payload sits at the hook probe; output.xdmf = .false. writes none."""
    out = tmp_path / "crane.h5"
    run_scene(INPUTS / "knuckle_crane_rope.nml", ["scene.analysis=static"], out,
              progress=False)
    mesh = meshio.read(out.with_suffix(".xdmf"))
    with h5py.File(out) as h5:
        parts = mesh_parts(h5)
        reference = h5["model/mesh/points"][()]
        hook = h5["static/probes/hook"][()]
        assert "dynamic" not in h5 and "modal" not in h5
    (payload,) = parts["payload"][1]
    np.testing.assert_allclose(mesh.points[payload], hook, rtol=0, atol=1e-12)
    np.testing.assert_allclose(mesh.points, reference + mesh.point_data["displacement"],
                               rtol=0, atol=1e-14)
    assert mesh.point_data["displacement"][payload][1] < -0.01  # it hangs lower
    assert len(mesh.cells[0].data) == 8 + 12 + 5 + 2 + 4
    # the same run kept in memory writes the same XDMF (naming its own file) on save
    import ancfdrv
    saved = ancfdrv.simulate(INPUTS / "knuckle_crane_rope.nml", ["scene.analysis=static"],
                             progress=False).save(tmp_path / "memory.h5")
    assert saved.with_suffix(".xdmf").read_text() == \
        out.with_suffix(".xdmf").read_text().replace("crane.h5", "memory.h5")
    # and Results.save writes it beside the copy, naming the copy
    copy = ancfdrv.open(out).save(tmp_path / "copy.h5", plot=False)
    assert copy.with_suffix(".xdmf").read_text() == \
        out.with_suffix(".xdmf").read_text().replace("crane.h5", "copy.h5")
    quiet = tmp_path / "quiet.h5"
    run_scene(INPUTS / "knuckle_crane_rope.nml", ["scene.analysis=static", "output.xdmf=.false."],
              quiet, progress=False)
    assert quiet.is_file() and not quiet.with_suffix(".xdmf").exists()


def test_saved_modal_result_keeps_its_shapes_xdmf(crane, tmp_path):
    """Results.save of a modal result writes the shapes' XDMF beside the copy."""
    import ancfdrv
    copy = ancfdrv.open(crane).save(tmp_path / "copy.h5", plot=False)
    assert copy.with_suffix(".xdmf").read_text() == \
        crane.with_suffix(".xdmf").read_text().replace("crane.h5", "copy.h5")


def values(item: ET.Element, h5: h5py.File) -> np.ndarray:
    """A DataItem's values as the XDMF model defines them (what ParaView reads): inline
    text (Format XML), a plain HDF item's dataset, or a HyperSlab's rows (its first child
    the start, stride and count per dimension, its second the dataset)."""
    dims = [int(d) for d in item.get("Dimensions").split()]
    if item.get("ItemType") == "HyperSlab":
        slab, source = list(item)
        assert slab.get("Format") == "XML" and source.get("Format") == "HDF"
        start, stride, count = np.array(slab.text.split(), dtype=int).reshape(3, -1)
        data = values(source, h5)
        assert dims == list(count)
        return data[tuple(slice(a, a + s * (n - 1) + 1, s)
                          for a, s, n in zip(start, stride, count))]
    if item.get("Format") == "XML":
        return np.array([float(v) for v in item.text.split()]).reshape(dims)
    assert item.get("Format") == "HDF"
    data = h5[item.text.split(":", 1)[1]][()]
    assert list(data.shape) == dims
    return data


@pytest.mark.parametrize("views", [False, True], ids=["inline", "views"])
def test_every_frame_gives_its_row_of_the_stored_positions(views, tmp_path, monkeypatch):
    """ParaView reads each frame's Geometry item, meshio the first frame's points and each
    frame's displacement: both must give /dynamic/mesh_nodes of that frame, at its time,
    exactly. 11 frames of 4 points are carried inline; with the inline limit at 0 the
    same series names one view per frame (the displacement meshio reads), not two."""
    from ancfdrv.results import xdmf
    if views:
        monkeypatch.setattr(xdmf, "INLINE_VALUES", 0)
    out = tmp_path / "boom.h5"
    run_scene(INPUTS / "boom_luffing.nml", ["beam.nodes=4", "solver.t_end=0.5",
                                            "output.xdmf_frames=11"], out, progress=False)
    grids = ET.parse(out.with_suffix(".xdmf")).getroot().findall("./Domain/Grid/Grid")
    points, _, frames = read_series(out.with_suffix(".xdmf"))
    with h5py.File(out) as h5:
        nodes = h5["dynamic/mesh_nodes"][()]
        shifts = h5["dynamic/mesh_displacement"][()]
        times = h5["dynamic/time"][()][h5["dynamic/mesh_rows"][()]]
        assert len(grids) == len(frames) == len(nodes) == 11
        for k, grid in enumerate(grids):
            np.testing.assert_array_equal(
                values(grid.find("./Geometry/DataItem"), h5).reshape(-1, 3), nodes[k])
            np.testing.assert_array_equal(
                values(grid.find("./Attribute[@Name='displacement']/DataItem"), h5),
                shifts[k])
            assert float(grid.find("Time").get("Value")) == times[k]
        if views:
            assert list(h5["dynamic/xdmf/position"]) == ["0"]
            assert len(h5["dynamic/xdmf/displacement"]) == 11
        else:
            assert "xdmf" not in h5["dynamic"]
    np.testing.assert_array_equal(points, nodes[0])
    assert [t for t, _ in frames] == list(times)
    for k in range(len(frames)):
        np.testing.assert_array_equal(frames[k][1], shifts[k])


def test_rewriting_the_description_makes_only_the_missing_views(tmp_path, monkeypatch):
    """write_xdmf on a file whose views are partly missing (an older or stopped file)
    makes the missing ones, each the row of its frame, and names all of them."""
    from ancfdrv.results import xdmf
    monkeypatch.setattr(xdmf, "INLINE_VALUES", 0)
    out = tmp_path / "boom.h5"
    run_scene(INPUTS / "boom_luffing.nml", ["beam.nodes=4", "solver.t_end=0.05",
                                            "output.xdmf_frames=6"], out, progress=False)
    with h5py.File(out, "a") as h5:
        for k in ("0", "2", "5"):
            del h5[f"dynamic/xdmf/displacement/{k}"]
        del h5["dynamic/xdmf/position/0"]
        assert len(h5["dynamic/xdmf/displacement"]) == 3
    out.with_suffix(".xdmf").unlink()
    xdmf.write_xdmf(out)
    points, _, frames = read_series(out.with_suffix(".xdmf"))
    grids = ET.parse(out.with_suffix(".xdmf")).getroot().findall("./Domain/Grid/Grid")
    with h5py.File(out) as h5:
        nodes = h5["dynamic/mesh_nodes"][()]
        shifts = h5["dynamic/mesh_displacement"][()]
        assert list(h5["dynamic/xdmf/position"]) == ["0"]
        assert sorted(h5["dynamic/xdmf/displacement"], key=int) == [str(k) for k in range(6)]
        for k in range(6):
            np.testing.assert_array_equal(h5[f"dynamic/xdmf/displacement/{k}"][()], shifts[k])
            assert h5[f"dynamic/xdmf/displacement/{k}"].attrs["units"] == "m"
            np.testing.assert_array_equal(
                values(grids[k].find("./Geometry/DataItem"), h5).reshape(-1, 3), nodes[k])
        assert h5["dynamic/xdmf/position/0"].attrs["units"] == "m"
    assert len(frames) == 6
    np.testing.assert_array_equal(points, nodes[0])


def test_a_run_with_its_description_opens_its_file_three_times(tmp_path, monkeypatch):
    """The description is made in the run's last opening of its file (it was closed and
    opened once more for it): create; static results and the dynamic set-up; the rows,
    the status and the description (tests/test_fixed_cost.py counts the same without it)."""
    opened = []
    real = h5py.File

    class Counted(real):
        def __init__(self, name, mode="r", *args, **kwargs):
            opened.append((Path(name).name, mode))
            super().__init__(name, mode, *args, **kwargs)
    monkeypatch.setattr(h5py, "File", Counted)
    out = tmp_path / "boom.h5"
    run_scene(INPUTS / "boom_luffing.nml", ["beam.nodes=4", "solver.t_end=0.05"], out,
              progress=False)
    monkeypatch.undo()
    assert opened == [("boom.h5", "w-"), ("boom.h5", "a"), ("boom.h5", "a")]
    assert out.with_suffix(".xdmf").exists()
