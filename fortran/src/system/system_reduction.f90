!> The reduction of a mechanical system (a component of system_model): linear constraints
!> eliminated by a constant matrix, q = B e + q0 (B CSR over the full coordinates, 1-based;
!> without reduction B = I, q0 = 0), B as a selection when it is one, the full pattern of the
!> tangents and the plan of B^T S B from it; q from e, B^T of a full vector, the reduced
!> tangent. No I/O.
module system_reduction
  use ancf_kinds, only: dp
  implicit none
  private
  public :: coordinate_reduction, reduction_setup, to_full, to_reduced, reduce_tangent, &
            pattern_position, row_terms, reduced_col, reduced_coef, full_at

  type :: coordinate_reduction
    ! q = B e + q0 (active: B given; otherwise B = I, q0 = 0)
    logical :: active = .false.
    integer, allocatable :: ptr(:), col(:)
    real(dp), allocatable :: values(:), offset(:)
    ! a reduction that selects (each row of B empty or one entry 1): the column of each
    ! full coordinate (0: fixed), for to_full and to_reduced; unallocated otherwise
    integer, allocatable :: select(:)
    ! the same selection as lists: the selected full coordinates (increasing) with their
    ! columns, and the fixed ones
    integer, allocatable :: select_full(:), select_column(:), select_fixed(:)
    ! the selection takes no column twice (each reduced coordinate one full one)
    logical :: select_one_to_one = .false.
    ! the full pattern of the tangents (CSR, 1-based) and the plan of B^T S B on it:
    ! values(plan_target) += plan_coef * full_values(plan_source)
    integer, allocatable :: full_ptr(:), full_col(:)
    integer, allocatable :: plan_source(:), plan_target(:)
    real(dp), allocatable :: plan_coef(:)
  end type coordinate_reduction

