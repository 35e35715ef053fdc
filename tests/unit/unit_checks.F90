! Pass/fail bookkeeping shared by the unit tests (tests/unit/test_*.F90): counters of the checks
! made and failed, the two kinds of check they make, and the exit status tests/run_tests.sh reads:
! a test passes only when it made at least one check and none failed. Also: a part of a test run in
! a child process on the other core (beside, end_beside, collect_beside).
module mod_unit_checks
  use mod_kinds, only: dp
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
  use, intrinsic :: iso_fortran_env, only: output_unit
  implicit none
  private
  public :: failures, checks, check, check_below, fail, finish, min_eig
  public :: beside_t, beside, end_beside, collect_beside

  !> A part of a test running in a child process: its pid (< 0: none) and the file of its output.
  type :: beside_t
    integer(c_int) :: pid = -1
    character(len=4096) :: log = ''
  end type beside_t

  interface
    integer(c_int) function c_fork() bind(C, name='fork')
      import :: c_int
    end function c_fork
    integer(c_int) function c_getpid() bind(C, name='getpid')
      import :: c_int
    end function c_getpid
    integer(c_int) function c_waitpid(p, wstatus, options) bind(C, name='waitpid')
      import :: c_int
      integer(c_int), value :: p, options
      integer(c_int), intent(out) :: wstatus
    end function c_waitpid
    integer(c_int) function c_creat(path, mode) bind(C, name='creat')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int), value :: mode
    end function c_creat
    integer(c_int) function c_dup2(old, new) bind(C, name='dup2')
      import :: c_int
      integer(c_int), value :: old, new
    end function c_dup2
  end interface

  !> failed checks so far (a test may also count its own failures here)
  integer :: failures = 0
  !> checks made so far
  integer :: checks = 0

contains

  !> A property that holds or does not.
  subroutine check(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    checks = checks + 1
    if (ok) then
      print '(2a)', '  ok    ', what
    else
      print '(2a)', '  FAIL  ', what
      failures = failures + 1
    end if
  end subroutine check

  !> A failure found by the test's own logic.
  subroutine fail(what)
    character(len=*), intent(in) :: what
    call check(.false., what)
  end subroutine fail

  !> A measured error against its tolerance (passes when value <= tol).
  subroutine check_below(what, value, tol)
    character(len=*), intent(in) :: what
    real(dp), intent(in) :: value, tol
    logical :: ok
    ok = value <= tol                   ! false for NaN
    checks = checks + 1
    print '(a,a,a,es10.3,a,es9.2,a)', merge('  ok    ', '  FAIL  ', ok), what, ': ', value, ' (tol ', tol, ')'
    if (.not. ok) failures = failures + 1
  end subroutine check_below

  !> The verdict: a test that failed a check, or made none, exits with status 1.
  subroutine finish(name)
    character(len=*), intent(in) :: name
    if (failures > 0) then
      print '(a,a,i0,a)', name, ': ', failures, ' check(s) FAILED'
      error stop 1
    end if
    if (checks == 0) then
      print '(2a)', name, ': FAIL  the test made no checks'
      error stop 1
    end if
    print '(a,a,i0,a)', name, ': all ', checks, ' checks passed'
  end subroutine finish
  !> Fork a child process to run an independent part of the test on the other core (the suite runs
  !> one test at a time on 2 cores): true in the child, whose output then goes to a file (TMPDIR,
  !> else /tmp), which runs the part and calls end_beside; false in the caller, which goes on and
  !> calls collect_beside where the part's output belongs. Where fork fails, false with no child:
  !> collect_beside then returns false and the caller runs the part itself.
  logical function beside(child)
    type(beside_t), intent(out) :: child
    integer :: k
    integer(c_int) :: fd
    call get_environment_variable('TMPDIR', child%log, status=k)
    if (k /= 0 .or. len_trim(child%log) == 0) child%log = '/tmp'
    write(child%log, '(2a,i0,a)') trim(child%log), '/unit_checks_beside.', c_getpid(), '.log'
    flush(output_unit)
    child%pid = c_fork()
    beside = child%pid == 0
    if (beside) then
      fd = c_creat(trim(child%log)//c_null_char, 384_c_int)        ! mode 0600
      if (fd < 0) call exit(2)
      if (c_dup2(fd, 1_c_int) < 0) call exit(2)
    end if
  end function beside

  !> The end of the child's part: its output flushed, exit status 0 (its checks are counted from
  !> its output by collect_beside; a part that stops with error stop exits non-zero).
  subroutine end_beside()
    flush(output_unit)
    call exit(0)
  end subroutine end_beside

  !> Wait for the child, print its output and count its checks (lines '  ok    ', '  FAIL  ') with
  !> the caller's; a child that did not end with status 0 fails the test. False when there was no
  !> child (fork failed): the caller runs the part itself.
  logical function collect_beside(child)
    type(beside_t), intent(in) :: child
    integer :: u, ios
    integer(c_int) :: waited, wstatus
    character(len=1000) :: line
    collect_beside = child%pid > 0
    if (.not. collect_beside) return
    waited = c_waitpid(child%pid, wstatus, 0_c_int)
    open(newunit=u, file=trim(child%log), status='old', action='read', iostat=ios)
    if (ios /= 0) then
      call fail('the child process left no output ('//trim(child%log)//')')
      return
    end if
    do
      read(u, '(a)', iostat=ios) line
      if (ios /= 0) exit
      print '(a)', trim(line)
      if (line(1:8) == '  ok    ') checks = checks + 1
      if (line(1:8) == '  FAIL  ') then
        checks = checks + 1
        failures = failures + 1
      end if
    end do
    close(u, status='delete')
    if (waited /= child%pid .or. wstatus /= 0) call fail('the child process did not end normally')
  end function collect_beside

  !> The smallest eigenvalue of a symmetric matrix (LAPACK dsyev), for the tests' definiteness checks.
  real(dp) function min_eig(m)
    real(dp), intent(in) :: m(:, :)
    real(dp) :: v(size(m, 1), size(m, 1)), ev(size(m, 1)), work(64 * size(m, 1))
    integer :: info
    external :: dsyev
    v = m
    call dsyev('N', 'U', size(m, 1), v, size(m, 1), ev, work, size(work), info)
    min_eig = ev(1)
  end function min_eig

end module mod_unit_checks
