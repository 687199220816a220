!> Step-size control of the stepper (issue 26): output rows on the grid t0 + k dt, each landed
!> on exactly (no interpolation; a step is shortened to reach the next grid time).
!> * step = 'fixed': whole chunks of steps at dt (time_integrator's integrator_chunk). A step
!>   that fails (Newton diverges or stalls, the state turns non-finite, a linear solve or the
!>   contact search fails) is retried from its start with half the step, again and again down
!>   to dt_min, and the step doubles back after grow_after successes in a row (at most to dt,
!>   where whole chunks resume). A failure at dt_min ends the run. A Newton stall at the
!>   round-off floor with a tolerance below what double precision resolves is not retried (a
!>   smaller step does not lower the floor).
!> * step = 'adaptive': every step sized by the local error estimate of Zienkiewicz & Xie
!>   (1991; local_error) to the tolerance (bounded by dt and dt_min), the same cuts for
!>   failed steps; a step at dt_min (within step_rtol) whose estimate exceeds the tolerance
!>   ends the run.
!> At each change of the step the method restarts from the consistent acceleration and
!> multipliers of the state (consistent_start): at rho_inf = 1 the method leaves a period-2
!> oscillation of a - e'' and of the multipliers undamped, and a change of the step turns it
!> into an error of order (constraint violation) / h^2 that is never damped either.
!> A method without numerical damping (neutral_method: rho_inf = 1, the trapezoidal rule)
!> on a constrained system also restarts where that period-2 oscillation of its multipliers
!> grows (issue 39: on the flexible double pendulum at dt = 2.5e-4 the nonlinear constraints
!> of the turning elbow amplify it ~0.5 % a step from t = 4.4 s, 0.4 N -> 164 N by 5.5 s,
!> until the steps fail and are cut by thousands): measured over blocks of
!> neutral_block_steps whole steps, a restart after a block where it exceeds both
!> neutral_growth times the run's quietest block and neutral_share of the block's largest
!> multiplier. The restart removes it without moving the positions (they see a_{n+1} + a_n
!> only), and the next step's Newton iteration is accepted on its own measured contraction,
!> not on one learned before the jump in e'' (relearn).
!> A call does at most `budget` tries (steps tried), so the caller can answer a stop request
!> between calls; an output interval left unfinished is resumed by the next call. Tries in a
!> row without an accepted step are bounded (control_tries). No I/O; failures return codes.
module step_control
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state, power_count, energy_count, &
                               contact_record
  use stepper, only: stepper_run, stepper_settings, control_settings, control_state
  use time_integrator, only: integrator_chunk, newton_floor_stall, step_work, allocate_work
  use consistent_start, only: consistent_acceleration
  use kernel_errors, only: message_length
  use row_answers, only: answer_row, answer_count
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  implicit none
  private
  public :: stepper_point, controlled_rows, control_failure

  !> the run's failures of the control itself (after integrator_chunk's 1 .. 8 and 10):
  !> tries in a row without an accepted step; the error estimate above the tolerance at
  !> dt_min; the restart's consistent acceleration failed
  integer, parameter, public :: control_tries = 11, control_tolerance = 12, control_restart = 13
  !> successful steps in a row after which a cut step doubles again
  integer, parameter, public :: grow_after = 4
  !> the relative slack within which two step sizes are one: a step that would end short of
  !> the next grid time by less is stretched onto it, and a step within it of dt_min is at
  !> dt_min (cannot be cut nor rejected). A sub-step that ends an interval is target - t, t
  !> the sum of the interval's earlier sub-steps, so it carries their round-off, a few ulps
  !> of t (issue 35: 1.9e-11 of a 4.9e-7 s step at t = 0.05 s, compared with dt_min at 1e-12,
  !> was rejected, cut back to that same remainder, forever). 1e-9 covers k ulps of t for
  !> k t / h up to ~4e6, far below the factor 2 between the sizes the control chooses.
  real(dp), parameter, public :: step_rtol = 1e-9_dp
  !> the restart of a method without numerical damping (the module's notes): blocks of
  !> neutral_block_steps whole steps; a restart after one whose period-2 oscillation of the
  !> multipliers exceeds neutral_growth times the run's quietest block's and neutral_share of
  !> the block's largest |lambda|. Measured (docs/hard-cases.md): the double pendulum's is
  !> 0.1-0.5 N (1-6 % of its multipliers) before it grows; the shipped scenes' stays below
  !> 0.4 % of their multipliers; the 4-node cable boom released from its unloaded shape
  !> rings at 194-225 N (0.4-2.8 %: not growing). A threshold of the quietest block since the
  !> last restart (instead of the run's) came too late: each restart left a larger
  !> oscillation behind, and it grew to kN.
  integer, parameter, public :: neutral_block_steps = 64
  real(dp), parameter, public :: neutral_growth = 2.0_dp, neutral_share = 1e-2_dp

  !> A stepper state: t; e, e', a (the generalized-alpha variable), e''; lambda; the works
  !> and the powers at the state; the contact guesses and counters.
  type :: stepper_point
    real(dp) :: t = 0.0_dp
    real(dp), allocatable :: e(:), v(:), a(:), accel(:), lam(:)
    real(dp) :: work(power_count) = 0.0_dp, powers(power_count) = 0.0_dp
    type(contact_state) :: contact
  end type stepper_point

  !> A failure of controlled_rows: the state's time and the step tried, the interval's cuts
  !> named in its message, the work of failed tries the caller counts, the tries in a row
  !> (control_tries), the kernel's text of the step's failure.
  type :: control_failure
    real(dp) :: t = 0.0_dp, h = 0.0_dp
    integer :: cuts = 0, tries = 0
    integer :: work(3) = 0
    character(len=message_length) :: text = ''
  end type control_failure

contains

  !> Up to nrows output rows from p (updated in place) with at most budget tries: rows(:, k)
  !> in stepper.f90's row layout, stats(:, k) = Newton corrections, factorizations, Jacobian
  !> evaluations (failed tries included), steps taken, step cuts; sizes(k) the smallest step
  !> to the row (a whole step at dt: the rows' time difference). done: the rows made; tries:
  !> the steps tried. info /= 0 (detail: integrator_chunk's detail): the run fails, described
  !> by failure; the state is at the failed step's start.
  subroutine controlled_rows(sys, run, p, nrows, budget, store_q, rows, stats, sizes, done, &
                             tries, info, detail, last_correction, floor_accepts, failure)
    type(system_model), intent(inout) :: sys
    type(stepper_run), intent(inout), target :: run
    type(stepper_point), intent(inout) :: p
    integer, intent(in) :: nrows, budget
    logical, intent(in) :: store_q
    real(dp), intent(out) :: rows(:, :), sizes(:)
    integer, intent(out) :: stats(:, :), done, tries, info, detail, floor_accepts
    real(dp), intent(out) :: last_correction
    type(control_failure), intent(out) :: failure
    type(control_settings), pointer :: cs
    type(control_state), pointer :: c
    type(stepper_point) :: before
    type(step_work) :: scratch  ! the steps' work arrays, for every step_rows call
    real(dp) :: buffer(size(rows, 1), 1), t_before, h, remaining, error
    integer :: step_stats(3, 1), n, k, j, floor, max_tries, at_lambda
    logical :: retry, finished, neutral, grew
    cs => run%control_settings
    c => run%control
    call allocate_work(sys, scratch)
    rows = 0.0_dp
    stats = 0
    sizes = 0.0_dp
    done = 0
    tries = 0
    info = 0
    detail = 0
    floor_accepts = 0
    last_correction = 0.0_dp
    if (.not. c%started) then
      c%started = .true.
      c%t0 = p%t
      c%restart_guesses = p%contact%guesses
    end if
    max_tries = 8 + ceiling(log(max(cs%dt / cs%dt_min, 1.0_dp)) / log(2.0_dp))
    do while (done < nrows .and. tries < budget)
      if (.not. c%open .and. .not. cs%adaptive .and. c%h >= cs%dt) then
        ! whole steps at dt
        if (c%last_h /= cs%dt) then  ! back to dt after cut steps
          call restart(sys, run, p, info, failure)
          if (info /= 0) return
          c%last_h = cs%dt
        end if
        n = min(nrows - done, budget - tries)
        neutral = neutral_method(run%settings) .and. sys%constraints%ncon > 0
        if (neutral) n = min(n, neutral_block_steps - c%block_steps)
        t_before = p%t
        call step_rows(sys, run, cs%dt, n, p, rows(:, done + 1:done + n), &
                       stats(1:3, done + 1:done + n), store_q, k, info, detail, last_correction, &
                       floor, scratch)
        floor_accepts = floor_accepts + floor
        tries = tries + k
        do j = 1, k
          if (j == 1) then
            sizes(done + j) = rows(1, done + j) - t_before
          else
            sizes(done + j) = rows(1, done + j) - rows(1, done + j - 1)
          end if
          stats(4, done + j) = 1
        end do
        c%taken = c%taken + k
        if (k > 0) c%smallest = min(c%smallest, cs%dt)
        c%rows = c%rows + k
        done = done + k
        if (neutral) then
          at_lambda = 1 + 6 * sys%probes%nprobe
          call block_rows(c, rows(at_lambda + 1:at_lambda + sys%constraints%ncon, done - k + 1:done))
          if (info /= 0) then
            call block_reset(c)
          else if (c%block_steps >= neutral_block_steps) then
            call block_verdict(c, grew)
            if (grew) then
              call restart(sys, run, p, info, failure)
              if (info /= 0) return
              call relearn(run)
            end if
            call block_reset(c)
          end if
        end if
        if (info == 0) cycle
        tries = tries + 1
        failure%work = 0
        if (k < n) then  ! (the failed step's column: its work, not a row)
          failure%work = stats(1:3, done + 1)
          stats(:, done + 1) = 0
          rows(:, done + 1) = 0.0_dp
        end if
        retry = retryable(info, detail)
        if (retry) retry = cut(c, cs, cs%dt)
        if (.not. retry) then
          failure%t = p%t
          failure%h = cs%dt
          failure%cuts = 0
          return
        end if
        ! the next interval starts with the failed step's work and its cut
        c%carried = .true.
        c%carried_stats = failure%work
        failure%work = 0
        info = 0
        detail = 0
        cycle
      end if
      if (.not. c%open) then  ! a new output interval
        c%open = .true.
        if (cs%adaptive) then
          c%target = c%t0 + real(c%rows + 1, dp) * cs%dt
        else
          c%target = p%t + cs%dt
        end if
        c%interval_stats = 0
        c%interval_cuts = 0
        if (c%carried) then
          c%interval_stats = c%carried_stats
          c%interval_cuts = 1
        end if
        c%carried = .false.
        c%carried_stats = 0
        c%interval_taken = 0
        c%interval_smallest = huge(1.0_dp)
        c%tries = 0
        if (.not. allocated(c%row)) allocate (c%row(size(rows, 1)))
        c%row = 0.0_dp
      end if
      finished = .false.
      do
        remaining = c%target - p%t
        if (remaining <= step_rtol * cs%dt_min) then
          finished = .true.
          exit
        end if
        if (tries >= budget) exit
        if (c%tries >= max_tries) then
          info = control_tries
          failure%t = p%t
          failure%tries = c%tries
          return
        end if
        h = c%h
        if (h >= remaining * (1.0_dp - step_rtol)) h = remaining
        if (abs(h - c%last_h) > step_rtol * h) then
          call restart(sys, run, p, info, failure)
          if (info /= 0) return
        end if
        before = p
        buffer = 0.0_dp
        step_stats = 0
        call step_rows(sys, run, h, 1, p, buffer, step_stats, store_q, k, info, detail, &
                       last_correction, floor, scratch)
        floor_accepts = floor_accepts + floor
        tries = tries + 1
        c%tries = c%tries + 1
        if (info /= 0) then
          if (k < 1) c%interval_stats = c%interval_stats + step_stats(:, 1)
          retry = retryable(info, detail)
          if (retry) retry = cut(c, cs, ladder_step(c, h))
          p = before
          if (.not. retry) then
            failure%t = p%t
            failure%h = h
            failure%cuts = 0
            if (retryable(info, detail)) failure%cuts = c%interval_cuts
            return
          end if
          c%interval_cuts = c%interval_cuts + 1
          info = 0
          detail = 0
          cycle
        end if
        c%interval_stats = c%interval_stats + step_stats(:, 1)
        error = -1.0_dp
        if (cs%adaptive) then
          error = local_error(run, h, before%accel, p%accel)
          if (error > 1.0_dp) then
            p = before
            if (at_floor(c, cs, h)) then
              info = control_tolerance
              failure%t = p%t
              failure%h = h
              return
            end if
            call reject(c, cs, h, error)
            cycle
          end if
        end if
        c%tries = 0
        c%last_h = h
        call succeeded(c, cs, h, c%target - p%t, error)
        c%interval_taken = c%interval_taken + 1
        c%interval_smallest = min(c%interval_smallest, h)
        c%row = buffer(:, 1)
      end do
      if (.not. finished) exit
      ! the row at the grid time, with the interval's statistics
      c%open = .false.
      p%t = c%target
      done = done + 1
      c%rows = c%rows + 1
      rows(:, done) = c%row
      rows(1, done) = c%target
      stats(1:3, done) = c%interval_stats
      stats(4, done) = c%interval_taken
      stats(5, done) = c%interval_cuts
      sizes(done) = c%interval_smallest
    end do
  end subroutine controlled_rows

  !> A restart of the method at a change of the step (the module's notes): a = e'' and
  !> lambda consistent with the state. The contact search starts from the guesses of the
  !> last restart (the run's start before the first), which it updates; its counters are not
  !> the run's.
  subroutine restart(sys, run, p, info, failure)
    type(system_model), intent(inout) :: sys
    type(stepper_run), intent(inout) :: run
    type(stepper_point), intent(inout) :: p
    integer, intent(out) :: info
    type(control_failure), intent(inout) :: failure
    type(contact_state) :: contact
    integer :: detail
    contact%guesses = run%control%restart_guesses
    call consistent_acceleration(sys, p%t, p%e, p%v, contact, p%accel, p%lam, info, detail, &
                                 failure%text)
    if (info /= 0) then
      info = control_restart
      failure%t = p%t
      return
    end if
    run%control%restart_guesses = contact%guesses
    p%a = p%accel
    run%control%restarts = run%control%restarts + 1
    call block_reset(run%control)
  end subroutine restart

  !> After a restart on the oscillation (the module's notes): the contraction learned before
  !> the jump in e'' is forgotten, so the next step is accepted on its own measured one.
  pure subroutine relearn(run)
    type(stepper_run), intent(inout) :: run
    run%state%theta = -1.0_dp
    run%state%unconfirmed = 0
    run%state%matrix_measured = 0
    run%state%matrix_unconfirmed = 0
  end subroutine relearn

  !> Whether the method leaves the infinite-frequency mode undamped (spectral radius 1 at
  !> h omega -> infinity): generalized-alpha with alpha_m = alpha_f (rho_inf = 1) and
  !> gamma = 1/2, Newmark's trapezoidal rule among them.
  pure logical function neutral_method(cfg)
    type(stepper_settings), intent(in) :: cfg
    neutral_method = abs(cfg%alpha_m - cfg%alpha_f) <= 1e-12_dp .and. &
                     abs(cfg%gamma - 0.5_dp) <= 1e-12_dp
  end function neutral_method

  !> The block's record of whole-step rows (their multipliers, columns, in order): the
  !> period-2 part of the multipliers, max |lambda_{n+1} - 2 lambda_n + lambda_{n-1}| / 4
  !> (c (-1)^n gives c; a smooth history ~h^2 lambda''), over the block's consecutive rows
  !> (those of earlier calls included), and the block's largest |lambda|.
  pure subroutine block_rows(c, lam)
    type(control_state), intent(inout) :: c
    real(dp), intent(in) :: lam(:, :)
    integer :: n
    if (.not. allocated(c%block_lambda)) then
      allocate (c%block_lambda(size(lam, 1), 2))
      c%block_lambda = 0.0_dp
    end if
    do n = 1, size(lam, 2)
      if (c%block_held == 2) c%block_swing = max(c%block_swing, maxval(abs( &
        lam(:, n) - 2.0_dp * c%block_lambda(:, 2) + c%block_lambda(:, 1))) / 4.0_dp)
      c%block_peak = max(c%block_peak, maxval(abs(lam(:, n))))
      c%block_lambda(:, 1) = c%block_lambda(:, 2)
      c%block_lambda(:, 2) = lam(:, n)
      c%block_held = min(c%block_held + 1, 2)
    end do
    c%block_steps = c%block_steps + size(lam, 2)
  end subroutine block_rows

  !> A full block's verdict (the module's notes): grew, its oscillation beyond neutral_growth
  !> times the run's quietest full block's (none yet: false) and beyond neutral_share of its
  !> largest multiplier; the quietest block is updated.
  pure subroutine block_verdict(c, grew)
    type(control_state), intent(inout) :: c
    logical, intent(out) :: grew
    grew = .false.
    if (c%quiet_swing < huge(1.0_dp)) grew = c%block_swing > neutral_growth * c%quiet_swing &
                                             .and. c%block_swing > neutral_share * c%block_peak
    c%quiet_swing = min(c%quiet_swing, c%block_swing)
  end subroutine block_verdict

  !> A new block: after a full one, a failed step or a restart.
  pure subroutine block_reset(c)
    type(control_state), intent(inout) :: c
    c%block_steps = 0
    c%block_held = 0
    c%block_swing = 0.0_dp
    c%block_peak = 0.0_dp
  end subroutine block_reset

  !> n steps of size h from p (integrator_chunk) with their output rows in the row layout of
  !> stepper.f90 (row_size) and their statistics (a failed step's: the column after the
  !> last completed one). A run whose rows answer (row_answers) takes the steps one by one
  !> and writes each row's answers from the state it reached (e', e'' as the method has
  !> them); answers that cannot be evaluated are written as NaN (the step stands).
  subroutine step_rows(sys, run, h, n, p, rows, stats, store_q, steps_done, info, detail, &
                       last_correction, floor_accepts, scratch)
    type(system_model), intent(inout) :: sys
    type(stepper_run), intent(inout) :: run
    real(dp), intent(in) :: h
    integer, intent(in) :: n
    type(stepper_point), intent(inout) :: p
    real(dp), intent(inout) :: rows(:, :)
    integer, intent(inout) :: stats(:, :)
    logical, intent(in) :: store_q
    integer, intent(out) :: steps_done, info, detail, floor_accepts
    real(dp), intent(out) :: last_correction
    type(step_work), intent(inout) :: scratch  ! (allocate_work, by the caller)
    real(dp), allocatable :: out_probe(:, :, :), out_deflection(:, :, :), out_contact(:, :, :)
    real(dp), allocatable :: no_q(:, :)
    integer :: ndof, ncon, nprobe, npoint, nanswer, step, k, j, floor, answer_info
    integer :: at_lambda, at_energy, at_constraint, at_answers, at_q  ! (row_size)
    ndof = sys%ndof
    ncon = sys%constraints%ncon
    nprobe = sys%probes%nprobe
    npoint = sys%contact%npoint
    nanswer = answer_count(sys, run%answers)
    ! (the stepper writes time, lam, energy, constraint violation and q straight into their
    ! rows, zeroed by the caller; the probes, deflections and contact records are copied)
    at_lambda = 1 + 6 * nprobe
    at_energy = at_lambda + ncon
    at_constraint = at_energy + energy_count
    at_answers = at_constraint + 1 + contact_record * npoint
    at_q = at_answers + nanswer
    allocate (out_probe(3, nprobe, n), out_deflection(3, nprobe, n), &
              out_contact(contact_record, npoint, n))
    out_probe = 0.0_dp
    out_deflection = 0.0_dp
    out_contact = 0.0_dp
    if (.not. store_q) allocate (no_q(ndof, 0))
    if (nanswer == 0) then
      call steps(1, n, steps_done)
    else
      steps_done = 0
      floor_accepts = 0
      do step = 1, n
        call steps(step, 1, k)
        floor_accepts = floor_accepts + floor
        if (k < 1) exit
        call answer_row(sys, run%answers, p%t, p%e, p%v, p%accel, p%contact, &
                        rows(at_answers + 1:at_answers + nanswer, step), answer_info)
        if (answer_info /= 0) rows(at_answers + 1:at_answers + nanswer, step) = &
          ieee_value(0.0_dp, ieee_quiet_nan)
        steps_done = step
        if (info /= 0) exit
      end do
    end if
    ! (the probes' and deflections' columns copied by loops: reshape was a library call a step)
    do step = 1, n
      k = 1
      do j = 1, nprobe
        rows(k + 3 * j - 2:k + 3 * j, step) = out_probe(:, j, step)
      end do
      k = k + 3 * nprobe
      do j = 1, nprobe
        rows(k + 3 * j - 2:k + 3 * j, step) = out_deflection(:, j, step)
      end do
      k = at_constraint + 1
      do j = 1, npoint
        rows(k + contact_record * (j - 1) + 1:k + contact_record * j, step) = &
          out_contact(:, j, step)
      end do
    end do

  contains

    !> m steps into the rows' columns first .. first + m - 1 (done: the steps completed).
    subroutine steps(first, m, done)
      integer, intent(in) :: first, m
      integer, intent(out) :: done
      integer :: last
      last = first + m - 1
      if (store_q) then
        call integrator_chunk(sys, run%settings, run%state, h, m, p%t, p%e, p%v, p%a, &
                              p%accel, p%lam, p%work, p%powers, p%contact, rows(1, first:last), &
                              out_probe(:, :, first:last), out_deflection(:, :, first:last), &
                              rows(at_lambda + 1:at_lambda + ncon, first:last), &
                              rows(at_energy + 1:at_energy + energy_count, first:last), &
                              rows(at_constraint + 1, first:last), stats(:, first:last), &
                              out_contact(:, :, first:last), store_q, &
                              rows(at_q + 1:at_q + ndof, first:last), done, info, detail, &
                              last_correction, floor, scratch)
      else
        call integrator_chunk(sys, run%settings, run%state, h, m, p%t, p%e, p%v, p%a, &
                              p%accel, p%lam, p%work, p%powers, p%contact, rows(1, first:last), &
                              out_probe(:, :, first:last), out_deflection(:, :, first:last), &
                              rows(at_lambda + 1:at_lambda + ncon, first:last), &
                              rows(at_energy + 1:at_energy + energy_count, first:last), &
                              rows(at_constraint + 1, first:last), stats(:, first:last), &
                              out_contact(:, :, first:last), store_q, no_q, done, info, &
                              detail, last_correction, floor, scratch)
      end if
      if (nanswer == 0) floor_accepts = floor
    end subroutine steps
  end subroutine step_rows

  !> Kernel failures a smaller step may avoid (not: a constraint or drive that cannot be
  !> evaluated, a force element's, a refused call; not a Newton stall at the round-off floor).
  pure logical function retryable(info, detail)
    integer, intent(in) :: info, detail
    select case (info)
    case (1, 2, 3, 4, 6, 7, 8)
      retryable = .not. (info == 1 .and. detail == newton_floor_stall)
    case default
      retryable = .false.
    end select
  end function retryable

  !> The local error estimate of Newmark's displacement update (Zienkiewicz & Xie 1991, "A
  !> simple error estimator and adaptive time stepping procedure for dynamic analysis",
  !> Earthquake Eng. Struct. Dyn. 20, 871-887): the Taylor remainder of
  !> e_{n+1} = e_n + h e'_n + h^2 ((1/2 - beta) a_n + beta a_{n+1}) against the exact motion
  !> is (beta - 1/6) h^3 e^(3), with e^(3) ~ (a_{n+1} - a_n) / h:
  !>   eta = |beta - 1/6| h^2 max |a_{n+1} - a_n|,
  !> here with the accelerations e'' (generalized-alpha: the same remainder with its beta).
  !> Relative to tolerance x length scale: a step is accepted at <= 1.
  pure real(dp) function local_error(run, h, accel_old, accel_new) result(error)
    type(stepper_run), intent(in) :: run
    real(dp), intent(in) :: h, accel_old(:), accel_new(:)
    real(dp) :: largest
    integer :: i
    largest = 0.0_dp
    do i = 1, size(accel_new)
      largest = max(largest, abs(accel_new(i) - accel_old(i)))
    end do
    error = abs(run%settings%beta - 1.0_dp / 6.0_dp) * h * h * largest / &
            (run%control_settings%tolerance * run%settings%length_scale)
  end function local_error

  !> A step of size h succeeded, remaining is left to the grid time. Steps are dt / 2^k: the
  !> step doubles after grow_after successes (adaptive, error >= 0: after a step whose error
  !> estimate, ~h^3, stays below 1 at twice the step: error <= 0.9 / 8) where the double step
  !> lands on the grid.
  pure subroutine succeeded(c, cs, h, remaining, error)
    type(control_state), intent(inout) :: c
    type(control_settings), intent(in) :: cs
    real(dp), intent(in) :: h, remaining, error
    real(dp) :: double
    logical :: grow, aligned
    c%taken = c%taken + 1
    c%smallest = min(c%smallest, h)
    c%successes = c%successes + 1
    if (error >= 0.0_dp) then
      grow = error <= 0.9_dp / 8.0_dp
    else
      grow = c%successes >= grow_after
    end if
    double = 2.0_dp * c%h
    aligned = remaining <= 0.0_dp
    if (.not. aligned) aligned = abs(remaining / double - anint(remaining / double)) < 1e-6_dp
    if (grow .and. c%h < cs%dt .and. aligned) then
      c%h = min(cs%dt, double)
      c%successes = 0
    end if
  end subroutine succeeded

  !> The step of the controller's ladder that a failed step of size h tried: c%h when h is
  !> c%h stretched onto the grid time (within step_rtol), else h. A cut halves that, so the
  !> controller's steps stay dt / 2^k exactly and double back to dt. Halving the
  !> stretched h moved the controller's step off the ladder by its round-off, and the
  !> shortfall grew with each such cut (issue 39: on the 17-node pendulum at dt = 5e-3 to
  !> 1.1e-9 of the step by t = 4.65 s, past step_rtol): from then on the step never came
  !> back to dt (2 c%h < dt) and every output interval ended with a sliver step of
  !> 5.6e-12 s, its restart and its accelerations taken from differences at round-off.
  pure real(dp) function ladder_step(c, h)
    type(control_state), intent(in) :: c
    real(dp), intent(in) :: h
    ladder_step = h
    if (abs(h - c%h) <= step_rtol * c%h) ladder_step = c%h
  end function ladder_step

  !> A step of size h failed: halve it; false when that falls below dt_min.
  logical function cut(c, cs, h)
    type(control_state), intent(inout) :: c
    type(control_settings), intent(in) :: cs
    real(dp), intent(in) :: h
    c%successes = 0
    cut = .not. 0.5_dp * h < cs%dt_min * (1.0_dp - step_rtol)
    if (.not. cut) return
    c%cuts = c%cuts + 1
    c%h = 0.5_dp * h
  end function cut

  !> Whether a step of size h is at dt_min (within step_rtol): it, or the controller's step
  !> it was stretched from to land on the grid, cannot be made smaller.
  pure logical function at_floor(c, cs, h)
    type(control_state), intent(in) :: c
    type(control_settings), intent(in) :: cs
    real(dp), intent(in) :: h
    real(dp) :: floor
    floor = cs%dt_min * (1.0_dp + step_rtol)
    at_floor = h <= floor .or. c%h <= floor
  end function at_floor

  !> The error estimate rejected a step of size h: halved until the estimate (~h^3) would
  !> meet the tolerance (at least once, at most to dt_min).
  pure subroutine reject(c, cs, h, error)
    type(control_state), intent(inout) :: c
    type(control_settings), intent(in) :: cs
    real(dp), intent(in) :: h
    real(dp), intent(in) :: error
    real(dp) :: left
    left = error
    c%rejected = c%rejected + 1
    c%successes = 0
    c%h = 0.5_dp * h
    do while (left / 8.0_dp > 1.0_dp .and. 0.5_dp * c%h >= cs%dt_min)
      c%h = c%h * 0.5_dp
      left = left / 8.0_dp
    end do
    c%h = max(c%h, cs%dt_min)
  end subroutine reject

end module step_control
