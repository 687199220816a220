!> Errors that carry their message (as tblite's error type does): the f2py layer returns
!> an integer code and a fixed-length text, and the Python wrappers raise with the text.
!> This module holds the texts of the codes the system routines share; a routine that
!> detects a problem of its own writes its own text.
module kernel_errors
  implicit none
  private
  public :: failure_text, handle_text

  !> Length of the message buffers of the f2py routines.
  integer, parameter, public :: message_length = 200

contains

  !> The text of a failure code of the force evaluations and the stepper (mechanical_system,
  !> time_integrator), for the codes that carry no detail.
  pure function failure_text(code) result(text)
    integer, intent(in) :: code
    character(len=message_length) :: text
    select case (code)
    case (5)
      text = 'a constraint or drive could not be evaluated'
    case (6)
      text = "a bending moment's section director became parallel to its axis"
    case (7)
      text = "an element's configuration is degenerate (a plate's mid-surface normal " // &
             "vanished: r_x parallel to r_y; or a cable's slope r' vanished)"
    case (8)
      text = 'the contact search found no closest point on the upper surface (the ' // &
             'projection diverged even from the sampled restart)'
    case (10)
      text = "a force element's two points coincide (its line of action is undefined) " // &
             'or its force table could not be evaluated'
    case default
      write (text, '(a, i0)') 'kernel failure code ', code
    end select
  end function failure_text

  !> The text of a handle that names no live system.
  pure function handle_text(handle) result(text)
    integer, intent(in) :: handle
    character(len=message_length) :: text
    write (text, '(a, i0, a)') 'handle ', handle, ' is not a live system (destroyed, or ' // &
      'never created): a stale handle'
  end function handle_text

end module kernel_errors
