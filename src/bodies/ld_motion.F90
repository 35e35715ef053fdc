! The particle velocities of one lubrication-dynamics step (&fluid model = 'none'): the 6N system
! that mod_lubrication_dynamics assembles into the solver's system, solved by its owner,
! mod_particle_solver (directly, block by block, when no pair couples it, else by the KSP with the
! prefix particles_, the same options as the DNS);
! then the contacts' implicit update, the links' corrections and the hydrodynamic force, torque
! and stresslet of every sphere. Identical on every rank (replicated data).
#include <petsc/finclude/petscksp.h>
module mod_ld_motion
  use petscksp
  use mod_kinds, only: dp
  use mod_particles, only: particles_t, MOTION_FREE, MOTION_FROZEN, impose_motion
  use mod_particle_solver, only: particle_solver_t, particle_solver_solve
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_corrections
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_implicit_update
  use mod_lubrication_dynamics, only: lubrication_dynamics_t, lubrication_dynamics_assemble, &
                                      lubrication_dynamics_hydrodynamics
  implicit none
  private
  public :: ld_motion_solve

contains

  !> U, Omega of the spheres at X^n (free and frozen: force- and torque-free apart from the
  !> external and contact forces; prescribed, resistance: imposed; fixed: at rest), then their
  !> hydrodynamics. solver: the owner of the 6N system, which it holds between steps.
  !> lubrication, contacts: each absent when the run has none.
  subroutine ld_motion_solve(ld, solver, parts, ierr, lubrication, contacts)
    type(lubrication_dynamics_t), intent(in) :: ld
    type(particle_solver_t), intent(inout) :: solver
    type(particles_t), intent(inout) :: parts
    PetscErrorCode, intent(out) :: ierr
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    type(particle_contacts_t), intent(inout), optional :: contacts
    real(dp), allocatable :: rhs(:, :)

    ierr = 0
    select case (parts%motion)
    case (MOTION_FREE, MOTION_FROZEN)
      allocate(rhs(6, parts%n))
      call lubrication_dynamics_assemble(ld, parts, solver%system, rhs, lubrication, contacts)
      PetscCall(particle_solver_solve(solver, rhs, parts, ierr, ''))
      if (present(contacts)) call particle_contacts_implicit_update(contacts, parts%velocity, parts%omega)
    case default                    ! prescribed, resistance, fixed
      call impose_motion(parts)
    end select
    if (present(lubrication)) call particle_lubrication_corrections(lubrication, parts%velocity, parts%omega)
    call lubrication_dynamics_hydrodynamics(ld, parts, lubrication)
  end subroutine ld_motion_solve

end module mod_ld_motion
