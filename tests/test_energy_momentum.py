"""solver.integrator = 'energy_momentum' (fortran/src/solvers/energy_momentum.f90; issue 39
item 4): the midpoint rule with a discrete gradient of the strain energy.

- the discrete-gradient identity W(e1) - W(e0) = f_dg . (e1 - e0) to round-off for random
  pairs of states, element by element family (the nonlinear beam's averaged stress, the
  rope's secant across its slack/taut switch, the cable's Gonzalez correction), and
  f_dg(e, e) = W'(e);
- the Jacobian of the step's residual (with a pin's multipliers) against central
  differences;
- the kernel's own refusals (adaptive steps, an unsupported model) past the validation;
- the undamped, undriven flexible pendulum and a payload on a rope (and on a cable) keep
  their total energy to 1e-6 of its scale at every step size;
- a free, spinning and vibrating beam keeps its energy, momentum and angular momentum;
- scenes it does not support are refused before the run (exit 2, naming the key and the
  item).
"""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from ancfdrv import Circle, Rectangle, System
from ancfdrv.cli import main
from ancfdrv.solvers.dynamic import DynamicSettings, integrate

from conftest import INPUTS
from helpers import beam_model

PENDULUM = INPUTS / "hard" / "pendulum.nml"
GRAVITY = 9.81


def _rope_system(tension_only: bool = True, nodes: int = 3,
                 bending: float = 1.0) -> tuple[System, object]:
    """A 2 m steel rope (d = 10 mm, EI = bending, 1 N m^2) hinged at its top (spherical
    joint), horizontal at rest with a 100 kg payload at its end, under gravity: it swings
    down and rings axially; its Gauss points go slack and taut again (tension-only law)."""
    s = System("rope pendulum")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    end = (2.0, 0.0, 0.0)
    rope = s.cable("rope", material=steel, start=(0, 0, 0), end=end, nodes=nodes,
                   section=Circle(0.01), tension_only=tension_only,
                   bending_stiffness=bending)
    s.joint("top", "spherical", "ground", "rope", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -GRAVITY, 0))
    s.load("payload", "point_mass", body="rope", point=end, mass=100.0)
    s.probe("hook", "rope", end)
    return s, rope


def _pinned_beam() -> System:
    """A soft nonlinear beam (the pendulum's section and material, 3 nodes) hinged at its
    root about z."""
    s = System("pinned beam")
    s.material("soft", youngs_modulus=0.7e6, density=5540.0)
    s.beam("beam", material="soft", start=(0, 0, 0), end=(1.2, 0, 0), nodes=3,
           section=Rectangle(0.2, 0.009), formulation="nonlinear")
    s.joint("pin", "revolute", "ground", "beam", point=(0, 0, 0), axis=(0, 0, 1))
    s.load("g", "gravity", vector=(0, -GRAVITY, 0))
    return s


def _identity_gap(model, e0: np.ndarray, e1: np.ndarray) -> tuple[float, float]:
    """(W(e1) - W(e0) - f_dg . (e1 - e0), the energies' size) of the model's sets."""
    w0 = model.forces(e0)["strain"]
    w1 = model.forces(e1)["strain"]
    zero = np.zeros(model.ndof)
    f = model.kernel.midpoint_residual(1.0, 0.0, e0, zero, e1,
                                       np.zeros(len(model.constraints)))["internal"]
    return w1 - w0 - f @ (e1 - e0), abs(w0) + abs(w1)


