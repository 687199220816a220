"""`ancf sweep` under faults: a case that raises anything, a worker process killed by a
signal, Ctrl-C, hostile --vary values, stale files of another sweep, a failed finest case,
and a real Dask cluster (scheduler and workers in other directories, no shared files, a
worker killed mid-case, an unreachable scheduler).

Faults are injected by replacing ancfdrv.runner.run_scene: in this process before a sweep
whose workers are forked (they inherit the replacement), or in the Dask workers through a
preload module."""
from __future__ import annotations

import csv
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import h5py
import pytest

from ancfdrv import runner
from ancfdrv.cli import main
from ancfdrv.errors import SolverError
from ancfdrv.results.hdf5 import read_summary
from ancfdrv.sweep import (MAX_NAME_CHARS, case_names, check_sweep_ids, read_sweep_id,
                           run_sweep)
from conftest import INPUTS

BOOM = INPUTS / "boom_static.nml"
NODES = ["beam.nodes=4,7,10"]
REAL_RUN_SCENE = runner.run_scene


def inject(monkeypatch, fault):
    """Replace run_scene by one that calls ``fault(overrides)`` first."""
    def run_scene(path, overrides=None, output=None, **kwargs):
        fault(overrides or [])
        return REAL_RUN_SCENE(path, overrides, output, **kwargs)
    monkeypatch.setattr(runner, "run_scene", run_scene)


def sag(overrides: list[str], tmp_path: Path) -> float:
    """The tip sag of one run in this process (the independent reference)."""
    out = tmp_path / f"ref-{len(list(tmp_path.glob('ref-*')))}.h5"
    REAL_RUN_SCENE(BOOM, overrides, out, progress=False)
    return float(read_summary(out)["static.deflection.tip"][1])


def read_csv(path: Path) -> dict[str, dict]:
    return {r["case"]: r for r in csv.DictReader(open(path))}


# --- any exception, killed workers ------------------------------------------------

@pytest.mark.parametrize("workers,start_method", [(2, "fork"), (1, None)],
                         ids=["process-pool", "in-process"])
def test_unexpected_exception_fails_only_its_case(monkeypatch, tmp_path, workers, start_method):
    def fault(overrides):
        if "beam.nodes=7" in overrides:
            raise ZeroDivisionError("injected fault")
    inject(monkeypatch, fault)
    out = tmp_path / "s"
    rows = run_sweep(str(BOOM), NODES, out, workers=workers, start_method=start_method,
                     progress=False)
    assert [r["status"] for r in rows] == ["ok", "failed", "ok"]
    failed = rows[1]
    assert failed["exit_code"] == 1 and failed["file"] == ""
    assert failed["message"].startswith("internal error: ZeroDivisionError: injected fault")
    assert rows[0]["tip_transverse"] == pytest.approx(sag(["beam.nodes=4"], tmp_path), rel=1e-12)
    assert rows[2]["err_vs_finest"] == 0 and rows[0]["err_vs_finest"] > 0
    table = (out / "summary.md").read_text()
    assert re.search(r"^\| 7 \| .*\| failed \|$", table, re.M)
    assert "- nodes-7 (failed, exit 1): internal error: ZeroDivisionError: injected fault" in table
    assert sorted(p.name for p in out.glob("*.h5")) == ["nodes-10.h5", "nodes-4.h5"]
    assert not list(out.glob(".*"))  # no part file left behind


def test_cli_exit_code_is_the_worst_case(monkeypatch, tmp_path, capsys):
    def fault(overrides):
        if "beam.nodes=7" in overrides:
            raise RuntimeError("injected")
    inject(monkeypatch, fault)
    out = tmp_path / "s"
    assert main(["sweep", str(BOOM), "--vary", NODES[0], "-o", str(out), "--workers", "1"]) == 1
    captured = capsys.readouterr()
    assert "1 case(s) failed" in captured.err
    assert read_csv(out / "summary.csv")["nodes-10"]["status"] == "ok"


