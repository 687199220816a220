"""Beam element kernel: mass, gravity, stiffness, rigid motions, the T^T M T = M identity.

References: Chrono's unit tests (ChElementBeamANCF_3243 compact mass and gravity for a
1 m, 0.1 x 0.1 m, rho = 7850 element: 13m/35, 11mL/210, 9m/70, -13mL/420; mg/2, mgL/12),
closed-form volume and weight, and invariants (rigid motions carry no strain).
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ancfdrv import kernel
from helpers import beam_model, frame_coordinates, rect

RNG = np.random.default_rng(20261121)


def straight_reference(length: float = 1.0) -> np.ndarray:
    ref = np.zeros((3, 8, 1), order="F")
    ref[:, 1, 0] = ref[:, 4, 0] = ref[:, 5, 0] = [1, 0, 0]
    ref[:, 4, 0] = [length, 0, 0]
    ref[:, 2, 0] = ref[:, 6, 0] = [0, 1, 0]
    ref[:, 3, 0] = ref[:, 7, 0] = [0, 0, 1]
    return ref


def free_beam(nodes: int = 5, length: float = 2.0, rotation=np.eye(3), gravity=None):
    return beam_model(nodes, length, width=0.1, height=0.08, rotation=rotation,
                      offset=(0.3, -0.2, 0.1), gravity=gravity)


def test_compact_mass_matches_chrono_3243_reference():
    mass, _ = kernel.beam_element_arrays([1.0], rect(0.1, 0.1), 7850.0, 2.1e11, 0.0,
                                         straight_reference())
    m = 78.5
    expected = [13 * m / 35, 11 * m / 210, 0, 0, 9 * m / 70, -13 * m / 420, 0, 0]
    np.testing.assert_allclose(mass[0, :, 0], expected, rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(mass[0, :4, 0], [29.1571428571429, 4.11190476190476, 0, 0],
                               rtol=1e-13, atol=1e-12)


def test_gravity_matches_chrono_3243_reference():
    force = kernel.beam_gravity([1.0], rect(0.1, 0.1), 7850.0, [0.0, 0.0, -9.80665])[:, :, 0]
    np.testing.assert_allclose(force[2, 0], -384.9110125, rtol=1e-13)
    np.testing.assert_allclose(force[2, 1], -64.1518354166667, rtol=1e-13)
    np.testing.assert_allclose(force[2, 5], 64.1518354166667, rtol=1e-13)
    np.testing.assert_allclose(force[:2], 0.0, atol=1e-12)


def test_global_mass_symmetric_positive_definite_with_total_mass():
    beam = free_beam()
    mass = beam.mass_matrix().toarray()
    np.testing.assert_allclose(mass, mass.T, rtol=0, atol=1e-12 * np.abs(mass).max())
    assert np.linalg.eigvalsh(mass).min() > 0
    translation = np.zeros(beam.ndof)
    translation[0::12] = 1.0  # unit rigid translation along r1
    total = 7850.0 * 0.1 * 0.08 * 2.0
    assert translation @ mass @ translation == pytest.approx(total, rel=1e-13)


def test_gravity_resultant_equals_weight():
    g = np.array([0.0, -9.81, 0.0])
    beam = free_beam(nodes=7, gravity=g)
    force = beam.constant_force().reshape(-1, 12)
    weight = 7850.0 * 0.1 * 0.08 * 2.0 * g
    np.testing.assert_allclose(force[:, 0:3].sum(axis=0), weight, rtol=1e-13, atol=1e-10)


def test_mass_blocks_are_scalar_so_rotation_leaves_mass_invariant():
    """T^T M T = M for any rotation A: every 3 x 3 block of M is a scalar times I3."""
    beam = free_beam()
    mass = beam.mass_matrix().toarray()
    a = Rotation.random(random_state=3).as_matrix()
    t = np.kron(np.eye(beam.ndof // 3), a)
    np.testing.assert_allclose(t.T @ mass @ t, mass, atol=1e-11 * np.abs(mass).max())


def test_stiffness_symmetric_psd_with_exactly_six_zero_modes():
    beam = free_beam(nodes=6)
    k = beam.stiffness_matrix().toarray()
    np.testing.assert_allclose(k, k.T, atol=1e-9 * np.abs(k).max())
    eig = np.linalg.eigvalsh(k)
    scale = eig.max()
    assert eig.min() > -1e-12 * scale
    assert np.sum(np.abs(eig) < 1e-10 * scale) == 6
    assert np.sort(np.abs(eig))[6] > 1e-8 * scale


@pytest.mark.parametrize("angle_deg", [0.0, 37.0, 179.0, 540.0])
def test_rigid_motion_reproduced_exactly_and_strain_free(angle_deg):
    """Positions of material points follow R X + t; the FFR force vanishes with A = R,
    also for large rotations (angle_deg up to 540)."""
    axis = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    rot = Rotation.from_rotvec(np.radians(angle_deg) * axis).as_matrix()
    shift = np.array([1.5, -2.0, 0.7])
    beam = free_beam()
    e0_frame = beam.e0  # the frame is the identity
    e0 = e0_frame.reshape(-1, 4, 3)
    moved = np.einsum("ij,nkj->nki", rot, e0)
    moved[:, 0, :] += shift
    e = moved.ravel()
    xi, y, z = RNG.random(20), RNG.uniform(-0.04, 0.04, 20), RNG.uniform(-0.05, 0.05, 20)
    dofs, lengths = beam.sets[0].dofs, beam.sets[0].body.lengths
    elements = RNG.integers(0, beam.sets[0].nel, 20)
    shape, *_ = kernel.beam_shape(xi, y, z, lengths[elements])
    for p in range(20):
        q0 = e0_frame[dofs[:, elements[p]]].reshape(8, 3)
        q = e[dofs[:, elements[p]]].reshape(8, 3)
        x_ref = shape[:, p] @ q0
        np.testing.assert_allclose(shape[:, p] @ q, rot @ x_ref + shift, atol=1e-13)
    moving = free_beam(rotation=rot)
    np.testing.assert_allclose(frame_coordinates(moving)[3:12], np.eye(3).ravel(), atol=1e-15)
    force, energy, _ = moving.internal_force(e)
    assert np.abs(force).max() < 1e-12 * np.abs(moving.sets[0].stiffness0).max()
    assert abs(energy) < 1e-20


def test_ffr_stiffness_matches_central_differences_of_the_force():
    rot = Rotation.from_euler("xyz", [0.4, -1.1, 2.3]).as_matrix()
    beam = free_beam(nodes=3, rotation=rot)
    e = beam.e0 + 1e-3 * RNG.standard_normal(beam.ndof)
    k = beam.stiffness_matrix().toarray()
    h = 1e-6
    fd = np.empty_like(k)
    for j in range(beam.ndof):
        step = np.zeros(beam.ndof)
        step[j] = h
        fd[:, j] = (beam.internal_force(e + step)[0] - beam.internal_force(e - step)[0]) / (2 * h)
    np.testing.assert_allclose(fd, k, atol=1e-7 * np.abs(k).max())
    # energy is consistent with the force: dU/de = Q_el
    j = 17
    step = np.zeros(beam.ndof)
    step[j] = h
    du = (beam.internal_force(e + step)[1] - beam.internal_force(e - step)[1]) / (2 * h)
    assert du == pytest.approx(beam.internal_force(e)[0][j], rel=1e-6)


def test_poisson_ratio_stiffens_bending_locking_documented():
    """With nu > 0 the linear continuum element locks (bending stiffer than EI) - the reason
    the paper and our default use nu = 0 (docs/theory.md)."""
    def tip_stiffness(nu: float) -> float:
        mesh = beam_model(5, 2.0, width=0.05, height=0.05, poisson=nu)
        k = mesh.stiffness_matrix().toarray()
        fixed = [0, 1, 2, 6, 7, 8, 9, 10, 11]
        free = np.setdiff1d(np.arange(mesh.ndof), fixed)
        f = np.zeros(mesh.ndof)
        f[mesh.ndof - 12 + 1] = -1.0
        u = np.linalg.solve(k[np.ix_(free, free)], f[free])
        return -1.0 / u[list(free).index(mesh.ndof - 12 + 1)]
    assert tip_stiffness(0.3) > 1.1 * tip_stiffness(0.0)
