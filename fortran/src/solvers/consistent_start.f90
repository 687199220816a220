!> The consistent acceleration and multipliers of a state (t, e, e'): the start of a run and
!> the restart of the method at a change of the step (step_control). With the equations of
!> motion and the constraints differentiated twice (Phi_e e'' = gamma):
!>   [[M, -Phi_e^T], [-Phi_e, 0]] [e''; lambda] = [Q(t) - B^T (Q_el - Q_c - Q_M); -gamma],
!> solved by the kind of solver the model's iteration matrix uses (one model, one linear
!> solver): where that is the banded Cholesky (sparse_direct's banded_spd), M is factorized
!> by it and the multipliers solved through their Schur complement G^T M^{-1} G (G = Phi_e^T,
!> dense n x ncon; LAPACK dgesv), so a banded run never loads MUMPS's code; otherwise, or
!> when M or the Schur complement is singular there (a massless coordinate the constraints
!> fix), MUMPS (unsymmetric) on the saddle's coordinate list: M as the model assembled it
!> (its zero entries kept: the saddle's pattern and its analysis do not depend on the
!> values), then Phi_e^T's and Phi_e's entries, constraint by constraint, operand by
!> operand, term by term. One solver instance per solve, released after it. No I/O;
!> failures return codes and text.
module consistent_start
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state, frame_rotations, internal_forces, &
                               external_forces, contact_record
  use system_constraints, only: constraint_derivatives, term_count, saddle_gradient_entries
  use system_mass, only: saddle_mass_entries
  use sparse_direct, only: solver_create, solver_analyse, solver_factorize, solver_solve, &
                           solver_destroy, solver_banded, banded_spd
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
    integer :: n, ncon, nmass, nterm, handle, stage, ignored
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
    if (solver_banded(sys%matrix%solver_handle)) then
      call banded_schur_solve(n, ncon, rows(1:nmass), cols(1:nmass), entries(1:nmass), &
                              rows(nmass + 1:nmass + nterm), cols(nmass + 1:nmass + nterm), &
                              entries(nmass + 1:nmass + nterm), rhs(:, 1), info)
      if (info == 0) then
        accel = rhs(1:n, 1)
        lam = rhs(n + 1:n + ncon, 1)
        return
      end if
    end if
    stage = 1
    call solver_create(0, handle, info, detail)
    if (info == 0) then
      stage = 2
      call solver_analyse(handle, n + ncon, size(rows), rows, cols, info, detail)
      if (info == 0) then
        stage = 3
        call solver_factorize(handle, size(entries), entries, info, detail)
      end if
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

  !> The saddle system by the banded solver and the multipliers' Schur complement:
  !> [Y0, Y] = M^{-1} [f, G] (G = Phi_e^T from its saddle entries, which hold -G; duplicates
  !> summed as in the coordinate list), lambda = (G^T Y)^{-1} (gamma - G^T Y0),
  !> e'' = Y0 + Y lambda. x: [f; -gamma] in, [e''; lambda] out when info = 0; info /= 0: M
  !> (banded Cholesky, then pivoted LU) or G^T Y (dgesv) is singular, x unchanged.
  subroutine banded_schur_solve(n, ncon, mass_rows, mass_cols, mass_values, gradient_rows, &
                                gradient_cols, gradient_values, x, info)
    integer, intent(in) :: n, ncon, mass_rows(:), mass_cols(:), gradient_rows(:), &
                           gradient_cols(:)
    real(dp), intent(in) :: mass_values(:), gradient_values(:)
    real(dp), intent(inout) :: x(:)
    integer, intent(out) :: info
    real(dp), allocatable :: g(:, :), y(:, :), schur(:, :), lam(:)
    integer, allocatable :: pivots(:)
    integer :: handle, k, detail, ignored
    allocate (g(n, ncon), y(n, 1 + ncon))
    g = 0.0_dp
    do k = 1, size(gradient_rows)
      g(gradient_rows(k), gradient_cols(k) - n) = g(gradient_rows(k), gradient_cols(k) - n) &
                                                  - gradient_values(k)
    end do
    y(:, 1) = x(1:n)
    y(:, 2:) = g
    call solver_create(banded_spd, handle, info, detail)
    if (info /= 0) return
    call solver_analyse(handle, n, size(mass_rows), mass_rows, mass_cols, info, detail)
    if (info == 0) call solver_factorize(handle, size(mass_values), mass_values, info, detail)
    if (info == 0) call solver_solve(handle, n, 1 + ncon, y, info, detail)
    call solver_destroy(handle, ignored)
    if (info /= 0) return
    if (ncon > 0) then
      allocate (schur(ncon, ncon), lam(ncon), pivots(ncon))
      schur = matmul(transpose(g), y(:, 2:))
      lam = -x(n + 1:n + ncon) - matmul(transpose(g), y(:, 1))
      call dgesv(ncon, 1, schur, ncon, pivots, lam, ncon, info)
      if (info /= 0) return
      x(1:n) = y(:, 1) + matmul(y(:, 2:), lam)
      x(n + 1:n + ncon) = lam
    else
      x(1:n) = y(:, 1)
    end if
  end subroutine banded_schur_solve

  pure function stage_name(stage) result(name)
    integer, intent(in) :: stage
    character(len=16) :: name
    select case (stage)
    case (1)
      name = 'creation'
    case (2)
      name = 'analysis'
    case (3)
      name = 'factorization'
    case default
      name = 'solve'
    end select
  end function stage_name

  !> MUMPS's INFOG(1) in words (the sparse_direct wrapper's own codes 1 .. 3 too).
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
