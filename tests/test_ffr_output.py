"""The FFR boom's output in bulk (issue 23 item 4): the cheaper computations give the
numbers of the straightforward ones they replace.

References: the plain computations themselves (argmax over every fibre of every row, the
dense linear-strain product, the section-vector check element by element), exact where the
arithmetic is the same (array bytes equal) and to rounding (1e-12 of the largest value)
where only the summation order changed; the stress bound against the fibre stresses it
bounds."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import Box, Circle, Rectangle, System, Tube
from ancfdrv.solvers.assumptions import ffr_departure_rows
from ancfdrv.system import answers
from ancfdrv.system.answers import SectionForces, peak_rows, von_mises_peak

SECTIONS = [Rectangle(0.05, 0.1), Box(0.2, 0.3, 0.01), Tube(0.1, 0.01), Circle(0.05)]
IDS = ["rectangle", "box", "tube", "circle"]


def _forces(rng, nt: int, ns: int) -> SectionForces:
    """Rows of an oscillating bending moment with a few shear and torsion terms: peaks
    that repeat (ties) and rows far below them."""
    t = np.linspace(0.0, 6.0, nt)[:, None]
    wave = np.sin(2 * np.pi * t + rng.uniform(0, 6, ns))
    m = np.stack([rng.normal(size=(nt, ns)) * 50.0, 2e3 * np.round(wave, 2)], axis=-1)
    return SectionForces(s=np.linspace(0, 1, ns), N=rng.normal(size=(nt, ns)) * 1e3,
                         T=rng.normal(size=(nt, ns)) * 10.0, Q=rng.normal(size=(nt, ns, 2)) * 1e2,
                         M=m)


@pytest.mark.parametrize("section", SECTIONS, ids=IDS)
def test_stress_bound_holds_at_every_fibre(section):
    """sqrt(sigma_bound^2 + 3 tau_bound^2) from the per-unit coefficients is >= the von
    Mises stress of every fibre point, and is reached (to 0.1%) where one force acts alone
    (a tight bound: no more rows evaluated than needed)."""
    rng = np.random.default_rng(3)
    forces = SectionForces(s=np.zeros(400), N=rng.normal(size=400) * 1e4,
                           T=rng.normal(size=400) * 1e3, Q=rng.normal(size=(400, 2)) * 1e4,
                           M=rng.normal(size=(400, 2)) * 1e4)
    normal, shear = answers._stress_bounds(section)
    sig = (np.abs(forces.N) * normal[0] + np.abs(forces.M[:, 1]) * normal[1]
           + np.abs(forces.M[:, 0]) * normal[2])
    tau = (np.abs(forces.T) * shear[0] + np.abs(forces.Q[:, 0]) * shear[1]
           + np.abs(forces.Q[:, 1]) * shear[2])
    assert np.all(np.sqrt(sig**2 + 3 * tau**2) >= von_mises_peak(section, forces))
    alone = SectionForces(s=np.zeros(1), N=np.zeros(1), T=np.zeros(1), Q=np.zeros((1, 2)),
                          M=np.array([[0.0, 1e4]]))
    assert von_mises_peak(section, alone)[0] == pytest.approx(1e4 * normal[1], rel=1e-3)


@pytest.mark.parametrize("section", SECTIONS, ids=IDS)
def test_peak_rows_is_argmax_of_every_fibre_bitwise(section):
    """peak_rows (fibres evaluated only where the bound reaches the peak) gives the row
    and value argmax over every fibre of every row gives: bit for bit, the first row of
    repeated peaks; with a floor (the envelope so far) the stations it lifts are the
    same, and a floor above every row lifts none."""
    rng = np.random.default_rng(11)
    forces = _forces(rng, 600, 7)
    vm = von_mises_peak(section, forces)
    row = np.argmax(vm, axis=0)
    found_row, found = peak_rows(section, forces)
    assert np.array_equal(found_row, row)
    assert found.tobytes() == vm[row, np.arange(7)].tobytes()
    floor = vm.max(axis=0) * np.array([0.5, 1.0, 2.0, 0.9, 1.0, 0.99, 0.1])
    found_row, found = peak_rows(section, forces, floor)
    lifted = vm.max(axis=0) > floor
    assert np.array_equal(found > floor, lifted)
    assert np.array_equal(found_row[lifted], row[lifted])
    assert found[lifted].tobytes() == vm[row, np.arange(7)][lifted].tobytes()


def test_peak_rows_falls_back_on_non_finite_forces():
    """A NaN force: the plain argmax's answer (NaN is its maximum), not a skipped row."""
    rng = np.random.default_rng(5)
    forces = _forces(rng, 50, 3)
    forces.N[17, 1] = np.nan
    vm = von_mises_peak(SECTIONS[0], forces)
    row, peak = peak_rows(SECTIONS[0], forces)
    assert np.array_equal(row, np.argmax(vm, axis=0)) and np.isnan(peak[1])


