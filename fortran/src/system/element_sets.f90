!> Element sets: the elements of one body (or of several bodies of the same kind and
!> material) with everything their forces need, precomputed from the reference
!> configuration. This module holds the interface every element family implements:
!>
!>   element_set        abstract: the set's dofs and scatter map, its floating frame and
!>                      material damping; deferred `forces` (force, strain energy, on request
!>                      the tangent, damped with the coordinate rates and a rate factor),
!>                      `energy_power` (strain energy, frame power, dissipation) and
!>                      `section_forces` (a beam family's N, T, Q, M at stations along its
!>                      elements for rows of states; beam_stations; none by default);
!>   local_element_set  abstract extension for families whose elements are independent of
!>                      any frame (the large-deformation kinds): deferred `element_forces` of
!>                      one element; the loop over elements (OpenMP), the assembly of forces
!>                      and the scatter of tangents live here once;
!>   set_slot           a holder of any set (an array of polymorphic sets).
!>
!> The families extend these types in their own modules: ffr_elastic (ffr_set), beam_nonlinear
!> (continuum_set), beam_cubic (cubic_set), plate_element (plate_set), cable_element
!> (cable_set); system_api constructs them and hands them to mechanical_system's append_set.
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
  implicit none
  private
  public :: element_set, local_element_set, set_slot, frame_omega, scatter_add, loop_work, &
            local_set_forces, local_energy_power

  !> Work of an element loop (microseconds on one thread) below which it runs on one thread
  !> whatever OMP_NUM_THREADS says: waking the sleeping team (OMP_WAIT_POLICY passive) costs
  !> more than it saves (2 threads made the 4-node cubic boom 5.6 times slower)
  real(dp), parameter, public :: threaded_work = 200.0_dp
  !> The largest element (dofs) the serial loop holds in fixed work arrays (plates: 36);
  !> below the threading threshold a set's loop runs without an OpenMP region and without
  !> heap arrays: each element's force, energy and tangent are added as it is computed, in
  !> the element order of the threaded loop's assembly (the same sums, bitwise)
  integer, parameter :: serial_max_dofs = 36

  type, abstract :: element_set
    integer :: nel = 0
    integer :: nde = 0                                 ! dofs per element: beams 24, plates 36
    integer :: frame = 0                               ! the body's frame (system frames; 0: none)
    integer, allocatable :: dofs(:, :)                 ! (nde, nel), 1-based full coordinates
    integer, allocatable :: scatter(:, :, :)           ! (nde, nde, nel) positions in full values
    real(dp) :: damping_time = 0.0_dp                 ! Kelvin-Voigt retardation time (s)
  contains
    procedure(set_forces_interface), deferred :: forces
    procedure :: energy_power => set_energy_power
    procedure :: selected_forces => no_selected_forces
    procedure :: section_forces => no_section_forces
    procedure :: column_forces => set_column_forces
  end type element_set

  abstract interface
    !> Adds the set's elastic force at the full coordinates e to force and returns the strain
    !> energy; sets in a floating frame use its rotation. With tangent_values present, the
    !> element tangents (in the frame of tangent_rotation, by default rotation) are added to
    !> the full pattern's values. info = 7: an element's configuration is degenerate (a plate
    !> normal vanished).
    !> Damping (damping_time > 0 and the full coordinate rates v given): the force adds the
    !> Kelvin-Voigt damping, dissipation returns its power, and the tangent is the combined
    !> dQ/dq + rate_factor dQ/dq' (default rate_factor 0). Sets in a frame use its angular
    !> velocity (omega_local, in the frame; default 0) in the force and tangent_omega (in the
    !> tangent's frame; default omega_local) in the tangent's omega term.
    subroutine set_forces_interface(set, rotation, e, force, energy, info, tangent_values, &
                                    tangent_rotation, v, omega_local, rate_factor, dissipation, &
                                    tangent_omega)
      import :: element_set, dp
      class(element_set), intent(in) :: set
      real(dp), intent(in) :: rotation(3, 3), e(:)
      real(dp), intent(inout) :: force(:)
      real(dp), intent(out) :: energy
      integer, intent(out) :: info
      real(dp), intent(inout), optional :: tangent_values(:)
      real(dp), intent(in), optional :: tangent_rotation(3, 3)
      real(dp), intent(in), optional :: v(:), omega_local(3), rate_factor, tangent_omega(3)
      real(dp), intent(out), optional :: dissipation
    end subroutine set_forces_interface
  end interface

  !> Families whose elements need nothing but their own coordinates (and rates).
  type, abstract, extends(element_set) :: local_element_set
    !> microseconds per element on one thread, force only / force and tangent (the
    !> threading threshold; benchmarks/element_cost.py and plate_cost.py)
    real(dp) :: force_cost = 6.0_dp, tangent_cost = 80.0_dp
  contains
    procedure(element_forces_interface), deferred :: element_forces
    procedure :: forces => local_set_forces
    procedure :: column_forces => local_column_forces
    procedure :: energy_power => local_energy_power
    procedure :: element_energy => local_element_energy
    procedure :: midpoint_forces => no_midpoint_forces
  end type local_element_set

  abstract interface
    !> One element el at its nodal vectors coords (3, nde / 3): force (nde), strain energy,
    !> on request (want_tangent) the tangent (nde, nde); info /= 0: a degenerate element.
    !> With rates (the element's nodal rates; a damped set: rate_factor and dissipation
    !> then present too) the damping force, the combined tangent dQ/dq + rate_factor dQ/dq'
    !> and the dissipated power.
    pure subroutine element_forces_interface(set, el, coords, want_tangent, force, energy, &
                                             tangent, info, rates, rate_factor, dissipation)
      import :: local_element_set, dp
      class(local_element_set), intent(in) :: set
      integer, intent(in) :: el
      real(dp), intent(in) :: coords(:, :)
      logical, intent(in) :: want_tangent
      real(dp), intent(out) :: force(:), energy, tangent(:, :)
      integer, intent(out) :: info
      real(dp), intent(in), optional :: rates(:, :), rate_factor
      real(dp), intent(out), optional :: dissipation
    end subroutine element_forces_interface
  end interface

  !> One set of any family, as the system holds its sets.
  type :: set_slot
    class(element_set), allocatable :: item
  end type set_slot

contains

  !> The force pass of an undamped set on the independent coordinates of a selection
  !> (q = B e + q0 with each row of B empty or one 1, no column twice: select(i) the column
  !> of full coordinate i, 0 where fixed, offset = q0): the set's force added to the reduced
  !> force as to_full, forces and to_reduced would give it, bit for bit; done = .false.
  !> where the family has no such pass (the default): nothing is computed.
  subroutine no_selected_forces(set, select, offset, e, force, energy, info, done)
    class(element_set), intent(in) :: set
    integer, intent(in) :: select(:)
    real(dp), intent(in) :: offset(:), e(:)
    real(dp), intent(inout) :: force(:)
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    logical, intent(out) :: done
    energy = 0.0_dp
    info = 0
    done = .false.
  end subroutine no_selected_forces

  !> The set's force added to force where wanted (nfull) is true, as forces adds it there
  !> (the same sums, bit for bit); elsewhere force may hold any partial sum. A damped set
  !> is given v and omega_local as forces is (rate factor 0, no tangent). The default: the
  !> whole forces pass.
  subroutine set_column_forces(set, rotation, e, wanted, force, info, v, omega_local)
    class(element_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), e(:)
    logical, intent(in) :: wanted(:)
    real(dp), intent(inout) :: force(:)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: v(:), omega_local(3)
    real(dp) :: energy
    call set%forces(rotation, e, force, energy, info, v=v, omega_local=omega_local)
  end subroutine set_column_forces

  !> column_forces of a local set: the elements with a wanted coordinate alone, in element
  !> order (the order in which local_set_forces adds them: the same sums at those
  !> coordinates). info = 7: such an element is degenerate.
  subroutine local_column_forces(set, rotation, e, wanted, force, info, v, omega_local)
    class(local_element_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), e(:)
    logical, intent(in) :: wanted(:)
    real(dp), intent(inout) :: force(:)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: v(:), omega_local(3)
    real(dp), allocatable :: element_force(:), tangent(:, :)
    real(dp) :: element_energy, element_power
    logical :: damped, touched
    integer :: el, a
    info = 0
    damped = present(v) .and. set%damping_time > 0.0_dp
    allocate (element_force(set%nde), tangent(set%nde, set%nde))
    do el = 1, set%nel
      touched = .false.
      do a = 1, set%nde
        touched = touched .or. wanted(set%dofs(a, el))
      end do
      if (.not. touched) cycle
      if (damped) then
        call gathered_forces(set, el, e, .false., element_force, element_energy, tangent, info, &
                             v, 0.0_dp, element_power)
      else
        call gathered_forces(set, el, e, .false., element_force, element_energy, tangent, info)
      end if
      if (info /= 0) then
        info = 7
        return
      end if
      do a = 1, set%nde
        force(set%dofs(a, el)) = force(set%dofs(a, el)) + element_force(a)
      end do
    end do
  end subroutine local_column_forces

  !> The section forces (ns nel, nrows, 6) [N, T, Q_height, Q_width, M_height, M_width] at
  !> the stations xi (ns, in [0, 1] along each element; station i of element el in row
  !> i + ns (el - 1)) of the states q_rows (nfull, nrows), the set's frame at each row
  !> rotations (3, 3, nrows): a beam family's (beam_stations; a family may keep what it
  !> builds for these stations). info = 1 here: the family reports no section forces (or
  !> its set was given no section data).
  subroutine no_section_forces(set, rotations, q_rows, xi, forces, info)
    class(element_set), intent(inout) :: set
    real(dp), intent(in) :: rotations(:, :, :), q_rows(:, :), xi(:)
    real(dp), intent(out) :: forces(:, :, :)
    integer, intent(out) :: info
    forces = 0.0_dp
    info = 1
  end subroutine no_section_forces

  !> Strain energy at e and the power of the frame's motion at fixed e (a set in a moving
  !> frame; unit axis, rate phi'; 0 here: the families that have one override this). A damped
  !> set given the coordinate rates v also returns the dissipated power (dissipation, >= 0;
  !> 0 otherwise).
  subroutine set_energy_power(set, rotation, axis, rate, e, energy, power, info, v, dissipation)
    class(element_set), intent(in) :: set
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
    allocate (unused(size(e)))
    unused = 0.0_dp
    if (present(v) .and. set%damping_time > 0.0_dp) then
      call set%forces(rotation, e, unused, energy, info, v=v, dissipation=power_lost)
    else
      call set%forces(rotation, e, unused, energy, info)
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

  !> The forces of a local set (the element_set interface): every element through
  !> element_forces, in parallel (OpenMP, when built with it) above the threading threshold;
  !> rotation, tangent_rotation and the omegas are not used (no frame enters).
  subroutine local_set_forces(set, rotation, e, force, energy, info, tangent_values, &
                              tangent_rotation, v, omega_local, rate_factor, dissipation, &
                              tangent_omega)
    class(local_element_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), e(:)
    real(dp), intent(inout) :: force(:)
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    real(dp), intent(inout), optional :: tangent_values(:)
    real(dp), intent(in), optional :: tangent_rotation(3, 3)
    real(dp), intent(in), optional :: v(:), omega_local(3), rate_factor, tangent_omega(3)
    real(dp), intent(out), optional :: dissipation
    real(dp), allocatable :: element_force(:, :), element_energy(:), tangents(:, :, :)
    real(dp), allocatable :: element_power(:)
    real(dp) :: factor, power
    logical :: want_tangent, damped
    integer, allocatable :: element_info(:)
    integer :: el
    info = 0
    want_tangent = present(tangent_values)
    damped = present(v) .and. set%damping_time > 0.0_dp
    power = 0.0_dp
    if (damped) then
      factor = 0.0_dp
      if (present(rate_factor)) factor = rate_factor
    end if
    if (loop_work(set, want_tangent) < threaded_work .and. set%nde <= serial_max_dofs) then
      if (damped) then
        call serial_set_forces(set, e, force, energy, info, tangent_values, v, factor, power)
      else
        call serial_set_forces(set, e, force, energy, info, tangent_values)
      end if
      if (present(dissipation)) dissipation = power
      return
    end if
    allocate (element_force(set%nde, set%nel), element_energy(set%nel), element_info(set%nel))
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
        call gathered_forces(set, el, e, want_tangent, element_force(:, el), element_energy(el), &
                             tangents(:, :, merge(el, 1, want_tangent)), element_info(el), v, &
                             factor, element_power(el))
      end do
      !$omp end parallel do
    else
      !$omp parallel do schedule(static) if(loop_work(set, want_tangent) >= threaded_work)
      do el = 1, set%nel
        call gathered_forces(set, el, e, want_tangent, element_force(:, el), element_energy(el), &
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
  end subroutine local_set_forces

  !> local_set_forces of a small set on this thread (below the threading threshold): each
  !> element's force, energy, dissipation and tangent added as it is computed, in element
  !> order (the threaded loop's assembly order: the same sums), with fixed work arrays. With
  !> v (a damped set) rate_factor and dissipation are present. On an element's failure
  !> (info = 7) force holds the elements before it.
  subroutine serial_set_forces(set, e, force, energy, info, tangent_values, v, rate_factor, &
                               dissipation)
    class(local_element_set), intent(in) :: set
    real(dp), intent(in) :: e(:)
    real(dp), intent(inout) :: force(:)
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    real(dp), intent(inout), optional :: tangent_values(:)
    real(dp), intent(in), optional :: v(:), rate_factor
    real(dp), intent(out), optional :: dissipation
    real(dp), target :: tangent_work(serial_max_dofs * serial_max_dofs)
    real(dp) :: element_force(serial_max_dofs), element_energy, element_power
    real(dp), pointer :: tangent(:, :)
    logical :: want_tangent
    integer :: el, a, b, nde, element_info
    info = 0
    nde = set%nde
    want_tangent = present(tangent_values)
    tangent(1:nde, 1:nde) => tangent_work(1:nde * nde)
    energy = 0.0_dp
    if (present(dissipation)) dissipation = 0.0_dp
    do el = 1, set%nel
      if (present(v)) then
        call gathered_forces(set, el, e, want_tangent, element_force(1:nde), element_energy, &
                             tangent, element_info, v, rate_factor, element_power)
        dissipation = dissipation + element_power
      else
        call gathered_forces(set, el, e, want_tangent, element_force(1:nde), element_energy, &
                             tangent, element_info)
      end if
      if (element_info /= 0) then
        info = 7
        energy = 0.0_dp
        return
      end if
      do a = 1, nde  ! (a loop: the vector-subscripted statement made a heap temporary)
        force(set%dofs(a, el)) = force(set%dofs(a, el)) + element_force(a)
      end do
      energy = energy + element_energy
      if (.not. want_tangent) cycle
      do b = 1, nde
        do a = 1, nde
          if (set%scatter(a, b, el) > 0) tangent_values(set%scatter(a, b, el)) = &
            tangent_values(set%scatter(a, b, el)) + tangent(a, b)
        end do
      end do
    end do
  end subroutine serial_set_forces

  !> The energy_power of a local set: the strain energy element by element through
  !> element_energy (no force assembly, no heap arrays), summed in element order as the
  !> force pass sums it; with v (a damped set) the dissipated power too. No frame: power 0.
  subroutine local_energy_power(set, rotation, axis, rate, e, energy, power, info, v, &
                                dissipation)
    class(local_element_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), axis(3), rate, e(:)
    real(dp), intent(out) :: energy, power
    integer, intent(out) :: info
    real(dp), intent(in), optional :: v(:)
    real(dp), intent(out), optional :: dissipation
    real(dp) :: coords(3, serial_max_dofs / 3), rates(3, serial_max_dofs / 3)
    real(dp) :: element_energy, element_power, power_lost
    logical :: damped
    integer :: el, nodes, element_info
    if (set%nde > serial_max_dofs) then
      call set_energy_power(set, rotation, axis, rate, e, energy, power, info, v, dissipation)
      return
    end if
    info = 0
    power = 0.0_dp
    energy = 0.0_dp
    power_lost = 0.0_dp
    damped = present(v) .and. set%damping_time > 0.0_dp
    nodes = set%nde / 3
    do el = 1, set%nel
      call gather_element(set, el, e, coords(:, 1:nodes))
      if (damped) then
        call gather_element(set, el, v, rates(:, 1:nodes))
        call set%element_energy(el, coords(:, 1:nodes), element_energy, element_info, &
                                rates(:, 1:nodes), element_power)
        power_lost = power_lost + element_power
      else
        call set%element_energy(el, coords(:, 1:nodes), element_energy, element_info)
      end if
      if (element_info /= 0) then
        info = 7
        energy = 0.0_dp
        return
      end if
      energy = energy + element_energy
    end do
    if (present(dissipation)) dissipation = power_lost
  end subroutine local_energy_power

  !> One element's strain energy at its nodal vectors coords (3, nde / 3) and, with rates,
  !> its dissipated power: by default through element_forces (a family with a cheaper
  !> energy-only path overrides this; it must return the same numbers). Only for elements
  !> of at most serial_max_dofs dofs (local_energy_power).
  pure subroutine local_element_energy(set, el, coords, energy, info, rates, dissipation)
    class(local_element_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: coords(:, :)
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    real(dp), intent(in), optional :: rates(:, :)
    real(dp), intent(out), optional :: dissipation
    real(dp), target :: tangent_work(serial_max_dofs * serial_max_dofs)
    real(dp) :: force(serial_max_dofs)
    real(dp), pointer :: tangent(:, :)
    tangent(1:set%nde, 1:set%nde) => tangent_work(1:set%nde * set%nde)
    if (present(rates)) then
      call set%element_forces(el, coords, .false., force(1:set%nde), energy, tangent, info, &
                              rates, 0.0_dp, dissipation)
    else
      call set%element_forces(el, coords, .false., force(1:set%nde), energy, tangent, info)
    end if
  end subroutine local_element_energy

  !> The discrete-gradient force of element el between the nodal vectors coords0 and coords1
  !> (3, nde / 3) for the energy-momentum stepper (energy_momentum): a force f with
  !> W(q1) - W(q0) = f . (q1 - q0) exactly, equal to W'(q) when q0 = q1, and on request
  !> (want_tangent) its Jacobian df/dq1 (nde, nde; not symmetric). info = 1 here: the family
  !> has no discrete gradient (the families that have one override this).
  pure subroutine no_midpoint_forces(set, el, coords0, coords1, want_tangent, force, tangent, &
                                     info)
    class(local_element_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: coords0(:, :), coords1(:, :)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(:), tangent(:, :)
    integer, intent(out) :: info
    force = 0.0_dp
    if (want_tangent) tangent = 0.0_dp
    info = 1
  end subroutine no_midpoint_forces

  !> Estimated work of one pass over a set's elements, microseconds on one thread.
  pure real(dp) function loop_work(set, want_tangent)
    class(local_element_set), intent(in) :: set
    logical, intent(in) :: want_tangent
    loop_work = merge(set%tangent_cost, set%force_cost, want_tangent) * set%nel
  end function loop_work

  !> One element of a local set: its coordinates (and rates) gathered from the full vectors,
  !> then the family's element_forces.
  pure subroutine gathered_forces(set, el, e, want_tangent, force, energy, tangent, info, v, &
                                  rate_factor, dissipation)
    class(local_element_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: e(:)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(:), energy, tangent(:, :)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: v(:), rate_factor
    real(dp), intent(out), optional :: dissipation
    ! (fixed work arrays: no heap allocation per element)
    real(dp) :: coords(3, serial_max_dofs / 3), rates(3, serial_max_dofs / 3)
    integer :: nodes
    if (set%nde > serial_max_dofs) then
      call gathered_large_forces(set, el, e, want_tangent, force, energy, tangent, info, v, &
                                 rate_factor, dissipation)
      return
    end if
    nodes = set%nde / 3
    ! the element's coordinates as (3, shapes), copied in place of a reshape temporary
    call gather_element(set, el, e, coords(:, 1:nodes))
    if (present(v)) then
      call gather_element(set, el, v, rates(:, 1:nodes))
      call set%element_forces(el, coords(:, 1:nodes), want_tangent, force, energy, tangent, &
                              info, rates(:, 1:nodes), rate_factor, dissipation)
      return
    end if
    call set%element_forces(el, coords(:, 1:nodes), want_tangent, force, energy, tangent, info)
  end subroutine gathered_forces

  !> gathered_forces of an element with more than serial_max_dofs dofs.
  pure subroutine gathered_large_forces(set, el, e, want_tangent, force, energy, tangent, info, &
                                        v, rate_factor, dissipation)
    class(local_element_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: e(:)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(:), energy, tangent(:, :)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: v(:), rate_factor
    real(dp), intent(out), optional :: dissipation
    real(dp) :: coords(3, set%nde / 3), rates(3, set%nde / 3)
    call gather_element(set, el, e, coords)
    if (present(v)) then
      call gather_element(set, el, v, rates)
      call set%element_forces(el, coords, want_tangent, force, energy, tangent, info, rates, &
                              rate_factor, dissipation)
      return
    end if
    call set%element_forces(el, coords, want_tangent, force, energy, tangent, info)
  end subroutine gathered_large_forces

  !> Element el's nodal 3-vectors (3, nde / 3) gathered from the full vector x.
  pure subroutine gather_element(set, el, x, nodal)
    class(local_element_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: x(:)
    real(dp), intent(out) :: nodal(:, :)
    integer :: node
    do node = 1, set%nde / 3
      nodal(:, node) = x(set%dofs(3 * node - 2:3 * node, el))
    end do
  end subroutine gather_element

  !> Adds the element matrices (nde, nde, nel) to the full pattern's values.
  pure subroutine scatter_add(set, matrices, values)
    class(element_set), intent(in) :: set
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
