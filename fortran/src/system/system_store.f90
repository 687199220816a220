!> The table of mechanical systems behind integer handles: Python builds a system once,
!> piece by piece (ancf_api's system_* routines), and steps it chunk by chunk without
!> sending its arrays again. Beside each system its stepper (stepper.f90: the run's
!> settings and what the stepper learned), apart from the system type. Besides
!> sparse_direct's solver table, this is the kernel's only module state.
module system_store
  use mechanical_system, only: system_model
  use stepper, only: stepper_run
  use sparse_direct, only: solver_destroy
  implicit none
  private
  public :: store_create, store_destroy, store_get

  integer, parameter :: max_systems = 256

  type :: system_slot
    type(system_model) :: model
    type(stepper_run) :: stepper
    logical :: in_use = .false.
  end type system_slot

  type(system_slot), target, save :: slots(max_systems)

contains

  !> A new, empty system. info = 1: no free slot.
  subroutine store_create(handle, info)
    integer, intent(out) :: handle, info
    integer :: h
    handle = 0
    info = 1
    do h = 1, max_systems
      if (.not. slots(h)%in_use) then
        slots(h)%in_use = .true.
        slots(h)%model = system_model()
        slots(h)%stepper = stepper_run()
        handle = h
        info = 0
        return
      end if
    end do
  end subroutine store_create

  !> Releases a system (its arrays and the static Newton's solver, which the system owns;
  !> its iteration matrix's solver is its creator's). info = 1: not a live handle.
  subroutine store_destroy(handle, info)
    integer, intent(in) :: handle
    integer, intent(out) :: info
    integer :: ignored
    info = 1
    if (handle < 1 .or. handle > max_systems) return
    if (.not. slots(handle)%in_use) return
    if (slots(handle)%model%matrix%saddle_handle /= 0) &
      call solver_destroy(slots(handle)%model%matrix%saddle_handle, ignored)
    slots(handle)%model = system_model()
    slots(handle)%stepper = stepper_run()
    slots(handle)%in_use = .false.
    info = 0
  end subroutine store_destroy

  !> The system behind a handle, and on request its stepper. info = 1: not a live handle
  !> (model and run then unassociated).
  subroutine store_get(handle, model, info, run)
    integer, intent(in) :: handle
    type(system_model), pointer, intent(out) :: model
    integer, intent(out) :: info
    type(stepper_run), pointer, intent(out), optional :: run
    model => null()
    if (present(run)) run => null()
    info = 1
    if (handle < 1 .or. handle > max_systems) return
    if (.not. slots(handle)%in_use) return
    model => slots(handle)%model
    if (present(run)) run => slots(handle)%stepper
    info = 0
  end subroutine store_get

end module system_store
