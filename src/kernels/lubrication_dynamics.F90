! Lubrication dynamics (&fluid model = 'none'; doc/METHOD.md §6): the spheres without a resolved fluid.
! Each sphere feels the one-body Stokes resistance relative to the imposed linear flow, each close
! pair and each sphere near a wall the exact two-body resistance minus the one-body part
! (mod_lubrication's model 'exact': the exact functions of mod_pair_resistance, which bin/pairtraj
! uses, and mod_wall_resistance), and the DEM contacts as in the DNS, all in one implicit 6N
! system (Ball & Melrose 1997; Mari, Seto, Morris & Denn 2014 without the far-field mobility):
!
!   [R_1B + sum_links R_link + K_contact] U = R_1B . U_inf + sum_links drive + F_c + F_ext + K-part
!
! with, per sphere (Kim & Karrila 1991 §2.2, §11.3: the one-body scalars X^A = X^C = X^M = 1),
!   F_1B = 6 pi eta a (U_inf(x) - U),  T_1B = 8 pi eta a^3 (Omega_inf - Omega),
!   S_1B = (20/3) pi eta a^3 E_inf                                                (Einstein 1906)
! U_inf = gamma_dot (y - Ly/2) e_x, Omega_inf = -gamma_dot/2 e_z, E_inf = gamma_dot/2 (e_x e_y +
! e_y e_x) between walls or across Lees-Edwards boundaries (0 in a periodic box at rest). The
! links are those of mod_particle_lubrication (R_2B - R_1B, clipped at a floor per link so the
! system stays positive definite); their stresslets are lub_pair_stresslets' (the deviatoric
! R_SU, R_SE part and the trace of doc/METHOD.md §5.9, as for the DNS correction), so the rheology
! compares with the DNS quantity by quantity.
! Spheres of several sizes (lubrication_dynamics_create's radii): each sphere's one-body
! resistance, force, torque and stresslet with its own radius a_i (doc/LUBRICATION.md "Spheres of
! several sizes"); equal spheres keep the one block of ld%radius.
! Pure: no PETSc, MPI or files (the system is solved by its owner, mod_particle_solver, in
! mod_ld_motion).
module mod_lubrication_dynamics
  use mod_kinds, only: dp, pi
  use mod_particles, only: particles_t, MOTION_FREE
  use mod_particle_system, only: particle_system_t, particle_system_reset, particle_system_add_diagonal
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_add_to_system, &
                                      particle_lubrication_add_corrections
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_add_stiffness
  implicit none
  private
  public :: lubrication_dynamics_t, lubrication_dynamics_create, lubrication_dynamics_ambient_velocity, &
            lubrication_dynamics_ambient_gradients, lubrication_dynamics_one_body_block, &
            lubrication_dynamics_assemble, lubrication_dynamics_hydrodynamics, lubrication_dynamics_set_local

  type :: lubrication_dynamics_t
    real(dp) :: radius = 1.0_dp, viscosity = 1.0_dp
    real(dp) :: shear_rate = 0.0_dp
    real(dp) :: box(3) = 0.0_dp
    logical :: sheared = .false.            ! walls or Lees-Edwards boundaries carry the shear
    logical :: sized = .false.              ! spheres of several sizes: radii (n) [a], each its own
    real(dp), allocatable :: radii(:)
  end type lubrication_dynamics_t

contains

  !> sheared: the imposed flow is the shear (walls or Lees-Edwards), else the fluid is at rest.
  !> radii, optional: (n) each sphere's radius in units of radius (absent or all equal: equal spheres).
  subroutine lubrication_dynamics_create(ld, radius, viscosity, shear_rate, box, sheared, radii)
    type(lubrication_dynamics_t), intent(out) :: ld
    real(dp), intent(in) :: radius, viscosity, shear_rate, box(3)
    logical, intent(in) :: sheared
    real(dp), intent(in), optional :: radii(:)
    if (present(radii)) then
      ld%sized = any(radii /= radii(1))
      if (ld%sized) ld%radii = radius * radii
    end if
    ld%radius = radius
    ld%viscosity = viscosity
    ld%shear_rate = shear_rate
    ld%box = box
    ld%sheared = sheared
  end subroutine lubrication_dynamics_create

  !> The radii (units of ld%radius) of the spheres a rank holds from now on, its own and their
  !> ghosts (doc/DESIGN.md "Spheres held by their slab"); nothing for equal spheres.
  pure subroutine lubrication_dynamics_set_local(ld, radii)
    type(lubrication_dynamics_t), intent(inout) :: ld
    real(dp), intent(in) :: radii(:)
    if (ld%sized) ld%radii = ld%radius * radii
  end subroutine lubrication_dynamics_set_local

  !> U_inf at x: gamma_dot (y - Ly/2) e_x.
  pure function lubrication_dynamics_ambient_velocity(ld, x) result(u)
    type(lubrication_dynamics_t), intent(in) :: ld
    real(dp), intent(in) :: x(3)
    real(dp) :: u(3)
    u = 0.0_dp
    if (ld%sheared) u(1) = ld%shear_rate * (x(2) - 0.5_dp * ld%box(2))
  end function lubrication_dynamics_ambient_velocity

  !> Omega_inf = -gamma_dot/2 e_z and E_inf = gamma_dot/2 (e_x e_y + e_y e_x).
  pure subroutine lubrication_dynamics_ambient_gradients(ld, om, e)
    type(lubrication_dynamics_t), intent(in) :: ld
    real(dp), intent(out) :: om(3), e(3, 3)
    real(dp) :: g
    g = 0.0_dp
    if (ld%sheared) g = ld%shear_rate
    om = [0.0_dp, 0.0_dp, -0.5_dp * g]
    e = 0.0_dp
    e(1, 2) = 0.5_dp * g
    e(2, 1) = 0.5_dp * g
  end subroutine lubrication_dynamics_ambient_gradients

  !> The one-body resistance R_1B = diag(6 pi eta a I, 8 pi eta a^3 I) (Stokes; Kim & Karrila §2.2).
  !> q (optional): of sphere q, with its own radius (spheres of several sizes).
  pure function lubrication_dynamics_one_body_block(ld, q) result(r)
    type(lubrication_dynamics_t), intent(in) :: ld
    integer, intent(in), optional :: q
    real(dp) :: r(6, 6), a
    integer :: k
    a = sphere_radius(ld, q)
    r = 0.0_dp
    do k = 1, 3
      r(k, k) = 6.0_dp * pi * ld%viscosity * a
      r(3 + k, 3 + k) = 8.0_dp * pi * ld%viscosity * a**3
    end do
  end function lubrication_dynamics_one_body_block

  ! the radius of sphere q (ld%radius for equal spheres or without q)
  pure real(dp) function sphere_radius(ld, q) result(a)
    type(lubrication_dynamics_t), intent(in) :: ld
    integer, intent(in), optional :: q
    a = ld%radius
    if (.not. present(q)) return
    if (ld%sized) a = ld%radii(q)
  end function sphere_radius

  !> The 6N system sys of free (or frozen) spheres at their positions (reset here; its owner,
  !> mod_particle_solver, solves it): R_1B on every diagonal block and R_1B (U_inf, Omega_inf) +
  !> F_ext onto rhs (6, n); the links of lubrication and the contact forces (and, for free motion
  !> with implicit contacts, their stiffness), each when present.
  subroutine lubrication_dynamics_assemble(ld, parts, sys, rhs, lubrication, contacts)
    type(lubrication_dynamics_t), intent(in) :: ld
    type(particles_t), intent(in) :: parts
    type(particle_system_t), intent(inout) :: sys
    real(dp), intent(out) :: rhs(:, :)
    type(particle_lubrication_t), intent(in), optional :: lubrication
    type(particle_contacts_t), intent(inout), optional :: contacts
    real(dp) :: r1(6, 6), om(3), e(3, 3)
    integer :: q
    r1 = lubrication_dynamics_one_body_block(ld)
    call lubrication_dynamics_ambient_gradients(ld, om, e)
    call particle_system_reset(sys, parts%n)
    do q = 1, parts%n
      if (ld%sized) r1 = lubrication_dynamics_one_body_block(ld, q)
      call particle_system_add_diagonal(sys, q, r1)
      rhs(:, q) = matmul(r1, [lubrication_dynamics_ambient_velocity(ld, parts%position(:, q)), om]) &
                  + [parts%external_force(:, q), parts%external_torque(:, q)]
      if (present(contacts)) rhs(:, q) = rhs(:, q) + [contacts%force(:, q), contacts%torque(:, q)]
    end do
    if (present(lubrication)) call particle_lubrication_add_to_system(lubrication, sys, rhs)
    if (present(contacts) .and. parts%motion == MOTION_FREE) &
      call particle_contacts_add_stiffness(contacts, sys, rhs, parts%velocity, parts%omega, parts%have_prev)
  end subroutine lubrication_dynamics_assemble

  !> With the velocities of the step: the hydrodynamic force, torque and stresslet on each sphere,
  !> one-body plus the links' (lubrication%force etc., particle_lubrication_corrections), into parts%force_hydro,
  !> torque_hydro, stresslet_hydro.
  subroutine lubrication_dynamics_hydrodynamics(ld, parts, lubrication)
    type(lubrication_dynamics_t), intent(in) :: ld
    type(particles_t), intent(inout) :: parts
    type(particle_lubrication_t), intent(in), optional :: lubrication
    real(dp) :: om(3), e(3, 3), a
    integer :: q
    call lubrication_dynamics_ambient_gradients(ld, om, e)
    do q = 1, parts%n
      a = sphere_radius(ld, q)
      parts%force_hydro(:, q) = 6.0_dp * pi * ld%viscosity * a &
                                * (lubrication_dynamics_ambient_velocity(ld, parts%position(:, q)) - parts%velocity(:, q))
      parts%torque_hydro(:, q) = 8.0_dp * pi * ld%viscosity * a**3 * (om - parts%omega(:, q))
      parts%stresslet_hydro(:, :, q) = 20.0_dp / 3.0_dp * pi * ld%viscosity * a**3 * e
    end do
    if (present(lubrication)) &
      call particle_lubrication_add_corrections(lubrication, parts%force_hydro, parts%torque_hydro, parts%stresslet_hydro)
  end subroutine lubrication_dynamics_hydrodynamics

end module mod_lubrication_dynamics
