! The deck of bin/fdsusp-pack: one namelist group &packing (doc/PACKING_INPUT.md lists every
! variable with its default, unit and range; keep the two in step).
!
! Errors stop the program before any work with one message naming the file, the group and the
! variable (mod_errors::input_error), as for fdsusp's own deck; the line-by-line diagnosis of a
! failed namelist read is shared with mod_params (mod_deck_text).
! Units: radius a = 1; lengths in a.
module mod_packing_deck
  use mod_kinds, only: dp, pi
  use mod_errors, only: input_error
  use mod_deck_text, only: deck_line_length, load_lines, group_on_line, to_lower, diagnose_group
  use mod_packing_geometry, only: phi_max, packing_count, packing_box_for
  implicit none
  private
  public :: pack_config_t, read_pack_deck, pack_deck_lines, max_line

  integer, parameter :: max_line = deck_line_length

  type :: pack_config_t
    character(len=max_line) :: deck_file = ''
    real(dp) :: box(3) = [20.0_dp, 20.0_dp, 20.0_dp]    ! box lengths Lx, Ly, Lz [a]
    character(len=16) :: y_boundary = 'walls'           ! 'walls' (Couette cell) or 'periodic'
    real(dp) :: phi = 0.3_dp                            ! target volume fraction [-]
    integer :: n_particles = 0                          ! > 0: box rescaled to hold exactly this many
    real(dp) :: min_gap = 0.0_dp                        ! smallest surface gap, pairs and walls [a]
    integer :: seed = 1                                 ! random seed [-]
    integer :: mc_sweeps = 1000                         ! Monte Carlo equilibration sweeps [-]
    character(len=max_line) :: directory = 'out'        ! output directory (created)
    character(len=256) :: file = 'packing.h5'          ! file name inside the directory
    ! derived, not read
    integer :: n = 0                                    ! number of spheres
    logical :: periodic(3) = [.true., .false., .true.]
  end type pack_config_t

  type(pack_config_t), save :: diagnosis_base   ! the configuration a diagnosis starts from

