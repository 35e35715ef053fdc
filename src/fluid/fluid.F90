! The fluid sub-problem: unsteady Stokes, rho du/dt = -grad p + eta lap u + f, div u = 0, on the
! MAC grid of mod_grid, by an incremental pressure-correction projection in rotational form with a
! theta scheme for the viscous term (theta = 1/2: Crank-Nicolson). doc/METHOD.md §2.2. In fdsusp
! units eta = 1 and rho = Re (Re = rho gamma_dot a^2 / eta).
!
! One step, from u^n and p^{n-1/2}:
!   1. (Re/dt - theta lap) u* = (Re/dt) u^n + (1-theta) lap u^n - grad p^{n-1/2} + f
!   2. lap phi = (Re/dt) div u*                       (solved as -lap phi = -(Re/dt) div u*)
!   3. u^{n+1} = u* - (dt/Re) grad phi                (discretely divergence-free)
!   4. p^{n+1/2} = p^{n-1/2} + phi - theta eta div u*  (rotational correction)
! The viscous solves of step 1 start from the linear extrapolation 2 u*^n - u*^{n-1} of the
! provisional velocities of the last two steps (u^n on the first two): u* changes smoothly, while
! u^n carries the projection and the particle correction of the last step, so the extrapolation
! starts nearer (39 -> 18 CG iterations per step in all three, doc/BENCHMARKS.md §10). The
! checkpoint keeps both, so a restart repeats the same iterations.
! The discrete Poisson operator is exactly div(grad) on this grid, so step 3 leaves div u^{n+1}
! at the level of the Poisson solver's residual. At a steady state the scheme satisfies the
! discrete steady Stokes equations exactly (phi -> constant).
!
! Memory (doc/BENCHMARKS.md §14, doc/DESIGN.md "One layout with the direct solves"): with the
! direct solves (the default) a solve may overwrite its right-hand side, so each right-hand side is
! built in the vector that receives the solution (u* in vel_star, phi in phi) and rhs, rhs_p and
! vel_star_old (the Krylov path's extrapolation history; its checkpoint datasets are written as
! the zeros they always held) are not made; the forcing vectors exist only when there is a
! forcing; the ghosted work vectors are borrowed from the DMDA (DMGetLocalVector), whose cache the
! carry of the fictitious domain shares. 9 grid vectors of the fluid's 23 remain in that path.
#include <petsc/finclude/petscdmda.h>
module mod_fluid
  use petscdmda
  use mod_kinds, only: dp
  use mod_params, only: config_t
  use mod_grid, only: grid_t, grid_position, grid_fixed_row, field_names, FIELD_U, FIELD_V, FIELD_W, FIELD_P, &
                      direct_solves_wanted
  use mod_solvers, only: solver_t, solver_create, solver_solve, solver_destroy, solver_cold_solve, &
                         fft_planner_flags, solver_set_sliding_shift
  use mod_errors, only: log_line
  use mod_manufactured, only: mms_forcing
  use mod_columns, only: column_t, column
  use mod_sliding_boundary, only: sliding_shift_rows
  implicit none
  private
  public :: fluid_t, fluid_create, fluid_step, fluid_destroy, fluid_mean_profile, fluid_columns
  public :: fluid_options_check, fluid_bench_cold_poisson, fluid_unit_response, fluid_add_response
  public :: fluid_set_sliding, fluid_ghosted
  integer, parameter :: AT_START = 1, AT_END = 2  ! the step's two instants t_n, t_{n+1} (Lees-Edwards)
  integer, parameter :: STAR_HISTORY_FULL = 2   ! u*^n and u*^{n-1} known: extrapolate

  type :: fluid_t
    Vec :: vel(3)           ! u^n, v^n, w^n
    Vec :: pressure         ! p^{n-1/2}
    Vec :: phi              ! pressure increment of the last step (warm start of the Poisson solve)
    Vec :: vel_star(3)      ! provisional velocity u*^{n+1}; between steps u*^n
    Vec :: vel_star_old(3)  ! u*^{n-1} between steps
    integer :: star_history = 0         ! how many earlier u* vel_star and vel_star_old hold (0..2)
    logical :: extrapolate = .true.     ! -fluid_extrapolate 0: warm start from u^n instead
    Vec :: rhs(3), rhs_p    ! right-hand sides
    Vec :: div_star         ! div u*
    Vec :: forcing(3)       ! steady body-force density at the faces
    logical :: has_forcing = .false.    ! forcing(3) exists (a body force or the manufactured solution)
    logical :: direct = .false.         ! every solve direct (mod_fft_solver): no rhs, rhs_p, vel_star_old
    type(solver_t) :: solver(4)
    real(dp) :: reynolds = 0.0_dp, dt = 0.0_dp, theta = 0.5_dp, viscosity = 1.0_dp
    real(dp) :: wall_speed = 0.0_dp
    ! Lees-Edwards (grid%lees_edwards, doc/METHOD.md §2.4): the boundary's offset delta [a] and the
    ! velocity of the image above, gamma_dot Ly, at t_n (AT_START: the explicit half of the step)
    ! and t_{n+1} (AT_END: the implicit half, the projection, the diagnostics); fluid_set_sliding
    real(dp) :: sliding_offset(2) = 0.0_dp, sliding_jump(2) = 0.0_dp
    ! diagnostics of the last step
    real(dp) :: divergence = 0.0_dp   ! max|div u| h / max|u| after projection
    real(dp) :: tau_bottom = 0.0_dp   ! mean eta du/dy on the wall y = 0
    real(dp) :: tau_top = 0.0_dp      ! mean eta du/dy on the wall y = Ly
    real(dp) :: max_rate = 0.0_dp     ! max|u^{n+1} - u^n| / dt
  end type fluid_t

