"""One writer per result file: an exclusive lock on a sidecar ``OUT.h5.lock``.

A run holds ``fcntl.flock(LOCK_EX)`` on ``OUT.h5.lock`` (beside the resolved output path)
from before the HDF5 file is created until its final status is written; the lock file
holds the writer's pid, host, start time and command line, so a second writer is refused
with a message naming the holder. The operating system drops the lock when its process
ends, however it ends (kill -9 included): a lock file left by a dead process is stale
and never blocks. The lock file is removed when the run releases it.

The HDF5 file itself is not locked with ``flock``: HDF5 takes its own lock on it each
time a writer or reader opens it, and the two would collide within one process.
Two names of one file by a hard link get two lock files: use one name.
"""
from __future__ import annotations

import datetime as _dt
import errno
import fcntl
import json
import os
import shlex
import sys
import time
from pathlib import Path

from ..records import record
from ..errors import InputError

#: how long a writer retries a busy lock before giving up: long enough to ride out a
#: reader's momentary probe (``holder``), far too short to wait for another run
_RETRY_SECONDS = 0.3


@record(frozen=True)
class LockHolder:
    """Who holds (or held) the lock of a result file."""

    pid: int | None
    host: str
    since: str
    command: str = ""

    def describe(self) -> str:
        pid = "unknown pid" if self.pid is None else f"pid {self.pid}"
        return f"{pid} on host {self.host or 'unknown'}, since {self.since or 'unknown'}"


def lock_path(path: str | Path) -> Path:
    """The sidecar lock file of a result file: ``OUT.h5.lock`` beside the resolved path
    (so that two spellings of one path, or a symbolic link, share a lock)."""
    resolved = Path(path).resolve()
    return resolved.with_name(resolved.name + ".lock")


def _read_holder(fd: int) -> LockHolder:
    try:
        os.lseek(fd, 0, os.SEEK_SET)
        data = json.loads(os.read(fd, 65536).decode() or "{}")
    except (OSError, ValueError):
        data = {}
    pid = data.get("pid")
    return LockHolder(pid=int(pid) if isinstance(pid, int) else None,
                      host=str(data.get("host", "")), since=str(data.get("since", "")),
                      command=str(data.get("command", "")))


def holder(path: str | Path) -> LockHolder | None:
    """The live writer of a result file, or None when no process holds its lock (never
    locked, finished, or its writer died)."""
    lock = lock_path(path)
    try:
        fd = os.open(lock, os.O_RDONLY | os.O_CLOEXEC | getattr(os, "O_NOFOLLOW", 0))
    except OSError:
        return None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except OSError as exc:
            if exc.errno in (errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK):
                return _read_holder(fd)
            return None
        fcntl.flock(fd, fcntl.LOCK_UN)
        return None
    finally:
        os.close(fd)


class OutputLock:
    """Exclusive ownership of a result file for the duration of a ``with`` block.

    Entering raises InputError (exit status 2) naming the holder when another live
    process writes the same file, or when the lock file cannot be created.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.lock = lock_path(path)
        self._fd: int | None = None

    def __enter__(self) -> "OutputLock":
        self.acquire()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    def acquire(self) -> None:
        deadline = time.monotonic() + _RETRY_SECONDS
        while True:
            fd = self._open()
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                if exc.errno not in (errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK):
                    os.close(fd)
                    raise InputError(f"cannot lock {self.lock}: {exc.strerror}",
                                     file=str(self.path)) from None
                if time.monotonic() < deadline:
                    os.close(fd)
                    time.sleep(0.02)
                    continue
                other = _read_holder(fd)
                os.close(fd)
                raise InputError(
                    f"is being written by another run ({other.describe()}); wait for it to "
                    "finish or choose another output file", file=str(self.path)) from None
            if self._same_file(fd):
                break
            # the previous holder removed the lock file between our open and our lock
            os.close(fd)
        # the host name as socket.gethostname() gives it (uname's node name), without
        # the socket module (0.4 MB of a run's peak memory; issue 23)
        record = {"pid": os.getpid(), "host": os.uname().nodename,
                  "since": _dt.datetime.now().astimezone().isoformat(timespec="seconds"),
                  "command": shlex.join(sys.argv)}
        text = (json.dumps(record) + "\n").encode()
        # written over a stale record, then cut to its length: a truncation to 0 bytes
        # makes ext4 (auto_da_alloc) write the file out when it is closed, ~4 ms a run
        os.pwrite(fd, text, 0)
        os.ftruncate(fd, len(text))
        self._fd = fd

    def release(self) -> None:
        """Remove the lock file (while still holding it) and drop the lock."""
        if self._fd is None:
            return
        try:
            if self._same_file(self._fd):
                os.unlink(self.lock)
        except OSError:
            pass  # a lock file that stays behind is stale: it blocks nobody
        finally:
            os.close(self._fd)
            self._fd = None

    def _open(self) -> int:
        try:
            return os.open(self.lock, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC
                           | getattr(os, "O_NOFOLLOW", 0), 0o644)
        except OSError as exc:
            if exc.errno == errno.ELOOP:  # never write through a link planted at the name
                raise InputError(f"the lock file {self.lock} is a symbolic link; remove it "
                                 "(a run writes its lock file itself)",
                                 file=str(self.path)) from None
            raise InputError(f"cannot create the lock file {self.lock}: {exc.strerror}",
                             file=str(self.path)) from None

    def _same_file(self, fd: int) -> bool:
        try:
            on_disk = os.stat(self.lock)
        except FileNotFoundError:
            return False
        mine = os.fstat(fd)
        return (on_disk.st_dev, on_disk.st_ino) == (mine.st_dev, mine.st_ino)
