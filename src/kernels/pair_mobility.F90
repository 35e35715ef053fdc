! Force- and torque-free pair of equal spheres in a linear flow (Batchelor & Green 1972; doc/METHOD.md
! §9.1-9.2): the mobility functions A, B, the pair's rotation c and the stresslet
! functions K, L, M at a gap, reduced from the exact resistance scalars of mod_pair_resistance.
! Printed by bin/fdsusp-resistance ('shear'); the unit tests check them against published values
! and use them as the isolated pair's reference (the relative motion bin/pairtraj integrates).
!
! Pure Fortran (no PETSc, MPI or HDF5). Conventions: mod_pair_resistance; derivation and
! checks: doc/RESISTANCE.md.
module mod_pair_mobility
  use mod_kinds, only: dp
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars, i_xa11, i_ya11, i_yb11, i_yc11, &
       i_xg11, i_yg11, i_yh11, i_xm11, i_ym11, i_zm11, i_xa12, i_ya12, i_yb12, i_yc12, i_xg12, &
       i_yg12, i_yh12, i_xm12, i_ym12, i_zm12
  implicit none
  private

  public :: pair_shear_functions

contains

  !> Mobility and stresslet functions of a force- and torque-free equal pair at gap xi:
  !>   dr/dt = Om x r + E.r - [A dd + B (I - dd)].E.r,   Om_pair = Om^inf + c d x (E.d),
  !>   S = (20/3) pi eta a^3 [(1+K) E + L (d(E.d) + (E.d)d - (2/3) I d.E.d) + M (dd - I/3) d.E.d].
  !> Derived from the six-unknown reduction of doc/METHOD.md §9.1-9.2 (doc/RESISTANCE.md).
  subroutine pair_shear_functions(gap, a_bg, b_bg, c_rot, k_bg, l_bg, m_bg)
    real(dp), intent(in) :: gap
    real(dp), intent(out) :: a_bg, b_bg, c_rot, k_bg, l_bg, m_bg
    real(dp) :: f(n_pair_scalars), s, xa, ya, yb, xg, yg, ycp, yhp, xmp, ymp, zmp, beta_u
    f = resistance_scalars(gap)
    s = 2.0_dp + gap
    xa = f(i_xa11) - f(i_xa12)
    ya = f(i_ya11) - f(i_ya12)
    yb = f(i_yb11) - f(i_yb12)
    xg = f(i_xg11) - f(i_xg12)
    yg = f(i_yg11) - f(i_yg12)
    ycp = f(i_yc11) + f(i_yc12)
    yhp = f(i_yh11) + f(i_yh12)
    xmp = f(i_xm11) + f(i_xm12)
    ymp = f(i_ym11) + f(i_ym12)
    zmp = f(i_zm11) + f(i_zm12)
    a_bg = 4.0_dp * xg / (3.0_dp * s * xa)
    beta_u = (8.0_dp * yg + 8.0_dp * yb * yhp / ycp) / (6.0_dp * ya - 2.0_dp * yb**2 / ycp)
    c_rot = (yb * beta_u + 4.0_dp * yhp) / (2.0_dp * ycp)
    b_bg = 2.0_dp * beta_u / s
    k_bg = zmp - 1.0_dp
    l_bg = ymp - zmp - 0.6_dp * yg * beta_u - 1.2_dp * yhp * c_rot
    m_bg = 1.5_dp * xmp - 2.0_dp * ymp + 0.5_dp * zmp - 0.4_dp * xg**2 / xa + 1.2_dp * yg * beta_u &
           + 2.4_dp * yhp * c_rot
  end subroutine pair_shear_functions

end module mod_pair_mobility
