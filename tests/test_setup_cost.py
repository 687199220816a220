"""The set-up of a run made cheaper (issue 23, the fixed cost outside the stepping and the
result file): each shortcut must give what the general way gives.

References: the kernel's constraint evaluation of every row (the reactions' constant
operand gradients), the initial acceleration solved by the integrator itself (an
integrator handed it), and the equations of motion (the residual of the initial
acceleration)."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import INPUTS
from ancfdrv import runner
from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.solvers import dynamic
from ancfdrv.system import answers

PENDULUM = ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy", "solver.dt=1e-3",
            "solver.t_end=0.05", "output.xdmf=.false."]


def _model(name: str, overrides: list[str] | None = None):
    return build_model(load_scene(INPUTS / name, overrides or []))


def _rows(model, n: int = 7, seed: int = 3):
    """Rows of perturbed coordinates, multipliers and times."""
    rng = np.random.default_rng(seed)
    e_rows = model.e0 + 1e-2 * rng.standard_normal((n, model.ndof))
    q_rows = model.expand(e_rows)
    lam_rows = rng.standard_normal((n, len(model.constraints)))
    return q_rows, lam_rows, np.linspace(0.0, 0.3, n)


def test_constant_gradients_give_the_kernels_reactions():
    """The pendulum's pin keeps two undriven coordinate constraints: their operand
    gradients are constant, and the reactions computed without the kernel's row evaluation
    are bitwise those computed with it (at states away from the reference)."""
    model = _model("hard/pendulum.nml", PENDULUM)
    try:
        rm = answers.reaction_map(model)
        constant = rm.constant_gradients()
        assert constant is not None and constant.shape == (6, len(model.constraints))
        q_rows, lam_rows, times = _rows(model)
        fast = rm.reaction_rows(q_rows, lam_rows, times)
        # the kernel's gradients at each row equal the constant ones
        kernel = rm._gradient_rows(q_rows, times)
        assert np.array_equal(kernel, np.repeat(constant[:, :, None], len(times), axis=2))
        rm._constant_gradients = None   # the kernel's path
        slow = rm.reaction_rows(q_rows, lam_rows, times)
        for name in fast:
            for a, b in zip(fast[name], slow[name]):
                assert (a is None and b is None) or np.array_equal(a, b)
        # the force balances the multipliers: the pin's force is minus Phi^T lambda's sum
        force = fast["clamp pin"][0]
        assert np.abs(force[:, :2] - lam_rows).max() == 0.0
    finally:
        model.close()


def test_state_dependent_gradients_are_evaluated():
    """A model with a distance or driven constraint (the boom's hydraulic cylinder, its
    luffing drive) is not given constant gradients: the kernel evaluates its rows."""
    model = _model("boom_luffing.nml", ["solver.t_end=0.05"])
    try:
        assert len(model.constraints)
        assert answers.reaction_map(model).constant_gradients() is None
    finally:
        model.close()


@pytest.mark.parametrize("name", ["boom_luffing.nml", "general/boom_luffing.nml"])
def test_gradient_rows_are_the_full_evaluations(name):
    """The reactions' gradients at the output rows (the kernel's constraint_gradients: no
    drive evaluated, since no gradient depends on one) are, row by row, those of the full
    evaluation with the drives (constraint_evaluate): the boom's coordinate, distance and
    cross constraints with its luffing drive, the general boom's coordinate and dot ones."""
    model = _model(name, ["solver.t_end=0.05"])
    try:
        rm = answers.reaction_map(model)
        kinds = set(rm.full.kinds)
        assert kinds == ({1, 2, 3} if name == "boom_luffing.nml" else {1, 4})
        assert any(d >= 0 for d in rm.full.drives)   # a driven constraint among them
        q_rows, _, times = _rows(model, n=9)
        rows = rm._gradient_rows(q_rows, times)
        assert rows.shape == (6, len(rm.full), len(times))
        for r, t in enumerate(times):
            assert np.array_equal(rows[:, :, r], rm.full.evaluate(q_rows[r], float(t))[1])
        # a distance constraint's gradient is 2 (x1 - x2), -2 (x1 - x2) at its operands
        distance = np.flatnonzero(np.array(rm.full.kinds) == 2)
        assert len(distance) == (1 if name == "boom_luffing.nml" else 0)
        for c in distance:
            x = np.array([rm.full.operand_const[c][s] + sum(a * q_rows[0][d]
                                                            for d, a in rm.full.terms[c][s])
                          for s in range(6)])
            assert rows[:3, c, 0] == pytest.approx(2 * (x[:3] - x[3:]), rel=1e-12)
            assert rows[3:, c, 0] == pytest.approx(-2 * (x[:3] - x[3:]), rel=1e-12)
    finally:
        model.close()


