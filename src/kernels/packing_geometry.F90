! What a random packing can be asked for (doc/PACKING_INPUT.md): the highest volume fraction the
! packer accepts, the number of spheres that fills a box at a volume fraction, and the box that
! holds n spheres at one exactly. Apart from mod_packing (the packer) so that the deck readers
! (mod_params, mod_packing_deck) check and size a packing without importing the packer: the
! configuration, which the fluid reads, then does not depend on the Monte Carlo code. Pure.
module mod_packing_geometry
  use mod_kinds, only: dp, pi
  implicit none
  private
  public :: phi_max, packing_count, packing_box_for

  real(dp), parameter :: phi_max = 0.55_dp     ! highest target accepted

contains

  !> Number of spheres of radius a closest to volume fraction phi in box.
  pure integer function packing_count(phi, box, a) result(n)
    real(dp), intent(in) :: phi, box(3), a
    n = nint(phi * product(box) / (4.0_dp / 3 * pi * a**3))
  end function packing_count

  !> The box of the shape of box that holds n spheres of radius a at volume fraction phi exactly.
  pure function packing_box_for(n, phi, box, a) result(b)
    integer, intent(in) :: n
    real(dp), intent(in) :: phi, box(3), a
    real(dp) :: b(3)
    b = box * (n * (4.0_dp / 3 * pi * a**3) / (phi * product(box)))**(1.0_dp / 3)
  end function packing_box_for

end module mod_packing_geometry
