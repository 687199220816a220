"""Analytic derivatives of the moment force and the constraints against central
differences (the standard of every kernel routine), including large rotations."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import kernel
from ancfdrv.codes import (CONSTRAINT_COORDINATE, CONSTRAINT_CROSS, CONSTRAINT_DISTANCE,
                           CONSTRAINT_DOT, DRIVE_LUFFING, DRIVE_SINE)
from ancfdrv.system.constraint_set import ConstraintSet

RNG = np.random.default_rng(7)


@pytest.mark.parametrize("angle", [0.0, 0.7, 2.9, -3.1])
def test_moment_force_is_m_times_gradient_of_rotation_angle(angle):
    axis = np.array([0.0, 0.0, 1.0])
    director = 1.3 * np.array([-np.sin(angle), np.cos(angle), 0.2])
    force, jac, hess = kernel.moment_force(director, axis, 1000.0)

    def theta(d):
        return np.arctan2(-d[0], d[1])

    h = 1e-6
    for i in range(3):
        step = np.zeros(3)
        step[i] = h
        dtheta = (np.unwrap([theta(director - step), theta(director + step)])[1]
                  - np.unwrap([theta(director - step), theta(director + step)])[0]) / (2 * h)
        assert force[i] == pytest.approx(1000.0 * dtheta, rel=1e-7, abs=1e-6)
        f_plus, j_plus, _ = kernel.moment_force(director + step, axis, 1000.0)
        f_minus, j_minus, _ = kernel.moment_force(director - step, axis, 1000.0)
        np.testing.assert_allclose((f_plus - f_minus) / (2 * h), jac[:, i], rtol=1e-6, atol=1e-4)
        np.testing.assert_allclose((j_plus - j_minus) / (2 * h), hess[:, :, i], rtol=1e-6,
                                   atol=1e-3)
    np.testing.assert_allclose(jac, jac.T, atol=1e-9)  # conservative load


def test_moment_force_rejects_director_along_axis():
    from ancfdrv.errors import SolverError
    with pytest.raises(SolverError, match="parallel"):
        kernel.moment_force([0.0, 0.0, 2.0], [0.0, 0.0, 1.0], 10.0)


def random_constraints(ndof: int) -> ConstraintSet:
    """One constraint of every kind, with operands that combine several coordinates (as a
    rigid body's point r + J u does) and driven values."""
    c = ConstraintSet(drive_kinds=[DRIVE_LUFFING, DRIVE_SINE],
                      drive_params=[[0.2, 1.0, 1.0, np.pi / 3, 0.1],
                                    [0.3, 0.7, 0.2, 1.1, 0.0, 0.5]])

    def single(dofs):
        return [({d: 1.0}, 0.0) for d in dofs]
    c.add(CONSTRAINT_COORDINATE, [({4: 1.0, 7: -0.6}, 0.2)], [0.5, 1.7, -0.3, 0.4], 0,
          "driven coordinate")
    c.add(CONSTRAINT_DISTANCE, single([0, 1, 2]) + [({}, 0.1), ({}, -0.2), ({}, 0.3)],
          [0.9, 0.0], -1, "distance to a point")
    c.add(CONSTRAINT_DISTANCE, [({0: 1.0, 3: 0.4}, 0.0), ({1: 1.0, 4: 0.4}, 0.0),
                                ({2: 1.0, 5: 0.4}, 0.0)] + single([12, 13, 14]),
          [0.0, 1.0], 1, "driven distance between two points")
    c.add(CONSTRAINT_CROSS, [({3: 1.0}, -0.5), ({4: 1.0}, -0.5), ({5: 1.0}, 0.0)]
          + single([9, 10, 11]), [0.2, 0.3, 0.9], -1, "cross")
    c.add(CONSTRAINT_DOT, single([6, 7, 8, 12, 13, 14]), [0.4], -1, "dot")
    return c


@pytest.mark.parametrize("t", [0.4, 3.0, 5.6])
def test_constraint_gradients_hessians_and_time_derivatives(t):
    ndof = 15
    c = random_constraints(ndof)
    e = RNG.standard_normal(ndof)
    e_dot = RNG.standard_normal(ndof)
    values, grads, hess, phi_t, phi_tt, gamma = c.evaluate(e, t, e_dot)
    jacobian = c.gradient_rows(e, ndof, t)
    hessian = np.zeros((len(c), ndof, ndof))
    for k, row, col, value in zip(*c.hessian_triplets(e)):
        hessian[k, row, col] += value
    h = 1e-6
    for j in range(ndof):
        step = np.zeros(ndof)
        step[j] = h
        fd = (c.evaluate(e + step, t)[0] - c.evaluate(e - step, t)[0]) / (2 * h)
        np.testing.assert_allclose(jacobian[:, j], fd, rtol=1e-7, atol=1e-8)
        fd_rows = (c.gradient_rows(e + step, ndof, t)
                   - c.gradient_rows(e - step, ndof, t)) / (2 * h)
        np.testing.assert_allclose(hessian[:, :, j], fd_rows, atol=1e-7)
    ht = 1e-5
    fd_t = (c.evaluate(e, t + ht)[0] - c.evaluate(e, t - ht)[0]) / (2 * ht)
    np.testing.assert_allclose(phi_t, fd_t, atol=1e-8)
    htt = 1e-4  # a second difference: round-off eps |Phi| / h^2 wants a larger step
    fd_tt = (c.evaluate(e, t + htt)[0] - 2 * values + c.evaluate(e, t - htt)[0]) / htt**2
    np.testing.assert_allclose(phi_tt, fd_tt, atol=1e-5)
    # gamma = -d/dt(Phi_e e_dot) - Phi_tt along a path e(t) = e + t e_dot (e'' = 0):
    # then d2 Phi/dt2 = -gamma, checked by central differences along the path
    path = lambda s: c.evaluate(e + s * e_dot, t + s)[0]  # noqa: E731
    d2 = (path(ht) - 2 * path(0.0) + path(-ht)) / ht**2
    np.testing.assert_allclose(d2, -gamma, atol=2e-4)


def test_luffing_drive_profile_spec_section5():
    """phi(t2) = pi/3 exactly; phi' is the SPEC's rate profile; phi is its integral."""
    omega, t_s, t_b, phi_end = 0.2, 1.0, 1.0, np.pi / 3
    t_c = phi_end / omega - (t_s + t_b) / 2
    t2 = t_s + t_c + t_b
    t = np.linspace(0, 10, 20001)
    phi, dphi, ddphi = kernel.drive_values(DRIVE_LUFFING, [omega, t_s, t_b, phi_end], t)
    assert kernel.drive_values(DRIVE_LUFFING, [omega, t_s, t_b, phi_end], [t2])[0][0] == \
        pytest.approx(np.pi / 3, abs=1e-15)
    assert phi[-1] == pytest.approx(np.pi / 3, abs=1e-15)
    mid = (t > t_s + 0.1) & (t < t_s + t_c - 0.1)
    np.testing.assert_allclose(dphi[mid], omega, rtol=1e-15)
    integral = np.concatenate([[0], np.cumsum((dphi[1:] + dphi[:-1]) / 2 * np.diff(t))])
    np.testing.assert_allclose(phi, integral, atol=1e-8)
    np.testing.assert_allclose(np.gradient(dphi, t)[1:-1], ddphi[1:-1], atol=2e-3)
