! Invariant: mod_sphere_halo gives each rank exactly the spheres of its z-slab and copies of exactly
! those of the others within reach of it, and its exchanges move the values of those spheres and
! nothing else. The positions (pseudo-random, z also outside [0, Lz)) are known on every rank here,
! so each check is against a brute-force answer from them:
!   1. migrate: a rank holds the spheres whose centres are in its slab (floor(P z/Lz),
!      mod_sphere_ownership's), ascending, each with its own data, and the ranks together hold every
!      sphere once: from contiguous ranges of indices (the first pass; from 4 ranks on some spheres
!      go beyond the ranks within reach, and the all-to-all path is taken, on every rank), and after
!      a move;
!   2. build: the ghosts are the spheres of other slabs whose periodic z-distance to this slab is
!      below reach, merged with the own ones in ascending global index, their centres bitwise;
!   3. forward: every ghost gets its owner's values, bitwise;
!   4. reverse: an owner receives one contribution from each rank holding a ghost of it (each
!      local copy contributing 1: the owner's total is 1 + the brute-force count of such ranks);
!   5. after the spheres move by less than reach, a second migrate and build hold 1 and 2 again;
!   6. a move shorter than reach takes the neighbours' path on every rank;
!   7. the bytes a rank sends in a forward of k values are 8 k times the copies it sends;
!   8. weak scaling (doc/SCALING.md §1): 500 spheres a rank, uniform in an L x L x P L box (phi 0.4
!      of spheres of radius a), reach 3.2a (the lubrication cut-off, a gap of 1a, plus the skin
!      0.2a): a rank sends each step 8 x 9 B for each copy of its own spheres (a forward of the
!      centre, U and Omega) and 8 x 15 B for each ghost it holds (a reverse of the links' force,
!      torque and stresslet), and its copies are
!      those of a slab within reach of its faces: 500 x 2 x 3.2/L on average from 2 ranks on
!      (each face's copies go to its neighbour; at 2 ranks one neighbour takes both), so the
!      largest rank's count is within 30 % of it (a binomial count of ~180, sd 7 %, over up to 8
!      ranks; one face only when the two slabs are one neighbour's: counted once per copy, as
!      sent). The table line printed is doc/SCALING.md's.
!   9. slabs of given edges (the grid's z-ranges in the resolved step), unequal, one of them empty:
!      the slab of a centre is the last whose lower edge is at or below it (a scan's answer).
! Exact checks (no tolerance: positions and values are copied, not computed). Runs as a singleton
! (tests/run_tests.sh) and on 3 and 5 ranks (test_unit_petsc_ranks).
#include <petsc/finclude/petscsys.h>
program test_sphere_halo
  use petscsys
  use mod_kinds, only: dp
  use mod_sphere_halo, only: sphere_halo_t, sphere_halo_create, sphere_halo_migrate, sphere_halo_build, &
                             sphere_halo_forward, sphere_halo_reverse, sphere_halo_slab_of, sphere_halo_distance
  use mod_unit_checks, only: check, finish
  implicit none

  integer, parameter :: n = 400, k = 2
  real(dp), parameter :: lz = 12.0_dp, reach = 1.7_dp
  PetscErrorCode :: ierr
  PetscMPIInt :: rank, ranks
  type(sphere_halo_t) :: h
  real(dp) :: x_all(3, n)
  integer, allocatable :: id(:)
  real(dp), allocatable :: x(:, :), data(:, :), values(:, :)
  integer :: i, first, last, pass
  integer(kind=8) :: before
  logical :: ok, far

  PetscCallA(PetscInitialize(ierr))
  call MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr)
  call MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr)
  do i = 1, n
    x_all(:, i) = [modulo(0.37_dp * i, 10.0_dp), modulo(0.61_dp * i, 10.0_dp), modulo(1.913_dp * i, 3.0_dp * lz) - lz]
  end do
  call sphere_halo_create(h, lz, reach)
  ! contiguous ranges of indices to start from, unrelated to the slabs
  first = rank * n / ranks + 1
  last = (rank + 1) * n / ranks
  id = [(i, i = first, last)]
  x = x_all(:, first:last)
  allocate(data(k, size(id)))
  do i = 1, size(id)
    data(:, i) = carried(id(i))
  end do

  do pass = 1, 2
    ! 1
    call sphere_halo_migrate(h, id, x, data, ierr, far)
    call check(ierr == 0, label('migrate: no error'))
    ! 6
    if (pass == 2) call check(.not. far, label('migrate: a move shorter than reach stays among neighbours'))
    if (pass == 1 .and. ranks >= 4) call check(far, label('migrate: from ranges of indices, the all-to-all'))
    ok = all(id == pack([(i, i = 1, n)], [(slab(x_all(3, i)) == rank, i = 1, n)]))
    call check(ok, label('migrate: this rank holds the spheres of its slab, ascending'))
    ok = size(id) == h%owned .and. all(h%id == id)
    do i = 1, size(id)
      ok = ok .and. all(x(:, i) == x_all(:, id(i))) .and. all(data(:, i) == carried(id(i)))
    end do
    call check(ok, label('migrate: each sphere with its centre and its data'))
    i = size(id)
    call MPI_Allreduce(MPI_IN_PLACE, i, 1, MPI_INTEGER, MPI_SUM, PETSC_COMM_WORLD, ierr)
    call check(i == n, label('migrate: every sphere held once over the ranks'))
    ! 2
    call sphere_halo_build(h, x, ierr)
    call check(ierr == 0, label('build: no error'))
    ok = all(h%id == pack([(i, i = 1, n)], [(slab(x_all(3, i)) == rank .or. &
                                             sphere_halo_distance(h, x_all(3, i), rank) < reach, i = 1, n)]))
    ok = ok .and. size(h%id) == h%owned + h%ghosts .and. count(h%is_owned) == h%owned
    ok = ok .and. ((ranks == 1) .eqv. (h%ghosts == 0))      ! not vacuous: ghosts from 2 ranks on
    do i = 1, size(h%id)
      ok = ok .and. (h%is_owned(i) .eqv. slab(x_all(3, h%id(i))) == rank) .and. all(x(:, i) == x_all(:, h%id(i)))
    end do
    call check(ok, label('build: the ghosts are the spheres within reach, ascending, centres bitwise'))
    ! 3
    allocate(values(k, size(h%id)))
    do i = 1, size(h%id)
      values(:, i) = -1.0_dp
      if (h%is_owned(i)) values(:, i) = carried(h%id(i))
    end do
    before = h%bytes_sent
    call sphere_halo_forward(h, values, ierr)
    ok = ierr == 0
    do i = 1, size(h%id)
      ok = ok .and. all(values(:, i) == carried(h%id(i)))
    end do
    call check(ok, label('forward: every ghost holds its owner''s values'))
    ! 7
    call check(h%bytes_sent - before == 8_8 * k * size(h%send_local), label('forward: 8 k bytes per copy sent'))
    ! 4
    values = 1.0_dp
    call sphere_halo_reverse(h, values, ierr)
    ok = ierr == 0
    do i = 1, size(h%id)
      if (h%is_owned(i)) then
        ok = ok .and. all(values(:, i) == 1.0_dp + holders(x_all(3, h%id(i))))
      else
        ok = ok .and. all(values(:, i) == 1.0_dp)
      end if
    end do
    call check(ok, label('reverse: an owner sums one part from each rank holding a ghost of it'))
    deallocate(values)
    ! 5: the spheres move by less than reach (also across the periodic face); the ghosts are dropped
    x_all(3, :) = x_all(3, :) + [(0.9_dp * reach * sin(1.7_dp * i), i = 1, n)]
    x_all(1, :) = x_all(1, :) + 0.5_dp
    x = x_all(:, id)
  end do

  call weak_scaling()
  call given_edges()
  call finish('test_sphere_halo')
  PetscCallA(PetscFinalize(ierr))

contains

  ! 8: the halo's bytes per rank and step at fixed spheres per rank
  subroutine weak_scaling()
    integer, parameter :: per_rank = 500
    real(dp), parameter :: reach_w = 3.2_dp, phi = 0.4_dp
    type(sphere_halo_t) :: hw
    real(dp) :: side, expected, u(3)
    real(dp), allocatable :: xw(:, :), dw(:, :), vw(:, :)
    integer, allocatable :: idw(:)
    integer :: nw, j, copies, most
    integer(kind=8) :: sent, most_sent
    integer(kind=4), allocatable :: seed(:)
    character(len=160) :: line
    side = (4.0_dp / 3.0_dp * acos(-1.0_dp) * per_rank / phi)**(1.0_dp / 3.0_dp)
    nw = per_rank * ranks
    ! every rank draws the same centres, keeps a contiguous range and migrates them
    call random_seed(size=j)
    allocate(seed(j))
    seed = 20261129
    call random_seed(put=seed)
    allocate(xw(3, nw))
    do j = 1, nw
      call random_number(u)
      xw(:, j) = u * [side, side, side * ranks]
    end do
    idw = [(j, j = rank * per_rank + 1, (rank + 1) * per_rank)]
    xw = xw(:, idw)
    allocate(dw(0, size(idw)))
    call sphere_halo_create(hw, side * ranks, reach_w)
    call sphere_halo_migrate(hw, idw, xw, dw, ierr)
    call sphere_halo_build(hw, xw, ierr)
    allocate(vw(24, size(hw%id)))
    vw = 1.0_dp
    sent = hw%bytes_sent
    call sphere_halo_forward(hw, vw(1:9, :), ierr)
    call sphere_halo_reverse(hw, vw(10:24, :), ierr)
    sent = hw%bytes_sent - sent
    copies = size(hw%send_local)
    most = copies
    most_sent = sent
    call MPI_Allreduce(MPI_IN_PLACE, most, 1, MPI_INTEGER, MPI_MAX, PETSC_COMM_WORLD, ierr)
    call MPI_Allreduce(MPI_IN_PLACE, most_sent, 1, MPI_INTEGER8, MPI_MAX, PETSC_COMM_WORLD, ierr)
    call check(sent == 8_8 * (9 * copies + 15 * size(hw%recv_local)), &
               label('weak scaling: 8 x 9 B per copy sent and 8 x 15 B per ghost held, each step'))
    expected = merge(0.0_dp, per_rank * 2.0_dp * reach_w / side, ranks == 1)
    call check(abs(most - expected) <= 0.3_dp * expected, label('weak scaling: the copies of a slab within reach'))
    write(line, '(a,i0,a,i0,a,i0,a,f6.1,a,i0,a)') 'halo weak scaling: ', ranks, ' ranks, ', nw, &
         ' spheres, most copies sent by a rank ', most, ' (expected ', expected, '), bytes per rank and step ', &
         most_sent, ' (forward 9 + reverse 15 values)'
    if (rank == 0) write(*, '(a)') trim(line)
  end subroutine weak_scaling

  ! 9: slabs of given edges, unequal and with an empty one (0, 0.1, 0.1, ... of lz): the rank of a
  ! centre (sphere_halo_slab_of's bisection) is the last slab whose lower edge is at or below it,
  ! found by a scan, for 2000 centres, the edges themselves among them.
  subroutine given_edges()
    type(sphere_halo_t) :: g
    real(dp) :: edges(0:ranks), z
    integer :: q, j, scan
    logical :: same
    edges(0) = 0.0_dp
    do q = 1, ranks - 1
      edges(q) = lz * (real(q, dp) / ranks)**1.5_dp
    end do
    if (ranks >= 3) edges(2) = edges(1)          ! rank 1's slab is empty
    edges(ranks) = lz
    call sphere_halo_create(g, lz, reach, edges)
    same = .true.
    do j = 0, 2000
      z = merge(edges(mod(j, ranks)), 1.3_dp * lz * j / 2000.0_dp - 0.1_dp * lz, mod(j, 7) == 0)
      scan = 0
      do q = 0, ranks - 1
        if (edges(q) <= modulo(z, lz)) scan = q
      end do
      same = same .and. sphere_halo_slab_of(g, z) == scan
    end do
    call check(same, label('given edges (one slab empty from 3 ranks on): the slab of 2000 centres by bisection '// &
                           'is the scan''s'))
  end subroutine given_edges

  pure function carried(i) result(v)
    integer, intent(in) :: i
    real(dp) :: v(k)
    v = [real(i, dp), sqrt(real(i, dp)) + 0.125_dp]
  end function carried

  integer function slab(z)
    real(dp), intent(in) :: z
    slab = sphere_halo_slab_of(h, z)
  end function slab

  ! the ranks other than its owner within reach of a centre at z
  integer function holders(z)
    real(dp), intent(in) :: z
    integer :: q
    holders = 0
    do q = 0, ranks - 1
      if (q /= slab(z) .and. sphere_halo_distance(h, z, q) < reach) holders = holders + 1
    end do
  end function holders

  function label(what) result(text)
    character(len=*), intent(in) :: what
    character(len=120) :: text
    write(text, '(a,i0,a,i0,a,a)') 'pass ', pass, ', rank ', rank, ': ', what
  end function label
end program test_sphere_halo
