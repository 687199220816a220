"""The large-deformation beam (continuum mechanics, Green-Lagrange, St. Venant-Kirchhoff)
against invariants, finite differences, the small-strain element and the elastica.

References: K0 of the FFR model (the tangent at the reference must equal it); rigid
motions (zero strain at any rotation); central differences of force and energy; the
elastica under a dead tip load solved independently with scipy's BVP solver
(analytic.elastica_tip_load, itself checked against Mattiasson 1981); the end moment
2 pi EI / L that rolls a cantilever into a full circle.
"""
from __future__ import annotations

import os
import subprocess
import sys

import h5py
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ancfdrv import kernel
from ancfdrv.reference import analytic
from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.solvers.static import solve_newton

from conftest import INPUTS
from helpers import beam_model, rect

RNG = np.random.default_rng(5)
CANTILEVER = INPUTS / "cantilever.nml"
SLENDER = ["beam.length=1", "beam.width=0.01", "beam.height=0.01",
           "scene.formulation=nonlinear"]
EI_SLENDER = 2.1e11 * 0.01**4 / 12


def beam(formulation: str, nodes: int = 4, poisson: float = 0.0):
    return beam_model(nodes, 1.5, width=0.06, height=0.1, poisson=poisson,
                      offset=(0.2, 0.1, -0.3), formulation=formulation, bending="continuum")


@pytest.mark.parametrize("poisson", [0.0, 0.3])
def test_tangent_at_reference_is_the_small_strain_stiffness(poisson):
    nonlinear = beam("nonlinear", poisson=poisson)
    _, energy, tangent = nonlinear.internal_force(nonlinear.e0, want_tangent=True)
    k0 = beam("ffr", poisson=0.0).stiffness_values()
    assert abs(energy) < 1e-15  # J0 J0^{-1} = I to round-off
    if poisson == 0.0:
        np.testing.assert_allclose(tangent, k0, atol=1e-12 * np.abs(k0).max())
    else:  # the Poisson part only adds (on the axis) what nu couples
        assert np.abs(tangent - k0).max() > 1e-3 * np.abs(k0).max()


@pytest.mark.parametrize("angle_deg", [0.0, 37.0, 179.0, 540.0])
def test_rigid_motions_carry_no_strain(angle_deg):
    model = beam("nonlinear", nodes=5, poisson=0.3)
    rot = Rotation.from_rotvec(np.radians(angle_deg) * np.array([0.6, 0.0, 0.8])).as_matrix()
    e = np.einsum("ij,nkj->nki", rot, model.e0.reshape(-1, 4, 3))
    e[:, 0, :] += [3.0, -1.0, 2.0]
    force, energy, _ = model.internal_force(e.ravel())
    assert abs(energy) < 1e-9  # J; the strain energy scale of this test is ~1e5 J
    assert np.abs(force).max() < 1e-3  # N, against element forces of ~1e9 N per unit strain


def test_tangent_and_energy_match_central_differences():
    model = beam("nonlinear", nodes=3, poisson=0.3)
    rot = Rotation.from_euler("xyz", [0.3, 1.2, -2.0]).as_matrix()
    e = (model.e0.reshape(-1, 3) @ rot.T).ravel() + 2e-3 * RNG.standard_normal(model.ndof)
    force, _, values = model.internal_force(e, want_tangent=True)
    tangent = model.pattern.to_scipy(values).toarray()
    h = 1e-7
    for j in range(model.ndof):
        step = np.zeros(model.ndof)
        step[j] = h
        fd = (model.internal_force(e + step)[0] - model.internal_force(e - step)[0]) / (2 * h)
        np.testing.assert_allclose(fd, tangent[:, j], atol=1e-6 * np.abs(tangent).max())
        du = (model.internal_force(e + step)[1] - model.internal_force(e - step)[1]) / (2 * h)
        assert du == pytest.approx(force[j], rel=1e-6, abs=1e-6 * np.abs(force).max())
    np.testing.assert_allclose(tangent, tangent.T, atol=1e-9 * np.abs(tangent).max())


