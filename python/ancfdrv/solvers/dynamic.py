"""Implicit dynamics of an assembled model: Newmark (seed 000, eqs. 58-62) and
generalized-alpha (Chung-Hulbert; Arnold-Bruels for constrained systems).

The model lives in the kernel behind a handle (``Model.kernel``); Python computes the
consistent initial acceleration and hands the stepping to the kernel
(``fortran/src/solvers/time_integrator.f90``), which advances whole chunks of steps per call
and decides when to factorize the iteration matrix S = beta' M + K:

* policy 'constant' (pure FFR systems in prescribed frames): once per run, in the solver
  frame (every 3 x 3 block of M is a scalar times I3, so beta' M + T K0 T^T = T S T^T for
  any frame rotation), with the flexibility S^{-1} E_c from which each step's Schur
  complement of the multipliers is built without further solves;
* otherwise as ``DynamicSettings.jacobian`` says: 'step' (at each step's predicted state,
  again when a correction does not halve), 'iteration' (full Newton), 'reuse' (modified
  Newton across steps, refreshed when Newton stops contracting, the contact set changes or
  the step size changes; a step failing with an old matrix retries with a fresh one).

Each chunk's outputs go to a ``sink`` (the HDF5 writer) before the next chunk starts, so an
interrupted or failed run keeps every completed chunk.
"""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp
from tqdm import tqdm

from ..codes import (CONTACT_COUNTERS, CONTACT_RECORD, ENERGY_NAMES, JACOBIAN_ITERATION,
                     JACOBIAN_REUSE, JACOBIAN_STEP, STAT_NAMES, STEP_FAILURES)
from ..errors import Interrupted, SolverError
from ..kernel import DirectSolver
from ..system.model import Model

#: what a contact record (per point and step) holds
CONTACT_FIELDS = CONTACT_RECORD
JACOBIAN_POLICIES = {"step": JACOBIAN_STEP, "iteration": JACOBIAN_ITERATION,
                     "reuse": JACOBIAN_REUSE}


@dataclass
class DynamicSettings:
    """Integrator settings (``&solver`` and ``&output`` of a scene). Newmark is
    alpha_m = alpha_f = 0; :meth:`generalized_alpha` sets all four from rho_inf.
    ``jacobian``: when a refactorized model's iteration matrix is refreshed ('step',
    'iteration', 'reuse'); ``contraction``: the reuse policy's limit on the ratio of
    successive corrections."""

    dt: float
    t_end: float
    beta: float = 0.25
    gamma: float = 0.5
    alpha_m: float = 0.0
    alpha_f: float = 0.0
    tol: float = 1e-10
    max_newton: int = 10
    chunk_steps: int = 1000
    store_q: bool = False
    jacobian: str = "step"
    contraction: float = 0.25
    length_scale: float = 1.0

    @classmethod
    def generalized_alpha(cls, dt: float, t_end: float, rho_inf: float,
                          **kwargs) -> "DynamicSettings":
        """Chung-Hulbert parameters for the spectral radius at infinity rho_inf in [0, 1]:
        alpha_m = (2 rho - 1)/(rho + 1), alpha_f = rho/(rho + 1), gamma = 1/2 - alpha_m +
        alpha_f, beta = (1 - alpha_m + alpha_f)^2 / 4 (second order, unconditionally stable,
        high frequencies damped to rho_inf per step)."""
        if not 0.0 <= rho_inf <= 1.0:
            raise SolverError(f"rho_inf = {rho_inf} outside [0, 1]")
        alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0)
        alpha_f = rho_inf / (rho_inf + 1.0)
        gamma = 0.5 - alpha_m + alpha_f
        return cls(dt=dt, t_end=t_end, beta=0.25 * (gamma + 0.5) ** 2, gamma=gamma,
                   alpha_m=alpha_m, alpha_f=alpha_f, **kwargs)

    @property
    def beta_prime(self) -> float:
        """d q''_{n+1} / d q_{n+1} = (1 - alpha_m) / (beta h^2 (1 - alpha_f))."""
        return (1.0 - self.alpha_m) / (self.beta * self.dt**2 * (1.0 - self.alpha_f))

    @property
    def jacobian_code(self) -> int:
        if self.jacobian not in JACOBIAN_POLICIES:
            raise SolverError(f"jacobian policy {self.jacobian!r} must be one of "
                              f"{', '.join(JACOBIAN_POLICIES)}")
        return JACOBIAN_POLICIES[self.jacobian]


@dataclass
class Chunk:
    """Outputs of consecutive steps (one row per step)."""

    time: np.ndarray
    probes: np.ndarray        # (nt, nprobe, 3)
    deflections: np.ndarray   # (nt, nprobe, 3)
    lam: np.ndarray           # (nt, ncon)
    energy: np.ndarray        # (nt, 11): ENERGY_NAMES
    constraint: np.ndarray    # (nt,) max |Phi|
    stats: np.ndarray         # (nt, 3): STAT_NAMES (corrections, factorizations, jacobians)
    q: np.ndarray | None      # (nt, ndof) when stored
    contact: np.ndarray | None = None  # (nt, npoints, 6): CONTACT_FIELDS

    @property
    def newton(self) -> np.ndarray:
        """Newton corrections per step."""
        return self.stats[:, 0]


