! Text of namelist decks, shared by every program's deck reader (mod_params for fdsusp,
! mod_packing_deck for fdsusp-pack): loading the lines, finding the groups, and the diagnosis of a
! failed namelist read, which names the variable and the line at fault (the compiler's message
! does not name the variable reliably).
module mod_deck_text
  use mod_errors, only: input_error
  implicit none
  private
  public :: deck_line_length, load_lines, group_on_line, to_lower, diagnose_group, group_reader, &
            qualified_names, unqualified_names, plain_echo_line

  integer, parameter :: deck_line_length = 1024
  integer, parameter :: max_line = deck_line_length

  abstract interface
    ! Read one group from src (lines of a deck, closed by '/') into a scratch configuration.
    subroutine group_reader(src, ios, msg)
      character(len=*), intent(in) :: src(:)
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: msg
    end subroutine group_reader
  end interface

contains

  ! The lines of the deck, plus one empty line; a missing or unreadable deck stops the run.
  subroutine load_lines(deck, lines)
    character(len=*), intent(in) :: deck
    character(len=max_line), allocatable, intent(out) :: lines(:)
    character(len=max_line) :: buf
    character(len=256) :: msg
    integer :: unit, ios, n
    logical :: exists

    inquire(file=deck, exist=exists)
    if (.not. exists) call input_error(deck, '', '', 'the deck does not exist')
    open(newunit=unit, file=deck, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) call input_error(deck, '', '', 'cannot open the deck: '//trim(msg))
    n = 0
    do
      read(unit, '(a)', iostat=ios) buf
      if (ios /= 0) exit
      n = n + 1
    end do
    allocate(lines(n + 1))
    rewind(unit)
    do n = 1, size(lines) - 1
      read(unit, '(a)', iostat=ios, iomsg=msg) lines(n)
      if (ios /= 0) call input_error(deck, '', '', 'cannot read the deck: '//trim(msg))
    end do
    close(unit)
    lines(size(lines)) = ''
  end subroutine load_lines

  ! The group name if the line opens a namelist group ('&name'), else ''.
  function group_on_line(line) result(name)
    character(len=*), intent(in) :: line
    character(len=64) :: name
    character(len=max_line) :: s
    integer :: e
    name = ''
    s = adjustl(line)
    if (s(1:1) /= '&' .and. s(1:1) /= '$') return
    e = scan(s(2:), ' ,!/') 
    if (e == 0) e = len_trim(s)
    name = to_lower(s(2:e))
  end function group_on_line

  function to_lower(s) result(t)
    character(len=*), intent(in) :: s
    character(len=len(s)) :: t
    integer :: i
    t = s
    do i = 1, len(s)
      if (s(i:i) >= 'A' .and. s(i:i) <= 'Z') t(i:i) = achar(iachar(s(i:i)) + 32)
    end do
  end function to_lower

  ! The group that starts at line first failed to read: read ever longer prefixes of it (each
  ! closed by '/') until one fails; that line holds the bad item. Stops the run with one message
  ! naming the file, the group, the variable and the line.
  subroutine diagnose_group(deck, group, lines, first, reader)
    character(len=*), intent(in) :: deck, group
    character(len=*), intent(in) :: lines(:)
    integer, intent(in) :: first
    procedure(group_reader) :: reader
    character(len=max_line), allocatable :: prefix(:)
    character(len=512) :: msg
    character(len=16) :: lnum
    integer :: ios, k
    msg = ''
    do k = first, size(lines)
      prefix = [character(len=max_line) :: lines(first:k), '/']
      call reader(prefix, ios, msg)
      if (ios /= 0) exit
    end do
    k = min(k, size(lines))
    write(lnum, '(i0)') k
    call input_error(deck, group, item_name(lines(k), msg), trim(explain(lines(k), msg))// &
         ' (line '//trim(lnum)//': "'//trim(adjustl(lines(k)))//'")')
  end subroutine diagnose_group

  ! The variable a failed read is about: from the compiler's message if it names it, else the
  ! name before '=' on the line at fault.
  function item_name(line, msg) result(name)
    character(len=*), intent(in) :: line, msg
    character(len=128) :: name
    character(len=*), parameter :: unknown = 'Cannot match namelist object name'
    integer :: p
    p = index(msg, unknown)
    if (p > 0) then
      name = to_lower(adjustl(msg(p + len(unknown):)))
      ! A value the compiler could not read may be taken for a name ("steps = 'many'"): then
      ! the item is the variable the value was given to.
      if (.not. follows_equals(to_lower(line), trim(name))) return
      name = variable_before(to_lower(line), index(to_lower(line), trim(name)))
      return
    end if
    name = variable_before(to_lower(line), len_trim(line) + 1)
  end function item_name

  ! True if token stands on the line as (part of) a value: right after an '=' (spaces and
  ! quotes skipped), or glued to the characters before it.
  logical function follows_equals(line, token)
    character(len=*), intent(in) :: line, token
    integer :: p, q
    follows_equals = .false.
    p = index(line, token)
    if (p == 0) return
    q = p - 1
    ! glued to what precedes it ("1e-3x"): part of a value
    if (q > 0) then
      if (scan(line(q:q), ' ,''"') == 0) then
        follows_equals = .true.
        return
      end if
    end if
    do while (q > 0)
      if (scan(line(q:q), ' ''"') == 0) exit
      q = q - 1
    end do
    follows_equals = (q > 0 .and. line(q:q) == '=')
  end function follows_equals

  ! The name before the last '=' that comes before position last on the line.
  function variable_before(line, last) result(name)
    character(len=*), intent(in) :: line
    integer, intent(in) :: last
    character(len=128) :: name
    character(len=max_line) :: s
    integer :: e, b
    name = '?'
    e = index(line(1:last - 1), '=', back=.true.)
    if (e <= 1) return
    s = line(1:e - 1)
    ! an array section "velocity(:,1)" holds separators of its own: cut it off first
    if (len_trim(s) > 0) then
      if (s(len_trim(s):len_trim(s)) == ')') then
        b = index(s, '(', back=.true.)
        if (b > 1) s = s(1:b - 1)
      end if
    end if
    b = scan(trim(s), ' ,&', back=.true.)
    name = adjustl(s(b + 1:))
  end function variable_before

  function explain(line, msg) result(text)
    character(len=*), intent(in) :: line, msg
    character(len=:), allocatable :: text
    character(len=*), parameter :: unknown = 'Cannot match namelist object name'
    integer :: p
    p = index(msg, unknown)
    text = 'cannot read its value: '//trim(msg)
    if (p > 0) then
      if (.not. follows_equals(to_lower(line), trim(to_lower(adjustl(msg(p + len(unknown):)))))) &
        text = 'unknown variable in this group (see doc/INPUT.md)'
    end if
  end function explain

  ! The lines of a group with each variable name qualified by OBJECT ('dt = 1e-3' becomes
  ! 'time_group%dt = 1e-3'): the reading of a namelist whose object is a derived type (mod_params)
  ! wants the components so. A name is an identifier followed, after an optional subscript, by
  ! '='; quoted strings, comments and the '&group' line itself are left as they are.
  function qualified_names(lines, object) result(out)
    character(len=*), intent(in) :: lines(:), object
    character(len=max_line), allocatable :: out(:)
    integer :: l
    allocate(out(size(lines)))
    do l = 1, size(lines)
      out(l) = qualified_line(lines(l), object)
    end do
  end function qualified_names

  function qualified_line(line, object) result(out)
    character(len=*), intent(in) :: line, object
    character(len=max_line) :: out
    character(len=1) :: quote, c
    integer :: i, j, n
    out = ''
    n = 0
    quote = ' '
    i = 1
    do while (i <= len_trim(line))
      c = line(i:i)
      if (quote /= ' ') then
        if (c == quote) quote = ' '
      else if (c == '''' .or. c == '"') then
        quote = c
      else if (c == '!') then
        out(n + 1:) = line(i:)
        return
      else if (starts_name(line, i)) then
        j = i
        do while (j < len_trim(line))
          if (.not. is_name_char(line(j + 1:j + 1))) exit
          j = j + 1
        end do
        if (assigned_to(line, j + 1)) then
          out(n + 1:) = object//'%'
          n = n + len(object) + 1
        end if
        out(n + 1:n + j - i + 1) = line(i:j)
        n = n + j - i + 1
        i = j + 1
        cycle
      end if
      out(n + 1:n + 1) = c
      n = n + 1
      i = i + 1
    end do
  end function qualified_line

  ! An identifier begins at position i: a letter not glued to a name or a number and not after a
  ! '.' (logicals), a '%' or the '&' of the group line.
  logical function starts_name(line, i)
    character(len=*), intent(in) :: line
    integer, intent(in) :: i
    character(len=1) :: c
    c = to_lower(line(i:i))
    starts_name = c >= 'a' .and. c <= 'z'
    if (.not. starts_name .or. i == 1) return
    starts_name = .not. (is_name_char(line(i - 1:i - 1)) .or. scan(line(i - 1:i - 1), '.%&$') > 0)
  end function starts_name

  logical function is_name_char(c)
    character(len=1), intent(in) :: c
    is_name_char = scan(to_lower(c), 'abcdefghijklmnopqrstuvwxyz0123456789_') > 0
  end function is_name_char

  ! From position k on: spaces, an optional '(...)' subscript, spaces, then '='.
  logical function assigned_to(line, k)
    character(len=*), intent(in) :: line
    integer, intent(in) :: k
    integer :: i, depth
    assigned_to = .false.
    i = skip_spaces(line, k)
    if (i > len_trim(line)) return
    if (line(i:i) == '(') then
      depth = 0
      do while (i <= len_trim(line))
        if (line(i:i) == '(') depth = depth + 1
        if (line(i:i) == ')') depth = depth - 1
        i = i + 1
        if (depth == 0) exit
      end do
      i = skip_spaces(line, i)
      if (i > len_trim(line)) return
    end if
    assigned_to = line(i:i) == '='
  end function assigned_to

  integer function skip_spaces(line, k) result(i)
    character(len=*), intent(in) :: line
    integer, intent(in) :: k
    i = k
    do while (i <= len_trim(line))
      if (line(i:i) /= ' ') exit
      i = i + 1
    end do
  end function skip_spaces

  ! A line of a namelist the compiler wrote for a derived-type object, as a deck has it: the
  ! object's qualifier dropped (' TIME_GROUP%DT= 1.0' becomes ' DT= 1.0') and the padding of a
  ! quoted character value removed.
  function plain_echo_line(line) result(out)
    character(len=*), intent(in) :: line
    character(len=len(line)) :: out
    integer :: e, p, q1, q2
    out = line
    e = index(out, '=')
    p = index(out(1:max(e, 1)), '%')
    if (out(1:1) == ' ' .and. p > 0) out = ' '//out(p + 1:)
    q1 = index(out, '"')
    q2 = index(out, '"', back=.true.)
    if (q1 > 0 .and. q2 > q1) out = out(1:q1)//trim(out(q1 + 1:q2 - 1))//out(q2:)
  end function plain_echo_line

  ! A compiler message about a qualified read with the qualifier removed: 'object%name' and
  ! '%name' become 'name', as the deck has it.
  function unqualified_names(msg, object) result(out)
    character(len=*), intent(in) :: msg, object
    character(len=len(msg)) :: out
    integer :: p
    out = msg
    do
      p = index(to_lower(out), to_lower(object)//'%')
      if (p == 0) exit
      out = out(1:p - 1)//out(p + len(object) + 1:)
    end do
    do
      p = index(out, '%')
      if (p == 0) exit
      out = out(1:p - 1)//out(p + 1:)
    end do
  end function unqualified_names

end module mod_deck_text
