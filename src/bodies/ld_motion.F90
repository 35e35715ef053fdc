! The particle velocities of one lubrication-dynamics step (&fluid model = 'none'): the 6N system of
! mod_lubrication_dynamics solved directly, block by block, when no pair couples it, else by the
! sparse solver of mod_particle_solver (KSP prefix particles_, the same options as the DNS);
! then the contacts' implicit update, the links' corrections and the hydrodynamic force, torque
! and stresslet of every sphere. Identical on every rank (replicated data).
#include <petsc/finclude/petscksp.h>
module mod_ld_motion
  use petscksp
  use mod_kinds, only: dp
  use mod_particles, only: particles_t, MOTION_FREE, MOTION_FROZEN, impose_motion
  use mod_particle_solver, only: particle_solver_t, psolver_solve_checked
  use mod_particle_lubrication, only: particle_lubrication_t, plub_corrections
  use mod_particle_contacts, only: particle_contacts_t, pcontacts_implicit_update
  use mod_lubrication_dynamics, only: lubrication_dynamics_t, ld_assemble, ld_hydrodynamics
  implicit none
  private
  public :: ld_solve_motion

contains

  !> U, Omega of the spheres at X^n (free and frozen: force- and torque-free apart from the
  !> external and contact forces; prescribed, resistance: imposed; fixed: at rest), then their
  !> hydrodynamics. lubrication, contacts: each absent when the run has none.
  subroutine ld_solve_motion(ld, solver, parts, ierr, lubrication, contacts)
    type(lubrication_dynamics_t), intent(inout) :: ld
    type(particle_solver_t), intent(inout) :: solver
    type(particles_t), intent(inout) :: parts
    PetscErrorCode, intent(out) :: ierr
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    type(particle_contacts_t), intent(inout), optional :: contacts
    real(dp), allocatable :: rhs(:, :), x(:, :)
    integer :: iterations

    ierr = 0
    select case (parts%motion)
    case (MOTION_FREE, MOTION_FROZEN)
      allocate(rhs(6, parts%n), x(6, parts%n))
      ! the last velocities start an iterative solve (they are in the checkpoint)
      x(1:3, :) = parts%velocity
      x(4:6, :) = parts%omega
      call ld_assemble(ld, parts, rhs, lubrication, contacts)
      PetscCall(psolver_solve_checked(solver, ld%system, rhs, x, iterations, ierr, ''))
      parts%velocity = x(1:3, :)
      parts%omega = x(4:6, :)
      if (present(contacts)) call pcontacts_implicit_update(contacts, parts%velocity, parts%omega)
    case default                    ! prescribed, resistance, fixed
      call impose_motion(parts)
    end select
    if (present(lubrication)) call plub_corrections(lubrication, parts%velocity, parts%omega)
    call ld_hydrodynamics(ld, parts, lubrication)
  end subroutine ld_solve_motion

end module mod_ld_motion
