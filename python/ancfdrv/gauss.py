"""Gauss-Legendre rules on [-1, 1] as numpy's ``np.polynomial.legendre.leggauss(n)``
returns them (each float written by its repr, which reads back bit for bit), without
importing numpy.polynomial: ~3 ms of a small ``ancf run``'s start (issue 38).
``tests/test_gauss.py`` compares them with numpy's."""
from __future__ import annotations

import numpy as np

#: n -> (points, weights), the values ``leggauss(n)`` returns
_RULES: dict[int, tuple[tuple[float, ...], tuple[float, ...]]] = {
    3: ((-0.7745966692414834, 0.0, 0.7745966692414834),
        (0.5555555555555557, 0.8888888888888888, 0.5555555555555557)),
    5: ((-0.906179845938664, -0.5384693101056831, 0.0, 0.5384693101056831,
         0.906179845938664),
        (0.23692688505618928, 0.4786286704993663, 0.5688888888888887, 0.4786286704993663,
         0.23692688505618928)),
}


def leggauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The points and weights of the n-point rule (n = 3 or 5; new arrays)."""
    points, weights = _RULES[n]
    return np.array(points), np.array(weights)
