!> The f2py-facing layer, part 1 (with system_api.f90 the one thin binding `_kernel`):
!> element-level routines over plain arrays, used to set models up and by the tests.
!> Every routine returns an error code (info) instead of stopping; Python turns non-zero
!> codes into exceptions. Array sizes are passed explicitly.

!> Element arrays of a beam mesh: compact mass (8 x 8) and small-strain stiffness K0
!> (24 x 24) per element, over a section rule (beam_section_rule). info = 10*element + code.
!> shear_scales: the torsion and shear correction [c, d_y, d_z] (beam_linear_stiffness).
subroutine beam_element_arrays(nel, nsec, lengths, section_y, section_z, section_w, density, &
                               youngs, poisson, shear_scales, reference, mass_compact, &
                               stiffness, info)
  use ancf_kinds, only: dp
  use beam_element, only: beam_mass_compact, beam_linear_stiffness
  implicit none
  integer, intent(in) :: nel, nsec
  real(dp), intent(in) :: lengths(nel), section_y(nsec), section_z(nsec), section_w(nsec)
  real(dp), intent(in) :: density, youngs, poisson, shear_scales(3), reference(3, 8, nel)
  real(dp), intent(out) :: mass_compact(8, 8, nel), stiffness(24, 24, nel)
  integer, intent(out) :: info
  integer :: el, code
  info = 0
  do el = 1, nel
    call beam_mass_compact(lengths(el), section_y, section_z, section_w, density, &
                           mass_compact(:, :, el), code)
    if (code == 0) call beam_linear_stiffness(reference(:, :, el), lengths(el), section_y, &
                                              section_z, section_w, youngs, poisson, &
                                              shear_scales, stiffness(:, :, el), code)
    if (code /= 0) then
      info = 10 * el + code
      return
    end if
  end do
end subroutine beam_element_arrays

!> Generalized gravity forces (3 x 8) per element (seed 000, eqs. 22-25).
subroutine beam_gravity(nel, nsec, lengths, section_y, section_z, section_w, density, gravity, &
                        gravity_force, info)
  use ancf_kinds, only: dp
  use beam_element, only: beam_gravity_compact
  implicit none
  integer, intent(in) :: nel, nsec
  real(dp), intent(in) :: lengths(nel), section_y(nsec), section_z(nsec), section_w(nsec)
  real(dp), intent(in) :: density, gravity(3)
  real(dp), intent(out) :: gravity_force(3, 8, nel)
  integer, intent(out) :: info
  integer :: el
  info = 0
  do el = 1, nel
    call beam_gravity_compact(lengths(el), section_y, section_z, section_w, density, gravity, &
                              gravity_force(:, :, el), info)
    if (info /= 0) return
  end do
end subroutine beam_gravity

!> Section rule (points, area weights; the first npoints of max_section_points entries)
!> and properties of a section kind (beam_section). info: 1 unknown kind, 2 dimensions.
subroutine beam_section_data(kind, dims, npoints, y, z, weight, area, inertia_y, inertia_z, &
                             polar, info)
  use ancf_kinds, only: dp
  use beam_section, only: section_rule, section_properties, max_section_points
  implicit none
  integer, intent(in) :: kind
  real(dp), intent(in) :: dims(3)
  integer, intent(out) :: npoints, info
  real(dp), intent(out) :: y(18), z(18), weight(18), area, inertia_y, inertia_z, polar
  call section_rule(kind, dims, npoints, y, z, weight, info)
  if (info == 0) call section_properties(kind, dims, area, inertia_y, inertia_z, polar, info)
end subroutine beam_section_data

!> Number of Gauss points per element of the large-deformation beam for a section rule of
!> nsec points.
subroutine beam_nonlinear_points(nsec, npts)
  use beam_nonlinear, only: nonlinear_rule_size
  implicit none
  integer, intent(in) :: nsec
  integer, intent(out) :: npts
  npts = nonlinear_rule_size(nsec)
end subroutine beam_nonlinear_points

!> Material shape-function gradients and weights at the Gauss points of every element,
!> computed once from the reference configuration. info = 10*element + code.
subroutine beam_nonlinear_setup(nel, npts, nsec, reference, lengths, section_y, section_z, &
                                section_w, gradients, weights, info)
  use ancf_kinds, only: dp
  use beam_nonlinear, only: nonlinear_setup
  implicit none
  integer, intent(in) :: nel, npts, nsec
  real(dp), intent(in) :: reference(3, 8, nel), lengths(nel)
  real(dp), intent(in) :: section_y(nsec), section_z(nsec), section_w(nsec)
  real(dp), intent(out) :: gradients(8, 3, npts, nel), weights(npts, nel)
  integer, intent(out) :: info
  integer :: el, code
  info = 0
  do el = 1, nel
    call nonlinear_setup(reference(:, :, el), lengths(el), section_y, section_z, section_w, &
                         gradients(:, :, :, el), weights(:, el), code)
    if (code /= 0) then
      info = 10 * el + code
      return
    end if
  end do
end subroutine beam_nonlinear_setup

!> Large-deformation elastic force (global), strain energy and, when want_tangent /= 0,
!> the element tangents (24 x 24 x nel) of a beam mesh; the first nvolume Gauss points of
!> an element are its volume points; shear_scales the torsion and shear correction
!> [c, d_y, d_z] (beam_nonlinear).
subroutine beam_nonlinear_forces(ndof, nel, npts, nvolume, dofs, e, gradients, weights, youngs, &
                                 poisson, shear_scales, want_tangent, force, energy, tangent)
  use ancf_kinds, only: dp
  use beam_nonlinear, only: nonlinear_element
  implicit none
  integer, intent(in) :: ndof, nel, npts, nvolume, dofs(24, nel), want_tangent
  real(dp), intent(in) :: e(ndof), gradients(8, 3, npts, nel), weights(npts, nel), youngs, poisson
  real(dp), intent(in) :: shear_scales(3)
  real(dp), intent(out) :: force(ndof), energy, tangent(24, 24, nel)
  real(dp) :: element_force(24, nel), element_energy(nel)
  integer :: el
  force = 0.0_dp
  tangent = 0.0_dp
  !$omp parallel do schedule(static)
  do el = 1, nel
    call nonlinear_element(reshape(e(dofs(:, el)), [3, 8]), gradients(:, :, :, el), weights(:, el), &
                           nvolume, youngs, poisson, shear_scales, want_tangent /= 0, &
                           element_force(:, el), &
                           element_energy(el), tangent(:, :, el))
  end do
  !$omp end parallel do
  do el = 1, nel
    force(dofs(:, el)) = force(dofs(:, el)) + element_force(:, el)
  end do
  energy = sum(element_energy)
