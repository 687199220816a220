!> Two-node segment of the multi-node 3D ANCF beam of seed 000 (eqs. 1-12),
!> the kinematics of Chrono's ChElementBeamANCF_3243.
!>
!> Each node carries 12 coordinates [r, r_x, r_y, r_z]. With xi = x/L in [0, 1]
!> and section coordinates y (height h) and z (width w), centred on the neutral axis,
!>
!>   r(x, y, z) = sum_a N_a q_a,   N = [N1, L N2, y (1 - xi), z (1 - xi), N3, L N4, y xi, z xi]
!>
!> with the cubic Hermite N1..N4 (eqs. 4-5, with f_yR = b a, f_zR = c a: the printed
!> "b - a" is a misprint, docs/README.md "References"). Compact arrays (8 x 8, 3 x 8) act on the
!> eight nodal 3-vectors q_a; the full 24 x 24 matrices are the compact ones times I3
!> (mass) or are built per 3 x 3 block (stiffness).
module beam_element
  use ancf_kinds, only: dp
  use quadrature, only: gauss_legendre
  use matrix3, only: invert3
  implicit none
  private
  public :: beam_shape, beam_mass_compact, beam_gravity_compact, &
            beam_linear_stiffness, beam_point_mass_compact, material_axes

  !> Gauss points along the axis: exact for the mass (degree 6 in xi) and the linear
  !> stiffness (degree 4 in xi); the section rules come from beam_section.
  integer, parameter :: n_axial = 4

