! Unit test: the packings of mod_packing are equilibrium hard-sphere fluids (doc/PACKING_INPUT.md "Tests").
! Invariant: in a triply periodic box, the radial distribution function at contact g(2a) agrees
! within 5 % with the Carnahan-Starling value g_CS(2a) = (1 - phi/2)/(1 - phi)^3 (the contact
! value of its equation of state, Z = 1 + 4 phi g(2a), itself within 1 % of simulations for
! phi <= 0.5) at phi = 0.2, 0.3 and 0.4.
! Method: N = 2000 spheres, random_packing with 200 equilibration sweeps (g(2a) settles within
! ~100 sweeps at phi = 0.4), then 400 samples 4 sweeps apart. Pair counts in 10 shells of width
! 0.02a on [2a, 2.2a] (pairs from mod_neighbours, itself tested against an O(N^2) search) give
! g(r) per shell; ln g is fitted by a weighted quadratic in r - 2a at the shells' mean radii and
! g(2a) = exp(fit(0)). The statistical error is the standard error of the same estimate over 10
! consecutive blocks of 40 samples. Asserted: the block standard error is below 1.5 % (so that
! the 5 % check has at least a 3-sigma margin), and |g(2a)/g_CS - 1| < 5 %. The extrapolation
! bias is shown by a cubic fit over the same shells and a linear fit over [2a, 2.1a]: both are
! printed and must agree with the quadratic within 2 %.
program test_packing_gr
  use mod_kinds, only: dp, pi
  use mod_packing, only: rng_t, rng_seed, random_packing, hs_monte_carlo, packing_report_t, min_separation
  use mod_packing_geometry, only: packing_box_for
  use mod_neighbours, only: nlist_t, nlist_init, nlist_build
  use mod_unit_checks, only: check, finish
  implicit none
  integer, parameter :: n = 2000, nbin = 10, nsamp = 400, nblk = 10, gap_sweeps = 4
  real(dp), parameter :: dr = 0.02_dp
  real(dp), parameter :: phis(3) = [0.2_dp, 0.3_dp, 0.4_dp]
  integer :: k, info, s, b, m, ib
  real(dp), allocatable :: x(:,:)
  real(dp) :: box(3), step, acc, cnt(nbin, nblk), g0, g0b(nblk), se, gcs, r(3), d, t0, t1
  real(dp) :: g3, g1, pg, wg
  type(rng_t) :: g
  type(nlist_t) :: nl
  type(packing_report_t) :: rep
  character(len=200) :: msg

  do k = 1, size(phis)
    call cpu_time(t0)
    box = packing_box_for(n, phis(k), [1.0_dp, 1.0_dp, 1.0_dp], 1.0_dp)
    call random_packing(n, box, [.true., .true., .true.], 1.0_dp, 0.0_dp, 100 + k, 200, x, info, &
                        msg, rep)
    if (info /= 0) then
      print '(2a)', 'FAIL packing: ', trim(msg)
      error stop 1
    end if
    call nlist_init(nl, n, box, [.true., .true., .true.], 2 + nbin * dr, 1.0_dp, 0.0_dp, info)
    call rng_seed(g, 7 + k)
    step = rep%step
    cnt = 0
    do s = 1, nsamp
      call hs_monte_carlo(x, box, [.true., .true., .true.], 1.0_dp, g, step, gap_sweeps, .false., acc)
      call nlist_build(nl, x)
      b = 1 + (s - 1) / (nsamp / nblk)
      do m = 1, nl%npairs
        r = x(:, nl%pair(2, m)) - x(:, nl%pair(1, m)) + nl%shift(:, m) * box
        d = norm2(r)
        ib = int((d - 2) / dr) + 1
        if (ib >= 1 .and. ib <= nbin) cnt(ib, b) = cnt(ib, b) + 1
      end do
    end do
    call min_separation(x, box, [.true., .true., .true.], 1.0_dp, pg, wg)
    call check(pg >= 0, 'no overlap appeared during Monte Carlo')
    g0 = contact_value(sum(cnt, 2), nsamp, 2, nbin)
    g3 = contact_value(sum(cnt, 2), nsamp, 3, nbin)
    g1 = contact_value(sum(cnt, 2), nsamp, 1, nbin / 2)
    do b = 1, nblk
      g0b(b) = contact_value(cnt(:, b), nsamp / nblk, 2, nbin)
    end do
    se = sqrt(sum((g0b - sum(g0b) / nblk)**2) / (nblk - 1) / nblk)
    gcs = (1 - phis(k) / 2) / (1 - phis(k))**3
    call cpu_time(t1)
    print '(a,f4.2,a,f7.4,a,f7.4,a,f7.4,a,f7.4,a,f6.3,a,f6.2,a,f6.3,a,f5.1,a)', 'phi ', phis(k), &
      ': g(2a) = ', g0, ' +- ', se, ' (cubic ', g3, ', linear ', g1, '), CS ', gcs, &
      ', rel. diff ', 100 * (g0 / gcs - 1), ' %, MC step ', step, ' a (', t1 - t0, ' s)'
    call check(se <= 0.015_dp * gcs, 'statistical error at most 1.5 % (conclusive)')
    call check(abs(g0 / gcs - 1) <= 0.05_dp, 'g(2a) within 5 % of Carnahan-Starling')
    call check(abs(g3 / g0 - 1) <= 0.02_dp .and. abs(g1 / g0 - 1) <= 0.02_dp, &
               'extrapolation to contact depends on the fit by at most 2 %')
  end do

  call finish('test_packing_gr')

