! The deck a checkpoint was written with, and what a restart may change of it (doc/INPUT.md
! "Restart: what must match, what may change").
!   deck_record   writes the deck's variables as attributes of the group /deck of a checkpoint,
!                 one per variable, named GROUP.VARIABLE ('time.dt', 'contact.friction'): numbers
!                 as float64 arrays (logicals as 0/1), strings as fixed-length strings
!   deck_compare  compares them with this run's deck: a variable that must match and differs stops
!                 the restart (its group, its name, both values); one that may change and differs is
!                 named in the run log; one the checkpoint does not record (written before
!                 2026-11-27) cannot be checked, and the log says so. A branch (-branch: the
!                 checkpoint's state, this deck's physics) may also change the contact and
!                 lubrication models, the particles' loads and the imposed shear (&shear, the
!                 rate) (BRANCH_MAY_CHANGE), each change
!                 named in the run log
! Only the variables the run uses are recorded and compared (the fluid's only with a resolved
! fluid, the particles' only with particles, the contacts' only with contacts). Values are compared
! exactly: the attribute holds the double the deck was read into, and the same text reads into the
! same double, so any difference is a different input. The box, the cell counts, the boundary
! type, the particle count and the &rheology window are checked by mod_checkpoint itself.
module mod_restart_deck
  use hdf5
  use mod_kinds, only: dp
  use mod_params, only: config_t
  use mod_h5util, only: write_attribute, read_attribute, write_string_attribute, read_string_attribute, &
                        has_attribute, has_object
  use mod_errors, only: log_line
  implicit none
  private
  public :: deck_record, deck_compare

  ! MUST_MATCH: on a restart; BRANCH_MAY_CHANGE: must match on a restart, may change on a branch
  ! (-branch: the contact and lubrication models and the particles' loads, what a study varies
  ! from a shared state); MAY_CHANGE: on either
  integer, parameter :: MUST_MATCH = 1, MAY_CHANGE = 2, BRANCH_MAY_CHANGE = 3
  integer, parameter :: max_items = 64
  character(len=*), parameter :: deck_group = 'deck'

  ! One deck variable as a restart sees it.
  type :: item_t
    character(len=16) :: group = ''
    character(len=24) :: name = ''
    integer :: rule = MUST_MATCH
    real(dp), allocatable :: values(:)             ! numbers (logicals as 0/1)
    character(len=:), allocatable :: text          ! strings (allocated instead of values)
    character(len=16) :: legacy = ''               ! the root attribute older checkpoints hold it in
    integer :: per = 0                             ! > 0: an array of PER values per particle
  end type item_t

