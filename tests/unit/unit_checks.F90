! Pass/fail bookkeeping shared by the unit tests (tests/unit/test_*.F90): counters of the checks
! made and failed, the two kinds of check they make, and the exit status tests/run_tests.sh reads:
! a test passes only when it made at least one check and none failed.
module mod_unit_checks
  use mod_kinds, only: dp
  implicit none
  private
  public :: failures, checks, check, check_below, fail, finish, min_eig

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
