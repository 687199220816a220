"""The kernel routines of a modally reduced FFR run's output rows and stepping (issue 23:
the reduced boom under 20 ms): the constraint values alone (constraints.constraint_values
through constraint_violation_rows), the energy forms (reduced_ffr_rows), the frame's turn
of the rows (ffr_reduced._turned) and the stepper's refusal of a load that is not a
number. References: the constraint kinds' closed forms (constraints.f90 module doc), the
forms evaluated with numpy's einsum on the tensors before their monomial table, the
rotation matrix of Rodrigues' formula, and constraint_evaluate (the full evaluation the
values must equal bit for bit: one formula)."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import kernel
from ancfdrv.errors import SolverError
from ancfdrv.kernel import _f, _kernel, _state
from ancfdrv.system.drives import Sine

# -- constraint values of every kind at many rows ---------------------------------------------
NDOF = 12      # four 3-vectors a, b, c, d at 0, 3, 6, 9


def _layout():
    """Seven constraints of all four kinds on four 3-vectors, three driven by one Sine
    drive (two coordinates, a distance, a dot), and the closed form of each."""
    drive = Sine("s", amplitude=0.7, frequency=0.9, phase=0.3, offset=0.2)
    # (kind, drive (1-based, 0: none), params, operands: 6 lists of (dof, coef), constants)
    rows = [
        (1, 1, [0.4, 1.3, -0.6, 0.25], [[(0, 1.0)]] + [[]] * 5, [0.0] * 6),
        (1, 0, [0.4, 1.3, -0.6, 0.25], [[(4, 2.0), (7, -1.0)]] + [[]] * 5, [0.1] + [0.0] * 5),
        (1, 1, [-0.3, 0.0, 2.0, 0.0], [[(11, 1.0)]] + [[]] * 5, [0.0] * 6),
        (2, 1, [1.5, 0.8], [[(0, 1.0)], [(1, 1.0)], [(2, 1.0)], [(3, 1.0)], [(4, 1.0)],
                            [(5, 1.0)]], [0.0] * 6),
        (3, 0, [0.0, 0.6, 0.8], [[(6, 1.0)], [(7, 1.0)], [(8, 1.0)], [(9, 0.5)], [(10, 1.0)],
                                 [(11, 1.0)]], [0.2, 0.0, -0.1, 0.0, 0.3, 0.0]),
        (4, 1, [0.9, 1.7], [[(3, 1.0)], [(4, 1.0)], [(5, 1.0)], [(6, 1.0)], [(7, 1.0)],
                            [(8, -2.0), (2, 1.0)]], [0.0] * 6),
        (4, 0, [0.9, 1.7], [[(0, 1.0)], [(1, 1.0)], [(2, 1.0)], [(9, 1.0)], [(10, 1.0)],
                            [(11, 1.0)]], [0.0] * 6),
    ]
    ncon = len(rows)
    kinds = np.array([k for k, *_ in rows], dtype=np.int32)
    drives = np.array([d for _, d, *_ in rows], dtype=np.int32)
    params = np.zeros((8, ncon))
    const = np.zeros((6, ncon))
    ptr, dof, coef = [1], [], []
    for c, (_, _, p, operands, constants) in enumerate(rows):
        params[:len(p), c] = p
        const[:, c] = constants
        for terms in operands:
            for d, a in terms:
                dof.append(d + 1)
                coef.append(a)
            ptr.append(len(dof) + 1)
    data = np.array(drive.params(), dtype=float)
    args = (kinds, drives, params, const, np.array(ptr), np.array(dof), np.array(coef),
            np.array([drive.kind]), np.array([1, 1 + len(data)]), data)

    def closed_form(e: np.ndarray, t: float) -> np.ndarray:
        phi = float(drive.values([t])[0][0])

        def operand(c: int, s: int) -> float:
            return const[s, c] + sum(a * e[d] for d, a in rows[c][3][s])
        out = []
        for c, (kind, driven, p, _, _) in enumerate(rows):
            x = np.array([operand(c, s) for s in range(6)])
            ph = phi if driven else 0.0
            p = params[:, c]
            if kind == 1:
                out.append(x[0] - (p[0] + p[1] * np.cos(ph) + p[2] * np.sin(ph) + p[3] * ph))
            elif kind == 2:
                out.append(np.sum((x[:3] - x[3:]) ** 2) - (p[0] + p[1] * ph) ** 2)
            elif kind == 3:
                out.append(p[:3] @ np.cross(x[:3], x[3:]))
            else:
                out.append(x[:3] @ x[3:] - p[0] - p[1] * ph)
        return np.array(out)
    return args, closed_form


def test_constraint_violation_rows_are_the_closed_forms_and_constraint_evaluate():
    """max |Phi| at 40 rows: the closed form of each kind to rounding (1e-14 of the
    terms), and bit for bit the values constraint_evaluate returns (one formula)."""
    args, closed_form = _layout()
    rng = np.random.default_rng(23)
    e_rows = rng.normal(size=(NDOF, 40))
    times = np.linspace(0.0, 4.0, 40)
    packed = (*kernel.constraint_arrays(*args), len(args[0]))
    violation, info = _kernel.constraint_violation_rows(*packed, _f(e_rows), _f(times))
    assert info == 0
    for row, t in enumerate(times):
        exact = closed_form(e_rows[:, row], t)
        full = _kernel.constraint_evaluate(*packed, _state(e_rows[:, row], np.zeros(NDOF)), t)
        assert full[-1] == 0
        assert violation[row] == np.max(np.abs(full[0]))
        assert abs(violation[row] - np.max(np.abs(exact))) <= 1e-14 * (1.0 + np.max(
            np.abs(e_rows[:, row])) ** 2)
    # the driven constraints move with t: the rows are not one state repeated
    assert np.ptp(violation) > 0.1


def test_constraint_violation_rows_refuse_a_bad_layout():
    """A coordinate out of range (info 1) and a drive index out of range (info: the
    constraint), as constraint_evaluate reports them."""
    args = list(_layout()[0])
    e_rows, times = np.zeros((NDOF, 3)), np.zeros(3)
    short = np.zeros((NDOF - 1, 3))          # the last coordinate (12) out of range
    packed = (*kernel.constraint_arrays(*args), len(args[0]))
    assert _kernel.constraint_violation_rows(*packed, _f(short), _f(times))[1] == 1
    drives = np.array(args[1])
    drives[2] = 5
    args[1] = drives
    packed = (*kernel.constraint_arrays(*args), len(args[0]))
    assert _kernel.constraint_violation_rows(*packed, _f(e_rows), _f(times))[1] == 3
    full = _kernel.constraint_evaluate(*packed, _state(np.zeros(NDOF), np.zeros(NDOF)), 0.0)
    assert full[-1] == 3


# -- the energy forms of the rows -------------------------------------------------------------
@pytest.mark.parametrize("cubic", [False, True], ids=["quadratic", "pdelta"])
def test_energy_rows_are_the_forms(cubic):
    """reduced_ffr_energy_rows at 150 rows (two blocks of 64 and a remainder) against the
    module doc's forms by einsum; the cubic forms from the tensors themselves (not the
    monomial table the kernel walks: ffr_reduced._cubic_table builds it), with the
    coefficients sin psi and 1 - cos psi left out of them as on the frame's axis."""
    from ancfdrv.solvers.ffr_reduced import _cubic_table
    rng = np.random.default_rng(5)
    r, n = 3, 150
    rate, psi = rng.normal(size=n), rng.uniform(-1.0, 1.0, n)
    sin, cos1 = np.sin(psi), 1.0 - np.cos(psi)
    eta, vel = rng.normal(size=(n, r)), rng.normal(size=(n, r))
    kin, strain, power = (rng.normal(size=(m, m)) for m in (1 + 2 * r, 3 + r, 3 + r))
    load_constant, load_linear = 0.7, rng.normal(size=(3, 1 + r))
    z = np.column_stack([rate, rate[:, None] * eta, vel])
    c = np.column_stack([np.ones(n), sin, cos1, eta])
    want_kin = 0.5 * np.einsum("ti,ij,tj->t", z, kin, z)
    want_strain = np.einsum("ti,ij,tj->t", c, strain, c)
    want_power = rate * np.einsum("ti,ij,tj->t", c, power, c)
    ones = np.column_stack([np.ones(n), eta])
    want_load = load_constant + ones @ load_linear[0] + sin * (ones @ load_linear[1]) \
        + cos1 * (ones @ load_linear[2])
    used, table = np.zeros(0, dtype=np.int64), np.zeros((1, 2))
    if cubic:
        tensors = [rng.normal(size=(3 + r,) * 3) for _ in range(2)]
        for t in tensors:          # sin psi and 1 - cos psi in no cubic term
            t[1:3], t[:, 1:3], t[:, :, 1:3] = 0.0, 0.0, 0.0
        used, table = _cubic_table(*tensors)
        assert list(used) == [0] + list(range(3, 3 + r))
        want_strain = want_strain + np.einsum("ti,tj,tk,ijk->t", c, c, c, tensors[0])
        want_power = want_power + rate * np.einsum("ti,tj,tk,ijk->t", c, c, c, tensors[1])
    energies = _kernel.reduced_ffr_energy_rows(
        _f(np.column_stack([rate, sin, cos1])), _f(eta.T), _f(vel.T), _f(kin), _f(strain),
        _f(power), _f(np.asarray(used) + 1, np.int32) if len(used) else np.zeros(0, np.int32),
        _f(table), load_constant, _f(load_linear.T))
    got = energies.T       # the columns kinetic, strain, power, load (KERNEL_LAYOUTS 're')
    for found, want in zip(got, (want_kin, want_strain, want_power, want_load)):
        assert np.abs(found - want).max() <= 1e-13 * np.abs(want).max()


