"""The lean step (issue 23 items 3-4): the stepper's output rows take the strain energy
from an energy-only pass over the elements (element_sets' element_energy; the cable's
point energies alone, without forces or assembly) instead of a whole force pass. The
energy of a row must be the force pass's energy at the row's state, to the last bit: the
same point energies summed in the same order (a cable; a rope, whose law - the clipped
axial strain, the polynomial bending - is the other branch of the pass; a Kelvin-Voigt
damped cable, whose dissipation takes the force path)."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import Circle, System
from ancfdrv.codes import ENERGY_NAMES
from ancfdrv.solvers.dynamic import DynamicSettings, integrate

E, RHO, D = 2.1e11, 7850.0, 0.01


@pytest.mark.parametrize("kind", ["cable", "rope", "damped"])
def test_row_strain_energy_is_the_force_pass_energy(kind):
    """A 1 m steel cable (rope: tension only) pinned at one end, released horizontally
    under gravity, 40 steps: at every row the output strain energy equals the strain energy
    of the kernel's force evaluation at the row's coordinates, bitwise (the energy is not
    trivial: a swinging, stretching and bending cable)."""
    s = System(f"lean {kind}")
    steel = s.material("steel", youngs_modulus=E, density=RHO,
                       damping_time=1e-4 if kind == "damped" else 0.0)
    s.cable("c", material=steel, start=(0, 0, 0), end=(1.0, 0, 0), nodes=5,
            section=Circle(D), tension_only=kind == "rope")
    s.joint("pin", "spherical", "ground", "c", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -9.81, 0))
    model = s.assemble()
    rows = []
    try:
        settings = DynamicSettings.generalized_alpha(1e-3, 0.04, 0.9, tol=1e-10, max_newton=20,
                                                     store_q=True)
        integrate(model, settings, model.e0, sink=rows.append, progress=False)
        t = np.concatenate([r.time for r in rows])
        q = np.concatenate([r.q for r in rows])
        strain = np.concatenate([r.energy for r in rows])[:, ENERGY_NAMES.index("strain")]
        assert len(t) == 41 and strain[-1] > 0.0
        guesses, counts = np.zeros((2, 1)), np.zeros(6, np.int32)
        for k in range(1, len(t)):
            out = model.kernel.evaluate(t[k], q[k], np.zeros(model.ndof), guesses, counts)
            assert strain[k] == out["strain"], (k, strain[k], out["strain"])
    finally:
        model.close()
