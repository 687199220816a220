"""No worker process outlives its parent (issue 35): stopped by a timeout (SIGTERM to the
parent), `examples/road_transmissibility.py` left its two workers running for 25 minutes,
and so did a SIGKILL. Checked here for the package's sweep workers (`ancf sweep --workers
2`) and for the example's process pool (``ancfdrv.sweep_exec.end_with_parent``), parent
stopped by SIGTERM and by SIGKILL while both workers run a case: a few seconds later none of
the parent's child processes is alive (read from /proc, Linux).

The processes' output goes to files, not pipes: an orphan holding a pipe open would also
hang the test's wait for the parent.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import pytest

from conftest import INPUTS

ROOT = Path(__file__).resolve().parent.parent
GUARD_S = 60  # bounds against a hang, not measurements
GONE_S = 10   # the children must be gone this long after the parent

pytestmark = pytest.mark.skipif(not Path("/proc/self/stat").exists(),
                                reason="reads the process table from /proc (Linux)")


def _stat(pid: int) -> list[str] | None:
    """The fields of /proc/PID/stat after the command name (state, ppid, ...), or None."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return text.rsplit(")", 1)[1].split()


def children(pid: int) -> list[int]:
    """The live child processes of pid."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            fields = _stat(int(entry.name))
            if fields and int(fields[1]) == pid and fields[0] != "Z":
                found.append(int(entry.name))
    return found


def alive(pid: int) -> bool:
    fields = _stat(pid)
    return fields is not None and fields[0] != "Z"  # a zombie has ended


def _start(args: list[str], tmp_path: Path) -> subprocess.Popen:
    log = open(tmp_path / "parent.log", "w")  # noqa: SIM115 - closed with the process
    proc = subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT, cwd=tmp_path)
    log.close()
    return proc


def _stepping(path: Path) -> bool:
    """Whether the case writing ``path`` has begun its dynamics (the file has /dynamic)."""
    from ancfdrv.results.hdf5 import open_result
    try:
        with open_result(path) as h5:
            return "dynamic" in h5
    except Exception:  # noqa: BLE001 - being created or written right now: look again
        return False


def _wait_for_busy_workers(proc: subprocess.Popen, files: Path, pattern: str,
                           tmp_path: Path) -> list[int]:
    """Until the parent has its workers and two case files are in their dynamics."""
    deadline = time.monotonic() + GUARD_S
    while time.monotonic() < deadline:
        assert proc.poll() is None, (tmp_path / "parent.log").read_text()
        workers = children(proc.pid)
        cases = list(files.glob(pattern))
        if len(workers) >= 2 and len(cases) >= 2 and all(_stepping(p) for p in cases):
            return children(proc.pid)
        time.sleep(0.1)
    proc.kill()
    pytest.fail("the workers never started their cases")


def _assert_all_gone(pids: list[int], proc: subprocess.Popen) -> None:
    proc.wait(timeout=GUARD_S)
    deadline = time.monotonic() + GONE_S
    while time.monotonic() < deadline and any(alive(p) for p in pids):
        time.sleep(0.1)
    left = [p for p in pids if alive(p)]
    for pid in left:  # do not leave them to the machine
        os.kill(pid, signal.SIGKILL)
    assert not left, f"workers {left} outlived their parent"


two_cores = pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2,
                               reason="--workers 2 runs inline on one core")


@two_cores
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_sweep_workers_end_with_their_parent(tmp_path, signum):
    """`ancf sweep --workers 2` of two long pendulum runs: SIGTERM to the parent stops the
    sweep (exit 143, the workers stopped with it); SIGKILL leaves no worker either (the
    kernel's parent-death signal, and the pipe to the parent)."""
    out = tmp_path / "sweep"
    proc = _start([sys.executable, "-m", "ancfdrv.cli", "sweep",
                   str(INPUTS / "hard" / "pendulum.nml"), "--vary", "beam.nodes=5,6",
                   "--set", "solver.t_end=500", "--set", "output.xdmf=.false.",
                   "--workers", "2", "-o", str(out)], tmp_path)
    workers = _wait_for_busy_workers(proc, out, "*.h5", tmp_path)
    assert len(workers) == 2
    os.kill(proc.pid, signum)
    _assert_all_gone(workers, proc)
    assert proc.returncode == (143 if signum == signal.SIGTERM else -signal.SIGKILL)


EXAMPLE_PARENT = """
import sys
from pathlib import Path
sys.path.insert(0, {examples!r})
import road_transmissibility as rt
if __name__ == "__main__":
    out = Path(sys.argv[1])
    cases = [rt.Case(f, False, 100.0, 4.0, 2.0, 0.5, out / f"road-{{f}}.h5", True)
             for f in (1.5, 2.0)]
    rt.sweep(cases, 2, progress=False)
"""


@two_cores
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_example_pool_workers_end_with_their_parent(tmp_path, signum):
    """examples/road_transmissibility.py's pool (spawned workers, two 100 s road runs):
    after SIGTERM or SIGKILL of the parent no child is alive a few seconds later, and each
    case's file opens, says 'interrupted' and keeps its rows (the run stopped at a step
    boundary and flushed)."""
    script = tmp_path / "parent.py"
    script.write_text(EXAMPLE_PARENT.format(examples=str(ROOT / "examples")))
    proc = _start([sys.executable, str(script), str(tmp_path)], tmp_path)
    pids = _wait_for_busy_workers(proc, tmp_path, "road-*.h5", tmp_path)
    os.kill(proc.pid, signum)
    _assert_all_gone(pids, proc)
    for path in sorted(tmp_path.glob("road-*.h5")):
        with h5py.File(path, "r") as h5:
            assert h5.attrs["status"] == "interrupted"
            assert len(h5["dynamic/time"]) >= 1
