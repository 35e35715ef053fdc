! The lubrication-dynamics step on a rank's local set (issue 45; doc/DESIGN.md "Spheres held by
! their slab", doc/SCALING.md §3.1): each rank evaluates the contacts and the lubrication links of
! the spheres whose centres are in its z-slab (its own) with the ghosts within reach of the slab
! (mod_sphere_halo), sets the block rows of its own spheres in the 6N system, and gets back the
! velocities of its own spheres only; the ghosts' velocities and link counts come from their owners
! through the halo. Nothing of the step's kernels is evaluated for every sphere on every rank, and
! neither the links' sums nor the 6N solution is gathered in the step. The statistics sample the
! local set too (ld_local_statistics: the ranks' shares summed in one reduction of O(bins)).
!
! The particle state itself is still replicated between steps (the view: positions, velocities,
! the hydrodynamic and contact results, the springs), because the positions advance there and the
! output and the checkpoints read it: ld_local_begin takes each rank's local set from it, ld_local_end gathers the
! own spheres' velocities (7 doubles a sphere) and springs (5 a spring) back into it every step, and
! their hydrodynamic, contact and link results (45 doubles) only when the output reads them
! (RESULTS_NOW, or ld_local_complete_view). Those gathers are the step's collectives of size N; they
! go once the output reads the own spheres and the state migrates with them (doc/SCALING.md §3.1).
!
! With one rank, or without contacts and links (the block-diagonal one-body problem), the step keeps
! the replicated state (ld_local_t%active false). An owned sphere sees every contact and link in
! the order one rank has them (ascending global index), so its sums are bitwise one rank's; the
! distributed solve agrees to its tolerance (test_ld_rank_independence).
#include <petsc/finclude/petscsys.h>
module mod_ld_local
  use petscsys
  use mod_kinds, only: dp
  use mod_particles, only: particles_t, particles_init
  use mod_sphere_halo, only: sphere_halo_t, sphere_halo_create, sphere_halo_migrate, sphere_halo_build, &
                             sphere_halo_forward, sphere_halo_slab_of
  use mod_sphere_ownership, only: sphere_ownership_t, sphere_ownership_by_slab
  use mod_contact, only: history_size, history_pack, history_unpack
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_set_local
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_set_local, &
                                      particle_lubrication_links, LINKS_COUNT, LINKS_EVALUATE
  use mod_lubrication_dynamics, only: lubrication_dynamics_t, lubrication_dynamics_set_local
  use mod_particle_solver, only: particle_solver_t, particle_solver_set_local
  use mod_rheology, only: rheology_t, rheo_set_local, rheo_sample, rheo_sample_shares, rheo_sample_finish
  implicit none
  private
  public :: ld_local_t, ld_local_create, ld_local_begin, ld_local_contacts_agree, ld_local_links, &
            ld_local_forward_velocities, ld_local_statistics, ld_local_end, ld_local_complete_view

  type :: ld_local_t
    logical :: active = .false.           ! the step runs on the local set
    type(sphere_halo_t) :: halo           ! own spheres and ghosts (ascending global index)
    type(particles_t) :: set              ! their state during the step
    integer :: total = 0                  ! spheres of the whole system
    ! the own spheres' results of the last step not yet in the view (ld_local_end, RESULTS_LATER)
    real(dp), allocatable :: pending(:, :)
  end type ld_local_t

  ! what ld_local_end does with the step's results (ld_local_end)
  integer, parameter, public :: RESULTS_NOW = 1, RESULTS_LATER = 2, RESULTS_NONE = 3

  ! the values per own sphere that ld_local_end gathers into the view (after its global index):
  ! velocity, omega, hydrodynamic force, torque, stresslet; the contacts' force, torque,
  ! stresslet; the links' force, torque, stresslet
  integer, parameter :: GATHERED = 51

contains

  !> Active on more than one rank when the run has contacts or lubrication links: reach, the
  !> largest of their neighbour lists' cut-offs (skin included) [a], and lz the box's period along z.
  !> Collective in name only.
  subroutine ld_local_create(loc, lz, reach)
    type(ld_local_t), intent(out) :: loc
    real(dp), intent(in) :: lz, reach
    PetscMPIInt :: ranks
    PetscErrorCode :: ierr
    call MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr)
    loc%active = ranks > 1 .and. reach > 0.0_dp
    if (loc%active) call sphere_halo_create(loc%halo, lz, reach)
  end subroutine ld_local_create

  !> The local set of the configuration in parts (the view): own spheres by slab, ghosts within
  !> reach through the halo, their state copied from the view; the contacts, the links, the
  !> one-body model, the solver and the statistics told the local set (their set_local), the block
  !> rows numbered by slab (mod_sphere_ownership), and the springs of the pairs with an own sphere
  !> kept. Collective.
  subroutine ld_local_begin(loc, parts, ld, solver, ierr, contacts, lubrication, rheology)
    type(ld_local_t), intent(inout) :: loc
    type(particles_t), intent(in) :: parts
    type(lubrication_dynamics_t), intent(inout) :: ld
    type(particle_solver_t), intent(inout) :: solver
    PetscErrorCode, intent(out) :: ierr
    type(particle_contacts_t), intent(inout), optional :: contacts
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    type(rheology_t), intent(inout), optional :: rheology
    integer, allocatable :: id(:), keys(:, :)
    real(dp), allocatable :: x(:, :), data(:, :), springs(:, :)
    real(dp), allocatable :: radii(:)
    type(sphere_ownership_t) :: o
    integer :: i, n, np_hist, k, kept, info

    ierr = 0
    loc%total = parts%n
    ! own spheres: those of this rank's slab (no sphere moves between ranks: the view is everywhere)
    id = pack([(i, i = 1, parts%n)], [(sphere_halo_slab_of(loc%halo, parts%position(3, i)) == loc%halo%rank, &
                                       i = 1, parts%n)])
    x = parts%position(:, id)
    allocate(data(0, size(id)))
    call sphere_halo_migrate(loc%halo, id, x, data, ierr)
    if (ierr /= 0) return
    call sphere_halo_build(loc%halo, x, ierr)
    if (ierr /= 0) return
    associate(h => loc%halo, s => loc%set)
      n = h%owned + h%ghosts
      call particles_init(s, n, parts%radius, parts%motion)
      s%radii = parts%radii(h%id)
      s%position = x
      s%velocity = parts%velocity(:, h%id)
      s%omega = parts%omega(:, h%id)
      s%velocity_prev = parts%velocity_prev(:, h%id)
      s%have_prev = parts%have_prev
      s%external_force = parts%external_force(:, h%id)
      s%external_torque = parts%external_torque(:, h%id)
      radii = s%radii / parts%radius
      ! the rows of the 6N system: numbered by slab, in ascending global index within a slab
      o = sphere_ownership_by_slab(parts%position, loc%halo%lz, h%ranks)
      call particle_solver_set_local(solver, o%row(h%id), h%is_owned, parts%n)
      call lubrication_dynamics_set_local(ld, radii)
      if (present(lubrication)) call particle_lubrication_set_local(lubrication, h%is_owned, radii)
      if (present(rheology)) call rheo_set_local(rheology, h%is_owned, radii)
      if (present(contacts)) then
        ! the springs of the pairs with an own sphere (the view holds every spring)
        k = history_size(contacts%history)
        allocate(keys(2, k), springs(3, k))
        call history_pack(contacts%history, np_hist, keys, springs)
        kept = 0
        do i = 1, k
          if (owns(loc, keys(1, i)) .or. owns(loc, keys(2, i))) then
            kept = kept + 1
            keys(:, kept) = keys(:, i)
            springs(:, kept) = springs(:, i)
          end if
        end do
        if (k > 0) call history_unpack(contacts%history, np_hist, kept, keys, springs, info)
        call particle_contacts_set_local(contacts, h%id, h%is_owned, radii)
      end if
    end associate
  end subroutine ld_local_begin

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

  !> After the solve: the own spheres' velocities and angular velocities sent to their ghosts.
  !> Collective among neighbours.
  subroutine ld_local_forward_velocities(loc, ierr)
    type(ld_local_t), intent(inout) :: loc
    PetscErrorCode, intent(out) :: ierr
    real(dp), allocatable :: v(:, :)
    allocate(v(6, loc%set%n))
    v(1:3, :) = loc%set%velocity
    v(4:6, :) = loc%set%omega
    call sphere_halo_forward(loc%halo, v, ierr)
    if (ierr /= 0) return
    loc%set%velocity = v(1:3, :)
    loc%set%omega = v(4:6, :)
  end subroutine ld_local_forward_velocities

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

  !> The end of the step on the local set, into the view (Collective):
  !>  - the own spheres' velocities and angular velocities gathered into parts (the next step and
  !>    the guard read them; 56 B a sphere), and the springs of the pairs whose first sphere is own
  !>    into the contacts' history (the next step's local sets and the checkpoints take them);
  !>  - results: RESULTS_NOW, the own spheres' hydrodynamic force, torque, stresslet, and the
  !>    contacts' and the links' per-sphere force, torque, stresslet gathered too (the output reads
  !>    them: a series record, a snapshot, a checkpoint); RESULTS_LATER, kept on their owner until
  !>    ld_local_complete_view gathers them (a step without output sends none of them);
  !>    RESULTS_NONE, a step that failed before its solve: those of the last step stay pending.
  !> The contacts and the links are left set for every sphere (set_local of the view), their
  !> per-sphere arrays zero until gathered; the links' wall forces summed over the ranks.
  subroutine ld_local_end(loc, parts, results, ierr, contacts, lubrication)
    type(ld_local_t), intent(inout) :: loc
    type(particles_t), intent(inout) :: parts
    integer, intent(in) :: results
    PetscErrorCode, intent(out) :: ierr
    type(particle_contacts_t), intent(inout), optional :: contacts
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    real(dp), allocatable :: rows(:, :), all(:, :), springs(:, :), all_springs(:, :), ups(:, :)
    integer, allocatable :: keys(:, :)
    integer :: q, k, np_hist, nsprings, i, info
    logical, allocatable :: every(:)

    ierr = 0
    associate(h => loc%halo, s => loc%set)
      if (results /= RESULTS_NONE) then
        ! this step's results of the own spheres, one row each (after the global index)
        allocate(rows(GATHERED + 1, h%owned))
        k = 0
        do q = 1, s%n
          if (.not. h%is_owned(q)) cycle
          k = k + 1
          rows(1, k) = real(h%id(q), dp)
          rows(2:4, k) = s%velocity(:, q)
          rows(5:7, k) = s%omega(:, q)
          rows(8:10, k) = s%force_hydro(:, q)
          rows(11:13, k) = s%torque_hydro(:, q)
          rows(14:22, k) = reshape(s%stresslet_hydro(:, :, q), [9])
          rows(23:52, k) = 0.0_dp
          if (present(contacts)) then
            rows(23:25, k) = contacts%force(:, q)
            rows(26:28, k) = contacts%torque(:, q)
            rows(29:37, k) = reshape(contacts%stresslet(:, :, q), [9])
          end if
          if (present(lubrication)) then
            rows(38:40, k) = lubrication%force(:, q)
            rows(41:43, k) = lubrication%torque(:, q)
            rows(44:52, k) = reshape(lubrication%stresslet(:, :, q), [9])
          end if
        end do
        call move_alloc(rows, loc%pending)
      end if
      if (results == RESULTS_NOW) then
        PetscCall(gather_rows(loc%pending, all, ierr))
        deallocate(loc%pending)
      else
        ! the velocities now (of this step, or unchanged after a failed one), the rest later
        allocate(rows(7, h%owned))
        k = 0
        do q = 1, s%n
          if (.not. h%is_owned(q)) cycle
          k = k + 1
          rows(:, k) = [real(h%id(q), dp), s%velocity(:, q), s%omega(:, q)]
        end do
        PetscCall(gather_rows(rows, all, ierr))
      end if
      parts%velocity(:, nint(all(1, :))) = all(2:4, :)
      parts%omega(:, nint(all(1, :))) = all(5:7, :)
      allocate(every(loc%total))
      every = .true.
      if (present(lubrication)) then
        PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, lubrication%wall_force, 6, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr))
        call particle_lubrication_set_local(lubrication, every, parts%radii / parts%radius)
        deallocate(lubrication%owned)
      end if
      if (present(contacts)) then
        ! the springs of the pairs whose first sphere is own (5 values each: the pair, the spring)
        nsprings = history_size(contacts%history)
        allocate(keys(2, nsprings), ups(3, nsprings), springs(5, nsprings))
        if (nsprings > 0) call history_pack(contacts%history, np_hist, keys, ups)
        k = 0
        do i = 1, nsprings
          if (.not. owns(loc, keys(1, i))) cycle
          k = k + 1
          springs(:, k) = [real(keys(:, i), dp), ups(:, i)]
        end do
        PetscCall(gather_rows(springs(:, 1:k), all_springs, ierr))
        nsprings = size(all_springs, 2)
        call particle_contacts_set_local(contacts, [(i, i = 1, loc%total)], every, parts%radii / parts%radius)
        deallocate(contacts%ids, contacts%owned)
        if (contacts%params%mu_d > 0) then
          call history_unpack(contacts%history, loc%total, nsprings, nint(all_springs(1:2, :)), all_springs(3:5, :), info)
          if (info /= 0) then
            ierr = 1
            SETERRQ(PETSC_COMM_SELF, ierr, 'the springs gathered from the ranks do not form a history')
          end if
        end if
      end if
    end associate
    if (results == RESULTS_NOW) call put_results(all, parts, contacts, lubrication)
  end subroutine ld_local_end

  !> The results ld_local_end kept on their owners (RESULTS_LATER or RESULTS_NONE), gathered into
  !> the view: parts' hydrodynamic force, torque, stresslet, the contacts' and the links' per-sphere
  !> arrays. Nothing when none is pending (loc%pending is the same on every rank). Called before the
  !> output reads them outside its cadence: a failure, the end of the run. Collective.
  subroutine ld_local_complete_view(loc, parts, ierr, contacts, lubrication)
    type(ld_local_t), intent(inout) :: loc
    type(particles_t), intent(inout) :: parts
    PetscErrorCode, intent(out) :: ierr
    type(particle_contacts_t), intent(inout), optional :: contacts
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    real(dp), allocatable :: all(:, :)
    ierr = 0
    if (.not. allocated(loc%pending)) return
    PetscCall(gather_rows(loc%pending, all, ierr))
    deallocate(loc%pending)
    call put_results(all, parts, contacts, lubrication)
  end subroutine ld_local_complete_view

  ! Whether the sphere of global index g is one of this rank's own (a bisection of the local set's
  ! ascending indices; false for a wall's id, < 0).
  pure logical function owns(loc, g)
    type(ld_local_t), intent(in) :: loc
    integer, intent(in) :: g
    integer :: lo, hi, mid
    owns = .false.
    lo = 1
    hi = size(loc%halo%id)
    do while (lo <= hi)
      mid = (lo + hi) / 2
      if (loc%halo%id(mid) == g) then
        owns = loc%halo%is_owned(mid)
        return
      else if (loc%halo%id(mid) < g) then
        lo = mid + 1
      else
        hi = mid - 1
      end if
    end do
  end function owns

  ! The rows (k, m) of every rank, one after the other (rank order), on every rank. Collective.
  subroutine gather_rows(rows, all, ierr)
    real(dp), intent(in) :: rows(:, :)
    real(dp), allocatable, intent(out) :: all(:, :)
    PetscErrorCode, intent(out) :: ierr
    integer, allocatable :: counts(:), displs(:)
    integer :: r
    PetscMPIInt :: ranks
    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr))
    allocate(counts(ranks), displs(ranks))
    PetscCallMPI(MPI_Allgather(size(rows), 1, MPI_INTEGER, counts, 1, MPI_INTEGER, PETSC_COMM_WORLD, ierr))
    displs(1) = 0
    do r = 2, ranks
      displs(r) = displs(r - 1) + counts(r - 1)
    end do
    allocate(all(size(rows, 1), sum(counts) / max(1, size(rows, 1))))
    PetscCallMPI(MPI_Allgatherv(rows, size(rows), MPI_DOUBLE_PRECISION, all, counts, displs, MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, ierr))
  end subroutine gather_rows

  ! The gathered rows of ld_local_end (every sphere's) into the view's per-sphere results.
  subroutine put_results(all, parts, contacts, lubrication)
    real(dp), intent(in) :: all(:, :)
    type(particles_t), intent(inout) :: parts
    type(particle_contacts_t), intent(inout), optional :: contacts
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    integer, allocatable :: id(:)
    integer :: n
    id = nint(all(1, :))
    n = size(id)
    parts%force_hydro(:, id) = all(8:10, :)
    parts%torque_hydro(:, id) = all(11:13, :)
    parts%stresslet_hydro(:, :, id) = reshape(all(14:22, :), [3, 3, n])
    if (present(contacts)) then
      contacts%force(:, id) = all(23:25, :)
      contacts%torque(:, id) = all(26:28, :)
      contacts%stresslet(:, :, id) = reshape(all(29:37, :), [3, 3, n])
    end if
    if (present(lubrication)) then
      lubrication%force(:, id) = all(38:40, :)
      lubrication%torque(:, id) = all(41:43, :)
      lubrication%stresslet(:, :, id) = reshape(all(44:52, :), [3, 3, n])
    end if
  end subroutine put_results

end module mod_ld_local
