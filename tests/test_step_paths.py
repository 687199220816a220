"""The stepper's leaner carried Schur complement (issue 26, w6-step2) against the routines
it replaced, bit for bit, on real runs: while system_api's stepper_path_checks is on for a
run's handle (turned on right after the run's stepper set-up), every use of the fast paths in time_integrator's carry_schur is compared with the old routine run
alongside (check_carry_gather, check_plane_correction):

* T^T Phi_e^T made only at the gathered pairs of a planar reduction (carry_plane_gradients)
  against carry_gradients' whole columns at those rows;
* gather_blocks' test of the scan lists only (carry_scan_setup: a finite turn maps a carried
  vector without a constraint term to +-0) against the test of every coordinate with the
  row map made anew (its answer, and w where inside);
* plane_carried_correction's sums written out for one or two nonzero multiplier corrections
  against its loop over the multipliers.

A planar cable pendulum (a pin: two multipliers), the planar cable spin-up (a driven hub)
and the spatial beam spin-up (carry_map's general path, no pairs)."""
from __future__ import annotations

from pathlib import Path

import pytest

import ancfdrv
from ancfdrv import _kernel
from ancfdrv.kernel import KernelSystem

INPUTS = Path(__file__).resolve().parents[1] / "inputs"


@pytest.mark.parametrize("scene, overrides, plane", [
    ("hard/pendulum.nml", ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy",
                           "solver.dt=1e-3", "solver.t_end=0.3"], True),
    ("hard/spinup.nml", ["spinup.omega=4", "beam.bending=cable", "scene.planar=xy",
                         "beam.nodes=11", "solver.dt=5e-3", "solver.t_end=2"], True),
    ("hard/spinup.nml", ["spinup.omega=6", "beam.nodes=6", "solver.dt=1e-2",
                         "solver.t_end=2"], False),
])
def test_carried_fast_paths_are_the_replaced_routines(scene, overrides, plane, monkeypatch):
    counted: list[tuple[int, int]] = []
    setup, close = KernelSystem.stepper_setup, KernelSystem.close

    def setup_checked(self, settings) -> None:
        setup(self, settings)
        assert _kernel.stepper_path_checks(self.handle, 1)[2] == 0

    def close_counted(self) -> None:
        if getattr(self, "handle", 0):
            checks, mismatches, info = _kernel.stepper_path_checks(self.handle, 0)
            if info == 0:
                counted.append((checks, mismatches))
        close(self)

    monkeypatch.setattr(KernelSystem, "stepper_setup", setup_checked)
    monkeypatch.setattr(KernelSystem, "close", close_counted)
    sim = ancfdrv.simulate(INPUTS / scene, [*overrides, "output.xdmf=.false."],
                           progress=False)
    checks = sum(c for c, _ in counted)
    mismatches = sum(m for _, m in counted)
    steps = len(sim.time) - 1
    print(f"\n{scene}: {checks} comparisons in {steps} steps, {mismatches} differed")
    assert sim.status == "ok"
    assert mismatches == 0
    # a carried step compares its gather once and (planar) its correction at each
    # correction: most steps of these runs carry their matrix
    assert checks >= (steps // 2 if plane else steps // 4)