def test_handed_initial_acceleration_gives_the_same_run(tmp_path, monkeypatch):
    """A run whose answers recorder needs the accelerations (the boom's eliminated joints)
    solves the initial acceleration once, and integrate handed it steps exactly as
    integrate solving it itself."""
    calls = []
    real = dynamic.initial_acceleration

    def counted(*args):
        calls.append(args[3])
        return real(*args)
    monkeypatch.setattr(dynamic, "initial_acceleration", counted)
    scene = load_scene(INPUTS / "boom_luffing.nml", ["solver.t_end=0.02",
                                                      "output.xdmf=.false."])
    out = tmp_path / "boom.h5"
    runner.run_loaded(scene, out, progress=False)
    assert calls == [0.0]   # once: the recorder's, handed to integrate
    model = build_model(scene)
    try:
        settings = runner.dynamic_settings(scene)
        e0 = model.e0
        static = runner.solve_static_path(model, scene["solver"]["static_method"],
                                          tol=scene["solver"]["tol"],
                                          max_iter=scene["solver"]["max_iter"],
                                          p=scene["solver"]["split_p"],
                                          load_steps=scene["solver"]["load_steps"]) \
            if scene["scene"]["analysis"] == "static+dynamic" else None
        if static is not None:
            e0 = static.e
        chunks = {}

        def sink(name):
            def keep(chunk):
                chunks.setdefault(name, []).append(chunk.q.copy())
            return keep
        settings.store_q = True
        a0 = real(model, e0, np.zeros(model.ndof), 0.0)
        dynamic.integrate(model, settings, e0, sink=sink("handed"), initial=a0,
                          progress=False)
        dynamic.integrate(model, settings, e0, sink=sink("solved"), progress=False)
        assert np.array_equal(np.concatenate(chunks["handed"]),
                              np.concatenate(chunks["solved"]))
    finally:
        model.close()


# -- the scene text (io/scene.py namelist_text) -----------------------------------------------
def _f90nml_text(nml) -> str:
    import io
    buffer = io.StringIO()
    nml.write(buffer)
    return buffer.getvalue()


def test_plain_text_is_what_f90nml_writes():
    """Every shipped scene, read both ways, is written byte for byte as f90nml's writer
    writes it (where the direct writer applies: all but namelists it leaves to f90nml)."""
    import f90nml
    from ancfdrv.io import scene as scene_io
    files = sorted(INPUTS.rglob("*.nml"))
    assert len(files) >= 20
    direct = 0
    for path in files:
        text = path.read_text(encoding="utf-8")
        for nml in (scene_io.fast_reads(text), f90nml.reads(text)):
            if nml is None:
                continue
            mine = scene_io._plain_text(nml)
            direct += mine is not None
            assert scene_io.namelist_text(nml) == _f90nml_text(nml), path
            assert mine is None or mine == _f90nml_text(nml), path
    assert direct >= len(files)


@pytest.mark.parametrize("values", [
    {"a": 1.5e-300, "b": -0.0, "c": float("inf"), "d": 7, "e": True, "f": False},
    {"s": "it's \"quoted\" ! / & = , text", "t": "", "u": "trailing  "},
    {"short": [1.0, 2.5, 3], "flags": [True, False], "names": ["a", "b'c"]},
    {"long": [float(i) / 7 for i in range(40)]},           # wrapped by f90nml
    {"x": 1e22, "y": 123456789012345678901234567890, "z": 2.0 ** -1074},
    {"w" * 70: "a header past the column width"},
])
def test_plain_text_of_values(values):
    """Values of every plain kind (and a list f90nml wraps over lines, which the direct
    writer leaves to it) give f90nml's text."""
    import f90nml
    from ancfdrv.io.scene import namelist_text
    nml = f90nml.Namelist({"group": f90nml.Namelist(values), "other": f90nml.Namelist({"k": 1})})
    assert namelist_text(nml) == _f90nml_text(nml)