def test_killed_worker_is_retried_once(monkeypatch, tmp_path):
    marker = tmp_path / "killed-once"

    def fault(overrides):
        if "beam.nodes=7" in overrides and not marker.exists():
            marker.touch()
            os.kill(os.getpid(), signal.SIGKILL)
    inject(monkeypatch, fault)
    rows = run_sweep(str(BOOM), NODES, tmp_path / "s", workers=2, start_method="fork",
                     progress=False)
    assert marker.exists()  # the first attempt did die
    assert [r["status"] for r in rows] == ["ok", "ok", "ok"]
    assert "killed by signal SIGKILL (9)" in rows[1]["message"]
    assert "retry on a fresh worker succeeded" in rows[1]["message"]
    assert rows[1]["tip_transverse"] == pytest.approx(sag(["beam.nodes=7"], tmp_path), rel=1e-12)
    assert read_sweep_id(rows[1]["file"]) == read_sweep_id(rows[0]["file"])


def test_retry_that_fails_otherwise_says_both(monkeypatch, tmp_path):
    marker = tmp_path / "killed-once"

    def fault(overrides):
        if "beam.nodes=7" in overrides:
            if not marker.exists():
                marker.touch()
                os.kill(os.getpid(), signal.SIGKILL)
            raise SolverError("injected on the retry")
    inject(monkeypatch, fault)
    rows = run_sweep(str(BOOM), NODES, tmp_path / "s", workers=2, start_method="fork",
                     progress=False)
    assert [(r["status"], r["exit_code"]) for r in rows] == [("ok", 0), ("failed", 3), ("ok", 0)]
    assert rows[1]["message"] == ("injected on the retry (on the retry: its worker process was "
                                  "killed by signal SIGKILL (9) before)")


def test_worker_that_always_dies_fails_its_case(monkeypatch, tmp_path):
    attempts = tmp_path / "attempts"

    def fault(overrides):
        if "beam.nodes=7" in overrides:
            with open(attempts, "a") as fh:
                fh.write("x")
            os.kill(os.getpid(), signal.SIGKILL)
    inject(monkeypatch, fault)
    out = tmp_path / "s"
    rows = run_sweep(str(BOOM), NODES, out, workers=2, start_method="fork", progress=False)
    assert attempts.read_text() == "xx"  # the attempt and one retry
    assert [r["status"] for r in rows] == ["ok", "failed", "ok"]
    assert rows[1]["exit_code"] == 1 and rows[1]["file"] == ""
    assert "killed by signal SIGKILL (9), also on the retry" in rows[1]["message"]
    assert rows[0]["err_reference"] == "nodes-10" and rows[0]["err_vs_finest"] > 0
    assert "killed by signal SIGKILL" in (out / "summary.md").read_text()
    assert not list(out.glob(".*"))


NEWTON_1 = ["solver.static_method=newton", "beam.nodes=4"]  # max_iter=1 does not converge


def test_solver_failure_keeps_its_file_with_the_sweep_id(tmp_path):
    """A case failing with SolverError (exit 3) keeps what it computed, stamped too."""
    rows = run_sweep(str(BOOM), ["solver.max_iter=1,50"], tmp_path / "s", base=NEWTON_1,
                     workers=2, progress=False)
    assert [(r["status"], r["exit_code"]) for r in rows] == [("failed", 3), ("ok", 0)]
    assert "did not converge in 1 iterations" in rows[0]["message"]
    with h5py.File(rows[0]["file"]) as h5:
        assert h5.attrs["status"] == "failed" and h5["model"].attrs["ndof"] == 48
        assert h5.attrs["sweep_id"] == read_sweep_id(rows[1]["file"])


# --- Ctrl-C ------------------------------------------------------------------------

