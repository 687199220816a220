"""What a run writes and what reads it back (SPEC sections 4 and 10): the HDF5 writer and
reader (:mod:`.hdf5`), the XDMF descriptions beside it (:mod:`.xdmf`), the output lock
(:mod:`.lock`), the check of an output path before a run (:mod:`.output_path`) and the
result object of :meth:`System.static` / :meth:`System.simulate` and ``ancfdrv.open``
(:mod:`.reader`). This layer sits above the solvers (it writes their records) and below the
builders and the runner."""
from __future__ import annotations

from typing import Any

__all__ = ["Analysis", "Record", "Results", "open_results"]


def __getattr__(name: str) -> Any:
    """The result object's names from :mod:`.reader`, imported on first use (a run writes
    its file with :mod:`.hdf5` and never reads it back as :class:`Results`)."""
    if name in __all__:
        from . import reader
        return getattr(reader, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
