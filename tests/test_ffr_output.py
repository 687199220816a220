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


def test_ffr_departure_rows_is_the_per_element_measure():
    """The kernel's small-strain check (each shared node's section vectors once) equals
    the measure element by element, |A^T r_i - r_i0| maximized over all elements' r_x,
    r_y, r_z (numpy's products: the same up to the round-off of a unit vector's turn)."""
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
    # the vectors are unit length: their turned values round at ~1e-16, the change ~1e-2
    np.testing.assert_allclose(change, plain.max(axis=1), rtol=0.0, atol=1e-14)
    assert change.min() > 1e-3
    model.close()


# -- the modally reduced FFR run's rows in bulk (solvers/ffr_reduced.RowMaps) ----------------
from conftest import INPUTS  # noqa: E402

BOOM = INPUTS / "boom_luffing.nml"
SMALL = ["beam.nodes=10", "solver.t_end=3.0", "solver.static_method=newton"]


def _reduced(*extra: str, modes: int = 3):
    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    from ancfdrv.solvers.ffr_reduced import reduce_ffr, simulate
    from ancfdrv.solvers.static import solve_newton
    model = build_model(load_scene(BOOM, [*SMALL, *extra]))
    static = solve_newton(model, tol=1e-12, max_iter=50)
    reduced = reduce_ffr(model, static, modes)
    return model, reduced, simulate(reduced, 3.0, 1e-3)


def _long_double_set_terms(model, reduced, t, eta):
    """Strain energy and frame power of the FFR sets (ffr_elastic: ffr_energy_power and
    add_second_order_power) at one reduced state, in long double from the expansion."""
    ld = np.longdouble
    frame = model.frames[0]
    k = (frame.axis / np.linalg.norm(frame.axis)).astype(ld)
    phi, rate, _ = (float(v[0]) for v in reduced.drive.values(np.array([t])))
    psi = ld(phi) - ld(reduced.start_angle)
    w = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]], dtype=ld)
    turn = np.eye(3, dtype=ld) + np.sin(psi) * w + (1 - np.cos(psi)) * (w @ w)
    y = (reduced.static_state - reduced.pivot_vector).astype(ld) \
        + reduced.basis.astype(ld) @ eta.astype(ld)
    e = reduced.pivot_vector.astype(ld) + (y.reshape(-1, 3) @ turn.T).reshape(-1)
    rotation = turn @ frame.rotation(0.0).astype(ld)
    energy = power = ld(0)
    for info in model.sets:
        for el in range(info.nel):
            ref = info.reference[:, el].astype(ld)
            local = (e[info.dofs[:, el]].reshape(8, 3) @ rotation).reshape(-1) - ref
            force = info.stiffness0[:, :, el].astype(ld) @ local
            if info.second_order is not None:
                rigidity, axis, length, gram = info.second_order
                axial = ld(rigidity[el]) * (axis[:, el].astype(ld) @ (local[12:15] - local[0:3])) \
                    / ld(length[el])
                extra = axial * (np.kron(gram[:, :, el], np.eye(3)).astype(ld) @ local)
                energy += ld(0.5) * local @ extra
                force = force + extra
            energy += ld(0.5) * local @ (info.stiffness0[:, :, el].astype(ld) @ local)
            x = (local + ref).reshape(8, 3)
            power -= ld(rate) * np.sum(force.reshape(8, 3) * np.cross(k, x))
    return energy, power


@pytest.mark.parametrize("extra", [[], ["beam.geometric_stiffness=true", "beam.bending=cubic"]],
                         ids=["linear", "pdelta"])
