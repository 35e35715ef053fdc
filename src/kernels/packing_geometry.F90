! What a random packing can be asked for (doc/PACKING_INPUT.md): the highest volume fraction the
! packer accepts, the number of spheres that fills a box at a volume fraction (per species for a
! mixture), and the box that holds them at one exactly. Apart from mod_packing (the packer) so
! that the deck readers (mod_params, mod_packing_deck) check and size a packing without importing
! the packer: the configuration, which the fluid reads, then does not depend on the Monte Carlo
! code. Pure. A single species goes through the equal-sphere expressions, so its counts, boxes and
! volume fractions are those of before the mixtures, bit for bit.
module mod_packing_geometry
  use mod_kinds, only: dp, pi
  implicit none
  private
  public :: phi_max, packing_count, packing_box_for, volume_fraction, species_counts, &
            species_counts_total, species_box_for, species_volume_fraction

  ! highest target accepted: what the compression reaches for equal spheres and the 1:1.4
  ! mixture in walls and periodic boxes (scripts/pack_reach.sh; doc/VALIDATION.md "Packings")
  real(dp), parameter :: phi_max = 0.60_dp

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

  !> Volume fraction of spheres of radii radius(:) in box (equal radii: n v / V).
  pure real(dp) function volume_fraction(radius, box) result(phi)
    real(dp), intent(in) :: radius(:), box(3)
    if (size(radius) == 0) then
      phi = 0
    else if (all(radius == radius(1))) then
      phi = size(radius) * (4.0_dp / 3 * pi * radius(1)**3) / product(box)
    else
      phi = sum(4.0_dp / 3 * pi * radius**3) / product(box)
    end if
  end function volume_fraction

  !> Volume fraction of counts(k) spheres of radius radius(k) in box.
  pure real(dp) function species_volume_fraction(counts, radius, box) result(phi)
    integer, intent(in) :: counts(:)
    real(dp), intent(in) :: radius(:), box(3)
    if (size(radius) == 1) then
      phi = counts(1) * (4.0_dp / 3 * pi * radius(1)**3) / product(box)
    else
      phi = sum(counts * (4.0_dp / 3 * pi * radius**3)) / product(box)
    end if
  end function species_volume_fraction

  !> Spheres per species closest to volume fraction phi in box, species k of radius radius(k)
  !> taking the share share(k) of the solid volume (by_volume) or of the number of spheres.
  !> Rounding: each species to the nearest integer on its own (doc/PACKING_INPUT.md), so the
  !> volume fraction is within sum_k v_k / (2V) of phi. One species: packing_count.
  pure function species_counts(phi, box, radius, share, by_volume) result(counts)
    real(dp), intent(in) :: phi, box(3), radius(:), share(:)
    logical, intent(in) :: by_volume
    integer :: counts(size(radius))
    real(dp) :: v(size(radius))
    if (size(radius) == 1) then
      counts(1) = packing_count(phi, box, radius(1))
      return
    end if
    v = 4.0_dp / 3 * pi * radius**3
    if (by_volume) then
      counts = nint(share * (phi * product(box)) / v)
    else
      counts = nint(share * (phi * product(box) / sum(share * v)))
    end if
  end function species_counts

  !> n spheres split into species by share (of the solid volume when by_volume, else of the
  !> number): the counts nearest n w_k (w_k = share_k / v_k normalised, or share_k), made to sum
  !> to n exactly by the largest remainders (Hamilton's rule; ties to the lower k).
  pure function species_counts_total(n, radius, share, by_volume) result(counts)
    integer, intent(in) :: n
    real(dp), intent(in) :: radius(:), share(:)
    logical, intent(in) :: by_volume
    integer :: counts(size(radius))
    real(dp) :: w(size(radius)), rem(size(radius))
    integer :: k, left
    if (by_volume) then
      w = share / radius**3
    else
      w = share
    end if
    w = n * (w / sum(w))
    counts = floor(w)
    rem = w - counts
    left = n - sum(counts)
    do k = 1, left
      counts(maxloc(rem, 1)) = counts(maxloc(rem, 1)) + 1
      rem(maxloc(rem, 1)) = -1
    end do
  end function species_counts_total

  !> The box of the shape of box that holds counts(k) spheres of radius radius(k) at volume
  !> fraction phi exactly (one species: packing_box_for).
  pure function species_box_for(counts, radius, phi, box) result(b)
    integer, intent(in) :: counts(:)
    real(dp), intent(in) :: radius(:), phi, box(3)
    real(dp) :: b(3)
    if (size(radius) == 1) then
      b = packing_box_for(counts(1), phi, box, radius(1))
    else
      b = box * (sum(counts * (4.0_dp / 3 * pi * radius**3)) / (phi * product(box)))**(1.0_dp / 3)
    end if
  end function species_box_for

end module mod_packing_geometry
