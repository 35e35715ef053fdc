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
! Each rank works on the faces it owns. The spheres are replicated and the moments summed over
! the ranks, or (halo, optional in each routine: the resolved step on the ranks' local sets,
! mod_ld_local) the spheres are a rank's own spheres and their ghosts, whose faces may lie on its
! grid, and each sphere's partial moments are added into its owner's (mod_sphere_halo's reverse
! exchange; nothing of size N is sent), which alone sets its block row and solves for its motion.
! Either way spheres cross processor boundaries freely and the result does not depend on the
! decomposition beyond round-off.
! Lees-Edwards (doc/METHOD.md §3.9): the grid is not wrapped in y; a sphere that reaches across
! y = 0 or Ly is visited once more as its image in the box, at x -+ delta, y -+ Ly, moving faster
! by -+ gamma_dot Ly in x. Each entry of the geometry is a sphere or an image of one (owner, copy);
! an image's M_p, moments, force, torque and stresslet (about its own centre) are its owner's, its
! faces' rigid velocity is the owner's plus its copy times gamma_dot Ly e_x, which the moments
! take off ũ (b - copy gamma_dot Ly M_p e_1).
#include <petsc/finclude/petscdmda.h>
#include <petsc/finclude/petscksp.h>
module mod_fictitious_domain
  use petscdmda
  use petscksp
  use mod_kinds, only: dp
  use mod_grid, only: grid_t, grid_create_box_layout, FIELD_P
  use mod_particles, only: particles_t, MOTION_FREE, MOTION_FROZEN, impose_motion
  use mod_particle_system, only: particle_system_t, particle_system_reset, particle_system_add_diagonal
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_add_to_system, &
                                      particle_lubrication_add_corrections, particle_lubrication_corrections
  use mod_sphere_halo, only: sphere_halo_t, sphere_halo_reverse
  use mod_ld_local, only: ld_local_contacts_update, ld_local_forward_motion
  use mod_lubrication_links, only: lubrication_links_corrections
  use mod_particle_contacts, only: particle_contacts_t, particle_contacts_add_stiffness, &
                                   particle_contacts_implicit_update, particle_contacts_set_rate
  use mod_particle_solver, only: particle_solver_t, particle_solver_create, particle_solver_solve, &
                                 particle_solver_destroy
  use mod_sphere_faces, only: mac_block_t, face_list_t, field_view_t, faces_build, faces_carry, faces_moments, &
                              faces_new_lambda, faces_update, face_run, run_offsets, new_lambda_run
  use mod_neighbours, only: nlist_t, nlist_init, nlist_candidates, min_image
  use mod_lees_edwards, only: lees_edwards_t, le_separation
  use mod_sliding_boundary, only: sliding_shift_rows
  use mod_errors, only: fatal_error
  use mod_limits, only: limit_finding_t, add_finding, LIMIT_WARN
  use mod_timers, only: event_begin, event_end, EVENT_GEOMETRY, EVENT_CARRY, EVENT_MOMENTS, EVENT_MOTION, &
                        EVENT_UPDATE
  implicit none
  private
  public :: fictitious_domain_t, fictitious_domain_create, fictitious_domain_geometry, &
            fictitious_domain_follow, fictitious_domain_moments, fictitious_domain_solve_motion, &
            fictitious_domain_update, fictitious_domain_destroy, fictitious_domain_response_moments, &
            fictitious_domain_solve_stress, fictitious_domain_set_image_speed, &
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
    ! the covered faces and cells of this rank, in runs of one sphere and one component (mod_sphere_faces)
    type(face_list_t) :: faces
    real(dp), allocatable :: rigid_matrix(:, :, :)               ! M_p (6, 6, n), summed over ranks
    real(dp), allocatable :: inflated_radius(:)                  ! (n) a_q + radius_offset h (§3.3)
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
    ! stress control (doc/METHOD.md §7.4): (6, n) b of the fluid step's response to a unit wall
    ! speed (fictitious_domain_response_moments)
    real(dp), allocatable :: response_moments(:, :)
    type(particle_solver_t) :: solver     ! the 6N system of the particle step and its solution
    ! Lees-Edwards (see the top): the boundary at the last geometry, the images' extra speed
    ! gamma_dot Ly of the step, and the entries: sphere owner(e) itself (copy 0, entries 1..n in
    ! order) or its image above (copy +1) or below (copy -1), at entry_position with entry_radius
    logical :: sliding = .false.
    type(lees_edwards_t) :: le
    real(dp) :: image_speed = 0.0_dp
    integer :: entries = 0
    integer, allocatable :: owner(:), copy(:)
    real(dp), allocatable :: entry_position(:, :), entry_radius(:)
    real(dp), allocatable :: rigid_entries(:, :, :)   ! (6, 6, entries): M_p of each entry, summed over ranks
    real(dp), allocatable :: previous_position(:, :)  ! (3, n) the spheres at the last geometry...
    real(dp) :: previous_offset = 0.0_dp              ! ... and the boundary's offset then
  end type fictitious_domain_t

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
  end subroutine fictitious_domain_create

  ! The geometry at the current positions: face ownership, alpha, the face list and M_p.
  ! Collective (M_p is summed over ranks).
  ! Each sphere visits the unknowns of this rank's block its control volumes can meet and
  ! computes alpha once (mod_sphere_faces' faces_build). Where rivals reach (15 % of the faces of
  ! the paper scene), the sphere computes their alphas there itself, so every sphere takes the same
  ! decision without grid-sized ownership arrays or a second pass (before 2026-11-26 the geometry
  ! was half of the paper scene's step).
  ! le, optional: a Lees-Edwards boundary (le%active), its offset now. halo, optional: parts is a
  ! rank's local set, M_p summed on each sphere's owner (see the top); set_made, optional: the
  ! local set was made anew since the last geometry (its indices are other spheres').
  subroutine fictitious_domain_geometry(grid, fd, parts, le, halo, set_made)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    type(particles_t), intent(in) :: parts
    type(lees_edwards_t), intent(in), optional :: le
    type(sphere_halo_t), intent(inout), optional :: halo
    logical, intent(in), optional :: set_made
    integer :: ierr, e
    logical :: new_set
    real(dp) :: h
    type(mac_block_t) :: block

    PetscCallA(event_begin(EVENT_GEOMETRY, ierr))
    ! the spheres are another set than the last geometry's (a local set made anew: the rivals'
    ! neighbour list starts afresh)
    new_set = .false.
    if (present(set_made)) new_set = set_made
    ! each sphere inflated by the same offset in cells (§3.3): the offset is the grid's, not the sphere's
    if (allocated(fd%inflated_radius)) then
      if (size(fd%inflated_radius) /= parts%n) deallocate(fd%inflated_radius)
    end if
    if (.not. allocated(fd%inflated_radius)) allocate(fd%inflated_radius(parts%n))
    fd%inflated_radius = parts%radii + fd%radius_offset * grid%h
    fd%lambda_listed = .false.      ! Lambda^n may sit on faces of another geometry (fictitious_domain_follow carries it)
    if (allocated(fd%rigid_matrix)) then
      if (size(fd%rigid_matrix, 3) /= parts%n) deallocate(fd%rigid_matrix)
    end if
    if (.not. allocated(fd%rigid_matrix)) allocate(fd%rigid_matrix(6, 6, parts%n))
    fd%rigid_matrix = 0.0_dp
    h = grid%h
    ! the unit of gamma = kappa (1 - alpha) beta h^2 / eta (doc/METHOD.md §3.3)
    if (present(le)) fd%sliding = le%active
    if (fd%sliding) then
      ! the spheres and their images in the box (see the top)
      fd%le = le
      call make_entries(grid, fd, parts)
      call find_rivals(grid, fd, fd%entry_position, fd%entry_radius, .true.)
      if (allocated(fd%rigid_entries)) deallocate(fd%rigid_entries)
      allocate(fd%rigid_entries(6, 6, fd%entries))
      fd%rigid_entries = 0.0_dp
      block = mac_block_t(h=h, box=grid%box, n=grid%n, walls=.false., sliding=.true., lo=grid%lo, hi=grid%hi)
      call faces_build(block, fd%entry_position, fd%entry_radius, fd%kappa * fd%beta * h**2 / fd%eta, &
                       fd%rival_start, fd%rival_part, fd%rival_offset, fd%faces, fd%rigid_entries)
      if (present(halo)) then
        ! (the entries' matrices stay this rank's parts: the moments use them linearly)
        do e = 1, fd%entries
          fd%rigid_matrix(:, :, fd%owner(e)) = fd%rigid_matrix(:, :, fd%owner(e)) + fd%rigid_entries(:, :, e)
        end do
        call owners_sum_matrices(fd%rigid_matrix, halo, ierr)
      else
        call MPI_Allreduce(MPI_IN_PLACE, fd%rigid_entries, 36 * fd%entries, MPI_DOUBLE_PRECISION, MPI_SUM, &
                           PETSC_COMM_WORLD, ierr)
        do e = 1, fd%entries
          fd%rigid_matrix(:, :, fd%owner(e)) = fd%rigid_matrix(:, :, fd%owner(e)) + fd%rigid_entries(:, :, e)
        end do
      end if
      fd%previous_position = parts%position
      fd%previous_offset = le%offset
    else
      call find_rivals(grid, fd, parts%position, fd%inflated_radius, new_set)
      block = mac_block_t(h=h, box=grid%box, n=grid%n, walls=grid%walls, lo=grid%lo, hi=grid%hi)
      call faces_build(block, parts%position, fd%inflated_radius, fd%kappa * fd%beta * h**2 / fd%eta, fd%rival_start, &
                       fd%rival_part, fd%rival_offset, fd%faces, fd%rigid_matrix)
      if (present(halo)) then
        call owners_sum_matrices(fd%rigid_matrix, halo, ierr)
      else
        call MPI_Allreduce(MPI_IN_PLACE, fd%rigid_matrix, 36 * parts%n, MPI_DOUBLE_PRECISION, MPI_SUM, &
                           PETSC_COMM_WORLD, ierr)
      end if
    end if
    PetscCallA(event_end(EVENT_GEOMETRY, ierr))
  end subroutine fictitious_domain_geometry

  ! A local set's ghost rows of the particle system: a placeholder (the identity, nothing on the
  ! right), since their owners solve for them (the distributed solve takes the own rows only; the
  ! block solve, without pairs, solves every row).
  subroutine ghost_rows(system, rhs, halo)
    type(particle_system_t), intent(inout) :: system
    real(dp), intent(inout) :: rhs(:, :)
    type(sphere_halo_t), intent(in) :: halo
    integer :: q, c
    do q = 1, size(rhs, 2)
      if (halo%is_owned(q)) cycle
      system%diag(:, :, q) = 0.0_dp
      do c = 1, 6
        system%diag(c, c, q) = 1.0_dp
      end do
      rhs(:, q) = 0.0_dp
    end do
  end subroutine ghost_rows

  ! The rigid-body matrices (6, 6, n) of a local set: each ghost's part, made from this rank's
  ! faces, added into its owner's (mod_sphere_halo); a ghost keeps its part. Collective among
  ! neighbours.
  subroutine owners_sum_matrices(matrices, halo, ierr)
    real(dp), intent(inout) :: matrices(:, :, :)
    type(sphere_halo_t), intent(inout) :: halo
    PetscErrorCode, intent(out) :: ierr
    real(dp), allocatable :: flat(:, :)
    flat = reshape(matrices, [36, size(matrices, 3)])
    call sphere_halo_reverse(halo, flat, ierr)
    matrices = reshape(flat, shape(matrices))
  end subroutine owners_sum_matrices

  ! The entries of a Lees-Edwards geometry (see the top): every sphere (entries 1..n), then the
  ! image above of each sphere whose visit may reach below y = 0 (its centre within its inflated
  ! radius and a cell and a half of it: a visit spans R + h/2 beyond a face's stagger) and the image
  ! below of each that may reach beyond y = Ly. x is wrapped into [0, Lx).
  subroutine make_entries(grid, fd, parts)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    type(particles_t), intent(in) :: parts
    integer :: q, e, pass, n
    real(dp) :: reach, ly
    character(len=200) :: text
    n = parts%n
    ly = grid%box(2)
    if (ly < 2.0_dp * (maxval(fd%inflated_radius) + 1.5_dp * grid%h)) then
      write(text, '(a,f8.4,a)') 'fdsusp: error: &domain box(y): a Lees-Edwards box must be at least ', &
           2.0_dp * (maxval(fd%inflated_radius) + 1.5_dp * grid%h), ' a high (a sphere would meet its own image)'
      call fatal_error(text, 2)
    end if
    do pass = 1, 2
      e = n
      do q = 1, n
        reach = fd%inflated_radius(q) + 1.5_dp * grid%h
        if (parts%position(2, q) < reach) then
          e = e + 1
          if (pass == 2) call set_entry(e, q, +1)
        end if
        if (parts%position(2, q) > ly - reach) then
          e = e + 1
          if (pass == 2) call set_entry(e, q, -1)
        end if
      end do
      if (pass == 1) then
        fd%entries = e
        if (allocated(fd%owner)) deallocate(fd%owner, fd%copy, fd%entry_position, fd%entry_radius)
        allocate(fd%owner(e), fd%copy(e), fd%entry_position(3, e), fd%entry_radius(e))
        do q = 1, n
          call set_entry(q, q, 0)
        end do
      end if
    end do
  contains
    subroutine set_entry(e, q, copy)
      integer, intent(in) :: e, q, copy
      fd%owner(e) = q
      fd%copy(e) = copy
      fd%entry_radius(e) = fd%inflated_radius(q)
      fd%entry_position(:, e) = parts%position(:, q) + copy * [fd%le%offset, ly, 0.0_dp]
      fd%entry_position(1, e) = modulo(fd%entry_position(1, e), grid%box(1))
    end subroutine set_entry
  end subroutine make_entries

  ! The images' extra speed gamma_dot Ly of the step to come (Lees-Edwards; the rate of the step).
  subroutine fictitious_domain_set_image_speed(fd, image_speed)
    type(fictitious_domain_t), intent(inout) :: fd
    real(dp), intent(in) :: image_speed
    fd%image_speed = image_speed
  end subroutine fictitious_domain_set_image_speed

  ! The rivals of each sphere: the spheres whose centres are closer than the sum of the two
  ! reaches R_i + sqrt(3) h/2 (R the inflated radius), so that some control volume may meet both
  ! (mod_neighbours' cell lists over the largest reach, with a skin of one cell; every pair when a
  ! periodic length is below twice the list's cut-off). A periodic length below twice the largest
  ! reach would let a sphere reach its own image: refused.
  ! Lees-Edwards: among the entries (spheres and images, positions (3, :)), with y not wrapped; the
  ! entries change with every geometry, so the list is made afresh each time.
  subroutine find_rivals(grid, fd, positions, radii, new_set)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    real(dp), intent(in) :: positions(:, :), radii(:)
    logical, intent(in) :: new_set
    real(dp) :: reach
    integer :: info, l, i, j, n, pass
    logical :: periodic(3)
    integer, allocatable :: count(:)
    character(len=200) :: text

    n = size(positions, 2)
    reach = 0.5_dp * sqrt(3.0_dp) * grid%h
    if (n > 0) reach = reach + maxval(radii)
    periodic = [.true., .not. (grid%walls .or. fd%sliding), .true.]
    if ((fd%sliding .or. new_set) .and. allocated(fd%rival_start)) then
      if (size(fd%rival_start) /= n + 1) deallocate(fd%rival_start)
      if (allocated(fd%reach_pairs)) deallocate(fd%reach_pairs)
    end if
    if (new_set) fd%reach_list%np = 0
    if (.not. allocated(fd%rival_start)) then
      if (any(periodic .and. grid%box < 2.0_dp * reach)) then
        write(text, '(a,f8.4,a)') 'fdsusp: error: &domain box: every periodic length must be at least ', &
             2.0_dp * reach, ' a (twice a sphere''s reach on the grid), or a sphere meets its own image'
        call fatal_error(text, 2)
      end if
      allocate(fd%rival_start(n + 1))
      if (.not. allocated(fd%rival_part)) allocate(fd%rival_part(64), fd%rival_offset(3, 64))
    end if
    if (fd%sliding .or. fd%reach_list%np == 0) then
      call nlist_init(fd%reach_list, n, grid%box, periodic, 2.0_dp * reach + grid%h, reach + grid%h, grid%h, info)
      fd%reach_list%built = .false.
      fd%use_reach_list = (info == 0)
    end if
    if (fd%use_reach_list .and. n > 1) then
      call nlist_candidates(fd%reach_list, positions, fd%reach_pairs, fd%nreach_pairs, fd%reach_walls, &
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
      d = min_image(positions(:, j) - positions(:, i), grid%box, periodic)
      if (sum(d**2) >= (radii(i) + radii(j) + sqrt(3.0_dp) * grid%h)**2) return
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
  ! le, optional: a Lees-Edwards boundary (le%active), its offset now. Each entry of its geometry
  ! (a sphere or an image) is then displaced from the copy of its sphere's last position nearest
  ! to it at the last offset (an image moves by -+ the offset's change besides its sphere), which
  ! the carry works out itself (displacement unused), and the old Lambda across y = 0, Ly is read
  ! at the last offset (the ghost rows of the carry layout, mod_sliding_boundary). Collective.
  subroutine fictitious_domain_follow(grid, fd, parts, displacement, ierr, le, halo)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    type(particles_t), intent(in) :: parts
    real(dp), intent(in) :: displacement(:, :)
    PetscErrorCode, intent(out) :: ierr
    type(lees_edwards_t), intent(in), optional :: le
    type(sphere_halo_t), intent(inout), optional :: halo
    Vec :: old(3)
    type(field_view_t) :: lam_old(3), lam(3)
    type(lees_edwards_t) :: before
    real(dp), allocatable :: entry_displacement(:, :), last_position(:, :)
    real(dp) :: r(3), shift(3)
    integer :: c, e
    character(len=200) :: text

    if (fd%sliding) then
      before = fd%le
      before%offset = fd%previous_offset
      last_position = fd%previous_position
    end if
    call fictitious_domain_geometry(grid, fd, parts, le, halo)
    if (fd%sliding) then
      allocate(entry_displacement(3, fd%entries))
      do e = 1, fd%entries
        call le_separation(before, last_position(:, fd%owner(e)) - fd%entry_position(:, e), r, shift)
        entry_displacement(:, e) = -r
      end do
    else
      entry_displacement = displacement
    end if
    if (maxval(abs(entry_displacement)) >= grid%h) then
      write(text, '(a,f8.3,a)') 'fdsusp: fatal: a sphere moved ', maxval(abs(entry_displacement)) / grid%h, &
           ' cells in one step (its force density can follow at most one): reduce &time dt'
      call fatal_error(text, 3)
    end if
    PetscCall(event_begin(EVENT_CARRY, ierr))
    do c = 1, 3
      PetscCall(DMGetLocalVector(fd%carry_layout, old(c), ierr))
      PetscCall(DMGlobalToLocalBegin(fd%carry_layout, fd%lambda(c), INSERT_VALUES, old(c), ierr))
      PetscCall(DMGlobalToLocalEnd(fd%carry_layout, fd%lambda(c), INSERT_VALUES, old(c), ierr))
      PetscCall(VecSet(fd%lambda(c), 0.0_dp, ierr))
      if (fd%sliding) then
        PetscCall(DMDAVecGetArrayF90(fd%carry_layout, old(c), lam_old(c)%v, ierr))
        call slide_ghost_rows(grid, lam_old(c)%v, before%offset)
      else
        PetscCall(DMDAVecGetArrayReadF90(fd%carry_layout, old(c), lam_old(c)%v, ierr))
      end if
      PetscCall(DMDAVecGetArrayF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
    end do
    ! run by run: the eight corner offsets and weights set once per run (mod_sphere_faces)
    call faces_carry(fd%faces, lam_old, lam, grid%glo, grid%ghi, grid%lo, grid%hi, entry_displacement, grid%h, &
                     grid%walls, grid%n(2))
    fd%lambda_listed = .true.
    do c = 1, 3
      PetscCall(DMDAVecRestoreArrayF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
      if (fd%sliding) then
        PetscCall(DMDAVecRestoreArrayF90(fd%carry_layout, old(c), lam_old(c)%v, ierr))
      else
        PetscCall(DMDAVecRestoreArrayReadF90(fd%carry_layout, old(c), lam_old(c)%v, ierr))
      end if
      PetscCall(DMRestoreLocalVector(fd%carry_layout, old(c), ierr))
    end do
    PetscCall(event_end(EVENT_CARRY, ierr))
  end subroutine fictitious_domain_follow

  ! The ghost rows j = -1 and n(2) of a ghosted face field (the carry layout's, every plane it
  ! holds, its ghost planes too) as the Lees-Edwards boundary at offset delta sees them: the top row
  ! read at x + delta below, the bottom row at x - delta above (mod_sliding_boundary; Lambda, a
  ! force density, has no jump). The grid is split in z only, so the rows are this rank's.
  subroutine slide_ghost_rows(grid, a, offset)
    type(grid_t), intent(in) :: grid
    real(dp), intent(inout) :: a(grid%glo(1):, grid%glo(2):, grid%glo(3):)
    real(dp), intent(in) :: offset
    real(dp), allocatable :: rows(:, :)
    integer :: nx, ny, k, k0, k1
    nx = grid%n(1)
    ny = grid%n(2)
    k0 = grid%glo(3)
    k1 = grid%ghi(3)
    allocate(rows(0:nx - 1, k0:k1))
    do k = k0, k1
      rows(:, k) = a(0:nx - 1, ny - 1, k)
    end do
    call sliding_shift_rows(rows, offset / grid%h)
    do k = k0, k1
      a(0:nx - 1, -1, k) = rows(:, k)
      rows(:, k) = a(0:nx - 1, 0, k)
    end do
    call sliding_shift_rows(rows, -offset / grid%h)
    do k = k0, k1
      a(0:nx - 1, ny, k) = rows(:, k)
    end do
    a(-1, -1, k0:k1) = a(nx - 1, -1, k0:k1)
    a(nx, -1, k0:k1) = a(0, -1, k0:k1)
    a(-1, ny, k0:k1) = a(nx - 1, ny, k0:k1)
    a(nx, ny, k0:k1) = a(0, ny, k0:k1)
  end subroutine slide_ghost_rows

  ! The particle sub-problem after the fluid step, in three named parts that main.F90 calls in
  ! turn (doc/METHOD.md §3.2 eq. (1), §3.3, §3.5):
  !   fictitious_domain_moments       b(u~) and m(Lambda^n) of every sphere, summed over ranks;
  !   fictitious_domain_solve_motion  the 6N system (rigid-body matrices, lubrication, contacts): U, Omega;
  !   fictitious_domain_update        Lambda^{n+1}, u^{n+1} = u~ + (Lambda^{n+1} - Lambda^n)/beta, and the
  !                    resolved force, torque and stresslet (plus the lubrication corrections).

  ! b = sum_f w u~_c g dV and m = sum_f Lambda^n_f/(1+gamma) g dV per sphere (rows 1-6, 7-12 of
  ! fd%moments). vel: the projected velocity u~. Collective.
  subroutine fictitious_domain_moments(grid, fd, vel, n, ierr, halo)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    Vec, intent(in) :: vel(3)
    integer, intent(in) :: n
    PetscErrorCode, intent(out) :: ierr
    type(sphere_halo_t), intent(inout), optional :: halo
    type(field_view_t) :: u(3), lam(3)
    real(dp) :: dv
    real(dp), allocatable :: entry_moments(:, :)
    integer :: c, e, q

    PetscCall(event_begin(EVENT_MOMENTS, ierr))
    dv = grid%h**3
    if (allocated(fd%moments)) then
      if (size(fd%moments, 2) /= n) deallocate(fd%moments)
    end if
    if (.not. allocated(fd%moments)) allocate(fd%moments(12, n))
    fd%moments = 0.0_dp
    do c = 1, 3
      PetscCall(DMDAVecGetArrayReadF90(grid%da(c), vel(c), u(c)%v, ierr))
      PetscCall(DMDAVecGetArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
    end do
    if (fd%sliding) then
      allocate(entry_moments(12, fd%entries))
      entry_moments = 0.0_dp
      call faces_moments(fd%faces, u, lam, grid%lo, grid%hi, dv, entry_moments)
    else
      call faces_moments(fd%faces, u, lam, grid%lo, grid%hi, dv, fd%moments)
    end if
    do c = 1, 3
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), vel(c), u(c)%v, ierr))
    end do
    if (fd%sliding) then
      if (.not. present(halo)) then
        call MPI_Allreduce(MPI_IN_PLACE, entry_moments, 12 * fd%entries, MPI_DOUBLE_PRECISION, MPI_SUM, &
                           PETSC_COMM_WORLD, ierr)
      end if
      ! an image's faces move faster by copy gamma_dot Ly e_x: b - copy gamma_dot Ly M_p e_1 (see the top)
      do e = 1, fd%entries
        q = fd%owner(e)
        fd%moments(:, q) = fd%moments(:, q) + entry_moments(:, e)
        if (fd%copy(e) /= 0) fd%moments(1:6, q) = fd%moments(1:6, q) &
                                                  - fd%copy(e) * fd%image_speed * fd%rigid_entries(1:6, 1, e)
      end do
    else if (.not. present(halo)) then
      call MPI_Allreduce(MPI_IN_PLACE, fd%moments, 12 * n, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr)
    end if
    ! a local set: each sphere's parts (with an image's, and its correction from this rank's part of
    ! the image's M_p: the sum is linear) added into its owner's
    if (present(halo)) call sphere_halo_reverse(halo, fd%moments, ierr)
    PetscCall(event_end(EVENT_MOMENTS, ierr))
  end subroutine fictitious_domain_moments

  ! The velocities of the spheres: beta M U = beta b(u~) - m(Lambda^n) + F_ext (doc/METHOD.md eq. (1)
  ! with the weights), for free motion; prescribed, resistance and fixed motions set them.
  ! extra_force, extra_torque (3, n), optional: further given forces on the particles, added to
  ! the right-hand side next to external_force/external_torque (free and frozen motion).
  ! lubrication, optional: the links of this configuration (those of this rank's spheres,
  ! mod_lubrication_links); their resistance enters the 6N system implicitly. contacts, optional:
  ! the contacts of this step (particle_contacts_step at X^n): their forces and torques join the
  ! right-hand side (free and frozen motion) and, for free motion with implicit contacts, their
  ! linearised stiffness the 6N system; after the solve their force, torque and stresslet are
  ! those the balance used (mod_particle_contacts). Identical on every rank (replicated data), or
  ! (halo, optional) parts is a rank's local set: the own spheres' rows are solved (fd%solver told
  ! the set, mod_ld_local), a ghost's row is a placeholder (the identity), and the own velocities
  ! are then forwarded to their ghosts, before the contacts' update.
  subroutine fictitious_domain_solve_motion(fd, parts, ierr, extra_force, extra_torque, lubrication, contacts, halo)
    type(fictitious_domain_t), intent(inout) :: fd
    type(particles_t), intent(inout) :: parts
    PetscErrorCode, intent(out) :: ierr
    real(dp), intent(in), optional :: extra_force(:, :), extra_torque(:, :)
    type(particle_lubrication_t), intent(in), optional :: lubrication
    type(particle_contacts_t), intent(inout), optional :: contacts
    type(sphere_halo_t), intent(inout), optional :: halo
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
      if (present(halo)) call ghost_rows(fd%solver%system, rhs, halo)
      if (present(lubrication)) call particle_lubrication_add_to_system(lubrication, fd%solver%system, rhs)
      if (present(contacts) .and. parts%motion == MOTION_FREE) &
        call particle_contacts_add_stiffness(contacts, fd%solver%system, rhs, parts%velocity, parts%omega, parts%have_prev)
      call particle_solver_solve(fd%solver, rhs, parts, ierr, ': a particle covers no grid face?')
      CHKERRQ(ierr)
      if (present(halo)) then
        PetscCall(ld_local_forward_motion(halo, parts, ierr))
      end if
      if (present(contacts)) then
        if (present(halo)) then
          ! (the walls' forces summed over the ranks)
          PetscCall(ld_local_contacts_update(contacts, parts%velocity, parts%omega, ierr))
        else
          call particle_contacts_implicit_update(contacts, parts%velocity, parts%omega)
        end if
      end if
    case default                    ! prescribed, resistance, fixed
      call impose_motion(parts)
    end select
    PetscCall(event_end(EVENT_MOTION, ierr))
  end subroutine fictitious_domain_solve_motion

  ! Stress control (doc/METHOD.md §7.4): b = sum_f w u_c g dV of vel, the fluid step's response to a
  ! unit wall speed (the same field every step; the geometry of X^n weighs it), into
  ! fd%response_moments (6, n), summed over ranks. Collective.
  subroutine fictitious_domain_response_moments(grid, fd, vel, n, ierr, halo)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    Vec, intent(in) :: vel(3)
    integer, intent(in) :: n
    PetscErrorCode, intent(out) :: ierr
    type(sphere_halo_t), intent(inout), optional :: halo
    type(field_view_t) :: u(3), lam(3)
    real(dp), allocatable :: both(:, :)
    integer :: c, e, q

    PetscCall(event_begin(EVENT_MOMENTS, ierr))
    allocate(both(12, max(n, fd%entries)))
    both = 0.0_dp
    do c = 1, 3
      PetscCall(DMDAVecGetArrayReadF90(grid%da(c), vel(c), u(c)%v, ierr))
      PetscCall(DMDAVecGetArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
    end do
    ! (the m of Lambda^n comes along in rows 7-12 and is not wanted: the response has no Lambda^n)
    call faces_moments(fd%faces, u, lam, grid%lo, grid%hi, grid%h**3, both)
    do c = 1, 3
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), vel(c), u(c)%v, ierr))
    end do
    if (fd%sliding) then
      ! per entry, then each image's to its sphere, less what its extra speed (gamma_dot Ly per
      ! unit rate: Ly) takes off (Lees-Edwards, see the top; a local set: this rank's parts, summed
      ! on the owners below)
      if (.not. present(halo)) then
        call MPI_Allreduce(MPI_IN_PLACE, both, 12 * fd%entries, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr)
      end if
      if (allocated(fd%response_moments)) deallocate(fd%response_moments)
      allocate(fd%response_moments(6, n))
      fd%response_moments = 0.0_dp
      do e = 1, fd%entries
        q = fd%owner(e)
        fd%response_moments(:, q) = fd%response_moments(:, q) + both(1:6, e) &
                                    - fd%copy(e) * fd%le%box(2) * fd%rigid_entries(1:6, 1, e)
      end do
    else
      if (.not. present(halo)) then
        call MPI_Allreduce(MPI_IN_PLACE, both, 12 * n, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr)
      end if
      fd%response_moments = both(1:6, 1:n)
    end if
    if (present(halo)) call sphere_halo_reverse(halo, fd%response_moments, ierr)
    PetscCall(event_end(EVENT_MOMENTS, ierr))
  end subroutine fictitious_domain_response_moments

  ! Stress control of the DNS between walls (doc/METHOD.md §7.4): the spheres' velocities of a step
  ! whose rate gamma_dot (the walls at -+ gamma_dot Ly/2) is the unknown, set so that the mean wall
  ! shear stress is stress. Given X^n, the contacts' explicit forces (particle_contacts_step, at
  ! the last step's rate) and the lubrication links evaluated per unit rate, the step is affine
  ! in the rate: the fluid step (the wall speed enters its right-hand side linearly), the moments,
  ! the 6N right-hand side (the links' drives, the walls' velocity in the implicit contacts), its
  ! solution and the wall forces; the matrix does not depend on it. With the fluid stepped at the
  ! last step's rate r0 (moments in fd%moments) and the response of the fluid step to a unit wall
  ! speed (fd%response_moments; response_scale = Ly/2 wall speed per unit rate):
  !   A U_0 = rhs(r0),  A U_1 = beta response_scale b(response) + drives(1) + contact walls(1)
  ! (the second with neither Lambda^n, contact forces nor U^{n-1}: the homogeneous step), and
  ! U(r) = U_0 + (r - r0) U_1. The mean wall shear stress is
  !   sigma(r) = fluid_stress + (r - r0) fluid_slope + (F_top,x - F_bottom,x)/(2 Lx Lz),
  ! fluid_stress, fluid_slope: the grid's (tau_bottom + tau_top)/2 of the step at r0 and per unit
  ! rate; F: the force of each wall on the spheres through the wall links and the wall contacts
  ! (explicit and implicit), affine in r. It is evaluated at r0 and r0 + 1, and
  ! r = r0 + (stress - sigma(r0))/(sigma(r0 + 1) - sigma(r0)); then the velocities, the contacts'
  ! implicit forces and the links' corrections are those of r. rate: in, r0 (the last step's, the
  ! one the explicit contacts and U^{n-1} went with); out, r. particle_stress: the walls' share of
  ! sigma(r), (F_top,x - F_bottom,x)/(2 Lx Lz). The guesses of the two solves are 0 and U^{n-1},
  ! from the checkpointed state, so that a restart repeats them: one fluid step's response to the
  ! walls reaches only ~sqrt(dt/Re) into the fluid, so U_1 moves the spheres near the walls and
  ! U^{n-1}/r0 is a worse guess than 0 (88 against 83 CG iterations a step, doc/BENCHMARKS.md §16).
  ! Free or frozen spheres. Collective.
  ! Lees-Edwards (fd%sliding; doc/METHOD.md §7.4): no walls; the mean shear stress of the box is
  ! eta gamma_dot (the fluid's, exactly: fluid_stress = r0, fluid_slope = 1 from the caller) plus
  ! the spheres' stresslets over the box's volume, sum_p (S_FD + S_lubrication + S_contact)_xy / V,
  ! which particle_stress returns instead. S_FD is the fictitious domain's -1/2 sum Lambda^{n+1}
  ! (r e_c + e_c r) dV of §3.7, affine in the rate through u~ and U: at r0 from u~ (grid, vel)
  ! with Lambda^n, per unit rate from the fluid's unit response (response_vel) without it
  ! (shear_stresslet); the links' and contacts' from their corrections at each rate. volume: the box's.
  ! halo (optional): parts is a rank's local set (see fictitious_domain_solve_motion): each solve
  ! gives the own spheres' velocities, forwarded to the ghosts; the walls' forces and the spheres'
  ! stresslets are summed over the own spheres of every rank.
  subroutine fictitious_domain_solve_stress(fd, parts, stress, fluid_stress, fluid_slope, response_scale, area, &
                                            rate, particle_stress, ierr, lubrication, contacts, grid, vel, &
                                            response_vel, volume, halo)
    type(fictitious_domain_t), intent(inout) :: fd
    type(particles_t), intent(inout) :: parts
    real(dp), intent(in) :: stress, fluid_stress, fluid_slope, response_scale, area
    real(dp), intent(inout) :: rate
    real(dp), intent(out) :: particle_stress
    PetscErrorCode, intent(out) :: ierr
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    type(particle_contacts_t), intent(inout), optional :: contacts
    type(grid_t), intent(in), optional :: grid
    Vec, intent(in), optional :: vel(3), response_vel(3)
    real(dp), intent(in), optional :: volume
    type(sphere_halo_t), intent(inout), optional :: halo
    real(dp), allocatable :: rhs(:, :), u_before(:, :), w_before(:, :), u0(:, :), w0(:, :), u1(:, :), w1(:, :)
    real(dp), allocatable :: drive(:, :), uinf(:, :), wall_drive(:, :)
    real(dp), allocatable :: c_force(:, :), c_torque(:, :), c_stresslet(:, :, :)
    real(dp) :: c_wall_force(3, 2), rate_before, sigma0, sigma1, slope, fd_stress0, fd_stress1
    logical :: c_added, stiffness
    character(len=300) :: text
    integer :: q, n, np, nw

    PetscCall(event_begin(EVENT_MOTION, ierr))
    n = parts%n
    rate_before = rate
    if (parts%motion /= MOTION_FREE .and. parts%motion /= MOTION_FROZEN) &
      call fatal_error('fdsusp: fatal: stress control needs free or frozen spheres', 4)
    stiffness = .false.
    if (present(contacts)) stiffness = parts%motion == MOTION_FREE
    ! the links' rate-proportional data, made per unit rate
    if (present(lubrication)) then
      np = lubrication%npairs
      nw = lubrication%nwalls
      drive = lubrication%pair_drive(:, 1:np)
      uinf = lubrication%pair_uinf(:, 1:np)
      wall_drive = lubrication%wall_drive(:, 1:nw)
    end if
    u_before = parts%velocity
    w_before = parts%omega
    allocate(rhs(6, n))
    ! the homogeneous step per unit rate: U_1, from 0
    call particle_system_reset(fd%solver%system, n)
    do q = 1, n
      call particle_system_add_diagonal(fd%solver%system, q, fd%beta * fd%rigid_matrix(:, :, q))
      rhs(:, q) = (fd%beta * response_scale) * fd%response_moments(:, q)
    end do
    if (present(halo)) call ghost_rows(fd%solver%system, rhs, halo)
    call set_rate(1.0_dp)
    if (present(lubrication)) call particle_lubrication_add_to_system(lubrication, fd%solver%system, rhs)
    if (stiffness) call particle_contacts_add_stiffness(contacts, fd%solver%system, rhs, 0.0_dp * u_before, &
                                                        0.0_dp * w_before, parts%have_prev)
    parts%velocity = 0.0_dp
    parts%omega = 0.0_dp
    call particle_solver_solve(fd%solver, rhs, parts, ierr, ': a particle covers no grid face? (stress control: '// &
                               'the part per unit rate)')
    CHKERRQ(ierr)
    if (present(halo)) then
      PetscCall(ld_local_forward_motion(halo, parts, ierr))
    end if
    u1 = parts%velocity
    w1 = parts%omega
    ! the step at r0 (assembled last: the contacts keep its U^{n-1} for their implicit update), from U^{n-1}
    call particle_system_reset(fd%solver%system, n)
    do q = 1, n
      call particle_system_add_diagonal(fd%solver%system, q, fd%beta * fd%rigid_matrix(:, :, q))
      rhs(:, q) = fd%beta * fd%moments(1:6, q) - fd%moments(7:12, q) &
           + [parts%external_force(:, q), parts%external_torque(:, q)]
      if (present(contacts)) rhs(:, q) = rhs(:, q) + [contacts%force(:, q), contacts%torque(:, q)]
    end do
    if (present(halo)) call ghost_rows(fd%solver%system, rhs, halo)
    call set_rate(rate_before)
    if (present(lubrication)) call particle_lubrication_add_to_system(lubrication, fd%solver%system, rhs)
    if (stiffness) call particle_contacts_add_stiffness(contacts, fd%solver%system, rhs, u_before, w_before, &
                                                        parts%have_prev)
    parts%velocity = u_before
    parts%omega = w_before
    call particle_solver_solve(fd%solver, rhs, parts, ierr, ': a particle covers no grid face?')
    CHKERRQ(ierr)
    if (present(halo)) then
      PetscCall(ld_local_forward_motion(halo, parts, ierr))
    end if
    u0 = parts%velocity
    w0 = parts%omega
    ! Lees-Edwards: the fictitious domain's stresslet at r0 and per unit rate (affine; see above)
    if (fd%sliding) then
      PetscCall(shear_stresslet(grid, fd, vel, .true., u0, w0, rate_before * grid%box(2), fd_stress0, ierr))
      PetscCall(shear_stresslet(grid, fd, response_vel, .false., u1, w1, grid%box(2), fd_stress1, ierr))
    end if
    ! the contacts' explicit forces of the step, kept for each evaluation
    if (present(contacts)) then
      c_force = contacts%force
      c_torque = contacts%torque
      c_stresslet = contacts%stresslet
      c_wall_force = contacts%wall_force
      c_added = contacts%stiffness_added
    end if
    PetscCall(at_rate(rate_before, u0, w0, sigma0))
    PetscCall(at_rate(rate_before + 1.0_dp, u0 + u1, w0 + w1, sigma1))
    sigma0 = sigma0 + fluid_stress
    sigma1 = sigma1 + fluid_stress + fluid_slope
    slope = sigma1 - sigma0
    if (.not. (slope > 0.0_dp)) then
      write(text, '(a,es12.4,a)') 'fdsusp: fatal: stress control: the mean wall stress does not grow with the rate '// &
           '(d sigma/d gamma_dot = ', slope, '): the step cannot set the stress'
      call fatal_error(text, 4)
    end if
    rate = rate_before + (stress - sigma0) / slope
    PetscCall(at_rate(rate, u0 + (rate - rate_before) * u1, w0 + (rate - rate_before) * w1, particle_stress))
    PetscCall(event_end(EVENT_MOTION, ierr))

  contains

    ! every rate-dependent datum of the particle problem at rate r: the links' drives, undisturbed
    ! velocities and E_inf, the walls' velocity in the contacts
    subroutine set_rate(r)
      real(dp), intent(in) :: r
      if (present(lubrication)) then
        lubrication%pair_drive(:, 1:np) = r * drive
        lubrication%pair_uinf(:, 1:np) = r * uinf
        lubrication%wall_drive(:, 1:nw) = r * wall_drive
        lubrication%shear_rate = r
        lubrication%le%shear_rate = r
      end if
      if (present(contacts)) call particle_contacts_set_rate(contacts, r, rate_before)
    end subroutine set_rate

    ! the particle problem at rate r with the velocities u, w (3, n): the spheres' velocities, the
    ! contacts' force (explicit forces restored, then the implicit part), the links' corrections,
    ! and the walls' share of the mean wall shear stress, (F_top,x - F_bottom,x)/(2 area) (with
    ! Lees-Edwards the spheres' share of the box's, sum_p S_xy/V, see above).
    ! Collective (the links' corrections; the host's ierr).
    subroutine at_rate(r, u, w, walls_share)
      real(dp), intent(in) :: r, u(:, :), w(:, :)
      real(dp), intent(out) :: walls_share
      real(dp) :: force(3, 2), lubrication_force(3, 2), spheres(2)
      call set_rate(r)
      parts%velocity = u
      parts%omega = w
      force = 0.0_dp
      spheres = 0.0_dp
      if (present(contacts)) then
        contacts%force = c_force
        contacts%torque = c_torque
        contacts%stresslet = c_stresslet
        contacts%wall_force = c_wall_force
        contacts%stiffness_added = c_added
        if (present(halo)) then
          PetscCall(ld_local_contacts_update(contacts, u, w, ierr))
        else
          call particle_contacts_implicit_update(contacts, u, w)
        end if
        force = force + contacts%wall_force
        spheres(1) = own_sum(contacts%stresslet(1, 2, :))
      end if
      if (present(lubrication)) then
        if (present(halo)) then
          ! (the own spheres' links: their walls' forces summed over the ranks here, the
          ! lubrication's own left for the step's end)
          call particle_lubrication_corrections(lubrication, u, w)
          lubrication_force = lubrication%wall_force
          PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, lubrication_force, 6, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr))
        else
          PetscCall(lubrication_links_corrections(lubrication, u, w, ierr))
          lubrication_force = lubrication%wall_force
        end if
        force = force + lubrication_force
        spheres(2) = own_sum(lubrication%stresslet(1, 2, :))
      end if
      walls_share = (force(1, 2) - force(1, 1)) / (2.0_dp * area)
      if (fd%sliding) then
        if (present(halo)) then
          PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, spheres, 2, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr))
        end if
        walls_share = fd_stress0 + (r - rate_before) * fd_stress1
        if (present(contacts)) walls_share = walls_share + spheres(1)
        if (present(lubrication)) walls_share = walls_share + spheres(2)
        walls_share = walls_share / volume
      end if
    end subroutine at_rate

    ! the sum of values (n) over the spheres, a local set's own only
    real(dp) function own_sum(values)
      real(dp), intent(in) :: values(:)
      if (present(halo)) then
        own_sum = sum(values, halo%is_owned)
      else
        own_sum = sum(values)
      end if
    end function own_sum
  end subroutine fictitious_domain_solve_stress

  ! Lees-Edwards stress control: the xy stresslet the fictitious domain would give all spheres,
  ! sum over the faces of -1/2 Lambda (r_y on u-faces, r_x on v-faces) dV (§3.7), with Lambda =
  ! [Lambda^n (with_lambda) + beta alpha (rigid - u)]/(1 + gamma) of §3.5 for the field vel and the
  ! spheres' velocity, omega (3, n), an image's rigid velocity faster by its copy times image_speed;
  ! nothing is written. Summed over ranks. Collective.
  subroutine shear_stresslet(grid, fd, vel, with_lambda, velocity, omega, image_speed, sxy, ierr)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    Vec, intent(in) :: vel(3)
    logical, intent(in) :: with_lambda
    real(dp), intent(in) :: velocity(:, :), omega(:, :), image_speed
    real(dp), intent(out) :: sxy
    PetscErrorCode, intent(out) :: ierr
    type(field_view_t) :: u(3), lam(3)
    real(dp), allocatable :: r(:, :), lambda(:)
    real(dp) :: ve(3), we(3), dv
    integer :: c, run, f0, f1, e, f, arm
    dv = grid%h**3
    do c = 1, 2
      PetscCall(DMDAVecGetArrayReadF90(grid%da(c), vel(c), u(c)%v, ierr))
      PetscCall(DMDAVecGetArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
    end do
    allocate(r(3, max(1, fd%faces%nf)), lambda(max(1, fd%faces%nf)))
    sxy = 0.0_dp
    do run = 1, fd%faces%nruns
      call face_run(fd%faces, run, f0, f1, c, e)
      if (c > 2) cycle
      call run_offsets(fd%faces, run, r)
      ve = velocity(:, fd%owner(e)) + [fd%copy(e) * image_speed, 0.0_dp, 0.0_dp]
      we = omega(:, fd%owner(e))
      call new_lambda_run(c, u(c)%v, lam(c)%v, grid%lo, grid%hi, f1 - f0 + 1, fd%faces%ijk(:, f0:f1), r, &
                          fd%faces%alpha(f0:f1), fd%faces%relax(f0:f1), fd%beta, ve, we, lambda)
      if (.not. with_lambda) then
        ! the same update without Lambda^n: take its share (Lambda^n relax) off again
        do f = f0, f1
          lambda(f - f0 + 1) = lambda(f - f0 + 1) &
               - lam(c)%v(fd%faces%ijk(1, f), fd%faces%ijk(2, f), fd%faces%ijk(3, f)) * fd%faces%relax(f)
        end do
      end if
      arm = 3 - c          ! u-faces carry r_y, v-faces r_x
      sxy = sxy - 0.5_dp * dv * sum(lambda(1:f1 - f0 + 1) * r(arm, 1:f1 - f0 + 1))
    end do
    do c = 1, 2
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), vel(c), u(c)%v, ierr))
    end do
    call MPI_Allreduce(MPI_IN_PLACE, sxy, 1, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr)
  end subroutine shear_stresslet

  ! Lambda^{n+1} = [Lambda^n + beta alpha (g.U - u~)]/(1 + gamma) on owned faces, 0 elsewhere;
  ! u^{n+1} = u~ + (Lambda^{n+1} - Lambda^n)/beta; the moments F = -sum Lambda e_c dV,
  ! T = -sum r x Lambda e_c dV, S = -1/2 sum Lambda (r e_c + e_c r) dV - (sum_cells alpha p dV) I
  ! (doc/METHOD.md §3.7). vel: u~ on entry, u^{n+1} on exit. lubrication, optional: its corrections are added to
  ! the resolved force, torque and stresslet, which then hold the total hydrodynamics. Collective.
  subroutine fictitious_domain_update(grid, fd, vel, pressure, parts, ierr, lubrication, halo)
    type(grid_t), intent(in) :: grid
    type(fictitious_domain_t), intent(inout) :: fd
    Vec, intent(inout) :: vel(3)
    Vec, intent(in) :: pressure
    type(particles_t), intent(inout) :: parts
    PetscErrorCode, intent(out) :: ierr
    type(particle_lubrication_t), intent(inout), optional :: lubrication
    type(sphere_halo_t), intent(inout), optional :: halo
    real(dp), allocatable :: sums(:, :), velocity(:, :), omega(:, :), entry_sums(:, :)
    type(field_view_t) :: u(3), lam(3), p
    real(dp) :: dv, integral
    integer :: c, q, n, e
    logical :: removed

    PetscCall(event_begin(EVENT_UPDATE, ierr))
    n = parts%n
    dv = grid%h**3
    allocate(sums(16, n))
    sums = 0.0_dp
    ! the rigid motion of each entry of the geometry: an image's is its sphere's plus copy
    ! gamma_dot Ly e_x (Lees-Edwards, see the top); otherwise the spheres'
    if (fd%sliding) then
      allocate(velocity(3, fd%entries), omega(3, fd%entries), entry_sums(16, fd%entries))
      entry_sums = 0.0_dp
      do e = 1, fd%entries
        velocity(:, e) = parts%velocity(:, fd%owner(e)) + [fd%copy(e) * fd%image_speed, 0.0_dp, 0.0_dp]
        omega(:, e) = parts%omega(:, fd%owner(e))
      end do
    else
      velocity = parts%velocity
      omega = parts%omega
    end if
    ! Lambda^n is non-zero only on the listed faces once fictitious_domain_follow has carried it there; then
    ! removing it and adding Lambda^{n+1} is one pass over the list. Otherwise (the first step
    ! of a run, -fd_carry_lambda 0) Lambda^{n+1} is computed first and Lambda^n removed from the
    ! whole grid, as the formula says; both give the same numbers where both apply.
    removed = .not. fd%lambda_listed
    if (removed) then
      if (allocated(fd%lambda_new)) then
        if (size(fd%lambda_new) < fd%faces%nf) deallocate(fd%lambda_new)
      end if
      if (.not. allocated(fd%lambda_new)) allocate(fd%lambda_new(size(fd%faces%alpha)))
      do c = 1, 3
        PetscCall(DMDAVecGetArrayReadF90(grid%da(c), vel(c), u(c)%v, ierr))
        PetscCall(DMDAVecGetArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
      end do
      call faces_new_lambda(fd%faces, u, lam, grid%lo, grid%hi, fd%beta, velocity, omega, fd%lambda_new)
      do c = 1, 3
        PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
        PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), vel(c), u(c)%v, ierr))
        PetscCall(VecAXPY(vel(c), -1.0_dp / fd%beta, fd%lambda(c), ierr))
        PetscCall(VecSet(fd%lambda(c), 0.0_dp, ierr))
      end do
    end if
    do c = 1, 3
      PetscCall(DMDAVecGetArrayF90(grid%da(c), vel(c), u(c)%v, ierr))
      PetscCall(DMDAVecGetArrayF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
    end do
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_P), pressure, p%v, ierr))
    ! with the interior pressure of doc/METHOD.md §3.7 from the runs of cell centres
    if (fd%sliding) then
      if (removed) then
        call faces_update(fd%faces, u, lam, p, grid%lo, grid%hi, fd%beta, dv, velocity, omega, entry_sums, &
                          fd%lambda_new)
      else
        call faces_update(fd%faces, u, lam, p, grid%lo, grid%hi, fd%beta, dv, velocity, omega, entry_sums)
      end if
    else if (removed) then
      call faces_update(fd%faces, u, lam, p, grid%lo, grid%hi, fd%beta, dv, velocity, omega, sums, fd%lambda_new)
    else
      call faces_update(fd%faces, u, lam, p, grid%lo, grid%hi, fd%beta, dv, velocity, omega, sums)
    end if
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_P), pressure, p%v, ierr))
    do c = 1, 3
      PetscCall(DMDAVecRestoreArrayF90(grid%da(c), fd%lambda(c), lam(c)%v, ierr))
      PetscCall(DMDAVecRestoreArrayF90(grid%da(c), vel(c), u(c)%v, ierr))
    end do
    if (fd%sliding) then
      ! an image's force, torque and stresslet (about its own centre) are its sphere's
      if (.not. present(halo)) then
        call MPI_Allreduce(MPI_IN_PLACE, entry_sums, 16 * fd%entries, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr)
      end if
      do e = 1, fd%entries
        sums(:, fd%owner(e)) = sums(:, fd%owner(e)) + entry_sums(:, e)
      end do
    else if (.not. present(halo)) then
      call MPI_Allreduce(MPI_IN_PLACE, sums, 16 * n, MPI_DOUBLE_PRECISION, MPI_SUM, PETSC_COMM_WORLD, ierr)
    end if
    ! a local set: each sphere's parts added into its owner's, whose sums are then complete (a
    ! ghost's are its part; nothing reads them), and its links' corrections (every link of an own
    ! sphere is this rank's)
    if (present(halo)) then
      call sphere_halo_reverse(halo, sums, ierr)
      CHKERRQ(ierr)
      if (present(lubrication)) call particle_lubrication_corrections(lubrication, parts%velocity, parts%omega)
    else if (present(lubrication)) then
      PetscCall(lubrication_links_corrections(lubrication, parts%velocity, parts%omega, ierr))
    end if
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
