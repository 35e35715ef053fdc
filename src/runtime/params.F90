! The input deck: Fortran namelist groups, their defaults, units, valid ranges and the echo of the
! effective deck. Every variable is documented in doc/INPUT.md; keep the two in step.
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
  use mod_deck_text, only: deck_line_length, load_lines, group_on_line, to_lower, diagnose_group
  use mod_packing_geometry, only: phi_max
  implicit none
  private
  public :: config_t, read_deck, echo_deck, max_line, max_inline_particles

  integer, parameter :: max_line = deck_line_length
  integer, parameter :: max_inline_particles = 64
  integer, parameter :: ngroups = 10
  character(len=16), parameter :: known_groups(ngroups) = [character(len=16) :: &
       'domain', 'fluid', 'time', 'output', 'run', 'verification', 'particles', 'contact', 'lubrication', &
       'rheology']

  type :: config_t
    character(len=max_line) :: deck_file = ''
    ! &domain
    real(dp) :: box(3) = [20.0_dp, 20.0_dp, 20.0_dp]   ! box lengths Lx, Ly, Lz [a]
    real(dp) :: cells_per_radius = 5.0_dp               ! a/Delta [-]
    character(len=16) :: y_boundary = 'walls'           ! 'walls' (Couette) or 'periodic'
    real(dp) :: shear_rate = 1.0_dp                     ! walls move at +-shear_rate*Ly/2 [gamma_dot]
    ! &fluid
    real(dp) :: reynolds = 0.01_dp                      ! rho*gamma_dot*a^2/eta [-]
    real(dp) :: body_force(3) = 0.0_dp                  ! uniform force density [eta*gamma_dot/a]
    ! 1e-6: eta_r within 1e-7 of the tight 1e-8/1e-10 at 22 % less CPU (doc/BENCHMARKS.md §9)
    real(dp) :: velocity_tolerance = 1.0e-6_dp          ! KSP rtol of the Helmholtz solves [-]
    real(dp) :: pressure_tolerance = 1.0e-6_dp          ! KSP rtol of the pressure Poisson solve [-]
    real(dp) :: viscous_theta = 0.5_dp                  ! 0.5 Crank-Nicolson, 1 backward Euler [-]
    character(len=16) :: initial_flow = 'rest'          ! 'rest' or 'shear' (the linear Couette profile)
    character(len=16) :: fluid_model = 'resolved'       ! 'resolved' (the DNS) or 'none' (lubrication dynamics)
    ! &time
    real(dp) :: dt = 1.0e-3_dp                          ! time step [1/gamma_dot]
    integer :: steps = -1                               ! last step [-] (-1: 1000, or what &rheology needs)
    real(dp) :: steady_tolerance = 0.0_dp               ! stop when max|du|/dt < tol*U_ref (0: off)
    ! &output
    character(len=max_line) :: output_directory = 'out'
    integer :: progress_every = 100                     ! steps between progress lines
    integer :: series_every = 1                         ! steps between series.h5 records
    integer :: fields_every = 0                         ! steps between field snapshots (0: end only)
    integer :: checkpoint_every = 0                     ! steps between checkpoints (0: end only)
    integer :: particles_every = 0                      ! steps between particle snapshots (0: end only)
    ! &run
    character(len=256) :: title = ''
    real(dp) :: max_wall_hours = 0.0_dp                 ! checkpoint and stop after this (0: never)
    ! &verification
    logical :: manufactured_solution = .false.          ! force with the manufactured solution
    ! &particles (inline arrays hold up to max_inline_particles; larger sets come from a file)
    integer :: particle_number = 0                      ! particles given inline
    real(dp) :: particle_position(3, max_inline_particles) = 0.0_dp     ! centres [a]
    character(len=max_line) :: position_file = ''       ! HDF5 file with particles/position
    real(dp) :: radius = 1.0_dp                         ! sphere radius [a]
    character(len=16) :: motion = 'free'                ! 'free', 'prescribed', 'resistance' or 'frozen'
    real(dp) :: particle_velocity(3, max_inline_particles) = 0.0_dp    ! prescribed U [a*gamma_dot]
    real(dp) :: particle_omega(3, max_inline_particles) = 0.0_dp       ! prescribed Omega [gamma_dot]
    real(dp) :: external_force(3, max_inline_particles) = 0.0_dp       ! [eta*gamma_dot*a^2]
    real(dp) :: external_torque(3, max_inline_particles) = 0.0_dp      ! [eta*gamma_dot*a^3]
    real(dp) :: radius_offset = 0.38_dp                 ! alpha radius = radius + offset*h [h]
    real(dp) :: slip_kappa = 0.5_dp                     ! relaxation on partly covered faces [-]
    real(dp) :: solid_fraction = 0.0_dp                 ! > 0: pack this volume fraction at start [-]
    integer :: seed = 1                                 ! random seed of that packing [-]
    integer :: packing_sweeps = 200                     ! its hard-sphere Monte Carlo sweeps [-]
    real(dp) :: packing_min_gap = -1.0_dp               ! its smallest surface gap [a] (-1: h_r with contacts, else 0)
    ! &contact (doc/CONTACT.md; active when the group is present and the run has particles)
    logical :: contact_group = .false.                  ! the deck has a &contact group (derived)
    real(dp) :: roughness = 0.0_dp                      ! eps_r = h_r/a [-]
    real(dp) :: eps_bar = 0.05_dp                       ! roughness deformation under 6 pi eta gamma_dot a^2 [-]
    real(dp) :: friction = 0.0_dp                       ! mu_d [-]
    real(dp) :: normal_stiffness = 0.0_dp               ! k_n [eta gamma_dot a^(1/2)] (0: from eps_bar)
    real(dp) :: neighbour_skin = 0.2_dp                 ! neighbour-list skin [a]
    logical :: contact_implicit = .true.                ! linearised contact stiffness in the particle solve
    ! &lubrication (doc/LUBRICATION.md)
    character(len=16) :: lubrication_model = 'full'     ! 'none', 'simple' or 'full'
    character(len=max_line) :: lubrication_table = ''   ! '' = the shipped table for this a/Delta
    real(dp) :: outer_cutoff = 0.0_dp                   ! gap where the correction ends [a] (0: model default)
    real(dp) :: inner_cutoff = 1.0e-4_dp                ! smallest gap the correction is evaluated at [a]
    real(dp) :: lubrication_skin = 0.2_dp               ! neighbour-list skin of lubricating pairs [a]
    ! &rheology (doc/RHEOLOGY.md; statistics on when the group is present)
    logical :: rheology_group = .false.                 ! the deck has a &rheology group (derived)
    real(dp) :: discard_strain = 5.0_dp                 ! strain discarded before averaging [-]
    real(dp) :: average_strain = 20.0_dp                ! strain averaged over [-]
    integer :: blocks = 5                               ! averaging blocks [-]
    real(dp) :: core(2) = [0.25_dp, 0.75_dp]            ! core region y/Ly [-] (paper eq. (4.10))
    integer :: profile_bins = 0                         ! bins across y (0: 4 per radius)
    integer :: angle_bins = 36                          ! bins of g(theta) over [0, 2 pi)
    real(dp) :: pair_shell = 2.1_dp                     ! g(theta) counts pairs at r < pair_shell [a]
    real(dp) :: contact_shell = 0.0_dp                  ! g_c(theta): r < 2a + contact_shell [a] (0: h_r or 0.005)
    integer :: discard_step = 0, block_steps = 1        ! derived
    ! derived, not read
    integer :: cells(3) = 0
    logical :: walls = .true.
    logical :: lees_edwards = .false.                   ! y_boundary = 'lees-edwards'
    logical :: resolved = .true.                        ! fluid_model = 'resolved'
    real(dp) :: h = 0.0_dp                              ! grid spacing Delta [a]
    real(dp) :: wall_speed = 0.0_dp                     ! top wall +U, bottom wall -U [a*gamma_dot]
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
             '); known groups: &domain &fluid &time &output &run &verification &particles &contact &lubrication '// &
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

  ! One place per group declares its namelist: used to read it (src present) and to echo it.
  subroutine group_io(group, cfg, src, ios, msg, echo_unit)
    character(len=*), intent(in) :: group
    type(config_t), intent(inout) :: cfg
    character(len=*), intent(in), optional :: src(:)
    integer, intent(out), optional :: ios
    character(len=*), intent(inout), optional :: msg
    integer, intent(in), optional :: echo_unit
    ! &domain
    real(dp) :: box(3), cells_per_radius, shear_rate
    character(len=16) :: y_boundary
    ! &time
    real(dp) :: dt, steady_tolerance
    integer :: steps
    ! &output
    character(len=max_line) :: directory
    integer :: progress_every, series_every, fields_every, checkpoint_every, particles_every
    ! &run
    character(len=256) :: title
    real(dp) :: max_wall_hours
    ! &verification
    logical :: manufactured_solution
    ! &particles
    integer :: number
    real(dp) :: position(3, max_inline_particles), radius, radius_offset, slip_kappa
    real(dp) :: velocity(3, max_inline_particles), omega(3, max_inline_particles)
    real(dp) :: external_force(3, max_inline_particles), external_torque(3, max_inline_particles)
    character(len=max_line) :: position_file
    character(len=16) :: motion
    real(dp) :: solid_fraction, packing_min_gap
    integer :: seed, packing_sweeps
    ! &rheology
    real(dp) :: discard_strain, average_strain, core(2), pair_shell, contact_shell
    integer :: blocks, profile_bins, angle_bins
    namelist /rheology/ discard_strain, average_strain, blocks, core, profile_bins, angle_bins, pair_shell, contact_shell
    ! &contact
    real(dp) :: roughness, eps_bar, friction, normal_stiffness, neighbour_skin
    logical :: implicit
    namelist /particles/ number, position, position_file, radius, motion, velocity, omega, &
         external_force, external_torque, radius_offset, slip_kappa, solid_fraction, seed, packing_sweeps, &
         packing_min_gap
    namelist /contact/ roughness, eps_bar, friction, normal_stiffness, neighbour_skin, implicit
    ! &lubrication
    character(len=16) :: model
    character(len=max_line) :: table
    real(dp) :: outer_cutoff, inner_cutoff, skin
    namelist /lubrication/ model, table, outer_cutoff, inner_cutoff, skin
    namelist /domain/ box, cells_per_radius, y_boundary, shear_rate
    namelist /time/ dt, steps, steady_tolerance
    namelist /output/ directory, progress_every, series_every, fields_every, checkpoint_every, particles_every
    namelist /run/ title, max_wall_hours
    namelist /verification/ manufactured_solution
    integer :: stat

    box = cfg%box; cells_per_radius = cfg%cells_per_radius
    y_boundary = cfg%y_boundary; shear_rate = cfg%shear_rate
    dt = cfg%dt; steps = cfg%steps; steady_tolerance = cfg%steady_tolerance
    directory = cfg%output_directory; progress_every = cfg%progress_every
    series_every = cfg%series_every; fields_every = cfg%fields_every
    checkpoint_every = cfg%checkpoint_every; particles_every = cfg%particles_every
    title = cfg%title; max_wall_hours = cfg%max_wall_hours
    manufactured_solution = cfg%manufactured_solution
    number = cfg%particle_number; position = cfg%particle_position; position_file = cfg%position_file
    radius = cfg%radius; motion = cfg%motion; velocity = cfg%particle_velocity
    omega = cfg%particle_omega; external_force = cfg%external_force
    external_torque = cfg%external_torque; radius_offset = cfg%radius_offset
    slip_kappa = cfg%slip_kappa
    solid_fraction = cfg%solid_fraction; seed = cfg%seed; packing_sweeps = cfg%packing_sweeps
    packing_min_gap = cfg%packing_min_gap
    discard_strain = cfg%discard_strain; average_strain = cfg%average_strain; blocks = cfg%blocks
    core = cfg%core; profile_bins = cfg%profile_bins; angle_bins = cfg%angle_bins
    pair_shell = cfg%pair_shell; contact_shell = cfg%contact_shell
    roughness = cfg%roughness; eps_bar = cfg%eps_bar; friction = cfg%friction
    normal_stiffness = cfg%normal_stiffness; neighbour_skin = cfg%neighbour_skin
    implicit = cfg%contact_implicit
    model = cfg%lubrication_model; table = cfg%lubrication_table; outer_cutoff = cfg%outer_cutoff
    inner_cutoff = cfg%inner_cutoff; skin = cfg%lubrication_skin

    stat = 0
    ! &fluid has its own reader: its 'model' is not &lubrication's
    if (group == 'fluid') then
      call fluid_io(cfg, src, ios, msg, echo_unit)
      return
    end if
    if (present(src)) then
      select case (group)
      case ('domain');       read(src, nml=domain, iostat=stat, iomsg=msg)
      case ('time');         read(src, nml=time, iostat=stat, iomsg=msg)
      case ('output');       read(src, nml=output, iostat=stat, iomsg=msg)
      case ('run');          read(src, nml=run, iostat=stat, iomsg=msg)
      case ('verification'); read(src, nml=verification, iostat=stat, iomsg=msg)
      case ('particles');    read(src, nml=particles, iostat=stat, iomsg=msg)
      case ('contact');      read(src, nml=contact, iostat=stat, iomsg=msg)
      case ('lubrication');  read(src, nml=lubrication, iostat=stat, iomsg=msg)
      case ('rheology');     read(src, nml=rheology, iostat=stat, iomsg=msg)
      end select
      if (present(ios)) ios = stat
      if (stat /= 0) return
      cfg%box = box; cfg%cells_per_radius = cells_per_radius
      cfg%y_boundary = to_lower(y_boundary); cfg%shear_rate = shear_rate
      cfg%dt = dt; cfg%steps = steps; cfg%steady_tolerance = steady_tolerance
      cfg%output_directory = directory; cfg%progress_every = progress_every
      cfg%series_every = series_every; cfg%fields_every = fields_every
      cfg%checkpoint_every = checkpoint_every; cfg%particles_every = particles_every
      cfg%title = title; cfg%max_wall_hours = max_wall_hours
      cfg%manufactured_solution = manufactured_solution
      cfg%particle_number = number; cfg%particle_position = position
      cfg%position_file = position_file; cfg%radius = radius; cfg%motion = to_lower(motion)
      cfg%particle_velocity = velocity; cfg%particle_omega = omega
      cfg%external_force = external_force; cfg%external_torque = external_torque
      cfg%radius_offset = radius_offset; cfg%slip_kappa = slip_kappa
      cfg%solid_fraction = solid_fraction; cfg%seed = seed; cfg%packing_sweeps = packing_sweeps
      cfg%packing_min_gap = packing_min_gap
      cfg%discard_strain = discard_strain; cfg%average_strain = average_strain; cfg%blocks = blocks
      cfg%core = core; cfg%profile_bins = profile_bins; cfg%angle_bins = angle_bins
      cfg%pair_shell = pair_shell; cfg%contact_shell = contact_shell
      cfg%roughness = roughness; cfg%eps_bar = eps_bar; cfg%friction = friction
      cfg%normal_stiffness = normal_stiffness; cfg%neighbour_skin = neighbour_skin
      cfg%contact_implicit = implicit
      cfg%lubrication_model = to_lower(model); cfg%lubrication_table = table
      cfg%outer_cutoff = outer_cutoff; cfg%inner_cutoff = inner_cutoff; cfg%lubrication_skin = skin
      if (group == 'contact') cfg%contact_group = .true.
      if (group == 'rheology') cfg%rheology_group = .true.
    end if
    if (present(echo_unit)) then
      select case (group)
      case ('domain');       write(echo_unit, nml=domain)
      case ('time');         write(echo_unit, nml=time)
      case ('output');       write(echo_unit, nml=output)
      case ('run');          write(echo_unit, nml=run)
      case ('verification'); write(echo_unit, nml=verification)
      case ('particles');    call echo_particles(echo_unit, cfg)
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

  ! &fluid (read from src when present, echoed to echo_unit when present), like group_io.
  subroutine fluid_io(cfg, src, ios, msg, echo_unit)
    type(config_t), intent(inout) :: cfg
    character(len=*), intent(in), optional :: src(:)
    integer, intent(out), optional :: ios
    character(len=*), intent(inout), optional :: msg
    integer, intent(in), optional :: echo_unit
    real(dp) :: reynolds, body_force(3), velocity_tolerance, pressure_tolerance, viscous_theta
    character(len=16) :: initial_flow, model
    namelist /fluid/ model, reynolds, body_force, velocity_tolerance, pressure_tolerance, viscous_theta, initial_flow
    integer :: stat
    model = cfg%fluid_model
    reynolds = cfg%reynolds; body_force = cfg%body_force
    velocity_tolerance = cfg%velocity_tolerance; pressure_tolerance = cfg%pressure_tolerance
    viscous_theta = cfg%viscous_theta; initial_flow = cfg%initial_flow
    stat = 0
    if (present(src)) then
      read(src, nml=fluid, iostat=stat, iomsg=msg)
      if (present(ios)) ios = stat
      if (stat /= 0) return
      cfg%fluid_model = to_lower(model)
      cfg%reynolds = reynolds; cfg%body_force = body_force
      cfg%velocity_tolerance = velocity_tolerance; cfg%pressure_tolerance = pressure_tolerance
      cfg%viscous_theta = viscous_theta; cfg%initial_flow = to_lower(initial_flow)
    end if
    if (present(echo_unit)) write(echo_unit, nml=fluid)
  end subroutine fluid_io

  ! &particles echoed with its inline arrays cut to the particles given (not 64 x 3 zeros each).
  subroutine echo_particles(unit, cfg)
    integer, intent(in) :: unit
    type(config_t), intent(in) :: cfg
    integer :: number
    real(dp) :: radius, radius_offset, slip_kappa, solid_fraction, packing_min_gap
    integer :: seed, packing_sweeps
    character(len=max_line) :: position_file
    character(len=16) :: motion
    namelist /particles/ number, position_file, radius, motion, radius_offset, slip_kappa, solid_fraction, &
         seed, packing_sweeps, packing_min_gap
    integer :: p
    number = cfg%particle_number; position_file = cfg%position_file; radius = cfg%radius
    motion = cfg%motion; radius_offset = cfg%radius_offset; slip_kappa = cfg%slip_kappa
    solid_fraction = cfg%solid_fraction; seed = cfg%seed; packing_sweeps = cfg%packing_sweeps
    packing_min_gap = cfg%packing_min_gap
    write(unit, nml=particles)
    do p = 1, cfg%particle_number
      write(unit, '(a,i0,a,3(es23.15e3,:,","))') ' position(:,', p, ')=', cfg%particle_position(:, p)
      if (any(cfg%particle_velocity(:, p) /= 0.0_dp)) &
        write(unit, '(a,i0,a,3(es23.15e3,:,","))') ' velocity(:,', p, ')=', cfg%particle_velocity(:, p)
      if (any(cfg%particle_omega(:, p) /= 0.0_dp)) &
        write(unit, '(a,i0,a,3(es23.15e3,:,","))') ' omega(:,', p, ')=', cfg%particle_omega(:, p)
      if (any(cfg%external_force(:, p) /= 0.0_dp)) &
        write(unit, '(a,i0,a,3(es23.15e3,:,","))') ' external_force(:,', p, ')=', cfg%external_force(:, p)
      if (any(cfg%external_torque(:, p) /= 0.0_dp)) &
        write(unit, '(a,i0,a,3(es23.15e3,:,","))') ' external_torque(:,', p, ')=', cfg%external_torque(:, p)
    end do
  end subroutine echo_particles

  ! The effective deck (defaults included), at the top of the run log. The compiler pads
  ! character values to their declared length; the padding is removed for reading.
  subroutine echo_deck(cfg)
    type(config_t), intent(in) :: cfg
    type(config_t) :: copy
    character(len=8192) :: line
    integer :: g, unit, ios, q1, q2
    if (.not. is_root()) return
    copy = cfg
    open(newunit=unit, status='scratch', action='readwrite', recl=8192)
    do g = 1, ngroups
      call group_io(trim(known_groups(g)), copy, echo_unit=unit)
    end do
    rewind(unit)
    write(*, '(a)') '# effective deck (file '//trim(cfg%deck_file)//', defaults included)'
    do
      read(unit, '(a)', iostat=ios) line
      if (ios /= 0) exit
      q1 = index(line, '"')
      q2 = index(line, '"', back=.true.)
      if (q1 > 0 .and. q2 > q1) line = line(1:q1)//trim(line(q1 + 1:q2 - 1))//line(q2:)
      write(*, '(a)') trim(line)
    end do
    close(unit)
    write(*, '(a)') '# end of effective deck'
    flush(6)
  end subroutine echo_deck

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

    do d = 1, 3
      call check_real(cfg, 'domain', 'box('//xyz(d:d)//')', cfg%box(d), 0.0_dp, 1.0e4_dp, .true.)
    end do
    call check_real(cfg, 'domain', 'cells_per_radius', cfg%cells_per_radius, 1.0_dp, 64.0_dp)
    if (cfg%fluid_model /= 'resolved' .and. cfg%fluid_model /= 'none') &
      call input_error(cfg%deck_file, 'fluid', 'model', 'must be ''resolved'' or ''none'', not '''// &
           trim(cfg%fluid_model)//'''')
    cfg%resolved = (cfg%fluid_model == 'resolved')
    if (all(cfg%y_boundary /= [character(len=16) :: 'walls', 'periodic', 'lees-edwards'])) &
      call input_error(cfg%deck_file, 'domain', 'y_boundary', 'must be ''walls'', ''periodic'' or ''lees-edwards'', not '''// &
           trim(cfg%y_boundary)//'''')
    cfg%lees_edwards = (cfg%y_boundary == 'lees-edwards')
    if (cfg%lees_edwards .and. cfg%resolved) &
      call input_error(cfg%deck_file, 'domain', 'y_boundary', &
           '''lees-edwards'' needs &fluid model = ''none'' (lubrication dynamics): the resolved fluid has walls or a periodic box')
    call check_real(cfg, 'domain', 'shear_rate', cfg%shear_rate, -1.0e3_dp, 1.0e3_dp)
    cfg%walls = (cfg%y_boundary == 'walls')
    if (.not. cfg%walls .and. .not. cfg%lees_edwards .and. cfg%shear_rate /= 0.0_dp) &
      call input_error(cfg%deck_file, 'domain', 'shear_rate', &
           'a periodic box in y cannot be sheared by walls: set shear_rate = 0 or y_boundary = ''walls''')
    cfg%h = 1.0_dp / cfg%cells_per_radius
    do d = 1, 3
      n = cfg%box(d) * cfg%cells_per_radius
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
    if (cfg%walls) cfg%wall_speed = 0.5_dp * cfg%shear_rate * cfg%box(2)

    call check_real(cfg, 'fluid', 'reynolds', cfg%reynolds, 0.0_dp, 100.0_dp, .true.)
    do d = 1, 3
      call check_real(cfg, 'fluid', 'body_force('//xyz(d:d)//')', cfg%body_force(d), -1.0e6_dp, 1.0e6_dp)
    end do
    call check_real(cfg, 'fluid', 'velocity_tolerance', cfg%velocity_tolerance, 1.0e-15_dp, 0.1_dp)
    call check_real(cfg, 'fluid', 'pressure_tolerance', cfg%pressure_tolerance, 1.0e-15_dp, 0.1_dp)
    call check_real(cfg, 'fluid', 'viscous_theta', cfg%viscous_theta, 0.5_dp, 1.0_dp)
    if (cfg%initial_flow /= 'rest' .and. cfg%initial_flow /= 'shear') &
      call input_error(cfg%deck_file, 'fluid', 'initial_flow', 'must be ''rest'' or ''shear'', not '''// &
           trim(cfg%initial_flow)//'''')

    call check_real(cfg, 'time', 'dt', cfg%dt, 0.0_dp, 10.0_dp, .true.)
    if (cfg%steps /= -1) call check_int(cfg, 'time', 'steps', cfg%steps, 0, 1000000000)
    call check_real(cfg, 'time', 'steady_tolerance', cfg%steady_tolerance, 0.0_dp, 1.0_dp)
    if (.not. cfg%resolved .and. cfg%steady_tolerance > 0.0_dp) &
      call input_error(cfg%deck_file, 'time', 'steady_tolerance', 'measures the fluid: needs &fluid model = ''resolved''')

    if (len_trim(cfg%output_directory) == 0) &
      call input_error(cfg%deck_file, 'output', 'directory', 'must not be empty')
    call check_int(cfg, 'output', 'progress_every', cfg%progress_every, 1, huge(1))
    call check_int(cfg, 'output', 'series_every', cfg%series_every, 1, huge(1))
    call check_int(cfg, 'output', 'fields_every', cfg%fields_every, 0, huge(1))
    call check_int(cfg, 'output', 'checkpoint_every', cfg%checkpoint_every, 0, huge(1))
    call check_int(cfg, 'output', 'particles_every', cfg%particles_every, 0, huge(1))

    call check_real(cfg, 'run', 'max_wall_hours', cfg%max_wall_hours, 0.0_dp, 1.0e5_dp)

    call validate_particles(cfg)
    call validate_contact(cfg)
    call validate_lubrication(cfg)
    call validate_rheology(cfg)
    if (cfg%steps == -1) cfg%steps = 1000
    ! the in-run packing of a rough contact run starts contact-free, like the paper's hard-sphere
    ! configurations (the start-gap rule of mod_particles::configuration_fault asks for h_r/2)
    if (cfg%packing_min_gap == -1.0_dp) then
      cfg%packing_min_gap = 0.0_dp
      if (cfg%contact_group) cfg%packing_min_gap = cfg%roughness * cfg%radius
    else if (cfg%contact_group .and. cfg%solid_fraction > 0.0_dp &
             .and. cfg%packing_min_gap < 0.5_dp * cfg%roughness * cfg%radius) then
      call input_error(cfg%deck_file, 'particles', 'packing_min_gap', &
           'rough contacts need gaps >= h_r/2 at the start (&contact roughness x radius / 2)')
    end if

    if (cfg%manufactured_solution .and. any(cfg%body_force /= 0.0_dp)) &
      call input_error(cfg%deck_file, 'verification', 'manufactured_solution', &
           'the manufactured solution brings its own forcing: set &fluid body_force = 0')
  end subroutine validate

  ! Ranges of &particles; positions given inline are checked against the box here, those from a
  ! file by mod_particles_io when it reads them (same rules, mod_particles::configuration_fault).
  subroutine validate_particles(cfg)
    type(config_t), intent(inout) :: cfg
    logical :: exists
    call check_int(cfg, 'particles', 'number', cfg%particle_number, 0, max_inline_particles)
    call check_real(cfg, 'particles', 'radius', cfg%radius, 0.0_dp, 100.0_dp, .true.)
    if (all(cfg%motion /= [character(len=16) :: 'free', 'prescribed', 'resistance', 'frozen', 'fixed'])) &
      call input_error(cfg%deck_file, 'particles', 'motion', &
           'must be ''free'', ''prescribed'', ''resistance'', ''frozen'' or ''fixed'', not '''// &
           trim(cfg%motion)//'''')
    call check_real(cfg, 'particles', 'radius_offset', cfg%radius_offset, -2.0_dp, 2.0_dp)
    call check_real(cfg, 'particles', 'slip_kappa', cfg%slip_kappa, 0.0_dp, 100.0_dp)
    if (len_trim(cfg%position_file) > 0) then
      if (cfg%particle_number > 0) &
        call input_error(cfg%deck_file, 'particles', 'position_file', &
             'give the particles either inline (number, position) or in position_file, not both')
      inquire(file=trim(cfg%position_file), exist=exists)
      if (.not. exists) call input_error(cfg%deck_file, 'particles', 'position_file', &
           '"'//trim(cfg%position_file)//'" does not exist')
      if (cfg%motion == 'prescribed' .or. cfg%motion == 'resistance') &
        call input_error(cfg%deck_file, 'particles', 'motion', &
           'prescribed velocities are given inline: use number and position, not position_file')
    end if
    call check_real(cfg, 'particles', 'solid_fraction', cfg%solid_fraction, 0.0_dp, phi_max)
    call check_int(cfg, 'particles', 'seed', cfg%seed, 0, huge(1))
    call check_int(cfg, 'particles', 'packing_sweeps', cfg%packing_sweeps, 0, 1000000)
    if (cfg%packing_min_gap /= -1.0_dp) &
      call check_real(cfg, 'particles', 'packing_min_gap', cfg%packing_min_gap, 0.0_dp, 1.0_dp)
    if (cfg%solid_fraction > 0.0_dp) then
      if (cfg%particle_number > 0 .or. len_trim(cfg%position_file) > 0) &
        call input_error(cfg%deck_file, 'particles', 'solid_fraction', &
             'give the particles one way: solid_fraction (a packing made now), number/position, or position_file')
      if (cfg%motion == 'prescribed' .or. cfg%motion == 'resistance') &
        call input_error(cfg%deck_file, 'particles', 'motion', &
           'prescribed velocities are given inline: use number and position, not solid_fraction')
    end if
    if (.not. cfg%resolved .and. cfg%particle_number == 0 .and. len_trim(cfg%position_file) == 0 .and. &
        cfg%solid_fraction == 0.0_dp) &
      call input_error(cfg%deck_file, 'fluid', 'model', '''none'' (lubrication dynamics) moves spheres and nothing '// &
           'else: give &particles (number/position, position_file or solid_fraction)')
    if (cfg%resolved .and. cfg%radius + cfg%radius_offset * cfg%h < 1.5_dp * cfg%h) &
      call input_error(cfg%deck_file, 'particles', 'radius', &
           'the sphere must span at least 1.5 grid cells in radius (raise &domain cells_per_radius)')
  end subroutine validate_particles

  ! Ranges of &rheology, and the step counts of the averaging window (doc/RHEOLOGY.md).
  subroutine validate_rheology(cfg)
    type(config_t), intent(inout) :: cfg
    character(len=200) :: text
    real(dp) :: strain_per_step
    integer :: needed
    if (.not. cfg%rheology_group) return
    if (.not. (cfg%walls .or. cfg%lees_edwards) .or. cfg%shear_rate == 0.0_dp) &
      call input_error(cfg%deck_file, 'rheology', '', &
           'statistics are taken in the core of the sheared Couette cell (or the whole Lees-Edwards box): '// &
           'needs y_boundary = ''walls'' or ''lees-edwards'' and shear_rate /= 0')
    if (cfg%particle_number == 0 .and. len_trim(cfg%position_file) == 0 .and. cfg%solid_fraction == 0.0_dp) &
      call input_error(cfg%deck_file, 'rheology', '', 'needs particles (&particles solid_fraction, number or position_file)')
    call check_real(cfg, 'rheology', 'discard_strain', cfg%discard_strain, 0.0_dp, 1.0e6_dp)
    call check_real(cfg, 'rheology', 'average_strain', cfg%average_strain, 0.0_dp, 1.0e6_dp, .true.)
    call check_int(cfg, 'rheology', 'blocks', cfg%blocks, 1, 1000)
    call check_real(cfg, 'rheology', 'core(1)', cfg%core(1), 0.0_dp, 1.0_dp)
    call check_real(cfg, 'rheology', 'core(2)', cfg%core(2), 0.0_dp, 1.0_dp)
    if (cfg%core(2) <= cfg%core(1)) call input_error(cfg%deck_file, 'rheology', 'core', 'must be y_lo/Ly < y_hi/Ly')
    call check_int(cfg, 'rheology', 'profile_bins', cfg%profile_bins, 0, 100000)
    if (cfg%profile_bins == 0) cfg%profile_bins = max(1, nint(4 * cfg%box(2) / cfg%radius))
    call check_int(cfg, 'rheology', 'angle_bins', cfg%angle_bins, 4, 3600)
    call check_real(cfg, 'rheology', 'pair_shell', cfg%pair_shell, 2.0_dp, 3.0_dp, .true.)
    call check_real(cfg, 'rheology', 'contact_shell', cfg%contact_shell, 0.0_dp, 0.5_dp)
    if (cfg%contact_shell == 0.0_dp) then
      cfg%contact_shell = 0.005_dp
      if (cfg%contact_group .and. cfg%roughness > 0.0_dp) cfg%contact_shell = cfg%roughness
    end if
    strain_per_step = abs(cfg%shear_rate) * cfg%dt
    cfg%discard_step = nint(cfg%discard_strain / strain_per_step)
    cfg%block_steps = nint(cfg%average_strain / (cfg%blocks * strain_per_step))
    if (cfg%block_steps < cfg%series_every) then
      write(text, '(a,i0,a,i0,a)') 'a block of average_strain/blocks is ', cfg%block_steps, &
           ' steps, fewer than &output series_every = ', cfg%series_every, ': every block needs records'
      call input_error(cfg%deck_file, 'rheology', 'average_strain', trim(text))
    end if
    needed = cfg%discard_step + cfg%blocks * cfg%block_steps
    if (cfg%steps == -1) cfg%steps = needed
  end subroutine validate_rheology

  ! Ranges of &lubrication; whether a table exists for this resolution is checked where it is read
  ! (mod_lubrication_io), still before any work.
  subroutine validate_lubrication(cfg)
    type(config_t), intent(in) :: cfg
    if (all(cfg%lubrication_model /= [character(len=16) :: 'none', 'simple', 'full'])) &
      call input_error(cfg%deck_file, 'lubrication', 'model', &
           'must be ''none'', ''simple'' or ''full'', not '''//trim(cfg%lubrication_model)//'''')
    if (cfg%resolved) then
      call check_real(cfg, 'lubrication', 'outer_cutoff', cfg%outer_cutoff, 0.0_dp, 2.0_dp)
    else
      ! lubrication dynamics: the exact functions hold at every gap (the pair test covers 10a)
      call check_real(cfg, 'lubrication', 'outer_cutoff', cfg%outer_cutoff, 0.0_dp, 20.0_dp)
      if (cfg%lubrication_model == 'simple') &
        call input_error(cfg%deck_file, 'lubrication', 'model', &
             '''simple'' corrects a resolved fluid: with &fluid model = ''none'' use ''full'' (the exact '// &
             'two-body functions, the default) or ''none'' (one-body drag only)')
    end if
    call check_real(cfg, 'lubrication', 'inner_cutoff', cfg%inner_cutoff, 1.0e-8_dp, 0.1_dp)
    call check_real(cfg, 'lubrication', 'skin', cfg%lubrication_skin, 0.0_dp, 2.0_dp, .true.)
    if (cfg%outer_cutoff > 0.0_dp .and. cfg%outer_cutoff <= cfg%inner_cutoff) &
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
    call check_real(cfg, 'contact', 'roughness', cfg%roughness, 0.0_dp, 0.5_dp)
    call check_real(cfg, 'contact', 'eps_bar', cfg%eps_bar, 0.0_dp, 1.0_dp, .true.)
    call check_real(cfg, 'contact', 'friction', cfg%friction, 0.0_dp, 10.0_dp)
    call check_real(cfg, 'contact', 'normal_stiffness', cfg%normal_stiffness, 0.0_dp, 1.0e15_dp)
    call check_real(cfg, 'contact', 'neighbour_skin', cfg%neighbour_skin, 0.0_dp, 2.0_dp, .true.)
    if (cfg%normal_stiffness <= 0.0_dp) then
      if (cfg%roughness <= 0.0_dp) &
        call input_error(cfg%deck_file, 'contact', 'normal_stiffness', &
             'smooth spheres (roughness = 0) need a prescribed normal_stiffness > 0')
      if (cfg%shear_rate == 0.0_dp) &
        call input_error(cfg%deck_file, 'contact', 'normal_stiffness', &
             'k_n from eps_bar needs a non-zero &domain shear_rate: prescribe normal_stiffness > 0')
    end if
    ! the neighbour search needs every periodic length >= 2 x cutoff (one image in range)
    cutoff = cfg%radius * (2.0_dp + cfg%roughness) + cfg%neighbour_skin
    do d = 1, 3
      if (d == 2 .and. cfg%walls) cycle
      if (cfg%box(d) < 2.0_dp * cutoff) then
        write(text, '(a,f0.4,a)') 'with contacts every periodic length must be >= 2 (2a + h_r + neighbour_skin) = ', &
             2.0_dp * cutoff, ' (lower &contact neighbour_skin or enlarge the box)'
        call input_error(cfg%deck_file, 'domain', 'box('//xyz(d:d)//')', trim(text))
      end if
    end do
  end subroutine validate_contact

end module mod_params
