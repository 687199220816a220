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

Step-size control (issue 26) is the kernel's too (``fortran/src/solvers/step_control.f90``):
the output stays on the user's grid t0 + k dt, every row landed on exactly. With
``step = 'fixed'`` the kernel steps whole chunks at dt; a step that fails (Newton diverges or
stalls, the state turns non-finite, a linear solve or the contact search fails) is retried
from its start with half the step, down to ``dt_min``, and the step doubles back after four
successes in a row; a failure at dt_min ends the run (SolverError, exit 3), and a Newton
stall at the round-off floor with a tolerance below what double precision resolves is not
retried. With ``step = 'adaptive'`` every step is sized by the local error estimate of
Zienkiewicz & Xie (1991) to ``tolerance`` (bounded by dt and dt_min), with the same cuts;
a step at dt_min whose estimate exceeds the tolerance ends the run (SolverError, exit 3).
At each change of the step the method restarts from the consistent acceleration
(:func:`initial_acceleration`'s kernel routine). A call tries a bounded number of steps, so
``should_stop`` is asked at least every ~0.25 s, also inside an output interval.
"""
from __future__ import annotations

import functools
import sys
import time
from dataclasses import field
from typing import Callable

import numpy as np

from ..records import record
from ..codes import (CONTACT_COUNTERS, CONTACT_RECORD, ENERGY_NAMES, JACOBIAN_ITERATION,
                     JACOBIAN_REUSE, JACOBIAN_STEP, KERNEL_LAYOUTS, STAT_NAMES)
from ..errors import InputError, Interrupted, SolverError, UnstableError
from ..io.validate import check_arguments, check_state
from ..kernel import _text as kernel_text
from ..system.model import Model
from .assumptions import FFR_LIMIT, check_ffr, ffr_departure_rows

#: what a contact record (per point and step) holds
CONTACT_FIELDS = CONTACT_RECORD
JACOBIAN_POLICIES = {"step": JACOBIAN_STEP, "iteration": JACOBIAN_ITERATION,
                     "reuse": JACOBIAN_REUSE}


@record(eq=False)
class DynamicSettings:
    """Integrator settings (``&solver`` and ``&output`` of a scene). Newmark is
    alpha_m = alpha_f = 0; :meth:`generalized_alpha` sets all four from rho_inf.
    ``jacobian``: when a refactorized model's iteration matrix is refreshed ('step',
    'iteration', 'reuse'; default 'reuse', the default of scenes and of ``ancf run``);
    ``contraction``: the reuse policy's limit on the ratio of successive corrections. The
    kernel's stepper takes these settings once per run (:meth:`TimeIntegrator.state`);
    change them between runs, not between chunks."""

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
    jacobian: str = "reuse"
    contraction: float = 0.25
    length_scale: float = 1.0
    #: the smallest step a failed step may be cut to (0: dt / 1024)
    dt_min: float = 0.0
    #: 'fixed' (dt, cut where a step fails) or 'adaptive' (sized by the local error estimate)
    step: str = "fixed"
    #: step = 'adaptive': the local error allowed per step, relative to the length scale
    tolerance: float = 1e-6
    #: jacobian = 'reuse': 'rotation' carries the iteration matrix with the system's
    #: rotation where that is exact (Model.carry_vectors), 'off' reuses it unturned
    carry: str = "rotation"
    #: the energy the integrator may make, relative to the run's energy scale, before the
    #: run ends as unstable (:class:`EnergyWatch`)
    energy_tolerance: float = 0.01
    #: the output rows carry the answers' kernel part (``fortran/src/solvers/
    #: row_answers.f90``: the force elements' reactions, the residual at the eliminated
    #: joints' coordinates) for :class:`~ancfdrv.system.answers.DynamicAnswers`
    answers: bool = False
    #: 'newmark' and 'generalized_alpha' (the kernel's alpha method with beta, gamma
    #: and the alphas) or 'energy_momentum' (the midpoint rule with a discrete gradient:
    #: ``fortran/src/solvers/energy_momentum.f90``; beta, gamma and the alphas unused)
    integrator: str = "newmark"

    @property
    def smallest_step(self) -> float:
        """dt_min, or dt / 1024 when it is 0 (the default)."""
        return self.dt_min if self.dt_min > 0 else self.dt / 1024.0

    @classmethod
    def generalized_alpha(cls, dt: float, t_end: float, rho_inf: float,
                          **kwargs) -> "DynamicSettings":
        """Chung-Hulbert parameters for the spectral radius at infinity rho_inf in [0, 1]:
        alpha_m = (2 rho - 1)/(rho + 1), alpha_f = rho/(rho + 1), gamma = 1/2 - alpha_m +
        alpha_f, beta = (1 - alpha_m + alpha_f)^2 / 4 (second order, unconditionally stable,
        high frequencies damped to rho_inf per step)."""
        if not 0.0 <= rho_inf <= 1.0:
            raise InputError(f"rho_inf = {rho_inf} outside [0, 1]", group="solver",
                             key="rho_inf")
        alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0)
        alpha_f = rho_inf / (rho_inf + 1.0)
        gamma = 0.5 - alpha_m + alpha_f
        return cls(dt=dt, t_end=t_end, integrator="generalized_alpha",
                   beta=0.25 * (gamma + 0.5) ** 2, gamma=gamma, alpha_m=alpha_m,
                   alpha_f=alpha_f, **kwargs)

    @property
    def beta_prime(self) -> float:
        """d q''_{n+1} / d q_{n+1} = (1 - alpha_m) / (beta h^2 (1 - alpha_f))."""
        return (1.0 - self.alpha_m) / (self.beta * self.dt**2 * (1.0 - self.alpha_f))

    @property
    def jacobian_code(self) -> int:
        if self.jacobian not in JACOBIAN_POLICIES:
            raise InputError(f"jacobian policy {self.jacobian!r} must be one of "
                             f"{', '.join(JACOBIAN_POLICIES)}", group="solver", key="jacobian")
        return JACOBIAN_POLICIES[self.jacobian]


@record(eq=False, repr=False)
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
    #: (nt, nanswer) with DynamicSettings.answers: per force element its reactions (force,
    #: moment, axial), then the residual at the eliminated joints' coordinates
    answers: np.ndarray | None = None
    #: per row: the smallest step taken to reach it (s; 0 for the initial row), the steps
    #: taken and the step cuts in its interval (None: one step of the grid's size, no cut)
    step_size: np.ndarray | None = None
    substeps: np.ndarray | None = None
    cuts: np.ndarray | None = None
    #: the kernel's rows the row fields are views of: (rows (nt, row_size), the number of
    #: columns before q, the fields made from them {name: array}, a function making those
    #: fields from any (nt, that number) array); a writer that keeps the fields without q
    #: copies the rows' first columns once (hdf5.thinned_chunk) instead of each field
    rows: tuple | None = field(default=None, repr=False, compare=False)

    @property
    def newton(self) -> np.ndarray:
        """Newton corrections per step."""
        return self.stats[:, 0]


@record(eq=False)
class DynamicResult:
    """Statistics of a completed run."""

    steps: int
    newton_iterations: int
    factorizations: int
    wall_time_s: float
    timing: dict[str, float] = field(default_factory=dict)
    jacobians: int = 0
    #: step control (issue 26): failed steps retried with a smaller step, steps rejected by
    #: the error estimate, steps taken (grid steps and their substeps), the smallest step,
    #: steps whose Newton iteration converged at the round-off floor
    step_cuts: int = 0
    steps_rejected: int = 0
    steps_taken: int = 0
    smallest_step: float = 0.0
    floor_accepts: int = 0


class _NoBar:
    """The progress bar of a run that shows none (tqdm and its imports not loaded: ~1 MB)."""

    def update(self, _n: float) -> None:
        pass

    def set_postfix(self, **_values) -> None:
        pass

    def close(self) -> None:
        pass


def _progress_bar(show: bool, total: float):
    """tqdm's bar over the simulated time when shown, else a bar that does nothing."""
    if not show:
        return _NoBar()
    from tqdm import tqdm
    return tqdm(total=total, unit="s", desc="dynamics",
                bar_format="{l_bar}{bar}| t={n:.3f}/{total:.3f} s [{elapsed}<{remaining}{postfix}]")


