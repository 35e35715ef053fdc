! One PetscLogStage per phase of the time step, so that -log_view tells where the time goes.
! Later phases (particles, lubrication, contacts) register their own stage here.
#include <petsc/finclude/petscsys.h>
module mod_timers
  use petscsys
  implicit none
  private
  public :: timers_register, stage_push, stage_pop
  public :: STAGE_SETUP, STAGE_FLUID, STAGE_OUTPUT, STAGE_PARTICLES, STAGE_CONTACTS, STAGE_LUBRICATION

  integer, parameter :: STAGE_SETUP = 1, STAGE_FLUID = 2, STAGE_OUTPUT = 3, STAGE_PARTICLES = 4, &
                        STAGE_CONTACTS = 5, STAGE_LUBRICATION = 6
  character(len=*), parameter :: stage_names(6) = ['Setup      ', 'Fluid      ', 'Output     ', 'Particles  ', &
                                                   'Contacts   ', 'Lubrication']
  PetscLogStage, save :: stages(6)

contains

  subroutine timers_register(ierr)
    PetscErrorCode, intent(out) :: ierr
    integer :: s
    do s = 1, size(stages)
      PetscCall(PetscLogStageRegister(trim(stage_names(s)), stages(s), ierr))
    end do
  end subroutine timers_register

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
