! Input deck of bin/pairtraj: three namelist groups, &pair (physics and start), &integration
! (step control) and &output (CSV file), each optional (an absent group keeps its defaults).
! Every variable, its default, unit and range: doc/PAIRTRAJ_INPUT.md. Bad input stops the program
! before any work with one message naming the file, the group and the variable, and exit status 2.
module mod_pair_deck
  use mod_kinds, only: dp
  implicit none
  private
  public :: pair_deck, read_pair_deck, deck_fail

  !> Everything pairtraj reads. Units: radius a = 1, viscosity eta = 1, shear rate = 1.
  type :: pair_deck
    ! &pair
    real(dp) :: eps_r = 0.0_dp          ! roughness height h_r / a
    real(dp) :: eps_bar = 0.05_dp       ! roughness deformation under 6 pi eta gamma_dot a^2 (JFM 2.4)
    real(dp) :: mu_d = 0.0_dp           ! Coulomb friction coefficient
    real(dp) :: kn_smooth = 1.0e6_dp    ! Hertz stiffness used when eps_r = 0
    real(dp) :: start(3) = [-6.0_dp, 0.5_dp, 0.0_dp]   ! r = x_2 - x_1 at t = 0, units of a
    real(dp) :: x_end = 6.0_dp          ! stop when r_x reaches x_end
    real(dp) :: size_ratio = 1.0_dp     ! radius of sphere 2 over that of sphere 1 (the unit a)
    ! &integration
    real(dp) :: rtol = 1.0e-9_dp
    real(dp) :: atol = 1.0e-12_dp
    real(dp) :: h_init = 1.0e-3_dp
    integer :: max_steps = 2000000
    real(dp) :: t_max = 1000.0_dp
    ! &output
    character(len=512) :: csv_file = 'out/pair.csv'
    real(dp) :: dt_out = 0.02_dp
  end type pair_deck

  character(len=*), parameter :: known_pair(7) = [character(len=12) :: 'eps_r', 'eps_bar', &
    'mu_d', 'kn_smooth', 'start', 'x_end', 'size_ratio']
  character(len=*), parameter :: known_integration(5) = [character(len=12) :: 'rtol', 'atol', &
    'h_init', 'max_steps', 't_max']
  character(len=*), parameter :: known_output(2) = [character(len=12) :: 'csv_file', 'dt_out']

