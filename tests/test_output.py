"""Output conventions: a units attribute on every dataset, provenance in the root
attributes, integer counters stored as integers, and an XDMF description that is valid
XML whatever the file name and that meshio reads back to the HDF5 data."""
from __future__ import annotations

import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import numpy as np
import pytest
import scipy

import ancfdrv
from conftest import INPUTS
from ancfdrv.runner import run_scene

PROVENANCE = ("ancfdrv_version", "git_commit", "numpy_version", "scipy_version",
              "h5py_version", "hdf5_version", "mumps", "compiler", "python_version",
              "platform", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "command")


@pytest.fixture(scope="module")
def boom(tmp_path_factory) -> Path:
    """A static+dynamic boom run (4 nodes, 0.5 s)."""
    out = tmp_path_factory.mktemp("boom") / "boom.h5"
    run_scene(INPUTS / "boom_luffing.nml", ["beam.nodes=4", "solver.t_end=0.5"], out,
              progress=False)
    return out


@pytest.fixture(scope="module")
def plate(tmp_path_factory) -> Path:
    """A plate pendulum run (2 x 2 elements, 20 steps) under a name XML must escape."""
    out = tmp_path_factory.mktemp("plate") / "a&b <c> \"d\" 'e'.h5"
    run_scene(INPUTS / "plate_pendulum.nml", ["plate.nx=2", "plate.ny=2", "solver.t_end=0.02"],
              out, progress=False)
    return out


def datasets(h5: h5py.File) -> dict[str, h5py.Dataset]:
    found: dict[str, h5py.Dataset] = {}

    def visit(name: str, obj: object) -> None:  # (a value returned would stop the visit)
        if isinstance(obj, h5py.Dataset):
            found[name] = obj
    h5.visititems(visit)
    return found


@pytest.mark.parametrize("run", ["boom", "plate"])
def test_every_dataset_has_units(run, request):
    with h5py.File(request.getfixturevalue(run), "r") as h5:
        found = datasets(h5)
        assert len(found) > 20
        missing = [name for name, data in found.items() if not data.attrs.get("units")]
        assert missing == []
        units = {name: data.attrs["units"] for name, data in found.items()}
    assert units["dynamic/time"] == "s"
    assert units["dynamic/energy/total"] == "J" and units["dynamic/energy/kinetic"] == "J"
    assert units["dynamic/newton_iterations"] == "count"
    assert units["dynamic/lambda"].startswith("mixed (N")
    if run == "boom":
        assert units["dynamic/probes/tip"] == units["dynamic/deflection/tip"] == "m"
        assert units["static/deflection/tip"] == "m" and units["model/node_s"] == "m"
        assert units["static/residual_history"] == "1"
    else:
        assert units["model/nodes"] == units["dynamic/mesh_nodes"] == "m"
        assert units["model/elements"] == "index"
        # 21 frames of 9 points: the XDMF carries them inline, no per-frame view
        assert not any(name.startswith("dynamic/xdmf") for name in found)


def test_counters_are_integers(boom):
    with h5py.File(boom, "r") as h5:
        assert h5["dynamic/newton_iterations"].dtype == np.int64
        assert h5["dynamic/newton_iterations"][1:].sum() == h5["dynamic"].attrs[
            "newton_iterations"]
        for key, value in h5["counters"].attrs.items():
            assert isinstance(value, np.int64), key
        for key in ("steps", "newton_iterations", "factorizations", "jacobian_evaluations", "rows"):
            assert isinstance(h5["dynamic"].attrs[key], np.int64), key
        for key in ("iterations", "inner_iterations"):
            assert isinstance(h5["static"].attrs[key], np.int64), key
        for key in ("ndof", "nnodes", "nelements", "nconstraints"):
            assert isinstance(h5["model"].attrs[key], np.int64), key
        assert h5["dynamic"].attrs["steps"] == 500


def test_provenance(boom):
    with h5py.File(boom, "r") as h5:
        attrs = dict(h5.attrs)
    for key in PROVENANCE:
        assert key in attrs, key
    assert attrs["ancfdrv_version"] == ancfdrv.__version__
    assert attrs["numpy_version"] == np.__version__
    assert attrs["scipy_version"] == scipy.__version__
    assert attrs["h5py_version"] == h5py.__version__
    assert attrs["hdf5_version"] == h5py.version.hdf5_version
    assert attrs["python_version"] == ".".join(map(str, sys.version_info[:3]))
    assert attrs["command"]  # the command line of the process
    package = Path(ancfdrv.__file__).resolve().parent
    checkout = package.parents[1]
    git = shutil.which("git")
    if (checkout / "meson.build").is_file():   # run from the checkout: its HEAD, from git
        if git:
            head = subprocess.run([git, "rev-parse", "HEAD"], cwd=package,
                                  capture_output=True, text=True)
            if head.returncode == 0:
                assert attrs["git_commit"].split()[0] == head.stdout.strip()
    else:   # an installed package: the commit and compiler its build recorded
        from ancfdrv import _build_info
        assert attrs["git_commit"] == _build_info.GIT_COMMIT
        assert attrs["compiler"] == _build_info.COMPILER


