!> The engineering answers' part of a dynamic output row (issue 36 item 3), written by the
!> stepper with the row from the state it reached, so that nothing above the kernel rebuilds
!> the integrator's velocities and accelerations:
!> - per force element the force and moment body1 exerts on body2 and the axial force
!>   (mechanical_system force_element_reactions at (t, e, e'): 7 values each);
!> - the residual of the equations of motion in the full coordinates q,
!>   r = M q'' + Q_int(q, q') - Q(t) (Q_int: internal_forces' full force, evaluated there
!>   alone by column_forces: elastic, damping, force elements, minus contact and applied
!>   moments; Q: the constant loads with gravity
!>   and the driven loads), at the full coordinates the eliminated linear joints' rows touch
!>   (python/ancfdrv/system/answers.py recovers those joints' multipliers from it).
!> The run sets the data once (system_answer_setup): those columns, the full mass's rows and
!> the loads there; a run without it writes no answers (answer_count 0).
module row_answers
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state, contact_record, frame_rotations, &
                               column_forces, force_element_reactions
  use system_reduction, only: to_full
  use system_drives, only: drive_at
  implicit none
  private
  public :: answer_data, answer_count, answer_row

  !> force-element values per element: force (3), moment (3), axial
  integer, parameter, public :: element_answers = 7

  !> What a run's rows answer: whether they carry answers at all, the full coordinates of
  !> the residual (1-based), the full mass's rows there (CSR over the full coordinates) and
  !> the loads there: constant (gravity included) and one column per driven load, in the
  !> order of the system's force drives.
  type :: answer_data
    logical :: on = .false.
    integer, allocatable :: columns(:), mass_ptr(:), mass_col(:)
    real(dp), allocatable :: mass_values(:), constant(:), driven(:, :)
  end type answer_data

contains

  !> The answer values of a row: 7 per force element, then the residual at the columns.
  pure integer function answer_count(sys, answers)
    type(system_model), intent(in) :: sys
    type(answer_data), intent(in) :: answers
    answer_count = 0
    if (.not. answers%on) return
    answer_count = element_answers * sys%force_elements%nfel + size(answers%columns)
  end function answer_count

  !> The answers of the state (t, e, e', e'') with the contact projections of `contact`
  !> (a copy is searched from; the run's counters are not changed) into out(answer_count).
  !> info: internal_forces' or force_element_reactions' failure codes, 5 a failed drive.
  subroutine answer_row(sys, answers, t, e, v, accel, contact, out, info)
    type(system_model), intent(in) :: sys
    type(answer_data), intent(in) :: answers
    real(dp), intent(in) :: t, e(:), v(:), accel(:)
    type(contact_state), intent(in) :: contact
    real(dp), intent(out) :: out(:)
    integer, intent(out) :: info
    type(contact_state) :: search
    real(dp), allocatable :: rotations(:, :, :), rates(:), full_force(:), &
                             accel_full(:), records(:, :), elements(:, :), phi(:)
    logical, allocatable :: wanted(:)
    real(dp) :: dphi, ddphi, external, inertia
    integer :: nfel, ncol, i, k, d
    info = 0
    out = 0.0_dp
    nfel = sys%force_elements%nfel
    if (nfel > 0) then
      allocate (elements(element_answers, nfel))
      call force_element_reactions(sys, t, e, v, elements, info)
      if (info /= 0) return
      out(1:element_answers * nfel) = reshape(elements, [element_answers * nfel])
    end if
    ncol = size(answers%columns)
    if (ncol == 0) return
    allocate (rotations(3, 3, 0:size(sys%frames)), rates(0:size(sys%frames)), &
              full_force(sys%nfull), accel_full(sys%nfull), wanted(sys%nfull), &
              records(contact_record, max(1, sys%contact%npoint)), phi(size(answers%driven, 2)))
    call frame_rotations(sys, t, rotations, rates, info)
    if (info /= 0) return
    search%guesses = contact%guesses
    search%counts = 0
    ! (the forces at the columns alone: the elements that touch them, the same sums there)
    wanted = .false.
    wanted(answers%columns) = .true.
    call column_forces(sys, rotations, rates, e, v, t, wanted, search, full_force, records, info)
    if (info /= 0) return
    call to_full(sys%reduction, accel, .false., accel_full)
    do d = 1, size(phi)
      call drive_at(sys%drives, sys%loads%force_drive(d), t, &
                       phi(d), dphi, ddphi, info)
      if (info /= 0) then
        info = 5
        return
      end if
    end do
    do i = 1, ncol
      external = answers%constant(i)
      do d = 1, size(phi)
        external = external + phi(d) * answers%driven(i, d)
      end do
      inertia = 0.0_dp
      do k = answers%mass_ptr(i), answers%mass_ptr(i + 1) - 1
        inertia = inertia + answers%mass_values(k) * accel_full(answers%mass_col(k))
      end do
      out(element_answers * nfel + i) = (full_force(answers%columns(i)) - external) + inertia
    end do
  end subroutine answer_row

end module row_answers
