!> The vectors the iteration matrix is carried with when the system turns (a component of
!> system_model; carried_rotation): the first full dof of each carried 3-vector, its weight
!> in the rotation fit, whether it is a position (fitted about the centroid) or a gradient
!> or director, its group (a body: each group is fitted its own rotation), and where their
!> components lie among the reduced coordinates.
!> The reduction may scale a full component (q_i = c e_j + q0_i: a joint the reduction
!> eliminated, e.g. a rod's end pinned to a crank's director) and share one reduced
!> coordinate among several full components. Each reduced coordinate is then turned with
!> the first carried vector (in the given order) that holds it with the same coefficient on
!> all of that vector's reduced components (its owner): the model layer lists the bodies
!> with stiffness first, whose turn the shared coordinate's stiff directions follow (a rigid
!> body's mass, kron(Mbar, I3), is turned exactly by any rotation). A reduced coordinate
!> without an owner is not turned. No I/O.
module system_carry
  use ancf_kinds, only: dp
  use system_reduction, only: coordinate_reduction
  implicit none
  private
  public :: carried_vectors, carry_setup, carry_enabled, carry_vectors, carry_apply, &
            plane_turn_rows

  type :: carried_vectors
    ! the first full dof of each carried 3-vector, its weight and whether it is a position;
    ! none: not carried
    integer, allocatable :: first(:)
    real(dp), allocatable :: weight(:)
    logical, allocatable :: position(:)
    ! the group of each carried vector (1 .. ngroups) and the number of groups
    integer, allocatable :: group(:)
    integer :: ngroups = 0
    ! the reduced coordinate each component of every full 3-vector turns (0: fixed by the
    ! reduction, or owned by another vector), (3, nfull / 3), and the group whose turn
    ! turns the full 3-vector, (nfull / 3)
    integer, allocatable :: map(:, :), map_group(:)
    ! the reduced coordinates without an owner (not turned)
    integer, allocatable :: unturned(:)
    ! when every 3-vector of map is a vector of the xy plane (its x and y reduced, z fixed)
    ! or wholly fixed: the reduced coordinates (x, y) of the plane vectors, (2, n), and
    ! their groups, (n); unallocated otherwise
    integer, allocatable :: plane(:, :), plane_group(:)
    ! where carry_vectors reads each component of the carried vectors, (3, nvec): the
    ! reduced coordinate (> 0) or minus the full dof whose reduction offset it is; with
    ! the reduction's coefficient (source > 0) and the full dof (3, nvec)
    integer, allocatable :: source(:, :), full(:, :)
    real(dp), allocatable :: coefficient(:, :)
  end type carried_vectors

