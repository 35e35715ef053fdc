! The imposed shear as a function of time: the rheometer's protocols of doc/INPUT.md "&shear" under
! rate control (doc/RHEOLOGY.md "Protocols"). The rate of a step is evaluated once, at the time
! t_n at which the step's forces are evaluated (the start of the step, the configuration X^n), and
! held over the step; the strain is integrated exactly over the step.
!   steady       gamma_dot(t) = rate                       strain(t) = rate t
!   reversal     gamma_dot = +-|rate|, the sign (that of rate at the start) flipping each time the
!                accumulated |strain| reaches a multiple of reversal_strain G; the flip happens at the
!                first step boundary at which it has (within 1e-9 of a step's strain, so that a G of
!                whole steps flips after exactly G/(|rate| dt) steps despite round-off)
!   oscillatory  gamma(t) = gamma_0 sin(omega t), gamma_dot(t) = gamma_0 omega cos(omega t),
!                omega = 2 pi/T; the strain is gamma(t) itself, evaluated, not summed
!   steps        piecewise constant: level k (rate, or stress under stress control) from the time or
!                the accumulated |strain| step_at(k) on (step_at(1) = 0); a level starts at the first
!                step boundary at which it is due (within 1e-9 of a step, as a reversal)
! Stress control (control = 'stress', doc/INPUT.md "&shear", doc/METHOD.md §7.4): the rate of a
! step is not a function of time but the solution of the step's stress balance, which the step
! solves and sets here (shear_protocol_set_rate) before the strain is integrated with it; until
! then p%rate holds the last step's rate (the one the previous velocities went with). The target
! stress of a step is the protocol's function of time, evaluated at t_n as the rate is:
!   steady       S
!   reversal     +-|S|, the sign (that of S at the start) flipping each time the accumulated
!                |strain| reaches a multiple of G, as under rate control
!   oscillatory  S sin(omega t_n), omega = 2 pi/T (S the amplitude); the strain is integrated
!   steps        the level of the step
! The reference rate (the unit of time and of stress, doc/INPUT.md "&shear") is rate (steady,
! reversal: signed, as given; any protocol under stress control) or gamma_0 omega (oscillatory
! under rate control): the rate at t = 0 in every rate-controlled protocol.
! The state (time, strain, accumulated |strain|, sign, reversals) is what a checkpoint holds
! (shear_protocol_state / shear_protocol_restore): a restart continues it exactly. A branch starts
! the protocol afresh from the checkpoint's configuration (shear_protocol_begin_at): its time,
! accumulated |strain| and reversals from zero, its strain from the strain reached (the origin), so
! that a reversal or an oscillation can follow a steady pre-shear.
module mod_shear_protocol
  use mod_kinds, only: dp, pi
  use mod_columns, only: column_t, column
  implicit none
  private
  public :: shear_protocol_t, shear_protocol_create, shear_protocol_begin_step, shear_protocol_end_step, &
            shear_protocol_varies, shear_protocol_state, shear_protocol_restore, shear_protocol_columns, &
            shear_protocol_kind, shear_protocol_reference_rate, shear_protocol_begin_at, shear_protocol_set_rate
  public :: PROTOCOL_STEADY, PROTOCOL_REVERSAL, PROTOCOL_OSCILLATORY, PROTOCOL_STEPS, PROTOCOL_STATE_SIZE
  public :: CONTROL_RATE, CONTROL_STRESS, MAX_LEVELS

  integer, parameter :: PROTOCOL_STEADY = 1, PROTOCOL_REVERSAL = 2, PROTOCOL_OSCILLATORY = 3, PROTOCOL_STEPS = 4
  integer, parameter :: MAX_LEVELS = 20
  integer, parameter :: PROTOCOL_STATE_SIZE = 7
  integer, parameter :: CONTROL_RATE = 1, CONTROL_STRESS = 2
  ! a reversal is due when the accumulated |strain| is within this share of one step's strain of it
  real(dp), parameter :: reversal_slack = 1.0e-9_dp

  type :: shear_protocol_t
    integer :: kind = PROTOCOL_STEADY
    integer :: control = CONTROL_RATE
    real(dp) :: stress = 0.0_dp           ! stress control: the target mean shear stress of the step [eta gamma_dot]
    real(dp) :: stress_given = 0.0_dp     ! stress control: &shear stress (steady, reversal: signed; oscillatory: the amplitude)
    real(dp) :: reference_rate = 1.0_dp   ! signed; the rate at t = 0 [gamma_dot]
    real(dp) :: reversal_strain = 0.0_dp  ! G [-]
    real(dp) :: strain_amplitude = 0.0_dp ! gamma_0 [-]
    real(dp) :: period = 0.0_dp           ! T [1/gamma_dot]
    ! steps: the levels (rates, or stresses under stress control), from step_at(k) on (times or
    ! accumulated |strain|s, by_strain)
    integer :: levels = 0
    real(dp) :: step_at(MAX_LEVELS) = 0.0_dp, step_level(MAX_LEVELS) = 0.0_dp
    logical :: by_strain = .true.
    real(dp) :: dt = 0.0_dp
    ! the state at the start of the next step (t_n), as checkpointed
    real(dp) :: time = 0.0_dp             ! t_n
    real(dp) :: strain = 0.0_dp           ! gamma(t_n): the signed strain imposed since t = 0
    real(dp) :: origin = 0.0_dp           ! the strain at t = 0 (a branch: the strain the checkpoint reached)
    real(dp) :: travel = 0.0_dp           ! the accumulated |strain| since t = 0
    real(dp) :: direction = 1.0_dp        ! +1, or -1 after an odd number of reversals
    integer :: reversals = 0              ! steps: the level of the last step (0 before the first)
    ! the step in progress (shear_protocol_begin_step)
    real(dp) :: rate = 0.0_dp             ! gamma_dot(t_n), held over the step
    real(dp) :: step_strain = 0.0_dp      ! gamma(t_n) of the step (the record's configuration)
    logical :: reversed = .false.         ! the direction flipped (steps: the level changed) at the start of this step
    real(dp) :: step_stress = 0.0_dp      ! stress control: the mean shear stress the step's solve reached
    real(dp) :: advance = 0.0_dp          ! stress control: the rate the step's strain advances at
  end type shear_protocol_t

contains

  !> A protocol of the given kind (PROTOCOL_*): rate is the steady/reversal rate (signed), ignored
  !> for an oscillation, whose reference rate is gamma_0 2 pi/T; dt: the time step. stress
  !> (optional): stress control at this mean shear stress (steady, reversal: signed; oscillatory:
  !> the amplitude; rate is then the reference rate, the unit, and the rate of the first step's
  !> explicit contacts).
  !> step_at, step_level, by_strain (optional): the levels of 'steps' (size: their number).
  pure function shear_protocol_create(kind, rate, dt, reversal_strain, strain_amplitude, period, stress, &
                                      step_at, step_level, by_strain) result(p)
    integer, intent(in) :: kind
    real(dp), intent(in) :: rate, dt, reversal_strain, strain_amplitude, period
    real(dp), intent(in), optional :: stress, step_at(:), step_level(:)
    logical, intent(in), optional :: by_strain
    type(shear_protocol_t) :: p
    p%kind = kind
    if (present(stress)) then
      p%control = CONTROL_STRESS
      p%stress_given = stress
      p%stress = stress
      if (kind == PROTOCOL_OSCILLATORY) p%stress = 0.0_dp
    end if
    if (present(step_at)) then
      p%levels = size(step_at)
      p%step_at(1:p%levels) = step_at
      p%step_level(1:p%levels) = step_level
      p%by_strain = by_strain
      if (p%control == CONTROL_STRESS) p%stress = step_level(1)
    end if
    p%dt = dt
    p%reversal_strain = reversal_strain
    p%strain_amplitude = strain_amplitude
    p%period = period
    if (p%control == CONTROL_STRESS) then
      p%reference_rate = rate
    else
      p%reference_rate = shear_protocol_reference_rate(kind, rate, strain_amplitude, period)
    end if
    p%rate = p%reference_rate
  end function shear_protocol_create

  !> The reference rate of a protocol (the unit): rate, or gamma_0 2 pi/T for an oscillation.
  pure real(dp) function shear_protocol_reference_rate(kind, rate, strain_amplitude, period) result(r)
    integer, intent(in) :: kind
    real(dp), intent(in) :: rate, strain_amplitude, period
    r = rate
    if (kind == PROTOCOL_OSCILLATORY) r = strain_amplitude * (2.0_dp * pi / period)
  end function shear_protocol_reference_rate

  !> PROTOCOL_* of a deck's protocol name ('steady', 'reversal', 'oscillatory', 'steps'); 0 if unknown.
  pure integer function shear_protocol_kind(name) result(kind)
    character(len=*), intent(in) :: name
    select case (trim(name))
    case ('steady');      kind = PROTOCOL_STEADY
    case ('reversal');    kind = PROTOCOL_REVERSAL
    case ('oscillatory'); kind = PROTOCOL_OSCILLATORY
    case ('steps');       kind = PROTOCOL_STEPS
    case default;         kind = 0
    end select
  end function shear_protocol_kind

  !> Does the rate change in time? (A steady protocol leaves every physics object as created.)
  pure logical function shear_protocol_varies(p)
    type(shear_protocol_t), intent(in) :: p
    shear_protocol_varies = p%kind /= PROTOCOL_STEADY .or. p%control == CONTROL_STRESS
  end function shear_protocol_varies

  !> The rate of the step that starts at p%time (t_n): a reversal that is due flips the direction
  !> first (p%reversed tells the caller).
  pure subroutine shear_protocol_begin_step(p)
    type(shear_protocol_t), intent(inout) :: p
    real(dp) :: due
    p%reversed = .false.
    p%step_strain = p%strain
    if (p%kind == PROTOCOL_STEPS) call begin_level(p)
    if (p%kind == PROTOCOL_REVERSAL) then
      due = (p%reversals + 1) * p%reversal_strain - reversal_slack * max(abs(p%rate), abs(p%reference_rate)) * p%dt
      if (p%travel >= due) then
        p%direction = -p%direction
        p%reversals = p%reversals + 1
        p%reversed = .true.
      end if
    end if
    if (p%control == CONTROL_STRESS) then         ! p%rate: the last step's, until the step sets its own
      select case (p%kind)
      case (PROTOCOL_STEADY)
        p%stress = p%stress_given
      case (PROTOCOL_REVERSAL)
        p%stress = p%direction * p%stress_given
      case (PROTOCOL_OSCILLATORY)
        p%stress = p%stress_given * sin(2.0_dp * pi * p%time / p%period)
      end select
      return
    end if
    select case (p%kind)
    case (PROTOCOL_STEADY)
      p%rate = p%reference_rate
    case (PROTOCOL_REVERSAL)
      p%rate = p%direction * p%reference_rate
    case (PROTOCOL_OSCILLATORY)
      p%rate = p%reference_rate * cos(2.0_dp * pi * p%time / p%period)
    case (PROTOCOL_STEPS)
      p%rate = p%step_level(p%reversals)
    end select
  end subroutine shear_protocol_begin_step

  ! steps: the level due at the start of this step (the last whose step_at the time or the
  ! accumulated |strain| has reached, within 1e-9 of a step's), into p%reversals; a change of
  ! level (not the first step's) is a jump of the rate, p%reversed. Under stress control the
  ! level is the target stress.
  pure subroutine begin_level(p)
    type(shear_protocol_t), intent(inout) :: p
    real(dp) :: reached, slack
    integer :: k, level
    if (p%by_strain) then
      reached = p%travel
      slack = reversal_slack * max(abs(p%rate), abs(p%reference_rate)) * p%dt
    else
      reached = p%time
      slack = reversal_slack * p%dt
    end if
    level = 1
    do k = 2, p%levels
      if (reached >= p%step_at(k) - slack) level = k
    end do
    p%reversed = p%reversals /= 0 .and. level /= p%reversals
    p%reversals = level
    if (p%control == CONTROL_STRESS) p%stress = p%step_level(level)
  end subroutine begin_level

  !> Stress control: the rate the step solved for, the mean shear stress it reached with it, and
  !> the rate its strain advances at: the spheres move by Adams-Bashforth, X^{n+1} - X^n =
  !> dt (3/2 U^n - 1/2 U^{n-1}), so the affine part of their motion, and with it the Lees-Edwards
  !> offset, advances at 3/2 gamma_dot^n - 1/2 gamma_dot^{n-1} (gamma_dot^n on a step by forward
  !> Euler); under a rate that jumps from step to step any other offset would shear the pairs
  !> across the boundary against the bulk (doc/METHOD.md §7.4).
  pure subroutine shear_protocol_set_rate(p, rate, stress, advance)
    type(shear_protocol_t), intent(inout) :: p
    real(dp), intent(in) :: rate, stress, advance
    p%rate = rate
    p%step_stress = stress
    p%advance = advance
  end subroutine shear_protocol_set_rate

  !> The end of the step: time t_{n+1}, the strain integrated exactly over the step (the rate is
  !> constant over a step of a steady or reversal protocol; an oscillation of the rate has its
  !> strain gamma(t); under stress control the strain advances with the spheres, p%advance).
  pure subroutine shear_protocol_end_step(p)
    type(shear_protocol_t), intent(inout) :: p
    p%time = p%time + p%dt
    if (p%control == CONTROL_STRESS) then
      p%strain = p%strain + p%advance * p%dt
    else if (p%kind == PROTOCOL_OSCILLATORY) then
      p%strain = p%origin + p%strain_amplitude * sin(2.0_dp * pi * p%time / p%period)
    else
      p%strain = p%strain + p%rate * p%dt
    end if
    if (p%control == CONTROL_STRESS) then
      p%travel = p%travel + abs(p%advance) * p%dt
    else
      p%travel = p%travel + abs(p%rate) * p%dt
    end if
  end subroutine shear_protocol_end_step

  !> The state a checkpoint holds: time, strain, travel, direction, reversals, the last step's rate,
  !> the strain's origin.
  pure function shear_protocol_state(p) result(s)
    type(shear_protocol_t), intent(in) :: p
    real(dp) :: s(PROTOCOL_STATE_SIZE)
    s = [p%time, p%strain, p%travel, p%direction, real(p%reversals, dp), p%rate, p%origin]
  end function shear_protocol_state

  !> Restore the state of shear_protocol_state (a restart).
  pure subroutine shear_protocol_restore(p, s)
    type(shear_protocol_t), intent(inout) :: p
    real(dp), intent(in) :: s(PROTOCOL_STATE_SIZE)
    p%time = s(1)
    p%strain = s(2)
    p%travel = s(3)
    p%direction = s(4)
    p%reversals = nint(s(5))
    p%rate = s(6)
    p%origin = s(7)
    p%step_strain = p%strain
  end subroutine shear_protocol_restore

  !> A branch: the protocol starts afresh (time 0, no accumulated |strain|, no reversal, the first
  !> direction) from the strain the checkpoint's configuration reached.
  pure subroutine shear_protocol_begin_at(p, strain)
    type(shear_protocol_t), intent(inout) :: p
    real(dp), intent(in) :: strain
    p%time = 0.0_dp
    p%origin = strain
    p%strain = strain
    p%step_strain = strain
    p%travel = 0.0_dp
    p%direction = 1.0_dp
    p%reversals = 0
    ! stress control keeps the rate the configuration was reached with (its explicit contacts')
    if (p%control == CONTROL_RATE) p%rate = p%reference_rate
  end subroutine shear_protocol_begin_at

  !> The protocol's columns of the series (doc/RHEOLOGY.md "Protocols"): the imposed rate of the
  !> step the record's statistics were sampled in, and the strain gamma(t_n) of that configuration;
  !> under stress control the rate is the one the step solved for, and shear/stress the mean shear
  !> stress it reached (the target to round-off).
  function shear_protocol_columns(p) result(c)
    type(shear_protocol_t), intent(in) :: p
    type(column_t), allocatable :: c(:)
    ! element by element: an array constructor of column_t leaks their values (gfortran 12)
    allocate(c(merge(3, 2, p%control == CONTROL_STRESS)))
    c(1) = column('shear/rate', p%rate)
    c(2) = column('shear/strain', p%step_strain)
    if (p%control == CONTROL_STRESS) c(3) = column('shear/stress', p%step_stress)
  end function shear_protocol_columns

end module mod_shear_protocol
