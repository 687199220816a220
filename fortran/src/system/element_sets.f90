!> Element sets: the elements of one body (or of several bodies of the same kind and
!> material) with everything their forces need, precomputed from the reference
!> configuration. Four kinds share one interface:
!>   ffr         ANCF-FFR beam (ffr_elastic): K0 and the rigid configuration in the
!>               body's floating frame;
!>   continuum   large-deformation beam (beam_nonlinear): material gradients at the
!>               Gauss points of the section rule;
!>   structural  large-deformation beam with 'cubic' bending (beam_structural): strain forms;
!>   plate       thin plate, plain or completed (plate_element): reference data at the
!>               Gauss points.
!> Element dofs index the FULL coordinate vector (before the elimination of linear
!> constraints); scatter(:, :, el) holds each element-matrix entry's position in the values
!> of the full sparse pattern.
!>
!> Kelvin-Voigt material damping: a set with damping_time tau > 0 adds the damping force
!> of the strain rates (element modules) when the coordinate rates are given, and its
!> tangent is then the combined dQ/dq + rate_factor dQ/dq' (rate_factor: the stepper's
!> d q'/d q = gamma / (beta h)); with tau = 0 (the effect off) none of that code runs.
module element_sets
  use ancf_kinds, only: dp
  use ffr_elastic, only: ffr_force, ffr_stiffness, ffr_energy_power, ffr_damped_force, &
                         ffr_damped_stiffness
  use beam_nonlinear, only: nonlinear_element, nonlinear_element_damped
  use beam_structural, only: structural_element, structural_element_damped
  use plate_element, only: plate_forces, plate_forces_damped
  implicit none
  private
  public :: element_set, set_forces, set_tangent_values, set_energy_power, frame_omega

  integer, parameter, public :: set_ffr = 1, set_continuum = 2, set_structural = 3, set_plate = 4
  !> Work of an element loop (microseconds on one thread) below which it runs on one thread
  !> whatever OMP_NUM_THREADS says: waking the sleeping team (OMP_WAIT_POLICY passive) costs
  !> more than it saves (2 threads made the 4-node cubic boom 5.6 times slower)
  real(dp), parameter :: threaded_work = 200.0_dp

  type :: element_set
    integer :: kind = 0
    integer :: nel = 0
    integer :: nde = 0                                 ! dofs per element: beams 24, plates 36
    integer :: frame = 0                               ! FFR: the floating frame (system frames)
    integer, allocatable :: dofs(:, :)                 ! (nde, nel), 1-based full coordinates
    integer, allocatable :: scatter(:, :, :)           ! (nde, nde, nel) positions in full values
    real(dp) :: youngs = 0.0_dp, poisson = 0.0_dp, thickness = 0.0_dp
    real(dp) :: damping_time = 0.0_dp                 ! Kelvin-Voigt retardation time (s)
    ! ffr: K0 (24, 24, nel) and the rigid configuration in the frame (24, nel)
    real(dp), allocatable :: stiffness0(:, :, :), reference(:, :)
    ! continuum: gradients (8, 3, npts, nel), weights (npts, nel); the first volume_points
    ! points carry the Poisson-free law
    integer :: volume_points = 0
    real(dp), allocatable :: gradients(:, :, :, :), weights(:, :)
    ! and the section's torsion and shear correction [c, d_y, d_z] (beam_nonlinear)
    real(dp) :: shear_scales(3) = [1.0_dp, 0.0_dp, 0.0_dp]
    ! structural: forms (8, 8, nterms, nel), reference strains and stiffnesses (nterms, nel)
    real(dp), allocatable :: forms(:, :, :, :), strain0(:, :), term_stiffness(:, :)
    ! and the forms' nonzero entries (structural_pattern): (2, 64, nterms), (nterms)
    integer, allocatable :: form_pairs(:, :, :), form_npairs(:)
    ! plate: derivs (12, 5, npts, nel), frame maps (2, 2, npts, nel), reference curvatures
    ! (3, npts, nel), weights (npts, nel)
    real(dp), allocatable :: derivs(:, :, :, :), plate_frame(:, :, :, :), curvature0(:, :, :)
  end type element_set