contains

  !> The carried vectors (first full dof, weight, position or not, group 1 .. ; none: not
  !> carried) with their map on the reduced coordinates (the module's notes); info 2: a row
  !> of the reduction mixes coordinates (then nothing is carried).
  subroutine carry_setup(carry, reduction, ndof, nfull, first, weight, position, group, info)
    type(carried_vectors), intent(inout) :: carry
    type(coordinate_reduction), intent(in) :: reduction
    integer, intent(in) :: ndof, nfull, first(:), group(:)
    real(dp), intent(in) :: weight(:)
    logical, intent(in) :: position(:)
    integer, intent(out) :: info
    integer :: i, k, nvec, vec, b, component, column(3), owned(ndof)
    real(dp) :: coefficient(3), common
    logical :: uniform
    info = 0
    nvec = size(first)
    carry%first = first
    carry%weight = weight
    carry%position = position
    carry%group = group
    carry%ngroups = 0
    if (nvec > 0) carry%ngroups = maxval(group)
    if (allocated(carry%map)) deallocate (carry%map)
    if (allocated(carry%map_group)) deallocate (carry%map_group)
    if (allocated(carry%unturned)) deallocate (carry%unturned)
    if (allocated(carry%plane)) deallocate (carry%plane)
    if (allocated(carry%plane_group)) deallocate (carry%plane_group)
    if (allocated(carry%source)) deallocate (carry%source)
    if (allocated(carry%full)) deallocate (carry%full)
    if (allocated(carry%coefficient)) deallocate (carry%coefficient)
    if (nvec == 0) return
    allocate (carry%map(3, nfull / 3), carry%map_group(nfull / 3))
    carry%map_group = 1
    do vec = 1, nvec
      carry%map_group((first(vec) - 1) / 3 + 1) = group(vec)
    end do
    if (.not. reduction%active) then
      carry%map = reshape([(i, i = 1, nfull)], [3, nfull / 3])
      allocate (carry%unturned(0))
      call carry_sources()
      return
    end if
    if (any(reduction%ptr(2:) - reduction%ptr(:nfull) > 1)) then
      info = 2
      deallocate (carry%first, carry%weight, carry%position, carry%group, carry%map, &
                  carry%map_group)
      allocate (carry%first(0), carry%weight(0), carry%position(0), carry%group(0))
      carry%ngroups = 0
      return
    end if
    ! each reduced coordinate turns with its owner: the first carried vector holding it
    ! with one coefficient on all its reduced components (the module's notes)
    carry%map = 0
    owned = 0
    do vec = 1, nvec
      b = (first(vec) - 1) / 3 + 1
      call vector_columns(b, column, coefficient)
      uniform = .true.
      common = 0.0_dp
      do component = 1, 3
        if (column(component) == 0) cycle
        if (common == 0.0_dp) common = coefficient(component)
        uniform = uniform .and. coefficient(component) == common
      end do
      if (.not. uniform) cycle
      do component = 1, 3
        if (column(component) == 0) cycle
        if (owned(column(component)) /= 0) cycle
        owned(column(component)) = b
        carry%map(component, b) = column(component)
      end do
    end do
    carry%unturned = pack([(i, i = 1, ndof)], owned == 0)
    call carry_sources()
    ! every vector of the xy plane or fixed (a planar reduction): carry_apply by the pairs
    if (all((carry%map(1, :) > 0 .and. carry%map(2, :) > 0 .and. &
             carry%map(3, :) == 0) .or. all(carry%map == 0, dim=1)) .and. &
        size(carry%unturned) == 0) then
      k = count(carry%map(1, :) > 0)
      allocate (carry%plane(2, k), carry%plane_group(k))
      k = 0
      do i = 1, size(carry%map, 2)
        if (carry%map(1, i) == 0) cycle
        k = k + 1
        carry%plane(:, k) = carry%map(1:2, i)
        carry%plane_group(k) = carry%map_group(i)
      end do
    end if

  contains

    !> The reduced coordinate of each component of full 3-vector b (0: fixed) and the
    !> reduction's coefficient.
    subroutine vector_columns(b, column, coefficient)
      integer, intent(in) :: b
      integer, intent(out) :: column(3)
      real(dp), intent(out) :: coefficient(3)
      integer :: c, row
      do c = 1, 3
        row = 3 * (b - 1) + c
        column(c) = 0
        coefficient(c) = 0.0_dp
        if (reduction%ptr(row + 1) - reduction%ptr(row) /= 1) cycle
        if (reduction%values(reduction%ptr(row)) == 0.0_dp) cycle
        column(c) = reduction%col(reduction%ptr(row))
        coefficient(c) = reduction%values(reduction%ptr(row))
      end do
    end subroutine vector_columns

    !> carry%source, full and coefficient from first and the reduction.
    subroutine carry_sources()
      integer :: vec, component, b, row
      allocate (carry%source(3, nvec), carry%full(3, nvec), carry%coefficient(3, nvec))
      do vec = 1, nvec
        b = (carry%first(vec) - 1) / 3 + 1
        do component = 1, 3
          row = carry%first(vec) + component - 1
          carry%full(component, vec) = row
          carry%coefficient(component, vec) = 1.0_dp
          if (.not. reduction%active) then
            carry%source(component, vec) = row
          else if (reduction%ptr(row + 1) - reduction%ptr(row) == 1) then
            carry%source(component, vec) = reduction%col(reduction%ptr(row))
            carry%coefficient(component, vec) = reduction%values(reduction%ptr(row))
          else
            carry%source(component, vec) = -row
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
    ! (carry%source: the reduced coordinate or minus the fixed full dof, made once by
    ! carry_setup; a selected component (coefficient 1) is its reduced coordinate)
    do k = 1, size(carry%first)
      do i = 1, 3
        source = carry%source(i, k)
        if (source > 0) then
          if (carry%coefficient(i, k) == 1.0_dp) then
            vectors(i, k) = e(source)
          else  ! a component the reduction scales (an eliminated joint)
            vectors(i, k) = carry%coefficient(i, k) * e(source) + &
                            reduction%offset(carry%full(i, k))
          end if
        else  ! a coordinate the reduction fixes
          vectors(i, k) = reduction%offset(-source)
        end if
      end do
    end do
  end subroutine carry_vectors

  !> y = T_e x (back = .false.: from the factorization's axes to the current ones) or
  !> y = T_e^T x (.true.), T_e = B^T blockdiag(turn) B on the reduced coordinates: every full
  !> 3-vector turned by its group's turn (turn(:, :, group)), its fixed components (the
  !> reduction's) and those owned by another vector taken as zero (carry%map: the reduced
  !> coordinate each full component turns, 0 otherwise); the coordinates without an owner
  !> copied unturned.
  pure subroutine carry_apply(carry, turn, x, back, y)
    type(carried_vectors), intent(in) :: carry
    real(dp), intent(in) :: turn(:, :, :), x(:)
    logical, intent(in) :: back
    real(dp), intent(out) :: y(:)
    real(dp) :: rotation(3, 3), v(3), w(3), r11, r12, r13, r21, r22, r23
    integer :: b, i, first, second, g, current
    current = 0
    if (allocated(carry%plane)) then
      ! every vector of the xy plane (or fixed): the plane path below by the list of pairs
      do b = 1, size(carry%plane, 2)
        g = carry%plane_group(b)
        if (g /= current) then
          rotation = turn(:, :, g)
          if (back) rotation = transpose(turn(:, :, g))
          call plane_turn_rows(rotation, r11, r12, r13, r21, r22, r23)
          current = g
        end if
        first = carry%plane(1, b)
        second = carry%plane(2, b)
        v(1) = x(first)
        v(2) = x(second)
        y(first) = r11 * v(1) + r12 * v(2) + r13
        y(second) = r21 * v(1) + r22 * v(2) + r23
      end do
      return
    end if
    do i = 1, size(carry%unturned)
      y(carry%unturned(i)) = x(carry%unturned(i))
    end do
    do b = 1, size(carry%map, 2)
      g = carry%map_group(b)
      if (g /= current) then
        rotation = turn(:, :, g)
        if (back) rotation = transpose(turn(:, :, g))
        current = g
      end if
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

  !> The in-plane rows of a turn as carry_apply applies them to a plane vector (its third
  !> column times the vector's zero third component kept, so the sums are carry_apply's;
  !> the transposed turn gives carry_apply's back turn).
  pure subroutine plane_turn_rows(turn, r11, r12, r13, r21, r22, r23)
    real(dp), intent(in) :: turn(3, 3)
    real(dp), intent(out) :: r11, r12, r13, r21, r22, r23
    r11 = turn(1, 1)
    r12 = turn(1, 2)
    r13 = turn(1, 3) * 0.0_dp
    r21 = turn(2, 1)
    r22 = turn(2, 2)
    r23 = turn(2, 3) * 0.0_dp
  end subroutine plane_turn_rows

end module system_carry
