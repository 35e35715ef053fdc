! Findings of the limit checks: a model's limit on the time step or its parameters, measured, is
! checked beside the physics it guards (mod_contact for the contacts, mod_fictitious_domain for the
! lag of Lambda and the stresslets), and the check returns what it found instead of printing or
! stopping, so that the kernels stay free of I/O and the program reports every finding through
! its one error path: a warning, or the deck item refused.
module mod_limits
  implicit none
  private
  public :: limit_finding_t, add_finding, LIMIT_WARN, LIMIT_REFUSE

  integer, parameter :: LIMIT_WARN = 1        ! the run goes on, with a warning
  integer, parameter :: LIMIT_REFUSE = 2      ! the deck is refused at the item named

  type :: limit_finding_t
    integer :: level = LIMIT_WARN
    character(len=16) :: group = ''           ! the deck item at fault (&group key), for a refusal
    character(len=16) :: key = ''
    character(len=800) :: text = ''
  end type limit_finding_t

contains

  ! Append one finding (group, key: the deck item a refusal names).
  pure subroutine add_finding(findings, level, text, group, key)
    type(limit_finding_t), allocatable, intent(inout) :: findings(:)
    integer, intent(in) :: level
    character(len=*), intent(in) :: text
    character(len=*), intent(in), optional :: group, key
    type(limit_finding_t) :: f
    f%level = level
    f%text = text
    if (present(group)) f%group = group
    if (present(key)) f%key = key
    if (.not. allocated(findings)) allocate(findings(0))
    findings = [findings, f]
  end subroutine add_finding

end module mod_limits
