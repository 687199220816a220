"""Implicit dynamics of the constrained ANCF beam: Newmark (seed 000, eqs. 58-62) and
generalized-alpha (Chung-Hulbert; Arnold-Bruels for constrained systems).

Python prepares what never changes during a run and hands the stepping to the Fortran
kernel (``fortran/src/time_integrator.f90``), which advances whole chunks of steps per call:

* ANCF-FFR: S = beta' M + K0 in the floating frame (beta' = (1 - alpha_m) / (beta h^2
  (1 - alpha_f))), factorized once (banded Cholesky). Because every 3 x 3 block of M is a
  scalar times I3, beta' M + T K0 T^T = T S T^T for any frame rotation A(t), so this one
  factorization serves every step of the run; and the flexibility S^{-1} E_c at the
  3-vectors the constraints touch (one solve per touched coordinate, once), from which the
  kernel builds the multipliers' Schur complement without further solves.
* Large deformation: the kernel refactorizes S = beta' M + K_t(q) once per step (and again
  within a step whose Newton correction does not halve per iteration) on the
  same banded pattern, with the flexibility.
* The consistent initial acceleration from [[M, -Phi_e^T], [-Phi_e, 0]] [a; lambda] =
  [Q - Q_el; -gamma].

Each chunk's outputs go to a ``sink`` (the HDF5 writer) before the next chunk starts, so
an interrupted or failed run keeps every completed chunk.
"""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp
from tqdm import tqdm

from .. import _kernel
from ..errors import Interrupted, SolverError
from ..kernel import DirectSolver, _f
from ..model import BeamModel

ENERGY_NAMES = ("kinetic", "strain", "gravity", "moment", "total", "drive_work", "frame_work",
                "contact", "damping_work", "friction_work")
#: what a contact record (per point and step) holds
CONTACT_FIELDS = ("penetration", "normal_force", "friction_force", "slip_speed", "xi", "eta")
CONTACT_COUNTERS = ("contact_points", "contact_active", "friction_evaluations",
                    "contact_projection_iterations", "contact_projection_fallbacks",
                    "contact_jacobian_dropped")

_FAILURES = {
    1: "Newton did not converge within {max_newton} iterations",
    2: "the state became non-finite (NaN or overflow)",
    3: "the linear solve failed (solver code {detail}: -10 = singular matrix)",
    4: "the multipliers' Schur complement is singular (dgesv info {detail}): the "
       "constraints are redundant or lost rank",
    5: "a constraint or drive could not be evaluated",
    6: "a bending moment's section director became parallel to its axis",
    7: "a plate element's mid-surface normal vanished (r_x parallel to r_y: the element "
       "folded onto a line)",
    8: "the contact search found no closest point on the upper leaf (the projection "
       "diverged even from the sampled restart)",
}


@dataclass
class DynamicSettings:
    """Integrator settings (``&solver`` and ``&output`` of a scene). Newmark is
    alpha_m = alpha_f = 0; :meth:`generalized_alpha` sets all four from rho_inf."""

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


@dataclass
class Chunk:
    """Outputs of consecutive steps (one row per step)."""

    time: np.ndarray
    probes: np.ndarray        # (nt, nprobe, 3)
    deflections: np.ndarray   # (nt, nprobe, 3)
    lam: np.ndarray           # (nt, ncon)
    energy: np.ndarray        # (nt, 10): ENERGY_NAMES
    constraint: np.ndarray    # (nt,) max |Phi|
    newton: np.ndarray        # (nt,) Newton corrections per step
    q: np.ndarray | None      # (nt, ndof) when stored
    contact: np.ndarray | None = None  # (nt, npoints, 6): CONTACT_FIELDS


@dataclass
class DynamicResult:
    """Statistics of a completed run."""

    steps: int
    newton_iterations: int
    factorizations: int
    solves_setup: int
    wall_time_s: float
    timing: dict[str, float] = field(default_factory=dict)