end subroutine beam_nonlinear_forces

!> The initial-stress stiffness (24 x 24 x nel) of a continuum beam mesh at e for the
!> increment de (beam_nonlinear.nonlinear_stress_stiffness per element).
subroutine beam_nonlinear_stress_stiffness(ndof, nel, npts, nvolume, dofs, e, de, gradients, &
                                           weights, youngs, poisson, shear_scales, tangent)
  use ancf_kinds, only: dp
  use beam_nonlinear, only: nonlinear_stress_stiffness
  implicit none
  integer, intent(in) :: ndof, nel, npts, nvolume, dofs(24, nel)
  real(dp), intent(in) :: e(ndof), de(ndof), gradients(8, 3, npts, nel), weights(npts, nel)
  real(dp), intent(in) :: youngs, poisson, shear_scales(3)
  real(dp), intent(out) :: tangent(24, 24, nel)
  integer :: el
  do el = 1, nel
    call nonlinear_stress_stiffness(reshape(e(dofs(:, el)), [3, 8]), &
                                    reshape(de(dofs(:, el)), [3, 8]), gradients(:, :, :, el), &
                                    weights(:, el), nvolume, youngs, poisson, shear_scales, &
                                    tangent(:, :, el))
  end do
end subroutine beam_nonlinear_stress_stiffness

!> The initial-stress stiffness (24 x 24 x nel) of a 'cubic' beam mesh at e for the
!> increment de (beam_cubic.cubic_stress_stiffness per element).
subroutine beam_cubic_stress_stiffness(ndof, nel, nterms, dofs, e, de, forms, stiffness, tangent)
  use ancf_kinds, only: dp
  use beam_cubic, only: cubic_stress_stiffness
  implicit none
  integer, intent(in) :: ndof, nel, nterms, dofs(24, nel)
  real(dp), intent(in) :: e(ndof), de(ndof), forms(8, 8, nterms, nel), stiffness(nterms, nel)
  real(dp), intent(out) :: tangent(24, 24, nel)
  integer :: el
  do el = 1, nel
    call cubic_stress_stiffness(reshape(e(dofs(:, el)), [3, 8]), &
                                reshape(de(dofs(:, el)), [3, 8]), forms(:, :, :, el), &
                                stiffness(:, el), tangent(:, :, el))
  end do
end subroutine beam_cubic_stress_stiffness

!> Number of strain terms per element of the 'cubic' bending beam.
subroutine beam_cubic_size(nterms)
  use beam_cubic, only: cubic_terms
  implicit none
  integer, intent(out) :: nterms
  nterms = cubic_terms
end subroutine beam_cubic_size

!> Strain forms, reference strains and stiffnesses of the 'cubic' bending beam per
!> element, from the reference configuration and the section properties (torsion: the
!> Saint-Venant constant J; shear_y, shear_z: the shear factors), all in section
!> (api_support cs_*: area, inertia_y, inertia_z, torsion, shear_y, shear_z, youngs,
!> poisson). info = 10*element + code.
subroutine beam_cubic_setup(nel, nterms, reference, lengths, section, forms, strain0, &
                            stiffness, info)
  use ancf_kinds, only: dp
  use beam_cubic, only: cubic_setup
  use api_support, only: cs_area, cs_inertia_y, cs_inertia_z, cs_torsion, cs_shear_y, &
                         cs_shear_z, cs_youngs, cs_poisson
  implicit none
  integer, intent(in) :: nel, nterms
  real(dp), intent(in) :: reference(3, 8, nel), lengths(nel), section(8)
  real(dp), intent(out) :: forms(8, 8, nterms, nel), strain0(nterms, nel), stiffness(nterms, nel)
  integer, intent(out) :: info
  integer :: el, code
  info = 0
  do el = 1, nel
    call cubic_setup(reference(:, :, el), lengths(el), section(cs_area), section(cs_inertia_y), &
                     section(cs_inertia_z), section(cs_torsion), section(cs_shear_y), &
                     section(cs_shear_z), section(cs_youngs), section(cs_poisson), &
                     forms(:, :, :, el), strain0(:, el), stiffness(:, el), code)
    if (code /= 0) then
      info = 10 * el + code
      return
    end if
  end do
end subroutine beam_cubic_setup

!> 'Cubic' bending elastic force (global), strain energy and, when want_tangent /= 0,
!> the element tangents (24 x 24 x nel) of a beam mesh.
subroutine beam_cubic_forces(ndof, nel, nterms, dofs, e, forms, strain0, stiffness, &
                                  want_tangent, force, energy, tangent)
  use ancf_kinds, only: dp
  use beam_cubic, only: cubic_element
  implicit none
  integer, intent(in) :: ndof, nel, nterms, dofs(24, nel), want_tangent
  real(dp), intent(in) :: e(ndof), forms(8, 8, nterms, nel), strain0(nterms, nel)
  real(dp), intent(in) :: stiffness(nterms, nel)
  real(dp), intent(out) :: force(ndof), energy, tangent(24, 24, nel)
  real(dp) :: element_force(24, nel), element_energy(nel)
  integer :: el
  force = 0.0_dp
  tangent = 0.0_dp
  !$omp parallel do schedule(static)
  do el = 1, nel
    call cubic_element(reshape(e(dofs(:, el)), [3, 8]), forms(:, :, :, el), strain0(:, el), &
                            stiffness(:, el), want_tangent /= 0, element_force(:, el), &
                            element_energy(el), tangent(:, :, el))
  end do
  !$omp end parallel do
  do el = 1, nel
    force(dofs(:, el)) = force(dofs(:, el)) + element_force(:, el)
  end do
  energy = sum(element_energy)
