!> The consistent acceleration and multipliers of a state (t, e, e'): the start of a run and
!> the restart of the method at a change of the step (step_control). With the equations of
!> motion and the constraints differentiated twice (Phi_e e'' = gamma):
!>   [[M, -Phi_e^T], [-Phi_e, 0]] [e''; lambda] = [Q(t) - B^T (Q_el - Q_c - Q_M); -gamma],
!> solved by the solver the cost rule picks for the saddle's pattern (sparse_direct's
!> solver_create_for: LAPACK's banded LU in its reverse Cuthill-McKee order when cheap, else
!> MUMPS) on the saddle's coordinate list: M as the model assembled it (its zero entries
!> kept: the saddle's pattern does not depend on the values), then Phi_e^T's and Phi_e's
!> entries, constraint by constraint, operand by operand, term by term. One solver
!> instance per solve, released after it. No I/O; failures return codes and text.
module consistent_start
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state, frame_rotations, internal_forces, &
                               external_forces, contact_record
  use system_constraints, only: constraint_derivatives, term_count, saddle_gradient_entries
  use system_mass, only: saddle_mass_entries
  use sparse_direct, only: solver_create_for, solver_factorize, solver_solve, solver_destroy
  use kernel_errors, only: failure_text, message_length
  implicit none
  private
  public :: consistent_acceleration

contains

  !> accel = e'' and lam = lambda consistent with (t, e, v); contact: the contact guesses the
  !> force evaluation starts from (updated) and its counters. info /= 0: the failure, in
  !> words in message (a force or constraint evaluation's code, or 3: the saddle system's
  !> solve failed, detail the MUMPS code INFOG(1)).
  subroutine consistent_acceleration(sys, t, e, v, contact, accel, lam, info, detail, message)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: t, e(:), v(:)
    type(contact_state), intent(inout) :: contact
    real(dp), intent(out) :: accel(:), lam(:)
    integer, intent(out) :: info, detail
    character(len=message_length), intent(out) :: message
    real(dp) :: rotations(3, 3, 0:size(sys%frames)), rates(0:size(sys%frames))
    real(dp) :: internal(sys%ndof), external(sys%ndof), strain, potential, powers(2)
    real(dp) :: records(contact_record, max(1, sys%contact%npoint))
    real(dp) :: values(sys%constraints%ncon), gradients(6, sys%constraints%ncon)
    real(dp) :: hessians(6, 6, sys%constraints%ncon)
    real(dp) :: phi_t(sys%constraints%ncon), phi_tt(sys%constraints%ncon)
    real(dp) :: gamma(sys%constraints%ncon)
    real(dp), allocatable :: entries(:), rhs(:, :)
    integer, allocatable :: rows(:), cols(:)
    integer :: n, ncon, nmass, nterm, handle, width, stage, ignored
    character(len=*), parameter :: what = "the consistent acceleration's saddle system " // &
                                           '[[M, -Phi_e^T], [-Phi_e, 0]]'
    n = sys%ndof
    ncon = sys%constraints%ncon
    accel = 0.0_dp
    lam = 0.0_dp
    detail = 0
    message = ''
    call frame_rotations(sys, t, rotations, rates, info)
    if (info == 0) call internal_forces(sys, rotations, e, v, 1.0_dp, 0.0_dp, contact, internal, &
                                        strain, potential, powers, records, info, rates=rates, &
                                        force_time=t)
    if (info == 0) call external_forces(sys, t, 1.0_dp, external, info, e)
    if (info /= 0) then
      message = 'the force evaluation of the consistent acceleration failed: ' // &
                failure_text(info)
      return
    end if
    if (ncon > 0) then
      call constraint_derivatives(sys%constraints, sys%drives, e, v, t, values, gradients, &
                                  hessians, phi_t, phi_tt, gamma, info)
      if (info /= 0) then
        info = 5
        message = 'the consistent acceleration: ' // failure_text(info)
        return
      end if
    end if
    ! the saddle's coordinate list: M's entries, Phi_e^T's (rows of e, columns of lambda),
    ! Phi_e's (rows of lambda)
    nmass = size(sys%mass%saddle_col)
    nterm = term_count(sys%constraints)
    allocate (rows(nmass + 2 * nterm), cols(nmass + 2 * nterm), entries(nmass + 2 * nterm))
    call saddle_mass_entries(sys%mass, rows(1:nmass), cols(1:nmass), entries(1:nmass))
    call saddle_gradient_entries(sys%constraints, gradients, n, rows(nmass + 1:), &
                                 cols(nmass + 1:), entries(nmass + 1:))
    allocate (rhs(n + ncon, 1))
    rhs(1:n, 1) = external - internal
    rhs(n + 1:n + ncon, 1) = -gamma
    stage = 2
    call solver_create_for(n + ncon, size(rows), rows, cols, handle, width, info, detail)
    if (info == 0) then
      stage = 3
      call solver_factorize(handle, size(entries), entries, info, detail)
      if (info == 0) then
        stage = 4
        call solver_solve(handle, n + ncon, 1, rhs, info, detail)
      end if
      call solver_destroy(handle, ignored)
    end if
    if (info /= 0) then
      detail = info
      info = 3
      message = what // ': ' // trim(stage_name(stage)) // ' failed (' // &
                trim(mumps_text(detail)) // ')'
      return
    end if
    accel = rhs(1:n, 1)
    lam = rhs(n + 1:n + ncon, 1)
  end subroutine consistent_acceleration

  pure function stage_name(stage) result(name)
    integer, intent(in) :: stage
    character(len=24) :: name
    select case (stage)
    case (2)
      name = 'creation and analysis'
    case (3)
      name = 'factorization'
    case default
      name = 'solve'
    end select
  end function stage_name

  !> The solver's code in words: MUMPS's INFOG(1), -10 the banded LU's singular matrix too
  !> (the sparse_direct wrapper's own codes 1 .. 3 as a number).
  pure function mumps_text(code) result(text)
    integer, intent(in) :: code
    character(len=80) :: text
    select case (code)
    case (-10)
      text = 'the matrix is numerically singular'
    case (-6)
      text = 'the matrix is structurally singular'
    case (-5, -13)
      text = 'MUMPS could not allocate memory'
    case (-9)
      text = 'MUMPS workspace too small'
    case default
      write (text, '(a, i0)') 'MUMPS error INFOG(1) = ', code
    end select
  end function mumps_text

end module consistent_start
