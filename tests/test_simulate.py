"""ancfdrv.simulate: a scene run with its results kept in memory (ancfdrv.simulation,
ancfdrv.results.memory). The reference of every check is the file run_scene writes for
the same scene, an independent path through the HDF5 writer: the in-memory series must
equal the file's bit for bit, Simulation.save must write that file again (every dataset
and attribute but wall times, timings and time stamps), and a failed run must keep the
rows the failed run's file keeps."""
from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest

import ancfdrv
from ancfdrv.errors import InputError, SolverError
from ancfdrv.runner import run_scene

ROOT = Path(__file__).resolve().parents[1]
INPUTS = ROOT / "inputs"
PENDULUM = (INPUTS / "hard" / "pendulum.nml",
            ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy", "solver.dt=1e-3",
             "solver.t_end=0.05"])

#: attributes that say when or how long (h5_compare's rule), not what was computed
VOLATILE = {"wall_time_s", "git_commit", "command", "created", "finished"}


def _volatile(key: str) -> bool:
    return key in VOLATILE or "wall" in key or "time_s" in key or (
        key.startswith("time_") and key.endswith("_s"))


def _content(path: Path) -> dict[str, object]:
    """Every dataset (value, dtype, shape) and attribute of a result file outside /timing,
    without the volatile attributes (benchmarks/h5_compare.py's rule)."""
    out: dict[str, object] = {}

    def attrs(name: str, obj) -> None:
        for key, value in obj.attrs.items():
            if not _volatile(key):
                out[f"{name}@{key}"] = value

    with h5py.File(path, "r") as h5:
        attrs("", h5)

        def visit(name: str, obj) -> None:
            if name.startswith("timing"):
                return
            if isinstance(obj, h5py.Dataset):
                out[name] = obj[()]
            attrs(name, obj)
        h5.visititems(visit)
    return out


def _assert_same_files(a: Path, b: Path) -> None:
    first, second = _content(a), _content(b)
    assert sorted(first) == sorted(second)
    for key, value in first.items():
        x, y = np.asarray(value), np.asarray(second[key])
        assert x.dtype == y.dtype and x.shape == y.shape, key
        assert x.tobytes() == y.tobytes() if x.dtype.kind in "fc" else np.array_equal(x, y), key


def _assert_series_equal_file(sim, path: Path) -> int:
    """Every /dynamic row series of the file equals the Simulation's, bit for bit (the
    same names, dtypes and shapes); returns how many were compared."""
    with h5py.File(path, "r") as h5:
        names = []

        def visit(name: str, obj) -> None:
            if isinstance(obj, h5py.Dataset) and obj.ndim and len(obj) == len(h5["dynamic/time"]):
                names.append(name)
        h5["dynamic"].visititems(visit)
        # the answers, support deflections and XDMF frames are not row series of the writer
        rows = [n for n in names if not n.startswith(("reactions/", "sections/", "tension/",
                                                      "mesh_", "deflection_support/"))]
        assert sorted(rows) == sim.names
        for name in rows:
            expected, got = h5["dynamic"][name][()], sim.series(name)
            assert got.dtype == expected.dtype and got.shape == expected.shape, name
            assert got.tobytes() == expected.tobytes(), name
    return len(rows)


def _run_both(tmp_path: Path, scene: Path, overrides: list[str]):
    """The scene through simulate and through run_scene (its file), and the file save
    writes."""
    sim = ancfdrv.simulate(scene, overrides, progress=False)
    outcome = run_scene(scene, overrides, tmp_path / "run.h5", progress=False)
    saved = sim.save(tmp_path / "saved.h5")
    return sim, outcome, tmp_path / "run.h5", saved


def test_pendulum_cable_planar_in_memory_equals_file(tmp_path):
    sim, outcome, path, saved = _run_both(tmp_path, *PENDULUM)
    assert sim.status == "ok" and len(sim.time) == 51
    assert _assert_series_equal_file(sim, path) >= 20
    with h5py.File(path, "r") as h5:
        assert sim.probe("tip").tobytes() == h5["dynamic/probes/tip"][()].tobytes()
        assert sim.deflection("tip").shape == (51, 3)
        force = h5["dynamic/reactions"]
        joint = sorted(force)[0]
        assert sim.reaction(joint)["force"].tobytes() == force[joint]["force"][()].tobytes()
        assert sim.attrs["steps"] == h5["dynamic"].attrs["steps"] == 50
    # the statistics are the run's (the same count run_scene's stepper made)
    assert sim.dynamic.newton_iterations == outcome.dynamic.newton_iterations
    assert int(sim.series("newton_iterations").sum()) == sim.dynamic.newton_iterations
    assert sim.q is None and sim.q_last is not None
    _assert_same_files(path, saved)


