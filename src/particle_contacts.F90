! Contacts in the particle time step (doc/CONTACT.md, "Wiring into the time step"): the contact
! parameters, the neighbour list and the contact history of one run, and one call per step.
! Pure: no PETSc, MPI or files. Particle data is replicated, so every rank holds the same state
! and computes the same forces.
!
! One step (method.md §1.9 item 3), at the positions X^n, before the particle sub-problem:
!   1. the neighbour list (cutoff 2a + h_r + skin, walls a + h_r + skin) is rebuilt when some
!      sphere has moved more than skin/2 since the last build;
!   2. its candidates are put in canonical order (pairs by i then j, walls by particle then wall),
!      so that the forces are summed in the same order whatever list is in use: a run restarted
!      from a checkpoint (fresh list) repeats the arithmetic of an uninterrupted one bitwise;
!   3. contact_forces with the latest velocities U, Omega (those of the previous step) and the
!      wall velocities (-+ shear_rate Ly/2 along x): per-particle force, torque and symmetric
!      stresslet, the history advanced by one step.
module mod_particle_contacts
  use mod_kinds, only: dp
  use mod_contact, only: contact_params_t, contact_setup, contact_stats_t, contact_history_t, &
                         contact_forces
  use mod_neighbours, only: nlist_t, nlist_init, nlist_candidates
  implicit none
  private
  public :: particle_contacts_t, pcontacts_create, pcontacts_step

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
  end type particle_contacts_t

contains

  !> Set up for np spheres of radius a. eps_r, mu_d, eps_bar, k_n_prescribed: the &contact
  !> values (doc/INPUT.md); skin: neighbour-list skin [a]; eta: viscosity; shear_rate: imposed
  !> shear rate (walls at -+ shear_rate Ly/2 when walls); box, walls: the domain; dt: time step.
  !> info: 0 ok, else msg says what is wrong (contact_setup or nlist_init refused).
  subroutine pcontacts_create(pc, np, a, eps_r, mu_d, eps_bar, k_n_prescribed, skin, eta, &
                              shear_rate, box, walls, dt, info, msg)
    type(particle_contacts_t), intent(out) :: pc
    integer, intent(in) :: np
    real(dp), intent(in) :: a, eps_r, mu_d, eps_bar, k_n_prescribed, skin, eta, shear_rate, box(3), dt
    logical, intent(in) :: walls
    integer, intent(out) :: info
    character(len=*), intent(out) :: msg
    call contact_setup(pc%params, a, eps_r, mu_d, eps_bar, k_n_prescribed, eta, shear_rate, info, msg)
    if (info /= 0) return
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
    if (pc%overlap_limit <= 0) pc%overlap_limit = 0.05_dp * a
    call nlist_init(pc%nlist, np, box, pc%periodic, 2 * a + pc%params%h_r + skin, &
                    a + pc%params%h_r + skin, skin, info)
    if (info /= 0) then
      msg = 'contacts: the neighbour search refuses this box (a periodic length below 2 x cutoff)'
      return
    end if
    allocate(pc%force(3, np), pc%torque(3, np), pc%stresslet(3, 3, np))
    pc%force = 0
    pc%torque = 0
    pc%stresslet = 0
  end subroutine pcontacts_create

  !> One step: contacts at positions x (3, np) with velocities u, om (3, np). Results in
  !> pc%force, pc%torque, pc%stresslet (3, 3, np) and pc%stats; the history advances by one step.
  !> info: 0 ok; 1 the history belongs to another particle count; 2 an overlap beyond
  !> pc%overlap_limit (pc%max_overlap says how far).
  subroutine pcontacts_step(pc, x, u, om, info)
    type(particle_contacts_t), intent(inout) :: pc
    real(dp), intent(in) :: x(:,:), u(:,:), om(:,:)
    integer, intent(out) :: info
    call nlist_candidates(pc%nlist, x, pc%pairs, pc%npairs, pc%walls, pc%nwalls)
    call contact_forces(pc%params, pc%history, x, u, om, pc%box, pc%periodic, pc%wall_velocity, &
                        pc%pairs, pc%npairs, pc%walls, pc%nwalls, pc%dt, pc%force, pc%torque, &
                        pc%stresslet, pc%stats, info)
    if (info /= 0) return
    pc%max_overlap = pc%stats%max_overlap * pc%params%h_r
    if (pc%params%h_r <= 0) pc%max_overlap = pc%stats%max_overlap * pc%params%a
    if (pc%max_overlap > pc%overlap_limit) info = 2
  end subroutine pcontacts_step


end module mod_particle_contacts