def test_installed_provenance_starts_no_process(monkeypatch):
    """An installed package's provenance comes from its build's record
    (``ancfdrv._build_info``): no git, no gfortran started per run (issue 38)."""
    from ancfdrv.results import hdf5
    started = []
    monkeypatch.setattr(hdf5, "_source_tree", lambda: None)
    monkeypatch.setattr(hdf5, "_run", lambda command, cwd=None: started.append(command) or "")
    hdf5._static_provenance.cache_clear()
    try:
        record = hdf5.provenance()
    finally:
        hdf5._static_provenance.cache_clear()
    from ancfdrv import _build_info
    assert started == []
    assert record["git_commit"] == _build_info.GIT_COMMIT
    assert record["compiler"] == _build_info.COMPILER != ""   # the compiler's --version line


def test_xdmf_is_valid_xml_with_every_data_item_formatted(plate):
    xdmf = plate.with_suffix(".xdmf")
    root = ET.parse(xdmf).getroot()  # would raise on an unescaped '&' or '<'
    grids = root.findall("./Domain/Grid/Grid")
    texts = []
    for k, grid in enumerate(grids):
        for item in grid.findall("./*/DataItem"):
            if item.get("ItemType") == "HyperSlab":  # a later frame's geometry (ParaView)
                assert k > 0 and grid.find("./Geometry/DataItem") is item
                slab, source = list(item)
                assert slab.get("Format") == "XML" and slab.text.split()[0] == str(k)
                texts.append(source.text)
            else:                                    # all that meshio reads
                assert item.get("Format") in ("HDF", "XML")
                if item.get("Format") == "HDF":
                    texts.append(item.text)
    assert texts and all(t.startswith(plate.name + ":/") for t in texts)
    with h5py.File(plate, "r") as h5:
        assert len(grids) == len(h5["dynamic/time"]) == 21


def test_meshio_reads_the_xdmf(plate):
    meshio = pytest.importorskip("meshio")
    with h5py.File(plate, "r") as h5:
        time = h5["dynamic/time"][()]
        nodes = h5["dynamic/mesh_nodes"][()]
        reference = h5["model/mesh/points"][()]
        elements = h5["model/elements"][()]
        # the plate's nodes, then the point of the joint that holds its corner
        np.testing.assert_array_equal(reference[:-1], h5["model/nodes"][()])
        assert h5["model/mesh"].attrs["bodies"].splitlines() == [
            "plate: plate, points 0..8", "corner: joint, points 9..9"]
    with meshio.xdmf.TimeSeriesReader(plate.with_suffix(".xdmf")) as reader:
        points, cells = reader.read_points_cells()
        assert reader.num_steps == len(time)
        np.testing.assert_array_equal(points, nodes[0])
        assert cells[0].type == "quad"
        np.testing.assert_array_equal(cells[0].data, elements)
        for k in (0, len(time) - 1):
            t, point_data, _ = reader.read_data(k)
            assert t == time[k]
            np.testing.assert_array_equal(point_data["displacement"], nodes[k] - reference)
    assert np.abs(nodes[-1] - reference).max() > 1e-4  # the plate did move


def test_model_nodes_count_every_body_with_a_mesh():
    """/model nnodes (printed by ancf run as 'model  N nodes') counts the nodes of every
    flexible body: the knuckle crane's boom (9), jib (13) and rope (6), a cable included
    (a cable-only model printed '0 nodes')."""
    from ancfdrv.builders import build_system
    from ancfdrv.io.scene import load_scene
    scene = load_scene(INPUTS / "knuckle_crane_rope.nml", [])
    model = build_system(scene).system.assemble(effects=scene.effects)
    try:
        assert model.summary()["nnodes"] == 9 + 13 + 6
    finally:
        model.close()
    scene = load_scene(INPUTS / "boom_luffing_cable.nml", [])
    model = build_system(scene).system.assemble(effects=scene.effects)
    try:
        nodes = [b.nodes for b in model.bodies if getattr(b, "nodes", 0)]
        assert len(nodes) == 1 and model.summary()["nnodes"] == nodes[0] > 0
    finally:
        model.close()
