!> Cross-sections of the ANCF beam: quadrature rules over the section (points (y, z) and
!> area weights) for the element integrals, and the section properties.
!>
!> The beam's position field is linear in the section coordinates (y along the section
!> height, the director r_y; z along the width, r_z), so the element integrands are
!> polynomials in (y, z): degree 2 for the mass and the small-strain stiffness, up to 4 for
!> the large-deformation energy. The rules:
!>   rectangle (width w, height h): 2 x 2 Gauss points, exact for y^a z^b with a, b <= 3;
!>   box (w, h, wall t): the outer rectangle's rule minus the inner one's (negative weights),
!>     the same exactness;
!>   tube (outer diameter D, wall t) and circle (diameter D): a polar rule, 3 Gauss points in
!>     the radius (weight rho) times 6 equally spaced angles, exact for every polynomial of
!>     total degree <= 5 in (y, z).
!> Properties: area A, I_z = int y^2 dA (bending in the y direction, about z),
!> I_y = int z^2 dA, and the polar moment I_y + I_z (the torsion constant the beam elements
!> use for every section, as the continuum element without warping has).
module beam_section
  use ancf_kinds, only: dp
  use quadrature, only: gauss_legendre
  implicit none
  private
  public :: section_rule, section_properties

  integer, parameter, public :: section_rectangle = 1, section_box = 2, section_tube = 3, &
                                section_circle = 4
  !> The largest rule (tube and circle).
  integer, parameter, public :: max_section_points = 18
  integer, parameter :: n_radial = 3, n_angular = 6
  real(dp), parameter :: pi = 3.14159265358979323846_dp

contains

  !> Number of points of a section kind's rule (0 for an unknown kind).
  pure integer function section_points(kind) result(npoints)
    integer, intent(in) :: kind
    select case (kind)
    case (section_rectangle)
      npoints = 4
    case (section_box)
      npoints = 8
    case (section_tube, section_circle)
      npoints = n_radial * n_angular
    case default
      npoints = 0
    end select
  end function section_points

  !> Points and area weights of the section rule. dims: rectangle (width, height), box
  !> (width, height, wall), tube (diameter, wall), circle (diameter). info: 0 ok, 1 unknown
  !> kind, 2 non-physical dimensions (not positive, or a wall of half the size or more).
  pure subroutine section_rule(kind, dims, npoints, y, z, weight, info)
    integer, intent(in) :: kind
    real(dp), intent(in) :: dims(3)
    integer, intent(out) :: npoints
    real(dp), intent(out) :: y(max_section_points), z(max_section_points)
    real(dp), intent(out) :: weight(max_section_points)
    integer, intent(out) :: info
    real(dp) :: inner, outer
    integer :: i, j, p
    real(dp) :: radial(n_radial), radial_w(n_radial), r, angle
    y = 0.0_dp
    z = 0.0_dp
    weight = 0.0_dp
    npoints = section_points(kind)
    call check_dimensions(kind, dims, info)
    if (info /= 0) return
    select case (kind)
    case (section_rectangle)
      call rectangle_rule(dims(1), dims(2), 1.0_dp, y(1:4), z(1:4), weight(1:4), info)
    case (section_box)
      call rectangle_rule(dims(1), dims(2), 1.0_dp, y(1:4), z(1:4), weight(1:4), info)
      call rectangle_rule(dims(1) - 2.0_dp * dims(3), dims(2) - 2.0_dp * dims(3), -1.0_dp, &
                          y(5:8), z(5:8), weight(5:8), info)
    case (section_tube, section_circle)
      outer = 0.5_dp * dims(1)
      inner = 0.0_dp
      if (kind == section_tube) inner = outer - dims(2)
      call gauss_legendre(n_radial, radial, radial_w, info)
      if (info /= 0) return
      p = 0
      do j = 1, n_angular
        angle = 2.0_dp * pi * (real(j, dp) - 0.5_dp) / real(n_angular, dp)
        do i = 1, n_radial
          p = p + 1
          r = inner + 0.5_dp * (outer - inner) * (radial(i) + 1.0_dp)
          y(p) = r * cos(angle)
          z(p) = r * sin(angle)
          weight(p) = 0.5_dp * (outer - inner) * radial_w(i) * r * 2.0_dp * pi &
                      / real(n_angular, dp)
        end do
      end do
    end select
  end subroutine section_rule

  !> A, I_y = int z^2 dA, I_z = int y^2 dA and the polar moment I_y + I_z, in closed form.
  pure subroutine section_properties(kind, dims, area, inertia_y, inertia_z, polar, info)
    integer, intent(in) :: kind
    real(dp), intent(in) :: dims(3)
    real(dp), intent(out) :: area, inertia_y, inertia_z, polar
    integer, intent(out) :: info
    real(dp) :: wi, hi, ro, ri
    area = 0.0_dp
    inertia_y = 0.0_dp
    inertia_z = 0.0_dp
    call check_dimensions(kind, dims, info)
    if (info /= 0) return
    select case (kind)
    case (section_rectangle)
      area = dims(1) * dims(2)
      inertia_z = dims(1) * dims(2)**3 / 12.0_dp
      inertia_y = dims(2) * dims(1)**3 / 12.0_dp
    case (section_box)
      wi = dims(1) - 2.0_dp * dims(3)
      hi = dims(2) - 2.0_dp * dims(3)
      area = dims(1) * dims(2) - wi * hi
      inertia_z = (dims(1) * dims(2)**3 - wi * hi**3) / 12.0_dp
      inertia_y = (dims(2) * dims(1)**3 - hi * wi**3) / 12.0_dp
    case (section_tube, section_circle)
      ro = 0.5_dp * dims(1)
      ri = 0.0_dp
      if (kind == section_tube) ri = ro - dims(2)
      area = pi * (ro**2 - ri**2)
      inertia_z = 0.25_dp * pi * (ro**4 - ri**4)
      inertia_y = inertia_z
    end select
    polar = inertia_y + inertia_z
  end subroutine section_properties

  pure subroutine check_dimensions(kind, dims, info)
    integer, intent(in) :: kind
    real(dp), intent(in) :: dims(3)
    integer, intent(out) :: info
    info = 0
    select case (kind)
    case (section_rectangle, section_circle)
      if (any(dims(1:merge(2, 1, kind == section_rectangle)) <= 0.0_dp)) info = 2
    case (section_box)
      if (any(dims <= 0.0_dp)) then
        info = 2
      else if (2.0_dp * dims(3) >= min(dims(1), dims(2))) then
        info = 2
      end if
    case (section_tube)
      if (any(dims(1:2) <= 0.0_dp)) then
        info = 2
      else if (2.0_dp * dims(2) > dims(1)) then
        info = 2
      end if
    case default
      info = 1
    end select
  end subroutine check_dimensions

  !> 2 x 2 Gauss rule over a w x h rectangle centred on the axis, weights times sign; the
  !> point order (y fastest) is the element loops' order.
  pure subroutine rectangle_rule(width, height, sign, y, z, weight, info)
    real(dp), intent(in) :: width, height, sign
    real(dp), intent(out) :: y(4), z(4), weight(4)
    integer, intent(out) :: info
    real(dp) :: points(2), weights(2)
    integer :: j, k
    call gauss_legendre(2, points, weights, info)
    do k = 1, 2
      do j = 1, 2
        y(2 * (k - 1) + j) = 0.5_dp * height * points(j)
        z(2 * (k - 1) + j) = 0.5_dp * width * points(k)
        weight(2 * (k - 1) + j) = sign * weights(j) * weights(k) * 0.25_dp * height * width
      end do
    end do
  end subroutine rectangle_rule

end module beam_section
