! Unit test: sphere-wall resistance functions of mod_wall_resistance (doc/METHOD.md §5.2) against published
! exact values and exact identities (doc/VALIDATION_pair.md §4).
!   1. Normal approach against Brenner's (1961) published table, lambda = F/(6 pi eta a U) at
!      l/a = cosh(alpha), alpha = 0.5, 1, 1.5, 2, 2.5, 3: 9.2518, 3.0361, 1.8375, 1.4129,
!      1.2220, 1.1253 (5 significant digits): relative error <= 1e-4.
!   2. Normal: the Cox & Brenner inner form used below eps = 1e-2 joins the exact series within
!      1e-4 relative (its error is O(eps^2 ln eps)/(1/eps)); lambda eps -> 1 at eps = 1e-8 (1e-6).
!      The far-field form 1/(1 - 9x/8 + x^3/2 - 0.57x^4 + 0.2x^5) equals the exact series within
!      2e-4 for l/a >= 3.76 (doc/METHOD.md §5.2: "to 4 digits").
!   3. Tangential translation/rotation at delta/a = 1e-3 against O'Neill & Stewartson's (1967)
!      table as quoted in doc/METHOD.md §5.2: F_xt = 4.640 (f_tt), F_xr = 0.665 (f_tr),
!      T_yr = 4.184 ((4/3) f_rr): relative error <= 1e-3 (4 digits; the module evaluates the
!      exact bispherical solution there; more in test_resistance_wall_tangential).
!   4. Rotation about the wall normal: by mirror symmetry a sphere twisting next to a no-slip wall
!      is half of two spheres counter-rotating about their line of centres, so
!      X_w(eps) = XC11 - XC12 at s = 2 + 2 eps. Checked against the Lamb-method rows of the pair
!      table (independent data) at 13 gaps, relative error <= 1e-4; X_w -> zeta(3) at contact.
!   5. The 6x6 sphere-wall resistance is symmetric and positive definite for eps in
!      [1e-6, 100] (dissipation), and the tangential functions are continuous across the
!      exact/inner/far switches (relative jump < 1e-6 over a 1e-8 step).
!   6. Coupling sign (GCB 1967): a torque-free sphere pushed parallel to the wall (n = +y, force
!      along +x) rotates in the rolling sense, Om_z < 0, with 0 < -a Om_z / U_x < 1/4 (1/4 is the
!      contact limit f_tr/((4/3) f_rr) -> (2/15)/(4/3 * 2/5)), at eps = 1e-3, 1e-2, 0.1, 1.
program test_resistance_wall
  use mod_kinds, only: dp
  use mod_pair_resistance, only: i_xc11, i_xc12
  use mod_wall_resistance, only: wall_normal_resistance, wall_normal_near_field, &
       wall_normal_far_field, wall_tangential_resistance, wall_twist_resistance
  use mod_resistance_blocks, only: wall_resistance_fu
  use mod_resistance_table, only: resistance_table_size, resistance_table_sep, resistance_table_values
  use mod_unit_checks, only: failures, check_below, finish
  implicit none
  real(dp), parameter :: brenner_alpha(6) = [0.5_dp, 1.0_dp, 1.5_dp, 2.0_dp, 2.5_dp, 3.0_dp]
  real(dp), parameter :: brenner_lambda(6) = [9.2518_dp, 3.0361_dp, 1.8375_dp, 1.4129_dp, &
                                              1.2220_dp, 1.1253_dp]
  integer :: k, n
  real(dp) :: worst, eps, f_tt, f_tr, f_rr, g_tt, g_tr, g_rr, xw, xc, r(6, 6), nrm(3), pmin, ut(6)

  worst = 0.0_dp
  do k = 1, size(brenner_alpha)
    eps = cosh(brenner_alpha(k)) - 1.0_dp
    print '(a,f7.4,a,f9.5,a,f8.4)', '   l/a = ', eps + 1, ': lambda = ', wall_normal_resistance(eps), &
      '  Brenner 1961: ', brenner_lambda(k)
    worst = max(worst, abs(wall_normal_resistance(eps) / brenner_lambda(k) - 1.0_dp))
  end do
  call check_below('1. normal vs Brenner table, max rel. error', worst, 1.0e-4_dp)

  call check_below('2. normal inner form vs exact series at eps = 1e-2', &
             abs(wall_normal_near_field(1.0e-2_dp) / wall_normal_resistance(1.0e-2_dp) - 1.0_dp), &
             1.0e-4_dp)
  call check_below('2. lambda eps -> 1 at eps = 1e-8', abs(wall_normal_resistance(1.0e-8_dp) * 1.0e-8_dp - 1.0_dp), &
             1.0e-6_dp)
  worst = 0.0_dp
  do k = 0, 20
    eps = 2.76_dp * 1.25_dp**k
    worst = max(worst, abs(wall_normal_far_field(eps) / wall_normal_resistance(eps) - 1.0_dp))
  end do
  call check_below('2. far-field form vs exact series for l/a >= 3.76', worst, 2.0e-4_dp)

  call wall_tangential_resistance(1.0e-3_dp, f_tt, f_tr, f_rr)
  print '(a,3f8.4,a)', '   delta/a = 1e-3: f_tt, f_tr, (4/3) f_rr = ', f_tt, f_tr, 4.0_dp / 3.0_dp * f_rr, &
    '  (O''Neill & Stewartson: 4.640, 0.665, 4.184)'
  worst = max(abs(f_tt / 4.640_dp - 1.0_dp), abs(f_tr / 0.665_dp - 1.0_dp), &
              abs(4.0_dp / 3.0_dp * f_rr / 4.184_dp - 1.0_dp))
  call check_below('3. tangential vs O''Neill & Stewartson at 1e-3, max rel. error', worst, 1.0e-3_dp)

  worst = 0.0_dp
  n = 0
  do k = 1, resistance_table_size
    if (resistance_table_sep(k) < 2.025_dp - 1.0e-9_dp) cycle
    if (mod(k, 2) == 0) cycle
    n = n + 1
    eps = (resistance_table_sep(k) - 2.0_dp) / 2.0_dp
    xw = wall_twist_resistance(eps)
    xc = resistance_table_values(k, i_xc11) - resistance_table_values(k, i_xc12)
    worst = max(worst, abs(xw / xc - 1.0_dp))
  end do
  print '(a,i0,a)', '   (', n, ' gaps)'
  call check_below('4. twist X_w vs XC11 - XC12 of the pair table, max rel. error', worst, 1.0e-4_dp)
  call check_below('4. twist at contact vs zeta(3)', abs(wall_twist_resistance(0.0_dp) - 1.2020569_dp), 1.0e-4_dp)

  pmin = huge(1.0_dp)
  worst = 0.0_dp
  nrm = [0.0_dp, 1.0_dp, 0.0_dp]
  do k = 0, 48
    eps = 10.0_dp**(-6.0_dp + k / 6.0_dp)
    r = wall_resistance_fu(eps, nrm, 1.0_dp, 1.0_dp)
    worst = max(worst, maxval(abs(r - transpose(r))) / maxval(abs(r)))
    pmin = min(pmin, min_eig_sym(r))
  end do
  call check_below('5. wall 6x6 symmetry', worst, 1.0e-14_dp)
  if (pmin > 0.0_dp) then
    print '(a,es10.3)', '   PASS 5. wall 6x6 positive definite; smallest eigenvalue ', pmin
  else
    print '(a,es10.3)', '   FAIL 5. wall 6x6 not positive definite; smallest eigenvalue ', pmin
    failures = failures + 1
  end if
  worst = 0.0_dp
  do k = 0, 200
    eps = 0.04_dp * 1.015_dp**k
    call wall_tangential_resistance(eps, f_tt, f_tr, f_rr)
    call wall_tangential_resistance(eps * (1.0_dp + 1.0e-8_dp), g_tt, g_tr, g_rr)
    worst = max(worst, abs(g_tt - f_tt) / f_tt, abs(g_tr - f_tr) / max(abs(f_tr), 1.0e-2_dp), &
                abs(g_rr - f_rr) / f_rr)
  end do
  call check_below('5. tangential functions continuous (0.04 < eps < 0.8)', worst, 1.0e-6_dp)

  do k = 1, 4
    eps = 10.0_dp**(k - 4)
    r = wall_resistance_fu(eps, nrm, 1.0_dp, 1.0_dp)
    ! Torque-free response to a unit force along +x: solve the 6x6 system R (U, Om) = (e_x, 0).
    ut = solve6(r, [1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp])
    print '(a,es8.1,a,f9.5)', '   eps = ', eps, ': torque-free rolling ratio -a Om_z / U_x = ', -ut(6) / ut(1)
    if (.not. (ut(6) < 0.0_dp .and. -ut(6) / ut(1) < 0.25_dp)) then
      print '(a)', '   FAIL 6. wrong rolling sense or ratio beyond the contact limit 1/4'
      failures = failures + 1
    end if
  end do

  call finish('test_resistance_wall')

