! The particle step on a rank's local set (issue 45; doc/DESIGN.md "Spheres held by their slab",
! doc/SCALING.md §3.1): lubrication dynamics, and since 2026-11-29 (evening) the resolved step too
! (mod_time_step: the slabs the grid's z-ranges, the fictitious domain's geometry, moments and
! update on the local set, each sphere's parts summed on its owner; ld_local_begin without a
! one-body model). Each rank holds the spheres whose centres are in its z-slab (its
! own) and the ghosts within reach of the slab (mod_sphere_halo), evaluates the contacts and the
! lubrication links of its own spheres, sets their block rows in the 6N system and gets back their
! velocities only; the ghosts' velocities and link counts come from their owners through the halo.
! The statistics sample the local set too (ld_local_statistics: the ranks' shares summed in one
! reduction of O(bins)).
!
! The local set is the state between steps: the positions advance on it (time_step), the ghosts'
! like their owners' from the same forwarded values. The sets are kept while no sphere has moved
! half the kernels' smallest skin along z since they were made; then, at the next step's start
! (ld_local_begin), the own spheres that left the slab go to their new owner with what they carry
! (velocities, the Adams-Bashforth history, external loads, radius), the ghosts are rebuilt, and the
! springs of the contacts go to the neighbours whose spheres they touch. No message of a step grows
! with the total number of spheres. The output takes each rank's share of the local sets
! (mod_time_step time_step_share: the series, the snapshots, the checkpoints, a failure's state).
! The first step takes the local set from the replicated particle state of the start (the deck,
! the packing or the checkpoint), which is then released: from then on a rank holds its own spheres
! and their ghosts only.
!
! With one rank, or without contacts and links (the block-diagonal one-body problem), the step keeps
! the replicated state (ld_local_t%active false). An owned sphere sees every contact and link in
! the order one rank has them (ascending global index), so its sums are bitwise one rank's; the
! distributed solve agrees to its tolerance (test_ld_rank_independence).
#include <petsc/finclude/petscsys.h>
module mod_ld_local
  use petscsys
  use mod_kinds, only: dp
  use mod_particles, only: particles_t, particles_init, particles_release
  use mod_sphere_halo, only: sphere_halo_t, sphere_halo_create, sphere_halo_migrate, sphere_halo_build, &
                             sphere_halo_forward, sphere_halo_exchange, sphere_halo_slab_of
  use mod_sorting, only: ascending_order, sorted_position
  use mod_contact, only: history_size, history_pack, history_unpack
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_set_local, particle_contacts_implicit_update
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_set_local, &
                                      particle_lubrication_links, LINKS_COUNT, LINKS_EVALUATE
  use mod_lubrication_dynamics, only: lubrication_dynamics_t, lubrication_dynamics_set_local
  use mod_particle_solver, only: particle_solver_t, particle_solver_set_local
  use mod_rheology, only: rheology_t, rheo_set_local, rheo_sample, rheo_sample_shares, rheo_sample_finish
  implicit none
  private
  public :: ld_local_t, ld_local_create, ld_local_begin, ld_local_contacts_agree, ld_local_contacts_update, &
            ld_local_forward_motion, ld_local_links, ld_local_statistics, ld_local_own_slot

  type :: ld_local_t
    logical :: active = .false.           ! the step runs on the local set
    logical :: live = .false.             ! the local set holds the state (from the first step on)
    type(sphere_halo_t) :: halo           ! own spheres and ghosts (ascending global index)
    type(particles_t) :: set              ! their state
    integer :: total = 0                  ! spheres of the whole system
    integer(kind=8) :: released = 0       ! bytes of the replicated particles released (the run's account)
    ! the sets are kept from step to step while no sphere has moved half the skin along z since
    ! they were made (ld_local_begin): skin, the smallest of the kernels' neighbour lists' [a]
    real(dp) :: skin = 0.0_dp             ! (the set's sets_made_z: its centres' z when the sets were made)
    logical :: kernels_told = .false.     ! the kernels hold the local set (their set_local)
    integer :: sets_made = 0              ! times the sets were made (the run's account)
    logical :: made = .false.             ! the last ld_local_begin made them (the caller's geometry follows)
  end type ld_local_t

  ! what a sphere carries to a new owner and its owner forwards to its ghosts (carried): velocity,
  ! omega, the last step's velocity (Adams-Bashforth), external force and torque, radius
  integer, parameter :: CARRIED = 16

contains

  !> Active on more than one rank when reach > 0: reach, the largest distance at which a sphere
  !> acts on another or on a grid face (the contacts' and the links' neighbour-list cut-offs, skin
  !> included; the fictitious domain's support plus half the skin) [a], skin the smallest of the
  !> neighbour lists' skins [a], and lz the box's period along z. edges (0:P), optional: the
  !> slabs' z-edges (the grid's z-ranges in the resolved step; default P equal slabs). Collective in
  !> name only.
  subroutine ld_local_create(loc, lz, reach, skin, edges)
    type(ld_local_t), intent(out) :: loc
    real(dp), intent(in) :: lz, reach, skin
    real(dp), intent(in), optional :: edges(0:)
    PetscMPIInt :: ranks
    PetscErrorCode :: ierr
    call MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr)
    loc%active = ranks > 1 .and. reach > 0.0_dp
    loc%skin = skin
    if (loc%active) call sphere_halo_create(loc%halo, lz, reach, edges)
  end subroutine ld_local_create

  !> The local set of the step: on the first step (and after a restart) taken from the replicated
  !> parts of the start, which are then released (particles_release: n, the radius, the motion and
  !> have_prev stay; after a restart on as many ranks the sets are the checkpoint's run's:
  !> parts%sets_made_z, so that the restart repeats its arithmetic bitwise), then kept from step
  !> to step while no sphere has moved half the skin along z since the sets were made (every
  !> sphere a rank's own spheres reach within a kernel's range is then still among its ghosts, and
  !> the ghosts, advanced like their owners from the same forwarded values, are their owners'
  !> copies: nothing to send), else made again from the last step's (carry_on: the own
  !> spheres that left the slab migrate with what they carry, the ghosts rebuilt and given their
  !> owners' values, the springs sent to the neighbours whose spheres they touch). When the sets
  !> are made, the contacts, the links, the one-body model, the solver and the statistics are told
  !> them (their set_local), the block rows numbered by slab (rank by rank, ascending global index
  !> within a rank, as mod_sphere_ownership), and the springs of the pairs with an own sphere kept.
  !> parts%have_prev (a reversal or a branch clears it) is the set's. Collective.
  subroutine ld_local_begin(loc, parts, solver, ierr, ld, contacts, lubrication, rheology)
    type(ld_local_t), intent(inout) :: loc
    type(particles_t), intent(inout) :: parts
    type(particle_solver_t), intent(inout) :: solver
    PetscErrorCode, intent(out) :: ierr
    type(lubrication_dynamics_t), intent(inout), optional :: ld
    type(particle_contacts_t), intent(inout), optional :: contacts
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    type(rheology_t), intent(inout), optional :: rheology
    real(dp), allocatable :: radii(:)
    integer, allocatable :: rows(:)
    logical :: keep

    ierr = 0
    loc%total = parts%n
    loc%made = .false.
    keep = .false.
    if (loc%live) then
      call sets_hold(loc, keep, ierr)
      if (ierr /= 0) return
      if (.not. loc%kernels_told) keep = .false.
      if (.not. keep) call carry_on(loc, ierr)
    else
      ! the sets the checkpoint's run held (if made for as many ranks), or new ones; then as on any
      ! step: made again if a sphere has moved half the skin since
      call take_replicated(loc, parts, ierr)
      if (ierr /= 0) return
      call particles_release(parts, loc%released)
      call sets_hold(loc, keep, ierr)
      if (ierr /= 0) return
      if (.not. keep) call carry_on(loc, ierr)
      keep = .false.                       ! (the kernels are told the sets)
    end if
    if (ierr /= 0) return
    loc%set%have_prev = parts%have_prev
    if (keep) return
    loc%live = .true.
    loc%made = .true.
    loc%sets_made = loc%sets_made + 1
    associate(h => loc%halo, s => loc%set)
      radii = s%radii / parts%radius
      call own_rows(loc, rows, ierr)
      if (ierr /= 0) return
      call particle_solver_set_local(solver, rows, h%is_owned, loc%total)
      if (present(ld)) call lubrication_dynamics_set_local(ld, radii)
      if (present(lubrication)) call particle_lubrication_set_local(lubrication, h%is_owned, radii)
      if (present(rheology)) call rheo_set_local(rheology, h%is_owned, radii)
      if (present(contacts)) then
        call keep_springs(loc, contacts, ierr)
        if (ierr /= 0) return
        call particle_contacts_set_local(contacts, h%id, h%is_owned, radii)
      end if
      loc%kernels_told = .true.
    end associate
  end subroutine ld_local_begin

  ! Whether the sets made last can serve this step (keep): no own sphere of any rank has moved half
  ! the skin along z since (the largest such move, one reduction). Collective.
  subroutine sets_hold(loc, keep, ierr)
    type(ld_local_t), intent(inout) :: loc
    logical, intent(out) :: keep
    PetscErrorCode, intent(out) :: ierr
    real(dp) :: moved, dz
    integer :: q
    moved = 0.0_dp
    associate(h => loc%halo, s => loc%set)
      do q = 1, s%n
        if (.not. h%is_owned(q)) cycle
        dz = s%position(3, q) - s%sets_made_z(q)
        moved = max(moved, abs(dz - h%lz * anint(dz / h%lz)))
      end do
    end associate
    call MPI_Allreduce(MPI_IN_PLACE, moved, 1, MPI_DOUBLE_PRECISION, MPI_MAX, PETSC_COMM_WORLD, ierr)
    keep = moved < 0.5_dp * loc%skin
  end subroutine sets_hold

  ! The local set taken from the replicated parts: own spheres by slab (no sphere moves between
  ! ranks: every rank holds every sphere), the ghosts within reach, the state of each copied. The
  ! slabs are those of each sphere's z when the sets were made (parts%sets_made_z, from a
  ! checkpoint of a run on as many ranks: the same owners and ghosts as that run held), else of its
  ! position. Collective.
  subroutine take_replicated(loc, parts, ierr)
    type(ld_local_t), intent(inout) :: loc
    type(particles_t), intent(in) :: parts
    PetscErrorCode, intent(out) :: ierr
    integer, allocatable :: id(:)
    real(dp), allocatable :: x(:, :), data(:, :), z_made(:)
    integer :: i
    z_made = parts%position(3, :)
    if (allocated(parts%sets_made_z) .and. parts%sets_made_ranks == loc%halo%ranks) z_made = parts%sets_made_z
    id = pack([(i, i = 1, parts%n)], [(sphere_halo_slab_of(loc%halo, z_made(i)) == loc%halo%rank, i = 1, parts%n)])
    x = parts%position(:, id)
    x(3, :) = z_made(id)
    allocate(data(0, size(id)))
    call sphere_halo_migrate(loc%halo, id, x, data, ierr)
    if (ierr /= 0) return
    call sphere_halo_build(loc%halo, x, ierr)
    if (ierr /= 0) return
    call particles_init(loc%set, size(loc%halo%id), parts%radius, parts%motion)
    loc%set%position = parts%position(:, loc%halo%id)
    loc%set%sets_made_z = z_made(loc%halo%id)
    loc%set%sets_made_ranks = loc%halo%ranks
    call put_cargo(loc%set, cargo(parts, loc%halo%id))
  end subroutine take_replicated

  ! The local set of the last step carried on to the positions it advanced to: the own spheres that
  ! left the slab to the rank of their new slab (a neighbour's) with what they carry, the ghosts
  ! rebuilt around the own spheres and given their owners' values. Collective.
  subroutine carry_on(loc, ierr)
    type(ld_local_t), intent(inout) :: loc
    PetscErrorCode, intent(out) :: ierr
    integer, allocatable :: own(:), id(:)
    real(dp), allocatable :: x(:, :), data(:, :), values(:, :)
    real(dp) :: radius
    integer :: motion, q
    associate(h => loc%halo, s => loc%set)
      own = pack([(q, q = 1, s%n)], h%is_owned)
      id = h%id(own)
      x = s%position(:, own)
      data = cargo(s, own)
      radius = s%radius
      motion = s%motion
      call sphere_halo_migrate(h, id, x, data, ierr)
      if (ierr /= 0) return
      call sphere_halo_build(h, x, ierr)
      if (ierr /= 0) return
      ! the own spheres' values into their slots (ascending global index, as data), the ghosts' from
      ! their owners
      allocate(values(CARRIED, size(h%id)))
      values = 0.0_dp
      values(:, pack([(q, q = 1, size(h%id))], h%is_owned)) = data
      call sphere_halo_forward(h, values, ierr)
      if (ierr /= 0) return
      call particles_init(s, size(h%id), radius, motion)
      s%position = x
      s%sets_made_z = x(3, :)
      s%sets_made_ranks = h%ranks
      call put_cargo(s, values)
    end associate
  end subroutine carry_on

  ! What the spheres idx of p carry (CARRIED values each).
  function cargo(p, idx) result(data)
    type(particles_t), intent(in) :: p
    integer, intent(in) :: idx(:)
    real(dp) :: data(CARRIED, size(idx))
    data(1:3, :) = p%velocity(:, idx)
    data(4:6, :) = p%omega(:, idx)
    data(7:9, :) = p%velocity_prev(:, idx)
    data(10:12, :) = p%external_force(:, idx)
    data(13:15, :) = p%external_torque(:, idx)
    data(16, :) = p%radii(idx)
  end function cargo

  ! The inverse of cargo, for every sphere of p.
  subroutine put_cargo(p, data)
    type(particles_t), intent(inout) :: p
    real(dp), intent(in) :: data(:, :)
    p%velocity = data(1:3, :)
    p%omega = data(4:6, :)
    p%velocity_prev = data(7:9, :)
    p%external_force = data(10:12, :)
    p%external_torque = data(13:15, :)
    p%radii = data(16, :)
  end subroutine put_cargo

  ! The 0-based block rows of the local set: the own spheres' numbered after those of the ranks
  ! before (an exclusive prefix sum of the own counts), the ghosts' from their owners. Collective.
  subroutine own_rows(loc, rows, ierr)
    type(ld_local_t), intent(inout) :: loc
    integer, allocatable, intent(out) :: rows(:)
    PetscErrorCode, intent(out) :: ierr
    integer :: first, k, q
    real(dp), allocatable :: values(:, :)
    associate(h => loc%halo)
      first = 0
      call MPI_Exscan(h%owned, first, 1, MPI_INTEGER, MPI_SUM, PETSC_COMM_WORLD, ierr)
      if (ierr /= 0) return
      if (h%rank == 0) first = 0           ! (MPI_Exscan leaves rank 0's undefined)
      allocate(values(1, size(h%id)))
      values = 0.0_dp
      k = 0
      do q = 1, size(h%id)
        if (.not. h%is_owned(q)) cycle
        values(1, q) = real(first + k, dp)
        k = k + 1
      end do
      call sphere_halo_forward(h, values, ierr)
      if (ierr /= 0) return
      rows = nint(values(1, :))
    end associate
  end subroutine own_rows

  ! The contacts' springs after the local set changed: each rank sends a neighbour the springs it
  ! holds of the pairs with a sphere that neighbour owns (a ghost received from it: a sphere that
  ! moved to it is one, since it moved less than the reach), then keeps those of the pairs with an
  ! own sphere, each pair once (a pair across a face comes from both of its ranks, with the same
  ! spring: both evaluated it from the same values). Collective among neighbours.
  subroutine keep_springs(loc, contacts, ierr)
    type(ld_local_t), intent(inout) :: loc
    type(particle_contacts_t), intent(inout) :: contacts
    PetscErrorCode, intent(out) :: ierr
    integer, allocatable :: keys(:, :), send_count(:), theirs(:), picked(:), order(:), new_keys(:, :)
    real(dp), allocatable :: ups(:, :), send(:, :), received(:, :), new_ups(:, :)
    integer :: k, np_hist, m, i, j, kept, info
    associate(h => loc%halo)
      k = history_size(contacts%history)
      allocate(keys(2, k), ups(3, k))
      np_hist = loc%total
      if (k > 0) call history_pack(contacts%history, np_hist, keys, ups)
      allocate(send_count(size(h%neighbour)), picked(0))
      do m = 1, size(h%neighbour)
        ! the global indices of the ghosts received from neighbour m, ascending
        theirs = h%id(h%recv_local(h%recv_start(m):h%recv_start(m + 1) - 1))
        picked = [picked, pack([(i, i = 1, k)], [(sorted_position(theirs, keys(1, i)) > 0 .or. &
                                                 sorted_position(theirs, keys(2, i)) > 0, i = 1, k)])]
        send_count(m) = size(picked) - sum(send_count(1:m - 1))
      end do
      allocate(send(5, size(picked)))
      do j = 1, size(picked)
        send(:, j) = [real(keys(:, picked(j)), dp), ups(:, picked(j))]
      end do
      call sphere_halo_exchange(h, send_count, send, received, ierr)
      if (ierr /= 0) return
      keys = reshape([keys, nint(received(1:2, :))], [2, k + size(received, 2)])
      ups = reshape([ups, received(3:5, :)], [3, k + size(received, 2)])
      ! the pairs with an own sphere, ordered by (first, second) sphere, each once
      kept = 0
      do i = 1, size(keys, 2)
        if (.not. (owns(loc, keys(1, i)) .or. owns(loc, keys(2, i)))) cycle
        kept = kept + 1
        keys(:, kept) = keys(:, i)
        ups(:, kept) = ups(:, i)
      end do
      order = ascending_order(keys(2, 1:kept))
      order = order(ascending_order(keys(1, order)))
      allocate(new_keys(2, kept), new_ups(3, kept))
      k = 0
      do i = 1, kept
        if (i > 1) then
          if (all(keys(:, order(i)) == keys(:, order(i - 1)))) cycle
        end if
        k = k + 1
        new_keys(:, k) = keys(:, order(i))
        new_ups(:, k) = ups(:, order(i))
      end do
      call history_unpack(contacts%history, loc%total, k, new_keys, new_ups, info)
      if (info /= 0) then
        ierr = 1
        SETERRQ(PETSC_COMM_SELF, ierr, 'the springs kept on a rank do not form a contact history')
      end if
    end associate
  end subroutine keep_springs

  !> After the contacts of the step on the local set: their diagnostics made the whole system's
  !> (counts summed, each pair counted once; the largest overlap and its pair; the walls' forces
  !> summed) and info the same on every rank (the largest). Collective.
  subroutine ld_local_contacts_agree(contacts, info, ierr)
    type(particle_contacts_t), intent(inout) :: contacts
    integer, intent(inout) :: info
    PetscErrorCode, intent(out) :: ierr
    integer :: counts(4)
    real(dp) :: largest(2), mine(2)
    associate(st => contacts%stats)
      counts = [st%pair_contacts, st%wall_contacts, st%sliding, info]
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, counts(1:3), 3, MPI_INTEGER, MPI_SUM, PETSC_COMM_WORLD, ierr))
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, counts(4), 1, MPI_INTEGER, MPI_MAX, PETSC_COMM_WORLD, ierr))
      st%pair_contacts = counts(1)
      st%wall_contacts = counts(2)
      st%sliding = counts(3)
      info = counts(4)
      ! the largest overlap and the largest normal force; the pair of the largest overlap from the
      ! rank that found it (the lowest such rank)
      mine = [st%max_overlap, st%max_normal_force]
      largest = mine
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, largest, 2, MPI_DOUBLE_PRECISION, MPI_MAX, PETSC_COMM_WORLD, ierr))
      if (mine(1) /= largest(1)) st%max_overlap_pair = huge(1)
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, st%max_overlap_pair, 2, MPI_INTEGER, MPI_MIN, PETSC_COMM_WORLD, ierr))
      st%max_overlap = largest(1)
      st%max_normal_force = largest(2)
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, st%wall_force, 6, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr))
      contacts%wall_force = st%wall_force
      contacts%max_overlap = st%max_overlap * contacts%params%h_r
      if (contacts%params%h_r <= 0) contacts%max_overlap = st%max_overlap * contacts%params%a
    end associate
  end subroutine ld_local_contacts_agree

  !> The links of the local set at its positions: the candidates and each sphere's count of links
  !> (the ghosts' counts from their owners, who see all their links), then the links with an own
  !> sphere; the smallest gap, a failed link and the pair links' counts made the whole system's
  !> (as mod_lubrication_links). offset: the Lees-Edwards offset. Collective.
  subroutine ld_local_links(loc, pl, ierr, offset)
    type(ld_local_t), intent(inout) :: loc
    type(particle_lubrication_t), intent(inout) :: pl
    PetscErrorCode, intent(out) :: ierr
    real(dp), intent(in), optional :: offset
    real(dp), allocatable :: counts(:, :)
    integer :: most(3)
    ierr = 0
    call particle_lubrication_links(pl, loc%set%position, offset=offset, phase=LINKS_COUNT)
    if (allocated(pl%links_of)) then
      allocate(counts(1, loc%set%n))
      counts(1, :) = real(pl%links_of, dp)
      call sphere_halo_forward(loc%halo, counts, ierr)
      if (ierr /= 0) return
      pl%links_of = nint(counts(1, :))
    end if
    call particle_lubrication_links(pl, loc%set%position, offset=offset, phase=LINKS_EVALUATE)
    ! each pair link counted by the owner of its first sphere
    pl%npairs_total = count(loc%halo%is_owned(pl%pair(1, 1:pl%npairs)))
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, pl%npairs_total, 1, MPI_INTEGER, MPI_SUM, PETSC_COMM_WORLD, ierr))
    ! the wall links: each on the owner of its sphere
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, pl%nwalls_total, 1, MPI_INTEGER, MPI_SUM, PETSC_COMM_WORLD, ierr))
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, pl%min_gap, 1, MPI_DOUBLE_PRECISION, MPI_MIN, PETSC_COMM_WORLD, ierr))
    ! a failed link named by global index (the largest, so that every rank names the same one)
    most = [0, 0, pl%npairs]
    if (pl%failed_link(1) /= 0) then
      most(1) = loc%halo%id(pl%failed_link(1))
      if (pl%failed_link(2) /= 0) most(2) = loc%halo%id(pl%failed_link(2))
    end if
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, most, 3, MPI_INTEGER, MPI_MAX, PETSC_COMM_WORLD, ierr))
    pl%failed_link = most(1:2)
    pl%npairs_most = most(3)
  end subroutine ld_local_links

  !> The contacts' implicit update (particle_contacts_implicit_update) on a local set: the walls'
  !> forces on the spheres made the whole system's again. Before it they are (ld_local_contacts_agree
  !> summed the explicit forces), and the update adds the implicit part of the own spheres' wall
  !> contacts only: those parts are summed over the ranks (6 doubles). Collective.
  subroutine ld_local_contacts_update(contacts, velocity, omega, ierr)
    type(particle_contacts_t), intent(inout) :: contacts
    real(dp), intent(in) :: velocity(:, :), omega(:, :)
    PetscErrorCode, intent(out) :: ierr
    real(dp) :: before(3, 2), part(3, 2)
    before = contacts%wall_force
    call particle_contacts_implicit_update(contacts, velocity, omega)
    part = contacts%wall_force - before
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, part, 6, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr))
    contacts%wall_force = before + part
  end subroutine ld_local_contacts_update

  !> The own spheres' velocities and angular velocities of the local set p (held by halo) sent to
  !> their ghosts. Collective among neighbours.
  subroutine ld_local_forward_motion(halo, p, ierr)
    type(sphere_halo_t), intent(inout) :: halo
    type(particles_t), intent(inout) :: p
    PetscErrorCode, intent(out) :: ierr
    real(dp), allocatable :: v(:, :)
    allocate(v(6, p%n))
    v(1:3, :) = p%velocity
    v(4:6, :) = p%omega
    call sphere_halo_forward(halo, v, ierr)
    if (ierr /= 0) return
    p%velocity = v(1:3, :)
    p%omega = v(4:6, :)
  end subroutine ld_local_forward_motion

  !> The statistics' sample of the configuration on the local set (mod_rheology's local set: sums
  !> over the own spheres, each pair by the owner of its reference, the ghosts within reach of the
  !> farthest shell, which ld_local_create's reach includes), the ranks' shares summed and the
  !> sample finished: one rank's sample to round-off, one reduction of O(bins), not O(N).
  !> stresslet_contact: the contacts' stresslets of the local set (absent: no contacts); offset:
  !> the Lees-Edwards offset. Collective.
  subroutine ld_local_statistics(loc, rheology, ierr, stresslet_contact, offset)
    type(ld_local_t), intent(inout) :: loc
    type(rheology_t), intent(inout) :: rheology
    PetscErrorCode, intent(out) :: ierr
    real(dp), intent(in), optional :: stresslet_contact(:, :, :)
    real(dp), intent(in), optional :: offset
    real(dp), allocatable :: shares(:)
    real(dp) :: min_gap
    ! (ld_local_begin told the statistics the local set)
    associate(s => loc%set)
      call rheo_sample(rheology, s%position, s%velocity, s%stresslet_hydro, stresslet_contact, offset)
    end associate
    shares = rheo_sample_shares(rheology)
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, shares, size(shares), MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr))
    min_gap = rheology%min_pair_gap
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, min_gap, 1, MPI_DOUBLE_PRECISION, MPI_MIN, PETSC_COMM_WORLD, ierr))
    call rheo_sample_finish(rheology, shares, min_gap)
  end subroutine ld_local_statistics

  !> The slot in the local set of the own sphere of global index g; 0 when g is not an own sphere.
  pure integer function ld_local_own_slot(loc, g) result(slot)
    type(ld_local_t), intent(in) :: loc
    integer, intent(in) :: g
    slot = sorted_position(loc%halo%id, g)
    if (slot > 0) then
      if (.not. loc%halo%is_owned(slot)) slot = 0
    end if
  end function ld_local_own_slot

  ! Whether the sphere of global index g is one of this rank's own (false for a wall's id, < 0).
  pure logical function owns(loc, g)
    type(ld_local_t), intent(in) :: loc
    integer, intent(in) :: g
    owns = ld_local_own_slot(loc, g) > 0
  end function owns

end module mod_ld_local
