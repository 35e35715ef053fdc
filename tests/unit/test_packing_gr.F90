! Unit test: the packings of mod_packing are equilibrium hard-sphere fluids (doc/PACKING_INPUT.md
! "Tests", doc/VALIDATION.md "Packings").
! Invariant 1 (equal spheres): in a triply periodic box, the radial distribution function at
! contact g(2a) agrees within 5 % with the Carnahan-Starling value g_CS(2a) = (1 - phi/2)/(1 - phi)^3
! (the contact value of its equation of state, Z = 1 + 4 phi g(2a), itself within 1 % of
! simulations for phi <= 0.5) at phi = 0.2, 0.3 and 0.4.
! Invariant 2 (a mixture): radii 1 and 1.4, 50/50 by volume, at phi = 0.3 and 0.4, the partial
! contact values g_ij(a_i + a_j) agree within 5 % with Boublik-Mansoori-Carnahan-Starling-Leland,
!   g_ij = 1/(1 - phi) + 3 z xi2/(1 - phi)^2 + 2 z^2 xi2^2/(1 - phi)^3,
!   z = d_i d_j/(d_i + d_j), xi2 = (pi/6) sum_k rho_k d_k^2, d = 2a
! (Boublik 1970, Mansoori et al. 1971; the form of Santos, Yuste & Lopez de Haro 1999, doc/
! VALIDATION.md; equal spheres: Carnahan-Starling). Its contact values are within ~1-2 % of
! simulations of mixtures of this size ratio at these fractions, well inside 5 %.
! Method: N = 2000 spheres (4000 for the mixture: its large-large pairs are 7 % of all, so that
! their error stays below 1 %), random_packing(_mixture) with 200 equilibration sweeps (g(2a) settles
! within ~100 sweeps at phi = 0.4), then 400 samples 4 sweeps apart. Pair counts in 10 shells of
! width 0.02a on [s, s + 0.2a], s = a_i + a_j (pairs from mod_neighbours, itself tested against an
! O(N^2) search), give g(r) per shell; ln g is fitted by a weighted quadratic in r - s at the
! shells' mean radii and g(s) = exp(fit(0)). The statistical error is the standard error of the
! same estimate over 10 consecutive blocks of 40 samples. Asserted: the block standard error is
! below 1.5 % (so that the 5 % check has at least a 3-sigma margin), and |g/g_theory - 1| < 5 %.
! The extrapolation bias is shown by a cubic fit over the same shells and a linear fit over
! [s, s + 0.1a]: both are printed and must agree with the quadratic within 2 %.
program test_packing_gr
  use mod_kinds, only: dp, pi
  use mod_packing, only: rng_t, rng_seed, random_packing_mixture, hs_monte_carlo, packing_report_t, &
                         min_separation
  use mod_packing_geometry, only: species_counts_total, species_box_for
  use mod_neighbours, only: nlist_t, nlist_init, nlist_build
  use mod_unit_checks, only: check, finish, beside_t, beside, end_beside, collect_beside
  implicit none
  integer, parameter :: n = 2000, n_mix = 4000, nbin = 10, nsamp = 400, nblk = 10, gap_sweeps = 4
  real(dp), parameter :: dr = 0.02_dp
  real(dp), parameter :: phis(3) = [0.2_dp, 0.3_dp, 0.4_dp], phis_mix(2) = [0.3_dp, 0.4_dp]
  real(dp), parameter :: mix_radius(2) = [1.0_dp, 1.4_dp], mix_share(2) = [0.5_dp, 0.5_dp]
  integer :: k
  type(beside_t) :: child

  ! The five cases are independent (each its own packing and seeds). The last, the mixture at phi
  ! 0.4 (a third of the run time), runs in a child process on the other core while this process
  ! runs the other four (mod_unit_checks' beside); its output is printed after theirs, in the
  ! order of the cases, and its checks counted with theirs: the same checks, the same verdict.
  if (beside(child)) then
    call mixture_case(2)
    call end_beside()
  end if
  do k = 1, size(phis)
    call contact_values([1.0_dp], [n], phis(k), 100 + k, 7 + k)
  end do
  call mixture_case(1)
  if (.not. collect_beside(child)) call mixture_case(2)

  call finish('test_packing_gr')

contains

  subroutine mixture_case(k)
    integer, intent(in) :: k
    call contact_values(mix_radius, species_counts_total(n_mix, mix_radius, mix_share, .true.), phis_mix(k), &
                        200 + k, 17 + k)
  end subroutine mixture_case

  !> Pack counts(k) spheres of radius radius(k) at phi in a periodic cube, sample, and check the
  !> contact value of every pair of species against BMCSL (Carnahan-Starling for one species).
  subroutine contact_values(radius, counts, phi, seed, mc_seed)
    real(dp), intent(in) :: radius(:), phi
    integer, intent(in) :: counts(:), seed, mc_seed
    integer :: ns, info, s, b, m, ib, i, j, p, q, t, npt
    integer, allocatable :: species(:)
    real(dp), allocatable :: x(:,:), r(:), cnt(:, :, :)
    real(dp) :: box(3), step, acc, g0, g0b(nblk), se, gth, rv(3), d, t0, t1, g3, g1, pg, wg, xi2, z, dens
    type(rng_t) :: g
    type(nlist_t) :: nl
    type(packing_report_t) :: rep
    character(len=200) :: msg
    character(len=12) :: label

    call cpu_time(t0)
    ns = size(radius)
    npt = ns * (ns + 1) / 2
    allocate(r(0), species(0))
    do p = 1, ns
      r = [r, spread(radius(p), 1, counts(p))]
      species = [species, spread(p, 1, counts(p))]
    end do
    box = species_box_for(counts, radius, phi, [1.0_dp, 1.0_dp, 1.0_dp])
    call random_packing_mixture(r, box, [.true., .true., .true.], 0.0_dp, seed, 200, x, info, msg, rep)
    if (info /= 0) then
      print '(2a)', 'FAIL packing: ', trim(msg)
      error stop 1
    end if
    call nlist_init(nl, size(r), box, [.true., .true., .true.], 2 * maxval(radius) + nbin * dr, 1.0_dp, &
                    0.0_dp, info)
    call rng_seed(g, mc_seed)
    step = rep%step
    allocate(cnt(nbin, nblk, npt))
    cnt = 0
    do s = 1, nsamp
      call hs_monte_carlo(x, box, [.true., .true., .true.], 1.0_dp, g, step, gap_sweeps, .false., acc, r)
      call nlist_build(nl, x)
      b = 1 + (s - 1) / (nsamp / nblk)
      do m = 1, nl%npairs
        i = nl%pair(1, m)
        j = nl%pair(2, m)
        rv = x(:, j) - x(:, i) + nl%shift(:, m) * box
        d = norm2(rv)
        ib = int((d - r(i) - r(j)) / dr) + 1
        t = pair_type(species(i), species(j), ns)
        if (ib >= 1 .and. ib <= nbin) cnt(ib, b, t) = cnt(ib, b, t) + 1
      end do
    end do
    call min_separation(x, box, [.true., .true., .true.], 1.0_dp, pg, wg, r)
    call check(pg >= 0, 'no overlap appeared during Monte Carlo')
    call cpu_time(t1)
    ! BMCSL: xi2 = (pi/6) sum_k rho_k d_k^2
    xi2 = pi / 6 * sum(counts * (2 * radius)**2) / product(box)
    do p = 1, ns
      do q = p, ns
        t = pair_type(p, q, ns)
        z = (2 * radius(p)) * (2 * radius(q)) / (2 * radius(p) + 2 * radius(q))
        gth = 1 / (1 - phi) + 3 * z * xi2 / (1 - phi)**2 + 2 * z**2 * xi2**2 / (1 - phi)**3
        ! pairs per unit volume: n_p (n_p - 1)/2 V of one species, n_p n_q / V of two
        if (p == q) then
          dens = 0.5_dp * counts(p) * (counts(p) - 1.0_dp) / product(box)
        else
          dens = real(counts(p), dp) * counts(q) / product(box)
        end if
        associate (c => cnt(:, :, t), sig => radius(p) + radius(q))
          g0 = contact_value(sum(c, 2), nsamp, 2, nbin, sig, dens)
          g3 = contact_value(sum(c, 2), nsamp, 3, nbin, sig, dens)
          g1 = contact_value(sum(c, 2), nsamp, 1, nbin / 2, sig, dens)
          do b = 1, nblk
            g0b(b) = contact_value(c(:, b), nsamp / nblk, 2, nbin, sig, dens)
          end do
        end associate
        se = sqrt(sum((g0b - sum(g0b) / nblk)**2) / (nblk - 1) / nblk)
        if (ns == 1) then
          label = 'g(2a)'
        else
          write(label, '(a,f3.1,a,f3.1,a)') 'g(', radius(p), '+', radius(q), ')'
        end if
        print '(a,i0,a,f4.2,4a,f7.4,a,f7.4,a,f7.4,a,f7.4,2a,f7.4,a,f6.2,a,f6.3,a,f5.1,a)', 'N ', size(r), ', phi ', phi, &
          ': ', trim(label), ' = ', ' ', g0, ' +- ', se, ' (cubic ', g3, ', linear ', g1, '), ', &
          trim(merge('CS   ', 'BMCSL', ns == 1)), gth, ', rel. diff ', 100 * (g0 / gth - 1), ' %, MC step ', step, &
          ' a (', t1 - t0, ' s)'
        call check(se <= 0.015_dp * gth, trim(label)//': statistical error at most 1.5 % (conclusive)')
        call check(abs(g0 / gth - 1) <= 0.05_dp, trim(label)//': within 5 % of '// &
                   trim(merge('Carnahan-Starling                          ', &
                              'Boublik-Mansoori-Carnahan-Starling-Leland  ', ns == 1)))
        call check(abs(g3 / g0 - 1) <= 0.02_dp .and. abs(g1 / g0 - 1) <= 0.02_dp, &
                   trim(label)//': extrapolation to contact depends on the fit by at most 2 %')
      end do
    end do
  end subroutine contact_values

  !> Index of the unordered pair of species (p, q) among ns (ns + 1)/2.
  pure integer function pair_type(p, q, ns) result(t)
    integer, intent(in) :: p, q, ns
    integer :: lo, hi
    lo = min(p, q)
    hi = max(p, q)
    t = (lo - 1) * ns - (lo - 1) * (lo - 2) / 2 + (hi - lo + 1)
  end function pair_type

  !> g(s) from shell counts c(1:nb) on [s, s + nb dr] accumulated over ns samples of pairs at
  !> density dens per unit volume: ln g fitted by a polynomial of degree deg in r - s at the
  !> shells' volume-weighted mean radii, weights = counts (the variance of ln c is 1/c), value
  !> at r = s.
  real(dp) function contact_value(c, ns, deg, nb, s, dens) result(g0v)
    real(dp), intent(in) :: c(:), s, dens
    integer, intent(in) :: ns, deg, nb
    real(dp) :: r1, r2, rm, gk, ideal, a(4, 4), rhs(4), phi_row(4)
    integer :: kb, p, q
    a = 0
    rhs = 0
    do kb = 1, nb
      r1 = s + (kb - 1) * dr
      r2 = r1 + dr
      rm = 0.75_dp * (r2**4 - r1**4) / (r2**3 - r1**3)
      ! ideal-gas pair count in the shell per sample
      ideal = dens * (4 * pi / 3) * (r2**3 - r1**3)
      gk = c(kb) / (ns * ideal)
      do p = 1, deg + 1
        phi_row(p) = (rm - s)**(p - 1)
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