contains

  ! The variables of CFG a restart compares, for a run with PARTICLES spheres. rule: must match
  ! (the state's meaning or the equations it is stepped with) or may change (how long, how much is
  ! written, how exactly the linear systems are solved, how the neighbours are searched for).
  subroutine deck_items(cfg, particles, list)
    type(config_t), intent(in) :: cfg
    integer, intent(in) :: particles
    type(item_t), allocatable, intent(out) :: list(:)
    type(item_t) :: found(max_items)
    integer :: n
    logical :: contacts
    n = 0
    contacts = particles > 0 .and. cfg%contact_group
    call text_item('domain', 'y_boundary', MUST_MATCH, cfg%domain%y_boundary)
    ! the reference rate, under its older name (as checkpoints before &shear record it), and the
    ! protocol (doc/INPUT.md "&shear"): a branch may change them (a reversal or an oscillation
    ! after a steady pre-shear), and starts the deck's protocol afresh
    call real_item('domain', 'shear_rate', BRANCH_MAY_CHANGE, [cfg%domain%shear_rate], legacy='shear_rate')
    call text_item('shear', 'control', BRANCH_MAY_CHANGE, cfg%shear%control)
    call text_item('shear', 'protocol', BRANCH_MAY_CHANGE, cfg%shear%protocol)
    if (cfg%shear%control == 'stress') call real_item('shear', 'stress', BRANCH_MAY_CHANGE, [cfg%shear%stress])
    if (cfg%shear%protocol == 'steps') then
      call text_item('shear', 'step_by', BRANCH_MAY_CHANGE, cfg%shear%step_by)
      call real_item('shear', 'step_at', BRANCH_MAY_CHANGE, cfg%shear%step_at(1:cfg%shear%levels))
      call real_item('shear', 'step_level', BRANCH_MAY_CHANGE, cfg%shear%step_level(1:cfg%shear%levels))
    end if
    if (cfg%shear%protocol == 'reversal') &
      call real_item('shear', 'reversal_strain', BRANCH_MAY_CHANGE, [cfg%shear%reversal_strain])
    if (cfg%shear%protocol == 'oscillatory') then
      call real_item('shear', 'strain_amplitude', BRANCH_MAY_CHANGE, [cfg%shear%strain_amplitude])
      call real_item('shear', 'period', BRANCH_MAY_CHANGE, [cfg%shear%period])
    end if
    if (cfg%resolved) then
      call real_item('fluid', 'reynolds', MUST_MATCH, [cfg%fluid%reynolds], legacy='reynolds')
      call real_item('fluid', 'body_force', MUST_MATCH, cfg%fluid%body_force)
      call real_item('fluid', 'viscous_theta', MUST_MATCH, [cfg%fluid%viscous_theta])
      call real_item('fluid', 'velocity_tolerance', MAY_CHANGE, [cfg%fluid%velocity_tolerance])
      call real_item('fluid', 'pressure_tolerance', MAY_CHANGE, [cfg%fluid%pressure_tolerance])
      call real_item('verification', 'manufactured_solution', MUST_MATCH, [merge(1.0_dp, 0.0_dp, &
                     cfg%verification%manufactured_solution)])
    end if
    call real_item('time', 'dt', MUST_MATCH, [cfg%time%dt], legacy='dt')
    call real_item('time', 'steps', MAY_CHANGE, [real(cfg%time%steps, dp)])
    call real_item('time', 'steady_tolerance', MAY_CHANGE, [cfg%time%steady_tolerance])
    call text_item('output', 'directory', MAY_CHANGE, cfg%output%directory)
    call real_item('output', 'progress_every', MAY_CHANGE, [real(cfg%output%progress_every, dp)])
    ! with &rheology series_every also sets the records the statistics take: mod_checkpoint checks
    ! it against the checkpoint's window
    call real_item('output', 'series_every', MAY_CHANGE, [real(cfg%output%series_every, dp)])
    call real_item('output', 'fields_every', MAY_CHANGE, [real(cfg%output%fields_every, dp)])
    call real_item('output', 'checkpoint_every', MAY_CHANGE, [real(cfg%output%checkpoint_every, dp)])
    call real_item('output', 'particles_every', MAY_CHANGE, [real(cfg%output%particles_every, dp)])
    call text_item('run', 'title', MAY_CHANGE, cfg%run%title)
    call real_item('run', 'max_wall_hours', MAY_CHANGE, [cfg%run%max_wall_hours])
    if (particles > 0) then
      ! (equal spheres: one radius, as checkpoints before mixtures recorded it)
      call real_item('particles', 'radius', MUST_MATCH, cfg%particles%radius(1:cfg%species))
      if (cfg%species > 1) then
        call real_item('particles', 'volume_share', MUST_MATCH, cfg%particles%volume_share(1:cfg%species))
        call real_item('particles', 'number_share', MUST_MATCH, cfg%particles%number_share(1:cfg%species))
      end if
      call text_item('particles', 'motion', MUST_MATCH, cfg%particles%motion)
      if (cfg%resolved) then
        call real_item('particles', 'radius_offset', MUST_MATCH, [cfg%particles%radius_offset])
        call real_item('particles', 'slip_kappa', MUST_MATCH, [cfg%particles%slip_kappa])
      end if
      ! the imposed velocities (prescribed motion) or the external loads (free motion) of the
      ! inline particles
      if (cfg%particles%motion == 'prescribed' .or. cfg%particles%motion == 'resistance') then
        call real_item('particles', 'velocity', MUST_MATCH, reshape(cfg%particles%velocity, [size(cfg%particles%velocity)]), &
                       per=3)
        call real_item('particles', 'omega', MUST_MATCH, reshape(cfg%particles%omega, [size(cfg%particles%omega)]), per=3)
      else if (cfg%particles%motion == 'free') then
        call real_item('particles', 'external_force', BRANCH_MAY_CHANGE, reshape(cfg%particles%external_force, &
                       [size(cfg%particles%external_force)]), per=3)
        call real_item('particles', 'external_torque', BRANCH_MAY_CHANGE, reshape(cfg%particles%external_torque, &
                       [size(cfg%particles%external_torque)]), per=3)
      end if
      call text_item('lubrication', 'model', BRANCH_MAY_CHANGE, cfg%lubrication%model)
      call real_item('lubrication', 'outer_cutoff', BRANCH_MAY_CHANGE, [cfg%lubrication%outer_cutoff])
      call real_item('lubrication', 'inner_cutoff', BRANCH_MAY_CHANGE, [cfg%lubrication%inner_cutoff])
      call real_item('lubrication', 'skin', MAY_CHANGE, [cfg%lubrication%skin])
      ! the table's path (its content is checked against the deck by mod_lubrication_io)
      if (cfg%resolved) call text_item('lubrication', 'table', MAY_CHANGE, cfg%lubrication%table)
    end if
    if (contacts) then
      call real_item('contact', 'roughness', BRANCH_MAY_CHANGE, [cfg%contact%roughness])
      call real_item('contact', 'normal_stiffness', BRANCH_MAY_CHANGE, [cfg%contact%normal_stiffness])
      ! eps_bar sets k_n only when normal_stiffness is 0 (doc/CONTACT.md)
      if (cfg%contact%normal_stiffness <= 0.0_dp) call real_item('contact', 'eps_bar', BRANCH_MAY_CHANGE, [cfg%contact%eps_bar])
      call real_item('contact', 'friction', BRANCH_MAY_CHANGE, [cfg%contact%friction])
      call real_item('contact', 'implicit', BRANCH_MAY_CHANGE, [merge(1.0_dp, 0.0_dp, cfg%contact%implicit)])
      call real_item('contact', 'neighbour_skin', MAY_CHANGE, [cfg%contact%neighbour_skin])
    end if
    allocate(list(n))
    list(1:n) = found(1:n)

  contains

    subroutine real_item(group, name, rule, values, legacy, per)
      character(len=*), intent(in) :: group, name
      integer, intent(in) :: rule
      real(dp), intent(in) :: values(:)
      character(len=*), intent(in), optional :: legacy
      integer, intent(in), optional :: per
      n = n + 1
      found(n)%group = group
      found(n)%name = name
      found(n)%rule = rule
      found(n)%values = values
      if (present(legacy)) found(n)%legacy = legacy
      if (present(per)) found(n)%per = per
    end subroutine real_item

    subroutine text_item(group, name, rule, text)
      character(len=*), intent(in) :: group, name, text
      integer, intent(in) :: rule
      n = n + 1
      found(n)%group = group
      found(n)%name = name
      found(n)%rule = rule
      found(n)%text = trim(text)
    end subroutine text_item
  end subroutine deck_items

  ! Record the deck of CFG (a run with PARTICLES spheres) in the group /deck of FILE (rank 0).
  ! err /= 0 on failure.
  subroutine deck_record(file, cfg, particles, err)
    integer(HID_T), intent(in) :: file
    type(config_t), intent(in) :: cfg
    integer, intent(in) :: particles
    integer, intent(out) :: err
    type(item_t), allocatable :: list(:)
    integer(HID_T) :: group
    integer :: k, e
    call deck_items(cfg, particles, list)
    call h5gcreate_f(file, deck_group, group, err)
    if (err /= 0) return
    do k = 1, size(list)
      if (allocated(list(k)%text)) then
        call write_string_attribute(group, attribute_name(list(k)), list(k)%text, e)
      else
        call write_attribute(group, attribute_name(list(k)), list(k)%values, e)
      end if
      if (e /= 0) err = e
    end do
    call h5gclose_f(group, e)
  end subroutine deck_record

  ! Compare the deck recorded in FILE with CFG (rank 0). A variable that must match and differs:
  ! group, variable and message are set (the first such variable), else they stay ''. Changes that
  ! are allowed, and variables the checkpoint does not record, go to the run log.
  subroutine deck_compare(file, cfg, particles, branch, group, variable, message)
    integer(HID_T), intent(in) :: file
    type(config_t), intent(in) :: cfg
    integer, intent(in) :: particles
    logical, intent(in) :: branch
    character(len=*), intent(out) :: group, variable, message
    type(item_t), allocatable :: list(:)
    integer(HID_T) :: deck, loc
    integer :: k, err, first
    logical :: has_deck
    character(len=:), allocatable :: missing, old_text
    character(len=400) :: stored
    real(dp), allocatable :: old(:)
    character(len=600) :: line
    character(len=:), allocatable :: kind, allowed

    group = ''
    variable = ''
    message = ''
    missing = ''
    kind = trim(merge('branch ', 'restart', branch))
    allowed = trim(merge(' (may change on a branch) ', ' (may change on a restart)', branch))
    call deck_items(cfg, particles, list)
    deck = -1
    has_deck = has_object(file, deck_group)
    if (has_deck) call h5gopen_f(file, deck_group, deck, err)
    do k = 1, size(list)
      ! where the checkpoint holds the variable: /deck, else (older checkpoints) a root attribute
      loc = -1
      if (has_deck) then
        if (has_attribute(deck, attribute_name(list(k)))) loc = deck
      end if
      if (loc == -1 .and. len_trim(list(k)%legacy) > 0) then
        if (has_attribute(file, trim(list(k)%legacy))) loc = file
      end if
      if (loc == -1) then
        ! (a branch may bring in what the checkpoint's run did not have: contacts)
        if (.not. (branch .and. (list(k)%rule == BRANCH_MAY_CHANGE .or. list(k)%group == 'contact'))) &
          missing = missing//' &'//trim(list(k)%group)//' '//trim(list(k)%name)//','
        cycle
      end if
      if (allocated(list(k)%text)) then
        call read_string_attribute(loc, stored_name(list(k), loc == deck), stored, err)
        old_text = trim(stored)
        if (err /= 0) then
          call refuse(k, 'is recorded in the checkpoint but cannot be read')
          exit
        end if
        if (old_text == list(k)%text) cycle
        if (must_be_kept(list(k))) then
          call refuse(k, 'the checkpoint''s run had '//trim(list(k)%name)//' = '''//old_text//''', the deck "'// &
               trim(cfg%deck_file)//'" has '''//list(k)%text//'''')
          exit
        end if
        call log_line(kind//': &'//trim(list(k)%group)//' '//trim(list(k)%name)//' changed from '''//old_text// &
             ''' to '''//list(k)%text//''''//allowed)
      else
        if (allocated(old)) deallocate(old)
        allocate(old(size(list(k)%values)))
        call read_attribute(loc, stored_name(list(k), loc == deck), old, err)
        if (err /= 0) then
          call refuse(k, 'is recorded in the checkpoint with another size, or cannot be read')
          exit
        end if
        if (all(old == list(k)%values)) cycle
        first = findloc(old == list(k)%values, .false., 1)
        if (must_be_kept(list(k))) then
          call refuse(k, 'the checkpoint''s run had '//shown(list(k), old, first)//', the deck "'// &
               trim(cfg%deck_file)//'" has '//shown(list(k), list(k)%values, first))
          exit
        end if
        line = kind//': &'//trim(list(k)%group)//' changed from '//shown(list(k), old, first)//' to '// &
               shown(list(k), list(k)%values, first)//allowed
        call log_line(line)
      end if
    end do
    if (has_deck) call h5gclose_f(deck, err)
    if (len_trim(message) > 0) return
    if (len(missing) > 0) call log_line(kind//': the checkpoint does not record'//missing(1:len(missing) - 1)// &
         ' (written before 2026-11-27): these cannot be checked, the deck''s values are used')
    call log_line(kind//': the state is the checkpoint''s; the deck''s initial conditions (&fluid initial_flow, '// &
         '&particles position, position_file, solid_fraction, seed, packing_sweeps, packing_min_gap) are not used')

  contains

    logical function must_be_kept(item)
      type(item_t), intent(in) :: item
      must_be_kept = item%rule == MUST_MATCH .or. (item%rule == BRANCH_MAY_CHANGE .and. .not. branch)
    end function must_be_kept

    subroutine refuse(k, text)
      integer, intent(in) :: k
      character(len=*), intent(in) :: text
      group = list(k)%group
      variable = list(k)%name
      if (list(k)%per > 0) write(variable, '(a,i0,a)') trim(list(k)%name)//'(:,', (first - 1) / list(k)%per + 1, ')'
      if (list(k)%rule == BRANCH_MAY_CHANGE) then
        message = text//': a restart continues the checkpoint''s physics (doc/INPUT.md "Restart"): restore '// &
                  'the value, or branch from the checkpoint (-branch CHECKPOINT: its state, this deck''s '// &
                  'contact and lubrication models and loads)'
      else
        message = text//': a restart continues the checkpoint''s physics (doc/INPUT.md "Restart"): restore '// &
                  'the value, or start a new run (its spheres may start from the checkpoint: &particles position_file)'
      end if
    end subroutine refuse
  end subroutine deck_compare

  ! The attribute of ITEM in /deck: GROUP.VARIABLE.
  function attribute_name(item) result(name)
    type(item_t), intent(in) :: item
    character(len=:), allocatable :: name
    name = trim(item%group)//'.'//trim(item%name)
  end function attribute_name

  function stored_name(item, in_deck) result(name)
    type(item_t), intent(in) :: item
    logical, intent(in) :: in_deck
    character(len=:), allocatable :: name
    if (in_deck) then
      name = attribute_name(item)
    else
      name = trim(item%legacy)
    end if
  end function stored_name

  ! 'dt = 5.00000E-03', or for arrays over the particles the particle of element FIRST
  ! ('external_force(:,2) = 1, 0, 0'), or the whole of a short array.
  function shown(item, values, first) result(text)
    type(item_t), intent(in) :: item
    real(dp), intent(in) :: values(:)
    integer, intent(in) :: first
    character(len=:), allocatable :: text
    integer :: lo, hi, j, p
    character(len=40) :: one
    lo = 1
    hi = size(values)
    text = trim(item%name)
    if (item%per > 0) then
      p = (first - 1) / item%per + 1
      lo = (p - 1) * item%per + 1
      hi = p * item%per
      write(one, '(a,i0,a)') '(:,', p, ')'
      text = text//trim(one)
    end if
    text = text//' = '
    do j = lo, hi
      text = text//trim(number(values(j)))
      if (j < hi) text = text//', '
    end do
  end function shown

  ! X with the fewest significant digits that read back as X exactly (whole numbers as integers).
  function number(x) result(text)
    real(dp), intent(in) :: x
    character(len=40) :: text
    character(len=20) :: form
    real(dp) :: back
    integer :: d, ios
    if (abs(x) < 1.0e15_dp .and. x == anint(x)) then
      write(text, '(i0)') nint(x, kind=8)
      return
    end if
    do d = 2, 17
      write(form, '(a,i0,a)') '(es30.', d - 1, ')'
      write(text, form) x
      read(text, *, iostat=ios) back
      if (ios == 0 .and. back == x) exit
    end do
    text = adjustl(text)
  end function number

end module mod_restart_deck
