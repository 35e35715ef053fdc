! Exact hydrodynamic resistance of two equal spheres and of a sphere near a plane wall.
!
! Pure Fortran (no PETSc, MPI or HDF5): used by the lubrication correction of the solver (src/)
! and by the independent pair-trajectory oracle bin/pairtraj (ref/). Full conventions, join
! locations and measured accuracy: doc/RESISTANCE.md.
!
! Conventions (method.md section 2.1; Kim & Karrila 1991 chapter 11; Jeffrey & Onishi 1984;
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
! (method.md sections 2.3, 3.1, 3.2; doc/RESISTANCE.md for the error budget):
!   1. gap < 0.025: near-field form g1/xi + g2 ln(1/xi) + c + g3 xi ln(1/xi) (Jeffrey & Onishi
!      1984, Jeffrey 1992, corrected by Townsend 2023; constants of method.md section 3.1), plus
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
!   3. s > 4.5: far-field series in 1/s (method.md section 3.2) plus a tail
!      [f_table(4.5) - f_far(4.5)] (4.5/s)^p, where p is the first power the truncated series
!      omits. It removes the truncation error of the series at s = 4.5 (up to 0.5 %, XG12), making the join
!      continuous in value and slope, and decays like the neglected terms.
module mod_resistance
  use mod_kinds, only: dp, pi
  use mod_vector, only: cross
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
  public :: pair_shear_functions
  public :: pair_resistance_fu, pair_resistance_fe, pair_resistance_su, pair_resistance_se
  public :: pair_force_torque_from_strain, pair_stresslets
  public :: strain_d0, strain_d1, strain_d2
  public :: wall_normal_resistance, wall_normal_near_field, wall_normal_far_field
  public :: wall_tangential_resistance, wall_twist_resistance, wall_resistance_fu, &
            wall_resistance_block, wall_tangential_exact, wall_tangential_inner, wall_tangential_far

  ! Exchange sign of each base scalar: f22 = sgn f11, f21 = sgn f12 (method.md section 2.1).
  real(dp), parameter :: exchange_sign(11) = [1, 1, -1, 1, 1, -1, -1, 1, 1, 1, 1] * 1.0_dp

  ! Near-field coefficients (method.md section 3.1): f = g1/xi + g2 ln(1/xi) + c + g3 xi ln(1/xi).
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

  ! Sphere-wall joins (method.md section 2.8; doc/RESISTANCE.md).
  real(dp), parameter :: wall_normal_series_min_gap = 1.0e-2_dp   ! below: Cox-Brenner form
  real(dp), parameter :: wall_tangential_exact_lo = 1.0e-3_dp, wall_tangential_exact_hi = 10.0_dp
  real(dp), parameter :: zeta3 = 1.2020569031595942_dp

contains

  ! ---------------------------------------------------------------------------------------------
  ! The 22 equal-sphere scalars
  ! ---------------------------------------------------------------------------------------------

  !> All 22 dimensionless scalars (index parameters i_xa11 ... i_zm12) at surface gap
  !> gap = r/a - 2 > 0 (non-positive gaps are evaluated at 1e-300: the caller must keep the gap
  !> positive; lubrication uses the true gap, method.md section 1.7).
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
  !> (method.md section 3.1), at gap xi > 0.
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

  !> The lubrication singularities alone, g1/xi + g2 ln(1/xi) (method.md 3.1): what the 'simple'
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

  !> Build the clamped cubic splines of the remainder (once).
  subroutine ensure_spline()
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

  ! ---------------------------------------------------------------------------------------------
  ! Force- and torque-free pair in a linear flow (Batchelor & Green 1972; method.md section 4.2)
  ! ---------------------------------------------------------------------------------------------

  !> Mobility and stresslet functions of a force- and torque-free equal pair at gap xi:
  !>   dr/dt = Om x r + E.r - [A dd + B (I - dd)].E.r,   Om_pair = Om^inf + c d x (E.d),
  !>   S = (20/3) pi eta a^3 [(1+K) E + L (d(E.d) + (E.d)d - (2/3) I d.E.d) + M (dd - I/3) d.E.d].
  !> Derived from the six-unknown reduction of method.md section 4.1 (doc/RESISTANCE.md).
  subroutine pair_shear_functions(gap, a_bg, b_bg, c_rot, k_bg, l_bg, m_bg)
    real(dp), intent(in) :: gap
    real(dp), intent(out) :: a_bg, b_bg, c_rot, k_bg, l_bg, m_bg
    real(dp) :: f(n_pair_scalars), s, xa, ya, yb, xg, yg, ycp, yhp, xmp, ymp, zmp, beta_u
    f = resistance_scalars(gap)
    s = 2.0_dp + gap
    xa = f(i_xa11) - f(i_xa12)
    ya = f(i_ya11) - f(i_ya12)
    yb = f(i_yb11) - f(i_yb12)
    xg = f(i_xg11) - f(i_xg12)
    yg = f(i_yg11) - f(i_yg12)
    ycp = f(i_yc11) + f(i_yc12)
    yhp = f(i_yh11) + f(i_yh12)
    xmp = f(i_xm11) + f(i_xm12)
    ymp = f(i_ym11) + f(i_ym12)
    zmp = f(i_zm11) + f(i_zm12)
    a_bg = 4.0_dp * xg / (3.0_dp * s * xa)
    beta_u = (8.0_dp * yg + 8.0_dp * yb * yhp / ycp) / (6.0_dp * ya - 2.0_dp * yb**2 / ycp)
    c_rot = (yb * beta_u + 4.0_dp * yhp) / (2.0_dp * ycp)
    b_bg = 2.0_dp * beta_u / s
    k_bg = zmp - 1.0_dp
    l_bg = ymp - zmp - 0.6_dp * yg * beta_u - 1.2_dp * yhp * c_rot
    m_bg = 1.5_dp * xmp - 2.0_dp * ymp + 0.5_dp * zmp - 0.4_dp * xg**2 / xa + 1.2_dp * yg * beta_u &
           + 2.4_dp * yhp * c_rot
  end subroutine pair_shear_functions

  ! ---------------------------------------------------------------------------------------------
  ! Pair resistance blocks (method.md sections 2.1 and 2.6)
  ! ---------------------------------------------------------------------------------------------

  !> Scalar of base index k (1..11) for the block (alpha, beta), from f(22) = (11-scalars, 12-scalars).
  pure function block_scalar(f, k, alpha, beta) result(v)
    real(dp), intent(in) :: f(n_pair_scalars)
    integer, intent(in) :: k, alpha, beta
    real(dp) :: v
    if (alpha == beta) then
      v = f(k)
      if (alpha == 2) v = exchange_sign(k) * v
    else
      v = f(k + 11)
      if (alpha == 2) v = exchange_sign(k) * v
    end if
  end function block_scalar

  pure function levi_civita(i, j, k) result(e)
    integer, intent(in) :: i, j, k
    real(dp) :: e
    e = real((i - j) * (j - k) * (k - i), dp) / 2.0_dp
  end function levi_civita

  pure function kron(i, j) result(v)
    integer, intent(in) :: i, j
    real(dp) :: v
    v = merge(1.0_dp, 0.0_dp, i == j)
  end function kron

  !> Third-rank G tensor (K&K 11.2): G_ijk = XG (d_i d_j - delta_ij/3) d_k
  !> + YG (d_i delta_jk + d_j delta_ik - 2 d_i d_j d_k).
  pure function g_tensor(xg, yg, d) result(g)
    real(dp), intent(in) :: xg, yg, d(3)
    real(dp) :: g(3, 3, 3)
    integer :: i, j, k
    do k = 1, 3
      do j = 1, 3
        do i = 1, 3
          g(i, j, k) = xg * (d(i) * d(j) - kron(i, j) / 3.0_dp) * d(k) &
                       + yg * (d(i) * kron(j, k) + d(j) * kron(i, k) - 2.0_dp * d(i) * d(j) * d(k))
        end do
      end do
    end do
  end function g_tensor

  !> Third-rank H tensor: H_ijk = YH (eps_ikl d_l d_j + eps_jkl d_l d_i).
  pure function h_tensor(yh, d) result(h)
    real(dp), intent(in) :: yh, d(3)
    real(dp) :: h(3, 3, 3)
    integer :: i, j, k, l
    h = 0.0_dp
    do k = 1, 3
      do j = 1, 3
        do i = 1, 3
          do l = 1, 3
            h(i, j, k) = h(i, j, k) + yh * (levi_civita(i, k, l) * d(l) * d(j) &
                                            + levi_civita(j, k, l) * d(l) * d(i))
          end do
        end do
      end do
    end do
  end function h_tensor

  !> Fourth-rank M tensor, M = XM d0 + YM d1 + ZM d2 (K&K 11.2; Jeffrey 1992).
  pure function m_tensor(xm, ym, zm, d) result(m)
    real(dp), intent(in) :: xm, ym, zm, d(3)
    real(dp) :: m(3, 3, 3, 3)
    integer :: i, j, k, l
    real(dp) :: d0, d1, d2
    do l = 1, 3
      do k = 1, 3
        do j = 1, 3
          do i = 1, 3
            d0 = 1.5_dp * (d(i) * d(j) - kron(i, j) / 3.0_dp) * (d(k) * d(l) - kron(k, l) / 3.0_dp)
            d1 = 0.5_dp * (d(i) * kron(j, l) * d(k) + d(j) * kron(i, l) * d(k) &
                           + d(i) * kron(j, k) * d(l) + d(j) * kron(i, k) * d(l) &
                           - 4.0_dp * d(i) * d(j) * d(k) * d(l))
            d2 = 0.5_dp * (kron(i, k) * kron(j, l) + kron(j, k) * kron(i, l) - kron(i, j) * kron(k, l) &
                           + d(i) * d(j) * kron(k, l) + kron(i, j) * d(k) * d(l) &
                           + d(i) * d(j) * d(k) * d(l) &
                           - d(i) * kron(j, l) * d(k) - d(j) * kron(i, l) * d(k) &
                           - d(i) * kron(j, k) * d(l) - d(j) * kron(i, k) * d(l))
            m(i, j, k, l) = xm * d0 + ym * d1 + zm * d2
          end do
        end do
      end do
    end do
  end function m_tensor

  !> 12x12 resistance R_FU: (F_1, T_1, F_2, T_2) = R_FU . (U^inf_1 - U_1, Om^inf - Om_1,
  !> U^inf_2 - U_2, Om^inf - Om_2). f(22) are the scalars (theory, or theory minus numerics for
  !> the subgrid correction); d is the unit vector from sphere 1 to sphere 2.
  pure function pair_resistance_fu(f, d, radius, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), radius, viscosity
    real(dp) :: r(12, 12)
    integer :: alpha, beta, i, j, k, ro, co
    real(dp) :: xa, ya, yb, xc, yc, ca, cb, cc, bij
    ca = 6.0_dp * pi * viscosity * radius
    cb = 4.0_dp * pi * viscosity * radius**2
    cc = 8.0_dp * pi * viscosity * radius**3
    r = 0.0_dp
    do alpha = 1, 2
      do beta = 1, 2
        ro = 6 * (alpha - 1)
        co = 6 * (beta - 1)
        xa = block_scalar(f, i_xa11, alpha, beta)
        ya = block_scalar(f, i_ya11, alpha, beta)
        yb = block_scalar(f, i_yb11, alpha, beta)
        xc = block_scalar(f, i_xc11, alpha, beta)
        yc = block_scalar(f, i_yc11, alpha, beta)
        do j = 1, 3
          do i = 1, 3
            r(ro + i, co + j) = ca * (xa * d(i) * d(j) + ya * (kron(i, j) - d(i) * d(j)))
            r(ro + 3 + i, co + 3 + j) = cc * (xc * d(i) * d(j) + yc * (kron(i, j) - d(i) * d(j)))
            bij = 0.0_dp
            do k = 1, 3
              bij = bij + levi_civita(i, j, k) * d(k)
            end do
            ! T_alpha <- U_beta: B^ab ; F_beta <- Om_alpha: Bt^ba_ji = B^ab_ij (transpose).
            r(ro + 3 + i, co + j) = cb * yb * bij
            r(co + j, ro + 3 + i) = cb * yb * bij
          end do
        end do
      end do
    end do
  end function pair_resistance_fu

  !> R_FE as a 12x3x3 array: (F_1, T_1, F_2, T_2)_m = sum_jk r(m, j, k) E_jk.
  pure function pair_resistance_fe(f, d, radius, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), radius, viscosity
    real(dp) :: r(12, 3, 3)
    real(dp) :: g(3, 3, 3), h(3, 3, 3), cg, ch
    integer :: alpha, beta, i, j, k
    cg = 4.0_dp * pi * viscosity * radius**2
    ch = 8.0_dp * pi * viscosity * radius**3
    r = 0.0_dp
    do alpha = 1, 2
      do beta = 1, 2
        ! Gt^ab_ijk = G^ba_jki: force on alpha from the stresslet response of beta.
        g = g_tensor(block_scalar(f, i_xg11, beta, alpha), block_scalar(f, i_yg11, beta, alpha), d)
        h = h_tensor(block_scalar(f, i_yh11, beta, alpha), d)
        do k = 1, 3
          do j = 1, 3
            do i = 1, 3
              r(6 * (alpha - 1) + i, j, k) = r(6 * (alpha - 1) + i, j, k) + cg * g(j, k, i)
              r(6 * (alpha - 1) + 3 + i, j, k) = r(6 * (alpha - 1) + 3 + i, j, k) + ch * h(j, k, i)
            end do
          end do
        end do
      end do
    end do
  end function pair_resistance_fe

  !> R_SU as a 3x3x2x12 array: S_alpha,ij = sum_m r(i, j, alpha, m) w_m, with
  !> w = (U^inf_1 - U_1, Om^inf - Om_1, U^inf_2 - U_2, Om^inf - Om_2).
  pure function pair_resistance_su(f, d, radius, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), radius, viscosity
    real(dp) :: r(3, 3, 2, 12)
    real(dp) :: g(3, 3, 3), h(3, 3, 3), cg, ch
    integer :: alpha, beta, k
    cg = 4.0_dp * pi * viscosity * radius**2
    ch = 8.0_dp * pi * viscosity * radius**3
    do alpha = 1, 2
      do beta = 1, 2
        g = g_tensor(block_scalar(f, i_xg11, alpha, beta), block_scalar(f, i_yg11, alpha, beta), d)
        h = h_tensor(block_scalar(f, i_yh11, alpha, beta), d)
        do k = 1, 3
          r(:, :, alpha, 6 * (beta - 1) + k) = cg * g(:, :, k)
          r(:, :, alpha, 6 * (beta - 1) + 3 + k) = ch * h(:, :, k)
        end do
      end do
    end do
  end function pair_resistance_su

  !> R_SE as a 3x3x2x3x3 array: S_alpha,ij = sum_kl r(i, j, alpha, k, l) E_kl.
  pure function pair_resistance_se(f, d, radius, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), radius, viscosity
    real(dp) :: r(3, 3, 2, 3, 3)
    real(dp) :: cm
    integer :: alpha
    cm = 20.0_dp / 3.0_dp * pi * viscosity * radius**3
    do alpha = 1, 2
      ! Sum over beta of M^ab (M scalars are even under exchange: M^a1 + M^a2 = M11 + M12).
      r(:, :, alpha, :, :) = cm * m_tensor(f(i_xm11) + f(i_xm12), f(i_ym11) + f(i_ym12), &
                                           f(i_zm11) + f(i_zm12), d)
    end do
  end function pair_resistance_se

  !> Contractions of the three M basis tensors with a symmetric traceless E (method.md 2.1).
  pure function strain_d0(d, e) result(c)
    real(dp), intent(in) :: d(3), e(3, 3)
    real(dp) :: c(3, 3)
    integer :: i, j
    real(dp) :: ded
    ded = dot_product(d, matmul(e, d))
    do j = 1, 3
      do i = 1, 3
        c(i, j) = 1.5_dp * (d(i) * d(j) - kron(i, j) / 3.0_dp) * ded
      end do
    end do
  end function strain_d0

  pure function strain_d1(d, e) result(c)
    real(dp), intent(in) :: d(3), e(3, 3)
    real(dp) :: c(3, 3), ed(3), ded
    integer :: i, j
    ed = matmul(e, d)
    ded = dot_product(d, ed)
    do j = 1, 3
      do i = 1, 3
        c(i, j) = d(i) * ed(j) + ed(i) * d(j) - 2.0_dp * d(i) * d(j) * ded
      end do
    end do
  end function strain_d1

  pure function strain_d2(d, e) result(c)
    real(dp), intent(in) :: d(3), e(3, 3)
    real(dp) :: c(3, 3), ed(3), ded
    integer :: i, j
    ed = matmul(e, d)
    ded = dot_product(d, ed)
    do j = 1, 3
      do i = 1, 3
        c(i, j) = e(i, j) + 0.5_dp * (kron(i, j) + d(i) * d(j)) * ded - d(i) * ed(j) - ed(i) * d(j)
      end do
    end do
  end function strain_d2

  !> (F_1, T_1, F_2, T_2) from the strain alone, R_FE : E, written out (method.md section 2.6).
  pure function pair_force_torque_from_strain(f, d, e, radius, viscosity) result(ft)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), e(3, 3), radius, viscosity
    real(dp) :: ft(12)
    real(dp) :: ed(3), ded, fvec(3), tvec(3), cg, ch
    cg = 4.0_dp * pi * viscosity * radius**2
    ch = 8.0_dp * pi * viscosity * radius**3
    ed = matmul(e, d)
    ded = dot_product(d, ed)
    fvec = cg * ((f(i_xg11) - f(i_xg12)) * ded * d + 2.0_dp * (f(i_yg11) - f(i_yg12)) * (ed - ded * d))
    tvec = 2.0_dp * ch * (f(i_yh11) + f(i_yh12)) * cross(d, ed)
    ft(1:3) = fvec
    ft(4:6) = tvec
    ft(7:9) = -fvec
    ft(10:12) = tvec
  end function pair_force_torque_from_strain

  !> Stresslets S_1, S_2 (3x3x2) from w = (U^inf_1 - U_1, Om^inf - Om_1, U^inf_2 - U_2,
  !> Om^inf - Om_2) and E, written out (method.md section 2.6).
  pure function pair_stresslets(f, d, w, e, radius, viscosity) result(s)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), w(12), e(3, 3), radius, viscosity
    real(dp) :: s(3, 3, 2)
    real(dp) :: cg, ch, cm, wb(3), wperp(3), od(3), me(3, 3), xg, yg, yh
    integer :: alpha, beta, i, j
    cg = 4.0_dp * pi * viscosity * radius**2
    ch = 8.0_dp * pi * viscosity * radius**3
    cm = 20.0_dp / 3.0_dp * pi * viscosity * radius**3
    me = cm * ((f(i_xm11) + f(i_xm12)) * strain_d0(d, e) + (f(i_ym11) + f(i_ym12)) * strain_d1(d, e) &
               + (f(i_zm11) + f(i_zm12)) * strain_d2(d, e))
    do alpha = 1, 2
      s(:, :, alpha) = me
      do beta = 1, 2
        xg = block_scalar(f, i_xg11, alpha, beta)
        yg = block_scalar(f, i_yg11, alpha, beta)
        yh = block_scalar(f, i_yh11, alpha, beta)
        wb = w(6 * (beta - 1) + 1:6 * (beta - 1) + 3)
        wperp = wb - dot_product(d, wb) * d
        od = cross(w(6 * (beta - 1) + 4:6 * (beta - 1) + 6), d)
        do j = 1, 3
          do i = 1, 3
            s(i, j, alpha) = s(i, j, alpha) &
              + cg * (xg * (d(i) * d(j) - kron(i, j) / 3.0_dp) * dot_product(d, wb) &
                      + yg * (d(i) * wperp(j) + wperp(i) * d(j))) &
              + ch * yh * (od(i) * d(j) + d(i) * od(j))
          end do
        end do
      end do
    end do
  end function pair_stresslets

  ! ---------------------------------------------------------------------------------------------
  ! Sphere - plane wall (method.md section 2.8)
  ! ---------------------------------------------------------------------------------------------

  !> Normal resistance lambda_perp = F / (6 pi eta a U) of a sphere moving along the wall normal,
  !> at gap eps = (centre height - a)/a. Brenner's (1961) exact bispherical series for
  !> eps >= 1e-2; the Cox & Brenner (1967) inner form below (doc/RESISTANCE.md).
  function wall_normal_resistance(gap) result(lam)
    real(dp), intent(in) :: gap
    real(dp) :: lam
    if (gap < wall_normal_series_min_gap) then
      lam = wall_normal_near_field(gap)
    else
      lam = brenner_wall_series(gap)
    end if
  end function wall_normal_resistance

  !> Cox & Brenner (1967): 1/eps + (1/5) ln(1/eps) + 0.9713 + (1/21) eps ln(1/eps).
  pure function wall_normal_near_field(gap) result(lam)
    real(dp), intent(in) :: gap
    real(dp) :: lam, eps
    eps = max(gap, 1.0e-300_dp)
    lam = 1.0_dp / eps + 0.2_dp * log(1.0_dp / eps) + 0.9713_dp + eps * log(1.0_dp / eps) / 21.0_dp
  end function wall_normal_near_field

  !> Far-field reflection form 1/(1 - 9x/8 + x^3/2 - 0.57 x^4 + 0.2 x^5), x = a/l (method.md 2.8).
  pure function wall_normal_far_field(gap) result(lam)
    real(dp), intent(in) :: gap
    real(dp) :: lam, x
    x = 1.0_dp / (1.0_dp + gap)
    lam = 1.0_dp / (1.0_dp - 1.125_dp * x + 0.5_dp * x**3 - 0.57_dp * x**4 + 0.2_dp * x**5)
  end function wall_normal_far_field

  !> Brenner (1961), rigid plane: with cosh(alpha) = l/a,
  !> lambda = (4/3) sinh(alpha) sum_{n>=1} n(n+1)/((2n-1)(2n+3))
  !>          [ (2 sinh((2n+1)alpha) + (2n+1) sinh(2 alpha))
  !>            / (4 sinh^2((n+1/2)alpha) - (2n+1)^2 sinh^2(alpha)) - 1 ].
  !> Written with exp(-(2n+1)alpha) scaling so that no term overflows.
  pure function brenner_wall_series(gap) result(lam)
    real(dp), intent(in) :: gap
    real(dp) :: lam, alpha, sh, term, q, num, den, m
    integer :: n
    alpha = acosh(1.0_dp + gap)
    sh = sinh(alpha)
    lam = 0.0_dp
    do n = 1, 200000
      m = real(2 * n + 1, dp)
      q = exp(-m * alpha)
      ! num and den both divided by exp(m alpha)/... : 2 sinh(m a) = e^{ma}(1 - q^2),
      ! 4 sinh^2(m a/2) = e^{ma}(1 - q)^2.
      num = (1.0_dp - q * q) + m * sinh(2.0_dp * alpha) * q
      den = (1.0_dp - q)**2 - m**2 * sh**2 * q
      term = real(n * (n + 1), dp) / ((m - 2.0_dp) * (m + 2.0_dp)) * (num / den - 1.0_dp)
      lam = lam + term
      if (abs(term) < 1.0e-16_dp * abs(lam) .and. m * alpha > 10.0_dp) exit
    end do
    lam = 4.0_dp / 3.0_dp * sh * lam
  end function brenner_wall_series

  !> Tangential sphere-wall functions at gap eps (method.md section 2.8): with s the sphere velocity
  !> relative to the wall along t and Om_b the rotation about b = n x t,
  !>   F_t = -6 pi eta a [f_tt s - f_tr a Om_b],  T_b = -6 pi eta a^2 [-f_tr s + (4/3) f_rr a Om_b].
  !> 1e-3 <= eps <= 10: the exact bispherical solutions, O'Neill (1964) for translation and Dean &
  !> O'Neill (1963) for rotation (wall_tangential_exact). eps < 1e-3: the inner forms of O'Neill &
  !> Stewartson (1967) / Goldman, Cox & Brenner (1967) with Dance & Maxey's eps ln eps terms, plus
  !> [exact - inner](1e-3) * eps/1e-3 (continuous, -> the inner forms at contact). eps > 10: the
  !> Faxen / GCB reflection forms plus [exact - far](10) * (11 a/l)^6 (they differ by < 1e-5 there).
  subroutine wall_tangential_resistance(gap, f_tt, f_tr, f_rr)
    real(dp), intent(in) :: gap
    real(dp), intent(out) :: f_tt, f_tr, f_rr
    real(dp) :: eps, v(3), ex(3), w
    eps = max(gap, 1.0e-300_dp)
    if (eps < wall_tangential_exact_lo) then
      call wall_tangential_exact(wall_tangential_exact_lo, ex(1), ex(2), ex(3))
      v = wall_tangential_inner(eps) + (ex - wall_tangential_inner(wall_tangential_exact_lo)) &
          * (eps / wall_tangential_exact_lo)
    else if (eps <= wall_tangential_exact_hi) then
      call wall_tangential_exact(eps, v(1), v(2), v(3))
    else
      call wall_tangential_exact(wall_tangential_exact_hi, ex(1), ex(2), ex(3))
      w = ((1.0_dp + wall_tangential_exact_hi) / (1.0_dp + eps))**6
      v = wall_tangential_far(eps) + (ex - wall_tangential_far(wall_tangential_exact_hi)) * w
    end if
    f_tt = v(1)
    f_tr = v(2)
    f_rr = v(3)
  end subroutine wall_tangential_resistance

  !> Inner forms (f_tt, f_tr, f_rr) of the tangential functions (method.md 2.8).
  pure function wall_tangential_inner(eps) result(v)
    real(dp), intent(in) :: eps
    real(dp) :: v(3), li
    li = log(1.0_dp / eps)
    v = [8.0_dp / 15 * li + 0.9588_dp + 64.0_dp / 375 * eps * li, &
         2.0_dp / 15 * li - 0.2526_dp + 86.0_dp / 375 * eps * li, &
         0.4_dp * li + 0.3817_dp + 66.0_dp / 125 * eps * li]
  end function wall_tangential_inner

  !> Far (reflection) forms: Faxen's f_tt, GCB's f_tr and f_rr, x = a/l.
  pure function wall_tangential_far(eps) result(v)
    real(dp), intent(in) :: eps
    real(dp) :: v(3), x
    x = 1.0_dp / (1.0_dp + eps)
    v = [1.0_dp / (1.0_dp - 9.0_dp / 16 * x + x**3 / 8 - 45.0_dp / 256 * x**4 - x**5 / 16), &
         x**4 / 8 * (1.0_dp - 3.0_dp / 8 * x), &
         1.0_dp + 5.0_dp / 16 * x**3]
  end function wall_tangential_far

  !> Exact tangential functions from the bispherical-coordinate solutions, cosh(alpha) = l/a:
  !> translation parallel to the wall (O'Neill 1964, Mathematika 11:67) and rotation about an axis
  !> parallel to it (Dean & O'Neill 1963, Mathematika 10:13). Each reduces to a tridiagonal system
  !> for coefficients A_n (n >= 1), with k_n = (n + 1/2) coth((n + 1/2) alpha) - coth(alpha):
  !>   A_{n-1} (n-1) c_a/(2n-1) - A_n [n c_a + (n+1) c_b]/(2n+1) + A_{n+1} (n+2) c_b/(2n+3) = r_n,
  !>   c_a = (2n-1) k_{n-1} - (2n-3) k_n,  c_b = (2n+5) k_n - (2n+3) k_{n+1},
  !> (right-hand sides r_n in the code), from which E_n, C_n, B_n, D_n and the force and torque
  !> sums follow. Truncated at N = 40/alpha + 40 (terms decay like exp(-2 n alpha)). Checked in
  !> tests/unit/test_resistance_wall_tangential: O'Neill & Stewartson's published values at
  !> eps = 1e-3, the reciprocity f_tr(translation) = f_tr(rotation), the far-field forms.
  pure subroutine wall_tangential_exact(eps, f_tt, f_tr, f_rr, f_rt)
    real(dp), intent(in) :: eps
    real(dp), intent(out) :: f_tt, f_tr, f_rr
    real(dp), intent(out), optional :: f_rt   ! coupling from the rotation problem (= f_tr)
    real(dp) :: alpha, sh, cth, ft, gt, fr, gr
    integer :: nn
    alpha = acosh(1.0_dp + eps)
    sh = sinh(alpha)
    cth = 1.0_dp / tanh(alpha)
    nn = int(40.0_dp / alpha) + 40
    call oneill_sums(.false., alpha, nn, ft, gt)
    call oneill_sums(.true., alpha, nn, fr, gr)
    f_tt = sqrt(2.0_dp) / 6.0_dp * sh * ft
    f_tr = gt * sh**2 / (12.0_dp * sqrt(2.0_dp)) * 4.0_dp / 3.0_dp
    ! rotation: (4/3) f_rr = [1 - G sinh^3(alpha)/(4 sqrt 2)] * 4/9  (torque / 6 pi eta a^3 Om)
    f_rr = (1.0_dp - gr * sh**3 / (4.0_dp * sqrt(2.0_dp))) / 3.0_dp
    if (present(f_rt)) f_rt = -sqrt(2.0_dp) / 6.0_dp * sh**2 * fr
  contains
    pure subroutine oneill_sums(rot, a, n_max, fsum, gsum)
      logical, intent(in) :: rot
      real(dp), intent(in) :: a
      integer, intent(in) :: n_max
      real(dp), intent(out) :: fsum, gsum
      real(dp) :: k(0:n_max + 2), am(0:n_max + 2), c0(n_max), c1(n_max), c2(n_max), r(n_max)
      real(dp) :: ca, cb, x, e, c, b, d, ln, ea, wq, an, am1, ap1, ri
      integer :: i, n
      do n = 0, n_max + 2
        k(n) = (n + 0.5_dp) / tanh((n + 0.5_dp) * a) - cth
      end do
      do i = 1, n_max
        ri = real(i, dp)
        ca = (2 * i - 1) * k(i - 1) - (2 * i - 3) * k(i)
        cb = (2 * i + 5) * k(i) - (2 * i + 3) * k(i + 1)
        c0(i) = ca * (ri - 1) / (2 * ri - 1)
        c1(i) = -ca * ri / (2 * ri + 1) - cb * (ri + 1) / (2 * ri + 1)
        c2(i) = cb * (ri + 2) / (2 * ri + 3)
        if (.not. rot) then
          r(i) = sqrt(2.0_dp) * (2.0_dp / tanh((ri + 0.5_dp) * a) - 1.0_dp / tanh((ri - 0.5_dp) * a) &
                                 - 1.0_dp / tanh((ri + 1.5_dp) * a))
        else
          x = (2 * ri + 1)**2 * (exp(a) / (2 * ri - 1) + exp(-a) / (2 * ri + 3)) / sinh((ri + 0.5_dp) * a) &
              - (2 * ri - 1) / sinh((ri - 0.5_dp) * a) - (2 * ri + 3) / sinh((ri + 1.5_dp) * a)
          r(i) = -sqrt(2.0_dp) * exp(-(ri + 0.5_dp) * a) / ((2 * ri + 1) * sh) * x
        end if
      end do
      ! Thomas algorithm (the system is diagonally dominant)
      do i = 2, n_max
        wq = c0(i) / c1(i - 1)
        c1(i) = c1(i) - wq * c2(i - 1)
        r(i) = r(i) - wq * r(i - 1)
      end do
      am = 0.0_dp
      am(n_max) = r(n_max) / c1(n_max)
      do i = n_max - 1, 1, -1
        am(i) = (r(i) - c2(i) * am(i + 1)) / c1(i)
      end do
      fsum = 0.0_dp
      gsum = 0.0_dp
      do n = 0, n_max - 1
        x = real(n, dp)
        am1 = 0.0_dp
        if (n >= 2) am1 = am(max(n - 1, 0))
        an = am(n)
        ap1 = am(n + 1)
        ln = -(exp(-(x - 0.5_dp) * a) / (2 * x - 1) - exp(-(x + 1.5_dp) * a) / (2 * x + 3)) / sqrt(2.0_dp)
        if (.not. rot) then
          e = 2.0_dp * sqrt(2.0_dp) * exp(-(x + 0.5_dp) * a) / sinh((x + 0.5_dp) * a)
        else
          e = (sqrt(2.0_dp) * (2 * x + 1) * exp(-(x + 0.5_dp) * a) - ln / sh) / sinh((x + 0.5_dp) * a)
        end if
        e = e + k(n) * (x - 1) * x / (2 * x - 1) * am1 - k(n) * (x + 1) * (x + 2) / (2 * x + 3) * ap1
        c = 0.0_dp
        b = 0.0_dp
        if (n >= 1) then
          c = -2.0_dp * k(n) * ((x - 1) / (2 * x - 1) * am1 - an + (x + 2) / (2 * x + 3) * ap1)
          if (rot) c = c + 4.0_dp * ln / (sh * sinh((x + 0.5_dp) * a))
          b = (x - 1) * am1 - (2 * x + 1) * an + (x + 2) * ap1
        end if
        d = -0.5_dp * (x - 1) * x * am1 + 0.5_dp * (x + 1) * (x + 2) * ap1
        fsum = fsum + e + x * (x + 1) * c
        ea = exp(-(2 * x + 1) * a)
        gsum = gsum + (2.0_dp + ea) * (x * (x + 1) * (2 * an + c * cth) - (2 * x + 1 - cth) * e) &
               + (2.0_dp - ea) * (x * (x + 1) * b * cth - (2 * x + 1 - cth) * d)
      end do
    end subroutine oneill_sums
  end subroutine wall_tangential_exact

  !> Rotation about the wall normal: T_n = -8 pi eta a^3 Om_n X_w with Jeffery's (1915) exact
  !> X_w = sinh^3(alpha) sum_{n>=1} cosech^3(n alpha), cosh(alpha) = 1 + eps; -> zeta(3) at
  !> contact (non-singular; gaps below 1e-6 are evaluated at 1e-6).
  pure function wall_twist_resistance(gap) result(xw)
    real(dp), intent(in) :: gap
    real(dp) :: xw, alpha, term, sh
    integer :: n
    alpha = acosh(1.0_dp + max(gap, 1.0e-6_dp))
    sh = sinh(alpha)
    xw = 0.0_dp
    do n = 1, 1000000
      term = (sh / sinh(n * alpha))**3
      xw = xw + term
      if (term < 1.0e-17_dp * xw .or. n * alpha > 40.0_dp) exit
    end do
  end function wall_twist_resistance

  !> 6x6 sphere-wall resistance: (F, T) = -R . (U - U_wall, Om) for a sphere at gap eps from a
  !> plane wall with unit normal n pointing from the wall into the fluid (towards the sphere).
  function wall_resistance_fu(gap, normal, radius, viscosity) result(r)
    real(dp), intent(in) :: gap, normal(3), radius, viscosity
    real(dp) :: r(6, 6)
    real(dp) :: f_tt, f_tr, f_rr
    call wall_tangential_resistance(gap, f_tt, f_tr, f_rr)
    r = wall_resistance_block(wall_normal_resistance(gap), f_tt, f_tr, f_rr, &
                              wall_twist_resistance(gap), normal, radius, viscosity)
  end function wall_resistance_fu

  !> The 6x6 sphere-wall block from given scalars (theory, or theory minus numerics for the
  !> subgrid correction): lam = lambda_perp (normal), f_tt, f_tr, f_rr (tangential, coupling,
  !> rotation; see wall_tangential_resistance), xw (twist about n). (F, T) = -R . (U - U_wall, Om).
  pure function wall_resistance_block(lam, f_tt, f_tr, f_rr, xw, normal, radius, viscosity) result(r)
    real(dp), intent(in) :: lam, f_tt, f_tr, f_rr, xw, normal(3), radius, viscosity
    real(dp) :: r(6, 6)
    real(dp) :: nn(3, 3), skew(3, 3), ca
    integer :: i, j
    ca = 6.0_dp * pi * viscosity * radius
    do j = 1, 3
      do i = 1, 3
        nn(i, j) = normal(i) * normal(j)
      end do
    end do
    ! skew . v = n x v
    skew = reshape([0.0_dp, normal(3), -normal(2), -normal(3), 0.0_dp, normal(1), &
                    normal(2), -normal(1), 0.0_dp], [3, 3])
    r = 0.0_dp
    do j = 1, 3
      do i = 1, 3
        r(i, j) = ca * (lam * nn(i, j) + f_tt * (kron(i, j) - nn(i, j)))
        r(3 + i, 3 + j) = ca * radius**2 * (4.0_dp / 3.0_dp * xw * nn(i, j) &
                                            + 4.0_dp / 3.0_dp * f_rr * (kron(i, j) - nn(i, j)))
        ! Coupling (method.md 2.8): F_t = +6 pi eta a^2 f_tr Om_b t with b = n x t, i.e.
        ! F = 6 pi eta a^2 f_tr (Om x n) = -R_{F,Om} . Om with R_{F,Om} = 6 pi eta a^2 f_tr [n x];
        ! reciprocity makes R_{T,U} its transpose (T = 6 pi eta a^2 f_tr n x U: a sphere sliding
        ! along t is turned in the rolling sense, about b).
        r(i, 3 + j) = ca * radius * f_tr * skew(i, j)
        r(3 + j, i) = ca * radius * f_tr * skew(i, j)
      end do
    end do
  end function wall_resistance_block


end module mod_resistance
