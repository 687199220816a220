!> Holonomic constraints Phi(e, t) = 0 from a small general set, each a polynomial of
!> degree <= 2 in the coordinates, so its Hessian is constant:
!>   kind 1  coordinate  e(i1) - (c1 + c2 cos phi + c3 sin phi) = 0   (fixed when undriven)
!>   kind 2  distance    |e(i1:i3) - p|^2 - d^2 = 0                    (p = c1:c3, d = c4)
!>   kind 3  cross       k . ((e(i1:i3) - p) x e(i4:i6)) = 0           (p = c1:c3, k = c4:c6):
!>                       a gradient parallel to a position vector, in the plane normal to k
!>   kind 4  dot         e(i1:i3) . e(i4:i6) - c1 = 0   (an unused index: a component held
!>                       at zero, e.g. eliminated by a planar guide)
!> phi is the value of the constraint's drive (drives module; no drive: phi = 0).
!> Layout: ints(8, n) = [kind, drive, i1..i6] (1-based dofs, 0 = unused), reals(8, n).
module constraints
  use ancf_kinds, only: dp
  use drives, only: drive_eval
  use matrix3, only: cross
  implicit none
  private
  public :: constraint_eval, constraint_kind_coordinate, constraint_kind_distance, &
            constraint_kind_cross, constraint_kind_dot

  integer, parameter :: constraint_kind_coordinate = 1, constraint_kind_distance = 2, &
                        constraint_kind_cross = 3, constraint_kind_dot = 4

contains

  !> Values, sparse gradients (over the dofs ints(3:8)), constant Hessians, Phi_t and
  !> Phi_tt at (e, t); gamma = -(e_dot^T H e_dot) - Phi_tt is the right-hand side of
  !> the acceleration equation Phi_e e'' = gamma (no Phi_et terms: drives enter only
  !> as additive targets). info: 0 ok, k > 0 constraint k is malformed, -k drive of
  !> constraint k failed.
  pure subroutine constraint_eval(ncon, ints, reals, ndrive, drive_kinds, drive_params, &
                                  ndof, e, e_dot, t, values, gradients, hessians, &
                                  phi_t, phi_tt, gamma, info)
    integer, intent(in) :: ncon, ndrive, ndof
    integer, intent(in) :: ints(8, ncon), drive_kinds(ndrive)
    real(dp), intent(in) :: reals(8, ncon), drive_params(8, ndrive), e(ndof), e_dot(ndof), t
    real(dp), intent(out) :: values(ncon), gradients(6, ncon), hessians(6, 6, ncon)
    real(dp), intent(out) :: phi_t(ncon), phi_tt(ncon), gamma(ncon)
    integer, intent(out) :: info
    integer :: c, m, idx(6), drive, drive_info
    real(dp) :: phi, dphi, ddphi, x(6), v(6), a(3), b(3), k(3)
    values = 0.0_dp
    gradients = 0.0_dp
    hessians = 0.0_dp
    phi_t = 0.0_dp
    phi_tt = 0.0_dp
    gamma = 0.0_dp
    info = 0
    do c = 1, ncon
      idx = ints(3:8, c)
      if (any(idx < 0) .or. any(idx > ndof)) then
        info = c
        return
      end if
      x = 0.0_dp
      v = 0.0_dp
      do m = 1, 6
        if (idx(m) > 0) then
          x(m) = e(idx(m))
          v(m) = e_dot(idx(m))
        end if
      end do
      drive = ints(2, c)
      phi = 0.0_dp
      dphi = 0.0_dp
      ddphi = 0.0_dp
      if (drive > 0) then
        if (drive > ndrive) then
          info = c
          return
        end if
        call drive_eval(drive_kinds(drive), drive_params(:, drive), t, phi, dphi, ddphi, drive_info)
        if (drive_info /= 0) then
          info = -c
          return
        end if
      end if
      select case (ints(1, c))
      case (constraint_kind_coordinate)
        if (idx(1) == 0) then
          info = c
          return
        end if
        values(c) = x(1) - (reals(1, c) + reals(2, c) * cos(phi) + reals(3, c) * sin(phi))
        gradients(1, c) = 1.0_dp
        phi_t(c) = -(-reals(2, c) * sin(phi) + reals(3, c) * cos(phi)) * dphi
        phi_tt(c) = -((-reals(2, c) * cos(phi) - reals(3, c) * sin(phi)) * dphi**2 &
                      + (-reals(2, c) * sin(phi) + reals(3, c) * cos(phi)) * ddphi)
      case (constraint_kind_distance)
        if (any(idx(1:3) == 0)) then
          info = c
          return
        end if
        a = x(1:3) - reals(1:3, c)
        values(c) = dot_product(a, a) - reals(4, c)**2
        gradients(1:3, c) = 2.0_dp * a
        do m = 1, 3
          hessians(m, m, c) = 2.0_dp
        end do
      case (constraint_kind_cross)
        if (any(idx == 0)) then
          info = c
          return
        end if
        a = x(1:3) - reals(1:3, c)
        b = x(4:6)
        k = reals(4:6, c)
        values(c) = dot_product(k, cross(a, b))
        gradients(1:3, c) = cross(b, k)
        gradients(4:6, c) = cross(k, a)
        ! d2/da db of k.(a x b) = a^T S b with S(i, j) = k . (u_i x u_j)
        hessians(1:3, 4:6, c) = reshape([0.0_dp, -k(3), k(2), k(3), 0.0_dp, -k(1), &
                                          -k(2), k(1), 0.0_dp], [3, 3])
        hessians(4:6, 1:3, c) = transpose(hessians(1:3, 4:6, c))
      case (constraint_kind_dot)  ! unused entries: components held at zero
        if (all(idx(1:3) == 0) .or. all(idx(4:6) == 0)) then
          info = c
          return
        end if
        values(c) = dot_product(x(1:3), x(4:6)) - reals(1, c)
        gradients(1:3, c) = x(4:6)
        gradients(4:6, c) = x(1:3)
        do m = 1, 3
          hessians(m, m + 3, c) = 1.0_dp
          hessians(m + 3, m, c) = 1.0_dp
        end do
      case default
        info = c
        return
      end select
      gamma(c) = -dot_product(v, matmul(hessians(:, :, c), v)) - phi_tt(c)
    end do
  end subroutine constraint_eval

end module constraints
