!> Newmark stepping of a modally reduced FFR model in one prescribed frame (python
!> ancfdrv.solvers.ffr_reduced, module doc there):
!>   eta'' + 2 psi' Gam eta' + (Lam + psi'' Gam + psi'^2 C2) eta + R(eta) = g(t),
!>   R(eta) = C eta + T(eta, eta)   (the P-delta remainder; absent without it),
!> with constant r x r matrices and the frame's rate psi', acceleration psi'' and angle psi
!> given at every output time, the load
!>   g = -psi'' l_euler - psi'^2 l_centrifugal - sin psi l_sin + (1 - cos psi) l_cos
!> formed step by step from its four constant patterns (as tests/reference/reduced_ffr_newmark.py forms it). The iteration matrix a I + v 2 psi' Gam + Lam + psi'' Gam +
!> psi'^2 C2 (+ C) is factorized (LU with partial pivoting) only when psi' or psi'' changed; the linear
!> model takes one exact solve per step, with P-delta simplified Newton on that matrix.
module reduced_ffr_stepper
  use ancf_kinds, only: dp
  implicit none
  private
  public :: reduced_newmark

contains

  !> steps Newmark steps of size dt from rest at eta = 0; eta(:, 1) = 0 is the start,
  !> eta(:, n + 1) the state at step n, velocity(:, n + 1) its rate eta'. The start's
  !> acceleration is the consistent one at rest, eta''(0) = g(0) (zero stiffness and
  !> gyroscopic terms at eta = eta' = 0). Per step n + 1: corrections(n + 1) Newton
  !> corrections, factorized(n + 1) = 1 when the iteration matrix was factorized (row 1:
  !> 0, the start). info = 0; 1: Newton did not converge within max_newton corrections
  !> (failed_step: the step); 2: a singular iteration matrix.
  subroutine reduced_newmark(r, steps, dt, beta, gamma, omega2, gyroscopic, centrifugal, &
                             pdelta, pdelta_linear, pdelta_quadratic, load_patterns, rate, &
                             accel, sin_psi, one_minus_cos, tol, max_newton, eta, velocity, &
                             corrections, factorized, info, failed_step)
    integer, intent(in) :: r, steps, max_newton
    real(dp), intent(in) :: dt, beta, gamma, omega2(r), gyroscopic(r, r), centrifugal(r, r)
    logical, intent(in) :: pdelta
    real(dp), intent(in) :: pdelta_linear(r, r), pdelta_quadratic(r, r, r)
    !> load_patterns(:, 1:4): l_euler, l_centrifugal, l_sin, l_cos (module doc)
    real(dp), intent(in) :: load_patterns(r, 4), rate(steps + 1), accel(steps + 1), tol
    real(dp), intent(in) :: sin_psi(steps + 1), one_minus_cos(steps + 1)
    real(dp), intent(out) :: eta(r, steps + 1), velocity(r, steps + 1)
    integer, intent(out) :: corrections(steps + 1), factorized(steps + 1)
    integer, intent(out) :: info, failed_step
    real(dp) :: vel(r), acc(r), base(r), vbase(r), x(r), a_new(r), v_new(r), res(r)
    real(dp) :: damp_v(r), stiff_x(r), linear_x(r), quadratic_x(r), load(r)
    real(dp) :: stiff(r, r), damp(r, r), jac(r, r), contracted(r, r)
    real(dp) :: a_fac, v_fac, last_rate, last_accel, largest_step, largest_x
    integer :: n, it, i, j, ipiv(r), lapack_info
    logical :: converged, fresh, not_a_number
    info = 0
    failed_step = 0
    a_fac = 1.0_dp / (beta * dt * dt)
    v_fac = gamma / (beta * dt)
    eta = 0.0_dp
    velocity = 0.0_dp
    corrections = 0
    factorized = 0
    vel = 0.0_dp
    call step_load(r, load_patterns, rate(1), accel(1), sin_psi(1), one_minus_cos(1), acc)
    fresh = .true.
    last_rate = 0.0_dp
    last_accel = 0.0_dp
    do n = 1, steps
      ! the iteration matrix a_fac I + v_fac damp + stiff (+ C): factorized again only when
      ! the frame's rate or acceleration changed (constant in the luffing and free stages)
      if (fresh .or. rate(n + 1) /= last_rate .or. accel(n + 1) /= last_accel) then
        do j = 1, r
          do i = 1, r
            stiff(i, j) = accel(n + 1) * gyroscopic(i, j) + rate(n + 1)**2 * centrifugal(i, j)
          end do
          stiff(j, j) = stiff(j, j) + omega2(j)
        end do
        do j = 1, r
          do i = 1, r
            damp(i, j) = 2.0_dp * rate(n + 1) * gyroscopic(i, j)
            jac(i, j) = v_fac * damp(i, j) + stiff(i, j)
          end do
          jac(j, j) = jac(j, j) + a_fac
        end do
        if (pdelta) then
          do j = 1, r
            do i = 1, r
              jac(i, j) = jac(i, j) + pdelta_linear(i, j)
            end do
          end do
        end if
        ! (r is small: an inline LU beats LAPACK's call overhead by a factor of 20)
        call small_lu(r, jac, ipiv, lapack_info)
        if (lapack_info /= 0) then
          info = 2
          failed_step = n
          return
        end if
        fresh = .false.
        factorized(n + 1) = 1
        last_rate = rate(n + 1)
        last_accel = accel(n + 1)
      end if
      call step_load(r, load_patterns, rate(n + 1), accel(n + 1), sin_psi(n + 1), &
                     one_minus_cos(n + 1), load)
      do i = 1, r
        base(i) = eta(i, n) + dt * vel(i) + dt * dt * (0.5_dp - beta) * acc(i)
        vbase(i) = vel(i) + dt * (1.0_dp - gamma) * acc(i)
        x(i) = base(i) + dt * dt * beta * acc(i)
      end do
      converged = .false.
      ! explicit loops (no array temporaries: the whole-array forms cost 13k instructions a
      ! step at r = 8, a third of the run's time); each sum in the order of matmul's
      do it = 1, max_newton
        do i = 1, r
          a_new(i) = (x(i) - base(i)) * a_fac
          v_new(i) = vbase(i) + dt * gamma * a_new(i)
        end do
        call matrix_vector(r, r, damp, v_new, damp_v)
        call matrix_vector(r, r, stiff, x, stiff_x)
        do i = 1, r
          res(i) = a_new(i) + damp_v(i) + stiff_x(i) - load(i)
        end do
        if (pdelta) then
          ! contracted(i, j) = sum_k T(i, j, k) x_k; R = C x + contracted x: T as an
          ! (r r, r) matrix times x (one long loop per k)
          call matrix_vector(r * r, r, pdelta_quadratic, x, contracted)
          call matrix_vector(r, r, pdelta_linear, x, linear_x)
          call matrix_vector(r, r, contracted, x, quadratic_x)
          do i = 1, r
            res(i) = res(i) + linear_x(i) + quadratic_x(i)
          end do
        end if
        do i = 1, r
          res(i) = -res(i)
        end do
        call small_lu_solve(r, jac, ipiv, res)
        largest_step = 0.0_dp
        largest_x = 0.0_dp
        not_a_number = .false.
        do i = 1, r
          x(i) = x(i) + res(i)
          largest_step = max(largest_step, abs(res(i)))
          largest_x = max(largest_x, abs(x(i)))
          not_a_number = not_a_number .or. res(i) /= res(i)
        end do
        corrections(n + 1) = it
        ! linear: the one correction solves the step exactly (the matrix is its Jacobian)
        if (.not. pdelta) then
          converged = .true.
          exit
        end if
        ! P-delta: simplified Newton with the linear part's matrix (the quadratic
        ! remainder is small against a_fac I)
        ! (a correction that is not a number never converges)
        if (.not. not_a_number .and. largest_step <= tol * max(1.0_dp, largest_x)) then
          converged = .true.
          exit
        end if
      end do
      if (.not. converged) then
        info = 1
        failed_step = n
        return
      end if
      do i = 1, r
        acc(i) = (x(i) - base(i)) * a_fac
        vel(i) = vbase(i) + dt * gamma * acc(i)
        eta(i, n + 1) = x(i)
        velocity(i, n + 1) = vel(i)
      end do
    end do
  end subroutine reduced_newmark

  !> The load g of the module doc at one time, each entry in the order numpy forms it in
  !> tests/reference/reduced_ffr_newmark.py: ((-psi'' l_e - psi'^2 l_c) - sin psi l_s) + (1 - cos psi) l_k.
  pure subroutine step_load(r, patterns, rate, accel, sin_psi, one_minus_cos, load)
    integer, intent(in) :: r
    real(dp), intent(in) :: patterns(r, 4), rate, accel, sin_psi, one_minus_cos
    real(dp), intent(out) :: load(r)
    integer :: i
    do i = 1, r
      load(i) = ((-accel) * patterns(i, 1) - rate**2 * patterns(i, 2) &
                 - sin_psi * patterns(i, 3)) + one_minus_cos * patterns(i, 4)
    end do
  end subroutine step_load

  !> y = a b for a(m, n), each y(i) summed over j = 1, ..., n in order (as matmul sums).
  pure subroutine matrix_vector(m, n, a, b, y)
    integer, intent(in) :: m, n
    real(dp), intent(in) :: a(m, n), b(n)
    real(dp), intent(out) :: y(m)
    integer :: i, j
    do i = 1, m
      y(i) = a(i, 1) * b(1)
    end do
    do j = 2, n
      do i = 1, m
        y(i) = y(i) + a(i, j) * b(j)
      end do
    end do
  end subroutine matrix_vector

  !> In-place LU factorization with partial pivoting of a (n, n): info = 1 for a zero pivot.
  pure subroutine small_lu(n, a, pivots, info)
    integer, intent(in) :: n
    real(dp), intent(inout) :: a(n, n)
    integer, intent(out) :: pivots(n), info
    real(dp) :: row(n)
    integer :: j, p, i
    info = 0
    do j = 1, n
      p = j - 1 + maxloc(abs(a(j:n, j)), 1)
      pivots(j) = p
      if (a(p, j) == 0.0_dp) then
        info = 1
        return
      end if
      if (p /= j) then
        row = a(j, :)
        a(j, :) = a(p, :)
        a(p, :) = row
      end if
      a(j + 1:n, j) = a(j + 1:n, j) / a(j, j)
      do i = j + 1, n
        a(j + 1:n, i) = a(j + 1:n, i) - a(j + 1:n, j) * a(j, i)
      end do
    end do
  end subroutine small_lu

  !> b := a^-1 b with the factors of small_lu.
  pure subroutine small_lu_solve(n, a, pivots, b)
    integer, intent(in) :: n, pivots(n)
    real(dp), intent(in) :: a(n, n)
    real(dp), intent(inout) :: b(n)
    real(dp) :: swap
    integer :: j
    do j = 1, n
      if (pivots(j) /= j) then
        swap = b(j)
        b(j) = b(pivots(j))
        b(pivots(j)) = swap
      end if
      b(j + 1:n) = b(j + 1:n) - a(j + 1:n, j) * b(j)
    end do
    do j = n, 1, -1
      b(j) = b(j) / a(j, j)
      b(1:j - 1) = b(1:j - 1) - a(1:j - 1, j) * b(j)
    end do
  end subroutine small_lu_solve

end module reduced_ffr_stepper
