! Invariants of the imposed shear in time (mod_shear_protocol, doc/INPUT.md "&shear"):
!  1. steady: the rate of every step is the deck's rate, exactly; the strain is the sum of rate dt;
!  2. reversal with G a whole number of steps' strain (G = 0.1, |rate| dt = 1e-3, rate -2 with
!     dt 5e-4): the direction flips at the start of steps 100, 200, 300 and at no other, despite the
!     round-off of the summed |strain| (the 1e-9 slack of a step); the rate keeps its magnitude, the
!     first segment has the sign of the deck's rate, the strain is the triangle wave between 0 and
!     -G (|gamma - triangle| < 1e-12: a sum of 400 steps of 1e-3), p%reversed marks the flip steps;
!  3. oscillatory: the rate of the step from t_n is gamma_0 omega cos(omega t_n) and the strain
!     after it gamma_0 sin(omega t_{n+1}) (to 1e-15: the same formula evaluated), the reference rate
!     is gamma_0 omega, and the strain is the integral of the rate over the steps to O(dt^2) per
!     period (the rate is held at its t_n value over a step: the sum of rate dt differs from
!     gamma(t) by at most gamma_0 omega^2 dt^2 / 2 per step, bound checked at T/4);
!  4. the state of shear_protocol_state restores exactly: a protocol restored half way continues
!     bitwise as the uninterrupted one (the restart of a run);
!  5. steps by strain (rates 1, -2, 0.5 from accumulated |strain| 0, 0.01, 0.05; dt 1e-3): the level
!     changes at the start of steps 10 and 30 (0.01 = 10 x 1e-3, 0.04 more = 20 x 2e-3) and at no
!     other, p%reversed marks exactly those, the rate is the level; by time (levels from t = 0 and
!     0.0125): the change at the first step boundary past it, step 13; a state restored after a
!     change continues without a spurious jump;
!  6. stress control: the step begins with the last step's rate, the target is the stress (or the
!     level of stress steps), and the strain advances with the rate set_rate gives to advance;
!  7. stress reversal (S = -3, G = 0.05, the solved rate 0.5 in magnitude, dt 1e-3: 100 steps per
!     segment): the target is -3 until the accumulated |strain| reaches G, then +3, -3, ...,
!     flipping at the start of steps 100, 200, 300 and no other (as the rate under rate control,
!     the same 1e-9 slack), p%reversed marks them; the reference rate (the unit) is the deck's
!     rate, not derived from the stress;
!  8. stress oscillation (amplitude 2, T = 0.8, dt 1e-3): the target of the step from t_n is
!     2 sin(2 pi t_n/T) with t_n = n dt (to 1e-12: the protocol sums its time step by step, n
!     round-offs of t ~ 1e-16 each, times the slope 2 x 2 pi/T), the reference rate is the deck's rate, and the
!     strain is the sum of the advance rates (not gamma_0 sin: to 1e-15 against the sum); a state
!     restored half way continues bitwise.
program test_shear_protocol
  use mod_kinds, only: dp, pi
  use mod_shear_protocol, only: shear_protocol_t, shear_protocol_create, shear_protocol_begin_step, &
                                shear_protocol_end_step, shear_protocol_state, shear_protocol_restore, &
                                shear_protocol_kind, shear_protocol_varies, PROTOCOL_STEADY, PROTOCOL_REVERSAL, &
                                PROTOCOL_OSCILLATORY, PROTOCOL_STEPS, shear_protocol_set_rate
  use mod_unit_checks, only: check, check_below, finish
  implicit none
  type(shear_protocol_t) :: p, q
  integer :: n, flips
  logical :: all_rates, all_flips, restored_same
  real(dp) :: worst, summed, omega, gamma_0, period, dt, triangle
  integer, allocatable :: flip_steps(:), changes(:)

  ! 1. steady
  p = shear_protocol_create(PROTOCOL_STEADY, 0.7_dp, 1.0e-3_dp, 0.0_dp, 0.0_dp, 0.0_dp)
  all_rates = .true.
  do n = 0, 99
    call shear_protocol_begin_step(p)
    all_rates = all_rates .and. p%rate == 0.7_dp .and. .not. p%reversed
    call shear_protocol_end_step(p)
  end do
  call check(all_rates .and. .not. shear_protocol_varies(p), 'steady: every step at the deck''s rate, exactly')
  call check_below('steady: strain = rate t', abs(p%strain - 0.07_dp), 1.0e-14_dp)
  call check(shear_protocol_kind('steady') == PROTOCOL_STEADY .and. shear_protocol_kind('reversal') == PROTOCOL_REVERSAL &
             .and. shear_protocol_kind('oscillatory') == PROTOCOL_OSCILLATORY .and. shear_protocol_kind('step') == 0, &
             'the deck''s protocol names')

  ! 2. reversal every 0.1 of strain, rate -2, dt 5e-4: 100 steps per segment
  p = shear_protocol_create(PROTOCOL_REVERSAL, -2.0_dp, 5.0e-4_dp, 0.1_dp, 0.0_dp, 0.0_dp)
  allocate(flip_steps(0))
  all_rates = .true.
  worst = 0.0_dp
  do n = 0, 399
    call shear_protocol_begin_step(p)
    if (p%reversed) flip_steps = [flip_steps, n]
    all_rates = all_rates .and. abs(p%rate) == 2.0_dp
    if (n < 100) all_rates = all_rates .and. p%rate < 0.0_dp
    call shear_protocol_end_step(p)
    ! the triangle wave: from 0 to -0.1 (the deck's direction), back to 0, ... in steps of 1e-3
    triangle = -1.0e-3_dp * real(triangle_steps(n + 1), dp)
    worst = max(worst, abs(p%strain - triangle))
  end do
  call check(size(flip_steps) == 3, 'reversal: three flips in 400 steps of 100 each')
  if (size(flip_steps) == 3) call check(all(flip_steps == [100, 200, 300]), 'reversal: at the steps 100, 200, 300')
  call check(all_rates, 'reversal: |rate| kept, the first segment in the deck''s direction')
  call check_below('reversal: the strain is the triangle wave', worst, 1.0e-12_dp)

  ! 3. oscillation gamma_0 = 0.01, T = 0.064, dt = 1e-3 (64 steps per period)
  gamma_0 = 0.01_dp
  period = 0.064_dp
  dt = 1.0e-3_dp
  omega = 2.0_dp * pi / period
  p = shear_protocol_create(PROTOCOL_OSCILLATORY, 5.0_dp, dt, 0.0_dp, gamma_0, period)
  call check_below('oscillatory: reference rate gamma_0 omega', abs(p%reference_rate - gamma_0 * omega), 1.0e-15_dp)
  worst = 0.0_dp
  summed = 0.0_dp
  all_flips = .true.
  do n = 0, 127
    call shear_protocol_begin_step(p)
    worst = max(worst, abs(p%rate - gamma_0 * omega * cos(omega * n * dt)))
    summed = summed + p%rate * dt
    all_flips = all_flips .and. .not. p%reversed
    call shear_protocol_end_step(p)
    worst = max(worst, abs(p%strain - gamma_0 * sin(omega * (n + 1) * dt)))
    if (n == 15) call check_below('oscillatory: sum of rate dt = gamma(T/4) to gamma_0 omega^2 dt^2/2 per step', &
                                  abs(summed - gamma_0), 16 * 0.5_dp * gamma_0 * omega**2 * dt**2)
  end do
  call check_below('oscillatory: rate gamma_0 omega cos(omega t_n), strain gamma_0 sin(omega t_n+1)', worst, 1.0e-13_dp)
  call check(all_flips .and. shear_protocol_varies(p), 'oscillatory: varies, never reverses')

  ! 4. restart: run 150 steps of a reversal, restore a copy at step 70 from its state, compare
  p = shear_protocol_create(PROTOCOL_REVERSAL, 1.0_dp, 1.0e-3_dp, 0.03_dp, 0.0_dp, 0.0_dp)
  q = shear_protocol_create(PROTOCOL_REVERSAL, 1.0_dp, 1.0e-3_dp, 0.03_dp, 0.0_dp, 0.0_dp)
  restored_same = .true.
  flips = 0
  do n = 0, 149
    if (n == 70) call shear_protocol_restore(q, shear_protocol_state(p))
    call shear_protocol_begin_step(p)
    if (p%reversed) flips = flips + 1
    call shear_protocol_end_step(p)
    if (n >= 70) then
      call shear_protocol_begin_step(q)
      call shear_protocol_end_step(q)
      restored_same = restored_same .and. all(shear_protocol_state(p) == shear_protocol_state(q))
    end if
  end do
  call check(restored_same .and. flips == 4, 'restore: a protocol restored at step 70 continues bitwise (4 flips)')

  ! 5. steps
  p = shear_protocol_create(PROTOCOL_STEPS, 1.0_dp, 1.0e-3_dp, 0.0_dp, 0.0_dp, 0.0_dp, step_at=[0.0_dp, 0.01_dp, 0.05_dp], &
                            step_level=[1.0_dp, -2.0_dp, 0.5_dp], by_strain=.true.)
  q = shear_protocol_create(PROTOCOL_STEPS, 1.0_dp, 1.0e-3_dp, 0.0_dp, 0.0_dp, 0.0_dp, step_at=[0.0_dp, 0.01_dp, 0.05_dp], &
                            step_level=[1.0_dp, -2.0_dp, 0.5_dp], by_strain=.true.)
  allocate(changes(0))
  all_rates = .true.
  restored_same = .true.
  do n = 0, 59
    if (n == 40) call shear_protocol_restore(q, shear_protocol_state(p))
    call shear_protocol_begin_step(p)
    if (p%reversed) changes = [changes, n]
    all_rates = all_rates .and. p%rate == merge(1.0_dp, merge(-2.0_dp, 0.5_dp, n < 30), n < 10)
    call shear_protocol_end_step(p)
    if (n >= 40) then
      call shear_protocol_begin_step(q)
      restored_same = restored_same .and. .not. q%reversed
      call shear_protocol_end_step(q)
      restored_same = restored_same .and. all(shear_protocol_state(p) == shear_protocol_state(q))
    end if
  end do
  call check(size(changes) == 2 .and. shear_protocol_varies(p) .and. shear_protocol_kind('steps') == PROTOCOL_STEPS, &
             'steps by strain: two changes of level')
  if (size(changes) == 2) call check(all(changes == [10, 30]), 'steps by strain: at the steps 10 and 30')
  call check(all_rates, 'steps by strain: the rate is the level of each step')
  call check(restored_same, 'steps: a state restored after a change continues bitwise, no spurious jump')
  p = shear_protocol_create(PROTOCOL_STEPS, 1.0_dp, 1.0e-3_dp, 0.0_dp, 0.0_dp, 0.0_dp, step_at=[0.0_dp, 0.0125_dp], &
                            step_level=[1.0_dp, 3.0_dp], by_strain=.false.)
  changes = [integer ::]
  do n = 0, 29
    call shear_protocol_begin_step(p)
    if (p%reversed) changes = [changes, n]
    call shear_protocol_end_step(p)
  end do
  call check(size(changes) == 1 .and. p%rate == 3.0_dp, 'steps by time: one change, to the second level')
  if (size(changes) == 1) call check(changes(1) == 13, 'steps by time: at the first step from t = 0.0125 on, 13')

  ! 6. stress control
  p = shear_protocol_create(PROTOCOL_STEADY, 1.0_dp, 1.0e-3_dp, 0.0_dp, 0.0_dp, 0.0_dp, stress=4.0_dp)
  call shear_protocol_begin_step(p)
  call check(p%rate == 1.0_dp .and. p%stress == 4.0_dp .and. shear_protocol_varies(p), &
             'stress control: the first step begins at the reference rate, the target the stress')
  call shear_protocol_set_rate(p, 1.5_dp, 4.0_dp, 1.5_dp)
  call shear_protocol_end_step(p)
  call shear_protocol_begin_step(p)
  call check(p%rate == 1.5_dp, 'stress control: a step begins with the last step''s rate')
  call shear_protocol_set_rate(p, 2.0_dp, 4.0_dp, 1.5_dp * 2.0_dp - 0.5_dp * 1.5_dp)
  call shear_protocol_end_step(p)
  call check_below('stress control: the strain advances with the advance rates', abs(p%strain - 1.0e-3_dp * (1.5_dp + 2.25_dp)), &
                   1.0e-15_dp)
  p = shear_protocol_create(PROTOCOL_STEPS, 1.0_dp, 1.0e-3_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, [0.0_dp, 0.002_dp], &
                            [5.0_dp, 7.0_dp], .false.)
  all_rates = .true.
  do n = 0, 3
    call shear_protocol_begin_step(p)
    all_rates = all_rates .and. p%stress == merge(5.0_dp, 7.0_dp, n < 2) .and. (p%reversed .eqv. n == 2)
    call shear_protocol_set_rate(p, 1.0_dp, p%stress, 1.0_dp)
    call shear_protocol_end_step(p)
  end do
  call check(all_rates, 'stress steps: the target is the level of each step, the change marked')

  ! 7. stress reversal: the solver's rate is +-0.5 with the sign of the target (a Newtonian
  ! response), so each segment of G = 0.05 is 100 steps of 5e-4
  p = shear_protocol_create(PROTOCOL_REVERSAL, 1.0_dp, 1.0e-3_dp, 0.05_dp, 0.0_dp, 0.0_dp, stress=-3.0_dp)
  call check(p%reference_rate == 1.0_dp, 'stress reversal: the reference rate is the deck''s rate (the unit)')
  flip_steps = [integer ::]
  all_rates = .true.
  do n = 0, 399
    call shear_protocol_begin_step(p)
    if (p%reversed) flip_steps = [flip_steps, n]
    all_rates = all_rates .and. p%stress == merge(-3.0_dp, 3.0_dp, mod(n / 100, 2) == 0)
    call shear_protocol_set_rate(p, sign(0.5_dp, p%stress), p%stress, sign(0.5_dp, p%stress))
    call shear_protocol_end_step(p)
  end do
  call check(size(flip_steps) == 3, 'stress reversal: three flips in 400 steps')
  if (size(flip_steps) == 3) call check(all(flip_steps == [100, 200, 300]), &
                                        'stress reversal: the target flips at the start of steps 100, 200, 300')
  call check(all_rates, 'stress reversal: the target is -3 on the first segment, then +-3 alternately')
  call check_below('stress reversal: the strain comes back to 0 after four segments', abs(p%strain), 1.0e-12_dp)

  ! 8. stress oscillation
  period = 0.8_dp
  p = shear_protocol_create(PROTOCOL_OSCILLATORY, 1.0_dp, 1.0e-3_dp, 0.0_dp, 0.0_dp, period, stress=2.0_dp)
  call check(p%reference_rate == 1.0_dp .and. p%stress == 0.0_dp, &
             'stress oscillation: the reference rate is the deck''s rate, the target at t = 0 is 0')
  worst = 0.0_dp
  summed = 0.0_dp
  restored_same = .true.
  do n = 0, 999
    if (n == 500) then
      q = p
      call shear_protocol_restore(q, shear_protocol_state(p))
    end if
    call shear_protocol_begin_step(p)
    worst = max(worst, abs(p%stress - 2.0_dp * sin(2.0_dp * pi * n * 1.0e-3_dp / period)))
    call shear_protocol_set_rate(p, 0.3_dp * p%stress, p%stress, 0.3_dp * p%stress)
    summed = summed + 0.3_dp * p%stress * 1.0e-3_dp
    call shear_protocol_end_step(p)
    if (n >= 500) then
      call shear_protocol_begin_step(q)
      call shear_protocol_set_rate(q, 0.3_dp * q%stress, q%stress, 0.3_dp * q%stress)
      call shear_protocol_end_step(q)
      restored_same = restored_same .and. q%stress == p%stress .and. q%strain == p%strain
    end if
  end do
  call check_below('stress oscillation: the target is 2 sin(2 pi n dt/T)', worst, 1.0e-12_dp)
  call check_below('stress oscillation: the strain is the sum of the advance rates', abs(p%strain - summed), 1.0e-15_dp)
  call check(restored_same, 'stress oscillation: a state restored at step 500 continues bitwise')
  call finish('test_shear_protocol')

contains

  ! the steps of strain after k steps of 100-step segments, back and forth: 0..100..0..100..
  pure integer function triangle_steps(k) result(s)
    integer, intent(in) :: k
    integer :: inside
    inside = mod(k, 100)
    s = inside
    if (mod(k / 100, 2) == 1) s = 100 - inside
  end function triangle_steps

end program test_shear_protocol
