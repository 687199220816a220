"""Deflection relative to the rigid motion of the mechanism (issue 22 item 3): general
scenes write /static and /dynamic deflection_support/<probe>, the probe's displacement
relative to the frame its beam's supports carry (ancfdrv.system.supports), stated in the
attribute 'reference'; sweeps compare it and report the error in mm next to the relative one.

References: the L-frame's girder is a cantilever on the column's top section, so the support
deflection of its free end is the girder's own bending, P a^3 / (3 EI) (Euler-Bernoulli)
across and the bent cantilever's shortening (3/5) d^2 / a along, while its displacement from
t = 0 also carries the column's rotation; the four-bar's coupler
moves by centimetres as a rigid link, its deflection relative to its pins is bounded by its
bending under gravity and inertia (about a micrometre: 5 q L^4 / (384 EI) = 2.5e-6 m for its
weight alone)."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

import ancfdrv
from ancfdrv.cli import main
from ancfdrv.sweep import run_sweep

SCENES = Path(__file__).resolve().parent / "scenes"
E, P, A_GIRDER = 2.1e11, 500.0, 1.5


def _box_inertia(width: float, height: float, wall: float) -> float:
    return (width * height**3 - (width - 2 * wall) * (height - 2 * wall)**3) / 12.0


def test_l_frame_girder_deflects_as_a_cantilever_on_its_support(tmp_path):
    """The girder (slender: shear below 1e-3 of bending) on the column's top section: its
    free end's support deflection is the cantilever's P a^3 / (3 EI) across, and along the
    chord the second-order shortening of the bent cantilever, int w'^2 / 2 = (3/5) d^2 / a."""
    out = tmp_path / "l.h5"
    assert main(["run", str(SCENES / "l_frame.nml"), "-o", str(out), "--set",
                 "scene.effects='point_loads'", "--set", "beam[column].bending='cubic'",
                 "--set", "beam[girder].bending='cubic'", "--set", "beam[girder].width=0.04",
                 "--set", "beam[girder].height=0.04", "--set", "beam[girder].wall=0.004"]) == 0
    res = ancfdrv.open(out)
    sag = P * A_GIRDER**3 / (3 * E * _box_inertia(0.04, 0.04, 0.004))
    support = res.deflection_support["free end"]
    np.testing.assert_allclose(support[1], -sag, rtol=3e-3)
    np.testing.assert_allclose(support[0], -0.6 * sag**2 / A_GIRDER, rtol=2e-2)
    assert abs(support[2]) < 1e-12
    # the plain deflection includes the column's top rotation P a h / EI over a
    assert abs(res.deflection["free end"][1]) > 1.1 * abs(support[1])
    with h5py.File(out) as h5:
        assert "supports" in h5["static/deflection_support"].attrs["reference"]
        assert "rigid motion" in h5["static/deflection"].attrs["reference"]
        assert h5["static/deflection_support/free end"].attrs["frame"] == \
            "girder: section at joints corner"


def test_four_bar_coupler_moves_rigidly_relative_to_its_pins(tmp_path):
    out = tmp_path / "fb.h5"
    assert main(["run", str(SCENES / "four_bar.nml"), "-o", str(out)]) == 0
    res = ancfdrv.open(out)
    moved = np.abs(res.deflection["coupler middle"]).max()
    elastic = np.abs(res.deflection_support["coupler middle"]).max()
    assert moved > 1e-2                                      # centimetres of rigid motion
    assert elastic < 2e-5                                    # micrometres of bending
    assert "rocker top" not in res.deflection_support        # a rigid body: none
    assert res.dynamic.deflection_support["coupler middle"].shape == (101, 3)


def test_sweep_reports_the_support_deflection_error_in_mm(tmp_path):
    rows = run_sweep(str(SCENES / "l_frame.nml"), ["beam[girder].nodes=2,4"], tmp_path,
                     base=["scene.effects='point_loads'", "scene.response='free end'",
                           "scene.response_component=1"], workers=1)
    assert all(r["status"] == "ok" for r in rows)
    coarse, fine = rows
    for row in rows:
        value = ancfdrv.open(row["file"]).deflection_support["free end"][1]
        assert row["response"] == pytest.approx(value, rel=1e-12)
    assert coarse["err_abs_vs_finest"] == pytest.approx(abs(coarse["response"]
                                                            - fine["response"]), rel=1e-12)
    assert coarse["err_vs_finest"] == pytest.approx(
        coarse["err_abs_vs_finest"] / abs(fine["response"]), rel=1e-12)
    assert coarse["err_reference"] == fine["case"]
    summary = (tmp_path / "summary.md").read_text()
    assert "err vs finest (mm)" in summary and f"reference {fine['case']}" in summary
