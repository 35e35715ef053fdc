! Unit test of the implicit contact stiffness (mod_contact contact_stiffness; mod_particle_contacts
! particle_contacts_add_stiffness, particle_contacts_implicit_update; doc/CONTACT.md "Implicit contacts").
! a = eta = gamma_dot = 1, eps_r = 5e-3, eps_bar = 0.05 (k_n = 4.769e6), mu_d = 0.5 unless said.
! Generalised coordinates q = (U_i, Omega_i, U_j, Omega_j); the generalised force of a contact is
! G = (F, T, -F, T) (F on i, T = a n x F on both).
! Invariants:
!   1. Both blocks are symmetric (bitwise) and positive semi-definite with the exact spectrum:
!      k_norm has the single eigenvalue 2k, k = (3/2) k_n |delta'|^{1/2}; k_tan the double
!      eigenvalue 2 (1 + a^2) k_t, k_t = (2/7) k_n |delta'|^{1/2} (B B^T = 2 (1 + a^2) P), and
!      for a sliding contact (stiffness across its slip direction only) that eigenvalue once; all
!      others 0 (LAPACK dsyev; 1e-12 of the largest: a few ulps of a 12 x 12 eigensolve).
!   2. Normal stiffness = the derivative of contact_pair's force: central differences of G in the
!      positions (step 1e-4 |delta'|, error ~1e-8 relative) equal -k_norm dX plus the geometric
!      term -(F_n/|r|) P (dx_j - dx_i) of the turning normal, which the kernel leaves out
!      (1e-6 relative); that stiffness, F_n/|r|, is |delta'|/(1.5 |r|) = 1.7e-3 of the kept one k
!      at |delta'| = h_r, the largest overlap a run accepts (checked below 2e-3).
!   3. Tangential stiffness = the derivative of contact_pair's force in the velocities over one
!      step, for a sticking contact: G(q + e dq) - G(q - e dq) = -2 e dt k_tan dq (the spring is
!      linear in the slip: 1e-9 relative, rounding of the differences); for a sliding contact
!      (spring 1 + 1e-7 times the Coulomb length along s, so both sides of the difference slide)
!      and slips across s, the capped force turns: the same with the sliding k_tan (1e-6: the
!      1e-7 offset beyond the limit enters the derivative, plus differences at e^2).
!   4. Null spaces: a common translation of both bodies and rolling without slip
!      (U_i - U_j = -a (Omega_i + Omega_j) x n) give no force (1e-12 of |K||q|).
!   5. No stiffness where there is no spring or no contact: frictionless and delta' = 0 give
!      k_tan = 0; an open contact gives both 0 (bitwise).
!   6. The assembly in a mock particle system (two spheres of resistance r I_6, no fluid, pressed
!      together by +-F = 6 pi; positions by Adams-Bashforth 2 as advance_positions): with
!      r = 75, k dt/r = 1.5 at the Hertz overlap (the explicit AB2 limit is 1), the explicit force
!      chatters (the overlap alternates by more than 10 % at the end, or grows beyond h_r, where a
!      run stops, or the contact opens in the second half of the run), the implicit one settles
!      without alternation: the contact closes within the second step, when it was still open at
!      X^n and so had no stiffness, overshoots once (to 1.23 times the Hertz overlap) and rebounds
!      once (0.92: the next position step still carries -dt U^{n-1}/2 of the approach velocity);
!      from step 4 on no sign change of consecutive overlap increments (those below 1e-12 of
!      the overlap are rounding), overlap (F/k_n)^(2/3) to 1e-9 and the contact force the
!      balance used (particle_contacts_implicit_update) equal to -F to 1e-9 after 300 steps (the linear
!      rate is (1 + z/2)/(1 + 3z/2) = 0.57 per step at z = 1.5), action = reaction bitwise.
!   7. The same with friction for a sphere pressed on the lower wall (moving at 0.01 e_x) with
!      resistance r I_6: k_t dt M_t = 4.3 > 2 at the Hertz overlap (the explicit spring's limit,
!      doc/CONTACT.md), the implicit spring settles: the sphere rolls with the wall without slip
!      ((U - V) + a Omega x n -> 0, 1e-9) with a sticking tangential force, and the velocities
!      converge (last change below 1e-10).
program test_contact_stiffness
  use mod_kinds, only: dp, pi
  use mod_vector, only: cross
  use mod_contact, only: contact_params_t, contact_setup, contact_pair, contact_stiffness
  use mod_particle_contacts, only: particle_contacts_settings_t, particle_contacts_t, particle_contacts_create, particle_contacts_step, &
                                   particle_contacts_add_stiffness, particle_contacts_implicit_update
  use mod_particle_system, only: particle_system_t, particle_system_reset, particle_system_add_diagonal, &
                                 particle_system_solve
  use mod_unit_checks, only: check, check_below, finish
  implicit none
  type(contact_params_t) :: p, p0
  real(dp) :: kn(12, 12), kt(12, 12), n(3), dlt, k, k_t, err, eig(12), geo(12), pred(12)
  real(dp) :: xi(3), xj(3), dx(12), eps, gp(12), gm(12), dq(12), q(12), ups(3), dt, fn
  integer :: info, trial
  real(dp), parameter :: fractions(3) = [0.05_dp, 0.3_dp, 1.0_dp], zero3(3) = 0
  real(dp) :: s(3), slip(3), cap
  character(len=200) :: msg
  logical :: sliding

  call contact_setup(p, 1.0_dp, 5.0e-3_dp, 0.5_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  call contact_setup(p0, 1.0_dp, 5.0e-3_dp, 0.0_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)

  ! ---- 1. symmetry, PSD, spectrum
  err = 0
  do trial = 1, 3
    n = unit_vector(trial)
    dlt = -fractions(trial) * p%h_r
    call contact_stiffness(p, n, dlt, zero3, .false., kn, kt)
    call check(all(kn == transpose(kn)) .and. all(kt == transpose(kt)), 'blocks symmetric (bitwise)')
    k = 1.5_dp * p%k_n * sqrt(-dlt)
    k_t = p%kt_coeff * p%k_n * sqrt(-dlt)
    eig = eigenvalues(kn)
    err = max(err, abs(eig(12) - 2 * k) / (2 * k), maxval(abs(eig(1:11))) / (2 * k))
    eig = eigenvalues(kt)
    err = max(err, maxval(abs(eig(11:12) - 4 * k_t)) / (4 * k_t), maxval(abs(eig(1:10))) / (4 * k_t))
    ! sliding along s (a tangent direction): the stiffness across s only
    s = cross(n, unit_vector(mod(trial, 3) + 1))
    s = s / norm2(s)
    call contact_stiffness(p, n, dlt, 1e-4_dp * s, .true., kn, kt)
    call check(all(kt == transpose(kt)), 'sliding block symmetric (bitwise)')
    eig = eigenvalues(kt)
    err = max(err, abs(eig(12) - 4 * k_t) / (4 * k_t), maxval(abs(eig(1:11))) / (4 * k_t))
  end do
  call check_below('1. spectra {2k, 0 x 11}, {2(1+a^2)k_t x 2, 0 x 10}, sliding {2(1+a^2)k_t, 0 x 11}', &
                   err, 1e-12_dp)

  ! ---- 2. normal stiffness against central differences of contact_pair's force
  err = 0
  do trial = 1, 3
    xi = [1.0_dp, 2.0_dp, 3.0_dp]
    n = unit_vector(trial)
    dlt = -fractions(trial) * p%h_r
    xj = xi + (2 * p%a + p%h_r + dlt) * n
    dx = 0
    dx(1:3) = [0.3_dp, -0.7_dp, 0.2_dp] * trial
    dx(7:9) = [-0.5_dp, 0.1_dp, 0.9_dp]
    dx = dx / norm2(dx)
    eps = 1e-4_dp * abs(dlt)
    gp = normal_force(xi + eps * dx(1:3), xj + eps * dx(7:9))
    gm = normal_force(xi - eps * dx(1:3), xj - eps * dx(7:9))
    call contact_stiffness(p0, n, dlt, zero3, .false., kn, kt)
    pred = -matmul(kn, dx)
    fn = p%k_n * abs(dlt)**1.5_dp
    geo = 0
    geo(1:3) = -fn / norm2(xj - xi) * (dx(7:9) - dx(1:3) - dot_product(n, dx(7:9) - dx(1:3)) * n)
    geo(7:9) = -geo(1:3)
    err = max(err, norm2((gp - gm) / (2 * eps) - pred - geo) / norm2(pred))
  end do
  call check_below('2. normal stiffness vs finite differences of the force (+ geometric term)', err, 1e-6_dp)
  ! the stiffness left out, |F_n|/|r|, against the one kept, k, at |delta'| = h_r (the largest
  ! overlap the run accepts): |delta'|/(1.5 |r|) = 1.7e-3
  dlt = -p%h_r
  call check_below('2. geometric stiffness left out / normal stiffness at |delta''| = h_r', &
                   (p%k_n * p%h_r**1.5_dp / (2 * p%a + p%h_r + dlt)) / (1.5_dp * p%k_n * sqrt(p%h_r)), 2e-3_dp)

  ! ---- 3. tangential stiffness against differences in the velocities, sticking contact
  dt = 1e-3_dp
  err = 0
  do trial = 1, 3
    n = unit_vector(trial)
    dlt = -0.3_dp * p%h_r
    q = 0.1_dp * [0.3_dp, -0.2_dp, 0.5_dp, 0.1_dp, 0.4_dp, -0.3_dp, -0.2_dp, 0.1_dp, 0.2_dp, 0.2_dp, -0.1_dp, 0.3_dp]
    dq = [0.7_dp, 0.1_dp, -0.3_dp, 0.2_dp, -0.5_dp, 0.4_dp, 0.1_dp, 0.6_dp, -0.2_dp, -0.4_dp, 0.3_dp, 0.1_dp] * trial
    eps = 1e-3_dp
    ups = 0.02_dp * p%h_r * cross(n, [1.0_dp, 1.0_dp, 1.0_dp])
    gp = pair_force(p, n, dlt, q + eps * dq, ups, dt, sliding)
    call check(.not. sliding, '3. the contact sticks')
    gm = pair_force(p, n, dlt, q - eps * dq, ups, dt, sliding)
    call contact_stiffness(p, n, dlt, zero3, .false., kn, kt)
    pred = -dt * matmul(kt, dq)
    err = max(err, norm2((gp - gm) / (2 * eps) - pred) / norm2(pred))
  end do
  call check_below('3. tangential stiffness vs differences of the force in the velocities', err, 1e-9_dp)
  ! sliding: the spring at the Coulomb limit along s (1 + 1e-7 beyond it, so that both sides of
  ! the difference slide), no slip at q, perturbations whose slip is across s
  err = 0
  do trial = 1, 3
    n = unit_vector(trial)
    dlt = -0.3_dp * p%h_r
    s = cross(n, unit_vector(mod(trial, 3) + 1))
    s = s / norm2(s)
    cap = p%mu_d * p%k_n * abs(dlt)**1.5_dp / (p%kt_coeff * p%k_n * sqrt(abs(dlt)))
    ups = (1 + 1e-7_dp) * cap * s
    q = 0
    dq = [0.7_dp, 0.1_dp, -0.3_dp, 0.2_dp, -0.5_dp, 0.4_dp, -0.4_dp, 0.6_dp, 0.2_dp, 0.1_dp, 0.3_dp, -0.6_dp] * trial
    slip = dq(1:3) - dq(7:9) - dot_product(dq(1:3) - dq(7:9), n) * n + p%a * cross(dq(4:6) + dq(10:12), n)
    dq(1:3) = dq(1:3) - dot_product(slip, s) * s
    eps = 1e-4_dp
    gp = pair_force(p, n, dlt, q + eps * dq, ups, dt, sliding)
    call check(sliding, '3. the contact slides')
    gm = pair_force(p, n, dlt, q - eps * dq, ups, dt, sliding)
    call contact_stiffness(p, n, dlt, cap * s, .true., kn, kt)
    pred = -dt * matmul(kt, dq)
    err = max(err, norm2((gp - gm) / (2 * eps) - pred) / norm2(pred))
  end do
  call check_below('3. sliding: stiffness across the slip vs differences of the capped force', err, 1e-6_dp)

  ! ---- 4. null spaces
  n = unit_vector(2)
  call contact_stiffness(p, n, -0.3_dp * p%h_r, zero3, .false., kn, kt)
  q = [0.3_dp, -0.2_dp, 0.5_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.3_dp, -0.2_dp, 0.5_dp, 0.0_dp, 0.0_dp, 0.0_dp]
  err = norm2(matmul(kn + kt, q)) / (maxval(abs(kn + kt)) * norm2(q))
  q(4:6) = [0.2_dp, 0.1_dp, -0.4_dp]
  q(10:12) = [-0.1_dp, 0.5_dp, 0.3_dp]
  q(7:9) = q(1:3) + p%a * cross(q(4:6) + q(10:12), n)
  err = max(err, norm2(matmul(kt, q)) / (maxval(abs(kt)) * norm2(q)))
  call check_below('4. common translation and rolling without slip give no force', err, 1e-12_dp)

  ! ---- 5. no spring, no stiffness
  call contact_stiffness(p0, n, -0.3_dp * p%h_r, zero3, .false., kn, kt)
  call check(all(kt == 0), '5. frictionless: no tangential stiffness')
  call contact_stiffness(p, n, 0.0_dp, zero3, .false., kn, kt)
  call check(all(kt == 0) .and. all(kn == 0), '5. delta'' = 0: no stiffness')
  call contact_stiffness(p, n, 1e-4_dp, zero3, .false., kn, kt)
  call check(all(kt == 0) .and. all(kn == 0), '5. open contact: no stiffness')

  ! ---- 6, 7. the assembly in a mock particle system
  call pressed_pair()
  call sphere_on_wall()
  call finish('test_contact_stiffness')

contains

  function unit_vector(which) result(v)
    integer, intent(in) :: which
    real(dp) :: v(3)
    select case (which)
    case (1); v = [1.0_dp, 0.0_dp, 0.0_dp]
    case (2); v = [0.0_dp, -1.0_dp, 0.0_dp]
    case default; v = [1.0_dp, 2.0_dp, -2.0_dp] / 3
    end select
  end function unit_vector

  ! the generalised force of the frictionless contact between spheres at xi and xj
  function normal_force(xi, xj) result(g)
    real(dp), intent(in) :: xi(3), xj(3)
    real(dp) :: g(12), ups(3), f(3), tq(3), fn, d
    logical :: sl
    ups = 0
    d = norm2(xj - xi)
    call contact_pair(p0, (xj - xi) / d, d - 2 * p0%a - p0%h_r, [0.0_dp, 0.0_dp, 0.0_dp], &
                      [0.0_dp, 0.0_dp, 0.0_dp], 1e-3_dp, ups, f, tq, fn, sl)
    g = [f, tq, -f, tq]
  end function normal_force

  ! the generalised force of one step of contact_pair at velocities q, spring ups before the step
  function pair_force(p, n, dlt, q, ups, dt, sl) result(g)
    type(contact_params_t), intent(in) :: p
    real(dp), intent(in) :: n(3), dlt, q(12), ups(3), dt
    logical, intent(out) :: sl
    real(dp) :: g(12), u(3), f(3), tq(3), fn
    u = ups
    call contact_pair(p, n, dlt, q(1:3) - q(7:9), q(4:6) + q(10:12), dt, u, f, tq, fn, sl)
    g = [f, tq, -f, tq]
  end function pair_force

  function eigenvalues(a) result(w)
    real(dp), intent(in) :: a(12, 12)
    real(dp) :: w(12), c(12, 12), work(200)
    integer :: lapack_info
    c = a
    call dsyev('N', 'U', 12, c, 12, w, work, size(work), lapack_info)
  end function eigenvalues

  ! Two spheres along x, resistance r I_6 each, pressed together by +-F; AB2 positions.
  subroutine pressed_pair()
    real(dp), parameter :: f = 6 * pi
    logical :: implicit_mode
    integer :: mode
    real(dp) :: overlap(400), target, alternation, last_force(3, 2), inc(296)
    logical :: monotone, opened
    target = (f / p0%k_n)**(2.0_dp / 3)
    do mode = 1, 2
      implicit_mode = mode == 2
      call run_pair(implicit_mode, overlap, last_force, opened)
      if (.not. implicit_mode) then
        alternation = abs(overlap(400) - 2 * overlap(399) + overlap(398)) / target
        print '(a,es9.2,a,l1)', '6. explicit: last second difference of the overlap / Hertz overlap ', &
              alternation, ', contact opened late in the run: ', opened
        call check(alternation > 0.1_dp .or. opened, '6. explicit contact chatters at k dt/r = 1.5')
      else
        ! from the step after the impact on (increments below 1e-12 of the overlap are rounding)
        inc = overlap(5:300) - overlap(4:299)
        where (abs(inc) < 1e-12_dp * target) inc = 0
        monotone = all(inc(2:) * inc(:size(inc) - 1) >= 0)
        print '(a,4f8.4)', '6. implicit: overlap / Hertz overlap at steps 2-5: ', overlap(2:5) / target
        call check(monotone, '6. implicit: the overlap settles without alternation after the impact')
        call check_below('6. implicit: overlap vs (F/k_n)^(2/3)', abs(overlap(300) - target) / target, 1e-9_dp)
        call check_below('6. implicit: contact force the balance used vs -F', &
                         abs(last_force(1, 1) + f) / f, 1e-9_dp)
        call check(all(last_force(:, 2) == -last_force(:, 1)), '6. implicit: action = reaction bitwise')
      end if
    end do
  end subroutine pressed_pair

  subroutine run_pair(implicit_mode, overlap, last_force, opened)
    logical, intent(in) :: implicit_mode
    real(dp), intent(out) :: overlap(:), last_force(3, 2)
    logical, intent(out) :: opened
    real(dp), parameter :: r = 75, f = 6 * pi, dt = 1e-3_dp
    type(particle_contacts_t) :: pc
    type(particle_system_t) :: sys
    real(dp) :: x(3, 2), u(3, 2), om(3, 2), u_prev(3, 2), rhs(6, 2), sol(6, 2), d6(6, 6)
    integer :: step, its, c, info
    logical :: ok, have_prev
    character(len=200) :: msg
    call particle_contacts_create(pc, 2, 1.0_dp, particle_contacts_settings_t(roughness=5.0e-3_dp, implicit=implicit_mode), &
                          1.0_dp, [20.0_dp, 20.0_dp, 20.0_dp], .true., dt, info, msg)
    d6 = 0
    do c = 1, 6
      d6(c, c) = r
    end do
    x(:, 1) = [10.0_dp - 1.0_dp - 0.6_dp * p0%h_r, 10.0_dp, 10.0_dp]
    x(:, 2) = [10.0_dp + 1.0_dp + 0.6_dp * p0%h_r, 10.0_dp, 10.0_dp]
    u = 0
    om = 0
    u_prev = 0
    have_prev = .false.
    opened = .false.
    do step = 1, size(overlap)
      call particle_contacts_step(pc, x, u, om, info)
      if (info /= 0) then
        opened = .true.                           ! overlap beyond h_r: as bad as chatter
        overlap(step:) = overlap(max(step - 1, 1))
        exit
      end if
      call particle_system_reset(sys, 2)
      call particle_system_add_diagonal(sys, 1, d6)
      call particle_system_add_diagonal(sys, 2, d6)
      rhs(:, 1) = [f, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp] + [pc%force(:, 1), pc%torque(:, 1)]
      rhs(:, 2) = [-f, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp] + [pc%force(:, 2), pc%torque(:, 2)]
      call particle_contacts_add_stiffness(pc, sys, rhs, u, om, have_prev)
      call particle_system_solve(sys, rhs, sol, 1e-14_dp, its, ok)
      call take_step(pc, sol, dt, x, u, om, u_prev, have_prev)
      overlap(step) = 2 + p0%h_r - norm2(x(:, 2) - x(:, 1))
      if (step > size(overlap) / 2 .and. pc%stats%pair_contacts == 0) opened = .true.
      last_force = pc%force
    end do
  end subroutine run_pair

  ! A sphere pressed on the lower wall (moving at V = 0.01 e_x) by -F e_y, friction 0.5,
  ! resistance r I_6; implicit contacts.
  subroutine sphere_on_wall()
    real(dp), parameter :: r = 10, f = 6 * pi, dt = 1e-3_dp, v_wall = 0.01_dp
    type(particle_contacts_t) :: pc
    type(particle_system_t) :: sys
    real(dp) :: x(3, 1), u(3, 1), om(3, 1), u_prev(3, 1), rhs(6, 1), sol(6, 1), d6(6, 6), slip(3)
    real(dp) :: change, nw(3), kt_dt_m
    integer :: step, its, c, info
    logical :: ok, have_prev, stuck
    character(len=200) :: msg
    ! the lower wall moves at -shear_rate Ly/2: shear_rate = -2 v_wall / Ly gives +v_wall
    call particle_contacts_create(pc, 1, 1.0_dp, particle_contacts_settings_t(roughness=5.0e-3_dp, friction=0.5_dp, &
                          normal_stiffness=p%k_n), -2 * v_wall / 20.0_dp, [20.0_dp, 20.0_dp, 20.0_dp], .true., dt, &
                          info, msg)
    call check(info == 0 .and. abs(pc%wall_velocity(1, 1) - v_wall) < 1e-15_dp, '7. wall at +0.01 e_x')
    kt_dt_m = p%kt_coeff * p%k_n * sqrt(p%eps_bar * p%h_r) * dt * (1 / r + 1 / r)
    print '(a,f6.2)', '7. k_t dt M_t at the Hertz overlap: ', kt_dt_m
    d6 = 0
    do c = 1, 6
      d6(c, c) = r
    end do
    nw = [0.0_dp, -1.0_dp, 0.0_dp]
    x(:, 1) = [10.0_dp, 1.0_dp + 0.6_dp * p%h_r, 10.0_dp]
    u = 0
    om = 0
    u_prev = 0
    have_prev = .false.
    stuck = .true.
    change = 0
    do step = 1, 600
      call particle_contacts_step(pc, x, u, om, info)
      call particle_system_reset(sys, 1)
      call particle_system_add_diagonal(sys, 1, d6)
      rhs(:, 1) = [0.0_dp, -f, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp] + [pc%force(:, 1), pc%torque(:, 1)]
      call particle_contacts_add_stiffness(pc, sys, rhs, u, om, have_prev)
      call particle_system_solve(sys, rhs, sol, 1e-14_dp, its, ok)
      change = norm2(sol(1:3, 1) - u(:, 1)) + norm2(sol(4:6, 1) - om(:, 1))
      call take_step(pc, sol, dt, x, u, om, u_prev, have_prev)
      if (step > 300 .and. pc%stats%sliding > 0) stuck = .false.
    end do
    slip = u(:, 1) - pc%wall_velocity(:, 1) + cross(om(:, 1), nw)
    slip = slip - dot_product(slip, nw) * nw
    print '(a,3es10.2,a,es9.2)', '7. implicit: U = ', u(:, 1), ', slip ', norm2(slip)
    call check(stuck .and. pc%stats%wall_contacts == 1, '7. implicit: the contact sticks (last 300 steps)')
    call check_below('7. implicit: rolls with the wall, |slip| / V', norm2(slip) / v_wall, 1e-9_dp)
    call check_below('7. implicit: last change of the velocities', change, 1e-10_dp)
    call check(abs(pc%force(1, 1) - r * u(1, 1)) < 1e-6_dp * abs(r * u(1, 1)) .and. abs(u(1, 1)) > 0, &
               '7. implicit: a tangential contact force drags the sphere (F_t = r U_x)')
  end subroutine sphere_on_wall

  ! The velocities of the solve sol (6, n) into u, om, the contacts' implicit update, then the
  ! positions by Adams-Bashforth 2 (Euler on the first step), as bin/fdsusp advances them.
  subroutine take_step(pc, sol, dt, x, u, om, u_prev, have_prev)
    type(particle_contacts_t), intent(inout) :: pc
    real(dp), intent(in) :: sol(:, :), dt
    real(dp), intent(inout) :: x(:, :), u(:, :), om(:, :), u_prev(:, :)
    logical, intent(inout) :: have_prev
    u = sol(1:3, :)
    om = sol(4:6, :)
    call particle_contacts_implicit_update(pc, u, om)
    if (have_prev) then
      x = x + dt * (1.5_dp * u - 0.5_dp * u_prev)
    else
      x = x + dt * u
    end if
    u_prev = u
    have_prev = .true.
  end subroutine take_step

end program test_contact_stiffness
