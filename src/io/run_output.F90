! What a run writes, and when (doc/DESIGN.md "Output schedule"): the records of series.h5, whose
! columns each physics module names (mod_columns), the statistics' share of each record, the
! progress line, field and particle snapshots, checkpoints, at the end the last of each and the
! summary of the statistics, and on a failure failed_state.h5 beside the last good checkpoint. One
! run_output_t, opened once by the program over the pieces the run has; the loop calls
! run_output_step after each step and run_output_close at its end. Each call is collective.
#include <petsc/finclude/petscsys.h>
module mod_run_output
  use petscsys
  use mod_kinds, only: dp
  use mod_params, only: config_t, max_line
  use mod_errors, only: log_line, is_root, abort_run, fatal_error
  use mod_file_services, only: write_failure_cause
  use mod_timers, only: stage_push, stage_pop, STAGE_OUTPUT
  use mod_grid, only: grid_t
  use mod_fluid, only: fluid_t, fluid_columns
  use mod_fluid_verification, only: fluid_errors_vs_manufactured
  use mod_series, only: series_t, series_column, series_add, series_open, series_record, series_flush, &
                        series_close, series_attributes
  use mod_output, only: write_fields, progress_line
  use mod_checkpoint, only: checkpoint_state_t, checkpoint_write
  use mod_particles, only: particles_t, sphere_share_t, particles_columns
  use mod_particles_io, only: particles_snapshot, owned_spheres
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_columns
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_columns
  use mod_rheology, only: rheology_t, rheo_accumulate, rheo_summarise, rheo_columns, summary_names, NSUMMARY, &
                          species_summary_t, rheo_summarise_species
  use mod_summary_io, only: summary_write
  use mod_lees_edwards, only: lees_edwards_t, le_columns
  use mod_shear_protocol, only: shear_protocol_columns, shear_protocol_varies
  implicit none
  private
  public :: run_output_t, run_output_open, run_output_step, run_output_checkpoint, run_output_fail, run_output_close

  type :: run_output_t
    type(config_t) :: cfg
    type(series_t) :: series
    type(checkpoint_state_t) :: state                 ! what checkpoints and failed_state.h5 hold
    character(len=max_line) :: checkpoint_path = ''
    real(dp) :: wall_start = 0.0_dp                   ! MPI_Wtime at the program's start
    integer :: first_step = 0                         ! the step this run started from
    logical :: restarted = .false.                    ! from a checkpoint
    ! the pieces whose columns and snapshots are written (associated when the run has them)
    type(grid_t), pointer :: grid => null()
    type(fluid_t), pointer :: fluid => null()
    type(lees_edwards_t), pointer :: le => null()
    type(particles_t), pointer :: parts => null()
    type(particle_contacts_t), pointer :: contacts => null()
    type(particle_lubrication_t), pointer :: lubrication => null()
    type(rheology_t), pointer :: rheology => null()
  end type run_output_t

