! The 22 exact resistance scalars of two equal spheres (XA..ZM, 11 and 12) at any gap.
!
! Pure Fortran (no PETSc, MPI or HDF5): used by the lubrication correction of the solver (src/)
! and by the independent pair-trajectory oracle bin/pairtraj (ref/). The tensors built from these
! scalars are in mod_resistance_blocks, the free pair's mobility functions in mod_pair_mobility,
! the sphere-wall functions in mod_wall_resistance. Full conventions, join locations and measured
! accuracy: doc/RESISTANCE.md.
!
! Conventions (doc/METHOD.md §5.1; Kim & Karrila 1991 chapter 11; Jeffrey & Onishi 1984;
! Jeffrey 1992):
!   * d is the unit vector from sphere 1 to sphere 2, in every block (11, 12, 21, 22).
!   * gap xi = r/a - 2 (surface gap over radius); separation s = r/a = 2 + xi.
!   * F_a = sum_b [A^ab.(U^inf_b - U_b) + Bt^ab.(Om^inf - Om_b) + Gt^ab : E^inf]
!     T_a = sum_b [B^ab.(U^inf_b - U_b) + C^ab.(Om^inf - Om_b) + Ht^ab : E^inf]
!     S_a = sum_b [G^ab.(U^inf_b - U_b) + H^ab.(Om^inf - Om_b) + M^ab : E^inf]
!     with F, T, S exerted BY the fluid ON sphere a, Bt^ab_ij = B^ba_ji, Gt^ab_ijk = G^ba_jki,
!     Ht^ab_ijk = H^ba_jki (reciprocity: the grand resistance matrix is symmetric).
!   * Tensor forms: A_ij = XA d_i d_j + YA (delta_ij - d_i d_j) (C likewise), B_ij = YB eps_ijk d_k,
!     G_ijk = XG (d_i d_j - delta_ij/3) d_k + YG (d_i delta_jk + d_j delta_ik - 2 d_i d_j d_k),
!     H_ijk = YH (eps_ikl d_l d_j + eps_jkl d_l d_i), M = XM d0 + YM d1 + ZM d2.
!   * Dimensionless scalars as in Kim & Karrila section 11.3: dimensional blocks are the scalars
!     times 6 pi eta a (A), 4 pi eta a^2 (B, G), 8 pi eta a^3 (C, H), (20/3) pi eta a^3 (M).
!   * Equal spheres: f22 = f11 and f21 = f12, except YB, XG, YG for which f22 = -f11 and
!     f21 = -f12 (odd under exchanging the spheres with d fixed).
!   * 12-vectors are ordered (U_1, Om_1, U_2, Om_2) and (F_1, T_1, F_2, T_2).
!
! The 22 scalars (XA..ZM, 11 and 12) at any gap are assembled from three pieces
! (doc/METHOD.md §5.2; doc/RESISTANCE.md for the error budget):
!   1. gap < 0.025: near-field form g1/xi + g2 ln(1/xi) + c + g3 xi ln(1/xi) (Jeffrey & Onishi
!      1984, Jeffrey 1992, corrected by Townsend 2023; constants of doc/METHOD.md §5.2), plus
!      a linear term b xi whose coefficient b = [f_table(0.025) - f_near(0.025)]/0.025 is the
!      form's missing O(xi) term, fitted to the first mid-field (Lamb-method) row. It makes the
!      join continuous in value and slope and tends to the pure asymptotic form at contact.
!      The table rows below s = 2.025 are themselves values of the asymptotic forms (README of
!      input/tables), O(xi) off the exact solution (1.6e-3 for XA11+XA12 at xi = 0.02 against
!      Stimson & Jeffery), so they are not interpolated: including them makes the spline ring.
!   2. 0.025 <= gap <= 2.5: the Lamb-method rows of the table (mod_resistance_table, 26 rows).
!      What is interpolated is the smooth remainder r = f - [g1/xi + g2 ln(1/xi) + g3 xi ln(1/xi)]
!      (the singular part removed), by a C2 cubic spline in ln(xi), clamped at both ends to the
!      slopes of pieces 1 and 3. The spline passes exactly through the rows.
!   3. s > 4.5: far-field series in 1/s (doc/METHOD.md §5.2) plus a tail
!      [f_table(4.5) - f_far(4.5)] (4.5/s)^p, where p is the first power the truncated series
!      omits. It removes the truncation error of the series at s = 4.5 (up to 0.5 %, XG12), making the join
!      continuous in value and slope, and decays like the neglected terms.
module mod_pair_resistance
  use mod_kinds, only: dp
  use mod_resistance_table, only: resistance_table_size, resistance_table_sep, &
                                  resistance_table_values, resistance_series_nmax, &
                                  resistance_series_coef
  implicit none
  private

  ! Scalar indices (column order of mod_resistance_table).
  integer, parameter, public :: n_pair_scalars = 22
  integer, parameter, public :: i_xa11 = 1, i_ya11 = 2, i_yb11 = 3, i_xc11 = 4, i_yc11 = 5, &
                                i_xg11 = 6, i_yg11 = 7, i_yh11 = 8, i_xm11 = 9, i_ym11 = 10, &
                                i_zm11 = 11
  integer, parameter, public :: i_xa12 = 12, i_ya12 = 13, i_yb12 = 14, i_xc12 = 15, i_yc12 = 16, &
                                i_xg12 = 17, i_yg12 = 18, i_yh12 = 19, i_xm12 = 20, i_ym12 = 21, &
                                i_zm12 = 22
  character(len=4), parameter, public :: pair_scalar_names(n_pair_scalars) = [ &
    "XA11", "YA11", "YB11", "XC11", "YC11", "XG11", "YG11", "YH11", "XM11", "YM11", "ZM11", &
    "XA12", "YA12", "YB12", "XC12", "YC12", "XG12", "YG12", "YH12", "XM12", "YM12", "ZM12"]

  ! Join locations (gap xi = s - 2).
  real(dp), parameter, public :: near_join_gap = 0.025_dp    ! first Lamb-method row, s = 2.025
  real(dp), parameter, public :: far_join_gap = 2.5_dp       ! last table row, s = 4.5
  ! Z^M_11 and Z^M_12 join at s = 2.1 instead: the table's Z^M rows at s = 2.025 and 2.05 differ
  ! from the converged series by 2.1e-4 and 7.7e-5 absolute (4.1e-3 and 9e-4 of |Z^M_12|),
  ! at s = 2.1 by 2.2e-5 (2.1e-4 of |Z^M_12|); the series there is converged to < 1e-6 (the same
  ! at nmax = 60, 120, 200) and equals libstokes' independently generated coefficients, so the
  ! module follows the series below s = 2.1 (doc/RESISTANCE.md).
  real(dp), parameter, public :: zm_join_gap = 0.1_dp

  public :: resistance_init, resistance_scalars, near_field_scalars, far_field_scalars, &
            series_scalars, contact_constants, leading_singular_part

  ! Near-field coefficients (doc/METHOD.md §5.2): f = g1/xi + g2 ln(1/xi) + c + g3 xi ln(1/xi).
  real(dp), parameter :: near_g1(n_pair_scalars) = [ &
    0.25_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.375_dp, 0.0_dp, 0.0_dp, 0.15_dp, 0.0_dp, 0.0_dp, &
    -0.25_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, -0.375_dp, 0.0_dp, 0.0_dp, 0.15_dp, 0.0_dp, 0.0_dp]
  real(dp), parameter :: near_g2(n_pair_scalars) = [ &
    9.0_dp/40, 1.0_dp/6, -0.25_dp, 0.0_dp, 0.2_dp, 27.0_dp/80, 0.125_dp, 1.0_dp/40, &
    27.0_dp/200, 3.0_dp/25, 0.0_dp, &
    -9.0_dp/40, -1.0_dp/6, 0.25_dp, 0.0_dp, 0.05_dp, -27.0_dp/80, -0.125_dp, 0.1_dp, &
    27.0_dp/200, 3.0_dp/100, 0.0_dp]
  real(dp), parameter :: near_c(n_pair_scalars) = [ &
    0.995419_dp, 0.998317_dp, 0.238920_dp, 1.051800_dp, 0.702834_dp, -0.469211_dp, &
    -0.141157_dp, -0.074012_dp, 0.716800_dp, 0.884671_dp, 1.025097_dp, &
    -0.350153_dp, -0.273652_dp, -0.001623_dp, -0.150257_dp, -0.027464_dp, 0.195508_dp, &
    0.102501_dp, -0.029290_dp, -0.145424_dp, -0.207581_dp, -0.072311_dp]
  real(dp), parameter :: near_g3(n_pair_scalars) = [ &
    3.0_dp/112, 0.0_dp, -0.125_dp, -0.125_dp, 0.188_dp, 117.0_dp/560, 0.0625_dp, 0.0685_dp, &
    353.0_dp/2800, 0.0228_dp, -0.075_dp, &
    -3.0_dp/112, 0.0_dp, 0.125_dp, 0.125_dp, 0.062_dp, -117.0_dp/560, -0.0625_dp, 0.0565_dp, &
    493.0_dp/2800, 0.1332_dp, 0.075_dp]

  ! Twin-multipole series (Jeffrey & Onishi 1984; Jeffrey 1992; coefficients generated into
  ! mod_resistance_table by scripts/gen_resistance_table.py). Scalar k is
  !   f_k = series_sign(k) * sum_{m = parity(k) mod 2} G_m(family(k)) t^m,   t = 2/s,
  ! evaluated in resummed form (see series_scalars). Family 0 = X^C (exact Jeffery 1915 sums).
  integer, parameter :: series_family(n_pair_scalars) = [ &
    1, 2, 3, 0, 4, 5, 6, 7, 8, 9, 10, 1, 2, 3, 0, 4, 5, 6, 7, 8, 9, 10]
  integer, parameter :: series_parity(n_pair_scalars) = [ &
    0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0, 1, 1, 1, 1]
  real(dp), parameter :: series_sign(n_pair_scalars) = [ &
    1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, -1, -1, -1, 1, 1, -1, -1, 1, 1, 1, -1] * 1.0_dp
  ! Decay power of the (round-off sized) far-join offset term.
  integer, parameter :: far_tail_power = 8
  ! Below this gap X^C uses c + g3 xi ln(1/xi) + b xi, b from the exact sum at this gap.
  real(dp), parameter :: xc_series_min_gap = 1.0e-3_dp

  ! Spline of the remainder r = f - singular part in x = ln(xi), built once on first use.
  logical, save :: spline_ready = .false.
  integer, save :: first_knot = 1                 ! first table row used (s = 2.025)
  real(dp), save :: knot_x(resistance_table_size)
  real(dp), save :: knot_r(resistance_table_size, n_pair_scalars)
  real(dp), save :: knot_r2(resistance_table_size, n_pair_scalars)   ! second derivatives
  real(dp), save :: near_offset(n_pair_scalars)   ! table(join) - series(join)
  real(dp), save :: join_gap(n_pair_scalars)      ! near join of each scalar
  integer, save :: join_knot(n_pair_scalars)      ! its table row
  real(dp), save :: far_offset(n_pair_scalars)    ! table(4.5) - series(4.5)
  ! Residual series coefficients sigma*(G_m - g1 - 2 g2/m + 4 g3/(m(m+2))) (m >= 1, own parity;
  ! entry 0 = sigma G_0 for even scalars) and the X^C O(xi) coefficients (11, 12).
  real(dp), save :: series_res(0:resistance_series_nmax, n_pair_scalars)
  real(dp), save :: xc_lin(2)

  ! Riemann zeta(3): the X^C scalars at contact.
  real(dp), parameter :: zeta3 = 1.2020569031595942_dp

