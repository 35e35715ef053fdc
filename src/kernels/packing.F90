! Random hard-sphere configurations (doc/PACKING_INPUT.md): spheres of radius a_i (equal, or a
! mixture) at a target volume fraction in a triply periodic box or in the Couette cell (x, z
! periodic; walls at y = 0 and y = Ly, which no sphere overlaps: a_i <= y <= Ly - a_i). Pure: no
! PETSc, MPI or HDF5. An optional minimum gap g_min keeps every surface-to-surface gap >= g_min
! (spheres of radius a_i + g_min/2 for the pairs, centres in [a_i + g_min, Ly - a_i - g_min]).
! Radii are held as one reference radius (the largest) times a factor f_i <= 1 per sphere; equal
! spheres have f_i = 1 exactly, so their arithmetic and random numbers are those of the
! equal-sphere packer, bit for bit (tests/unit/test_packing_mixture.F90).
!
! Algorithm
!   1. n centres uniformly at random in the accessible region.
!   2. Compression by growing radii with overlap relaxation and Monte Carlo mixing. The radius
!      starts at the value giving phi = 0.1 and grows stage by stage; the diameter grows each
!      stage by 0.1 x the mean-gap estimate 2 rad ((0.64/phi_s)^(1/3) - 1), a fraction of the
!      room left before random close packing (0.64), so the steps shrink as phi_s rises. After
!      each growth, overlaps are relaxed away by Gauss-Seidel sweeps over cell lists (each
!      overlapping pair pushed apart along its line of centres, walls clamp the centres) with
!      radius rad (1 + 0.03), until no overlap exceeds 0.015 rad: every gap ends >= 0.045 rad.
!      Relaxing with that margin, rather than to bare contact, leaves no contact network (which
!      would freeze the Monte Carlo below); 5 Monte Carlo sweeps at radius rad then mix the
!      structure before the next growth. Above phi_s = 0.64/1.05^3 = 0.553 (mean-gap estimate
!      g = (0.64/phi_s)^(1/3) - 1 below 0.05) the margin shrinks as 0.03 (g/0.05)^2 (a relaxation
!      at phi_s (1 + 0.03)^3 would pass random close packing; quadratic rather than linear in g
!      lets walls reach 0.60); no stage at or below 0.55 sees that (doc/PACKING_INPUT.md "Dense").
!   3. Equilibration: hard-sphere Metropolis Monte Carlo at the final radius, n_sweeps sweeps of
!      n trial displacements of a sphere chosen at random, uniform in a cube of side 2 step; a
!      move is rejected when it overlaps another sphere or a wall. The step is tuned towards
!      40 % acceptance in the first half of the sweeps and then frozen, so that detailed balance
!      holds in the second half. The equilibrium hard-sphere fluid is reached in about 100
!      sweeps at phi = 0.4 (g(2a) is tested against Carnahan-Starling at 0.2, 0.3, 0.4).
! Reproducible: the generator (MRG32k3a, L'Ecuyer 1999) runs in exact integer(8) arithmetic,
! so a seed gives the same stream with every compiler; positions are identical for a given build.
module mod_packing
  use mod_kinds, only: dp, i8, pi
  use mod_neighbours, only: cell_coord, cell_index, cells_around, min_image
  use mod_packing_geometry, only: phi_max, volume_fraction
  implicit none
  private
  public :: rng_t, rng_seed, rng_uniform
  public :: packing_report_t, random_packing, random_packing_mixture, hs_monte_carlo, min_separation

  type :: rng_t
    integer(i8) :: s(6) = 12345_i8             ! MRG32k3a state: s(1:3) component 1, s(4:6) 2
  end type rng_t
  integer(i8), parameter :: m1 = 4294967087_i8, m2 = 4294944443_i8

  real(dp), parameter :: margin = 3.0e-2_dp    ! relaxation radius rad (1 + margin)
  real(dp), parameter :: phi_start = 0.1_dp    ! volume fraction of the first stage
  real(dp), parameter :: phi_rcp = 0.64_dp     ! random close packing, for the growth schedule
  real(dp), parameter :: growth = 0.1_dp       ! diameter growth per stage / mean gap estimate
  real(dp), parameter :: gap_dense = 0.05_dp   ! mean gap estimate below which the margin shrinks
  integer, parameter :: max_stages = 1000
  integer, parameter :: stage_sweeps = 5       ! Monte Carlo sweeps after each stage
  integer, parameter :: max_relax = 20000      ! relaxation sweeps per stage

  type :: packing_report_t
    integer :: n = 0
    real(dp) :: phi = 0                        ! sum_i (4/3) pi a_i^3 / (Lx Ly Lz)
    real(dp) :: phi_reached = 0                ! phi of the last overlap-free compression stage
    integer :: stages = 0                      ! compression stages
    integer :: relax_sweeps = 0                ! total overlap-relaxation sweeps
    real(dp) :: acceptance = 0                 ! Monte Carlo acceptance over the frozen-step half
    real(dp) :: step = 0                       ! final Monte Carlo step [a]
    real(dp) :: min_pair_gap = 0               ! min |r| - a_i - a_j [a]
    real(dp) :: min_wall_gap = 0               ! min distance to a wall - a_i [a] (huge if periodic)
  end type packing_report_t

  !> Cell lists for spheres of diameter <= cell side, kept up to date under single moves.
  type :: cells_t
    integer :: nc(3) = 1
    real(dp) :: box(3) = 1
    logical :: periodic(3) = .true.
    integer, allocatable :: head(:), next(:), prev(:), cell(:)
  end type cells_t

contains

  ! ---- random numbers ------------------------------------------------------------------------

  !> Seed MRG32k3a from an integer (any value) by a Lehmer scramble. Every product stays below
  !> 2^63, so the stream is exact and compiler independent.
  subroutine rng_seed(g, seed)
    type(rng_t), intent(out) :: g
    integer, intent(in) :: seed
    integer(i8) :: x
    integer :: k
    real(dp) :: dummy
    x = 1 + modulo(int(seed, i8) * 69069_i8 + 1234567_i8, 2147483646_i8)
    do k = 1, 6
      x = modulo(x * 48271_i8, 2147483647_i8)
      if (k <= 3) then
        g%s(k) = 1 + modulo(x, m1 - 1)
      else
        g%s(k) = 1 + modulo(x, m2 - 1)
      end if
    end do
    do k = 1, 16
      dummy = rng_uniform(g)
    end do
  end subroutine rng_seed

  !> MRG32k3a, uniform in (0, 1): L'Ecuyer's recurrence; the output is (z + 1)/(m1 + 1) with
  !> z = (p1 - p2) mod m1, never 0 or 1.
  real(dp) function rng_uniform(g) result(r)
    type(rng_t), intent(inout) :: g
    integer(i8) :: p1, p2
    p1 = modulo(1403580_i8 * g%s(2) - 810728_i8 * g%s(1), m1)
    g%s(1:2) = g%s(2:3)
    g%s(3) = p1
    p2 = modulo(527612_i8 * g%s(6) - 1370589_i8 * g%s(4), m2)
    g%s(4:5) = g%s(5:6)
    g%s(6) = p2
    r = real(modulo(p1 - p2, m1) + 1, dp) / real(m1 + 1, dp)
  end function rng_uniform

  ! ---- cell lists ---------------------------------------------------------------------------

  subroutine cells_init(cl, box, periodic, side, n)
    type(cells_t), intent(inout) :: cl
    real(dp), intent(in) :: box(3), side
    logical, intent(in) :: periodic(3)
    integer, intent(in) :: n
    cl%box = box
    cl%periodic = periodic
    cl%nc = max(1, int(box / side))
    if (allocated(cl%head)) deallocate(cl%head, cl%next, cl%prev, cl%cell)
    allocate(cl%head(product(cl%nc)), cl%next(n), cl%prev(n), cl%cell(n))
  end subroutine cells_init

  pure integer function cell_of(cl, x) result(idx)
    type(cells_t), intent(in) :: cl
    real(dp), intent(in) :: x(3)
    idx = cell_index(cell_coord(x, cl%box, cl%periodic, cl%nc), cl%nc)
  end function cell_of

  !> The distinct cells around the cell of position x.
  pure subroutine cells_near(cl, x, cells, nu)
    type(cells_t), intent(in) :: cl
    real(dp), intent(in) :: x(3)
    integer, intent(out) :: cells(27), nu
    call cells_around(cell_coord(x, cl%box, cl%periodic, cl%nc), cl%nc, cl%periodic, cells, nu)
  end subroutine cells_near

  subroutine cells_fill(cl, x, n)
    type(cells_t), intent(inout) :: cl
    real(dp), intent(in) :: x(:,:)
    integer, intent(in) :: n
    integer :: i
    cl%head = 0
    do i = n, 1, -1
      call cells_insert(cl, i, cell_of(cl, x(:, i)))
    end do
  end subroutine cells_fill

  subroutine cells_insert(cl, i, c)
    type(cells_t), intent(inout) :: cl
    integer, intent(in) :: i, c
    cl%cell(i) = c
    cl%prev(i) = 0
    cl%next(i) = cl%head(c)
    if (cl%head(c) > 0) cl%prev(cl%head(c)) = i
    cl%head(c) = i
  end subroutine cells_insert

  subroutine cells_remove(cl, i)
    type(cells_t), intent(inout) :: cl
    integer, intent(in) :: i
    if (cl%prev(i) > 0) then
      cl%next(cl%prev(i)) = cl%next(i)
    else
      cl%head(cl%cell(i)) = cl%next(i)
    end if
    if (cl%next(i) > 0) cl%prev(cl%next(i)) = cl%prev(i)
  end subroutine cells_remove

  ! ---- the packing --------------------------------------------------------------------------

  !> n equal spheres of radius a: random_packing_mixture with a_i = a (bit for bit the
  !> equal-sphere packer of before the mixtures; fdsusp's in-run packing calls it).
  subroutine random_packing(n, box, periodic, a, min_gap, seed, n_sweeps, x, info, msg, rep)
    integer, intent(in) :: n, seed, n_sweeps
    real(dp), intent(in) :: box(3), a, min_gap
    logical, intent(in) :: periodic(3)
    real(dp), allocatable, intent(out) :: x(:,:)
    integer, intent(out) :: info
    character(len=*), intent(out) :: msg
    type(packing_report_t), intent(out) :: rep
    real(dp), allocatable :: radius(:)
    allocate(radius(max(n, 0)))
    radius = a
    call random_packing_mixture(radius, box, periodic, min_gap, seed, n_sweeps, x, info, msg, rep)
  end subroutine random_packing

  !> size(radius) spheres of radii radius(:) at random in box (periodic(2) = .false.: walls at
  !> y = 0, Ly), every gap >= min_gap, then n_sweeps Monte Carlo sweeps. x(3, n) is allocated
  !> here, positions in [0, L) per periodic direction; sphere i has radius radius(i).
  !> info: 0 ok; 1 no sphere, a radius <= 0, min_gap < 0, or the volume fraction with the
  !> minimum gap above phi_max by more than one (largest) sphere; 2 a box length below
  !> 4 (a_max + min_gap); 3 the compression jammed (target not reached). msg says which.
  subroutine random_packing_mixture(radius, box, periodic, min_gap, seed, n_sweeps, x, info, msg, rep)
    real(dp), intent(in) :: radius(:), box(3), min_gap
    integer, intent(in) :: seed, n_sweeps
    logical, intent(in) :: periodic(3)
    real(dp), allocatable, intent(out) :: x(:,:)
    integer, intent(out) :: info
    character(len=*), intent(out) :: msg
    type(packing_report_t), intent(out) :: rep
    type(rng_t) :: g
    integer :: n, i, k, stage, its
    real(dp) :: a, ae, rad, lo(3), hi(3), step, acc, phi, phie, phis, mrg
    real(dp), allocatable :: f(:), ylo(:), yhi(:)
    logical :: ok

    info = 0
    msg = ''
    allocate(x(3, 0))
    n = size(radius)
    if (n < 1 .or. .not. (min_gap >= 0)) then
      info = 1
      msg = 'packing: no sphere to place, or a negative minimum gap'
      return
    end if
    if (.not. all(radius > 0)) then
      info = 1
      msg = 'packing: a radius is not positive'
      return
    end if
    a = maxval(radius)
    ae = a + 0.5_dp * min_gap                  ! hard-sphere radius of the largest pairs
    ! radius of sphere i at any stage: rad f(i), rad growing to ae; f = 1 for equal spheres
    f = (radius + 0.5_dp * min_gap) / ae
    phi = volume_fraction(radius, box)
    if (all(radius == a)) then
      phie = phi * (ae / a)**3
    else
      phie = volume_fraction(radius + 0.5_dp * min_gap, box)
    end if
    rep%n = n
    rep%phi = phi
    ! (one sphere of slack: the count closest to phi_max V / v may round up)
    if (phie - (4.0_dp / 3 * pi * ae**3) / product(box) > phi_max * (1 + 1.0e-12_dp)) then
      info = 1
      if (min_gap > 0) then
        write(msg, '(a,f6.4,a,f4.2)') 'packing: volume fraction with the minimum gap ', phie, &
          ' above the supported ', phi_max
      else
        write(msg, '(a,f6.4,a,f4.2)') 'packing: volume fraction ', phi, ' above the supported ', phi_max
      end if
      return
    end if
    if (any(box < 4 * (a + min_gap))) then
      info = 2
      msg = 'packing: every box length must be at least 4 (a + min_gap), a the largest radius'
      return
    end if
    deallocate(x)
    allocate(x(3, n))

    ! centres are confined to [lo, hi], in y to [ylo(i), yhi(i)]: the walls exclude a layer
    ! a_i + min_gap thick
    call rng_seed(g, seed)
    lo = 0
    hi = box
    allocate(ylo(n), yhi(n))
    ylo = lo(2)
    yhi = hi(2)
    if (.not. periodic(2)) then
      ylo = radius + min_gap
      yhi = box(2) - radius - min_gap
    end if
    do i = 1, n
      lo(2) = ylo(i)
      hi(2) = yhi(i)
      do k = 1, 3
        x(k, i) = lo(k) + (hi(k) - lo(k)) * rng_uniform(g)
      end do
    end do

    ! --- compression (see the module header)
    step = 0.1_dp * ae
    rad = ae * (min(phie, phi_start) / phie)**(1.0_dp / 3)
    ok = .false.
    do stage = 1, max_stages
      phis = phie * (rad / ae)**3
      mrg = min(margin, max(1.0e-3_dp, margin * (((phi_rcp / phis)**(1.0_dp / 3) - 1) / gap_dense)**2))
      call relax_overlaps(x, box, periodic, rad, mrg, f, ylo, yhi, its, ok)
      rep%relax_sweeps = rep%relax_sweeps + its
      rep%stages = stage
      if (.not. ok) exit
      rep%phi_reached = phi * (rad / ae)**3
      call mc_core(x, box, periodic, rad, f, ylo, yhi, g, step, stage_sweeps, .true., acc)
      if (rad >= ae) exit
      phis = phie * (rad / ae)**3
      rad = min(ae, rad * (1 + growth * ((phi_rcp / phis)**(1.0_dp / 3) - 1)))
    end do

    ! --- exact check: every gap >= min_gap (up to rounding of a + min_gap - a at a clamped wall)
    call min_separation(x, box, periodic, a, rep%min_pair_gap, rep%min_wall_gap, radius)
    if (.not. ok) then
      info = 3
      write(msg, '(a,f6.4,a,i0,a,f6.4,a)') 'packing: jammed at phi = ', rep%phi_reached, &
        ' (overlaps not removed in ', max_relax, ' relaxation sweeps) below the target ', phi, &
        ' (target not reached)'
      return
    end if
    if (rad < ae .or. rep%min_pair_gap < min_gap - 1.0e-12_dp * a .or. &
        rep%min_wall_gap < min_gap - 1.0e-12_dp * a) then
      info = 3
      write(msg, '(a,f6.4,a)') 'packing: compression could not remove every overlap at phi = ', &
        phi, ' (target not reached)'
      return
    end if

    ! --- equilibration
    call mc_core(x, box, periodic, ae, f, ylo, yhi, g, step, n_sweeps, .true., acc)
    rep%acceptance = acc
    rep%step = step
    call min_separation(x, box, periodic, a, rep%min_pair_gap, rep%min_wall_gap, radius)
  end subroutine random_packing_mixture

  !> Push overlapping spheres of radii rad f(i) apart until every gap is positive: Gauss-Seidel
  !> sweeps in which each overlapping pair in turn is separated along its line of centres by
  !> 1.05 x its overlap (the small excess ends pairs with a gap rather than at contact), the
  !> centres clamped to [ylo(i), yhi(i)] in a bounded y, with radii rad f(i) (1 + mrg) and
  !> tolerance mrg rad min(f) / 2, so that every gap at radii rad f(i) ends >= 1.5 mrg rad min(f).
  !> its: sweeps done; ok: converged.
  subroutine relax_overlaps(x, box, periodic, rad, mrg, f, ylo, yhi, its, ok)
    real(dp), intent(inout) :: x(:,:)
    real(dp), intent(in) :: box(3), rad, mrg, f(:), ylo(:), yhi(:)
    logical, intent(in) :: periodic(3)
    integer, intent(out) :: its
    logical, intent(out) :: ok
    type(cells_t) :: cl
    integer :: n, i, j, k, m, cells(27), nu
    real(dp) :: rr, rri, tol, r(3), d, ov, maxov, push(3)
    n = size(x, 2)
    rr = rad * (1 + mrg)
    tol = 0.5_dp * mrg * rad * minval(f)
    ! f <= 1: cells of side 2 rr hold every overlapping pair in neighbouring cells
    call cells_init(cl, box, periodic, 2 * rr, n)
    ok = .false.
    do its = 1, max_relax
      call cells_fill(cl, x, n)
      maxov = 0
      do i = 1, n
        rri = rr * f(i)
        call cells_near(cl, x(:, i), cells, nu)
        do m = 1, nu
          j = cl%head(cells(m))
          do while (j > 0)
            if (j > i) then
              r = min_image(x(:, j) - x(:, i), box, periodic)
              d = norm2(r)
              ov = (rri + rr * f(j)) - d
              if (ov > 0) then
                maxov = max(maxov, ov)
                if (d > 1.0e-12_dp * rad) then
                  push = (0.5_dp * 1.05_dp * ov / d) * r
                else
                  push = [0.5_dp * ov, 0.0_dp, 0.0_dp]   ! coincident centres: any direction
                end if
                x(:, i) = x(:, i) - push
                x(:, j) = x(:, j) + push
                if (.not. periodic(2)) then
                  x(2, i) = min(max(x(2, i), ylo(i)), yhi(i))
                  x(2, j) = min(max(x(2, j), ylo(j)), yhi(j))
                end if
              end if
            end if
            j = cl%next(j)
          end do
        end do
      end do
      ! wrap (the cells of this sweep were built before the moves: a pair missed because of
      ! that is caught by the next sweep, and the final check of random_packing is exact)
      do i = 1, n
        do k = 1, 3
          if (periodic(k)) then
            x(k, i) = x(k, i) - box(k) * floor(x(k, i) / box(k))
            if (x(k, i) >= box(k)) x(k, i) = 0          ! -tiny wraps to box(k) in rounding
          end if
        end do
      end do
      if (maxov <= tol) then
        ok = .true.
        exit
      end if
    end do
    its = min(its, max_relax)
  end subroutine relax_overlaps

  !> Hard-sphere Metropolis Monte Carlo on spheres of radius a (or radius(i) when given),
  !> centres confined to a_i <= y <= Ly - a_i when y is bounded: n_sweeps sweeps of size(x, 2)
  !> trial moves of a sphere chosen at random, displaced uniformly in a cube of side 2 step.
  !> x must be overlap-free. adapt: tune step towards 40 % acceptance during the first half, then
  !> keep it; acc is the acceptance ratio over the sweeps with a fixed step.
  subroutine hs_monte_carlo(x, box, periodic, a, g, step, n_sweeps, adapt, acc, radius)
    real(dp), intent(inout) :: x(:,:)
    real(dp), intent(in) :: box(3), a
    logical, intent(in) :: periodic(3), adapt
    type(rng_t), intent(inout) :: g
    real(dp), intent(inout) :: step
    integer, intent(in) :: n_sweeps
    real(dp), intent(out) :: acc
    real(dp), intent(in), optional :: radius(:)
    real(dp), allocatable :: ai(:)
    real(dp) :: amax
    if (present(radius)) then
      ai = radius
    else
      allocate(ai(size(x, 2)))
      ai = a
    end if
    amax = a
    if (size(ai) > 0) amax = maxval(ai)
    call mc_core(x, box, periodic, amax, ai / amax, ai, box(2) - ai, g, step, n_sweeps, adapt, acc)
  end subroutine hs_monte_carlo

  !> hs_monte_carlo for spheres of radii rad f(i) (f <= 1) with the centres confined to
  !> ylo(i) <= y <= yhi(i).
  subroutine mc_core(x, box, periodic, rad, f, ylo, yhi, g, step, n_sweeps, adapt, acc)
    real(dp), intent(inout) :: x(:,:)
    real(dp), intent(in) :: box(3), rad, f(:), ylo(:), yhi(:)
    logical, intent(in) :: periodic(3), adapt
    type(rng_t), intent(inout) :: g
    real(dp), intent(inout) :: step
    integer, intent(in) :: n_sweeps
    real(dp), intent(out) :: acc
    type(cells_t) :: cl
    integer :: n, sweep, m, i, k, c, nacc
    integer(i8) :: nacc_fixed, ntry_fixed
    real(dp) :: xn(3)
    logical :: tuning
    n = size(x, 2)
    acc = 0
    if (n < 1 .or. n_sweeps < 1) return
    ! cells of side >= 2 rad: a sphere can only overlap spheres in the 27 cells around it
    call cells_init(cl, box, periodic, 2 * rad, n)
    call cells_fill(cl, x, n)
    nacc_fixed = 0
    ntry_fixed = 0
    do sweep = 1, n_sweeps
      tuning = adapt .and. 2 * sweep <= n_sweeps
      nacc = 0
      do m = 1, n
        i = 1 + min(n - 1, int(n * rng_uniform(g)))
        do k = 1, 3
          xn(k) = x(k, i) + step * (2 * rng_uniform(g) - 1)
          if (periodic(k)) then
            xn(k) = xn(k) - box(k) * floor(xn(k) / box(k))
            if (xn(k) >= box(k)) xn(k) = 0
          end if
        end do
        if (.not. periodic(2)) then
          if (xn(2) < ylo(i) .or. xn(2) > yhi(i)) cycle
        end if
        if (.not. fits(i, xn)) cycle
        nacc = nacc + 1
        x(:, i) = xn
        c = cell_of(cl, xn)
        if (c /= cl%cell(i)) then
          call cells_remove(cl, i)
          call cells_insert(cl, i, c)
        end if
      end do
      if (tuning) then
        ! acceptance falls monotonically with the step: scale it by (acceptance / 0.4), at most
        ! by a factor 2 per sweep
        step = step * min(2.0_dp, max(0.5_dp, real(nacc, dp) / (0.4_dp * n)))
        step = min(max(step, 1.0e-4_dp * rad), rad)
      else
        nacc_fixed = nacc_fixed + nacc
        ntry_fixed = ntry_fixed + n
      end if
    end do
    if (ntry_fixed > 0) acc = real(nacc_fixed, dp) / real(ntry_fixed, dp)
  contains
    !> Sphere ip at y overlaps no other: |r| >= rad (f(ip) + f(jj)) for every neighbour jj (for
    !> equal spheres (2 rad)^2 = 4 rad^2 exactly, the test of the equal-sphere packer).
    logical function fits(ip, y) result(yes)
      integer, intent(in) :: ip
      real(dp), intent(in) :: y(3)
      integer :: cells(27), nu, mm, jj
      real(dp) :: ri, sigma
      yes = .true.
      ri = rad * f(ip)
      call cells_near(cl, y, cells, nu)
      do mm = 1, nu
        jj = cl%head(cells(mm))
        do while (jj > 0)
          if (jj /= ip) then
            sigma = ri + rad * f(jj)
            if (sum(min_image(x(:, jj) - y, box, periodic)**2) < sigma * sigma) then
              yes = .false.
              return
            end if
          end if
          jj = cl%next(jj)
        end do
      end do
    end function fits
  end subroutine mc_core

  !> Smallest gap between spheres of radius a, or radius(i) when given (min |r| - a_i - a_j over
  !> pairs, minimum image) and to the walls (min over spheres of min(y, Ly - y) - a_i; huge(1.0)
  !> if y is periodic). O(n) with cells.
  subroutine min_separation(x, box, periodic, a, pair_gap, wall_gap, radius)
    real(dp), intent(in) :: x(:,:), box(3), a
    logical, intent(in) :: periodic(3)
    real(dp), intent(out) :: pair_gap, wall_gap
    real(dp), intent(in), optional :: radius(:)
    type(cells_t) :: cl
    integer :: n, i, j, m, cells(27), nu
    real(dp) :: side, amax
    real(dp), allocatable :: ai(:)
    n = size(x, 2)
    if (present(radius)) then
      ai = radius
    else
      allocate(ai(n))
      ai = a
    end if
    amax = maxval([ai, 0.0_dp])
    pair_gap = huge(1.0_dp)
    ! cells of side >= 2.5 a_max: any pair closer than 2.5 a_max is seen; a farther closest
    ! pair means a gap of >= 0.5 a_max, reported as such
    side = 2.5_dp * amax
    call cells_init(cl, box, periodic, min(side, minval(box) / 2), n)
    call cells_fill(cl, x, n)
    do i = 1, n
      call cells_near(cl, x(:, i), cells, nu)
      do m = 1, nu
        j = cl%head(cells(m))
        do while (j > 0)
          if (j > i) pair_gap = min(pair_gap, &
                                    sqrt(sum(min_image(x(:, j) - x(:, i), box, periodic)**2)) - (ai(i) + ai(j)))
          j = cl%next(j)
        end do
      end do
    end do
    pair_gap = min(pair_gap, side - 2 * amax)
    wall_gap = huge(1.0_dp)
    if (.not. periodic(2)) then
      do i = 1, n
        wall_gap = min(wall_gap, x(2, i) - ai(i), box(2) - x(2, i) - ai(i))
      end do
    end if
  end subroutine min_separation

end module mod_packing
