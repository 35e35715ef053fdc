! How dense mod_packing gets (doc/VALIDATION.md "Packings"): compression only (no equilibration
! sweeps), equal spheres and the 1:1.4 mixture 50/50 by volume, triply periodic cube and Couette
! cube, N spheres, targets up to and past phi_max, 3 seeds each. Prints one Markdown row per case:
! target, seeds that reached it, the phi reached (the last overlap-free stage when jammed), the
! compression stages, relaxation sweeps and seconds (mean over the seeds). Above phi_max the packer
! refuses; scripts/pack_reach.sh builds this against a copy of the kernels with the limit lifted.
!   pack_reach [N [SEEDS [PHI ...]]]     defaults 1000, 3, and 0.55 0.58 0.60 0.61 0.62 0.63
program pack_reach
  use mod_kinds, only: dp, i8
  use mod_packing, only: random_packing_mixture, packing_report_t
  use mod_packing_geometry, only: species_counts_total, species_box_for
  implicit none
  integer :: nseed = 3
  real(dp), allocatable :: targets(:)
  real(dp) :: radius(2), share(2), box(3), phimin, t, stages, sweeps
  real(dp), allocatable :: r(:), x(:,:)
  integer :: mix, geo, k, s, info, counts(2), nok, n, nsp
  integer(i8) :: c0, c1, rate
  type(packing_report_t) :: rep
  character(len=300) :: msg
  character(len=8) :: arg
  logical :: per(3)

  n = 1000
  targets = [0.55_dp, 0.58_dp, 0.60_dp, 0.61_dp, 0.62_dp, 0.63_dp]
  if (command_argument_count() > 0) then
    call get_command_argument(1, arg)
    read(arg, *) n
  end if
  if (command_argument_count() > 1) then
    call get_command_argument(2, arg)
    read(arg, *) nseed
  end if
  if (command_argument_count() > 2) then
    deallocate(targets)
    allocate(targets(command_argument_count() - 2))
    do k = 1, size(targets)
      call get_command_argument(k + 2, arg)
      read(arg, *) targets(k)
    end do
  end if
  print '(a,i0,a)', '| spheres | box | N | target | reached (seeds) | phi reached min | stages | relax sweeps | s |'
  print '(a)', '|---|---|---|---|---|---|---|---|---|'
  do mix = 1, 2
    nsp = mix
    radius = [1.0_dp, 1.4_dp]
    share = [0.5_dp, 0.5_dp]
    if (mix == 1) then
      counts(1) = n
    else
      counts = species_counts_total(n, radius, share, .true.)
    end if
    r = [spread(radius(1), 1, counts(1))]
    if (mix == 2) r = [r, spread(radius(2), 1, counts(2))]
    do geo = 1, 2
      per = [.true., geo == 1, .true.]
      do k = 1, size(targets)
        box = species_box_for(counts(1:nsp), radius(1:nsp), targets(k), [1.0_dp, 1.0_dp, 1.0_dp])
        nok = 0
        phimin = 1
        t = 0
        stages = 0
        sweeps = 0
        do s = 1, nseed
          call system_clock(c0, rate)
          call random_packing_mixture(r, box, per, 0.0_dp, s, 0, x, info, msg, rep)
          call system_clock(c1)
          if (info == 0) nok = nok + 1
          if (info == 1 .or. info == 2) print '(a)', trim(msg)
          phimin = min(phimin, merge(rep%phi, rep%phi_reached, info == 0))
          t = t + real(c1 - c0, dp) / rate / nseed
          stages = stages + real(rep%stages, dp) / nseed
          sweeps = sweeps + real(rep%relax_sweeps, dp) / nseed
        end do
        print '(5a,i0,a,f5.3,a,i0,a,i0,a,f6.4,a,f6.1,a,f9.0,a,f7.2,a)', '| ', &
          trim(merge('equal       ', '1:1.4, 50/50', mix == 1)), ' | ', trim(merge('periodic', 'walls   ', geo == 1)), &
          ' | ', size(r), ' | ', targets(k), ' | ', nok, '/', nseed, ' | ', phimin, ' | ', stages, ' | ', &
          sweeps, ' | ', t, ' |'
      end do
    end do
  end do
end program pack_reach
