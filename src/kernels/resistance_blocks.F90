! Resistance tensors from the scalar functions: the pair blocks R_FU (12x12), R_FE, R_SU, R_SE and
! their written-out contractions (force and torque from the strain, the stresslets; doc/METHOD.md
! §5.1 and §5.7), and the 6x6 sphere-wall block (doc/METHOD.md §5.2, §5.8).
!
! The blocks take the scalars as arguments (the exact theory of mod_pair_resistance, or theory
! minus what the grid resolves for the subgrid correction), the unit vector d from sphere 1 to
! sphere 2, the radius and the viscosity; conventions (tensor forms, normalisation, exchange
! symmetry, 12-vector order) as in mod_pair_resistance and doc/RESISTANCE.md.
!
! Pure Fortran (no PETSc, MPI or HDF5): used by the lubrication correction and bin/pairtraj.
module mod_resistance_blocks
  use mod_kinds, only: dp, pi
  use mod_vector, only: cross
  use mod_pair_resistance, only: n_pair_scalars, i_xa11, i_ya11, i_yb11, i_xc11, i_yc11, i_xg11, &
       i_yg11, i_yh11, i_xm11, i_ym11, i_zm11, i_xg12, i_yg12, i_yh12, i_xm12, i_ym12, i_zm12
  use mod_wall_resistance, only: wall_normal_resistance, wall_tangential_resistance, &
       wall_twist_resistance
  implicit none
  private

  public :: pair_resistance_fu, pair_resistance_fe, pair_resistance_su, pair_resistance_se
  public :: pair_resistance_fu_sized, pair_resistance_fe_sized, pair_resistance_su_sized, &
            pair_resistance_se_sized, pair_stresslets_sized
  public :: pair_force_torque_from_strain, pair_stresslets
  public :: strain_d0, strain_d1, strain_d2
  public :: wall_resistance_fu, wall_resistance_block

  ! Exchange sign of each base scalar: f22 = sgn f11, f21 = sgn f12 (doc/METHOD.md §5.1).
  real(dp), parameter :: exchange_sign(11) = [1, 1, -1, 1, 1, -1, -1, 1, 1, 1, 1] * 1.0_dp

