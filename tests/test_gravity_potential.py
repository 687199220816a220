"""The output row's gravity potential from the constant loads directly (probe_output): a
tilted cable under gravity, rho A g times the integral of its height."""
from __future__ import annotations

import numpy as np

from ancfdrv import Circle, System
from ancfdrv.codes import ENERGY_NAMES


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