@pytest.mark.parametrize("scene,overrides", [
    ("hard/pendulum.nml", PENDULUM + ["scene.title='it''s a pendulum'",
                                      "scene.effects='gravity'"]),
    ("boom_luffing.nml", ["beam.segments=1.791,3.0,3.0", "output.q=.true."]),
    ("general/spinup.nml", ["solver.t_end=0.5"]),
    ("general/leaf_spring.nml", []),
])
def test_scene_text_unchanged(scene, overrides, monkeypatch):
    """A loaded scene's text (what the result file keeps) is the text f90nml's writer
    gives the same namelist, with overrides and repeated groups."""
    from ancfdrv.io import scene as scene_io
    fast = load_scene(INPUTS / scene, overrides)
    monkeypatch.setattr(scene_io, "_plain_text", lambda nml: None)
    assert load_scene(INPUTS / scene, overrides).text == fast.text


def test_repeated_group_still_found_without_the_scan(tmp_path, monkeypatch):
    """A plain scene is not scanned for repeated keys (its reader refuses them), but a
    group given twice is still refused with both lines, and a plain scene without repeats
    is loaded without the scan."""
    from ancfdrv.errors import InputError
    from ancfdrv.io import validate
    scans = []
    real = validate.scan_groups
    monkeypatch.setattr(validate, "scan_groups", lambda text: scans.append(1) or real(text))
    load_scene(INPUTS / "hard/pendulum.nml", PENDULUM)
    assert scans == []
    text = (INPUTS / "hard/pendulum.nml").read_text() + "&beam nodes = 4 /\n"
    path = tmp_path / "twice.nml"
    path.write_text(text)
    with pytest.raises(InputError, match=r"group given twice \(lines \d+ and \d+\)") as err:
        load_scene(path)
    assert err.value.group == "beam" and scans == [1]


# -- the constraint set's kernel arguments (system/constraint_set.py) ------------------------
def _copy_of(cs):
    """A new set with the same lists (no cached arguments)."""
    from ancfdrv.system.constraint_set import ConstraintSet
    import copy
    return ConstraintSet(kinds=list(cs.kinds), drives=list(cs.drives),
                         params=copy.deepcopy(cs.params),
                         operand_const=copy.deepcopy(cs.operand_const),
                         terms=copy.deepcopy(cs.terms), names=list(cs.names),
                         drive_kinds=list(cs.drive_kinds),
                         drive_params=copy.deepcopy(cs.drive_params))


def _same_evaluation(a, b, e, t):
    return all(np.array_equal(x, y) for x, y in zip(a.evaluate(e, t, e), b.evaluate(e, t, e)))


def test_constraint_arguments_follow_every_change():
    """The kernel arguments a constraint set keeps between evaluations are made again
    after any change of its lists (a constraint added, a parameter, an operand's term or
    constant, a drive's parameters changed in place): every evaluation equals that of a
    new set holding the same lists."""
    from ancfdrv.codes import CONSTRAINT_COORDINATE
    model = _model("boom_luffing.nml", ["solver.t_end=0.05"])
    try:
        cs = model.constraints
        e = model.e0 * (1 + 1e-3)
        t = 0.7
        assert _same_evaluation(cs, _copy_of(cs), e, t)
        first = cs._kernel_inputs()
        assert cs._kernel_inputs() is first          # unchanged: kept
        cs.params[0][0] += 0.25
        assert _same_evaluation(cs, _copy_of(cs), e, t)
        d, a = cs.terms[0][0][0]
        cs.terms[0][0][0] = (d, 2 * a)
        assert _same_evaluation(cs, _copy_of(cs), e, t)
        cs.operand_const[-1][0] -= 0.5
        assert _same_evaluation(cs, _copy_of(cs), e, t)
        driven = [c for c in range(len(cs)) if cs.drives[c] >= 0]
        assert driven, "the boom's luffing drive"
        params = cs.drive_params[cs.drives[driven[0]]]
        params[0] = float(params[0]) + 0.1
        assert _same_evaluation(cs, _copy_of(cs), e, t)
        cs.add(CONSTRAINT_COORDINATE, [({1: 1.0}, 0.0)], [0.5], -1, "added")
        values, *_ = cs.evaluate(e, t)
        assert len(values) == len(cs) and values[-1] == e[1] - 0.5
        assert _same_evaluation(cs, _copy_of(cs), e, t)
        arrays = [a for a in cs._kernel_inputs() if isinstance(a, np.ndarray)]
        assert len(arrays) == 2 and not any(a.flags.writeable for a in arrays)
    finally:
        model.close()