contains

  ! Open the output of a run at step (restarting: from a checkpoint, whose series records up to
  ! step are kept; else from the start, an empty series). state: what the checkpoints hold; the
  ! pieces, as in mod_time_step: a fluid (grid, fluid), the Lees-Edwards boundaries (le, when
  ! active), particles (parts, when the run has any) with their contacts, lubrication and
  ! statistics.
  subroutine run_output_open(out, cfg, state, step, restarting, wall_start, grid, fluid, le, parts, contacts, &
                             lubrication, rheology)
    type(run_output_t), intent(out) :: out
    type(config_t), intent(in) :: cfg
    type(checkpoint_state_t), intent(in) :: state
    integer, intent(in) :: step
    logical, intent(in) :: restarting
    real(dp), intent(in) :: wall_start
    type(grid_t), target, intent(in), optional :: grid
    type(fluid_t), target, intent(in), optional :: fluid
    type(lees_edwards_t), target, intent(in), optional :: le
    type(particles_t), target, intent(in), optional :: parts
    type(particle_contacts_t), target, intent(in), optional :: contacts
    type(particle_lubrication_t), target, intent(in), optional :: lubrication
    type(rheology_t), target, intent(in), optional :: rheology
    real(dp) :: friction, roughness
    character(len=32), allocatable :: names(:)
    real(dp), allocatable :: values(:)
    integer :: k
    out%cfg = cfg
    out%state = state
    out%checkpoint_path = trim(cfg%output%directory)//'/checkpoint.h5'
    out%wall_start = wall_start
    out%first_step = step
    out%restarted = restarting
    if (present(grid)) out%grid => grid
    if (present(fluid)) out%fluid => fluid
    if (present(le)) out%le => le
    if (present(parts)) out%parts => parts
    if (present(contacts)) out%contacts => contacts
    if (present(lubrication)) out%lubrication => lubrication
    if (present(rheology)) out%rheology => rheology
    ! the columns are declared by the routine that also fills each record
    call series_columns(out, step, 0.0_dp)
    if (associated(out%rheology)) then
      ! what scripts/rheology.py needs to repeat the statistics from series.h5 alone
      friction = 0.0_dp
      roughness = 0.0_dp
      if (associated(out%contacts)) then
        friction = cfg%contact%friction
        roughness = cfg%contact%roughness
      end if
      names = [character(len=32) :: 'box_x', 'box_y', 'box_z', 'radius', 'shear_rate', &
           'dt', 'core_lo', 'core_hi', 'pair_radius', 'contact_radius', 'blocks', 'discard_step', 'block_steps', &
           'series_every', 'friction', 'roughness']
      values = [cfg%domain%box, cfg%radius, cfg%domain%shear_rate, &
           cfg%time%dt, out%rheology%core, out%rheology%r_outer, out%rheology%r_contact, &
           real([cfg%rheology%blocks, cfg%discard_step, cfg%block_steps, cfg%output%series_every], dp), &
           friction, roughness]
      if (out%rheology%nspecies > 1) then
        ! a mixture's species (radius [a] and number of spheres) and the bins of g_ab(r)
        ! (doc/RHEOLOGY.md "Per species"); equal spheres have none of these
        names = [names, [character(len=32) :: 'species', 'radial_width']]
        values = [values, real(out%rheology%nspecies, dp), out%rheology%radial_width / out%rheology%radius]
        do k = 1, out%rheology%nspecies
          names = [names, [character(len=32) :: species_attribute('species_radius_', k), &
                                                species_attribute('species_count_', k)]]
          values = [values, out%rheology%species_radius(k) / out%rheology%radius, out%rheology%species_count(k)]
        end do
      end if
    end if
    ! a rate that varies: the protocol, for the analysis of fdsusp.protocols (doc/RHEOLOGY.md "Protocols")
    if (associated(out%state%protocol)) then
      if (shear_protocol_varies(out%state%protocol)) then
        if (.not. allocated(names)) allocate(names(0), values(0))
        names = [names, [character(len=32) :: 'shear_protocol', 'shear_reference_rate', 'shear_reversal_strain', &
                         'shear_strain_amplitude', 'shear_period', 'shear_dt', 'shear_control', 'shear_stress']]
        ! shear_control: 1 rate, 2 stress (mod_shear_protocol CONTROL_*); shear_stress: the target
        values = [values, real(out%state%protocol%kind, dp), out%state%protocol%reference_rate, &
                  out%state%protocol%reversal_strain, out%state%protocol%strain_amplitude, out%state%protocol%period, &
                  cfg%time%dt, real(out%state%protocol%control, dp), out%state%protocol%stress]
      end if
    end if
    if (allocated(names)) call series_attributes(out%series, names, values)
    ! from the start: an empty series; from a checkpoint: its records up to the checkpoint's step
    call series_open(out%series, cfg%output%directory, merge(step, -1, restarting), &
                     (cfg%time%steps - step) / cfg%output%series_every)
  end subroutine run_output_open

  ! name_k, the attribute of species k
  pure function species_attribute(name, k) result(s)
    character(len=*), intent(in) :: name
    integer, intent(in) :: k
    character(len=32) :: s
    write(s, '(a,i0)') name, k
  end function species_attribute

  ! The output of step (time), on the deck's &output cadences. share: this rank's share of the
  ! spheres (the local set of lubrication dynamics on several ranks, mod_ld_local), the state of the
  ! step, which the series record, the snapshot and the checkpoint then take instead of the
  ! replicated particles (and the contacts and the links are set for it).
  subroutine run_output_step(out, step, time, ierr, share)
    type(run_output_t), intent(inout) :: out
    integer, intent(in) :: step
    real(dp), intent(in) :: time
    PetscErrorCode, intent(out) :: ierr
    type(sphere_share_t), intent(in), optional :: share
    real(dp) :: wall_now, wall_per_step
    ierr = 0
    associate(schedule => out%cfg%output)
      PetscCall(stage_push(STAGE_OUTPUT, ierr))
      wall_now = MPI_Wtime() - out%wall_start
      if (mod(step, schedule%series_every) == 0) call record(out, step, time, share)
      if (mod(step, schedule%progress_every) == 0) then
        wall_per_step = wall_now / (step - out%first_step)
        if (associated(out%fluid)) then
          call progress_line(step, out%cfg%time%steps, time, wall_now, wall_per_step, out%fluid)
        else
          call progress_line(step, out%cfg%time%steps, time, wall_now, wall_per_step)
        end if
        call series_flush(out%series, progress=.true.)
      end if
      if (schedule%fields_every > 0 .and. associated(out%fluid)) then
        if (mod(step, schedule%fields_every) == 0) then
          PetscCall(write_fields(schedule%directory, out%grid, out%fluid, step, time, ierr))
        end if
      end if
      if (schedule%particles_every > 0 .and. associated(out%parts)) then
        if (mod(step, schedule%particles_every) == 0) call snapshot(out, step, time, share)
      end if
      if (schedule%checkpoint_every > 0) then
        if (mod(step, schedule%checkpoint_every) == 0) then
          PetscCall(run_output_checkpoint(out, step, time, ierr, share))
        end if
      end if
      PetscCall(stage_pop(ierr))
    end associate
  end subroutine run_output_step

  ! A particle snapshot of step (time): of the replicated particles, or of the ranks' shares.
  subroutine snapshot(out, step, time, share)
    type(run_output_t), intent(inout) :: out
    integer, intent(in) :: step
    real(dp), intent(in) :: time
    type(sphere_share_t), intent(in), optional :: share
    if (present(share)) then
      call particles_snapshot(out%cfg%output%directory, out%parts, out%cfg%domain%box, step, time, [integer ::], share)
    else
      call particles_snapshot(out%cfg%output%directory, out%parts, out%cfg%domain%box, step, time, &
                              owned_spheres(out%state%owned_spheres, out%parts, out%cfg%domain%box))
    end if
  end subroutine snapshot

  ! checkpoint.h5 at step (time), the series flushed first so that it holds every record up to it.
  subroutine run_output_checkpoint(out, step, time, ierr, share)
    type(run_output_t), intent(inout) :: out
    integer, intent(in) :: step
    real(dp), intent(in) :: time
    PetscErrorCode, intent(out) :: ierr
    type(sphere_share_t), intent(in), optional :: share
    call series_flush(out%series)
    PetscCall(checkpoint_write(out%checkpoint_path, out%cfg, out%state, step, time, ierr, share))
  end subroutine run_output_checkpoint

  ! The end of a run at step (time): the last record, the series closed, and when steps were taken
  ! the last fields, particles and a checkpoint to continue from; then the statistics' summary.
  ! A run restarted at its last step (a batch chain's job after a kill between the last checkpoint
  ! and the end of the last outputs) writes the last fields and particles again: the killed run may
  ! not have published them (the checkpoint it restarts from already is the last one).
  subroutine run_output_close(out, step, time, ierr, share)
    type(run_output_t), intent(inout) :: out
    integer, intent(in) :: step
    real(dp), intent(in) :: time
    PetscErrorCode, intent(out) :: ierr
    type(sphere_share_t), intent(in), optional :: share
    ierr = 0
    PetscCall(stage_push(STAGE_OUTPUT, ierr))
    if (step > out%first_step .and. mod(step, out%cfg%output%series_every) /= 0) call record(out, step, time, share)
    call series_close(out%series)
    if (step > out%first_step .or. out%restarted) then
      if (associated(out%fluid)) then
        PetscCall(write_fields(out%cfg%output%directory, out%grid, out%fluid, step, time, ierr))
      end if
      if (associated(out%parts)) call snapshot(out, step, time, share)
    end if
    if (step > out%first_step) then
      PetscCall(run_output_checkpoint(out, step, time, ierr, share))
    end if
    if (associated(out%rheology)) call summary(out, step)
    PetscCall(stage_pop(ierr))
  end subroutine run_output_close

  ! Stop a run that went wrong at at_step: the series so far, the state of step (time) in
  ! failed_state.h5 beside the last good checkpoint (never over it), one message naming the step
  ! and what went wrong, status 5. share: this rank's share of the spheres (absent: the replicated
  ! particles).
  subroutine run_output_fail(out, step, time, at_step, what, share)
    type(run_output_t), intent(inout) :: out
    integer, intent(in) :: step, at_step
    real(dp), intent(in) :: time
    character(len=*), intent(in) :: what
    type(sphere_share_t), intent(in), optional :: share
    PetscErrorCode :: ierr
    character(len=:), allocatable :: path
    character(len=16) :: number
    path = trim(out%cfg%output%directory)//'/failed_state.h5'
    call series_close(out%series)
    PetscCallA(checkpoint_write(path, out%cfg, out%state, step, time, ierr, share))
    write(number, '(i0)') at_step
    call fatal_error('fdsusp: fatal: at step '//trim(number)//': '//trim(what)//'; state written to '//path// &
                     ', the last good checkpoint is kept', 5)
  end subroutine run_output_fail

  ! One record of series.h5, and the statistics' share of it: only the records on the series_every
  ! grid enter the statistics (a restart then adds exactly the records an uninterrupted run would).
  subroutine record(out, step, time, share)
    type(run_output_t), intent(inout) :: out
    integer, intent(in) :: step
    real(dp), intent(in) :: time
    type(sphere_share_t), intent(in), optional :: share
    call series_columns(out, step, time, share)
    call series_record(out%series)
    if (associated(out%parts) .and. associated(out%rheology)) then
      if (mod(step, out%cfg%output%series_every) == 0) call rheo_accumulate(out%rheology, step)
    end if
  end subroutine record

  ! The columns of series.h5 in the file's order: the name and the value of each (the value's shape
  ! is the column's). Called once before series_open, which makes these calls the declaration of
  ! the columns, then for every record, so the header and the records cannot differ.
  subroutine series_columns(out, step, time, share)
    type(run_output_t), intent(inout) :: out
    integer, intent(in) :: step
    real(dp), intent(in) :: time
    type(sphere_share_t), intent(in), optional :: share
    real(dp) :: err_vel, err_p_max, err_p_rms
    integer, allocatable :: owned(:), rows(:)
    integer :: q
    PetscErrorCode :: ierr
    call series_column(out%series, 'step', step)
    call series_column(out%series, 'time', time)
    call series_column(out%series, 'wall_time', MPI_Wtime() - out%wall_start)
    ! each physics module names its columns (mod_columns); the manufactured solution's errors are
    ! the verification's
    if (associated(out%fluid)) call series_add(out%series, fluid_columns(out%fluid))
    if (associated(out%le)) call series_add(out%series, le_columns(out%le))
    ! the imposed shear of the record's step (mod_shear_protocol), when the flow is sheared
    if (associated(out%state%protocol) .and. (out%cfg%walls .or. out%cfg%lees_edwards)) &
      call series_add(out%series, shear_protocol_columns(out%state%protocol))
    if (out%cfg%verification%manufactured_solution) then
      PetscCallA(fluid_errors_vs_manufactured(out%grid, out%fluid, out%cfg%domain%shear_rate, err_vel, err_p_max, err_p_rms, ierr))
      call series_column(out%series, 'mms_error_velocity_max', err_vel)
      call series_column(out%series, 'mms_error_pressure_max', err_p_max)
      call series_column(out%series, 'mms_error_pressure_rms', err_p_rms)
    end if
    if (.not. associated(out%parts)) return
    ! the per-sphere columns: each rank gives the rows of the spheres it owns (as for the particle
    ! files), the series writes them collectively (mod_series); from a local set, its own spheres
    ! with their global indices
    if (present(share)) then
      owned = pack([(q, q = 1, share%set%n)], share%own)
      rows = share%id(owned)
      call series_add(out%series, particles_columns(share%set, owned, rows, share%total))
      if (associated(out%lubrication)) call series_add(out%series, &
        particle_lubrication_columns(out%lubrication, owned, rows, share%total))
      if (associated(out%contacts)) call series_add(out%series, &
        particle_contacts_columns(out%contacts, owned, rows, share%total))
    else
      owned = owned_spheres(out%state%owned_spheres, out%parts, out%cfg%domain%box)
      call series_add(out%series, particles_columns(out%parts, owned))
      if (associated(out%lubrication)) call series_add(out%series, particle_lubrication_columns(out%lubrication, owned))
      if (associated(out%contacts)) call series_add(out%series, particle_contacts_columns(out%contacts, owned))
    end if
    if (associated(out%rheology)) then
      call series_add(out%series, rheo_columns(out%rheology))
      if (associated(out%contacts)) call series_column(out%series, 'contact_overlap_over_roughness', &
           out%contacts%max_overlap / max(out%contacts%params%h_r, tiny(1.0_dp)))
    end if
  end subroutine series_columns

  ! summary.json (rank 0) and the rheology in the run log: value +- standard error over the blocks.
  subroutine summary(out, step)
    type(run_output_t), intent(inout) :: out
    integer, intent(in) :: step
    integer :: err, k, q, complete
    real(dp) :: value(NSUMMARY), error(NSUMMARY)
    real(dp), allocatable :: profile(:, :), angles(:, :)
    type(species_summary_t) :: species
    character(len=1100) :: path
    character(len=200) :: text
    character(len=20), parameter :: shown(14) = [character(len=20) :: 'eta_r', 'eta_h', 'eta_c', 'N1/tau', &
         'N2/tau', 'Pi/tau', 'lambda_2', 'lambda_3', 'eta_n', 'I_v', 'mu', 'phi_core', 'gamma_dot_core', 'tau']
    if (.not. is_root()) return
    path = trim(out%cfg%output%directory)//'/summary.json'
    call rheo_summarise(out%rheology, step, complete, value, error, profile, angles)
    if (out%rheology%nspecies > 1) then
      call rheo_summarise_species(out%rheology, step, species)
      call summary_write(out%rheology, path, step, complete, value, error, profile, angles, err, species)
    else
      call summary_write(out%rheology, path, step, complete, value, error, profile, angles, err)
    end if
    if (err /= 0) call abort_run(trim(path)//' cannot be written: '// &
                                 write_failure_cause(out%cfg%output%directory, 0.0_dp))
    write(text, '(a,i0,a,i0,a)') 'rheology of the core region (', complete, ' of ', out%cfg%rheology%blocks, &
         ' blocks complete; value +- standard error; doc/RHEOLOGY.md):'
    call log_line(text)
    if (out%rheology%raw_stress) call log_line('  (a rate that varies: stresses over eta*|reference rate|, not over '// &
         'the measured rate; doc/RHEOLOGY.md "Protocols")')
    do k = 1, size(shown)
      q = findloc(summary_names, shown(k), 1)
      write(text, '(2x,a16,es13.5,a,es10.3)') shown(k), value(q), ' +- ', error(q)
      call log_line(text)
    end do
    call log_line('summary written to '//trim(path))
  end subroutine summary

end module mod_run_output
