"""How the cases of a sweep run, and how their result files reach the sweep directory.

Three executors, one contract: every case is reported exactly once to ``record(case, row,
data)``, whatever happens to it. A case that raises, whose worker process dies, or that a
Ctrl-C stops becomes a row with a status ('ok', 'failed', 'interrupted', 'cancelled'), a
message and an exit code; the other cases go on.

- :func:`run_inline`: one case after the other in this process (one worker).
- :func:`run_processes`: ``workers`` local worker processes, each running one case at a
  time, so a worker that dies (killed by a signal, or exiting without a result) is
  attributed to its case from its exit status; that case is retried once on a fresh
  worker, then marked failed naming the signal. (A ProcessPoolExecutor cannot do this: one
  dead worker breaks the pool and fails every pending case.)
- :func:`run_dask`: the cases go to a Dask distributed scheduler. Nothing is shared but the
  network: each task carries the scene text and the case's overrides, runs in a private
  temporary directory on the worker and returns the row and the HDF5 file as bytes.

Ctrl-C (KeyboardInterrupt in this process) stops an executor: the running cases are
stopped and reported 'interrupted', the queued ones 'cancelled', and the executor returns
True so that the caller can still write the report of what finished.
"""
from __future__ import annotations

import logging
import multiprocessing
import os
import signal
import tempfile
import threading
import time
import traceback
from collections import deque
from multiprocessing.connection import Connection, wait
from pathlib import Path
from typing import Any, Callable

from .records import record
from .errors import AncfError, InputError, Interrupted

#: Seconds a Dask client waits for the scheduler before the sweep gives up (exit 2).
CONNECT_TIMEOUT_S = 5.0

#: Exit code of a case that was stopped or never started because of Ctrl-C.
INTERRUPTED_EXIT = 130


@record(frozen=True)
class Case:
    """One combination of a sweep."""

    index: int  # position in the sweep (the order of the report)
    name: str  # file stem: sanitized, unique in the sweep
    params: dict[str, str]  # the varied keys and this case's values, as given
    overrides: list[str]  # this case's own overrides (without the sweep's base --set)
    output: Path  # final result file, inside the sweep directory
    part: Path  # where the file is written until the case is over (same directory)


#: record(case, row, data): called once per case; data is the HDF5 file as bytes (Dask).
Recorder = Callable[[Case, dict, "bytes | None"], None]


def internal_error(exc: BaseException) -> str:
    """'internal error: TYPE: message (at file:line)' for an exception ancfdrv did not raise
    on purpose."""
    where = ""
    frames = traceback.extract_tb(exc.__traceback__)
    if frames:
        where = f" (at {Path(frames[-1].filename).name}:{frames[-1].lineno})"
    text = str(exc).strip().splitlines()
    return f"internal error: {type(exc).__name__}: {text[0] if text else ''}{where}"


def failure(params: dict[str, str], status: str, message: str, exit_code: int) -> dict:
    """The row of a case that produced no result."""
    return dict(params, status=status, message=message, exit_code=exit_code)


def run_case(scene_file: str, params: dict[str, str], overrides: list[str],
             output: str) -> dict:
    """Run one case and read its summary; never raises an Exception (a failure is a row
    with status 'failed', the message and an exit code). KeyboardInterrupt passes."""
    from . import runner
    try:
        outcome = runner.run_scene(scene_file, overrides, output, progress=False)
    except Interrupted as exc:  # SIGINT/SIGTERM reached this process during the case
        return failure(params, "interrupted", str(exc), exc.exit_code)
    except AncfError as exc:  # 'failed', or 'unstable' (UnstableError)
        return failure(params, getattr(exc, "status", "failed"), str(exc), exc.exit_code)
    except Exception as exc:  # a bug or an environment problem: still only this case's
        return failure(params, "failed", internal_error(exc), 1)
    if not Path(output).is_file():
        return failure(params, "failed", f"the run reported success but wrote no result file "
                       f"where the sweep asked for it ({output})", 1)
    try:
        return dict(params, **_result_fields(outcome, Path(output)))
    except Exception as exc:
        return failure(params, "failed", internal_error(exc), 1)


