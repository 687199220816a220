"""The 'cubic' bending option (fortran/src/beam_cubic.f90, docs/theory.md section 12)
for both formulations.

References: the kernel's own central differences, rigid motions (zero strain), the
Timoshenko cantilever in closed form (analytic.py; the element reproduces it with one
element), the boom's closed form (docs/boom_closed_form.md), the elastica (scipy BVP) and
energy conservation of the flexible pendulum.
"""
from __future__ import annotations

import h5py
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ancfdrv import kernel
from ancfdrv.reference import analytic
from ancfdrv.reference.analytic import boom_static_tip_deflection
from ancfdrv.builders import build_model
from ancfdrv.runner import run_scene
from ancfdrv.io.scene import load_scene
from ancfdrv.solvers.static import solve_newton

from conftest import INPUTS
from helpers import beam_model, rect

RNG = np.random.default_rng(11)
CANTILEVER = INPUTS / "cantilever.nml"
E, L, B = 2.1e11, 2.0, 0.05
A, I, G = B * B, B**4 / 12, 2.1e11 / 2


def beam(formulation: str, nodes: int = 4, poisson: float = 0.0):
    return beam_model(nodes, 1.5, width=0.06, height=0.1, poisson=poisson,
                      offset=(0.2, 0.1, -0.3), formulation=formulation, bending="cubic")


def test_stiffness_has_exactly_the_six_rigid_modes_and_matches_the_tangent():
    ffr = beam("ffr", nodes=2)
    k0 = ffr.sets[0].stiffness0[:, :, 0]
    assert np.abs(k0 - k0.T).max() < 1e-12 * np.abs(k0).max()
    eigenvalues = np.linalg.eigvalsh(k0)
    assert np.sum(np.abs(eigenvalues) < 1e-9 * eigenvalues.max()) == 6
    assert eigenvalues.min() > -1e-9 * eigenvalues.max()
    # the large-deformation tangent at the reference is the FFR K0 (frame = identity)
    nonlinear = beam("nonlinear", nodes=4, poisson=0.3)
    _, energy, tangent = nonlinear.internal_force(nonlinear.e0, want_tangent=True)
    assert abs(energy) < 1e-12
    np.testing.assert_allclose(tangent, beam("ffr", poisson=0.3).stiffness_values(),
                               atol=1e-12 * np.abs(tangent).max())


def test_mass_is_the_continuum_elements():
    cubic, continuum = beam("ffr"), beam_model(4, 1.5, width=0.06, height=0.1)
    m = cubic.mass_matrix().toarray()
    np.testing.assert_array_equal(m, continuum.mass_matrix().toarray())
    assert np.abs(m - m.T).max() < 1e-14 * np.abs(m).max()


@pytest.mark.parametrize("angle_deg", [0.0, 37.0, 179.0, 540.0])
def test_rigid_motions_carry_no_strain(angle_deg):
    model = beam("nonlinear", nodes=5, poisson=0.3)
    rot = Rotation.from_rotvec(np.radians(angle_deg) * np.array([0.6, 0.0, 0.8])).as_matrix()
    e = np.einsum("ij,nkj->nki", rot, model.e0.reshape(-1, 4, 3))
    e[:, 0, :] += [3.0, -1.0, 2.0]
    force, energy, _ = model.internal_force(e.ravel())
    assert abs(energy) < 1e-9
    assert np.abs(force).max() < 1e-3  # N, against ~1e9 N per unit strain


def test_system_force_over_the_nonzero_entries_is_the_dense_elements():
    """The system sums each strain form over its nonzero entries only (cubic_pattern);
    the element entry point multiplies the dense 8 x 8 forms. At a rotated, perturbed state
    of a straight beam both give the same force and energy to round-off."""
    model = beam("nonlinear", nodes=5, poisson=0.3)
    try:
        beam_set = model.sets[0]
        assert beam_set.kind == "cubic"
        rot = Rotation.from_euler("xyz", [2.1, -0.7, 0.4]).as_matrix()
        e = (model.e0.reshape(-1, 3) @ rot.T).ravel() + 1e-2 * RNG.standard_normal(model.ndof)
        system_force, system_energy = model.internal_force(e)[:2]
        dense_force, dense_energy, _ = beam_set.cubic.forces(beam_set.dofs, e, False)
        assert np.abs(system_force).max() > 0
        np.testing.assert_allclose(system_force, dense_force,
                                   atol=1e-13 * np.abs(dense_force).max())
        assert system_energy == pytest.approx(dense_energy, rel=1e-13)
    finally:
        model.close()


