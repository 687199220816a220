"""The dynamic answers' kernel part (fortran/src/solvers/row_answers.f90): the stepper writes
each row's force-element reactions and the residual at the eliminated joints' coordinates
from the state it reached, so the answers do not depend on how the run is cut into kernel
calls (the knuckle crane: eliminated joints and a rope), and the recorder refuses chunks
without them."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv import runner
from ancfdrv.system import answers

ROOT = Path(__file__).resolve().parents[1]


def _answers(path: Path) -> dict[str, np.ndarray]:
    out = {}
    with h5py.File(path, "r") as h5:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and name.startswith(
                    ("dynamic/reactions", "dynamic/sections", "dynamic/stress")):
                out[name] = obj[()]
        h5.visititems(visit)
    return out


def test_kernel_calls_of_any_length_give_the_same_answers(tmp_path):
    """One row per kernel call (output.chunk_steps = 1) against the default calls: the same
    reactions, section forces and stresses within 1e-12 of each series' magnitude (the
    matrix products over one row or many may round differently: BLAS gemv against gemm)."""
    scene = ROOT / "inputs/knuckle_crane_rope.nml"
    runner.run_scene(scene, ["solver.t_end=0.05"], tmp_path / "whole.h5", progress=False)
    runner.run_scene(scene, ["solver.t_end=0.05", "output.chunk_steps=1"],
                     tmp_path / "rows.h5", progress=False)
    whole, rows = _answers(tmp_path / "whole.h5"), _answers(tmp_path / "rows.h5")
    assert any(k.startswith("dynamic/reactions") for k in whole) and set(whole) == set(rows)
    worst = 0.0
    for name, values in whole.items():
        assert np.all(np.isfinite(values)), name
        scale = float(np.max(np.abs(values)))
        diff = float(np.max(np.abs(values - rows[name])))
        worst = max(worst, diff / scale if scale > 0 else diff)
    assert worst <= 1e-12


def test_the_recorder_refuses_rows_without_their_answers():
    """A model with an eliminated joint needs the rows' answers (DynamicSettings.answers):
    a chunk without them is refused with words that say so."""
    from types import SimpleNamespace
    from ancfdrv import System
    s = System("pendulum")
    s.rigid_body("bob", mass=2.0, inertia=(0.01, 0.01, 0.02, 0, 0, 0), position=(0.5, 0, 0),
                 planar=True, plane_normal=(0, 0, 1))
    s.joint("hinge", "revolute", "ground", "bob", point=(0, 0, 0), axis=(0, 0, 1))
    model = s.assemble()
    try:
        recorder = answers.DynamicAnswers(model)
        assert recorder.needs_answers
        chunk = SimpleNamespace(time=np.zeros(1), q=model.e0[None],
                                lam=np.zeros((1, len(model.constraints))), answers=None)
        with pytest.raises(ValueError, match="needs the rows' answers"):
            recorder(chunk)
    finally:
        model.close()


def test_recording_the_answers_leaves_the_motion_alone(tmp_path):
    """The answers are written by the stepper from the states it reaches: a run that records
    them (a contact scene with joints) has the motion of one that does not, bit for bit
    (the same computation; the recorder once solved the start's consistent acceleration
    again, which moved the contact projections the run started from)."""
    scene = ROOT / "inputs/leaf_spring_road.nml"
    common = ["solver.t_end=0.01", "output.q=.true.", "output.xdmf=.false."]
    runner.run_scene(scene, common, tmp_path / "with.h5", progress=False)
    runner.run_scene(scene, common + ["output.answers=.false."], tmp_path / "without.h5",
                     progress=False)
    with h5py.File(tmp_path / "with.h5", "r") as a, h5py.File(tmp_path / "without.h5", "r") as b:
        assert "dynamic/reactions" in a and "dynamic/reactions" not in b
        for name in ("dynamic/q", "dynamic/lambda", "dynamic/contact/normal_force"):
            assert np.array_equal(a[name][()], b[name][()]), name


def test_the_residual_at_a_few_columns_is_that_of_every_element():
    """The rows' residual at the eliminated joints' coordinates is evaluated from the
    elements that touch them alone (mechanical_system column_forces): at those coordinates
    it is the residual the kernel forms when every full coordinate is asked for (every
    element of both leaves evaluated), bit for bit, at a state off the assembled one with
    rates and accelerations (the two-leaf spring: plates, contact, rigid bodies)."""
    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    from ancfdrv.runner import dynamic_settings

    scene = load_scene(ROOT / "inputs/leaf_spring.nml", [])
    model = build_model(scene)
    try:
        model.kernel.stepper_setup(dynamic_settings(scene))
        few = answers.answer_inputs(model)[0]
        every = np.arange(model.nfull)
        assert 0 < len(few) < model.nfull // 4
        constant = np.asarray(model.full_loads[0], dtype=float)
        mass = model.mass_full.to_scipy().tocsr()
        rng = np.random.default_rng(7)
        e = model.e0 + 1e-4 * rng.standard_normal(model.ndof)
        v = 1e-2 * rng.standard_normal(model.ndof)
        accel = rng.standard_normal(model.ndof)

        def residual(columns):
            model.kernel.answer_setup(columns, mass[columns], constant[columns],
                                      np.zeros((len(columns), 0)))
            return model.kernel.answer_row(0.1, e, v, accel, model.contact_guesses.copy())

        at_few, at_every = residual(few), residual(every)
        assert np.abs(at_every[few]).max() > 0.0
        assert np.array_equal(at_few, at_every[few])
    finally:
        model.close()
