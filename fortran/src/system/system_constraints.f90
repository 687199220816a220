!> The constraints with Lagrange multipliers of a mechanical system (a component of
!> system_model): per constraint a kind, a drive (0: none), parameters and six affine
!> operands on the independent coordinates e (constraints.f90 layout: operand s of
!> constraint c has the constant operand_const(s, c) and the terms term_ptr(6 (c - 1) + s)
!> .. term_ptr(6 (c - 1) + s + 1) - 1); their values, gradients and the products with
!> Phi_e. No I/O.
module system_constraints
  use ancf_kinds, only: dp
  use constraints, only: constraint_eval, constraint_value, constraint_kind_coordinate, &
                         constraint_kind_distance, constraint_kind_cross, constraint_kind_dot
  use matrix3, only: cross
  use system_drives, only: drive_table, drive_at
  implicit none
  private
  public :: constraint_table, evaluate_constraints, constraint_derivatives, &
            constraint_reaction, gradient_dot, gradient_product, operand_count, &
            add_gradient_column, term_count, saddle_gradient_entries

  type :: constraint_table
    integer :: ncon = 0
    integer, allocatable :: kind(:), drive(:), term_ptr(:), term_dof(:)
    ! each constraint's last operand with terms (0: none), set with the constraints
    integer, allocatable :: operands(:)
    real(dp), allocatable :: params(:, :), operand_const(:, :), term_coef(:)
  end type constraint_table

