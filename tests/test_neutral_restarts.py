"""Step control of a method without numerical damping (issue 39 item 3; docs/hard-cases.md,
'Step cuts that converge').

At rho_inf = 1 (generalized-alpha with alpha_m = alpha_f, the trapezoidal rule) an error in
the acceleration-like variable a is a period-2 oscillation of e'' and of the multipliers that
nothing damps (a_{n+1} + a_n is what the positions see); on the flexible double pendulum at
dt = 2.5e-4 it grew from 0.4 N to 164 N by t = 5.5 s and the run drowned in step cuts. The
kernel's step control restarts such a method from the consistent acceleration after a block
of 64 whole steps whose period-2 part of the multipliers exceeds twice the run's quietest
block's and 1 % of the block's largest multiplier (step_control.f90). Asserted here: the
restart comes exactly after the first block that meets the rule (the rule recomputed from
the rows), none for a damped method; and a finer step costs no more Newton corrections per
step than a coarser one. The 10 s runs that need the restarts (40,000 steps) are
benchmarks/hard_case_suite.py's.
"""
from __future__ import annotations

import numpy as np

import h5py

from ancfdrv import Rectangle, System
from ancfdrv.runner import run_scene
from ancfdrv.solvers.dynamic import DynamicSettings, integrate

from conftest import INPUTS



def double_pendulum(nodes: int = 3) -> System:
    """inputs/hard/double_pendulum.nml with `nodes` nodes a beam."""
    s = System("flexible double pendulum")
    mat = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    sec = Rectangle(0.012, 0.012)
    for name, x0 in (("upper", 0.0), ("lower", 1.0)):
        s.beam(name, material=mat, start=(x0, 0, 0), end=(x0 + 1.0, 0, 0), nodes=nodes,
               section=sec, formulation="nonlinear")
    s.joint("shoulder", "revolute", "ground", "upper", point=(0, 0, 0), axis=(0, 0, 1))
    s.joint("elbow", "revolute", "upper", "lower", point=(1, 0, 0), axis=(0, 0, 1))
    s.load("g", "gravity", vector=(0, -9.81, 0))
    s.probe("tip", "lower", (2, 0, 0))
    return s


def _run(dt: float, t_end: float, rho_inf: float = 1.0):
    """The run's multipliers and Newton corrections per row."""
    model = double_pendulum().assemble()
    try:
        rows = []
        integrate(model, DynamicSettings.generalized_alpha(dt, t_end, rho_inf, tol=1e-10,
                                                           max_newton=20),
                  model.e0, sink=rows.append, progress=False)
    finally:
        model.close()
    lam = np.concatenate([r.lam for r in rows])
    corrections = np.concatenate([r.stats for r in rows])[:, 0]
    return lam, corrections


def test_a_finer_step_needs_no_more_corrections_per_step():
    t_end = 0.3
    _, coarse = _run(1e-3, t_end)
    _, fine = _run(2.5e-4, t_end)
    # (row 0 is the initial state)
    assert fine[1:].mean() <= coarse[1:].mean()


def _pendulum(tmp_path, t_end: float, rho_inf: float = 1.0):
    """The 5-node flexible pendulum at dt = 4e-3 (its undamped oscillation grows: the
    energy audit refuses it at t ~ 3.9 s): the multipliers' rows and the restarts."""
    out = tmp_path / f"pendulum_{t_end}_{rho_inf}.h5"
    run_scene(INPUTS / "hard" / "pendulum.nml",
              ["beam.nodes=5", "solver.dt=4e-3", f"solver.rho_inf={rho_inf}",
               f"solver.t_end={t_end}", "output.xdmf=false"], out, progress=False)
    with h5py.File(out) as h5:
        return h5["dynamic/lambda"][()], int(h5["counters"].attrs["step_restarts"])


def _first_growing_block(lam: np.ndarray) -> int | None:
    """The rule of step_control.f90 on an unrestarted history (row 0: the start): the first
    block of 64 rows whose largest |l_{n+1} - 2 l_n + l_{n-1}| / 4 (within the block)
    exceeds twice the quietest earlier block's and 1 % of the block's largest |lambda|."""
    quiet = np.inf
    for b in range((len(lam) - 1) // 64):
        rows = lam[1 + 64 * b:1 + 64 * (b + 1)]
        swing = (np.abs(rows[2:] - 2.0 * rows[1:-1] + rows[:-2]).max(axis=1) / 4.0).max()
        if swing > 2.0 * quiet and swing > 0.01 * np.abs(rows).max():
            return b
        quiet = min(quiet, swing)
    return None


def test_an_undamped_method_restarts_after_the_first_block_whose_oscillation_grew(tmp_path):
    # measured: blocks 0-4 ring at 0.5-2.9 N (0.5-1 % of 108-439 N), block 5 (rows
    # 321-384, to t = 1.536 s) at 9.2 N, 3.3 % of its 282 N
    lam, restarts = _pendulum(tmp_path, 384 * 4e-3)
    block = _first_growing_block(lam)
    assert block == 5 and restarts == 1
    # one row short of the block's end: no restart yet, the same rows
    short, restarts = _pendulum(tmp_path, 383 * 4e-3)
    assert restarts == 0
    np.testing.assert_array_equal(short, lam[:-1])
    # a damped method never restarts
    assert _pendulum(tmp_path, 384 * 4e-3, rho_inf=0.9)[1] == 0
