!> The loads of a mechanical system (a component of system_model): constant loads and
!> driven forces phi_d(t) f_d on the independent coordinates, dead moments on director
!> coordinates of the full vector, and driven and follower point loads (vector_loads); the
!> forces, the point loads' Jacobian and the dead moments' potential. A load may be fixed:
!> kept at its value whatever the load factor (buckling's fixed loads, e.g. gravity, beside
!> the reference loads the factor scales; load_scale). No I/O.
module system_loads
  use ancf_kinds, only: dp
  use section_moment, only: moment_force, moment_force_only, moment_angle
  use vector_loads, only: vector_load_force
  use system_drives, only: drive_table, drive_at
  use system_reduction, only: coordinate_reduction, pattern_position, row_terms, reduced_col, &
                              reduced_coef, full_at
  implicit none
  private
  public :: load_set, vector_load_forces, vector_load_tangent, dead_moment_forces, &
            dead_moment_energy, moment_pattern_size, moment_pattern, moment_tangent, &
            load_scale

  type :: load_set
    ! constant (reduced; fixed_force: its fixed share), driven forces phi_d(t) f_d
    ! (reduced), dead moments on full director coordinates (axis, magnitude, the director
    ! at t = 0 for the potential); force_fixed, moment_fixed, vload_fixed: the fixed loads
    real(dp), allocatable :: constant_force(:), fixed_force(:)
    integer, allocatable :: force_drive(:)
    real(dp), allocatable :: force_vectors(:, :)
    logical, allocatable :: force_fixed(:)
    integer, allocatable :: moment_dofs(:, :)
    real(dp), allocatable :: moment_axis(:, :), moment_magnitude(:), moment_reference(:, :)
    logical, allocatable :: moment_fixed(:)
    ! driven and follower point loads (vector_loads): per load a kind, a drive (0: none), a
    ! vector, the torsion shares, and the terms of its slots a, b, p on full coordinates
    ! (vload_ptr(3 (l - 1) + s) .. vload_ptr(3 (l - 1) + s + 1) - 1)
    integer :: nvload = 0
    integer, allocatable :: vload_kind(:), vload_drive(:), vload_ptr(:), vload_dof(:)
    real(dp), allocatable :: vload_vector(:, :), vload_shares(:, :), vload_coef(:)
    logical, allocatable :: vload_fixed(:)
  end type load_set

