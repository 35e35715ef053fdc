! The spheres of a deck that asks for a volume fraction (&particles solid_fraction): a random
! hard-sphere packing made at the start of the run by mod_packing, the packer bin/fdsusp-pack uses,
! with the deck's seed, sweeps and minimum gap. Every rank builds the same packing (replicated
! particle data, a deterministic generator), so nothing is communicated. Apart from
! mod_particles_io, which reads and writes particle files, so that the files do not run the packer.
module mod_initial_packing
  use mod_kinds, only: dp
  use mod_params, only: config_t
  use mod_particles, only: particles_t, particles_init, motion_code
  use mod_packing, only: random_packing_mixture, packing_report_t
  use mod_packing_geometry, only: species_counts
  use mod_errors, only: input_error, fatal_error, log_line
  implicit none
  private
  public :: initial_packing_make

contains

  !> parts: the spheres of &particles solid_fraction at random, non-overlapping positions (off the
  !> walls when there are walls): packing_count of them, or of a mixture (several &particles
  !> radius) the counts per species of its volume_share or number_share (mod_packing_geometry's
  !> rounding, doc/PACKING_INPUT.md), each sphere with its radius. A target the packer refuses
  !> stops the run with one message naming the deck variable; a compression that fails, with
  !> status 3. restart: the spheres of the packing, their count and radii, without their positions
  !> (zero), which a checkpoint gives: a restart does not pack again (the packer's sweeps are
  !> most of a large run's start, and each rank made them).
  subroutine initial_packing_make(cfg, parts, restart)
    type(config_t), intent(in) :: cfg
    type(particles_t), intent(out) :: parts
    logical, intent(in) :: restart
    real(dp), allocatable :: position(:, :), radius(:)
    character(len=400) :: message
    integer :: n, info, k, counts(cfg%species)
    type(packing_report_t) :: report

    ! the counts per species (of equal spheres: packing_count), then the spheres species by species
    associate(share_by_volume => any(cfg%particles%volume_share /= 0.0_dp))
      counts = species_counts(cfg%particles%solid_fraction, cfg%domain%box, cfg%particles%radius(1:cfg%species), &
                              merge(cfg%particles%volume_share(1:cfg%species), &
                                    cfg%particles%number_share(1:cfg%species), share_by_volume), share_by_volume)
    end associate
    allocate(radius(0))
    do k = 1, cfg%species
      radius = [radius, spread(cfg%particles%radius(k), 1, counts(k))]
    end do
    n = size(radius)
    if (restart) then
      write(message, '(a,i0,a)') 'packing: not made at a restart: ', n, ' spheres, positions from the checkpoint'
      call log_line(message)
      call particles_init(parts, n, cfg%radius, motion_code(cfg%particles%motion))
      parts%radii = radius
      return
    end if
    call random_packing_mixture(radius, cfg%domain%box, [.true., .not. cfg%walls, .true.], &
                                cfg%particles%packing_min_gap, cfg%particles%seed, cfg%particles%packing_sweeps, &
                                position, info, message, report)
    select case (info)
    case (0)
    case (1)
      call input_error(cfg%deck_file, 'particles', 'solid_fraction', trim(message))
    case (2)
      call input_error(cfg%deck_file, 'domain', 'box', trim(message))
    case default
      call fatal_error('fdsusp: '//trim(message), 3)
    end select
    write(message, '(a,i0,a,f8.5,a,i0,a,es10.3,a)') 'packing: ', n, ' spheres, phi = ', report%phi, &
         ' (seed ', cfg%particles%seed, '), smallest gap ', min(report%min_pair_gap, report%min_wall_gap), ' a'
    call log_line(message)
    if (cfg%species > 1) then
      write(message, '(a,8(i0,:,", "))') 'packing: spheres per species (&particles radius): ', counts
      call log_line(message)
    end if
    call particles_init(parts, n, cfg%radius, motion_code(cfg%particles%motion))
    parts%position = position
    parts%radii = radius
  end subroutine initial_packing_make

end module mod_initial_packing
