! Neighbour search by cell lists with a skin: O(N) per build (doc/CONTACT.md, "Neighbour search").
! Box [0,Lx) x [0,Ly) x [0,Lz); each direction periodic or bounded (y: walls at 0 and Ly).
! Positions may lie outside the box in periodic directions (they are not wrapped here).
! A pair i < j is listed when the minimum-image distance of its centres is < cutoff, with the
! integer image shift s such that x_j - x_i + s * box is that minimum image (s = 0 in bounded
! directions); a particle-wall candidate (i, 1 = lower | 2 = upper wall) when the distance of the
! centre to the wall plane is < wall_cutoff. Choose cutoff = contact range + skin and
! wall_cutoff = wall contact range + skin: the lists then hold every contact as long as no
! particle has moved more than skin/2 since the build (nlist_needs_rebuild).
! Every periodic length must be >= 2 cutoff, so that at most one image of a particle is in range.
! Lees-Edwards boundaries (mod_lees_edwards; nlist_init's le): y is periodic with images sliding
! by the offset delta in x; a cell row reached across y = 0 or Ly is searched over all its x cells
! (the sliding images are not aligned with the cells), distances are le_separation's, the image
! shift is not set (0), and the list is rebuilt once 2 x (largest move) + (change of delta since the
! build) exceeds the skin, the bound on the change of any pair distance across the boundary.
module mod_neighbours
  use mod_kinds, only: dp, i8
  use mod_lees_edwards, only: lees_edwards_t, le_separation
  implicit none
  private
  public :: nlist_t, nlist_init, nlist_build, nlist_needs_rebuild, nlist_candidates, min_image
  public :: cell_coord, cell_index, cells_around

  type :: nlist_t
    integer :: np = 0
    real(dp) :: box(3) = 0, cutoff = 0, wall_cutoff = 0, skin = 0
    logical :: periodic(3) = .true.
    integer :: ncell(3) = 1
    integer :: npairs = 0, nwalls = 0
    integer, allocatable :: pair(:,:)        ! (2, :) i < j
    integer, allocatable :: shift(:,:)       ! (3, :) image shift of each pair
    integer, allocatable :: wall(:,:)        ! (2, :) particle, wall (1: y = 0, 2: y = Ly)
    integer, allocatable :: cell_start(:)    ! (ncells + 1) particles of cell c: order(start(c):start(c+1)-1)
    integer, allocatable :: order(:)         ! (np) particle indices sorted by cell
    integer, allocatable :: cell_of(:)       ! (np)
    real(dp), allocatable :: x_ref(:,:)      ! (3, np) positions at the last build
    logical :: built = .false.               ! x_ref and the lists hold a build
    type(lees_edwards_t) :: le               ! sliding boundaries in y (le%active), with delta now
    real(dp) :: offset_ref = 0               ! delta at the last build
    integer(i8) :: n_dist = 0                ! distance evaluations of the last build
  end type nlist_t

contains

  !> Minimum-image separation d - box * anint(d / box) in periodic directions.
  pure function min_image(d, box, periodic) result(r)
    real(dp), intent(in) :: d(3), box(3)
    logical, intent(in) :: periodic(3)
    real(dp) :: r(3)
    integer :: k
    r = d
    do k = 1, 3
      if (periodic(k)) r(k) = r(k) - box(k) * anint(r(k) / box(k))
    end do
  end function min_image

  !> Set up for np particles. info: 0 ok; 1 a periodic length < 2 cutoff; 2 cutoff, wall_cutoff
  !> or a box length not > 0, or skin < 0 or skin >= cutoff.
  !> le, optional: Lees-Edwards boundaries in y (then periodic(2) must be .true.).
  subroutine nlist_init(nl, np, box, periodic, cutoff, wall_cutoff, skin, info, le)
    type(nlist_t), intent(inout) :: nl
    integer, intent(in) :: np
    real(dp), intent(in) :: box(3), cutoff, wall_cutoff, skin
    logical, intent(in) :: periodic(3)
    integer, intent(out) :: info
    type(lees_edwards_t), intent(in), optional :: le
    integer :: k
    info = 0
    nl%le%active = .false.
    if (present(le)) nl%le = le
    if (.not. (cutoff > 0) .or. .not. (wall_cutoff > 0) .or. .not. all(box > 0) .or. &
        .not. (skin >= 0) .or. skin >= cutoff) then
      info = 2
      return
    end if
    do k = 1, 3
      if (periodic(k) .and. box(k) < 2 * cutoff) info = 1
    end do
    if (info /= 0) return
    nl%np = np
    nl%box = box
    nl%periodic = periodic
    nl%cutoff = cutoff
    nl%wall_cutoff = wall_cutoff
    nl%skin = skin
    ! cells no smaller than the cutoff: the 27 cells around a particle's cell hold all partners
    nl%ncell = max(1, int(box / cutoff))
    if (allocated(nl%cell_start)) deallocate(nl%cell_start, nl%order, nl%cell_of, nl%x_ref)
    allocate(nl%cell_start(product(nl%ncell) + 1), nl%order(np), nl%cell_of(np), nl%x_ref(3, np))
    if (.not. allocated(nl%pair)) allocate(nl%pair(2, max(16, 8 * np)), nl%shift(3, max(16, 8 * np)))
    if (.not. allocated(nl%wall)) allocate(nl%wall(2, max(16, np)))
    nl%npairs = 0
    nl%nwalls = 0
  end subroutine nlist_init

  !> Cell coordinates (0-based) of a position in a grid of ncell cells over box; wrapped in
  !> periodic directions, clamped to the edge cells in bounded ones (a particle slightly inside a
  !> wall stays in the edge cell). Shared with the packing generator's cell lists.
  pure function cell_coord(x, box, periodic, ncell) result(c)
    real(dp), intent(in) :: x(3), box(3)
    logical, intent(in) :: periodic(3)
    integer, intent(in) :: ncell(3)
    integer :: c(3), k
    real(dp) :: s
    do k = 1, 3
      s = x(k) / box(k)
      if (periodic(k)) s = s - floor(s)
      c(k) = min(ncell(k) - 1, max(0, int(s * ncell(k))))
    end do
  end function cell_coord

  !> 1-based index of the cell of coordinates c (x fastest).
  pure integer function cell_index(c, ncell)
    integer, intent(in) :: c(3), ncell(3)
    cell_index = 1 + c(1) + ncell(1) * (c(2) + ncell(2) * c(3))
  end function cell_index

  !> The distinct cells (indices) around cell c: 27, fewer when a periodic direction has < 3
  !> cells (the images coincide) or at a wall.
  pure subroutine cells_around(c, ncell, periodic, cells, nc)
    integer, intent(in) :: c(3), ncell(3)
    logical, intent(in) :: periodic(3)
    integer, intent(out) :: cells(27), nc
    integer :: o1, o2, o3, k, cn(3), idx
    logical :: outside, repeats
    nc = 0
    cells = 0
    repeats = any(periodic .and. ncell < 3)     ! only then do two offsets wrap onto one cell
    do o3 = -1, 1
      do o2 = -1, 1
        do o1 = -1, 1
          cn = c + [o1, o2, o3]
          outside = .false.
          do k = 1, 3
            if (cn(k) < 0 .or. cn(k) >= ncell(k)) then
              if (periodic(k)) then
                cn(k) = modulo(cn(k), ncell(k))
              else
                outside = .true.
              end if
            end if
          end do
          if (outside) cycle
          idx = cell_index(cn, ncell)
          if (repeats) then
            if (any(cells(1:nc) == idx)) cycle
          end if
          nc = nc + 1
          cells(nc) = idx
        end do
      end do
    end do
  end subroutine cells_around

  !> Lees-Edwards: the distinct cells around cell c (all directions periodic); a row reached
  !> across y = 0 or Ly contributes all its x cells, since the sliding images are not aligned with
  !> them. cells must hold 9 ncell(1) entries.
  pure subroutine le_cells_around(c, ncell, cells, nc)
    integer, intent(in) :: c(3), ncell(3)
    integer, intent(out) :: cells(:), nc
    integer :: o1, o2, o3, cn(3), idx, x_lo, x_hi
    logical :: across
    nc = 0
    do o3 = -1, 1
      do o2 = -1, 1
        cn(2) = c(2) + o2
        across = cn(2) < 0 .or. cn(2) >= ncell(2)
        cn(2) = modulo(cn(2), ncell(2))
        cn(3) = modulo(c(3) + o3, ncell(3))
        x_lo = c(1) - 1
        x_hi = c(1) + 1
        if (across) then
          x_lo = 0
          x_hi = ncell(1) - 1
        end if
        do o1 = x_lo, x_hi
          cn(1) = modulo(o1, ncell(1))
          idx = cell_index(cn, ncell)
          if (any(cells(1:nc) == idx)) cycle
          nc = nc + 1
          cells(nc) = idx
        end do
      end do
    end do
  end subroutine le_cells_around

  !> Build the pair and wall lists from positions x(3, np). The arrays grow as needed.
  subroutine nlist_build(nl, x)
    type(nlist_t), intent(inout) :: nl
    real(dp), intent(in) :: x(:,:)
    integer :: i, j, k, m, c, q, ncl, cells(27), ncells
    integer, allocatable :: fill(:), le_cells(:)
    real(dp) :: d(3), r(3), rc2, vshift(3)
    integer(i8) :: nd

    ! counting sort of the particles by cell
    ncells = product(nl%ncell)
    nl%cell_start = 0
    do i = 1, nl%np
      c = cell_index(cell_coord(x(:, i), nl%box, nl%periodic, nl%ncell), nl%ncell)
      nl%cell_of(i) = c
      nl%cell_start(c + 1) = nl%cell_start(c + 1) + 1
    end do
    nl%cell_start(1) = 1
    do c = 1, ncells
      nl%cell_start(c + 1) = nl%cell_start(c + 1) + nl%cell_start(c)
    end do
    allocate(fill(ncells))
    fill = nl%cell_start(1:ncells)
    do i = 1, nl%np
      c = nl%cell_of(i)
      nl%order(fill(c)) = i
      fill(c) = fill(c) + 1
    end do

    rc2 = nl%cutoff**2
    nl%npairs = 0
    nd = 0
    if (nl%le%active) allocate(le_cells(9 * nl%ncell(1)))
    do i = 1, nl%np
      if (nl%le%active) then
        call le_cells_around(cell_coord(x(:, i), nl%box, nl%periodic, nl%ncell), nl%ncell, le_cells, ncl)
      else
        call cells_around(cell_coord(x(:, i), nl%box, nl%periodic, nl%ncell), nl%ncell, nl%periodic, cells, ncl)
      end if
      do m = 1, ncl
        if (nl%le%active) then
          c = le_cells(m)
        else
          c = cells(m)
        end if
        do q = nl%cell_start(c), nl%cell_start(c + 1) - 1
          j = nl%order(q)
          if (j <= i) cycle
          nd = nd + 1
          d = x(:, j) - x(:, i)
          if (nl%le%active) then
            call le_separation(nl%le, d, r, vshift)
          else
            r = min_image(d, nl%box, nl%periodic)
          end if
          if (sum(r**2) < rc2) then
            if (nl%npairs == size(nl%pair, 2)) call grow_pairs(nl)
            nl%npairs = nl%npairs + 1
            nl%pair(:, nl%npairs) = [i, j]
            do k = 1, 3
              nl%shift(k, nl%npairs) = 0
              if (nl%periodic(k) .and. .not. nl%le%active) nl%shift(k, nl%npairs) = nint((r(k) - d(k)) / nl%box(k))
            end do
          end if
        end do
      end do
    end do
    nl%n_dist = nd

    nl%nwalls = 0
    if (.not. nl%periodic(2)) then
      do i = 1, nl%np
        if (x(2, i) < nl%wall_cutoff) call add_wall(i, 1)
        if (nl%box(2) - x(2, i) < nl%wall_cutoff) call add_wall(i, 2)
      end do
    end if
    nl%x_ref(:, 1:nl%np) = x(:, 1:nl%np)
    nl%offset_ref = nl%le%offset
    nl%built = .true.

  contains

    subroutine add_wall(ip, w)
      integer, intent(in) :: ip, w
      integer, allocatable :: tmp(:,:)
      if (nl%nwalls == size(nl%wall, 2)) then
        allocate(tmp(2, 2 * size(nl%wall, 2)))
        tmp(:, 1:nl%nwalls) = nl%wall(:, 1:nl%nwalls)
        call move_alloc(tmp, nl%wall)
      end if
      nl%nwalls = nl%nwalls + 1
      nl%wall(:, nl%nwalls) = [ip, w]
    end subroutine add_wall

  end subroutine nlist_build

  subroutine grow_pairs(nl)
    type(nlist_t), intent(inout) :: nl
    integer, allocatable :: tp(:,:), ts(:,:)
    allocate(tp(2, 2 * size(nl%pair, 2)), ts(3, 2 * size(nl%pair, 2)))
    tp(:, 1:nl%npairs) = nl%pair(:, 1:nl%npairs)
    ts(:, 1:nl%npairs) = nl%shift(:, 1:nl%npairs)
    call move_alloc(tp, nl%pair)
    call move_alloc(ts, nl%shift)
  end subroutine grow_pairs

  !> True when some particle has moved more than skin/2 (minimum image) since the last build.
  logical function nlist_needs_rebuild(nl, x) result(yes)
    type(nlist_t), intent(in) :: nl
    real(dp), intent(in) :: x(:,:)
    integer :: i
    real(dp) :: lim2, drift
    lim2 = (0.5_dp * nl%skin)**2
    yes = .false.
    if (nl%le%active) then
      ! pairs across the sliding boundary also move apart by the change of delta
      drift = abs(nl%le%offset - nl%offset_ref)
      drift = min(drift, nl%box(1) - drift)
      if (drift >= nl%skin) then
        yes = .true.
        return
      end if
      lim2 = (0.5_dp * (nl%skin - drift))**2
    end if
    do i = 1, nl%np
      if (sum(min_image(x(:, i) - nl%x_ref(:, i), nl%box, nl%periodic)**2) > lim2) then
        yes = .true.
        return
      end if
    end do
  end function nlist_needs_rebuild

  !> The candidates at x in canonical order (pairs by i then j, walls by particle then wall), so
  !> that forces summed over them come out in the same order whatever list is in use: a run
  !> restarted from a checkpoint (fresh list) repeats the arithmetic of an uninterrupted one
  !> bitwise. The list is rebuilt (and pairs, walls rewritten) only when it has never been built
  !> or some particle has moved more than skin/2 since; otherwise pairs and walls are left as they are.
  !> offset, optional: the Lees-Edwards offset delta now (lists made with nlist_init's le).
  subroutine nlist_candidates(nl, x, pairs, npairs, walls, nwalls, offset)
    type(nlist_t), intent(inout) :: nl
    real(dp), intent(in) :: x(:,:)
    integer, allocatable, intent(inout) :: pairs(:,:), walls(:,:)
    integer, intent(inout) :: npairs, nwalls
    real(dp), intent(in), optional :: offset
    if (present(offset)) nl%le%offset = offset
    if (nl%built) then
      if (.not. nlist_needs_rebuild(nl, x)) return
    end if
    call nlist_build(nl, x)
    call canonical_order(nl%pair, nl%npairs, pairs, npairs)
    call canonical_order(nl%wall, nl%nwalls, walls, nwalls)
  end subroutine nlist_candidates

  !> Copy the n columns of list (2, :) into sorted (2, n), ordered by (list(1, :), list(2, :)).
  !> The neighbour search gives the first entries in ascending order already (pairs by i, walls by
  !> particle); an insertion sort orders the few entries of each run by the second index.
  subroutine canonical_order(list, n, sorted, nsorted)
    integer, intent(in) :: list(:,:), n
    integer, allocatable, intent(inout) :: sorted(:,:)
    integer, intent(out) :: nsorted
    integer :: k, q, key(2)
    if (allocated(sorted)) then
      if (size(sorted, 2) < max(1, n)) deallocate(sorted)
    end if
    if (.not. allocated(sorted)) allocate(sorted(2, max(16, n)))
    nsorted = n
    sorted(:, 1:n) = list(:, 1:n)
    do k = 2, n
      key = sorted(:, k)
      q = k - 1
      do while (q >= 1)
        if (sorted(1, q) < key(1) .or. (sorted(1, q) == key(1) .and. sorted(2, q) <= key(2))) exit
        sorted(:, q + 1) = sorted(:, q)
        q = q - 1
      end do
      sorted(:, q + 1) = key
    end do
  end subroutine canonical_order

end module mod_neighbours
