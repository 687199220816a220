"""The small call's shortcuts (issue 38, "a model build and output path whose fixed cost is
at most Exudyn's") give what the general paths give: the cable strains from the slope rows
cached per mesh, the stiffness triplets without the dead moments' Hessians, the stability
count with single-coordinate constraint groups left undecomposed, and the reactions' scatter
matrices made once per joint. Structural checks against independent references (closed
forms, the general path's values); no timings."""
from __future__ import annotations

import numpy as np
import pytest

import ancfdrv
from ancfdrv import System
from ancfdrv.system.kinds.cable import _gauss_slopes
from ancfdrv.system.sections import Rectangle

BOOM_3PCT = ["scene.formulation=nonlinear", "solver.static_method=newton",
             "output.xdmf=.false.", "beam.bending=cable", "scene.planar=xy", "beam.nodes=4",
             "solver.dt=0.02", "solver.t_end=0.2"]


def _cable(nodes: int = 4, length: float = 3.0):
    s = System("strip")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.cable("c", material=steel, start=(0, 0, 0), end=(length, 0, 0), nodes=nodes,
            section=Rectangle(0.02, 0.02))
    s.joint("A", "spherical", "ground", "c", point=(0, 0, 0))
    return s


@pytest.mark.parametrize("stretch", [1.0, 1.01, 0.98])
def test_cable_strains_of_a_uniform_stretch(stretch):
    """A straight cable stretched uniformly by lambda (r = lambda x, r_x = lambda e_x) has
    the Green strain (lambda^2 - 1) / 2 at every Gauss point, at a single state and along a
    history, on a mesh of unequal element lengths."""
    model = _cable(nodes=4).assemble()
    try:
        cable = model.bodies[0]
        cable.stations = np.array([0.0, 0.5, 1.7, 3.0])   # unequal elements (the cached rows)
        cable.lengths = np.diff(cable.stations)
        q = np.zeros(cable.ncoordinates)
        for node, x in enumerate(cable.stations):
            q[6 * node:6 * node + 3] = (stretch * x, 0.0, 0.0)
            q[6 * node + 3:6 * node + 6] = (stretch, 0.0, 0.0)
        expected = 0.5 * (stretch**2 - 1.0)
        one = cable.strains(q)
        assert one.shape == (3, 5)
        assert np.abs(one - expected).max() <= 1e-14 * max(1.0, stretch**2)
        rows = cable.strains(np.stack([q, q]))
        assert rows.shape == (2, 3, 5) and np.array_equal(rows[0], one)
    finally:
        model.close()


def test_the_cached_slope_rows_are_the_kernels():
    """The slope rows of the 5-point rule cached per mesh ((4, nel, 5, 1): shape function,
    element, point) are the kernel's cable_shape slopes at each point and element length
    (the same floats), read only."""
    from ancfdrv import kernel
    from ancfdrv.gauss import leggauss
    lengths = (0.5, 1.2, 1.3)
    rows = _gauss_slopes(lengths)
    assert rows.shape == (4, 3, 5, 1) and not rows.flags.writeable
    for g, x in enumerate(0.5 * (leggauss(5)[0] + 1.0)):
        for k, length in enumerate(lengths):
            assert np.array_equal(rows[:, k, g, 0], kernel.cable_shape(x, length)[1])
    assert _gauss_slopes(lengths) is rows


def test_moment_terms_without_hessians_keep_the_jacobian():
    """moment_terms(hessians=False): the same coordinates, force and Jacobian, no
    Hessian."""
    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    model = build_model(load_scene("inputs/boom_luffing.nml", BOOM_3PCT))
    try:
        assert model.moments, "the boom carries its dead bending moment"
        e = model.e0 + 1e-3 * np.sin(np.arange(model.ndof))
        full = model.moment_terms(e, load_factor=0.7)
        lean = model.moment_terms(e, load_factor=0.7, hessians=False)
        for (c1, f1, j1, h1), (c2, f2, j2, h2) in zip(full, lean):
            assert np.array_equal(c1, c2) and np.array_equal(f1, f2)
            assert np.array_equal(j1, j2)
            assert h1 is not None and h1.shape == (len(c1),) * 3 and h2 is None
    finally:
        model.close()


def test_the_boom_static_state_is_stable_and_its_reactions_balance():
    """The boom's static start (planar: single-coordinate fixes beside the joints' group)
    is counted stable (index 0, as the eigenvalues of the reduced tangent say), and the
    dynamic run's reactions at its first row (from the scatter matrices made for the
    static state) equal the static reactions: the run starts from that state at rest."""
    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    from ancfdrv.solvers.path import _reduced_tangent
    sim = ancfdrv.simulate("inputs/boom_luffing.nml", BOOM_3PCT, progress=False)
    assert sim.status == "ok"
    assert sim.static.extra["stability_index"] == 0
    model = build_model(load_scene("inputs/boom_luffing.nml", BOOM_3PCT))   # the same model
    try:
        rows, cols, vals, size = _reduced_tangent(model, sim.static.e, sim.static.lam, 1.0)
    finally:
        model.close()
    dense = np.zeros((size, size))
    np.add.at(dense, (rows, cols), vals)
    w = np.linalg.eigvalsh(dense)
    assert w.min() > -1e-10 * np.abs(w).max()
    static = sim.static_answers.reactions
    for joint in sim.reactions:
        first = sim.reaction(joint)["force"][0]
        scale = max(np.abs(static[joint].force).max(), 1.0)
        assert np.abs(first - static[joint].force).max() <= 1e-6 * scale
