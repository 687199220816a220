!> Implicit time stepping of constrained ANCF models (seed 000, eqs. 58-62; seed 003 eq. 38):
!>   M q'' + Q_el(q, t) = Q(q) + Phi_q^T lambda,   Phi(q, t) = 0,
!> by the generalized-alpha method (Chung-Hulbert, in the form of Arnold and Bruels for
!> constrained systems) with Newmark (alpha_m = alpha_f = 0) as its special case:
!>   (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) q''_{n+1} + alpha_f q''_n,
!>   q_{n+1} = q_n + h v_n + h^2 ((1/2 - beta) a_n + beta a_{n+1}),
!>   v_{n+1} = v_n + h ((1 - gamma) a_n + gamma a_{n+1}),
!> Newton on (q_{n+1}, lambda_{n+1}) with the iteration matrix beta' M + K, beta' = (1 -
!> alpha_m) / (beta h^2 (1 - alpha_f)).
!>
!> Three elastic models share the driver:
!> * ANCF-FFR (Q_el = T K0 (T^T q - e0), frame A(t) = Rot(axis, phi(t)) A_base): every 3 x 3
!>   block of M is a scalar times I3, so beta' M + T K0 T^T = T S T^T with the constant
!>   S = beta' M + K0, factorized once per run;
!> * large deformation (beam_nonlinear, and the thin plate of plate_element): S = beta' M +
!>   K_t(q) is refactorized once per step at the predicted state and reused by the step's
!>   iterations (modified Newton), and again at the current iterate whenever a correction
!>   is not below half the previous one (strongly nonlinear steps).
!> The multipliers enter through a Schur complement built from the flexibility S^{-1} E_c at
!> the 3-vectors the constraints touch (E_c: their unit vectors in the frame), so a Newton
!> correction costs one back-substitution plus small dense algebra (LAPACK dgesv). The
!> Jacobians of the moment and of lambda . Phi_qq are left out of the iteration matrix; the
!> residual is exact. A correction with max |dq| <= tol * length_scale ends the step.
!> Linear constraints (seed 003 eqs. 34-37: hinges to ANCF reference nodes, fixed or tied
!> coordinates) are eliminated before the solve: the stepper's unknowns are the independent
!> coordinates q_i, the elements see q = B q_i + q0, forces are reduced by B^T and the
!> iteration matrix by a precomputed plan of B^T S B (Python builds B, the plan, and
!> M_ii = B^T M B). Leaf contact (leaf_contact) adds velocity-dependent forces; its Jacobian
!> enters the iteration matrix with d q'/d q = gamma / (beta h).
!> No I/O; failures return codes (see integrator_chunk).
module time_integrator
  use ancf_kinds, only: dp
  use drives, only: drive_eval
  use constraints, only: constraint_eval
  use ffr_elastic, only: ffr_force
  use beam_nonlinear, only: nonlinear_element
  use beam_structural, only: structural_element
  use plate_element, only: plate_forces
  use section_moment, only: moment_force, moment_angle
  use sparse_pattern, only: pattern_assemble
  use sparse_direct, only: solver_solve, solver_factorize
  use leaf_contact, only: contact_assemble, cp_count, contact_counters, contact_record
  implicit none
  private
  public :: mechanical_system, integrator_settings, integrator_chunk, frame_rotation, csr_matvec, &
            contact_state
  public :: energy_kinetic, energy_strain, energy_loads, energy_moment, energy_total, &
            work_drive, work_frame, energy_contact, work_damping, work_friction, energy_count

  integer, parameter :: energy_kinetic = 1, energy_strain = 2, energy_loads = 3, &
                        energy_moment = 4, energy_total = 5, work_drive = 6, work_frame = 7, &
                        energy_contact = 8, work_damping = 9, work_friction = 10, &
                        energy_count = 10
  integer, parameter, public :: formulation_ffr = 0, formulation_nonlinear = 1, &
                                formulation_plate = 2, formulation_structural = 3

  !> The model, as the stepper reads it (never changed by a step).
  type :: mechanical_system
    integer :: formulation = formulation_ffr
    integer :: ndof = 0, nel = 0, ncon = 0, nmoment = 0, nblock = 0, nprobe = 0
    integer :: element_dofs = 24                       ! beam 24, plate 36
    integer, allocatable :: dofs(:, :)                 ! (element_dofs, nel)
    real(dp), allocatable :: stiffness0(:, :, :)       ! FFR: (24, 24, nel)
    real(dp), allocatable :: e0_frame(:)
    integer, allocatable :: mass_row_ptr(:), mass_col(:)
    real(dp), allocatable :: mass_values(:)
    real(dp), allocatable :: constant_force(:)         ! gravity, tip loads
    integer, allocatable :: moment_dofs(:, :)          ! (3, nmoment) director dofs
    real(dp), allocatable :: moment_axis(:, :), moment_magnitude(:), moment_reference(:, :)
    integer, allocatable :: con_ints(:, :), drive_kinds(:)
    real(dp), allocatable :: con_reals(:, :), drive_params(:, :)
    integer :: frame_drive = 0                         ! 0: A = A_base
    real(dp) :: frame_axis(3) = [0.0_dp, 0.0_dp, 1.0_dp], frame_base(3, 3)
    integer :: solver_handle = 0                       ! S (FFR: factorized once by Python)
    integer, allocatable :: block_first(:)             ! (nblock) first dof of touched 3-vectors
    real(dp), allocatable :: flexibility(:, :)         ! FFR: S^{-1} E_c (ndof, 3 nblock)
    real(dp), allocatable :: flexibility_cc(:, :)      ! FFR: E_c^T S^{-1} E_c
    ! large deformation: Gauss data, the pattern S is assembled on, M on that pattern
    real(dp) :: youngs = 0.0_dp, poisson = 0.0_dp
    real(dp), allocatable :: gauss_gradients(:, :, :, :), gauss_weights(:, :)
    ! large deformation, 'cubic' bending (beam_structural): strain forms per element
    real(dp), allocatable :: structural_forms(:, :, :, :), structural_strain0(:, :)
    real(dp), allocatable :: structural_stiffness(:, :)
    ! thin plate (plate_element): reference data at the Gauss points, thickness
    real(dp), allocatable :: plate_derivs(:, :, :, :), plate_frame(:, :, :, :)
    real(dp), allocatable :: plate_curvature0(:, :, :), plate_weights(:, :)
    real(dp) :: thickness = 0.0_dp
    integer, allocatable :: scatter_map(:, :, :)
    real(dp), allocatable :: mass_pattern(:)
    integer, allocatable :: probe_dofs(:, :)           ! (element_dofs, nprobe)
    real(dp), allocatable :: probe_shape(:, :)         ! (element_dofs / 3, nprobe)
    real(dp), allocatable :: probe_reference(:, :)     ! (3, nprobe) rigid position in frame
    ! linear-constraint elimination q = B q_i + q0 (reduced = .false.: B = I, q0 = 0);
    ! dofs, scatter_map, probe_dofs and the contact data index the full q
    logical :: reduced = .false.
    integer :: nfull = 0
    integer, allocatable :: reduction_ptr(:), reduction_col(:)      ! B, CSR (nfull rows)
    real(dp), allocatable :: reduction_values(:), reduction_offset(:)
    integer, allocatable :: plan_source(:), plan_target(:)         ! B^T S B on the pattern
    real(dp), allocatable :: plan_coef(:)
    integer, allocatable :: full_row_ptr(:), full_col(:)           ! pattern of the full S
    ! time-dependent load Q(t) = constant_force + phi(t) drive_force (force_drive = 0: none)
    integer :: force_drive = 0
    real(dp), allocatable :: drive_force(:)
    ! leaf contact (ncontact = 0: never evaluated)
    integer :: ncontact = 0
    integer, allocatable :: contact_grid(:, :), contact_element(:)
    real(dp), allocatable :: contact_local(:, :), element_size(:, :)
    real(dp) :: contact_params(cp_count) = 0.0_dp
  end type mechanical_system

  !> What the contact evaluation carries from iteration to iteration and step to step.
  type :: contact_state
    real(dp), allocatable :: guesses(:, :)     ! (2, ncontact) leaf-level projections
    integer :: counts(contact_counters) = 0
  end type contact_state

  type :: integrator_settings
    real(dp) :: h, beta = 0.25_dp, gamma = 0.5_dp, alpha_m = 0.0_dp, alpha_f = 0.0_dp
    real(dp) :: tol = 1e-10_dp, length_scale = 1.0_dp
    integer :: max_newton = 10
  end type integrator_settings