contains

  !> The factor a load is applied with at the load factor load_factor: 1 for a fixed load
  !> (kept at its value), load_factor for the others.
  pure real(dp) function load_scale(fixed, load_factor) result(scale)
    logical, intent(in) :: fixed
    real(dp), intent(in) :: load_factor
    scale = load_factor
    if (fixed) scale = 1.0_dp
  end function load_scale

  !> The dead moments (times load_factor; the fixed ones at their value) at the full coordinates e_full subtracted from
  !> full_force (the residual's internal sign); the force alone: the moment's Jacobian is
  !> not part of the tangent. info = 6: a moment is undefined.
  subroutine dead_moment_forces(loads, e_full, load_factor, full_force, info)
    type(load_set), intent(in) :: loads
    real(dp), intent(in) :: e_full(:), load_factor
    real(dp), intent(inout) :: full_force(:)
    integer, intent(out) :: info
    real(dp) :: director(3), moment(3)
    integer :: m, k
    info = 0
    do m = 1, size(loads%moment_magnitude)
      ! (the director gathered and the force scattered by loops: vector subscripts made heap
      ! temporaries)
      do k = 1, 3
        director(k) = e_full(loads%moment_dofs(k, m))
      end do
      call moment_force_only(director, loads%moment_axis(:, m), &
                             load_scale(loads%moment_fixed(m), load_factor) &
                             * loads%moment_magnitude(m), moment, info)
      if (info /= 0) then
        info = 6
        return
      end if
      do k = 1, 3
        full_force(loads%moment_dofs(k, m)) = full_force(loads%moment_dofs(k, m)) - moment(k)
      end do
    end do
  end subroutine dead_moment_forces

  !> The dead moments' potential at the full coordinates e_full.
  pure real(dp) function dead_moment_energy(loads, e_full) result(energy)
    type(load_set), intent(in) :: loads
    real(dp), intent(in) :: e_full(:)
    real(dp) :: director(3)
    integer :: m, k
    energy = 0.0_dp
    do m = 1, size(loads%moment_magnitude)
      do k = 1, 3  ! (gathered by a loop: a vector subscript made a heap temporary)
        director(k) = e_full(loads%moment_dofs(k, m))
      end do
      energy = energy - loads%moment_magnitude(m) * &
        moment_angle(director, loads%moment_axis(:, m), loads%moment_reference(:, m))
    end do
  end function dead_moment_energy

  !> The driven and follower point loads at the full coordinates e_full and time t, times
  !> load_factor (the fixed ones at their value), added to full_force. info = 5 when a drive fails, 6 for a malformed load.
  subroutine vector_load_forces(loads, drives, t, e_full, load_factor, full_force, info)
    type(load_set), intent(in) :: loads
    type(drive_table), intent(in) :: drives
    real(dp), intent(in) :: t, e_full(:), load_factor
    real(dp), intent(inout) :: full_force(:)
    integer, intent(out) :: info
    real(dp) :: force(3, 3), jacobian(3, 3, 3, 2)
    integer :: l, s, k, dof
    info = 0
    do l = 1, loads%nvload
      call vector_load_at(loads, drives, l, t, e_full, load_factor, force, jacobian, info)
      if (info /= 0) return
      do s = 1, 3
        do k = loads%vload_ptr(3 * (l - 1) + s), loads%vload_ptr(3 * (l - 1) + s + 1) - 1
          dof = loads%vload_dof(k)
          full_force(dof:dof + 2) = full_force(dof:dof + 2) + loads%vload_coef(k) * force(:, s)
        end do
      end do
    end do
  end subroutine vector_load_forces

  !> Minus the Jacobian of the driven and follower point loads at (e_full, t), times
  !> load_factor, added to values_full (the full pattern): the residual carries
  !> internal - external. Entries outside the pattern (none: a load's slots lie in one
  !> element or node) are skipped. info = 5 when a drive fails, 6 for a malformed load.
  subroutine vector_load_tangent(loads, drives, reduction, t, e_full, load_factor, values_full, info)
    type(load_set), intent(in) :: loads
    type(drive_table), intent(in) :: drives
    type(coordinate_reduction), intent(in) :: reduction  ! (its full pattern)
    real(dp), intent(in) :: t, e_full(:), load_factor
    real(dp), intent(inout) :: values_full(:)
    integer, intent(out) :: info
    real(dp) :: force(3, 3), jacobian(3, 3, 3, 2)
    integer :: l, s, w, k, m, i, j, row, col, pos, base
    info = 0
    do l = 1, loads%nvload
      call vector_load_at(loads, drives, l, t, e_full, load_factor, force, jacobian, info)
      if (info /= 0) return
      do s = 1, 3
        do k = loads%vload_ptr(3 * (l - 1) + s), loads%vload_ptr(3 * (l - 1) + s + 1) - 1
          do w = 1, 2
            base = 3 * (l - 1) + w
            do m = loads%vload_ptr(base), loads%vload_ptr(base + 1) - 1
              do i = 1, 3
                row = loads%vload_dof(k) + i - 1
                do j = 1, 3
                  col = loads%vload_dof(m) + j - 1
                  pos = pattern_position(reduction, row, col)
                  if (pos > 0) values_full(pos) = values_full(pos) - loads%vload_coef(k) &
                                                  * loads%vload_coef(m) * jacobian(i, s, j, w)
                end do
              end do
            end do
          end do
        end do
      end do
    end do
  end subroutine vector_load_tangent

  !> Load l of the driven and follower point loads at (e_full, t), times load_factor (a
  !> fixed load at its value): its
  !> generalized forces on its slots (a, b, p) and their Jacobian (vector_loads). info = 5
  !> when its drive fails, 6 for a malformed load.
  subroutine vector_load_at(loads, drives, l, t, e_full, load_factor, force, jacobian, info)
    type(load_set), intent(in) :: loads
    type(drive_table), intent(in) :: drives
    integer, intent(in) :: l
    real(dp), intent(in) :: t, e_full(:), load_factor
    real(dp), intent(out) :: force(3, 3), jacobian(3, 3, 3, 2)
    integer, intent(out) :: info
    real(dp) :: phi, dphi, ddphi, x(3, 2)
    integer :: s, k, dof
    info = 0
    phi = 1.0_dp
    if (loads%vload_drive(l) > 0) then
      call drive_at(drives, loads%vload_drive(l), &
                       t, phi, dphi, ddphi, info)
      if (info /= 0) then
        info = 5
        return
      end if
    end if
    x = 0.0_dp
    do s = 1, 2
      do k = loads%vload_ptr(3 * (l - 1) + s), loads%vload_ptr(3 * (l - 1) + s + 1) - 1
        dof = loads%vload_dof(k)
        x(:, s) = x(:, s) + loads%vload_coef(k) * e_full(dof:dof + 2)
      end do
    end do
    call vector_load_force(loads%vload_kind(l), &
                           load_scale(loads%vload_fixed(l), load_factor) * phi &
                           * loads%vload_vector(:, l), &
                           loads%vload_shares(:, l), x(:, 1), x(:, 2), force, jacobian, info)
    if (info /= 0) info = 6
  end subroutine vector_load_at

  !> The entries of the dead moments' Jacobian on the independent coordinates e (each pair
  !> of a moment's director components, every pair of the coordinates their full
  !> coordinates depend on: q = B e + q0).
  pure integer function moment_pattern_size(loads, reduction) result(nmom)
    type(load_set), intent(in) :: loads
    type(coordinate_reduction), intent(in) :: reduction
    integer :: m, i, j
    nmom = 0
    do m = 1, size(loads%moment_magnitude)
      do i = 1, 3
        do j = 1, 3
          nmom = nmom + row_terms(reduction, loads%moment_dofs(i, m)) &
                      * row_terms(reduction, loads%moment_dofs(j, m))
        end do
      end do
    end do
  end function moment_pattern_size

  !> The rows and columns (reduced coordinates) of the dead moments' Jacobian entries in the
  !> order of moment_tangent (moment_pattern_size of them; duplicates summed by the caller).
  pure subroutine moment_pattern(loads, reduction, rows, cols)
    type(load_set), intent(in) :: loads
    type(coordinate_reduction), intent(in) :: reduction
    integer, intent(out) :: rows(:), cols(:)
    integer :: m, i, j, a, b, k
    k = 0
    do m = 1, size(loads%moment_magnitude)
      do i = 1, 3
        do j = 1, 3
          do a = 1, row_terms(reduction, loads%moment_dofs(i, m))
            do b = 1, row_terms(reduction, loads%moment_dofs(j, m))
              k = k + 1
              rows(k) = reduced_col(reduction, loads%moment_dofs(i, m), a)
              cols(k) = reduced_col(reduction, loads%moment_dofs(j, m), b)
            end do
          end do
        end do
      end do
    end do
  end subroutine moment_pattern

  !> Minus the dead moments' Jacobian (times load_factor; the fixed ones at their value) at e on the independent
  !> coordinates, the entries of moment_pattern (the residual carries minus the external
  !> forces). info = 6: a moment is undefined.
  subroutine moment_tangent(loads, reduction, e, load_factor, values, info)
    type(load_set), intent(in) :: loads
    type(coordinate_reduction), intent(in) :: reduction
    real(dp), intent(in) :: e(:), load_factor
    real(dp), intent(out) :: values(:)
    integer, intent(out) :: info
    real(dp) :: moment(3), jacobian(3, 3), hessian(3, 3, 3)
    integer :: m, i, j, a, b, k
    info = 0
    k = 0
    do m = 1, size(loads%moment_magnitude)
      call moment_force(full_at(reduction, e, loads%moment_dofs(:, m)), &
                        loads%moment_axis(:, m), &
                        load_scale(loads%moment_fixed(m), load_factor) * loads%moment_magnitude(m), &
                        moment, jacobian, hessian, info)
      if (info /= 0) then
        info = 6
        return
      end if
      do i = 1, 3
        do j = 1, 3
          do a = 1, row_terms(reduction, loads%moment_dofs(i, m))
            do b = 1, row_terms(reduction, loads%moment_dofs(j, m))
              k = k + 1
              values(k) = -jacobian(i, j) * reduced_coef(reduction, loads%moment_dofs(i, m), a) &
                          * reduced_coef(reduction, loads%moment_dofs(j, m), b)
            end do
          end do
        end do
      end do
    end do
  end subroutine moment_tangent

end module system_loads