contains

  !> Shape functions N(8) at (xi, y, z) and their derivatives with respect to the
  !> element parameters (x = xi L, y, z).
  pure subroutine beam_shape(xi, y, z, length, shape, dshape_dx, dshape_dy, dshape_dz)
    real(dp), intent(in) :: xi, y, z, length
    real(dp), intent(out) :: shape(8), dshape_dx(8), dshape_dy(8), dshape_dz(8)
    real(dp) :: xi2, xi3
    xi2 = xi * xi
    xi3 = xi2 * xi
    shape = [1.0_dp - 3.0_dp * xi2 + 2.0_dp * xi3, length * (xi - 2.0_dp * xi2 + xi3), &
             y * (1.0_dp - xi), z * (1.0_dp - xi), &
             3.0_dp * xi2 - 2.0_dp * xi3, length * (xi3 - xi2), y * xi, z * xi]
    dshape_dx = [(-6.0_dp * xi + 6.0_dp * xi2) / length, 1.0_dp - 4.0_dp * xi + 3.0_dp * xi2, &
                 -y / length, -z / length, &
                 (6.0_dp * xi - 6.0_dp * xi2) / length, 3.0_dp * xi2 - 2.0_dp * xi, &
                 y / length, z / length]
    dshape_dy = [0.0_dp, 0.0_dp, 1.0_dp - xi, 0.0_dp, 0.0_dp, 0.0_dp, xi, 0.0_dp]
    dshape_dz = [0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp - xi, 0.0_dp, 0.0_dp, 0.0_dp, xi]
  end subroutine beam_shape

  !> Gauss points along the axis (xi in [0, 1]) and the volume weights of the axial points
  !> times the section points: weight(i, s) = L dxi_i dA_s for a straight reference.
  pure subroutine volume_rule(length, section_w, xi, weight, info)
    real(dp), intent(in) :: length, section_w(:)
    real(dp), intent(out) :: xi(n_axial), weight(n_axial, size(section_w))
    integer, intent(out) :: info
    real(dp) :: pa(n_axial), wa(n_axial)
    integer :: i, s
    call gauss_legendre(n_axial, pa, wa, info)
    xi = 0.5_dp * (pa + 1.0_dp)
    do s = 1, size(section_w)
      do i = 1, n_axial
        weight(i, s) = 0.5_dp * wa(i) * length * section_w(s)
      end do
    end do
  end subroutine volume_rule

  !> Compact consistent mass matrix m_ab = int rho N_a N_b dV (8 x 8) over the section rule
  !> (section_y, section_z, section_w) (beam_section); the full element mass matrix is
  !> kron(mass, I3). Exact for the section rules of beam_section.
  pure subroutine beam_mass_compact(length, section_y, section_z, section_w, density, mass, info)
    real(dp), intent(in) :: length, section_y(:), section_z(:), section_w(:), density
    real(dp), intent(out) :: mass(8, 8)
    integer, intent(out) :: info
    real(dp) :: xi(n_axial), weight(n_axial, size(section_w))
    real(dp) :: shape(8), d_dx(8), d_dy(8), d_dz(8)
    integer :: i, s, a
    call volume_rule(length, section_w, xi, weight, info)
    mass = 0.0_dp
    do s = 1, size(section_w)
      do i = 1, n_axial
        call beam_shape(xi(i), section_y(s), section_z(s), length, shape, d_dx, d_dy, d_dz)
        do a = 1, 8
          mass(:, a) = mass(:, a) + density * weight(i, s) * shape * shape(a)
        end do
      end do
    end do
  end subroutine beam_mass_compact

  !> Generalized gravity force (eqs. 22-24): Q_a = int rho N_a g dV, as 3 x 8.
  pure subroutine beam_gravity_compact(length, section_y, section_z, section_w, density, &
                                       gravity, force, info)
    real(dp), intent(in) :: length, section_y(:), section_z(:), section_w(:), density, gravity(3)
    real(dp), intent(out) :: force(3, 8)
    integer, intent(out) :: info
    real(dp) :: xi(n_axial), weight(n_axial, size(section_w))
    real(dp) :: shape(8), d_dx(8), d_dy(8), d_dz(8)
    integer :: i, s, a
    call volume_rule(length, section_w, xi, weight, info)
    force = 0.0_dp
    do s = 1, size(section_w)
      do i = 1, n_axial
        call beam_shape(xi(i), section_y(s), section_z(s), length, shape, d_dx, d_dy, d_dz)
        do a = 1, 8
          force(:, a) = force(:, a) + density * weight(i, s) * shape(a) * gravity
        end do
      end do
    end do
  end subroutine beam_gravity_compact

  !> Compact mass of a point mass at the material point (xi, y, z): mass N_a N_b.
  pure subroutine beam_point_mass_compact(xi, y, z, length, point_mass, mass)
    real(dp), intent(in) :: xi, y, z, length, point_mass
    real(dp), intent(out) :: mass(8, 8)
    real(dp) :: shape(8), d_dx(8), d_dy(8), d_dz(8)
    integer :: a
    call beam_shape(xi, y, z, length, shape, d_dx, d_dy, d_dz)
    do a = 1, 8
      mass(:, a) = point_mass * shape * shape(a)
    end do
  end subroutine beam_point_mass_compact

  !> Constant small-strain stiffness K0 (eqs. 13-21) of the element in its reference
  !> configuration reference(3, 8) (nodal vectors, expressed in the floating frame).
  !> Strain eps = [e_xx, e_yy, e_zz, g_xy, g_yz, g_xz] of u = S (e - e0) with respect
  !> to the reference material coordinates X = r0(x, y, z); isotropic law (E, nu), which
  !> for nu = 0 is the paper's Q = diag(E, E, E, E/2, E/2, E/2) (eq. 18).
  !> Torsion and shear of the section (shear_scales = [c, d_y, d_z], as beam_nonlinear):
  !> E/2 on g_xy, g_xz over the section, G d_y, G d_z on the neutral axis, and c G - E/2 on
  !> g_xy at the twist points (0, +-sqrt(I_y/A)), on g_xz at (+-sqrt(I_z/A), 0) (weights
  !> A/2), so the twist costs G J (c = J / I_p) and a uniform shear k G A (d = k - c).
  !> info: 0 ok, 1 bad quadrature, 2 degenerate reference (det J0 <= 0).
  pure subroutine beam_linear_stiffness(reference, length, section_y, section_z, section_w, &
                                        youngs, poisson, shear_scales, stiffness, info)
    real(dp), intent(in) :: reference(3, 8), length, section_y(:), section_z(:), section_w(:)
    real(dp), intent(in) :: youngs, poisson, shear_scales(3)
    real(dp), intent(out) :: stiffness(24, 24)
    integer, intent(out) :: info
    real(dp) :: xi(n_axial), weight(n_axial, size(section_w))
    real(dp) :: shape(8), dshape(8, 3), jacobian0(3, 3), inverse0(3, 3), det0
    real(dp) :: material_gradient(8, 3), strain_matrix(6, 24), elasticity(6, 6)
    real(dp) :: laws(6, 6, 3), shear, area, point_y(5), point_z(5), point_w(5), law(6, 6)
    real(dp) :: pt(2), wt(2), xi_point, weight_point, axes(3, 3)
    integer :: i, s, nsection, extra, naxial, a
    call volume_rule(length, section_w, xi, weight, info)
    if (info == 0) call gauss_legendre(2, pt, wt, info)   ! the twist points' axial rule
    call isotropic_elasticity(youngs, poisson, elasticity)
    shear = elasticity(4, 4)
    elasticity(4, 4) = 0.5_dp * youngs                       ! as beam_nonlinear's volume law
    elasticity(6, 6) = 0.5_dp * youngs
    laws = 0.0_dp
    laws(4, 4, 1) = shear_scales(2) * shear                  ! neutral axis
    laws(6, 6, 1) = shear_scales(3) * shear
    laws(4, 4, 2) = shear_scales(1) * shear - 0.5_dp * youngs   ! twist points (0, +-z0)
    laws(6, 6, 3) = shear_scales(1) * shear - 0.5_dp * youngs   ! twist points (+-y0, 0)
    nsection = size(section_w)
    area = sum(section_w)
    point_y = [0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, -1.0_dp] * sqrt(sum(section_w * section_y**2) / area)
    point_z = [0.0_dp, 1.0_dp, -1.0_dp, 0.0_dp, 0.0_dp] * sqrt(sum(section_w * section_z**2) / area)
    point_w = [1.0_dp, 0.5_dp, 0.5_dp, 0.5_dp, 0.5_dp]       ! times the area
    stiffness = 0.0_dp
    do s = 1, nsection + 5
      extra = s - nsection
      if (extra >= 1) then
        law = laws(:, :, min(extra, 1) + merge(1, 0, extra >= 2) + merge(1, 0, extra >= 4))
        if (all(law == 0.0_dp)) cycle
      else
        law = elasticity
      end if
      naxial = merge(2, n_axial, extra >= 2)
      do i = 1, naxial
        if (extra >= 2) then          ! twist points: 2 Gauss points, as beam_nonlinear
          xi_point = 0.5_dp * (pt(i) + 1.0_dp)
          weight_point = 0.5_dp * wt(i) * length * area
        else
          xi_point = xi(i)
          weight_point = sum(weight(i, :))
        end if
        if (extra < 1) then
          call beam_shape(xi(i), section_y(s), section_z(s), length, shape, dshape(:, 1), &
                          dshape(:, 2), dshape(:, 3))
        else
          call beam_shape(xi_point, point_y(extra), point_z(extra), length, shape, &
                          dshape(:, 1), dshape(:, 2), dshape(:, 3))
        end if
        jacobian0 = matmul(reference, dshape)
        call invert3(jacobian0, inverse0, det0)
        if (det0 <= 0.0_dp) then
          info = 2
          return
        end if
        ! strains in the section's material axes R0 (as beam_nonlinear): the gradients
        ! with respect to them, and the displacements' components along them, R0^T u_a
        axes = material_axes(jacobian0)
        material_gradient = matmul(dshape, matmul(inverse0, axes))
        call small_strain_matrix(material_gradient, strain_matrix)
        do a = 1, 8
          strain_matrix(:, 3 * a - 2:3 * a) = matmul(strain_matrix(:, 3 * a - 2:3 * a), &
                                                     transpose(axes))
        end do
        if (extra < 1) then
          stiffness = stiffness + weight(i, s) * det0 * &
                      matmul(transpose(strain_matrix), matmul(law, strain_matrix))
        else
          stiffness = stiffness + point_w(extra) * weight_point * det0 * &
                      matmul(transpose(strain_matrix), matmul(law, strain_matrix))
        end if
      end do
    end do
  end subroutine beam_linear_stiffness

  !> The orthonormal material axes at a point of the reference: the columns of J0 = d r0 /
  !> d(x, y, z) made orthonormal from the first (the axis, then the height, then their
  !> cross product). The identity for an element along x with its height along y.
  pure function material_axes(jac0) result(axes)
    real(dp), intent(in) :: jac0(3, 3)
    real(dp) :: axes(3, 3)
    axes(:, 1) = jac0(:, 1) / norm2(jac0(:, 1))
    axes(:, 2) = jac0(:, 2) - dot_product(axes(:, 1), jac0(:, 2)) * axes(:, 1)
    axes(:, 2) = axes(:, 2) / norm2(axes(:, 2))
    axes(:, 3) = [axes(2, 1) * axes(3, 2) - axes(3, 1) * axes(2, 2), &
                  axes(3, 1) * axes(1, 2) - axes(1, 1) * axes(3, 2), &
                  axes(1, 1) * axes(2, 2) - axes(2, 1) * axes(1, 2)]
  end function material_axes

  !> B(6, 24) with eps = B u for u = sum_a N_a u_a, given dN_a/dX_j = gradient(a, j).
  pure subroutine small_strain_matrix(gradient, strain_matrix)
    real(dp), intent(in) :: gradient(8, 3)
    real(dp), intent(out) :: strain_matrix(6, 24)
    integer :: a, c
    strain_matrix = 0.0_dp
    do a = 1, 8
      c = 3 * (a - 1)
      strain_matrix(1, c + 1) = gradient(a, 1)
      strain_matrix(2, c + 2) = gradient(a, 2)
      strain_matrix(3, c + 3) = gradient(a, 3)
      strain_matrix(4, c + 1) = gradient(a, 2)
      strain_matrix(4, c + 2) = gradient(a, 1)
      strain_matrix(5, c + 2) = gradient(a, 3)
      strain_matrix(5, c + 3) = gradient(a, 2)
      strain_matrix(6, c + 1) = gradient(a, 3)
      strain_matrix(6, c + 3) = gradient(a, 1)
    end do
  end subroutine small_strain_matrix

  !> Isotropic elasticity in Voigt form with engineering shear strains.
  pure subroutine isotropic_elasticity(youngs, poisson, elasticity)
    real(dp), intent(in) :: youngs, poisson
    real(dp), intent(out) :: elasticity(6, 6)
    real(dp) :: lame, shear
    integer :: i
    lame = youngs * poisson / ((1.0_dp + poisson) * (1.0_dp - 2.0_dp * poisson))
    shear = youngs / (2.0_dp * (1.0_dp + poisson))
    elasticity = 0.0_dp
    elasticity(1:3, 1:3) = lame
    do i = 1, 3
      elasticity(i, i) = lame + 2.0_dp * shear
      elasticity(i + 3, i + 3) = shear
    end do
  end subroutine isotropic_elasticity

end module beam_element