@pytest.mark.parametrize("family", ["beam", "rope", "cable"])
def test_discrete_gradient_identity_and_consistency(family):
    """For random pairs of large perturbations of the reference (strains of several
    percent; the rope's Gauss points slack in one state and taut in the other) the
    discrete-gradient force closes the energy difference to round-off (1e-12 of the
    energies; the cable's Gonzalez correction 1e-10: it divides a difference of energies
    by |dI|^2), and at e0 = e1 it is the element's force W'(e) to 1e-10."""
    rng = np.random.default_rng(7)
    rope = None
    if family == "beam":
        model = beam_model(nodes=3, formulation="nonlinear")
        scale = 0.02
    else:
        system, rope = _rope_system(tension_only=family == "rope")
        model = system.assemble()
        scale = 0.01
    try:
        ref = model.e0.copy()
        bound = 1e-12 if family != "cable" else 1e-10
        for _ in range(5):
            e0 = ref + scale * rng.standard_normal(model.ndof)
            e1 = ref + scale * rng.standard_normal(model.ndof)
            gap, size = _identity_gap(model, e0, e1)
            assert size > 0.0
            assert abs(gap) <= bound * size, (gap, size)
            # near each other: e1 = e0 + a tiny step (the mean-value limit)
            e_near = e0 + 1e-7 * rng.standard_normal(model.ndof)
            gap, size = _identity_gap(model, e0, e_near)
            assert abs(gap) <= 1e-12 * size + 1e-9 * abs(
                model.forces(e0)["strain"] - model.forces(e_near)["strain"])
            # consistency: f_dg(e, e) = W'(e)
            zero = np.zeros(model.ndof)
            f = model.kernel.midpoint_residual(1.0, 0.0, e0, zero, e0,
                                               np.zeros(len(model.constraints)))["internal"]
            grad = model.forces(e0)["internal"]
            assert np.abs(f - grad).max() <= 1e-10 * np.abs(grad).max()
        if family == "rope":
            # the pairs above did cross the kink: some points taut in one, slack in the other
            strains = [rope.strains(e[None, :]) for e in (e0, e1)]
            assert min(s.min() for s in strains) < 0.0 < max(s.max() for s in strains)
    finally:
        model.close()


@pytest.mark.parametrize("which", ["beam", "rope", "cable"])
def test_step_jacobian_matches_central_differences(which):
    """The Jacobian of the step's residual in (e1, lambda) (the discrete gradient's, the
    mass term's, the multipliers' columns and their d(Phi_e(e_m)^T lambda)/de1) against
    central differences of the residual, to 1e-6 of the Jacobian's largest entry in its
    column block."""
    rng = np.random.default_rng(3)
    # (the cable's bending made stiff, 1e5 N m^2: its part of the Jacobian, Gonzalez's
    # correction and its derivative among it, must show above the axial stiffness's 1e-6)
    system = _pinned_beam() if which == "beam" else \
        _rope_system(which == "rope", bending=1.0 if which == "rope" else 1e5)[0]
    model = system.assemble()
    try:
        n, m = model.ndof, len(model.constraints)
        e0 = model.e0 + 1e-3 * rng.standard_normal(n)
        v0 = rng.standard_normal(n)
        e1 = e0 + 0.01 * v0 + 1e-3 * rng.standard_normal(n)
        lam = 100.0 * rng.standard_normal(m)
        h, t = 0.01, 0.3
        out = model.kernel.midpoint_residual(h, t, e0, v0, e1, lam, want_jacobian=True)
        jac = out["jacobian"]
        assert m > 0
        numeric = np.zeros_like(jac)
        for j in range(n + m):
            steps = 1e-6 if j < n else 1e-3
            de, dl = np.zeros(n), np.zeros(m)
            (de if j < n else dl)[j if j < n else j - n] = steps
            rp = model.kernel.midpoint_residual(h, t, e0, v0, e1 + de, lam + dl)["residual"]
            rm = model.kernel.midpoint_residual(h, t, e0, v0, e1 - de, lam - dl)["residual"]
            numeric[:, j] = (rp - rm) / (2 * steps)
        for cols in (slice(0, n), slice(n, n + m)):
            scale = np.abs(jac[:, cols]).max()
            assert np.abs(jac[:, cols] - numeric[:, cols]).max() <= 1e-6 * scale
    finally:
        model.close()


def _run_pendulum(tmp_path, dt: float, integrator: str = "energy_momentum") -> dict:
    out = tmp_path / f"pendulum_{dt:g}.h5"
    assert main(["run", str(PENDULUM), "-o", str(out), "--set", "beam.nodes=3",
                 "--set", f"solver.dt={dt}", "--set", "solver.t_end=0.4",
                 "--set", f"solver.integrator={integrator}"]) == 0
    with h5py.File(out) as h5:
        return {k: h5[f"dynamic/energy/{k}"][()] for k in ("total", "kinetic", "gravity")}


