"""Whether a solution stays within its formulation's assumptions (SPEC 8.1: a model outside
them is refused, never a status 'ok' with a warning).

An 'ffr' beam is linear in its floating frame: its strains are linear in the nodal vectors'
changes from their reference in the frame, which holds while those changes are small. The
measure is the largest change of a section vector r_x, r_y, r_z (unit at t = 0) from its
reference in the frame, |A(t)^T r_i - r_i0|: about the section's turn in radians plus its
strain. Beyond :data:`FFR_LIMIT` the linear model's answer is no longer the structure's (a
turn of 0.1 rad already reads as a spurious strain of 0.5%), and the solvers stop with a
:class:`~ancfdrv.errors.SolverError` (exit 3) naming the beam and suggesting 'nonlinear'.
"""
from __future__ import annotations

import numpy as np

from ..errors import SolverError

#: the largest change of a section vector of an 'ffr' beam from its reference in the frame
FFR_LIMIT = 0.1


def ffr_departures(model, e: np.ndarray, t: float) -> list[tuple[str, float]]:
    """(beam, largest change of a section vector in its frame) of every 'ffr' beam of the
    model at the state e and time t."""
    return [(name, float(change[0]))
            for name, change in ffr_departure_rows(model, np.atleast_2d(e), np.atleast_1d(t))]


def ffr_departure_rows(model, rows: np.ndarray, times: np.ndarray) -> list[tuple[str, np.ndarray]]:
    """(beam, largest change of a section vector in its frame at each row) of every 'ffr'
    beam for the states rows (n, ndof) at the times (n,): a run's chunk at once, one kernel
    call per beam (``ffr_elastic.f90`` ffr_departures: each section vector turned into the
    frame at the row's rotation, as the elastic forces turn it; a vector shared by
    neighbouring elements measured once)."""
    sets = [s for s in model.sets if s.floating]
    if not sets:
        return []
    rows = np.atleast_2d(np.asarray(rows, dtype=float))
    times = np.atleast_1d(np.asarray(times, dtype=float))
    return [(info.body.name, model.kernel.ffr_departures(info.index, times, rows))
            for info in sets]


def _section_vectors(info) -> tuple[np.ndarray, np.ndarray]:
    """(first dof (m,), reference in the frame (m, 3)) of the section vectors r_x, r_y, r_z
    of an 'ffr' set's elements, each (vector, reference) once (neighbouring elements share
    their common node's: half the work, the same maximum)."""
    cached = info.__dict__.get("_section_vectors") if hasattr(info, "__dict__") else None
    if cached is not None:
        return cached
    directions = [1, 2, 3, 5, 6, 7]   # r_x, r_y, r_z of both nodes
    dofs = np.asarray(info.dofs).reshape(3, 8, info.nel, order="F")[0, directions]   # (6, el)
    reference = np.asarray(info.reference).reshape(3, 8, info.nel, order="F")
    reference = reference[:, directions].transpose(2, 1, 0)          # (el, vector, xyz)
    table = np.column_stack([dofs.T.reshape(-1), reference.reshape(-1, 3)])
    # np.unique(table, axis=0) (rows sorted by their columns, each once) without numpy.ma
    table = table[np.lexsort(table.T[::-1])]
    table = table[np.concatenate([[True], (table[1:] != table[:-1]).any(axis=1)])]
    found = (table[:, 0].astype(np.int64), np.ascontiguousarray(table[:, 1:]))
    if hasattr(info, "__dict__"):
        info.__dict__["_section_vectors"] = found
    return found


def check_ffr(model, e: np.ndarray, t: float, *, when: str) -> None:
    """SolverError when an 'ffr' beam's section vectors leave the small-strain range at the
    state e (``when``: where the run stands, for the message)."""
    for name, change in ffr_departures(model, e, t):
        if not np.isfinite(change) or change > FFR_LIMIT:
            raise SolverError(
                f"beam {name!r} (formulation 'ffr') leaves its small-strain assumption {when}: "
                f"its section vectors change by {change:.3g} in its floating frame (a turn of "
                f"about {change:.3g} rad or a strain of {change:.3g}; the linear model holds "
                f"below {FFR_LIMIT:g}); use formulation = 'nonlinear' for it, or give its "
                "frame the motion it follows (frame_drive)")