def _watch_reference(first, energy, times, tolerance):
    """The energy watch's figures written out row by row: the largest balance, the scale
    (the largest flow less the energy made by then, per row) and the first time the
    balance exceeded tolerance x scale."""
    works = energy[:, [5, 6, 8, 9, 10]]
    balance = energy[:, 4] - first[4] - works.sum(axis=1)
    potential = energy[:, 1:4].sum(axis=1) - first[1:4].sum()
    most = scale = 0.0
    for k in range(len(balance)):
        flow = max(abs(energy[k, 0]), abs(potential[k]), abs(energy[k, 0] + energy[k, 1]),
                   *np.abs(works[k]))
        scale = max(scale, flow - max(balance[k], 0.0))
        most = max(most, balance[k])
    above = np.flatnonzero(balance > tolerance * scale)
    return most, scale, (times[above[0]] if len(above) else None), balance


def test_energy_watch_sums_as_numpy_does():
    """The energy watch's figures (the largest balance, the energy scale less the energy
    made, the time the balance first exceeded the tolerance) are those of a row-by-row
    reference, for chunks of every size the stepper hands it; its column sums are numpy's
    row sums bitwise."""
    rng = np.random.default_rng(5)
    for rows in (1, 2, 7, 16, 17, 990, 1001):
        energy = rng.standard_normal((rows, 11)) * np.exp(rng.uniform(-5, 5, (rows, 11)))
        times = np.arange(1, rows + 1) * 1e-3
        works = energy[:, [5, 6, 8, 9, 10]]
        columns = energy.T
        assert np.array_equal(works.sum(axis=1), columns[5] + columns[6] + columns[8]
                              + columns[9] + columns[10])
        assert np.array_equal(energy[:, 1:4].sum(axis=1), columns[1] + columns[2] + columns[3])
        first = energy[0]
        watch = dynamic.EnergyWatch(first, tolerance=0.01)
        watch.add(energy, times)
        most, scale, onset, balance = _watch_reference(first, energy, times, 0.01)
        assert watch.most == max(0.0, most)
        assert watch.scale == scale
        assert watch.unstable() == (max(0.0, most) > 0.01 * scale)
        if onset is not None:   # the records keep each rise of 1 %: the time within it
            found = watch.first_above(0.01 * scale)
            assert onset <= found
            before = balance[times < found]
            assert not len(before) or before.max() <= 0.01 * scale * watch.RECORD_STEP


def test_energy_watch_at_rest_and_blown_up():
    """A run at rest (every energy round-off, 1e-26 J) is never unstable: the scale has
    the integrator's floor. A run whose kinetic energy is mostly made energy is measured
    against the flow less the energy made: 25 kJ made on a 70 J pendulum reads 357 times
    the scale (the old measure, against the kinetic energy itself, read 1.0)."""
    rest = np.zeros((50, 11))
    rest[:, 0] = np.linspace(0.0, 2e-26, 50)
    rest[:, 4] = rest[:, 0]
    watch = dynamic.EnergyWatch(rest[0], tolerance=0.01, floor=1e-13)
    watch.add(rest, np.arange(50) * 1e-3)
    assert not watch.unstable() and watch.created() < 1e-12
    blown = np.zeros((3, 11))
    blown[:, 0] = [0.0, 70.0, 25070.0]       # kinetic: 70 J of physics, then 25 kJ made
    blown[:, 2] = [0.0, -70.0, -70.0]        # gravity
    blown[:, 4] = blown[:, 0] + blown[:, 2]  # total
    watch = dynamic.EnergyWatch(blown[0], tolerance=0.01)
    watch.add(blown, np.array([0.0, 1.0, 2.0]))
    assert watch.scale == 70.0 and watch.created() == pytest.approx(25000.0 / 70.0)
    assert watch.unstable() and watch.runaway()
    assert watch.first_above(0.01 * 70.0) == 2.0


