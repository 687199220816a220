!> The iteration matrix of a mechanical system (a component of system_model): the solver
!> (sparse_direct) of S = beta' M + B^T (K + c_v C_c) B on the reduced pattern, M on that
!> pattern, the policy (constant: S assembled in the solver frame, where every 3-vector of
!> a body in a moving frame is resolved in that frame; refactor: in global coordinates),
!> the current factorization and its flexibility for the constraints' Schur complement.
!> No I/O.
module system_iteration
  use ancf_kinds, only: dp
  use sparse_direct, only: solver_solve, solver_factorize
  implicit none
  private
  public :: iteration_matrix, to_solver_frame, dof_frame, factorize_matrix

  integer, parameter, public :: policy_constant = 0, policy_refactor = 1

  type :: iteration_matrix
    ! iteration matrix: solver handle (sparse_direct), M on its pattern, policy, the
    ! frame of each reduced 3-vector (policy constant), the touched 3-vector blocks
    integer :: solver_handle = 0, policy = policy_refactor
    real(dp), allocatable :: mass_pattern(:)
    integer, allocatable :: vector_frame(:), block_first(:)
    integer :: single_frame = -1                       ! the frame of every vector, or -1
    ! the current factorization: its flexibility S^{-1} E_c and E_c^T S^{-1} E_c
    logical :: factorized = .false.
    real(dp) :: factor_beta_prime = 0.0_dp
    integer :: factor_active = -1                      ! active contact points at it
    ! the static Newton's saddle-point solver (sparse_direct's solver_create_for) and the
    ! pattern it analysed: made by the first static call, kept while the pattern stays,
    ! released with the system (system_store)
    integer :: saddle_handle = 0
    integer, allocatable :: saddle_rows(:), saddle_cols(:)
    ! (what the stepper learns from step to step lives apart: stepper.f90)
    real(dp), allocatable :: flexibility(:, :), flexibility_cc(:, :)
  end type iteration_matrix

contains

  !> Factorizes S = values + beta' M (values: the reduced tangent, overwritten with S) and
  !> computes the flexibility S^{-1} E_c and E_c^T S^{-1} E_c at the touched blocks for the
  !> Schur complement. info 3 (solver failure, detail = its code).
  subroutine factorize_matrix(matrix, ndof, beta_prime, values, info, detail)
    type(iteration_matrix), intent(inout) :: matrix
    integer, intent(in) :: ndof
    real(dp), intent(in) :: beta_prime
    real(dp), intent(inout) :: values(:)
    integer, intent(out) :: info, detail
    integer :: b, j
    values = values + beta_prime * matrix%mass_pattern
    matrix%factorized = .false.
    call solver_factorize(matrix%solver_handle, size(values), values, info, detail)
    if (info /= 0) then
      detail = info
      info = 3
      return
    end if
    matrix%factorized = .true.
    matrix%factor_beta_prime = beta_prime
    if (size(matrix%block_first) == 0) return
    matrix%flexibility = 0.0_dp
    do b = 1, size(matrix%block_first)
      do j = 1, min(3, ndof - matrix%block_first(b) + 1)  ! (fewer than 3 unknowns left)
        matrix%flexibility(matrix%block_first(b) + j - 1, 3 * (b - 1) + j) = 1.0_dp
      end do
    end do
    call solver_solve(matrix%solver_handle, ndof, 3 * size(matrix%block_first), &
                      matrix%flexibility, info, detail)
    if (info /= 0) then
      detail = info
      info = 3
      return
    end if
    matrix%flexibility_cc = 0.0_dp
    do b = 1, size(matrix%block_first)
      do j = 1, min(3, ndof - matrix%block_first(b) + 1)
        matrix%flexibility_cc(3 * (b - 1) + j, :) = &
          matrix%flexibility(matrix%block_first(b) + j - 1, :)
      end do
    end do
  end subroutine factorize_matrix

  !> The solver frame: policy constant rotates each reduced 3-vector of a moving frame's
  !> bodies into that frame (U^T x, transpose_first) or back (U x); otherwise a copy.
  pure subroutine to_solver_frame(matrix, rotations, x, transpose_first, y)
    type(iteration_matrix), intent(in) :: matrix
    real(dp), intent(in) :: rotations(:, :, 0:), x(:)
    logical, intent(in) :: transpose_first
    real(dp), intent(out) :: y(:)
    integer :: b, i, f
    real(dp) :: r(3, 3)
    if (matrix%policy /= policy_constant .or. .not. allocated(matrix%vector_frame)) then
      y = x
      return
    end if
    if (matrix%single_frame > 0) then  ! every vector in one frame: one rotation, no look-up
      r = rotations(:, :, matrix%single_frame)
      if (.not. transpose_first) r = transpose(r)
      do b = 0, size(x) / 3 - 1
        y(3 * b + 1) = r(1, 1) * x(3 * b + 1) + r(2, 1) * x(3 * b + 2) + r(3, 1) * x(3 * b + 3)
        y(3 * b + 2) = r(1, 2) * x(3 * b + 1) + r(2, 2) * x(3 * b + 2) + r(3, 2) * x(3 * b + 3)
        y(3 * b + 3) = r(1, 3) * x(3 * b + 1) + r(2, 3) * x(3 * b + 2) + r(3, 3) * x(3 * b + 3)
      end do
      return
    end if
    do b = 0, size(x) / 3 - 1
      f = matrix%vector_frame(b + 1)
      if (f == 0) then
        y(3 * b + 1:3 * b + 3) = x(3 * b + 1:3 * b + 3)
      else if (transpose_first) then
        do i = 1, 3  ! written out: a generic matmul per 3-vector cost a tenth of a step
          y(3 * b + i) = rotations(1, i, f) * x(3 * b + 1) + rotations(2, i, f) * x(3 * b + 2) &
                         + rotations(3, i, f) * x(3 * b + 3)
        end do
      else
        do i = 1, 3
          y(3 * b + i) = rotations(i, 1, f) * x(3 * b + 1) + rotations(i, 2, f) * x(3 * b + 2) &
                         + rotations(i, 3, f) * x(3 * b + 3)
        end do
      end if
    end do
  end subroutine to_solver_frame

  !> Frame of the reduced 3-vector holding dof (0: global).
  pure integer function dof_frame(matrix, dof)
    type(iteration_matrix), intent(in) :: matrix
    integer, intent(in) :: dof
    dof_frame = 0
    if (matrix%policy /= policy_constant .or. .not. allocated(matrix%vector_frame)) return
    dof_frame = matrix%vector_frame((dof - 1) / 3 + 1)
  end function dof_frame

end module system_iteration
