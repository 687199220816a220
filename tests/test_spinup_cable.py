"""The spin-up beam as an ANCF cable (``beam.bending = 'cable'``, issue 23): the hub holds the
root's r and r_x on the turning hub, the planar cable has 4 unknowns per node, and its
transverse tip deflection in the hub frame agrees with the independent cubic beam element."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv.errors import InputError
from ancfdrv.runner import run_scene

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "inputs/hard/spinup.nml"
# W = 4 rad/s up to 16 s (past the end of the spin-up at T = 15 s), dt = 10 ms
BASE = ["spinup.omega=4", "solver.t_end=16", "solver.dt=1e-2", "scene.planar=xy"]


def _deflection(tmp_path: Path, bending: str, nodes: int) -> tuple[np.ndarray, int]:
    out = tmp_path / f"{bending}{nodes}.h5"
    run_scene(SCENE, BASE + [f"beam.bending={bending}", f"beam.nodes={nodes}"], out,
              progress=False)
    with h5py.File(out, "r") as h5:
        return h5["dynamic/deflection/tip"][:, 1], int(h5["model/e0"].shape[0])


def test_spinup_cable_matches_the_cubic_beam(tmp_path):
    """Cable (11 nodes) against the cubic beam (11 nodes, 7 unknowns per node): measured
    2.6e-5 m apart against the cubic's 21-node run, the cubic 11 and 21 nodes 1.1e-5 m
    apart; the peak deflection is 0.40 m."""
    cable, ncable = _deflection(tmp_path, "cable", 11)
    cubic, ncubic = _deflection(tmp_path, "cubic", 11)
    assert ncable == 4 * 11 and ncubic == 7 * 11
    peak = float(np.max(np.abs(cubic)))
    assert 0.39 < peak < 0.41
    assert float(np.max(np.abs(cable - cubic))) < 1e-4


def test_spinup_cable_needs_the_nonlinear_formulation(tmp_path):
    with pytest.raises(InputError, match="formulation = 'nonlinear'"):
        run_scene(SCENE, BASE + ["beam.bending=cable", "scene.formulation=ffr"],
                  tmp_path / "never.h5", progress=False)
    assert not (tmp_path / "never.h5").exists()
