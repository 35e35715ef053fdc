! Unit test of mod_neighbours (doc/CONTACT.md "Neighbour search"). Invariants, all exact (integer sets, no tolerance):
!   1. The cell list returns exactly the pairs (i < j, image shift s) with |x_j - x_i + s L| <
!      cutoff found by an O(N^2) search that tries all 27 periodic images of every pair (it does
!      not assume the minimum image), for random configurations at volume fraction phi = 0.1,
!      0.2, 0.3, 0.4, 0.5, 0.55 and N up to 5000: uniform random points at that number density
!      (generic distances, overlaps allowed) and hard-sphere packings from mod_packing (many
!      pairs just beyond contact), in a triply periodic box, in the Couette cell (x, z periodic,
!      walls in y) and with thin boxes of 2 or 3 cells per direction (wrapped neighbour cells
!      repeat). Particles on cell and box boundaries, slightly inside the walls and outside
!      [0, L) in periodic directions (unwrapped) are included.
!   2. The wall candidates are exactly the particles whose centre is closer than wall_cutoff to
!      a wall plane (direct O(N) scan).
!   3. Skin: after moves of less than skin/2 per particle, nlist_needs_rebuild is false and every
!      pair closer than cutoff - skin is in the old list; a move beyond skin/2 asks for a rebuild.
!   4. Work per particle (distance evaluations / N) does not grow with N: ratio between
!      N = 5000 and N = 500 at phi = 0.3 below 1.3 (cell-occupancy fluctuations only; the
!      timing is in scripts/bench_neighbours.sh).
program test_neighbours
  use mod_kinds, only: dp, i8, pi
  use mod_neighbours, only: nlist_t, nlist_init, nlist_build, nlist_needs_rebuild, min_image
  use mod_packing, only: rng_t, rng_seed, rng_uniform, random_packing, packing_report_t
  use mod_packing_geometry, only: packing_box_for
  use mod_unit_checks, only: check, fail, finish
  implicit none
  integer :: k, info
  real(dp), parameter :: phis(6) = [0.1_dp, 0.2_dp, 0.3_dp, 0.4_dp, 0.5_dp, 0.55_dp]
  integer, parameter :: ns(6) = [5000, 3000, 2000, 1500, 1000, 5000]
  real(dp), parameter :: cutoff = 2.25_dp, wall_cutoff = 1.25_dp
  real(dp), allocatable :: x(:,:)
  type(rng_t) :: g
  type(nlist_t) :: nl
  type(packing_report_t) :: rep
  character(len=200) :: msg
  integer(i8) :: work(2)
  real(dp) :: box(3), t0, t1

  call rng_seed(g, 4)
  do k = 1, size(phis)
    ! uniform random points, triply periodic cube
    call uniform_points(ns(k), phis(k), [1.0_dp, 1.0_dp, 1.0_dp], .true., x, box)
    call compare('uniform periodic', x, box, [.true., .true., .true.])
    ! uniform random points, Couette cell 2:1:1
    call uniform_points(max(100, ns(k) / 2), phis(k), [2.0_dp, 1.0_dp, 1.0_dp], .false., x, box)
    call compare('uniform Couette', x, box, [.true., .false., .true.])
  end do
  ! hard-sphere packings (pairs just beyond contact), periodic and Couette
  do k = 1, size(phis)
    box = packing_box_for(1000, phis(k), [1.0_dp, 1.0_dp, 1.0_dp], 1.0_dp)
    call random_packing(1000, box, [.true., .true., .true.], 1.0_dp, 0.0_dp, k, 20, &
                        x, info, msg, rep)
    if (info /= 0) call fail('packing: '//trim(msg))
    call compare('packing periodic', x, box, [.true., .true., .true.])
    box = packing_box_for(1000, phis(k), [1.5_dp, 1.0_dp, 1.0_dp], 1.0_dp)
    call random_packing(1000, box, [.true., .false., .true.], 1.0_dp, 0.0_dp, k, 20, &
                        x, info, msg, rep)
    if (info /= 0) call fail('packing: '//trim(msg))
    call compare('packing Couette', x, box, [.true., .false., .true.])
  end do
  ! y periodic too, thin boxes: 2 and 3 cells across (neighbour cells repeat after wrapping)
  call uniform_points(400, 0.3_dp, [1.0_dp, 1.0_dp, 1.0_dp], .true., x, box)
  box = [2 * cutoff, 3 * cutoff + 0.1_dp, 40.0_dp]
  call scatter(x, box, .true.)
  call compare('thin periodic (2, 3 cells)', x, box, [.true., .true., .true.])
  box = [2 * cutoff + 0.3_dp, 7.0_dp, 2 * cutoff]
  call scatter(x, box, .false.)
  call compare('thin Couette', x, box, [.true., .false., .true.])
  ! boundaries and unwrapped positions
  call uniform_points(1000, 0.3_dp, [1.0_dp, 1.0_dp, 1.0_dp], .false., x, box)
  call edge_cases(x, box)
  call compare('edges, unwrapped positions', x, box, [.true., .false., .true.], .true.)

  call skin_check()

  ! work per particle
  call uniform_points(500, 0.3_dp, [1.0_dp, 1.0_dp, 1.0_dp], .true., x, box)
  call build(x, box, [.true., .true., .true.])
  work(1) = nl%n_dist / 500
  call cpu_time(t0)
  call uniform_points(5000, 0.3_dp, [1.0_dp, 1.0_dp, 1.0_dp], .true., x, box)
  call build(x, box, [.true., .true., .true.])
  call cpu_time(t1)
  work(2) = nl%n_dist / 5000
  print '(a,i0,a,i0,a,f7.4,a)', 'distance evaluations per particle: N = 500: ', work(1), &
    ', N = 5000: ', work(2), ' (build ', t1 - t0, ' s)'
  call check(real(work(2), dp) <= 1.3_dp * real(work(1), dp), 'work per particle does not grow with N (O(N) build)')

  call finish('test_neighbours')

contains

  !> n uniform random points at number density phi / (4/3 pi): a box of the given shape.
  !> Couette (periodic_y false): y uniform in [0.99, Ly - 0.99] (slightly inside the walls).
  subroutine uniform_points(n, phi, shape, periodic_y, xx, bx)
    integer, intent(in) :: n
    real(dp), intent(in) :: phi, shape(3)
    logical, intent(in) :: periodic_y
    real(dp), allocatable, intent(out) :: xx(:,:)
    real(dp), intent(out) :: bx(3)
    bx = packing_box_for(n, phi, shape, 1.0_dp)
    allocate(xx(3, n))
    call scatter(xx, bx, periodic_y)
  end subroutine uniform_points

  subroutine scatter(xx, bx, periodic_y)
    real(dp), intent(inout) :: xx(:,:)
    real(dp), intent(in) :: bx(3)
    logical, intent(in) :: periodic_y
    integer :: i, d
    do i = 1, size(xx, 2)
      do d = 1, 3
        xx(d, i) = bx(d) * rng_uniform(g)
      end do
      if (.not. periodic_y) xx(2, i) = 0.99_dp + (bx(2) - 1.98_dp) * rng_uniform(g)
    end do
  end subroutine scatter

  !> Put particles on cell boundaries, at 0 and just below L, and unwrap some by +-L.
  subroutine edge_cases(xx, bx)
    real(dp), intent(inout) :: xx(:,:)
    real(dp), intent(in) :: bx(3)
    real(dp) :: side
    integer :: i
    side = bx(1) / int(bx(1) / cutoff)
    xx(1, 1) = 0
    xx(1, 2) = nearest(bx(1), -1.0_dp)
    xx(3, 2) = nearest(bx(3), -1.0_dp)
    xx(1, 3) = side
    xx(1, 4) = 2 * side
    xx(:, 5) = xx(:, 4) + [cutoff - 1.0e-12_dp, 0.0_dp, 0.0_dp]   ! just inside the cutoff
    xx(:, 6) = xx(:, 4) + [0.0_dp, 0.0_dp, cutoff]                 ! exactly at the cutoff: out
    xx(2, 7) = 0.99_dp
    xx(2, 8) = bx(2) - 0.99_dp
    xx(:, 9) = [0.1_dp, 5.0_dp, 0.1_dp]
    xx(:, 10) = [bx(1) - 0.1_dp, 5.5_dp, bx(3) - 0.1_dp]          ! partner of 9 across a corner
    do i = 20, size(xx, 2), 7
      xx(1, i) = xx(1, i) + bx(1) * merge(1, -1, mod(i, 2) == 0)
      xx(3, i) = xx(3, i) - 2 * bx(3)
    end do
  end subroutine edge_cases

  subroutine build(xx, bx, per)
    real(dp), intent(in) :: xx(:,:), bx(3)
    logical, intent(in) :: per(3)
    integer :: inf
    call nlist_init(nl, size(xx, 2), bx, per, cutoff, wall_cutoff, 0.25_dp, inf)
    if (inf /= 0) call fail('nlist_init refused a valid box')
    call nlist_build(nl, xx)
  end subroutine build

  !> Key of (i, j, shift) with shift components in -3..3 (unwrapped positions can need +-2).
  pure integer(i8) function key(n, i, j, s)
    integer, intent(in) :: n, i, j, s(3)
    key = ((int(i, i8) * (n + 1) + j) * 7 + (s(1) + 3)) * 49 + (s(2) + 3) * 7 + (s(3) + 3)
  end function key

  subroutine compare(label, xx, bx, per, unwrapped)
    character(len=*), intent(in) :: label
    logical, intent(in), optional :: unwrapped
    real(dp), intent(in) :: xx(:,:), bx(3)
    logical, intent(in) :: per(3)
    integer :: n, i, j, m, nb, s1, s2, s3, lo(3), hi(3), s(3), d, nbw, nw_direct
    integer(i8), allocatable :: kb(:), kc(:), tmp(:)
    real(dp) :: r(3), c2, base(3)
    logical :: same
    n = size(xx, 2)
    call build(xx, bx, per)
    ! O(N^2) over all images: shifts -1..1 in periodic directions, -3..3 when positions are
    ! unwrapped by up to 2 L
    c2 = cutoff**2
    lo = 0
    hi = 0
    do d = 1, 3
      if (per(d)) then
        hi(d) = 1
        if (present(unwrapped)) hi(d) = 3
        lo(d) = -hi(d)
      end if
    end do
    allocate(kb(1024))
    nb = 0
    do i = 1, n
      do j = i + 1, n
        base = xx(:, j) - xx(:, i)
        ! (a component alone beyond the cutoff excludes the image: a necessary condition only)
        do s3 = lo(3), hi(3)
          if (abs(base(3) + s3 * bx(3)) >= cutoff) cycle
          do s2 = lo(2), hi(2)
            if (abs(base(2) + s2 * bx(2)) >= cutoff) cycle
            do s1 = lo(1), hi(1)
              r = base + [s1, s2, s3] * bx
              if (sum(r**2) < c2) then
                if (nb == size(kb)) then
                  allocate(tmp(2 * nb))
                  tmp(1:nb) = kb(1:nb)
                  call move_alloc(tmp, kb)
                end if
                nb = nb + 1
                kb(nb) = key(n, i, j, [s1, s2, s3])
              end if
            end do
          end do
        end do
      end do
    end do
    allocate(kc(nl%npairs))
    do m = 1, nl%npairs
      s = nl%shift(:, m)
      kc(m) = key(n, nl%pair(1, m), nl%pair(2, m), s)
      ! the shift must reproduce the minimum image used for the test
      r = xx(:, nl%pair(2, m)) - xx(:, nl%pair(1, m)) + s * bx
      if (maxval(abs(r - min_image(xx(:, nl%pair(2, m)) - xx(:, nl%pair(1, m)), bx, per))) > &
          1.0e-12_dp * maxval(bx)) call fail(label//': shift does not give the minimum image')
    end do
    call heapsort(kb(1:nb))
    call heapsort(kc)
    same = nb == nl%npairs
    if (same) same = all(kb(1:nb) == kc)
    nbw = 0
    nw_direct = 0
    if (.not. per(2)) then
      do i = 1, n
        if (xx(2, i) < wall_cutoff) nw_direct = nw_direct + 1
        if (bx(2) - xx(2, i) < wall_cutoff) nw_direct = nw_direct + 1
      end do
      do m = 1, nl%nwalls
        i = nl%wall(1, m)
        if (nl%wall(2, m) == 1 .and. xx(2, i) < wall_cutoff) nbw = nbw + 1
        if (nl%wall(2, m) == 2 .and. bx(2) - xx(2, i) < wall_cutoff) nbw = nbw + 1
      end do
    end if
    print '(a,a28,a,i5,a,f5.2,a,i6,a,i6,a,i4,a,l1)', '  ', label, ' N ', n, ' phi ', &
      n * 4 * pi / 3 / product(bx), ' pairs ', nl%npairs, ' O(N^2) ', nb, ' walls ', nl%nwalls, &
      ' equal ', same
    call check(same, label//': the pair set is the O(N^2) search''s')
    call check(nbw == nl%nwalls .and. nw_direct == nl%nwalls, label//': the wall candidates are the direct search''s')
  end subroutine compare

  subroutine skin_check()
    real(dp), allocatable :: y(:,:)
    integer :: i, j, m, d, missing
    real(dp) :: skin, r(3)
    logical :: found
    skin = 0.25_dp
    call uniform_points(2000, 0.4_dp, [1.0_dp, 1.0_dp, 1.0_dp], .true., x, box)
    call build(x, box, [.true., .true., .true.])
    y = x
    do i = 1, size(x, 2)                       ! moves of length < skin/2 in a random direction
      do d = 1, 3
        r(d) = 2 * rng_uniform(g) - 1
      end do
      y(:, i) = x(:, i) + 0.49_dp * skin * rng_uniform(g) * r / max(norm2(r), 1.0e-12_dp)
    end do
    call check(.not. nlist_needs_rebuild(nl, y), 'skin: no rebuild asked after moves < skin/2')
    missing = 0
    do i = 1, size(y, 2)
      do j = i + 1, size(y, 2)
        r = min_image(y(:, j) - y(:, i), box, [.true., .true., .true.])
        if (norm2(r) >= cutoff - skin) cycle
        found = .false.
        do m = 1, nl%npairs
          if (nl%pair(1, m) == i .and. nl%pair(2, m) == j) then
            found = .true.
            exit
          end if
        end do
        if (.not. found) missing = missing + 1
      end do
    end do
    print '(a,i0)', '  skin: pairs within cutoff - skin missing from the old list: ', missing
    call check(missing == 0, 'skin: every pair within cutoff - skin is in the old list')
    y(:, 7) = x(:, 7) + [0.51_dp * skin, 0.0_dp, 0.0_dp]
    call check(nlist_needs_rebuild(nl, y), 'skin: a rebuild after a move > skin/2')
  end subroutine skin_check

  subroutine heapsort(a)
    integer(i8), intent(inout) :: a(:)
    integer :: n, i, last
    integer(i8) :: t
    n = size(a)
    do i = n / 2, 1, -1
      call sift(a, i, n)
    end do
    do last = n, 2, -1
      t = a(1)
      a(1) = a(last)
      a(last) = t
      call sift(a, 1, last - 1)
    end do
  end subroutine heapsort

  subroutine sift(a, start, bottom)
    integer(i8), intent(inout) :: a(:)
    integer, intent(in) :: start, bottom
    integer :: root, child
    integer(i8) :: t
    root = start
    do while (2 * root <= bottom)
      child = 2 * root
      if (child < bottom) then
        if (a(child + 1) > a(child)) child = child + 1
      end if
      if (a(root) >= a(child)) return
      t = a(root)
      a(root) = a(child)
      a(child) = t
      root = child
    end do
  end subroutine sift

end program test_neighbours
