"""The consistent acceleration and multipliers of a state, solved in the kernel
(``fortran/src/solvers/consistent_start.f90``: the start of a run and the step-size
control's restarts). References: the equations of motion M a - Phi_e^T lambda = f and the
constraints' acceleration equation Phi_e a = gamma, evaluated in Python from the model's
forces, constraint gradients and mass matrix. The saddle system is solved by the cost
rule's solver for its pattern (banded LU in reverse Cuthill-McKee order, else MUMPS);
the cases cover iteration matrices of both the banded and the MUMPS kinds."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import INPUTS, mumps_pages
from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.solvers import dynamic

CASES = [
    ("hard/pendulum.nml", ["beam.nodes=5", "beam.bending=cable", "scene.planar=xy"]),
    ("hard/pendulum.nml", ["beam.nodes=9"]),
    ("hard/spinup.nml", []),
    ("boom_luffing.nml", ["beam.nodes=4"]),
    ("general/cardan_shaft.nml", []),
    ("general/boom_mounts.nml", []),       # MUMPS (its force elements), no constraints
    ("knuckle_crane_rope.nml", []),        # MUMPS, 23 constraints
]
#: the cases whose iteration matrix is banded (the rest: MUMPS)
BANDED = 5


def _residuals(model, e, v, t, a, lam):
    """The residuals of the equations of motion and of Phi_e a = gamma (largest entries)
    and the sizes of their terms."""
    forces = model.forces(e, t, v)
    evaluated = model.constraints.evaluate(e, t, v)
    _, rows, cols, grads = model.constraints.jacobian(e, model.ndof, t, evaluated)
    phi_e = np.zeros((len(model.constraints), model.ndof))
    np.add.at(phi_e, (rows, cols), grads)
    f = forces["external"] - forces["internal"]
    ma = model.mass.toarray() @ a
    motion = np.abs(ma - phi_e.T @ lam - f).max()
    motion_scale = np.abs(ma).max() + np.abs(phi_e.T @ lam).max() + np.abs(f).max()
    gamma = evaluated[-1]
    acceleration = np.abs(phi_e @ a - gamma).max(initial=0.0)
    acceleration_scale = np.abs(phi_e).max(initial=0.0) * np.abs(a).max() + \
        np.abs(gamma).max(initial=0.0)
    return motion, motion_scale, acceleration, acceleration_scale


@pytest.mark.parametrize("scene,overrides", CASES)
def test_consistent_acceleration_meets_the_equations_of_motion(scene, overrides):
    """At the initial state and at a perturbed moving state at t = 0.1 s, the kernel's
    (a, lambda) satisfy both equations to round-off of their terms."""
    model = build_model(load_scene(INPUTS / scene, overrides=overrides))
    try:
        assert model.banded() == (CASES.index((scene, overrides)) < BANDED)
        rng = np.random.default_rng(7)
        states = [(model.e0, np.zeros(model.ndof), 0.0),
                  (model.e0 + 1e-4 * rng.standard_normal(model.ndof),
                   1e-2 * rng.standard_normal(model.ndof), 0.1)]
        for e, v, t in states:
            a, lam = dynamic.initial_acceleration(model, e, v, t)
            assert a.shape == (model.ndof,) and lam.shape == (len(model.constraints),)
            motion, motion_scale, acceleration, scale = _residuals(model, e, v, t, a, lam)
            assert motion <= 1e-13 * motion_scale and acceleration <= 1e-13 * scale
    finally:
        model.close()


def test_a_banded_model_never_runs_mumps():
    """The consistent acceleration of a banded model (the cantilever, 8 cable elements)
    in a fresh interpreter leaves the MUMPS libraries' resident pages as they were (MUMPS's
    code pages were ~2 MB of a small run's peak); one MUMPS solve afterwards in the same
    process adds hundreds of kB of them (the measure sees MUMPS run)."""
    banded, mumps = mumps_pages(
        INPUTS / "hard" / "cantilever_drop.nml",
        ["beam.nodes=9", "beam.bending=cable", "scene.planar=xy"],
        "assert model.banded()\n"
        "dynamic.initial_acceleration(model, model.e0, np.zeros(model.ndof), 0.0)")
    assert banded == 0
    assert mumps >= 256