contains

  !> Strain energy at e and, for an FFR set in a moving frame (unit axis, rate phi'), the
  !> power of the frame's motion at fixed e (ffr_energy_power); 0 for the other kinds.
  !> A damped set given the coordinate rates v also returns the dissipated power
  !> (dissipation, >= 0; 0 otherwise), and an FFR set's frame power then includes that of
  !> its damping force.
  subroutine set_energy_power(set, rotation, axis, rate, e, energy, power, info, v, dissipation)
    type(element_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), axis(3), rate, e(:)
    real(dp), intent(out) :: energy, power
    integer, intent(out) :: info
    real(dp), intent(in), optional :: v(:)
    real(dp), intent(out), optional :: dissipation
    real(dp), allocatable :: unused(:)
    real(dp) :: power_lost
    info = 0
    power = 0.0_dp
    power_lost = 0.0_dp
    if (set%kind == set_ffr) then
      if (present(v) .and. set%damping_time > 0.0_dp) then
        call ffr_energy_power(set%nel, set%dofs, set%stiffness0, set%reference, rotation, &
                              axis, rate, e, energy, power, v, &
                              frame_omega(rotation, axis, rate), set%damping_time, power_lost)
      else
        call ffr_energy_power(set%nel, set%dofs, set%stiffness0, set%reference, rotation, &
                              axis, rate, e, energy, power)
      end if
      if (present(dissipation)) dissipation = power_lost
      return
    end if
    allocate (unused(size(e)))
    unused = 0.0_dp
    if (present(v) .and. set%damping_time > 0.0_dp) then
      call set_forces(set, rotation, e, unused, energy, info, v=v, dissipation=power_lost)
    else
      call set_forces(set, rotation, e, unused, energy, info)
    end if
    if (present(dissipation)) dissipation = power_lost
  end subroutine set_energy_power

  !> The angular velocity of a frame turning at rate phi' about the unit axis k (global),
  !> in the frame: phi' A^T k.
  pure function frame_omega(rotation, axis, rate) result(omega_local)
    real(dp), intent(in) :: rotation(3, 3), axis(3), rate
    real(dp) :: omega_local(3)
    omega_local = 0.0_dp
    if (rate == 0.0_dp) return
    omega_local = rate * matmul(transpose(rotation), axis / norm2(axis))
  end function frame_omega

  !> Adds the set's elastic force at the full coordinates e to force and returns the strain
  !> energy; FFR elements use the frame rotation. With tangent_values present, the element
  !> tangents (FFR: T K0 T^T with tangent_rotation, by default the same rotation) are added
  !> to the full pattern's values. Elements in parallel
  !> (OpenMP, when built with it) for the large-deformation kinds. info = 7: a plate
  !> element's normal vanished.
  !> Damping (set%damping_time > 0 and the full coordinate rates v given): the force adds
  !> the Kelvin-Voigt damping, dissipation returns its power, and the tangent is the combined
  !> dQ/dq + rate_factor dQ/dq' (default rate_factor 0). FFR sets use the frame's angular
  !> velocity (omega_local, in the frame; default 0) in the force and tangent_omega (in the
  !> tangent's frame; default omega_local) in the tangent's omega term.
  subroutine set_forces(set, rotation, e, force, energy, info, tangent_values, tangent_rotation, &
                        v, omega_local, rate_factor, dissipation, tangent_omega)
    type(element_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), e(:)
    real(dp), intent(inout) :: force(:)
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    real(dp), intent(inout), optional :: tangent_values(:)
    real(dp), intent(in), optional :: tangent_rotation(3, 3)  ! FFR: default rotation
    real(dp), intent(in), optional :: v(:), omega_local(3), rate_factor, tangent_omega(3)
    real(dp), intent(out), optional :: dissipation
    real(dp), allocatable :: element_force(:, :), element_energy(:), tangents(:, :, :)
    real(dp), allocatable :: element_power(:), stiffness(:, :, :)
    real(dp) :: omega(3), omega_t(3), factor, power
    logical :: want_tangent, damped
    integer :: el, element_info(set%nel)
    info = 0
    want_tangent = present(tangent_values)
    damped = present(v) .and. set%damping_time > 0.0_dp
    power = 0.0_dp
    if (damped) then
      omega = 0.0_dp
      if (present(omega_local)) omega = omega_local
      omega_t = omega
      if (present(tangent_omega)) omega_t = tangent_omega
      factor = 0.0_dp
      if (present(rate_factor)) factor = rate_factor
    end if
    if (set%kind == set_ffr) then
      if (damped) then
        call ffr_damped_force(set%nel, set%dofs, set%stiffness0, set%reference, rotation, &
                              omega, set%damping_time, e, v, force, energy, power)
        if (want_tangent) then
          allocate (stiffness(24, 24, set%nel))
          if (present(tangent_rotation)) then
            call ffr_damped_stiffness(set%nel, set%stiffness0, tangent_rotation, omega_t, &
                                      factor, set%damping_time, stiffness)
          else
            call ffr_damped_stiffness(set%nel, set%stiffness0, rotation, omega_t, factor, &
                                      set%damping_time, stiffness)
          end if
          call scatter_add(set, stiffness, tangent_values)
        end if
      else
        call ffr_force(set%nel, set%dofs, set%stiffness0, set%reference, rotation, e, force, &
                       energy)
        if (want_tangent) then
          if (present(tangent_rotation)) then
            call set_tangent_values(set, tangent_rotation, tangent_values)
          else
            call set_tangent_values(set, rotation, tangent_values)
          end if
        end if
      end if
      if (present(dissipation)) dissipation = power
      return
    end if
    allocate (element_force(set%nde, set%nel), element_energy(set%nel))
    if (want_tangent) then
      allocate (tangents(set%nde, set%nde, set%nel))
    else
      allocate (tangents(set%nde, set%nde, 1))
    end if
    element_info = 0
    if (damped) then
      allocate (element_power(set%nel))
      !$omp parallel do schedule(static) if(loop_work(set, want_tangent) >= threaded_work)
      do el = 1, set%nel
        call element_forces(set, el, e, want_tangent, element_force(:, el), element_energy(el), &
                            tangents(:, :, merge(el, 1, want_tangent)), element_info(el), v, &
                            factor, element_power(el))
      end do
      !$omp end parallel do
    else
      !$omp parallel do schedule(static) if(loop_work(set, want_tangent) >= threaded_work)
      do el = 1, set%nel
        call element_forces(set, el, e, want_tangent, element_force(:, el), element_energy(el), &
                            tangents(:, :, merge(el, 1, want_tangent)), element_info(el))
      end do
      !$omp end parallel do
    end if
    if (any(element_info /= 0)) then
      info = 7
      energy = 0.0_dp
      return
    end if
    do el = 1, set%nel
      force(set%dofs(:, el)) = force(set%dofs(:, el)) + element_force(:, el)
    end do
    energy = sum(element_energy)
    if (damped) power = sum(element_power)
    if (present(dissipation)) dissipation = power
    if (want_tangent) call scatter_add(set, tangents, tangent_values)
  end subroutine set_forces

  !> Estimated work of one pass over a set's elements, microseconds on one thread (per
  !> element, as benchmarks/element_cost.py and plate_cost.py measured: force / force +
  !> tangent: continuum beam 1.2 / 15, cubic beam 1.2 / 3, plate 6 / 80).
  pure real(dp) function loop_work(set, want_tangent)
    type(element_set), intent(in) :: set
    logical, intent(in) :: want_tangent
    real(dp) :: per_element
    select case (set%kind)
    case (set_continuum)
      per_element = merge(15.0_dp, 1.2_dp, want_tangent)
    case (set_structural)
      per_element = merge(3.0_dp, 1.2_dp, want_tangent)
    case default
      per_element = merge(80.0_dp, 6.0_dp, want_tangent)
    end select
    loop_work = per_element * set%nel
  end function loop_work

  !> One element of a large-deformation set; with the full coordinate rates v (a damped
  !> set: then rate_factor and dissipation too), the damping force, the combined tangent and
  !> the dissipated power (the element modules' *_damped routines).
  pure subroutine element_forces(set, el, e, want_tangent, force, energy, tangent, info, v, &
                                 rate_factor, dissipation)
    type(element_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: e(:)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(:), energy, tangent(:, :)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: v(:), rate_factor
    real(dp), intent(out), optional :: dissipation
    real(dp) :: coords(3, set%nde / 3), rates(3, set%nde / 3)
    integer :: node
    info = 0
    ! the element's coordinates as (3, shapes), copied in place of a reshape temporary
    do node = 1, set%nde / 3
      coords(:, node) = e(set%dofs(3 * node - 2:3 * node, el))
    end do
    if (present(v)) then
      do node = 1, set%nde / 3
        rates(:, node) = v(set%dofs(3 * node - 2:3 * node, el))
      end do
      select case (set%kind)
      case (set_continuum)
        call nonlinear_element_damped(coords, rates, set%gradients(:, :, :, el), &
                                      set%weights(:, el), set%volume_points, set%youngs, &
                                      set%poisson, set%shear_scales, set%damping_time, &
                                      rate_factor, want_tangent, &
                                      force, energy, dissipation, tangent)
      case (set_structural)
        call structural_element_damped(coords, rates, set%forms(:, :, :, el), &
                                       set%strain0(:, el), set%term_stiffness(:, el), &
                                       set%damping_time, rate_factor, want_tangent, force, &
                                       energy, dissipation, tangent)
      case (set_plate)
        call plate_forces_damped(coords, rates, set%derivs(:, :, :, el), &
                                 set%plate_frame(:, :, :, el), set%curvature0(:, :, el), &
                                 set%weights(:, el), set%youngs, set%poisson, set%thickness, &
                                 set%damping_time, rate_factor, want_tangent, force, energy, &
                                 dissipation, tangent, info)
      end select
      return
    end if
    select case (set%kind)
    case (set_continuum)
      call nonlinear_element(coords, set%gradients(:, :, :, el), set%weights(:, el), &
                             set%volume_points, set%youngs, set%poisson, set%shear_scales, &
                             want_tangent, force, &
                             energy, tangent)
    case (set_structural)
      call structural_element(coords, set%forms(:, :, :, el), set%strain0(:, el), &
                              set%term_stiffness(:, el), want_tangent, force, energy, tangent, &
                              set%form_pairs, set%form_npairs)
    case (set_plate)
      call plate_forces(coords, set%derivs(:, :, :, el), set%plate_frame(:, :, :, el), &
                        set%curvature0(:, :, el), set%weights(:, el), set%youngs, set%poisson, &
                        set%thickness, want_tangent, force, energy, tangent, info)
    end select
  end subroutine element_forces

  !> FFR: adds T K0 T^T of every element to the full pattern's values.
  subroutine set_tangent_values(set, rotation, values)
    type(element_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3)
    real(dp), intent(inout) :: values(:)
    real(dp), allocatable :: stiffness(:, :, :)
    allocate (stiffness(24, 24, set%nel))
    call ffr_stiffness(set%nel, set%stiffness0, rotation, stiffness)
    call scatter_add(set, stiffness, values)
  end subroutine set_tangent_values

  pure subroutine scatter_add(set, matrices, values)
    type(element_set), intent(in) :: set
    real(dp), intent(in) :: matrices(:, :, :)
    real(dp), intent(inout) :: values(:)
    integer :: el, a, b
    do el = 1, set%nel
      do b = 1, set%nde
        do a = 1, set%nde
          if (set%scatter(a, b, el) > 0) values(set%scatter(a, b, el)) = &
            values(set%scatter(a, b, el)) + matrices(a, b, el)
        end do
      end do
    end do
  end subroutine scatter_add

end module element_sets
