! fdsusp: fictitious-domain simulation of sheared suspensions (doc/METHOD.md), or with &fluid model =
! 'none' their lubrication dynamics: the spheres alone, one-body Stokes drag plus exact pair and wall
! resistance and contacts, between walls or across Lees-Edwards boundaries (doc/METHOD.md §6).
!   bin/fdsusp DECK [-restart CHECKPOINT | -branch CHECKPOINT | -continue] [PETSc options]
! Reads and checks everything before any work, then steps the flow in time, writing the series,
! field snapshots and checkpoints the deck asks for. SIGTERM or SIGUSR1 (what batch schedulers
! send before the kill) ends the run at the end of the current step with a checkpoint, status 0.
! This file is the run's algorithm: the pieces are made and checked, wired into the time step
! (mod_time_step) and the output (mod_run_output), and stepped until the run stops
! (mod_run_control); doc/DESIGN.md "Source layout" says which module does what.
program fdsusp
#include <petsc/finclude/petscsys.h>
  use petscsys
  use mod_kinds, only: dp, pi
  use mod_params, only: config_t, read_deck, echo_deck, max_line
  use mod_errors, only: log_line, warn_line, input_error, report_limits, fatal_error
  use mod_run_control, only: command_line, prepare_output_directory, continue_from_directory, run_stop_reason, &
                             run_stop_line, run_signal_line, RUN_GOES_ON, RUN_DONE
  use mod_os_services, only: install_signal_handlers, release_directory, peak_resident_kb, resident_kb
  use mod_timers, only: timers_register, stage_push, stage_pop, STAGE_SETUP
  use mod_h5util, only: h5util_init
  use mod_grid, only: grid_t, grid_create, grid_destroy
  use mod_fluid, only: fluid_t, fluid_create, fluid_destroy, fluid_options_check, fluid_bench_cold_poisson, &
                       fluid_unit_response
  use mod_fluid_verification, only: fluid_errors_vs_manufactured
  use mod_particles, only: particles_t, sphere_share_t, MOTION_FREE
  use mod_particles_io, only: particles_load
  use mod_initial_packing, only: initial_packing_make
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_create, particle_contacts_description
  use mod_contact, only: contact_limits
  use mod_lubrication, only: lubrication_t, lub_description, LUB_NONE
  use mod_lubrication_io, only: lubrication_load
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_create
  use mod_rheology, only: rheology_t, rheo_create
  use mod_lees_edwards, only: lees_edwards_t, le_create
  use mod_shear_protocol, only: shear_protocol_t, shear_protocol_create, shear_protocol_kind, shear_protocol_varies, &
                                PROTOCOL_STEPS, &
                                shear_protocol_begin_at
  use mod_fictitious_domain, only: fictitious_domain_t, fictitious_domain_create, fictitious_domain_destroy, &
                                   fictitious_domain_pair_lag_limit, fictitious_domain_stresslet_lag_limit
  use mod_lubrication_dynamics, only: lubrication_dynamics_t, lubrication_dynamics_create
  use mod_particle_solver, only: particle_solver_t, particle_solver_create, particle_solver_destroy
  use mod_sphere_ownership, only: sphere_ownership_mine
  use mod_checkpoint, only: checkpoint_state_t, checkpoint_check, checkpoint_read
  use mod_time_step, only: time_step_t, time_step_create, time_step_advance, time_step_guard, time_step_report, &
                           time_step_share
  use mod_run_output, only: run_output_t, run_output_open, run_output_step, run_output_checkpoint, &
                            run_output_fail, run_output_close
  implicit none

  PetscErrorCode :: ierr
  type(config_t) :: cfg
  type(grid_t), target :: grid
  type(fluid_t), target :: fl
  type(fluid_t), allocatable, target :: fl_unit     ! stress control of the pure fluid: the step per unit wall speed
  type(particles_t), target :: parts
  type(fictitious_domain_t), target :: fd
  type(particle_contacts_t), allocatable, target :: pc    ! allocated when the run has contacts
  type(lubrication_t) :: lub
  type(particle_lubrication_t), allocatable, target :: pl ! allocated when lubrication is on
  type(rheology_t), allocatable, target :: rh       ! allocated when the deck has &rheology
  type(lees_edwards_t), target :: le                ! y_boundary = 'lees-edwards' (le%active), its offset
  type(shear_protocol_t), target :: protocol        ! the imposed shear in time (&shear)
  type(lubrication_dynamics_t), target :: ld        ! &fluid model = 'none': the spheres alone
  type(particle_solver_t), target :: ld_solver      ! its sparse 6N solve
  type(checkpoint_state_t) :: state                 ! what the checkpoints hold: the pieces this run has
  ! the pieces the step and the output work on, associated when the run has them
  type(grid_t), pointer :: grid_p => null()
  type(fluid_t), pointer :: fluid_p => null()
  type(particles_t), pointer :: parts_p => null()
  type(particle_contacts_t), pointer :: contacts_p => null()
  type(particle_lubrication_t), pointer :: lubrication_p => null()
  type(rheology_t), pointer :: rheology_p => null()
  type(lees_edwards_t), pointer :: le_p => null()
  type(time_step_t), target :: ts                   ! the step of this run
  type(sphere_share_t), target :: share             ! this rank's share of the spheres (output_share)
  type(run_output_t) :: out                         ! what it writes, and when
  character(len=max_line) :: deck, restart
  character(len=400) :: text
  integer :: step, first_step, stop_reason
  real(dp) :: time, wall_start, wall_loop, err_vel, err_p_max, err_p_rms
  logical :: restarting, continuing, branching, has_particles, statistics_afresh
  real(dp), allocatable :: mixture_radii(:)         ! a mixture's radii; unallocated (absent) for equal spheres

  PetscCallA(PetscInitialize(ierr))
  ! SIGTERM/SIGUSR1 from now on only ask the run to stop after its next step (they replace
  ! PETSc's handlers, which would abort a run signalled during its set-up)
  call install_signal_handlers()
  wall_start = MPI_Wtime()
  call h5util_init()

  ! ---- everything is checked before any work ----
  call command_line(deck, restart, restarting, continuing, branching)
  call fluid_options_check()
  call read_deck(deck, cfg)
  call log_line('fdsusp: '//trim(cfg%run%title))
  call echo_deck(cfg)
  call prepare_output_directory(cfg)
  if (continuing) call continue_from_directory(cfg, restart, restarting)
  call make_particles()
  has_particles = parts%n > 0
  ! a mixture's radii, in units of the smallest (the unit), for the models that take each sphere's
  ! radius: contacts, lubrication, lubrication dynamics, statistics (doc/INPUT.md "Mixtures");
  ! unallocated for equal spheres, which passes them as absent
  if (cfg%species > 1) mixture_radii = parts%radii / parts%radius
  ! sliding periodic boundaries in y (lubrication dynamics): the offset starts at 0, a restart
  ! reads it from the checkpoint
  if (cfg%lees_edwards) le = le_create(cfg%domain%box, cfg%domain%shear_rate, 0.0_dp)
  ! the imposed shear as a function of time (doc/INPUT.md "&shear"); the pieces below are made with
  ! its reference rate, the rate at t = 0, and the step gives them the rate of each step
  ! (stress control: the reference rate is the unit, and each step solves for its own rate)
  if (cfg%shear%protocol == 'steps') then
    associate(n => cfg%shear%levels)
      if (cfg%shear%control == 'stress') then
        protocol = shear_protocol_create(PROTOCOL_STEPS, cfg%shear%rate, cfg%time%dt, 0.0_dp, 0.0_dp, 0.0_dp, &
                                         0.0_dp, cfg%shear%step_at(1:n), cfg%shear%step_level(1:n), &
                                         cfg%shear%step_by == 'strain')
      else
        protocol = shear_protocol_create(PROTOCOL_STEPS, cfg%shear%rate, cfg%time%dt, 0.0_dp, 0.0_dp, 0.0_dp, &
                                         step_at=cfg%shear%step_at(1:n), step_level=cfg%shear%step_level(1:n), &
                                         by_strain=cfg%shear%step_by == 'strain')
      end if
    end associate
  else if (cfg%shear%control == 'stress') then
    protocol = shear_protocol_create(shear_protocol_kind(cfg%shear%protocol), cfg%shear%rate, cfg%time%dt, &
                                     cfg%shear%reversal_strain, cfg%shear%strain_amplitude, cfg%shear%period, &
                                     cfg%shear%stress)
  else
    protocol = shear_protocol_create(shear_protocol_kind(cfg%shear%protocol), cfg%shear%rate, cfg%time%dt, &
                                     cfg%shear%reversal_strain, cfg%shear%strain_amplitude, cfg%shear%period)
  end if
  call make_contacts()
  call make_lubrication()
  call make_statistics()
  step = 0
  time = 0.0_dp
  if (restarting) then
    call checkpoint_check(restart, cfg, parts%n, branching, step, time, rh)   ! rh: absent unless allocated
    write(text, '(a,i0,a,es12.5)') trim(merge('branch from ', 'restart from', branching))//' '//trim(restart)// &
         ' at step ', step, ', time ', time
    call log_line(text)
  end if

  ! ---- set-up ----
  PetscCallA(timers_register(ierr))
  PetscCallA(stage_push(STAGE_SETUP, ierr))
  if (cfg%resolved) then
    PetscCallA(grid_create(cfg, grid, ierr))
    PetscCallA(fluid_create(cfg, grid, fl, ierr))
    if (cfg%shear%control == 'stress') then
      ! stress control (doc/METHOD.md §7.4): a second fluid, one step from rest with walls at -+1
      allocate(fl_unit)
      PetscCallA(fluid_create(cfg, grid, fl_unit, ierr))
      PetscCallA(fluid_unit_response(grid, fl_unit, ierr))
      ! backward Euler keeps the response monotone (a discrete maximum principle): its wall stress is > 0
      if (.not. (fl_unit%tau_bottom + fl_unit%tau_top > 0.0_dp)) call fatal_error('fdsusp: fatal: stress control: '// &
           'the wall stress of the unit wall-speed response is not positive: the wall speed cannot set the stress', 4)
    end if
    if (has_particles) then
      call fictitious_domain_create(grid, cfg%fluid%reynolds, cfg%time%dt, cfg%particles%slip_kappa, &
                                    cfg%particles%radius_offset, fd, ierr); CHKERRA(ierr)
    end if
  else
    ! lubrication dynamics: no grid, no fluid; the imposed shear comes from the walls or the
    ! sliding boundaries (mod_lubrication_dynamics)
    call lubrication_dynamics_create(ld, parts%radius, 1.0_dp, cfg%domain%shear_rate, cfg%domain%box, &
                                     cfg%walls .or. cfg%lees_edwards, mixture_radii)
    PetscCallA(particle_solver_create(ld_solver, ierr))
  end if
  ! the pieces this run has, and the state the checkpoints hold and a restart restores
  call point_at_pieces()
  if (restarting) then
    PetscCallA(checkpoint_read(restart, state, statistics_afresh, ierr))
    if (statistics_afresh) call log_line('statistics: the &rheology window begins after the checkpoint''s step; '// &
         'they start from zero there (nothing the checkpoint accumulated is carried over)')
    ! a branch starts the deck's protocol afresh from the configuration reached (its strain: with
    ! Lees-Edwards boundaries the checkpoint's offset, which the boundary continues from)
    if (branching) then
      if (cfg%lees_edwards) then
        call shear_protocol_begin_at(protocol, le%offset / cfg%domain%box(2))
      else
        call shear_protocol_begin_at(protocol, protocol%strain)
      end if
      call log_line('branch: &shear protocol '''//trim(cfg%shear%protocol)//''' starts afresh here (time 0 of '// &
           'the protocol, no reversal yet; doc/INPUT.md "&shear")')
      ! the rate may jump here: the spheres' Adams-Bashforth extrapolation starts afresh, as after
      ! a reversal (a steady branch keeps it, as branches did before &shear)
      if (shear_protocol_varies(protocol) .and. has_particles) parts%have_prev = .false.
    end if
  end if
  ! what the run writes, and when, over the pieces it has (disassociated pointers are absent)
  call run_output_open(out, cfg, state, step, restarting, wall_start, grid_p, fluid_p, le_p, parts_p, contacts_p, &
                       lubrication_p, rheology_p)
  PetscCallA(stage_pop(ierr))
  ! free lubricated pairs must not separate faster than their Lambda relaxes (mod_fictitious_domain)
  if (cfg%resolved .and. has_particles .and. allocated(pl) .and. parts%motion == MOTION_FREE) &
    call report_limits(cfg%deck_file, fictitious_domain_pair_lag_limit(cfg%time%dt, cfg%fluid%reynolds, cfg%h))
  call log_line(models_line())
  if (cfg%resolved) then
    PetscCallA(fluid_bench_cold_poisson(grid, fl, ierr))
  end if
  ! a run from the start publishes its initial state as checkpoint.h5 before the first step, so the
  ! directory holds a whole checkpoint whatever kills the run later (a kill during a write leaves
  ! the previous one; doc/DESIGN.md "Files, restart and signals")
  if (.not. restarting .and. step < cfg%time%steps) then
    PetscCallA(run_output_checkpoint(out, step, time, ierr))
  end if
  PetscCallA(make_time_step(ierr))

  ! ---- time loop ----
  first_step = step
  wall_loop = MPI_Wtime()
  stop_reason = RUN_GOES_ON
  if (step >= cfg%time%steps) stop_reason = RUN_DONE
  do while (stop_reason == RUN_GOES_ON)
    PetscCallA(time_step_advance(ts, step, ierr))
    if (len_trim(ts%failure) > 0) call run_output_fail(out, step, time, step + 1, ts%failure, output_share())
    step = step + 1
    time = time + cfg%time%dt
    PetscCallA(run_output_step(out, step, time, ierr, output_share()))
    ! the runtime guard: a non-finite or escaped state stops the run with a diagnostic
    PetscCallA(time_step_guard(ts, step, ierr))
    if (len_trim(ts%failure) > 0) call run_output_fail(out, step, time, step, ts%failure, output_share())
    stop_reason = run_stop_reason(cfg, step, first_step, wall_start, steady_flow())
  end do

  ! ---- end of run: the series, the last fields and a checkpoint to continue from ----
  if (step > first_step) call time_step_report(ts, (MPI_Wtime() - wall_loop) / (step - first_step))
  if (len_trim(run_signal_line(stop_reason, step)) > 0) call log_line(run_signal_line(stop_reason, step))
  PetscCallA(run_output_close(out, step, time, ierr, output_share()))
  call log_line(run_stop_line(cfg, stop_reason, step, merge(fl%max_rate, 0.0_dp, cfg%resolved)))
  if (cfg%verification%manufactured_solution .and. cfg%resolved) then
    PetscCallA(fluid_errors_vs_manufactured(grid, fl, cfg%domain%shear_rate, err_vel, err_p_max, err_p_rms, ierr))
    write(text, '(a,3es14.6)') 'manufactured solution errors (velocity max, pressure max, pressure rms):', &
         err_vel, err_p_max, err_p_rms
    call log_line(text)
  end if
  write(text, '(a,f10.2,a)') 'wall time ', MPI_Wtime() - wall_start, ' s'
  call log_line(text)
  call memory_line()

  if (cfg%resolved) then
    if (has_particles) then
      PetscCallA(fictitious_domain_destroy(fd, ierr))
    end if
    PetscCallA(fluid_destroy(fl, ierr))
    if (allocated(fl_unit)) then
      PetscCallA(fluid_destroy(fl_unit, ierr))
    end if
    PetscCallA(grid_destroy(grid, ierr))
  else
    PetscCallA(particle_solver_destroy(ld_solver, ierr))
  end if
  call release_directory()
  PetscCallA(PetscFinalize(ierr))

contains

  ! What the output takes of the spheres: this rank's share when the state is the ranks' local sets
  ! (time_step_share), else nothing (a disassociated pointer, an absent argument: the replicated
  ! particles).
  function output_share() result(p)
    type(sphere_share_t), pointer :: p
    logical :: shared
    call time_step_share(ts, share, shared)
    p => null()
    if (shared) p => share
  end function output_share

  ! The peak resident memory of the run (VmHWM), summed over the ranks and per grid cell: gross,
  ! the libraries' fixed cost included. scripts/bench_memory.sh takes the difference of two grids
  ! for the cost of a cell (doc/BENCHMARKS.md §14). Then what the ranks hold at the end (VmRSS):
  ! the start's replicated particles released, a run's own state (doc/BENCHMARKS.md §23).
  subroutine memory_line()
    real(dp) :: total(1), largest(1), cells
    integer :: nranks, mpierr
    call MPI_Comm_size(PETSC_COMM_WORLD, nranks, mpierr)
    call over_ranks(real(resident_kb(), dp), total, largest)
    if (total(1) >= 0.0_dp) then
      write(text, '(a,i0,a,f10.1,a,f10.1,a)') 'memory: resident at the end (VmRSS) summed over ', nranks, ' ranks ', &
           total(1) / 1024.0_dp, ' MiB, largest rank ', largest(1) / 1024.0_dp, ' MiB'
      call log_line(text)
    end if
    call over_ranks(real(peak_resident_kb(), dp), total, largest)
    if (total(1) < 0.0_dp) return    ! no /proc
    write(text, '(a,i0,a,f10.1,a,f10.1,a)') 'memory: peak resident (VmHWM) summed over ', nranks, ' ranks ', &
         total(1) / 1024.0_dp, ' MiB, largest rank ', largest(1) / 1024.0_dp, ' MiB'
    if (cfg%resolved) then
      cells = real(cfg%cells(1), dp) * real(cfg%cells(2), dp) * real(cfg%cells(3), dp)
      write(text, '(a,a,f8.1,a)') trim(text), ';', total(1) * 1024.0_dp / cells, ' B per grid cell (gross)'
    end if
    call log_line(text)
  end subroutine memory_line

  ! A rank's kB summed over the ranks (total) and the largest rank's (largest). Collective.
  subroutine over_ranks(kb, total, largest)
    real(dp), intent(in) :: kb
    real(dp), intent(out) :: total(1), largest(1)
    integer :: mpierr
    call MPI_Allreduce([kb], total, 1, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, mpierr)
    call MPI_Allreduce([kb], largest, 1, MPI_DOUBLE_PRECISION, MPI_MAX, PETSC_COMM_WORLD, mpierr)
  end subroutine over_ranks

  ! The spheres: a random packing made now (&particles solid_fraction; at a restart only its count
  ! and radii, the checkpoint having the positions), or the deck's or the position file's.
  ! Lubrication dynamics moves spheres and nothing else: a file or packing that yields none leaves
  ! nothing to compute (the deck itself is checked in mod_params).
  subroutine make_particles()
    if (cfg%particles%solid_fraction > 0.0_dp) then
      call initial_packing_make(cfg, parts, restarting)
    else
      call particles_load(cfg, parts)
    end if
    if (cfg%resolved .or. parts%n > 0) return
    if (len_trim(cfg%particles%position_file) > 0) then
      call input_error(cfg%deck_file, 'particles', 'position_file', '"'//trim(cfg%particles%position_file)// &
           '" holds no particles: &fluid model = ''none'' (lubrication dynamics) has nothing to compute')
    else
      call input_error(cfg%deck_file, 'particles', 'solid_fraction', 'packs no particles in this box: '// &
           '&fluid model = ''none'' (lubrication dynamics) has nothing to compute')
    end if
  end subroutine make_particles

  ! Contacts when the deck has &contact and the run has particles (doc/CONTACT.md); their limits
  ! (doc/CONTACT.md, doc/VALIDATION.md §6) checked before any work.
  subroutine make_contacts()
    integer :: info
    if (.not. (has_particles .and. cfg%contact_group)) return
    allocate(pc)
    call particle_contacts_create(pc, parts%n, parts%radius, cfg%contact, cfg%domain%shear_rate, cfg%domain%box, &
                                  cfg%walls, cfg%time%dt, info, text, le, mixture_radii)
    if (info /= 0) call input_error(cfg%deck_file, 'contact', '', trim(text))
  end subroutine make_contacts

  ! Lubrication when there are pairs or walls to lubricate (doc/LUBRICATION.md); the table is read
  ! and checked now. Then the rough contacts' limits, which depend on both.
  subroutine make_lubrication()
    integer :: info
    real(dp) :: solid_fraction
    call lubrication_load(cfg, has_particles .and. (parts%n >= 2 .or. cfg%walls), lub)
    if (lub%model /= LUB_NONE) then
      allocate(pl)
      call particle_lubrication_create(pl, lub, parts%n, cfg%domain%box, cfg%walls, cfg%domain%shear_rate, &
                                       cfg%lubrication%skin, info, text, le, mixture_radii)
      if (info /= 0) call input_error(cfg%deck_file, 'lubrication', 'skin', trim(text))
    end if
    if (allocated(pc) .and. (allocated(pl) .or. .not. cfg%resolved)) then
      solid_fraction = parts%n * (4.0_dp / 3.0_dp) * pi * parts%radius**3 / product(cfg%domain%box)
      if (cfg%species > 1) solid_fraction = sum((4.0_dp / 3.0_dp) * pi * parts%radii**3) / product(cfg%domain%box)
      call report_limits(cfg%deck_file, contact_limits(pc%params, cfg%time%dt, pc%implicit, &
                         cfg%walls .or. cfg%lees_edwards, solid_fraction, cfg%contact%eps_bar, &
                         cfg%contact%normal_stiffness > 0.0_dp, maxval(parts%radii) / parts%radius))
    end if
  end subroutine make_lubrication

  ! Statistics of the core region when the deck has &rheology (doc/RHEOLOGY.md).
  subroutine make_statistics()
    integer :: info
    real(dp) :: core_edge_speed
    if (.not. cfg%rheology_group) return
    allocate(rh)
    call rheo_create(rh, parts%n, cfg%domain%box, parts%radius, cfg%domain%shear_rate, cfg%rheology, &
                     cfg%discard_step, cfg%block_steps, info, le, mixture_radii)
    if (info /= 0) call input_error(cfg%deck_file, 'domain', 'box', &
         'with &rheology every periodic length must be >= 2 (pair_shell + 0.3) a')
    ! a rate that varies: stresses over eta*|reference rate| (doc/RHEOLOGY.md "Protocols")
    rh%raw_stress = shear_protocol_varies(protocol)
    write(text, '(a,i0,a,i0,a,i0,a,i0)') 'statistics: discard ', cfg%discard_step, ' steps, then ', &
         cfg%rheology%blocks, ' blocks of ', cfg%block_steps, ' steps, ending at step ', &
         cfg%discard_step + cfg%rheology%blocks * cfg%block_steps
    call log_line(text)
    ! spheres at the edge of the core must not outrun their Lambda (mod_fictitious_domain)
    core_edge_speed = abs(cfg%domain%shear_rate) * max(rh%core(2) - 0.5_dp * cfg%domain%box(2), &
                                                       0.5_dp * cfg%domain%box(2) - rh%core(1))
    if (cfg%resolved) call report_limits(cfg%deck_file, &
                                         fictitious_domain_stresslet_lag_limit(core_edge_speed, cfg%time%dt, cfg%h))
    if (cfg%time%steps < cfg%discard_step + cfg%rheology%blocks * cfg%block_steps) then
      write(text, '(a,i0,a)') '&time steps = ', cfg%time%steps, ' ends before the averaging window: the summary '// &
           'will hold the blocks complete by then (restart with more steps to finish)'
      call warn_line(text)
    end if
  end subroutine make_statistics

  ! The step of this run (mod_time_step) over the pieces it has: its variant follows from them.
  subroutine make_time_step(ierr)
    PetscErrorCode, intent(out) :: ierr
    if (cfg%resolved) then
      call time_step_create(ts, cfg%time%dt, cfg%domain%box, cfg%walls, le, protocol, ierr, grid=grid_p, fluid=fluid_p, &
                            fd=fd, parts=parts_p, contacts=contacts_p, lubrication=lubrication_p, rheology=rheology_p, &
                            fluid_response=fl_unit)
    else
      call time_step_create(ts, cfg%time%dt, cfg%domain%box, cfg%walls, le, protocol, ierr, parts=parts_p, ld=ld, &
                            ld_solver=ld_solver, contacts=contacts_p, lubrication=lubrication_p, rheology=rheology_p)
    end if
    CHKERRQ(ierr)
  end subroutine make_time_step

  ! The pieces this run has, pointed at (and the state the checkpoints hold: the same pieces).
  subroutine point_at_pieces()
    if (cfg%resolved) then
      grid_p => grid
      fluid_p => fl
      state%fl => fl
    end if
    if (cfg%lees_edwards) then
      le_p => le
      state%offset => le%offset
    end if
    state%protocol => protocol
    if (has_particles) then
      parts_p => parts
      state%parts => parts
      ! each rank writes the per-sphere rows of the spheres in its z-slab (mod_particles_io)
      state%owned_spheres => sphere_ownership_mine
      if (cfg%resolved) state%lambda => fd%lambda
    end if
    if (allocated(pc)) then
      contacts_p => pc
      state%history => pc%history
    end if
    if (allocated(pl)) lubrication_p => pl
    if (allocated(rh)) then
      rheology_p => rh
      state%rh => rh
    end if
  end subroutine point_at_pieces

  ! The run log's 'models:' line.
  function models_line() result(line)
    character(len=600) :: line
    character(len=200) :: contacts
    if (allocated(pc)) then
      contacts = particle_contacts_description(pc)
    else
      contacts = particle_contacts_description()
    end if
    if (.not. cfg%resolved) then
      write(line, '(a,i0,a)') 'models: lubrication dynamics, no fluid (one-body Stokes drag in the imposed flow, '// &
           trim(merge('Lees-Edwards boundaries', 'walls in y             ', cfg%lees_edwards))//'); ', parts%n, &
           ' rigid spheres (motion '''//trim(cfg%particles%motion)//'''); '//trim(contacts)//'; '// &
           trim(lub_description(lub, cfg%resolved))
    else if (has_particles) then
      write(line, '(a,i0,a)') 'models: fluid (unsteady Stokes, projection); ', parts%n, &
           ' rigid spheres (fictitious domain, motion '''//trim(cfg%particles%motion)//'''); '//trim(contacts)// &
           '; '//trim(lub_description(lub, cfg%resolved))
    else
      line = 'models: fluid (unsteady Stokes, projection); no particles in this deck'
    end if
  end function models_line

  ! &time steady_tolerance reached: the resolved flow's largest rate of change is below it.
  logical function steady_flow()
    steady_flow = .false.
    if (cfg%resolved .and. cfg%time%steady_tolerance > 0.0_dp) steady_flow = fl%max_rate < cfg%time%steady_tolerance
  end function steady_flow

end program fdsusp