contains

  subroutine fluid_create(cfg, grid, fl, ierr)
    type(config_t), intent(in) :: cfg
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(inout) :: fl
    PetscErrorCode, intent(out) :: ierr
    integer :: c
    real(dp) :: tol, floor, u_ref, cells
    PetscBool :: found

    fl%reynolds = cfg%fluid%reynolds
    fl%dt = cfg%time%dt
    fl%theta = cfg%fluid%viscous_theta
    fl%wall_speed = cfg%wall_speed
    fl%direct = direct_solves_wanted()
    fl%has_forcing = cfg%verification%manufactured_solution .or. any(cfg%fluid%body_force /= 0.0_dp)
    do c = 1, 3
      PetscCall(DMCreateGlobalVector(grid%da(c), fl%vel(c), ierr))
      PetscCall(VecDuplicate(fl%vel(c), fl%vel_star(c), ierr))
      if (.not. fl%direct) then
        PetscCall(VecDuplicate(fl%vel(c), fl%vel_star_old(c), ierr))
        PetscCall(VecDuplicate(fl%vel(c), fl%rhs(c), ierr))
        PetscCall(VecSet(fl%vel_star_old(c), 0.0_dp, ierr))
        PetscCall(PetscObjectSetName(fl%vel_star_old(c), trim(field_names(c))//'_star_old', ierr))
      end if
      if (fl%has_forcing) then
        PetscCall(VecDuplicate(fl%vel(c), fl%forcing(c), ierr))
      end if
      PetscCall(VecSet(fl%vel(c), 0.0_dp, ierr))
      PetscCall(VecSet(fl%vel_star(c), 0.0_dp, ierr))          ! written to checkpoints before it is set
      PetscCall(PetscObjectSetName(fl%vel(c), field_names(c), ierr))
      PetscCall(PetscObjectSetName(fl%vel_star(c), trim(field_names(c))//'_star', ierr))
    end do
    PetscCall(DMCreateGlobalVector(grid%da(FIELD_P), fl%pressure, ierr))
    PetscCall(VecDuplicate(fl%pressure, fl%phi, ierr))
    if (.not. fl%direct) then
      PetscCall(VecDuplicate(fl%pressure, fl%rhs_p, ierr))
    end if
    PetscCall(VecDuplicate(fl%pressure, fl%div_star, ierr))
    PetscCall(VecSet(fl%pressure, 0.0_dp, ierr))
    PetscCall(VecSet(fl%phi, 0.0_dp, ierr))
    PetscCall(PetscObjectSetName(fl%pressure, 'p', ierr))
    PetscCall(PetscObjectSetName(fl%phi, 'phi', ierr))

    ! -fluid_extrapolate 0: the warm start from u^n (for the comparison of doc/BENCHMARKS.md §10)
    PetscCall(PetscOptionsGetBool(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-fluid_extrapolate', fl%extrapolate, found, ierr))
    PetscCall(set_forcing(cfg, grid, fl, ierr))
    if (grid%lees_edwards) fl%sliding_jump = cfg%domain%shear_rate * cfg%domain%box(2)
    if (cfg%fluid%initial_flow == 'shear' .and. grid%walls) then
      PetscCall(set_linear_shear(grid, fl, fl%wall_speed, ierr))
    else if (cfg%fluid%initial_flow == 'shear' .and. grid%lees_edwards) then
      PetscCall(set_linear_shear(grid, fl, 0.5_dp * fl%sliding_jump(AT_END), ierr))
    end if

    ! Round-off floor of each solve: 100 machine epsilons of the right-hand side that a field of
    ! the reference speed U_ref = max(U_wall, a*gamma_dot) would give (before the h^3 row scaling),
    ! Helmholtz (Re/dt) U_ref per face, Poisson (Re/dt) U_ref/h per cell, times sqrt(cells) for
    ! the 2-norm. It stops solves whose right-hand side is pure round-off (the steady Couette
    ! profile gives v, w and phi right-hand sides of order 1e-16) at zero iterations; it is
    ! 2e-14 of a physically sized right-hand side, below any tolerance worth asking for.
    u_ref = max(abs(fl%wall_speed), 1.0_dp)
    cells = real(grid%n(1), dp) * real(grid%n(2), dp) * real(grid%n(3), dp)
    do c = 1, 4
      tol = cfg%fluid%velocity_tolerance
      floor = 1.0e2_dp * epsilon(1.0_dp) * (fl%reynolds / fl%dt) * u_ref * sqrt(cells)
      if (c == FIELD_P) then
        tol = cfg%fluid%pressure_tolerance
        floor = floor / grid%h
      end if
      PetscCall(solver_create(grid, c, tol, floor, fl%reynolds / fl%dt, fl%theta * fl%viscosity, fl%solver(c), ierr))
    end do
  end subroutine fluid_create

  ! Uniform body force plus, in verification runs, the manufactured-solution forcing.
  subroutine set_forcing(cfg, grid, fl, ierr)
    type(config_t), intent(in) :: cfg
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(inout) :: fl
    PetscErrorCode, intent(out) :: ierr
    PetscScalar, pointer :: f(:,:,:)
    integer :: c, i, j, k

    if (.not. fl%has_forcing) return   ! no forcing vectors: fluid_step adds zero (fluid_create)
    do c = 1, 3
      PetscCall(VecSet(fl%forcing(c), cfg%fluid%body_force(c), ierr))
      if (.not. cfg%verification%manufactured_solution) cycle
      PetscCall(DMDAVecGetArrayF90(grid%da(c), fl%forcing(c), f, ierr))
      do k = grid%lo(3), grid%hi(3)
        do j = grid%lo(2), grid%hi(2)
          do i = grid%lo(1), grid%hi(1)
            f(i, j, k) = mms_forcing(c, grid_position(grid, c, i, j, k), grid%box, grid%walls, fl%viscosity)
          end do
        end do
      end do
      PetscCall(DMDAVecRestoreArrayF90(grid%da(c), fl%forcing(c), f, ierr))
    end do
  end subroutine set_forcing

  ! u = U (2y/Ly - 1): the steady Couette profile, exact on the grid (the wall ghosts reproduce it,
  ! and so do the Lees-Edwards ghosts, U = gamma_dot Ly/2).
  subroutine set_linear_shear(grid, fl, speed, ierr)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(inout) :: fl
    real(dp), intent(in) :: speed
    PetscErrorCode, intent(out) :: ierr
    PetscScalar, pointer :: a(:,:,:)
    integer :: j
    real(dp) :: y
    PetscCall(DMDAVecGetArrayF90(grid%da(FIELD_U), fl%vel(FIELD_U), a, ierr))
    do j = grid%lo(2), grid%hi(2)
      y = (j + 0.5_dp) * grid%h
      a(:, j, :) = speed * (2.0_dp * y / grid%box(2) - 1.0_dp)
    end do
    PetscCall(DMDAVecRestoreArrayF90(grid%da(FIELD_U), fl%vel(FIELD_U), a, ierr))
  end subroutine set_linear_shear

  ! Wall velocity seen by component c at the bottom (side = -1) or top (side = +1) wall.
  pure real(dp) function wall_velocity(fl, c, side)
    type(fluid_t), intent(in) :: fl
    integer, intent(in) :: c, side
    wall_velocity = 0.0_dp
    if (c == FIELD_U) wall_velocity = side * fl%wall_speed
  end function wall_velocity

  ! Ghosted copy of a face field with the wall ghosts of cell-centred-in-y components set to
  ! 2 U_wall - x_0 (second order, doc/METHOD.md §2.1). v needs nothing: its wall face holds 0.
  ! The wall ghosts are set above and below the owned (i, k) only: the 7-point stencil reads
  ! nothing else there, and the star-stencil exchange leaves the edge ghosts beside them unfilled
  ! (mod_grid, doc/DESIGN.md "Ghost layers").
  ! With Lees-Edwards the rows across y = 0 and y = Ly are the boundary's images at the instant
  ! `at` (AT_START or AT_END, default AT_END: the state after the step; sliding_ghosts).
  ! local: a local vector of grid%da(c) (borrowed by the caller).
  subroutine ghosted(grid, fl, c, global, local, ierr, at)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(in) :: fl
    integer, intent(in) :: c
    Vec, intent(in) :: global
    Vec, intent(inout) :: local
    PetscErrorCode, intent(out) :: ierr
    integer, intent(in), optional :: at
    PetscScalar, pointer :: a(:,:,:)
    integer :: ny, lo(3), hi(3), instant
    PetscCall(DMGlobalToLocalBegin(grid%da(c), global, INSERT_VALUES, local, ierr))
    PetscCall(DMGlobalToLocalEnd(grid%da(c), global, INSERT_VALUES, local, ierr))
    if (grid%lees_edwards) then
      instant = AT_END
      if (present(at)) instant = at
      PetscCall(DMDAVecGetArrayF90(grid%da(c), local, a, ierr))
      call sliding_ghosts(grid, c, a, fl%sliding_offset(instant), fl%sliding_jump(instant))
      PetscCall(DMDAVecRestoreArrayF90(grid%da(c), local, a, ierr))
      return
    end if
    if (.not. grid%walls .or. c == FIELD_V .or. c == FIELD_P) return
    ny = grid%n(2)
    lo = grid%lo
    hi = grid%hi
    PetscCall(DMDAVecGetArrayF90(grid%da(c), local, a, ierr))
    if (grid%lo(2) == 0) a(lo(1):hi(1), -1, lo(3):hi(3)) = 2.0_dp * wall_velocity(fl, c, -1) &
                                                          - a(lo(1):hi(1), 0, lo(3):hi(3))
    if (grid%hi(2) == ny - 1) a(lo(1):hi(1), ny, lo(3):hi(3)) = 2.0_dp * wall_velocity(fl, c, +1) &
                                                               - a(lo(1):hi(1), ny - 1, lo(3):hi(3))
    PetscCall(DMDAVecRestoreArrayF90(grid%da(c), local, a, ierr))
  end subroutine ghosted

  ! The ghosted copy of a face field (fluid_step's, at the end of the last step): for readers
  ! outside the fluid step (the output's cell-centred averages). Collective.
  subroutine fluid_ghosted(grid, fl, c, global, local, ierr)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(in) :: fl
    integer, intent(in) :: c
    Vec, intent(in) :: global
    Vec, intent(inout) :: local
    PetscErrorCode, intent(out) :: ierr
    PetscCall(ghosted(grid, fl, c, global, local, ierr))
  end subroutine fluid_ghosted

  ! The Lees-Edwards ghost rows of component c in its ghosted array a (doc/METHOD.md §2.4): below
  ! the box (j = -1) the top row read at x + delta, above it (j = n(2)) the bottom row read at
  ! x - delta (mod_sliding_boundary), and for u the image's velocity -+ gamma_dot Ly (jump) added:
  ! u(x, y -+ Ly) = u(x +- delta, y) -+ gamma_dot Ly. The grid is split in z only (mod_grid), so
  ! the rows are this rank's; their x ghosts are the periodic ones. The star stencil's reads are
  ! these rows above and below the owned (i, k); edge ghosts beside them (k outside the slab) are
  ! not set.
  subroutine sliding_ghosts(grid, c, a, offset, jump)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: c
    PetscScalar, intent(inout) :: a(grid%glo(1):, grid%glo(2):, grid%glo(3):)
    real(dp), intent(in) :: offset, jump
    real(dp), allocatable :: rows(:, :)
    real(dp) :: image_velocity
    integer :: nx, ny, k, lo, hi
    nx = grid%n(1)
    ny = grid%n(2)
    lo = grid%lo(3)
    hi = grid%hi(3)
    image_velocity = 0.0_dp
    if (c == FIELD_U) image_velocity = jump
    allocate(rows(0:nx - 1, lo:hi))
    do k = lo, hi
      rows(:, k) = a(0:nx - 1, ny - 1, k)
    end do
    call sliding_shift_rows(rows, offset / grid%h)
    do k = lo, hi
      a(0:nx - 1, -1, k) = rows(:, k) - image_velocity
    end do
    do k = lo, hi
      rows(:, k) = a(0:nx - 1, 0, k)
    end do
    call sliding_shift_rows(rows, -offset / grid%h)
    do k = lo, hi
      a(0:nx - 1, ny, k) = rows(:, k) + image_velocity
    end do
    a(-1, -1, lo:hi) = a(nx - 1, -1, lo:hi)
    a(nx, -1, lo:hi) = a(0, -1, lo:hi)
    a(-1, ny, lo:hi) = a(nx - 1, ny, lo:hi)
    a(nx, ny, lo:hi) = a(0, ny, lo:hi)
  end subroutine sliding_ghosts

  ! The Lees-Edwards boundary of the step to come (doc/METHOD.md §2.4): its offset delta [a] and
  ! image velocity gamma_dot Ly at t_n and at t_{n+1}.
  subroutine fluid_set_sliding(fl, offset_start, offset_end, jump_start, jump_end)
    type(fluid_t), intent(inout) :: fl
    real(dp), intent(in) :: offset_start, offset_end, jump_start, jump_end
    fl%sliding_offset = [offset_start, offset_end]
    fl%sliding_jump = [jump_start, jump_end]
  end subroutine fluid_set_sliding

  ! source: an extra force density on the u, v, w faces (the fictitious-domain Lambda^n).
  subroutine fluid_step(grid, fl, ierr, source)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(inout) :: fl
    PetscErrorCode, intent(out) :: ierr
    Vec, intent(in), optional :: source(3)
    PetscScalar, pointer :: a(:,:,:), p(:,:,:), r(:,:,:), f(:,:,:), ph(:,:,:), ds(:,:,:)
    integer :: c, i, j, k, e(3), ny
    real(dp) :: h, mass, lap, explicit, implicit, wall_term, rate, force
    PetscReal :: local_max, global_max
    PetscErrorCode :: mpierr
    Vec :: loc_p, loc_c, rhs, rhs_p

    h = grid%h
    ny = grid%n(2)
    mass = fl%reynolds / fl%dt
    explicit = (1.0_dp - fl%theta) * fl%viscosity
    implicit = fl%theta * fl%viscosity

    ! 1. provisional velocity; with the direct solves the right-hand side is built in vel_star,
    ! which the solve then overwrites with u*
    PetscCall(DMGetLocalVector(grid%da(FIELD_P), loc_p, ierr))
    PetscCall(ghosted(grid, fl, FIELD_P, fl%pressure, loc_p, ierr, AT_START))
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_P), loc_p, p, ierr))
    ! the implicit solves and the projection see the boundary at t_{n+1}
    if (grid%lees_edwards) call solver_set_sliding_shift(fl%sliding_offset(AT_END) / h)
    force = 0.0_dp
    do c = 1, 3
      e = 0
      e(c) = 1
      if (fl%direct) then
        rhs = fl%vel_star(c)
      else
        rhs = fl%rhs(c)
      end if
      PetscCall(DMGetLocalVector(grid%da(c), loc_c, ierr))
      PetscCall(ghosted(grid, fl, c, fl%vel(c), loc_c, ierr, AT_START))
      PetscCall(DMDAVecGetArrayReadF90(grid%da(c), loc_c, a, ierr))
      PetscCall(DMDAVecGetArrayF90(grid%da(c), rhs, r, ierr))
      if (fl%has_forcing) then
        PetscCall(DMDAVecGetArrayReadF90(grid%da(c), fl%forcing(c), f, ierr))
      end if
      do k = grid%lo(3), grid%hi(3)
        do j = grid%lo(2), grid%hi(2)
          do i = grid%lo(1), grid%hi(1)
            if (grid_fixed_row(grid, c, j)) then
              r(i, j, k) = 0.0_dp
              cycle
            end if
            lap = (a(i-1, j, k) + a(i+1, j, k) + a(i, j-1, k) + a(i, j+1, k) + a(i, j, k-1) &
                 + a(i, j, k+1) - 6.0_dp * a(i, j, k)) / h**2
            ! without forcing vectors the force is +0.0, added all the same (the same bits)
            if (fl%has_forcing) force = f(i, j, k)
            r(i, j, k) = mass * a(i, j, k) + explicit * lap &
                 - (p(i, j, k) - p(i - e(1), j - e(2), k - e(3))) / h + force
            ! implicit half of the wall ghost 2 U_w - x_0: its U_w part is known
            if (grid%walls .and. c /= FIELD_V) then
              wall_term = 0.0_dp
              if (j == 0) wall_term = 2.0_dp * wall_velocity(fl, c, -1)
              if (j == ny - 1) wall_term = 2.0_dp * wall_velocity(fl, c, +1)
              r(i, j, k) = r(i, j, k) + implicit * wall_term / h**2
            end if
            ! Lees-Edwards: the known part of u's image across the boundary at t_{n+1},
            ! -+ gamma_dot Ly below and above (sliding_ghosts)
            if (grid%lees_edwards .and. c == FIELD_U) then
              if (j == 0) r(i, j, k) = r(i, j, k) - implicit * fl%sliding_jump(AT_END) / h**2
              if (j == ny - 1) r(i, j, k) = r(i, j, k) + implicit * fl%sliding_jump(AT_END) / h**2
            end if
          end do
        end do
      end do
      if (fl%has_forcing) then
        PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), fl%forcing(c), f, ierr))
      end if
      PetscCall(DMDAVecRestoreArrayF90(grid%da(c), rhs, r, ierr))
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), loc_c, a, ierr))
      PetscCall(DMRestoreLocalVector(grid%da(c), loc_c, ierr))
      if (present(source)) then
        PetscCall(VecAXPY(rhs, 1.0_dp, source(c), ierr))
        ! the wall row of v stays a fixed row (v = 0): a particle never forces it
      end if
      if (fl%direct) then
        ! exact solves need no guess, and may solve in place: u*^n is kept only for the Krylov
        ! path's extrapolation
        PetscCall(solver_solve(fl%solver(c), rhs, fl%vel_star(c), ierr))
      else if (fl%star_history == STAR_HISTORY_FULL .and. fl%extrapolate) then
        ! vel_star_old := 2 u*^n - u*^{n-1}, then swapped: the guess in vel_star, u*^n in vel_star_old
        PetscCall(VecAXPBY(fl%vel_star_old(c), 2.0_dp, -1.0_dp, fl%vel_star(c), ierr))
        PetscCall(VecSwap(fl%vel_star_old(c), fl%vel_star(c), ierr))
        ! u^n where it already solves the step (a settled flow: no drift, mod_solvers)
        PetscCall(solver_solve(fl%solver(c), fl%rhs(c), fl%vel_star(c), ierr, settled=fl%vel(c)))
      else
        PetscCall(VecCopy(fl%vel_star(c), fl%vel_star_old(c), ierr))
        PetscCall(VecCopy(fl%vel(c), fl%vel_star(c), ierr))    ! warm start from u^n
        PetscCall(solver_solve(fl%solver(c), fl%rhs(c), fl%vel_star(c), ierr))
      end if
    end do
    ! (direct solves keep no history: a Krylov run restarted from their checkpoint starts from u^n)
    if (.not. fl%direct) fl%star_history = min(STAR_HISTORY_FULL, fl%star_history + 1)
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_P), loc_p, p, ierr))
    ! returned before the divergence borrows three: at most three ghosted work vectors at once
    PetscCall(DMRestoreLocalVector(grid%da(FIELD_P), loc_p, ierr))

    ! 2. pressure increment: -lap phi = -(Re/dt) div u* (the direct solve in place in phi)
    PetscCall(divergence(grid, fl, fl%vel_star, fl%div_star, ierr))
    if (fl%direct) then
      rhs_p = fl%phi
    else
      rhs_p = fl%rhs_p
    end if
    PetscCall(VecAXPBY(rhs_p, -mass, 0.0_dp, fl%div_star, ierr))
    PetscCall(solver_solve(fl%solver(FIELD_P), rhs_p, fl%phi, ierr))

    ! 3. projection, with the rate of change for steady-state detection
    PetscCall(DMGetLocalVector(grid%da(FIELD_P), loc_p, ierr))
    PetscCall(ghosted(grid, fl, FIELD_P, fl%phi, loc_p, ierr))
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_P), loc_p, ph, ierr))
    local_max = 0.0_dp
    do c = 1, 3
      e = 0
      e(c) = 1
      PetscCall(DMDAVecGetArrayF90(grid%da(c), fl%vel(c), a, ierr))
      PetscCall(DMDAVecGetArrayReadF90(grid%da(c), fl%vel_star(c), r, ierr))
      do k = grid%lo(3), grid%hi(3)
        do j = grid%lo(2), grid%hi(2)
          do i = grid%lo(1), grid%hi(1)
            if (grid_fixed_row(grid, c, j)) cycle
            rate = r(i, j, k) - fl%dt / fl%reynolds * (ph(i, j, k) - ph(i - e(1), j - e(2), k - e(3))) / h
            local_max = max(local_max, abs(rate - a(i, j, k)))
            a(i, j, k) = rate
          end do
        end do
      end do
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), fl%vel_star(c), r, ierr))
      PetscCall(DMDAVecRestoreArrayF90(grid%da(c), fl%vel(c), a, ierr))
    end do
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_P), loc_p, ph, ierr))
    PetscCall(DMRestoreLocalVector(grid%da(FIELD_P), loc_p, ierr))
    call MPI_Allreduce(local_max, global_max, 1, MPIU_REAL, MPI_MAX, PETSC_COMM_WORLD, mpierr)
    fl%max_rate = global_max / fl%dt

    ! 4. rotational pressure update
    PetscCall(DMDAVecGetArrayF90(grid%da(FIELD_P), fl%pressure, p, ierr))
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_P), fl%phi, ph, ierr))
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_P), fl%div_star, ds, ierr))
    p = p + ph - implicit * ds
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_P), fl%div_star, ds, ierr))
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_P), fl%phi, ph, ierr))
    PetscCall(DMDAVecRestoreArrayF90(grid%da(FIELD_P), fl%pressure, p, ierr))

    PetscCall(diagnostics(grid, fl, ierr))
  end subroutine fluid_step

  ! Stress control of the pure fluid (doc/METHOD.md §7.4): the step is affine in the wall speed U_w
  ! (it enters the right-hand side of step 1 and the wall stresses only, linearly), so what one unit
  ! of U_w adds to any step of the run is one step of the same fluid from rest without forcing, the
  ! walls at -+1. fl: a fluid made by fluid_create for this run; it is set so and takes that step,
  ! and then holds the response (u, p^{n+1/2}, phi, u*, the wall stresses). Collective.
  subroutine fluid_unit_response(grid, fl, ierr)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(inout) :: fl
    PetscErrorCode, intent(out) :: ierr
    integer :: c
    ! vel_star_old exists only on the Krylov path and forcing only with a forcing (fluid_create):
    ! what exists is zeroed, so the response step runs from rest without forcing
    do c = 1, 3
      PetscCall(VecSet(fl%vel(c), 0.0_dp, ierr))
      PetscCall(VecSet(fl%vel_star(c), 0.0_dp, ierr))
      if (.not. fl%direct) then
        PetscCall(VecSet(fl%vel_star_old(c), 0.0_dp, ierr))
      end if
      if (fl%has_forcing) then
        PetscCall(VecSet(fl%forcing(c), 0.0_dp, ierr))
      end if
    end do
    PetscCall(VecSet(fl%pressure, 0.0_dp, ierr))
    PetscCall(VecSet(fl%phi, 0.0_dp, ierr))
    fl%star_history = 0
    fl%wall_speed = 1.0_dp
    ! Lees-Edwards: the response to a unit rate, the boundary's jump Ly (its offset does not
    ! matter: the response does not depend on x)
    if (grid%lees_edwards) call fluid_set_sliding(fl, 0.0_dp, 0.0_dp, grid%box(2), grid%box(2))
    PetscCall(fluid_step(grid, fl, ierr))
  end subroutine fluid_unit_response

  ! fl after its step plus factor times the unit response of fluid_unit_response: the step as if
  ! its walls had moved factor faster (velocity, pressure, increment, provisional velocity, wall
  ! speed, and the diagnostics, wall stresses included, of the result). Collective.
  subroutine fluid_add_response(grid, fl, response, factor, ierr)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(inout) :: fl
    type(fluid_t), intent(in) :: response
    real(dp), intent(in) :: factor
    PetscErrorCode, intent(out) :: ierr
    integer :: c
    do c = 1, 3
      PetscCall(VecAXPY(fl%vel(c), factor, response%vel(c), ierr))
      PetscCall(VecAXPY(fl%vel_star(c), factor, response%vel_star(c), ierr))
    end do
    PetscCall(VecAXPY(fl%pressure, factor, response%pressure, ierr))
    PetscCall(VecAXPY(fl%phi, factor, response%phi, ierr))
    fl%wall_speed = fl%wall_speed + factor * response%wall_speed
    PetscCall(diagnostics(grid, fl, ierr))
  end subroutine fluid_add_response

  ! div of a face field at the cell centres: (u(i+1)-u(i) + v(j+1)-v(j) + w(k+1)-w(k))/h.
  ! With walls, v(n) is the periodic image of v(0) = 0: the top wall; with Lees-Edwards the image
  ! of v(0) across the sliding boundary (sliding_ghosts).
  subroutine divergence(grid, fl, vel, div, ierr)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(in) :: fl
    Vec, intent(in) :: vel(3)
    Vec, intent(inout) :: div
    PetscErrorCode, intent(out) :: ierr
    PetscScalar, pointer :: u(:,:,:), v(:,:,:), w(:,:,:), d(:,:,:)
    Vec :: loc(3)
    integer :: i, j, k
    do i = 1, 3
      PetscCall(DMGetLocalVector(grid%da(i), loc(i), ierr))
      if (i == FIELD_V .and. grid%lees_edwards) then
        PetscCall(ghosted(grid, fl, i, vel(i), loc(i), ierr))
      else
        PetscCall(DMGlobalToLocalBegin(grid%da(i), vel(i), INSERT_VALUES, loc(i), ierr))
        PetscCall(DMGlobalToLocalEnd(grid%da(i), vel(i), INSERT_VALUES, loc(i), ierr))
      end if
    end do
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_U), loc(FIELD_U), u, ierr))
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_V), loc(FIELD_V), v, ierr))
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_W), loc(FIELD_W), w, ierr))
    PetscCall(DMDAVecGetArrayF90(grid%da(FIELD_P), div, d, ierr))
    do k = grid%lo(3), grid%hi(3)
      do j = grid%lo(2), grid%hi(2)
        do i = grid%lo(1), grid%hi(1)
          d(i, j, k) = (u(i+1, j, k) - u(i, j, k) + v(i, j+1, k) - v(i, j, k) &
                      + w(i, j, k+1) - w(i, j, k)) / grid%h
        end do
      end do
    end do
    PetscCall(DMDAVecRestoreArrayF90(grid%da(FIELD_P), div, d, ierr))
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_W), loc(FIELD_W), w, ierr))
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_V), loc(FIELD_V), v, ierr))
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_U), loc(FIELD_U), u, ierr))
    do i = 3, 1, -1
      PetscCall(DMRestoreLocalVector(grid%da(i), loc(i), ierr))
    end do
  end subroutine divergence

  ! Divergence of u^{n+1} relative to max|u|/h, and the mean shear stress on each wall,
  ! tau = eta du/dy with du/dy = (u_0 - U_bottom)/(h/2) at y = 0 and (U_top - u_{n-1})/(h/2).
  subroutine diagnostics(grid, fl, ierr)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(inout) :: fl
    PetscErrorCode, intent(out) :: ierr
    PetscScalar, pointer :: u(:,:,:)
    PetscReal :: dmax, umax, c_max, sums(2), tot(2)
    PetscErrorCode :: mpierr
    integer :: c, ny

    PetscCall(divergence(grid, fl, fl%vel, fl%div_star, ierr))
    PetscCall(VecNorm(fl%div_star, NORM_INFINITY, dmax, ierr))
    umax = 0.0_dp
    do c = 1, 3
      PetscCall(VecNorm(fl%vel(c), NORM_INFINITY, c_max, ierr))
      umax = max(umax, c_max)
    end do
    fl%divergence = 0.0_dp
    if (umax > 0.0_dp) fl%divergence = dmax * grid%h / umax

    fl%tau_bottom = 0.0_dp
    fl%tau_top = 0.0_dp
    if (grid%lees_edwards) then
      PetscCall(sliding_shear_stress(grid, fl, ierr))
      return
    end if
    if (.not. grid%walls) return
    ny = grid%n(2)
    sums = 0.0_dp
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_U), fl%vel(FIELD_U), u, ierr))
    if (grid%lo(2) == 0) sums(1) = sum(u(:, 0, :) - wall_velocity(fl, FIELD_U, -1))
    if (grid%hi(2) == ny - 1) sums(2) = sum(wall_velocity(fl, FIELD_U, +1) - u(:, ny - 1, :))
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_U), fl%vel(FIELD_U), u, ierr))
    call MPI_Allreduce(sums, tot, 2, MPIU_REAL, MPI_SUM, PETSC_COMM_WORLD, mpierr)
    tot = tot * fl%viscosity / (0.5_dp * grid%h) / real(grid%n(1) * grid%n(3), dp)
    fl%tau_bottom = tot(1)
    fl%tau_top = tot(2)
  end subroutine diagnostics

  ! Lees-Edwards: the mean viscous shear stress eta du/dy across the sliding boundary (between the
  ! first row and its image below), reported as both wall stresses. Its mean over the box is
  ! eta gamma_dot exactly (u - gamma_dot y is periodic in y up to a shift in x, which leaves
  ! x-means alone), so this is the fluid's part of the shear stress at y = 0 alone. Collective.
  subroutine sliding_shear_stress(grid, fl, ierr)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(inout) :: fl
    PetscErrorCode, intent(out) :: ierr
    PetscScalar, pointer :: u(:,:,:)
    Vec :: loc
    PetscReal :: local_sum, total
    PetscErrorCode :: mpierr
    PetscCall(DMGetLocalVector(grid%da(FIELD_U), loc, ierr))
    PetscCall(ghosted(grid, fl, FIELD_U, fl%vel(FIELD_U), loc, ierr))
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_U), loc, u, ierr))
    local_sum = sum(u(grid%lo(1):grid%hi(1), 0, grid%lo(3):grid%hi(3)) - u(grid%lo(1):grid%hi(1), -1, grid%lo(3):grid%hi(3)))
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_U), loc, u, ierr))
    PetscCall(DMRestoreLocalVector(grid%da(FIELD_U), loc, ierr))
    call MPI_Allreduce(local_sum, total, 1, MPIU_REAL, MPI_SUM, PETSC_COMM_WORLD, mpierr)
    fl%tau_bottom = total * fl%viscosity / grid%h / real(grid%n(1) * grid%n(3), dp)
    fl%tau_top = fl%tau_bottom
  end subroutine sliding_shear_stress

  ! Errors against the manufactured solution (plus the Couette shear, which needs no forcing):
  ! max over all velocity unknowns, and max and rms of the pressure with both means removed.
  ! The x-z plane mean of u at every cell row j (y = (j + 1/2) h): the mean velocity profile of
  ! the suspension (fluid, and the particles' rigid motion that the fictitious domain imposes on
  ! the faces they cover). Collective.
  subroutine fluid_mean_profile(grid, fl, profile, ierr)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(in) :: fl
    real(dp), intent(out) :: profile(0:)
    PetscErrorCode, intent(out) :: ierr
    PetscScalar, pointer :: u(:,:,:)
    real(dp), allocatable :: sums(:)
    PetscErrorCode :: mpierr
    integer :: j
    allocate(sums(0:grid%n(2) - 1))
    sums = 0.0_dp
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_U), fl%vel(FIELD_U), u, ierr))
    do j = grid%lo(2), grid%hi(2)
      sums(j) = sum(u(grid%lo(1):grid%hi(1), j, grid%lo(3):grid%hi(3)))
    end do
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_U), fl%vel(FIELD_U), u, ierr))
    call MPI_Allreduce(sums, profile, grid%n(2), MPIU_REAL, MPI_SUM, PETSC_COMM_WORLD, mpierr)
    profile = profile / real(grid%n(1) * grid%n(3), dp)
  end subroutine fluid_mean_profile

  subroutine fluid_destroy(fl, ierr)
    type(fluid_t), intent(inout) :: fl
    PetscErrorCode, intent(out) :: ierr
    integer :: c
    do c = 1, 3
      PetscCall(VecDestroy(fl%vel(c), ierr))
      PetscCall(VecDestroy(fl%vel_star(c), ierr))
      if (.not. fl%direct) then
        PetscCall(VecDestroy(fl%vel_star_old(c), ierr))
        PetscCall(VecDestroy(fl%rhs(c), ierr))
      end if
      if (fl%has_forcing) then
        PetscCall(VecDestroy(fl%forcing(c), ierr))
      end if
    end do
    do c = 1, 4
      PetscCall(solver_destroy(fl%solver(c), ierr))
    end do
    PetscCall(VecDestroy(fl%pressure, ierr))
    PetscCall(VecDestroy(fl%phi, ierr))
    if (.not. fl%direct) then
      PetscCall(VecDestroy(fl%rhs_p, ierr))
    end if
    PetscCall(VecDestroy(fl%div_star, ierr))
  end subroutine fluid_destroy

  ! The fluid's columns of the series: the wall stresses, the divergence after the projection, the
  ! rate of change and the iterations of each solve (doc/INPUT.md "&output").
  function fluid_columns(fl) result(c)
    type(fluid_t), intent(in) :: fl
    type(column_t), allocatable :: c(:)
    ! element by element: an array constructor of column_t leaks their values (gfortran 12)
    allocate(c(8))
    c(1) = column('tau_wall_bottom', fl%tau_bottom)
    c(2) = column('tau_wall_top', fl%tau_top)
    c(3) = column('divergence', fl%divergence)
    c(4) = column('rate_of_change', fl%max_rate)
    c(5) = column('iterations_u', fl%solver(1)%iterations)
    c(6) = column('iterations_v', fl%solver(2)%iterations)
    c(7) = column('iterations_w', fl%solver(3)%iterations)
    c(8) = column('iterations_p', fl%solver(4)%iterations)
  end function fluid_columns

  ! The fluid solvers' command-line options, checked before any work (each wrong one stops with
  ! one message): -fluid_solver, and with the transforms -fft_planner.
  subroutine fluid_options_check()
    integer :: plan
    if (direct_solves_wanted()) plan = fft_planner_flags()
  end subroutine fluid_options_check

  ! -bench_cold_poisson: time one pressure solve from a zero guess to 1e-8 (doc/BENCHMARKS.md),
  ! logged. The yardstick is the multigrid solve whatever solves the steps (-fluid_solver fft
  ! needs no KSP: one is made for it).
  subroutine fluid_bench_cold_poisson(grid, fl, ierr)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(inout) :: fl
    PetscErrorCode, intent(out) :: ierr
    type(solver_t) :: yardstick
    PetscBool :: wanted
    real(dp) :: seconds
    integer :: iterations
    character(len=120) :: text
    PetscCall(PetscOptionsHasName(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-bench_cold_poisson', wanted, ierr))
    if (.not. wanted) return
    if (fl%solver(FIELD_P)%direct) then
      PetscCall(solver_create(grid, FIELD_P, 1.0e-8_dp, 0.0_dp, 0.0_dp, 1.0_dp, yardstick, ierr, krylov=.true.))
      PetscCall(solver_cold_solve(yardstick, 1.0e-8_dp, seconds, iterations, ierr))
      PetscCall(solver_destroy(yardstick, ierr))
    else
      PetscCall(solver_cold_solve(fl%solver(FIELD_P), 1.0e-8_dp, seconds, iterations, ierr))
    end if
    write(text, '(a,f10.5,a,i0,a)') 'bench: cold Poisson solve to 1e-8:', seconds, ' s, ', iterations, ' iterations'
    call log_line(text)
  end subroutine fluid_bench_cold_poisson

end module mod_fluid
