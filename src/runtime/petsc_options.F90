! Defaults in PETSc's options database that the command line may override: every solver of
! fdsusp (the fluid's KSPs, the particle system's) sets its defaults here before KSPSetFromOptions,
! so a user's -u_ksp_rtol or -particles_pc_type always wins. In runtime, not in the fluid, because
! the lubrication-dynamics path has no fluid but sets the particle solver's defaults.
#include <petsc/finclude/petscsys.h>
module mod_petsc_options
  use petscsys
  implicit none
  private
  public :: set_default_option

contains

  !> Set option name to value unless the options database already holds name.
  subroutine set_default_option(name, value, ierr)
    character(len=*), intent(in) :: name, value
    PetscErrorCode, intent(out) :: ierr
    PetscBool :: set
    PetscCall(PetscOptionsHasName(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, name, set, ierr))
    if (.not. set) then
      PetscCall(PetscOptionsSetValue(PETSC_NULL_OPTIONS, name, value, ierr))
    end if
  end subroutine set_default_option

end module mod_petsc_options
