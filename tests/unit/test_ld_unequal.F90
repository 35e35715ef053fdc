! Invariants of lubrication dynamics and the rheology with spheres of several sizes
! (doc/LUBRICATION.md and doc/RHEOLOGY.md "Spheres of several sizes"):
!  1. one-body blocks per radius: sphere q's block is diag(6 pi eta a_q, 8 pi eta a_q^3) (1e-15
!     relative, round-off), three free spheres of radii 1, 1.4, 2 in shear move with the flow
!     (U = U_inf, Omega = -1/2 e_z) and carry S_xy = (10/3) pi a_q^3 (1e-14: one 6x6 solve each);
!     radii all equal select the equal-sphere path (the block is the one of ld%radius, bitwise);
!  2. a sphere of radius 2 at a wall: its one-body block plus its wall link is the exact wall
!     resistance of a sphere of radius 2 at its gap over its own radius (wall_resistance_fu, 1e-12
!     relative: the block is not clipped, R_wall - R_1B being positive semi-definite), and pushed
!     towards the wall by F it moves at F / (6 pi eta a lambda_perp(eps)) (1e-12);
!  3. an isolated unequal pair keeps its exact block: the lowest eigenvalue of R_2B - R_1B in the
!     metric of half the one-body blocks stays above the floor -1 at lambda 1.4, 2, 4 over gaps
!     1e-4 .. 10 (measured and printed), and a free pair (radii 1 and 2) solved with the links
!     moves as the exact two-sphere resistance of the sized blocks dictates (a direct 12x12 solve
!     of R_2B U = R_2B U_inf + R_FE : E): relative velocity to 1e-10 (two eliminations at condition
!     numbers up to ~1e4);
!  4. rheology with radii: slab volumes of a sphere of radius 1, 1.4 or 2 over any partition sum
!     to (4/3) pi a^3 (1e-13); a static mixture in a Lees-Edwards box has phi_core = sum_i (4/3) pi
!     a_i^3 / V and its phi profile integrates to the same volume (1e-12); the Q6 bond of a pair of
!     radii 1 and 1.4 reaches 1.4 (a_i + a_j) = 3.36 a (Q6 = 1 at r = 3.3, no bond at 3.4); radii
!     all equal select the equal-sphere path.
program test_ld_unequal
  use mod_kinds, only: dp, pi
  use mod_particles, only: particles_t, particles_init, MOTION_FREE
  use mod_particle_system, only: particle_system_t, particle_system_solve
  use mod_lubrication, only: lubrication_t, lub_setup, LUB_EXACT, lub_sized_scalars
  use mod_pair_resistance_unequal, only: sized_pair_scalars, sized_pair_scalars_22
  use mod_resistance_blocks, only: pair_resistance_fu_sized, pair_resistance_fe_sized, wall_resistance_fu
  use mod_wall_resistance, only: wall_normal_resistance
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_create, particle_lubrication_links
  use mod_lubrication_dynamics, only: lubrication_dynamics_t, lubrication_dynamics_create, &
                                      lubrication_dynamics_assemble, lubrication_dynamics_hydrodynamics, &
                                      lubrication_dynamics_one_body_block
  use mod_lees_edwards, only: lees_edwards_t, le_create
  use mod_rheology, only: rheology_settings_t, rheology_t, rheo_create, rheo_sample, slab_volume
  use mod_unit_checks, only: check, check_below, finish
  implicit none
  type(particles_t) :: parts
  type(lubrication_dynamics_t) :: ld
  type(particle_system_t) :: sys
  type(lubrication_t) :: lub
  type(particle_lubrication_t) :: pl
  type(lees_edwards_t) :: le
  real(dp) :: box(3), worst, r1(6, 6), rw(6, 6), gap, e(3, 3), d(3)
  real(dp), allocatable :: rhs(:, :), x(:, :)
  integer :: its, info, k, q, l
  logical :: ok
  character(len=200) :: msg

  call one_body()
  call wall()
  call pair()
  call rheology()
  call finish('test_ld_unequal')