def initial_acceleration(model: Model, e: np.ndarray, v: np.ndarray, t: float):
    """Consistent a(t) and lambda(t) from the equations of motion and Phi_e a = gamma: the
    kernel's saddle solve (``fortran/src/solvers/consistent_start.f90``), the one the
    stepper's restarts use. The contact guesses start from and update the model's."""
    out = model.kernel.consistent_acceleration(t, e, v, model.contact_guesses,
                                               model.contact_counts)
    model.contact_guesses, model.contact_counts = out["guesses"], out["counts"]
    model.count_consistent_accelerations(1)
    return out["accel"], out["lam"]


class TimeIntegrator:
    """The run's constant data and the chunked stepping over the kernel."""

    def __init__(self, model: Model, settings: DynamicSettings) -> None:
        if settings.dt <= 0:
            raise InputError(f"time step dt = {settings.dt} must be positive", group="solver",
                             key="dt")
        model.check_alive()
        settings.jacobian_code  # validates the policy  # noqa: B018
        if settings.step not in ("fixed", "adaptive"):
            raise InputError(f"step {settings.step!r} must be 'fixed' or 'adaptive'",
                             group="solver", key="step")
        self.model, self.settings = model, settings
        settings.length_scale = model.length_scale
        self.floor_accepts = 0   # steps converged at the round-off floor (all calls)
        self.failure_text = ""   # the kernel's text of the last failed step
        #: the last call's status and figures (codes.KERNEL_LAYOUTS 'as', 'af')
        self.status = [0] * len(KERNEL_LAYOUTS["as"])
        self.figures = np.zeros(len(KERNEL_LAYOUTS["af"]))

    def state(self, t: float, e: np.ndarray, v: np.ndarray, a: np.ndarray,
              lam: np.ndarray) -> dict:
        """A stepper state at t with q'' = a (the generalized-alpha variable starts at a):
        the start of a run. The kernel's stepper gets the run's settings and forgets what it
        learned in earlier runs, so runs are reproducible."""
        if self.settings.carry not in ("rotation", "off"):
            raise InputError(f"carry {self.settings.carry!r} must be 'rotation' or 'off'",
                             group="solver", key="carry")
        self.model.kernel.set_carry(self.model.carry_vectors()
                                    if self.settings.carry == "rotation" else None)
        self.model.kernel.stepper_setup(self.settings)
        if self.settings.answers:
            from ..system.answers import answer_inputs
            self.model.kernel.answer_setup(*answer_inputs(self.model))
        # one packed buffer the kernel steps in place (kernel.PackedState): its arrays are
        # views, changed by the next call
        return self.model.kernel.packed_state(dict(
            t=t, e=e, v=v, a=a, accel=a, lam=lam, work=np.zeros(5), powers=np.zeros(5),
            guesses=self.model.contact_guesses.copy(), counts=np.zeros(6, dtype=np.int32)))

    def advance(self, state: dict, nrows: int, budget: int | None = None
                ) -> tuple[Chunk, int, int]:
        """Advance up to ``nrows`` output rows with at most ``budget`` steps tried (default
        1024 per row) under the kernel's step-size control
        (``fortran/src/solvers/step_control.f90``); ``state`` is updated in place (an
        output interval the budget ended inside is resumed by the next call). Returns the
        chunk of completed rows, the kernel's info and detail codes (:meth:`failure_message`
        says a failure in words; the kernel's status and figures are kept in ``status`` and
        ``figures``)."""
        s, m = self.settings, self.model
        kernel = m.kernel
        rows, stats, sizes, self.status, self.figures, message = kernel.advance_rows(
            nrows, 1024 * nrows if budget is None else budget, state, s.store_q)
        done, info, detail = self.status[:3]
        self.failure_text = kernel_text(message) if info else ""
        self.floor_accepts += self.status[_STATUS["floor_accepts"]]
        _, probes, deflections, lam, energy, constraint, contact, answers, q = \
            kernel.row_slices(s.store_q)
        cols = rows.T[:done]     # (done, row_size): one row per output time
        made = functools.partial(_row_fields, cuts=(probes, deflections, lam, energy,
                                                    constraint, contact),
                                 nprobe=kernel.nprobe,
                                 npoint=m.npoint if m.contact_pairs else -1)
        fields = made(cols)
        counts = stats[:, :done].T
        chunk = Chunk(**fields, stats=counts[:, :3], q=cols[:, q] if s.store_q else None,
                      answers=cols[:, answers] if s.answers else None,
                      rows=(cols, q.start, fields, made), step_size=sizes[:done],
                      substeps=counts[:, 3], cuts=counts[:, 4])
        return chunk, info, detail

    def control_counts(self) -> dict[str, int]:
        """The run's step-size control so far (the last call's status): step cuts, steps
        rejected by the error estimate, restarts, steps taken."""
        return {name: int(self.status[_STATUS[name]])
                for name in ("cuts", "rejected", "restarts", "taken")}

    @property
    def failed_work(self) -> np.ndarray:
        """The work of a failed call's failed tries the run counts (corrections,
        factorizations, Jacobian evaluations)."""
        return np.array(self.status[_STATUS["failed_corrections"]:
                                    _STATUS["failed_jacobians"] + 1], dtype=np.int64)

    def failure_message(self, info: int, detail: int) -> str:
        """The failure of the last call in words, with the scene keys that help."""
        s = self.settings
        t = float(self.figures[_FIGURES["failure_t"]])
        h = float(self.figures[_FIGURES["failure_h"]])
        if info == CONTROL_TRIES:
            halvings = int(np.ceil(np.log2(max(s.dt / s.smallest_step, 1.0))))
            return (f"step-size control: {self.status[_STATUS['failure_tries']]} tries in a "
                    f"row from t = {t:.6g} s without an accepted step (halving dt = "
                    f"{s.dt:.3g} s to solver.dt_min = {s.smallest_step:.3g} s takes "
                    f"{halvings}); the run stops")
        if info == CONTROL_TOLERANCE:
            allowed = s.tolerance * s.length_scale
            return (f"time step {_interval(t, h)}: its local error "
                    f"estimate exceeds solver.tolerance x length = {allowed:.3g} m even at "
                    f"the smallest step, solver.dt_min = {s.smallest_step:.3g} s: the "
                    "tolerance cannot be met; raise solver.tolerance or lower solver.dt_min")
        if info == CONTROL_RESTART:
            return f"the restart of the method at t = {t:.6g} s failed: {self.failure_text}"
        # what failed, in the kernel's words (time_integrator step_failure_text); the
        # scene keys that help, here
        reason = self.failure_text or f"kernel code {info} (detail {detail})"
        if info == 1:
            last = float(self.figures[_FIGURES["last_correction"]])
            reason += (f" (last correction {last:.3e} m, tolerance "
                       f"{s.tol * self.model.length_scale:.3e} m = newton_tol x length")
            if detail == NEWTON_FLOOR_STALL:
                reason += ("; the corrections cannot fall below the round-off of the "
                           "coordinates: raise solver.newton_tol)")
            else:
                reason += "; raise solver.max_newton or lower solver.dt_min)"
        cuts = self.status[_STATUS["failure_cuts"]]
        if cuts:
            reason += (f"; the step was cut {cuts} times, the last from {2 * h:.3g} s to "
                       f"{h:.3g} s, and solver.dt_min = {s.smallest_step:.3g} s allows no "
                       "smaller one")
            reason += _rope_advice(self.model, s)
        return f"time step {_interval(t, h)} failed: {reason}"