# -- the frame's turn of the rows --------------------------------------------------------------
def test_turned_rows_are_the_rotation_matrix():
    """_turned (W^T and (W^2)^T on all the rows' 3-vectors at once) against Rot(k, psi)
    of each row, Rodrigues' matrix built in long double; lengths kept."""
    from ancfdrv.solvers.ffr_reduced import _skew, _turn
    rng = np.random.default_rng(8)
    k = rng.normal(size=3)
    k /= np.linalg.norm(k)
    psi = rng.uniform(-3.0, 3.0, 25)
    vectors = rng.normal(size=(25, 12))
    turned = _turn(vectors, k, psi)
    w = _skew(k).astype(np.longdouble)
    for i, a in enumerate(psi.astype(np.longdouble)):
        rot = np.eye(3, dtype=np.longdouble) + np.sin(a) * w + (1 - np.cos(a)) * (w @ w)
        want = (vectors[i].reshape(4, 3).astype(np.longdouble) @ rot.T).reshape(-1)
        assert float(np.abs(turned[i] - want).max()) <= 4e-16 * np.abs(vectors[i]).max() * 4
        assert np.allclose(np.linalg.norm(turned[i].reshape(4, 3), axis=1),
                           np.linalg.norm(vectors[i].reshape(4, 3), axis=1), rtol=1e-15,
                           atol=0)