contains

  !> A(t) and phi_frame'(t).
  subroutine frame_rotation(sys, t, rotation, rate, info)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: t
    real(dp), intent(out) :: rotation(3, 3), rate
    integer, intent(out) :: info
    real(dp) :: phi, ddphi, k(3), skew(3, 3), turn(3, 3)
    integer :: i
    info = 0
    rate = 0.0_dp
    rotation = sys%frame_base
    if (sys%frame_drive == 0) return
    call drive_eval(sys%drive_kinds(sys%frame_drive), sys%drive_params(:, sys%frame_drive), t, &
                    phi, rate, ddphi, info)
    if (info /= 0) return
    k = sys%frame_axis / norm2(sys%frame_axis)
    skew = reshape([0.0_dp, k(3), -k(2), -k(3), 0.0_dp, k(1), k(2), -k(1), 0.0_dp], [3, 3])
    turn = sin(phi) * skew + (1.0_dp - cos(phi)) * matmul(skew, skew)
    do i = 1, 3
      turn(i, i) = turn(i, i) + 1.0_dp
    end do
    rotation = matmul(turn, sys%frame_base)
  end subroutine frame_rotation

  !> y = M x for the CSR mass matrix (1-based).
  pure subroutine csr_matvec(row_ptr, col, values, x, y)
    integer, intent(in) :: row_ptr(:), col(:)
    real(dp), intent(in) :: values(:), x(:)
    real(dp), intent(out) :: y(:)
    integer :: i, k
    real(dp) :: total
    do i = 1, size(row_ptr) - 1
      total = 0.0_dp
      do k = row_ptr(i), row_ptr(i + 1) - 1
        total = total + values(k) * x(col(k))
      end do
      y(i) = total
    end do
  end subroutine csr_matvec

  !> T^T x (to the frame) or T x (to the global frame), 3-vector by 3-vector.
  pure subroutine rotate_all(rotation, x, transpose_first, y)
    real(dp), intent(in) :: rotation(3, 3), x(:)
    logical, intent(in) :: transpose_first
    real(dp), intent(out) :: y(:)
    integer :: b, i
    ! written out: a generic matmul call per 3-vector cost a tenth of a step
    if (transpose_first) then
      do b = 0, size(x) / 3 - 1
        do i = 1, 3
          y(3 * b + i) = rotation(1, i) * x(3 * b + 1) + rotation(2, i) * x(3 * b + 2) &
                         + rotation(3, i) * x(3 * b + 3)
        end do
      end do
    else
      do b = 0, size(x) / 3 - 1
        do i = 1, 3
          y(3 * b + i) = rotation(i, 1) * x(3 * b + 1) + rotation(i, 2) * x(3 * b + 2) &
                         + rotation(i, 3) * x(3 * b + 3)
        end do
      end do
    end if
  end subroutine rotate_all

  !> rotate_all for FFR (S lives in the floating frame); a copy for large deformation, whose
  !> S lives in the global frame (and whose reduced vectors need not hold whole 3-vectors).
  pure subroutine to_solver_frame(sys, rotation, x, transpose_first, y)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: rotation(3, 3), x(:)
    logical, intent(in) :: transpose_first
    real(dp), intent(out) :: y(:)
    if (sys%formulation == formulation_ffr) then
      call rotate_all(rotation, x, transpose_first, y)
    else
      y = x
    end if
  end subroutine to_solver_frame

  !> Constraint values and gradients at (e, t) (velocities only feed terms not used here).
  !> info = 5 when a constraint or drive cannot be evaluated.
  subroutine evaluate_constraints(sys, e, t, phi, gradients, info)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: e(:), t
    real(dp), intent(out) :: phi(:), gradients(:, :)
    integer, intent(out) :: info
    real(dp) :: hessians(6, 6, sys%ncon), phi_t(sys%ncon), phi_tt(sys%ncon), gamma(sys%ncon)
    call constraint_eval(sys%ncon, sys%con_ints, sys%con_reals, size(sys%drive_kinds), &
                         sys%drive_kinds, sys%drive_params, sys%ndof, e, e, t, phi, gradients, &
                         hessians, phi_t, phi_tt, gamma, info)
    if (info /= 0) info = 5
  end subroutine evaluate_constraints

  !> Elastic force and strain energy of the formulation (FFR with the frame rotation).
  !> info = 7: a plate element's normal vanished.
  subroutine elastic_force(sys, rotation, e, force, strain, info)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: rotation(3, 3), e(:)
    real(dp), intent(out) :: force(:), strain
    integer, intent(out) :: info
    real(dp) :: element_force(sys%element_dofs, sys%nel), element_energy(sys%nel)
    real(dp) :: unused(sys%element_dofs, sys%element_dofs, 1)
    real(dp) :: e_full(sys%nfull), force_full(sys%nfull)
    info = 0
    if (sys%formulation == formulation_ffr) then
      call ffr_force(sys%ndof, sys%nel, sys%dofs, sys%stiffness0, rotation, e, sys%e0_frame, &
                     force, strain)
      return
    end if
    call to_full(sys, e, .true., e_full)
    call element_pass(sys, e_full, .false., element_force, element_energy, unused, info)
    call scatter_forces(sys, element_force, element_energy, force_full, strain)
    call to_reduced(sys, force_full, force)
  end subroutine elastic_force

  !> q = B q_i + q0 (with_offset; velocities and accelerations without).
  pure subroutine to_full(sys, x, with_offset, full)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: x(:)
    logical, intent(in) :: with_offset
    real(dp), intent(out) :: full(:)
    integer :: i, k
    if (.not. sys%reduced) then
      full = x
      return
    end if
    do i = 1, sys%nfull
      full(i) = 0.0_dp
      if (with_offset) full(i) = sys%reduction_offset(i)
      do k = sys%reduction_ptr(i), sys%reduction_ptr(i + 1) - 1
        full(i) = full(i) + sys%reduction_values(k) * x(sys%reduction_col(k))
      end do
    end do
  end subroutine to_full

  !> Q_i = B^T Q (seed 003 eq. 37).
  pure subroutine to_reduced(sys, full, x)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: full(:)
    real(dp), intent(out) :: x(:)
    integer :: i, k
    if (.not. sys%reduced) then
      x = full
      return
    end if
    x = 0.0_dp
    do i = 1, sys%nfull
      do k = sys%reduction_ptr(i), sys%reduction_ptr(i + 1) - 1
        x(sys%reduction_col(k)) = x(sys%reduction_col(k)) + sys%reduction_values(k) * full(i)
      end do
    end do
  end subroutine to_reduced

  !> Contact forces (reduced) at the reduced state (e, v), the per-point records, the
  !> penalty potential and the powers (damping, friction); with values_full, the contact
  !> Jacobian (velocity_factor = d q'/d q) is added to the full pattern's values.
  !> info = 7 (normal vanished) or 8 (projection failed).
  subroutine contact_force(sys, e, v, velocity_factor, state, force, records, potential, powers, &
                           info, values_full)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: e(:), v(:), velocity_factor
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: force(:), records(:, :), potential, powers(2)
    integer, intent(out) :: info
    real(dp), intent(inout), optional :: values_full(:)
    real(dp) :: e_full(sys%nfull), v_full(sys%nfull), force_full(sys%nfull)
    call to_full(sys, e, .true., e_full)
    call to_full(sys, v, .false., v_full)
    force_full = 0.0_dp
    if (present(values_full)) then
      call contact_assemble(e_full, v_full, sys%dofs, sys%element_size, sys%contact_grid, &
                            sys%contact_element, sys%contact_local, sys%contact_params, &
                            velocity_factor, state%guesses, force_full, records, potential, &
                            powers, state%counts, info, sys%full_row_ptr, sys%full_col, &
                            values_full)
    else
      call contact_assemble(e_full, v_full, sys%dofs, sys%element_size, sys%contact_grid, &
                            sys%contact_element, sys%contact_local, sys%contact_params, &
                            velocity_factor, state%guesses, force_full, records, potential, &
                            powers, state%counts, info)
    end if
    call to_reduced(sys, force_full, force)
  end subroutine contact_force

  !> Forces, energies and (on request) tangents of every element of the large-deformation
  !> formulations (beam_nonlinear, beam_structural, plate_element); elements in parallel (OpenMP, when built
  !> with it). info = 7: a plate element's normal vanished.
  subroutine element_pass(sys, e, want_tangent, element_force, element_energy, tangents, info)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: e(:)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: element_force(:, :), element_energy(:), tangents(:, :, :)
    integer, intent(out) :: info
    real(dp) :: unused(sys%element_dofs, sys%element_dofs)
    integer :: el, element_info(sys%nel)
    element_info = 0
    !$omp parallel do schedule(static) private(unused)
    do el = 1, sys%nel
      if (sys%formulation == formulation_plate) then
        if (want_tangent) then
          call plate_forces(reshape(e(sys%dofs(:, el)), [3, 12]), sys%plate_derivs(:, :, :, el), &
                            sys%plate_frame(:, :, :, el), sys%plate_curvature0(:, :, el), &
                            sys%plate_weights(:, el), sys%youngs, sys%poisson, sys%thickness, &
                            .true., element_force(:, el), element_energy(el), tangents(:, :, el), &
                            element_info(el))
        else
          call plate_forces(reshape(e(sys%dofs(:, el)), [3, 12]), sys%plate_derivs(:, :, :, el), &
                            sys%plate_frame(:, :, :, el), sys%plate_curvature0(:, :, el), &
                            sys%plate_weights(:, el), sys%youngs, sys%poisson, sys%thickness, &
                            .false., element_force(:, el), element_energy(el), unused, &
                            element_info(el))
        end if
      else if (sys%formulation == formulation_structural) then
        if (want_tangent) then
          call structural_element(reshape(e(sys%dofs(:, el)), [3, 8]), &
                                  sys%structural_forms(:, :, :, el), sys%structural_strain0(:, el), &
                                  sys%structural_stiffness(:, el), .true., element_force(:, el), &
                                  element_energy(el), tangents(:, :, el))
        else
          call structural_element(reshape(e(sys%dofs(:, el)), [3, 8]), &
                                  sys%structural_forms(:, :, :, el), sys%structural_strain0(:, el), &
                                  sys%structural_stiffness(:, el), .false., element_force(:, el), &
                                  element_energy(el), unused)
        end if
      else if (want_tangent) then
        call nonlinear_element(reshape(e(sys%dofs(:, el)), [3, 8]), sys%gauss_gradients(:, :, :, el), &
                               sys%gauss_weights(:, el), sys%youngs, sys%poisson, .true., &
                               element_force(:, el), element_energy(el), tangents(:, :, el))
      else
        call nonlinear_element(reshape(e(sys%dofs(:, el)), [3, 8]), sys%gauss_gradients(:, :, :, el), &
                               sys%gauss_weights(:, el), sys%youngs, sys%poisson, .false., &
                               element_force(:, el), element_energy(el), unused)
      end if
    end do
    !$omp end parallel do
    info = 0
    if (any(element_info /= 0)) info = 7
  end subroutine element_pass

  !> Global force and total energy from the element forces (serial scatter).
  pure subroutine scatter_forces(sys, element_force, element_energy, force, strain)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: element_force(:, :), element_energy(:)
    real(dp), intent(out) :: force(:), strain
    integer :: el
    force = 0.0_dp
    do el = 1, sys%nel
      force(sys%dofs(:, el)) = force(sys%dofs(:, el)) + element_force(:, el)
    end do
    strain = sum(element_energy)
  end subroutine scatter_forces

  !> Large deformation: factorize S = beta' M + K_t(e) on the solver's pattern and compute
  !> the flexibility S^{-1} E_c and E_c^T S^{-1} E_c for the Schur complement; the elastic
  !> force and strain energy at e come out of the same element pass, and force returns the
  !> elastic minus the contact force at (e, v) (the contact Jacobian's evaluation).
  subroutine refactorize(sys, beta_prime, velocity_factor, e, v, state, flexibility, &
                         flexibility_cc, force, strain, info, detail)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: beta_prime, velocity_factor, e(:), v(:)
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: flexibility(:, :), flexibility_cc(:, :), force(:), strain
    integer, intent(out) :: info, detail
    real(dp) :: tangents(sys%element_dofs, sys%element_dofs, sys%nel)
    real(dp) :: element_force(sys%element_dofs, sys%nel), element_energy(sys%nel)
    real(dp) :: values(size(sys%mass_pattern)), values_full(size(sys%full_col))
    real(dp) :: e_full(sys%nfull), force_full(sys%nfull), contact(sys%ndof)
    real(dp) :: records(contact_record, sys%ncontact), potential, powers(2)
    integer :: b, j, k
    detail = 0
    call to_full(sys, e, .true., e_full)
    call element_pass(sys, e_full, .true., element_force, element_energy, tangents, info)
    if (info /= 0) return
    ! the elastic force at e comes with the tangent: the step's first residual reuses it
    call scatter_forces(sys, element_force, element_energy, force_full, strain)
    call to_reduced(sys, force_full, force)
    call pattern_assemble(size(values_full), sys%element_dofs, sys%nel, sys%scatter_map, &
                          tangents, values_full)
    if (sys%ncontact > 0) then
      call contact_force(sys, e, v, velocity_factor, state, contact, records, potential, &
                         powers, info, values_full)
      if (info /= 0) return
      force = force - contact
    end if
    if (sys%reduced) then  ! B^T S B by the plan
      values = 0.0_dp
      do k = 1, size(sys%plan_source)
        values(sys%plan_target(k)) = values(sys%plan_target(k)) &
                                     + sys%plan_coef(k) * values_full(sys%plan_source(k))
      end do
    else
      values = values_full
    end if
    values = values + beta_prime * sys%mass_pattern
    call solver_factorize(sys%solver_handle, size(values), values, info, detail)
    if (info /= 0) then
      detail = info
      info = 3
      return
    end if
    if (sys%nblock == 0) return
    flexibility = 0.0_dp
    do b = 1, sys%nblock
      do j = 1, 3
        flexibility(sys%block_first(b) + j - 1, 3 * (b - 1) + j) = 1.0_dp
      end do
    end do
    call solver_solve(sys%solver_handle, sys%ndof, 3 * sys%nblock, flexibility, info, detail)
    if (info /= 0) then
      detail = info
      info = 3
      return
    end if
    do b = 1, sys%nblock
      do j = 1, 3
        flexibility_cc(3 * (b - 1) + j, :) = flexibility(sys%block_first(b) + j - 1, :)
      end do
    end do
  end subroutine refactorize

  !> Residual r = M q'' + Q_el(q) - Q(q) - Phi_q^T lambda at time t, with the constraint
  !> values and gradients and the strain energy.
  subroutine residual(sys, t, e, v, acceleration, lam, rotation, state, r, phi, gradients, &
                      strain, info, known_internal)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: t, e(:), v(:), acceleration(:), lam(:), rotation(3, 3)
    type(contact_state), intent(inout) :: state
    real(dp), intent(inout) :: strain  ! out; in with known_internal
    real(dp), intent(out) :: r(:), phi(:), gradients(:, :)
    integer, intent(out) :: info
    ! elastic minus contact force at (e, v), already computed (by refactorize)
    real(dp), intent(in), optional :: known_internal(:)
    real(dp) :: elastic(sys%ndof), inertia(sys%ndof), force(3), jacobian(3, 3), hessian(3, 3, 3)
    real(dp) :: contact(sys%ndof), records(contact_record, sys%ncontact), potential, powers(2)
    integer :: m, c, i
    info = 0
    if (present(known_internal)) then
      elastic = known_internal
    else
      call elastic_force(sys, rotation, e, elastic, strain, info)
      if (info /= 0) return
      if (sys%ncontact > 0) then
        call contact_force(sys, e, v, 0.0_dp, state, contact, records, potential, powers, info)
        if (info /= 0) return
        elastic = elastic - contact
      end if
    end if
    call csr_matvec(sys%mass_row_ptr, sys%mass_col, sys%mass_values, acceleration, inertia)
    r = inertia + elastic - sys%constant_force
    if (sys%force_drive > 0) r = r - load_factor(sys, t, info) * sys%drive_force
    if (info /= 0) return
    do m = 1, sys%nmoment
      call moment_force(e(sys%moment_dofs(:, m)), sys%moment_axis(:, m), &
                        sys%moment_magnitude(m), force, jacobian, hessian, info)
      if (info /= 0) then
        info = 6
        return
      end if
      r(sys%moment_dofs(:, m)) = r(sys%moment_dofs(:, m)) - force
    end do
    call evaluate_constraints(sys, e, t, phi, gradients, info)
    if (info /= 0) return
    do c = 1, sys%ncon
      do i = 1, 6
        if (sys%con_ints(2 + i, c) > 0) r(sys%con_ints(2 + i, c)) = &
          r(sys%con_ints(2 + i, c)) - gradients(i, c) * lam(c)
      end do
    end do
  end subroutine residual

  !> Advances nsteps steps from (t, q = e, v, a, q'' = accel, lambda), writing one output
  !> row per step; a is the generalized-alpha acceleration-like variable (= q'' for
  !> Newmark). info: 0 ok; 1 Newton did not converge; 2 non-finite state; 3 linear solve
  !> failed (detail = solver code); 4 singular Schur complement (detail = dgesv info);
  !> 5 constraint or drive evaluation failed; 6 moment undefined; 7 a plate element's normal
  !> vanished. steps_done counts the
  !> completed steps; the state is that of the last completed step; last_correction is the
  !> size of the last Newton correction (why a step failed to converge).
  subroutine integrator_chunk(sys, cfg, nsteps, t, e, v, a, accel, lam, work, state, out_time, &
                              out_probe, out_deflection, out_lambda, out_energy, out_constraint, &
                              out_newton, out_contact, store_q, out_q, steps_done, info, detail, &
                              refactorizations, last_correction)
    type(mechanical_system), intent(in) :: sys
    type(integrator_settings), intent(in) :: cfg
    integer, intent(in) :: nsteps
    real(dp), intent(inout) :: t, e(:), v(:), a(:), accel(:), lam(:), work(4)
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: out_contact(:, :, :)  ! (contact_record, ncontact, nsteps)
    real(dp), intent(out) :: out_time(:), out_probe(:, :, :), out_deflection(:, :, :)
    real(dp), intent(out) :: out_lambda(:, :), out_energy(:, :), out_constraint(:)
    integer, intent(out) :: out_newton(:)
    logical, intent(in) :: store_q
    real(dp), intent(out) :: out_q(:, :)
    integer, intent(out) :: steps_done, info, detail
    integer, intent(out) :: refactorizations  ! of S during this call (large deformation)
    real(dp), intent(out) :: last_correction  ! max |de| of the last Newton correction (m)
    real(dp) :: e_new(sys%ndof), a_new(sys%ndof), accel_new(sys%ndof), lam_new(sys%ncon)
    real(dp) :: r(sys%ndof), z(sys%ndof, 1), direction(sys%ndof), correction(sys%ndof)
    real(dp) :: phi(sys%ncon), gradients(6, sys%ncon)
    real(dp) :: w(3 * sys%nblock, sys%ncon), schur(sys%ncon, sys%ncon), dlam(sys%ncon, 1)
    real(dp) :: flexibility(sys%ndof, 3 * sys%nblock), flexibility_cc(3 * sys%nblock, 3 * sys%nblock)
    real(dp) :: predicted_elastic(sys%ndof), v_new(sys%ndof)
    real(dp) :: rotation(3, 3), transform(3, 3), rate, strain, violation, powers_old(4), powers_new(4)
    real(dp) :: t_new, h, beta_prime, velocity_factor, contact_potential, step_cap
    integer :: step, it, ipiv(sys%ncon), lapack_info
    logical :: done, fresh_force
    real(dp) :: previous_correction
    info = 0
    refactorizations = 0
    detail = 0
    steps_done = 0
    last_correction = 0.0_dp
    h = cfg%h
    beta_prime = (1.0_dp - cfg%alpha_m) / (cfg%beta * h * h * (1.0_dp - cfg%alpha_f))
    velocity_factor = cfg%gamma / (cfg%beta * h)
    if (sys%formulation == formulation_ffr) then
      flexibility = sys%flexibility
      flexibility_cc = sys%flexibility_cc
    end if
    call frame_rotation(sys, t, rotation, rate, info)
    if (info /= 0) then
      info = 5
      return
    end if
    call step_powers(sys, e, v, lam, rotation, rate, t, state, powers_old, strain, violation, &
                     contact_potential, out_contact(:, :, 1), info)
    if (info /= 0) return
    do step = 1, nsteps
      t_new = t + h
      if (sys%ncontact == 0) then
        ! predictor: q''_{n+1} = q''_n
        accel_new = accel
        a_new = (cfg%alpha_f * accel + (1.0_dp - cfg%alpha_f) * accel_new - cfg%alpha_m * a) &
                / (1.0_dp - cfg%alpha_m)
        e_new = e + h * v + h * h * ((0.5_dp - cfg%beta) * a + cfg%beta * a_new)
      else
        ! penalty contact: q_{n+1} = q_n (an acceleration predictor carries a contact
        ! impulse of the last step into the next one, far through the other leaf)
        e_new = e
        a_new = -(v / h + (0.5_dp - cfg%beta) * a) / cfg%beta
        accel_new = ((1.0_dp - cfg%alpha_m) * a_new + cfg%alpha_m * a - cfg%alpha_f * accel) &
                    / (1.0_dp - cfg%alpha_f)
      end if
      v_new = v + h * ((1.0_dp - cfg%gamma) * a + cfg%gamma * a_new)
      lam_new = lam
      call frame_rotation(sys, t_new, rotation, rate, info)
      if (info /= 0) then
        info = 5
        return
      end if
      ! the solve works in the frame of S: the floating frame for FFR, the global frame
      ! for large deformation (where A(t) only resolves the output deflections)
      transform = rotation
      if (sys%formulation /= formulation_ffr) then
        transform = reshape([1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [3, 3])
        call refactorize(sys, beta_prime, velocity_factor, e_new, v_new, state, flexibility, &
                         flexibility_cc, predicted_elastic, strain, info, detail)
        if (info /= 0) return
        refactorizations = refactorizations + 1
      end if
      done = .false.
      fresh_force = sys%formulation /= formulation_ffr
      previous_correction = huge(1.0_dp)
      do it = 1, cfg%max_newton
        if (fresh_force) then
          call residual(sys, t_new, e_new, v_new, accel_new, lam_new, rotation, state, r, phi, &
                        gradients, strain, info, predicted_elastic)
        else
          call residual(sys, t_new, e_new, v_new, accel_new, lam_new, rotation, state, r, phi, &
                        gradients, strain, info)
        end if
        if (info /= 0) return
        fresh_force = .false.
        ! z = T S^{-1} T^T r
        call to_solver_frame(sys, transform, r, .true., z(:, 1))
        call solver_solve(sys%solver_handle, sys%ndof, 1, z, info, detail)
        if (info /= 0) then
          detail = info
          info = 3
          return
        end if
        call to_solver_frame(sys, transform, z(:, 1), .false., direction)
        ! Schur complement C dlam = Phi_e z - Phi, C = W^T (E_c^T S^{-1} E_c) W
        call frame_gradients(sys, transform, gradients, w)
        schur = matmul(transpose(w), matmul(flexibility_cc, w))
        dlam(:, 1) = gradient_dot(sys, gradients, direction) - phi
        if (sys%ncon > 0) then
          call dgesv(sys%ncon, 1, schur, sys%ncon, ipiv, dlam, sys%ncon, lapack_info)
          if (lapack_info /= 0) then
            info = 4
            detail = lapack_info
            return
          end if
          call to_solver_frame(sys, transform, matmul(flexibility, matmul(w, dlam(:, 1))), .false., &
                          correction)
          correction = correction - direction
        else
          correction = -direction
        end if
        if (sys%ncontact > 0) then
          ! damped Newton with contact: no correction moves a coordinate by more than half
          ! a leaf thickness (a contact that is open at the linearization point has no
          ! stiffness there, and a full step would jump far through the other leaf)
          step_cap = 0.5_dp * min(sys%contact_params(5), sys%contact_params(6))
          if (maxval(abs(correction)) > step_cap) then
            dlam = dlam * (step_cap / maxval(abs(correction)))
            correction = correction * (step_cap / maxval(abs(correction)))
          end if
        end if
        e_new = e_new + correction
        accel_new = accel_new + beta_prime * correction
        v_new = v_new + velocity_factor * correction
        lam_new = lam_new + dlam(:, 1)
        if (.not. (all(abs(correction) < huge(1.0_dp)) .and. all(abs(lam_new) < huge(1.0_dp)))) then
          info = 2
          return
        end if
        last_correction = maxval(abs(correction))
        if (last_correction <= cfg%tol * cfg%length_scale) then
          done = .true.
          exit
        end if
        ! large deformation: when the step's tangent no longer halves the correction
        ! (a strongly nonlinear step), update it at the current iterate (full Newton)
        if (sys%formulation /= formulation_ffr .and. it < cfg%max_newton .and. &
            last_correction > 0.5_dp * previous_correction) then
          call refactorize(sys, beta_prime, velocity_factor, e_new, v_new, state, flexibility, &
                           flexibility_cc, predicted_elastic, strain, info, detail)
          if (info /= 0) return
          refactorizations = refactorizations + 1
          fresh_force = .true.
        end if
        previous_correction = last_correction
      end do
      if (.not. done) then
        info = 1
        return
      end if
      ! accept the step
      a_new = (cfg%alpha_f * accel + (1.0_dp - cfg%alpha_f) * accel_new - cfg%alpha_m * a) &
              / (1.0_dp - cfg%alpha_m)
      v = v + h * ((1.0_dp - cfg%gamma) * a + cfg%gamma * a_new)
      e = e_new
      a = a_new
      accel = accel_new
      lam = lam_new
      t = t_new
      call step_powers(sys, e, v, lam, rotation, rate, t, state, powers_new, strain, &
                       out_constraint(step), contact_potential, out_contact(:, :, step), info)
      if (info /= 0) return
      work = work + 0.5_dp * h * (powers_old + powers_new)
      powers_old = powers_new
      steps_done = step
      out_time(step) = t
      out_newton(step) = it
      out_lambda(:, step) = lam
      call record(sys, e, v, t, rotation, work, strain, contact_potential, out_probe(:, :, step), &
                  out_deflection(:, :, step), out_energy(:, step))
      if (store_q) out_q(:, step) = e
    end do
  end subroutine integrator_chunk

  !> W(3 nblock, ncon): frame components (T^T Phi_e^T) at the touched 3-vectors.
  subroutine frame_gradients(sys, rotation, gradients, w)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: rotation(3, 3), gradients(:, :)
    real(dp), intent(out) :: w(:, :)
    integer :: c, i, dof, b, comp
    w = 0.0_dp
    do c = 1, sys%ncon
      do i = 1, 6
        dof = sys%con_ints(2 + i, c)
        if (dof == 0) cycle
        do b = 1, sys%nblock  ! the first block holding dof
          if (dof >= sys%block_first(b) .and. dof <= sys%block_first(b) + 2) exit
        end do
        comp = dof - sys%block_first(b) + 1
        w(3 * (b - 1) + 1:3 * b, c) = w(3 * (b - 1) + 1:3 * b, c) + rotation(comp, :) * gradients(i, c)
      end do
    end do
  end subroutine frame_gradients

  !> Phi_e x for every constraint.
  pure function gradient_dot(sys, gradients, x) result(y)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: gradients(:, :), x(:)
    real(dp) :: y(sys%ncon)
    integer :: c, i
    y = 0.0_dp
    do c = 1, sys%ncon
      do i = 1, 6
        if (sys%con_ints(2 + i, c) > 0) y(c) = y(c) + gradients(i, c) * x(sys%con_ints(2 + i, c))
      end do
    end do
  end function gradient_dot

  !> Powers of the constraint forces (lambda . Phi_e v: the drive) and, for FFR, of the moving
  !> frame, dU/dt at fixed e = -phi' sum_b f_b . (k x x_b), f = K0 u, u = T^T e - e0,
  !> x = T^T e, with the strain energy U, all from one pass over the elements, and the
  !> constraint violation max |Phi| at (e, t).
  subroutine step_powers(sys, e, v, lam, rotation, rate, t, state, powers, strain, violation, &
                         contact_potential, contact_records, info)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: e(:), v(:), lam(:), rotation(3, 3), rate, t
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: powers(4), strain, violation, contact_potential
    real(dp), intent(out) :: contact_records(:, :)
    integer, intent(out) :: info
    real(dp) :: phi(sys%ncon), gradients(6, sys%ncon)
    real(dp) :: frame_coords(24), local(24), frame_force(24), k(3), x(3)
    real(dp) :: frame_force_global(sys%ndof)
    integer :: el, b
    call evaluate_constraints(sys, e, t, phi, gradients, info)
    if (info /= 0) return
    violation = 0.0_dp
    if (sys%ncon > 0) violation = maxval(abs(phi))
    powers(1) = dot_product(lam, gradient_dot(sys, gradients, v))
    powers(2:4) = 0.0_dp
    contact_potential = 0.0_dp
    if (sys%ncontact > 0) then
      call contact_force(sys, e, v, 0.0_dp, state, frame_force_global, contact_records, &
                         contact_potential, powers(3:4), info)
      if (info /= 0) return
    end if
    if (sys%formulation /= formulation_ffr) then
      call elastic_force(sys, rotation, e, frame_force_global, strain, info)
      return
    end if
    strain = 0.0_dp
    k = sys%frame_axis / norm2(sys%frame_axis)
    do el = 1, sys%nel
      do b = 0, 7
        frame_coords(3 * b + 1:3 * b + 3) = rotation(1, :) * e(sys%dofs(3 * b + 1, el)) &
                                            + rotation(2, :) * e(sys%dofs(3 * b + 2, el)) &
                                            + rotation(3, :) * e(sys%dofs(3 * b + 3, el))
      end do
      local = frame_coords - sys%e0_frame(sys%dofs(:, el))
      frame_force = matmul(sys%stiffness0(:, :, el), local)
      strain = strain + 0.5_dp * dot_product(local, frame_force)
      if (rate == 0.0_dp) cycle
      do b = 0, 7
        x = frame_coords(3 * b + 1:3 * b + 3)
        powers(2) = powers(2) - rate * dot_product(frame_force(3 * b + 1:3 * b + 3), &
                    [k(2) * x(3) - k(3) * x(2), k(3) * x(1) - k(1) * x(3), k(1) * x(2) - k(2) * x(1)])
      end do
    end do
  end subroutine step_powers

  !> One output row: probes, deflections in the frame, energies.
  subroutine record(sys, e, v, t, rotation, work, strain, contact_potential, probe, deflection, &
                    energy)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: e(:), v(:), t, rotation(3, 3), work(4), strain, contact_potential
    real(dp), intent(out) :: probe(:, :), deflection(:, :), energy(:)
    real(dp) :: mv(sys%ndof), e_full(sys%nfull), factor
    integer :: p, a, m, info
    call to_full(sys, e, .true., e_full)
    do p = 1, sys%nprobe
      probe(:, p) = 0.0_dp
      do a = 0, size(sys%probe_shape, 1) - 1
        probe(:, p) = probe(:, p) + sys%probe_shape(a + 1, p) &
                      * e_full(sys%probe_dofs(3 * a + 1:3 * a + 3, p))
      end do
      deflection(:, p) = matmul(transpose(rotation), probe(:, p)) - sys%probe_reference(:, p)
    end do
    call csr_matvec(sys%mass_row_ptr, sys%mass_col, sys%mass_values, v, mv)
    energy(energy_kinetic) = 0.5_dp * dot_product(v, mv)
    energy(energy_strain) = strain
    energy(energy_loads) = -dot_product(sys%constant_force, e)
    if (sys%force_drive > 0) then
      factor = load_factor(sys, t, info)
      energy(energy_loads) = energy(energy_loads) - factor * dot_product(sys%drive_force, e)
    end if
    energy(energy_moment) = 0.0_dp
    do m = 1, sys%nmoment
      energy(energy_moment) = energy(energy_moment) - sys%moment_magnitude(m) * &
        moment_angle(e(sys%moment_dofs(:, m)), sys%moment_axis(:, m), sys%moment_reference(:, m))
    end do
    energy(energy_contact) = contact_potential
    energy(energy_total) = sum(energy(energy_kinetic:energy_moment)) + contact_potential
    energy(work_drive) = work(1)
    energy(work_frame) = work(2)
    energy(work_damping) = work(3)
    energy(work_friction) = work(4)
  end subroutine record

  !> phi(t) of the time-dependent load (info = 5 when its drive fails).
  function load_factor(sys, t, info) result(factor)
    type(mechanical_system), intent(in) :: sys
    real(dp), intent(in) :: t
    integer, intent(out) :: info
    real(dp) :: factor, rate, second
    call drive_eval(sys%drive_kinds(sys%force_drive), sys%drive_params(:, sys%force_drive), t, &
                    factor, rate, second, info)
    if (info /= 0) info = 5
  end function load_factor

end module time_integrator