def _rope_advice(model, settings: DynamicSettings) -> str:
    """What helps a run with tension-only ropes whose step failed however small it was cut,
    unless its method already damps unresolved modes fully (rho_inf = 0): a rope that goes
    slack and taut faster than the step resolves excites its axial modes (a light rope's
    reach some 1e4 rad/s), and only full numerical damping of them steadies the iteration.
    Measured (docs/hard-cases.md): the knuckle crane without its payload fails at t = 2.03 s
    at rho_inf 0.8 (dt 5e-3, cut to dt_min; 0.97 s before the kept matrix's contraction
    check), and at dt 1e-3 grinds through cuts; at rho_inf 0 it runs; the rope's throw and drop are right at
    rho_inf 0 at both grid steps and refused at 0.8 and 1."""
    ropes = [b.name for b in model.bodies if getattr(b, "tension_only", False)]
    full_damping = settings.integrator == "generalized_alpha" and settings.alpha_f == 0.0
    if not ropes or full_damping:
        return ""
    return (f"; the model's tension-only rope{'s' if len(ropes) > 1 else ''} "
            f"{', '.join(repr(n) for n in ropes)} can switch between slack and taut faster "
            "than any step resolves: solver.rho_inf = 0 damps the axial modes this excites "
            "(generalized-alpha; docs/hard-cases.md)")