def test_ctrl_c_reports_what_finished_and_exits_130(tmp_path):
    """SIGINT once the quick first case has its file: the running cases are 'interrupted',
    the queued ones 'cancelled', the report written, exit 130."""
    out = tmp_path / "s"
    cmd = [sys.executable, "-m", "ancfdrv.cli", "sweep", str(INPUTS / "boom_luffing.nml"),
           "--vary", "solver.dt=0.01,5e-5,4e-5,2e-5", "--set", "beam.nodes=4",
           "--workers", "2", "-o", str(out)]
    # a shell may start background jobs with SIGINT ignored; the user's terminal does not
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 120
        while not list(out.glob("[!.]*.h5")):  # a finished case (not a .part file)
            assert proc.poll() is None and time.monotonic() < deadline, proc.stderr.read()
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ancf sweep: interrupted: 1 of 4 cases"), stderr
    rows = read_csv(out / "summary.csv")
    assert rows["dt-0.01"]["status"] == "ok" and float(rows["dt-0.01"]["steps"]) == 1000
    # dt-4e-5 starts on the worker dt-0.01 frees, just after that file appears
    assert rows["dt-5e-5"]["status"] == "interrupted"
    assert rows["dt-4e-5"]["status"] in ("interrupted", "cancelled")
    assert rows["dt-2e-5"]["status"] == "cancelled"
    assert all(rows[c]["exit_code"] == "130" for c in ("dt-5e-5", "dt-4e-5", "dt-2e-5"))
    summary = (out / "summary.md").read_text()
    assert re.search(r"4 cases, 1 ok, [12] interrupted, [12] cancelled\.", summary)
    assert "dt-2e-5 (cancelled, exit 130): cancelled by Ctrl-C before it started" in summary
    assert (out / "histories.png").exists()
    assert not list(out.glob(".*part*"))


# --- names -------------------------------------------------------------------------

def test_hostile_values_give_safe_names_inside_the_sweep_directory(tmp_path):
    out = tmp_path / "a" / "s"
    rows = run_sweep(str(BOOM), ["scene.title=../../escape,x/y z,ok"], out,
                     base=["beam.nodes=4"], workers=1, progress=False)
    assert [r["status"] for r in rows] == ["ok", "ok", "ok"]
    files = [p for p in tmp_path.rglob("*") if p.is_file() and p.suffix == ".h5"]
    assert len(files) == 3 and all(p.parent == out for p in files)
    assert all(re.fullmatch(r"[A-Za-z0-9._+-]+\.h5", p.name) for p in files)
    assert re.fullmatch(r"title-\.\._\.\._escape_[0-9a-f]{8}", rows[0]["case"])
    assert re.fullmatch(r"title-x_y_z_[0-9a-f]{8}", rows[1]["case"])
    assert rows[2]["case"] == "title-ok"  # unchanged values keep their plain name
    with h5py.File(out / f"{rows[0]['case']}.h5") as h5:
        assert h5.attrs["title"] == "../../escape"


def test_names_are_unique_and_bounded():
    combos = [{"scene.formulation": "ffr"}, {"scene.formulation": "'ffr'"},
              {"scene.title": "Boom"}, {"scene.title": "boom"}, {"scene.title": "x" * 500},
              {"beam.nodes": "28", "solver.dt": "1e-3"}]
    names = case_names(combos)
    assert len({n.lower() for n in names}) == len(names)
    hashed = r"_[0-9a-f]{8}"
    assert re.fullmatch("formulation-ffr" + hashed, names[0])
    assert re.fullmatch("formulation-ffr" + hashed, names[1])
    assert re.fullmatch("title-Boom" + hashed, names[2])
    assert len(names[4]) == MAX_NAME_CHARS + 9 and names[4].startswith("title-xxx")
    assert names[5] == "nodes-28_dt-1e-3"


def test_repeated_vary_value_is_bad_input(tmp_path, capsys):
    assert main(["sweep", str(BOOM), "--vary", "beam.nodes=4,4", "-o", str(tmp_path)]) == 2
    assert "beam.nodes gives the value '4' more than once" in capsys.readouterr().err


# --- files of another sweep ----------------------------------------------------------