def test_output_q_kept_in_memory(tmp_path):
    scene, sets = PENDULUM
    sim, _, path, saved = _run_both(tmp_path, scene, [*sets, "output.q=true"])
    with h5py.File(path, "r") as h5:
        assert sim.q.tobytes() == h5["dynamic/q"][()].tobytes()
    assert np.array_equal(sim.q_last, sim.q[-1])
    _assert_same_files(path, saved)


def test_boom_ffr_static_start_and_answers(tmp_path):
    sim, _, path, saved = _run_both(tmp_path, INPUTS / "boom_luffing.nml",
                                    ["beam.nodes=4", "solver.t_end=0.05"])
    assert sim.static is not None and sim.static_answers is not None
    _assert_series_equal_file(sim, path)
    with h5py.File(path, "r") as h5:
        assert sim.static.e.tobytes() == h5["static/q"][()].tobytes()
        assert sim.static_probe("tip").tobytes() == h5["static/probes/tip"][()].tobytes()
        beam = sorted(h5["dynamic/stress"])[0]
        envelope = sim.stress_envelope(beam)
        assert envelope["von_mises_max"].tobytes() == \
            h5["dynamic/stress"][beam]["von_mises_max"][()].tobytes()
    _assert_same_files(path, saved)


def test_static_scene(tmp_path):
    sim, _, path, saved = _run_both(tmp_path, INPUTS / "boom_static.nml", [])
    assert len(sim.time) == 0 and sim.dynamic is None and sim.names == []
    with h5py.File(path, "r") as h5:
        assert sim.static.e.tobytes() == h5["static/q"][()].tobytes()
        stress = sim.static_answers.stress
        name = sorted(stress)[0]
        assert stress[name].von_mises.tobytes() == \
            h5["static/stress"][name]["von_mises"][()].tobytes()
    _assert_same_files(path, saved)


def test_general_scene_with_force_element_answers(tmp_path):
    sim, _, path, saved = _run_both(tmp_path, INPUTS / "general" / "boom_mounts.nml",
                                    ["solver.t_end=0.02"])
    _assert_series_equal_file(sim, path)
    assert "cylinder" in sim.reactions
    with h5py.File(path, "r") as h5:
        assert sim.reaction("cylinder")["axial"].tobytes() == \
            h5["dynamic/reactions/cylinder/axial"][()].tobytes()
    _assert_same_files(path, saved)


def test_general_scene_support_deflections(tmp_path):
    sim, _, path, saved = _run_both(tmp_path, INPUTS / "general" / "boom_luffing.nml",
                                    ["solver.t_end=0.05"])
    _assert_series_equal_file(sim, path)
    with h5py.File(path, "r") as h5:
        names = sorted(h5["dynamic/deflection_support"])
        assert names
        for name in names:
            assert sim.deflection_support(name).tobytes() == \
                h5["dynamic/deflection_support"][name][()].tobytes()
            assert sim.deflection_support(name, "static").tobytes() == \
                h5["static/deflection_support"][name][()].tobytes()
    _assert_same_files(path, saved)


def test_plate_frames_saved_as_run_scene_writes_them(tmp_path):
    """The XDMF frames (the file alone needs them: their points are computed by save from
    the kept rows of q) equal run_scene's."""
    sim, _, path, saved = _run_both(tmp_path, INPUTS / "plate_pendulum.nml",
                                    ["solver.t_end=0.002"])
    with h5py.File(saved, "r") as h5:
        assert len(h5["dynamic/mesh_nodes"]) > 1
    assert saved.with_suffix(".xdmf").exists()
    _assert_same_files(path, saved)


def test_modal_analysis(tmp_path):
    sim, _, path, saved = _run_both(tmp_path, INPUTS / "crane_boom_modes.nml", [])
    with h5py.File(path, "r") as h5:
        assert sim.modal.frequency.tobytes() == h5["modal/frequency"][()].tobytes()
    _assert_same_files(path, saved)


