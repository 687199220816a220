!> Prescribed time functions phi(t), phi'(t), phi''(t) that drive rheonomic constraints.
!>   kind 0  constant:  phi = p(1)
!>   kind 1  luffing profile of SPEC section 5 (smooth start, constant rate, smooth brake):
!>           p = [omega, t_s, t_b, sweep, phi_start] (omega and sweep of one sign)
!>   kind 2  spin-up of Simo & Vu-Quoc (J. Appl. Mech. 53, 1986): p = [W, T, phi_start],
!>           phi = (W/T) (t^2/2 + (T/(2 pi))^2 (cos(2 pi t/T) - 1)) for t < T, W t - W T/2 after
!>   kind 3  load cycle: p = [amplitude, T, t_0]: phi = amplitude (1 - cos(2 pi (t - t_0)/T))/2
!>           on [t_0, t_0 + T] (0 -> amplitude -> 0 with zero rate at both ends), 0 outside
!>   kind 4  sine: p = [amplitude, frequency (Hz), phase (rad), offset, t_0, t_ramp]:
!>           phi = offset + amplitude r(tau) sin(2 pi f tau + phase), tau = t - t_0, with the
!>           envelope r = 0 before t_0, (1 - cos(pi tau / t_ramp))/2 while tau < t_ramp, 1 after
!>           (t_ramp = 0: a plain sine from t_0 on)
!>   kind 5  table: p = [t_1 .. t_n, v_1 .. v_n] with increasing t_k: phi linear in between,
!>           constant outside [t_1, t_n]; phi'' = 0 (use smooth drives for prescribed motion)
!>   kind 10 ramp: p = [rate, t_ramp, phi_start, t_0]: phi = phi_start before t_0, then the
!>           rate rises smoothly, phi' = rate (tau/T - sin(2 pi tau/T)/(2 pi)) ... in closed form:
!>           phi = phi_start + (rate/T) (tau^2/2 + (T/(2 pi))^2 (cos(2 pi tau/T) - 1)) for
!>           tau = t - t_0 < T = t_ramp, phi_start + rate (tau - T/2) after (phi'' continuous,
!>           zero at both ends of the ramp); t_ramp = 0: the rate at once from t_0
!>   kind 11 piecewise cubic Hermite table: p = [t_1 .. t_n, v_1 .. v_n, s_1 .. s_n] with
!>           increasing t_k, values v_k and slopes s_k at the points (the caller chooses the
!>           slopes: a C2 cubic spline or PCHIP); constant outside [t_1, t_n]
!> A drive's parameters are an array of any length (the caller slices a packed store).
module drives
  use ancf_kinds, only: dp
  implicit none
  private
  public :: drive_eval

  integer, parameter, public :: drive_constant = 0, drive_luffing = 1, drive_spinup = 2, &
                                   drive_cycle = 3, drive_sine = 4, drive_table = 5, &
                                   drive_ramp = 10, drive_hermite = 11
  real(dp), parameter :: pi = 3.14159265358979323846_dp

