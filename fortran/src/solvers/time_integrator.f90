!> Implicit time stepping of a mechanical system (mechanical_system):
!>   M e'' + B^T (Q_el - Q_c - Q_M) - Q(t) - Phi_e^T lambda = 0,   Phi(e, t) = 0,
!> by the generalized-alpha method (Chung-Hulbert, in the form of Arnold and Bruels for
!> constrained systems) with Newmark (alpha_m = alpha_f = 0) as its special case:
!>   (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) e''_{n+1} + alpha_f e''_n,
!>   e_{n+1} = e_n + h e'_n + h^2 ((1/2 - beta) a_n + beta a_{n+1}),
!>   e'_{n+1} = e'_n + h ((1 - gamma) a_n + gamma a_{n+1}),
!> Newton on (e_{n+1}, lambda_{n+1}) with the iteration matrix S = beta' M + K (+ the
!> contact Jacobian times c_v = gamma / (beta h)), beta' = (1 - alpha_m) / (beta h^2
!> (1 - alpha_f)). The multipliers enter through a Schur complement built from the
!> flexibility S^{-1} E_c at the 3-vectors the constraints touch (E_c: their unit vectors in
!> the solver frame), so a Newton correction costs one back-substitution plus small dense
!> algebra (small_lu; LAPACK dgesv for many multipliers). The Jacobians of the dead moments
!> and of lambda . Phi_ee are left out of S; the residual is exact. A correction with
!> max |de| <= tol * length_scale ends the step (jacobian_reuse and the constant policy: an
!> error estimate below it, see converged; jacobian_reuse ends no step on a correction of a
!> kept matrix without a measured contraction).
!>
!> The run's settings and what the stepper learns from step to step (contraction estimate,
!> reuse back-off, predictor) live apart from the system, in stepper.f90's stepper_run; the
!> system keeps its iteration matrix (the factorization, its beta' and active contact
!> points) and answers the stepper's one contact question, contact_step_limit.
!>
!> When S is factorized (the Jacobian policy of the stepper's settings):
!> * the system's policy 'constant' (pure FFR in prescribed frames): once, in the solver
!>   frame, for the whole run (every 3 x 3 block of M is a scalar times I3, so
!>   beta' M + T K0 T^T = T (beta' M + K0) T^T for any frame rotation);
!> * jacobian_step: at the predicted state of every step, and again at the current iterate
!>   whenever a correction is not below half the previous one;
!> * jacobian_iteration: at every iterate (full Newton);
!> * jacobian_reuse (modified Newton across steps): kept from step to step while Newton
!>   contracts; refreshed at the current iterate when a correction is not below
!>   `contraction` times the previous one (from the step's third correction on:
!>   min(contraction, settled_contraction) times it), when the number of active contact points
!>   differs from the factorization's, when beta' changed; a step that fails with a
!>   matrix from an earlier step is retried once from its start with a fresh one. Where the
!>   matrix of an earlier step does not serve (two steps in a row that started with it had
!>   to refresh it: a fast rotation turns the stiff directions in every step), the next
!>   steps start with a fresh matrix, 1, 2, 4 .. max_reuse_backoff of them before reuse is
!>   tried again; a step that succeeds with an old matrix halves the back-off.
!> The predictor without contact takes the extrapolation of e''_{n+1} that came nearest the
!> last step's converged e'' (acceleration_predictor's learn_predictor; max norm): e''_n, e''_{n-1}, the linear
!> 2 e''_n - e''_{n-1}, the quadratic 3 e''_n - 3 e''_{n-1} + e''_{n-2}, the linear one
!> with a period-2 alternation e''_n + e''_{n-1} - e''_{n-2}, or the fitted recurrence
!> e''_n + alpha d_n + beta d_{n-1} (d_k = e''_k - e''_{k-1}; alpha, beta fitted to the last
!> three differences over all coordinates: one dominant mode, e.g. the cable's ringing
!> axial mode at rho_inf = 1), or the recurrence of order 6 e''_n + sum_j c_j d_{n+1-j}
!> fitted to the last nine differences (several modes at once: the 5-node cable pendulum's
!> ringing e'' predicted ~75 times better, its first correction ~1e-7 m instead of ~1e-5)
!> (the extrapolations only across steps of the same size). A
!> smooth motion (the spin-up's rotating acceleration) is predicted to O(h^3) instead of
!> O(h): the first correction of the W = 4 spin-up, 11 nodes, dt 5e-3, falls from ~6e-6 m,
!> the step from 2.84 to 1.80 corrections; the 5-node cable pendulum 3.37 -> 2.82. The
!> alternation: the trapezoidal rule (Newmark 1/4, 1/2; generalized-alpha at
!> rho_inf = 1) leaves index-3 constraints an undamped acceleration and multiplier
!> oscillation of period 2 h that does not move the positions (e_{n+1} - 2 e_n + e_{n-1} =
!> h^2/4 (a_{n+1} + 2 a_n + a_{n-1})), and e''_{n-1} predicts it exactly: the luffing boom's
!> first correction 3e-8 to 5e-7 m instead of 1.3e-5, 2.2 corrections per step instead of 3.0.
!> Penalty contact uses the predictor q_{n+1} = q_n and damps corrections to half a
!> thickness (an acceleration predictor carries a contact impulse of the last step into the
!> next one, far through the other leaf).
!> No I/O; failures return codes (see integrator_chunk).
module time_integrator
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state, frame_rotations, internal_forces, &
                               external_forces, refactorize, to_solver_frame, frame_gradients, &
                               energies, probe_output, policy_constant, drive_step_work, &
                               power_drive, power_count, energy_count, contact_record, &
                               contact_step_limit
  use system_constraints, only: evaluate_constraints, constraint_reaction, gradient_product
  use system_mass, only: mass_product
  use stepper, only: stepper_settings, stepper_state, jacobian_step, jacobian_iteration, &
                     jacobian_reuse, update_reuse_backoff, contraction_memory, &
                     method_energy_momentum
  use energy_momentum, only: energy_momentum_chunk, em_unsupported
  use kernel_errors, only: failure_text, message_length
  use acceleration_predictor, only: extrapolate, usable_predictor, learn_predictor
  use sparse_direct, only: solver_solve
  use carried_rotation, only: carry_turn, carry_gradients, carry_plane_gradients
  use system_carry, only: carry_enabled, carry_vectors, carry_apply, plane_turn_rows
  implicit none
  private
  public :: integrator_chunk, output_row, step_failure_text, step_work, allocate_work
  !> per-step statistics: Newton corrections, factorizations, Jacobian evaluations
  integer, parameter, public :: stat_corrections = 1, stat_factorizations = 2, &
                                stat_jacobians = 3, stat_count = 3
  !> why a step's Newton iteration ended without meeting the tolerance (the detail of
  !> info = 1): the iteration limit; a stall at the round-off floor of the corrections (the
  !> tolerance asks for more digits than the arithmetic carries); a stall above it; growth
  !> (divergence)
  integer, parameter, public :: newton_limit = 0, newton_floor_stall = 1, newton_stall = 2, &
                                newton_diverged = 3
  !> corrections that set no new minimum in this many iterations in a row: a stall
  integer, parameter :: stall_iterations = 4
  !> the round-off floor of a correction, in ulps of the largest coordinate (or the length
  !> scale): a correction there is the solve of a residual that is round-off noise
  real(dp), parameter :: floor_ulps = 1000.0_dp
  !> the largest error a refactorized system's step without contact may keep, as a
  !> fraction of its motion (max |e_new - e_n| of the predicted state; converged), whatever
  !> newton_tol x L allows: the error
  !> delta e left in e_{n+1} moves e'_{n+1} by gamma / (beta h) delta e and e''_{n+1} by
  !> beta' delta e, a relative change of about 2 delta e / |e_{n+1} - e_n| in the velocity,
  !> and the predictor extrapolates both into the next step. newton_tol x L alone allowed
  !> 0.8 mm per step on the 7.8 m luffing boom at newton_tol = 1e-4, as much as the boom
  !> moves in a step: the nonlinear cubic boom (10 nodes, dt 1e-3) failed at t = 6.2 s, the
  !> 4-node one at 0.8 s; at 0.046 of the motion (first corrections accepted below
  !> newton_tol^(1/3) of it at 1e-4) the 4-node boom's energy grew without bound. At
  !> newton_tol = 1e-10 the fraction binds only below 100 tol L of motion per step (a
  !> start from rest). Contact steps start from q + h v, without the accelerations'
  !> extrapolation (the leaf spring runs at newton_tol = 1e-4 without it), and their
  !> nearly static steps would pay up to 70 % more corrections for it.
  real(dp), parameter :: motion_fraction = 1e-2_dp
  !> jacobian_reuse: the largest first correction of a matrix kept from earlier steps that
  !> may end a step, as a fraction of the step's motion (converged; the square of
  !> motion_fraction): a first correction shows no contraction, and what it leaves enters
  !> the velocity as 2 delta e / h unchecked. At newton_tol = 1e-10 it binds only below
  !> 1e-5 L of motion per step; at 1e-2 .. 1e-5, where the limit is the motion cap, steps
  !> whose first corrections ended them on the plain test failed (the 10-node cubic boom at
  !> dt 5e-3 at t = 6.03 s; the W = 4 spin-up at 1e-2 .. 1e-5, issue 38)
  real(dp), parameter :: first_fraction = motion_fraction**2
  !> the smallest newton_tol that double precision resolves: a stall at the floor with a
  !> tolerance at least this is converged (counted); below it the tolerance cannot be met
  real(dp), parameter :: resolvable_tol = 100.0_dp * epsilon(1.0_dp)
  !> jacobian_reuse: the ratio of successive corrections a matrix must keep from the
  !> step's second ratio on (the first, from the predictor's error, is held to the
  !> settings' contraction); a matrix that contracts worse costs more corrections than its
  !> refresh on the small stiff systems of issue 23 (the 17-node cable pendulum, dt 1e-3:
  !> 5966 corrections and 21 factorizations -> 4719 and 68, 20 % fewer instructions)
  real(dp), parameter :: settled_contraction = 0.1_dp
  !> the smallest turn (rad) since the factorization that jacobian_reuse carries the matrix
  !> through (carried_rotation); below it the unturned matrix is as good
  real(dp), parameter :: carry_threshold = 1e-3_dp
  !> the most multipliers whose Schur complement is solved by small_lu (LAPACK's dgesv,
  !> dgetrf and dgetrs above: for 2 multipliers they cost ~800 instructions a call, most of
  !> it the library's dispatch and workspace)
  integer, parameter :: small_dense_limit = 8

  !> The stagnation and divergence test of a step's Newton iteration (reset at each try).
  type :: newton_monitor
    real(dp) :: smallest = huge(1.0_dp)  ! the smallest correction so far
    integer :: since_smallest = 0        ! corrections since it, none smaller
    integer :: growing = 0               ! corrections in a row larger than the previous
    integer :: outcome = newton_limit    ! why the iteration ended unconverged
    logical :: at_floor = .false.        ! converged at the round-off floor (counted)
  end type newton_monitor

  !> The work arrays of the steps' Newton iterations and residuals, allocated once by the
  !> caller of integrator_chunk for all its chunks (step_control: once per call of
  !> controlled_rows, which takes single steps when the rows answer or the step adapts;
  !> automatic arrays and matmul temporaries were heap allocations in every step). What
  !> they cache depends on the system and the time alone.
  type :: step_work
    real(dp), allocatable :: r(:), z(:, :), direction(:), correction(:), back(:)
    real(dp), allocatable :: phi(:), gradients(:, :), w(:, :), flex_w(:, :), w_dlam(:)
    real(dp), allocatable :: schur(:, :), dlam(:, :), internal(:), loads(:), records(:, :)
    real(dp), allocatable :: full(:), row_phi(:), row_gradients(:, :), row_ndof(:)
    real(dp), allocatable :: full_pair(:, :)
    integer, allocatable :: ipiv(:)
    ! loads holds the external loads at loads_time (residual)
    logical :: loads_ready = .false.
    real(dp) :: loads_time = 0.0_dp
    ! the carried matrix's Schur complement (carried_rotation): T^T Phi_e^T, S^{-1} of it and
    ! the LU factors of C, built at a step's first carried correction
    real(dp), allocatable :: carry_columns(:, :), carry_flexibility(:, :), carry_lu(:, :)
    ! carry_gradients' column of Phi_e^T (its work array), and the row of w (E_c^T) of each
    ! reduced coordinate (0: in no touched block; a dof in two blocks: the first), made once
    ! by allocate_work for gather_blocks (automatic arrays were heap allocations in every step)
    real(dp), allocatable :: carry_column(:)
    integer, allocatable :: block_row(:)
    ! the reduced coordinates in touched blocks (block_row > 0), and those outside them
    ! that T^T Phi_e^T can make nonzero (scan_known: the list holds; else all are scanned)
    integer, allocatable :: touched_dofs(:), scan_dofs(:)
    logical :: scan_known = .false.
    ! a planar reduction with scan_known: the pairs (carry_plane) holding a touched or a
    ! scanned coordinate, the only rows of T^T Phi_e^T that gather_blocks reads
    integer, allocatable :: carry_pairs(:)
  end type step_work

contains

  !> The work arrays of sys's steps.
  pure subroutine allocate_work(sys, work)
    type(system_model), intent(in) :: sys
    type(step_work), intent(out) :: work
    integer :: nb, b, j, ncon
    nb = 3 * size(sys%matrix%block_first)
    ncon = sys%constraints%ncon
    allocate (work%r(sys%ndof), work%z(sys%ndof, 1), work%direction(sys%ndof), &
              work%correction(sys%ndof), work%back(sys%ndof), work%phi(ncon), &
              work%gradients(6, ncon), work%w(nb, ncon), work%flex_w(nb, ncon), &
              work%w_dlam(nb), work%schur(ncon, ncon), work%dlam(ncon, 1), &
              work%internal(sys%ndof), work%loads(sys%ndof), &
              work%records(contact_record, max(1, sys%contact%npoint)), work%ipiv(ncon), &
              work%full(sys%nfull), work%row_phi(ncon), work%row_gradients(6, ncon), &
              work%row_ndof(sys%ndof), work%full_pair(sys%nfull, 2))
    if (carry_enabled(sys%carry)) then
      allocate (work%carry_columns(sys%ndof, ncon), &
                work%carry_flexibility(sys%ndof, ncon), work%carry_lu(ncon, ncon), &
                work%carry_column(sys%ndof), work%block_row(sys%ndof))
      work%block_row = 0
      do b = size(sys%matrix%block_first), 1, -1
        do j = 0, min(2, sys%ndof - sys%matrix%block_first(b))
          work%block_row(sys%matrix%block_first(b) + j) = 3 * (b - 1) + j + 1
        end do
      end do
      work%touched_dofs = pack([(j, j = 1, sys%ndof)], work%block_row > 0)
      call carry_scan_setup(sys, work)
    end if
  end subroutine allocate_work

  !> work%scan_dofs: the reduced coordinates outside the touched blocks (block_row = 0)
  !> where carry_gradients' columns T^T Phi_e^T can be nonzero. Column c of Phi_e^T is
  !> nonzero at the constraints' term dofs only, and T^T (carry_apply) turns each carried
  !> 3-vector on its own: a vector without a term dof gets exactly +-0 from a finite turn
  !> (r11 * 0 + r12 * 0 + r13 * 0), which gather_blocks' test (/= 0) passes. So with a finite
  !> turn only the coordinates of vectors holding a term dof need the test. scan_known =
  !> .false. (every coordinate tested, as before) unless each reduced coordinate is in
  !> exactly one carried vector.
  pure subroutine carry_scan_setup(sys, work)
    type(system_model), intent(in) :: sys
    type(step_work), intent(inout) :: work
    integer :: vector_of(sys%ndof), b, i, k, dof
    logical :: reached(sys%ndof)
    work%scan_known = .false.
    allocate (work%scan_dofs(0))
    if (sys%constraints%ncon == 0) return
    vector_of = 0
    do b = 1, size(sys%carry%map, 2)
      do i = 1, 3
        dof = sys%carry%map(i, b)
        if (dof <= 0) cycle
        if (dof > sys%ndof) return
        if (vector_of(dof) /= 0) return
        vector_of(dof) = b
      end do
    end do
    if (any(vector_of == 0)) return
    reached = .false.
    do k = sys%constraints%term_ptr(1), sys%constraints%term_ptr(6 * sys%constraints%ncon + 1) - 1
      dof = sys%constraints%term_dof(k)
      if (dof < 1 .or. dof > sys%ndof) return
      b = vector_of(dof)
      do i = 1, 3
        if (sys%carry%map(i, b) > 0) reached(sys%carry%map(i, b)) = .true.
      end do
    end do
    work%scan_dofs = pack([(dof, dof = 1, sys%ndof)], reached .and. work%block_row == 0)
    work%scan_known = .true.
    if (.not. allocated(sys%carry%plane)) return
    ! (every term dof is reached: its pair is among them)
    reached = reached .or. work%block_row > 0
    work%carry_pairs = pack([(k, k = 1, size(sys%carry%plane, 2))], &
                            reached(sys%carry%plane(1, :)) .or. reached(sys%carry%plane(2, :)))
  end subroutine carry_scan_setup

  !> Residual r = M e'' + B^T (Q_el - Q_c - Q_M) - Q(t) - Phi_e^T lambda at time t, with the
  !> constraint values and gradients, the strain energy and the number of active contact
  !> points; known_internal: B^T (Q_el - Q_c - Q_M) already computed (by refactorize).
  subroutine residual(sys, t, rotations, rates, e, v, acceleration, lam, state, r, phi, &
                      gradients, strain, active, work, info, known_internal)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: t, rotations(:, :, 0:), rates(0:), e(:), v(:), acceleration(:)
    real(dp), intent(in) :: lam(:)
    type(contact_state), intent(inout) :: state
    real(dp), intent(inout) :: strain  ! out; in with known_internal
    real(dp), intent(out) :: r(:), phi(:), gradients(:, :)
    integer, intent(inout) :: active   ! out; in with known_internal
    type(step_work), intent(inout) :: work  ! its internal, loads and records
    integer, intent(out) :: info
    real(dp), intent(in), optional :: known_internal(:)
    real(dp) :: potential, powers(2)
    info = 0
    associate (internal => work%internal, loads => work%loads, records => work%records)
    if (present(known_internal)) then
      internal = known_internal
    else
      call internal_forces(sys, rotations, e, v, 1.0_dp, 0.0_dp, state, internal, strain, &
                           potential, powers, records, info, rates=rates, force_time=t, &
                           full_work=work%full_pair)
      if (info /= 0) return
      if (sys%contact%npoint > 0) active = count(records(1, 1:sys%contact%npoint) > 0.0_dp)
    end if
    call mass_product(sys%mass, acceleration, r)
    ! (loads of t alone, without point loads that follow e: once per time, kept for the
    ! step's later corrections; without driven loads (force_drive) they are constant_force
    ! at every time: once per work arrays)
    if (sys%loads%nvload > 0 .or. .not. work%loads_ready .or. &
        (work%loads_time /= t .and. size(sys%loads%force_drive) > 0)) then
      work%loads_ready = .false.
      call external_forces(sys, t, 1.0_dp, loads, info, e)
      if (info /= 0) return
      work%loads_ready = .true.
      work%loads_time = t
    end if
    r = r + internal - loads
    call evaluate_constraints(sys%constraints, sys%drives, sys%ndof, e, t, phi, gradients, info)
    if (info /= 0) return
    call constraint_reaction(sys%constraints, gradients, lam, r)
    end associate
  end subroutine residual

  !> Advances nsteps steps of size h from (t, e, e' = v, a, e'' = accel, lambda) with the
  !> run's settings cfg and the learned state of the run's earlier steps, writing one output
  !> row per step; a is the generalized-alpha acceleration-like variable (= e'' for
  !> Newmark). work(power_count) accumulates the works of the drives, the moving frames,
  !> contact damping and friction. info: 0 ok; 1 Newton did not converge; 2 non-finite
  !> state; 3 linear solve failed (detail = solver code); 4 singular Schur complement
  !> (detail = dgesv info); 5 constraint or drive evaluation failed; 6 moment undefined; 7 a
  !> plate element's normal vanished; 8 contact search failed. steps_done counts the
  !> completed steps; the state is that of the last completed step; last_correction is the
  !> size of the last Newton correction (why a step failed to converge). scratch: the
  !> steps' work arrays (allocate_work for sys), made once by the caller for all its calls.
  subroutine integrator_chunk(sys, cfg, learned, h, nsteps, t, e, v, a, accel, lam, work, &
                              powers, state, out_time, out_probe, out_deflection, out_lambda, &
                              out_energy, out_constraint, out_stats, out_contact, store_q, &
                              out_q, steps_done, info, detail, last_correction, floor_accepts, &
                              scratch)
    type(system_model), intent(inout) :: sys
    type(stepper_settings), intent(in) :: cfg
    type(stepper_state), intent(inout) :: learned
    real(dp), intent(in) :: h
    integer, intent(in) :: nsteps
    real(dp), intent(inout) :: t, e(:), v(:), a(:), accel(:), lam(:), work(power_count)
    real(dp), intent(inout) :: powers(power_count)  ! the powers at the current state
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: out_time(:), out_probe(:, :, :), out_deflection(:, :, :)
    real(dp), intent(out) :: out_lambda(:, :), out_energy(:, :), out_constraint(:)
    integer, intent(out) :: out_stats(:, :)
    real(dp), intent(out) :: out_contact(:, :, :)  ! (contact_record, npoint, nsteps)
    logical, intent(in) :: store_q
    real(dp), intent(out) :: out_q(:, :)
    integer, intent(out) :: steps_done, info, detail
    real(dp), intent(out) :: last_correction  ! max |de| of the last Newton correction
    integer, intent(out) :: floor_accepts  ! steps converged at the round-off floor
    type(step_work), intent(inout) :: scratch
    type(newton_monitor) :: monitor
    real(dp) :: e_new(sys%ndof), a_new(sys%ndof), accel_new(sys%ndof), v_new(sys%ndof)
    real(dp) :: lam_new(sys%constraints%ncon), predicted_internal(sys%ndof)
    real(dp) :: rotations(3, 3, 0:size(sys%frames)), rates(0:size(sys%frames))
    real(dp) :: powers_new(power_count), strain
    real(dp) :: contact_potential, beta_prime, velocity_factor, step_drive_work
    real(dp) :: motion  ! max |e_new - e| of the step's predicted state
    integer :: step, attempt, stats(stat_count), i
    logical :: done, fresh_matrix, start_fresh, started_old
    logical :: constraints_checked  ! scratch's phi and gradients are those of the new state
    if (cfg%method == method_energy_momentum) then
      ! (its own Newton on the midpoint rule: energy_momentum.f90)
      floor_accepts = 0
      call energy_momentum_chunk(sys, cfg, h, nsteps, t, e, v, a, accel, lam, work, powers, &
                                 state, out_time, out_probe, out_deflection, out_lambda, &
                                 out_energy, out_constraint, out_stats, out_contact, store_q, &
                                 out_q, steps_done, info, detail, last_correction)
      return
    end if
    info = 0
    detail = 0
    steps_done = 0
    last_correction = 0.0_dp
    floor_accepts = 0
    out_stats = 0
    beta_prime = (1.0_dp - cfg%alpha_m) / (cfg%beta * h * h * (1.0_dp - cfg%alpha_f))
    velocity_factor = cfg%gamma / (cfg%beta * h)
    do step = 1, nsteps
      stats = 0
      call frame_rotations(sys, t + h, rotations, rates, info)
      if (info /= 0) return
      start_fresh = learned%reuse_skip > 0
      if (start_fresh) learned%reuse_skip = learned%reuse_skip - 1
      started_old = .false.
      do attempt = 1, 2
        call predict(sys, cfg, learned, h, e, v, a, accel, e_new, v_new, a_new, accel_new)
        ! (the multipliers' copies by loops: a few entries, no memcpy call)
        do i = 1, sys%constraints%ncon
          lam_new(i) = lam(i)
        end do
        fresh_matrix = .false.
        if (needs_factorization(sys, cfg, beta_prime, attempt) .or. start_fresh) then
          call factorize(sys, learned, beta_prime, velocity_factor, rotations, e_new, v_new, &
                         state, predicted_internal, strain, info, detail, rates, t + h)
          if (info /= 0) return
          stats(stat_factorizations) = stats(stat_factorizations) + 1
          stats(stat_jacobians) = stats(stat_jacobians) + 1
          fresh_matrix = sys%matrix%policy /= policy_constant
        else if (attempt == 1) then
          started_old = sys%matrix%policy /= policy_constant
        end if
        call carry_step(sys, cfg, learned, fresh_matrix, e_new)
        ! (the step's motion: the scale of converged's test; the constant policy's
        ! linear steps and contact do not read it)
        motion = 0.0_dp
        if (sys%matrix%policy /= policy_constant .and. sys%contact%npoint == 0) then
          do i = 1, sys%ndof
            motion = max(motion, abs(e_new(i) - e(i)))
          end do
        end if
        call newton(sys, cfg, learned, t + h, rotations, rates, beta_prime, velocity_factor, &
                    e_new, v_new, accel_new, lam_new, state, predicted_internal, fresh_matrix, &
                    motion, stats, done, last_correction, monitor, scratch, info, detail, &
                    constraints_checked)
        if (info /= 0) return
        ! a step that started with a matrix of an earlier step and failed (even if it
        ! refreshed the matrix on the way) gets one retry from its start with a fresh one
        if (done .or. cfg%jacobian /= jacobian_reuse .or. sys%matrix%policy == policy_constant &
            .or. fresh_matrix) exit
      end do
      if (.not. done) then
        ! the failed step's work is reported in its row (not a completed step)
        out_stats(:, step) = stats
        info = 1
        detail = monitor%outcome
        return
      end if
      if (monitor%at_floor) floor_accepts = floor_accepts + 1
      if (started_old) call update_reuse_backoff(learned, stats(stat_factorizations) > 0)
      ! the drives' work over the step, from (t, e, lambda) to (t + h, e_new, lambda_new)
      call drive_step_work(sys, t, t + h, e, e_new, lam, lam_new, step_drive_work, info)
      if (info /= 0) return
      ! accept the step
      ! (one pass: each coordinate's a_new, v, e and a by the same expressions as the
      ! array statements they replace, without their separate loops and copies)
      do i = 1, sys%ndof
        a_new(i) = (cfg%alpha_f * accel(i) + (1.0_dp - cfg%alpha_f) * accel_new(i) &
                    - cfg%alpha_m * a(i)) / (1.0_dp - cfg%alpha_m)
        v(i) = v(i) + h * ((1.0_dp - cfg%gamma) * a(i) + cfg%gamma * a_new(i))
        e(i) = e_new(i)
        a(i) = a_new(i)
      end do
      ! the predictor of the next step: the extrapolation that came nearest e''_{n+1}
      ! (refactorized systems without contact only: the others never use it)
      if (sys%contact%npoint == 0 .and. sys%matrix%policy /= policy_constant) &
        call learn_predictor(learned, h, accel, accel_new)
      accel = accel_new
      do i = 1, sys%constraints%ncon
        lam(i) = lam_new(i)
      end do
      t = t + h
      ! (a step accepted on the contraction estimate evaluated its constraints at e_new,
      ! t + h: the energies read them instead of evaluating them again)
      if (constraints_checked) then
        call energies(sys, rotations, rates, e, v, lam, t, state, strain, powers_new, &
                      contact_potential, out_constraint(step), out_contact(:, :, step), info, &
                      scratch%full, scratch%phi, scratch%gradients, constraints_known=.true.)
      else
        call energies(sys, rotations, rates, e, v, lam, t, state, strain, powers_new, &
                      contact_potential, out_constraint(step), out_contact(:, :, step), info, &
                      scratch%full, scratch%row_phi, scratch%row_gradients)
      end if
      if (info /= 0) return
      work = work + 0.5_dp * h * (powers + powers_new)
      work(power_drive) = work(power_drive) + step_drive_work
      powers = powers_new
      steps_done = step
      out_time(step) = t
      out_stats(:, step) = stats
      do i = 1, sys%constraints%ncon
        out_lambda(i, step) = lam(i)
      end do
      call probe_output(sys, rotations, e, v, work, strain, contact_potential, &
                        out_probe(:, :, step), out_deflection(:, :, step), out_energy(:, step), info, &
                        scratch%full, scratch%row_ndof)
      if (info /= 0) return
      if (store_q) out_q(:, step) = e
    end do
  end subroutine integrator_chunk

  !> The predictor: e''_{n+1} extrapolated (see the module's notes); with penalty
  !> contact e_{n+1} = e_n.
  pure subroutine predict(sys, cfg, learned, h, e, v, a, accel, e_new, v_new, a_new, accel_new)
    type(system_model), intent(in) :: sys
    type(stepper_settings), intent(in) :: cfg
    type(stepper_state), intent(in) :: learned
    real(dp), intent(in) :: h, e(:), v(:), a(:), accel(:)
    real(dp), intent(out) :: e_new(:), v_new(:), a_new(:), accel_new(:)
    integer :: i
    if (sys%contact%npoint == 0) then
      call extrapolate(usable_predictor(learned, h, learned%predictor), accel, learned, &
                       accel_new)
      ! (one pass: each coordinate's a_new, e_new and v_new by the expressions of the array
      ! statements they replace)
      do i = 1, size(e)
        a_new(i) = (cfg%alpha_f * accel(i) + (1.0_dp - cfg%alpha_f) * accel_new(i) &
                    - cfg%alpha_m * a(i)) / (1.0_dp - cfg%alpha_m)
        e_new(i) = e(i) + h * v(i) + h * h * ((0.5_dp - cfg%beta) * a(i) + cfg%beta * a_new(i))
        v_new(i) = v(i) + h * ((1.0_dp - cfg%gamma) * a(i) + cfg%gamma * a_new(i))
      end do
      return
    else
      if (maxval(abs(h * v)) <= contact_step_limit(sys%contact)) then
        e_new = e + h * v
        a_new = -((0.5_dp - cfg%beta) * a) / cfg%beta
      else
        e_new = e
        a_new = -(v / h + (0.5_dp - cfg%beta) * a) / cfg%beta
      end if
      accel_new = ((1.0_dp - cfg%alpha_m) * a_new + cfg%alpha_m * a - cfg%alpha_f * accel) &
                  / (1.0_dp - cfg%alpha_f)
    end if
    v_new = v + h * ((1.0_dp - cfg%gamma) * a + cfg%gamma * a_new)
  end subroutine predict

  !> refactorize (mechanical_system) at (e, e'), the factorization's active contact points
  !> kept by the system; a new factorization (even one whose flexibility solve then failed)
  !> has its contraction rate still to measure.
  subroutine factorize(sys, learned, beta_prime, velocity_factor, rotations, e, v, state, &
                       force, strain, info, detail, rates, t)
    type(system_model), intent(inout) :: sys
    type(stepper_state), intent(inout) :: learned
    real(dp), intent(in) :: beta_prime, velocity_factor, rotations(:, :, 0:), e(:), v(:)
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: force(:), strain
    integer, intent(out) :: info, detail
    real(dp), intent(in) :: rates(0:), t
    call refactorize(sys, beta_prime, velocity_factor, rotations, e, v, state, force, strain, &
                     sys%matrix%factor_active, info, detail, rates, t)
    if (info == 0 .or. (info == 3 .and. sys%matrix%factorized)) then
      learned%theta = -1.0_dp
      learned%unconfirmed = 0
      learned%matrix_measured = 0
      learned%matrix_unconfirmed = 0
    end if
    learned%carry_on = .false.
    if (info == 0 .and. carry_enabled(sys%carry)) then
      if (.not. allocated(learned%carry_reference)) &
        allocate (learned%carry_reference(3, size(sys%carry%first)), &
                  learned%carry_current(3, size(sys%carry%first)), &
                  learned%carry_turn(3, 3, sys%carry%ngroups))
      call carry_vectors(sys%carry, sys%reduction, e, learned%carry_reference)
    end if
  end subroutine factorize

  !> jacobian_reuse with a carried matrix: the turn of the system from the factorization to
  !> the step's predicted state e (carried_rotation), used by the step's corrections when it
  !> exceeds carry_threshold; off with a fresh matrix (factorized at e itself).
  subroutine carry_step(sys, cfg, learned, fresh_matrix, e)
    type(system_model), intent(in) :: sys
    type(stepper_settings), intent(in) :: cfg
    type(stepper_state), intent(inout) :: learned
    logical, intent(in) :: fresh_matrix
    real(dp), intent(in) :: e(:)
    real(dp) :: angle
    integer :: svd_info
    learned%carry_on = .false.
    if (fresh_matrix .or. cfg%jacobian /= jacobian_reuse .or. .not. carry_enabled(sys%carry) .or. &
        .not. sys%matrix%factorized .or. .not. allocated(learned%carry_reference)) return
    call carry_vectors(sys%carry, sys%reduction, e, learned%carry_current)
    call carry_turn(sys, learned%carry_reference, learned%carry_current, learned%carry_turn, &
                    angle, svd_info)
    learned%carry_on = svd_info == 0 .and. angle > carry_threshold
  end subroutine carry_step

  !> Whether the step starts with a new factorization.
  pure logical function needs_factorization(sys, cfg, beta_prime, attempt)
    type(system_model), intent(in) :: sys
    type(stepper_settings), intent(in) :: cfg
    real(dp), intent(in) :: beta_prime
    integer, intent(in) :: attempt
    needs_factorization = .not. sys%matrix%factorized .or. &
                          sys%matrix%factor_beta_prime /= beta_prime
    if (sys%matrix%policy == policy_constant) return
    if (cfg%jacobian /= jacobian_reuse .or. attempt > 1) needs_factorization = .true.
  end function needs_factorization

  !> Newton iterations of one step from the predicted state (updated in place). done: the
  !> last correction met the tolerance.
  subroutine newton(sys, cfg, learned, t_new, rotations, rates, beta_prime, velocity_factor, &
                    e_new, v_new, accel_new, lam_new, state, predicted_internal, fresh_matrix, &
                    motion, stats, done, last_correction, monitor, work, info, detail, &
                    constraints_checked)
    type(system_model), intent(inout) :: sys
    type(stepper_settings), intent(in) :: cfg
    type(stepper_state), intent(inout) :: learned
    real(dp), intent(in) :: t_new, rotations(:, :, 0:), rates(0:), beta_prime, velocity_factor
    real(dp), intent(inout) :: e_new(:), v_new(:), accel_new(:), lam_new(:)
    type(contact_state), intent(inout) :: state
    real(dp), intent(inout) :: predicted_internal(:)
    logical, intent(in) :: fresh_matrix
    real(dp), intent(in) :: motion  ! max |e_new - e_n| of the predicted state
    integer, intent(inout) :: stats(stat_count)
    logical, intent(out) :: done
    real(dp), intent(inout) :: last_correction
    type(newton_monitor), intent(out) :: monitor
    type(step_work), intent(inout) :: work
    integer, intent(out) :: info, detail
    !> done with work%phi and work%gradients evaluated at the final e_new and t_new
    logical, intent(out) :: constraints_checked
    real(dp) :: strain, previous_correction, step_cap, step_theta
    integer :: it, lapack_info, active, i
    integer :: refreshed_at  ! the correction after which the matrix was last refreshed
    logical :: measured      ! the step's contraction entered the learned bound (converged)
    logical :: exact_tangent ! the matrix was factorized at the iterate being corrected
    logical :: theta_seen    ! the step has set learned%theta (converged)
    logical :: use_known, refresh, capped, halt, finite
    real(dp) :: largest_correction, largest_coordinate, step_part
    logical :: carry_ready  ! the carried Schur complement is built for this step
    associate (r => work%r, z => work%z, direction => work%direction, &
               correction => work%correction, phi => work%phi, gradients => work%gradients, &
               w => work%w, schur => work%schur, dlam => work%dlam, ipiv => work%ipiv)
    info = 0
    detail = 0
    done = .false.
    constraints_checked = .false.
    use_known = fresh_matrix
    carry_ready = .false.
    previous_correction = huge(1.0_dp)
    step_theta = 0.0_dp
    refreshed_at = 0
    measured = .false.
    exact_tangent = fresh_matrix
    theta_seen = .false.
    active = sys%matrix%factor_active
    do it = 1, cfg%max_newton
      if (use_known) then
        call residual(sys, t_new, rotations, rates, e_new, v_new, accel_new, lam_new, state, r, &
                      phi, gradients, strain, active, work, info, predicted_internal)
      else
        call residual(sys, t_new, rotations, rates, e_new, v_new, accel_new, lam_new, state, r, &
                      phi, gradients, strain, active, work, info)
      end if
      if (info /= 0) return
      use_known = .false.
      ! reuse: a changed contact set invalidates the matrix before it is used
      if (cfg%jacobian == jacobian_reuse .and. sys%matrix%policy /= policy_constant .and. &
          sys%contact%npoint > 0 .and. active /= sys%matrix%factor_active .and. &
          it < cfg%max_newton) then
        call refresh_matrix()
        if (info /= 0) return
        refreshed_at = it - 1
        exact_tangent = .true.
        call residual(sys, t_new, rotations, rates, e_new, v_new, accel_new, lam_new, state, r, &
                      phi, gradients, strain, active, work, info, predicted_internal)
        if (info /= 0) return
      end if
      ! z = U S^{-1} U^T r (carried: T S^{-1} T^T r)
      if (learned%carry_on) then
        call carry_apply(sys%carry, learned%carry_turn, r, .true., z(:, 1))
      else
        call to_solver_frame(sys%matrix, rotations, r, .true., z(:, 1))
      end if
      call solver_solve(sys%matrix%solver_handle, sys%ndof, 1, z, info, detail)
      if (info /= 0) then
        detail = info
        info = 3
        return
      end if
      if (learned%carry_on) then
        call carry_apply(sys%carry, learned%carry_turn, z(:, 1), .false., direction)
      else
        call to_solver_frame(sys%matrix, rotations, z(:, 1), .false., direction)
      end if
      ! (with constraints both paths below overwrite the correction)
      ! (dlam: written whole by gradient_product in both paths below; empty without constraints)
      if (sys%constraints%ncon == 0) correction = -direction
      if (sys%constraints%ncon > 0 .and. learned%carry_on) then
        ! the Schur complement with the carried matrix: C = G^T S^{-1} G, G = T^T Phi_e^T
        call carry_schur()
        if (info /= 0) return
      else if (sys%constraints%ncon > 0) then
        ! Schur complement C dlam = Phi_e z - Phi, C = W^T (E_c^T S^{-1} E_c) W
        call frame_gradients(sys, rotations, gradients, w)
        call schur_complement(sys%matrix%flexibility_cc, w, work%flex_w, schur)
        call gradient_product(sys%constraints, gradients, direction, dlam(:, 1))
        dlam(:, 1) = dlam(:, 1) - phi
        if (sys%constraints%ncon <= small_dense_limit) then
          call small_lu(schur, ipiv, lapack_info)
          if (lapack_info == 0) call small_lu_solve(schur, ipiv, dlam(:, 1))
        else
          call dgesv(sys%constraints%ncon, 1, schur, sys%constraints%ncon, ipiv, dlam, &
                     sys%constraints%ncon, lapack_info)
        end if
        if (lapack_info /= 0) then
          info = 4
          detail = lapack_info
          return
        end if
        call sparse_columns_product(w, dlam(:, 1), work%w_dlam)
        call sparse_columns_product(sys%matrix%flexibility, work%w_dlam, work%back)
        call to_solver_frame(sys%matrix, rotations, work%back, .false., correction)
        correction = correction - direction
      end if
      capped = .false.
      if (sys%contact%npoint > 0) then
        ! damped Newton with contact: no correction moves a coordinate by more than half a
        ! leaf thickness (a contact that is open at the linearization point has no stiffness
        ! there, and a full step would jump far through the other leaf)
        step_cap = contact_step_limit(sys%contact)
        if (maxval(abs(correction)) > step_cap) then
          capped = .true.
          dlam = dlam * (step_cap / maxval(abs(correction)))
          correction = correction * (step_cap / maxval(abs(correction)))
        end if
      end if
      ! (one pass over the coordinates: the same elementwise updates, the finiteness test,
      ! and the largest |correction| and |e_new| as maxval takes them; max is exact)
      finite = .true.
      largest_correction = 0.0_dp
      do i = 1, sys%ndof
        step_part = correction(i)
        if (.not. abs(step_part) < huge(1.0_dp)) finite = .false.
        e_new(i) = e_new(i) + step_part
        accel_new(i) = accel_new(i) + beta_prime * step_part
        v_new(i) = v_new(i) + velocity_factor * step_part
        largest_correction = max(largest_correction, abs(step_part))
      end do
      lam_new = lam_new + dlam(:, 1)
      stats(stat_corrections) = stats(stat_corrections) + 1
      if (.not. (finite .and. all(abs(lam_new) < huge(1.0_dp)))) then
        info = 2
        return
      end if
      last_correction = largest_correction
      if (converged(sys, cfg, learned, it, last_correction, previous_correction, step_theta, &
                    it - 1 > refreshed_at, exact_tangent, measured, theta_seen, motion)) then
        ! accepted on the contraction estimate with a correction larger than the tolerance:
        ! the constraints (linearized exactly, not contracted by the matrix) must hold to it
        ! too, in the units of the tightest of length and angle
        if (sys%constraints%ncon > 0 .and. last_correction > cfg%tol * cfg%length_scale) then
          call evaluate_constraints(sys%constraints, sys%drives, sys%ndof, e_new, t_new, phi, &
                                    gradients, info)
          if (info /= 0) return
          done = maxval(abs(phi)) <= cfg%tol * min(1.0_dp, cfg%length_scale)
          constraints_checked = done
        else
          done = .true.
        end if
        if (done) return
      end if
      exact_tangent = .false.
      ! (a correction cut to the contact cap says nothing about convergence)
      if (.not. capped) then
        ! (the largest |e_new| only here, where it is read: e_new is finite, max is exact)
        largest_coordinate = 0.0_dp
        do i = 1, sys%ndof
          largest_coordinate = max(largest_coordinate, abs(e_new(i)))
        end do
        call stagnated(monitor, cfg, it, last_correction, previous_correction, &
                       largest_coordinate, halt)
        if (halt) then
          done = monitor%at_floor
          return
        end if
      end if
      if (sys%matrix%policy == policy_constant .or. it >= cfg%max_newton) then
        previous_correction = last_correction
        cycle
      end if
      select case (cfg%jacobian)
      case (jacobian_iteration)
        refresh = .true.
      case (jacobian_reuse)
        ! (the first ratio mostly measures the predictor's linear part; the later ones the
        ! matrix's own contraction, held to settled_contraction)
        if (it >= 3) then
          refresh = last_correction > min(cfg%contraction, settled_contraction) &
                                      * previous_correction
        else
          refresh = last_correction > cfg%contraction * previous_correction
        end if
      case default
        ! a step whose tangent no longer halves the correction (a strongly nonlinear step):
        ! update it at the current iterate
        refresh = last_correction > 0.5_dp * previous_correction
      end select
      if (refresh) then
        call refresh_matrix()
        if (info /= 0) return
        use_known = .true.
        exact_tangent = .true.
        refreshed_at = it
      end if
      previous_correction = last_correction
    end do
    end associate

  contains

    !> dlam and the correction of a carried matrix: F = S^{-1} G (G = T^T Phi_e^T) by one
    !> solve of ncon right-hand sides and the LU factors of C = G^T F, both at the step's
    !> first carried correction and kept for its others (the gradients move little within a
    !> step; the residual and Phi stay exact, so the converged state does not depend on
    !> them); then C dlam = Phi_e z - Phi, correction = T F dlam - z.
    subroutine carry_schur()
      integer :: c
      logical :: partial, inside
      ! (the newton's associate names are not visible here: the work arrays by name)
      if (.not. carry_ready) then
        ! a planar reduction whose rows outside the gathered pairs are known to be +-0 (a
        ! finite turn, carry_scan_setup): T^T Phi_e^T at those pairs only; the whole
        ! columns when the solve below needs them
        partial = allocated(work%carry_pairs)
        if (partial) partial = all(abs(learned%carry_turn) <= huge(1.0_dp))
        if (partial) then
          call carry_plane_gradients(sys, learned%carry_turn, work%gradients, &
                                     work%carry_pairs, work%carry_columns, work%carry_column)
        else
          call carry_gradients(sys, learned%carry_turn, work%gradients, work%carry_columns, &
                               work%carry_column)
        end if
        inside = gather_blocks(work%carry_columns, work%w)
        if (partial .and. .not. inside) &
          call carry_gradients(sys, learned%carry_turn, work%gradients, work%carry_columns, &
                               work%carry_column)
        if (inside) then
          ! within the factorization's flexibility S^{-1} E_c (the model's touched blocks
          ! hold each constrained vector whole): no solve
          ! (matmul's sums by the loops of sparse_columns_product and schur_complement:
          ! the same numbers without the library calls and the temporary)
          do c = 1, sys%constraints%ncon
            call sparse_columns_product(sys%matrix%flexibility, work%w(:, c), &
                                        work%carry_flexibility(:, c))
          end do
          call schur_complement(sys%matrix%flexibility_cc, work%w, work%flex_w, work%carry_lu)
        else
          work%carry_flexibility = work%carry_columns
          call solver_solve(sys%matrix%solver_handle, sys%ndof, sys%constraints%ncon, &
                            work%carry_flexibility, info, detail)
          if (info /= 0) then
            detail = info
            info = 3
            return
          end if
          work%carry_lu = matmul(transpose(work%carry_columns), work%carry_flexibility)
        end if
        if (sys%constraints%ncon <= small_dense_limit) then
          call small_lu(work%carry_lu, work%ipiv, lapack_info)
        else
          call dgetrf(sys%constraints%ncon, sys%constraints%ncon, work%carry_lu, &
                      sys%constraints%ncon, work%ipiv, lapack_info)
        end if
        if (lapack_info /= 0) then
          info = 4
          detail = lapack_info
          return
        end if
        carry_ready = .true.
      end if
      call gradient_product(sys%constraints, work%gradients, work%direction, work%dlam(:, 1))
      work%dlam(:, 1) = work%dlam(:, 1) - work%phi
      if (sys%constraints%ncon <= small_dense_limit) then
        call small_lu_solve(work%carry_lu, work%ipiv, work%dlam(:, 1))
      else
        call dgetrs('N', sys%constraints%ncon, 1, work%carry_lu, sys%constraints%ncon, work%ipiv, &
                    work%dlam, sys%constraints%ncon, lapack_info)
      end if
      if (allocated(sys%carry%plane)) then
        call plane_carried_correction(sys%carry%plane, sys%carry%plane_group, &
                                      learned%carry_turn, &
                                      work%carry_flexibility, work%dlam(:, 1), work%direction, &
                                      work%correction)
        return
      end if
      call sparse_columns_product(work%carry_flexibility, work%dlam(:, 1), work%back)
      call carry_apply(sys%carry, learned%carry_turn, work%back, .false., work%correction)
      work%correction = work%correction - work%direction
    end subroutine carry_schur

    !> w = E_c^T columns (the rows of the touched blocks; a dof in two blocks: the first)
    !> when every nonzero of columns lies in a touched block; .false. otherwise.
    logical function gather_blocks(columns, w) result(inside)
      real(dp), intent(in) :: columns(:, :)
      real(dp), intent(out) :: w(:, :)
      integer :: dof, c, k
      ! (work%block_row, touched_dofs and scan_dofs: made once by allocate_work;
      ! with a finite turn only scan_dofs can hold a nonzero outside the blocks, see
      ! carry_scan_setup; the same w and the same answer as the test of every coordinate)
      w = 0.0_dp
      inside = .true.
      if (work%scan_known .and. all(abs(learned%carry_turn) <= huge(1.0_dp))) then
        do k = 1, size(work%scan_dofs)
          dof = work%scan_dofs(k)
          do c = 1, size(columns, 2)
            if (columns(dof, c) /= 0.0_dp) then
              inside = .false.
              return
            end if
          end do
        end do
        do k = 1, size(work%touched_dofs)
          dof = work%touched_dofs(k)
          do c = 1, size(columns, 2)
            w(work%block_row(dof), c) = columns(dof, c)
          end do
        end do
        return
      end if
      do dof = 1, sys%ndof
        if (work%block_row(dof) > 0) then
          do c = 1, size(columns, 2)
            w(work%block_row(dof), c) = columns(dof, c)
          end do
        else
          do c = 1, size(columns, 2)
            if (columns(dof, c) /= 0.0_dp) then
              inside = .false.
              return
            end if
          end do
        end if
      end do
    end function gather_blocks

    subroutine refresh_matrix()
      call factorize(sys, learned, beta_prime, velocity_factor, rotations, e_new, v_new, state, &
                     predicted_internal, strain, info, detail, rates, t_new)
      if (info /= 0) return
      stats(stat_factorizations) = stats(stat_factorizations) + 1
      stats(stat_jacobians) = stats(stat_jacobians) + 1
      active = sys%matrix%factor_active
    end subroutine refresh_matrix

  end subroutine newton

  !> LU factorization with partial pivoting P A = L U of a small dense matrix in place
  !> (LAPACK dgetf2's algorithm: the first largest |entry| of each column as its pivot,
  !> whole rows swapped; L below the diagonal with a unit diagonal, U on and above it);
  !> info = k > 0: U(k, k) is exactly zero (as dgetrf's info).
  pure subroutine small_lu(a, ipiv, info)
    real(dp), intent(inout) :: a(:, :)
    integer, intent(out) :: ipiv(:), info
    integer :: n, j, k, p
    real(dp) :: swap
    n = size(a, 1)
    info = 0
    do j = 1, n
      p = j - 1 + maxloc(abs(a(j:n, j)), 1)
      ipiv(j) = p
      if (a(p, j) /= 0.0_dp) then
        if (p /= j) then
          ! (entry by entry: a row temporary of unknown size was a heap allocation a call)
          do k = 1, size(a, 2)
            swap = a(j, k)
            a(j, k) = a(p, k)
            a(p, k) = swap
          end do
        end if
        a(j + 1:n, j) = a(j + 1:n, j) / a(j, j)
      else if (info == 0) then
        info = j
      end if
      do k = j + 1, n
        a(j + 1:n, k) = a(j + 1:n, k) - a(j + 1:n, j) * a(j, k)
      end do
    end do
  end subroutine small_lu

  !> Solves A x = b (b overwritten by x) with small_lu's factors of A: the row swaps, the
  !> unit lower and the upper triangular solves (as dgetrs).
  pure subroutine small_lu_solve(a, ipiv, b)
    real(dp), intent(in) :: a(:, :)
    integer, intent(in) :: ipiv(:)
    real(dp), intent(inout) :: b(:)
    integer :: n, j
    real(dp) :: swap
    n = size(a, 1)
    do j = 1, n
      if (ipiv(j) /= j) then
        swap = b(j)
        b(j) = b(ipiv(j))
        b(ipiv(j)) = swap
      end if
    end do
    do j = 1, n - 1
      b(j + 1:n) = b(j + 1:n) - b(j) * a(j + 1:n, j)
    end do
    do j = n, 1, -1
      b(j) = b(j) / a(j, j)
      b(1:j - 1) = b(1:j - 1) - b(j) * a(1:j - 1, j)
    end do
  end subroutine small_lu_solve

  !> The Schur complement C = W^T F W of the multipliers (F = E_c^T S^{-1} E_c, W the
  !> solver-frame gradients at the touched blocks), with flex_w = F W: matmul's sums (each
  !> entry summed over the inner index in increasing order, from 0) without the products
  !> by the zero entries of W (a constraint touches a block or two): the same numbers.
  pure subroutine schur_complement(flexibility_cc, w, flex_w, schur)
    real(dp), intent(in) :: flexibility_cc(:, :), w(:, :)
    real(dp), intent(out) :: flex_w(:, :), schur(:, :)
    integer :: i, j, r
    real(dp) :: total
    do j = 1, size(w, 2)
      flex_w(:, j) = 0.0_dp
      do r = 1, size(w, 1)
        if (w(r, j) == 0.0_dp) cycle
        do i = 1, size(flex_w, 1)
          flex_w(i, j) = flex_w(i, j) + flexibility_cc(i, r) * w(r, j)
        end do
      end do
    end do
    do j = 1, size(w, 2)
      do i = 1, size(w, 2)
        total = 0.0_dp
        do r = 1, size(w, 1)
          if (w(r, i) == 0.0_dp) cycle
          total = total + w(r, i) * flex_w(r, j)
        end do
        schur(i, j) = total
      end do
    end do
  end subroutine schur_complement

  !> The carried correction T F dlam - z of a planar reduction (pairs: carry_plane, every
  !> reduced coordinate in one; groups: the group whose turn turns each) in one pass over
  !> the pairs: each pair's F dlam as sparse_columns_product sums it, turned as carry_apply
  !> turns a plane vector, less z: the same numbers.
  pure subroutine plane_carried_correction(pairs, groups, turn, flexibility, dlam, direction, &
                                           correction)
    integer, intent(in) :: pairs(:, :), groups(:)
    real(dp), intent(in) :: turn(:, :, :), flexibility(:, :), dlam(:), direction(:)
    real(dp), intent(out) :: correction(:)
    real(dp) :: back_x, back_y, r11, r12, r13, r21, r22, r23, d1, d2
    integer :: p, c, first, second, c1, c2, nonzero, current
    current = 0
    ! one or two nonzero multiplier corrections (a pin in the plane): their sums written
    ! out, the same terms in the same order as the loop below (zero ones skipped there too)
    nonzero = count(dlam /= 0.0_dp)
    if (nonzero >= 1 .and. nonzero <= 2) then
      c1 = 0
      c2 = 0
      do c = 1, size(dlam)
        if (dlam(c) == 0.0_dp) cycle
        if (c1 == 0) then
          c1 = c
        else
          c2 = c
        end if
      end do
      d1 = dlam(c1)
      if (nonzero == 1) then
        do p = 1, size(pairs, 2)
          if (groups(p) /= current) then  ! (the turn of the pair's group)
            current = groups(p)
            call plane_turn_rows(turn(:, :, current), r11, r12, r13, r21, r22, r23)
          end if
          first = pairs(1, p)
          second = pairs(2, p)
          back_x = 0.0_dp + flexibility(first, c1) * d1
          back_y = 0.0_dp + flexibility(second, c1) * d1
          correction(first) = (r11 * back_x + r12 * back_y + r13) - direction(first)
          correction(second) = (r21 * back_x + r22 * back_y + r23) - direction(second)
        end do
        return
      end if
      d2 = dlam(c2)
      do p = 1, size(pairs, 2)
        if (groups(p) /= current) then  ! (the turn of the pair's group)
          current = groups(p)
          call plane_turn_rows(turn(:, :, current), r11, r12, r13, r21, r22, r23)
        end if
        first = pairs(1, p)
        second = pairs(2, p)
        back_x = 0.0_dp + flexibility(first, c1) * d1 + flexibility(first, c2) * d2
        back_y = 0.0_dp + flexibility(second, c1) * d1 + flexibility(second, c2) * d2
        correction(first) = (r11 * back_x + r12 * back_y + r13) - direction(first)
        correction(second) = (r21 * back_x + r22 * back_y + r23) - direction(second)
      end do
      return
    end if
    do p = 1, size(pairs, 2)
      if (groups(p) /= current) then  ! (the turn of the pair's group)
        current = groups(p)
        call plane_turn_rows(turn(:, :, current), r11, r12, r13, r21, r22, r23)
      end if
      first = pairs(1, p)
      second = pairs(2, p)
      back_x = 0.0_dp
      back_y = 0.0_dp
      do c = 1, size(dlam)
        if (dlam(c) == 0.0_dp) cycle
        back_x = back_x + flexibility(first, c) * dlam(c)
        back_y = back_y + flexibility(second, c) * dlam(c)
      end do
      correction(first) = (r11 * back_x + r12 * back_y + r13) - direction(first)
      correction(second) = (r21 * back_x + r22 * back_y + r23) - direction(second)
    end do

  end subroutine plane_carried_correction

  !> y = A x (matmul's sums over the columns in increasing order, from 0) without the
  !> columns whose x is zero: the same numbers.
  pure subroutine sparse_columns_product(a, x, y)
    real(dp), intent(in) :: a(:, :), x(:)
    real(dp), intent(out) :: y(:)
    integer :: r
    y = 0.0_dp
    do r = 1, size(x)
      if (x(r) == 0.0_dp) cycle
      y = y + a(:, r) * x(r)
    end do
  end subroutine sparse_columns_product

  !> The stagnation and divergence test after correction it of size last (the one before:
  !> previous; coordinate_size: the largest |e|); halt: the iteration must stop:
  !> * a stall: stall_iterations corrections in a row set no new minimum. At the round-off
  !>   floor (the smallest correction within floor_ulps ulps of the largest coordinate or
  !>   the length scale) the state is as converged as double precision resolves: accepted
  !>   (at_floor) when newton_tol is itself resolvable (>= resolvable_tol), otherwise the
  !>   tolerance cannot be met (newton_floor_stall); above the floor: newton_stall;
  !> * divergence: three corrections in a row each larger than the one before and ten times
  !>   the smallest, or one correction larger than the length scale (newton_diverged).
  pure subroutine stagnated(monitor, cfg, it, last, previous, coordinate_size, halt)
    type(newton_monitor), intent(inout) :: monitor
    type(stepper_settings), intent(in) :: cfg
    integer, intent(in) :: it
    real(dp), intent(in) :: last, previous, coordinate_size
    logical, intent(out) :: halt
    real(dp) :: floor
    halt = .false.
    if (last < monitor%smallest) then
      monitor%smallest = last
      monitor%since_smallest = 0
    else
      monitor%since_smallest = monitor%since_smallest + 1
    end if
    if (it > 1 .and. last > previous) then
      monitor%growing = monitor%growing + 1
    else
      monitor%growing = 0
    end if
    if (monitor%since_smallest >= stall_iterations) then
      floor = floor_ulps * epsilon(1.0_dp) * max(coordinate_size, cfg%length_scale)
      halt = .true.
      if (monitor%smallest > floor) then
        monitor%outcome = newton_stall
      else if (cfg%tol >= resolvable_tol) then
        monitor%at_floor = .true.
      else
        monitor%outcome = newton_floor_stall
      end if
    else if ((monitor%growing >= 3 .and. last > 10.0_dp * monitor%smallest) .or. &
             last > cfg%length_scale) then
      halt = .true.
      monitor%outcome = newton_diverged
    end if
  end subroutine stagnated

  !> Whether the Newton iteration of a step has converged after correction it of size
  !> last (the one before: previous). The limit is tol L, without contact at most
  !> motion_fraction of the step's motion (max |e_new - e_n| of its predicted state; never
  !> below ten times the round-off floor): an error of tol L is as large as a step's whole
  !> motion at a loose tolerance (1e-4 on the 7.8 m boom), and it enters the velocity and
  !> the acceleration scaled by gamma / (beta h) and beta'. jacobian_step and _iteration:
  !> last <= limit. The
  !> simplified Newton of the policy constant and of jacobian_reuse (Hairer & Wanner's
  !> criterion): theta / (1 - theta) last <= limit, the error left after the correction,
  !> with the contraction theta = last / previous from the second correction on. With the
  !> constant policy's matrix (the same for the whole run, its contraction with it) the first
  !> correction uses twice the theta last measured, and a confirming correction re-measures
  !> it every confirm_every accepted steps.
  !> jacobian_reuse accepts no correction of a matrix kept from earlier steps on the plain
  !> test alone (it leaves about theta / (1 - theta) of itself, theta unmeasured): the
  !> first one only on the largest ratio the matrix showed in the last step that measured
  !> one (learned%theta) and below first_fraction of the step's motion, the second only
  !> with its own ratio to the first bounding the error too (the first correction of a
  !> matrix factorized at the iterate is Newton's: the plain test; issue 38). It
  !> measures the contraction in every step that reaches its third
  !> correction and accepts from there on the step's largest ratio (the first ratio, from
  !> the predictor's error, mostly measures its linear part). At the second correction it
  !> accepts on the contraction bound theta_b learned from earlier steps (issue 26;
  !> docs/theory.md section 14): the largest of the ratios measured from a third correction
  !> on (both corrections of a ratio made with the current factorization: same_matrix), one
  !> per measuring step (its largest), over the last contraction_memory measuring steps
  !> since the factorization (learned%matrix_ratios), when
  !>   theta / (1 - theta) last <= limit,  theta = max(last / previous, min(0.5, 2 theta_b)):
  !> twice the bound, never below the step's own first ratio; and only while the
  !> contraction is steady: at least steady_count measurements, the largest within
  !> steady_spread times the smallest (the 5-node cable pendulum: spreads 1.2-8, median 2,
  !> no ratio above 1.7 times the bound before it; the driven luffing boom's ratios jump
  !> between 1e-3 and 0.3 from step to step, spreads 4-750, median 33: not accepted
  !> there, where a decayed maximum as the bound left up to 4.6 tol L). Not with contact
  !> points (their corrections fall irregularly), not without a bound (a new factorization
  !> forgets it: a refresh, a changed contact set or step, a retry), not when the matrix
  !> was refreshed within the step, and not after confirm_every steps in a row accepted on
  !> the bound: that step goes on to its third correction and measures the contraction
  !> again (a drive, a large rotation or a stiffening shows there). The caller checks the
  !> constraints to the tolerance whenever a step is accepted on an estimate (newton), and
  !> the stagnation and divergence tests (stagnated) run on every correction not accepted.
  !> measured: this step has its entry in the bound's ring.
  logical function converged(sys, cfg, learned, it, last, previous, step_theta, same_matrix, &
                             exact_tangent, measured, theta_seen, motion) result(ok)
    type(system_model), intent(in) :: sys
    type(stepper_settings), intent(in) :: cfg
    type(stepper_state), intent(inout) :: learned
    integer, intent(in) :: it
    real(dp), intent(in) :: last, previous
    real(dp), intent(inout) :: step_theta  ! the largest contraction measured in this step
    logical, intent(in) :: same_matrix     ! last and previous came from the same matrix
    !> last was made with a matrix factorized at the iterate it corrects
    logical, intent(in) :: exact_tangent
    logical, intent(inout) :: measured
    !> this step has set learned%theta (jacobian_reuse: from a ratio of one matrix)
    logical, intent(inout) :: theta_seen
    real(dp), intent(in) :: motion  ! max |e_new - e_n| of the step's predicted state
    integer, parameter :: confirm_every = 20
    ! a steady contraction: at least steady_count measurements, the largest within
    ! steady_spread times the smallest
    integer, parameter :: steady_count = 8
    real(dp), parameter :: steady_spread = 4.0_dp
    real(dp) :: limit, theta, bound
    integer :: slot, known  ! the ring's entry of this step; the entries measured
    limit = cfg%tol * cfg%length_scale
    ! (refactorized systems without contact: also a fraction of the step's motion, never
    ! below ten times the round-off floor, where a system at rest ends its steps)
    if (sys%matrix%policy /= policy_constant .and. sys%contact%npoint == 0) &
      limit = min(limit, max(motion_fraction * motion, &
                             10.0_dp * floor_ulps * epsilon(1.0_dp) * cfg%length_scale))
    ok = last <= limit
    if (sys%matrix%policy /= policy_constant .and. cfg%jacobian /= jacobian_reuse) return
    if (it == 1 .and. sys%matrix%policy /= policy_constant) then
      ! reuse: the first correction of a matrix factorized at the predicted state is
      ! Newton's (the plain test). One of a matrix kept from earlier steps leaves about
      ! theta / (1 - theta) of itself, theta the matrix's contraction in this step, which
      ! one correction does not show: it ends the step only when the contraction the
      ! matrix showed in the last step that measured one (learned%theta) puts that below
      ! the limit, and only when it is itself below first_fraction of the step's motion
      ! (what the matrix's contraction here may leave of it is then negligible however
      ! the contraction changed since)
      ! (contact steps keep the plain test: they start from q + h v, without the
      ! accelerations' extrapolation, under no motion cap, and damp their corrections)
      if (exact_tangent .or. sys%contact%npoint > 0) return
      ok = ok .and. learned%theta >= 0.0_dp .and. learned%theta < 1.0_dp .and. &
           last <= max(first_fraction * motion, &
                       10.0_dp * floor_ulps * epsilon(1.0_dp) * cfg%length_scale)
      if (ok) ok = learned%theta / (1.0_dp - learned%theta) * last <= limit
      return
    end if
    if (it == 1) then
      if (ok .or. learned%theta < 0.0_dp .or. learned%unconfirmed >= confirm_every) then
        if (ok) learned%unconfirmed = learned%unconfirmed + 1
        return
      end if
      theta = min(0.9_dp, 2.0_dp * learned%theta)
      ok = theta / (1.0_dp - theta) * last <= limit
      if (ok) learned%unconfirmed = learned%unconfirmed + 1
      return
    end if
    theta = last / previous
    if (sys%matrix%policy == policy_constant) then
      learned%theta = theta
    else if (same_matrix) then
      ! (reuse: the step's largest ratio of two corrections of the current matrix)
      if (theta_seen) then
        learned%theta = max(learned%theta, theta)
      else
        learned%theta = theta
        theta_seen = .true.
      end if
    end if
    learned%unconfirmed = 0
    ! the largest contraction of the step: a contact point that moves, sticks or slips
    ! makes the corrections fall irregularly, and a small ratio after a large one is no
    ! evidence that the next would be as small
    if (it == 2 .and. sys%matrix%policy /= policy_constant) then
      step_theta = theta
      ! the plain test only with the step's own ratio of one matrix bounding the error
      ! left below the limit too (a ratio near 1 left several times the last correction)
      if (ok .and. same_matrix .and. .not. exact_tangent .and. sys%contact%npoint == 0) &
        ok = theta < 1.0_dp .and. theta / (1.0_dp - theta) * last <= limit
      if (ok .or. sys%contact%npoint > 0 .or. learned%matrix_measured < steady_count .or. &
          learned%matrix_unconfirmed >= confirm_every .or. .not. same_matrix) return
      known = min(learned%matrix_measured, contraction_memory)
      bound = maxval(learned%matrix_ratios(1:known))
      if (.not. bound <= steady_spread * minval(learned%matrix_ratios(1:known))) return
      theta = max(theta, min(0.5_dp, 2.0_dp * bound))
      ok = theta < 1.0_dp .and. theta / (1.0_dp - theta) * last <= limit
      if (ok) learned%matrix_unconfirmed = learned%matrix_unconfirmed + 1
      return
    end if
    if (sys%matrix%policy /= policy_constant .and. same_matrix) then
      ! the step's entry in the ring: its largest ratio from the third correction on
      if (.not. measured) then
        learned%matrix_measured = learned%matrix_measured + 1
        slot = modulo(learned%matrix_measured - 1, contraction_memory) + 1
        learned%matrix_ratios(slot) = theta
        measured = .true.
      else
        slot = modulo(learned%matrix_measured - 1, contraction_memory) + 1
        learned%matrix_ratios(slot) = max(learned%matrix_ratios(slot), theta)
      end if
      learned%matrix_unconfirmed = 0
    end if
    step_theta = max(step_theta, theta)
    ok = ok .or. (step_theta < 1.0_dp .and. step_theta / (1.0_dp - step_theta) * last <= limit)
  end function converged

  !> One output row (probes, deflections, energies, constraint violation, contact records) of
  !> a state that was not stepped to (the initial state), with the powers there (the start
  !> of the stepper's work integrals).
  subroutine output_row(sys, t, e, v, lam, work, state, probe, deflection, energy, violation, &
                        contact, powers, info)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: t, e(:), v(:), lam(:), work(power_count)
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: probe(:, :), deflection(:, :), energy(energy_count), violation
    real(dp), intent(out) :: contact(:, :), powers(power_count)
    integer, intent(out) :: info
    real(dp) :: rotations(3, 3, 0:size(sys%frames)), rates(0:size(sys%frames))
    real(dp) :: strain, contact_potential
    call frame_rotations(sys, t, rotations, rates, info)
    if (info /= 0) return
    call energies(sys, rotations, rates, e, v, lam, t, state, strain, powers, contact_potential, &
                  violation, contact, info)
    if (info /= 0) return
    call probe_output(sys, rotations, e, v, work, strain, contact_potential, probe, deflection, &
                      energy, info)
  end subroutine output_row

  !> The text of a failure of integrator_chunk (info, with its detail; max_newton: the
  !> iteration limit of the run) for the message of system_advance.
  pure function step_failure_text(info, detail, max_newton) result(text)
    integer, intent(in) :: info, detail, max_newton
    character(len=message_length) :: text
    select case (info)
    case (1)
      select case (detail)
      case (newton_floor_stall)
        text = 'Newton stalled at the round-off floor (the corrections stopped falling at ' // &
               'the size double precision resolves, above a tolerance below it)'
      case (newton_stall)
        text = 'Newton stalled (four corrections in a row set no new minimum, above the ' // &
               'round-off floor)'
      case (newton_diverged)
        text = 'Newton diverged (the corrections grew three times in a row, or one ' // &
               'exceeded the length scale)'
      case default
        write (text, '(a, i0, a)') 'Newton did not converge within ', max_newton, ' iterations'
      end select
    case (2)
      text = 'the state became non-finite (NaN or overflow)'
    case (3)
      write (text, '(a, i0, a)') 'the linear solve failed (solver code ', detail, &
        ': -10 = singular matrix)'
    case (4)
      write (text, '(a, i0, a)') "the multipliers' Schur complement is singular (dgesv info ", &
        detail, '): the constraints are redundant or lost rank'
    case (em_unsupported)
      text = "the energy-momentum integrator does not support this model (contact, force " // &
             'elements, driven or follower loads, moments, moving frames, driven ' // &
             'constraints, damping, or an element family without a discrete gradient)'
    case default
      text = failure_text(info)
    end select
  end function step_failure_text

end module time_integrator
