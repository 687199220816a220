!> A mechanical system as the kernel holds it behind a handle (system_store): element sets
!> of any kinds, rigid bodies (through their constant mass), floating frames, drives,
!> loads, constraints with Lagrange multipliers, linear constraints eliminated by a
!> constant matrix B, contact pairs, probes, and the iteration matrix's solver. Each of
!> these is a component of system_model in its own module (system/system_*.f90: mass,
!> reduction, drives, loads, force elements, constraints, contact, probes, iteration
!> matrix, carried vectors) with the routines that own it; this module keeps what combines
!> them: the forces, the energies, the refactorization and the output rows.
!>
!> Coordinates. The full vector q holds every body's coordinates; linear constraints give
!> q = B e + q0 with the independent coordinates e, the unknowns of the solvers (without
!> reduction B = I, q0 = 0). Element sets, contact pairs, moments and probes index q;
!> the mass, the loads, the constraints (whose operands are affine in e) and the solver's
!> pattern index e. Forces are accumulated in full coordinates and reduced once (B^T).
!>
!> Equations of motion (seed 000 eqs. 58-62, seed 003 eq. 38):
!>   M e'' + B^T (Q_el(q) - Q_c(q, q') - Q_M(q)) - Q(t) - Phi_e^T lambda = 0,   Phi(e, t) = 0,
!> Q_el the elastic forces of the sets, Q_c the contact forces, Q_M the dead moments, Q(t) the
!> constant loads plus driven forces phi_d(t) f_d.
!>
!> The iteration matrix S = beta' M + B^T (K + c_v C_c) B (K the sets' tangents, C_c the
!> contact Jacobian with c_v = d q'/d q) lives on the reduced pattern. Policy 'constant'
!> (pure FFR systems): S is assembled in the solver frame, where every 3-vector of a body
!> in a moving frame A(t) is resolved in A(t) (S = U S_c U^T, U = diag(A_f(t)) per
!> vector): S_c is constant and factorized once per run. Otherwise S is assembled in
!> global coordinates and refactorized as the stepper's policy asks.
!>
!> Material damping (Kelvin-Voigt, element sets with a retardation time tau > 0): the sets
!> get the full coordinate rates and their frame's angular velocity (the frame rates
!> phi'_f), the tangent becomes K + c_v C (C = dQ/dq') and the dissipated power is a work
!> of the output rows (power_material_damping = -sum tau s'^T D s'). In the policy
!> 'constant' the factorized matrix holds beta' M + (1 + c_v tau) K0 in the solver frame;
!> the moving frame's term -tau T K0 T^T [omega]x of the damping force's derivative (it
!> varies with phi') is left to the simplified Newton, whose residual is exact.
!> No I/O; failures return codes.
module mechanical_system
  use ancf_kinds, only: dp
  use constraints, only: constraint_value
  use element_sets, only: element_set, set_slot, frame_omega
  use force_elements, only: force_element_slots
  use system_drives, only: drive_table, drive_at
  use system_constraints, only: constraint_table, evaluate_constraints
  use system_loads, only: load_set, vector_load_forces, vector_load_tangent, &
                          dead_moment_forces, dead_moment_energy, load_scale
  use system_force_elements, only: force_element_table, force_element_forces, &
                                   force_element_at
  use system_contact, only: contact_set, contact_pair, contact_state, contact_record, &
                            contact_forces, contact_step_limit
  use system_probes, only: probe_set, probe_values
  use system_iteration, only: iteration_matrix, policy_constant, policy_refactor, &
                              to_solver_frame, dof_frame, factorize_matrix
  use system_carry, only: carried_vectors
  use system_mass, only: mass_matrix, kinetic_energy
  use system_reduction, only: coordinate_reduction, to_full, to_reduced, reduce_tangent
  implicit none
  private
  public :: system_model, frame_def, contact_pair, contact_state
  public :: frame_rotations, internal_forces, column_forces, &
            external_forces, &
            refactorize, to_solver_frame, &
            frame_gradients, energies, probe_output, tangent_rotations, append_set, &
            tangent_frame_rates, damped_sets, force_element_reactions, contact_forces, &
            drive_step_work
  ! what the stepper asks of the system's contact (it uses no contact module itself)
  public :: contact_record, contact_step_limit
  public :: policy_constant, policy_refactor  ! (system_iteration's)

  !> energy(:) layout of an output row
  integer, parameter, public :: energy_kinetic = 1, energy_strain = 2, energy_loads = 3, &
                                energy_moment = 4, energy_total = 5, work_drive = 6, &
                                work_frame = 7, energy_contact = 8, work_contact_damping = 9, &
                                work_friction = 10, work_material_damping = 11, energy_count = 11
  !> work(:) layout of the accumulated works (powers integrated by the stepper)
  integer, parameter, public :: power_drive = 1, power_frame = 2, power_contact_damping = 3, &
                                power_friction = 4, power_material_damping = 5, power_count = 5

  !> A floating frame A(t) = Rot(axis, phi(t)) base about pivot (drive 0: A = base).
  type :: frame_def
    integer :: drive = 0
    real(dp) :: axis(3) = [0.0_dp, 0.0_dp, 1.0_dp]
    real(dp) :: base(3, 3) = reshape([1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, &
                                      0.0_dp, 1.0_dp], [3, 3])
    real(dp) :: pivot(3) = 0.0_dp
  end type frame_def

  !> The system: its dimensions (ndof independent coordinates e, nfull full coordinates q),
  !> element sets and frames, and one component per concern, each in its own module with
  !> the routines that own it.
  type :: system_model
    integer :: ndof = 0, nfull = 0
    type(set_slot), allocatable :: sets(:)             ! element sets of any family
    type(frame_def), allocatable :: frames(:)
    type(drive_table) :: drives                       ! the drive table (system_drives)
    type(mass_matrix) :: mass                         ! M and its forms (system_mass)
    type(coordinate_reduction) :: reduction           ! q = B e + q0 (system_reduction)
    type(load_set) :: loads                           ! forces and moments (system_loads)
    type(force_element_table) :: force_elements       ! (system_force_elements)
    type(constraint_table) :: constraints             ! with multipliers (system_constraints)
    type(contact_set) :: contact                      ! plate-plate contact (system_contact)
    type(probe_set) :: probes                         ! output points (system_probes)
    type(iteration_matrix) :: matrix                  ! S and its solver (system_iteration)
    type(carried_vectors) :: carry                    ! the carried matrix's (system_carry)
  end type system_model

contains

  !> Appends an element set of any family (moved into the system: set is deallocated on
  !> return); index: its 1-based position. The one append path of every set.
  subroutine append_set(sys, set, index)
    type(system_model), intent(inout) :: sys
    class(element_set), allocatable, intent(inout) :: set
    integer, intent(out) :: index
    type(set_slot), allocatable :: grown(:)
    integer :: s
    allocate (grown(size(sys%sets) + 1))
    do s = 1, size(sys%sets)
      call move_alloc(sys%sets(s)%item, grown(s)%item)
    end do
    call move_alloc(set, grown(size(grown))%item)
    call move_alloc(grown, sys%sets)
    index = size(sys%sets)
  end subroutine append_set

  !> Rotations A_f(t) (index 0: the identity) and rates phi_f'(t) of every frame. info = 5:
  !> a drive failed.
  subroutine frame_rotations(sys, t, rotations, rates, info)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: t
    real(dp), intent(out) :: rotations(3, 3, 0:size(sys%frames)), rates(0:size(sys%frames))
    integer, intent(out) :: info
    real(dp) :: phi, ddphi, k(3), skew(3, 3), turn(3, 3)
    integer :: f, i
    info = 0
    rotations = 0.0_dp
    rates = 0.0_dp
    do i = 1, 3
      rotations(i, i, 0) = 1.0_dp
    end do
    do f = 1, size(sys%frames)
      rotations(:, :, f) = sys%frames(f)%base
      if (sys%frames(f)%drive == 0) cycle
      call drive_at(sys%drives, sys%frames(f)%drive, t, &
                       phi, rates(f), ddphi, info)
      if (info /= 0) then
        info = 5
        return
      end if
      k = sys%frames(f)%axis / norm2(sys%frames(f)%axis)
      skew = reshape([0.0_dp, k(3), -k(2), -k(3), 0.0_dp, k(1), k(2), -k(1), 0.0_dp], [3, 3])
      turn = sin(phi) * skew + (1.0_dp - cos(phi)) * matmul(skew, skew)
      do i = 1, 3
        turn(i, i) = turn(i, i) + 1.0_dp
      end do
      rotations(:, :, f) = matmul(turn, sys%frames(f)%base)
    end do
  end subroutine frame_rotations

  !> The rotation each set's tangent is assembled with: its frame's, except in the constant
  !> policy, where a moving frame's sets are assembled in the frame itself (identity).
  pure function tangent_rotations(sys, rotations) result(out)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: rotations(:, :, 0:)
    real(dp) :: out(3, 3, 0:size(sys%frames))
    integer :: f
    out = rotations
    if (sys%matrix%policy /= policy_constant) return
    do f = 1, size(sys%frames)
      if (sys%frames(f)%drive /= 0) out(:, :, f) = rotations(:, :, 0)
    end do
  end function tangent_rotations

  !> The frame rates the tangent's damping terms use: each frame's, except in the constant
  !> policy, where the sets of a moving frame are assembled in the frame itself and the
  !> angular velocity's term is left out (0), as tangent_rotations does for the rotation.
  pure function tangent_frame_rates(sys, rates) result(out)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: rates(0:)
    real(dp) :: out(0:size(sys%frames))
    integer :: f
    out = rates
    if (sys%matrix%policy /= policy_constant) return
    do f = 1, size(sys%frames)
      if (sys%frames(f)%drive /= 0) out(f) = 0.0_dp
    end do
  end function tangent_frame_rates

  !> Whether any element set carries material damping (tau > 0).
  pure logical function damped_sets(sys)
    type(system_model), intent(in) :: sys
    integer :: s
    damped_sets = .false.
    do s = 1, size(sys%sets)
      if (sys%sets(s)%item%damping_time > 0.0_dp) damped_sets = .true.
    end do
  end function damped_sets

  !> The angular velocity of frame f at rate phi', in the rotation's frame (0 for no frame).
  pure function set_omega(sys, f, rotation, rate) result(omega_local)
    type(system_model), intent(in) :: sys
    integer, intent(in) :: f
    real(dp), intent(in) :: rotation(3, 3), rate
    real(dp) :: omega_local(3)
    omega_local = 0.0_dp
    if (f > 0) omega_local = frame_omega(rotation, sys%frames(f)%axis, rate)
  end function set_omega

  !> Elastic minus contact forces minus the dead moments (times load_factor), reduced: the
  !> configuration-dependent part of the residual at (e, e') and t; strain energy, contact
  !> potential, contact powers (damping, friction) and per-point records. With
  !> tangent_values (reduced pattern; tangent_rotation then required) the sets' tangents
  !> (FFR: in the tangent_rotation frames) plus
  !> velocity_factor times the contact Jacobian, reduced by the plan, are returned too.
  !> Damped sets add their damping force at e' with the frames' rates phi'_f (rates; 0 when
  !> absent) and their combined tangent dQ/dq + velocity_factor dQ/dq' (the FFR omega term
  !> with tangent_rates, by default rates).
  !> info = 6 (moment undefined), 7 (a plate normal vanished), 8 (contact search failed).
  subroutine internal_forces(sys, rotations, e, v, load_factor, velocity_factor, state, force, &
                             strain, contact_potential, contact_powers, records, info, &
                             tangent_rotation, tangent_values, rates, tangent_rates, full_out, t, &
                             force_time, full_work)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: rotations(:, :, 0:), e(:), v(:), load_factor, velocity_factor
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: force(:), strain, contact_potential, contact_powers(2)
    real(dp), intent(out) :: records(:, :)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: tangent_rotation(:, :, 0:)
    real(dp), intent(out), optional :: tangent_values(:)
    real(dp), intent(in), optional :: rates(0:), tangent_rates(0:)
    !> the same forces in the full coordinates q (before B^T), for the joint reactions
    real(dp), intent(out), optional :: full_out(:)
    real(dp), intent(in), optional :: t  ! with the tangent: the point loads' Jacobian at t
    !> the time of the force elements' drives (every caller passes it; 0 when absent)
    real(dp), intent(in), optional :: force_time
    !> work arrays of the caller (nfull, 2) for q and the full force: no heap arrays per call
    real(dp), intent(out), optional, target :: full_work(:, :)
    real(dp), allocatable, target :: own_full(:, :)
    real(dp), pointer :: e_full(:), full_force(:)
    real(dp), allocatable :: v_full(:), values_full(:)
    real(dp) :: set_energy, rate, tangent_rate
    real(dp) :: fel_powers(2)
    logical :: want_tangent, done
    integer :: s, f
    want_tangent = present(tangent_values)
    ! the force alone of undamped sets on a one-to-one selection, nothing else acting: each
    ! set straight on the independent coordinates (selected_forces), without q, the full
    ! force and B^T (the same numbers)
    done = .not. want_tangent .and. sys%reduction%select_one_to_one .and. &
           sys%contact%npoint == 0 .and. sys%force_elements%nfel == 0 .and. .not. present(full_out)
    if (done .and. allocated(sys%loads%moment_magnitude)) &
      done = size(sys%loads%moment_magnitude) == 0
    if (done) then
      force = 0.0_dp
      strain = 0.0_dp
      do s = 1, size(sys%sets)
        call sys%sets(s)%item%selected_forces(sys%reduction%select, sys%reduction%offset, e, &
                                              force, set_energy, info, done)
        if (.not. done .or. info /= 0) exit
        strain = strain + set_energy
      end do
      if (done .and. info /= 0) return
      if (done) then
        contact_potential = 0.0_dp
        contact_powers = 0.0_dp
        return
      end if
      info = 0   ! (a set without the pass: the general path below, from the start)
    end if
    if (present(full_work)) then
      e_full => full_work(:, 1)
      full_force => full_work(:, 2)
    else
      allocate (own_full(sys%nfull, 2))
      e_full => own_full(:, 1)
      full_force => own_full(:, 2)
    end if
    call to_full(sys%reduction, e, .true., e_full)
    full_force = 0.0_dp
    strain = 0.0_dp
    if (want_tangent) then
      allocate (values_full(size(sys%reduction%full_col)))
      values_full = 0.0_dp
    end if
    if (sys%contact%npoint > 0 .or. damped_sets(sys) .or. sys%force_elements%nfel > 0) then
      allocate (v_full(sys%nfull))
      call to_full(sys%reduction, v, .false., v_full)
    end if
    if (sys%force_elements%nfel > 0) then
      if (want_tangent) then
        call force_element_forces(sys%force_elements, sys%drives, sys%reduction, &
                                  merge_time(force_time), e_full, v_full, velocity_factor, &
                                  full_force, set_energy, fel_powers, info, values_full)
      else
        call force_element_forces(sys%force_elements, sys%drives, sys%reduction, &
                                  merge_time(force_time), e_full, v_full, velocity_factor, &
                                  full_force, set_energy, fel_powers, info)
      end if
      if (info /= 0) return
      strain = strain + set_energy
    end if
    do s = 1, size(sys%sets)
      f = sys%sets(s)%item%frame
      if (sys%sets(s)%item%damping_time > 0.0_dp) then
        rate = 0.0_dp
        if (present(rates)) rate = rates(f)
        tangent_rate = rate
        if (present(tangent_rates)) tangent_rate = tangent_rates(f)
        if (want_tangent) then
          call sys%sets(s)%item%forces(rotations(:, :, f), e_full, full_force, set_energy, info, &
                          values_full, tangent_rotation(:, :, f), v=v_full, &
                          omega_local=set_omega(sys, f, rotations(:, :, f), rate), &
                          rate_factor=velocity_factor, &
                          tangent_omega=set_omega(sys, f, tangent_rotation(:, :, f), tangent_rate))
        else
          call sys%sets(s)%item%forces(rotations(:, :, f), e_full, full_force, set_energy, info, &
                          v=v_full, omega_local=set_omega(sys, f, rotations(:, :, f), rate))
        end if
      else if (want_tangent) then
        call sys%sets(s)%item%forces(rotations(:, :, f), e_full, full_force, set_energy, info, &
                        values_full, tangent_rotation(:, :, f))
      else
        call sys%sets(s)%item%forces(rotations(:, :, f), e_full, full_force, set_energy, info)
      end if
      if (info /= 0) return
      strain = strain + set_energy
    end do
    contact_potential = 0.0_dp
    contact_powers = 0.0_dp
    if (sys%contact%npoint > 0) then
      call contact_forces(sys%contact, sys%reduction, e_full, v_full, velocity_factor, state, &
                          full_force, records, contact_potential, contact_powers, info, &
                          values_full)
      if (info /= 0) return
    end if
    call dead_moment_forces(sys%loads, e_full, load_factor, full_force, info)
    if (info /= 0) return
    if (present(full_out)) full_out = full_force
    call to_reduced(sys%reduction, full_force, force)
    if (.not. want_tangent) return
    if (present(t) .and. sys%loads%nvload > 0) then
      call vector_load_tangent(sys%loads, sys%drives, sys%reduction, t, e_full, load_factor, &
                               values_full, info)
      if (info /= 0) return
    end if
    call reduce_tangent(sys%reduction, values_full, tangent_values)
  end subroutine internal_forces

  !> Configuration-independent external loads at t, times load_factor (the fixed loads at
  !> their value): the constant loads plus the driven forces. info = 5 when a drive fails.
  !> With e, the driven and follower point loads at e are added (vector_load_forces).
  subroutine external_forces(sys, t, load_factor, force, info, e)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: t, load_factor
    real(dp), intent(out) :: force(:)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: e(:)
    real(dp) :: phi, dphi, ddphi
    real(dp), allocatable :: e_full(:), full_force(:), reduced(:)
    integer :: d
    info = 0
    force = load_factor * sys%loads%constant_force &
            + (1.0_dp - load_factor) * sys%loads%fixed_force
    if (present(e) .and. sys%loads%nvload > 0) then
      allocate (e_full(sys%nfull), full_force(sys%nfull), reduced(sys%ndof))
      call to_full(sys%reduction, e, .true., e_full)
      full_force = 0.0_dp
      call vector_load_forces(sys%loads, sys%drives, t, e_full, load_factor, full_force, info)
      if (info /= 0) return
      call to_reduced(sys%reduction, full_force, reduced)
      force = force + reduced
    end if
    do d = 1, size(sys%loads%force_drive)
      call drive_at(sys%drives, sys%loads%force_drive(d), t, &
                       phi, dphi, ddphi, info)
      if (info /= 0) then
        info = 5
        return
      end if
      force = force + load_scale(sys%loads%force_fixed(d), load_factor) * phi &
                      * sys%loads%force_vectors(:, d)
    end do
  end subroutine external_forces

  !> The time an internal-force evaluation hands the force elements (0 when not given:
  !> only systems without driven force elements are evaluated so).
  !> internal_forces' full force (its full_out at load factor 1, velocity factor 0, rates
  !> and force time t) at the full coordinates marked in wanted (nfull), bit for bit: the
  !> sets' elements that touch a wanted coordinate (element_set column_forces), the whole
  !> contact (its search from state's guesses, records as internal_forces'), force
  !> elements and dead moments; the other entries of full_force hold partial sums. The
  !> answers' residual at a few coordinates (row_answers) without every element's force.
  !> info as internal_forces.
  subroutine column_forces(sys, rotations, rates, e, v, t, wanted, state, full_force, records, &
                           info)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: rotations(:, :, 0:), rates(0:), e(:), v(:), t
    logical, intent(in) :: wanted(:)
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: full_force(:), records(:, :)
    integer, intent(out) :: info
    real(dp), allocatable :: e_full(:), v_full(:), no_values(:)
    real(dp) :: energy, powers(2)
    integer :: s, f
    allocate (e_full(sys%nfull))
    call to_full(sys%reduction, e, .true., e_full)
    full_force = 0.0_dp
    info = 0
    if (sys%contact%npoint > 0 .or. damped_sets(sys) .or. sys%force_elements%nfel > 0) then
      allocate (v_full(sys%nfull))
      call to_full(sys%reduction, v, .false., v_full)
    end if
    if (sys%force_elements%nfel > 0) then
      call force_element_forces(sys%force_elements, sys%drives, sys%reduction, t, e_full, v_full, &
                                0.0_dp, full_force, energy, powers, info)
      if (info /= 0) return
    end if
    do s = 1, size(sys%sets)
      f = sys%sets(s)%item%frame
      if (sys%sets(s)%item%damping_time > 0.0_dp) then
        call sys%sets(s)%item%column_forces(rotations(:, :, f), e_full, wanted, full_force, info, &
                                            v_full, set_omega(sys, f, rotations(:, :, f), rates(f)))
      else
        call sys%sets(s)%item%column_forces(rotations(:, :, f), e_full, wanted, full_force, info)
      end if
      if (info /= 0) return
    end do
    if (sys%contact%npoint > 0) then
      call contact_forces(sys%contact, sys%reduction, e_full, v_full, 0.0_dp, state, full_force, &
                          records, energy, powers, info, no_values)
      if (info /= 0) return
    end if
    call dead_moment_forces(sys%loads, e_full, 1.0_dp, full_force, info)
  end subroutine column_forces

  pure real(dp) function merge_time(time)
    real(dp), intent(in), optional :: time
    merge_time = 0.0_dp
    if (present(time)) merge_time = time
  end function merge_time

  !> The reactions of every force element at (e, e', t) (reduced coordinates): per element
  !> the force and moment body1 exerts on body2 (global) and the axial force (tension
  !> positive), force_elements' layout (7, nfel). info = 5 or 10 (force_element_at).
  subroutine force_element_reactions(sys, t, e, v, reactions, info)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: t, e(:), v(:)
    real(dp), intent(out) :: reactions(:, :)
    integer, intent(out) :: info
    real(dp), allocatable :: e_full(:), v_full(:), force(:, :), stiffness(:, :, :, :), &
                             damping(:, :, :, :)
    real(dp) :: energy, dissipation, power
    integer :: l, ns
    info = 0
    allocate (e_full(sys%nfull), v_full(sys%nfull))
    call to_full(sys%reduction, e, .true., e_full)
    call to_full(sys%reduction, v, .false., v_full)
    do l = 1, sys%force_elements%nfel
      ns = force_element_slots(sys%force_elements%kind(l))
      allocate (force(3, ns), stiffness(3, ns, 3, ns), damping(3, ns, 3, ns))
      call force_element_at(sys%force_elements, sys%drives, l, t, e_full, v_full, force, &
                            stiffness, damping, energy, dissipation, power, reactions(:, l), info)
      if (info /= 0) return
      deallocate (force, stiffness, damping)
    end do
  end subroutine force_element_reactions

  !> W(3 nblock, ncon): the solver-frame components of Phi_e^T at the touched blocks.
  pure subroutine frame_gradients(sys, rotations, gradients, w)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: rotations(:, :, 0:), gradients(:, :)
    real(dp), intent(out) :: w(:, :)
    integer :: c, s, k, dof, b, comp, f, i
    real(dp) :: g
    w = 0.0_dp
    do c = 1, sys%constraints%ncon
      do s = 1, 6
        do k = sys%constraints%term_ptr(6 * (c - 1) + s), &
               sys%constraints%term_ptr(6 * (c - 1) + s + 1) - 1
          dof = sys%constraints%term_dof(k)
          g = gradients(s, c) * sys%constraints%term_coef(k)
          do b = 1, size(sys%matrix%block_first)  ! the first block holding dof
            if (dof >= sys%matrix%block_first(b) .and. dof <= sys%matrix%block_first(b) + 2) exit
          end do
          comp = dof - sys%matrix%block_first(b) + 1
          f = dof_frame(sys%matrix, dof)
          do i = 1, 3  ! (written out: the strided row slice cost a third of the Schur set-up)
            w(3 * (b - 1) + i, c) = w(3 * (b - 1) + i, c) + rotations(comp, i, f) * g
          end do
        end do
      end do
    end do
  end subroutine frame_gradients

  !> Factorizes S = beta' M + B^T (K + c_v C_c) B at (e, e') (K in the policy's frames) and
  !> computes the flexibility S^{-1} E_c and E_c^T S^{-1} E_c for the Schur complement; the
  !> internal force at (e, e') comes out of the same pass (force, strain), with the number
  !> of active contact points. info: 3 (solver failure, detail = its code) or the
  !> internal_forces codes.
  subroutine refactorize(sys, beta_prime, velocity_factor, rotations, e, v, state, force, &
                         strain, active, info, detail, rates, t)
    type(system_model), intent(inout) :: sys
    real(dp), intent(in) :: beta_prime, velocity_factor, rotations(:, :, 0:), e(:), v(:)
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: force(:), strain
    integer, intent(out) :: active, info, detail
    real(dp), intent(in), optional :: rates(0:)  ! the frames' phi' (material damping)
    real(dp), intent(in), optional :: t          ! the time (the point loads' Jacobian)
    real(dp), allocatable :: values(:), records(:, :)
    real(dp) :: potential, powers(2), frame_rates(0:size(sys%frames))
    detail = 0
    allocate (values(size(sys%matrix%mass_pattern)), &
              records(contact_record, max(1, sys%contact%npoint)))
    frame_rates = 0.0_dp
    if (present(rates)) frame_rates = rates
    call internal_forces(sys, rotations, e, v, 1.0_dp, velocity_factor, state, force, strain, &
                         potential, powers, records, info, tangent_rotations(sys, rotations), &
                         values, frame_rates, tangent_frame_rates(sys, frame_rates), t=t, &
                         force_time=t)
    if (info /= 0) return
    active = 0
    if (sys%contact%npoint > 0) active = count(records(1, 1:sys%contact%npoint) > 0.0_dp)
    call factorize_matrix(sys%matrix, sys%ndof, beta_prime, values, info, detail)
  end subroutine refactorize

  !> Strain energy, the load potentials and the powers of the moving frames (FFR sets), of
  !> the driven point loads and of the cylinders at (e, e', t); contact potential, powers
  !> and records; the constraint violation max |Phi|. (The driven constraints' and driven
  !> forces' work is booked per step: drive_step_work.)
  !> full_work (optional, nfull; with phi_work (ncon) and gradients_work (6, ncon)): work
  !> arrays of the caller, full_work returning the full coordinates q of e (for
  !> probe_output) - no heap arrays per output row.
  subroutine energies(sys, rotations, rates, e, v, lam, t, state, strain, powers, &
                      contact_potential, violation, records, info, full_work, phi_work, &
                      gradients_work, constraints_known)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: rotations(:, :, 0:), rates(0:), e(:), v(:), lam(:), t
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: strain, powers(power_count), contact_potential, violation
    real(dp), intent(out) :: records(:, :)
    integer, intent(out) :: info
    real(dp), intent(inout), optional, target :: full_work(:), phi_work(:), gradients_work(:, :)
    !> .true.: phi_work and gradients_work hold evaluate_constraints(sys, e, t) already (the
    !> stepper's check of an accepted state), not evaluated again
    logical, intent(in), optional :: constraints_known
    real(dp) :: set_energy, set_power, dissipation
    logical :: known
    real(dp) :: fel_powers(2)
    real(dp), allocatable, target :: own_full(:), own_phi(:), own_gradients(:, :)
    real(dp), allocatable :: v_full(:), unused(:), values_unused(:)
    real(dp), pointer :: e_full(:), phi(:), gradients(:, :)
    integer :: s, f
    if (present(full_work)) then
      e_full => full_work
      phi => phi_work
      gradients => gradients_work
    else
      allocate (own_full(sys%nfull), own_phi(sys%constraints%ncon), &
                own_gradients(6, sys%constraints%ncon))
      e_full => own_full
      phi => own_phi
      gradients => own_gradients
    end if
    known = .false.
    if (present(constraints_known) .and. present(full_work)) known = constraints_known
    if (known) then
      info = 0
    else
      call evaluate_constraints(sys%constraints, sys%drives, sys%ndof, e, t, phi, gradients, info)
      if (info /= 0) return
    end if
    violation = 0.0_dp
    if (sys%constraints%ncon > 0) violation = maxval(abs(phi))
    powers = 0.0_dp
    ! the driven constraints and the driven forces phi_d(t) f_d do their work per step
    ! (drive_step_work, the integrator's own discrete identity), not here as powers
    call to_full(sys%reduction, e, .true., e_full)
    if (sys%contact%npoint > 0 .or. damped_sets(sys) .or. sys%force_elements%nfel > 0 .or. &
        sys%loads%nvload > 0) then
      allocate (v_full(sys%nfull))
      call to_full(sys%reduction, v, .false., v_full)
    end if
    strain = 0.0_dp
    if (sys%loads%nvload > 0) then  ! the driven and follower point loads and a rigid body's dead
      ! moments have no potential: their power Q . q' is a work (of the drives)
      allocate (unused(sys%nfull))
      unused = 0.0_dp
      call vector_load_forces(sys%loads, sys%drives, t, e_full, 1.0_dp, unused, info)
      if (info /= 0) return
      powers(power_drive) = powers(power_drive) + dot_product(unused, v_full)
      deallocate (unused)
    end if
    ! potential, dissipation (a lost work) and the cylinders' drives
    if (sys%force_elements%nfel > 0) then
      allocate (unused(sys%nfull))
      unused = 0.0_dp
      call force_element_forces(sys%force_elements, sys%drives, sys%reduction, t, e_full, &
                                v_full, 0.0_dp, unused, set_energy, fel_powers, info)
      if (info /= 0) return
      deallocate (unused)
      strain = strain + set_energy
      powers(power_material_damping) = powers(power_material_damping) - fel_powers(1)
      powers(power_drive) = powers(power_drive) + fel_powers(2)
    end if
    do s = 1, size(sys%sets)
      f = sys%sets(s)%item%frame
      if (sys%sets(s)%item%damping_time > 0.0_dp) then
        ! the dissipated power is lost (a negative work); an FFR set's frame power includes
        ! that of its damping force
        call sys%sets(s)%item%energy_power(rotations(:, :, f), sys_axis(sys, f), rates(f), &
                              e_full, set_energy, set_power, info, v_full, dissipation)
        powers(power_material_damping) = powers(power_material_damping) - dissipation
      else
        call sys%sets(s)%item%energy_power(rotations(:, :, f), sys_axis(sys, f), rates(f), &
                              e_full, set_energy, set_power, info)
      end if
      if (info /= 0) return
      strain = strain + set_energy
      powers(power_frame) = powers(power_frame) + set_power
    end do
    contact_potential = 0.0_dp
    if (sys%contact%npoint > 0) then
      allocate (unused(sys%nfull))
      unused = 0.0_dp
      call contact_forces(sys%contact, sys%reduction, e_full, v_full, 0.0_dp, state, unused, &
                          records, contact_potential, powers(power_contact_damping:power_friction), &
                          info, values_unused)
    end if
  end subroutine energies

  !> The drives' work over one step from (t0, e0, lambda0) to (t1, e1, lambda1), booked as
  !> the integrator's own discrete energy identity books it (docs/theory.md section 7):
  !> the driven constraints' -1/2 (lambda0 + lambda1) . [Phi(e1, t1) - Phi(e1, t0)] (the
  !> increment of the constraints' time part, the same for any e: the time part of every
  !> kind is additive, constraint_value) and the driven forces' 1/2 (phi_d(t0) + phi_d(t1))
  !> f_d . (e1 - e0). For Newmark with constant constraint gradients both are the
  !> constraint and load terms of the step's kinetic-energy change exactly; the trapezoid
  !> of the pointwise powers -lambda Phi_t and phi_d f_d . e' missed it by O(h^2) (3 h^2 J
  !> on a 2 kg slide driven 0.1 m in 0.2 s). Zero, exactly, without a drive. info 5: a
  !> drive failed.
  subroutine drive_step_work(sys, t0, t1, e0, e1, lam0, lam1, work, info)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: t0, t1, e0(:), e1(:), lam0(:), lam1(:)
    real(dp), intent(out) :: work
    integer, intent(out) :: info
    real(dp) :: phi0, phi1, unused_rate, unused_accel, origin(6), before, after
    integer :: c, k
    work = 0.0_dp
    info = 0
    origin = 0.0_dp
    do c = 1, sys%constraints%ncon
      if (sys%constraints%drive(c) == 0) cycle
      call drive_ends(sys%constraints%drive(c))
      if (info /= 0) return
      before = constraint_value(sys%constraints%kind(c), .true., sys%constraints%params(:, c), &
                                origin, phi0, cos(phi0), sin(phi0))
      after = constraint_value(sys%constraints%kind(c), .true., sys%constraints%params(:, c), &
                               origin, phi1, cos(phi1), sin(phi1))
      work = work - 0.5_dp * (lam0(c) + lam1(c)) * (after - before)
    end do
    do c = 1, size(sys%loads%force_drive)
      call drive_ends(sys%loads%force_drive(c))
      if (info /= 0) return
      do k = 1, size(e0)  ! (a loop: e1 - e0 would make a temporary)
        work = work + 0.5_dp * (phi0 + phi1) * sys%loads%force_vectors(k, c) * (e1(k) - e0(k))
      end do
    end do
  contains
    !> The drive's values at the step's ends, phi0 at t0 and phi1 at t1 (info 5: failed).
    subroutine drive_ends(drive)
      integer, intent(in) :: drive
      call drive_at(sys%drives, drive, t0, phi0, &
                       unused_rate, unused_accel, info)
      if (info == 0) call drive_at(sys%drives, drive, &
                                      t1, phi1, unused_rate, unused_accel, info)
      if (info /= 0) info = 5
    end subroutine drive_ends
  end subroutine drive_step_work

  pure function sys_axis(sys, f) result(axis)
    type(system_model), intent(in) :: sys
    integer, intent(in) :: f
    real(dp) :: axis(3)
    axis = [0.0_dp, 0.0_dp, 1.0_dp]
    if (f > 0) axis = sys%frames(f)%axis
  end function sys_axis

  !> One output row's probes (positions), deflections (A_f^T (p - pivot_f) - reference) and
  !> energies (kinetic, strain, loads, moments, total, works, contact).
  !> known_full (optional): the full coordinates q of e (energies' full_work), with
  !> ndof_work (ndof) a work array of the caller - no heap arrays per output row.
  !> The loads' potential is that of the constant loads alone: a driven force has none (its
  !> power phi(t) f . e' is a work of the drives, energies), so a force released at t = 0
  !> leaves the strain it held in the initial total instead of a jump of -f . e in it.
  subroutine probe_output(sys, rotations, e, v, work, strain, contact_potential, probe, &
                          deflection, energy, info, known_full, ndof_work)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: rotations(:, :, 0:), e(:), v(:), work(:), strain
    real(dp), intent(in) :: contact_potential
    real(dp), intent(out) :: probe(:, :), deflection(:, :), energy(:)
    integer, intent(out) :: info
    real(dp), intent(in), optional, target :: known_full(:)
    real(dp), intent(out), optional, target :: ndof_work(:)
    real(dp), allocatable, target :: own_full(:), own_ndof(:)
    real(dp), pointer :: e_full(:), mv(:)
    real(dp) :: pivots(3, 0:size(sys%frames))
    integer :: f
    info = 0
    if (present(known_full)) then
      e_full => known_full
      mv => ndof_work
    else
      allocate (own_full(sys%nfull), own_ndof(sys%ndof))
      call to_full(sys%reduction, e, .true., own_full)
      e_full => own_full
      mv => own_ndof
    end if
    pivots(:, 0) = 0.0_dp
    do f = 1, size(sys%frames)
      pivots(:, f) = sys%frames(f)%pivot
    end do
    call probe_values(sys%probes, e_full, rotations, pivots, probe, deflection)
    energy = 0.0_dp
    call kinetic_energy(sys%mass, v, mv, energy(energy_kinetic))
    energy(energy_strain) = strain
    energy(energy_loads) = -dot_product(sys%loads%constant_force, e)
    energy(energy_moment) = dead_moment_energy(sys%loads, e_full)
    energy(energy_contact) = contact_potential
    energy(energy_total) = sum(energy(energy_kinetic:energy_moment)) + contact_potential
    energy(work_drive) = work(power_drive)
    energy(work_frame) = work(power_frame)
    energy(work_contact_damping) = work(power_contact_damping)
    energy(work_friction) = work(power_friction)
    energy(work_material_damping) = work(power_material_damping)
  end subroutine probe_output

end module mechanical_system
