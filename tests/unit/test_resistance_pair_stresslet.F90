! Unit test: stresslet of a force- and torque-free pair in simple shear, two routes.
!   Route 1 (general blocks): solve R_FU . w = -R_FE : E for w = U^inf - U (12 unknowns, force-
!     and torque-free), then S_1 = R_SU . w + R_SE : E with mod_resistance_blocks' pair_stresslets.
!   Route 2 (Batchelor & Green closed forms, doc/METHOD.md §9.2 and §9.4): in the shear plane,
!     d = (cos t, sin t, 0):  N1* = M sin(2t) cos(2t),  N2* = sin(2t) [L + M sin^2 t],
!     with L, M from pair_shear_functions (which reduces the same scalars to the 6-unknown
!     symmetric problem by hand: different algebra, same physics).
! Invariants:
!   1. the two routes agree for N1*, N2* at 7 gaps (1e-4 .. 5) x 7 angles within 1e-9 of
!      max(|N|, 1e-3) (they are algebraically identical; round-off only);
!   2. the pair's relative velocity from route 1 equals Batchelor & Green's
!      Om x r + E.r - [A dd + B (I - dd)].E.r (1e-12 relative);
!   3. isolated-sphere limit: at s = 1e3 the stresslet of each sphere is (20/3) pi E (Einstein;
!      S_xy = (10/3) pi), and both spheres rotate at -1/2 (1e-6, the O(s^-3) corrections).
!   4. K = ZM11 + ZM12 - 1 at contact is -0.04721 (doc/METHOD.md §9.2, from the near-field constants
!      1.025097 - 0.072311 - 1): evaluated at xi = 1e-10, within 1e-5.
program test_resistance_pair_stresslet
  use mod_kinds, only: dp, pi
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars
  use mod_resistance_blocks, only: pair_resistance_fu, pair_resistance_fe, pair_stresslets
  use mod_pair_mobility, only: pair_shear_functions
  use mod_unit_checks, only: check_below, finish
  implicit none
  real(dp), parameter :: gaps(7) = [1.0e-4_dp, 1.0e-3_dp, 0.01_dp, 0.1_dp, 0.5_dp, 1.5_dp, 5.0_dp]
  real(dp), parameter :: e_shear(3, 3) = reshape([0.0_dp, 0.5_dp, 0.0_dp, 0.5_dp, 0.0_dp, 0.0_dp, &
                                                  0.0_dp, 0.0_dp, 0.0_dp], [3, 3])
  real(dp), parameter :: s_inf = 20.0_dp / 3.0_dp * pi
  real(dp) :: f(n_pair_scalars), d(3), w(12), s(3, 3, 2), r(3), vrel(3), vbg(3), er(3)
  real(dp) :: a, b, c, kk, l, m, t, n1, n2, n1_bg, n2_bg, worst_n, worst_v, err_iso, rho
  integer :: i, j

  worst_n = 0.0_dp
  worst_v = 0.0_dp
  do i = 1, size(gaps)
    call pair_shear_functions(gaps(i), a, b, c, kk, l, m)
    f = resistance_scalars(gaps(i))
    rho = 2.0_dp + gaps(i)
    do j = 1, 7
      t = pi * (j - 0.5_dp) / 7.0_dp
      d = [cos(t), sin(t), 0.0_dp]
      call free_pair(f, d, w)
      s = pair_stresslets(f, d, w, e_shear, 1.0_dp, 1.0_dp)
      n1 = 2.0_dp * (s(1, 1, 1) - s(2, 2, 1)) / s_inf
      n2 = 2.0_dp * (s(2, 2, 1) - s(3, 3, 1)) / s_inf
      n1_bg = m * sin(2 * t) * cos(2 * t)
      n2_bg = sin(2 * t) * (l + m * sin(t)**2)
      worst_n = max(worst_n, abs(n1 - n1_bg) / max(abs(n1_bg), 1.0e-3_dp), &
                    abs(n2 - n2_bg) / max(abs(n2_bg), 1.0e-3_dp))
      ! relative velocity U_2 - U_1, spheres at -r/2 and r/2, u^inf = (y, 0, 0)
      r = rho * d
      vrel = [r(2), 0.0_dp, 0.0_dp] - (w(7:9) - w(1:3))
      er = matmul(e_shear, r)
      vbg = [r(2), 0.0_dp, 0.0_dp] - (a * dot_product(d, er) * d + b * (er - dot_product(d, er) * d))
      worst_v = max(worst_v, norm2(vrel - vbg) / norm2(vbg))
    end do
  end do
  call check_below('1. N1*, N2*: general blocks vs Batchelor-Green closed forms', worst_n, 1.0e-9_dp)
  call check_below('2. relative velocity vs Batchelor-Green A, B form', worst_v, 1.0e-12_dp)

  f = resistance_scalars(998.0_dp)
  d = [cos(0.3_dp), sin(0.3_dp), 0.0_dp]
  call free_pair(f, d, w)
  s = pair_stresslets(f, d, w, e_shear, 1.0_dp, 1.0_dp)
  ! Om_a = Om^inf - w(4:6), Om^inf - w(10:12): rotation with the fluid means w = 0 there.
  err_iso = max(maxval(abs(s(:, :, 1) - s_inf * e_shear)) / (s_inf / 2), &
                maxval(abs(w(4:6))), maxval(abs(w(10:12))))
  call check_below('3. isolated spheres: S = (20/3) pi E and Om = -1/2', err_iso, 1.0e-6_dp)

  call pair_shear_functions(1.0e-10_dp, a, b, c, kk, l, m)
  print '(a,f10.6)', '   K at xi = 1e-10: ', kk
  call check_below('4. K(contact) = -0.04721', abs(kk + 0.04721_dp), 1.0e-5_dp)

  call finish('test_resistance_pair_stresslet')