def test_curved_reference_is_strain_free():
    """J = J_e J0^{-1}: an element whose reference is a circular arc carries no strain in
    its reference configuration nor after any rigid motion of it."""
    radius, length = 0.8, 0.5

    def arc(s):
        angle = s / radius
        position = radius * np.array([np.sin(angle), 1.0 - np.cos(angle), 0.0])
        tangent = np.array([np.cos(angle), np.sin(angle), 0.0])
        normal = np.array([-np.sin(angle), np.cos(angle), 0.0])
        return np.stack([position, tangent, normal, [0.0, 0.0, 1.0]])
    reference = np.concatenate([arc(0.0), arc(length)]).T.reshape(3, 8, 1)
    gradients, weights, nvolume = kernel.beam_nonlinear_setup(reference, [length],
                                                                 rect(0.02, 0.03))
    dofs = np.arange(24)[:, None]
    e0 = reference[:, :, 0].T.ravel()
    force, energy, _ = kernel.beam_nonlinear_forces(dofs, e0, gradients, weights, nvolume, 2e11, 0.3,
                                                    False)
    assert abs(energy) < 1e-12 and np.abs(force).max() < 1e-3
    rot = Rotation.from_euler("zyx", [2.5, -0.7, 1.9]).as_matrix()
    moved = (e0.reshape(8, 3) @ rot.T)
    moved[[0, 4]] += [1.0, 2.0, 3.0]
    force, energy, _ = kernel.beam_nonlinear_forces(dofs, moved.ravel(), gradients, weights,
                                                    nvolume, 2e11, 0.3, False)
    assert abs(energy) < 1e-9 and np.abs(force).max() < 1e-3
    # bending it further costs energy: the reference curvature is the zero of the strain
    bent = e0.copy()
    bent[12:15] += [0.0, 1e-3, 0.0]
    assert kernel.beam_nonlinear_forces(dofs, bent, gradients, weights, nvolume, 2e11, 0.3,
                                        False)[1] > 0


def elastica(nodes: int, k: float):
    scene = load_scene(CANTILEVER, [f"beam.nodes={nodes}", *SLENDER,
                                    f"loads.tip_force=0,{-k * EI_SLENDER},0"])
    model = build_model(scene)
    result = solve_newton(model, tol=1e-10, max_iter=40, load_steps=max(1, int(k)))
    axial, transverse, _ = model.deflections(result.e)["tip"]
    return -transverse, -axial


@pytest.mark.parametrize("k", [1.0, 3.0, 10.0])
def test_large_deflection_matches_the_elastica(k):
    w_ref, u_ref = analytic.elastica_tip_load(k)
    errors = []
    for nodes in (17, 33, 65):
        w, u = elastica(nodes, k)
        errors.append(max(abs(w - w_ref) / w_ref, abs(u - u_ref) / u_ref))
    print(f"\nk = {k}: w/L = {w:.6f} (elastica {w_ref:.6f}), u/L = {u:.6f} ({u_ref:.6f}); "
          f"errors with 17, 33, 65 nodes {np.array2string(np.array(errors), precision=2)}")
    assert errors[-1] < 1e-3
    assert errors[0] > errors[1] > errors[2]


def test_mattiasson_reference_values():
    w, u = analytic.elastica_tip_load(1.0)
    assert w == pytest.approx(0.30172, abs=5e-6) and u == pytest.approx(0.05643, abs=5e-6)


def test_end_moment_rolls_the_beam_into_a_circle():
    distances, turn_errors = [], []
    for nodes in (17, 33):
        scene = load_scene(CANTILEVER, [f"beam.nodes={nodes}", *SLENDER,
                                        "scene.effects=end_moment",
                                        f"loads.end_moment={2 * np.pi * EI_SLENDER}"])
        model = build_model(scene)
        result = solve_newton(model, tol=1e-10, max_iter=40, load_steps=20)
        distances.append(np.linalg.norm(model.probe_positions(result.e)["tip"]))
        # the tip section has turned by a full revolution: its gradient is back along +x
        r_x = result.e[-9:-6]
        turn_errors.append(abs(np.arctan2(r_x[1], r_x[0])))
    print(f"\nfull circle: tip to root {distances} (beam length 1), tip angle from a full "
          f"turn {turn_errors} rad")
    assert distances[1] < 0.02 and distances[1] < distances[0] / 5
    assert turn_errors[1] < 0.1 and turn_errors[1] < turn_errors[0] / 5


