"""Runs that never lose or mislabel data, and a CLI that never shows a traceback.

Each test asserts the exit status, the message and the state of every file involved:
output paths refused before anything is computed (the scene file, a directory, below a
regular file, a read-only directory, a non-HDF5 file), one writer per output file,
SIGINT / SIGTERM (flushed, 'interrupted', exit 130 / 143), SIGKILL ('abandoned'),
`ancf info` on files that are not results, and internal errors (one line, trace file).
"""
from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import INPUTS
from ancfdrv import cli, runner
from ancfdrv.cli import main
from ancfdrv.errors import Interrupted

TINY = ["--set", "beam.nodes=4", "--set", "solver.t_end=0.5"]
# 0.2-1 ms per step, 60000 steps: long enough to be signalled after the first chunk (every
# test that uses it stops the run), and one output chunk of 10000 steps would take 2-10 s
# in one kernel call without the integrator's sub-chunks
LONG = ["--set", "beam.nodes=28", "--set", "scene.formulation=nonlinear", "--set",
        "solver.static_method=newton", "--set", "solver.t_end=60", "--set",
        "output.chunk_steps=10000"]
HANG_GUARD_S = 60  # a bound against hanging, not a measurement


@pytest.fixture
def scene(tmp_path) -> Path:
    """A private copy of the luffing boom scene (so that a damaged input would show)."""
    path = tmp_path / "boom.nml"
    shutil.copy(INPUTS / "boom_luffing.nml", path)
    return path


def ancf(*args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "ancfdrv.cli", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def refused(capsys, args: list[str], *fragments: str) -> str:
    """main(args) exits 2 with one line on stderr holding every fragment."""
    assert main(args) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    for fragment in fragments:
        assert fragment in err, err
    return err


def rows_written(path: Path) -> int:
    """Output rows on disk now (0 until the file exists and holds /dynamic)."""
    from ancfdrv.results.hdf5 import open_result
    if not path.exists() or not h5py.is_hdf5(path):
        return 0
    try:
        with open_result(path) as h5:
            return len(h5["dynamic/time"]) if "dynamic/time" in h5 else 0
    except Exception:  # noqa: BLE001 - being created right now: look again
        return 0


def wait_for_rows(path: Path, proc: subprocess.Popen, rows: int) -> int:
    deadline = time.monotonic() + HANG_GUARD_S
    while time.monotonic() < deadline:
        n = rows_written(path)
        if n >= rows:
            return n
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.05)
    proc.kill()
    pytest.fail(f"{path} never got {rows} rows")


def _per_station(name: str) -> bool:
    """Datasets of /dynamic along the beams, not over time (SPEC section 10): the stress
    envelope (von_mises_max, t_max, s per station), the section forces' stations s, the
    envelope at the XDMF points."""
    return (name.startswith("stress/") or name == "mesh_von_mises_max"
            or (name.startswith("sections/") and name.endswith("/s")))


def assert_consistent_dynamic(path: Path, dt: float) -> int:
    """Every /dynamic series has the same length; time advances by dt per row. The XDMF
    frames (mesh_*, one per frame, and their views under xdmf/) are consistent among
    themselves and name rows that were written."""
    frames = ("mesh_nodes", "mesh_displacement", "mesh_rows")
    with h5py.File(path, "r") as h5:
        group = h5["dynamic"]
        t = group["time"][()]
        lengths = set()
        group.visititems(lambda name, obj: lengths.add(obj.shape[0])
                         if isinstance(obj, h5py.Dataset) and obj.ndim and name not in frames
                         and name != "q_last" and not name.startswith("xdmf/")
                         and not _per_station(name) else None)
        assert lengths == {len(t)}
        if "mesh_rows" in group:
            rows = group["mesh_rows"][()]
            assert {group[name].shape[0] for name in frames} == {len(rows)}
            assert len(rows) and rows[0] == 0 and np.all(np.diff(rows) > 0)
            assert rows[-1] < len(t)
            if h5.attrs.get("status") in ("ok", "interrupted", "failed"):
                # a finished file's motion ends where the run ended (the last row's q)
                assert rows[-1] == len(t) - 1
        assert np.allclose(np.diff(t), dt, rtol=0, atol=1e-9)
        assert group.attrs["rows"] == len(t)
        return len(t)