def test_files_of_an_earlier_sweep_are_never_read(monkeypatch, tmp_path):
    """A 0 kg sweep left files under the same names. This 50 kg sweep's nodes=7 case
    'succeeds' but writes elsewhere (as a worker with another working directory did):
    it fails, and no table reads the 0 kg file."""
    out = tmp_path / "s"
    old = run_sweep(str(BOOM), NODES, out, base=["loads.tip_mass=0"], workers=1, progress=False)
    old_id = read_sweep_id(out / "nodes-7.h5")

    def misplaced(path, overrides=None, output=None, **kwargs):
        if "beam.nodes=7" in overrides:
            output = tmp_path / "elsewhere.h5"
        return REAL_RUN_SCENE(path, overrides, output, **kwargs)
    monkeypatch.setattr(runner, "run_scene", misplaced)
    rows = run_sweep(str(BOOM), NODES, out, workers=1, progress=False)
    assert [r["status"] for r in rows] == ["ok", "failed", "ok"]
    assert "wrote no result file where the sweep asked for it" in rows[1]["message"]
    assert rows[1]["file"] == "" and "tip_transverse" not in rows[1]
    assert read_sweep_id(out / "nodes-7.h5") == old_id  # left alone, not tabulated
    new_id = read_sweep_id(out / "nodes-4.h5")
    assert new_id == read_sweep_id(out / "nodes-10.h5") and new_id != old_id
    assert rows[0]["tip_transverse"] == pytest.approx(sag(["beam.nodes=4"], tmp_path), rel=1e-12)
    assert abs(rows[0]["tip_transverse"] - old[0]["tip_transverse"]) > 1e-3  # 50 kg vs 0 kg
    table = read_csv(out / "summary.csv")
    assert table["nodes-7"]["tip_transverse"] == "" and table["nodes-7"]["status"] == "failed"


def test_rows_whose_file_has_another_sweep_id_fail(tmp_path):
    other, bare = tmp_path / "other.h5", tmp_path / "bare.h5"
    with h5py.File(other, "w") as h5:
        h5.attrs["sweep_id"] = "0123"
    h5py.File(bare, "w").close()
    rows = [{"status": "ok", "file": str(other)}, {"status": "ok", "file": str(bare)},
            {"status": "failed", "file": str(bare), "message": "kept"}]
    check_sweep_ids(rows, "abcd")
    assert [r["status"] for r in rows] == ["failed", "failed", "failed"]
    assert f"{other} has sweep_id 0123, not this sweep's abcd" in rows[0]["message"]
    assert "has no sweep_id" in rows[1]["message"] and "not used" in rows[1]["message"]
    assert rows[2]["message"] == "kept"


# --- the reference of err vs finest -------------------------------------------------------

def test_reference_not_the_finest_is_said(monkeypatch, tmp_path, capsys):
    def fault(overrides):
        if "beam.nodes=10" in overrides:
            raise SolverError("injected: Newton did not converge")
    inject(monkeypatch, fault)
    out = tmp_path / "s"
    assert main(["sweep", str(BOOM), "--vary", NODES[0], "-o", str(out), "--workers", "1"]) == 3
    rows = read_csv(out / "summary.csv")
    assert rows["nodes-10"]["status"] == "failed"
    for case in ("nodes-4", "nodes-7"):
        assert rows[case]["err_reference"] == "nodes-7"
        assert rows[case]["err_reference_is_finest"] == "False"
        assert rows[case]["err_finest_requested"] == "nodes-10"
    s4, s7 = (float(rows[c]["tip_transverse"]) for c in ("nodes-4", "nodes-7"))
    assert float(rows["nodes-4"]["err_vs_finest"]) == pytest.approx(abs(s4 - s7) / abs(s7),
                                                                    rel=1e-12)
    note = "* err vs finest: reference nodes-7, NOT the finest case requested (nodes-10: failed)"
    summary = (out / "summary.md").read_text()
    assert note in summary and note in capsys.readouterr().out
    assert re.search(r"^\| 4 \|.* \*\s\|", summary, re.M)  # the error cell is marked


