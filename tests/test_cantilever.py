"""Cantilevers clamped by constraints against beam theory (analytic.py).

The continuum beam element has a shear strain constant over the section, so its converged
limit is Timoshenko's beam with shear factor 1 (G = E/2 at nu = 0); the references include
that shear term (PL/(GA), qL^2/(2GA); 0.03% here). Observed convergence rates are printed
(pytest -s) and asserted.
"""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv.reference import analytic
from ancfdrv.builders import build_model
from ancfdrv.io.scene import load_scene
from ancfdrv.solvers.static import solve_newton, solve_split

E, L, B = 2.1e11, 2.0, 0.05
A, I, G = B * B, B**4 / 12, 2.1e11 / 2


def tip(scene_path, nodes, effects, *extra, method=solve_newton):
    scene = load_scene(scene_path, [f"beam.nodes={nodes}", f"scene.effects={effects}", *extra])
    model = build_model(scene)
    result = method(model, tol=1e-11, max_iter=20)
    return model.deflections(result.e)["tip"]


def rates(errors):
    errors = np.asarray(errors)
    return np.log2(errors[:-1] / errors[1:])


CASES = {
    "tip force": ("tip_force", ["loads.tip_force=0,-100,0"],
                  analytic.cantilever_tip_load(100.0, L, E, I, A=A, G=G)),
    "uniform load": ("gravity", [], analytic.cantilever_uniform_load(7850 * A * 9.81, L, E, I,
                                                                      A=A, G=G)),
}


@pytest.mark.parametrize("name", CASES)
def test_bending_converges_at_second_order(cantilever_scene, name):
    effects, extra, reference = CASES[name]
    errors = [abs(-tip(cantilever_scene, n, effects, *extra)[1] - reference) / reference
              for n in (2, 3, 5, 9, 17)]
    observed = rates(errors)
    print(f"\n{name}: relative errors {np.array2string(np.array(errors), precision=3)}, "
          f"observed orders {np.array2string(observed, precision=3)}")
    assert errors[-1] < 1.5e-3
    np.testing.assert_allclose(observed, 2.0, atol=0.02)


def test_end_moment_is_reproduced_by_constant_curvature(cantilever_scene):
    """Pure bending has constant curvature, which the element represents exactly: the
    tip deflection ML^2/(2EI) and rotation ML/(EI) hold on one element. The remaining
    8e-7 is the geometric nonlinearity of the moment's generalized force (theta ~ 1e-3)."""
    moment = 50.0
    deflection, rotation = analytic.cantilever_end_moment(moment, L, E, I)
    for nodes in (2, 5):
        scene = load_scene(cantilever_scene, [f"beam.nodes={nodes}", "scene.effects=end_moment",
                                              f"loads.end_moment={moment}"])
        model = build_model(scene)
        result = solve_newton(model, tol=1e-12, max_iter=20)
        assert model.deflections(result.e)["tip"][1] == pytest.approx(deflection, rel=2e-6)
        r_y = result.e[-6:-3]
        assert np.arctan2(-r_y[0], r_y[1]) == pytest.approx(rotation, rel=2e-6)


def test_axial_load(cantilever_scene):
    reference = analytic.cantilever_axial(1000.0, L, E, A)
    assert tip(cantilever_scene, 3, "tip_force", "loads.tip_force=1000,0,0")[0] == \
        pytest.approx(reference, rel=1e-9)


def test_split_iteration_on_cantilever_matches_newton(cantilever_scene):
    a = tip(cantilever_scene, 9, "tip_force", "loads.tip_force=0,-100,30")
    b = tip(cantilever_scene, 9, "tip_force", "loads.tip_force=0,-100,30", method=solve_split)
    np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-15)
