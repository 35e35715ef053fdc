! The 22 resistance scalars of two UNEQUAL spheres (radii a1 and a2 = lambda a1) at any gap, from
! the twin-multipole series of Jeffrey & Onishi (1984, J. Fluid Mech. 139:261) and Jeffrey (1992,
! Phys. Fluids A 4:16), resummed so that it holds down to contact (doc/RESISTANCE.md "Unequal
! spheres").
!
! Conventions (those of Jeffrey & Onishi; doc/RESISTANCE.md):
!   * separation s = 2r/(a1 + a2), gap xi = s - 2 (for lambda = 1 the gap of mod_pair_resistance);
!     d from sphere 1 to sphere 2; tensor forms and block layout as in mod_pair_resistance.
!   * scalar of block (alpha, beta) scaled by 3 pi eta (a_alpha + a_beta) for A, pi eta (a_alpha +
!     a_beta)^2 for B and G, pi eta (a_alpha + a_beta)^3 for C and H, (5/6) pi eta (a_alpha +
!     a_beta)^3 for M. So the 11 scalars use 6 pi eta a1, 4 pi eta a1^2, 8 pi eta a1^3,
!     (20/3) pi eta a1^3 (Kim & Karrila's equal-sphere factors with a = a1), the 12 ones the
!     mean radius (a1 + a2)/2 in their place; at lambda = 1 both are today's normalisation.
!   * 22 and 21 from 11 and 12 at 1/lambda (Jeffrey & Onishi section 1): f22(lambda) =
!     f11(1/lambda), f21(lambda) = f12(1/lambda), with a minus sign for YB, XG, YG.
!
! Method. Each scalar is sigma * sum_m c_m t^m over one parity of m, t = 2/s, with
! c_m = 2^-m (1 + lambda)^-m f_m(lambda). The recurrences for the multipole coefficients
! P_npq, V_npq, Q_npq are those of Jeffrey & Onishi (eqs 3.6-3.15, 4.6-4.11, 7.3-7.5) and Jeffrey
! (1992), as corrected and completed by Townsend (2023, Phys. Fluids 35:127126; arXiv:1802.08226);
! f_m(lambda) = 2^m sum_q P_{n,m-q,q} lambda^q. Rather than generating the lambda-polynomials, the
! module runs the recurrences for the given lambda directly: with mu = lambda/(1+lambda) and
! nu = 1/(1+lambda), the weighted sums W_n^T = sum_{p+q=T} P_npq mu^q nu^p of sphere 1 and their
! mirror images (mu <-> nu) of sphere 2 obey a closed recurrence in (n, T) (the index swap of
! every right-hand side is the reflection from one sphere into the other), so a lambda costs
! O(nmax^3) operations and O(nmax^2) memory, and c_m = W_{n_eval}^m needs no large powers.
! The sum is resummed exactly as for equal spheres (mod_pair_resistance, series_scalars): the
! near-field coefficients h1, h2, h3 of 1/xi, ln(1/xi), xi ln(1/xi) (Jeffrey & Onishi, Jeffrey,
! corrected by Townsend) are summed in closed form and only the residual c_m - [h1 + 2 h2/m -
! 4 h3/(m(m+2))] is truncated at nmax (residual ~ m^-3). X^C uses the exact image sum of axial
! rotlets (the image of a rotlet in a no-slip sphere is a rotlet at the inverse point: Jeffery
! 1915's solution written as images), with the inner form near contact.
!
! Pure except sized_pair_scalars and sized_pair_scalars_22, which keep two set-ups (lambda and
! 1/lambda) as saved module state; lambda == 1 goes to mod_pair_resistance unchanged (bitwise).
module mod_pair_resistance_unequal
  use mod_kinds, only: dp
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars, i_xc11, i_xc12
  implicit none
  private

  public :: unequal_pair_t, unequal_pair_setup, unequal_pair_scalars, unequal_contact_constants, &
            unequal_near_field_scalars, sized_pair_scalars, sized_pair_scalars_22, &
            exchange_sign, twin_multipole_order, max_twin_multipole_order, n_series_families, &
            sphere_wall_gap

  !> Default truncation of the residual series (the equal-sphere table uses the same order).
  integer, parameter :: twin_multipole_order = 200
  integer, parameter :: max_twin_multipole_order = 400
  !> Families of series coefficients: XA, YA, YB, YC, XG, YG, YH, XM, YM, ZM (X^C: images).
  integer, parameter :: n_series_families = 10

  !> Sign of f22 relative to f11(1/lambda) and of f21 relative to f12(1/lambda): the scalars odd
  !> under exchanging the spheres with d fixed (YB, XG, YG).
  real(dp), parameter :: exchange_sign(n_pair_scalars) = [ &
    1, 1, -1, 1, 1, -1, -1, 1, 1, 1, 1, 1, 1, -1, 1, 1, -1, -1, 1, 1, 1, 1] * 1.0_dp

  ! Family and parity of the series of each scalar (order XA..ZM, 11 then 12; 0 = X^C).
  integer, parameter :: family(n_pair_scalars) = [ &
    1, 2, 3, 0, 4, 5, 6, 7, 8, 9, 10, 1, 2, 3, 0, 4, 5, 6, 7, 8, 9, 10]
  integer, parameter :: parity(n_pair_scalars) = [ &
    0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0, 1, 1, 1, 1]
  ! Below this gap X^C is the inner form c + k xi ln(1/xi) + b xi, b fixed by the image sum here.
  real(dp), parameter :: xc_inner_gap = 1.0e-3_dp
  ! Above s = 4 (t < 1/2) the plain series is summed (converged to round-off; no cancellation
  ! between the closed-form singular sums and the residual at large s).
  real(dp), parameter :: plain_series_t = 0.5_dp

  !> Everything the scalars need at one size ratio (unequal_pair_setup).
  type :: unequal_pair_t
    real(dp) :: lambda = 1.0_dp
    integer :: nmax = 0
    !> c_m of each family, m = 0 .. nmax
    real(dp), allocatable :: coef(:, :)                ! (0:nmax, n_series_families)
    !> prefactor sigma and near-field coefficients h1, h2, h3 of each scalar's series
    real(dp) :: sigma(n_pair_scalars) = 0.0_dp
    real(dp) :: h(3, n_pair_scalars) = 0.0_dp
    !> residual coefficients c_m - h1 - 2 h2/m + 4 h3/(m (m+2)) (own parity; entry 0 = c_0)
    real(dp), allocatable :: res(:, :)                 ! (0:nmax, n_pair_scalars)
    !> X^C inner forms (11, 12): constant, coefficient of xi ln(1/xi), matched coefficient of xi
    real(dp) :: xc_const(2) = 0.0_dp, xc_log(2) = 0.0_dp, xc_lin(2) = 0.0_dp
  end type unequal_pair_t

  ! Two cached set-ups (sized_pair_scalars): a lambda and its inverse are what a pair needs.
  type(unequal_pair_t), save :: cache(2)
  logical, save :: cache_used(2) = .false.
  integer, save :: cache_next = 1

contains

  ! ---------------------------------------------------------------------------------------------
  ! Convenience entry points
  ! ---------------------------------------------------------------------------------------------

  !> The 22 scalars (XA11 .. ZM11, XA12 .. ZM12, Jeffrey & Onishi's scaling) of spheres a1 and
  !> a2 = lambda a1 at gap = 2r/(a1 + a2) - 2 > 0. lambda == 1 is mod_pair_resistance's
  !> resistance_scalars itself (bitwise); other lambda the resummed series at order
  !> twin_multipole_order (set up once per lambda, two lambdas kept).
  function sized_pair_scalars(gap, lambda) result(f)
    real(dp), intent(in) :: gap, lambda
    real(dp) :: f(n_pair_scalars)
    integer :: slot
    if (lambda == 1.0_dp) then
      f = resistance_scalars(gap)
      return
    end if
    slot = cached_slot(lambda)
    f = unequal_pair_scalars(cache(slot), gap)
  end function sized_pair_scalars

  !> The 22- and 21-blocks' scalars in the same order (XA22 .. ZM22, XA21 .. ZM21), from the 11
  !> and 12 scalars at 1/lambda with exchange_sign (Jeffrey & Onishi's symmetry).
  function sized_pair_scalars_22(gap, lambda) result(f)
    real(dp), intent(in) :: gap, lambda
    real(dp) :: f(n_pair_scalars)
    f = exchange_sign * sized_pair_scalars(gap, 1.0_dp / lambda)
  end function sized_pair_scalars_22

  !> Gap of a sphere of radius `radius` whose centre is `height` above a plane wall, in units of
  !> its own radius: the argument of mod_wall_resistance's functions for that sphere (each
  !> sphere of an unequal pair uses the wall functions at its own gap over radius).
  pure function sphere_wall_gap(height, radius) result(eps)
    real(dp), intent(in) :: height, radius
    real(dp) :: eps
    eps = (height - radius) / radius
  end function sphere_wall_gap

  integer function cached_slot(lambda) result(slot)
    real(dp), intent(in) :: lambda
    integer :: k
    do k = 1, 2
      if (cache_used(k)) then
        if (cache(k)%lambda == lambda .and. cache(k)%nmax == twin_multipole_order) then
          slot = k
          return
        end if
      end if
    end do
    slot = cache_next
    cache(slot) = unequal_pair_setup(lambda, twin_multipole_order)
    cache_used(slot) = .true.
    cache_next = 3 - cache_next
  end function cached_slot

  ! ---------------------------------------------------------------------------------------------
  ! Set-up for one size ratio
  ! ---------------------------------------------------------------------------------------------

  !> Series coefficients, near-field coefficients and residuals for size ratio lambda > 0,
  !> truncated at order nmax (<= max_twin_multipole_order).
  pure function unequal_pair_setup(lambda, nmax) result(pr)
    real(dp), intent(in) :: lambda
    integer, intent(in) :: nmax
    type(unequal_pair_t) :: pr
    real(dp), allocatable :: p(:, :), v(:, :), q(:, :)
    real(dp) :: l, d, g(3), mm, lam_odd
    integer :: k, m, n
    n = min(max(nmax, 4), max_twin_multipole_order)
    pr%lambda = lambda
    pr%nmax = n
    allocate(pr%coef(0:n, n_series_families), pr%res(0:n, n_pair_scalars), source=0.0_dp)
    l = lambda
    d = 1.0_dp + l
    ! Series coefficients. Recurrence kinds: 'A' (X^A, X^G, X^M), 'Y' (Y^A, Y^B, Y^C, Y^G, Y^H,
    ! Y^M), 'Z' (Z^M); seeded by P or Q at n0; read at n = 1 or 2 (Townsend 2023 eqs 5-9, 18, 21,
    ! 29; Jeffrey 1992).
    call recurrence(n, 'A', 1, .false., l, p, v, q)
    pr%coef(0:n, 1) = p(1, 0:n)                      ! XA
    pr%coef(0:n, 5) = 0.75_dp * p(2, 0:n)            ! XG
    call recurrence(n, 'Y', 1, .false., l, p, v, q)
    pr%coef(0:n, 2) = p(1, 0:n)                      ! YA
    pr%coef(0:n, 3) = 2.0_dp * q(1, 0:n)             ! YB
    pr%coef(0:n, 6) = 0.75_dp * p(2, 0:n)            ! YG
    call recurrence(n, 'Y', 1, .true., l, p, v, q)
    pr%coef(0:n, 4) = q(1, 0:n)                      ! YC
    pr%coef(0:n, 7) = -0.375_dp * p(2, 0:n)          ! YH
    call recurrence(n, 'A', 2, .false., l, p, v, q)
    pr%coef(0:n, 8) = p(2, 0:n)                      ! XM
    call recurrence(n, 'Y', 2, .false., l, p, v, q)
    pr%coef(0:n, 9) = p(2, 0:n)                      ! YM
    call recurrence(n, 'Z', 2, .false., l, p, v, q)
    pr%coef(0:n, 10) = p(2, 0:n)                     ! ZM
    ! The families seeded by a rotation or a strain carry lambda^(m mod 2) (Townsend 2023 eq 29;
    ! Ichiki et al. 2013): the odd coefficients of YC, YH, XM, YM, ZM times lambda.
    lam_odd = l
    do m = 1, n, 2
      pr%coef(m, [4, 7, 8, 9, 10]) = lam_odd * pr%coef(m, [4, 7, 8, 9, 10])
    end do

    ! Prefactor and near-field coefficients of each scalar (Jeffrey & Onishi 1984 eqs 3.17-3.19,
    ! 4.15-4.16, 5.6, 7.10; Jeffrey 1992 eqs 19b, 27b, 35b, 48b, 64b, 79b; with Townsend's 2023
    ! corrections and his added 12 forms of Y^C, Y^H). sigma * (h1/xi + h2 ln(1/xi) + h3 xi ln(1/xi))
    ! is the singular part of the scalar in Jeffrey & Onishi's scaling.
    g = [2 * l**2, l * (1 + 7 * l + l**2) / 5, (1 + 18 * l - 29 * l**2 + 18 * l**3 + l**4) / 42] / d**3
    call set_scalar(pr, 1, 1.0_dp, g)                            ! XA11
    call set_scalar(pr, 12, -2 / d, g)                           ! XA12
    g = [0.0_dp, 4 * l * (2 + l + 2 * l**2) / 15, &
         2 * (16 - 45 * l + 58 * l**2 - 45 * l**3 + 16 * l**4) / 375] / d**3
    call set_scalar(pr, 2, 1.0_dp, g)                            ! YA11
    call set_scalar(pr, 13, -2 / d, g)                           ! YA12
    g = [0.0_dp, -l * (4 + l) / 5, -(32 - 33 * l + 83 * l**2 + 43 * l**3) / 250] / d**2
    call set_scalar(pr, 3, 1.0_dp, g)                            ! YB11
    call set_scalar(pr, 14, -4 / d**2, g)                        ! YB12
    g = [0.0_dp, 2 * l / 5, (8 + 6 * l + 33 * l**2) / 125] / d
    call set_scalar(pr, 5, 1.0_dp, g)                            ! YC11
    g = [0.0_dp, l**2 / 10, l * (43 - 24 * l + 43 * l**2) / 500] / d
    call set_scalar(pr, 16, 8 / d**3, g)                         ! YC12
    g = [3 * l**2, 3 * (l + 12 * l**2 - 4 * l**3) / 10, &
         (5 + 181 * l - 453 * l**2 + 566 * l**3 - 65 * l**4) / 140] / d**3
    call set_scalar(pr, 6, 1.0_dp, g)                            ! XG11
    call set_scalar(pr, 17, -4 / d**2, g)                        ! XG12
    g = [0.0_dp, (4 * l - l**2 + 7 * l**3) / 10, &
         (32 - 179 * l + 532 * l**2 - 356 * l**3 + 221 * l**4) / 500] / d**3
    call set_scalar(pr, 7, 1.0_dp, g)                            ! YG11
    call set_scalar(pr, 18, -4 / d**2, g)                        ! YG12
    g = [0.0_dp, (2 * l - l**2) / 10, (16 - 61 * l + 180 * l**2 + 2 * l**3) / 500] / d**2
    call set_scalar(pr, 8, 1.0_dp, g)                            ! YH11
    g = [0.0_dp, (l**2 + 7 * l**3) / 20, (43 * l + 147 * l**2 - 185 * l**3 + 221 * l**4) / 1000] / d**2
    call set_scalar(pr, 19, 8 / d**3, g)                         ! YH12
    g = [6 * l**2 / 5, 3 * (l + 17 * l**2 - 9 * l**3) / 25, &
         (5 + 272 * l - 831 * l**2 + 1322 * l**3 - 415 * l**4) / 350] / d**3
    call set_scalar(pr, 9, 1.0_dp, g)                            ! XM11
    g = [6 * l**3 / 5, 3 * (-4 * l**2 + 17 * l**3 - 4 * l**4) / 25, &
         (-65 * l + 832 * l**2 - 1041 * l**3 + 832 * l**4 - 65 * l**5) / 350] / d**3
    call set_scalar(pr, 20, 8 / d**3, g)                         ! XM12
    g = [0.0_dp, 6 * (l - l**2 + 4 * l**3) / 25, &
         (24 - 201 * l + 882 * l**2 - 1182 * l**3 + 591 * l**4) / 625] / d**3
    call set_scalar(pr, 10, 1.0_dp, g)                           ! YM11
    g = [0.0_dp, 3 * (7 * l**2 - 10 * l**3 + 7 * l**4) / 50, &
         3 * l * (221 - 728 * l + 1902 * l**2 - 728 * l**3 + 221 * l**4) / 2500] / d**3
    call set_scalar(pr, 21, 8 / d**3, g)                         ! YM12
    g = [0.0_dp, 0.0_dp, -3 * (l**2 + l**4) / 10] / d**3
    call set_scalar(pr, 11, 1.0_dp, g)                           ! ZM11
    call set_scalar(pr, 22, -8 / d**3, g)                        ! ZM12

    ! Residuals.
    do k = 1, n_pair_scalars
      if (family(k) == 0) cycle
      if (parity(k) == 0) pr%res(0, k) = pr%coef(0, family(k))
      do m = 1, n
        if (mod(m, 2) /= parity(k)) cycle
        mm = real(m, dp)
        pr%res(m, k) = pr%coef(m, family(k)) - pr%h(1, k) - 2 * pr%h(2, k) / mm &
                       + 4 * pr%h(3, k) / (mm * (mm + 2))
      end do
    end do

    ! X^C inner forms (Townsend 2023 eqs 26-27 in this scaling): X^C_11 -> lambda^3/(1+lambda)^3
    ! zeta(3, lambda/(1+lambda)) - lambda^2/(4(1+lambda)) xi ln(1/xi), X^C_12 -> 8/(1+lambda)^3
    ! [-lambda^3/(1+lambda)^3 zeta(3) + lambda^2/(4(1+lambda)) xi ln(1/xi)]; the O(xi) term b is
    ! matched to the image sum at xc_inner_gap.
    pr%xc_const = [l**3 / d**3 * hurwitz_zeta3(l / d), -8 * l**3 / d**6 * hurwitz_zeta3(1.0_dp)]
    pr%xc_log = [-l**2 / (4 * d), 2 * l**2 / d**4]
    block
      real(dp) :: x11, x12, xl
      call xc_images(xc_inner_gap, l, x11, x12)
      xl = xc_inner_gap * log(1 / xc_inner_gap)
      pr%xc_lin = ([x11, x12] - pr%xc_const - pr%xc_log * xl) / xc_inner_gap
    end block
  end function unequal_pair_setup

  pure subroutine set_scalar(pr, k, sigma, g)
    type(unequal_pair_t), intent(inout) :: pr
    integer, intent(in) :: k
    real(dp), intent(in) :: sigma, g(3)
    pr%sigma(k) = sigma
    pr%h(:, k) = g
  end subroutine set_scalar

  !> The recurrences for P, V, Q (Jeffrey & Onishi 1984; Jeffrey 1992; Townsend 2023) summed over
  !> p + q = T with the weights of sphere 1, W(n, T) = sum P_{n,p,q} mu^q nu^p (mu = lambda/(1+
  !> lambda), nu = 1 - mu), for T = 0 .. nmax. Every right-hand side P_{s, q-s-j, p-n+delta} has
  !> its two power indices swapped (the reflection into the other sphere): summed with these
  !> weights it is mu^(s+j) nu^(n-delta) times the other sphere's sum (mu <-> nu) at total
  !> T - s - j - n + delta. kind 'A', 'Y', 'Z': the binomial C(n+s, n), C(n+s, n+1), C(n+s, n+2)
  !> families; seed_q: seeded by Q_{n0,0,0} = 1 instead of P_{n0,0,0} = V_{n0,0,0} = 1.
  pure subroutine recurrence(nmax, kind, n0, seed_q, lambda, p1, v1, q1)
    integer, intent(in) :: nmax, n0
    character, intent(in) :: kind
    logical, intent(in) :: seed_q
    real(dp), intent(in) :: lambda
    real(dp), allocatable, intent(out) :: p1(:, :), v1(:, :), q1(:, :)
    real(dp), allocatable :: p2(:, :), v2(:, :), q2(:, :), binom(:, :), wa(:, :), wb(:, :)
    integer :: nn, tt, side, n, s, smin, shift, nhi
    real(dp) :: mu, nu, rn, rs, b, pa, pb, vc, qd, qe, pe, term, sp, sv, sq, vsign
    nn = nmax + 4
    allocate(p1(nn, 0:nmax), v1(nn, 0:nmax), q1(nn, 0:nmax), source=0.0_dp)
    allocate(p2(nn, 0:nmax), v2(nn, 0:nmax), q2(nn, 0:nmax), source=0.0_dp)
    if (seed_q) then
      q1(n0, 0) = 1
      q2(n0, 0) = 1
    else
      p1(n0, 0) = 1
      v1(n0, 0) = 1
      p2(n0, 0) = 1
      v2(n0, 0) = 1
    end if
    mu = lambda / (1 + lambda)
    nu = 1 / (1 + lambda)
    ! powers: wa(k, 1) = mu^k, wa(k, 2) = nu^k (sphere 1's weights); wb swapped (sphere 2's)
    allocate(wa(0:2 * nn, 2), wb(0:2 * nn, 2))
    wa(0, :) = 1
    do n = 1, 2 * nn
      wa(n, :) = wa(n - 1, :) * [mu, nu]
    end do
    wb(:, 1) = wa(:, 2)
    wb(:, 2) = wa(:, 1)
    ! binomials C(i, j), i <= nn + nmax
    allocate(binom(0:nn + nmax, 0:nn + nmax), source=0.0_dp)
    do n = 0, nn + nmax
      binom(n, 0) = 1
      do s = 1, n
        binom(n, s) = binom(n - 1, s - 1) + binom(n - 1, s)
      end do
    end do
    smin = 1
    shift = 0
    vsign = -1
    if (kind == 'Y') shift = 1
    if (kind == 'Z') then
      smin = 2
      shift = 2
    end if
    if (kind /= 'A') vsign = 1
    do tt = 1, nmax
      ! only n <= nmax - T + 2 is ever read again, and P_npq = 0 for n > p + 2
      nhi = min(nmax - tt + 2, tt + 2)
      do side = 1, 2
        do n = 1, nhi
          rn = n
          sp = 0
          sv = 0
          sq = 0
          do s = smin, tt
            rs = s
            b = binom(n + s, n + shift)
            if (side == 1) then
              pa = other(p2, s, tt - s - n + 1) * wa(s, 1) * wa(n - 1, 2)
              pb = other(p2, s, tt - s - n - 1) * wa(s, 1) * wa(n + 1, 2)
              vc = other(v2, s, tt - s - n - 1) * wa(s + 2, 1) * wa(n - 1, 2)
              qd = other(q2, s, tt - s - n) * wa(s + 1, 1) * wa(n - 1, 2)
              qe = other(q2, s, tt - s - n - 1) * wa(s + 1, 1) * wa(n, 2)
              pe = other(p2, s, tt - s - n) * wa(s, 1) * wa(n, 2)
            else
              pa = other(p1, s, tt - s - n + 1) * wb(s, 1) * wb(n - 1, 2)
              pb = other(p1, s, tt - s - n - 1) * wb(s, 1) * wb(n + 1, 2)
              vc = other(v1, s, tt - s - n - 1) * wb(s + 2, 1) * wb(n - 1, 2)
              qd = other(q1, s, tt - s - n) * wb(s + 1, 1) * wb(n - 1, 2)
              qe = other(q1, s, tt - s - n - 1) * wb(s + 1, 1) * wb(n, 2)
              pe = other(p1, s, tt - s - n) * wb(s, 1) * wb(n, 2)
            end if
            select case (kind)
            case ('A')
              term = rn * (2 * rn + 1) * (2 * rn * rs - rn - rs + 2) &
                     / (2 * (rn + 1) * (2 * rs - 1) * (rn + rs)) * pa &
                     - rn * (2 * rn - 1) / (2 * (rn + 1)) * pb &
                     - rn * (4 * rn**2 - 1) / (2 * (rn + 1) * (2 * rs + 1)) * vc
            case ('Y')
              term = (2 * rn + 1) / (2 * (rn + 1)) * (3 * (rn + rs) - (rn * rs + 1) &
                     * (2 * rn * rs - rs - rn + 2)) / (rs * (rn + rs) * (2 * rs - 1)) * pa &
                     + rn * (2 * rn - 1) / (2 * (rn + 1)) * pb &
                     + rn * (4 * rn**2 - 1) / (2 * (rn + 1) * (2 * rs + 1)) * vc &
                     - 2 * (4 * rn**2 - 1) / (3 * (rn + 1)) * qd
              sq = sq + b * (rs / (rn + 1) * qe - 3 / (2 * rn * rs * (rn + 1)) * pe)
            case default
              term = -2 * (2 * rn + 1) * (2 * rn - 1) / (rn + 1) * qd &
                     + rn * (2 * rn + 1) * (2 * rn - 1) / (2 * (rn + 1) * (2 * rs + 1)) * vc &
                     + (2 * rn + 1) / (rn + 1) * (rn * rs * (rn + rs - 2 * rn * rs - 2) &
                     - 4 * (2 * rn * rs - 4 * rs - 4 * rn + 2)) / (2 * rs * (rn + rs) * (2 * rs - 1)) * pa &
                     + rn * (2 * rn - 1) / (2 * (rn + 1)) * pb
              sq = sq + b * (rs / (rn + 1) * qe - 2 / (rn * rs * (rn + 1)) * pe)
            end select
            sp = sp + b * term
            sv = sv + b * pb
          end do
          if (side == 1) then
            p1(n, tt) = sp
            q1(n, tt) = sq
            v1(n, tt) = sp + vsign * 2 * rn / ((rn + 1) * (2 * rn + 3)) * sv
          else
            p2(n, tt) = sp
            q2(n, tt) = sq
            v2(n, tt) = sp + vsign * 2 * rn / ((rn + 1) * (2 * rn + 3)) * sv
          end if
        end do
      end do
    end do
  contains
    pure real(dp) function other(arr, s, t)
      real(dp), intent(in) :: arr(:, 0:)
      integer, intent(in) :: s, t
      if (t < 0) then
        other = 0
      else
        other = arr(s, t)
      end if
    end function other
  end subroutine recurrence

  ! ---------------------------------------------------------------------------------------------
  ! Evaluation
  ! ---------------------------------------------------------------------------------------------

  !> The 22 scalars (11 and 12, Jeffrey & Onishi's scaling) of the set-up pr at gap xi > 0
  !> (non-positive gaps are evaluated at 1e-300). For any lambda, including 1 (where it is the
  !> same series as mod_pair_resistance's, without that module's Lamb-table middle piece).
  pure function unequal_pair_scalars(pr, gap) result(f)
    type(unequal_pair_t), intent(in) :: pr
    real(dp), intent(in) :: gap
    real(dp) :: f(n_pair_scalars)
    real(dp) :: xi, t, l1t2, lodd, s_even(3), s_odd(3), sv(3), pe, po, acc
    integer :: m, k, n
    xi = max(gap, 1.0e-300_dp)
    t = 2 / (2 + xi)
    n = pr%nmax
    if (t < plain_series_t) then
      do k = 1, n_pair_scalars
        if (family(k) == 0) cycle
        acc = 0
        do m = n - mod(n - parity(k), 2), parity(k), -2
          acc = acc * t**2 + pr%coef(m, family(k))
        end do
        if (parity(k) == 1) acc = acc * t
        f(k) = pr%sigma(k) * acc
      end do
    else
      l1t2 = log(xi) + log(4 + xi) - 2 * log(2 + xi)      ! ln(1 - t^2)
      lodd = log((4 + xi) / xi)                            ! ln((1+t)/(1-t))
      s_even = [4 / (xi * (4 + xi)), -l1t2, 1 + 0.25_dp * xi * (4 + xi) * l1t2]
      s_odd = [2 * (2 + xi) / (xi * (4 + xi)), lodd, (2 + xi) - 0.25_dp * xi * (4 + xi) * lodd]
      do k = 1, n_pair_scalars
        if (family(k) == 0) cycle
        acc = 0
        do m = n - mod(n - parity(k), 2), parity(k), -2
          acc = acc * t**2 + pr%res(m, k)
        end do
        if (parity(k) == 1) acc = acc * t
        if (parity(k) == 0) then
          sv = s_even
        else
          sv = s_odd
        end if
        f(k) = pr%sigma(k) * (pr%h(1, k) * sv(1) + pr%h(2, k) * sv(2) - pr%h(3, k) * sv(3) + acc)
      end do
    end if
    if (xi < xc_inner_gap) then
      f([i_xc11, i_xc12]) = pr%xc_const + pr%xc_log * xi * log(1 / xi) + pr%xc_lin * xi
    else
      call xc_images(xi, pr%lambda, pe, po)
      f(i_xc11) = pe
      f(i_xc12) = po
    end if
  end function unequal_pair_scalars

  !> O(1) constants of the near-contact forms f = sigma (h1/xi + h2 ln(1/xi) + h3 xi ln(1/xi)) + c
  !> as given by the resummed series at t -> 1 (Jeffrey & Onishi's A^X_11 etc. in this scaling).
  pure function unequal_contact_constants(pr) result(c)
    type(unequal_pair_t), intent(in) :: pr
    real(dp) :: c(n_pair_scalars)
    integer :: k
    do k = 1, n_pair_scalars
      if (family(k) == 0) cycle
      if (parity(k) == 0) then
        c(k) = pr%sigma(k) * (sum(pr%res(0:pr%nmax, k)) - 0.25_dp * pr%h(1, k) - pr%h(3, k))
      else
        c(k) = pr%sigma(k) * (sum(pr%res(0:pr%nmax, k)) + 0.25_dp * pr%h(1, k) &
                              + pr%h(2, k) * log(4.0_dp) - 2 * pr%h(3, k))
      end if
    end do
    c([i_xc11, i_xc12]) = pr%xc_const
  end function unequal_contact_constants

  !> The near-contact forms alone, sigma (h1/xi + h2 ln(1/xi) + h3 xi ln(1/xi)) + c (X^C: its inner
  !> form), at gap xi > 0: what the series tends to at contact (they differ by O(xi)).
  pure function unequal_near_field_scalars(pr, gap) result(f)
    type(unequal_pair_t), intent(in) :: pr
    real(dp), intent(in) :: gap
    real(dp) :: f(n_pair_scalars)
    real(dp) :: lg
    lg = log(1 / gap)
    f = unequal_contact_constants(pr) + pr%sigma * (pr%h(1, :) / gap + pr%h(2, :) * lg &
                                                    + pr%h(3, :) * gap * lg)
    f([i_xc11, i_xc12]) = pr%xc_const + pr%xc_log * gap * lg
  end function unequal_near_field_scalars

  !> X^C_11 and X^C_12 (Jeffrey & Onishi's scaling) by images: sphere 1 (radius 1, centre 0)
  !> rotating about d inside a rotlet of strength 1 at its centre; the image of an axial rotlet m
  !> at distance R from the centre of a no-slip sphere of radius a is the rotlet -m (a/R)^3 at the
  !> inverse point a^2/R (the velocity m d x (x - x0)/|x - x0|^3 of the pair vanishes on the
  !> sphere). Reflected back and forth until the strengths fall below 1e-17; the torques are
  !> -8 pi eta times the strengths inside each sphere, so X^C_11 = sum in 1 and X^C_12 = X^C_21
  !> = 8/(1+lambda)^3 sum in 2.
  pure subroutine xc_images(xi, lambda, xc11, xc12)
    real(dp), intent(in) :: xi, lambda
    real(dp), intent(out) :: xc11, xc12
    real(dp) :: r, x, m, big_r, sum1, sum2
    integer :: it
    r = 0.5_dp * (1 + lambda) * (2 + xi)
    x = 0          ! rotlet position on the axis (sphere 1 at 0, sphere 2 at r)
    m = 1
    sum1 = 1
    sum2 = 0
    do it = 1, 100000000
      ! into sphere 2
      big_r = r - x
      m = -m * (lambda / big_r)**3
      x = r - lambda**2 / big_r
      sum2 = sum2 + m
      ! back into sphere 1
      big_r = x
      m = -m * (1 / big_r)**3
      x = 1 / big_r
      sum1 = sum1 + m
      if (abs(m) < 1.0e-17_dp) exit
    end do
    xc11 = sum1
    xc12 = 8 * sum2 / (1 + lambda)**3
  end subroutine xc_images

  !> Hurwitz zeta(3, q) = sum_{k >= 0} (k + q)^-3, q > 0: 30 terms, then Euler-Maclaurin
  !> (error < 1e-16 relative).
  pure real(dp) function hurwitz_zeta3(q) result(z)
    real(dp), intent(in) :: q
    real(dp) :: y
    integer :: k
    z = 0
    do k = 0, 29
      z = z + 1 / (k + q)**3
    end do
    y = 30 + q
    z = z + 1 / (2 * y**2) + 1 / (2 * y**3) + 1 / (4 * y**4) - 1 / (12 * y**6) + 1 / (12 * y**8)
  end function hurwitz_zeta3

end module mod_pair_resistance_unequal
