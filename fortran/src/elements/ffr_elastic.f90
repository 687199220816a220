!> Elastic forces of the ANCF-FFR model (seed 000, eqs. 13-21): the constant element
!> stiffness K0 lives in the floating frame A; with T = blockdiag(A, ..., A),
!>   Q_el = T K0 (T^T e - e0),   K = T K0 T^T,   U = 1/2 (T^T e - e0)^T K0 (T^T e - e0),
!> where e0 is the rigid (reference) configuration expressed in the frame.
module ffr_elastic
  use ancf_kinds, only: dp
  implicit none
  private
  public :: ffr_force, ffr_stiffness

contains

  !> Global elastic force and strain energy; dofs(24, nel) are 1-based global indices.
  pure subroutine ffr_force(ndof, nel, dofs, stiffness0, rotation, e, e0_frame, force, energy)
    integer, intent(in) :: ndof, nel, dofs(24, nel)
    real(dp), intent(in) :: stiffness0(24, 24, nel), rotation(3, 3), e(ndof), e0_frame(ndof)
    real(dp), intent(out) :: force(ndof), energy
    real(dp) :: local_disp(24), local_force(24)
    integer :: el, a, i
    force = 0.0_dp
    energy = 0.0_dp
    do el = 1, nel
      do a = 0, 7
        ! A^T e_a - e0_a, written out: (A^T v)_j = sum_i A(i, j) v_i
        local_disp(3 * a + 1:3 * a + 3) = rotation(1, :) * e(dofs(3 * a + 1, el)) &
                                          + rotation(2, :) * e(dofs(3 * a + 2, el)) &
                                          + rotation(3, :) * e(dofs(3 * a + 3, el))
      end do
      local_disp = local_disp - e0_frame(dofs(:, el))
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
