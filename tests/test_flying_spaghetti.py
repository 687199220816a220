"""The 3D flying spaghetti (Simo & Vu-Quoc 1988), short version: a free beam (L = 10,
EA = GA = 1e4, EI = GJ = 500, rho A = 1, rho J = diag(20, 10, 10), section = 'general')
driven at one end by the dead force (1/10, 0, 0) p(t) and the dead torque (0, 1, 1/2) p(t),
p a triangular pulse 0 -> 200 -> 0 on 0..5 s (a 'table' drive on a 'force' and a 'moment'
load). Against this code's converged reference (finer mesh and step) over the pulse
(0..5 s): the end point's displacement within 2% of each component's range. The long
version (0..10 s, the mesh/step sequence, JSON) is benchmarks/flying_spaghetti.py.

Independent checks that do not need the reference: a free body's linear momentum is the
impulse of the force, int F dt = (1/10) * 500 = 50 N s along x, so after the pulse the
centre of mass (total mass 10) moves at 5 m/s along x; the torque changes the angular
momentum about the centre of mass, so the end points must differ from a rigid translation.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from flying_spaghetti import END, build, compare, simulate  # noqa: E402

from ancfdrv.solvers.dynamic import DynamicSettings, integrate  # noqa: E402


@pytest.fixture(scope="module")
def runs():
    coarse = simulate(17, 0.01, 5.0)
    reference = simulate(33, 0.005, 5.0)
    return coarse, reference


def test_flying_spaghetti_converges_to_the_reference(runs):
    """'cubic' bending, 17 nodes, dt = 0.01 against 33 nodes, dt = 0.005 (measured: 0.39%,
    1.01%, 1.25% of the ranges of u1, u2, u3; 13 nodes: 0.87%, 2.1%, 2.8%; the 33-node run
    is within 0.07-0.21% of 49 nodes over the pulse, and the 'continuum' option at 33
    nodes within 0.23-0.38%: benchmarks/results/flying_spaghetti.json)."""
    (t, u, *_), (t_ref, u_ref, *_) = runs
    assert t[-1] == pytest.approx(5.0) and t_ref[-1] == pytest.approx(5.0)
    errors = compare(t, u, t_ref, u_ref)
    assert max(errors) < 0.02
    assert np.ptp(u_ref[:, 0]) > 5.0   # it flies: metres along x, and turns out of the plane
    assert np.ptp(u_ref[:, 1]) > 0.5


def test_flying_spaghetti_momentum_is_the_impulse():
    """After the pulse (t = 5 .. 6 s, no load) the centre of mass moves at 50 N s / 10 kg =
    5 m/s along x and not at all along y, z; the centre of mass of the cubic centre line
    exactly: int r ds = sum_elements h (r0 + r1)/2 + h^2 (r0' - r1')/12, the slopes of
    inner nodes cancelling."""
    model = build(17).assemble()
    rows = []
    try:
        settings = DynamicSettings.generalized_alpha(0.01, 6.0, rho_inf=0.8, max_newton=30)
        settings.store_q = True
        integrate(model, settings, model.e0, sink=lambda c: rows.append(
            (np.array(c.time), np.array(c.q))), progress=False)
        t = np.concatenate([r[0] for r in rows])
        q = model.expand(np.concatenate([r[1] for r in rows]))
    finally:
        model.close()
    body = model.bodies[0]
    positions = np.stack([q[:, body.node_first(n):body.node_first(n) + 3]
                          for n in range(body.nodes)], axis=1)
    h = body.length / (body.nodes - 1)
    weights = np.full(body.nodes, h)
    weights[[0, -1]] = h / 2
    slope = [q[:, body.node_first(n, "r_x"):body.node_first(n, "r_x") + 3] for n in (0, body.nodes - 1)]
    centre = (np.einsum("n,tnk->tk", weights, positions)
              + h**2 / 12 * (slope[0] - slope[1])) / body.length
    assert np.allclose(centre[0], END / 2)
    after = t >= 5.0
    velocity = np.polyfit(t[after], centre[after], 1)[0]
    assert velocity == pytest.approx([5.0, 0.0, 0.0], abs=2e-3)
