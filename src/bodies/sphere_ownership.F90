! Which rank owns each sphere's block row of the 6N particle system (doc/DESIGN.md "Parallelism",
! issue 45, step 3 of doc/SCALING.md §3): the rank whose z-slab of the box holds the sphere's centre
! (P equal slabs of Lz). The rows are numbered rank by rank, and within a rank in the order of the
! sphere indices, so one rank keeps the identity numbering (bitwise the numbers of before). A rank
! evaluates the lubrication links of the spheres it owns (mod_lubrication_links), so the links
! evaluated on two ranks are only those across a slab face, where with ranges of sphere indices
! (before 2026-11-29), unrelated to where the spheres are, almost every link crossed two ranks.
!
! The ownership follows the positions: mod_lubrication_links sets it from the positions at which it
! evaluates the step's links (sphere_ownership_set), and the particle solve and the links' sums use
! that one (sphere_ownership_of), so the links a rank holds are always those of the rows it sets.
! Nothing of a sphere moves with its ownership (the particle state is still replicated), so a
! sphere changes rank by crossing a slab face between steps at no cost. Without links (contacts
! and one-body blocks only, which every rank holds) any ownership serves; sphere_ownership_of then
! falls back to contiguous ranges of indices when none was set for this number of spheres.
#include <petsc/finclude/petscsys.h>
module mod_sphere_ownership
  use petscsys
  use mod_kinds, only: dp
  implicit none
  private
  public :: sphere_ownership_t, sphere_ownership_by_slab, sphere_ownership_contiguous, sphere_ownership_set, &
            sphere_ownership_of, sphere_ownership_mine

  type :: sphere_ownership_t
    integer :: n = 0                         ! spheres
    integer, allocatable :: owner(:)         ! (n) the owning rank (0-based) of each sphere
    integer, allocatable :: row(:)           ! (n) the 0-based block row of each sphere
    integer, allocatable :: sphere(:)        ! (n) the sphere of each block row + 1, rank by rank
    integer, allocatable :: counts(:)        ! (ranks) spheres a rank owns
    integer, allocatable :: displs(:)        ! (ranks) its first block row
  end type sphere_ownership_t

  ! the ownership of the step (set from the positions of its lubrication links)
  type(sphere_ownership_t), save :: current

contains

  !> Sphere i belongs to slab floor(P z_i/Lz) (z wrapped into [0, Lz)).
  pure function sphere_ownership_by_slab(x, lz, ranks) result(o)
    real(dp), intent(in) :: x(:, :), lz
    integer, intent(in) :: ranks
    type(sphere_ownership_t) :: o
    integer :: i
    integer :: slab(size(x, 2))
    do i = 1, size(x, 2)
      slab(i) = min(ranks - 1, max(0, int(modulo(x(3, i), lz) / lz * ranks)))
    end do
    o = numbered(slab, ranks)
  end function sphere_ownership_by_slab

  !> Contiguous ranges of indices, PETSc's split of n over the ranks (the first mod(n, P) ranks
  !> one more).
  pure function sphere_ownership_contiguous(n, ranks) result(o)
    integer, intent(in) :: n, ranks
    type(sphere_ownership_t) :: o
    integer :: i, r, first
    integer :: owner(n)
    first = 0
    do r = 0, ranks - 1
      do i = first + 1, first + n / ranks + merge(1, 0, r < mod(n, ranks))
        owner(i) = r
      end do
      first = first + n / ranks + merge(1, 0, r < mod(n, ranks))
    end do
    o = numbered(owner, ranks)
  end function sphere_ownership_contiguous

  ! The rows numbered rank by rank, in index order within a rank.
  pure function numbered(owner, ranks) result(o)
    integer, intent(in) :: owner(:), ranks
    type(sphere_ownership_t) :: o
    integer :: i, r
    integer :: next(ranks)
    o%n = size(owner)
    allocate(o%owner(o%n), o%row(o%n), o%sphere(o%n), o%counts(ranks), o%displs(ranks))
    o%owner = owner
    o%counts = 0
    do i = 1, o%n
      o%counts(owner(i) + 1) = o%counts(owner(i) + 1) + 1
    end do
    o%displs(1) = 0
    do r = 2, ranks
      o%displs(r) = o%displs(r - 1) + o%counts(r - 1)
    end do
    next = o%displs
    do i = 1, o%n
      r = owner(i) + 1
      o%row(i) = next(r)
      o%sphere(next(r) + 1) = i
      next(r) = next(r) + 1
    end do
  end function numbered

  !> The step's ownership from the positions x (3, n) in a box of height lz along z (the same on
  !> every rank: the positions are replicated). Not collective.
  subroutine sphere_ownership_set(x, lz)
    real(dp), intent(in) :: x(:, :), lz
    PetscMPIInt :: ranks
    PetscErrorCode :: ierr
    call MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr)
    current = sphere_ownership_by_slab(x, lz, ranks)
  end subroutine sphere_ownership_set

  !> The ownership of n spheres: the step's, or contiguous ranges when none was set for n spheres.
  function sphere_ownership_of(n) result(o)
    integer, intent(in) :: n
    type(sphere_ownership_t) :: o
    PetscMPIInt :: ranks
    PetscErrorCode :: ierr
    if (current%n == n .and. n > 0) then
      o = current
      return
    end if
    call MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr)
    o = sphere_ownership_contiguous(n, ranks)
  end function sphere_ownership_of

  !> The spheres this rank owns at positions x (3, n) in a box of height lz along z
  !> (sphere_ownership_by_slab), in index order: the rows of the per-sphere datasets it writes in
  !> the particle files and checkpoints (mod_particles_io, owned_spheres_rule). Not collective.
  function sphere_ownership_mine(x, lz) result(mine)
    real(dp), intent(in) :: x(:, :), lz
    integer, allocatable :: mine(:)
    PetscMPIInt :: rank, ranks
    PetscErrorCode :: ierr
    type(sphere_ownership_t) :: o
    call MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr)
    call MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr)
    o = sphere_ownership_by_slab(x, lz, ranks)
    mine = o%sphere(o%displs(rank + 1) + 1:o%displs(rank + 1) + o%counts(rank + 1))
  end function sphere_ownership_mine

end module mod_sphere_ownership