def _result_fields(outcome: Any, output: Path) -> dict:
    """What a sweep tabulates from a finished run."""
    from .results.hdf5 import read_summary
    summary = read_summary(output)
    row: dict[str, Any] = dict(status="ok", message="", exit_code=0,
                               total_time_s=summary["timing.total"],
                               compute_time_s=summary["timing.compute"],
                               ndof=summary["model.ndof"])
    static, dynamic = outcome.static, outcome.dynamic
    if static is not None:
        row.update(iterations=static.iterations, residual=static.residual_norm,
                   solve_time_s=static.wall_time_s)
        # general scenes: the deflection relative to the supports' rigid motion when the
        # file has it (ancfdrv.system.supports), not the mechanism's rigid motion
        probe, component = response_of(summary)
        row.update(static_response(summary.get(f"static.deflection_support.{probe}",
                                                summary[f"static.deflection.{probe}"]),
                                    probe, component))
    if dynamic is not None:
        row.update(dynamic=True, steps=dynamic.steps, newton_iterations=dynamic.newton_iterations,
                   factorizations=dynamic.factorizations, dynamic_time_s=dynamic.wall_time_s,
                   **{f"stage_{k}": v for k, v in outcome.stages.items()})
    eigen = eigen_values(output)
    if eigen is not None:  # modal or buckling: the headline is the case's response
        analysis, values = eigen
        row.update(analysis=analysis, eigen_count=len(values),
                   eigen_time_s=summary[f"{analysis}.wall_time_s"])
        if len(values):
            row[EIGEN_HEADLINE[analysis]] = float(values[0])
    return row


def static_response(values: Any, probe: str, component: int) -> dict[str, float]:
    """A static case's compared fields from its probe's deflection ``values`` (3,): a
    beam's tip sag with its other components (tip_axial, tip_transverse, tip_lateral) for
    (tip, 1), else the compared component (response): the scene's response probe, not a
    probe that is called tip."""
    if (probe, component) == ("tip", 1):
        axial, transverse, lateral = (float(v) for v in values)
        return dict(tip_axial=axial, tip_transverse=transverse, tip_lateral=lateral)
    return dict(response=float(values[component]))


#: The row field of the headline of an eigenvalue analysis: the first elastic frequency (Hz)
#: of a modal run, the first load factor of a buckling run.
EIGEN_HEADLINE = {"modal": "first_frequency_hz", "buckling": "first_load_factor"}


def eigen_values(path: str | Path) -> tuple[str, Any] | None:
    """('modal', the elastic frequencies in Hz, ascending: the rigid-body modes, reported
    at 0 Hz, left out) or ('buckling', the load factors, ascending) of a result file; None
    for a file of another analysis."""
    import h5py
    import numpy as np
    with h5py.File(path, "r") as h5:
        if "modal" in h5:
            frequency = h5["modal/frequency"][()]
            rigid = h5["modal/rigid"][()].astype(bool) if "rigid" in h5["modal"] else \
                np.zeros(len(frequency), dtype=bool)
            return "modal", frequency[~rigid]
        if "buckling" in h5:
            return "buckling", h5["buckling/load_factor"][()]
    return None


def response_of(attrs: Any) -> tuple[str, int]:
    """The probe and component a sweep compares: the beam's tip sag (tip, transverse), or
    what the model names in the result file's 'response_probe' attributes."""
    probe = attrs.get("response_probe", "tip")
    return (probe.decode() if isinstance(probe, bytes) else str(probe),
            int(attrs.get("response_component", 1)))


# --- in this process ---------------------------------------------------------------

def run_inline(scene_file: str, base: list[str], cases: list[Case], record: Recorder) -> bool:
    """One case after the other in this process. Returns True when Ctrl-C stopped it."""
    done = 0
    try:
        for case in cases:
            row = run_case(scene_file, case.params, base + case.overrides, str(case.part))
            record(case, row, None)
            done += 1
            if row["status"] == "interrupted":  # the run's own handler caught the signal
                _stop_rows([], cases[done:], record)
                return True
    except KeyboardInterrupt:
        _stop_rows(cases[done:done + 1], cases[done + 1:], record)
        return True
    return False


