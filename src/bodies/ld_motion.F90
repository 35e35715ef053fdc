! The particle velocities of one lubrication-dynamics step (&fluid model = 'none'): the 6N system
! that mod_lubrication_dynamics assembles into the solver's system, solved by its owner,
! mod_particle_solver (directly, block by block, when no pair couples it, else by the KSP with the
! prefix particles_, the same options as the DNS);
! then the contacts' implicit update, the links' corrections and the hydrodynamic force, torque
! and stresslet of every sphere. Identical on every rank (replicated data; each rank holds the
! lubrication links of its own spheres, whose corrections mod_lubrication_links gathers).
! Under stress control (ld_motion_solve_stress; doc/METHOD.md §7.4) the step's rate is an unknown:
! the step is affine in it, so two solves with the same matrix (the rate-independent part and the
! part per unit rate) and one scalar equation give it.
#include <petsc/finclude/petscksp.h>
module mod_ld_motion
  use petscksp
  use mod_kinds, only: dp
  use mod_errors, only: fatal_error
  use mod_particles, only: particles_t, MOTION_FREE, MOTION_FROZEN, impose_motion
  use mod_particle_solver, only: particle_solver_t, particle_solver_solve
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_corrections
  use mod_ld_local, only: ld_local_t, ld_local_forward_motion, ld_local_contacts_update
  use mod_lubrication_links, only: lubrication_links_corrections
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_implicit_update, particle_contacts_set_rate
  use mod_lubrication_dynamics, only: lubrication_dynamics_t, lubrication_dynamics_assemble, &
                                      lubrication_dynamics_hydrodynamics
  use mod_rheology, only: rheology_t, rheo_particle_shear_stress
  implicit none
  private
  public :: ld_motion_solve, ld_motion_solve_stress