def test_reference_is_named(tmp_path, capsys):
    out = tmp_path / "s"
    assert main(["sweep", str(BOOM), "--vary", "beam.nodes=4,7", "--vary",
                 "boom.angle_deg=0,60", "-o", str(out), "--workers", "1"]) == 0
    rows = read_csv(out / "summary.csv")
    assert rows["nodes-4_angle_deg-60"]["err_reference"] == "nodes-7_angle_deg-60"
    assert rows["nodes-4_angle_deg-0"]["err_reference_is_finest"] == "True"
    note = ("err vs finest: reference nodes-7_angle_deg-0, nodes-7_angle_deg-60 (the finest "
            "case of each group)")
    assert note in capsys.readouterr().out and note in (out / "summary.md").read_text()


# --- a real Dask cluster: separate processes and directories ---------------------------

KILL_ONCE = '''"""Dask worker preload of the sweep tests: the nodes=7 case of a scene titled
'kill-worker-once' kills its worker process the first time it runs."""
import os
import signal

import ancfdrv.runner as runner

# Dask may load a preload more than once in a process: wrap the original only
_real = runner.__dict__.setdefault("_original_run_scene", runner.run_scene)


def _run_scene(path, overrides=None, output=None, **kwargs):
    text = open(path).read()
    if "kill-worker-once" in text and "beam.nodes=7" in (overrides or []):
        try:
            fd = os.open(os.environ["ANCF_TEST_KILL_MARKER"], os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            pass
        else:
            os.close(fd)
            os.kill(os.getpid(), signal.SIGKILL)
    return _real(path, overrides, output, **kwargs)


runner.run_scene = _run_scene
'''


