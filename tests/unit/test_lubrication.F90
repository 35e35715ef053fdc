! Invariants of the subgrid lubrication kernels (mod_lubrication), checked against the exact
! forms of mod_pair_resistance and against symmetries, without the DNS:
!  1. simple model: the squeeze combination XA11 - XA12 equals the singular difference
!     [1/(2 xi) + (9/20) ln(1/xi)] - [same at xi_c] inside the cut-off (1e-12: the same formula
!     evaluated two ways), is held below the saturation gap, and is zero beyond xi_c;
!  2. co-translation along the line of centres is not resisted (the singular terms of XA11 and
!     XA12 cancel): |F| < 1e-12 of the squeeze force at the same gap;
!  3. the correction vanishes beyond the outer cut-off and is continuous there (the C1 taper:
!     value below 1e-12 just inside, no jump larger than the local slope allows);
!  4. full model: a table whose resolved part equals the exact pair part gives no correction
!     (1e-12), and a zero table gives exactly the exact pair part minus the one-body part;
!  5. every 12x12 pair block is symmetric and positive semi-definite for gaps 1e-6 .. outer
!     (smallest eigenvalue >= -1e-10 of the largest), for both models, also with a table that
!     over-resolves (clip_to_psd at work);
!  6. clip_to_psd leaves a positive definite matrix unchanged (1e-12) and returns the nearest
!     PSD matrix otherwise (its negative eigenvalue removed, the rest kept to 1e-10); with a floor
!     the smallest eigenvalue becomes the floor (the wall blocks' allowance); a non-finite block
!     gives a status and NaN instead of stopping the program (the caller reports it);
!  7. wall link: a sphere moving with the wall feels no correction (drive = R.(u_wall, 0));
!     the simple normal function equals 1/e + ln(1/e)/5 minus its value at the cut-off;
!  8. pair stresslet: symmetric, and its trace is a d.F_1 for a squeeze (doc/METHOD.md §5.9).
program test_lubrication
  use mod_kinds, only: dp
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars, i_xa11, i_xa12, i_ya11, i_xc11, &
       i_yc11, i_xm11, i_ym11, i_zm11, i_xm12, i_ym12, i_zm12
  use mod_lubrication, only: lubrication_t, lub_setup, lub_pair_scalars, lub_wall_scalars, lub_pair_link, &
       lub_wall_link, lub_pair_stresslets, clip_to_psd, LUB_SIMPLE, LUB_FULL
  use mod_unit_checks, only: check, finish, min_eig
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_nan
  implicit none
  integer :: info
  type(lubrication_t) :: simple, full
  integer :: k
  real(dp) :: f(n_pair_scalars), f_exact(n_pair_scalars), xi, expect, r(12, 12), drive(12), ft(12), d(3), u_inf(3, 2), e0(3, 3)
  real(dp) :: w(5), rw(6, 6), dw(6), gaps(40), worst, a(6, 6), b(6, 6), s(3, 3, 2), squeeze

  call lub_setup(simple, LUB_SIMPLE, 1.0_dp, 1.0_dp, 5.0_dp, 0.0_dp, 1.0e-4_dp)
  d = [1.0_dp, 2.0_dp, 2.0_dp] / 3.0_dp
  u_inf = 0
  e0 = 0

  ! 1. simple squeeze function
  do k = 1, 3
    xi = 0.05_dp * k
    f = lub_pair_scalars(simple, xi)
    expect = (sing(xi) - sing(simple%simple_cutoff))
    call check(abs((f(i_xa11) - f(i_xa12)) / lub_taper_at(simple, xi) - expect) < 1.0e-12_dp * expect, &
               'simple: XA11 - XA12 is the singular difference')
  end do
  f = lub_pair_scalars(simple, 0.001_dp)
  call check(abs(f(i_xa11) - f(i_xa12) - (sing(0.02_dp) - sing(simple%simple_cutoff))) < 1.0e-12_dp * f(i_xa11), &
             'simple: held below the saturation gap')
  call check(all(lub_pair_scalars(simple, 0.19_dp) == 0.0_dp), 'simple: zero beyond the cut-off')

  ! 2. co-translation along d
  call lub_pair_link(simple, lub_pair_scalars(simple, 0.01_dp), d, u_inf, [0.0_dp, 0.0_dp, 0.0_dp], e0, r, drive)
  ft = drive - matmul(r, [d, 0.0_dp, 0.0_dp, 0.0_dp, d, 0.0_dp, 0.0_dp, 0.0_dp])
  squeeze = norm2(matmul(r, [d, 0.0_dp, 0.0_dp, 0.0_dp, -d, 0.0_dp, 0.0_dp, 0.0_dp]))
  call check(norm2(ft(1:3)) < 1.0e-12_dp * squeeze .and. norm2(ft(7:9)) < 1.0e-12_dp * squeeze, &
             'simple: co-translation along d is free')

  ! 3. taper to zero at the outer cut-off
  f = lub_pair_scalars(simple, simple%outer_cutoff * (1.0_dp - 1.0e-9_dp))
  call check(maxval(abs(f)) < 1.0e-12_dp, 'simple: continuous at the outer cut-off')

  ! 4. full model with synthetic tables
  do k = 1, 40
    gaps(k) = 1.0e-3_dp * 1.2_dp**(k - 1)
  end do
  call full_with_table(exact_pair_part=.true.)
  worst = 0
  do k = 1, 40, 3
    worst = max(worst, maxval(abs(lub_pair_scalars(full, gaps(k)))))
  end do
  call check(worst < 1.0e-12_dp, 'full: resolved = exact gives no correction')
  call full_with_table(exact_pair_part=.false.)
  xi = 0.05_dp
  f = resistance_scalars(xi)
  expect = f(i_xa11) - 1.0_dp
  f = lub_pair_scalars(full, xi)
  call check(abs(f(i_xa11) - expect) < 1.0e-12_dp * expect, &
             'full: zero table gives exact minus one-body')
  f_exact = resistance_scalars(xi)
  expect = f_exact(i_xm11) + f_exact(i_xm12) - 1.0_dp
  call check(abs(f(i_xm11) - expect) < 1.0e-12_dp, &
             'full: M carried as the sum M11 + M12')

  ! 5. PSD pair blocks; the full table made to over-resolve (resolved = 1.3 x exact) needs clipping
  call check(psd_everywhere(simple), 'simple: pair blocks symmetric PSD for gaps 1e-6 .. outer')
  call check(psd_everywhere(full), 'full: pair blocks symmetric PSD for gaps 1e-6 .. outer')
  call full_with_table(exact_pair_part=.true., factor=1.3_dp)
  call check(psd_everywhere(full), 'full, over-resolved table: clipped to PSD')

  ! 6. clip_to_psd
  a = spd6()
  call check(maxval(abs(clip_to_psd(a) - a)) < 1.0e-12_dp * maxval(abs(a)), 'clip_to_psd: SPD unchanged')
  b = a - 2.0_dp * min_eig(a) * identity6() - 3.0_dp * outer6()
  a = b
  b = clip_to_psd(a)
  call check(min_eig(b) > -1.0e-10_dp * maxval(abs(b)), 'clip_to_psd: result PSD')
  b = clip_to_psd(a, -0.5_dp)
  call check(abs(min_eig(b) + 0.5_dp) < 1.0e-10_dp * maxval(abs(b)), 'clip_to_psd: eigenvalues raised to the floor')
  ! a block LAPACK cannot decompose (non-finite) returns a status and NaN, the run is not stopped here
  a(2, 3) = ieee_value(1.0_dp, ieee_quiet_nan)
  a(3, 2) = a(2, 3)
  b = clip_to_psd(a, info=info)
  call check(info /= 0 .and. all(ieee_is_nan(b)), 'clip_to_psd: a non-finite block gives a status and NaN, no stop')

  ! 7. wall link
  w = lub_wall_scalars(simple, 0.01_dp)
  expect = (1.0_dp / 0.02_dp + 0.2_dp * log(50.0_dp)) - (1.0_dp / simple%simple_cutoff + 0.2_dp * log(1.0_dp / simple%simple_cutoff))
  call check(abs(w(1) - expect) < 1.0e-12_dp * expect, 'wall simple: normal function (held at the saturation gap)')
  call lub_wall_link(simple, w, [0.0_dp, 1.0_dp, 0.0_dp], [3.0_dp, 0.0_dp, 0.5_dp], rw, dw)
  call check(norm2(dw - matmul(rw, [3.0_dp, 0.0_dp, 0.5_dp, 0.0_dp, 0.0_dp, 0.0_dp])) < 1.0e-12_dp * norm2(dw), &
             'wall: a sphere moving with the wall feels nothing')

  ! 8. squeeze stresslet: trace = a d.F_1
  f = lub_pair_scalars(simple, 0.01_dp)
  call lub_pair_link(simple, f, d, u_inf, [0.0_dp, 0.0_dp, 0.0_dp], e0, r, drive)
  ft = -matmul(r, [d, 0.0_dp, 0.0_dp, 0.0_dp, -d, 0.0_dp, 0.0_dp, 0.0_dp])
  s = lub_pair_stresslets(simple, f, d, [-d, 0.0_dp, 0.0_dp, 0.0_dp, d, 0.0_dp, 0.0_dp, 0.0_dp], e0)
  call check(abs(s(1, 1, 1) + s(2, 2, 1) + s(3, 3, 1) - dot_product(d, ft(1:3))) < 1.0e-10_dp * norm2(ft(1:3)), &
             'pair stresslet: trace = a d.F_1 for a squeeze')
  call check(maxval(abs(s(:, :, 1) - transpose(s(:, :, 1)))) < 1.0e-12_dp * maxval(abs(s)), 'pair stresslet: symmetric')

  call finish('test_lubrication')

contains

  ! g1/xi + g2 ln(1/xi) of XA11 - XA12 (doc/METHOD.md §5.2)
  real(dp) function sing(x)
    real(dp), intent(in) :: x
    sing = 0.5_dp / x + 0.45_dp * log(1.0_dp / x)
  end function sing

  real(dp) function lub_taper_at(lub, x)
    type(lubrication_t), intent(in) :: lub
    real(dp), intent(in) :: x
    real(dp) :: s
    s = (lub%outer_cutoff - x) / (0.3_dp * lub%outer_cutoff)
    lub_taper_at = 1.0_dp
    if (s < 1.0_dp) lub_taper_at = s * s * (3.0_dp - 2.0_dp * s)
  end function lub_taper_at

  ! full model on the 40 gaps with resolved part = factor x (exact pair part), or zero
  subroutine full_with_table(exact_pair_part, factor)
    logical, intent(in) :: exact_pair_part
    real(dp), intent(in), optional :: factor
    real(dp) :: g(n_pair_scalars), scale
    integer :: k
    scale = 1.0_dp
    if (present(factor)) scale = factor
    full%pair_gap = gaps
    full%wall_gap = gaps
    if (allocated(full%pair_resolved)) deallocate(full%pair_resolved, full%wall_resolved)
    allocate(full%pair_resolved(40, n_pair_scalars), full%wall_resolved(40, 5))
    full%pair_resolved = 0
    full%wall_resolved = 0
    if (exact_pair_part) then
      do k = 1, 40
        g = resistance_scalars(gaps(k))
        g([i_xa11, i_ya11, i_xc11, i_yc11, i_xm11, i_ym11, i_zm11]) = &
          g([i_xa11, i_ya11, i_xc11, i_yc11, i_xm11, i_ym11, i_zm11]) - 1.0_dp
        g([i_xm11, i_ym11, i_zm11]) = g([i_xm11, i_ym11, i_zm11]) + g([i_xm12, i_ym12, i_zm12])
        g([i_xm12, i_ym12, i_zm12]) = 0
        full%pair_resolved(k, :) = scale * g
      end do
    end if
    call lub_setup(full, LUB_FULL, 1.0_dp, 1.0_dp, 5.0_dp, 1.0_dp, 1.0e-4_dp)
  end subroutine full_with_table

  logical function psd_everywhere(lub)
    type(lubrication_t), intent(in) :: lub
    real(dp) :: x, rr(12, 12), dr(12), ev
    integer :: k
    psd_everywhere = .true.
    do k = 0, 60
      x = 1.0e-6_dp * (lub%outer_cutoff / 1.0e-6_dp)**(k / 60.0_dp)
      call lub_pair_link(lub, lub_pair_scalars(lub, x), d, u_inf, [0.0_dp, 0.0_dp, 0.0_dp], e0, rr, dr)
      ev = min_eig(rr)
      if (ev < -1.0e-10_dp * maxval(abs(rr)) .or. maxval(abs(rr - transpose(rr))) > 1.0e-12_dp * maxval(abs(rr))) then
        print '(a,es10.3,a,es10.3)', '  gap ', x, ': smallest eigenvalue ', ev
        psd_everywhere = .false.
      end if
    end do
  end function psd_everywhere

  function spd6() result(m)
    real(dp) :: m(6, 6), g(6, 6)
    integer :: p, q
    do q = 1, 6
      do p = 1, 6
        g(p, q) = sin(1.7_dp * p + 0.3_dp * q * q)
      end do
    end do
    m = matmul(g, transpose(g)) + identity6()
  end function spd6

  function identity6() result(m)
    real(dp) :: m(6, 6)
    integer :: p
    m = 0
    do p = 1, 6
      m(p, p) = 1
    end do
  end function identity6

  function outer6() result(m)
    real(dp) :: m(6, 6), v(6)
    v = [1.0_dp, -1.0_dp, 0.5_dp, 0.0_dp, 2.0_dp, 1.0_dp]
    m = spread(v, 2, 6) * spread(v, 1, 6)
  end function outer6


end program test_lubrication