end subroutine beam_cubic_forces

!> Shape functions and their parameter derivatives at npts material points.
subroutine beam_shape_functions(npts, xi, y, z, lengths, shape, dshape_dx, dshape_dy, dshape_dz)
  use ancf_kinds, only: dp
  use beam_element, only: beam_shape
  implicit none
  integer, intent(in) :: npts
  real(dp), intent(in) :: xi(npts), y(npts), z(npts), lengths(npts)
  real(dp), intent(out) :: shape(8, npts), dshape_dx(8, npts), dshape_dy(8, npts), dshape_dz(8, npts)
  integer :: p
  do p = 1, npts
    call beam_shape(xi(p), y(p), z(p), lengths(p), shape(:, p), dshape_dx(:, p), &
                    dshape_dy(:, p), dshape_dz(:, p))
  end do
end subroutine beam_shape_functions

!> Compact mass of a point mass at a material point of an element.
subroutine beam_point_mass(xi, y, z, length, point_mass, mass_compact)
  use ancf_kinds, only: dp
  use beam_element, only: beam_point_mass_compact
  implicit none
  real(dp), intent(in) :: xi, y, z, length, point_mass
  real(dp), intent(out) :: mass_compact(8, 8)
  call beam_point_mass_compact(xi, y, z, length, point_mass, mass_compact)
end subroutine beam_point_mass

!> FFR elastic force and strain energy of a beam mesh (reference: the rigid configuration
!> in the frame, per element).
subroutine ffr_elastic_force(ndof, nel, dofs, stiffness0, reference, rotation, e, force, energy)
  use ancf_kinds, only: dp
  use ffr_elastic, only: ffr_force
  implicit none
  integer, intent(in) :: ndof, nel, dofs(24, nel)
  real(dp), intent(in) :: stiffness0(24, 24, nel), reference(24, nel), rotation(3, 3), e(ndof)
  real(dp), intent(out) :: force(ndof), energy
  force = 0.0_dp
  call ffr_force(nel, dofs, stiffness0, reference, rotation, e, force, energy)
end subroutine ffr_elastic_force

!> FFR element stiffness matrices rotated into the global frame.
subroutine ffr_element_stiffness(nel, stiffness0, rotation, stiffness)
  use ancf_kinds, only: dp
  use ffr_elastic, only: ffr_stiffness
  implicit none
  integer, intent(in) :: nel
  real(dp), intent(in) :: stiffness0(24, 24, nel), rotation(3, 3)
  real(dp), intent(out) :: stiffness(24, 24, nel)
  call ffr_stiffness(nel, stiffness0, rotation, stiffness)
end subroutine ffr_element_stiffness


! ---------------------------------------------------------------------------------------
! Thin plate element (plate_element): 36 coordinates per element, (3, 12) per element
! ---------------------------------------------------------------------------------------

!> Sizes of the plate element's Gauss rule.
subroutine plate_rule(npoints)
  use plate_element, only: plate_points
  implicit none
  integer, intent(out) :: npoints
  npoints = plate_points
end subroutine plate_rule

!> Shape functions (12) and their x, y, xx, yy, xy derivatives (12, 5) at (xi, eta).
subroutine plate_shape_functions(xi, eta, a, b, shape, derivs)
  use ancf_kinds, only: dp
  use plate_element, only: plate_shape
  implicit none
  real(dp), intent(in) :: xi, eta, a, b
  real(dp), intent(out) :: shape(12), derivs(12, 5)
  call plate_shape(xi, eta, a, b, shape, derivs)
end subroutine plate_shape_functions

!> Compact mass matrices (12, 12, nel) and the generalized force (3, 12, nel) of a
!> constant load per unit area.
subroutine plate_element_arrays(nel, a, b, thickness, density, load, mass, load_force, info)
  use ancf_kinds, only: dp
  use plate_element, only: plate_mass, plate_surface_load
  implicit none
  integer, intent(in) :: nel
  real(dp), intent(in) :: a(nel), b(nel), thickness, density, load(3)
  real(dp), intent(out) :: mass(12, 12, nel), load_force(3, 12, nel)
  integer, intent(out) :: info
  integer :: el, info_load
  info = 0
  do el = 1, nel
    call plate_mass(a(el), b(el), thickness, density, mass(:, :, el), info)
    call plate_surface_load(a(el), b(el), load, load_force(:, :, el), info_load)
    info = max(info, info_load)
    if (info /= 0) return
  end do
end subroutine plate_element_arrays

!> Reference data at the Gauss points of every element (variant 0 plain, 1 completed).
!> info = 2 + 1000 el: degenerate reference in element el (1-based).
subroutine plate_reference(nel, npts, reference, a, b, variant, derivs, frame, curvature0, &
                           weights, info)
  use ancf_kinds, only: dp
  use plate_element, only: plate_setup
  implicit none
  integer, intent(in) :: nel, npts, variant
  real(dp), intent(in) :: reference(3, 12, nel), a(nel), b(nel)
  real(dp), intent(out) :: derivs(12, 5, npts, nel), frame(2, 2, npts, nel)
  real(dp), intent(out) :: curvature0(3, npts, nel), weights(npts, nel)
  integer, intent(out) :: info
  integer :: el
  info = 0
  do el = 1, nel
    call plate_setup(reference(:, :, el), a(el), b(el), variant, derivs(:, :, :, el), &
                     frame(:, :, :, el), curvature0(:, :, el), weights(:, el), info)
    if (info /= 0) then
      info = info + 1000 * el
      return
    end if
  end do
