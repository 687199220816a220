"""The stepping kernels of small planar cable systems (issue 23, the flexible pendulum's
cost per Newton correction): each lean path must give the numbers of the general path it
replaces, to the last bit, and keep the element's invariants.

* cable_set_forces (fortran/src/elements/cable_element.f90): a small cable set's force pass
  without the generic dispatch (on a planar reduction's one-to-one selection straight on the
  independent coordinates: cable_selected_forces), a plane element (z = 0) by plane_element_force (the five
  Gauss points side by side), the output rows' energy by plane_element_energy: against the
  element routine of the element API (rule_element_force, the general 3D expressions),
  bit for bit, in the plane and out of it; the plane force against central differences of
  the plane energy; no force and no energy in a large rigid rotation in the plane.
* the mass product of a planar reduction by (x, y) pairs (mechanical_system's
  plane_mass_setup, set at the stepper's setup): the kinetic energy of an output row the
  same bits before and after the setup, and 1/2 v.M v of the assembled mass.
* the banded Cholesky's forward substitution by the columns of U^T: against a dense solve.
"""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import Circle, System, kernel
from ancfdrv.codes import ENERGY_NAMES
from ancfdrv.kernel import DirectSolver
from ancfdrv.solvers.dynamic import DynamicSettings

E, RHO, D, LENGTH, NODES = 2.1e11, 7850.0, 0.02, 1.2, 5
AREA, INERTIA = np.pi * D**2 / 4.0, np.pi * D**4 / 64.0


def _free_cable(planar: str = "off"):
    """A free steel cable along x (no joints: the full coordinates are the unknowns, node
    by node (r, r_x))."""
    s = System("plane kernels", planar=planar)
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.cable("c", material=steel, start=(0, 0, 0), end=(LENGTH, 0, 0), nodes=NODES,
            section=Circle(D))
    return s.assemble()


def _bent(z_amplitude: float = 0.0) -> np.ndarray:
    """Nodal (r, r_x) of the cable bent along an arc of radius 0.9 m and stretched by 0.3 %,
    lifted out of the plane by z_amplitude sin(pi x / L) (0: in the plane z = 0)."""
    e = []
    for x in np.linspace(0.0, LENGTH, NODES):
        angle = x / 0.9
        stretch = 1.003
        r = [0.9 * np.sin(angle) * stretch, 0.9 * (1.0 - np.cos(angle)) * stretch,
             z_amplitude * np.sin(np.pi * x / LENGTH)]
        r_x = [np.cos(angle) * stretch, np.sin(angle) * stretch,
               z_amplitude * np.pi / LENGTH * np.cos(np.pi * x / LENGTH)]
        e += r + r_x
    return np.array(e)


def _element_reference(model, e: np.ndarray, lengths_from=None) -> tuple[np.ndarray, float]:
    """The element API's force and energy (rule_element_force per element, summed in
    element order from 0, as the system's set loop sums them) at the full coordinates e,
    with the model's element lengths (its nodes' distances in the reference, the full
    reference lengths_from, default the model's e0)."""
    dofs = np.array([np.arange(6 * k, 6 * k + 12) for k in range(NODES - 1)]).T
    lengths = np.diff((model.e0 if lengths_from is None else lengths_from)[0::6])
    force, energy, _, _ = kernel.cable_forces(dofs, e, lengths, E * AREA, E * INERTIA, False)
    return force, energy


@pytest.mark.parametrize("z_amplitude", [0.0, 0.01])
def test_set_force_pass_is_the_element_routine_bit_for_bit(z_amplitude):
    """In the plane z = 0 the set's plane kernel, out of it the general element routine,
    through the set loop without the generic dispatch: force and strain energy equal to
    the element API's to the last bit (a bent, stretched cable: every term nonzero)."""
    model = _free_cable()
    try:
        e = _bent(z_amplitude)
        assert model.ndof == 6 * NODES
        out = model.forces(e)
        force, energy = _element_reference(model, e)
        assert np.abs(force).max() > 1.0 and energy > 1.0
        assert out["internal"].tobytes() == force.tobytes()
        assert out["strain"] == energy
    finally:
        model.close()


