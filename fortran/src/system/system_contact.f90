!> The contact of a mechanical system (a component of system_model): pairs of plates whose
!> points on one surface are searched on the other's mid-surface (leaf_contact), the state
!> contact carries from iteration to iteration, the contact forces with their Jacobian on
!> the full pattern, and the step limit contact puts on a Newton correction. No I/O.
module system_contact
  use ancf_kinds, only: dp
  use leaf_contact, only: contact_assemble, cp_count, contact_counters, contact_record, &
                          cp_upper_thickness, cp_lower_thickness
  use system_reduction, only: coordinate_reduction
  implicit none
  private
  public :: contact_set, contact_pair, contact_state, contact_record, contact_forces, &
            contact_step_limit

  !> Points on one plate surface searched on another's mid-surface (leaf_contact). Element
  !> columns 1..nel of dofs: the upper body's grid elements and the points' elements.
  type :: contact_pair
    integer :: nel = 0, npoint = 0, first_point = 0
    integer, allocatable :: dofs(:, :), grid(:, :), point_element(:)
    real(dp), allocatable :: sizes(:, :), point_local(:, :)
    real(dp) :: params(cp_count) = 0.0_dp
  end type contact_pair

  !> What contact carries from iteration to iteration and step to step.
  type :: contact_state
    real(dp), allocatable :: guesses(:, :)     ! (2, npoint) leaf-level projections
    integer :: counts(contact_counters) = 0
  end type contact_state

  !> Every pair (npoint points in all, pair p's from pairs(p)%first_point + 1).
  type :: contact_set
    integer :: npoint = 0
    type(contact_pair), allocatable :: pairs(:)
  end type contact_set

contains

  !> Contact forces of every pair subtracted from full_force (they are external: the
  !> residual carries elastic minus contact), with the Jacobian of minus the forces added
  !> to values_full when allocated. info = 7 (normal vanished) or 8 (projection failed).
  subroutine contact_forces(contact, reduction, e_full, v_full, velocity_factor, state, full_force, records, &
                            potential, powers, info, values_full)
    type(contact_set), intent(in) :: contact
    type(coordinate_reduction), intent(in) :: reduction  ! (its full pattern)
    real(dp), intent(in) :: e_full(:), v_full(:), velocity_factor
    type(contact_state), intent(inout) :: state
    real(dp), intent(inout) :: full_force(:)
    real(dp), intent(out) :: records(:, :), potential, powers(2)
    integer, intent(out) :: info
    real(dp), allocatable, intent(inout) :: values_full(:)
    real(dp), allocatable :: pair_force(:)
    real(dp) :: pair_potential, pair_powers(2)
    integer :: p, first, last
    potential = 0.0_dp
    powers = 0.0_dp
    info = 0
    allocate (pair_force(size(full_force)))
    do p = 1, size(contact%pairs)
      first = contact%pairs(p)%first_point + 1
      last = contact%pairs(p)%first_point + contact%pairs(p)%npoint
      pair_force = 0.0_dp
      if (allocated(values_full)) then
        call contact_assemble(e_full, v_full, contact%pairs(p)%dofs, contact%pairs(p)%sizes, &
                              contact%pairs(p)%grid, contact%pairs(p)%point_element, &
                              contact%pairs(p)%point_local, contact%pairs(p)%params, velocity_factor, &
                              state%guesses(:, first:last), pair_force, records(:, first:last), &
                              pair_potential, pair_powers, state%counts, info, reduction%full_ptr, &
                              reduction%full_col, values_full)
      else
        call contact_assemble(e_full, v_full, contact%pairs(p)%dofs, contact%pairs(p)%sizes, &
                              contact%pairs(p)%grid, contact%pairs(p)%point_element, &
                              contact%pairs(p)%point_local, contact%pairs(p)%params, velocity_factor, &
                              state%guesses(:, first:last), pair_force, records(:, first:last), &
                              pair_potential, pair_powers, state%counts, info)
      end if
      if (info /= 0) return
      full_force = full_force - pair_force
      potential = potential + pair_potential
      powers = powers + pair_powers
    end do
  end subroutine contact_forces

  !> The contact step limit: half the thinnest leaf of any contact pair (huge without
  !> contact). No Newton correction of the stepper moves a coordinate further (a contact
  !> open at the linearization point has no stiffness there, and a full step would jump far
  !> through the other leaf), and the predictor of a contact system moves on at constant
  !> velocity only while no coordinate moves further in the step.
  pure real(dp) function contact_step_limit(contact) result(limit)
    type(contact_set), intent(in) :: contact
    integer :: pair
    limit = huge(1.0_dp)
    do pair = 1, size(contact%pairs)
      limit = min(limit, 0.5_dp * contact%pairs(pair)%params(cp_upper_thickness), &
                  0.5_dp * contact%pairs(pair)%params(cp_lower_thickness))
    end do
  end function contact_step_limit

end module system_contact
