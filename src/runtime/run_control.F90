! The run as a batch job sees it (doc/DESIGN.md "Files, restart and signals"): the command line,
! the output directory (created, locked, probed), where a -continue starts from, and when the run
! stops: its last step, a signal (SIGTERM or SIGUSR1, what batch schedulers send before the kill),
! &run max_wall_hours, or a steady flow. Each call is collective: every rank takes the same
! decision.
#include <petsc/finclude/petscsys.h>
module mod_run_control
  use petscsys
  use mod_kinds, only: dp
  use mod_params, only: config_t
  use mod_errors, only: log_line, warn_line, input_error, fatal_error, is_root
  use mod_os_services, only: stop_signal, make_directory, probe_directory, lock_directory
  implicit none
  private
  public :: command_line, prepare_output_directory, continue_from_directory, run_stop_reason, run_stop_line, &
            run_signal_line
  integer, parameter, public :: RUN_GOES_ON = 0, RUN_DONE = 1, RUN_SIGNALLED = 2, RUN_WALL_LIMIT = 3, RUN_STEADY = 4

contains

  ! DECK is the first argument; -restart FILE, -branch FILE and -continue are read from PETSc's
  ! options database. -continue: restart from the deck's output directory's checkpoint.h5 when
  ! there is one, else start (what each job of a batch chain runs, scripts/slurm/). -branch: start
  ! from the checkpoint's state with this deck's contact and lubrication models and loads, which a
  ! restart must keep (doc/INPUT.md "Restart"): the cases of a study that share their past.
  subroutine command_line(deck, restart, restarting, continuing, branching)
    character(len=*), intent(out) :: deck, restart
    logical, intent(out) :: restarting, continuing, branching
    character(len=len(restart)) :: branch_from
    PetscBool :: set
    PetscErrorCode :: ierr
    call get_command_argument(1, deck)
    if (len_trim(deck) == 0 .or. deck(1:1) == '-') &
      call fatal_error('usage: fdsusp DECK [-restart CHECKPOINT | -branch CHECKPOINT | -continue] [PETSc options]', 2)
    restart = ''
    PetscCallA(PetscOptionsGetString(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-restart', restart, set, ierr))
    restarting = logical(set)
    if (restarting .and. len_trim(restart) == 0) &
      call fatal_error('fdsusp: -restart needs the path of a checkpoint', 2)
    branch_from = ''
    PetscCallA(PetscOptionsGetString(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-branch', branch_from, set, ierr))
    branching = logical(set)
    if (branching .and. len_trim(branch_from) == 0) &
      call fatal_error('fdsusp: -branch needs the path of a checkpoint', 2)
    PetscCallA(PetscOptionsHasName(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-continue', set, ierr))
    continuing = logical(set)
    if (count([restarting, continuing, branching]) > 1) &
      call fatal_error('fdsusp: -restart, -branch and -continue exclude each other (-continue restarts from the '// &
                       'output directory''s checkpoint.h5)', 2)
    if (branching) then
      restart = branch_from
      restarting = .true.
    end if
  end subroutine command_line

  ! -continue: the output directory's checkpoint.h5 if it exists (looked for under the directory's
  ! lock, so no other run is writing it), else a start from the beginning.
  subroutine continue_from_directory(cfg, restart, restarting)
    type(config_t), intent(in) :: cfg
    character(len=*), intent(out) :: restart
    logical, intent(out) :: restarting
    PetscErrorCode :: ierr
    integer :: found
    found = 0
    if (is_root()) then
      inquire(file=trim(cfg%output%directory)//'/checkpoint.h5', exist=restarting)
      found = merge(1, 0, restarting)
    end if
    call MPI_Bcast(found, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
    restarting = found == 1
    restart = ''
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
    PetscErrorCode :: ierr
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

  ! Whether the run stops after step (RUN_GOES_ON or why it stops), it having started at
  ! first_step, wall_start = MPI_Wtime at the program's start; steady: the flow has reached &time
  ! steady_tolerance. A signal wins over the wall limit, the wall limit over a steady flow, each
  ! over the last step.
  integer function run_stop_reason(cfg, step, first_step, wall_start, steady) result(reason)
    type(config_t), intent(in) :: cfg
    integer, intent(in) :: step, first_step
    real(dp), intent(in) :: wall_start
    logical, intent(in) :: steady
    integer :: flags(3), all_flags(3)
    PetscErrorCode :: ierr
    real(dp) :: elapsed, per_step
    flags = 0
    if (stop_signal() /= 0) flags(1) = 1
    if (cfg%run%max_wall_hours > 0.0_dp) then
      elapsed = MPI_Wtime() - wall_start
      per_step = elapsed / max(1, step - first_step)
      ! leave room for two more steps and the final output
      if (elapsed + 3.0_dp * per_step > 3600.0_dp * cfg%run%max_wall_hours) flags(2) = 1
    end if
    if (steady) flags(3) = 1
    call MPI_Allreduce(flags, all_flags, 3, MPI_INTEGER, MPI_MAX, PETSC_COMM_WORLD, ierr)
    reason = RUN_GOES_ON
    if (step >= cfg%time%steps) reason = RUN_DONE
    if (all_flags(3) == 1) reason = RUN_STEADY
    if (all_flags(2) == 1) reason = RUN_WALL_LIMIT
    if (all_flags(1) == 1) reason = RUN_SIGNALLED
  end function run_stop_reason

  ! What the run does on a signal, said before it writes the checkpoint (a SIGKILL that follows the
  ! signal may end the run before its last word; the log then still tells where the checkpoint
  ! came from); '' for any other reason to stop.
  function run_signal_line(reason, step) result(text)
    integer, intent(in) :: reason, step
    character(len=200) :: text
    text = ''
    if (reason == RUN_SIGNALLED) write(text, '(a,i0,a,i0,a)') 'signal ', stop_signal(), ' at step ', step, &
                                                              ': writing the checkpoint'
  end function run_signal_line

  ! The run log's last word on why the run stopped at step (max_rate: the flow's max|du/dt| when
  ! it stopped steady).
  function run_stop_line(cfg, reason, step, max_rate) result(text)
    type(config_t), intent(in) :: cfg
    integer, intent(in) :: reason, step
    real(dp), intent(in) :: max_rate
    character(len=400) :: text
    character(len=:), allocatable :: checkpoint
    checkpoint = trim(cfg%output%directory)//'/checkpoint.h5'
    select case (reason)
    case (RUN_SIGNALLED)
      write(text, '(a,i0,a,i0,a)') 'stopped by signal ', stop_signal(), ' at step ', step, &
           ': checkpoint written to '//checkpoint
    case (RUN_WALL_LIMIT)
      write(text, '(a,i0,a)') 'stopped at step ', step, ' before &run max_wall_hours: checkpoint written to '// &
           checkpoint
    case (RUN_STEADY)
      write(text, '(a,i0,a,es10.3)') 'steady state at step ', step, ': max|du/dt| = ', max_rate
    case default
      write(text, '(a,i0)') 'finished at step ', step
    end select
  end function run_stop_line

end module mod_run_control
