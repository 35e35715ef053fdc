! The lubrication links of a step shared out over the ranks (doc/DESIGN.md "Fictitious domain", Costs). Every rank needs every
! link (the 6N particle system is replicated), but evaluating them (resistance functions, the
! 12x12 blocks, their projection onto positive semi-definite matrices) is ~15 us per pair, and the
! paper scene has ~4000 pairs: each rank evaluates one contiguous share of the pair candidates
! (particle_lubrication_links), and the shares are gathered in rank order, so every rank holds the
! links in the order one rank alone would have made them, bitwise the same.
#include <petsc/finclude/petscsys.h>
module mod_lubrication_links
  use petscsys
  use mod_kinds, only: dp
  use mod_pair_resistance, only: n_pair_scalars
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_links, &
                                      particle_lubrication_reserve_pairs
  implicit none
  private
  public :: lubrication_links_evaluate

contains

  !> The links at positions x (3, np) on every rank. Collective. offset (optional): the
  !> Lees-Edwards offset of this configuration (lubrication dynamics with sliding boundaries).
  subroutine lubrication_links_evaluate(pl, x, ierr, offset)
    type(particle_lubrication_t), intent(inout) :: pl
    real(dp), intent(in) :: x(:, :)
    PetscErrorCode, intent(out) :: ierr
    real(dp), intent(in), optional :: offset
    PetscMPIInt :: rank, ranks
    integer, allocatable :: counts(:), displs(:)
    integer :: mine, total, r

    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr))
    PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr))
    if (ranks == 1) then
      call particle_lubrication_links(pl, x, offset=offset)
      return
    end if
    call particle_lubrication_links(pl, x, rank, ranks, offset)
    mine = pl%npairs
    allocate(counts(0:ranks - 1), displs(0:ranks - 1))
    PetscCallMPI(MPI_Allgather(mine, 1, MPI_INTEGER, counts, 1, MPI_INTEGER, PETSC_COMM_WORLD, ierr))
    displs(0) = 0
    do r = 1, ranks - 1
      displs(r) = displs(r - 1) + counts(r - 1)
    end do
    total = sum(counts)
    call particle_lubrication_reserve_pairs(pl, max(total, 1))
    ! each share at its place in the whole, then gathered in place
    if (displs(rank) > 0 .and. mine > 0) then
      pl%pair(:, displs(rank) + 1:displs(rank) + mine) = pl%pair(:, 1:mine)
      pl%pair_d(:, displs(rank) + 1:displs(rank) + mine) = pl%pair_d(:, 1:mine)
      pl%pair_f(:, displs(rank) + 1:displs(rank) + mine) = pl%pair_f(:, 1:mine)
      if (pl%sized) pl%pair_f2(:, displs(rank) + 1:displs(rank) + mine) = pl%pair_f2(:, 1:mine)
      pl%pair_uinf(:, displs(rank) + 1:displs(rank) + mine) = pl%pair_uinf(:, 1:mine)
      pl%pair_r(:, :, displs(rank) + 1:displs(rank) + mine) = pl%pair_r(:, :, 1:mine)
      pl%pair_drive(:, displs(rank) + 1:displs(rank) + mine) = pl%pair_drive(:, 1:mine)
    end if
    PetscCallMPI(MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, pl%pair, 2 * counts, 2 * displs, MPI_INTEGER, PETSC_COMM_WORLD, ierr))
    call gather(pl%pair_d, 3)
    call gather(pl%pair_f, n_pair_scalars)
    if (pl%sized) call gather(pl%pair_f2, n_pair_scalars)     ! spheres of several sizes
    call gather(pl%pair_uinf, 6)
    call gather(pl%pair_r, 144)
    call gather(pl%pair_drive, 12)
    pl%npairs = total
    ! the smallest gap of all shares (the walls are the same on every rank), and a failed link of
    ! any share (the largest particle index that failed, so that every rank names the same one)
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, pl%min_gap, 1, MPI_DOUBLE_PRECISION, MPI_MIN, PETSC_COMM_WORLD, ierr))
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, pl%failed_link, 2, MPI_INTEGER, MPI_MAX, PETSC_COMM_WORLD, ierr))
  contains
    subroutine gather(a, per_link)
      real(dp), intent(inout) :: a(*)
      integer, intent(in) :: per_link
      PetscCallMPI(MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, a, per_link * counts, per_link * displs, MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, ierr))
    end subroutine gather
  end subroutine lubrication_links_evaluate

end module mod_lubrication_links
