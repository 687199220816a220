!> The predictor of e''_{n+1} for the steppers' Newton iteration (time_integrator's module
!> notes): the extrapolations of the accelerations of the last steps, and after each step the
!> choice of the one that came nearest (learn_predictor). The history lives in the
!> stepper's state (stepper_state: accel_before .. accel_before3, predict_step,
!> predict_history, predictor).
module acceleration_predictor
  use ancf_kinds, only: dp
  use stepper, only: stepper_state
  implicit none
  private
  public :: extrapolate, usable_predictor, learn_predictor
  public :: predict_hold, predict_alternate, predict_linear, predict_quadratic, &
            predict_alternate_linear, predict_fitted

  !> the predictor's extrapolations of e''_{n+1} (learn_predictor): e''_n; e''_{n-1}; linear
  !> 2 e''_n - e''_{n-1}; quadratic 3 e''_n - 3 e''_{n-1} + e''_{n-2}; linear with the
  !> period-2 alternation e''_n + e''_{n-1} - e''_{n-2}; the fitted recurrence
  !> e''_n + alpha d_n + beta d_{n-1} (fit_recurrence)
  integer, parameter :: predict_hold = 0, predict_alternate = 1, predict_linear = 2, &
                        predict_quadratic = 3, predict_alternate_linear = 4, &
                        predict_fitted = 5

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
    real(dp) :: misses(0:predict_fitted), alpha, beta, now, before, before2
    logical :: usable(0:predict_fitted)
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
      do kind = 0, predict_fitted
        usable(kind) = usable_predictor(learned, h, kind) == kind
      end do
      alpha = 0.0_dp
      beta = 0.0_dp
      if (usable(predict_fitted)) call fit_recurrence(accel, learned, alpha, beta)
      ! (every kind's miss in the same pass, each by its one expression (extrapolated) with
      ! the kind fixed: no selection per coordinate; an unusable kind's miss is not read)
      misses = 0.0_dp
      do i = 1, size(accel)
        now = accel(i)
        before = learned%accel_before(i)
        before2 = learned%accel_before2(i)
        do kind = predict_hold, predict_fitted
          misses(kind) = max(misses(kind), abs(accel_new(i) - &
                                               extrapolated(kind, now, before, before2, alpha, beta)))
        end do
      end do
      learned%predictor = predict_hold
      do kind = predict_alternate, predict_fitted
        if (usable(kind) .and. misses(kind) < misses(learned%predictor)) &
          learned%predictor = kind
      end do
      learned%accel_before3 = learned%accel_before2
      learned%accel_before2 = learned%accel_before
    end if
    if (learned%predict_step == h) then
      learned%predict_history = min(learned%predict_history + 1, 3)
    else
      learned%predict_step = h
      learned%predict_history = 1
    end if
    learned%accel_before = accel
  end subroutine learn_predictor

end module acceleration_predictor