@dataclass
class DynamicResult:
    """Statistics of a completed run."""

    steps: int
    newton_iterations: int
    factorizations: int
    wall_time_s: float
    timing: dict[str, float] = field(default_factory=dict)
    jacobians: int = 0


def _saddle_solve(model: Model, matrix: sp.spmatrix, rhs_top: np.ndarray,
                  rhs_bottom: np.ndarray, e: np.ndarray, t: float, what: str):
    """Solve [[matrix, -Phi_e^T], [-Phi_e, 0]] [x; lam] = [rhs_top; rhs_bottom]."""
    n, ncon = model.ndof, len(model.constraints)
    _, rows, cols, grads = model.constraints.jacobian(e, n, t)
    coo = matrix.tocoo()
    r = np.concatenate([coo.row, cols, n + rows])
    c = np.concatenate([coo.col, n + rows, cols])
    v = np.concatenate([coo.data, -grads, -grads])
    with DirectSolver(n + ncon, r, c, what=what) as solver:
        solver.factorize(v)
        x = solver.solve(np.concatenate([rhs_top, rhs_bottom]))
    return x[:n], x[n:]


def initial_acceleration(model: Model, e: np.ndarray, v: np.ndarray, t: float):
    """Consistent a(t) and lambda(t) from the equations of motion and Phi_e a = gamma."""
    *_, gamma = model.constraints.evaluate(e, t, v)
    forces = model.forces(e, t, v)
    return _saddle_solve(model, model.mass_matrix(), forces["external"] - forces["internal"],
                         -gamma, e, t, "initial acceleration [[M, -Phi_e^T], [-Phi_e, 0]]")


class TimeIntegrator:
    """The run's constant data and the chunked stepping over the kernel."""

    def __init__(self, model: Model, settings: DynamicSettings) -> None:
        if settings.dt <= 0:
            raise SolverError(f"time step dt = {settings.dt} must be positive")
        model.check_alive()
        settings.jacobian_code  # validates the policy  # noqa: B018
        self.model, self.settings = model, settings
        settings.length_scale = model.length_scale
        self.last_correction = 0.0

    def state(self, t: float, e: np.ndarray, v: np.ndarray, a: np.ndarray,
              lam: np.ndarray) -> dict:
        """A stepper state at t with q'' = a (the generalized-alpha variable starts at a);
        the kernel forgets what it learned in earlier runs, so runs are reproducible."""
        self.model.kernel.reset_stepper()
        return dict(t=t, e=e.copy(), v=v.copy(), a=a.copy(), accel=a.copy(), lam=lam.copy(),
                    work=np.zeros(5), powers=np.zeros(5),
                    guesses=self.model.contact_guesses.copy(),
                    counts=np.zeros(6, dtype=np.int32))

    def advance(self, state: dict, nsteps: int) -> tuple[Chunk, int, int]:
        """Advance ``nsteps`` steps; ``state`` is updated in place. Returns the chunk of
        completed steps, the kernel's info and detail codes."""
        s, m = self.settings, self.model
        out = m.kernel.advance(nsteps, s, state, s.store_q)
        done, info, detail = out["status"]
        self.last_correction = out["last_correction"]
        chunk = Chunk(time=out["time"][:done],
                      probes=np.transpose(out["probes"][:, :m.kernel.nprobe, :done], (2, 1, 0)),
                      deflections=np.transpose(out["deflections"][:, :m.kernel.nprobe, :done],
                                               (2, 1, 0)),
                      lam=out["lam"][:len(m.constraints), :done].T, energy=out["energy"][:, :done].T,
                      constraint=out["constraint"][:done], stats=out["stats"][:, :done].T,
                      q=out["q"][:, :done].T if s.store_q else None,
                      contact=np.transpose(out["contact"][:, :m.npoint, :done], (2, 1, 0))
                      if m.contact_pairs else None)
        return chunk, info, detail

    def failure_message(self, info: int, detail: int, t: float) -> str:
        s = self.settings
        reason = STEP_FAILURES.get(info, f"kernel code {info}").format(max_newton=s.max_newton,
                                                                       detail=detail)
        if info == 1:
            reason += (f" (last correction {self.last_correction:.3e} m, tolerance "
                       f"{s.tol * self.model.length_scale:.3e} m = newton_tol x length; raise "
                       "solver.max_newton or lower solver.dt)")
        return f"time step from t = {t:.6g} s to t = {t + s.dt:.6g} s failed: {reason}"


