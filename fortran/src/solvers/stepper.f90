!> The stepper's own data, apart from the mechanical system it steps (issue 25): the
!> settings of a run (set once per run through system_stepper_setup, not re-sent with every
!> chunk) and what the stepper learns from step to step (the contraction estimate of the
!> simplified Newton, the back-off of jacobian_reuse, the predictor's choice). The system
!> (mechanical_system) keeps what belongs to the model and its iteration matrix (the
!> factorization, its beta' and its active contact points); a new stepper policy edits
!> this module and time_integrator, not the system type. system_store holds one
!> stepper_run beside each system; time_integrator reads and updates it.
!>
!> The packed arrays of system_advance (one state vector in and out, one output row per
!> step) are laid out here, in one place: state_size, row_size and the offsets below.
module stepper
  use ancf_kinds, only: dp
  use mechanical_system, only: power_count, energy_count, contact_record
  use row_answers, only: answer_data
  implicit none
  private
  public :: stepper_settings, stepper_state, stepper_run, stepper_start, update_reuse_backoff, &
            state_size, row_size, control_settings, control_state

  !> the stepping method: generalized-alpha (Newmark its special case; time_integrator) or
  !> the energy-momentum midpoint rule (energy_momentum)
  integer, parameter, public :: method_alpha = 0, method_energy_momentum = 1
  !> when a refactorized system's iteration matrix is refreshed (time_integrator)
  integer, parameter, public :: jacobian_step = 1, jacobian_iteration = 2, jacobian_reuse = 3
  !> the most steps jacobian_reuse starts with a fresh matrix before trying an old one again
  integer, parameter :: max_reuse_backoff = 64
  !> the recurrence predictor's order (the differences of e'' each predicted difference
  !> depends on: up to three oscillating modes) and the window of differences it is fitted
  !> to (each over all coordinates); it needs recurrence_span differences of equal steps
  integer, parameter, public :: recurrence_order = 6, recurrence_window = 3, &
                                recurrence_span = recurrence_order + recurrence_window
  !> the steps whose measured contraction jacobian_reuse's bound remembers (their largest)
  integer, parameter, public :: contraction_memory = 16

  !> The settings of a run: the method (method_alpha, method_energy_momentum), the
  !> generalized-alpha parameters (Newmark: alpha_m = alpha_f = 0), the
  !> Newton tolerance (max |de| <= tol * length_scale), the iteration limit, the Jacobian
  !> policy and jacobian_reuse's limit on the ratio of successive corrections. The step h
  !> is not a setting: each chunk gives its own (step control cuts and grows it).
  type :: stepper_settings
    integer :: method = method_alpha
    real(dp) :: beta = 0.25_dp, gamma = 0.5_dp, alpha_m = 0.0_dp, alpha_f = 0.0_dp
    real(dp) :: tol = 1e-10_dp, length_scale = 1.0_dp
    integer :: max_newton = 10
    integer :: jacobian = jacobian_reuse
    real(dp) :: contraction = 0.25_dp
  end type stepper_settings

  !> What the stepper learns while it steps (forgotten at the start of each run).
  type :: stepper_state
    ! the simplified-Newton contraction rate measured with the current factorization (-1:
    ! not yet) and the steps accepted since without measuring it again
    real(dp) :: theta = -1.0_dp
    integer :: unconfirmed = 0
    ! jacobian_reuse back-off: steps that started with a matrix of an earlier step and had
    ! to refresh it (in a row), the current back-off and the steps still to start with a
    ! fresh matrix
    integer :: reuse_failures = 0, reuse_backoff = 0, reuse_skip = 0
    ! the predictor of refactorized systems without contact (time_integrator's
    ! predict_accel): e'' of the two steps before the last (allocated once a step is done),
    ! the number of steps of size predict_step behind them (the extrapolations need equal
    ! steps) and the extrapolation that predicted the last step best
    real(dp), allocatable :: accel_before(:), accel_before2(:), accel_before3(:)
    real(dp) :: predict_step = 0.0_dp
    integer :: predict_history = 0
    integer :: predictor = 0
    ! the recurrence predictor (acceleration_predictor's predict_recurrence): the last
    ! differences d_k = e''_k - e''_{k-1} in a ring (ndof, recurrence_span; newest in column
    ! recurrence_newest), their dot products (recurrence_span, recurrence_span, by lag:
    ! (a + 1, b + 1) for lags a >= b; acceleration_predictor's push_difference), the coefficients fitted to them and the next step's difference they predict
    ! (recurrence_guess; both valid when recurrence_ready)
    real(dp), allocatable :: recurrence_differences(:, :), recurrence_guess(:)
    real(dp) :: recurrence_dots(recurrence_span, recurrence_span) = 0.0_dp
    real(dp) :: recurrence_coefficients(recurrence_order) = 0.0_dp
    integer :: recurrence_newest = 0
    logical :: recurrence_ready = .false.
    ! jacobian_reuse's contraction bound (converged() in time_integrator): the largest
    ! ratio of successive corrections measured from a step's third correction on, in each
    ! of the last contraction_memory steps that measured one with the current
    ! factorization (a ring; matrix_measured: how many, 0 after a factorization), and the
    ! steps accepted on the bound since the last measurement
    real(dp) :: matrix_ratios(contraction_memory) = 0.0_dp
    integer :: matrix_measured = 0
    integer :: matrix_unconfirmed = 0
    ! the matrix carried with the system's rotation (carried_rotation): the carried vectors
    ! at the factorization and at the current step (3, nvec), the turn from them to the current step's predicted
    ! state of each group (body) and whether the step uses them (a turn above
    ! carry_threshold)
    real(dp), allocatable :: carry_reference(:, :), carry_current(:, :)
    real(dp), allocatable :: carry_turn(:, :, :)  ! (3, 3, groups)
    logical :: carry_on = .false.
  end type stepper_state

  !> The step-size control of a run (step_control.f90): the output grid's step dt, the
  !> smallest step a failed or rejected step may be cut to (dt_min, dt / 1024 when given as
  !> 0), step = 'adaptive' (sized by the local error estimate) or 'fixed', and the local
  !> error allowed per step relative to the length scale (adaptive).
  type :: control_settings
    real(dp) :: dt = 0.0_dp, dt_min = 0.0_dp, tolerance = 1e-6_dp
    logical :: adaptive = .false.
  end type control_settings

  !> The step-size control's state, kept from call to call (forgotten at the start of each
  !> run): the controller's step h, the successes since the last cut, the size of the last
  !> step taken (a change restarts the method), the run's counts (cuts, rejections,
  !> restarts, steps taken, the smallest step), and the output interval in progress when a
  !> call's budget ran out inside it (its grid time, the statistics and the row of its last
  !> accepted step so far, its tries since the last accepted step), and the contact guesses
  !> the restarts' force evaluations start from and update.
  type :: control_state
    real(dp) :: h = 0.0_dp, last_h = 0.0_dp, smallest = huge(1.0_dp)
    integer :: successes = 0, cuts = 0, rejected = 0, restarts = 0, taken = 0
    logical :: started = .false.
    ! the output interval in progress (open) and what it has done so far
    logical :: open = .false.
    real(dp) :: target = 0.0_dp, interval_smallest = huge(1.0_dp)
    integer :: interval_stats(3) = 0, interval_cuts = 0, interval_taken = 0, tries = 0
    real(dp), allocatable :: row(:)
    ! a whole step at dt failed and was cut: the next interval starts with its work and cut
    logical :: carried = .false.
    integer :: carried_stats(3) = 0
    ! the grid rows done in the run (adaptive: the grid times are t0 + k dt) and t0
    integer :: rows = 0
    real(dp) :: t0 = 0.0_dp
    real(dp), allocatable :: restart_guesses(:, :)
    ! the block of whole steps in progress of a method without numerical damping on a
    ! constrained system (step_control's neutral_method): its steps so far, the largest
    ! period-2 part of the multipliers and the largest |lambda| in it, and its last two
    ! rows' multipliers (how many are held): carried from call to call, so the chunk sizes
    ! do not change the run; the quietest full block's period-2 part of the run (huge: none)
    integer :: block_steps = 0, block_held = 0
    real(dp) :: block_swing = 0.0_dp, block_peak = 0.0_dp, quiet_swing = huge(1.0_dp)
    real(dp), allocatable :: block_lambda(:, :)
  end type control_state

  !> A system's stepper: its run's settings, its learned state, its step-size control,
  !> whether a run was set up, what its rows answer (row_answers; none unless set up).
  type :: stepper_run
    type(stepper_settings) :: settings
    type(stepper_state) :: state
    type(control_settings) :: control_settings
    type(control_state) :: control
    type(answer_data) :: answers
    logical :: ready = .false.
  end type stepper_run

contains

  !> A new run with these settings: what earlier runs learned is forgotten (a run from a new
  !> initial state then gives the same result on any handle).
  pure subroutine stepper_start(run, settings, control)
    type(stepper_run), intent(inout) :: run
    type(stepper_settings), intent(in) :: settings
    type(control_settings), intent(in) :: control
    run%settings = settings
    run%state = stepper_state()
    run%control_settings = control
    if (run%control_settings%dt_min <= 0.0_dp) run%control_settings%dt_min = control%dt / 1024.0_dp
    run%control = control_state()
    run%answers = answer_data()
    run%control%h = control%dt
    run%control%last_h = control%dt
    run%ready = .true.
  end subroutine stepper_start

  !> The length of system_advance's packed state, in this order: t; e, e', a, e'' (ndof
  !> each); lambda (ncon); the accumulated works and the powers at the state (power_count
  !> each); the contact guesses (2, npoint).
  pure integer function state_size(ndof, ncon, npoint)
    integer, intent(in) :: ndof, ncon, npoint
    state_size = 1 + 4 * ndof + ncon + 2 * power_count + 2 * npoint
  end function state_size

  !> The length of one output row of system_advance, in this order: the time; the probe
  !> positions and their deflections (3, nprobe each); lambda (ncon); the energies
  !> (energy_count); the constraint violation max |Phi|; the contact records
  !> (contact_record, npoint); the run's answers (nanswer: row_answers answer_count); and,
  !> when the coordinates are stored, e (ndof).
  pure integer function row_size(ndof, ncon, nprobe, npoint, nanswer, store_q)
    integer, intent(in) :: ndof, ncon, nprobe, npoint, nanswer
    logical, intent(in) :: store_q
    row_size = 1 + 6 * nprobe + ncon + energy_count + 1 + contact_record * npoint + nanswer
    if (store_q) row_size = row_size + ndof
  end function row_size

  !> jacobian_reuse's back-off after a step that started with a matrix of an earlier step:
  !> refreshed, it had to refresh that matrix (or retry with a fresh one). Two such steps in
  !> a row double the back-off (1, 2, 4 .. max_reuse_backoff steps start fresh); a step that
  !> succeeds with the old matrix halves it.
  pure subroutine update_reuse_backoff(learned, refreshed)
    type(stepper_state), intent(inout) :: learned
    logical, intent(in) :: refreshed
    if (refreshed) then
      learned%reuse_failures = learned%reuse_failures + 1
      if (learned%reuse_failures >= 2) then
        learned%reuse_backoff = min(max(1, 2 * learned%reuse_backoff), max_reuse_backoff)
        learned%reuse_skip = learned%reuse_backoff
      end if
    else
      learned%reuse_failures = 0
      learned%reuse_backoff = learned%reuse_backoff / 2
    end if
  end subroutine update_reuse_backoff

end module stepper
