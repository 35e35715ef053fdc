! Solid fraction of a MAC control volume covered by a sphere (method.md §1.4), and the weights of
! the relaxed rigid constraint (method.md §1.5b).
!
! alpha is the fraction of the cube of side h centred on a face (or a cell centre) that lies inside
! a sphere of radius R. Faces wholly inside give 1, wholly outside 0; cut faces are sampled on
! n_sub^3 points, each contributing the covered fraction of a segment of length h/n_sub across the
! surface, clamp((R - d)/s + 1/2, 0, 1), s = h/n_sub. Every sample's contribution is continuous in
! the sphere's position, so alpha is too (issue 9: no jumps when a sphere crosses a grid line); the
! volume error of the planar ramp is O(s^2/R) per sample.
module mod_solid_fraction
  use mod_kinds, only: dp
  implicit none
  private
  public :: cube_fraction, relaxation_gamma, n_sub

  integer, parameter :: n_sub = 4

contains

  ! Fraction of the cube of side h centred at offset r from the sphere centre inside radius R.
  pure real(dp) function cube_fraction(r, radius, h) result(alpha)
    real(dp), intent(in) :: r(3), radius, h
    real(dp) :: d, half_diag, s, dist2, inner2, outer2, x2(n_sub), y2(n_sub), z2(n_sub)
    integer :: a, b, c
    d = norm2(r)
    half_diag = 0.5_dp * sqrt(3.0_dp) * h
    if (d <= radius - half_diag) then
      alpha = 1.0_dp
      return
    end if
    if (d >= radius + half_diag) then
      alpha = 0.0_dp
      return
    end if
    s = h / n_sub
    ! Each sub-sample counts min(1, max(0, (radius - dist)/s + 1/2)): 1 inside radius - s/2, 0
    ! beyond radius + s/2, so only the samples in that band need the square root (this routine
    ! is most of the geometry's cost: doc/BENCHMARKS.md §7).
    inner2 = max(0.0_dp, radius - 0.5_dp * s)**2
    outer2 = (radius + 0.5_dp * s)**2
    do a = 1, n_sub
      x2(a) = (r(1) + (a - 0.5_dp * (n_sub + 1)) * s)**2
      y2(a) = (r(2) + (a - 0.5_dp * (n_sub + 1)) * s)**2
      z2(a) = (r(3) + (a - 0.5_dp * (n_sub + 1)) * s)**2
    end do
    alpha = 0.0_dp
    do c = 1, n_sub
      do b = 1, n_sub
        do a = 1, n_sub
          dist2 = x2(a) + y2(b) + z2(c)
          if (dist2 <= inner2) then
            alpha = alpha + 1.0_dp
          else if (dist2 < outer2) then
            alpha = alpha + min(1.0_dp, max(0.0_dp, (radius - sqrt(dist2)) / s + 0.5_dp))
          end if
        end do
      end do
    end do
    alpha = alpha / n_sub**3
  end function cube_fraction

  ! gamma of the implicit relaxation of lambda on partly covered faces (method.md §1.5b):
  ! gamma = kappa (1 - alpha) beta h^2 / eta with beta = rho/dt. At a steady state this is a
  ! Brinkman slip of permeability ~ (1 - alpha) h^2 / alpha, independent of rho/dt.
  pure real(dp) function relaxation_gamma(alpha, kappa, beta, h, eta) result(gamma)
    real(dp), intent(in) :: alpha, kappa, beta, h, eta
    gamma = kappa * (1.0_dp - alpha) * beta * h**2 / eta
  end function relaxation_gamma

end module mod_solid_fraction