def _interval(t: float, h: float) -> str:
    """'from t = A s to t = B s' for the step of size ``h`` from ``t``, A and B with six
    significant digits or as many more as they need to differ (six alone printed a step of
    9.77e-07 s at t = 6.207 s as 'from t = 6.207 s to t = 6.207 s'), and the step's size
    when six did not tell it."""
    digits = 6
    while digits < 17 and f"{t:.{digits}g}" == f"{t + h:.{digits}g}":
        digits += 1
    text = f"from t = {t:.{digits}g} s to t = {t + h:.{digits}g} s"
    return text if digits == 6 else f"{text} (a step of {h:.3g} s)"


def _row_fields(cols: np.ndarray, cuts: tuple, nprobe: int, npoint: int) -> dict:
    """A chunk's row fields (time, probes, deflections, lam, energy, constraint, contact)
    as views of rows ``cols`` (nt, at least up to q) cut at the layout's slices ``cuts``
    (probes, deflections, lam, energy, constraint, contact); ``npoint`` < 0: no contact."""
    probes, deflections, lam, energy, constraint, contact = cuts
    done = len(cols)
    return dict(time=cols[:, 0], probes=cols[:, probes].reshape(done, nprobe, 3),
                deflections=cols[:, deflections].reshape(done, nprobe, 3),
                lam=cols[:, lam], energy=cols[:, energy], constraint=cols[:, constraint.start],
                contact=cols[:, contact].reshape(done, npoint, len(CONTACT_RECORD))
                if npoint >= 0 else None)


#: why a step's Newton iteration ended unconverged (time_integrator's newton_* codes; the
#: kernel's message says it in words)
NEWTON_LIMIT, NEWTON_FLOOR_STALL, NEWTON_STALL, NEWTON_DIVERGED = 0, 1, 2, 3
#: the step-size control's own failures (step_control.f90 control_*): tries in a row without
#: an accepted step, the error estimate above the tolerance at dt_min, a failed restart
CONTROL_TRIES, CONTROL_TOLERANCE, CONTROL_RESTART = 11, 12, 13
#: the positions in a controlled advance's status and figures (system_advance)
_STATUS = {name: i for i, name in enumerate(KERNEL_LAYOUTS["as"])}
_FIGURES = {name: i for i, name in enumerate(KERNEL_LAYOUTS["af"])}


