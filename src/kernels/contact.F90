! Contact law of Gallier et al. (2014, JFM) §2.4 (doc/METHOD.md §4); pure kernels, no PETSc.
! Documented in doc/CONTACT.md (parameters, units, the k_t interpretation, the history).
!
! Conventions. For a pair i < j: r = x_j - x_i (minimum image), n = r/|r|, F = force on i by j;
! j receives -F. A wall is a partner of infinite radius: n is the unit normal from the centre
! towards the wall (-e_y for the lower wall y = 0, +e_y for the upper wall y = Ly), the gap is the
! centre-to-plane distance minus a, the wall translates with its own velocity and does not rotate.
!   normal    F_n = -k_n |delta'|^{3/2} n,  delta' = |r| - 2a - h_r, contact iff delta' <= 0  (2.17)
!   stiffness 6 pi eta gamma_dot a^2 = k_n (eps_bar h_r)^{3/2}, unless k_n is prescribed     (§2.4)
!   slip      U^s = (U_i - U_j) - [(U_i - U_j).n] n + a (Omega_i + Omega_j) x n              (2.21)
!   spring    Upsilon = int U^s dt over the contact, rotated into the current tangent plane
!             (length kept) before each increment; F_t = -k_t Upsilon                       (2.19-20)
!             k_t = (2/7) k_n |delta'|^{1/2}  (paper: k_t/k_n = 2 delta^{1/2}/7, delta -> |delta'|)
!   Coulomb   |F_t| <= mu_d |F_n|; when capped, Upsilon = -F_t/k_t (spring consistent)     (2.22)
!   torque    T_i = T_j = a n x F                                                           (2.23)
!   stresslet S_i = S_j = 1/2 (F (x) r/2 + r/2 (x) F); wall: r/2 -> (a + gap/2) n           (2.24)
! Spheres of several sizes (contact_forces' radii; doc/CONTACT.md "Spheres of several sizes"): radii
! a_i in units of the unit radius a (p%a, to which k_n, eps_bar and h_r refer); for spheres i, j
!   delta' = |r| - a_i - a_j - h_r (h_r a property of the surface, not scaled with the sphere),
!   k_ij = k_n sqrt(R*_ij / (a/2)), R*_ij = a_i a_j/(a_i + a_j) (walls: k_n sqrt(a_i/a)),
!   U^s = (U_i - U_j)_perp + (a_i Omega_i + a_j Omega_j) x n, T_i = a_i n x F, T_j = a_j n x F,
!   levers (a_i + g/2) n and -(a_j + g/2) n to the middle of the gap g = |r| - a_i - a_j.
! A pair of unit spheres keeps the arithmetic above (contact_pair) bitwise.
! Contact history: Upsilon per open contact, keyed by pair identity (i, partner) with i < partner
! for a particle pair and partner = -1 (wall y = 0) or -2 (wall y = Ly) for a wall. Entries are
! rebuilt every step from the contacts found, so a contact that opens is forgotten (Upsilon
! restarts at 0). With mu_d = 0 the history is never touched: no tangential state exists.
! The image shift is deliberately not part of the key: the neighbour search requires every
! periodic length >= 2 x cutoff, so at most one image of j can touch i, and the shift of a pair
! changes when a particle is wrapped into the box during a contact.
! Lees-Edwards boundaries (contact_forces' le): the pair separation is le_separation's and the
! partner's velocity that of its sliding image, U_j + s gamma_dot Ly e_x (kept per link, image_velocity).
module mod_contact
  use mod_kinds, only: dp, pi
  use mod_vector, only: cross
  use mod_lees_edwards, only: lees_edwards_t, le_separation
  use mod_limits, only: limit_finding_t, add_finding, LIMIT_WARN, LIMIT_REFUSE
  use mod_sorting, only: ascending_order
  implicit none
  private
  public :: contact_params_t, contact_setup, contact_stats_t
  public :: contact_history_t, history_size, history_pack, history_unpack, history_clear
  public :: history_lookup, contact_pair, contact_forces, contact_stresslet
  public :: wall_lower, wall_upper, chatter_number, stick_number, flattening_estimate
  public :: contact_limits, overlap_limit
  public :: contact_links_t, contact_stiffness
  public :: contact_pair_sized, hertz_stiffness

  integer, parameter :: wall_lower = -1, wall_upper = -2   ! history partner ids of the walls

  ! largest chatter_number accepted (doc/CONTACT.md "Time-step considerations"): explicit contacts
  ! chatter beyond it; implicit ones were measured free of chatter up to IMPLICIT_CHATTER_LIMIT
  real(dp), parameter :: CHATTER_LIMIT = 0.025_dp, IMPLICIT_CHATTER_LIMIT = 0.2_dp
  ! largest stick_number without a warning: friction converged at 1.1-4.6, 14 % low at 11.4
  ! (doc/CONTACT.md "Time-step considerations", doc/VALIDATION.md §5.4)
  real(dp), parameter :: STICK_LIMIT = 5.0_dp
  ! rough frictional spheres at the densest fractions (doc/VALIDATION.md §6 "Shear jamming,
  ! revisited"): from SHEAR_JAM_MU on, at bulk phi >= SHEAR_JAM_PHI, a sheared suspension flows
  ! (498 spheres at phi 0.5495, mu_d 0.5: eta_r ~ 290 with eps_bar 0.005), but its contacts press
  ! past the roughness unless they are at least as stiff as eps_bar DENSE_EPS_BAR: every run with
  ! softer contacts (eps_bar 0.01; 77, 306 spheres) stopped on the overlap guard within a strain.
  ! Between walls the core packs denser (0.570-0.576 in a 15.6a cell, where it sheared at a fifth
  ! to a quarter of the imposed rate); small walled cells (77 spheres, 12a) jammed even with
  ! stiffer contacts.
  ! With mu_d >= SHEAR_JAM_WARN_MU the overlap guard stopped runs from SHEAR_JAM_WARN_PHI on,
  ! between walls. In Lees-Edwards cubes (12a) with mu_d 0.5 equal spheres and the 1:1.4 mixture
  ! flow at 0.57 (eta_r ~130); at 0.589 (STARTUP_JAM_PHI on) the start-up from the isotropic
  ! packing under rate control jams (the contact stress doubles every 0.02 strain, the same at two
  ! stiffnesses, until the overlap guard at strain 0.12-0.14), while stress control creeps through
  ! it and flows, and rate control branched from that flowing state flows (eta_r ~265;
  ! doc/VALIDATION.md §11.2, §12.11).
  real(dp), parameter :: SHEAR_JAM_MU = 0.2_dp, SHEAR_JAM_PHI = 0.545_dp, DENSE_EPS_BAR = 0.005_dp
  real(dp), parameter :: SHEAR_JAM_WARN_MU = 0.5_dp, SHEAR_JAM_WARN_PHI = 0.52_dp, STARTUP_JAM_PHI = 0.585_dp
  ! smooth spheres (h_r = 0) stop when an overlap exceeds this fraction of their radius
  ! (mod_particle_contacts overlap_limit; doc/CONTACT.md "Overlap guard")
  real(dp), parameter, public :: SMOOTH_OVERLAP_BOUND = 0.05_dp

  type :: contact_params_t
    real(dp) :: a = 1                   ! sphere radius [a]
    real(dp) :: h_r = 0                 ! roughness height eps_r a [a]
    real(dp) :: eps_bar = 0.05_dp       ! roughness deformation under 6 pi eta gamma_dot a^2 [-]
    real(dp) :: k_n = 0                 ! Hertz stiffness [eta gamma_dot a^(1/2)]
    real(dp) :: kt_coeff = 2.0_dp / 7   ! k_t = kt_coeff k_n |delta'|^(1/2) [-]
    real(dp) :: mu_d = 0                ! dynamic (= static) friction coefficient [-]
    real(dp) :: eta = 1, gamma_dot = 1  ! force scale 6 pi eta gamma_dot a^2 [eta, gamma_dot]
  end type contact_params_t

  !> Per-step diagnostics of contact_forces.
  type :: contact_stats_t
    integer :: pair_contacts = 0, wall_contacts = 0
    integer :: sliding = 0              ! contacts at the Coulomb limit
    real(dp) :: max_overlap = 0         ! max |delta'| / h_r (/ a when h_r = 0)
    integer :: max_overlap_pair(2) = 0  ! its particles (partner wall_lower/wall_upper for a wall)
    real(dp) :: max_normal_force = 0
    ! the force of the lower and the upper wall on the spheres (the shear stress the walls take
    ! through their contacts, doc/METHOD.md §7.4)
    real(dp) :: wall_force(3, 2) = 0
  end type contact_stats_t

  !> The open contacts of one step, for their implicit stiffness (contact_stiffness): one entry per
  !> contact found by contact_forces, in the order it met them. partner: the other particle (> i)
  !> or wall_lower/wall_upper; normal: unit normal from i towards the partner; overlap: delta'
  !> (<= 0); lever: centre of i to the middle of the gap (the stresslet's lever, r/2 for a pair);
  !> lever_partner: the partner's centre to the middle of the gap (-r/2 for equal spheres; a
  !> wall: 0, it has no stresslet); arm: the torque lever arms (a_i, a_partner) (a wall: (a_i, a_i),
  !> the second unused, a wall does not rotate); stiffness: the Hertz k of the contact (k_n for unit
  !> spheres, hertz_stiffness); spring: the spring after the step (0 without friction); sliding: at
  !> the Coulomb limit.
  type :: contact_links_t
    integer :: n = 0
    integer, allocatable :: i(:), partner(:)
    real(dp), allocatable :: normal(:,:), lever(:,:), lever_partner(:,:), spring(:,:)   ! (3, n)
    real(dp), allocatable :: arm(:,:)                                                  ! (2, n)
    real(dp), allocatable :: overlap(:), stiffness(:)
    logical, allocatable :: sliding(:)
    ! what the partner's velocity gains as seen from i: its Lees-Edwards image's s gamma_dot Ly e_x
    ! (0 without sliding boundaries, and for walls)
    real(dp), allocatable :: image_velocity(:,:)   ! (3, n)
    ! the s of that image (0 without sliding boundaries, and for walls): a stress-controlled step
    ! sets image_velocity anew for the rate it solves for (particle_contacts_set_rate)
    real(dp), allocatable :: image_shift(:)        ! (n)
    ! the image's velocity shift over the last step, whose velocities U^{n-1} the implicit
    ! contacts' Adams-Bashforth term takes (image_velocity but under stress control, where the
    ! rate of the last step differs from this one's)
    real(dp), allocatable :: image_velocity_before(:,:)   ! (3, n)
  end type contact_links_t

  !> Tangential springs of the open contacts, keyed by the global indices of the pair (owner i <
  !> partner, or i with a wall), sorted by owner, then partner: a rank that holds part of the
  !> spheres keys them as one rank would. A plain data structure: history_pack and history_unpack
  !> convert it to and from flat arrays for checkpoints.
  type :: contact_history_t
    integer :: np = 0                   ! spheres of the whole system (0: empty)
    integer :: n = 0                    ! stored contacts
    integer, allocatable :: owner(:)    ! (n) global index of the first sphere, ascending
    integer, allocatable :: partner(:)  ! (n) its partner's (or the wall's), ascending per owner
    real(dp), allocatable :: ups(:,:)   ! (3, n): Upsilon [a]
  end type contact_history_t

contains

  !> dt gamma_dot h_r / delta_0, with delta_0 = (6 pi eta gamma_dot a^2 / k_n)^(2/3) the overlap
  !> under the force scale (= dt gamma_dot / eps_bar when k_n comes from eps_bar): the explicit
  !> Hertz force against the lubricated one-step response of a pair at a gap ~h_r, i.e.
  !> dt k_eff / R with k_eff = (3/2) k_n delta_0^(1/2), R ~ 6 pi eta a^2 / h_r, up to a constant.
  !> Measured in a lubricated phi = 0.3 suspension: a period-two chatter of the contact stress at
  !> 0.04, none at 0.02 (doc/CONTACT.md "Time-step considerations"). 0 without roughness or shear.
  !> Expected largest overlap over h_r in a sheared suspension at volume fraction phi:
  !> (delta_0/h_r) g(phi), delta_0 the overlap under the force scale (= eps_bar h_r with k_n from
  !> eps_bar) and g = (F_max/F_0)^(2/3) the flattening factor of the densest force chains, measured
  !> in the Couette cell with mu_d = 0.5 over 1.4-6.5 strains (doc/VALIDATION.md §6): 3.2 at
  !> phi = 0.3, 6.9 at 0.4, 16.7 at 0.5, 26 at 0.55; linear in between, g = 1 + 2.2 phi/0.3 below
  !> 0.3 (one isolated pair carries about the force scale), the last slope beyond 0.55. An
  !> empirical estimate, for the start-up checks only: at phi = 0.55 stiffer contacts flatten more
  !> than this (eps_bar 0.01: g = 46), so the run-time overlap checks stay the enforcement.
  !> 0 without roughness or shear.
  pure real(dp) function flattening_estimate(p, phi) result(e)
    type(contact_params_t), intent(in) :: p
    real(dp), intent(in) :: phi
    real(dp), parameter :: phis(4) = [0.3_dp, 0.4_dp, 0.5_dp, 0.55_dp], g(4) = [3.2_dp, 6.9_dp, 16.7_dp, 26.0_dp]
    real(dp) :: factor
    integer :: k
    e = 0
    if (p%h_r <= 0 .or. p%gamma_dot == 0 .or. p%k_n <= 0) return
    if (phi <= phis(1)) then
      factor = 1 + (g(1) - 1) * max(phi, 0.0_dp) / phis(1)
    else
      k = min(3, count(phis(2:3) <= phi) + 1)
      factor = g(k) + (g(k + 1) - g(k)) * (phi - phis(k)) / (phis(k + 1) - phis(k))
    end if
    e = reference_overlap(p) / p%h_r * factor
  end function flattening_estimate

  pure real(dp) function chatter_number(p, dt) result(q)
    type(contact_params_t), intent(in) :: p
    real(dp), intent(in) :: dt
    q = 0
    if (p%h_r <= 0 .or. p%gamma_dot == 0 .or. p%k_n <= 0) return
    q = dt * abs(p%gamma_dot) * p%h_r / reference_overlap(p)
  end function chatter_number

  !> The slip of one step at the shear velocity, gamma_dot a dt, against the length over which a
  !> contact's spring sticks at the reference overlap, mu_d |F_n|/k_t = mu_d delta_0/kt_coeff
  !> ((2.19)-(2.22); (7/2) mu_d delta_0). Above ~5 a step turns contacts that should stick into
  !> sliding ones (doc/CONTACT.md "Time-step considerations", the friction study of
  !> doc/VALIDATION.md §5.4). 0 without friction, roughness or shear.
  pure real(dp) function stick_number(p, dt) result(q)
    type(contact_params_t), intent(in) :: p
    real(dp), intent(in) :: dt
    q = 0
    if (p%mu_d <= 0 .or. p%h_r <= 0 .or. p%gamma_dot == 0 .or. p%k_n <= 0) return
    q = dt * abs(p%gamma_dot) * p%a * p%kt_coeff / (p%mu_d * reference_overlap(p))
  end function stick_number

  !> The rough contacts against the lubricated response, checked before any work: refused beyond
  !> the chatter numbers measured (doc/CONTACT.md "Time-step considerations": explicit contacts
  !> chatter from ~0.02 on and are refused above 0.025; implicit ones were measured clean up to 0.2
  !> and are refused beyond), friction whose step slips further than a contact sticks (a warning),
  !> and, in a sheared suspension (sheared: between walls or across Lees-Edwards boundaries, at
  !> solid fraction phi), frictional spheres packed densely enough to jam (refused; a warning close
  !> to it) and roughness that would flatten completely (doc/VALIDATION.md §6).
  !> dt: the time step; implicit: the contacts are taken implicitly; eps_bar: the deck's;
  !> stiffness_prescribed: k_n is the deck's normal_stiffness (the item a refusal names).
  !> largest_radius (a mixture: the largest species' radius over the smallest, p's): the overlap
  !> estimate is that of the largest pair. A contact of two spheres of radius r carries a force
  !> ~ r^2 on a Hertz stiffness ~ r^(1/2), so its overlap grows like r (doc/CONTACT.md "Spheres of
  !> several sizes": 1.40-1.50 times the small pairs' in a 1:1.4 mixture). The chatter and stick
  !> numbers stay the unit pair's: the chatter's lubricated resistance grows faster (r^2) than the
  !> stiffness, and slip per step and sticking length both grow like r.
  function contact_limits(p, dt, implicit, sheared, phi, eps_bar, stiffness_prescribed, largest_radius) &
       result(findings)
    type(contact_params_t), intent(in) :: p
    real(dp), intent(in) :: dt, phi, eps_bar
    logical, intent(in) :: implicit, sheared, stiffness_prescribed
    real(dp), intent(in), optional :: largest_radius
    type(limit_finding_t), allocatable :: findings(:)
    real(dp) :: chatter, stick, expected_overlap, effective_eps_bar, radius_factor
    logical :: shear_jamming   ! the jamming checks apply: rough contacts under shear
    character(len=800) :: text
    allocate(findings(0))
    ! a mixture's overlaps are those of its largest pair
    radius_factor = 1
    if (present(largest_radius)) radius_factor = max(1.0_dp, largest_radius)
    chatter = chatter_number(p, dt)
    ! friction: a step that slips further than a spring sticks makes every contact slide
    stick = stick_number(p, dt)
    if (.not. implicit .and. stick > 0) then
      call add_finding(findings, LIMIT_WARN, 'explicit frictional contacts: at the one set-up measured (stick '// &
           'number 2.3) 82 % of them slid and the friction raised eta_r by 1.35 where implicit contacts give 1.67 '// &
           '(doc/CONTACT.md "Time-step considerations"): &contact implicit = .true. for friction')
    else if (stick > STICK_LIMIT) then
      write(text, '(a,f6.1,a,f4.1,a,es9.2,a)') 'friction: a step slips further than a contact sticks: '// &
           'dt gamma_dot a/((7/2) mu_d delta_0) = ', stick, ' exceeds ', STICK_LIMIT, &
           ' (contacts that should stick slide; eta_r 14 % low at 11, doc/CONTACT.md): dt <= ', &
           STICK_LIMIT * dt / stick, ' (or a larger &contact eps_bar) resolves it'
      call add_finding(findings, LIMIT_WARN, text)
    end if
    if (.not. implicit .and. chatter > CHATTER_LIMIT) then
      write(text, '(a,f6.3,a,f5.3,a,es9.2,a)') 'the explicit rough contacts would chatter: dt gamma_dot h_r/delta_0 = ', &
           chatter, ' exceeds ', CHATTER_LIMIT, &
           ' (period-two oscillation measured above it; doc/CONTACT.md): the largest stable dt here is ', &
           CHATTER_LIMIT * dt / chatter, ' (or raise &contact eps_bar, or take them implicitly: &contact implicit)'
      call add_finding(findings, LIMIT_REFUSE, text, 'time', 'dt')
    else if (implicit .and. chatter > IMPLICIT_CHATTER_LIMIT) then
      write(text, '(a,f6.3,a,f5.3,a,es9.2,a)') 'the rough contacts: dt gamma_dot h_r/delta_0 = ', chatter, &
           ' exceeds ', IMPLICIT_CHATTER_LIMIT, ', the largest chatter number at which implicit contacts were '// &
           'measured free of chatter (doc/CONTACT.md): the largest dt measured stable here is ', &
           IMPLICIT_CHATTER_LIMIT * dt / chatter, ' (or raise &contact eps_bar)'
      call add_finding(findings, LIMIT_REFUSE, text, 'time', 'dt')
    end if
    ! frictional spheres at the densest fractions: a flowing state needs contacts stiff enough that
    ! its force chains do not flatten the roughness (doc/VALIDATION.md §6 "Shear jamming,
    ! revisited"); the effective eps_bar is the overlap under the force scale over h_r, of the
    ! largest pair of a mixture (its overlaps grow like the radius)
    shear_jamming = sheared .and. p%gamma_dot /= 0 .and. p%h_r > 0 .and. p%k_n > 0
    if (shear_jamming .and. p%mu_d >= SHEAR_JAM_MU .and. phi >= SHEAR_JAM_PHI) then
      effective_eps_bar = reference_overlap(p) / p%h_r * radius_factor
      if (effective_eps_bar > DENSE_EPS_BAR * (1 + 1.0e-9_dp)) then
        write(text, '(a,f6.4,a,f5.2,a,f6.4,a,f5.3,a,es9.2,a,es9.2,a)') 'frictional spheres at phi = ', phi, &
             ' with mu_d = ', p%mu_d, ' need stiffer contacts: a flowing suspension here presses contacts this soft '// &
             '(effective eps_bar ', effective_eps_bar, ') past the roughness, and every such run stopped on the '// &
             'overlap guard within a strain, while eps_bar ', DENSE_EPS_BAR, ' flowed (498 spheres at phi 0.5495, '// &
             'mu_d 0.5; doc/VALIDATION.md §6): eps_bar <= ', eps_bar * DENSE_EPS_BAR / effective_eps_bar, &
             ' (normal_stiffness >= ', p%k_n * (effective_eps_bar / DENSE_EPS_BAR)**1.5_dp, &
             '), with dt within the stick-number limit. The limit is the asperities'' overlap budget h_r, not jamming'
        call add_finding(findings, LIMIT_REFUSE, text, 'contact', &
                         trim(merge('normal_stiffness', 'eps_bar         ', stiffness_prescribed)))
        return
      end if
      if (p%mu_d >= SHEAR_JAM_WARN_MU .and. phi >= STARTUP_JAM_PHI) then
        write(text, '(a,f6.4,a,f5.2,a)') 'phi = ', phi, ' with mu_d = ', p%mu_d, ' jams on start-up under rate '// &
             'control: at phi 0.589 with mu_d 0.5 the isotropic packing''s contact stress doubled every 0.02 strain '// &
             'whatever the stiffness until the overlap guard stopped it at strain 0.12-0.14, while the same packing '// &
             'under &shear control = ''stress'' crept through the start-up and flowed, and rate control branched '// &
             '(-branch) from that sheared state flowed (doc/VALIDATION.md §11.2, §12.11): start from a sheared state'
      else
        write(text, '(a,f6.4,a,f5.2,a)') 'phi = ', phi, ' with mu_d = ', p%mu_d, ' flows with contacts this stiff '// &
             'in Lees-Edwards cubes up to phi 0.589 (doc/VALIDATION.md §6, §11.2, §12.11); between walls '// &
             'the core packs denser (0.570-0.576 in a 15.6a cell, where the shear localised at the walls and the '// &
             'core sheared at a fifth of the rate; cells 12a high jammed at any stiffness): the overlap guard stops '// &
             'a run that jams'
      end if
      call add_finding(findings, LIMIT_WARN, text)
    else if (shear_jamming .and. p%mu_d >= SHEAR_JAM_WARN_MU .and. phi >= SHEAR_JAM_WARN_PHI) then
      write(text, '(a,f6.4,a,f5.2,a)') 'phi = ', phi, ' with mu_d = ', p%mu_d, ' is close to shear jamming: '// &
           'lubrication dynamics between walls jammed at phi 0.53 (mu_d 0.5) and 0.52 (mu_d 1) within the first '// &
           'strain (doc/VALIDATION.md §6): the overlap guard may stop this run'
      call add_finding(findings, LIMIT_WARN, text)
    end if
    ! the roughness of a dense suspension flattens under its force chains (doc/VALIDATION.md §6)
    if (sheared) then
      expected_overlap = flattening_estimate(p, phi) * radius_factor
      if (expected_overlap > 1.0_dp) then
        write(text, '(a,f6.2,a,f5.3,a,es9.2,a)') 'the roughness would flatten completely: expected largest overlap ', &
             expected_overlap, ' h_r at phi = ', phi, ' (doc/VALIDATION.md §6); stiffer contacts, eps_bar <= ', &
             0.5_dp * eps_bar / expected_overlap, ' (or a larger normal_stiffness), keep it below h_r/2'
        call add_finding(findings, LIMIT_REFUSE, text, 'contact', &
                         trim(merge('normal_stiffness', 'eps_bar         ', stiffness_prescribed)))
      else if (expected_overlap > 0.5_dp) then
        write(text, '(a,f6.2,a,f5.3,a)') 'expected largest contact overlap ', expected_overlap, ' h_r at phi = ', &
             phi, ' (> h_r/2, doc/VALIDATION.md §6): a smaller &contact eps_bar keeps the roughness'
        call add_finding(findings, LIMIT_WARN, text)
      end if
    end if
  end function contact_limits

  !> A run's largest contact overlap grows from largest_before to overlap at step (both in a): warned
  !> once, when it passes half the guard's bound, h_r/2 for rough spheres (the bound the extreme
  !> scenes hold, doc/VALIDATION.md §6) and 0.025 a for smooth ones (their guard stops at 0.05 a).
  function overlap_limit(p, largest_before, overlap, step) result(findings)
    type(contact_params_t), intent(in) :: p
    real(dp), intent(in) :: largest_before, overlap
    integer, intent(in) :: step
    type(limit_finding_t), allocatable :: findings(:)
    character(len=400) :: text
    real(dp) :: bound
    allocate(findings(0))
    bound = p%h_r
    if (bound <= 0) bound = SMOOTH_OVERLAP_BOUND * p%a
    if (largest_before > 0.5_dp * bound .or. overlap <= 0.5_dp * bound) return
    if (p%h_r > 0) then
      write(text, '(a,i0,a,f6.3,a)') 'at step ', step, ' a contact overlap reaches ', &
           overlap / p%h_r, ' h_r (> h_r/2): stiffer contacts (a smaller &contact eps_bar '// &
           'or a larger normal_stiffness, with dt gamma_dot h_r/delta_0 within its limit, doc/CONTACT.md) keep the '// &
           'roughness from flattening'
    else
      write(text, '(a,i0,a,es9.2,a,f5.3,a)') 'at step ', step, ' a contact overlap of smooth spheres reaches ', &
           overlap / p%a, ' a (> ', 0.5_dp * SMOOTH_OVERLAP_BOUND, &
           ' a, half the bound at which the run stops): a larger &contact normal_stiffness keeps them apart'
    end if
    call add_finding(findings, LIMIT_WARN, text)
  end function overlap_limit

  !> delta_0 = (6 pi eta gamma_dot a^2 / k_n)^(2/3): the Hertz overlap under the force scale
  !> (eps_bar h_r when k_n comes from eps_bar); needs k_n > 0 and gamma_dot /= 0.
  pure real(dp) function reference_overlap(p) result(delta_0)
    type(contact_params_t), intent(in) :: p
    delta_0 = (6 * pi * p%eta * abs(p%gamma_dot) * p%a**2 / p%k_n)**(2.0_dp / 3)
  end function reference_overlap

  !> Parameters from the deck quantities. eps_r = h_r/a. k_n_prescribed > 0 overrides the eps_bar
  !> rule. info: 0 ok; 1 a <= 0, eta <= 0 or a negative eps_r, mu_d; 2 k_n cannot be derived
  !> (h_r = 0, eps_bar <= 0 or gamma_dot = 0) and none is prescribed.
  subroutine contact_setup(p, a, eps_r, mu_d, eps_bar, k_n_prescribed, eta, gamma_dot, info, msg)
    type(contact_params_t), intent(out) :: p
    real(dp), intent(in) :: a, eps_r, mu_d, eps_bar, k_n_prescribed, eta, gamma_dot
    integer, intent(out) :: info
    character(len=*), intent(out) :: msg
    info = 0
    msg = ''
    p%a = a
    p%h_r = eps_r * a
    p%mu_d = mu_d
    p%eps_bar = eps_bar
    p%eta = eta
    p%gamma_dot = abs(gamma_dot)
    if (.not. (a > 0) .or. .not. (eta > 0) .or. .not. (eps_r >= 0) .or. .not. (mu_d >= 0)) then
      info = 1
      msg = 'contact: a and eta must be > 0, eps_r and mu_d >= 0'
    else if (k_n_prescribed > 0) then
      p%k_n = k_n_prescribed
    else if (p%h_r <= 0) then
      info = 2
      msg = 'contact: smooth spheres (eps_r = 0) need a prescribed k_n > 0'
    else if (.not. (eps_bar > 0) .or. p%gamma_dot <= 0) then
      info = 2
      msg = 'contact: k_n from eps_bar needs eps_bar > 0 and a non-zero shear rate'
    else
      p%k_n = 6 * pi * eta * p%gamma_dot * a**2 / (eps_bar * p%h_r)**1.5_dp
    end if
  end subroutine contact_setup

  ! ---- one contact -----------------------------------------------------------------------

  !> One contact of two unit spheres (or a unit sphere and a wall). n: unit normal from i towards
  !> the partner; dlt = delta' (contact iff <= 0); du = U_i - U_partner; om_sum = Omega_i +
  !> Omega_partner (wall: Omega_i); dt: time step. ups: the spring, in: the previous step's (0 for
  !> a new contact), out: updated (0 if open or mu_d = 0). f: force on i; tq: torque on i (the
  !> partner sphere gets -f and the same tq); fn: |F_n|; sliding: the Coulomb cap was applied.
  pure subroutine contact_pair(p, n, dlt, du, om_sum, dt, ups, f, tq, fn, sliding)
    type(contact_params_t), intent(in) :: p
    real(dp), intent(in) :: n(3), dlt, du(3), om_sum(3), dt
    real(dp), intent(inout) :: ups(3)
    real(dp), intent(out) :: f(3), tq(3), fn
    logical, intent(out) :: sliding
    call contact_law(p, p%k_n, n, dlt, du, p%a * cross(om_sum, n), dt, ups, f, fn, sliding)   ! (2.21)
    tq = 0
    if (p%mu_d > 0 .and. dlt <= 0) tq = p%a * cross(n, f)              ! (2.23); frictionless: none
  end subroutine contact_pair

  !> One contact of spheres of any sizes (doc/CONTACT.md "Spheres of several sizes"), or of a sphere
  !> and a wall. k: the contact's Hertz stiffness (hertz_stiffness); arm_i: the radius a_i of
  !> sphere i; om_i: Omega_i; om_j, arm_j, tq_j, optional: the partner sphere's Omega_j, radius
  !> a_j and the torque on it, a_j n x F (absent for a wall, which does not rotate); tq_i: the torque
  !> a_i n x F on i. Otherwise as contact_pair: the slip is (2.21) with a Omega_i + a Omega_j ->
  !> a_i Omega_i + a_j Omega_j.
  pure subroutine contact_pair_sized(p, k, n, dlt, du, om_i, arm_i, dt, ups, f, tq_i, fn, sliding, om_j, arm_j, tq_j)
    type(contact_params_t), intent(in) :: p
    real(dp), intent(in) :: k, n(3), dlt, du(3), om_i(3), arm_i, dt
    real(dp), intent(inout) :: ups(3)
    real(dp), intent(out) :: f(3), tq_i(3), fn
    logical, intent(out) :: sliding
    real(dp), intent(in), optional :: om_j(3), arm_j
    real(dp), intent(out), optional :: tq_j(3)
    real(dp) :: roll(3), c(3)
    if (present(om_j)) then
      roll = cross(arm_i * om_i + arm_j * om_j, n)
    else
      roll = arm_i * cross(om_i, n)      ! a wall: as contact_pair's a (Omega_i x n) for a unit sphere
    end if
    call contact_law(p, k, n, dlt, du, roll, dt, ups, f, fn, sliding)
    c = 0
    if (p%mu_d > 0 .and. dlt <= 0) c = cross(n, f)
    tq_i = arm_i * c
    if (present(tq_j)) tq_j = arm_j * c
  end subroutine contact_pair_sized

  !> The Hertz stiffness of a contact of spheres of radii ai, aj (absent: a wall), in the unit of
  !> p%a: k_n sqrt(R*/R*_1) with R* = ai aj/(ai + aj) the reduced radius and R*_1 = a/2 that of two
  !> unit spheres (for a wall R* = ai and R*_1 = a: the wall keeps the pair's k_n for a unit sphere,
  !> doc/CONTACT.md "Walls"). Exactly k_n for unit spheres.
  pure real(dp) function hertz_stiffness(p, ai, aj) result(k)
    type(contact_params_t), intent(in) :: p
    real(dp), intent(in) :: ai
    real(dp), intent(in), optional :: aj
    if (present(aj)) then
      k = p%k_n * sqrt(2 * ai * aj / ((ai + aj) * p%a))
    else
      k = p%k_n * sqrt(ai / p%a)
    end if
  end function hertz_stiffness

  !> The law of one contact (doc/CONTACT.md "One step of a contact"), shared by contact_pair and
  !> contact_pair_sized: Hertz stiffness k; roll = the rotational part of the slip (2.21),
  !> (a_i Omega_i + a_j Omega_j) x n; f: the force on i; no torque.
  pure subroutine contact_law(p, k, n, dlt, du, roll, dt, ups, f, fn, sliding)
    type(contact_params_t), intent(in) :: p
    real(dp), intent(in) :: k, n(3), dlt, du(3), roll(3), dt
    real(dp), intent(inout) :: ups(3)
    real(dp), intent(out) :: f(3), fn
    logical, intent(out) :: sliding
    real(dp) :: us(3), len0, len1, k_t, ft(3), ftm
    f = 0
    fn = 0
    sliding = .false.
    if (dlt > 0 .or. p%mu_d <= 0) ups = 0
    if (dlt > 0) return
    fn = k * abs(dlt)**1.5_dp                                      ! (2.17)
    f = -fn * n
    if (p%mu_d > 0) then
      ! rotate the old spring into the current tangent plane, keeping its length
      len0 = norm2(ups)
      ups = ups - dot_product(ups, n) * n
      len1 = norm2(ups)
      if (len1 > 0) then
        ups = ups * (len0 / len1)
      else
        ups = 0
      end if
      us = du - dot_product(du, n) * n + roll                       ! (2.21)
      ups = ups + us * dt                                           ! (2.20)
      k_t = p%kt_coeff * k * sqrt(abs(dlt))
      ft = -k_t * ups                                               ! (2.19)
      ftm = norm2(ft)
      if (fn <= 0) then
        ups = 0                                   ! delta' = 0 exactly: the Coulomb limit is 0
        ft = 0
      else if (ftm > p%mu_d * fn) then            ! (2.22), spring reset to match
        ft = ft * (p%mu_d * fn / ftm)
        ups = -ft / k_t
        sliding = .true.
      end if
      f = f + ft
    end if                                     ! frictionless: F parallel to n
  end subroutine contact_law

  !> Symmetric contact stresslet (2.24) of a force f applied with lever l (centre to contact).
  pure function contact_stresslet(f, l) result(s)
    real(dp), intent(in) :: f(3), l(3)
    real(dp) :: s(3, 3)
    integer :: k, m
    do m = 1, 3
      do k = 1, 3
        s(k, m) = 0.5_dp * (f(k) * l(m) + l(k) * f(m))
      end do
    end do
  end function contact_stresslet

  !> The linearised stiffness of one contact (doc/CONTACT.md "Implicit contacts"), in the
  !> generalised coordinates q = (U_i, Omega_i, U_partner, Omega_partner) (12) of contact_pair
  !> (for a wall: its translation and zero rotation). n, dlt, sliding: as contact_pair saw them;
  !> ups: the spring contact_pair left (at the Coulomb limit when sliding).
  !>   k_norm = k b b^T, b = (n, 0, -n, 0), k = dF_n/d|delta'| = (3/2) k_n |delta'|^{1/2}: the
  !>            generalised force changes by -k_norm dX for displacements dX of the two bodies
  !>            (the geometric term |F_n|/|r| (I - n n^T) of the turning normal, smaller by
  !>            |delta'|/|r| and not positive semi-definite, is left out);
  !>   k_tan  = k_t B^T B, B = (P, -a [n]x, -P, -a [n]x), P = I - n n^T, so that B q is the slip
  !>            velocity U^s of (2.21); the force changes by -k_tan dq dt when the spring takes one
  !>            more increment U^s dt. A sliding contact (|F_t| = mu_d |F_n|, spring ups at the
  !>            limit) keeps that stiffness across its slip direction s = ups/|ups| only:
  !>            k_t B^T (I - s s^T) B, the derivative of the capped force -mu_d |F_n| s' with
  !>            s' the direction of ups + U^s dt (the consistent tangent of the Coulomb return:
  !>            mu_d |F_n|/|ups| = k_t; along s the force stays mu_d |F_n|). Frictionless
  !>            contacts, and those at delta' = 0, have none.
  !> Both symmetric positive semi-definite by construction (sums of outer products). Open
  !> contacts (dlt > 0) give zero blocks.
  !> Spheres of several sizes (doc/CONTACT.md "Spheres of several sizes"), optional: arms = (a_i,
  !> a_partner), the lever arms in B (-a_i [n]x, -a_partner [n]x; default (a, a); a wall's is
  !> unused), and k_hertz, the contact's Hertz stiffness (hertz_stiffness; default k_n), which
  !> replaces k_n in k and k_t. Rows 10-12 of both blocks are then a_partner/a_i times rows 4-6.
  pure subroutine contact_stiffness(p, n, dlt, ups, sliding, k_norm, k_tan, arms, k_hertz)
    type(contact_params_t), intent(in) :: p
    real(dp), intent(in) :: n(3), dlt, ups(3)
    logical, intent(in) :: sliding
    real(dp), intent(out) :: k_norm(12, 12), k_tan(12, 12)
    real(dp), intent(in), optional :: arms(2), k_hertz
    real(dp) :: b(12), bt(3, 12), k, k_t, s(3), kh, arm(2)
    integer :: c
    k_norm = 0
    k_tan = 0
    if (dlt > 0) return
    kh = p%k_n
    if (present(k_hertz)) kh = k_hertz
    arm = p%a
    if (present(arms)) arm = arms
    k = 1.5_dp * kh * sqrt(abs(dlt))
    b = 0
    b(1:3) = n
    b(7:9) = -n
    k_norm = k * spread(b, 2, 12) * spread(b, 1, 12)
    if (p%mu_d <= 0 .or. dlt == 0) return
    k_t = p%kt_coeff * kh * sqrt(abs(dlt))
    bt = 0
    do c = 1, 3
      bt(c, c) = 1
      bt(:, c) = bt(:, c) - n(c) * n                       ! P
      bt(:, 6 + c) = -bt(:, c)                             ! -P
      bt(:, 3 + c) = -arm(1) * cross(n, unit(c))           ! -a_i n x e_c
      bt(:, 9 + c) = -arm(2) * cross(n, unit(c))           ! -a_partner n x e_c
    end do
    k_tan = k_t * matmul(transpose(bt), bt)
    if (sliding) then
      s = 0
      if (norm2(ups) > 0) s = ups / norm2(ups)
      b = matmul(s, bt)                                    ! B^T s
      k_tan = k_tan - k_t * spread(b, 2, 12) * spread(b, 1, 12)
    end if
  contains
    pure function unit(c) result(e)
      integer, intent(in) :: c
      real(dp) :: e(3)
      e = 0
      e(c) = 1
    end function unit
  end subroutine contact_stiffness

  ! ---- all contacts of one step ------------------------------------------------------------

  !> All contacts of one step. x, u, om: (3, np) positions, velocities, angular velocities;
  !> box, periodic: the domain (walls at y = 0 and y = box(2) when .not. periodic(2));
  !> vw(3, 2): velocities of the lower and upper walls; pairs(2, npairs): candidate pairs (any
  !> order, each pair once, e.g. from mod_neighbours); walls(2, nwalls): candidates (particle,
  !> wall 1 = lower | 2 = upper). Outputs per particle: force, torque (3, np), symmetric contact
  !> stresslet (3, 3, np); stats. The history h advances by one step (not touched if mu_d = 0).
  !> info: 0 ok; 1 the history was built for another particle count. links, optional: the open
  !> contacts of this step (for their implicit stiffness, contact_stiffness). le, optional:
  !> Lees-Edwards boundaries in y (mod_lees_edwards), when active. radii, optional: (np) the
  !> spheres' radii in units of p%a (doc/CONTACT.md "Spheres of several sizes"); absent, all are
  !> p%a. A pair of unit spheres (radius exactly 1) takes the arithmetic of the equal-sphere law
  !> (contact_pair) whether radii is given or not, so that results are bitwise those without it.
  !> A rank's local set (doc/DESIGN.md "Spheres held by their slab"): ids (np) the global index of
  !> each sphere (ascending), owned (np) those the rank owns, total the spheres of the whole system.
  !> Then only the pairs with an owned sphere are evaluated (an owned sphere has all its contacts,
  !> in one rank's order), the walls of owned spheres only, the history is keyed and the
  !> overlap's pair named by global index, and stats count each pair on the rank that owns its
  !> first sphere (summed over ranks they are one rank's). Absent: every sphere, ids = 1..np.
  subroutine contact_forces(p, h, x, u, om, box, periodic, vw, pairs, npairs, walls, nwalls, dt, &
                            force, torque, stresslet, stats, info, links, le, radii, ids, owned, total)
    type(contact_params_t), intent(in) :: p
    type(contact_history_t), intent(inout) :: h
    real(dp), intent(in) :: x(:,:), u(:,:), om(:,:), box(3), vw(3, 2), dt
    logical, intent(in) :: periodic(3)
    integer, intent(in) :: pairs(:,:), npairs, walls(:,:), nwalls
    real(dp), intent(out) :: force(:,:), torque(:,:), stresslet(:,:,:)
    type(contact_stats_t), intent(out) :: stats
    integer, intent(out) :: info
    type(contact_links_t), intent(inout), optional :: links
    type(lees_edwards_t), intent(in), optional :: le
    real(dp), intent(in), optional :: radii(:)
    integer, intent(in), optional :: ids(:), total
    logical, intent(in), optional :: owned(:)
    integer :: m, i, j, k, w, np, nnew, gi, gj
    integer, allocatable :: new_owner(:), new_partner(:)
    real(dp), allocatable :: new_ups(:,:)
    real(dp) :: r(3), d, n(3), dlt, ups(3), f(3), tq(3), tqj(3), fn, scale, s(3, 3), sj(3, 3), vshift(3)
    real(dp) :: ai, aj, kh, li(3), lj(3)
    logical :: tangential, sliding, sliding_boundaries, sized

    info = 0
    np = size(x, 2)
    if (present(total)) np = total
    force = 0
    torque = 0
    stresslet = 0
    tangential = p%mu_d > 0
    if (tangential .and. h%np /= 0 .and. h%np /= np) then
      info = 1
      return
    end if
    if (tangential) allocate(new_owner(npairs + nwalls), new_partner(npairs + nwalls), &
                             new_ups(3, npairs + nwalls))
    nnew = 0
    scale = p%h_r
    if (scale <= 0) scale = p%a
    if (present(links)) call links_reserve(links, npairs + nwalls)
    sliding_boundaries = .false.
    if (present(le)) sliding_boundaries = le%active
    vshift = 0

    do m = 1, npairs
      i = min(pairs(1, m), pairs(2, m))
      j = max(pairs(1, m), pairs(2, m))
      if (present(owned)) then
        if (.not. (owned(i) .or. owned(j))) cycle
      end if
      r = x(:, j) - x(:, i)
      if (sliding_boundaries) then
        call le_separation(le, x(:, j) - x(:, i), r, vshift)
      else
        do k = 1, 3
          if (periodic(k)) r(k) = r(k) - box(k) * anint(r(k) / box(k))
        end do
      end if
      d = norm2(r)
      ai = p%a
      aj = p%a
      sized = .false.
      if (present(radii)) then
        sized = radii(i) /= 1 .or. radii(j) /= 1
        ai = radii(i) * p%a
        aj = radii(j) * p%a
      end if
      dlt = d - (ai + aj) - p%h_r               ! unit spheres: ai + aj = 2a exactly
      if (dlt > 0) cycle
      n = r / d
      ups = 0
      gi = global(i)
      gj = global(j)
      if (tangential) ups = history_lookup(h, gi, gj)
      if (sized) then
        ! levers to the middle of the gap d - ai - aj (doc/CONTACT.md "Spheres of several sizes")
        kh = hertz_stiffness(p, ai, aj)
        call contact_pair_sized(p, kh, n, dlt, u(:, i) - (u(:, j) + vshift), om(:, i), ai, dt, ups, f, tq, fn, &
                                sliding, om(:, j), aj, tqj)
        li = (ai + 0.5_dp * (d - ai - aj)) * n
        lj = -(aj + 0.5_dp * (d - ai - aj)) * n
        s = contact_stresslet(f, li)
        sj = contact_stresslet(-f, lj)
      else
        kh = p%k_n
        call contact_pair(p, n, dlt, u(:, i) - (u(:, j) + vshift), om(:, i) + om(:, j), dt, ups, f, tq, fn, &
                          sliding)
        tqj = tq
        li = 0.5_dp * r
        lj = -li
        s = contact_stresslet(f, li)
        sj = s
      end if
      if (tangential) call append(gi, gj)
      force(:, i) = force(:, i) + f
      force(:, j) = force(:, j) - f
      torque(:, i) = torque(:, i) + tq
      torque(:, j) = torque(:, j) + tqj
      stresslet(:, :, i) = stresslet(:, :, i) + s
      stresslet(:, :, j) = stresslet(:, :, j) + sj
      if (present(links)) call add_link(j, li, lj, [ai, aj], vshift, image_shift_of(r(2) - (x(2, j) - x(2, i))))
      call tally(.false., gj)
    end do

    do m = 1, nwalls
      i = walls(1, m)
      w = walls(2, m)
      if (present(owned)) then
        if (.not. owned(i)) cycle
      end if
      gi = global(i)
      if (w == 1) then
        d = x(2, i)
        n = [0.0_dp, -1.0_dp, 0.0_dp]
      else
        d = box(2) - x(2, i)
        n = [0.0_dp, 1.0_dp, 0.0_dp]
      end if
      ai = p%a
      if (present(radii)) ai = radii(i) * p%a
      dlt = d - ai - p%h_r
      if (dlt > 0) cycle
      ups = 0
      if (tangential) ups = history_lookup(h, gi, -w)
      ! a unit sphere: k_n and contact_pair's arithmetic exactly (ai = a)
      kh = hertz_stiffness(p, ai)
      call contact_pair_sized(p, kh, n, dlt, u(:, i) - vw(:, w), om(:, i), ai, dt, ups, f, tq, fn, sliding)
      if (tangential) call append(gi, -w)
      force(:, i) = force(:, i) + f
      stats%wall_force(:, w) = stats%wall_force(:, w) + f
      torque(:, i) = torque(:, i) + tq
      li = 0.5_dp * (ai + d) * n               ! (a_i + gap/2) n, gap = d - a_i
      stresslet(:, :, i) = stresslet(:, :, i) + contact_stresslet(f, li)
      if (present(links)) call add_link(-w, li, [0.0_dp, 0.0_dp, 0.0_dp], [ai, ai], [0.0_dp, 0.0_dp, 0.0_dp], 0.0_dp)
      call tally(.true., -w)
    end do

    if (tangential) call history_build(h, np, nnew, new_owner, new_partner, new_ups, info)

  contains

    ! the global index of local sphere q
    integer function global(q)
      integer, intent(in) :: q
      global = q
      if (present(ids)) global = ids(q)
    end function global

    subroutine append(owner, other)
      integer, intent(in) :: owner, other
      nnew = nnew + 1
      new_owner(nnew) = owner
      new_partner(nnew) = other
      new_ups(:, nnew) = ups
    end subroutine append

    subroutine add_link(other, lever, lever_partner, arm, image_velocity, image_shift)
      integer, intent(in) :: other
      real(dp), intent(in) :: lever(3), lever_partner(3), arm(2), image_velocity(3), image_shift
      links%n = links%n + 1
      links%i(links%n) = i
      links%partner(links%n) = other
      links%normal(:, links%n) = n
      links%lever(:, links%n) = lever
      links%lever_partner(:, links%n) = lever_partner
      links%arm(:, links%n) = arm
      links%stiffness(links%n) = kh
      links%overlap(links%n) = dlt
      links%spring(:, links%n) = ups
      links%sliding(links%n) = sliding
      links%image_velocity(:, links%n) = image_velocity
      links%image_shift(links%n) = image_shift
      links%image_velocity_before(:, links%n) = image_velocity
    end subroutine add_link

    ! s of the Lees-Edwards image (le_separation shifted the y separation by s Ly: dy, 0 or +-Ly)
    real(dp) function image_shift_of(dy) result(s)
      real(dp), intent(in) :: dy
      s = 0
      if (sliding_boundaries) s = anint(dy / box(2))
    end function image_shift_of

    ! partner: the global index of the other sphere, or the wall's id
    subroutine tally(wall, partner)
      logical, intent(in) :: wall
      integer, intent(in) :: partner
      if (present(owned)) then
        ! a pair across two ranks is counted by the owner of its first sphere
        if (.not. owned(i)) return
      end if
      if (wall) then
        stats%wall_contacts = stats%wall_contacts + 1
      else
        stats%pair_contacts = stats%pair_contacts + 1
      end if
      if (sliding) stats%sliding = stats%sliding + 1
      if (-dlt / scale > stats%max_overlap) then
        stats%max_overlap = -dlt / scale
        stats%max_overlap_pair = [global(i), partner]
      end if
      stats%max_normal_force = max(stats%max_normal_force, fn)
    end subroutine tally

  end subroutine contact_forces

  !> Empty links with room for at least m contacts (kept allocated from step to step).
  pure subroutine links_reserve(links, m)
    type(contact_links_t), intent(inout) :: links
    integer, intent(in) :: m
    links%n = 0
    if (allocated(links%i)) then
      if (size(links%i) >= m) return
      deallocate(links%i, links%partner, links%normal, links%lever, links%lever_partner, links%arm, links%spring, &
                 links%overlap, links%stiffness, links%sliding, links%image_velocity, links%image_shift, &
                 links%image_velocity_before)
    end if
    allocate(links%i(max(m, 16)), links%partner(max(m, 16)), links%normal(3, max(m, 16)), &
             links%lever(3, max(m, 16)), links%lever_partner(3, max(m, 16)), links%arm(2, max(m, 16)), &
             links%spring(3, max(m, 16)), links%overlap(max(m, 16)), links%stiffness(max(m, 16)), &
             links%sliding(max(m, 16)), links%image_velocity(3, max(m, 16)), links%image_shift(max(m, 16)), &
             links%image_velocity_before(3, max(m, 16)))
  end subroutine links_reserve

  ! ---- the history -------------------------------------------------------------------------

  integer function history_size(h)
    type(contact_history_t), intent(in) :: h
    history_size = h%n
  end function history_size

  subroutine history_clear(h)
    type(contact_history_t), intent(inout) :: h
    h%np = 0
    h%n = 0
    if (allocated(h%owner)) deallocate(h%owner)
    if (allocated(h%partner)) deallocate(h%partner)
    if (allocated(h%ups)) deallocate(h%ups)
  end subroutine history_clear

  !> The stored spring of contact (i, partner) (global indices), i < partner or partner < 0; 0 if
  !> none. A bisection for i's first contact, then its few partners.
  pure function history_lookup(h, i, partner) result(ups)
    type(contact_history_t), intent(in) :: h
    integer, intent(in) :: i, partner
    real(dp) :: ups(3)
    integer :: k, lo, hi, mid
    ups = 0
    if (h%n == 0) return
    lo = 1
    hi = h%n + 1
    do while (lo < hi)
      mid = (lo + hi) / 2
      if (h%owner(mid) < i) then
        lo = mid + 1
      else
        hi = mid
      end if
    end do
    do k = lo, h%n
      if (h%owner(k) /= i .or. h%partner(k) > partner) return
      if (h%partner(k) == partner) then
        ups = h%ups(:, k)
        return
      end if
    end do
  end function history_lookup

  !> (Re)build h from an unordered list of n contacts (owner, partner, ups) of a system of np
  !> spheres: sorted by owner, then partner (the walls, -2 and -1, before the spheres), whatever
  !> the input order. info = 2 for an invalid index, 3 for a duplicate contact (h is then left
  !> empty). The storage is O(contacts), not O(np): a rank holding part of the spheres holds the
  !> springs of its own contacts only (doc/DESIGN.md "Spheres held by their slab").
  subroutine history_build(h, np, n, owner, partner, ups, info)
    type(contact_history_t), intent(inout) :: h
    integer, intent(in) :: np, n
    integer, intent(in) :: owner(:), partner(:)
    real(dp), intent(in) :: ups(:,:)
    integer, intent(out) :: info
    integer :: k
    integer, allocatable :: order(:)
    info = 0
    call history_clear(h)
    if (np < 1) then
      if (n > 0) info = 2
      return
    end if
    do k = 1, n
      if (owner(k) < 1 .or. owner(k) > np .or. .not. (partner(k) == wall_lower .or. partner(k) == wall_upper &
          .or. (partner(k) > owner(k) .and. partner(k) <= np))) then
        info = 2
        return
      end if
    end do
    ! lexicographic: a stable sort by owner of the list sorted by partner
    allocate(order(n))
    order = ascending_order(partner(1:n))
    order = order(ascending_order(owner(order)))
    h%np = np
    h%n = n
    allocate(h%owner(n), h%partner(n), h%ups(3, n))
    h%owner = owner(order)
    h%partner = partner(order)
    h%ups = ups(:, order)
    do k = 2, n
      if (h%owner(k) == h%owner(k - 1) .and. h%partner(k) == h%partner(k - 1)) info = 3
    end do
    if (info /= 0) call history_clear(h)
  end subroutine history_build

  !> Flat arrays for a checkpoint: ids(1:2, k) = (owner, partner), ups(1:3, k), k = 1..history_size,
  !> in canonical order (owner, then partner). np is the particle count the history belongs to.
  !> The arrays must hold at least history_size(h) columns.
  subroutine history_pack(h, np, ids, ups)
    type(contact_history_t), intent(in) :: h
    integer, intent(out) :: np
    integer, intent(out) :: ids(:,:)
    real(dp), intent(out) :: ups(:,:)
    np = h%np
    if (h%n == 0) return              ! (an empty history has no arrays)
    ids(1, 1:h%n) = h%owner(1:h%n)
    ids(2, 1:h%n) = h%partner(1:h%n)
    ups(:, 1:h%n) = h%ups(:, 1:h%n)
  end subroutine history_pack

  !> Inverse of history_pack: n contacts ids(2, n), ups(3, n) of a system of np particles, in any
  !> order. info: 0 ok; 2 an id is invalid (owner outside 1..np, partner not > owner nor a wall);
  !> 3 a contact appears twice. On error h is empty.
  subroutine history_unpack(h, np, n, ids, ups, info)
    type(contact_history_t), intent(inout) :: h
    integer, intent(in) :: np, n
    integer, intent(in) :: ids(:,:)
    real(dp), intent(in) :: ups(:,:)
    integer, intent(out) :: info
    call history_build(h, np, n, ids(1, 1:n), ids(2, 1:n), ups(:, 1:n), info)
  end subroutine history_unpack

end module mod_contact
