! The lubrication links of a step shared out over the ranks (doc/DESIGN.md "Parallelism"). Each
! rank owns the block rows of a contiguous range of spheres in the 6N particle system
! (mod_particle_solver's split) and evaluates the links with a sphere in its range, in the order
! of all candidates; a link whose spheres two ranks own is evaluated on both. Each rank then holds
! every link of its own spheres, in the order one rank alone would have them: its block rows and
! right-hand side come out complete and bitwise those of one rank, nothing crosses ranks in the
! assembly, and no rank holds the links of the whole system (before 2026-11-28 every link, ~1.5
! kB, was gathered on every rank each step). Sending the blocks of the other ranks' rows through
! PETSc's off-process stash instead would evaluate each link once, but would split the system
! into replicated and local parts and sum the rows in another order; with spheres owned by their
! subdomain (doc/SCALING.md §3) the links evaluated twice are only those across its faces.
! The per-sphere sums of the links (force, torque, stresslet: 15 doubles, 120 B a sphere, against
! 8.1 kB of links a sphere) are gathered from their owners, bitwise those of one rank.
#include <petsc/finclude/petscsys.h>
module mod_lubrication_links
  use petscsys
  use mod_kinds, only: dp
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_links, &
                                      particle_lubrication_corrections
  use mod_particle_solver, only: particle_solver_split
  implicit none
  private
  public :: lubrication_links_evaluate, lubrication_links_corrections

contains

  !> The links at positions x (3, np) of this rank's spheres (all on one rank), and, on every
  !> rank, the smallest gap, a failed link and the count of pair links of the whole system
  !> (pl%min_gap, failed_link, npairs_total, npairs_most). Collective. offset (optional): the
  !> Lees-Edwards offset of this configuration (lubrication dynamics with sliding boundaries).
  subroutine lubrication_links_evaluate(pl, x, ierr, offset)
    type(particle_lubrication_t), intent(inout) :: pl
    real(dp), intent(in) :: x(:, :)
    PetscErrorCode, intent(out) :: ierr
    real(dp), intent(in), optional :: offset
    PetscMPIInt :: rank, ranks
    integer, allocatable :: counts(:), displs(:)
    integer :: lo, hi, most(3)

    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr))
    PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr))
    if (ranks == 1) then
      call particle_lubrication_links(pl, x, offset=offset)
      return
    end if
    call particle_solver_split(pl%np, ranks, counts, displs)
    lo = displs(rank + 1) + 1
    hi = displs(rank + 1) + counts(rank + 1)
    call particle_lubrication_links(pl, x, [lo, hi], offset)
    ! each link counted by the owner of its first sphere
    pl%npairs_total = count(pl%pair(1, 1:pl%npairs) >= lo .and. pl%pair(1, 1:pl%npairs) <= hi)
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, pl%npairs_total, 1, MPI_INTEGER, MPI_SUM, PETSC_COMM_WORLD, ierr))
    ! the smallest gap of all shares (the walls are the same on every rank); a failed link of any
    ! share (the largest particle index that failed, so that every rank names the same one), and
    ! the most links a rank holds, in one reduction
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, pl%min_gap, 1, MPI_DOUBLE_PRECISION, MPI_MIN, PETSC_COMM_WORLD, ierr))
    most = [pl%failed_link, pl%npairs]
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, most, 3, MPI_INTEGER, MPI_MAX, PETSC_COMM_WORLD, ierr))
    pl%failed_link = most(1:2)
    pl%npairs_most = most(3)
  end subroutine lubrication_links_evaluate

  !> The links' corrections with the velocities u, om (3, np) of every sphere
  !> (particle_lubrication_corrections): each rank sums those of its own spheres, whose links it
  !> holds, and the sums are gathered, so every rank has pl%force, torque, stresslet of every
  !> sphere. Collective.
  subroutine lubrication_links_corrections(pl, u, om, ierr)
    type(particle_lubrication_t), intent(inout) :: pl
    real(dp), intent(in) :: u(:, :), om(:, :)
    PetscErrorCode, intent(out) :: ierr
    PetscMPIInt :: ranks
    integer, allocatable :: counts(:), displs(:)
    real(dp), allocatable :: sums(:, :)

    call particle_lubrication_corrections(pl, u, om)
    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr))
    if (ranks == 1) return
    call particle_solver_split(pl%np, ranks, counts, displs)
    allocate(sums(15, pl%np))
    sums(1:3, :) = pl%force
    sums(4:6, :) = pl%torque
    sums(7:15, :) = reshape(pl%stresslet, [9, pl%np])
    PetscCallMPI(MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, sums, 15 * counts, 15 * displs, MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, ierr))
    pl%force = sums(1:3, :)
    pl%torque = sums(4:6, :)
    pl%stresslet = reshape(sums(7:15, :), [3, 3, pl%np])
  end subroutine lubrication_links_corrections

end module mod_lubrication_links
