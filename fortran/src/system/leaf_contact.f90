!> Leaf-to-leaf contact of seed 003 (eqs. 17-28): points P on the lower leaf's mid-surface
!> (its end edges) against the upper leaf's mid-surface, penalty normal force with contact
!> damping, and a smooth Coulomb friction law with a critical slip velocity V_t.
!>
!> Search (eqs. 17-18): the closest point Qc of the upper mid-surface to Pc solves
!> (r_Qc - r_Pc) . r_xi = (r_Qc - r_Pc) . r_eta = 0, written in the leaf-level coordinates
!> (xi, eta) in [0, n_l] x [0, n_w], integer part = element column/row, fraction = the local
!> parent coordinate, so Newton-Raphson walks across element boundaries. Newton starts from
!> the previous solution (warm start); when it fails (no convergence, indefinite Hessian of
!> the distance) a sweep over every element's sample points restarts it from the nearest one.
!>
!> Gap (eqs. 19-21): surface points r_Q = r_Qc - H_u/2 N_Q, r_P = r_Pc + H_l/2 N_P, and
!> g = (r_Q - r_P) . N with N = N_Q: at the orthogonal projection r_Qc - r_Pc is parallel to
!> N_Q, so this is eq. 19's N as long as the mid-surfaces have not crossed, and it stays
!> defined beyond. Penetration delta = -g when g < 0.
!>
!> Velocities (eqs. 22-23, 25): V_rel = r_Q' - r_P' with the normals' rates,
!> r_Q' = A_Q e_u', A_Q = S_Q - H_u/2 dN_Q/de_u (exact), V_tan = (I - N N^T) V_rel, and the
!> penetration rate D = g' = G . e' (G = dg/de); D = V_rel . N (eq. 23) up to
!> H_l/2 N_Q' . N_P, which vanishes when the two normals are parallel.
!>
!> Forces (eqs. 24, 27, 28): F_n = K delta - C D delta, clamped at 0 (no adhesion while the
!> leaves separate fast). The normal force acts through G, the exact gradient of the gap up
!> to the term -H_l/2 N_P . dN_Q/dxi dxi of the moving projection (zero for parallel normals),
!> so the penalty force derives from the potential K delta^2 / 2. Friction (eq. 26 is missing
!> in the seed; our law): F_t = -mu F_n phi(V_tan) with
!>   phi(u) = f(s) u/|u|,  s = |u|/V_t,  f(s) = s (2 - s) for s < 1, 1 for s >= 1,
!> a C1 regularized Coulomb law: viscous with slope 2 mu F_n / V_t at rest (phi = (2 - s) u
!> / V_t, no division by zero), full Coulomb mu F_n from the critical slip velocity V_t on.
!> It acts on the surface points: Q_u += A_Q^T F_t, Q_l -= A_P^T F_t, so its power
!> F_t . V_rel = -mu F_n f |V_tan| is never positive.
!>
!> Jacobian for the implicit step (c_v = d e'/d e of the integrator, gamma / (beta h)):
!>   S_c = k_n G G^T - mu k_n A^T phi G^T + c_v mu F_n A^T Phi (I - N N^T) A,
!>   k_n = K - C D + c_v C delta,  A = [A_Q, -A_P],  Phi = d phi / du,
!> exact for the first-order (Gauss-Newton) terms; frozen: the projection (xi, eta), the
!> normals' directions in G and A (terms proportional to delta d2g/de2 and to F_t dA/de).
!> No I/O; failures return codes.
module leaf_contact
  use ancf_kinds, only: dp
  use matrix3, only: cross, skew
  use plate_element, only: plate_shape, plate_shapes
  implicit none
  private
  public :: surface_frame, project_point, contact_point, contact_assemble

  !> contact_params layout
  integer, parameter, public :: cp_stiffness = 1, cp_damping = 2, cp_friction = 3, &
                                cp_slip_velocity = 4, cp_upper_thickness = 5, &
                                cp_lower_thickness = 6, cp_friction_on = 7, cp_count = 8
  !> per-point record: penetration, normal force, friction force, slip speed, xi, eta
  integer, parameter, public :: contact_record = 6
  !> counters (accumulated): point evaluations, active points, friction evaluations,
  !> projection Newton iterations, fallback sweeps, Jacobian entries outside the pattern
  integer, parameter, public :: cc_points = 1, cc_active = 2, cc_friction = 3, &
                                cc_iterations = 4, cc_fallbacks = 5, cc_dropped = 6, &
                                contact_counters = 6
  integer, parameter :: max_projection_iterations = 30

contains

  !> The coordinates (or rates) of one element as (3, 12), from the system vector x at the
  !> element's dofs.
  pure function element_coords(x, element_dofs) result(coords)
    real(dp), intent(in) :: x(:)
    integer, intent(in) :: element_dofs(:)
    real(dp) :: coords(3, plate_shapes)
    integer :: k
    do k = 1, plate_shapes
      coords(:, k) = x(element_dofs(3 * k - 2:3 * k))
    end do
  end function element_coords

  !> Position, velocity, unit normal, its rate and dN/de (3 x 36) at local (xi, eta) of an
  !> element with coordinates coords(3, 12) and velocities rates(3, 12); shape(12) are
  !> the shape functions there. info = 1 when r_x x r_y vanishes.
  pure subroutine surface_frame(coords, rates, xi, eta, a, b, shape, position, velocity, &
                                normal, normal_rate, normal_gradient, info)
    real(dp), intent(in) :: coords(3, plate_shapes), rates(3, plate_shapes), xi, eta, a, b
    real(dp), intent(out) :: shape(plate_shapes), position(3), velocity(3), normal(3)
    real(dp), intent(out) :: normal_rate(3), normal_gradient(3, 3 * plate_shapes)
    integer, intent(out) :: info
    real(dp) :: derivs(plate_shapes, 5), r_x(3), r_y(3), g(3), length, projector(3, 3)
    integer :: k, i
    info = 0
    call plate_shape(xi, eta, a, b, shape, derivs)
    position = matmul(coords, shape)
    velocity = matmul(rates, shape)
    r_x = matmul(coords, derivs(:, 1))
    r_y = matmul(coords, derivs(:, 2))
    g = cross(r_x, r_y)
    length = norm2(g)
    if (length <= 1e-12_dp * norm2(r_x) * norm2(r_y) .or. length == 0.0_dp) then
      info = 1
      normal = 0.0_dp
      normal_rate = 0.0_dp
      normal_gradient = 0.0_dp
      return
    end if
    normal = g / length
    projector = -spread(normal, 2, 3) * spread(normal, 1, 3)
    do i = 1, 3
      projector(i, i) = projector(i, i) + 1.0_dp
    end do
    projector = projector / length
    ! dg/de_k = S_y,k [r_x]x - S_x,k [r_y]x = [S_y,k r_x - S_x,k r_y]x (skew is linear)
    normal_rate = 0.0_dp
    do k = 1, plate_shapes
      normal_gradient(:, 3 * k - 2:3 * k) = matmul(projector, &
                                                   skew(derivs(k, 2) * r_x - derivs(k, 1) * r_y))
      normal_rate = normal_rate + matmul(normal_gradient(:, 3 * k - 2:3 * k), rates(:, k))
    end do
  end subroutine surface_frame

  !> Element and local coordinates of the leaf-level point (s, t) of grid(n_l, n_w).
  pure subroutine locate(grid, s, t, element, xi, eta)
    integer, intent(in) :: grid(:, :)
    real(dp), intent(in) :: s, t
    integer, intent(out) :: element
    real(dp), intent(out) :: xi, eta
    integer :: i, j
    i = min(max(int(s), 0), size(grid, 1) - 1)
    j = min(max(int(t), 0), size(grid, 2) - 1)
    element = grid(i + 1, j + 1)
    xi = s - i
    eta = t - j
  end subroutine locate

  !> Squared distance to p, its gradient and Hessian in the leaf-level coordinates (s, t).
  pure subroutine distance_terms(e, dofs, grid, sizes, p, s, t, dist2, grad, hess)
    real(dp), intent(in) :: e(:), sizes(:, :), p(3), s, t
    integer, intent(in) :: dofs(:, :), grid(:, :)
    real(dp), intent(out) :: dist2, grad(2), hess(2, 2)
    real(dp) :: shape(plate_shapes), derivs(plate_shapes, 5), coords(3, plate_shapes)
    real(dp) :: xi, eta, a, b, d(3), r_s(3), r_t(3), r_ss(3), r_tt(3), r_st(3)
    integer :: element
    call locate(grid, s, t, element, xi, eta)
    a = sizes(1, element)
    b = sizes(2, element)
    coords = element_coords(e, dofs(:, element))
    call plate_shape(xi, eta, a, b, shape, derivs)
    d = matmul(coords, shape) - p
    r_s = a * matmul(coords, derivs(:, 1))
    r_t = b * matmul(coords, derivs(:, 2))
    r_ss = a * a * matmul(coords, derivs(:, 3))
    r_tt = b * b * matmul(coords, derivs(:, 4))
    r_st = a * b * matmul(coords, derivs(:, 5))
    dist2 = dot_product(d, d)
    grad = [dot_product(d, r_s), dot_product(d, r_t)]
    hess(1, 1) = dot_product(r_s, r_s) + dot_product(d, r_ss)
    hess(2, 2) = dot_product(r_t, r_t) + dot_product(d, r_tt)
    hess(1, 2) = dot_product(r_s, r_t) + dot_product(d, r_st)
    hess(2, 1) = hess(1, 2)
  end subroutine distance_terms

  !> Newton-Raphson from guess (s, t) for the closest point; steps limited to half an
  !> element and clamped to the leaf. converged: the gradient vanished (or the point sits
  !> on the leaf's boundary with the gradient pointing out).
  pure subroutine newton_projection(e, dofs, grid, sizes, p, guess, iterations, converged)
    real(dp), intent(in) :: e(:), sizes(:, :), p(3)
    integer, intent(in) :: dofs(:, :), grid(:, :)
    real(dp), intent(inout) :: guess(2)
    integer, intent(inout) :: iterations
    logical, intent(out) :: converged
    real(dp) :: dist2, grad(2), hess(2, 2), det, step(2), upper(2), trial(2)
    integer :: it
    upper = [real(size(grid, 1), dp), real(size(grid, 2), dp)]
    converged = .false.
    do it = 1, max_projection_iterations
      iterations = iterations + 1
      call distance_terms(e, dofs, grid, sizes, p, guess(1), guess(2), dist2, grad, hess)
      det = hess(1, 1) * hess(2, 2) - hess(1, 2) ** 2
      if (det <= 0.0_dp .or. hess(1, 1) <= 0.0_dp) return  ! not a minimum's basin
      step = -[hess(2, 2) * grad(1) - hess(1, 2) * grad(2), &
               hess(1, 1) * grad(2) - hess(1, 2) * grad(1)] / det
      step = step * min(1.0_dp, 0.5_dp / maxval(abs(step)))
      trial = min(max(guess + step, 0.0_dp), upper)
      if (maxval(abs(trial - guess)) <= 1e-12_dp) then
        converged = .true.
        guess = trial
        return
      end if
      guess = trial
    end do
  end subroutine newton_projection

  !> Closest point (s, t) of the upper mid-surface grid to p, from the warm start guess;
  !> fallback: restart from the nearest of 5 x 5 samples per element. fallbacks counts
  !> restarts; info = 1 when no sweep converged.
  pure subroutine project_point(e, dofs, grid, sizes, p, guess, iterations, fallbacks, info)
    real(dp), intent(in) :: e(:), sizes(:, :), p(3)
    integer, intent(in) :: dofs(:, :), grid(:, :)
    real(dp), intent(inout) :: guess(2)
    integer, intent(inout) :: iterations, fallbacks
    integer, intent(out) :: info
    real(dp) :: best(2), best_dist, dist2, grad(2), hess(2, 2), s, t
    logical :: converged
    integer :: i, j, m, n
    info = 0
    call newton_projection(e, dofs, grid, sizes, p, guess, iterations, converged)
    if (converged) return
    fallbacks = fallbacks + 1
    best_dist = huge(1.0_dp)
    best = guess
    do i = 0, size(grid, 1) - 1
      do j = 0, size(grid, 2) - 1
        do m = 0, 4
          do n = 0, 4
            s = i + 0.1_dp + 0.2_dp * m
            t = j + 0.1_dp + 0.2_dp * n
            call distance_terms(e, dofs, grid, sizes, p, s, t, dist2, grad, hess)
            if (dist2 < best_dist) then
              best_dist = dist2
              best = [s, t]
            end if
          end do
        end do
      end do
    end do
    guess = best
    call newton_projection(e, dofs, grid, sizes, p, guess, iterations, converged)
    if (.not. converged) info = 1
  end subroutine project_point

  !> Contact of the lower-leaf point at local (xi_p, eta_p) of its element (coordinates
  !> lower, velocities lower_rates, sizes a_l, b_l) with the upper element at local
  !> (xi_q, eta_q): generalized forces on both elements (to be added to the right-hand
  !> side), on request the Jacobian S_c (72 x 72, upper then lower) of minus those forces,
  !> the record (penetration, F_n, |F_t|, |V_tan|), the penalty potential and the powers of
  !> contact damping and friction. info = 1: a normal vanished.
  pure subroutine contact_point(upper, upper_rates, a_u, b_u, xi_q, eta_q, lower, lower_rates, &
                                a_l, b_l, xi_p, eta_p, params, velocity_factor, want_jacobian, &
                                force_upper, force_lower, jacobian, record, potential, powers, &
                                active, info)
    real(dp), intent(in) :: upper(3, plate_shapes), upper_rates(3, plate_shapes), a_u, b_u
    real(dp), intent(in) :: xi_q, eta_q, lower(3, plate_shapes), lower_rates(3, plate_shapes)
    real(dp), intent(in) :: a_l, b_l, xi_p, eta_p, params(cp_count), velocity_factor
    logical, intent(in) :: want_jacobian
    real(dp), intent(out) :: force_upper(3 * plate_shapes), force_lower(3 * plate_shapes)
    real(dp), intent(out) :: jacobian(6 * plate_shapes, 6 * plate_shapes), record(4)
    real(dp), intent(out) :: potential, powers(2)
    logical, intent(out) :: active
    integer, intent(out) :: info
    real(dp) :: shape_q(plate_shapes), shape_p(plate_shapes), r_q(3), r_p(3), v_q(3), v_p(3)
    real(dp) :: n_q(3), n_p(3), dn_q(3), dn_p(3), grad_nq(3, 36), grad_np(3, 36)
    real(dp) :: map_q(3, 36), map_p(3, 36), gap_gradient(72), relative(3, 72)
    real(dp) :: rates(72), v_rel(3), v_tan(3), gap, delta, rate, normal_force, stiffness
    real(dp) :: friction_force(3), phi(3), dphi(3, 3), slip, s, projector(3, 3), k_pen, c_pen
    real(dp) :: mu, v_t, h_u, h_l, tangent_force(72)
    integer :: k, i
    force_upper = 0.0_dp
    force_lower = 0.0_dp
    if (want_jacobian) jacobian = 0.0_dp
    record = 0.0_dp
    potential = 0.0_dp
    powers = 0.0_dp
    active = .false.
    k_pen = params(cp_stiffness)
    c_pen = params(cp_damping)
    mu = params(cp_friction)
    v_t = params(cp_slip_velocity)
    h_u = params(cp_upper_thickness)
    h_l = params(cp_lower_thickness)
    call surface_frame(upper, upper_rates, xi_q, eta_q, a_u, b_u, shape_q, r_q, v_q, n_q, dn_q, &
                       grad_nq, info)
    if (info /= 0) return
    call surface_frame(lower, lower_rates, xi_p, eta_p, a_l, b_l, shape_p, r_p, v_p, n_p, dn_p, &
                       grad_np, info)
    if (info /= 0) return
    gap = dot_product(r_q - r_p, n_q) - 0.5_dp * h_u - 0.5_dp * h_l * dot_product(n_p, n_q)
    if (gap >= 0.0_dp) return
    active = .true.
    delta = -gap
    ! G = dg/de (upper, lower) and the surface points' maps A_Q, A_P
    do k = 1, plate_shapes
      gap_gradient(3 * k - 2:3 * k) = shape_q(k) * n_q
      gap_gradient(36 + 3 * k - 2:36 + 3 * k) = -shape_p(k) * n_q
      map_q(:, 3 * k - 2:3 * k) = 0.0_dp
      map_p(:, 3 * k - 2:3 * k) = 0.0_dp
      do i = 1, 3
        map_q(i, 3 * (k - 1) + i) = shape_q(k)
        map_p(i, 3 * (k - 1) + i) = shape_p(k)
      end do
    end do
    gap_gradient(1:36) = gap_gradient(1:36) - 0.5_dp * h_l * matmul(n_p, grad_nq)
    gap_gradient(37:72) = gap_gradient(37:72) - 0.5_dp * h_l * matmul(n_q, grad_np)
    map_q = map_q - 0.5_dp * h_u * grad_nq
    map_p = map_p + 0.5_dp * h_l * grad_np
    relative(:, 1:36) = map_q
    relative(:, 37:72) = -map_p
    do k = 1, plate_shapes
      rates(3 * k - 2:3 * k) = upper_rates(:, k)
      rates(36 + 3 * k - 2:36 + 3 * k) = lower_rates(:, k)
    end do
    v_rel = matmul(relative, rates)
    rate = dot_product(gap_gradient, rates)
    normal_force = k_pen * delta - c_pen * rate * delta
    stiffness = k_pen - c_pen * rate + velocity_factor * c_pen * delta
    if (normal_force <= 0.0_dp) then
      normal_force = 0.0_dp
      stiffness = 0.0_dp
    end if
    potential = 0.5_dp * k_pen * delta ** 2
    powers(1) = (normal_force - k_pen * delta) * rate
    projector = -spread(n_q, 2, 3) * spread(n_q, 1, 3)
    do i = 1, 3
      projector(i, i) = projector(i, i) + 1.0_dp
    end do
    v_tan = matmul(projector, v_rel)
    slip = norm2(v_tan)
    friction_force = 0.0_dp
    phi = 0.0_dp
    dphi = 0.0_dp
    if (params(cp_friction_on) > 0.5_dp .and. normal_force > 0.0_dp) then
      s = slip / v_t
      if (s < 1.0_dp) then
        phi = (2.0_dp - s) * v_tan / v_t
        dphi = -spread(v_tan, 2, 3) * spread(v_tan, 1, 3) / (max(slip, tiny(1.0_dp)) * v_t * v_t)
        do i = 1, 3
          dphi(i, i) = dphi(i, i) + (2.0_dp - s) / v_t
        end do
      else
        phi = v_tan / slip
        dphi = -spread(phi, 2, 3) * spread(phi, 1, 3) / slip
        do i = 1, 3
          dphi(i, i) = dphi(i, i) + 1.0_dp / slip
        end do
      end if
      friction_force = -mu * normal_force * phi
      powers(2) = dot_product(friction_force, v_rel)
    end if
    tangent_force = matmul(transpose(relative), friction_force)
    force_upper = normal_force * gap_gradient(1:36) + tangent_force(1:36)
    force_lower = normal_force * gap_gradient(37:72) + tangent_force(37:72)
    record = [delta, normal_force, norm2(friction_force), slip]
    if (.not. want_jacobian) return
    do k = 1, 72
      jacobian(:, k) = stiffness * gap_gradient * gap_gradient(k)
    end do
    if (params(cp_friction_on) > 0.5_dp .and. normal_force > 0.0_dp) then
      tangent_force = matmul(transpose(relative), phi)
      do k = 1, 72
        jacobian(:, k) = jacobian(:, k) - mu * stiffness * tangent_force * gap_gradient(k)
      end do
      jacobian = jacobian + velocity_factor * mu * normal_force * &
                 matmul(transpose(relative), matmul(matmul(dphi, projector), relative))
    end if
  end subroutine contact_point

  !> All contact points: project (warm start from and update of guesses(2, npoints)),
  !> evaluate, add the generalized forces to force(nfull) and, when values is present, the
  !> Jacobians to the CSR values of the full pattern (row_ptr, col, 1-based, sorted columns;
  !> entries missing from the pattern are counted and left out). Records (contact_record,
  !> npoints), penalty potential and the powers (damping, friction) are totals.
  !> info = 8: a projection failed; 7: a normal vanished.
  pure subroutine contact_assemble(e, rates, dofs, sizes, grid, point_element, point_local, &
                                   params, velocity_factor, guesses, force, records, potential, &
                                   powers, counts, info, row_ptr, col, values)
    real(dp), intent(in) :: e(:), rates(:), sizes(:, :), point_local(:, :), params(cp_count)
    real(dp), intent(in) :: velocity_factor
    integer, intent(in) :: dofs(:, :), grid(:, :), point_element(:)
    real(dp), intent(inout) :: guesses(:, :), force(:)
    real(dp), intent(out) :: records(:, :), potential, powers(2)
    integer, intent(inout) :: counts(contact_counters)
    integer, intent(out) :: info
    integer, intent(in), optional :: row_ptr(:), col(:)
    real(dp), intent(inout), optional :: values(:)
    real(dp) :: force_upper(36), force_lower(36), jacobian(72, 72), record(4), point_potential
    real(dp) :: point_powers(2), p(3), shape(plate_shapes), point_derivs(plate_shapes, 5)
    real(dp) :: xi_q, eta_q
    integer :: c, upper, lower, index(72), order(72), place(72), i, j, k, m, last
    logical :: active, want_jacobian
    info = 0
    potential = 0.0_dp
    powers = 0.0_dp
    records = 0.0_dp
    want_jacobian = present(values)
    do c = 1, size(point_element)
      lower = point_element(c)
      counts(cc_points) = counts(cc_points) + 1
      ! the point's position on the lower leaf
      call plate_shape(point_local(1, c), point_local(2, c), sizes(1, lower), sizes(2, lower), &
                       shape, point_derivs)
      p = matmul(element_coords(e, dofs(:, lower)), shape)
      call project_point(e, dofs, grid, sizes, p, guesses(:, c), counts(cc_iterations), &
                         counts(cc_fallbacks), info)
      if (info /= 0) then
        info = 8
        return
      end if
      records(:, c) = 0.0_dp
      records(5:6, c) = guesses(:, c)
      ! a point beyond the upper leaf's ends has no closest point inside it: no contact
      if (guesses(1, c) <= 0.0_dp .or. guesses(1, c) >= real(size(grid, 1), dp)) cycle
      call locate(grid, guesses(1, c), guesses(2, c), upper, xi_q, eta_q)
      call contact_point(element_coords(e, dofs(:, upper)), element_coords(rates, dofs(:, upper)), &
                         sizes(1, upper), sizes(2, upper), xi_q, eta_q, &
                         element_coords(e, dofs(:, lower)), element_coords(rates, dofs(:, lower)), &
                         sizes(1, lower), sizes(2, lower), point_local(1, c), &
                         point_local(2, c), params, velocity_factor, want_jacobian, force_upper, &
                         force_lower, jacobian, record, point_potential, point_powers, active, info)
      if (info /= 0) then
        info = 7
        return
      end if
      records(1:4, c) = record
      records(5:6, c) = guesses(:, c)
      if (.not. active) cycle
      counts(cc_active) = counts(cc_active) + 1
      if (params(cp_friction_on) > 0.5_dp) counts(cc_friction) = counts(cc_friction) + 1
      potential = potential + point_potential
      powers = powers + point_powers
      force(dofs(:, upper)) = force(dofs(:, upper)) + force_upper
      force(dofs(:, lower)) = force(dofs(:, lower)) + force_lower
      if (.not. want_jacobian) cycle
      index(1:36) = dofs(:, upper)
      index(37:72) = dofs(:, lower)
      call ascending_order(index, order)
      do i = 1, 72
        ! the positions of row index(i)'s 72 entries in the pattern (place 0: absent) by one
        ! merge of its sorted columns with the sorted index, in place of a binary search each
        m = row_ptr(index(i))
        last = row_ptr(index(i) + 1) - 1
        do k = 1, 72
          j = order(k)
          do while (m <= last)
            if (col(m) >= index(j)) exit
            m = m + 1
          end do
          place(j) = 0
          if (m <= last) then
            if (col(m) == index(j)) place(j) = m
          end if
        end do
        do j = 1, 72
          if (jacobian(i, j) == 0.0_dp) cycle
          if (place(j) == 0) then
            counts(cc_dropped) = counts(cc_dropped) + 1
          else
            values(place(j)) = values(place(j)) + jacobian(i, j)
          end if
        end do
      end do
    end do
  end subroutine contact_assemble

  !> order: the permutation that sorts values ascending (values(order) non-decreasing;
  !> insertion sort, equal values in their given order).
  pure subroutine ascending_order(values, order)
    integer, intent(in) :: values(:)
    integer, intent(out) :: order(:)
    integer :: i, k, held
    do i = 1, size(values)
      held = i
      k = i - 1
      do while (k >= 1)
        if (values(order(k)) <= values(held)) exit
        order(k + 1) = order(k)
        k = k - 1
      end do
      order(k + 1) = held
    end do
  end subroutine ascending_order

end module leaf_contact
