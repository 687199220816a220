!> Envelope (profile, skyline) LU factorization A = L U without pivoting, for a matrix with a
!> structurally symmetric pattern (the entries' symmetric closure) whose symmetric part is
!> positive definite, such as the iteration matrix beta' M + K + c_v C of a dynamic step:
!> contact and friction make it unsymmetric, the mass keeps every pivot positive (a matrix
!> whose symmetric part is positive definite has positive leading principal minors, and
!> its pivots are their ratios). L (unit diagonal) and U fill only the envelope: row i of L
!> and column i of U from first(i), the pattern's first column in row i (or row in column
!> i), to i - 1, which a profile-reducing order of the unknowns keeps small
!> (graph_order's profile_order). Its cost against the banded LU of the same matrix: the
!> two-leaf spring (n = 370) factorizes in about 1.2 M multiply-adds in Sloan's order,
!> against 11.6 M for LAPACK's dgbtrf in reverse Cuthill-McKee order (kd = 125), and
!> solves in 43 k against 139 k.
!>
!> Storage (envelope_layout): factor(1 : m) holds L's rows, row i at ptr(i) .. ptr(i + 1)
!> - 1 for columns first(i) .. i - 1; factor(m + 1 : 2 m) U's columns likewise (column i,
!> rows first(i) .. i - 1); factor(2 m + 1 : 2 m + n) U's diagonal; m = ptr(n + 1) - 1.
!> Every product is a dot product of contiguous segments (Crout's order: row i of L and
!> column i of U from the rows and columns before them), summed in four interleaved
!> partial sums (vector lanes: no reassociation by the compiler is needed).
!> No I/O; errors are returned as codes.
module envelope_lu
  use ancf_kinds, only: dp
  implicit none
  private
  public :: envelope_layout, envelope_factorize, envelope_solve, envelope_multiply_adds

