!> Numeric kinds shared by every module of the kernel.
module ancf_kinds
  use, intrinsic :: iso_fortran_env, only: real64
  implicit none
  private
  !> Working precision of the whole kernel.
  integer, parameter, public :: dp = real64
end module ancf_kinds
