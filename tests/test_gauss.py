"""ancfdrv.gauss: the Gauss-Legendre rules the package uses without importing
numpy.polynomial are numpy's (points and weights to round-off) and integrate the
polynomials they must exactly."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv.gauss import leggauss


@pytest.mark.parametrize("n", [3, 5])
def test_rules_are_numpys(n):
    points, weights = leggauss(n)
    reference = np.polynomial.legendre.leggauss(n)
    assert np.allclose(points, reference[0], rtol=0.0, atol=4e-16)
    assert np.allclose(weights, reference[1], rtol=0.0, atol=4e-16)


@pytest.mark.parametrize("n", [3, 5])
def test_rules_integrate_degree_2n_minus_1_exactly(n):
    points, weights = leggauss(n)
    for degree in range(2 * n):
        exact = 2.0 / (degree + 1) if degree % 2 == 0 else 0.0
        assert abs(weights @ points**degree - exact) < 1e-14, degree


def test_each_call_returns_new_arrays():
    points, _ = leggauss(3)
    points[0] = 99.0
    assert leggauss(3)[0][0] == pytest.approx(-np.sqrt(0.6), abs=1e-15)