# --- output paths: refused before anything is computed -------------------------------

def test_output_is_the_scene_file(scene, capsys):
    before = scene.read_bytes()
    refused(capsys, ["run", str(scene), "-o", str(scene), *TINY], "is the input file",
            str(scene))
    assert scene.read_bytes() == before
    link = scene.with_name("link.h5")
    link.symlink_to(scene)
    refused(capsys, ["run", str(scene), "-o", str(link), *TINY], "is the input file")
    assert scene.read_bytes() == before


def test_output_beside_would_overwrite_the_scene(tmp_path, capsys):
    scene = tmp_path / "case.png"  # the plot of case.h5 would be written over it
    shutil.copy(INPUTS / "boom_luffing.nml", scene)
    before = scene.read_bytes()
    refused(capsys, ["run", str(scene), "-o", str(tmp_path / "case.h5"), *TINY],
            "the plot written beside it", "would overwrite the input file")
    assert scene.read_bytes() == before and not (tmp_path / "case.h5").exists()


def test_output_is_a_directory(scene, tmp_path, capsys):
    out = tmp_path / "results"
    out.mkdir()
    refused(capsys, ["run", str(scene), "-o", str(out), *TINY], str(out), "is a directory")
    assert list(out.iterdir()) == []


def test_output_below_a_regular_file(scene, tmp_path, capsys):
    blocker = tmp_path / "notes.txt"
    blocker.write_text("keep me")
    refused(capsys, ["run", str(scene), "-o", str(blocker / "sub" / "x.h5"), *TINY],
            f"{blocker} is not a directory")
    assert blocker.read_text() == "keep me"


def test_output_in_a_read_only_directory(scene, tmp_path, capsys):
    locked = tmp_path / "ro"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        if os.access(locked, os.W_OK):
            pytest.skip("permissions are not enforced for this user (root)")
        refused(capsys, ["run", str(scene), "-o", str(locked / "x.h5"), *TINY],
                "is not writable")
    finally:
        locked.chmod(0o755)


def test_read_only_directory_message(scene, tmp_path, monkeypatch, capsys):
    """The rule above as an unprivileged user sees it, also where the tests run as root:
    os.access answers as it would for a directory without write permission."""
    locked = tmp_path / "ro"
    locked.mkdir()
    real = os.access
    monkeypatch.setattr(os, "access", lambda path, mode, *a, **k:
                        False if Path(path) == locked and mode & os.W_OK else
                        real(path, mode, *a, **k))
    refused(capsys, ["run", str(scene), "-o", str(locked / "x.h5"), *TINY],
            f"the output directory {locked} is not writable")
    refused(capsys, ["run", str(scene), "-o", str(locked / "new" / "x.h5"), *TINY],
            f"the output parent directory {locked} is not writable")
    assert list(locked.iterdir()) == []


def test_existing_file_that_is_not_hdf5_is_not_overwritten(scene, tmp_path, capsys):
    other = tmp_path / "other.nml"
    other.write_text("&scene /\n")
    refused(capsys, ["run", str(scene), "-o", str(other), *TINY], "not an HDF5 file")
    assert other.read_text() == "&scene /\n"
    refused(capsys, ["run", str(scene), "-o", str(tmp_path / "x.png"), *TINY],
            "must not end in .png")


def test_a_previous_result_survives_a_refused_run(scene, tmp_path, capsys):
    out = tmp_path / "r.h5"
    assert main(["run", str(scene), "-o", str(out), *TINY]) == 0
    before = out.read_bytes()
    refused(capsys, ["run", str(scene), "-o", str(out), "--set", "beam.nodes=5"], "3j+1")
    assert out.read_bytes() == before


# --- one writer per file ---------------------------------------------------------------

