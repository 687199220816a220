!> The mass of a mechanical system (a component of system_model): the reduced mass M as CSR
!> (1-based), or kron(Mbar, I3) over whole 3-vectors, or kron(Mbar, I2) over a plane's (x, y)
!> pairs, and M as the model assembled it for the consistent acceleration's saddle system;
!> the products with M and the kinetic energy. No I/O.
module system_mass
  use ancf_kinds, only: dp
  use iso_fortran_env, only: int64
  implicit none
  private
  public :: mass_matrix, mass_product, kinetic_energy, csr_matvec, plane_mass_setup, &
            saddle_mass_entries, kron_band_setup

  type :: mass_matrix
    ! mass M (reduced, CSR, 1-based), used for M a and the kinetic energy; when M is
    ! kron(Mbar, I3) over whole 3-vectors (beams, plates and rigid bodies all are), the CSR
    ! of Mbar on the 3-vectors instead (a ninth of the entries)
    integer, allocatable :: row_ptr(:), col(:)
    real(dp), allocatable :: values(:)
    logical :: kron = .false.
    ! kron(Mbar, I3) by diagonals (kron_band_setup; unallocated otherwise): Mbar's diagonal
    ! d = -band_width..band_width at each coordinate of row i's 3-vector, band(3 (i-1) + c,
    ! d) = Mbar(i, i + d) (0 outside Mbar's entries and beyond the last vector)
    real(dp), allocatable :: band(:, :)
    integer :: band_width = 0
    ! M as the model assembled it (CSR, 1-based, its zero entries kept): the mass block of
    ! the consistent acceleration's saddle system (consistent_start)
    integer, allocatable :: saddle_ptr(:), saddle_col(:)
    real(dp), allocatable :: saddle_values(:)
    ! the CSR mass of a planar reduction as kron(Mbar, I2) over the plane's (x, y) pairs
    ! (plane_mass_setup; unallocated otherwise): Mbar's rows by pair, each entry's column the
    ! x coordinate of its pair (y: x + 1), and each pair's x coordinate
    integer, allocatable :: pair_ptr(:), pair_col(:), pair_row(:)
    real(dp), allocatable :: pair_values(:)
    ! the pairs' x coordinates are 1, 3, 5, .. in pair order (kinetic_energy's one pass)
    logical :: pairs_ordered = .false.
  end type mass_matrix

