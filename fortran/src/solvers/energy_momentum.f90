!> The energy-momentum stepper (solver.integrator = 'energy_momentum'; issue 39 item 4): the
!> implicit midpoint rule with a discrete gradient of the strain energy (Simo & Tarnow 1992,
!> Gonzalez 1996), for conservative systems, on the unknowns (e1, lambda):
!>   (e1 - e0) / h = (v0 + v1) / 2,
!>   M (v1 - v0) / h + f_dg(e0, e1) - Q(t_m) - Phi_e(e_m)^T lambda = 0,   Phi(e1) = 0,
!> e_m = (e0 + e1) / 2, t_m = t0 + h / 2. f_dg is the element families' discrete gradient
!> (local_element_set's midpoint_forces: the beam's averaged stress, the cable's and rope's
!> invariant-space secant), reduced by B^T, so W(e1) - W(e0) = f_dg . (e1 - e0) to round-off.
!> The constraints of the kernel are linear or quadratic in e (coordinate, distance, cross and
!> dot kinds: pins and revolute joints), so Phi_e(e_m) (e1 - e0) = Phi(e1) - Phi(e0) exactly
!> and the multipliers do no work; the constant loads (gravity) have a linear potential.
!> Hence with Phi(e0) = 0 the total energy K + W - Q.e of each step is that of the step before
!> to the Newton tolerance, whatever h; and since f_dg, the loads' resultant moment aside, is
!> made of invariants of rigid motion, momentum and angular momentum are conserved too.
!> Newton with the exact Jacobian of this residual, assembled dense:
!>   [ 2/h^2 M + df_dg/de1 - d(Phi_e(e_m)^T lambda)/de1   -Phi_e(e_m)^T ]
!>   [ Phi_e(e1)                                           0            ],
!> factorized through the Schur complement of the multipliers with a banded LU of its first
!> block (LAPACK dgbtrf; O(ndof kd^2) for a half-bandwidth kd: beams and ropes numbered along
!> their length) or, where the band is wide, by a dense LU of the whole (dgetrf,
!> O((ndof + ncon)^3)). The term of the multipliers is exact: the constraint gradients are
!> affine in e, differenced over a half unit of each coordinate they touch. Within a step the
!> Jacobian is kept while each correction is at most keep_contraction times the one before
!> (simplified Newton: a correction costs a force evaluation and a back-substitution), and
!> refreshed at the iterate otherwise; the residual is always exact.
!> Supported: undamped local element sets (the nonlinear beam, the cable, the rope; they
!> take no frame, and frames that do not move are allowed), masses, constant loads,
!> undriven constraints. Anything else (contact, force
!> elements, point loads that follow or are driven, driven forces, moments, moving frames,
!> driven constraints, material damping, a family without a discrete gradient) is refused
!> with info = em_unsupported (Python refuses such scenes before they reach the kernel).
!> No I/O; failures return codes (time_integrator's integrator_chunk's).
module energy_momentum
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model, contact_state, frame_rotations, &
                               external_forces, energies, probe_output, power_count
  use system_mass, only: mass_product
  use system_constraints, only: evaluate_constraints, constraint_reaction, add_gradient_column, &
                                constraint_derivatives
  use system_reduction, only: to_full, to_reduced, row_terms, reduced_col, reduced_coef
  use element_sets, only: local_element_set
  use beam_nonlinear, only: continuum_set
  use beam_cubic, only: cubic_set
  use cable_element, only: cable_set
  use plate_element, only: plate_set
  use kernel_errors, only: message_length
  use stepper, only: stepper_settings
  implicit none
  private
  public :: energy_momentum_chunk, midpoint_residual, energy_momentum_obstacle, dense_mass

  !> integrator_chunk's info of a model the energy-momentum stepper does not support
  integer, parameter, public :: em_unsupported = 14
  !> a step's Jacobian is kept while each correction is at most this times the one before
  !> (simplified Newton); a correction that contracts less refreshes it at the iterate
  real(dp), parameter :: keep_contraction = 0.1_dp

  !> The factors of a step's bordered Jacobian (factor_bordered): banded (A's band LU, Y =
  !> A^{-1} B, C, the Schur complement's LU) or dense (the whole LU).
  type :: bordered_factors
    logical :: banded = .false.
    integer :: kl = 0, ku = 0
    real(dp), allocatable :: band(:, :), y(:, :), c(:, :), schur(:, :), dense(:, :)
    integer, allocatable :: ipiv(:), schur_ipiv(:)
  end type bordered_factors