contains

  !> Gaussian elimination with partial pivoting for a small dense system.
  function solve6(a_in, b_in) result(x)
    real(dp), intent(in) :: a_in(6, 6), b_in(6)
    real(dp) :: x(6), a(6, 6), b(6), tmp(6), tb, f
    integer :: i, j, p
    a = a_in
    b = b_in
    do i = 1, 6
      p = maxloc(abs(a(i:6, i)), 1) + i - 1
      tmp = a(i, :); a(i, :) = a(p, :); a(p, :) = tmp
      tb = b(i); b(i) = b(p); b(p) = tb
      do j = i + 1, 6
        f = a(j, i) / a(i, i)
        a(j, :) = a(j, :) - f * a(i, :)
        b(j) = b(j) - f * b(i)
      end do
    end do
    do i = 6, 1, -1
      x(i) = (b(i) - sum(a(i, i + 1:6) * x(i + 1:6))) / a(i, i)
    end do
  end function solve6

  !> Smallest eigenvalue of a symmetric matrix by cyclic Jacobi rotations.
  function min_eig_sym(a_in) result(lmin)
    real(dp), intent(in) :: a_in(:, :)
    real(dp) :: lmin, a(size(a_in, 1), size(a_in, 1)), th, t, c, s, apq
    integer :: p, q, sweep, nn, i
    real(dp) :: aip, aiq
    a = a_in
    nn = size(a, 1)
    do sweep = 1, 100
      if (sum(a**2) - sum([(a(i, i)**2, i = 1, nn)]) < 1.0e-30_dp * sum(a**2)) exit
      do p = 1, nn - 1
        do q = p + 1, nn
          apq = a(p, q)
          if (abs(apq) < 1.0e-300_dp) cycle
          th = (a(q, q) - a(p, p)) / (2.0_dp * apq)
          t = sign(1.0_dp, th) / (abs(th) + sqrt(th**2 + 1.0_dp))
          c = 1.0_dp / sqrt(t**2 + 1.0_dp)
          s = t * c
          do i = 1, nn
            aip = a(i, p)
            aiq = a(i, q)
            a(i, p) = c * aip - s * aiq
            a(i, q) = s * aip + c * aiq
          end do
          do i = 1, nn
            aip = a(p, i)
            aiq = a(q, i)
            a(p, i) = c * aip - s * aiq
            a(q, i) = s * aip + c * aiq
          end do
        end do
      end do
    end do
    lmin = minval([(a(i, i), i = 1, nn)])
  end function min_eig_sym

end program test_resistance_wall