def test_poisson_split_avoids_locking():
    """nu = 0.3: the split law keeps the cantilever's accuracy of nu = 0, the plain law
    (FFR, integrated over the section) locks."""
    def error(formulation: str, nu: float) -> float:
        scene = load_scene(CANTILEVER, ["beam.nodes=17", f"material.poisson_ratio={nu}",
                                        f"scene.formulation={formulation}"])
        model = build_model(scene)
        tip = model.deflections(solve_newton(model).e)["tip"][1]
        reference = analytic.cantilever_tip_load(100.0, 2.0, 2.1e11, 0.05**4 / 12,
                                                 A=0.05**2, G=2.1e11 / (2 * (1 + nu)))
        return -tip / reference - 1.0
    assert abs(error("nonlinear", 0.3)) < 2e-3
    assert error("nonlinear", 0.3) == pytest.approx(error("nonlinear", 0.0), abs=1e-5)
    assert error("ffr", 0.3) < -0.2


@pytest.mark.parametrize("angle,low,high", [(0, -2e-3, 2e-3), (60, 0.012, 0.022)])
def test_boom_nonlinear_against_ffr(angle, low, high):
    """The boom with both formulations (28 nodes, 50 kg): at 0 deg nothing compresses the
    overhang and they agree; at 60 deg the axial weight component compresses it and the
    large-deformation model sags more (P-delta), which FFR neglects. A second-order estimate
    of that amplification (beam under axial load, derived with docs/boom_closed_form.md's
    solution) gave +1.72%; measured +1.67%."""
    from ancfdrv.solvers.static import solve_split
    boom = INPUTS / "boom_static.nml"
    common = ["beam.nodes=28", f"boom.angle_deg={angle}"]
    ffr = build_model(load_scene(boom, common))
    sag_ffr = ffr.deflections(solve_split(ffr).e)["tip"][1]
    nonlinear = build_model(load_scene(boom, common + ["scene.formulation=nonlinear",
                                                      "solver.static_method=newton"]))
    sag_nl = nonlinear.deflections(solve_newton(nonlinear).e)["tip"][1]
    assert low < sag_nl / sag_ffr - 1.0 < high


def test_threads_change_no_number(tmp_path):
    """The element loops run on OMP_NUM_THREADS threads when their estimated work reaches
    200 us (the 28-node beam's tangents) and on one thread below (its forces): each element
    is evaluated alone and assembled in order, so 1 and 2 threads give the same history to
    the last bit."""
    histories = []
    for threads in ("1", "2"):
        out = tmp_path / f"boom_{threads}.h5"
        subprocess.run([sys.executable, "-m", "ancfdrv.cli", "run",
                        str(INPUTS / "boom_luffing.nml"), "-o", str(out),
                        "--set", "scene.formulation=nonlinear", "--set",
                        "solver.static_method=newton", "--set", "solver.t_end=0.2",
                        "--set", "solver.jacobian=step"],
                       check=True, capture_output=True,
                       env={**os.environ, "OMP_NUM_THREADS": threads})
        with h5py.File(out) as h5:
            assert h5.attrs["OMP_NUM_THREADS"] == threads
            histories.append((h5["dynamic/probes/tip"][()], h5["dynamic/q_last"][()],
                              int(h5["dynamic"].attrs["factorizations"])))
    (tip1, q1, f1), (tip2, q2, f2) = histories
    assert f1 == f2 >= 200  # a tangent per step: the threaded loop ran every step
    np.testing.assert_array_equal(tip1, tip2)
    np.testing.assert_array_equal(q1, q2)
