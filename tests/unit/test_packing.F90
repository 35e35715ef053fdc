! Unit test of mod_packing (doc/PACKING_INPUT.md "Tests"). Invariants:
!   1. The generator is L'Ecuyer's MRG32k3a: from the state 12345 x 6 the integers
!      z = (p1 - p2) mod m1 behind the first five outputs are the published 545508589,
!      1368065410, 1327943761, 3546985096, 951893194 (exact; u = (z + 1)/(m1 + 1)).
!   2. No overlaps: in a triply periodic box (N = 1000) and in the 20a Couette cube, at
!      phi = 0.1, 0.3, 0.45, 0.5 and 0.55, every pair gap |r| - 2a >= 0 by an O(N^2) check over
!      minimum images (independent of the module's cell lists; minimum image is exact for
!      |r| < 2a since every box length is > 4a), every centre in [a, Ly - a] in the Couette
!      cell, every coordinate in [0, L) in periodic directions. With min_gap = 0.02a every pair
!      and wall gap is >= 0.02a (- 1e-12 a for rounding of |r|).
!   3. Volume fraction: N = nint(phi V / v) gives |phi_N / phi - 1| <= 1/(2 phi V / v), below
!      0.5 % for every case here (N >= 191); with packing_box_for the fraction is exact (1e-12).
!   4. Reproducible: the same seed gives bit-identical positions, another seed other positions.
!   5. Refused: phi above phi_max (0.60), a box length below 4a.
!   6. N = 1000 at phi = 0.45 (Couette and periodic): wall-clock time measured and printed (the
!      acceptance asks for under a minute; not asserted, machines differ).
program test_packing
  use mod_kinds, only: dp, i8, pi
  use mod_packing, only: rng_t, rng_uniform, random_packing, packing_report_t
  use mod_packing_geometry, only: packing_count, packing_box_for, phi_max
  use mod_unit_checks, only: check, fail, finish, beside_t, beside, end_beside, collect_beside
  implicit none
  integer, parameter :: nphi = 5
  real(dp), parameter :: phis(nphi) = [0.1_dp, 0.3_dp, 0.45_dp, 0.5_dp, 0.55_dp]
  integer(i8), parameter :: published(5) = [545508589_i8, 1368065410_i8, 1327943761_i8, &
                                            3546985096_i8, 951893194_i8]
  integer(i8), parameter :: m1 = 4294967087_i8
  type(rng_t) :: g
  type(packing_report_t) :: rep
  real(dp), allocatable :: x(:,:), y(:,:)
  real(dp) :: box(3), u
  integer :: k, n, info
  type(beside_t) :: child
  integer(i8) :: z
  integer(i8) :: c0, c1, rate
  character(len=200) :: msg
  logical :: per(3)

  ! 2's packings in the Couette cube run in a child process on the other core (mod_unit_checks'
  ! beside) while this process runs the rest (the times printed are then those of two packings
  ! at once; they are not asserted)
  if (beside(child)) then
    call overlaps(2)
    call end_beside()
  end if

  ! 1. generator
  g%s = 12345_i8
  do k = 1, 5
    u = rng_uniform(g)
    z = nint(u * real(m1 + 1, dp), i8) - 1
    if (z /= published(k)) call fail('MRG32k3a output differs from the published stream')
  end do
  print '(a)', '1. MRG32k3a stream from 12345 x 6 matches the published integers'

  ! 2, 3. overlaps and volume fraction: the periodic box here, the Couette cube (three fifths of
  ! the run time, independent of the rest) in the child started above; its output printed where
  ! it stood, its checks counted with the others'
  call overlaps(1)
  if (.not. collect_beside(child)) call overlaps(2)
  ! minimum gap
  box = 20
  per = [.true., .false., .true.]
  n = packing_count(0.45_dp, box, 1.0_dp)
  call random_packing(n, box, per, 1.0_dp, 0.02_dp, 5, 100, x, info, msg, rep)
  if (info /= 0) call fail(trim(msg))
  if (info == 0) call check_configuration(x, box, per, 0.45_dp, 0.02_dp, 0_i8, 1_i8)

  ! 4. reproducibility
  box = packing_box_for(500, 0.4_dp, [1.0_dp, 1.0_dp, 1.0_dp], 1.0_dp)
  call random_packing(500, box, [.true., .true., .true.], 1.0_dp, 0.0_dp, 3, 50, x, info, msg, rep)
  call random_packing(500, box, [.true., .true., .true.], 1.0_dp, 0.0_dp, 3, 50, y, info, msg, rep)
  call check(all(x == y), 'the same seed gives the same positions')
  call random_packing(500, box, [.true., .true., .true.], 1.0_dp, 0.0_dp, 4, 50, y, info, msg, rep)
  call check(.not. all(abs(x - y) < 1.0e-6_dp), 'another seed gives other positions')
  print '(a)', '4. same seed: bit-identical positions; seed 4 differs from seed 3'

  ! 5. refusals
  box = 20
  call random_packing(packing_count(phi_max + 0.01_dp, box, 1.0_dp), box, per, 1.0_dp, 0.0_dp, 1, &
                      10, x, info, msg, rep)
  print '(a,f4.2,2a)', '5. phi = ', phi_max + 0.01_dp, ': ', trim(msg)
  call check(info == 1, 'phi above phi_max is refused')
  call random_packing(10, [20.0_dp, 3.9_dp, 20.0_dp], per, 1.0_dp, 0.0_dp, 1, 10, x, info, msg, rep)
  print '(2a)', '   Ly = 3.9a: ', trim(msg)
  call check(info == 2, 'a box below 4a is refused')

  call finish('test_packing')