def test_reduced_rows_are_the_kernel_output_row(extra):
    """RowMaps.rows (quadratic and cubic forms of the reduced state) against the kernel's
    output row of the expanded state: probes, deflections, kinetic, loads' and moment
    energies to 1e-12 of their largest value, the constraint violation to the expansion's
    rounding; the strain energy and frame power, whose kernel sums cancel by 3-4 orders
    of magnitude, against the same formulas in long double (1e-11 and 1e-9 of the
    largest; measured on the 28-node boom: the kernel itself 4e-12 and 7e-10 off)."""
    from ancfdrv.solvers.ffr_reduced import RowMaps, expand
    model, reduced, out = _reduced(*extra)
    assert RowMaps.supported(model)
    rows = np.arange(0, len(out["time"]), 150)
    times, eta, vel = out["time"][rows], out["eta"][rows], out["velocity"][rows]
    found = RowMaps(model, reduced).rows(times, eta, vel)
    e, v = expand(reduced, times, eta, vel)
    ncon = len(model.constraints)
    kernel = [model.kernel.output_row(float(t), e[i], v[i], np.zeros(ncon), np.zeros(5),
                                      model.contact_guesses.copy(), np.zeros(6, dtype=np.int32))
              for i, t in enumerate(times)]
    for key, name in (("probes", "probes"), ("deflections", "deflections")):
        plain = np.array([row[key] for row in kernel])
        assert np.abs(found[name] - plain).max() <= 1e-12 * np.abs(plain).max()
    energy = np.array([row["energy"] for row in kernel])
    for column in (0, 2, 3):     # kinetic, loads, moment
        scale = np.abs(energy[:, column]).max()
        assert scale > 0
        assert np.abs(found["energy"][:, column] - energy[:, column]).max() <= 1e-12 * scale
    violation = np.array([row["violation"] for row in kernel])
    assert np.abs(found["violation"] - violation).max() <= 4e-16 * model.length_scale
    exact = np.array([_long_double_set_terms(model, reduced, t, eta[i])
                      for i, t in enumerate(times)], dtype=np.longdouble)
    strain, power = exact[:, 0], exact[:, 1]
    assert float(np.abs(found["energy"][:, 1] - strain).max()) <= 1e-11 * float(
        np.abs(strain).max())
    assert float(np.abs(found["power"] - power).max()) <= 1e-9 * float(np.abs(power).max())
    total = found["energy"][:, :4].sum(axis=1)
    assert np.abs(found["energy"][:, 4] - total).max() <= 1e-12 * np.abs(total).max()
    model.close()


def test_expanded_rows_expand_only_what_is_asked():
    """ExpandedRows gives expand()'s rows: the last row, a mask's rows, a slice, and every
    row through np.asarray (bit for bit: the same arithmetic)."""
    from ancfdrv.solvers.ffr_reduced import ExpandedRows, expand
    model, reduced, out = _reduced()
    times, eta = out["time"][:40], out["eta"][:40]
    plain, _ = expand(reduced, times, eta, np.zeros_like(eta))
    lazy = ExpandedRows(reduced, times, eta)
    assert len(lazy) == 40 and lazy.shape == plain.shape
    mask = np.arange(40) % 7 == 0
    assert np.allclose(lazy[mask], plain[mask], rtol=0, atol=1e-15)
    assert np.allclose(lazy[-1], plain[-1], rtol=0, atol=1e-15)
    assert np.allclose(lazy[3:9], plain[3:9], rtol=0, atol=1e-15)
    assert np.asarray(lazy).tobytes() == plain.tobytes()
    model.close()


def test_reduced_small_strain_check_bound_and_stop():
    """The bound c + n . |eta| is >= the section vectors' change at reduced states, small
    and far beyond the limit; a history driven past the limit stops at the first row the
    full check (every row expanded) finds outside, the rows after it dropped."""
    from ancfdrv.solvers.assumptions import FFR_LIMIT
    from ancfdrv.solvers.ffr_reduced import (ExpandedRows, _departure_bound,
                                             _reduced_assumptions, expand)
    model, reduced, out = _reduced()
    c, n = _departure_bound(model, reduced)
    rng = np.random.default_rng(9)
    eta = rng.normal(size=(30, reduced.size)) * np.logspace(-3, 1, 30)[:, None]
    times = np.linspace(0.0, 3.0, 30)
    e, _ = expand(reduced, times, eta, np.zeros_like(eta))
    (_, change), = ffr_departure_rows(model, e, times)
    assert np.all(c + np.abs(eta) @ n >= change)
    ramp = np.linspace(0.0, 1.0, 30)[:, None] * eta[-1]        # crosses the limit once
    e, _ = expand(reduced, times, ramp, np.zeros_like(ramp))
    (_, change), = ffr_departure_rows(model, e, times)
    first = int(np.argmax(change > FFR_LIMIT))
    assert 0 < first < 29
    from ancfdrv.solvers import dynamic
    chunk = dynamic.Chunk(time=times, probes=np.zeros((30, 1, 3)),
                          deflections=np.zeros((30, 1, 3)), lam=np.zeros((30, 0)),
                          energy=np.zeros((30, 11)), constraint=np.zeros(30),
                          stats=np.zeros((30, 3)), q=ExpandedRows(reduced, times, ramp))
    kept, why = _reduced_assumptions(model, reduced, chunk, ramp, True)
    assert len(kept.time) == first + 1 and "small-strain" in why
    assert len(kept.q) == first + 1
    model.close()


