! What the unit tests on PETSc share at their start (tests/unit_petsc): PETSc and HDF5 initialised,
! the output of every rank but 0 silenced (the verdicts are printed once), and a scratch directory
! of this run (under TMPDIR, else /tmp), made by rank 0 and named alike on every rank (rank 0's pid).
#include <petsc/finclude/petscsys.h>
module mod_unit_start
  use, intrinsic :: iso_fortran_env, only: output_unit
  use petscsys
  use mod_h5util, only: h5util_init
  use mod_os_services, only: make_directory
  implicit none
  private
  public :: unit_start

contains

  !> Start the test NAME: rank and ranks of PETSC_COMM_WORLD, and dir, its scratch directory
  !> (TMPDIR/fdsusp-NAME-PID), which exists on return. Collective.
  subroutine unit_start(name, rank, ranks, dir)
    character(len=*), intent(in) :: name
    PetscMPIInt, intent(out) :: rank, ranks
    character(len=*), intent(out) :: dir
    PetscErrorCode :: ierr
    character(len=512) :: tmpdir
    integer :: status, pid(1)
    PetscCallA(PetscInitialize(ierr))
    call MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr)
    call MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr)
    if (rank /= 0) open(unit=output_unit, file='/dev/null')
    call h5util_init()
    call get_environment_variable('TMPDIR', tmpdir, status=status)
    if (status /= 0 .or. len_trim(tmpdir) == 0) tmpdir = '/tmp'
    pid = getpid()
    call MPI_Bcast(pid, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
    write(dir, '(a,i0)') trim(tmpdir)//'/fdsusp-'//name//'-', pid(1)
    if (rank == 0) then
      status = make_directory(dir)
      if (status /= 0) error stop 'cannot create the temporary directory of the test'
    end if
    call MPI_Barrier(PETSC_COMM_WORLD, ierr)
  end subroutine unit_start

end module mod_unit_start
