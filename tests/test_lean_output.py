"""Lean per-step output and the stepper's packed state (issues 23 item 4, 25): what got
cheaper must give bitwise the same numbers as the straightforward computation it replaces.

References: the plain computations themselves (``beam_stress(...).von_mises``, a writer that
writes every chunk on its own, the stepper fed a plain dict that is packed per call), so
every comparison is exact (array bytes equal), and a run split into kernel calls differently
(the stepper's state is the same state whichever way it is carried)."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from ancfdrv import Box, Circle, Rectangle, System, Tube
from ancfdrv.results.hdf5 import DynamicWriter
from ancfdrv.solvers.dynamic import (DynamicSettings, TimeIntegrator, initial_acceleration,
                                     initial_row)
from ancfdrv.system import answers
from ancfdrv.system.answers import SectionForces, beam_stress, von_mises_peak



def cantilever() -> System:
    """A large-deformation (refactorized) cantilever under its own weight (test_stepper's)."""
    s = System("cantilever")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(2.0, 0, 0), nodes=5,
           section=Rectangle(0.05, 0.1), height_axis=(0, 1, 0), formulation="nonlinear",
           bending="cubic")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -9.81, 0))
    s.probe("end", "arm", (2.0, 0, 0))
    return s


@pytest.mark.parametrize("section", [Rectangle(0.05, 0.1), Box(0.2, 0.3, 0.01),
                                     Tube(0.1, 0.01), Circle(0.05)],
                         ids=["rectangle", "box", "tube", "circle"])
def test_von_mises_peak_is_beam_stress_bitwise(section, monkeypatch):
    """The envelope's peak (square root after the maximum, in row blocks) equals
    beam_stress's von Mises stress bit for bit, also when the rows are cut into blocks
    of a few rows (a small STRESS_BLOCK) and for a single state without a time axis."""
    rng = np.random.default_rng(7)
    nt, ns = 37, 9
    forces = SectionForces(s=np.linspace(0, 1, ns), N=rng.normal(size=(nt, ns)) * 1e4,
                           T=rng.normal(size=(nt, ns)) * 1e2, Q=rng.normal(size=(nt, ns, 2)) * 1e3,
                           M=rng.normal(size=(nt, ns, 2)) * 1e3)
    plain = beam_stress(section, forces).von_mises
    assert von_mises_peak(section, forces).tobytes() == plain.tobytes()
    monkeypatch.setattr(answers, "STRESS_BLOCK", 100)    # blocks of a few rows, one ragged
    assert von_mises_peak(section, forces).tobytes() == plain.tobytes()
    one = SectionForces(s=forces.s, N=forces.N[3], T=forces.T[3], Q=forces.Q[3], M=forces.M[3])
    assert von_mises_peak(section, one).tobytes() == plain[3].tobytes()


def _chunks(model, settings, sizes):
    integrator = TimeIntegrator(model, settings)
    v0 = np.zeros(model.ndof)
    a0, lam0 = initial_acceleration(model, model.e0, v0, 0.0)
    state = integrator.state(0.0, model.e0, v0, a0, lam0)
    out = [initial_row(model, state)]
    for n in sizes:
        chunk, info, _ = integrator.advance(state, n)
        assert info == 0
        out.append(chunk)
    return out


def test_merged_writes_give_the_same_file(tmp_path):
    """Chunks written together (one write per series for several chunks) give the file
    that writing every chunk on its own gives: every dataset bitwise equal, also the step
    sizes the writer derives from the rows' times across the chunks' seams."""
    model = cantilever().assemble()
    try:
        settings = DynamicSettings(dt=1e-3, t_end=0.02, store_q=True)
        chunks = _chunks(model, settings, [5, 1, 7, 7])
        files = {}
        for name, flush_rows in (("each", 1), ("merged", 10**6)):
            path = tmp_path / f"{name}.h5"
            with h5py.File(path, "w"):
                pass
            writer = DynamicWriter(path, model, True, flush_rows, xdmf=False)
            for chunk in chunks:
                writer(chunk)
            writer.flush()
            files[name] = path
        with h5py.File(files["each"]) as a, h5py.File(files["merged"]) as b:
            names = []
            a["dynamic"].visititems(lambda n, o: names.append(n)
                                    if isinstance(o, h5py.Dataset) else None)
            assert "step_size" in names and "q" in names and len(names) > 15
            for n in names:
                x, y = a["dynamic"][n][()], b["dynamic"][n][()]
                assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes(), n
            assert len(a["dynamic/time"]) == 21
            np.testing.assert_allclose(a["dynamic/step_size"][1:], 1e-3, rtol=1e-9)
            assert a["dynamic/step_size"][0] == 0.0
    finally:
        model.close()


def test_packed_state_steps_as_a_plain_dict():
    """The packed state the kernel steps in place and a plain dict packed and unpacked per
    call give bitwise the same history, the same final state and the same counters; the
    packed state's arrays are views of one buffer (nothing copied per call), and
    assigning a key copies into it."""
    model = cantilever().assemble()
    try:
        settings = DynamicSettings(dt=1e-3, t_end=0.02, store_q=True)
        integrator = TimeIntegrator(model, settings)
        v0 = np.zeros(model.ndof)
        a0, lam0 = initial_acceleration(model, model.e0, v0, 0.0)
        results = []
        for plain in (False, True):
            state = integrator.state(0.0, model.e0, v0, a0, lam0)
            if plain:
                state = {k: (v.copy() if isinstance(v, np.ndarray) else v)
                         for k, v in state.items()}
            else:
                e_view = state["e"]
                assert np.shares_memory(e_view, state.packed)
            qs = [integrator.advance(state, 1)[0].q for _ in range(12)]
            if not plain:
                assert state["e"] is e_view and np.shares_memory(state["accel"], state.packed)
                before = state["e"].copy()
                state["e"] = before + 1.0
                assert state["e"] is e_view and np.array_equal(e_view, before + 1.0)
                state["e"] = before
            results.append((np.concatenate(qs), state["e"].copy(), state["lam"].copy(),
                            state["accel"].copy(), state["t"]))
        for a, b in zip(*results):
            assert np.asarray(a).tobytes() == np.asarray(b).tobytes()
        assert results[0][4] == pytest.approx(0.012, abs=1e-15)
    finally:
        model.close()
