!> The energies and the frame's power of a modally reduced FFR run's output rows (python
!> ancfdrv.solvers.ffr_reduced.RowMaps, docs/theory.md "Modal reduction of FFR bodies"):
!> constant quadratic and cubic forms of the reduced state, evaluated row by row in one
!> pass (numpy spent ~90 M instructions on the temporaries and calls of the same forms
!> over the 10 s luffing run's 10,001 rows). Per row, with psi the frame angle, psi' its
!> rate, eta and eta' the reduced state:
!>   kinetic = 1/2 z^T K z,        z = (psi', psi' eta, eta')
!>   strain  = c^T S c + E(c),     c = (1, sin psi, 1 - cos psi, eta)
!>   power   = psi' c^T P c + psi' F(c)
!>   load    = l0 + (1, eta) . (l1 + sin psi l2 + (1 - cos psi) l3)
!> E and F the P-delta cubic forms, as sums over the monomials c_i c_j c_k (i <= j <= k)
!> of the coefficients c(used) in the order of ffr_reduced._cubic_table (for k, for j <= k,
!> for i <= j), table(:, 1) for E and table(:, 2) for F.
module reduced_ffr_rows
  use ancf_kinds, only: dp
  implicit none
  private
  public :: reduced_energy_rows

contains

  !> The forms of the module doc at nrow rows, in blocks of rows_per_block rows: every
  !> loop runs over the rows of a block (contiguous, vectorized), the sums of each row in
  !> the order of quadratic_rows and the monomials'. nused = 0: no cubic forms (used, table
  !> unread).
  pure subroutine reduced_energy_rows(r, nrow, nused, nmono, rate, sin_psi, one_minus_cos, &
                                      eta, velocity, kinetic_form, strain_form, power_form, &
                                      used, table, load_constant, load_linear, kinetic, &
                                      strain, power, load)
    integer, intent(in) :: r, nrow, nused, nmono
    real(dp), intent(in) :: rate(nrow), sin_psi(nrow), one_minus_cos(nrow)
    real(dp), intent(in) :: eta(r, nrow), velocity(r, nrow)
    real(dp), intent(in) :: kinetic_form(1 + 2 * r, 1 + 2 * r)
    real(dp), intent(in) :: strain_form(3 + r, 3 + r), power_form(3 + r, 3 + r)
    integer, intent(in) :: used(nused)
    real(dp), intent(in) :: table(nmono, 2), load_constant, load_linear(1 + r, 3)
    real(dp), intent(out) :: kinetic(nrow), strain(nrow), power(nrow), load(nrow)
    integer, parameter :: rows_per_block = 64
    real(dp) :: z(rows_per_block, 1 + 2 * r), c(rows_per_block, 3 + r)
    real(dp) :: pair(rows_per_block, max(nused * (nused + 1) / 2, 1))
    real(dp) :: monomial
    real(dp) :: cubic_strain(rows_per_block), cubic_power(rows_per_block)
    real(dp) :: linear(rows_per_block, 3), form(rows_per_block)
    integer :: first, last, nb, i, j, k, at, row
    do first = 1, nrow, rows_per_block
      last = min(nrow, first + rows_per_block - 1)
      nb = last - first + 1
      z(1:nb, 1) = rate(first:last)
      c(1:nb, 1) = 1.0_dp
      c(1:nb, 2) = sin_psi(first:last)
      c(1:nb, 3) = one_minus_cos(first:last)
      do i = 1, r
        z(1:nb, 1 + i) = rate(first:last) * eta(i, first:last)
        z(1:nb, 1 + r + i) = velocity(i, first:last)
        c(1:nb, 3 + i) = eta(i, first:last)
      end do
      call quadratic_rows(nb, 1 + 2 * r, kinetic_form, z, form)
      kinetic(first:last) = 0.5_dp * form(1:nb)
      call quadratic_rows(nb, 3 + r, strain_form, c, form)
      strain(first:last) = form(1:nb)
      call quadratic_rows(nb, 3 + r, power_form, c, form)
      power(first:last) = rate(first:last) * form(1:nb)
      if (nused > 0) then
        ! the pairs c_i c_j (i <= j, ordered by j), then each monomial a pair times c_k
        at = 0
        do j = 1, nused
          do i = 1, j
            at = at + 1
            pair(1:nb, at) = c(1:nb, used(i)) * c(1:nb, used(j))
          end do
        end do
        cubic_strain(1:nb) = 0.0_dp
        cubic_power(1:nb) = 0.0_dp
        at = 0
        do k = 1, nused
          do j = 1, k * (k + 1) / 2
            at = at + 1
            do row = 1, nb   ! one pass per monomial (no monomial array)
              monomial = pair(row, j) * c(row, used(k))
              cubic_strain(row) = cubic_strain(row) + monomial * table(at, 1)
              cubic_power(row) = cubic_power(row) + monomial * table(at, 2)
            end do
          end do
        end do
        strain(first:last) = strain(first:last) + cubic_strain(1:nb)
        power(first:last) = power(first:last) + rate(first:last) * cubic_power(1:nb)
      end if
      do k = 1, 3
        linear(1:nb, k) = load_linear(1, k)
        do i = 1, r
          linear(1:nb, k) = linear(1:nb, k) + c(1:nb, 3 + i) * load_linear(1 + i, k)
        end do
      end do
      load(first:last) = load_constant + (linear(1:nb, 1) + sin_psi(first:last) * linear(1:nb, 2) &
                                          + one_minus_cos(first:last) * linear(1:nb, 3))
    end do
  end subroutine reduced_energy_rows

  !> value(row) = x(row, :) a x(row, :)^T at rows 1..nb of x, each as
  !> sum_i (sum_j x(row, j) a(j, i)) x(row, i) in the order of i and j.
  pure subroutine quadratic_rows(nb, n, a, x, value)
    integer, intent(in) :: nb, n
    real(dp), intent(in) :: a(n, n), x(:, :)
    real(dp), intent(out) :: value(:)
    real(dp) :: column(size(value))
    integer :: i, j
    value(1:nb) = 0.0_dp
    do i = 1, n
      column(1:nb) = 0.0_dp
      do j = 1, n
        column(1:nb) = column(1:nb) + x(1:nb, j) * a(j, i)
      end do
      value(1:nb) = value(1:nb) + column(1:nb) * x(1:nb, i)
    end do
  end subroutine quadratic_rows

end module reduced_ffr_rows
