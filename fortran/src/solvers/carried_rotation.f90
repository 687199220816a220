!> The iteration matrix carried with the system's rotation (issue 23, item 3), each body
!> (a group of system_carry) with its own.
!>
!> Every coordinate of an absolute-coordinate system (ANCF positions and gradients, a rigid
!> body's position and directors) is a 3-vector in the global axes, the mass matrix is
!> kron(Mbar, I3) and the elastic forces are objective. Turning a configuration q rigidly by
!> R turns its iteration matrix with it: S(T q) = T S(q) T^T with T = blockdiag(R, R, ..)
!> (the mass term because every 3 x 3 block of M is a scalar times I3, the stiffness
!> because the strain energy does not change under a rigid turn). A matrix factorized at
!> q_f therefore serves at a state q that is q_f turned by R, plus a deformation, as
!> S(q)^{-1} ~ T S(q_f)^{-1} T^T, where reusing it unturned would see its stiff directions
!> (axial, in-plane) misaligned by the whole turn: modified Newton then stops contracting
!> and the stepper refactorizes in every step of a spinning or swinging body.
!>
!> R is fitted to the carried 3-vectors of each body (weighted orthogonal Procrustes, the
!> Kabsch algorithm: positions about their weighted centroid, gradients and directors as
!> they are): the rotation that best maps the body's vectors at the factorization onto the
!> current ones. A small multiple of the identity added to their correlation keeps
!> directions the vectors do not determine (a straight cable's own axis) unturned. Joints
!> are constraints (their gradients exact in every correction), so S is block-diagonal over
!> the bodies and each block turns with its own body: T = blockdiag(R_b) (issue 38: the
!> slider-crank's rod swings +-19 degrees while its crank turns, and one rotation fitted to
!> both served neither). On reduced coordinates e (q = B e + q0) the turn is T_e = B^T T B,
!> exact where B selects coordinates and the turn keeps the selection (the planar
!> reduction, turned about the plane's normal); a joint the reduction eliminated
!> (a coordinate scaled or shared between bodies) turns with one owner (system_carry), an
!> approximation the simplified iteration's contraction measures. The model layer enables
!> the carry where each row of B holds at most one entry (python/ancfdrv/system/model.py,
!> carry_vectors).
!>
!> The turned matrix is a preconditioner of the simplified Newton iteration: the residual
!> and the constraints are exact, so the converged state does not depend on it; only the
!> number of corrections (and of refactorizations) does. No I/O; the 3 x 3 polar factor by
!> Newton iterations, LAPACK dgesvd where they do not settle.
module carried_rotation
  use ancf_kinds, only: dp
  use mechanical_system, only: system_model
  use system_carry, only: carry_apply, plane_turn_rows
  use system_constraints, only: add_gradient_column, operand_count
  implicit none
  private
  public :: carry_turn, carry_gradients, &
            carry_plane_gradients

  !> the identity's share of the fitted correlation (relative to its Frobenius norm)
  real(dp), parameter :: identity_share = 1e-6_dp

contains

  !> The rotation of each group (turn(:, :, g), system_carry) that best maps its reference
  !> vectors onto its current ones (weighted; positions about their centroids) and the
  !> largest of their angles (rad). info = 1: an SVD failed (that turn = identity).
  subroutine carry_turn(sys, reference, current, turn, angle, info)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: reference(:, :), current(:, :)
    real(dp), intent(out) :: turn(:, :, :), angle
    integer, intent(out) :: info
    real(dp) :: group_angle
    integer :: g
    angle = 0.0_dp
    do g = 1, size(turn, 3)
      call group_turn(sys, g, reference, current, turn(:, :, g), group_angle, info)
      if (info /= 0) return
      angle = max(angle, group_angle)
    end do
  end subroutine carry_turn

  !> carry_turn of group g's vectors.
  subroutine group_turn(sys, g, reference, current, turn, angle, info)
    type(system_model), intent(in) :: sys
    integer, intent(in) :: g
    real(dp), intent(in) :: reference(:, :), current(:, :)
    real(dp), intent(out) :: turn(3, 3), angle
    integer, intent(out) :: info
    real(dp) :: correlation(3, 3), centre_ref(3), centre_now(3), weight_sum, scale
    real(dp) :: a(3), b(3)
    integer :: k, i, j
    logical :: settled
    centre_ref = 0.0_dp
    centre_now = 0.0_dp
    weight_sum = 0.0_dp
    do k = 1, size(sys%carry%first)
      if (.not. sys%carry%position(k) .or. sys%carry%group(k) /= g) cycle
      centre_ref = centre_ref + sys%carry%weight(k) * reference(:, k)
      centre_now = centre_now + sys%carry%weight(k) * current(:, k)
      weight_sum = weight_sum + sys%carry%weight(k)
    end do
    if (weight_sum > 0.0_dp) then
      centre_ref = centre_ref / weight_sum
      centre_now = centre_now / weight_sum
    end if
    correlation = 0.0_dp  ! sum w b a^T (b: reference, a: current)
    do k = 1, size(sys%carry%first)
      if (sys%carry%group(k) /= g) cycle
      if (sys%carry%position(k)) then
        b = sys%carry%weight(k) * (reference(:, k) - centre_ref)
        a = current(:, k) - centre_now
      else
        b = sys%carry%weight(k) * reference(:, k)
        a = current(:, k)
      end if
      do j = 1, 3
        correlation(:, j) = correlation(:, j) + b * a(j)
      end do
    end do
    scale = identity_share * sqrt(sum(correlation**2))
    do i = 1, 3
      correlation(i, i) = correlation(i, i) + scale
    end do
    ! the orthogonal polar factor of correlation^T = V S U^T is V U^T: scaled Newton
    ! iterations X <- (g X + X^{-T} / g) / 2 (Higham 1986), a few hundred flops; the SVD
    ! where they do not settle on a rotation
    angle = 0.0_dp
    if (all([correlation(1, 3), correlation(2, 3), correlation(3, 1), correlation(3, 2)] &
            == 0.0_dp)) then
      ! vectors in the xy plane (a scene reduced to it): the rotation about z that
      ! maximizes trace(R^T correlation^T), closed form (the polar iterations do not
      ! settle on the nearly rank-one correlation of a straight beam, the SVD costs
      ! ~4000 instructions a step)
      call plane_rotation(correlation, turn)
      info = 0
    else
      call polar_factor(transpose(correlation), turn, settled)
      if (settled) then
        info = 0
      else
        call svd_rotation(correlation, turn, info)
        if (info /= 0) return
      end if
    end if
    angle = acos(max(-1.0_dp, min(1.0_dp, 0.5_dp * (turn(1, 1) + turn(2, 2) + turn(3, 3) &
                                                     - 1.0_dp))))
  end subroutine group_turn

  !> The rotation about z, turn = [c -s 0; s c 0; 0 0 1], that maximizes
  !> trace(turn^T correlation^T) = c (C11 + C22) + s (C12 - C21): the angle
  !> atan2(C12 - C21, C11 + C22) (C = correlation, its z row and column zero but C33).
  pure subroutine plane_rotation(correlation, turn)
    real(dp), intent(in) :: correlation(3, 3)
    real(dp), intent(out) :: turn(3, 3)
    real(dp) :: theta
    theta = atan2(correlation(1, 2) - correlation(2, 1), correlation(1, 1) + correlation(2, 2))
    turn = 0.0_dp
    turn(1, 1) = cos(theta)
    turn(2, 1) = sin(theta)
    turn(1, 2) = -turn(2, 1)
    turn(2, 2) = turn(1, 1)
    turn(3, 3) = 1.0_dp
  end subroutine plane_rotation

  !> The rotation V diag(1, 1, d) U^T of correlation = U S V^T (d = det(V U^T)); info = 1:
  !> the SVD failed (turn = identity).
  subroutine svd_rotation(correlation, turn, info)
    real(dp), intent(in) :: correlation(3, 3)
    real(dp), intent(out) :: turn(3, 3)
    integer, intent(out) :: info
    real(dp) :: work_matrix(3, 3), left(3, 3), right_t(3, 3), singular(3), work(64)
    real(dp) :: flip(3, 3)
    integer :: i
    work_matrix = correlation
    call dgesvd('A', 'A', 3, 3, work_matrix, 3, singular, left, 3, right_t, 3, work, &
                size(work), info)
    turn = 0.0_dp
    do i = 1, 3
      turn(i, i) = 1.0_dp
    end do
    if (info /= 0) then
      info = 1
      return
    end if
    flip = turn
    turn = matmul(transpose(right_t), transpose(left))
    if (determinant(turn) < 0.0_dp) then
      flip(3, 3) = -1.0_dp
      turn = matmul(transpose(right_t), matmul(flip, transpose(left)))
    end if
  end subroutine svd_rotation

  !> The orthogonal factor of the polar decomposition of x (scaled Newton iterations);
  !> ok = .false. where x is singular, the iterations do not settle within 40, or the factor is
  !> a reflection (then the SVD decides).
  pure subroutine polar_factor(x, factor, ok)
    real(dp), intent(in) :: x(3, 3)
    real(dp), intent(out) :: factor(3, 3)
    logical, intent(out) :: ok
    real(dp) :: inverse_t(3, 3), next(3, 3), det, gamma
    integer :: k
    ok = .false.
    factor = x
    do k = 1, 40
      det = determinant(factor)
      if (.not. abs(det) > tiny(1.0_dp)) return
      ! the inverse transposed: the cofactor matrix over the determinant
      inverse_t(1, :) = [factor(2, 2) * factor(3, 3) - factor(2, 3) * factor(3, 2), &
                         factor(2, 3) * factor(3, 1) - factor(2, 1) * factor(3, 3), &
                         factor(2, 1) * factor(3, 2) - factor(2, 2) * factor(3, 1)] / det
      inverse_t(2, :) = [factor(1, 3) * factor(3, 2) - factor(1, 2) * factor(3, 3), &
                         factor(1, 1) * factor(3, 3) - factor(1, 3) * factor(3, 1), &
                         factor(1, 2) * factor(3, 1) - factor(1, 1) * factor(3, 2)] / det
      inverse_t(3, :) = [factor(1, 2) * factor(2, 3) - factor(1, 3) * factor(2, 2), &
                         factor(1, 3) * factor(2, 1) - factor(1, 1) * factor(2, 3), &
                         factor(1, 1) * factor(2, 2) - factor(1, 2) * factor(2, 1)] / det
      gamma = sqrt(sqrt(sum(inverse_t**2) / sum(factor**2)))
      next = 0.5_dp * (gamma * factor + inverse_t / gamma)
      if (sum((next - factor)**2) <= (1e-13_dp)**2 * sum(next**2)) then
        factor = next
        ok = determinant(factor) > 0.0_dp
        return
      end if
      factor = next
    end do
  end subroutine polar_factor

  pure real(dp) function determinant(a)
    real(dp), intent(in) :: a(3, 3)
    determinant = a(1, 1) * (a(2, 2) * a(3, 3) - a(3, 2) * a(2, 3)) &
                  - a(1, 2) * (a(2, 1) * a(3, 3) - a(3, 1) * a(2, 3)) &
                  + a(1, 3) * (a(2, 1) * a(3, 2) - a(3, 1) * a(2, 2))
  end function determinant

  !> columns (ndof, ncon): T_e^T Phi_e^T, the constraint gradients turned back to the
  !> factorization's axes (the right-hand sides of the Schur complement's flexibility);
  !> column (ndof): work (the caller's: an automatic array was a heap allocation a call).
  pure subroutine carry_gradients(sys, turn, gradients, columns, column)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: turn(:, :, :), gradients(:, :)
    real(dp), intent(out) :: columns(:, :), column(:)
    integer :: c
    do c = 1, sys%constraints%ncon
      column = 0.0_dp
      call add_gradient_column(sys%constraints, gradients, c, 6, column)
      call carry_apply(sys%carry, turn, column, .true., columns(:, c))
    end do
  end subroutine carry_gradients

  !> carry_gradients of a planar reduction (carry_plane) at the listed pairs only (pairs:
  !> indices into carry_plane, holding every term dof of the constraints): columns at
  !> those pairs' coordinates as carry_gradients gives them (the same scatter into a zeroed
  !> column, the same turn as carry_apply's plane path), the other rows not written.
  pure subroutine carry_plane_gradients(sys, turn, gradients, pairs, columns, column)
    type(system_model), intent(in) :: sys
    real(dp), intent(in) :: turn(:, :, :), gradients(:, :)
    integer, intent(in) :: pairs(:)
    real(dp), intent(inout) :: columns(:, :), column(:)
    real(dp) :: r11, r12, r13, r21, r22, r23, v1, v2
    integer :: c, p, first, second, g, current
    do c = 1, sys%constraints%ncon
      do p = 1, size(pairs)
        column(sys%carry%plane(1, pairs(p))) = 0.0_dp
        column(sys%carry%plane(2, pairs(p))) = 0.0_dp
      end do
      ! (the operands up to the last with terms: the rest are empty)
      call add_gradient_column(sys%constraints, gradients, c, operand_count(sys%constraints, c), &
                               column)
      current = 0
      do p = 1, size(pairs)
        ! (back: the transposed turn of the pair's group, as carry_apply(.., back = .true., ..))
        g = sys%carry%plane_group(pairs(p))
        if (g /= current) then
          call plane_turn_rows(transpose(turn(:, :, g)), r11, r12, r13, r21, r22, r23)
          current = g
        end if
        first = sys%carry%plane(1, pairs(p))
        second = sys%carry%plane(2, pairs(p))
        v1 = column(first)
        v2 = column(second)
        columns(first, c) = r11 * v1 + r12 * v2 + r13
        columns(second, c) = r21 * v1 + r22 * v2 + r23
      end do
    end do
  end subroutine carry_plane_gradients

end module carried_rotation