contains

  !> U, Omega of the spheres at X^n (free and frozen: force- and torque-free apart from the
  !> external and contact forces; prescribed, resistance: imposed; fixed: at rest), then their
  !> hydrodynamics. solver: the owner of the 6N system, which it holds between steps.
  !> lubrication, contacts: each absent when the run has none. local (optional): parts is this
  !> rank's local set (mod_ld_local): the solve gives the own spheres' velocities, the halo brings
  !> the ghosts' before the contacts' update and the links' corrections (each rank's own sums
  !> complete, nothing gathered).
  subroutine ld_motion_solve(ld, solver, parts, ierr, lubrication, contacts, local)
    type(lubrication_dynamics_t), intent(in) :: ld
    type(particle_solver_t), intent(inout) :: solver
    type(particles_t), intent(inout) :: parts
    PetscErrorCode, intent(out) :: ierr
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    type(particle_contacts_t), intent(inout), optional :: contacts
    type(ld_local_t), intent(inout), optional :: local
    real(dp), allocatable :: rhs(:, :)

    ierr = 0
    select case (parts%motion)
    case (MOTION_FREE, MOTION_FROZEN)
      allocate(rhs(6, parts%n))
      call lubrication_dynamics_assemble(ld, parts, solver%system, rhs, lubrication, contacts)
      PetscCall(particle_solver_solve(solver, rhs, parts, ierr, ''))
      if (present(local)) then
        PetscCall(ld_local_forward_motion(local%halo, parts, ierr))
        if (present(contacts)) then
          PetscCall(ld_local_contacts_update(contacts, parts%velocity, parts%omega, ierr))
        end if
      else if (present(contacts)) then
        call particle_contacts_implicit_update(contacts, parts%velocity, parts%omega)
      end if
    case default                    ! prescribed, resistance, fixed
      call impose_motion(parts)
    end select
    if (present(lubrication)) then
      if (present(local)) then
        call particle_lubrication_corrections(lubrication, parts%velocity, parts%omega)
      else
        PetscCall(lubrication_links_corrections(lubrication, parts%velocity, parts%omega, ierr))
      end if
    end if
    call lubrication_dynamics_hydrodynamics(ld, parts, lubrication)
  end subroutine ld_motion_solve

  !> Stress control (doc/METHOD.md §7.4): the rate gamma_dot of this step such that the mean shear
  !> stress of the configuration, eta gamma_dot + Sigma^h_xy + Sigma^c_xy as mod_rheology weighs it
  !> (rheo_particle_shear_stress), equals stress; then the spheres' velocities and hydrodynamics at
  !> that rate, as ld_motion_solve leaves them. Free or frozen spheres. Within a step everything
  !> the rate enters is affine in it: the one-body drive R_1B U_inf, the links' drives (evaluated
  !> per unit rate: lubrication%shear_rate = 1 when its links were made), the walls' and the
  !> Lees-Edwards images' velocities in the implicit contacts; the matrix (R_1B, the links' R, the
  !> contacts' stiffness, whose sliding state the explicit contact forces of particle_contacts_step
  !> fixed at the start of the step) does not depend on it. So U = U_0 + gamma_dot U_1 with
  !>   A U_0 = b(0),  A U_1 = b(1) - b(0),
  !> the stress is sigma(gamma_dot) = sigma_0 + gamma_dot (sigma_1 - sigma_0), and
  !> gamma_dot = (stress - sigma_0)/(sigma_1 - sigma_0): two solves, no iteration. The guesses of
  !> the solves come from the checkpointed state alone (0 for U_0, U^{n-1}/gamma_dot^{n-1} for U_1),
  !> so that a restart repeats the iterations bitwise. rate: in, the last step's rate (the one the
  !> velocities U^{n-1} and the explicit contact forces went with); out, this step's. reached: the stress the step's velocities give (stress to round-off).
  !> rheology: the statistics' weights (mod_params asks for &rheology under stress control).
  !> local (optional): parts is this rank's local set (mod_ld_local; the statistics told it too):
  !> the two solves' own velocities forwarded to the ghosts, the links' corrections of the own
  !> spheres, and the mean stress summed over the ranks' own spheres.
  subroutine ld_motion_solve_stress(ld, solver, parts, stress, rate, reached, ierr, rheology, lubrication, contacts, local)
    type(lubrication_dynamics_t), intent(inout) :: ld
    type(particle_solver_t), intent(inout) :: solver
    type(particles_t), intent(inout) :: parts
    real(dp), intent(in) :: stress
    real(dp), intent(inout) :: rate
    real(dp), intent(out) :: reached
    PetscErrorCode, intent(out) :: ierr
    type(rheology_t), intent(in), optional :: rheology
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    type(particle_contacts_t), intent(inout), optional :: contacts
    type(ld_local_t), intent(inout), optional :: local
    real(dp), allocatable :: rhs0(:, :), rhs1(:, :), u0(:, :), w0(:, :), u1(:, :), w1(:, :)
    real(dp), allocatable :: drive(:, :), wall_drive(:, :), uinf(:, :)
    real(dp), allocatable :: c_force(:, :), c_torque(:, :), c_stresslet(:, :, :)
    real(dp) :: sigma0, sigma1, slope, rate_before, c_wall_force(3, 2)
    logical :: c_added
    character(len=300) :: text
    integer :: n, np, nw

    ierr = 0
    n = parts%n
    rate_before = rate
    if (.not. present(rheology)) call fatal_error('fdsusp: fatal: stress control with spheres needs the '// &
                                                  'statistics'' weights (&rheology)', 4)
    if (parts%motion /= MOTION_FREE .and. parts%motion /= MOTION_FROZEN) &
      call fatal_error('fdsusp: fatal: stress control needs free or frozen spheres', 4)
    ! the links' rate-proportional data, made per unit rate
    if (present(lubrication)) then
      np = lubrication%npairs
      nw = lubrication%nwalls
      drive = lubrication%pair_drive(:, 1:np)
      uinf = lubrication%pair_uinf(:, 1:np)
      wall_drive = lubrication%wall_drive(:, 1:nw)
    end if
    allocate(rhs0(6, n), rhs1(6, n))
    call set_rate(0.0_dp)
    call lubrication_dynamics_assemble(ld, parts, solver%system, rhs0, lubrication, contacts)
    call set_rate(1.0_dp)
    call lubrication_dynamics_assemble(ld, parts, solver%system, rhs1, lubrication, contacts)
    rhs1 = rhs1 - rhs0
    ! U_0 from rest, U_1 from the last step's velocities per unit of its rate
    if (rate /= 0.0_dp) then
      u1 = parts%velocity / rate
      w1 = parts%omega / rate
    else
      u1 = 0.0_dp * parts%velocity
      w1 = 0.0_dp * parts%omega
    end if
    parts%velocity = 0.0_dp
    parts%omega = 0.0_dp
    PetscCall(particle_solver_solve(solver, rhs0, parts, ierr, ' (stress control: the rate-independent part)'))
    if (present(local)) then
      PetscCall(ld_local_forward_motion(local%halo, parts, ierr))
    end if
    u0 = parts%velocity
    w0 = parts%omega
    parts%velocity = u1
    parts%omega = w1
    PetscCall(particle_solver_solve(solver, rhs1, parts, ierr, ' (stress control: the part per unit rate)'))
    if (present(local)) then
      PetscCall(ld_local_forward_motion(local%halo, parts, ierr))
    end if
    u1 = parts%velocity
    w1 = parts%omega
    ! the stress at rates 0 and 1; the contacts' step forces are kept for the final update
    if (present(contacts)) then
      c_force = contacts%force
      c_torque = contacts%torque
      c_stresslet = contacts%stresslet
      c_wall_force = contacts%wall_force
      c_added = contacts%stiffness_added
    end if
    PetscCall(at_rate(0.0_dp, u0, w0, sigma0))
    PetscCall(at_rate(1.0_dp, u0 + u1, w0 + w1, sigma1))
    slope = sigma1 - sigma0
    if (.not. (slope > 0.0_dp)) then
      write(text, '(a,es12.4,a)') 'fdsusp: fatal: stress control: the mean shear stress does not grow with the rate '// &
           '(d sigma/d gamma_dot = ', slope, '): the step cannot set the stress'
      call fatal_error(text, 4)
    end if
    rate = (stress - sigma0) / slope
    PetscCall(at_rate(rate, u0 + rate * u1, w0 + rate * w1, reached))

  contains

    ! every rate-dependent datum of the step at rate r
    subroutine set_rate(r)
      real(dp), intent(in) :: r
      ld%shear_rate = r
      if (present(lubrication)) then
        lubrication%pair_drive(:, 1:np) = r * drive
        lubrication%pair_uinf(:, 1:np) = r * uinf
        lubrication%wall_drive(:, 1:nw) = r * wall_drive
        lubrication%shear_rate = r
        lubrication%le%shear_rate = r
      end if
      if (present(contacts)) call particle_contacts_set_rate(contacts, r, rate_before)
    end subroutine set_rate

    ! the step at rate r with the velocities U, Omega (3, n): every rate-dependent datum, the
    ! spheres' velocities, their contact and hydrodynamic force, torque, stresslet (as
    ! ld_motion_solve leaves them; the contacts' step forces restored first), and sigma, the mean
    ! shear stress they give. Collective (the links' corrections; the host's ierr).
    subroutine at_rate(r, u, w, sigma)
      real(dp), intent(in) :: r, u(:, :), w(:, :)
      real(dp), intent(out) :: sigma
      call set_rate(r)
      parts%velocity = u
      parts%omega = w
      if (present(contacts)) then
        contacts%force = c_force
        contacts%torque = c_torque
        contacts%stresslet = c_stresslet
        contacts%wall_force = c_wall_force
        contacts%stiffness_added = c_added
        if (present(local)) then
          PetscCall(ld_local_contacts_update(contacts, u, w, ierr))
        else
          call particle_contacts_implicit_update(contacts, u, w)
        end if
      end if
      if (present(lubrication)) then
        if (present(local)) then
          call particle_lubrication_corrections(lubrication, u, w)
        else
          PetscCall(lubrication_links_corrections(lubrication, u, w, ierr))
        end if
      end if
      call lubrication_dynamics_hydrodynamics(ld, parts, lubrication)
      if (present(contacts)) then
        sigma = rheo_particle_shear_stress(rheology, parts%position, parts%stresslet_hydro + contacts%stresslet)
      else
        sigma = rheo_particle_shear_stress(rheology, parts%position, parts%stresslet_hydro)
      end if
      ! (a local set: this rank's own spheres' share)
      if (present(local)) then
        PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, sigma, 1, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr))
      end if
      sigma = ld%viscosity * r + sigma
    end subroutine at_rate
  end subroutine ld_motion_solve_stress

end module mod_ld_motion
