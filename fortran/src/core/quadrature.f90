!> Gauss-Legendre rules on [-1, 1].
module quadrature
  use ancf_kinds, only: dp
  implicit none
  private
  public :: gauss_legendre

contains

  !> Points and weights of the n-point Gauss-Legendre rule (1 <= n <= 5),
  !> exact for polynomials of degree 2n-1. info = 1 for an unsupported n.
  pure subroutine gauss_legendre(n, points, weights, info)
    integer, intent(in) :: n
    real(dp), intent(out) :: points(n), weights(n)
    integer, intent(out) :: info
    real(dp) :: a, b
    info = 0
    select case (n)
    case (1)
      points = [0.0_dp]
      weights = [2.0_dp]
    case (2)
      a = 1.0_dp / sqrt(3.0_dp)
      points = [-a, a]
      weights = [1.0_dp, 1.0_dp]
    case (3)
      a = sqrt(0.6_dp)
      points = [-a, 0.0_dp, a]
      weights = [5.0_dp, 8.0_dp, 5.0_dp] / 9.0_dp
    case (4)
      a = sqrt(3.0_dp / 7.0_dp - 2.0_dp / 7.0_dp * sqrt(1.2_dp))
      b = sqrt(3.0_dp / 7.0_dp + 2.0_dp / 7.0_dp * sqrt(1.2_dp))
      points = [-b, -a, a, b]
      a = (18.0_dp + sqrt(30.0_dp)) / 36.0_dp
      b = (18.0_dp - sqrt(30.0_dp)) / 36.0_dp
      weights = [b, a, a, b]
    case (5)
      a = sqrt(5.0_dp - 2.0_dp * sqrt(10.0_dp / 7.0_dp)) / 3.0_dp
      b = sqrt(5.0_dp + 2.0_dp * sqrt(10.0_dp / 7.0_dp)) / 3.0_dp
      points = [-b, -a, 0.0_dp, a, b]
      a = (322.0_dp + 13.0_dp * sqrt(70.0_dp)) / 900.0_dp
      b = (322.0_dp - 13.0_dp * sqrt(70.0_dp)) / 900.0_dp
      weights = [b, a, 128.0_dp / 225.0_dp, a, b]
    case default
      points = 0.0_dp
      weights = 0.0_dp
      info = 1
    end select
  end subroutine gauss_legendre

end module quadrature
