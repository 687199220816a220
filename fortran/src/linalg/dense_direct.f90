!> Dense direct solves of small sparse systems given as coordinate triplets: the matrix is
!> formed densely and factorized by LAPACK's LU with partial pivoting (dgesv). For a few
!> dozen unknowns (a small model's saddle system of the consistent initial acceleration)
!> this costs microseconds, where a sparse direct solver's analysis, set-up and
!> factorization cost a quarter of a millisecond.
!> info: 0 ok; -1 an index outside 1..n or a size below 1; > 0 dgesv's: the pivot
!> U(info, info) is exactly zero (the matrix is singular).
module dense_direct
  use ancf_kinds, only: dp
  implicit none
  private
  public :: dense_coo_solve

  !> info of an index outside 1..n or a size below 1
  integer, parameter, public :: dense_bad_index = -1

contains

  !> Solves A x = b for the n x n matrix A of the triplets (rows(k), cols(k), values(k)),
  !> 1-based, entries at the same place added in the order given; rhs (n, nrhs) holds b on
  !> entry and x on return (unchanged when info /= 0 before the factorization).
  subroutine dense_coo_solve(n, nnz, rows, cols, values, nrhs, rhs, info)
    integer, intent(in) :: n, nnz, nrhs
    integer, intent(in) :: rows(nnz), cols(nnz)
    real(dp), intent(in) :: values(nnz)
    real(dp), intent(inout) :: rhs(n, nrhs)
    integer, intent(out) :: info
    real(dp), allocatable :: matrix(:, :)
    integer, allocatable :: pivots(:)
    integer :: k, lapack_info
    external :: dgesv
    info = 0
    if (n < 1 .or. nrhs < 1) then
      info = dense_bad_index
      return
    end if
    do k = 1, nnz
      if (rows(k) < 1 .or. rows(k) > n .or. cols(k) < 1 .or. cols(k) > n) then
        info = dense_bad_index
        return
      end if
    end do
    allocate (matrix(n, n), pivots(n))
    matrix = 0.0_dp
    do k = 1, nnz
      matrix(rows(k), cols(k)) = matrix(rows(k), cols(k)) + values(k)
    end do
    call dgesv(n, nrhs, matrix, n, pivots, rhs, n, lapack_info)
    if (lapack_info > 0) info = lapack_info
  end subroutine dense_coo_solve

end module dense_direct
