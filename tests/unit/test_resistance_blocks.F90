! Unit test: the pair resistance blocks FU, FE, SU, SE of mod_resistance_blocks (doc/METHOD.md §5.1, §5.7).
! Invariants (none of them is produced by the code itself: each is a theorem of Stokes flow or an
! identity of the tensor algebra):
!   1. R_FU (12x12) is symmetric (Lorentz reciprocity) and positive definite (dissipation is
!      positive) at 61 gaps from 1e-6 to 10, for random line-of-centre directions: Cholesky
!      succeeds and the smallest pivot is > 0. Symmetry tolerance 1e-12 relative (round-off).
!   2. Reciprocity of the coupling blocks: R_FE(m, j, k) = R_SU(j, k, alpha, m) summed over the
!      stresslet of the grand matrix, i.e. sum_jk R_FE(m,j,k) E_jk = sum_jk E_jk R_SU(j,k,.,m)
!      for symmetric traceless E (1e-12 relative).
!   3. The written-out contractions of doc/METHOD.md §5.7 (pair_force_torque_from_strain,
!      pair_stresslets) equal the general tensor forms (R_FE : E, R_SU . w + R_SE : E) (1e-12).
!   4. M basis: with XM = YM = ZM = 1, M : E = E for any symmetric traceless E, both for the
!      fourth-rank tensor (R_SE) and for the contraction formulas strain_d0 + d1 + d2 (1e-13).
!   5. Equal-sphere symmetry: under exchange of the spheres (d -> -d), forces and torques
!      induced by E are exchanged: F_2(d) = F_1(-d), T_2(d) = T_1(-d) (1e-12).
!   6. Block assembly: a pair co-translating at velocity u through still fluid feels a total
!      force F_1 + F_2 = -2 (6 pi a) [(XA11 + XA12) dd + (YA11 + YA12)(I - dd)] . u. Tolerance
!      1e-9: at gap 1e-6 XA11 ~ 2.5e5 cancels against XA12 to leave 0.65 (round-off ~ 1e-10).
! Random directions and strains use a fixed seed (reproducible).
program test_resistance_blocks
  use mod_kinds, only: dp, pi
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars, i_xa11, i_xa12, i_ya11, i_ya12
  use mod_resistance_blocks, only: pair_resistance_fu, pair_resistance_fe, pair_resistance_su, &
       pair_resistance_se, pair_force_torque_from_strain, pair_stresslets, strain_d0, strain_d1, &
       strain_d2
  use mod_unit_checks, only: failures, check_below, finish
  implicit none
  integer :: k, l, alpha, ntrial, nseed
  integer, allocatable :: seed(:)
  real(dp) :: gap, d(3), f(n_pair_scalars), r(12, 12), fe(12, 3, 3), su(3, 3, 2, 12)
  real(dp) :: se(3, 3, 2, 3, 3), e(3, 3), w(12), ft(12), ft2(12), s1(3, 3, 2), s2(3, 3, 2)
  real(dp) :: worst_sym, min_pivot, worst_recip, worst_contr, worst_m, worst_swap, worst_rigid
  real(dp) :: ones(n_pair_scalars), m4(3, 3), pivot, a(3), u(3)
  real(dp) :: fe_swap(12, 3, 3)

  worst_sym = 0; min_pivot = huge(1.0_dp); worst_recip = 0; worst_contr = 0; worst_m = 0
  worst_swap = 0; worst_rigid = 0
  call random_seed(size=nseed)
  allocate(seed(nseed))
  seed = 20260331
  call random_seed(put=seed)
  ntrial = 0
  do k = 0, 60
    gap = 10.0_dp**(-6.0_dp + 7.0_dp * k / 60.0_dp)
    f = resistance_scalars(gap)
    do l = 1, 3
      ntrial = ntrial + 1
      call random_number(a)
      d = a - 0.5_dp
      d = d / norm2(d)
      r = pair_resistance_fu(f, d, 1.0_dp, 1.0_dp)
      worst_sym = max(worst_sym, maxval(abs(r - transpose(r))) / maxval(abs(r)))
      call cholesky_min_pivot(r, pivot)
      min_pivot = min(min_pivot, pivot)
      ! Random strain (symmetric traceless) and velocities.
      e = random_strain()
      call random_number(w)
      w = w - 0.5_dp
      fe = pair_resistance_fe(f, d, 1.0_dp, 1.0_dp)
      su = pair_resistance_su(f, d, 1.0_dp, 1.0_dp)
      se = pair_resistance_se(f, d, 1.0_dp, 1.0_dp)
      ! 2. reciprocity: w . (R_FE : E) = sum_alpha S_alpha(w) : E
      ft = contract_fe(fe, e)
      s1 = contract_su(su, w)
      worst_recip = max(worst_recip, abs(dot_product(w, ft) - sum(s1(:, :, 1) * e) &
                                         - sum(s1(:, :, 2) * e)) / max(norm2(ft) * norm2(w), 1e-300_dp))
      ! 3. written-out contractions vs tensor forms
      ft2 = pair_force_torque_from_strain(f, d, e, 1.0_dp, 1.0_dp)
      worst_contr = max(worst_contr, maxval(abs(ft2 - ft)) / max(maxval(abs(ft)), 1e-300_dp))
      s2 = pair_stresslets(f, d, w, e, 1.0_dp, 1.0_dp)
      do alpha = 1, 2
        s1(:, :, alpha) = s1(:, :, alpha) + contract_se(se(:, :, alpha, :, :), e)
      end do
      worst_contr = max(worst_contr, maxval(abs(s2 - s1)) / maxval(abs(s1)))
      ! 5. exchange symmetry
      fe_swap = pair_resistance_fe(f, -d, 1.0_dp, 1.0_dp)
      ft2 = contract_fe(fe_swap, e)
      worst_swap = max(worst_swap, maxval(abs(ft2(1:6) - ft(7:12))) / maxval(abs(ft)))
      ! 6. rigid co-translation with velocity u relative to still fluid: w = (-u, 0, -u, 0)
      call random_number(u)
      w = 0.0_dp
      w(1:3) = -u
      w(7:9) = -u
      ft = matmul(r, w)
      ft2(1:3) = -6.0_dp * pi * ((f(i_xa11) + f(i_xa12)) * dot_product(d, u) * d &
                                 + (f(i_ya11) + f(i_ya12)) * (u - dot_product(d, u) * d))
      worst_rigid = max(worst_rigid, maxval(abs(ft(1:3) + ft(7:9) - 2.0_dp * ft2(1:3))) &
                                      / maxval(abs(ft2(1:3))))
    end do
  end do
  ! 4. M basis with unit scalars
  ones = 0.0_dp
  ones([9, 10, 11]) = 1.0_dp
  do l = 1, 5
    call random_number(a)
    d = (a - 0.5_dp) / norm2(a - 0.5_dp)
    e = random_strain()
    se = pair_resistance_se(ones, d, 1.0_dp, 3.0_dp / (20.0_dp * pi))
    m4 = contract_se(se(:, :, 1, :, :), e)
    worst_m = max(worst_m, maxval(abs(m4 - e)))
    m4 = strain_d0(d, e) + strain_d1(d, e) + strain_d2(d, e)
    worst_m = max(worst_m, maxval(abs(m4 - e)))
  end do

  print '(a,i0,a)', 'R_FU at 61 gaps in [1e-6, 10] x 3 directions (', ntrial, ' matrices):'
  call check_below('max |R - R^T| / max |R|', worst_sym, 1.0e-12_dp)
  call report_pd(min_pivot)
  call check_below('reciprocity w.(R_FE:E) = sum_a S_a(w):E', worst_recip, 1.0e-12_dp)
  call check_below('written-out contractions = tensor forms', worst_contr, 1.0e-12_dp)
  call check_below('M basis with X=Y=Z=1 is the identity on traceless E', worst_m, 1.0e-13_dp)
  call check_below('exchange symmetry of R_FE : E', worst_swap, 1.0e-12_dp)
  call check_below('co-translation force from the assembled R_FU', worst_rigid, 1.0e-9_dp)
  call finish('test_resistance_blocks')

