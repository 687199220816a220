!> What the f2py binding (element_api.f90, system_api.f90) shares and f2py does not wrap:
!> the one handle check of the system routines and the layouts of the small arrays that
!> group a routine's related scalars (so that no routine takes more than 15 arguments).
!> Each layout is a set of 1-based indices <prefix>_<name> and its length <prefix>_count;
!> python/ancfdrv/codes.py KERNEL_LAYOUTS mirrors every one (tests/test_codes.py checks).
module api_support
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, frame_rotations
  use stepper, only: stepper_run
  use system_store, only: store_get
  use kernel_errors, only: handle_text
  use element_sets, only: element_set
  use beam_stations, only: station_section
  use ffr_elastic, only: ffr_set
  use beam_nonlinear, only: continuum_set
  use beam_cubic, only: cubic_set
  implicit none
  private
  public :: api_system, unpack_constraints, give_sections, frame_at_rows

  !> The arrays of a constraint set (constraints module layout)
  type, public :: constraint_layout
    integer, allocatable :: kinds(:), drives(:), term_ptr(:), term_dof(:), drive_kinds(:), &
                            drive_ptr(:)
    real(dp), allocatable :: params(:, :), operand_const(:, :), term_coef(:), drive_data(:)
  end type constraint_layout

  !> beam_cubic_setup's section and material
  integer, parameter, public :: cs_area = 1, cs_inertia_y = 2, cs_inertia_z = 3, &
                                cs_torsion = 4, cs_shear_y = 5, cs_shear_z = 6, cs_youngs = 7, &
                                cs_poisson = 8, cs_count = 8
  !> a beam set's section data for its section forces (beam_stations station_section):
  !> EA, G J, k_y G A, k_z G A, the moments' factors -E I_y and E I_z, E, I_y, I_z, I_p
  integer, parameter, public :: bs_axial = 1, bs_torsion = 2, bs_shear_y = 3, bs_shear_z = 4, &
                                bs_moment_height = 5, bs_moment_width = 6, bs_youngs = 7, &
                                bs_inertia_y = 8, bs_inertia_z = 9, bs_polar = 10, bs_count = 10
  !> a continuum beam set's material
  integer, parameter, public :: bm_youngs = 1, bm_poisson = 2, bm_count = 2
  !> a plate's material and thickness
  integer, parameter, public :: pm_youngs = 1, pm_poisson = 2, pm_thickness = 3, pm_count = 3
  !> a cable's section and its axial Kelvin-Voigt damping (damping_time 0: none)
  integer, parameter, public :: cb_axial_stiffness = 1, cb_bending_stiffness = 2, &
                                cb_damping_time = 3, cb_rate_factor = 4, cb_count = 4
  !> one force element: its kinds, its length and rate, its energies
  integer, parameter, public :: fk_element = 1, fk_table = 2, fk_count = 2
  integer, parameter, public :: fg_length = 1, fg_length_rate = 2, fg_count = 2
  integer, parameter, public :: fe_energy = 1, fe_dissipation = 2, fe_drive_power = 3, &
                                fe_count = 3
  !> a system's force elements (columns of elements(:, l)) and their pointers (columns)
  integer, parameter, public :: fl_kind = 1, fl_drive = 2, fl_table_kind = 3, &
                                fl_slot_first = 4, fl_count = 4
  integer, parameter, public :: fp_param = 1, fp_table = 2, fp_position = 3, fp_count = 3
  !> the header of a packed constraint layout (constraint_offsets)
  integer, parameter, public :: cl_ncon = 1, cl_nterm = 2, cl_ndrive = 3, cl_count = 3
  !> a reduced FFR run: the frame's motion at each time (columns), the stepper's settings
  !> and controls, per-step counts (columns), its status, the energy rows (columns)
  integer, parameter, public :: fm_rate = 1, fm_sin_psi = 2, fm_one_minus_cos = 3, &
                                fm_accel = 4, fm_count = 4
  integer, parameter, public :: rs_dt = 1, rs_beta = 2, rs_gamma = 3, rs_tol = 4, rs_count = 4
  integer, parameter, public :: rc_pdelta = 1, rc_max_newton = 2, rc_count = 2
  integer, parameter, public :: rn_corrections = 1, rn_factorized = 2, rn_count = 2
  integer, parameter, public :: rt_info = 1, rt_failed_step = 2, rt_count = 2
  integer, parameter, public :: re_kinetic = 1, re_strain = 2, re_power = 3, re_load = 4, &
                                re_count = 4
  !> a state's coordinates and rates (columns), the forces of system_evaluate (columns),
  !> its factors and energies
  integer, parameter, public :: sv_coordinates = 1, sv_rates = 2, sv_count = 2
  integer, parameter, public :: ff_internal = 1, ff_external = 2, ff_count = 2
  integer, parameter, public :: ef_time = 1, ef_load_factor = 2, ef_velocity_factor = 3, &
                                ef_count = 3
  integer, parameter, public :: ee_strain = 1, ee_contact_potential = 2, ee_count = 2
  !> a static load step or arc-length step: settings, controls, the residual scales and the
  !> path's figures (in and out), outcome, the reference and previous increment (columns)
  integer, parameter, public :: ss_time = 1, ss_load_factor = 2, ss_tol = 3, &
                                ss_length_scale = 4, ss_arc = 5, ss_direction = 6, ss_count = 6
  integer, parameter, public :: sc_check_start = 1, sc_load_step = 2, sc_load_steps = 3, &
                                sc_mode = 4, sc_count = 4
  integer, parameter, public :: sr_force_scale = 1, sr_force_res = 2, sr_con_res = 3, &
                                sr_load_factor = 4, sr_load_norm = 5, sr_tangent_norm = 6, &
                                sr_flexibility = 7, sr_count = 7
  integer, parameter, public :: sx_reference = 1, sx_previous = 2, sx_count = 2
  integer, parameter, public :: so_info = 1, so_iterations = 2, so_converged_by = 3, &
                                so_factorizations = 4, so_count = 4
  !> the stepper's step-size control (system_stepper_setup), a controlled advance's per-row
  !> statistics (columns), its status and its figures (system_advance)
  integer, parameter, public :: sk_dt = 1, sk_dt_min = 2, sk_adaptive = 3, sk_tolerance = 4, &
                                sk_count = 4
  integer, parameter, public :: at_corrections = 1, at_factorizations = 2, at_jacobians = 3, &
                                at_substeps = 4, at_cuts = 5, at_count = 5
  integer, parameter, public :: as_rows = 1, as_info = 2, as_detail = 3, as_floor_accepts = 4, &
                                as_tries = 5, as_failure_cuts = 6, as_failure_tries = 7, &
                                as_failed_corrections = 8, as_failed_factorizations = 9, &
                                as_failed_jacobians = 10, as_cuts = 11, as_rejected = 12, &
                                as_restarts = 13, as_taken = 14, as_count = 14
  integer, parameter, public :: af_last_correction = 1, af_failure_t = 2, af_failure_h = 3, &
                                af_smallest = 4, af_count = 4
  !> the columns of a pattern's coordinates (rows, columns)
  integer, parameter, public :: tp_rows = 1, tp_cols = 2, tp_count = 2
  !> a solver: its handle (sparse_direct) and its policy (mechanical_system policy_*)
  integer, parameter, public :: sl_handle = 1, sl_policy = 2, sl_count = 2
  !> one contact pair: each side's element size and local point (columns upper, lower)
  integer, parameter, public :: cg_a = 1, cg_b = 2, cg_xi = 3, cg_eta = 4, cg_count = 4
  !> contact energies: the penalty potential, the damping and friction powers
  integer, parameter, public :: ce_potential = 1, ce_damping = 2, ce_friction = 3, &
                                ce_count = 3

