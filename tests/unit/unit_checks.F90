! Pass/fail bookkeeping shared by the unit tests (tests/unit/test_*.F90): one counter of failed
! checks, the two kinds of check they make, and the exit status tests/run_tests.sh reads.
module mod_unit_checks
  use mod_kinds, only: dp
  implicit none
  private
  public :: failures, check, check_below, fail, finish

  !> failed checks so far (a test may also count its own failures here)
  integer :: failures = 0

contains

  !> A property that holds or does not.
  subroutine check(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
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
    print '(a,a,a,es10.3,a,es9.2,a)', merge('  ok    ', '  FAIL  ', ok), what, ': ', value, ' (tol ', tol, ')'
    if (.not. ok) failures = failures + 1
  end subroutine check_below

  !> The verdict: a failed test exits with status 1.
  subroutine finish(name)
    character(len=*), intent(in) :: name
    if (failures > 0) then
      print '(a,a,i0,a)', name, ': ', failures, ' check(s) FAILED'
      error stop 1
    end if
    print '(2a)', name, ': all checks passed'
  end subroutine finish
end module mod_unit_checks
