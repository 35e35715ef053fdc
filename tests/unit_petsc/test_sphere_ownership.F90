! Invariant: the ownership of the spheres' block rows (mod_sphere_ownership, doc/DESIGN.md
! "Parallelism") is a numbering of the 6N system that every rank can use: for pseudo-random centres
! (z also outside [0, Lz), as periodic positions may be) and 1 to 5 ranks,
!   1. each sphere belongs to the slab that holds its centre: P z_wrapped / Lz in [owner, owner + 1);
!   2. the rows are a permutation of 0..n-1, rank by rank: the rows of rank r are displs(r) ..
!      displs(r) + counts(r) - 1, counts sum to n, and sphere(row(i) + 1) = i;
!   3. within a rank the rows follow the sphere indices (so one rank is the identity numbering, the
!      numbers of before bitwise);
!   4. the contiguous split (the fallback) gives rank r the indices PETSc's split would, the first
!      mod(n, P) ranks one more;
!   5. sphere_ownership_of returns the step's ownership for its n and the contiguous one otherwise.
! Exact integer checks (no tolerance). The program runs as an MPI singleton (tests/run_tests.sh) and
! on 3 ranks (test_unit_petsc_ranks), where 5 takes the communicator's size.
#include <petsc/finclude/petscsys.h>
program test_sphere_ownership
  use petscsys
  use mod_kinds, only: dp
  use mod_sphere_ownership, only: sphere_ownership_t, sphere_ownership_by_slab, sphere_ownership_contiguous, &
                                  sphere_ownership_set, sphere_ownership_of
  use mod_unit_checks, only: check, finish
  implicit none

  integer, parameter :: n = 97
  real(dp), parameter :: lz = 7.5_dp
  PetscErrorCode :: ierr
  type(sphere_ownership_t) :: o, slabs
  real(dp) :: x(3, n), zw
  integer :: ranks, i, r
  PetscMPIInt :: size_world
  logical :: ok_slab, ok_perm, ok_order, ok_split
  integer, allocatable :: seen(:)
  character(len=80) :: what

  PetscCallA(PetscInitialize(ierr))
  do i = 1, n
    x(:, i) = [modulo(0.37_dp * i, 3.0_dp), modulo(0.61_dp * i, 5.0_dp), modulo(1.913_dp * i, 3.0_dp * lz) - lz]
  end do
  do ranks = 1, 5
    o = sphere_ownership_by_slab(x, lz, ranks)
    ok_slab = .true.
    do i = 1, n
      zw = modulo(x(3, i), lz)
      if (zw / lz * ranks < o%owner(i) .or. zw / lz * ranks >= o%owner(i) + 1) ok_slab = .false.
    end do
    write(what, '(i0,a)') ranks, ' rank(s): every sphere in the slab of its centre'
    call check(ok_slab, trim(what))
    allocate(seen(0:n - 1))
    seen = 0
    ok_perm = sum(o%counts) == n .and. o%displs(1) == 0
    do i = 1, n
      seen(o%row(i)) = seen(o%row(i)) + 1
      if (o%sphere(o%row(i) + 1) /= i) ok_perm = .false.
      r = o%owner(i) + 1
      if (o%row(i) < o%displs(r) .or. o%row(i) >= o%displs(r) + o%counts(r)) ok_perm = .false.
    end do
    ok_perm = ok_perm .and. all(seen == 1)
    deallocate(seen)
    write(what, '(i0,a)') ranks, ' rank(s): the rows are a permutation, rank by rank'
    call check(ok_perm, trim(what))
    ok_order = .true.
    do i = 2, n
      if (o%owner(i) == o%owner(i - 1) .and. o%row(i) <= o%row(i - 1)) ok_order = .false.
    end do
    if (ranks == 1) ok_order = ok_order .and. all(o%row == [(i - 1, i = 1, n)])
    write(what, '(i0,a)') ranks, ' rank(s): rows in index order within a rank (1 rank: the identity)'
    call check(ok_order, trim(what))
    o = sphere_ownership_contiguous(n, ranks)
    ok_split = all(o%row == [(i - 1, i = 1, n)])
    do r = 1, ranks
      ok_split = ok_split .and. o%counts(r) == n / ranks + merge(1, 0, r - 1 < mod(n, ranks))
    end do
    write(what, '(i0,a)') ranks, ' rank(s): the contiguous split is PETSc''s'
    call check(ok_split, trim(what))
  end do
  call sphere_ownership_set(x, lz)
  o = sphere_ownership_of(n)
  call MPI_Comm_size(PETSC_COMM_WORLD, size_world, ierr)
  slabs = sphere_ownership_by_slab(x, lz, size_world)
  call check(all(o%owner == slabs%owner) .and. o%n == n, &
             'sphere_ownership_of(n) is the step''s ownership')
  o = sphere_ownership_of(n - 1)
  slabs = sphere_ownership_contiguous(n - 1, size_world)
  call check(o%n == n - 1 .and. all(o%row == slabs%row) .and. all(o%owner == slabs%owner), &
             'sphere_ownership_of another n is the contiguous split')
  call finish('test_sphere_ownership')
  PetscCallA(PetscFinalize(ierr))
end program test_sphere_ownership
