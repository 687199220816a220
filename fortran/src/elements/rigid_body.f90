!> ANCF reference node (seed 003 eqs. 29-32): a rigid body described by a position r and
!> three gradients J = [r_x r_y r_z] (natural coordinates), r(u) = r + J u = [I, xI, yI, zI] q.
!> Its mass matrix (eq. 32) is constant: M = kron(Mbar, I3) with
!>   Mbar = [[m, m c^T], [m c, m c c^T + tr(I_c)/2 I - I_c]]
!> (c: centre of mass in the body frame, I_c: inertia tensor about the centre of mass), whose
!> lower block is the second moment int rho u u^T dV. Orthonormality of J (eq. 30) is imposed
!> by the constraints module (dot constraints with multipliers).
module rigid_body
  use ancf_kinds, only: dp
  implicit none
  private
  public :: rigid_body_mass

contains

  !> 12 x 12 mass matrix, coordinates ordered [r, r_x, r_y, r_z]. info = 1: mass not positive;
  !> 2: the inertia tensor is not symmetric or its second moment int rho u u^T is not
  !> positive semi-definite (principal moments violate the triangle inequality).
  pure subroutine rigid_body_mass(mass, centre, inertia, mass_matrix, info)
    real(dp), intent(in) :: mass, centre(3), inertia(3, 3)
    real(dp), intent(out) :: mass_matrix(12, 12)
    integer, intent(out) :: info
    real(dp) :: compact(4, 4), spread_about_centre(3, 3), minors(3), scale
    integer :: a, b, i
    mass_matrix = 0.0_dp
    info = 0
    if (.not. mass > 0.0_dp) then
      info = 1
      return
    end if
    scale = max(maxval(abs(inertia)), tiny(1.0_dp))
    if (maxval(abs(inertia - transpose(inertia))) > 1e-12_dp * scale) then
      info = 2
      return
    end if
    spread_about_centre = -inertia
    do i = 1, 3
      spread_about_centre(i, i) = spread_about_centre(i, i) + 0.5_dp * (inertia(1, 1) &
                                  + inertia(2, 2) + inertia(3, 3))
    end do
    ! Sylvester-type check of positive semi-definiteness (leading minors)
    minors(1) = minval([spread_about_centre(1, 1), spread_about_centre(2, 2), spread_about_centre(3, 3)])
    minors(2) = spread_about_centre(1, 1) * spread_about_centre(2, 2) - spread_about_centre(1, 2)**2
    minors(3) = spread_about_centre(1, 1) * (spread_about_centre(2, 2) * spread_about_centre(3, 3) &
                - spread_about_centre(2, 3)**2) - spread_about_centre(1, 2) * (spread_about_centre(1, 2) &
                * spread_about_centre(3, 3) - spread_about_centre(2, 3) * spread_about_centre(1, 3)) &
                + spread_about_centre(1, 3) * (spread_about_centre(1, 2) * spread_about_centre(2, 3) &
                - spread_about_centre(2, 2) * spread_about_centre(1, 3))
    if (minors(1) < -1e-12_dp * scale .or. minors(2) < -1e-12_dp * scale**2 .or. &
        minors(3) < -1e-12_dp * scale**3) then
      info = 2
      return
    end if
    compact(1, 1) = mass
    compact(1, 2:4) = mass * centre
    compact(2:4, 1) = mass * centre
    do a = 1, 3
      do b = a, 3  ! one triangle, mirrored: exactly symmetric
        compact(1 + a, 1 + b) = mass * centre(a) * centre(b) + spread_about_centre(a, b)
        compact(1 + b, 1 + a) = compact(1 + a, 1 + b)
      end do
    end do
    do a = 1, 4
      do b = 1, 4
        do i = 1, 3
          mass_matrix(3 * (a - 1) + i, 3 * (b - 1) + i) = compact(a, b)
        end do
      end do
    end do
  end subroutine rigid_body_mass

end module rigid_body