end subroutine plate_reference

!> Elastic force (ndof), strain energy and element tangents (36, 36, nel) of a plate mesh;
!> material (api_support pm_*): Young's modulus, Poisson's ratio, thickness.
!> info = 2 + 1000 el: the normal vanished in element el.
subroutine plate_elastic_forces(ndof, nel, npts, dofs, e, derivs, frame, curvature0, weights, &
                                material, want_tangent, force, energy, tangent, info)
  use ancf_kinds, only: dp
  use plate_element, only: plate_forces
  use api_support, only: pm_youngs, pm_poisson, pm_thickness
  implicit none
  integer, intent(in) :: ndof, nel, npts, dofs(36, nel), want_tangent
  real(dp), intent(in) :: e(ndof), derivs(12, 5, npts, nel), frame(2, 2, npts, nel)
  real(dp), intent(in) :: curvature0(3, npts, nel), weights(npts, nel)
  real(dp), intent(in) :: material(3)
  real(dp), intent(out) :: force(ndof), energy, tangent(36, 36, nel)
  integer, intent(out) :: info
  real(dp) :: element_force(36, nel), element_energy(nel)
  integer :: el, element_info(nel)
  force = 0.0_dp
  !$omp parallel do schedule(static)
  do el = 1, nel
    call plate_forces(reshape(e(dofs(:, el)), [3, 12]), derivs(:, :, :, el), frame(:, :, :, el), &
                      curvature0(:, :, el), weights(:, el), material(pm_youngs), &
                      material(pm_poisson), material(pm_thickness), &
                      want_tangent /= 0, element_force(:, el), element_energy(el), &
                      tangent(:, :, el), element_info(el))
  end do
  !$omp end parallel do
  info = 0
  do el = 1, nel
    if (element_info(el) /= 0) then
      info = element_info(el) + 1000 * el
      return
    end if
    force(dofs(:, el)) = force(dofs(:, el)) + element_force(:, el)
  end do
  energy = sum(element_energy)
end subroutine plate_elastic_forces

!> Mass matrix of an ANCF reference node (rigid body; seed 003 eq. 32).
subroutine reference_node_mass(mass, centre, inertia, mass_matrix, info)
  use ancf_kinds, only: dp
  use rigid_body, only: rigid_body_mass
  implicit none
  real(dp), intent(in) :: mass, centre(3), inertia(3, 3)
  real(dp), intent(out) :: mass_matrix(12, 12)
  integer, intent(out) :: info
  call rigid_body_mass(mass, centre, inertia, mass_matrix, info)
end subroutine reference_node_mass

!> One contact pair (leaf_contact%contact_point): the upper element at its local point and
!> the lower-leaf point; geometry(:, 1) upper, geometry(:, 2) lower (api_support cg_*:
!> element sizes a, b and the local point xi, eta). forces(:, 1) on the upper element,
!> forces(:, 2) on the lower; energies (ce_*): the penalty potential, the damping and
!> friction powers.
subroutine contact_pair(upper, upper_rates, lower, lower_rates, geometry, params, &
                        velocity_factor, forces, jacobian, record, energies, active, info)
  use ancf_kinds, only: dp
  use leaf_contact, only: contact_point
  use api_support, only: cg_a, cg_b, cg_xi, cg_eta, ce_potential, ce_damping, ce_friction
  implicit none
  real(dp), intent(in) :: upper(3, 12), upper_rates(3, 12), lower(3, 12), lower_rates(3, 12)
  real(dp), intent(in) :: geometry(4, 2), params(8), velocity_factor
  real(dp), intent(out) :: forces(36, 2), jacobian(72, 72), record(4), energies(3)
  integer, intent(out) :: active, info
  logical :: is_active
  call contact_point(upper, upper_rates, geometry(cg_a, 1), geometry(cg_b, 1), &
                     geometry(cg_xi, 1), geometry(cg_eta, 1), lower, lower_rates, &
                     geometry(cg_a, 2), geometry(cg_b, 2), geometry(cg_xi, 2), &
                     geometry(cg_eta, 2), params, velocity_factor, .true., forces(:, 1), &
                     forces(:, 2), jacobian, record, energies(ce_potential), &
                     energies(ce_damping:ce_friction), is_active, info)
  active = merge(1, 0, is_active)
end subroutine contact_pair

!> Closest point of the upper leaf's mid-surface (elements grid(n_l, n_w), leaf-level
!> coordinates) to p, from guess; counts = [Newton iterations, fallback sweeps].
subroutine contact_projection(nfull, nel, ngrid_l, ngrid_w, e, dofs, sizes, grid, p, guess, &
                              counts, info)
  use ancf_kinds, only: dp
  use leaf_contact, only: project_point
  implicit none
  integer, intent(in) :: nfull, nel, ngrid_l, ngrid_w, dofs(36, nel), grid(ngrid_l, ngrid_w)
  real(dp), intent(in) :: e(nfull), sizes(2, nel), p(3)
  real(dp), intent(inout) :: guess(2)
  !f2py intent(in,out) :: guess
  integer, intent(out) :: counts(2), info
  counts = 0
  call project_point(e, dofs, grid, sizes, p, guess, counts(1), counts(2), info)
end subroutine contact_projection

!> Generalized force of a dead moment on a section director, with its first and
!> second derivatives.
subroutine moment_generalized_force(director, axis, magnitude, force, jacobian, hessian, info)
  use ancf_kinds, only: dp
  use section_moment, only: moment_force
  implicit none
  real(dp), intent(in) :: director(3), axis(3), magnitude
  real(dp), intent(out) :: force(3), jacobian(3, 3), hessian(3, 3, 3)
  integer, intent(out) :: info
  call moment_force(director, axis, magnitude, force, jacobian, hessian, info)
end subroutine moment_generalized_force

