! Unit test of mod_contact, one rule at a time (paper §2.4, doc/METHOD.md §4.1, doc/CONTACT.md).
! a = eta = gamma_dot = 1, eps_r = 5e-3 (h_r = 5e-3 a), eps_bar = 0.05, mu_d = 0.5 unless said.
! Tolerances: results built from a few O(1) products and one power are exact to a few ulps, so
! 1e-13 relative is used where the reference is computed along another path, 0 (bitwise) where
! the code must produce the very same numbers (action = reaction, T_i = T_j, frictionless).
!   1. Stiffness: k_n (eps_bar h_r)^{3/2} = 6 pi eta gamma_dot a^2 (1e-13).
!   2. Hertz: F = -k_n |delta'|^{3/2} n at delta' = -0.01, -0.05, -0.3, -1 h_r (1e-13), along -n.
!   3. Onset exactly at gap h_r (exact binary positions, h_r = 2^-8): at |r| = 2a + h_r the
!      contact exists with zero force; one ulp farther there is no contact; one ulp closer the
!      force is repulsive.
!   4. Coulomb: under a large slip |F_t| = mu_d |F_n| (1e-13) and F_t is antiparallel to the slip
!      (1 + cos < 1e-13); the spring is reset so that k_t |Upsilon| = |F_t| (1e-13).
!   5. Rotation of the spring: when n turns, Upsilon . n = 0 (1e-15 |Upsilon|) and |Upsilon| is
!      kept (1e-14), with zero slip.
!   6. Reset on opening: the history forgets a contact that opens; a reopened contact restarts
!      from Upsilon = 0 (its force after one step is half the force after two steps of the same
!      constant slip, 1e-12).
!   7. Action = reaction and T_i = T_j = a n x F bitwise; the total torque about the midpoint is
!      the lever-arm defect (2a - |r|) n x F_t (1e-13 |F|).
!   8. Stresslet (2.24): symmetric, equal to 1/2 (F r/2 + r/2 F) (1e-15 |F||r|), trace F.r/2
!      (1e-13), the same on both spheres; wall contact with lever (a + gap/2) n.
!   9. mu_d = 0: no tangential state (the history stays unallocated, size 0), F parallel to n
!      bitwise (F = -|F_n| n) and zero torque whatever the slip.
!  10. Walls by the same law: the normal force on a sphere at wall gap g equals the pair force
!      at pair gap g (bitwise), pointing away from the wall.
!  11. Set-up refusals: eps_r = 0 without a prescribed k_n; negative mu_d; a prescribed k_n wins.
!  12. The chatter number dt gamma_dot h_r/delta_0 reduces to dt gamma_dot/eps_bar when k_n comes
!      from eps_bar (1e-13: one power and a few products), scales as k_n^(2/3) for a prescribed
!      k_n (8 k_n gives 4 times the number, 1e-13), and is 0 for smooth spheres.
!  13. The flattening estimate eps_bar g(phi) takes the measured g at its table points (6.9 at
!      phi = 0.4, 26 at 0.55; 1e-13), is continuous at the joins (0.3, 0.5: 1e-12) and is eps_bar
!      at phi = 0 (one pair under the force scale).
!  14. Frictional spheres at phi >= 0.545 (doc/VALIDATION.md §6 "Shear jamming, revisited": they
!      flow with contacts at least as stiff as eps_bar 0.005, and every softer run stopped on the
!      overlap guard): contact_limits refuses phi 0.5485 with mu_d 0.5 and eps_bar 0.01 in a sheared
!      cell, naming &contact eps_bar, the budget and the stiffness that flowed (eps_bar <= 0.005,
!      normal_stiffness >= 2^1.5 k_n); a prescribed k_n as soft is refused naming normal_stiffness;
!      eps_bar 0.005 passes with a warning; a 1:1.4 mixture at eps_bar 0.005 is refused (its
!      largest pair's overlaps are 1.4 times); at phi 0.589 (a rate-controlled start-up measured
!      to jam at any stiffness, doc/VALIDATION.md §11.2) eps_bar 0.002 passes with that warning; warns at
!      phi 0.53 with mu_d 0.5, and lets phi 0.5485 pass frictionless, with mu_d 0.1, or without
!      shear (no sliding boundary, or walls at rest).
!  15. A mixture's overlap estimate is its largest pair's (doc/CONTACT.md "Spheres of several
!      sizes": overlaps grow like the radius, measured 1.40-1.50 for 1:1.4): at phi 0.4 with
!      eps_bar 0.06 the unit estimate 0.41 h_r passes, 1.4 times it (0.58) warns; eps_bar 0.09
!      (0.62) warns, twice it (1.24) is refused naming &contact eps_bar; largest_radius 1 is the
!      equal-sphere result.
program test_contact
  use mod_kinds, only: dp, pi
  use mod_vector, only: cross
  use mod_contact, only: contact_params_t, contact_setup, chatter_number, stick_number, flattening_estimate, contact_history_t, history_size, &
                         contact_limits, contact_pair, contact_forces, contact_stats_t, history_lookup
  use mod_limits, only: limit_finding_t, LIMIT_REFUSE, LIMIT_WARN
  use mod_unit_checks, only: check, finish
  implicit none
  type(contact_params_t) :: p, p0, pb
  type(limit_finding_t), allocatable :: found(:)
  type(contact_history_t) :: h
  type(contact_stats_t) :: st
  integer :: info, k, step
  integer :: pairs(2, 1), walls(2, 1)
  character(len=200) :: msg
  real(dp) :: n(3), ups(3), f(3), tq(3), fn, dlt, x(3, 2), u(3, 2), om(3, 2), box(3), vw(3, 2)
  real(dp) :: force(3, 2), torque(3, 2), ss(3, 3, 2), r(3), ft(3), d, kt, l0, err, tot(3)
  real(dp) :: fsave(3), slip(3), frac(4) = [0.01_dp, 0.05_dp, 0.3_dp, 1.0_dp], fwall(3)
  logical :: per(3), sliding

  call contact_setup(p, 1.0_dp, 5.0e-3_dp, 0.5_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  call check(info == 0, 'set-up accepted')

  ! 1. stiffness
  err = abs(p%k_n * (p%eps_bar * p%h_r)**1.5_dp / (6 * pi) - 1)
  print '(a,es12.5,a,es9.2)', '1. k_n = ', p%k_n, ' eta gd a^1/2; balance rel. error ', err
  call check(err < 1e-13_dp, 'k_n from eps_bar')

  ! 2. Hertz value and direction
  n = [1.0_dp, 2.0_dp, -2.0_dp] / 3
  err = 0
  do k = 1, size(frac)
    dlt = frac(k) * p%h_r
    ups = 0
    call contact_pair(p, n, -dlt, [0.0_dp, 0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp, 0.0_dp], 1e-3_dp, &
                      ups, f, tq, fn, sliding)
    err = max(err, norm2(f + p%k_n * dlt**1.5_dp * n) / (p%k_n * dlt**1.5_dp))
  end do
  print '(a,es9.2)', '2. Hertz force, max rel. error over 4 overlaps ', err
  call check(err < 1e-13_dp, 'Hertz force value and direction')

  ! 3. onset exactly at |r| = 2a + h_r, through contact_forces with exact binary positions
  call contact_setup(pb, 1.0_dp, 2.0_dp**(-8), 0.5_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  box = 20
  per = [.true., .false., .true.]
  vw = 0
  u = 0
  om = 0
  pairs(:, 1) = [1, 2]
  x(:, 1) = [4.0_dp, 10.0_dp, 5.0_dp]
  x(:, 2) = x(:, 1) + [2 + pb%h_r, 0.0_dp, 0.0_dp]
  call cf(pb, x)
  print '(a,i0,a,es10.3)', '3. at gap h_r: contacts ', st%pair_contacts, ', |F| ', norm2(force(:, 1))
  call check(st%pair_contacts == 1 .and. all(force == 0), 'contact with zero force at gap = h_r')
  x(1, 2) = nearest(x(1, 2), 1.0_dp)
  call cf(pb, x)
  call check(st%pair_contacts == 0 .and. all(force == 0), 'no contact one ulp farther')
  x(1, 2) = nearest(nearest(x(1, 2), -1.0_dp), -1.0_dp)
  call cf(pb, x)
  print '(a,es10.3)', '   one ulp closer: F_x on sphere 1 ', force(1, 1)
  call check(st%pair_contacts == 1 .and. force(1, 1) < 0, 'repulsive one ulp closer')

  ! 4. Coulomb cap under a large slip
  dlt = 0.3_dp * p%h_r
  ups = 0
  call contact_pair(p, n, -dlt, [3.0_dp, 0.0_dp, 1.0_dp], [0.0_dp, 0.0_dp, 0.0_dp], 1.0_dp, ups, &
                    f, tq, fn, sliding)
  ft = f - dot_product(f, n) * n
  slip = [3.0_dp, 0.0_dp, 1.0_dp]
  slip = slip - dot_product(slip, n) * n
  kt = (2.0_dp / 7) * p%k_n * sqrt(dlt)
  err = abs(norm2(ft) / (p%mu_d * fn) - 1)
  print '(a,es9.2,a,es9.2,a,es9.2)', '4. |F_t|/(mu_d|F_n|) - 1 = ', err, ', 1 + cos(F_t, slip) = ', &
    1 + dot_product(ft, slip) / (norm2(ft) * norm2(slip)), ', k_t|Ups|/|F_t| - 1 = ', &
    kt * norm2(ups) / norm2(ft) - 1
  call check(err < 1e-13_dp .and. sliding, 'Coulomb cap exact')
  call check(1 + dot_product(ft, slip) / (norm2(ft) * norm2(slip)) < 1e-13_dp, 'F_t opposes the slip')
  call check(abs(kt * norm2(ups) / norm2(ft) - 1) < 1e-13_dp, 'spring reset to the cap')

  ! 5. rotation of the spring into a new tangent plane (the old spring has a normal part)
  ups = [1e-6_dp, 2e-6_dp, 0.5e-6_dp]
  l0 = norm2(ups)
  call contact_pair(p, n, -dlt, [0.0_dp, 0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp, 0.0_dp], 1e-3_dp, ups, &
                    f, tq, fn, sliding)
  print '(a,es9.2,a,es9.2)', '5. after rotation |Ups.n|/|Ups| = ', abs(dot_product(ups, n)) / l0, &
    ', |Ups|/l0 - 1 = ', norm2(ups) / l0 - 1
  call check(abs(dot_product(ups, n)) < 1e-15_dp * l0, 'rotated spring is tangent')
  call check(abs(norm2(ups) / l0 - 1) < 1e-14_dp, 'rotated spring keeps its length')

  ! 6. reset on opening (history through contact_forces)
  x(:, 1) = [5.0_dp, 10.0_dp, 5.0_dp]
  x(:, 2) = x(:, 1) + [2 + 0.5_dp * p%h_r, 0.0_dp, 0.0_dp]
  u(:, 1) = [0.0_dp, 0.0_dp, 1.0_dp]
  call cf(p, x)
  call cf(p, x)
  fsave = force(:, 1)
  call check(history_size(h) == 1, 'history holds the contact')
  x(1, 2) = x(1, 2) + p%h_r
  call cf(p, x)
  call check(history_size(h) == 0 .and. &
             all(history_lookup(h, 1, 2) == 0), 'history forgets an open contact')
  x(1, 2) = x(1, 2) - p%h_r
  call cf(p, x)
  print '(a,es11.4,a,es11.4)', '6. F_t,z after 2 steps ', fsave(3), ', after reopening, 1 step ', &
    force(3, 1)
  call check(abs(force(3, 1) - 0.5_dp * fsave(3)) < 1e-12_dp * abs(fsave(3)), &
             'reopened spring restarts at zero')

  ! 7. action-reaction, torque rule, midpoint torque
  call clear_history()
  x(:, 2) = x(:, 1) + (2 + 0.4_dp * p%h_r) * n
  u(:, 1) = [0.3_dp, -0.1_dp, 0.2_dp]
  u(:, 2) = [-0.2_dp, 0.1_dp, 0.4_dp]
  om(:, 1) = [0.1_dp, 0.5_dp, -0.3_dp]
  om(:, 2) = [0.2_dp, -0.1_dp, 0.3_dp]
  do step = 1, 5
    call cf(p, x)
  end do
  r = x(:, 2) - x(:, 1)
  d = norm2(r)
  n = r / d
  f = force(:, 1)
  ft = f - dot_product(f, n) * n
  print '(a,es9.2,a,es9.2)', '7. |F_i + F_j| = ', norm2(force(:, 1) + force(:, 2)), &
    ', |F_t|/|F_n| = ', norm2(ft) / abs(dot_product(f, n))
  call check(all(force(:, 1) == -force(:, 2)) .and. norm2(ft) > 0, 'action = reaction (bitwise)')
  call check(all(torque(:, 1) == torque(:, 2)), 'T_i = T_j (bitwise)')
  call check(norm2(torque(:, 1) - cross(n, f)) <= 1e-15_dp * norm2(f), 'torque = a n x F')
  tot = torque(:, 1) + torque(:, 2) + cross(-0.5_dp * r, force(:, 1)) + cross(0.5_dp * r, force(:, 2))
  err = norm2(tot - (2 - d) * cross(n, ft)) / norm2(f)
  print '(a,es9.2,a,es9.2)', '   midpoint torque |T_tot|/|F| = ', norm2(tot) / norm2(f), &
    ', minus (2a - |r|) n x F_t: ', err
  call check(err < 1e-13_dp, 'midpoint torque = lever defect')

  ! 8. stresslet
  err = 0
  do k = 1, 2
    err = max(err, maxval(abs(ss(:, :, k) - transpose(ss(:, :, k)))))
  end do
  err = max(err, maxval(abs(ss(:, :, 1) - 0.5_dp * (spread(f, 2, 3) * spread(0.5_dp * r, 1, 3) + &
                                                    spread(0.5_dp * r, 2, 3) * spread(f, 1, 3)))))
  print '(a,es9.2,a,es9.2)', '8. stresslet formula/symmetry error ', err / (norm2(f) * d), &
    ', trace rel. error ', (ss(1, 1, 1) + ss(2, 2, 1) + ss(3, 3, 1)) / (dot_product(f, r) / 2) - 1
  call check(err < 1e-15_dp * norm2(f) * d, 'stresslet (2.24), symmetric')
  call check(abs((ss(1, 1, 1) + ss(2, 2, 1) + ss(3, 3, 1)) / (dot_product(f, r) / 2) - 1) < 1e-13_dp, &
             'stresslet trace F.r/2')
  call check(all(ss(:, :, 1) == ss(:, :, 2)), 'same stresslet on both spheres')

  ! 9. mu_d = 0: no tangential state at all
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, 0.0_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  call clear_history()
  do step = 1, 3
    call cf(p0, x)
  end do
  print '(a,i0,a,l1,a,es9.2)', '9. mu_d = 0: stored ', history_size(h), ', allocated ', &
    allocated(h%partner), ', |F + |F_n| n| = ', norm2(force(:, 1) + norm2(force(:, 1)) * n)
  call check(history_size(h) == 0 .and. &
             .not. allocated(h%partner) .and. .not. allocated(h%ups), 'mu_d = 0 keeps no tangential state')
  call check(all(force(:, 1) == -st%max_normal_force * n) .and. &
             all(torque == 0), 'mu_d = 0: F along -n, no torque')

  ! 10. walls by the same law (exact binary gap 2^-9 < h_r = 2^-8); stresslet lever (a + gap/2) n
  call clear_history()
  x(:, 1) = [5.0_dp, 1 + 2.0_dp**(-9), 5.0_dp]
  walls(:, 1) = [1, 1]
  u = 0
  om = 0
  call contact_forces(pb, h, x(:, 1:1), u(:, 1:1), om(:, 1:1), box, per, vw, pairs, 0, walls, 1, &
                      1e-3_dp, force(:, 1:1), torque(:, 1:1), ss(:, :, 1:1), st, info)
  fwall = force(:, 1)
  err = abs(ss(2, 2, 1) - fwall(2) * (-(1 + 0.5_dp * 2.0_dp**(-9)))) / abs(ss(2, 2, 1))
  call clear_history()
  x(:, 1) = [5.0_dp, 10.0_dp, 5.0_dp]
  x(:, 2) = x(:, 1) - [0.0_dp, 2 + 2.0_dp**(-9), 0.0_dp]
  call cf(pb, x)
  print '(a,es12.5,a,es12.5)', '10. wall F_y = ', fwall(2), ', pair F_y at the same gap = ', force(2, 1)
  call check(fwall(2) == force(2, 1) .and. fwall(2) > 0 &
             .and. fwall(1) == 0 .and. fwall(3) == 0, 'wall force = pair force at the same gap')
  call check(err < 1e-15_dp, 'wall stresslet with lever (a + gap/2) n')

  ! 11. refusals
  call contact_setup(p0, 1.0_dp, 0.0_dp, 0.5_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  print '(2a)', '11. eps_r = 0 without k_n: ', trim(msg)
  call check(info /= 0, 'smooth spheres need a prescribed k_n')
  call contact_setup(p0, 1.0_dp, 0.0_dp, 0.5_dp, 0.05_dp, 1.0e6_dp, 1.0_dp, 1.0_dp, info, msg)
  call check(info == 0 .and. p0%k_n == 1e6_dp, 'a prescribed k_n is accepted')
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, -0.1_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  call check(info /= 0, 'negative mu_d refused')
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, 0.5_dp, 0.05_dp, 2.0e5_dp, 1.0_dp, 1.0_dp, info, msg)
  call check(info == 0 .and. p0%k_n == 2e5_dp, 'a prescribed k_n overrides eps_bar')

  ! 12. chatter number
  err = abs(chatter_number(p, 2.0e-3_dp) / (2.0e-3_dp / 0.05_dp) - 1)
  print '(a,es12.5,a,es9.2)', '12. chatter number at dt = 2e-3: ', chatter_number(p, 2.0e-3_dp), ' rel. error ', err
  call check(err < 1e-13_dp, 'chatter number = dt gamma_dot / eps_bar')
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, 0.5_dp, 0.05_dp, 8 * p%k_n, 1.0_dp, 1.0_dp, info, msg)
  err = abs(chatter_number(p0, 2.0e-3_dp) / (4 * chatter_number(p, 2.0e-3_dp)) - 1)
  call check(err < 1e-13_dp, 'chatter number scales as k_n^(2/3)')
  call contact_setup(p0, 1.0_dp, 0.0_dp, 0.5_dp, 0.05_dp, 1.0e6_dp, 1.0_dp, 1.0_dp, info, msg)
  call check(chatter_number(p0, 2.0e-3_dp) == 0, 'no chatter number for smooth spheres')
  ! the stick number: slip of a step gamma_dot a dt over the stick length (7/2) mu_d eps_bar h_r
  ! (p: eps_r = 5e-3, eps_bar = 0.05, mu_d = 0.5): 2e-3/(3.5 x 0.5 x 2.5e-4) = 4.5714...
  err = abs(stick_number(p, 2.0e-3_dp) / (2.0e-3_dp / (3.5_dp * 0.5_dp * 0.05_dp * 5.0e-3_dp)) - 1)
  print '(a,es12.5,a,es9.2)', '12b. stick number at dt = 2e-3: ', stick_number(p, 2.0e-3_dp), ' rel. error ', err
  call check(err < 1e-13_dp, 'stick number = gamma_dot a dt / ((7/2) mu_d eps_bar h_r)')
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, 0.0_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  call check(stick_number(p0, 2.0e-3_dp) == 0, 'no stick number without friction')

  ! 13. flattening estimate (p: eps_bar = 0.05)
  call check(abs(flattening_estimate(p, 0.4_dp) / (6.9_dp * 0.05_dp) - 1) < 1e-13_dp, 'flattening at phi = 0.4 is 6.9 eps_bar')
  call check(abs(flattening_estimate(p, 0.55_dp) / (26.0_dp * 0.05_dp) - 1) < 1e-13_dp, 'flattening at phi = 0.55 is 26 eps_bar')
  call check(abs(flattening_estimate(p, 0.3_dp - 1e-12_dp) &
             / flattening_estimate(p, 0.3_dp + 1e-12_dp) - 1) < 1e-10_dp, 'flattening continuous at phi = 0.3')
  call check(abs(flattening_estimate(p, 0.5_dp - 1e-12_dp) &
             / flattening_estimate(p, 0.5_dp + 1e-12_dp) - 1) < 1e-10_dp, 'flattening continuous at phi = 0.5')
  call check(abs(flattening_estimate(p, 0.0_dp) / 0.05_dp - 1) < 1e-13_dp, 'flattening at phi = 0 is eps_bar')

  ! 14. shear jamming, with eps_bar 0.01 (the extreme scenes'; the flattening estimate stays below
  ! h_r there) and dt 1e-3 (chatter number 0.1)
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, 0.5_dp, 0.01_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  found = contact_limits(p0, 1.0e-3_dp, .true., .true., 0.5485_dp, 0.01_dp, .false.)
  call check(count(found%level == LIMIT_REFUSE) == 1, 'phi 0.5485, mu_d 0.5, eps_bar 0.01, sheared: refused')
  call check(any(found%group == 'contact' .and. found%key == 'eps_bar' .and. index(found%text, 'overlap budget') > 0 &
             .and. index(found%text, 'eps_bar <=  5.00E-03') > 0), &
             'the refusal names &contact eps_bar, the overlap budget and eps_bar <= 0.005')
  call check(any(index(found%text, 'normal_stiffness >= ') > 0), 'and the stiffness that flowed')
  call contact_setup(pb, 1.0_dp, 5.0e-3_dp, 0.5_dp, 0.05_dp, p0%k_n, 1.0_dp, 1.0_dp, info, msg)
  found = contact_limits(pb, 1.0e-3_dp, .true., .true., 0.5485_dp, 0.05_dp, .true.)
  call check(any(found%level == LIMIT_REFUSE .and. found%key == 'normal_stiffness'), &
             'the same k_n prescribed: refused naming &contact normal_stiffness')
  call contact_setup(pb, 1.0_dp, 5.0e-3_dp, 0.5_dp, 0.005_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  found = contact_limits(pb, 2.0e-4_dp, .true., .true., 0.5485_dp, 0.005_dp, .false.)
  call check(count(found%level == LIMIT_REFUSE) == 0 .and. any(found%level == LIMIT_WARN .and. &
             index(found%text, 'Lees-Edwards cubes up to phi 0.589') > 0), 'eps_bar 0.005: no refusal, a warning')
  found = contact_limits(pb, 2.0e-4_dp, .true., .true., 0.5485_dp, 0.005_dp, .false., 1.4_dp)
  call check(count(found%level == LIMIT_REFUSE) == 1, 'eps_bar 0.005 with a 1:1.4 mixture: refused')
  call contact_setup(pb, 1.0_dp, 5.0e-3_dp, 0.5_dp, 0.002_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  found = contact_limits(pb, 8.0e-5_dp, .true., .true., 0.589_dp, 0.002_dp, .false.)
  call check(count(found%level == LIMIT_REFUSE) == 0 .and. any(found%level == LIMIT_WARN .and. &
             index(found%text, 'jams on start-up') > 0 .and. index(found%text, 'control = ''stress''') > 0), &
             'phi 0.589, mu_d 0.5, eps_bar 0.002: no refusal, the warning that a rate-controlled start-up jams')
  found = contact_limits(p0, 1.0e-3_dp, .true., .false., 0.5485_dp, 0.01_dp, .false.)
  call check(count(found%level == LIMIT_REFUSE) == 0, 'not sheared: no refusal')
  call contact_setup(pb, 1.0_dp, 5.0e-3_dp, 0.5_dp, 0.01_dp, 1.0e8_dp, 1.0_dp, 0.0_dp, info, msg)
  found = contact_limits(pb, 1.0e-3_dp, .true., .true., 0.5485_dp, 0.01_dp, .true.)
  call check(info == 0 .and. count(found%level == LIMIT_REFUSE) == 0, 'walls at rest (shear_rate 0): no refusal')
  found = contact_limits(p0, 1.0e-3_dp, .true., .true., 0.53_dp, 0.01_dp, .false.)
  call check(count(found%level == LIMIT_REFUSE) == 0 .and. any(index(found%text, 'close to shear jamming') > 0 &
             .and. found%level == LIMIT_WARN), 'phi 0.53, mu_d 0.5: a warning, no refusal')
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, 0.1_dp, 0.01_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  found = contact_limits(p0, 1.0e-3_dp, .true., .true., 0.5485_dp, 0.01_dp, .false.)
  call check(count(found%level == LIMIT_REFUSE) == 0, 'mu_d 0.1 at phi 0.5485: no refusal')
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, 0.0_dp, 0.01_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  found = contact_limits(p0, 1.0e-3_dp, .true., .true., 0.5485_dp, 0.01_dp, .false.)
  call check(count(found%level == LIMIT_REFUSE) == 0, 'frictionless at phi 0.5485: no refusal')

  ! 15. a mixture's largest pair
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, 0.0_dp, 0.06_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  found = contact_limits(p0, 1.0e-3_dp, .true., .true., 0.4_dp, 0.06_dp, .false., 1.0_dp)
  call check(size(found) == 0, 'eps_bar 0.06 at phi 0.4, equal spheres: no finding')
  found = contact_limits(p0, 1.0e-3_dp, .true., .true., 0.4_dp, 0.06_dp, .false., 1.4_dp)
  call check(count(found%level == LIMIT_WARN) == 1 .and. any(index(found%text, '0.58 h_r') > 0), &
             'the same with a 1:1.4 mixture: a warning at 0.58 h_r')
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, 0.0_dp, 0.09_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  found = contact_limits(p0, 1.0e-3_dp, .true., .true., 0.4_dp, 0.09_dp, .false.)
  call check(count(found%level == LIMIT_WARN) == 1 .and. count(found%level == LIMIT_REFUSE) == 0, &
             'eps_bar 0.09 at phi 0.4, equal spheres: a warning')
  found = contact_limits(p0, 1.0e-3_dp, .true., .true., 0.4_dp, 0.09_dp, .false., 2.0_dp)
  call check(count(found%level == LIMIT_REFUSE) == 1 .and. any(found%group == 'contact' .and. found%key == 'eps_bar'), &
             'the same with a 1:2 mixture: refused, naming &contact eps_bar')

  call finish('test_contact')

contains

  subroutine cf(pp, xx)
    type(contact_params_t), intent(in) :: pp
    real(dp), intent(in) :: xx(:,:)
    call contact_forces(pp, h, xx, u, om, box, per, vw, pairs, 1, walls, 0, 1e-3_dp, force, &
                        torque, ss, st, info)
    if (info /= 0) call check(.false., 'contact_forces info')
  end subroutine cf

  subroutine clear_history()
    h = contact_history_t()       ! the default: no contacts, nothing allocated
  end subroutine clear_history

end program test_contact
