!> Holonomic constraints Phi(e, t) = 0 from a small general set, each a polynomial of
!> degree <= 2 in its operands, so its Hessian is constant. A constraint has six scalar
!> operands x_s (two 3-vectors x(1:3), x(4:6)), each an affine combination of coordinates,
!>   x_s = c_s + sum_k a_k e(i_k),
!> which expresses nodal vectors, material points of rigid bodies (r + J u) and coordinates
!> eliminated by linear constraints alike. The kinds:
!>   kind 1  coordinate  x_1 - (p1 + p2 cos phi + p3 sin phi + p4 phi) = 0
!>   kind 2  distance    |x(1:3) - x(4:6)|^2 - (p1 + p2 phi)^2 = 0  (a driven length with p2 = 1)
!>   kind 3  cross       k . (x(1:3) x x(4:6)) = 0,  k = p(1:3): a vector parallel to a
!>                       position vector in the plane normal to k
!>   kind 4  dot         x(1:3) . x(4:6) - (p1 + p2 phi) = 0  (with p2 /= 0 and a drive: a driven
!>                       relative translation, e.g. a prismatic joint's actuator)
!> phi is the value of the constraint's drive (drives module; no drive: phi = 0).
!> Layout: kinds(n), drives(n), params(8, n), operand_const(6, n), and the terms of operand
!> s of constraint c at term_ptr(6 (c - 1) + s) ... term_ptr(6 (c - 1) + s + 1) - 1 of
!> term_dof (1-based) and term_coef. Drives: drive_kinds(m), and the parameters of drive d
!> at drive_data(drive_ptr(d) : drive_ptr(d + 1) - 1).
module constraints
  use ancf_kinds, only: dp
  use drives, only: drive_eval
  use matrix3, only: cross
  implicit none
  private
  public :: constraint_eval, constraint_values, constraint_gradients, operand_values, &
            drive_value, constraint_value, constraint_gradient

  integer, parameter, public :: constraint_kind_coordinate = 1, constraint_kind_distance = 2, &
                                constraint_kind_cross = 3, constraint_kind_dot = 4

contains

  !> phi, phi', phi'' of drive d (d = 0: no drive, all zero). info /= 0: the drive failed.
  pure subroutine drive_value(d, drive_kinds, drive_ptr, drive_data, t, phi, dphi, ddphi, info)
    integer, intent(in) :: d, drive_kinds(:), drive_ptr(:)
    real(dp), intent(in) :: drive_data(:), t
    real(dp), intent(out) :: phi, dphi, ddphi
    integer, intent(out) :: info
    phi = 0.0_dp
    dphi = 0.0_dp
    ddphi = 0.0_dp
    info = 0
    if (d == 0) return
    if (d < 0 .or. d > size(drive_kinds)) then
      info = 1
      return
    end if
    call drive_eval(drive_kinds(d), drive_data(drive_ptr(d):drive_ptr(d + 1) - 1), t, phi, dphi, &
                    ddphi, info)
  end subroutine drive_value

  !> Operand values of constraint c at x (with the constants) or their rates (without).
  pure function operand_values(c, operand_const, term_ptr, term_dof, term_coef, x, &
                               with_constant) result(values)
    integer, intent(in) :: c, term_ptr(:), term_dof(:)
    real(dp), intent(in) :: operand_const(:, :), term_coef(:), x(:)
    logical, intent(in) :: with_constant
    real(dp) :: values(6)
    integer :: s, k
    do s = 1, 6
      values(s) = 0.0_dp
      if (with_constant) values(s) = operand_const(s, c)
      do k = term_ptr(6 * (c - 1) + s), term_ptr(6 * (c - 1) + s + 1) - 1
        values(s) = values(s) + term_coef(k) * x(term_dof(k))
      end do
    end do
  end function operand_values

  !> Values, gradients and (constant) Hessians with respect to the operands, Phi_t, Phi_tt
  !> and gamma = -(x'^T H x') - Phi_tt (x' = the operands' rates at e_dot), the right-hand
  !> side of the acceleration equation Phi_e e'' = gamma. info: 0 ok, k > 0 constraint k is
  !> malformed (kind, drive or term indices), -k the drive of constraint k failed.
  pure subroutine constraint_eval(ncon, kinds, drives, params, operand_const, term_ptr, term_dof, &
                                  term_coef, drive_kinds, drive_ptr, drive_data, e, e_dot, t, &
                                  values, gradients, hessians, phi_t, phi_tt, gamma, info, &
                                  first_order_only)
    integer, intent(in) :: ncon, kinds(:), drives(:), term_ptr(:), term_dof(:)
    integer, intent(in) :: drive_kinds(:), drive_ptr(:)
    real(dp), intent(in) :: params(:, :), operand_const(:, :), term_coef(:), drive_data(:)
    real(dp), intent(in) :: e(:), e_dot(:), t
    real(dp), intent(out) :: values(:), gradients(:, :), hessians(:, :, :)
    real(dp), intent(out) :: phi_t(:), phi_tt(:), gamma(:)
    integer, intent(out) :: info
    !> values and gradients only (hessians, phi_t, phi_tt, gamma left undefined): the
    !> stepper's residual needs no more
    logical, intent(in), optional :: first_order_only
    integer :: c, m, drive_info
    real(dp) :: phi, dphi, ddphi, x(6), v(6), k(3), length, cos_phi, sin_phi
    logical :: second
    second = .true.
    if (present(first_order_only)) second = .not. first_order_only
    values = 0.0_dp
    gradients = 0.0_dp
    if (second) then
      hessians = 0.0_dp
      phi_t = 0.0_dp
      phi_tt = 0.0_dp
      gamma = 0.0_dp
    end if
    info = 0
    if (ncon > 0) then
      if (any(term_dof(1:term_ptr(6 * ncon + 1) - 1) < 1) .or. &
          any(term_dof(1:term_ptr(6 * ncon + 1) - 1) > size(e))) then
        info = 1
        return
      end if
    end if
    do c = 1, ncon
      x = operand_values(c, operand_const, term_ptr, term_dof, term_coef, e, .true.)
      if (second) v = operand_values(c, operand_const, term_ptr, term_dof, term_coef, e_dot, &
                                     .false.)
      call drive_value(drives(c), drive_kinds, drive_ptr, drive_data, t, phi, dphi, ddphi, &
                       drive_info)
      if (drive_info /= 0) then
        info = merge(c, -c, drives(c) < 0 .or. drives(c) > size(drive_kinds))
        return
      end if
      select case (kinds(c))
      case (constraint_kind_coordinate)
        if (term_ptr(6 * (c - 1) + 2) == term_ptr(6 * (c - 1) + 1)) then
          info = c  ! no coordinate in the first operand
          return
        end if
        ! (without a drive phi = 0: cos 0 = 1 and sin 0 = 0 exactly, without the calls)
        ! (without a drive phi = 0: cos 0 = 1 and sin 0 = 0 exactly, without the calls)
        cos_phi = 1.0_dp
        sin_phi = 0.0_dp
        if (drives(c) /= 0) then
          cos_phi = cos(phi)
          sin_phi = sin(phi)
        end if
        values(c) = constraint_value(kinds(c), drives(c) /= 0, params(:, c), x, phi, cos_phi, &
                                     sin_phi)
        gradients(:, c) = constraint_gradient(kinds(c), params(:, c), x)
        if (.not. second) cycle
        phi_t(c) = -(-params(2, c) * sin(phi) + params(3, c) * cos(phi) + params(4, c)) * dphi
        phi_tt(c) = -((-params(2, c) * cos(phi) - params(3, c) * sin(phi)) * dphi**2 &
                      + (-params(2, c) * sin(phi) + params(3, c) * cos(phi) + params(4, c)) * ddphi)
      case (constraint_kind_distance)
        length = params(1, c) + params(2, c) * phi
        values(c) = constraint_value(kinds(c), drives(c) /= 0, params(:, c), x, phi, 1.0_dp, &
                                     0.0_dp)
        gradients(:, c) = constraint_gradient(kinds(c), params(:, c), x)
        if (.not. second) cycle
        do m = 1, 3
          hessians(m, m, c) = 2.0_dp
          hessians(m + 3, m + 3, c) = 2.0_dp
          hessians(m, m + 3, c) = -2.0_dp
          hessians(m + 3, m, c) = -2.0_dp
        end do
        phi_t(c) = -2.0_dp * length * params(2, c) * dphi
        phi_tt(c) = -2.0_dp * (params(2, c) * dphi)**2 - 2.0_dp * length * params(2, c) * ddphi
      case (constraint_kind_cross)
        k = params(1:3, c)
        values(c) = constraint_value(kinds(c), drives(c) /= 0, params(:, c), x, phi, 1.0_dp, &
                                     0.0_dp)
        gradients(:, c) = constraint_gradient(kinds(c), params(:, c), x)
        if (.not. second) cycle
        ! d2/da db of k.(a x b) = a^T S b with S(i, j) = k . (u_i x u_j)
        hessians(1:3, 4:6, c) = reshape([0.0_dp, -k(3), k(2), k(3), 0.0_dp, -k(1), &
                                          -k(2), k(1), 0.0_dp], [3, 3])
        hessians(4:6, 1:3, c) = transpose(hessians(1:3, 4:6, c))
      case (constraint_kind_dot)
        values(c) = constraint_value(kinds(c), drives(c) /= 0, params(:, c), x, phi, 1.0_dp, &
                                     0.0_dp)
        gradients(:, c) = constraint_gradient(kinds(c), params(:, c), x)
        if (.not. second) cycle
        do m = 1, 3
          hessians(m, m + 3, c) = 1.0_dp
          hessians(m + 3, m, c) = 1.0_dp
        end do
        if (drives(c) /= 0) then
          phi_t(c) = -params(2, c) * dphi
          phi_tt(c) = -params(2, c) * ddphi
        end if
      case default
        info = c
        return
      end select
      gamma(c) = -dot_product(v, matmul(hessians(:, :, c), v)) - phi_tt(c)
    end do
  end subroutine constraint_eval

  !> The value of one constraint of kind ``kind`` (module doc) at its operands x and its
  !> drive's value phi (driven: the constraint has a drive; without one phi = 0), with
  !> cos_phi = cos(phi) and sin_phi = sin(phi) for the coordinate kind (1 and 0 exactly
  !> without a drive; the callers evaluate them, once per drive where they can). The one
  !> formula of constraint_eval and constraint_values; an unknown kind gives 0 (the callers
  !> refuse it).
  pure function constraint_value(kind, driven, p, x, phi, cos_phi, sin_phi) result(value)
    integer, intent(in) :: kind
    logical, intent(in) :: driven
    real(dp), intent(in) :: p(:), x(6), phi, cos_phi, sin_phi
    real(dp) :: value
    real(dp) :: a(3), length
    select case (kind)
    case (constraint_kind_coordinate)
      value = x(1) - (p(1) + p(2) * cos_phi + p(3) * sin_phi + p(4) * phi)
    case (constraint_kind_distance)
      a = x(1:3) - x(4:6)
      length = p(1) + p(2) * phi
      value = dot_product(a, a) - length**2
    case (constraint_kind_cross)
      value = dot_product(p(1:3), cross(x(1:3), x(4:6)))
    case (constraint_kind_dot)
      value = dot_product(x(1:3), x(4:6)) - p(1)
      if (driven) value = value - p(2) * phi
    case default
      value = 0.0_dp
    end select
  end function constraint_value

  !> The gradient of one constraint of kind ``kind`` with respect to its six operands at x
  !> (it depends on no drive: a driven term is a function of t alone). The one formula of
  !> constraint_eval and constraint_gradients; an unknown kind gives 0 (the callers refuse
  !> it).
  pure function constraint_gradient(kind, p, x) result(gradient)
    integer, intent(in) :: kind
    real(dp), intent(in) :: p(:), x(6)
    real(dp) :: gradient(6)
    real(dp) :: a(3)
    gradient = 0.0_dp
    select case (kind)
    case (constraint_kind_coordinate)
      gradient(1) = 1.0_dp
    case (constraint_kind_distance)
      a = x(1:3) - x(4:6)
      gradient(1:3) = 2.0_dp * a
      gradient(4:6) = -2.0_dp * a
    case (constraint_kind_cross)
      gradient(1:3) = cross(x(4:6), p(1:3))
      gradient(4:6) = cross(p(1:3), x(1:3))
    case (constraint_kind_dot)
      gradient(1:3) = x(4:6)
      gradient(4:6) = x(1:3)
    end select
  end function constraint_gradient

  !> The layout check of the row evaluators (constraint_gradients, constraint_values), once
  !> for all rows: 1 when a term's coordinate lies outside 1..ncoord, else the first
  !> constraint whose kind or drive index is invalid or that is a coordinate constraint
  !> without a coordinate (as constraint_eval reports them), else 0.
  pure integer function rows_layout_error(ncon, kinds, drives, ndrive, term_ptr, term_dof, &
                                          ncoord) result(info)
    integer, intent(in) :: ncon, kinds(:), drives(:), ndrive, term_ptr(:), term_dof(:), ncoord
    integer :: c
    info = 0
    if (any(term_dof(1:term_ptr(6 * ncon + 1) - 1) < 1) .or. &
        any(term_dof(1:term_ptr(6 * ncon + 1) - 1) > ncoord)) then
      info = 1
      return
    end if
    do c = 1, ncon
      if (kinds(c) < constraint_kind_coordinate .or. kinds(c) > constraint_kind_dot .or. &
          drives(c) < 0 .or. drives(c) > ndrive .or. &
          (kinds(c) == constraint_kind_coordinate .and. &
           term_ptr(6 * (c - 1) + 2) == term_ptr(6 * (c - 1) + 1))) then
        info = c
        return
      end if
    end do
  end function rows_layout_error

  !> The operand gradients alone at nrow states (e_rows(:, row)): what constraint_eval
  !> returns as gradients, with the same arithmetic (operand_values, constraint_gradient),
  !> for the reactions of the output rows. The gradients depend on no drive, so none is
  !> evaluated; the layout is checked once. info: 0 ok, 1 a term index outside e_rows, k > 0
  !> constraint k is malformed (kind, drive index, a coordinate constraint without a
  !> coordinate), as constraint_eval reports them.
  pure subroutine constraint_gradients(ncon, nrow, kinds, drives, params, operand_const, &
                                       term_ptr, term_dof, term_coef, ndrive, e_rows, &
                                       gradients, info)
    integer, intent(in) :: ncon, nrow, kinds(:), drives(:), term_ptr(:), term_dof(:), ndrive
    real(dp), intent(in) :: params(:, :), operand_const(:, :), term_coef(:), e_rows(:, :)
    real(dp), intent(out) :: gradients(6, ncon, nrow)
    integer, intent(out) :: info
    integer :: c, row
    gradients = 0.0_dp
    info = 0
    if (ncon == 0) return
    info = rows_layout_error(ncon, kinds, drives, ndrive, term_ptr, term_dof, size(e_rows, 1))
    if (info /= 0) return
    do row = 1, nrow
      do c = 1, ncon
        gradients(:, c, row) = constraint_gradient(kinds(c), params(:, c), operand_values( &
          c, operand_const, term_ptr, term_dof, term_coef, e_rows(:, row), .true.))
      end do
    end do
  end subroutine constraint_gradients

  !> The values Phi(e, t) alone at nrow states (e_rows(:, row), times(row)): what
  !> constraint_eval returns as values, with the same arithmetic (constraint_value), for
  !> the output rows' constraint check. The layout is checked once, each drive evaluated
  !> once a row (its cos and sin too). info as constraint_eval's (at the first failing row).
  pure subroutine constraint_values(ncon, nrow, kinds, drives, params, operand_const, &
                                    term_ptr, term_dof, term_coef, drive_kinds, drive_ptr, &
                                    drive_data, e_rows, times, values, info)
    integer, intent(in) :: ncon, nrow, kinds(:), drives(:), term_ptr(:), term_dof(:)
    integer, intent(in) :: drive_kinds(:), drive_ptr(:)
    real(dp), intent(in) :: params(:, :), operand_const(:, :), term_coef(:), drive_data(:)
    real(dp), intent(in) :: e_rows(:, :), times(:)
    real(dp), intent(out) :: values(ncon, nrow)
    integer, intent(out) :: info
    real(dp) :: x(6), phi(size(drive_kinds)), cos_phi(size(drive_kinds))
    real(dp) :: sin_phi(size(drive_kinds)), phi_c, cos_c, sin_c, unused_rate, unused_accel
    logical :: evaluated(size(drive_kinds)), turned(size(drive_kinds))
    integer :: c, d, row, s, k, drive_info
    values = 0.0_dp
    info = 0
    if (ncon == 0) return
    info = rows_layout_error(ncon, kinds, drives, size(drive_kinds), term_ptr, term_dof, &
                             size(e_rows, 1))
    if (info /= 0) return
    do row = 1, nrow
      evaluated = .false.
      turned = .false.
      do c = 1, ncon
        d = drives(c)
        phi_c = 0.0_dp
        cos_c = 1.0_dp
        sin_c = 0.0_dp
        if (d /= 0) then
          if (.not. evaluated(d)) then
            call drive_value(d, drive_kinds, drive_ptr, drive_data, times(row), phi(d), &
                             unused_rate, unused_accel, drive_info)
            if (drive_info /= 0) then
              info = -c
              return
            end if
            evaluated(d) = .true.
          end if
          phi_c = phi(d)
          if (kinds(c) == constraint_kind_coordinate) then
            if (.not. turned(d)) then
              cos_phi(d) = cos(phi(d))
              sin_phi(d) = sin(phi(d))
              turned(d) = .true.
            end if
            cos_c = cos_phi(d)
            sin_c = sin_phi(d)
          end if
        end if
        ! the operands, as operand_values sums them
        do s = 1, 6
          x(s) = operand_const(s, c)
          do k = term_ptr(6 * (c - 1) + s), term_ptr(6 * (c - 1) + s + 1) - 1
            x(s) = x(s) + term_coef(k) * e_rows(term_dof(k), row)
          end do
        end do
        values(c, row) = constraint_value(kinds(c), d /= 0, params(:, c), x, phi_c, cos_c, &
                                          sin_c)
      end do
    end do
  end subroutine constraint_values

end module constraints
