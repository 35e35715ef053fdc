! One time step of the run, from X^n to X^{n+1} (doc/METHOD.md §7): the resolved variant (the fluid
! by projection, the spheres by the fictitious domain; §7.1) or the fluid-free one (lubrication
! dynamics; §7.2), chosen once by time_step_create from the pieces the run has. The step owns no
! physics object: it points at those main made and calls them in order, each phase in its
! PetscLogStage. Output, statistics' bookkeeping and the run's schedule stay with the caller.
! What can go wrong in a step is found here and described in time_step_t%failure, for the caller to
! stop with (the state as it was, written as failed_state.h5): a contact overlap far beyond the
! roughness or a lubrication block LAPACK cannot decompose end the step early (time_step_advance);
! a non-finite velocity, pressure or particle quantity, or a sphere half way through a wall, is
! found by the runtime guard after it (time_step_guard). The step also keeps the run's account of
! itself: solver iterations, the largest contact overlap (warned past h_r/2), and time_step_report
! logs it at the end.
#include <petsc/finclude/petscvec.h>
module mod_time_step
  use petscvec
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_finite
  use mod_kinds, only: dp
  use mod_errors, only: log_line, report_limits
  use mod_contact, only: overlap_limit, wall_lower, wall_upper
  use mod_grid, only: grid_t
  use mod_fluid, only: fluid_t, fluid_step, fluid_mean_profile, fluid_add_response, fluid_set_sliding
  use mod_timers, only: stage_push, stage_pop, STAGE_FLUID, STAGE_PARTICLES, STAGE_CONTACTS, STAGE_LUBRICATION
  use mod_particles, only: particles_t, sphere_share_t, advance_positions, displacements, MOTION_FREE, MOTION_FROZEN
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_step
  use mod_particle_lubrication, only: particle_lubrication_t
  use mod_rheology, only: rheology_t, rheo_sample, rheo_sample_flow, rheo_reach, rheo_skin
  use mod_lees_edwards, only: lees_edwards_t, le_wrap, le_advance, le_set_strain
  use mod_shear_protocol, only: shear_protocol_t, shear_protocol_begin_step, shear_protocol_end_step, &
                                shear_protocol_varies, shear_protocol_set_rate, PROTOCOL_OSCILLATORY, CONTROL_STRESS
  use mod_lubrication_dynamics, only: lubrication_dynamics_t
  use mod_fictitious_domain, only: fictitious_domain_t, fictitious_domain_geometry, fictitious_domain_follow, &
                                   fictitious_domain_moments, fictitious_domain_solve_motion, fictitious_domain_update, &
                                   fictitious_domain_set_image_speed, fictitious_domain_response_moments, &
                                   fictitious_domain_solve_stress
  use mod_lubrication_links, only: lubrication_links_evaluate
  use mod_ld_motion, only: ld_motion_solve, ld_motion_solve_stress
  use mod_particle_solver, only: particle_solver_t
  use mod_sphere_halo, only: sphere_halo_t
  use mod_ld_local, only: ld_local_t, ld_local_create, ld_local_begin, ld_local_contacts_agree, ld_local_links, &
                          ld_local_statistics, ld_local_own_slot
  implicit none
  private
  public :: time_step_t, time_step_create, time_step_advance, time_step_guard, time_step_report, time_step_share

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
    ! what went wrong in the last step or the guard after it ('' when nothing did)
    character(len=400) :: failure = ''
    ! -fault_nan_step N: the guard poisons the state at step N (tests of the guard only; -1: never)
    integer :: fault_nan_step = -1
    ! the run's account: steps taken, the fluid solvers' iterations (u, v, w, p) summed over them,
    ! the largest contact overlap |delta'| [a] and its step
    integer :: steps_taken = 0
    integer :: iterations_sum(4) = 0
    real(dp) :: largest_overlap = 0.0_dp
    integer :: largest_overlap_step = 0
    type(grid_t), pointer :: grid => null()
    type(fluid_t), pointer :: fluid => null()
    type(fluid_t), pointer :: fluid_response => null()   ! stress control: the step per unit wall speed
    type(fictitious_domain_t), pointer :: fd => null()
    type(particles_t), pointer :: parts => null()
    type(particle_contacts_t), pointer :: contacts => null()
    type(particle_lubrication_t), pointer :: lubrication => null()
    type(rheology_t), pointer :: rheology => null()
    type(lees_edwards_t), pointer :: le => null()
    type(lubrication_dynamics_t), pointer :: ld => null()
    type(particle_solver_t), pointer :: ld_solver => null()
    type(shear_protocol_t), pointer :: protocol => null()   ! the imposed shear (&shear)
    real(dp), allocatable :: mean_flow(:)          ! x-z plane means of u per cell row (statistics)
    real(dp), allocatable :: position_before(:, :) ! X^n, then X^{n+1} - X^n
    ! spheres on more than one rank: each rank's own spheres and ghosts (mod_ld_local), the state
    ! between steps from the first step on, which the output takes (time_step_share); parts, the
    ! replicated state of the start, is then released (it keeps n, the radius, the motion, have_prev)
    type(ld_local_t) :: local
  end type time_step_t

