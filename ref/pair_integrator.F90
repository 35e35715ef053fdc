! Adaptive explicit Runge-Kutta integrator for pairtraj: Dormand & Prince (1980) 5(4) pair,
! FSAL, with the PI step-size controller and the stiffness detector of Hairer, Norsett & Wanner
! (Solving ODEs I, section II.4 and II.10 (DOPRI5)).
!
! Why an explicit method (doc/PAIRTRAJ_INPUT.md, "integrator"): the pair equations are only
! mildly stiff. Their fastest time scales are the contact relaxations, tau_n ~ eps_bar/3 (normal,
! doc/METHOD.md §4.3) and tau_t ~ R_t/k_t ~ 1e-4..1e-2 (tangential spring) in units of 1/gamma_dot,
! against O(10) for the whole passage: a stiffness ratio of 1e2..1e4. An explicit 5th-order
! method then costs a few thousand stability-limited steps during contact (well under a second)
! and needs no Jacobian of a right-hand side that contains a Coulomb cap and Hertz
! |delta'|^{3/2} (non-smooth, where Rosenbrock/implicit methods lose their order and need a
! Jacobian that jumps). The step controller rejects unstable steps, and the stiffness detector
! counts the steps whose size stability rather than accuracy limited ("stiff-aware"): pairtraj
! reports the count, and a run that is stiffness-bound for most steps (eps_bar << 0.01) is told
! so in its summary.
module mod_pair_integrator
  use mod_kinds, only: dp
  implicit none
  private
  public :: rk_rhs, dopri5_step, error_norm

  abstract interface
    subroutine rk_rhs(y, dydt)
      import :: dp
      real(dp), intent(in) :: y(:)
      real(dp), intent(out) :: dydt(:)
    end subroutine rk_rhs
  end interface

  ! Dormand-Prince coefficients (the system is autonomous, so the nodes c_i are not needed).
  real(dp), parameter :: a21 = 1.0_dp / 5
  real(dp), parameter :: a31 = 3.0_dp / 40, a32 = 9.0_dp / 40
  real(dp), parameter :: a41 = 44.0_dp / 45, a42 = -56.0_dp / 15, a43 = 32.0_dp / 9
  real(dp), parameter :: a51 = 19372.0_dp / 6561, a52 = -25360.0_dp / 2187, &
                         a53 = 64448.0_dp / 6561, a54 = -212.0_dp / 729
  real(dp), parameter :: a61 = 9017.0_dp / 3168, a62 = -355.0_dp / 33, a63 = 46732.0_dp / 5247, &
                         a64 = 49.0_dp / 176, a65 = -5103.0_dp / 18656
  real(dp), parameter :: a71 = 35.0_dp / 384, a73 = 500.0_dp / 1113, a74 = 125.0_dp / 192, &
                         a75 = -2187.0_dp / 6784, a76 = 11.0_dp / 84
  real(dp), parameter :: e1 = 71.0_dp / 57600, e3 = -71.0_dp / 16695, e4 = 71.0_dp / 1920, &
                         e5 = -17253.0_dp / 339200, e6 = 22.0_dp / 525, e7 = -1.0_dp / 40

contains

  !> One Dormand-Prince step of size h from y (with k1 = f(y) given). Returns the 5th-order
  !> solution y_new, f(y_new) (FSAL), the scaled error norm err (accept if <= 1) and the
  !> stiffness indicator h*lambda ~ h |f(y_new) - f(y6)| / |y_new - y6| (> 3.25: the step sits at
  !> the stability boundary of the method).
  subroutine dopri5_step(rhs, y, k1, h, rtol, atol, y_new, k7, err, h_lambda)
    procedure(rk_rhs) :: rhs
    real(dp), intent(in) :: y(:), k1(:), h, rtol, atol
    real(dp), intent(out) :: y_new(:), k7(:), err, h_lambda
    real(dp), dimension(size(y)) :: k2, k3, k4, k5, k6, y_stage, y6, e
    real(dp) :: den
    y_stage = y + h * a21 * k1
    call rhs(y_stage, k2)
    y_stage = y + h * (a31 * k1 + a32 * k2)
    call rhs(y_stage, k3)
    y_stage = y + h * (a41 * k1 + a42 * k2 + a43 * k3)
    call rhs(y_stage, k4)
    y_stage = y + h * (a51 * k1 + a52 * k2 + a53 * k3 + a54 * k4)
    call rhs(y_stage, k5)
    y6 = y + h * (a61 * k1 + a62 * k2 + a63 * k3 + a64 * k4 + a65 * k5)
    call rhs(y6, k6)
    y_new = y + h * (a71 * k1 + a73 * k3 + a74 * k4 + a75 * k5 + a76 * k6)
    call rhs(y_new, k7)
    e = h * (e1 * k1 + e3 * k3 + e4 * k4 + e5 * k5 + e6 * k6 + e7 * k7)
    err = error_norm(e, y, y_new, rtol, atol)
    den = norm2(y_new - y6)
    if (den > 0.0_dp) then
      h_lambda = h * norm2(k7 - k6) / den
    else
      h_lambda = 0.0_dp
    end if
  end subroutine dopri5_step

  !> RMS norm of the error scaled by atol + rtol max(|y|, |y_new|).
  pure function error_norm(e, y, y_new, rtol, atol) result(err)
    real(dp), intent(in) :: e(:), y(:), y_new(:), rtol, atol
    real(dp) :: err
    err = sqrt(sum((e / (atol + rtol * max(abs(y), abs(y_new))))**2) / size(e))
  end function error_norm

end module mod_pair_integrator
