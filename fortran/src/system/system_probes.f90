!> The probes of a mechanical system (a component of system_model): output points whose
!> positions are sums of coef q(dof:dof+2) over the full coordinates, and their deflections
!> A_f(t)^T (p - pivot_f) - reference in the frame f of each. No I/O.
module system_probes
  use ancf_kinds, only: dp
  implicit none
  private
  public :: probe_set, probe_values

  type :: probe_set
    ! per probe its terms ptr(p) .. ptr(p + 1) - 1 (dof, coef), its frame (0: global) and
    ! its reference (deflection 0)
    integer :: nprobe = 0
    integer, allocatable :: ptr(:), dof(:), frame(:)
    real(dp), allocatable :: coef(:), reference(:, :)
  end type probe_set

contains

  !> The probes' positions at the full coordinates e_full and their deflections
  !> A_f^T (p - pivot_f) - reference with the frames' rotations (index 0: the identity) and
  !> pivots (index 0: the origin).
  pure subroutine probe_values(probes, e_full, rotations, pivots, probe, deflection)
    type(probe_set), intent(in) :: probes
    real(dp), intent(in) :: e_full(:), rotations(:, :, 0:), pivots(:, 0:)
    real(dp), intent(out) :: probe(:, :), deflection(:, :)
    real(dp) :: relative(3), total
    integer :: p, k, f, j
    do p = 1, probes%nprobe
      probe(:, p) = 0.0_dp
      do k = probes%ptr(p), probes%ptr(p + 1) - 1
        probe(:, p) = probe(:, p) + probes%coef(k) &
                      * e_full(probes%dof(k):probes%dof(k) + 2)
      end do
      f = probes%frame(p)
      ! A_f^T (p - pivot) by its sums as matmul takes them (from 0, in the order of the
      ! rows), without matmul's library call and temporaries
      relative = probe(:, p) - pivots(:, f)
      do k = 1, 3
        total = 0.0_dp
        do j = 1, 3
          total = total + rotations(j, k, f) * relative(j)
        end do
        deflection(k, p) = total - probes%reference(k, p)
      end do
    end do
  end subroutine probe_values

end module system_probes
