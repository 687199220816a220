"""The static Newton in the kernel (fortran/src/solvers/static_solver.f90, issue 25 item 4)
against the Python static Newton it replaced (tests/reference/static_newton.py, which
assembles the moments' and point loads' Jacobians, the constraint Hessians and the
convergence test from separate kernel calls and Python's constraint code), against closed
forms, and its error texts.

References: the elastica under a dead tip load k = PL^2/EI = 10 (Mattiasson 1981: w/L =
0.81061, u/L = 0.55500) and the end moment that bends a cantilever into a quarter circle
(tip at (2L/pi, 2L/pi)); the equilibrium residual recomputed in Python (static.residuals,
with Python's constraint Jacobian) at the kernel's solution.
"""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv.builders import build_model
from ancfdrv.errors import SolverError
from ancfdrv.io.scene import load_scene
from ancfdrv.solvers.static import residuals, solve_newton

from conftest import INPUTS
from helpers import beam_model
from reference.static_newton import solve_newton_python  # (tests/reference: never used by a run)

SLENDER = ["beam.length=1", "beam.width=0.01", "beam.height=0.01",
           "scene.formulation=nonlinear"]
EI_SLENDER = 2.1e11 * 0.01**4 / 12


def both(model, **kwargs):
    """The kernel's and the Python Newton's results on one model, compared: the largest
    coordinate difference relative to the largest displacement, the largest multiplier
    difference relative to the largest multiplier (or 1 when they vanish)."""
    kernel = solve_newton(model, **kwargs)
    python = solve_newton_python(model, **kwargs)
    d = np.abs(kernel.e - python.e).max() / np.abs(python.e - model.e0).max()
    lam = np.abs(kernel.lam - python.lam).max(initial=0.0) / max(
        np.abs(python.lam).max(initial=0.0), 1.0)
    return kernel, python, d, lam


def check_equilibrium(model, result, tol):
    """Python's residual (its own constraint Jacobian) at the kernel's solution is the one
    the kernel reported (to the scale floor the kernel keeps from the start), below tol or,
    converged at the round-off floor, below sqrt(tol); the constraints hold to tol."""
    out = model.forces(result.e, want_tangent=False)
    force_res, con_res = residuals(model, result.e - model.e0, result.lam, out["internal"],
                                   out["external"])
    assert con_res <= tol
    assert force_res <= (tol if result.extra["converged_by"] == "residual" else np.sqrt(tol))
    assert force_res == pytest.approx(result.residual_norm, rel=1e-3)


def test_elastica_tip_load_matches_python_and_mattiasson():
    """k = 10 in 10 load steps on 17 nodes: the two Newtons agree to round-off with the same
    iteration count; the tip is Mattiasson's within the 17-node discretization error
    (1.5 % in w, 2.7 % in u measured; tests/test_nonlinear.py shows it falls with the mesh)."""
    model = build_model(load_scene(INPUTS / "cantilever.nml", [
        "beam.nodes=17", *SLENDER, "scene.effects=tip_force", "loads.tip_force=0,-1750,0"]))
    kernel, python, d, lam = both(model, tol=1e-10, max_iter=40, load_steps=10)
    assert d < 1e-10 and lam < 1e-10
    assert kernel.iterations == python.iterations
    # the residual histories agree to 1e-6 until round-off enters: each relative residual
    # carries the rounding of the previous solve, eps kappa(K), with kappa(K) ~ 12 (L/h)^2
    # (n - 1)^2 = 3e7 for L/h = 100 on 17 nodes (axial against bending stiffness): 7e-9,
    # taken as 1e-8 (measured up to 1.7e-10 at a residual of 1.2e-4)
    np.testing.assert_allclose(np.array(kernel.history), np.array(python.history),
                               rtol=1e-6, atol=1e-8)
    check_equilibrium(model, kernel, 1e-10)
    tip = model.deflections(kernel.e)["tip"]
    assert -tip[1] == pytest.approx(0.81061, rel=0.02)
    assert -tip[0] == pytest.approx(0.55500, rel=0.03)