contains

  !> info = 1 for an unknown kind, 2 for non-physical parameters.
  pure subroutine drive_eval(kind, params, t, phi, dphi, ddphi, info)
    integer, intent(in) :: kind
    real(dp), intent(in) :: params(:), t
    real(dp), intent(out) :: phi, dphi, ddphi
    integer, intent(out) :: info
    real(dp) :: omega, t_s, t_b, t_c, t_1, t_2, tau, period
    info = 0
    if (size(params) < minimum_parameters(kind)) then
      info = merge(1, 2, minimum_parameters(kind) < 0)
      phi = 0.0_dp
      dphi = 0.0_dp
      ddphi = 0.0_dp
      return
    end if
    phi = 0.0_dp
    dphi = 0.0_dp
    ddphi = 0.0_dp
    select case (kind)
    case (drive_constant)
      phi = params(1)
    case (drive_luffing)
      omega = params(1)
      t_s = params(2)
      t_b = params(3)
      t_c = params(4) / omega - 0.5_dp * (t_s + t_b)
      if (omega == 0.0_dp .or. t_s <= 0.0_dp .or. t_b <= 0.0_dp .or. t_c < 0.0_dp) then
        info = 2
        return
      end if
      t_1 = t_s + t_c
      t_2 = t_1 + t_b
      if (t < 0.0_dp) then
        phi = 0.0_dp
      else if (t < t_s) then
        phi = 0.5_dp * omega * (t - t_s / pi * sin(pi * t / t_s))
        dphi = 0.5_dp * omega * (1.0_dp - cos(pi * t / t_s))
        ddphi = 0.5_dp * omega * pi / t_s * sin(pi * t / t_s)
      else if (t < t_1) then
        phi = 0.5_dp * omega * t_s + omega * (t - t_s)
        dphi = omega
      else if (t < t_2) then
        tau = t - t_1
        phi = 0.5_dp * omega * t_s + omega * t_c + 0.5_dp * omega * (tau + t_b / pi * sin(pi * tau / t_b))
        dphi = 0.5_dp * omega * (1.0_dp + cos(pi * tau / t_b))
        ddphi = -0.5_dp * omega * pi / t_b * sin(pi * tau / t_b)
      else
        phi = params(4)
      end if
      phi = phi + params(5)
    case (drive_spinup)
      omega = params(1)
      period = params(2)
      if (period <= 0.0_dp) then
        info = 2
        return
      end if
      if (t < 0.0_dp) then
        phi = 0.0_dp
      else if (t < period) then
        phi = omega / period * (0.5_dp * t * t + (period / (2.0_dp * pi))**2 &
                                * (cos(2.0_dp * pi * t / period) - 1.0_dp))
        dphi = omega / period * (t - period / (2.0_dp * pi) * sin(2.0_dp * pi * t / period))
        ddphi = omega / period * (1.0_dp - cos(2.0_dp * pi * t / period))
      else
        phi = omega * t - 0.5_dp * omega * period
        dphi = omega
      end if
      phi = phi + params(3)
    case (drive_cycle)
      period = params(2)
      if (period <= 0.0_dp) then
        info = 2
        return
      end if
      tau = t - params(3)
      if (tau > 0.0_dp .and. tau < period) then
        phi = 0.5_dp * params(1) * (1.0_dp - cos(2.0_dp * pi * tau / period))
        dphi = params(1) * pi / period * sin(2.0_dp * pi * tau / period)
        ddphi = 2.0_dp * params(1) * (pi / period)**2 * cos(2.0_dp * pi * tau / period)
      end if
    case (drive_sine)
      call sine(params, t, phi, dphi, ddphi, info)
    case (drive_table)
      call table(params, t, phi, dphi, ddphi, info)
    case (drive_ramp)
      call ramp(params, t, phi, dphi, ddphi, info)
    case (drive_hermite)
      call hermite_table(params, t, phi, dphi, ddphi, info)
    case default
      info = 1
    end select
  end subroutine drive_eval

  !> Parameters a kind needs at least (-1: unknown kind).
  pure integer function minimum_parameters(kind)
    integer, intent(in) :: kind
    select case (kind)
    case (drive_constant)
      minimum_parameters = 1
    case (drive_luffing)
      minimum_parameters = 5
    case (drive_spinup, drive_cycle)
      minimum_parameters = 3
    case (drive_sine)
      minimum_parameters = 6
    case (drive_table)
      minimum_parameters = 2
    case (drive_ramp)
      minimum_parameters = 4
    case (drive_hermite)
      minimum_parameters = 3
    case default
      minimum_parameters = -1
    end select
  end function minimum_parameters

  pure subroutine sine(params, t, phi, dphi, ddphi, info)
    real(dp), intent(in) :: params(:), t
    real(dp), intent(out) :: phi, dphi, ddphi
    integer, intent(out) :: info
    real(dp) :: amplitude, omega, tau, ramp, r, dr, ddr, s, ds, dds
    info = 0
    amplitude = params(1)
    omega = 2.0_dp * pi * params(2)
    ramp = params(6)
    phi = params(4)
    dphi = 0.0_dp
    ddphi = 0.0_dp
    if (params(2) < 0.0_dp .or. ramp < 0.0_dp) then
      info = 2
      return
    end if
    tau = t - params(5)
    if (tau < 0.0_dp) return
    if (tau < ramp) then
      r = 0.5_dp * (1.0_dp - cos(pi * tau / ramp))
      dr = 0.5_dp * pi / ramp * sin(pi * tau / ramp)
      ddr = 0.5_dp * (pi / ramp)**2 * cos(pi * tau / ramp)
    else
      r = 1.0_dp
      dr = 0.0_dp
      ddr = 0.0_dp
    end if
    s = amplitude * sin(omega * tau + params(3))
    ds = amplitude * omega * cos(omega * tau + params(3))
    dds = -omega**2 * s
    phi = phi + r * s
    dphi = dr * s + r * ds
    ddphi = ddr * s + 2.0_dp * dr * ds + r * dds
  end subroutine sine

  pure subroutine table(params, t, phi, dphi, ddphi, info)
    real(dp), intent(in) :: params(:), t
    real(dp), intent(out) :: phi, dphi, ddphi
    integer, intent(out) :: info
    integer :: n, lo, hi
    info = 0
    phi = 0.0_dp
    dphi = 0.0_dp
    ddphi = 0.0_dp
    n = size(params) / 2
    if (2 * n /= size(params) .or. n < 1) then
      info = 2
      return
    end if
    if (t <= params(1)) then
      phi = params(n + 1)
      return
    end if
    if (t >= params(n)) then
      phi = params(2 * n)
      return
    end if
    lo = table_interval(params(1:n), t)
    hi = lo + 1
    if (params(hi) <= params(lo)) then
      info = 2
      return
    end if
    dphi = (params(n + hi) - params(n + lo)) / (params(hi) - params(lo))
    phi = params(n + lo) + dphi * (t - params(lo))
  end subroutine table

  !> The ramp to a constant rate (kind 10).
  pure subroutine ramp(params, t, phi, dphi, ddphi, info)
    real(dp), intent(in) :: params(:), t
    real(dp), intent(out) :: phi, dphi, ddphi
    integer, intent(out) :: info
    real(dp) :: rate, period, tau, angle
    info = 0
    rate = params(1)
    period = params(2)
    phi = params(3)
    dphi = 0.0_dp
    ddphi = 0.0_dp
    if (period < 0.0_dp) then
      info = 2
      return
    end if
    tau = t - params(4)
    if (tau <= 0.0_dp) return
    if (tau < period) then
      angle = 2.0_dp * pi * tau / period
      phi = phi + rate / period * (0.5_dp * tau * tau + (period / (2.0_dp * pi))**2 &
                                   * (cos(angle) - 1.0_dp))
      dphi = rate / period * (tau - period / (2.0_dp * pi) * sin(angle))
      ddphi = rate / period * (1.0_dp - cos(angle))
    else
      phi = phi + rate * (tau - 0.5_dp * period)
      dphi = rate
    end if
  end subroutine ramp

  !> The piecewise cubic Hermite table (kind 11): on [t_k, t_k+1] with h = t_k+1 - t_k and
  !> u = (t - t_k)/h, phi = h00 v_k + h h10 s_k + h01 v_k+1 + h h11 s_k+1.
  pure subroutine hermite_table(params, t, phi, dphi, ddphi, info)
    real(dp), intent(in) :: params(:), t
    real(dp), intent(out) :: phi, dphi, ddphi
    integer, intent(out) :: info
    integer :: n, lo, hi
    real(dp) :: h, u, v0, v1, s0, s1
    info = 0
    phi = 0.0_dp
    dphi = 0.0_dp
    ddphi = 0.0_dp
    n = size(params) / 3
    if (3 * n /= size(params) .or. n < 1) then
      info = 2
      return
    end if
    if (t <= params(1)) then
      phi = params(n + 1)
      return
    end if
    if (t >= params(n)) then
      phi = params(2 * n)
      return
    end if
    lo = table_interval(params(1:n), t)
    hi = lo + 1
    h = params(hi) - params(lo)
    if (h <= 0.0_dp) then
      info = 2
      return
    end if
    u = (t - params(lo)) / h
    v0 = params(n + lo)
    v1 = params(n + hi)
    s0 = params(2 * n + lo)
    s1 = params(2 * n + hi)
    phi = (2.0_dp * u**3 - 3.0_dp * u**2 + 1.0_dp) * v0 + h * (u**3 - 2.0_dp * u**2 + u) * s0 &
          + (-2.0_dp * u**3 + 3.0_dp * u**2) * v1 + h * (u**3 - u**2) * s1
    dphi = (6.0_dp * u**2 - 6.0_dp * u) * (v0 - v1) / h + (3.0_dp * u**2 - 4.0_dp * u + 1.0_dp) * s0 &
           + (3.0_dp * u**2 - 2.0_dp * u) * s1
    ddphi = ((12.0_dp * u - 6.0_dp) * (v0 - v1) / h + (6.0_dp * u - 4.0_dp) * s0 &
             + (6.0_dp * u - 2.0_dp) * s1) / h
  end subroutine hermite_table

  !> The interval [times(lo), times(lo + 1)] holding t (times(1) < t < times(n), bisection).
  pure integer function table_interval(times, t) result(lo)
    real(dp), intent(in) :: times(:), t
    integer :: hi, mid
    lo = 1
    hi = size(times)
    do while (hi - lo > 1)
      mid = (lo + hi) / 2
      if (times(mid) <= t) then
        lo = mid
      else
        hi = mid
      end if
    end do
  end function table_interval

end module drives
