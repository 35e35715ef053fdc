! pairtraj: reference trajectory of two rough, frictional, force- and torque-free spheres in
! unbounded simple shear (the "theory" curves of Gallier et al. 2014 JFM section 3, figures 3-5;
! DaCunha & Hinch 1996), equal or of radii a and size_ratio * a. Independent of the DNS solver: it
! shares only mod_kinds, mod_vector and the resistance kernels (mod_pair_resistance + its table,
! mod_pair_resistance_unequal, mod_resistance_blocks) with src/.
!
!   usage: pairtraj DECK.nml
!
! Reads the namelist deck (doc/PAIRTRAJ_INPUT.md), integrates r = x_2 - x_1 from start until
! r_x = x_end with the adaptive Dormand-Prince 5(4) integrator (mod_pair_integrator), and writes a
! CSV (header: t,x,y,z,theta,gap,fc_normal,fc_tangential,N1star,N2star,...; positions in units
! of a, time in strain units, forces in units of eta gamma_dot a^2, then per-sphere columns
! omega2_z, N1star_1, N2star_1, N1star_2, N2star_2; theta = atan2(y, x) from +x,
! so the pair arrives at theta ~ pi and leaves at theta ~ 0). A summary goes to stdout.
program pairtraj
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use mod_kinds, only: dp
  use mod_pair_deck, only: pair_deck, read_pair_deck, deck_fail
  use mod_pair_dynamics, only: pair_model, pair_diagnostics, pair_state_size, make_pair_model, &
                               pair_rates, project_spring
  use mod_pair_integrator, only: dopri5_step
  implicit none

  type(pair_deck) :: deck
  type(pair_model) :: model
  type(pair_diagnostics) :: diag
  character(len=1024) :: deck_path
  real(dp), dimension(pair_state_size) :: y, k1, y_new, k7, y_end, k_end, y_out
  real(dp) :: t, h, err, err_old, h_lambda, next_out, h_lo, h_hi, x_lo, x_hi, h_try, fac
  real(dp) :: min_gap, max_fn, max_ft, err_end, hl_end
  integer :: csv, n_accept, n_reject, n_stiff, n_rhs, iter, nargs, ios
  integer(kind=8) :: clock0, clock1, clock_rate
  logical :: changed, done
  character(len=256) :: msg
  real(dp), parameter :: safety = 0.9_dp, beta_pi = 0.04_dp

  nargs = command_argument_count()
  if (nargs /= 1) then
    write (error_unit, '(a)') 'usage: pairtraj DECK.nml   (deck variables: doc/PAIRTRAJ_INPUT.md)'
    stop 2, quiet=.true.
  end if
  call get_command_argument(1, deck_path)
  call read_pair_deck(trim(deck_path), deck)
  model = make_pair_model(deck%eps_r, deck%eps_bar, deck%mu_d, deck%kn_smooth, deck%size_ratio)
  call system_clock(clock0, clock_rate)

  call open_csv(trim(deck%csv_file), csv)
  write (csv, '(a)') 't,x,y,z,theta,gap,fc_normal,fc_tangential,N1star,N2star,' // &
    'N1star_contact,N2star_contact,omega1_z,contact,sliding,omega2_z,N1star_1,N2star_1,' // &
    'N1star_2,N2star_2'

  write (output_unit, '(a,a)') 'pairtraj: deck ', trim(deck_path)
  write (output_unit, '(a,es10.3,a,es10.3,a,es10.3,a,es10.3)') 'pairtraj: eps_r = ', deck%eps_r, &
    ', eps_bar = ', deck%eps_bar, ', mu_d = ', deck%mu_d, ', k_n = ', model%k_n
  if (deck%size_ratio /= 1.0_dp) write (output_unit, '(a,es10.3,a,es10.3)') &
    'pairtraj: unequal spheres: radii 1 and size_ratio = ', deck%size_ratio, &
    ', pair stiffness k = ', model%k_pair
  if (deck%mu_d > 0.0_dp) then
    write (output_unit, '(a)') 'pairtraj: models: lubrication (exact two-sphere), Hertz contact, ' // &
      'tangential spring with Coulomb cap'
  else
    write (output_unit, '(a)') 'pairtraj: models: lubrication (exact two-sphere), Hertz contact; ' // &
      'mu_d = 0: frictionless, no tangential spring'
  end if

  t = 0.0_dp
  y = 0.0_dp
  y(1:3) = deck%start
  call rhs(y, k1)
  n_rhs = 1
  call write_record(t, y)
  min_gap = huge(1.0_dp)
  max_fn = 0.0_dp
  max_ft = 0.0_dp
  next_out = deck%dt_out
  h = deck%h_init
  err_old = 1.0e-4_dp
  n_accept = 0
  n_reject = 0
  n_stiff = 0
  done = .false.

  do while (.not. done)
    if (n_accept + n_reject >= deck%max_steps) call run_fail('max_steps reached before x_end')
    if (t > deck%t_max) call run_fail('t_max reached before x_end (closed or stalled trajectory?)')
    call dopri5_step(rhs, y, k1, h, deck%rtol, deck%atol, y_new, k7, err, h_lambda)
    n_rhs = n_rhs + 6
    if (.not. (err == err)) err = 1.0e10_dp   ! NaN from an unstable trial step: reject
    if (err > 1.0_dp) then
      n_reject = n_reject + 1
      h = h * max(0.2_dp, safety * err**(-0.2_dp))
      if (h < 1.0e-14_dp) call run_fail('step size underflow')
      cycle
    end if
    n_accept = n_accept + 1
    if (h_lambda > 3.25_dp) n_stiff = n_stiff + 1

    if (y_new(1) >= deck%x_end) then
      ! Land exactly on r_x = x_end: regula falsi on the step size (re-steps from y; each is
      ! shorter than the accepted step, so within tolerance).
      h_lo = 0.0_dp
      x_lo = y(1)
      h_hi = h
      x_hi = y_new(1)
      y_end = y_new
      k_end = k7
      do iter = 1, 60
        h_try = h_lo + (deck%x_end - x_lo) * (h_hi - h_lo) / (x_hi - x_lo)
        call dopri5_step(rhs, y, k1, h_try, deck%rtol, deck%atol, y_end, k_end, err_end, hl_end)
        n_rhs = n_rhs + 6
        if (abs(y_end(1) - deck%x_end) < 1.0e-13_dp) exit
        if (y_end(1) > deck%x_end) then
          h_hi = h_try
          x_hi = y_end(1)
        else
          h_lo = h_try
          x_lo = y_end(1)
        end if
      end do
      call output_until(t + h_try, h_try, y, k1, y_end, k_end)
      t = t + h_try
      y = y_end
      call write_record(t, y)
      done = .true.
      exit
    end if

    call output_until(t + h, h, y, k1, y_new, k7)
    call project_spring(model, y_new, changed)
    if (changed) then
      call rhs(y_new, k7)
      n_rhs = n_rhs + 1
    end if
    t = t + h
    y = y_new
    k1 = k7
    call track(y)
    if (deck%dt_out == 0.0_dp) call write_record(t, y)

    ! PI step-size control (Hairer & Wanner's DOPRI5 settings).
    fac = err**(0.2_dp - 0.75_dp * beta_pi) / err_old**beta_pi / safety
    h = h / max(0.1_dp, min(5.0_dp, fac))
    err_old = max(err, 1.0e-4_dp)
  end do
  close (csv)
  call system_clock(clock1)

  call rhs_diag(y, diag)
  write (output_unit, '(a,f22.15)') 'final_x = ', y(1)
  write (output_unit, '(a,f22.15)') 'final_y = ', y(2)
  write (output_unit, '(a,f22.15)') 'final_z = ', y(3)
  write (output_unit, '(a,f22.12)') 'final_t = ', t
  write (output_unit, '(a,es22.12)') 'min_gap = ', min_gap
  write (output_unit, '(a,es22.12)') 'max_fc_normal = ', max_fn
  write (output_unit, '(a,es22.12)') 'max_fc_tangential = ', max_ft
  write (output_unit, '(a,i0,a,i0,a,i0,a,i0)') 'steps_accepted = ', n_accept, ', rejected = ', &
    n_reject, ', stiffness_limited = ', n_stiff, ', rhs_evaluations = ', n_rhs
  write (output_unit, '(a,f10.3,a)') 'wall_time = ', real(clock1 - clock0, dp) / real(clock_rate, dp), ' s'
  if (n_stiff > n_accept / 2) write (output_unit, '(a)') 'pairtraj: note: most steps were ' // &
    'limited by stability (stiff contact); consider a larger eps_bar or expect long runs'
  write (output_unit, '(a,a)') 'pairtraj: wrote ', trim(deck%csv_file)

contains

  subroutine rhs(yy, dy)
    real(dp), intent(in) :: yy(:)
    real(dp), intent(out) :: dy(:)
    call pair_rates(model, yy, dy)
  end subroutine rhs

  subroutine rhs_diag(yy, dg)
    real(dp), intent(in) :: yy(:)
    type(pair_diagnostics), intent(out) :: dg
    real(dp) :: dy(pair_state_size)
    call pair_rates(model, yy, dy, dg)
  end subroutine rhs_diag

  subroutine track(yy)
    real(dp), intent(in) :: yy(:)
    type(pair_diagnostics) :: dg
    call rhs_diag(yy, dg)
    min_gap = min(min_gap, dg%gap)
    max_fn = max(max_fn, dg%fc_normal)
    max_ft = max(max_ft, dg%fc_tangential)
  end subroutine track

  !> Records at the output times in (t, t_stop], by cubic Hermite interpolation of the step.
  subroutine output_until(t_stop, hh, y0, f0, y1, f1)
    real(dp), intent(in) :: t_stop, hh, y0(:), f0(:), y1(:), f1(:)
    real(dp) :: th
    if (deck%dt_out <= 0.0_dp) return
    do while (next_out < t_stop)
      th = (next_out - t) / hh
      y_out = (1.0_dp - th) * y0 + th * y1 + th * (th - 1.0_dp) * ((1.0_dp - 2.0_dp * th) * (y1 - y0) &
              + (th - 1.0_dp) * hh * f0 + th * hh * f1)
      call write_record(next_out, y_out)
      next_out = next_out + deck%dt_out
    end do
  end subroutine output_until

  subroutine write_record(tt, yy)
    real(dp), intent(in) :: tt, yy(:)
    type(pair_diagnostics) :: dg
    call rhs_diag(yy, dg)
    write (csv, '(13(es23.15e3,","),i1,",",i1,5(",",es23.15e3))') tt, yy(1), yy(2), yy(3), &
      atan2(yy(2), yy(1)), dg%gap, dg%fc_normal, dg%fc_tangential, dg%n1star, dg%n2star, &
      dg%n1star_contact, dg%n2star_contact, dg%omega1(3), merge(1, 0, dg%in_contact), &
      merge(1, 0, dg%sliding), dg%omega2(3), dg%n1star_sphere(1), dg%n2star_sphere(1), &
      dg%n1star_sphere(2), dg%n2star_sphere(2)
  end subroutine write_record

  subroutine open_csv(path, unit)
    character(len=*), intent(in) :: path
    integer, intent(out) :: unit
    integer :: slash, stat
    slash = index(path, '/', back=.true.)
    if (slash > 1) call execute_command_line('mkdir -p "' // path(:slash - 1) // '"', exitstat=stat)
    open (newunit=unit, file=path, status='replace', action='write', iostat=ios, iomsg=msg)
    if (ios /= 0) call deck_fail(trim(deck_path), 'output', 'csv_file', 'cannot write ' // path // &
                                 ': ' // trim(msg))
  end subroutine open_csv

  subroutine run_fail(what)
    character(len=*), intent(in) :: what
    write (error_unit, '(a,a,a,f12.6,a,3f12.6)') 'pairtraj: ', what, ' at t = ', t, ', r = ', y(1:3)
    stop 3, quiet=.true.
  end subroutine run_fail

end program pairtraj
