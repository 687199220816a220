!> The predictor of e''_{n+1} for the steppers' Newton iteration (time_integrator's module
!> notes): the extrapolations of the accelerations of the last steps, and after each step the
!> choice of the one that came nearest (learn_predictor). The history lives in the
!> stepper's state (stepper_state: accel_before .. accel_before3, predict_step,
!> predict_history, predictor).
module acceleration_predictor
  use ancf_kinds, only: dp
  use stepper, only: stepper_state, recurrence_order, recurrence_window, recurrence_span
  implicit none
  private
  public :: extrapolate, usable_predictor, learn_predictor
  public :: predict_hold, predict_alternate, predict_linear, predict_quadratic, &
            predict_alternate_linear, predict_fitted, predict_recurrence

  !> the predictor's extrapolations of e''_{n+1} (learn_predictor): e''_n; e''_{n-1}; linear
  !> 2 e''_n - e''_{n-1}; quadratic 3 e''_n - 3 e''_{n-1} + e''_{n-2}; linear with the
  !> period-2 alternation e''_n + e''_{n-1} - e''_{n-2}; the fitted recurrence
  !> e''_n + alpha d_n + beta d_{n-1} (fit_recurrence); the recurrence of order
  !> recurrence_order e''_n + sum_j c_j d_{n+1-j} (fit_modes: several modes at once)
  integer, parameter :: predict_hold = 0, predict_alternate = 1, predict_linear = 2, &
                        predict_quadratic = 3, predict_alternate_linear = 4, &
                        predict_fitted = 5, predict_recurrence = 6
  !> fit_modes' regularization, relative to the scaled normal equations' unit diagonal (a
  !> history with fewer modes than recurrence_order leaves them singular)
  real(dp), parameter :: modes_ridge = 1e-12_dp

