! Unit test of the mixture packings of mod_packing and mod_packing_geometry (doc/PACKING_INPUT.md
! "Tests"). Invariants:
!   1. Equal spheres are packed bit for bit as before the mixtures: two packings (Couette cell with
!      min_gap 0.01a, N = 150; periodic phi = 0.55, N = 300) hash (over the bits of every
!      coordinate) to the values printed by the same program built from the code before
!      (commit 7695ac2); fdsusp's in-run packing calls this path.
!   2. Counts: one species gives packing_count and packing_box_for bit for bit; 1:1.4 by volume
!      50/50 gives n_1/n_2 within rounding of 1.4^3 and phi within sum_k v_k / (2V) of the
!      target; by number 50/50 gives n_1 = n_2; species_counts_total sums to n exactly;
!      species_box_for holds the counts at phi exactly (1e-12, rounding).
!   3. No overlaps for the 1:1.4 mixture, 50/50 by volume, in a triply periodic cube (N = 1000)
!      and in the Couette cell, at phi = 0.3 and at phi_max (0.60), and with min_gap = 0.02a at
!      phi = 0.5: every pair |r| - a_i - a_j >= min_gap by an O(N^2) check over minimum images
!      (exact: every box length > 4 a_max), every wall gap y - a_i, Ly - y - a_i >= min_gap
!      (1e-12 a for the rounding of |r|), periodic coordinates in [0, L); the sphere order (and so
!      the radius of each) is the caller's.
!   4. Refused: a target above phi_max (the message names phi and the limit), a radius <= 0.
program test_packing_mixture
  use mod_kinds, only: dp, i8, pi
  use mod_packing, only: random_packing, random_packing_mixture, packing_report_t
  use mod_packing_geometry, only: phi_max, packing_count, packing_box_for, species_counts, &
                                  species_counts_total, species_box_for, species_volume_fraction
  use mod_unit_checks, only: check, check_below, fail, finish, beside_t, beside, end_beside, collect_beside
  implicit none
  real(dp), parameter :: radius(2) = [1.0_dp, 1.4_dp], half(2) = [0.5_dp, 0.5_dp]
  real(dp), parameter :: phis(3) = [0.3_dp, phi_max, 0.5_dp]
  integer(i8), parameter :: hash_walls = int(z'EB4F59CC3DA93C76', i8), hash_dense = int(z'EB506F25FD836459', i8)
  real(dp), allocatable :: x(:,:), r(:)
  real(dp) :: box(3), phi, b1(3), b2(3), vk(2)
  integer :: counts(2), c1(1), info, k
  type(beside_t) :: child
  type(packing_report_t) :: rep
  character(len=300) :: msg
  logical :: per(3)

  ! 3.'s packings in the Couette cell are independent of the rest: they run in a child process on
  ! the other core (mod_unit_checks' beside) while this process runs 1, 2 and 3's periodic cube;
  ! their output is printed where it stood and their checks counted with the others'
  if (beside(child)) then
    call no_overlaps(2)
    call end_beside()
  end if

  ! 1. equal spheres, bit for bit
  call random_packing(150, [14.0_dp, 12.0_dp, 11.0_dp], [.true., .false., .true.], 1.0_dp, 0.01_dp, 5, 40, &
                      x, info, msg, rep)
  print '(a,z16.16)', '1. Couette N = 150, min_gap 0.01: hash ', hash(x)
  call check(info == 0 .and. hash(x) == hash_walls, 'equal spheres in walls: positions as before, bit for bit')
  call random_packing(300, packing_box_for(300, 0.55_dp, [1.0_dp, 1.0_dp, 1.0_dp], 1.0_dp), [.true., .true., .true.], &
                      1.0_dp, 0.0_dp, 9, 30, x, info, msg, rep)
  print '(a,z16.16)', '   periodic N = 300, phi 0.55: hash ', hash(x)
  call check(info == 0 .and. hash(x) == hash_dense, 'equal spheres at phi 0.55: positions as before, bit for bit')

  ! 2. counts
  box = [20.0_dp, 21.0_dp, 22.0_dp]
  c1 = species_counts(0.45_dp, box, [1.0_dp], [1.0_dp], .true.)
  call check(c1(1) == packing_count(0.45_dp, box, 1.0_dp), 'one species: packing_count')
  b1 = species_box_for([777], [1.0_dp], 0.45_dp, box)
  b2 = packing_box_for(777, 0.45_dp, box, 1.0_dp)
  call check(all(b1 == b2), 'one species: packing_box_for, bit for bit')
  counts = species_counts(0.5_dp, box, radius, half, .true.)
  vk = 4 * pi / 3 * radius**3
  phi = species_volume_fraction(counts, radius, box)
  print '(a,2i6,a,f9.6,a,f8.5)', '2. 1:1.4 by volume 50/50 at phi 0.5: counts ', counts, ', phi ', phi, &
    ', n1/n2 ', real(counts(1), dp) / counts(2)
  call check(abs(counts(1) * vk(1) - 0.5_dp * 0.5_dp * product(box)) <= vk(1) / 2 .and. &
             abs(counts(2) * vk(2) - 0.5_dp * 0.5_dp * product(box)) <= vk(2) / 2, &
             'volume shares: each species within half a sphere of its share')
  call check_below('|phi - 0.5| against sum_k v_k / 2V', abs(phi - 0.5_dp), sum(vk) / (2 * product(box)))
  counts = species_counts(0.5_dp, box, radius, half, .false.)
  call check(counts(1) == counts(2), 'number shares 50/50: equal counts')
  do k = 1, 100
    counts = species_counts_total(k + 1, radius, [0.3_dp, 0.7_dp], mod(k, 2) == 0)
    if (sum(counts) /= k + 1) call fail('species_counts_total does not sum to n')
  end do
  counts = species_counts_total(1000, radius, half, .true.)
  b1 = species_box_for(counts, radius, 0.6_dp, [1.0_dp, 2.0_dp, 1.0_dp])
  call check_below('species_box_for: |phi / 0.6 - 1|', abs(species_volume_fraction(counts, radius, b1) / 0.6_dp - 1), &
                   1.0e-12_dp)
  call check(abs(b1(2) / b1(1) - 2) < 1.0e-12_dp, 'species_box_for keeps the shape')

  ! 3. no overlaps (the Couette cell's three packings, two thirds of the run time, in the child
  ! started above)
  call no_overlaps(1)
  if (.not. collect_beside(child)) call no_overlaps(2)

  ! 4. refusals
  box = 16
  counts = species_counts(phi_max + 0.01_dp, box, radius, half, .true.)
  r = [spread(radius(1), 1, counts(1)), spread(radius(2), 1, counts(2))]
  call random_packing_mixture(r, box, [.true., .false., .true.], 0.0_dp, 1, 10, x, info, msg, rep)
  print '(2a)', '4. phi_max + 0.01: ', trim(msg)
  call check(info == 1 .and. index(msg, 'volume fraction') > 0 .and. index(msg, 'supported') > 0, &
             'above phi_max refused, naming phi and the limit')
  call random_packing_mixture([1.0_dp, -1.0_dp], box, [.true., .false., .true.], 0.0_dp, 1, 10, x, info, msg, rep)
  call check(info == 1, 'a negative radius refused')

  call finish('test_packing_mixture')

contains

  !> 3. in the periodic cube (geo 1) or the Couette cell (geo 2)
  subroutine no_overlaps(geo)
    integer, intent(in) :: geo
    per = [.true., geo == 1, .true.]
    do k = 1, 3
      phi = phis(k)
      if (geo == 1) then
        counts = species_counts_total(1000, radius, half, .true.)
        box = species_box_for(counts, radius, phi, [1.0_dp, 1.0_dp, 1.0_dp])
      else
        box = [16.0_dp, 20.0_dp, 16.0_dp]
        counts = species_counts(phi, box, radius, half, .true.)
      end if
      r = [spread(radius(1), 1, counts(1)), spread(radius(2), 1, counts(2))]
      call random_packing_mixture(r, box, per, merge(0.02_dp, 0.0_dp, k == 3), 20 * geo + k, 20, x, info, msg, rep)
      if (info /= 0) then
        call fail(trim(msg))
        cycle
      end if
      call check_configuration(x, r, box, per, phi, merge(0.02_dp, 0.0_dp, k == 3), rep)
    end do
  end subroutine no_overlaps

  !> A hash of the bits of every coordinate (order-dependent).
  integer(i8) function hash(y) result(h)
    real(dp), intent(in) :: y(:,:)
    integer :: i, kk
    h = 0
    do i = 1, size(y, 2)
      do kk = 1, 3
        h = ieor(h * 31_i8 + 7_i8, transfer(y(kk, i), 0_i8))
      end do
    end do
  end function hash

  subroutine check_configuration(xx, rr, bx, pr, phit, gmin, rp)
    real(dp), intent(in) :: xx(:,:), rr(:), bx(3), phit, gmin
    logical, intent(in) :: pr(3)
    type(packing_report_t), intent(in) :: rp
    integer :: i, j, d, nn
    real(dp) :: rv(3), gap, wmin, phin
    character(len=60) :: label
    write(label, '(a,l1,a,f5.3,a,f4.2)') 'periodic y ', pr(2), ', phi ', phit, ', min_gap ', gmin
    nn = size(xx, 2)
    gap = huge(1.0_dp)
    do i = 1, nn
      do j = i + 1, nn
        rv = xx(:, j) - xx(:, i)
        do d = 1, 3
          if (pr(d)) rv(d) = rv(d) - bx(d) * anint(rv(d) / bx(d))
        end do
        gap = min(gap, norm2(rv) - rr(i) - rr(j))
      end do
    end do
    wmin = huge(1.0_dp)
    if (.not. pr(2)) wmin = min(minval(xx(2, :) - rr), minval(bx(2) - xx(2, :) - rr))
    phin = sum(4 * pi / 3 * rr**3) / product(bx)
    print '(3a,i5,a,f8.5,a,es10.3,a,es10.3,a,i0,a,i0,a)', '3. ', trim(label), ': N ', nn, ' phi ', phin, &
      ', min pair gap ', gap, ', min wall gap ', wmin, ' (', rp%stages, ' stages, ', rp%relax_sweeps, ' relaxation sweeps)'
    call check(gap >= gmin - 1.0e-12_dp, trim(label)//': no overlap, pairs (a_i + a_j + min_gap)')
    call check(wmin >= gmin - 1.0e-12_dp, trim(label)//': no overlap, walls (a_i + min_gap)')
    call check(abs(phin - rp%phi) <= 1.0e-12_dp, trim(label)//': reported phi is the packing''s')
    call check_below(trim(label)//': |phi - target| against sum_k v_k / 2V', abs(phin - phit), &
                     sum(4 * pi / 3 * radius**3) / (2 * product(bx)))
    do d = 1, 3
      if (pr(d)) then
        if (any(xx(d, :) < 0) .or. any(xx(d, :) >= bx(d))) call fail('a coordinate outside [0, L)')
      end if
    end do
  end subroutine check_configuration

end program test_packing_mixture