contains

  subroutine one_body()
    real(dp), parameter :: radii(3) = [1.0_dp, 1.4_dp, 2.0_dp]
    real(dp) :: blk(6, 6), a
    box = [20.0_dp, 20.0_dp, 20.0_dp]
    call lubrication_dynamics_create(ld, 1.0_dp, 1.0_dp, 1.0_dp, box, .true., radii)
    worst = 0
    do q = 1, 3
      a = radii(q)
      blk = lubrication_dynamics_one_body_block(ld, q)
      do k = 1, 3
        worst = max(worst, abs(blk(k, k) / (6 * pi * a) - 1), abs(blk(3 + k, 3 + k) / (8 * pi * a**3) - 1))
      end do
      worst = max(worst, sum(abs(blk)) - sum([(abs(blk(k, k)), k = 1, 6)]))
    end do
    call check_below('one body: diag(6 pi a_q, 8 pi a_q^3) of radii 1, 1.4, 2 (relative)', worst, 1.0e-15_dp)
    call particles_init(parts, 3, 1.0_dp, MOTION_FREE)
    parts%position = reshape([5.0_dp, 5.0_dp, 5.0_dp, 12.0_dp, 13.0_dp, 6.0_dp, 6.0_dp, 15.0_dp, 14.0_dp], [3, 3])
    allocate(rhs(6, 3), x(6, 3))
    call lubrication_dynamics_assemble(ld, parts, sys, rhs)
    x = 0
    call particle_system_solve(sys, rhs, x, 1.0e-14_dp, its, ok)
    parts%velocity = x(1:3, :)
    parts%omega = x(4:6, :)
    call lubrication_dynamics_hydrodynamics(ld, parts)
    worst = 0
    do q = 1, 3
      worst = max(worst, norm2(parts%velocity(:, q) - [parts%position(2, q) - 10, 0.0_dp, 0.0_dp]) / 10, &
                  norm2(parts%omega(:, q) - [0.0_dp, 0.0_dp, -0.5_dp]) / 0.5_dp, &
                  abs(parts%stresslet_hydro(1, 2, q) / (10 * pi / 3 * radii(q)**3) - 1))
    end do
    call check(ok, 'one body: three free spheres solved')
    call check_below('one body: U = U_inf, Omega = -1/2 e_z, S_xy = (10/3) pi a_q^3 (relative)', worst, 1.0e-14_dp)
    call lubrication_dynamics_create(ld, 1.0_dp, 1.0_dp, 1.0_dp, box, .true., [1.0_dp, 1.0_dp, 1.0_dp])
    call check(.not. ld%sized .and. all(lubrication_dynamics_one_body_block(ld, 2) == lubrication_dynamics_one_body_block(ld)), &
               'one body: radii all equal take the equal-sphere block')
    deallocate(rhs, x)
  end subroutine one_body

  subroutine wall()
    real(dp), parameter :: eps(3) = [0.01_dp, 0.1_dp, 0.5_dp]
    real(dp) :: u_expect
    box = [16.0_dp, 20.0_dp, 16.0_dp]
    call lub_setup(lub, LUB_EXACT, 1.0_dp, 1.0_dp, 5.0_dp, 1.0_dp, 1.0e-8_dp)
    call lubrication_dynamics_create(ld, 1.0_dp, 1.0_dp, 0.0_dp, box, .true., [1.0_dp, 2.0_dp])
    call particles_init(parts, 2, 1.0_dp, MOTION_FREE)
    allocate(rhs(6, 2), x(6, 2))
    worst = 0
    do k = 1, 3
      ! sphere 2 (radius 2) at height 2 (1 + eps) over y = 0, sphere 1 far from it and the walls
      parts%position(:, 1) = [4.0_dp, 10.0_dp, 4.0_dp]
      parts%position(:, 2) = [12.0_dp, 2 * (1 + eps(k)), 12.0_dp]
      parts%external_force = 0
      parts%external_force(:, 2) = [0.0_dp, -1.0_dp, 0.0_dp]
      call particle_lubrication_create(pl, lub, 2, box, .true., 0.0_dp, 0.2_dp, info, msg, radii=[1.0_dp, 2.0_dp])
      call particle_lubrication_links(pl, parts%position)
      call check(info == 0 .and. pl%nwalls == 1 .and. pl%npairs == 0, 'wall: one wall link, of sphere 2')
      l = 1
      r1 = lubrication_dynamics_one_body_block(ld, 2)
      rw = wall_resistance_fu(eps(k), [0.0_dp, 1.0_dp, 0.0_dp], 2.0_dp, 1.0_dp)
      worst = max(worst, norm2(r1 + pl%wall_r(:, :, l) - rw) / norm2(rw))
      call lubrication_dynamics_assemble(ld, parts, sys, rhs, pl)
      x = 0
      call particle_system_solve(sys, rhs, x, 1.0e-14_dp, its, ok)
      u_expect = -1.0_dp / (6 * pi * 2 * wall_normal_resistance(eps(k)))
      write(*, '(a,f5.2,a,es14.6,a,es14.6)') 'radius 2 at eps ', eps(k), ': U_y ', x(2, 2), ', exact ', u_expect
      worst = max(worst, abs(x(2, 2) / u_expect - 1))
    end do
    call check_below('wall: R_1B(2) + wall link = exact wall resistance of radius 2, and U_y under F (relative)', &
                     worst, 1.0e-12_dp)
    deallocate(rhs, x)
  end subroutine wall

  subroutine pair()
    real(dp), parameter :: lambdas(3) = [1.4_dp, 2.0_dp, 4.0_dp], gaps(4) = [1.0e-3_dp, 0.05_dp, 0.7_dp, 2.5_dp]
    real(dp) :: f(22), f2(22), b(12, 12), s(12), ev(12), work(400), lowest, fe(12, 3, 3), drive(12), u_inf(12)
    real(dp) :: a(12, 12), expect(3), got(3), lam
    integer :: piv(12), m
    external :: dsyev, dgesv
    call lub_setup(lub, LUB_EXACT, 1.0_dp, 1.0_dp, 5.0_dp, 100.0_dp, 1.0e-8_dp)
    d = [1.0_dp, 0.0_dp, 0.0_dp]
    do m = 1, 3
      lam = lambdas(m)
      s(1:3) = sqrt(0.5_dp * 6 * pi)
      s(4:6) = sqrt(0.5_dp * 8 * pi)
      s(7:9) = sqrt(0.5_dp * 6 * pi * lam)
      s(10:12) = sqrt(0.5_dp * 8 * pi * lam**3)
      lowest = huge(1.0_dp)
      do k = 0, 50
        gap = 1.0e-4_dp * 10.0_dp**(k * 5.0_dp / 50)
        f = sized_pair_scalars(gap, lam)
        f2 = sized_pair_scalars_22(gap, lam)
        call lub_sized_scalars(lub, gap, f, f2)
        b = pair_resistance_fu_sized(f, f2, d, 1.0_dp, lam, 1.0_dp)
        do q = 1, 12
          b(:, q) = b(:, q) / (s * s(q))
        end do
        call dsyev('N', 'U', 12, b, 12, ev, work, size(work), info)
        lowest = min(lowest, ev(1))
      end do
      write(msg, '(a,f4.1,a,f8.4,a)') 'isolated pair lambda ', lam, ': lowest eigenvalue of R_2B - R_1B in the metric '// &
           'R_1B/2 over gaps 1e-4..10 = ', lowest, ' > -1 (the floor does not act)'
      call check(lowest > -1.0_dp .and. lowest < 0.0_dp, trim(msg))
    end do
    ! a free pair, radii 1 and 2, in Lees-Edwards shear
    box = [40.0_dp, 40.0_dp, 40.0_dp]
    le = le_create(box, 1.0_dp, 0.0_dp)
    call lub_setup(lub, LUB_EXACT, 1.0_dp, 1.0_dp, 5.0_dp, 6.0_dp, 1.0e-8_dp)
    call lubrication_dynamics_create(ld, 1.0_dp, 1.0_dp, 1.0_dp, box, .true., [1.0_dp, 2.0_dp])
    call particles_init(parts, 2, 1.0_dp, MOTION_FREE)
    allocate(rhs(6, 2), x(6, 2))
    e = 0
    e(1, 2) = 0.5_dp
    e(2, 1) = 0.5_dp
    worst = 0
    d = [-0.8_dp, 0.6_dp, 0.0_dp]
    do k = 1, 4
      gap = gaps(k)
      parts%position(:, 1) = [20.0_dp, 20.0_dp, 20.0_dp]
      parts%position(:, 2) = parts%position(:, 1) + 1.5_dp * (2 + gap) * d
      call particle_lubrication_create(pl, lub, 2, box, .false., 1.0_dp, 0.2_dp, info, msg, le, [1.0_dp, 2.0_dp])
      call particle_lubrication_links(pl, parts%position)
      call lubrication_dynamics_assemble(ld, parts, sys, rhs, pl)
      x = 0
      call particle_system_solve(sys, rhs, x, 1.0e-14_dp, its, ok)
      got = x(1:3, 2) - x(1:3, 1)
      ! the exact two-sphere problem: R_2B U = R_2B U_inf + R_FE : E
      f = sized_pair_scalars(gap, 2.0_dp)
      f2 = sized_pair_scalars_22(gap, 2.0_dp)
      a = pair_resistance_fu_sized(f, f2, d, 1.0_dp, 2.0_dp, 1.0_dp)
      fe = pair_resistance_fe_sized(f, f2, d, 1.0_dp, 2.0_dp, 1.0_dp)
      u_inf = [parts%position(2, 1) - 20, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, -0.5_dp, &
               parts%position(2, 2) - 20, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, -0.5_dp]
      do q = 1, 12
        drive(q) = sum(fe(q, :, :) * e)
      end do
      drive = matmul(a, u_inf) + drive
      call dgesv(12, 1, a, 12, piv, drive, 12, info)
      expect = drive(7:9) - drive(1:3)
      write(*, '(a,es9.2,a,3es14.6,a,es9.2)') 'radii 1, 2 at gap ', gap, ': U_rel ', got, ', relative difference ', &
           norm2(got - expect) / norm2(expect)
      worst = max(worst, norm2(got - expect) / norm2(expect))
    end do
    call check(ok .and. info == 0, 'free unequal pair: solved')
    call check_below('free unequal pair: relative velocity against the exact sized resistance', worst, 1.0e-10_dp)
    deallocate(rhs, x)
  end subroutine pair

  subroutine rheology()
    type(rheology_settings_t), parameter :: settings = rheology_settings_t(blocks=3, profile_bins=48, angle_bins=8, &
                                                                           contact_shell=0.01_dp)
    type(rheology_t) :: r
    real(dp), parameter :: radii(6) = [1.0_dp, 1.4_dp, 1.0_dp, 1.4_dp, 1.0_dp, 2.0_dp], sizes(3) = [1.0_dp, 1.4_dp, 2.0_dp]
    real(dp) :: pos(3, 6), zero(3, 6), zeros3(3, 3, 6), v, total, a
    integer :: j
    worst = 0
    do q = 1, 3
      a = sizes(q)
      v = 0
      do j = -20, 20
        v = v + slab_volume(0.123_dp, a, 0.37_dp * j, 0.37_dp * (j + 1))
      end do
      worst = max(worst, abs(v / (4.0_dp / 3 * pi * a**3) - 1))
    end do
    call check_below('rheology: slab volumes of radii 1, 1.4, 2 sum to (4/3) pi a^3 (relative)', worst, 1.0e-13_dp)
    box = [12.0_dp, 12.0_dp, 12.0_dp]
    ! every sphere inside 0 < y < Ly (the profile bins do not wrap across y)
    pos = reshape([1.0_dp, 2.0_dp, 2.0_dp, 5.0_dp, 3.0_dp, 7.0_dp, 9.0_dp, 10.5_dp, 1.0_dp, &
                   2.0_dp, 8.0_dp, 9.0_dp, 7.0_dp, 6.0_dp, 3.0_dp, 10.0_dp, 3.5_dp, 10.0_dp], [3, 6])
    zero = 0
    zeros3 = 0
    call rheo_create(r, 6, box, 1.0_dp, 1.0_dp, settings, 10, 5, info, le_create(box, 1.0_dp, 0.0_dp), radii)
    call rheo_sample(r, pos, zero, zeros3, offset=0.0_dp)
    total = 4.0_dp / 3 * pi * sum(radii**3)
    call check(info == 0 .and. r%sized, 'rheology: a mixture in a Lees-Edwards box')
    call check_below('rheology: phi_core = sum (4/3) pi a_i^3 / V (relative)', abs(r%values(11) / (total / product(box)) - 1), &
                     1.0e-12_dp)
    call check_below('rheology: the phi profile integrates to the spheres'' volume (relative)', &
                     abs(sum(r%profile(:, 1)) * product(box) / r%nbins / total - 1), 1.0e-12_dp)
    ! Q6 bonds: radii 1 and 1.4 at 3.3 (< 3.36) bond, at 3.4 do not
    call rheo_create(r, 2, box, 1.0_dp, 1.0_dp, settings, 10, 5, info, le_create(box, 1.0_dp, 0.0_dp), [1.0_dp, 1.4_dp])
    call rheo_sample(r, reshape([4.0_dp, 6.0_dp, 6.0_dp, 7.3_dp, 6.0_dp, 6.0_dp], [3, 2]), zero(:, 1:2), zeros3(:, :, 1:2), &
                     offset=0.0_dp)
    call check(r%order .and. abs(r%q6 - 1) < 1.0e-12_dp, 'rheology: radii 1 and 1.4 at 3.3 a: one Q6 bond (Q6 = 1)')
    call rheo_sample(r, reshape([4.0_dp, 6.0_dp, 6.0_dp, 7.4_dp, 6.0_dp, 6.0_dp], [3, 2]), zero(:, 1:2), zeros3(:, :, 1:2), &
                     offset=0.0_dp)
    call check(r%q6 == 0, 'rheology: radii 1 and 1.4 at 3.4 a (> 1.4 (a_i + a_j)): no bond')
    call rheo_create(r, 2, box, 1.0_dp, 1.0_dp, settings, 10, 5, info, le_create(box, 1.0_dp, 0.0_dp), [1.0_dp, 1.0_dp])
    call check(.not. r%sized .and. .not. allocated(r%radii), 'rheology: radii all equal take the equal-sphere path')
  end subroutine rheology

end program test_ld_unequal