def test_second_writer_is_refused_naming_the_first(scene, tmp_path, capsys):
    out = tmp_path / "shared.h5"
    # (30 s of luffing: rows reach the file once a second, so the run must outlast the first
    # flush by a margin; 10 s ran in about one second once the matrix was carried)
    first = ancf("run", str(scene), "-o", str(out), *LONG[2:-4], "--set", "beam.nodes=10",
                 "--set", "solver.t_end=30")
    wait_for_rows(out, first, 2)
    # the first run is held (SIGSTOP) while the second tries: it still writes then, however
    # fast the kernel has become
    first.send_signal(signal.SIGSTOP)
    try:
        err = refused(capsys, ["run", str(scene), "-o", str(out), *TINY],
                      f"is being written by another run (pid {first.pid} on host")
        assert "since 20" in err
        assert main(["info", str(out)]) == 0
        assert capsys.readouterr().out.startswith(
            f"{out}: running: being written by pid {first.pid} on host")
    finally:
        first.send_signal(signal.SIGCONT)
    _, err1 = first.communicate(timeout=HANG_GUARD_S)
    assert first.returncode == 0, err1
    with h5py.File(out, "r") as h5:  # the first run's scene and data, complete
        assert h5.attrs["status"] == "ok"
        assert "nodes = 10" in h5.attrs["scene"] and h5["model"].attrs["nnodes"] == 10
        assert len(h5["dynamic/time"]) == 30001
    assert_consistent_dynamic(out, 1e-3)
    assert not Path(str(out) + ".lock").exists()


# --- signals ---------------------------------------------------------------------------

@pytest.mark.parametrize("signum,code,name", [(signal.SIGINT, 130, "SIGINT"),
                                              (signal.SIGTERM, 143, "SIGTERM")])
def test_signal_stops_the_run_and_keeps_every_step(scene, tmp_path, signum, code, name):
    out = tmp_path / "long.h5"
    proc = ancf("run", str(scene), "-o", str(out), *LONG)
    before = wait_for_rows(out, proc, 2)  # the initial row and the first flushed chunk
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=HANG_GUARD_S)
    assert proc.returncode == code, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and f"interrupted by {name} at t = " in lines[0], err
    assert "status 'interrupted'" in lines[0] and "Traceback" not in err
    rows = assert_consistent_dynamic(out, 1e-3)
    assert rows >= before
    # the kernel returned within its chunk of 10000 steps: the run did not wait for it
    assert (rows - 1) % 10000 != 0
    with h5py.File(out, "r") as h5:
        assert h5.attrs["status"] == "interrupted"
        assert h5["dynamic"].attrs["status"] == "interrupted"
        assert h5.attrs["message"] == f"interrupted by {name}"
        assert h5["dynamic"].attrs["steps"] == rows - 1
        assert h5["counters"].attrs["time_steps"] >= rows - 1
        assert "static" in h5  # the static solution of static+dynamic is kept
    info = ancf("info", str(out))
    text, _ = info.communicate(timeout=HANG_GUARD_S)
    assert info.returncode == 0 and text.splitlines()[0].startswith(f"{out}: interrupted:")


def wait_for_model(path: Path, proc: subprocess.Popen) -> None:
    """Until the run's file holds its model (written before any solve)."""
    from ancfdrv.results.hdf5 import open_result
    deadline = time.monotonic() + HANG_GUARD_S
    while True:
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, f"{path} never got its model"
        try:
            with open_result(path) as h5:
                if "model" in h5:
                    return
        except Exception:  # noqa: BLE001 - not there or being created: look again
            pass
        time.sleep(0.05)


def _stopped(proc: subprocess.Popen, signum: int) -> tuple[int, str]:
    """Send signum and wait for the process: it must end within SIGNAL_GUARD_S (a bound
    against a run that does not listen, not a measurement)."""
    proc.send_signal(signum)
    try:
        _, err = proc.communicate(timeout=SIGNAL_GUARD_S)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        pytest.fail(f"the run did not stop within {SIGNAL_GUARD_S} s of {signum!r}")
    return proc.returncode, err