def _saddle_solve(model: BeamModel, matrix: sp.spmatrix, rhs_top: np.ndarray,
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


def initial_acceleration(model: BeamModel, e: np.ndarray, v: np.ndarray, t: float):
    """Consistent a(t) and lambda(t) from the equations of motion and Phi_e a = gamma."""
    *_, gamma = model.constraints.evaluate(e, t, v)
    elastic, _, _ = model.internal_force(e, t)
    external = model.external_force(e)
    return _saddle_solve(model, model.mass_matrix(), external - elastic, -gamma, e, t,
                         "initial acceleration [[M, -Phi_e^T], [-Phi_e, 0]]")


class TimeIntegrator:
    """The constant data of a run and the chunked stepping over the kernel."""

    def __init__(self, model: BeamModel, settings: DynamicSettings) -> None:
        if settings.dt <= 0:
            raise SolverError(f"time step dt = {settings.dt} must be positive")
        self.model, self.settings = model, settings
        start = time.perf_counter()
        self.mass = model.mass_matrix()
        self.mass_pattern = model.mass_values()
        self.nonlinear = model.formulation != "ffr"  # refactorized every step
        table = model.constraints.dof_table()
        used = table[table >= 0]
        # blocks of 3 consecutive unknowns holding every constrained one (the kernel takes
        # the first block that holds a dof; the last block is kept inside the vector)
        self.block_first = np.unique(np.minimum(used - used % 3, model.ndof - 3))
        if getattr(model, "solver_kind", "banded") == "banded":
            self.solver = DirectSolver(model.ndof, model.pattern.rows, model.pattern.col_index,
                                       banded_spd=True,
                                       what="iteration matrix beta' M + K (banded Cholesky)")
        else:  # coupled bodies and friction: unsymmetric, not banded (sequential MUMPS)
            self.solver = DirectSolver(model.ndof, model.pattern.rows, model.pattern.col_index,
                                       what="iteration matrix beta' M + K (MUMPS)")
        self.setup_solves = 0
        self.flexibility = np.zeros((model.ndof, 3 * len(self.block_first)))
        self.flexibility_cc = np.zeros((3 * len(self.block_first),) * 2)
        if not self.nonlinear:  # S = beta' M + K0 in the frame: once for the whole run
            k0 = model.pattern.assemble(model.stiffness0)
            self.solver.factorize(settings.beta_prime * self.mass_pattern + k0)
            model.counters["factorizations"] += 1
            columns = np.zeros((model.ndof, 3 * len(self.block_first)))
            for b, first in enumerate(self.block_first):
                columns[first:first + 3, 3 * b:3 * b + 3] = np.eye(3)
            if columns.size:
                self.flexibility = self.solver.solve(columns)
                block_dofs = (self.block_first[:, None] + np.arange(3)).ravel()
                self.flexibility_cc = self.flexibility[block_dofs]
            self.setup_solves = columns.shape[1]
        self.refactorizations = 0  # large deformation: factorizations of S by the kernel
        self.setup_time = time.perf_counter() - start
        self._arrays = self._kernel_arrays()

    def _kernel_arrays(self) -> dict:
        """The stepper's arguments: the model's element part (``model.stepper_arrays``)
        and the mass, loads, moments, constraints and solver data common to all models."""
        model = self.model
        ints, reals, kinds, params = model.constraints.arrays()
        moments = model.moments

        def pad(a: np.ndarray) -> np.ndarray:
            """f2py refuses zero-size arrays: give one unused column; counts say how many
            are real."""
            if a.shape[-1]:
                return a
            return np.zeros(a.shape[:-1] + (1,), dtype=a.dtype, order="F")
        csr = self.mass.tocsr()
        csr.eliminate_zeros()  # the x, y, z blocks of M are decoupled: 2/3 of the pattern is 0
        csr.sort_indices()
        arrays = dict(
            plate_derivs=np.zeros((12, 5, 1, 1), order="F"),
            plate_frame=np.zeros((2, 2, 1, 1), order="F"),
            plate_curvature0=np.zeros((3, 1, 1), order="F"),
            plate_weights=np.zeros((1, 1), order="F"), thickness=0.0,
            structural_forms=np.zeros((8, 8, 1, 1), order="F"),
            structural_strain0=np.zeros((1, 1), order="F"),
            structural_stiffness=np.zeros((1, 1), order="F"))
        arrays.update(model.stepper_arrays())
        arrays.update(extension_arrays(model, arrays["dofs"].shape[1]))
        arrays.update(
            mass_row_ptr=_f(csr.indptr + 1, np.int32),
            mass_col=_f(csr.indices + 1, np.int32), mass_values=_f(csr.data),
            constant_force=_f(model.constant_force()),
            nmoment=len(moments),
            moment_dofs=pad(_f(np.array([np.array(m.dofs) + 1 for m in moments],
                                        dtype=np.int32).reshape(-1, 3).T, np.int32)),
            moment_axis=pad(_f(np.array([m.axis for m in moments]).reshape(-1, 3).T)),
            moment_magnitude=pad(_f(np.array([m.magnitude for m in moments]))),
            moment_reference=pad(_f(np.array([model.e0[m.dofs] for m in moments]).reshape(-1, 3).T)),
            ncon=len(model.constraints),
            con_ints=pad(_f(ints, np.int32)), con_reals=pad(_f(reals)), drive_kinds=_f(kinds, np.int32),
            drive_params=_f(params),
            scatter_map=arrays.get("scatter_map", getattr(model.pattern, "scatter_map", None)),
            mass_pattern=_f(self.mass_pattern),
            solver_handle=self.solver.handle, nblock=len(self.block_first),
            block_first=pad(_f(self.block_first + 1, np.int32)),
            flexibility=_f(self.flexibility) if len(self.block_first)
            else np.zeros((model.ndof, 3), order="F"),
            flexibility_cc=_f(self.flexibility_cc) if len(self.block_first)
            else np.zeros((3, 3), order="F"),
        )
        return arrays

    def close(self) -> None:
        self.solver.close()

    def advance(self, state: dict, nsteps: int) -> tuple[Chunk, int, int]:
        """Advance ``nsteps`` steps; ``state`` (t, e, v, a, accel, lam, work) is updated in
        place (a: the generalized-alpha acceleration variable, accel: q'').
        Returns the chunk of completed steps, the kernel's info and detail codes."""
        s, m = self.settings, self.model
        nq = nsteps if s.store_q else 1
        out = _kernel.integrator_advance(
            **self._arrays, nsteps=nsteps, nq=nq, h=s.dt, beta=s.beta, gamma=s.gamma,
            alpha_m=s.alpha_m, alpha_f=s.alpha_f, tol=s.tol,
            length_scale=m.length_scale, max_newton=s.max_newton,
            t=state["t"], e=_f(state["e"]), v=_f(state["v"]), a=_f(state["a"]),
            accel=_f(state["accel"]),
            lam=_f(state["lam"]) if len(state["lam"]) else np.zeros(1), work=_f(state["work"]),
            contact_guess=_f(state["contact_guess"]),
            contact_counts=_f(state["contact_counts"], np.int32))
        (t, e, v, a, accel, lam, work, guess, counts, o_time, o_probe, o_defl, o_lam, o_energy,
         o_con, o_newton, o_contact, o_q, status, self.last_correction) = out
        state.update(t=float(t), e=e, v=v, a=a, accel=accel, lam=lam[:len(m.constraints)],
                     work=work, contact_guess=guess, contact_counts=counts)
        done, info, detail, refactorizations = (int(x) for x in status)
        self.refactorizations += refactorizations
        chunk = Chunk(time=o_time[:done], probes=np.transpose(o_probe[:, :, :done], (2, 1, 0)),
                      deflections=np.transpose(o_defl[:, :, :done], (2, 1, 0)),
                      lam=o_lam[:len(m.constraints), :done].T, energy=o_energy[:, :done].T,
                      constraint=o_con[:done], newton=o_newton[:done],
                      q=o_q[:, :done].T if s.store_q else None,
                      contact=np.transpose(o_contact[:, :, :done], (2, 1, 0))
                      if getattr(m, "contact", None) is not None else None)
        return chunk, info, detail

    def failure_message(self, info: int, detail: int, t: float) -> str:
        s = self.settings
        reason = _FAILURES.get(info, f"kernel code {info}").format(max_newton=s.max_newton,
                                                                  detail=detail)
        if info == 1:
            reason += (f" (last correction {self.last_correction:.3e} m, tolerance "
                       f"{s.tol * self.model.length_scale:.3e} m = newton_tol x length; raise "
                       "solver.max_newton or lower solver.dt)")
        return f"time step from t = {t:.6g} s to t = {t + s.dt:.6g} s failed: {reason}"


def extension_arrays(model, nel: int) -> dict:
    """The stepper's arguments for linear-constraint elimination, a time-dependent load and
    leaf contact; neutral values for models without them."""
    f = np.asfortranarray
    reduction = getattr(model, "reduction", None)
    full = reduction.full_pattern if reduction is not None else model.pattern
    out = dict(nfull=full.n, full_row_ptr=f(full.row_ptr + 1, dtype=np.int32),
               full_col=f(full.col_index + 1, dtype=np.int32), reduced=0,
               reduction_ptr=np.ones(full.n + 1, dtype=np.int32), reduction_col=np.ones(1, np.int32),
               reduction_values=np.zeros(1), reduction_offset=np.zeros(full.n),
               plan_source=np.ones(1, np.int32), plan_target=np.ones(1, np.int32),
               plan_coef=np.zeros(1), nnz_b=0, nplan=0, force_drive=0, drive_force=np.zeros(model.ndof),
               element_size=np.ones((2, nel), order="F"), ncontact=0,
               contact_grid=np.ones((1, 1), dtype=np.int32, order="F"),
               contact_element=np.ones(1, np.int32), contact_local=np.zeros((2, 1), order="F"),
               contact_params=np.zeros(8))
    if reduction is not None:
        b = reduction.matrix
        out.update(reduced=1, reduction_ptr=f(b.indptr + 1, dtype=np.int32),
                   reduction_col=f(b.indices + 1, dtype=np.int32), reduction_values=f(b.data),
                   reduction_offset=f(reduction.offset), plan_source=f(reduction.plan_source + 1,
                                                                        dtype=np.int32),
                   plan_target=f(reduction.plan_target + 1, dtype=np.int32),
                   plan_coef=f(reduction.plan_coef), nnz_b=len(b.data),
                   nplan=len(reduction.plan_coef))
    if getattr(model, "force_drive", None) is not None:
        out.update(force_drive=model.force_drive_index + 1, drive_force=f(model.drive_force))
    contact = getattr(model, "contact", None)
    if hasattr(model, "element_sizes"):
        out.update(element_size=f(model.element_sizes()))
    if contact is not None:
        out.update(ncontact=len(contact.point_element),
                   contact_grid=f(contact.grid + 1, dtype=np.int32),
                   contact_element=f(contact.point_element + 1, dtype=np.int32),
                   contact_local=f(contact.point_local), contact_params=f(contact.params))
    return out


def initial_row(model: BeamModel, state: dict, mass: sp.spmatrix) -> Chunk:
    """The output row of the initial state, with the kernel's energy definitions."""
    e, v, t = state["e"], state["v"], state["t"]
    positions = model.probe_positions(e)
    deflections = model.deflections_at(e, t)
    _, strain, _ = model.internal_force(e, t)
    moment = -sum(m.magnitude * float(_kernel.moment_rotation_angle(e[m.dofs], m.axis,
                                                                   model.e0[m.dofs]))
                  for m in model.moments)
    kinetic = 0.5 * v @ (mass @ v)
    loads = -model.constant_force() @ e
    contact_energy, records = 0.0, None
    if getattr(model, "contact", None) is not None:
        _, records, contact_energy, _ = model.contact_forces(e, v)
    if getattr(model, "force_drive", None) is not None:
        loads -= model.load_factor(t) * (model.drive_force @ e)
    energy = np.array([kinetic, strain, loads, moment,
                       kinetic + strain + loads + moment + contact_energy,
                       *state["work"][:2], contact_energy, *state["work"][2:]])
    values, *_ = model.constraints.evaluate(e, t)
    names = list(model.probes)
    return Chunk(time=np.array([t]), probes=np.array([[positions[n] for n in names]]),
                 deflections=np.array([[deflections[n] for n in names]]),
                 lam=state["lam"][None, :], energy=energy[None, :],
                 constraint=np.array([np.abs(values).max(initial=0.0)]),
                 newton=np.array([0]), q=e[None, :].copy(),
                 contact=None if records is None else records.T[None, :, :])


def integrate(model: BeamModel, settings: DynamicSettings, e0: np.ndarray,
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
    start = time.perf_counter()
    timing = {"setup": 0.0, "stepping": 0.0, "output": 0.0}
    if settings.t_end < t0:
        raise SolverError(f"t_end = {settings.t_end} lies before the start time {t0}")
    v0 = np.zeros(model.ndof) if v0 is None else v0
    integrator = TimeIntegrator(model, settings)
    try:
        a0, lam0 = initial_acceleration(model, e0, v0, t0)
        contact = getattr(model, "contact", None)
        state = dict(t=t0, e=e0.copy(), v=v0.copy(), a=a0.copy(), accel=a0, lam=lam0,
                     work=np.zeros(4),
                     contact_guess=contact.guesses.copy() if contact is not None
                     else np.zeros((2, 1)),
                     contact_counts=np.zeros(6, dtype=np.int32))
        timing["setup"] = time.perf_counter() - start
        t0_out = time.perf_counter()
        if sink:
            first = initial_row(model, state, integrator.mass)
            if not settings.store_q:
                first.q = None
            sink(first)
        timing["output"] += time.perf_counter() - t0_out
        total = int(round((settings.t_end - t0) / settings.dt))
        show = sys.stderr.isatty() if progress is None else progress
        bar = tqdm(total=round(settings.t_end - t0, 9), unit="s", disable=not show,
                   desc="dynamics", bar_format="{l_bar}{bar}| t={n:.3f}/{total:.3f} s "
                   "[{elapsed}<{remaining}{postfix}]")
        steps = newton = 0
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
                newton += int(chunk.newton.sum())
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
            model.counters["solves"] += newton + integrator.setup_solves
            if integrator.nonlinear:  # FFR counted its single factorization at set-up
                model.counters["factorizations"] += integrator.refactorizations
            if getattr(model, "contact", None) is not None:
                for name, count in zip(CONTACT_COUNTERS, state["contact_counts"]):
                    model.counters[name] += int(count)
                model.contact.guesses = state["contact_guess"].copy()
    finally:
        integrator.close()
    wall = time.perf_counter() - start
    timing["total"] = wall
    factorizations = integrator.refactorizations if integrator.nonlinear else 1
    return DynamicResult(steps=steps, newton_iterations=newton, factorizations=factorizations,
                         solves_setup=integrator.setup_solves, wall_time_s=wall, timing=timing)