contains

  function random_strain() result(e)
    real(dp) :: e(3, 3), b(3, 3)
    integer :: i
    call random_number(b)
    e = 0.5_dp * (b + transpose(b))
    do i = 1, 3
      e(i, i) = e(i, i) - (b(1, 1) + b(2, 2) + b(3, 3)) / 3.0_dp
    end do
  end function random_strain

  function contract_fe(fe, e) result(ft)
    real(dp), intent(in) :: fe(12, 3, 3), e(3, 3)
    real(dp) :: ft(12)
    integer :: m
    do m = 1, 12
      ft(m) = sum(fe(m, :, :) * e)
    end do
  end function contract_fe

  function contract_su(su, w) result(s)
    real(dp), intent(in) :: su(3, 3, 2, 12), w(12)
    real(dp) :: s(3, 3, 2)
    integer :: m
    s = 0.0_dp
    do m = 1, 12
      s = s + su(:, :, :, m) * w(m)
    end do
  end function contract_su

  function contract_se(se, e) result(s)
    real(dp), intent(in) :: se(3, 3, 3, 3), e(3, 3)
    real(dp) :: s(3, 3)
    integer :: i, j
    do j = 1, 3
      do i = 1, 3
        s(i, j) = sum(se(i, j, :, :) * e)
      end do
    end do
  end function contract_se

  !> Cholesky factorisation; returns the smallest pivot relative to the largest diagonal entry
  !> (negative or zero if the matrix is not positive definite).
  subroutine cholesky_min_pivot(a_in, pmin)
    real(dp), intent(in) :: a_in(:, :)
    real(dp), intent(out) :: pmin
    real(dp) :: a(size(a_in, 1), size(a_in, 2)), piv
    integer :: n, jj, ii
    a = a_in
    n = size(a, 1)
    pmin = huge(1.0_dp)
    do jj = 1, n
      piv = a(jj, jj) - sum(a(jj, 1:jj - 1)**2)
      pmin = min(pmin, piv / maxval([(a_in(ii, ii), ii = 1, n)]))
      if (piv <= 0.0_dp) return
      a(jj, jj) = sqrt(piv)
      do ii = jj + 1, n
        a(ii, jj) = (a(ii, jj) - sum(a(ii, 1:jj - 1) * a(jj, 1:jj - 1))) / a(jj, jj)
      end do
    end do
  end subroutine cholesky_min_pivot

  subroutine report_pd(p)
    real(dp), intent(in) :: p
    if (p > 0.0_dp) then
      print '(a,es10.3)', '   PASS positive definite (Cholesky); smallest relative pivot ', p
    else
      print '(a,es10.3)', '   FAIL not positive definite; smallest relative pivot ', p
      failures = failures + 1
    end if
  end subroutine report_pd

end program test_resistance_blocks