contains

  !> Values, gradients, Hessians, Phi_t, Phi_tt and gamma of every constraint at (e, e', t)
  !> (constraint_eval on the table; first_order_only: no Hessians and second-order terms).
  pure subroutine constraint_derivatives(constraints, drives, e, e_dot, t, values, gradients, &
                                         hessians, phi_t, phi_tt, gamma, info, first_order_only)
    type(constraint_table), intent(in) :: constraints
    type(drive_table), intent(in) :: drives
    real(dp), intent(in) :: e(:), e_dot(:), t
    real(dp), intent(out) :: values(:), gradients(:, :), hessians(:, :, :)
    real(dp), intent(out) :: phi_t(:), phi_tt(:), gamma(:)
    integer, intent(out) :: info
    logical, intent(in), optional :: first_order_only
    call constraint_eval(constraints%ncon, constraints%kind, constraints%drive, &
                         constraints%params, constraints%operand_const, constraints%term_ptr, &
                         constraints%term_dof, constraints%term_coef, drives%kinds, drives%ptr, &
                         drives%data, e, e_dot, t, values, gradients, hessians, phi_t, phi_tt, &
                         gamma, info, first_order_only)
  end subroutine constraint_derivatives

  !> Constraint values and operand gradients at (e, t). info = 5 when a constraint or its
  !> drive cannot be evaluated. constraint_eval's first-order results with the same
  !> arithmetic (constraint_value, the operands summed as operand_values sums them), without
  !> its argument descriptors, and a coordinate constraint's first operand alone (the only
  !> one its value and gradient use): the Newton corrections of small systems evaluate it
  !> in every correction.
  subroutine evaluate_constraints(constraints, drives, ndof, e, t, phi, gradients, info)
    type(constraint_table), intent(in) :: constraints
    type(drive_table), intent(in) :: drives
    integer, intent(in) :: ndof
    real(dp), intent(in) :: e(:), t
    real(dp), intent(out) :: phi(:), gradients(:, :)
    integer, intent(out) :: info
    real(dp) :: x(6), drive_phi, dphi, ddphi, cos_phi, sin_phi
    integer :: c, s, k, last_operand, drive_info
    info = 0
    if (constraints%ncon == 0) return
    ! (every term's coordinate lies in 1..ndof: system_set_constraints checked it once)
    if (size(e) < ndof) then
      info = 5
      return
    end if
    do c = 1, constraints%ncon
      drive_phi = 0.0_dp  ! (drive_value's value without a drive)
      if (constraints%drive(c) /= 0) then
        call drive_at(drives, constraints%drive(c), t, &
                         drive_phi, dphi, ddphi, drive_info)
        if (drive_info /= 0) then
          info = 5
          return
        end if
      end if
      last_operand = 6
      if (constraints%kind(c) == constraint_kind_coordinate) then
        if (constraints%term_ptr(6 * (c - 1) + 2) == constraints%term_ptr(6 * (c - 1) + 1)) then
          info = 5  ! no coordinate in the first operand
          return
        end if
        last_operand = 1
      else if (constraints%kind(c) < constraint_kind_coordinate .or. &
               constraints%kind(c) > constraint_kind_dot) then
        info = 5
        return
      end if
      do s = 1, 6
        x(s) = 0.0_dp
      end do
      do s = 1, last_operand
        x(s) = constraints%operand_const(s, c)
        do k = constraints%term_ptr(6 * (c - 1) + s), constraints%term_ptr(6 * (c - 1) + s + 1) - 1
          x(s) = x(s) + constraints%term_coef(k) * e(constraints%term_dof(k))
        end do
      end do
      cos_phi = 1.0_dp
      sin_phi = 0.0_dp
      if (constraints%kind(c) == constraint_kind_coordinate .and. constraints%drive(c) /= 0) then
        cos_phi = cos(drive_phi)
        sin_phi = sin(drive_phi)
      end if
      if (constraints%kind(c) == constraint_kind_coordinate) then
        ! (constraint_value's formula of the kind, written in place of the call)
        phi(c) = x(1) - (constraints%params(1, c) + constraints%params(2, c) * cos_phi &
                         + constraints%params(3, c) * sin_phi + constraints%params(4, &
                             c) * drive_phi)
      else
        phi(c) = constraint_value(constraints%kind(c), constraints%drive(c) /= 0, &
                                  constraints%params(:, c), x, drive_phi, cos_phi, sin_phi)
      end if
      do s = 1, 6
        gradients(s, c) = 0.0_dp
      end do
      select case (constraints%kind(c))
      case (constraint_kind_coordinate)
        gradients(1, c) = 1.0_dp
      case (constraint_kind_distance)
        gradients(1:3, c) = 2.0_dp * (x(1:3) - x(4:6))
        gradients(4:6, c) = -2.0_dp * (x(1:3) - x(4:6))
      case (constraint_kind_cross)
        gradients(1:3, c) = cross(x(4:6), constraints%params(1:3, c))
        gradients(4:6, c) = cross(constraints%params(1:3, c), x(1:3))
      case default  ! constraint_kind_dot
        gradients(1:3, c) = x(4:6)
        gradients(4:6, c) = x(1:3)
      end select
    end do
  end subroutine evaluate_constraints

  !> r = r - Phi_e^T lambda.
  pure subroutine constraint_reaction(constraints, gradients, lam, r)
    type(constraint_table), intent(in) :: constraints
    real(dp), intent(in) :: gradients(:, :), lam(:)
    real(dp), intent(inout) :: r(:)
    integer :: c, s, k
    do c = 1, constraints%ncon
      do s = 1, operand_count(constraints, c)
        do k = constraints%term_ptr(6 * (c - 1) + s), constraints%term_ptr(6 * (c - 1) + s + 1) - 1
          r(constraints%term_dof(k)) = r(constraints%term_dof(k)) - gradients(s, &
                                       c) * constraints%term_coef(k) * lam(c)
        end do
      end do
    end do
  end subroutine constraint_reaction

  !> Phi_e x for every constraint.
  pure function gradient_dot(constraints, gradients, x) result(y)
    type(constraint_table), intent(in) :: constraints
    real(dp), intent(in) :: gradients(:, :), x(:)
    real(dp) :: y(constraints%ncon)
    call gradient_product(constraints, gradients, x, y)
  end function gradient_dot

  !> y = Phi_e x for every constraint (gradient_dot into a given array).
  pure subroutine gradient_product(constraints, gradients, x, y)
    type(constraint_table), intent(in) :: constraints
    real(dp), intent(in) :: gradients(:, :), x(:)
    real(dp), intent(out) :: y(:)
    integer :: c, s, k
    y = 0.0_dp
    do c = 1, constraints%ncon
      do s = 1, operand_count(constraints, c)
        do k = constraints%term_ptr(6 * (c - 1) + s), constraints%term_ptr(6 * (c - 1) + s + 1) - 1
          y(c) = y(c) + gradients(s, c) * constraints%term_coef(k) * x(constraints%term_dof(k))
        end do
      end do
    end do
  end subroutine gradient_product

  !> The operands of constraint c up to the last with terms (con_operands, set with the
  !> constraints; 6 without it): the loops over the operands' terms skip the empty rest
  !> (a coordinate constraint's five unused operands).
  pure integer function operand_count(constraints, c) result(count_c)
    type(constraint_table), intent(in) :: constraints
    integer, intent(in) :: c
    count_c = 6
    if (allocated(constraints%operands)) count_c = constraints%operands(c)
  end function operand_count

  !> column += Phi_e^T's column of constraint c (its operands 1 .. last; the loops over the
  !> operands' terms in order).
  pure subroutine add_gradient_column(constraints, gradients, c, last, column)
    type(constraint_table), intent(in) :: constraints
    real(dp), intent(in) :: gradients(:, :)
    integer, intent(in) :: c, last
    real(dp), intent(inout) :: column(:)
    integer :: s, k
    do s = 1, last
      do k = constraints%term_ptr(6 * (c - 1) + s), constraints%term_ptr(6 * (c - 1) + s + 1) - 1
        column(constraints%term_dof(k)) = column(constraints%term_dof(k)) &
                                          + gradients(s, c) * constraints%term_coef(k)
      end do
    end do
  end subroutine add_gradient_column

  !> The number of terms of all the constraints' operands.
  pure integer function term_count(constraints)
    type(constraint_table), intent(in) :: constraints
    term_count = 0
    if (constraints%ncon > 0) term_count = constraints%term_ptr(6 * constraints%ncon + 1) &
                                           - constraints%term_ptr(1)
  end function term_count

  !> Phi_e^T and Phi_e as coordinates of a saddle matrix whose rows and columns n + c are
  !> the constraints': the first term_count entries Phi_e^T's (rows of e, columns of lambda,
  !> minus the gradients), the next term_count the same values at Phi_e's positions.
  pure subroutine saddle_gradient_entries(constraints, gradients, n, rows, cols, entries)
    type(constraint_table), intent(in) :: constraints
    real(dp), intent(in) :: gradients(:, :)
    integer, intent(in) :: n
    integer, intent(out) :: rows(:), cols(:)
    real(dp), intent(out) :: entries(:)
    integer :: c, s, k, i, nterm
    nterm = term_count(constraints)
    i = 0
    do c = 1, constraints%ncon
      do s = 1, 6
        do k = constraints%term_ptr(6 * (c - 1) + s), constraints%term_ptr(6 * (c - 1) + s + 1) - 1
          i = i + 1
          rows(i) = constraints%term_dof(k)
          cols(i) = n + c
          entries(i) = -(constraints%term_coef(k) * gradients(s, c))
          rows(i + nterm) = n + c
          cols(i + nterm) = constraints%term_dof(k)
          entries(i + nterm) = entries(i)
        end do
      end do
    end do
  end subroutine saddle_gradient_entries

end module system_constraints
