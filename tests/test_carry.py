"""The iteration matrix carried with the system's rotation (``solver.carry = 'rotation'``,
``fortran/src/solvers/carried_rotation.f90``, docs/theory.md section 28; issue 23 item 3).

The carry rests on one property of absolute-coordinate elements: turning a configuration
rigidly by R turns its tangent with it, K(T e) = T K(e) T^T (T = blockdiag(R) on every
3-vector), because the strain energy does not change under a rigid turn; the mass matrix
is kron(Mbar, I3) and commutes with T. That identity is checked first, on the tangents the
kernel assembles (the cubic beam, the cable, both planar-reduced), against the unturned
tangent turned by hand. The carried matrix only preconditions the simplified Newton
iteration, so the stepper's answer must still be full Newton's within the Newton tolerance
(the reference of tests/test_jacobian_reuse.py), while the spinning beam keeps its matrix
instead of refactorizing in nearly every step.
"""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.runner import run_scene

from conftest import INPUTS

SPINUP = INPUTS / "hard" / "spinup.nml"


def turn_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def turned_state(model, e: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """The reduced coordinates of the configuration e turned rigidly by rotation about the
    origin (every full 3-vector turned: positions and gradients alike)."""
    q = model.expand(e)
    q_turned = (q.reshape(-1, 3) @ rotation.T).reshape(-1)
    return q_turned[model.reduction.independent] if model.reduction is not None else q_turned


def turn_matrix(model, rotation: np.ndarray) -> np.ndarray:
    """T_e = B^T blockdiag(R) B on the reduced coordinates (B a selection)."""
    full = np.kron(np.eye(model.nfull // 3), rotation)
    if model.reduction is None:
        return full
    b = model.reduction.matrix.toarray()
    return b.T @ full @ b


def tangents(model, e: np.ndarray, rotation: np.ndarray) -> tuple[np.ndarray, ...]:
    """K(T e), T K(e) T^T and K(e) (dense) of the model at e turned by rotation."""
    t_e = turn_matrix(model, rotation)
    k_here = model.pattern.to_scipy(model.stiffness_values(0.0, e)).toarray()
    k_turned = model.pattern.to_scipy(
        model.stiffness_values(0.0, turned_state(model, e, rotation))).toarray()
    return k_turned, t_e @ k_here @ t_e.T, k_here


def test_the_tangent_turns_with_the_body():
    """K(T e) = T K(e) T^T to round-off at a deformed state (the spin-up's cubic beam,
    planar, perturbed, turned by 1.1 rad about the plane's normal): the property that makes
    a matrix factorized before a turn serve after it."""
    scene = load_scene(SPINUP, ["beam.bending=cubic", "beam.nodes=5", "scene.planar=xy"])
    model = build_model(scene)
    e = model.e0.copy()
    rng = np.random.default_rng(3)
    e = e + 1e-3 * rng.standard_normal(e.shape)   # a deformed state
    k_turned, k_carried, k_here = tangents(model, e, turn_z(1.1))
    scale = np.abs(k_here).max()
    assert np.abs(k_turned - k_carried).max() <= 1e-9 * scale
    # and turning matters: the unturned tangent is far off
    assert np.abs(k_turned - k_here).max() > 1e-2 * scale
    assert model.carry_vectors() is not None


def test_the_cable_tangent_turns_with_the_body():
    """The same identity for the planar ANCF cable (the flexible pendulum's model)."""
    model = build_model(load_scene(INPUTS / "hard" / "pendulum.nml",
                                   ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy"]))
    rng = np.random.default_rng(5)
    e = model.e0 + 1e-2 * rng.standard_normal(model.e0.shape)
    k_turned, k_carried, k_here = tangents(model, e, turn_z(-0.7))
    scale = np.abs(k_here).max()
    assert np.abs(k_turned - k_carried).max() <= 1e-9 * scale
    assert np.abs(k_turned - k_here).max() > 1e-2 * scale


def run(tmp_path, name: str, overrides: list[str]):
    out = tmp_path / f"{name}.h5"
    run_scene(SPINUP, ["spinup.omega=6", "solver.t_end=8", "beam.nodes=6", "solver.dt=1e-2",
                       "scene.planar=xy", "output.xdmf=.false.", *overrides], out)
    with h5py.File(out) as h5:
        return (h5["dynamic/deflection/tip"][()], int(h5["dynamic"].attrs["factorizations"]),
                int(h5["dynamic"].attrs["steps"]))


def test_a_spinning_beam_keeps_its_matrix_and_full_newtons_answer(tmp_path):
    """The spin-up (Simo & Vu-Quoc) to 8 s, when the hub has turned 25 rad: unturned, the
    kept matrix stops contracting within a step or two of the hub's turn and 'reuse'
    refactorizes in most steps; carried, a few matrices serve the run. Both answers are
    full Newton's within the Newton tolerance (ten times closer at a 1e-4 times tighter
    tolerance, as tests/test_jacobian_reuse.py demands of reuse).

    The bound at newton_tol = 1e-8: a step ends when its correction is below newton_tol x
    length (the model's length scale), and a contracting simplified Newton keeps at most
    about that much error in the step's state, so the run's answer is within steps x
    newton_tol x length of full Newton's (each step's kept error carried by the stable
    motion, not amplified). Which steps refresh the kept matrix, and so where within that
    bound the answer lands, follows round-off (main and a build differing from it only in
    the last bits of the initial acceleration read 9.6e-6 and 1.7e-5 of the span for the
    unturned matrix): the test asserts the bound and its scaling with the tolerance, not
    one machine's sample."""
    off, fact_off, steps = run(tmp_path, "off", ["solver.carry=off", "solver.newton_tol=1e-8"])
    off_tight, *_ = run(tmp_path, "off_tight", ["solver.carry=off", "solver.newton_tol=1e-12"])
    on, fact_on, _ = run(tmp_path, "on", ["solver.carry=rotation", "solver.newton_tol=1e-8"])
    full, *_ = run(tmp_path, "full", ["solver.jacobian=iteration", "solver.newton_tol=1e-8"])
    on_tight, *_ = run(tmp_path, "on_tight", ["solver.newton_tol=1e-12"])
    full_tight, *_ = run(tmp_path, "full_tight", ["solver.jacobian=iteration",
                                                  "solver.newton_tol=1e-12"])
    span = np.ptp(full, axis=0).max()
    length = build_model(load_scene(SPINUP, ["spinup.omega=6", "beam.nodes=6",
                                             "scene.planar=xy"])).length_scale
    bound = steps * 1e-8 * length / span
    d_loose = np.abs(on - full).max() / span
    d_tight = np.abs(on_tight - full_tight).max() / span
    d_off = np.abs(off - full).max() / span
    d_off_tight = np.abs(off_tight - full_tight).max() / span
    print(f"\nfactorizations: carried {fact_on}, unturned {fact_off}, {steps} steps; "
          f"carried - full Newton {d_loose:.2e} (1e-8), {d_tight:.2e} (1e-12); unturned "
          f"{d_off:.2e}, {d_off_tight:.2e}; bound {bound:.2e}")
    assert fact_off > 0.5 * steps
    assert fact_on < 0.05 * steps
    assert d_loose < bound
    assert d_tight < max(d_loose / 10, 1e-11)
    assert d_off < bound
    assert d_off_tight < max(d_off / 10, 1e-11)


def test_a_planar_spinning_cable_keeps_its_matrix_turned_in_closed_form(tmp_path):
    """A scene reduced to the xy plane turns its kept matrix about z by the closed-form
    angle atan2(C12 - C21, C11 + C22) of the correlation C (issue 23; the polar iterations
    do not settle on a straight beam's nearly rank-one correlation and the SVD cost ~4000
    instructions a step). The planar cable spin-up (W = 4, 11 nodes, dt 5e-3) to 8 s, when
    the hub has turned 5.5 rad: carried, a few matrices serve the run (a turn of the wrong
    sense or size would refresh it in most steps, as the unturned one is); the answer is
    full Newton's within the Newton tolerance."""
    planar = ["spinup.omega=4", "beam.bending=cable", "scene.planar=xy", "beam.nodes=11",
              "solver.dt=5e-3", "solver.t_end=8", "output.xdmf=.false."]

    def cable_run(name: str, extra: str):
        out = tmp_path / f"{name}.h5"
        run_scene(SPINUP, [*planar, extra], out)
        with h5py.File(out) as h5:
            return (h5["dynamic/deflection/tip"][()],
                    int(h5["dynamic"].attrs["factorizations"]), int(h5["dynamic"].attrs["steps"]))

    on, fact_on, steps = cable_run("plane_on", "solver.carry=rotation")
    off, fact_off, _ = cable_run("plane_off", "solver.carry=off")
    full, *_ = cable_run("plane_full", "solver.jacobian=iteration")
    span = np.ptp(full, axis=0).max()
    print(f"\nfactorizations: carried {fact_on}, unturned {fact_off}, {steps} steps; "
          f"carried - full Newton {np.abs(on - full).max() / span:.2e} of the range")
    assert fact_off > 0.3 * steps
    assert fact_on < 0.01 * steps
    assert np.abs(on - full).max() / span < 1e-6


def test_the_carry_is_refused_where_turning_is_not_exact():
    """FFR bodies (their frames carry their matrix already), contact (its tangent is not
    objective in the leaves' gap) and eliminated joints (a reduction that mixes
    coordinates) are never carried."""
    ffr = build_model(load_scene(INPUTS / "boom_luffing.nml", []))
    assert ffr.carry_vectors() is None
    spring = build_model(load_scene(INPUTS / "leaf_spring.nml", []))
    assert spring.carry_vectors() is None
    spin = build_model(load_scene(SPINUP, ["beam.bending=cubic", "scene.planar=xy"]))
    first, weight, position, group = spin.carry_vectors()
    # a beam node's four vectors: its position (weight 1) and three gradients (L^2)
    assert len(first) == 4 * 11 and position[::4].all() and not position[1::4].any()
    assert np.allclose(weight[1::4], spin.length_scale**2)
    assert not group.any()   # one body: one rotation, fitted to all its vectors


def slider_crank(carry: str, newton_tol: float = 1e-10):
    """The stiff (40 mm rod) flexible slider-crank of examples/slider_crank.py: a rigid crank
    driven to 60 rad/s in 0.05 s, a cubic-beam rod (5 nodes) whose end pins the reduction
    eliminates (the rod's first position is 0.15 times the crank's director, its last x the
    slider's), a slider on a guide; to 1 s at dt 1e-3. Returns the rod's midpoint history,
    the factorizations, the steps and the length scale."""
    from ancfdrv import Circle, System
    r, l = 0.15, 0.45
    pin, wrist = np.array([r, 0.0, 0.0]), np.array([r + l, 0.0, 0.0])
    s = System("slider-crank")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0, poisson_ratio=0.3)
    s.drive("crank", "spinup", omega=60.0, period=0.05)
    s.rigid_body("crank", mass=1.0, position=pin / 2, planar=True, plane_normal=(0, 0, 1),
                 inertia=(1e-6, r**2 / 12, r**2 / 12, 0, 0, 0))
    s.beam("rod", material=steel, start=pin, end=wrist, nodes=5, section=Circle(0.04),
           height_axis=(0, 1, 0), formulation="nonlinear", bending="cubic")
    s.rigid_body("slider", mass=0.5, inertia=(1e-4, 1e-4, 1e-4, 0, 0, 0), position=wrist,
                 planar=True, plane_normal=(0, 0, 1))
    s.joint("main bearing", "revolute", "ground", "crank", point=(0, 0, 0), axis=(0, 0, 1))
    s.joint("crank drive", "prescribed", "ground", "crank", point=pin, pivot=(0, 0, 0),
            axis=(0, 0, 1), drive="crank")
    s.joint("crank pin", "revolute", "crank", "rod", point=pin, axis=(0, 0, 1))
    s.joint("wrist pin", "revolute", "slider", "rod", point=wrist, axis=(0, 0, 1))
    s.joint("guide", "fix", "ground", "slider", point=wrist, axis=(0, 1, 0))
    s.joint("no turn", "fix", "ground", "slider", point=wrist, vector="r_x")
    s.probe("midpoint", "rod", (pin + wrist) / 2)
    res = s.simulate(1.0, 1e-3, integrator="generalized_alpha", rho_inf=0.8, max_newton=20,
                     carry=carry, newton_tol=newton_tol)
    return (np.asarray(res.probes["midpoint"]), res.counters["factorizations"],
            res.counters["time_steps"], float(res.model.attrs["length_scale"]))


def test_each_body_carries_its_own_turn():
    """Issue 38: the slider-crank's crank turns 0.06 rad a step while its rod swings +-19
    degrees; the rod's axial stiffness (~1e9 N/m against beta' M ~ 1e7) turned by the swing
    stops a kept matrix contracting within a step. Each body's matrix block turns with its
    own fitted rotation (joints are constraints, so S is block-diagonal over the bodies),
    through the reduction's scaled and shared end pins: fewer than 10 % of the steps
    refactorize (unturned: nearly every step), and the answer is the tight tolerance's within
    steps x newton_tol x length (the bound of the spin-up test above)."""
    kept, fact_on, steps, length = slider_crank("rotation")
    _, fact_off, _, _ = slider_crank("off")
    tight, *_ = slider_crank("rotation", 1e-12)
    span = np.ptp(tight, axis=0).max()
    print(f"\nfactorizations: carried {fact_on}, unturned {fact_off}, {steps} steps; "
          f"against newton_tol 1e-12: {np.abs(kept - tight).max() / span:.2e} of the range")
    assert fact_off > 0.5 * steps
    assert fact_on < 0.1 * steps
    assert np.abs(kept - tight).max() / span < steps * 1e-10 * length / span
