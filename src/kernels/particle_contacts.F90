! Contacts in the particle time step (doc/CONTACT.md, "Wiring into the time step"): the contact
! parameters, the neighbour list and the contact history of one run, and one call per step.
! Pure: no PETSc, MPI or files. Every sphere on every rank (the replicated state), or a rank's local
! set (particle_contacts_set_local: its own spheres and their ghosts; the pairs with an own sphere,
! the springs keyed by global index; doc/DESIGN.md "Parallelism").
!
! One step (doc/METHOD.md §7.1 item 2), at the positions X^n, before the particle sub-problem:
!   1. the neighbour list (cutoff 2a + h_r + skin, walls a + h_r + skin, a the largest radius) is
!      rebuilt when some sphere has moved more than skin/2 since the last build;
!   2. its candidates are put in canonical order (pairs by i then j, walls by particle then wall),
!      so that the forces are summed in the same order whatever list is in use: a run restarted
!      from a checkpoint (fresh list) repeats the arithmetic of an uninterrupted one bitwise;
!   3. contact_forces with the latest velocities U, Omega (those of the previous step) and the
!      wall velocities (-+ shear_rate Ly/2 along x): per-particle force, torque and symmetric
!      stresslet, the history advanced by one step.
! Implicit contacts (doc/CONTACT.md "Implicit contacts"; the default, pc%implicit): the particle
! solve then adds the linearised stiffness of every open contact to its 6N system
! (particle_contacts_add_stiffness) and, once U^n is known, the force it implied to the step's contact
! force, torque and stresslet (particle_contacts_implicit_update): the force the balance used is the
! contact force at the end of the step, X^{n+1}, linearised about X^n.
! Spheres of several sizes (doc/CONTACT.md "Spheres of several sizes"): particle_contacts_create's
! radii; each contact then has its own Hertz stiffness, lever arms and stresslet levers (the links).
module mod_particle_contacts
  use mod_kinds, only: dp
  use mod_contact, only: contact_params_t, contact_setup, contact_stats_t, contact_history_t, &
                         contact_forces, contact_links_t, contact_stiffness, contact_stresslet, &
                         SMOOTH_OVERLAP_BOUND
  use mod_neighbours, only: nlist_t, nlist_init, nlist_candidates
  use mod_lees_edwards, only: lees_edwards_t
  use mod_particle_system, only: particle_system_t, particle_system_add_diagonal, particle_system_add_pair
  use mod_columns, only: column_t, column, sphere_column, sphere_rows
  implicit none
  private
  public :: particle_contacts_settings_t, particle_contacts_t, particle_contacts_create, particle_contacts_step, &
            particle_contacts_description
  public :: particle_contacts_add_stiffness, particle_contacts_implicit_update, particle_contacts_columns, &
            particle_contacts_set_rate, particle_contacts_set_local

  ! The deck's &contact (doc/INPUT.md): its variables, named as in the deck, with their defaults.
  type :: particle_contacts_settings_t
    real(dp) :: roughness = 0.0_dp         ! eps_r = h_r/a [-]
    real(dp) :: eps_bar = 0.05_dp          ! roughness deformation under 6 pi eta gamma_dot a^2 [-]
    real(dp) :: friction = 0.0_dp          ! mu_d [-]
    real(dp) :: normal_stiffness = 0.0_dp  ! k_n [eta gamma_dot a^(1/2)] (0: from eps_bar)
    real(dp) :: neighbour_skin = 0.2_dp    ! neighbour-list skin [a]
    logical :: implicit = .true.           ! linearised contact stiffness in the particle solve
  end type particle_contacts_settings_t

  type :: particle_contacts_t
    type(contact_params_t) :: params
    type(contact_history_t) :: history       ! tangential springs (empty when mu_d = 0)
    type(nlist_t) :: nlist
    integer :: np = 0
    real(dp) :: box(3) = 0, dt = 0
    logical :: periodic(3) = .true.
    real(dp) :: wall_velocity(3, 2) = 0      ! lower, upper wall
    real(dp) :: overlap_limit = 0            ! |delta'| beyond which the run must stop [a]
    integer :: npairs = 0, nwalls = 0        ! candidates in canonical order
    integer, allocatable :: pairs(:,:), walls(:,:)
    type(contact_stats_t) :: stats           ! of the last step
    real(dp) :: max_overlap = 0              ! max |delta'| of the last step [a]
    real(dp), allocatable :: force(:,:), torque(:,:), stresslet(:,:,:)   ! of the last step
    ! the force of the lower and the upper wall on the spheres in the last step, explicit and
    ! implicit parts (the walls' share of the wall shear stress, doc/METHOD.md §7.4)
    real(dp) :: wall_force(3, 2) = 0
    ! implicit contacts: the switch, the open contacts of the step, and what
    ! particle_contacts_add_stiffness keeps for particle_contacts_implicit_update
    logical :: implicit = .true.
    type(contact_links_t) :: links
    logical :: stiffness_added = .false.
    real(dp) :: c_now = 0, c_before = 0      ! X^{n+1} - X^n = c_now U^n + c_before U^{n-1}
    real(dp), allocatable :: u_before(:,:), om_before(:,:)   ! U^{n-1}, Omega^{n-1}
    type(lees_edwards_t) :: le               ! sliding boundaries in y (le%active), delta of the step
    real(dp), allocatable :: radii(:)        ! (np) in units of a; not allocated: all a
    real(dp) :: skin = 0                     ! the neighbour list's
    ! a rank's local set (particle_contacts_set_local; not allocated: every sphere, on every rank)
    integer, allocatable :: ids(:)           ! (np) global index of each local sphere, ascending
    logical, allocatable :: owned(:)         ! (np) the spheres this rank owns
    integer :: total = 0                     ! spheres of the whole system
  end type particle_contacts_t

contains

  ! The contact part of the run log's 'models:' line (pc absent: a run without contacts).
  function particle_contacts_description(pc) result(line)
    type(particle_contacts_t), intent(in), optional :: pc
    character(len=200) :: line
    character(len=32) :: friction
    line = 'no contacts'
    if (.not. present(pc)) return
    friction = 'friction off'
    if (pc%params%mu_d > 0) write(friction, '(a,f5.3,a)') 'friction on (mu_d = ', pc%params%mu_d, ')'
    write(line, '(a,es10.3,a,es10.3,a)') 'contacts on (Hertz, h_r = ', pc%params%h_r, ' a, k_n = ', &
         pc%params%k_n, '), '//trim(friction)
  end function particle_contacts_description

  !> Set up for np spheres of radius a with the deck's &contact settings; shear_rate: imposed
  !> shear rate (walls at -+ shear_rate Ly/2 when walls); box, walls: the domain; dt: time step.
  !> info: 0 ok, else msg says what is wrong (contact_setup or nlist_init refused).
  !> le, optional: Lees-Edwards boundaries in y (walls must then be .false.).
  !> radii, optional: (np) the spheres' radii in units of a (doc/CONTACT.md "Spheres of several
  !> sizes"); a is then the unit radius to which k_n, eps_bar and h_r refer (the smallest species').
  subroutine particle_contacts_create(pc, np, a, settings, shear_rate, box, walls, dt, info, msg, le, radii)
    type(particle_contacts_t), intent(out) :: pc
    integer, intent(in) :: np
    real(dp), intent(in) :: a, shear_rate, box(3), dt
    type(particle_contacts_settings_t), intent(in) :: settings
    logical, intent(in) :: walls
    integer, intent(out) :: info
    character(len=*), intent(out) :: msg
    type(lees_edwards_t), intent(in), optional :: le
    real(dp), intent(in), optional :: radii(:)
    ! the viscosity is the unit of stress (doc/METHOD.md §0.2)
    real(dp), parameter :: eta = 1.0_dp
    real(dp) :: a_max
    call contact_setup(pc%params, a, settings%roughness, settings%friction, settings%eps_bar, &
                       settings%normal_stiffness, eta, shear_rate, info, msg)
    if (info /= 0) return
    pc%implicit = settings%implicit
    pc%np = np
    pc%box = box
    pc%dt = dt
    pc%periodic = [.true., .not. walls, .true.]
    pc%wall_velocity = 0
    if (walls) then
      pc%wall_velocity(1, 1) = -0.5_dp * shear_rate * box(2)
      pc%wall_velocity(1, 2) = 0.5_dp * shear_rate * box(2)
    end if
    ! far beyond the roughness: the true surfaces overlap (smooth spheres: 5 % of the radius)
    pc%overlap_limit = pc%params%h_r
    if (pc%overlap_limit <= 0) pc%overlap_limit = SMOOTH_OVERLAP_BOUND * a
    if (present(le)) pc%le = le
    ! the largest sphere's contacts (conservative for the smaller ones; unit spheres: a exactly)
    a_max = a
    if (present(radii)) then
      if (size(radii) /= np .or. .not. all(radii > 0)) then
        info = 1
        msg = 'contacts: the radii must be one per sphere and > 0'
        return
      end if
      pc%radii = radii
      a_max = maxval(radii) * a
    end if
    pc%total = np
    pc%skin = settings%neighbour_skin
    call nlist_init(pc%nlist, np, box, pc%periodic, 2 * a_max + pc%params%h_r + settings%neighbour_skin, &
                    a_max + pc%params%h_r + settings%neighbour_skin, settings%neighbour_skin, info, pc%le)
    if (info /= 0) then
      msg = 'contacts: the neighbour search refuses this box (a periodic length below 2 x cutoff)'
      return
    end if
    allocate(pc%force(3, np), pc%torque(3, np), pc%stresslet(3, 3, np))
    pc%force = 0
    pc%torque = 0
    pc%stresslet = 0
  end subroutine particle_contacts_create

  !> The spheres this rank holds from now on (doc/DESIGN.md "Spheres held by their slab"): ids (np)
  !> their global indices, ascending, owned (np) those it owns, radii (np, units of a) theirs when
  !> the run has several sizes. The contacts then take the local set's positions and velocities
  !> (contact_forces' local set: the pairs with an owned sphere, the history by global index), the
  !> per-sphere results are complete for the owned spheres, and the neighbour list starts afresh
  !> for the new set (its cut-offs and skin kept). The history is kept: the caller brings the
  !> springs of spheres that came to this rank (mod_contact's history).
  subroutine particle_contacts_set_local(pc, ids, owned, radii)
    type(particle_contacts_t), intent(inout) :: pc
    integer, intent(in) :: ids(:)
    logical, intent(in) :: owned(:)
    real(dp), intent(in), optional :: radii(:)
    integer :: np, info
    np = size(ids)
    pc%ids = ids
    pc%owned = owned
    pc%np = np
    if (present(radii) .and. allocated(pc%radii)) pc%radii = radii
    call nlist_init(pc%nlist, np, pc%box, pc%periodic, pc%nlist%cutoff, pc%nlist%wall_cutoff, pc%skin, info, pc%le)
    pc%nlist%built = .false.
    if (allocated(pc%force)) deallocate(pc%force, pc%torque, pc%stresslet)
    allocate(pc%force(3, np), pc%torque(3, np), pc%stresslet(3, 3, np))
    pc%force = 0
    pc%torque = 0
    pc%stresslet = 0
  end subroutine particle_contacts_set_local

  !> One step: contacts at positions x (3, np) with velocities u, om (3, np). Results in
  !> pc%force, pc%torque, pc%stresslet (3, 3, np) and pc%stats; the history advances by one step.
  !> info: 0 ok; 1 the history belongs to another particle count; 2 an overlap beyond
  !> pc%overlap_limit (pc%max_overlap says how far). offset, optional: the Lees-Edwards offset
  !> delta of this configuration (runs created with le).
  subroutine particle_contacts_step(pc, x, u, om, info, offset)
    type(particle_contacts_t), intent(inout) :: pc
    real(dp), intent(in) :: x(:,:), u(:,:), om(:,:)
    integer, intent(out) :: info
    real(dp), intent(in), optional :: offset
    if (present(offset)) pc%le%offset = offset
    call nlist_candidates(pc%nlist, x, pc%pairs, pc%npairs, pc%walls, pc%nwalls, pc%le%offset)
    pc%stiffness_added = .false.
    if (pc%implicit) then
      call contact_forces(pc%params, pc%history, x, u, om, pc%box, pc%periodic, pc%wall_velocity, &
                          pc%pairs, pc%npairs, pc%walls, pc%nwalls, pc%dt, pc%force, pc%torque, &
                          pc%stresslet, pc%stats, info, pc%links, pc%le, pc%radii, pc%ids, pc%owned, pc%total)
    else
      ! pc%radii unallocated: not present (all spheres of radius a)
      call contact_forces(pc%params, pc%history, x, u, om, pc%box, pc%periodic, pc%wall_velocity, &
                          pc%pairs, pc%npairs, pc%walls, pc%nwalls, pc%dt, pc%force, pc%torque, &
                          pc%stresslet, pc%stats, info, le=pc%le, radii=pc%radii, ids=pc%ids, owned=pc%owned, &
                          total=pc%total)
    end if
    if (info /= 0) return
    pc%wall_force = pc%stats%wall_force
    pc%max_overlap = pc%stats%max_overlap * pc%params%h_r
    if (pc%params%h_r <= 0) pc%max_overlap = pc%stats%max_overlap * pc%params%a
    if (pc%max_overlap > pc%overlap_limit) info = 2
  end subroutine particle_contacts_step

  !> The implicit part of this step's contacts into the 6N system [(rho/dt) M + R + K] U = rhs of
  !> the particle solve (free motion; after particle_contacts_step, whose forces stay on the right-hand
  !> side). Positions advance by X^{n+1} - X^n = c_now U^n + c_before U^{n-1} (advance_positions:
  !> Adams-Bashforth 2, c_now = 3/2 dt, c_before = -1/2 dt; forward Euler on a run's first step,
  !> ab2 = .false.: dt, 0), and the next step's spring by U^s(U^n) dt. The force the solve sees is
  !> the contact force at the end of the step linearised about X^n,
  !>   F + dF,  dF = -(c_now K_n + dt K_t) q^n - c_before K_n q^{n-1}
  !> (contact_stiffness; q = the two bodies' velocities, a wall's own translation for a wall):
  !> c_now K_n + dt K_t goes into the matrix (two 6x6 diagonal blocks and one coupling block per
  !> pair, one diagonal block per wall contact), the rest onto rhs (6, np). u, om (3, np): the
  !> velocities of the previous step, U^{n-1}, Omega^{n-1}. Nothing when pc%implicit is off.
  subroutine particle_contacts_add_stiffness(pc, sys, rhs, u, om, ab2)
    type(particle_contacts_t), intent(inout) :: pc
    type(particle_system_t), intent(inout) :: sys
    real(dp), intent(inout) :: rhs(:,:)
    real(dp), intent(in) :: u(:,:), om(:,:)
    logical, intent(in) :: ab2
    real(dp) :: kn(12, 12), kt(12, 12), a(12, 12), q(12), qw(6), g(12)
    integer :: m, i, j
    pc%stiffness_added = .false.
    if (.not. pc%implicit) return
    if (ab2) then
      pc%c_now = 1.5_dp * pc%dt
      pc%c_before = -0.5_dp * pc%dt
    else
      pc%c_now = pc%dt
      pc%c_before = 0
    end if
    pc%u_before = u
    pc%om_before = om
    do m = 1, pc%links%n
      call contact_stiffness(pc%params, pc%links%normal(:, m), pc%links%overlap(m), &
                             pc%links%spring(:, m), pc%links%sliding(m), kn, kt, pc%links%arm(:, m), &
                             pc%links%stiffness(m))
      a = pc%c_now * kn + pc%dt * kt
      i = pc%links%i(m)
      j = pc%links%partner(m)
      call particle_system_add_diagonal(sys, i, a(1:6, 1:6))
      if (j > 0) then
        call particle_system_add_diagonal(sys, j, a(7:12, 7:12))
        call particle_system_add_pair(sys, i, j, a(1:6, 7:12))
        q = [u(:, i), om(:, i), u(:, j) + pc%links%image_velocity_before(:, m), om(:, j)]
        g = -pc%c_before * matmul(kn, q)
        if (pc%le%active) then
          ! the partner's Lees-Edwards image moves with U_j + image_velocity: the known part of
          ! its velocity this step goes to the right-hand side with the matrix block
          qw = [pc%links%image_velocity(:, m), 0.0_dp, 0.0_dp, 0.0_dp]
          g = g - matmul(a(:, 7:12), qw)
        end if
        rhs(:, i) = rhs(:, i) + g(1:6)
        rhs(:, j) = rhs(:, j) + g(7:12)
      else
        qw = [pc%wall_velocity(:, -j), 0.0_dp, 0.0_dp, 0.0_dp]
        q = [u(:, i), om(:, i), qw]
        g(1:6) = -matmul(a(1:6, 7:12), qw) - pc%c_before * matmul(kn(1:6, :), q)
        rhs(:, i) = rhs(:, i) + g(1:6)
      end if
    end do
    pc%stiffness_added = .true.
  end subroutine particle_contacts_add_stiffness

  !> After the solve: u, om (3, np) = U^n, Omega^n. Adds dF of particle_contacts_add_stiffness to the
  !> step's contact force, torque and stresslet (levers as in contact_forces), which then hold the
  !> contact force the particle balance used. Nothing unless particle_contacts_add_stiffness ran this step.
  subroutine particle_contacts_implicit_update(pc, u, om)
    type(particle_contacts_t), intent(inout) :: pc
    real(dp), intent(in) :: u(:,:), om(:,:)
    real(dp) :: kn(12, 12), kt(12, 12), q(12), q0(12), g(12), s(3, 3)
    integer :: m, i, j
    if (.not. pc%stiffness_added) return
    do m = 1, pc%links%n
      call contact_stiffness(pc%params, pc%links%normal(:, m), pc%links%overlap(m), &
                             pc%links%spring(:, m), pc%links%sliding(m), kn, kt, pc%links%arm(:, m), &
                             pc%links%stiffness(m))
      i = pc%links%i(m)
      j = pc%links%partner(m)
      if (j > 0) then
        q = [u(:, i), om(:, i), u(:, j) + pc%links%image_velocity(:, m), om(:, j)]
        q0 = [pc%u_before(:, i), pc%om_before(:, i), pc%u_before(:, j) + pc%links%image_velocity_before(:, m), &
              pc%om_before(:, j)]
      else
        q = [u(:, i), om(:, i), pc%wall_velocity(:, -j), 0.0_dp, 0.0_dp, 0.0_dp]
        q0 = [pc%u_before(:, i), pc%om_before(:, i), pc%wall_velocity(:, -j), 0.0_dp, 0.0_dp, 0.0_dp]
      end if
      ! the generalised force on i; the partner takes -dF and a_j/a_i times the torque (rows 7-12
      ! of K are those of -F and of a_j n x F), set from rows 1-6 so that action = reaction
      ! exactly (equal spheres: the ratio is 1 exactly, the same torque); its stresslet with its own
      ! lever
      g(1:6) = -matmul(pc%c_now * kn(1:6, :) + pc%dt * kt(1:6, :), q) - pc%c_before * matmul(kn(1:6, :), q0)
      pc%force(:, i) = pc%force(:, i) + g(1:3)
      pc%torque(:, i) = pc%torque(:, i) + g(4:6)
      s = contact_stresslet(g(1:3), pc%links%lever(:, m))
      pc%stresslet(:, :, i) = pc%stresslet(:, :, i) + s
      if (j < 0) pc%wall_force(:, -j) = pc%wall_force(:, -j) + g(1:3)
      if (j > 0) then
        pc%force(:, j) = pc%force(:, j) - g(1:3)
        pc%torque(:, j) = pc%torque(:, j) + (pc%links%arm(2, m) / pc%links%arm(1, m)) * g(4:6)
        pc%stresslet(:, :, j) = pc%stresslet(:, :, j) + contact_stresslet(-g(1:3), pc%links%lever_partner(:, m))
      end if
    end do
    pc%stiffness_added = .false.
  end subroutine particle_contacts_implicit_update

  !> The imposed rate of the step in every velocity the contacts take from it: the walls' (-+ rate
  !> Ly/2 along x), the Lees-Edwards images' (s rate Ly e_x, per boundary and per open contact of
  !> the step's links); rate_before: the last step's rate, that of the images' velocities U^{n-1}
  !> in the Adams-Bashforth term (X^{n+1} - X^n = c_now U^n + c_before U^{n-1}; an image moves
  !> with the boundary's offset, which advances at c_now rate + c_before rate_before). A
  !> stress-controlled step (doc/METHOD.md §7.4) calls it between particle_contacts_step, whose
  !> explicit forces keep the rate they were evaluated with (the last step's), and the particle
  !> solve, whose implicit part (particle_contacts_add_stiffness, particle_contacts_implicit_update)
  !> is then affine in the rate.
  pure subroutine particle_contacts_set_rate(pc, rate, rate_before)
    type(particle_contacts_t), intent(inout) :: pc
    real(dp), intent(in) :: rate, rate_before
    integer :: m
    if (.not. pc%periodic(2)) then
      pc%wall_velocity(1, 1) = -0.5_dp * rate * pc%box(2)
      pc%wall_velocity(1, 2) = 0.5_dp * rate * pc%box(2)
    end if
    pc%le%shear_rate = rate
    if (.not. pc%le%active) return
    do m = 1, pc%links%n
      pc%links%image_velocity(:, m) = [pc%links%image_shift(m) * rate * pc%box(2), 0.0_dp, 0.0_dp]
      pc%links%image_velocity_before(:, m) = [pc%links%image_shift(m) * rate_before * pc%box(2), 0.0_dp, 0.0_dp]
    end do
  end subroutine particle_contacts_set_rate

  !> The contacts' columns of the series: open and sliding contacts, the largest overlap, and the
  !> contact force, torque and stresslet on each sphere (doc/INPUT.md "&contact").
  function particle_contacts_columns(pc, owned, rows, total) result(c)
    type(particle_contacts_t), intent(in) :: pc
    integer, intent(in) :: owned(:)           ! the spheres whose rows this rank gives (mod_columns)
    ! (a rank's local set: the global indices of owned and the number of all spheres; absent, the
    ! contacts are set for every sphere and owned are global indices)
    integer, intent(in), optional :: rows(:), total
    type(column_t), allocatable :: c(:)
    integer, allocatable :: r(:)
    integer :: n
    call sphere_rows(owned, size(pc%force, 2), r, n, rows, total)
    ! element by element: an array constructor of column_t leaks their values (gfortran 12)
    allocate(c(merge(8, 7, .not. pc%periodic(2))))
    c(1) = column('contacts_pair', pc%stats%pair_contacts)
    c(2) = column('contacts_wall', pc%stats%wall_contacts)
    c(3) = column('contacts_sliding', pc%stats%sliding)
    c(4) = column('contact_max_overlap', pc%max_overlap)
    c(5) = sphere_column('particles/force_contact', n, r, pc%force(:, owned))
    c(6) = sphere_column('particles/torque_contact', n, r, pc%torque(:, owned))
    c(7) = sphere_column('particles/stresslet_contact', n, r, pc%stresslet(:, :, owned))
    ! between walls: the force of the lower and the upper wall on the spheres (3 x 2)
    if (.not. pc%periodic(2)) c(8) = column('wall_force_contact', pc%wall_force)
  end function particle_contacts_columns

end module mod_particle_contacts
