! Lubrication in the particle time step (doc/LUBRICATION.md): the model, the neighbour list of
! lubricating pairs and sphere-wall links, and per step the 6x6 / 12x12 blocks that the implicit
! particle system takes (doc/METHOD.md §3.2 equation (1)) and the corrections once the velocities are
! known. Pure: no PETSc, MPI or files. Particle data is replicated; on several ranks each evaluates
! the links of a set of spheres (particle_lubrication_links' owned) and mod_lubrication_links
! combines what the ranks need of them.
!
! The undisturbed flow is the imposed shear of the Couette cell: U_inf = shear_rate (y - Ly/2) e_x,
! Om_inf = -shear_rate/2 e_z, E_inf = shear_rate/2 (e_x e_y + e_y e_x); at rest in a periodic box.
! The same shear with Lees-Edwards boundaries (mod_lees_edwards, lubrication dynamics only): a pair
! across the sliding boundary is taken with le_separation's image of j, and U_inf of j at its own
! centre, since the image's velocity and its undisturbed velocity differ by the same
! s gamma_dot Ly e_x (the block acts on U - U_inf, doc/METHOD.md §5.1).
! Model 'exact' (lubrication dynamics): the blocks R_2B - R_1B are clipped at a floor per link,
! -(1/2) min(6 pi eta a, 8 pi eta a^3) / max(z_i, z_j), z the links (pairs and walls) of each sphere
! this step: the links of a sphere then lower the spectrum of its one-body block by at most half,
! so the 6N system of mod_lubrication_dynamics stays positive definite, and an isolated pair,
! whose R_2B is positive definite, keeps its exact block (its lowest eigenvalue, ~-0.36 x 6 pi
! eta a at contact, is above the floor -3 pi eta a).
! Spheres of several sizes (particle_lubrication_create's radii; models 'exact' and 'full',
! doc/LUBRICATION.md "Spheres of several sizes" and "Tables for mixtures"): a pair's gap is
! xi = 2r/(a_i + a_j) - 2 (over the mean radius, as Jeffrey & Onishi's), its blocks the sized ones
! of mod_resistance_blocks at lambda = a_j/a_i minus each sphere's one-body part (and, 'full',
! minus the resolved part of the table of its two species), the outer cut-off applies to xi; a
! wall link takes the wall functions at the sphere's own gap over its own radius, scaled by its
! radius ('full': minus the wall part of its species' table). Model 'exact': the floor of a pair
! block is in the metric of the one-body blocks (clip_scaled): the links of sphere i lower its
! one-body block R_1B,i by at most R_1B,i / 2; a wall block's floor is
! -(1/2) min(6 pi eta a_i, 8 pi eta a_i^3) / z_i. Model 'full' (the DNS): pair blocks made positive
! semi-definite, wall blocks floored at lub_wall_floor with the sphere's own radius, as for equal
! spheres.
module mod_particle_lubrication
  use mod_kinds, only: dp, pi
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars
  use mod_pair_resistance_unequal, only: unequal_pair_t, unequal_pair_setup, unequal_pair_scalars, &
       exchange_sign, twin_multipole_order, sphere_wall_gap
  use mod_lubrication, only: lubrication_t, lub_pair_scalars, lub_wall_scalars, lub_pair_link, &
       lub_wall_link, lub_pair_stresslets, lub_wall_stresslet, n_wall_scalars, LUB_NONE, LUB_EXACT, &
       lub_sized_scalars, lub_pair_link_sized, lub_pair_stresslets_sized, LUB_FULL, lub_species_wall_floor
  use mod_neighbours, only: nlist_t, nlist_init, nlist_candidates
  use mod_lees_edwards, only: lees_edwards_t, le_separation
  use mod_particle_system, only: particle_system_t, particle_system_add_diagonal, particle_system_add_pair
  use mod_columns, only: column_t, column, sphere_column, sphere_rows
  implicit none
  private
  public :: particle_lubrication_t, particle_lubrication_create, particle_lubrication_links, &
            particle_lubrication_corrections, particle_lubrication_add_to_system, particle_lubrication_add_corrections, &
            particle_lubrication_columns, particle_lubrication_set_local

  type :: particle_lubrication_t
    type(lubrication_t) :: lub
    type(nlist_t) :: nlist
    integer :: np = 0
    real(dp) :: box(3) = 0, shear_rate = 0
    logical :: walls = .false., periodic(3) = .true.
    type(lees_edwards_t) :: le                                 ! sliding boundaries in y (le%active)
    integer, allocatable :: links_of(:)                        ! (np) links per sphere (model 'exact')
    integer :: ncand = 0, ncand_walls = 0
    integer, allocatable :: cand(:, :), cand_walls(:, :)        ! canonical candidate lists
    ! links of the current configuration (pairs: those evaluated here, all of them or those with a
    ! sphere in the owned range; npairs_total, npairs_most: the pair links of the whole system and
    ! the most one rank holds, npairs on one rank, set by mod_lubrication_links on several)
    integer :: npairs = 0, nwalls = 0, npairs_total = 0, npairs_most = 0
    integer :: nwalls_total = 0                                ! the wall links of the whole system
    integer, allocatable :: pair(:, :)                         ! (2, npairs)
    real(dp), allocatable :: pair_d(:, :), pair_f(:, :)        ! (3, :), (22, :)
    real(dp), allocatable :: pair_f2(:, :)                     ! (22, :) 22 and 21 scalars (sized)
    real(dp), allocatable :: pair_uinf(:, :)                   ! (6, :) U_inf at both centres
    real(dp), allocatable :: pair_r(:, :, :), pair_drive(:, :) ! (12, 12, :), (12, :)
    integer, allocatable :: wall_part(:)
    real(dp), allocatable :: wall_n(:, :), wall_r(:, :, :), wall_drive(:, :)   ! (3, :), (6, 6, :), (6, :)
    real(dp) :: min_gap = huge(1.0_dp)                         ! smallest pair or wall gap [a]
    ! the first link whose block could not be decomposed (non-finite input): particle, partner
    ! (0 for a wall); 0, 0 when all were
    integer :: failed_link(2) = 0
    ! spheres of several sizes (sized): each sphere's radius, its species (index into
    ! species_radius: model 'full' lub%species_radius, the tables' species, else the radii in the
    ! order met) and the unequal-pair set-up of each ordered pair of species (lambda =
    ! species_radius(t) / species_radius(s); s = t unused: equal radii take mod_pair_resistance)
    logical :: sized = .false.
    real(dp), allocatable :: radii(:), species_radius(:)
    integer, allocatable :: species(:)
    type(unequal_pair_t), allocatable :: setup(:, :)
    ! corrections of the last step, on each particle
    real(dp), allocatable :: force(:, :), torque(:, :), stresslet(:, :, :)
    ! the force of the lower and the upper wall on the spheres through the wall links of the last
    ! step (every rank holds every wall link: the same on every rank; the walls' share of the
    ! wall shear stress, doc/METHOD.md §7.4)
    real(dp) :: wall_force(3, 2) = 0
    real(dp) :: skin = 0                                       ! the neighbour list's
    ! a rank's local set (particle_lubrication_set_local; not allocated: every sphere)
    logical, allocatable :: owned(:)                           ! (np) the spheres this rank owns
  end type particle_lubrication_t

  ! the phases of particle_lubrication_links on a local set
  integer, parameter, public :: LINKS_COUNT = 1, LINKS_EVALUATE = 2

contains

  !> lub: the configured model (mod_lubrication lub_setup); skin: neighbour-list skin [a].
  !> le, optional: Lees-Edwards boundaries in y (walls .false.).
  !> radii, optional: (np) the spheres' radii in units of lub%radius (a mixture: model 'exact', or
  !> 'full' with a mixture's tables in lub, lub%species_radius holding every radius); absent or all
  !> equal: equal spheres.
  subroutine particle_lubrication_create(pl, lub, np, box, walls, shear_rate, skin, info, msg, le, radii)
    type(particle_lubrication_t), intent(out) :: pl
    type(lubrication_t), intent(in) :: lub
    integer, intent(in) :: np
    real(dp), intent(in) :: box(3), shear_rate, skin
    logical, intent(in) :: walls
    integer, intent(out) :: info
    character(len=*), intent(out) :: msg
    type(lees_edwards_t), intent(in), optional :: le
    real(dp), intent(in), optional :: radii(:)
    real(dp) :: reach, a_max
    pl%lub = lub
    if (present(le)) pl%le = le
    allocate(pl%links_of(np))
    pl%np = np
    pl%box = box
    pl%walls = walls
    pl%shear_rate = shear_rate
    pl%periodic = [.true., .not. walls, .true.]
    allocate(pl%force(3, np), pl%torque(3, np), pl%stresslet(3, 3, np))
    pl%force = 0
    pl%torque = 0
    pl%stresslet = 0
    allocate(pl%pair(2, 16), pl%pair_d(3, 16), pl%pair_f(n_pair_scalars, 16), pl%pair_f2(n_pair_scalars, 16), &
             pl%pair_uinf(6, 16), pl%pair_r(12, 12, 16), &
             pl%pair_drive(12, 16), pl%wall_part(16), pl%wall_n(3, 16), pl%wall_r(6, 6, 16), pl%wall_drive(6, 16))
    info = 0
    msg = ''
    if (lub%model == LUB_NONE) return
    a_max = lub%radius
    if (present(radii)) then
      if (any(radii /= radii(1))) call set_sizes()
      if (info /= 0) return
    end if
    if (lub%model == LUB_FULL .and. .not. pl%sized .and. .not. allocated(lub%pair_gap)) then
      info = 1
      msg = 'lubrication: the full model of equal spheres needs their table (a mixture''s tables were given)'
      return
    end if
    if (np == 1) then
      ! one sphere: no pairs, and its two wall candidates need no search (nor a box large
      ! enough for one)
      pl%ncand = 0
      pl%ncand_walls = 0
      allocate(pl%cand(2, 0), pl%cand_walls(2, 2))
      if (walls) then
        pl%ncand_walls = 2
        pl%cand_walls = reshape([1, 1, 1, 2], [2, 2])
      end if
      return
    end if
    ! a pair is in range while r < (a_i + a_j)(1 + outer_cutoff/2) <= 2 a_max + outer_cutoff a_max,
    ! a wall link while its height < a_i (1 + outer_cutoff) (a_max = a for equal spheres)
    reach = lub%outer_cutoff * a_max
    pl%skin = skin
    call nlist_init(pl%nlist, np, box, pl%periodic, 2 * a_max + reach + skin, a_max + reach + skin, &
                    skin, info, pl%le)
    if (info /= 0) msg = 'lubrication: the neighbour search refuses this box (a periodic length below '// &
                         '2 x (2a + outer_cutoff + skin), a the largest radius)'

  contains

    ! the radii, their species and the set-up of each unequal pair of species
    subroutine set_sizes()
      integer :: i, s, t, ns
      real(dp) :: found(np)
      if (lub%model /= LUB_EXACT .and. lub%model /= LUB_FULL) then
        info = 1
        msg = 'lubrication: spheres of several sizes take the exact functions (lubrication dynamics) or '// &
              'the full model with a table per pair of species (the resolved fluid), not model ''simple'''
        return
      end if
      if (lub%model == LUB_FULL .and. .not. allocated(lub%species_pair)) then
        info = 1
        msg = 'lubrication: the full model of spheres of several sizes needs a table per pair of species '// &
              '(mod_lubrication_io; doc/LUBRICATION.md "Tables for mixtures")'
        return
      end if
      pl%sized = .true.
      pl%radii = lub%radius * radii
      a_max = maxval(pl%radii)
      ns = 0
      allocate(pl%species(np))
      if (lub%model == LUB_FULL) then
        ! the tables' species: each radius must be one of them (to rounding of the units)
        ns = size(lub%species_radius)
        found(1:ns) = lub%species_radius
        do i = 1, np
          s = minloc(abs(found(1:ns) - pl%radii(i)), 1)
          if (abs(found(s) - pl%radii(i)) > 1.0e-12_dp * found(s)) then
            info = 1
            write(msg, '(a,i0,a,es12.5,a)') 'lubrication: sphere ', i, ' has radius ', pl%radii(i), &
                 ', which no table of the mixture is for'
            return
          end if
          pl%species(i) = s
        end do
      else
        do i = 1, np
          s = findloc(found(1:ns), pl%radii(i), 1)
          if (s == 0) then
            ns = ns + 1
            found(ns) = pl%radii(i)
            s = ns
          end if
          pl%species(i) = s
        end do
      end if
      pl%species_radius = found(1:ns)
      allocate(pl%setup(ns, ns))
      do t = 1, ns
        do s = 1, ns
          if (s /= t) pl%setup(s, t) = unequal_pair_setup(found(t) / found(s), twin_multipole_order)
        end do
      end do
    end subroutine set_sizes
  end subroutine particle_lubrication_create

  !> The spheres this rank holds from now on (doc/DESIGN.md "Spheres held by their slab"): owned (np)
  !> those it owns among its local set (own spheres and ghosts, ascending global index), radii (np,
  !> units of lub%radius) theirs when the run has several sizes. The links then take the local
  !> set's positions in two phases (particle_lubrication_links' phase): LINKS_COUNT finds the
  !> candidates and counts each sphere's links (links_of, complete for the owned spheres only; the
  !> caller brings the ghosts' counts from their owners, model 'exact' floors a pair by both
  !> counts), LINKS_EVALUATE evaluates the pairs with an owned sphere and the walls of the owned
  !> spheres. The neighbour list starts afresh for the new set.
  subroutine particle_lubrication_set_local(pl, owned, radii)
    type(particle_lubrication_t), intent(inout) :: pl
    logical, intent(in) :: owned(:)
    real(dp), intent(in), optional :: radii(:)
    integer :: np, info, i
    np = size(owned)
    pl%np = np
    pl%owned = owned
    if (allocated(pl%links_of)) deallocate(pl%links_of)
    if (allocated(pl%force)) deallocate(pl%force, pl%torque, pl%stresslet)
    allocate(pl%links_of(np), pl%force(3, np), pl%torque(3, np), pl%stresslet(3, 3, np))
    pl%links_of = 0
    pl%force = 0
    pl%torque = 0
    pl%stresslet = 0
    if (pl%sized .and. present(radii)) then
      ! each radius is one of the species found at creation (to rounding of the units)
      pl%radii = pl%lub%radius * radii
      if (allocated(pl%species)) deallocate(pl%species)
      allocate(pl%species(np))
      do i = 1, np
        pl%species(i) = minloc(abs(pl%species_radius - pl%radii(i)), 1)
      end do
    end if
    if (pl%lub%model == LUB_NONE) return
    call nlist_init(pl%nlist, np, pl%box, pl%periodic, pl%nlist%cutoff, pl%nlist%wall_cutoff, pl%skin, info, pl%le)
    pl%nlist%built = .false.
  end subroutine particle_lubrication_set_local

  pure function ambient_velocity(pl, x) result(u)
    type(particle_lubrication_t), intent(in) :: pl
    real(dp), intent(in) :: x(3)
    real(dp) :: u(3)
    u = 0
    if (pl%walls .or. pl%le%active) u(1) = pl%shear_rate * (x(2) - 0.5_dp * pl%box(2))
  end function ambient_velocity

  subroutine ambient_gradients(pl, om, e)
    type(particle_lubrication_t), intent(in) :: pl
    real(dp), intent(out) :: om(3), e(3, 3)
    real(dp) :: g
    g = 0
    if (pl%walls .or. pl%le%active) g = pl%shear_rate
    om = [0.0_dp, 0.0_dp, -0.5_dp * g]
    e = 0
    e(1, 2) = 0.5_dp * g
    e(2, 1) = 0.5_dp * g
  end subroutine ambient_gradients

  !> The lubrication links at positions x (3, np): which pairs and walls are within the outer
  !> cut-off, and their blocks. Call once per step before the particle problem. A block that
  !> cannot be decomposed is named in pl%failed_link for the caller to report.
  !> owned (optional, np): the spheres this caller owns; only the pair candidates with a sphere
  !> among them, in the order of all candidates, so that each owned sphere has all its pair links, in the
  !> order all links would have them (mod_lubrication_links); walls always all.
  !> offset (optional): the Lees-Edwards offset delta of this configuration (runs created with le).
  !> phase (optional, a local set only: particle_lubrication_set_local): LINKS_COUNT or
  !> LINKS_EVALUATE; absent, both.
  subroutine particle_lubrication_links(pl, x, owned, offset, phase)
    type(particle_lubrication_t), intent(inout) :: pl
    real(dp), intent(in) :: x(:, :)
    logical, intent(in), optional :: owned(:)
    real(dp), intent(in), optional :: offset
    integer, intent(in), optional :: phase
    integer :: c, i, j, side, status
    logical :: count_phase, evaluate_phase, local
    real(dp) :: r(3), dist, gap, d(3), om_inf(3), e_inf(3, 3), u_inf(3, 2), normal(3), u_wall(3), w(n_wall_scalars)
    real(dp) :: vshift(3), floor_scale, scale(12)
    pl%npairs = 0
    pl%nwalls = 0
    pl%npairs_total = 0
    pl%nwalls_total = 0
    pl%npairs_most = 0
    pl%min_gap = huge(1.0_dp)
    pl%failed_link = 0
    if (pl%lub%model == LUB_NONE) return
    local = allocated(pl%owned)
    count_phase = .true.
    evaluate_phase = .true.
    if (present(phase)) then
      count_phase = phase == LINKS_COUNT
      evaluate_phase = phase == LINKS_EVALUATE
    end if
    if (present(offset)) pl%le%offset = offset
    if (count_phase) then
      ! one sphere: its wall candidates were set once by particle_lubrication_create
      if (pl%np > 1 .or. local) &
        call nlist_candidates(pl%nlist, x, pl%cand, pl%ncand, pl%cand_walls, pl%ncand_walls, pl%le%offset)
      if (pl%lub%model == LUB_EXACT) call count_links()
    end if
    if (.not. evaluate_phase) return
    call ambient_gradients(pl, om_inf, e_inf)
    if (pl%lub%model == LUB_EXACT) floor_scale = -0.5_dp * min(6.0_dp * pi * pl%lub%viscosity * pl%lub%radius, &
                                                               8.0_dp * pi * pl%lub%viscosity * pl%lub%radius**3)
    do c = 1, pl%ncand
      i = pl%cand(1, c)
      j = pl%cand(2, c)
      if (present(owned)) then
        if (.not. (owned(i) .or. owned(j))) cycle
      end if
      if (local) then
        if (.not. (pl%owned(i) .or. pl%owned(j))) cycle
      end if
      r = separation(i, j)
      dist = norm2(r)
      gap = pair_gap(i, j, dist)
      pl%min_gap = min(pl%min_gap, gap)
      if (gap >= pl%lub%outer_cutoff) cycle
      call grow_pairs()
      pl%npairs = pl%npairs + 1
      d = r / dist
      ! the undisturbed velocity at sphere 2 as seen from sphere 1 (same image); across a sliding
      ! boundary at j's own centre, where j's velocity is
      u_inf(:, 1) = ambient_velocity(pl, x(:, i))
      if (pl%le%active) then
        u_inf(:, 2) = ambient_velocity(pl, x(:, j))
      else
        u_inf(:, 2) = ambient_velocity(pl, x(:, i) + r)
      end if
      pl%pair(:, pl%npairs) = [i, j]
      pl%pair_d(:, pl%npairs) = d
      pl%pair_uinf(:, pl%npairs) = [u_inf(:, 1), u_inf(:, 2)]
      if (pl%sized) then
        call sized_scalars(i, j, gap, pl%pair_f(:, pl%npairs), pl%pair_f2(:, pl%npairs))
        ! the floor's metric of model 'exact' ('full' makes the block PSD and counts no links)
        scale = 1.0_dp
        if (pl%lub%model == LUB_EXACT) then
          scale(1:6) = floor_metric(i)
          scale(7:12) = floor_metric(j)
        end if
        call lub_pair_link_sized(pl%lub, pl%pair_f(:, pl%npairs), pl%pair_f2(:, pl%npairs), d, pl%radii(i), pl%radii(j), &
                                 u_inf, om_inf, e_inf, scale, pl%pair_r(:, :, pl%npairs), pl%pair_drive(:, pl%npairs), &
                                 status)
        if (status /= 0 .and. pl%failed_link(1) == 0) pl%failed_link = [i, j]
        cycle
      end if
      pl%pair_f(:, pl%npairs) = lub_pair_scalars(pl%lub, gap)
      if (pl%lub%model == LUB_EXACT) then
        call lub_pair_link(pl%lub, pl%pair_f(:, pl%npairs), d, u_inf, om_inf, e_inf, &
                           pl%pair_r(:, :, pl%npairs), pl%pair_drive(:, pl%npairs), status, &
                           floor_scale / max(pl%links_of(i), pl%links_of(j)))
      else
        call lub_pair_link(pl%lub, pl%pair_f(:, pl%npairs), d, u_inf, om_inf, e_inf, &
                           pl%pair_r(:, :, pl%npairs), pl%pair_drive(:, pl%npairs), status)
      end if
      if (status /= 0 .and. pl%failed_link(1) == 0) pl%failed_link = [i, j]
    end do
    do c = 1, pl%ncand_walls
      i = pl%cand_walls(1, c)
      side = pl%cand_walls(2, c)
      if (local) then
        if (.not. pl%owned(i)) cycle
      end if
      gap = wall_gap(i, side)
      if (side == 1) then
        normal = [0.0_dp, 1.0_dp, 0.0_dp]
        u_wall = [-0.5_dp * pl%shear_rate * pl%box(2), 0.0_dp, 0.0_dp]
      else
        normal = [0.0_dp, -1.0_dp, 0.0_dp]
        u_wall = [0.5_dp * pl%shear_rate * pl%box(2), 0.0_dp, 0.0_dp]
      end if
      pl%min_gap = min(pl%min_gap, gap)
      if (gap >= pl%lub%outer_cutoff) cycle
      call grow_walls()
      pl%nwalls = pl%nwalls + 1
      pl%wall_part(pl%nwalls) = i
      pl%wall_n(:, pl%nwalls) = normal
      if (pl%sized .and. pl%lub%model == LUB_FULL) then
        ! the wall part of this sphere's species' table, and the wall floor with its own radius
        w = lub_wall_scalars(pl%lub, gap, pl%species(i))
        call lub_wall_link(pl%lub, w, normal, u_wall, pl%wall_r(:, :, pl%nwalls), pl%wall_drive(:, pl%nwalls), status, &
                           lub_species_wall_floor(pl%lub, pl%radii(i)), pl%radii(i))
        if (status /= 0 .and. pl%failed_link(1) == 0) pl%failed_link = [i, 0]
        cycle
      end if
      w = lub_wall_scalars(pl%lub, gap)
      if (pl%sized) then
        ! the floor of equal spheres with this sphere's own one-body block
        call lub_wall_link(pl%lub, w, normal, u_wall, pl%wall_r(:, :, pl%nwalls), pl%wall_drive(:, pl%nwalls), status, &
                           -minval(floor_metric(i)**2), pl%radii(i))
      else if (pl%lub%model == LUB_EXACT) then
        call lub_wall_link(pl%lub, w, normal, u_wall, pl%wall_r(:, :, pl%nwalls), pl%wall_drive(:, pl%nwalls), status, &
                           floor_scale / pl%links_of(i))
      else
        call lub_wall_link(pl%lub, w, normal, u_wall, pl%wall_r(:, :, pl%nwalls), pl%wall_drive(:, pl%nwalls), status)
      end if
      if (status /= 0 .and. pl%failed_link(1) == 0) pl%failed_link = [i, 0]
    end do
    pl%npairs_total = pl%npairs
    pl%npairs_most = pl%npairs
    pl%nwalls_total = pl%nwalls

  contains

    ! the gap of a pair [a]; of unequal spheres over their mean radius, xi = 2r/(a_i + a_j) - 2
    real(dp) function pair_gap(i, j, dist) result(g)
      integer, intent(in) :: i, j
      real(dp), intent(in) :: dist
      if (pl%sized) then
        g = 2.0_dp * dist / (pl%radii(i) + pl%radii(j)) - 2.0_dp
      else
        g = dist / pl%lub%radius - 2.0_dp
      end if
    end function pair_gap

    ! the gap of sphere i to the wall side (1: y = 0, 2: y = Ly) over its radius
    real(dp) function wall_gap(i, side) result(g)
      integer, intent(in) :: i, side
      real(dp) :: height
      height = x(2, i)
      if (side /= 1) height = pl%box(2) - x(2, i)
      if (pl%sized) then
        g = sphere_wall_gap(height, pl%radii(i))
      else
        g = height / pl%lub%radius - 1.0_dp
      end if
    end function wall_gap

    ! the subgrid scalars of an unequal pair at gap (evaluated at the inner cut-off below it):
    ! R_2B - R_1B, and for model 'full' minus the resolved part of its species' table
    subroutine sized_scalars(i, j, gap, f, f2)
      integer, intent(in) :: i, j
      real(dp), intent(in) :: gap
      real(dp), intent(out) :: f(n_pair_scalars), f2(n_pair_scalars)
      real(dp) :: xi
      integer :: s, t
      xi = max(gap, pl%lub%inner_cutoff)
      s = pl%species(i)
      t = pl%species(j)
      if (s == t) then
        f = resistance_scalars(xi)
        f2 = exchange_sign * f
      else
        f = unequal_pair_scalars(pl%setup(s, t), xi)
        f2 = exchange_sign * unequal_pair_scalars(pl%setup(t, s), xi)
      end if
      call lub_sized_scalars(pl%lub, gap, f, f2, s, t)
    end subroutine sized_scalars

    ! sqrt of the share of sphere i's one-body block (6 pi eta a_i, 8 pi eta a_i^3) its links may
    ! take each: half of it over its links
    function floor_metric(i) result(m)
      integer, intent(in) :: i
      real(dp) :: m(6)
      m(1:3) = sqrt(0.5_dp * 6.0_dp * pi * pl%lub%viscosity * pl%radii(i) / pl%links_of(i))
      m(4:6) = sqrt(0.5_dp * 8.0_dp * pi * pl%lub%viscosity * pl%radii(i)**3 / pl%links_of(i))
    end function floor_metric

    ! r = x_j - x_i, minimum image (across sliding boundaries: le_separation's)
    function separation(i, j) result(r)
      integer, intent(in) :: i, j
      real(dp) :: r(3)
      r = x(:, j) - x(:, i)
      if (pl%le%active) then
        call le_separation(pl%le, x(:, j) - x(:, i), r, vshift)
      else
        where (pl%periodic) r = r - pl%box * anint(r / pl%box)
      end if
    end function separation

    ! links_of: the pair and wall links of every sphere within the outer cut-off (all candidates,
    ! whatever share this rank evaluates, so that every rank sets the same floors)
    subroutine count_links()
      integer :: k, a, b
      real(dp) :: g
      pl%links_of = 0
      do k = 1, pl%ncand
        a = pl%cand(1, k)
        b = pl%cand(2, k)
        g = pair_gap(a, b, norm2(separation(a, b)))
        if (g >= pl%lub%outer_cutoff) cycle
        pl%links_of(a) = pl%links_of(a) + 1
        pl%links_of(b) = pl%links_of(b) + 1
      end do
      do k = 1, pl%ncand_walls
        a = pl%cand_walls(1, k)
        g = wall_gap(a, pl%cand_walls(2, k))
        if (g < pl%lub%outer_cutoff) pl%links_of(a) = pl%links_of(a) + 1
      end do
    end subroutine count_links

    subroutine grow_pairs()
      integer :: m
      integer, allocatable :: ip(:, :)
      real(dp), allocatable :: t2(:, :), t3(:, :, :)
      if (pl%npairs < size(pl%pair, 2)) return
      m = 2 * size(pl%pair, 2)
      allocate(ip(2, m)); ip(:, 1:pl%npairs) = pl%pair(:, 1:pl%npairs); call move_alloc(ip, pl%pair)
      allocate(t2(3, m)); t2(:, 1:pl%npairs) = pl%pair_d(:, 1:pl%npairs); call move_alloc(t2, pl%pair_d)
      allocate(t2(n_pair_scalars, m)); t2(:, 1:pl%npairs) = pl%pair_f(:, 1:pl%npairs); call move_alloc(t2, pl%pair_f)
      allocate(t2(n_pair_scalars, m)); t2(:, 1:pl%npairs) = pl%pair_f2(:, 1:pl%npairs); call move_alloc(t2, pl%pair_f2)
      allocate(t2(6, m)); t2(:, 1:pl%npairs) = pl%pair_uinf(:, 1:pl%npairs); call move_alloc(t2, pl%pair_uinf)
      allocate(t3(12, 12, m)); t3(:, :, 1:pl%npairs) = pl%pair_r(:, :, 1:pl%npairs); call move_alloc(t3, pl%pair_r)
      allocate(t2(12, m)); t2(:, 1:pl%npairs) = pl%pair_drive(:, 1:pl%npairs); call move_alloc(t2, pl%pair_drive)
    end subroutine grow_pairs

    subroutine grow_walls()
      integer :: m
      integer, allocatable :: ip(:)
      real(dp), allocatable :: t2(:, :), t3(:, :, :)
      if (pl%nwalls < size(pl%wall_part)) return
      m = 2 * size(pl%wall_part)
      allocate(ip(m)); ip(1:pl%nwalls) = pl%wall_part(1:pl%nwalls); call move_alloc(ip, pl%wall_part)
      allocate(t2(3, m)); t2(:, 1:pl%nwalls) = pl%wall_n(:, 1:pl%nwalls); call move_alloc(t2, pl%wall_n)
      allocate(t3(6, 6, m)); t3(:, :, 1:pl%nwalls) = pl%wall_r(:, :, 1:pl%nwalls); call move_alloc(t3, pl%wall_r)
      allocate(t2(6, m)); t2(:, 1:pl%nwalls) = pl%wall_drive(:, 1:pl%nwalls); call move_alloc(t2, pl%wall_drive)
    end subroutine grow_walls

  end subroutine particle_lubrication_links

  !> The links into a 6N system (doc/METHOD.md §3.2 eq. (1)): each pair's 12x12 block as two diagonal
  !> blocks and one coupling block, each wall link's 6x6 on its particle's diagonal; their
  !> velocity-independent parts (R.U_inf + R_FE:E_inf) onto rhs (6, np).
  subroutine particle_lubrication_add_to_system(pl, sys, rhs)
    type(particle_lubrication_t), intent(in) :: pl
    type(particle_system_t), intent(inout) :: sys
    real(dp), intent(inout) :: rhs(:, :)
    integer :: l, i, j
    do l = 1, pl%npairs
      i = pl%pair(1, l)
      j = pl%pair(2, l)
      call particle_system_add_diagonal(sys, i, pl%pair_r(1:6, 1:6, l))
      call particle_system_add_diagonal(sys, j, pl%pair_r(7:12, 7:12, l))
      call particle_system_add_pair(sys, i, j, pl%pair_r(1:6, 7:12, l))
      rhs(:, i) = rhs(:, i) + pl%pair_drive(1:6, l)
      rhs(:, j) = rhs(:, j) + pl%pair_drive(7:12, l)
    end do
    do l = 1, pl%nwalls
      i = pl%wall_part(l)
      call particle_system_add_diagonal(sys, i, pl%wall_r(:, :, l))
      rhs(:, i) = rhs(:, i) + pl%wall_drive(:, l)
    end do
  end subroutine particle_lubrication_add_to_system

  !> The corrections with the velocities of this step, u and om (3, np): force, torque and
  !> stresslet on each particle (pl%force, pl%torque, pl%stresslet) from the links evaluated here:
  !> complete for the spheres whose links all are (every sphere, or the owned range of
  !> particle_lubrication_links, whose sums mod_lubrication_links gathers).
  subroutine particle_lubrication_corrections(pl, u, om)
    type(particle_lubrication_t), intent(inout) :: pl
    real(dp), intent(in) :: u(:, :), om(:, :)
    integer :: l, i, j, side
    real(dp) :: ft(12), ft6(6), v(12), w(12), om_inf(3), e_inf(3, 3), s(3, 3, 2)
    pl%force = 0
    pl%torque = 0
    pl%stresslet = 0
    pl%wall_force = 0
    if (pl%npairs + pl%nwalls == 0) return
    call ambient_gradients(pl, om_inf, e_inf)
    do l = 1, pl%npairs
      i = pl%pair(1, l)
      j = pl%pair(2, l)
      v = [u(:, i), om(:, i), u(:, j), om(:, j)]
      ft = pl%pair_drive(:, l) - matmul(pl%pair_r(:, :, l), v)
      pl%force(:, i) = pl%force(:, i) + ft(1:3)
      pl%torque(:, i) = pl%torque(:, i) + ft(4:6)
      pl%force(:, j) = pl%force(:, j) + ft(7:9)
      pl%torque(:, j) = pl%torque(:, j) + ft(10:12)
      w = [pl%pair_uinf(1:3, l) - u(:, i), om_inf - om(:, i), pl%pair_uinf(4:6, l) - u(:, j), om_inf - om(:, j)]
      if (pl%sized) then
        s = lub_pair_stresslets_sized(pl%lub, pl%pair_f(:, l), pl%pair_f2(:, l), pl%pair_d(:, l), pl%radii(i), &
                                      pl%radii(j), w, e_inf)
      else
        s = lub_pair_stresslets(pl%lub, pl%pair_f(:, l), pl%pair_d(:, l), w, e_inf)
      end if
      pl%stresslet(:, :, i) = pl%stresslet(:, :, i) + s(:, :, 1)
      pl%stresslet(:, :, j) = pl%stresslet(:, :, j) + s(:, :, 2)
    end do
    do l = 1, pl%nwalls
      i = pl%wall_part(l)
      ft6 = pl%wall_drive(:, l) - matmul(pl%wall_r(:, :, l), [u(:, i), om(:, i)])
      pl%force(:, i) = pl%force(:, i) + ft6(1:3)
      pl%torque(:, i) = pl%torque(:, i) + ft6(4:6)
      ! the normal points from the wall into the box: +y at the lower wall (1), -y at the upper (2)
      side = merge(1, 2, pl%wall_n(2, l) > 0)
      pl%wall_force(:, side) = pl%wall_force(:, side) + ft6(1:3)
      if (pl%sized) then
        pl%stresslet(:, :, i) = pl%stresslet(:, :, i) + lub_wall_stresslet(pl%lub, pl%wall_n(:, l), ft6(1:3), pl%radii(i))
      else
        pl%stresslet(:, :, i) = pl%stresslet(:, :, i) + lub_wall_stresslet(pl%lub, pl%wall_n(:, l), ft6(1:3))
      end if
    end do
  end subroutine particle_lubrication_corrections

  !> Add the links' corrections of particle_lubrication_corrections to a sphere's hydrodynamic force, torque
  !> (3, np) and stresslet (3, 3, np).
  subroutine particle_lubrication_add_corrections(pl, force, torque, stresslet)
    type(particle_lubrication_t), intent(in) :: pl
    real(dp), intent(inout) :: force(:, :), torque(:, :), stresslet(:, :, :)
    force = force + pl%force
    torque = torque + pl%torque
    stresslet = stresslet + pl%stresslet
  end subroutine particle_lubrication_add_corrections

  ! The lubrication's columns of the series: links within the outer cut-off, the smallest gap among
  ! the candidates, and the correction's force and torque on each sphere (doc/INPUT.md "&lubrication").
  function particle_lubrication_columns(pl, owned, rows, total) result(c)
    type(particle_lubrication_t), intent(in) :: pl
    integer, intent(in) :: owned(:)           ! the spheres whose rows this rank gives (mod_columns)
    ! (a rank's local set: the global indices of owned and the number of all spheres; absent, the
    ! links are set for every sphere and owned are global indices)
    integer, intent(in), optional :: rows(:), total
    type(column_t), allocatable :: c(:)
    integer, allocatable :: r(:)
    integer :: n
    call sphere_rows(owned, size(pl%force, 2), r, n, rows, total)
    ! element by element: an array constructor of column_t leaks their values (gfortran 12)
    allocate(c(merge(6, 5, pl%walls)))
    c(1) = column('lubrication_pairs', pl%npairs_total)
    c(2) = column('lubrication_walls', pl%nwalls_total)
    c(3) = column('min_gap', pl%min_gap)
    c(4) = sphere_column('particles/force_lubrication', n, r, pl%force(:, owned))
    c(5) = sphere_column('particles/torque_lubrication', n, r, pl%torque(:, owned))
    ! between walls: the force of the lower and the upper wall on the spheres (3 x 2)
    if (pl%walls) c(6) = column('wall_force_lubrication', pl%wall_force)
  end function particle_lubrication_columns

end module mod_particle_lubrication
