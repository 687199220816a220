!> Structural ("cubic") elastic forces of the 12-coordinate ANCF beam (kinematics of
!> beam_element): the higher-accuracy bending option of both formulations.
!>
!> In the continuum element the bending strain is the section gradient's rate r_y,x . r_x,
!> constant along an element because r_y is linear in x. Here the curvature follows the
!> cubic centre line: with r_x, r_xx, r_y, r_z on the neutral axis,
!>
!>   kappa_z = - r_y,x . r_x + r_xx . r_y - mean_el(r_xx . r_y)      (and z for y)
!>
!> the section rotation carries the element mean of the curvature (a clamped or loaded
!> section passes its moment on without a penalty) and r_xx its linear variation. Shear
!> gamma_y = r_x . r_y is sampled at the nodes only, where r_x and r_y are both nodal:
!> n + 1 tying conditions for n + 1 section rotations, so it cannot lock, and a constant
!> shear is integrated exactly. Small strain: kappa = theta' + v'' - mean(v''), gamma =
!> v' - theta; the element reproduces the Timoshenko beam under end loads and uniform load
!> exactly with one element (tests/test_cubic_beam.py). Torsion 1/2 (r_y,x . r_z -
!> r_z,x . r_y); axial Green strain (r_x . r_x - 1)/2; section strains (r_y . r_y - 1)/2,
!> (r_z . r_z - 1)/2, r_y . r_z at the nodes.
!>
!> Every strain is a quadratic form of the nodal vectors q_a minus its reference value,
!>   s = 1/2 sum_ab C_ab q_a . q_b - s0,      U = 1/2 sum_terms k s^2,
!> so dS/dq_a = sum_b C_ab q_b, the tangent is k (g g^T + s C x I3), rigid motions leave
!> every s unchanged, and a curved reference is strain-free by s0. Stiffnesses: EA, EI_z,
!> EI_y, G J with J the section's Saint-Venant torsion constant and k_y G A, k_z G A with
!> its shear factors (python/ancfdrv/system/sections.py), as the continuum element has
!> with its torsion and shear correction, so the two options differ in the bending
!> interpolation only.
!>
!> Kelvin-Voigt material damping (retardation time tau, cubic_element given the rates) acts on
!> every strain: s -> s + tau s' with s' = q' . C q, so Q_d = sum_terms k tau s' C q, the
!> dissipated power sum k tau s'^2 >= 0 (a rigid motion leaves every s' at zero), and the
!> tangent dQ/dq + c dQ/dq' = sum k ((1 + c tau) g g^T + tau g (C q')^T + (s + tau s') C x I3)
!> (g = C q), not symmetric.
module beam_cubic
  use ancf_kinds, only: dp
  use quadrature, only: gauss_legendre
  use element_sets, only: element_set, local_element_set
  use beam_stations, only: centreline_rows, station_section, set_station_forces
  implicit none
  private
  public :: cubic_setup, cubic_element, cubic_stress_stiffness, cubic_pattern, cubic_set, &
            cubic_set_with_forms

  !> Axial points of the axial and bending strains, of the torsion.
  integer, parameter :: n_line = 3, n_axial = 3, n_torsion = 2
  !> Nodal terms per node: shear y, shear z, section yy, zz, yz.
  integer, parameter :: n_nodal = 5
  integer, parameter, public :: cubic_terms = 2 * n_line + n_axial + n_torsion + 2 * n_nodal

  !> The family's element set (element_sets): strain forms (8, 8, nterms, nel), reference
  !> strains and stiffnesses (nterms, nel), and the forms' nonzero entries
  !> (cubic_pattern): (2, 64, nterms), (nterms).
  type, extends(local_element_set) :: cubic_set
    real(dp), allocatable :: forms(:, :, :, :), strain0(:, :), term_stiffness(:, :)
    integer, allocatable :: form_pairs(:, :, :), form_npairs(:)
    !> the section data of its section forces (beam_stations)
    type(station_section) :: sections
  contains
    procedure :: element_forces => cubic_element_forces
    procedure :: section_forces => cubic_section_forces
  end type cubic_set

contains

  !> a b^T + b a^T: the form of the dot product (sum a_i q_i) . (sum b_j q_j).
  pure function product_form(a, b) result(form)
    real(dp), intent(in) :: a(8), b(8)
    real(dp) :: form(8, 8)
    form = spread(a, 2, 8) * spread(b, 1, 8) + spread(b, 2, 8) * spread(a, 1, 8)
  end function product_form

  !> Quadratic forms C (8, 8, term), reference values s0 and stiffnesses k (material times
  !> line element |r0_x| L dxi) of one element. info = 1: quadrature unavailable; 2: the
  !> reference tangent r0_x vanishes somewhere.
  !> Section data: area, I_y = int z^2 dA, I_z = int y^2 dA, the Saint-Venant torsion
  !> constant J (torsion) and the shear factors k_y (shear along the height, 2E12) and k_z.
  pure subroutine cubic_setup(reference, length, area, inertia_y, inertia_z, torsion, &
                                   shear_y, shear_z, youngs, poisson, forms, strain0, &
                                   stiffness, info)
    real(dp), intent(in) :: reference(3, 8), length, area, inertia_y, inertia_z, torsion
    real(dp), intent(in) :: shear_y, shear_z, youngs, poisson
    real(dp), intent(out) :: forms(8, 8, cubic_terms), strain0(cubic_terms)
    real(dp), intent(out) :: stiffness(cubic_terms)
    integer, intent(out) :: info
    real(dp) :: points(n_line), weights(n_line), p2(n_torsion), w2(n_torsion)
    real(dp) :: pa(n_axial), wa(n_axial)
    real(dp) :: slope(8), second(8), dir_y(8), dir_z(8), dir_y_x(8), dir_z_x(8)
    real(dp) :: mean_y(8, 8), mean_z(8, 8), shear, line, xi
    integer :: i, t, node, info_torsion
    forms = 0.0_dp
    strain0 = 0.0_dp
    stiffness = 0.0_dp
    call gauss_legendre(n_line, points, weights, info)
    call gauss_legendre(n_torsion, p2, w2, info_torsion)
    info = max(info, info_torsion)
    call gauss_legendre(n_axial, pa, wa, info_torsion)
    info = max(info, info_torsion)
    if (info /= 0) return
    shear = youngs / (2.0_dp * (1.0_dp + poisson))
    ! element means of r_xx . r_y and r_xx . r_z (quadratic in xi: 2 points are exact)
    mean_y = 0.0_dp
    mean_z = 0.0_dp
    do i = 1, n_torsion
      call centreline_rows(0.5_dp * (p2(i) + 1.0_dp), length, slope, second, dir_y, dir_z, &
                           dir_y_x, dir_z_x)
      mean_y = mean_y + 0.5_dp * w2(i) * product_form(second, dir_y)
      mean_z = mean_z + 0.5_dp * w2(i) * product_form(second, dir_z)
    end do
    t = 0
    do i = 1, n_line
      xi = 0.5_dp * (points(i) + 1.0_dp)
      call centreline_rows(xi, length, slope, second, dir_y, dir_z, dir_y_x, dir_z_x)
      line = 0.5_dp * weights(i) * length * norm2(matmul(reference, slope))
      forms(:, :, t + 1) = product_form(second, dir_y) - product_form(dir_y_x, slope) - mean_y
      stiffness(t + 1) = youngs * inertia_z * line
      forms(:, :, t + 2) = product_form(second, dir_z) - product_form(dir_z_x, slope) - mean_z
      stiffness(t + 2) = youngs * inertia_y * line
      t = t + 2
    end do
    do i = 1, n_axial
      xi = 0.5_dp * (pa(i) + 1.0_dp)
      call centreline_rows(xi, length, slope, second, dir_y, dir_z, dir_y_x, dir_z_x)
      t = t + 1
      forms(:, :, t) = spread(slope, 2, 8) * spread(slope, 1, 8)
      stiffness(t) = youngs * area * 0.5_dp * wa(i) * length * norm2(matmul(reference, slope))
    end do
    do i = 1, n_torsion
      call centreline_rows(0.5_dp * (p2(i) + 1.0_dp), length, slope, second, dir_y, dir_z, &
                           dir_y_x, dir_z_x)
      line = 0.5_dp * w2(i) * length * norm2(matmul(reference, slope))
      t = t + 1
      forms(:, :, t) = 0.5_dp * (product_form(dir_y_x, dir_z) - product_form(dir_z_x, dir_y))
      stiffness(t) = shear * torsion * line
    end do
    do node = 0, 1
      call centreline_rows(real(node, dp), length, slope, second, dir_y, dir_z, dir_y_x, dir_z_x)
      line = 0.5_dp * length * norm2(matmul(reference, slope))
      forms(:, :, t + 1) = product_form(slope, dir_y)
      stiffness(t + 1) = shear_y * shear * area * line
      forms(:, :, t + 2) = product_form(slope, dir_z)
      stiffness(t + 2) = shear_z * shear * area * line
      forms(:, :, t + 3) = spread(dir_y, 2, 8) * spread(dir_y, 1, 8)
      stiffness(t + 3) = youngs * area * line
      forms(:, :, t + 4) = spread(dir_z, 2, 8) * spread(dir_z, 1, 8)
      stiffness(t + 4) = youngs * area * line
      forms(:, :, t + 5) = product_form(dir_y, dir_z)
      stiffness(t + 5) = shear * area * line
      t = t + n_nodal
    end do
    if (any(stiffness(2 * n_line + 1:2 * n_line + n_axial) <= 0.0_dp) .or. &
        minval(stiffness) < 0.0_dp) then
      info = 2
      return
    end if
    do t = 1, cubic_terms
      strain0(t) = 0.5_dp * sum(reference * matmul(reference, forms(:, :, t)))
    end do
  end subroutine cubic_setup

  !> A system's set: built (everything but its forms) as a polymorphic element set with the
  !> forms (10.8 kB an element) copied into it once (allocate's source= would copy forms held
  !> by built a second time).
  subroutine cubic_set_with_forms(built, forms, set)
    type(cubic_set), intent(in) :: built
    real(dp), intent(in) :: forms(:, :, :, :)
    class(element_set), allocatable, intent(out) :: set
    allocate (set, source=built)
    select type (set)
    type is (cubic_set)
      set%forms = forms
    end select
  end subroutine cubic_set_with_forms

  !> The nonzero entries (a, b) of each term's form in any element of a set (forms (8, 8,
  !> cubic_terms, nel)): a term couples few of the eight nodal vectors (an axial
  !> strain the four of the centre line, a nodal shear two), so the force over these
  !> pairs costs about a third of the dense product.
  pure subroutine cubic_pattern(forms, pairs, npairs)
    real(dp), intent(in) :: forms(:, :, :, :)
    integer, intent(out) :: pairs(2, 64, cubic_terms), npairs(cubic_terms)
    integer :: t, a, b
    pairs = 0
    npairs = 0
    do t = 1, cubic_terms
      do b = 1, 8
        do a = 1, 8
          if (all(forms(a, b, t, :) == 0.0_dp)) cycle
          npairs(t) = npairs(t) + 1
          pairs(:, npairs(t), t) = [a, b]
        end do
      end do
    end do
  end subroutine cubic_pattern

  !> Internal force (24), strain energy and, when want_tangent, the tangent (24 x 24) of
  !> one element with nodal vectors q(3, 8). With the set's pattern (cubic_pattern)
  !> the gradients C q run over the forms' nonzero entries only.
  !> With Kelvin-Voigt damping (the nodal rates q'(3, 8), damping_time tau > 0, rate_factor
  !> and dissipation all present): the force includes the damping force, dissipation is its
  !> power and the tangent (when want_tangent) is dQ/dq + rate_factor dQ/dq' (not symmetric:
  !> whole columns, and the gradients from the full forms). (The two term loops stay apart,
  !> as in beam_nonlinear: one loop behind a flag compiles to a slower undamped force.)
  pure subroutine cubic_element(q, forms, strain0, stiffness, want_tangent, force, energy, &
                                     tangent, pairs, npairs, rates, damping_time, rate_factor, &
                                     dissipation)
    real(dp), intent(in) :: q(3, 8), forms(8, 8, cubic_terms), strain0(cubic_terms)
    real(dp), intent(in) :: stiffness(cubic_terms)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(24), energy, tangent(24, 24)
    integer, intent(in), optional :: pairs(2, 64, cubic_terms), npairs(cubic_terms)
    real(dp), intent(in), optional :: rates(3, 8), damping_time, rate_factor
    real(dp), intent(out), optional :: dissipation
    if (present(rates)) then
      call damped_terms(q, rates, forms, strain0, stiffness, damping_time, rate_factor, &
                        want_tangent, force, energy, dissipation, tangent)
    else
      call elastic_terms(q, forms, strain0, stiffness, want_tangent, force, energy, tangent, &
                         pairs, npairs)
    end if
  end subroutine cubic_element

  !> The initial-stress part of cubic_element's tangent for the strain increments of the
  !> nodal increment dq(3, 8) at q(3, 8): sum_terms k (C q . dq) C x I3, the tangent's
  !> s C x I3 with each strain s replaced by its increment (the stress of a load
  !> increment): K_T = sum k g g^T + K_sigma(s), and K_sigma(ds) is the geometric
  !> stiffness of classical linear buckling (python/ancfdrv/solvers/buckling.py).
  pure subroutine cubic_stress_stiffness(q, dq, forms, stiffness, tangent)
    real(dp), intent(in) :: q(3, 8), dq(3, 8), forms(8, 8, cubic_terms)
    real(dp), intent(in) :: stiffness(cubic_terms)
    real(dp), intent(out) :: tangent(24, 24)
    real(dp) :: geometric(8, 8)
    integer :: t
    tangent = 0.0_dp
    geometric = 0.0_dp
    do t = 1, cubic_terms
      geometric = geometric + stiffness(t) * sum(dq * matmul(q, forms(:, :, t))) * forms(:, :, t)
    end do
    call add_kron_identity(geometric, tangent)
  end subroutine cubic_stress_stiffness

  !> cubic_element without damping (its loop over the strain terms). With the set's pattern (cubic_pattern)
  !> the gradients C q run over the forms' nonzero entries only.
  pure subroutine elastic_terms(q, forms, strain0, stiffness, want_tangent, force, energy, &
                                tangent, pairs, npairs)
    real(dp), intent(in) :: q(3, 8), forms(8, 8, cubic_terms), strain0(cubic_terms)
    real(dp), intent(in) :: stiffness(cubic_terms)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(24), energy, tangent(24, 24)
    integer, intent(in), optional :: pairs(2, 64, cubic_terms), npairs(cubic_terms)
    real(dp) :: gradient(3, 8), flat(24), strain, geometric(8, 8), scaled
    integer :: t, j, a, k
    force = 0.0_dp
    energy = 0.0_dp
    if (want_tangent) tangent = 0.0_dp  ! (a force-only call leaves it alone, as the plate does)
    geometric = 0.0_dp
    do t = 1, cubic_terms
      if (present(pairs)) then
        gradient = 0.0_dp
        do k = 1, npairs(t)
          gradient(:, pairs(2, k, t)) = gradient(:, pairs(2, k, t)) &
                                        + q(:, pairs(1, k, t)) * forms(pairs(1, k, t), pairs(2, k, t), t)
        end do
      else
        gradient = matmul(q, forms(:, :, t))
      end if
      strain = 0.5_dp * sum(q * gradient) - strain0(t)
      energy = energy + 0.5_dp * stiffness(t) * strain**2
      do a = 1, 8  ! the 3 x 8 gradient as 24 numbers, copied in place of a reshape
        flat(3 * a - 2:3 * a) = gradient(:, a)
      end do
      force = force + stiffness(t) * strain * flat
      if (.not. want_tangent) cycle
      do j = 1, 24
        scaled = stiffness(t) * flat(j)
        tangent(j:24, j) = tangent(j:24, j) + scaled * flat(j:24)
      end do
      geometric = geometric + stiffness(t) * strain * forms(:, :, t)
    end do
    if (.not. want_tangent) return
    call add_kron_identity(geometric, tangent)
    ! the rank-one parts filled the lower triangle; the geometric part is symmetric
    do j = 2, 24
      tangent(1:j - 1, j) = tangent(j, 1:j - 1)
    end do
  end subroutine elastic_terms

  !> cubic_element with Kelvin-Voigt damping (damping_time tau > 0) at the nodal rates
  !> q'(3, 8) (its loop over the strain terms): the force includes the damping force, dissipation is its power and the
  !> tangent (when want_tangent) is dQ/dq + rate_factor dQ/dq' (not symmetric).
  pure subroutine damped_terms(q, rates, forms, strain0, stiffness, damping_time, &
                                            rate_factor, want_tangent, force, energy, &
                                            dissipation, tangent)
    real(dp), intent(in) :: q(3, 8), rates(3, 8), forms(8, 8, cubic_terms)
    real(dp), intent(in) :: strain0(cubic_terms), stiffness(cubic_terms)
    real(dp), intent(in) :: damping_time, rate_factor
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(24), energy, dissipation, tangent(24, 24)
    real(dp) :: gradient(3, 8), rate_gradient(3, 8), strain, strain_rate, total
    real(dp) :: geometric(8, 8), row(24), column(24)
    integer :: t, j, a
    force = 0.0_dp
    energy = 0.0_dp
    dissipation = 0.0_dp
    if (want_tangent) tangent = 0.0_dp  ! (a force-only call leaves it alone, as the plate does)
    geometric = 0.0_dp
    do t = 1, cubic_terms
      gradient = matmul(q, forms(:, :, t))
      strain = 0.5_dp * sum(q * gradient) - strain0(t)
      strain_rate = sum(rates * gradient)                 ! s' = q' . C q
      total = strain + damping_time * strain_rate
      energy = energy + 0.5_dp * stiffness(t) * strain**2
      dissipation = dissipation + damping_time * stiffness(t) * strain_rate**2
      do a = 1, 8  ! the 3 x 8 gradient as 24 numbers, copied in place of a reshape
        column(3 * a - 2:3 * a) = gradient(:, a)
      end do
      force = force + stiffness(t) * total * column
      if (.not. want_tangent) cycle
      ! k g ((1 + c tau) g + tau C q')^T, whole columns
      rate_gradient = matmul(rates, forms(:, :, t))
      do a = 1, 8
        row(3 * a - 2:3 * a) = stiffness(t) * ((1.0_dp + rate_factor * damping_time) &
                               * gradient(:, a) + damping_time * rate_gradient(:, a))
      end do
      do j = 1, 24
        tangent(:, j) = tangent(:, j) + row(j) * column
      end do
      geometric = geometric + stiffness(t) * total * forms(:, :, t)
    end do
    if (.not. want_tangent) return
    call add_kron_identity(geometric, tangent)
  end subroutine damped_terms

  !> The element_set element_forces of a cubic set: cubic_element of element el.
  pure subroutine cubic_element_forces(set, el, coords, want_tangent, force, energy, tangent, &
                                       info, rates, rate_factor, dissipation)
    class(cubic_set), intent(in) :: set
    integer, intent(in) :: el
    real(dp), intent(in) :: coords(:, :)
    logical, intent(in) :: want_tangent
    real(dp), intent(out) :: force(:), energy, tangent(:, :)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: rates(:, :), rate_factor
    real(dp), intent(out), optional :: dissipation
    info = 0
    if (present(rates)) then
      call cubic_element(coords, set%forms(:, :, :, el), set%strain0(:, el), &
                              set%term_stiffness(:, el), want_tangent, force, energy, tangent, &
                              rates=rates, damping_time=set%damping_time, &
                              rate_factor=rate_factor, dissipation=dissipation)
    else
      call cubic_element(coords, set%forms(:, :, :, el), set%strain0(:, el), &
                              set%term_stiffness(:, el), want_tangent, force, energy, tangent, &
                              set%form_pairs, set%form_npairs)
    end if
  end subroutine cubic_element_forces

  !> The element_set section_forces of a cubic set (beam_stations, 'cubic' measures).
  subroutine cubic_section_forces(set, rotations, q_rows, xi, forces, info)
    class(cubic_set), intent(inout) :: set
    real(dp), intent(in) :: rotations(:, :, :), q_rows(:, :), xi(:)
    real(dp), intent(out) :: forces(:, :, :)
    integer, intent(out) :: info
    call set_station_forces(set%sections, set%dofs, q_rows, xi, forces, info)
  end subroutine cubic_section_forces

  !> tangent += kron(geometric, I3): an (8, 8) form acting alike on the three components.
  pure subroutine add_kron_identity(geometric, tangent)
    real(dp), intent(in) :: geometric(8, 8)
    real(dp), intent(inout) :: tangent(24, 24)
    integer :: a, c, i
    do c = 1, 8
      do a = 1, 8
        do i = 1, 3
          tangent(3 * (a - 1) + i, 3 * (c - 1) + i) = tangent(3 * (a - 1) + i, 3 * (c - 1) + i) &
                                                      + geometric(a, c)
        end do
      end do
    end do
  end subroutine add_kron_identity

end module beam_cubic
