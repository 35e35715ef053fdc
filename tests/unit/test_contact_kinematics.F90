! Unit test of mod_contact under prescribed kinematics over many steps (doc/CONTACT.md "Tests").
! a = eta = gamma_dot = 1, eps_r = 5e-3, eps_bar = 0.05, mu_d = 0.5; contact_forces is called
! once per step with positions advanced by the prescribed velocities, as a time step would.
! Invariants:
!   1. A sphere pressed against a moving wall (sphere not rotating, lower wall translating at
!      V = -e_x, overlap delta'(t) = -h_r (0.3 + 0.1 sin(2 pi t / 0.1))):
!      a. stick: until the spring reaches the Coulomb limit, F_t = -k_t(delta') Upsilon with
!         Upsilon = (U - V) t, i.e. the spring stretches at the slip rate (1e-12 relative:
!         Upsilon is a sum of t/dt equal increments, k_t a square root);
!      b. slide: from then on |F_t| = mu_d |F_n| at every step while the load oscillates
!         (1e-13 relative: the cap is a rescaling by mu_d |F_n| / |F_t|), F_t opposes the slip
!         (along -x); sliding starts at the first step with |U - V| t >= (7/2) mu_d |delta'(t)|
!         (k_t |Upsilon| = mu_d |F_n| with k_t/k_n = (2/7) |delta'|^{1/2});
!      c. wall reversed (V = +e_x): the spring unloads through zero (sticking, |F_t| below the
!         cap) and the sphere slides again the other way with |F_t| = mu_d |F_n| (1e-13);
!      d. torque = a n x F at every step (1e-15 |F|), n = -e_y.
!   2. Rolling without slip gives no tangential force: a sphere translating along the moving
!      wall with U - V_w + a Omega x n = 0 (plus a spin about n, which is not slip in this law),
!      with the same oscillating load and wrapped in x across the periodic boundary, has
!      F_t = 0 at every step (exactly: the slip cancels in floating point for these values;
!      asserted to 1e-14 |F_n|) and the history keeps a zero spring.
!   3. Two spheres rolling on each other without slip along an oblique normal,
!      U_i - U_j = -a (Omega_i + Omega_j) x n: |F_t| <= 1e-12 |F_n| over 2000 steps (the slip
!      cancels only to rounding, ~1e-16, integrated over the steps), and action = reaction.
!   4. Two spheres sliding past each other at a fixed overlap with an oblique tangential
!      velocity: after the stick phase |F_t| = mu_d |F_n| (1e-13) with F_t on i opposing the
!      slip of i relative to j (1 + cos < 1e-12).
program test_contact_kinematics
  use mod_kinds, only: dp, pi
  use mod_vector, only: cross
  use mod_contact, only: contact_params_t, contact_setup, contact_history_t, history_size, &
                         history_lookup, contact_forces, contact_stats_t
  use mod_unit_checks, only: check, fail, finish
  implicit none
  type(contact_params_t) :: p
  type(contact_history_t) :: h
  type(contact_stats_t) :: st
  integer :: info, step, nstick, first_slide, pairs(2, 1), walls(2, 1)
  character(len=200) :: msg
  real(dp) :: dt, t, dlt, x(3, 2), u(3, 2), om(3, 2), box(3), vw(3, 2), force(3, 2), torque(3, 2)
  real(dp) :: ss(3, 3, 2), kt, fn, ft(3), n(3), err_stick, err_slide, err_torque, fmax_t
  real(dp) :: slip(3), err_cos, ups(3), tstick
  logical :: per(3), was_negative, slid_back

  call contact_setup(p, 1.0_dp, 5.0e-3_dp, 0.5_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  box = 20
  per = [.true., .false., .true.]
  walls(:, 1) = [1, 1]
  pairs(:, 1) = [1, 2]
  n = [0.0_dp, -1.0_dp, 0.0_dp]

  ! ---- 1. sliding on a moving wall
  dt = 1.0e-4_dp
  x = 0
  u = 0
  om = 0
  vw = 0
  vw(:, 1) = [-1.0_dp, 0.0_dp, 0.0_dp]
  x(:, 1) = [5.0_dp, 0.0_dp, 5.0_dp]
  err_stick = 0
  err_slide = 0
  err_torque = 0
  nstick = 0
  first_slide = 0
  was_negative = .false.
  slid_back = .false.
  do step = 1, 1200
    t = step * dt
    if (step == 601) vw(:, 1) = [1.0_dp, 0.0_dp, 0.0_dp]          ! reverse the wall
    dlt = -p%h_r * (0.3_dp + 0.1_dp * sin(2 * pi * t / 0.1_dp))
    x(2, 1) = 1 + p%h_r + dlt
    call one_wall_step()
    fn = force(2, 1)
    ft = [force(1, 1), 0.0_dp, force(3, 1)]
    err_torque = max(err_torque, norm2(torque(:, 1) - cross(n, force(:, 1))) / norm2(force(:, 1)))
    if (step <= 600) then
      if (st%sliding == 0) then
        if (first_slide == 0) then
          ! stick: Upsilon = (U - V) t = step dt e_x, F_t = -k_t Upsilon
          kt = (2.0_dp / 7) * p%k_n * sqrt(-(x(2, 1) - 1 - p%h_r))
          err_stick = max(err_stick, abs(ft(1) / (-kt * step * dt) - 1))
          nstick = step
        end if
      else
        if (first_slide == 0) first_slide = step
        err_slide = max(err_slide, abs(norm2(ft) / (p%mu_d * fn) - 1))
        if (ft(1) >= 0) call fail('sliding force does not oppose the slip')
      end if
    else
      if (ft(1) > 0) was_negative = .true.
      if (st%sliding > 0) then
        if (was_negative) slid_back = .true.
        err_slide = max(err_slide, abs(norm2(ft) / (p%mu_d * fn) - 1))
      else if (slid_back) then
        call fail('the reversed sphere stopped sliding')
      end if
    end if
  end do
  ! predicted first sliding step: the first m with |U - V| m dt >= (7/2) mu_d |delta'(m dt)|
  do step = 1, 600
    tstick = step * dt
    if (tstick >= 3.5_dp * p%mu_d * p%h_r * (0.3_dp + 0.1_dp * sin(2 * pi * tstick / 0.1_dp))) exit
  end do
  print '(a,i0,a,i0,a,es9.2,a,es9.2)', '1. stick for ', nstick, ' steps (first slide predicted at ', &
    step, '), stick error ', err_stick, ', slide |F_t|/(mu|F_n|) - 1 ', err_slide
  print '(a,l1,a,es9.2)', '   reversed wall: slid back ', slid_back, '; torque error ', err_torque
  call check(err_stick <= 1.0e-12_dp, 'stick phase: F_t = -k_t (U - V) t')
  call check(first_slide == step, 'stick phase duration')
  call check(err_slide <= 1.0e-13_dp, 'sliding: |F_t| = mu_d |F_n|')
  call check(slid_back, 'sliding after the reversal')
  call check(err_torque <= 1.0e-15_dp, 'torque = a n x F')

  ! ---- 2. rolling without slip on the moving wall, wrapped across x = Lx
  call clear_history()
  dt = 1.0e-3_dp
  vw(:, 1) = [-1.0_dp, 0.0_dp, 0.0_dp]
  u(:, 1) = [0.5_dp, 0.0_dp, 0.2_dp]
  om(:, 1) = [0.2_dp, 0.7_dp, -1.5_dp]            ! U - V + a Omega x n = 0; spin 0.7 about n
  x(:, 1) = [18.9_dp, 0.0_dp, 5.0_dp]
  fmax_t = 0
  do step = 1, 5000
    t = step * dt
    dlt = -p%h_r * (0.3_dp + 0.1_dp * sin(2 * pi * t / 0.1_dp))
    x(2, 1) = 1 + p%h_r + dlt
    call one_wall_step()
    fmax_t = max(fmax_t, norm2(force([1, 3], 1)) / force(2, 1))
    x(1, 1) = x(1, 1) + u(1, 1) * dt
    x(3, 1) = x(3, 1) + u(3, 1) * dt
    x(1, 1) = x(1, 1) - box(1) * floor(x(1, 1) / box(1))
  end do
  ups = history_lookup(h, 1, -1)
  print '(a,es9.2,a,f6.3,a,i0,a,es9.2)', '2. rolling on the wall: max |F_t|/|F_n| = ', fmax_t, &
    ', x now ', x(1, 1), ' (wrapped), stored contacts ', history_size(h), ', |Ups| ', norm2(ups)
  call check(fmax_t <= 1.0e-14_dp, 'rolling without slip gives no tangential force')
  call check(history_size(h) == 1, 'the rolling contact is in the history')

  ! ---- 3. two spheres rolling on each other, oblique normal
  call clear_history()
  n = [2.0_dp, 3.0_dp, 6.0_dp] / 7
  om(:, 1) = [0.3_dp, -0.2_dp, 0.5_dp]
  om(:, 2) = [-0.1_dp, 0.4_dp, 0.2_dp]
  u(:, 2) = [0.1_dp, 0.2_dp, -0.3_dp]
  u(:, 1) = u(:, 2) - cross(om(:, 1) + om(:, 2), n)
  fmax_t = 0
  do step = 1, 2000
    t = step * dt
    x(:, 1) = [5.0_dp, 10.0_dp, 5.0_dp] + u(:, 1) * t
    dlt = -p%h_r * (0.3_dp + 0.1_dp * sin(2 * pi * t / 0.1_dp))
    x(:, 2) = x(:, 1) + (2 + p%h_r + dlt) * n
    call one_pair_step()
    ft = force(:, 1) - dot_product(force(:, 1), n) * n
    fmax_t = max(fmax_t, norm2(ft) / abs(dot_product(force(:, 1), n)))
    if (any(force(:, 1) /= -force(:, 2))) call fail('pair: action /= reaction')
  end do
  print '(a,es9.2)', '3. two spheres rolling on each other: max |F_t|/|F_n| = ', fmax_t
  call check(fmax_t <= 1.0e-12_dp, 'a rolling pair gives no tangential force')

  ! ---- 4. two spheres sliding past each other at a fixed overlap
  call clear_history()
  om = 0
  u(:, 2) = 0
  u(:, 1) = [1.0_dp, -0.5_dp, 0.25_dp]
  slip = u(:, 1) - dot_product(u(:, 1), n) * n
  err_slide = 0
  err_cos = 0
  first_slide = 0
  do step = 1, 400
    x(:, 1) = [5.0_dp, 10.0_dp, 5.0_dp]
    x(:, 2) = x(:, 1) + (2 + 0.7_dp * p%h_r) * n
    call one_pair_step()
    if (st%sliding > 0) then
      if (first_slide == 0) first_slide = step
      ft = force(:, 1) - dot_product(force(:, 1), n) * n
      fn = abs(dot_product(force(:, 1), n))
      err_slide = max(err_slide, abs(norm2(ft) / (p%mu_d * fn) - 1))
      err_cos = max(err_cos, 1 + dot_product(ft, slip) / (norm2(ft) * norm2(slip)))
    end if
  end do
  print '(a,i0,a,es9.2,a,es9.2)', '4. pair sliding from step ', first_slide, &
    ': |F_t|/(mu|F_n|) - 1 = ', err_slide, ', 1 + cos(F_t, slip) = ', err_cos
  call check(first_slide /= 0 .and. err_slide <= 1.0e-13_dp, 'pair sliding: |F_t| = mu_d |F_n|')
  call check(err_cos <= 1.0e-12_dp, 'pair sliding: F_t opposes the slip')

  call finish('test_contact_kinematics')

contains

  subroutine one_wall_step()
    call contact_forces(p, h, x(:, 1:1), u(:, 1:1), om(:, 1:1), box, per, vw, pairs, 0, walls, 1, &
                        dt, force(:, 1:1), torque(:, 1:1), ss(:, :, 1:1), st, info)
    if (info /= 0 .or. st%wall_contacts /= 1) call fail('wall contact lost')
  end subroutine one_wall_step

  subroutine one_pair_step()
    call contact_forces(p, h, x, u, om, box, per, vw, pairs, 1, walls, 0, dt, force, torque, ss, &
                        st, info)
    if (info /= 0 .or. st%pair_contacts /= 1) call fail('pair contact lost')
  end subroutine one_pair_step

  subroutine clear_history()
    h = contact_history_t()       ! the default: no contacts, nothing allocated
  end subroutine clear_history

end program test_contact_kinematics