class EnergyWatch:
    """The energy balance over a run (ENERGY_NAMES: total - total(0) - the works of drives,
    frames, contact damping, friction, material damping): the most energy the integrator
    made, against the run's energy scale. The methods dissipate (rho_inf < 1) or conserve
    energy to their order; a rise is instability. A run is unstable (:meth:`unstable`) when
    the largest balance exceeds ``tolerance`` times the scale.

    The scale is the run's own energy flow: the largest, over the rows, of the kinetic
    energy, the change of the potential energies (strain, loads, moments) from t = 0, the
    kinetic plus strain energy (what the structure holds: a run resting in a prestressed
    state holds its strain energy) and the magnitudes of the works, each row's less the
    energy made by then (its positive balance): the energy made is not measured against
    itself (at the end of a blown-up run the kinetic energy is mostly made energy, and the
    ratio read "100 %" whatever was made: 25 kJ on a 70 J pendulum). Never less than
    ``floor``, the integrator's own resolution (:func:`energy_floor`), so a run at rest,
    whose energies are all round-off (1e-26 J), never counts its balance as made energy.

    Measured a chunk at a time, row by row in numpy (no loop over the rows): the records of
    the balance (each new largest value 1 % above the last kept) give the time at which it
    first exceeded a level (:meth:`message`)."""

    #: the works among ENERGY_NAMES (drives, frames, contact damping, friction, damping)
    WORKS = (5, 6, 8, 9, 10)
    #: chunks wait until this many rows (90 kB of energies) are there, or until a figure is
    #: asked: the ~20 numpy calls of a measurement are then made once for many chunks (a
    #: chunk of a single step under step control paid ~25 us for them)
    WAIT_ROWS = 1024
    #: the records of the balance kept: each a factor RECORD_STEP above the last
    RECORD_STEP = 1.01

    def __init__(self, first: np.ndarray, tolerance: float = 0.01, floor: float = 0.0) -> None:
        self.first = first.copy()
        self.tolerance, self.floor = float(tolerance), float(floor)
        self._most, self._scale = 0.0, 0.0
        #: the time of the last row measured
        self.last_time = 0.0
        #: (times, balances) of the balance's records, and the last record's bucket
        self._records: list[tuple[np.ndarray, np.ndarray]] = []
        self._bucket = -np.inf
        #: chunks' energy columns (11, rows) and times waiting to be measured together
        self._waiting: list[tuple[np.ndarray, np.ndarray]] = []
        self._waiting_rows = 0

    def add(self, energy: np.ndarray, time: np.ndarray) -> None:
        """A chunk's energy rows (rows, 11) at its times (rows,)."""
        # the chunk's columns copied contiguous once (they are strided views of the
        # kernel's rows: each operation on them was a strided loop), and the times: always
        # copies (ascontiguousarray returns a single row's columns, asarray the times, as
        # the views they are), since a view keeps the kernel's whole row buffer (mostly q)
        # alive while the chunk waits: up to WAIT_ROWS rows, the 512-element cantilever's
        # whole run (16 MB)
        self._waiting.append((np.array(energy.T, order="C"), np.array(time, dtype=float)))
        self._waiting_rows += len(energy)
        if self._waiting_rows >= self.WAIT_ROWS:
            self.measure()

    def measure(self) -> None:
        """Measure the waiting chunks at once (maxima and records over rows: the figures
        are those of measuring each chunk on arrival)."""
        waiting, self._waiting, self._waiting_rows = self._waiting, [], 0
        if not waiting:
            return
        if len(waiting) == 1:
            columns, times = waiting[0]
        else:
            columns = np.concatenate([w[0] for w in waiting], axis=1)
            times = np.concatenate([w[1] for w in waiting])
        if not len(times):
            return
        works = columns[5] + columns[6] + columns[8] + columns[9] + columns[10]
        balance = columns[4] - self.first[4] - works
        potential = columns[1] + columns[2] + columns[3] - self.first[1:4].sum()
        flow = np.fmax.reduce(np.abs(np.stack([columns[0], potential, columns[0] + columns[1],
                                               *columns[list(self.WORKS)]])), axis=0)
        made = np.fmax(balance, 0.0)
        self._scale = max(self._scale, float(np.fmax.reduce(flow - made)))
        self._most = max(self._most, float(np.fmax.reduce(balance)))
        self.last_time = float(times[-1])
        # the records: the first row of each new bucket of log(balance) / log(RECORD_STEP)
        positive = balance > 0.0
        if positive.any():
            bucket = np.full(len(balance), -np.inf)
            bucket[positive] = np.floor(np.log(balance[positive]) / np.log(self.RECORD_STEP))
            top = np.fmax.accumulate(np.fmax(bucket, self._bucket))
            rising = np.flatnonzero(bucket > np.concatenate([[self._bucket], top[:-1]]))
            if len(rising):
                self._records.append((times[rising], balance[rising]))
                self._bucket = float(top[-1])

    @property
    def most(self) -> float:
        """The largest balance so far (J; the waiting chunks measured first)."""
        self.measure()
        return self._most

    @property
    def scale(self) -> float:
        """The run's energy scale so far (J; the waiting chunks measured first), at least
        the floor."""
        self.measure()
        return max(self._scale, self.floor)

    def created(self) -> float:
        """The largest balance so far relative to the energy scale."""
        return self.most / self.scale if self.scale > 0 else 0.0

    def unstable(self) -> bool:
        """Whether the energy made exceeds the tolerance (the rows so far)."""
        return self.created() > self.tolerance

    def runaway(self) -> bool:
        """Whether the energy made already exceeds the whole scale (the rows measured so
        far, the waiting ones not: cheap to ask after every chunk). Such a run cannot end
        within the tolerance however its scale grows later: its rows from then on are the
        instability's, and it is stopped there instead of run on (a blown-up payload on a
        rope ran 548 s)."""
        return self._most > max(self._scale, self.floor)

    def first_above(self, level: float) -> float:
        """The time at which the balance first exceeded ``level`` (within RECORD_STEP)."""
        for times, values in self._records:
            above = np.flatnonzero(values > level)
            if len(above):
                return float(times[above[0]])
        return self.last_time

    def message(self, where: str = "") -> str:
        """Why the run is unstable: when the energy grew, how much, where (``where``: the
        words of :func:`where_energy_grew`, '' for none) and what to change."""
        scale = self.scale
        level = self.tolerance * scale
        where = f"; {where}" if where else ""
        return (f"the energy grew with no work to explain it: the balance (total - total(0) "
                f"- works) exceeded solver.energy_tolerance = {self.tolerance:g} of the run's "
                f"energy scale ({scale:.4g} J) at t = {self.first_above(level):.6g} s and "
                f"reached {self.most:.4g} J ({self.created():.3g} times the scale) by t = "
                f"{self.last_time:.6g} s{where}: the integrator's numerical instability, not the "
                "physics (the rows computed are kept). Take solver.rho_inf < 1 (numerical "
                "damping of the modes the step does not resolve), a smaller solver.dt, or a "
                "mesh whose highest modes the step resolves")


