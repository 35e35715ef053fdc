! The input deck: Fortran namelist groups, their defaults, units, valid ranges and the echo of the
! effective deck. Every variable is documented in doc/INPUT.md; keep the two in step.
!
! One derived type per group (doc/DESIGN.md "The deck"): its components are the group's variables,
! named as in the deck, with their defaults; the type is the namelist's one object, so a variable
! is declared once, in its type, and validated once, below (its range and message). The physics
! modules own the types of the groups they alone read (&contact: mod_particle_contacts, &rheology:
! mod_rheology) and are passed them whole. A namelist read of a derived-type object wants
! 'object%variable = value'; mod_deck_text qualifies the deck's names so before reading, and the
! echo drops the qualifier again, so the deck keeps its plain names.
!
! Reading is collective: every rank reads the same file, so every rank detects the same error and
! the run stops cleanly with one message (mod_errors::input_error) naming the file, the group and
! the variable, before any work is done.
!
! Units: radius a = 1, fluid viscosity eta = 1, imposed shear rate = 1 (doc/METHOD.md §0.2). Lengths in a,
! times in strain units 1/gamma_dot, stresses in eta*gamma_dot.
module mod_params
  use mod_kinds, only: dp
  use mod_errors, only: input_error, log_line, is_root
  use mod_deck_text, only: deck_line_length, load_lines, group_on_line, to_lower, diagnose_group, &
                           qualified_names, unqualified_names, plain_echo_line
  use mod_packing_geometry, only: phi_max
  use mod_particle_contacts, only: particle_contacts_settings_t
  use mod_rheology, only: rheology_settings_t
  use mod_shear_protocol, only: shear_protocol_kind, shear_protocol_reference_rate, PROTOCOL_OSCILLATORY, MAX_LEVELS
  implicit none
  private
  public :: config_t, read_deck, echo_deck, max_line, max_inline_particles, max_species
  public :: domain_settings_t, shear_settings_t, fluid_settings_t, time_settings_t, output_settings_t, run_settings_t, &
            verification_settings_t, particles_settings_t, lubrication_settings_t

  integer, parameter :: max_line = deck_line_length
  integer, parameter :: max_inline_particles = 64
  integer, parameter :: max_species = 8           ! sphere sizes of a mixture (&particles radius)
  integer, parameter :: ngroups = 11
  character(len=16), parameter :: known_groups(ngroups) = [character(len=16) :: &
       'domain', 'shear', 'fluid', 'time', 'output', 'run', 'verification', 'particles', 'contact', 'lubrication', &
       'rheology']
  ! a rate the deck did not give (&domain shear_rate, &shear rate): one of them may give it
  real(dp), parameter :: rate_not_given = -huge(1.0_dp)

  ! &domain
  type :: domain_settings_t
    real(dp) :: box(3) = [20.0_dp, 20.0_dp, 20.0_dp]   ! box lengths Lx, Ly, Lz [a]
    real(dp) :: cells_per_radius = 5.0_dp               ! a/Delta [-]
    character(len=16) :: y_boundary = 'walls'           ! 'walls' (Couette), 'periodic' or 'lees-edwards'
    ! the older name of &shear rate (doc/INPUT.md "&shear"); after validation the reference rate
    real(dp) :: shear_rate = rate_not_given             ! walls move at +-shear_rate*Ly/2 [gamma_dot]
  end type domain_settings_t

  ! &shear: the imposed flow (doc/INPUT.md "&shear"; mod_shear_protocol)
  type :: shear_settings_t
    real(dp) :: rate = rate_not_given                   ! the imposed rate (default 1) [gamma_dot]
    character(len=16) :: control = 'rate'               ! 'rate' or 'stress' (lubrication dynamics)
    real(dp) :: stress = 0.0_dp                         ! control = 'stress': the mean shear stress [eta*gamma_dot]
    character(len=16) :: protocol = 'steady'            ! 'steady', 'reversal' or 'oscillatory'
    real(dp) :: reversal_strain = 0.0_dp                ! 'reversal': the strain between reversals [-]
    real(dp) :: strain_amplitude = 0.0_dp               ! 'oscillatory': gamma_0 [-]
    real(dp) :: period = 0.0_dp                         ! 'oscillatory': T [1/gamma_dot]
    integer :: levels = 0                               ! 'steps': how many levels (2..MAX_LEVELS)
    character(len=16) :: step_by = 'strain'             ! 'steps': step_at counts 'strain' (accumulated |strain|) or 'time'
    real(dp) :: step_at(MAX_LEVELS) = 0.0_dp            ! 'steps': where each level starts [-] or [1/gamma_dot]
    real(dp) :: step_level(MAX_LEVELS) = 0.0_dp         ! 'steps': each level's rate [gamma_dot] (stress control: stress [eta*gamma_dot])
  end type shear_settings_t

  ! &fluid
  type :: fluid_settings_t
    character(len=16) :: model = 'resolved'             ! 'resolved' (the DNS) or 'none' (lubrication dynamics)
    real(dp) :: reynolds = 0.01_dp                      ! rho*gamma_dot*a^2/eta [-]
    real(dp) :: body_force(3) = 0.0_dp                  ! uniform force density [eta*gamma_dot/a]
    ! 1e-6: eta_r within 1e-7 of the tight 1e-8/1e-10 at 22 % less CPU (doc/BENCHMARKS.md §9)
    real(dp) :: velocity_tolerance = 1.0e-6_dp          ! KSP rtol of the Helmholtz solves [-]
    real(dp) :: pressure_tolerance = 1.0e-6_dp          ! KSP rtol of the pressure Poisson solve [-]
    real(dp) :: viscous_theta = 0.5_dp                  ! 0.5 Crank-Nicolson, 1 backward Euler [-]
    character(len=16) :: initial_flow = 'rest'          ! 'rest' or 'shear' (the linear Couette profile)
  end type fluid_settings_t

  ! &time
  type :: time_settings_t
    real(dp) :: dt = 1.0e-3_dp                          ! time step [1/gamma_dot]
    integer :: steps = -1                               ! last step [-] (-1: 1000, or what &rheology needs)
    real(dp) :: steady_tolerance = 0.0_dp               ! stop when max|du|/dt < tol*U_ref (0: off)
  end type time_settings_t

  ! &output
  type :: output_settings_t
    character(len=max_line) :: directory = 'out'
    integer :: progress_every = 100                     ! steps between progress lines
    integer :: series_every = 1                         ! steps between series.h5 records
    integer :: fields_every = 0                         ! steps between field snapshots (0: end only)
    integer :: checkpoint_every = 0                     ! steps between checkpoints (0: end only)
    integer :: particles_every = 0                      ! steps between particle snapshots (0: end only)
  end type output_settings_t

  ! &run
  type :: run_settings_t
    character(len=256) :: title = ''
    real(dp) :: max_wall_hours = 0.0_dp                 ! checkpoint and stop after this (0: never)
  end type run_settings_t

  ! &verification
  type :: verification_settings_t
    logical :: manufactured_solution = .false.          ! force with the manufactured solution
  end type verification_settings_t

  ! &particles (inline arrays hold up to max_inline_particles; larger sets come from a file)
  type :: particles_settings_t
    integer :: number = 0                               ! particles given inline
    real(dp) :: position(3, max_inline_particles) = 0.0_dp          ! centres [a]
    character(len=max_line) :: position_file = ''       ! HDF5 file with particles/position
    ! the radius of each species [a], smallest first (one entry: equal spheres); the smallest is
    ! the unit of length, so it is 1 for a mixture (doc/INPUT.md "Mixtures")
    real(dp) :: radius(max_species) = [1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
    real(dp) :: volume_share(max_species) = 0.0_dp      ! a mixture's share of the solid volume per species [-]
    real(dp) :: number_share(max_species) = 0.0_dp      ! or of the spheres per species [-]
    integer :: species(max_inline_particles) = 1        ! a mixture's inline particle i: its radius is radius(species(i))
    character(len=16) :: motion = 'free'                ! 'free', 'prescribed', 'resistance' or 'frozen'
    real(dp) :: velocity(3, max_inline_particles) = 0.0_dp          ! prescribed U [a*gamma_dot]
    real(dp) :: omega(3, max_inline_particles) = 0.0_dp             ! prescribed Omega [gamma_dot]
    real(dp) :: external_force(3, max_inline_particles) = 0.0_dp    ! [eta*gamma_dot*a^2]
    real(dp) :: external_torque(3, max_inline_particles) = 0.0_dp   ! [eta*gamma_dot*a^3]
    real(dp) :: radius_offset = 0.38_dp                 ! alpha radius = radius + offset*h [h]
    real(dp) :: slip_kappa = 0.5_dp                     ! relaxation on partly covered faces [-]
    real(dp) :: solid_fraction = 0.0_dp                 ! > 0: pack this volume fraction at start [-]
    integer :: seed = 1                                 ! random seed of that packing [-]
    integer :: packing_sweeps = 200                     ! its hard-sphere Monte Carlo sweeps [-]
    real(dp) :: packing_min_gap = -1.0_dp               ! its smallest surface gap [a] (-1: h_r with contacts, else 0)
  end type particles_settings_t

  ! &lubrication (doc/LUBRICATION.md)
  type :: lubrication_settings_t
    character(len=16) :: model = 'full'                 ! 'none', 'simple' or 'full'
    character(len=max_line) :: table = ''               ! '' = the shipped table for this a/Delta
    real(dp) :: outer_cutoff = 0.0_dp                   ! gap where the correction ends [a] (0: model default)
    real(dp) :: inner_cutoff = 1.0e-4_dp                ! smallest gap the correction is evaluated at [a]
    real(dp) :: skin = 0.2_dp                           ! neighbour-list skin of lubricating pairs [a]
  end type lubrication_settings_t

  ! The deck: its groups as read (defaults where absent), and what follows from them.
  type :: config_t
    character(len=max_line) :: deck_file = ''
    type(domain_settings_t) :: domain
    type(shear_settings_t) :: shear
    type(fluid_settings_t) :: fluid
    type(time_settings_t) :: time
    type(output_settings_t) :: output
    type(run_settings_t) :: run
    type(verification_settings_t) :: verification
    type(particles_settings_t) :: particles
    type(particle_contacts_settings_t) :: contact       ! active when the group is present and the run has particles
    type(lubrication_settings_t) :: lubrication
    type(rheology_settings_t) :: rheology               ! statistics on when the group is present
    ! derived, not read
    integer :: species = 1                              ! sphere sizes: the positive entries of radius
    real(dp) :: radius = 1.0_dp                         ! the smallest sphere's radius [a] (of equal spheres: theirs)
    real(dp) :: radius_max = 1.0_dp                     ! the largest sphere's radius [a]
    logical :: contact_group = .false.                  ! the deck has a &contact group
    logical :: rheology_group = .false.                 ! the deck has a &rheology group
    integer :: discard_step = 0, block_steps = 1        ! the &rheology window in steps
    integer :: cells(3) = 0
    logical :: walls = .true.
    logical :: lees_edwards = .false.                   ! y_boundary = 'lees-edwards'
    logical :: resolved = .true.                        ! &fluid model = 'resolved'
    real(dp) :: h = 0.0_dp                              ! grid spacing Delta [a]
    real(dp) :: wall_speed = 0.0_dp                     ! top wall +U, bottom wall -U at t = 0 [a*gamma_dot]
    character(len=16) :: rate_group = 'shear'           ! the group that gave the rate: 'shear' or 'domain'
    character(len=16) :: rate_name = 'rate'             ! and its name there: 'rate' or 'shear_rate'
  end type config_t

  ! state of a diagnosis in progress (read_group -> mod_deck_text -> read_into_copy)
  type(config_t), save :: diagnosis_base
  character(len=16), save :: diagnosis_group = ''

contains

  ! Read, validate and derive the whole configuration from DECK. Collective.
  subroutine read_deck(deck, cfg)
    character(len=*), intent(in) :: deck
    type(config_t), intent(out) :: cfg
    character(len=max_line), allocatable :: lines(:)
    integer :: g

    cfg%deck_file = deck
    call load_lines(deck, lines)
    call check_group_names(deck, lines)
    do g = 1, ngroups
      call read_group(deck, lines, trim(known_groups(g)), cfg)
    end do
    call validate(cfg)
  end subroutine read_deck

  ! Every '&name' in the deck must be a group this program knows.
  subroutine check_group_names(deck, lines)
    character(len=*), intent(in) :: deck
    character(len=*), intent(in) :: lines(:)
    integer :: l
    character(len=64) :: name
    character(len=16) :: lnum
    do l = 1, size(lines)
      name = group_on_line(lines(l))
      if (len_trim(name) == 0 .or. name == 'end') cycle
      if (.not. any(known_groups == name)) then
        write(lnum, '(i0)') l
        call input_error(deck, trim(name), '', 'unknown group (line '//trim(lnum)// &
             '); known groups: &domain &shear &fluid &time &output &run &verification &particles &contact &lubrication '// &
             '&rheology')
      end if
    end do
  end subroutine check_group_names

  ! Read one group from the deck text. If it is absent, the defaults stand. If reading fails,
  ! mod_deck_text finds the line at fault and names its variable.
  subroutine read_group(deck, lines, group, cfg)
    character(len=*), intent(in) :: deck, group
    character(len=*), intent(in) :: lines(:)
    type(config_t), intent(inout) :: cfg
    character(len=512) :: msg
    integer :: first, l, ios

    first = 0
    do l = 1, size(lines)
      if (group_on_line(lines(l)) == group) then
        first = l
        exit
      end if
    end do
    if (first == 0) return
    msg = ''
    call group_io(group, cfg, lines(first:), ios, msg)
    if (ios /= 0) then
      diagnosis_base = cfg
      diagnosis_group = group
      call diagnose_group(deck, group, lines, first, read_into_copy)
    end if
    if (group == 'contact') cfg%contact_group = .true.
    if (group == 'rheology') cfg%rheology_group = .true.
  end subroutine read_group

  ! The reader mod_deck_text calls while diagnosing: reads group diagnosis_group from src into a
  ! copy of diagnosis_base. (A module procedure, not an internal one: passing an internal
  ! procedure would need an executable stack.)
  subroutine read_into_copy(src, ios, msg)
    character(len=*), intent(in) :: src(:)
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    type(config_t) :: trial
    trial = diagnosis_base
    call group_io(trim(diagnosis_group), trial, src, ios, msg)
  end subroutine read_into_copy

  ! One group of the deck: read from src (its lines from the '&group' on) when present, echoed to
  ! echo_unit when present. Each group's namelist has one object, the group's settings, named
  ! GROUP_group; the deck's names are qualified with it for the read (mod_deck_text), and the
  ! compiler's message unqualified again for the diagnosis.
  subroutine group_io(group, cfg, src, ios, msg, echo_unit)
    character(len=*), intent(in) :: group
    type(config_t), intent(inout) :: cfg
    character(len=*), intent(in), optional :: src(:)
    integer, intent(out), optional :: ios
    character(len=*), intent(inout), optional :: msg
    integer, intent(in), optional :: echo_unit
    type(domain_settings_t) :: domain_group
    type(shear_settings_t) :: shear_group
    type(fluid_settings_t) :: fluid_group
    type(time_settings_t) :: time_group
    type(output_settings_t) :: output_group
    type(run_settings_t) :: run_group
    type(verification_settings_t) :: verification_group
    type(particles_settings_t) :: particles_group
    type(particle_contacts_settings_t) :: contact_group
    type(lubrication_settings_t) :: lubrication_group
    type(rheology_settings_t) :: rheology_group
    namelist /domain/ domain_group
    namelist /shear/ shear_group
    namelist /fluid/ fluid_group
    namelist /time/ time_group
    namelist /output/ output_group
    namelist /run/ run_group
    namelist /verification/ verification_group
    namelist /particles/ particles_group
    namelist /contact/ contact_group
    namelist /lubrication/ lubrication_group
    namelist /rheology/ rheology_group
    character(len=max_line), allocatable :: text(:)
    character(len=:), allocatable :: object
    integer :: stat

    domain_group = cfg%domain
    shear_group = cfg%shear
    fluid_group = cfg%fluid
    time_group = cfg%time
    output_group = cfg%output
    run_group = cfg%run
    verification_group = cfg%verification
    particles_group = cfg%particles
    contact_group = cfg%contact
    lubrication_group = cfg%lubrication
    rheology_group = cfg%rheology
    object = group//'_group'
    if (present(src)) then
      text = qualified_names(src, object)
      stat = 0
      select case (group)
      case ('domain');       read(text, nml=domain, iostat=stat, iomsg=msg)
      case ('shear');        read(text, nml=shear, iostat=stat, iomsg=msg)
      case ('fluid');        read(text, nml=fluid, iostat=stat, iomsg=msg)
      case ('time');         read(text, nml=time, iostat=stat, iomsg=msg)
      case ('output');       read(text, nml=output, iostat=stat, iomsg=msg)
      case ('run');          read(text, nml=run, iostat=stat, iomsg=msg)
      case ('verification'); read(text, nml=verification, iostat=stat, iomsg=msg)
      case ('particles');    read(text, nml=particles, iostat=stat, iomsg=msg)
      case ('contact');      read(text, nml=contact, iostat=stat, iomsg=msg)
      case ('lubrication');  read(text, nml=lubrication, iostat=stat, iomsg=msg)
      case ('rheology');     read(text, nml=rheology, iostat=stat, iomsg=msg)
      end select
      ios = stat
      if (stat /= 0) then
        msg = unqualified_names(msg, object)
        return
      end if
      cfg%domain = domain_group
      cfg%shear = shear_group
      cfg%fluid = fluid_group
      cfg%time = time_group
      cfg%output = output_group
      cfg%run = run_group
      cfg%verification = verification_group
      cfg%particles = particles_group
      cfg%contact = contact_group
      cfg%lubrication = lubrication_group
      cfg%rheology = rheology_group
    end if
    if (present(echo_unit)) then
      select case (group)
      case ('domain');       write(echo_unit, nml=domain)
      case ('shear');        write(echo_unit, nml=shear)
      case ('fluid');        write(echo_unit, nml=fluid)
      case ('time');         write(echo_unit, nml=time)
      case ('output');       write(echo_unit, nml=output)
      case ('run');          write(echo_unit, nml=run)
      case ('verification'); write(echo_unit, nml=verification)
      case ('particles');    write(echo_unit, nml=particles)
      case ('lubrication');  write(echo_unit, nml=lubrication)
      case ('rheology')
        if (cfg%rheology_group) then
          write(echo_unit, nml=rheology)
        else
          write(echo_unit, '(a)') '! &rheology absent: no statistics'
        end if
      case ('contact')
        ! only when given: an absent &contact means no contacts, not these defaults
        if (cfg%contact_group) then
          write(echo_unit, nml=contact)
        else
          write(echo_unit, '(a)') '! &contact absent: no contact forces'
        end if
      end select
    end if
  end subroutine group_io

  ! The effective deck (defaults included), at the top of the run log, readable as a deck: the
  ! compiler's qualified names lose their GROUP_group% again, character values their padding, and
  ! &particles' inline arrays are cut to the particles given (not 64 x 3 zeros each).
  subroutine echo_deck(cfg)
    type(config_t), intent(in) :: cfg
    type(config_t) :: copy
    ! (a namelist write puts an array in one record: 64 inline spheres' values, ~25 characters each,
    ! in each of &particles' arrays)
    character(len=65536) :: line
    character(len=32) :: item
    character(len=64) :: group
    integer :: g, unit, ios, e, p
    logical :: inline_array
    character(len=16), parameter :: inline_arrays(6) = [character(len=16) :: 'position', 'velocity', 'omega', &
                                                         'external_force', 'external_torque', 'species']
    if (.not. is_root()) return
    copy = cfg
    open(newunit=unit, status='scratch', action='readwrite', recl=len(line))
    do g = 1, ngroups
      call group_io(trim(known_groups(g)), copy, echo_unit=unit)
    end do
    rewind(unit)
    write(*, '(a)') '# effective deck (file '//trim(cfg%deck_file)//', defaults included)'
    inline_array = .false.
    group = ''
    do
      read(unit, '(a)', iostat=ios) line
      if (ios /= 0) exit
      ! '&GROUP' opens a group, ' GROUP_GROUP%NAME= values' an item, '/' closes the group; other
      ! lines continue the last item. The rate is echoed once, as &shear rate (an oscillation's
      ! follows from its amplitude and period, and is not echoed): the deck reads back alike
      e = index(line, '=')
      p = index(line(1:max(e, 1)), '%')
      if (len_trim(group_on_line(line)) > 0) then
        group = group_on_line(line)
      else if (line(1:1) == ' ' .and. p > 0) then
        item = to_lower(line(p + 1:e - 1))
        inline_array = (group == 'particles' .and. any(inline_arrays == item)) .or. &
                       (group == 'domain' .and. item == 'shear_rate') .or. &
                       (group == 'shear' .and. item == 'rate' .and. cfg%shear%protocol == 'oscillatory')
      else if (adjustl(line) == '/') then
        if (group == 'particles') call echo_inline_particles(cfg%particles)
        inline_array = .false.
      end if
      if (.not. inline_array) write(*, '(a)') trim(plain_echo_line(line))
    end do
    close(unit)
    write(*, '(a)') '# end of effective deck'
    flush(6)
  end subroutine echo_deck

  ! The inline particles of &particles, one line per particle and array, zeros left out.
  subroutine echo_inline_particles(particles)
    type(particles_settings_t), intent(in) :: particles
    integer :: p
    character(len=*), parameter :: row = '(a,i0,a,3(es23.15e3,:,","))'
    do p = 1, particles%number
      write(*, row) ' position(:,', p, ')=', particles%position(:, p)
      if (any(particles%velocity(:, p) /= 0.0_dp)) write(*, row) ' velocity(:,', p, ')=', particles%velocity(:, p)
      if (any(particles%omega(:, p) /= 0.0_dp)) write(*, row) ' omega(:,', p, ')=', particles%omega(:, p)
      if (any(particles%external_force(:, p) /= 0.0_dp)) &
        write(*, row) ' external_force(:,', p, ')=', particles%external_force(:, p)
      if (any(particles%external_torque(:, p) /= 0.0_dp)) &
        write(*, row) ' external_torque(:,', p, ')=', particles%external_torque(:, p)
      if (particles%species(p) /= 1) write(*, '(a,i0,a,i0)') ' species(', p, ')=', particles%species(p)
    end do
  end subroutine echo_inline_particles

  ! ---- validation -------------------------------------------------------------------------

  subroutine check_real(cfg, group, name, value, lo, hi, lo_open)
    type(config_t), intent(in) :: cfg
    character(len=*), intent(in) :: group, name
    real(dp), intent(in) :: value, lo, hi
    logical, intent(in), optional :: lo_open
    character(len=160) :: text
    character(len=1) :: bracket
    logical :: open_lo
    open_lo = .false.
    if (present(lo_open)) open_lo = lo_open
    bracket = '['
    if (open_lo) bracket = '('
    if (value /= value .or. value > hi .or. value < lo .or. (open_lo .and. value <= lo)) then
      write(text, '(a,es11.4,2a,es10.3,a,es10.3,a)') 'value ', value, ' out of range ', bracket, lo, ',', hi, ']'
      call input_error(cfg%deck_file, group, name, trim(text))
    end if
  end subroutine check_real

  subroutine check_int(cfg, group, name, value, lo, hi)
    type(config_t), intent(in) :: cfg
    character(len=*), intent(in) :: group, name
    integer, intent(in) :: value, lo, hi
    character(len=160) :: text
    if (value < lo .or. value > hi) then
      write(text, '(a,i0,a,i0,a,i0,a)') 'value ', value, ' out of range [', lo, ', ', hi, ']'
      call input_error(cfg%deck_file, group, name, trim(text))
    end if
  end subroutine check_int

  subroutine validate(cfg)
    type(config_t), intent(inout) :: cfg
    integer :: d
    real(dp) :: n
    character(len=*), parameter :: xyz = 'xyz'
    character(len=200) :: text

    ! the keywords are read case-blind
    cfg%domain%y_boundary = to_lower(cfg%domain%y_boundary)
    cfg%fluid%model = to_lower(cfg%fluid%model)
    cfg%fluid%initial_flow = to_lower(cfg%fluid%initial_flow)
    cfg%particles%motion = to_lower(cfg%particles%motion)
    cfg%lubrication%model = to_lower(cfg%lubrication%model)
    do d = 1, 3
      call check_real(cfg, 'domain', 'box('//xyz(d:d)//')', cfg%domain%box(d), 0.0_dp, 1.0e4_dp, .true.)
    end do
    call check_real(cfg, 'domain', 'cells_per_radius', cfg%domain%cells_per_radius, 1.0_dp, 64.0_dp)
    if (cfg%fluid%model /= 'resolved' .and. cfg%fluid%model /= 'none') &
      call input_error(cfg%deck_file, 'fluid', 'model', 'must be ''resolved'' or ''none'', not '''// &
           trim(cfg%fluid%model)//'''')
    cfg%resolved = (cfg%fluid%model == 'resolved')
    if (all(cfg%domain%y_boundary /= [character(len=16) :: 'walls', 'periodic', 'lees-edwards'])) &
      call input_error(cfg%deck_file, 'domain', 'y_boundary', 'must be ''walls'', ''periodic'' or ''lees-edwards'', not '''// &
           trim(cfg%domain%y_boundary)//'''')
    cfg%lees_edwards = (cfg%domain%y_boundary == 'lees-edwards')
    call resolve_shear_rate(cfg)
    cfg%walls = (cfg%domain%y_boundary == 'walls')
    if (.not. cfg%walls .and. .not. cfg%lees_edwards .and. cfg%domain%shear_rate /= 0.0_dp) &
      call input_error(cfg%deck_file, trim(cfg%rate_group), trim(cfg%rate_name), &
           'a periodic box in y cannot be sheared by walls: set '//trim(cfg%rate_name)//' = 0 or y_boundary = ''walls''')
    cfg%h = 1.0_dp / cfg%domain%cells_per_radius
    do d = 1, 3
      n = cfg%domain%box(d) * cfg%domain%cells_per_radius
      if (.not. cfg%resolved) then
        ! no grid: the cell count is only recorded
        cfg%cells(d) = max(4, nint(n))
        cycle
      end if
      if (abs(n - nint(n)) > 1.0e-9_dp * n) then
        write(text, '(a,f0.6,a)') 'box length times cells_per_radius must be a whole number of cells (it is ', n, ')'
        call input_error(cfg%deck_file, 'domain', 'box('//xyz(d:d)//')', trim(text))
      end if
      cfg%cells(d) = nint(n)
      if (cfg%cells(d) < 4) &
        call input_error(cfg%deck_file, 'domain', 'box('//xyz(d:d)//')', 'fewer than 4 cells across the box')
    end do
    cfg%wall_speed = 0.0_dp
    if (cfg%walls) cfg%wall_speed = 0.5_dp * cfg%domain%shear_rate * cfg%domain%box(2)

    call check_real(cfg, 'fluid', 'reynolds', cfg%fluid%reynolds, 0.0_dp, 100.0_dp, .true.)
    do d = 1, 3
      call check_real(cfg, 'fluid', 'body_force('//xyz(d:d)//')', cfg%fluid%body_force(d), -1.0e6_dp, 1.0e6_dp)
    end do
    call check_real(cfg, 'fluid', 'velocity_tolerance', cfg%fluid%velocity_tolerance, 1.0e-15_dp, 0.1_dp)
    call check_real(cfg, 'fluid', 'pressure_tolerance', cfg%fluid%pressure_tolerance, 1.0e-15_dp, 0.1_dp)
    call check_real(cfg, 'fluid', 'viscous_theta', cfg%fluid%viscous_theta, 0.5_dp, 1.0_dp)
    if (cfg%fluid%initial_flow /= 'rest' .and. cfg%fluid%initial_flow /= 'shear') &
      call input_error(cfg%deck_file, 'fluid', 'initial_flow', 'must be ''rest'' or ''shear'', not '''// &
           trim(cfg%fluid%initial_flow)//'''')

    call check_real(cfg, 'time', 'dt', cfg%time%dt, 0.0_dp, 10.0_dp, .true.)
    if (cfg%time%steps /= -1) call check_int(cfg, 'time', 'steps', cfg%time%steps, 0, 1000000000)
    call check_real(cfg, 'time', 'steady_tolerance', cfg%time%steady_tolerance, 0.0_dp, 1.0_dp)
    if (.not. cfg%resolved .and. cfg%time%steady_tolerance > 0.0_dp) &
      call input_error(cfg%deck_file, 'time', 'steady_tolerance', 'measures the fluid: needs &fluid model = ''resolved''')
    call validate_shear(cfg)

    if (len_trim(cfg%output%directory) == 0) &
      call input_error(cfg%deck_file, 'output', 'directory', 'must not be empty')
    call check_int(cfg, 'output', 'progress_every', cfg%output%progress_every, 1, huge(1))
    call check_int(cfg, 'output', 'series_every', cfg%output%series_every, 1, huge(1))
    call check_int(cfg, 'output', 'fields_every', cfg%output%fields_every, 0, huge(1))
    call check_int(cfg, 'output', 'checkpoint_every', cfg%output%checkpoint_every, 0, huge(1))
    call check_int(cfg, 'output', 'particles_every', cfg%output%particles_every, 0, huge(1))

    call check_real(cfg, 'run', 'max_wall_hours', cfg%run%max_wall_hours, 0.0_dp, 1.0e5_dp)

    call validate_particles(cfg)
    call validate_contact(cfg)
    call validate_lubrication(cfg)
    call validate_rheology(cfg)
    if (cfg%time%steps == -1) cfg%time%steps = 1000
    ! the in-run packing of a rough contact run starts contact-free, like the paper's hard-sphere
    ! configurations (the start-gap rule of mod_particles::configuration_fault asks for h_r/2)
    if (cfg%particles%packing_min_gap == -1.0_dp) then
      cfg%particles%packing_min_gap = 0.0_dp
      if (cfg%contact_group) cfg%particles%packing_min_gap = cfg%contact%roughness * cfg%radius
    else if (cfg%contact_group .and. cfg%particles%solid_fraction > 0.0_dp &
             .and. cfg%particles%packing_min_gap < 0.5_dp * cfg%contact%roughness * cfg%radius) then
      call input_error(cfg%deck_file, 'particles', 'packing_min_gap', &
           'rough contacts need gaps >= h_r/2 at the start (&contact roughness x radius / 2)')
    end if

    if (cfg%verification%manufactured_solution .and. any(cfg%fluid%body_force /= 0.0_dp)) &
      call input_error(cfg%deck_file, 'verification', 'manufactured_solution', &
           'the manufactured solution brings its own forcing: set &fluid body_force = 0')
  end subroutine validate

  ! Ranges of &particles; positions given inline are checked against the box here, those from a
  ! file by mod_particles_io when it reads them (same rules, mod_particles::configuration_fault).
  subroutine validate_particles(cfg)
    type(config_t), intent(inout) :: cfg
    logical :: exists
    call check_int(cfg, 'particles', 'number', cfg%particles%number, 0, max_inline_particles)
    call validate_species(cfg)
    if (all(cfg%particles%motion /= [character(len=16) :: 'free', 'prescribed', 'resistance', 'frozen', 'fixed'])) &
      call input_error(cfg%deck_file, 'particles', 'motion', &
           'must be ''free'', ''prescribed'', ''resistance'', ''frozen'' or ''fixed'', not '''// &
           trim(cfg%particles%motion)//'''')
    call check_real(cfg, 'particles', 'radius_offset', cfg%particles%radius_offset, -2.0_dp, 2.0_dp)
    call check_real(cfg, 'particles', 'slip_kappa', cfg%particles%slip_kappa, 0.0_dp, 100.0_dp)
    if (len_trim(cfg%particles%position_file) > 0) then
      if (cfg%particles%number > 0) &
        call input_error(cfg%deck_file, 'particles', 'position_file', &
             'give the particles either inline (number, position) or in position_file, not both')
      inquire(file=trim(cfg%particles%position_file), exist=exists)
      if (.not. exists) call input_error(cfg%deck_file, 'particles', 'position_file', &
           '"'//trim(cfg%particles%position_file)//'" does not exist')
      if (cfg%particles%motion == 'prescribed' .or. cfg%particles%motion == 'resistance') &
        call input_error(cfg%deck_file, 'particles', 'motion', &
           'prescribed velocities are given inline: use number and position, not position_file')
    end if
    call validate_inline_species(cfg)
    call check_real(cfg, 'particles', 'solid_fraction', cfg%particles%solid_fraction, 0.0_dp, phi_max)
    call check_int(cfg, 'particles', 'seed', cfg%particles%seed, 0, huge(1))
    call check_int(cfg, 'particles', 'packing_sweeps', cfg%particles%packing_sweeps, 0, 1000000)
    if (cfg%particles%packing_min_gap /= -1.0_dp) &
      call check_real(cfg, 'particles', 'packing_min_gap', cfg%particles%packing_min_gap, 0.0_dp, 1.0_dp)
    if (cfg%particles%solid_fraction > 0.0_dp) then
      if (cfg%particles%number > 0 .or. len_trim(cfg%particles%position_file) > 0) &
        call input_error(cfg%deck_file, 'particles', 'solid_fraction', &
             'give the particles one way: solid_fraction (a packing made now), number/position, or position_file')
      if (cfg%particles%motion == 'prescribed' .or. cfg%particles%motion == 'resistance') &
        call input_error(cfg%deck_file, 'particles', 'motion', &
           'prescribed velocities are given inline: use number and position, not solid_fraction')
    end if
    if (.not. cfg%resolved .and. cfg%particles%number == 0 .and. len_trim(cfg%particles%position_file) == 0 .and. &
        cfg%particles%solid_fraction == 0.0_dp) &
      call input_error(cfg%deck_file, 'fluid', 'model', '''none'' (lubrication dynamics) moves spheres and nothing '// &
           'else: give &particles (number/position, position_file or solid_fraction)')
    if (cfg%resolved .and. cfg%radius + cfg%particles%radius_offset * cfg%h < 1.5_dp * cfg%h) &
      call input_error(cfg%deck_file, 'particles', 'radius', &
           'the (smallest) sphere must span at least 1.5 grid cells in radius (raise &domain cells_per_radius)')
  end subroutine validate_particles

  ! The sizes of the spheres (doc/INPUT.md "Mixtures"): &particles radius lists one radius per
  ! species, smallest first; a mixture (two or more) is 1 for the smallest, the unit of length,
  ! and gives the share of each species by volume or by number (volume_share or number_share,
  ! positive, summing to 1). Sets the derived species, radius (smallest) and radius_max.
  subroutine validate_species(cfg)
    type(config_t), intent(inout) :: cfg
    character(len=200) :: text
    real(dp), parameter :: share_tolerance = 1.0e-9_dp   ! decimal shares sum to 1 within round-off
    integer :: k, given
    associate(particles => cfg%particles)
      cfg%species = count(particles%radius > 0.0_dp)
      if (cfg%species == 0) call input_error(cfg%deck_file, 'particles', 'radius', 'needs one positive radius per species')
      if (any(particles%radius(cfg%species + 1:) /= 0.0_dp)) call input_error(cfg%deck_file, 'particles', 'radius', &
           'lists its radii one after the other, without zeros or negative values between them')
      do k = 1, cfg%species
        write(text, '(a,i0,a)') 'radius(', k, ')'
        call check_real(cfg, 'particles', trim(text), particles%radius(k), 0.0_dp, 100.0_dp, .true.)
      end do
      do k = 2, cfg%species
        write(text, '(a,i0,a)') 'radius(', k, ')'
        if (particles%radius(k) <= particles%radius(k - 1)) call input_error(cfg%deck_file, 'particles', &
             trim(text), 'the radii of a mixture are listed smallest first, each larger than the one before')
      end do
      cfg%radius = particles%radius(1)
      cfg%radius_max = particles%radius(cfg%species)
      given = count([any(particles%volume_share /= 0.0_dp), any(particles%number_share /= 0.0_dp)])
      if (cfg%species == 1) then
        if (given > 0 .and. .not. (all(particles%volume_share(2:) == 0.0_dp) .and. &
                                   all(particles%number_share(2:) == 0.0_dp))) &
          call input_error(cfg%deck_file, 'particles', trim(merge('volume_share', 'number_share', &
               any(particles%volume_share /= 0.0_dp))), 'gives shares of several species, radius lists one')
        return
      end if
      if (particles%radius(1) /= 1.0_dp) call input_error(cfg%deck_file, 'particles', 'radius(1)', &
           'the smallest sphere of a mixture is the unit of length: radius(1) = 1, the others in its units')
      ! the shares make a packing's counts; spheres given inline or in a file have their own
      if (given > 1 .or. (given == 0 .and. particles%solid_fraction > 0.0_dp)) &
        call input_error(cfg%deck_file, 'particles', 'volume_share', &
             'a mixture gives the share of each species by volume (volume_share) or by number (number_share), one of them')
      if (any(particles%volume_share /= 0.0_dp)) then
        call check_shares('volume_share', particles%volume_share)
      else if (any(particles%number_share /= 0.0_dp)) then
        call check_shares('number_share', particles%number_share)
      end if
    end associate

  contains

    subroutine check_shares(name, share)
      character(len=*), intent(in) :: name
      real(dp), intent(in) :: share(:)
      if (count(share /= 0.0_dp) /= cfg%species .or. any(share(1:cfg%species) <= 0.0_dp)) then
        write(text, '(a,i0,a)') 'gives one positive share per species (', cfg%species, ' radii)'
        call input_error(cfg%deck_file, 'particles', name, trim(text))
      end if
      if (abs(sum(share(1:cfg%species)) - 1.0_dp) > share_tolerance) then
        write(text, '(a,es12.5,a)') 'sums to ', sum(share(1:cfg%species)), ', not 1'
        call input_error(cfg%deck_file, 'particles', name, trim(text))
      end if
    end subroutine check_shares
  end subroutine validate_species

  ! The species of inline particles (doc/INPUT.md "Mixtures"): each species(i) names one of the
  ! deck's radii, and a mixture's inline particles hold every species it lists (as a position
  ! file must); equal spheres leave species alone.
  subroutine validate_inline_species(cfg)
    type(config_t), intent(in) :: cfg
    character(len=200) :: text
    integer :: i, k
    associate(particles => cfg%particles)
      do i = 1, max_inline_particles
        write(text, '(a,i0,a)') 'species(', i, ')'
        if (i > particles%number) then
          if (particles%species(i) /= 1) call input_error(cfg%deck_file, 'particles', trim(text), &
               'is given for a particle beyond number')
        else
          call check_int(cfg, 'particles', trim(text), particles%species(i), 1, cfg%species)
        end if
      end do
      if (particles%number == 0 .or. cfg%species == 1) return
      do k = 1, cfg%species
        if (all(particles%species(1:particles%number) /= k)) then
          write(text, '(a,i0,a,i0,a)') 'gives no inline particle of species ', k, &
               ' (radius(', k, ')): a mixture''s inline particles hold every species &particles radius lists'
          call input_error(cfg%deck_file, 'particles', 'species', trim(text))
        end if
      end do
    end associate
  end subroutine validate_inline_species

  ! The imposed rate (doc/INPUT.md "&shear"): &shear rate, or its older name &domain shear_rate,
  ! not both; 1 when neither is given; an oscillation's is its reference rate gamma_0 2 pi/T
  ! (validate_shear checks amplitude and period). After this cfg%domain%shear_rate and
  ! cfg%shear%rate hold the reference rate, which every limit and the unit of stress use.
  subroutine resolve_shear_rate(cfg)
    type(config_t), intent(inout) :: cfg
    logical :: old_name, new_name
    cfg%shear%control = to_lower(cfg%shear%control)
    cfg%shear%protocol = to_lower(cfg%shear%protocol)
    old_name = cfg%domain%shear_rate /= rate_not_given
    new_name = cfg%shear%rate /= rate_not_given
    if (old_name .and. new_name) call input_error(cfg%deck_file, 'shear', 'rate', &
         'is also given as &domain shear_rate (its older name): give the rate once, as &shear rate')
    if (old_name) then
      cfg%rate_group = 'domain'
      cfg%rate_name = 'shear_rate'
      cfg%shear%rate = cfg%domain%shear_rate
    end if
    if (cfg%shear%protocol == 'oscillatory' .and. cfg%shear%control /= 'stress') then
      if (new_name .or. old_name) call input_error(cfg%deck_file, trim(cfg%rate_group), trim(cfg%rate_name), &
           'is not given with protocol = ''oscillatory'': its rate follows from strain_amplitude and period '// &
           '(reference rate strain_amplitude*2*pi/period)')
      cfg%rate_group = 'shear'
      cfg%rate_name = 'strain_amplitude'
      call check_real(cfg, 'shear', 'strain_amplitude', cfg%shear%strain_amplitude, 0.0_dp, 1.0e3_dp, .true.)
      call check_real(cfg, 'shear', 'period', cfg%shear%period, 0.0_dp, 1.0e9_dp, .true.)
      cfg%shear%rate = shear_protocol_reference_rate(PROTOCOL_OSCILLATORY, 0.0_dp, cfg%shear%strain_amplitude, &
                                                     cfg%shear%period)
    else if (.not. (new_name .or. old_name)) then
      cfg%shear%rate = 1.0_dp
    end if
    call check_real(cfg, trim(cfg%rate_group), trim(cfg%rate_name), cfg%shear%rate, -1.0e3_dp, 1.0e3_dp)
    cfg%domain%shear_rate = cfg%shear%rate
  end subroutine resolve_shear_rate

  ! The protocol of &shear (doc/INPUT.md "&shear"): its name, the control, and the variables of
  ! each protocol given with it only.
  subroutine validate_shear(cfg)
    type(config_t), intent(inout) :: cfg
    character(len=200) :: text
    if (cfg%shear%control /= 'rate' .and. cfg%shear%control /= 'stress') call input_error(cfg%deck_file, 'shear', &
         'control', 'must be ''rate'' or ''stress'', not '''//trim(cfg%shear%control)//'''')
    if (cfg%shear%control == 'rate' .and. cfg%shear%stress /= 0.0_dp) call input_error(cfg%deck_file, 'shear', &
         'stress', 'is given only with control = ''stress'' (under control = ''rate'' the rate is imposed)')
    cfg%shear%step_by = to_lower(cfg%shear%step_by)
    if (cfg%shear%control == 'stress') call validate_stress_control(cfg)
    if (shear_protocol_kind(cfg%shear%protocol) == 0) call input_error(cfg%deck_file, 'shear', 'protocol', &
         'must be ''steady'', ''reversal'', ''oscillatory'' or ''steps'', not '''//trim(cfg%shear%protocol)//'''')
    call validate_steps(cfg)
    if (cfg%shear%protocol /= 'oscillatory') then
      if (cfg%shear%strain_amplitude /= 0.0_dp) call input_error(cfg%deck_file, 'shear', 'strain_amplitude', &
           'is given only with protocol = ''oscillatory''')
      if (cfg%shear%period /= 0.0_dp) call input_error(cfg%deck_file, 'shear', 'period', &
           'is given only with protocol = ''oscillatory''')
    end if
    if (cfg%shear%protocol /= 'reversal' .and. cfg%shear%reversal_strain /= 0.0_dp) &
      call input_error(cfg%deck_file, 'shear', 'reversal_strain', 'is given only with protocol = ''reversal''')
    if (cfg%shear%protocol == 'steady') return
    if (cfg%shear%rate == 0.0_dp) call input_error(cfg%deck_file, trim(cfg%rate_group), trim(cfg%rate_name), &
         'protocol = '''//trim(cfg%shear%protocol)//''' needs a non-zero rate')
    ! what presumes a steady imposed flow
    if (cfg%time%steady_tolerance > 0.0_dp) call input_error(cfg%deck_file, 'time', 'steady_tolerance', &
         'stops the run on a steady flow, which &shear protocol = '''//trim(cfg%shear%protocol)//''' never reaches: set 0')
    if (cfg%verification%manufactured_solution) call input_error(cfg%deck_file, 'verification', &
         'manufactured_solution', 'is a steady solution under a steady rate: needs &shear protocol = ''steady''')
    if (cfg%shear%protocol == 'reversal') then
      call check_real(cfg, 'shear', 'reversal_strain', cfg%shear%reversal_strain, 0.0_dp, 1.0e9_dp, .true.)
      if (cfg%shear%reversal_strain < abs(cfg%shear%rate) * cfg%time%dt) then
        write(text, '(a,es10.3,a)') 'is shorter than the strain of one step (|rate| dt = ', &
             abs(cfg%shear%rate) * cfg%time%dt, '): the rate would reverse every step'
        call input_error(cfg%deck_file, 'shear', 'reversal_strain', trim(text))
      end if
    else if (cfg%shear%protocol == 'oscillatory') then
      if (cfg%shear%period < 4.0_dp * cfg%time%dt) then
        write(text, '(a,es10.3,a)') 'is shorter than 4 steps (dt = ', cfg%time%dt, '): the step cannot follow the oscillation'
        call input_error(cfg%deck_file, 'shear', 'period', trim(text))
      end if
    end if
  end subroutine validate_shear

  ! Steps (doc/INPUT.md "&shear", protocol 'steps'): its variables with it only; 2..MAX_LEVELS
  ! levels, the first from 0, each later one after the one before, at least a step long; levels
  ! within the range of a rate (or of a stress), non-zero when counted in strain (a level at rest
  ! would never reach the next); &shear rate, the unit, positive.
  subroutine validate_steps(cfg)
    type(config_t), intent(inout) :: cfg
    character(len=200) :: text
    character(len=16) :: name
    real(dp) :: bound, per_step
    integer :: k
    associate(sh => cfg%shear)
      if (sh%protocol /= 'steps') then
        if (sh%levels /= 0) call input_error(cfg%deck_file, 'shear', 'levels', 'is given only with protocol = ''steps''')
        if (any(sh%step_at /= 0.0_dp)) call input_error(cfg%deck_file, 'shear', 'step_at', &
             'is given only with protocol = ''steps''')
        if (any(sh%step_level /= 0.0_dp)) call input_error(cfg%deck_file, 'shear', 'step_level', &
             'is given only with protocol = ''steps''')
        if (sh%step_by /= 'strain') call input_error(cfg%deck_file, 'shear', 'step_by', &
             'is given only with protocol = ''steps''')
        return
      end if
      write(text, '(a,i0,a)') 'must be 2 .. ', MAX_LEVELS, ' (the number of step_at and step_level given)'
      if (sh%levels < 2 .or. sh%levels > MAX_LEVELS) call input_error(cfg%deck_file, 'shear', 'levels', trim(text))
      if (sh%step_by /= 'strain' .and. sh%step_by /= 'time') call input_error(cfg%deck_file, 'shear', 'step_by', &
           'must be ''strain'' or ''time'', not '''//trim(sh%step_by)//'''')
      if (any(sh%step_at(sh%levels + 1:) /= 0.0_dp)) call input_error(cfg%deck_file, 'shear', 'step_at', &
           'has more values than levels')
      if (any(sh%step_level(sh%levels + 1:) /= 0.0_dp)) call input_error(cfg%deck_file, 'shear', 'step_level', &
           'has more values than levels')
      if (sh%step_at(1) /= 0.0_dp) call input_error(cfg%deck_file, 'shear', 'step_at(1)', &
           'must be 0: the first level starts the run')
      if (sh%rate <= 0.0_dp) call input_error(cfg%deck_file, trim(cfg%rate_group), trim(cfg%rate_name), &
           'is the unit of time and stress with protocol = ''steps'' (the levels give the rates): must be > 0')
      bound = merge(1.0e6_dp, 1.0e3_dp, sh%control == 'stress')
      do k = 1, sh%levels
        write(name, '(a,i0,a)') 'step_level(', k, ')'
        call check_real(cfg, 'shear', trim(name), sh%step_level(k), -bound, bound)
        if (sh%step_by == 'strain' .and. sh%step_level(k) == 0.0_dp) call input_error(cfg%deck_file, 'shear', &
             trim(name), 'is 0, and a level at rest never reaches the next strain: step_by = ''time'' allows it')
      end do
      do k = 2, sh%levels
        write(name, '(a,i0,a)') 'step_at(', k, ')'
        per_step = cfg%time%dt
        if (sh%step_by == 'strain' .and. sh%control == 'rate') per_step = abs(sh%step_level(k - 1)) * cfg%time%dt
        if (sh%step_at(k) - sh%step_at(k - 1) < per_step) then
          write(text, '(a,es10.3,a)') 'must follow step_at(k-1) by at least one step (', per_step, ')'
          call input_error(cfg%deck_file, 'shear', trim(name), trim(text))
        end if
      end do
    end associate
  end subroutine validate_steps

  ! Stress control (doc/INPUT.md "&shear", doc/METHOD.md §7.4): a non-zero stress (an
  ! oscillation's amplitude, with a period), a stress to measure (spheres or walls; in lubrication
  ! dynamics with the statistics' weights, &rheology; in the DNS the mean wall stress, or the
  ! Lees-Edwards box's mean stress, with backward Euler), spheres that move freely; &shear rate
  ! stays the unit (positive).
  subroutine validate_stress_control(cfg)
    type(config_t), intent(inout) :: cfg
    logical :: spheres
    spheres = cfg%particles%number > 0 .or. len_trim(cfg%particles%position_file) > 0 .or. &
              cfg%particles%solid_fraction > 0.0_dp
    if (cfg%shear%protocol == 'steps') then
      if (cfg%shear%stress /= 0.0_dp) call input_error(cfg%deck_file, 'shear', 'stress', &
           'is not given with protocol = ''steps'': the stresses are its step_level')
    else
      if (cfg%shear%stress == 0.0_dp) call input_error(cfg%deck_file, 'shear', 'stress', &
           'must be given (non-zero, in eta*gamma_dot_ref) with control = ''stress''')
      call check_real(cfg, 'shear', 'stress', cfg%shear%stress, -1.0e6_dp, 1.0e6_dp)
    end if
    if (cfg%shear%protocol == 'oscillatory' .and. cfg%shear%strain_amplitude /= 0.0_dp) call input_error( &
         cfg%deck_file, 'shear', 'strain_amplitude', 'is not given with control = ''stress'': an oscillation '// &
         'of the stress has the amplitude &shear stress (stress(t) = stress sin(2 pi t/period))')
    if (cfg%shear%protocol == 'oscillatory') &
      call check_real(cfg, 'shear', 'period', cfg%shear%period, 0.0_dp, 1.0e9_dp, .true.)
    if (cfg%resolved .and. cfg%fluid%viscous_theta /= 1.0_dp) call input_error(cfg%deck_file, 'fluid', &
         'viscous_theta', 'must be 1 (backward Euler) with &shear control = ''stress'': the wall speed jumps each '// &
         'step, and the Crank-Nicolson response of the wall cells to a jump overshoots (a wall stress that falls as '// &
         'the wall speeds up), which the stress balance amplifies (doc/METHOD.md §7.4)')
    if (.not. (cfg%walls .or. cfg%lees_edwards)) call input_error(cfg%deck_file, 'shear', 'control', &
         '''stress'' needs a sheared box (y_boundary = ''walls'' or ''lees-edwards''): a periodic box in y has '// &
         'no shear stress to control')
    if (.not. spheres .and. .not. cfg%walls) call input_error(cfg%deck_file, 'shear', 'control', &
         '''stress'': no stress can be measured without particles and without walls')
    if (cfg%shear%rate <= 0.0_dp) call input_error(cfg%deck_file, trim(cfg%rate_group), trim(cfg%rate_name), &
         'is the unit of time and stress under control = ''stress'' (gamma_dot_ref): must be > 0')
    ! (the DNS controls the mean wall stress, which needs no statistics)
    if (spheres .and. .not. cfg%resolved .and. .not. cfg%rheology_group) call input_error(cfg%deck_file, 'shear', &
         'control', '''stress'' with particles in lubrication dynamics needs &rheology: the mean shear stress is the '// &
         'one the statistics measure (doc/RHEOLOGY.md), and so are their weights')
    if (spheres .and. cfg%particles%motion /= 'free' .and. cfg%particles%motion /= 'frozen') &
      call input_error(cfg%deck_file, 'particles', 'motion', 'must be ''free'' or ''frozen'' with &shear '// &
           'control = ''stress'' (imposed particle motion leaves no balance for the rate)')
  end subroutine validate_stress_control

  ! Ranges of &rheology, and the step counts of the averaging window (doc/RHEOLOGY.md).
  subroutine validate_rheology(cfg)
    type(config_t), intent(inout) :: cfg
    character(len=200) :: text
    real(dp) :: strain_per_step
    integer :: needed
    if (.not. cfg%rheology_group) return
    if (.not. (cfg%walls .or. cfg%lees_edwards) .or. cfg%domain%shear_rate == 0.0_dp) &
      call input_error(cfg%deck_file, 'rheology', '', &
           'statistics are taken in the core of the sheared Couette cell (or the whole Lees-Edwards box): '// &
           'needs y_boundary = ''walls'' or ''lees-edwards'' and a non-zero &shear rate')
    if (cfg%particles%number == 0 .and. len_trim(cfg%particles%position_file) == 0 .and. cfg%particles%solid_fraction == 0.0_dp) &
      call input_error(cfg%deck_file, 'rheology', '', 'needs particles (&particles solid_fraction, number or position_file)')
    call check_real(cfg, 'rheology', 'discard_strain', cfg%rheology%discard_strain, 0.0_dp, 1.0e6_dp)
    call check_real(cfg, 'rheology', 'average_strain', cfg%rheology%average_strain, 0.0_dp, 1.0e6_dp, .true.)
    call check_int(cfg, 'rheology', 'blocks', cfg%rheology%blocks, 1, 1000)
    call check_real(cfg, 'rheology', 'core(1)', cfg%rheology%core(1), 0.0_dp, 1.0_dp)
    call check_real(cfg, 'rheology', 'core(2)', cfg%rheology%core(2), 0.0_dp, 1.0_dp)
    if (cfg%rheology%core(2) <= cfg%rheology%core(1)) call input_error(cfg%deck_file, 'rheology', 'core', 'must be y_lo/Ly < y_hi/Ly')
    call check_int(cfg, 'rheology', 'profile_bins', cfg%rheology%profile_bins, 0, 100000)
    if (cfg%rheology%profile_bins == 0) cfg%rheology%profile_bins = max(1, nint(4 * cfg%domain%box(2) / cfg%radius))
    call check_int(cfg, 'rheology', 'angle_bins', cfg%rheology%angle_bins, 4, 3600)
    call check_real(cfg, 'rheology', 'pair_shell', cfg%rheology%pair_shell, 2.0_dp, 3.0_dp, .true.)
    call check_real(cfg, 'rheology', 'contact_shell', cfg%rheology%contact_shell, 0.0_dp, 0.5_dp)
    if (cfg%rheology%contact_shell == 0.0_dp) then
      cfg%rheology%contact_shell = 0.005_dp
      if (cfg%contact_group .and. cfg%contact%roughness > 0.0_dp) cfg%rheology%contact_shell = cfg%contact%roughness
    end if
    strain_per_step = abs(cfg%domain%shear_rate) * cfg%time%dt
    cfg%discard_step = nint(cfg%rheology%discard_strain / strain_per_step)
    cfg%block_steps = nint(cfg%rheology%average_strain / (cfg%rheology%blocks * strain_per_step))
    if (cfg%block_steps < cfg%output%series_every) then
      write(text, '(a,i0,a,i0,a)') 'a block of average_strain/blocks is ', cfg%block_steps, &
           ' steps, fewer than &output series_every = ', cfg%output%series_every, ': every block needs records'
      call input_error(cfg%deck_file, 'rheology', 'average_strain', trim(text))
    end if
    needed = cfg%discard_step + cfg%rheology%blocks * cfg%block_steps
    if (cfg%time%steps == -1) cfg%time%steps = needed
  end subroutine validate_rheology

  ! Ranges of &lubrication; whether a table exists for this resolution is checked where it is read
  ! (mod_lubrication_io), still before any work.
  subroutine validate_lubrication(cfg)
    type(config_t), intent(in) :: cfg
    if (all(cfg%lubrication%model /= [character(len=16) :: 'none', 'simple', 'full'])) &
      call input_error(cfg%deck_file, 'lubrication', 'model', &
           'must be ''none'', ''simple'' or ''full'', not '''//trim(cfg%lubrication%model)//'''')
    if (cfg%resolved) then
      call check_real(cfg, 'lubrication', 'outer_cutoff', cfg%lubrication%outer_cutoff, 0.0_dp, 2.0_dp)
    else
      ! lubrication dynamics: the exact functions hold at every gap (the pair test covers 10a)
      call check_real(cfg, 'lubrication', 'outer_cutoff', cfg%lubrication%outer_cutoff, 0.0_dp, 20.0_dp)
      if (cfg%lubrication%model == 'simple') &
        call input_error(cfg%deck_file, 'lubrication', 'model', &
             '''simple'' corrects a resolved fluid: with &fluid model = ''none'' use ''full'' (the exact '// &
             'two-body functions, the default) or ''none'' (one-body drag only)')
    end if
    call check_real(cfg, 'lubrication', 'inner_cutoff', cfg%lubrication%inner_cutoff, 1.0e-8_dp, 0.1_dp)
    call check_real(cfg, 'lubrication', 'skin', cfg%lubrication%skin, 0.0_dp, 2.0_dp, .true.)
    if (cfg%lubrication%outer_cutoff > 0.0_dp .and. cfg%lubrication%outer_cutoff <= cfg%lubrication%inner_cutoff) &
      call input_error(cfg%deck_file, 'lubrication', 'outer_cutoff', 'must exceed inner_cutoff')
  end subroutine validate_lubrication

  ! Ranges of &contact, and what the contact law and the neighbour search need (doc/CONTACT.md).
  ! Checked whenever the group is present, even in a deck without particles.
  subroutine validate_contact(cfg)
    type(config_t), intent(inout) :: cfg
    character(len=*), parameter :: xyz = 'xyz'
    character(len=200) :: text
    real(dp) :: cutoff
    integer :: d
    if (.not. cfg%contact_group) return
    call check_real(cfg, 'contact', 'roughness', cfg%contact%roughness, 0.0_dp, 0.5_dp)
    call check_real(cfg, 'contact', 'eps_bar', cfg%contact%eps_bar, 0.0_dp, 1.0_dp, .true.)
    call check_real(cfg, 'contact', 'friction', cfg%contact%friction, 0.0_dp, 10.0_dp)
    call check_real(cfg, 'contact', 'normal_stiffness', cfg%contact%normal_stiffness, 0.0_dp, 1.0e15_dp)
    call check_real(cfg, 'contact', 'neighbour_skin', cfg%contact%neighbour_skin, 0.0_dp, 2.0_dp, .true.)
    if (cfg%contact%normal_stiffness <= 0.0_dp) then
      if (cfg%contact%roughness <= 0.0_dp) &
        call input_error(cfg%deck_file, 'contact', 'normal_stiffness', &
             'smooth spheres (roughness = 0) need a prescribed normal_stiffness > 0')
      if (cfg%domain%shear_rate == 0.0_dp) &
        call input_error(cfg%deck_file, 'contact', 'normal_stiffness', &
             'k_n from eps_bar needs a non-zero &shear rate (or &domain shear_rate): prescribe normal_stiffness > 0')
    end if
    ! the neighbour search needs every periodic length >= 2 x cutoff (one image in range)
    cutoff = 2.0_dp * cfg%radius_max + cfg%contact%roughness * cfg%radius + cfg%contact%neighbour_skin
    do d = 1, 3
      if (d == 2 .and. cfg%walls) cycle
      if (cfg%domain%box(d) < 2.0_dp * cutoff) then
        write(text, '(a,f0.4,a)') 'with contacts every periodic length must be >= 2 (2a + h_r + neighbour_skin) = ', &
             2.0_dp * cutoff, ' (lower &contact neighbour_skin or enlarge the box)'
        call input_error(cfg%deck_file, 'domain', 'box('//xyz(d:d)//')', trim(text))
      end if
    end do
  end subroutine validate_contact

end module mod_params