!> A drive's phi, phi', phi'' at nt times (params: its parameters, any length).
subroutine drive_values(kind, nparams, params, nt, t, phi, dphi, ddphi, info)
  use ancf_kinds, only: dp
  use drives, only: drive_eval
  implicit none
  integer, intent(in) :: kind, nparams, nt
  real(dp), intent(in) :: params(nparams), t(nt)
  real(dp), intent(out) :: phi(nt), dphi(nt), ddphi(nt)
  integer, intent(out) :: info
  integer :: i
  info = 0
  do i = 1, nt
    call drive_eval(kind, params, t(i), phi(i), dphi(i), ddphi(i), info)
    if (info /= 0) return
  end do
end subroutine drive_values

!> Constraint values, operand gradients (6, ncon), constant operand Hessians, Phi_t,
!> Phi_tt and the acceleration right-hand side gamma at (e, e_dot, t), state(:, sv_*) = (e,
!> e_dot), of the packed constraint layout (ints, reals: api_support unpack_constraints).
subroutine constraint_evaluate(nint, ints, nreal, reals, ncon, ndof, state, t, values, &
                               gradients, hessians, phi_t, phi_tt, gamma, info)
  use ancf_kinds, only: dp
  use constraints, only: constraint_eval
  use api_support, only: constraint_layout, unpack_constraints, sv_coordinates, sv_rates
  implicit none
  integer, intent(in) :: nint, ints(nint), nreal, ncon, ndof
  real(dp), intent(in) :: reals(nreal), state(ndof, 2), t
  real(dp), intent(out) :: values(ncon), gradients(6, ncon), hessians(6, 6, ncon)
  real(dp), intent(out) :: phi_t(ncon), phi_tt(ncon), gamma(ncon)
  integer, intent(out) :: info
  type(constraint_layout) :: lay
  values = 0.0_dp
  gradients = 0.0_dp
  hessians = 0.0_dp
  phi_t = 0.0_dp
  phi_tt = 0.0_dp
  gamma = 0.0_dp
  call unpack_constraints(ints, reals, ncon, lay, info)
  if (info /= 0) return
  call constraint_eval(ncon, lay%kinds, lay%drives, lay%params, lay%operand_const, &
                       lay%term_ptr, lay%term_dof, lay%term_coef, lay%drive_kinds, &
                       lay%drive_ptr, lay%drive_data, state(:, sv_coordinates), &
                       state(:, sv_rates), t, values, gradients, hessians, phi_t, phi_tt, &
                       gamma, info)
end subroutine constraint_evaluate

!> Pattern size of an n x n matrix coupled by element dof lists.
subroutine sparse_pattern_count(n, ndofe, nel, dofs, nnz, info)
  use sparse_pattern, only: pattern_count
  implicit none
  integer, intent(in) :: n, ndofe, nel, dofs(ndofe, nel)
  integer, intent(out) :: nnz, info
  integer :: row_length(n)
  call pattern_count(n, ndofe, nel, dofs, row_length, nnz, info)
end subroutine sparse_pattern_count

!> CSR pattern (1-based) and scatter map for element matrices.
subroutine sparse_pattern_build(n, ndofe, nel, dofs, nnz, row_ptr, col_index, scatter_map, info)
  use sparse_pattern, only: pattern_fill
  implicit none
  integer, intent(in) :: n, ndofe, nel, dofs(ndofe, nel), nnz
  integer, intent(out) :: row_ptr(n + 1), col_index(nnz), scatter_map(ndofe, ndofe, nel), info
  call pattern_fill(n, ndofe, nel, dofs, nnz, row_ptr, col_index, scatter_map, info)
end subroutine sparse_pattern_build

!> CSR values from element matrices through a scatter map.
subroutine sparse_assemble(nnz, ndofe, nel, scatter_map, element_values, values)
  use ancf_kinds, only: dp
  use sparse_pattern, only: pattern_assemble
  implicit none
  integer, intent(in) :: nnz, ndofe, nel, scatter_map(ndofe, ndofe, nel)
  real(dp), intent(in) :: element_values(ndofe, ndofe, nel)
  real(dp), intent(out) :: values(nnz)
  call pattern_assemble(nnz, ndofe, nel, scatter_map, element_values, values)
end subroutine sparse_assemble

subroutine direct_create(symmetry, handle, info, info_detail)
  use sparse_direct, only: solver_create
  implicit none
  integer, intent(in) :: symmetry
  integer, intent(out) :: handle, info, info_detail
  call solver_create(symmetry, handle, info, info_detail)
end subroutine direct_create

!> A solver of the kind the cost rule picks for the pattern (sparse_direct's
!> solver_create_for), analysed; positive: 1 when every matrix to factorize has a positive
!> definite symmetric part (an iteration matrix: the envelope LU may replace the banded
!> LU); kind: sparse_direct's solver_kind (0 MUMPS, 2 banded LU, 3 envelope LU); width:
!> the pattern's half-bandwidth in its reverse Cuthill-McKee order.
subroutine direct_create_for(n, nnz, rows, cols, positive, handle, width, kind, info, &
                             info_detail)
  use sparse_direct, only: solver_create_for, solver_kind
  implicit none
  integer, intent(in) :: n, nnz, rows(nnz), cols(nnz), positive
  integer, intent(out) :: handle, width, kind, info, info_detail
  call solver_create_for(n, nnz, rows, cols, handle, width, info, info_detail, positive /= 0)
  kind = solver_kind(handle)
end subroutine direct_create_for

!> An envelope LU solver's factorizations that fell back to the pivoted banded LU and its
!> envelope's entries below the diagonal (0 and 0 for other kinds).
subroutine direct_envelope_counts(handle, fallbacks, entries)
  use sparse_direct, only: solver_fallbacks, solver_envelope
  implicit none
  integer, intent(in) :: handle
  integer, intent(out) :: fallbacks, entries
  fallbacks = solver_fallbacks(handle)
  entries = solver_envelope(handle)
end subroutine direct_envelope_counts

