!> The gradient-deficient ANCF thin plate element (Dufva & Shabana 2005; seed 003 eqs. 3-8)
!> and its completed variant (seed 003 eqs. 9-16).
!>
!> Kinematics: 4 nodes x [r, r_x, r_y] = 36 coordinates, r(x, y) = S(x, y) e with the
!> 12 incomplete bicubic (Adini-Clough-Melosh) shape functions of xi = x/a, eta = y/b, nodes
!> at (0,0), (a,0), (a,b), (0,b). Mass and surface loads are integrated over the parent
!> rectangle (for the curved leaves, meshed by arc length, this is the reference area).
!>
!> Elastic energy per unit reference area, plane stress, D = E/(1-nu^2) [1 nu 0; nu 1 0;
!> 0 0 (1-nu)/2]:
!>   membrane  W_m = h/2 eps^T D eps,          eps = [E11, E22, 2 E12],  E = (F^T F - I)/2
!>   bending   W_b = h^3/24 kappa^T D kappa,   kappa = [k11, k22, 2 k12]
!> with the curvatures of eq. 6, c_ab = r_ab . g / |g|^3, g = r_x x r_y (the unnormalized
!> normal: docs/README.md "References" on eq. 6 vs eq. 7).
!>  * plain:     F = [r_x r_y], k_ab = c_ab (a curved reference carries initial strain);
!>  * completed: J = [r_x r_y n] J0^{-1}. Because n is a unit vector normal to r_x and r_y,
!>    J^T J = blockdiag(A, 1) with A the in-plane metric, so eps_ZZ, eps_XZ, eps_YZ of eq. 10
!>    vanish identically and their n-derivatives (eqs. 12-13, 16) cancel exactly; what
!>    remains is the in-plane block in the reference's orthonormal tangent frame (t1, t2):
!>    F = [r_x r_y] K, K = ([t1 t2]^T [r0_x r0_y])^{-1}, and k = |g0|^2 K^T (c - c0) K
!>    (eq. 14; |g0|^2 c is the covariant curvature r_ab . n at the reference metric),
!>    integrated over the reference area |g0| dx dy, |g0| = |r0_x x r0_y| = 1/det K. With
!>    unit, orthogonal reference gradients (our rectangles and arc-length leaves) K = I;
!>    a flat one also has c0 = 0, and then both variants coincide.
!>
!> Implementation: at each Gauss point the energy density is a function of the 15 numbers
!> z = (r_x, r_y, r_xx, r_yy, r_xy); its gradient and Hessian with respect to z are
!> analytic, and Q = sum_A dS_A^T dW/dz_A, K_t = sum_AB dS_A^T d2W/dz_A dz_B dS_B.
!>
!> Kelvin-Voigt material damping (retardation time tau, plate_forces given the rates): the membrane
!> stress and the bending moment become D (eps + tau eps') and D (kappa + tau kappa'), with
!> the rates eps' = (d eps/dz) z' and kappa' = (d kappa/dz) z' of the field rates z'
!> (objective: a rigid motion leaves both at zero). Writing s = (eps, kappa) and J = ds/dz,
!> the damping force density is tau J^T D J z', its power tau s'^T D s' >= 0, and the
!> combined point tangent d/dz + c d/dz' is
!>   (1 + c tau) J^T D J + sum_k [D (s - s0 + tau s')]_k d2s_k/dz2 + tau J^T D (d2s/dz2 z'),
!> the last term (the strain rate's dependence on z: B(F') for the membrane, the
!> curvature Hessians applied to z' for the bending) not symmetric.
module plate_element
  use ancf_kinds, only: dp
  use quadrature, only: gauss_legendre
  use matrix3, only: skew
  use element_sets, only: local_element_set
  implicit none
  private
  public :: plate_shape, plate_mass, plate_surface_load, plate_setup, plate_forces, &
            plate_curvatures, plate_set

  integer, parameter, public :: plate_shapes = 12, plate_dofs = 36, plate_fields = 5
  integer, parameter, public :: plate_variant_plain = 0, plate_variant_completed = 1
  !> Gauss points per direction of the elastic, mass and load integrals.
  integer, parameter, public :: plate_gauss_1d = 4
  integer, parameter, public :: plate_points = plate_gauss_1d * plate_gauss_1d

  !> The family's element set (element_sets): shape derivatives (12, 5, npts, nel), frame
  !> maps (2, 2, npts, nel), reference curvatures (3, npts, nel), weights (npts, nel).
  type, extends(local_element_set) :: plate_set
    real(dp), allocatable :: derivs(:, :, :, :), plate_frame(:, :, :, :), curvature0(:, :, :)
    real(dp), allocatable :: weights(:, :)
    real(dp) :: youngs = 0.0_dp, poisson = 0.0_dp, thickness = 0.0_dp
  contains
    procedure :: element_forces => plate_element_forces
    procedure :: element_energy => plate_element_energy
  end type plate_set
  !> Field indices of z: r_x, r_y, r_xx, r_yy, r_xy.
  integer, parameter :: f_x = 1, f_y = 2, f_xx = 3, f_yy = 4, f_xy = 5

  !> Monomial coefficients of the 12 shape functions in xi, eta (rows: 1, xi, eta, xi^2,
  !> xi eta, eta^2, xi^3, xi^2 eta, xi eta^2, eta^3, xi^3 eta, xi eta^3; columns: node 1
  !> r, r_x, r_y, node 2 r, r_x, r_y, ...). The r_x columns carry a factor a, the r_y
  !> columns a factor b, applied in plate_shape.
  real(dp), parameter :: coefficients(12, 12) = reshape([ &
    1, 0, 0, -3, -1, -3, 2, 3, 3, 2, -2, -2, &
    0, 1, 0, -2, -1, 0, 1, 2, 0, 0, -1, 0, &
    0, 0, 1, 0, -1, -2, 0, 0, 2, 1, 0, -1, &
    0, 0, 0, 3, 1, 0, -2, -3, -3, 0, 2, 2, &
    0, 0, 0, -1, 0, 0, 1, 1, 0, 0, -1, 0, &
    0, 0, 0, 0, 1, 0, 0, 0, -2, 0, 0, 1, &
    0, 0, 0, 0, -1, 0, 0, 3, 3, 0, -2, -2, &
    0, 0, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, &
    0, 0, 0, 0, 0, 0, 0, 0, -1, 0, 0, 1, &
    0, 0, 0, 0, 1, 3, 0, -3, -3, -2, 2, 2, &
    0, 0, 0, 0, 1, 0, 0, -2, 0, 0, 1, 0, &
    0, 0, 0, 0, 0, -1, 0, 0, 1, 1, 0, -1], [12, 12])
  !> coefficients transposed: coefficient_rows(:, k) = coefficients(k, :), monomial k's
  !> coefficient in each shape function
  real(dp), parameter :: coefficient_rows(12, 12) = transpose(coefficients)
  !> the monomials that do not vanish identically in plate_shape's m, m_x, m_y, m_xx, m_yy,
  !> m_xy (by its tables)
  integer, parameter :: all_terms(12) = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12], &
                        x_terms(8) = [2, 4, 5, 7, 8, 9, 11, 12], &
                        y_terms(8) = [3, 5, 6, 8, 9, 10, 11, 12], &
                        xx_terms(4) = [4, 7, 8, 11], yy_terms(4) = [6, 9, 10, 12], &
                        xy_terms(5) = [5, 8, 9, 11, 12]

