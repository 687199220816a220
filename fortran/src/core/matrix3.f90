!> Small dense 3 x 3 algebra shared by the element routines.
module matrix3
  use ancf_kinds, only: dp
  implicit none
  private
  public :: invert3, cross, skew

contains

  !> The vector product u x v.
  pure function cross(u, v) result(w)
    real(dp), intent(in) :: u(3), v(3)
    real(dp) :: w(3)
    w = [u(2) * v(3) - u(3) * v(2), u(3) * v(1) - u(1) * v(3), u(1) * v(2) - u(2) * v(1)]
  end function cross

  !> The skew matrix [u]x with [u]x v = u x v.
  pure function skew(u) result(s)
    real(dp), intent(in) :: u(3)
    real(dp) :: s(3, 3)
    s(1, 1) = 0.0_dp
    s(2, 1) = u(3)
    s(3, 1) = -u(2)
    s(1, 2) = -u(3)
    s(2, 2) = 0.0_dp
    s(3, 2) = u(1)
    s(1, 3) = u(2)
    s(2, 3) = -u(1)
    s(3, 3) = 0.0_dp
  end function skew

  !> Inverse and determinant of a 3 x 3 matrix (inverse left at zero when singular).
  pure subroutine invert3(matrix, inverse, det)
    real(dp), intent(in) :: matrix(3, 3)
    real(dp), intent(out) :: inverse(3, 3), det
    inverse(1, 1) = matrix(2, 2) * matrix(3, 3) - matrix(2, 3) * matrix(3, 2)
    inverse(1, 2) = matrix(1, 3) * matrix(3, 2) - matrix(1, 2) * matrix(3, 3)
    inverse(1, 3) = matrix(1, 2) * matrix(2, 3) - matrix(1, 3) * matrix(2, 2)
    inverse(2, 1) = matrix(2, 3) * matrix(3, 1) - matrix(2, 1) * matrix(3, 3)
    inverse(2, 2) = matrix(1, 1) * matrix(3, 3) - matrix(1, 3) * matrix(3, 1)
    inverse(2, 3) = matrix(1, 3) * matrix(2, 1) - matrix(1, 1) * matrix(2, 3)
    inverse(3, 1) = matrix(2, 1) * matrix(3, 2) - matrix(2, 2) * matrix(3, 1)
    inverse(3, 2) = matrix(1, 2) * matrix(3, 1) - matrix(1, 1) * matrix(3, 2)
    inverse(3, 3) = matrix(1, 1) * matrix(2, 2) - matrix(1, 2) * matrix(2, 1)
    det = matrix(1, 1) * inverse(1, 1) + matrix(1, 2) * inverse(2, 1) + matrix(1, 3) * inverse(3, 1)
    if (det /= 0.0_dp) then
      inverse = inverse / det
    else
      inverse = 0.0_dp
    end if
  end subroutine invert3

end module matrix3