subroutine direct_analyse(handle, n, nnz, rows, cols, info, info_detail)
  use sparse_direct, only: solver_analyse
  implicit none
  integer, intent(in) :: handle, n, nnz, rows(nnz), cols(nnz)
  integer, intent(out) :: info, info_detail
  call solver_analyse(handle, n, nnz, rows, cols, info, info_detail)
end subroutine direct_analyse

subroutine direct_factorize(handle, nnz, values, info, info_detail)
  use ancf_kinds, only: dp
  use sparse_direct, only: solver_factorize
  implicit none
  integer, intent(in) :: handle, nnz
  real(dp), intent(in) :: values(nnz)
  integer, intent(out) :: info, info_detail
  call solver_factorize(handle, nnz, values, info, info_detail)
end subroutine direct_factorize

subroutine direct_solve(handle, n, nrhs, rhs, info, info_detail)
  use ancf_kinds, only: dp
  use sparse_direct, only: solver_solve
  implicit none
  integer, intent(in) :: handle, n, nrhs
  real(dp), intent(inout) :: rhs(n, nrhs)
  !f2py intent(in,out) :: rhs
  integer, intent(out) :: info, info_detail
  call solver_solve(handle, n, nrhs, rhs, info, info_detail)
end subroutine direct_solve

subroutine direct_destroy(handle, info)
  use sparse_direct, only: solver_destroy
  implicit none
  integer, intent(in) :: handle
  integer, intent(out) :: info
  call solver_destroy(handle, info)
end subroutine direct_destroy

!> Generalized forces of one driven or follower point load (vector_loads) on its slots
!> (a, b, p) and their Jacobian(i, slot, j, wrt) with respect to a (wrt 1) and b (wrt 2).
subroutine vector_load_generalized_force(kind, vector, shares, a, b, force, jacobian, info)
  use ancf_kinds, only: dp
  use vector_loads, only: vector_load_force
  implicit none
  integer, intent(in) :: kind
  real(dp), intent(in) :: vector(3), shares(2), a(3), b(3)
  real(dp), intent(out) :: force(3, 3), jacobian(3, 3, 3, 2)
  integer, intent(out) :: info
  call vector_load_force(kind, vector, shares, a, b, force, jacobian, info)
end subroutine vector_load_generalized_force

!> One force element (force_elements) at its ns slot values x and rates xd: the generalized
!> force, its derivatives by x and xd, the energies (api_support fe_*: energy, dissipated
!> and drive powers), the reaction (force, moment, axial). kinds (fk_*): the element's and
!> its table's (0: no table); geometry (fg_*): its length and length rate; nparam, ntable:
!> sizes (ntable 0: no table).
subroutine force_element_generalized(kinds, nparam, params, ntable, table, ns, x, xd, geometry, &
                                     force, stiffness, damping, energies, reaction, info)
  use ancf_kinds, only: dp
  use force_elements, only: force_element_eval
  use api_support, only: fk_element, fk_table, fg_length, fg_length_rate, fe_energy, &
                         fe_dissipation, fe_drive_power
  implicit none
  integer, intent(in) :: kinds(2), nparam, ntable, ns
  real(dp), intent(in) :: params(max(1, nparam)), table(max(1, ntable)), x(3, ns), xd(3, ns)
  real(dp), intent(in) :: geometry(2)
  real(dp), intent(out) :: force(3, ns), stiffness(3, ns, 3, ns), damping(3, ns, 3, ns)
  real(dp), intent(out) :: energies(3), reaction(7)
  integer, intent(out) :: info
  call force_element_eval(kinds(fk_element), params(1:nparam), kinds(fk_table), &
                          table(1:ntable), x, xd, geometry(fg_length), geometry(fg_length_rate), &
                          force, stiffness, damping, energies(fe_energy), &
                          energies(fe_dissipation), energies(fe_drive_power), reaction, info)
end subroutine force_element_generalized

!> Cable elements (cable_element): the scalar element masses Mbar (4, 4, nel) (the element
!> mass is kron(Mbar, I3)) for the mass per length, and the generalized forces (12, nel) of
!> a uniform load per length (3).
subroutine cable_element_arrays(nel, lengths, mass_per_length, load, mass, load_force)
  use ancf_kinds, only: dp
  use cable_element, only: cable_mass, cable_gravity
  implicit none
  integer, intent(in) :: nel
  real(dp), intent(in) :: lengths(nel), mass_per_length, load(3)
  real(dp), intent(out) :: mass(4, 4, nel), load_force(12, nel)
  integer :: el
  do el = 1, nel
    call cable_mass(lengths(el), mass_per_length, mass(:, :, el))
    call cable_gravity(lengths(el), load, load_force(:, el))
  end do
end subroutine cable_element_arrays

!> Cable shape rows at xi (element of the given length): position, d/dx, d2/dx2 (4 each).
subroutine cable_shape_functions(xi, length, shape, slope, second)
  use ancf_kinds, only: dp
  use cable_element, only: cable_shape
  implicit none
  real(dp), intent(in) :: xi, length
  real(dp), intent(out) :: shape(4), slope(4), second(4)
  call cable_shape(xi, length, shape, slope, second)
end subroutine cable_shape_functions

