! The lubrication links of a step shared out over the ranks (doc/DESIGN.md "Parallelism"). Each
! rank owns the block rows of the spheres in its z-slab in the 6N particle system
! (mod_sphere_ownership, set here from the positions of the links) and evaluates the links with a
! sphere it owns, in the order of all candidates; a link across a slab face is evaluated by both
! ranks. Each rank then holds every link of its own spheres, in the order one rank alone would have
! them: its block rows and right-hand side come out complete and bitwise those of one rank, nothing
! crosses ranks in the assembly, and no rank holds the links of the whole system (before
! 2026-11-28 every link, ~1.5 kB, was gathered on every rank each step; until 2026-11-29 the ranks
! owned ranges of sphere indices, so almost every link crossed two ranks). Sending the blocks of
! the other ranks' rows through PETSc's off-process stash instead would evaluate each link once,
! but would split the system into replicated and local parts and sum the rows in another order.
! The per-sphere sums of the links (force, torque, stresslet: 15 doubles, 120 B a sphere, against
! 8.1 kB of links a sphere) are gathered from their owners, bitwise those of one rank.
#include <petsc/finclude/petscsys.h>
module mod_lubrication_links
  use petscsys
  use mod_kinds, only: dp
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_links, &
                                      particle_lubrication_corrections
  use mod_sphere_ownership, only: sphere_ownership_t, sphere_ownership_set, sphere_ownership_of
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
    type(sphere_ownership_t) :: o
    integer :: most(3)

    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr))
    PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr))
    if (ranks == 1) then
      call particle_lubrication_links(pl, x, offset=offset)
      return
    end if
    ! the step's ownership, from these positions: the particle solve and the links' sums use it
    call sphere_ownership_set(x, pl%box(3))
    o = sphere_ownership_of(pl%np)
    call particle_lubrication_links(pl, x, o%owner == rank, offset)
    ! each link counted by the owner of its first sphere
    pl%npairs_total = count(o%owner(pl%pair(1, 1:pl%npairs)) == rank)
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
    PetscMPIInt :: rank, ranks
    type(sphere_ownership_t) :: o
    real(dp), allocatable :: sums(:, :)
    integer :: k

    call particle_lubrication_corrections(pl, u, om)
    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr))
    if (ranks == 1) return
    PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr))
    o = sphere_ownership_of(pl%np)
    ! this rank's sums in its rows, gathered in row order, put back by sphere
    allocate(sums(15, pl%np))
    do k = o%displs(rank + 1) + 1, o%displs(rank + 1) + o%counts(rank + 1)
      sums(1:3, k) = pl%force(:, o%sphere(k))
      sums(4:6, k) = pl%torque(:, o%sphere(k))
      sums(7:15, k) = reshape(pl%stresslet(:, :, o%sphere(k)), [9])
    end do
    PetscCallMPI(MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, sums, 15 * o%counts, 15 * o%displs, MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, ierr))
    sums(:, o%sphere) = sums
    pl%force = sums(1:3, :)
    pl%torque = sums(4:6, :)
    pl%stresslet = reshape(sums(7:15, :), [3, 3, pl%np])
  end subroutine lubrication_links_corrections

end module mod_lubrication_links