def initial_row(model: Model, state: dict) -> Chunk:
    """The output row of the initial state, with the kernel's energy definitions; the state
    gets the powers there (the start of the works the stepper integrates)."""
    row = model.kernel.output_row(state["t"], state["e"], state["v"], state["lam"],
                                  state["work"], state["guesses"], state["counts"])
    state["powers"] = row["powers"]
    # copies: the kernel updates the state's arrays in place as it steps on
    return Chunk(time=np.array([state["t"]]), probes=row["probes"][None],
                 deflections=row["deflections"][None], lam=state["lam"][None, :].copy(),
                 energy=row["energy"][None],
                 constraint=np.array([row["violation"]]), stats=np.zeros((1, 3), dtype=np.int64),
                 q=state["e"][None, :].copy(),
                 contact=row["records"].T[None] if model.contact_pairs else None)


def integrate(model: Model, settings: DynamicSettings, e0: np.ndarray,
              v0: np.ndarray | None = None, t0: float = 0.0, *,
              sink: Callable[[Chunk], None] | None = None,
              progress: bool | None = None,
              should_stop: Callable[[], bool] | None = None) -> DynamicResult:
    """Integrate from (t0, e0, v0) to settings.t_end. Each chunk goes to ``sink`` as soon
    as it is computed (the first one holds the initial state). A failed step raises
    SolverError after the completed steps have gone to the sink.

    A kernel call takes at most about 0.25 s of wall time (the first call's time per step
    caps the following ones, never more than settings.chunk_steps), and ``should_stop`` is
    asked after every chunk: when it says True, Interrupted is raised after the sink got
    the chunk, so a stop request (SIGINT) is answered within about a second."""
    model.require_runnable()
    start = time.perf_counter()
    timing = {"setup": 0.0, "stepping": 0.0, "output": 0.0}
    if settings.t_end < t0:
        raise SolverError(f"t_end = {settings.t_end} lies before the start time {t0}")
    v0 = np.zeros(model.ndof) if v0 is None else v0
    integrator = TimeIntegrator(model, settings)
    a0, lam0 = initial_acceleration(model, e0, v0, t0)
    state = integrator.state(t0, e0, v0, a0, lam0)
    timing["setup"] = time.perf_counter() - start
    t1 = time.perf_counter()
    first = initial_row(model, state)
    if sink:
        if not settings.store_q:
            first.q = None
        sink(first)
    timing["output"] += time.perf_counter() - t1
    total = int(round((settings.t_end - t0) / settings.dt))
    show = sys.stderr.isatty() if progress is None else progress
    bar = tqdm(total=round(settings.t_end - t0, 9), unit="s", disable=not show, desc="dynamics",
               bar_format="{l_bar}{bar}| t={n:.3f}/{total:.3f} s [{elapsed}<{remaining}{postfix}]")
    steps = newton = factorizations = jacobians = 0
    call_steps = min(settings.chunk_steps, 10)  # the first call measures a step's cost
    try:
        while steps < total:
            n = min(call_steps, total - steps)
            t_before = state["t"]
            t1 = time.perf_counter()
            chunk, info, detail = integrator.advance(state, n)
            elapsed = time.perf_counter() - t1
            timing["stepping"] += elapsed
            if len(chunk.time):  # calls of at most ~0.25 s: a stop request waits no longer
                call_steps = max(1, min(settings.chunk_steps,
                                        int(0.25 * len(chunk.time) / max(elapsed, 1e-9))))
            steps += len(chunk.time)
            newton += int(chunk.stats[:, 0].sum())
            factorizations += int(chunk.stats[:, 1].sum())
            jacobians += int(chunk.stats[:, 2].sum())
            t1 = time.perf_counter()
            if sink and len(chunk.time):
                sink(chunk)
            timing["output"] += time.perf_counter() - t1
            bar.update(round(state["t"] - t_before, 9))
            bar.set_postfix(steps=steps, newton=newton)
            if info:
                raise SolverError(integrator.failure_message(info, detail, state["t"]))
            if should_stop is not None and should_stop():
                raise Interrupted(f"stopped at t = {state['t']:.6g} s after {steps} steps")
    finally:  # the counters hold what was done, also when a step failed
        bar.close()
        model.counters["time_steps"] += steps
        model.counters["newton_iterations"] += newton
        model.counters["solves"] += newton
        model.counters["factorizations"] += factorizations
        model.counters["jacobian_evaluations"] += jacobians
        if model.contact_pairs:
            for name, count in zip(CONTACT_COUNTERS, state["counts"]):
                model.counters[name] += int(count)
            model.contact_guesses = state["guesses"].copy()
    wall = time.perf_counter() - start
    timing["total"] = wall
    return DynamicResult(steps=steps, newton_iterations=newton, factorizations=factorizations,
                         wall_time_s=wall, timing=timing, jacobians=jacobians)


__all__ = ["DynamicSettings", "Chunk", "DynamicResult", "TimeIntegrator", "integrate",
           "initial_acceleration", "initial_row", "ENERGY_NAMES", "CONTACT_FIELDS", "STAT_NAMES"]