SIGNAL_GUARD_S = 20
SIGNALS = [(signal.SIGINT, 130, "SIGINT"), (signal.SIGTERM, 143, "SIGTERM")]


@pytest.mark.parametrize("signum,code,name", SIGNALS)
def test_signal_stops_an_adaptive_run_within_its_output_interval(tmp_path, signum, code,
                                                                 name):
    """Issue 35: under step = 'adaptive' the stop request is asked after every step tried,
    not only at the output rows. The 5-node pendulum with rows 5 s apart and a tolerance
    of 1e-12 (steps down to dt_min = 1e-9 s) spends minutes in its first interval (its
    first second took 14.7 s when only the rows asked); signalled a second after its file
    holds the model, it stops with exit 130 / 143, one line, and a file that opens with status
    'interrupted' and the initial row."""
    out = tmp_path / "adaptive.h5"
    proc = ancf("run", str(INPUTS / "hard" / "pendulum.nml"), "-o", str(out), "--set",
                "beam.nodes=5", "--set", "solver.dt=5.0", "--set", "solver.t_end=100",
                "--set", "solver.step=adaptive", "--set", "solver.tolerance=1e-12",
                "--set", "solver.dt_min=1e-9", "--set", "output.xdmf=.false.")
    wait_for_model(out, proc)
    time.sleep(1.0)  # into the first interval (the rows wait there: none is flushed yet)
    returncode, err = _stopped(proc, signum)
    assert returncode == code, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and f"interrupted by {name} at t = 0 s" in lines[0], err
    with h5py.File(out, "r") as h5:
        assert h5.attrs["status"] == "interrupted"
        assert h5["dynamic/time"][()].tolist() == [0.0]


@pytest.mark.parametrize("signum,code,name", SIGNALS)
def test_signal_stops_a_static_run(tmp_path, signum, code, name):
    """A long static run in a process (the 400-node elastica in 2000 load steps, one
    kernel call each): signalled once its file holds the model, it stops with exit 130 /
    143 and one line; the file opens, says 'interrupted' and keeps the model, no static
    solution (none was complete)."""
    out = tmp_path / "static.h5"
    proc = ancf("run", str(INPUTS / "hard" / "elastica.nml"), "-o", str(out), "--set",
                "beam.nodes=400", "--set", "solver.load_steps=2000")
    wait_for_model(out, proc)
    returncode, err = _stopped(proc, signum)
    assert returncode == code, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and f"interrupted by {name} before any result" in lines[0], err
    with h5py.File(out, "r") as h5:
        assert h5.attrs["status"] == "interrupted"
        assert h5["model"].attrs["nnodes"] == 400 and "static" not in h5