# -- the stepper: a correction that is not a number --------------------------------------------
def test_stepper_refuses_a_load_that_is_not_a_number():
    """With P-delta (simplified Newton), a NaN in the load at one time makes the
    corrections NaN: the stepper reports that Newton did not converge at that step, and
    the same run with a number there converges in a few corrections a step."""
    r, steps = 2, 20
    omega2 = np.array([4.0, 9.0])
    zero = np.zeros((r, r))
    patterns = np.zeros((r, 4))
    patterns[:, 2] = [1.0, 2.0]                  # l_sin
    sin = np.full(steps + 1, 0.5)
    sin[7] = np.nan                              # the load of step 7 (times[7])
    quad = np.zeros((r, r, r))
    quad[1, 1, 1] = 1e-3

    def run():
        return kernel.reduced_ffr_newmark(1e-2, 0.25, 0.5, omega2, zero, zero, zero, quad,
                                          patterns, np.zeros(steps + 1), np.zeros(steps + 1),
                                          sin, np.zeros(steps + 1), 1e-10, 10)
    with pytest.raises(SolverError, match="Newton did not converge at step 7"):
        run()
    sin[7] = 0.5
    out = run()
    assert np.all(np.isfinite(out["eta"])) and 1 <= out["corrections"][1:].max() <= 3


# -- the rows reuse the stepper's frame values ---------------------------------------------------
def test_rows_with_the_simulated_frame_values_are_the_same_rows():
    """RowMaps.rows given simulate's frame values (angle, rate, sin and 1 - cos of psi)
    equals the rows that evaluate the drive themselves, bit for bit, across blocks."""
    from conftest import INPUTS
    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    from ancfdrv.solvers import ffr_reduced
    from ancfdrv.solvers.static import solve_newton
    model = build_model(load_scene(INPUTS / "boom_luffing.nml", [
        "beam.nodes=7", "solver.static_method=newton", "beam.geometric_stiffness=true"]))
    reduced = ffr_reduced.reduce_ffr(model, solve_newton(model, tol=1e-12, max_iter=50), 2)
    frame: dict = {}
    out = ffr_reduced.simulate(reduced, 2.5, 1e-3, frame=frame)
    assert set(frame) == {"angle", "rate", "sin", "one_minus_cos"}
    assert np.ptp(frame["rate"]) > 0                  # the frame turns in these 2.5 s
    rows = slice(3, 2503)                             # two blocks and a part
    given = reduced.row_maps.rows(out["time"][rows], out["eta"][rows], out["velocity"][rows],
                                  {k: v[rows] for k, v in frame.items()})
    plain = reduced.row_maps.rows(out["time"][rows], out["eta"][rows], out["velocity"][rows])
    for key, value in plain.items():
        assert value.tobytes() == given[key].tobytes(), key
    model.close()