@pytest.fixture(scope="module")
def dask_cluster(tmp_path_factory):
    """`dask scheduler` and two `dask worker` processes, each in its own directory."""
    distributed = pytest.importorskip("distributed")
    root = tmp_path_factory.mktemp("dask")
    procs: list[subprocess.Popen] = []

    def start(args: list[str], cwd: Path, env: dict | None = None) -> None:
        cwd.mkdir()
        log = open(cwd / "log", "w")
        procs.append(subprocess.Popen([sys.executable, "-m", "dask", *args], cwd=cwd,
                                      stdout=log, stderr=subprocess.STDOUT, env=env,
                                      start_new_session=True))
        log.close()
    try:
        scheduler_file = root / "scheduler.json"
        start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
               "--scheduler-file", str(scheduler_file)], root / "scheduler")
        deadline = time.monotonic() + 60
        while not scheduler_file.exists():
            assert procs[0].poll() is None and time.monotonic() < deadline, "no scheduler"
            time.sleep(0.1)
        time.sleep(0.2)  # the file is complete once written; be safe about a partial read
        address = json.loads(scheduler_file.read_text())["address"]
        preload = root / "kill_once.py"
        preload.write_text(KILL_ONCE)
        # the workers' temporary directories in the test's own: a worker killed mid-case
        # cannot clean its case directory up (it left one in /tmp per run of the suite)
        (root / "tmp").mkdir()
        env = dict(os.environ, ANCF_TEST_KILL_MARKER=str(root / "killed"), TMPDIR=str(root / "tmp"))
        workers = [root / "worker-a", root / "worker-b"]
        for cwd in workers:
            start(["worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard",
                   "--preload", str(preload), "--local-directory", str(cwd / "scratch")],
                  cwd, env)
        with distributed.Client(address, timeout=30, set_as_default=False) as client:
            client.wait_for_workers(2, timeout=90)
        yield SimpleNamespace(address=address, workers=workers, marker=root / "killed")
    finally:
        for proc in procs:  # each in its own session: the group holds its worker processes
            try:
                os.killpg(proc.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        for proc in procs:
            try:
                proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()


def test_dask_cluster_without_shared_files(dask_cluster, tmp_path, monkeypatch):
    """From a third directory with a relative scene path (whose &output file is relative
    too): the files land in the client's sweep directory, the numbers equal a local run,
    and the files a 0 kg sweep left under the same names are replaced, never read."""
    client_dir = tmp_path / "client"
    client_dir.mkdir()
    shutil.copy(BOOM, client_dir / "boom.nml")
    monkeypatch.chdir(client_dir)
    vary = ["beam.nodes=4,7"]
    stale = run_sweep("boom.nml", vary, "sweep", base=["loads.tip_mass=0"], workers=1,
                      progress=False)
    stale_id = read_sweep_id("sweep/nodes-4.h5")
    remote = run_sweep("boom.nml", vary, "sweep", scheduler=dask_cluster.address,
                       progress=False)
    local = run_sweep("boom.nml", vary, "local", workers=1, progress=False)
    assert [r["status"] for r in remote] == ["ok", "ok"], [r["message"] for r in remote]
    for r, loc, old in zip(remote, local, stale):
        assert r["tip_transverse"] == pytest.approx(loc["tip_transverse"], rel=1e-12)
        assert abs(r["tip_transverse"] - old["tip_transverse"]) > 1e-3
        assert Path(r["file"]) == Path("sweep") / f"{r['case']}.h5"
    ids = {read_sweep_id(f"sweep/nodes-{n}.h5") for n in (4, 7)}
    assert len(ids) == 1 and stale_id not in ids
    with h5py.File("sweep/nodes-7.h5") as h5:
        assert h5.attrs["scene_file"] == str(client_dir / "boom.nml")
        assert h5["static/deflection/tip"][1] == pytest.approx(remote[1]["tip_transverse"])
    assert not (client_dir / "results").exists()
    for worker in dask_cluster.workers:
        assert not list(worker.rglob("*.h5")) and not (worker / "results").exists()


def test_dask_worker_killed_mid_case_is_rerun(dask_cluster, tmp_path):
    base = ["scene.title=kill-worker-once"]
    remote = run_sweep(str(BOOM), ["beam.nodes=4,7"], tmp_path / "remote", base=base,
                       scheduler=dask_cluster.address, progress=False)
    assert dask_cluster.marker.exists()  # a worker process died running nodes=7
    assert [r["status"] for r in remote] == ["ok", "ok"], [r["message"] for r in remote]
    assert remote[1]["tip_transverse"] == pytest.approx(sag(["beam.nodes=7"], tmp_path),
                                                        rel=1e-12)


def test_dask_failed_case_returns_its_file(dask_cluster, tmp_path):
    rows = run_sweep(str(BOOM), ["solver.max_iter=1,50"], tmp_path / "s", base=NEWTON_1,
                     scheduler=dask_cluster.address, progress=False)
    assert [(r["status"], r["exit_code"]) for r in rows] == [("failed", 3), ("ok", 0)]
    assert "did not converge in 1 iterations" in rows[0]["message"]
    with h5py.File(tmp_path / "s" / "max_iter-1.h5") as h5:
        assert h5.attrs["status"] == "failed" and h5.attrs["sweep_id"] == read_sweep_id(
            rows[1]["file"])


def test_remote_case_names_the_client_scene_not_its_temporary_copy():
    """What a Dask worker runs, here in this process: the scene text in a private temporary
    directory; an error names the client's scene file."""
    from ancfdrv.sweep_exec import run_case_remote
    row, data = run_case_remote(BOOM.read_text(), "client/boom.nml", {"beam.nodes": "5"},
                                ["beam.nodes=5"])
    assert row["status"] == "failed" and row["exit_code"] == 2 and data is None
    assert row["message"].startswith("client/boom.nml: &beam nodes"), row["message"]
    row, data = run_case_remote(BOOM.read_text(), "client/boom.nml", {"beam.nodes": "4"},
                                ["beam.nodes=4"])
    assert row["status"] == "ok" and data[:8] == b"\x89HDF\r\n\x1a\n"


def test_unreachable_scheduler_is_one_line_and_exit_2(tmp_path):
    pytest.importorskip("distributed")
    with socket.socket() as sock:  # a port nobody listens on
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    out = tmp_path / "s"
    proc = subprocess.run([sys.executable, "-m", "ancfdrv.cli", "sweep", str(BOOM), "--vary",
                           "beam.nodes=4,7", "--scheduler", f"tcp://127.0.0.1:{port}", "-o",
                           str(out)], capture_output=True, text=True, timeout=15)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith(f"ancf sweep: error: cannot reach the Dask scheduler "
                               f"'tcp://127.0.0.1:{port}'")
    assert not out.exists()  # nothing written