contains

  !> g(2a) from shell counts c(1:nb) accumulated over ns samples: ln g fitted by a polynomial of
  !> degree deg in r - 2a at the shells' volume-weighted mean radii, weights = counts (the
  !> variance of ln c is 1/c), value at r = 2a.
  real(dp) function contact_value(c, ns, deg, nb) result(g0v)
    real(dp), intent(in) :: c(:)
    integer, intent(in) :: ns, deg, nb
    real(dp) :: r1, r2, rm, gk, ideal, a(4, 4), rhs(4), phi_row(4)
    integer :: kb, p, q
    a = 0
    rhs = 0
    do kb = 1, nb
      r1 = 2 + (kb - 1) * dr
      r2 = r1 + dr
      rm = 0.75_dp * (r2**4 - r1**4) / (r2**3 - r1**3)
      ! ideal-gas pair count in the shell per sample: N (N - 1) / 2 pairs, density 1/V each
      ideal = 0.5_dp * n * (n - 1) / product(box) * (4 * pi / 3) * (r2**3 - r1**3)
      gk = c(kb) / (ns * ideal)
      do p = 1, deg + 1
        phi_row(p) = (rm - 2)**(p - 1)
      end do
      do p = 1, deg + 1
        do q = 1, deg + 1
          a(p, q) = a(p, q) + c(kb) * phi_row(p) * phi_row(q)
        end do
        rhs(p) = rhs(p) + c(kb) * phi_row(p) * log(gk)
      end do
    end do
    call solve(a(1:deg + 1, 1:deg + 1), rhs(1:deg + 1))
    g0v = exp(rhs(1))
  end function contact_value

  !> Gaussian elimination with partial pivoting (small SPD systems); b is overwritten by x.
  subroutine solve(a, b)
    real(dp), intent(inout) :: a(:,:), b(:)
    integer :: nn, i, j, p
    real(dp) :: f, t(size(b))
    nn = size(b)
    do i = 1, nn
      p = i - 1 + maxloc(abs(a(i:nn, i)), 1)
      if (p /= i) then
        t = a(i, :)
        a(i, :) = a(p, :)
        a(p, :) = t
        f = b(i)
        b(i) = b(p)
        b(p) = f
      end if
      do j = i + 1, nn
        f = a(j, i) / a(i, i)
        a(j, i:nn) = a(j, i:nn) - f * a(i, i:nn)
        b(j) = b(j) - f * b(i)
      end do
    end do
    do i = nn, 1, -1
      b(i) = (b(i) - dot_product(a(i, i + 1:nn), b(i + 1:nn))) / a(i, i)
    end do
  end subroutine solve

end program test_packing_gr
