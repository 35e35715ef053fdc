! Unit test: the resistance blocks of two UNEQUAL spheres (pair_resistance_*_sized,
! pair_stresslets_sized of mod_resistance_blocks) built from the scalars of
! mod_pair_resistance_unequal with Jeffrey & Onishi's (1984) block scaling (doc/RESISTANCE.md
! "Unequal spheres"): the hydrodynamics of bin/pairtraj for size_ratio /= 1.
! Invariants:
!   1. lambda = 1: the sized R_FU, R_FE, R_SU equal the equal-sphere blocks bitwise (the factors
!      3 pi (2a), pi (2a)^2, pi (2a)^3 are the equal-sphere 6 pi a, 4 pi a^2, 8 pi a^3 times
!      powers of two, exact in binary); the stresslets to round-off (1e-13 relative: (5/6) pi 8
!      rounds differently from (20/3) pi).
!   2. lambda = 0.1, 0.5, 1.4, 2, 10 at 25 gaps 1e-6 .. 100, random directions: R_FU symmetric
!      (Lorentz reciprocity, 1e-12 relative) and positive definite (Cholesky); the coupling blocks
!      reciprocal, w . (R_FE : E) = sum_a S_a(w) : E (1e-12). Symmetry across the 11/12/21/22
!      blocks holds only if the 21 scalars and the (a_a + a_b) factors are consistent.
!   3. Relabelling: the pair (1, lambda) seen with the spheres swapped is the pair (lambda, 1)
!      with d -> -d and the scalars at 1/lambda; R_FU, R_FE : E and the stresslets of one, with
!      the sphere blocks permuted, equal those of the other (1e-12 relative; round-off).
!   4. Far field of a force- and torque-free pair in simple shear: the relative velocity is the
!      affine E.r + Om x r minus [A dd + B(I - dd)].E.r with A -> (5/2)(a1^3 + a2^3)/r^3 (each
!      sphere convected by the other's Einstein stresslet, u = -(5/2) a^3 x (x.E.x)/|x|^5;
!      Batchelor & Green 1972 for a1 = a2), B = O(r^-5): checked at gaps xi = 10, 20, 40, 80 for
!      lambda = 2 and 0.5, d in the shear plane at 30 degrees (E.d has both parts); the relative
!      error of A r^3 must fall like r^-2 (next term of the far-field series; ratio >= 3 per
!      doubling of r, observed 3.1 .. 3.7) and be < 2e-3 at xi = 40, and |B| r^3 must fall
!      likewise (>= 3 per doubling) and be < 1e-2 at xi = 80.
program test_resistance_unequal_blocks
  use mod_kinds, only: dp, pi
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars
  use mod_pair_resistance_unequal, only: sized_pair_scalars, sized_pair_scalars_22
  use mod_resistance_blocks, only: pair_resistance_fu, pair_resistance_fe, pair_resistance_su, &
       pair_stresslets, pair_resistance_fu_sized, pair_resistance_fe_sized, &
       pair_resistance_su_sized, pair_stresslets_sized
  use mod_unit_checks, only: check, check_below, finish
  implicit none
  real(dp), parameter :: lambdas(5) = [0.1_dp, 0.5_dp, 1.4_dp, 2.0_dp, 10.0_dp]
  real(dp), parameter :: shear(3, 3) = reshape([0.0_dp, 0.5_dp, 0.0_dp, 0.5_dp, 0.0_dp, 0.0_dp, &
                                                0.0_dp, 0.0_dp, 0.0_dp], [3, 3])
  integer :: k, l, il, nseed, perm(12)
  integer, allocatable :: seed(:)
  real(dp) :: gap, lam, d(3), f(n_pair_scalars), f2(n_pair_scalars), g(n_pair_scalars)
  real(dp) :: g2(n_pair_scalars), r(12, 12), rb(12, 12), fe(12, 3, 3), feb(12, 3, 3)
  real(dp) :: su(3, 3, 2, 12), e(3, 3), w(12), ft(12), ftb(12), s1(3, 3, 2), s2(3, 3, 2)
  real(dp) :: worst_sym, min_pivot, worst_recip, worst_swap, pivot, diff_equal, diff_stress
  real(dp) :: a_err(4, 2), b_far(4, 2), a_exp, rho, v(3), dev_a, t_e(3), ded

  call random_seed(size=nseed)
  allocate(seed(nseed))
  seed = 20260612
  call random_seed(put=seed)
  perm = [7, 8, 9, 10, 11, 12, 1, 2, 3, 4, 5, 6]

  ! 1. lambda = 1
  diff_equal = 0.0_dp
  diff_stress = 0.0_dp
  do k = 0, 20
    gap = 10.0_dp**(-6.0_dp + 8.0_dp * k / 20.0_dp)
    d = random_direction()
    f = resistance_scalars(gap)
    f2 = sized_pair_scalars_22(gap, 1.0_dp)
    e = random_strain()
    call random_number(w)
    diff_equal = max(diff_equal, maxval(abs(pair_resistance_fu_sized(f, f2, d, 1.0_dp, 1.0_dp, 1.0_dp) &
                                            - pair_resistance_fu(f, d, 1.0_dp, 1.0_dp))))
    diff_equal = max(diff_equal, maxval(abs(pair_resistance_fe_sized(f, f2, d, 1.0_dp, 1.0_dp, 1.0_dp) &
                                            - pair_resistance_fe(f, d, 1.0_dp, 1.0_dp))))
    diff_equal = max(diff_equal, maxval(abs(pair_resistance_su_sized(f, f2, d, 1.0_dp, 1.0_dp, 1.0_dp) &
                                            - pair_resistance_su(f, d, 1.0_dp, 1.0_dp))))
    s1 = pair_stresslets(f, d, w, e, 1.0_dp, 1.0_dp)
    s2 = pair_stresslets_sized(f, f2, d, w, e, 1.0_dp, 1.0_dp, 1.0_dp)
    diff_stress = max(diff_stress, maxval(abs(s2 - s1)) / maxval(abs(s1)))
  end do
  call check(diff_equal == 0.0_dp, 'lambda = 1: sized R_FU, R_FE, R_SU bitwise the equal-sphere blocks')
  call check_below('lambda = 1: sized stresslets vs equal-sphere, relative', diff_stress, 1.0e-13_dp)

  ! 2. and 3.
  worst_sym = 0.0_dp
  min_pivot = huge(1.0_dp)
  worst_recip = 0.0_dp
  worst_swap = 0.0_dp
  do il = 1, size(lambdas)
    lam = lambdas(il)
    do k = 0, 24
      gap = 10.0_dp**(-6.0_dp + 8.0_dp * k / 24.0_dp)
      f = sized_pair_scalars(gap, lam)
      f2 = sized_pair_scalars_22(gap, lam)
      g = sized_pair_scalars(gap, 1.0_dp / lam)
      g2 = sized_pair_scalars_22(gap, 1.0_dp / lam)
      do l = 1, 2
        d = random_direction()
        r = pair_resistance_fu_sized(f, f2, d, 1.0_dp, lam, 1.0_dp)
        worst_sym = max(worst_sym, maxval(abs(r - transpose(r))) / maxval(abs(r)))
        call cholesky_min_pivot(r, pivot)
        min_pivot = min(min_pivot, pivot)
        e = random_strain()
        call random_number(w)
        w = w - 0.5_dp
        fe = pair_resistance_fe_sized(f, f2, d, 1.0_dp, lam, 1.0_dp)
        su = pair_resistance_su_sized(f, f2, d, 1.0_dp, lam, 1.0_dp)
        ft = contract_fe(fe, e)
        s1 = contract_su(su, w)
        worst_recip = max(worst_recip, abs(dot_product(w, ft) - sum(s1(:, :, 1) * e) &
                                           - sum(s1(:, :, 2) * e)) / (norm2(ft) * norm2(w)))
        ! Relabelled: sphere 1 of radius lambda, sphere 2 of radius 1, d reversed.
        rb = pair_resistance_fu_sized(g, g2, -d, lam, 1.0_dp, 1.0_dp)
        worst_swap = max(worst_swap, maxval(abs(rb(perm, perm) - r)) / maxval(abs(r)))
        feb = pair_resistance_fe_sized(g, g2, -d, lam, 1.0_dp, 1.0_dp)
        ftb = contract_fe(feb, e)
        worst_swap = max(worst_swap, maxval(abs(ftb(perm) - ft)) / maxval(abs(ft)))
        s1 = pair_stresslets_sized(f, f2, d, w, e, 1.0_dp, lam, 1.0_dp)
        s2 = pair_stresslets_sized(g, g2, -d, w(perm), e, lam, 1.0_dp, 1.0_dp)
        worst_swap = max(worst_swap, maxval(abs(s2(:, :, [2, 1]) - s1)) / maxval(abs(s1)))
      end do
    end do
  end do
  print '(a)', 'lambda = 0.1, 0.5, 1.4, 2, 10 at 25 gaps in [1e-6, 100] x 2 directions:'
  call check_below('max |R_FU - R_FU^T| / max |R_FU|', worst_sym, 1.0e-12_dp)
  call check(min_pivot > 0.0_dp, 'R_FU positive definite (Cholesky)')
  print '(a,es10.3)', '   smallest relative pivot ', min_pivot
  call check_below('reciprocity w.(R_FE:E) = sum_a S_a(w):E', worst_recip, 1.0e-12_dp)
  call check_below('relabelling (1, lambda, d) = (lambda, 1, -d), blocks permuted', worst_swap, &
                   1.0e-12_dp)

  ! 4. far field of the free pair, d in the shear plane at 30 degrees from the flow
  d = [cos(pi / 6.0_dp), sin(pi / 6.0_dp), 0.0_dp]
  ded = dot_product(d, matmul(shear, d))
  t_e = matmul(shear, d) - ded * d
  do il = 1, 2
    lam = merge(2.0_dp, 0.5_dp, il == 1)
    a_exp = 2.5_dp * (1.0_dp + lam**3)
    do k = 1, 4
      gap = 10.0_dp * 2.0_dp**(k - 1)
      rho = (gap + 2.0_dp) * (1.0_dp + lam) / 2.0_dp
      f = sized_pair_scalars(gap, lam)
      f2 = sized_pair_scalars_22(gap, lam)
      w = free_pair_w(f, f2, d, lam)
      ! U_2 - U_1 - (E.r + Om x r) = w_1 - w_2 = -[A dd + B (I - dd)].E.r
      v = w(1:3) - w(7:9)
      dev_a = -dot_product(d, v) / (ded * rho)
      a_err(k, il) = abs(dev_a * rho**3 / a_exp - 1.0_dp)
      b_far(k, il) = abs(dot_product(t_e, v)) / (dot_product(t_e, t_e) * rho) * rho**3
    end do
    print '(a,f4.1,a,4es10.2)', '   lambda = ', lam, ': |A r^3 / ((5/2)(1 + lambda^3)) - 1| at xi = 10, 20, 40, 80:', &
      a_err(:, il)
    call check(all(a_err(1:3, il) / a_err(2:4, il) >= 3.0_dp), &
               'far field: error of A r^3 falls like r^-2 (ratio >= 3 per doubling)')
    call check_below('far field: relative error of A r^3 at xi = 40', a_err(3, il), 2.0e-3_dp)
    print '(a,4es10.2)', '   |B| r^3 at xi = 10, 20, 40, 80:', b_far(:, il)
    call check(all(b_far(1:3, il) / b_far(2:4, il) >= 3.0_dp), &
               'far field: |B| r^3 falls like r^-2 (ratio >= 3 per doubling)')
    call check_below('far field: |B| r^3 at xi = 80', b_far(4, il), 1.0e-2_dp)
  end do
  call finish('test_resistance_unequal_blocks')

