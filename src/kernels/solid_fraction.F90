! Solid fraction of a MAC control volume covered by a sphere (doc/METHOD.md §3.1), and the weights of
! the relaxed rigid constraint (doc/METHOD.md §3.3).
!
! alpha is the fraction of the cube of side h centred on a face (or a cell centre) that lies inside
! a sphere of radius R. Faces wholly inside give 1, wholly outside 0; cut faces are sampled on
! n_sub^3 points, each contributing the covered fraction of a segment of length h/n_sub across the
! surface, clamp((R - d)/s + 1/2, 0, 1), s = h/n_sub. Every sample's contribution is continuous in
! the sphere's position, so alpha is too (no jumps when a sphere crosses a grid line, doc/METHOD.md §3.1); the
! volume error of the planar ramp is O(s^2/R) per sample.
module mod_solid_fraction
  use mod_kinds, only: dp
  implicit none
  private
  public :: cube_fraction, relaxation_gamma, n_sub

  integer, parameter :: n_sub = 4

contains

  ! Fraction of the cube of side h centred at offset r from the sphere centre inside radius R.
  ! Each sub-sample counts min(1, max(0, (radius - dist)/s + 1/2)): 1 inside radius - s/2, 0
  ! beyond radius + s/2. The samples lie on n_sub^2 rows along x; a row wholly inside or wholly
  ! outside that band is counted at once, and only the rows that cross it evaluate their samples,
  ! without branches (until 2026-11-26 this routine was the largest single cost of the particle step,
  ! mostly mispredicted branches per sample).
  pure real(dp) function cube_fraction(r, radius, h) result(alpha)
    real(dp), intent(in) :: r(3), radius, h
    real(dp) :: half_diag, s, inv_s, d2, inner2, outer2, yz, x2min, x2max, x2(n_sub), y2(n_sub), z2(n_sub)
    integer :: a, b, c
    d2 = r(1)**2 + r(2)**2 + r(3)**2
    half_diag = 0.5_dp * sqrt(3.0_dp) * h
    if (radius > half_diag) then
      if (d2 <= (radius - half_diag)**2) then
        alpha = 1.0_dp
        return
      end if
    end if
    if (d2 >= (radius + half_diag)**2) then
      alpha = 0.0_dp
      return
    end if
    s = h / n_sub
    inv_s = 1.0_dp / s
    inner2 = max(0.0_dp, radius - 0.5_dp * s)**2
    outer2 = (radius + 0.5_dp * s)**2
    do a = 1, n_sub
      x2(a) = (r(1) + (a - 0.5_dp * (n_sub + 1)) * s)**2
      y2(a) = (r(2) + (a - 0.5_dp * (n_sub + 1)) * s)**2
      z2(a) = (r(3) + (a - 0.5_dp * (n_sub + 1)) * s)**2
    end do
    x2min = minval(x2)
    x2max = maxval(x2)
    alpha = 0.0_dp
    do c = 1, n_sub
      do b = 1, n_sub
        yz = y2(b) + z2(c)
        if (yz + x2min >= outer2) cycle
        if (yz + x2max <= inner2) then
          alpha = alpha + n_sub
          cycle
        end if
        do a = 1, n_sub
          alpha = alpha + min(1.0_dp, max(0.0_dp, (radius - sqrt(x2(a) + yz)) * inv_s + 0.5_dp))
        end do
      end do
    end do
    alpha = alpha / n_sub**3
  end function cube_fraction

  ! gamma of the implicit relaxation of lambda on partly covered faces (doc/METHOD.md §3.3):
  ! gamma = kappa (1 - alpha) beta h^2 / eta with beta = rho/dt. At a steady state this is a
  ! Brinkman slip of permeability ~ (1 - alpha) h^2 / alpha, independent of rho/dt.
  pure real(dp) function relaxation_gamma(alpha, kappa, beta, h, eta) result(gamma)
    real(dp), intent(in) :: alpha, kappa, beta, h, eta
    gamma = kappa * (1.0_dp - alpha) * beta * h**2 / eta
  end function relaxation_gamma

end module mod_solid_fraction