contains

  ! ---------------------------------------------------------------------------------------------
  ! The 22 equal-sphere scalars
  ! ---------------------------------------------------------------------------------------------

  !> All 22 dimensionless scalars (index parameters i_xa11 ... i_zm12) at surface gap
  !> gap = r/a - 2 > 0 (non-positive gaps are evaluated at 1e-300: the caller must keep the gap
  !> positive; lubrication uses the true gap, doc/METHOD.md §4.1).
  function resistance_scalars(gap) result(f)
    real(dp), intent(in) :: gap
    real(dp) :: f(n_pair_scalars)
    real(dp) :: xi, s, g(n_pair_scalars)
    call ensure_spline()
    xi = max(gap, 1.0e-300_dp)
    s = 2.0_dp + xi
    if (xi < near_join_gap) then
      f = series_scalars(xi) + near_offset * (xi / join_gap)
    else if (xi <= far_join_gap) then
      f = singular_part(xi) + spline_remainder(log(xi))
      if (xi < zm_join_gap) then
        g = series_scalars(xi) + near_offset * (xi / join_gap)
        f([i_zm11, i_zm12]) = g([i_zm11, i_zm12])
      end if
    else
      f = series_scalars(xi) + far_offset * (resistance_table_sep(resistance_table_size) / s) &
          ** far_tail_power
    end if
  end function resistance_scalars

  !> Near-field asymptotic forms alone, f = g1/xi + g2 ln(1/xi) + c + g3 xi ln(1/xi)
  !> (doc/METHOD.md §5.2), at gap xi > 0.
  pure function near_field_scalars(gap) result(f)
    real(dp), intent(in) :: gap
    real(dp) :: f(n_pair_scalars)
    f = singular_part(gap) + near_c
  end function near_field_scalars

  !> Far-field values at separation s = r/a: the twin-multipole series (series_scalars), which
  !> at s >= 4.5 (t <= 0.44) is converged to round-off. Kept under this name for the tests.
  function far_field_scalars(sep) result(f)
    real(dp), intent(in) :: sep
    real(dp) :: f(n_pair_scalars)
    f = series_scalars(sep - 2.0_dp)
  end function far_field_scalars

  !> The 22 scalars from the twin-multipole series of Jeffrey & Onishi (1984) and Jeffrey (1992),
  !> resummed so that it holds down to contact (their eqs 3.17-3.23 evaluated at finite s):
  !>   f = h1 S1(t) + h2 S2(t) - h3 S3(t) + sum_{m <= nmax} series_res(m) t^m,   t = 2/(2 + xi),
  !> where h1, h2, h3 are the near-field coefficients (1/xi, ln(1/xi), xi ln(1/xi)) and S1..S3 the
  !> closed-form sums of t^m, (2/m) t^m and 4 t^m/(m(m+2)) over the scalar's parity:
  !>   even: S1 = 4/(xi(4+xi)), S2 = -ln(1-t^2), S3 = 1 + (1-t^2) ln(1-t^2)/t^2;
  !>   odd:  S1 = 2(2+xi)/(xi(4+xi)), S2 = ln((1+t)/(1-t)), S3 = 2/t - (1/t^2 - 1) ln((1+t)/(1-t)).
  !> As nmax -> infinity this is the exact function at every gap; what the truncation leaves is
  !> largest at contact (residual coefficients ~ m^-3, oscillating): measured 9e-6 for the
  !> co-translation X^A_11 + X^A_12 against Stimson & Jeffery, and below 1e-6 for gap >= 0.025
  !> (doc/RESISTANCE.md). X^C uses Jeffery's (1915) exact bispherical sums instead.
  function series_scalars(gap) result(f)
    real(dp), intent(in) :: gap
    real(dp) :: f(n_pair_scalars)
    real(dp) :: xi, t, l1t2, lodd, s_even(3), s_odd(3), p(n_pair_scalars)
    integer :: m, k
    call ensure_spline()
    xi = max(gap, 1.0e-300_dp)
    t = 2.0_dp / (2.0_dp + xi)
    l1t2 = log(xi) + log(4.0_dp + xi) - 2.0_dp * log(2.0_dp + xi)      ! ln(1 - t^2)
    lodd = log((4.0_dp + xi) / xi)                                      ! ln((1+t)/(1-t))
    s_even = [4.0_dp / (xi * (4.0_dp + xi)), -l1t2, 1.0_dp + 0.25_dp * xi * (4.0_dp + xi) * l1t2]
    s_odd = [2.0_dp * (2.0_dp + xi) / (xi * (4.0_dp + xi)), lodd, &
             (2.0_dp + xi) - 0.25_dp * xi * (4.0_dp + xi) * lodd]
    ! Horner in t over the residual series (all 22 columns at once).
    p = series_res(resistance_series_nmax, :)
    do m = resistance_series_nmax - 1, 0, -1
      p = p * t + series_res(m, :)
    end do
    do k = 1, n_pair_scalars
      if (series_parity(k) == 0) then
        f(k) = near_g1(k) * s_even(1) + near_g2(k) * s_even(2) - near_g3(k) * s_even(3) + p(k)
      else
        f(k) = near_g1(k) * s_odd(1) + near_g2(k) * s_odd(2) - near_g3(k) * s_odd(3) + p(k)
      end if
    end do
    call xc_scalars(xi, f(i_xc11), f(i_xc12))
  end function series_scalars

  !> X^C_11 and X^C_12 from Jeffery's (1915) exact bispherical solutions, cosh(alpha) = s/2:
  !> counter-rotation XC11 - XC12 = sum_n (sinh a / sinh n a)^3 (the mid-plane is a no-slip
  !> plane), co-rotation XC11 + XC12 = sum_n (-1)^(n+1) (sinh a / sinh n a)^3. Below gap 1e-3
  !> (where the sums need more than ~400 terms) the inner forms (7/8) zeta(3) - (1/8) xi ln(1/xi)
  !> + b11 xi and -(1/8) zeta(3) + (1/8) xi ln(1/xi) + b12 xi, with b fixed by the exact sums at
  !> 1e-3 (neglected: O(xi^2 ln xi) < 1e-6).
  subroutine xc_scalars(xi, xc11, xc12)
    real(dp), intent(in) :: xi
    real(dp), intent(out) :: xc11, xc12
    real(dp), parameter :: zeta3_local = 1.2020569031595942_dp
    if (xi < xc_series_min_gap) then
      xc11 = 0.875_dp * zeta3_local - 0.125_dp * xi * log(1.0_dp / xi) + xc_lin(1) * xi
      xc12 = -0.125_dp * zeta3_local + 0.125_dp * xi * log(1.0_dp / xi) + xc_lin(2) * xi
    else
      call xc_exact(xi, xc11, xc12)
    end if
  end subroutine xc_scalars

  pure subroutine xc_exact(xi, xc11, xc12)
    real(dp), intent(in) :: xi
    real(dp), intent(out) :: xc11, xc12
    real(dp) :: alpha, term, co, counter, sgn, e2
    integer :: n
    alpha = acosh(1.0_dp + 0.5_dp * xi)
    e2 = 1.0_dp - exp(-2.0_dp * alpha)
    co = 0.0_dp
    counter = 0.0_dp
    sgn = 1.0_dp
    do n = 1, 100000000
      ! (sinh a / sinh(n a))^3 written with exponentials (no overflow at large n a)
      term = (e2 / (1.0_dp - exp(-2.0_dp * n * alpha)))**3 * exp(-3.0_dp * (n - 1) * alpha)
      counter = counter + term
      co = co + sgn * term
      sgn = -sgn
      if (term < 1.0e-17_dp) exit
    end do
    xc11 = 0.5_dp * (co + counter)
    xc12 = 0.5_dp * (co - counter)
  end subroutine xc_exact

  !> O(1) constants of the 22 near-contact forms as given by the resummed series (t -> 1):
  !> c = sum_m series_res(m) + h1 c1 + h2 c2 - h3 c3 with (c1, c2, c3) = (-1/4, 0, 1) (even
  !> scalars) or (1/4, ln 4, 2) (odd). X^C: (7/8) zeta(3), -(1/8) zeta(3).
  function contact_constants() result(c)
    real(dp) :: c(n_pair_scalars)
    integer :: k
    call ensure_spline()
    do k = 1, n_pair_scalars
      if (series_parity(k) == 0) then
        c(k) = sum(series_res(:, k)) - 0.25_dp * near_g1(k) - near_g3(k)
      else
        c(k) = sum(series_res(:, k)) + 0.25_dp * near_g1(k) + near_g2(k) * log(4.0_dp) &
               - 2.0_dp * near_g3(k)
      end if
    end do
    c(i_xc11) = 0.875_dp * zeta3
    c(i_xc12) = -0.125_dp * zeta3
  end function contact_constants

  !> The singular (and xi ln xi) part of the near-field form, without the constant c.
  pure function singular_part(xi) result(f)
    real(dp), intent(in) :: xi
    real(dp) :: f(n_pair_scalars)
    real(dp) :: log_inv
    log_inv = log(1.0_dp / xi)
    f = near_g1 / xi + near_g2 * log_inv + near_g3 * xi * log_inv
  end function singular_part

  !> The lubrication singularities alone, g1/xi + g2 ln(1/xi) (doc/METHOD.md §5.2): what the 'simple'
  !> lubrication model corrects with.
  pure function leading_singular_part(xi) result(f)
    real(dp), intent(in) :: xi
    real(dp) :: f(n_pair_scalars)
    f = near_g1 / xi + near_g2 * log(1.0_dp / xi)
  end function leading_singular_part

  !> Build the interpolation data now (otherwise done on the first call of resistance_scalars).
  !> Call it once before any threaded region: the data are saved module state.
  subroutine resistance_init()
    call ensure_spline()
  end subroutine resistance_init

  !> Build the clamped cubic splines of the remainder (once). Recursive: it evaluates series_scalars,
  !> which calls it back and returns at once (spline_ready is set before).
  recursive subroutine ensure_spline()
    integer :: k, nt, k0, m, fam
    real(dp) :: xin, s_end, slope_lo(n_pair_scalars), slope_hi(n_pair_scalars), g(3), sig, mm, h
    real(dp) :: x11, x12, f0(n_pair_scalars), fp(n_pair_scalars), fm(n_pair_scalars)
    if (spline_ready) return
    ! Residual series coefficients (needed by series_scalars, which the rest below calls).
    series_res = 0.0_dp
    do k = 1, n_pair_scalars
      fam = series_family(k)
      if (fam == 0) cycle
      sig = series_sign(k)
      g = sig * [near_g1(k), near_g2(k), near_g3(k)]
      if (series_parity(k) == 0) series_res(0, k) = sig * resistance_series_coef(0, fam)
      do m = 1, resistance_series_nmax
        if (mod(m, 2) /= series_parity(k)) cycle
        mm = real(m, dp)
        series_res(m, k) = sig * (resistance_series_coef(m, fam) - g(1) - 2.0_dp * g(2) / mm &
                                  + 4.0_dp * g(3) / (mm * (mm + 2.0_dp)))
      end do
    end do
    call xc_exact(xc_series_min_gap, x11, x12)
    xc_lin(1) = (x11 - 0.875_dp * zeta3 + 0.125_dp * xc_series_min_gap * log(1.0_dp / xc_series_min_gap)) &
                / xc_series_min_gap
    xc_lin(2) = (x12 + 0.125_dp * zeta3 - 0.125_dp * xc_series_min_gap * log(1.0_dp / xc_series_min_gap)) &
                / xc_series_min_gap
    spline_ready = .true.   ! series_scalars is usable from here on

    nt = resistance_table_size
    join_gap = near_join_gap
    join_gap([i_zm11, i_zm12]) = zm_join_gap
    do k = 1, n_pair_scalars
      k0 = 1
      do while (resistance_table_sep(k0) - 2.0_dp < join_gap(k) * (1.0_dp - 1.0e-9_dp))
        k0 = k0 + 1
      end do
      join_knot(k) = k0
    end do
    first_knot = minval(join_knot)
    knot_x = log(resistance_table_sep - 2.0_dp)
    xin = resistance_table_sep(nt) - 2.0_dp
    s_end = resistance_table_sep(nt)
    do k = 1, nt
      knot_r(k, :) = resistance_table_values(k, :) - singular_part(resistance_table_sep(k) - 2.0_dp)
    end do
    ! End slopes d r / d ln(xi) of the neighbouring pieces (central differences in ln xi, step
    ! 1e-4: error ~1e-8 of the slope). Below the near join f = series + near_offset xi/xi_j, whose
    ! remainder slope is that of (series - singular part) plus near_offset. Above the table
    ! f = series + far_offset (s_end/s)^p.
    h = 1.0e-4_dp
    do k = 1, n_pair_scalars
      k0 = join_knot(k)
      f0 = series_scalars(join_gap(k))
      near_offset(k) = resistance_table_values(k0, k) - f0(k)
      fp = series_scalars(join_gap(k) * exp(h)) - singular_part(join_gap(k) * exp(h))
      fm = series_scalars(join_gap(k) * exp(-h)) - singular_part(join_gap(k) * exp(-h))
      slope_lo(k) = (fp(k) - fm(k)) / (2.0_dp * h) + near_offset(k)
    end do
    far_offset = resistance_table_values(nt, :) - series_scalars(xin)
    slope_hi = (series_scalars(xin * exp(h)) - singular_part(xin * exp(h)) &
                - series_scalars(xin * exp(-h)) + singular_part(xin * exp(-h))) / (2.0_dp * h) &
               - xin * far_offset * far_tail_power / s_end
    knot_r2 = 0.0_dp
    do k = 1, n_pair_scalars
      k0 = join_knot(k)
      call clamped_spline(knot_x(k0:nt), knot_r(k0:nt, k), slope_lo(k), slope_hi(k), &
                          knot_r2(k0:nt, k))
    end do
    spline_ready = .true.
  end subroutine ensure_spline

  !> Second derivatives of the clamped cubic spline through (x, y) (tridiagonal solve).
  pure subroutine clamped_spline(x, y, slope_first, slope_last, y2)
    real(dp), intent(in) :: x(:), y(:), slope_first, slope_last
    real(dp), intent(out) :: y2(:)
    real(dp) :: sub(size(x)), diag(size(x)), sup(size(x)), rhs(size(x)), w
    integer :: n, i
    n = size(x)
    diag(1) = (x(2) - x(1)) / 3.0_dp
    sup(1) = (x(2) - x(1)) / 6.0_dp
    sub(1) = 0.0_dp
    rhs(1) = (y(2) - y(1)) / (x(2) - x(1)) - slope_first
    do i = 2, n - 1
      sub(i) = (x(i) - x(i - 1)) / 6.0_dp
      diag(i) = (x(i + 1) - x(i - 1)) / 3.0_dp
      sup(i) = (x(i + 1) - x(i)) / 6.0_dp
      rhs(i) = (y(i + 1) - y(i)) / (x(i + 1) - x(i)) - (y(i) - y(i - 1)) / (x(i) - x(i - 1))
    end do
    sub(n) = (x(n) - x(n - 1)) / 6.0_dp
    diag(n) = (x(n) - x(n - 1)) / 3.0_dp
    sup(n) = 0.0_dp
    rhs(n) = slope_last - (y(n) - y(n - 1)) / (x(n) - x(n - 1))
    ! Thomas algorithm (diagonally dominant).
    do i = 2, n
      w = sub(i) / diag(i - 1)
      diag(i) = diag(i) - w * sup(i - 1)
      rhs(i) = rhs(i) - w * rhs(i - 1)
    end do
    y2(n) = rhs(n) / diag(n)
    do i = n - 1, 1, -1
      y2(i) = (rhs(i) - sup(i) * y2(i + 1)) / diag(i)
    end do
  end subroutine clamped_spline

  !> Spline remainder of all 22 scalars at x = ln(xi) inside the table.
  function spline_remainder(x) result(r)
    real(dp), intent(in) :: x
    real(dp) :: r(n_pair_scalars)
    integer :: lo, hi, mid
    real(dp) :: h, a, b
    lo = first_knot
    hi = resistance_table_size
    do while (hi - lo > 1)
      mid = (lo + hi) / 2
      if (knot_x(mid) > x) then
        hi = mid
      else
        lo = mid
      end if
    end do
    h = knot_x(hi) - knot_x(lo)
    a = (knot_x(hi) - x) / h
    b = 1.0_dp - a
    r = a * knot_r(lo, :) + b * knot_r(hi, :) &
        + ((a**3 - a) * knot_r2(lo, :) + (b**3 - b) * knot_r2(hi, :)) * h**2 / 6.0_dp
  end function spline_remainder

end module mod_pair_resistance