contains

  !> e''_{n+1} by the extrapolation kind from accel = e''_n and the learned e''_{n-1},
  !> e''_{n-2} (predict_hold .. predict_fitted; time_integrator's module notes).
  pure subroutine extrapolate(kind, accel, learned, accel_new)
    integer, intent(in) :: kind
    real(dp), intent(in) :: accel(:)
    type(stepper_state), intent(in) :: learned
    real(dp), intent(out) :: accel_new(:)
    real(dp) :: alpha, beta
    if (kind == predict_hold) then   ! (no history needed: none may be learned yet)
      accel_new = accel
      return
    end if
    if (kind == predict_recurrence) then   ! (the difference predicted with the fit)
      accel_new = accel + learned%recurrence_guess
      return
    end if
    alpha = 0.0_dp
    beta = 0.0_dp
    if (kind == predict_fitted) call fit_recurrence(accel, learned, alpha, beta)
    accel_new = extrapolated(kind, accel, learned%accel_before, learned%accel_before2, &
                             alpha, beta)
  end subroutine extrapolate

  !> One coordinate of e''_{n+1} by the extrapolation kind from now = e''_n, before =
  !> e''_{n-1}, before2 = e''_{n-2} (alpha, beta: fit_recurrence's, for predict_fitted): the
  !> one expression of each kind, for the predictor (extrapolate) and for judging the kinds
  !> after a step (learn_predictor).
  elemental real(dp) function extrapolated(kind, now, before, before2, alpha, beta)
    integer, intent(in) :: kind
    real(dp), intent(in) :: now, before, before2, alpha, beta
    select case (kind)
    case (predict_alternate)
      extrapolated = before
    case (predict_linear)
      extrapolated = 2.0_dp * now - before
    case (predict_quadratic)
      extrapolated = 3.0_dp * (now - before) + before2
    case (predict_alternate_linear)
      extrapolated = (now + before) - before2
    case (predict_fitted)
      extrapolated = now + alpha * (now - before) + beta * (before - before2)
    case default
      extrapolated = now
    end select
  end function extrapolated

  !> alpha, beta: the least-squares fit of d_n = alpha d_{n-1} + beta d_{n-2} over the
  !> coordinates (d_k = e''_k - e''_{k-1}, e''_n = accel): the recurrence of one dominant
  !> mode of the last steps, a smooth drift or an oscillation of any period (0, 0 where
  !> the differences vanish; beta = 0 where d_{n-1} and d_{n-2} are parallel).
  pure subroutine fit_recurrence(accel, learned, alpha, beta)
    real(dp), intent(in) :: accel(:)
    type(stepper_state), intent(in) :: learned
    real(dp), intent(out) :: alpha, beta
    real(dp) :: d0, d1, d2, a11, a12, a22, r1, r2, det
    integer :: i
    a11 = 0.0_dp
    a12 = 0.0_dp
    a22 = 0.0_dp
    r1 = 0.0_dp
    r2 = 0.0_dp
    do i = 1, size(accel)
      d0 = accel(i) - learned%accel_before(i)
      d1 = learned%accel_before(i) - learned%accel_before2(i)
      d2 = learned%accel_before2(i) - learned%accel_before3(i)
      a11 = a11 + d1 * d1
      a12 = a12 + d1 * d2
      a22 = a22 + d2 * d2
      r1 = r1 + d0 * d1
      r2 = r2 + d0 * d2
    end do
    det = a11 * a22 - a12**2
    if (det > 1e-10_dp * a11 * a22) then
      alpha = (r1 * a22 - r2 * a12) / det
      beta = (a11 * r2 - a12 * r1) / det
    else if (a11 > 0.0_dp) then
      alpha = r1 / a11
      beta = 0.0_dp
    else
      alpha = 0.0_dp
      beta = 0.0_dp
    end if
  end subroutine fit_recurrence

  !> kind, when the learned history serves it for a next step of size h (e''_{n-1} for the
  !> alternation, as before issue 23's extrapolations; the extrapolations need the steps
  !> they span of size h), otherwise predict_hold.
  pure integer function usable_predictor(learned, h, kind) result(usable)
    type(stepper_state), intent(in) :: learned
    real(dp), intent(in) :: h
    integer, intent(in) :: kind
    integer :: needed
    select case (kind)
    case (predict_alternate)
      needed = 0
    case (predict_linear)
      needed = 1
    case (predict_quadratic, predict_alternate_linear)
      needed = 2
    case (predict_fitted)
      needed = 3
    case (predict_recurrence)
      needed = recurrence_span
      if (.not. learned%recurrence_ready) then
        usable = predict_hold
        return
      end if
    case default
      usable = predict_hold
      return
    end select
    usable = kind
    if (.not. allocated(learned%accel_before)) then
      usable = predict_hold
    else if (needed > 0 .and. (learned%predict_step /= h .or. &
                                learned%predict_history < needed)) then
      usable = predict_hold
    end if
  end function usable_predictor

  !> After a step of size h from e''_n = accel to e''_{n+1} = accel_new: the extrapolation
  !> of e''_n and the history before it that came nearest e''_{n+1} (max norm; ties: the
  !> simpler) becomes the next step's predictor, and the history moves on by one step.
  pure subroutine learn_predictor(learned, h, accel, accel_new)
    type(stepper_state), intent(inout) :: learned
    real(dp), intent(in) :: h, accel(:), accel_new(:)
    real(dp) :: misses(0:predict_recurrence), alpha, beta, now, before, before2, target
    real(dp), allocatable :: spare(:)
    logical :: usable(0:predict_recurrence)
    integer :: kind, i
    if (.not. allocated(learned%accel_before)) then
      allocate (learned%accel_before(size(accel)), learned%accel_before2(size(accel)), &
                learned%accel_before3(size(accel)))
      learned%accel_before2 = 0.0_dp   ! (read, unused, by the kinds that do not need them)
      learned%accel_before3 = 0.0_dp
      learned%predictor = predict_hold
      learned%predict_history = 0
    else
      ! the candidates as this step would have used them (its own size h), their misses in
      ! one pass over the coordinates
      do kind = 0, predict_recurrence
        usable(kind) = usable_predictor(learned, h, kind) == kind
      end do
      alpha = 0.0_dp
      beta = 0.0_dp
      if (usable(predict_fitted)) call fit_recurrence(accel, learned, alpha, beta)
      ! (every kind's miss in the same pass, each by its one expression (extrapolated) with
      ! the kind fixed: no selection per coordinate; an unusable kind's miss is not read)
      misses = 0.0_dp
      do i = 1, size(accel)
        target = accel_new(i)
        now = accel(i)
        before = learned%accel_before(i)
        before2 = learned%accel_before2(i)
        misses(predict_hold) = max(misses(predict_hold), abs(target - &
          extrapolated(predict_hold, now, before, before2, alpha, beta)))
        misses(predict_alternate) = max(misses(predict_alternate), abs(target - &
          extrapolated(predict_alternate, now, before, before2, alpha, beta)))
        misses(predict_linear) = max(misses(predict_linear), abs(target - &
          extrapolated(predict_linear, now, before, before2, alpha, beta)))
        misses(predict_quadratic) = max(misses(predict_quadratic), abs(target - &
          extrapolated(predict_quadratic, now, before, before2, alpha, beta)))
        misses(predict_alternate_linear) = max(misses(predict_alternate_linear), abs(target - &
          extrapolated(predict_alternate_linear, now, before, before2, alpha, beta)))
        misses(predict_fitted) = max(misses(predict_fitted), abs(target - &
          extrapolated(predict_fitted, now, before, before2, alpha, beta)))
        ! (the recurrence's guess is allocated and defined from the first step on)
        misses(predict_recurrence) = max(misses(predict_recurrence), &
                                         abs(target - (now + learned%recurrence_guess(i))))
      end do
      learned%predictor = predict_hold
      do kind = predict_alternate, predict_recurrence
        if (usable(kind) .and. misses(kind) < misses(learned%predictor)) &
          learned%predictor = kind
      end do
      ! the history moves on by one step: the arrays change places (no copies), the
      ! oldest one's storage takes e''_n below
      call move_alloc(learned%accel_before3, spare)
      call move_alloc(learned%accel_before2, learned%accel_before3)
      call move_alloc(learned%accel_before, learned%accel_before2)
      call move_alloc(spare, learned%accel_before)
    end if
    if (learned%predict_step == h) then
      learned%predict_history = min(learned%predict_history + 1, recurrence_span)
    else
      learned%predict_step = h
      learned%predict_history = 1
    end if
    learned%accel_before = accel
    call learn_modes(learned, accel, accel_new)
  end subroutine learn_predictor

  !> The ring columns of the differences by lag (lag 0: the newest, d_{n+1} after
  !> learn_modes has taken the last step's).
  pure function ring_columns(learned) result(columns)
    type(stepper_state), intent(in) :: learned
    integer :: columns(0:recurrence_span - 1), lag
    ! (modulo(newest - 1 - lag, recurrence_span) + 1, newest in 1 .. recurrence_span)
    do lag = 0, recurrence_span - 1
      columns(lag) = learned%recurrence_newest - lag
      if (columns(lag) < 1) columns(lag) = columns(lag) + recurrence_span
    end do
  end function ring_columns

  !> After a step from e''_n = accel to e''_{n+1} = accel_new: d_{n+1} enters the ring
  !> (with its dot products with the differences before it); once recurrence_span
  !> differences of equal steps are known the coefficients c of the recurrence are fitted
  !> (fit_modes) and the next step's difference predicted by it (recurrence_guess):
  !>   e''_{n+2} - e''_{n+1} = sum_j c_j d_{n+2-j}   (j = 1 .. recurrence_order).
  pure subroutine learn_modes(learned, accel, accel_new)
    type(stepper_state), intent(inout) :: learned
    real(dp), intent(in) :: accel(:), accel_new(:)
    integer :: columns(0:recurrence_span - 1)
    if (.not. allocated(learned%recurrence_differences)) then
      allocate (learned%recurrence_differences(size(accel), recurrence_span), &
                learned%recurrence_guess(size(accel)))
      learned%recurrence_differences = 0.0_dp
      learned%recurrence_guess = 0.0_dp
      learned%recurrence_dots = 0.0_dp
      learned%recurrence_newest = 0
    end if
    learned%recurrence_newest = modulo(learned%recurrence_newest, recurrence_span) + 1
    columns = ring_columns(learned)
    call push_difference(size(accel), accel, accel_new, columns, &
                         learned%recurrence_differences, learned%recurrence_dots)
    learned%recurrence_ready = .false.
    if (learned%predict_history < recurrence_span) return
    call fit_modes(learned%recurrence_dots, learned%recurrence_coefficients, &
                   learned%recurrence_ready)
    if (.not. learned%recurrence_ready) return
    call predicted_difference(size(accel), learned%recurrence_differences, columns, &
                              learned%recurrence_coefficients, learned%recurrence_guess)
  end subroutine learn_modes

  !> d = accel_new - accel into ring column columns(0) of differences (n, recurrence_span)
  !> and its dot products with the differences of lags 0 .. recurrence_order into dots, the
  !> products by lag (dots(a + 1, b + 1) = d(lag a) . d(lag b), a >= b: the lower triangle;
  !> the older products move one lag on, the new ones in column 1), each summed over the
  !> coordinates in their order, as dot_product would, in one pass. fit_modes reads the
  !> products of lags a, b with |a - b| <= recurrence_order only (its normal equations' a, b
  !> in 1 .. recurrence_span - 1, |a - b| < recurrence_order; its right-hand side's b - a = 1
  !> .. recurrence_order): those of the newest with lags recurrence_order + 1 ..
  !> recurrence_span - 1 are never read (their entries keep older products).
  pure subroutine push_difference(n, accel, accel_new, columns, differences, dots)
    integer, intent(in) :: n, columns(0:recurrence_span - 1)
    real(dp), intent(in) :: accel(n), accel_new(n)
    real(dp), intent(inout) :: differences(n, recurrence_span)
    real(dp), intent(inout) :: dots(recurrence_span, recurrence_span)
    integer :: lag, i, a, b
    real(dp) :: total(0:recurrence_order), d
    total = 0.0_dp
    do i = 1, n
      d = accel_new(i) - accel(i)
      differences(i, columns(0)) = d
      do lag = 0, recurrence_order
        total(lag) = total(lag) + d * differences(i, columns(lag))
      end do
    end do
    ! (backwards: each entry is read before it is overwritten)
    do b = recurrence_span, 2, -1
      do a = recurrence_span, b, -1
        dots(a, b) = dots(a - 1, b - 1)
      end do
    end do
    do lag = 0, recurrence_order
      dots(lag + 1, 1) = total(lag)
    end do
  end subroutine push_difference

  !> guess = sum_j c_j d(lag j - 1) (j = 1 .. recurrence_order): the next difference (each
  !> coordinate's sum in the order of j, from 0).
  pure subroutine predicted_difference(n, differences, columns, coefficients, guess)
    integer, intent(in) :: n, columns(0:)
    real(dp), intent(in) :: differences(n, recurrence_span), coefficients(recurrence_order)
    real(dp), intent(out) :: guess(n)
    integer :: j, i
    real(dp) :: total
    do i = 1, n
      total = 0.0_dp
      do j = 1, recurrence_order
        total = total + coefficients(j) * differences(i, columns(j - 1))
      end do
      guess(i) = total
    end do
  end subroutine predicted_difference

  !> The coefficients c of d_m = sum_j c_j d_{m-j} (j = 1 .. recurrence_order), the least
  !> squares fit over all coordinates of the recurrence_window newest differences d_m: the
  !> recurrence that a few lightly damped modes of the last steps follow (a sum of k
  !> sinusoids or exponentials satisfies one of order 2k). The normal equations from the
  !> dot products of the differences by lag (lagged(a, b) = d_{n-a} . d_{n-b}), scaled to a
  !> unit diagonal and regularized by modes_ridge, by Cholesky; ready = .false. where a
  !> difference vanishes or a pivot is not positive.
  pure subroutine fit_modes(dots, coefficients, ready)
    real(dp), intent(in) :: dots(recurrence_span, recurrence_span)
    real(dp), intent(out) :: coefficients(recurrence_order)
    logical, intent(out) :: ready
    real(dp) :: normal(recurrence_order, recurrence_order), rhs(recurrence_order)
    real(dp) :: scale(recurrence_order), pivot
    integer :: i, j, k
    ready = .false.
    coefficients = 0.0_dp
    ! (lagged(a, b) = dots(a + 1, b + 1) for a >= b, push_difference's lower triangle)
    do j = 1, recurrence_order
      rhs(j) = 0.0_dp
      do i = 0, recurrence_window - 1
        rhs(j) = rhs(j) + dots(i + j + 1, i + 1)
      end do
      do k = j, recurrence_order
        normal(k, j) = 0.0_dp
        do i = 0, recurrence_window - 1
          normal(k, j) = normal(k, j) + dots(i + k + 1, i + j + 1)
        end do
      end do
    end do
    do j = 1, recurrence_order
      if (.not. normal(j, j) > 0.0_dp) return
      scale(j) = sqrt(normal(j, j))
    end do
    ! (the lower triangle only: scaled, then Cholesky normal = L L^T in place)
    do j = 1, recurrence_order
      do k = j + 1, recurrence_order
        normal(k, j) = normal(k, j) / (scale(k) * scale(j))
      end do
      normal(j, j) = 1.0_dp + modes_ridge
      rhs(j) = rhs(j) / scale(j)
    end do
    do k = 1, recurrence_order
      pivot = normal(k, k) - sum(normal(k, 1:k - 1)**2)
      if (.not. pivot > 0.0_dp) return
      normal(k, k) = sqrt(pivot)
      do i = k + 1, recurrence_order
        normal(i, k) = (normal(i, k) - sum(normal(i, 1:k - 1) * normal(k, 1:k - 1))) &
                       / normal(k, k)
      end do
    end do
    do k = 1, recurrence_order
      rhs(k) = (rhs(k) - sum(normal(k, 1:k - 1) * rhs(1:k - 1))) / normal(k, k)
    end do
    do k = recurrence_order, 1, -1
      rhs(k) = (rhs(k) - sum(normal(k + 1:recurrence_order, k) * rhs(k + 1:recurrence_order))) &
               / normal(k, k)
    end do
    coefficients = rhs / scale
    ready = all(abs(coefficients) < huge(1.0_dp))
  end subroutine fit_modes

end module acceleration_predictor