def _stop_rows(running: list[Case], queued: list[Case], record: Recorder) -> None:
    for case in running:
        record(case, failure(case.params, "interrupted", "stopped by Ctrl-C while running",
                             INTERRUPTED_EXIT), None)
    for case in queued:
        record(case, failure(case.params, "cancelled", "cancelled by Ctrl-C before it started",
                             INTERRUPTED_EXIT), None)


# --- local child processes ---------------------------------------------------------

def process_context(start_method: str | None = None) -> multiprocessing.context.BaseContext:
    """The multiprocessing context of the local workers: the platform's default start method
    (as ProcessPoolExecutor uses: 'fork' on Linux up to Python 3.13, so a script without a
    ``__main__`` guard still works), or the one asked for. Under 'forkserver' the server
    imports ancfdrv once, so that each worker starts warm."""
    ctx = multiprocessing.get_context(start_method)
    if ctx.get_start_method() == "forkserver":
        ctx.set_forkserver_preload(["ancfdrv.sweep_exec", "ancfdrv.runner"])
    return ctx


def _worker_main(conn: Connection, parent_end: Connection) -> None:
    """A local worker process: run the cases it is sent, one at a time, until it receives
    None or its parent goes away. Ctrl-C is the parent's to handle (it stops the workers it
    needs to), so the worker ignores SIGINT."""
    parent_end.close()  # the copy a fork gave us: the parent's death must be EOF here
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _exit_on_sigterm)
    _die_with_parent()
    # one case at a time: a thread lock for tqdm rather than its default multiprocessing
    # semaphore, which a killed worker would leave to the resource tracker (a warning)
    from tqdm import tqdm
    tqdm.set_lock(threading.RLock())
    try:
        while True:
            try:
                job = conn.recv()
            except (EOFError, OSError):
                return
            if job is None:
                return
            row = run_case(*job)
            try:
                conn.send(row)
            except OSError:  # the parent went away (killed): nobody to report to
                return
            if row.get("status") == "interrupted":  # SIGTERM (the parent stopping us)
                return
    finally:
        conn.close()


def _die_with_parent() -> None:
    """Ask the kernel to send this worker SIGTERM when its parent dies (Linux
    PR_SET_PDEATHSIG): a killed sweep parent (SIGKILL) leaves no orphan running cases. The
    case stops at its next step boundary; its row has nobody to go to and is dropped."""
    parent = os.getppid()
    try:
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(signal.SIGTERM), 0, 0, 0)  # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:  # the parent died before the request was in place
        os._exit(128 + signal.SIGTERM)


#: how often a pool worker started by :func:`end_with_parent` looks for its parent (s)
PARENT_POLL_S = 0.25


def end_with_parent() -> None:
    """Make this process, a worker of a process pool (the ``initializer`` of a
    ``concurrent.futures.ProcessPoolExecutor`` or a ``multiprocessing.Pool``), end with its
    parent, however the parent ends (SIGTERM, SIGKILL, a crash): a parent stopped by a
    timeout left its two workers running for 25 minutes (issue 35).

    * Linux: the kernel sends SIGTERM when the parent dies (PR_SET_PDEATHSIG), so a case
      being run stops at its next step boundary (:mod:`ancfdrv.interrupt`), its file says
      'interrupted';
    * SIGTERM outside a run ends the worker at once (an idle worker, blocked on its queue);
    * a daemon thread looks for the parent every PARENT_POLL_S seconds and, once it is
      gone, sends this process SIGTERM until it ends: the first one stops a running case
      (also where PR_SET_PDEATHSIG does not exist), the next ends the worker that the
      stopped case left waiting for work that will not come.

    (PR_SET_PDEATHSIG follows the thread that started the worker: start the pool's workers
    from a thread that outlives them, e.g. the main thread, as both pools here do.)"""
    parent = os.getppid()
    _die_with_parent()
    signal.signal(signal.SIGTERM, _exit_on_sigterm)
    threading.Thread(target=_watch_parent, args=(parent,), name="ancf-parent-watch",
                     daemon=True).start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(PARENT_POLL_S)
    while True:
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(PARENT_POLL_S)


