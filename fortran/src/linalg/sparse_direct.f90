!> Sparse direct solves behind integer handles: analyse a pattern once, factorize as often
!> as the values change, solve many right-hand sides per factorization, release cleanly.
!> Three kinds share the API: sequential MUMPS (any sparse matrix; it never prints, ICNTL
!> 1-4), LAPACK's banded Cholesky (dpbtrf/dpbtrs) for symmetric matrices with a narrow
!> band, such as a beam's iteration matrix, and LAPACK's banded LU with partial pivoting
!> (dgbtrf/dgbtrs) for unsymmetric ones, both of whose solves cost O(n kd) with none of
!> MUMPS's per-call overhead (every MUMPS call, a solve included, walks its whole structure
!> to estimate the memory a save would take: tens of microseconds). When the Cholesky finds
!> the matrix not positive definite (a tangent stiffness under compression), the same
!> handle falls back to the banded LU. solver_create_for picks the kind for every system a
!> model factorizes that is not for the banded Cholesky (the iteration matrix of an
!> unsymmetric or wide-banded model, the saddle-point systems of the static Newton and the
!> consistent start): the banded LU in the pattern's reverse Cuthill-McKee order
!> (graph_order's band_order; its callers keep the original numbering) when its
!> factorization costs at most banded_lu_flops (4 n kd^2), else MUMPS. An iteration
!> matrix (beta' M + ..., whose symmetric part the mass keeps positive definite: the
!> caller says so) that the banded LU would factorize takes the envelope LU without
!> pivoting instead (envelope_lu, in Sloan's profile order or the reverse Cuthill-McKee
!> one, whichever envelope is smaller), a tenth of the banded LU's work on the two-leaf
!> spring; a factorization that meets a pivot that is not positive falls back to the
!> pivoted banded LU of the same handle (counted: solver_fallbacks). The handle table is
!> the kernel's only module state.
!> info: 0 ok; 1 bad handle or no free slot; 2 call out of sequence (solve before
!> factorize, ...); 3 size mismatch; < 0 MUMPS INFOG(1) (-10: numerically singular),
!> with INFOG(2) in info_detail; the banded kind reports a non-positive-definite matrix
!> as -10 with the failing column in info_detail.
module sparse_direct
  use ancf_kinds, only: dp
  use graph_order, only: band_order, profile_order, envelope_entries
  use envelope_lu, only: envelope_layout, envelope_factorize, envelope_solve
  implicit none
  private
  include 'mpif.h'
  include 'dmumps_struc.h'
  public :: solver_create, solver_analyse, solver_factorize, solver_solve, &
            solver_destroy, solver_create_for, solver_kind, &
            solver_fallbacks, solver_envelope

  !> symmetry code that selects the banded LAPACK Cholesky
  integer, parameter, public :: banded_spd = 3
  !> symmetry code that selects the banded LAPACK LU (general matrices)
  integer, parameter, public :: banded_general = 4
  !> symmetry code that selects the envelope LU without pivoting (general matrices whose
  !> symmetric part is positive definite), the banded LU with pivoting its fallback
  integer, parameter, public :: envelope_general = 5
  !> the kinds solver_kind reports
  integer, parameter, public :: kind_mumps = 0, kind_banded_cholesky = 1, &
                                kind_banded_lu = 2, kind_envelope_lu = 3
  !> the banded LU replaces MUMPS when its factorization takes at most this many flops
  !> (4 n kd^2: kd rows below the diagonal times the 2 kd columns of U's band, per column):
  !> about a millisecond at the BLAS-3 rate, where MUMPS's fixed costs per call (some 50 us
  !> per solve, whatever the size: it estimates the memory a save would take on each call)
  !> outweigh its savings on fill. The two-leaf spring (n = 370, kd = 125): 0.58 against
  !> MUMPS's 0.86 ms per factorization and 18 against 67 us per solve
  real(dp), parameter, public :: banded_lu_flops = 5.0e7_dp

  type :: solver_slot
    type(dmumps_struc) :: id
    logical :: banded = .false.
    logical :: general = .false.     ! banded LU from the start (no Cholesky attempt)
    integer :: n = 0, bandwidth = 0
    ! rows and cols in the band's numbering; place(i): the band's unknown of unknown i
    ! (none: the same numbering)
    integer, allocatable :: rows(:), cols(:), pivots(:), place(:)
    real(dp), allocatable :: ordered(:, :)           ! right-hand sides in the band's numbering
    real(dp), allocatable :: band(:, :), general_band(:, :)
    ! the Cholesky factor's rows (lower(1 + m, i) = U(i, i + m), m = 0 .. kd: the band
    ! transposed), for the forward substitution by contiguous columns of U^T
    real(dp), allocatable :: lower(:, :)
    logical :: pivoted_lu = .false.
    ! the envelope LU (kind envelope_general): its order (env_place(i): the envelope's
    ! unknown of unknown i), layout (envelope_layout: first, ptr, the entries' positions)
    ! and factors; fallbacks: factorizations that fell back to the banded LU
    logical :: envelope = .false.
    integer, allocatable :: env_place(:), env_first(:), env_ptr(:), env_position(:)
    real(dp), allocatable :: env_factor(:)
    integer :: fallbacks = 0
    logical :: in_use = .false.
    logical :: analysed = .false.
    logical :: factorized = .false.
  end type solver_slot

  integer, parameter :: max_slots = 256
  type(solver_slot), target, save :: slots(max_slots)
  logical, save :: mpi_ready = .false.

contains

  !> Solves U^T U x = b for the banded Cholesky factor U in LAPACK's upper band storage
  !> (band(kd + 1 + i - j, j) = U(i, j)) and its rows (lower, the band transposed): the
  !> forward and backward substitutions written out over contiguous columns of U^T and U
  !> (the same arithmetic as dpbtrs, without its per-column BLAS calls, which dominated a
  !> narrow band's solve).
  pure subroutine cholesky_band_solve(n, kd, nrhs, band, lower, rhs)
    integer, intent(in) :: n, kd, nrhs
    real(dp), intent(in) :: band(kd + 1, n), lower(kd + 1, n)
    real(dp), intent(inout) :: rhs(n, nrhs)
    integer :: i, j, k, m, first, last
    real(dp) :: x
    do k = 1, nrhs
      ! U^T y = b by the columns of U^T (the rows of U, contiguous in lower): each rhs(j)
      ! loses U(i, j) y(i) for i = j - kd .. j - 1 in increasing i, then is divided by
      ! U(j, j), the sums of the dot-product form, in array operations the compiler vectorizes
      ! (scalar loops: a band of a few entries is shorter than the vector code's set-up;
      ! both sweeps as running sums in a register, each rhs(j) losing its terms in the
      ! order of the column forms: U^T y = b in increasing i, U x = y in decreasing j)
      do j = 1, n  ! U^T y = b
        first = max(1, j - kd)
        x = rhs(j, k)
        !GCC$ novector
        !GCC$ unroll 4
        do i = first, j - 1
          x = x - band(kd + 1 - j + i, j) * rhs(i, k)
        end do
        rhs(j, k) = x / band(kd + 1, j)
      end do
      do i = n, 1, -1  ! U x = y: x(i) loses U(i, j) x(j) for j = i + kd .. i + 1
        last = min(kd, n - i)
        x = rhs(i, k)
        !GCC$ novector
        !GCC$ unroll 4
        do m = last, 1, -1
          x = x - rhs(i + m, k) * lower(1 + m, i)
        end do
        rhs(i, k) = x / lower(1, i)
      end do
    end do
  end subroutine cholesky_band_solve

  !> Solves P L U x = b for dgbtrf's factors (kl = ku = kd: the multipliers in rows
  !> 2 kd + 2 .. 3 kd + 1 of ab, U in rows 1 .. 2 kd + 1) in place: dgbtrs's arithmetic by
  !> columns (row interchange and axpy of the multipliers, then U x = y by columns) written
  !> out, without its per-column BLAS calls (dger, and dtbsv's daxpy per column: their call
  !> overhead was most of a 370-unknown solve).
  pure subroutine lu_band_solve(n, kd, nrhs, ab, pivots, rhs)
    integer, intent(in) :: n, kd, nrhs, pivots(n)
    real(dp), intent(in) :: ab(3 * kd + 1, n)
    real(dp), intent(inout) :: rhs(n, nrhs)
    integer :: i, j, k, l
    real(dp) :: x
    do k = 1, nrhs
      do j = 1, n - 1  ! L y = P b
        l = pivots(j)
        x = rhs(l, k)
        if (l /= j) then
          rhs(l, k) = rhs(j, k)
          rhs(j, k) = x
        end if
        do i = 1, min(kd, n - j)
          rhs(j + i, k) = rhs(j + i, k) - x * ab(2 * kd + 1 + i, j)
        end do
      end do
      do j = n, 1, -1  ! U x = y
        x = rhs(j, k) / ab(2 * kd + 1, j)
        rhs(j, k) = x
        do i = max(1, j - 2 * kd), j - 1
          rhs(i, k) = rhs(i, k) - x * ab(2 * kd + 1 + i - j, j)
        end do
      end do
    end do
  end subroutine lu_band_solve

  !> A solver for the n x n pattern (rows, cols: 1-based coordinates, duplicates allowed),
  !> analysed, of the kind the cost rule picks: LAPACK's banded LU in the reverse
  !> Cuthill-McKee order of the pattern's symmetric closure (band_order) when
  !> 4 n kd^2 <= banded_lu_flops, else MUMPS (general). positive (optional, default
  !> .false.): every matrix to factorize has a positive definite symmetric part (an
  !> iteration matrix beta' M + ...): the envelope LU instead of the banded LU, in whichever
  !> of Sloan's and the reverse Cuthill-McKee order has the smaller envelope, with the
  !> banded LU as its fallback. width: kd in the reverse Cuthill-McKee order (whichever
  !> kind was chosen). info as solver_create and solver_analyse (3: an entry outside
  !> 1..n); on failure no handle is left behind (handle 0).
  subroutine solver_create_for(n, nnz, rows, cols, handle, width, info, info_detail, positive)
    integer, intent(in) :: n, nnz, rows(nnz), cols(nnz)
    integer, intent(out) :: handle, width, info, info_detail
    logical, intent(in), optional :: positive
    integer, allocatable :: place(:), profile(:)
    integer :: ignored
    logical :: envelope
    allocate (place(n))
    handle = 0
    width = 0
    info_detail = 0
    info = 3
    if (any(rows < 1) .or. any(rows > n) .or. any(cols < 1) .or. any(cols > n)) return
    envelope = .false.
    if (present(positive)) envelope = positive
    call band_order(n, nnz, rows, cols, place, width)
    if (4.0_dp * real(n, dp) * real(width, dp)**2 <= banded_lu_flops .and. envelope) then
      allocate (profile(n))
      call profile_order(n, nnz, rows, cols, profile)
      if (envelope_entries(n, nnz, rows, cols, place) &
          < envelope_entries(n, nnz, rows, cols, profile)) profile = place
      call solver_create(envelope_general, handle, info, info_detail)
      if (info == 0) call solver_order(handle, n, place, info)
      if (info == 0) slots(handle)%env_place = profile
    else if (4.0_dp * real(n, dp) * real(width, dp)**2 <= banded_lu_flops) then
      call solver_create(banded_general, handle, info, info_detail)
      if (info == 0) call solver_order(handle, n, place, info)
    else
      call solver_create(0, handle, info, info_detail)
    end if
    if (info == 0) call solver_analyse(handle, n, nnz, rows, cols, info, info_detail)
    if (info /= 0 .and. handle /= 0) then
      call solver_destroy(handle, ignored)
      handle = 0
    end if
  end subroutine solver_create_for

  !> New solver; symmetry 0 = general, 2 = symmetric (give one triangle only),
  !> 3 = symmetric positive definite, banded LAPACK Cholesky (give both triangles or one),
  !> 4 = general, banded LAPACK LU (give every entry), 5 = general with a positive definite
  !> symmetric part, envelope LU (give every entry; its order from solver_create_for,
  !> else the natural one).
  subroutine solver_create(symmetry, handle, info, info_detail)
    integer, intent(in) :: symmetry
    integer, intent(out) :: handle, info, info_detail
    integer :: h, ierr
    handle = 0
    info_detail = 0
    info = 1
    if (symmetry < 0 .or. symmetry > 5) return
    if (symmetry == banded_spd .or. symmetry == banded_general .or. &
        symmetry == envelope_general) then
      do h = 1, max_slots
        if (.not. slots(h)%in_use) then
          slots(h)%in_use = .true.
          slots(h)%banded = .true.
          slots(h)%general = symmetry == banded_general .or. symmetry == envelope_general
          slots(h)%envelope = symmetry == envelope_general
          slots(h)%fallbacks = 0
          slots(h)%analysed = .false.
          slots(h)%factorized = .false.
          handle = h
          info = 0
          return
        end if
      end do
      return
    end if
    if (.not. mpi_ready) then
      call mpi_init(ierr)
      mpi_ready = .true.
    end if
    do h = 1, max_slots
      if (.not. slots(h)%in_use) then
        slots(h)%id%comm = mpi_comm_world
        slots(h)%id%par = 1
        slots(h)%id%sym = symmetry
        slots(h)%id%job = -1
        call dmumps(slots(h)%id)
        if (slots(h)%id%infog(1) < 0) then
          info = slots(h)%id%infog(1)
          info_detail = slots(h)%id%infog(2)
          return
        end if
        call silence(slots(h)%id)
        slots(h)%in_use = .true.
        slots(h)%banded = .false.
        slots(h)%analysed = .false.
        slots(h)%factorized = .false.
        nullify (slots(h)%id%irn, slots(h)%id%jcn, slots(h)%id%a, slots(h)%id%rhs)
        handle = h
        info = 0
        return
      end if
    end do
  end subroutine solver_create

  !> The banded kinds' ordering of the n unknowns, before solver_analyse: place(i) is the
  !> position of unknown i in the band (a permutation of 1..n). info 1: bad handle or a
  !> MUMPS handle; 3: not a permutation.
  subroutine solver_order(handle, n, place, info)
    integer, intent(in) :: handle, n, place(n)
    integer, intent(out) :: info
    logical :: seen(n)
    integer :: i
    info = 1
    if (.not. valid(handle)) return
    if (.not. slots(handle)%banded) return
    info = 3
    if (any(place < 1) .or. any(place > n)) return
    seen = .false.
    do i = 1, n
      if (seen(place(i))) return
      seen(place(i)) = .true.
    end do
    slots(handle)%place = place
    slots(handle)%analysed = .false.
    slots(handle)%factorized = .false.
    info = 0
  end subroutine solver_order

  !> Symbolic analysis of the n x n pattern given by 1-based coordinates (rows, cols).
  subroutine solver_analyse(handle, n, nnz, rows, cols, info, info_detail)
    integer, intent(in) :: handle, n, nnz, rows(nnz), cols(nnz)
    integer, intent(out) :: info, info_detail
    info_detail = 0
    if (.not. valid(handle)) then
      info = 1
      return
    end if
    if (any(rows < 1) .or. any(rows > n) .or. any(cols < 1) .or. any(cols > n)) then
      info = 3
      return
    end if
    if (slots(handle)%banded) then
      info = 0
      if (allocated(slots(handle)%place)) then
        if (size(slots(handle)%place) /= n) then
          info = 3
          return
        end if
        slots(handle)%rows = slots(handle)%place(rows)
        slots(handle)%cols = slots(handle)%place(cols)
      else
        slots(handle)%rows = rows
        slots(handle)%cols = cols
      end if
      slots(handle)%n = n
      slots(handle)%bandwidth = maxval(abs(slots(handle)%rows - slots(handle)%cols))
      if (allocated(slots(handle)%band)) deallocate (slots(handle)%band)
      if (.not. slots(handle)%general) allocate (slots(handle)%band(slots(handle)%bandwidth + 1, n))
      ! (the LU's band is sized by its first factorization)
      if (allocated(slots(handle)%general_band)) &
        deallocate (slots(handle)%general_band, slots(handle)%pivots)
      if (slots(handle)%envelope) call envelope_analyse(slots(handle), nnz, rows, cols, info)
      if (info /= 0) return
      slots(handle)%analysed = .true.
      slots(handle)%factorized = .false.
      info = 0
      return
    end if
    associate (id => slots(handle)%id)
      call release_arrays(id)
      allocate (id%irn(nnz), id%jcn(nnz), id%a(nnz))
      id%irn = rows
      id%jcn = cols
      id%a = 0.0_dp
      id%n = n
      id%nnz = int(nnz, kind(id%nnz))
      id%job = 1
      call dmumps(id)
      info = min(id%infog(1), 0)
      info_detail = id%infog(2)
    end associate
    slots(handle)%analysed = info == 0
    slots(handle)%factorized = .false.
  end subroutine solver_analyse

  !> Numerical factorization with new values on the analysed pattern. Retries with
  !> more workspace when MUMPS asks for it.
  subroutine solver_factorize(handle, nnz, values, info, info_detail)
    integer, intent(in) :: handle, nnz
    real(dp), intent(in) :: values(nnz)
    integer, intent(out) :: info, info_detail
    integer :: attempt
    info_detail = 0
    if (.not. valid(handle)) then
      info = 1
      return
    end if
    if (.not. slots(handle)%analysed) then
      info = 2
      return
    end if
    if (slots(handle)%banded) then
      call banded_factorize(slots(handle), nnz, values, info, info_detail)
      slots(handle)%factorized = info == 0
      return
    end if
    associate (id => slots(handle)%id)
      if (size(id%a) /= nnz) then
        info = 3
        return
      end if
      id%a = values
      do attempt = 1, 4
        id%job = 2
        call dmumps(id)
        if (id%infog(1) /= -8 .and. id%infog(1) /= -9 .and. id%infog(1) /= -14 &
            .and. id%infog(1) /= -15 .and. id%infog(1) /= -17) exit
        id%icntl(14) = 2 * max(id%icntl(14), 20)
      end do
      info = min(id%infog(1), 0)
      info_detail = id%infog(2)
    end associate
    slots(handle)%factorized = info == 0
  end subroutine solver_factorize

  !> Solves for nrhs right-hand sides in place (rhs is n x nrhs).
  subroutine solver_solve(handle, n, nrhs, rhs, info, info_detail)
    integer, intent(in) :: handle, n, nrhs
    real(dp), intent(inout), target :: rhs(n, nrhs)
    integer, intent(out) :: info, info_detail
    real(dp), pointer :: flat(:)
    real(dp), allocatable :: ordered(:, :)
    info_detail = 0
    if (.not. valid(handle)) then
      info = 1
      return
    end if
    if (.not. slots(handle)%factorized) then
      info = 2
      return
    end if
    if (slots(handle)%banded) then
      if (slots(handle)%n /= n) then
        info = 3
        return
      end if
      associate (slot => slots(handle))
        if (slot%envelope .and. .not. slot%pivoted_lu) then
          if (allocated(slot%ordered)) then
            if (size(slot%ordered, 2) /= nrhs) deallocate (slot%ordered)
          end if
          if (.not. allocated(slot%ordered)) allocate (slot%ordered(n, nrhs))
          call move_alloc(slot%ordered, ordered)  ! (the factors stay read-only)
          ordered(slot%env_place, :) = rhs
          call envelope_solve(n, slot%env_first, slot%env_ptr, slot%env_factor, nrhs, ordered)
          rhs = ordered(slot%env_place, :)
          call move_alloc(ordered, slot%ordered)
        else if (allocated(slot%place)) then
          if (allocated(slot%ordered)) then
            if (size(slot%ordered, 2) /= nrhs) deallocate (slot%ordered)
          end if
          if (.not. allocated(slot%ordered)) allocate (slot%ordered(n, nrhs))
          call move_alloc(slot%ordered, ordered)  ! (the factors stay read-only)
          ordered(slot%place, :) = rhs
          call banded_solve(slot, nrhs, ordered)
          rhs = ordered(slot%place, :)
          call move_alloc(ordered, slot%ordered)
        else
          call banded_solve(slot, nrhs, rhs)
        end if
      end associate
      info = 0
      return
    end if
    associate (id => slots(handle)%id)
      if (id%n /= n) then
        info = 3
        return
      end if
      allocate (flat(n * nrhs))
      flat = reshape(rhs, [n * nrhs])
      id%rhs => flat
      id%nrhs = nrhs
      id%lrhs = n
      id%job = 3
      call dmumps(id)
      info = min(id%infog(1), 0)
      info_detail = id%infog(2)
      if (info == 0) rhs = reshape(flat, [n, nrhs])
      nullify (id%rhs)
      deallocate (flat)
    end associate
  end subroutine solver_solve

  !> Releases the solver and its handle.
  subroutine solver_destroy(handle, info)
    integer, intent(in) :: handle
    integer, intent(out) :: info
    if (.not. valid(handle)) then
      info = 1
      return
    end if
    if (slots(handle)%banded) then
      if (allocated(slots(handle)%band)) deallocate (slots(handle)%band)
      if (allocated(slots(handle)%general_band)) deallocate (slots(handle)%general_band)
      if (allocated(slots(handle)%lower)) deallocate (slots(handle)%lower)
      if (allocated(slots(handle)%pivots)) deallocate (slots(handle)%pivots)
      if (allocated(slots(handle)%rows)) deallocate (slots(handle)%rows, slots(handle)%cols)
      if (allocated(slots(handle)%place)) deallocate (slots(handle)%place)
      if (allocated(slots(handle)%ordered)) deallocate (slots(handle)%ordered)
      if (allocated(slots(handle)%env_place)) deallocate (slots(handle)%env_place)
      if (allocated(slots(handle)%env_first)) &
        deallocate (slots(handle)%env_first, slots(handle)%env_ptr, slots(handle)%env_position, &
                    slots(handle)%env_factor)
      slots(handle)%envelope = .false.
      slots(handle)%in_use = .false.
      slots(handle)%analysed = .false.
      slots(handle)%factorized = .false.
      info = 0
      return
    end if
    associate (id => slots(handle)%id)
      id%job = -2
      call dmumps(id)
      info = min(id%infog(1), 0)
      call release_arrays(id)
    end associate
    slots(handle)%in_use = .false.
    slots(handle)%analysed = .false.
    slots(handle)%factorized = .false.
  end subroutine solver_destroy

  !> Solves with the banded factors for nrhs right-hand sides in the band's numbering.
  pure subroutine banded_solve(slot, nrhs, rhs)
    type(solver_slot), intent(in) :: slot
    integer, intent(in) :: nrhs
    real(dp), intent(inout) :: rhs(slot%n, nrhs)
    if (slot%pivoted_lu) then
      call lu_band_solve(slot%n, slot%bandwidth, nrhs, slot%general_band, slot%pivots, rhs)
    else
      call cholesky_band_solve(slot%n, slot%bandwidth, nrhs, slot%band, slot%lower, rhs)
    end if
  end subroutine banded_solve

  !> Banded Cholesky of the upper triangle (entries below the diagonal are ignored, so
  !> both triangles or the upper one may be given; duplicates are summed). A matrix that
  !> is not positive definite, or any matrix of the general kind, is factorized by the
  !> pivoted banded LU instead, which needs both triangles; info = -10 only when that
  !> fails (singular).
  subroutine banded_factorize(slot, nnz, values, info, info_detail)
    type(solver_slot), intent(inout) :: slot
    integer, intent(in) :: nnz
    real(dp), intent(in) :: values(nnz)
    integer, intent(out) :: info, info_detail
    integer :: k, kd, row_in_band, j
    info_detail = 0
    if (size(slot%rows) /= nnz) then
      info = 3
      return
    end if
    kd = slot%bandwidth
    info = 0
    if (slot%envelope) then
      slot%env_factor = 0.0_dp
      do k = 1, nnz
        slot%env_factor(slot%env_position(k)) = slot%env_factor(slot%env_position(k)) + values(k)
      end do
      call envelope_factorize(slot%n, slot%env_first, slot%env_ptr, slot%env_factor, info, &
                              info_detail)
      slot%pivoted_lu = info /= 0
      if (.not. slot%pivoted_lu) return
      ! a pivot that is not positive: the pivoted banded LU of the same matrix
      slot%fallbacks = slot%fallbacks + 1
      info = 0
      info_detail = 0
    end if
    slot%pivoted_lu = slot%general
    if (slot%general) then
      call banded_lu(slot, nnz, values, info, info_detail)
      return
    end if
    slot%band = 0.0_dp
    do k = 1, nnz
      if (slot%rows(k) <= slot%cols(k)) slot%band(kd + 1 + slot%rows(k) - slot%cols(k), slot%cols(k)) = &
        slot%band(kd + 1 + slot%rows(k) - slot%cols(k), slot%cols(k)) + values(k)
    end do
    call dpbtrf('U', slot%n, kd, slot%band, kd + 1, info_detail)
    slot%pivoted_lu = info_detail /= 0
    if (.not. slot%pivoted_lu) then
      if (allocated(slot%lower)) then
        if (size(slot%lower, 1) /= kd + 1 .or. size(slot%lower, 2) /= slot%n) &
          deallocate (slot%lower)
      end if
      if (.not. allocated(slot%lower)) allocate (slot%lower(kd + 1, slot%n))
      slot%lower = 0.0_dp
      do j = 1, slot%n
        do k = 0, min(kd, slot%n - j)
          slot%lower(1 + k, j) = slot%band(kd + 1 - k, j + k)
        end do
      end do
      return
    end if
    ! not positive definite: the banded LU
    call banded_lu(slot, nnz, values, info, info_detail)
  end subroutine banded_factorize

  !> Banded LU with partial pivoting (general band storage, kl = ku = kd, with room for the
  !> fill-in) of every given entry (duplicates summed); info = -10 when singular.
  subroutine banded_lu(slot, nnz, values, info, info_detail)
    type(solver_slot), intent(inout) :: slot
    integer, intent(in) :: nnz
    real(dp), intent(in) :: values(nnz)
    integer, intent(out) :: info, info_detail
    integer :: k, kd, row_in_band
    kd = slot%bandwidth
    info = 0
    if (.not. allocated(slot%general_band)) then
      allocate (slot%general_band(3 * kd + 1, slot%n), slot%pivots(slot%n))
    end if
    slot%general_band = 0.0_dp
    do k = 1, nnz
      row_in_band = 2 * kd + 1 + slot%rows(k) - slot%cols(k)
      slot%general_band(row_in_band, slot%cols(k)) = slot%general_band(row_in_band, slot%cols(k)) &
                                                     + values(k)
    end do
    call dgbtrf(slot%n, slot%n, kd, kd, slot%general_band, 3 * kd + 1, slot%pivots, info_detail)
    if (info_detail /= 0) info = -10
  end subroutine banded_lu

  !> The envelope LU's layout of the pattern (rows, cols: the caller's numbering) in the
  !> slot's envelope order (env_place; none: the natural one), and its factor's storage.
  !> info 3: the order is not of size n.
  subroutine envelope_analyse(slot, nnz, rows, cols, info)
    type(solver_slot), intent(inout) :: slot
    integer, intent(in) :: nnz, rows(nnz), cols(nnz)
    integer, intent(out) :: info
    integer :: i, m
    info = 3
    if (.not. allocated(slot%env_place)) slot%env_place = [(i, i = 1, slot%n)]
    if (size(slot%env_place) /= slot%n) return
    if (allocated(slot%env_first)) &
      deallocate (slot%env_first, slot%env_ptr, slot%env_position, slot%env_factor)
    allocate (slot%env_first(slot%n), slot%env_ptr(slot%n + 1), slot%env_position(nnz))
    call envelope_layout(slot%n, nnz, slot%env_place(rows), slot%env_place(cols), &
                         slot%env_first, slot%env_ptr, slot%env_position)
    m = slot%env_ptr(slot%n + 1) - 1
    allocate (slot%env_factor(2 * m + slot%n))
    info = 0
  end subroutine envelope_analyse

  !> The kind of handle's solver (kind_mumps, kind_banded_cholesky, kind_banded_lu,
  !> kind_envelope_lu); -1 for a bad handle.
  integer function solver_kind(handle)
    integer, intent(in) :: handle
    solver_kind = -1
    if (.not. valid(handle)) return
    if (.not. slots(handle)%banded) then
      solver_kind = kind_mumps
    else if (slots(handle)%envelope) then
      solver_kind = kind_envelope_lu
    else if (slots(handle)%general) then
      solver_kind = kind_banded_lu
    else
      solver_kind = kind_banded_cholesky
    end if
  end function solver_kind

  !> The factorizations of an envelope LU handle that fell back to the pivoted banded LU
  !> (a pivot not positive); 0 for other kinds and bad handles.
  integer function solver_fallbacks(handle)
    integer, intent(in) :: handle
    solver_fallbacks = 0
    if (valid(handle)) solver_fallbacks = slots(handle)%fallbacks
  end function solver_fallbacks

  !> The entries below the diagonal of an envelope LU handle's envelope (its L's, as many
  !> in U), in the order it chose; 0 for other kinds, bad handles and before analysis.
  integer function solver_envelope(handle)
    integer, intent(in) :: handle
    solver_envelope = 0
    if (.not. valid(handle)) return
    if (.not. allocated(slots(handle)%env_ptr)) return
    solver_envelope = slots(handle)%env_ptr(slots(handle)%n + 1) - 1
  end function solver_envelope

  logical function valid(handle)
    integer, intent(in) :: handle
    valid = .false.
    if (handle >= 1 .and. handle <= max_slots) valid = slots(handle)%in_use
  end function valid

  subroutine silence(id)
    type(dmumps_struc), intent(inout) :: id
    id%icntl(1) = -1
    id%icntl(2) = -1
    id%icntl(3) = -1
    id%icntl(4) = 0
  end subroutine silence

  subroutine release_arrays(id)
    type(dmumps_struc), intent(inout) :: id
    if (associated(id%irn)) deallocate (id%irn)
    if (associated(id%jcn)) deallocate (id%jcn)
    if (associated(id%a)) deallocate (id%a)
  end subroutine release_arrays

end module sparse_direct
