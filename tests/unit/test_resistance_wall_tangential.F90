! Unit test: tangential sphere-wall functions of mod_wall_resistance (f_tt translation, f_tr coupling,
! f_rr rotation; doc/METHOD.md §5.2) against published values and exact identities.
! The module evaluates the exact bispherical solutions (O'Neill 1964 translation, Dean & O'Neill
! 1963 rotation) for 1e-3 <= eps <= 10, the inner forms below and the reflection forms above.
! Invariants and tolerances:
!   0. Published exact (bispherical) values at nine gaps eps = cosh(alpha) - 1, alpha = 3 .. 0.06
!      (eps = 9.07 .. 1.8e-3): the module's value, rounded to the digits printed, must be the
!      printed value to within one unit of the last digit (absolute |module - printed| <= 1 unit;
!      rounding alone leaves <= 0.5 unit, the module's own error is < 1e-10, so 1 unit also admits
!      a last-digit slip of the source). Sources and normalisations (torques about the centre):
!      a. O'Neill (1964, Mathematika 11:67, table p. 73), translation without rotation:
!         F* = F/(6 pi eta a U) = f_tt (4 decimals), G* = T/(8 pi eta a^2 U) = (3/4) f_tr
!         (5 decimals). G* is held to 2 units: O'Neill's 0.38496 at alpha = 0.08 is 1.7 units
!         above the exact value 0.384943 (his neighbouring entries are within 0.7 unit).
!      b. Goldman, Cox & Brenner (1967, Chem. Eng. Sci. 22:637, exact-solution tables),
!         F*_t = f_tt and T*_r = T/(8 pi eta a^3 Omega) = f_rr (4 decimals; (4/3) f_rr is the
!         6 pi eta a^3 normalisation of invariant 1). Includes alpha = 1.5, not in O'Neill's table.
!      Transcriptions read (the papers themselves were not available): O'Neill's F*, G* from
!      github.com/OZAKI39/ulm-3d-vascular-model-generation, review/
!      microbubble_wall_handoff_20260916/wall_reference/src/compare_oneill_table.py (a466b77b...,
!      "visually checked" there against p. 73);
!      GCB's F*_t, T*_r decoded from github.com/antoniodimauro/PhasicFlow, PhasicFlowPlus/
!      phasicFlowCoupling/couplingSystem/unresolved/interaction/wallCorrection/wallCorrection.hpp
!      (e85971e2...), which stores (F*_t - 1) l/a and (T*_r - 1)(l/a)^3 at the table's l/a; the
!      decoded values are 4-decimal numbers to 1e-6 at all eight points.
!   1. Published exact values, O'Neill & Stewartson (1967, J. Fluid Mech. 27:705, table of the
!      bispherical solution) at delta/a = 1e-3: F_xt = 4.640 (f_tt), F_xr = 0.665 (f_tr),
!      T_yr = 4.184 ((4/3) f_rr), 4 significant digits: relative error <= 1e-3 (half a unit of
!      the last digit is 1.1e-4 .. 7.5e-4).
!   2. Reciprocity, two independent solutions: the torque on a translating sphere (O'Neill 1964)
!      equals the force on a rotating one (Dean & O'Neill 1963), f_tr = f_rt, at eps = 1e-3, 0.1,
!      0.5, 1, 2, 5: relative difference <= 1e-8 (both are truncated series converged to ~1e-12).
!   3. Far field: at eps = 10 (l/a = 11) the exact solution equals Faxen's f_tt and GCB's f_tr,
!      f_rr reflection forms within their first omitted order, x^6 = 5.6e-7 (f_tt, f_rr) and
!      x^6/8 relative to f_tr ~ x^4/8, i.e. x^2 = 8e-3 (f_tr): tolerances 2e-6 and 2e-2.
!   4. Near field: the inner forms of doc/METHOD.md §5.2 against the exact solution at eps = 1e-4.
!      Measured 7.6e-4 (f_tt), 4.8e-3 (f_tr), 2.7e-3 (f_rr): absolute 0.004-0.011, which does
!      not shrink with eps, i.e. the O(1) constants 0.9588, -0.2526, 0.3817 (quoted from
!      memory of the literature, doc/METHOD.md §5.2) are off by that much (exact ~0.9545, ~-0.2573, ~0.3709). Asserted
!      <= 6e-3 so that the finding stays visible; the module uses the inner forms only below
!      eps = 1e-3, matched there to the exact solution (doc/RESISTANCE.md, open item).
!   5. Continuity of the module across its switches eps = 1e-3 and 10: relative jump < 1e-9.
!   6. Printed, not asserted: module values at eps = 0.1, 0.5, 1, 2, 5 next to those of the
!      former inner/far blend, to record how far off the blend was (doc/RESISTANCE.md).
program test_resistance_wall_tangential
  use mod_kinds, only: dp
  use mod_wall_resistance, only: wall_tangential_resistance, wall_tangential_exact, &
       wall_tangential_inner, wall_tangential_far
  use mod_unit_checks, only: check_below, finish
  implicit none
  real(dp), parameter :: gaps(6) = [1.0e-3_dp, 0.1_dp, 0.5_dp, 1.0_dp, 2.0_dp, 5.0_dp]
  ! 0a. O'Neill (1964) p. 73: alpha, F* (f_tt), G* ((3/4) f_tr)
  real(dp), parameter :: on_alpha(8) = [3.0_dp, 2.0_dp, 1.0_dp, 0.5_dp, 0.3_dp, 0.1_dp, 0.08_dp, &
                                        0.06_dp]
  real(dp), parameter :: on_f(8) = [1.0591_dp, 1.1738_dp, 1.5675_dp, 2.1515_dp, 2.6475_dp, &
                                    3.7863_dp, 4.0223_dp, 4.3275_dp]
  real(dp), parameter :: on_g(8) = [0.00001_dp, 0.00042_dp, 0.01465_dp, 0.07372_dp, 0.14552_dp, &
                                    0.34187_dp, 0.38496_dp, 0.44116_dp]
  ! 0b. Goldman, Cox & Brenner (1967): alpha, F*_t (f_tt), T*_r (f_rr)
  real(dp), parameter :: gcb_alpha(8) = [3.0_dp, 2.0_dp, 1.5_dp, 1.0_dp, 0.5_dp, 0.3_dp, 0.1_dp, &
                                         0.08_dp]
  real(dp), parameter :: gcb_ft(8) = [1.0591_dp, 1.1738_dp, 1.3079_dp, 1.5675_dp, 2.1514_dp, &
                                      2.6475_dp, 3.7863_dp, 4.0223_dp]
  real(dp), parameter :: gcb_tr(8) = [1.0003_dp, 1.0059_dp, 1.0250_dp, 1.0998_dp, 1.3877_dp, &
                                      1.6996_dp, 2.5056_dp, 2.6793_dp]
  real(dp) :: v(3), w(3), f_rt, worst, eps, old(3), x, lo, hi, d(4), dmax(4), rmax
  integer :: k

  print '(a)', ' 0.  alpha   eps        f_tt  O''Neill   GCB  |  (3/4)f_tr  O''Neill |  f_rr    GCB'
  dmax = 0.0_dp
  rmax = 0.0_dp
  do k = 1, 8
    eps = cosh(on_alpha(k)) - 1.0_dp
    call wall_tangential_resistance(eps, v(1), v(2), v(3))
    print '(f8.2,es11.3,f9.5,f8.4,a8,a,f10.6,f9.5)', on_alpha(k), eps, v(1), on_f(k), '', ' |', &
          0.75_dp * v(2), on_g(k)
    d(1:2) = [abs(v(1) - on_f(k)) / 1.0e-4_dp, abs(0.75_dp * v(2) - on_g(k)) / 1.0e-5_dp]
    dmax(1:2) = max(dmax(1:2), d(1:2))
    rmax = max(rmax, abs(v(1) / on_f(k) - 1.0_dp))
    if (k >= 3) rmax = max(rmax, abs(0.75_dp * v(2) / on_g(k) - 1.0_dp))
  end do
  do k = 1, 8
    eps = cosh(gcb_alpha(k)) - 1.0_dp
    call wall_tangential_resistance(eps, v(1), v(2), v(3))
    print '(f8.2,es11.3,f9.5,a8,f8.4,a,a19,a,f9.5,f8.4)', gcb_alpha(k), eps, v(1), '', gcb_ft(k), &
          ' |', '', ' |', v(3), gcb_tr(k)
    d(3:4) = [abs(v(1) - gcb_ft(k)) / 1.0e-4_dp, abs(v(3) - gcb_tr(k)) / 1.0e-4_dp]
    dmax(3:4) = max(dmax(3:4), d(3:4))
    rmax = max(rmax, abs(v(1) / gcb_ft(k) - 1.0_dp), abs(v(3) / gcb_tr(k) - 1.0_dp))
  end do
  print '(a,es10.3,a)', '    max relative difference (G* with >= 3 digits): ', rmax, &
        ' (printed digits, not module error)'
  call check_below('0a. O''Neill (1964) F* = f_tt, 8 gaps, max |diff| in units of 1e-4', dmax(1), 1.0_dp)
  call check_below('0a. O''Neill (1964) G* = (3/4) f_tr, 8 gaps, max |diff| in units of 1e-5', dmax(2), &
             2.0_dp)
  call check_below('0b. GCB (1967) F*_t = f_tt, 8 gaps, max |diff| in units of 1e-4', dmax(3), 1.0_dp)
  call check_below('0b. GCB (1967) T*_r = f_rr, 8 gaps, max |diff| in units of 1e-4', dmax(4), 1.0_dp)

  call wall_tangential_resistance(1.0e-3_dp, v(1), v(2), v(3))
  print '(a,3f9.5)', ' 1. eps = 1e-3: f_tt, f_tr, (4/3) f_rr = ', v(1), v(2), 4.0_dp / 3.0_dp * v(3)
  print '(a)', '    O''Neill & Stewartson (1967):             4.640    0.665    4.184'
  worst = max(abs(v(1) / 4.640_dp - 1.0_dp), abs(v(2) / 0.665_dp - 1.0_dp), &
              abs(4.0_dp / 3.0_dp * v(3) / 4.184_dp - 1.0_dp))
  call check_below('1. published values at 1e-3, max rel. error', worst, 1.0e-3_dp)

  worst = 0.0_dp
  do k = 1, size(gaps)
    call wall_tangential_exact(gaps(k), v(1), v(2), v(3), f_rt)
    worst = max(worst, abs(f_rt / v(2) - 1.0_dp))
  end do
  call check_below('2. reciprocity f_tr (translation) = f_rt (rotation), max rel. diff.', worst, 1.0e-8_dp)

  call wall_tangential_exact(10.0_dp, v(1), v(2), v(3))
  w = wall_tangential_far(10.0_dp)
  call check_below('3. far field eps = 10: f_tt vs Faxen', abs(w(1) / v(1) - 1.0_dp), 2.0e-6_dp)
  call check_below('3. far field eps = 10: f_rr vs GCB', abs(w(3) / v(3) - 1.0_dp), 2.0e-6_dp)
  call check_below('3. far field eps = 10: f_tr vs GCB', abs(w(2) / v(2) - 1.0_dp), 2.0e-2_dp)

  call wall_tangential_exact(1.0e-4_dp, v(1), v(2), v(3))
  w = wall_tangential_inner(1.0e-4_dp)
  print '(a,3f9.5,a,3f9.5)', '    eps = 1e-4 exact ', v, ', inner forms ', w
  call check_below('4. inner forms vs exact at eps = 1e-4, max rel. error', maxval(abs(w / v - 1.0_dp)), &
             6.0e-3_dp)

  worst = 0.0_dp
  do k = 1, 2
    eps = merge(1.0e-3_dp, 10.0_dp, k == 1)
    call wall_tangential_resistance(eps * (1.0_dp - 1.0e-12_dp), v(1), v(2), v(3))
    call wall_tangential_resistance(eps * (1.0_dp + 1.0e-12_dp), w(1), w(2), w(3))
    worst = max(worst, maxval(abs(w / v - 1.0_dp)))
  end do
  call check_below('5. continuity at eps = 1e-3 and 10, max rel. jump', worst, 1.0e-9_dp)

  print '(a)', ' 6.  eps     f_tt      f_tr      f_rr    | former blend: f_tt      f_tr      f_rr'
  do k = 2, size(gaps)
    eps = gaps(k)
    call wall_tangential_resistance(eps, v(1), v(2), v(3))
    ! the former module: C1 smoothstep in ln(eps) between the inner (<= 0.05) and far (>= 0.5) forms
    lo = log(0.05_dp)
    hi = log(0.5_dp)
    x = min(1.0_dp, max(0.0_dp, (log(eps) - lo) / (hi - lo)))
    x = x * x * (3.0_dp - 2.0_dp * x)
    old = (1.0_dp - x) * wall_tangential_inner(eps) + x * wall_tangential_far(eps)
    print '(f7.2,3f10.5,a,3f10.5)', eps, v, '   |             ', old
  end do

  call finish('test_resistance_wall_tangential')

end program test_resistance_wall_tangential
