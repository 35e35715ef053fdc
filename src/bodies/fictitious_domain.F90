! The fictitious domain: inertialess rigid spheres in the MAC-grid fluid (doc/METHOD.md §3,
! with the relaxed constraint of §3.3).
!
! Lambda is stored as the force density Lambda = rho*lambda on the u, v, w faces (fdsusp units:
! rho = Re). One time step, given the geometry at X^n:
!   geometry   solid fraction alpha of every face control volume for a sphere of radius
!              a + radius_offset*h (§3.3: the relaxed constraint shrinks the effective sphere);
!              each face goes to the particle covering most of it (one owner, so sum alpha <= 1),
!              and where two inflated spheres overlap (gaps below 2 radius_offset) the owner's
!              weight is alpha_1 - alpha_2, the excess of its cover over the runner-up's: the gap
!              fluid stays free, so two faces a cell apart never carry opposing fully rigid
!              constraints (with alpha = 1 on both there is no relaxation and no steady state:
!              Lambda then grows linearly in time; doc/DESIGN.md "Close pairs").
!              gamma = kappa (1 - alpha) beta h^2 / eta, beta = rho/dt, weight w = alpha/(1+gamma);
!              the discrete rigid-body matrix M_p = sum_f w g g^T dV with g the 6-vector such that
!              (U + Omega x r)_c = g . (U, Omega), i.e. g = (e_c, r x e_c).
!   fluid      the projection step with Lambda^n as a body force (mod_fluid) -> u~.
!   particles  beta M U = beta b(u~) - m(Lambda^n) + F_ext    (doc/METHOD.md eq. (1))
!              b = sum_f w u~_c g dV,  m = sum_f Lambda^n_f/(1+gamma) g dV; later models add their
!              stiffness and forces to the 6N system (mod_particle_solver).
!              Lambda^{n+1} = [Lambda^n + beta alpha (g.U - u~)]/(1 + gamma) on owned faces, 0 elsewhere;
!              u^{n+1} = u~ + (Lambda^{n+1} - Lambda^n)/beta.
!   moments    F = -sum Lambda e_c dV, T = -sum r x Lambda e_c dV,
!              S = -1/2 sum Lambda (r e_c + e_c r) dV - (sum_cells alpha p dV) I   (§3.7: the
!              trace of the traction moment needs the interior pressure).
! Particle data is replicated; each rank works on the faces it owns and the moments are summed
! over ranks, so spheres cross processor boundaries freely and the result does not depend on the
! decomposition beyond round-off.
#include <petsc/finclude/petscdmda.h>
#include <petsc/finclude/petscksp.h>
module mod_fictitious_domain
  use petscdmda
  use petscksp
  use mod_kinds, only: dp
  use mod_grid, only: grid_t, grid_create_box_layout, FIELD_U, FIELD_V, FIELD_W, FIELD_P
  use mod_particles, only: particles_t, MOTION_FREE, MOTION_FROZEN, impose_motion
  use mod_particle_system, only: particle_system_reset, particle_system_add_diagonal
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_corrections, &
                                      particle_lubrication_add_to_system, &
                                      particle_lubrication_add_corrections
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_add_stiffness, &
                                   particle_contacts_implicit_update
  use mod_particle_solver, only: particle_solver_t, particle_solver_create, particle_solver_solve, &
                                 particle_solver_destroy
  use mod_solid_fraction, only: cube_fraction
  use mod_neighbours, only: nlist_t, nlist_init, nlist_candidates, min_image
  use mod_errors, only: fatal_error
  use mod_limits, only: limit_finding_t, add_finding, LIMIT_WARN
  use mod_timers, only: event_begin, event_end, EVENT_GEOMETRY, EVENT_CARRY, EVENT_MOMENTS, EVENT_MOTION, &
                        EVENT_UPDATE
  implicit none
  private
  public :: fictitious_domain_t, fictitious_domain_create, fictitious_domain_geometry, &
            fictitious_domain_follow, fictitious_domain_moments, fictitious_domain_solve_motion, &
            fictitious_domain_update, fictitious_domain_destroy, &
            fictitious_domain_pair_lag_limit, fictitious_domain_stresslet_lag_limit

  type :: fictitious_domain_t
    real(dp) :: beta = 0.0_dp           ! rho/dt = Re/dt
    real(dp) :: kappa = 0.5_dp          ! relaxation constant of doc/METHOD.md §3.3
    real(dp) :: radius_offset = 0.38_dp ! in grid cells
    real(dp) :: eta = 1.0_dp
    Vec :: lambda(3)                    ! Lambda = rho*lambda on the u, v, w faces
    ! The layout of the faces with edge and corner ghosts (box stencil, mod_grid): the trilinear
    ! carry of fictitious_domain_follow reads them; the fields' own DMDAs (star) never fill them.
    DM :: carry_layout
    ! the covered faces and cells of this rank, in runs of one sphere and one component
    integer :: nf = 0
    integer, allocatable :: f_ijk(:, :)
    real(dp), allocatable :: f_r(:, :), f_alpha(:), f_relax(:)   ! r, alpha, 1/(1+gamma)
    integer :: nruns = 0
    integer, allocatable :: run_start(:)   ! run r (one sphere, one component) is run_start(r) .. run_start(r+1)-1
    integer, allocatable :: run_comp(:), run_part(:)   ! its component and its sphere
    real(dp), allocatable :: rigid_matrix(:, :, :)               ! M_p (6, 6, n), summed over ranks
    ! The rivals of each sphere: the spheres whose control-volume reach meets its own (centres
    ! closer than twice the reach). Only they can contest a face; elsewhere a sphere owns what it
    ! covers outright. Found by mod_neighbours' cell lists, or among all spheres in a box too
    ! small for them.
    type(nlist_t) :: reach_list
    logical :: use_reach_list = .false.
    integer :: nreach_pairs = 0, nreach_walls = 0
    integer, allocatable :: reach_pairs(:, :), reach_walls(:, :)
    integer, allocatable :: rival_start(:)       ! (n + 1): rivals of q are rival_start(q) .. rival_start(q+1)-1
    integer, allocatable :: rival_part(:)        ! the rival's index
    real(dp), allocatable :: rival_offset(:, :)  ! (3, :): centre of the rival minus the centre of q (minimum image)
    real(dp), allocatable :: lambda_new(:)   ! Lambda^{n+1} per listed face (kept: no allocation per step)
    logical :: lambda_listed = .false.       ! Lambda^n is zero off the listed faces (fictitious_domain_follow put it there)
    real(dp), allocatable :: moments(:, :)   ! (12, n): b(u~) and m(Lambda^n) of the step (fictitious_domain_moments)
    type(particle_solver_t) :: solver     ! the 6N system of the particle step and its solution
  end type fictitious_domain_t

  type :: field_pointer
    PetscScalar, pointer :: ptr(:, :, :) => null()
  end type field_pointer

  ! position of unknown c inside its cell, in cells: u on x-faces, v on y-faces, ...
  real(dp), parameter :: stagger(3, 4) = reshape([0.0_dp, 0.5_dp, 0.5_dp, 0.5_dp, 0.0_dp, 0.5_dp, &
       0.5_dp, 0.5_dp, 0.0_dp, 0.5_dp, 0.5_dp, 0.5_dp], [3, 4])

