! Manufactured solutions of the steady Stokes equations, -grad p + eta*lap u + f = 0, div u = 0,
! used to verify the fluid solver (&verification manufactured_solution). Pure: no PETSc.
!
! Periodic box (kx = 2 pi/Lx, ...):
!   u = c/kx sin(kx x) cos(ky y) cos(kz z), v = c/ky cos sin cos, w = -2c/kz cos cos sin,
!   p = cos(kx x) cos(ky y) cos(kz z),  c = (kx+ky+kz)/3 so that |u| = O(1).
!   div u = c cos cos cos (1 + 1 - 2) = 0, and lap u = -(kx^2+ky^2+kz^2) u.
! Walls at y = 0 and y = Ly (no slip; a Couette shear adds linearly and needs no forcing):
!   psi = sin(kx x) g(y) cos(kz z), g = sin^2(s y), s = pi/Ly, so g = g' = 0 at both walls;
!   u = d psi/dy, v = -d psi/dx, w = sin(kx x) g(y): divergence-free, zero on the walls.
!   p = cos(kx x) cos(s y) cos(kz z).
! The forcing is f = grad p - eta lap u, evaluated pointwise (eta = 1 in fdsusp units).
module mod_manufactured
  use mod_kinds, only: dp, pi
  implicit none
  private
  public :: mms_velocity, mms_pressure, mms_forcing

contains

  ! Component comp (1 = x, 2 = y, 3 = z) of the exact velocity at point x.
  pure real(dp) function mms_velocity(comp, x, box, walls) result(val)
    integer, intent(in) :: comp
    real(dp), intent(in) :: x(3), box(3)
    logical, intent(in) :: walls
    real(dp) :: k(3), c, sx, cx, sy, cy, sz, cz, s, g, gp
    k = 2.0_dp * pi / box
    sx = sin(k(1)*x(1)); cx = cos(k(1)*x(1))
    sz = sin(k(3)*x(3)); cz = cos(k(3)*x(3))
    if (.not. walls) then
      c = sum(k) / 3.0_dp
      sy = sin(k(2)*x(2)); cy = cos(k(2)*x(2))
      select case (comp)
      case (1); val = c / k(1) * sx * cy * cz
      case (2); val = c / k(2) * cx * sy * cz
      case default; val = -2.0_dp * c / k(3) * cx * cy * sz
      end select
    else
      s = pi / box(2)
      g = sin(s*x(2))**2
      gp = s * sin(2.0_dp*s*x(2))
      select case (comp)
      case (1); val = sx * gp * cz
      case (2); val = -k(1) * cx * g * cz
      case default; val = sx * g
      end select
    end if
  end function mms_velocity

  pure real(dp) function mms_pressure(x, box, walls) result(val)
    real(dp), intent(in) :: x(3), box(3)
    logical, intent(in) :: walls
    real(dp) :: k(3)
    k = 2.0_dp * pi / box
    if (walls) k(2) = pi / box(2)
    val = cos(k(1)*x(1)) * cos(k(2)*x(2)) * cos(k(3)*x(3))
  end function mms_pressure

  ! Component comp of f = grad p - eta lap u at point x (eta = viscosity).
  pure real(dp) function mms_forcing(comp, x, box, walls, viscosity) result(val)
    integer, intent(in) :: comp
    real(dp), intent(in) :: x(3), box(3), viscosity
    logical, intent(in) :: walls
    real(dp) :: k(3), kp(3), dp_dx, lap, sx, cx, sz, cz, s, g, g1, g2, g3, ksq
    k = 2.0_dp * pi / box
    kp = k
    if (walls) kp(2) = pi / box(2)
    ! pressure gradient
    select case (comp)
    case (1); dp_dx = -kp(1) * sin(kp(1)*x(1)) * cos(kp(2)*x(2)) * cos(kp(3)*x(3))
    case (2); dp_dx = -kp(2) * cos(kp(1)*x(1)) * sin(kp(2)*x(2)) * cos(kp(3)*x(3))
    case default; dp_dx = -kp(3) * cos(kp(1)*x(1)) * cos(kp(2)*x(2)) * sin(kp(3)*x(3))
    end select
    if (.not. walls) then
      lap = -sum(k**2) * mms_velocity(comp, x, box, walls)
    else
      sx = sin(k(1)*x(1)); cx = cos(k(1)*x(1))
      sz = sin(k(3)*x(3)); cz = cos(k(3)*x(3))
      s = pi / box(2)
      g = sin(s*x(2))**2                       ! g
      g1 = s * sin(2.0_dp*s*x(2))              ! g'
      g2 = 2.0_dp * s**2 * cos(2.0_dp*s*x(2))  ! g''
      g3 = -4.0_dp * s**3 * sin(2.0_dp*s*x(2)) ! g'''
      ksq = k(1)**2 + k(3)**2
      select case (comp)
      case (1); lap = sx * cz * (g3 - ksq * g1)
      case (2); lap = -k(1) * cx * cz * (g2 - ksq * g)
      case default; lap = sx * (g2 - k(1)**2 * g)
      end select
    end if
    val = dp_dx - viscosity * lap
  end function mms_forcing

end module mod_manufactured