def test_end_moment_quarter_circle_matches_python_and_closed_form():
    """M = (pi/2) EI/L: constant curvature, the tip at (2L/pi, 2L/pi) (the dead moment's
    Jacobian enters the kernel's matrix); 17 nodes within 1.5 % (measured 1.4 %)."""
    model = build_model(load_scene(INPUTS / "cantilever.nml", [
        "beam.nodes=17", *SLENDER, "scene.effects=end_moment",
        f"loads.end_moment={np.pi / 2 * EI_SLENDER}"]))
    kernel, python, d, lam = both(model, tol=1e-10, max_iter=40, load_steps=4)
    assert d < 1e-10 and lam < 1e-10
    assert kernel.iterations == python.iterations
    np.testing.assert_allclose(model.probe_positions(kernel.e)["tip"][:2], 2 / np.pi, rtol=0.015)


@pytest.mark.parametrize("scene, settings, loads", [
    ("plate_pressure.nml", ["plate.nx=4", "plate.ny=4"], 1.0),
    ("leaf_spring.nml", [], 0.0),                        # contact carries the prestress
])
def test_plate_and_leaf_spring_match_python(scene, settings, loads):
    model = build_model(load_scene(INPUTS / scene, settings))
    kernel, python, d, lam = both(model, tol=1e-10, max_iter=50, loads=loads)
    assert d < 1e-10 and lam < 1e-10
    assert kernel.iterations == python.iterations
    assert kernel.extra["converged_by"] == python.extra["converged_by"]


@pytest.mark.parametrize("scene", ["knuckle_crane_rope.nml", "general/boom_luffing_cable.nml"])
def test_constrained_mechanisms_match_python(scene):
    """Joints with multipliers and constraint Hessians (the knuckle crane with its rope), a
    planar reduction q = B e + q0 with a dead moment (the cable on the luffing arm)."""
    model = build_model(load_scene(INPUTS / scene))
    kernel, python, d, lam = both(model, tol=1e-10, max_iter=50)
    assert d < 1e-10 and lam < 1e-10
    assert kernel.iterations == python.iterations
    assert np.abs(kernel.lam).max() > 1.0  # the joints carry load
    check_equilibrium(model, kernel, 1e-10)


def test_error_texts():
    model = build_model(load_scene(INPUTS / "cantilever.nml", [
        "beam.nodes=9", *SLENDER, "scene.effects=tip_force", "loads.tip_force=0,-1750,0"]))
    with pytest.raises(SolverError, match=r"static Newton did not converge in 1 iterations at "
                       r"load step 1 of 1 \(relative residual 1\.000e\+00, constraint "):
        solve_newton(model, max_iter=1)
    # a free beam under gravity: its rigid modes leave the residual where it is; the
    # kernel and Python name the same stall
    free = beam_model(4, gravity=(0.0, 0.0, -9.81))
    # (the words, not the digits: the residual a free beam stalls at is the rounding of a
    # singular solve, about 0.97, and moves with the machine's arithmetic)
    with pytest.raises(SolverError, match=r"static Newton stalled at the round-off floor at "
                       r"load step 1 of 1: the relative residual stays at \d\.\d{3}e[+-]\d{2}") as kernel:
        solve_newton(free)
    with pytest.raises(SolverError, match=r"stays at \d\.\d{3}e[+-]\d{2}") as python:
        solve_newton_python(free)
    assert str(kernel.value).split(" (")[0][:60] == str(python.value).split(" (")[0][:60]
    # sizes that do not fit the system are named as such
    out = model.kernel.static_solve(
        t=0.0, load_factor=1.0, e0=model.e0, rows=model.pattern.rows[:-1],
        cols=model.pattern.col_index[:-1], e=model.e0, lam=np.zeros(len(model.constraints)),
        guesses=model.contact_guesses, counts=model.contact_counts, tol=1e-10,
        length_scale=model.length_scale, max_iter=5, check_start=False, force_scale=-1.0,
        load_step=1, load_steps=1)
    assert out["info"] and "sizes inconsistent" in out["message"]
    model.close()
    with pytest.raises(SolverError, match="released"):
        solve_newton(model)