!> Cable elastic force (global), strain energy and, when want_tangent /= 0, the element
!> tangents (12 x 12 x nel) of a cable mesh; tension_only /= 0: a rope's axial law.
!> properties (api_support cb_*): EA, EI, the axial Kelvin-Voigt damping_time (0: none) and
!> the rate_factor; with damping the force includes the damping force at the rates v, the
!> tangents are dQ/de + rate_factor dQ/de' and dissipation is the damping's power (else 0).
!> info = element number whose r' vanished.
subroutine cable_forces(ndof, nel, dofs, e, v, lengths, properties, want_tangent, tension_only, &
                        force, energy, tangent, dissipation, info)
  use ancf_kinds, only: dp
  use cable_element, only: cable_element_force
  use api_support, only: cb_axial_stiffness, cb_bending_stiffness, cb_damping_time, &
                         cb_rate_factor
  implicit none
  integer, intent(in) :: ndof, nel, dofs(12, nel), want_tangent, tension_only
  real(dp), intent(in) :: e(ndof), v(ndof), lengths(nel), properties(4)
  real(dp), intent(out) :: force(ndof), energy, tangent(12, 12, nel), dissipation
  integer, intent(out) :: info
  real(dp) :: element_force(12), element_energy, element_power
  integer :: el, code
  force = 0.0_dp
  energy = 0.0_dp
  dissipation = 0.0_dp
  tangent = 0.0_dp
  info = 0
  do el = 1, nel
    if (properties(cb_damping_time) > 0.0_dp) then
      call cable_element_force(reshape(e(dofs(:, el)), [3, 4]), lengths(el), &
                               properties(cb_axial_stiffness), properties(cb_bending_stiffness), &
                               want_tangent /= 0, element_force, element_energy, &
                               tangent(:, :, el), code, tension_only /= 0, &
                               reshape(v(dofs(:, el)), [3, 4]), properties(cb_damping_time), &
                               properties(cb_rate_factor), element_power)
    else
      call cable_element_force(reshape(e(dofs(:, el)), [3, 4]), lengths(el), &
                               properties(cb_axial_stiffness), properties(cb_bending_stiffness), &
                               want_tangent /= 0, element_force, element_energy, &
                               tangent(:, :, el), code, tension_only /= 0)
      element_power = 0.0_dp
    end if
    if (code /= 0) then
      info = el
      return
    end if
    force(dofs(:, el)) = force(dofs(:, el)) + element_force
    energy = energy + element_energy
    dissipation = dissipation + element_power
  end do
end subroutine cable_forces

!> The cable elements' initial-stress stiffness (cable_element's cable_stress_stiffness)
!> (12 x 12 x nel) at e for the increment de; tension_only /= 0: a rope. info = element
!> whose Gauss rule is unavailable.
subroutine cable_stress_stiffness_set(ndof, nel, dofs, e, de, lengths, axial_stiffness, &
                                      tension_only, tangent, info)
  use ancf_kinds, only: dp
  use cable_element, only: cable_stress_stiffness
  implicit none
  integer, intent(in) :: ndof, nel, dofs(12, nel), tension_only
  real(dp), intent(in) :: e(ndof), de(ndof), lengths(nel), axial_stiffness
  real(dp), intent(out) :: tangent(12, 12, nel)
  integer, intent(out) :: info
  integer :: el, code
  info = 0
  tangent = 0.0_dp
  do el = 1, nel
    call cable_stress_stiffness(reshape(e(dofs(:, el)), [3, 4]), reshape(de(dofs(:, el)), &
                                [3, 4]), lengths(el), axial_stiffness, tension_only /= 0, &
                                tangent(:, :, el), code)
    if (code /= 0) then
      info = el
      return
    end if
  end do
end subroutine cable_stress_stiffness_set

!> One force element's initial-stress stiffness (force_elements'
!> force_element_initial_stress): its measures' forces at the slot values x and rates xd
!> times their Hessians at the slot values ``at``; arguments as force_element_generalized's.
subroutine force_element_initial_stress_generalized(kinds, nparam, params, ntable, table, ns, &
                                                    x, xd, geometry, at, stiffness, info)
  use ancf_kinds, only: dp
  use force_elements, only: force_element_initial_stress
  use api_support, only: fk_element, fk_table, fg_length, fg_length_rate
  implicit none
  integer, intent(in) :: kinds(2), nparam, ntable, ns
  real(dp), intent(in) :: params(max(1, nparam)), table(max(1, ntable)), x(3, ns), xd(3, ns)
  real(dp), intent(in) :: geometry(2), at(3, ns)
  real(dp), intent(out) :: stiffness(3, ns, 3, ns)
  integer, intent(out) :: info
  call force_element_initial_stress(kinds(fk_element), params(1:nparam), kinds(fk_table), &
                                    table(1:ntable), x, xd, geometry(fg_length), &
                                    geometry(fg_length_rate), at, stiffness, info)
end subroutine force_element_initial_stress_generalized

!> Newmark stepping of a modally reduced FFR model (reduced_ffr_stepper; python
!> ancfdrv.solvers.ffr_reduced): eta and its rate (r, steps + 1) from rest at 0, per step
!> counts(:, rn_corrections) Newton corrections and counts(:, rn_factorized)
!> factorizations; the load from its four patterns (columns of load_patterns) and the
!> frame's motion at each time (api_support fm_* columns: psi', sin psi, 1 - cos psi,
!> psi''). settings (rs_*): dt, beta, gamma, tol; controls (rc_*): pdelta (0: no P-delta
!> remainder, pdelta_linear and pdelta_quadratic unused), max_newton. status (rt_*): info
!> (1 Newton failed, 2 singular iteration matrix) and the failed step.
subroutine reduced_ffr_newmark(r, steps, settings, controls, omega2, gyroscopic, centrifugal, &
                               pdelta_linear, pdelta_quadratic, load_patterns, frame, eta, &
                               velocity, counts, status)
  use ancf_kinds, only: dp
  use reduced_ffr_stepper, only: reduced_newmark
  use api_support, only: rs_dt, rs_beta, rs_gamma, rs_tol, rc_pdelta, rc_max_newton, &
                         fm_rate, fm_accel, fm_sin_psi, fm_one_minus_cos, rn_corrections, &
                         rn_factorized, rt_info, rt_failed_step
  implicit none
  integer, intent(in) :: r, steps, controls(2)
  real(dp), intent(in) :: settings(4), omega2(r), gyroscopic(r, r), centrifugal(r, r)
  real(dp), intent(in) :: pdelta_linear(r, r), pdelta_quadratic(r, r, r)
  real(dp), intent(in) :: load_patterns(r, 4), frame(steps + 1, 4)
  real(dp), intent(out) :: eta(r, steps + 1), velocity(r, steps + 1)
  integer, intent(out) :: counts(steps + 1, 2), status(2)
  call reduced_newmark(r, steps, settings(rs_dt), settings(rs_beta), settings(rs_gamma), &
                       omega2, gyroscopic, centrifugal, controls(rc_pdelta) /= 0, &
                       pdelta_linear, pdelta_quadratic, load_patterns, frame(:, fm_rate), &
                       frame(:, fm_accel), frame(:, fm_sin_psi), frame(:, fm_one_minus_cos), &
                       settings(rs_tol), controls(rc_max_newton), eta, velocity, &
                       counts(:, rn_corrections), counts(:, rn_factorized), status(rt_info), &
                       status(rt_failed_step))