def kinetic_by_body(model: Model, v: np.ndarray) -> np.ndarray:
    """Each body's share (model.bodies' order) of the kinetic energy 1/2 v^T M v at the
    velocities v (solved coordinates): 1/2 sum of v_i (M v)_i over the coordinates i it owns
    (a reduced coordinate is its independent full coordinate's body), exact for each body
    where the mass matrix couples no two bodies; the shares sum to the total."""
    terms = 0.5 * v * model.mass.matvec(v)
    full = (np.arange(model.ndof) if model.reduction is None
            else np.asarray(model.reduction.independent))
    owner = np.full(max(len(model.q0), int(full.max(initial=-1)) + 1), len(model.bodies))
    for k, body in enumerate(model.bodies):
        owner[body.first:body.first + body.ncoordinates] = k
    return np.bincount(owner[full], weights=terms, minlength=len(model.bodies) + 1)[:-1]


def where_energy_grew(model: Model, v0: np.ndarray, t: float, v: np.ndarray) -> str:
    """Where a run's energy grew (the unstable run's message): the body whose kinetic
    energy (:func:`kinetic_by_body`) rose most from the start (v0) to the state (t, v) the
    run ended at, with its share of the rise ('' without bodies)."""
    if not model.bodies:
        return ""
    start, end = kinetic_by_body(model, v0), kinetic_by_body(model, v)
    rise = end - start
    k = int(np.argmax(rise))
    total = float(np.fmax(rise, 0.0).sum())
    share = f", {rise[k] / total:.0%} of the bodies' rise" if len(rise) > 1 and total > 0 else ""
    return (f"the kinetic energy grew most in body '{model.bodies[k].name}' ({start[k]:.4g} J at "
            f"the start, {end[k]:.4g} J at t = {t:.6g} s{share})")


def energy_floor(model: Model, settings: DynamicSettings) -> float:
    """The smallest energy the integrator resolves: the kinetic energy 1/2 u^T M u of a
    velocity error u of newton_tol x length / dt on every coordinate (the velocity of the
    position error a step accepts), trace(M) / 2 (newton_tol L / dt)^2. A balance below it
    is no measurement of energy made (a run at rest: energies of 1e-26 J; the flexible
    pendulum at dt = 5e-4: 3.5e-13 J)."""
    mass = model.mass
    trace = float(mass.data[mass.indices == mass.row_index()].sum())
    return 0.5 * trace * (settings.tol * model.length_scale / settings.dt) ** 2


