! Suspension rheology in the core of the Couette cell (doc/RHEOLOGY.md; paper §4, eqs. (4.1)-(4.18)).
! Pure kernels on plain arrays, no PETSc: every sphere on every rank, or a rank's local set
! (rheo_set_local: its own spheres and their ghosts; a sample is then this rank's share, which the
! caller sums over the ranks before rheo_sample_finish; doc/DESIGN.md "Parallelism").
!
! Per record (rheo_sample): the particle stress of the core region D^C = [0,Lx] x [y_lo,y_hi] x
! [0,Lz] (paper eq. (4.10): y_lo = Ly/4, y_hi = 3Ly/4), split into hydrodynamic and contact parts,
!     Sigma^h = (1/V_core) sum_i w_i S^h_i,   Sigma^c = (1/V_core) sum_i w_i S^c_i   (eqs. (4.3)-(4.4))
! where w_i is the fraction of sphere i's volume inside the core (a smooth indicator: a sphere
! half in the core counts half), so that the core volume fraction
!     phi_core = (1/V_core) sum_i w_i (4/3) pi a^3
! is the same ensemble as the stresses and (eta_r - 1)/phi_core does not jump when a sphere crosses
! y_lo or y_hi. The core shear rate is the slope of the particle-phase velocity u_x against y in
! the core, a w-weighted least-squares fit whose five sums are kept (so block averages fit the
! pooled data, not average per-record slopes). Profiles across y: phi(y) and the particle momentum
! phi u_x (y) in bins (exact sphere-slab volumes); pair counts in the shear plane for the pair
! distribution g(theta) at r < r_outer and at contact (r < 2a + h_c).
!
! Lees-Edwards boundaries (lubrication dynamics, rheo_create's le): the shear is homogeneous, there
! are no wall layers, and the core is the whole box: every sphere counts whole (w_i = 1, so
! phi_core = N (4/3) pi a^3 / V), its centre is a reference of g(theta), and pairs are taken across
! the sliding boundary (le_separation).
!
! Spheres of several sizes (rheo_create's radii; doc/RHEOLOGY.md "Spheres of several sizes"): each
! sphere's weight w_i is the fraction of its own volume (4/3) pi a_i^3 in the core, phi_core and
! the profiles sum each sphere's slab volumes with its own radius, the velocity fit weights each
! sphere by its volume in the core (w_i a_i^3 / a^3: the particle phase), pairs are in the shells
! r < pair_shell (a_i + a_j)/2 and r < a_i + a_j + contact_shell a, and Q6 bonds are shorter than
! 1.4 (a_i + a_j). Equal spheres keep the arithmetic of one radius.
!
! Per species (two or more distinct radii, smallest first; doc/RHEOLOGY.md "Per species"): the
! same sums restricted to the spheres of each species s, so that they add up to the pooled ones,
!     Sigma^h_s, Sigma^c_s = (1/V_core) sum_{i in s} w_i S_i,   phi_core,s,   phi_s(y),
! the references (core centres) of each species, and the partial pair counts C_ab(r) (partners of
! species b at r from the references of species a, in bins of radial_width up to radial_range, over
! the whole box and across the periodic and sliding boundaries) that give the partial pair
! distribution g_ab(r) = C_ab / (n_b S_ab), n_b = (phi_core,b / v_b) (N_b - delta_ab) / N_b, S_ab
! the volume of the shells around the references of a where a centre of b can be: R_a V_shell with
! Lees-Edwards boundaries, between walls their parts within [a_b, Ly - a_b] (kept per record).
! Equal spheres measure none of it (no arrays, no columns, no accumulators).
!
! Statistics (paper §4, "five statistically independent time-segments"): the records after
! discard_step are split into `blocks` blocks of block_steps steps; a block's mean is taken over
! its records, every summary quantity is evaluated on each complete block's means (the error: the
! standard deviation over blocks, ddof = 1, divided by sqrt(blocks)) and on the mean of the block
! means (the value). scripts/rheology.py repeats exactly this from series.h5.
module mod_rheology
  use mod_kinds, only: dp, pi
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use mod_neighbours, only: nlist_t, nlist_init, nlist_candidates, min_image
  use mod_lees_edwards, only: lees_edwards_t, le_separation
  use mod_columns, only: column_t, column
  use mod_bond_order, only: bond_order_q6, bond_order_shares, bond_order_global
  implicit none
  private
  ! bonds of Q6: shorter than bond_factor (a_i + a_j)
  real(dp), parameter :: bond_factor = 1.4_dp

  ! per-species summary: the shares of the pooled quantities (doc/RHEOLOGY.md "Per species")
  integer, parameter :: NSPECIES_Q = 13
  character(len=20), parameter :: species_names(NSPECIES_Q) = [character(len=20) :: &
       'eta_r-1', 'eta_h-1', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau', 'N1_h/tau', 'N2_h/tau', 'Pi_h/tau', &
       'N1_c/tau', 'N2_c/tau', 'Pi_c/tau', 'phi_core']
  ! per-species values of a record: stress_hydro(5), stress_contact(5), phi_core,s
  integer, parameter :: NQS = 11
  ! partial g(r): bins of radial_width [a], up to the box's half periodic length less the search
  ! skin and at most radial_cap [a] (past the second shell of radii 1 and 1.4, 5.6 a; the cap keeps
  ! the pair search O(N) in large boxes)
  real(dp), parameter :: radial_width = 0.05_dp, radial_cap = 6.0_dp

  public :: species_summary_t, rheo_summarise_species, rheo_species_quantities, NSPECIES_Q, NQS, species_names
  public :: rheology_settings_t, rheology_t, rheo_create, rheo_sample, rheo_sample_flow, rheo_accumulate, rheo_quantities, rheo_block_of, &
            rheo_state, rheo_restore, rheo_summarise, rheo_columns, NQ, NSUMMARY, summary_names, slab_volume, &
            rheo_particle_shear_stress, rheo_set_local, rheo_sample_shares, rheo_sample_finish, rheo_reach, rheo_skin

  ! per-record values that are block-averaged: stress_hydro(5), stress_contact(5), phi_core,
  ! particle fit(5), suspension fit(5)
  integer, parameter :: NQ = 21
  integer, parameter :: NSUMMARY = 33
  ! the summary quantities, in the order of rheo_quantities (doc/RHEOLOGY.md defines each)
  character(len=20), parameter :: summary_names(NSUMMARY) = [character(len=20) :: &
       'eta_r', 'eta_h', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau', &
       'Sigma_xx/tau', 'Sigma_yy/tau', 'Sigma_zz/tau', 'Sigma_xx_c/tau', 'Sigma_yy_c/tau', 'Sigma_zz_c/tau', &
       'N1_c/tau', 'N2_c/tau', 'Pi_c/tau', &
       'lambda_2', 'lambda_3', 'lambda_2_c', 'lambda_3_c', 'eta_n', 'eta_n_c', &
       'I_v', 'mu', 'mu_h', 'mu_c', 'phi_core', 'gamma_dot_core', 'tau', &
       'Sigma_xy/tau', 'Sigma_xy_c/tau', 'Pi_h/tau', 'N1_h/tau', 'gamma_dot_flow']

  ! The deck's &rheology (doc/INPUT.md, doc/RHEOLOGY.md): its variables, named as in the deck, with
  ! their defaults. The step counts of the window follow from them and &time dt (rheo_create's
  ! discard_step, block_steps).
  type :: rheology_settings_t
    real(dp) :: discard_strain = 5.0_dp       ! strain discarded before averaging [-]
    real(dp) :: average_strain = 20.0_dp      ! strain averaged over [-]
    integer :: blocks = 5                     ! averaging blocks [-]
    real(dp) :: core(2) = [0.25_dp, 0.75_dp]  ! core region y/Ly [-] (paper eq. (4.10))
    integer :: profile_bins = 0               ! bins across y (0: 4 per radius)
    integer :: angle_bins = 36                ! bins of g(theta) over [0, 2 pi)
    real(dp) :: pair_shell = 2.1_dp           ! g(theta) counts pairs at r < pair_shell [a]
    real(dp) :: contact_shell = 0.0_dp        ! g_c(theta): r < 2a + contact_shell [a] (0: h_r or 0.005)
  end type rheology_settings_t

  type :: rheology_t
    real(dp) :: box(3) = 0, radius = 1, shear_rate = 1
    ! a rate that varies in time (&shear protocol 'reversal', 'oscillatory'): the summary's stresses
    ! are block means over eta*|shear_rate| (the reference rate), never over the measured rate, which
    ! averages to zero or changes sign (doc/RHEOLOGY.md "Protocols")
    logical :: raw_stress = .false.
    ! spheres of several sizes: each sphere's radius [a] (allocated only then), and the mean
    ! sphere volume (the core's number density from phi_core)
    logical :: sized = .false.
    real(dp), allocatable :: radii(:)
    real(dp) :: mean_volume = 0
    real(dp) :: core(2) = 0                 ! y_lo, y_hi of the core region [a]
    real(dp) :: r_outer = 2.1_dp            ! pair shell of g(theta): r < r_outer [a]
    real(dp) :: r_contact = 2.005_dp        ! contact shell: r < 2a + h_c [a]
    integer :: nbins = 0, nangles = 0       ! profile bins across y, angle bins of g over [0, 2 pi)
    integer :: blocks = 5, discard_step = 0, block_steps = 1
    type(nlist_t) :: nl
    type(lees_edwards_t) :: le              ! sliding boundaries (le%active): the whole box is the core
    ! the pair candidates of nl: kept here between samples, because nlist_candidates refreshes them
    ! only when it rebuilds the list (a list local to rheo_sample was empty between rebuilds)
    integer :: npairs = 0, nwalls = 0
    integer, allocatable :: pairs(:, :), walls(:, :)
    ! the last sample
    real(dp) :: values(NQ) = 0              ! stress_hydro(5), stress_contact(5), phi_core, fit(5), flow fit(5)
    real(dp) :: shear_rate_core = 0         ! this record's particle-phase slope (for the series only)
    real(dp) :: min_pair_gap = 0            ! smallest surface gap of any pair [a]
    real(dp) :: references = 0              ! spheres with their centre in the core
    real(dp), allocatable :: profile(:, :)  ! (nbins, 2): phi, phi u_x
    real(dp), allocatable :: angles(:, :)   ! (nangles, 2): pair counts r < r_outer, r < r_contact
    ! accumulators per block (sums over records)
    real(dp), allocatable :: block_sums(:, :)        ! (NQ, blocks)
    real(dp), allocatable :: block_profile(:, :, :)  ! (nbins, 2, blocks)
    real(dp), allocatable :: block_angles(:, :, :)   ! (nangles, 2, blocks)
    real(dp), allocatable :: block_references(:)     ! (blocks)
    real(dp), allocatable :: block_records(:)        ! (blocks)
    ! crystalline order of each sample (doc/RHEOLOGY.md "Order"): Steinhardt's Q6 of the bonds
    ! shorter than bond_range, globally and the mean of the spheres' own; when every periodic
    ! length holds twice the bonds' search range (order), else not measured
    logical :: order = .false.
    real(dp) :: bond_range = 0
    type(nlist_t) :: bond_list
    integer :: nbond_pairs = 0, nbond_walls = 0
    integer, allocatable :: bond_pairs(:, :), bond_walls(:, :)
    real(dp) :: q6 = 0, q6_local = 0
    ! per species (nspecies >= 2 only; doc/RHEOLOGY.md "Per species"): each species' radius and
    ! number of spheres, each sphere's species; this record's sums restricted to a species, and
    ! their accumulators per block
    integer :: nspecies = 1
    real(dp), allocatable :: species_radius(:), species_count(:)   ! (nspecies)
    integer, allocatable :: species_of(:)                          ! (n)
    real(dp), allocatable :: species_values(:, :)                  ! (NQS, nspecies)
    real(dp), allocatable :: species_profile(:, :)                 ! (nbins, nspecies): phi_s(y)
    real(dp), allocatable :: species_references(:)                 ! (nspecies)
    real(dp), allocatable :: block_species_values(:, :, :)         ! (NQS, nspecies, blocks)
    real(dp), allocatable :: block_species_profile(:, :, :)        ! (nbins, nspecies, blocks)
    real(dp), allocatable :: block_species_references(:, :)        ! (nspecies, blocks)
    ! partial pair counts (k, partner's species, reference's species), when the box allows a range
    integer :: nradial = 0
    real(dp) :: radial_width = 0, radial_range = 0   ! [length]
    type(nlist_t) :: radial_list
    integer :: nradial_pairs = 0, nradial_walls = 0
    integer, allocatable :: radial_pairs(:, :), radial_walls(:, :)
    real(dp), allocatable :: radial(:, :, :)                       ! (nradial, nspecies, nspecies)
    real(dp), allocatable :: block_radial(:, :, :, :)              ! (nradial, nspecies, nspecies, blocks)
    ! between walls, the shell volumes around the references where a partner's centre can be, as
    ! radial (Lees-Edwards: none, every shell is whole)
    integer :: nradial_volume = 0
    real(dp), allocatable :: radial_volume(:, :, :)                ! (nradial_volume, nspecies, nspecies)
    real(dp), allocatable :: block_radial_volume(:, :, :, :)       ! (nradial_volume, nspecies, nspecies, blocks)
    ! a rank's local set (rheo_set_local; not allocated: every sphere): the spheres it owns; a
    ! sample then leaves this rank's shares (rheo_sample_shares), which the caller sums over the
    ! ranks before rheo_sample_finish
    logical, allocatable :: owned(:)
    ! Q6's sums of a sample: the bonds' harmonics over the owned spheres' ends and their count, the
    ! owned spheres' local q6 and how many have bonds
    complex(dp) :: q6_total(0:6) = (0.0_dp, 0.0_dp)
    real(dp) :: q6_bonds = 0, q6_local_sum = 0, q6_local_count = 0
  end type rheology_t

  ! The per-species summary over the complete blocks (rheo_summarise_species): value and error of
  ! each species' share of the pooled quantities, phi_s(y) with its block error and the number
  ! density n_s(y) = phi_s(y) / v_s, and the partial pair distribution g(r, b, a) = g_ab(r) (a the
  ! reference's species) with its block error.
  type :: species_summary_t
    real(dp), allocatable :: value(:, :), error(:, :)              ! (NSPECIES_Q, nspecies)
    real(dp), allocatable :: phi(:, :), phi_error(:, :), number(:, :)   ! (nbins, nspecies)
    real(dp), allocatable :: r(:)                                  ! (nradial) bin centres [a]
    real(dp), allocatable :: g(:, :, :), g_error(:, :, :)          ! (nradial, nspecies, nspecies)
  end type species_summary_t

contains

  !> Set up for n spheres with the deck's &rheology settings (profile_bins and contact_shell as
  !> resolved by the deck reader: non-zero); steps are counted from the start of the simulation.
  !> info: 0 ok; 1 a periodic length below twice the pair search range.
  !> le, optional: Lees-Edwards boundaries in y (the core is then the whole box).
  !> radii, optional: (n) each sphere's radius in units of radius (absent or all equal: equal spheres).
  subroutine rheo_create(r, n, box, radius, shear_rate, settings, discard_step, block_steps, info, le, radii)
    type(rheology_t), intent(out) :: r
    integer, intent(in) :: n                ! number of spheres
    real(dp), intent(in) :: box(3), radius, shear_rate
    type(rheology_settings_t), intent(in) :: settings
    integer, intent(in) :: discard_step, block_steps
    integer, intent(out) :: info
    type(lees_edwards_t), intent(in), optional :: le
    real(dp), intent(in), optional :: radii(:)
    real(dp), parameter :: skin = 0.3_dp
    integer :: bond_info
    real(dp) :: a_max
    if (present(le)) r%le = le
    a_max = radius
    if (present(radii)) then
      r%sized = any(radii /= radii(1))
      if (r%sized) then
        r%radii = radius * radii
        a_max = maxval(r%radii)
        r%mean_volume = 4.0_dp / 3.0_dp * pi * sum(r%radii**3) / n
      end if
    end if
    r%box = box
    r%radius = radius
    r%shear_rate = shear_rate
    r%core = settings%core * box(2)
    if (r%le%active) r%core = [0.0_dp, box(2)]
    r%nbins = settings%profile_bins
    r%nangles = settings%angle_bins
    r%r_outer = settings%pair_shell * radius
    r%r_contact = (2.0_dp + settings%contact_shell) * radius
    r%blocks = settings%blocks
    r%discard_step = discard_step
    r%block_steps = block_steps
    allocate(r%profile(r%nbins, 2), r%angles(r%nangles, 2))
    allocate(r%block_sums(NQ, r%blocks), r%block_profile(r%nbins, 2, r%blocks), r%block_angles(r%nangles, 2, r%blocks), &
             r%block_references(r%blocks), r%block_records(r%blocks))
    r%profile = 0; r%angles = 0
    r%block_sums = 0; r%block_profile = 0; r%block_angles = 0; r%block_references = 0; r%block_records = 0
    ! the pair search reaches the largest pair's shells (a_max = a for equal spheres)
    call nlist_init(r%nl, n, box, [.true., r%le%active, .true.], max(r%r_outer, r%r_contact) * a_max / radius + skin, &
                    a_max + skin, skin, info, r%le)
    ! bonds of Q6 up to 1.4 contact distances, near the first minimum of g(r) of a dense
    ! suspension, so that a crystal's nearest shell is whole and its second shell (sqrt(2) x the
    ! first for fcc) is not
    r%bond_range = bond_factor * 2 * radius
    call nlist_init(r%bond_list, n, box, [.true., r%le%active, .true.], r%bond_range * a_max / radius + skin, &
                    a_max + skin, skin, bond_info, r%le)
    r%order = bond_info == 0
    if (r%sized) call create_species(r, n, a_max, skin)
  end subroutine rheo_create

  !> The spheres a rank holds from now on (doc/DESIGN.md "Parallelism"): its own (owned) and their
  !> ghosts, in ascending global index, radii (units of r%radius) theirs for a mixture. A sample
  !> then takes the local set's arrays and sums over the owned spheres only (a pair's counts by the
  !> owner of the reference sphere, Q6's bonds at the owned ends), so that the shares of the ranks
  !> add up to one rank's sample: the ghosts must reach the farthest shell, rheo_reach. The pair
  !> searches start afresh for the new set.
  subroutine rheo_set_local(r, owned, radii)
    type(rheology_t), intent(inout) :: r
    logical, intent(in) :: owned(:)
    real(dp), intent(in), optional :: radii(:)
    integer :: n, info, i
    n = size(owned)
    r%owned = owned
    if (r%sized .and. present(radii)) then
      r%radii = r%radius * radii
      if (r%nspecies > 1) then
        if (allocated(r%species_of)) deallocate(r%species_of)
        allocate(r%species_of(n))
        do i = 1, n
          r%species_of(i) = findloc(r%species_radius, r%radii(i), 1)
        end do
      end if
    end if
    call renew(r%nl)
    if (r%order) call renew(r%bond_list)
    if (r%nradial > 0) call renew(r%radial_list)
  contains
    subroutine renew(list)
      type(nlist_t), intent(inout) :: list
      call nlist_init(list, n, r%box, list%periodic, list%cutoff, list%wall_cutoff, list%skin, info, r%le)
      list%built = .false.
    end subroutine renew
  end subroutine rheo_set_local

  !> The farthest a sample looks from a sphere [length]: its pair shells, Q6's bonds, the partial
  !> g(r)'s range, each with its search skin (the reach of the ghosts of rheo_set_local).
  pure real(dp) function rheo_reach(r) result(reach)
    type(rheology_t), intent(in) :: r
    reach = r%nl%cutoff
    if (r%order) reach = max(reach, r%bond_list%cutoff)
    if (r%nradial > 0) reach = max(reach, r%radial_list%cutoff)
  end function rheo_reach

  !> The smallest skin of the statistics' neighbour lists: their partners stay listed while no
  !> sphere has moved half of it since their build.
  pure real(dp) function rheo_skin(r) result(skin)
    type(rheology_t), intent(in) :: r
    skin = r%nl%skin
    if (r%order) skin = min(skin, r%bond_list%skin)
    if (r%nradial > 0) skin = min(skin, r%radial_list%skin)
  end function rheo_skin

  ! The species of a mixture (distinct radii, smallest first), each sphere's species, and the
  ! per-species arrays and accumulators; the range of the partial g(r) (doc/RHEOLOGY.md "Per
  ! species"): half the smallest periodic length less the search skin (minimum image), at most
  ! radial_cap; in bins of radial_width. No bins when that leaves none. Between walls a shell may
  ! reach past them: its part where a partner's centre can be is summed per record instead.
  subroutine create_species(r, n, a_max, skin)
    type(rheology_t), intent(inout) :: r
    integer, intent(in) :: n
    real(dp), intent(in) :: a_max, skin
    real(dp) :: unique(n), range
    integer :: i, s, info
    r%nspecies = 0
    do i = 1, n
      if (any(unique(1:r%nspecies) == r%radii(i))) cycle
      r%nspecies = r%nspecies + 1
      unique(r%nspecies) = r%radii(i)
    end do
    ! smallest first (a handful of species: insertion order by minloc)
    allocate(r%species_radius(r%nspecies), r%species_count(r%nspecies), r%species_of(n))
    do s = 1, r%nspecies
      i = minloc(unique(1:r%nspecies), 1)
      r%species_radius(s) = unique(i)
      unique(i) = huge(1.0_dp)
    end do
    do i = 1, n
      r%species_of(i) = findloc(r%species_radius, r%radii(i), 1)
    end do
    do s = 1, r%nspecies
      r%species_count(s) = count(r%species_of == s)
    end do
    allocate(r%species_values(NQS, r%nspecies), r%species_profile(r%nbins, r%nspecies), &
             r%species_references(r%nspecies), r%block_species_values(NQS, r%nspecies, r%blocks), &
             r%block_species_profile(r%nbins, r%nspecies, r%blocks), r%block_species_references(r%nspecies, r%blocks))
    r%species_values = 0; r%species_profile = 0; r%species_references = 0
    r%block_species_values = 0; r%block_species_profile = 0; r%block_species_references = 0
    r%radial_width = radial_width * r%radius
    range = min(r%box(1), r%box(3)) / 2 - skin
    if (r%le%active) range = min(range, r%box(2) / 2 - skin)
    range = min(range, radial_cap * r%radius)
    r%nradial = max(0, int(range / r%radial_width))
    r%radial_range = r%nradial * r%radial_width
    if (r%nradial > 0) then
      call nlist_init(r%radial_list, n, r%box, [.true., r%le%active, .true.], r%radial_range + skin, a_max + skin, &
                      skin, info, r%le)
      if (info /= 0) r%nradial = 0
    end if
    allocate(r%radial(r%nradial, r%nspecies, r%nspecies), r%block_radial(r%nradial, r%nspecies, r%nspecies, r%blocks))
    r%radial = 0
    r%block_radial = 0
    r%nradial_volume = merge(0, r%nradial, r%le%active)
    allocate(r%radial_volume(r%nradial_volume, r%nspecies, r%nspecies), &
             r%block_radial_volume(r%nradial_volume, r%nspecies, r%nspecies, r%blocks))
    r%radial_volume = 0
    r%block_radial_volume = 0
  end subroutine create_species

  !> The block of a record at step (0-based), or -1 outside the averaging window.
  pure integer function rheo_block_of(r, step) result(b)
    type(rheology_t), intent(in) :: r
    integer, intent(in) :: step
    b = -1
    if (step <= r%discard_step) return
    b = (step - r%discard_step - 1) / r%block_steps
    if (b >= r%blocks) b = -1
  end function rheo_block_of

  !> Volume of the sphere of radius a centred at height yc between the planes y1 < y2.
  pure real(dp) function slab_volume(yc, a, y1, y2) result(v)
    real(dp), intent(in) :: yc, a, y1, y2
    real(dp) :: t1, t2
    t1 = max(y1 - yc, -a)
    t2 = min(y2 - yc, a)
    v = 0.0_dp
    if (t2 > t1) v = pi * (a * a * (t2 - t1) - (t2**3 - t1**3) / 3.0_dp)
  end function slab_volume

  !> One record: core stresses, volume fraction, velocity-fit sums, profiles, pair counts.
  !> position, velocity (3, N); stresslet_hydro, stresslet_contact (3, 3, N) [eta gamma_dot a^3];
  !> stresslet_contact absent: no contacts (zero contact stress). offset (optional): the
  !> Lees-Edwards offset of this configuration (rheo_create's le).
  subroutine rheo_sample(r, position, velocity, stresslet_hydro, stresslet_contact, offset)
    type(rheology_t), intent(inout) :: r
    real(dp), intent(in) :: position(:, :), velocity(:, :), stresslet_hydro(:, :, :)
    real(dp), intent(in), optional :: stresslet_contact(:, :, :)
    real(dp), intent(in), optional :: offset
    real(dp) :: a, vp, v_core, w, y, u, dbin, d(3), dist, theta, sin_half, gap, ai, vi, phi, fit
    real(dp) :: r_outer, r_contact
    integer :: n, i, b, b1, b2, k, p, i1, i2, sp
    logical :: ref_i, ref_j, species, local

    n = size(position, 2)
    a = r%radius
    vp = 4.0_dp / 3.0_dp * pi * a**3
    v_core = r%box(1) * r%box(3) * (r%core(2) - r%core(1))
    r%values(1:16) = 0
    r%profile = 0
    r%angles = 0
    r%references = 0
    species = r%nspecies > 1
    if (species) then
      r%species_values = 0
      r%species_profile = 0
      r%species_references = 0
    end if
    dbin = r%box(2) / r%nbins
    ai = a
    vi = vp
    phi = 0
    local = allocated(r%owned)
    do i = 1, n
      if (local) then
        if (.not. r%owned(i)) cycle
      end if
      y = position(2, i)
      u = velocity(1, i)
      if (r%sized) then
        ai = r%radii(i)
        vi = 4.0_dp / 3.0_dp * pi * ai**3
      end if
      w = slab_volume(y, ai, r%core(1), r%core(2)) / vi
      if (r%le%active) w = 1.0_dp
      if (w > 0) then
        r%values(1:5) = r%values(1:5) + w * components(stresslet_hydro(:, :, i))
        if (present(stresslet_contact)) r%values(6:10) = r%values(6:10) + w * components(stresslet_contact(:, :, i))
        if (r%sized) then
          ! each sphere's volume in the core: phi_core, and the particle phase's velocity fit
          phi = phi + w * vi
          fit = w * vi / vp
          r%values(12:16) = r%values(12:16) + fit * [1.0_dp, y, u, y * y, y * u]
          if (species) then
            ! the same terms, restricted to sphere i's species
            sp = r%species_of(i)
            r%species_values(1:5, sp) = r%species_values(1:5, sp) + w * components(stresslet_hydro(:, :, i))
            if (present(stresslet_contact)) &
              r%species_values(6:10, sp) = r%species_values(6:10, sp) + w * components(stresslet_contact(:, :, i))
            r%species_values(11, sp) = r%species_values(11, sp) + w * vi
          end if
        else
          r%values(11) = r%values(11) + w
          r%values(12:16) = r%values(12:16) + w * [1.0_dp, y, u, y * y, y * u]
        end if
      end if
      if (y >= r%core(1) .and. y < r%core(2)) then
        r%references = r%references + 1
        if (species) r%species_references(r%species_of(i)) = r%species_references(r%species_of(i)) + 1
      end if
      b1 = max(1, int((y - ai) / dbin) + 1)
      b2 = min(r%nbins, int((y + ai) / dbin) + 1)
      do b = b1, b2
        w = slab_volume(y, ai, (b - 1) * dbin, b * dbin)
        r%profile(b, 1) = r%profile(b, 1) + w
        r%profile(b, 2) = r%profile(b, 2) + w * u
        if (species) r%species_profile(b, r%species_of(i)) = r%species_profile(b, r%species_of(i)) + w
      end do
    end do
    if (species) then
      r%species_values = r%species_values / v_core
      r%species_profile = r%species_profile / (r%box(1) * r%box(3) * dbin)
    end if
    r%values(1:11) = r%values(1:11) / v_core
    r%values(11) = r%values(11) * vp
    if (r%sized) r%values(11) = phi / v_core
    r%profile = r%profile / (r%box(1) * r%box(3) * dbin)
    r%shear_rate_core = line_slope(r%values(12:16))

    ! pairs in the shear plane: polar angle from the vorticity axis within pi/2 -+ half an angle bin
    sin_half = sin(pi / r%nangles)
    r%min_pair_gap = max(r%r_outer, r%r_contact) - 2 * a
    if (present(offset)) r%le%offset = offset
    call nlist_candidates(r%nl, position, r%pairs, r%npairs, r%walls, r%nwalls, r%le%offset)
    do p = 1, r%npairs
      i1 = r%pairs(1, p)
      i2 = r%pairs(2, p)
      d = pair_separation(r, position(:, i2) - position(:, i1))
      dist = norm2(d)
      r_outer = r%r_outer
      r_contact = r%r_contact
      if (r%sized) then
        ! the pair's own shells and surface gap
        r_outer = r%r_outer * 0.5_dp * (r%radii(i1) + r%radii(i2)) / a
        r_contact = r%r_contact - 2 * a + r%radii(i1) + r%radii(i2)
        gap = dist - r%radii(i1) - r%radii(i2)
      else
        gap = dist - 2 * a
      end if
      r%min_pair_gap = min(r%min_pair_gap, gap)
      if (dist >= r_outer .and. dist >= r_contact) cycle
      if (abs(d(3)) >= dist * sin_half) cycle
      ref_i = position(2, i1) >= r%core(1) .and. position(2, i1) < r%core(2)
      ref_j = position(2, i2) >= r%core(1) .and. position(2, i2) < r%core(2)
      if (local) then
        ! a reference's pairs are counted by its owner
        ref_i = ref_i .and. r%owned(i1)
        ref_j = ref_j .and. r%owned(i2)
      end if
      ! seen from i the partner is at d; seen from j at -d (theta + pi)
      theta = modulo(atan2(d(2), d(1)), 2 * pi)
      if (ref_i) call count_pair(theta)
      if (ref_j) call count_pair(modulo(theta + pi, 2 * pi))
    end do
    if (r%order) call sample_order(r, position)
    if (species .and. r%nradial > 0) call sample_radial(r, position)
  contains
    subroutine count_pair(angle)
      real(dp), intent(in) :: angle
      k = min(r%nangles, int(angle / (2 * pi) * r%nangles) + 1)
      if (dist < r_outer) r%angles(k, 1) = r%angles(k, 1) + 1
      if (dist < r_contact) r%angles(k, 2) = r%angles(k, 2) + 1
    end subroutine count_pair
  end subroutine rheo_sample

  !> The particle shear stress Sigma^h_xy + Sigma^c_xy of one configuration, exactly as rheo_sample
  !> weighs it (the core's w_i, 1 across Lees-Edwards boundaries; the same order of summation):
  !> what a stress-controlled step (doc/METHOD.md §7.4) sets, with the solvent's eta gamma_dot, to
  !> the target stress. stresslet: (3, 3, n) the sum of each sphere's hydrodynamic and contact stresslets.
  pure real(dp) function rheo_particle_shear_stress(r, position, stresslet) result(sxy)
    type(rheology_t), intent(in) :: r
    real(dp), intent(in) :: position(:, :), stresslet(:, :, :)
    real(dp) :: ai, vi, w
    integer :: i
    sxy = 0
    ai = r%radius
    vi = 4.0_dp / 3.0_dp * pi * ai**3
    do i = 1, size(position, 2)
      ! (a local set: the own spheres' share, rheo_set_local)
      if (allocated(r%owned)) then
        if (.not. r%owned(i)) cycle
      end if
      if (r%sized) then
        ai = r%radii(i)
        vi = 4.0_dp / 3.0_dp * pi * ai**3
      end if
      w = slab_volume(position(2, i), ai, r%core(1), r%core(2)) / vi
      if (r%le%active) w = 1.0_dp
      if (w > 0) sxy = sxy + w * stresslet(1, 2, i)
    end do
    sxy = sxy / (r%box(1) * r%box(3) * (r%core(2) - r%core(1)))
  end function rheo_particle_shear_stress

  !> The suspension's mean velocity profile u(y_j) (x-z plane means at the cell rows y_j =
  !> (j + 1/2) h, j = 0..): the five sums of its least-squares line over the rows in the core.
  pure subroutine rheo_sample_flow(r, profile, h)
    type(rheology_t), intent(inout) :: r
    real(dp), intent(in) :: profile(0:), h
    integer :: j
    real(dp) :: y
    r%values(17:21) = 0
    do j = 0, size(profile) - 1
      y = (j + 0.5_dp) * h
      if (y < r%core(1) .or. y > r%core(2)) cycle
      r%values(17:21) = r%values(17:21) + [1.0_dp, y, profile(j), y * y, y * profile(j)]
    end do
  end subroutine rheo_sample_flow

  !> xx, yy, zz, xy and the trace of a 3 x 3 tensor.
  pure function components(s) result(c)
    real(dp), intent(in) :: s(3, 3)
    real(dp) :: c(5)
    c = [s(1, 1), s(2, 2), s(3, 3), s(1, 2), s(1, 1) + s(2, 2) + s(3, 3)]
  end function components

  !> Add the last sample to its block (the record at step; nothing outside the window).
  subroutine rheo_accumulate(r, step)
    type(rheology_t), intent(inout) :: r
    integer, intent(in) :: step
    integer :: b
    b = rheo_block_of(r, step)
    if (b < 0) return
    b = b + 1
    r%block_sums(:, b) = r%block_sums(:, b) + r%values
    r%block_profile(:, :, b) = r%block_profile(:, :, b) + r%profile
    r%block_angles(:, :, b) = r%block_angles(:, :, b) + r%angles
    r%block_references(b) = r%block_references(b) + r%references
    r%block_records(b) = r%block_records(b) + 1
    if (r%nspecies > 1) then
      r%block_species_values(:, :, b) = r%block_species_values(:, :, b) + r%species_values
      r%block_species_profile(:, :, b) = r%block_species_profile(:, :, b) + r%species_profile
      r%block_species_references(:, b) = r%block_species_references(:, b) + r%species_references
      r%block_radial(:, :, :, b) = r%block_radial(:, :, :, b) + r%radial
      r%block_radial_volume(:, :, :, b) = r%block_radial_volume(:, :, :, b) + r%radial_volume
    end if
  end subroutine rheo_accumulate

  !> The summary quantities of one set of (block-)mean values m(NQ), in the order of
  !> summary_names; NaN where undefined (no contact pressure, no contact stress).
  !> gamma_dot_core is the particle-phase slope over the core (the paper's, m(12:16));
  !> gamma_dot_flow, the slope of the suspension's mean velocity (m(17:21)), is reported beside it.
  !> fixed_rate: the rate the stresses are divided by instead of gamma_dot_core (a rate that varies:
  !> the reference rate, so that 'eta_r' - 1 is the mean particle shear stress over eta*rate).
  pure function rheo_quantities(m, shear_rate, fixed_rate) result(q)
    real(dp), intent(in) :: m(NQ), shear_rate
    real(dp), intent(in), optional :: fixed_rate
    real(dp) :: q(NSUMMARY)
    real(dp) :: sh(5), sc(5), sp(5), gd, tau, eta_r, eta_h, eta_c, p, nan
    nan = ieee_value(1.0_dp, ieee_quiet_nan)
    sh = m(1:5)
    sc = m(6:10)
    sp = sh + sc
    gd = line_slope(m(12:16))
    if (present(fixed_rate)) gd = fixed_rate
    eta_r = 1.0_dp + sp(4) / gd
    eta_h = 1.0_dp + sh(4) / gd        ! the solvent is lumped into the hydrodynamic part (paper §4.1)
    eta_c = sc(4) / gd
    tau = eta_r * gd
    p = -sc(2)                          ! the confining pressure of the mu(I_v) rheology: -Sigma_yy^c
    q = nan
    q(1:3) = [eta_r, eta_h, eta_c]
    q(4) = (sp(1) - sp(2)) / tau
    q(5) = (sp(2) - sp(3)) / tau
    q(6) = -sp(5) / 3.0_dp / tau
    q(7:9) = sp(1:3) / tau
    q(10:12) = sc(1:3) / tau
    q(13) = (sc(1) - sc(2)) / tau
    q(14) = (sc(2) - sc(3)) / tau
    q(15) = -sc(5) / 3.0_dp / tau
    if (sp(1) /= 0) q(16:17) = sp(2:3) / sp(1)
    if (sc(1) /= 0) q(18:19) = sc(2:3) / sc(1)
    q(20) = -sp(1) / gd
    q(21) = -sc(1) / gd
    if (p > 0) q(22:25) = [gd / p, tau / p, eta_h * gd / p, eta_c * gd / p]
    q(26) = m(11)
    q(27) = line_slope(m(12:16)) / shear_rate   ! measured, also under a fixed_rate
    q(28) = tau / shear_rate
    q(29) = sp(4) / tau
    q(30) = sc(4) / tau
    q(31) = -sh(5) / 3.0_dp / tau
    q(32) = (sh(1) - sh(2)) / tau
    q(33) = line_slope(m(17:21)) / shear_rate
  end function rheo_quantities

  !> One species' shares of the pooled quantities (species_names), from the pooled (block-)mean
  !> values m(NQ) and the species' own ms(NQS): its stresses over the pooled gamma_dot_core and tau,
  !> so that the shares of all species add up to eta_r - 1, eta_h - 1, eta_c, N1/tau, ... and
  !> phi_core (doc/RHEOLOGY.md "Per species").
  pure function rheo_species_quantities(m, ms) result(q)
    real(dp), intent(in) :: m(NQ), ms(NQS)
    real(dp) :: q(NSPECIES_Q)
    real(dp) :: sh(5), sc(5), sp(5), gd, tau
    gd = line_slope(m(12:16))
    tau = (1.0_dp + (m(4) + m(9)) / gd) * gd
    sh = ms(1:5)
    sc = ms(6:10)
    sp = sh + sc
    q(1:3) = [sp(4), sh(4), sc(4)] / gd
    q(4:6) = [sp(1) - sp(2), sp(2) - sp(3), -sp(5) / 3.0_dp] / tau
    q(7:9) = [sh(1) - sh(2), sh(2) - sh(3), -sh(5) / 3.0_dp] / tau
    q(10:12) = [sc(1) - sc(2), sc(2) - sc(3), -sc(5) / 3.0_dp] / tau
    q(13) = ms(11)
  end function rheo_species_quantities

  !> The blocks complete at last_step: those whose last step <= last_step and that hold records.
  pure integer function complete_blocks(r, last_step) result(complete)
    type(rheology_t), intent(in) :: r
    integer, intent(in) :: last_step
    integer :: b
    complete = 0
    do b = 1, r%blocks
      if (r%discard_step + b * r%block_steps <= last_step .and. r%block_records(b) > 0) complete = b
    end do
  end function complete_blocks

  !> Standard error over the first nb entries of x (ddof = 1, over sqrt(nb)); NaN below 2.
  pure real(dp) function block_error(x, nb) result(e)
    real(dp), intent(in) :: x(:)
    integer, intent(in) :: nb
    e = ieee_value(1.0_dp, ieee_quiet_nan)
    if (nb > 1) e = sqrt(sum((x(1:nb) - sum(x(1:nb)) / nb)**2) / (nb - 1)) / sqrt(real(nb, dp))
  end function block_error

  !> The per-species summary of a mixture over the blocks complete at last_step (as rheo_summarise:
  !> values from the mean of the block means, errors the standard deviation over blocks / sqrt):
  !> each species' shares of the pooled quantities; phi_s(y) (records pooled, as phi(y)), its error
  !> and n_s(y) = phi_s(y) / v_s; the partial pair distribution
  !>     g_ab(r_k) = C_ab(k) / (n_b S_ab(k)),   n_b = (phi_core,b / v_b) (N_b - delta_ab) / N_b,
  !> C_ab the partner counts of species b around the R_a references of species a, S_ab(k) the
  !> volume of their shells of bin k where a centre of b can be: R_a V_k, V_k = (4/3) pi
  !> (r_k^3 - r_k-1^3), with Lees-Edwards boundaries, the sampled sums between walls; n_b is the
  !> core's number density of species b with the reference itself taken out of its own species,
  !> so that an ideal mixture gives 1 at any N_b.
  !> Not allocated for equal spheres.
  subroutine rheo_summarise_species(r, last_step, ss)
    type(rheology_t), intent(in) :: r
    integer, intent(in) :: last_step
    type(species_summary_t), intent(out) :: ss
    integer :: complete, b, s, a, k, ns
    real(dp), allocatable :: per_block(:, :, :), mean_values(:), mean_species(:, :), g_block(:, :, :, :)
    real(dp), allocatable :: phi_block(:, :, :), refs(:)
    real(dp) :: nan, records, v_s(r%nspecies), shell(r%nradial)
    if (r%nspecies < 2) return
    nan = ieee_value(1.0_dp, ieee_quiet_nan)
    ns = r%nspecies
    complete = complete_blocks(r, last_step)
    v_s = 4.0_dp / 3.0_dp * pi * r%species_radius**3
    do k = 1, r%nradial
      shell(k) = 4.0_dp / 3.0_dp * pi * r%radial_width**3 * (real(k, dp)**3 - real(k - 1, dp)**3)
    end do
    allocate(ss%value(NSPECIES_Q, ns), ss%error(NSPECIES_Q, ns), ss%phi(r%nbins, ns), ss%phi_error(r%nbins, ns), &
             ss%number(r%nbins, ns), ss%r(r%nradial), ss%g(r%nradial, ns, ns), ss%g_error(r%nradial, ns, ns))
    ss%r = [((k - 0.5_dp) * r%radial_width / r%radius, k = 1, r%nradial)]
    ss%value = nan; ss%error = nan; ss%phi = nan; ss%phi_error = nan; ss%number = nan; ss%g = nan; ss%g_error = nan
    if (complete == 0) return
    allocate(per_block(NSPECIES_Q, ns, complete), mean_values(NQ), mean_species(NQS, ns), &
             g_block(r%nradial, ns, ns, complete), phi_block(r%nbins, ns, complete), refs(ns))
    mean_values = 0
    mean_species = 0
    do b = 1, complete
      mean_values = mean_values + r%block_sums(:, b) / r%block_records(b)
      mean_species = mean_species + r%block_species_values(:, :, b) / r%block_records(b)
      do s = 1, ns
        per_block(:, s, b) = rheo_species_quantities(r%block_sums(:, b) / r%block_records(b), &
                                                     r%block_species_values(:, s, b) / r%block_records(b))
      end do
      phi_block(:, :, b) = r%block_species_profile(:, :, b) / r%block_records(b)
      g_block(:, :, :, b) = partial_g(r%block_radial(:, :, :, b), shells(r%block_species_references(:, b), &
                                      r%block_radial_volume(:, :, :, b:b)), &
                                      r%block_species_values(11, :, b) / r%block_records(b))
    end do
    mean_values = mean_values / complete
    mean_species = mean_species / complete
    records = sum(r%block_records(1:complete))
    refs = sum(r%block_species_references(:, 1:complete), 2)
    do s = 1, ns
      ss%value(:, s) = rheo_species_quantities(mean_values, mean_species(:, s))
      do k = 1, NSPECIES_Q
        ss%error(k, s) = block_error(per_block(k, s, :), complete)
      end do
      ss%phi(:, s) = sum(r%block_species_profile(:, s, 1:complete), 2) / records
      ss%number(:, s) = ss%phi(:, s) / v_s(s)
      do k = 1, r%nbins
        ss%phi_error(k, s) = block_error(phi_block(k, s, :), complete)
      end do
    end do
    ss%g = partial_g(sum(r%block_radial(:, :, :, 1:complete), 4), &
                     shells(refs, r%block_radial_volume(:, :, :, 1:complete)), mean_species(11, :))
    do a = 1, ns
      do s = 1, ns
        do k = 1, r%nradial
          ss%g_error(k, s, a) = block_error(g_block(k, s, a, :), complete)
        end do
      end do
    end do
  contains
    ! S(k, b, a): the references' shell volumes, R_a V_k (Lees-Edwards), or the sampled sums over
    ! the blocks given (walls)
    pure function shells(references, volumes) result(v)
      real(dp), intent(in) :: references(:), volumes(:, :, :, :)
      real(dp) :: v(r%nradial, r%nspecies, r%nspecies)
      integer :: i, j
      if (r%nradial_volume > 0) then
        v = sum(volumes, 4)
      else
        do i = 1, r%nspecies
          do j = 1, r%nspecies
            v(:, j, i) = references(i) * shell
          end do
        end do
      end if
    end function shells
    ! g(k, b, a) from the counts, the shell volumes and the core volume fractions phi_core,b (NaN
    ! without references or partners)
    pure function partial_g(counts, volumes, phi_core) result(g)
      real(dp), intent(in) :: counts(:, :, :), volumes(:, :, :), phi_core(:)
      real(dp) :: g(size(counts, 1), size(counts, 2), size(counts, 3))
      real(dp) :: density
      integer :: i, j
      do i = 1, size(counts, 3)
        do j = 1, size(counts, 2)
          density = phi_core(j) / v_s(j) * (r%species_count(j) - merge(1.0_dp, 0.0_dp, i == j)) / r%species_count(j)
          if (density > 0 .and. all(volumes(:, j, i) > 0)) then
            g(:, j, i) = counts(:, j, i) / (density * volumes(:, j, i))
          else
            g(:, j, i) = nan
          end if
        end do
      end do
    end function partial_g
  end subroutine rheo_summarise_species

  !> Slope of the least-squares line from its sums (n, sum x, sum y, sum x^2, sum x y); NaN if
  !> undefined.
  pure real(dp) function line_slope(t) result(slope)
    real(dp), intent(in) :: t(5)
    real(dp) :: den
    slope = ieee_value(1.0_dp, ieee_quiet_nan)
    den = t(1) * t(4) - t(2)**2
    if (den > 0) slope = (t(1) * t(5) - t(2) * t(3)) / den
  end function line_slope

  !> The accumulators as one flat array (checkpoints) and back.
  pure function rheo_state(r) result(s)
    type(rheology_t), intent(in) :: r
    real(dp), allocatable :: s(:)
    s = [reshape(r%block_sums, [size(r%block_sums)]), reshape(r%block_profile, [size(r%block_profile)]), &
         reshape(r%block_angles, [size(r%block_angles)]), r%block_references, r%block_records]
    ! a mixture's per-species accumulators follow (equal spheres: none, the array as before)
    if (r%nspecies > 1) s = [s, reshape(r%block_species_values, [size(r%block_species_values)]), &
                             reshape(r%block_species_profile, [size(r%block_species_profile)]), &
                             reshape(r%block_species_references, [size(r%block_species_references)]), &
                             reshape(r%block_radial, [size(r%block_radial)]), &
                             reshape(r%block_radial_volume, [size(r%block_radial_volume)])]
  end function rheo_state

  !> info: 0 ok, 1 the array does not fit this set-up.
  subroutine rheo_restore(r, s, info)
    type(rheology_t), intent(inout) :: r
    real(dp), intent(in) :: s(:)
    integer, intent(out) :: info
    integer :: k, m
    info = 1
    if (size(s) /= size(rheo_state(r))) return
    info = 0
    k = 0
    m = size(r%block_sums); r%block_sums = reshape(s(k + 1:k + m), shape(r%block_sums)); k = k + m
    m = size(r%block_profile); r%block_profile = reshape(s(k + 1:k + m), shape(r%block_profile)); k = k + m
    m = size(r%block_angles); r%block_angles = reshape(s(k + 1:k + m), shape(r%block_angles)); k = k + m
    m = r%blocks; r%block_references = s(k + 1:k + m); k = k + m
    r%block_records = s(k + 1:k + m); k = k + m
    if (r%nspecies > 1) then
      m = size(r%block_species_values)
      r%block_species_values = reshape(s(k + 1:k + m), shape(r%block_species_values)); k = k + m
      m = size(r%block_species_profile)
      r%block_species_profile = reshape(s(k + 1:k + m), shape(r%block_species_profile)); k = k + m
      m = size(r%block_species_references)
      r%block_species_references = reshape(s(k + 1:k + m), shape(r%block_species_references)); k = k + m
      m = size(r%block_radial)
      r%block_radial = reshape(s(k + 1:k + m), shape(r%block_radial)); k = k + m
      m = size(r%block_radial_volume)
      r%block_radial_volume = reshape(s(k + 1:k + m), shape(r%block_radial_volume))
    end if
  end subroutine rheo_restore

  !> The summary over the complete blocks (those whose last step <= last_step): value and
  !> standard error of every quantity (NaN where undefined or with fewer than 2 blocks), the
  !> profiles phi(y) and u_x(y) = <phi u_x>/<phi>, and the pair distributions g(theta) at
  !> r < r_outer and r < r_contact, normalised by the references, the core number density and
  !> the bin volume (shell x dtheta x 2 sin(dtheta/2) in the polar angle).
  subroutine rheo_summarise(r, last_step, complete, value, err, profile, angles)
    type(rheology_t), intent(in) :: r
    integer, intent(in) :: last_step
    integer, intent(out) :: complete
    real(dp), intent(out) :: value(NSUMMARY), err(NSUMMARY)
    real(dp), allocatable, intent(out) :: profile(:, :), angles(:, :)
    integer :: b, k
    real(dp), allocatable :: per_block(:, :), mean_values(:)
    real(dp) :: shell(2), references, records, n_core, dtheta, nan
    nan = ieee_value(1.0_dp, ieee_quiet_nan)
    complete = complete_blocks(r, last_step)
    allocate(per_block(NSUMMARY, max(1, complete)), mean_values(NQ))
    mean_values = 0
    do b = 1, complete
      if (r%raw_stress) then
        per_block(:, b) = rheo_quantities(r%block_sums(:, b) / r%block_records(b), r%shear_rate, abs(r%shear_rate))
      else
        per_block(:, b) = rheo_quantities(r%block_sums(:, b) / r%block_records(b), r%shear_rate)
      end if
      mean_values = mean_values + r%block_sums(:, b) / r%block_records(b)
    end do
    value = nan
    err = nan
    if (complete > 0) then
      mean_values = mean_values / complete
      if (r%raw_stress) then
        value = rheo_quantities(mean_values, r%shear_rate, abs(r%shear_rate))
      else
        value = rheo_quantities(mean_values, r%shear_rate)
      end if
    end if
    if (complete > 1) then
      do k = 1, NSUMMARY
        err(k) = sqrt(sum((per_block(k, 1:complete) - sum(per_block(k, 1:complete)) / complete)**2) &
                      / (complete - 1)) / sqrt(real(complete, dp))
      end do
    end if
    allocate(profile(r%nbins, 2), angles(r%nangles, 2))
    profile = 0; angles = 0; references = 0; records = 0
    do b = 1, complete
      profile = profile + r%block_profile(:, :, b)
      angles = angles + r%block_angles(:, :, b)
      references = references + r%block_references(b)
      records = records + r%block_records(b)
    end do
    if (records > 0) then
      profile(:, 2) = merge(profile(:, 2) / profile(:, 1), nan, profile(:, 1) > 0)
      profile(:, 1) = profile(:, 1) / records
      dtheta = 2 * pi / r%nangles
      n_core = value(26) / (4.0_dp / 3.0_dp * pi * r%radius**3)
      if (r%sized) n_core = value(26) / r%mean_volume
      shell = [(r%r_outer**3 - (2 * r%radius)**3), (r%r_contact**3 - (2 * r%radius)**3)] / 3.0_dp &
              * dtheta * 2 * sin(0.5_dp * dtheta)
      do k = 1, 2
        angles(:, k) = angles(:, k) / (references * n_core * shell(k))
      end do
    else
      profile = nan
      angles = nan
    end if
  end subroutine rheo_summarise

  !> The statistics' columns of the series, this record's values (doc/RHEOLOGY.md): the core's
  !> stresses, volume fraction and velocity fits (r%values: stress_hydro(5), stress_contact(5),
  !> phi_core, particle fit(5), suspension fit(5)), pair counts and profiles across y.
  function rheo_columns(r) result(c)
    type(rheology_t), intent(in) :: r
    type(column_t), allocatable :: c(:)
    ! element by element: an array constructor of column_t leaks their values (gfortran 12)
    integer :: k
    allocate(c(merge(14, 12, r%order) + merge(5, 0, r%nspecies > 1) + merge(1, 0, r%nspecies > 1 .and. r%nradial > 0) &
               + merge(1, 0, r%nspecies > 1 .and. r%nradial_volume > 0)))
    c(1) = column('core/stress_hydro', r%values(1:5))
    c(2) = column('core/stress_contact', r%values(6:10))
    c(3) = column('core/solid_fraction', r%values(11))
    c(4) = column('core/velocity_fit', r%values(12:16))
    c(5) = column('core/flow_fit', r%values(17:21))
    c(6) = column('core/shear_rate', r%shear_rate_core)
    c(7) = column('min_pair_gap', r%min_pair_gap)
    c(8) = column('pairs/references', r%references)
    c(9) = column('pairs/shell', r%angles(:, 1))
    c(10) = column('pairs/contact', r%angles(:, 2))
    c(11) = column('profiles/solid_fraction', r%profile(:, 1))
    c(12) = column('profiles/momentum', r%profile(:, 2))
    if (r%order) then
      c(13) = column('structure/q6', r%q6)
      c(14) = column('structure/q6_local', r%q6_local)
    end if
    ! a mixture's per-species sums (doc/RHEOLOGY.md "Per species"); none for equal spheres
    if (r%nspecies > 1) then
      k = merge(14, 12, r%order)
      c(k + 1) = column('species/stress_hydro', r%species_values(1:5, :))
      c(k + 2) = column('species/stress_contact', r%species_values(6:10, :))
      c(k + 3) = column('species/solid_fraction', r%species_values(11, :))
      c(k + 4) = column('species/references', r%species_references)
      c(k + 5) = column('species/profile_solid_fraction', r%species_profile)
      if (r%nradial > 0) c(k + 6) = column('species/pair_counts', r%radial)
      if (r%nradial_volume > 0) c(k + 7) = column('species/pair_volumes', r%radial_volume)
    end if
  end function rheo_columns

  ! The partial pair counts of this configuration (doc/RHEOLOGY.md "Per species"): for every pair
  ! closer than radial_range (minimum image in x and z, across the sliding boundary with
  ! Lees-Edwards), the partner's species in the bin of its distance, seen from each end whose
  ! centre is in the core (the references of g(theta)). Between walls, also the volume of each
  ! reference's shells where a centre of each species can be, y in [a_b, Ly - a_b] (exact
  ! sphere-slab volumes): the ideal mixture's count, so that g_ab is 1 for it at any range.
  subroutine sample_radial(r, position)
    type(rheology_t), intent(inout) :: r
    real(dp), intent(in) :: position(:, :)
    real(dp) :: d(3), dist, inner, outer, y
    integer :: p, i1, i2, k, s1, s2, i
    r%radial = 0
    if (r%nradial_volume > 0) then
      r%radial_volume = 0
      do i = 1, size(position, 2)
        if (allocated(r%owned)) then
          if (.not. r%owned(i)) cycle
        end if
        y = position(2, i)
        if (y < r%core(1) .or. y >= r%core(2)) cycle
        s1 = r%species_of(i)
        do s2 = 1, r%nspecies
          inner = 0
          do k = 1, r%nradial
            outer = slab_volume(y, k * r%radial_width, r%species_radius(s2), r%box(2) - r%species_radius(s2))
            r%radial_volume(k, s2, s1) = r%radial_volume(k, s2, s1) + (outer - inner)
            inner = outer
          end do
        end do
      end do
    end if
    call nlist_candidates(r%radial_list, position, r%radial_pairs, r%nradial_pairs, r%radial_walls, r%nradial_walls, &
                          r%le%offset)
    do p = 1, r%nradial_pairs
      i1 = r%radial_pairs(1, p)
      i2 = r%radial_pairs(2, p)
      d = pair_separation(r, position(:, i2) - position(:, i1))
      dist = norm2(d)
      if (dist >= r%radial_range) cycle
      k = min(r%nradial, int(dist / r%radial_width) + 1)
      s1 = r%species_of(i1)
      s2 = r%species_of(i2)
      ! (a rank's local set: each reference counted by its owner)
      if (position(2, i1) >= r%core(1) .and. position(2, i1) < r%core(2) .and. is_owned(i1)) &
        r%radial(k, s2, s1) = r%radial(k, s2, s1) + 1
      if (position(2, i2) >= r%core(1) .and. position(2, i2) < r%core(2) .and. is_owned(i2)) &
        r%radial(k, s1, s2) = r%radial(k, s1, s2) + 1
    end do
  contains
    logical function is_owned(q)
      integer, intent(in) :: q
      is_owned = .true.
      if (allocated(r%owned)) is_owned = r%owned(q)
    end function is_owned
  end subroutine sample_radial

  ! Q6 of this configuration's bonds (mod_bond_order), the whole box's, and the mean local q6 of
  ! the spheres that have bonds.
  ! The separation of a pair (centre 2 minus centre 1, dx) as the statistics see it: across the
  ! sliding boundaries of Lees-Edwards, else the minimum image in x and z.
  pure function pair_separation(r, dx) result(d)
    type(rheology_t), intent(in) :: r
    real(dp), intent(in) :: dx(3)
    real(dp) :: d(3), vshift(3)
    if (r%le%active) then
      call le_separation(r%le, dx, d, vshift)
    else
      d = min_image(dx, r%box, [.true., .false., .true.])
    end if
  end function pair_separation

  subroutine sample_order(r, position)
    type(rheology_t), intent(inout) :: r
    real(dp), intent(in) :: position(:, :)
    integer, allocatable :: ends(:, :)
    real(dp), allocatable :: separation(:, :), local(:)
    real(dp) :: d(3)
    integer :: p, nb, n
    n = size(position, 2)
    call nlist_candidates(r%bond_list, position, r%bond_pairs, r%nbond_pairs, r%bond_walls, r%nbond_walls, &
                          r%le%offset)
    allocate(ends(2, r%nbond_pairs), separation(3, r%nbond_pairs), local(n))
    nb = 0
    do p = 1, r%nbond_pairs
      d = pair_separation(r, position(:, r%bond_pairs(2, p)) - position(:, r%bond_pairs(1, p)))
      if (r%sized) then
        if (norm2(d) >= bond_factor * (r%radii(r%bond_pairs(1, p)) + r%radii(r%bond_pairs(2, p)))) cycle
      else
        if (norm2(d) >= r%bond_range) cycle
      end if
      nb = nb + 1
      ends(:, nb) = r%bond_pairs(:, p)
      separation(:, nb) = d
    end do
    if (allocated(r%owned)) then
      ! this rank's share: the bonds at its owned spheres' ends (rheo_sample_finish takes the sums)
      call bond_order_shares(n, nb, ends, separation, r%owned, r%q6_total, r%q6_bonds, local)
      r%q6_local_sum = sum(local, mask=r%owned .and. local > 0)
      r%q6_local_count = count(r%owned .and. local > 0)
      return
    end if
    call bond_order_q6(n, nb, ends, separation, r%q6, local)
    r%q6_local = sum(local) / max(1, count(local > 0))
  end subroutine sample_order

  !> This rank's shares of the last sample on a local set (rheo_set_local), in one vector: the
  !> stresses, phi_core and the particle fit's sums, the references, the profiles, the pair
  !> counts, the per-species sums, the partial pair counts and shells, Q6's sums. Summed over the
  !> ranks they are one rank's sample (to round-off: the order of the sums); rheo_sample_finish
  !> takes the sum.
  pure function rheo_sample_shares(r) result(v)
    type(rheology_t), intent(in) :: r
    real(dp), allocatable :: v(:)
    v = [r%values(1:16), r%references, reshape(r%profile, [size(r%profile)]), reshape(r%angles, [size(r%angles)]), &
         real(r%q6_total, dp), aimag(r%q6_total), r%q6_bonds, r%q6_local_sum, r%q6_local_count]
    if (r%nspecies > 1) then
      v = [v, reshape(r%species_values, [size(r%species_values)]), reshape(r%species_profile, [size(r%species_profile)]), &
           r%species_references, reshape(r%radial, [size(r%radial)])]
      if (r%nradial_volume > 0) v = [v, reshape(r%radial_volume, [size(r%radial_volume)])]
    end if
  end function rheo_sample_shares

  !> The sample from v, the sum over the ranks of rheo_sample_shares, and min_gap, the smallest
  !> pair gap over the ranks: the shares put back, and what is not a sum (the core's shear rate,
  !> Q6 and the mean local q6) formed from them.
  subroutine rheo_sample_finish(r, v, min_gap)
    type(rheology_t), intent(inout) :: r
    real(dp), intent(in) :: v(:)
    real(dp), intent(in) :: min_gap
    real(dp) :: re(0:6), im(0:6)
    integer :: k
    k = 0
    r%values(1:16) = take(16)
    r%references = sum(take(1))
    r%profile = reshape(take(size(r%profile)), shape(r%profile))
    r%angles = reshape(take(size(r%angles)), shape(r%angles))
    ! (two statements: the order of two calls in one expression is the compiler's)
    re = take(7)
    im = take(7)
    r%q6_total = cmplx(re, im, dp)
    r%q6_bonds = sum(take(1))
    r%q6_local_sum = sum(take(1))
    r%q6_local_count = sum(take(1))
    if (r%nspecies > 1) then
      r%species_values = reshape(take(size(r%species_values)), shape(r%species_values))
      r%species_profile = reshape(take(size(r%species_profile)), shape(r%species_profile))
      r%species_references = take(size(r%species_references))
      r%radial = reshape(take(size(r%radial)), shape(r%radial))
      if (r%nradial_volume > 0) r%radial_volume = reshape(take(size(r%radial_volume)), shape(r%radial_volume))
    end if
    r%min_pair_gap = min_gap
    r%shear_rate_core = line_slope(r%values(12:16))
    if (r%order) then
      r%q6 = bond_order_global(r%q6_total, r%q6_bonds)
      r%q6_local = r%q6_local_sum / max(1.0_dp, r%q6_local_count)
    end if
  contains
    function take(m) result(part)
      integer, intent(in) :: m
      real(dp) :: part(m)
      part = v(k + 1:k + m)
      k = k + m
    end function take
  end subroutine rheo_sample_finish

end module mod_rheology
