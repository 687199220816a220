"""The stepper's work outside the Newton corrections (issue 26, w6-step): each leaner path
against an independent reference.

* the recurrence predictor (acceleration_predictor's learn_modes): the ring of differences
  keeps the dot products of each new difference with lags 0 .. 6 only and the fit reads them
  in place; after the ring has wrapped several times its coefficients and predicted
  difference are those of the least-squares fit from scratch over the last three
  differences (numpy), and on a signal of three damped modes (which an order-6 recurrence
  continues exactly) it predicts the next difference and wins the choice of kind.
* the output row's loads potential from the constant loads directly (probe_output): a
  tilted cable under gravity, rho A g times the integral of its height.
* the kinetic energy in one pass over the plane's mass pairs: test_planar_step_kernels'
  test_mass_product_by_pairs_is_the_csr_product (the same bits as the CSR product and
  dot_product, and 1/2 v.M v of the assembled mass).
"""
from __future__ import annotations

import numpy as np

from ancfdrv import Circle, System, _kernel
from ancfdrv.codes import ENERGY_NAMES

ORDER, WINDOW = 6, 3          # stepper.f90's recurrence_order, recurrence_window
RECURRENCE_KIND = 6           # acceleration_predictor's predict_recurrence


def _fit_from_scratch(accels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The recurrence d_m = sum_j c_j d_{m-j} (j = 1 .. 6) fitted by least squares over
    all coordinates of the WINDOW newest differences of accels (columns e''_0 ..), and the
    next difference it predicts."""
    d = np.diff(accels, axis=1)                 # d[:, k] = e''_{k+1} - e''_k
    newest = d.shape[1] - 1
    rows, rhs = [], []
    for m in range(newest - WINDOW + 1, newest + 1):
        rows.append(np.stack([d[:, m - j] for j in range(1, ORDER + 1)], axis=1))
        rhs.append(d[:, m])
    c = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]
    guess = sum(c[j - 1] * d[:, newest + 1 - j] for j in range(1, ORDER + 1))
    return c, guess


def test_recurrence_ring_is_the_fit_from_scratch():
    """Random accelerations (20 coordinates, 31 steps: the ring of 9 differences wrapped
    three times): the kernel's coefficients and predicted difference are those of the
    least-squares fit from scratch over the last three differences (the normal equations'
    ridge, 1e-12 of a unit diagonal, moves them by far less than 1e-9)."""
    rng = np.random.default_rng(26)
    accels = rng.standard_normal((20, 32))
    kind, ready, coefficients, guess = _kernel.predictor_learn_sequence(1e-3, accels)
    assert ready == 1
    c, expected = _fit_from_scratch(accels)
    np.testing.assert_allclose(coefficients, c, rtol=0, atol=1e-9 * np.abs(c).max())
    np.testing.assert_allclose(guess, expected, rtol=0, atol=1e-9 * np.abs(expected).max())
    # a history one step shorter (another place in the ring) gives another fit
    _, _, shorter, _ = _kernel.predictor_learn_sequence(1e-3, accels[:, :-1])
    assert np.abs(shorter - coefficients).max() > 1e-3


def test_recurrence_continues_three_damped_modes():
    """e'' of three lightly damped modes (each coordinate its own amplitudes and phases):
    the order-6 recurrence fitted in the ring predicts the next difference to 1e-8 of its
    size, and the predictor chooses it over the six simpler extrapolations."""
    rng = np.random.default_rng(3)
    n, m = 20, 24
    k = np.arange(m + 1)
    accels = np.zeros((n, m + 1))
    for rate, damping in ((0.31, 0.002), (0.77, 0.004), (1.63, 0.001)):
        amplitude, phase = rng.uniform(0.5, 2.0, n), rng.uniform(0, 2 * np.pi, n)
        accels += amplitude[:, None] * np.exp(-damping * k) * np.cos(rate * k + phase[:, None])
    kind, ready, _, guess = _kernel.predictor_learn_sequence(1e-3, accels[:, :m])
    assert ready == 1 and kind == RECURRENCE_KIND
    truth = accels[:, m] - accels[:, m - 1]
    assert np.abs(guess - truth).max() <= 1e-8 * np.abs(truth).max()


def test_gravity_potential_of_a_tilted_cable():
    """A cable of length L tilted by 30 degrees in the x-y plane, pinned at its lower end,
    gravity g along -y: the output row's gravity potential is rho A g times the integral
    of its height, rho A g L (L sin 30 / 2) (exact for the cubic cable: its height is
    linear along it), to 1e-13."""
    length, density, diameter, g = 1.2, 7850.0, 0.02, 9.81
    angle = np.radians(30.0)
    s = System("tilted", planar="xy")
    steel = s.material("steel", youngs_modulus=2.1e11, density=density)
    s.cable("c", material=steel, start=(0, 0, 0),
            end=(length * np.cos(angle), length * np.sin(angle), 0), nodes=5,
            section=Circle(diameter))
    s.joint("pin", "spherical", "ground", "c", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -g, 0))
    model = s.assemble()
    try:
        ks = model.kernel
        row = ks.output_row(0.0, model.e0, np.zeros(model.ndof), np.zeros(ks.ncon),
                            np.zeros(5), np.zeros((2, 1)), np.zeros(6, np.int32))
        potential = row["energy"][ENERGY_NAMES.index("gravity")]
        area = np.pi * diameter**2 / 4.0
        expected = density * area * g * length * (0.5 * length * np.sin(angle))
        assert abs(potential - expected) <= 1e-13 * expected
    finally:
        model.close()