def test_force_on_the_planar_selection_is_the_element_routine_bit_for_bit():
    """A pinned cable reduced to the x-y plane (a one-to-one selection of the full
    coordinates): the internal force on the independent coordinates (the sets straight on
    them, selected_forces) is the element API's full force at q = B e + q0, taken at the
    selected coordinates, to the last bit, and the strain energy the same."""
    s = System("selection", planar="xy")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.cable("c", material=steel, start=(0, 0, 0), end=(LENGTH, 0, 0), nodes=NODES,
            section=Circle(D))
    s.joint("pin", "spherical", "ground", "c", point=(0, 0, 0))
    model = s.assemble()
    try:
        independent = model.reduction.independent
        # B selects, one to one: column k is the unit vector of full coordinate independent[k]
        unit = model.expand(np.eye(model.ndof), with_offset=False)
        np.testing.assert_array_equal(unit, np.eye(model.nfull)[:, independent].T)
        bent = _bent()
        bent[:3] = 0.0   # the pinned root
        e = bent[independent]
        q = model.expand(e)
        np.testing.assert_array_equal(q, bent)
        out = model.forces(e)
        force, energy = _element_reference(model, q, lengths_from=model.q0)
        assert out["internal"].tobytes() == force[independent].tobytes()
        assert out["strain"] == energy
    finally:
        model.close()


def test_plane_force_is_the_gradient_of_the_plane_energy():
    """The plane kernel's force against central differences of its own strain energy (the
    row energy's path, plane_element_energy) in the x and y coordinates."""
    model = _free_cable()
    try:
        e = _bent()
        force = model.forces(e)["internal"]
        step = 1e-7
        for i in [0, 1, 3, 4, 6, 7, 9, 10, 13, 22]:
            ep, em = e.copy(), e.copy()
            ep[i] += step
            em[i] -= step
            numeric = (model.forces(ep)["strain"] - model.forces(em)["strain"]) / (2 * step)
            assert abs(numeric - force[i]) <= 2e-6 * np.abs(force).max(), (i, numeric, force[i])
    finally:
        model.close()


def test_rigid_rotation_in_the_plane_has_no_strain():
    """A straight, unstretched cable turned by 37 degrees about z: no strain energy and no
    force beyond round-off of the axial stiffness."""
    model = _free_cable()
    try:
        c, s = np.cos(np.radians(37.0)), np.sin(np.radians(37.0))
        e = np.concatenate([[c * x, s * x, 0.0, c, s, 0.0]
                            for x in np.linspace(0.0, LENGTH, NODES)])
        out = model.forces(e)
        assert out["strain"] < 1e-18 * E * AREA * LENGTH
        assert np.abs(out["internal"]).max() < 1e-12 * E * AREA
    finally:
        model.close()


def test_mass_product_by_pairs_is_the_csr_product():
    """A pinned cable reduced to the x-y plane (4 unknowns per node): the kinetic energy of
    an output row (mass_product) is the same bits with the CSR mass (before the stepper's
    setup) and by the plane's (x, y) pairs (after it), and 1/2 v.M v of the assembled
    mass."""
    s = System("pairs", planar="xy")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.cable("c", material=steel, start=(0, 0, 0), end=(LENGTH, 0, 0), nodes=NODES,
            section=Circle(D))
    s.joint("pin", "spherical", "ground", "c", point=(0, 0, 0))
    model = s.assemble()
    try:
        ks = model.kernel
        assert model.ndof == 4 * NODES
        v = np.random.default_rng(7).standard_normal(model.ndof)
        args = (0.0, model.e0, v, np.zeros(ks.ncon), np.zeros(5), np.zeros((2, 1)),
                np.zeros(6, np.int32))
        kinetic = ENERGY_NAMES.index("kinetic")
        before = ks.output_row(*args)["energy"][kinetic]
        ks.stepper_setup(DynamicSettings.generalized_alpha(1e-3, 0.01, 1.0, tol=1e-10,
                                                           max_newton=20))
        after = ks.output_row(*args)["energy"][kinetic]
        assert after == before
        reference = 0.5 * v @ (model.mass_matrix() @ v)
        assert abs(after - reference) <= 1e-13 * reference
    finally:
        model.close()


def test_banded_forward_substitution_by_columns():
    """The banded Cholesky (n = 20, kd = 7, as the 5-node planar cable's matrix) solves
    against numpy's dense solve, one and several right-hand sides, refactorized."""
    rng = np.random.default_rng(11)
    n, kd = 20, 7
    for attempt in range(2):
        a = np.zeros((n, n))
        for i in range(n):
            for j in range(max(0, i - kd), i + 1):
                a[i, j] = a[j, i] = rng.standard_normal()
        a += (np.abs(a).sum(axis=1).max() + 1.0) * np.eye(n)   # positive definite
        rows, cols = np.nonzero(a)
        with DirectSolver(n, rows, cols, banded_spd=True) as solver:
            solver.factorize(a[rows, cols])
            for rhs in (rng.standard_normal(n), rng.standard_normal((n, 3))):
                np.testing.assert_allclose(solver.solve(rhs), np.linalg.solve(a, rhs),
                                           rtol=1e-12, atol=1e-14)
