! Relative motion of two inertialess, force- and torque-free spheres in unbounded simple shear
! u = (gamma_dot y, 0, 0), with the exact two-sphere hydrodynamics (mod_pair_resistance,
! mod_resistance_blocks) and the contact law of the reference paper (Gallier et al. 2014 JFM
! section 2.4, eqs 2.16-2.24; doc/METHOD.md §4 and §9). Units: a = eta = gamma_dot = 1, a the
! radius of sphere 1; sphere 2 has radius lambda a (the deck's size_ratio, default 1).
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
!
! Unequal spheres (lambda /= 1; lambda == 1 takes the equal-sphere arithmetic above, bitwise):
!   hydrodynamics from the unequal scalars (mod_pair_resistance_unequal, gap xi = 2|r|/(1 + lambda)
!   - 2) and the sized blocks (Jeffrey & Onishi 1984 scaling, doc/RESISTANCE.md "Unequal spheres");
!   contact as doc/CONTACT.md "Spheres of several sizes" with a = sphere 1's radius: delta' =
!   |r| - 1 - lambda - h_r, k = k_n sqrt(R*/(1/2)) with R* = lambda/(1 + lambda), slip
!   (U_1 - U_2)_t + (Om_1 + lambda Om_2) x n, torques n x F^c on 1 and lambda n x F^c on 2, contact
!   stresslets with the levers l_1 = (1 + g/2) n, l_2 = -(lambda + g/2) n (g = |r| - 1 - lambda);
!   N1*, N2* of the pair = 2 (S_1 + S_2)_(xx - yy, yy - zz) / (S_inf (1 + lambda^3)), the pair's
!   stresslet over that of the two spheres alone (at lambda = 1 the equal-sphere definition), and
!   per sphere 2 S_alpha / (S_inf a_alpha^3) (doc/PAIRTRAJ_INPUT.md "Output").
module mod_pair_dynamics
  use mod_kinds, only: dp, pi
  use mod_vector, only: cross, outer
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars
  use mod_pair_resistance_unequal, only: sized_pair_scalars, sized_pair_scalars_22
  use mod_resistance_blocks, only: pair_resistance_fu, pair_resistance_fe, pair_stresslets, &
                                   pair_resistance_fu_sized, pair_resistance_fe_sized, &
                                   pair_stresslets_sized
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
    real(dp) :: lambda = 1.0_dp     ! radius of sphere 2 (sphere 1: 1)
    real(dp) :: k_pair = 0.0_dp     ! Hertz stiffness of this pair, k_n sqrt(R*/(1/2))
  end type pair_model

  !> Everything written per output record.
  type :: pair_diagnostics
    real(dp) :: gap = 0.0_dp              ! true surface gap |r| - 2
    real(dp) :: fc_normal = 0.0_dp        ! |F_n|, repulsive normal contact force
    real(dp) :: fc_tangential = 0.0_dp    ! |F_t|
    real(dp) :: n1star = 0.0_dp, n2star = 0.0_dp                 ! total (JFM 3.1, 3.2)
    real(dp) :: n1star_contact = 0.0_dp, n2star_contact = 0.0_dp ! contact stresslet part
    real(dp) :: omega1(3) = 0.0_dp        ! angular velocity of sphere 1
    real(dp) :: omega2(3) = 0.0_dp        ! angular velocity of sphere 2
    real(dp) :: n1star_sphere(2) = 0.0_dp, n2star_sphere(2) = 0.0_dp ! per sphere, 2 S_a/(S_inf a_a^3)
    logical :: in_contact = .false.
    logical :: sliding = .false.
  end type pair_diagnostics

  ! Ambient simple shear, gamma_dot = 1: u = (y, 0, 0), Om = (0, 0, -1/2), E = (e_x e_y + e_y e_x)/2.
  real(dp), parameter :: omega_inf(3) = [0.0_dp, 0.0_dp, -0.5_dp]
  real(dp), parameter :: shear_strain(3, 3) = reshape([0.0_dp, 0.5_dp, 0.0_dp, 0.5_dp, 0.0_dp, &
                                                       0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp], [3, 3])
  real(dp), parameter :: stresslet_unit = 20.0_dp / 3.0_dp * pi   ! S_inf

contains

  !> Contact constants from the deck values (JFM section 2.4); size_ratio = lambda, the radius of
  !> sphere 2 in units of sphere 1's.
  pure function make_pair_model(eps_r, eps_bar, mu_d, kn_smooth, size_ratio) result(model)
    real(dp), intent(in) :: eps_r, eps_bar, mu_d, kn_smooth, size_ratio
    type(pair_model) :: model
    model%h_r = eps_r
    model%mu_d = mu_d
    model%lambda = size_ratio
    if (eps_r > 0.0_dp) then
      ! Balance 6 pi eta gamma_dot a^2 = k_n (eps_bar h_r)^{3/2}.
      model%k_n = 6.0_dp * pi / (eps_bar * eps_r)**1.5_dp
    else
      model%k_n = kn_smooth
    end if
    model%k_pair = model%k_n
    ! Hertz: stiffness as sqrt(R*), normalised by R* = 1/2 of two unit spheres (doc/CONTACT.md).
    if (size_ratio /= 1.0_dp) model%k_pair = model%k_n * sqrt(2.0_dp * size_ratio / (1.0_dp + size_ratio))
  end function make_pair_model

  !> Time derivative of the state, and (optionally) the diagnostics at that state.
  subroutine pair_rates(model, y, dydt, diag)
    type(pair_model), intent(in) :: model
    real(dp), intent(in) :: y(pair_state_size)
    real(dp), intent(out) :: dydt(pair_state_size)
    type(pair_diagnostics), intent(out), optional :: diag
    real(dp) :: r(3), rho, d(3), gap, overlap, f(n_pair_scalars), rfu(12, 12), rfe(12, 3, 3)
    real(dp) :: fc(3), fn_mag, ft(3), kt, rhs(12), w(12), u1(3), u2(3), om1(3), om2(3), us(3)
    real(dp) :: s(3, 3, 2), sc(3, 3), stot(3, 3), ups(3), ft_mag, x1(3), x2(3), f2(n_pair_scalars)
    real(dp) :: sc2(3, 3), lam
    logical :: contact, sliding, sized
    integer :: m

    lam = model%lambda
    sized = lam /= 1.0_dp
    r = y(1:3)
    ups = y(4:6)
    rho = norm2(r)
    d = r / rho
    if (sized) then
      gap = rho - 1.0_dp - lam         ! true surface gap g
    else
      gap = rho - 2.0_dp
    end if
    overlap = gap - model%h_r          ! delta' (negative in contact)
    contact = overlap < 0.0_dp
    sliding = .false.

    ! Contact force on sphere 1.
    fc = 0.0_dp
    fn_mag = 0.0_dp
    ft = 0.0_dp
    ft_mag = 0.0_dp
    if (contact) then
      fn_mag = model%k_pair * abs(overlap)**1.5_dp
      fc = -fn_mag * d
      if (model%mu_d > 0.0_dp) then
        kt = 2.0_dp / 7.0_dp * model%k_pair * sqrt(abs(overlap))
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
    if (sized) then
      ! Jeffrey & Onishi's gap 2|r|/(a_1 + a_2) - 2.
      f = sized_pair_scalars(max(2.0_dp * gap / (1.0_dp + lam), 1.0e-12_dp), lam)
      f2 = sized_pair_scalars_22(max(2.0_dp * gap / (1.0_dp + lam), 1.0e-12_dp), lam)
      rfu = pair_resistance_fu_sized(f, f2, d, 1.0_dp, lam, 1.0_dp)
      rfe = pair_resistance_fe_sized(f, f2, d, 1.0_dp, lam, 1.0_dp)
    else
      f = resistance_scalars(max(gap, 1.0e-12_dp))
      rfu = pair_resistance_fu(f, d, 1.0_dp, 1.0_dp)
      rfe = pair_resistance_fe(f, d, 1.0_dp, 1.0_dp)
    end if
    do m = 1, 12
      rhs(m) = -sum(rfe(m, :, :) * shear_strain)
    end do
    rhs(1:3) = rhs(1:3) - fc
    rhs(4:6) = rhs(4:6) - cross(d, fc)     ! T^c_1 = a n x F^c_1
    rhs(7:9) = rhs(7:9) + fc
    if (sized) then
      rhs(10:12) = rhs(10:12) - lam * cross(d, fc)   ! T^c_2 = a_2 n x F^c_1
    else
      rhs(10:12) = rhs(10:12) - cross(d, fc) ! T^c_2 = a n x F^c_1 as well
    end if
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
      if (sized) then
        ! Relative velocity of the surface points x_1 + a_1 n and x_2 - a_2 n.
        us = (u1 - u2) - dot_product(u1 - u2, d) * d + cross(om1 + lam * om2, d)
      else
        us = (u1 - u2) - dot_product(u1 - u2, d) * d + cross(om1 + om2, d)
      end if
      dydt(4:6) = us - dot_product(us, d) * d
    end if

    if (present(diag)) then
      if (sized) then
        s = pair_stresslets_sized(f, f2, d, w, shear_strain, 1.0_dp, lam, 1.0_dp)
        ! Contact stresslets with the levers to the middle of the gap (doc/CONTACT.md).
        sc = 0.5_dp * (outer(fc, (1.0_dp + 0.5_dp * gap) * d) + outer((1.0_dp + 0.5_dp * gap) * d, fc))
        sc2 = 0.5_dp * (outer(fc, (lam + 0.5_dp * gap) * d) + outer((lam + 0.5_dp * gap) * d, fc))
        stot = s(:, :, 1) + s(:, :, 2) + sc + sc2
        diag%n1star = 2.0_dp * (stot(1, 1) - stot(2, 2)) / (stresslet_unit * (1.0_dp + lam**3))
        diag%n2star = 2.0_dp * (stot(2, 2) - stot(3, 3)) / (stresslet_unit * (1.0_dp + lam**3))
        diag%n1star_contact = 2.0_dp * (sc(1, 1) + sc2(1, 1) - sc(2, 2) - sc2(2, 2)) &
                              / (stresslet_unit * (1.0_dp + lam**3))
        diag%n2star_contact = 2.0_dp * (sc(2, 2) + sc2(2, 2) - sc(3, 3) - sc2(3, 3)) &
                              / (stresslet_unit * (1.0_dp + lam**3))
        stot = s(:, :, 1) + sc
      else
        s = pair_stresslets(f, d, w, shear_strain, 1.0_dp, 1.0_dp)
        ! Contact stresslet of sphere 1: (1/2)(F^c r/2 + r/2 F^c), r = x_2 - x_1.
        sc = 0.25_dp * (outer(fc, r) + outer(r, fc))
        sc2 = sc
        stot = s(:, :, 1) + sc
        diag%n1star = 2.0_dp * (stot(1, 1) - stot(2, 2)) / stresslet_unit
        diag%n2star = 2.0_dp * (stot(2, 2) - stot(3, 3)) / stresslet_unit
        diag%n1star_contact = 2.0_dp * (sc(1, 1) - sc(2, 2)) / stresslet_unit
        diag%n2star_contact = 2.0_dp * (sc(2, 2) - sc(3, 3)) / stresslet_unit
      end if
      diag%n1star_sphere(1) = 2.0_dp * (stot(1, 1) - stot(2, 2)) / stresslet_unit
      diag%n2star_sphere(1) = 2.0_dp * (stot(2, 2) - stot(3, 3)) / stresslet_unit
      ! Sphere 2: -F^c with the lever l_2 = -(a_2 + g/2) n gives the same sign as sphere 1's.
      stot = s(:, :, 2) + sc2
      diag%n1star_sphere(2) = 2.0_dp * (stot(1, 1) - stot(2, 2)) / (stresslet_unit * lam**3)
      diag%n2star_sphere(2) = 2.0_dp * (stot(2, 2) - stot(3, 3)) / (stresslet_unit * lam**3)
      diag%gap = gap
      diag%fc_normal = fn_mag
      diag%fc_tangential = ft_mag
      diag%omega1 = om1
      diag%omega2 = om2
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
    if (model%lambda /= 1.0_dp) then
      overlap = norm2(y(1:3)) - 1.0_dp - model%lambda - model%h_r
    else
      overlap = norm2(y(1:3)) - 2.0_dp - model%h_r
    end if
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
