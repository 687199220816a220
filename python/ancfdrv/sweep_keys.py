"""What a sweep's keys and rows mean, shared by the sweep (:mod:`ancfdrv.sweep`) and its
plots (:mod:`ancfdrv.plots`): which keys refine a model, in which sense, and the static
quantity the rows compare, and the response a sweep picked for them."""
from __future__ import annotations

from .io.scene import parse_address


def full_model_first(values):
    """The sense of ``beam.modes``: 0 (the full FFR model) is the finest, then the most
    modes."""
    return max(values, key=lambda v: float("inf") if float(v) == 0 else float(v))


#: Parameters that refine a model; the finest value is the reference of the others.
RESOLUTION_KEYS = {"beam.nodes": max, "solver.dt": min, "plate.nx": max, "plate.ny": max,
                   "leaf.nx": max, "leaf.ny": max, "beam.modes": full_model_first}


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


def resolution_rank(key: str, value) -> float:
    """Orders a refining key's values finest first (smallest rank)."""
    sense = resolution_sense(key)
    if sense is full_model_first:
        return -float("inf") if float(value) == 0 else -float(value)
    return (-1 if sense is max else 1) * float(value)


def static_value(row: dict) -> float:
    """The quantity a sweep compares in a case without a history: the tip sag for beams,
    the response probe's deflection otherwise, the headline of a modal or buckling case
    (its first elastic frequency or first load factor)."""
    for key in ("tip_transverse", "response", "first_frequency_hz", "first_load_factor"):
        if key in row:
            return row[key]
    raise KeyError(f"case {row.get('case', '?')} has no compared quantity")


#: A compared probe and component, (probe, component)
Response = tuple[str, int]


def row_response(row: dict) -> Response | None:
    """The response the sweep picked for a row's case (``ancfdrv.sweep.pick_response``:
    a general scene without a named response); None: the result file's own
    (``response_probe``, ``response_component``)."""
    return (row["response_probe"], int(row["response_component"])) \
        if "response_probe" in row else None
