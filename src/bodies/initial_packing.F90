! The spheres of a deck that asks for a volume fraction (&particles solid_fraction): a random
! hard-sphere packing made at the start of the run by mod_packing, the packer bin/fdsusp-pack uses,
! with the deck's seed, sweeps and minimum gap. Every rank builds the same packing (replicated
! particle data, a deterministic generator), so nothing is communicated. Apart from
! mod_particles_io, which reads and writes particle files, so that the files do not run the packer.
module mod_initial_packing
  use mod_kinds, only: dp
  use mod_params, only: config_t
  use mod_particles, only: particles_t, particles_init, motion_code
  use mod_packing, only: random_packing, packing_report_t
  use mod_packing_geometry, only: packing_count
  use mod_errors, only: input_error, fatal_error, log_line
  implicit none
  private
  public :: initial_packing_make

contains

  !> parts: packing_count(solid_fraction) spheres at random, non-overlapping positions (off the
  !> walls when there are walls). A target the packer refuses stops the run with one message
  !> naming the deck variable; a compression that fails, with status 3.
  subroutine initial_packing_make(cfg, parts)
    type(config_t), intent(in) :: cfg
    type(particles_t), intent(out) :: parts
    real(dp), allocatable :: position(:, :)
    character(len=400) :: message
    integer :: n, info
    type(packing_report_t) :: report

    n = packing_count(cfg%particles%solid_fraction, cfg%domain%box, cfg%radius)
    call random_packing(n, cfg%domain%box, [.true., .not. cfg%walls, .true.], cfg%radius, cfg%particles%packing_min_gap, &
                        cfg%particles%seed, cfg%particles%packing_sweeps, position, info, message, report)
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
    call particles_init(parts, n, cfg%radius, motion_code(cfg%particles%motion))
    parts%position = position
  end subroutine initial_packing_make

end module mod_initial_packing
