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
    sets = [s for s in model.sets if s.kind == "ffr"]
    if not sets:
        return []
    q = model.expand(e)
    out = []
    for info in sets:
        frame = model.frames[info.frame - 1]
        rotation = frame.rotation(t)
        current = q[info.dofs].reshape(3, 8, info.nel, order="F")      # (xyz, vector, el)
        reference = np.asarray(info.reference).reshape(3, 8, info.nel, order="F")
        directions = [1, 2, 3, 5, 6, 7]   # r_x, r_y, r_z of both nodes
        local = np.einsum("ji,jvn->ivn", rotation, current[:, directions])
        change = np.linalg.norm(local - reference[:, directions], axis=0)
        out.append((info.body.name, float(np.max(change, initial=0.0))))
    return out


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