def initial_row(model: Model, state: dict) -> Chunk:
    """The output row of the initial state, with the kernel's energy definitions; the state
    gets the powers there (the start of the works the stepper integrates)."""
    # (a copy of the guesses: output_row updates them in place, and the state's are the
    # stepper's packed buffer; the contact counters count the row's evaluations, as before)
    row = model.kernel.output_row(state["t"], state["e"], state["v"], state["lam"],
                                  state["work"], np.array(state["guesses"], order="F"),
                                  state["counts"])
    state["powers"] = row["powers"]
    answers = None
    if getattr(model.kernel, "nanswer", 0):   # the run's rows answer (DynamicSettings.answers)
        answers = model.kernel.answer_row(state["t"], state["e"], state["v"], state["accel"],
                                          state["guesses"])[None]
    # copies: the kernel updates the state's arrays in place as it steps on
    return Chunk(answers=answers, time=np.array([state["t"]]), probes=row["probes"][None],
                 deflections=row["deflections"][None], lam=state["lam"][None, :].copy(),
                 energy=row["energy"][None],
                 constraint=np.array([row["violation"]]), stats=np.zeros((1, 3), dtype=np.int64),
                 q=state["e"][None, :].copy(),
                 contact=row["records"].T[None] if model.contact_pairs else None)


#: the most bytes of output rows one kernel call returns (:func:`call_rows`). The rows
#: of a call are a fresh array, mostly q when the chunks carry it: 0.25 s of steps of the
#: 512-element cantilever (2052 unknowns) were 3.5 MB, and the peak resident set rose with
#: the speed of the machine (issue 23: a run's peak memory, 78 -> 71 MB there).
ROW_BUFFER_BYTES = 1 << 19


