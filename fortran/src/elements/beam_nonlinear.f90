!> Large-deformation elastic forces of the 12-coordinate ANCF beam (kinematics of
!> beam_element): continuum mechanics with the Green-Lagrange strain and a St. Venant-
!> Kirchhoff material, F = J J0^{-1} so a curved reference is strain-free (seed 003,
!> eqs. 1-2). With the material gradients g_a = J0^{-T} grad N_a precomputed at the Gauss
!> points,
!>   F = sum_a q_a g_a^T,  E = (F^T F - I)/2,  S = D : E,
!>   Q_a = int F S g_a dV0,  K_ab = int B_a^T D B_b dV0 + int (g_a^T S g_b) I3 dV0.
!> At the reference (F = I, S = 0) the tangent equals the small-strain K0 of the FFR model.
!>
!> Poisson locking (the section fields are linear in y, z): D is split into the Poisson-free
!> part D0 = diag(E, E, E, G, G, G), integrated over the whole section, and the Poisson
!> part D - D0, integrated on the neutral axis only (the splitting of enhanced continuum
!> mechanics); with nu = 0 both coincide with the plain law.
!>
!> Torsion and shear of the section (shear_scales = [c, d_y, d_z], docs/theory.md): the
!> linear section field has no warping, so the shears 2E12, 2E13 at the volume points
!> carry a twist tau with the polar moment, G I_p tau^2/2. Their modulus is scaled there by
!> c = J / I_p (J the Saint-Venant torsion constant), and the neutral-axis points add
!> G d_y, G d_z on 2E12, 2E13 with d = k - c (k the section's shear factor): the section
!> strain 2E12 = a + y b + z t is linear in (y, z) for any F, so the section integrates to
!>   c G (A a^2 + I_z b^2 + I_y t^2) + d_y G A a^2 = k_y G A a^2 + c G (I_z b^2 + I_y t^2):
!> torsion G J, shear k G A, exactly (the rule is symmetric). [1, 0, 0]: the plain law.
!>
!> Kelvin-Voigt material damping (retardation time tau, nonlinear_element_damped):
!> S = D : (E + tau E'), with the strain rate E' = B(F) q' (the Voigt form of sym(F^T F'),
!> F' = q' g^T), so the damping force is Q_d = int tau B^T D E' dV0 and the dissipated power
!> int tau E'^T D E' dV0 >= 0; a rigid motion has E' = 0 (objective). Its derivatives:
!> d/dq' = tau int B^T D B; d/dq = the geometric term of the damping stress tau D E' plus
!> tau int B(F)^T D B(F') (E' is bilinear in F and F'), not symmetric.
module beam_nonlinear
  use ancf_kinds, only: dp
  use quadrature, only: gauss_legendre
  use beam_element, only: beam_shape
  use matrix3, only: invert3
  implicit none
  private
  public :: nonlinear_rule_size, nonlinear_setup, nonlinear_element, nonlinear_element_damped

  !> Gauss points along the axis; the section rule comes from beam_section.
  integer, parameter, public :: nonlinear_axial_points = 4

contains

  !> Points per element for a section rule of nsection points: the volume points, then the
  !> neutral-axis points.
  pure integer function nonlinear_rule_size(nsection)
    integer, intent(in) :: nsection
    nonlinear_rule_size = nonlinear_axial_points * (nsection + 1)
  end function nonlinear_rule_size

  !> Material gradients g_a (8, 3, point) and weights (volume element det J0 included) of
  !> one element: first the axial x section volume points (section point outer), then the
  !> neutral-axis points whose weights carry the section area. info = 2 for det J0 <= 0.
  pure subroutine nonlinear_setup(reference, length, section_y, section_z, section_w, &
                                  gradients, weights, info)
    real(dp), intent(in) :: reference(3, 8), length, section_y(:), section_z(:), section_w(:)
    real(dp), intent(out) :: gradients(:, :, :), weights(:)   ! (8, 3, npts), (npts)
    integer, intent(out) :: info
    real(dp) :: pa(nonlinear_axial_points), wa(nonlinear_axial_points)
    real(dp) :: shape(8), dshape(8, 3), jac0(3, 3), inv0(3, 3), det0, y, z
    integer :: i, s, p, nsection
    nsection = size(section_w)
    call gauss_legendre(nonlinear_axial_points, pa, wa, info)
    if (info /= 0) return
    p = 0
    do s = 1, nsection + 1
      do i = 1, nonlinear_axial_points
        p = p + 1
        if (s <= nsection) then
          y = section_y(s)
          z = section_z(s)
          weights(p) = 0.5_dp * wa(i) * length * section_w(s)
        else
          y = 0.0_dp
          z = 0.0_dp
          weights(p) = 0.5_dp * wa(i) * length * sum(section_w)
        end if
        call beam_shape(0.5_dp * (pa(i) + 1.0_dp), y, z, length, shape, dshape(:, 1), &
                        dshape(:, 2), dshape(:, 3))
        jac0 = matmul(reference, dshape)
        call invert3(jac0, inv0, det0)
        if (det0 <= 0.0_dp) then
          info = 2
          return
        end if
        gradients(:, :, p) = matmul(dshape, inv0)
        weights(p) = weights(p) * det0
      end do
    end do
  end subroutine nonlinear_setup

  !> Internal force (24), strain energy and, when want_tangent, the tangent (24 x 24) of
  !> one element with nodal vectors q(3, 8).
  !> The first volume_points points integrate the Poisson-free law over the volume, the
  !> others (the neutral-axis points) the Poisson part.
  pure subroutine nonlinear_element(q, gradients, weights, volume_points, youngs, poisson, &
                                    shear_scales, want_tangent, force, energy, tangent)
    real(dp), intent(in) :: q(3, 8), gradients(:, :, :), weights(:)
    integer, intent(in) :: volume_points
    real(dp), intent(in) :: youngs, poisson, shear_scales(3)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(24), energy, tangent(24, 24)
    real(dp) :: law_free(6, 6), law_poisson(6, 6), law(6, 6), deformation(3, 3), strain(6)
    real(dp) :: stress(6), b(6, 24), db(6, 24)
    integer :: p
    call split_laws(youngs, poisson, shear_scales, law_free, law_poisson)
    force = 0.0_dp
    energy = 0.0_dp
    if (want_tangent) tangent = 0.0_dp  ! (a force-only call leaves it alone, as the plate does)
    do p = 1, size(weights)
      if (p <= volume_points) then
        law = law_free
      else
        law = law_poisson
        if (all(law == 0.0_dp)) cycle
      end if
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
  end subroutine nonlinear_element

  !> nonlinear_element with Kelvin-Voigt damping (damping_time tau > 0) at the nodal rates
  !> q'(3, 8): the force includes the damping force, dissipation is its power and the
  !> tangent (when want_tangent) is dQ/dq + rate_factor dQ/dq' (not symmetric).
  pure subroutine nonlinear_element_damped(q, rates, gradients, weights, volume_points, youngs, &
                                           poisson, shear_scales, damping_time, rate_factor, &
                                           want_tangent, force, energy, dissipation, tangent)
    real(dp), intent(in) :: q(3, 8), rates(3, 8), gradients(:, :, :), weights(:)
    integer, intent(in) :: volume_points
    real(dp), intent(in) :: youngs, poisson, shear_scales(3), damping_time, rate_factor
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(24), energy, dissipation, tangent(24, 24)
    real(dp) :: law_free(6, 6), law_poisson(6, 6), law(6, 6), deformation(3, 3), strain(6)
    real(dp) :: stress(6), b(6, 24), b_rate(6, 24)
    real(dp) :: deformation_rate(3, 3), strain_rate(6), damping_stress(6)
    integer :: p
    call split_laws(youngs, poisson, shear_scales, law_free, law_poisson)
    force = 0.0_dp
    energy = 0.0_dp
    dissipation = 0.0_dp
    if (want_tangent) tangent = 0.0_dp  ! (a force-only call leaves it alone, as the plate does)
    do p = 1, size(weights)
      if (p <= volume_points) then
        law = law_free
      else
        law = law_poisson
        if (all(law == 0.0_dp)) cycle
      end if
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
  end subroutine nonlinear_element_damped

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
  !> section's torsion and shear correction shear_scales = [c, d_y, d_z]: D0's G on 2E12
  !> and 2E13 times c (volume points), G d_y and G d_z added to the neutral-axis law.
  pure subroutine split_laws(youngs, poisson, shear_scales, law_free, law_poisson)
    real(dp), intent(in) :: youngs, poisson, shear_scales(3)
    real(dp), intent(out) :: law_free(6, 6), law_poisson(6, 6)
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
    law_free(4, 4) = shear_scales(1) * shear
    law_free(6, 6) = shear_scales(1) * shear
    law_poisson(4, 4) = shear_scales(2) * shear
    law_poisson(6, 6) = shear_scales(3) * shear
  end subroutine split_laws

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

end module beam_nonlinear
