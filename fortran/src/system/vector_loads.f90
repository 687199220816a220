!> Generalized forces of the configuration-dependent point loads (SPEC 8.1): a dead
!> (spatially fixed) moment written on the current section, a follower moment and a
!> follower force (fixed in the body's material frame), each scaled by a drive.
!>
!> A load acts at a material point whose two directions a, b (a beam's section directors
!> r_y, r_z; a plate's r_x, r_y; a rigid body's r_x, r_y) and position p are linear in the
!> coordinates; n = a x b is the third direction (the beam's axis, the plate's normal, the
!> rigid body's r_z). A moment m = m_a a + m_b b + m_n n does the virtual work m . dtheta
!> on the section's turn (da = dtheta x a, db = dtheta x b) through the forces
!>   Q_a = w_a m_n b - m_b n,   Q_b = m_a n - w_b m_n a   (w_a + w_b = 1)
!> on a and b: a x Q_a + b x Q_b = m when a, b, n are orthonormal; the components about a
!> and b act on the other director, the torsion m_n on both in the shares w that turn the
!> section without shearing it. A dead moment takes m_a = m . a, m_b = m . b, m_n = m . n
!> at the current directors; a follower moment keeps its material components. A follower
!> force F = c_a a + c_b b + c_n n acts on p. The Jacobians are exact (not symmetric: these
!> loads have no potential).
module vector_loads
  use ancf_kinds, only: dp
  implicit none
  private
  public :: vector_load_force
  integer, parameter, public :: vload_dead_moment = 1, vload_follower_moment = 2, &
                                vload_follower_force = 3

contains

  !> Forces on the slots (a, b, p): force(:, slot); jacobian(i, slot, j, wrt) =
  !> d force(i, slot) / d x(j) with x = a (wrt = 1) or b (wrt = 2). vector: the moment m
  !> (dead) or the material components (c_a, c_b, c_n) (follower), times the drive's value
  !> already; shares: (w_a, w_b). info = 1 for an unknown kind.
  pure subroutine vector_load_force(kind, vector, shares, a, b, force, jacobian, info)
    integer, intent(in) :: kind
    real(dp), intent(in) :: vector(3), shares(2), a(3), b(3)
    real(dp), intent(out) :: force(3, 3), jacobian(3, 3, 3, 2)
    integer, intent(out) :: info
    real(dp) :: n(3), eye(3, 3), m_a, m_b, m_n, b_m(3), m_a_x(3)
    integer :: i
    info = 0
    force = 0.0_dp
    jacobian = 0.0_dp
    eye = 0.0_dp
    do i = 1, 3
      eye(i, i) = 1.0_dp
    end do
    n = cross(a, b)
    select case (kind)
    case (vload_dead_moment)
      m_a = dot_product(vector, a)
      m_b = dot_product(vector, b)
      m_n = dot_product(vector, n)
      b_m = cross(b, vector)     ! d m_n / da
      m_a_x = cross(vector, a)   ! d m_n / db
      force(:, 1) = shares(1) * m_n * b - m_b * n
      force(:, 2) = m_a * n - shares(2) * m_n * a
      jacobian(:, 1, :, 1) = shares(1) * outer(b, b_m) + m_b * skew(b)
      jacobian(:, 1, :, 2) = shares(1) * outer(b, m_a_x) + shares(1) * m_n * eye &
                             - outer(n, vector) - m_b * skew(a)
      jacobian(:, 2, :, 1) = outer(n, vector) - m_a * skew(b) - shares(2) * outer(a, b_m) &
                             - shares(2) * m_n * eye
      jacobian(:, 2, :, 2) = m_a * skew(a) - shares(2) * outer(a, m_a_x)
    case (vload_follower_moment)
      force(:, 1) = shares(1) * vector(3) * b - vector(2) * n
      force(:, 2) = vector(1) * n - shares(2) * vector(3) * a
      jacobian(:, 1, :, 1) = vector(2) * skew(b)
      jacobian(:, 1, :, 2) = shares(1) * vector(3) * eye - vector(2) * skew(a)
      jacobian(:, 2, :, 1) = -vector(1) * skew(b) - shares(2) * vector(3) * eye
      jacobian(:, 2, :, 2) = vector(1) * skew(a)
    case (vload_follower_force)
      force(:, 3) = vector(1) * a + vector(2) * b + vector(3) * n
      jacobian(:, 3, :, 1) = vector(1) * eye - vector(3) * skew(b)
      jacobian(:, 3, :, 2) = vector(2) * eye + vector(3) * skew(a)
    case default
      info = 1
    end select
  end subroutine vector_load_force

  pure function cross(x, y) result(z)
    real(dp), intent(in) :: x(3), y(3)
    real(dp) :: z(3)
    z = [x(2) * y(3) - x(3) * y(2), x(3) * y(1) - x(1) * y(3), x(1) * y(2) - x(2) * y(1)]
  end function cross

  !> skew(x) y = x cross y
  pure function skew(x) result(s)
    real(dp), intent(in) :: x(3)
    real(dp) :: s(3, 3)
    s = reshape([0.0_dp, x(3), -x(2), -x(3), 0.0_dp, x(1), x(2), -x(1), 0.0_dp], [3, 3])
  end function skew

  pure function outer(x, y) result(s)
    real(dp), intent(in) :: x(3), y(3)
    real(dp) :: s(3, 3)
    s = spread(x, 2, 3) * spread(y, 1, 3)
  end function outer

end module vector_loads
