! Unit test of contacts between spheres of several sizes (mod_contact contact_forces, radii;
! contact_pair_sized, hertz_stiffness, contact_stiffness arms/k_hertz; mod_particle_contacts with
! radii; doc/CONTACT.md "Spheres of several sizes"), against the closed forms.
! a = eta = gamma_dot = 1 (the unit radius), eps_r = 5e-3 (h_r = 5e-3 a), eps_bar = 0.05
! (k_n = 4.769e6), mu_d = 0.5 unless said; radii in units of a. For a pair i < j: r = x_j - x_i,
! n = r/|r|, F = force on i, g = |r| - a_i - a_j, k_ij = k_n sqrt(R*/(a/2)), R* = a_i a_j/(a_i + a_j).
! Tolerances: a result built from a few O(1) products, one square root and one power, compared
! with the same closed form evaluated in the test from the same positions (the same |r|, so the
! same rounding of the overlap), agrees to a few ulps: 1e-14 relative; 0 (bitwise) where the code
! must produce the very same numbers.
!   1. Hertz of unequal pairs (1:1.4, 1:2, 1.4:2) at |delta'| = 0.05, 0.3, 1 h_r along an oblique
!      normal: F = -k_ij |delta'|^{3/2} n (1e-14), the partner gets -F bitwise; the onset is at
!      gap h_r whatever the radii (1:2 at gap 0.8 h_r touches, at 1.2 h_r does not: h_r is not
!      scaled with the spheres).
!   2. Rolling without slip, a_i Omega_i = -a_j Omega_j (1:1.4, Omega_j rounded) over 10 steps:
!      |F_t| <= 1e-14 of the tangential force the rotation of i alone would build in those steps
!      (the slip cancels to ~1 ulp of a_i Omega_i); a sphere of radius 2 rolling on the lower wall
!      at rest, U = -a_i Omega x n: no tangential force (1e-14 likewise). Sliding (1:2, a large
!      slip): |F_t| = mu_d |F_n| (1e-13, as test_contact item 4), counted as sliding.
!   3. Torques of that sliding contact: T_i = a_i n x F (1e-15 |T_i|: one product), T_j = (a_j/a_i)
!      T_i (1e-15: two roundings); angular momentum about the origin: x_i x F + x_j x (-F) + T_i +
!      T_j = -g n x F, the law's lever-arm defect (the torques act with levers a_i, a_j while the
!      surfaces are g apart; for equal spheres the defect of test_contact item 7) to 1e-14 of
!      |x||F| (cancellation of the moments about the origin, |x| ~ 6).
!   4. Stresslets of that contact: S_i = sym(F (x) (a_i + g/2) n), S_j = sym(F (x) (a_j + g/2) n)
!      (1e-15 of |F| times the lever), each symmetric bitwise, and S_i + S_j = sym(F (x) r), the
!      pair's total whatever the split (1e-15 |F||r|: a few ulps of the products and lever sum).
!   5. Walls: a sphere of radius 1.4 on the lower wall and one of radius 2 on the upper wall:
!      F = k_n sqrt(a_i/a) |delta'|^{3/2} away from the wall (1e-14), lever (a_i + gap/2) n.
!   6. Implicit stiffness of unequal pairs (1:1.4, 1:2): symmetric bitwise; rows 10-12 (torque on
!      j) = a_j/a_i rows 4-6 (1e-15 of the block's largest entry); spectra 2k once with
!      k = (3/2) k_ij |delta'|^{1/2}, and k_t (2 + a_i^2 + a_j^2) twice (B B^T = (2 + a_i^2 +
!      a_j^2) P), as K K = lambda K and tr K = m lambda (1e-14 of lambda: sums of 12 products);
!      equal to finite differences of
!      contact_pair_sized's force, as test_contact_stiffness items 2 and 3 (normal in the
!      positions with the geometric term, 1e-6; tangential in the velocities, sticking 1e-9,
!      sliding 1e-6: the same steps and the same reasons); common translation and rolling
!      without slip (a_i Omega_i + a_j Omega_j) give no force (1e-12 of |K||q|).
!   7. Radii all 1 reproduce the results without radii bitwise, for the unit radius a = 1 and 1.3
!      (at 1.3 the general formulas round differently from the equal-sphere ones, so this also
!      shows that unit spheres take the latter): 27 spheres in a Couette box with pair (many
!      oblique) and wall contacts, friction, 5 steps of contact_forces (forces, torques, stresslets,
!      springs, every field of the links, each link's stiffness), and 20 steps of
!      particle_contacts (create, step, add_stiffness, implicit_update) in a mock particle
!      system (resistance r I_6, positions by Adams-Bashforth 2): velocities, positions, contact
!      forces, torques and stresslets.
!   8. particle_contacts with radii: the neighbour list reaches the largest spheres (radius 2 at
!      gap h_r/2 from each other and from a wall); a frictionless 1:2 pair pressed by +-F in the
!      mock system settles at the Hertz overlap (F/k_ij)^{2/3} (1e-9 after 300 steps, the
!      implicit rate ~0.5 per step) with the force the balance used equal to -F (1e-9); with
!      friction and +-F_t across the normal, at every step after the implicit update: action =
!      reaction bitwise, T_j = (a_j/a_i) T_i (1e-14 of |T_j|: the explicit torque and the
!      implicit one scaled by the ratio, a few roundings), S_1 + S_2 = sym(F_1 (x) r) (1e-14 of
!      |F||r|).
program test_contact_unequal
  use mod_kinds, only: dp, pi
  use mod_vector, only: cross
  use mod_contact, only: contact_params_t, contact_setup, contact_history_t, contact_stats_t, contact_links_t, &
                         contact_forces, contact_pair_sized, contact_stiffness, contact_stresslet, hertz_stiffness
  use mod_particle_contacts, only: particle_contacts_settings_t, particle_contacts_t, particle_contacts_create, &
                                   particle_contacts_step, particle_contacts_add_stiffness, &
                                   particle_contacts_implicit_update
  use mod_particle_system, only: particle_system_t, particle_system_reset, particle_system_add_diagonal, &
                                 particle_system_solve
  use mod_unit_checks, only: check, check_below, finish
  implicit none
  type(contact_params_t) :: p, p0
  type(contact_history_t) :: h
  type(contact_stats_t) :: st
  integer :: info, c, k, step
  character(len=200) :: msg
  real(dp), parameter :: cases(2, 3) = reshape([1.0_dp, 1.4_dp, 1.0_dp, 2.0_dp, 1.4_dp, 2.0_dp], [2, 3])
  real(dp), parameter :: frac(3) = [0.05_dp, 0.3_dp, 1.0_dp], zero3(3) = 0, dt = 1e-3_dp
  real(dp) :: nv(3), x(3, 2), u(3, 2), om(3, 2), force(3, 2), torque(3, 2), ss(3, 3, 2), rad(2)
  real(dp) :: r(3), d, dlt, g, kij, fexp(3), err, ft(3), t(3), ref, lmom(3), li(3), lj(3), fn
  logical :: ok
  integer(8) :: seed

  call contact_setup(p, 1.0_dp, 5.0e-3_dp, 0.5_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, 0.0_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  nv = [1.0_dp, 2.0_dp, -2.0_dp] / 3
  u = 0
  om = 0

  ! ---- 1. Hertz with the reduced radius
  err = 0
  ok = .true.
  do c = 1, 3
    rad = cases(:, c)
    do k = 1, 3
      call place(rad(1) + rad(2) + (1 - frac(k)) * p%h_r)
      call pair_step(p, h, .true.)
      r = x(:, 2) - x(:, 1)
      d = norm2(r)
      dlt = d - (rad(1) + rad(2)) - p%h_r
      kij = p%k_n * sqrt((rad(1) * rad(2) / (rad(1) + rad(2))) / 0.5_dp)
      fexp = -kij * abs(dlt)**1.5_dp * r / d
      err = max(err, norm2(force(:, 1) - fexp) / norm2(fexp))
      ok = ok .and. all(force(:, 2) == -force(:, 1)) .and. st%pair_contacts == 1
    end do
  end do
  call check_below('1. F = -k_n sqrt(R*/(a/2)) |delta''|^{3/2} n, 1:1.4, 1:2, 1.4:2', err, 1e-14_dp)
  call check(ok, '1. the partner gets -F (bitwise)')
  rad = [1.0_dp, 2.0_dp]
  call place(3 + 0.8_dp * p%h_r)
  call pair_step(p, h, .true.)
  ok = st%pair_contacts == 1
  call place(3 + 1.2_dp * p%h_r)
  call pair_step(p, h, .true.)
  call check(ok .and. st%pair_contacts == 0, '1. 1:2 touches at gap 0.8 h_r, not at 1.2 h_r (h_r not scaled)')

  ! ---- 2. rolling without slip, sliding
  rad = [1.0_dp, 1.4_dp]
  call place(rad(1) + rad(2) + 0.7_dp * p%h_r)
  t = cross(nv, [1.0_dp, 0.0_dp, 0.0_dp])
  t = t / norm2(t)
  om(:, 1) = 0.8_dp * t
  om(:, 2) = -(rad(1) / rad(2)) * om(:, 1)
  do step = 1, 10
    call pair_step(p, h, step == 1)
  end do
  ft = force(:, 1) - dot_product(force(:, 1), nv) * nv
  ref = p%kt_coeff * hertz_stiffness(p, rad(1), rad(2)) * sqrt(0.3_dp * p%h_r) * rad(1) * norm2(om(:, 1)) * 10 * dt
  call check_below('2. rolling 1:1.4, a_i Omega_i = -a_j Omega_j: |F_t| / (k_t a_i |Omega_i| 10 dt)', &
                   norm2(ft) / ref, 1e-14_dp)
  call wall_roll()
  rad = [1.0_dp, 2.0_dp]
  call place(rad(1) + rad(2) + 0.7_dp * p%h_r)
  om = 0
  u(:, 1) = [3.0_dp, 0.0_dp, 1.0_dp]
  call pair_step(p, h, .true., 1.0_dp)
  u = 0
  r = x(:, 2) - x(:, 1)
  d = norm2(r)
  g = d - rad(1) - rad(2)
  fn = -dot_product(force(:, 1), r / d)
  ft = force(:, 1) + fn * r / d
  call check_below('2. sliding 1:2: |F_t| / (mu_d |F_n|) - 1', abs(norm2(ft) / (p%mu_d * fn) - 1), 1e-13_dp)
  call check(st%sliding == 1, '2. counted as sliding')

  ! ---- 3. torques of the sliding contact, angular momentum
  err = norm2(torque(:, 1) - rad(1) * cross(r / d, force(:, 1))) / norm2(torque(:, 1))
  call check_below('3. T_i = a_i n x F', err, 1e-15_dp)
  err = norm2(torque(:, 2) - (rad(2) / rad(1)) * torque(:, 1)) / norm2(torque(:, 2))
  call check_below('3. T_j = (a_j/a_i) T_i', err, 1e-15_dp)
  lmom = cross(x(:, 1), force(:, 1)) + cross(x(:, 2), force(:, 2)) + torque(:, 1) + torque(:, 2)
  print '(a,es10.3,a,es10.3)', '3. angular momentum defect |.|/|F| = ', norm2(lmom) / norm2(force(:, 1)), &
        ', g = ', g
  err = norm2(lmom + g * cross(r / d, force(:, 1))) / (max(norm2(x(:, 1)), norm2(x(:, 2))) * norm2(force(:, 1)))
  call check_below('3. x_i x F - x_j x F + T_i + T_j = -g n x F (the law''s lever-arm defect)', err, 1e-14_dp)

  ! ---- 4. stresslets of the sliding contact
  li = (rad(1) + 0.5_dp * g) * r / d
  lj = (rad(2) + 0.5_dp * g) * r / d
  err = max(maxabs(ss(:, :, 1) - sym(force(:, 1), li)) / (norm2(force(:, 1)) * norm2(li)), &
            maxabs(ss(:, :, 2) - sym(force(:, 1), lj)) / (norm2(force(:, 1)) * norm2(lj)))
  call check_below('4. S_i, S_j each with its own lever (a + g/2) n', err, 1e-15_dp)
  call check(all(ss(:, :, 1) == transpose(ss(:, :, 1))) .and. all(ss(:, :, 2) == transpose(ss(:, :, 2))), &
             '4. stresslets symmetric (bitwise)')
  err = maxabs(ss(:, :, 1) + ss(:, :, 2) - sym(force(:, 1), r)) / (norm2(force(:, 1)) * d)
  call check_below('4. S_i + S_j = sym(F (x) r)', err, 1e-15_dp)

  ! ---- 5. walls
  call walls_by_radius()

  ! ---- 6. implicit stiffness of unequal pairs
  call stiffness_checks()

  ! ---- 7. radii all 1 = no radii, bitwise
  call unit_radii_bitwise(1.0_dp)
  call unit_radii_bitwise(1.3_dp)

  ! ---- 8. particle_contacts with radii
  call neighbour_reach()
  call pressed_unequal_pair()
  call frictional_unequal_pair()

  call finish('test_contact_unequal')

contains

  ! spheres of radii rad at distance dist along nv
  subroutine place(dist)
    real(dp), intent(in) :: dist
    x(:, 1) = [5.0_dp, 10.0_dp, 5.0_dp]
    x(:, 2) = x(:, 1) + dist * nv
  end subroutine place

  ! one step of contact_forces for the pair (1, 2) of radii rad (fresh history when fresh)
  subroutine pair_step(pp, hh, fresh, step_dt)
    type(contact_params_t), intent(in) :: pp
    type(contact_history_t), intent(inout) :: hh
    logical, intent(in) :: fresh
    real(dp), intent(in), optional :: step_dt
    real(dp) :: tstep
    integer :: pairs(2, 1), walls(2, 1), inf
    tstep = dt
    if (present(step_dt)) tstep = step_dt
    if (fresh) hh = contact_history_t()
    pairs(:, 1) = [2, 1]                       ! either way round
    walls = 0
    call contact_forces(pp, hh, x, u, om, [20.0_dp, 20.0_dp, 20.0_dp], [.true., .false., .true.], &
                        spread(zero3, 2, 2), pairs, 1, walls, 0, tstep, force, torque, ss, st, inf, radii=rad)
  end subroutine pair_step

  pure function sym(f, l) result(s)
    real(dp), intent(in) :: f(3), l(3)
    real(dp) :: s(3, 3)
    s = 0.5_dp * (spread(f, 2, 3) * spread(l, 1, 3) + spread(l, 2, 3) * spread(f, 1, 3))
  end function sym

  pure real(dp) function maxabs(a)
    real(dp), intent(in) :: a(:, :)
    maxabs = maxval(abs(a))
  end function maxabs

  ! A sphere of radius 2 rolling on the lower wall at rest: U = -a Omega x n, n = -e_y.
  subroutine wall_roll()
    real(dp) :: xs(3, 1), us(3, 1), oms(3, 1), fs(3, 1), ts(3, 1), s1(3, 3, 1), n(3), refw
    integer :: walls(2, 1), pairs(2, 1), inf, st_ep
    type(contact_history_t) :: hw
    n = [0.0_dp, -1.0_dp, 0.0_dp]
    xs(:, 1) = [5.0_dp, 2.0_dp + 0.7_dp * p%h_r, 5.0_dp]
    oms(:, 1) = [0.1_dp, 0.2_dp, 0.3_dp]
    us(:, 1) = -2 * cross(oms(:, 1), n)
    walls(:, 1) = [1, 1]
    pairs = 0
    do st_ep = 1, 10
      call contact_forces(p, hw, xs, us, oms, [20.0_dp, 20.0_dp, 20.0_dp], [.true., .false., .true.], &
                          spread(zero3, 2, 2), pairs, 0, walls, 1, dt, fs, ts, s1, st, inf, radii=[2.0_dp])
    end do
    refw = p%kt_coeff * hertz_stiffness(p, 2.0_dp) * sqrt(0.3_dp * p%h_r) * 2 * norm2(cross(oms(:, 1), n)) * 10 * dt
    call check_below('2. radius 2 rolling on the wall: |F_t| / (k_t a_i |Omega x n| 10 dt)', &
                     norm2(fs(:, 1) - dot_product(fs(:, 1), n) * n) / refw, 1e-14_dp)
  end subroutine wall_roll

  ! Radius 1.4 on the lower wall, radius 2 on the upper wall (box 20 high).
  subroutine walls_by_radius()
    real(dp) :: xs(3, 2), fs(3, 2), ts(3, 2), s2(3, 3, 2), radw(2), gap(2), nw(3, 2), e, el
    integer :: walls(2, 2), pairs(2, 1), inf, q
    type(contact_history_t) :: hw
    radw = [1.4_dp, 2.0_dp]
    xs(:, 1) = [5.0_dp, 1.4_dp + 0.7_dp * p%h_r, 5.0_dp]
    xs(:, 2) = [12.0_dp, 20.0_dp - 2.0_dp - 0.4_dp * p%h_r, 5.0_dp]
    walls(:, 1) = [1, 1]
    walls(:, 2) = [2, 2]
    pairs = 0
    call contact_forces(p, hw, xs, 0 * xs, 0 * xs, [20.0_dp, 20.0_dp, 20.0_dp], [.true., .false., .true.], &
                        spread(zero3, 2, 2), pairs, 0, walls, 2, dt, fs, ts, s2, st, inf, radii=radw)
    gap = [xs(2, 1), 20.0_dp - xs(2, 2)]
    nw(:, 1) = [0.0_dp, -1.0_dp, 0.0_dp]
    nw(:, 2) = [0.0_dp, 1.0_dp, 0.0_dp]
    e = 0
    el = 0
    do q = 1, 2
      fexp = -p%k_n * sqrt(radw(q)) * abs(gap(q) - radw(q) - p%h_r)**1.5_dp * nw(:, q)
      e = max(e, norm2(fs(:, q) - fexp) / norm2(fexp))
      li = (radw(q) + 0.5_dp * (gap(q) - radw(q))) * nw(:, q)
      el = max(el, maxabs(s2(:, :, q) - sym(fs(:, q), li)) / (norm2(fexp) * norm2(li)))
    end do
    call check(st%wall_contacts == 2, '5. two wall contacts')
    call check_below('5. wall: F = k_n sqrt(a_i/a) |delta''|^{3/2} away from the wall (1.4 lower, 2 upper)', e, 1e-14_dp)
    call check_below('5. wall stresslet lever (a_i + gap/2) n', el, 1e-15_dp)
  end subroutine walls_by_radius

  ! ---- 6 -------------------------------------------------------------------------------------

  subroutine stiffness_checks()
    real(dp) :: kn(12, 12), kt(12, 12), n(3), ai, aj, kh, k1, kt1, e(6), xi(3), xj(3), dx(12), eps
    real(dp) :: gp(12), gm(12), pred(12), geo(12), q(12), dq(12), ups(3), s(3), slip(3), cap
    integer :: cs
    logical :: sl
    e = 0
    do cs = 1, 2
      ai = cases(1, cs)
      aj = cases(2, cs)
      kh = hertz_stiffness(p, ai, aj)
      n = nv
      dlt = -0.3_dp * p%h_r
      ! symmetry, torque rows, spectra
      call contact_stiffness(p, n, dlt, zero3, .false., kn, kt, [ai, aj], kh)
      call check(all(kn == transpose(kn)) .and. all(kt == transpose(kt)), '6. blocks symmetric (bitwise)')
      e(1) = max(e(1), maxabs(kt(10:12, :) - (aj / ai) * kt(4:6, :)) / maxabs(kt))
      k1 = 1.5_dp * kh * sqrt(-dlt)
      kt1 = p%kt_coeff * kh * sqrt(-dlt)
      e(2) = max(e(2), spectrum_error(kn, 2 * k1, 1), spectrum_error(kt, (2 + ai**2 + aj**2) * kt1, 2))
      ! normal: central differences in the positions (frictionless), plus the geometric term
      xi = [1.0_dp, 2.0_dp, 3.0_dp]
      xj = xi + (ai + aj + p%h_r + dlt) * n
      dx = 0
      dx(1:3) = [0.3_dp, -0.7_dp, 0.2_dp]
      dx(7:9) = [-0.5_dp, 0.1_dp, 0.9_dp]
      dx = dx / norm2(dx)
      eps = 1e-4_dp * abs(dlt)
      gp = normal_force(xi + eps * dx(1:3), xj + eps * dx(7:9), ai, aj)
      gm = normal_force(xi - eps * dx(1:3), xj - eps * dx(7:9), ai, aj)
      call contact_stiffness(p0, n, dlt, zero3, .false., kn, kt, [ai, aj], kh)
      pred = -matmul(kn, dx)
      geo = 0
      geo(1:3) = -kh * abs(dlt)**1.5_dp / norm2(xj - xi) * (dx(7:9) - dx(1:3) - dot_product(n, dx(7:9) - dx(1:3)) * n)
      geo(7:9) = -geo(1:3)
      e(3) = max(e(3), norm2((gp - gm) / (2 * eps) - pred - geo) / norm2(pred))
      ! tangential, sticking: differences in the velocities over one step
      q = 0.1_dp * [0.3_dp, -0.2_dp, 0.5_dp, 0.1_dp, 0.4_dp, -0.3_dp, -0.2_dp, 0.1_dp, 0.2_dp, 0.2_dp, -0.1_dp, 0.3_dp]
      dq = [0.7_dp, 0.1_dp, -0.3_dp, 0.2_dp, -0.5_dp, 0.4_dp, 0.1_dp, 0.6_dp, -0.2_dp, -0.4_dp, 0.3_dp, 0.1_dp]
      eps = 1e-3_dp
      ups = 0.02_dp * p%h_r * cross(n, [1.0_dp, 1.0_dp, 1.0_dp])
      gp = sized_force(n, dlt, q + eps * dq, ups, ai, aj, sl)
      call check(.not. sl, '6. the contact sticks')
      gm = sized_force(n, dlt, q - eps * dq, ups, ai, aj, sl)
      call contact_stiffness(p, n, dlt, zero3, .false., kn, kt, [ai, aj], kh)
      pred = -dt * matmul(kt, dq)
      e(4) = max(e(4), norm2((gp - gm) / (2 * eps) - pred) / norm2(pred))
      ! tangential, sliding: the spring 1 + 1e-7 beyond the Coulomb length along s, slips across s
      s = cross(n, [0.0_dp, 1.0_dp, 0.0_dp])
      s = s / norm2(s)
      cap = p%mu_d * abs(dlt) / p%kt_coeff
      ups = (1 + 1e-7_dp) * cap * s
      q = 0
      slip = dq(1:3) - dq(7:9) - dot_product(dq(1:3) - dq(7:9), n) * n + cross(ai * dq(4:6) + aj * dq(10:12), n)
      dq(1:3) = dq(1:3) - dot_product(slip, s) * s
      eps = 1e-4_dp
      gp = sized_force(n, dlt, q + eps * dq, ups, ai, aj, sl)
      call check(sl, '6. the contact slides')
      gm = sized_force(n, dlt, q - eps * dq, ups, ai, aj, sl)
      call contact_stiffness(p, n, dlt, cap * s, .true., kn, kt, [ai, aj], kh)
      pred = -dt * matmul(kt, dq)
      e(5) = max(e(5), norm2((gp - gm) / (2 * eps) - pred) / norm2(pred))
      ! null spaces: common translation; rolling without slip with each sphere's own arm
      call contact_stiffness(p, n, dlt, zero3, .false., kn, kt, [ai, aj], kh)
      q = [0.3_dp, -0.2_dp, 0.5_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.3_dp, -0.2_dp, 0.5_dp, 0.0_dp, 0.0_dp, 0.0_dp]
      e(6) = max(e(6), norm2(matmul(kn + kt, q)) / (maxabs(kn + kt) * norm2(q)))
      q(4:6) = [0.2_dp, 0.1_dp, -0.4_dp]
      q(10:12) = [-0.1_dp, 0.5_dp, 0.3_dp]
      q(7:9) = q(1:3) + cross(ai * q(4:6) + aj * q(10:12), n)
      e(6) = max(e(6), norm2(matmul(kt, q)) / (maxabs(kt) * norm2(q)))
    end do
    call check_below('6. torque rows of j = a_j/a_i those of i', e(1), 1e-15_dp)
    call check_below('6. spectra {2k, 0 x 11}, {(2 + a_i^2 + a_j^2) k_t x 2, 0 x 10}', e(2), 1e-14_dp)
    call check_below('6. normal stiffness vs finite differences of the force (+ geometric term)', e(3), 1e-6_dp)
    call check_below('6. tangential stiffness vs differences in the velocities, sticking', e(4), 1e-9_dp)
    call check_below('6. tangential stiffness vs differences in the velocities, sliding', e(5), 1e-6_dp)
    call check_below('6. common translation and rolling without slip give no force', e(6), 1e-12_dp)
  end subroutine stiffness_checks

  ! the generalised force (F, T_i, -F, T_j) of the frictionless contact of spheres ai at xi, aj at xj
  function normal_force(xi, xj, ai, aj) result(gf)
    real(dp), intent(in) :: xi(3), xj(3), ai, aj
    real(dp) :: gf(12), ups(3), f(3), ti(3), tj(3), fnn, dd
    logical :: sl
    ups = 0
    dd = norm2(xj - xi)
    call contact_pair_sized(p0, hertz_stiffness(p0, ai, aj), (xj - xi) / dd, dd - ai - aj - p0%h_r, zero3, zero3, &
                            ai, dt, ups, f, ti, fnn, sl, zero3, aj, tj)
    gf = [f, ti, -f, tj]
  end function normal_force

  ! the generalised force of one step of contact_pair_sized at velocities q, spring ups before it
  function sized_force(n, dl, q, ups, ai, aj, sl) result(gf)
    real(dp), intent(in) :: n(3), dl, q(12), ups(3), ai, aj
    logical, intent(out) :: sl
    real(dp) :: gf(12), us(3), f(3), ti(3), tj(3), fnn
    us = ups
    call contact_pair_sized(p, hertz_stiffness(p, ai, aj), n, dl, q(1:3) - q(7:9), q(4:6), ai, dt, us, f, ti, fnn, &
                            sl, q(10:12), aj, tj)
    gf = [f, ti, -f, tj]
  end function sized_force

  ! How far the symmetric a is from having the eigenvalue lambda m times and 0 otherwise: then and
  ! only then a a = lambda a (each eigenvalue 0 or lambda) and tr a = m lambda (m of them),
  ! relative to lambda.
  pure real(dp) function spectrum_error(a, lambda, m) result(e)
    real(dp), intent(in) :: a(12, 12), lambda
    integer, intent(in) :: m
    integer :: c
    e = 0
    do c = 1, 12
      e = e + a(c, c)
    end do
    e = max(abs(e - m * lambda) / lambda, maxabs(matmul(a, a) - lambda * a) / lambda**2)
  end function spectrum_error

  ! ---- 7 -------------------------------------------------------------------------------------

  ! 27 spheres in 3 layers (y) of 3 x 3 at spacing s = 2 + 0.6 h_r in x and z, each layer shifted
  ! by (0.7, 0, 0.4) from the one below at centre distance s (oblique normals, whose round trip
  ! r/|r| |r|/2 is not r/2 bitwise: the arithmetic of the two paths differs there), in a Couette
  ! box periodic over 3s in x and z, jittered by up to 0.2 h_r per coordinate: every neighbour
  ! (also across x and z) and every sphere of the bottom and top layers with its wall in contact,
  ! delta' between -0.9 h_r and 0; velocities and angular velocities up to 0.1 (a fixed
  ! pseudo-random sequence). Lengths in units of the spheres' radius aa (roughness hr); box: the
  ! domain.
  subroutine cluster(aa, hr, xc, uc, omc, box)
    real(dp), intent(in) :: aa, hr
    real(dp), intent(out) :: xc(:, :), uc(:, :), omc(:, :), box(3)
    integer :: i1, i2, i3, m, c3
    real(dp) :: sp, dy
    sp = 2 * aa + 0.6_dp * hr
    dy = sqrt(sp**2 - (0.7_dp * aa)**2 - (0.4_dp * aa)**2)
    box = [3 * sp, 2 * dy + 2 * aa + 0.6_dp * hr, 3 * sp]
    seed = 12345
    m = 0
    do i3 = 1, 3
      do i2 = 1, 3
        do i1 = 1, 3
          m = m + 1
          xc(:, m) = [sp * (i1 - 1) + 0.7_dp * aa * (i2 - 1), dy * (i2 - 1), sp * (i3 - 1) + 0.4_dp * aa * (i2 - 1)] + &
                     aa + 0.3_dp * hr
          do c3 = 1, 3
            xc(c3, m) = xc(c3, m) + 0.2_dp * hr * (2 * uniform() - 1)
            uc(c3, m) = 0.2_dp * (uniform() - 0.5_dp)
            omc(c3, m) = 0.2_dp * (uniform() - 0.5_dp)
          end do
        end do
      end do
    end do
  end subroutine cluster

  ! a fixed pseudo-random sequence in [0, 1) (linear congruential, state seed)
  real(dp) function uniform()
    seed = modulo(seed * 1103515245_8 + 12345_8, 2147483648_8)
    uniform = real(seed, dp) / 2147483648.0_dp
  end function uniform

  ! with the unit radius aa (1, and 1.3 where a_i Omega_i and the levers of the sized formulas
  ! round differently from the equal-sphere ones: the results must come from the latter)
  subroutine unit_radii_bitwise(aa)
    real(dp), intent(in) :: aa
    integer, parameter :: np = 27
    type(contact_params_t) :: pa
    character(len=12) :: tag
    real(dp) :: xc(3, np), uc(3, np), omc(3, np), f1(3, np), f2(3, np), t1(3, np), t2(3, np), box(3)
    real(dp) :: s1(3, 3, np), s2(3, 3, np), ones(np), kn1(12, 12), kt1(12, 12), kn2(12, 12), kt2(12, 12)
    integer :: pairs(2, np * (np - 1) / 2), walls(2, 2 * np), i, j, m, inf1, inf2, npairs
    type(contact_history_t) :: h1, h2
    type(contact_stats_t) :: st1, st2
    type(contact_links_t) :: l1, l2
    logical :: same, same_links, same_k
    call contact_setup(pa, aa, 5.0e-3_dp, 0.5_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, inf1, msg)
    write(tag, '(a,f3.1,a)') '7. a = ', aa, ':'
    call cluster(aa, pa%h_r, xc, uc, omc, box)
    uc = 20 * uc                   ! slips of up to ~4e-3 per step: sticking and sliding contacts
    ones = 1
    npairs = 0
    do i = 1, np
      do j = i + 1, np
        npairs = npairs + 1
        pairs(:, npairs) = [i, j]
      end do
      walls(:, 2 * i - 1) = [i, 1]
      walls(:, 2 * i) = [i, 2]
    end do
    same = .true.
    same_links = .true.
    same_k = .true.
    do step = 1, 5
      call contact_forces(pa, h1, xc, uc, omc, box, [.true., .false., .true.], reshape([0.1_dp, 0.0_dp, 0.0_dp, &
                          -0.1_dp, 0.0_dp, 0.0_dp], [3, 2]), pairs, npairs, walls, 2 * np, dt, f1, t1, s1, st1, inf1, l1)
      call contact_forces(pa, h2, xc, uc, omc, box, [.true., .false., .true.], reshape([0.1_dp, 0.0_dp, 0.0_dp, &
                          -0.1_dp, 0.0_dp, 0.0_dp], [3, 2]), pairs, npairs, walls, 2 * np, dt, f2, t2, s2, st2, inf2, l2, &
                          radii=ones)
      same = same .and. inf1 == 0 .and. inf2 == 0 .and. all(f1 == f2) .and. all(t1 == t2) .and. all(s1 == s2) .and. &
             h1%n == h2%n .and. all(h1%partner(1:h1%n) == h2%partner(1:h2%n)) .and. all(h1%ups(:, 1:h1%n) == h2%ups(:, 1:h2%n))
      same_links = same_links .and. l1%n == l2%n
      if (l1%n /= l2%n) cycle
      m = l1%n
      same_links = same_links .and. all(l1%i(1:m) == l2%i(1:m)) .and. all(l1%partner(1:m) == l2%partner(1:m)) .and. &
                   all(l1%normal(:, 1:m) == l2%normal(:, 1:m)) .and. all(l1%lever(:, 1:m) == l2%lever(:, 1:m)) .and. &
                   all(l1%lever_partner(:, 1:m) == l2%lever_partner(:, 1:m)) .and. all(l1%arm(:, 1:m) == l2%arm(:, 1:m)) .and. &
                   all(l1%stiffness(1:m) == l2%stiffness(1:m)) .and. all(l1%overlap(1:m) == l2%overlap(1:m)) .and. &
                   all(l1%spring(:, 1:m) == l2%spring(:, 1:m)) .and. (all(l1%sliding(1:m) .eqv. l2%sliding(1:m))) .and. &
                   all(l1%image_velocity(:, 1:m) == l2%image_velocity(:, 1:m))
      ! each link's stiffness without the optional arguments and with the link's arms and k
      do i = 1, m
        call contact_stiffness(pa, l1%normal(:, i), l1%overlap(i), l1%spring(:, i), l1%sliding(i), kn1, kt1)
        call contact_stiffness(pa, l2%normal(:, i), l2%overlap(i), l2%spring(:, i), l2%sliding(i), kn2, kt2, &
                               l2%arm(:, i), l2%stiffness(i))
        same_k = same_k .and. all(kn1 == kn2) .and. all(kt1 == kt2)
      end do
      xc = xc + 0.1_dp * dt * uc     ! the normals turn a little: springs rotated
    end do
    print '(2a,i0,a,i0,a,i0,a)', tag, ' last step: ', st1%pair_contacts, ' pair and ', st1%wall_contacts, &
          ' wall contacts, ', st1%sliding, ' sliding'
    call check(st1%pair_contacts > 30 .and. st1%wall_contacts > 10 .and. st1%sliding > 0 .and. &
               st1%sliding < st1%pair_contacts + st1%wall_contacts, tag//' the scene has contacts of all kinds')
    call check(same, tag//' radii = 1: forces, torques, stresslets, springs bitwise those without radii')
    call check(same_links, tag//' radii = 1: every field of the links bitwise')
    call check(same_k, tag//' radii = 1: each link''s stiffness (arms, k_hertz) bitwise that without them')
    call mock_run_compare(aa, pa%h_r, tag)
  end subroutine unit_radii_bitwise

  ! particle_contacts with and without radii = 1 in the mock system, 20 steps
  subroutine mock_run_compare(aa, hr, tag)
    real(dp), intent(in) :: aa, hr
    character(len=*), intent(in) :: tag
    integer, parameter :: np = 27
    type(particle_contacts_t) :: pc1, pc2
    real(dp) :: x1(3, np), u1(3, np), om1(3, np), x2(3, np), u2(3, np), om2(3, np), pv1(3, np), pv2(3, np), ones(np)
    real(dp) :: box(3)
    integer :: inf1, inf2, st_ep
    logical :: same
    call cluster(aa, hr, x1, u1, om1, box)
    x2 = x1
    u2 = u1
    om2 = om1
    pv1 = u1
    pv2 = u2
    ones = 1
    call particle_contacts_create(pc1, np, aa, particle_contacts_settings_t(roughness=5.0e-3_dp, friction=0.5_dp), &
                                  1.0_dp, box, .true., dt, inf1, msg)
    call particle_contacts_create(pc2, np, aa, particle_contacts_settings_t(roughness=5.0e-3_dp, friction=0.5_dp), &
                                  1.0_dp, box, .true., dt, inf2, msg, radii=ones)
    call check(inf1 == 0 .and. inf2 == 0, tag//' particle_contacts_create with and without radii')
    same = .true.
    do st_ep = 1, 20
      call mock_step(pc1, x1, u1, om1, pv1, st_ep > 1, 75.0_dp)
      call mock_step(pc2, x2, u2, om2, pv2, st_ep > 1, 75.0_dp)
      same = same .and. all(x1 == x2) .and. all(u1 == u2) .and. all(om1 == om2) .and. all(pc1%force == pc2%force) .and. &
             all(pc1%torque == pc2%torque) .and. all(pc1%stresslet == pc2%stresslet)
    end do
    call check(same, tag//' particle_contacts, radii = 1: 20 implicit steps bitwise those without radii')
  end subroutine mock_run_compare

  ! One step of the mock particle problem: contacts at x, a diagonal resistance rr I_6 with the
  ! external forces fe (6, n) (none when absent), the contact stiffness, the solve, the implicit
  ! update, then positions by Adams-Bashforth 2 (Euler without a previous step) as
  ! advance_positions. u_prev: U^{n-1}, kept up to date.
  subroutine mock_step(pc, xm, um, omm, u_prev, ab2, rr, fe)
    type(particle_contacts_t), intent(inout) :: pc
    real(dp), intent(inout) :: xm(:, :), um(:, :), omm(:, :), u_prev(:, :)
    logical, intent(in) :: ab2
    real(dp), intent(in) :: rr
    real(dp), intent(in), optional :: fe(:, :)
    type(particle_system_t) :: sys
    real(dp) :: rhs(6, size(xm, 2)), sol(6, size(xm, 2)), d6(6, 6)
    integer :: q, its, inf
    logical :: conv
    call particle_contacts_step(pc, xm, um, omm, inf)
    call check_silently(inf == 0)
    d6 = 0
    do q = 1, 6
      d6(q, q) = rr
    end do
    call particle_system_reset(sys, size(xm, 2))
    do q = 1, size(xm, 2)
      call particle_system_add_diagonal(sys, q, d6)
      rhs(:, q) = [pc%force(:, q), pc%torque(:, q)]
    end do
    if (present(fe)) rhs = rhs + fe
    call particle_contacts_add_stiffness(pc, sys, rhs, um, omm, ab2)
    call particle_system_solve(sys, rhs, sol, 1e-14_dp, its, conv)
    um = sol(1:3, :)
    omm = sol(4:6, :)
    call particle_contacts_implicit_update(pc, um, omm)
    if (ab2) then
      xm = xm + dt * (1.5_dp * um - 0.5_dp * u_prev)
    else
      xm = xm + dt * um
    end if
    u_prev = um
  end subroutine mock_step

  ! a failure inside a loop counts once and says where
  subroutine check_silently(cond)
    logical, intent(in) :: cond
    if (.not. cond) call check(.false., 'particle_contacts_step refused a step of the mock run')
  end subroutine check_silently

  ! ---- 8 -------------------------------------------------------------------------------------

  ! spheres of radius 2 at gap h_r/2 from each other and from the lower wall are found
  subroutine neighbour_reach()
    type(particle_contacts_t) :: pc
    real(dp) :: xs(3, 2)
    integer :: inf
    call particle_contacts_create(pc, 2, 1.0_dp, particle_contacts_settings_t(roughness=5.0e-3_dp), 1.0_dp, &
                                  [20.0_dp, 20.0_dp, 20.0_dp], .true., dt, inf, msg, radii=[2.0_dp, 2.0_dp])
    xs(:, 1) = [5.0_dp, 2.0_dp + 0.5_dp * p%h_r, 5.0_dp]
    xs(:, 2) = xs(:, 1) + (4 + 0.5_dp * p%h_r) * [1.0_dp, 0.0_dp, 0.0_dp]
    call particle_contacts_step(pc, xs, 0 * xs, 0 * xs, inf)
    call check(inf == 0 .and. pc%stats%pair_contacts == 1 .and. pc%stats%wall_contacts == 2, &
               '8. the neighbour list holds the contacts of radius-2 spheres (pair and walls)')
    call particle_contacts_create(pc, 2, 1.0_dp, particle_contacts_settings_t(roughness=5.0e-3_dp), 1.0_dp, &
                                  [20.0_dp, 20.0_dp, 20.0_dp], .true., dt, inf, msg, radii=[2.0_dp, -1.0_dp])
    call check(inf /= 0, '8. a non-positive radius is refused')
  end subroutine neighbour_reach

  ! Two spheres at rest at distance dist along x, pressed together by +-6 pi e_x and pulled apart
  ! across the normal by -+ft 6 pi e_z: positions, velocities, previous velocities, forces (6, 2).
  subroutine start_pair(dist, ft, xs, us, oms, pv, fe)
    real(dp), intent(in) :: dist, ft
    real(dp), intent(out) :: xs(3, 2), us(3, 2), oms(3, 2), pv(3, 2), fe(6, 2)
    xs(:, 1) = [8.0_dp, 10.0_dp, 10.0_dp]
    xs(:, 2) = xs(:, 1) + [dist, 0.0_dp, 0.0_dp]
    us = 0
    oms = 0
    pv = 0
    fe = 0
    fe(1, :) = [6 * pi, -6 * pi]
    fe(3, :) = [ft * 6 * pi, -ft * 6 * pi]
  end subroutine start_pair

  ! a frictionless 1:2 pair along x pressed by +-F, resistance 75 I_6, implicit contacts
  subroutine pressed_unequal_pair()
    real(dp), parameter :: f = 6 * pi
    type(particle_contacts_t) :: pc
    real(dp) :: xs(3, 2), us(3, 2), oms(3, 2), pv(3, 2), fe(6, 2), target, ov
    integer :: inf, st_ep
    logical :: opposite
    rad = [1.0_dp, 2.0_dp]
    call particle_contacts_create(pc, 2, 1.0_dp, particle_contacts_settings_t(roughness=5.0e-3_dp), 1.0_dp, &
                                  [20.0_dp, 20.0_dp, 20.0_dp], .true., dt, inf, msg, radii=rad)
    call start_pair(3 + 0.4_dp * p%h_r, 0.0_dp, xs, us, oms, pv, fe)
    opposite = .true.
    do st_ep = 1, 300
      call mock_step(pc, xs, us, oms, pv, st_ep > 1, 75.0_dp, fe)
      opposite = opposite .and. all(pc%force(:, 2) == -pc%force(:, 1))
    end do
    target = (f / hertz_stiffness(p, rad(1), rad(2)))**(2.0_dp / 3)
    ov = 3 + p%h_r - norm2(xs(:, 2) - xs(:, 1))
    call check_below('8. pressed 1:2 pair: overlap vs (F/k_ij)^(2/3)', abs(ov - target) / target, 1e-9_dp)
    call check_below('8. pressed 1:2 pair: the contact force the balance used vs -F', abs(pc%force(1, 1) + f) / f, 1e-9_dp)
    call check(opposite, '8. pressed 1:2 pair: action = reaction (bitwise, every step)')
  end subroutine pressed_unequal_pair

  ! the same 1.4:2 pair with friction and +-F_t along z on the spheres: torques and stresslets of
  ! the force the balance used at every step
  subroutine frictional_unequal_pair()
    type(particle_contacts_t) :: pc
    real(dp) :: xs(3, 2), us(3, 2), oms(3, 2), pv(3, 2), fe(6, 2), rs(3), et, es
    integer :: inf, st_ep, with_torque
    logical :: opposite
    rad = [1.4_dp, 2.0_dp]
    call particle_contacts_create(pc, 2, 1.0_dp, particle_contacts_settings_t(roughness=5.0e-3_dp, friction=0.5_dp), &
                                  1.0_dp, [20.0_dp, 20.0_dp, 20.0_dp], .true., dt, inf, msg, radii=rad)
    call start_pair(3.4_dp + 0.4_dp * p%h_r, 0.2_dp, xs, us, oms, pv, fe)
    opposite = .true.
    et = 0
    es = 0
    with_torque = 0
    do st_ep = 1, 50
      rs = xs(:, 2) - xs(:, 1)
      call mock_step(pc, xs, us, oms, pv, st_ep > 1, 75.0_dp, fe)
      if (pc%stats%pair_contacts /= 1) cycle
      opposite = opposite .and. all(pc%force(:, 2) == -pc%force(:, 1))
      if (norm2(pc%torque(:, 2)) > 0) then
        with_torque = with_torque + 1
        et = max(et, norm2(pc%torque(:, 2) - (rad(2) / rad(1)) * pc%torque(:, 1)) / norm2(pc%torque(:, 2)))
      end if
      es = max(es, maxabs(pc%stresslet(:, :, 1) + pc%stresslet(:, :, 2) - sym(pc%force(:, 1), rs)) / &
               (norm2(pc%force(:, 1)) * norm2(rs)))
    end do
    print '(a,i0,a)', '8. frictional 1.4:2 pair: ', with_torque, ' of 50 steps with a contact torque'
    call check(with_torque > 40, '8. frictional 1.4:2 pair: the contact carries a torque')
    call check(opposite, '8. frictional 1.4:2 pair: action = reaction (bitwise, every step)')
    call check_below('8. frictional 1.4:2 pair: T_j = (a_j/a_i) T_i after the implicit update', et, 1e-14_dp)
    call check_below('8. frictional 1.4:2 pair: S_1 + S_2 = sym(F_1 (x) r) after the implicit update', es, 1e-14_dp)
  end subroutine frictional_unequal_pair

end program test_contact_unequal