contains

  !> Shape functions at (xi, eta) in [0,1]^2 and their derivatives with respect to the
  !> parent coordinates x = a xi, y = b eta: derivs(:, 1..5) = S_x, S_y, S_xx, S_yy, S_xy.
  pure subroutine plate_shape(xi, eta, a, b, shape, derivs)
    real(dp), intent(in) :: xi, eta, a, b
    real(dp), intent(out) :: shape(plate_shapes), derivs(plate_shapes, plate_fields)
    real(dp) :: m(12), mx(12), my(12), mxx(12), myy(12), mxy(12), scale(12)
    integer :: k
    m = [1.0_dp, xi, eta, xi**2, xi * eta, eta**2, xi**3, xi**2 * eta, xi * eta**2, eta**3, &
         xi**3 * eta, xi * eta**3]
    mx = [0.0_dp, 1.0_dp, 0.0_dp, 2 * xi, eta, 0.0_dp, 3 * xi**2, 2 * xi * eta, eta**2, &
          0.0_dp, 3 * xi**2 * eta, eta**3]
    my = [0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, xi, 2 * eta, 0.0_dp, xi**2, 2 * xi * eta, &
          3 * eta**2, xi**3, 3 * xi * eta**2]
    mxx = [0.0_dp, 0.0_dp, 0.0_dp, 2.0_dp, 0.0_dp, 0.0_dp, 6 * xi, 2 * eta, 0.0_dp, 0.0_dp, &
           6 * xi * eta, 0.0_dp]
    myy = [0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 2.0_dp, 0.0_dp, 0.0_dp, 2 * xi, 6 * eta, &
           0.0_dp, 6 * xi * eta]
    mxy = [0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 2 * xi, 2 * eta, 0.0_dp, &
           3 * xi**2, 3 * eta**2]
    do k = 0, 3
      scale(3 * k + 1:3 * k + 3) = [1.0_dp, a, b]
    end do
    shape = monomial_sum(m, all_terms) * scale
    derivs(:, f_x) = monomial_sum(mx, x_terms) * scale / a
    derivs(:, f_y) = monomial_sum(my, y_terms) * scale / b
    derivs(:, f_xx) = monomial_sum(mxx, xx_terms) * scale / a**2
    derivs(:, f_yy) = monomial_sum(myy, yy_terms) * scale / b**2
    derivs(:, f_xy) = monomial_sum(mxy, xy_terms) * scale / (a * b)
  end subroutine plate_shape

  !> matmul(m, coefficients) bit for bit when m is 0 outside terms (increasing): each shape
  !> function's sum of m(k) coefficients(k, j) in increasing k from +0, without the terms
  !> of the monomials that vanish identically (a +-0 product leaves a sum that started at +0
  !> unchanged), all shape functions at once (coefficient_rows: a row per column).
  pure function monomial_sum(m, terms) result(total)
    real(dp), intent(in) :: m(12)
    integer, intent(in) :: terms(:)
    real(dp) :: total(12)
    integer :: t, k
    total = 0.0_dp
    do t = 1, size(terms)
      k = terms(t)
      total = total + m(k) * coefficient_rows(:, k)
    end do
  end function monomial_sum

  !> Compact mass matrix (12 x 12; the element's is kron(mass, I3)): rho h int S^T S dx dy.
  pure subroutine plate_mass(a, b, thickness, density, mass, info)
    real(dp), intent(in) :: a, b, thickness, density
    real(dp), intent(out) :: mass(plate_shapes, plate_shapes)
    integer, intent(out) :: info
    real(dp) :: points(plate_gauss_1d), weights(plate_gauss_1d), shape(plate_shapes)
    real(dp) :: derivs(plate_shapes, plate_fields)
    integer :: i, j, k
    call gauss_legendre(plate_gauss_1d, points, weights, info)
    mass = 0.0_dp
    if (info /= 0) return
    do j = 1, plate_gauss_1d
      do i = 1, plate_gauss_1d
        call plate_shape(0.5_dp * (points(i) + 1), 0.5_dp * (points(j) + 1), a, b, shape, derivs)
        do k = 1, plate_shapes
          mass(:, k) = mass(:, k) + 0.25_dp * weights(i) * weights(j) * shape * shape(k)
        end do
      end do
    end do
    mass = density * thickness * a * b * mass
  end subroutine plate_mass

  !> Generalized force (3, 12) of a constant load per unit area (gravity: rho h g;
  !> pressure: q times the reference normal): int S^T load dx dy.
  pure subroutine plate_surface_load(a, b, load, force, info)
    real(dp), intent(in) :: a, b, load(3)
    real(dp), intent(out) :: force(3, plate_shapes)
    integer, intent(out) :: info
    real(dp) :: points(plate_gauss_1d), weights(plate_gauss_1d), shape(plate_shapes)
    real(dp) :: derivs(plate_shapes, plate_fields), integral(plate_shapes)
    integer :: i, j, k
    call gauss_legendre(plate_gauss_1d, points, weights, info)
    integral = 0.0_dp
    do j = 1, plate_gauss_1d
      do i = 1, plate_gauss_1d
        call plate_shape(0.5_dp * (points(i) + 1), 0.5_dp * (points(j) + 1), a, b, shape, derivs)
        integral = integral + 0.25_dp * weights(i) * weights(j) * a * b * shape
      end do
    end do
    do k = 1, plate_shapes
      force(:, k) = integral(k) * load
    end do
  end subroutine plate_surface_load

  !> The three curvatures c_11, c_22, c_12 = r_ab . g / |g|^3 of eq. 6 at the fields z.
  pure subroutine plate_curvatures(fields, curvatures)
    real(dp), intent(in) :: fields(3, plate_fields)
    real(dp), intent(out) :: curvatures(3)
    real(dp) :: g(3), norm3
    g = point_cross(fields(:, f_x), fields(:, f_y))
    norm3 = norm2(g)**3
    curvatures = [dot_product(fields(:, f_xx), g), dot_product(fields(:, f_yy), g), &
                  dot_product(fields(:, f_xy), g)] / norm3
  end subroutine plate_curvatures

  !> Reference data of one element at the Gauss points: shape derivatives, the frame map K,
  !> the reference curvatures c0 and the weights (reference area included). The plain
  !> variant uses K = I, c0 = 0 and the parent area. info = 2: degenerate reference.
  pure subroutine plate_setup(reference, a, b, variant, derivs, frame, curvature0, weights, info)
    real(dp), intent(in) :: reference(3, plate_shapes), a, b
    integer, intent(in) :: variant
    real(dp), intent(out) :: derivs(plate_shapes, plate_fields, plate_points)
    real(dp), intent(out) :: frame(2, 2, plate_points), curvature0(3, plate_points)
    real(dp), intent(out) :: weights(plate_points)
    integer, intent(out) :: info
    real(dp) :: points(plate_gauss_1d), w1(plate_gauss_1d), shape(plate_shapes)
    real(dp) :: fields(3, plate_fields), g(3), t1(3), t2(3), metric(2, 2), det
    integer :: i, j, p
    call gauss_legendre(plate_gauss_1d, points, w1, info)
    if (info /= 0) return
    p = 0
    do j = 1, plate_gauss_1d
      do i = 1, plate_gauss_1d
        p = p + 1
        call plate_shape(0.5_dp * (points(i) + 1), 0.5_dp * (points(j) + 1), a, b, shape, &
                         derivs(:, :, p))
        weights(p) = 0.25_dp * w1(i) * w1(j) * a * b
        frame(:, :, p) = reshape([1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [2, 2])
        curvature0(:, p) = 0.0_dp
        if (variant /= plate_variant_completed) cycle
        fields = matmul(reference, derivs(:, :, p))
        g = point_cross(fields(:, f_x), fields(:, f_y))
        if (norm2(g) <= epsilon(1.0_dp) * norm2(fields(:, f_x)) * norm2(fields(:, f_y))) then
          info = 2
          return
        end if
        t1 = fields(:, f_x) / norm2(fields(:, f_x))
        t2 = point_cross(g / norm2(g), t1)
        metric = reshape([dot_product(t1, fields(:, f_x)), dot_product(t2, fields(:, f_x)), &
                          dot_product(t1, fields(:, f_y)), dot_product(t2, fields(:, f_y))], [2, 2])
        det = metric(1, 1) * metric(2, 2) - metric(1, 2) * metric(2, 1)
        frame(:, :, p) = reshape([metric(2, 2), -metric(2, 1), -metric(1, 2), metric(1, 1)], &
                                 [2, 2]) / det
        weights(p) = weights(p) * det
        call plate_curvatures(fields, curvature0(:, p))
      end do
    end do
  end subroutine plate_setup

  !> The strains at a Gauss point and the energy density (point_energy's first part, and
  !> all of plate_element_energy): F = [r_x r_y] K and the membrane strain, its stress,
  !> the normal g = r_x x r_y and |g|, the map to_local of curvature_map, kappa = to_local
  !> (c - reference) with c_ab = r_ab . g / |g|^3 (local kappa = K^T (c - c0) K in Voigt
  !> form), the bending moment and W.
  pure subroutine point_strains(fields, k, reference, membrane_d, bending_d, deformation, &
                                strain, stress, g, gnorm, to_local, kappa, moment, energy)
    real(dp), intent(in) :: fields(3, plate_fields), k(2, 2), reference(3)
    real(dp), intent(in) :: membrane_d(3, 3), bending_d(3, 3)
    real(dp), intent(out) :: deformation(3, 2), strain(3), stress(3), g(3), gnorm
    real(dp), intent(out) :: to_local(3, 3), kappa(3), moment(3), energy
    real(dp) :: c(3)
    deformation = matmul(fields(:, f_x:f_y), k)
    strain = [0.5_dp * (dot_product(deformation(:, 1), deformation(:, 1)) - 1.0_dp), &
              0.5_dp * (dot_product(deformation(:, 2), deformation(:, 2)) - 1.0_dp), &
              dot_product(deformation(:, 1), deformation(:, 2))]
    stress = matmul(membrane_d, strain)
    energy = 0.5_dp * dot_product(strain, stress)
    g = point_cross(fields(:, f_x), fields(:, f_y))
    gnorm = norm2(g)
    c = [dot_product(fields(:, f_xx), g), dot_product(fields(:, f_yy), g), &
         dot_product(fields(:, f_xy), g)] / gnorm**3
    call curvature_map(k, to_local)
    kappa = matmul(to_local, c - reference)
    moment = matmul(bending_d, kappa)
    energy = energy + 0.5_dp * dot_product(kappa, moment)
  end subroutine point_strains

  !> Energy density W(z) at one Gauss point, its gradient (3, 5) and, on request, its
  !> Hessian (15, 15) with respect to z = (r_x, r_y, r_xx, r_yy, r_xy).
  !> With Kelvin-Voigt damping (the field rates z', tau, rate_factor and power all present):
  !> the elastic energy density, the dissipated power density, the gradient of the total
  !> (elastic plus damping) force and, on request, the combined Hessian d/dz + rate_factor
  !> d/dz'. The bending part is the elastic one at the shifted reference curvature
  !> c0 - tau c' (c' = (dc/dz) z'): its moment is then D (kappa + tau kappa'), which its
  !> gradient and its geometric Hessian carry; the membrane damping stress, the rate
  !> derivative c tau J^T D J and the rate terms tau J^T D (d2s/dz2 z') are added to them.
  pure subroutine point_energy(fields, frame, curvature0, membrane_d, bending_d, want_hessian, &
                               energy, gradient, hessian, field_rates, tau, rate_factor, power)
    real(dp), intent(in) :: fields(3, plate_fields), frame(2, 2), curvature0(3)
    real(dp), intent(in) :: membrane_d(3, 3), bending_d(3, 3)
    logical, intent(in) :: want_hessian
    real(dp), intent(out) :: energy, gradient(3, plate_fields), hessian(15, 15)
    real(dp), intent(in), optional :: field_rates(3, plate_fields), tau, rate_factor
    real(dp), intent(out), optional :: power
    real(dp) :: reference(3), deformation_rate(3, 2), strain_rate(3), damping_stress(3)
    real(dp) :: b_rate(3, 6), rate_map(3, 3), rate_dcurv(3, 15), curvature_rate(3)
    real(dp) :: elastic_kappa(3), kappa_rate(3), rate_dkappa(3, 15), curvature_hessian_rate(3, 15)
    real(dp) :: g_now(3), gnorm_now, c_now(3)
    logical :: damped
    real(dp) :: deformation(3, 2), strain(3), stress(3), stress_tensor(2, 2), geometric(2, 2)
    real(dp) :: b_strain(3, 6), g(3), gnorm, u(3), v(3), to_local(3, 3), kappa(3)
    real(dp) :: moment(3), omega(3), dcurv(3, 15), dkappa(3, 15), w_eff(3), wg, h_eff(3)
    real(dp) :: hwg(3, 3), hgg(3, 3), gu(3, 3), gv(3, 3), k(2, 2)
    real(dp) :: du(3, 3), dv(3, 3), g_scaled(3)
    integer :: gamma, i, f
    damped = present(field_rates) .and. present(tau) .and. present(rate_factor) .and. &
             present(power)
    reference = curvature0
    if (damped) then  ! the curvatures' rates and the shifted reference curvature
      g_now = point_cross(fields(:, f_x), fields(:, f_y))
      gnorm_now = norm2(g_now)
      c_now = [dot_product(fields(:, f_xx), g_now), dot_product(fields(:, f_yy), g_now), &
               dot_product(fields(:, f_xy), g_now)] / gnorm_now**3
      call curvature_map(frame, rate_map)
      call curvature_gradients(fields, g_now, gnorm_now, rate_dcurv)
      do i = 1, 3
        curvature_rate(i) = 0.0_dp
        do f = 1, plate_fields
          curvature_rate(i) = curvature_rate(i) &
                              + dot_product(rate_dcurv(i, 3 * f - 2:3 * f), field_rates(:, f))
        end do
      end do
      elastic_kappa = matmul(rate_map, c_now - curvature0)
      kappa_rate = matmul(rate_map, curvature_rate)
      reference = curvature0 - tau * curvature_rate
    end if
    k = frame
    u = fields(:, f_x)
    v = fields(:, f_y)
    call point_strains(fields, k, reference, membrane_d, bending_d, deformation, strain, stress, &
                       g, gnorm, to_local, kappa, moment, energy)
    do gamma = 1, 2
      b_strain(1, 3 * gamma - 2:3 * gamma) = k(gamma, 1) * deformation(:, 1)
      b_strain(2, 3 * gamma - 2:3 * gamma) = k(gamma, 2) * deformation(:, 2)
      b_strain(3, 3 * gamma - 2:3 * gamma) = k(gamma, 1) * deformation(:, 2) &
                                             + k(gamma, 2) * deformation(:, 1)
    end do
    gradient = 0.0_dp
    do gamma = 1, 2
      do i = 1, 3
        gradient(:, f_x + gamma - 1) = gradient(:, f_x + gamma - 1) &
                                       + stress(i) * b_strain(i, 3 * gamma - 2:3 * gamma)
      end do
    end do
    omega = matmul(moment, to_local)        ! dW/dc
    ! dc/dz: dc/du = v x h, dc/dv = h x u, dc/dw = g/|g|^3, h = dc/dg; curvature i
    ! depends on one second derivative w_i alone, so the gradient of the w fields takes
    ! one term each (the zero blocks of dc/dz are not added: the same sums)
    g_scaled = g / gnorm**3
    do i = 1, 3
      h_eff = fields(:, f_xx + i - 1) / gnorm**3 &
              - 3.0_dp * dot_product(fields(:, f_xx + i - 1), g) * g / gnorm**5
      du(:, i) = point_cross(v, h_eff)
      dv(:, i) = point_cross(h_eff, u)
    end do
    do i = 1, 3
      gradient(:, f_x) = gradient(:, f_x) + omega(i) * du(:, i)
    end do
    do i = 1, 3
      gradient(:, f_y) = gradient(:, f_y) + omega(i) * dv(:, i)
    end do
    do i = 1, 3
      gradient(:, f_xx + i - 1) = omega(i) * g_scaled
    end do
    if (damped) then
      ! membrane: the damping stress tau D eps', eps' = B(F) z'
      deformation_rate = matmul(field_rates(:, f_x:f_y), frame)
      strain_rate = [dot_product(deformation(:, 1), deformation_rate(:, 1)), &
                     dot_product(deformation(:, 2), deformation_rate(:, 2)), &
                     dot_product(deformation(:, 1), deformation_rate(:, 2)) &
                     + dot_product(deformation(:, 2), deformation_rate(:, 1))]
      damping_stress = tau * matmul(membrane_d, strain_rate)
      do gamma = 1, 2
        do i = 1, 3
          gradient(:, f_x + gamma - 1) = gradient(:, f_x + gamma - 1) &
                                         + damping_stress(i) * b_strain(i, 3 * gamma - 2:3 * gamma)
        end do
      end do
      ! the elastic energy (not the shifted one) and the dissipated power
      energy = 0.5_dp * dot_product(strain, matmul(membrane_d, strain)) &
               + 0.5_dp * dot_product(elastic_kappa, matmul(bending_d, elastic_kappa))
      power = dot_product(strain_rate, damping_stress) &
              + tau * dot_product(kappa_rate, matmul(bending_d, kappa_rate))
    end if
    if (.not. want_hessian) return
    ! membrane: B^T D B + kron(K S K^T, I3)
    hessian = 0.0_dp
    hessian(1:6, 1:6) = matmul(transpose(b_strain), matmul(membrane_d, b_strain))
    stress_tensor = reshape([stress(1), stress(3), stress(3), stress(2)], [2, 2])
    geometric = matmul(k, matmul(stress_tensor, transpose(k)))
    call add_geometric_membrane(geometric, hessian)
    ! bending, material part
    dcurv = 0.0_dp
    do i = 1, 3
      dcurv(i, 1:3) = du(:, i)
      dcurv(i, 4:6) = dv(:, i)
      dcurv(i, 3 * (f_xx + i - 1) - 2:3 * (f_xx + i - 1)) = g_scaled
    end do
    dkappa = matmul(to_local, dcurv)
    hessian = hessian + matmul(transpose(dkappa), matmul(bending_d, dkappa))
    ! bending, geometric part: sum_c omega_c d2c/dz2; c is linear in w, so the (u, v)
    ! blocks are those of one curvature with w_eff = sum_c omega_c w_c
    w_eff = omega(1) * fields(:, f_xx) + omega(2) * fields(:, f_yy) + omega(3) * fields(:, f_xy)
    wg = dot_product(w_eff, g)
    h_eff = w_eff / gnorm**3 - 3.0_dp * wg * g / gnorm**5
    do i = 1, 3
      hwg(:, i) = -3.0_dp * g * g(i) / gnorm**5
      hwg(i, i) = hwg(i, i) + 1.0_dp / gnorm**3
      hgg(:, i) = -3.0_dp * (w_eff * g(i) + g * w_eff(i)) / gnorm**5 &
                  + 15.0_dp * wg * g * g(i) / gnorm**7
      hgg(i, i) = hgg(i, i) - 3.0_dp * wg / gnorm**5
    end do
    gu = -skew(v)
    gv = skew(u)
    hessian(1:3, 1:3) = hessian(1:3, 1:3) + matmul(transpose(gu), matmul(hgg, gu))
    hessian(4:6, 4:6) = hessian(4:6, 4:6) + matmul(transpose(gv), matmul(hgg, gv))
    hessian(1:3, 4:6) = hessian(1:3, 4:6) + matmul(transpose(gu), matmul(hgg, gv)) - skew(h_eff)
    hessian(4:6, 1:3) = hessian(4:6, 1:3) + transpose(matmul(transpose(gu), matmul(hgg, gv)) &
                                                      - skew(h_eff))
    do i = 1, 3
      f = f_xx + i - 1
      hessian(3 * f - 2:3 * f, 1:3) = hessian(3 * f - 2:3 * f, 1:3) + omega(i) * matmul(hwg, gu)
      hessian(3 * f - 2:3 * f, 4:6) = hessian(3 * f - 2:3 * f, 4:6) + omega(i) * matmul(hwg, gv)
      hessian(1:3, 3 * f - 2:3 * f) = hessian(1:3, 3 * f - 2:3 * f) &
                                      + omega(i) * transpose(matmul(hwg, gu))
      hessian(4:6, 3 * f - 2:3 * f) = hessian(4:6, 3 * f - 2:3 * f) &
                                      + omega(i) * transpose(matmul(hwg, gv))
    end do
    if (.not. damped) return
    ! membrane: geometric term of the damping stress, c tau B^T D B + tau B^T D B(F')
    stress_tensor = reshape([damping_stress(1), damping_stress(3), damping_stress(3), &
                             damping_stress(2)], [2, 2])
    geometric = matmul(frame, matmul(stress_tensor, transpose(frame)))
    call add_geometric_membrane(geometric, hessian)
    call membrane_strain_matrix(frame, deformation_rate, b_rate)
    hessian(1:6, 1:6) = hessian(1:6, 1:6) + matmul(transpose(b_strain), &
      matmul(membrane_d, rate_factor * tau * b_strain + tau * b_rate))
    ! bending: c tau dkappa^T D dkappa + tau dkappa^T D K-map((d2c/dz2) z')
    rate_dkappa = matmul(rate_map, rate_dcurv)
    call curvature_gradient_rate(fields, field_rates, g_now, gnorm_now, curvature_hessian_rate)
    hessian = hessian + matmul(transpose(rate_dkappa), matmul(bending_d, &
      rate_factor * tau * rate_dkappa + tau * matmul(rate_map, curvature_hessian_rate)))
  end subroutine point_energy

  !> Elastic force (36), strain energy and, on request, tangent (36 x 36) of one element at
  !> coordinates (3, 12), from the reference data of plate_setup. info = 2: the normal
  !> vanished (a degenerate configuration).
  !> With Kelvin-Voigt damping (the coordinate rates (3, 12), damping_time tau > 0,
  !> rate_factor and dissipation all present): the force includes the damping force,
  !> dissipation is its power and the tangent (when want_tangent) the combined dQ/dq +
  !> rate_factor dQ/dq', both triangles (it is not symmetric). (The two point loops stay
  !> apart, as in beam_nonlinear: one loop behind a flag compiles to a slower undamped force.)
  pure subroutine plate_forces(coords, derivs, frame, curvature0, weights, youngs, poisson, &
                               thickness, want_tangent, force, energy, tangent, info, rates, &
                               damping_time, rate_factor, dissipation)
    real(dp), intent(in) :: coords(3, plate_shapes)
    real(dp), intent(in) :: derivs(plate_shapes, plate_fields, plate_points)
    real(dp), intent(in) :: frame(2, 2, plate_points), curvature0(3, plate_points)
    real(dp), intent(in) :: weights(plate_points), youngs, poisson, thickness
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(plate_dofs), energy, tangent(plate_dofs, plate_dofs)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: rates(3, plate_shapes), damping_time, rate_factor
    real(dp), intent(out), optional :: dissipation
    if (present(rates)) then
      call damped_points(coords, rates, derivs, frame, curvature0, weights, youngs, poisson, &
                         thickness, damping_time, rate_factor, want_tangent, force, energy, &
                         dissipation, tangent, info)
    else
      call elastic_points(coords, derivs, frame, curvature0, weights, youngs, poisson, &
                          thickness, want_tangent, force, energy, tangent, info)
    end if
  end subroutine plate_forces

  !> plate_forces without damping (its loop over the Gauss points).
  pure subroutine elastic_points(coords, derivs, frame, curvature0, weights, youngs, poisson, &
                                 thickness, want_tangent, force, energy, tangent, info)
    real(dp), intent(in) :: coords(3, plate_shapes)
    real(dp), intent(in) :: derivs(plate_shapes, plate_fields, plate_points)
    real(dp), intent(in) :: frame(2, 2, plate_points), curvature0(3, plate_points)
    real(dp), intent(in) :: weights(plate_points), youngs, poisson, thickness
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(plate_dofs), energy, tangent(plate_dofs, plate_dofs)
    integer, intent(out) :: info
    real(dp) :: membrane_d(3, 3), bending_d(3, 3)
    real(dp) :: fields(3, plate_fields), point_w, gradient(3, plate_fields), hessian(15, 15)
    real(dp) :: nodal(3, plate_shapes), shape_d(plate_fields, plate_shapes)
    integer :: p, row, col
    info = 0
    call elastic_matrices(youngs, poisson, thickness, membrane_d, bending_d)
    energy = 0.0_dp
    if (want_tangent) tangent = 0.0_dp
    nodal = 0.0_dp
    do p = 1, plate_points
      shape_d = transpose(derivs(:, :, p))
      call interpolate(coords, shape_d, fields)
      if (degenerate(fields)) then
        info = 2
        return
      end if
      call point_energy(fields, frame(:, :, p), curvature0(:, p), membrane_d, bending_d, &
                        want_tangent, point_w, gradient, hessian)
      energy = energy + weights(p) * point_w
      call add_nodal_force(weights(p) * gradient, shape_d, nodal)
      ! H is symmetric: the upper triangle, mirrored at the end
      if (want_tangent) call add_point_tangent(hessian, shape_d, weights(p), .true., tangent)
    end do
    if (want_tangent) then
      do col = 1, plate_dofs
        do row = col + 1, plate_dofs
          tangent(row, col) = tangent(col, row)
        end do
      end do
    end if
    force = reshape(nodal, [plate_dofs])
  end subroutine elastic_points

  !> plate_forces with Kelvin-Voigt damping (damping_time tau > 0) at the coordinate rates
  !> (3, 12) (its loop over the Gauss points): the force includes the damping force, dissipation is its power and the tangent
  !> (when want_tangent) the combined dQ/dq + rate_factor dQ/dq', both triangles (it is not
  !> symmetric). info = 2: the normal vanished.
  pure subroutine damped_points(coords, rates, derivs, frame, curvature0, weights, youngs, &
                                      poisson, thickness, damping_time, rate_factor, &
                                      want_tangent, force, energy, dissipation, tangent, info)
    real(dp), intent(in) :: coords(3, plate_shapes), rates(3, plate_shapes)
    real(dp), intent(in) :: derivs(plate_shapes, plate_fields, plate_points)
    real(dp), intent(in) :: frame(2, 2, plate_points), curvature0(3, plate_points)
    real(dp), intent(in) :: weights(plate_points), youngs, poisson, thickness
    real(dp), intent(in) :: damping_time, rate_factor
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(plate_dofs), energy, dissipation
    real(dp), intent(out) :: tangent(plate_dofs, plate_dofs)
    integer, intent(out) :: info
    real(dp) :: membrane_d(3, 3), bending_d(3, 3)
    real(dp) :: fields(3, plate_fields), field_rates(3, plate_fields), point_w, point_power
    real(dp) :: gradient(3, plate_fields), hessian(15, 15), nodal(3, plate_shapes)
    real(dp) :: shape_d(plate_fields, plate_shapes)
    integer :: p
    info = 0
    call elastic_matrices(youngs, poisson, thickness, membrane_d, bending_d)
    energy = 0.0_dp
    dissipation = 0.0_dp
    if (want_tangent) tangent = 0.0_dp
    nodal = 0.0_dp
    do p = 1, plate_points
      shape_d = transpose(derivs(:, :, p))
      call interpolate(coords, shape_d, fields)
      call interpolate(rates, shape_d, field_rates)
      if (degenerate(fields)) then
        info = 2
        return
      end if
      call point_energy(fields, frame(:, :, p), curvature0(:, p), membrane_d, bending_d, &
                        want_tangent, point_w, gradient, hessian, field_rates, damping_time, &
                        rate_factor, point_power)
      energy = energy + weights(p) * point_w
      dissipation = dissipation + weights(p) * point_power
      call add_nodal_force(weights(p) * gradient, shape_d, nodal)
      ! H is not symmetric: every entry
      if (want_tangent) call add_point_tangent(hessian, shape_d, weights(p), .false., tangent)
    end do
    force = reshape(nodal, [plate_dofs])
  end subroutine damped_points

  !> The element_set element_forces of a plate set: plate_forces of element el.
  pure subroutine plate_element_forces(set, el, coords, want_tangent, force, energy, tangent, &
                                       info, rates, rate_factor, dissipation)
    class(plate_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: coords(:, :)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(:), energy, tangent(:, :)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: rates(:, :), rate_factor
    real(dp), intent(out), optional :: dissipation
    if (present(rates)) then
      call plate_forces(coords, set%derivs(:, :, :, el), set%plate_frame(:, :, :, el), &
                        set%curvature0(:, :, el), set%weights(:, el), set%youngs, set%poisson, &
                        set%thickness, want_tangent, force, energy, tangent, info, rates, &
                        set%damping_time, rate_factor, dissipation)
    else
      call plate_forces(coords, set%derivs(:, :, :, el), set%plate_frame(:, :, :, el), &
                        set%curvature0(:, :, el), set%weights(:, el), set%youngs, set%poisson, &
                        set%thickness, want_tangent, force, energy, tangent, info)
    end if
  end subroutine plate_element_forces

  !> One element's strain energy (the stepper's energy balance, every step) without its
  !> force: the Gauss points' strains alone (point_strains), the numbers of
  !> plate_element_forces bit for bit at a third of its cost. With rates (a damped set)
  !> through plate_element_forces, for the dissipated power.
  pure subroutine plate_element_energy(set, el, coords, energy, info, rates, dissipation)
    class(plate_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: coords(:, :)
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    real(dp), intent(in), optional :: rates(:, :)
    real(dp), intent(out), optional :: dissipation
    real(dp) :: force(plate_dofs), tangent(plate_dofs, plate_dofs), membrane_d(3, 3)
    real(dp) :: bending_d(3, 3), fields(3, plate_fields), shape_d(plate_fields, plate_shapes)
    real(dp) :: deformation(3, 2), strain(3), stress(3), g(3), gnorm, to_local(3, 3)
    real(dp) :: kappa(3), moment(3), point_w
    integer :: p
    if (present(rates)) then
      call plate_element_forces(set, el, coords, .false., force, energy, tangent, info, rates, &
                                0.0_dp, dissipation)
      return
    end if
    info = 0
    call elastic_matrices(set%youngs, set%poisson, set%thickness, membrane_d, bending_d)
    energy = 0.0_dp
    do p = 1, plate_points
      shape_d = transpose(set%derivs(:, :, p, el))
      call interpolate(coords, shape_d, fields)
      if (degenerate(fields)) then
        info = 2
        return
      end if
      call point_strains(fields, set%plate_frame(:, :, p, el), set%curvature0(:, p, el), &
                         membrane_d, bending_d, deformation, strain, stress, g, gnorm, &
                         to_local, kappa, moment, point_w)
      energy = energy + set%weights(p, el) * point_w
    end do
  end subroutine plate_element_energy

  !> The geometric part of the membrane tangent, kron(G, I3) with G (2, 2) = K S K^T, added
  !> to the (6, 6) block of a point's Hessian on the two in-plane gradients.
  pure subroutine add_geometric_membrane(geometric, hessian)
    real(dp), intent(in) :: geometric(2, 2)
    real(dp), intent(inout) :: hessian(:, :)
    integer :: row, col, i
    do col = 1, 2
      do row = 1, 2
        do i = 1, 3
          hessian(3 * row - 3 + i, 3 * col - 3 + i) = hessian(3 * row - 3 + i, 3 * col - 3 + i) &
                                                      + geometric(row, col)
        end do
      end do
    end do
  end subroutine add_geometric_membrane

  !> B(3, 6) of the membrane strain with respect to (r_x, r_y) at F = [r_x r_y] K (or, with
  !> F' in place of F, the derivative of eps' = B(F) z' with respect to z).
  pure subroutine membrane_strain_matrix(k, deformation, b_strain)
    real(dp), intent(in) :: k(2, 2), deformation(3, 2)
    real(dp), intent(out) :: b_strain(3, 6)
    integer :: gamma
    do gamma = 1, 2
      b_strain(1, 3 * gamma - 2:3 * gamma) = k(gamma, 1) * deformation(:, 1)
      b_strain(2, 3 * gamma - 2:3 * gamma) = k(gamma, 2) * deformation(:, 2)
      b_strain(3, 3 * gamma - 2:3 * gamma) = k(gamma, 1) * deformation(:, 2) &
                                             + k(gamma, 2) * deformation(:, 1)
    end do
  end subroutine membrane_strain_matrix

  !> The map kappa = to_local c of point_energy (Voigt, rescaled by the reference metric:
  !> c = b / |g|^2 with b_ab = r_ab . n the covariant curvature tensor; K^T b K is the
  !> curvature in the reference's orthonormal frame, so c is rescaled by the reference
  !> |g0|^2 = 1 / det(K)^2, 1 for unit, orthogonal reference gradients and for plain).
  pure subroutine curvature_map(k, to_local)
    real(dp), intent(in) :: k(2, 2)
    real(dp), intent(out) :: to_local(3, 3)
    to_local(1, :) = [k(1, 1)**2, k(2, 1)**2, 2 * k(1, 1) * k(2, 1)]
    to_local(2, :) = [k(1, 2)**2, k(2, 2)**2, 2 * k(1, 2) * k(2, 2)]
    to_local(3, :) = 2 * [k(1, 1) * k(1, 2), k(2, 1) * k(2, 2), k(1, 1) * k(2, 2) + k(2, 1) * k(1, 2)]
    to_local = to_local / (k(1, 1) * k(2, 2) - k(1, 2) * k(2, 1))**2
  end subroutine curvature_map

  !> dc_i/dz (rows i, columns z) of the curvatures c_i = w_i . g / |g|^3: dc/du = v x h,
  !> dc/dv = h x u, dc/dw_i = g / |g|^3, h = dc/dg (as point_energy).
  pure subroutine curvature_gradients(fields, g, gnorm, dcurv)
    real(dp), intent(in) :: fields(3, plate_fields), g(3), gnorm
    real(dp), intent(out) :: dcurv(3, 15)
    real(dp) :: h(3)
    integer :: i
    dcurv = 0.0_dp
    do i = 1, 3
      h = fields(:, f_xx + i - 1) / gnorm**3 &
          - 3.0_dp * dot_product(fields(:, f_xx + i - 1), g) * g / gnorm**5
      dcurv(i, 1:3) = point_cross(fields(:, f_y), h)
      dcurv(i, 4:6) = point_cross(h, fields(:, f_x))
      dcurv(i, 3 * (f_xx + i - 1) - 2:3 * (f_xx + i - 1)) = g / gnorm**3
    end do
  end subroutine curvature_gradients

  !> d/dt (dc_i/dz) = (d2c_i/dz2) z' of the three curvatures (rows i, columns z): with
  !> g' = u' x v + u x v' and h_i = dc_i/dg,
  !>   d/dt (v x h_i) = v' x h_i + v x h_i',  d/dt (h_i x u) = h_i' x u + h_i x u',
  !>   d/dt (g / |g|^3) = g' / |g|^3 - 3 (g . g') g / |g|^5.
  pure subroutine curvature_gradient_rate(fields, field_rates, g, gnorm, rate)
    real(dp), intent(in) :: fields(3, plate_fields), field_rates(3, plate_fields), g(3), gnorm
    real(dp), intent(out) :: rate(3, 15)
    real(dp) :: g_rate(3), gg, w(3), w_rate(3), wg, h(3), h_rate(3)
    integer :: i, f
    g_rate = point_cross(field_rates(:, f_x), fields(:, f_y)) &
             + point_cross(fields(:, f_x), field_rates(:, f_y))
    gg = dot_product(g, g_rate)
    rate = 0.0_dp
    do i = 1, 3
      f = f_xx + i - 1
      w = fields(:, f)
      w_rate = field_rates(:, f)
      wg = dot_product(w, g)
      h = w / gnorm**3 - 3.0_dp * wg * g / gnorm**5
      h_rate = w_rate / gnorm**3 - 3.0_dp * gg * w / gnorm**5 &
               - 3.0_dp * ((dot_product(w_rate, g) + dot_product(w, g_rate)) * g + wg * g_rate) &
                 / gnorm**5 + 15.0_dp * wg * gg * g / gnorm**7
      rate(i, 1:3) = point_cross(field_rates(:, f_y), h) + point_cross(fields(:, f_y), h_rate)
      rate(i, 4:6) = point_cross(h_rate, fields(:, f_x)) + point_cross(h, field_rates(:, f_x))
      rate(i, 3 * f - 2:3 * f) = g_rate / gnorm**3 - 3.0_dp * gg * g / gnorm**5
    end do
  end subroutine curvature_gradient_rate

  !> The plane-stress membrane (h D) and bending (h^3/12 D) matrices.
  pure subroutine elastic_matrices(youngs, poisson, thickness, membrane_d, bending_d)
    real(dp), intent(in) :: youngs, poisson, thickness
    real(dp), intent(out) :: membrane_d(3, 3), bending_d(3, 3)
    real(dp) :: plane_stress(3, 3)
    plane_stress = youngs / (1.0_dp - poisson**2) * reshape([1.0_dp, poisson, 0.0_dp, poisson, &
                   1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.5_dp * (1.0_dp - poisson)], [3, 3])
    membrane_d = thickness * plane_stress
    bending_d = thickness**3 / 12.0_dp * plane_stress
  end subroutine elastic_matrices

  !> The fields z = (r_x, r_y, r_xx, r_yy, r_xy) (or their rates) at a Gauss point from the
  !> nodal values (3, 12) and the shape derivatives there, shape_d(field, shape).
  pure subroutine interpolate(values, shape_d, fields)
    real(dp), intent(in) :: values(3, plate_shapes), shape_d(plate_fields, plate_shapes)
    real(dp), intent(out) :: fields(3, plate_fields)
    integer :: ka, f
    fields = 0.0_dp
    do ka = 1, plate_shapes
      do f = 1, plate_fields
        fields(:, f) = fields(:, f) + values(:, ka) * shape_d(f, ka)
      end do
    end do
  end subroutine interpolate

  !> The vector product u x v, as matrix3's cross: written here because the point loops
  !> call it 7 times per Gauss point for the force alone, and a procedure of another file
  !> is never inlined (each call was a real call through the library's symbol table:
  !> 15 % of the elastic force's time).
  pure function point_cross(u, v) result(w)
    real(dp), intent(in) :: u(3), v(3)
    real(dp) :: w(3)
    w = [u(2) * v(3) - u(3) * v(2), u(3) * v(1) - u(1) * v(3), u(1) * v(2) - u(2) * v(1)]
  end function point_cross

  !> Whether the normal r_x x r_y (nearly) vanishes, |r_x x r_y| <= sqrt(eps) |r_x| |r_y|:
  !> a degenerate configuration (compared squared: no norm2, whose overflow-safe scaling
  !> costs three divisions per vector, in the elastic force's point loop).
  pure logical function degenerate(fields)
    real(dp), intent(in) :: fields(3, plate_fields)
    real(dp) :: g(3)
    g = point_cross(fields(:, f_x), fields(:, f_y))
    degenerate = dot_product(g, g) <= epsilon(1.0_dp) &
                 * dot_product(fields(:, f_x), fields(:, f_x)) &
                 * dot_product(fields(:, f_y), fields(:, f_y))
  end function degenerate

  !> nodal += dS^T-weighted gradient: the point's share of the generalized force.
  pure subroutine add_nodal_force(gradient, shape_d, nodal)
    real(dp), intent(in) :: gradient(3, plate_fields), shape_d(plate_fields, plate_shapes)
    real(dp), intent(inout) :: nodal(3, plate_shapes)
    integer :: ka, f
    do ka = 1, plate_shapes
      do f = 1, plate_fields
        nodal(:, ka) = nodal(:, ka) + gradient(:, f) * shape_d(f, ka)
      end do
    end do
  end subroutine add_nodal_force

  !> tangent += w L^T H L with L = kron(dS^T, I3), in two passes: half = w H L (15 x 36),
  !> then L^T half; with upper_only the upper triangle alone (H symmetric; the caller
  !> mirrors it).
  pure subroutine add_point_tangent(hessian, shape_d, weight, upper_only, tangent)
    real(dp), intent(in) :: hessian(15, 15), shape_d(plate_fields, plate_shapes), weight
    logical, intent(in) :: upper_only
    real(dp), intent(inout) :: tangent(plate_dofs, plate_dofs)
    real(dp) :: half(15, plate_dofs), total
    integer :: ka, kb, i, j, f, row, col, last
    do kb = 1, plate_shapes
      do j = 1, 3
        col = 3 * kb - 3 + j
        do row = 1, 15
          total = 0.0_dp
          do f = 1, plate_fields
            total = total + hessian(row, 3 * f - 3 + j) * shape_d(f, kb)
          end do
          half(row, col) = weight * total
        end do
      end do
    end do
    do col = 1, plate_dofs
      last = plate_shapes
      if (upper_only) last = (col + 2) / 3
      do ka = 1, last
        do i = 1, 3
          total = 0.0_dp
          do f = 1, plate_fields
            total = total + shape_d(f, ka) * half(3 * f - 3 + i, col)
          end do
          tangent(3 * ka - 3 + i, col) = tangent(3 * ka - 3 + i, col) + total
        end do
      end do
    end do
  end subroutine add_point_tangent

end module plate_element