def test_sigkill_leaves_an_abandoned_file_and_no_blocking_lock(scene, tmp_path, capsys):
    out = tmp_path / "killed.h5"
    proc = ancf("run", str(scene), "-o", str(out), *LONG)
    wait_for_rows(out, proc, 2)
    proc.kill()
    proc.communicate(timeout=HANG_GUARD_S)
    assert Path(str(out) + ".lock").exists()  # stale: its process is gone
    assert main(["info", str(out)]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith(f"{out}: abandoned:") and "writer was killed" in first
    assert_consistent_dynamic(out, 1e-3)
    assert main(["run", str(scene), "-o", str(out), *TINY]) == 0  # the stale lock: no block
    with h5py.File(out, "r") as h5:
        assert h5.attrs["status"] == "ok" and len(h5["dynamic/time"]) == 501


def test_interrupted_static_solve_is_marked(scene, tmp_path, monkeypatch, capsys):
    """SIGINT during a static solve (which cannot poll for it) ends it at once."""
    real = runner.solve_static_path

    def signalled(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.01)  # the handler runs here and raises
        return real(*args, **kwargs)
    monkeypatch.setattr(runner, "solve_static_path", signalled)
    out = tmp_path / "static.h5"
    assert main(["run", str(scene), "-o", str(out), *TINY]) == 130
    err = capsys.readouterr().err
    assert err.strip() == (f"ancf run: interrupted by SIGINT before any result; {out} holds "
                           "the model only (status 'interrupted')")
    with h5py.File(out, "r") as h5:
        assert h5.attrs["status"] == "interrupted" and "static" not in h5
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored


def test_integrate_stops_after_the_chunk_it_computed():
    """should_stop is asked after every kernel call; the chunk goes to the sink first."""
    from ancfdrv.io.scene import load_scene
    from ancfdrv.builders import build_model
    from ancfdrv.solvers.dynamic import integrate
    scene = load_scene(INPUTS / "boom_luffing.nml", ["beam.nodes=4", "solver.t_end=5"])
    model = build_model(scene)
    chunks = []
    with pytest.raises(Interrupted, match="stopped at t = "):
        integrate(model, runner.dynamic_settings(scene), model.e0, sink=chunks.append,
                  should_stop=lambda: True)
    assert len(chunks) == 2  # the initial row and the first call (a short measuring call)
    assert 1 <= len(chunks[1].time) <= 10 and chunks[1].time[0] == pytest.approx(1e-3)
    assert model.counters["time_steps"] == len(chunks[1].time)


# --- info on files that are not results ------------------------------------------------

def test_info_on_files_that_are_not_results(tmp_path, capsys):
    text = tmp_path / "notes.h5"
    text.write_text("not hdf5")
    refused(capsys, ["info", str(text)], str(text), "not an HDF5 file")
    bare = tmp_path / "bare.h5"
    with h5py.File(bare, "w") as h5:
        h5.attrs["status"] = "ok"
    refused(capsys, ["info", str(bare)], str(bare), "no /model group")
    refused(capsys, ["info", str(tmp_path / "missing.h5")], "not found")


def test_info_verdicts_ok_and_failed(scene, tmp_path, capsys):
    out = tmp_path / "ok.h5"
    assert main(["run", str(scene), "-o", str(out), *TINY]) == 0
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    assert capsys.readouterr().out.splitlines()[0] == \
        f"{out}: ok: the run finished; dynamic reached t = 0.5 s"
    failed = tmp_path / "failed.h5"
    assert main(["run", str(scene), "-o", str(failed), *TINY, "--set",
                 "solver.static_method=newton", "--set", "solver.max_iter=1", "--set",
                 "solver.tol=1e-14"]) == 3
    capsys.readouterr()
    assert main(["info", str(failed)]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith(f"{failed}: failed: ") and "did not converge" in first


# --- internal errors -------------------------------------------------------------------

def test_internal_error_is_one_line_with_a_trace_file(scene, tmp_path, monkeypatch, capsys):
    def broken(*args, **kwargs):
        raise RuntimeError("deliberate failure for the test")
    monkeypatch.setattr(runner, "solve_static_path", broken)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    out = tmp_path / "bug.h5"
    assert main(["run", str(scene), "-o", str(out), *TINY]) == 1
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert err.startswith("ancf run: internal error: RuntimeError: deliberate failure for "
                          "the test (full trace in ")
    assert err.rstrip().endswith("; run with --debug to see it)")
    trace = Path(err.split("full trace in ")[1].split(";")[0])
    assert trace.parent == tmp_path and "Traceback" in trace.read_text()
    assert "RuntimeError: deliberate failure for the test" in trace.read_text()
    with h5py.File(out, "r") as h5:  # the file does not claim to be running
        assert h5.attrs["status"] == "failed"
        assert h5.attrs["message"] == "internal error: RuntimeError: deliberate failure " \
                                      "for the test"
    assert main(["--debug", "run", str(scene), "-o", str(out), *TINY]) == 1
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err and "in broken" in err


def test_version_and_exit_codes_in_help(capsys):
    from ancfdrv import __version__
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and __version__ in capsys.readouterr().out
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    text = capsys.readouterr().out
    for line in ("  0    success", "  1    internal error", "  2    bad input",
                 "  3    solver failure", "  130  interrupted by SIGINT", "143 by SIGTERM"):
        assert line in text
    assert "130" in cli.__doc__ and "143" in cli.__doc__
