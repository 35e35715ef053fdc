! Unit test: tangential sphere-wall functions of mod_resistance (f_tt translation, f_tr coupling,
! f_rr rotation; method.md 2.8) against published values and exact identities (issue 3).
! The module evaluates the exact bispherical solutions (O'Neill 1964 translation, Dean & O'Neill
! 1963 rotation) for 1e-3 <= eps <= 10, the inner forms below and the reflection forms above.
! Invariants and tolerances:
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
!   4. Near field: the inner forms of method.md 2.8 against the exact solution at eps = 1e-4.
!      Measured 7.6e-4 (f_tt), 4.8e-3 (f_tr), 2.7e-3 (f_rr): absolute 0.004-0.011, which does
!      not shrink with eps, i.e. the O(1) constants 0.9588, -0.2526, 0.3817 (tagged [M], from
!      memory, in method.md) are off by that much (exact ~0.9545, ~-0.2573, ~0.3709). Asserted
!      <= 6e-3 so that the finding stays visible; the module uses the inner forms only below
!      eps = 1e-3, matched there to the exact solution (doc/RESISTANCE.md, open item).
!   5. Continuity of the module across its switches eps = 1e-3 and 10: relative jump < 1e-9.
!   6. Printed, not asserted: module values at eps = 0.1, 0.5, 1, 2, 5 next to those of the
!      former inner/far blend, to record how far off the blend was (doc/RESISTANCE.md).
program test_resistance_wall_tangential
  use mod_kinds, only: dp
  use mod_resistance, only: wall_tangential_resistance, wall_tangential_exact, &
                            wall_tangential_inner, wall_tangential_far
  implicit none
  real(dp), parameter :: gaps(6) = [1.0e-3_dp, 0.1_dp, 0.5_dp, 1.0_dp, 2.0_dp, 5.0_dp]
  real(dp) :: v(3), w(3), f_rt, worst, eps, old(3), x, lo, hi
  integer :: k, failures

  failures = 0
  call wall_tangential_resistance(1.0e-3_dp, v(1), v(2), v(3))
  print '(a,3f9.5)', ' 1. eps = 1e-3: f_tt, f_tr, (4/3) f_rr = ', v(1), v(2), 4.0_dp / 3.0_dp * v(3)
  print '(a)', '    O''Neill & Stewartson (1967):             4.640    0.665    4.184'
  worst = max(abs(v(1) / 4.640_dp - 1.0_dp), abs(v(2) / 0.665_dp - 1.0_dp), &
              abs(4.0_dp / 3.0_dp * v(3) / 4.184_dp - 1.0_dp))
  call check('1. published values at 1e-3, max rel. error', worst, 1.0e-3_dp)

  worst = 0.0_dp
  do k = 1, size(gaps)
    call wall_tangential_exact(gaps(k), v(1), v(2), v(3), f_rt)
    worst = max(worst, abs(f_rt / v(2) - 1.0_dp))
  end do
  call check('2. reciprocity f_tr (translation) = f_rt (rotation), max rel. diff.', worst, 1.0e-8_dp)

  call wall_tangential_exact(10.0_dp, v(1), v(2), v(3))
  w = wall_tangential_far(10.0_dp)
  call check('3. far field eps = 10: f_tt vs Faxen', abs(w(1) / v(1) - 1.0_dp), 2.0e-6_dp)
  call check('3. far field eps = 10: f_rr vs GCB', abs(w(3) / v(3) - 1.0_dp), 2.0e-6_dp)
  call check('3. far field eps = 10: f_tr vs GCB', abs(w(2) / v(2) - 1.0_dp), 2.0e-2_dp)

  call wall_tangential_exact(1.0e-4_dp, v(1), v(2), v(3))
  w = wall_tangential_inner(1.0e-4_dp)
  print '(a,3f9.5,a,3f9.5)', '    eps = 1e-4 exact ', v, ', inner forms ', w
  call check('4. inner forms vs exact at eps = 1e-4, max rel. error', maxval(abs(w / v - 1.0_dp)), &
             6.0e-3_dp)

  worst = 0.0_dp
  do k = 1, 2
    eps = merge(1.0e-3_dp, 10.0_dp, k == 1)
    call wall_tangential_resistance(eps * (1.0_dp - 1.0e-12_dp), v(1), v(2), v(3))
    call wall_tangential_resistance(eps * (1.0_dp + 1.0e-12_dp), w(1), w(2), w(3))
    worst = max(worst, maxval(abs(w / v - 1.0_dp)))
  end do
  call check('5. continuity at eps = 1e-3 and 10, max rel. jump', worst, 1.0e-9_dp)

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

  if (failures > 0) error stop 1
  print '(a)', 'all checks passed'

contains

  subroutine check(what, value, tol)
    character(len=*), intent(in) :: what
    real(dp), intent(in) :: value, tol
    if (value <= tol) then
      print '(a,a,a,es10.3,a,es9.2,a)', '   PASS ', what, ': ', value, ' (tol ', tol, ')'
    else
      print '(a,a,a,es10.3,a,es9.2,a)', '   FAIL ', what, ': ', value, ' (tol ', tol, ')'
      failures = failures + 1
    end if
  end subroutine check
end program test_resistance_wall_tangential