def test_failed_newton_keeps_the_rows(tmp_path):
    """inputs/hard/newton_failure.nml fails at t = 0.95 s: the SolverError carries the
    Simulation, whose rows are the failed run's file's rows, and save writes that file."""
    scene = INPUTS / "hard" / "newton_failure.nml"
    with pytest.raises(SolverError) as caught:
        ancfdrv.simulate(scene, progress=False)
    with pytest.raises(SolverError) as in_file:
        run_scene(scene, [], tmp_path / "run.h5", progress=False)
    assert str(caught.value) == str(in_file.value)
    sim = caught.value.simulation
    assert sim.status == "failed" and sim.dynamic is None
    assert sim.time[-1] == pytest.approx(0.950) and len(sim.time) == 951
    _assert_series_equal_file(sim, tmp_path / "run.h5")
    _assert_same_files(tmp_path / "run.h5", sim.save(tmp_path / "saved.h5"))


def test_bad_input_names_the_key():
    scene, sets = PENDULUM
    with pytest.raises(InputError) as caught:
        ancfdrv.simulate(scene, [*sets, "beam.nodez=5"])
    assert "nodez" in str(caught.value) and caught.value.group == "beam"
    assert not hasattr(caught.value, "simulation")   # refused before anything ran


def test_save_refuses_an_existing_file_and_input_files(tmp_path):
    scene, sets = PENDULUM
    sim = ancfdrv.simulate(scene, sets, progress=False)
    path = sim.save(tmp_path / "a.h5")
    with pytest.raises(InputError, match="exists"):
        sim.save(path)
    assert sim.save(path, replace=True) == path
    with pytest.raises(InputError):
        sim.save(scene, replace=True)     # never over the scene it ran
    assert scene.read_text().startswith("!") or "&scene" in scene.read_text()


def test_a_failed_replacing_save_keeps_the_old_file(tmp_path, monkeypatch):
    """save(replace=True) writes the new file beside the old one and moves it over only
    when complete: a write that fails half-way leaves the old result byte for byte, and
    no staging file behind."""
    from ancfdrv.results import hdf5
    scene, sets = PENDULUM
    sim = ancfdrv.simulate(scene, sets, progress=False)
    path = sim.save(tmp_path / "a.h5")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}   # a.h5 and its a.xdmf

    def fail(*args, **kwargs):
        raise OSError("disk gone")
    monkeypatch.setattr(hdf5, "finish", fail)
    with pytest.raises(OSError, match="disk gone"):
        sim.save(path, replace=True)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    monkeypatch.undo()
    assert sim.save(path, replace=True) == path and path.stat().st_size > 0


def test_in_memory_run_writes_no_file(tmp_path):
    """No file anywhere: not the scene's default output (results/<scene>.h5), nothing in
    the working directory. ``import ancfdrv`` does not import the in-memory module (it is
    loaded on first use of ``ancfdrv.simulate``), and the run imports no scipy, as a
    dynamic run_scene (tests/test_lazy_imports.py)."""
    scene, sets = PENDULUM
    code = textwrap.dedent(f"""
        import sys
        import ancfdrv
        print("ancfdrv.simulation" in sys.modules)
        sim = ancfdrv.simulate({str(scene)!r}, {sets!r}, progress=False)
        print(sorted(m for m in sys.modules if m == "scipy" or m.startswith("scipy.")))
        print(len(sim.time))
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split("\n")[:3] == ["False", "[]", "51"]
    assert list(tmp_path.iterdir()) == []


def test_docs_example_runs_as_printed(tmp_path, monkeypatch):
    """The in-memory example of docs/python-api.md, run in an empty directory (the scene's
    path made absolute): it saves the file it asks for (with its XDMF), and the history it reports conserves
    energy (the pendulum has no damping: the balance total - total(0) - works stays
    below 1e-4 of the largest kinetic energy) while the tip falls from the horizontal."""
    text = (ROOT / "docs" / "python-api.md").read_text()
    blocks = [b.split("```", 1)[0] for b in text.split("```python\n")[1:]]
    block = next(b for b in blocks if "ancfdrv.simulate(" in b)
    block = block.replace('"inputs/hard/pendulum.nml"', repr(str(PENDULUM[0])))
    monkeypatch.chdir(tmp_path)
    names: dict[str, object] = {}
    exec(compile(block, "docs/python-api.md", "exec"), names)
    sim = names["sim"]
    # the result and its XDMF (the cable pendulum's polyline, as `ancf run` writes it)
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == \
        ["pendulum.h5", "pendulum.xdmf"]
    assert np.abs(sim.energy("balance")).max() < 1e-4 * sim.energy("kinetic").max()
    assert sim.probe("tip")[:, 1].min() < -1.0
