! Bench of the neighbour search (mod_neighbours) and of one contact evaluation (mod_contact) versus
! the number of spheres N, for scripts/bench_neighbours.sh (results in doc/BENCHMARKS.md §3).
! Configurations: hard-sphere packings (mod_packing, no Monte Carlo) at phi = 0.4 in a Couette
! cell of shape 2:1:1 (x, z periodic, walls in y); cutoff 2a + h_r + skin with h_r = 0.005a,
! skin = 0.2a. Each timing is the best of 5 means over repetitions lasting at least 0.1 s.
program bench_neighbours
  use mod_kinds, only: dp, i8
  use mod_neighbours, only: nlist_t, nlist_init, nlist_build
  use mod_packing, only: random_packing, packing_report_t
  use mod_packing_geometry, only: packing_box_for
  use mod_contact, only: contact_params_t, contact_setup, contact_history_t, contact_forces, &
                         contact_stats_t
  implicit none
  integer, parameter :: nn = 6
  integer, parameter :: ns(nn) = [1000, 2000, 4000, 8000, 16000, 32000]
  real(dp), parameter :: phi = 0.4_dp, h_r = 0.005_dp, skin = 0.2_dp
  logical, parameter :: per(3) = [.true., .false., .true.]
  type(nlist_t) :: nl
  type(packing_report_t) :: rep
  type(contact_params_t) :: p
  type(contact_history_t) :: h
  type(contact_stats_t) :: st
  real(dp), allocatable :: x(:,:), u(:,:), om(:,:), f(:,:), t(:,:), s(:,:,:)
  real(dp) :: box(3), tb(nn), tc(nn), tn2, vw(3, 2), sx, sy, sxx, sxy, slope
  integer :: k, info, reps, i, j, nclose, blk
  integer(i8) :: c0, c1, rate
  character(len=200) :: msg

  call contact_setup(p, 1.0_dp, h_r, 0.5_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  vw = 0
  print '(a)', '|      N | pairs/N | dist. evals/N | build [ms] | build/N [us] | contacts [ms] | O(N^2) [ms] |'
  print '(a)', '|-------:|--------:|--------------:|-----------:|-------------:|--------------:|------------:|'
  do k = 1, nn
    box = packing_box_for(ns(k), phi, [2.0_dp, 1.0_dp, 1.0_dp], 1.0_dp)
    call random_packing(ns(k), box, per, 1.0_dp, 0.0_dp, k, 0, x, info, msg, rep)
    if (info /= 0) error stop 'packing failed'
    call nlist_init(nl, ns(k), box, per, 2 + h_r + skin, 1 + h_r + skin, skin, info)
    ! neighbour list build: best of 5 blocks of >= 0.1 s (the machine may be shared)
    tb(k) = huge(1.0_dp)
    do blk = 1, 5
      reps = 0
      call system_clock(c0, rate)
      do
        call nlist_build(nl, x)
        reps = reps + 1
        call system_clock(c1)
        if (real(c1 - c0, dp) / rate > 0.1_dp) exit
      end do
      tb(k) = min(tb(k), real(c1 - c0, dp) / rate / reps)
    end do
    ! one contact evaluation (forces, torques, stresslets, history) over the list
    allocate(u(3, ns(k)), om(3, ns(k)), f(3, ns(k)), t(3, ns(k)), s(3, 3, ns(k)))
    u = 0.1_dp
    om = 0.1_dp
    h = contact_history_t()
    tc(k) = huge(1.0_dp)
    do blk = 1, 5
      reps = 0
      call system_clock(c0)
      do
        call contact_forces(p, h, x, u, om, box, per, vw, nl%pair, nl%npairs, nl%wall, nl%nwalls, &
                            1.0e-3_dp, f, t, s, st, info)
        reps = reps + 1
        call system_clock(c1)
        if (real(c1 - c0, dp) / rate > 0.1_dp) exit
      end do
      tc(k) = min(tc(k), real(c1 - c0, dp) / rate / reps)
    end do
    deallocate(u, om, f, t, s)
    ! brute force O(N^2) minimum-image search, for comparison (up to N = 8000)
    tn2 = -1
    if (ns(k) <= 8000) then
      call system_clock(c0)
      nclose = 0
      do i = 1, ns(k)
        do j = i + 1, ns(k)
          if (sum(mi(x(:, j) - x(:, i))**2) < (2 + h_r + skin)**2) nclose = nclose + 1
        end do
      end do
      call system_clock(c1)
      tn2 = real(c1 - c0, dp) / rate
      if (nclose /= nl%npairs) error stop 'O(N^2) pair count differs'
    end if
    if (tn2 > 0) then
      print '(a,i6,a,f7.3,a,f13.2,a,f10.3,a,f12.3,a,f13.3,a,f11.1,a)', '| ', ns(k), ' | ', &
        real(nl%npairs, dp) / ns(k), ' | ', real(nl%n_dist, dp) / ns(k), ' | ', 1e3 * tb(k), ' | ', &
        1e6 * tb(k) / ns(k), ' | ', 1e3 * tc(k), ' | ', 1e3 * tn2, ' |'
    else
      print '(a,i6,a,f7.3,a,f13.2,a,f10.3,a,f12.3,a,f13.3,a)', '| ', ns(k), ' | ', &
        real(nl%npairs, dp) / ns(k), ' | ', real(nl%n_dist, dp) / ns(k), ' | ', 1e3 * tb(k), ' | ', &
        1e6 * tb(k) / ns(k), ' | ', 1e3 * tc(k), ' |           - |'
    end if
  end do
  ! least-squares slope of log(build time) against log N
  sx = sum(log(real(ns, dp)))
  sy = sum(log(tb))
  sxx = sum(log(real(ns, dp))**2)
  sxy = sum(log(real(ns, dp)) * log(tb))
  slope = (nn * sxy - sx * sy) / (nn * sxx - sx**2)
  print '(a,f5.2,a)', 'build time ~ N^', slope, ' (least squares over N = 1000..32000)'
  sy = sum(log(tc))
  sxy = sum(log(real(ns, dp)) * log(tc))
  print '(a,f5.2)', 'contact evaluation time ~ N^', (nn * sxy - sx * sy) / (nn * sxx - sx**2)
contains
  pure function mi(d) result(r)
    real(dp), intent(in) :: d(3)
    real(dp) :: r(3)
    r = d
    r(1) = r(1) - box(1) * anint(r(1) / box(1))
    r(3) = r(3) - box(3) * anint(r(3) / box(3))
  end function mi
end program bench_neighbours