contains

  !> The rotation of the system's frame `frame` (0: none, the identity) at each of the
  !> times, for the routines that read a set's stored rows in its frame
  !> (system_section_forces, system_ffr_departures). info /= 0: a frame's drive failed.
  subroutine frame_at_rows(sys, frame, times, rotations, info)
    type(system_model), intent(in) :: sys
    integer, intent(in) :: frame
    real(dp), intent(in) :: times(:)
    real(dp), intent(out) :: rotations(:, :, :)
    integer, intent(out) :: info
    real(dp) :: frames(3, 3, 0:size(sys%frames)), rates(0:size(sys%frames))
    integer :: row
    info = 0
    do row = 1, size(times)
      call frame_rotations(sys, times(row), frames, rates, info)
      if (info /= 0) return
      rotations(:, :, row) = frames(:, :, frame)
    end do
  end subroutine frame_at_rows

  !> The system (and on request its stepper run) behind handle; info = 1 with the text in
  !> message when it is not a live handle, else info = 0 and message blank.
  subroutine api_system(handle, sys, info, message, run)
    integer, intent(in) :: handle
    type(system_model), pointer, intent(out) :: sys
    integer, intent(out) :: info
    character(len=200), intent(out), optional :: message
    type(stepper_run), pointer, intent(out), optional :: run
    if (present(run)) then
      call store_get(handle, sys, info, run)
    else
      call store_get(handle, sys, info)
    end if
    if (present(message)) then
      message = ' '
      if (info /= 0) message = handle_text(handle)
    end if
  end subroutine api_system

  !> Hands a beam set (ffr, continuum or cubic) the data of its section forces
  !> (system_set_sections; here, where f2py does not read the type selection). info = 2:
  !> the set is of another family.
  subroutine give_sections(set, sections, info)
    class(element_set), intent(inout) :: set
    type(station_section), intent(in) :: sections
    integer, intent(out) :: info
    info = 0
    select type (set)
    type is (ffr_set)
      set%sections = sections
      if (allocated(set%stations%xi)) deallocate (set%stations%xi)   ! its forms: rebuilt
    type is (continuum_set)
      set%sections = sections
    type is (cubic_set)
      set%sections = sections
    class default
      info = 2
    end select
  end subroutine give_sections

  !> A packed constraint layout unpacked into the arrays of the constraints module,
  !>   ints  = [ncon, nterm, ndrive, kinds(ncon), drives(ncon), term_ptr(6 ncon + 1),
  !>            term_dof(nterm), drive_kinds(ndrive), drive_ptr(ndrive + 1)]
  !>   reals = [params(8, ncon), operand_const(6, ncon), term_coef(nterm), drive_data(:)]
  !> (drive_data to the end). info = ncon + 1 (no constraint's number): the lengths
  !> disagree with the header or with ncon.
  pure subroutine unpack_constraints(ints, reals, ncon, layout, info)
    integer, intent(in) :: ints(:), ncon
    real(dp), intent(in) :: reals(:)
    type(constraint_layout), intent(out) :: layout
    integer, intent(out) :: info
    integer :: nterm, ndrive, at
    info = ncon + 1
    if (size(ints) < cl_count) return
    nterm = ints(cl_nterm)
    ndrive = ints(cl_ndrive)
    if (ints(cl_ncon) /= ncon .or. nterm < 0 .or. ndrive < 0) return
    if (size(ints) /= cl_count + 8 * ncon + 1 + nterm + 2 * ndrive + 1) return
    if (size(reals) < 14 * ncon + nterm) return
    at = cl_count
    layout%kinds = ints(at + 1:at + ncon)
    at = at + ncon
    layout%drives = ints(at + 1:at + ncon)
    at = at + ncon
    layout%term_ptr = ints(at + 1:at + 6 * ncon + 1)
    at = at + 6 * ncon + 1
    layout%term_dof = ints(at + 1:at + nterm)
    at = at + nterm
    layout%drive_kinds = ints(at + 1:at + ndrive)
    at = at + ndrive
    layout%drive_ptr = ints(at + 1:at + ndrive + 1)
    layout%params = reshape(reals(1:8 * ncon), [8, ncon])
    at = 8 * ncon
    layout%operand_const = reshape(reals(at + 1:at + 6 * ncon), [6, ncon])
    at = at + 6 * ncon
    layout%term_coef = reals(at + 1:at + nterm)
    layout%drive_data = reals(at + nterm + 1:)
    info = 0
  end subroutine unpack_constraints

end module api_support
