"""What a sweep's keys and rows mean, shared by the sweep (:mod:`ancfdrv.sweep`) and its
plots (:mod:`ancfdrv.plots`): which keys refine a model, in which sense, and the static
quantity the rows compare."""
from __future__ import annotations

from .io.scene import parse_address

#: Parameters that refine a model; the finest value is the reference of the others.
RESOLUTION_KEYS = {"beam.nodes": max, "solver.dt": min, "plate.nx": max, "plate.ny": max,
                   "leaf.nx": max, "leaf.ny": max}


def _plain_key(part: str) -> str:
    """'beam[upper].nodes' -> 'beam.nodes' (the schema key a named group's key stands for)."""
    group, _, key = parse_address(part)
    return f"{group}.{key}"


def is_resolution(key: str) -> bool:
    """A refining key, or keys tied with '+' that all refine (plate.nx+plate.ny)."""
    return all(_plain_key(part) in RESOLUTION_KEYS for part in key.split("+"))


def resolution_sense(key: str):
    """max or min: the sense in which the key (the first of tied keys) refines."""
    return RESOLUTION_KEYS[_plain_key(key.split("+")[0])]


def static_value(row: dict) -> float:
    """The static quantity a sweep compares (tip sag for beams)."""
    return row["tip_transverse"] if "tip_transverse" in row else row["response"]