contains

  !> The envelope of the n x n pattern (rows, cols: 1-based, in the envelope's numbering;
  !> duplicates allowed): first(i) = min(i, the least column of row i, the least row of
  !> column i), ptr (n + 1) the segments' starts (m = ptr(n + 1) - 1 entries per
  !> triangle) and position(k), the place of entry k in factor (size 2 m + n).
  pure subroutine envelope_layout(n, nnz, rows, cols, first, ptr, position)
    integer, intent(in) :: n, nnz, rows(nnz), cols(nnz)
    integer, intent(out) :: first(n), ptr(n + 1), position(nnz)
    integer :: i, k, r, c, m
    do i = 1, n
      first(i) = i
    end do
    do k = 1, nnz
      r = rows(k)
      c = cols(k)
      if (c < r) then
        first(r) = min(first(r), c)
      else if (r < c) then
        first(c) = min(first(c), r)
      end if
    end do
    ptr(1) = 1
    do i = 1, n
      ptr(i + 1) = ptr(i) + i - first(i)
    end do
    m = ptr(n + 1) - 1
    do k = 1, nnz
      r = rows(k)
      c = cols(k)
      if (c < r) then
        position(k) = ptr(r) + c - first(r)
      else if (r < c) then
        position(k) = m + ptr(c) + r - first(c)
      else
        position(k) = 2 * m + r
      end if
    end do
  end subroutine envelope_layout

  !> Multiply-adds of envelope_factorize on the envelope first (n): per row i and column
  !> j in first(i) .. i - 1, two dot products of j - max(first(i), first(j)) terms, and
  !> the pivot's i - first(i). (The cost rule's estimate; exact for the loops below.)
  pure real(dp) function envelope_multiply_adds(n, first) result(total)
    integer, intent(in) :: n, first(n)
    integer :: i, j
    total = 0.0_dp
    do i = 1, n
      do j = first(i), i - 1
        total = total + 2.0_dp * real(j - max(first(i), first(j)), dp)
      end do
      total = total + real(i - first(i), dp)
    end do
  end function envelope_multiply_adds

  !> L U = A in place: factor holds A's entries in the layout of envelope_layout (zeros
  !> elsewhere in the envelope) and returns L below, U above and on the diagonal. Crout's
  !> order, row and column i from those before them:
  !>   L(i, j) = (A(i, j) - L(i, k0:j-1) . U(k0:j-1, j)) / U(j, j),
  !>   U(j, i) =  A(j, i) - L(j, k0:j-1) . U(k0:j-1, i),   k0 = max(first(i), first(j)),
  !>   U(i, i) =  A(i, i) - L(i, first(i):i-1) . U(first(i):i-1, i).
  !> info = -10 with detail = i when the pivot U(i, i) is not positive and finite (the
  !> symmetric part is not positive definite, or the matrix is singular: the caller
  !> factorizes it with pivoting instead); 0 otherwise.
  pure subroutine envelope_factorize(n, first, ptr, factor, info, detail)
    integer, intent(in) :: n, first(n), ptr(n + 1)
    real(dp), intent(inout), contiguous :: factor(:)
    integer, intent(out) :: info, detail
    integer :: i, j, fi, fj, pi, pj, k0, m, length
    real(dp) :: lij, pivot
    info = 0
    detail = 0
    m = ptr(n + 1) - 1
    do i = 1, n
      fi = first(i)
      pi = ptr(i)
      do j = fi, i - 1
        fj = first(j)
        pj = ptr(j)
        k0 = max(fi, fj)
        length = j - k0
        lij = factor(pi + j - fi) &
              - dot(length, factor(pi + k0 - fi:), factor(m + pj + k0 - fj:))
        factor(m + pi + j - fi) = factor(m + pi + j - fi) &
                                  - dot(length, factor(pj + k0 - fj:), factor(m + pi + k0 - fi:))
        factor(pi + j - fi) = lij / factor(2 * m + j)
      end do
      pivot = factor(2 * m + i) - dot(i - fi, factor(pi:), factor(m + pi:))
      if (.not. (pivot > 0.0_dp .and. pivot <= huge(1.0_dp))) then
        info = -10
        detail = i
        return
      end if
      factor(2 * m + i) = pivot
    end do
  end subroutine envelope_factorize

  !> Solves L U x = b for nrhs right-hand sides in place (rhs: n x nrhs, the envelope's
  !> numbering): L y = b by L's rows (dot products), U x = y by U's columns (each x(j)
  !> taken off the rows first(j) .. j - 1 above it).
  pure subroutine envelope_solve(n, first, ptr, factor, nrhs, rhs)
    integer, intent(in) :: n, first(n), ptr(n + 1), nrhs
    real(dp), intent(in), contiguous :: factor(:)
    real(dp), intent(inout) :: rhs(n, nrhs)
    integer :: i, j, k, m, fj, pj, r
    real(dp) :: x
    m = ptr(n + 1) - 1
    do k = 1, nrhs
      do i = 1, n
        rhs(i, k) = rhs(i, k) - dot(i - first(i), factor(ptr(i):), rhs(first(i):, k))
      end do
      do j = n, 1, -1
        x = rhs(j, k) / factor(2 * m + j)
        rhs(j, k) = x
        fj = first(j)
        pj = m + ptr(j) - fj
        do r = fj, j - 1
          rhs(r, k) = rhs(r, k) - x * factor(pj + r)
        end do
      end do
    end do
  end subroutine envelope_solve

  !> a(1:length) . b(1:length) in four interleaved partial sums (terms k, k + 4, ... in
  !> sum mod(k - 1, 4)), added pairwise at the end; 0 for length 0.
  pure real(dp) function dot(length, a, b) result(total)
    integer, intent(in) :: length
    real(dp), intent(in) :: a(*), b(*)
    real(dp) :: s1, s2, s3, s4
    integer :: k, blocks
    s1 = 0.0_dp
    s2 = 0.0_dp
    s3 = 0.0_dp
    s4 = 0.0_dp
    blocks = length / 4
    do k = 1, 4 * blocks, 4
      s1 = s1 + a(k) * b(k)
      s2 = s2 + a(k + 1) * b(k + 1)
      s3 = s3 + a(k + 2) * b(k + 2)
      s4 = s4 + a(k + 3) * b(k + 3)
    end do
    !GCC$ novector
    do k = 4 * blocks + 1, length
      s1 = s1 + a(k) * b(k)
    end do
    total = (s1 + s2) + (s3 + s4)
  end function dot

end module envelope_lu