# -- the planar reduction's plan (system/patterns.py) -----------------------------------------
@pytest.mark.parametrize("scene,overrides", [
    ("hard/pendulum.nml", PENDULUM),
    ("hard/pendulum.nml", ["beam.nodes=9", "scene.planar=xy"]),
    ("boom_luffing.nml", ["scene.formulation=nonlinear", "solver.static_method=newton",
                          "beam.bending=cable", "beam.nodes=4", "scene.planar=xy"]),
    ("boom_luffing.nml", ["scene.formulation=nonlinear", "solver.static_method=newton",
                          "beam.nodes=4", "scene.planar=xy"]),
    ("hard/spinup.nml", ["scene.planar=xy"]),
])
def test_selection_plan_is_the_general_plan(scene, overrides, monkeypatch):
    """A reduction that only fixes coordinates (the planar fixes) gets from the direct
    construction exactly the arrays of the general one (B, q0, the coordinates kept, the
    reduced pattern, the plan of B^T S B), and the model built with it is the same."""
    from ancfdrv.system import assembly, patterns
    seen = []
    real = patterns.reduction_plan

    def spy(*args):
        seen.append(args)
        return real(*args)
    monkeypatch.setattr(assembly, "reduction_plan", spy)
    model = _model(scene, overrides)
    model.close()
    assert seen
    for args in seen:
        nfull, elimination, q0, full_pattern = args
        if any(r.terms for r in elimination.relations.values()):
            continue   # eliminated joints: the general plan
        fast = patterns._selection_plan(*args)
        general = patterns._general_plan(*args)
        for name in ("offset", "independent", "plan_source", "plan_target", "plan_coef"):
            a, b = getattr(fast, name), getattr(general, name)
            assert a.dtype == b.dtype and np.array_equal(a, b), name
        for name in ("data", "indices", "indptr"):
            a, b = getattr(fast.matrix, name), getattr(general.matrix, name)
            assert a.dtype == b.dtype and np.array_equal(a, b), name
        assert fast.matrix.shape == general.matrix.shape
        assert fast.pattern.n == general.pattern.n
        assert np.array_equal(fast.pattern.row_ptr, general.pattern.row_ptr)
        assert np.array_equal(fast.pattern.col_index, general.pattern.col_index)
        break
    else:
        pytest.fail("no planar reduction without eliminated joints")


def test_selection_plan_refuses_a_missed_configuration():
    """A fixed coordinate whose constant misses the initial configuration is refused as by
    the general construction."""
    from ancfdrv.system.expressions import Scalar
    from ancfdrv.system.patterns import Elimination, Pattern, reduction_plan
    q0 = np.array([0.0, 1.0, 2.0, 3.0])
    pattern = Pattern.from_blocks(4, [np.arange(4)])
    ok = reduction_plan(4, Elimination({1: Scalar({}, 1.0)}, []), q0, pattern)
    assert np.array_equal(ok.independent, [0, 2, 3])
    assert np.array_equal(ok.expand(np.array([5.0, 6.0, 7.0])), [5.0, 1.0, 6.0, 7.0])
    with pytest.raises(AssertionError, match="misses the initial configuration"):
        reduction_plan(4, Elimination({1: Scalar({}, 1.5)}, []), q0, pattern)


def test_selection_expand_is_the_product():
    """Expanding through a selecting reduction gives B x + q0 as the sparse product forms
    it, bitwise (a -0.0 turned 0.0, NaN kept), for one row and for rows, with and without
    the offset; a wrong width is refused."""
    from dataclasses import replace
    model = _model("hard/pendulum.nml", PENDULUM)
    try:
        fast = model.reduction
        assert fast.selects is not None
        general = replace(fast, selects=None)
        rng = np.random.default_rng(9)
        rows = rng.standard_normal((37, model.ndof))
        rows[0, :3] = [-0.0, np.nan, np.inf]
        for x in (rows, rows[5], rows[:, :][::2], np.asfortranarray(rows)):
            for offset in (True, False):
                a, b = fast.expand(x, offset), general.expand(x, offset)
                assert a.shape == b.shape and a.dtype == b.dtype
                assert np.array_equal(a, b, equal_nan=True)
                assert np.array_equal(np.signbit(a), np.signbit(b))
        with pytest.raises(ValueError, match="dimension mismatch"):
            fast.expand(rows[:, 1:])
        # the carried-matrix vectors take the selection as the general check finds it
        assert model.reduction.matrix.selection_columns() is not None
        assert model.carry_vectors() is not None
    finally:
        model.close()


