!> The static Newton in the kernel (issue 25 item 4): equilibrium at a load factor lf,
!>   r(e, lambda) = B^T (Q_el - Q_c - lf Q_M)(e) - lf Q(e, t) - Phi_e^T lambda = 0,
!>   Phi(e, t) = 0,
!> the residual of the time stepper (time_integrator) with the inertia terms off: the same
!> internal_forces (element sets, force elements, contact, dead moments, through q = B e + q0
!> when linear constraints are eliminated), the same external_forces (constant, driven,
!> driven and follower point loads) and the same constraints. Newton-Raphson on the
!> symmetric saddle-point system
!>   [[K - dQ/de - sum_k lambda_k H_k, -Phi_e^T], [-Phi_e, 0]] [de; dlambda] = [-r; Phi]
!> (K: the tangent of internal_forces with the point loads' Jacobian; dQ/de: the dead
!> moments' Jacobian; H_k: the constraint Hessians), factorized by the solver the cost rule
!> picks for its pattern (sparse_direct's solver_create_for: the banded LU in reverse
!> Cuthill-McKee order when cheap, else MUMPS), one instance per model kept in its
!> iteration_matrix (saddle_handle) and analysed once while the pattern stays (every load
!> step and path step of a static solve reuses it) - the stepper's iteration matrix
!> beta' M + K regularizes the rigid modes, the static one has the multipliers for them.
!> The convergence test is static.py's converged (its floor as tests/reference/
!> static_newton.py's residual_floor): the relative force residual and the constraint
!> violation below tol, or, on fine meshes whose residual has a round-off floor, the
!> correction or the residual stopped falling there; the stagnation and divergence test
!> watches the residuals (no step size to cut: the load stepping in Python does).
!> One call solves one load step; the load stepping and its reporting stay in Python.
!>
!> The same Newton follows a static path by arc length (issue 34 item 2, issue 36 item 4:
!> one static Newton): with the optional path_request the load factor P is an unknown beside
!> (e, lambda) and each call takes one step of Crisfield's (1981) cylindrical method from the
!> converged state on entry, ||Delta e|| = Delta l with Delta e the step's increment. Every
!> iteration factorizes the same saddle-point matrix once and solves it for two right-hand
!> sides, [-r; Phi] (du_r, dlambda_r) and [q; 0] (du_q, dlambda_q) with the load vector
!> q = -dr/dP (r is linear in P: the difference of the residuals at P and P - 1); the
!> correction is du = du_r + dP du_q with dP the root of the quadratic
!> ||Delta e + du_r + dP du_q||^2 = Delta l^2 whose new increment makes the smaller angle
!> with the step's increment so far. The predictor (the first iteration, at the converged
!> state) is dP = +-Delta l / ||du_q|| along du_q, the sign that keeps the direction of the
!> previous step's increment (Feng's criterion), or the requested direction on the first
!> step. A quadratic without a real root fails with static_no_root. The path driver (arc
!> adaptation and cuts, the target crossing, the stability count, the limit marks) stays
!> in Python (solvers/path.py). The request path_tangent takes no step: it returns the
!> tangent along the loads at the state (||q||, ||du_q|| and q . du_q).
!> No I/O; failures return codes with their text (static_failure_text).
module static_solver
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state, frame_rotations, internal_forces, &
                               external_forces, contact_record
  use system_constraints, only: constraint_derivatives, constraint_reaction
  use system_loads, only: moment_pattern_size, moment_pattern, moment_tangent
  use sparse_direct, only: solver_create_for, solver_factorize, solver_solve, solver_destroy
  use kernel_errors, only: failure_text, message_length
  implicit none
  private
  public :: static_newton, static_failure_text

  !> path_request modes: an arc-length step; the tangent along the loads only (no step)
  integer, parameter, public :: path_step = 1, path_tangent = 2

  !> static_newton's arc-length request (module doc). In: mode, the arc Delta l, the sign of
  !> the first step's load increment (direction) and the previous step's increment of e
  !> (previous, all zero on the first step). Out: the load factor reached and, at the state
  !> on entry, ||q||, ||du_q|| and the flexibility along the loads q . du_q.
  type, public :: path_request
    integer :: mode = path_step
    real(dp) :: arc = 0.0_dp, direction = 1.0_dp
    real(dp), allocatable :: previous(:)
    real(dp) :: load_factor = 0.0_dp, load_norm = 0.0_dp, tangent_norm = 0.0_dp, &
                flexibility = 0.0_dp
  end type path_request

  !> why the iteration stopped (converged_by): the relative residual; the round-off floor
  !> with a correction below sqrt(tol); the correction below tol; the residual stopped
  !> falling below sqrt(tol); the start is the equilibrium (no load at all, an unstressed
  !> start); the tangent along the loads returned without a step (path_tangent)
  integer, parameter, public :: by_residual = 1, by_roundoff = 2, by_step = 3, by_floor = 4, &
                                by_unloaded_start = 5, by_tangent_only = 6
  !> failures (info): iteration limit, divergence, stall at the round-off floor, stall,
  !> non-finite step, linear solve failed (detail: the solver code), the arc-length
  !> constraint without a real root; 5..10: internal_forces
  integer, parameter, public :: static_limit = 1, static_diverged = 11, &
                                static_floor_stall = 12, static_stall = 13, &
                                static_nonfinite = 2, static_solve_failed = 3, &
                                static_no_root = 14
  !> iterations in a row without a new smallest residual: a stall once the residual is
  !> small (below stall_near or at the floor); far from it, far_stall_iterations
  integer, parameter :: stall_iterations = 4, far_stall_iterations = 25
  real(dp), parameter :: stall_near = 1.0e-6_dp

