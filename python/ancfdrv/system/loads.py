"""Loads, each belonging to an effect (what ``scene.effects`` switches on):

- :class:`Gravity` (effect 'gravity'): the weight of every body and point mass;
- :class:`PointForce` (effect 'point_loads'): a force at a material point, constant or
  scaled by a drive, dead or ``follower`` (fixed in the body's material frame there);
- :class:`DeadMoment` (effect 'point_loads'): a moment (vector: axis times magnitude, N m)
  on the section at a material point (beams: any point, between nodes through the shape
  functions; plates: a node) or on a rigid body, constant, scaled by a drive, or
  ``follower``;
- :class:`PointMass` (effect 'tip_mass'): a lumped mass at a material point (mass matrix
  and, with gravity, its weight);
- :class:`Pressure` (effect 'pressure'): a dead pressure on a plate or leaf along minus its
  initial normal (r_x x r_y), per element at its centre.
"""
from __future__ import annotations

import math

import numpy as np

from ..records import record
from ..errors import InputError
from .bodies import Body
from .drives import Drive


def _vector(value, what: str) -> np.ndarray:
    v = np.asarray(value, dtype=float).ravel()
    if v.shape != (3,) or not all(map(math.isfinite, v.tolist())):   # (np.isfinite(v).all())
        raise InputError(f"{what}: expected three finite numbers, got {value!r}")
    return v


def _flag(value, what: str) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"{what}: expected True or False, got {value!r}")
    return bool(value)


class Load:
    """Base of the loads: a name and the effect it belongs to."""

    name: str
    effect: str


@record
class Gravity(Load):
    name: str
    vector: np.ndarray
    effect: str = "gravity"

    def __post_init__(self) -> None:
        self.vector = _vector(self.vector, f"load {self.name!r}: vector")


@record
class PointForce(Load):
    name: str
    body: Body
    point: np.ndarray
    vector: np.ndarray
    drive: Drive | None = None
    effect: str = "point_loads"
    #: fixed in the body's material frame at the point (the vector given at t = 0)
    follower: bool = False

    def __post_init__(self) -> None:
        self.point = _vector(self.point, f"load {self.name!r}: point")
        self.vector = _vector(self.vector, f"load {self.name!r}: vector")
        self.follower = _flag(self.follower, f"load {self.name!r}: follower")


@record
class DeadMoment(Load):
    """A moment (vector: axis times magnitude, N m) on the section at a material point:
    without drive nor follower the constant moment of seed 000 (its rotation measured about
    the fixed axis); with a ``drive`` it is scaled by the drive's value and acts on the
    current section about the fixed spatial vector; ``follower``: its components in the
    body's material frame at the point are kept (it turns with the body)."""

    name: str
    body: Body
    point: np.ndarray
    vector: np.ndarray
    effect: str = "point_loads"
    drive: Drive | None = None
    follower: bool = False

    def __post_init__(self) -> None:
        self.point = _vector(self.point, f"load {self.name!r}: point")
        self.vector = _vector(self.vector, f"load {self.name!r}: vector")
        self.follower = _flag(self.follower, f"load {self.name!r}: follower")
        if np.linalg.norm(self.vector) == 0.0:
            raise InputError(f"load {self.name!r}: the moment vector must not vanish (it gives "
                             "the axis)")


@record
class PointMass(Load):
    name: str
    body: Body
    point: np.ndarray
    mass: float
    effect: str = "tip_mass"

    def __post_init__(self) -> None:
        self.point = _vector(self.point, f"load {self.name!r}: point")
        if not (np.isfinite(self.mass) and self.mass >= 0):
            raise InputError(f"load {self.name!r}: mass {self.mass!r} must not be negative")


@record
class Pressure(Load):
    name: str
    body: Body
    value: float
    effect: str = "pressure"

    def __post_init__(self) -> None:
        if not self.body.surface:
            raise InputError(f"load {self.name!r}: a pressure acts on a plate or leaf, not on "
                             f"{self.body.name!r}")
        if not np.isfinite(self.value):
            raise InputError(f"load {self.name!r}: value must be finite")


LOAD_TYPES = {"gravity": Gravity, "force": PointForce, "moment": DeadMoment,
              "point_mass": PointMass, "pressure": Pressure}