contains

  !> q = B e + q0 (B CSR over nfull = size(b_ptr) - 1 rows, 1-based) and the plan of B^T S B;
  !> a selection (each row of B empty or one entry 1) also as its lists.
  subroutine reduction_setup(reduction, b_ptr, b_col, b_values, offset, plan_source, &
                             plan_target, plan_coef)
    type(coordinate_reduction), intent(inout) :: reduction
    integer, intent(in) :: b_ptr(:), b_col(:), plan_source(:), plan_target(:)
    real(dp), intent(in) :: b_values(:), offset(:), plan_coef(:)
    integer :: i, nfull
    nfull = size(b_ptr) - 1
    reduction%active = .true.
    reduction%ptr = b_ptr
    reduction%col = b_col
    reduction%values = b_values
    reduction%offset = offset
    reduction%plan_source = plan_source
    reduction%plan_target = plan_target
    reduction%plan_coef = plan_coef
    ! a selection: to_full and to_reduced by its columns (offset or 0, plus 1 x: the same
    ! sums without the row pointers and the products by 1)
    if (allocated(reduction%select)) deallocate (reduction%select, reduction%select_full, &
                                                 reduction%select_column, reduction%select_fixed)
    reduction%select_one_to_one = .false.
    if (all(b_ptr(2:) - b_ptr(:nfull) <= 1) .and. all(b_values == 1.0_dp)) then
      allocate (reduction%select(nfull))
      do i = 1, nfull
        reduction%select(i) = 0
        if (b_ptr(i + 1) > b_ptr(i)) reduction%select(i) = b_col(b_ptr(i))
      end do
      reduction%select_full = pack([(i, i = 1, nfull)], reduction%select > 0)
      reduction%select_column = pack(reduction%select, reduction%select > 0)
      reduction%select_fixed = pack([(i, i = 1, nfull)], reduction%select == 0)
      reduction%select_one_to_one = .true.
      do i = 1, size(reduction%select_column) - 1
        if (any(reduction%select_column(i + 1:) == reduction%select_column(i))) &
          reduction%select_one_to_one = .false.
      end do
    end if
  end subroutine reduction_setup

  !> q = B e + q0 (with_offset; velocities without).
  pure subroutine to_full(reduction, x, with_offset, full)
    type(coordinate_reduction), intent(in) :: reduction
    real(dp), intent(in) :: x(:)
    logical, intent(in) :: with_offset
    real(dp), intent(out) :: full(:)
    integer :: i, k
    real(dp) :: total
    if (.not. reduction%active) then
      full = x
      return
    end if
    if (allocated(reduction%select)) then
      ! a selection: the same sums (offset or 0, plus 1 x) without the row pointers, by the
      ! lists of selected and fixed coordinates
      if (with_offset) then
        do k = 1, size(reduction%select_fixed)
          full(reduction%select_fixed(k)) = reduction%offset(reduction%select_fixed(k))
        end do
        do k = 1, size(reduction%select_full)
          i = reduction%select_full(k)
          full(i) = reduction%offset(i) + x(reduction%select_column(k))
        end do
      else
        do k = 1, size(reduction%select_fixed)
          full(reduction%select_fixed(k)) = 0.0_dp
        end do
        do k = 1, size(reduction%select_full)
          full(reduction%select_full(k)) = 0.0_dp + x(reduction%select_column(k))
        end do
      end if
      return
    end if
    ! (a scalar accumulator per row, from the offset or 0: the same sums, in a register)
    do i = 1, size(reduction%offset)
      total = 0.0_dp
      if (with_offset) total = reduction%offset(i)
      do k = reduction%ptr(i), reduction%ptr(i + 1) - 1
        total = total + reduction%values(k) * x(reduction%col(k))
      end do
      full(i) = total
    end do
  end subroutine to_full

  !> x = B^T full (seed 003 eq. 37).
  pure subroutine to_reduced(reduction, full, x)
    type(coordinate_reduction), intent(in) :: reduction
    real(dp), intent(in) :: full(:)
    real(dp), intent(out) :: x(:)
    integer :: i, k
    if (.not. reduction%active) then
      x = full
      return
    end if
    x = 0.0_dp
    if (allocated(reduction%select)) then
      ! a selection: the same sums (0 plus 1 full(i), in increasing i) without the row
      ! pointers
      do k = 1, size(reduction%select_full)
        x(reduction%select_column(k)) = x(reduction%select_column(k)) &
                                        + full(reduction%select_full(k))
      end do
      return
    end if
    do i = 1, size(reduction%offset)
      do k = reduction%ptr(i), reduction%ptr(i + 1) - 1
        x(reduction%col(k)) = x(reduction%col(k)) + reduction%values(k) * full(i)
      end do
    end do
  end subroutine to_reduced

  !> Position of (row, col) in the full pattern, 0 when absent.
  pure integer function pattern_position(reduction, row, col) result(pos)
    type(coordinate_reduction), intent(in) :: reduction
    integer, intent(in) :: row, col
    integer :: k
    pos = 0
    do k = reduction%full_ptr(row), reduction%full_ptr(row + 1) - 1
      if (reduction%full_col(k) == col) then
        pos = k
        return
      end if
    end do
  end function pattern_position

  !> The reduced tangent B^T S B from the full pattern's values by the plan (a copy without
  !> reduction).
  pure subroutine reduce_tangent(reduction, values_full, tangent_values)
    type(coordinate_reduction), intent(in) :: reduction
    real(dp), intent(in) :: values_full(:)
    real(dp), intent(out) :: tangent_values(:)
    integer :: k
    if (reduction%active) then
      tangent_values = 0.0_dp
      do k = 1, size(reduction%plan_source)
        tangent_values(reduction%plan_target(k)) = tangent_values(reduction%plan_target(k)) &
                                                   + reduction%plan_coef(k) &
                                                   * values_full(reduction%plan_source(k))
      end do
    else
      tangent_values = values_full
    end if
  end subroutine reduce_tangent

  !> The coordinates e the full coordinate q(i) depends on (q = B e + q0): their number, the
  !> a-th of them and its coefficient.
  pure integer function row_terms(reduction, i)
    type(coordinate_reduction), intent(in) :: reduction
    integer, intent(in) :: i
    row_terms = 1
    if (reduction%active) row_terms = reduction%ptr(i + 1) - reduction%ptr(i)
  end function row_terms

  pure integer function reduced_col(reduction, i, a)
    type(coordinate_reduction), intent(in) :: reduction
    integer, intent(in) :: i, a
    reduced_col = i
    if (reduction%active) reduced_col = reduction%col(reduction%ptr(i) + a - 1)
  end function reduced_col

  pure real(dp) function reduced_coef(reduction, i, a)
    type(coordinate_reduction), intent(in) :: reduction
    integer, intent(in) :: i, a
    reduced_coef = 1.0_dp
    if (reduction%active) reduced_coef = reduction%values(reduction%ptr(i) + a - 1)
  end function reduced_coef

  !> The full coordinates q(dofs) at e.
  pure function full_at(reduction, e, dofs) result(q)
    type(coordinate_reduction), intent(in) :: reduction
    real(dp), intent(in) :: e(:)
    integer, intent(in) :: dofs(:)
    real(dp) :: q(size(dofs))
    integer :: p, a2
    do p = 1, size(dofs)
      if (.not. reduction%active) then
        q(p) = e(dofs(p))
      else
        q(p) = reduction%offset(dofs(p))
        do a2 = 1, row_terms(reduction, dofs(p))
          q(p) = q(p) + reduced_coef(reduction, dofs(p), a2) &
                        * e(reduced_col(reduction, dofs(p), a2))
        end do
      end if
    end do
  end function full_at

end module system_reduction
