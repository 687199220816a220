!> The f2py-facing layer, part 2: a mechanical system behind an integer handle
!> (system_store, mechanical_system), built once piece by piece and then evaluated or
!> stepped without sending its arrays again. Counts of optional items may be 0; their
!> arrays then carry one unused entry (f2py refuses zero sizes). info: 0 ok; 1 not a live
!> handle; 2 sizes inconsistent with the system; other codes as documented per routine.

!> A new, empty system of ndof independent and nfull full coordinates.
subroutine system_create(ndof, nfull, handle, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use system_store, only: store_create
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: ndof, nfull
  integer, intent(out) :: handle, info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  message = ' '
  call store_create(handle, info)
  if (info /= 0) then
    message = "the kernel's system table is full (256 systems alive)"
    return
  end if
  call api_system(handle, sys, info)
  sys%ndof = ndof
  sys%nfull = nfull
  allocate (sys%sets(0), sys%frames(0), sys%contact%pairs(0))
  allocate (sys%drives%kinds(0), sys%drives%ptr(1), sys%drives%data(0))
  sys%drives%ptr = 1
  allocate (sys%loads%constant_force(ndof), sys%loads%fixed_force(ndof), &
            sys%loads%force_drive(0), sys%loads%force_vectors(ndof, 0), &
            sys%loads%force_fixed(0), sys%loads%vload_fixed(0))
  sys%loads%constant_force = 0.0_dp
  sys%loads%fixed_force = 0.0_dp
  allocate (sys%loads%moment_dofs(3, 0), sys%loads%moment_axis(3, 0), &
            sys%loads%moment_magnitude(0), &
            sys%loads%moment_reference(3, 0), sys%loads%moment_fixed(0))
  allocate (sys%constraints%kind(0), sys%constraints%drive(0), sys%constraints%term_ptr(1), &
            sys%constraints%term_dof(0), sys%constraints%params(8, 0), &
            sys%constraints%operand_const(6, 0), sys%constraints%term_coef(0))
  sys%constraints%term_ptr = 1
  allocate (sys%probes%ptr(1), sys%probes%dof(0), sys%probes%frame(0), sys%probes%coef(0), &
            sys%probes%reference(3, 0))
  sys%probes%ptr = 1
  allocate (sys%matrix%block_first(0), sys%matrix%flexibility(ndof, 0), &
            sys%matrix%flexibility_cc(0, 0))
end subroutine system_create

subroutine system_destroy(handle, info, message)
  use system_store, only: store_destroy
  use kernel_errors, only: handle_text
  implicit none
  integer, intent(in) :: handle
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  message = ' '
  call store_destroy(handle, info)
  if (info /= 0) message = handle_text(handle)
end subroutine system_destroy

!> Starts a run of the stepper (stepper.f90) with its settings, set once per run: the
!> method (0 generalized-alpha, 1 energy-momentum: energy_momentum.f90), the alpha method's
!> beta, gamma, alpha_m, alpha_f (Newmark: alpha_m = alpha_f = 0), the Newton
!> tolerance (max |de| <= tol * length_scale) and iteration limit, the Jacobian policy
!> (1 per step, 2 per iteration, 3 reused across steps), the reuse policy's contraction
!> limit and the step-size control (control(sk_*): the output grid's dt, dt_min (0: dt /
!> 1024), adaptive /= 0 for step = 'adaptive', the local error tolerance; step_control.f90).
!> What the stepper learned in earlier runs is forgotten (the contraction estimate; a matrix
!> factorized at another state, except the constant policy's, which depends on the step
!> alone): a run from a new initial state then gives the same result on any handle.
!> info: 1 not a live handle; 2 a setting out of its range.
subroutine system_stepper_setup(handle, method, beta, gamma, alpha_m, alpha_f, tol, &
                                length_scale, max_newton, jacobian, contraction, control, info, &
                                message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, policy_constant
  use system_mass, only: plane_mass_setup
  use stepper, only: stepper_run, stepper_settings, stepper_start, jacobian_step, &
                     jacobian_reuse, control_settings, method_alpha, method_energy_momentum
  use api_support, only: api_system, sk_dt, sk_dt_min, sk_adaptive, sk_tolerance
  implicit none
  integer, intent(in) :: handle, method, max_newton, jacobian
  real(dp), intent(in) :: beta, gamma, alpha_m, alpha_f, tol, length_scale, contraction
  real(dp), intent(in) :: control(4)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(stepper_run), pointer :: run
  call api_system(handle, sys, info, message, run)
  if (info /= 0) return
  if (.not. (beta > 0.0_dp .and. gamma > 0.0_dp .and. alpha_m < 1.0_dp .and. &
             alpha_f < 1.0_dp .and. tol > 0.0_dp .and. length_scale > 0.0_dp .and. &
             contraction > 0.0_dp .and. contraction < 1.0_dp)) then
    info = 2
    message = 'system_stepper_setup: a setting out of its range (beta, gamma, tol, ' // &
              'length_scale > 0; alpha_m, alpha_f < 1; 0 < contraction < 1)'
    return
  end if
  if (max_newton < 1 .or. jacobian < jacobian_step .or. jacobian > jacobian_reuse .or. &
      (method /= method_alpha .and. method /= method_energy_momentum)) then
    info = 2
    message = 'system_stepper_setup: max_newton < 1, a Jacobian policy outside 1..3 or ' // &
              'a method outside 0..1'
    return
  end if
  if (.not. (control(sk_dt) > 0.0_dp .and. control(sk_dt_min) >= 0.0_dp .and. &
             control(sk_tolerance) > 0.0_dp)) then
    info = 2
    message = 'system_stepper_setup: a step-size control setting out of its range ' // &
              '(dt > 0, dt_min >= 0, tolerance > 0)'
    return
  end if
  if (method == method_energy_momentum .and. control(sk_adaptive) /= 0.0_dp) then
    info = 2
    message = 'system_stepper_setup: the energy-momentum method takes fixed steps ' // &
              '(no adaptive step control)'
    return
  end if
  call stepper_start(run, stepper_settings(method=method, beta=beta, gamma=gamma, &
                                           alpha_m=alpha_m, &
                                           alpha_f=alpha_f, tol=tol, &
                                           length_scale=length_scale, &
                                           max_newton=max_newton, jacobian=jacobian, &
                                           contraction=contraction), &
                     control_settings(dt=control(sk_dt), dt_min=control(sk_dt_min), &
                                      tolerance=control(sk_tolerance), &
                                      adaptive=control(sk_adaptive) /= 0.0_dp))
  if (sys%matrix%policy /= policy_constant) sys%matrix%factorized = .false.
  call plane_mass_setup(sys%mass, sys%ndof, sys%carry%plane)
end subroutine system_stepper_setup

!> Element sets: one routine per family builds the family's set (element_sets: an
!> extension of element_set in the family's module) from plain arrays and hands it to the
!> one append path (mechanical_system append_set). Each checks the dofs (1..nfull) and the
!> damping_time (the Kelvin-Voigt retardation time, s; 0: no material damping; negative:
!> info = 2) and returns the set's 1-based index.

!> ANCF-FFR beam elements: K0 and the rigid configuration (24, nel) in the floating frame
!> `frame` (1-based index into the system's frames), the element dofs (full, 1-based) and
!> the scatter map into the full pattern.
subroutine system_add_ffr_set(handle, nel, dofs, scatter, stiffness0, reference, frame, &
                              damping_time, index, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, append_set
  use element_sets, only: element_set
  use ffr_elastic, only: ffr_set
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, nel, dofs(24, nel), scatter(24, 24, nel), frame
  real(dp), intent(in) :: stiffness0(24, 24, nel), reference(24, nel), damping_time
  integer, intent(out) :: index, info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  class(element_set), allocatable :: set
  type(ffr_set) :: built
  index = 0
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (any(dofs < 1) .or. any(dofs > sys%nfull) .or. frame < 1 .or. &
      .not. (damping_time >= 0.0_dp)) then
    info = 2
    message = 'system_add_ffr_set: an element dof outside 1..nfull, a' // &
              ' frame < 1 or a negative damping_time'
    return
  end if
  built%nel = nel
  built%nde = 24
  built%frame = frame
  built%dofs = dofs
  built%scatter = scatter
  built%stiffness0 = stiffness0
  built%reference = reference
  built%damping_time = damping_time
  allocate (set, source=built)
  call append_set(sys, set, index)
end subroutine system_add_ffr_set

!> Turns on the geometric stiffness (P-delta) of the FFR set `index` (ffr_elastic's
!> second_order): per element the axial rigidity EA, the unit axis in the frame, the length
!> and the centre-line slope Gram matrix G_ab = int S_a' S_b' dx (8, 8). info = 2: the
!> index is not an FFR set of this system or a length is not positive.
subroutine system_ffr_second_order(handle, index, nel, axial_rigidity, axis, length, &
                                   slope_gram, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use ffr_elastic, only: ffr_enable_second_order
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, index, nel
  real(dp), intent(in) :: axial_rigidity(nel), axis(3, nel), length(nel), slope_gram(8, 8, nel)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  info = 2
  message = 'system_ffr_second_order: set index is not an FFR set of this size, or a' // &
            ' length is not positive'
  if (index < 1 .or. index > size(sys%sets)) return
  if (.not. all(length > 0.0_dp)) return
  call ffr_enable_second_order(sys%sets(index)%item, axial_rigidity, axis, length, &
                               slope_gram, info)
  if (info == 0) message = ' '
end subroutine system_ffr_second_order

!> Large-deformation (continuum) beam elements: material gradients and weights at npts
!> Gauss points of which the first nvolume are volume points (beam_nonlinear);
!> damping_time as system_add_ffr_set; shear_scales the section's torsion and shear
!> correction [c, d_y, d_z]; material (api_support bm_*): Young's modulus, Poisson's ratio.
subroutine system_add_continuum_set(handle, nel, npts, nvolume, dofs, scatter, gradients, &
                                    weights, material, shear_scales, frame, damping_time, &
                                    index, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, append_set
  use element_sets, only: element_set
  use beam_nonlinear, only: continuum_set
  use api_support, only: api_system, bm_youngs, bm_poisson
  implicit none
  integer, intent(in) :: handle, nel, npts, nvolume, dofs(24, nel), scatter(24, 24, nel), frame
  real(dp), intent(in) :: gradients(8, 3, npts, nel), weights(npts, nel), material(2)
  real(dp), intent(in) :: shear_scales(3), damping_time
  integer, intent(out) :: index, info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  class(element_set), allocatable :: set
  type(continuum_set) :: built
  index = 0
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (any(dofs < 1) .or. any(dofs > sys%nfull) .or. .not. (damping_time >= 0.0_dp)) then
    info = 2
    message = 'system_add_continuum_set: an element dof outside 1..nfull or a negative damping_time'
    return
  end if
  built%nel = nel
  built%nde = 24
  built%frame = frame
  built%dofs = dofs
  built%scatter = scatter
  built%volume_points = nvolume
  built%gradients = gradients
  built%weights = weights
  built%youngs = material(bm_youngs)
  built%poisson = material(bm_poisson)
  built%shear_scales = shear_scales
  built%damping_time = damping_time
  built%force_cost = 1.2d0
  built%tangent_cost = 15.0d0
  allocate (set, source=built)
  call append_set(sys, set, index)
end subroutine system_add_continuum_set

!> Large-deformation beam elements with 'cubic' bending: strain forms (beam_cubic).
subroutine system_add_cubic_set(handle, nel, nterms, dofs, scatter, forms, strain0, &
                                stiffness, frame, damping_time, index, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, append_set
  use element_sets, only: element_set
  use beam_cubic, only: cubic_set, cubic_pattern, cubic_terms, cubic_set_with_forms
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, nel, nterms, dofs(24, nel), scatter(24, 24, nel), frame
  real(dp), intent(in) :: forms(8, 8, nterms, nel), strain0(nterms, nel), stiffness(nterms, nel)
  real(dp), intent(in) :: damping_time
  integer, intent(out) :: index, info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  class(element_set), allocatable :: set
  type(cubic_set) :: built
  index = 0
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (any(dofs < 1) .or. any(dofs > sys%nfull) .or. .not. (damping_time >= 0.0_dp) .or. &
      nterms /= cubic_terms) then
    info = 2
    message = 'system_add_cubic_set: an element dof outside 1..nfull, a' // &
              ' negative damping_time or nterms wrong'
    return
  end if
  built%nel = nel
  built%nde = 24
  built%frame = frame
  built%dofs = dofs
  built%scatter = scatter
  built%strain0 = strain0
  built%term_stiffness = stiffness
  allocate (built%form_pairs(2, 64, nterms), built%form_npairs(nterms))
  call cubic_pattern(forms, built%form_pairs, built%form_npairs)
  built%damping_time = damping_time
  built%force_cost = 1.2d0
  built%tangent_cost = 3.0d0
  call cubic_set_with_forms(built, forms, set)
  call append_set(sys, set, index)
end subroutine system_add_cubic_set

!> Gives the beam set `index` (ffr, continuum or cubic) the data of its section forces
!> (beam_stations): the element lengths (nel), the reference nodal vectors (3, 8, nel)
!> (global; an FFR set's in its frame, as its reference), the section (api_support bs_*) and
!> the bending option (cubic /= 0: 'cubic'). info = 2: index is not a beam set of nel
!> elements, or a length or I_p is not positive.
subroutine system_set_sections(handle, index, nel, lengths, reference, section, cubic, info, &
                               message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use beam_stations, only: station_section
  use api_support, only: api_system, give_sections, bs_axial, bs_torsion, bs_shear_y, bs_shear_z, &
                         bs_moment_height, bs_moment_width, bs_youngs, bs_inertia_y, &
                         bs_inertia_z, bs_polar
  implicit none
  integer, intent(in) :: handle, index, nel, cubic
  real(dp), intent(in) :: lengths(nel), reference(3, 8, nel), section(10)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(station_section) :: built
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  info = 2
  message = 'system_set_sections: index is not a beam set of nel elements, or a length' // &
            ' or the polar moment is not positive'
  if (index < 1 .or. index > size(sys%sets)) return
  if (sys%sets(index)%item%nel /= nel .or. .not. all(lengths > 0.0_dp) .or. &
      .not. (section(bs_polar) > 0.0_dp)) return
  built%cubic = cubic /= 0
  built%axial = section(bs_axial)
  built%torsion = section(bs_torsion)
  built%shear_y = section(bs_shear_y)
  built%shear_z = section(bs_shear_z)
  built%moment_height = section(bs_moment_height)
  built%moment_width = section(bs_moment_width)
  built%youngs = section(bs_youngs)
  built%inertia_y = section(bs_inertia_y)
  built%inertia_z = section(bs_inertia_z)
  built%polar = section(bs_polar)
  built%length = lengths
  built%reference = reference
  call give_sections(sys%sets(index)%item, built, info)
  if (info == 0) message = ' '
end subroutine system_set_sections

!> Section forces of the beam set `index` at the stations xi (ns, in [0, 1] along every
!> element) of the states e_rows (ndof, nrows) (the independent coordinates, expanded as
!> to_full) at the times (nrows) (where the set's frame is): forces (ns nel, nrows, 6)
!> [N, T, Q_height, Q_width, M_height, M_width], station i of element el in row
!> i + ns (el - 1) (element_sets section_forces), and each one's largest magnitude over the
!> rows, largest (nst, 6) (not a number where a row's is: the stress envelope's bound per
!> station, answers.peak_rows). `forces` is the caller's (numpy.empty: neither f2py nor this
!> routine zero-fills it, since every family writes all its entries; 700 kB per chunk of the
!> FFR boom's rows, twice, beyond the cache); undefined where info /= 0. info = 2: sizes
!> inconsistent or a station outside [0, 1]; 3: the set reports no section forces; 5: a
!> frame's drive failed.
subroutine system_section_forces(handle, index, nrows, ndof, ns, nst, times, e_rows, xi, &
                                 forces, largest, info, message)
  use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_value, ieee_quiet_nan
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use system_reduction, only: to_full
  use api_support, only: api_system, frame_at_rows
  implicit none
  integer, intent(in) :: handle, index, nrows, ndof, ns, nst
  real(dp), intent(in) :: times(nrows), e_rows(ndof, nrows), xi(ns)
  real(dp), intent(inout) :: forces(nst, nrows, 6)
  real(dp), intent(out) :: largest(nst, 6)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  real(dp), allocatable :: rotations(:, :, :), q_rows(:, :), total(:, :)
  integer :: row, frame, k
  largest = 0.0_dp
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  info = 2
  message = 'system_section_forces: set index, rows (ndof per row, one per time) or' // &
            ' stations (ns nel, each in [0, 1]) inconsistent'
  if (index < 1 .or. index > size(sys%sets)) return
  if (ndof /= sys%ndof .or. ns < 1 .or. nst /= ns * sys%sets(index)%item%nel) return
  if (any(xi < 0.0_dp) .or. any(xi > 1.0_dp)) return
  frame = sys%sets(index)%item%frame
  allocate (rotations(3, 3, nrows))
  call frame_at_rows(sys, frame, times, rotations, info)
  if (info /= 0) then
    message = "system_section_forces: a frame's drive failed"
    return
  end if
  if (sys%reduction%active) then
    allocate (q_rows(sys%nfull, nrows))
    do row = 1, nrows
      call to_full(sys%reduction, e_rows(:, row), .true., q_rows(:, row))
    end do
    call sys%sets(index)%item%section_forces(rotations, q_rows, xi, forces, info)
  else   ! (the rows are the full coordinates: to_full's copy, not made)
    call sys%sets(index)%item%section_forces(rotations, e_rows, xi, forces, info)
  end if
  if (info /= 0) then
    info = 3
    message = 'system_section_forces: the set reports no section forces'
    return
  end if
  allocate (total(nst, 6))
  total = 0.0_dp
  do k = 1, 6
    do row = 1, nrows
      largest(:, k) = max(largest(:, k), abs(forces(:, row, k)))
      total(:, k) = total(:, k) + forces(:, row, k)   ! not a number when one is (or +-inf)
    end do
  end do
  where (ieee_is_nan(total)) largest = ieee_value(1.0_dp, ieee_quiet_nan)   ! (max may skip it)
  message = ' '
end subroutine system_section_forces

!> The small-strain measure of the FFR set `index` (ffr_elastic ffr_departures: the largest
!> change of a section vector in its frame) at the states e_rows (ndof, nrows) (independent
!> coordinates, expanded as to_full) at the times (nrows), in departure (nrows): the check of
!> solvers/assumptions.py for a run's rows in one call. info = 2: sizes inconsistent or the
!> set is not an FFR set; 5: a frame's drive failed.
subroutine system_ffr_departures(handle, index, nrows, ndof, times, e_rows, departure, info, &
                                 message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use system_reduction, only: to_full
  use ffr_elastic, only: ffr_departures
  use api_support, only: api_system, frame_at_rows
  implicit none
  integer, intent(in) :: handle, index, nrows, ndof
  real(dp), intent(in) :: times(nrows), e_rows(ndof, nrows)
  real(dp), intent(out) :: departure(nrows)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  real(dp), allocatable :: rotations(:, :, :), q_rows(:, :)
  integer :: row, frame
  departure = 0.0_dp
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  info = 2
  message = 'system_ffr_departures: set index (an FFR set) or rows (ndof per row, one per' // &
            ' time) inconsistent'
  if (index < 1 .or. index > size(sys%sets)) return
  if (ndof /= sys%ndof) return
  frame = sys%sets(index)%item%frame
  allocate (rotations(3, 3, nrows))
  call frame_at_rows(sys, frame, times, rotations, info)
  if (info /= 0) then
    info = 5
    message = "system_ffr_departures: a frame's drive failed"
    return
  end if
  if (sys%reduction%active) then
    allocate (q_rows(sys%nfull, nrows))
    do row = 1, nrows
      call to_full(sys%reduction, e_rows(:, row), .true., q_rows(:, row))
    end do
    call ffr_departures(sys%sets(index)%item, rotations, q_rows, departure, info)
  else   ! (the rows are the full coordinates: to_full's copy, not made)
    call ffr_departures(sys%sets(index)%item, rotations, e_rows, departure, info)
  end if
  if (info /= 0) then
    info = 2
    return
  end if
  message = ' '
end subroutine system_ffr_departures

!> Thin plate elements (plate_element): reference data at npts Gauss points; material
!> (api_support pm_*): Young's modulus, Poisson's ratio, thickness.
subroutine system_add_plate_set(handle, nel, npts, dofs, scatter, derivs, plate_frame, curvature0, &
                                weights, material, damping_time, index, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, append_set
  use element_sets, only: element_set
  use plate_element, only: plate_set
  use api_support, only: api_system, pm_youngs, pm_poisson, pm_thickness
  implicit none
  integer, intent(in) :: handle, nel, npts, dofs(36, nel), scatter(36, 36, nel)
  real(dp), intent(in) :: derivs(12, 5, npts, nel), plate_frame(2, 2, npts, nel)
  real(dp), intent(in) :: curvature0(3, npts, nel), weights(npts, nel), material(3)
  real(dp), intent(in) :: damping_time
  integer, intent(out) :: index, info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  class(element_set), allocatable :: set
  type(plate_set) :: built
  index = 0
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (any(dofs < 1) .or. any(dofs > sys%nfull) .or. .not. (damping_time >= 0.0_dp)) then
    info = 2
    message = 'system_add_plate_set: an element dof outside 1..nfull or a negative damping_time'
    return
  end if
  built%nel = nel
  built%nde = 36
  built%dofs = dofs
  built%scatter = scatter
  built%derivs = derivs
  built%plate_frame = plate_frame
  built%curvature0 = curvature0
  built%weights = weights
  built%youngs = material(pm_youngs)
  built%poisson = material(pm_poisson)
  built%thickness = material(pm_thickness)
  built%damping_time = damping_time
  built%force_cost = 6.0d0
  built%tangent_cost = 80.0d0
  allocate (set, source=built)
  call append_set(sys, set, index)
end subroutine system_add_plate_set

!> ANCF cable elements (cable_element): element lengths and the section's EA and EI;
!> tension_only /= 0: a rope (no compression); damping_time: the axial Kelvin-Voigt time.
subroutine system_add_cable_set(handle, nel, dofs, scatter, lengths, axial_stiffness, &
                                bending_stiffness, damping_time, tension_only, index, info, &
                                message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, append_set
  use element_sets, only: element_set
  use cable_element, only: cable_set, cable_rule, cable_element_rows
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, nel, dofs(12, nel), scatter(12, 12, nel), tension_only
  real(dp), intent(in) :: lengths(nel), axial_stiffness, bending_stiffness, damping_time
  integer, intent(out) :: index, info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  class(element_set), allocatable :: set
  type(cable_set) :: built
  index = 0
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (any(dofs < 1) .or. any(dofs > sys%nfull) .or. damping_time < 0.0_dp .or. &
      any(lengths <= 0.0_dp) .or. bending_stiffness < 0.0_dp) then
    info = 2
    message = 'system_add_cable_set: an element dof outside 1..nfull, a' // &
              ' non-positive element length, a negative damping_time or bending stiffness'
    return
  end if
  built%nel = nel
  built%nde = 12
  built%dofs = dofs
  built%scatter = scatter
  built%lengths = lengths
  built%axial_stiffness = axial_stiffness
  built%bending_stiffness = bending_stiffness
  built%tension_only = tension_only /= 0
  built%damping_time = damping_time
  built%force_cost = 0.5d0
  built%tangent_cost = 2.0d0
  call cable_rule(built%rule, info)
  if (info /= 0) then
    info = 2
    message = 'system_add_cable_set: the Gauss rule of the elements is not available'
    return
  end if
  call cable_element_rows(built)
  allocate (set, source=built)
  call append_set(sys, set, index)
end subroutine system_add_cable_set

!> Floating frames A_f(t) = Rot(axis_f, phi_d(t)) base_f about pivot_f (drive 0: fixed).
subroutine system_set_frames(handle, nframe, drives, axes, bases, pivots, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, nframe, drives(max(1, nframe))
  real(dp), intent(in) :: axes(3, max(1, nframe)), bases(3, 3, max(1, nframe))
  real(dp), intent(in) :: pivots(3, max(1, nframe))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  integer :: f
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  deallocate (sys%frames)
  allocate (sys%frames(nframe))
  do f = 1, nframe
    if (drives(f) /= 0 .and. norm2(axes(:, f)) == 0.0_dp) then
      info = 2
      message = 'system_set_frames: a driven frame with a zero axis'
      return
    end if
    sys%frames(f)%drive = drives(f)
    sys%frames(f)%axis = axes(:, f)
    sys%frames(f)%base = bases(:, :, f)
    sys%frames(f)%pivot = pivots(:, f)
  end do
end subroutine system_set_frames

!> Drives (drives module): kinds and the packed parameters of drive d at
!> data(ptr(d):ptr(d+1)-1).
subroutine system_set_drives(handle, ndrive, ndata, kinds, ptr, data, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, ndrive, ndata, kinds(max(1, ndrive)), ptr(ndrive + 1)
  real(dp), intent(in) :: data(max(1, ndata))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (ptr(1) /= 1 .or. ptr(ndrive + 1) /= ndata + 1) then
    info = 2
    message = 'system_set_drives: drive pointers inconsistent with ndata'
    return
  end if
  sys%drives%kinds = kinds(1:ndrive)
  sys%drives%ptr = ptr
  sys%drives%data = data(1:ndata)
end subroutine system_set_drives

!> The mass matrix on the independent coordinates (CSR, 1-based; zero entries may be left
!> out), on the solver's pattern (mass_pattern, aligned with the pattern analysed by the
!> solver) and as the model assembled it (saddle_*, CSR, 1-based, zero entries kept: the mass
!> block of the consistent acceleration, consistent_start). system_set_solver sets the
!> pattern and the solver.
subroutine system_set_mass(handle, ndof, nnz_mass, mass_row_ptr, mass_col, mass_values, &
                           nnz_pattern, mass_pattern, nnz_saddle, saddle_ptr, saddle_col, &
                           saddle_values, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, ndof, nnz_mass, mass_row_ptr(ndof + 1), mass_col(nnz_mass)
  real(dp), intent(in) :: mass_values(nnz_mass)
  integer, intent(in) :: nnz_pattern
  real(dp), intent(in) :: mass_pattern(nnz_pattern)
  integer, intent(in) :: nnz_saddle, saddle_ptr(ndof + 1), saddle_col(nnz_saddle)
  real(dp), intent(in) :: saddle_values(nnz_saddle)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (ndof /= sys%ndof) then
    info = 2
    message = 'system_set_mass: sizes inconsistent with the system (ndof)'
    return
  end if
  sys%mass%row_ptr = mass_row_ptr
  sys%mass%col = mass_col
  sys%mass%values = mass_values
  if (allocated(sys%mass%band)) deallocate (sys%mass%band)
  if (allocated(sys%mass%pair_ptr)) deallocate (sys%mass%pair_ptr, sys%mass%pair_col, &
                                                sys%mass%pair_row, sys%mass%pair_values)
  if (any(saddle_col < 1) .or. any(saddle_col > ndof) .or. saddle_ptr(1) /= 1 .or. &
      saddle_ptr(ndof + 1) /= nnz_saddle + 1) then
    info = 2
    message = 'system_set_mass: the saddle mass is no CSR of ndof rows (1-based)'
    return
  end if
  sys%matrix%mass_pattern = mass_pattern
  sys%mass%saddle_ptr = saddle_ptr
  sys%mass%saddle_col = saddle_col
  sys%mass%saddle_values = saddle_values
  sys%matrix%factorized = .false.
end subroutine system_set_mass

!> The full pattern of the tangents (CSR, 1-based), the solver (api_support sl_*: its
!> handle, its policy: 0 constant, 1 refactorized), the frame of every reduced 3-vector
!> (policy constant; 0: global) and the first dofs of the 3-vector blocks the constraints
!> touch.
subroutine system_set_solver(handle, nfull, nnz_full, full_row_ptr, full_col, solver, nvec, &
                             vector_frame, nblock, block_first, info, message)
  use mechanical_system, only: system_model
  use api_support, only: api_system, sl_handle, sl_policy
  implicit none
  integer, intent(in) :: handle, nfull, nnz_full, full_row_ptr(nfull + 1), full_col(nnz_full)
  integer, intent(in) :: solver(2), nvec, nblock
  integer, intent(in) :: vector_frame(max(1, nvec)), block_first(max(1, nblock))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (nfull /= sys%nfull) then
    info = 2
    message = 'system_set_solver: sizes inconsistent with the system (nfull)'
    return
  end if
  sys%reduction%full_ptr = full_row_ptr
  sys%reduction%full_col = full_col
  sys%matrix%solver_handle = solver(sl_handle)
  sys%matrix%policy = solver(sl_policy)
  if (allocated(sys%matrix%vector_frame)) deallocate (sys%matrix%vector_frame)
  sys%matrix%single_frame = -1
  if (nvec > 0) then
    sys%matrix%vector_frame = vector_frame(1:nvec)
    if (all(vector_frame(1:nvec) == vector_frame(1)) .and. vector_frame(1) > 0) &
      sys%matrix%single_frame = vector_frame(1)
  end if
  sys%matrix%block_first = block_first(1:nblock)
  deallocate (sys%matrix%flexibility, sys%matrix%flexibility_cc)
  allocate (sys%matrix%flexibility(sys%ndof, 3 * nblock), &
            sys%matrix%flexibility_cc(3 * nblock, 3 * nblock))
  sys%matrix%factorized = .false.
end subroutine system_set_solver

!> The 3-vectors jacobian_reuse carries the iteration matrix with (carried_rotation): the
!> first full dof of each (1-based), its weight in the rotation fit, whether it is a
!> position (1) or a gradient or director (0) and its group (1 .. : a body, fitted its own
!> rotation; a reduced coordinate several vectors hold turns with the first listed); nvec
!> = 0: the matrix is not carried. The model layer decides where the carry applies (every
!> full coordinate a 3-vector, each row of the reduction at most one entry). info: 1 not a
!> live handle; 2 a dof outside 1..nfull - 2, a negative weight or a group below 1, or a
!> row of the reduction that mixes coordinates.
subroutine system_set_carry(handle, nvec, first, weight, position, group, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use system_carry, only: carry_setup
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, nvec, first(max(1, nvec)), position(max(1, nvec))
  integer, intent(in) :: group(max(1, nvec))
  real(dp), intent(in) :: weight(max(1, nvec))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (nvec > 0) then
    if (any(first(1:nvec) < 1 .or. first(1:nvec) > sys%nfull - 2) .or. &
        any(weight(1:nvec) < 0.0_dp) .or. any(group(1:nvec) < 1) .or. &
        mod(sys%nfull, 3) /= 0) then
      info = 2
      message = 'system_set_carry: a carried vector outside the full coordinates, a ' // &
                'negative weight, a group below 1, or full coordinates that are not 3-vectors'
      return
    end if
  end if
  call carry_setup(sys%carry, sys%reduction, sys%ndof, sys%nfull, first(1:max(0, nvec)), &
                   weight(1:max(0, nvec)), position(1:max(0, nvec)) /= 0, &
                   group(1:max(0, nvec)), info)
  if (info /= 0) message = 'system_set_carry: a row of the reduction mixes coordinates'
end subroutine system_set_carry

!> The mass as kron(Mbar, I3): Mbar's CSR over the nvec = ndof / 3 vectors (1-based),
!> replacing the CSR of system_set_mass in products (a ninth of the entries).
subroutine system_set_kron_mass(handle, nvec, nnz, row_ptr, col, values, info, message)
  use ancf_kinds, only: dp
  use system_mass, only: kron_band_setup
  use mechanical_system, only: system_model
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, nvec, nnz, row_ptr(nvec + 1), col(nnz)
  real(dp), intent(in) :: values(nnz)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (3 * nvec /= sys%ndof .or. any(col < 1) .or. any(col > nvec)) then
    info = 2
    message = 'system_set_kron_mass: sizes inconsistent with the system (3 nvec /= ndof)'
    return
  end if
  sys%mass%row_ptr = row_ptr
  sys%mass%col = col
  sys%mass%values = values
  sys%mass%kron = .true.
  call kron_band_setup(sys%mass)
  if (allocated(sys%mass%pair_ptr)) deallocate (sys%mass%pair_ptr, sys%mass%pair_col, &
                                                sys%mass%pair_row, sys%mass%pair_values)
end subroutine system_set_kron_mass

!> q = B e + q0 (B CSR over nfull rows, 1-based) and the plan of B^T S B: values(target)
!> += coef * full_values(source).
subroutine system_set_reduction(handle, nfull, nnz_b, b_ptr, b_col, b_values, offset, nplan, &
                                plan_source, plan_target, plan_coef, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use system_reduction, only: reduction_setup
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, nfull, nnz_b, b_ptr(nfull + 1), b_col(max(1, nnz_b)), nplan
  real(dp), intent(in) :: b_values(max(1, nnz_b)), offset(nfull)
  integer, intent(in) :: plan_source(max(1, nplan)), plan_target(max(1, nplan))
  real(dp), intent(in) :: plan_coef(max(1, nplan))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (nfull /= sys%nfull) then
    info = 2
    message = 'system_set_reduction: sizes inconsistent with the system (nfull)'
    return
  end if
  call reduction_setup(sys%reduction, b_ptr, b_col(1:nnz_b), b_values(1:nnz_b), offset, &
                       plan_source(1:nplan), plan_target(1:nplan), plan_coef(1:nplan))
end subroutine system_set_reduction

!> Loads: the constant force (independent coordinates), driven forces phi_d(t) f_d, dead
!> moments on director coordinates of the full vector (axis, magnitude, the director at
!> t = 0 for the potential); none fixed (system_set_fixed_loads).
subroutine system_set_loads(handle, ndof, constant_force, nforce, force_drive, force_vectors, &
                            nmoment, moment_dofs, moment_axis, moment_magnitude, moment_reference, &
                            info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, ndof, nforce, nmoment
  real(dp), intent(in) :: constant_force(ndof), force_vectors(ndof, max(1, nforce))
  integer, intent(in) :: force_drive(max(1, nforce)), moment_dofs(3, max(1, nmoment))
  real(dp), intent(in) :: moment_axis(3, max(1, nmoment)), moment_magnitude(max(1, nmoment))
  real(dp), intent(in) :: moment_reference(3, max(1, nmoment))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (ndof /= sys%ndof) then
    info = 2
    message = 'system_set_loads: sizes inconsistent with the system (ndof)' // &
              ' or a drive index out of range'
    return
  end if
  if (nmoment > 0) then
    if (any(moment_dofs(:, 1:nmoment) < 1) .or. any(moment_dofs(:, 1:nmoment) > sys%nfull)) then
      info = 2
      message = 'system_set_loads: sizes inconsistent with the system (ndof)' // &
                ' or a drive index out of range'
      return
    end if
  end if
  sys%loads%constant_force = constant_force
  sys%loads%force_drive = force_drive(1:nforce)
  sys%loads%force_vectors = force_vectors(:, 1:nforce)
  sys%loads%moment_dofs = moment_dofs(:, 1:nmoment)
  sys%loads%moment_axis = moment_axis(:, 1:nmoment)
  sys%loads%moment_magnitude = moment_magnitude(1:nmoment)
  sys%loads%moment_reference = moment_reference(:, 1:nmoment)
  sys%loads%fixed_force = 0.0_dp
  sys%loads%force_fixed = spread(.false., 1, nforce)
  sys%loads%moment_fixed = spread(.false., 1, nmoment)
end subroutine system_set_loads

!> The fixed loads, kept at their value whatever the load factor (buckling's, beside the
!> reference loads the factor scales), after system_set_loads and system_set_vector_loads:
!> the fixed share of the constant force and, per driven force, dead moment and driven or
!> follower point load, 1 when it is fixed (else 0), in their order there.
subroutine system_set_fixed_loads(handle, ndof, fixed_force, nforce, force_fixed, nmoment, &
                                  moment_fixed, nload, vload_fixed, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, ndof, nforce, nmoment, nload
  real(dp), intent(in) :: fixed_force(ndof)
  integer, intent(in) :: force_fixed(max(1, nforce)), moment_fixed(max(1, nmoment)), &
                         vload_fixed(max(1, nload))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (ndof /= sys%ndof .or. nforce /= size(sys%loads%force_drive) .or. &
      nmoment /= size(sys%loads%moment_magnitude) .or. nload /= sys%loads%nvload) then
    info = 2
    message = 'system_set_fixed_loads: sizes inconsistent with the loads set'
    return
  end if
  sys%loads%fixed_force = fixed_force
  sys%loads%force_fixed = force_fixed(1:nforce) /= 0
  sys%loads%moment_fixed = moment_fixed(1:nmoment) /= 0
  sys%loads%vload_fixed = vload_fixed(1:nload) /= 0
end subroutine system_set_fixed_loads

!> Driven and follower point loads (vector_loads): kinds, drives (1-based, 0: none), vectors
!> (3, n), torsion shares (2, n), and per load and slot (a, b, p) the terms ptr(3 n + 1)
!> over full coordinates dof (1-based, the first of a 3-vector) with coefficients coef.
subroutine system_set_vector_loads(handle, nload, nterm, kinds, drives, vectors, shares, ptr, &
                                   dofs, coefs, info)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, nload, nterm
  integer, intent(in) :: kinds(max(1, nload)), drives(max(1, nload)), ptr(3 * nload + 1)
  integer, intent(in) :: dofs(max(1, nterm))
  real(dp), intent(in) :: vectors(3, max(1, nload)), shares(2, max(1, nload))
  real(dp), intent(in) :: coefs(max(1, nterm))
  integer, intent(out) :: info
  type(system_model), pointer :: sys
  call api_system(handle, sys, info)
  if (info /= 0) return
  if (ptr(3 * nload + 1) /= nterm + 1) then
    info = 2
    return
  end if
  if (nterm > 0) then
    if (any(dofs(1:nterm) < 1) .or. any(dofs(1:nterm) + 2 > sys%nfull)) then
      info = 2
      return
    end if
  end if
  if (nload > 0) then
    if (any(kinds(1:nload) < 1) .or. any(kinds(1:nload) > 3) .or. &
        any(drives(1:nload) < 0) .or. any(drives(1:nload) > size(sys%drives%kinds))) then
      info = 2
      return
    end if
  end if
  sys%loads%nvload = nload
  sys%loads%vload_kind = kinds(1:nload)
  sys%loads%vload_drive = drives(1:nload)
  sys%loads%vload_vector = vectors(:, 1:nload)
  sys%loads%vload_shares = shares(:, 1:nload)
  sys%loads%vload_ptr = ptr
  sys%loads%vload_dof = dofs(1:nterm)
  sys%loads%vload_coef = coefs(1:nterm)
  sys%loads%vload_fixed = spread(.false., 1, nload)
end subroutine system_set_vector_loads

!> The slots of the force elements (set before system_set_force_elements): nslot slots with
!> constants slot_const(3, nslot) and terms term_ptr(slot) .. term_ptr(slot + 1) - 1
!> (term_dof: first full coordinate of a 3-vector, term_coef). info: 1 not a live handle;
!> 2 the pointers disagree with nterm or a term outside the full coordinates.
subroutine system_set_force_slots(handle, nslot, nterm, slot_const, term_ptr, term_dof, &
                                  term_coef, info)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, nslot, nterm
  integer, intent(in) :: term_ptr(nslot + 1), term_dof(max(1, nterm))
  real(dp), intent(in) :: slot_const(3, max(1, nslot)), term_coef(max(1, nterm))
  integer, intent(out) :: info
  type(system_model), pointer :: sys
  call api_system(handle, sys, info)
  if (info /= 0) return
  info = 2
  if (term_ptr(nslot + 1) /= nterm + 1) return
  if (nterm > 0) then
    if (any(term_dof(1:nterm) < 1) .or. any(term_dof(1:nterm) + 2 > sys%nfull)) return
  end if
  info = 0
  sys%force_elements%slot_const = slot_const(:, 1:nslot)
  sys%force_elements%term_ptr = term_ptr
  sys%force_elements%term_dof = term_dof(1:nterm)
  sys%force_elements%term_coef = term_coef(1:nterm)
end subroutine system_set_force_slots

!> Force elements (force_elements) on the slots of system_set_force_slots: per element l
!> elements(:, l) (api_support fl_*: kind, drive (0: none), table kind (0: none), first
!> slot), its parameters params(p(l) .. p(l + 1) - 1), p = pointers(:, fp_param), its table
!> likewise (fp_table) and the tangent's positions in the full pattern's values (0: absent;
!> fp_position; in force_element_forces' loop order; npos 0: searched instead). info: 1 not
!> a live handle; 2 an inconsistent layout (no slots set, a kind, drive or slot out of range,
!> too few parameters).
subroutine system_set_force_elements(handle, nfel, nparam, ntable, npos, elements, pointers, &
                                     params, table, positions, info)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use force_elements, only: force_element_slots, force_element_parameters
  use api_support, only: api_system, fl_kind, fl_drive, fl_table_kind, &
                         fl_slot_first, fp_param, fp_table, fp_position
  implicit none
  integer, intent(in) :: handle, nfel, nparam, ntable, npos
  integer, intent(in) :: elements(4, max(1, nfel)), pointers(nfel + 1, 3)
  real(dp), intent(in) :: params(max(1, nparam)), table(max(1, ntable))
  integer, intent(in) :: positions(max(1, npos))
  integer, intent(out) :: info
  type(system_model), pointer :: sys
  integer :: l, kind, first
  call api_system(handle, sys, info)
  if (info /= 0) return
  info = 2
  if (.not. allocated(sys%force_elements%slot_const)) return
  if (pointers(nfel + 1, fp_param) /= nparam + 1 .or. pointers(nfel + 1, fp_table) /= ntable + 1 &
      .or. pointers(nfel + 1, fp_position) /= npos + 1) return
  if (npos > 0) then
    if (any(positions(1:npos) < 0)) return
  end if
  do l = 1, nfel
    kind = elements(fl_kind, l)
    first = elements(fl_slot_first, l)
    if (force_element_slots(kind) == 0) return
    if (pointers(l + 1, fp_param) - pointers(l, fp_param) < force_element_parameters(kind)) return
    if (first < 1 .or. &
        first + force_element_slots(kind) - 1 > size(sys%force_elements%slot_const, 2)) return
    if (elements(fl_drive, l) < 0 .or. elements(fl_drive, l) > size(sys%drives%kinds)) return
  end do
  info = 0
  sys%force_elements%nfel = nfel
  sys%force_elements%kind = elements(fl_kind, 1:nfel)
  sys%force_elements%drive = elements(fl_drive, 1:nfel)
  sys%force_elements%table_kind = elements(fl_table_kind, 1:nfel)
  sys%force_elements%param_ptr = pointers(:, fp_param)
  sys%force_elements%params = params(1:nparam)
  sys%force_elements%table_ptr = pointers(:, fp_table)
  sys%force_elements%table = table(1:ntable)
  sys%force_elements%slot_first = elements(fl_slot_first, 1:nfel)
  sys%force_elements%pos_ptr = pointers(:, fp_position)
  sys%force_elements%pos = positions(1:npos)
end subroutine system_set_force_elements

!> The reactions (7, nfel) of the force elements at (t, e, e'): force and moment body1
!> exerts on body2 (global), axial force (tension positive). info: 5 (a drive failed) or
!> 10 (an element's points coincide), with its text in message.
subroutine system_force_element_reactions(handle, ndof, nfel, t, e, v, reactions, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, force_element_reactions
  use api_support, only: api_system
  use kernel_errors, only: failure_text
  implicit none
  integer, intent(in) :: handle, ndof, nfel
  real(dp), intent(in) :: t, e(ndof), v(ndof)
  real(dp), intent(out) :: reactions(7, max(1, nfel))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  message = ' '
  reactions = 0.0_dp
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (ndof /= sys%ndof .or. nfel /= sys%force_elements%nfel) then
    info = 2
    message = 'system_force_element_reactions: sizes inconsistent with the system'
    return
  end if
  if (nfel == 0) return
  call force_element_reactions(sys, t, e, v, reactions(:, 1:nfel), info)
  if (info /= 0) message = failure_text(info)
end subroutine system_force_element_reactions

!> Constraints with multipliers, in the constraints module's layout over the independent
!> coordinates.
subroutine system_set_constraints(handle, ncon, nterm, kinds, drives, params, operand_const, &
                                  term_ptr, term_dof, term_coef, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, ncon, nterm
  integer, intent(in) :: kinds(max(1, ncon)), drives(max(1, ncon)), term_ptr(6 * ncon + 1)
  integer, intent(in) :: term_dof(max(1, nterm))
  real(dp), intent(in) :: params(8, max(1, ncon)), operand_const(6, max(1, ncon))
  real(dp), intent(in) :: term_coef(max(1, nterm))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  integer :: c, s
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (term_ptr(6 * ncon + 1) /= nterm + 1) then
    info = 2
    message = 'system_set_constraints: term pointers or dofs inconsistent with the system'
    return
  end if
  if (nterm > 0) then
    if (any(term_dof(1:nterm) < 1) .or. any(term_dof(1:nterm) > sys%ndof)) then
      info = 2
      message = 'system_set_constraints: term pointers or dofs inconsistent with the system'
      return
    end if
  end if
  sys%constraints%ncon = ncon
  sys%constraints%kind = kinds(1:ncon)
  sys%constraints%drive = drives(1:ncon)
  sys%constraints%params = params(:, 1:ncon)
  sys%constraints%operand_const = operand_const(:, 1:ncon)
  sys%constraints%term_ptr = term_ptr
  sys%constraints%term_dof = term_dof(1:nterm)
  sys%constraints%term_coef = term_coef(1:nterm)
  if (allocated(sys%constraints%operands)) deallocate (sys%constraints%operands)
  allocate (sys%constraints%operands(ncon))
  do c = 1, ncon
    sys%constraints%operands(c) = 0
    do s = 1, 6
      if (term_ptr(6 * (c - 1) + s + 1) > term_ptr(6 * (c - 1) + s)) sys%constraints%operands(c) = s
    end do
  end do
end subroutine system_set_constraints

!> A contact pair (leaf_contact): the pair's element columns (dofs into the full vector,
!> sizes), the grid of the searched surface and the points (element column, local xi, eta),
!> with the contact parameters.
subroutine system_add_contact_pair(handle, nel, dofs, sizes, ngrid_l, ngrid_w, grid, npoint, &
                                   point_element, point_local, params, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_pair
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, nel, dofs(36, nel), ngrid_l, ngrid_w, grid(ngrid_l, ngrid_w)
  integer, intent(in) :: npoint, point_element(npoint)
  real(dp), intent(in) :: sizes(2, nel), point_local(2, npoint), params(8)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(contact_pair), allocatable :: grown(:)
  integer :: n
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (any(dofs < 1) .or. any(dofs > sys%nfull) .or. any(grid < 1) .or. any(grid > nel) .or. &
      any(point_element < 1) .or. any(point_element > nel)) then
    info = 2
    message = 'system_add_contact_pair: dofs outside 1..nfull or inconsistent contact sizes'
    return
  end if
  n = size(sys%contact%pairs)
  allocate (grown(n + 1))
  grown(1:n) = sys%contact%pairs
  grown(n + 1)%nel = nel
  grown(n + 1)%npoint = npoint
  grown(n + 1)%first_point = sys%contact%npoint
  grown(n + 1)%dofs = dofs
  grown(n + 1)%sizes = sizes
  grown(n + 1)%grid = grid
  grown(n + 1)%point_element = point_element
  grown(n + 1)%point_local = point_local
  grown(n + 1)%params = params
  call move_alloc(grown, sys%contact%pairs)
  sys%contact%npoint = sys%contact%npoint + npoint
end subroutine system_add_contact_pair

!> Probes: positions sum_k coef_k q(dof_k:dof_k+2) over the terms ptr(p):ptr(p+1)-1, the
!> frame their deflections are resolved in (0: global) and the rigid position in it.
subroutine system_set_probes(handle, nprobe, nterm, ptr, dofs, coefs, frames, reference, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, nprobe, nterm, ptr(nprobe + 1), dofs(max(1, nterm))
  integer, intent(in) :: frames(max(1, nprobe))
  real(dp), intent(in) :: coefs(max(1, nterm)), reference(3, max(1, nprobe))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (nterm > 0) then
    if (any(dofs(1:nterm) < 1) .or. any(dofs(1:nterm) + 2 > sys%nfull)) then
      info = 2
      message = 'system_set_probes: probe pointers, dofs or frames inconsistent with the system'
      return
    end if
  end if
  if (nprobe > 0) then
    if (any(frames(1:nprobe) < 0) .or. any(frames(1:nprobe) > size(sys%frames))) then
      info = 2
      message = 'system_set_probes: probe pointers, dofs or frames inconsistent with the system'
      return
    end if
  end if
  sys%probes%nprobe = nprobe
  sys%probes%ptr = ptr
  sys%probes%dof = dofs(1:nterm)
  sys%probes%coef = coefs(1:nterm)
  sys%probes%frame = frames(1:nprobe)
  sys%probes%reference = reference(:, 1:nprobe)
end subroutine system_set_probes

!> The configuration-dependent forces at (e, e', t): internal = B^T (Q_el - Q_c -
!> load_factor Q_M), external = load_factor Q(t), strain energy, contact potential and
!> records, and with want_tangent /= 0 the tangent (sets, plus velocity_factor times the
!> contact Jacobian) on the solver's (reduced) pattern in global coordinates. Damped sets
!> add their damping force at e' (with the frames' angular velocities at t) and their
!> tangent is dQ/de + velocity_factor dQ/de'. state(:, sv_coordinates) = e,
!> state(:, sv_rates) = e'; factors (ef_*): t, load_factor, velocity_factor; forces(:, ff_*):
!> internal, external; energies (ee_*): strain, contact potential. Codes as the stepper's
!> (5 drive, 6 moment, 7 plate normal, 8 contact search).
subroutine system_evaluate(handle, ndof, nnz, npoint, state, factors, want_tangent, guesses, &
                           counts, forces, energies, records, tangent, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state, frame_rotations, internal_forces, &
                               external_forces
  use kernel_errors, only: failure_text
  use api_support, only: api_system, sv_coordinates, sv_rates, ef_time, &
                         ef_load_factor, ef_velocity_factor, ff_internal, &
                         ff_external, ee_strain, ee_contact_potential
  implicit none
  integer, intent(in) :: handle, ndof, nnz, npoint, want_tangent
  real(dp), intent(in) :: state(ndof, 2), factors(3)
  real(dp), intent(inout) :: guesses(2, max(1, npoint))
  integer, intent(inout) :: counts(6)
  !f2py intent(in,out) :: guesses, counts
  real(dp), intent(out) :: forces(ndof, 2), energies(2)
  real(dp), intent(out) :: records(6, max(1, npoint)), tangent(nnz)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(contact_state) :: contact
  real(dp), allocatable :: rotations(:, :, :), rates(:)
  real(dp) :: powers(2), t, load_factor, velocity_factor
  forces = 0.0_dp
  energies = 0.0_dp
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (ndof /= sys%ndof .or. npoint /= sys%contact%npoint .or. (want_tangent /= 0 .and. &
      nnz /= size(sys%matrix%mass_pattern))) then
    info = 2
    message = 'system_evaluate: sizes inconsistent with the system (ndof,' // &
              ' npoint, or nnz of the tangent)'
    return
  end if
  t = factors(ef_time)
  load_factor = factors(ef_load_factor)
  velocity_factor = factors(ef_velocity_factor)
  allocate (rotations(3, 3, 0:size(sys%frames)), rates(0:size(sys%frames)))
  call frame_rotations(sys, t, rotations, rates, info)
  if (info /= 0) then
    message = failure_text(info)
    return
  end if
  contact%guesses = guesses
  contact%counts = counts
  records = 0.0_dp
  tangent = 0.0_dp
  if (want_tangent /= 0) then  ! the tangent in global coordinates
    call internal_forces(sys, rotations, state(:, sv_coordinates), state(:, sv_rates), &
                         load_factor, velocity_factor, contact, forces(:, ff_internal), &
                         energies(ee_strain), energies(ee_contact_potential), powers, records, &
                         info, rotations, tangent, rates, force_time=t)
  else
    call internal_forces(sys, rotations, state(:, sv_coordinates), state(:, sv_rates), &
                         load_factor, velocity_factor, contact, forces(:, ff_internal), &
                         energies(ee_strain), energies(ee_contact_potential), powers, records, &
                         info, rates=rates, force_time=t)
  end if
  if (info /= 0) then
    message = failure_text(info)
    return
  end if
  call external_forces(sys, t, load_factor, forces(:, ff_external), info, &
                       state(:, sv_coordinates))
  guesses = contact%guesses
  counts = contact%counts
end subroutine system_evaluate

!> The configuration-dependent forces Q_el - Q_c - lf Q_M at (t, e, e') in the full
!> coordinates q (before the reduction B^T): the joint reactions of eliminated linear joints
!> are recovered from them (python/ancfdrv/system/answers.py). The contact guesses and
!> counters are used and returned unchanged in the caller's copy.
subroutine system_full_forces(handle, ndof, nfull, npoint, t, e, v, load_factor, guesses, &
                              full_force, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state, frame_rotations, internal_forces
  use api_support, only: api_system
  use kernel_errors, only: failure_text
  implicit none
  integer, intent(in) :: handle, ndof, nfull, npoint
  real(dp), intent(in) :: t, e(ndof), v(ndof), load_factor
  real(dp), intent(in) :: guesses(2, max(1, npoint))
  real(dp), intent(out) :: full_force(nfull)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(contact_state) :: state
  real(dp), allocatable :: rotations(:, :, :), rates(:), reduced(:)
  real(dp) :: strain, potential, powers(2), records(6, max(1, npoint))
  full_force = 0.0_dp
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (ndof /= sys%ndof .or. nfull /= sys%nfull .or. npoint /= sys%contact%npoint) then
    info = 2
    message = 'system_full_forces: sizes inconsistent with the system (ndof, nfull, npoint)'
    return
  end if
  allocate (rotations(3, 3, 0:size(sys%frames)), rates(0:size(sys%frames)), reduced(ndof))
  call frame_rotations(sys, t, rotations, rates, info)
  if (info /= 0) then
    message = failure_text(info)
    return
  end if
  state%guesses = guesses
  state%counts = 0
  call internal_forces(sys, rotations, e, v, load_factor, 0.0_dp, state, reduced, strain, &
                       potential, powers, records, info, rates=rates, full_out=full_force, &
                       force_time=t)
  if (info /= 0) message = failure_text(info)
end subroutine system_full_forces

!> What of the system the energy-momentum stepper (energy_momentum.f90) does not support,
!> named in obstacle ('' when it supports the system): the run's validation refuses such a
!> scene before anything is computed. info: 1 not a live handle.
subroutine system_energy_momentum_check(handle, obstacle, info, message)
  use mechanical_system, only: system_model
  use energy_momentum, only: energy_momentum_obstacle
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle
  character(len=200), intent(out) :: obstacle
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  obstacle = ''
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  obstacle = energy_momentum_obstacle(sys)
end subroutine system_energy_momentum_check

!> The residual of one energy-momentum step (energy_momentum.f90's midpoint_residual) from
!> (e0, v0) = states(:, 1:2) at t with step h, at e1 = states(:, 3) and the multipliers lam:
!> residual (ndof + ncon), the reduced discrete-gradient force alone (internal) and, with
!> want_jacobian /= 0, the residual's Jacobian in (e1, lambda). For the tests of the
!> discrete gradient and of its Jacobian. info: 2 sizes; the stepper's codes (14: the model
!> is not supported).
subroutine system_midpoint_residual(handle, ndof, ncon, h, t, states, lam, want_jacobian, &
                                    residual, internal, jacobian, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use energy_momentum, only: midpoint_residual, dense_mass
  use time_integrator, only: step_failure_text
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, ndof, ncon, want_jacobian
  real(dp), intent(in) :: h, t, states(ndof, 3), lam(max(1, ncon))
  real(dp), intent(out) :: residual(ndof + ncon), internal(ndof)
  real(dp), intent(out) :: jacobian(ndof + ncon, ndof + ncon)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  real(dp), allocatable :: mass(:, :)
  residual = 0.0_dp
  internal = 0.0_dp
  jacobian = 0.0_dp
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (ndof /= sys%ndof .or. ncon /= sys%constraints%ncon .or. .not. h > 0.0_dp) then
    info = 2
    message = 'system_midpoint_residual: sizes inconsistent with the system (ndof, ncon) ' // &
              'or h <= 0'
    return
  end if
  if (want_jacobian /= 0) then
    allocate (mass(ndof, ndof))
    call dense_mass(sys, mass)
    call midpoint_residual(sys, h, t, states(:, 1), states(:, 2), states(:, 3), lam(1:ncon), &
                           residual, internal, info, mass, jacobian)
  else
    call midpoint_residual(sys, h, t, states(:, 1), states(:, 2), states(:, 3), lam(1:ncon), &
                           residual, internal, info)
  end if
  if (info /= 0) message = step_failure_text(info, 0, 0)
end subroutine system_midpoint_residual

!> One output row of the state (t, e, e', lambda) with the accumulated works, in the layout
!> of a row of system_advance without q (stepper.f90 row_size: time, probes, deflections,
!> lambda, energies, constraint violation, contact records); state(:, sv_coordinates) = e,
!> state(:, sv_rates) = e'. powers: the powers at the state.
subroutine system_output_row(handle, ndof, ncon, npoint, nrow, t, state, lam, work, guesses, &
                             counts, row, powers, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state, power_count, energy_count, &
                               contact_record
  use stepper, only: row_size
  use time_integrator, only: output_row
  use kernel_errors, only: failure_text
  use api_support, only: api_system, sv_coordinates, sv_rates
  implicit none
  integer, intent(in) :: handle, ndof, ncon, npoint, nrow
  real(dp), intent(in) :: t, state(ndof, 2), lam(max(1, ncon)), work(5)
  real(dp), intent(inout) :: guesses(2, max(1, npoint))
  integer, intent(inout) :: counts(6)
  !f2py intent(in,out) :: guesses, counts
  real(dp), intent(out) :: row(nrow), powers(5)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(contact_state) :: contact
  real(dp), allocatable :: probe(:, :), deflection(:, :), records(:, :)
  real(dp) :: energy(energy_count), violation
  integer :: nprobe, k
  row = 0.0_dp
  powers = 0.0_dp
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  nprobe = sys%probes%nprobe
  if (ndof /= sys%ndof .or. ncon /= sys%constraints%ncon .or. npoint /= sys%contact%npoint .or. &
      nrow /= row_size(ndof, ncon, nprobe, npoint, 0, .false.) .or. power_count /= 5) then
    info = 2
    message = 'system_output_row: sizes inconsistent with the system (ndof, ncon, npoint,' // &
              ' the row length)'
    return
  end if
  contact%guesses = guesses
  contact%counts = counts
  allocate (probe(3, nprobe), deflection(3, nprobe), records(contact_record, npoint))
  probe = 0.0_dp
  deflection = 0.0_dp
  records = 0.0_dp
  call output_row(sys, t, state(:, sv_coordinates), state(:, sv_rates), lam(1:ncon), work, &
                  contact, probe, deflection, energy, violation, records, powers, info)
  guesses = contact%guesses
  counts = contact%counts
  if (info /= 0) then
    message = failure_text(info)
    return
  end if
  row(1) = t
  k = 1
  row(k + 1:k + 3 * nprobe) = reshape(probe, [3 * nprobe])
  k = k + 3 * nprobe
  row(k + 1:k + 3 * nprobe) = reshape(deflection, [3 * nprobe])
  k = k + 3 * nprobe
  row(k + 1:k + ncon) = lam(1:ncon)
  k = k + ncon
  row(k + 1:k + energy_count) = energy
  k = k + energy_count
  row(k + 1) = violation
  row(k + 2:k + 1 + contact_record * npoint) = reshape(records, [contact_record * npoint])
end subroutine system_output_row

!> Makes the rows of the run set up by system_stepper_setup answer (row_answers): per force
!> element its reactions, and the residual of the equations of motion at the full
!> coordinates columns(ncol) (1-based), from the full mass's rows there (CSR: mass_ptr(ncol +
!> 1), mass_col(nnz) over the full coordinates, mass_values(nnz)) and the loads there:
!> constant (gravity included) and driven(:, d) for the system's force drive d (ndrive of
!> them). info = 2: sizes inconsistent with the system or an index outside it; 9 no run set up.
subroutine system_answer_setup(handle, ncol, nnz, ndrive, columns, mass_ptr, mass_col, &
                               mass_values, constant, driven, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use stepper, only: stepper_run
  use row_answers, only: answer_data
  use api_support, only: api_system
  implicit none
  integer, intent(in) :: handle, ncol, nnz, ndrive
  integer, intent(in) :: columns(max(1, ncol)), mass_ptr(ncol + 1), mass_col(max(1, nnz))
  real(dp), intent(in) :: mass_values(max(1, nnz)), constant(max(1, ncol))
  real(dp), intent(in) :: driven(max(1, ncol), max(1, ndrive))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(stepper_run), pointer :: run
  call api_system(handle, sys, info, message, run)
  if (info /= 0) return
  if (.not. run%ready) then
    info = 9
    message = 'system_answer_setup: no run set up (call system_stepper_setup first)'
    return
  end if
  info = 2
  message = 'system_answer_setup: sizes inconsistent with the system (the force drives) ' // &
            'or a column outside the full coordinates'
  if (ncol < 0 .or. nnz < 0 .or. ndrive /= size(sys%loads%force_drive)) return
  if (mass_ptr(1) /= 1 .or. mass_ptr(ncol + 1) /= nnz + 1) return
  if (ncol > 0) then
    if (any(columns(1:ncol) < 1) .or. any(columns(1:ncol) > sys%nfull)) return
  end if
  if (nnz > 0) then
    if (any(mass_col(1:nnz) < 1) .or. any(mass_col(1:nnz) > sys%nfull)) return
  end if
  info = 0
  message = ' '
  run%answers = answer_data(on=.true., columns=columns(1:ncol), mass_ptr=mass_ptr, &
                            mass_col=mass_col(1:nnz), mass_values=mass_values(1:nnz), &
                            constant=constant(1:ncol), driven=driven(1:ncol, 1:ndrive))
end subroutine system_answer_setup

!> The answers (row_answers, answer_row) of the state (t, e, e') (columns sv_*) with the
!> accelerations e'' and the contact projections guesses, for the run's rows' layout:
!> what a row of system_advance carries, for a state the stepper did not reach (the run's
!> initial row). info = 2: nanswer is not the run's; else answer_row's code.
subroutine system_answer_row(handle, ndof, npoint, nanswer, t, state, accel, guesses, &
                             answers, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state
  use stepper, only: stepper_run
  use row_answers, only: answer_row, answer_count
  use kernel_errors, only: failure_text
  use api_support, only: api_system, sv_coordinates, sv_rates
  implicit none
  integer, intent(in) :: handle, ndof, npoint, nanswer
  real(dp), intent(in) :: t, state(ndof, 2), accel(ndof), guesses(2, max(1, npoint))
  real(dp), intent(out) :: answers(max(1, nanswer))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(stepper_run), pointer :: run
  type(contact_state) :: contact
  answers = 0.0_dp
  call api_system(handle, sys, info, message, run)
  if (info /= 0) return
  if (ndof /= sys%ndof .or. npoint /= sys%contact%npoint .or. &
      nanswer /= answer_count(sys, run%answers)) then
    info = 2
    message = 'system_answer_row: sizes inconsistent with the system or its run (ndof, ' // &
              'npoint, the answers)'
    return
  end if
  if (nanswer == 0) return
  contact%guesses = guesses(:, 1:npoint)
  call answer_row(sys, run%answers, t, state(:, sv_coordinates), state(:, sv_rates), accel, &
                  contact, answers(1:nanswer), info)
  if (info /= 0) message = failure_text(info)
end subroutine system_answer_row

!> Advances up to nrows output rows of the run set up by system_stepper_setup, with at most
!> budget steps tried (step_control: whole chunks at dt, cut steps, restarts, adaptive
!> steps; an output interval left unfinished is resumed by the next call). state (packed,
!> stepper.f90 state_size: t, e, e', a, e'', lambda, works, the powers at the state, contact
!> guesses) and the contact counters are updated in place: calls may split a run anywhere
!> without changing its result. rows(:, k) (stepper.f90 row_size: time, probes,
!> deflections, lambda, energies, constraint violation, contact records, the answers of a
!> run set up with system_answer_setup (row_answers), and e when nrow has room for it); stats(at_*, k): Newton corrections, factorizations, Jacobian
!> evaluations (failed tries included), steps taken, step cuts; sizes(k): the smallest step
!> to the row. status(as_*): the rows done, info, detail, steps converged at the round-off
!> floor, the steps tried; of a failure: the interval's cuts, the tries in a row, the work of
!> failed tries the run counts; the run's cuts, rejections, restarts and steps taken so far.
!> figures(af_*): the last Newton correction; a failure's time and step; the run's smallest
!> step. info: integrator_chunk's codes (1 .. 8, 10), step_control's (11 .. 13), 9 a
!> refused call (not a live handle, no run set up, sizes inconsistent with the system);
!> message: the failure's text.
subroutine system_advance(handle, nrows, budget, nstate, state, counts, nrow, rows, stats, &
                          sizes, status, figures, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, power_count
  use stepper, only: stepper_run, state_size, row_size
  use row_answers, only: answer_count
  use time_integrator, only: stat_count, step_failure_text
  use energy_momentum, only: em_unsupported
  use step_control, only: stepper_point, controlled_rows, control_failure
  use api_support, only: api_system, as_rows, as_info, as_detail, as_floor_accepts, as_tries, &
                         as_failure_cuts, as_failure_tries, as_failed_corrections, &
                         as_failed_jacobians, as_cuts, as_rejected, as_restarts, as_taken, &
                         af_last_correction, af_failure_t, af_failure_h, af_smallest
  implicit none
  integer, intent(in) :: handle, nrows, budget, nstate, nrow
  real(dp), intent(inout) :: state(nstate)
  integer, intent(inout) :: counts(6)
  !f2py intent(in,out) :: state, counts
  real(dp), intent(out) :: rows(nrow, nrows), sizes(nrows), figures(4)
  integer, intent(out) :: stats(5, nrows), status(14)
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(stepper_run), pointer :: run
  type(stepper_point) :: p
  type(control_failure) :: failure
  integer :: info, ndof, ncon, nprobe, npoint, nanswer, k
  logical :: store_q
  rows = 0.0_dp
  stats = 0
  sizes = 0.0_dp
  status = 0
  figures = 0.0_dp
  call api_system(handle, sys, info, message, run)
  if (info /= 0) then
    status(as_info) = 9
    return
  end if
  if (.not. run%ready) then
    status(as_info) = 9
    message = 'system_advance: no run set up (call system_stepper_setup first)'
    return
  end if
  ndof = sys%ndof
  ncon = sys%constraints%ncon
  nprobe = sys%probes%nprobe
  npoint = sys%contact%npoint
  nanswer = answer_count(sys, run%answers)
  store_q = nrow == row_size(ndof, ncon, nprobe, npoint, nanswer, .true.)
  if (nstate /= state_size(ndof, ncon, npoint) .or. (.not. store_q .and. &
      nrow /= row_size(ndof, ncon, nprobe, npoint, nanswer, .false.)) .or. nrows < 1 .or. &
      budget < 1 .or. power_count /= 5 .or. stat_count /= 3) then
    status(as_info) = 9
    message = 'system_advance: sizes inconsistent with the system (the packed state or ' // &
              'row length) or nrows, budget < 1'
    return
  end if
  ! the packed state (stepper.f90 state_size)
  p%t = state(1)
  k = 1
  p%e = state(k + 1:k + ndof)
  k = k + ndof
  p%v = state(k + 1:k + ndof)
  k = k + ndof
  p%a = state(k + 1:k + ndof)
  k = k + ndof
  p%accel = state(k + 1:k + ndof)
  k = k + ndof
  p%lam = state(k + 1:k + ncon)
  k = k + ncon
  p%work = state(k + 1:k + power_count)
  k = k + power_count
  p%powers = state(k + 1:k + power_count)
  k = k + power_count
  p%contact%guesses = reshape(state(k + 1:k + 2 * npoint), [2, npoint])
  p%contact%counts = counts
  call controlled_rows(sys, run, p, nrows, budget, store_q, rows, stats, sizes, &
                       status(as_rows), status(as_tries), status(as_info), status(as_detail), &
                       figures(af_last_correction), status(as_floor_accepts), failure)
  if (status(as_info) /= 0) then
    message = failure%text
    if (status(as_info) <= 10 .or. status(as_info) == em_unsupported) &
      message = step_failure_text(status(as_info), status(as_detail), run%settings%max_newton)
    figures(af_failure_t) = failure%t
    figures(af_failure_h) = failure%h
    status(as_failure_cuts) = failure%cuts
    status(as_failure_tries) = failure%tries
    status(as_failed_corrections:as_failed_jacobians) = failure%work
  end if
  status(as_cuts) = run%control%cuts
  status(as_rejected) = run%control%rejected
  status(as_restarts) = run%control%restarts
  status(as_taken) = run%control%taken
  figures(af_smallest) = run%control%smallest
  state = [p%t, p%e, p%v, p%a, p%accel, p%lam, p%work, p%powers, &
           reshape(p%contact%guesses, [2 * npoint])]
  counts = p%contact%counts
end subroutine system_advance

!> system_advance into arrays the caller made (rows, stats and sizes, intent(inout)): the
!> same call, whose every output it writes. f2py zero-filled the fresh output arrays of
!> system_advance before the call (one memset of the rows, ~0.34 MB per second of the
!> 5-node pendulum's steps) that the kernel overwrote; arrays from numpy.empty are handed
!> over as they are.
subroutine system_advance_into(handle, nrows, budget, nstate, state, counts, nrow, rows, stats, &
                               sizes, status, figures, message)
  use ancf_kinds, only: dp
  implicit none
  integer, intent(in) :: handle, nrows, budget, nstate, nrow
  real(dp), intent(inout) :: state(nstate)
  integer, intent(inout) :: counts(6)
  !f2py intent(in,out) :: state, counts
  real(dp), intent(inout) :: rows(nrow, nrows), sizes(nrows)
  integer, intent(inout) :: stats(5, nrows)
  real(dp), intent(out) :: figures(4)
  integer, intent(out) :: status(14)
  character(len=200), intent(out) :: message
  call system_advance(handle, nrows, budget, nstate, state, counts, nrow, rows, stats, sizes, &
                      status, figures, message)
end subroutine system_advance_into

!> The consistent acceleration e'' and multipliers lambda of the state (t, e, e') (columns
!> sv_*; consistent_start): the start of a run. The contact guesses and counters are used
!> and updated. info /= 0: the failure, in words in message.
subroutine system_consistent_acceleration(handle, ndof, ncon, npoint, t, state, guesses, &
                                          counts, accel, lam, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state
  use consistent_start, only: consistent_acceleration
  use api_support, only: api_system, sv_coordinates, sv_rates
  implicit none
  integer, intent(in) :: handle, ndof, ncon, npoint
  real(dp), intent(in) :: t, state(ndof, 2)
  real(dp), intent(inout) :: guesses(2, max(1, npoint))
  integer, intent(inout) :: counts(6)
  !f2py intent(in,out) :: guesses, counts
  real(dp), intent(out) :: accel(ndof), lam(max(1, ncon))
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(contact_state) :: contact
  integer :: detail
  accel = 0.0_dp
  lam = 0.0_dp
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (ndof /= sys%ndof .or. ncon /= sys%constraints%ncon .or. npoint /= sys%contact%npoint) then
    info = 2
    message = 'system_consistent_acceleration: sizes inconsistent with the system (ndof, ' // &
              'ncon, npoint)'
    return
  end if
  contact%guesses = guesses(:, 1:npoint)
  contact%counts = counts
  call consistent_acceleration(sys, t, state(:, sv_coordinates), state(:, sv_rates), contact, &
                               accel, lam(1:ncon), info, detail, message)
  guesses(:, 1:npoint) = contact%guesses
  counts = contact%counts
end subroutine system_consistent_acceleration

!> One load step of the static Newton in the kernel (static_solver): equilibrium of the
!> system at load factor and time from the packed state [e (ndof), lambda (ncon), contact
!> guesses (2, npoint)] (updated in place; vectors(:, sx_reference) the reference
!> configuration), the tangent's reduced pattern (pattern(:, tp_rows), pattern(:, tp_cols),
!> 1-based, the solvers' pattern). settings (ss_*): t, load_factor, tol, length_scale, and
!> for an arc-length step its arc and the sign of a first step's load increment; controls
!> (sc_*): check_start (/= 0: a start that is already the equilibrium ends with 0
!> iterations), load_step and load_steps (named in a failure's text), mode (0: Newton at
!> load_factor; 1: one arc-length step from the converged state, the load factor an unknown,
!> vectors(:, sx_previous) the previous step's increment of e, zero on the first; 2: the
!> tangent along the loads at the state, no step). scales (sr_*): the residual's scale floor
!> force_scale (< 0: set from the start and returned), the last relative residual and
!> constraint violation, the load factor reached and, at the state on entry (modes 1, 2),
!> ||q||, ||K_T^{-1} q|| and q . K_T^{-1} q (out). Returns the relative residual after each
!> iteration (history) and outcome (so_*): info, the iterations, why it converged
!> (static_solver's by_* codes), the factorizations; info /= 0 with the text in message.
subroutine system_static_solve(handle, nstate, state, counts, ndof, vectors, nnz, pattern, &
                               settings, controls, max_iter, scales, history, outcome, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state
  use static_solver, only: static_newton, static_failure_text, path_request
  use api_support, only: api_system, tp_rows, tp_cols, ss_time, ss_load_factor, ss_tol, &
                         ss_length_scale, ss_arc, ss_direction, sc_check_start, &
                         sc_load_step, sc_load_steps, sc_mode, sr_force_scale, &
                         sr_force_res, sr_con_res, sr_load_factor, sr_load_norm, &
                         sr_tangent_norm, sr_flexibility, sx_reference, sx_previous, &
                         so_info, so_iterations, so_converged_by, so_factorizations
  implicit none
  integer, intent(in) :: handle, nstate, ndof, nnz, max_iter
  real(dp), intent(inout) :: state(nstate), scales(7)
  integer, intent(inout) :: counts(6)
  !f2py intent(in,out) :: state, counts, scales
  real(dp), intent(in) :: vectors(ndof, 2), settings(6)
  integer, intent(in) :: pattern(nnz, 2), controls(4)
  real(dp), intent(out) :: history(max_iter)
  integer, intent(out) :: outcome(4)
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(contact_state) :: contact
  type(path_request) :: path
  real(dp), allocatable :: e(:), lam(:)
  integer :: info, detail, ncon, npoint, mode
  outcome = 0
  history = 0.0_dp
  call api_system(handle, sys, info, message)
  outcome(so_info) = info
  if (info /= 0) return
  ncon = sys%constraints%ncon
  npoint = sys%contact%npoint
  mode = controls(sc_mode)
  if (ndof /= sys%ndof .or. nstate /= ndof + ncon + 2 * npoint .or. &
      nnz /= size(sys%matrix%mass_pattern) .or. max_iter < 1 .or. mode < 0 .or. mode > 2) then
    outcome(so_info) = 4
    message = 'system_static_solve: sizes inconsistent with the system (ndof, the packed' // &
              ' state, nnz of the pattern), max_iter < 1 or a mode outside 0..2'
    return
  end if
  if (any(pattern < 1) .or. any(pattern > ndof)) then
    outcome(so_info) = 4
    message = 'system_static_solve: a pattern entry outside 1..ndof'
    return
  end if
  e = state(1:ndof)
  lam = state(ndof + 1:ndof + ncon)
  contact%guesses = reshape(state(ndof + ncon + 1:nstate), [2, npoint])
  contact%counts = counts
  if (mode == 0) then
    call static_newton(sys, settings(ss_time), settings(ss_load_factor), &
                       vectors(:, sx_reference), pattern(:, tp_rows), pattern(:, tp_cols), e, &
                       lam, contact, settings(ss_tol), settings(ss_length_scale), max_iter, &
                       controls(sc_check_start) /= 0, scales(sr_force_scale), &
                       outcome(so_iterations), history, scales(sr_force_res), &
                       scales(sr_con_res), outcome(so_converged_by), &
                       outcome(so_factorizations), info, detail)
    scales(sr_load_factor) = settings(ss_load_factor)
  else
    path%mode = mode
    path%arc = settings(ss_arc)
    path%direction = settings(ss_direction)
    path%previous = vectors(:, sx_previous)
    call static_newton(sys, settings(ss_time), settings(ss_load_factor), &
                       vectors(:, sx_reference), pattern(:, tp_rows), pattern(:, tp_cols), e, &
                       lam, contact, settings(ss_tol), settings(ss_length_scale), max_iter, &
                       .false., scales(sr_force_scale), outcome(so_iterations), history, &
                       scales(sr_force_res), scales(sr_con_res), outcome(so_converged_by), &
                       outcome(so_factorizations), info, detail, path)
    scales(sr_load_factor) = path%load_factor
    scales(sr_load_norm) = path%load_norm
    scales(sr_tangent_norm) = path%tangent_norm
    scales(sr_flexibility) = path%flexibility
  end if
  state = [e, lam, reshape(contact%guesses, [2 * npoint])]
  counts = contact%counts
  outcome(so_info) = info
  if (info /= 0) message = static_failure_text(info, detail, controls(sc_load_step), &
                                               controls(sc_load_steps), max_iter, &
                                               minval(history(1:max(1, outcome(so_iterations)))), &
                                               scales(sr_force_res), scales(sr_con_res), &
                                               settings(ss_tol), mode /= 0)
end subroutine system_static_solve


!> The contact forces of the system's contact pairs (system_add_contact_pair) at the full
!> coordinates and rates state(:, sv_*) (leaf_contact%contact_assemble): force (full),
!> records (6, npoint), energies (api_support ce_*: penalty potential, damping and
!> friction powers), and when want_jacobian /= 0 the Jacobian of minus the forces on the
!> full pattern (system_set_solver, nnz entries). The contact guesses and counters are
!> updated. info: 1 not a live handle; 2 sizes inconsistent with the system; 7 a normal
!> vanished; 8 the closest-point search failed.
subroutine system_contact_forces(handle, nfull, nnz, npoint, state, velocity_factor, &
                                 want_jacobian, guesses, counts, force, records, energies, &
                                 values, info, message)
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state, contact_forces
  use kernel_errors, only: failure_text
  use api_support, only: api_system, sv_coordinates, sv_rates, ce_potential, ce_damping, &
                         ce_friction
  implicit none
  integer, intent(in) :: handle, nfull, nnz, npoint, want_jacobian
  real(dp), intent(in) :: state(nfull, 2), velocity_factor
  real(dp), intent(inout) :: guesses(2, max(1, npoint))
  integer, intent(inout) :: counts(6)
  !f2py intent(in,out) :: guesses, counts
  real(dp), intent(out) :: force(nfull), records(6, max(1, npoint)), energies(3), values(nnz)
  integer, intent(out) :: info
  character(len=200), intent(out) :: message
  type(system_model), pointer :: sys
  type(contact_state) :: contact
  real(dp), allocatable :: jacobian(:)
  force = 0.0_dp
  records = 0.0_dp
  energies = 0.0_dp
  values = 0.0_dp
  call api_system(handle, sys, info, message)
  if (info /= 0) return
  if (nfull /= sys%nfull .or. npoint /= sys%contact%npoint .or. (want_jacobian /= 0 .and. &
      nnz /= size(sys%reduction%full_col))) then
    info = 2
    message = 'system_contact_forces: sizes inconsistent with the system (nfull, npoint,' // &
              ' or nnz of the full pattern)'
    return
  end if
  contact%guesses = guesses
  contact%counts = counts
  if (want_jacobian /= 0) then
    allocate (jacobian(nnz))
    jacobian = 0.0_dp
  end if
  call contact_forces(sys%contact, sys%reduction, state(:, sv_coordinates), state(:, sv_rates), &
                      velocity_factor, contact, force, records(:, 1:npoint), energies(ce_potential), &
                      energies(ce_damping:ce_friction), info, jacobian)
  if (info /= 0) then
    message = failure_text(info)
    return
  end if
  force = -force   ! (contact_forces subtracts them: the residual carries elastic minus contact)
  if (want_jacobian /= 0) values = jacobian
  guesses = contact%guesses
  counts = contact%counts
end subroutine system_contact_forces
