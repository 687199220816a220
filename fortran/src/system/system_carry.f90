!> The vectors the iteration matrix is carried with when the system turns (a component of
!> system_model; carried_rotation): the first full dof of each carried 3-vector, its weight
!> in the rotation fit, whether it is a position (fitted about the centroid) or a gradient
!> or director, and where their components lie among the reduced coordinates. No I/O.
module system_carry
  use ancf_kinds, only: dp
  use system_reduction, only: coordinate_reduction
  implicit none
  private
  public :: carried_vectors, carry_setup, carry_enabled, carry_vectors, carry_apply

  type :: carried_vectors
    ! the first full dof of each carried 3-vector, its weight and whether it is a position;
    ! none: not carried
    integer, allocatable :: first(:)
    real(dp), allocatable :: weight(:)
    logical, allocatable :: position(:)
    ! the reduced coordinate of each component of every full 3-vector (0: fixed by the
    ! reduction), (3, nfull / 3)
    integer, allocatable :: map(:, :)
    ! when every 3-vector of map is a vector of the xy plane (its x and y reduced, z fixed)
    ! or wholly fixed: the reduced coordinates (x, y) of the plane vectors, (2, n);
    ! unallocated otherwise
    integer, allocatable :: plane(:, :)
    ! where carry_vectors reads each component of the carried vectors, (3, nvec): the
    ! reduced coordinate (> 0) or minus the full dof whose reduction offset it is
    integer, allocatable :: source(:, :)
  end type carried_vectors