def worker_cap(requested: int, cases: int) -> int:
    """The number of local worker processes for ``requested`` (--workers) and ``cases``:
    at most one per case, per core this process may run on, and per BASE_BYTES of the
    memory available (each worker holds the interpreter, the libraries and a model), and
    at least 1. So ``--workers 100000`` runs as many workers as the machine has cores."""
    from .io.validate import BASE_BYTES, available_memory
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    by_memory = max(1, available_memory() // BASE_BYTES)
    return max(1, min(requested, cases, cores, by_memory))


def _exit_on_sigterm(signum: int, frame: Any) -> None:
    """SIGTERM (the parent stopping a busy worker) unwinds the case: its HDF5 file is closed
    and the process's resources are released."""
    raise SystemExit(128 + signum)


class _Worker:
    """A local worker process, its end of the pipe and the case it is running."""

    def __init__(self, ctx: Any) -> None:
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_worker_main, args=(child, self.conn),
                                name="ancf-sweep-worker", daemon=True)
        self.proc.start()
        child.close()  # the worker holds the only other end: its death is EOF here
        self.case: Case | None = None

    def start(self, case: Case, scene_file: str, overrides: list[str]) -> None:
        remove_quietly(case.part)  # left by an attempt whose worker died
        self.case = case
        try:
            self.conn.send((scene_file, case.params, overrides, str(case.part)))
        except OSError:  # the worker died while idle: result() reports it
            pass

    def result(self) -> dict | None:
        """The row of the current case, or None when the worker died first."""
        try:
            return self.conn.recv()
        except (EOFError, OSError):
            self.conn.close()
            self.proc.join()
            return None

    def stop(self, now: bool = False, grace: float = 5.0) -> None:
        """End the worker: after its case (now=False) or at once (SIGTERM, then SIGKILL
        after ``grace`` seconds)."""
        if now:
            self.proc.terminate()
            self.proc.join(grace)
            if self.proc.is_alive():
                self.proc.kill()
        else:
            try:
                self.conn.send(None)
            except OSError:
                pass
        self.proc.join()
        self.conn.close()


def describe_exit(exitcode: int | None) -> str:
    """How a worker process ended, e.g. 'killed by signal SIGKILL (9)'."""
    if exitcode is None:
        return "ended without a result"
    if exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = "an unknown signal"
        return f"killed by signal {name} ({-exitcode})"
    return f"exited with code {exitcode} without a result"


def run_processes(scene_file: str, base: list[str], cases: list[Case], record: Recorder, *,
                  workers: int, start_method: str | None = None, retries: int = 1) -> bool:
    """The cases on ``workers`` local worker processes, each running one case at a time.
    When a worker dies (killed by a signal, or exiting), its case is retried ``retries``
    times on a fresh worker, then failed naming the cause; the other cases go on. Returns
    True when Ctrl-C stopped the sweep (the busy workers are terminated)."""
    ctx = process_context(start_method)
    queue = deque(cases)
    pool: list[_Worker] = []
    deaths: dict[int, list[str]] = {}
    try:
        while queue or any(w.case for w in pool):
            while queue and len(pool) < workers:
                pool.append(_Worker(ctx))
            for worker in pool:
                if worker.case is None and queue:
                    case = queue.popleft()
                    worker.start(case, scene_file, base + case.overrides)
            busy = {w.conn: w for w in pool if w.case is not None}
            for conn in wait(list(busy)):
                worker = busy[conn]
                case, row = worker.case, worker.result()
                worker.case = None
                if row is None:
                    pool.remove(worker)
                    causes = deaths.setdefault(case.index, [])
                    causes.append(describe_exit(worker.proc.exitcode))
                    if len(causes) <= retries:
                        queue.appendleft(case)
                        continue
                    row = failure(case.params, "failed", _death_message(causes), 1)
                elif case.index in deaths:
                    note = f"its worker process was {deaths[case.index][-1]}"
                    row["message"] = (f"{note}; the retry on a fresh worker succeeded"
                                      if row["status"] == "ok" else
                                      f"{row['message']} (on the retry: {note} before)")
                record(case, row, None)
    except KeyboardInterrupt:
        running = [w.case for w in pool if w.case is not None]
        for worker in pool:
            worker.stop(now=worker.case is not None)
        pool.clear()
        _stop_rows(running, list(queue), record)
        return True
    finally:
        for worker in pool:
            worker.stop(now=worker.case is not None)
    return False


