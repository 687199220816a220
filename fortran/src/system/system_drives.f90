!> The drives of a mechanical system (a component of system_model): the table of prescribed
!> time functions (drives.f90 kinds, their data by drive) that frames, driven constraints,
!> driven forces, point loads and force elements refer to by number. No I/O.
module system_drives
  use ancf_kinds, only: dp
  use constraints, only: drive_value
  implicit none
  private
  public :: drive_table, drive_at

  type :: drive_table
    ! per drive its kind and its data data(ptr(d):ptr(d + 1) - 1)
    integer, allocatable :: kinds(:), ptr(:)
    real(dp), allocatable :: data(:)
  end type drive_table

contains

  !> Drive d's phi, phi', phi'' at t (d = 0: none, all 0); info /= 0 when it fails
  !> (drive_value).
  pure subroutine drive_at(drives, d, t, phi, dphi, ddphi, info)
    type(drive_table), intent(in) :: drives
    integer, intent(in) :: d
    real(dp), intent(in) :: t
    real(dp), intent(out) :: phi, dphi, ddphi
    integer, intent(out) :: info
    call drive_value(d, drives%kinds, drives%ptr, drives%data, t, phi, dphi, ddphi, info)
  end subroutine drive_at

end module system_drives
