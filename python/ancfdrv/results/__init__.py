"""What a run writes and what reads it back (SPEC sections 4 and 10): the HDF5 writer and
reader (:mod:`.hdf5`), the XDMF descriptions beside it (:mod:`.xdmf`), the output lock
(:mod:`.lock`), the check of an output path before a run (:mod:`.output_path`) and the
result object of :meth:`System.static` / :meth:`System.simulate` and ``ancfdrv.open``
(:mod:`.reader`). This layer sits above the solvers (it writes their records) and below the
builders and the runner."""
from __future__ import annotations

from .reader import Analysis, Record, Results, open_results

__all__ = ["Analysis", "Record", "Results", "open_results"]