contains

  !> 2. and 3. in the periodic box (geo 1) or the Couette cube (geo 2)
  subroutine overlaps(geo)
    integer, intent(in) :: geo
    do k = 1, nphi
      if (geo == 1) then
        per = .true.
        n = 1000
        box = packing_box_for(n, phis(k), [1.0_dp, 1.0_dp, 1.0_dp], 1.0_dp)
      else
        per = [.true., .false., .true.]
        box = 20
        n = packing_count(phis(k), box, 1.0_dp)
      end if
      call system_clock(c0, rate)
      call random_packing(n, box, per, 1.0_dp, 0.0_dp, 11 * k + geo, 200, x, info, msg, rep)
      call system_clock(c1)
      if (info /= 0) then
        call fail(trim(msg))
        cycle
      end if
      call check_configuration(x, box, per, phis(k), 0.0_dp, c1 - c0, rate)
    end do
  end subroutine overlaps

  subroutine check_configuration(xx, bx, pr, phi, gmin, ticks, tick_rate)
    real(dp), intent(in) :: xx(:,:), bx(3), phi, gmin
    logical, intent(in) :: pr(3)
    integer(i8), intent(in) :: ticks, tick_rate
    integer :: i, j, d, nn
    real(dp) :: r(3), dmin2, wmin, phin, bound
    character(len=40) :: label
    write(label, '(a,l1,a,f5.2)') 'periodic y ', pr(2), ', phi ', phi
    nn = size(xx, 2)
    dmin2 = huge(1.0_dp)
    do i = 1, nn
      do j = i + 1, nn
        r = xx(:, j) - xx(:, i)
        do d = 1, 3
          if (pr(d)) r(d) = r(d) - bx(d) * anint(r(d) / bx(d))
        end do
        dmin2 = min(dmin2, sum(r**2))
      end do
    end do
    wmin = huge(1.0_dp)
    if (.not. pr(2)) wmin = min(minval(xx(2, :)) - 1, minval(bx(2) - xx(2, :)) - 1)
    phin = nn * (4 * pi / 3) / product(bx)
    bound = 1 / (2 * phi * product(bx) / (4 * pi / 3))
    print '(a,l1,a,f5.2,a,i5,a,f8.5,a,es10.3,a,es10.3,a,f7.3,a)', '2. periodic y ', pr(2), &
      ' phi ', phi, ': N ', nn, ' phi_N ', phin, ', min pair gap ', sqrt(dmin2) - 2, &
      ', min wall gap ', wmin, ', ', real(ticks, dp) / real(tick_rate, dp), ' s'
    call check(sqrt(dmin2) - 2 >= gmin - 1.0e-12_dp, trim(label)//': no overlapping spheres (pair gaps >= min_gap)')
    call check(wmin >= gmin - 1.0e-12_dp, trim(label)//': no sphere overlaps a wall (wall gaps >= min_gap)')
    do d = 1, 3
      if (pr(d)) then
        if (any(xx(d, :) < 0) .or. any(xx(d, :) >= bx(d))) call fail('a coordinate outside [0, L)')
      end if
    end do
    call check(.not. (abs(phin / phi - 1) > max(bound, 1.0e-12_dp) .or. abs(phin / phi - 1) > 0.005_dp), &
               trim(label)//': volume fraction on target')
  end subroutine check_configuration

end program test_packing