contains

  !> y = M x with the system's mass (CSR, or kron(Mbar, I3) with Mbar's CSR on 3-vectors).
  pure subroutine mass_product(mass, x, y)
    type(mass_matrix), intent(in) :: mass
    real(dp), intent(in) :: x(:)
    real(dp), intent(out) :: y(:)
    integer :: i, k, j
    real(dp) :: total(3), m
    if (allocated(mass%pair_ptr)) then
      ! kron(Mbar, I2) over the plane's pairs: each row's sums as csr_matvec takes them
      do i = 1, size(mass%pair_ptr) - 1
        total(1:2) = 0.0_dp
        do k = mass%pair_ptr(i), mass%pair_ptr(i + 1) - 1
          j = mass%pair_col(k)
          m = mass%pair_values(k)
          total(1) = total(1) + m * x(j)
          total(2) = total(2) + m * x(j + 1)
        end do
        j = mass%pair_row(i)
        y(j) = total(1)
        y(j + 1) = total(2)
      end do
      return
    end if
    if (.not. mass%kron) then
      call csr_matvec(mass%row_ptr, mass%col, mass%values, x, y)
      return
    end if
    if (allocated(mass%band)) then
      call band_product(mass%band, mass%band_width, x, y)
      return
    end if
    do i = 1, size(mass%row_ptr) - 1
      total = 0.0_dp
      do k = mass%row_ptr(i), mass%row_ptr(i + 1) - 1
        j = 3 * (mass%col(k) - 1)
        m = mass%values(k)
        total(1) = total(1) + m * x(j + 1)
        total(2) = total(2) + m * x(j + 2)
        total(3) = total(3) + m * x(j + 3)
      end do
      y(3 * i - 2:3 * i) = total
    end do
  end subroutine mass_product

  !> y = kron(Mbar, I3) x by Mbar's diagonals, each a contiguous pass the compiler
  !> vectorizes (the CSR rows' short loops with their column indices took ~20 instructions
  !> per entry: 23,000 per product on the 28-node FFR boom, two products per step). Each
  !> y(k) adds its products in the order of the diagonals, from 0: the CSR row's order
  !> (ascending columns, kron_band_setup's condition), the zeros of the band adding
  !> exactly nothing, so the sums are the CSR product's bit for bit.
  pure subroutine band_product(band, width, x, y)
    real(dp), intent(in) :: band(:, -width:), x(:)
    integer, intent(in) :: width
    real(dp), intent(out) :: y(:)
    integer :: d, k, n
    n = size(x)
    ! (the first diagonal starts the sums, 0 + its product as the CSR row adds it; the
    ! coordinates before its first row start at 0)
    do k = 1, min(n, 3 * width)
      y(k) = 0.0_dp
    end do
    do k = 1 + 3 * width, n
      y(k) = 0.0_dp + band(k, -width) * x(k - 3 * width)
    end do
    do d = 1 - width, width
      do k = max(1, 1 - 3 * d), min(n, n - 3 * d)
        y(k) = y(k) + band(k, d) * x(k + 3 * d)
      end do
    end do
  end subroutine band_product

  !> The diagonals of kron(Mbar, I3) (mass%band) when Mbar's rows list their columns in
  !> ascending order and its band holds at most twice its entries (a banded mass: beams,
  !> plates); otherwise none (the CSR products stay in use).
  pure subroutine kron_band_setup(mass)
    type(mass_matrix), intent(inout) :: mass
    integer :: nvec, i, k, width
    if (allocated(mass%band)) deallocate (mass%band)
    mass%band_width = 0
    if (.not. mass%kron) return
    nvec = size(mass%row_ptr) - 1
    width = 0
    do i = 1, nvec
      do k = mass%row_ptr(i), mass%row_ptr(i + 1) - 1
        if (k > mass%row_ptr(i)) then
          if (mass%col(k) <= mass%col(k - 1)) return
        end if
        width = max(width, abs(mass%col(k) - i))
      end do
    end do
    if ((2 * width + 1) * nvec > 2 * size(mass%col)) return
    allocate (mass%band(3 * nvec, -width:width))
    mass%band = 0.0_dp
    do i = 1, nvec
      do k = mass%row_ptr(i), mass%row_ptr(i + 1) - 1
        mass%band(3 * i - 2:3 * i, mass%col(k) - i) = mass%values(k)
      end do
    end do
    mass%band_width = width
  end subroutine kron_band_setup

  !> The mass product of a planar reduction by pairs (mass_pair_*): when every reduced
  !> coordinate is the x or y of a plane vector (carry_plane, y = x + 1) and the CSR mass's
  !> y row of each pair is its x row moved to the partner columns with the same values
  !> (bit for bit) in the same order, Mbar's rows by pair, so that mass_product takes the
  !> same sums with half the index work; otherwise nothing (the CSR stays in use).
  subroutine plane_mass_setup(mass, ndof, carry_plane)
    type(mass_matrix), intent(inout) :: mass
    integer, intent(in) :: ndof
    !> the reduced coordinates (x, y) of the plane vectors (carried_vectors%plane)
    integer, allocatable, intent(in) :: carry_plane(:, :)
    integer, allocatable :: pair_of(:)
    integer :: npair, p, k, row_x, row_y, kx, ky, count_x, nnz
    if (allocated(mass%pair_ptr)) deallocate (mass%pair_ptr, mass%pair_col, &
                                                  mass%pair_row, mass%pair_values)
    mass%pairs_ordered = .false.
    if (mass%kron .or. .not. allocated(carry_plane) .or. &
        .not. allocated(mass%row_ptr)) return
    npair = size(carry_plane, 2)
    if (2 * npair /= ndof .or. size(mass%row_ptr) /= ndof + 1) return
    allocate (pair_of(ndof))
    pair_of = 0
    do p = 1, npair
      row_x = carry_plane(1, p)
      if (carry_plane(2, p) /= row_x + 1) return
      if (pair_of(row_x) /= 0 .or. pair_of(row_x + 1) /= 0) return
      pair_of(row_x) = p
      pair_of(row_x + 1) = -p
    end do
    nnz = 0
    do p = 1, npair
      row_x = carry_plane(1, p)
      row_y = row_x + 1
      count_x = mass%row_ptr(row_x + 1) - mass%row_ptr(row_x)
      if (mass%row_ptr(row_y + 1) - mass%row_ptr(row_y) /= count_x) return
      do k = 0, count_x - 1
        kx = mass%row_ptr(row_x) + k
        ky = mass%row_ptr(row_y) + k
        if (pair_of(mass%col(kx)) <= 0 .or. mass%col(ky) /= mass%col(kx) + 1) return
        if (transfer(mass%values(kx), 1_int64) /= transfer(mass%values(ky), 1_int64)) &
          return
      end do
      nnz = nnz + count_x
    end do
    allocate (mass%pair_ptr(npair + 1), mass%pair_col(nnz), mass%pair_row(npair), &
              mass%pair_values(nnz))
    mass%pair_ptr(1) = 1
    do p = 1, npair
      row_x = carry_plane(1, p)
      mass%pair_row(p) = row_x
      count_x = mass%row_ptr(row_x + 1) - mass%row_ptr(row_x)
      kx = mass%row_ptr(row_x)
      mass%pair_col(mass%pair_ptr(p):mass%pair_ptr(p) + count_x - 1) = &
        mass%col(kx:kx + count_x - 1)
      mass%pair_values(mass%pair_ptr(p):mass%pair_ptr(p) + count_x - 1) = &
        mass%values(kx:kx + count_x - 1)
      mass%pair_ptr(p + 1) = mass%pair_ptr(p) + count_x
    end do
    mass%pairs_ordered = all(mass%pair_row == [(2 * p - 1, p = 1, npair)])
  end subroutine plane_mass_setup

  !> kinetic: the kinetic energy 1/2 e'^T M e' (M: mass_product's). With the plane's pairs in
  !> coordinate order, in one pass: each row's sums as mass_product takes them, and their
  !> products with e' summed in coordinate order from 0, as dot_product(v, M v) sums them
  !> (the same number, bit for bit, without M v in memory); otherwise by mass_product and
  !> dot_product (mv: work, ndof).
  pure subroutine kinetic_energy(mass, v, mv, kinetic)
    type(mass_matrix), intent(in) :: mass
    real(dp), intent(in) :: v(:)
    real(dp), intent(out) :: mv(:), kinetic
    integer :: i, k, j
    real(dp) :: total, total_x, total_y, m
    if (mass%pairs_ordered .and. allocated(mass%pair_ptr)) then
      total = 0.0_dp
      do i = 1, size(mass%pair_ptr) - 1
        total_x = 0.0_dp
        total_y = 0.0_dp
        do k = mass%pair_ptr(i), mass%pair_ptr(i + 1) - 1
          j = mass%pair_col(k)
          m = mass%pair_values(k)
          total_x = total_x + m * v(j)
          total_y = total_y + m * v(j + 1)
        end do
        total = total + v(2 * i - 1) * total_x
        total = total + v(2 * i) * total_y
      end do
      kinetic = 0.5_dp * total
      return
    end if
    call mass_product(mass, v, mv)
    kinetic = 0.5_dp * dot_product(v, mv)
  end subroutine kinetic_energy

  !> y = M x for a CSR matrix (1-based).
  pure subroutine csr_matvec(row_ptr, col, values, x, y)
    integer, intent(in) :: row_ptr(:), col(:)
    real(dp), intent(in) :: values(:), x(:)
    real(dp), intent(out) :: y(:)
    integer :: i, k
    real(dp) :: total
    do i = 1, size(row_ptr) - 1
      total = 0.0_dp
      do k = row_ptr(i), row_ptr(i + 1) - 1
        total = total + values(k) * x(col(k))
      end do
      y(i) = total
    end do
  end subroutine csr_matvec

  !> The saddle mass (M as the model assembled it) as coordinates: rows, columns and values
  !> of its entries in CSR order (size(saddle_col) of them).
  pure subroutine saddle_mass_entries(mass, rows, cols, entries)
    type(mass_matrix), intent(in) :: mass
    integer, intent(out) :: rows(:), cols(:)
    real(dp), intent(out) :: entries(:)
    integer :: row, k
    do row = 1, size(mass%saddle_ptr) - 1
      do k = mass%saddle_ptr(row), mass%saddle_ptr(row + 1) - 1
        rows(k) = row
        cols(k) = mass%saddle_col(k)
        entries(k) = mass%saddle_values(k)
      end do
    end do
  end subroutine saddle_mass_entries

end module system_mass
