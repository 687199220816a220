!> Generalized force of a constant (dead) moment M k on a node's cross-section
!> (seed 000, eqs. 26-29). The section's rotation about the fixed unit axis k is
!> measured by a section director d (r_y or r_z of the node):
!>   theta = angle of p = d - (k.d) k in the plane normal to k,
!>   dtheta/dd = (k x d) / s,   s = |p|^2,
!> so the virtual work M dtheta gives Q = M (k x d) / s on the director's three
!> coordinates. Q is the gradient of the potential -M theta, so its Jacobian is
!> symmetric; the second derivative (used by the split iteration's Taylor
!> expansion) is returned too.
module section_moment
  use ancf_kinds, only: dp
  implicit none
  private
  public :: moment_force, moment_force_only, moment_angle

contains

  !> What force and Jacobian share: the unit axis k, the director's part p normal to it,
  !> s = |p|^2, skew = [k x] and the force Q = magnitude (k x p) / s. info = 1 (force 0)
  !> when the director is parallel to k (rotation undefined).
  pure subroutine section_plane(director, axis, magnitude, k, p, s, skew, force, info)
    real(dp), intent(in) :: director(3), axis(3), magnitude
    real(dp), intent(out) :: k(3), p(3), s, skew(3, 3), force(3)
    integer, intent(out) :: info
    k = axis / norm2(axis)
    p = director - dot_product(k, director) * k
    s = dot_product(p, p)
    force = 0.0_dp
    skew = 0.0_dp
    info = 0
    if (s <= epsilon(1.0_dp) * dot_product(director, director)) then
      info = 1
      return
    end if
    skew(:, 1) = [0.0_dp, k(3), -k(2)]
    skew(:, 2) = [-k(3), 0.0_dp, k(1)]
    skew(:, 3) = [k(2), -k(1), 0.0_dp]
    force = magnitude * matmul(skew, p) / s
  end subroutine section_plane

  !> force(3) = Q, jacobian(3,3) = dQ/dd, hessian(3,3,3) = d2Q_i/dd_j dd_l.
  !> info = 1 when the director is parallel to k (rotation undefined).
  pure subroutine moment_force(director, axis, magnitude, force, jacobian, hessian, info)
    real(dp), intent(in) :: director(3), axis(3), magnitude
    real(dp), intent(out) :: force(3), jacobian(3, 3), hessian(3, 3, 3)
    integer, intent(out) :: info
    real(dp) :: k(3), p(3), kp(3), skew(3, 3), projector(3, 3), s
    integer :: i, j, l
    jacobian = 0.0_dp
    hessian = 0.0_dp
    call section_plane(director, axis, magnitude, k, p, s, skew, force, info)
    if (info /= 0) return
    projector = -spread(k, 2, 3) * spread(k, 1, 3)
    do i = 1, 3
      projector(i, i) = projector(i, i) + 1.0_dp
    end do
    kp = matmul(skew, p)
    do j = 1, 3
      do i = 1, 3
        jacobian(i, j) = magnitude * (skew(i, j) / s - 2.0_dp * kp(i) * p(j) / s**2)
      end do
    end do
    do l = 1, 3
      do j = 1, 3
        do i = 1, 3
          hessian(i, j, l) = magnitude * (-2.0_dp * (skew(i, j) * p(l) + skew(i, l) * p(j) &
                                                     + kp(i) * projector(j, l)) / s**2 &
                                          + 8.0_dp * kp(i) * p(j) * p(l) / s**3)
        end do
      end do
    end do
  end subroutine moment_force

  !> The force(3) = Q of moment_force alone (no Jacobian or Hessian): the residual's dead
  !> moments. info = 1 when the director is parallel to k.
  pure subroutine moment_force_only(director, axis, magnitude, force, info)
    real(dp), intent(in) :: director(3), axis(3), magnitude
    real(dp), intent(out) :: force(3)
    integer, intent(out) :: info
    real(dp) :: k(3), p(3), skew(3, 3), s
    call section_plane(director, axis, magnitude, k, p, s, skew, force, info)
  end subroutine moment_force_only

  !> Rotation angle of the director about the axis, measured from a reference direction
  !> (both projected on the plane normal to the axis), in (-pi, pi]. The potential of the
  !> dead moment is -magnitude * angle.
  pure real(dp) function moment_angle(director, axis, reference) result(angle)
    real(dp), intent(in) :: director(3), axis(3), reference(3)
    real(dp) :: k(3), p(3), q(3)
    k = axis / norm2(axis)
    p = director - dot_product(k, director) * k
    q = reference - dot_product(k, reference) * k
    angle = atan2(dot_product(k, [q(2) * p(3) - q(3) * p(2), q(3) * p(1) - q(1) * p(3), &
                                  q(1) * p(2) - q(2) * p(1)]), dot_product(q, p))
  end function moment_angle

end module section_moment