contains

  !> What of the model the energy-momentum stepper does not support (module header), named
  !> for a message ('' when it supports the model): the first such item found.
  pure function energy_momentum_obstacle(sys) result(text)
    type(system_model), intent(in) :: sys
    character(len=message_length) :: text
    integer :: s
    text = ''
    if (sys%contact%npoint > 0) then
      text = 'contact (a contact pair)'
    else if (sys%force_elements%nfel > 0) then
      text = 'force elements (springs, dampers, cylinders)'
    else if (sys%loads%nvload > 0) then
      text = 'driven or follower point loads'
    else if (nonempty_real(sys%loads%moment_magnitude)) then
      text = 'applied moments'
    else if (allocated(sys%loads%force_drive)) then
      if (size(sys%loads%force_drive) > 0) text = 'driven forces'
    end if
    if (text /= '') return
    if (allocated(sys%frames)) then
      if (size(sys%frames) > 0) then
        if (any(sys%frames%drive /= 0)) text = 'a driven (moving) frame'
      end if
    end if
    if (text /= '') return
    if (allocated(sys%constraints%drive) .and. sys%constraints%ncon > 0) then
      if (any(sys%constraints%drive /= 0)) text = 'driven constraints (drives)'
    end if
    if (text /= '' .or. .not. allocated(sys%sets)) return
    do s = 1, size(sys%sets)
      associate (set => sys%sets(s)%item)
        if (set%damping_time > 0.0_dp) then
          text = 'material damping (Kelvin-Voigt)'
        else
          select type (set)
          type is (continuum_set)
          type is (cable_set)
          type is (cubic_set)
            text = "the 'cubic' beam formulation"
          type is (plate_set)
            text = 'plates'
          class default
            text = 'a floating-frame (FFR) body'
          end select
        end if
      end associate
      if (text /= '') return
    end do
  end function energy_momentum_obstacle

  pure logical function nonempty_real(x)
    real(dp), allocatable, intent(in) :: x(:)
    nonempty_real = .false.
    if (allocated(x)) nonempty_real = size(x) > 0
  end function nonempty_real

  !> The residual of one step from (e0, v0) at t0 with step h, at the unknowns (e1, lambda):
  !> residual(1:ndof) the equations of motion, residual(ndof + 1:) = Phi(e1, t0 + h); internal
  !> the reduced discrete-gradient force f_dg(e0, e1) alone; with jacobian present its
  !> derivative with respect to (e1, lambda) (ndof + ncon, ndof + ncon). mass: the dense M
  !> (ndof, ndof; dense_mass), needed with jacobian. info: em_unsupported, 5 (constraints),
  !> 7 (a degenerate element).
  subroutine midpoint_residual(sys, h, t0, e0, v0, e1, lam, residual, internal, info, mass, &
                               jacobian)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: h, t0, e0(:), v0(:), e1(:), lam(:)
    real(dp), intent(out) :: residual(:), internal(:)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: mass(:, :)
    real(dp), intent(out), optional :: jacobian(:, :)
    real(dp) :: full0(sys%nfull), full1(sys%nfull), full_force(sys%nfull)
    real(dp) :: step(sys%ndof), mid(sys%ndof), loads(sys%ndof)
    real(dp) :: phi(sys%constraints%ncon), gradients(6, sys%constraints%ncon)
    real(dp) :: reaction(sys%ndof), column(sys%ndof), zero_rates(sys%ndof)
    real(dp) :: hessians(6, 6, sys%constraints%ncon), phi_t(sys%constraints%ncon)
    real(dp) :: phi_tt(sys%constraints%ncon), gamma(sys%constraints%ncon)
    real(dp), allocatable :: coords0(:, :), coords1(:, :), force(:), tangent(:, :)
    logical :: want
    integer :: n, s, el, k, i, c, code, nde, s1, s2, k1, k2
    n = sys%ndof
    want = present(jacobian)
    info = 0
    residual = 0.0_dp
    internal = 0.0_dp
    if (energy_momentum_obstacle(sys) /= '') then
      info = em_unsupported
      return
    end if
    if (want) jacobian = 0.0_dp
    call to_full(sys%reduction, e0, .true., full0)
    call to_full(sys%reduction, e1, .true., full1)
    full_force = 0.0_dp
    do s = 1, size(sys%sets)
      select type (set => sys%sets(s)%item)
      class is (local_element_set)
        nde = set%nde
        allocate (coords0(3, nde / 3), coords1(3, nde / 3), force(nde), tangent(nde, nde))
        do el = 1, set%nel
          do k = 1, nde / 3
            do i = 1, 3
              coords0(i, k) = full0(set%dofs(3 * (k - 1) + i, el))
              coords1(i, k) = full1(set%dofs(3 * (k - 1) + i, el))
            end do
          end do
          call set%midpoint_forces(el, coords0, coords1, want, force, tangent, code)
          if (code == 1) then
            info = em_unsupported
            return
          else if (code /= 0) then
            info = 7
            return
          end if
          do k = 1, nde
            full_force(set%dofs(k, el)) = full_force(set%dofs(k, el)) + force(k)
          end do
          if (want) call add_reduced(sys, set%dofs(:, el), tangent, jacobian)
        end do
        deallocate (coords0, coords1, force, tangent)
      class default
        info = em_unsupported
        return
      end select
    end do
    call to_reduced(sys%reduction, full_force, internal)
    step = (2.0_dp / (h * h)) * (e1 - e0 - h * v0)
    call mass_product(sys%mass, step, residual(1:n))
    mid = 0.5_dp * (e0 + e1)
    call external_forces(sys, t0 + 0.5_dp * h, 1.0_dp, loads, info, mid)
    if (info /= 0) return
    residual(1:n) = residual(1:n) + internal - loads
    if (want) jacobian(1:n, 1:n) = jacobian(1:n, 1:n) + (2.0_dp / (h * h)) * mass
    if (sys%constraints%ncon == 0) return
    ! - Phi_e(e_m)^T lambda, and the multipliers' columns -Phi_e(e_m)^T
    call evaluate_constraints(sys%constraints, sys%drives, sys%ndof, mid, t0 + h, phi, gradients, info)
    if (info /= 0) return
    reaction = 0.0_dp
    call constraint_reaction(sys%constraints, gradients, lam, reaction)
    residual(1:n) = residual(1:n) + reaction
    if (want) then
      do c = 1, sys%constraints%ncon
        column = 0.0_dp
        call add_gradient_column(sys%constraints, gradients, c, 6, column)
        jacobian(1:n, n + c) = jacobian(1:n, n + c) - column
      end do
      zero_rates = 0.0_dp
      ! d(-Phi_e(e_m)^T lambda)/de1 = -1/2 sum_c lambda_c Phi_c,ee (e_m = (e0 + e1) / 2), the
      ! constraints' Hessians on their operands' terms (as the static Newton's tangent)
      call constraint_derivatives(sys%constraints, sys%drives, mid, zero_rates, t0 + h, phi, &
                                  gradients, hessians, phi_t, phi_tt, gamma, info)
      if (info /= 0) return
      do c = 1, sys%constraints%ncon
        do s1 = 1, 6
          do s2 = 1, 6
            if (hessians(s1, s2, c) == 0.0_dp) cycle
            do k1 = sys%constraints%term_ptr(6 * (c - 1) + s1), &
                    sys%constraints%term_ptr(6 * (c - 1) + s1 + 1) - 1
              do k2 = sys%constraints%term_ptr(6 * (c - 1) + s2), &
                      sys%constraints%term_ptr(6 * (c - 1) + s2 + 1) - 1
                associate (i => sys%constraints%term_dof(k1), j => sys%constraints%term_dof(k2))
                  jacobian(i, j) = jacobian(i, j) - 0.5_dp * lam(c) * hessians(s1, s2, c) &
                                   * sys%constraints%term_coef(k1) * sys%constraints%term_coef(k2)
                end associate
              end do
            end do
          end do
        end do
      end do
    end if
    call evaluate_constraints(sys%constraints, sys%drives, sys%ndof, e1, t0 + h, phi, gradients, info)
    if (info /= 0) return
    residual(n + 1:n + sys%constraints%ncon) = phi
    if (want) then
      do c = 1, sys%constraints%ncon
        column = 0.0_dp
        call add_gradient_column(sys%constraints, gradients, c, 6, column)
        jacobian(n + c, 1:n) = jacobian(n + c, 1:n) + column
      end do
    end if
  end subroutine midpoint_residual

  !> Factorizes the bordered matrix [A B; C 0] of jacobian ((n + m)^2, A: n x n) into
  !> factors. Where A's band (half-bandwidths kl, ku of its nonzeros) makes LAPACK's banded LU
  !> cheaper than a dense one: A = LU by dgbtrf, Y = A^{-1} B and the LU factors of the
  !> multipliers' Schur complement C Y (m x m, dense); otherwise the dense LU of the whole
  !> (dgetrf). info: LAPACK's (0: factorized).
  subroutine factor_bordered(n, m, jacobian, factors, info)
    integer, intent(in) :: n, m
    real(dp), intent(in) :: jacobian(:, :)
    type(bordered_factors), intent(inout) :: factors
    integer, intent(out) :: info
    integer :: i, j, kl, ku, rows
    kl = 0
    ku = 0
    do j = 1, n
      do i = 1, n
        if (jacobian(i, j) == 0.0_dp) cycle
        kl = max(kl, i - j)
        ku = max(ku, j - i)
      end do
    end do
    rows = 2 * kl + ku + 1
    factors%banded = rows * (kl + ku + 1) < n * n / 3
    if (.not. factors%banded) then
      factors%dense = jacobian(1:n + m, 1:n + m)
      if (allocated(factors%ipiv)) deallocate (factors%ipiv)
      allocate (factors%ipiv(n + m))
      call dgetrf(n + m, n + m, factors%dense, n + m, factors%ipiv, info)
      return
    end if
    factors%kl = kl
    factors%ku = ku
    if (allocated(factors%band)) deallocate (factors%band)
    if (allocated(factors%ipiv)) deallocate (factors%ipiv)
    allocate (factors%band(rows, n), factors%ipiv(n))
    factors%band = 0.0_dp
    do j = 1, n
      do i = max(1, j - ku), min(n, j + kl)
        factors%band(kl + ku + 1 + i - j, j) = jacobian(i, j)
      end do
    end do
    call dgbtrf(n, n, kl, ku, factors%band, rows, factors%ipiv, info)
    if (info /= 0 .or. m == 0) return
    factors%y = jacobian(1:n, n + 1:n + m)
    call dgbtrs('N', n, kl, ku, m, factors%band, rows, factors%ipiv, factors%y, n, info)
    if (info /= 0) return
    factors%c = jacobian(n + 1:n + m, 1:n)
    factors%schur = matmul(factors%c, factors%y)
    if (allocated(factors%schur_ipiv)) deallocate (factors%schur_ipiv)
    allocate (factors%schur_ipiv(m))
    call dgetrf(m, m, factors%schur, m, factors%schur_ipiv, info)
  end subroutine factor_bordered

  !> Solves [A B; C 0] x = rhs with factor_bordered's factors (rhs overwritten by x): the
  !> dense LU's, or z = A^{-1} rhs_1, x_2 = (C Y)^{-1} (C z - rhs_2), x_1 = z - Y x_2.
  subroutine solve_bordered(n, m, factors, rhs)
    integer, intent(in) :: n, m
    type(bordered_factors), intent(in) :: factors
    real(dp), intent(inout) :: rhs(:)
    real(dp) :: z(n, 1), x2(m, 1)
    integer :: info
    if (.not. factors%banded) then
      call dgetrs('N', n + m, 1, factors%dense, n + m, factors%ipiv, rhs, n + m, info)
      return
    end if
    z(:, 1) = rhs(1:n)
    call dgbtrs('N', n, factors%kl, factors%ku, 1, factors%band, size(factors%band, 1), &
                factors%ipiv, z, n, info)
    if (m == 0) then
      rhs(1:n) = z(:, 1)
      return
    end if
    x2(:, 1) = matmul(factors%c, z(:, 1)) - rhs(n + 1:n + m)
    call dgetrs('N', m, 1, factors%schur, m, factors%schur_ipiv, x2, m, info)
    rhs(n + 1:n + m) = x2(:, 1)
    rhs(1:n) = z(:, 1) - matmul(factors%y, x2(:, 1))
  end subroutine solve_bordered

  !> jacobian(1:ndof, 1:ndof) += B^T K B over an element's full dofs (q = B e + q0).
  pure subroutine add_reduced(sys, dofs, tangent, jacobian)
    type(system_model), intent(in) :: sys
    integer, intent(in) :: dofs(:)
    real(dp), intent(in) :: tangent(:, :)
    real(dp), intent(inout) :: jacobian(:, :)
    integer :: a, b, ka, kb
    do b = 1, size(dofs)
      do a = 1, size(dofs)
        if (tangent(a, b) == 0.0_dp) cycle
        do kb = 1, row_terms(sys%reduction, dofs(b))
          do ka = 1, row_terms(sys%reduction, dofs(a))
            associate (i => reduced_col(sys%reduction, dofs(a), ka), &
                       j => reduced_col(sys%reduction, dofs(b), kb))
              jacobian(i, j) = jacobian(i, j) + reduced_coef(sys%reduction, dofs(a), ka) &
                               * tangent(a, b) * reduced_coef(sys%reduction, dofs(b), kb)
            end associate
          end do
        end do
      end do
    end do
  end subroutine add_reduced

  !> The dense mass matrix M (ndof, ndof) of the system (its products with the unit vectors).
  pure subroutine dense_mass(sys, mass)
    type(system_model), intent(in) :: sys
    real(dp), intent(out) :: mass(:, :)
    real(dp) :: unit(sys%ndof)
    integer :: j
    unit = 0.0_dp
    do j = 1, sys%ndof
      unit(j) = 1.0_dp
      call mass_product(sys%mass, unit, mass(:, j))
      unit(j) = 0.0_dp
    end do
  end subroutine dense_mass

  !> nsteps energy-momentum steps of size h from (t, e, e' = v, lambda), in the form and with
  !> the outputs of time_integrator's integrator_chunk (whose arguments these are): a and
  !> e'' both take the step's mean acceleration (v1 - v0) / h. Each step iterates from the
  !> predictor e1 = e0 + h v0 + h^2/2 e''_0 (the Jacobian kept or refreshed: module header)
  !> until a correction max |de| <= tol * length_scale. info: 1 Newton did not converge
  !> (detail 0: the iteration limit); 2 non-finite state; 3 the factorization failed
  !> (detail: LAPACK's info); em_unsupported; 5, 7 (midpoint_residual).
  subroutine energy_momentum_chunk(sys, cfg, h, nsteps, t, e, v, a, accel, lam, work, powers, &
                                   state, out_time, out_probe, out_deflection, out_lambda, &
                                   out_energy, out_constraint, out_stats, out_contact, store_q, &
                                   out_q, steps_done, info, detail, last_correction)
    type(system_model), intent(inout) :: sys
    type(stepper_settings), intent(in) :: cfg
    real(dp), intent(in) :: h
    integer, intent(in) :: nsteps
    real(dp), intent(inout) :: t, e(:), v(:), a(:), accel(:), lam(:), work(power_count)
    real(dp), intent(inout) :: powers(power_count)
    type(contact_state), intent(inout) :: state
    real(dp), intent(out) :: out_time(:), out_probe(:, :, :), out_deflection(:, :, :)
    real(dp), intent(out) :: out_lambda(:, :), out_energy(:, :), out_constraint(:)
    integer, intent(out) :: out_stats(:, :)
    real(dp), intent(out) :: out_contact(:, :, :)
    logical, intent(in) :: store_q
    real(dp), intent(out) :: out_q(:, :)
    integer, intent(out) :: steps_done, info, detail
    real(dp), intent(out) :: last_correction
    real(dp), allocatable :: mass(:, :), jacobian(:, :), residual(:), internal(:), full(:)
    real(dp), allocatable :: phi(:), gradients(:, :)
    real(dp) :: e1(sys%ndof), lam1(sys%constraints%ncon), v1(sys%ndof)
    real(dp) :: rotations(3, 3, 0:size(sys%frames)), rates(0:size(sys%frames))
    real(dp) :: powers_new(power_count), strain, contact_potential
    integer :: n, m, step, it, lapack_info
    logical :: done, refresh
    real(dp) :: previous
    type(bordered_factors) :: factors
    n = sys%ndof
    m = sys%constraints%ncon
    info = 0
    detail = 0
    steps_done = 0
    last_correction = 0.0_dp
    out_stats = 0
    if (energy_momentum_obstacle(sys) /= '') then
      info = em_unsupported
      return
    end if
    allocate (mass(n, n), jacobian(n + m, n + m), residual(n + m), internal(n), &
              full(sys%nfull), phi(m), gradients(6, m))
    call dense_mass(sys, mass)
    do step = 1, nsteps
      call frame_rotations(sys, t + h, rotations, rates, info)
      if (info /= 0) return
      e1 = e + h * v + 0.5_dp * h * h * accel
      lam1 = lam
      done = .false.
      refresh = .true.
      previous = huge(1.0_dp)
      do it = 1, cfg%max_newton
        if (refresh) then
          call midpoint_residual(sys, h, t, e, v, e1, lam1, residual, internal, info, mass, &
                                 jacobian)
          if (info /= 0) return
          call factor_bordered(n, m, jacobian, factors, lapack_info)
          out_stats(2:3, step) = out_stats(2:3, step) + 1
          if (lapack_info /= 0) then
            info = 3
            detail = lapack_info
            return
          end if
          refresh = .false.
        else
          call midpoint_residual(sys, h, t, e, v, e1, lam1, residual, internal, info)
          if (info /= 0) return
        end if
        residual = -residual
        call solve_bordered(n, m, factors, residual)
        out_stats(1, step) = out_stats(1, step) + 1
        if (.not. all(abs(residual) < huge(1.0_dp))) then
          info = 2
          return
        end if
        e1 = e1 + residual(1:n)
        lam1 = lam1 + residual(n + 1:n + m)
        last_correction = maxval(abs(residual(1:n)))
        if (last_correction <= cfg%tol * cfg%length_scale) then
          done = .true.
          exit
        end if
        refresh = last_correction > keep_contraction * previous
        previous = last_correction
      end do
      if (.not. done) then
        info = 1
        detail = 0
        return
      end if
      v1 = 2.0_dp * (e1 - e) / h - v
      accel = (v1 - v) / h
      a = accel
      e = e1
      v = v1
      lam = lam1
      t = t + h
      call energies(sys, rotations, rates, e, v, lam, t, state, strain, powers_new, &
                    contact_potential, out_constraint(step), out_contact(:, :, step), info, &
                    full, phi, gradients)
      if (info /= 0) return
      work = work + 0.5_dp * h * (powers + powers_new)
      powers = powers_new
      steps_done = step
      out_time(step) = t
      out_lambda(:, step) = lam
      call probe_output(sys, rotations, e, v, work, strain, contact_potential, &
                        out_probe(:, :, step), out_deflection(:, :, step), out_energy(:, step), &
                        info, full, internal)
      if (info /= 0) return
      if (store_q) out_q(:, step) = e
    end do
  end subroutine energy_momentum_chunk

end module energy_momentum
