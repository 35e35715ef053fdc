! One PetscLogStage per phase of the time step, so that -log_view tells where the time goes, and
! within them one PetscLogEvent per part that costs (the particle sub-steps, the fast-transform
! solves), so that the stage table of doc/BENCHMARKS.md §8 can be split further.
#include <petsc/finclude/petscsys.h>
module mod_timers
  use petscsys
  implicit none
  private
  public :: timers_register, stage_push, stage_pop, event_begin, event_end
  public :: EVENT_GEOMETRY, EVENT_CARRY, EVENT_MOMENTS, EVENT_MOTION, EVENT_UPDATE, EVENT_FFT
  public :: STAGE_SETUP, STAGE_FLUID, STAGE_OUTPUT, STAGE_PARTICLES, STAGE_CONTACTS, STAGE_LUBRICATION

  integer, parameter :: STAGE_SETUP = 1, STAGE_FLUID = 2, STAGE_OUTPUT = 3, STAGE_PARTICLES = 4, &
                        STAGE_CONTACTS = 5, STAGE_LUBRICATION = 6
  character(len=*), parameter :: stage_names(6) = ['Setup      ', 'Fluid      ', 'Output     ', 'Particles  ', &
                                                   'Contacts   ', 'Lubrication']
  PetscLogStage, save :: stages(6)
  integer, parameter :: EVENT_GEOMETRY = 1, EVENT_CARRY = 2, EVENT_MOMENTS = 3, EVENT_MOTION = 4, &
                        EVENT_UPDATE = 5, EVENT_FFT = 6
  character(len=*), parameter :: event_names(6) = ['FDGeometry   ', 'FDCarryLambda', 'FDMoments    ', &
                                                   'ParticleSolve', 'FDUpdate     ', 'FFTSolve     ']
  PetscLogEvent, save :: events(6) = -1

contains

  subroutine timers_register(ierr)
    PetscErrorCode, intent(out) :: ierr
    integer :: s
    PetscClassId :: class
    do s = 1, size(stages)
      PetscCall(PetscLogStageRegister(trim(stage_names(s)), stages(s), ierr))
    end do
    PetscCall(PetscClassIdRegister('fdsusp', class, ierr))
    do s = 1, size(events)
      PetscCall(PetscLogEventRegister(trim(event_names(s)), class, events(s), ierr))
    end do
  end subroutine timers_register

  ! Events may be used before timers_register (unit tests, set-up): then they record nothing.
  subroutine event_begin(e, ierr)
    integer, intent(in) :: e
    PetscErrorCode, intent(out) :: ierr
    ierr = 0
    if (events(e) < 0) return
    PetscCall(PetscLogEventBegin(events(e), ierr))
  end subroutine event_begin

  subroutine event_end(e, ierr)
    integer, intent(in) :: e
    PetscErrorCode, intent(out) :: ierr
    ierr = 0
    if (events(e) < 0) return
    PetscCall(PetscLogEventEnd(events(e), ierr))
  end subroutine event_end

  subroutine stage_push(s, ierr)
    integer, intent(in) :: s
    PetscErrorCode, intent(out) :: ierr
    PetscCall(PetscLogStagePush(stages(s), ierr))
  end subroutine stage_push

  subroutine stage_pop(ierr)
    PetscErrorCode, intent(out) :: ierr
    PetscCall(PetscLogStagePop(ierr))
  end subroutine stage_pop

end module mod_timers