def test_the_built_model_keeps_the_strain_forms_in_its_kernel_only():
    """After the build the kernel's set holds the forms (10.8 kB an element) and the Python
    set none: each ask remakes them (new arrays), the same as the kernel's copy (the
    system's force above, through the remade ones, is the kernel's to round-off)."""
    model = beam("nonlinear", nodes=5, poisson=0.3)
    try:
        cubic = model.sets[0].cubic
        first, again = cubic.tables(), cubic.tables()
        assert first[0].shape == (8, 8, kernel._kernel.beam_cubic_size(), 4)
        for made, remade in zip(first, again):
            assert made is not remade
            np.testing.assert_array_equal(made, remade)
    finally:
        model.close()


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
        plus, minus = model.internal_force(e + step), model.internal_force(e - step)
        np.testing.assert_allclose((plus[0] - minus[0]) / (2 * h), tangent[:, j],
                                   atol=1e-6 * np.abs(tangent).max())
        assert (plus[1] - minus[1]) / (2 * h) == pytest.approx(
            force[j], rel=1e-6, abs=1e-6 * np.abs(force).max())
    np.testing.assert_allclose(tangent, tangent.T, atol=1e-12 * np.abs(tangent).max())


def test_curved_reference_is_strain_free():
    radius, length = 0.8, 0.5

    def arc(s):
        angle = s / radius
        return np.stack([radius * np.array([np.sin(angle), 1.0 - np.cos(angle), 0.0]),
                         [np.cos(angle), np.sin(angle), 0.0],
                         [-np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    reference = np.concatenate([arc(0.0), arc(length)]).T.reshape(3, 8, 1)
    element = kernel.CubicBeam(reference, [length], rect(0.02, 0.03), 2e11, 0.3)
    dofs = np.arange(24)[:, None]
    e0 = reference[:, :, 0].T.ravel()
    force, energy, _ = element.forces(dofs, e0, False)
    assert abs(energy) < 1e-12 and np.abs(force).max() < 1e-3
    moved = e0.reshape(8, 3) @ Rotation.from_euler("zyx", [2.5, -0.7, 1.9]).as_matrix().T
    moved[[0, 4]] += [1.0, 2.0, 3.0]
    force, energy, _ = element.forces(dofs, moved.ravel(), False)
    assert abs(energy) < 1e-9 and np.abs(force).max() < 1e-3
    bent = e0.copy()
    bent[12:15] += [0.0, 1e-3, 0.0]
    assert element.forces(dofs, bent, False)[1] > 0


CASES = {
    "tip force": ("tip_force", ["loads.tip_force=0,-100,0"],
                  analytic.cantilever_tip_load(100.0, L, E, I, A=A, G=G)),
    "uniform load": ("gravity", [], analytic.cantilever_uniform_load(7850 * A * 9.81, L, E, I,
                                                                      A=A, G=G)),
}


@pytest.mark.parametrize("name", CASES)
def test_one_element_reproduces_the_timoshenko_cantilever(name):
    """Linear statics (FFR): the curvature theta' + v'' - mean(v'') and the nodal shear
    hold the exact Timoshenko solution (k = 1) of end and uniform loads on any mesh; the
    continuum element needs 17 nodes for 0.1% (test_cantilever.py)."""
    effects, extra, reference = CASES[name]
    for nodes in (2, 3, 6):
        scene = load_scene(CANTILEVER, [f"beam.nodes={nodes}", f"scene.effects={effects}",
                                        "beam.bending=cubic", *extra])
        model = build_model(scene)
        tip = model.deflections(solve_newton(model, tol=1e-12, max_iter=20).e)["tip"]
        assert -tip[1] == pytest.approx(reference, rel=1e-9)


def test_boom_is_accurate_on_the_coarsest_mesh(boom_scene):
    """The boom against its closed form (Timoshenko k = 1): 4 nodes within 0.07% where
    the continuum element is 25-27% off. What remains converges at first order: the shear
    force jumps at the pin A2, which nodal shear (continuous r_x) cannot follow; it is
    bounded by the shear part of the sag (0.11% here)."""
    _, reference = boom_static_tip_deflection(60, 50, shear=True)
    _, bernoulli = boom_static_tip_deflection(60, 50, shear=False)
    errors = []
    for nodes in (4, 7, 16, 28):
        scene = load_scene(boom_scene, [f"beam.nodes={nodes}", "boom.angle_deg=60",
                                        "loads.tip_mass=50", "beam.bending=cubic"])
        model = build_model(scene)
        sag = model.deflections(solve_newton(model, tol=1e-12, max_iter=50).e)["tip"][1]
        errors.append(abs(sag - reference) / abs(reference))
    print(f"\nboom, cubic bending: errors {np.array2string(np.array(errors), precision=3)}")
    assert errors[0] < 1e-3 < abs(bernoulli - reference) / abs(reference)
    assert all(a > b for a, b in zip(errors, errors[1:]))
    assert errors[0] / errors[-1] > 28 / 4 * 0.9  # first order in the element size


@pytest.mark.parametrize("k", [1.0, 10.0])
def test_large_deflection_matches_the_elastica(k):
    ei = 2.1e11 * 0.01**4 / 12
    w_ref, u_ref = analytic.elastica_tip_load(k)
    errors = []
    for nodes in (9, 33, 65):
        scene = load_scene(CANTILEVER, [f"beam.nodes={nodes}", "beam.length=1",
                                        "beam.width=0.01", "beam.height=0.01",
                                        "scene.formulation=nonlinear", "beam.bending=cubic",
                                        f"loads.tip_force=0,{-k * ei},0"])
        model = build_model(scene)
        result = solve_newton(model, tol=1e-10, max_iter=40, load_steps=max(1, int(k)))
        axial, transverse, _ = model.deflections(result.e)["tip"]
        errors.append(max(abs(-transverse - w_ref) / w_ref, abs(-axial - u_ref) / u_ref))
    print(f"\nk = {k}: cubic bending, errors with 9, 33, 65 nodes "
          f"{np.array2string(np.array(errors), formatter={'float_kind': '{:.2e}'.format})}")
    assert errors[-1] < 1e-3
    assert errors[0] > errors[1] > errors[2]


def test_pendulum_conserves_energy(tmp_path):
    """The flexible pendulum (rho_inf = 1) with cubic bending: energy within 0.1% of the
    potential energy exchanged over 1 s; the early motion is a free fall."""
    out = tmp_path / "p.h5"
    run_scene(INPUTS / "hard" / "pendulum.nml", ["beam.nodes=9", "beam.bending=cubic"], out,
              progress=False)
    with h5py.File(out) as h5:
        t, total = h5["dynamic/time"][()], h5["dynamic/energy/total"][()]
        gravity, probe = h5["dynamic/energy/gravity"][()], h5["dynamic/probes/tip"][()]
        assert h5.attrs["status"] == "ok" and h5.attrs["bending"] == "cubic"
    drift = np.abs(total - total[0]).max() / np.abs(gravity - gravity[0]).max()
    print(f"\npendulum, cubic bending: energy drift {drift:.2e}")
    assert t[-1] == pytest.approx(1.0) and drift < 1e-3
    i = np.argmin(np.abs(t - 0.1))
    assert probe[i, 1] == pytest.approx(-9.81 * t[i] ** 2 / 2, abs=1e-3)


def test_spinup_with_cubic_bending_stays_bounded(tmp_path):
    out = tmp_path / "spin.h5"
    run_scene(INPUTS / "hard" / "spinup.nml", ["spinup.omega=6", "beam.bending=cubic",
                                               "beam.nodes=6"], out, progress=False)
    with h5py.File(out) as h5:
        t, tip = h5["dynamic/time"][()], h5["dynamic/deflection/tip"][:, 1]
    assert 0.2 < np.abs(tip).max() < 0.7
    assert np.abs(tip[t > 16.0]).max() < 0.01