def _death_message(causes: list[str]) -> str:
    if len(causes) == 1:
        return f"its worker process was {causes[0]}"
    return (f"its worker process was {causes[-1]}, also on the retry with a fresh worker "
            f"(first attempt: {causes[0]})")


def remove_quietly(path: Path) -> None:
    try:
        path.unlink()
    except FileNotFoundError:
        pass


# --- Dask distributed --------------------------------------------------------------

def run_case_remote(scene_text: str, scene_label: str, params: dict[str, str],
                    overrides: list[str]) -> tuple[dict, bytes | None]:
    """A case on a Dask worker that shares no filesystem with the client: the scene text is
    written to a private temporary directory, the case runs there with an explicit output
    path, and the row comes back with the result file's bytes (None if it made none)."""
    with tempfile.TemporaryDirectory(prefix="ancf-case-") as tmp:
        scene_path = Path(tmp) / "scene.nml"
        scene_path.write_text(scene_text)
        output = Path(tmp) / "case.h5"
        row = run_case(str(scene_path), params, overrides, str(output))
        row["message"] = row.get("message", "").replace(str(scene_path), scene_label)
        data = output.read_bytes() if output.is_file() else None
    return row, data


def connect(address: str, timeout: float = CONNECT_TIMEOUT_S) -> Any:
    """A Dask client of the scheduler at ``address``; InputError (exit 2, one line) when
    distributed is missing or the scheduler does not answer within ``timeout`` seconds."""
    try:
        from distributed import Client
    except ImportError:
        raise InputError("--scheduler needs dask[distributed]: pip install 'dask[distributed]'")
    try:
        return Client(address, timeout=timeout, set_as_default=False)
    except Exception as exc:  # OSError on timeout; ValueError, TypeError on a bad address
        detail = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
        raise InputError(f"cannot reach the Dask scheduler {address!r}: {detail}") from None


def run_dask(client: Any, scene_text: str, scene_label: str, cases: list[Case],
             record: Recorder) -> bool:
    """The cases as tasks of the Dask scheduler of ``client`` (see :func:`connect` and
    :func:`run_case_remote`; the client is closed on return). A task that raises, whose
    workers all died (KilledWorker) or whose scheduler went away, fails its case only.
    Returns True when Ctrl-C stopped the sweep: the remaining tasks are cancelled (Dask
    cannot stop a task a worker thread is already running; it finishes there and its result
    is dropped)."""
    from distributed import as_completed
    quiet = _Quiet("distributed.client")  # a lost scheduler: each case's row says it
    tag = os.urandom(4).hex()  # task keys unique on a shared scheduler
    futures = {client.submit(run_case_remote, scene_text, scene_label, case.params,
                             case.overrides, pure=False, key=f"ancf-case-{case.name}-{tag}"):
               case for case in cases}
    finished: set[int] = set()
    try:
        for future in as_completed(list(futures), loop=client.loop):
            case = futures[future]
            try:
                row, data = future.result()
            except Exception as exc:
                row, data = failure(case.params, "failed", internal_error(exc), 1), None
            record(case, row, data)
            finished.add(case.index)
    except KeyboardInterrupt:
        rest = [f for f, c in futures.items() if c.index not in finished]
        running = _processing_keys(client)
        client.cancel(rest)
        _stop_rows([futures[f] for f in rest if f.key in running],
                   [futures[f] for f in rest if f.key not in running], record)
        return True
    finally:
        client.close()
        quiet.restore()
    return False


class _Quiet:
    """Raise a logger's level to CRITICAL until restore()."""

    def __init__(self, name: str) -> None:
        self.logger = logging.getLogger(name)
        self.level = self.logger.level
        self.logger.setLevel(logging.CRITICAL)

    def restore(self) -> None:
        self.logger.setLevel(self.level)


def _processing_keys(client: Any) -> set:
    """Keys of the tasks the scheduler reports as running (empty if it cannot tell)."""
    try:
        return {key for keys in client.processing().values() for key in keys}
    except Exception:
        return set()