contains

  ! The step of a run: fluid (grid, fluid), spheres (parts) with, when resolved, their fictitious
  ! domain fd, or, without a fluid, their lubrication dynamics (ld, ld_solver); contacts,
  ! lubrication and rheology where the run has them; le: the Lees-Edwards boundaries (offset 0
  ! when inactive); protocol: the imposed shear in time (mod_shear_protocol). walls: walls in y.
  ! Options: -fd_carry_lambda, -fault_nan_step, -ld_local_set. Collective (resolved: the geometry
  ! of X^n is built here).
  subroutine time_step_create(ts, dt, box, walls, le, protocol, ierr, grid, fluid, fd, parts, ld, ld_solver, &
                              contacts, lubrication, rheology, fluid_response)
    type(time_step_t), intent(out) :: ts
    real(dp), intent(in) :: dt, box(3)
    logical, intent(in) :: walls
    type(lees_edwards_t), target, intent(in) :: le
    type(shear_protocol_t), target, intent(in) :: protocol
    PetscErrorCode, intent(out) :: ierr
    type(grid_t), target, intent(in), optional :: grid
    type(fluid_t), target, intent(in), optional :: fluid
    type(fluid_t), target, intent(in), optional :: fluid_response
    type(fictitious_domain_t), target, intent(in), optional :: fd
    type(particles_t), target, intent(in), optional :: parts
    type(lubrication_dynamics_t), target, intent(in), optional :: ld
    type(particle_solver_t), target, intent(in), optional :: ld_solver
    type(particle_contacts_t), target, intent(in), optional :: contacts
    type(particle_lubrication_t), target, intent(in), optional :: lubrication
    type(rheology_t), target, intent(in), optional :: rheology
    PetscBool :: set, use_local
    PetscInt :: fault_step
    PetscMPIInt :: ranks
    real(dp) :: reach, skin, support
    real(dp), allocatable :: edges(:)
    integer :: q
    character(len=200) :: text
    ierr = 0
    ts%dt = dt
    ts%box = box
    ts%walls = walls
    PetscCall(PetscOptionsGetBool(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-fd_carry_lambda', ts%carry_lambda, set, ierr))
    fault_step = -1
    PetscCall(PetscOptionsGetInt(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-fault_nan_step', fault_step, set, ierr))
    ts%fault_nan_step = fault_step
    ts%le => le
    ts%protocol => protocol
    if (present(grid)) ts%grid => grid
    if (present(fluid)) ts%fluid => fluid
    if (present(fluid_response)) ts%fluid_response => fluid_response
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
    if (associated(ts%parts)) then
      ! the reach of the local set: the largest neighbour-list cut-off of the contacts and links
      ! and the smallest skin of those lists: the local sets are kept while no sphere has moved
      ! half of it (mod_ld_local)
      reach = 0.0_dp
      skin = huge(1.0_dp)
      if (associated(ts%contacts)) then
        reach = ts%contacts%nlist%cutoff
        skin = ts%contacts%nlist%skin
      end if
      if (associated(ts%lubrication)) then
        reach = max(reach, ts%lubrication%nlist%cutoff)
        skin = min(skin, ts%lubrication%nlist%skin)
      end if
      ! -ld_local_set 0, -fd_local_set 0: every rank evaluates the step for every sphere (the
      ! replicated state, as before 2026-11-29; for comparisons)
      use_local = PETSC_TRUE
      PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr))
      if (ts%variant == TIME_STEP_FLUID_FREE) then
        PetscCall(PetscOptionsGetBool(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-ld_local_set', use_local, set, ierr))
      else
        PetscCall(PetscOptionsGetBool(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-fd_local_set', use_local, set, ierr))
        ! the resolved step on local sets: the slabs are the grid's z-ranges (a grid split in z
        ! only), a sphere is a ghost of every rank whose faces it may visit before the sets are
        ! made again: its inflated radius and a cell and a half (as the Lees-Edwards entries), plus
        ! half the skin, plus one cell, the most a sphere moves in the step between the check of
        ! the sets (ld_local_begin) and the geometry at the step's end (fictitious_domain_follow);
        ! the motion is solved (free or frozen), the rate imposed or set by the stress
        use_local = use_local .and. size(ts%grid%rank_cells_z) == ranks &
                    .and. (ts%parts%motion == MOTION_FREE .or. ts%parts%motion == MOTION_FROZEN)
        if (skin == huge(1.0_dp)) skin = 0.5_dp * ts%parts%radius
        support = maxval(ts%parts%radii) + ts%fd%radius_offset * ts%grid%h + 1.5_dp * ts%grid%h
        reach = max(reach, support + 0.5_dp * skin + ts%grid%h)
        if (use_local) then
          allocate(edges(0:ranks))
          edges(0) = 0.0_dp
          do q = 1, ranks
            edges(q) = edges(q - 1) + ts%grid%rank_cells_z(q) * ts%grid%h
          end do
          edges(ranks) = box(3)
        end if
      end if
      ! (the statistics' shells too, which the local step samples: ghosts within their reach)
      if (associated(ts%rheology) .and. reach > 0.0_dp) then
        reach = max(reach, rheo_reach(ts%rheology))
        skin = min(skin, rheo_skin(ts%rheology))
      end if
      ! (one sphere: nothing to share out; its kernels keep their one-sphere set-up)
      if (.not. use_local .or. ts%parts%n < 2) reach = 0.0_dp
      if (allocated(edges)) then
        call ld_local_create(ts%local, box(3), reach, skin, edges)
      else
        call ld_local_create(ts%local, box(3), reach, skin)
      end if
      if (ts%local%active) then
        write(text, '(a,f7.3,a)') 'spheres on the ranks'' local sets: each rank steps the spheres of '// &
             'its z-slab and their ghosts within ', reach, ' a (free or frozen spheres)'
        call log_line(text)
      end if
    end if
    if (ts%variant == TIME_STEP_RESOLVED .and. .not. ts%local%active) then
      ! the geometry at X^n; each step then moves it, and Lambda with it, to X^{n+1} (on local sets
      ! the first step makes it, on its rank's spheres: local_step)
      PetscCall(stage_push(STAGE_PARTICLES, ierr))
      call fictitious_domain_geometry(ts%grid, ts%fd, ts%parts, ts%le)
      PetscCall(stage_pop(ierr))
    end if
  end subroutine time_step_create

  ! One step: X^n, u^n to X^{n+1}, u^{n+1} (doc/METHOD.md §7), n = step. The core statistics
  ! sample the configuration X^n with its velocities before it moves on. A failure ends it early,
  ! described in ts%failure. Collective.
  subroutine time_step_advance(ts, step, ierr)
    type(time_step_t), target, intent(inout) :: ts
    integer, intent(in) :: step
    PetscErrorCode, intent(out) :: ierr
    integer :: info
    real(dp) :: rate, reached
    logical :: stress_control, local
    type(particles_t), pointer :: spheres
    type(sphere_halo_t), pointer :: halo
    ierr = 0
    ts%failure = ''
    ! the imposed rate of this step, gamma_dot(t_n), in every piece that uses it (stress control:
    ! the last step's, until the particle solve has found this step's; doc/METHOD.md §7.4)
    call shear_protocol_begin_step(ts%protocol)
    if (shear_protocol_varies(ts%protocol)) call impose_rate(ts)
    stress_control = ts%protocol%control == CONTROL_STRESS
    if (associated(ts%fluid) .and. ts%le%active) call slide_fluid(ts)
    if (ts%variant == TIME_STEP_FLUID) then
      PetscCall(stage_push(STAGE_FLUID, ierr))
      PetscCall(fluid_step(ts%grid, ts%fluid, ierr))
      if (stress_control) then
        ! the walls' speed that sets the mean wall stress to the target: the step plus the
        ! multiple of its unit response that makes up the difference (doc/METHOD.md §7.4)
        associate(fl => ts%fluid, unit => ts%fluid_response)
          PetscCall(fluid_add_response(ts%grid, fl, unit, (ts%protocol%stress - 0.5_dp * (fl%tau_bottom + fl%tau_top)) / (0.5_dp * (unit%tau_bottom + unit%tau_top)), ierr))
          rate = 2.0_dp * fl%wall_speed / ts%box(2)
          call shear_protocol_set_rate(ts%protocol, rate, 0.5_dp * (fl%tau_bottom + fl%tau_top), rate)
        end associate
      end if
      PetscCall(stage_pop(ierr))
      call shear_protocol_end_step(ts%protocol)
      if (ts%le%active) call slide(ts%le, ts%protocol, ts%dt)
      call count_step(ts, step)
      return
    end if
    associate(parts => ts%parts, le => ts%le)
      ! a reversal (or a change of level of 'steps') is a jump of the rate: the Adams-Bashforth
      ! extrapolation across it would carry the old rate on, so the step after it starts afresh
      ! (Euler, as the first step does), and so does the implicit contacts' prediction of the
      ! motion (particle_contacts_add_stiffness), set from the same flag
      if (ts%protocol%reversed) parts%have_prev = .false.
      local = ts%local%active .and. (parts%motion == MOTION_FREE .or. parts%motion == MOTION_FROZEN)
      if (local) then
        ! the spheres on the ranks' local sets (mod_ld_local)
        PetscCall(local_step(ts, ierr))
        if (len_trim(ts%failure) > 0) return
      else
        if (associated(ts%contacts)) then
          ! contacts at X^n with the latest velocities (those of the previous step)
          PetscCall(stage_push(STAGE_CONTACTS, ierr))
          call particle_contacts_step(ts%contacts, parts%position, parts%velocity, parts%omega, info, le%offset)
          PetscCall(stage_pop(ierr))
          if (info /= 0) then
            ts%failure = contact_failure(ts%contacts, info)
            return
          end if
        end if
        if (associated(ts%lubrication)) then
          ! the lubrication links at X^n, taken implicitly in the particle problem below (stress
          ! control: their drives per unit rate, which the particle solve scales)
          if (stress_control) then
            ts%lubrication%shear_rate = 1.0_dp
            ts%lubrication%le%shear_rate = 1.0_dp
          end if
          PetscCall(stage_push(STAGE_LUBRICATION, ierr))
          PetscCall(lubrication_links_evaluate(ts%lubrication, parts%position, ierr, le%offset))
          PetscCall(stage_pop(ierr))
          if (ts%lubrication%failed_link(1) /= 0) then
            ts%failure = lubrication_failure(ts%lubrication%failed_link)
            return
          end if
        end if
        ! (a disassociated pointer passed to an optional argument is absent: contacts, lubrication)
        if (ts%variant == TIME_STEP_RESOLVED) then
          PetscCall(resolved_particles(ts, ierr))
        else
          PetscCall(stage_push(STAGE_PARTICLES, ierr))
          ! lubrication dynamics: the 6N Stokes balance of the spheres alone (one-body drag in the
          ! imposed flow, the pair and wall links, the contacts), then their hydrodynamic force,
          ! torque and stresslet (doc/METHOD.md §6); under stress control with the rate that sets the
          ! mean shear stress, which every piece then takes (§7.4)
          if (stress_control) then
            rate = ts%protocol%rate
            PetscCall(ld_motion_solve_stress(ts%ld, ts%ld_solver, parts, ts%protocol%stress, rate, reached, ierr, rheology=ts%rheology, lubrication=ts%lubrication, contacts=ts%contacts))
            call take_stress_rate(ts, rate, reached)
          else
            PetscCall(ld_motion_solve(ts%ld, ts%ld_solver, parts, ierr, lubrication=ts%lubrication, contacts=ts%contacts))
          end if
        end if
      end if
      ! the core statistics of this configuration, before it moves on (the local step sampled it)
      if (associated(ts%rheology) .and. .not. local) then
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
      ! the spheres advance: every sphere, or each rank's local set, which is the state
      call stepped_spheres(ts, spheres, halo)
      if (ts%variant == TIME_STEP_RESOLVED) ts%position_before = spheres%position
      call advance_positions(spheres, ts%dt, ts%box, [.true., .not. (ts%walls .or. le%active), .true.])
      parts%have_prev = spheres%have_prev
      call shear_protocol_end_step(ts%protocol)
      if (le%active) then
        ! the boundary slides on; spheres that left through y = 0 or Ly re-enter from the image
        call slide(le, ts%protocol, ts%dt)
        call le_wrap(le, spheres%position, spheres%velocity, spheres%velocity_prev)
      end if
      if (ts%variant == TIME_STEP_RESOLVED) then
        ! the geometry at X^{n+1} (of a local set: each sphere's parts summed on its owner)
        if (ts%carry_lambda) then
          ! (with Lees-Edwards the carry finds the displacement of each sphere and image itself)
          ts%position_before = displacements(spheres%position, ts%position_before, ts%box, [.true., .not. ts%walls, .true.])
          PetscCall(fictitious_domain_follow(ts%grid, ts%fd, spheres, ts%position_before, ierr, le, halo))
        else
          call fictitious_domain_geometry(ts%grid, ts%fd, spheres, le, halo)
        end if
      end if
      PetscCall(stage_pop(ierr))
    end associate
    call count_step(ts, step)
  end subroutine time_step_advance

  ! The particle part of a lubrication-dynamics step on the ranks' local sets (mod_ld_local): the
  ! local set of X^n (kept or carried on from the last step's, or taken from ts%parts on the
  ! first), its contacts and links, the 6N solve of the own spheres' rows, the statistics' sample
  ! (time_step_advance then advances the local set, which the output takes: time_step_share). A
  ! failure (an overlap, a link) is described in
  ! ts%failure, the local set left at X^n (every stage popped); otherwise the Particles stage is
  ! left pushed for the step's end. Collective.
  subroutine local_step(ts, ierr)
    type(time_step_t), intent(inout) :: ts
    PetscErrorCode, intent(out) :: ierr
    integer :: info
    real(dp) :: rate, reached
    ierr = 0
    associate(loc => ts%local, set => ts%local%set, le => ts%le)
      PetscCall(stage_push(STAGE_PARTICLES, ierr))
      if (ts%variant == TIME_STEP_RESOLVED) then
        PetscCall(ld_local_begin(loc, ts%parts, ts%fd%solver, ierr, contacts=ts%contacts, lubrication=ts%lubrication, rheology=ts%rheology))
        ! sets made anew (the first step, or spheres moved half the skin): the geometry of X^n
        ! again on them, for their indices (the same faces: Lambda^n stays where it was carried)
        if (loc%made) call regeometry(ts)
      else
        PetscCall(ld_local_begin(loc, ts%parts, ts%ld_solver, ierr, ld=ts%ld, contacts=ts%contacts, lubrication=ts%lubrication, rheology=ts%rheology))
      end if
      PetscCall(stage_pop(ierr))
      if (associated(ts%contacts)) then
        PetscCall(stage_push(STAGE_CONTACTS, ierr))
        call particle_contacts_step(ts%contacts, set%position, set%velocity, set%omega, info, le%offset)
        PetscCall(ld_local_contacts_agree(ts%contacts, info, ierr))
        PetscCall(stage_pop(ierr))
        if (info /= 0) then
          ts%failure = contact_failure(ts%contacts, info)
          return
        end if
      end if
      if (associated(ts%lubrication)) then
        ! (stress control: the links' drives per unit rate, which the particle solve scales)
        if (ts%protocol%control == CONTROL_STRESS) then
          ts%lubrication%shear_rate = 1.0_dp
          ts%lubrication%le%shear_rate = 1.0_dp
        end if
        PetscCall(stage_push(STAGE_LUBRICATION, ierr))
        PetscCall(ld_local_links(loc, ts%lubrication, ierr, le%offset))
        PetscCall(stage_pop(ierr))
        if (ts%lubrication%failed_link(1) /= 0) then
          ts%failure = lubrication_failure(ts%lubrication%failed_link)
          return
        end if
      end if
      ! (the stage stays pushed for the rest of the step, as in time_step_advance)
      if (ts%variant == TIME_STEP_RESOLVED) then
        ! the own spheres' moments summed on them, their rows solved, their velocities forwarded
        PetscCall(resolved_particles(ts, ierr))
      else
        PetscCall(stage_push(STAGE_PARTICLES, ierr))
        if (ts%protocol%control == CONTROL_STRESS) then
          ! the rate that sets the mean shear stress (doc/METHOD.md §7.4), as time_step_advance
          rate = ts%protocol%rate
          PetscCall(ld_motion_solve_stress(ts%ld, ts%ld_solver, set, ts%protocol%stress, rate, reached, ierr, rheology=ts%rheology, lubrication=ts%lubrication, contacts=ts%contacts, local=loc))
          call take_stress_rate(ts, rate, reached)
        else
          PetscCall(ld_motion_solve(ts%ld, ts%ld_solver, set, ierr, lubrication=ts%lubrication, contacts=ts%contacts, local=loc))
        end if
      end if
      ! the core statistics of this configuration, before it moves on: the own spheres' shares (and
      ! the resolved flow's profile)
      if (associated(ts%rheology)) then
        if (associated(ts%contacts)) then
          PetscCall(ld_local_statistics(loc, ts%rheology, ierr, ts%contacts%stresslet, le%offset))
        else
          PetscCall(ld_local_statistics(loc, ts%rheology, ierr, offset=le%offset))
        end if
        if (ts%variant == TIME_STEP_RESOLVED) then
          PetscCall(fluid_mean_profile(ts%grid, ts%fluid, ts%mean_flow, ierr))
          call rheo_sample_flow(ts%rheology, ts%mean_flow, ts%grid%h)
        end if
      end if
      ! the links' wall forces of the own spheres summed over the ranks (a series column)
      if (associated(ts%lubrication)) then
        PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, ts%lubrication%wall_force, 6, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr))
      end if
    end associate
  end subroutine local_step

  ! The spheres the step takes: every sphere (halo disassociated, an absent argument), or, once the
  ! ranks' local sets hold the state, this rank's set and its halo. Points into ts.
  subroutine stepped_spheres(ts, spheres, halo)
    type(time_step_t), target, intent(inout) :: ts
    type(particles_t), pointer, intent(out) :: spheres
    type(sphere_halo_t), pointer, intent(out) :: halo
    spheres => ts%parts
    halo => null()
    if (ts%local%live) then
      spheres => ts%local%set
      halo => ts%local%halo
    end if
  end subroutine stepped_spheres

  ! The resolved step after the spheres' contacts and links (doc/METHOD.md §3.2 eq. (1)): the fluid
  ! with Lambda^n (stress control: at the last step's wall speed, impose_rate), the moments of u~
  ! and Lambda^n, the 6N system for U, Omega (or the rate that sets the stress and U at it), then
  ! Lambda^{n+1}, u^{n+1} and the hydrodynamic force, torque and stresslet; on a local set each
  ! sphere's moments and sums on its owner (stepped_spheres). The Particles stage is left pushed
  ! for the rest of the step. Collective.
  subroutine resolved_particles(ts, ierr)
    type(time_step_t), target, intent(inout) :: ts
    PetscErrorCode, intent(out) :: ierr
    type(particles_t), pointer :: spheres
    type(sphere_halo_t), pointer :: halo
    call stepped_spheres(ts, spheres, halo)
    PetscCall(stage_push(STAGE_FLUID, ierr))
    PetscCall(fluid_step(ts%grid, ts%fluid, ierr, ts%fd%lambda))
    PetscCall(stage_pop(ierr))
    PetscCall(stage_push(STAGE_PARTICLES, ierr))
    if (ts%le%active) call fictitious_domain_set_image_speed(ts%fd, ts%protocol%rate * ts%box(2))
    PetscCall(fictitious_domain_moments(ts%grid, ts%fd, ts%fluid%vel, spheres%n, ierr, halo))
    if (ts%protocol%control == CONTROL_STRESS) then
      PetscCall(resolved_stress_control(ts, ierr))
    else
      PetscCall(fictitious_domain_solve_motion(ts%fd, spheres, ierr, lubrication=ts%lubrication, contacts=ts%contacts, halo=halo))
    end if
    PetscCall(fictitious_domain_update(ts%grid, ts%fd, ts%fluid%vel, ts%fluid%pressure, spheres, ierr, ts%lubrication, halo))
  end subroutine resolved_particles

  ! The geometry of X^n on the local set just made (the same faces as the last geometry's, which the
  ! old set's ghosts covered: Lambda^n, carried onto them, stays listed). Collective.
  subroutine regeometry(ts)
    type(time_step_t), intent(inout) :: ts
    logical :: listed
    listed = ts%fd%lambda_listed
    call fictitious_domain_geometry(ts%grid, ts%fd, ts%local%set, ts%le, ts%local%halo, set_made=.true.)
    ts%fd%lambda_listed = listed
  end subroutine regeometry

  ! The rate a stress-controlled lubrication-dynamics step solved for (rate, giving the stress
  ! reached) to the protocol and every piece: the strain and the offset advance with the spheres'
  ! Adams-Bashforth step (doc/METHOD.md §7.4), forward Euler on a first step.
  subroutine take_stress_rate(ts, rate, reached)
    type(time_step_t), intent(inout) :: ts
    real(dp), intent(in) :: rate, reached
    if (ts%parts%have_prev) then
      call shear_protocol_set_rate(ts%protocol, rate, reached, 1.5_dp * rate - 0.5_dp * ts%protocol%rate)
    else
      call shear_protocol_set_rate(ts%protocol, rate, reached, rate)
    end if
    call impose_rate(ts)
  end subroutine take_stress_rate

  ! This rank's share of the spheres when the state of the run is the ranks' local sets (shared):
  ! the output then takes the share, and the contacts and the links as they are, set for it.
  ! share%set points into ts (a target).
  subroutine time_step_share(ts, share, shared)
    type(time_step_t), target, intent(in) :: ts
    type(sphere_share_t), intent(out) :: share
    logical, intent(out) :: shared
    shared = ts%local%live
    if (.not. shared) return
    share%set => ts%local%set
    share%id = ts%local%halo%id
    share%own = ts%local%halo%is_owned
    share%total = ts%local%total
  end subroutine time_step_share

  ! Stress control of the DNS with spheres between walls (doc/METHOD.md §7.4): after the fluid step
  ! at the last step's wall speed and its moments, the rate gamma_dot^n whose mean wall shear stress
  ! is the target (fictitious_domain_solve_stress: the coupled step is affine in the rate, and the
  ! fluid step's part of it is the run's unit wall-speed response, ts%fluid_response), then the
  ! fluid step made that of gamma_dot^n by adding the multiple of the response (u~, p, phi, u*,
  ! the wall speed and stresses), every piece given gamma_dot^n, and the protocol told the rate,
  ! the stress reached and the walls' strain rate (the walls move at gamma_dot^n over the step).
  ! The update that follows (Lambda^{n+1}, u^{n+1}) is affine in u~ and U and is made once, with
  ! both at gamma_dot^n. Collective.
  ! On the ranks' local sets (ts%local live) the spheres are a rank's own and ghosts, their sums
  ! made on their owners (halo).
  subroutine resolved_stress_control(ts, ierr)
    type(time_step_t), target, intent(inout) :: ts
    PetscErrorCode, intent(out) :: ierr
    real(dp) :: rate, rate_before, per_rate, walls_share, fluid_stress, fluid_slope
    type(particles_t), pointer :: spheres
    type(sphere_halo_t), pointer :: halo
    call stepped_spheres(ts, spheres, halo)
    associate(fl => ts%fluid, unit => ts%fluid_response)
      PetscCall(fictitious_domain_response_moments(ts%grid, ts%fd, unit%vel, spheres%n, ierr, halo))
      rate_before = ts%protocol%rate
      rate = rate_before
      if (ts%le%active) then
        ! Lees-Edwards (doc/METHOD.md §7.4): the mean shear stress of the box, eta gamma_dot plus
        ! the spheres' stresslets over its volume; the unit response is per unit rate
        per_rate = 1.0_dp
        PetscCall(fictitious_domain_solve_stress(ts%fd, spheres, ts%protocol%stress, rate_before, 1.0_dp, per_rate, 0.0_dp, rate, walls_share, ierr, lubrication=ts%lubrication, contacts=ts%contacts, grid=ts%grid, vel=fl%vel, response_vel=unit%vel, volume=product(ts%box), halo=halo))
        ! the images and the boundary's jump at the rate found; the offset after the step stays the
        ! one the fluid's step took (the strain advances at the last step's rate, slide_fluid)
        call fictitious_domain_set_image_speed(ts%fd, rate * ts%box(2))
        call fluid_set_sliding(fl, fl%sliding_offset(1), fl%sliding_offset(2), rate * ts%box(2), rate * ts%box(2))
        PetscCall(stage_push(STAGE_FLUID, ierr))
        PetscCall(fluid_add_response(ts%grid, fl, unit, rate - rate_before, ierr))
        PetscCall(stage_pop(ierr))
        call shear_protocol_set_rate(ts%protocol, rate, rate + walls_share, rate_before)
      else
        ! the wall speed per unit rate, Ly/2
        per_rate = 0.5_dp * ts%box(2)
        fluid_stress = 0.5_dp * (fl%tau_bottom + fl%tau_top)
        fluid_slope = per_rate * 0.5_dp * (unit%tau_bottom + unit%tau_top)
        PetscCall(fictitious_domain_solve_stress(ts%fd, spheres, ts%protocol%stress, fluid_stress, fluid_slope, per_rate, ts%box(1) * ts%box(3), rate, walls_share, ierr, lubrication=ts%lubrication, contacts=ts%contacts, halo=halo))
        PetscCall(stage_push(STAGE_FLUID, ierr))
        PetscCall(fluid_add_response(ts%grid, fl, unit, (rate - rate_before) * per_rate, ierr))
        PetscCall(stage_pop(ierr))
        ! the stress reached: the fluid's wall stress of the step as it now is, and the walls' share
        call shear_protocol_set_rate(ts%protocol, rate, 0.5_dp * (fl%tau_bottom + fl%tau_top) + walls_share, rate)
      end if
    end associate
    call impose_rate(ts)
  end subroutine resolved_stress_control

  ! The rate of the step, gamma_dot(t_n) = ts%protocol%rate, given to every piece that uses the
  ! imposed shear (doc/RHEOLOGY.md "Protocols"): the walls of the fluid, of the lubrication and of
  ! the contacts (-+ gamma_dot Ly/2), the undisturbed flow of lubrication dynamics and of the
  ! lubrication links, the velocity of the Lees-Edwards images (the boundaries' own copy and those
  ! of the contacts and the lubrication). Only for a rate that varies: a steady run keeps the
  ! values its pieces were made with.
  subroutine impose_rate(ts)
    type(time_step_t), intent(inout) :: ts
    real(dp) :: rate
    rate = ts%protocol%rate
    if (associated(ts%fluid) .and. ts%walls) ts%fluid%wall_speed = 0.5_dp * rate * ts%box(2)
    if (associated(ts%ld)) ts%ld%shear_rate = rate
    if (associated(ts%lubrication)) then
      ts%lubrication%shear_rate = rate
      ts%lubrication%le%shear_rate = rate
    end if
    if (associated(ts%contacts)) then
      if (ts%walls) then
        ts%contacts%wall_velocity(1, 1) = -0.5_dp * rate * ts%box(2)
        ts%contacts%wall_velocity(1, 2) = 0.5_dp * rate * ts%box(2)
      end if
      ts%contacts%le%shear_rate = rate
    end if
    ts%le%shear_rate = rate
  end subroutine impose_rate

  ! The Lees-Edwards boundary after the step (protocol: at its end), by the strain of the step
  ! exactly: an oscillation's offset is gamma(t_{n+1}) Ly, stress control's the strain its spheres
  ! advanced (doc/METHOD.md §7.4), otherwise the rate times dt.
  pure subroutine slide(le, protocol, dt)
    type(lees_edwards_t), intent(inout) :: le
    type(shear_protocol_t), intent(in) :: protocol
    real(dp), intent(in) :: dt
    if (protocol%kind == PROTOCOL_OSCILLATORY .or. protocol%control == CONTROL_STRESS) then
      call le_set_strain(le, protocol%strain)
    else
      call le_advance(le, dt)
    end if
  end subroutine slide

  ! The resolved fluid's Lees-Edwards boundary for the step to come (doc/METHOD.md §2.4): the
  ! offset now and after the step (the same rule as slide, on copies), and the images' velocity
  ! gamma_dot Ly at the step's rate.
  subroutine slide_fluid(ts)
    type(time_step_t), intent(inout) :: ts
    type(lees_edwards_t) :: after
    type(shear_protocol_t) :: protocol_after
    real(dp) :: jump
    after = ts%le
    protocol_after = ts%protocol
    ! under stress control the boundary slides at the last step's rate, the one the step starts
    ! with (resolved_stress_control keeps it as the strain's advance)
    if (protocol_after%control == CONTROL_STRESS) protocol_after%advance = protocol_after%rate
    call shear_protocol_end_step(protocol_after)
    call slide(after, protocol_after, ts%dt)
    jump = ts%protocol%rate * ts%box(2)
    call fluid_set_sliding(ts%fluid, ts%le%offset, after%offset, jump, jump)
  end subroutine slide_fluid

  ! The account of a step taken: the fluid solvers' iterations, and a new largest contact overlap
  ! of the run, warned once past h_r/2 (mod_contact::overlap_limit).
  subroutine count_step(ts, step)
    type(time_step_t), intent(inout) :: ts
    integer, intent(in) :: step
    integer :: c
    ts%steps_taken = ts%steps_taken + 1
    if (associated(ts%fluid)) then
      do c = 1, 4
        ts%iterations_sum(c) = ts%iterations_sum(c) + ts%fluid%solver(c)%iterations
      end do
    end if
    if (associated(ts%contacts)) then
      if (ts%contacts%max_overlap > ts%largest_overlap) then
        call report_limits('', overlap_limit(ts%contacts%params, ts%largest_overlap, ts%contacts%max_overlap, step))
        ts%largest_overlap = ts%contacts%max_overlap
        ts%largest_overlap_step = step
      end if
    end if
  end subroutine count_step

  ! What a contact failure of particle_contacts_step (its info) means for the run.
  function contact_failure(pc, info) result(what)
    type(particle_contacts_t), intent(in) :: pc
    integer, intent(in) :: info
    character(len=400) :: what
    character(len=40) :: partner
    integer :: pair(2)
    what = 'the contact history does not belong to this particle set'
    if (info /= 2) return
    pair = pc%stats%max_overlap_pair
    select case (pair(2))
    case (wall_lower)
      partner = 'the lower wall'
    case (wall_upper)
      partner = 'the upper wall'
    case default
      write(partner, '(a,i0)') 'particle ', pair(2)
    end select
    write(what, '(a,es10.3,a,i0,a,a,es10.3,a)') 'a contact overlap |delta''| = ', pc%max_overlap, &
         ' a between particle ', pair(1), ' and '//trim(partner), ' exceeds ', pc%overlap_limit, &
         ' a (far beyond the roughness): lower &time dt or raise &contact normal_stiffness'
  end function contact_failure

  ! A lubrication block LAPACK could not decompose (link: the particle and its partner, 0 for a
  ! wall): non-finite positions or resistance.
  function lubrication_failure(link) result(what)
    integer, intent(in) :: link(2)
    character(len=400) :: what
    if (link(2) == 0) then
      write(what, '(a,i0,a)') 'the lubrication block of particle ', link(1), ' and a wall could not be '// &
           'decomposed (LAPACK dsyev failed: non-finite position or resistance)'
    else
      write(what, '(a,i0,a,i0,a)') 'the lubrication block of particles ', link(1), ' and ', link(2), &
           ' could not be decomposed (LAPACK dsyev failed: non-finite positions or resistance)'
    end if
  end function lubrication_failure

  ! The runtime guard after step (doc/DESIGN.md "Files, restart and signals"): a non-finite
  ! velocity, pressure or particle quantity, or a sphere half way through a wall, is described in
  ! ts%failure. The norms are global reductions and the spheres are either replicated or looked at
  ! by their owners (the local set: the first failing sphere found by one reduction, described by
  ! its owner, whose text every rank receives), so every rank finds the same. At step
  ! -fault_nan_step the state is poisoned first (the guard's own test).
  subroutine time_step_guard(ts, step, ierr)
    type(time_step_t), intent(inout) :: ts
    integer, intent(in) :: step
    PetscErrorCode, intent(out) :: ierr
    PetscReal :: norms(4)
    integer :: c, q, first, teller
    ierr = 0
    ts%failure = ''
    if (step == ts%fault_nan_step) then
      if (associated(ts%fluid)) then
        PetscCall(VecScale(ts%fluid%vel(1), ieee_value(1.0_dp, ieee_quiet_nan), ierr))
      else if (ts%local%live) then
        q = ld_local_own_slot(ts%local, 1)
        if (q > 0) ts%local%set%velocity(1, q) = ieee_value(1.0_dp, ieee_quiet_nan)
      else
        ts%parts%velocity(1, 1) = ieee_value(1.0_dp, ieee_quiet_nan)
      end if
    end if
    norms = 0.0_dp
    if (associated(ts%fluid)) then
      do c = 1, 3
        PetscCall(VecNorm(ts%fluid%vel(c), NORM_INFINITY, norms(c), ierr))
      end do
      PetscCall(VecNorm(ts%fluid%pressure, NORM_INFINITY, norms(4), ierr))
    end if
    do c = 1, 4
      if (.not. ieee_is_finite(norms(c))) then
        write(ts%failure, '(a,a,a,es10.3)') 'the fluid ', trim(merge('velocity', 'pressure', c <= 3)), &
             ' is not finite: max norm ', norms(c)
        return
      end if
    end do
    if (.not. associated(ts%parts)) return
    if (ts%local%live) then
      ! the own spheres of the local set; the smallest failing global index of all ranks, described
      ! by its owner
      first = huge(1)
      associate(set => ts%local%set, h => ts%local%halo)
        do q = 1, set%n
          if (.not. h%is_owned(q)) cycle
          if (sphere_fault(ts, set, q)) then
            first = h%id(q)
            exit
          end if
        end do
        PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, first, 1, MPI_INTEGER, MPI_MIN, PETSC_COMM_WORLD, ierr))
        if (first == huge(1)) return
        q = ld_local_own_slot(ts%local, first)
        teller = -1
        if (q > 0) then
          teller = h%rank
          ts%failure = sphere_failure(ts, set, q, first)
        end if
      end associate
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, teller, 1, MPI_INTEGER, MPI_MAX, PETSC_COMM_WORLD, ierr))
      PetscCallMPI(MPI_Bcast(ts%failure, len(ts%failure), MPI_CHARACTER, teller, PETSC_COMM_WORLD, ierr))
      return
    end if
    do q = 1, ts%parts%n
      if (.not. sphere_fault(ts, ts%parts, q)) cycle
      ts%failure = sphere_failure(ts, ts%parts, q, q)
      return
    end do
  end subroutine time_step_guard

  ! What is wrong with sphere q of p, of global index g, which fails the runtime guard (sphere_fault).
  function sphere_failure(ts, p, q, g) result(text)
    type(time_step_t), intent(in) :: ts
    type(particles_t), intent(in) :: p
    integer, intent(in) :: q, g
    character(len=400) :: text
    if (.not. sphere_finite(p, q)) then
      write(text, '(a,i0,a,3es10.3,a,3es10.3)') 'particle ', g, ' is not finite: velocity ', p%velocity(:, q), &
           ' omega ', p%omega(:, q)
    else
      write(text, '(a,i0,a,f10.5,a,f10.5,a)') 'particle ', g, ' is half way through a wall (centre y = ', &
           p%position(2, q), ', walls at 0 and ', ts%box(2), '): add &contact, keep &lubrication on, or lower &time dt'
    end if
  end function sphere_failure

  ! Whether sphere q of p fails the runtime guard: a non-finite velocity, omega or position, or
  ! half way through a wall (nothing physical holds it back any more: no wall contacts or
  ! lubrication, or a step far too large for them).
  pure logical function sphere_fault(ts, p, q)
    type(time_step_t), intent(in) :: ts
    type(particles_t), intent(in) :: p
    integer, intent(in) :: q
    sphere_fault = .not. sphere_finite(p, q)
    if (ts%walls .and. .not. sphere_fault) sphere_fault = p%position(2, q) < 0.5_dp * p%radii(q) .or. &
                                                        p%position(2, q) > ts%box(2) - 0.5_dp * p%radii(q)
  end function sphere_fault

  ! Whether sphere q of p has a finite velocity, omega and position.
  pure logical function sphere_finite(p, q)
    type(particles_t), intent(in) :: p
    integer, intent(in) :: q
    sphere_finite = all(ieee_is_finite(p%velocity(:, q))) .and. all(ieee_is_finite(p%omega(:, q))) &
                    .and. all(ieee_is_finite(p%position(:, q)))
  end function sphere_finite

  ! The run's account of its steps, in the run log: wall time per step (seconds_per_step) and the
  ! fluid solvers' mean iterations, the largest contact overlap, the particle solves.
  subroutine time_step_report(ts, seconds_per_step)
    type(time_step_t), intent(in) :: ts
    real(dp), intent(in) :: seconds_per_step
    character(len=300) :: text
    integer :: solves, most, mpierr
    real(dp) :: seconds
    if (ts%steps_taken == 0) return
    if (associated(ts%fluid)) then
      write(text, '(a,i0,a,f10.5,a,4(f6.1))') 'steps run: ', ts%steps_taken, '  wall time per step:', &
           seconds_per_step, ' s  mean iterations u v w p:', real(ts%iterations_sum, dp) / ts%steps_taken
    else
      write(text, '(a,i0,a,f10.5,a)') 'steps run: ', ts%steps_taken, '  wall time per step:', seconds_per_step, ' s'
    end if
    call log_line(text)
    if (.not. associated(ts%parts)) return
    if (associated(ts%contacts)) then
      if (ts%contacts%params%h_r > 0) then
        ! the overlap bound of the extreme scenes (doc/VALIDATION.md §6): below h_r/2
        write(text, '(a,f8.4,a,i0,a)') 'contacts: largest overlap |delta''| over this run ', &
             ts%largest_overlap / ts%contacts%params%h_r, ' h_r (step ', ts%largest_overlap_step, ')'
        call log_line(text)
      end if
    end if
    if (ts%local%live) then
      ! the state between steps is the local sets; the replicated particles are gone
      most = ts%local%set%n
      call MPI_Allreduce(MPI_IN_PLACE, most, 1, MPI_INTEGER, MPI_MAX, PETSC_COMM_WORLD, mpierr)
      write(text, '(a,i0,a,f0.1,a,i0,a,i0,a)') 'spheres on the ranks'' local sets: the replicated particles of ', &
           ts%local%total, ' spheres (', real(ts%local%released, dp) / 1024.0_dp, &
           ' kB a rank) released at the first step; each rank holds its own spheres and their ghosts only (at the end '// &
           'at most ', most, ' of the ', ts%local%total, ' on a rank)'
      call log_line(text)
      write(text, '(a,i0,a,i0,a,f6.3,a)') 'spheres on the ranks'' local sets: the sets made ', &
           ts%local%sets_made, ' times in ', ts%steps_taken, ' steps (kept while no sphere has moved half the skin, ', &
           0.5_dp * ts%local%skin, ' a, along z)'
      call log_line(text)
    end if
    if (associated(ts%lubrication)) then
      ! each rank holds the pair links of its own spheres (mod_lubrication_links)
      write(text, '(a,i0,a,i0,a)') 'lubrication: ', ts%lubrication%npairs_total, &
           ' pair links in the last step, at most ', ts%lubrication%npairs_most, ' held on one rank'
      call log_line(text)
    end if
    if (ts%variant == TIME_STEP_RESOLVED) then
      solves = ts%fd%solver%solves
      seconds = ts%fd%solver%seconds
    else
      solves = ts%ld_solver%solves
      seconds = ts%ld_solver%seconds
    end if
    if (solves > 0) then
      write(text, '(a,i0,a,f10.3,a)') 'particle system with lubrication pairs: ', solves, &
           ' sparse solves, mean ', 1.0e3_dp * seconds / solves, ' ms (assembly + solve)'
      call log_line(text)
    end if
  end subroutine time_step_report

end module mod_time_step