contains

  !> The carried vectors (first full dof, weight, position or not; none: not carried) with
  !> their map on the reduced coordinates; info 2: the reduction is not a selection of
  !> coordinates (then nothing is carried).
  subroutine carry_setup(carry, reduction, ndof, nfull, first, weight, position, info)
    type(carried_vectors), intent(inout) :: carry
    type(coordinate_reduction), intent(in) :: reduction
    integer, intent(in) :: ndof, nfull, first(:)
    real(dp), intent(in) :: weight(:)
    logical, intent(in) :: position(:)
    integer, intent(out) :: info
    integer :: i, k, nvec
    info = 0
    nvec = size(first)
    carry%first = first
    carry%weight = weight
    carry%position = position
    if (allocated(carry%map)) deallocate (carry%map)
    if (allocated(carry%plane)) deallocate (carry%plane)
    if (allocated(carry%source)) deallocate (carry%source)
    if (nvec == 0) return
    allocate (carry%map(3, nfull / 3))
    if (.not. reduction%active) then
      carry%map = reshape([(i, i = 1, nfull)], [3, nfull / 3])
      call carry_sources()
      return
    end if
    carry%map = 0
    do i = 1, nfull  ! a selection: at most one unit entry per row of B
      k = reduction%ptr(i)
      if (reduction%ptr(i + 1) - k /= 1) cycle
      if (reduction%values(k) /= 1.0_dp) cycle
      carry%map(mod(i - 1, 3) + 1, (i - 1) / 3 + 1) = reduction%col(k)
    end do
    if (count(carry%map > 0) /= ndof .or. any(reduction%ptr(2:) - &
        reduction%ptr(:nfull) > 1)) then
      info = 2
      deallocate (carry%first, carry%weight, carry%position, carry%map)
      allocate (carry%first(0), carry%weight(0), carry%position(0))
      return
    end if
    call carry_sources()
    ! every vector of the xy plane or fixed (a planar reduction): carry_apply by the pairs
    if (all((carry%map(1, :) > 0 .and. carry%map(2, :) > 0 .and. &
             carry%map(3, :) == 0) .or. all(carry%map == 0, dim=1))) then
      k = count(carry%map(1, :) > 0)
      allocate (carry%plane(2, k))
      k = 0
      do i = 1, size(carry%map, 2)
        if (carry%map(1, i) == 0) cycle
        k = k + 1
        carry%plane(:, k) = carry%map(1:2, i)
      end do
    end if

  contains

    !> carry%source from first and map (carry_vectors' reads).
    subroutine carry_sources()
      integer :: vec, component, b
      allocate (carry%source(3, nvec))
      do vec = 1, nvec
        b = (carry%first(vec) - 1) / 3 + 1
        do component = 1, 3
          if (carry%map(component, b) > 0) then
            carry%source(component, vec) = carry%map(component, b)
          else
            carry%source(component, vec) = -(carry%first(vec) + component - 1)
          end if
        end do
      end do
    end subroutine carry_sources
  end subroutine carry_setup

  !> Whether the system carries its matrix (carried vectors were given).
  pure logical function carry_enabled(carry)
    type(carried_vectors), intent(in) :: carry
    carry_enabled = .false.
    if (allocated(carry%first)) carry_enabled = size(carry%first) > 0
  end function carry_enabled

  !> The carried 3-vectors (3, nvec) of the system at the reduced coordinates e.
  pure subroutine carry_vectors(carry, reduction, e, vectors)
    type(carried_vectors), intent(in) :: carry
    type(coordinate_reduction), intent(in) :: reduction
    real(dp), intent(in) :: e(:)
    real(dp), intent(out) :: vectors(:, :)
    integer :: k, i, source
    ! (carry_source: carry_map's reduced coordinate or minus the fixed full dof, made once
    ! by carry_setup)
    do k = 1, size(carry%first)
      do i = 1, 3
        source = carry%source(i, k)
        if (source > 0) then
          vectors(i, k) = e(source)
        else  ! a coordinate the reduction fixes
          vectors(i, k) = reduction%offset(-source)
        end if
      end do
    end do
  end subroutine carry_vectors

  !> y = T_e x (back = .false.: from the factorization's axes to the current ones) or
  !> y = T_e^T x (.true.), T_e = B^T blockdiag(turn) B on the reduced coordinates: every full
  !> 3-vector turned, its fixed components (the reduction's) taken as zero (carry_map: the
  !> reduced coordinate of each full component, 0 where fixed; B selects, so each reduced
  !> coordinate is one full component).
  pure subroutine carry_apply(carry, turn, x, back, y)
    type(carried_vectors), intent(in) :: carry
    real(dp), intent(in) :: turn(3, 3), x(:)
    logical, intent(in) :: back
    real(dp), intent(out) :: y(:)
    real(dp) :: rotation(3, 3), v(3), w(3), r11, r12, r13, r21, r22, r23
    integer :: b, i, first, second
    rotation = turn
    if (back) rotation = transpose(turn)
    if (allocated(carry%plane)) then
      ! every vector of the xy plane (or fixed): the plane path below by the list of pairs
      r11 = rotation(1, 1)
      r12 = rotation(1, 2)
      r13 = rotation(1, 3) * 0.0_dp
      r21 = rotation(2, 1)
      r22 = rotation(2, 2)
      r23 = rotation(2, 3) * 0.0_dp
      do b = 1, size(carry%plane, 2)
        first = carry%plane(1, b)
        second = carry%plane(2, b)
        v(1) = x(first)
        v(2) = x(second)
        y(first) = r11 * v(1) + r12 * v(2) + r13
        y(second) = r21 * v(1) + r22 * v(2) + r23
      end do
      return
    end if
    do b = 1, size(carry%map, 2)
      first = carry%map(1, b)
      second = carry%map(2, b)
      if (first > 0 .and. second > 0 .and. carry%map(3, b) == 0) then
        ! a vector of the xy plane (a planar reduction): the same sums with v(3) = 0,
        ! without the general path's branches
        v(1) = x(first)
        v(2) = x(second)
        y(first) = rotation(1, 1) * v(1) + rotation(1, 2) * v(2) + rotation(1, 3) * 0.0_dp
        y(second) = rotation(2, 1) * v(1) + rotation(2, 2) * v(2) + rotation(2, 3) * 0.0_dp
        cycle
      end if
      do i = 1, 3
        v(i) = 0.0_dp
        if (carry%map(i, b) > 0) v(i) = x(carry%map(i, b))
      end do
      w = rotation(:, 1) * v(1) + rotation(:, 2) * v(2) + rotation(:, 3) * v(3)
      do i = 1, 3
        if (carry%map(i, b) > 0) y(carry%map(i, b)) = w(i)
      end do
    end do
  end subroutine carry_apply

end module system_carry
