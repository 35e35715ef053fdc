! fdsusp: fictitious-domain simulation of sheared suspensions (doc/METHOD.md), or with &fluid model =
! 'none' their lubrication dynamics: the spheres alone, one-body Stokes drag plus exact pair and wall
! resistance and contacts, between walls or across Lees-Edwards boundaries (doc/METHOD.md §6).
!   bin/fdsusp DECK [-restart CHECKPOINT | -continue] [PETSc options]
! Reads and checks everything before any work, then steps the flow in time, writing the series,
! field snapshots and checkpoints the deck asks for. SIGTERM or SIGUSR1 (what batch schedulers
! send before the kill) ends the run at the end of the current step with a checkpoint, status 0.
program fdsusp
#include <petsc/finclude/petscvec.h>
  use petscvec
  use mod_kinds, only: dp, pi
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_finite
  use mod_params, only: config_t, read_deck, echo_deck, max_line
  use mod_errors, only: log_line, warn_line, input_error, fatal_error, is_root, abort_run
  use mod_file_services, only: write_failure_cause
  use mod_grid, only: grid_t, grid_create, grid_destroy, direct_solves_wanted
  use mod_fluid, only: fluid_t, fluid_create, fluid_destroy, fluid_columns
  use mod_fluid_verification, only: fluid_errors_vs_manufactured
  use mod_series, only: series_t, series_column, series_add, series_open, series_record, series_flush, series_close, &
                        series_attributes
  use mod_output, only: write_fields, progress_line
  use mod_checkpoint, only: checkpoint_state_t, checkpoint_write, checkpoint_check, checkpoint_read
  use mod_os_services, only: install_signal_handlers, stop_signal, make_directory, probe_directory, &
                             lock_directory, release_directory
  use mod_timers, only: timers_register, stage_push, stage_pop, STAGE_SETUP, STAGE_OUTPUT
  use mod_particles, only: particles_t, particles_columns, MOTION_FREE
  use mod_particles_io, only: particles_load, particles_snapshot
  use mod_initial_packing, only: initial_packing_make
  use mod_rheology, only: rheology_t, rheo_create, rheo_accumulate, rheo_summarise, rheo_columns, summary_names, NSUMMARY
  use mod_summary_io, only: summary_write
  use mod_fictitious_domain, only: fictitious_domain_t, fictitious_domain_create, fictitious_domain_destroy, &
                                   fictitious_domain_pair_lag_limit, fictitious_domain_stresslet_lag_limit
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_create, particle_contacts_columns
  use mod_contact, only: contact_limits, overlap_limit, wall_lower, wall_upper
  use mod_limits, only: limit_finding_t, LIMIT_REFUSE
  use mod_lubrication, only: lubrication_t, LUB_NONE, LUB_SIMPLE, LUB_EXACT
  use mod_lubrication_io, only: lubrication_load
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_create, particle_lubrication_columns
  use mod_h5util, only: h5util_init
  use mod_solvers, only: solver_t, solver_create, solver_cold_solve, solver_destroy, fft_planner_flags
  use mod_grid, only: FIELD_P
  use mod_lees_edwards, only: lees_edwards_t, le_create, le_columns
  use mod_lubrication_dynamics, only: lubrication_dynamics_t, lubrication_dynamics_create
  use mod_time_step, only: time_step_t, time_step_create, time_step_advance
  use mod_particle_solver, only: particle_solver_t, particle_solver_create, particle_solver_destroy
  implicit none

  PetscErrorCode :: ierr
  type(config_t) :: cfg
  type(grid_t), target :: grid
  type(fluid_t), target :: fl
  type(solver_t) :: yardstick                       ! -bench_cold_poisson's multigrid solve
  type(series_t) :: series
  type(particles_t), target :: parts
  type(fictitious_domain_t), target :: fd
  type(particle_contacts_t), target :: pc
  type(lubrication_t) :: lub
  type(particle_lubrication_t), allocatable, target :: pl   ! allocated when lubrication is on
  type(rheology_t), allocatable, target :: rh       ! allocated when the deck has &rheology
  type(lees_edwards_t), target :: le                ! y_boundary = 'lees-edwards' (le%active), its offset
  type(lubrication_dynamics_t), target :: ld        ! &fluid model = 'none': the spheres alone
  type(particle_solver_t), target :: ld_solver      ! its sparse 6N solve
  type(time_step_t) :: ts                           ! the step of this run (mod_time_step)
  type(checkpoint_state_t) :: state                 ! what the checkpoints hold: the pieces this run has
  real(dp) :: largest_overlap = 0.0_dp              ! of this run (since the start or restart) [a]
  integer :: largest_overlap_step = 0
  logical :: carry_lambda                           ! -fd_carry_lambda (default true)
  logical :: has_particles, has_contacts, has_lubrication
  integer :: info
  character(len=max_line) :: deck, restart, checkpoint_path
  character(len=400) :: text
  integer :: step, first_step, stop_reason, cold_its
  integer :: iterations_sum(4)
  real(dp) :: time, wall_start, wall_now, wall_per_step, wall_loop, cold_seconds, core_edge_speed, solid_fraction
  PetscBool :: bench_cold, fault_set
  PetscInt :: fault_nan_step
  real(dp) :: err_vel, err_p_max, err_p_rms
  logical :: restarting, continuing
  logical :: statistics_afresh                      ! a restart before its &rheology window begins
  integer, parameter :: RUNNING = 0, DONE = 1, SIGNALLED = 2, WALL_LIMIT = 3, STEADY = 4

  PetscCallA(PetscInitialize(ierr))
  ! SIGTERM/SIGUSR1 from now on only ask the run to stop after its next step (they replace
  ! PETSc's handlers, which would abort a run signalled during its set-up)
  call install_signal_handlers()
  wall_start = MPI_Wtime()
  call h5util_init()

  ! ---- everything is checked before any work ----
  call command_line(deck, restart, restarting, continuing)
  call read_deck(deck, cfg)
  call log_line('fdsusp: '//trim(cfg%run%title))
  call echo_deck(cfg)
  call prepare_output_directory(cfg)
  if (continuing) call continue_from_directory()
  if (cfg%particles%solid_fraction > 0.0_dp) then
    call initial_packing_make(cfg, parts)        ! a random packing made now
  else
    call particles_load(cfg, parts)              ! the deck's or the position file's
  end if
  has_particles = parts%n > 0
  ! lubrication dynamics moves spheres and nothing else: a file or packing that yields none leaves
  ! nothing to compute (the deck itself is checked in mod_params::validate_particles)
  if (.not. cfg%resolved .and. .not. has_particles) then
    if (len_trim(cfg%particles%position_file) > 0) then
      call input_error(cfg%deck_file, 'particles', 'position_file', '"'//trim(cfg%particles%position_file)// &
           '" holds no particles: &fluid model = ''none'' (lubrication dynamics) has nothing to compute')
    else
      call input_error(cfg%deck_file, 'particles', 'solid_fraction', 'packs no particles in this box: '// &
           '&fluid model = ''none'' (lubrication dynamics) has nothing to compute')
    end if
  end if
  ! sliding periodic boundaries in y (lubrication dynamics): the offset starts at 0, a restart
  ! reads it from the checkpoint
  if (cfg%lees_edwards) le = le_create(cfg%domain%box, cfg%domain%shear_rate, 0.0_dp)
  ! contacts: the deck has &contact and the run has particles (doc/CONTACT.md)
  has_contacts = has_particles .and. cfg%contact_group
  if (has_contacts) then
    call particle_contacts_create(pc, parts%n, parts%radius, cfg%contact, cfg%domain%shear_rate, cfg%domain%box, &
         cfg%walls, cfg%time%dt, info, text, le)
    if (info /= 0) call input_error(cfg%deck_file, 'contact', '', trim(text))
  end if
  ! lubrication: pairs or walls to lubricate (doc/LUBRICATION.md); the table is read and checked now
  call lubrication_load(cfg, has_particles .and. (parts%n >= 2 .or. cfg%walls), lub)
  has_lubrication = lub%model /= LUB_NONE
  if (has_lubrication) then
    allocate(pl)
    call particle_lubrication_create(pl, lub, parts%n, cfg%domain%box, cfg%walls, cfg%domain%shear_rate, cfg%lubrication%skin, info, text, le)
    if (info /= 0) call input_error(cfg%deck_file, 'lubrication', 'skin', trim(text))
  end if
  ! rough contacts: the limits of doc/CONTACT.md and doc/VALIDATION.md §6, before any work
  if (has_contacts .and. (has_lubrication .or. .not. cfg%resolved)) then
    solid_fraction = parts%n * (4.0_dp / 3.0_dp) * pi * parts%radius**3 / product(cfg%domain%box)
    call report(contact_limits(pc%params, cfg%time%dt, pc%implicit, cfg%walls .or. cfg%lees_edwards, solid_fraction, &
                               cfg%contact%eps_bar, cfg%contact%normal_stiffness > 0.0_dp))
  end if
  ! statistics of the core region (doc/RHEOLOGY.md)
  if (cfg%rheology_group) then
    allocate(rh)
    call rheo_create(rh, parts%n, cfg%domain%box, parts%radius, cfg%domain%shear_rate, cfg%rheology, cfg%discard_step, &
         cfg%block_steps, info, le)
    if (info /= 0) call input_error(cfg%deck_file, 'domain', 'box', &
         'with &rheology every periodic length must be >= 2 (pair_shell + 0.3) a')
    write(text, '(a,i0,a,i0,a,i0,a,i0)') 'statistics: discard ', cfg%discard_step, ' steps, then ', cfg%rheology%blocks, &
         ' blocks of ', cfg%block_steps, ' steps, ending at step ', cfg%discard_step + cfg%rheology%blocks * cfg%block_steps
    call log_line(text)
    ! spheres at the edge of the core must not outrun their Lambda (mod_fictitious_domain)
    core_edge_speed = abs(cfg%domain%shear_rate) * max(rh%core(2) - 0.5_dp * cfg%domain%box(2), 0.5_dp * cfg%domain%box(2) - rh%core(1))
    if (cfg%resolved) call report(fictitious_domain_stresslet_lag_limit(core_edge_speed, cfg%time%dt, cfg%h))
    if (cfg%time%steps < cfg%discard_step + cfg%rheology%blocks * cfg%block_steps) then
      write(text, '(a,i0,a)') '&time steps = ', cfg%time%steps, ' ends before the averaging window: the summary '// &
           'will hold the blocks complete by then (restart with more steps to finish)'
      call warn_line(text)
    end if
  end if
  checkpoint_path = trim(cfg%output%directory)//'/checkpoint.h5'
  step = 0
  time = 0.0_dp
  if (restarting) then
    call checkpoint_check(restart, cfg, parts%n, step, time, rh)   ! rh: absent unless allocated
    write(text, '(a,i0,a,es12.5)') 'restart from '//trim(restart)//' at step ', step, ', time ', time
    call log_line(text)
  end if

  ! ---- set-up ----
  PetscCallA(timers_register(ierr))
  PetscCallA(stage_push(STAGE_SETUP, ierr))
  if (cfg%resolved) then
    PetscCallA(grid_create(cfg, grid, ierr))
    PetscCallA(fluid_create(cfg, grid, fl, ierr))
    if (has_particles) then
      PetscCallA(fictitious_domain_create(grid, cfg%fluid%reynolds, cfg%time%dt, cfg%particles%slip_kappa, cfg%particles%radius_offset, fd, ierr))
    end if
  else
    ! lubrication dynamics: no grid, no fluid; the imposed shear comes from the walls or the
    ! sliding boundaries (mod_lubrication_dynamics)
    call lubrication_dynamics_create(ld, parts%radius, 1.0_dp, cfg%domain%shear_rate, cfg%domain%box, cfg%walls .or. cfg%lees_edwards)
    PetscCallA(particle_solver_create(ld_solver, ierr))
  end if
  ! the state the checkpoints hold and a restart restores: the pieces this run has
  if (cfg%resolved) state%fl => fl
  if (cfg%resolved .and. has_particles) state%lambda => fd%lambda
  if (has_particles) state%parts => parts
  if (has_contacts) state%history => pc%history
  if (allocated(rh)) state%rh => rh
  if (cfg%lees_edwards) state%offset => le%offset
  if (restarting) then
    PetscCallA(checkpoint_read(restart, state, statistics_afresh, ierr))
    if (statistics_afresh) call log_line('statistics: the &rheology window begins after the checkpoint''s step; '// &
         'they start from zero there (nothing the checkpoint accumulated is carried over)')
  end if
  ! the columns of series.h5, declared by the routine that also fills each record
  call series_columns()
  if (allocated(rh)) then
    ! what scripts/rheology.py needs to repeat the statistics from series.h5 alone
    call series_attributes(series, [character(len=32) :: 'box_x', 'box_y', 'box_z', 'radius', 'shear_rate', &
         'dt', 'core_lo', 'core_hi', 'pair_radius', 'contact_radius', 'blocks', 'discard_step', 'block_steps', &
         'series_every', 'friction', 'roughness'], [cfg%domain%box, parts%radius, cfg%domain%shear_rate, cfg%time%dt, rh%core, &
         rh%r_outer, rh%r_contact, real([cfg%rheology%blocks, cfg%discard_step, cfg%block_steps, cfg%output%series_every], dp), &
         merge(cfg%contact%friction, 0.0_dp, has_contacts), merge(cfg%contact%roughness, 0.0_dp, has_contacts)])
  end if
  ! from the start: an empty series; from a checkpoint: its records up to the checkpoint's step
  call series_open(series, cfg%output%directory, merge(step, -1, restarting), (cfg%time%steps - step) / cfg%output%series_every)
  PetscCallA(stage_pop(ierr))
  ! free lubricated pairs must not separate faster than their Lambda relaxes (mod_fictitious_domain)
  if (cfg%resolved .and. has_particles .and. has_lubrication .and. parts%motion == MOTION_FREE) &
    call report(fictitious_domain_pair_lag_limit(cfg%time%dt, cfg%fluid%reynolds, cfg%h))
  if (.not. cfg%resolved) then
    write(text, '(a,i0,a)') 'models: lubrication dynamics, no fluid (one-body Stokes drag in the imposed flow, '// &
         trim(merge('Lees-Edwards boundaries', 'walls in y             ', cfg%lees_edwards))//'); ', parts%n, &
         ' rigid spheres (motion '''//trim(cfg%particles%motion)//'''); '//trim(contact_models())//'; '//trim(lubrication_models())
    call log_line(text)
  else if (has_particles) then
    write(text, '(a,i0,a)') 'models: fluid (unsteady Stokes, projection); ', parts%n, &
         ' rigid spheres (fictitious domain, motion '''//trim(cfg%particles%motion)//'''); '//trim(contact_models())// &
         '; '//trim(lubrication_models())
    call log_line(text)
  else
    call log_line('models: fluid (unsteady Stokes, projection); no particles in this deck')
  end if
  ! -bench_cold_poisson: time one pressure solve from a zero guess to 1e-8 (doc/BENCHMARKS.md)
  PetscCallA(PetscOptionsHasName(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-bench_cold_poisson', bench_cold, ierr))
  if (bench_cold .and. cfg%resolved) then
    ! the yardstick is the multigrid solve whatever solves the steps (-fluid_solver fft needs no KSP)
    if (fl%solver(FIELD_P)%direct) then
      PetscCallA(solver_create(grid, FIELD_P, 1.0e-8_dp, 0.0_dp, yardstick, ierr, krylov=.true.))
      PetscCallA(solver_cold_solve(yardstick, 1.0e-8_dp, cold_seconds, cold_its, ierr))
      PetscCallA(solver_destroy(yardstick, ierr))
    else
      PetscCallA(solver_cold_solve(fl%solver(FIELD_P), 1.0e-8_dp, cold_seconds, cold_its, ierr))
    end if
    write(text, '(a,f10.5,a,i0,a)') 'bench: cold Poisson solve to 1e-8:', cold_seconds, ' s, ', cold_its, ' iterations'
    call log_line(text)
  end if
  ! -fault_nan_step N: poison the velocity at step N (tests of the runtime guard only)
  fault_nan_step = -1
  PetscCallA(PetscOptionsGetInt(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-fault_nan_step', fault_nan_step, fault_set, ierr))
  ! a run from the start publishes its initial state as checkpoint.h5 before the first step, so the
  ! directory holds a whole checkpoint whatever kills the run later (a kill during a write leaves
  ! the previous one; doc/DESIGN.md "Files, restart and signals")
  if (.not. restarting .and. step < cfg%time%steps) then
    PetscCallA(stage_push(STAGE_OUTPUT, ierr))
    call checkpoint()
    PetscCallA(stage_pop(ierr))
  end if
  iterations_sum = 0
  wall_loop = MPI_Wtime()

  ! ---- time loop ----
  first_step = step
  stop_reason = RUNNING
  if (step >= cfg%time%steps) stop_reason = DONE
  ! the step of this run, its variant chosen once (mod_time_step); -fd_carry_lambda 0 leaves Lambda
  ! on the faces of X^n (the scheme before 2026-11-23; for the comparison of doc/VALIDATION.md §5.3)
  carry_lambda = .true.
  PetscCallA(PetscOptionsGetBool(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-fd_carry_lambda', carry_lambda, fault_set, ierr))
  PetscCallA(make_time_step(ierr))
  do while (stop_reason == RUNNING)
    PetscCallA(time_step_advance(ts, ierr))
    if (ts%contact_failure /= 0) call contact_failure(ts%contact_failure)
    if (ts%lubrication_failure(1) /= 0) call lubrication_failure(ts%lubrication_failure)
    if (has_contacts) then
      if (pc%max_overlap > largest_overlap) then
        ! a new largest overlap of the run: warned once past h_r/2 (mod_contact)
        call report(overlap_limit(pc%params, largest_overlap, pc%max_overlap, step))
        largest_overlap = pc%max_overlap
        largest_overlap_step = step
      end if
    end if
    if (cfg%resolved) iterations_sum = iterations_sum + [fl%solver(1)%iterations, fl%solver(2)%iterations, &
                                                         fl%solver(3)%iterations, fl%solver(4)%iterations]
    step = step + 1
    time = time + cfg%time%dt

    PetscCallA(stage_push(STAGE_OUTPUT, ierr))
    wall_now = MPI_Wtime() - wall_start
    if (mod(step, cfg%output%series_every) == 0) call record()
    if (mod(step, cfg%output%progress_every) == 0) then
      wall_per_step = wall_now / (step - first_step)
      if (cfg%resolved) then
        call progress_line(step, cfg%time%steps, time, wall_now, wall_per_step, fl)
      else
        call progress_line(step, cfg%time%steps, time, wall_now, wall_per_step)
      end if
      call series_flush(series, progress=.true.)
    end if
    if (cfg%output%fields_every > 0 .and. cfg%resolved) then
      if (mod(step, cfg%output%fields_every) == 0) then
        PetscCallA(write_fields(cfg%output%directory, grid, fl, step, time, ierr))
      end if
    end if
    if (cfg%output%particles_every > 0 .and. has_particles) then
      if (mod(step, cfg%output%particles_every) == 0) call particles_snapshot(cfg%output%directory, parts, cfg%domain%box, step, time)
    end if
    if (cfg%output%checkpoint_every > 0) then
      if (mod(step, cfg%output%checkpoint_every) == 0) call checkpoint()
    end if
    PetscCallA(stage_pop(ierr))

    if (step == fault_nan_step) then
      if (cfg%resolved) then
        PetscCallA(VecScale(fl%vel(1), ieee_value(1.0_dp, ieee_quiet_nan), ierr))
      else
        parts%velocity(1, 1) = ieee_value(1.0_dp, ieee_quiet_nan)
      end if
    end if
    call check_health()

    stop_reason = why_stop()
  end do

  ! ---- end of run: the series, the last fields and a checkpoint to continue from ----
  if (step > first_step) then
    wall_loop = (MPI_Wtime() - wall_loop) / (step - first_step)
    write(text, '(a,i0,a,f10.5,a,4(f6.1))') 'steps run: ', step - first_step, '  wall time per step:', wall_loop, &
         ' s  mean iterations u v w p:', real(iterations_sum, dp) / (step - first_step)
    if (.not. cfg%resolved) write(text, '(a,i0,a,f10.5,a)') 'steps run: ', step - first_step, &
         '  wall time per step:', wall_loop, ' s'
    call log_line(text)
    if (has_particles) then
      if (has_contacts .and. pc%params%h_r > 0) then
        ! the overlap bound of the extreme scenes (doc/VALIDATION.md §6): below h_r/2
        write(text, '(a,f8.4,a,i0,a)') 'contacts: largest overlap |delta''| over this run ', &
             largest_overlap / pc%params%h_r, ' h_r (step ', largest_overlap_step, ')'
        call log_line(text)
      end if
      if (cfg%resolved) then
        if (fd%solver%solves > 0) then
          write(text, '(a,i0,a,f10.3,a)') 'particle system with lubrication pairs: ', fd%solver%solves, &
               ' sparse solves, mean ', 1.0e3_dp * fd%solver%seconds / fd%solver%solves, ' ms (assembly + solve)'
          call log_line(text)
        end if
      else if (ld_solver%solves > 0) then
        write(text, '(a,i0,a,f10.3,a)') 'particle system with lubrication pairs: ', ld_solver%solves, &
             ' sparse solves, mean ', 1.0e3_dp * ld_solver%seconds / ld_solver%solves, ' ms (assembly + solve)'
        call log_line(text)
      end if
    end if
  end if
  PetscCallA(stage_push(STAGE_OUTPUT, ierr))
  if (step > first_step .and. mod(step, cfg%output%series_every) /= 0) call record()
  call series_close(series)
  if (step > first_step) then
    if (cfg%resolved) then
      PetscCallA(write_fields(cfg%output%directory, grid, fl, step, time, ierr))
    end if
    if (has_particles) call particles_snapshot(cfg%output%directory, parts, cfg%domain%box, step, time)
    call checkpoint()
  end if
  if (allocated(rh)) call summary()
  PetscCallA(stage_pop(ierr))
  select case (stop_reason)
  case (SIGNALLED)
    write(text, '(a,i0,a,i0,a)') 'stopped by signal ', stop_signal(), ' at step ', step, &
         ': checkpoint written to '//trim(checkpoint_path)
  case (WALL_LIMIT)
    write(text, '(a,i0,a)') 'stopped at step ', step, ' before &run max_wall_hours: checkpoint written to '// &
         trim(checkpoint_path)
  case (STEADY)
    write(text, '(a,i0,a,es10.3)') 'steady state at step ', step, ': max|du/dt| = ', fl%max_rate
  case default
    write(text, '(a,i0)') 'finished at step ', step
  end select
  call log_line(text)
  if (cfg%verification%manufactured_solution .and. cfg%resolved) then
    PetscCallA(fluid_errors_vs_manufactured(grid, fl, cfg%domain%shear_rate, err_vel, err_p_max, err_p_rms, ierr))
    write(text, '(a,3es14.6)') 'manufactured solution errors (velocity max, pressure max, pressure rms):', &
         err_vel, err_p_max, err_p_rms
    call log_line(text)
  end if
  write(text, '(a,f10.2,a)') 'wall time ', MPI_Wtime() - wall_start, ' s'
  call log_line(text)

  if (cfg%resolved) then
    if (has_particles) then
      PetscCallA(fictitious_domain_destroy(fd, ierr))
    end if
    PetscCallA(fluid_destroy(fl, ierr))
    PetscCallA(grid_destroy(grid, ierr))
  else
    PetscCallA(particle_solver_destroy(ld_solver, ierr))
  end if
  call release_directory()
  PetscCallA(PetscFinalize(ierr))

contains

  ! DECK is the first argument; -restart FILE and -continue are read from PETSc's options database.
  ! -continue: restart from the deck's output directory's checkpoint.h5 when there is one, else
  ! start (what each job of a batch chain runs, scripts/slurm/).
  subroutine command_line(deck, restart, restarting, continuing)
    character(len=*), intent(out) :: deck, restart
    logical, intent(out) :: restarting, continuing
    PetscBool :: set
    PetscErrorCode :: ierr
    logical :: direct
    integer :: plan
    call get_command_argument(1, deck)
    if (len_trim(deck) == 0 .or. deck(1:1) == '-') &
      call fatal_error('usage: fdsusp DECK [-restart CHECKPOINT | -continue] [PETSc options]', 2)
    restart = ''
    PetscCallA(PetscOptionsGetString(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-restart', restart, set, ierr))
    restarting = logical(set)
    if (restarting .and. len_trim(restart) == 0) &
      call fatal_error('fdsusp: -restart needs the path of a checkpoint', 2)
    PetscCallA(PetscOptionsHasName(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-continue', set, ierr))
    continuing = logical(set)
    if (restarting .and. continuing) &
      call fatal_error('fdsusp: -restart and -continue exclude each other (-continue restarts from the '// &
                       'output directory''s checkpoint.h5)', 2)
    ! the fluid-solver options are checked now, not after the set-up (each stops with one message)
    direct = direct_solves_wanted()
    if (direct) plan = fft_planner_flags()
  end subroutine command_line

  ! -continue: the output directory's checkpoint.h5 if it exists (looked for under the directory's
  ! lock, so no other run is writing it), else a start from the beginning.
  subroutine continue_from_directory()
    integer :: found
    found = 0
    if (is_root()) then
      inquire(file=trim(cfg%output%directory)//'/checkpoint.h5', exist=restarting)
      found = merge(1, 0, restarting)
    end if
    call MPI_Bcast(found, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
    restarting = found == 1
    if (restarting) then
      restart = trim(cfg%output%directory)//'/checkpoint.h5'
      call log_line('-continue: continuing from '//trim(restart))
    else
      call log_line('-continue: no checkpoint in '//trim(cfg%output%directory)//' yet: starting from the beginning')
    end if
  end subroutine continue_from_directory

  ! The output directory must exist (it is created), be this run's alone (a lock, before anything
  ! is written there) and be writable now, not hours from now. The lock (src/runtime/os_services_c.c) is held by
  ! rank 0's process until it ends and dies with it, so a lock file left by a killed run does not
  ! block the next start. A checkpoint.h5.tmp left by a run killed while writing is removed.
  subroutine prepare_output_directory(cfg)
    type(config_t), intent(in) :: cfg
    integer :: state(3)                        ! errno, lock status, a stale checkpoint.h5.tmp removed
    integer :: u, e
    character(len=16) :: code
    character(len=400) :: holder
    character(len=:), allocatable :: dir
    dir = trim(cfg%output%directory)
    state = 0
    holder = ''
    if (is_root()) then
      state(1) = make_directory(dir)
      if (state(1) == 0) then
        state(2) = lock_directory(dir, holder)
        if (state(2) > 0) state(1) = state(2)
      end if
      if (state(1) == 0 .and. state(2) /= -1) state(1) = probe_directory(dir)
      if (state(1) == 0 .and. state(2) /= -1) then
        open(newunit=u, file=dir//'/checkpoint.h5.tmp', status='old', action='read', iostat=e)
        if (e == 0) then
          close(u, status='delete', iostat=e)
          state(3) = 1
        end if
      end if
    end if
    call MPI_Bcast(state, 3, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
    call MPI_Bcast(holder, len(holder), MPI_CHARACTER, 0, PETSC_COMM_WORLD, ierr)
    if (state(2) == -1) then
      call input_error(cfg%deck_file, 'output', 'directory', '"'//dir//'" is in use by another run ('// &
           trim(holder)//', lock file '//dir//'/.fdsusp.lock): wait for it to end, or choose another directory')
    end if
    if (state(1) /= 0) then
      write(code, '(i0)') state(1)
      call input_error(cfg%deck_file, 'output', 'directory', '"'//dir// &
           '" cannot be created or written (errno '//trim(code)//')')
    end if
    if (state(2) == -2) call warn_line('the file system of "'//dir//'" offers no locks: a second run '// &
         'started into it would not be refused')
    if (state(2) == 0 .and. len_trim(holder) > 0) call log_line('output directory '//dir//': its lock file '// &
         'names '//trim(holder)//', a run that ended without releasing it (killed or crashed); that lock '// &
         'ended with its process: taken over')
    if (state(3) == 1) call log_line('output directory '//dir//': removed checkpoint.h5.tmp, the partial '// &
         'write of a killed run (checkpoint.h5, if there, is the last whole checkpoint)')
  end subroutine prepare_output_directory

  ! One record of series.h5, and the statistics' share of it.
  subroutine record()
    call series_columns()
    call series_record(series)
    ! only the records on the series_every grid enter the statistics (a restart then adds
    ! exactly the records an uninterrupted run would)
    if (has_particles .and. allocated(rh)) then
      if (mod(step, cfg%output%series_every) == 0) call rheo_accumulate(rh, step)
    end if
  end subroutine record

  ! The columns of series.h5 in the file's order: the name and the value of each (the value's shape
  ! is the column's). Called once before series_open, which makes these calls the declaration of
  ! the columns, then for every record, so the header and the records cannot differ.
  subroutine series_columns()
    call series_column(series, 'step', step)
    call series_column(series, 'time', time)
    call series_column(series, 'wall_time', MPI_Wtime() - wall_start)
    ! each physics module names its columns (mod_columns); the manufactured solution's errors are
    ! the verification's
    if (cfg%resolved) call series_add(series, fluid_columns(fl))
    if (cfg%lees_edwards) call series_add(series, le_columns(le))
    if (cfg%verification%manufactured_solution) then
      PetscCallA(fluid_errors_vs_manufactured(grid, fl, cfg%domain%shear_rate, err_vel, err_p_max, err_p_rms, ierr))
      call series_column(series, 'mms_error_velocity_max', err_vel)
      call series_column(series, 'mms_error_pressure_max', err_p_max)
      call series_column(series, 'mms_error_pressure_rms', err_p_rms)
    end if
    if (.not. has_particles) return
    call series_add(series, particles_columns(parts))
    if (has_lubrication) call series_add(series, particle_lubrication_columns(pl))
    if (has_contacts) call series_add(series, particle_contacts_columns(pc))
    if (allocated(rh)) then
      call series_add(series, rheo_columns(rh))
      if (has_contacts) call series_column(series, 'contact_overlap_over_roughness', &
                                           pc%max_overlap / max(pc%params%h_r, tiny(1.0_dp)))
    end if
  end subroutine series_columns

  ! The step of this run (mod_time_step) over the pieces it has: the variant follows from them.
  subroutine make_time_step(ierr)
    PetscErrorCode, intent(out) :: ierr
    type(particle_contacts_t), pointer :: contacts
    type(particle_lubrication_t), pointer :: lubrication
    type(rheology_t), pointer :: rheology
    contacts => null()
    lubrication => null()
    rheology => null()
    if (has_contacts) contacts => pc
    if (allocated(pl)) lubrication => pl
    if (allocated(rh)) rheology => rh
    ! (disassociated pointers are absent arguments)
    if (cfg%resolved .and. has_particles) then
      call time_step_create(ts, cfg%time%dt, cfg%domain%box, cfg%walls, le, carry_lambda, ierr, grid=grid, fluid=fl, fd=fd, &
                            parts=parts, contacts=contacts, lubrication=lubrication, rheology=rheology)
    else if (cfg%resolved) then
      call time_step_create(ts, cfg%time%dt, cfg%domain%box, cfg%walls, le, carry_lambda, ierr, grid=grid, fluid=fl)
    else
      call time_step_create(ts, cfg%time%dt, cfg%domain%box, cfg%walls, le, carry_lambda, ierr, parts=parts, ld=ld, &
                            ld_solver=ld_solver, contacts=contacts, lubrication=lubrication, rheology=rheology)
    end if
    CHKERRQ(ierr)
  end subroutine make_time_step

  subroutine checkpoint()
    call series_flush(series)
    PetscCallA(checkpoint_write(checkpoint_path, cfg, state, step, time, ierr))
  end subroutine checkpoint

  ! summary.json (rank 0) and the rheology in the run log: value +- standard error over the blocks.
  subroutine summary()
    integer :: err, k, q, complete
    real(dp) :: value(NSUMMARY), error(NSUMMARY)
    real(dp), allocatable :: profile(:, :), angles(:, :)
    character(len=1100) :: path
    character(len=20), parameter :: shown(14) = [character(len=20) :: 'eta_r', 'eta_h', 'eta_c', 'N1/tau', &
         'N2/tau', 'Pi/tau', 'lambda_2', 'lambda_3', 'eta_n', 'I_v', 'mu', 'phi_core', 'gamma_dot_core', 'tau']
    if (.not. is_root()) return
    path = trim(cfg%output%directory)//'/summary.json'
    call rheo_summarise(rh, step, complete, value, error, profile, angles)
    call summary_write(rh, path, step, complete, value, error, profile, angles, err)
    if (err /= 0) call abort_run(trim(path)//' cannot be written: '//write_failure_cause(cfg%output%directory, 0.0_dp))
    write(text, '(a,i0,a,i0,a)') 'rheology of the core region (', complete, ' of ', cfg%rheology%blocks, &
         ' blocks complete; value +- standard error; doc/RHEOLOGY.md):'
    call log_line(text)
    do k = 1, size(shown)
      q = findloc(summary_names, shown(k), 1)
      write(text, '(2x,a16,es13.5,a,es10.3)') shown(k), value(q), ' +- ', error(q)
      call log_line(text)
    end do
    call log_line('summary written to '//trim(path))
  end subroutine summary

  ! The contact part of the run log's 'models:' line.
  function contact_models() result(line)
    character(len=200) :: line
    character(len=32) :: friction
    if (.not. has_contacts) then
      line = 'no contacts'
      return
    end if
    friction = 'friction off'
    if (pc%params%mu_d > 0) write(friction, '(a,f5.3,a)') 'friction on (mu_d = ', pc%params%mu_d, ')'
    write(line, '(a,es10.3,a,es10.3,a)') 'contacts on (Hertz, h_r = ', pc%params%h_r, ' a, k_n = ', &
         pc%params%k_n, '), '//trim(friction)
  end function contact_models

  ! The lubrication part of the run log's 'models:' line.
  function lubrication_models() result(line)
    character(len=200) :: line
    select case (lub%model)
    case (LUB_NONE)
      line = 'no lubrication correction'
      if (.not. cfg%resolved) line = 'no pair hydrodynamics (one-body drag only)'
    case (LUB_EXACT)
      write(line, '(a,f7.3,a)') 'exact two-body pair and wall resistance minus one-body (outer cut-off ', &
           lub%outer_cutoff, ' a)'
    case (LUB_SIMPLE)
      write(line, '(a,f6.3,a)') 'lubrication simple (singular terms, outer cut-off ', lub%outer_cutoff, ' a)'
    case default
      write(line, '(a,f6.3,a,i0,a)') 'lubrication full (calibrated, outer cut-off ', lub%outer_cutoff, &
           ' a, ', size(lub%pair_gap), ' tabulated gaps)'
    end select
  end function lubrication_models

  ! The findings of a limit check (mod_limits), in their order: warnings, and the refusal of the
  ! deck item named, which stops the run. Collective: every rank finds the same.
  subroutine report(findings)
    type(limit_finding_t), intent(in) :: findings(:)
    integer :: k
    do k = 1, size(findings)
      if (findings(k)%level == LIMIT_REFUSE) then
        call input_error(cfg%deck_file, trim(findings(k)%group), trim(findings(k)%key), trim(findings(k)%text))
      else
        call warn_line(findings(k)%text)
      end if
    end do
  end subroutine report

  ! Collective (every rank holds the same contacts): stop with a diagnostic.
  subroutine contact_failure(code)
    integer, intent(in) :: code
    character(len=400) :: what
    character(len=40) :: partner
    integer :: pair(2)
    if (code == 2) then
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
      call stop_with_state(step + 1, what)
    end if
    call fatal_error('fdsusp: fatal: the contact history does not belong to this particle set', 4)
  end subroutine contact_failure

  ! A lubrication block LAPACK could not decompose (the kernels return the status, the caller stops):
  ! non-finite positions or resistance. Collective (every rank holds the same links).
  subroutine lubrication_failure(link)
    integer, intent(in) :: link(2)
    character(len=200) :: what
    if (link(2) == 0) then
      write(what, '(a,i0,a)') 'the lubrication block of particle ', link(1), ' and a wall could not be '// &
           'decomposed (LAPACK dsyev failed: non-finite position or resistance)'
    else
      write(what, '(a,i0,a,i0,a)') 'the lubrication block of particles ', link(1), ' and ', link(2), &
           ' could not be decomposed (LAPACK dsyev failed: non-finite positions or resistance)'
    end if
    call stop_with_state(step, what)
  end subroutine lubrication_failure

  ! Runtime guard (doc/DESIGN.md "Files, restart and signals"): a non-finite velocity, pressure or particle quantity, or a
  ! sphere half way through a wall, stops
  ! the run at once, collectively, with a diagnostic; the state is written to failed_state.h5
  ! beside the last good checkpoint, which is never overwritten. The norms are global reductions
  ! and particle data is replicated, so every rank takes the same decision.
  subroutine check_health()
    PetscReal :: norms(5)
    integer :: c, q
    character(len=400) :: what
    what = ''
    norms = 0.0_dp
    if (cfg%resolved) then
      do c = 1, 3
        PetscCallA(VecNorm(fl%vel(c), NORM_INFINITY, norms(c), ierr))
      end do
      PetscCallA(VecNorm(fl%pressure, NORM_INFINITY, norms(4), ierr))
    end if
    do c = 1, 4
      if (.not. ieee_is_finite(norms(c))) then
        write(what, '(a,a,a,es10.3)') 'the fluid ', trim(merge('velocity', 'pressure', c <= 3)), &
             ' is not finite: max norm ', norms(c)
        exit
      end if
    end do
    if (len_trim(what) == 0 .and. has_particles) then
      do q = 1, parts%n
        if (.not. (all(ieee_is_finite(parts%velocity(:, q))) .and. all(ieee_is_finite(parts%omega(:, q))) &
                   .and. all(ieee_is_finite(parts%position(:, q))))) then
          write(what, '(a,i0,a,3es10.3,a,3es10.3)') 'particle ', q, ' is not finite: velocity ', &
               parts%velocity(:, q), ' omega ', parts%omega(:, q)
          exit
        end if
        ! a sphere half way through a wall: nothing physical holds it back any more (no wall
        ! contacts or lubrication, or a step far too large for them)
        if (cfg%walls .and. (parts%position(2, q) < 0.5_dp * parts%radius .or. &
                             parts%position(2, q) > cfg%domain%box(2) - 0.5_dp * parts%radius)) then
          write(what, '(a,i0,a,f10.5,a,f10.5,a)') 'particle ', q, ' is half way through a wall (centre y = ', &
               parts%position(2, q), ', walls at 0 and ', cfg%domain%box(2), &
               '): add &contact, keep &lubrication on, or lower &time dt'
          exit
        end if
      end do
    end if
    if (len_trim(what) == 0) return
    call stop_with_state(step, what)
  end subroutine check_health

  ! Stop a run that went wrong: the series so far, the state in failed_state.h5 beside the last
  ! good checkpoint (never over it), one message naming the step and what went wrong, status 5.
  subroutine stop_with_state(at_step, what)
    integer, intent(in) :: at_step
    character(len=*), intent(in) :: what
    call series_close(series)
    PetscCallA(checkpoint_write(trim(cfg%output%directory)//'/failed_state.h5', cfg, state, step, time, ierr))
    write(text, '(a,i0,a)') 'fdsusp: fatal: at step ', at_step, ': '//trim(what)// &
         '; state written to '//trim(cfg%output%directory)//'/failed_state.h5, the last good checkpoint is kept'
    call fatal_error(text, 5)
  end subroutine stop_with_state

  ! Collective: every rank takes the same decision.
  integer function why_stop()
    integer :: flags(3), all_flags(3)
    real(dp) :: elapsed, per_step
    flags = 0
    if (stop_signal() /= 0) flags(1) = 1
    if (cfg%run%max_wall_hours > 0.0_dp) then
      elapsed = MPI_Wtime() - wall_start
      per_step = elapsed / max(1, step - first_step)
      ! leave room for two more steps and the final output
      if (elapsed + 3.0_dp * per_step > 3600.0_dp * cfg%run%max_wall_hours) flags(2) = 1
    end if
    if (cfg%resolved .and. cfg%time%steady_tolerance > 0.0_dp) then
      if (fl%max_rate < cfg%time%steady_tolerance) flags(3) = 1
    end if
    call MPI_Allreduce(flags, all_flags, 3, MPI_INTEGER, MPI_MAX, PETSC_COMM_WORLD, ierr)
    why_stop = RUNNING
    if (step >= cfg%time%steps) why_stop = DONE
    if (all_flags(3) == 1) why_stop = STEADY
    if (all_flags(2) == 1) why_stop = WALL_LIMIT
    if (all_flags(1) == 1) why_stop = SIGNALLED
  end function why_stop

end program fdsusp