@pytest.mark.parametrize("dt", [2e-3, 5e-3, 2e-2, 5e-2])
def test_pendulum_energy_at_every_step_size(tmp_path, dt):
    """The undamped, undriven flexible pendulum (inputs/hard/pendulum.nml, 3 nodes, 0.4 s:
    it falls through ~0.7 m and its energy scale, the kinetic energy it reaches, is ~40 J)
    keeps its total energy to 1e-6 of that scale at every row, from dt = 2e-3 to 5e-2 (two
    to eight steps per tenth of a second): the identity is exact, only Newton's tolerance
    (1e-10 m) is left."""
    energy = _run_pendulum(tmp_path, dt)
    scale = energy["kinetic"].max()
    assert scale > 10.0
    drift = np.abs(energy["total"] - energy["total"][0]).max()
    assert drift <= 1e-6 * scale, drift / scale


@pytest.mark.parametrize("dt", [1e-3, 4e-3, 1e-2])
def test_rope_payload_energy_at_every_step_size(dt):
    """The payload on a rope (3 nodes, 1 s: it swings down, the rope rings axially with
    Gauss points going slack and taut again) keeps its total energy to 1e-6 of the kinetic
    energy it reaches at every step size (generalized-alpha at rho_inf = 1 and the same
    steps gains energy without bound on this model: benchmarks/energy_momentum.py)."""
    s, rope = _rope_system()
    res = s.simulate(1.0, dt, integrator="energy_momentum", newton_tol=1e-10, xdmf=False,
                     q=True)
    total, kinetic = res.energy["total"], res.energy["kinetic"]
    assert kinetic.max() > 1000.0   # 100 kg fallen through ~2 m
    assert np.abs(total - total[0]).max() <= 1e-6 * kinetic.max()
    strains = rope.strains(res.dynamic.q)
    assert strains.min() < 0.0 < strains.max()   # the tension-only switch was crossed


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_cable_payload_energy_at_every_step_size(dt):
    """The same payload on a cable (the exact-curvature law, Gonzalez's discrete gradient in
    its invariants) keeps its energy to 1e-6 of the kinetic energy it reaches, at dt = 1e-2
    too, where Newton needs step cuts (the cable's axial ringing): the cut steps conserve
    the energy as well."""
    s, _ = _rope_system(tension_only=False)
    res = s.simulate(1.0, dt, integrator="energy_momentum", newton_tol=1e-10, xdmf=False)
    total, kinetic = res.energy["total"], res.energy["kinetic"]
    assert kinetic.max() > 1000.0
    assert np.abs(total - total[0]).max() <= 1e-6 * kinetic.max()


def test_free_spinning_beam_keeps_energy_momentum_and_angular_momentum():
    """A free nonlinear beam (no joints, no gravity, 3 nodes) spinning at 20 rad/s about
    an axis through its start, with a random vibration on top, over 0.05 s at dt = 5e-4:
    the total energy, the linear momentum P = U^T M e' and the angular momentum
    L = sum (Omega_i e)^T M e' (U, Omega_i e: the coordinates of a rigid translation and
    rotation) keep their first values to 1e-8 of their size at every step."""
    model = beam_model(nodes=3, length=1.0, width=0.02, height=0.02, formulation="nonlinear")
    try:
        assert model.reduction is None
        rng = np.random.default_rng(11)
        e0 = model.e0.copy()
        omega = np.array([0.3, 1.0, 20.0])
        v0 = np.cross(omega, e0.reshape(-1, 3)).ravel() + 0.05 * rng.standard_normal(model.ndof)
        settings = DynamicSettings(dt=5e-4, t_end=0.05, integrator="energy_momentum",
                                   tol=1e-12, store_q=True, max_newton=20)
        chunks = []
        integrate(model, settings, e0, v0, sink=chunks.append, progress=False)
        q = np.vstack([c.q for c in chunks if c.q is not None])
        time = np.concatenate([c.time for c in chunks])
        assert len(time) == 101
        mass = model.mass_matrix().toarray()
        # the method's velocities: v_{n+1} = 2 (q_{n+1} - q_n) / h - v_n
        v = np.empty_like(q)
        v[0] = v0
        for k in range(1, len(q)):
            v[k] = 2.0 * (q[k] - q[k - 1]) / settings.dt - v[k - 1]
        nvec = model.ndof // 3
        translation = np.zeros((3, model.ndof))
        for i in range(3):
            translation[i, i::12] = 1.0   # the positions of each 12-coordinate node
        momentum = (translation @ mass @ v.T).T
        angular = np.array([[np.cross(np.eye(3)[i], qk.reshape(nvec, 3)).ravel() @ mass @ vk
                             for i in range(3)] for qk, vk in zip(q, v)])
        energy = np.concatenate([c.energy[:, 4] for c in chunks])   # total
        assert np.abs(momentum - momentum[0]).max() <= 1e-8 * np.abs(momentum[0]).max()
        assert np.abs(angular - angular[0]).max() <= 1e-8 * np.abs(angular[0]).max()
        assert np.abs(energy - energy[0]).max() <= 1e-8 * energy[0]
    finally:
        model.close()


