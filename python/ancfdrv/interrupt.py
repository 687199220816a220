"""SIGINT (Ctrl-C) and SIGTERM as a request to stop a run cleanly.

While a :class:`StopRequest` is active (a ``with`` block in the main thread) the two
signals do not kill the process: they are recorded, and the run stops at the next point
where its output is consistent (after the chunk being computed, which the time
integrator keeps below ~0.25 s of wall time, or under step control after the step being
tried), marks the file 'interrupted' and raises :class:`~ancfdrv.errors.Interrupted`
(exit status 130 for SIGINT, 143 for SIGTERM). Phases that cannot look at the request
(model building, a static solve) run inside :meth:`StopRequest.immediate`, where a signal
raises at once: they write nothing. (A handler runs between two Python operations: a
kernel call in progress, e.g. one load step of the static Newton solve, is finished first.)
"""
from __future__ import annotations

import signal
import threading
from contextlib import contextmanager
from typing import Any, Iterator

from .errors import Interrupted

SIGNALS = (signal.SIGINT, signal.SIGTERM)


def signal_name(signum: int | None) -> str:
    """'SIGINT', 'SIGTERM', ... (or 'a signal' when unknown)."""
    if signum is None:
        return "a signal"
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


class StopRequest:
    """Records SIGINT and SIGTERM while active; calling it says whether one arrived.

    Outside the main thread (a Dask worker thread) signal handlers cannot be installed:
    the request is then inert and never says stop.
    """

    def __init__(self) -> None:
        self.signum: int | None = None
        self._immediate = False
        self._saved: dict[int, Any] = {}

    def __call__(self) -> bool:
        return self.signum is not None

    def __enter__(self) -> "StopRequest":
        if threading.current_thread() is threading.main_thread():
            for signum in SIGNALS:
                self._saved[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for signum, previous in self._saved.items():
            signal.signal(signum, previous)
        self._saved.clear()

    def _handle(self, signum: int, frame: object) -> None:
        if self.signum is None:
            self.signum = signum
        if self._immediate:
            self._immediate = False
            raise Interrupted(f"interrupted by {signal_name(signum)}", signum=signum)

    def check(self) -> None:
        """Raise Interrupted when a stop was requested."""
        if self.signum is not None:
            raise Interrupted(f"interrupted by {signal_name(self.signum)}", signum=self.signum)

    @contextmanager
    def immediate(self) -> Iterator[None]:
        """A block that a signal interrupts at once (it must leave no half-written output)."""
        self.check()
        self._immediate = True
        try:
            yield
        finally:
            self._immediate = False