contains

  !> w = U^inf - U of the force- and torque-free pair: R_FU . w = -R_FE : E.
  subroutine free_pair(f, d, w)
    real(dp), intent(in) :: f(n_pair_scalars), d(3)
    real(dp), intent(out) :: w(12)
    real(dp) :: rfu(12, 12), rfe(12, 3, 3), rhs(12)
    integer :: k
    rfu = pair_resistance_fu(f, d, 1.0_dp, 1.0_dp)
    rfe = pair_resistance_fe(f, d, 1.0_dp, 1.0_dp)
    do k = 1, 12
      rhs(k) = -sum(rfe(k, :, :) * e_shear)
    end do
    w = solve(rfu, rhs)
  end subroutine free_pair

  !> Gaussian elimination with partial pivoting.
  function solve(a_in, b_in) result(x)
    real(dp), intent(in) :: a_in(:, :), b_in(:)
    real(dp) :: x(size(b_in)), am(size(b_in), size(b_in)), bm(size(b_in)), tmp(size(b_in)), tb, fac
    integer :: ii, jj, p, nn
    nn = size(b_in)
    am = a_in
    bm = b_in
    do ii = 1, nn
      p = maxloc(abs(am(ii:nn, ii)), 1) + ii - 1
      tmp = am(ii, :); am(ii, :) = am(p, :); am(p, :) = tmp
      tb = bm(ii); bm(ii) = bm(p); bm(p) = tb
      do jj = ii + 1, nn
        fac = am(jj, ii) / am(ii, ii)
        am(jj, :) = am(jj, :) - fac * am(ii, :)
        bm(jj) = bm(jj) - fac * bm(ii)
      end do
    end do
    do ii = nn, 1, -1
      x(ii) = (bm(ii) - sum(am(ii, ii + 1:nn) * x(ii + 1:nn))) / am(ii, ii)
    end do
  end function solve

end program test_resistance_pair_stresslet