contains

  !> One load step of the static Newton from (e, lambda) (updated in place) at load factor
  !> load_factor and time t. e0: the reference configuration (the corrections' size is
  !> measured against |e - e0|); rows, cols: the tangent's reduced pattern (1-based, the
  !> order of internal_forces' tangent values); force_scale: the residual's scale floor (the
  !> forces at the start; < 0 on entry: set from the first iterate); check_start: a start
  !> that is already the equilibrium ends the call with 0 iterations - only when no load
  !> acts at all (external loads and dead moments exactly zero) and the internal forces
  !> there are zero to their round-off, eps || |K| |e| || (an unstressed start).
  !> history(1:iterations): the relative residual after each correction. path: an
  !> arc-length step from the converged (e, lambda) at load_factor instead (module doc;
  !> the predictor counts as the first iteration, and no convergence is taken before a
  !> correction), or the tangent along the loads (path_tangent: 0 iterations).
  subroutine static_newton(sys, t, load_factor, e0, rows, cols, e, lam, state, tol, &
                           length_scale, max_iter, check_start, force_scale, iterations, &
                           history, force_res, con_res, converged_by, factorizations, info, &
                           detail, path)
    type(system_model), intent(inout) :: sys
    real(dp), intent(in) :: t, load_factor, e0(:), tol, length_scale
    integer, intent(in) :: rows(:), cols(:), max_iter
    logical, intent(in) :: check_start
    real(dp), intent(inout) :: e(:), lam(:), force_scale
    type(contact_state), intent(inout) :: state
    integer, intent(out) :: iterations, converged_by, factorizations, info, detail
    real(dp), intent(out) :: history(:), force_res, con_res
    type(path_request), intent(inout), optional :: path
    integer :: n, ncon, nnz, nhess, nmom, ngrad, total, handle, it, c, s1, s2, k1, k2, k, m
    integer :: i, j, a, b, best, since, destroy_info, width
    integer, allocatable :: srows(:), scols(:)
    real(dp), allocatable :: values(:), tangent(:), rhs(:, :)
    real(dp) :: internal(size(e)), loads(size(e)), reaction(size(e)), residual(size(e))
    real(dp) :: phi(sys%constraints%ncon), gradients(6, sys%constraints%ncon)
    real(dp) :: hessians(6, 6, sys%constraints%ncon)
    real(dp) :: rotations(3, 3, 0:size(sys%frames)), rates(0:size(sys%frames))
    real(dp) :: step_size, size_now, scale, floor, previous, moment(3)
    real(dp) :: jacobian(3, 3), hessian(3, 3, 3)
    real(dp) :: factor, base_factor, delta_factor, dfactor, a2, b2, c2, disc, root1, root2
    real(dp), allocatable :: load(:), base_e(:), base_lam(:), delta_e(:), delta_lam(:), &
                             ahead(:), change(:)
    logical :: near, growing, arc
    n = size(e)
    arc = present(path)
    factor = load_factor
    ncon = sys%constraints%ncon
    nnz = size(rows)
    iterations = 0
    converged_by = 0
    factorizations = 0
    force_res = huge(1.0_dp)
    con_res = huge(1.0_dp)
    history = 0.0_dp
    detail = 0
    call frame_rotations(sys, t, rotations, rates, info)
    if (info /= 0) return
    ! the saddle-point pattern: tangent, constraint Hessians, moment Jacobians, gradients
    nhess = 0
    ngrad = 0
    do c = 1, ncon
      do s1 = 1, 6
        ngrad = ngrad + slot_terms(c, s1)
        do s2 = 1, 6
          nhess = nhess + slot_terms(c, s1) * slot_terms(c, s2)
        end do
      end do
    end do
    nmom = moment_pattern_size(sys%loads, sys%reduction)
    total = nnz + nhess + nmom + 2 * ngrad
    allocate (srows(total), scols(total), values(total), tangent(nnz))
    if (arc) then
      ! the second right-hand side [q; 0] and the step's increment from the state on entry
      allocate (rhs(n + ncon, 2), load(n), delta_e(n), delta_lam(ncon), ahead(n), change(n))
      base_e = e
      base_lam = lam
      delta_e = 0.0_dp
      delta_lam = 0.0_dp
      base_factor = load_factor
      delta_factor = 0.0_dp
      path%load_factor = load_factor
    else
      allocate (rhs(n + ncon, 1))
    end if
    srows(1:nnz) = rows
    scols(1:nnz) = cols
    k = nnz
    do c = 1, ncon
      do s1 = 1, 6
        do s2 = 1, 6
          do k1 = first_term(c, s1), first_term(c, s1) + slot_terms(c, s1) - 1
            do k2 = first_term(c, s2), first_term(c, s2) + slot_terms(c, s2) - 1
              k = k + 1
              srows(k) = sys%constraints%term_dof(k1)
              scols(k) = sys%constraints%term_dof(k2)
            end do
          end do
        end do
      end do
    end do
    call moment_pattern(sys%loads, sys%reduction, srows(k + 1:k + nmom), scols(k + 1:k + nmom))
    k = k + nmom
    do c = 1, ncon
      do s1 = 1, 6
        do k1 = first_term(c, s1), first_term(c, s1) + slot_terms(c, s1) - 1
          srows(k + 1) = sys%constraints%term_dof(k1)
          scols(k + 1) = n + c
          srows(k + 2) = n + c
          scols(k + 2) = sys%constraints%term_dof(k1)
          k = k + 2
        end do
      end do
    end do
    ! the model's saddle-point solver, analysed anew only for a new pattern
    associate (m => sys%matrix)
      if (m%saddle_handle /= 0) then
        if (size(m%saddle_rows) /= total) then
          call solver_destroy(m%saddle_handle, destroy_info)
          m%saddle_handle = 0
        else if (any(m%saddle_rows /= srows) .or. any(m%saddle_cols /= scols)) then
          call solver_destroy(m%saddle_handle, destroy_info)
          m%saddle_handle = 0
        end if
      end if
      if (m%saddle_handle == 0) then
        call solver_create_for(n + ncon, total, srows, scols, m%saddle_handle, width, info, &
                               detail)
        if (info /= 0) then
          detail = info
          info = static_solve_failed
          return
        end if
        m%saddle_rows = srows
        m%saddle_cols = scols
      end if
      handle = m%saddle_handle
    end associate
    do it = 1, max_iter
      call evaluate(.true.)
      if (info /= 0) exit
      residual = internal - loads - reaction
      if (force_scale < 0.0_dp) force_scale = max(norm2(internal), norm2(loads))
      if (arc) then
        call load_vector()
        if (info /= 0) exit
      end if
      if (check_start .and. it == 1) then
        ! no load at all and the internal forces zero to their own round-off: the start is
        ! the equilibrium (a load, however small, is always solved for)
        if (all(loads == 0.0_dp) .and. &
            all(merge(1.0_dp, factor, sys%loads%moment_fixed) &
                * sys%loads%moment_magnitude == 0.0_dp) .and. &
            norm2(residual) <= residual_floor(1.0_dp) .and. &
            max_abs(phi) <= tol * length_scale) then
          converged_by = by_unloaded_start
          force_res = 0.0_dp
          con_res = 0.0_dp
          exit
        end if
      end if
      ! the saddle-point values in the pattern's order
      values(1:nnz) = tangent
      k = nnz
      do c = 1, ncon
        do s1 = 1, 6
          do s2 = 1, 6
            do k1 = first_term(c, s1), first_term(c, s1) + slot_terms(c, s1) - 1
              do k2 = first_term(c, s2), first_term(c, s2) + slot_terms(c, s2) - 1
                k = k + 1
                values(k) = -lam(c) * hessians(s1, s2, c) * sys%constraints%term_coef(k1) &
                            * sys%constraints%term_coef(k2)
              end do
            end do
          end do
        end do
      end do
      call moment_tangent(sys%loads, sys%reduction, e, factor, values(k + 1:k + nmom), info)
      if (info /= 0) exit
      k = k + nmom
      do c = 1, ncon
        do s1 = 1, 6
          do k1 = first_term(c, s1), first_term(c, s1) + slot_terms(c, s1) - 1
            values(k + 1) = -gradients(s1, c) * sys%constraints%term_coef(k1)
            values(k + 2) = values(k + 1)
            k = k + 2
          end do
        end do
      end do
      call solver_factorize(handle, total, values, info, detail)
      factorizations = factorizations + 1
      if (info == 0) then
        rhs(1:n, 1) = -residual
        rhs(n + 1:, 1) = phi
        if (arc) then
          rhs(1:n, 2) = load
          rhs(n + 1:, 2) = 0.0_dp
        end if
        call solver_solve(handle, n + ncon, size(rhs, 2), rhs, info, detail)
      end if
      if (info /= 0) then
        detail = info
        info = static_solve_failed
        exit
      end if
      iterations = it
      if (.not. all(abs(rhs) < huge(1.0_dp))) then
        info = static_nonfinite
        exit
      end if
      if (arc) then
        if (it == 1) then
          path%load_norm = norm2(load)
          path%tangent_norm = norm2(rhs(1:n, 2))
          path%flexibility = dot_product(load, rhs(1:n, 2))
          if (path%mode == path_tangent) then
            iterations = 0
            converged_by = by_tangent_only
            exit
          end if
          ! the predictor along du_q
          if (.not. path%tangent_norm > 0.0_dp) then
            info = static_no_root
            exit
          end if
          dfactor = path%direction
          if (any(path%previous /= 0.0_dp)) &
            dfactor = merge(1.0_dp, -1.0_dp, dot_product(rhs(1:n, 2), path%previous) >= 0.0_dp)
          dfactor = dfactor * path%arc / path%tangent_norm
          change = dfactor * rhs(1:n, 2)
        else
          ! the corrector: the root of ||delta_e + du_r + dP du_q|| = arc at the smaller angle
          ahead = delta_e + rhs(1:n, 1)
          a2 = dot_product(rhs(1:n, 2), rhs(1:n, 2))
          b2 = 2.0_dp * dot_product(rhs(1:n, 2), ahead)
          c2 = dot_product(ahead, ahead) - path%arc**2
          disc = b2 * b2 - 4.0_dp * a2 * c2
          if (.not. a2 > 0.0_dp .or. disc < 0.0_dp) then
            info = static_no_root
            exit
          end if
          root1 = (-b2 + sqrt(disc)) / (2.0_dp * a2)
          root2 = (-b2 - sqrt(disc)) / (2.0_dp * a2)
          dfactor = root1
          if (dot_product(ahead + root2 * rhs(1:n, 2), delta_e) > &
              dot_product(ahead + root1 * rhs(1:n, 2), delta_e)) dfactor = root2
          change = rhs(1:n, 1) + dfactor * rhs(1:n, 2)
          delta_lam = delta_lam + rhs(n + 1:, 1)
        end if
        delta_e = delta_e + change
        delta_lam = delta_lam + dfactor * rhs(n + 1:, 2)
        delta_factor = delta_factor + dfactor
        e = base_e + delta_e
        lam = base_lam + delta_lam
        factor = base_factor + delta_factor
        path%load_factor = factor
        rhs(1:n, 1) = change
        if (.not. all(abs(e) < huge(1.0_dp))) then
          info = static_nonfinite
          exit
        end if
      else
        e = e + rhs(1:n, 1)
        lam = lam + rhs(n + 1:, 1)
      end if
      call evaluate(.false.)
      if (info /= 0) exit
      scale = max(norm2(loads), norm2(reaction), norm2(internal), force_scale, 1.0e-300_dp)
      force_res = norm2(internal - loads - reaction) / scale
      con_res = 0.0_dp
      con_res = max_abs(phi) / length_scale
      previous = huge(1.0_dp)
      if (it > 1) previous = history(it - 1)
      history(it) = force_res
      scale = max(norm2(loads), norm2(internal), force_scale)
      floor = residual_floor(scale)
      step_size = norm2(rhs(1:n, 1))
      size_now = norm2(e - e0)
      ! an arc-length step converges on a correction, never on its predictor
      if (.not. (arc .and. it == 1)) &
        converged_by = converged(force_res, con_res, step_size, size_now, previous, floor)
      if (converged_by /= 0) exit
      best = minloc(history(1:it), dim=1)
      near = history(best) <= max(stall_near, floor)
      growing = it >= 4 .and. rising(history(1:it)) .and. force_res > 1.0e6_dp * history(best)
      since = it - best
      if ((near .and. since >= stall_iterations) .or. since >= far_stall_iterations .or. &
          growing .or. .not. (force_res < huge(1.0_dp))) then
        ! as tests/reference/static_newton.py's message: divergence, a stall at or above the floor
        detail = 0
        if (it >= 4 .and. rising(history(max(1, it - 3):it)) .and. &
            force_res > 1.0e6_dp * history(best)) then
          info = static_diverged
        else if (history(best) <= floor) then
          info = static_floor_stall
        else
          info = static_stall
        end if
        exit
      end if
    end do
    if (info == 0 .and. converged_by == 0) info = static_limit

  contains

    !> the load vector q = -dr/dP at e (load): r is linear in the load factor, q the
    !> loads minus the internal forces at the factor less those at the factor - 1
    subroutine load_vector()
      real(dp) :: strain, potential, powers(2), records(contact_record, max(1, sys%contact%npoint))
      real(dp) :: zero_rates(size(e)), below(size(e))
      zero_rates = 0.0_dp
      call internal_forces(sys, rotations, e, zero_rates, factor - 1.0_dp, 0.0_dp, state, &
                           below, strain, potential, powers, records, info, rates=rates, &
                           force_time=t)
      if (info /= 0) return
      call external_forces(sys, t, factor - 1.0_dp, load, info, e)
      if (info /= 0) return
      load = (loads - internal) - (load - below)
    end subroutine load_vector

    !> internal (with the tangent on request), loads, constraints and reaction at e
    subroutine evaluate(with_tangent)
      logical, intent(in) :: with_tangent
      real(dp) :: strain, potential, powers(2), records(contact_record, max(1, sys%contact%npoint))
      real(dp) :: zero_rates(size(e)), phi_t(ncon), phi_tt(ncon), gamma(ncon)
      zero_rates = 0.0_dp
      if (with_tangent) then
        call internal_forces(sys, rotations, e, zero_rates, factor, 0.0_dp, state, &
                             internal, strain, potential, powers, records, info, rotations, &
                             tangent, rates, t=t, force_time=t)
      else
        call internal_forces(sys, rotations, e, zero_rates, factor, 0.0_dp, state, &
                             internal, strain, potential, powers, records, info, rates=rates, &
                             force_time=t)
      end if
      if (info /= 0) return
      call external_forces(sys, t, factor, loads, info, e)
      if (info /= 0) return
      if (ncon > 0) then
        call constraint_derivatives(sys%constraints, sys%drives, e, zero_rates, t, phi, &
                                    gradients, hessians, phi_t, phi_tt, gamma, info, &
                                    first_order_only=.not. with_tangent)
        if (info /= 0) then
          info = 5
          return
        end if
      end if
      reaction = 0.0_dp
      call constraint_reaction(sys%constraints, gradients, lam, reaction)
      reaction = -reaction
    end subroutine evaluate

    !> eps || |K| |e| || / scale (tests/reference/static_newton.py residual_floor)
    real(dp) function residual_floor(scale) result(level)
      real(dp), intent(in) :: scale
      real(dp) :: magnitude(size(e))
      integer :: p
      magnitude = 0.0_dp
      do p = 1, nnz
        magnitude(rows(p)) = magnitude(rows(p)) + abs(tangent(p)) * abs(e(cols(p)))
      end do
      level = epsilon(1.0_dp) * norm2(magnitude) / max(scale, 1.0e-300_dp)
    end function residual_floor

    !> static.py converged: 0 while iterating, else by_residual .. by_floor
    integer function converged(force, violation, step, size_d, before, level) result(how)
      real(dp), intent(in) :: force, violation, step, size_d, before, level
      how = 0
      if (violation > tol) return
      if (force <= tol) then
        how = by_residual
      else if (force <= level .and. step <= sqrt(tol) * size_d) then
        how = by_roundoff
      else if (force <= sqrt(tol)) then
        if (step <= tol * size_d) then
          how = by_step
        else if (force >= 0.5_dp * before) then
          how = by_floor
        end if
      end if
    end function converged

    !> max |x| (0 for an empty x)
    pure real(dp) function max_abs(x)
      real(dp), intent(in) :: x(:)
      max_abs = 0.0_dp
      if (size(x) > 0) max_abs = maxval(abs(x))
    end function max_abs

    !> the last (up to) three residuals each larger than the one before
    pure logical function rising(h)
      real(dp), intent(in) :: h(:)
      integer :: p
      rising = .true.
      do p = max(2, size(h) - 2), size(h)
        rising = rising .and. h(p) > h(p - 1)
      end do
    end function rising

    !> the number of terms and the first term of slot s of constraint c
    integer function slot_terms(c, s)
      integer, intent(in) :: c, s
      slot_terms = sys%constraints%term_ptr(6 * (c - 1) + s + 1) &
                   - sys%constraints%term_ptr(6 * (c - 1) + s)
    end function slot_terms

    integer function first_term(c, s)
      integer, intent(in) :: c, s
      first_term = sys%constraints%term_ptr(6 * (c - 1) + s)
    end function first_term

  end subroutine static_newton

  !> The text of a failure of static_newton (info, detail) at load step load_step of
  !> load_steps (along_path: at step load_step of an arc-length path), with the smallest
  !> and last residuals and the iteration limit. Every text
  !> fits message_length (200) with 10-digit counts and 3-digit exponents: a longer one
  !> is cut mid-word by the assignment (the floor stall's ended in 'raise solver.to').
  pure function static_failure_text(info, detail, load_step, load_steps, max_iter, smallest, &
                                    last, con_res, tol, along_path) result(text)
    integer, intent(in) :: info, detail, load_step, load_steps, max_iter
    real(dp), intent(in) :: smallest, last, con_res, tol
    logical, intent(in) :: along_path
    character(len=message_length) :: text
    character(len=40) :: where, shorter
    if (along_path) then
      write (where, '(a, i0)') 'at path step ', load_step
      shorter = 'shorten solver.arc_length'
    else
      write (where, '(a, i0, a, i0)') 'at load step ', load_step, ' of ', load_steps
      shorter = 'raise solver.load_steps'
    end if
    select case (info)
    case (static_limit)
      write (text, '(a, i0, 9a)') 'static Newton did not converge in ', max_iter, &
        ' iterations ', trim(where), ' (relative residual ', sci(last), ', constraint ', &
        sci(con_res), '); ', trim(shorter), ' or max_iter'
    case (static_diverged)
      text = 'static Newton diverged ' // trim(where) // ': the relative residual grew ' // &
             'three times in a row to ' // sci(last) // ' (smallest ' // sci(smallest) // &
             '); ' // trim(shorter)
    case (static_floor_stall)
      text = 'static Newton stalled at the round-off floor ' // trim(where) // &
             ': the relative residual stays at ' // sci(smallest) // ' above solver.tol = ' // &
             sci(tol) // ', beyond double precision; raise solver.tol'
    case (static_stall)
      text = 'static Newton stalled ' // trim(where) // ': no smaller residual in the last ' // &
             'iterations (smallest ' // sci(smallest) // ', tolerance ' // sci(tol) // &
             '); ' // trim(shorter)
    case (static_nonfinite)
      text = 'static Newton: non-finite step ' // trim(where)
    case (static_no_root)
      text = 'static Newton: the arc-length constraint ||Delta e|| = Delta l has no real ' // &
             'root ' // trim(where) // '; ' // trim(shorter)
    case (static_solve_failed)
      write (text, '(3a, i0, a)') 'static Newton: the saddle-point solve failed ', &
        trim(where), ' (solver code ', detail, ': -10 = singular matrix)'
    case default
      text = 'static Newton ' // trim(where) // ': ' // trim(failure_text(info))
    end select

  contains

    !> x as Python's '{:.3e}' writes it (a 3-digit exponent too: es12.3 drops its 'E',
    !> '1.000-300')
    pure function sci(x) result(out)
      real(dp), intent(in) :: x
      character(len=:), allocatable :: out
      character(len=16) :: buffer
      integer :: p
      write (buffer, '(es12.3)') x
      if (index(buffer, 'E') == 0 .and. scan(buffer, '0123456789') > 0) &
        write (buffer, '(es13.3e3)') x
      buffer = adjustl(buffer)
      p = index(buffer, 'E')
      if (p > 0) buffer(p:p) = 'e'
      out = trim(buffer)
    end function sci

  end function static_failure_text

end module static_solver
