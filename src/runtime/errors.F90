! Error reporting shared by every module that talks to the user.
! Input errors are raised collectively (every rank reads and validates the same deck), so the run
! stops cleanly on all ranks with one message printed by rank 0. Runtime faults detected on one
! rank only abort the MPI job.
#include <petsc/finclude/petscsys.h>
module mod_errors
  use petscsys
  use mod_os_services, only: release_directory
  use mod_limits, only: limit_finding_t, LIMIT_REFUSE
  implicit none
  private
  public :: input_error, file_error, file_error_from_root, fatal_error, abort_run, abort_if_any, is_root, log_line, &
            warn_line, report_limits

contains

  logical function is_root()
    PetscMPIInt :: rank
    PetscErrorCode :: ierr
    call MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr)
    is_root = (rank == 0)
  end function is_root

  ! One line on the run log (rank 0 only).
  subroutine log_line(text)
    character(len=*), intent(in) :: text
    if (is_root()) then
      write(*, '(a)') trim(text)
      flush(6)
    end if
  end subroutine log_line

  subroutine warn_line(text)
    character(len=*), intent(in) :: text
    if (is_root()) then
      write(0, '(a)') 'fdsusp: warning: '//trim(text)
      flush(0)
    end if
  end subroutine warn_line

  ! Bad input: one message naming the file, the group and the variable. Collective.
  subroutine input_error(file, group, variable, message)
    character(len=*), intent(in) :: file, group, variable, message
    character(len=:), allocatable :: where
    where = 'fdsusp: input error: '//trim(file)
    if (len_trim(group) > 0) where = where//', group &'//trim(group)
    if (len_trim(variable) > 0) where = where//', variable '//trim(variable)
    call fatal_error(where//': '//trim(message), 2)
  end subroutine input_error

  ! The findings of a limit check (mod_limits) on the deck FILE, in their order: warnings, and the
  ! refusal of the deck item named, which stops the run. Collective: every rank finds the same.
  subroutine report_limits(file, findings)
    character(len=*), intent(in) :: file
    type(limit_finding_t), intent(in) :: findings(:)
    integer :: k
    do k = 1, size(findings)
      if (findings(k)%level == LIMIT_REFUSE) then
        call input_error(file, trim(findings(k)%group), trim(findings(k)%key), trim(findings(k)%text))
      else
        call warn_line(findings(k)%text)
      end if
    end do
  end subroutine report_limits

  ! A file the run reads (checkpoint, particle file, table) is unusable. Collective.
  subroutine file_error(file, item, message)
    character(len=*), intent(in) :: file, item, message
    character(len=:), allocatable :: where
    where = 'fdsusp: input error: '//trim(file)
    if (len_trim(item) > 0) where = where//', item '//trim(item)
    call fatal_error(where//': '//trim(message), 2)
  end subroutine file_error

  ! A fault in a file that rank 0 alone read (message: empty when the file is sound): every rank
  ! learns rank 0's verdict, and a fault stops the run on all of them (file_error). Collective.
  subroutine file_error_from_root(file, item, message)
    character(len=*), intent(in) :: file, item
    character(len=*), intent(inout) :: message
    PetscErrorCode :: ierr
    call MPI_Bcast(message, len(message), MPI_CHARACTER, 0, PETSC_COMM_WORLD, ierr)
    if (len_trim(message) > 0) call file_error(file, item, message)
  end subroutine file_error_from_root

  ! A collective fatal error: every rank calls it. Rank 0 prints and releases the output
  ! directory (mod_os_services; a no-op before it is locked); all ranks finalise and exit.
  subroutine fatal_error(message, status)
    character(len=*), intent(in) :: message
    integer, intent(in) :: status
    PetscErrorCode :: ierr
    if (is_root()) then
      write(0, '(a)') trim(message)
      flush(0)
    end if
    call release_directory()
    call PetscFinalize(ierr)
    call exit(status)
  end subroutine fatal_error

  ! A fault that may be seen by some ranks only, after a collective operation (a parallel write):
  ! when any rank saw it, rank 0 prints the message and every rank aborts the job (status 3).
  ! Collective.
  subroutine abort_if_any(failed, message)
    logical, intent(in) :: failed
    character(len=*), intent(in) :: message
    logical :: any_failed
    PetscErrorCode :: ierr
    call MPI_Allreduce(failed, any_failed, 1, MPI_LOGICAL, MPI_LOR, PETSC_COMM_WORLD, ierr)
    if (.not. any_failed) return
    if (is_root()) then
      write(0, '(a)') 'fdsusp: fatal: '//trim(message)
      flush(0)
    end if
    call MPI_Abort(PETSC_COMM_WORLD, 3, ierr)
  end subroutine abort_if_any

  ! A fault seen by one rank only: print it and abort the whole job.
  subroutine abort_run(message)
    character(len=*), intent(in) :: message
    PetscErrorCode :: ierr
    write(0, '(a)') 'fdsusp: fatal: '//trim(message)
    flush(0)
    call MPI_Abort(PETSC_COMM_WORLD, 3, ierr)
  end subroutine abort_run

end module mod_errors
