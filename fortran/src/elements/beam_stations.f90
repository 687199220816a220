!> Section forces of the 12-coordinate ANCF beam at stations along its elements: what the
!> beam families (beam_nonlinear's continuum_set, beam_cubic's cubic_set, ffr_elastic's
!> ffr_set) report through the element interface's section_forces (element_sets), from
!> the beam's strain measures and the section's stiffness (docs/theory.md, "Section
!> forces from the strains").
!>
!> The neutral-axis fields r_x, r_xx, r_y, r_z, r_y,x, r_z,x at xi (centreline_rows, also
!> the cubic element's kinematics) give per station the strain measures
!>   eps      axial Green strain (r_x . r_x - 1)/2 at the three axial Gauss points of the
!>            cubic element, carried to the station by the quadratic through them (the
!>            Green strain between them holds the bending slopes' spurious share);
!>   b_y      -r_y,x . r_x, with 'cubic' bending + r_xx . r_y - mean_el(r_xx . r_y) (the
!>            mean by 2-point Gauss); b_z likewise with r_z;
!>   twist    'cubic': 1/2 (r_y,x . r_z - r_z,x . r_y); continuum:
!>            (I_z r_y,x . r_z - I_y r_z,x . r_y) / I_p;
!>   gamma_y  r_x . r_y ('cubic': its nodal values interpolated linearly); gamma_z with r_z.
!> Every measure is a quadratic form of the nodal vectors, B(q, q) with B symmetric and
!> bilinear (station_measures evaluates B(x, y)). A large-deformation set's change is
!> B(q, q) - B(q0, q0) from its reference q0; a small-strain (FFR) set's is the linear part
!> 2 B(q0, d) of its displacement d in the frame. Forces (what the part beyond s exerts on
!> the part before it): N = EA eps (+ E (I_z b_y c_y + I_y b_z c_z) at large deformation,
!> the bending strains' share of the force along the section normal n = r_y x r_z / |...|,
!> c_y = -r_y,x . n), T = G J twist, Q = (k_y G A gamma_y, k_z G A gamma_z),
!> M = (-E I_y b_z, E I_z b_y) along the section's height and width axes.
module beam_stations
  use ancf_kinds, only: dp
  implicit none
  private
  public :: centreline_rows, station_section, station_forces, set_station_forces
  public :: station_map, small_station_map

  !> A beam set's section data for its section forces: bending option, the section's
  !> stiffnesses and moments, the element lengths and the reference nodal vectors (3, 8, nel)
  !> (global; a small-strain set's in its frame, as its own reference).
  type :: station_section
    logical :: cubic = .false.
    real(dp) :: axial = 0.0_dp, torsion = 0.0_dp, shear_y = 0.0_dp, shear_z = 0.0_dp
    real(dp) :: moment_height = 0.0_dp, moment_width = 0.0_dp
    real(dp) :: youngs = 0.0_dp, inertia_y = 0.0_dp, inertia_z = 0.0_dp, polar = 0.0_dp
    real(dp), allocatable :: length(:), reference(:, :, :)
  end type station_section

  !> The section forces of a small-strain (FFR) set at the stations xi as linear forms of
  !> each element's displacement d (24) in its frame (they are linear in d: 2 B(q0, d) times
  !> the section's stiffnesses), built once per set of stations: output o = (i, k, el)
  !> (station i, force k, element el; o = i + ns (k - 1) + 6 ns (el - 1)) is
  !> sum coef(p) d(col(p)) over p = first(o) .. first(o + 1) - 1, the forms' exact zeros
  !> left out (a straight beam's forces each read 2 to 8 of the 24 coordinates).
  type :: station_map
    real(dp), allocatable :: xi(:)
    integer, allocatable :: first(:), col(:)
    real(dp), allocatable :: coef(:)
  end type station_map

contains

  !> Coefficient rows of the neutral-axis fields at xi: r_x = sum_a slope_a q_a, r_xx,
  !> r_y, r_z and the (constant) r_y,x, r_z,x.
  pure subroutine centreline_rows(xi, length, slope, second, dir_y, dir_z, dir_y_x, dir_z_x)
    real(dp), intent(in) :: xi, length
    real(dp), intent(out) :: slope(8), second(8), dir_y(8), dir_z(8), dir_y_x(8), dir_z_x(8)
    slope = [(-6.0_dp * xi + 6.0_dp * xi**2) / length, 1.0_dp - 4.0_dp * xi + 3.0_dp * xi**2, &
             0.0_dp, 0.0_dp, (6.0_dp * xi - 6.0_dp * xi**2) / length, 3.0_dp * xi**2 - 2.0_dp * xi, &
             0.0_dp, 0.0_dp]
    second = [(-6.0_dp + 12.0_dp * xi) / length**2, (-4.0_dp + 6.0_dp * xi) / length, 0.0_dp, &
              0.0_dp, (6.0_dp - 12.0_dp * xi) / length**2, (6.0_dp * xi - 2.0_dp) / length, &
              0.0_dp, 0.0_dp]
    dir_y = [0.0_dp, 0.0_dp, 1.0_dp - xi, 0.0_dp, 0.0_dp, 0.0_dp, xi, 0.0_dp]
    dir_z = [0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp - xi, 0.0_dp, 0.0_dp, 0.0_dp, xi]
    dir_y_x = [0.0_dp, 0.0_dp, -1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp] / length
    dir_z_x = [0.0_dp, 0.0_dp, 0.0_dp, -1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp] / length
  end subroutine centreline_rows

  !> The six fields (3, 6) r_x, r_xx, r_y, r_z, r_y,x, r_z,x of nodal vectors x (3, 8) at xi.
  pure function fields(x, xi, length) result(f)
    real(dp), intent(in) :: x(3, 8), xi, length
    real(dp) :: f(3, 6)
    real(dp) :: rows(8, 6)
    call centreline_rows(xi, length, rows(:, 1), rows(:, 2), rows(:, 3), rows(:, 4), &
                         rows(:, 5), rows(:, 6))
    f = matmul(x, rows)
  end function fields

  !> The symmetric bilinear form of a dot product: (a(x) . b(y) + a(y) . b(x)) / 2 (a(x) . b(x)
  !> exactly when x = y).
  pure real(dp) function sym(ax, bx, ay, by)
    real(dp), intent(in) :: ax(3), bx(3), ay(3), by(3)
    sym = 0.5_dp * (dot_product(ax, by) + dot_product(ay, bx))
  end function sym

  !> The strain measures' bilinear forms B(x, y) (6, ns) [eps + 1/2, b_y, b_z, twist,
  !> gamma_y, gamma_z] of one element (nodal vectors x, y (3, 8), length) at the stations xi.
  pure subroutine station_measures(sec, length, x, y, xi, m)
    type(station_section), intent(in) :: sec
    real(dp), intent(in) :: length, x(3, 8), y(3, 8), xi(:)
    real(dp), intent(out) :: m(6, size(xi))
    real(dp) :: fx(3, 6), fy(3, 6), axial(3), fit(3), slope_sq(3), gauss(2)
    real(dp) :: mean_y, mean_z, nodal_y(0:1), nodal_z(0:1)
    integer :: i, k, j
    axial = 0.5_dp + [-1.0_dp, 0.0_dp, 1.0_dp] * sqrt(0.15_dp)
    do k = 1, 3
      fx = fields(x, axial(k), length)
      fy = fields(y, axial(k), length)
      slope_sq(k) = 0.5_dp * sym(fx(:, 1), fx(:, 1), fy(:, 1), fy(:, 1))
    end do
    if (sec%cubic) then
      gauss = 0.5_dp + [-0.5_dp, 0.5_dp] / sqrt(3.0_dp)
      mean_y = 0.0_dp
      mean_z = 0.0_dp
      do k = 1, 2
        fx = fields(x, gauss(k), length)
        fy = fields(y, gauss(k), length)
        mean_y = mean_y + sym(fx(:, 2), fx(:, 3), fy(:, 2), fy(:, 3))
        mean_z = mean_z + sym(fx(:, 2), fx(:, 4), fy(:, 2), fy(:, 4))
      end do
      mean_y = mean_y / 2.0_dp
      mean_z = mean_z / 2.0_dp
      do k = 0, 1
        fx = fields(x, real(k, dp), length)
        fy = fields(y, real(k, dp), length)
        nodal_y(k) = sym(fx(:, 1), fx(:, 3), fy(:, 1), fy(:, 3))
        nodal_z(k) = sym(fx(:, 1), fx(:, 4), fy(:, 1), fy(:, 4))
      end do
    end if
    do i = 1, size(xi)
      do k = 1, 3   ! Lagrange weights of the quadratic through the axial points
        fit(k) = 1.0_dp
        do j = 1, 3
          if (j /= k) fit(k) = fit(k) * (xi(i) - axial(j)) / (axial(k) - axial(j))
        end do
      end do
      m(1, i) = sum(fit * slope_sq)
      fx = fields(x, xi(i), length)
      fy = fields(y, xi(i), length)
      m(2, i) = -sym(fx(:, 5), fx(:, 1), fy(:, 5), fy(:, 1))
      m(3, i) = -sym(fx(:, 6), fx(:, 1), fy(:, 6), fy(:, 1))
      if (sec%cubic) then
        m(2, i) = m(2, i) + sym(fx(:, 2), fx(:, 3), fy(:, 2), fy(:, 3)) - mean_y
        m(3, i) = m(3, i) + sym(fx(:, 2), fx(:, 4), fy(:, 2), fy(:, 4)) - mean_z
        m(4, i) = 0.5_dp * (sym(fx(:, 5), fx(:, 4), fy(:, 5), fy(:, 4)) &
                            - sym(fx(:, 6), fx(:, 3), fy(:, 6), fy(:, 3)))
        m(5, i) = nodal_y(0) * (1.0_dp - xi(i)) + nodal_y(1) * xi(i)
        m(6, i) = nodal_z(0) * (1.0_dp - xi(i)) + nodal_z(1) * xi(i)
      else
        m(4, i) = (sec%inertia_z * sym(fx(:, 5), fx(:, 4), fy(:, 5), fy(:, 4)) &
                   - sec%inertia_y * sym(fx(:, 6), fx(:, 3), fy(:, 6), fy(:, 3))) / sec%polar
        m(5, i) = sym(fx(:, 1), fx(:, 3), fy(:, 1), fy(:, 3))
        m(6, i) = sym(fx(:, 1), fx(:, 4), fy(:, 1), fy(:, 4))
      end if
    end do
  end subroutine station_measures

  !> Section forces (ns, nrows, 6) of element el at the stations xi for nrows states of its
  !> nodal vectors (3, 8, nrows) (a large-deformation set's current vectors).
  pure subroutine station_forces(sec, el, xi, nodal, forces)
    type(station_section), intent(in) :: sec
    integer, intent(in) :: el
    real(dp), intent(in) :: xi(:), nodal(:, :, :)
    real(dp), intent(out) :: forces(:, :, :)
    real(dp) :: length, change(6, size(xi)), reference(6, size(xi))
    real(dp) :: f(3, 6), normal(3), c_y, c_z
    integer :: row, i
    length = sec%length(el)
    call station_measures(sec, length, sec%reference(:, :, el), sec%reference(:, :, el), xi, &
                          reference)
    do row = 1, size(nodal, 3)
      call station_measures(sec, length, nodal(:, :, row), nodal(:, :, row), xi, change)
      change = change - reference
      do i = 1, size(xi)
        f = fields(nodal(:, :, row), xi(i), length)
        normal = [f(2, 3) * f(3, 4) - f(3, 3) * f(2, 4), f(3, 3) * f(1, 4) - f(1, 3) * f(3, 4), &
                  f(1, 3) * f(2, 4) - f(2, 3) * f(1, 4)]
        normal = normal / norm2(normal)
        c_y = -dot_product(f(:, 5), normal)
        c_z = -dot_product(f(:, 6), normal)
        forces(i, row, 1) = sec%axial * change(1, i) + sec%youngs * (sec%inertia_z * change(2, i) &
                            * c_y + sec%inertia_y * change(3, i) * c_z)
      end do
      call forces_of_measures(sec, change, forces(:, row, :))
    end do
  end subroutine station_forces

  !> The forces T, Q, M (ns, 2:6) of the measures' changes (6, ns) (N: the caller's).
  pure subroutine forces_of_measures(sec, change, forces)
    type(station_section), intent(in) :: sec
    real(dp), intent(in) :: change(:, :)
    real(dp), intent(inout) :: forces(:, :)
    forces(:, 2) = sec%torsion * change(4, :)
    forces(:, 3) = sec%shear_y * change(5, :)
    forces(:, 4) = sec%shear_z * change(6, :)
    forces(:, 5) = sec%moment_height * change(3, :)
    forces(:, 6) = sec%moment_width * change(2, :)
  end subroutine forces_of_measures

  !> The station map (station_map) of a small-strain set with nel elements at the stations
  !> xi: each element's forms from the measures' bilinear forms 2 B(q0, e_j) of the unit
  !> displacements e_j (exact: the forms are linear).
  pure subroutine small_station_map(sec, nel, xi, map)
    type(station_section), intent(in) :: sec
    integer, intent(in) :: nel
    real(dp), intent(in) :: xi(:)
    type(station_map), intent(out) :: map
    real(dp) :: unit(24), change(6, size(xi)), forms(size(xi), 6, 24)
    integer :: el, j, ns, o, p, i, k, used
    integer, allocatable :: col(:)
    real(dp), allocatable :: coef(:)
    ns = size(xi)
    map%xi = xi
    allocate (map%first(6 * ns * nel + 1), col(6 * ns * nel * 24), coef(6 * ns * nel * 24))
    used = 0
    do el = 1, nel
      do j = 1, 24
        unit = 0.0_dp
        unit(j) = 1.0_dp
        call station_measures(sec, sec%length(el), sec%reference(:, :, el), &
                              reshape(unit, [3, 8]), xi, change)
        change = 2.0_dp * change
        forms(:, 1, j) = sec%axial * change(1, :)
        call forces_of_measures(sec, change, forms(:, :, j))
      end do
      do k = 1, 6
        do i = 1, ns
          o = i + ns * (k - 1) + 6 * ns * (el - 1)
          map%first(o) = used + 1
          do p = 1, 24
            if (forms(i, k, p) /= 0.0_dp) then
              used = used + 1
              col(used) = p
              coef(used) = forms(i, k, p)
            end if
          end do
        end do
      end do
    end do
    map%first(6 * ns * nel + 1) = used + 1
    map%col = col(:used)
    map%coef = coef(:used)
  end subroutine small_station_map

  !> The section forces (ns nel, nrows, 6) of a large-deformation beam set (element_sets
  !> section_forces) from its element dofs (24, nel) and the states q_rows (nfull, nrows).
  !> info = 1: the set has no section data.
  pure subroutine set_station_forces(sec, dofs, q_rows, xi, forces, info)
    type(station_section), intent(in) :: sec
    integer, intent(in) :: dofs(:, :)
    real(dp), intent(in) :: q_rows(:, :), xi(:)
    real(dp), intent(out) :: forces(:, :, :)
    integer, intent(out) :: info
    real(dp) :: nodal(3, 8, size(q_rows, 2))
    integer :: el, row, ns
    forces = 0.0_dp
    info = 1
    if (.not. allocated(sec%reference)) return
    info = 0
    ns = size(xi)
    do el = 1, size(dofs, 2)
      do row = 1, size(q_rows, 2)
        nodal(:, :, row) = reshape(q_rows(dofs(:, el), row), [3, 8])
      end do
      call station_forces(sec, el, xi, nodal, forces(ns * (el - 1) + 1:ns * el, :, :))
    end do
  end subroutine set_station_forces

end module beam_stations