def _ffr_beam(nodes: int = 7):
    s = System("c")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(2, 0, 0), nodes=nodes,
           section=Rectangle(0.05, 0.1), height_axis=(0, 1, 0), formulation="ffr",
           bending="cubic")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("tip", "force", body="arm", point=(2, 0, 0), vector=(30.0, 100.0, -40.0))
    return s.assemble()


def test_element_blocks_hold_the_whole_linear_strain_matrix():
    """Every entry of the FFR linear-strain matrix outside the element's own 24 rows is
    exactly zero, so the stacked per-element product is the dense product: the same
    strain measures to rounding (1e-12 of the largest) on rows of random displacements."""
    model = _ffr_beam()
    beam = model.bodies[0]
    tables = answers._tables(beam, 3)
    dense = tables.linear_strain(beam).reshape(beam.ncoordinates, beam.nel, 3, 8)
    for e in range(beam.nel):
        outside = np.ones(beam.ncoordinates, dtype=bool)
        outside[12 * e:12 * e + 24] = False
        assert not dense[outside, e].any()
    rng = np.random.default_rng(2)
    d = rng.normal(size=(40, beam.ncoordinates)) * 1e-3
    plain = (d @ tables.linear_strain(beam)).reshape(40, beam.nel, 3, 8)[..., :6]
    stacked = answers._element_strains(tables.element_strain(beam), d, 3)
    assert np.abs(stacked - plain).max() <= 1e-12 * np.abs(plain).max()
    one = answers._element_strains(tables.element_strain(beam), d[4], 3)
    assert np.abs(one - plain[4]).max() <= 1e-12 * np.abs(plain).max()
    model.close()


def test_ffr_departure_rows_is_the_per_element_measure():
    """The small-strain check on each node's section vectors once equals the measure
    element by element, |A^T r_i - r_i0| maximized over all elements' r_x, r_y, r_z, bit
    for bit (shared nodes counted once change nothing)."""
    model = _ffr_beam()
    info = [s for s in model.sets if s.kind == "ffr"][0]
    rng = np.random.default_rng(4)
    rows = model.e0[None, :] + rng.normal(size=(25, model.ndof)) * 1e-2
    times = np.linspace(0.0, 1.0, 25)
    q = model.expand(rows)
    current = q[:, info.dofs.reshape(-1, order="F")].reshape(25, info.nel, 8, 3)
    current = current[:, :, [1, 2, 3, 5, 6, 7]]
    reference = np.asarray(info.reference).reshape(3, 8, info.nel, order="F")
    reference = reference[:, [1, 2, 3, 5, 6, 7]].transpose(2, 1, 0)
    rotation = model.frames[info.frame - 1].rotation(0.0) if info.frame else np.eye(3)
    plain = np.linalg.norm(current @ rotation - reference[None], axis=-1).reshape(25, -1)
    (name, change), = ffr_departure_rows(model, rows, times)
    assert name == "arm"
    assert change.tobytes() == plain.max(axis=1).tobytes()
    model.close()
