!> Elastic forces of the ANCF-FFR model (seed 000, eqs. 13-21): the constant element
!> stiffness K0 lives in the floating frame A; with T = blockdiag(A, ..., A),
!>   Q_el = T K0 (T^T e - e0),   K = T K0 T^T,   U = 1/2 (T^T e - e0)^T K0 (T^T e - e0),
!> where e0 is the rigid (reference) configuration expressed in the frame (per element,
!> reference(24, nel)). A rigid translation of the frame's origin changes T^T e - e0 by a
!> uniform translation of the position vectors, which K0 annihilates: only the frame's
!> rotation enters.
!>
!> Kelvin-Voigt material damping (retardation time tau) on the linear strain in the frame:
!> with the frame's angular velocity omega (A' = [omega]x A; omega_l = A^T omega in the
!> frame), each nodal vector's rate in the frame is x'_a = A^T e'_a - omega_l x (A^T e_a)
!> (the pivot's share, omega_l x A^T p on the positions, is a uniform translation rate that
!> K0 annihilates), and
!>   Q_d = tau T K0 x',   power tau x'^T K0 x' >= 0,
!> zero for a rigid motion. dQ_d/de' = tau T K0 T^T, dQ_d/de = -tau T K0 T^T [omega]x per
!> vector (= -tau T K0 [omega_l]x T^T): the combined tangent block of a pair of nodal
!> vectors is A K0_ab ((1 + c tau) I - tau [omega_l]x) A^T.
!>
!> Geometric stiffness (P-delta, optional per set: `second_order`). Each element (length L,
!> unit axis t in the frame, axial rigidity EA) carries the axial force of its mean linear
!> axial strain, N = EA t . (u_rB - u_rA) / L, read from the current frame displacement u at
!> every force evaluation, and adds the force of the initial-stress (geometric) stiffness
!>   f_2 = N (G (x) I3) u,   G_ab = int S_a' S_b' dx
!> over the centre-line shape functions (compact 8 x 8, zero on the r_y, r_z slots): the
!> work of N on the centre line's slopes, N int u' . du' dx. Its tangent is taken as
!> N (G (x) I3) (the part from dN/du, (G u) EA t / L, is left out: modified Newton). The
!> reported energy is U_2 = N u^T (G (x) I3) u / 2 (with N frozen, f_2 = dU_2/du): the
!> force is not exactly conservative, the balance misses the work of the left-out part,
!> which is third order in u. Why not the Green strain's (eps + eta)^2 with the shortening
!> of a bent element: with the C1 axial field of ANCF (r_x shared by neighbours) the mean
!> Green strain of every element is forced to one value and the bending locks (a 9-node
!> cantilever 2.4% too stiff at a tip rotation of 0.05 rad).
!> The tangent with N (G (x) I3) is added where tangents are asked for (statics, the
!> refactorizing policies; the constant policy's one factorization takes it at its state).
!>
!> ffr_set: the family's element set (element_sets), the elements of one body in its frame.
module ffr_elastic
  use ancf_kinds, only: dp
  use element_sets, only: element_set, frame_omega, scatter_add
  use beam_stations, only: station_section, station_map, small_station_map
  implicit none
  private
  public :: ffr_force, ffr_stiffness, ffr_energy_power, ffr_set, ffr_second_order
  public :: ffr_enable_second_order, ffr_departures

  !> ANCF-FFR beam elements: K0 (24, 24, nel) and the rigid configuration in the body's
  !> floating frame (24, nel). With second_order, the geometric stiffness of the current
  !> axial force (module doc): per element EA (axial_rigidity), the unit axis in the frame
  !> (axis(3, nel)), the length and the centre-line slope Gram matrix G (slope_gram(8, 8, nel)).
  type, extends(element_set) :: ffr_set
    real(dp), allocatable :: stiffness0(:, :, :), reference(:, :)
    logical :: second_order = .false.
    real(dp), allocatable :: axial_rigidity(:), axis(:, :), length(:), slope_gram(:, :, :)
    !> the section data of its section forces (beam_stations)
    type(station_section) :: sections
    !> its section forces' linear forms at the stations last asked for (built on first use),
    !> and its elements' distinct nodal vectors: their dofs (3, nv) and each element's
    !> (element_vector(8, nel)), turned into the frame once per row
    type(station_map) :: stations
    integer, allocatable :: vector_dofs(:, :), element_vector(:, :)
  contains
    procedure :: forces => ffr_set_forces
    procedure :: energy_power => ffr_set_energy_power
    procedure :: section_forces => ffr_section_forces
  end type ffr_set

contains

  !> Frame coordinates A^T e_a - e0_a of one element's eight nodal vectors.
  pure function frame_displacement(rotation, e, dofs, reference) result(local)
    real(dp), intent(in) :: rotation(3, 3), e(:), reference(24)
    integer, intent(in) :: dofs(24)
    real(dp) :: local(24)
    real(dp) :: x1, x2, x3
    integer :: a
    do a = 0, 7
      ! (A^T v)_j = A(1, j) v_1 + A(2, j) v_2 + A(3, j) v_3, in scalars (as an array
      ! expression over j, ~80 instructions a vector)
      x1 = e(dofs(3 * a + 1))
      x2 = e(dofs(3 * a + 2))
      x3 = e(dofs(3 * a + 3))
      local(3 * a + 1) = rotation(1, 1) * x1 + rotation(2, 1) * x2 + rotation(3, 1) * x3
      local(3 * a + 2) = rotation(1, 2) * x1 + rotation(2, 2) * x2 + rotation(3, 2) * x3
      local(3 * a + 3) = rotation(1, 3) * x1 + rotation(2, 3) * x2 + rotation(3, 3) * x3
    end do
    local = local - reference
  end function frame_displacement

  !> Rates x'_a = A^T e'_a - omega_l x (A^T e_a) of one element's eight nodal vectors in the
  !> frame (omega_l: the frame's angular velocity in the frame).
  pure function frame_rate(rotation, omega_local, e, v, dofs) result(rate)
    real(dp), intent(in) :: rotation(3, 3), omega_local(3), e(:), v(:)
    integer, intent(in) :: dofs(24)
    real(dp) :: rate(24)
    real(dp) :: x(3)
    integer :: a
    do a = 0, 7
      x = rotation(1, :) * e(dofs(3 * a + 1)) + rotation(2, :) * e(dofs(3 * a + 2)) &
          + rotation(3, :) * e(dofs(3 * a + 3))
      rate(3 * a + 1:3 * a + 3) = rotation(1, :) * v(dofs(3 * a + 1)) &
                                  + rotation(2, :) * v(dofs(3 * a + 2)) &
                                  + rotation(3, :) * v(dofs(3 * a + 3)) &
                                  - [omega_local(2) * x(3) - omega_local(3) * x(2), &
                                     omega_local(3) * x(1) - omega_local(1) * x(3), &
                                     omega_local(1) * x(2) - omega_local(2) * x(1)]
    end do
  end function frame_rate

  !> Adds the global elastic force to force and returns the strain energy; dofs(24, nel)
  !> are 1-based indices into e and force. With the coordinate rates v (and omega_local,
  !> the frame's angular velocity in the frame, and damping_time tau > 0) the Kelvin-Voigt
  !> damping force too: T K0 (u + tau x'), and dissipation returns tau x'^T K0 x'.
  pure subroutine ffr_force(nel, dofs, stiffness0, reference, rotation, e, force, energy, v, &
                            omega_local, damping_time, dissipation)
    integer, intent(in) :: nel, dofs(24, nel)
    real(dp), intent(in) :: stiffness0(24, 24, nel), reference(24, nel), rotation(3, 3), e(:)
    real(dp), intent(inout) :: force(:)
    real(dp), intent(out) :: energy
    real(dp), intent(in), optional :: v(:), omega_local(3), damping_time
    real(dp), intent(out), optional :: dissipation
    real(dp) :: local_disp(24), local_force(24), local_rate(24), damping_force(24)
    logical :: damped
    integer :: el
    damped = present(v)
    energy = 0.0_dp
    if (present(dissipation)) dissipation = 0.0_dp
    do el = 1, nel
      local_disp = frame_displacement(rotation, e, dofs(:, el), reference(:, el))
      local_force = matmul(stiffness0(:, :, el), local_disp)
      energy = energy + 0.5_dp * dot_product(local_disp, local_force)
      if (damped) then
        local_rate = frame_rate(rotation, omega_local, e, v, dofs(:, el))
        damping_force = damping_time * matmul(stiffness0(:, :, el), local_rate)
        dissipation = dissipation + dot_product(local_rate, damping_force)
        local_force = local_force + damping_force
      end if
      call add_global_force(rotation, local_force, dofs(:, el), force)
    end do
  end subroutine ffr_force

  !> Strain energy and the power of the moving frame at fixed e, dU/dt = -phi' sum_b
  !> f_b . (k x x_b) with f = K0 u in the frame, u = T^T e - e0, x = T^T e (k: the unit axis
  !> of the frame's rotation, rate = phi').
  !> With v (the coordinate rates), omega_local and damping_time tau > 0 the frame's power
  !> adds that of the damping force, -sum_b (tau K0 x')_b . (omega_l x x_b) (the frame turns
  !> under the total force, so the balance closes with total + dissipated work), and
  !> dissipation returns tau x'^T K0 x'; otherwise dissipation is 0.
  pure subroutine ffr_energy_power(nel, dofs, stiffness0, reference, rotation, axis, rate, e, &
                                   energy, power, v, omega_local, damping_time, dissipation)
    integer, intent(in) :: nel, dofs(24, nel)
    real(dp), intent(in) :: stiffness0(24, 24, nel), reference(24, nel), rotation(3, 3)
    real(dp), intent(in) :: axis(3), rate, e(:)
    real(dp), intent(out) :: energy, power
    real(dp), intent(in), optional :: v(:), omega_local(3), damping_time
    real(dp), intent(out), optional :: dissipation
    real(dp) :: local(24), frame_force(24), x(3), k(3), local_rate(24), damping_force(24)
    real(dp) :: w(3)
    logical :: damped
    integer :: el, b
    damped = .false.
    if (present(v)) damped = damping_time > 0.0_dp
    if (present(dissipation)) dissipation = 0.0_dp
    energy = 0.0_dp
    power = 0.0_dp
    k = axis / norm2(axis)
    do el = 1, nel
      local = frame_displacement(rotation, e, dofs(:, el), reference(:, el))
      frame_force = matmul(stiffness0(:, :, el), local)
      energy = energy + 0.5_dp * dot_product(local, frame_force)
      if (damped) then
        local_rate = frame_rate(rotation, omega_local, e, v, dofs(:, el))
        damping_force = damping_time * matmul(stiffness0(:, :, el), local_rate)
        if (present(dissipation)) dissipation = dissipation + dot_product(local_rate, damping_force)
        w = omega_local
        do b = 0, 7
          x = local(3 * b + 1:3 * b + 3) + reference(3 * b + 1:3 * b + 3, el)
          power = power - dot_product(damping_force(3 * b + 1:3 * b + 3), &
                  [w(2) * x(3) - w(3) * x(2), w(3) * x(1) - w(1) * x(3), w(1) * x(2) - w(2) * x(1)])
        end do
      end if
      if (rate == 0.0_dp) cycle
      do b = 0, 7
        x = local(3 * b + 1:3 * b + 3) + reference(3 * b + 1:3 * b + 3, el)
        power = power - rate * dot_product(frame_force(3 * b + 1:3 * b + 3), &
                [k(2) * x(3) - k(3) * x(2), k(3) * x(1) - k(1) * x(3), k(1) * x(2) - k(2) * x(1)])
      end do
    end do
  end subroutine ffr_energy_power

  !> Element stiffness matrices in the global frame, T K0 T^T, block by block. Damped
  !> (damping_time tau > 0 given, with omega_local and rate_factor c): the combined tangents
  !> dQ/de + c dQ/de', blocks A K0_ab ((1 + c tau) I - tau [omega_l]x) A^T (omega_l = 0: the
  !> stiffness (1 + c tau) T K0 T^T alone).
  pure subroutine ffr_stiffness(nel, stiffness0, rotation, stiffness, omega_local, rate_factor, &
                                damping_time)
    integer, intent(in) :: nel
    real(dp), intent(in) :: stiffness0(24, 24, nel), rotation(3, 3)
    real(dp), intent(out) :: stiffness(24, 24, nel)
    real(dp), intent(in), optional :: omega_local(3), rate_factor, damping_time
    real(dp) :: right(3, 3), turn(3, 3)
    integer :: el, a, b, i
    if (present(damping_time)) then
      ! right = ((1 + c tau) I - tau [omega_l]x) A^T
      turn = 0.0_dp
      turn(2, 1) = omega_local(3)
      turn(3, 1) = -omega_local(2)
      turn(1, 2) = -omega_local(3)
      turn(3, 2) = omega_local(1)
      turn(1, 3) = omega_local(2)
      turn(2, 3) = -omega_local(1)
      turn = -damping_time * turn
      do i = 1, 3
        turn(i, i) = turn(i, i) + 1.0_dp + rate_factor * damping_time
      end do
      right = matmul(turn, transpose(rotation))
    else
      right = transpose(rotation)
    end if
    do el = 1, nel
      do b = 0, 7
        do a = 0, 7
          stiffness(3 * a + 1:3 * a + 3, 3 * b + 1:3 * b + 3, el) = matmul(rotation, &
            matmul(stiffness0(3 * a + 1:3 * a + 3, 3 * b + 1:3 * b + 3, el), right))
        end do
      end do
    end do
  end subroutine ffr_stiffness

  !> force(dofs) += T f for the frame force f (24) of one element, T = blockdiag(A, ..., A).
  pure subroutine add_global_force(rotation, local_force, element_dofs, force)
    real(dp), intent(in) :: rotation(3, 3), local_force(24)
    integer, intent(in) :: element_dofs(24)
    real(dp), intent(inout) :: force(:)
    integer :: a, i
    do a = 0, 7
      do i = 1, 3
        force(element_dofs(3 * a + i)) = force(element_dofs(3 * a + i)) &
                                         + rotation(i, 1) * local_force(3 * a + 1) &
                                         + rotation(i, 2) * local_force(3 * a + 2) &
                                         + rotation(i, 3) * local_force(3 * a + 3)
      end do
    end do
  end subroutine add_global_force

  !> The element_set forces of an FFR set: the frame rotation in the force, tangent_rotation
  !> (default rotation) in the tangents T K0 T^T; damped, the frame's angular velocities.
  subroutine ffr_set_forces(set, rotation, e, force, energy, info, tangent_values, &
                            tangent_rotation, v, omega_local, rate_factor, dissipation, &
                            tangent_omega)
    class(ffr_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), e(:)
    real(dp), intent(inout) :: force(:)
    real(dp), intent(out) :: energy
    integer, intent(out) :: info
    real(dp), intent(inout), optional :: tangent_values(:)
    real(dp), intent(in), optional :: tangent_rotation(3, 3)
    real(dp), intent(in), optional :: v(:), omega_local(3), rate_factor, tangent_omega(3)
    real(dp), intent(out), optional :: dissipation
    real(dp), allocatable :: stiffness(:, :, :)
    real(dp) :: omega(3), omega_t(3), factor, power, turned(3, 3)
    logical :: damped
    info = 0
    damped = present(v) .and. set%damping_time > 0.0_dp
    power = 0.0_dp
    if (damped) then
      omega = 0.0_dp
      if (present(omega_local)) omega = omega_local
      omega_t = omega
      if (present(tangent_omega)) omega_t = tangent_omega
      factor = 0.0_dp
      if (present(rate_factor)) factor = rate_factor
      call ffr_force(set%nel, set%dofs, set%stiffness0, set%reference, rotation, e, force, &
                     energy, v, omega, set%damping_time, power)
    else
      call ffr_force(set%nel, set%dofs, set%stiffness0, set%reference, rotation, e, force, &
                     energy)
    end if
    if (set%second_order) call add_second_order(set, rotation, e, force, energy)
    if (present(tangent_values)) then
      turned = rotation
      if (present(tangent_rotation)) turned = tangent_rotation
      allocate (stiffness(24, 24, set%nel))
      if (damped) then
        call ffr_stiffness(set%nel, set%stiffness0, turned, stiffness, omega_t, factor, &
                           set%damping_time)
      else
        call ffr_stiffness(set%nel, set%stiffness0, turned, stiffness)
      end if
      if (set%second_order) call add_second_order_tangent(set, rotation, turned, e, stiffness)
      call scatter_add(set, stiffness, tangent_values)
    end if
    if (present(dissipation)) dissipation = power
  end subroutine ffr_set_forces

  !> The element_set energy_power of an FFR set: ffr_energy_power (the frame's power).
  subroutine ffr_set_energy_power(set, rotation, axis, rate, e, energy, power, info, v, &
                                  dissipation)
    class(ffr_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), axis(3), rate, e(:)
    real(dp), intent(out) :: energy, power
    integer, intent(out) :: info
    real(dp), intent(in), optional :: v(:)
    real(dp), intent(out), optional :: dissipation
    real(dp) :: power_lost
    info = 0
    power_lost = 0.0_dp
    if (present(v) .and. set%damping_time > 0.0_dp) then
      call ffr_energy_power(set%nel, set%dofs, set%stiffness0, set%reference, rotation, &
                            axis, rate, e, energy, power, v, &
                            frame_omega(rotation, axis, rate), set%damping_time, power_lost)
    else
      call ffr_energy_power(set%nel, set%dofs, set%stiffness0, set%reference, rotation, &
                            axis, rate, e, energy, power)
    end if
    if (set%second_order) call add_second_order_power(set, rotation, axis, rate, e, energy, &
                                                      power)
    if (present(dissipation)) dissipation = power_lost
  end subroutine ffr_set_energy_power

  !> Turns on the second-order terms of `set` if it is an FFR set of size(length) elements
  !> (info = 0; else info = 2 and the set is unchanged).
  subroutine ffr_enable_second_order(set, axial_rigidity, axis, length, slope_gram, info)
    class(element_set), intent(inout) :: set
    real(dp), intent(in) :: axial_rigidity(:), axis(:, :), length(:), slope_gram(:, :, :)
    integer, intent(out) :: info
    info = 2
    select type (set)
    type is (ffr_set)
      if (set%nel /= size(length)) return
      set%second_order = .true.
      set%axial_rigidity = axial_rigidity
      set%axis = axis
      set%length = length
      set%slope_gram = slope_gram
      info = 0
    end select
  end subroutine ffr_enable_second_order

  !> The P-delta terms of one element at its frame displacement u (24): the axial force
  !> N = EA eps, the force f_2 = N (G (x) I3) u, the energy U_2 = N u^T (G (x) I3) u / 2 and,
  !> with hessian, N (G (x) I3) (module doc).
  pure subroutine ffr_second_order(axial_rigidity, axis, length, slope_gram, u, energy, &
                                   force, hessian)
    real(dp), intent(in) :: axial_rigidity, axis(3), length, slope_gram(8, 8), u(24)
    real(dp), intent(out) :: energy, force(24)
    real(dp), intent(out), optional :: hessian(24, 24)
    real(dp) :: axial_force
    integer :: a, b, i
    axial_force = axial_rigidity * dot_product(axis, u(13:15) - u(1:3)) / length
    do a = 0, 7
      do i = 1, 3
        force(3 * a + i) = axial_force * sum(slope_gram(a + 1, :) * u(i:24:3))
      end do
    end do
    energy = 0.5_dp * dot_product(force, u)
    if (.not. present(hessian)) return
    hessian = 0.0_dp
    do b = 0, 7
      do a = 0, 7
        do i = 1, 3
          hessian(3 * a + i, 3 * b + i) = axial_force * slope_gram(a + 1, b + 1)
        end do
      end do
    end do
  end subroutine ffr_second_order

  !> Adds the set's second-order forces T f_2 and energies U_2 (rotation: the frame's).
  pure subroutine add_second_order(set, rotation, e, force, energy)
    class(ffr_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), e(:)
    real(dp), intent(inout) :: force(:), energy
    real(dp) :: local(24), local_force(24), element_energy
    integer :: el
    do el = 1, set%nel
      local = frame_displacement(rotation, e, set%dofs(:, el), set%reference(:, el))
      call ffr_second_order(set%axial_rigidity(el), set%axis(:, el), set%length(el), &
                            set%slope_gram(:, :, el), local, element_energy, local_force)
      energy = energy + element_energy
      call add_global_force(rotation, local_force, set%dofs(:, el), force)
    end do
  end subroutine add_second_order

  !> Adds T_t H_2 T_t^T to the element stiffness matrices (H_2 at the state in the frame
  !> `rotation`, turned with `turned`, the tangent's frame).
  pure subroutine add_second_order_tangent(set, rotation, turned, e, stiffness)
    class(ffr_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), turned(3, 3), e(:)
    real(dp), intent(inout) :: stiffness(:, :, :)
    real(dp) :: local(24), local_force(24), element_energy, hessian(24, 24)
    integer :: el, a, b
    do el = 1, set%nel
      local = frame_displacement(rotation, e, set%dofs(:, el), set%reference(:, el))
      call ffr_second_order(set%axial_rigidity(el), set%axis(:, el), set%length(el), &
                            set%slope_gram(:, :, el), local, element_energy, local_force, hessian)
      do b = 0, 7
        do a = 0, 7
          stiffness(3 * a + 1:3 * a + 3, 3 * b + 1:3 * b + 3, el) = &
            stiffness(3 * a + 1:3 * a + 3, 3 * b + 1:3 * b + 3, el) + matmul(turned, &
            matmul(hessian(3 * a + 1:3 * a + 3, 3 * b + 1:3 * b + 3), transpose(turned)))
        end do
      end do
    end do
  end subroutine add_second_order_tangent

  !> Adds U_2 to energy and the frame's power of f_2 at fixed e, -phi' sum_b f_b . (k x x_b)
  !> (as ffr_energy_power for K0 u).
  pure subroutine add_second_order_power(set, rotation, axis, rate, e, energy, power)
    class(ffr_set), intent(in) :: set
    real(dp), intent(in) :: rotation(3, 3), axis(3), rate, e(:)
    real(dp), intent(inout) :: energy, power
    real(dp) :: local(24), local_force(24), element_energy, x(3), k(3)
    integer :: el, b
    k = axis / norm2(axis)
    do el = 1, set%nel
      local = frame_displacement(rotation, e, set%dofs(:, el), set%reference(:, el))
      call ffr_second_order(set%axial_rigidity(el), set%axis(:, el), set%length(el), &
                            set%slope_gram(:, :, el), local, element_energy, local_force)
      energy = energy + element_energy
      if (rate == 0.0_dp) cycle
      do b = 0, 7
        x = local(3 * b + 1:3 * b + 3) + set%reference(3 * b + 1:3 * b + 3, el)
        power = power - rate * dot_product(local_force(3 * b + 1:3 * b + 3), &
                [k(2) * x(3) - k(3) * x(2), k(3) * x(1) - k(1) * x(3), k(1) * x(2) - k(2) * x(1)])
      end do
    end do
  end subroutine add_second_order_power

  !> The small-strain measure of an FFR set at rows of states (solvers/assumptions.py): per
  !> row the largest change of a section vector r_x, r_y, r_z from its reference in the
  !> frame, |A^T r - r0|, over its elements' vectors; a vector a neighbour listed already
  !> (the same dofs and reference: a shared node's) is not measured twice. rotations
  !> (3, 3, nrows): the frame at each row; q_rows (nfull, nrows). Not a number at a row whose
  !> change is not one (also when another vector's is larger). info = 1: `item` is not an
  !> FFR set (departure 0).
  pure subroutine ffr_departures(item, rotations, q_rows, departure, info)
    class(element_set), intent(in) :: item
    real(dp), intent(in) :: rotations(:, :, :), q_rows(:, :)
    real(dp), intent(out) :: departure(:)
    integer, intent(out) :: info
    departure = 0.0_dp
    info = 1
    select type (item)
    type is (ffr_set)
      call set_departures(item, rotations, q_rows, departure)
      info = 0
    end select
  end subroutine ffr_departures

  !> ffr_departures of an FFR set.
  pure subroutine set_departures(set, rotations, q_rows, departure)
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
    type(ffr_set), intent(in) :: set
    real(dp), intent(in) :: rotations(:, :, :), q_rows(:, :)
    real(dp), intent(out) :: departure(:)
    integer, parameter :: directions(6) = [1, 2, 3, 5, 6, 7]   ! r_x, r_y, r_z of both nodes
    logical :: skip(6, set%nel), bad
    real(dp) :: x(3), square, largest, turn(3, 3), v1, v2, v3
    integer :: el, k, a, row
    ! a first node's vector equal to the previous element's second node's (dofs and
    ! reference) is that one: measured once
    skip = .false.
    do el = 2, set%nel
      do k = 1, 3
        a = directions(k)
        skip(k, el) = all(set%dofs(3 * a + 1:3 * a + 3, el) &
                          == set%dofs(3 * a + 13:3 * a + 15, el - 1)) .and. &
                      all(set%reference(3 * a + 1:3 * a + 3, el) &
                          == set%reference(3 * a + 13:3 * a + 15, el - 1))
      end do
    end do
    do row = 1, size(q_rows, 2)
      largest = 0.0_dp
      bad = .false.
      turn = rotations(:, :, row)
      do el = 1, set%nel
        do k = 1, 6
          if (skip(k, el)) cycle
          a = directions(k)
          ! (A^T v)_j = sum_i A(i, j) v_i, as frame_displacement writes it (in scalars)
          v1 = q_rows(set%dofs(3 * a + 1, el), row)
          v2 = q_rows(set%dofs(3 * a + 2, el), row)
          v3 = q_rows(set%dofs(3 * a + 3, el), row)
          x(1) = (turn(1, 1) * v1 + turn(2, 1) * v2 + turn(3, 1) * v3) &
                 - set%reference(3 * a + 1, el)
          x(2) = (turn(1, 2) * v1 + turn(2, 2) * v2 + turn(3, 2) * v3) &
                 - set%reference(3 * a + 2, el)
          x(3) = (turn(1, 3) * v1 + turn(2, 3) * v2 + turn(3, 3) * v3) &
                 - set%reference(3 * a + 3, el)
          square = (x(1) * x(1) + x(2) * x(2)) + x(3) * x(3)
          if (square > largest) largest = square
          if (.not. (square == square)) bad = .true.
        end do
      end do
      departure(row) = sqrt(largest)
      if (bad) departure(row) = ieee_value(1.0_dp, ieee_quiet_nan)
    end do
  end subroutine set_departures

  !> The element_set section_forces of an FFR set: linear forms (beam_stations station_map,
  !> built at the first call with these stations and kept) of each element's displacement in
  !> the frame at each row, A^T e - e0 (frame_displacement's, each distinct nodal vector
  !> turned once: the frame's pivot moves the positions uniformly, which no strain measure
  !> sees).
  subroutine ffr_section_forces(set, rotations, q_rows, xi, forces, info)
    class(ffr_set), intent(inout) :: set
    real(dp), intent(in) :: rotations(:, :, :), q_rows(:, :), xi(:)
    real(dp), intent(out) :: forces(:, :, :)
    integer, intent(out) :: info
    integer, parameter :: block = 32
    real(dp), allocatable :: turned(:, :, :)
    real(dp) :: acc(block), turn(3, 3), x1, x2, x3
    integer :: el, row, ns, v, nv, first, nb, r, k, i, o, p, col, a, c, base
    info = 1
    if (.not. allocated(set%sections%reference)) then
      forces = 0.0_dp
      return
    end if
    info = 0
    ns = size(xi)
    if (allocated(set%stations%xi)) then
      if (size(set%stations%xi) /= ns) deallocate (set%stations%xi)
    end if
    if (allocated(set%stations%xi)) then
      if (any(set%stations%xi /= xi)) deallocate (set%stations%xi)
    end if
    if (.not. allocated(set%stations%xi)) call small_station_map(set%sections, set%nel, xi, &
                                                                 set%stations)
    if (.not. allocated(set%element_vector)) call distinct_vectors(set)
    nv = size(set%vector_dofs, 2)
    allocate (turned(block, 3, nv))
    do first = 1, size(q_rows, 2), block   ! blocks of rows: each product runs over them
      nb = min(block, size(q_rows, 2) - first + 1)
      do r = 1, nb   ! A^T e_v as frame_displacement writes it, turned once per row
        row = first + r - 1
        turn = rotations(:, :, row)
        do v = 1, nv
          ! (A^T x)_j = A(1, j) x_1 + A(2, j) x_2 + A(3, j) x_3, in scalars: the array
          ! expression's loop over j cost ~80 instructions a vector
          x1 = q_rows(set%vector_dofs(1, v), row)
          x2 = q_rows(set%vector_dofs(2, v), row)
          x3 = q_rows(set%vector_dofs(3, v), row)
          turned(r, 1, v) = turn(1, 1) * x1 + turn(2, 1) * x2 + turn(3, 1) * x3
          turned(r, 2, v) = turn(1, 2) * x1 + turn(2, 2) * x2 + turn(3, 2) * x3
          turned(r, 3, v) = turn(1, 3) * x1 + turn(2, 3) * x2 + turn(3, 3) * x3
        end do
      end do
      ! each station's force: the map's form (beam_stations station_map) of the element's
      ! displacement A^T e - e0, each term's coordinate read from the turned vectors (the
      ! same sums in the same order, without the element's copy)
      do el = 1, set%nel
        base = 6 * ns * (el - 1)
        do k = 1, 6
          do i = 1, ns
            o = i + ns * (k - 1)
            acc(:nb) = 0.0_dp
            do p = set%stations%first(base + o), set%stations%first(base + o + 1) - 1
              col = set%stations%col(p)
              a = (col - 1) / 3
              c = col - 3 * a
              acc(:nb) = acc(:nb) + set%stations%coef(p) * (turned(:nb, c, &
                         set%element_vector(a + 1, el)) - set%reference(col, el))
            end do
            forces(ns * (el - 1) + i, first:first + nb - 1, k) = acc(:nb)
          end do
        end do
      end do
    end do
  end subroutine ffr_section_forces

  !> The set's distinct nodal vectors (dof triples) and each element's (ffr_set).
  pure subroutine distinct_vectors(set)
    class(ffr_set), intent(inout) :: set
    integer :: found(3, 8 * set%nel), el, a, v, nv
    allocate (set%element_vector(8, set%nel))
    nv = 0
    do el = 1, set%nel
      do a = 0, 7
        do v = nv, 1, -1   ! (neighbours share their common node's: look back)
          if (all(found(:, v) == set%dofs(3 * a + 1:3 * a + 3, el))) exit
        end do
        if (v < 1) then
          nv = nv + 1
          found(:, nv) = set%dofs(3 * a + 1:3 * a + 3, el)
          v = nv
        end if
        set%element_vector(a + 1, el) = v
      end do
    end do
    set%vector_dofs = found(:, :nv)
  end subroutine distinct_vectors

end module ffr_elastic