contains

  !> Read and validate the deck at path. Stops with exit status 2 on any error.
  subroutine read_pair_deck(path, deck)
    character(len=*), intent(in) :: path
    type(pair_deck), intent(out) :: deck
    real(dp) :: eps_r, eps_bar, mu_d, kn_smooth, start(3), x_end, rtol, atol, h_init, t_max, dt_out
    real(dp) :: size_ratio
    integer :: max_steps, unit, ios
    character(len=512) :: csv_file
    character(len=256) :: msg
    logical :: exists
    namelist /pair/ eps_r, eps_bar, mu_d, kn_smooth, start, x_end, size_ratio
    namelist /integration/ rtol, atol, h_init, max_steps, t_max
    namelist /output/ csv_file, dt_out

    eps_r = deck%eps_r; eps_bar = deck%eps_bar; mu_d = deck%mu_d; kn_smooth = deck%kn_smooth
    start = deck%start; x_end = deck%x_end; size_ratio = deck%size_ratio
    rtol = deck%rtol; atol = deck%atol; h_init = deck%h_init; max_steps = deck%max_steps
    t_max = deck%t_max
    csv_file = deck%csv_file; dt_out = deck%dt_out

    inquire (file=path, exist=exists)
    if (.not. exists) call deck_fail(path, '', '', 'file not found')
    open (newunit=unit, file=path, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) call deck_fail(path, '', '', 'cannot open: ' // trim(msg))

    ! Every '&name' line must open a known group (a misspelt group would be silently skipped).
    call check_group_names(unit, path)
    ! Check every group's names and values first, for messages that name the variable.
    call scan_group(unit, path, 'pair', known_pair)
    call scan_group(unit, path, 'integration', known_integration)
    call scan_group(unit, path, 'output', known_output)

    rewind (unit)
    if (group_present(unit, 'pair')) then
      read (unit, nml=pair, iostat=ios, iomsg=msg)
      if (ios /= 0) call deck_fail(path, 'pair', '', trim(msg))
    end if
    rewind (unit)
    if (group_present(unit, 'integration')) then
      read (unit, nml=integration, iostat=ios, iomsg=msg)
      if (ios /= 0) call deck_fail(path, 'integration', '', trim(msg))
    end if
    rewind (unit)
    if (group_present(unit, 'output')) then
      read (unit, nml=output, iostat=ios, iomsg=msg)
      if (ios /= 0) call deck_fail(path, 'output', '', trim(msg))
    end if
    close (unit)

    deck%eps_r = eps_r; deck%eps_bar = eps_bar; deck%mu_d = mu_d; deck%kn_smooth = kn_smooth
    deck%start = start; deck%x_end = x_end; deck%size_ratio = size_ratio
    deck%rtol = rtol; deck%atol = atol; deck%h_init = h_init; deck%max_steps = max_steps
    deck%t_max = t_max
    deck%csv_file = csv_file; deck%dt_out = dt_out

    ! Ranges (doc/PAIRTRAJ_INPUT.md).
    call require(eps_r >= 0.0_dp .and. eps_r <= 0.5_dp, 'pair', 'eps_r', 'must be in [0, 0.5]')
    call require(eps_bar > 0.0_dp .and. eps_bar <= 1.0_dp, 'pair', 'eps_bar', 'must be in (0, 1]')
    call require(mu_d >= 0.0_dp .and. mu_d <= 10.0_dp, 'pair', 'mu_d', 'must be in [0, 10]')
    call require(kn_smooth > 0.0_dp .and. kn_smooth <= 1.0e15_dp, 'pair', 'kn_smooth', &
                 'must be in (0, 1e15]')
    ! The unequal-sphere scalars are accurate to 1.4e-3 at contact for 0.1 <= lambda <= 10
    ! (doc/RESISTANCE.md "Unequal spheres").
    call require(size_ratio >= 0.1_dp .and. size_ratio <= 10.0_dp, 'pair', 'size_ratio', &
                 'must be in [0.1, 10] (radius of sphere 2 over that of sphere 1)')
    call require(norm2(start) > 1.0_dp + size_ratio + eps_r, 'pair', 'start', &
                 'spheres must start apart: |start| > 1 + size_ratio + eps_r')
    call require(norm2(start) < 1.0e3_dp, 'pair', 'start', '|start| must be < 1000')
    call require(x_end > start(1) .and. x_end < 1.0e3_dp, 'pair', 'x_end', &
                 'must exceed start(1) and be < 1000')
    call require(abs(start(2)) > 0.0_dp .or. abs(start(3)) > 0.0_dp, 'pair', 'start', &
                 'a pair on the flow axis (start(2) = start(3) = 0) never moves')
    call require(rtol >= 1.0e-14_dp .and. rtol <= 1.0e-2_dp, 'integration', 'rtol', &
                 'must be in [1e-14, 1e-2]')
    call require(atol > 0.0_dp .and. atol <= 1.0e-2_dp, 'integration', 'atol', 'must be in (0, 1e-2]')
    call require(h_init > 0.0_dp .and. h_init <= 1.0_dp, 'integration', 'h_init', 'must be in (0, 1]')
    call require(max_steps >= 1, 'integration', 'max_steps', 'must be >= 1')
    call require(t_max > 0.0_dp, 'integration', 't_max', 'must be > 0')
    call require(dt_out >= 0.0_dp, 'output', 'dt_out', 'must be >= 0 (0: every accepted step)')
    call require(len_trim(csv_file) > 0, 'output', 'csv_file', 'must not be empty')

  contains

    subroutine require(ok, group, var, what)
      logical, intent(in) :: ok
      character(len=*), intent(in) :: group, var, what
      if (.not. ok) call deck_fail(path, group, var, what)
    end subroutine require

  end subroutine read_pair_deck

  !> One message naming file, group and variable; exit status 2.
  subroutine deck_fail(path, group, var, what)
    use, intrinsic :: iso_fortran_env, only: error_unit
    character(len=*), intent(in) :: path, group, var, what
    character(len=:), allocatable :: where
    where = 'pairtraj: input error in ' // trim(path)
    if (len_trim(group) > 0) where = where // ', group &' // trim(group)
    if (len_trim(var) > 0) where = where // ', variable ' // trim(var)
    write (error_unit, '(a)') where // ': ' // trim(what)
    stop 2, quiet=.true.
  end subroutine deck_fail

  !> Stop if a line opens a group other than &pair, &integration, &output.
  subroutine check_group_names(unit, path)
    integer, intent(in) :: unit
    character(len=*), intent(in) :: path
    character(len=1024) :: line
    character(len=:), allocatable :: word
    integer :: ios
    rewind (unit)
    do
      read (unit, '(a)', iostat=ios) line
      if (ios /= 0) exit
      word = lower(first_word(strip_comment(line)))
      if (len(word) == 0) cycle
      if (word(1:1) /= '&') cycle
      if (word /= '&pair' .and. word /= '&integration' .and. word /= '&output' .and. word /= '&end') &
        call deck_fail(path, word(2:), '', 'unknown group (known: &pair, &integration, &output)')
    end do
  end subroutine check_group_names

  !> True if a line starting with &group exists; leaves the unit positioned at that line.
  function group_present(unit, group) result(found)
    integer, intent(in) :: unit
    character(len=*), intent(in) :: group
    logical :: found
    character(len=1024) :: line
    integer :: ios
    found = .false.
    rewind (unit)
    do
      read (unit, '(a)', iostat=ios) line
      if (ios /= 0) exit
      if (lower(first_word(line)) == '&' // group) then
        found = .true.
        backspace (unit)
        return
      end if
    end do
  end function group_present

  !> Check the names and the syntax of each value of a group before the namelist read, so that
  !> an error names the variable (the compiler's namelist messages often do not).
  subroutine scan_group(unit, path, group, known)
    integer, intent(in) :: unit
    character(len=*), intent(in) :: path, group
    character(len=*), intent(in) :: known(:)
    character(len=4096) :: text
    character(len=1024) :: line
    character(len=:), allocatable :: item, name, current
    integer :: ios, p, k, q, nvals
    logical :: in_group, in_quote
    real(dp) :: probe
    if (.not. group_present(unit, group)) return
    ! Gather the group's text between '&group' and the closing '/' (outside quotes).
    text = ''
    in_group = .false.
    do
      read (unit, '(a)', iostat=ios) line
      if (ios /= 0) call deck_fail(path, group, '', 'group not closed by /')
      line = strip_comment(line)
      if (.not. in_group) then
        p = index(lower(line), '&' // group)
        line = line(p + len(group) + 1:)
        in_group = .true.
      end if
      p = closing_slash(line)
      if (p > 0) then
        text = trim(text) // ' ' // line(:p - 1)
        exit
      end if
      text = trim(text) // ' ' // line
    end do
    ! Split into items at commas and blanks outside quotes; a token "name=" starts a variable.
    current = ''
    nvals = 0
    k = 1
    do while (k <= len_trim(text))
      ! next item
      do while (k <= len_trim(text) .and. (text(k:k) == ' ' .or. text(k:k) == ','))
        k = k + 1
      end do
      if (k > len_trim(text)) exit
      q = k
      in_quote = .false.
      do while (q <= len_trim(text))
        if (text(q:q) == "'" .or. text(q:q) == '"') in_quote = .not. in_quote
        if (.not. in_quote .and. (text(q:q) == ',' .or. text(q:q) == ' ' .or. text(q:q) == '=')) exit
        q = q + 1
      end do
      item = text(k:q - 1)
      ! Is it followed (possibly after blanks) by '='?
      p = q
      do while (p <= len_trim(text) .and. text(p:p) == ' ')
        p = p + 1
      end do
      if (p <= len_trim(text) .and. text(p:p) == '=') then
        name = lower(item)
        if (index(name, '(') > 0) name = name(:index(name, '(') - 1)
        if (.not. any(known == name)) call deck_fail(path, group, name, 'unknown variable (known: ' &
                                                     // join(known) // ')')
        current = name
        nvals = 0
        k = p + 1
        cycle
      end if
      nvals = nvals + 1
      if (nvals > merge(3, 1, current == 'start')) &
        call deck_fail(path, group, current, 'too many values ("' // item // '")')
      if (len(current) == 0) call deck_fail(path, group, '', 'value "' // item // '" without a variable name')
      ! Value syntax check by type.
      select case (current)
      case ('csv_file')
        if (item(1:1) /= "'" .and. item(1:1) /= '"') call deck_fail(path, group, current, &
          'expects a quoted string, got ' // item)
      case ('max_steps')
        read (item, *, iostat=ios) p
        if (ios /= 0 .or. verify(item, '+-0123456789') /= 0) call deck_fail(path, group, current, &
          'expects an integer, got "' // item // '"')
      case default
        read (item, *, iostat=ios) probe
        if (ios /= 0 .or. verify(lower(item), '+-0123456789.ed') /= 0) call deck_fail(path, group, &
          current, 'expects a real number, got "' // item // '"')
      end select
      k = q
    end do
  end subroutine scan_group

  pure function first_word(line) result(w)
    character(len=*), intent(in) :: line
    character(len=:), allocatable :: w
    integer :: e
    w = adjustl(line)
    e = scan(w, ' ,')
    if (e > 0) w = w(:e - 1)
    w = trim(w)
  end function first_word

  pure function strip_comment(line) result(s)
    character(len=*), intent(in) :: line
    character(len=len(line)) :: s
    integer :: i
    logical :: in_quote
    s = line
    in_quote = .false.
    do i = 1, len(line)
      if (line(i:i) == "'" .or. line(i:i) == '"') in_quote = .not. in_quote
      if (line(i:i) == '!' .and. .not. in_quote) then
        s = line(:i - 1)
        return
      end if
    end do
  end function strip_comment

  pure integer function closing_slash(line)
    character(len=*), intent(in) :: line
    integer :: i
    logical :: in_quote
    in_quote = .false.
    closing_slash = 0
    do i = 1, len_trim(line)
      if (line(i:i) == "'" .or. line(i:i) == '"') in_quote = .not. in_quote
      if (line(i:i) == '/' .and. .not. in_quote) then
        closing_slash = i
        return
      end if
    end do
  end function closing_slash

  pure function lower(s) result(t)
    character(len=*), intent(in) :: s
    character(len=len(s)) :: t
    integer :: i
    t = s
    do i = 1, len(s)
      if (s(i:i) >= 'A' .and. s(i:i) <= 'Z') t(i:i) = achar(iachar(s(i:i)) + 32)
    end do
  end function lower

  pure function join(names) result(s)
    character(len=*), intent(in) :: names(:)
    character(len=:), allocatable :: s
    integer :: i
    s = trim(names(1))
    do i = 2, size(names)
      s = s // ', ' // trim(names(i))
    end do
  end function join

end module mod_pair_deck
