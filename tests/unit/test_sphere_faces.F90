! Unit test of mod_sphere_faces: the unknowns of the MAC grid a sphere covers and the per-run
! arithmetic of the fictitious domain (doc/METHOD.md §3). Invariants, each against something the
! visit does not compute itself:
!   1. completeness: for a lone sphere, the alphas the visit lists, summed, equal a brute-force sum
!      of cube_fraction over every unknown of the grid at its nearest image (so the box the visit
!      scans misses no covered unknown); relative 1e-12: the two compute r by differently
!      rounded expressions (unwrapped index against nearest image), and alpha moves by at most
!      ~4 |dr|/h per unknown (test_solid_fraction's continuity), i.e. ~1e-14 here;
!   2. volume: sum alpha h^3 of each component = V = 4/3 pi R^3, and M_p (no relaxation) has V
!      on its translational diagonal and on its rotational one the second moment 8/15 pi R^5 as
!      the sum gives it: sum (r_y^2 + r_z^2) alpha h^3 counts each point y of the sphere with the
!      r^2 of the unknown whose control volume holds y, on average over the sphere's place on the
!      grid h^2/12 more per direction, so 8/15 pi R^5 + V h^2/6 (the correction is 1.7 % at
!      h = R/5, and the error measured against 8/15 pi R^5 alone is 1.8e-2). The planar ramp of
!      cube_fraction errs by ~(h/4)^2/R^2 relative (test_solid_fraction): 2.5e-3 at h = R/5, so
!      both tolerances are 3e-3; halving h must cut the volume error by more than 3 (second order);
!   3. weights: 0 < alpha <= 1 and 0 < 1/(1+gamma) <= 1 on every listed unknown, exactly 1 where
!      alpha = 1 (a covered face does not relax, §3.3); M_p symmetric with a positive diagonal;
!   4. periodic images: a sphere moved by a whole period in every direction lists the same
!      unknowns in the same order with alphas equal to 1e-12 (round-off of the offsets, as in 1);
!      a sphere straddling the periodic boundaries (centre 0.3 h from a corner of the box)
!      covers as many unknowns, with the same cover to 1e-12, as the same sphere moved by whole
!      cells into the interior; its wrapped indices all lie in the grid;
!   5. decomposition: the lists of a grid split into 8 blocks (2 x 2 x 2 ranks) are together the
!      one-block list, the same unknowns with bitwise the same alpha and relaxation (each is the
!      same arithmetic), and M_p summed over the blocks equals the one-block M_p to 1e-13
!      relative (only the order of the sums differs);
!   6. close pairs (§3.4): two spheres 0.1 h apart (inflated spheres overlapping) list disjoint
!      unknowns; where both reach, the owner is the sphere with the larger cube_fraction
!      (computed here directly) and its weight is the excess over the other's, to 1e-15 (no
!      periodic image in this scene: the same offsets, so the same alphas bit for bit); with
!      the pair mirror-symmetric about a grid plane both spheres own the same total weight per
!      component to 1e-12 (ties on the plane go to neither: weight 0);
!   7. walls: with walls in y no unknown lies outside 0 <= j < n_y, and no v on the wall j = 0;
!   8. moments: with u~ the rigid motion U + Omega x r on every face and no Lambda,
!      b = M_p (U, Omega) (faces_moments against the visit's M_p, two separate sums) to 1e-12
!      relative, and Lambda^{n+1} = 0 (faces_new_lambda) to 1e-12 of beta |U| (round-off of g.U
!      against Omega x r);
!   9. update: the two paths of the update (Lambda^n removed first and Lambda^{n+1} given, or
!      both in one pass) give bitwise the same u, Lambda and sums (the same operations in the
!      same order, which doc/DESIGN.md "Face runs" relies on); the force is -sum Lambda dV and
!      the interior pressure of a uniform p0 is p0 sum alpha dV, both to 1e-12 relative (sums of ~10^3
!      terms in another order: at most N eps = 2e-13 of the sum of magnitudes);
!  The pair scenes (5, 6) sit in a box of 6 R: a pair meets through one periodic image only while
!  the box exceeds four reaches (R + sqrt(3) h/2 each), and the rivals of mod_fictitious_domain
!  hold the minimum image alone.
!  10. carry (§3.6): the trilinear weights sum to 1 (to 1e-15), a field linear in the index is
!      carried exactly (to 1e-12 of its size), and no displacement copies bitwise.
program test_sphere_faces
  use mod_kinds, only: dp, pi
  use mod_solid_fraction, only: cube_fraction
  use mod_sphere_faces, only: STAGGER, mac_block_t, face_list_t, field_view_t, faces_build, face_run, &
                              faces_moments, faces_new_lambda, faces_update, torque_arm, carry_corners, carry_run, face_offset
  use mod_vector, only: cross
  use mod_unit_checks, only: check, check_below, finish
  implicit none
  real(dp), parameter :: radius = 1.0_dp
  real(dp) :: vol_err(2), mom_err(2)
  integer :: level

  do level = 1, 2
    call lone_sphere(5 * level, vol_err(level), mom_err(level))
  end do
  write(*, '(a,2es10.2,a,2es10.2)') '# volume error at h = R/5, R/10:', vol_err, '; rotational M_p error:', mom_err
  call check_below('volume sum alpha h^3 / (4/3 pi R^3) - 1 at h = R/5', vol_err(1), 3.0e-3_dp)
  call check_below('rotational M_p / (8/15 pi R^5 + V h^2/6) - 1 at h = R/5', mom_err(1), 3.0e-3_dp)
  call check(vol_err(1) / max(vol_err(2), 1.0e-300_dp) > 3.0_dp, 'the volume error falls as h^2')
  call periodic_images()
  call decomposition()
  call close_pair()
  call unequal_pair()
  call walls()
  call run_kernels()
  call carry()
  call finish('test_sphere_faces')

contains

  ! A periodic cube of n cells of side h = R/cells_per_radius per axis, one block.
  type(mac_block_t) function periodic_block(cells_per_radius, n) result(block)
    integer, intent(in) :: cells_per_radius, n
    block%h = radius / cells_per_radius
    block%n = n
    block%box = n * block%h
    block%walls = .false.
    block%lo = 0
    block%hi = n - 1
  end function periodic_block

  ! The faces of spheres at positions (3, :) without rivals (every sphere alone) or, with
  ! rivals, each sphere the rival of every other (the minimum image of a periodic block).
  ! radii (optional): each sphere's radius (a mixture), else radius for all.
  subroutine build(block, positions, faces, rigid, gamma_unit, rivals, radii)
    type(mac_block_t), intent(in) :: block
    real(dp), intent(in) :: positions(:, :)
    type(face_list_t), intent(inout) :: faces
    real(dp), allocatable, intent(out) :: rigid(:, :, :)
    real(dp), intent(in) :: gamma_unit
    logical, intent(in) :: rivals
    real(dp), intent(in), optional :: radii(:)
    integer :: n, q, p, m
    integer, allocatable :: start(:), part(:)
    real(dp), allocatable :: offset(:, :), sphere_radii(:)
    n = size(positions, 2)
    sphere_radii = spread(radius, 1, n)
    if (present(radii)) sphere_radii = radii
    allocate(rigid(6, 6, n), start(n + 1), part(max(1, n * n)), offset(3, max(1, n * n)))
    rigid = 0.0_dp
    m = 0
    do q = 1, n
      start(q) = m + 1
      if (.not. rivals) cycle
      do p = 1, n
        if (p == q) cycle
        m = m + 1
        part(m) = p
        offset(:, m) = positions(:, p) - positions(:, q)
        if (.not. block%walls) offset(:, m) = offset(:, m) - block%box * nint(offset(:, m) / block%box)
      end do
    end do
    start(n + 1) = m + 1
    call faces_build(block, positions, sphere_radii, gamma_unit, start, part, offset, faces, rigid)
  end subroutine build

  ! Sum of alpha over the runs of component c (and sphere q, when given).
  real(dp) function alpha_sum(faces, c, q)
    type(face_list_t), intent(in) :: faces
    integer, intent(in) :: c
    integer, intent(in), optional :: q
    integer :: run, f0, f1, cc, qq
    alpha_sum = 0.0_dp
    do run = 1, faces%nruns
      call face_run(faces, run, f0, f1, cc, qq)
      if (cc /= c) cycle
      if (present(q)) then
        if (qq /= q) cycle
      end if
      alpha_sum = alpha_sum + sum(faces%alpha(f0:f1))
    end do
  end function alpha_sum

  ! 1, 2, 3 for one grid: returns the worst relative volume error and the rotational M_p error.
  subroutine lone_sphere(cells_per_radius, vol_err, mom_err)
    integer, intent(in) :: cells_per_radius
    real(dp), intent(out) :: vol_err, mom_err
    type(mac_block_t) :: block
    type(face_list_t) :: faces
    real(dp), allocatable :: rigid(:, :, :)
    real(dp) :: centre(3), brute, listed, x(3), worst, volume, inertia
    integer :: c, i, j, k, f, n
    character(len=120) :: what
    n = 4 * cells_per_radius        ! a box of 4 R: room for the reach R + sqrt(3) h/2
    block = periodic_block(cells_per_radius, n)
    centre = [0.5_dp * n + 0.37_dp, 0.5_dp * n + 0.11_dp, 0.5_dp * n - 0.23_dp] * block%h
    call build(block, reshape(centre, [3, 1]), faces, rigid, 0.0_dp, .false.)
    volume = 4.0_dp / 3.0_dp * pi * radius**3
    ! each point of the sphere counts with the r^2 of the unknown whose control volume holds it:
    ! h^2/12 more per direction, on average over the sphere's place on the grid
    inertia = 8.0_dp / 15.0_dp * pi * radius**5 + volume * block%h**2 / 6.0_dp
    vol_err = 0.0_dp
    worst = 0.0_dp
    do c = 1, 4
      ! 1. brute force over the whole grid, nearest image
      brute = 0.0_dp
      do k = 0, n - 1
        do j = 0, n - 1
          do i = 0, n - 1
            x = ([i, j, k] + STAGGER(:, c)) * block%h - centre
            x = x - block%box * nint(x / block%box)
            brute = brute + cube_fraction(x, radius, block%h)
          end do
        end do
      end do
      listed = alpha_sum(faces, c)
      worst = max(worst, abs(listed - brute) / brute)
      vol_err = max(vol_err, abs(listed * block%h**3 / volume - 1.0_dp))
    end do
    write(what, '(a,i0,a)') 'h = R/', cells_per_radius, ': the listed alphas are the brute-force sum over the grid'
    call check_below(trim(what), worst, 1.0e-12_dp)
    ! 3. weights
    call check(all(faces%alpha(1:faces%nf) > 0.0_dp .and. faces%alpha(1:faces%nf) <= 1.0_dp) .and. &
               all(faces%relax(1:faces%nf) == 1.0_dp), 'alpha in (0, 1]; no relaxation when gamma = 0')
    call check(all(faces%ijk(:, 1:faces%nf) >= 0 .and. faces%ijk(:, 1:faces%nf) < n), 'wrapped indices in the grid')
    ! 2. M_p
    do f = 1, 3
      vol_err = max(vol_err, abs(rigid(f, f, 1) / volume - 1.0_dp))
    end do
    mom_err = 0.0_dp
    do f = 4, 6
      mom_err = max(mom_err, abs(rigid(f, f, 1) / inertia - 1.0_dp))
    end do
    call check(all(abs(rigid(:, :, 1) - transpose(rigid(:, :, 1))) == 0.0_dp), 'M_p is symmetric')
    ! 3. with relaxation
    call build(block, reshape(centre, [3, 1]), faces, rigid, 3.0_dp, .false.)
    call check(all(faces%relax(1:faces%nf) > 0.0_dp .and. faces%relax(1:faces%nf) <= 1.0_dp) .and. &
               all(merge(faces%relax(1:faces%nf) == 1.0_dp, .true., faces%alpha(1:faces%nf) == 1.0_dp)) .and. &
               any(faces%relax(1:faces%nf) < 1.0_dp), &
               '1/(1+gamma) in (0, 1], 1 exactly on covered unknowns')
  end subroutine lone_sphere

  ! 4. whole periods, and a sphere straddling the periodic boundaries
  subroutine periodic_images()
    type(mac_block_t) :: block
    type(face_list_t) :: a, b
    real(dp), allocatable :: rigid(:, :, :)
    real(dp) :: centre(3), worst
    integer :: c
    logical :: same
    block = periodic_block(5, 20)
    centre = [1.3_dp, 2.05_dp, 0.71_dp]
    call build(block, reshape(centre, [3, 1]), a, rigid, 3.0_dp, .false.)
    call build(block, reshape(centre + block%box, [3, 1]), b, rigid, 3.0_dp, .false.)
    same = a%nf == b%nf .and. a%nruns == b%nruns
    if (same) same = all(a%ijk(:, 1:a%nf) == b%ijk(:, 1:b%nf))
    call check(same, 'a whole period in x, y and z: the same unknowns in the same order')
    worst = 1.0_dp
    if (same) worst = maxval(abs(a%alpha(1:a%nf) - b%alpha(1:a%nf)))
    call check_below('a whole period: largest alpha difference', worst, 1.0e-12_dp)
    ! centre 0.3 h from the corner (0, 0, 0): the box wraps in every direction
    centre = 0.3_dp * block%h
    call build(block, reshape(centre, [3, 1]), a, rigid, 0.0_dp, .false.)
    call build(block, reshape(centre + 10 * block%h, [3, 1]), b, rigid, 0.0_dp, .false.)
    call check(a%nf == b%nf, 'straddling the periodic boundaries: as many unknowns as in the interior')
    call check(all(a%ijk(:, 1:a%nf) >= 0 .and. a%ijk(:, 1:a%nf) < 20), 'straddling: wrapped indices in the grid')
    worst = 0.0_dp
    do c = 1, 4
      worst = max(worst, abs(alpha_sum(a, c) - alpha_sum(b, c)) / alpha_sum(b, c))
    end do
    call check_below('straddling: relative difference of the cover per component', worst, 1.0e-12_dp)
  end subroutine periodic_images

  ! 5. 2 x 2 x 2 blocks against one
  subroutine decomposition()
    type(mac_block_t) :: whole, part
    type(face_list_t) :: one, piece
    real(dp), allocatable :: rigid_one(:, :, :), rigid(:, :, :)
    real(dp) :: positions(3, 2), summed(6, 6, 2)
    integer :: bx, by, bz, f, g, found, matched
    integer, allocatable :: owner(:, :, :, :)   ! (0:n-1)^3 x component: index in the one-block list
    logical :: same, outside
    whole = periodic_block(5, 30)
    outside = .false.
    ! two close spheres (rivals contest unknowns), one near a block boundary and the box's edge
    positions(:, 1) = [1.93_dp, 2.11_dp, 0.57_dp]
    positions(:, 2) = [3.98_dp, 2.07_dp, 0.69_dp]
    call build(whole, positions, one, rigid_one, 3.0_dp, .true.)
    allocate(owner(0:29, 0:29, 0:29, 4))
    owner = 0
    do f = 1, one%nf
      owner(one%ijk(1, f), one%ijk(2, f), one%ijk(3, f), comp_of(one, f)) = f
    end do
    summed = 0.0_dp
    found = 0
    matched = 0
    do bz = 0, 1
      do by = 0, 1
        do bx = 0, 1
          part = whole
          part%lo = [bx, by, bz] * 15
          part%hi = part%lo + 14
          call build(part, positions, piece, rigid, 3.0_dp, .true.)
          summed = summed + rigid
          found = found + piece%nf
          if (any(piece%ijk(:, 1:piece%nf) < spread(part%lo, 2, piece%nf)) .or. &
              any(piece%ijk(:, 1:piece%nf) > spread(part%hi, 2, piece%nf))) outside = .true.
          do f = 1, piece%nf
            g = owner(piece%ijk(1, f), piece%ijk(2, f), piece%ijk(3, f), comp_of(piece, f))
            if (g == 0) cycle
            if (piece%alpha(f) == one%alpha(g) .and. piece%relax(f) == one%relax(g) .and. &
                all(face_offset(piece, f) == face_offset(one, g))) matched = matched + 1
          end do
        end do
      end do
    end do
    same = found == one%nf .and. matched == one%nf .and. .not. outside
    call check(same, '8 blocks list the one-block unknowns, with bitwise the same alpha, relaxation and r')
    call check_below('8 blocks: M_p summed over the blocks against one block (relative)', &
                     maxval(abs(summed - rigid_one)) / maxval(abs(rigid_one)), 1.0e-13_dp)
  end subroutine decomposition

  ! The component of face f.
  integer function comp_of(faces, f)
    type(face_list_t), intent(in) :: faces
    integer, intent(in) :: f
    comp_of = faces%run_comp(run_of(faces, f))
  end function comp_of

  ! The run that holds face f.
  integer function run_of(faces, f)
    type(face_list_t), intent(in) :: faces
    integer, intent(in) :: f
    do run_of = 1, faces%nruns - 1
      if (f < faces%run_start(run_of + 1)) return
    end do
  end function run_of

  ! 6. a close pair, mirror-symmetric about the grid plane x = 15 h
  subroutine close_pair()
    type(mac_block_t) :: block
    type(face_list_t) :: faces
    real(dp), allocatable :: rigid(:, :, :)
    real(dp) :: positions(3, 2), worst_rule, worst_sym
    integer :: c, n_shared
    logical :: disjoint
    block = periodic_block(5, 30)
    ! gap 0.1 h between the spheres, the inflated spheres of the code would overlap further
    positions(:, 1) = [15 * block%h - radius - 0.05_dp * block%h, 2.03_dp, 1.97_dp]
    positions(:, 2) = [15 * block%h + radius + 0.05_dp * block%h, 2.03_dp, 1.97_dp]
    call build(block, positions, faces, rigid, 3.0_dp, .true.)
    call audit_pair(block, faces, positions, [radius, radius], disjoint, n_shared, worst_rule)
    call check(disjoint, 'close pair: the two spheres list disjoint unknowns')
    call check(n_shared > 0, 'close pair: both spheres reach some unknowns (the rule is exercised)')
    call check_below('close pair: owner = larger cover, weight = excess over the other''s', worst_rule, 1.0e-15_dp)
    worst_sym = 0.0_dp
    do c = 1, 4
      worst_sym = max(worst_sym, abs(alpha_sum(faces, c, 1) - alpha_sum(faces, c, 2)) / alpha_sum(faces, c, 1))
    end do
    call check_below('close pair mirrored about a grid plane: the same total weight per component', worst_sym, 1.0e-12_dp)
  end subroutine close_pair

  ! The ownership of a pair's faces audited against §3.4 recomputed from cube_fraction of both
  ! spheres (each with its own radius): disjoint, no unknown listed twice; n_shared, the listed
  ! unknowns both spheres cover; worst_rule, the largest difference between a listed weight and
  ! the owner's cover less the other's (huge when the smaller cover owns one).
  subroutine audit_pair(block, faces, positions, radii, disjoint, n_shared, worst_rule)
    type(mac_block_t), intent(in) :: block
    type(face_list_t), intent(in) :: faces
    real(dp), intent(in) :: positions(3, 2), radii(2)
    logical, intent(out) :: disjoint
    integer, intent(out) :: n_shared
    real(dp), intent(out) :: worst_rule
    integer, allocatable :: seen(:, :, :, :)
    real(dp) :: a(2), x(3)
    integer :: f, g, c, q
    allocate(seen(0:block%n(1) - 1, 0:block%n(2) - 1, 0:block%n(3) - 1, 4))
    seen = 0
    disjoint = .true.
    worst_rule = 0.0_dp
    n_shared = 0
    do f = 1, faces%nf
      c = comp_of(faces, f)
      q = faces%run_part(run_of(faces, f))
      if (seen(faces%ijk(1, f), faces%ijk(2, f), faces%ijk(3, f), c) /= 0) disjoint = .false.
      seen(faces%ijk(1, f), faces%ijk(2, f), faces%ijk(3, f), c) = q
      do g = 1, 2
        x = (faces%ijk(:, f) + STAGGER(:, c)) * block%h - positions(:, g)
        x = x - block%box * nint(x / block%box)
        a(g) = cube_fraction(x, radii(g), block%h)
      end do
      if (a(3 - q) > 0.0_dp) n_shared = n_shared + 1
      if (a(q) < a(3 - q)) then
        worst_rule = huge(1.0_dp)
      else
        worst_rule = max(worst_rule, abs(faces%alpha(f) - (a(q) - a(3 - q))))
      end if
    end do
  end subroutine audit_pair

  ! 11. spheres of two sizes (radii R and 2R, a mixture): alone, each covers its own volume
  ! 4/3 pi R_i^3 within 3e-3 (the planar ramp's error, as in 2); 0.1 h apart, they list disjoint
  ! unknowns, the owner of a contested one is the sphere with the larger cube_fraction of its OWN
  ! radius and its weight is the excess, to 1e-13 (the large sphere crosses the periodic boundary:
  ! its wrapped offsets differ from the visit's unwrapped ones by ~1 ulp of the box, 1e-15, and
  ! alpha moves by at most 4 |dr|/h, 2e-14 at h = 0.2); and the
  ! small sphere keeps unknowns the large one reaches (the rival test uses each sphere's reach:
  ! with the small sphere's reach in its place the large sphere would miss unknowns it contests,
  ! which the disjointness check would catch).
  subroutine unequal_pair()
    type(mac_block_t) :: block
    type(face_list_t) :: faces
    real(dp), allocatable :: rigid(:, :, :)
    real(dp) :: positions(3, 2), radii(2), worst_rule, worst_vol
    integer :: c, q, n_shared
    logical :: disjoint
    block = periodic_block(5, 40)
    radii = [radius, 2.0_dp * radius]
    positions(:, 1) = [4.03_dp, 4.01_dp, 3.97_dp]
    positions(:, 2) = [4.03_dp + 3.0_dp * radius + 0.1_dp * block%h, 4.01_dp, 3.97_dp]
    ! alone (no rivals): each sphere's own volume, component by component
    call build(block, positions, faces, rigid, 3.0_dp, .false., radii)
    worst_vol = 0.0_dp
    do c = 1, 4
      do q = 1, 2
        worst_vol = max(worst_vol, abs(alpha_sum(faces, c, q) * block%h**3 / (4.0_dp / 3.0_dp * pi * radii(q)**3) - 1))
      end do
    end do
    call check_below('radii R and 2R, alone: sum alpha h^3 / (4/3 pi R_i^3) - 1', worst_vol, 3.0e-3_dp)
    call build(block, positions, faces, rigid, 3.0_dp, .true., radii)
    call audit_pair(block, faces, positions, radii, disjoint, n_shared, worst_rule)
    call check(disjoint, 'radii R and 2R 0.1 h apart: the two spheres list disjoint unknowns')
    call check(n_shared > 0, 'radii R and 2R: both spheres reach some unknowns (the rule is exercised)')
    call check_below('radii R and 2R: owner = larger cover of its own radius, weight = the excess', worst_rule, &
                     1.0e-13_dp)
  end subroutine unequal_pair

  ! 7. walls in y
  subroutine walls()
    type(mac_block_t) :: block
    type(face_list_t) :: faces
    real(dp), allocatable :: rigid(:, :, :)
    integer :: f
    logical :: inside, no_wall_v
    block = periodic_block(5, 20)
    block%walls = .true.
    ! touching the wall y = 0 and crossing it by 0.3 h
    call build(block, reshape([2.0_dp, radius - 0.3_dp * block%h, 2.0_dp], [3, 1]), faces, rigid, 3.0_dp, .false.)
    inside = all(faces%ijk(2, 1:faces%nf) >= 0 .and. faces%ijk(2, 1:faces%nf) < 20)
    no_wall_v = .true.
    do f = 1, faces%nf
      if (comp_of(faces, f) == 2 .and. faces%ijk(2, f) == 0) no_wall_v = .false.
    end do
    call check(inside .and. faces%nf > 0, 'walls: every listed unknown lies between the walls')
    call check(no_wall_v, 'walls: no v on the wall j = 0')
  end subroutine walls

  ! 8, 9 on one sphere with plain arrays as the fields (the whole grid, one block), through the
  ! passes over the list that mod_fictitious_domain calls
  subroutine run_kernels()
    type(mac_block_t) :: block
    type(face_list_t) :: faces
    real(dp), allocatable :: rigid(:, :, :), lambda_new(:)
    real(dp), allocatable, target :: u(:, :, :, :), lam(:, :, :, :), u2(:, :, :, :), lam2(:, :, :, :), p(:, :, :)
    type(field_view_t) :: vu(3), vlam(3), vu2(3), vlam2(3), vp
    real(dp) :: centre(3), velocity(3, 1), omega(3, 1), gu(3), moments(12, 1), b6(6), sums(16, 1), sums2(16, 1)
    real(dp) :: dv, beta, worst, force(3), sgn(2)
    integer :: run, f0, f1, c, q, f, idx(3), arm(2)
    block = periodic_block(5, 20)
    dv = block%h**3
    beta = 100.0_dp
    centre = [2.03_dp, 1.94_dp, 2.11_dp]
    velocity(:, 1) = [0.3_dp, -0.7_dp, 0.2_dp]
    omega(:, 1) = [0.5_dp, 0.1_dp, -0.4_dp]
    call build(block, reshape(centre, [3, 1]), faces, rigid, 0.8_dp, .false.)
    allocate(u(0:19, 0:19, 0:19, 3), lam(0:19, 0:19, 0:19, 3), p(0:19, 0:19, 0:19), lambda_new(faces%nf))
    ! u~ = U + Omega x r on the listed faces (elsewhere 1, which no kernel may read)
    u = 1.0_dp
    lam = 0.0_dp
    do run = 1, faces%nruns
      call face_run(faces, run, f0, f1, c, q)
      if (c == 4) cycle
      do f = f0, f1
        gu = velocity(:, 1) + cross(omega(:, 1), face_offset(faces, f))
        u(faces%ijk(1, f), faces%ijk(2, f), faces%ijk(3, f), c) = gu(c)
      end do
    end do
    u2 = u
    lam2 = lam
    do c = 1, 3
      vu(c)%v => u(:, :, :, c)
      vlam(c)%v => lam(:, :, :, c)
      vu2(c)%v => u2(:, :, :, c)
      vlam2(c)%v => lam2(:, :, :, c)
    end do
    vp%v => p
    ! 8. b = M_p (U, Omega), m(0) = 0, Lambda^{n+1} = 0
    moments = 0.0_dp
    call faces_moments(faces, vu, vlam, block%lo, block%hi, dv, moments)
    call faces_new_lambda(faces, vu, vlam, block%lo, block%hi, beta, velocity, omega, lambda_new)
    b6 = matmul(rigid(:, :, 1), [velocity(:, 1), omega(:, 1)])
    call check_below('b(U + Omega x r) = M_p (U, Omega) (relative)', maxval(abs(moments(1:6, 1) - b6)) / maxval(abs(b6)), &
                     1.0e-12_dp)
    call check(all(moments(7:12, 1) == 0.0_dp), 'm(0) = 0')
    worst = 0.0_dp
    do run = 1, faces%nruns
      call face_run(faces, run, f0, f1, c, q)
      if (c /= 4) worst = max(worst, maxval(abs(lambda_new(f0:f1))))
    end do
    call check_below('Lambda^{n+1} of the rigid motion / (beta |U|)', worst / (beta * norm2(velocity)), 1.0e-12_dp)
    ! 9. the two update paths, from a u~ off the rigid motion and a Lambda^n on the faces
    do run = 1, faces%nruns
      call face_run(faces, run, f0, f1, c, q)
      if (c == 4) cycle
      do f = f0, f1
        u(faces%ijk(1, f), faces%ijk(2, f), faces%ijk(3, f), c) = 0.1_dp * sin(real(f, dp))
        lam(faces%ijk(1, f), faces%ijk(2, f), faces%ijk(3, f), c) = cos(real(3 * f, dp))
      end do
    end do
    u2 = u
    lam2 = lam
    p = 2.5_dp
    sums = 0.0_dp
    sums2 = 0.0_dp
    call faces_update(faces, vu, vlam, vp, block%lo, block%hi, beta, dv, velocity, omega, sums)
    call faces_new_lambda(faces, vu2, vlam2, block%lo, block%hi, beta, velocity, omega, lambda_new)
    ! the whole-grid removal of Lambda^n (VecAXPY and VecSet in mod_fictitious_domain), then the pass
    u2 = u2 + (-1.0_dp / beta) * lam2
    lam2 = 0.0_dp
    call faces_update(faces, vu2, vlam2, vp, block%lo, block%hi, beta, dv, velocity, omega, sums2, lambda_new)
    call check(all(u == u2) .and. all(lam == lam2) .and. all(sums == sums2), &
               'update: Lambda^n removed first or in the pass, bitwise the same u, Lambda and sums')
    force = 0.0_dp
    worst = 0.0_dp
    do run = 1, faces%nruns
      call face_run(faces, run, f0, f1, c, q)
      if (c == 4) cycle
      force(c) = force(c) - sum(lambda_new(f0:f1)) * dv
      worst = worst + sum(abs(lambda_new(f0:f1))) * dv
    end do
    call check_below('update: force = -sum Lambda dV (relative to sum |Lambda| dV)', &
                     maxval(abs(sums(1:3, 1) - force)) / worst, 1.0e-12_dp)
    ! the interior pressure of the uniform p0 = 2.5 (the runs of cell centres)
    call check_below('update: interior pressure of p0 = p0 sum alpha dV (relative)', &
                     abs(sums(16, 1) - 2.5_dp * alpha_sum(faces, 4) * dv) / sums(16, 1), 1.0e-12_dp)
    ! the torque's arm (g = (e_c, r x e_c)) against the cross product
    worst = 0.0_dp
    do c = 1, 3
      call torque_arm(c, idx, arm, sgn)
      gu = cross(centre, axis(c))
      worst = max(worst, abs(sgn(1) * centre(arm(1)) - gu(idx(2) - 3)) + abs(sgn(2) * centre(arm(2)) - gu(idx(3) - 3)))
    end do
    call check(worst == 0.0_dp, 'torque_arm: the non-zeros of r x e_c')
  end subroutine run_kernels

  ! 10. the carry of a linear field
  subroutine carry()
    integer, parameter :: n = 8
    real(dp) :: old(-1:n, -1:n, -1:n), new(0:n - 1, 0:n - 1, 0:n - 1), weight(8), dx(3), worst, expect
    integer :: corner(3, 8), ijk(3, n**3), i, j, k, f, trial
    real(dp), parameter :: slope(3) = [0.7_dp, -1.3_dp, 0.4_dp], h = 0.2_dp
    do k = -1, n
      do j = -1, n
        do i = -1, n
          old(i, j, k) = 2.0_dp + slope(1) * i + slope(2) * j + slope(3) * k
        end do
      end do
    end do
    f = 0
    do k = 0, n - 1
      do j = 0, n - 1
        do i = 0, n - 1
          f = f + 1
          ijk(:, f) = [i, j, k]
        end do
      end do
    end do
    worst = 0.0_dp
    do trial = 1, 4
      dx = [0.37_dp, -0.81_dp, 0.05_dp] * h * (trial - 2.5_dp) / 1.5_dp
      call carry_corners(dx, h, corner, weight)
      call check_below('carry: the eight weights sum to 1', abs(sum(weight) - 1.0_dp), 1.0e-15_dp)
      new = 0.0_dp
      call carry_run(old, new, [-1, -1, -1], [n, n, n], [0, 0, 0], [n - 1, n - 1, n - 1], n**3, ijk, corner, &
                     weight, .true., .false., n)
      do f = 1, n**3
        expect = 2.0_dp + sum(slope * (ijk(:, f) - dx / h))
        worst = max(worst, abs(new(ijk(1, f), ijk(2, f), ijk(3, f)) - expect))
      end do
    end do
    call check_below('carry: a linear field arrives exactly (error / its size 10)', worst / 10.0_dp, 1.0e-12_dp)
    call carry_corners([0.0_dp, 0.0_dp, 0.0_dp], h, corner, weight)
    new = 0.0_dp
    call carry_run(old, new, [-1, -1, -1], [n, n, n], [0, 0, 0], [n - 1, n - 1, n - 1], n**3, ijk, corner, &
                   weight, .false., .false., n)
    call check(all(new == old(0:n - 1, 0:n - 1, 0:n - 1)), 'carry: no displacement copies bitwise')
  end subroutine carry

  pure function axis(c) result(e)
    integer, intent(in) :: c
    real(dp) :: e(3)
    e = 0.0_dp
    e(c) = 1.0_dp
  end function axis

end program test_sphere_faces
