"""The beam element families' section forces from the kernel (element_sets section_forces,
fortran/src/elements/beam_stations.f90; issue 36 item 3): zero in the reference and after
any rigid motion (the strain measures are invariant), each row independent of the rows
called with it (bit for bit: the dynamic recorder's chunks may group rows any way), and a
set without section forces or a station outside its element refused with the kernel's
words."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import Rectangle, System, _kernel
from ancfdrv.errors import SolverError
from ancfdrv.system.answers import section_forces

STEEL = dict(youngs_modulus=2.1e11, poisson_ratio=0.3, density=7850.0)


def _free_beam(bending: str):
    s = System("free")
    steel = s.material("steel", **STEEL)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(2, 0.5, 0.2), nodes=5,
           section=Rectangle(0.05, 0.1), formulation="nonlinear", bending=bending)
    return s.assemble()


def _rotation(axis, angle: float) -> np.ndarray:
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    skew = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * skew + (1 - np.cos(angle)) * skew @ skew


@pytest.mark.parametrize("bending", ["continuum", "cubic"])
def test_rigid_motions_carry_no_section_force(bending):
    """A free beam in its reference and turned by 1.1 rad about a skew axis and moved:
    every section force is zero to round-off (E A times 1e-13 at most)."""
    model = _free_beam(bending)
    beam = model.bodies[0]
    q0 = model.expand(model.e0)
    vectors = q0[beam.first:beam.first + beam.ncoordinates].reshape(-1, 3)
    moved = vectors @ _rotation((1.0, -2.0, 0.5), 1.1).T
    moved[0::4] += (0.3, -4.0, 2.0)   # positions move, directors and slopes only turn
    q = q0.copy()
    q[beam.first:beam.first + beam.ncoordinates] = moved.ravel()
    assert model.reduction is None   # a free beam: e is q
    f = section_forces(model, np.stack([model.e0, q]), t=np.zeros(2))["arm"]
    scale = 2.1e11 * 0.05 * 0.1
    for values in (f.N, f.T, f.Q, f.M):
        assert np.abs(values).max() <= 1e-13 * scale
    model.close()


@pytest.mark.parametrize("bending", ["continuum", "cubic"])
def test_rows_are_independent_of_their_grouping(bending):
    """Random deformed states: one call over eight rows gives each row bit for bit as a
    call with that row alone (and the forces are not all zero)."""
    model = _free_beam(bending)
    rng = np.random.default_rng(5)
    rows = model.e0 + 1e-3 * rng.normal(size=(8, model.ndof))
    times = np.linspace(0.0, 0.7, 8)
    together = section_forces(model, rows, 4, t=times)["arm"]
    assert np.abs(together.N).max() > 1e3
    for r in (0, 3, 7):
        alone = section_forces(model, rows[r], 4, t=times[r])["arm"]
        for key in ("N", "T", "Q", "M"):
            assert np.array_equal(getattr(together, key)[r], getattr(alone, key))
    model.close()


def test_a_set_without_section_forces_and_a_station_outside_are_refused():
    """The kernel refuses a plate's set (it reports no section forces) and a station
    outside [0, 1], naming the problem."""
    s = System("mixed")
    steel = s.material("steel", **STEEL)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(1, 0, 0), nodes=3,
           section=Rectangle(0.05, 0.1), formulation="nonlinear")
    s.plate("sheet", material=steel, thickness=0.01, corner=(0, 1, 0), edge_x=(1, 0, 0),
            edge_y=(0, 1, 0), nx=1, ny=1)
    model = s.assemble()
    beam, plate = (next(info for info in model.sets if info.body.name == name)
                   for name in ("arm", "sheet"))
    with pytest.raises(SolverError, match="stations"):
        model.kernel.section_forces(beam.index, [0.0], model.e0[None], [0.0, 1.5])
    forces = np.empty((2 * plate.nel, 1, 6), order="F")   # (the caller gives it)
    _, info, message = _kernel.system_section_forces(
        model.kernel.handle, plate.index, [0.0], model.e0[:, None], [0.0, 1.0], forces)
    assert info == 3 and "reports no section forces" in message.decode()
    model.close()


def _ffr_cantilever(nodes: int = 4, length: float = 2.0, tip=(0.0, 400.0, 0.0)):
    s = System("ffr cantilever")
    steel = s.material("steel", **STEEL)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=nodes,
           section=Rectangle(0.06, 0.1), height_axis=(0, 1, 0), formulation="ffr",
           bending="cubic")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("tip", "force", body="arm", point=(length, 0, 0), vector=tip)
    return s.assemble()


def test_ffr_forms_follow_the_stations_asked_for():
    """An FFR beam's section forces come from linear forms the kernel builds for the
    stations of a call and keeps: a cantilever (2 m, 3 elements, 'cubic') with a tip force
    P = 400 N along its height axis has Q_height = P and M_width = P (L - s) at every
    station (small-strain statics, exact for the cubic field), asked with 3, then 4, then 3
    stations per element (the forms rebuilt each time the stations change), to 1e-9 of
    P L; N, T and the other components vanish."""
    from ancfdrv.solvers.static import solve_newton
    model = _ffr_cantilever()
    e = solve_newton(model, tol=1e-12).e
    P, L = 400.0, 2.0
    for stations in (3, 4, 3):
        f = section_forces(model, e, stations)["arm"]
        assert len(f.s) == 3 * stations
        assert np.abs(f.Q[:, 0] - P).max() <= 1e-9 * P * L
        assert np.abs(f.M[:, 1] - P * (L - f.s)).max() <= 1e-9 * P * L
        for values in (f.N, f.T, f.Q[:, 1], f.M[:, 0]):
            assert np.abs(values).max() <= 1e-9 * P * L
    model.close()


def test_ffr_rows_are_independent_of_their_grouping():
    """Random FFR states over 37 rows (more than the kernel's blocks of 16): one call gives
    each row bit for bit as a call with that row alone (the dynamic recorder's chunks may
    group rows any way), and the forces are not all zero."""
    model = _ffr_cantilever()
    rng = np.random.default_rng(11)
    rows = model.e0 + 1e-3 * rng.standard_normal((37, model.ndof))
    times = np.zeros(len(rows))
    together = section_forces(model, rows, 3, t=times)["arm"]
    assert np.abs(together.N).max() > 1e3
    for r in (0, 15, 16, 36):
        alone = section_forces(model, rows[r], 3, t=0.0)["arm"]
        for key in ("N", "T", "Q", "M"):
            assert np.array_equal(getattr(together, key)[r], getattr(alone, key))
    model.close()


@pytest.mark.parametrize("formulation", ["ffr", "nonlinear"])
def test_largest_magnitudes_are_those_of_the_rows(formulation):
    """The kernel returns with the section forces each force's largest magnitude over the
    rows (the stress envelope's bound): numpy's max |F| over the same forces, bit for bit,
    and not a number at the stations of a row that is not a number."""
    model = _ffr_cantilever() if formulation == "ffr" else _free_beam("cubic")
    index = model.sets[0].index
    rng = np.random.default_rng(3)
    rows = model.e0 + 1e-3 * rng.standard_normal((9, model.ndof))
    xi = np.linspace(0.0, 1.0, 3)
    forces, largest = model.kernel.section_forces(index, np.zeros(9), rows, xi)
    assert np.array_equal(largest, np.abs(forces).max(axis=1))
    assert np.all(largest > 0.0)
    rows[4, :] = np.nan
    forces, largest = model.kernel.section_forces(index, np.zeros(9), rows, xi)
    assert np.isnan(forces[:, 4]).all() and np.isnan(largest).all()
    model.close()