end subroutine reduced_ffr_newmark

!> The energies and the frame's power of a modally reduced FFR run's output rows
!> (reduced_ffr_rows; python ancfdrv.solvers.ffr_reduced.RowMaps): energies(:, re_*) the
!> kinetic, strain (with the P-delta cubic form when nused > 0), the frame's power and the
!> loads' potential at nrow rows of the frame's motion (api_support fm_* columns: psi',
!> sin psi, 1 - cos psi). used: 1-based indices into c = (1, sin psi, 1 - cos psi, eta).
subroutine reduced_ffr_energy_rows(r, nrow, nused, nmono, frame, eta, velocity, kinetic_form, &
                                   strain_form, power_form, used, table, load_constant, &
                                   load_linear, energies)
  use ancf_kinds, only: dp
  use reduced_ffr_rows, only: reduced_energy_rows
  use api_support, only: fm_rate, fm_sin_psi, fm_one_minus_cos, re_kinetic, re_strain, &
                         re_power, re_load
  implicit none
  integer, intent(in) :: r, nrow, nused, nmono
  real(dp), intent(in) :: frame(nrow, 3), eta(r, nrow), velocity(r, nrow)
  real(dp), intent(in) :: kinetic_form(1 + 2 * r, 1 + 2 * r)
  real(dp), intent(in) :: strain_form(3 + r, 3 + r), power_form(3 + r, 3 + r)
  integer, intent(in) :: used(nused)
  real(dp), intent(in) :: table(nmono, 2), load_constant, load_linear(1 + r, 3)
  real(dp), intent(out) :: energies(nrow, 4)
  call reduced_energy_rows(r, nrow, nused, nmono, frame(:, fm_rate), frame(:, fm_sin_psi), &
                           frame(:, fm_one_minus_cos), eta, velocity, kinetic_form, &
                           strain_form, power_form, used, table, load_constant, load_linear, &
                           energies(:, re_kinetic), energies(:, re_strain), &
                           energies(:, re_power), energies(:, re_load))
end subroutine reduced_ffr_energy_rows

!> The constraints' operand gradients at each of nrow states (q_rows(:, r), times(r)):
!> gradients(:, :, r) as constraint_evaluate returns them (constraints' constraint_gradients:
!> the operand gradients alone, no drive evaluated: they depend on none), of the packed
!> constraint layout (ints, reals: api_support unpack_constraints). One call for a chunk of
!> output rows (the reactions of every step, python/ancfdrv/system/answers.py); ``times``
!> is kept in the interface for the callers (the gradients do not depend on t).
subroutine constraint_gradient_rows(nint, ints, nreal, reals, ncon, ndof, nrow, q_rows, times, &
                                    gradients, info)
  use ancf_kinds, only: dp
  use constraints, only: constraint_gradients
  use api_support, only: constraint_layout, unpack_constraints
  implicit none
  integer, intent(in) :: nint, ints(nint), nreal, ncon, ndof, nrow
  real(dp), intent(in) :: reals(nreal), q_rows(ndof, nrow), times(nrow)
  real(dp), intent(out) :: gradients(6, ncon, nrow)
  integer, intent(out) :: info
  type(constraint_layout) :: lay
  gradients = 0.0_dp
  call unpack_constraints(ints, reals, ncon, lay, info)
  if (info /= 0) return
  call constraint_gradients(ncon, nrow, lay%kinds, lay%drives, lay%params, lay%operand_const, &
                            lay%term_ptr, lay%term_dof, lay%term_coef, size(lay%drive_kinds), &
                            q_rows, gradients, info)
end subroutine constraint_gradient_rows

!> The constraint violation max |Phi| at each of nrow states (q_rows(:, r), times(r)) of the
!> packed constraint layout (ints, reals: api_support unpack_constraints), as the system's
!> output row computes it (the values of constraint_eval, through constraints'
!> constraint_values: the layout checked once, each drive evaluated once a row): one call
!> for the rows of a modally reduced FFR run (python/ancfdrv/solvers/ffr_reduced.py), whose
!> states need only the constrained coordinates filled in.
subroutine constraint_violation_rows(nint, ints, nreal, reals, ncon, ndof, nrow, q_rows, times, &
                                     violation, info)
  use ancf_kinds, only: dp
  use constraints, only: constraint_values
  use api_support, only: constraint_layout, unpack_constraints
  implicit none
  integer, intent(in) :: nint, ints(nint), nreal, ncon, ndof, nrow
  real(dp), intent(in) :: reals(nreal), q_rows(ndof, nrow), times(nrow)
  real(dp), intent(out) :: violation(nrow)
  integer, intent(out) :: info
  real(dp), allocatable :: values(:, :)
  type(constraint_layout) :: lay
  integer :: row
  violation = 0.0_dp
  call unpack_constraints(ints, reals, ncon, lay, info)
  if (info /= 0) return
  allocate(values(ncon, nrow))
  call constraint_values(ncon, nrow, lay%kinds, lay%drives, lay%params, lay%operand_const, &
                         lay%term_ptr, lay%term_dof, lay%term_coef, lay%drive_kinds, &
                         lay%drive_ptr, lay%drive_data, q_rows, times, values, info)
  if (info /= 0 .or. ncon == 0) return
  do row = 1, nrow
    violation(row) = maxval(abs(values(:, row)))
  end do
end subroutine constraint_violation_rows


