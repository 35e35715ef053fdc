! Unit test: axisymmetric two-sphere motions of mod_pair_resistance against the exact bispherical-
! coordinate solutions, implemented here independently of the module (doc/VALIDATION_pair.md §1).
! With cosh(alpha) = s/2 (s = r/a) and m = 2n + 1:
!   * co-translation along the line of centres, XA11 + XA12 (Stimson & Jeffery 1926):
!       (4/3) sinh(a) sum n(n+1)/((2n-1)(2n+3)) [1 - (4 sinh^2(m a/2) - m^2 sinh^2 a)
!                                                 / (2 sinh(m a) + m sinh(2a))]
!   * squeeze, equal and opposite velocities, XA11 - XA12: the mid-plane is a plane of symmetry
!     with zero normal velocity and zero shear stress, i.e. Brenner's (1961) free-surface problem
!     (also Maude 1961):
!       (4/3) sinh(a) sum n(n+1)/((2n-1)(2n+3)) [(4 cosh^2(m a/2) + m^2 sinh^2 a)
!                                                 / (2 sinh(m a) - m sinh(2a)) - 1]
!   * rotation about the line of centres (Jeffery 1915): counter-rotation, XC11 - XC12 (the
!     mid-plane is then a no-slip plane) = sinh^3(a) sum cosech^3(n a); co-rotation,
!     XC11 + XC12 = sinh^3(a) sum (-1)^(n+1) cosech^3(n a). Contact limits zeta(3), (3/4)zeta(3).
! Checked at 16 gaps from 1e-5 to 15 (near piece, table spline, far piece). Tolerances (relative),
! from what limits the module in each range:
!   * co-translation 3e-5: XA11 + XA12 cancels the 1/xi and log terms, so near contact its
!     accuracy is that of the O(1) constants. The module's near piece is the resummed
!     twin-multipole series truncated at t^200, whose residual coefficients fall like m^-3:
!     measured 9.4e-6 at contact (0.6451354 against the exact 0.6451414; the published 6-digit
!     constants of doc/METHOD.md §5.2, 0.995419 - 0.350153 = 0.645266, were 1.9e-4 off, the
!     truncation of Townsend's 100-term sums); 3x margin;
!   * squeeze 3e-5: measured 7.6e-6, the spline of the Lamb rows between rows;
!   * rotation 1e-4: X^C is exact (Jeffery's sums) outside the table; inside, the spline between
!     rows (measured 4.5e-5, counter-rotation at gap 0.15).
! Also: the contact value of the co-translation drag itself (gap 1e-9) against the exact
! series' limit, 3e-5 as above.
program test_resistance_bispherical
  use mod_kinds, only: dp
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars, i_xa11, i_xa12, i_xc11, i_xc12
  use mod_unit_checks, only: check_below, finish
  implicit none
  real(dp), parameter :: gaps(16) = [1.0e-5_dp, 1.0e-4_dp, 1.0e-3_dp, 5.0e-3_dp, 0.01_dp, 0.02_dp, &
                                     0.035_dp, 0.07_dp, 0.15_dp, 0.33_dp, 0.7_dp, 1.45_dp, 2.2_dp, &
                                     3.3_dp, 6.0_dp, 15.0_dp]
  real(dp) :: f(n_pair_scalars), e(4), worst(4), ex(4), s
  integer :: k
  character(len=*), parameter :: names(4) = [character(len=22) :: 'co-translation XA+', &
    'squeeze XA-', 'co-rotation XC+', 'counter-rotation XC-']
  real(dp), parameter :: tol(4) = [3.0e-5_dp, 3.0e-5_dp, 1.0e-4_dp, 1.0e-4_dp]

  worst = 0.0_dp
  print '(a)', '    gap       XA+ exact   rel.err    XA- exact   rel.err    XC+ exact   rel.err    XC- exact   rel.err'
  do k = 1, size(gaps)
    s = 2.0_dp + gaps(k)
    f = resistance_scalars(gaps(k))
    ex = [stimson_jeffery(s), free_surface_squeeze(s), jeffery_rotation(s, .true.), &
          jeffery_rotation(s, .false.)]
    e = [f(i_xa11) + f(i_xa12), f(i_xa11) - f(i_xa12), f(i_xc11) + f(i_xc12), f(i_xc11) - f(i_xc12)]
    e = abs(e / ex - 1.0_dp)
    worst = max(worst, e)
    print '(es10.2, 4(es12.5, es10.2))', gaps(k), ex(1), e(1), ex(2), e(2), ex(3), e(3), ex(4), e(4)
  end do
  do k = 1, 4
    call check_below(trim(names(k))//': max rel. error', worst(k), tol(k))
  end do
  f = resistance_scalars(1.0e-9_dp)
  e(1) = abs((f(i_xa11) + f(i_xa12)) / stimson_jeffery(2.0_dp + 1.0e-9_dp) - 1.0_dp)
  print '(a,f10.7,a,f10.7,a,es9.2)', 'co-translation at contact (gap 1e-9): module ', &
    f(i_xa11) + f(i_xa12), ', Stimson & Jeffery ', stimson_jeffery(2.0_dp + 1.0e-9_dp), &
    ', rel. error ', e(1)
  call check_below('co-translation contact constant, rel. error', e(1), 3.0e-5_dp)
  ! Contact limits of the exact solutions themselves (sanity of the series): zeta(3), 3/4 zeta(3).
  call check_below('Jeffery counter-rotation series at gap 1e-6 - zeta(3)', &
                   abs(jeffery_rotation(2.0_dp + 1.0e-6_dp, .false.) - 1.2020569_dp), 1.0e-4_dp)
  call finish('test_resistance_bispherical')

contains

  function stimson_jeffery(sep) result(lam)
    real(dp), intent(in) :: sep
    real(dp) :: lam, alpha, sh, q, m, num, den, term
    integer :: n
    alpha = acosh(sep / 2.0_dp)
    sh = sinh(alpha)
    lam = 0.0_dp
    do n = 1, 10000000
      m = real(2 * n + 1, dp)
      q = exp(-m * alpha)   ! everything divided by exp(m alpha) to avoid overflow
      num = (1.0_dp - q)**2 - m**2 * sh**2 * q
      den = (1.0_dp - q * q) + m * sinh(2.0_dp * alpha) * q
      term = real(n, dp) * real(n + 1, dp) / ((m - 2.0_dp) * (m + 2.0_dp)) * (1.0_dp - num / den)
      lam = lam + term
      if (abs(term) < 1.0e-17_dp * abs(lam) .and. m * alpha > 10.0_dp) exit
    end do
    lam = 4.0_dp / 3.0_dp * sh * lam
  end function stimson_jeffery

  function free_surface_squeeze(sep) result(lam)
    real(dp), intent(in) :: sep
    real(dp) :: lam, alpha, sh, q, m, num, den, term
    integer :: n
    alpha = acosh(sep / 2.0_dp)
    sh = sinh(alpha)
    lam = 0.0_dp
    do n = 1, 10000000
      m = real(2 * n + 1, dp)
      q = exp(-m * alpha)
      num = (1.0_dp + q)**2 + m**2 * sh**2 * q
      den = (1.0_dp - q * q) - m * sinh(2.0_dp * alpha) * q
      term = real(n, dp) * real(n + 1, dp) / ((m - 2.0_dp) * (m + 2.0_dp)) * (num / den - 1.0_dp)
      lam = lam + term
      if (abs(term) < 1.0e-17_dp * abs(lam) .and. m * alpha > 10.0_dp) exit
    end do
    lam = 4.0_dp / 3.0_dp * sh * lam
  end function free_surface_squeeze

  function jeffery_rotation(sep, co_rotating) result(x)
    real(dp), intent(in) :: sep
    logical, intent(in) :: co_rotating
    real(dp) :: x, alpha, term, sgn
    integer :: n
    alpha = acosh(sep / 2.0_dp)
    x = 0.0_dp
    sgn = 1.0_dp
    do n = 1, 100000000
      ! (sinh a / sinh(n a))^3 written with exponentials to avoid overflow at large n a
      term = ((1.0_dp - exp(-2.0_dp * alpha)) / (1.0_dp - exp(-2.0_dp * n * alpha)))**3 &
             * exp(-3.0_dp * (n - 1) * alpha)
      x = x + sgn * term
      if (co_rotating) sgn = -sgn
      if (term < 1.0e-17_dp) exit
    end do
  end function jeffery_rotation
end program test_resistance_bispherical
