"""Contact pairs between plate or leaf surfaces (seed 003 eqs. 17-28; the kernel's
``fortran/src/system/leaf_contact.f90``): points on body2's surface (on its two end edges,
``points`` per edge; the upper surface) are searched on body1's lower surface, with a
penalty normal force F_n = K d - C d' d and a smooth Coulomb friction with critical slip
speed V_t. Each pair has its own K, C, mu, V_t. Effect 'contact'; friction also needs the
effect 'friction' (mu = 0 or the effect off: frictionless).
"""
from __future__ import annotations


import numpy as np

from ..records import record
from ..errors import InputError
from .bodies import Body


@record
class ContactPair:
    name: str
    body1: Body             # the searched (upper) surface (a plate or leaf)
    body2: Body             # the points' (lower) surface
    stiffness: float
    damping: float = 0.0
    friction: float = 0.0
    slip_speed: float = 0.08
    points: int = 3
    effect: str = "contact"

    def __post_init__(self) -> None:
        where = f"contact {self.name!r}"
        for body in (self.body1, self.body2):
            if not body.surface:
                raise InputError(f"{where}: {body.name!r} is not a plate or leaf surface")
        if self.body1 is self.body2:
            raise InputError(f"{where}: body1 and body2 are the same surface")
        if not (np.isfinite(self.stiffness) and self.stiffness > 0):
            raise InputError(f"{where}: stiffness must be positive")
        for key in ("damping", "friction"):
            if not (np.isfinite(getattr(self, key)) and getattr(self, key) >= 0):
                raise InputError(f"{where}: {key} must not be negative")
        if not (np.isfinite(self.slip_speed) and self.slip_speed > 0):
            raise InputError(f"{where}: slip_speed must be positive")
        if not isinstance(self.points, (int, np.integer)) or self.points < 2:
            raise InputError(f"{where}: points (per edge) must be an integer >= 2")
