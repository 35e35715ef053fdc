! One time step of the run, from X^n to X^{n+1} (doc/METHOD.md §7): the resolved variant (the fluid
! by projection, the spheres by the fictitious domain; §7.1) or the fluid-free one (lubrication
! dynamics; §7.2), chosen once by time_step_create from the pieces the run has. The step owns no
! physics object: it points at those main made and calls them in order, each phase in its
! PetscLogStage. Output, statistics' bookkeeping and the run's schedule stay with the caller.
! A contact or lubrication failure ends the step early (time_step_t%contact_failure,
! %lubrication_failure), the state as it was when the failure was found, for the caller to report
! and write as failed_state.h5.
#include <petsc/finclude/petscsys.h>
module mod_time_step
  use petscsys
  use mod_kinds, only: dp
  use mod_grid, only: grid_t
  use mod_fluid, only: fluid_t, fluid_step, fluid_mean_profile
  use mod_timers, only: stage_push, stage_pop, STAGE_FLUID, STAGE_PARTICLES, STAGE_CONTACTS, STAGE_LUBRICATION
  use mod_particles, only: particles_t, advance_positions, displacements
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_step
  use mod_particle_lubrication, only: particle_lubrication_t
  use mod_rheology, only: rheology_t, rheo_sample, rheo_sample_flow
  use mod_lees_edwards, only: lees_edwards_t, le_wrap, le_advance
  use mod_lubrication_dynamics, only: lubrication_dynamics_t
  use mod_fictitious_domain, only: fictitious_domain_t, fictitious_domain_geometry, fictitious_domain_follow, &
                                   fictitious_domain_moments, fictitious_domain_solve_motion, fictitious_domain_update
  use mod_lubrication_links, only: lubrication_links_evaluate
  use mod_ld_motion, only: ld_motion_solve
  use mod_particle_solver, only: particle_solver_t
  implicit none
  private
  public :: time_step_t, time_step_create, time_step_advance

  ! the variants
  integer, parameter :: TIME_STEP_FLUID = 1       ! the fluid alone (no spheres)
  integer, parameter :: TIME_STEP_RESOLVED = 2    ! fluid and spheres (fictitious domain)
  integer, parameter :: TIME_STEP_FLUID_FREE = 3  ! the spheres alone (lubrication dynamics)

  type :: time_step_t
    integer :: variant = 0
    real(dp) :: dt = 0.0_dp
    real(dp) :: box(3) = 0.0_dp
    logical :: walls = .false.
    ! Lambda carried with the moving spheres (default); .false. recomputes the geometry at X^{n+1}
    ! and leaves Lambda on the faces of X^n (the scheme before 2026-11-23, -fd_carry_lambda 0)
    logical :: carry_lambda = .true.
    ! why the last step ended early (0: it did not): particle_contacts_step's info, or the link
    ! (particle, partner or 0 for a wall) whose lubrication block could not be decomposed
    integer :: contact_failure = 0
    integer :: lubrication_failure(2) = 0
    type(grid_t), pointer :: grid => null()
    type(fluid_t), pointer :: fluid => null()
    type(fictitious_domain_t), pointer :: fd => null()
    type(particles_t), pointer :: parts => null()
    type(particle_contacts_t), pointer :: contacts => null()
    type(particle_lubrication_t), pointer :: lubrication => null()
    type(rheology_t), pointer :: rheology => null()
    type(lees_edwards_t), pointer :: le => null()
    type(lubrication_dynamics_t), pointer :: ld => null()
    type(particle_solver_t), pointer :: ld_solver => null()
    real(dp), allocatable :: mean_flow(:)          ! x-z plane means of u per cell row (statistics)
    real(dp), allocatable :: position_before(:, :) ! X^n, then X^{n+1} - X^n
  end type time_step_t

