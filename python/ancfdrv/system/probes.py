"""Probes: named material points whose positions (and deflections) are recorded."""
from __future__ import annotations


import numpy as np

from ..records import record
from .bodies import Body


@record
class Probe:
    """A material point of a body (any point of a rigid body, a point of a beam's volume or
    of a plate's mid-surface). Beams resolve its deflection in their frame, other bodies in
    global components."""

    name: str
    body: Body
    point: np.ndarray