def test_gradients_of_an_evaluation_with_velocities():
    """Phi_e from an evaluation that had the velocities (the initial acceleration's) is
    Phi_e of an evaluation without them (the operand gradients do not depend on e')."""
    model = _model("boom_luffing.nml", ["solver.t_end=0.05"])
    try:
        cs, e = model.constraints, model.e0 * (1 + 1e-3)
        v = np.linspace(-1.0, 1.0, model.ndof)
        with_v = cs.gradient_rows(e, model.ndof, 0.3, cs.evaluate(e, 0.3, v))
        assert np.array_equal(with_v, cs.gradient_rows(e, model.ndof, 0.3))
    finally:
        model.close()


@pytest.mark.parametrize("scene,overrides", [
    ("hard/pendulum.nml", ["beam.nodes=17", "beam.bending=cable", "scene.planar=xy"]),
    ("hard/spinup.nml", ["scene.planar=xy"]),
    ("boom_luffing.nml", ["scene.formulation=nonlinear", "solver.static_method=newton",
                          "scene.planar=xy", "solver.linear_joints='eliminate'"]),
])
def test_single_term_elimination_is_the_general_one(scene, overrides, monkeypatch):
    """The planar fixes (one coordinate each) eliminated directly give the relations the
    general substitution gives (the same equations with a zero term added, which the
    substitution drops, take the general way): keys, terms and constants bitwise."""
    import copy
    from ancfdrv.system import assembly, patterns
    seen = []
    real = patterns.eliminate

    def spy(equations, q0):
        seen.append((copy.deepcopy(equations), q0.copy()))
        return real(equations, q0)
    monkeypatch.setattr(assembly, "eliminate", spy)
    _model(scene, overrides).close()
    assert seen
    for equations, q0 in seen:
        singles = [eq for eq in equations if len(eq.expr.terms) == 1]
        assert singles, "planar fixes"
        general = copy.deepcopy(equations)
        spare = len(q0) - 1
        for eq in general:
            eq.expr.terms = {**eq.expr.terms, spare: 0.0} if spare not in eq.expr.terms \
                else {**eq.expr.terms, 0: 0.0}
        fast, slow = real(equations, q0), real(general, q0)
        assert fast.redundant == slow.redundant
        assert list(fast.relations) == list(slow.relations)
        for dof, relation in fast.relations.items():
            other = slow.relations[dof]
            assert relation.terms == other.terms
            assert np.array_equal(np.float64(relation.const), np.float64(other.const))
            assert np.signbit(relation.const) == np.signbit(other.const)


def test_energy_watch_waiting_chunks_measure_as_each_alone(monkeypatch):
    """Chunks measured together after waiting (EnergyWatch.WAIT_ROWS) give the largest
    balance, the scale and the records of measuring each chunk on arrival (WAIT_ROWS = 1),
    NaN rows and signed zeros included, whatever the chunks' sizes."""
    rng = np.random.default_rng(9)
    for trial in range(200):
        sizes = rng.integers(1, 40, int(rng.integers(1, 12)))
        chunks = [rng.standard_normal((int(n), 11)) * np.exp(rng.uniform(-20, 20, (int(n), 11)))
                  for n in sizes]
        for c in chunks:
            c[rng.random(c.shape) < 0.05] = -0.0
            if trial % 7 == 0:
                c[rng.random(c.shape) < 0.02] = np.nan
        first = chunks[0][0].copy()
        starts = np.concatenate([[0], np.cumsum(sizes)])
        watches = []
        for wait in (1, int(rng.integers(2, 100))):
            monkeypatch.setattr(dynamic.EnergyWatch, "WAIT_ROWS", wait)
            watch = dynamic.EnergyWatch(first)
            for k, c in enumerate(chunks):
                watch.add(c, np.arange(starts[k], starts[k + 1]) * 1e-3)
            watches.append(watch)
        alone, together = watches
        assert (together.most, together.scale, together.created()) == \
            (alone.most, alone.scale, alone.created())
        for level in (0.0, 1.0, 1e3):
            assert together.first_above(level) == alone.first_above(level)