def call_rows(model: Model, settings: DynamicSettings) -> int:
    """The most steps one kernel call takes: its rows within :data:`ROW_BUFFER_BYTES`
    (at least one). The chunks' sizes do not change the results: the stepper carries
    its whole state from call to call."""
    return max(1, ROW_BUFFER_BYTES // (8 * model.kernel.row_size(settings.store_q)))


def integrate(model: Model, settings: DynamicSettings, e0: np.ndarray,
              v0: np.ndarray | None = None, t0: float = 0.0, *,
              sink: Callable[[Chunk], None] | None = None,
              progress: bool | None = None,
              should_stop: Callable[[], bool] | None = None,
              initial: tuple[np.ndarray, np.ndarray] | None = None) -> DynamicResult:
    """Integrate from (t0, e0, v0) to settings.t_end. Each chunk goes to ``sink`` as soon
    as it is computed (the first one holds the initial state). A failed step raises
    SolverError after the completed steps have gone to the sink. ``initial``: the
    consistent (a0, lambda0) of :func:`initial_acceleration` at (t0, e0, v0) when the
    caller computed them already (not solved again).

    A kernel call takes at most about 0.25 s of wall time (the first call's time per step
    caps the following ones, never more than settings.chunk_steps nor :func:`call_rows`
    steps), and ``should_stop`` is asked after every chunk: when it says True,
    Interrupted is raised after the sink got the chunk, so a stop request (SIGINT) is
    answered within about a second."""
    check_arguments("integrate", dt=settings.dt, t_end=settings.t_end, tol=settings.tol,
                    max_newton=settings.max_newton, chunk_steps=settings.chunk_steps, t0=t0,
                    dt_min=settings.dt_min)
    e0 = check_state("integrate", "e0", e0, model.ndof)
    v0 = None if v0 is None else check_state("integrate", "v0", v0, model.ndof)
    model.require_runnable()
    start = time.perf_counter()
    timing = {"setup": 0.0, "stepping": 0.0, "output": 0.0}
    if settings.t_end < t0:
        raise InputError(f"t_end = {settings.t_end} lies before the start time {t0}",
                         group="solver", key="t_end")
    v0 = np.zeros(model.ndof) if v0 is None else v0
    v_start = v0.copy()   # (where the energy grew, should the run be unstable)
    integrator = TimeIntegrator(model, settings)
    a0, lam0 = initial_acceleration(model, e0, v0, t0) if initial is None else initial
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
    bar = _progress_bar(show, round(settings.t_end - t0, 9))
    steps = newton = factorizations = jacobians = 0
    row_cap = call_rows(model, settings)
    # the first call measures a step's cost
    call_steps = min(settings.chunk_steps, 10, row_cap)
    energy_watch = EnergyWatch(first.energy[0], settings.energy_tolerance,
                               energy_floor(model, settings))
    try:
        while steps < total:
            t_before = state["t"]
            t1 = time.perf_counter()
            # rows within the call's budget of steps tried (all of them at dt unless a step
            # is cut or sized by the error estimate)
            chunk, info, detail = integrator.advance(state, min(call_steps, total - steps),
                                                     call_steps)
            elapsed = time.perf_counter() - t1
            tries = integrator.status[_STATUS["tries"]]
            if tries:  # calls of at most ~0.25 s: a stop request waits no longer
                call_steps = max(1, min(settings.chunk_steps, row_cap,
                                        int(0.25 * tries / max(elapsed, 1e-9))))
            pending = SolverError(integrator.failure_message(info, detail)) if info else None
            timing["stepping"] += elapsed
            steps += len(chunk.time)
            # (the three columns' sums in one reduction: integers, exact either way)
            totals = np.add.reduce(chunk.stats, axis=0)
            newton += int(totals[0])
            factorizations += int(totals[1])
            jacobians += int(totals[2])
            chunk, outside = _check_assumptions(model, chunk, state, pending is not None)
            if len(chunk.time):
                energy_watch.add(chunk.energy, chunk.time)
            t1 = time.perf_counter()
            if sink and len(chunk.time):
                sink(chunk)
            timing["output"] += time.perf_counter() - t1
            bar.update(round(state["t"] - t_before, 9))
            bar.set_postfix(steps=steps, newton=newton)
            if outside:
                raise SolverError(outside)
            if pending is not None:
                failed = integrator.failed_work
                newton += int(failed[0])
                factorizations += int(failed[1])
                jacobians += int(failed[2])
                raise pending
            if energy_watch.runaway():  # the rows are in the sink: the run ends here
                raise UnstableError(energy_watch.message(
                    where_energy_grew(model, v_start, state["t"], state["v"])))
            if should_stop is not None and should_stop():
                raise Interrupted(f"stopped at t = {state['t']:.6g} s after {steps} steps")
        if energy_watch.unstable():
            raise UnstableError(energy_watch.message(
                where_energy_grew(model, v_start, state["t"], state["v"])))
    finally:  # the counters hold what was done, also when a step failed
        bar.close()
        control = integrator.control_counts()
        model.counters["time_steps"] += steps
        model.counters["newton_iterations"] += newton
        model.counters["solves"] += newton
        model.counters["factorizations"] += factorizations
        model.counters["jacobian_evaluations"] += jacobians
        # (each restart evaluated the forces and constraints for its consistent acceleration)
        model.count_consistent_accelerations(control["restarts"])
        for name, count in (("step_cuts", control["cuts"]),
                            ("steps_rejected", control["rejected"]),
                            ("step_restarts", control["restarts"]),
                            ("steps_taken", control["taken"]),
                            ("newton_floor_accepts", integrator.floor_accepts)):
            model.counters[name] = model.counters.get(name, 0) + int(count)
        if model.contact_pairs:
            for name, count in zip(CONTACT_COUNTERS, state["counts"]):
                model.counters[name] += int(count)
            model.contact_guesses = state["guesses"].copy()
    wall = time.perf_counter() - start
    timing["total"] = wall
    return DynamicResult(steps=steps, newton_iterations=newton, factorizations=factorizations,
                         wall_time_s=wall, timing=timing, jacobians=jacobians,
                         step_cuts=control["cuts"], steps_rejected=control["rejected"],
                         steps_taken=control["taken"],
                         smallest_step=float(integrator.figures[_FIGURES["smallest"]])
                         if control["taken"] else 0.0,
                         floor_accepts=integrator.floor_accepts)


def _check_assumptions(model: Model, chunk: Chunk, state: dict,
                       info: bool) -> tuple[Chunk, str]:
    """(the rows to keep, why the run stops or ''): an 'ffr' beam that leaves its
    small-strain assumption (solvers.assumptions) stops the run at the first row that does
    when the chunk holds q (the rows after it dropped), else at the chunk's last state."""
    if not any(s.floating for s in model.sets) or not len(chunk.time):
        return chunk, ""
    if chunk.q is not None:  # every row at once; the first row outside ends the run
        # q in one contiguous copy (a view of the kernel's rows, strided by the row's
        # length): the kernel's check and the answers' kernel calls then read it in place
        # instead of copying it each (the FFR boom's chunk: 486 kB, three times)
        chunk.q = np.ascontiguousarray(chunk.q)
        outside = np.zeros(len(chunk.time), dtype=bool)
        for _, change in ffr_departure_rows(model, chunk.q, chunk.time):
            outside |= ~(change <= FFR_LIMIT)      # beyond the limit, or not finite
        if not outside.any():
            return chunk, ""
        row = int(np.argmax(outside))
        why = _outside(model, chunk.q[row], float(chunk.time[row]), "at")
        # (the rows' views: the fields cut here are no longer theirs)
        return Chunk(**{k: (None if v is None or k == "rows" else v[:row + 1])
                        for k, v in vars(chunk).items()}), why
    if info:
        return chunk, ""
    return chunk, _outside(model, state["e"], float(state["t"]), "by")


def _outside(model: Model, e, t: float, how: str) -> str:
    """Why the state e at t is outside the formulation's assumptions ('' when it is not)."""
    try:
        check_ffr(model, e, t, when=f"{how} t = {t:.6g} s")
    except SolverError as exc:
        return str(exc)
    return ""


__all__ = ["DynamicSettings", "Chunk", "DynamicResult", "TimeIntegrator", "integrate",
           "initial_acceleration", "initial_row", "ENERGY_NAMES", "CONTACT_FIELDS", "STAT_NAMES"]
