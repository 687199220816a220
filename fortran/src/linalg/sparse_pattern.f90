!> Sparsity pattern of an assembled matrix, computed once from the element dof lists,
!> and the scatter map from element-matrix entries to CSR slots: assembling is then
!> values(map(p)) += element_values(p), with no search.
module sparse_pattern
  use ancf_kinds, only: dp
  implicit none
  private
  public :: pattern_count, pattern_fill, pattern_assemble

contains

  !> Row lengths of the pattern of an n x n matrix whose element e couples the dofs
  !> dofs(:, e) (0 entries are skipped). Returns nnz; info = 1 for a dof out of range.
  pure subroutine pattern_count(n, ndofe, nel, dofs, row_length, nnz, info)
    integer, intent(in) :: n, ndofe, nel, dofs(ndofe, nel)
    integer, intent(out) :: row_length(n), nnz, info
    integer, allocatable :: row_ptr(:), columns(:)
    call build_rows(n, ndofe, nel, dofs, row_ptr, columns, row_length, info)
    nnz = sum(row_length)
  end subroutine pattern_count

  !> CSR arrays (1-based) and the scatter map of every element entry (ndofe*ndofe*nel,
  !> column-major per element; 0 where a dof is 0).
  pure subroutine pattern_fill(n, ndofe, nel, dofs, nnz, row_ptr, col_index, scatter_map, info)
    integer, intent(in) :: n, ndofe, nel, dofs(ndofe, nel), nnz
    integer, intent(out) :: row_ptr(n + 1), col_index(nnz), scatter_map(ndofe, ndofe, nel), info
    integer, allocatable :: bucket_ptr(:), buckets(:)
    integer :: row_length(n), i, e, a, b, lo, hi, mid
    call build_rows(n, ndofe, nel, dofs, bucket_ptr, buckets, row_length, info)
    if (info /= 0) return
    if (sum(row_length) /= nnz) then
      info = 2
      return
    end if
    row_ptr(1) = 1
    do i = 1, n
      row_ptr(i + 1) = row_ptr(i) + row_length(i)
      col_index(row_ptr(i):row_ptr(i + 1) - 1) = buckets(bucket_ptr(i):bucket_ptr(i) + row_length(i) - 1)
    end do
    scatter_map = 0
    do e = 1, nel
      do b = 1, ndofe
        if (dofs(b, e) == 0) cycle
        do a = 1, ndofe
          i = dofs(a, e)
          if (i == 0) cycle
          lo = row_ptr(i)
          hi = row_ptr(i + 1) - 1
          do while (lo < hi)
            mid = (lo + hi) / 2
            if (col_index(mid) < dofs(b, e)) then
              lo = mid + 1
            else
              hi = mid
            end if
          end do
          scatter_map(a, b, e) = lo
        end do
      end do
    end do
  end subroutine pattern_fill

  !> CSR values from element matrices through the scatter map.
  pure subroutine pattern_assemble(nnz, ndofe, nel, scatter_map, element_values, values)
    integer, intent(in) :: nnz, ndofe, nel, scatter_map(ndofe, ndofe, nel)
    real(dp), intent(in) :: element_values(ndofe, ndofe, nel)
    real(dp), intent(out) :: values(nnz)
    integer :: e, a, b
    values = 0.0_dp
    do e = 1, nel
      do b = 1, ndofe
        do a = 1, ndofe
          if (scatter_map(a, b, e) > 0) then
            values(scatter_map(a, b, e)) = values(scatter_map(a, b, e)) + element_values(a, b, e)
          end if
        end do
      end do
    end do
  end subroutine pattern_assemble

  !> Sorted, unique column lists per row, stored in buckets sized by an upper bound.
  pure subroutine build_rows(n, ndofe, nel, dofs, bucket_ptr, buckets, row_length, info)
    integer, intent(in) :: n, ndofe, nel, dofs(ndofe, nel)
    integer, allocatable, intent(out) :: bucket_ptr(:), buckets(:)
    integer, intent(out) :: row_length(n), info
    integer :: bound(n), e, a, b, i, j, p, q, start, count, value
    info = 0
    row_length = 0
    if (any(dofs < 0) .or. any(dofs > n)) then
      info = 1
      allocate (bucket_ptr(n + 1), buckets(0))
      return
    end if
    bound = 0
    do e = 1, nel
      count = count_nonzero(dofs(:, e))
      do a = 1, ndofe
        if (dofs(a, e) > 0) bound(dofs(a, e)) = bound(dofs(a, e)) + count
      end do
    end do
    allocate (bucket_ptr(n + 1))
    bucket_ptr(1) = 1
    do i = 1, n
      bucket_ptr(i + 1) = bucket_ptr(i) + bound(i)
    end do
    allocate (buckets(bucket_ptr(n + 1) - 1))
    do e = 1, nel
      do a = 1, ndofe
        i = dofs(a, e)
        if (i == 0) cycle
        do b = 1, ndofe
          j = dofs(b, e)
          if (j == 0) cycle
          buckets(bucket_ptr(i) + row_length(i)) = j
          row_length(i) = row_length(i) + 1
        end do
      end do
    end do
    do i = 1, n
      start = bucket_ptr(i)
      ! insertion sort of the row, then drop duplicates in place
      do p = start + 1, start + row_length(i) - 1
        value = buckets(p)
        q = p - 1
        do while (q >= start)
          if (buckets(q) <= value) exit
          buckets(q + 1) = buckets(q)
          q = q - 1
        end do
        buckets(q + 1) = value
      end do
      count = min(row_length(i), 1)
      do p = start + 1, start + row_length(i) - 1
        if (buckets(p) /= buckets(start + count - 1)) then
          buckets(start + count) = buckets(p)
          count = count + 1
        end if
      end do
      row_length(i) = count
    end do
  end subroutine build_rows

  pure integer function count_nonzero(list)
    integer, intent(in) :: list(:)
    count_nonzero = count(list > 0)
  end function count_nonzero

end module sparse_pattern
