!> The force elements of a mechanical system (a component of system_model): springs,
!> dampers and cylinders between points of the bodies (force_elements.f90 kinds), each a
!> kind, a drive (0: none; the cylinder's length), parameters, an optional force-deflection
!> table and slots affine in the full coordinates; their forces, energy, powers and tangent.
!> No I/O.
module system_force_elements
  use ancf_kinds, only: dp
  use force_elements, only: force_element_eval, force_element_slots, fe_reaction_count
  use system_drives, only: drive_table, drive_at
  use system_reduction, only: coordinate_reduction, pattern_position
  implicit none
  private
  public :: force_element_table, force_element_forces, force_element_at

  type :: force_element_table
    ! per element a kind, a drive (0: none; the cylinder's length), its parameters
    ! (param_ptr), a force-deflection table (table_ptr; table_kind 0: none), its first slot
    ! (slot_first); per slot a constant and the terms term_ptr(slot) .. term_ptr(slot + 1) - 1
    ! on full coordinates
    integer :: nfel = 0
    integer, allocatable :: kind(:), drive(:), table_kind(:), param_ptr(:), table_ptr(:), &
                            slot_first(:), term_ptr(:), term_dof(:)
    real(dp), allocatable :: params(:), table(:), slot_const(:, :), term_coef(:)
    ! the tangent's positions in the full pattern's values (0: absent) in the loop order of
    ! force_element_forces, element l's from pos_ptr(l); none given: searched
    integer, allocatable :: pos_ptr(:), pos(:)
  end type force_element_table

contains

  !> The force elements at (e_full, v_full, t): their generalized forces added to full_force
  !> (the residual's internal sign), the potential energy, powers(1) the dissipated power
  !> and powers(2) the cylinders' drive power into the system; with values_full the tangent
  !> dF/dq + velocity_factor dF/dq' added on the full pattern (entries outside it: none,
  !> the assembly adds each element's coordinates as one block). info = 5 (a drive failed)
  !> or 10 (an element's points coincide or its table fails).
  subroutine force_element_forces(elements, drives, reduction, t, e_full, v_full, velocity_factor, full_force, &
                                  energy, powers, info, values_full)
    type(force_element_table), intent(in) :: elements
    type(drive_table), intent(in) :: drives
    type(coordinate_reduction), intent(in) :: reduction  ! (its full pattern)
    real(dp), intent(in) :: t, e_full(:), v_full(:), velocity_factor
    real(dp), intent(inout) :: full_force(:)
    real(dp), intent(out) :: energy, powers(2)
    integer, intent(out) :: info
    real(dp), intent(inout), optional :: values_full(:)
    real(dp), allocatable :: force(:, :), stiffness(:, :, :, :), damping(:, :, :, :)
    real(dp) :: el_energy, el_dissipation, el_power, reaction(fe_reaction_count)
    integer :: l, ns, s, w, k, m, i, j, row, col, pos, slot_s, slot_w, next
    logical :: known
    energy = 0.0_dp
    powers = 0.0_dp
    info = 0
    if (elements%nfel == 0) return
    ! one work space for every element, sized for the kind with the most slots
    ns = maxval([(force_element_slots(elements%kind(l)), l = 1, elements%nfel)])
    allocate (force(3, ns), stiffness(3, ns, 3, ns), damping(3, ns, 3, ns))
    do l = 1, elements%nfel
      ns = force_element_slots(elements%kind(l))
      call force_element_at(elements, drives, l, t, e_full, v_full, force(:, 1:ns), &
                            stiffness(:, 1:ns, :, 1:ns), damping(:, 1:ns, :, 1:ns), el_energy, &
                            el_dissipation, el_power, reaction, info)
      if (info /= 0) return
      energy = energy + el_energy
      powers = powers + [el_dissipation, el_power]
      do s = 1, ns
        slot_s = elements%slot_first(l) + s - 1
        do k = elements%term_ptr(slot_s), elements%term_ptr(slot_s + 1) - 1
          row = elements%term_dof(k)
          full_force(row:row + 2) = full_force(row:row + 2) + elements%term_coef(k) * force(:, s)
        end do
      end do
      if (present(values_full)) then
        stiffness(:, 1:ns, :, 1:ns) = stiffness(:, 1:ns, :, 1:ns) &
                                      + velocity_factor * damping(:, 1:ns, :, 1:ns)
        known = .false.
        if (allocated(elements%pos_ptr)) known = elements%pos_ptr(l + 1) > elements%pos_ptr(l)
        next = 0
        if (known) next = elements%pos_ptr(l)
        do s = 1, ns
          slot_s = elements%slot_first(l) + s - 1
          do w = 1, ns
            slot_w = elements%slot_first(l) + w - 1
            do k = elements%term_ptr(slot_s), elements%term_ptr(slot_s + 1) - 1
              do m = elements%term_ptr(slot_w), elements%term_ptr(slot_w + 1) - 1
                do i = 1, 3
                  row = elements%term_dof(k) + i - 1
                  do j = 1, 3
                    if (known) then
                      pos = elements%pos(next)
                      next = next + 1
                    else
                      col = elements%term_dof(m) + j - 1
                      pos = pattern_position(reduction, row, col)
                    end if
                    if (pos > 0) values_full(pos) = values_full(pos) + elements%term_coef(k) &
                                                    * elements%term_coef(m) * stiffness(i, s, j, w)
                  end do
                end do
              end do
            end do
          end do
        end do
      end if
    end do
  end subroutine force_element_forces

  !> Force element l at (e_full, v_full, t): its slots gathered, its drive evaluated (the
  !> cylinder's nominal length), force_elements' evaluation. info = 5 (drive) or 10.
  subroutine force_element_at(elements, drives, l, t, e_full, v_full, force, stiffness, damping, energy, &
                              dissipation, drive_power, reaction, info)
    type(force_element_table), intent(in) :: elements
    type(drive_table), intent(in) :: drives
    integer, intent(in) :: l
    real(dp), intent(in) :: t, e_full(:), v_full(:)
    real(dp), intent(out) :: force(:, :), stiffness(:, :, :, :), damping(:, :, :, :)
    real(dp), intent(out) :: energy, dissipation, drive_power, reaction(:)
    integer, intent(out) :: info
    real(dp) :: x(3, size(force, 2)), xd(3, size(force, 2)), length, length_rate, ddl
    integer :: s, k, slot, dof
    info = 0
    length = 0.0_dp
    length_rate = 0.0_dp
    if (elements%drive(l) > 0) then
      call drive_at(drives, elements%drive(l), t, &
                       length, length_rate, ddl, info)
      if (info /= 0) then
        info = 5
        return
      end if
    end if
    do s = 1, size(force, 2)
      slot = elements%slot_first(l) + s - 1
      x(:, s) = elements%slot_const(:, slot)
      xd(:, s) = 0.0_dp
      do k = elements%term_ptr(slot), elements%term_ptr(slot + 1) - 1
        dof = elements%term_dof(k)
        x(:, s) = x(:, s) + elements%term_coef(k) * e_full(dof:dof + 2)
        xd(:, s) = xd(:, s) + elements%term_coef(k) * v_full(dof:dof + 2)
      end do
    end do
    call force_element_eval(elements%kind(l), &
                            elements%params(elements%param_ptr(l):elements%param_ptr(l + 1) - 1), &
                            elements%table_kind(l), &
                            elements%table(elements%table_ptr(l):elements%table_ptr(l + 1) - 1), &
                            x, xd, length, length_rate, force, stiffness, damping, energy, &
                            dissipation, drive_power, reaction, info)
    if (info /= 0) info = 10
  end subroutine force_element_at

end module system_force_elements
