!> Small dense 3 x 3 algebra shared by the element routines.
module matrix3
  use ancf_kinds, only: dp
  implicit none
  private
  public :: invert3

contains

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
