! Invariants of the lubrication dynamics kernels (mod_lubrication_dynamics, mod_lees_edwards, the
! 'exact' model of mod_lubrication through mod_particle_lubrication):
!  1. one free sphere in simple shear: the 6N system is R_1B alone, so U = U_inf(x),
!     Omega = -gamma_dot/2 e_z and S = (20/3) pi eta a^3 E_inf, S_xy = (10/3) pi (Einstein):
!     to 1e-14 relative (one 6x6 Cholesky solve, round-off only);
!  2. the floor of the exact pair blocks never acts on an isolated pair: the lowest eigenvalue of
!     R_2B - R_1B over gaps 1e-4 .. 10 stays above -3 pi eta a (R_2B is positive definite, so it is
!     above -6 pi eta a; measured -0.355 x 6 pi, near contact), so a lone pair keeps its exact block;
!  3. a free pair in shear: solving [R_1B + (R_2B - R_1B)] U = drive gives the relative velocity
!     of the exact two-sphere mobility, U_rel = E.r - (A d d + B (I - d d)).E.r (Batchelor & Green
!     1972) with A, B from mod_pair_mobility's pair_shear_functions, the functions bin/pairtraj
!     integrates: to 1e-12 relative (A, B come from the same resistance scalars; the difference is
!     the round-off of two 12x12 eliminations at condition numbers up to ~1e4 at gap 1e-3);
!  4. Lees-Edwards: le_separation of a pair straddling y = Ly equals the separation of the same
!     pair moved inside the box (exactly for these binary-exact numbers), its image velocity is
!     gamma_dot Ly e_x, and le_wrap keeps every pair's separation (to 1e-14 a) while moving the
!     velocity by the image's.
program test_lubrication_dynamics
  use mod_kinds, only: dp, pi
  use mod_pair_mobility, only: pair_shear_functions
  use mod_particles, only: particles_t, particles_init, MOTION_FREE
  use mod_particle_system, only: particle_system_t, particle_system_solve
  use mod_lubrication, only: lubrication_t, lub_setup, LUB_EXACT, lub_pair_scalars
  use mod_resistance_blocks, only: pair_resistance_fu
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_create, &
                                      particle_lubrication_links, particle_lubrication_corrections
  use mod_lubrication_dynamics, only: lubrication_dynamics_t, lubrication_dynamics_create, &
                                      lubrication_dynamics_assemble, lubrication_dynamics_hydrodynamics, &
                                      lubrication_dynamics_one_body_block
  use mod_lees_edwards, only: lees_edwards_t, le_create, le_separation, le_wrap
  use mod_unit_checks, only: check, check_below, finish
  implicit none
  type(particles_t) :: parts
  type(lubrication_dynamics_t) :: ld
  type(particle_system_t) :: sys
  type(lubrication_t) :: lub
  type(particle_lubrication_t) :: pl
  type(lees_edwards_t) :: le
  real(dp) :: rhs(6, 2), x(6, 2), box(3), r(12, 12), ev(12), work(200), lowest, gap, worst, a_bg, b_bg, c_rot
  real(dp) :: k_bg, l_bg, m_bg, d(3), e(3, 3), urel(3), expect(3), sep(3), r1(3), r2(3), vs(3), vs2(3)
  real(dp) :: pos(3, 3), vel(3, 3), vprev(3, 3), before(3, 3)
  real(dp), parameter :: gaps(4) = [1.0e-3_dp, 0.05_dp, 0.7_dp, 4.0_dp]
  integer :: its, info, k, i, j
  logical :: ok
  character(len=200) :: msg
  external :: dsyev

  box = [10.0_dp, 20.0_dp, 10.0_dp]
  ! 1. one sphere in shear
  call particles_init(parts, 1, 1.0_dp, MOTION_FREE)
  parts%position(:, 1) = [5.0_dp, 13.0_dp, 5.0_dp]
  call lubrication_dynamics_create(ld, 1.0_dp, 1.0_dp, 1.0_dp, box, .true.)
  call lubrication_dynamics_assemble(ld, parts, sys, rhs(:, 1:1))
  call particle_system_solve(sys, rhs(:, 1:1), x(:, 1:1), 1.0e-14_dp, its, ok)
  parts%velocity(:, 1) = x(1:3, 1)
  parts%omega(:, 1) = x(4:6, 1)
  call lubrication_dynamics_hydrodynamics(ld, parts)
  call check(ok, 'one sphere: solved')
  call check_below('one sphere: |U - (3, 0, 0)|', norm2(parts%velocity(:, 1) - [3.0_dp, 0.0_dp, 0.0_dp]) / 3, 1.0e-14_dp)
  call check_below('one sphere: |Omega - (0, 0, -1/2)| / (1/2)', norm2(parts%omega(:, 1) - [0.0_dp, 0.0_dp, -0.5_dp]) &
                   / 0.5_dp, 1.0e-14_dp)
  call check_below('one sphere: |S_xy - (10/3) pi| / ((10/3) pi)', abs(parts%stresslet_hydro(1, 2, 1) - 10 * pi / 3) &
                   / (10 * pi / 3), 1.0e-14_dp)
  call check_below('one sphere: force and torque free (|F| + |T|)', norm2(parts%force_hydro(:, 1)) + &
                   norm2(parts%torque_hydro(:, 1)), 1.0e-12_dp)

  ! 2. the lowest eigenvalue of an isolated pair's R_2B - R_1B
  call lub_setup(lub, LUB_EXACT, 1.0_dp, 1.0_dp, 5.0_dp, 10.0_dp, 1.0e-8_dp)
  worst = huge(1.0_dp)
  d = [1.0_dp, 0.0_dp, 0.0_dp]
  do k = 0, 50
    gap = 1.0e-4_dp * 10.0_dp**(k * 5.0_dp / 50)
    r = pair_resistance_fu(lub_pair_scalars(lub, gap), d, 1.0_dp, 1.0_dp)
    call dsyev('N', 'U', 12, r, 12, ev, work, size(work), info)
    lowest = ev(1) / (6 * pi)
    worst = min(worst, lowest)
  end do
  write(*, '(a,f8.4,a)') 'lowest eigenvalue of R_2B - R_1B over gaps 1e-4..10: ', worst, ' x 6 pi eta a'
  call check(worst > -0.5_dp .and. worst < 0.0_dp, 'isolated pair: lowest eigenvalue of R_2B - R_1B in (-3 pi, 0)')

  ! 3. a free pair in shear against the exact mobility functions
  call particles_init(parts, 2, 1.0_dp, MOTION_FREE)
  box = [30.0_dp, 30.0_dp, 30.0_dp]
  le = le_create(box, 1.0_dp, 0.0_dp)
  call lubrication_dynamics_create(ld, 1.0_dp, 1.0_dp, 1.0_dp, box, .true.)
  e = 0
  e(1, 2) = 0.5_dp
  e(2, 1) = 0.5_dp
  worst = 0
  do k = 1, 4
    gap = gaps(k)
    d = [-0.8_dp, 0.6_dp, 0.0_dp] / norm2([-0.8_dp, 0.6_dp, 0.0_dp])
    parts%position(:, 1) = [15.0_dp, 15.0_dp, 15.0_dp]
    parts%position(:, 2) = parts%position(:, 1) + (2 + gap) * d
    call particle_lubrication_create(pl, lub, 2, box, .false., 1.0_dp, 0.2_dp, info, msg, le)
    call particle_lubrication_links(pl, parts%position)
    call lubrication_dynamics_assemble(ld, parts, sys, rhs, pl)
    x = 0
    call particle_system_solve(sys, rhs, x, 1.0e-14_dp, its, ok)
    urel = x(1:3, 2) - x(1:3, 1)
    call pair_shear_functions(gap, a_bg, b_bg, c_rot, k_bg, l_bg, m_bg)
    sep = (2 + gap) * d
    ! U_rel = Omega x r + E.r - [A d d + B (I - d d)].E.r, Omega_inf x r = (-1/2 e_z) x r
    expect = [0.5_dp * sep(2), -0.5_dp * sep(1), 0.0_dp] + matmul(e, sep) &
             - (a_bg * d * dot_product(d, matmul(e, sep)) + b_bg * (matmul(e, sep) - d * dot_product(d, matmul(e, sep))))
    worst = max(worst, norm2(urel - expect) / norm2(expect))
    write(*, '(a,es9.2,a,3es14.6,a,es9.2)') 'gap ', gap, ': U_rel ', urel, ', relative difference ', &
         norm2(urel - expect) / norm2(expect)
  end do
  call check(ok, 'free pair: solved')
  call check_below('free pair: relative velocity against pair_shear_functions (A, B)', worst, 1.0e-12_dp)

  ! 4. Lees-Edwards separations, images and the wrap
  box = [12.0_dp, 12.0_dp, 12.0_dp]
  le = le_create(box, 1.0_dp, 4.25_dp)
  ! inside: j - i = (-3, 0.5, 0); across y = Ly: j sits at y + 0.5 - Ly, x - delta
  call le_separation(le, [4.5_dp, 6.25_dp, 6.0_dp] - [7.5_dp, 5.75_dp, 6.0_dp], r1, vs)
  call le_separation(le, [4.5_dp - 4.25_dp, 0.25_dp, 6.0_dp] - [7.5_dp, 11.75_dp, 6.0_dp], r2, vs2)
  call check(all(r1 == r2), 'Lees-Edwards: a pair across y = Ly has the separation of the same pair inside')
  call check(all(vs == 0) .and. all(vs2 == [12.0_dp, 0.0_dp, 0.0_dp]), &
             'Lees-Edwards: the image above moves at +gamma_dot Ly e_x')
  pos = reshape([1.0_dp, 11.9_dp, 3.0_dp, 2.0_dp, 12.3_dp, 3.5_dp, 11.0_dp, -0.2_dp, 5.0_dp], [3, 3])
  vel = reshape([0.1_dp, 0.2_dp, 0.0_dp, 6.3_dp, 0.0_dp, 0.1_dp, -6.1_dp, 0.0_dp, 0.0_dp], [3, 3])
  vprev = vel
  before = pos
  call le_wrap(le, pos, vel, vprev)
  call check(all(pos(2, :) >= 0 .and. pos(2, :) < 12) .and. all(pos(1, :) >= 0 .and. pos(1, :) < 12), &
             'Lees-Edwards: wrapped into the box')
  worst = 0
  do i = 1, 3
    do j = 1, 3
      if (i == j) cycle
      call le_separation(le, before(:, j) - before(:, i), r1, vs)
      call le_separation(le, pos(:, j) - pos(:, i), r2, vs2)
      worst = max(worst, norm2(r1 - r2))
    end do
  end do
  call check_below('Lees-Edwards: le_wrap keeps every separation [a]', worst, 1.0e-14_dp)
  call check(abs(vel(1, 2) - (6.3_dp - 12)) < 1.0e-14_dp .and. abs(vel(1, 3) - (-6.1_dp + 12)) < 1.0e-14_dp &
             .and. vprev(1, 2) == vel(1, 2), 'Lees-Edwards: a wrapped sphere takes the velocity of its image')
  call check(all(lubrication_dynamics_one_body_block(ld) >= 0), 'one-body block non-negative')
  call finish('test_lubrication_dynamics')
end program test_lubrication_dynamics