def test_reduced_run_file_keeps_every_dataset(tmp_path, monkeypatch):
    """A reduced run with the rows in bulk writes the datasets and attributes the row by
    row path writes (XDMF frames included), with the same values: 1e-12 of each dataset's
    largest (each value is a short sum of terms of that scale, summed in another order);
    the energies and works to 1e-11 of the run's energy scale (the largest energy of any
    kind: each is a sum of terms of that scale - the frame's work 0.8 J nets the gravity
    moment's 4.3 kJ of power terms - and the works accumulate their rounding over the
    run's 1000 steps, 1e3 x 2.2e-16 = 2.2e-13 of the scale; measured 4.4e-13)."""
    import h5py
    from ancfdrv.runner import run_scene
    from ancfdrv.solvers import ffr_reduced
    over = ["beam.nodes=10", "solver.static_method=newton", "beam.modes=2", "solver.t_end=1.0",
            "output.xdmf_frames=20"]
    bulk, plain = tmp_path / "bulk.h5", tmp_path / "plain.h5"
    run_scene(BOOM, over, bulk, progress=False)
    monkeypatch.setattr(ffr_reduced.RowMaps, "supported", staticmethod(lambda model: False))
    run_scene(BOOM, over, plain, progress=False)
    with h5py.File(bulk) as a, h5py.File(plain) as b:
        energy_scale = max(np.nanmax(np.abs(d[()]), initial=0.0)
                           for d in b["dynamic/energy"].values())
        names_a, names_b = [], []
        a["dynamic"].visit(names_a.append)
        b["dynamic"].visit(names_b.append)
        assert names_a == names_b
        assert a["dynamic"].attrs["not_provided"] == b["dynamic"].attrs["not_provided"]
        for name in names_a:
            x, y = a["dynamic"][name], b["dynamic"][name]
            if not isinstance(x, h5py.Dataset) or x.dtype.kind != "f":
                continue
            x, y = x[()], y[()]
            assert np.array_equal(np.isnan(x), np.isnan(y)), name
            scale = np.nanmax(np.abs(y)) if np.isfinite(y).any() else 0.0
            tol = (1e-11 * energy_scale if name.startswith("energy/") else 1e-12 * scale) \
                + 1e-300
            assert np.nanmax(np.abs(x - y), initial=0.0) <= tol, name


def test_kinetic_energy_of_the_banded_kron_mass():
    """The kernel's mass products of an 'ffr' boom go by the diagonals of kron(Mbar, I3)
    (system_mass band_product): its kinetic energy at a random velocity is 1/2 v.M v of
    the assembled mass, and so is that of a spatial cable with a pin (kron mass too)."""
    from ancfdrv.builders import build_model
    from ancfdrv.codes import ENERGY_NAMES
    from ancfdrv.io.scene import load_scene
    boom = load_scene(BOOM, SMALL)
    s = System("cable")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.cable("c", material=steel, start=(0, 0, 0), end=(2.0, 0.3, 0.1), nodes=7,
            section=Circle(0.02))
    s.joint("pin", "spherical", "ground", "c", point=(0, 0, 0))
    kinetic = ENERGY_NAMES.index("kinetic")
    for model in (build_model(boom), s.assemble()):
        try:
            ks = model.kernel
            v = np.random.default_rng(3).standard_normal(model.ndof)
            row = ks.output_row(0.0, model.e0, v, np.zeros(ks.ncon), np.zeros(5),
                                model.contact_guesses, np.zeros(6, np.int32))
            reference = 0.5 * v @ (model.mass_matrix() @ v)
            assert abs(row["energy"][kinetic] - reference) <= 1e-13 * reference
        finally:
            model.close()
