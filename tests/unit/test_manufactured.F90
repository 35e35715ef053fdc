! Invariant: the manufactured solutions used to verify the fluid solver are exact solutions of
! steady Stokes with their forcing: div u = 0, u = 0 on the walls (walled case), and
! f = grad p - lap u. Checked by fourth-order central differences (step 1e-3, truncation error
! ~1e-11 for these O(1) smooth fields; tolerance 1e-7 allows for round-off h^-2 * 1e-16).
program test_manufactured
  use mod_kinds, only: dp
  use mod_manufactured, only: mms_velocity, mms_pressure, mms_forcing
  use mod_unit_checks, only: check, check_below, finish
  implicit none
  real(dp), parameter :: box(3) = [3.2_dp, 4.0_dp, 2.4_dp], step = 1.0e-3_dp, tol = 1.0e-7_dp
  real(dp) :: x(3), div, lap, gradp, f, worst
  integer :: n, c, d, w
  logical :: walls

  do w = 0, 1
    walls = (w == 1)
    worst = 0.0_dp
    do n = 1, 50
      x = box * [mod(0.137_dp * n, 1.0_dp), mod(0.311_dp * n + 0.05_dp, 1.0_dp), mod(0.731_dp * n, 1.0_dp)]
      div = 0.0_dp
      do d = 1, 3
        div = div + deriv(d, d, x, 1)
      end do
      worst = max(worst, abs(div))
      do c = 1, 3
        lap = 0.0_dp
        do d = 1, 3
          lap = lap + deriv(c, d, x, 2)
        end do
        gradp = deriv(0, c, x, 1)
        f = mms_forcing(c, x, box, walls, 1.0_dp)
        worst = max(worst, abs(f - (gradp - lap)))
      end do
      if (walls) then
        do c = 1, 3
          worst = max(worst, abs(mms_velocity(c, [x(1), 0.0_dp, x(3)], box, walls)))
          worst = max(worst, abs(mms_velocity(c, [x(1), box(2), x(3)], box, walls)))
        end do
      end if
    end do
    ! the field must not be trivial
    call check(abs(mms_velocity(3, [0.3_dp, 0.7_dp, 0.5_dp], box, walls)) >= 1.0e-3_dp, &
               trim(merge('walls:    ', 'periodic: ', walls))//' w is not trivial')
    call check_below(trim(merge('walls:    ', 'periodic: ', walls))//' worst residual of div u, f - (grad p - lap u), u at the walls', &
                     worst, tol)
  end do
  call finish('test_manufactured')

contains

  ! order-th derivative along d of velocity component c (c = 0: pressure), 4th-order stencil
  real(dp) function deriv(c, d, x, order)
    integer, intent(in) :: c, d, order
    real(dp), intent(in) :: x(3)
    real(dp) :: e(3), v(-2:2)
    integer :: s
    e = 0.0_dp
    e(d) = step
    do s = -2, 2
      if (c == 0) then
        v(s) = mms_pressure(x + s * e, box, walls)
      else
        v(s) = mms_velocity(c, x + s * e, box, walls)
      end if
    end do
    if (order == 1) then
      deriv = (v(-2) - 8.0_dp * v(-1) + 8.0_dp * v(1) - v(2)) / (12.0_dp * step)
    else
      deriv = (-v(-2) + 16.0_dp * v(-1) - 30.0_dp * v(0) + 16.0_dp * v(1) - v(2)) / (12.0_dp * step**2)
    end if
  end function deriv

end program test_manufactured
