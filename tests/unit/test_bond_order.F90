! Invariants of Steinhardt's bond-orientational order Q6 (mod_bond_order), against the values of
! perfect lattices published by Steinhardt, Nelson & Ronchetti (1983, Phys. Rev. B 28, 784, Table
! I): face-centred cubic (12 neighbours) 0.57452, hexagonal close-packed (12) 0.48476,
! body-centred cubic (8 + 6 neighbours) 0.51069, simple cubic (6) 0.35355. The values are
! rounded to 5 digits, so the tolerance is 5e-6; the lattices are exact (every sphere sees the
! same shell), so every local q6 equals the global Q6 to round-off (1e-12).
!  1. the four lattices in periodic boxes, the bonds from the shells by distance;
!  2. rotation invariance: the fcc crystal's bonds turned by an arbitrary rotation keep Q6 (1e-12:
!     the harmonics are evaluated afresh, a few ulps of each);
!  3. disorder: 2000 spheres placed at random (an ideal gas) with bonds below 1.4 of the mean
!     spacing: Q6 of the ~N_b bonds is of order N_b^(-1/2), here below 0.05, and the mean local q6
!     well below the lattices' (< 0.45);
!  4. a sphere without bonds has q6 = 0;
!  5. shares (bond_order_shares, a rank's own spheres): over a partition of the ideal gas into
!     three sets the shares' sums give Q6 (bond_order_global) to round-off (1e-12: the sums in
!     another order) and every sphere's local q6 exactly.
program test_bond_order
  use mod_kinds, only: dp
  use mod_bond_order, only: bond_order_q6, bond_order_shares, bond_order_global
  use mod_unit_checks, only: check, check_below, finish
  implicit none
  real(dp), allocatable :: x(:, :)
  real(dp) :: box(3), q6, rot(3, 3), c, s, value_straight
  real(dp), allocatable :: q6_local(:)
  character(len=80) :: what

  ! 1. lattices; spacing of the cubic cell 1
  call lattice('fcc', reshape([0, 0, 0, 0, 1, 1, 1, 0, 1, 1, 1, 0] * 0.5_dp, [3, 4]), 4, 0.8_dp, 0.57452_dp)
  call lattice('bcc', reshape([0, 0, 0, 1, 1, 1] * 0.5_dp, [3, 2]), 4, 1.1_dp, 0.51069_dp)
  call lattice('sc', reshape([0.0_dp, 0.0_dp, 0.0_dp], [3, 1]), 4, 1.2_dp, 0.35355_dp)
  ! bcc with its 8 nearest neighbours only (a cutoff between sqrt(3)/2 and 1)
  call lattice('bcc, 8 neighbours', reshape([0, 0, 0, 1, 1, 1] * 0.5_dp, [3, 2]), 4, 0.95_dp, 0.62854_dp)
  call hcp_lattice()

  ! 2. the fcc crystal rotated (about an oblique axis, by 0.7 rad)
  c = cos(0.7_dp)
  s = sin(0.7_dp)
  rot = rotation([1.0_dp, 2.0_dp, 3.0_dp] / sqrt(14.0_dp), c, s)
  call cubic_cells(reshape([0, 0, 0, 0, 1, 1, 1, 0, 1, 1, 1, 0] * 0.5_dp, [3, 4]), 3, x, box)
  call q6_of(x, box, 0.8_dp, value_straight, q6_local)
  call q6_of(x, box, 0.8_dp, q6, q6_local, turn=rot)
  call check_below('fcc with every bond rotated: |Q6 - Q6 unrotated|', abs(q6 - value_straight), 1.0e-12_dp)

  ! 3. an ideal gas
  call random_gas(2000, x, box)
  call q6_of(x, box, 1.4_dp * (product(box) / 2000)**(1.0_dp / 3), q6, q6_local)
  write(what, '(a,f8.5,a)') 'random positions: Q6 = ', q6, ' < 0.05 (order N_b^(-1/2))'
  call check(q6 < 0.05_dp, trim(what))
  write(what, '(a,f8.5,a)') 'random positions: mean local q6 = ', sum(q6_local) / size(q6_local), ' < 0.45'
  call check(sum(q6_local) / size(q6_local) < 0.45_dp, trim(what))

  ! 4. a lone sphere
  call bond_order_q6(1, 0, reshape([0], [2, 0]), reshape([0.0_dp], [3, 0]), q6, q6_local(1:1))
  call check(q6 == 0.0_dp .and. q6_local(1) == 0.0_dp, 'no bonds: Q6 = q6 = 0')

  ! 5. the ideal gas shared out in three sets (by x)
  call random_gas(2000, x, box)
  call shared_out(x, box, 1.4_dp * (product(box) / 2000)**(1.0_dp / 3))
  call finish('test_bond_order')