contains

  !> Read, validate and derive the configuration from deck. Collective (every rank reads).
  subroutine read_pack_deck(deck, cfg)
    character(len=*), intent(in) :: deck
    type(pack_config_t), intent(out) :: cfg
    character(len=max_line), allocatable :: lines(:)
    integer :: l, first
    character(len=64) :: name
    character(len=16) :: lnum

    cfg%deck_file = deck
    call load_lines(deck, lines)
    first = 0
    do l = 1, size(lines)
      name = group_on_line(lines(l))
      if (len_trim(name) == 0 .or. name == 'end') cycle
      if (name /= 'packing') then
        write(lnum, '(i0)') l
        call input_error(deck, trim(name), '', 'unknown group (line '//trim(lnum)// &
             '); fdsusp-pack reads only &packing (doc/PACKING_INPUT.md)')
      end if
      if (first == 0) first = l
    end do
    if (first == 0) call input_error(deck, 'packing', '', 'the group is missing')
    call read_group(deck, lines, first, cfg)
    call validate(cfg)
  end subroutine read_pack_deck

  !> The effective deck (defaults included) as namelist text, one line per element.
  subroutine pack_deck_lines(cfg, text)
    type(pack_config_t), intent(in) :: cfg
    character(len=max_line), allocatable, intent(out) :: text(:)
    allocate(text(11))
    write(text(1), '(a)') '&packing'
    write(text(2), '(a,3(g0.10,:,", "))') '  box = ', cfg%box
    write(text(3), '(a)') "  y_boundary = '"//trim(cfg%y_boundary)//"'"
    write(text(4), '(a,g0.10)') '  phi = ', cfg%phi
    write(text(5), '(a,i0)') '  n_particles = ', cfg%n_particles
    write(text(6), '(a,g0.10)') '  min_gap = ', cfg%min_gap
    write(text(7), '(a,i0)') '  seed = ', cfg%seed
    write(text(8), '(a,i0)') '  mc_sweeps = ', cfg%mc_sweeps
    write(text(9), '(a)') "  directory = '"//trim(cfg%directory)//"'"
    write(text(10), '(a)') "  file = '"//trim(cfg%file)//"'"
    write(text(11), '(a)') '/'
  end subroutine pack_deck_lines

  ! ---- reading ----------------------------------------------------------------------------

  !> Read &packing starting at line first; if reading fails, mod_deck_text names the variable
  !> and the line at fault.
  subroutine read_group(deck, lines, first, cfg)
    character(len=*), intent(in) :: deck
    character(len=*), intent(in) :: lines(:)
    integer, intent(in) :: first
    type(pack_config_t), intent(inout) :: cfg
    character(len=512) :: msg
    integer :: ios
    msg = ''
    call group_io(cfg, lines(first:), ios, msg)
    if (ios /= 0) then
      diagnosis_base = cfg
      call diagnose_group(deck, 'packing', lines, first, read_into_copy)
    end if
  end subroutine read_group

  !> The reader mod_deck_text calls while diagnosing (a module procedure: passing an internal
  !> one would need an executable stack).
  subroutine read_into_copy(src, ios, msg)
    character(len=*), intent(in) :: src(:)
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    type(pack_config_t) :: trial
    trial = diagnosis_base
    call group_io(trial, src, ios, msg)
  end subroutine read_into_copy

  subroutine group_io(cfg, src, ios, msg)
    type(pack_config_t), intent(inout) :: cfg
    character(len=*), intent(in) :: src(:)
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    real(dp) :: box(3), phi, min_gap
    character(len=16) :: y_boundary
    integer :: n_particles, seed, mc_sweeps
    character(len=max_line) :: directory
    character(len=256) :: file
    namelist /packing/ box, y_boundary, phi, n_particles, min_gap, seed, mc_sweeps, directory, file
    box = cfg%box
    y_boundary = cfg%y_boundary
    phi = cfg%phi
    n_particles = cfg%n_particles
    min_gap = cfg%min_gap
    seed = cfg%seed
    mc_sweeps = cfg%mc_sweeps
    directory = cfg%directory
    file = cfg%file
    read(src, nml=packing, iostat=ios, iomsg=msg)
    if (ios /= 0) return
    cfg%box = box
    cfg%y_boundary = to_lower(y_boundary)
    cfg%phi = phi
    cfg%n_particles = n_particles
    cfg%min_gap = min_gap
    cfg%seed = seed
    cfg%mc_sweeps = mc_sweeps
    cfg%directory = directory
    cfg%file = file
  end subroutine group_io


  ! ---- validation -------------------------------------------------------------------------

  subroutine check_real(cfg, name, value, lo, hi, lo_open)
    type(pack_config_t), intent(in) :: cfg
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value, lo, hi
    logical, intent(in) :: lo_open
    character(len=160) :: text
    character(len=1) :: bracket
    bracket = merge('(', '[', lo_open)
    if (value /= value .or. value > hi .or. value < lo .or. (lo_open .and. value <= lo)) then
      write(text, '(a,es11.4,2a,es10.3,a,es10.3,a)') 'value ', value, ' out of range ', bracket, &
        lo, ',', hi, ']'
      call input_error(cfg%deck_file, 'packing', name, trim(text))
    end if
  end subroutine check_real

  subroutine check_int(cfg, name, value, lo, hi)
    type(pack_config_t), intent(in) :: cfg
    character(len=*), intent(in) :: name
    integer, intent(in) :: value, lo, hi
    character(len=160) :: text
    if (value < lo .or. value > hi) then
      write(text, '(a,i0,a,i0,a,i0,a)') 'value ', value, ' out of range [', lo, ', ', hi, ']'
      call input_error(cfg%deck_file, 'packing', name, trim(text))
    end if
  end subroutine check_int

  subroutine validate(cfg)
    type(pack_config_t), intent(inout) :: cfg
    character(len=*), parameter :: xyz = 'xyz'
    character(len=200) :: text
    real(dp) :: phie
    integer :: d

    call check_real(cfg, 'phi', cfg%phi, 0.0_dp, phi_max, .true.)
    call check_int(cfg, 'n_particles', cfg%n_particles, 0, 10000000)
    call check_real(cfg, 'min_gap', cfg%min_gap, 0.0_dp, 0.5_dp, .false.)
    call check_int(cfg, 'seed', cfg%seed, 0, huge(1))
    call check_int(cfg, 'mc_sweeps', cfg%mc_sweeps, 0, 10000000)
    if (cfg%y_boundary /= 'walls' .and. cfg%y_boundary /= 'periodic') &
      call input_error(cfg%deck_file, 'packing', 'y_boundary', &
           'must be ''walls'' or ''periodic'', not '''//trim(cfg%y_boundary)//'''')
    cfg%periodic = [.true., cfg%y_boundary == 'periodic', .true.]
    do d = 1, 3
      call check_real(cfg, 'box('//xyz(d:d)//')', cfg%box(d), 0.0_dp, 1.0e4_dp, .true.)
    end do
    if (cfg%n_particles > 0) then
      cfg%box = packing_box_for(cfg%n_particles, cfg%phi, cfg%box, 1.0_dp)
      cfg%n = cfg%n_particles
    else
      cfg%n = packing_count(cfg%phi, cfg%box, 1.0_dp)
      if (cfg%n < 1) call input_error(cfg%deck_file, 'packing', 'phi', &
           'gives no sphere in this box (set a larger phi or box, or n_particles)')
    end if
    do d = 1, 3
      if (cfg%box(d) < 4 * (1 + cfg%min_gap)) then
        write(text, '(a,f0.4,a)') 'every box length must be at least 4 (a + min_gap) (it is ', &
          cfg%box(d), ' a)'
        call input_error(cfg%deck_file, 'packing', 'box('//xyz(d:d)//')', trim(text))
      end if
    end do
    phie = (cfg%n - 1) * (4 * pi / 3) * (1 + cfg%min_gap / 2)**3 / product(cfg%box)
    if (cfg%min_gap > 0 .and. phie > phi_max * (1 + 1.0e-12_dp)) then
      write(text, '(a,f6.4,a,f4.2)') 'with this minimum gap the spheres fill phi = ', phie, &
        ', above the supported ', phi_max
      call input_error(cfg%deck_file, 'packing', 'min_gap', trim(text))
    end if
    if (len_trim(cfg%directory) == 0) call input_error(cfg%deck_file, 'packing', 'directory', &
         'must not be empty')
    if (len_trim(cfg%file) == 0 .or. index(cfg%file, '/') > 0) call input_error(cfg%deck_file, &
         'packing', 'file', 'must be a plain file name (no directory part)')
  end subroutine validate

end module mod_packing_deck
