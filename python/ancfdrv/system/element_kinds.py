"""Element kinds: where each family of elements registers how its element set is built from
a body (the assembly) and handed to the kernel (``Model.build_kernel``).

A family is one Fortran module (an extension of ``element_set`` in
``fortran/src/system/element_sets.f90``, built by one ``system_add_<kind>_set`` routine)
plus one Python file that registers

- a *set builder* for its body class: ``build(body, context) -> SetInfo`` (the element
  dofs, the element masses as compact (n, n, nel) matrices of the scalar shape functions,
  and whatever the kernel's set needs);
- a *kernel adder* for its set kind: ``add(kernel_system, info) -> int`` (the set's index).

The beams ('ffr', 'continuum', 'cubic') and plates register in ``assembly``; the cable in
``cable``. A body whose class has no builder has no element set (rigid bodies, the ground).
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any, Callable

__all__ = ["SetContext", "register_body", "register_set", "set_builder", "add_to_kernel"]


@dataclass
class SetContext:
    """What a set builder may need besides its body: the body's floating frame (FrameInfo,
    or None) and its 1-based id (0: none), the active effects, the counters and warnings."""

    frame: Any = None
    frame_id: int = 0
    active: set[str] = field(default_factory=set)
    counters: Counter = field(default_factory=Counter)
    warnings: list[str] = field(default_factory=list)


_BUILDERS: dict[type, Callable[[Any, SetContext], Any]] = {}
_ADDERS: dict[str, Callable[[Any, Any], int]] = {}


def register_body(body_type: type, build: Callable[[Any, SetContext], Any]) -> None:
    """Bodies of ``body_type`` (and its subclasses) get their element set from ``build``."""
    _BUILDERS[body_type] = build


def register_set(kind: str, add: Callable[[Any, Any], int]) -> None:
    """Sets of ``kind`` (SetInfo.kind) reach the kernel through ``add``."""
    _ADDERS[kind] = add


def set_builder(body) -> Callable[[Any, SetContext], Any] | None:
    """The set builder of the body's class (the nearest registered base), or None."""
    for cls in type(body).__mro__:
        if cls in _BUILDERS:
            return _BUILDERS[cls]
    return None


def add_to_kernel(kernel_system, info) -> int:
    """Hands one assembled set to the kernel; its index there."""
    try:
        add = _ADDERS[info.kind]
    except KeyError:
        raise ValueError(f"no kernel adder registered for element sets of kind {info.kind!r}") \
            from None
    return add(kernel_system, info)
