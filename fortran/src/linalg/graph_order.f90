!> Orders of the unknowns of a sparse matrix from its pattern's graph (the symmetric
!> closure of the entries): the reverse Cuthill-McKee order that narrows the band
!> (band_order, for the banded LU) and Sloan's order that shrinks the envelope
!> (profile_order, for the envelope LU), with the envelope's size in a given order. Both
!> start each connected component from a pseudo-peripheral node (George and Liu: from a
!> node of least degree, the last level's node of lowest (degree, index) until the number
!> of levels stops growing). No I/O.
module graph_order
  implicit none
  private
  public :: band_order, profile_order, envelope_entries

  !> Sloan's weights of a node's distance to the end node and of its current degree
  !> (Sloan 1989's choice, W1 = 1, W2 = 2)
  integer, parameter :: distance_weight = 1, degree_weight = 2

contains

  !> The symmetric closure of the pattern (rows, cols) as adjacency lists, duplicates
  !> dropped: node i's neighbours adj(ptr(i) : ptr(i + 1) - 1) in the order first met,
  !> degree(i) their number (i itself counted when the pattern has its diagonal entry).
  pure subroutine closure(n, nnz, rows, cols, ptr, adj, degree)
    integer, intent(in) :: n, nnz, rows(nnz), cols(nnz)
    integer, intent(out) :: ptr(n + 1), degree(n)
    integer, allocatable, intent(out) :: adj(:)
    integer, allocatable :: fill(:), mark(:)
    integer :: k, i, j, p, q, first
    allocate (fill(n), adj(2 * nnz), mark(n))
    ptr = 0
    do k = 1, nnz
      ptr(rows(k)) = ptr(rows(k)) + 1
      if (rows(k) /= cols(k)) ptr(cols(k)) = ptr(cols(k)) + 1
    end do
    p = 1
    do i = 1, n
      q = ptr(i)
      ptr(i) = p
      p = p + q
    end do
    ptr(n + 1) = p
    fill = ptr(1:n)
    do k = 1, nnz
      adj(fill(rows(k))) = cols(k)
      fill(rows(k)) = fill(rows(k)) + 1
      if (rows(k) /= cols(k)) then
        adj(fill(cols(k))) = rows(k)
        fill(cols(k)) = fill(cols(k)) + 1
      end if
    end do
    mark = 0
    p = 1
    do i = 1, n
      first = p
      do k = ptr(i), ptr(i + 1) - 1
        j = adj(k)
        if (mark(j) == i) cycle
        mark(j) = i
        adj(p) = j
        p = p + 1
      end do
      ptr(i) = first
      degree(i) = p - first
    end do
    ptr(n + 1) = p
  end subroutine closure

  !> The nodes in increasing (degree, index): a counting sort by degree.
  pure subroutine by_degree(n, degree, seeds)
    integer, intent(in) :: n, degree(n)
    integer, intent(out) :: seeds(n)
    integer :: start_count(0:n), i, k, p, q
    start_count = 0
    do i = 1, n
      start_count(degree(i)) = start_count(degree(i)) + 1
    end do
    p = 1
    do k = 0, n
      q = start_count(k)
      start_count(k) = p
      p = p + q
    end do
    do i = 1, n
      seeds(start_count(degree(i))) = i
      start_count(degree(i)) = start_count(degree(i)) + 1
    end do
  end subroutine by_degree

  !> a precedes b in (degree, index)
  pure logical function before(degree, a, b)
    integer, intent(in) :: degree(:), a, b
    before = degree(a) < degree(b) .or. (degree(a) == degree(b) .and. a < b)
  end function before

  !> Breadth-first levels from s over its component (level: 1 at s, 0 where not reached;
  !> queue: the nodes reached, in the order reached): their number and the last level's
  !> first node in (degree, index).
  pure subroutine levels_from(n, ptr, adj, degree, s, level, queue, number, last_first)
    integer, intent(in) :: n, ptr(n + 1), adj(:), degree(n), s
    integer, intent(out) :: level(n), queue(n), number, last_first
    integer :: h, t, u, v, r
    level = 0
    level(s) = 1
    queue(1) = s
    h = 1
    t = 1
    do while (h <= t)
      u = queue(h)
      h = h + 1
      do r = ptr(u), ptr(u + 1) - 1
        v = adj(r)
        if (level(v) /= 0) cycle
        level(v) = level(u) + 1
        t = t + 1
        queue(t) = v
      end do
    end do
    number = level(queue(t))
    last_first = queue(t)
    do r = t, 1, -1
      if (level(queue(r)) /= number) exit
      if (before(degree, queue(r), last_first)) last_first = queue(r)
    end do
  end subroutine levels_from

  !> A pseudo-peripheral pair of seed's component: start, and finish, the last level's
  !> first node in (degree, index) of start's level structure.
  pure subroutine pseudo_diameter(n, ptr, adj, degree, seed, level, queue, start, finish)
    integer, intent(in) :: n, ptr(n + 1), adj(:), degree(n), seed
    integer, intent(out) :: level(n), queue(n), start, finish
    integer :: nlevels, deeper, found
    start = seed
    call levels_from(n, ptr, adj, degree, start, level, queue, nlevels, finish)
    do
      call levels_from(n, ptr, adj, degree, finish, level, queue, deeper, found)
      if (deeper <= nlevels) exit
      start = finish
      nlevels = deeper
      finish = found
    end do
  end subroutine pseudo_diameter

  !> Reverse Cuthill-McKee order of the symmetric closure of the pattern (rows, cols): each
  !> connected component from a pseudo-peripheral start, seeds and neighbours in increasing
  !> (degree, index); the degree counts a node's distinct neighbours, itself included when
  !> the pattern has its diagonal entry. place(i): the position (1..n) of unknown i; width:
  !> max |place(i) - place(j)| over the entries.
  pure subroutine band_order(n, nnz, rows, cols, place, width)
    integer, intent(in) :: n, nnz, rows(nnz), cols(nnz)
    integer, intent(out) :: place(n), width
    integer, allocatable :: ptr(:), adj(:), degree(:), seeds(:), order(:), level(:), queue(:)
    logical, allocatable :: visited(:)
    integer :: k, i, j, p, q, head, seed, start, finish, count, first
    allocate (ptr(n + 1), degree(n), seeds(n), order(n), level(n), queue(n), visited(n))
    call closure(n, nnz, rows, cols, ptr, adj, degree)
    call by_degree(n, degree, seeds)
    visited = .false.
    count = 0
    do k = 1, n
      seed = seeds(k)
      if (visited(seed)) cycle
      call pseudo_diameter(n, ptr, adj, degree, seed, level, queue, start, finish)
      ! Cuthill-McKee from start: each node's unvisited neighbours in (degree, index) order
      head = count + 1
      count = count + 1
      order(count) = start
      visited(start) = .true.
      do while (head <= count)
        i = order(head)
        head = head + 1
        first = count + 1
        do p = ptr(i), ptr(i + 1) - 1
          j = adj(p)
          if (visited(j)) cycle
          visited(j) = .true.
          count = count + 1
          order(count) = j
          ! insertion into the sorted tail first .. count
          q = count
          do while (q > first)
            if (before(degree, order(q - 1), j)) exit
            order(q) = order(q - 1)
            q = q - 1
          end do
          order(q) = j
        end do
      end do
    end do
    do k = 1, n
      place(order(k)) = n + 1 - k
    end do
    width = 0
    if (nnz > 0) width = maxval(abs(place(rows) - place(cols)))
  end subroutine band_order

  !> Sloan's profile-reducing order (S. W. Sloan, "A Fortran program for profile and
  !> wavefront reduction", Int. J. Numer. Meth. Eng. 28, 1989) of the symmetric closure of
  !> the pattern (rows, cols): each connected component from a pseudo-peripheral start s
  !> toward the end node e of its diameter; the next node numbered is the eligible one
  !> (a neighbour of a numbered node, or s) of highest priority W1 dist(i, e) - W2
  !> (current degree + 1), lowest index among equals, where a node's current degree counts
  !> its neighbours not yet numbered nor adjacent to a numbered node (kept by raising the
  !> priority W2 per neighbour that becomes eligible or numbered). place(i): the position
  !> (1..n) of unknown i.
  pure subroutine profile_order(n, nnz, rows, cols, place)
    integer, intent(in) :: n, nnz, rows(nnz), cols(nnz)
    integer, intent(out) :: place(n)
    integer, parameter :: inactive = 0, preactive = 1, active = 2, numbered = 3
    integer, allocatable :: ptr(:), adj(:), degree(:), seeds(:), level(:), queue(:), &
                            status(:), priority(:), eligible(:)
    integer :: k, i, j, p, r, seed, start, finish, count, neighbours, best, size_q, at
    allocate (ptr(n + 1), degree(n), seeds(n), level(n), queue(n), status(n), priority(n), &
              eligible(n))
    call closure(n, nnz, rows, cols, ptr, adj, degree)
    call by_degree(n, degree, seeds)
    status = inactive
    count = 0
    do k = 1, n
      seed = seeds(k)
      if (status(seed) /= inactive) cycle
      call pseudo_diameter(n, ptr, adj, degree, seed, level, queue, start, finish)
      ! distances to the end node over the component (level - 1 from finish)
      call levels_from(n, ptr, adj, degree, finish, level, queue, r, j)
      do i = 1, n
        if (level(i) == 0) cycle
        neighbours = degree(i)
        do p = ptr(i), ptr(i + 1) - 1
          if (adj(p) == i) neighbours = neighbours - 1
        end do
        priority(i) = distance_weight * (level(i) - 1) - degree_weight * (neighbours + 1)
      end do
      ! the eligible nodes (preactive or active) in eligible(1 : size_q)
      status(start) = preactive
      size_q = 1
      eligible(1) = start
      do while (size_q > 0)
        ! the highest priority, lowest index among equals
        at = 1
        best = eligible(1)
        do p = 2, size_q
          j = eligible(p)
          if (priority(j) > priority(best) .or. &
              (priority(j) == priority(best) .and. j < best)) then
            best = j
            at = p
          end if
        end do
        eligible(at) = eligible(size_q)
        size_q = size_q - 1
        i = best
        if (status(i) == preactive) then
          do p = ptr(i), ptr(i + 1) - 1
            j = adj(p)
            if (j == i) cycle
            priority(j) = priority(j) + degree_weight
            if (status(j) == inactive) then
              status(j) = preactive
              size_q = size_q + 1
              eligible(size_q) = j
            end if
          end do
        end if
        count = count + 1
        place(i) = count
        status(i) = numbered
        do p = ptr(i), ptr(i + 1) - 1
          j = adj(p)
          if (status(j) /= preactive) cycle
          status(j) = active
          priority(j) = priority(j) + degree_weight
          do r = ptr(j), ptr(j + 1) - 1
            at = adj(r)
            if (at == j .or. status(at) == numbered) cycle
            priority(at) = priority(at) + degree_weight
            if (status(at) == inactive) then
              status(at) = preactive
              size_q = size_q + 1
              eligible(size_q) = at
            end if
          end do
        end do
      end do
    end do
  end subroutine profile_order

  !> The envelope's entries below the diagonal in the order place (as envelope_lu lays
  !> them out): the sum over i of i - first(i), first(i) the least position among i and
  !> the pattern's entries of row and column i.
  pure integer function envelope_entries(n, nnz, rows, cols, place) result(total)
    integer, intent(in) :: n, nnz, rows(nnz), cols(nnz), place(n)
    integer :: first(n), k, r, c, i
    do i = 1, n
      first(i) = i
    end do
    do k = 1, nnz
      r = max(place(rows(k)), place(cols(k)))
      c = min(place(rows(k)), place(cols(k)))
      first(r) = min(first(r), c)
    end do
    total = 0
    do i = 1, n
      total = total + i - first(i)
    end do
  end function envelope_entries

end module graph_order
