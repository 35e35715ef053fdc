! Spheres held by the rank whose z-slab holds their centre, with ghost copies within an interaction
! range (issue 45 item 2; doc/DESIGN.md "Spheres held by their slab", doc/SCALING.md §3). The building
! block of a particle state that is not replicated: each rank holds its own spheres and copies of
! the others' spheres whose centres lie within `reach` of its slab (reach: the largest distance at
! which two spheres interact through a kernel, the contact and lubrication cut-offs and the
! fictitious-domain support, plus the neighbour list's skin), and exchanges with the ranks whose
! slabs lie within reach of its own only, so that no message grows with the total number of spheres.
!
! A rank's spheres ("the local set") are its own and its ghosts, held in ascending order of their
! global index (the index of one rank's run): a loop over the local set visits the spheres in the
! order one rank would, so sums over the pairs of local spheres can follow one rank's order.
!   sphere_halo_create     the slabs (P equal slabs of Lz, those of mod_sphere_ownership, or given
!                          edges: the grid's z-ranges in the resolved step) and reach
!   sphere_halo_migrate    after the spheres moved: each sphere with its data to the rank of its
!                          slab (among neighbours; one all-to-all when a sphere went farther, as
!                          at the first distribution; one integer reduction decides which)
!   sphere_halo_build      the ghosts of the own spheres' positions; their global indices and
!                          slots, and the lists of what goes to each neighbour
!   sphere_halo_forward    owners' values -> their ghost copies (positions, velocities)
!   sphere_halo_reverse    ghosts' partial sums -> added into their owners' values (forces)
!   sphere_halo_exchange   records of any count to each neighbour (what goes with a sphere but is
!                          not one value per sphere: the contacts' springs)
! A sphere is a ghost of rank q when the periodic distance along z from its centre to q's slab is
! below reach; a rank exchanges with every rank q /= itself whose slab lies within reach of its own.
! With one rank there are no ghosts and nothing is sent: periodic images are the kernels' minimum
! image, as before. The bytes each rank sent are counted (bytes_sent) for doc/SCALING.md.
#include <petsc/finclude/petscsys.h>
module mod_sphere_halo
  use petscsys
  use mod_kinds, only: dp
  use mod_sorting, only: ascending_order
  implicit none
  private
  public :: sphere_halo_t, sphere_halo_create, sphere_halo_migrate, sphere_halo_build, sphere_halo_forward, &
            sphere_halo_reverse, sphere_halo_exchange, sphere_halo_slab_of, sphere_halo_distance

  type :: sphere_halo_t
    real(dp) :: lz = 0.0_dp                 ! the box's period along z [a]
    ! the slabs: rank q's is [edge(q), edge(q + 1)); equal: edge(q) = q lz / P (then slab_of is
    ! mod_sphere_ownership's floor(P z/lz) exactly)
    real(dp), allocatable :: edge(:)        ! (0:P)
    logical :: equal = .true.
    real(dp) :: reach = 0.0_dp              ! the interaction range plus skin [a]
    integer :: rank = 0, ranks = 1
    integer :: owned = 0                    ! own spheres of the local set
    integer :: ghosts = 0                   ! ghost copies of the local set
    integer, allocatable :: id(:)           ! (owned + ghosts) global index, ascending
    logical, allocatable :: is_owned(:)     ! (owned + ghosts)
    integer, allocatable :: neighbour(:)    ! ranks within reach, ascending
    integer, allocatable :: send_start(:)   ! (neighbours + 1) own spheres sent to each, by local index
    integer, allocatable :: send_local(:)
    integer, allocatable :: recv_start(:)   ! (neighbours + 1) ghosts received from each, by local index
    integer, allocatable :: recv_local(:)
    integer(kind=8) :: bytes_sent = 0       ! by this rank through the exchanges, since creation
  end type sphere_halo_t

  integer, parameter :: TAG_COUNT = 4501, TAG_DATA = 4502

contains

  !> The slabs of the ranks of PETSC_COMM_WORLD (P equal slabs of lz, mod_sphere_ownership's, or
  !> edges (0:P), ascending from 0 to lz: rank q's slab is [edges(q), edges(q + 1))) and the ranks
  !> within reach of this one. Collective in name only (no messages).
  subroutine sphere_halo_create(h, lz, reach, edges)
    type(sphere_halo_t), intent(out) :: h
    real(dp), intent(in) :: lz, reach
    real(dp), intent(in), optional :: edges(0:)
    PetscMPIInt :: rank, ranks
    PetscErrorCode :: ierr
    integer :: q
    call MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr)
    call MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr)
    h%rank = rank
    h%ranks = ranks
    h%lz = lz
    h%reach = reach
    h%equal = .not. present(edges)
    allocate(h%edge(0:ranks))
    if (present(edges)) then
      h%edge(0:ranks) = edges(0:ranks)
    else
      h%edge(0:ranks) = [(lz * q / ranks, q = 0, ranks)]
    end if
    allocate(h%neighbour(0))
    do q = 0, ranks - 1
      if (q /= rank .and. slab_gap(h, q, rank) < reach) h%neighbour = [h%neighbour, q]
    end do
    allocate(h%id(0), h%is_owned(0), h%send_start(size(h%neighbour) + 1), h%send_local(0), &
             h%recv_start(size(h%neighbour) + 1), h%recv_local(0))
    h%send_start = 1
    h%recv_start = 1
  end subroutine sphere_halo_create

  !> The rank whose slab holds z (wrapped into [0, lz)): equal slabs floor(P z/lz), as
  !> mod_sphere_ownership; given edges, the last q with edge(q) <= z (by bisection: log2 P
  !> comparisons a sphere, an empty slab skipped as its upper neighbour's edge equals its own).
  pure integer function sphere_halo_slab_of(h, z)
    type(sphere_halo_t), intent(in) :: h
    real(dp), intent(in) :: z
    real(dp) :: zw
    integer :: lo, hi, mid
    zw = modulo(z, h%lz)
    if (h%equal) then
      sphere_halo_slab_of = min(h%ranks - 1, max(0, int(zw / h%lz * h%ranks)))
    else
      ! edge(lo) <= zw throughout (edge(0) = 0); the answer in lo..hi
      lo = 0
      hi = h%ranks - 1
      do while (lo < hi)
        mid = (lo + hi + 1) / 2
        if (h%edge(mid) <= zw) then
          lo = mid
        else
          hi = mid - 1
        end if
      end do
      sphere_halo_slab_of = lo
    end if
  end function sphere_halo_slab_of

  !> The periodic distance along z from z to the slab of rank q (0 inside it).
  pure real(dp) function sphere_halo_distance(h, z, q)
    type(sphere_halo_t), intent(in) :: h
    real(dp), intent(in) :: z
    integer, intent(in) :: q
    real(dp) :: zw, lo, hi
    if (sphere_halo_slab_of(h, z) == q) then
      sphere_halo_distance = 0.0_dp
      return
    end if
    zw = modulo(z, h%lz)
    lo = h%edge(q)
    hi = h%edge(q + 1)
    sphere_halo_distance = min(modulo(lo - zw, h%lz), modulo(zw - hi, h%lz))
  end function sphere_halo_distance

  ! The periodic gap along z between the slabs of ranks q and r (0 when they touch).
  pure real(dp) function slab_gap(h, q, r)
    type(sphere_halo_t), intent(in) :: h
    integer, intent(in) :: q, r
    real(dp) :: lo_q, hi_q, lo_r, hi_r
    lo_q = h%edge(q)
    hi_q = h%edge(q + 1)
    lo_r = h%edge(r)
    hi_r = h%edge(r + 1)
    slab_gap = min(modulo(lo_q - hi_r, h%lz), modulo(lo_r - hi_q, h%lz))
  end function slab_gap

  !> After the spheres moved: every own sphere whose centre has left this rank's slab goes, with its
  !> data, to the rank of its new slab. In a step a sphere moves less than reach between two
  !> migrations (the caller's skin), so it goes to a neighbour and only neighbours exchange; when
  !> some sphere, on any rank, goes farther (the first distribution, from a file or from contiguous
  !> ranges of indices), every rank takes part in one all-to-all exchange instead. On entry id
  !> (owned), x (3, owned) and data (k, owned) are this rank's own spheres (the ghosts dropped, any
  !> order); on return the own spheres after the move, in ascending global index, and h holds them
  !> with no ghosts (sphere_halo_build next). far: whether the all-to-all was needed. Collective.
  subroutine sphere_halo_migrate(h, id, x, data, ierr, far)
    type(sphere_halo_t), intent(inout) :: h
    integer, allocatable, intent(inout) :: id(:)
    real(dp), allocatable, intent(inout) :: x(:, :), data(:, :)
    PetscErrorCode, intent(out) :: ierr
    logical, intent(out), optional :: far
    integer :: n, k, i, m, w, nb, total, kept, beyond, ndest
    integer, allocatable :: slab(:), dest(:), send_count(:), recv_count(:), order(:), new_id(:), offset(:), roffset(:)
    real(dp), allocatable :: send_buf(:), recv_buf(:), new_x(:, :), new_data(:, :)

    ierr = 0
    n = size(id)
    k = size(data, 1)
    w = 4 + k                    ! the record of a sphere: id, x (3), data (k)
    nb = size(h%neighbour)
    ! the destination of each sphere: 0 kept, else a neighbour's position in h%neighbour
    allocate(slab(n), dest(n))
    beyond = 0
    do i = 1, n
      slab(i) = sphere_halo_slab_of(h, x(3, i))
      dest(i) = 0
      if (slab(i) /= h%rank) dest(i) = findloc(h%neighbour, slab(i), dim=1)
      if (slab(i) /= h%rank .and. dest(i) == 0) beyond = beyond + 1
    end do
    ! whether any rank must reach beyond its neighbours (one integer)
    call MPI_Allreduce(MPI_IN_PLACE, beyond, 1, MPI_INTEGER, MPI_SUM, PETSC_COMM_WORLD, ierr)
    if (ierr /= 0) return
    if (present(far)) far = beyond > 0
    if (beyond > 0) then
      ! every rank a destination: dest is the rank + 1, 0 for kept
      dest = merge(0, slab + 1, slab == h%rank)
      ndest = h%ranks
    else
      ndest = nb
    end if
    allocate(send_count(ndest), recv_count(ndest), offset(ndest + 1), roffset(ndest + 1))
    send_count = 0
    do i = 1, n
      if (dest(i) > 0) send_count(dest(i)) = send_count(dest(i)) + 1
    end do
    if (beyond > 0) then
      call MPI_Alltoall(send_count, 1, MPI_INTEGER, recv_count, 1, MPI_INTEGER, PETSC_COMM_WORLD, ierr)
      h%bytes_sent = h%bytes_sent + 4_8 * ndest
    else
      call exchange_counts(h, send_count, recv_count, ierr)
    end if
    if (ierr /= 0) return
    offset(1) = 0
    roffset(1) = 0
    do m = 1, ndest
      offset(m + 1) = offset(m) + send_count(m) * w
      roffset(m + 1) = roffset(m) + recv_count(m) * w
    end do
    allocate(send_buf(max(1, offset(ndest + 1))), recv_buf(max(1, roffset(ndest + 1))))
    send_count = 0
    do i = 1, n
      if (dest(i) == 0) cycle
      m = dest(i)
      send_buf(offset(m) + send_count(m) * w + 1:offset(m) + (send_count(m) + 1) * w) = &
        [real(id(i), dp), x(:, i), data(:, i)]
      send_count(m) = send_count(m) + 1
    end do
    if (beyond > 0) then
      call MPI_Alltoallv(send_buf, send_count * w, offset(1:ndest), MPI_DOUBLE_PRECISION, recv_buf, recv_count * w, &
                         roffset(1:ndest), MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, ierr)
    else
      call swap(h, send_buf, offset, recv_buf, roffset, ierr)
    end if
    if (ierr /= 0) return
    h%bytes_sent = h%bytes_sent + 8_8 * offset(ndest + 1)
    ! the kept spheres and the received ones, in ascending global index
    kept = count(dest == 0)
    total = kept + roffset(ndest + 1) / w
    allocate(new_id(total), new_x(3, total), new_data(k, total))
    m = 0
    do i = 1, n
      if (dest(i) /= 0) cycle
      m = m + 1
      new_id(m) = id(i)
      new_x(:, m) = x(:, i)
      new_data(:, m) = data(:, i)
    end do
    do i = 1, roffset(ndest + 1) / w
      m = m + 1
      new_id(m) = nint(recv_buf((i - 1) * w + 1))
      new_x(:, m) = recv_buf((i - 1) * w + 2:(i - 1) * w + 4)
      new_data(:, m) = recv_buf((i - 1) * w + 5:i * w)
    end do
    order = ascending_order(new_id)
    id = new_id(order)
    x = new_x(:, order)
    data = new_data(:, order)
    h%owned = total
    h%ghosts = 0
    h%id = id
    h%is_owned = [(.true., i = 1, total)]
    h%send_local = [integer ::]
    h%recv_local = [integer ::]
    h%send_start = 1
    h%recv_start = 1
  end subroutine sphere_halo_migrate

  !> The ghosts of this rank's own spheres: on entry h holds the own spheres (sphere_halo_migrate)
  !> and x (3, owned) their centres; on return x (3, owned + ghosts) is the local set's centres in
  !> ascending global index (h%id, h%is_owned), the ghosts' centres as their owners sent them, and h
  !> knows what goes to whom in sphere_halo_forward and sphere_halo_reverse. Collective among
  !> neighbours.
  subroutine sphere_halo_build(h, x, ierr)
    type(sphere_halo_t), intent(inout) :: h
    real(dp), allocatable, intent(inout) :: x(:, :)
    PetscErrorCode, intent(out) :: ierr
    integer :: nb, m, i, n, g, total
    integer, allocatable :: send_count(:), recv_count(:), order(:), own_id(:), all_id(:)
    integer, allocatable :: send_own(:), near(:)
    real(dp), allocatable :: send_buf(:), recv_buf(:), own_x(:, :)
    integer :: offset(size(h%neighbour) + 1), roffset(size(h%neighbour) + 1)

    ierr = 0
    nb = size(h%neighbour)
    n = h%owned
    allocate(own_id(n), own_x(3, n))
    own_id = h%id(1:n)
    own_x = x(:, 1:n)
    ! what goes to each neighbour: the own spheres within reach of its slab, ascending
    allocate(send_count(nb), recv_count(nb), send_own(0))
    do m = 1, nb
      near = pack([(i, i = 1, n)], [(sphere_halo_distance(h, own_x(3, i), h%neighbour(m)) < h%reach, i = 1, n)])
      send_count(m) = size(near)
      send_own = [send_own, near]
    end do
    call exchange_counts(h, send_count, recv_count, ierr)
    if (ierr /= 0) return
    ! the ghosts' global indices and centres (4 values each)
    offset(1) = 0
    roffset(1) = 0
    do m = 1, nb
      offset(m + 1) = offset(m) + 4 * send_count(m)
      roffset(m + 1) = roffset(m) + 4 * recv_count(m)
    end do
    allocate(send_buf(max(1, offset(nb + 1))), recv_buf(max(1, roffset(nb + 1))))
    do g = 1, size(send_own)
      send_buf(4 * g - 3:4 * g) = [real(own_id(send_own(g)), dp), own_x(:, send_own(g))]
    end do
    call swap(h, send_buf, offset, recv_buf, roffset, ierr)
    if (ierr /= 0) return
    h%bytes_sent = h%bytes_sent + 8_8 * offset(nb + 1)
    ! the local set: own spheres and ghosts merged in ascending global index
    h%ghosts = roffset(nb + 1) / 4
    total = n + h%ghosts
    allocate(all_id(total))
    all_id(1:n) = own_id
    do g = 1, h%ghosts
      all_id(n + g) = nint(recv_buf(4 * g - 3))
    end do
    order = ascending_order(all_id)        ! local slot l holds entry order(l) of [own; received]
    h%id = all_id(order)
    h%is_owned = order <= n
    deallocate(x)
    allocate(x(3, total))
    do i = 1, total
      if (order(i) <= n) then
        x(:, i) = own_x(:, order(i))
      else
        x(:, i) = recv_buf(4 * (order(i) - n) - 2:4 * (order(i) - n))
      end if
    end do
    ! where each own sphere and each ghost sits now: the inverse of order
    block
      integer :: slot(total)
      do i = 1, total
        slot(order(i)) = i
      end do
      h%send_local = slot(send_own)
      h%recv_local = slot(n + 1:total)
    end block
    h%send_start(1) = 1
    h%recv_start(1) = 1
    do m = 1, nb
      h%send_start(m + 1) = h%send_start(m) + send_count(m)
      h%recv_start(m + 1) = h%recv_start(m) + recv_count(m)
    end do
  end subroutine sphere_halo_build

  !> values (k, owned + ghosts) of the local set: the ghosts' columns set to their owners'.
  !> Collective among neighbours.
  subroutine sphere_halo_forward(h, values, ierr)
    type(sphere_halo_t), intent(inout) :: h
    real(dp), intent(inout) :: values(:, :)
    PetscErrorCode, intent(out) :: ierr
    real(dp), allocatable :: send_buf(:, :), recv_buf(:, :)
    call move(h, values, h%send_local, h%send_start, h%recv_local, h%recv_start, send_buf, recv_buf, ierr)
    if (ierr /= 0) return
    values(:, h%recv_local) = recv_buf
  end subroutine sphere_halo_forward

  !> values (k, owned + ghosts): each ghost's column (a partial sum made on this rank) added into
  !> its owner's column; the ghosts' columns are left as they were. Collective among neighbours.
  !> The owner adds the neighbours' parts in ascending rank order.
  subroutine sphere_halo_reverse(h, values, ierr)
    type(sphere_halo_t), intent(inout) :: h
    real(dp), intent(inout) :: values(:, :)
    PetscErrorCode, intent(out) :: ierr
    real(dp), allocatable :: send_buf(:, :), recv_buf(:, :)
    integer :: g
    call move(h, values, h%recv_local, h%recv_start, h%send_local, h%send_start, send_buf, recv_buf, ierr)
    if (ierr /= 0) return
    do g = 1, size(h%send_local)
      values(:, h%send_local(g)) = values(:, h%send_local(g)) + recv_buf(:, g)
    end do
  end subroutine sphere_halo_reverse

  !> Records of width w: send_count(m) of them to neighbour m (send_buf's columns grouped by
  !> neighbour, in h%neighbour's order); on return recv_buf (w, received) holds the neighbours'
  !> records, grouped in the same order. Collective among neighbours.
  subroutine sphere_halo_exchange(h, send_count, send_buf, recv_buf, ierr)
    type(sphere_halo_t), intent(inout) :: h
    integer, intent(in) :: send_count(:)
    real(dp), intent(in) :: send_buf(:, :)
    real(dp), allocatable, intent(out) :: recv_buf(:, :)
    PetscErrorCode, intent(out) :: ierr
    integer :: recv_count(size(h%neighbour)), m, nb, w
    integer :: offset(size(h%neighbour) + 1), roffset(size(h%neighbour) + 1)
    nb = size(h%neighbour)
    w = size(send_buf, 1)
    call exchange_counts(h, send_count, recv_count, ierr)
    if (ierr /= 0) return
    offset(1) = 0
    roffset(1) = 0
    do m = 1, nb
      offset(m + 1) = offset(m) + w * send_count(m)
      roffset(m + 1) = roffset(m) + w * recv_count(m)
    end do
    allocate(recv_buf(w, roffset(nb + 1) / max(1, w)))
    call swap(h, send_buf, offset, recv_buf, roffset, ierr)
    if (ierr /= 0) return
    h%bytes_sent = h%bytes_sent + 8_8 * offset(nb + 1)
  end subroutine sphere_halo_exchange

  ! The columns from(from_start(m):...) of values go to neighbour m, which receives them into its
  ! columns to(to_start(m):...) (here: recv_buf in that order).
  subroutine move(h, values, from, from_start, to, to_start, send_buf, recv_buf, ierr)
    type(sphere_halo_t), intent(inout) :: h
    real(dp), intent(in) :: values(:, :)
    integer, intent(in) :: from(:), from_start(:), to(:), to_start(:)
    real(dp), allocatable, intent(out) :: send_buf(:, :), recv_buf(:, :)
    PetscErrorCode, intent(out) :: ierr
    integer :: k, nb, m
    integer :: offset(size(h%neighbour) + 1), roffset(size(h%neighbour) + 1)
    k = size(values, 1)
    nb = size(h%neighbour)
    send_buf = values(:, from)
    allocate(recv_buf(k, size(to)))
    do m = 1, nb + 1
      offset(m) = k * (from_start(m) - 1)
      roffset(m) = k * (to_start(m) - 1)
    end do
    call swap(h, send_buf, offset, recv_buf, roffset, ierr)
    h%bytes_sent = h%bytes_sent + 8_8 * offset(nb + 1)
  end subroutine move

  ! One exchange with the neighbours: neighbour m gets send_buf(offset(m)+1:offset(m+1)) and its
  ! part arrives in recv_buf(roffset(m)+1:roffset(m+1)) (flat, any shape); returns when both are done.
  subroutine swap(h, send_buf, offset, recv_buf, roffset, ierr)
    type(sphere_halo_t), intent(in) :: h
    real(dp), intent(in), target :: send_buf(*)
    real(dp), intent(inout), target :: recv_buf(*)
    integer, intent(in) :: offset(:), roffset(:)
    PetscErrorCode, intent(out) :: ierr
    integer :: m, nb
    integer :: requests(2 * size(h%neighbour))
    nb = size(h%neighbour)
    ierr = 0
    do m = 1, nb
      call MPI_Irecv(recv_buf(roffset(m) + 1), roffset(m + 1) - roffset(m), MPI_DOUBLE_PRECISION, h%neighbour(m), &
                     TAG_DATA, PETSC_COMM_WORLD, requests(m), ierr)
      if (ierr /= 0) return
    end do
    do m = 1, nb
      call MPI_Isend(send_buf(offset(m) + 1), offset(m + 1) - offset(m), MPI_DOUBLE_PRECISION, h%neighbour(m), &
                     TAG_DATA, PETSC_COMM_WORLD, requests(nb + m), ierr)
      if (ierr /= 0) return
    end do
    call MPI_Waitall(2 * nb, requests, MPI_STATUSES_IGNORE, ierr)
  end subroutine swap

  ! How many records each neighbour will send: one integer each way per neighbour.
  subroutine exchange_counts(h, send_count, recv_count, ierr)
    type(sphere_halo_t), intent(inout) :: h
    integer, intent(in) :: send_count(:)
    integer, intent(out) :: recv_count(:)
    PetscErrorCode, intent(out) :: ierr
    integer :: m, nb
    integer :: requests(2 * size(h%neighbour))
    nb = size(h%neighbour)
    recv_count = 0
    ierr = 0
    do m = 1, nb
      call MPI_Irecv(recv_count(m), 1, MPI_INTEGER, h%neighbour(m), TAG_COUNT, PETSC_COMM_WORLD, requests(m), ierr)
      if (ierr /= 0) return
    end do
    do m = 1, nb
      call MPI_Isend(send_count(m), 1, MPI_INTEGER, h%neighbour(m), TAG_COUNT, PETSC_COMM_WORLD, requests(nb + m), ierr)
      if (ierr /= 0) return
    end do
    call MPI_Waitall(2 * nb, requests, MPI_STATUSES_IGNORE, ierr)
    h%bytes_sent = h%bytes_sent + 4_8 * nb
  end subroutine exchange_counts

end module mod_sphere_halo
