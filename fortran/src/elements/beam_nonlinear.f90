!> Large-deformation elastic forces of the 12-coordinate ANCF beam (kinematics of
!> beam_element): continuum mechanics with the Green-Lagrange strain and a St. Venant-
!> Kirchhoff material, F = J J0^{-1} so a curved reference is strain-free (seed 003,
!> eqs. 1-2). With the material gradients g_a = J0^{-T} grad N_a precomputed at the Gauss
!> points,
!>   F = sum_a q_a g_a^T,  E = (F^T F - I)/2,  S = D : E,
!>   Q_a = int F S g_a dV0,  K_ab = int B_a^T D B_b dV0 + int (g_a^T S g_b) I3 dV0.
!> At the reference (F = I, S = 0) the tangent equals the small-strain K0 of the FFR model.
!> F and E are taken in the section's material axes R0 (beam_element's material_axes: the
!> axis, the height, the width): g_a = R0^T J0^{-T} grad N_a. The laws below are not
!> isotropic, so in the global axes an inclined element's energy depended on its direction.
!>
!> Poisson locking (the section fields are linear in y, z): D is split into the Poisson-free
!> part D0 = diag(E, E, E, E/2, G, E/2), integrated over the whole section, and the Poisson
!> part D - D0 (its normal block), integrated on the neutral axis only (the splitting of
!> enhanced continuum mechanics); the shears' G enters through the twist and axis points
!> below. With nu = 0 all coincide with the plain law.
!>
!> Torsion and shear of the section (shear_scales = [c, d_y, d_z], docs/theory.md section
!> 17): the linear section field has no warping; the shears 2E12 = a_y + y b_y + z t_y,
!> 2E13 = a_z + y t_z + z b_z are linear in y, z for any F (a the transverse shears, t the
!> twist, b the axial gradients of the section's stretch). Over the volume they take E/2
!> (D0 is the Poisson-free law: with G there the b terms tied a spinning rod's deflection to
!> nu); twist points, at each axial station a pair (0, +-z0), z0 = sqrt(I_y/A), weights A/2,
!> with c G - E/2 on 2E12 only, and a pair (+-y0, 0), y0 = sqrt(I_z/A), with c G - E/2 on
!> 2E13 only (2 Gauss points along the element, the others 4); the neutral-axis points add
!> d G on 2E12, 2E13. With c = J / I_p and
!> d = k - c the twist costs G J tau^2 and a uniform shear k G A, exactly (the pairs are
!> symmetric), and b keeps E/2. Twist and axis points whose law vanishes are skipped.
!>
!> Kelvin-Voigt material damping (retardation time tau, nonlinear_element given the rates):
!> S = D : (E + tau E'), with the strain rate E' = B(F) q' (the Voigt form of sym(F^T F'),
!> F' = q' g^T), so the damping force is Q_d = int tau B^T D E' dV0 and the dissipated power
!> int tau E'^T D E' dV0 >= 0; a rigid motion has E' = 0 (objective). Its derivatives:
!> d/dq' = tau int B^T D B; d/dq = the geometric term of the damping stress tau D E' plus
!> tau int B(F)^T D B(F') (E' is bilinear in F and F'), not symmetric.
module beam_nonlinear
  use ancf_kinds, only: dp
  use quadrature, only: gauss_legendre
  use beam_element, only: beam_shape, material_axes
  use matrix3, only: invert3
  use element_sets, only: local_element_set
  use beam_stations, only: station_section, set_station_forces
  implicit none
  private
  public :: nonlinear_rule_size, nonlinear_setup, nonlinear_element, continuum_set, &
            nonlinear_stress_stiffness, nonlinear_midpoint_element

  !> The family's element set (element_sets): material gradients (8, 3, npts, nel) and
  !> weights (npts, nel) at the Gauss points, the first volume_points of them volume points.
  type, extends(local_element_set) :: continuum_set
    integer :: volume_points = 0
    real(dp), allocatable :: gradients(:, :, :, :), weights(:, :)
    real(dp) :: youngs = 0.0_dp, poisson = 0.0_dp
    !> the section's torsion and shear correction [c, d_y, d_z] (docs/theory.md section 17)
    real(dp) :: shear_scales(3) = [1.0_dp, 0.0_dp, 0.0_dp]
    !> the section data of its section forces (beam_stations)
    type(station_section) :: sections
  contains
    procedure :: element_forces => continuum_element_forces
    procedure :: section_forces => continuum_section_forces
    procedure :: midpoint_forces => continuum_midpoint_forces
  end type continuum_set

  !> Gauss points along the axis; the section rule comes from beam_section. The twist
  !> points use 2 (t^2 is quadratic along the element: exact).
  integer, parameter, public :: nonlinear_axial_points = 4
  integer, parameter :: twist_axial_points = 2

contains

  !> Points per element for a section rule of nsection points: the volume points, the
  !> neutral-axis points, the twist points (0, +-z0) and (+-y0, 0).
  pure integer function nonlinear_rule_size(nsection)
    integer, intent(in) :: nsection
    nonlinear_rule_size = nonlinear_axial_points * (nsection + 1) + 4 * twist_axial_points
  end function nonlinear_rule_size

  !> Material gradients g_a (8, 3, point) and weights (volume element det J0 included) of
  !> one element: first the axial x section volume points (section point outer), then the
  !> neutral-axis points whose weights carry the section area, then the twist points (0, z0),
  !> (0, -z0), (y0, 0), (-y0, 0) of weight A/2. info = 2 for det J0 <= 0.
  pure subroutine nonlinear_setup(reference, length, section_y, section_z, section_w, &
                                  gradients, weights, info)
    real(dp), intent(in) :: reference(3, 8), length, section_y(:), section_z(:), section_w(:)
    real(dp), intent(out) :: gradients(:, :, :), weights(:)   ! (8, 3, npts), (npts)
    integer, intent(out) :: info
    real(dp) :: pa(nonlinear_axial_points), wa(nonlinear_axial_points)
    real(dp) :: pt(twist_axial_points), wt(twist_axial_points), xi, axial_weight
    real(dp) :: shape(8), dshape(8, 3), jac0(3, 3), inv0(3, 3), det0, y, z
    real(dp) :: area, twist_y(4), twist_z(4), twist_w(4)
    integer :: i, s, p, nsection, naxial
    nsection = size(section_w)
    call gauss_legendre(nonlinear_axial_points, pa, wa, info)
    if (info /= 0) return
    call gauss_legendre(twist_axial_points, pt, wt, info)
    if (info /= 0) return
    area = sum(section_w)
    twist_y = [0.0_dp, 0.0_dp, 1.0_dp, -1.0_dp] * sqrt(sum(section_w * section_y**2) / area)
    twist_z = [1.0_dp, -1.0_dp, 0.0_dp, 0.0_dp] * sqrt(sum(section_w * section_z**2) / area)
    twist_w = 0.5_dp * area
    p = 0
    do s = 1, nsection + 5
      naxial = merge(nonlinear_axial_points, twist_axial_points, s <= nsection + 1)
      do i = 1, naxial
        p = p + 1
        if (s <= nsection + 1) then
          xi = 0.5_dp * (pa(i) + 1.0_dp)
          axial_weight = 0.5_dp * wa(i) * length
        else
          xi = 0.5_dp * (pt(i) + 1.0_dp)
          axial_weight = 0.5_dp * wt(i) * length
        end if
        if (s <= nsection) then
          y = section_y(s)
          z = section_z(s)
          weights(p) = axial_weight * section_w(s)
        else if (s == nsection + 1) then
          y = 0.0_dp
          z = 0.0_dp
          weights(p) = axial_weight * area
        else
          y = twist_y(s - nsection - 1)
          z = twist_z(s - nsection - 1)
          weights(p) = axial_weight * twist_w(s - nsection - 1)
        end if
        call beam_shape(xi, y, z, length, shape, dshape(:, 1), dshape(:, 2), dshape(:, 3))
        jac0 = matmul(reference, dshape)
        call invert3(jac0, inv0, det0)
        if (det0 <= 0.0_dp) then
          info = 2
          return
        end if
        ! strains in the section's material axes (axis, height, width): F R0 with R0 the
        ! orthonormal frame of J0's columns (material_axes); F alone would give them in the
        ! global axes, where the split laws below are not those of an isotropic material
        gradients(:, :, p) = matmul(dshape, matmul(inv0, material_axes(jac0)))
        weights(p) = weights(p) * det0
      end do
    end do
  end subroutine nonlinear_setup

  !> Internal force (24), strain energy and, when want_tangent, the tangent (24 x 24) of
  !> one element with nodal vectors q(3, 8).
  !> The first volume_points points integrate the Poisson-free law over the volume, the
  !> others (the neutral-axis points) the Poisson part.
  !> With Kelvin-Voigt damping (the nodal rates q'(3, 8), damping_time tau > 0, rate_factor
  !> and dissipation all present): the force includes the damping force, dissipation is its
  !> power and the tangent (when want_tangent) is dQ/dq + rate_factor dQ/dq' (not symmetric).
  !> (The two point loops stay apart: one loop with the damping behind a flag let the
  !> compiler inline the point helpers and made the undamped force 24 % dearer, measured
  !> with callgrind.)
  pure subroutine nonlinear_element(q, gradients, weights, volume_points, youngs, poisson, &
                                    shear_scales, want_tangent, force, energy, tangent, rates, &
                                    damping_time, rate_factor, dissipation)
    real(dp), intent(in) :: q(3, 8), gradients(:, :, :), weights(:)
    integer, intent(in) :: volume_points
    real(dp), intent(in) :: youngs, poisson, shear_scales(3)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(24), energy, tangent(24, 24)
    real(dp), intent(in), optional :: rates(3, 8), damping_time, rate_factor
    real(dp), intent(out), optional :: dissipation
    if (present(rates)) then
      call damped_points(q, rates, gradients, weights, volume_points, youngs, poisson, &
                         shear_scales, damping_time, rate_factor, want_tangent, force, energy, &
                         dissipation, tangent)
    else
      call elastic_points(q, gradients, weights, volume_points, youngs, poisson, shear_scales, &
                          want_tangent, force, energy, tangent)
    end if
  end subroutine nonlinear_element

  !> The initial-stress part of nonlinear_element's tangent for the stress increments of
  !> the nodal increment dq(3, 8) at q(3, 8): sum_points w kron(G dS G^T, I3) with
  !> dS = D B(q) dq (the tangent's geometric term with each stress replaced by its
  !> increment): the geometric stiffness of classical linear buckling.
  pure subroutine nonlinear_stress_stiffness(q, dq, gradients, weights, volume_points, &
                                             youngs, poisson, shear_scales, tangent)
    real(dp), intent(in) :: q(3, 8), dq(3, 8), gradients(:, :, :), weights(:)
    integer, intent(in) :: volume_points
    real(dp), intent(in) :: youngs, poisson, shear_scales(3)
    real(dp), intent(out) :: tangent(24, 24)
    real(dp) :: law_free(6, 6), law_poisson(6, 6), law(6, 6), deformation(3, 3)
    real(dp) :: law_twist_y(6, 6), law_twist_z(6, 6), b(6, 24)
    integer :: p
    call split_laws(youngs, poisson, shear_scales, law_free, law_poisson, law_twist_y, &
                    law_twist_z)
    tangent = 0.0_dp
    do p = 1, size(weights)
      law = point_law(p, volume_points, law_free, law_poisson, law_twist_y, law_twist_z)
      if (p > volume_points .and. all(law == 0.0_dp)) cycle
      call deformation_gradient(q, gradients(:, :, p), deformation)
      call strain_matrix(deformation, gradients(:, :, p), b)
      call add_geometric_stiffness(matmul(law, matmul(b, reshape(dq, [24]))), &
                                   gradients(:, :, p), weights(p), tangent)
    end do
  end subroutine nonlinear_stress_stiffness

  !> nonlinear_element without damping (its loop over the Gauss points). The first
  !> volume_points points integrate the Poisson-free law over the volume, the
  !> others (the neutral-axis points) the Poisson part.
  pure subroutine elastic_points(q, gradients, weights, volume_points, youngs, poisson, &
                                 shear_scales, want_tangent, force, energy, tangent)
    real(dp), intent(in) :: q(3, 8), gradients(:, :, :), weights(:)
    integer, intent(in) :: volume_points
    real(dp), intent(in) :: youngs, poisson, shear_scales(3)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(24), energy, tangent(24, 24)
    real(dp) :: law_free(6, 6), law_poisson(6, 6), law(6, 6), deformation(3, 3), strain(6)
    real(dp) :: law_twist_y(6, 6), law_twist_z(6, 6)
    real(dp) :: stress(6), b(6, 24), db(6, 24)
    integer :: p
    call split_laws(youngs, poisson, shear_scales, law_free, law_poisson, law_twist_y, &
                    law_twist_z)
    force = 0.0_dp
    energy = 0.0_dp
    if (want_tangent) tangent = 0.0_dp  ! (a force-only call leaves it alone, as the plate does)
    do p = 1, size(weights)
      law = point_law(p, volume_points, law_free, law_poisson, law_twist_y, law_twist_z)
      if (p > volume_points .and. all(law == 0.0_dp)) cycle
      call deformation_gradient(q, gradients(:, :, p), deformation)
      call green_lagrange(deformation, strain)
      stress = matmul(law, strain)
      energy = energy + 0.5_dp * weights(p) * dot_product(strain, stress)
      call add_nodal_force(deformation, stress, gradients(:, :, p), weights(p), force)
      if (.not. want_tangent) cycle
      call strain_matrix(deformation, gradients(:, :, p), b)
      db = matmul(law, b)
      tangent = tangent + weights(p) * matmul(transpose(b), db)
      call add_geometric_stiffness(stress, gradients(:, :, p), weights(p), tangent)
    end do
  end subroutine elastic_points

  !> nonlinear_element with Kelvin-Voigt damping (damping_time tau > 0) at the nodal rates
  !> q'(3, 8) (its loop over the Gauss points): the force includes the damping force, dissipation is its power and the
  !> tangent (when want_tangent) is dQ/dq + rate_factor dQ/dq' (not symmetric).
  pure subroutine damped_points(q, rates, gradients, weights, volume_points, youngs, &
                                poisson, shear_scales, damping_time, rate_factor, &
                                want_tangent, force, energy, dissipation, tangent)
    real(dp), intent(in) :: q(3, 8), rates(3, 8), gradients(:, :, :), weights(:)
    integer, intent(in) :: volume_points
    real(dp), intent(in) :: youngs, poisson, shear_scales(3), damping_time, rate_factor
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(24), energy, dissipation, tangent(24, 24)
    real(dp) :: law_free(6, 6), law_poisson(6, 6), law(6, 6), deformation(3, 3), strain(6)
    real(dp) :: law_twist_y(6, 6), law_twist_z(6, 6)
    real(dp) :: stress(6), b(6, 24), b_rate(6, 24)
    real(dp) :: deformation_rate(3, 3), strain_rate(6), damping_stress(6)
    integer :: p
    call split_laws(youngs, poisson, shear_scales, law_free, law_poisson, law_twist_y, &
                    law_twist_z)
    force = 0.0_dp
    energy = 0.0_dp
    dissipation = 0.0_dp
    if (want_tangent) tangent = 0.0_dp  ! (a force-only call leaves it alone, as the plate does)
    do p = 1, size(weights)
      law = point_law(p, volume_points, law_free, law_poisson, law_twist_y, law_twist_z)
      if (p > volume_points .and. all(law == 0.0_dp)) cycle
      call deformation_gradient(q, gradients(:, :, p), deformation)
      call deformation_gradient(rates, gradients(:, :, p), deformation_rate)
      call green_lagrange(deformation, strain)
      call green_lagrange_rate(deformation, deformation_rate, strain_rate)
      stress = matmul(law, strain)
      damping_stress = damping_time * matmul(law, strain_rate)
      energy = energy + 0.5_dp * weights(p) * dot_product(strain, stress)
      dissipation = dissipation + weights(p) * dot_product(strain_rate, damping_stress)
      stress = stress + damping_stress
      call add_nodal_force(deformation, stress, gradients(:, :, p), weights(p), force)
      if (.not. want_tangent) cycle
      call strain_matrix(deformation, gradients(:, :, p), b)
      ! (1 + c tau) B^T D B + tau B^T D B(F') + the geometric term of the total stress
      call strain_matrix(deformation_rate, gradients(:, :, p), b_rate)
      tangent = tangent + weights(p) * matmul(transpose(b), &
                matmul(law, (1.0_dp + rate_factor * damping_time) * b + damping_time * b_rate))
      call add_geometric_stiffness(stress, gradients(:, :, p), weights(p), tangent)
    end do
  end subroutine damped_points

  !> The element_set element_forces of a continuum set: nonlinear_element of element el.
  pure subroutine continuum_element_forces(set, el, coords, want_tangent, force, energy, &
                                           tangent, info, rates, rate_factor, dissipation)
    class(continuum_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: coords(:, :)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(:), energy, tangent(:, :)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: rates(:, :), rate_factor
    real(dp), intent(out), optional :: dissipation
    info = 0
    if (present(rates)) then
      call nonlinear_element(coords, set%gradients(:, :, :, el), set%weights(:, el), &
                             set%volume_points, set%youngs, set%poisson, set%shear_scales, &
                             want_tangent, force, energy, tangent, rates, set%damping_time, &
                             rate_factor, dissipation)
    else
      call nonlinear_element(coords, set%gradients(:, :, :, el), set%weights(:, el), &
                             set%volume_points, set%youngs, set%poisson, set%shear_scales, &
                             want_tangent, force, energy, tangent)
    end if
  end subroutine continuum_element_forces

  !> The discrete-gradient force of the energy-momentum stepper (Simo & Tarnow 1992, the
  !> averaged stress): with F_m = (F0 + F1)/2 and S = D (E(F0) + E(F1))/2 at each point,
  !>   f = sum_p w_p B(F_m)^T S,
  !> and, since E is quadratic in q (E1 - E0 = B(F_m) (q1 - q0) exactly),
  !> W(q1) - W(q0) = sum w (E1 - E0)^T D (E1 + E0)/2 = f . (q1 - q0) to round-off; at q0 = q1
  !> it is the force of nonlinear_element. The points' laws are those of elastic_points
  !> (undamped). The Jacobian df/dq1 (want_tangent): w [B(F_m)^T D B(F1) + kron(G S G^T, I3)] / 2
  !> (not symmetric).
  pure subroutine nonlinear_midpoint_element(q0, q1, gradients, weights, volume_points, &
                                             youngs, poisson, shear_scales, want_tangent, &
                                             force, tangent)
    real(dp), intent(in) :: q0(3, 8), q1(3, 8), gradients(:, :, :), weights(:)
    integer, intent(in) :: volume_points
    real(dp), intent(in) :: youngs, poisson, shear_scales(3)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(24), tangent(24, 24)
    real(dp) :: law_free(6, 6), law_poisson(6, 6), law(6, 6), law_twist_y(6, 6)
    real(dp) :: law_twist_z(6, 6), deformation0(3, 3), deformation1(3, 3), middle(3, 3)
    real(dp) :: strain0(6), strain1(6), stress(6), b_middle(6, 24), b_end(6, 24)
    integer :: p
    call split_laws(youngs, poisson, shear_scales, law_free, law_poisson, law_twist_y, &
                    law_twist_z)
    force = 0.0_dp
    if (want_tangent) tangent = 0.0_dp
    do p = 1, size(weights)
      law = point_law(p, volume_points, law_free, law_poisson, law_twist_y, law_twist_z)
      if (p > volume_points .and. all(law == 0.0_dp)) cycle
      call deformation_gradient(q0, gradients(:, :, p), deformation0)
      call deformation_gradient(q1, gradients(:, :, p), deformation1)
      middle = 0.5_dp * (deformation0 + deformation1)
      call green_lagrange(deformation0, strain0)
      call green_lagrange(deformation1, strain1)
      stress = matmul(law, 0.5_dp * (strain0 + strain1))
      call add_nodal_force(middle, stress, gradients(:, :, p), weights(p), force)
      if (.not. want_tangent) cycle
      call strain_matrix(middle, gradients(:, :, p), b_middle)
      call strain_matrix(deformation1, gradients(:, :, p), b_end)
      tangent = tangent + 0.5_dp * weights(p) * matmul(transpose(b_middle), matmul(law, b_end))
      call add_geometric_stiffness(stress, gradients(:, :, p), 0.5_dp * weights(p), tangent)
    end do
  end subroutine nonlinear_midpoint_element

  !> The local_element_set midpoint_forces of a continuum set: nonlinear_midpoint_element of
  !> element el (an undamped set; a damped one has no discrete gradient here: info = 1).
  pure subroutine continuum_midpoint_forces(set, el, coords0, coords1, want_tangent, force, &
                                            tangent, info)
    class(continuum_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: coords0(:, :), coords1(:, :)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(:), tangent(:, :)
    integer, intent(out) :: info
    info = 0
    if (set%damping_time > 0.0_dp) then
      force = 0.0_dp
      info = 1
      return
    end if
    call nonlinear_midpoint_element(coords0, coords1, set%gradients(:, :, :, el), &
                                    set%weights(:, el), set%volume_points, set%youngs, &
                                    set%poisson, set%shear_scales, want_tangent, force, tangent)
  end subroutine continuum_midpoint_forces

  !> The rate of the Green-Lagrange strain (Voigt, engineering shears) at the deformation
  !> gradient F and its rate F': the Voigt form of sym(F^T F'), i.e. B(F) q'.
  pure subroutine green_lagrange_rate(deformation, deformation_rate, strain_rate)
    real(dp), intent(in) :: deformation(3, 3), deformation_rate(3, 3)
    real(dp), intent(out) :: strain_rate(6)
    strain_rate(1) = dot_product(deformation(:, 1), deformation_rate(:, 1))
    strain_rate(2) = dot_product(deformation(:, 2), deformation_rate(:, 2))
    strain_rate(3) = dot_product(deformation(:, 3), deformation_rate(:, 3))
    strain_rate(4) = dot_product(deformation(:, 1), deformation_rate(:, 2)) &
                     + dot_product(deformation(:, 2), deformation_rate(:, 1))
    strain_rate(5) = dot_product(deformation(:, 2), deformation_rate(:, 3)) &
                     + dot_product(deformation(:, 3), deformation_rate(:, 2))
    strain_rate(6) = dot_product(deformation(:, 1), deformation_rate(:, 3)) &
                     + dot_product(deformation(:, 3), deformation_rate(:, 1))
  end subroutine green_lagrange_rate

  !> F = sum_a q_a g_a^T (or its rate, with the nodal rates for q) at one point.
  pure subroutine deformation_gradient(q, point_gradients, deformation)
    real(dp), intent(in) :: q(3, 8), point_gradients(8, 3)
    real(dp), intent(out) :: deformation(3, 3)
    integer :: a, k
    deformation = 0.0_dp
    do k = 1, 3
      do a = 1, 8
        deformation(:, k) = deformation(:, k) + q(:, a) * point_gradients(a, k)
      end do
    end do
  end subroutine deformation_gradient

  !> force += w B^T S, as Q_a += w F S g_a (S the symmetric stress matrix of the Voigt
  !> stress): without forming B, which only the tangent needs.
  pure subroutine add_nodal_force(deformation, stress, point_gradients, weight, force)
    real(dp), intent(in) :: deformation(3, 3), stress(6), point_gradients(8, 3), weight
    real(dp), intent(inout) :: force(24)
    real(dp) :: piola(3, 3)
    integer :: a
    ! w F S, column by column of S = [S1 S4 S6; S4 S2 S5; S6 S5 S3]
    piola(:, 1) = weight * (deformation(:, 1) * stress(1) + deformation(:, 2) * stress(4) &
                            + deformation(:, 3) * stress(6))
    piola(:, 2) = weight * (deformation(:, 1) * stress(4) + deformation(:, 2) * stress(2) &
                            + deformation(:, 3) * stress(5))
    piola(:, 3) = weight * (deformation(:, 1) * stress(6) + deformation(:, 2) * stress(5) &
                            + deformation(:, 3) * stress(3))
    do a = 1, 8
      force(3 * a - 2:3 * a) = force(3 * a - 2:3 * a) + piola(:, 1) * point_gradients(a, 1) &
                               + piola(:, 2) * point_gradients(a, 2) &
                               + piola(:, 3) * point_gradients(a, 3)
    end do
  end subroutine add_nodal_force

  !> Green-Lagrange strain in Voigt form with engineering shears [E11, E22, E33, 2E12, 2E23, 2E13].
  pure subroutine green_lagrange(deformation, strain)
    real(dp), intent(in) :: deformation(3, 3)
    real(dp), intent(out) :: strain(6)
    real(dp) :: c(3, 3)
    c = matmul(transpose(deformation), deformation)
    strain = [0.5_dp * (c(1, 1) - 1.0_dp), 0.5_dp * (c(2, 2) - 1.0_dp), 0.5_dp * (c(3, 3) - 1.0_dp), &
              c(1, 2), c(2, 3), c(1, 3)]
  end subroutine green_lagrange

  !> B(6, 24): d strain = B dq, columns (a, i) -> 3(a-1)+i.
  pure subroutine strain_matrix(deformation, gradient, b)
    real(dp), intent(in) :: deformation(3, 3), gradient(8, 3)
    real(dp), intent(out) :: b(6, 24)
    integer :: a, i, col
    do a = 1, 8
      do i = 1, 3
        col = 3 * (a - 1) + i
        b(1, col) = deformation(i, 1) * gradient(a, 1)
        b(2, col) = deformation(i, 2) * gradient(a, 2)
        b(3, col) = deformation(i, 3) * gradient(a, 3)
        b(4, col) = deformation(i, 1) * gradient(a, 2) + deformation(i, 2) * gradient(a, 1)
        b(5, col) = deformation(i, 2) * gradient(a, 3) + deformation(i, 3) * gradient(a, 2)
        b(6, col) = deformation(i, 1) * gradient(a, 3) + deformation(i, 3) * gradient(a, 1)
      end do
    end do
  end subroutine strain_matrix

  !> D0 = diag(E, E, E, G, G, G) and the Poisson part D - D0 of the isotropic law, with the
  !> section's torsion and shear correction shear_scales = [c, d_y, d_z]: G d_y and G d_z
  !> on 2E12, 2E13 added to the neutral-axis law, (c - 1) G on 2E12 at the twist points
  !> (0, +-z0) and on 2E13 at (+-y0, 0).
  pure subroutine split_laws(youngs, poisson, shear_scales, law_free, law_poisson, &
                             law_twist_y, law_twist_z)
    real(dp), intent(in) :: youngs, poisson, shear_scales(3)
    real(dp), intent(out) :: law_free(6, 6), law_poisson(6, 6)
    real(dp), intent(out) :: law_twist_y(6, 6), law_twist_z(6, 6)
    real(dp) :: lame, shear
    integer :: i
    lame = youngs * poisson / ((1.0_dp + poisson) * (1.0_dp - 2.0_dp * poisson))
    shear = youngs / (2.0_dp * (1.0_dp + poisson))
    law_free = 0.0_dp
    law_poisson = 0.0_dp
    law_poisson(1:3, 1:3) = lame
    do i = 1, 3
      law_free(i, i) = youngs
      law_free(i + 3, i + 3) = shear
      law_poisson(i, i) = lame + 2.0_dp * shear - youngs
    end do
    ! the shears that vary over the section (2E12, 2E13) take E/2, the Poisson-free law's
    ! modulus, over the volume (docs/theory.md section 17: with G there, their y b_y and z b_z
    ! parts tied the deflection of a spinning rod to nu); the twist points make the twist
    ! c G I_p = G J and the neutral axis the uniform shear k G A
    law_free(4, 4) = 0.5_dp * youngs
    law_free(6, 6) = 0.5_dp * youngs
    law_poisson(4, 4) = shear_scales(2) * shear
    law_poisson(6, 6) = shear_scales(3) * shear
    law_twist_y = 0.0_dp
    law_twist_z = 0.0_dp
    law_twist_y(4, 4) = shear_scales(1) * shear - 0.5_dp * youngs
    law_twist_z(6, 6) = shear_scales(1) * shear - 0.5_dp * youngs
  end subroutine split_laws

  !> The law of point p: volume points, then the neutral-axis points (nonlinear_axial_points
  !> of them), the twist points (0, +-z0) and (+-y0, 0) (twist_axial_points of each;
  !> nonlinear_setup's order).
  pure function point_law(p, volume_points, law_free, law_poisson, law_twist_y, law_twist_z) &
      result(law)
    integer, intent(in) :: p, volume_points
    real(dp), intent(in) :: law_free(6, 6), law_poisson(6, 6), law_twist_y(6, 6)
    real(dp), intent(in) :: law_twist_z(6, 6)
    real(dp) :: law(6, 6)
    if (p <= volume_points) then
      law = law_free
    else if (p <= volume_points + nonlinear_axial_points) then
      law = law_poisson
    else if (p <= volume_points + nonlinear_axial_points + 2 * twist_axial_points) then
      law = law_twist_y
    else
      law = law_twist_z
    end if
  end function point_law

  !> tangent += w kron(G S G^T, I3): the geometric stiffness of the second Piola-Kirchhoff
  !> stress S (Voigt) with the material gradients G (8, 3) of the shape functions.
  pure subroutine add_geometric_stiffness(stress, point_gradients, weight, tangent)
    real(dp), intent(in) :: stress(6), point_gradients(8, 3), weight
    real(dp), intent(inout) :: tangent(24, 24)
    real(dp) :: stress_matrix(3, 3), sg(3), geometric
    integer :: a, c, i
    stress_matrix = reshape([stress(1), stress(4), stress(6), stress(4), stress(2), stress(5), &
                             stress(6), stress(5), stress(3)], [3, 3])
    do a = 1, 8
      sg = matmul(stress_matrix, point_gradients(a, :))
      do c = 1, 8
        geometric = weight * dot_product(point_gradients(c, :), sg)
        do i = 1, 3
          tangent(3 * (a - 1) + i, 3 * (c - 1) + i) = tangent(3 * (a - 1) + i, 3 * (c - 1) + i) &
                                                      + geometric
        end do
      end do
    end do
  end subroutine add_geometric_stiffness

  !> The element_set section_forces of a continuum set (beam_stations; its bending option
  !> in the section data: a nonlinear beam's 'cubic' bending is a cubic_set).
  subroutine continuum_section_forces(set, rotations, q_rows, xi, forces, info)
    class(continuum_set), intent(inout) :: set
    real(dp), intent(in) :: rotations(:, :, :), q_rows(:, :), xi(:)
    real(dp), intent(out) :: forces(:, :, :)
    integer, intent(out) :: info
    call set_station_forces(set%sections, set%dofs, q_rows, xi, forces, info)
  end subroutine continuum_section_forces

end module beam_nonlinear
