! Unit test: the 22 equal-sphere resistance scalars of mod_resistance against the reference table
! (input/tables/two_sphere_resistance_equal_spheres.csv, Jeffrey-Onishi / Lamb-method values,
! compiled in as mod_resistance_table), at every tabulated separation and at the joins with the
! asymptotic forms (issue 3 acceptance; method.md sections 2.3, 3.1, 3.2; doc/RESISTANCE.md).
!
! Errors are measured as |f - f_ref| / max(|f_ref|, 1e-2): relative for O(1) and singular
! scalars, absolute 1e-2-scaled for the few that pass through zero (YH11, YM12 ...), whose
! relative error is meaningless there.
! Invariants and tolerances:
!   1. Inside the interpolated range (the 26 Lamb-method rows, 0.025 <= gap <= 2.5) every scalar
!      equals the table within 1e-6 (the spline passes through the rows: only round-off remains).
!   2. Near join: below gap 0.025 the module uses the near-field forms (method.md 3.1, 6-digit
!      O(1) constants) plus an O(xi) term fitted to the first Lamb-method row (s = 2.025). The
!      12 rows below s = 2.025 are themselves asymptotic-form values (input/tables/README.md).
!      (a) the bare forms reproduce those rows within 1e-4 (they are the same forms: checks the
!          coefficients transcribed from method.md 3.1 against Townsend's);
!      (b) the module agrees with them within 1e-3 for gap <= 2e-3, where the fitted O(xi) term
!          (|b| xi < 1e-4 absolute) is below the issue's join tolerance (measured 9.3e-4, ZM12);
!      (c) at 5e-3 <= gap <= 0.02 the module departs from the rows by the O(xi) term the
!          asymptotic forms lack; bounded by 3e-2 (measured 9.4e-3, ZM12 at 0.02). The bare
!          forms miss the exact Lamb row at s = 2.025 by up to 1.0e-2 (YB11), so no smooth
!          function can meet 1e-3 against both kinds of rows there; the module follows the exact
!          side (for XA11 +- XA12 it is 40x closer to Stimson & Jeffery than the row at 0.02,
!          see test_resistance_bispherical).
!      Here the scale in the error is max(|f_ref|, 0.1) (YM12 crosses zero at gap ~ 1e-3).
!   3. Both joins (gap 0.025 and s = 4.5) are continuous: value jump < 1e-8, slope jump < 1e-4
!      of the largest slope (one-sided finite differences, step 1e-6 relative).
!   4. The bare truncated far-field series of method.md 3.2 is within 1e-2 of the table at
!      s = 4.5 (method.md quotes <= 2 %; the module's tail term closes the rest).
!   5. Isolated-sphere limits at s = 1e4: XA11 = YA11 = XC11 = YC11 = XM11 = YM11 = ZM11 = 1,
!      the others 0 apart from the Stokeslet terms XA12 = -3/(2s), YA12 = -3/(4s), within 1e-6
!      (the next terms are O(s^-2) = 1e-8).
program test_resistance_table
  use mod_kinds, only: dp
  use mod_resistance, only: n_pair_scalars, pair_scalar_names, resistance_scalars, &
                            near_field_scalars, far_field_scalars, i_xa12, i_ya12, &
                            near_join_gap, far_join_gap
  use mod_resistance_table, only: resistance_table_size, resistance_table_sep, &
                                  resistance_table_values
  implicit none
  integer :: k, j, failures
  real(dp) :: f(n_pair_scalars), g(n_pair_scalars), ref(n_pair_scalars), err, worst, xi, s
  real(dp) :: slope_lo(n_pair_scalars), slope_hi(n_pair_scalars), h
  real(dp) :: isolated(n_pair_scalars)

  failures = 0
  h = 0.0_dp

  print '(a)', '1. every scalar at every Lamb-method row, gap >= 0.025 (tolerance 1e-6)'
  worst = 0.0_dp
  do k = 1, resistance_table_size
    xi = resistance_table_sep(k) - 2.0_dp
    if (xi < near_join_gap * (1.0_dp - 1.0e-9_dp)) cycle
    f = resistance_scalars(xi)
    ref = resistance_table_values(k, :)
    worst = max(worst, maxval(scaled_error(f, ref)))
  end do
  call check('Lamb rows, max scaled error', worst, 1.0e-6_dp)

  print '(a)', '2. rows below the near join (gap < 0.025)'
  worst = 0.0_dp
  err = 0.0_dp
  do k = 1, resistance_table_size
    xi = resistance_table_sep(k) - 2.0_dp
    if (xi >= near_join_gap * (1.0_dp - 1.0e-9_dp)) exit
    g = near_field_scalars(xi)
    f = resistance_scalars(xi)
    ref = resistance_table_values(k, :)
    print '(a,es9.2,a,es9.2,a,a,a,es9.2,a,a)', '   gap ', xi, ': bare forms ', &
      maxval(near_error(g, ref)), ' (', pair_scalar_names(maxloc(near_error(g, ref), 1)), &
      '), module ', maxval(near_error(f, ref)), ' (', &
      pair_scalar_names(maxloc(near_error(f, ref), 1)) // ')'
    worst = max(worst, maxval(near_error(g, ref)))
    if (xi <= 2.0e-3_dp * (1.0_dp + 1.0e-9_dp)) then
      err = max(err, maxval(near_error(f, ref)))
    else
      h = max(h, maxval(near_error(f, ref)))
    end if
  end do
  call check('(a) bare near-field forms vs near rows', worst, 1.0e-4_dp)
  call check('(b) module vs near rows, gap <= 2e-3', err, 1.0e-3_dp)
  call check('(c) module vs near rows, 5e-3 <= gap <= 0.02', h, 3.0e-2_dp)

  print '(a)', '3. continuity at the joins'
  do k = 1, 2
    if (k == 1) xi = near_join_gap
    if (k == 2) xi = far_join_gap
    h = 1.0e-6_dp * xi
    f = resistance_scalars(xi * (1.0_dp - 1.0e-12_dp))
    g = resistance_scalars(xi * (1.0_dp + 1.0e-12_dp))
    print '(a,f6.3)', '   join at gap ', xi
    call check('value jump', maxval(scaled_error(g, f)), 1.0e-8_dp)
    slope_lo = (resistance_scalars(xi) - resistance_scalars(xi - h)) / h
    slope_hi = (resistance_scalars(xi + h) - resistance_scalars(xi)) / h
    call check('slope jump / max |slope|', &
               maxval(abs(slope_hi - slope_lo)) / maxval(abs(slope_lo)), 1.0e-4_dp)
  end do

  print '(a)', '4. bare far-field series at s = 4.5'
  s = resistance_table_sep(resistance_table_size)
  err = maxval(scaled_error(far_field_scalars(s), resistance_table_values(resistance_table_size, :)))
  print '(a,a)', '   worst scalar of the bare series: ', &
    pair_scalar_names(maxloc(scaled_error(far_field_scalars(s), &
                                          resistance_table_values(resistance_table_size, :)), 1))
  call check('bare truncated far-field series vs table at s = 4.5', err, 1.0e-2_dp)

  print '(a)', '5. isolated-sphere limits at s = 1e4'
  s = 1.0e4_dp
  isolated = 0.0_dp
  isolated([1, 2, 4, 5, 9, 10, 11]) = 1.0_dp
  isolated(i_xa12) = -1.5_dp / s
  isolated(i_ya12) = -0.75_dp / s
  f = resistance_scalars(s - 2.0_dp)
  call check('isolated-sphere limits, max abs error', maxval(abs(f - isolated)), 1.0e-6_dp)

  do j = 1, n_pair_scalars
    if (.not. (abs(f(j)) < huge(1.0_dp))) failures = failures + 1
  end do

  if (failures > 0) then
    print '(i0,a)', failures, ' check(s) FAILED'
    error stop 1
  end if
  print '(a)', 'all checks passed'

contains

  pure elemental function scaled_error(v, vref) result(e)
    real(dp), intent(in) :: v, vref
    real(dp) :: e
    e = abs(v - vref) / max(abs(vref), 1.0e-2_dp)
  end function scaled_error

  pure elemental function near_error(v, vref) result(e)
    real(dp), intent(in) :: v, vref
    real(dp) :: e
    e = abs(v - vref) / max(abs(vref), 0.1_dp)
  end function near_error

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
end program test_resistance_table
