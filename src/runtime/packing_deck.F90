! The deck of bin/fdsusp-pack: one namelist group &packing (doc/PACKING_INPUT.md lists every
! variable with its default, unit and range; keep the two in step).
!
! Errors stop the program before any work with one message naming the file, the group and the
! variable (mod_errors::input_error), as for fdsusp's own deck; the line-by-line diagnosis of a
! failed namelist read is shared with mod_params (mod_deck_text).
! Units: the radius of the smallest species, a = 1 (required: radius holds 1 as its smallest
! entry); lengths in a.
module mod_packing_deck
  use mod_kinds, only: dp, pi
  use mod_errors, only: input_error
  use mod_deck_text, only: deck_line_length, load_lines, group_on_line, to_lower, diagnose_group, &
                           qualified_names, unqualified_names, plain_echo_line
  use mod_packing_geometry, only: phi_max, species_counts, species_counts_total, species_box_for
  implicit none
  private
  public :: pack_config_t, read_pack_deck, pack_deck_lines, max_line, max_species

  integer, parameter :: max_line = deck_line_length
  integer, parameter :: max_species = 8                 ! entries of radius and the shares
  real(dp), parameter :: max_radius = 10                ! largest radius [a] (size ratio)
  real(dp), parameter :: share_tolerance = 1.0e-9_dp    ! |sum of the shares - 1|

  ! &packing: its variables, named as in the deck, with their defaults (doc/DESIGN.md "Input":
  ! one derived type per group, the namelist's one object)
  type :: packing_settings_t
    real(dp) :: box(3) = [20.0_dp, 20.0_dp, 20.0_dp]    ! box lengths Lx, Ly, Lz [a]
    character(len=16) :: y_boundary = 'walls'           ! 'walls' (Couette cell) or 'periodic'
    real(dp) :: phi = 0.3_dp                            ! target volume fraction [-]
    ! species: radius(k) > 0 for k <= number of species, 0 after; the smallest must be 1
    real(dp) :: radius(max_species) = [1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    real(dp) :: volume_share(max_species) = 0.0_dp      ! share of the solid volume per species
    real(dp) :: number_share(max_species) = 0.0_dp      ! or share of the number of spheres
    integer :: n_particles = 0                          ! > 0: box rescaled to hold exactly this many
    real(dp) :: min_gap = 0.0_dp                        ! smallest surface gap, pairs and walls [a]
    integer :: seed = 1                                 ! random seed [-]
    integer :: mc_sweeps = 1000                         ! Monte Carlo equilibration sweeps [-]
    character(len=max_line) :: directory = 'out'        ! output directory (created)
    character(len=256) :: file = 'packing.h5'           ! file name inside the directory
  end type packing_settings_t

  type :: pack_config_t
    character(len=max_line) :: deck_file = ''
    type(packing_settings_t) :: packing
    ! derived, not read
    integer :: n = 0                                    ! number of spheres
    integer :: n_species = 1
    integer :: counts(max_species) = 0                  ! spheres per species
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

  !> The effective deck (defaults included) as namelist text, one line per variable.
  subroutine pack_deck_lines(cfg, text)
    type(pack_config_t), intent(in) :: cfg
    character(len=max_line), allocatable, intent(out) :: text(:)
    type(pack_config_t) :: copy
    character(len=8192) :: line            ! a character value is written padded to its length
    integer :: unit, ios
    copy = cfg
    open(newunit=unit, status='scratch', action='readwrite', recl=8192)
    call group_io(copy, echo_unit=unit)
    rewind(unit)
    allocate(text(0))
    do
      read(unit, '(a)', iostat=ios) line
      if (ios /= 0) exit
      text = [character(len=max_line) :: text, plain_echo_line(line)]
    end do
    close(unit)
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

  !> &packing read from src (its lines from '&packing' on) when present, echoed to echo_unit when
  !> present. The namelist's one object is the group's settings; the deck's names are qualified
  !> with it for the read, the compiler's message unqualified for the diagnosis (mod_deck_text).
  subroutine group_io(cfg, src, ios, msg, echo_unit)
    type(pack_config_t), intent(inout) :: cfg
    character(len=*), intent(in), optional :: src(:)
    integer, intent(out), optional :: ios
    character(len=*), intent(inout), optional :: msg
    integer, intent(in), optional :: echo_unit
    type(packing_settings_t) :: packing_group
    namelist /packing/ packing_group
    character(len=max_line), allocatable :: text(:)
    packing_group = cfg%packing
    if (present(src)) then
      text = qualified_names(src, 'packing_group')
      read(text, nml=packing, iostat=ios, iomsg=msg)
      if (ios /= 0) then
        msg = unqualified_names(msg, 'packing_group')
        return
      end if
      cfg%packing = packing_group
    end if
    if (present(echo_unit)) write(echo_unit, nml=packing)
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
    real(dp) :: phie, share(max_species), amax
    integer :: d, ns
    logical :: by_volume

    cfg%packing%y_boundary = to_lower(cfg%packing%y_boundary)
    call validate_species(cfg, share, by_volume)
    ns = cfg%n_species
    call check_real(cfg, 'phi', cfg%packing%phi, 0.0_dp, phi_max, .true.)
    call check_int(cfg, 'n_particles', cfg%packing%n_particles, 0, 10000000)
    call check_real(cfg, 'min_gap', cfg%packing%min_gap, 0.0_dp, 0.5_dp, .false.)
    call check_int(cfg, 'seed', cfg%packing%seed, 0, huge(1))
    call check_int(cfg, 'mc_sweeps', cfg%packing%mc_sweeps, 0, 10000000)
    if (cfg%packing%y_boundary /= 'walls' .and. cfg%packing%y_boundary /= 'periodic') &
      call input_error(cfg%deck_file, 'packing', 'y_boundary', &
           'must be ''walls'' or ''periodic'', not '''//trim(cfg%packing%y_boundary)//'''')
    cfg%periodic = [.true., cfg%packing%y_boundary == 'periodic', .true.]
    do d = 1, 3
      call check_real(cfg, 'box('//xyz(d:d)//')', cfg%packing%box(d), 0.0_dp, 1.0e4_dp, .true.)
    end do
    associate (r => cfg%packing%radius(1:ns), counts => cfg%counts(1:ns))
      if (cfg%packing%n_particles > 0) then
        counts = species_counts_total(cfg%packing%n_particles, r, share(1:ns), by_volume)
        if (any(counts < 1)) call input_error(cfg%deck_file, 'packing', 'n_particles', &
             'too few for one sphere of every species')
        cfg%packing%box = species_box_for(counts, r, cfg%packing%phi, cfg%packing%box)
      else
        counts = species_counts(cfg%packing%phi, cfg%packing%box, r, share(1:ns), by_volume)
        if (any(counts < 1)) call input_error(cfg%deck_file, 'packing', 'phi', &
             'gives no sphere'//trim(merge(' of some species', '                ', ns > 1))// &
             ' in this box (set a larger phi or box, or n_particles)')
      end if
      cfg%n = sum(counts)
      amax = maxval(r)
      do d = 1, 3
        if (cfg%packing%box(d) < 4 * (amax + cfg%packing%min_gap)) then
          write(text, '(a,f0.4,a)') 'every box length must be at least 4 (a_max + min_gap), a_max the '// &
            'largest radius (it is ', cfg%packing%box(d), ' a)'
          call input_error(cfg%deck_file, 'packing', 'box('//xyz(d:d)//')', trim(text))
        end if
      end do
      ! the spheres with the gap, less one of the largest (the slack of the packer's own check)
      phie = (sum(counts * (4 * pi / 3) * (r + cfg%packing%min_gap / 2)**3) - &
              (4 * pi / 3) * (amax + cfg%packing%min_gap / 2)**3) / product(cfg%packing%box)
    end associate
    if (cfg%packing%min_gap > 0 .and. phie > phi_max * (1 + 1.0e-12_dp)) then
      write(text, '(a,f6.4,a,f4.2)') 'with this minimum gap the spheres fill phi = ', phie, &
        ', above the supported ', phi_max
      call input_error(cfg%deck_file, 'packing', 'min_gap', trim(text))
    end if
    if (len_trim(cfg%packing%directory) == 0) call input_error(cfg%deck_file, 'packing', 'directory', &
         'must not be empty')
    if (len_trim(cfg%packing%file) == 0 .or. index(cfg%packing%file, '/') > 0) call input_error(cfg%deck_file, &
         'packing', 'file', 'must be a plain file name (no directory part)')
  end subroutine validate

  !> The species: radius(1:n_species) positive and the rest 0, the smallest 1 (the unit of
  !> length), none above max_radius; one share list (volume_share or number_share) with one
  !> positive entry per species adding up to 1 within share_tolerance (optional for one species).
  !> share: the shares given (1 for one species without), by_volume: they are volume shares.
  subroutine validate_species(cfg, share, by_volume)
    type(pack_config_t), intent(inout) :: cfg
    real(dp), intent(out) :: share(max_species)
    logical, intent(out) :: by_volume
    character(len=200) :: text
    character(len=16) :: name
    integer :: k, ns, m
    associate (r => cfg%packing%radius)
      ns = 0
      do k = 1, max_species
        if (.not. (r(k) > 0)) exit
        ns = k
      end do
      do k = ns + 1, max_species
        if (r(k) /= 0 .or. k == 1) then
          write(text, '(a,i0,a,es10.3,a)') 'radius(', k, ') = ', r(k), ' must be positive (a list of '// &
            'one positive radius per species)'
          call input_error(cfg%deck_file, 'packing', 'radius', trim(text))
        end if
      end do
      if (abs(minval(r(1:ns)) - 1) > 1.0e-12_dp) then
        write(text, '(a,es10.3,a)') 'the smallest radius is the unit of length and must be 1 (it is ', &
          minval(r(1:ns)), '): divide the radii, box and min_gap by it'
        call input_error(cfg%deck_file, 'packing', 'radius', trim(text))
      end if
      if (maxval(r(1:ns)) > max_radius) then
        write(text, '(a,es10.3,a,f0.1,a)') 'largest radius ', maxval(r(1:ns)), ' above ', max_radius, &
          ' (size ratio at most 10)'
        call input_error(cfg%deck_file, 'packing', 'radius', trim(text))
      end if
    end associate
    cfg%n_species = ns
    by_volume = .true.
    if (any(cfg%packing%volume_share /= 0) .and. any(cfg%packing%number_share /= 0)) &
      call input_error(cfg%deck_file, 'packing', 'number_share', 'given together with volume_share: '// &
           'give one of the two')
    if (any(cfg%packing%volume_share /= 0)) then
      name = 'volume_share'
      share = cfg%packing%volume_share
    else if (any(cfg%packing%number_share /= 0)) then
      name = 'number_share'
      share = cfg%packing%number_share
      by_volume = .false.
    else
      if (ns > 1) then
        write(text, '(a,i0,a)') 'a mixture (radius has ', ns, ' entries) needs volume_share or number_share'
        call input_error(cfg%deck_file, 'packing', 'volume_share', trim(text))
      end if
      share = 0
      share(1) = 1
      return
    end if
    m = 0
    do k = 1, max_species
      if (share(k) /= 0) m = k
    end do
    if (m /= ns) then
      write(text, '(a,i0,a,i0,a)') 'has ', m, ' entries, radius ', ns, ' (one share per species)'
      call input_error(cfg%deck_file, 'packing', trim(name), trim(text))
    end if
    do k = 1, ns
      if (.not. (share(k) > 0 .and. share(k) <= 1)) then
        write(text, '(a,i0,a,es10.3,a)') '(', k, ') = ', share(k), ' must be in (0, 1]'
        call input_error(cfg%deck_file, 'packing', trim(name), trim(name)//trim(text))
      end if
    end do
    if (abs(sum(share(1:ns)) - 1) > share_tolerance) then
      write(text, '(a,es22.15,a)') 'the shares add up to ', sum(share(1:ns)), ', not 1 (within 1e-9)'
      call input_error(cfg%deck_file, 'packing', trim(name), trim(text))
    end if
  end subroutine validate_species

end module mod_packing_deck
