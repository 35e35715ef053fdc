! Relative motion of two equal, inertialess, force- and torque-free spheres in unbounded simple
! shear u = (gamma_dot y, 0, 0), with the exact two-sphere hydrodynamics (mod_pair_resistance,
! mod_resistance_blocks) and the contact law of the reference paper (Gallier et al. 2014 JFM
! section 2.4, eqs 2.16-2.24; doc/METHOD.md §4 and §9). Units: a = eta = gamma_dot = 1.
!
! State y = (r, Upsilon): r = x_2 - x_1 (units of a) and the tangential spring elongation
! Upsilon (JFM 2.20), integrated only while the rough surfaces touch. The spheres sit at
! x_1 = -r/2 and x_2 = +r/2 (only r matters: the ambient flow is linear).
!
! Velocities: the 12 unknowns (U_1, Om_1, U_2, Om_2) follow from the force and torque balance
! F^h + F^c = 0 (JFM 2.5, 2.6) with F^h = R_FU . (U^inf - U) + R_FE : E^inf (JFM 2.10):
!   R_FU . w = -(R_FE : E + F^c),  w = U^inf - U,
! solved by Cholesky (R_FU is symmetric positive definite, test_resistance_blocks). Using the full
! 12x12 form rather than the 6-unknown symmetric reduction of doc/METHOD.md §9.1 keeps pairtraj on the
! same blocks as the solver's lubrication correction; both are equivalent here.
!
! Contact (force F^c on sphere 1 exerted by sphere 2, n = d = r/|r| from 1 to 2):
!   delta = |r| - 2 (true gap, used by the hydrodynamics), delta' = delta - h_r (JFM fig. 1);
!   in contact when delta' < 0:
!   F_n = -k_n |delta'|^{3/2} n (JFM 2.17), k_n = 6 pi eta gamma_dot a^2 / (eps_bar h_r)^{3/2}
!     (JFM section 2.4), or kn_smooth when h_r = 0;
!   F_t = -k_t Upsilon (JFM 2.19), k_t = (2/7) k_n |delta'|^{1/2}, dUpsilon/dt = U^s (JFM 2.20),
!     U^s = (U_1 - U_2) - [(U_1 - U_2).n] n + a (Om_1 + Om_2) x n (JFM 2.21);
!   Coulomb: |F_t| <= mu_d |F_n| (JFM 2.22), with the DEM return mapping after each step
!     (Upsilon rescaled so that k_t |Upsilon| = mu_d |F_n|, i.e. |Upsilon| <= (7/2) mu_d |delta'|),
!     Upsilon kept in the tangent plane, and reset to 0 when the contact opens (doc/METHOD.md §4.2);
!   torques T^c_1 = T^c_2 = a n x F^c (JFM 2.23); sphere 2 receives -F^c.
! Stresslets: S^h from R_SU . w + R_SE : E (JFM 2.13, mod_resistance_blocks pair_stresslets), and
! S^c = (1/2)(F^c r/2 + r/2 F^c) per sphere (JFM 2.24, sphere 1: F^c_1 and r = x_2 - x_1; sphere 2
! gives the same). N1* = 2 (S_xx - S_yy) / S_inf, N2* = 2 (S_yy - S_zz) / S_inf with S = S^h + S^c
! of one sphere and S_inf = (20/3) pi eta a^3 gamma_dot (JFM 3.1, 3.2).
module mod_pair_dynamics
  use mod_kinds, only: dp, pi
  use mod_vector, only: cross, outer
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars
  use mod_resistance_blocks, only: pair_resistance_fu, pair_resistance_fe, pair_stresslets
  implicit none
  private
  public :: pair_model, pair_diagnostics, pair_state_size, make_pair_model, pair_rates, &
            project_spring, shear_strain

  integer, parameter :: pair_state_size = 6

  !> Contact-law constants.
  type :: pair_model
    real(dp) :: h_r = 0.0_dp        ! roughness height (units of a)
    real(dp) :: k_n = 0.0_dp        ! Hertz stiffness
    real(dp) :: mu_d = 0.0_dp       ! Coulomb friction coefficient
  end type pair_model

  !> Everything written per output record.
  type :: pair_diagnostics
    real(dp) :: gap = 0.0_dp              ! true surface gap |r| - 2
    real(dp) :: fc_normal = 0.0_dp        ! |F_n|, repulsive normal contact force
    real(dp) :: fc_tangential = 0.0_dp    ! |F_t|
    real(dp) :: n1star = 0.0_dp, n2star = 0.0_dp                 ! total (JFM 3.1, 3.2)
    real(dp) :: n1star_contact = 0.0_dp, n2star_contact = 0.0_dp ! contact stresslet part
    real(dp) :: omega1(3) = 0.0_dp        ! angular velocity of sphere 1
    logical :: in_contact = .false.
    logical :: sliding = .false.
  end type pair_diagnostics

  ! Ambient simple shear, gamma_dot = 1: u = (y, 0, 0), Om = (0, 0, -1/2), E = (e_x e_y + e_y e_x)/2.
  real(dp), parameter :: omega_inf(3) = [0.0_dp, 0.0_dp, -0.5_dp]
  real(dp), parameter :: shear_strain(3, 3) = reshape([0.0_dp, 0.5_dp, 0.0_dp, 0.5_dp, 0.0_dp, &
                                                       0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp], [3, 3])
  real(dp), parameter :: stresslet_unit = 20.0_dp / 3.0_dp * pi   ! S_inf

contains

  !> Contact constants from the deck values (JFM section 2.4).
  pure function make_pair_model(eps_r, eps_bar, mu_d, kn_smooth) result(model)
    real(dp), intent(in) :: eps_r, eps_bar, mu_d, kn_smooth
    type(pair_model) :: model
    model%h_r = eps_r
    model%mu_d = mu_d
    if (eps_r > 0.0_dp) then
      ! Balance 6 pi eta gamma_dot a^2 = k_n (eps_bar h_r)^{3/2}.
      model%k_n = 6.0_dp * pi / (eps_bar * eps_r)**1.5_dp
    else
      model%k_n = kn_smooth
    end if
  end function make_pair_model

  !> Time derivative of the state, and (optionally) the diagnostics at that state.
  subroutine pair_rates(model, y, dydt, diag)
    type(pair_model), intent(in) :: model
    real(dp), intent(in) :: y(pair_state_size)
    real(dp), intent(out) :: dydt(pair_state_size)
    type(pair_diagnostics), intent(out), optional :: diag
    real(dp) :: r(3), rho, d(3), gap, overlap, f(n_pair_scalars), rfu(12, 12), rfe(12, 3, 3)
    real(dp) :: fc(3), fn_mag, ft(3), kt, rhs(12), w(12), u1(3), u2(3), om1(3), om2(3), us(3)
    real(dp) :: s(3, 3, 2), sc(3, 3), stot(3, 3), ups(3), ft_mag, x1(3), x2(3)
    logical :: contact, sliding
    integer :: m

    r = y(1:3)
    ups = y(4:6)
    rho = norm2(r)
    d = r / rho
    gap = rho - 2.0_dp
    overlap = gap - model%h_r          ! delta' (negative in contact)
    contact = overlap < 0.0_dp
    sliding = .false.

    ! Contact force on sphere 1.
    fc = 0.0_dp
    fn_mag = 0.0_dp
    ft = 0.0_dp
    ft_mag = 0.0_dp
    if (contact) then
      fn_mag = model%k_n * abs(overlap)**1.5_dp
      fc = -fn_mag * d
      if (model%mu_d > 0.0_dp) then
        kt = 2.0_dp / 7.0_dp * model%k_n * sqrt(abs(overlap))
        ups = ups - dot_product(ups, d) * d
        ft = -kt * ups
        ft_mag = norm2(ft)
        if (ft_mag > model%mu_d * fn_mag) then
          ft = ft * (model%mu_d * fn_mag / ft_mag)
          ft_mag = model%mu_d * fn_mag
          sliding = .true.
        end if
        fc = fc + ft
      end if
    end if

    ! Hydrodynamics: R_FU . w = -(R_FE : E + F^c).
    f = resistance_scalars(max(gap, 1.0e-12_dp))
    rfu = pair_resistance_fu(f, d, 1.0_dp, 1.0_dp)
    rfe = pair_resistance_fe(f, d, 1.0_dp, 1.0_dp)
    do m = 1, 12
      rhs(m) = -sum(rfe(m, :, :) * shear_strain)
    end do
    rhs(1:3) = rhs(1:3) - fc
    rhs(4:6) = rhs(4:6) - cross(d, fc)     ! T^c_1 = a n x F^c_1
    rhs(7:9) = rhs(7:9) + fc
    rhs(10:12) = rhs(10:12) - cross(d, fc) ! T^c_2 = a n x F^c_1 as well
    w = solve_spd(rfu, rhs)

    x1 = -0.5_dp * r
    x2 = 0.5_dp * r
    u1 = [x1(2), 0.0_dp, 0.0_dp] - w(1:3)
    om1 = omega_inf - w(4:6)
    u2 = [x2(2), 0.0_dp, 0.0_dp] - w(7:9)
    om2 = omega_inf - w(10:12)

    dydt(1:3) = u2 - u1
    dydt(4:6) = 0.0_dp
    if (contact .and. model%mu_d > 0.0_dp) then
      us = (u1 - u2) - dot_product(u1 - u2, d) * d + cross(om1 + om2, d)
      dydt(4:6) = us - dot_product(us, d) * d
    end if

    if (present(diag)) then
      s = pair_stresslets(f, d, w, shear_strain, 1.0_dp, 1.0_dp)
      ! Contact stresslet of sphere 1: (1/2)(F^c r/2 + r/2 F^c), r = x_2 - x_1.
      sc = 0.25_dp * (outer(fc, r) + outer(r, fc))
      stot = s(:, :, 1) + sc
      diag%gap = gap
      diag%fc_normal = fn_mag
      diag%fc_tangential = ft_mag
      diag%n1star = 2.0_dp * (stot(1, 1) - stot(2, 2)) / stresslet_unit
      diag%n2star = 2.0_dp * (stot(2, 2) - stot(3, 3)) / stresslet_unit
      diag%n1star_contact = 2.0_dp * (sc(1, 1) - sc(2, 2)) / stresslet_unit
      diag%n2star_contact = 2.0_dp * (sc(2, 2) - sc(3, 3)) / stresslet_unit
      diag%omega1 = om1
      diag%in_contact = contact
      diag%sliding = sliding
    end if
  end subroutine pair_rates

  !> DEM return mapping after an accepted step (doc/METHOD.md §4.2): keep Upsilon in the tangent
  !> plane with its length, cap it at the Coulomb limit, reset it when the contact is open.
  !> Returns changed = .true. if the state was modified.
  subroutine project_spring(model, y, changed)
    type(pair_model), intent(in) :: model
    real(dp), intent(inout) :: y(pair_state_size)
    logical, intent(out) :: changed
    real(dp) :: d(3), overlap, ups(3), len0, len1, cap
    changed = .false.
    ups = y(4:6)
    if (all(ups == 0.0_dp)) return
    d = y(1:3) / norm2(y(1:3))
    overlap = norm2(y(1:3)) - 2.0_dp - model%h_r
    if (overlap >= 0.0_dp .or. model%mu_d <= 0.0_dp) then
      y(4:6) = 0.0_dp
      changed = .true.
      return
    end if
    len0 = norm2(ups)
    ups = ups - dot_product(ups, d) * d
    len1 = norm2(ups)
    if (len1 > 0.0_dp) ups = ups * (len0 / len1)
    ! k_t |Upsilon| <= mu_d |F_n|  <=>  |Upsilon| <= (7/2) mu_d |delta'|.
    cap = 3.5_dp * model%mu_d * abs(overlap)
    if (norm2(ups) > cap) ups = ups * (cap / norm2(ups))
    changed = any(ups /= y(4:6))
    y(4:6) = ups
  end subroutine project_spring

  !> Solve A x = b for symmetric positive definite A (Cholesky).
  pure function solve_spd(a_in, b) result(x)
    real(dp), intent(in) :: a_in(:, :), b(:)
    real(dp) :: x(size(b)), l(size(b), size(b))
    integer :: n, i, j
    n = size(b)
    l = 0.0_dp
    do j = 1, n
      l(j, j) = sqrt(a_in(j, j) - sum(l(j, 1:j - 1)**2))
      do i = j + 1, n
        l(i, j) = (a_in(i, j) - sum(l(i, 1:j - 1) * l(j, 1:j - 1))) / l(j, j)
      end do
    end do
    x = b
    do i = 1, n
      x(i) = (x(i) - sum(l(i, 1:i - 1) * x(1:i - 1))) / l(i, i)
    end do
    do i = n, 1, -1
      x(i) = (x(i) - sum(l(i + 1:n, i) * x(i + 1:n))) / l(i, i)
    end do
  end function solve_spd

end module mod_pair_dynamics
