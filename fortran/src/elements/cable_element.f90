!> The gradient-deficient ANCF cable element in 3D (Euler-Bernoulli): per node the position
!> r and the slope r_x (6 coordinates), cubic Hermite interpolation along the element,
!>   r(xi) = S1 r_1 + L S2 r_1,x + S3 r_2 + L S4 r_2,x,   xi = x / L in [0, 1],
!>   S1 = 1 - 3 xi^2 + 2 xi^3, S2 = xi - 2 xi^2 + xi^3, S3 = 3 xi^2 - 2 xi^3, S4 = xi^3 - xi^2
!> (Gerstmayr and Shabana, Nonlinear Dynamics 45 (2006) 109-130; Exudyn's ANCFCable2D and
!> ANCFCable). Nodal vectors as q(3, 4) = [r_1, r_1,x, r_2, r_2,x]; the element shape rows
!> below carry the factor L of the slopes.
!>
!> Strain energy of a straight, unstrained reference (x the reference arc length):
!>   U = 1/2 int EA eps^2 dx + 1/2 int EI kappa^2 dx,
!>   eps = (r' . r' - 1) / 2                          (axial Green strain),
!>   kappa^2 = |r' x r''|^2 / |r'|^6 = ((r'.r')(r''.r'') - (r'.r'')^2) / (r'.r')^3
!> (the exact curvature of the centre line, not the simplified r''.r'' of the small-strain
!> cable). Both are invariant under rigid motions (a translation leaves r', r'' alone, a
!> rotation turns them together), so rigid-body modes carry no strain energy at any angle.
!> The cross-section's torsion and shear are not modelled (a cable has no section frame).
!> Gauss points per element: 5 for the axial term (eps^2 is a polynomial of degree 8, exact)
!> and 5 for the bending term (rational).
!>
!> The force is Q = dU/dq and the tangent its analytic derivative K = d^2U/dq^2 (symmetric),
!> from the gradient and Hessian of the point energy w(a, b) in a = r', b = r'':
!>   dw/da = EA eps a + EI/2 df/da,  dw/db = EI/2 df/db,  f = g / h,
!>   g = (a.a)(b.b) - (a.b)^2,  h = (a.a)^3  (the quotient rule twice, below).
!>
!> Rope (tension_only): the axial law carries no compression, point by point,
!>   w_axial = EA/2 max(eps, 0)^2,   N = EA max(eps, 0)   (the force dw/da = N a),
!> exact and piecewise: the energy is C1 (the force is continuous, zero at eps = 0) and the
!> tangent jumps there, from EA (a a^T + eps I) on the taut side to 0 on the slack side.
!> The tangent is the exact one of each side; only in the band -slack_band < eps <= 0 (a
!> state unstrained to rounding, e.g. the straight reference) it keeps the taut side's
!> EA a a^T, the one-sided derivative at eps = 0+, so that a rope at rest in its reference
!> still has its axial stiffness in a static Newton step. A rope's bending energy is
!> EI/2 |r' x r''|^2 = EI/2 kappa^2 |r'|^6 (kappa^2 to within the strain's size; EI a small
!> model parameter): the exact curvature above is singular where r' vanishes, and a slack
!> rope folding onto itself passes r' = 0; |r' x r''|^2 is a polynomial, zero for any
!> straight state (stretched unevenly or not) and unchanged by rigid motions.
!>
!> Kelvin-Voigt damping (damping_time tau > 0, the nodal rates given): the axial force
!> adds N_d = EA tau eps', eps' = a . a' (the bending is not damped). For a rope only in
!> tension (eps > 0) and clipped so that the total EA eps + N_d never goes below zero (a
!> rope that unloads faster than its damping allows goes slack, it never pushes). The
!> dissipation is sum w N_d eps' >= 0; the tangent dQ/dq + rate_factor dQ/dq' of the
!> damping force, EA tau (a a'^T + eps' I + rate_factor a a^T), is not symmetric.
module cable_element
  use ancf_kinds, only: dp
  use quadrature, only: gauss_legendre
  use element_sets, only: local_element_set, loop_work, threaded_work, local_set_forces, &
                          local_energy_power
  implicit none
  private
  public :: cable_shape, cable_mass, cable_gravity, cable_element_force, cable_set
  public :: cable_rule, cable_element_rows, cable_midpoint_force, cable_stress_stiffness

  !> Gauss points per element.
  integer, parameter, public :: cable_points = 5
  !> Coordinates per node and per element.
  integer, parameter, public :: cable_node_dofs = 6, cable_dofs = 12
  !> A rope's Green strain above -slack_band counts as taut for the tangent (not for the
  !> force): the reference, unstrained to rounding, keeps its axial stiffness.
  real(dp), parameter, public :: slack_band = 1.0e-12_dp

  !> The Gauss rule with the length-free factors of the shape rows at its points (the
  !> numerators of cable_shape's slope and second rows: slope = [s1 / L, s2, s3 / L, s4],
  !> second = [c1 / L^2, c2 / L, c3 / L^2, c4 / L]) and the half weights (weight = w/2 L):
  !> computed once per set instead of in every element call, the same numbers bitwise.
  type :: cable_point_rule
    real(dp) :: slope(4, cable_points) = 0.0_dp, second(4, cable_points) = 0.0_dp
    real(dp) :: half_weight(cable_points) = 0.0_dp
  end type cable_point_rule

  !> The family's element set (element_sets): element lengths and the section's axial and
  !> bending stiffnesses EA, EI (one material and section per set); tension_only: a rope;
  !> rule: cable_rule's table (set by the constructor).
  type, extends(local_element_set) :: cable_set
    real(dp), allocatable :: lengths(:)
    real(dp) :: axial_stiffness = 0.0_dp, bending_stiffness = 0.0_dp
    logical :: tension_only = .false.
    type(cable_point_rule) :: rule
    ! each element's shape rows at the rule's points (rule_rows: slope, second) and its
    ! point weights (half_weight L), computed once per set (cable_element_rows): the same
    ! numbers as in every call, without their eight divisions a point
    real(dp), allocatable :: slope_rows(:, :, :), second_rows(:, :, :), weights(:, :)
  contains
    procedure :: forces => cable_set_forces
    procedure :: column_forces => cable_column_forces
    procedure :: selected_forces => cable_selected_forces
    procedure :: energy_power => cable_set_energy_power
    procedure :: element_forces => cable_element_forces
    procedure :: element_energy => cable_element_energy
    procedure :: midpoint_forces => cable_midpoint_forces
  end type cable_set

contains

  !> Shape rows at xi: the position (shape), the first and second derivatives with respect
  !> to x (slope, second), each (4) acting on q(3, 4) = [r_1, r_1,x, r_2, r_2,x].
  pure subroutine cable_shape(xi, length, shape, slope, second)
    real(dp), intent(in) :: xi, length
    real(dp), intent(out) :: shape(4), slope(4), second(4)
    shape = [1.0_dp - 3.0_dp * xi**2 + 2.0_dp * xi**3, length * (xi - 2.0_dp * xi**2 + xi**3), &
             3.0_dp * xi**2 - 2.0_dp * xi**3, length * (xi**3 - xi**2)]
    slope = [(-6.0_dp * xi + 6.0_dp * xi**2) / length, 1.0_dp - 4.0_dp * xi + 3.0_dp * xi**2, &
             (6.0_dp * xi - 6.0_dp * xi**2) / length, 3.0_dp * xi**2 - 2.0_dp * xi]
    second = [(-6.0_dp + 12.0_dp * xi) / length**2, (-4.0_dp + 6.0_dp * xi) / length, &
              (6.0_dp - 12.0_dp * xi) / length**2, (6.0_dp * xi - 2.0_dp) / length]
  end subroutine cable_shape

  !> The element's Gauss rule and the length-free factors of the shape rows at its points
  !> (cable_point_rule). info /= 0: the rule is not available.
  pure subroutine cable_rule(rule, info)
    type(cable_point_rule), intent(out) :: rule
    integer, intent(out) :: info
    real(dp) :: xg(cable_points), wg(cable_points), xi
    integer :: p
    call gauss_legendre(cable_points, xg, wg, info)
    if (info /= 0) return
    do p = 1, cable_points
      xi = 0.5_dp * (xg(p) + 1.0_dp)
      rule%slope(:, p) = [-6.0_dp * xi + 6.0_dp * xi**2, 1.0_dp - 4.0_dp * xi + 3.0_dp * xi**2, &
                          6.0_dp * xi - 6.0_dp * xi**2, 3.0_dp * xi**2 - 2.0_dp * xi]
      rule%second(:, p) = [-6.0_dp + 12.0_dp * xi, -4.0_dp + 6.0_dp * xi, &
                           6.0_dp - 12.0_dp * xi, 6.0_dp * xi - 2.0_dp]
      rule%half_weight(p) = 0.5_dp * wg(p)
    end do
  end subroutine cable_rule

  !> The set's per-element rows and weights (cable_set: slope_rows, second_rows (4, points,
  !> nel), weights (points, nel)) from its rule and lengths.
  pure subroutine cable_element_rows(set)
    type(cable_set), intent(inout) :: set
    integer :: el, p
    allocate (set%slope_rows(4, cable_points, set%nel), set%second_rows(4, cable_points, set%nel), &
              set%weights(cable_points, set%nel))
    do el = 1, set%nel
      do p = 1, cable_points
        call rule_rows(set%rule, p, set%lengths(el), set%slope_rows(:, p, el), &
                       set%second_rows(:, p, el))
        set%weights(p, el) = set%rule%half_weight(p) * set%lengths(el)
      end do
    end do
  end subroutine cable_element_rows

  !> The slope and second rows of cable_shape at the rule's point p for length L (the same
  !> numbers: the same numerators divided by the same powers of L).
  pure subroutine rule_rows(rule, p, length, slope, second)
    type(cable_point_rule), intent(in) :: rule
    integer, intent(in) :: p
    real(dp), intent(in) :: length
    real(dp), intent(out) :: slope(4), second(4)
    real(dp) :: length_squared
    length_squared = length**2
    slope(1) = rule%slope(1, p) / length
    slope(2) = rule%slope(2, p)
    slope(3) = rule%slope(3, p) / length
    slope(4) = rule%slope(4, p)
    second(1) = rule%second(1, p) / length_squared
    second(2) = rule%second(2, p) / length
    second(3) = rule%second(3, p) / length_squared
    second(4) = rule%second(4, p) / length
  end subroutine rule_rows

  !> The element mass of the scalar shapes, Mbar = rho A int S S^T dx (4 x 4; the element
  !> mass is kron(Mbar, I3)), in closed form: rho A L / 420 [156, 22L, 54, -13L; ...].
  pure subroutine cable_mass(length, mass_per_length, mass)
    real(dp), intent(in) :: length, mass_per_length
    real(dp), intent(out) :: mass(4, 4)
    real(dp) :: l
    l = length
    mass = reshape([156.0_dp, 22.0_dp * l, 54.0_dp, -13.0_dp * l, &
                    22.0_dp * l, 4.0_dp * l**2, 13.0_dp * l, -3.0_dp * l**2, &
                    54.0_dp, 13.0_dp * l, 156.0_dp, -22.0_dp * l, &
                    -13.0_dp * l, -3.0_dp * l**2, -22.0_dp * l, 4.0_dp * l**2], [4, 4])
    mass = mass * mass_per_length * length / 420.0_dp
  end subroutine cable_mass

  !> Generalized force (3, 4) of a uniform load per length (3): load int S dx, in closed
  !> form load [L/2, L^2/12, L/2, -L^2/12].
  pure subroutine cable_gravity(length, load, force)
    real(dp), intent(in) :: length, load(3)
    real(dp), intent(out) :: force(3, 4)
    force(:, 1) = 0.5_dp * length * load
    force(:, 2) = length**2 / 12.0_dp * load
    force(:, 3) = 0.5_dp * length * load
    force(:, 4) = -length**2 / 12.0_dp * load
  end subroutine cable_gravity

  !> Elastic force dU/dq (12), strain energy and, when want_tangent, the tangent d^2U/dq^2
  !> (12 x 12) of one element of length L at its nodal vectors q(3, 4); tension_only
  !> (default .false.): the rope's axial law. With the nodal rates q'(3, 4), damping_time
  !> tau > 0, rate_factor and dissipation all present: the axial Kelvin-Voigt damping (module
  !> header), the force includes the damping force, dissipation is its power and the tangent
  !> is dQ/dq + rate_factor dQ/dq'. info = 2: r' vanished at a Gauss point (the curvature is
  !> undefined).
  pure subroutine cable_element_force(q, length, axial_stiffness, bending_stiffness, &
                                      want_tangent, force, energy, tangent, info, tension_only, &
                                      rates, damping_time, rate_factor, dissipation)
    real(dp), intent(in) :: q(3, 4), length, axial_stiffness, bending_stiffness
    logical, intent(in) :: want_tangent
    logical, intent(in), optional :: tension_only
    real(dp), intent(out) :: force(cable_dofs), energy, tangent(cable_dofs, cable_dofs)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: rates(3, 4), damping_time, rate_factor
    real(dp), intent(out), optional :: dissipation
    type(cable_point_rule) :: rule
    logical :: rope
    rope = .false.
    if (present(tension_only)) rope = tension_only
    call cable_rule(rule, info)
    if (info /= 0) return
    call rule_element_force(q, length, rule, axial_stiffness, bending_stiffness, want_tangent, &
                            force, energy, tangent, info, rope, rates, damping_time, &
                            rate_factor, dissipation)
  end subroutine cable_element_force

  !> The initial-stress stiffness of the axial force increment (the classical linear
  !> buckling's geometric stiffness, python/ancfdrv/solvers/buckling.py) of one element:
  !> sum over the Gauss points of w dN S'^T S' x I3 (12 x 12), dN = EA r'(q) . r'(dq) the
  !> axial force of the strain's derivative at q along dq (exact for the difference of two
  !> states when q is their middle: the Green strain is quadratic). The axial part of the
  !> tangent is EA (a a^T + eps I): this is its N I part for the increment, without the
  !> material part's change; the bending's (EI kappa, slender cables) is left out. A rope
  !> (tension_only) adds nothing where the strain at q is not positive (slack).
  pure subroutine cable_stress_stiffness(q, dq, length, axial_stiffness, tension_only, &
                                         tangent, info)
    real(dp), intent(in) :: q(3, 4), dq(3, 4), length, axial_stiffness
    logical, intent(in) :: tension_only
    real(dp), intent(out) :: tangent(cable_dofs, cable_dofs)
    integer, intent(out) :: info
    type(cable_point_rule) :: rule
    real(dp) :: slope(4), second(4), a(3), geometric(4, 4), increment
    integer :: p, i, j, r
    tangent = 0.0_dp
    call cable_rule(rule, info)
    if (info /= 0) return
    geometric = 0.0_dp
    do p = 1, cable_points
      call rule_rows(rule, p, length, slope, second)
      a = matmul(q, slope)
      if (tension_only .and. dot_product(a, a) <= 1.0_dp) cycle
      increment = rule%half_weight(p) * length * axial_stiffness * &
                  dot_product(a, matmul(dq, slope))
      do j = 1, 4
        do i = 1, 4
          geometric(i, j) = geometric(i, j) + increment * slope(i) * slope(j)
        end do
      end do
    end do
    do j = 1, 4
      do i = 1, 4
        do r = 1, 3
          tangent(3 * i - 3 + r, 3 * j - 3 + r) = geometric(i, j)
        end do
      end do
    end do
  end subroutine cable_stress_stiffness

  !> cable_element_force with the element's rule given (cable_rule); damped when the rates,
  !> damping_time, rate_factor and dissipation are present.
  pure subroutine rule_element_force(q, length, rule, axial_stiffness, bending_stiffness, &
                                     want_tangent, force, energy, tangent, info, rope, rates, &
                                     damping_time, rate_factor, dissipation)
    real(dp), intent(in) :: q(3, 4), length, axial_stiffness, bending_stiffness
    type(cable_point_rule), intent(in) :: rule
    logical, intent(in) :: want_tangent, rope
    real(dp), intent(out) :: force(cable_dofs), energy, tangent(cable_dofs, cable_dofs)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: rates(3, 4), damping_time, rate_factor
    real(dp), intent(out), optional :: dissipation
    real(dp) :: slope(4), second(4)
    real(dp) :: a(3), b(3), grad_a(3), grad_b(3), hessian(6, 6), weight, point_energy
    real(dp) :: a_rate(3), strain, strain_rate, damping_force, viscous, identity(3, 3)
    logical :: damped
    integer :: p, i
    damped = present(rates) .and. present(damping_time) .and. present(rate_factor) .and. &
             present(dissipation)
    info = 0
    force = 0.0_dp
    energy = 0.0_dp
    if (want_tangent) tangent = 0.0_dp
    if (damped) then
      dissipation = 0.0_dp
      viscous = axial_stiffness * damping_time
      identity = 0.0_dp
      do i = 1, 3
        identity(i, i) = 1.0_dp
      end do
    end if
    do p = 1, cable_points
      call rule_rows(rule, p, length, slope, second)
      weight = rule%half_weight(p) * length
      a = matmul(q, slope)
      b = matmul(q, second)
      call point_derivatives(a, b, axial_stiffness, bending_stiffness, want_tangent, &
                             point_energy, grad_a, grad_b, hessian, info, rope)
      if (info /= 0) return
      energy = energy + weight * point_energy
      if (damped) then
        a_rate = matmul(rates, slope)
        strain = 0.5_dp * (dot_product(a, a) - 1.0_dp)
        strain_rate = dot_product(a, a_rate)
        if (rope .and. strain <= 0.0_dp) then
          damping_force = 0.0_dp                              ! slack: no damping either
        else if (rope .and. axial_stiffness * strain + viscous * strain_rate < 0.0_dp) then
          damping_force = -axial_stiffness * strain           ! clipped: the total is zero
          grad_a = grad_a + damping_force * a
          if (want_tangent) hessian(1:3, 1:3) = hessian(1:3, 1:3) &
            - axial_stiffness * (outer(a, a) + strain * identity)
        else
          damping_force = viscous * strain_rate
          grad_a = grad_a + damping_force * a
          if (want_tangent) hessian(1:3, 1:3) = hessian(1:3, 1:3) &
            + viscous * (outer(a, a_rate) + strain_rate * identity + rate_factor * outer(a, a))
        end if
        dissipation = dissipation + weight * damping_force * strain_rate
      end if
      call add_point(slope, second, weight, grad_a, grad_b, hessian, want_tangent, force, &
                     tangent)
    end do
  end subroutine rule_element_force

  !> The strain energy alone of rule_element_force (the same sum of the same point
  !> energies; no gradients, no assembly).
  pure subroutine rule_element_energy(q, length, rule, axial_stiffness, bending_stiffness, &
                                      energy, info, rope)
    real(dp), intent(in) :: q(3, 4), length, axial_stiffness, bending_stiffness
    type(cable_point_rule), intent(in) :: rule
    logical, intent(in) :: rope
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    real(dp) :: slope(4), second(4), a(3), b(3), weight, aa, bb, ab, strain
    logical :: plane
    integer :: p
    info = 0
    energy = 0.0_dp
    ! (in the plane z = 0 the z terms of the sums are +0: the x and y terms alone, the same
    ! numbers)
    plane = all(q(3, :) == 0.0_dp)
    do p = 1, cable_points
      call rule_rows(rule, p, length, slope, second)
      weight = rule%half_weight(p) * length
      if (plane) then
        a(1:2) = matmul(q(1:2, :), slope)
        b(1:2) = matmul(q(1:2, :), second)
        aa = dot_product(a(1:2), a(1:2))
        bb = dot_product(b(1:2), b(1:2))
        ab = dot_product(a(1:2), b(1:2))
      else
        a = matmul(q, slope)
        b = matmul(q, second)
        aa = dot_product(a, a)
        bb = dot_product(b, b)
        ab = dot_product(a, b)
      end if
      strain = 0.5_dp * (aa - 1.0_dp)
      if (rope) then  ! (rope_point_derivatives' energy)
        strain = max(strain, 0.0_dp)
        energy = energy + weight * (0.5_dp * axial_stiffness * strain**2 &
                                    + 0.5_dp * bending_stiffness * (aa * bb - ab**2))
        cycle
      end if
      if (aa <= 0.0_dp) then  ! (point_derivatives' energy)
        info = 2
        return
      end if
      energy = energy + weight * (0.5_dp * axial_stiffness * strain**2 &
                                  + 0.5_dp * bending_stiffness * ((aa * bb - ab**2) / aa**3))
    end do
  end subroutine rule_element_energy

  !> Adds one Gauss point's force (the gradients in a = r', b = r'') and, when want_tangent,
  !> its tangent (the 6 x 6 matrix in (a, b)) to the element's.
  pure subroutine add_point(slope, second, weight, grad_a, grad_b, hessian, want_tangent, &
                            force, tangent)
    real(dp), intent(in) :: slope(4), second(4), weight, grad_a(3), grad_b(3), hessian(6, 6)
    logical, intent(in) :: want_tangent
    real(dp), intent(inout) :: force(cable_dofs), tangent(cable_dofs, cable_dofs)
    real(dp) :: rows(2, 4), s11, s21, s12, s22
    integer :: i, j, r, c
    do i = 1, 4
      force(3 * i - 2:3 * i) = force(3 * i - 2:3 * i) &
                               + weight * (slope(i) * grad_a + second(i) * grad_b)
    end do
    if (.not. want_tangent) return
    rows(1, :) = slope
    rows(2, :) = second
    ! block (i, j) = sum over n, then m (1, 2) of rows(m, i) rows(n, j) H_mn (H_mn the
    ! (m, n) 3 x 3 block of the hessian), from 0, entry by entry; tangent += weight block
    do j = 1, 4
      do i = 1, 4
        s11 = rows(1, i) * rows(1, j)
        s21 = rows(2, i) * rows(1, j)
        s12 = rows(1, i) * rows(2, j)
        s22 = rows(2, i) * rows(2, j)
        do c = 1, 3
          do r = 1, 3
            tangent(3 * i - 3 + r, 3 * j - 3 + c) = tangent(3 * i - 3 + r, 3 * j - 3 + c) &
              + weight * ((((0.0_dp + s11 * hessian(r, c)) + s21 * hessian(3 + r, c)) &
                           + s12 * hessian(r, 3 + c)) + s22 * hessian(3 + r, 3 + c))
          end do
        end do
      end do
    end do
  end subroutine add_point

  !> The point energy w = EA/2 eps^2 + EI/2 kappa^2 at a = r', b = r'', its gradient
  !> (dw/da, dw/db) and, when want_hessian, its Hessian (6 x 6, in (a, b)); tension_only:
  !> the rope's axial law EA/2 max(eps, 0)^2 (module header).
  pure subroutine point_derivatives(a, b, axial_stiffness, bending_stiffness, want_hessian, &
                                    energy, grad_a, grad_b, hessian, info, tension_only)
    real(dp), intent(in) :: a(3), b(3), axial_stiffness, bending_stiffness
    logical, intent(in) :: want_hessian, tension_only
    real(dp), intent(out) :: energy, grad_a(3), grad_b(3), hessian(6, 6)
    integer, intent(out) :: info
    real(dp) :: aa, bb, ab, strain, g, h, f, dg(6), dh(6), df(6), hg(6, 6), hh(6, 6)
    real(dp) :: identity(3, 3)
    integer :: i
    info = 0
    if (tension_only) then
      call rope_point_derivatives(a, b, axial_stiffness, bending_stiffness, want_hessian, &
                                  energy, grad_a, grad_b, hessian)
      return
    end if
    aa = dot_product(a, a)
    bb = dot_product(b, b)
    ab = dot_product(a, b)
    if (aa <= 0.0_dp) then
      info = 2
      return
    end if
    strain = 0.5_dp * (aa - 1.0_dp)
    g = aa * bb - ab**2                                  ! |a x b|^2
    h = aa**3
    f = g / h                                            ! kappa^2
    energy = 0.5_dp * axial_stiffness * strain**2 + 0.5_dp * bending_stiffness * f
    dg(1:3) = 2.0_dp * bb * a - 2.0_dp * ab * b
    dg(4:6) = 2.0_dp * aa * b - 2.0_dp * ab * a
    dh(1:3) = 6.0_dp * aa**2 * a
    dh(4:6) = 0.0_dp
    df = dg / h - g * dh / h**2
    grad_a = axial_stiffness * strain * a + 0.5_dp * bending_stiffness * df(1:3)
    grad_b = 0.5_dp * bending_stiffness * df(4:6)
    if (.not. want_hessian) return
    identity = 0.0_dp
    do i = 1, 3
      identity(i, i) = 1.0_dp
    end do
    hg(1:3, 1:3) = 2.0_dp * bb * identity - 2.0_dp * outer(b, b)
    hg(4:6, 4:6) = 2.0_dp * aa * identity - 2.0_dp * outer(a, a)
    hg(1:3, 4:6) = 4.0_dp * outer(a, b) - 2.0_dp * outer(b, a) - 2.0_dp * ab * identity
    hg(4:6, 1:3) = transpose(hg(1:3, 4:6))
    hh = 0.0_dp
    hh(1:3, 1:3) = 6.0_dp * aa**2 * identity + 24.0_dp * aa * outer(a, a)
    hessian = 0.5_dp * bending_stiffness * (hg / h - (outer6(dg, dh) + outer6(dh, dg)) / h**2 &
                                            - g * hh / h**2 + 2.0_dp * g * outer6(dh, dh) / h**3)
    hessian(1:3, 1:3) = hessian(1:3, 1:3) + axial_stiffness * (outer(a, a) + strain * identity)
  end subroutine point_derivatives

  !> The rope's point energy w = EA/2 max(eps, 0)^2 + EI/2 |r' x r''|^2 at a = r', b = r'',
  !> its gradient and, when want_hessian, its Hessian (module header): a polynomial in the
  !> bending part, defined for every a, including a = 0 (a slack rope folding onto itself).
  pure subroutine rope_point_derivatives(a, b, axial_stiffness, bending_stiffness, &
                                         want_hessian, energy, grad_a, grad_b, hessian)
    real(dp), intent(in) :: a(3), b(3), axial_stiffness, bending_stiffness
    logical, intent(in) :: want_hessian
    real(dp), intent(out) :: energy, grad_a(3), grad_b(3), hessian(6, 6)
    real(dp) :: aa, bb, ab, strain, identity(3, 3)
    logical :: taut_tangent
    integer :: i
    aa = dot_product(a, a)
    bb = dot_product(b, b)
    ab = dot_product(a, b)
    strain = 0.5_dp * (aa - 1.0_dp)
    taut_tangent = strain > -slack_band
    strain = max(strain, 0.0_dp)                         ! slack: no axial force, no energy
    ! bending: EI/2 g with g = |a x b|^2 = (a.a)(b.b) - (a.b)^2
    energy = 0.5_dp * axial_stiffness * strain**2 + 0.5_dp * bending_stiffness * (aa * bb - ab**2)
    grad_a = axial_stiffness * strain * a + bending_stiffness * (bb * a - ab * b)
    grad_b = bending_stiffness * (aa * b - ab * a)
    if (.not. want_hessian) return
    identity = 0.0_dp
    do i = 1, 3
      identity(i, i) = 1.0_dp
    end do
    hessian(1:3, 1:3) = bending_stiffness * (bb * identity - outer(b, b))
    hessian(4:6, 4:6) = bending_stiffness * (aa * identity - outer(a, a))
    hessian(1:3, 4:6) = bending_stiffness * (2.0_dp * outer(a, b) - outer(b, a) - ab * identity)
    hessian(4:6, 1:3) = transpose(hessian(1:3, 4:6))
    if (.not. taut_tangent) return                       ! slack: bending alone
    hessian(1:3, 1:3) = hessian(1:3, 1:3) + axial_stiffness * (outer(a, a) + strain * identity)
  end subroutine rope_point_derivatives

  pure function outer(x, y) result(m)
    real(dp), intent(in) :: x(3), y(3)
    real(dp) :: m(3, 3)
    integer :: j
    do j = 1, 3
      m(:, j) = x * y(j)
    end do
  end function outer

  pure function outer6(x, y) result(m)
    real(dp), intent(in) :: x(6), y(6)
    real(dp) :: m(6, 6)
    integer :: j
    do j = 1, 6
      m(:, j) = x * y(j)
    end do
  end function outer6

  !> The discrete-gradient force of the energy-momentum stepper between q0 and q1 (3, 4).
  !> The point energy is a function of the invariants I = (a.a, b.b, a.b) (a = r', b = r''),
  !> each quadratic in q, so I(q1) - I(q0) = P(q_m) (q1 - q0) exactly with their gradients
  !> P at the midpoint q_m; with a discrete gradient s(I0, I1) of the point energy in the
  !> invariants (s . (I1 - I0) = w(I1) - w(I0)) the force f = sum w_p P(q_m)^T s satisfies
  !> W(q1) - W(q0) = f . (q1 - q0) to round-off (Gonzalez 1996):
  !> * axial EA/2 eps^2 (eps = (a.a - 1)/2, quadratic in I): its derivative at the mean I;
  !>   the rope's EA/2 max(eps, 0)^2: the secant (w1 - w0) / (I1 - I0) where the strain
  !>   changes sign within the step, the mean-I derivative where it does not (the same
  !>   number without the cancellation);
  !> * the rope's bending EI/2 ((a.a)(b.b) - (a.b)^2), quadratic in I: its gradient at the mean I;
  !> * the cable's exact curvature EI/2 ((a.a)(b.b) - (a.b)^2) / (a.a)^3: Gonzalez's
  !>   midpoint gradient in I, grad w(I_m) + c (I1 - I0), c = (w1 - w0 - grad w(I_m).dI) /
  !>   |dI|^2 (the correction left out where |dI| <= gonzalez_floor |I_m|: its size there,
  !>   O(|dI|^3), is below the round-off of w).
  !> The invariants are unchanged by rigid motions, so the force conserves momentum and
  !> angular momentum. The Jacobian df/dq1 (want_tangent) is exact, the derivative of the
  !> cable's correction c included. info = 2: a slope vanished (the cable's curvature is
  !> undefined).
  pure subroutine cable_midpoint_force(q0, q1, length, rule, axial_stiffness, &
                                       bending_stiffness, rope, want_tangent, force, tangent, info)
    real(dp), intent(in) :: q0(3, 4), q1(3, 4), length, axial_stiffness, bending_stiffness
    type(cable_point_rule), intent(in) :: rule
    logical, intent(in) :: rope, want_tangent
    real(dp), intent(out) :: force(cable_dofs), tangent(cable_dofs, cable_dofs)
    integer, intent(out) :: info
    real(dp), parameter :: gonzalez_floor = 1e-6_dp
    real(dp) :: slope(4), second(4), weight, a0(3), b0(3), a1(3), b1(3), am(3), bm(3)
    real(dp) :: inv0(3), inv1(3), invm(3), delta(3), sigma(3), dsigma(3, 3)
    real(dp) :: x0, x1, w0, w1, w_mid, grad(3), hess(3, 3), grad_end(3), hess_end(3, 3)
    real(dp) :: correction, dcorrection(3)
    real(dp) :: grad_a(3), grad_b(3), hessian(6, 6), p_mid(3, 6), p_end(3, 6), identity(3, 3)
    integer :: p, i
    info = 0
    force = 0.0_dp
    if (want_tangent) tangent = 0.0_dp
    hessian = 0.0_dp
    identity = 0.0_dp
    do i = 1, 3
      identity(i, i) = 1.0_dp
    end do
    do p = 1, cable_points
      call rule_rows(rule, p, length, slope, second)
      weight = rule%half_weight(p) * length
      a0 = matmul(q0, slope)
      b0 = matmul(q0, second)
      a1 = matmul(q1, slope)
      b1 = matmul(q1, second)
      am = 0.5_dp * (a0 + a1)
      bm = 0.5_dp * (b0 + b1)
      inv0 = [dot_product(a0, a0), dot_product(b0, b0), dot_product(a0, b0)]
      inv1 = [dot_product(a1, a1), dot_product(b1, b1), dot_product(a1, b1)]
      invm = 0.5_dp * (inv0 + inv1)
      delta = inv1 - inv0
      sigma = 0.0_dp
      dsigma = 0.0_dp
      ! axial: w = EA/8 x^2 (rope: max(x, 0)^2), x = a.a - 1
      x0 = inv0(1) - 1.0_dp
      x1 = inv1(1) - 1.0_dp
      if (.not. rope .or. (x0 >= 0.0_dp .and. x1 >= 0.0_dp)) then
        sigma(1) = 0.125_dp * axial_stiffness * (x0 + x1)
        dsigma(1, 1) = 0.125_dp * axial_stiffness
      else if (x0 > 0.0_dp .or. x1 > 0.0_dp) then
        ! the strain changes sign within the step: the secant (x1 - x0 is at least |x0|, |x1|)
        w0 = 0.125_dp * axial_stiffness * max(x0, 0.0_dp)**2
        w1 = 0.125_dp * axial_stiffness * max(x1, 0.0_dp)**2
        sigma(1) = (w1 - w0) / (x1 - x0)
        dsigma(1, 1) = (0.25_dp * axial_stiffness * max(x1, 0.0_dp) - sigma(1)) / (x1 - x0)
      end if
      if (rope) then
        ! bending EI/2 (i1 i2 - i3^2): its gradient at the mean invariants
        sigma = sigma + 0.5_dp * bending_stiffness * [invm(2), invm(1), -2.0_dp * invm(3)]
        dsigma(1, 2) = dsigma(1, 2) + 0.25_dp * bending_stiffness
        dsigma(2, 1) = dsigma(2, 1) + 0.25_dp * bending_stiffness
        dsigma(3, 3) = dsigma(3, 3) - 0.5_dp * bending_stiffness
      else
        if (min(inv0(1), inv1(1), invm(1)) <= 0.0_dp) then
          info = 2
          return
        end if
        call curvature_energy(invm, bending_stiffness, w_mid, grad, hess)
        sigma = sigma + grad
        dsigma = dsigma + 0.5_dp * hess
        if (norm2(delta) > gonzalez_floor * norm2(invm)) then
          call curvature_energy(inv0, bending_stiffness, w0, grad_end, hess_end)
          call curvature_energy(inv1, bending_stiffness, w1, grad_end, hess_end)
          correction = (w1 - w0 - dot_product(grad, delta)) / dot_product(delta, delta)
          sigma = sigma + correction * delta
          ! d(c dI)/dI1 = dI (dc/dI1)^T + c I, dc/dI1 = (grad w(I1) - grad w(I_m)
          ! - H(I_m) dI / 2 - 2 c dI) / |dI|^2
          dcorrection = (grad_end - grad - 0.5_dp * matmul(hess, delta) &
                         - 2.0_dp * correction * delta) / dot_product(delta, delta)
          do i = 1, 3
            dsigma(:, i) = dsigma(:, i) + delta * dcorrection(i)
            dsigma(i, i) = dsigma(i, i) + correction
          end do
        end if
      end if
      ! f_p = P(q_m)^T sigma, P's rows the invariants' gradients in (a, b)
      grad_a = 2.0_dp * sigma(1) * am + sigma(3) * bm
      grad_b = 2.0_dp * sigma(2) * bm + sigma(3) * am
      if (want_tangent) then
        p_mid = 0.0_dp
        p_end = 0.0_dp
        p_mid(1, 1:3) = 2.0_dp * am
        p_mid(2, 4:6) = 2.0_dp * bm
        p_mid(3, 1:3) = bm
        p_mid(3, 4:6) = am
        p_end(1, 1:3) = 2.0_dp * a1
        p_end(2, 4:6) = 2.0_dp * b1
        p_end(3, 1:3) = b1
        p_end(3, 4:6) = a1
        ! d/d(a1, b1) of P(q_m)^T sigma: P's own change (a half of the midpoint's) and sigma's
        hessian = matmul(transpose(p_mid), matmul(dsigma, p_end))
        hessian(1:3, 1:3) = hessian(1:3, 1:3) + sigma(1) * identity
        hessian(4:6, 4:6) = hessian(4:6, 4:6) + sigma(2) * identity
        hessian(1:3, 4:6) = hessian(1:3, 4:6) + 0.5_dp * sigma(3) * identity
        hessian(4:6, 1:3) = hessian(4:6, 1:3) + 0.5_dp * sigma(3) * identity
      end if
      call add_point(slope, second, weight, grad_a, grad_b, hessian, want_tangent, force, &
                     tangent)
    end do
  end subroutine cable_midpoint_force

  !> The cable's bending energy EI/2 (i1 i2 - i3^2) / i1^3 as a function of the invariants
  !> I = (a.a, b.b, a.b) (i1 > 0), its gradient and Hessian in I.
  pure subroutine curvature_energy(inv, bending_stiffness, energy, grad, hess)
    real(dp), intent(in) :: inv(3), bending_stiffness
    real(dp), intent(out) :: energy, grad(3), hess(3, 3)
    real(dp) :: c
    c = 0.5_dp * bending_stiffness
    energy = c * (inv(2) / inv(1)**2 - inv(3)**2 / inv(1)**3)
    grad = c * [-2.0_dp * inv(2) / inv(1)**3 + 3.0_dp * inv(3)**2 / inv(1)**4, &
                1.0_dp / inv(1)**2, -2.0_dp * inv(3) / inv(1)**3]
    hess = 0.0_dp
    hess(1, 1) = c * (6.0_dp * inv(2) / inv(1)**4 - 12.0_dp * inv(3)**2 / inv(1)**5)
    hess(1, 2) = -2.0_dp * c / inv(1)**3
    hess(2, 1) = hess(1, 2)
    hess(1, 3) = 6.0_dp * c * inv(3) / inv(1)**4
    hess(3, 1) = hess(1, 3)
    hess(3, 3) = -2.0_dp * c / inv(1)**3
  end subroutine curvature_energy

  !> The local_element_set midpoint_forces of a cable set: cable_midpoint_force of element el
  !> (undamped; a damped set has no discrete gradient here: info = 1; a vanished slope 2).
  pure subroutine cable_midpoint_forces(set, el, coords0, coords1, want_tangent, force, &
                                        tangent, info)
    class(cable_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: coords0(:, :), coords1(:, :)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(:), tangent(:, :)
    integer, intent(out) :: info
    if (set%damping_time > 0.0_dp) then
      force = 0.0_dp
      info = 1
      return
    end if
    call cable_midpoint_force(coords0, coords1, set%lengths(el), set%rule, set%axial_stiffness, &
                              set%bending_stiffness, set%tension_only, want_tangent, force, &
                              tangent, info)
  end subroutine cable_midpoint_forces

  !> The element_set element_forces of a cable set: with rates (a damped set) the axial
  !> Kelvin-Voigt damping, else the elastic force alone.
  pure subroutine cable_element_forces(set, el, coords, want_tangent, force, energy, tangent, &
                                       info, rates, rate_factor, dissipation)
    class(cable_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: coords(:, :)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(:), energy, tangent(:, :)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: rates(:, :), rate_factor
    real(dp), intent(out), optional :: dissipation
    real(dp) :: factor, power
    if (present(rates)) then
      factor = 0.0_dp
      if (present(rate_factor)) factor = rate_factor
      call rule_element_force(coords, set%lengths(el), set%rule, set%axial_stiffness, &
                              set%bending_stiffness, want_tangent, force, energy, tangent, &
                              info, set%tension_only, rates, set%damping_time, factor, power)
      if (present(dissipation)) dissipation = power
      return
    end if
    if (present(dissipation)) dissipation = 0.0_dp
    if (.not. want_tangent .and. .not. set%tension_only .and. allocated(set%weights)) then
      if (all(coords(3, :) == 0.0_dp)) then
        call plane_element_force(coords, set%slope_rows(:, :, el), set%second_rows(:, :, el), &
                                 set%weights(:, el), set%axial_stiffness, &
                                 set%bending_stiffness, force, energy, info)
        return
      end if
    end if
    call rule_element_force(coords, set%lengths(el), set%rule, set%axial_stiffness, &
                            set%bending_stiffness, want_tangent, force, energy, tangent, info, &
                            set%tension_only)
  end subroutine cable_element_forces

  !> rule_element_force's force and energy (no tangent, not a rope) of an element in the
  !> plane z = 0 (q(3, :) = 0, as in a scene reduced to the xy plane): the x and y
  !> components of the same expressions in the same order, the z components (+0 there:
  !> the z terms of the sums are +0) left out; the same numbers as rule_element_force, in
  !> two thirds of its vector arithmetic (issue 23: the planar cable's Newton corrections).
  pure subroutine plane_element_force(q, slope_rows, second_rows, weights, axial_stiffness, &
                                      bending_stiffness, force, energy, info)
    real(dp), intent(in) :: q(3, 4), slope_rows(4, cable_points), second_rows(4, cable_points)
    real(dp), intent(in) :: weights(cable_points), axial_stiffness, bending_stiffness
    real(dp), intent(out) :: force(cable_dofs), energy
    integer, intent(out) :: info
    real(dp), dimension(cable_points) :: ax, ay, bx, by, aa, bb, ab, strain, g, h, f
    real(dp), dimension(cable_points) :: point_energy, dg1, dg2, dg3, dg4, dh1, dh2
    real(dp), dimension(cable_points) :: df1, df2, df3, df4, grad_ax, grad_ay, grad_bx, grad_by
    real(dp) :: planar(2, 4)
    integer :: p, i, k
    info = 0
    energy = 0.0_dp
    ! (the points side by side, each with its point's expressions of the one-point form:
    ! a = matmul(q(1:2, :), slope) sums from 0 over the four shapes in order, the dot
    ! products from 0 over x then y; the x and y components summed in a (2, 4) array from
    ! 0, as in force, then stored)
    ax = 0.0_dp
    ay = 0.0_dp
    bx = 0.0_dp
    by = 0.0_dp
    do k = 1, 4
      do p = 1, cable_points
        ax(p) = ax(p) + q(1, k) * slope_rows(k, p)
        ay(p) = ay(p) + q(2, k) * slope_rows(k, p)
        bx(p) = bx(p) + q(1, k) * second_rows(k, p)
        by(p) = by(p) + q(2, k) * second_rows(k, p)
      end do
    end do
    do p = 1, cable_points
      aa(p) = 0.0_dp + ax(p) * ax(p) + ay(p) * ay(p)
      bb(p) = 0.0_dp + bx(p) * bx(p) + by(p) * by(p)
      ab(p) = 0.0_dp + ax(p) * bx(p) + ay(p) * by(p)
    end do
    if (any(aa <= 0.0_dp)) then
      force = 0.0_dp
      info = 2
      return
    end if
    ! (point_derivatives' expressions, component by component)
    do p = 1, cable_points
      strain(p) = 0.5_dp * (aa(p) - 1.0_dp)
      g(p) = aa(p) * bb(p) - ab(p)**2
      h(p) = aa(p)**3
      f(p) = g(p) / h(p)
      point_energy(p) = 0.5_dp * axial_stiffness * strain(p)**2 + 0.5_dp * bending_stiffness * f(p)
      dg1(p) = 2.0_dp * bb(p) * ax(p) - 2.0_dp * ab(p) * bx(p)
      dg2(p) = 2.0_dp * bb(p) * ay(p) - 2.0_dp * ab(p) * by(p)
      dg3(p) = 2.0_dp * aa(p) * bx(p) - 2.0_dp * ab(p) * ax(p)
      dg4(p) = 2.0_dp * aa(p) * by(p) - 2.0_dp * ab(p) * ay(p)
      dh1(p) = 6.0_dp * aa(p)**2 * ax(p)
      dh2(p) = 6.0_dp * aa(p)**2 * ay(p)
      df1(p) = dg1(p) / h(p) - g(p) * dh1(p) / h(p)**2
      df2(p) = dg2(p) / h(p) - g(p) * dh2(p) / h(p)**2
      df3(p) = dg3(p) / h(p) - g(p) * 0.0_dp / h(p)**2
      df4(p) = dg4(p) / h(p) - g(p) * 0.0_dp / h(p)**2
      grad_ax(p) = axial_stiffness * strain(p) * ax(p) + 0.5_dp * bending_stiffness * df1(p)
      grad_ay(p) = axial_stiffness * strain(p) * ay(p) + 0.5_dp * bending_stiffness * df2(p)
      grad_bx(p) = 0.5_dp * bending_stiffness * df3(p)
      grad_by(p) = 0.5_dp * bending_stiffness * df4(p)
    end do
    planar = 0.0_dp
    do p = 1, cable_points
      energy = energy + weights(p) * point_energy(p)
      ! (add_point's force)
      do i = 1, 4
        planar(1, i) = planar(1, i) + weights(p) * (slope_rows(i, p) * grad_ax(p) &
                                                    + second_rows(i, p) * grad_bx(p))
        planar(2, i) = planar(2, i) + weights(p) * (slope_rows(i, p) * grad_ay(p) &
                                                    + second_rows(i, p) * grad_by(p))
      end do
    end do
    do i = 1, 4
      force(3 * i - 2:3 * i - 1) = planar(:, i)
      force(3 * i) = 0.0_dp
    end do
  end subroutine plane_element_force

  !> The element_set forces of a cable set. The force alone of an undamped elastic cable
  !> set below the threading threshold (the Newton corrections of small systems): the loop
  !> of local_set_forces' serial path (element by element, each element's force added as
  !> it is computed, in element order) without its dispatch through gathered_forces and
  !> cable_element_forces, an element of the plane z = 0 by plane_element_force: the same
  !> numbers. Everything else: local_set_forces.
  subroutine cable_set_forces(set, rotation, e, force, energy, info, tangent_values, &
                              tangent_rotation, v, omega_local, rate_factor, dissipation, &
                              tangent_omega)
    class(cable_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), e(:)
    real(dp), intent(inout) :: force(:)
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    real(dp), intent(inout), optional :: tangent_values(:)
    real(dp), intent(in), optional :: tangent_rotation(3, 3)
    real(dp), intent(in), optional :: v(:), omega_local(3), rate_factor, tangent_omega(3)
    real(dp), intent(out), optional :: dissipation
    real(dp) :: coords(3, 4), element_force(cable_dofs), element_energy
    real(dp) :: unused_tangent(cable_dofs, cable_dofs)
    integer :: el, a, node, element_info
    if (present(tangent_values) .or. set%tension_only .or. .not. allocated(set%weights) .or. &
        set%nde /= cable_dofs .or. loop_work(set, .false.) >= threaded_work .or. &
        (present(v) .and. set%damping_time > 0.0_dp)) then
      call local_set_forces(set, rotation, e, force, energy, info, tangent_values, &
                            tangent_rotation, v, omega_local, rate_factor, dissipation, &
                            tangent_omega)
      return
    end if
    info = 0
    energy = 0.0_dp
    if (present(dissipation)) dissipation = 0.0_dp
    do el = 1, set%nel
      do node = 1, 4
        coords(1, node) = e(set%dofs(3 * node - 2, el))
        coords(2, node) = e(set%dofs(3 * node - 1, el))
        coords(3, node) = e(set%dofs(3 * node, el))
      end do
      if (all(coords(3, :) == 0.0_dp)) then
        call plane_element_force(coords, set%slope_rows(:, :, el), set%second_rows(:, :, el), &
                                 set%weights(:, el), set%axial_stiffness, &
                                 set%bending_stiffness, element_force, element_energy, &
                                 element_info)
        if (element_info /= 0) then
          info = 7
          energy = 0.0_dp
          return
        end if
        ! (the z components are +0: adding them to the sums, which start at +0 and so are
        ! never -0, changes nothing)
        do node = 1, 4
          force(set%dofs(3 * node - 2, el)) = force(set%dofs(3 * node - 2, el)) &
                                              + element_force(3 * node - 2)
          force(set%dofs(3 * node - 1, el)) = force(set%dofs(3 * node - 1, el)) &
                                              + element_force(3 * node - 1)
        end do
        energy = energy + element_energy
        cycle
      else
        call rule_element_force(coords, set%lengths(el), set%rule, set%axial_stiffness, &
                                set%bending_stiffness, .false., element_force, element_energy, &
                                unused_tangent, element_info, .false.)
      end if
      if (element_info /= 0) then
        info = 7
        energy = 0.0_dp
        return
      end if
      do a = 1, cable_dofs
        force(set%dofs(a, el)) = force(set%dofs(a, el)) + element_force(a)
      end do
      energy = energy + element_energy
    end do
  end subroutine cable_set_forces

  !> The element_set column_forces of a cable set: its whole forces pass (cable_set_forces'
  !> lean pass is not element_forces': local_column_forces would not give its sums).
  subroutine cable_column_forces(set, rotation, e, wanted, force, info, v, omega_local)
    class(cable_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), e(:)
    logical, intent(in) :: wanted(:)
    real(dp), intent(inout) :: force(:)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: v(:), omega_local(3)
    real(dp) :: energy
    call set%forces(rotation, e, force, energy, info, v=v, omega_local=omega_local)
  end subroutine cable_column_forces

  !> The element_set selected_forces of a cable set: cable_set_forces' lean pass (an
  !> undamped elastic set below the threading threshold; done = .false. otherwise) on the
  !> independent coordinates of a selection: each element's coordinates as to_full gives
  !> them (q0 + e, or q0 where fixed), its force added to the reduced force of each selected
  !> coordinate in element order (each full coordinate's sum of cable_set_forces, from +0,
  !> which to_reduced then adds to 0: the same numbers, the selection being one to one).
  subroutine cable_selected_forces(set, select, offset, e, force, energy, info, done)
    class(cable_set), intent(in) :: set
    integer, intent(in) :: select(:)
    real(dp), intent(in) :: offset(:), e(:)
    real(dp), intent(inout) :: force(:)
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    logical, intent(out) :: done
    real(dp) :: coords(3, 4), element_force(cable_dofs), element_energy
    real(dp) :: unused_tangent(cable_dofs, cable_dofs)
    integer :: el, a, i, k, node, component, element_info
    integer :: selected(cable_dofs)  ! the element's reduced coordinates (0: fixed)
    logical :: plane
    energy = 0.0_dp
    info = 0
    done = .not. (set%tension_only .or. .not. allocated(set%weights) .or. &
                  set%nde /= cable_dofs .or. loop_work(set, .false.) >= threaded_work .or. &
                  set%damping_time > 0.0_dp)
    if (.not. done) return
    do el = 1, set%nel
      ! (each element dof's reduced coordinate looked up once, for the gather and the
      ! scatter; coords by node and component, not by mod and division of a)
      a = 0
      do node = 1, 4
        do component = 1, 3
          a = a + 1
          i = set%dofs(a, el)
          k = select(i)
          selected(a) = k
          if (k > 0) then
            coords(component, node) = offset(i) + e(k)
          else
            coords(component, node) = offset(i)
          end if
        end do
      end do
      plane = all(coords(3, :) == 0.0_dp)
      if (plane) then
        call plane_element_force(coords, set%slope_rows(:, :, el), set%second_rows(:, :, el), &
                                 set%weights(:, el), set%axial_stiffness, &
                                 set%bending_stiffness, element_force, element_energy, &
                                 element_info)
      else
        call rule_element_force(coords, set%lengths(el), set%rule, set%axial_stiffness, &
                                set%bending_stiffness, .false., element_force, element_energy, &
                                unused_tangent, element_info, .false.)
      end if
      if (element_info /= 0) then
        info = 7
        energy = 0.0_dp
        return
      end if
      ! (a z component of a plane element is +0: added or not, the same sums (force starts
      ! at +0 and a sum is -0 only when both terms are, so no entry is ever -0 and adding +0
      ! leaves it as it is): a plane element's z components are skipped)
      if (plane) then
        do node = 1, 4
          do a = 3 * node - 2, 3 * node - 1
            k = selected(a)
            if (k > 0) force(k) = force(k) + element_force(a)
          end do
        end do
      else
        do a = 1, cable_dofs
          k = selected(a)
          if (k > 0) force(k) = force(k) + element_force(a)
        end do
      end if
      energy = energy + element_energy
    end do
  end subroutine cable_selected_forces

  !> The element_set energy_power of a cable set. An undamped elastic cable set (or one
  !> given no rates): local_energy_power's loop (each element's strain energy summed in
  !> element order; no frame: power 0) without its dispatch through element_energy, a plane
  !> element by plane_element_energy: the same numbers. Everything else: local_energy_power.
  subroutine cable_set_energy_power(set, rotation, axis, rate, e, energy, power, info, v, &
                                    dissipation)
    class(cable_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), axis(3), rate, e(:)
    real(dp), intent(out) :: energy, power
    integer, intent(out) :: info
    real(dp), intent(in), optional :: v(:)
    real(dp), intent(out), optional :: dissipation
    real(dp) :: coords(3, 4), element_energy
    integer :: el, node, element_info
    if (set%tension_only .or. .not. allocated(set%weights) .or. set%nde /= cable_dofs .or. &
        (present(v) .and. set%damping_time > 0.0_dp)) then
      call local_energy_power(set, rotation, axis, rate, e, energy, power, info, v, dissipation)
      return
    end if
    info = 0
    power = 0.0_dp
    energy = 0.0_dp
    do el = 1, set%nel
      do node = 1, 4
        coords(1, node) = e(set%dofs(3 * node - 2, el))
        coords(2, node) = e(set%dofs(3 * node - 1, el))
        coords(3, node) = e(set%dofs(3 * node, el))
      end do
      if (all(coords(3, :) == 0.0_dp)) then
        call plane_element_energy(coords, set%slope_rows(:, :, el), set%second_rows(:, :, el), &
                                  set%weights(:, el), set%axial_stiffness, &
                                  set%bending_stiffness, element_energy, element_info)
      else
        call rule_element_energy(coords, set%lengths(el), set%rule, set%axial_stiffness, &
                                 set%bending_stiffness, element_energy, element_info, .false.)
      end if
      if (element_info /= 0) then
        info = 7
        energy = 0.0_dp
        return
      end if
      energy = energy + element_energy
    end do
    if (present(dissipation)) dissipation = 0.0_dp
  end subroutine cable_set_energy_power

  !> The element_set element_energy of a cable set: the energy-only pass (the damped set,
  !> given rates, through its force for the dissipation).
  pure subroutine cable_element_energy(set, el, coords, energy, info, rates, dissipation)
    class(cable_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: coords(:, :)
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    real(dp), intent(in), optional :: rates(:, :)
    real(dp), intent(out), optional :: dissipation
    real(dp) :: force(cable_dofs), tangent(cable_dofs, cable_dofs)
    if (present(rates)) then
      call cable_element_forces(set, el, coords, .false., force, energy, tangent, info, rates, &
                                0.0_dp, dissipation)
      return
    end if
    if (.not. set%tension_only .and. allocated(set%weights)) then
      if (all(coords(3, :) == 0.0_dp)) then
        call plane_element_energy(coords, set%slope_rows(:, :, el), set%second_rows(:, :, el), &
                                  set%weights(:, el), set%axial_stiffness, &
                                  set%bending_stiffness, energy, info)
        return
      end if
    end if
    call rule_element_energy(coords, set%lengths(el), set%rule, set%axial_stiffness, &
                             set%bending_stiffness, energy, info, set%tension_only)
  end subroutine cable_element_energy

  !> rule_element_energy of an element in the plane z = 0 (not a rope) with the set's
  !> shape rows and weights (cable_element_rows: the numbers rule_rows and half_weight L
  !> give): the same sums, without the eight divisions a point.
  pure subroutine plane_element_energy(q, slope_rows, second_rows, weights, axial_stiffness, &
                                       bending_stiffness, energy, info)
    real(dp), intent(in) :: q(3, 4), slope_rows(4, cable_points), second_rows(4, cable_points)
    real(dp), intent(in) :: weights(cable_points), axial_stiffness, bending_stiffness
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    real(dp), dimension(cable_points) :: ax, ay, bx, by, aa, bb, ab, strain, point_energy
    integer :: p, k
    info = 0
    energy = 0.0_dp
    ! (the points side by side, as in plane_element_force; the kinematics block is written
    ! out in both: a shared pure subroutine was not inlined and cost 2-3 % of the planar
    ! pendulum's step, callgrind 47.3k -> 48.4k instructions at 5 nodes)
    ax = 0.0_dp
    ay = 0.0_dp
    bx = 0.0_dp
    by = 0.0_dp
    do k = 1, 4
      do p = 1, cable_points
        ax(p) = ax(p) + q(1, k) * slope_rows(k, p)
        ay(p) = ay(p) + q(2, k) * slope_rows(k, p)
        bx(p) = bx(p) + q(1, k) * second_rows(k, p)
        by(p) = by(p) + q(2, k) * second_rows(k, p)
      end do
    end do
    do p = 1, cable_points
      aa(p) = 0.0_dp + ax(p) * ax(p) + ay(p) * ay(p)
      bb(p) = 0.0_dp + bx(p) * bx(p) + by(p) * by(p)
      ab(p) = 0.0_dp + ax(p) * bx(p) + ay(p) * by(p)
    end do
    if (any(aa <= 0.0_dp)) then
      info = 2
      return
    end if
    do p = 1, cable_points
      strain(p) = 0.5_dp * (aa(p) - 1.0_dp)
      point_energy(p) = 0.5_dp * axial_stiffness * strain(p)**2 &
                        + 0.5_dp * bending_stiffness * ((aa(p) * bb(p) - ab(p)**2) / aa(p)**3)
    end do
    do p = 1, cable_points
      energy = energy + weights(p) * point_energy(p)
    end do
  end subroutine plane_element_energy

end module cable_element
