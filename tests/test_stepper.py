"""The stepper apart from the system (issue 25 item 2): its settings go to the kernel once
per run (``system_stepper_setup``), its learned state (contraction estimate, reuse back-off,
predictor) lives beside the system in ``fortran/src/solvers/stepper.f90``, and
``system_advance`` takes a packed state and returns packed rows with the failure's text
(issue 25 item 5). The Python default of the Jacobian policy is the CLI's (issue 22).

References: the scene schema's defaults (what ``ancf run`` and ``System.simulate`` use,
tests/test_results_api.py shows the two agree); invariance of a run under how it is split
into kernel calls; the kernel's documented failure texts."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import Rectangle, System
from ancfdrv.errors import SolverError
from ancfdrv.io.schema import SCHEMA
from ancfdrv.solvers.dynamic import (DynamicSettings, TimeIntegrator, initial_acceleration,
                                     integrate)

E, RHO, L, W, H, G = 2.1e11, 7850.0, 2.0, 0.05, 0.1, 9.81


def cantilever() -> System:
    """A large-deformation (refactorized) cantilever under its own weight."""
    s = System("cantilever")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(L, 0, 0), nodes=5,
           section=Rectangle(W, H), height_axis=(0, 1, 0), formulation="nonlinear",
           bending="cubic")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -G, 0))
    s.probe("end", "arm", (L, 0, 0))
    return s


def test_python_defaults_are_the_cli_defaults():
    """DynamicSettings defaults to the scene schema's solver defaults (jacobian 'reuse', not
    'step'), so integrate() without options steps exactly as System.simulate and ancf run:
    the same history bit for bit and the same factorizations (with 'step' this model
    factorizes at every step: 20, against reuse's few)."""
    solver = SCHEMA["solver"]
    settings = DynamicSettings(dt=1e-3, t_end=0.02)
    assert settings.jacobian == solver["jacobian"].default == "reuse"
    assert settings.contraction == solver["contraction"].default
    assert (settings.tol, settings.max_newton, settings.beta, settings.gamma) == \
        (solver["newton_tol"].default, solver["max_newton"].default, solver["beta"].default,
         solver["gamma"].default)

    system = cantilever()
    res = system.simulate(t_end=0.02, xdmf=False)
    model = system.assemble()
    rows = []
    try:
        run = integrate(model, settings, model.e0, sink=rows.append)
    finally:
        model.close()
    probes = np.concatenate([c.probes for c in rows])[:, 0, :]
    np.testing.assert_array_equal(probes, res.probes["end"])
    assert run.factorizations == res.dynamic.attrs["factorizations"] < 20


def test_a_run_split_into_calls_is_the_same_run():
    """The packed state round-trips exactly: 20 steps in one kernel call, in calls of 7
    and in single steps give bitwise the same coordinates, multipliers and statistics (the
    learned state stays in the kernel between calls)."""
    model = cantilever().assemble()
    try:
        settings = DynamicSettings(dt=1e-3, t_end=0.02, store_q=True)
        integrator = TimeIntegrator(model, settings)
        v0 = np.zeros(model.ndof)
        a0, lam0 = initial_acceleration(model, model.e0, v0, 0.0)
        histories = []
        for sizes in ([20], [7, 7, 6], [1] * 20):
            state = integrator.state(0.0, model.e0, v0, a0, lam0)
            chunks = [integrator.advance(state, n) for n in sizes]
            assert all(info == 0 for _, info, _ in chunks)
            histories.append((np.concatenate([c.q for c, _, _ in chunks]),
                              np.concatenate([c.lam for c, _, _ in chunks]),
                              np.concatenate([c.stats for c, _, _ in chunks]), state["t"]))
        for other in histories[1:]:
            for a, b in zip(histories[0], other):
                np.testing.assert_array_equal(a, b)
        assert histories[0][0].shape == (20, model.ndof)
        assert histories[0][3] == pytest.approx(0.02, abs=1e-15)
    finally:
        model.close()


def test_advance_errors_carry_the_kernels_text():
    """system_advance returns info and a text: a run not set up, a state of the wrong size
    and a stale handle are named as what they are; a Newton failure is described by the
    kernel with the run's iteration limit (max_newton = 1 here: the first correction of the
    cantilever's first step, ~5e-6 m of sag, cannot meet 1e-10 m)."""
    model = cantilever().assemble()
    kernel = model.kernel
    v0 = np.zeros(model.ndof)
    a0, lam0 = initial_acceleration(model, model.e0, v0, 0.0)
    state = dict(t=0.0, e=model.e0.copy(), v=v0.copy(), a=a0.copy(), accel=a0.copy(),
                 lam=lam0.copy(), work=np.zeros(5), powers=np.zeros(5),
                 guesses=model.contact_guesses.copy(), counts=np.zeros(6, dtype=np.int32))
    try:
        with pytest.raises(SolverError, match="no run set up .call system_stepper_setup"):
            kernel.advance(1, dict(state), False)
        with pytest.raises(SolverError, match="stepper_setup.*code 2: system_stepper_setup: "
                                              "a setting out of its range"):
            kernel.stepper_setup(DynamicSettings(dt=1e-3, t_end=1.0, contraction=1.5))
        settings = DynamicSettings(dt=1e-3, t_end=1.0, max_newton=1, dt_min=1e-3)  # no cut
        integrator = TimeIntegrator(model, settings)
        run = integrator.state(0.0, model.e0, v0, a0, lam0)
        kernel.ndof += 3    # the caller's bug: a state of another system's size
        wrong = {k: np.zeros(model.ndof + 3) if k in ("e", "v", "a", "accel") else v
                 for k, v in run.items()}
        with pytest.raises(SolverError, match="system_advance: sizes inconsistent"):
            kernel.advance(1, wrong, False)
        kernel.ndof -= 3
        chunk, info, detail = integrator.advance(run, 1)
        assert (info, detail, len(chunk.time)) == (1, 0, 0)
        assert integrator.failure_text == "Newton did not converge within 1 iterations"
        message = integrator.failure_message(info, detail)
        assert message.startswith("time step from t = 0 s to t = 0.001 s failed: Newton did "
                                  "not converge within 1 iterations (last correction")
    finally:
        handle = kernel.handle
        model.close()
    kernel.handle = handle   # destroyed: a stale handle
    try:
        with pytest.raises(SolverError, match=f"handle {handle} is not a live system"):
            kernel.advance(1, state, False)
    finally:
        kernel.handle = 0
