! Bond-orientational order: Steinhardt's Q6 (Steinhardt, Nelson & Ronchetti 1983, Phys. Rev. B 28,
! 784), the measure of crystalline order in a packing of spheres (doc/RHEOLOGY.md "Order"): 0.575
! for a face-centred cubic crystal, about N_b^(-1/2) for a liquid of N_b bonds. Each bond k joins
! spheres ends(1, k), ends(2, k) at separation r(:, k) (the caller's neighbour list decides what a
! bond is, e.g. centres closer than 1.2 (a_i + a_j), near the first minimum of g(r)).
!   q_6m(i)  = (1/N_b(i)) sum over i's bonds of Y_6m(r_hat)              (local, per sphere)
!   q6(i)    = sqrt(4 pi/13 sum_m |q_6m(i)|^2)
!   Q_6m     = sum of all bonds' Y_6m at both ends / sum_i N_b(i)          (global)
!   Q6       = sqrt(4 pi/13 sum_m |Q_6m|^2)
! Y_6m(-r_hat) = Y_6m(r_hat) (l even), so a bond adds the same to both of its spheres, and
! |q_6,-m| = |q_6m|, so m = 0..6 suffice. Rotation invariant by construction. Pure.
module mod_bond_order
  use mod_kinds, only: dp, pi
  implicit none
  private
  public :: bond_order_q6, bond_order_shares, bond_order_global

  integer, parameter :: l = 6

contains

  !> Q6 of the bonds (global) and q6 of each of np spheres (0 for a sphere without bonds).
  pure subroutine bond_order_q6(np, nbonds, ends, r, q6_global, q6_local)
    integer, intent(in) :: np, nbonds
    integer, intent(in) :: ends(:, :)            ! (2, nbonds)
    real(dp), intent(in) :: r(:, :)              ! (3, nbonds)
    real(dp), intent(out) :: q6_global
    real(dp), intent(out) :: q6_local(np)
    complex(dp) :: total(0:l)
    real(dp) :: bonds
    integer :: k
    ! one share: every sphere's
    call bond_order_shares(np, nbonds, ends, r, [(.true., k = 1, np)], total, bonds, q6_local)
    q6_global = bond_order_global(total, bonds)
  end subroutine bond_order_q6

  !> A share of the global sums over some of the spheres (owned, np): sum of their q_6m(i) N_b(i)
  !> (total) and of their N_b(i) (bonds), and q6 of each sphere (as bond_order_q6). Shares over a
  !> partition of the spheres add up to the sums of bond_order_q6, whose Q6 bond_order_global gives.
  pure subroutine bond_order_shares(np, nbonds, ends, r, owned, total, bonds, q6_local)
    integer, intent(in) :: np, nbonds
    integer, intent(in) :: ends(:, :)            ! (2, nbonds)
    real(dp), intent(in) :: r(:, :)              ! (3, nbonds)
    logical, intent(in) :: owned(:)              ! (np)
    complex(dp), intent(out) :: total(0:l)
    real(dp), intent(out) :: bonds
    real(dp), intent(out) :: q6_local(np)
    complex(dp) :: q(0:l, np), y(0:l)
    integer :: count_of(np), k, i, e
    q = (0.0_dp, 0.0_dp)
    count_of = 0
    do k = 1, nbonds
      y = spherical_harmonics(r(:, k))
      do e = 1, 2
        i = ends(e, k)
        q(:, i) = q(:, i) + y
        count_of(i) = count_of(i) + 1
      end do
    end do
    total = (0.0_dp, 0.0_dp)
    bonds = 0
    do i = 1, np
      q6_local(i) = 0.0_dp
      if (count_of(i) > 0) q6_local(i) = invariant(q(:, i) / count_of(i))
      if (.not. owned(i)) cycle
      total = total + q(:, i)
      bonds = bonds + count_of(i)
    end do
  end subroutine bond_order_shares

  !> Q6 from the sums of the shares (bond_order_shares): 0 without bonds.
  pure real(dp) function bond_order_global(total, bonds) result(q6)
    complex(dp), intent(in) :: total(0:l)
    real(dp), intent(in) :: bonds
    q6 = 0.0_dp
    if (bonds > 0) q6 = invariant(total / bonds)
  end function bond_order_global

  ! sqrt(4 pi/(2l+1) sum_{m=-l..l} |q_lm|^2) from m = 0..l (|q_l,-m| = |q_lm|).
  pure real(dp) function invariant(q) result(v)
    complex(dp), intent(in) :: q(0:l)
    v = sqrt(4 * pi / (2 * l + 1) * (abs(q(0))**2 + 2 * sum(abs(q(1:l))**2)))
  end function invariant

  ! Y_lm(r_hat), m = 0..l: N_lm P_l^m(cos theta) e^{i m phi}, the associated Legendre functions
  ! with the Condon-Shortley phase by the standard upward recurrence in l from P_m^m, and
  ! sin^m theta e^{i m phi} = ((x + i y)/|r|)^m (no angle needed).
  pure function spherical_harmonics(r) result(y)
    real(dp), intent(in) :: r(3)
    complex(dp) :: y(0:l)
    real(dp) :: c, p_mm, p_prev, p_now, p_next, norm
    complex(dp) :: e
    integer :: m, n
    c = r(3) / norm2(r)
    e = cmplx(r(1), r(2), dp) / norm2(r)       ! sin(theta) e^{i phi}
    do m = 0, l
      ! P_m^m / sin^m = (-1)^m (2m-1)!!
      p_mm = 1.0_dp
      do n = 1, m
        p_mm = -p_mm * (2 * n - 1)
      end do
      if (m == l) then
        p_now = p_mm
      else
        p_prev = p_mm
        p_now = c * (2 * m + 1) * p_mm
        do n = m + 2, l
          p_next = (c * (2 * n - 1) * p_now - (n + m - 1) * p_prev) / (n - m)
          p_prev = p_now
          p_now = p_next
        end do
      end if
      norm = sqrt((2 * l + 1) / (4 * pi) * factorial_ratio(l - m, l + m))
      y(m) = norm * p_now * e**m
    end do
  end function spherical_harmonics

  ! a!/b! for 0 <= a <= b
  pure real(dp) function factorial_ratio(a, b) result(f)
    integer, intent(in) :: a, b
    integer :: k
    f = 1.0_dp
    do k = a + 1, b
      f = f / k
    end do
  end function factorial_ratio

end module mod_bond_order
