!> Elastic forces of the ANCF-FFR model (seed 000, eqs. 13-21): the constant element
!> stiffness K0 lives in the floating frame A; with T = blockdiag(A, ..., A),
!>   Q_el = T K0 (T^T e - e0),   K = T K0 T^T,   U = 1/2 (T^T e - e0)^T K0 (T^T e - e0),
!> where e0 is the rigid (reference) configuration expressed in the frame (per element,
!> reference(24, nel)). A rigid translation of the frame's origin changes T^T e - e0 by a
!> uniform translation of the position vectors, which K0 annihilates: only the frame's
!> rotation enters.
module ffr_elastic
  use ancf_kinds, only: dp
  implicit none
  private
  public :: ffr_force, ffr_stiffness, ffr_energy_power

contains

  !> Frame coordinates A^T e_a - e0_a of one element's eight nodal vectors.
  pure function frame_displacement(rotation, e, dofs, reference) result(local)
    real(dp), intent(in) :: rotation(3, 3), e(:), reference(24)
    integer, intent(in) :: dofs(24)
    real(dp) :: local(24)
    integer :: a
    do a = 0, 7
      ! (A^T v)_j = sum_i A(i, j) v_i, written out
      local(3 * a + 1:3 * a + 3) = rotation(1, :) * e(dofs(3 * a + 1)) &
                                   + rotation(2, :) * e(dofs(3 * a + 2)) &
                                   + rotation(3, :) * e(dofs(3 * a + 3))
    end do
    local = local - reference
  end function frame_displacement

  !> Adds the global elastic force to force and returns the strain energy; dofs(24, nel)
  !> are 1-based indices into e and force.
  pure subroutine ffr_force(nel, dofs, stiffness0, reference, rotation, e, force, energy)
    integer, intent(in) :: nel, dofs(24, nel)
    real(dp), intent(in) :: stiffness0(24, 24, nel), reference(24, nel), rotation(3, 3), e(:)
    real(dp), intent(inout) :: force(:)
    real(dp), intent(out) :: energy
    real(dp) :: local_disp(24), local_force(24)
    integer :: el, a, i
    energy = 0.0_dp
    do el = 1, nel
      local_disp = frame_displacement(rotation, e, dofs(:, el), reference(:, el))
      local_force = matmul(stiffness0(:, :, el), local_disp)
      energy = energy + 0.5_dp * dot_product(local_disp, local_force)
      do a = 0, 7
        do i = 1, 3
          force(dofs(3 * a + i, el)) = force(dofs(3 * a + i, el)) + rotation(i, 1) * local_force(3 * a + 1) &
                                       + rotation(i, 2) * local_force(3 * a + 2) &
                                       + rotation(i, 3) * local_force(3 * a + 3)
        end do
      end do
    end do
  end subroutine ffr_force

  !> Strain energy and the power of the moving frame at fixed e, dU/dt = -phi' sum_b
  !> f_b . (k x x_b) with f = K0 u in the frame, u = T^T e - e0, x = T^T e (k: the unit axis
  !> of the frame's rotation, rate = phi').
  pure subroutine ffr_energy_power(nel, dofs, stiffness0, reference, rotation, axis, rate, e, &
                                   energy, power)
    integer, intent(in) :: nel, dofs(24, nel)
    real(dp), intent(in) :: stiffness0(24, 24, nel), reference(24, nel), rotation(3, 3)
    real(dp), intent(in) :: axis(3), rate, e(:)
    real(dp), intent(out) :: energy, power
    real(dp) :: local(24), frame_force(24), x(3), k(3)
    integer :: el, b
    energy = 0.0_dp
    power = 0.0_dp
    k = axis / norm2(axis)
    do el = 1, nel
      local = frame_displacement(rotation, e, dofs(:, el), reference(:, el))
      frame_force = matmul(stiffness0(:, :, el), local)
      energy = energy + 0.5_dp * dot_product(local, frame_force)
      if (rate == 0.0_dp) cycle
      do b = 0, 7
        x = local(3 * b + 1:3 * b + 3) + reference(3 * b + 1:3 * b + 3, el)
        power = power - rate * dot_product(frame_force(3 * b + 1:3 * b + 3), &
                [k(2) * x(3) - k(3) * x(2), k(3) * x(1) - k(1) * x(3), k(1) * x(2) - k(2) * x(1)])
      end do
    end do
  end subroutine ffr_energy_power

  !> Element stiffness matrices in the global frame, T K0 T^T, block by block.
  pure subroutine ffr_stiffness(nel, stiffness0, rotation, stiffness)
    integer, intent(in) :: nel
    real(dp), intent(in) :: stiffness0(24, 24, nel), rotation(3, 3)
    real(dp), intent(out) :: stiffness(24, 24, nel)
    integer :: el, a, b
    do el = 1, nel
      do b = 0, 7
        do a = 0, 7
          stiffness(3 * a + 1:3 * a + 3, 3 * b + 1:3 * b + 3, el) = matmul(rotation, &
            matmul(stiffness0(3 * a + 1:3 * a + 3, 3 * b + 1:3 * b + 3, el), transpose(rotation)))
        end do
      end do
    end do
  end subroutine ffr_stiffness

end module ffr_elastic
