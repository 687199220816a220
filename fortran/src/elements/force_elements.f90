!> Force elements between two bodies (SPEC 8.1): a spring-damper, a bushing, a compliant
!> hydraulic cylinder and a torsion spring. One element acts through "slots": 3-vectors
!> affine in the full coordinates (material points and direction vectors of its two bodies,
!> the ground's constants; the system gathers them), so that this module needs nothing but
!> the slot values x(3, ns) and rates xd(3, ns).
!>
!> Every element is a sum of scalar measures m(x) with a force f(m, m'):
!>   generalized force (the residual's internal sign)   F = sum f dm/dx
!>   stiffness  dF/dx  = sum f d2m/dx2 + dm/dx (df/dm dm/dx + c d2m/dx2 xd)^T
!>   damping    dF/dxd = sum c dm/dx dm/dx^T          (dm'/dxd = dm/dx; f = f_el + c m')
!> exact (the tangent the stepper combines as dF/dx + rate_factor dF/dxd).
!>
!>   spring_damper  slots p1, p2; m = L = |p2 - p1|; f = F0 + k (L - L0) + c L', or
!>                  f = table(L - L0) + c L' (a drive table's interpolation with the
!>                  deflection as argument; energy: its integral from 0, exact by Gauss);
!>   cylinder       slots p1, p2; m = L; f = k (L - l(t)) + c (L' - l'(t)) with the driven
!>                  nominal length l: the oil column in series with a rigid actuator; the
!>                  energy k (L - l)^2 / 2 depends on t: the drive's power -f l' is returned;
!>   bushing        slots p1, p2 (the point on either body), g1..g3 (body1's direction
!>                  vectors at the point), h1..h3 (body2's, mapped so that h_i = g_i at
!>                  t = 0); translations u_i = g_i . (p2 - p1), small relative rotations
!>                  theta_i = (g_k . h_j - g_j . h_k) / 2 for (i, j, k) cyclic: the relative
!>                  rotation vector's components on body1's axes to first order, exactly
!>                  zero when both bodies turn together; f_i = k_i u_i + c_i u_i' (and the
!>                  rotational k_r, c_r with theta).
!>   torsion        slots p1, p2 (the point on either body), g1, g2 (body1's unit vectors
!>                  normal to the axis a = g1 x g2 at t = 0), h1 (body2's, equal to g1 at
!>                  t = 0); the relative rotation about the axis theta = atan2(g2 . h1,
!>                  g1 . h1) (exact for any angle in (-pi, pi) when the relative turn is
!>                  about a); f = k_t theta + c_t theta'; the moment on body2 is -f a.
!> Reaction (7): what body1 exerts on body2: force (3, global), moment (3, global), and the
!> axial force (tension positive; 0 for the bushing and the torsion).
module force_elements
  use ancf_kinds, only: dp
  use drives, only: drive_eval, drive_table, drive_hermite
  implicit none
  private
  public :: force_element_eval, force_element_slots, force_element_parameters
  public :: force_element_initial_stress

  integer, parameter, public :: fe_spring_damper = 1, fe_bushing = 2, fe_cylinder = 3, &
                                fe_torsion = 4
  integer, parameter, public :: fe_reaction_count = 7

contains

  !> Number of slots of a kind (0: unknown kind).
  pure integer function force_element_slots(kind) result(n)
    integer, intent(in) :: kind
    select case (kind)
    case (fe_spring_damper, fe_cylinder)
      n = 2
    case (fe_bushing)
      n = 8
    case (fe_torsion)
      n = 5
    case default
      n = 0
    end select
  end function force_element_slots

  !> Number of parameters of a kind (spring: k, c, L0, F0; cylinder: k, c; bushing: k(3),
  !> k_r(3), c(3), c_r(3); torsion: k_t, c_t).
  pure integer function force_element_parameters(kind) result(n)
    integer, intent(in) :: kind
    select case (kind)
    case (fe_spring_damper)
      n = 4
    case (fe_cylinder, fe_torsion)
      n = 2
    case (fe_bushing)
      n = 12
    case default
      n = 0
    end select
  end function force_element_parameters

  !> One element at its slot values x(3, ns) and rates xd(3, ns): the generalized force on
  !> the slots, its derivatives by x (stiffness) and by xd (damping) as (3, ns, 3, ns), the
  !> potential energy, the dissipated power (>= 0), the drive's power into the system and
  !> the reaction. length, length_rate: the cylinder's l(t), l'(t) (unused otherwise);
  !> table_kind (0: none), table: a spring's force-deflection table (drives module layout).
  !> info = 1: unknown kind or wrong sizes, 2: the points coincide (no line of action),
  !> 3: the table cannot be evaluated.
  pure subroutine force_element_eval(kind, params, table_kind, table, x, xd, length, &
                                     length_rate, force, stiffness, damping, energy, &
                                     dissipation, drive_power, reaction, info)
    integer, intent(in) :: kind, table_kind
    real(dp), intent(in) :: params(:), table(:), x(:, :), xd(:, :), length, length_rate
    real(dp), intent(out) :: force(:, :), stiffness(:, :, :, :), damping(:, :, :, :)
    real(dp), intent(out) :: energy, dissipation, drive_power, reaction(fe_reaction_count)
    integer, intent(out) :: info
    real(dp) :: grad(3, size(x, 2)), hess(3, size(x, 2), 3, size(x, 2))
    real(dp) :: d(3), span, unit(3), f, slope, c, rate, total, deflection, dummy, m, g_unit(3)
    integer :: ns, i
    info = 0
    force = 0.0_dp
    stiffness = 0.0_dp
    damping = 0.0_dp
    energy = 0.0_dp
    dissipation = 0.0_dp
    drive_power = 0.0_dp
    reaction = 0.0_dp
    ns = force_element_slots(kind)
    if (ns == 0 .or. size(x, 2) /= ns .or. size(xd, 2) /= ns .or. size(params) < &
        force_element_parameters(kind)) then
      info = 1
      return
    end if
    select case (kind)
    case (fe_spring_damper, fe_cylinder)
      d = x(:, 2) - x(:, 1)
      span = norm2(d)
      if (span <= tiny(1.0_dp) * 1.0e10_dp) then
        info = 2
        return
      end if
      call length_measure(x, span, grad, hess)
      rate = sum(grad * xd)
      c = params(2)
      if (kind == fe_spring_damper) then
        deflection = span - params(3)
        if (table_kind > 0) then
          call drive_eval(table_kind, table, deflection, f, slope, dummy, info)
          if (info /= 0) then
            info = 3
            return
          end if
          call table_integral(table_kind, table, deflection, energy, info)
          if (info /= 0) then
            info = 3
            return
          end if
        else
          f = params(4) + params(1) * deflection
          slope = params(1)
          energy = params(4) * deflection + 0.5_dp * params(1) * deflection**2
        end if
        total = f + c * rate
        dissipation = c * rate**2
      else
        deflection = span - length
        f = params(1) * deflection
        slope = params(1)
        energy = 0.5_dp * params(1) * deflection**2
        total = f + c * (rate - length_rate)
        dissipation = c * (rate - length_rate)**2
        drive_power = -total * length_rate
      end if
      call accumulate(grad, hess, xd, total, slope, c, force, stiffness, damping)
      unit = d / span
      reaction(1:3) = -total * unit
      reaction(7) = total
    case (fe_bushing)
      d = x(:, 2) - x(:, 1)
      do i = 1, 6                      ! translations u_i, then rotations theta_i
        call bushing_measure(i, x, m, grad, hess)
        call elastic(params(i), params(6 + i), m, grad, hess, xd, force, stiffness, damping, &
                     energy, dissipation, total)
        g_unit = x(:, 2 + modulo(i - 1, 3) + 1) / &
                 max(norm2(x(:, 2 + modulo(i - 1, 3) + 1)), tiny(1.0_dp))
        if (i <= 3) then
          reaction(1:3) = reaction(1:3) - total * g_unit
        else
          reaction(4:6) = reaction(4:6) - total * g_unit
        end if
      end do
    case (fe_torsion)
      call turn_measure(x, m, grad, hess, info)
      if (info /= 0) return
      call elastic(params(1), params(2), m, grad, hess, xd, force, stiffness, damping, &
                   energy, dissipation, total)
      g_unit = [x(2, 3) * x(3, 4) - x(3, 3) * x(2, 4), x(3, 3) * x(1, 4) - x(1, 3) * x(3, 4), &
                x(1, 3) * x(2, 4) - x(2, 3) * x(1, 4)]
      reaction(4:6) = -total * g_unit / max(norm2(g_unit), tiny(1.0_dp))
    end select
  end subroutine force_element_eval

  !> The initial-stress stiffness of one element (the classical linear buckling's geometric
  !> stiffness, python/ancfdrv/solvers/buckling.py): each measure's force f_i at the state
  !> (x, xd) (force_element_eval's: the line's tension, a bushing's or a torsion's force)
  !> times the measure's Hessian at the configuration ``at`` (3, ns): sum f_i(x) d2m_i/dx2
  !> (at), (3, ns, 3, ns). The difference of two states' values at one ``at`` is the
  !> geometric stiffness of the force increment, for a line (f2 - f1) (I - n n^T) / L on
  !> its two slots, without the change of the material part df/dm dm/dx dm/dx^T by the
  !> turn of the line between the states (force_element_eval's stiffness holds both).
  !> info: as force_element_eval's (2 also for ``at``'s points).
  pure subroutine force_element_initial_stress(kind, params, table_kind, table, x, xd, &
                                               length, length_rate, at, stiffness, info)
    integer, intent(in) :: kind, table_kind
    real(dp), intent(in) :: params(:), table(:), x(:, :), xd(:, :), length, length_rate
    real(dp), intent(in) :: at(:, :)
    real(dp), intent(out) :: stiffness(:, :, :, :)
    integer, intent(out) :: info
    real(dp) :: grad(3, size(x, 2)), hess(3, size(x, 2), 3, size(x, 2))
    real(dp) :: force(3, size(x, 2)), tangent(3, size(x, 2), 3, size(x, 2))
    real(dp) :: damping(3, size(x, 2), 3, size(x, 2)), energy, dissipation, power, m, span
    real(dp) :: reaction(fe_reaction_count)
    integer :: i
    stiffness = 0.0_dp
    if (size(at, 2) /= size(x, 2)) then
      info = 1
      return
    end if
    call force_element_eval(kind, params, table_kind, table, x, xd, length, length_rate, &
                            force, tangent, damping, energy, dissipation, power, reaction, info)
    if (info /= 0) return
    select case (kind)
    case (fe_spring_damper, fe_cylinder)
      span = norm2(at(:, 2) - at(:, 1))
      if (span <= tiny(1.0_dp) * 1.0e10_dp) then
        info = 2
        return
      end if
      call length_measure(at, span, grad, hess)
      stiffness = reaction(7) * hess
    case (fe_bushing)                  ! bilinear measures: their Hessians are constant
      do i = 1, 6
        call bushing_measure(i, x, m, grad, hess)
        stiffness = stiffness + (params(i) * m + params(6 + i) * sum(grad * xd)) * hess
      end do
    case (fe_torsion)
      call turn_measure(x, m, grad, hess, info)
      if (info /= 0) return
      m = params(1) * m + params(2) * sum(grad * xd)
      call turn_measure(at, span, grad, hess, info)
      if (info /= 0) return
      stiffness = m * hess
    end select
  end subroutine force_element_initial_stress

  !> The bushing's measure i (1-3: the translation u_i = g_i . (p2 - p1); 4-6: the small
  !> rotation theta_{i-3} = (g_k . h_j - g_j . h_k) / 2, (i-3, j, k) cyclic), its gradient
  !> and its (constant) Hessian on the slots.
  pure subroutine bushing_measure(i, x, m, grad, hess)
    integer, intent(in) :: i
    real(dp), intent(in) :: x(:, :)
    real(dp), intent(out) :: m, grad(:, :), hess(:, :, :, :)
    integer :: r, j, k
    grad = 0.0_dp
    hess = 0.0_dp
    if (i <= 3) then
      call bilinear(2 + i, 2, 1.0_dp, x, grad, hess)
      call bilinear(2 + i, 1, -1.0_dp, x, grad, hess)
      m = dot_product(x(:, 2 + i), x(:, 2) - x(:, 1))
      return
    end if
    r = i - 3
    j = modulo(r, 3) + 1
    k = modulo(r + 1, 3) + 1
    call bilinear(2 + k, 5 + j, 0.5_dp, x, grad, hess)
    call bilinear(2 + j, 5 + k, -0.5_dp, x, grad, hess)
    m = 0.5_dp * (dot_product(x(:, 2 + k), x(:, 5 + j)) - dot_product(x(:, 2 + j), x(:, 5 + k)))
  end subroutine bushing_measure

  !> The torsion's measure theta = atan2(s, c), s = g2 . h1, c = g1 . h1 (slots 3, 4, 5), its
  !> gradient and Hessian: theta_c grad c + theta_s grad s, and theta_c H_c + theta_s H_s +
  !> theta_cc gc gc^T + theta_ss gs gs^T + theta_cs (gc gs^T + gs gc^T) with theta_c = -s/r2,
  !> theta_s = c/r2, theta_cc = 2cs/r2^2 = -theta_ss, theta_cs = (s^2 - c^2)/r2^2, r2 = c^2 + s^2.
  !> info = 2: h1 is normal to the plane of g1, g2 (no angle).
  pure subroutine turn_measure(x, m, grad, hess, info)
    real(dp), intent(in) :: x(:, :)
    real(dp), intent(out) :: m, grad(:, :), hess(:, :, :, :)
    integer, intent(out) :: info
    real(dp) :: gc(3, size(x, 2)), gs(3, size(x, 2)), hc(3, size(x, 2), 3, size(x, 2))
    real(dp) :: hs(3, size(x, 2), 3, size(x, 2)), c, s, r2
    integer :: a, b, i, j
    info = 0
    gc = 0.0_dp
    gs = 0.0_dp
    hc = 0.0_dp
    hs = 0.0_dp
    call bilinear(3, 5, 1.0_dp, x, gc, hc)
    call bilinear(4, 5, 1.0_dp, x, gs, hs)
    c = dot_product(x(:, 3), x(:, 5))
    s = dot_product(x(:, 4), x(:, 5))
    r2 = c**2 + s**2
    if (r2 <= tiny(1.0_dp) * 1.0e10_dp) then
      info = 2
      return
    end if
    m = atan2(s, c)
    grad = (c * gs - s * gc) / r2
    hess = (c * hs - s * hc) / r2
    do b = 1, size(x, 2)
      do j = 1, 3
        do a = 1, size(x, 2)
          do i = 1, 3
            hess(i, a, j, b) = hess(i, a, j, b) + (2.0_dp * c * s * (gc(i, a) * gc(j, b) - &
              gs(i, a) * gs(j, b)) + (s**2 - c**2) * (gc(i, a) * gs(j, b) + gs(i, a) * &
              gc(j, b))) / r2**2
          end do
        end do
      end do
    end do
  end subroutine turn_measure

  !> A linear elastic measure m with stiffness k and damping c: f = k m + c m'.
  pure subroutine elastic(k, c, m, grad, hess, xd, force, stiffness, damping, energy, &
                          dissipation, total)
    real(dp), intent(in) :: k, c, m, grad(:, :), hess(:, :, :, :), xd(:, :)
    real(dp), intent(inout) :: force(:, :), stiffness(:, :, :, :), damping(:, :, :, :)
    real(dp), intent(inout) :: energy, dissipation
    real(dp), intent(out) :: total
    real(dp) :: rate
    rate = sum(grad * xd)
    total = k * m + c * rate
    energy = energy + 0.5_dp * k * m**2
    dissipation = dissipation + c * rate**2
    call accumulate(grad, hess, xd, total, k, c, force, stiffness, damping)
  end subroutine elastic

  !> Adds one measure's force total * dm/dx and its derivatives (module documentation);
  !> explicit loops (spread temporaries made the 8-slot bushing 10 times slower).
  pure subroutine accumulate(grad, hess, xd, total, slope, c, force, stiffness, damping)
    real(dp), intent(in) :: grad(:, :), hess(:, :, :, :), xd(:, :), total, slope, c
    real(dp), intent(inout) :: force(:, :), stiffness(:, :, :, :), damping(:, :, :, :)
    real(dp) :: column(3, size(grad, 2))
    integer :: ns, s, w, i, j
    ns = size(grad, 2)
    force = force + total * grad
    stiffness = stiffness + total * hess
    ! d f / d x_w = slope dm/dx_w + c d m'/d x_w, with d m'/d x_w = sum_s H(s, w)^T xd_s
    do w = 1, ns
      do j = 1, 3
        column(j, w) = slope * grad(j, w)
        if (c /= 0.0_dp) column(j, w) = column(j, w) + c * sum(hess(:, :, j, w) * xd)
      end do
    end do
    do w = 1, ns
      do j = 1, 3
        if (column(j, w) == 0.0_dp .and. (c == 0.0_dp .or. grad(j, w) == 0.0_dp)) cycle
        do s = 1, ns
          do i = 1, 3
            stiffness(i, s, j, w) = stiffness(i, s, j, w) + grad(i, s) * column(j, w)
            damping(i, s, j, w) = damping(i, s, j, w) + c * grad(i, s) * grad(j, w)
          end do
        end do
      end do
    end do
  end subroutine accumulate

  !> The gradient and Hessian of L = |x2 - x1| on slots 1, 2.
  pure subroutine length_measure(x, span, grad, hess)
    real(dp), intent(in) :: x(:, :), span
    real(dp), intent(out) :: grad(:, :), hess(:, :, :, :)
    real(dp) :: unit(3), projector(3, 3)
    integer :: i
    grad = 0.0_dp
    hess = 0.0_dp
    unit = (x(:, 2) - x(:, 1)) / span
    grad(:, 1) = -unit
    grad(:, 2) = unit
    projector = -spread(unit, 2, 3) * spread(unit, 1, 3)
    do i = 1, 3
      projector(i, i) = projector(i, i) + 1.0_dp
    end do
    projector = projector / span
    hess(:, 1, :, 1) = projector
    hess(:, 2, :, 2) = projector
    hess(:, 1, :, 2) = -projector
    hess(:, 2, :, 1) = -projector
  end subroutine length_measure

  !> Adds w x_a . x_b to a measure's gradient and Hessian.
  pure subroutine bilinear(a, b, w, x, grad, hess)
    integer, intent(in) :: a, b
    real(dp), intent(in) :: w, x(:, :)
    real(dp), intent(inout) :: grad(:, :), hess(:, :, :, :)
    integer :: i
    grad(:, a) = grad(:, a) + w * x(:, b)
    grad(:, b) = grad(:, b) + w * x(:, a)
    do i = 1, 3
      hess(i, a, i, b) = hess(i, a, i, b) + w
      hess(i, b, i, a) = hess(i, b, i, a) + w
    end do
  end subroutine bilinear

  !> The integral of a table's force from 0 to the deflection: 3-point Gauss on every piece
  !> between the table's points (exact for the linear and the cubic Hermite pieces, and for
  !> the constant extension outside the table). info = 2: a malformed table.
  pure subroutine table_integral(table_kind, table, deflection, integral, info)
    integer, intent(in) :: table_kind
    real(dp), intent(in) :: table(:), deflection
    real(dp), intent(out) :: integral
    integer, intent(out) :: info
    real(dp), parameter :: nodes(3) = [-sqrt(0.6_dp), 0.0_dp, sqrt(0.6_dp)]
    real(dp), parameter :: weights(3) = [5.0_dp, 8.0_dp, 5.0_dp] / 9.0_dp
    real(dp) :: lo, hi, a, b, f, slope, dummy, sign_of
    integer :: n, p, q
    integral = 0.0_dp
    info = 0
    if (table_kind == drive_table) then
      n = size(table) / 2
    else if (table_kind == drive_hermite) then
      n = size(table) / 3
    else
      info = 2
      return
    end if
    if (deflection == 0.0_dp) return
    lo = min(0.0_dp, deflection)
    hi = max(0.0_dp, deflection)
    sign_of = merge(1.0_dp, -1.0_dp, deflection > 0.0_dp)
    a = lo
    do p = 1, n + 1
      if (p <= n) then
        b = table(p)
        if (b <= a) cycle
        b = min(b, hi)
      else
        b = hi
      end if
      if (b <= a) cycle
      do q = 1, 3
        call drive_eval(table_kind, table, 0.5_dp * (a + b) + 0.5_dp * (b - a) * nodes(q), f, &
                        slope, dummy, info)
        if (info /= 0) return
        integral = integral + 0.5_dp * (b - a) * weights(q) * f
      end do
      a = b
      if (a >= hi) exit
    end do
    integral = sign_of * integral
  end subroutine table_integral

end module force_elements