contains

  ! The step of a run: fluid (grid, fluid), spheres (parts) with, when resolved, their fictitious
  ! domain fd, or, without a fluid, their lubrication dynamics (ld, ld_solver); contacts,
  ! lubrication and rheology where the run has them; le: the Lees-Edwards boundaries (offset 0
  ! when inactive). walls: walls in y. Collective (resolved: the geometry of X^n is built here).
  subroutine time_step_create(ts, dt, box, walls, le, carry_lambda, ierr, grid, fluid, fd, parts, ld, ld_solver, &
                              contacts, lubrication, rheology)
    type(time_step_t), intent(out) :: ts
    real(dp), intent(in) :: dt, box(3)
    logical, intent(in) :: walls, carry_lambda
    type(lees_edwards_t), target, intent(in) :: le
    PetscErrorCode, intent(out) :: ierr
    type(grid_t), target, intent(in), optional :: grid
    type(fluid_t), target, intent(in), optional :: fluid
    type(fictitious_domain_t), target, intent(in), optional :: fd
    type(particles_t), target, intent(in), optional :: parts
    type(lubrication_dynamics_t), target, intent(in), optional :: ld
    type(particle_solver_t), target, intent(in), optional :: ld_solver
    type(particle_contacts_t), target, intent(in), optional :: contacts
    type(particle_lubrication_t), target, intent(in), optional :: lubrication
    type(rheology_t), target, intent(in), optional :: rheology
    ierr = 0
    ts%dt = dt
    ts%box = box
    ts%walls = walls
    ts%carry_lambda = carry_lambda
    ts%le => le
    if (present(grid)) ts%grid => grid
    if (present(fluid)) ts%fluid => fluid
    if (present(fd)) ts%fd => fd
    if (present(parts)) ts%parts => parts
    if (present(ld)) ts%ld => ld
    if (present(ld_solver)) ts%ld_solver => ld_solver
    if (present(contacts)) ts%contacts => contacts
    if (present(lubrication)) ts%lubrication => lubrication
    if (present(rheology)) ts%rheology => rheology
    if (associated(ts%fluid) .and. associated(ts%parts)) then
      ts%variant = TIME_STEP_RESOLVED
    else if (associated(ts%fluid)) then
      ts%variant = TIME_STEP_FLUID
    else
      ts%variant = TIME_STEP_FLUID_FREE
    end if
    if (associated(ts%rheology) .and. associated(ts%fluid)) allocate(ts%mean_flow(0:ts%grid%n(2) - 1))
    if (ts%variant == TIME_STEP_RESOLVED) then
      ! the geometry at X^n; each step then moves it, and Lambda with it, to X^{n+1}
      PetscCall(stage_push(STAGE_PARTICLES, ierr))
      call fictitious_domain_geometry(ts%grid, ts%fd, ts%parts)
      PetscCall(stage_pop(ierr))
    end if
  end subroutine time_step_create

  ! One step: X^n, u^n to X^{n+1}, u^{n+1} (doc/METHOD.md §7). The core statistics sample the
  ! configuration X^n with its velocities before it moves on. Collective.
  subroutine time_step_advance(ts, ierr)
    type(time_step_t), intent(inout) :: ts
    PetscErrorCode, intent(out) :: ierr
    integer :: info
    ierr = 0
    ts%contact_failure = 0
    ts%lubrication_failure = 0
    if (ts%variant == TIME_STEP_FLUID) then
      PetscCall(stage_push(STAGE_FLUID, ierr))
      PetscCall(fluid_step(ts%grid, ts%fluid, ierr))
      PetscCall(stage_pop(ierr))
      return
    end if
    associate(parts => ts%parts, le => ts%le)
      if (associated(ts%contacts)) then
        ! contacts at X^n with the latest velocities (those of the previous step)
        PetscCall(stage_push(STAGE_CONTACTS, ierr))
        call particle_contacts_step(ts%contacts, parts%position, parts%velocity, parts%omega, info, le%offset)
        PetscCall(stage_pop(ierr))
        if (info /= 0) then
          ts%contact_failure = info
          return
        end if
      end if
      if (associated(ts%lubrication)) then
        ! the lubrication links at X^n, taken implicitly in the particle problem below
        PetscCall(stage_push(STAGE_LUBRICATION, ierr))
        PetscCall(lubrication_links_evaluate(ts%lubrication, parts%position, ierr, le%offset))
        PetscCall(stage_pop(ierr))
        if (ts%lubrication%failed_link(1) /= 0) then
          ts%lubrication_failure = ts%lubrication%failed_link
          return
        end if
      end if
      ! (a disassociated pointer passed to an optional argument is absent: contacts, lubrication)
      if (ts%variant == TIME_STEP_RESOLVED) then
        PetscCall(stage_push(STAGE_FLUID, ierr))
        PetscCall(fluid_step(ts%grid, ts%fluid, ierr, ts%fd%lambda))
        PetscCall(stage_pop(ierr))
        PetscCall(stage_push(STAGE_PARTICLES, ierr))
        ! the particle sub-problem (doc/METHOD.md §3.2 eq. (1)): moments of u~ and Lambda^n, the
        ! 6N system for U, Omega, then Lambda^{n+1}, u^{n+1} and the hydrodynamic force, torque,
        ! stresslet
        PetscCall(fictitious_domain_moments(ts%grid, ts%fd, ts%fluid%vel, parts%n, ierr))
        PetscCall(fictitious_domain_solve_motion(ts%fd, parts, ierr, lubrication=ts%lubrication, contacts=ts%contacts))
        PetscCall(fictitious_domain_update(ts%grid, ts%fd, ts%fluid%vel, ts%fluid%pressure, parts, ierr, ts%lubrication))
      else
        PetscCall(stage_push(STAGE_PARTICLES, ierr))
        ! lubrication dynamics: the 6N Stokes balance of the spheres alone (one-body drag in the
        ! imposed flow, the pair and wall links, the contacts), then their hydrodynamic force,
        ! torque and stresslet (doc/METHOD.md §6)
        PetscCall(ld_motion_solve(ts%ld, ts%ld_solver, parts, ierr, lubrication=ts%lubrication, contacts=ts%contacts))
      end if
      ! the core statistics of this configuration, before it moves on
      if (associated(ts%rheology)) then
        if (associated(ts%contacts)) then
          call rheo_sample(ts%rheology, parts%position, parts%velocity, parts%stresslet_hydro, &
                           ts%contacts%stresslet, le%offset)
        else
          call rheo_sample(ts%rheology, parts%position, parts%velocity, parts%stresslet_hydro, offset=le%offset)
        end if
        if (ts%variant == TIME_STEP_RESOLVED) then
          PetscCall(fluid_mean_profile(ts%grid, ts%fluid, ts%mean_flow, ierr))
          call rheo_sample_flow(ts%rheology, ts%mean_flow, ts%grid%h)
        end if
      end if
      ts%position_before = parts%position
      call advance_positions(parts, ts%dt, ts%box, [.true., .not. (ts%walls .or. le%active), .true.])
      if (le%active) then
        ! the boundary slides on; spheres that left through y = 0 or Ly re-enter from the image
        call le_advance(le, ts%dt)
        call le_wrap(le, parts%position, parts%velocity, parts%velocity_prev)
      end if
      if (ts%variant == TIME_STEP_RESOLVED) then
        if (ts%carry_lambda) then
          ts%position_before = displacements(parts%position, ts%position_before, ts%box, [.true., .not. ts%walls, .true.])
          PetscCall(fictitious_domain_follow(ts%grid, ts%fd, parts, ts%position_before, ierr))
        else
          call fictitious_domain_geometry(ts%grid, ts%fd, parts)
        end if
      end if
      PetscCall(stage_pop(ierr))
    end associate
  end subroutine time_step_advance

end module mod_time_step
