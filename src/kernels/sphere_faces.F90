! The unknowns of the staggered (MAC) grid a sphere covers, and the arithmetic of the fictitious
! domain on them (doc/METHOD.md §3), on plain arrays: no PETSc, no ranks. mod_fictitious_domain
! hands in the rank's block of the grid and the field arrays, and keeps only their access.
!
! Component c = 1..3 is u, v, w on the x, y, z faces, c = 4 the cell centres (the interior
! pressure of §3.7). A sphere's visit (sphere_visit) lists the unknowns it owns in the block with
! their wrapped index, their cover alpha (§3.1, less the runner-up's where rivals reach, §3.4) and the relaxation
! 1/(1 + gamma) (§3.3), and adds w g g^T dV to M_p (§3.2). The list comes in runs of one sphere
! and one component (faces_build visits every sphere once), and the per-run kernels below work
! run by run with the block's bounds, so that the compiler sees fixed strides and a run's sums
! stay in registers (doc/DESIGN.md "Fictitious domain", Face runs).
! The offset r of a face from its sphere's centre is not stored (24 B per listed unknown, ~65 B per
! grid cell at the paper's scene; doc/BENCHMARKS.md §14): each pass forms
! it run by run (run_offsets) from the unwrapped index, recovered from the wrapped one and the
! run's box, by the visit's own expression, so it is bitwise the value the visit used.
module mod_sphere_faces
  use mod_kinds, only: dp
  use mod_solid_fraction, only: cube_fraction
  implicit none
  private
  public :: STAGGER, mac_block_t, face_list_t, field_view_t
  public :: faces_build, sphere_visit, sphere_box, box_width, face_run, faces_reserve, run_offsets, face_offset
  public :: torque_arm, carry_corners, carry_run, moments_run, new_lambda_run, update_run, pressure_run
  public :: faces_carry, faces_moments, faces_new_lambda, faces_update

  ! position of unknown c inside its cell, in cells: u on x-faces, v on y-faces, ...
  real(dp), parameter :: STAGGER(3, 4) = reshape([0.0_dp, 0.5_dp, 0.5_dp, 0.5_dp, 0.0_dp, 0.5_dp, &
       0.5_dp, 0.5_dp, 0.0_dp, 0.5_dp, 0.5_dp, 0.5_dp], [3, 4])

  ! The grid as a visit sees it: cells of side h, n per axis over the box, walls at y = 0 and
  ! y = box(2) or periodic, and the block of indices [lo, hi] this rank owns (the same for every
  ! component on the MAC layout of mod_grid). sliding: a Lees-Edwards box (doc/METHOD.md §2.4),
  ! where y is not wrapped either: what a sphere covers beyond y = 0 or Ly is covered by its image
  ! in the box (mod_fictitious_domain visits the images as spheres of their own), and v on j = 0
  ! is an unknown like any other.
  type :: mac_block_t
    real(dp) :: h = 1.0_dp
    real(dp) :: box(3) = 1.0_dp
    integer :: n(3) = 1
    logical :: walls = .false.
    logical :: sliding = .false.
    integer :: lo(3) = 0, hi(3) = 0
  end type mac_block_t

  ! The covered unknowns of a block, in runs of one sphere and one component (offsets r: run_offsets). The arrays grow by
  ! doubling and are kept between steps (no allocation per step).
  type :: face_list_t
    integer :: nf = 0
    integer, allocatable :: ijk(:, :)                        ! (3, :) wrapped index
    real(dp), allocatable :: alpha(:), relax(:)             ! alpha, 1/(1+gamma)
    integer :: nruns = 0
    integer, allocatable :: run_start(:)   ! run r is run_start(r) .. run_start(r+1)-1
    integer, allocatable :: run_comp(:), run_part(:)   ! its component and its sphere
    integer, allocatable :: run_lo(:, :), run_hi(:, :) ! (3, :) its sphere's box (unwrapped indices, sphere_box)
    real(dp), allocatable :: centre(:, :)  ! (3, n) the centres the list was built at
    type(mac_block_t) :: block             ! the block it was built on
  end type face_list_t

  ! One field on the block: the array of a component with the block's bounds (or the ghosted
  ! bounds, for the carry's old Lambda).
  type :: field_view_t
    real(dp), pointer :: v(:, :, :) => null()
  end type field_view_t

contains

  ! Every sphere visited once per component, in order (q, then c = 1..4), into a fresh list;
  ! rigid (6, 6, n) gains each sphere's M_p from this block. positions (3, n), radii (n): each
  ! sphere's inflated radius (a_q + radius_offset h, §3.3; a mixture's spheres have their own
  ! a_q). gamma_unit: kappa beta h^2 / eta.
  ! The rivals of q are rival_part(rival_start(q) : rival_start(q+1)-1), their centres minus
  ! q's (minimum image) in rival_offset.
  subroutine faces_build(block, positions, radii, gamma_unit, rival_start, rival_part, rival_offset, faces, rigid)
    type(mac_block_t), intent(in) :: block
    real(dp), intent(in) :: positions(:, :), radii(:), gamma_unit
    integer, intent(in) :: rival_start(:), rival_part(:)
    real(dp), intent(in) :: rival_offset(:, :)
    type(face_list_t), intent(inout) :: faces
    real(dp), intent(inout) :: rigid(:, :, :)
    integer :: n, q, c, f0, m0, m1, box_lo(3), box_hi(3)
    n = size(positions, 2)
    if (.not. allocated(faces%ijk)) call faces_reserve(faces, 1024)
    faces%nf = 0
    faces%nruns = 0
    faces%block = block
    faces%centre = positions
    if (allocated(faces%run_start)) then
      if (size(faces%run_start) < 4 * n + 1) deallocate(faces%run_start, faces%run_comp, faces%run_part, &
                                                         faces%run_lo, faces%run_hi)
    end if
    if (.not. allocated(faces%run_start)) then
      allocate(faces%run_start(max(1, 4 * n + 1)), faces%run_comp(4 * n), faces%run_part(4 * n), &
               faces%run_lo(3, 4 * n), faces%run_hi(3, 4 * n))
    end if
    do q = 1, n
      m0 = rival_start(q)
      m1 = rival_start(q + 1) - 1
      do c = 1, 4
        f0 = faces%nf + 1
        call sphere_visit(block, c, q, positions, radii, gamma_unit, rival_part(m0:m1), rival_offset(:, m0:m1), &
                          faces, rigid(:, :, q), box_lo, box_hi)
        if (faces%nf >= f0) then
          faces%nruns = faces%nruns + 1
          faces%run_start(faces%nruns) = f0
          faces%run_comp(faces%nruns) = c
          faces%run_part(faces%nruns) = q
          faces%run_lo(:, faces%nruns) = box_lo
          faces%run_hi(:, faces%nruns) = box_hi
        end if
      end do
    end do
    faces%run_start(faces%nruns + 1) = faces%nf + 1
  end subroutine faces_build

  ! The offsets r (3, f1 - f0 + 1) from the centre of the faces of run (f0..f1, component c, sphere
  ! q; face_run), as sphere_visit formed them: (k + stagger) h - centre with k the unwrapped index,
  ! the one in the run's box whose wrap is the stored index (within the reach of the sphere,
  ! should a box be wider than a periodic length: the other candidate lies a period away, beyond it).
  pure subroutine run_offsets(faces, run, r)
    type(face_list_t), intent(in) :: faces
    integer, intent(in) :: run
    real(dp), intent(out) :: r(:, :)
    integer :: f0, f1, c, q, d, f, k, lo, hi, n
    real(dp) :: h, x, other
    logical :: periodic
    call face_run(faces, run, f0, f1, c, q)
    h = faces%block%h
    do d = 1, 3
      lo = faces%run_lo(d, run)
      hi = faces%run_hi(d, run)
      n = faces%block%n(d)
      periodic = .not. (d == 2 .and. (faces%block%walls .or. faces%block%sliding))
      do f = f0, f1
        k = faces%ijk(d, f)
        if (periodic) then
          if (k < lo) then
            k = k + n
          else if (k > hi) then
            k = k - n
          end if
        end if
        x = (k + STAGGER(d, c)) * h - faces%centre(d, q)
        if (periodic .and. hi - lo + 1 > n) then
          ! a box wider than the period: the wrap has two unwrapped indices in it
          if (k + n <= hi) then
            other = (k + n + STAGGER(d, c)) * h - faces%centre(d, q)
            if (abs(other) < abs(x)) x = other
          end if
          if (k - n >= lo) then
            other = (k - n + STAGGER(d, c)) * h - faces%centre(d, q)
            if (abs(other) < abs(x)) x = other
          end if
        end if
        r(d, f - f0 + 1) = x
      end do
    end do
  end subroutine run_offsets

  ! The offset r of listed face f (run_offsets of its run; for tests and diagnostics).
  function face_offset(faces, f) result(r)
    type(face_list_t), intent(in) :: faces
    integer, intent(in) :: f
    real(dp) :: r(3)
    real(dp), allocatable :: rr(:, :)
    integer :: run
    do run = 1, faces%nruns
      if (f < faces%run_start(run + 1)) exit
    end do
    allocate(rr(3, faces%run_start(run + 1) - faces%run_start(run)))
    call run_offsets(faces, run, rr)
    r = rr(:, f - faces%run_start(run) + 1)
  end function face_offset

  ! The longest run of the list (the size of the work arrays of the passes).
  pure integer function longest_run(faces)
    type(face_list_t), intent(in) :: faces
    integer :: run
    longest_run = 1
    do run = 1, faces%nruns
      longest_run = max(longest_run, faces%run_start(run + 1) - faces%run_start(run))
    end do
  end function longest_run

  ! The faces f0..f1 of run, their component c and their sphere q.
  pure subroutine face_run(faces, run, f0, f1, c, q)
    type(face_list_t), intent(in) :: faces
    integer, intent(in) :: run
    integer, intent(out) :: f0, f1, c, q
    f0 = faces%run_start(run)
    f1 = faces%run_start(run + 1) - 1
    c = faces%run_comp(run)
    q = faces%run_part(run)
  end subroutine face_run

  ! Indices per axis a sphere's box can hold: at most 2R/h + 2 (sphere_box), one to spare for round-off.
  pure integer function box_width(radius, h)
    real(dp), intent(in) :: radius, h
    box_width = ceiling(2.0_dp * radius / h) + 3
  end function box_width

  ! The index range [lo, hi] per axis of the unknowns of component c whose control volume can meet
  ! the sphere (centre, radius): that of unknown i spans (i + stagger +- 1/2) h, so only
  ! |(i + stagger) h - x_d| < R + h/2 can; the box is that range, no wider (doc/BENCHMARKS.md §8:
  ! the loops are most of the geometry's cost). Index lo(d) + m - 1 wraps to wrapped(m, d)
  ! (periodic axes; across the walls in y it stays as it is), and mine(m, d) says whether the
  ! block owns it: outside the walls there is no fluid, and on the wall itself v = 0 stays (no
  ! constraint). wrapped, mine: (box_width(radius, h), 3) or more rows.
  pure subroutine sphere_box(block, c, centre, radius, lo, hi, wrapped, mine)
    type(mac_block_t), intent(in) :: block
    integer, intent(in) :: c
    real(dp), intent(in) :: centre(3), radius
    integer, intent(out) :: lo(3), hi(3), wrapped(:, :)
    logical, intent(out) :: mine(:, :)
    integer :: d, m, i
    do d = 1, 3
      lo(d) = floor((centre(d) - radius) / block%h - STAGGER(d, c) - 0.5_dp)
      hi(d) = min(ceiling((centre(d) + radius) / block%h - STAGGER(d, c) + 0.5_dp), lo(d) + size(mine, 1) - 1)
      do m = 1, hi(d) - lo(d) + 1
        i = lo(d) + m - 1
        if (d == 2 .and. block%sliding) then
          wrapped(m, d) = i
          mine(m, d) = i >= 0 .and. i < block%n(2)
        else if (d == 2 .and. block%walls) then
          wrapped(m, d) = i
          mine(m, d) = i >= 0 .and. i < block%n(2) .and. .not. (c == 2 .and. i == 0)
        else
          wrapped(m, d) = modulo(i, block%n(d))
          mine(m, d) = .true.
        end if
        mine(m, d) = mine(m, d) .and. wrapped(m, d) >= block%lo(d) .and. wrapped(m, d) <= block%hi(d)
      end do
    end do
  end subroutine sphere_box

  ! Sphere q's visit of the unknowns of component c in the block: the ones it owns appended to
  ! faces, and w g g^T dV of them added to rigid (its M_p; c = 4 adds nothing). An unknown no
  ! rival reaches is q's outright. Where rivals reach, q computes their alphas there itself, with
  ! the very arithmetic each rival's own visit uses (the same unwrapped index, the same
  ! expressions), so every sphere takes the same decision: the largest alpha owns the unknown
  ! (ties to the lower index) with weight alpha - the runner-up's (doc/METHOD.md §3.4). No
  ! grid-sized ownership arrays, no second pass. rival_part, rival_offset (3, :): q's rivals and
  ! their centres minus q's (minimum image); positions (3, :), radii (:): every centre and every
  ! inflated radius (a rival of another size reaches as far as its own radius takes it).
  ! box_lo, box_hi, optional: the box visited (sphere_box), for run_offsets.
  subroutine sphere_visit(block, c, q, positions, radii, gamma_unit, rival_part, rival_offset, faces, rigid, &
                          box_lo, box_hi)
    type(mac_block_t), intent(in) :: block
    integer, intent(in) :: c, q
    real(dp), intent(in) :: positions(:, :), radii(:), gamma_unit
    integer, intent(in) :: rival_part(:)
    real(dp), intent(in) :: rival_offset(:, :)
    type(face_list_t), intent(inout) :: faces
    real(dp), intent(inout) :: rigid(6, 6)
    integer, intent(out), optional :: box_lo(3), box_hi(3)
    integer :: wrapped(box_width(radii(q), block%h), 3)
    logical :: mine(box_width(radii(q), block%h), 3)
    integer :: lo(3), hi(3), i, j, k, m, ilo, ihi, iw, jw, kw, f, nrow, idx(3), arm(2)
    real(dp) :: centre(3), r(3), a, h, radius, reach2, inside2, rest2, chord, gamma, rival2, second, rival_alpha
    real(dp) :: w, dv, sgn(2), block3(3, 3), sums6(6), v2, v3
    logical :: owned
    ! the rivals that reach the current row, and what is left of the reach there
    integer :: row_rival(max(1, size(rival_part)))
    real(dp) :: row_rest2(max(1, size(rival_part)))
    ! each rival's reach and inside (as q's own below, with its radius)
    real(dp) :: rival_reach2(max(1, size(rival_part))), rival_inside2(max(1, size(rival_part)))
    h = block%h
    dv = h**3
    radius = radii(q)
    centre = positions(:, q)
    call sphere_box(block, c, centre, radius, lo, hi, wrapped, mine)
    if (present(box_lo)) box_lo = lo
    if (present(box_hi)) box_hi = hi
    call reach_of(radius, reach2, inside2)
    do m = 1, size(rival_part)
      call reach_of(radii(rival_part(m)), rival_reach2(m), rival_inside2(m))
    end do
    ! room for every unknown of the box, once, so that the loop below stores without checks
    call faces_reserve(faces, faces%nf + product(hi - lo + 1))
    ! gamma = kappa (1 - alpha) beta h^2 / eta (relaxation_gamma, doc/METHOD.md §3.3), written out;
    ! the cell centres carry no constraint
    gamma = 0.0_dp
    sums6 = 0.0_dp
    if (c /= 4) then
      gamma = gamma_unit
      call torque_arm(c, idx, arm, sgn)
    end if
    do k = lo(3), hi(3)
      if (.not. mine(k - lo(3) + 1, 3)) cycle
      kw = wrapped(k - lo(3) + 1, 3)
      r(3) = (k + STAGGER(3, c)) * h - centre(3)
      do j = lo(2), hi(2)
        if (.not. mine(j - lo(2) + 1, 2)) cycle
        jw = wrapped(j - lo(2) + 1, 2)
        r(2) = (j + STAGGER(2, c)) * h - centre(2)
        rest2 = reach2 - r(2)**2 - r(3)**2
        if (rest2 <= 0.0_dp) cycle
        ! the row's chord, widened by a cell for round-off; the test below decides
        chord = sqrt(rest2)
        ilo = max(lo(1), floor((centre(1) - chord) / h - STAGGER(1, c)) - 1)
        ihi = min(hi(1), ceiling((centre(1) + chord) / h - STAGGER(1, c)) + 1)
        ! the rivals whose reach meets this row at all: only they can contest its unknowns (a
        ! margin of 1e-12 keeps the test on the safe side of round-off: contested if in doubt)
        nrow = 0
        do m = 1, size(rival_part)
          rival2 = (r(2) - rival_offset(2, m))**2 + (r(3) - rival_offset(3, m))**2
          if (rival2 >= rival_reach2(m) * (1.0_dp + 1.0e-12_dp)) cycle
          nrow = nrow + 1
          row_rival(nrow) = m
          row_rest2(nrow) = rival_reach2(m) * (1.0_dp + 1.0e-12_dp) - rival2
        end do
        do i = ilo, ihi
          if (.not. mine(i - lo(1) + 1, 1)) cycle
          r(1) = (i + STAGGER(1, c)) * h - centre(1)
          a = alpha_at(r, radius, reach2, inside2)
          if (a <= 0.0_dp) cycle
          iw = wrapped(i - lo(1) + 1, 1)
          ! the rivals that reach this unknown: the largest alpha owns it, the runner-up's is taken off
          second = 0.0_dp
          owned = .true.
          do m = 1, nrow
            if ((r(1) - rival_offset(1, row_rival(m)))**2 >= row_rest2(m)) cycle
            rival_alpha = alpha_of_rival(row_rival(m), [iw, jw, kw])
            if (rival_alpha > a .or. (rival_alpha == a .and. rival_part(row_rival(m)) < q)) then
              owned = .false.
              exit
            end if
            second = max(second, rival_alpha)
          end do
          if (.not. owned) cycle
          a = a - second
          if (a <= 0.0_dp) cycle
          f = faces%nf + 1
          faces%nf = f
          faces%ijk(:, f) = [iw, jw, kw]
          faces%alpha(f) = a
          if (a == 1.0_dp) then
            faces%relax(f) = 1.0_dp       ! a covered face does not relax (gamma = 0)
          else
            faces%relax(f) = 1.0_dp / (1.0_dp + gamma * (1.0_dp - a))
          end if
          if (c == 4) cycle
          ! w g g^T on the non-zeros (1, v2, v3) of g: six distinct sums
          v2 = sgn(1) * r(arm(1))
          v3 = sgn(2) * r(arm(2))
          w = faces%alpha(f) * faces%relax(f) * dv
          sums6 = sums6 + [w, w * v2, w * v3, w * v2 * v2, w * v2 * v3, w * v3 * v3]
        end do
      end do
    end do
    ! M_p gains w g g^T on the three non-zeros of g
    if (c /= 4) then
      block3 = reshape([sums6(1), sums6(2), sums6(3), sums6(2), sums6(4), sums6(5), sums6(3), sums6(5), sums6(6)], &
                       [3, 3])
      rigid(idx, idx) = rigid(idx, idx) + block3
    end if
  contains
    ! Beyond reach2_of from a centre a control volume lies wholly outside the sphere of radius rad
    ! (its half-diagonal); within inside2_of wholly inside (alpha = 1; -1 when none is).
    pure subroutine reach_of(rad, reach2_of, inside2_of)
      real(dp), intent(in) :: rad
      real(dp), intent(out) :: reach2_of, inside2_of
      reach2_of = (rad + 0.5_dp * sqrt(3.0_dp) * h)**2
      inside2_of = -1.0_dp
      if (rad > 0.5_dp * sqrt(3.0_dp) * h) inside2_of = (rad - 0.5_dp * sqrt(3.0_dp) * h)**2
    end subroutine reach_of

    ! The cover of the control volume at offset x from the centre of a sphere of radius rad (0
    ! beyond its reach).
    real(dp) function alpha_at(x, rad, reach2_of, inside2_of)
      real(dp), intent(in) :: x(3), rad, reach2_of, inside2_of
      real(dp) :: d2
      d2 = x(1)**2 + x(2)**2 + x(3)**2
      if (d2 >= reach2_of) then
        alpha_at = 0.0_dp
      else if (d2 <= inside2_of) then
        alpha_at = 1.0_dp      ! the whole control volume is inside (cube_fraction's first test)
      else
        alpha_at = cube_fraction(x, rad, h)
      end if
    end function alpha_at

    ! Rival m's alpha of the unknown with wrapped index ijk, computed as its own visit does: from
    ! the image of the unknown nearest to its centre (the one its box holds), with its radius.
    real(dp) function alpha_of_rival(m, ijk)
      integer, intent(in) :: m, ijk(3)
      integer :: d, unwrapped, p
      real(dp) :: x(3)
      p = rival_part(m)
      do d = 1, 3
        unwrapped = ijk(d)
        if (.not. (d == 2 .and. (block%walls .or. block%sliding))) unwrapped = ijk(d) + block%n(d) * &
             nint((positions(d, p) - (ijk(d) + STAGGER(d, c)) * h) / block%box(d))
        x(d) = (unwrapped + STAGGER(d, c)) * h - positions(d, p)
      end do
      alpha_of_rival = alpha_at(x, radii(p), rival_reach2(m), rival_inside2(m))
    end function alpha_of_rival
  end subroutine sphere_visit

  ! Room for n faces in the list (its arrays grow by doubling, kept between steps).
  subroutine faces_reserve(faces, n)
    type(face_list_t), intent(inout) :: faces
    integer, intent(in) :: n
    integer :: m
    integer, allocatable :: t3(:, :)
    real(dp), allocatable :: tr(:)
    if (.not. allocated(faces%ijk)) then
      allocate(faces%ijk(3, n), faces%alpha(n), faces%relax(n))
      return
    end if
    if (n <= size(faces%alpha)) return
    m = max(n, 2 * size(faces%alpha))
    allocate(t3(3, m)); t3(:, 1:faces%nf) = faces%ijk(:, 1:faces%nf); call move_alloc(t3, faces%ijk)
    allocate(tr(m)); tr(1:faces%nf) = faces%alpha(1:faces%nf); call move_alloc(tr, faces%alpha)
    allocate(tr(m)); tr(1:faces%nf) = faces%relax(1:faces%nf); call move_alloc(tr, faces%relax)
  end subroutine faces_reserve

  ! g = (e_c, r x e_c) enters through its three non-zeros: 1 at idx(1), sgn(1) r(k(1)) at idx(2)
  ! and sgn(2) r(k(2)) at idx(3) (once per run).
  pure subroutine torque_arm(c, idx, k, sgn)
    integer, intent(in) :: c
    integer, intent(out) :: idx(3), k(2)
    real(dp), intent(out) :: sgn(2)
    select case (c)
    case (1)
      idx = [1, 5, 6]; k = [3, 2]; sgn = [1.0_dp, -1.0_dp]
    case (2)
      idx = [2, 4, 6]; k = [3, 1]; sgn = [-1.0_dp, 1.0_dp]
    case default
      idx = [3, 4, 5]; k = [2, 1]; sgn = [1.0_dp, -1.0_dp]
    end select
  end subroutine torque_arm

  ! The carry of a sphere displaced by dX (doc/METHOD.md §3.6): x_f - dX in cells from the face
  ! itself, t = -dX/h, lies between the offsets o = floor(t) and o + 1 (in {-1, 0, 1} while
  ! |dX| < h); corner m = 1..8 is o + (a, b, e), a fastest, with the trilinear weight of t - o.
  pure subroutine carry_corners(displacement, h, corner, weight)
    real(dp), intent(in) :: displacement(3), h
    integer, intent(out) :: corner(3, 8)
    real(dp), intent(out) :: weight(8)
    real(dp) :: t(3), w(3)
    integer :: o(3), a, b, e, m
    t = -displacement / h
    o = floor(t)
    w = t - o
    m = 0
    do e = 0, 1
      do b = 0, 1
        do a = 0, 1
          m = m + 1
          corner(:, m) = o + [a, b, e]
          weight(m) = merge(w(1), 1.0_dp - w(1), a == 1) * merge(w(2), 1.0_dp - w(2), b == 1) &
                    * merge(w(3), 1.0_dp - w(3), e == 1)
        end do
      end do
    end do
  end subroutine carry_corners

  ! Lambda carried by the displacement: trilinear from the eight corners of x_f - dX (carry_corners).
  ! old: Lambda^n with ghosts (glo:ghi, including edge and corner ghosts); new: the block's.
  ! walls: the y index of a wall grid runs over 0 .. ny-1 and nothing lies beyond.
  pure subroutine carry_run(old, new, glo, ghi, lo, hi, nfaces, ijk, corner, weight, moved, walls, ny)
    integer, intent(in) :: glo(3), ghi(3), lo(3), hi(3), nfaces, ijk(3, nfaces), corner(3, 8), ny
    real(dp), intent(in) :: old(glo(1):ghi(1), glo(2):ghi(2), glo(3):ghi(3)), weight(8)
    real(dp), intent(inout) :: new(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3))
    logical, intent(in) :: moved, walls
    integer :: f, m, i, j, k, jj, i0, j0, k0
    real(dp) :: value
    if (.not. moved) then
      do f = 1, nfaces
        new(ijk(1, f), ijk(2, f), ijk(3, f)) = old(ijk(1, f), ijk(2, f), ijk(3, f))
      end do
      return
    end if
    i0 = corner(1, 1); j0 = corner(2, 1); k0 = corner(3, 1)
    do f = 1, nfaces
      i = ijk(1, f) + i0; j = ijk(2, f) + j0; k = ijk(3, f) + k0
      if (walls .and. (j < 0 .or. j + 1 >= ny)) then
        ! beyond a wall there is no fluid and no Lambda (the periodic ghost would wrap)
        value = 0.0_dp
        do m = 1, 8
          jj = ijk(2, f) + corner(2, m)
          if (jj < 0 .or. jj >= ny) cycle
          value = value + weight(m) * old(ijk(1, f) + corner(1, m), jj, ijk(3, f) + corner(3, m))
        end do
      else
        value = ((((((weight(1) * old(i, j, k) + weight(2) * old(i + 1, j, k)) + weight(3) * old(i, j + 1, k)) &
                + weight(4) * old(i + 1, j + 1, k)) + weight(5) * old(i, j, k + 1)) + weight(6) * old(i + 1, j, k + 1)) &
                + weight(7) * old(i, j + 1, k + 1)) + weight(8) * old(i + 1, j + 1, k + 1)
      end if
      new(ijk(1, f), ijk(2, f), ijk(3, f)) = value
    end do
  end subroutine carry_run

  ! moments(1:6) += sum w u~_c g dV, moments(7:12) += sum Lambda^n/(1+gamma) g dV (§3.2).
  pure subroutine moments_run(c, u, lam, lo, hi, nfaces, ijk, r, alpha, relax, dv, moments)
    integer, intent(in) :: c, lo(3), hi(3), nfaces, ijk(3, nfaces)
    real(dp), intent(in) :: u(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)), lam(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3))
    real(dp), intent(in) :: r(3, nfaces), alpha(nfaces), relax(nfaces), dv
    real(dp), intent(inout) :: moments(12)
    integer :: f, idx(3), k(2)
    real(dp) :: val(3), b(3), m(3), su, sl, sgn(2)
    call torque_arm(c, idx, k, sgn)
    b = 0.0_dp
    m = 0.0_dp
    do f = 1, nfaces
      val = [1.0_dp, sgn(1) * r(k(1), f), sgn(2) * r(k(2), f)]
      su = alpha(f) * relax(f) * u(ijk(1, f), ijk(2, f), ijk(3, f)) * dv
      sl = lam(ijk(1, f), ijk(2, f), ijk(3, f)) * relax(f) * dv
      b = b + su * val
      m = m + sl * val
    end do
    moments(idx) = moments(idx) + b
    moments(6 + idx) = moments(6 + idx) + m
  end subroutine moments_run

  ! Lambda^{n+1} = [Lambda^n + beta alpha (g.U - u~)]/(1 + gamma) of each face of the run (§3.5).
  pure subroutine new_lambda_run(c, u, lam, lo, hi, nfaces, ijk, r, alpha, relax, beta, velocity, omega, lambda_new)
    integer, intent(in) :: c, lo(3), hi(3), nfaces, ijk(3, nfaces)
    real(dp), intent(in) :: u(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)), lam(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3))
    real(dp), intent(in) :: r(3, nfaces), alpha(nfaces), relax(nfaces), beta, velocity(3), omega(3)
    real(dp), intent(out) :: lambda_new(nfaces)
    integer :: f, idx(3), k(2)
    real(dp) :: rigid, sgn(2)
    call torque_arm(c, idx, k, sgn)
    do f = 1, nfaces
      rigid = velocity(c) + sgn(1) * r(k(1), f) * omega(idx(2) - 3) + sgn(2) * r(k(2), f) * omega(idx(3) - 3)
      lambda_new(f) = (lam(ijk(1, f), ijk(2, f), ijk(3, f)) + beta * alpha(f) &
                       * (rigid - u(ijk(1, f), ijk(2, f), ijk(3, f)))) * relax(f)
    end do
  end subroutine new_lambda_run

  ! One run of the update: Lambda^{n+1} (from lambda_new when given, the grid then already free of
  ! Lambda^n), u^{n+1} = u~ - Lambda^n/beta + Lambda^{n+1}/beta, and the run's force, torque and
  ! stresslet added to sums(1:15) (the 3x3 block stored by columns in 7:15; §3.5, §3.7).
  pure subroutine update_run(c, u, lam, lo, hi, nfaces, ijk, r, alpha, relax, beta, dv, velocity, omega, sums, lambda_new)
    integer, intent(in) :: c, lo(3), hi(3), nfaces, ijk(3, nfaces)
    real(dp), intent(inout) :: u(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)), lam(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3))
    real(dp), intent(in) :: r(3, nfaces), alpha(nfaces), relax(nfaces), beta, dv, velocity(3), omega(3)
    real(dp), intent(inout) :: sums(16)
    real(dp), intent(in), optional :: lambda_new(nfaces)
    integer :: f, i, j, k, idx(3), arm(2), d
    real(dp) :: val(3), rigid, b, force(3), first(3), bd, sgn(2)
    call torque_arm(c, idx, arm, sgn)
    force = 0.0_dp
    first = 0.0_dp
    do f = 1, nfaces
      i = ijk(1, f); j = ijk(2, f); k = ijk(3, f)
      val = [1.0_dp, sgn(1) * r(arm(1), f), sgn(2) * r(arm(2), f)]
      if (present(lambda_new)) then
        b = lambda_new(f)
        u(i, j, k) = u(i, j, k) + b / beta
      else
        rigid = velocity(c) + val(2) * omega(idx(2) - 3) + val(3) * omega(idx(3) - 3)
        b = (lam(i, j, k) + beta * alpha(f) * (rigid - u(i, j, k))) * relax(f)
        u(i, j, k) = (u(i, j, k) + (-1.0_dp / beta) * lam(i, j, k)) + b / beta
      end if
      lam(i, j, k) = b
      ! force -Lambda e_c dV and torque -r x (Lambda e_c) dV: -Lambda dV times g
      bd = b * dv
      force = force - bd * val
      ! -1/2 Lambda dV (r e_c + e_c r): column c and row c of the 3x3 block; r_d Lambda dV summed here
      first = first + bd * r(:, f)
    end do
    sums(idx) = sums(idx) + force
    do d = 1, 3
      sums(6 + d + 3 * (c - 1)) = sums(6 + d + 3 * (c - 1)) - 0.5_dp * first(d)
      sums(6 + c + 3 * (d - 1)) = sums(6 + c + 3 * (d - 1)) - 0.5_dp * first(d)
    end do
  end subroutine update_run

  ! The interior pressure sum_cells alpha p dV of one run of cell centres (doc/METHOD.md §3.7).
  pure subroutine pressure_run(p, lo, hi, nfaces, ijk, alpha, dv, integral)
    integer, intent(in) :: lo(3), hi(3), nfaces, ijk(3, nfaces)
    real(dp), intent(in) :: p(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)), alpha(nfaces), dv
    real(dp), intent(inout) :: integral
    integer :: f
    real(dp) :: total
    total = 0.0_dp
    do f = 1, nfaces
      total = total + alpha(f) * p(ijk(1, f), ijk(2, f), ijk(3, f))
    end do
    integral = integral + total * dv
  end subroutine pressure_run

  ! The passes over the whole list, run by run. Each takes the three velocity components (and
  ! Lambda) as field views on the block's bounds lo:hi.

  ! Lambda carried onto the listed faces (doc/METHOD.md §3.6): new(c) on the faces of c from
  ! old(c) (ghosted bounds glo:ghi), sphere q displaced by displacement(:, q) (below one cell per
  ! component); ny: the cells across, for the walls.
  subroutine faces_carry(faces, old, new, glo, ghi, lo, hi, displacement, h, walls, ny)
    type(face_list_t), intent(in) :: faces
    type(field_view_t), intent(in) :: old(3)
    type(field_view_t), intent(inout) :: new(3)
    integer, intent(in) :: glo(3), ghi(3), lo(3), hi(3), ny
    real(dp), intent(in) :: displacement(:, :), h
    logical, intent(in) :: walls
    integer :: run, f0, f1, c, q, corner(3, 8)
    real(dp) :: weight(8)
    do run = 1, faces%nruns
      call face_run(faces, run, f0, f1, c, q)
      if (c == 4) cycle
      call carry_corners(displacement(:, q), h, corner, weight)
      call carry_run(old(c)%v, new(c)%v, glo, ghi, lo, hi, f1 - f0 + 1, faces%ijk(:, f0:f1), corner, weight, &
                     any(displacement(:, q) /= 0.0_dp), walls, ny)
    end do
  end subroutine faces_carry

  ! b and m of every sphere (moments (12, n), added to; §3.2), dv the cell volume.
  subroutine faces_moments(faces, u, lam, lo, hi, dv, moments)
    type(face_list_t), intent(in) :: faces
    type(field_view_t), intent(in) :: u(3), lam(3)
    integer, intent(in) :: lo(3), hi(3)
    real(dp), intent(in) :: dv
    real(dp), intent(inout) :: moments(:, :)
    integer :: run, f0, f1, c, q
    real(dp), allocatable :: r(:, :)
    allocate(r(3, longest_run(faces)))
    do run = 1, faces%nruns
      call face_run(faces, run, f0, f1, c, q)
      if (c == 4) cycle
      call run_offsets(faces, run, r)
      call moments_run(c, u(c)%v, lam(c)%v, lo, hi, f1 - f0 + 1, faces%ijk(:, f0:f1), r, &
                       faces%alpha(f0:f1), faces%relax(f0:f1), dv, moments(:, q))
    end do
  end subroutine faces_moments

  ! Lambda^{n+1} of every listed face into lambda_new (its size at least faces%nf; §3.5), the
  ! spheres moving with velocity, omega (3, n).
  subroutine faces_new_lambda(faces, u, lam, lo, hi, beta, velocity, omega, lambda_new)
    type(face_list_t), intent(in) :: faces
    type(field_view_t), intent(in) :: u(3), lam(3)
    integer, intent(in) :: lo(3), hi(3)
    real(dp), intent(in) :: beta, velocity(:, :), omega(:, :)
    real(dp), intent(inout) :: lambda_new(:)
    integer :: run, f0, f1, c, q
    real(dp), allocatable :: r(:, :)
    allocate(r(3, longest_run(faces)))
    do run = 1, faces%nruns
      call face_run(faces, run, f0, f1, c, q)
      if (c == 4) cycle
      call run_offsets(faces, run, r)
      call new_lambda_run(c, u(c)%v, lam(c)%v, lo, hi, f1 - f0 + 1, faces%ijk(:, f0:f1), r, &
                          faces%alpha(f0:f1), faces%relax(f0:f1), beta, velocity(:, q), omega(:, q), lambda_new(f0:f1))
    end do
  end subroutine faces_new_lambda

  ! The update of every run (update_run; the cell runs add the interior pressure of p to
  ! sums(16, q), §3.7): sums (16, n) added to. lambda_new, optional: Lambda^{n+1} already computed
  ! (faces_new_lambda), the grid then free of Lambda^n.
  subroutine faces_update(faces, u, lam, p, lo, hi, beta, dv, velocity, omega, sums, lambda_new)
    type(face_list_t), intent(in) :: faces
    type(field_view_t), intent(inout) :: u(3), lam(3)
    type(field_view_t), intent(in) :: p
    integer, intent(in) :: lo(3), hi(3)
    real(dp), intent(in) :: beta, dv, velocity(:, :), omega(:, :)
    real(dp), intent(inout) :: sums(:, :)
    real(dp), intent(in), optional :: lambda_new(:)
    integer :: run, f0, f1, c, q
    real(dp), allocatable :: r(:, :)
    allocate(r(3, longest_run(faces)))
    do run = 1, faces%nruns
      call face_run(faces, run, f0, f1, c, q)
      if (c /= 4) call run_offsets(faces, run, r)
      if (c == 4) then
        call pressure_run(p%v, lo, hi, f1 - f0 + 1, faces%ijk(:, f0:f1), faces%alpha(f0:f1), dv, sums(16, q))
      else if (present(lambda_new)) then
        call update_run(c, u(c)%v, lam(c)%v, lo, hi, f1 - f0 + 1, faces%ijk(:, f0:f1), r, &
                        faces%alpha(f0:f1), faces%relax(f0:f1), beta, dv, velocity(:, q), omega(:, q), sums(:, q), &
                        lambda_new(f0:f1))
      else
        call update_run(c, u(c)%v, lam(c)%v, lo, hi, f1 - f0 + 1, faces%ijk(:, f0:f1), r, &
                        faces%alpha(f0:f1), faces%relax(f0:f1), beta, dv, velocity(:, q), omega(:, q), sums(:, q))
      end if
    end do
  end subroutine faces_update

end module mod_sphere_faces
