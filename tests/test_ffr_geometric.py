"""The FFR geometric stiffness (P-delta), `beam.geometric_stiffness` (issue 23, item 2;
docs/theory.md, 'FFR geometric stiffness').

References: the Euler-Bernoulli beam-column in closed form (a cantilever under an axial end
force P and a transverse end force Q: tip deflection Q (tan u - u) / (P k) in compression,
Q (u - tanh u) / (P k) in tension, u = k L, k = sqrt(|P| / EI)), and this code's converged
large-deformation model of the luffing boom (28 'cubic' nodes, which differs from 40 nodes by
2e-4 of the sag range, benchmarks/ffr_pdelta.py)."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from ancfdrv.errors import InputError
from ancfdrv.runner import run_scene

from conftest import INPUTS

E, SIDE, LENGTH = 2.1e11, 0.05, 2.0
EI = E * SIDE**4 / 12.0


def cantilever_tip(tmp_path, axial: float, transverse: float, *extra: str) -> np.ndarray:
    """Static tip deflection of inputs/cantilever.nml (FFR, 9 nodes, 'cubic' bending)
    under the end force (axial, -transverse, 0)."""
    out = tmp_path / "c.h5"
    run_scene(INPUTS / "cantilever.nml", [
        f"loads.tip_force={axial},{-transverse},0.0", "beam.bending=cubic", "beam.nodes=9",
        *extra], out, progress=False)
    with h5py.File(out) as h5:
        return h5["static/deflection/tip"][()].ravel()


@pytest.mark.parametrize("load_ratio", [0.5, -1.0])   # P / P_cr: compression 0.5, tension 1
def test_beam_column_amplification(tmp_path, load_ratio):
    # P_cr = pi^2 EI / (4 L^2) for the cantilever; the amplification of the lateral deflection
    # (closed form) is about 1/(1 - P/P_cr): 2 at P = P_cr / 2 (exactly 1.98629), 0.5 in
    # tension P_cr (exactly 0.50594); measured 1.98687 and 0.50593. Ratios of the same mesh,
    # so the element's shear flexibility (5e-4 of the deflection) and mesh error cancel to
    # second order.
    p_cr = np.pi**2 * EI / (4.0 * LENGTH**2)
    p = load_ratio * p_cr          # > 0: compression
    q = 1e-3 * 3.0 * EI / LENGTH**3  # linear tip deflection 1e-3 m
    u = np.sqrt(abs(p) / EI) * LENGTH
    factor = 3.0 * ((np.tan(u) - u) if p > 0 else (u - np.tanh(u))) / u**3
    linear = cantilever_tip(tmp_path, 0.0, q)[1]
    plain = cantilever_tip(tmp_path, -p, q)[1]
    second = cantilever_tip(tmp_path, -p, q, "beam.geometric_stiffness=true")[1]
    assert plain == pytest.approx(linear, rel=1e-6)   # the paper's FFR: no amplification
    assert second / linear == pytest.approx(factor, rel=1e-3)
    assert abs(second / linear - 1.0 / (1.0 - load_ratio)) < 0.05  # the P-delta rule


def test_transverse_load_alone_is_unchanged(tmp_path):
    # no axial force, no geometric stiffness: the linear FFR answer to round-off
    q = 1e-3 * 3.0 * EI / LENGTH**3
    assert cantilever_tip(tmp_path, 0.0, q, "beam.geometric_stiffness=true") == \
        pytest.approx(cantilever_tip(tmp_path, 0.0, q), rel=1e-9, abs=1e-15)


def test_split_iteration_refuses_it(tmp_path):
    """An explicit 'split' (boom_luffing.nml asks for it) is bad input here (issue 35):
    refused before the run, naming the key and why."""
    with pytest.raises(InputError, match="static_method: 'split' cannot solve this scene: "
                       ".*geometric_stiffness"):
        run_scene(INPUTS / "boom_luffing.nml", ["scene.analysis=static",
                  "beam.geometric_stiffness=true"], tmp_path / "b.h5", progress=False)
    assert not (tmp_path / "b.h5").exists()


def boom_sag(tmp_path, name: str, *extra: str) -> tuple[np.ndarray, np.ndarray]:
    out = tmp_path / f"{name}.h5"
    run_scene(INPUTS / "boom_luffing.nml", ["loads.tip_mass=0", "solver.t_end=4.0",
              "solver.static_method=newton", "beam.bending=cubic", "output.xdmf=false",
              *extra], out, progress=False)
    with h5py.File(out) as h5:
        return h5["dynamic/time"][()], h5["dynamic/deflection/tip"][()][:, 1]


def test_luffing_boom_against_the_nonlinear_model(tmp_path):
    # the shipped boom, 28 nodes, m = 0 (the larger FFR error), luffing to t = 4 s: plain FFR
    # is 2.8% of this history's sag range (0.049 m) off the converged large-deformation model
    # (its overhang's compression at up to 60 deg softens it), FFR with P-delta 0.30%
    # (measured; over the full 10 s, 8.6% -> 0.24%)
    t_ref, reference = boom_sag(tmp_path, "ref", "scene.formulation=nonlinear")
    t, plain = boom_sag(tmp_path, "ffr")
    _, second = boom_sag(tmp_path, "pdelta", "beam.geometric_stiffness=true")
    assert np.array_equal(t, t_ref)
    sag_range = np.ptp(reference)
    assert np.max(np.abs(plain - reference)) > 0.02 * sag_range
    assert np.max(np.abs(second - reference)) < 0.005 * sag_range


def boom_modes(tmp_path, *extra: str) -> np.ndarray:
    out = tmp_path / "modes.h5"
    run_scene(INPUTS / "boom_luffing.nml", [
        "scene.analysis=modal", "boom.angle_deg=60", "loads.tip_mass=0", "beam.bending=cubic",
        "solver.static_method=newton", *extra], out, progress=False)
    with h5py.File(out) as h5:
        return h5["modal/frequency"][()]


def test_boom_modes_feel_the_axial_force(tmp_path):
    # the boom at 60 deg (m = 0, 28 'cubic' nodes): the compressed overhang lowers the first
    # bending frequencies. Reference: the large-deformation model's modes about its own
    # static state (its tangent holds the initial-stress stiffness): 1.94643 / 2.01880 Hz;
    # plain FFR 1.95967 / 2.03155 (0.7% high), FFR with P-delta 1.94640 / 2.01846 (measured)
    reference = boom_modes(tmp_path, "scene.formulation=nonlinear")[:2]
    plain = boom_modes(tmp_path)[:2]
    second = boom_modes(tmp_path, "beam.geometric_stiffness=true")[:2]
    assert np.all(plain / reference - 1.0 > 5e-3)
    assert np.all(np.abs(second / reference - 1.0) < 5e-4)


def test_spinup_above_the_first_frequency_stays_bounded(tmp_path):
    # the spin-up beam at W = 6 rad/s, above its first clamped bending frequency: the paper's
    # FFR diverges (test_hard_cases), with P-delta the centrifugal tension, read from the
    # elastic coordinates as the hub turns, stiffens it as in the large-deformation model
    # (max |tip deflection| 0.5747 m against the nonlinear model's 0.5701 m; the largest
    # difference of the histories 9.1e-3 m, 1.6% of the range; measured)
    spin = INPUTS / "hard" / "spinup.nml"
    histories, warnings = {}, {}
    for name, extra in (("ffr", ["scene.formulation=ffr", "beam.geometric_stiffness=true"]),
                        ("nonlinear", [])):
        out = tmp_path / f"{name}.h5"
        run_scene(spin, ["spinup.omega=6", "output.xdmf=false", *extra], out, progress=False)
        with h5py.File(out) as h5:
            histories[name] = h5["dynamic/deflection/tip"][()][:, 1]
            warnings[name] = str(h5.attrs.get("warnings", ""))
    assert "from the P-delta option" in warnings["ffr"]
    assert "no geometric (centrifugal) stiffening" not in warnings["ffr"]
    ffr, reference = histories["ffr"], histories["nonlinear"]
    assert len(ffr) == len(reference)
    assert np.abs(ffr).max() == pytest.approx(np.abs(reference).max(), rel=0.02)
    assert np.max(np.abs(ffr - reference)) < 0.03 * np.ptp(reference)
