"""The 'integrator created energy' warning (solvers/dynamic.py EnergyWatch): measured against
an energy scale that means something (the largest kinetic, kinetic plus strain energy,
potential-energy change or work), it stays silent for a run at rest and still fires for the
rho_inf = 1 instability of the flexible pendulum at a coarse step."""
from __future__ import annotations

import re

import h5py
import numpy as np

from ancfdrv.runner import run_scene

from conftest import INPUTS


def _created(warnings) -> float | None:
    for text in warnings:
        found = re.search(r"integrator created energy.*?rose to ([0-9.]+)%", text)
        if found:
            return float(found.group(1)) / 100
    return None


def test_a_run_at_rest_does_not_warn(tmp_path):
    """inputs/general/boom_mounts.nml held for 0.5 s (its drive starts at 0.5 s): the boom
    rests in its static state (kinetic energy below 1e-15 J, the balance 7e-12 J of round-off
    against 1621 J of strain energy). Measured against the kinetic energy and potential
    change alone (both round-off) the balance read 100 % and warned."""
    out = tmp_path / "rest.h5"
    outcome = run_scene(INPUTS / "general" / "boom_mounts.nml", ["solver.t_end=0.5"], out,
                        progress=False)
    with h5py.File(out) as h5:
        kinetic = h5["dynamic/energy/kinetic"][()]
        balance = h5["dynamic/energy/balance"][()]
        strain = h5["dynamic/energy/strain"][()]
    assert kinetic.max() < 1e-15 and np.abs(balance).max() < 1e-9 < 1e3 < strain.min()
    assert _created(outcome.warnings) is None


def test_the_flexible_pendulum_instability_still_warns(tmp_path):
    """inputs/hard/pendulum.nml (9 nodes) at rho_inf = 1 and dt = 2e-3: the method's
    instability on this nonlinear model sets in around t = 3 s and within a few tenths of a
    second the integrator has created some 1000-2000 J, over ten times the 82 J of kinetic
    plus strain energy the pendulum held before (the run to 10 s: +128 % on the old scale).
    Its onset moves with the path of the Newton iterates (before 3.0 s at main 7cd1edb,
    3.15 s earlier; with issue 23's extrapolated predictor between 3.3 and 3.5 s, the
    balance -1 J at 3.3 s and +947 J at 3.5 s), hence the run to 3.6 s. Measured: 97.6 % of
    the new scale (the energy created is pumped into kinetic and strain energy, which caps
    the figure near 100 %); the warning fires above 5 %."""
    out = tmp_path / "pendulum.h5"
    outcome = run_scene(INPUTS / "hard" / "pendulum.nml",
                        ["solver.dt=2e-3", "solver.t_end=3.6"], out, progress=False)
    created = _created(outcome.warnings)
    assert created is not None and created > 0.5