contains

  !> w = U^inf - U of a force- and torque-free pair (radii 1 and lam) in the shear, R_FU w = -R_FE:E.
  function free_pair_w(f, f2, d, lam) result(w)
    real(dp), intent(in) :: f(n_pair_scalars), f2(n_pair_scalars), d(3), lam
    real(dp) :: w(12), rfu(12, 12)
    integer :: info
    rfu = pair_resistance_fu_sized(f, f2, d, 1.0_dp, lam, 1.0_dp)
    w = -contract_fe(pair_resistance_fe_sized(f, f2, d, 1.0_dp, lam, 1.0_dp), shear)
    call dposv('U', 12, 1, rfu, 12, w, 12, info)
    if (info /= 0) call check(.false., 'dposv failed in the far-field solve')
  end function free_pair_w

  function random_direction() result(d)
    real(dp) :: d(3), b(3)
    call random_number(b)
    d = (b - 0.5_dp) / norm2(b - 0.5_dp)
  end function random_direction

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

  !> Smallest Cholesky pivot relative to the largest diagonal entry (<= 0: not positive definite).
  subroutine cholesky_min_pivot(a_in, pmin)
    real(dp), intent(in) :: a_in(:, :)
    real(dp), intent(out) :: pmin
    real(dp) :: m(size(a_in, 1), size(a_in, 2))
    integer :: info, i
    m = a_in
    call dpotrf('L', size(m, 1), m, size(m, 1), info)
    if (info /= 0) then
      pmin = -1.0_dp
      return
    end if
    pmin = huge(1.0_dp)
    do i = 1, size(m, 1)
      pmin = min(pmin, m(i, i)**2 / maxval(abs(a_in)))
    end do
  end subroutine cholesky_min_pivot

end program test_resistance_unequal_blocks
