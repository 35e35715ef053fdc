! Exact resistance of a sphere near a plane wall (doc/METHOD.md §5.2): the scalar functions of
! the normal approach (lambda_perp: Brenner 1961, Cox & Brenner 1967), of tangential translation
! and rotation with their coupling (f_tt, f_tr, f_rr: O'Neill 1964, Dean & O'Neill 1963,
! Goldman, Cox & Brenner 1967) and of the twist about the normal (x_w: Jeffery 1915), at gap
! eps = (centre height - a)/a. The 6x6 sphere-wall block built from them is in
! mod_resistance_blocks.
!
! Pure Fortran (no PETSc, MPI or HDF5): used by the lubrication correction (sphere-wall links)
! and bin/fdsusp-resistance ('wall'). Joins and measured accuracy: doc/RESISTANCE.md.
module mod_wall_resistance
  use mod_kinds, only: dp
  implicit none
  private

  public :: wall_normal_resistance, wall_normal_near_field, wall_normal_far_field
  public :: wall_tangential_resistance, wall_twist_resistance, wall_tangential_exact, &
            wall_tangential_inner, wall_tangential_far

  ! Sphere-wall joins (doc/METHOD.md §5.2; doc/RESISTANCE.md).
  real(dp), parameter :: wall_normal_series_min_gap = 1.0e-2_dp   ! below: Cox-Brenner form
  real(dp), parameter :: wall_tangential_exact_lo = 1.0e-3_dp, wall_tangential_exact_hi = 10.0_dp

contains

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

  !> Far-field reflection form 1/(1 - 9x/8 + x^3/2 - 0.57 x^4 + 0.2 x^5), x = a/l (doc/METHOD.md §5.2).
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

  !> Tangential sphere-wall functions at gap eps (doc/METHOD.md §5.2): with s the sphere velocity
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

  !> Inner forms (f_tt, f_tr, f_rr) of the tangential functions (doc/METHOD.md §5.2).
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

end module mod_wall_resistance
