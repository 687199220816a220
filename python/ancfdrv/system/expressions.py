"""Affine expressions of the full coordinate vector q: what joints, loads and probes are
written in before the assembly numbers and reduces them.

A :class:`Vec3` is c + sum_k a_k q[d_k : d_k + 3]: every position or direction of a body
point is such a combination of nodal 3-vectors with scalar coefficients (a beam's material
point: its shape functions; a rigid body's point r + J u: 1, u_1, u_2, u_3). A
:class:`Scalar` is c + sum_k a_k q[d_k] over single coordinates.
"""
from __future__ import annotations

from dataclasses import field

import numpy as np
from ..records import record


@record
class Scalar:
    """c + sum a_k q[d_k] (terms: {dof: coefficient})."""

    terms: dict[int, float] = field(default_factory=dict)
    const: float = 0.0

    def __add__(self, other: "Scalar") -> "Scalar":
        terms = dict(self.terms)
        for dof, coef in other.terms.items():
            terms[dof] = terms.get(dof, 0.0) + coef
        return Scalar({d: c for d, c in terms.items() if c != 0.0}, self.const + other.const)

    def scaled(self, factor: float) -> "Scalar":
        return Scalar({d: factor * c for d, c in self.terms.items()}, factor * self.const)

    def __sub__(self, other: "Scalar") -> "Scalar":
        return self + other.scaled(-1.0)

    def value(self, q: np.ndarray) -> float:
        return self.const + sum(c * q[d] for d, c in self.terms.items())


@record
class Vec3:
    """c + sum a_k q[d_k : d_k + 3] (terms: {first dof of a 3-vector: coefficient})."""

    terms: dict[int, float] = field(default_factory=dict)
    const: np.ndarray = field(default_factory=lambda: np.zeros(3))

    @classmethod
    def constant(cls, value) -> "Vec3":
        return cls({}, np.array(value, dtype=float))

    @classmethod
    def of(cls, first: int, coef: float = 1.0) -> "Vec3":
        """The nodal 3-vector q[first : first + 3]."""
        return cls({first: coef}, np.zeros(3))

    def __add__(self, other: "Vec3") -> "Vec3":
        terms = dict(self.terms)
        for dof, coef in other.terms.items():
            terms[dof] = terms.get(dof, 0.0) + coef
        return Vec3({d: c for d, c in terms.items() if c != 0.0}, self.const + other.const)

    def scaled(self, factor: float) -> "Vec3":
        return Vec3({d: factor * c for d, c in self.terms.items()}, factor * self.const)

    def __sub__(self, other: "Vec3") -> "Vec3":
        return self + other.scaled(-1.0)

    def component(self, i: int) -> Scalar:
        return Scalar({d + i: c for d, c in self.terms.items()}, float(self.const[i]))

    def along(self, direction) -> Scalar:
        """k . v for a constant direction k."""
        k = np.asarray(direction, dtype=float)
        out = Scalar({}, float(k @ self.const))
        for i in range(3):
            if k[i] != 0.0:
                out = out + Scalar({d + i: k[i] * c for d, c in self.terms.items()}, 0.0)
        return out

    def components(self) -> list[Scalar]:
        return [self.component(i) for i in range(3)]

    def value(self, q: np.ndarray) -> np.ndarray:
        out = self.const.copy()
        for d, c in self.terms.items():
            out += c * q[d:d + 3]
        return out


def combination(vectors: list[Vec3], coefficients) -> Vec3:
    """sum_k c_k v_k."""
    out = Vec3()
    for v, c in zip(vectors, coefficients):
        if c != 0.0:
            out = out + v.scaled(float(c))
    return out