contains

  ! A cubic lattice of basis `basis` (in cells of side 1), n^3 cells, bonds up to `cutoff`.
  subroutine lattice(name, basis, n, cutoff, published)
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: basis(:, :), cutoff, published
    integer, intent(in) :: n
    real(dp), allocatable :: q(:)
    real(dp) :: value
    call cubic_cells(basis, n, x, box)
    call q6_of(x, box, cutoff, value, q)
    call check_below(name//': |Q6 - published|', abs(value - published), 5.0e-6_dp)
    call check_below(name//': every local q6 equals Q6', maxval(abs(q - value)), 1.0e-12_dp)
  end subroutine lattice

  ! hcp: ABAB stacking of triangular layers, nearest distance 1, layers 2 sqrt(2/3) apart in the
  ! repeat; a periodic box of 6 x 4 x 4 orthorhombic cells of 4 spheres.
  subroutine hcp_lattice()
    real(dp) :: cell(3), basis(3, 4), value
    real(dp), allocatable :: q(:)
    integer :: i, j, k, b, m
    cell = [1.0_dp, sqrt(3.0_dp), 2 * sqrt(2.0_dp / 3)]
    basis(:, 1) = [0.0_dp, 0.0_dp, 0.0_dp]
    basis(:, 2) = [0.5_dp, 0.5_dp * sqrt(3.0_dp), 0.0_dp]
    basis(:, 3) = [0.5_dp, sqrt(3.0_dp) / 6, sqrt(2.0_dp / 3)]
    basis(:, 4) = [0.0_dp, 2 * sqrt(3.0_dp) / 3, sqrt(2.0_dp / 3)]
    if (allocated(x)) deallocate(x)
    allocate(x(3, 6 * 4 * 4 * 4))
    m = 0
    do k = 0, 3
      do j = 0, 3
        do i = 0, 5
          do b = 1, 4
            m = m + 1
            x(:, m) = [i, j, k] * cell + basis(:, b)
          end do
        end do
      end do
    end do
    box = [6, 4, 4] * cell
    call q6_of(x, box, 1.1_dp, value, q)
    call check_below('hcp: |Q6 - published|', abs(value - 0.48476_dp), 5.0e-6_dp)
    call check_below('hcp: every local q6 equals Q6', maxval(abs(q - value)), 1.0e-12_dp)
  end subroutine hcp_lattice

  subroutine cubic_cells(basis, n, pos, side)
    real(dp), intent(in) :: basis(:, :)
    integer, intent(in) :: n
    real(dp), allocatable, intent(out) :: pos(:, :)
    real(dp), intent(out) :: side(3)
    integer :: i, j, k, b, m
    allocate(pos(3, n**3 * size(basis, 2)))
    m = 0
    do k = 0, n - 1
      do j = 0, n - 1
        do i = 0, n - 1
          do b = 1, size(basis, 2)
            m = m + 1
            pos(:, m) = [i, j, k] + basis(:, b)
          end do
        end do
      end do
    end do
    side = n
  end subroutine cubic_cells

  ! Q6 and the local q6 of the spheres at pos in a periodic box, bonds shorter than cutoff;
  ! turn, optional: the bond vectors rotated by it first.
  subroutine q6_of(pos, side, cutoff, value, local, turn)
    real(dp), intent(in) :: pos(:, :), side(3), cutoff
    real(dp), intent(out) :: value
    real(dp), allocatable, intent(out) :: local(:)
    real(dp), intent(in), optional :: turn(3, 3)
    integer, allocatable :: ends(:, :)
    real(dp), allocatable :: sep(:, :)
    integer :: nb
    call bonds_of(pos, side, cutoff, ends, sep, nb, turn)
    allocate(local(size(pos, 2)))
    call bond_order_q6(size(pos, 2), nb, ends, sep, value, local)
  end subroutine q6_of

  ! Check 5: three sets of spheres by x, their shares summed against bond_order_q6.
  subroutine shared_out(pos, side, cutoff)
    real(dp), intent(in) :: pos(:, :), side(3), cutoff
    integer, allocatable :: ends(:, :)
    real(dp), allocatable :: sep(:, :)
    real(dp) :: value, bonds, bonds_sum, q6_set(size(pos, 2)), local(size(pos, 2)), local_sets(size(pos, 2))
    complex(dp) :: total(0:6), total_sum(0:6)
    logical :: owned(size(pos, 2))
    integer :: nb, set, n
    n = size(pos, 2)
    call bonds_of(pos, side, cutoff, ends, sep, nb)
    call bond_order_q6(n, nb, ends, sep, value, local)
    total_sum = (0.0_dp, 0.0_dp)
    bonds_sum = 0
    local_sets = -1
    do set = 0, 2
      owned = int(3 * pos(1, :) / side(1)) == set
      call bond_order_shares(n, nb, ends, sep, owned, total, bonds, q6_set)
      total_sum = total_sum + total
      bonds_sum = bonds_sum + bonds
      where (owned) local_sets = q6_set
    end do
    call check_below('three shares: |Q6 of the summed shares - Q6|', abs(bond_order_global(total_sum, bonds_sum) - value), &
                     1.0e-12_dp)
    call check(bonds_sum == 2 * nb .and. all(local_sets == local), 'three shares: every bond end counted once, '// &
               'every local q6 as bond_order_q6''s')
  end subroutine shared_out

  ! The bonds shorter than cutoff of the spheres at pos in a periodic box (an O(N^2) search): ends
  ! (2, nb) and separations (3, nb), turned by turn when present.
  subroutine bonds_of(pos, side, cutoff, ends, sep, nb, turn)
    real(dp), intent(in) :: pos(:, :), side(3), cutoff
    integer, allocatable, intent(out) :: ends(:, :)
    real(dp), allocatable, intent(out) :: sep(:, :)
    integer, intent(out) :: nb
    real(dp), intent(in), optional :: turn(3, 3)
    real(dp) :: d(3)
    integer :: i, j, n
    n = size(pos, 2)
    allocate(ends(2, 8 * n), sep(3, 8 * n))
    nb = 0
    do i = 1, n
      do j = i + 1, n
        d = pos(:, j) - pos(:, i)
        d = d - side * anint(d / side)
        if (norm2(d) < cutoff) then
          nb = nb + 1
          ends(:, nb) = [i, j]
          sep(:, nb) = d
          if (present(turn)) sep(:, nb) = matmul(turn, d)
        end if
      end do
    end do
  end subroutine bonds_of

  subroutine random_gas(n, pos, side)
    integer, intent(in) :: n
    real(dp), allocatable, intent(out) :: pos(:, :)
    real(dp), intent(out) :: side(3)
    integer, allocatable :: seed(:)
    integer :: m
    call random_seed(size=m)
    allocate(seed(m))
    seed = 12345
    call random_seed(put=seed)
    allocate(pos(3, n))
    call random_number(pos)
    side = 12.6_dp
    pos = pos * side(1)
  end subroutine random_gas

  ! the rotation by angle (cosine c, sine s) about the unit axis u (Rodrigues)
  pure function rotation(u, c, s) result(m)
    real(dp), intent(in) :: u(3), c, s
    real(dp) :: m(3, 3)
    m(:, 1) = [c + u(1)**2 * (1 - c), u(2) * u(1) * (1 - c) + u(3) * s, u(3) * u(1) * (1 - c) - u(2) * s]
    m(:, 2) = [u(1) * u(2) * (1 - c) - u(3) * s, c + u(2)**2 * (1 - c), u(3) * u(2) * (1 - c) + u(1) * s]
    m(:, 3) = [u(1) * u(3) * (1 - c) + u(2) * s, u(2) * u(3) * (1 - c) - u(1) * s, c + u(3)**2 * (1 - c)]
  end function rotation

end program test_bond_order