contains

  ! ---------------------------------------------------------------------------------------------
  ! Pair resistance blocks (doc/METHOD.md §5.1 and §5.7)
  ! ---------------------------------------------------------------------------------------------

  !> Scalar of base index k (1..11) for the block (alpha, beta), from f(22) = (11-scalars, 12-scalars).
  pure function block_scalar(f, k, alpha, beta) result(v)
    real(dp), intent(in) :: f(n_pair_scalars)
    integer, intent(in) :: k, alpha, beta
    real(dp) :: v
    if (alpha == beta) then
      v = f(k)
      if (alpha == 2) v = exchange_sign(k) * v
    else
      v = f(k + 11)
      if (alpha == 2) v = exchange_sign(k) * v
    end if
  end function block_scalar

  pure function levi_civita(i, j, k) result(e)
    integer, intent(in) :: i, j, k
    real(dp) :: e
    e = real((i - j) * (j - k) * (k - i), dp) / 2.0_dp
  end function levi_civita

  pure function kron(i, j) result(v)
    integer, intent(in) :: i, j
    real(dp) :: v
    v = merge(1.0_dp, 0.0_dp, i == j)
  end function kron

  !> Third-rank G tensor (K&K 11.2): G_ijk = XG (d_i d_j - delta_ij/3) d_k
  !> + YG (d_i delta_jk + d_j delta_ik - 2 d_i d_j d_k).
  pure function g_tensor(xg, yg, d) result(g)
    real(dp), intent(in) :: xg, yg, d(3)
    real(dp) :: g(3, 3, 3)
    integer :: i, j, k
    do k = 1, 3
      do j = 1, 3
        do i = 1, 3
          g(i, j, k) = xg * (d(i) * d(j) - kron(i, j) / 3.0_dp) * d(k) &
                       + yg * (d(i) * kron(j, k) + d(j) * kron(i, k) - 2.0_dp * d(i) * d(j) * d(k))
        end do
      end do
    end do
  end function g_tensor

  !> Third-rank H tensor: H_ijk = YH (eps_ikl d_l d_j + eps_jkl d_l d_i).
  pure function h_tensor(yh, d) result(h)
    real(dp), intent(in) :: yh, d(3)
    real(dp) :: h(3, 3, 3)
    integer :: i, j, k, l
    h = 0.0_dp
    do k = 1, 3
      do j = 1, 3
        do i = 1, 3
          do l = 1, 3
            h(i, j, k) = h(i, j, k) + yh * (levi_civita(i, k, l) * d(l) * d(j) &
                                            + levi_civita(j, k, l) * d(l) * d(i))
          end do
        end do
      end do
    end do
  end function h_tensor

  !> Fourth-rank M tensor, M = XM d0 + YM d1 + ZM d2 (K&K 11.2; Jeffrey 1992).
  pure function m_tensor(xm, ym, zm, d) result(m)
    real(dp), intent(in) :: xm, ym, zm, d(3)
    real(dp) :: m(3, 3, 3, 3)
    integer :: i, j, k, l
    real(dp) :: d0, d1, d2
    do l = 1, 3
      do k = 1, 3
        do j = 1, 3
          do i = 1, 3
            d0 = 1.5_dp * (d(i) * d(j) - kron(i, j) / 3.0_dp) * (d(k) * d(l) - kron(k, l) / 3.0_dp)
            d1 = 0.5_dp * (d(i) * kron(j, l) * d(k) + d(j) * kron(i, l) * d(k) &
                           + d(i) * kron(j, k) * d(l) + d(j) * kron(i, k) * d(l) &
                           - 4.0_dp * d(i) * d(j) * d(k) * d(l))
            d2 = 0.5_dp * (kron(i, k) * kron(j, l) + kron(j, k) * kron(i, l) - kron(i, j) * kron(k, l) &
                           + d(i) * d(j) * kron(k, l) + kron(i, j) * d(k) * d(l) &
                           + d(i) * d(j) * d(k) * d(l) &
                           - d(i) * kron(j, l) * d(k) - d(j) * kron(i, l) * d(k) &
                           - d(i) * kron(j, k) * d(l) - d(j) * kron(i, k) * d(l))
            m(i, j, k, l) = xm * d0 + ym * d1 + zm * d2
          end do
        end do
      end do
    end do
  end function m_tensor

  !> 12x12 resistance R_FU: (F_1, T_1, F_2, T_2) = R_FU . (U^inf_1 - U_1, Om^inf - Om_1,
  !> U^inf_2 - U_2, Om^inf - Om_2). f(22) are the scalars (theory, or theory minus numerics for
  !> the subgrid correction); d is the unit vector from sphere 1 to sphere 2.
  pure function pair_resistance_fu(f, d, radius, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), radius, viscosity
    real(dp) :: r(12, 12)
    r = fu_blocks(equal_block_scalars(f), spread_scale(6.0_dp * pi * viscosity * radius), &
                  spread_scale(4.0_dp * pi * viscosity * radius**2), &
                  spread_scale(8.0_dp * pi * viscosity * radius**3), d)
  end function pair_resistance_fu

  !> R_FU of two UNEQUAL spheres, radii a1 and a2: f are the 11 and 12 scalars and f2 the 22 and
  !> 21 scalars (sized_pair_scalars, sized_pair_scalars_22 of mod_pair_resistance_unequal), scaled
  !> as Jeffrey & Onishi (1984) scale them: block (alpha, beta) by 3 pi eta (a_alpha + a_beta) for
  !> A, pi eta (a_alpha + a_beta)^2 for B, pi eta (a_alpha + a_beta)^3 for C (doc/RESISTANCE.md
  !> "Unequal spheres"). Same layout and d as pair_resistance_fu.
  pure function pair_resistance_fu_sized(f, f2, d, a1, a2, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), f2(n_pair_scalars), d(3), a1, a2, viscosity
    real(dp) :: r(12, 12)
    real(dp) :: sum_a(2, 2)
    sum_a = radius_sums(a1, a2)
    r = fu_blocks(sized_block_scalars(f, f2), 3.0_dp * pi * viscosity * sum_a, &
                  pi * viscosity * sum_a**2, pi * viscosity * sum_a**3, d)
  end function pair_resistance_fu_sized

  !> R_FU from the scalars s(k, alpha, beta) of each block and each block's dimensional factors
  !> of A, B and C.
  pure function fu_blocks(s, ca, cb, cc, d) result(r)
    real(dp), intent(in) :: s(11, 2, 2), ca(2, 2), cb(2, 2), cc(2, 2), d(3)
    real(dp) :: r(12, 12)
    integer :: alpha, beta, i, j, k, ro, co
    real(dp) :: xa, ya, yb, xc, yc, bij
    r = 0.0_dp
    do alpha = 1, 2
      do beta = 1, 2
        ro = 6 * (alpha - 1)
        co = 6 * (beta - 1)
        xa = s(i_xa11, alpha, beta)
        ya = s(i_ya11, alpha, beta)
        yb = s(i_yb11, alpha, beta)
        xc = s(i_xc11, alpha, beta)
        yc = s(i_yc11, alpha, beta)
        do j = 1, 3
          do i = 1, 3
            r(ro + i, co + j) = ca(alpha, beta) * (xa * d(i) * d(j) + ya * (kron(i, j) - d(i) * d(j)))
            r(ro + 3 + i, co + 3 + j) = cc(alpha, beta) * (xc * d(i) * d(j) + yc * (kron(i, j) - d(i) * d(j)))
            bij = 0.0_dp
            do k = 1, 3
              bij = bij + levi_civita(i, j, k) * d(k)
            end do
            ! T_alpha <- U_beta: B^ab ; F_beta <- Om_alpha: Bt^ba_ji = B^ab_ij (transpose).
            r(ro + 3 + i, co + j) = cb(alpha, beta) * yb * bij
            r(co + j, ro + 3 + i) = cb(alpha, beta) * yb * bij
          end do
        end do
      end do
    end do
  end function fu_blocks

  !> R_FE as a 12x3x3 array: (F_1, T_1, F_2, T_2)_m = sum_jk r(m, j, k) E_jk.
  pure function pair_resistance_fe(f, d, radius, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), radius, viscosity
    real(dp) :: r(12, 3, 3)
    r = fe_blocks(equal_block_scalars(f), spread_scale(4.0_dp * pi * viscosity * radius**2), &
                  spread_scale(8.0_dp * pi * viscosity * radius**3), d)
  end function pair_resistance_fe

  !> R_FE of two unequal spheres (scalars and scaling as pair_resistance_fu_sized: G by
  !> pi eta (a_alpha + a_beta)^2, H by pi eta (a_alpha + a_beta)^3).
  pure function pair_resistance_fe_sized(f, f2, d, a1, a2, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), f2(n_pair_scalars), d(3), a1, a2, viscosity
    real(dp) :: r(12, 3, 3)
    real(dp) :: sum_a(2, 2)
    sum_a = radius_sums(a1, a2)
    r = fe_blocks(sized_block_scalars(f, f2), pi * viscosity * sum_a**2, pi * viscosity * sum_a**3, d)
  end function pair_resistance_fe_sized

  pure function fe_blocks(s, cg, ch, d) result(r)
    real(dp), intent(in) :: s(11, 2, 2), cg(2, 2), ch(2, 2), d(3)
    real(dp) :: r(12, 3, 3)
    real(dp) :: g(3, 3, 3), h(3, 3, 3)
    integer :: alpha, beta, i, j, k
    r = 0.0_dp
    do alpha = 1, 2
      do beta = 1, 2
        ! Gt^ab_ijk = G^ba_jki: force on alpha from the stresslet response of beta.
        g = g_tensor(s(i_xg11, beta, alpha), s(i_yg11, beta, alpha), d)
        h = h_tensor(s(i_yh11, beta, alpha), d)
        do k = 1, 3
          do j = 1, 3
            do i = 1, 3
              r(6 * (alpha - 1) + i, j, k) = r(6 * (alpha - 1) + i, j, k) + cg(alpha, beta) * g(j, k, i)
              r(6 * (alpha - 1) + 3 + i, j, k) = r(6 * (alpha - 1) + 3 + i, j, k) &
                                                 + ch(alpha, beta) * h(j, k, i)
            end do
          end do
        end do
      end do
    end do
  end function fe_blocks

  !> R_SU as a 3x3x2x12 array: S_alpha,ij = sum_m r(i, j, alpha, m) w_m, with
  !> w = (U^inf_1 - U_1, Om^inf - Om_1, U^inf_2 - U_2, Om^inf - Om_2).
  pure function pair_resistance_su(f, d, radius, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), radius, viscosity
    real(dp) :: r(3, 3, 2, 12)
    r = su_blocks(equal_block_scalars(f), spread_scale(4.0_dp * pi * viscosity * radius**2), &
                  spread_scale(8.0_dp * pi * viscosity * radius**3), d)
  end function pair_resistance_su

  !> R_SU of two unequal spheres (as pair_resistance_fe_sized).
  pure function pair_resistance_su_sized(f, f2, d, a1, a2, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), f2(n_pair_scalars), d(3), a1, a2, viscosity
    real(dp) :: r(3, 3, 2, 12)
    real(dp) :: sum_a(2, 2)
    sum_a = radius_sums(a1, a2)
    r = su_blocks(sized_block_scalars(f, f2), pi * viscosity * sum_a**2, pi * viscosity * sum_a**3, d)
  end function pair_resistance_su_sized

  pure function su_blocks(s, cg, ch, d) result(r)
    real(dp), intent(in) :: s(11, 2, 2), cg(2, 2), ch(2, 2), d(3)
    real(dp) :: r(3, 3, 2, 12)
    real(dp) :: g(3, 3, 3), h(3, 3, 3)
    integer :: alpha, beta, k
    do alpha = 1, 2
      do beta = 1, 2
        g = g_tensor(s(i_xg11, alpha, beta), s(i_yg11, alpha, beta), d)
        h = h_tensor(s(i_yh11, alpha, beta), d)
        do k = 1, 3
          r(:, :, alpha, 6 * (beta - 1) + k) = cg(alpha, beta) * g(:, :, k)
          r(:, :, alpha, 6 * (beta - 1) + 3 + k) = ch(alpha, beta) * h(:, :, k)
        end do
      end do
    end do
  end function su_blocks

  !> R_SE of two unequal spheres as a 3x3x2x3x3 array: S_alpha = sum_beta M^ab : E, M^ab scaled by
  !> (5/6) pi eta (a_alpha + a_beta)^3 (Jeffrey 1992; the M scalars are even under exchange, so the
  !> 21 ones are the 12 ones at 1/lambda).
  pure function pair_resistance_se_sized(f, f2, d, a1, a2, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), f2(n_pair_scalars), d(3), a1, a2, viscosity
    real(dp) :: r(3, 3, 2, 3, 3)
    real(dp) :: s(11, 2, 2), cm(2, 2), x(2), y(2), z(2)
    integer :: alpha
    s = sized_block_scalars(f, f2)
    cm = 5.0_dp / 6.0_dp * pi * viscosity * radius_sums(a1, a2)**3
    do alpha = 1, 2
      x = s(i_xm11, alpha, :) * cm(alpha, :)
      y = s(i_ym11, alpha, :) * cm(alpha, :)
      z = s(i_zm11, alpha, :) * cm(alpha, :)
      r(:, :, alpha, :, :) = m_tensor(sum(x), sum(y), sum(z), d)
    end do
  end function pair_resistance_se_sized

  !> Stresslets S_1, S_2 (3x3x2) of two unequal spheres from w (as pair_stresslets) and E: the
  !> contractions of pair_resistance_su_sized and pair_resistance_se_sized.
  pure function pair_stresslets_sized(f, f2, d, w, e, a1, a2, viscosity) result(s)
    real(dp), intent(in) :: f(n_pair_scalars), f2(n_pair_scalars), d(3), w(12), e(3, 3), a1, a2, &
                            viscosity
    real(dp) :: s(3, 3, 2)
    real(dp) :: rsu(3, 3, 2, 12), rse(3, 3, 2, 3, 3)
    integer :: alpha, i, j
    rsu = pair_resistance_su_sized(f, f2, d, a1, a2, viscosity)
    rse = pair_resistance_se_sized(f, f2, d, a1, a2, viscosity)
    do alpha = 1, 2
      do j = 1, 3
        do i = 1, 3
          s(i, j, alpha) = sum(rsu(i, j, alpha, :) * w) + sum(rse(i, j, alpha, :, :) * e)
        end do
      end do
    end do
  end function pair_stresslets_sized

  !> The scalars of each block, s(k, alpha, beta), of two equal spheres from the 11 and 12 ones.
  pure function equal_block_scalars(f) result(s)
    real(dp), intent(in) :: f(n_pair_scalars)
    real(dp) :: s(11, 2, 2)
    integer :: k, alpha, beta
    do beta = 1, 2
      do alpha = 1, 2
        do k = 1, 11
          s(k, alpha, beta) = block_scalar(f, k, alpha, beta)
        end do
      end do
    end do
  end function equal_block_scalars

  !> The same for unequal spheres: f = (11, 12) scalars, f2 = (22, 21) scalars, exchange signs
  !> already applied (sized_pair_scalars_22).
  pure function sized_block_scalars(f, f2) result(s)
    real(dp), intent(in) :: f(n_pair_scalars), f2(n_pair_scalars)
    real(dp) :: s(11, 2, 2)
    s(:, 1, 1) = f(1:11)
    s(:, 1, 2) = f(12:22)
    s(:, 2, 2) = f2(1:11)
    s(:, 2, 1) = f2(12:22)
  end function sized_block_scalars

  !> a_alpha + a_beta of each block.
  pure function radius_sums(a1, a2) result(sum_a)
    real(dp), intent(in) :: a1, a2
    real(dp) :: sum_a(2, 2)
    sum_a(1, 1) = 2.0_dp * a1
    sum_a(1, 2) = a1 + a2
    sum_a(2, 1) = a1 + a2
    sum_a(2, 2) = 2.0_dp * a2
  end function radius_sums

  !> One dimensional factor for all four blocks (equal spheres).
  pure function spread_scale(c) result(cs)
    real(dp), intent(in) :: c
    real(dp) :: cs(2, 2)
    cs = c
  end function spread_scale

  !> R_SE as a 3x3x2x3x3 array: S_alpha,ij = sum_kl r(i, j, alpha, k, l) E_kl.
  pure function pair_resistance_se(f, d, radius, viscosity) result(r)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), radius, viscosity
    real(dp) :: r(3, 3, 2, 3, 3)
    real(dp) :: cm
    integer :: alpha
    cm = 20.0_dp / 3.0_dp * pi * viscosity * radius**3
    do alpha = 1, 2
      ! Sum over beta of M^ab (M scalars are even under exchange: M^a1 + M^a2 = M11 + M12).
      r(:, :, alpha, :, :) = cm * m_tensor(f(i_xm11) + f(i_xm12), f(i_ym11) + f(i_ym12), &
                                           f(i_zm11) + f(i_zm12), d)
    end do
  end function pair_resistance_se

  !> Contractions of the three M basis tensors with a symmetric traceless E (doc/METHOD.md §5.1).
  pure function strain_d0(d, e) result(c)
    real(dp), intent(in) :: d(3), e(3, 3)
    real(dp) :: c(3, 3)
    integer :: i, j
    real(dp) :: ded
    ded = dot_product(d, matmul(e, d))
    do j = 1, 3
      do i = 1, 3
        c(i, j) = 1.5_dp * (d(i) * d(j) - kron(i, j) / 3.0_dp) * ded
      end do
    end do
  end function strain_d0

  pure function strain_d1(d, e) result(c)
    real(dp), intent(in) :: d(3), e(3, 3)
    real(dp) :: c(3, 3), ed(3), ded
    integer :: i, j
    ed = matmul(e, d)
    ded = dot_product(d, ed)
    do j = 1, 3
      do i = 1, 3
        c(i, j) = d(i) * ed(j) + ed(i) * d(j) - 2.0_dp * d(i) * d(j) * ded
      end do
    end do
  end function strain_d1

  pure function strain_d2(d, e) result(c)
    real(dp), intent(in) :: d(3), e(3, 3)
    real(dp) :: c(3, 3), ed(3), ded
    integer :: i, j
    ed = matmul(e, d)
    ded = dot_product(d, ed)
    do j = 1, 3
      do i = 1, 3
        c(i, j) = e(i, j) + 0.5_dp * (kron(i, j) + d(i) * d(j)) * ded - d(i) * ed(j) - ed(i) * d(j)
      end do
    end do
  end function strain_d2

  !> (F_1, T_1, F_2, T_2) from the strain alone, R_FE : E, written out (doc/METHOD.md §5.7).
  pure function pair_force_torque_from_strain(f, d, e, radius, viscosity) result(ft)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), e(3, 3), radius, viscosity
    real(dp) :: ft(12)
    real(dp) :: ed(3), ded, fvec(3), tvec(3), cg, ch
    cg = 4.0_dp * pi * viscosity * radius**2
    ch = 8.0_dp * pi * viscosity * radius**3
    ed = matmul(e, d)
    ded = dot_product(d, ed)
    fvec = cg * ((f(i_xg11) - f(i_xg12)) * ded * d + 2.0_dp * (f(i_yg11) - f(i_yg12)) * (ed - ded * d))
    tvec = 2.0_dp * ch * (f(i_yh11) + f(i_yh12)) * cross(d, ed)
    ft(1:3) = fvec
    ft(4:6) = tvec
    ft(7:9) = -fvec
    ft(10:12) = tvec
  end function pair_force_torque_from_strain

  !> Stresslets S_1, S_2 (3x3x2) from w = (U^inf_1 - U_1, Om^inf - Om_1, U^inf_2 - U_2,
  !> Om^inf - Om_2) and E, written out (doc/METHOD.md §5.7).
  pure function pair_stresslets(f, d, w, e, radius, viscosity) result(s)
    real(dp), intent(in) :: f(n_pair_scalars), d(3), w(12), e(3, 3), radius, viscosity
    real(dp) :: s(3, 3, 2)
    real(dp) :: cg, ch, cm, wb(3), wperp(3), od(3), me(3, 3), xg, yg, yh
    integer :: alpha, beta, i, j
    cg = 4.0_dp * pi * viscosity * radius**2
    ch = 8.0_dp * pi * viscosity * radius**3
    cm = 20.0_dp / 3.0_dp * pi * viscosity * radius**3
    me = cm * ((f(i_xm11) + f(i_xm12)) * strain_d0(d, e) + (f(i_ym11) + f(i_ym12)) * strain_d1(d, e) &
               + (f(i_zm11) + f(i_zm12)) * strain_d2(d, e))
    do alpha = 1, 2
      s(:, :, alpha) = me
      do beta = 1, 2
        xg = block_scalar(f, i_xg11, alpha, beta)
        yg = block_scalar(f, i_yg11, alpha, beta)
        yh = block_scalar(f, i_yh11, alpha, beta)
        wb = w(6 * (beta - 1) + 1:6 * (beta - 1) + 3)
        wperp = wb - dot_product(d, wb) * d
        od = cross(w(6 * (beta - 1) + 4:6 * (beta - 1) + 6), d)
        do j = 1, 3
          do i = 1, 3
            s(i, j, alpha) = s(i, j, alpha) &
              + cg * (xg * (d(i) * d(j) - kron(i, j) / 3.0_dp) * dot_product(d, wb) &
                      + yg * (d(i) * wperp(j) + wperp(i) * d(j))) &
              + ch * yh * (od(i) * d(j) + d(i) * od(j))
          end do
        end do
      end do
    end do
  end function pair_stresslets

  ! ---------------------------------------------------------------------------------------------
  ! Sphere - plane wall (doc/METHOD.md §5.2, §5.8)
  ! ---------------------------------------------------------------------------------------------

  !> 6x6 sphere-wall resistance: (F, T) = -R . (U - U_wall, Om) for a sphere at gap eps from a
  !> plane wall with unit normal n pointing from the wall into the fluid (towards the sphere).
  function wall_resistance_fu(gap, normal, radius, viscosity) result(r)
    real(dp), intent(in) :: gap, normal(3), radius, viscosity
    real(dp) :: r(6, 6)
    real(dp) :: f_tt, f_tr, f_rr
    call wall_tangential_resistance(gap, f_tt, f_tr, f_rr)
    r = wall_resistance_block(wall_normal_resistance(gap), f_tt, f_tr, f_rr, &
                              wall_twist_resistance(gap), normal, radius, viscosity)
  end function wall_resistance_fu

  !> The 6x6 sphere-wall block from given scalars (theory, or theory minus numerics for the
  !> subgrid correction): lam = lambda_perp (normal), f_tt, f_tr, f_rr (tangential, coupling,
  !> rotation; see wall_tangential_resistance), xw (twist about n). (F, T) = -R . (U - U_wall, Om).
  pure function wall_resistance_block(lam, f_tt, f_tr, f_rr, xw, normal, radius, viscosity) result(r)
    real(dp), intent(in) :: lam, f_tt, f_tr, f_rr, xw, normal(3), radius, viscosity
    real(dp) :: r(6, 6)
    real(dp) :: nn(3, 3), skew(3, 3), ca
    integer :: i, j
    ca = 6.0_dp * pi * viscosity * radius
    do j = 1, 3
      do i = 1, 3
        nn(i, j) = normal(i) * normal(j)
      end do
    end do
    ! skew . v = n x v
    skew = reshape([0.0_dp, normal(3), -normal(2), -normal(3), 0.0_dp, normal(1), &
                    normal(2), -normal(1), 0.0_dp], [3, 3])
    r = 0.0_dp
    do j = 1, 3
      do i = 1, 3
        r(i, j) = ca * (lam * nn(i, j) + f_tt * (kron(i, j) - nn(i, j)))
        r(3 + i, 3 + j) = ca * radius**2 * (4.0_dp / 3.0_dp * xw * nn(i, j) &
                                            + 4.0_dp / 3.0_dp * f_rr * (kron(i, j) - nn(i, j)))
        ! Coupling (doc/METHOD.md §5.2): F_t = +6 pi eta a^2 f_tr Om_b t with b = n x t, i.e.
        ! F = 6 pi eta a^2 f_tr (Om x n) = -R_{F,Om} . Om with R_{F,Om} = 6 pi eta a^2 f_tr [n x];
        ! reciprocity makes R_{T,U} its transpose (T = 6 pi eta a^2 f_tr n x U: a sphere sliding
        ! along t is turned in the rolling sense, about b).
        r(i, 3 + j) = ca * radius * f_tr * skew(i, j)
        r(3 + j, i) = ca * radius * f_tr * skew(i, j)
      end do
    end do
  end function wall_resistance_block

end module mod_resistance_blocks