@pytest.mark.parametrize("scene,override,words", [
    (PENDULUM, ["material.damping_time=1e-3", "scene.effects=gravity,damping"],
     ["material damping"]),
    (PENDULUM, ["solver.step=adaptive"], ["fixed steps"]),
    (PENDULUM, ["scene.formulation=ffr"], ["(FFR)"]),
    (PENDULUM, ["beam.bending=cubic"], ["'cubic' beam"]),
    (INPUTS / "hard" / "spinup.nml", [], ["a driven (moving) frame"]),
])
def test_unsupported_scenes_are_refused_before_the_run(tmp_path, capsys, scene, override,
                                                       words):
    """Damping, adaptive steps, a floating-frame beam, the 'cubic' beam and the spin-up's
    driven hub with 'energy_momentum': exit 2 before anything is written, the message naming
    the scene's &solver key, the integrator and the item."""
    out = tmp_path / "refused.h5"
    argv = ["run", str(scene), "-o", str(out), "--set", "solver.integrator=energy_momentum"]
    if scene == PENDULUM:
        argv += ["--set", "beam.nodes=3"]
    for item in override:
        argv += ["--set", item]
    assert main(argv) == 2
    err = capsys.readouterr().err
    for word in ["solver.integrator", "'energy_momentum'", *words]:
        assert word in err, err
    assert "&solver" in err
    assert not out.exists()


def test_kernel_refuses_adaptive_steps_and_unsupported_models():
    """Past the scene's validation (the Python API's DynamicSettings), the kernel itself
    refuses: adaptive steps at the stepper's set-up (code 2), and a model with material
    damping at the first step, its message naming the integrator."""
    from ancfdrv.errors import SolverError
    model = beam_model(nodes=2, formulation="nonlinear")
    try:
        settings = DynamicSettings(dt=1e-3, t_end=2e-3, integrator="energy_momentum",
                                   step="adaptive")
        with pytest.raises(SolverError, match="energy-momentum method takes fixed steps"):
            integrate(model, settings, model.e0, progress=False)
        assert model.kernel.energy_momentum_obstacle() == ""
    finally:
        model.close()
    s = System("damped beam", effects=("damping",))
    s.material("steel", youngs_modulus=2.1e11, density=7850.0, damping_time=1e-3)
    s.beam("beam", material="steel", start=(0, 0, 0), end=(1, 0, 0), nodes=2,
           section=Rectangle(0.02, 0.02), formulation="nonlinear")
    damped = s.assemble(effects=("damping",))
    try:
        assert "material damping" in damped.kernel.energy_momentum_obstacle()
        settings = DynamicSettings(dt=1e-3, t_end=2e-3, integrator="energy_momentum")
        with pytest.raises(SolverError, match="energy-momentum integrator does not support"):
            integrate(damped, settings, damped.e0, progress=False)
    finally:
        damped.close()