contains

  ! Close free pairs: Lambda on the faces between them relaxes over ~dt^2/(kappa (1 - alpha) Re h^2)
  ! strains, so a pair that opens separates too fast: by ~0.7 % per 1e-3 of dt^2/(Re h^2) at gaps
  ! 0.05-0.1 a (a/Delta = 4, 5, 6; doc/VALIDATION.md §4.4, the pair test's mobility table).
  ! A warning beyond LAG_LIMIT (h: the cell size).
  function fictitious_domain_pair_lag_limit(dt, reynolds, h) result(findings)
    real(dp), intent(in) :: dt, reynolds, h
    type(limit_finding_t), allocatable :: findings(:)
    real(dp), parameter :: LAG_LIMIT = 4.0e-3_dp     ! ~3 % in the separation, measured
    real(dp) :: lag
    character(len=400) :: text
    allocate(findings(0))
    lag = dt**2 / (reynolds * h**2)
    if (lag > LAG_LIMIT) then
      write(text, '(a,es9.2,a,es8.1,a,es9.2,a)') 'close pairs will separate too fast: dt^2/(Re Delta^2) = ', lag, &
           ' exceeds ', LAG_LIMIT, ' (about 0.7 % per 1e-3 in the separation velocity, doc/VALIDATION.md 4.4): dt <= ', &
           sqrt(LAG_LIMIT * reynolds) * h, ' keeps it within ~3 %'
      call add_finding(findings, LIMIT_WARN, text)
    end if
  end function fictitious_domain_pair_lag_limit

  ! Spheres crossing more than ~0.02 cells per step lose stresslet: their Lambda lags the moving
  ! geometry (doc/VALIDATION.md §5.3). edge_speed: the shear velocity at the edge of the region
  ! measured (the core of &rheology); a warning beyond it (h: the cell size).
  function fictitious_domain_stresslet_lag_limit(edge_speed, dt, h) result(findings)
    real(dp), intent(in) :: edge_speed, dt, h
    type(limit_finding_t), allocatable :: findings(:)
    character(len=400) :: text
    allocate(findings(0))
    if (edge_speed * dt > 0.02_dp * h) then
      write(text, '(a,f6.3,a,es9.2,a)') 'spheres at the edge of the core cross ', edge_speed * dt / h, &
           ' cells per step, and their stresslets lag (doc/VALIDATION.md 5.3): dt <= ', &
           0.02_dp * h / edge_speed, ' keeps them within 1 %'
      call add_finding(findings, LIMIT_WARN, text)
    end if
  end function fictitious_domain_stresslet_lag_limit

  subroutine fictitious_domain_create(grid, reynolds, dt, kappa, radius_offset, fd, ierr)
    type(grid_t), intent(in) :: grid
    real(dp), intent(in) :: reynolds, dt, kappa, radius_offset
    type(fictitious_domain_t), intent(inout) :: fd
    PetscErrorCode, intent(out) :: ierr
    integer :: c
    character(len=8), parameter :: names(3) = ['lambda_u', 'lambda_v', 'lambda_w']
    fd%beta = reynolds / dt
    fd%kappa = kappa
    fd%radius_offset = radius_offset
    do c = 1, 3
      PetscCall(DMCreateGlobalVector(grid%da(c), fd%lambda(c), ierr))
      PetscCall(VecSet(fd%lambda(c), 0.0_dp, ierr))
      PetscCall(PetscObjectSetName(fd%lambda(c), trim(names(c)), ierr))
    end do
    PetscCall(grid_create_box_layout(grid, fd%carry_layout, ierr))
    PetscCall(particle_solver_create(fd%solver, ierr))
    allocate(fd%f_ijk(3, 1024), fd%f_r(3, 1024), fd%f_alpha(1024), fd%f_relax(1024))
    allocate(fd%run_start(1), fd%run_comp(0), fd%run_part(0))
  end subroutine fictitious_domain_create

  ! The geometry at the current positions: face ownership, alpha, the face list and M_p.
  ! Collective (M_p is summed over ranks).
  ! Each sphere visits the unknowns its control volumes can meet and computes alpha once. An
  ! unknown no rival can reach is its own outright. Where rivals reach (15 % of the faces of the
  ! paper scene), the sphere computes their alphas there itself, with the very arithmetic each
  ! rival's own visit uses (the same unwrapped index, the same expressions), so every sphere
  ! takes the same decision: the largest alpha owns the unknown (ties to the lower index) with
  ! weight alpha - the runner-up's. No grid-sized ownership arrays, no second pass (before 2026-11-26 the
  ! geometry was half of the paper scene's step).
  subroutine fictitious_domain_geometry(grid, fd, parts)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    type(particles_t), intent(in) :: parts
    integer :: q, c, ierr, f0
    real(dp) :: radius

    PetscCallA(event_begin(EVENT_GEOMETRY, ierr))
    radius = parts%radius + fd%radius_offset * grid%h
    fd%lambda_listed = .false.      ! Lambda^n may sit on faces of another geometry (fictitious_domain_follow carries it)
    call find_rivals(grid, fd, parts, radius)
    if (allocated(fd%rigid_matrix)) then
      if (size(fd%rigid_matrix, 3) /= parts%n) deallocate(fd%rigid_matrix)
    end if
    if (.not. allocated(fd%rigid_matrix)) allocate(fd%rigid_matrix(6, 6, parts%n))
    fd%rigid_matrix = 0.0_dp
    fd%nf = 0
    fd%nruns = 0
    if (size(fd%run_start) < 4 * parts%n + 1) then
      deallocate(fd%run_start, fd%run_comp, fd%run_part)
      allocate(fd%run_start(4 * parts%n + 1), fd%run_comp(4 * parts%n), fd%run_part(4 * parts%n))
    end if
    do q = 1, parts%n
      do c = 1, 4
        f0 = fd%nf + 1
        call visit(grid, fd, parts, q, c, radius)
        if (fd%nf >= f0) then
          fd%nruns = fd%nruns + 1
          fd%run_start(fd%nruns) = f0
          fd%run_comp(fd%nruns) = c
          fd%run_part(fd%nruns) = q
        end if
      end do
    end do
    fd%run_start(fd%nruns + 1) = fd%nf + 1
    call MPI_Allreduce(MPI_IN_PLACE, fd%rigid_matrix, 36 * parts%n, MPI_DOUBLE_PRECISION, MPI_SUM, &
                       PETSC_COMM_WORLD, ierr)
    PetscCallA(event_end(EVENT_GEOMETRY, ierr))
  end subroutine fictitious_domain_geometry

  ! The unknowns of component c (1..4, 4 = cell centres) that particle q owns, listed with their
  ! owned (wrapped) index, their offset r from the centre (unwrapped, so no image logic), their
  ! weight and relaxation; M_p of q accumulated (sum_f w g g^T dV over the non-zeros of g).
  subroutine visit(grid, fd, parts, q, c, radius)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    type(particles_t), intent(in) :: parts
    integer, intent(in) :: q, c
    real(dp), intent(in) :: radius
    ! indices per axis: at most 2R/h + 2 (the box below), with one to spare for round-off
    integer :: wrapped(ceiling(2.0_dp * radius / grid%h) + 3, 3)
    logical :: mine(ceiling(2.0_dp * radius / grid%h) + 3, 3)
    integer :: lo(3), hi(3), i, j, k, d, m, ilo, ihi, iw, jw, kw, f, nrow, idx(3), arm(2)
    real(dp) :: centre(3), r(3), a, h, reach2, inside2, rest2, chord, gamma_unit, rival2, second, rival_alpha
    real(dp) :: w, dv, sgn(2), block3(3, 3), sums6(6), v2, v3
    logical :: owned
    ! the rivals that reach the current row, and what is left of the reach there
    integer :: row_rival(max(1, fd%rival_start(q + 1) - fd%rival_start(q)))
    real(dp) :: row_rest2(max(1, fd%rival_start(q + 1) - fd%rival_start(q)))
    h = grid%h
    dv = h**3
    centre = parts%position(:, q)
    ! The control volume of unknown i spans (i + stagger +- 1/2) h, so only |(i + stagger) h - x_d|
    ! < R + h/2 can meet the sphere: the box below is that range, no wider (doc/BENCHMARKS.md §8: the loops are
    ! most of the geometry's cost). Each index is wrapped and tested for ownership once per axis.
    do d = 1, 3
      lo(d) = floor((centre(d) - radius) / h - stagger(d, c) - 0.5_dp)
      hi(d) = min(ceiling((centre(d) + radius) / h - stagger(d, c) + 0.5_dp), lo(d) + size(mine, 1) - 1)
      do m = 1, hi(d) - lo(d) + 1
        i = lo(d) + m - 1
        if (d == 2 .and. grid%walls) then
          wrapped(m, d) = i
          ! outside the walls there is no fluid; on the wall itself v = 0 stays (no constraint)
          mine(m, d) = i >= 0 .and. i < grid%n(2) .and. .not. (c == FIELD_V .and. i == 0)
        else
          wrapped(m, d) = modulo(i, grid%n(d))
          mine(m, d) = .true.
        end if
        mine(m, d) = mine(m, d) .and. wrapped(m, d) >= grid%lo(d) .and. wrapped(m, d) <= grid%hi(d)
      end do
    end do
    ! beyond this distance from the centre a control volume lies wholly outside (its half-diagonal)
    reach2 = (radius + 0.5_dp * sqrt(3.0_dp) * h)**2
    ! within this distance it lies wholly inside (alpha = 1)
    inside2 = -1.0_dp
    if (radius > 0.5_dp * sqrt(3.0_dp) * h) inside2 = (radius - 0.5_dp * sqrt(3.0_dp) * h)**2
    ! room for every unknown of the box, once, so that the loop below stores without checks
    call reserve_faces(fd, fd%nf + product(hi - lo + 1))
    ! gamma = kappa (1 - alpha) beta h^2 / eta (relaxation_gamma, doc/METHOD.md §3.3), written out
    gamma_unit = 0.0_dp
    sums6 = 0.0_dp
    if (c /= FIELD_P) then
      gamma_unit = fd%kappa * fd%beta * h**2 / fd%eta
      call torque_arm(c, idx, arm, sgn)
    end if
    do k = lo(3), hi(3)
      if (.not. mine(k - lo(3) + 1, 3)) cycle
      kw = wrapped(k - lo(3) + 1, 3)
      r(3) = (k + stagger(3, c)) * h - centre(3)
      do j = lo(2), hi(2)
        if (.not. mine(j - lo(2) + 1, 2)) cycle
        jw = wrapped(j - lo(2) + 1, 2)
        r(2) = (j + stagger(2, c)) * h - centre(2)
        rest2 = reach2 - r(2)**2 - r(3)**2
        if (rest2 <= 0.0_dp) cycle
        ! the row's chord, widened by a cell for round-off; the test below decides
        chord = sqrt(rest2)
        ilo = max(lo(1), floor((centre(1) - chord) / h - stagger(1, c)) - 1)
        ihi = min(hi(1), ceiling((centre(1) + chord) / h - stagger(1, c)) + 1)
        ! the rivals whose reach meets this row at all: only they can contest its unknowns (a
        ! margin of 1e-12 keeps the test on the safe side of round-off: contested if in doubt)
        nrow = 0
        do m = fd%rival_start(q), fd%rival_start(q + 1) - 1
          rival2 = (r(2) - fd%rival_offset(2, m))**2 + (r(3) - fd%rival_offset(3, m))**2
          if (rival2 >= reach2 * (1.0_dp + 1.0e-12_dp)) cycle
          nrow = nrow + 1
          row_rival(nrow) = m
          row_rest2(nrow) = reach2 * (1.0_dp + 1.0e-12_dp) - rival2
        end do
        do i = ilo, ihi
          if (.not. mine(i - lo(1) + 1, 1)) cycle
          r(1) = (i + stagger(1, c)) * h - centre(1)
          a = alpha_at(r)
          if (a <= 0.0_dp) cycle
          iw = wrapped(i - lo(1) + 1, 1)
          ! the rivals that reach this unknown: the largest alpha owns it, the runner-up's is taken off
          second = 0.0_dp
          owned = .true.
          do m = 1, nrow
            if ((r(1) - fd%rival_offset(1, row_rival(m)))**2 >= row_rest2(m)) cycle
            rival_alpha = alpha_of_rival(fd%rival_part(row_rival(m)), [iw, jw, kw])
            if (rival_alpha > a .or. (rival_alpha == a .and. fd%rival_part(row_rival(m)) < q)) then
              owned = .false.
              exit
            end if
            second = max(second, rival_alpha)
          end do
          if (.not. owned) cycle
          a = a - second
          if (a <= 0.0_dp) cycle
          f = fd%nf + 1
          fd%nf = f
          fd%f_ijk(:, f) = [iw, jw, kw]
          fd%f_r(:, f) = r
          fd%f_alpha(f) = a
          if (a == 1.0_dp) then
            fd%f_relax(f) = 1.0_dp       ! a covered face does not relax (gamma = 0)
          else
            fd%f_relax(f) = 1.0_dp / (1.0_dp + gamma_unit * (1.0_dp - a))
          end if
          if (c == FIELD_P) cycle
          ! w g g^T on the non-zeros (1, v2, v3) of g: six distinct sums
          v2 = sgn(1) * r(arm(1))
          v3 = sgn(2) * r(arm(2))
          w = fd%f_alpha(f) * fd%f_relax(f) * dv
          sums6 = sums6 + [w, w * v2, w * v3, w * v2 * v2, w * v2 * v3, w * v3 * v3]
        end do
      end do
    end do
    ! M_p gains w g g^T on the three non-zeros of g
    if (c /= FIELD_P) then
      block3 = reshape([sums6(1), sums6(2), sums6(3), sums6(2), sums6(4), sums6(5), sums6(3), sums6(5), sums6(6)], &
                       [3, 3])
      fd%rigid_matrix(idx, idx, q) = fd%rigid_matrix(idx, idx, q) + block3
    end if
  contains
    ! The cover of the control volume at offset x from a centre (0 beyond the reach).
    real(dp) function alpha_at(x)
      real(dp), intent(in) :: x(3)
      real(dp) :: d2
      d2 = x(1)**2 + x(2)**2 + x(3)**2
      if (d2 >= reach2) then
        alpha_at = 0.0_dp
      else if (d2 <= inside2) then
        alpha_at = 1.0_dp      ! the whole control volume is inside (cube_fraction's first test)
      else
        alpha_at = cube_fraction(x, radius, h)
      end if
    end function alpha_at

    ! Rival p's alpha of the unknown with wrapped index ijk, computed as p's own visit does: from
    ! the image of the unknown nearest to p's centre (the one p's box holds).
    real(dp) function alpha_of_rival(p, ijk)
      integer, intent(in) :: p, ijk(3)
      integer :: d, unwrapped
      real(dp) :: x(3)
      do d = 1, 3
        unwrapped = ijk(d)
        if (.not. (d == 2 .and. grid%walls)) unwrapped = ijk(d) + grid%n(d) * &
             nint((parts%position(d, p) - (ijk(d) + stagger(d, c)) * h) / grid%box(d))
        x(d) = (unwrapped + stagger(d, c)) * h - parts%position(d, p)
      end do
      alpha_of_rival = alpha_at(x)
    end function alpha_of_rival
  end subroutine visit

  ! Room for n faces in the face list (its arrays grow by doubling, kept between steps).
  subroutine reserve_faces(fd, n)
    type(fictitious_domain_t), intent(inout) :: fd
    integer, intent(in) :: n
    integer :: m
    integer, allocatable :: t3(:, :)
    real(dp), allocatable :: tr(:), tr3(:, :)
    if (n <= size(fd%f_alpha)) return
    m = max(n, 2 * size(fd%f_alpha))
    allocate(t3(3, m)); t3(:, 1:fd%nf) = fd%f_ijk(:, 1:fd%nf); call move_alloc(t3, fd%f_ijk)
    allocate(tr3(3, m)); tr3(:, 1:fd%nf) = fd%f_r(:, 1:fd%nf); call move_alloc(tr3, fd%f_r)
    allocate(tr(m)); tr(1:fd%nf) = fd%f_alpha(1:fd%nf); call move_alloc(tr, fd%f_alpha)
    allocate(tr(m)); tr(1:fd%nf) = fd%f_relax(1:fd%nf); call move_alloc(tr, fd%f_relax)
  end subroutine reserve_faces

  ! The rivals of each sphere: the spheres whose centres are closer than twice the reach
  ! R + sqrt(3) h/2, so that some control volume may meet both (mod_neighbours' cell lists, with a
  ! skin of one cell; every pair when a periodic length is below twice the list's cut-off).
  ! A periodic length below twice the reach would let a sphere reach its own image: refused.
  subroutine find_rivals(grid, fd, parts, radius)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    type(particles_t), intent(in) :: parts
    real(dp), intent(in) :: radius
    real(dp) :: reach
    integer :: info, l, i, j, n, pass
    logical :: periodic(3)
    integer, allocatable :: count(:)
    character(len=200) :: text

    n = parts%n
    reach = radius + 0.5_dp * sqrt(3.0_dp) * grid%h
    periodic = [.true., .not. grid%walls, .true.]
    if (.not. allocated(fd%rival_start)) then
      if (any(periodic .and. grid%box < 2.0_dp * reach)) then
        write(text, '(a,f8.4,a)') 'fdsusp: error: &domain box: every periodic length must be at least ', &
             2.0_dp * reach, ' a (twice a sphere''s reach on the grid), or a sphere meets its own image'
        call fatal_error(text, 2)
      end if
      call nlist_init(fd%reach_list, n, grid%box, periodic, 2.0_dp * reach + grid%h, reach + grid%h, grid%h, info)
      fd%use_reach_list = (info == 0)
      allocate(fd%rival_start(n + 1), fd%rival_part(64), fd%rival_offset(3, 64))
    end if
    if (fd%use_reach_list .and. n > 1) then
      call nlist_candidates(fd%reach_list, parts%position, fd%reach_pairs, fd%nreach_pairs, fd%reach_walls, &
                            fd%nreach_walls)
    else if (.not. allocated(fd%reach_pairs)) then
      ! every pair, in the same canonical order (the list never changes: made once)
      fd%nreach_pairs = n * (n - 1) / 2
      allocate(fd%reach_pairs(2, max(1, fd%nreach_pairs)))
      l = 0
      do i = 1, n - 1
        do j = i + 1, n
          l = l + 1
          fd%reach_pairs(:, l) = [i, j]
        end do
      end do
    end if
    ! count, then fill (each close pair is a rival of both its spheres)
    allocate(count(n))
    do pass = 1, 2
      count = 0
      do l = 1, fd%nreach_pairs
        i = fd%reach_pairs(1, l)
        j = fd%reach_pairs(2, l)
        call add_pair(i, j, pass)
      end do
      if (pass == 1) then
        fd%rival_start(1) = 1
        do i = 1, n
          fd%rival_start(i + 1) = fd%rival_start(i) + count(i)
        end do
        if (size(fd%rival_part) < fd%rival_start(n + 1)) then
          deallocate(fd%rival_part, fd%rival_offset)
          allocate(fd%rival_part(2 * fd%rival_start(n + 1)), fd%rival_offset(3, 2 * fd%rival_start(n + 1)))
        end if
      end if
    end do
  contains
    subroutine add_pair(i, j, pass)
      integer, intent(in) :: i, j, pass
      real(dp) :: d(3)
      d = min_image(parts%position(:, j) - parts%position(:, i), grid%box, periodic)
      if (sum(d**2) >= (2.0_dp * reach)**2) return
      if (pass == 2) then
        fd%rival_part(fd%rival_start(i) + count(i)) = j
        fd%rival_offset(:, fd%rival_start(i) + count(i)) = d
        fd%rival_part(fd%rival_start(j) + count(j)) = i
        fd%rival_offset(:, fd%rival_start(j) + count(j)) = -d
      end if
      count(i) = count(i) + 1
      count(j) = count(j) + 1
    end subroutine add_pair
  end subroutine find_rivals

  ! The geometry at the new positions, and Lambda carried with the spheres that moved (doc/METHOD.md §3.6,
  ! doc/VALIDATION.md §5.3). Lambda is incremental: each step only corrects it, so left on the
  ! faces of X^n it lags a sphere that has moved on to X^{n+1}; the leading faces start from zero
  ! and relax over several steps, and a sphere crossing 0.08 cells per step loses 14 % of its
  ! stresslet. Carried, each face the sphere now owns takes the old Lambda at the same place
  ! relative to the centre, x_f - dX, interpolated trilinearly on its own staggered grid; faces no
  ! sphere owns get zero. Only the translation is carried: the traction on a sphere that turns in
  ! a steady flow is steady in the lab frame, not in the body's. displacement (3, n): X^{n+1} - X^n,
  ! unwrapped; each component must stay below one cell (the ghost width). The eight corners of a
  ! face next to an edge or corner of this rank's block lie in edge or corner ghosts: Lambda^n is
  ! exchanged on fd%carry_layout (box stencil), which fills them (doc/DESIGN.md "Ghost layers").
  ! Collective.
  subroutine fictitious_domain_follow(grid, fd, parts, displacement, ierr)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    type(particles_t), intent(in) :: parts
    real(dp), intent(in) :: displacement(:, :)
    PetscErrorCode, intent(out) :: ierr
    Vec :: old(3)
    type(field_pointer) :: lam_old(3), lam(3)
    real(dp) :: t(3), w(3), weight(8)
    integer :: run, f0, f1, c, q, o(3), a, b, e, m, corner(3, 8)
    character(len=200) :: text

    call fictitious_domain_geometry(grid, fd, parts)
    if (maxval(abs(displacement)) >= grid%h) then
      write(text, '(a,f8.3,a)') 'fdsusp: fatal: a sphere moved ', maxval(abs(displacement)) / grid%h, &
           ' cells in one step (its force density can follow at most one): reduce &time dt'
      call fatal_error(text, 3)
    end if
    PetscCall(event_begin(EVENT_CARRY, ierr))
    do c = 1, 3
      PetscCall(DMGetLocalVector(fd%carry_layout, old(c), ierr))
      PetscCall(DMGlobalToLocalBegin(fd%carry_layout, fd%lambda(c), INSERT_VALUES, old(c), ierr))
      PetscCall(DMGlobalToLocalEnd(fd%carry_layout, fd%lambda(c), INSERT_VALUES, old(c), ierr))
      PetscCall(VecSet(fd%lambda(c), 0.0_dp, ierr))
      PetscCall(DMDAVecGetArrayReadF90(fd%carry_layout, old(c), lam_old(c)%ptr, ierr))
      PetscCall(DMDAVecGetArrayF90(grid%da(c), fd%lambda(c), lam(c)%ptr, ierr))
    end do
    ! The list comes in runs of one sphere and one component: the eight corner offsets and
    ! weights are set once per run, and each run is carried by a kernel on plain arrays.
    do run = 1, fd%nruns
      f0 = fd%run_start(run)
      f1 = fd%run_start(run + 1) - 1
      c = fd%run_comp(run)
      q = fd%run_part(run)
      if (c /= FIELD_P) then
        ! x_f - dX in cells from the face itself: offsets o and o + 1 in {-1, 0, 1}, weights w of o + 1
        t = -displacement(:, q) / grid%h
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
        call carry_run(lam_old(c)%ptr, lam(c)%ptr, grid%glo, grid%ghi, grid%lo, grid%hi, f1 - f0 + 1, &
                       fd%f_ijk(:, f0:f1), corner, weight, any(displacement(:, q) /= 0.0_dp), &
                       grid%walls, grid%n(2))
      end if
    end do
    fd%lambda_listed = .true.
    do c = 1, 3
      PetscCall(DMDAVecRestoreArrayF90(grid%da(c), fd%lambda(c), lam(c)%ptr, ierr))
      PetscCall(DMDAVecRestoreArrayReadF90(fd%carry_layout, old(c), lam_old(c)%ptr, ierr))
      PetscCall(DMRestoreLocalVector(fd%carry_layout, old(c), ierr))
    end do
    PetscCall(event_end(EVENT_CARRY, ierr))
  end subroutine fictitious_domain_follow

  ! The particle sub-problem after the fluid step, in three named parts that main.F90 calls in
  ! turn (doc/METHOD.md §3.2 eq. (1), §3.3, §3.5):
  !   fictitious_domain_moments       b(u~) and m(Lambda^n) of every sphere, summed over ranks;
  !   fictitious_domain_solve_motion  the 6N system (rigid-body matrices, lubrication, contacts): U, Omega;
  !   fictitious_domain_update        Lambda^{n+1}, u^{n+1} = u~ + (Lambda^{n+1} - Lambda^n)/beta, and the
  !                    resolved force, torque and stresslet (plus the lubrication corrections).

  ! b = sum_f w u~_c g dV and m = sum_f Lambda^n_f/(1+gamma) g dV per sphere (rows 1-6, 7-12 of
  ! fd%moments). vel: the projected velocity u~. Collective.
  subroutine fictitious_domain_moments(grid, fd, vel, n, ierr)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    Vec, intent(in) :: vel(3)
    integer, intent(in) :: n
    PetscErrorCode, intent(out) :: ierr
    type(field_pointer) :: u(3), lam(3)
    real(dp) :: dv
    integer :: run, f0, f1, c, q

    PetscCall(event_begin(EVENT_MOMENTS, ierr))
    dv = grid%h**3
    if (allocated(fd%moments)) then
      if (size(fd%moments, 2) /= n) deallocate(fd%moments)
    end if
    if (.not. allocated(fd%moments)) allocate(fd%moments(12, n))
    fd%moments = 0.0_dp
    do c = 1, 3
      PetscCall(DMDAVecGetArrayReadF90(grid%da(c), vel(c), u(c)%ptr, ierr))
      PetscCall(DMDAVecGetArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%ptr, ierr))
    end do
    do run = 1, fd%nruns
      f0 = fd%run_start(run)
      f1 = fd%run_start(run + 1) - 1
      c = fd%run_comp(run)
      q = fd%run_part(run)
      if (c /= FIELD_P) call moments_run(c, u(c)%ptr, lam(c)%ptr, grid%lo, grid%hi, f1 - f0 + 1, fd%f_ijk(:, f0:f1), &
                                         fd%f_r(:, f0:f1), fd%f_alpha(f0:f1), fd%f_relax(f0:f1), dv, fd%moments(:, q))
    end do
    do c = 1, 3
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%ptr, ierr))
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), vel(c), u(c)%ptr, ierr))
    end do
    call MPI_Allreduce(MPI_IN_PLACE, fd%moments, 12 * n, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr)
    PetscCall(event_end(EVENT_MOMENTS, ierr))
  end subroutine fictitious_domain_moments

  ! The velocities of the spheres: beta M U = beta b(u~) - m(Lambda^n) + F_ext (doc/METHOD.md eq. (1)
  ! with the weights), for free motion; prescribed, resistance and fixed motions set them.
  ! extra_force, extra_torque (3, n), optional: further given forces on the particles, added to
  ! the right-hand side next to external_force/external_torque (free and frozen motion).
  ! lubrication, optional: the links of this configuration (mod_particle_lubrication); their
  ! resistance enters the 6N system implicitly. contacts, optional: the contacts of this step
  ! (particle_contacts_step at X^n): their forces and torques join the right-hand side (free and frozen
  ! motion) and, for free motion with implicit contacts, their linearised stiffness the 6N system;
  ! after the solve their force, torque and stresslet are those the balance used
  ! (mod_particle_contacts). Identical on every rank (replicated data).
  subroutine fictitious_domain_solve_motion(fd, parts, ierr, extra_force, extra_torque, lubrication, contacts)
    type(fictitious_domain_t), intent(inout) :: fd
    type(particles_t), intent(inout) :: parts
    PetscErrorCode, intent(out) :: ierr
    real(dp), intent(in), optional :: extra_force(:, :), extra_torque(:, :)
    type(particle_lubrication_t), intent(in), optional :: lubrication
    type(particle_contacts_t), intent(inout), optional :: contacts
    real(dp), allocatable :: rhs(:, :)
    integer :: q, n

    PetscCall(event_begin(EVENT_MOTION, ierr))
    n = parts%n
    select case (parts%motion)
    case (MOTION_FREE, MOTION_FROZEN)
      allocate(rhs(6, n))
      call particle_system_reset(fd%solver%system, n)
      do q = 1, n
        call particle_system_add_diagonal(fd%solver%system, q, fd%beta * fd%rigid_matrix(:, :, q))
        rhs(:, q) = fd%beta * fd%moments(1:6, q) - fd%moments(7:12, q) &
             + [parts%external_force(:, q), parts%external_torque(:, q)]
        if (present(extra_force)) rhs(1:3, q) = rhs(1:3, q) + extra_force(:, q)
        if (present(extra_torque)) rhs(4:6, q) = rhs(4:6, q) + extra_torque(:, q)
        if (present(contacts)) rhs(:, q) = rhs(:, q) + [contacts%force(:, q), contacts%torque(:, q)]
      end do
      if (present(lubrication)) call particle_lubrication_add_to_system(lubrication, fd%solver%system, rhs)
      if (present(contacts) .and. parts%motion == MOTION_FREE) &
        call particle_contacts_add_stiffness(contacts, fd%solver%system, rhs, parts%velocity, parts%omega, parts%have_prev)
      call particle_solver_solve(fd%solver, rhs, parts, ierr, ': a particle covers no grid face?')
      CHKERRQ(ierr)
      if (present(contacts)) call particle_contacts_implicit_update(contacts, parts%velocity, parts%omega)
    case default                    ! prescribed, resistance, fixed
      call impose_motion(parts)
    end select
    PetscCall(event_end(EVENT_MOTION, ierr))
  end subroutine fictitious_domain_solve_motion

  ! Lambda^{n+1} = [Lambda^n + beta alpha (g.U - u~)]/(1 + gamma) on owned faces, 0 elsewhere;
  ! u^{n+1} = u~ + (Lambda^{n+1} - Lambda^n)/beta; the moments F = -sum Lambda e_c dV,
  ! T = -sum r x Lambda e_c dV, S = -1/2 sum Lambda (r e_c + e_c r) dV - (sum_cells alpha p dV) I
  ! (doc/METHOD.md §3.7). vel: u~ on entry, u^{n+1} on exit. lubrication, optional: its corrections are added to
  ! the resolved force, torque and stresslet, which then hold the total hydrodynamics. Collective.
  subroutine fictitious_domain_update(grid, fd, vel, pressure, parts, ierr, lubrication)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    Vec, intent(inout) :: vel(3)
    Vec, intent(in) :: pressure
    type(particles_t), intent(inout) :: parts
    PetscErrorCode, intent(out) :: ierr
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    real(dp), allocatable :: sums(:, :)
    type(field_pointer) :: u(3), lam(3)
    PetscScalar, pointer :: p(:,:,:)
    real(dp) :: dv, integral
    integer :: run, f0, f1, c, q, n
    logical :: removed

    PetscCall(event_begin(EVENT_UPDATE, ierr))
    n = parts%n
    dv = grid%h**3
    allocate(sums(16, n))
    sums = 0.0_dp
    ! Lambda^n is non-zero only on the listed faces once fictitious_domain_follow has carried it there; then
    ! removing it and adding Lambda^{n+1} is one pass over the list. Otherwise (the first step
    ! of a run, -fd_carry_lambda 0) Lambda^{n+1} is computed first and Lambda^n removed from the
    ! whole grid, as the formula says; both give the same numbers where both apply.
    removed = .not. fd%lambda_listed
    if (removed) then
      if (allocated(fd%lambda_new)) then
        if (size(fd%lambda_new) < fd%nf) deallocate(fd%lambda_new)
      end if
      if (.not. allocated(fd%lambda_new)) allocate(fd%lambda_new(size(fd%f_alpha)))
      do c = 1, 3
        PetscCall(DMDAVecGetArrayReadF90(grid%da(c), vel(c), u(c)%ptr, ierr))
        PetscCall(DMDAVecGetArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%ptr, ierr))
      end do
      do run = 1, fd%nruns
        f0 = fd%run_start(run)
        f1 = fd%run_start(run + 1) - 1
        c = fd%run_comp(run)
        q = fd%run_part(run)
        if (c /= FIELD_P) call new_lambda_run(c, u(c)%ptr, lam(c)%ptr, grid%lo, grid%hi, f1 - f0 + 1, &
             fd%f_ijk(:, f0:f1), fd%f_r(:, f0:f1), fd%f_alpha(f0:f1), fd%f_relax(f0:f1), fd%beta, &
             parts%velocity(:, q), parts%omega(:, q), fd%lambda_new(f0:f1))
      end do
      do c = 1, 3
        PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%ptr, ierr))
        PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), vel(c), u(c)%ptr, ierr))
        PetscCall(VecAXPY(vel(c), -1.0_dp / fd%beta, fd%lambda(c), ierr))
        PetscCall(VecSet(fd%lambda(c), 0.0_dp, ierr))
      end do
    end if
    do c = 1, 3
      PetscCall(DMDAVecGetArrayF90(grid%da(c), vel(c), u(c)%ptr, ierr))
      PetscCall(DMDAVecGetArrayF90(grid%da(c), fd%lambda(c), lam(c)%ptr, ierr))
    end do
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_P), pressure, p, ierr))
    do run = 1, fd%nruns
      f0 = fd%run_start(run)
      f1 = fd%run_start(run + 1) - 1
      c = fd%run_comp(run)
      q = fd%run_part(run)
      if (c == FIELD_P) then
        ! the interior pressure of doc/METHOD.md §3.7
        call pressure_run(p, grid%lo, grid%hi, f1 - f0 + 1, fd%f_ijk(:, f0:f1), fd%f_alpha(f0:f1), dv, sums(16, q))
      else if (removed) then
        call update_run(c, u(c)%ptr, lam(c)%ptr, grid%lo, grid%hi, f1 - f0 + 1, fd%f_ijk(:, f0:f1), &
             fd%f_r(:, f0:f1), fd%f_alpha(f0:f1), fd%f_relax(f0:f1), fd%beta, dv, parts%velocity(:, q), &
             parts%omega(:, q), sums(:, q), fd%lambda_new(f0:f1))
      else
        call update_run(c, u(c)%ptr, lam(c)%ptr, grid%lo, grid%hi, f1 - f0 + 1, fd%f_ijk(:, f0:f1), &
             fd%f_r(:, f0:f1), fd%f_alpha(f0:f1), fd%f_relax(f0:f1), fd%beta, dv, parts%velocity(:, q), &
             parts%omega(:, q), sums(:, q))
      end if
    end do
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_P), pressure, p, ierr))
    do c = 1, 3
      PetscCall(DMDAVecRestoreArrayF90(grid%da(c), fd%lambda(c), lam(c)%ptr, ierr))
      PetscCall(DMDAVecRestoreArrayF90(grid%da(c), vel(c), u(c)%ptr, ierr))
    end do
    call MPI_Allreduce(MPI_IN_PLACE, sums, 16 * n, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr)
    if (present(lubrication)) call particle_lubrication_corrections(lubrication, parts%velocity, parts%omega)
    do q = 1, n
      parts%force_hydro(:, q) = sums(1:3, q)
      parts%torque_hydro(:, q) = sums(4:6, q)
      integral = sums(16, q)
      parts%stresslet_hydro(:, :, q) = reshape(sums(7:15, q), [3, 3])
      do c = 1, 3
        parts%stresslet_hydro(c, c, q) = parts%stresslet_hydro(c, c, q) - integral
      end do
    end do
    if (present(lubrication)) &
      call particle_lubrication_add_corrections(lubrication, parts%force_hydro, parts%torque_hydro, parts%stresslet_hydro)
    PetscCall(event_end(EVENT_UPDATE, ierr))
  end subroutine fictitious_domain_update


  ! The kernels below take one run (one sphere, one velocity component c) on plain arrays with the
  ! bounds of the rank's part of the grid, so that the compiler sees fixed strides (doc/DESIGN.md "Fictitious domain", Face runs).
  ! g = (e_c, r x e_c) enters through its three non-zeros: 1 at idx(1), sgn(1) r(k(1)) at idx(2)
  ! and sgn(2) r(k(2)) at idx(3) (torque_arm, once per run).

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

  ! Lambda carried by the displacement: trilinear from the eight corners of x_f - dX (fictitious_domain_follow).
  subroutine carry_run(old, new, glo, ghi, lo, hi, nfaces, ijk, corner, weight, moved, walls, ny)
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
    ! corner m = 1..8 is (o1 + a, o2 + b, o3 + e), a fastest (fictitious_domain_follow)
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

  ! moments(1:6) += sum w u~_c g dV, moments(7:12) += sum Lambda^n/(1+gamma) g dV (fictitious_domain_moments).
  subroutine moments_run(c, u, lam, lo, hi, nfaces, ijk, r, alpha, relax, dv, moments)
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

  ! Lambda^{n+1} = [Lambda^n + beta alpha (g.U - u~)]/(1 + gamma) of each face of the run.
  subroutine new_lambda_run(c, u, lam, lo, hi, nfaces, ijk, r, alpha, relax, beta, velocity, omega, lambda_new)
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

  ! One run of fictitious_domain_update: Lambda^{n+1} (from lambda_new when given, the grid then already free
  ! of Lambda^n), u^{n+1} = u~ - Lambda^n/beta + Lambda^{n+1}/beta, and the run's force, torque
  ! and stresslet added to sums(1:15) (the 3x3 block stored by columns in 7:15).
  subroutine update_run(c, u, lam, lo, hi, nfaces, ijk, r, alpha, relax, beta, dv, velocity, omega, sums, lambda_new)
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
  subroutine pressure_run(p, lo, hi, nfaces, ijk, alpha, dv, integral)
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


  subroutine fictitious_domain_destroy(fd, ierr)
    type(fictitious_domain_t), intent(inout) :: fd
    PetscErrorCode, intent(out) :: ierr
    integer :: c
    do c = 1, 3
      PetscCall(VecDestroy(fd%lambda(c), ierr))
    end do
    PetscCall(DMDestroy(fd%carry_layout, ierr))
    PetscCall(particle_solver_destroy(fd%solver, ierr))
  end subroutine fictitious_domain_destroy

end module mod_fictitious_domain
