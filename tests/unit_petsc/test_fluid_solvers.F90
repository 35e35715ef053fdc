! Invariant: each linear system of the fluid step (mod_solvers; mod_fft_solver's header) is solved
! exactly. For every field of a tiny MAC grid (8 x 6 x 4 cells by default; -test_cells nx,ny,nz),
! with walls in y and fully periodic, a chosen exact discrete field x* (pseudo-random, a function of
! the global index only, so every rank knows it everywhere: v = 0 on the wall face j = 0, p of zero
! mean) gives b = A x* through a stencil written here from the operators' documentation,
! independently of compute_operator and of the transforms:
!   u, v, w: A = mass I - diffusion lap   (mass = Re/dt = 10, diffusion = theta eta = 0.5)
!   p:       A = -lap
!   periodic in x and z (and y without walls); with walls: u, w ghost = -x_0 across a wall (DST-II),
!   p neighbour across a wall dropped (DCT-II), v = 0 on the wall face j = 0 = n_y (DST-I on the
!   n_y - 1 inner faces; the wall row of b is 0).
! Checks, per field and boundary kind:
!   1. the assembled Krylov operator (compute_operator, rows scaled by h^3) times x* is h^3 b:
!      the hand stencil and the code's operator are the same matrix (tolerance 1e-13: each row sums
!      7 terms of size <= (mass + 6 diffusion/h^2)|x| ~ 60 |x|, a few ulps of that against |b|
!      ~ 10 |x|, in the 2-norm);
!   2. the direct FFT solve (solver_create, the production path) returns x* to 1e-12 relative
!      (2-norm). A solve by orthogonal transforms has backward error O(eps log N), so the forward
!      error is at most ~ cond(A) eps log N: cond <= 1 + 12 diffusion/(mass h^2) = 10.6 for the
!      Helmholtz systems and 12/(4 sin^2(pi/(2 n_y))) = 45 for the Poisson one on 8 x 6 x 4 with
!      walls (it is printed), i.e. <= 1e-13;
!   3. the Krylov path (solver_create(..., krylov=.true.): CG with the default preconditioner for
!      the grid, Jacobi or multigrid) to rtol 1e-14 returns x* to 1e-12 relative: |x - x*|/|x*| <=
!      cond(A) |r|/|b| <= 45e-14;
!   4. the transform kinds match the boundary kinds: with walls, the Helmholtz system of u (ghost
!      -x_0, DST-II) solved with the transforms of p's boundary (DCT-II), and p's boundary's
!      Helmholtz system solved with u's transforms (DST-II), miss x* by O(1) (> 0.1 relative),
!      while each with its own kind meets 1e-12: a transform of the wrong kind cannot pass 2;
!   6. Lees-Edwards (doc/METHOD.md §2.4): y periodic up to the offset delta, the row across the
!      boundary read at x + delta (below) or x - delta (above) by trigonometric interpolation with
!      the Nyquist mode of an even row unshifted; the hand stencil computes each shifted neighbour by
!      its own direct Fourier sum (not FFTW, not mod_sliding_boundary). At delta = 0, 1.3 h,
!      2.71 h and Lx - 0.2 h (s = delta/h cells) the direct solve (the phase-ramped complex
!      transforms) returns x* of every field to 1e-12 relative (cond <= 10.6 and <= 12/(4 sin^2(pi/
!      n)) as for the periodic box: the twist only raises the y eigenvalues of the x-modes); and
!      mod_sliding_boundary's shift of a row equals the direct sum to 1e-13 of its largest value and
!      is undone by the shift by -delta to 1e-13 (the operator is unitary, which div(grad) across
!      the boundary needs). Told delta = 0, the solve misses the x* of 1.3 h by > 0.01 (the offset
!      is used). The Krylov path (mod_solvers' twisted operator, a shell over the assembled periodic
!      one, preconditioned by the periodic operator's multigrid or Jacobi) at every offset: its
!      operator times x* is h^3 b to 1e-13 (as check 1), and its solve to rtol 1e-14 returns x* to
!      1e-12 (as check 3: cond is the same bound); the iterations are printed. Told delta = 0, its
!      operator misses h^3 b by > 0.01.
!   5. structure (issue 45, memory per cell): with the direct solves the four fields share one DMDA,
!      and its application ordering is AOMEMORYSCALABLE (never a copy of the global ordering on
!      every rank).
! Every check is of a global quantity (reduced over the ranks): the program runs as a singleton
! (tests/run_tests.sh) and on 3 ranks (tests/regression/test_unit_petsc_ranks.sh, where 8 x 6 x 4
! leaves one rank without a z-slab of the transforms, and 8 x 6 x 6 gives the pressure its
! two-level cell-centred multigrid). Only rank 0 prints.
#include <petsc/finclude/petscksp.h>
program test_fluid_solvers
  use, intrinsic :: iso_fortran_env, only: output_unit
  use petscksp
  use petscdmda
  use mod_kinds, only: dp, pi
  use mod_params, only: config_t
  use mod_grid, only: grid_t, grid_create, grid_destroy, FIELD_U, FIELD_V, FIELD_P, field_names
  use mod_solvers, only: solver_t, solver_create, solver_solve, solver_destroy, fft_planner_flags, &
                         solver_set_sliding_shift
  use mod_fft_solver, only: fft_solver_t, fft_create, fft_solve, fft_destroy
  use mod_sliding_boundary, only: sliding_shift_rows
  use mod_unit_checks, only: check, check_below, finish
  implicit none

  real(dp), parameter :: mass = 10.0_dp, diffusion = 0.5_dp, h = 0.25_dp
  real(dp), parameter :: krylov_rtol = 1.0e-14_dp
  real(dp), parameter :: tol_operator = 1.0e-13_dp, tol_solve = 1.0e-12_dp
  PetscErrorCode :: ierr
  PetscMPIInt :: rank, nranks
  PetscInt :: cells(3), ncells
  PetscBool :: found
  type(config_t) :: cfg
  type(grid_t) :: grid
  integer :: pass
  character(len=64) :: scene
  real(dp) :: t0
  real(dp) :: shift = 0.0_dp    ! Lees-Edwards: the offset in cells the hand stencil uses

  PetscCallA(PetscInitialize(ierr))
  call MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr)
  call MPI_Comm_size(PETSC_COMM_WORLD, nranks, ierr)
  if (rank /= 0) open(unit=output_unit, file='/dev/null')     ! one copy of the verdicts
  t0 = MPI_Wtime()
  cells = [8, 6, 4]
  ncells = 3
  PetscCallA(PetscOptionsGetIntArray(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-test_cells', cells, ncells, found, ierr))

  do pass = 1, 3
    cfg%cells = cells
    cfg%h = h
    cfg%domain%box = cells * h
    cfg%walls = pass == 1
    cfg%lees_edwards = pass == 3
    cfg%domain%y_boundary = merge('walls   ', 'periodic', cfg%walls)
    if (cfg%lees_edwards) cfg%domain%y_boundary = 'lees-edwards'
    write(scene, '(i0,a,i0,a,i0,a,a,a,i0,a)') cells(1), ' x ', cells(2), ' x ', cells(3), ', ', &
         trim(cfg%domain%y_boundary), ', ', nranks, ' rank(s)'
    if (rank == 0) print '(2a)', '# ', trim(scene)
    PetscCallA(grid_create(cfg, grid, ierr))
    call test_layout(grid, trim(scene))
    if (grid%lees_edwards) then
      call test_sliding(grid, trim(scene))
    else
      call test_scene(grid, trim(scene))
    end if
    PetscCallA(grid_destroy(grid, ierr))
  end do
  if (rank == 0) print '(a,f0.2,a)', '# wall time ', MPI_Wtime() - t0, ' s'
  call finish('test_fluid_solvers')
  PetscCallA(PetscFinalize(ierr))

contains

  ! Structure (doc/DESIGN.md "One layout with the direct solves"): the direct solves put every
  ! field on one DMDA, and its application ordering, should anything ask for one, is the
  ! memory-scalable kind, not a copy of the global ordering on every rank.
  subroutine test_layout(grid, scene)
    type(grid_t), intent(in) :: grid
    character(len=*), intent(in) :: scene
    AO :: ao
    PetscBool :: scalable
    call check(grid%shared_layout, scene//': the direct solves share one DMDA among the four fields')
    PetscCallA(DMDAGetAO(grid%da(FIELD_P), ao, ierr))
    PetscCallA(PetscObjectTypeCompare(ao, AOMEMORYSCALABLE, scalable, ierr))
    call check(logical(scalable), scene//': the DMDA''s ordering is memory-scalable (AOMEMORYSCALABLE)')
  end subroutine test_layout

  ! The three checks of every field, and the transform kinds with walls.
  subroutine test_scene(grid, scene)
    type(grid_t), intent(in) :: grid
    character(len=*), intent(in) :: scene
    type(solver_t) :: direct, krylov
    Vec :: exact, rhs, x, work
    Mat :: A, P
    integer :: f
    real(dp) :: m, d, mean, err, cond
    PetscInt :: its
    character(len=200) :: what

    do f = FIELD_U, FIELD_P
      if (f == FIELD_P) then
        m = 0.0_dp
        d = 1.0_dp
      else
        m = mass
        d = diffusion
      end if
      mean = field_mean(grid, f)
      PetscCallA(DMCreateGlobalVector(grid%da(f), exact, ierr))
      PetscCallA(VecDuplicate(exact, rhs, ierr))
      PetscCallA(VecDuplicate(exact, x, ierr))
      PetscCallA(VecDuplicate(exact, work, ierr))
      call fill(grid, f, f, exact, .false., m, d, mean)
      call fill(grid, f, f, rhs, .true., m, d, mean)
      cond = condition_bound(grid, f, m, d)
      if (rank == 0) print '(3a,es9.2)', '# ', field_names(f), ': condition number bound ', cond

      ! 1. the code's assembled operator is the hand stencil
      PetscCallA(solver_create(grid, f, krylov_rtol, 0.0_dp, mass, diffusion, krylov, ierr, krylov=.true.))
      PetscCallA(KSPGetOperators(krylov%ksp, A, P, ierr))
      PetscCallA(MatMult(A, exact, work, ierr))
      PetscCallA(VecScale(work, 1.0_dp / grid%h**3, ierr))
      write(what, '(*(a))') scene, ', ', field_names(f), ': assembled operator (compute_operator) x* = hand stencil ', &
           'b (relative, 2-norm)'
      call check_below(trim(what), relative_difference(work, rhs), tol_operator)

      ! 2. the direct solve
      PetscCallA(solver_create(grid, f, krylov_rtol, 0.0_dp, mass, diffusion, direct, ierr))
      call check(direct%direct, scene//', '//field_names(f)//': solver_create takes the FFT path by default')
      PetscCallA(VecCopy(rhs, work, ierr))
      PetscCallA(VecSet(x, 0.0_dp, ierr))
      PetscCallA(solver_solve(direct, work, x, ierr))
      err = relative_difference(x, exact)
      write(what, '(*(a))') scene, ', ', field_names(f), ': FFT solve |x - x*|/|x*| (', trim(kind_name(grid, f)), ')'
      call check_below(trim(what), err, tol_solve)
      call check(rhs_unchanged(work, rhs), scene//', '//field_names(f)//': the FFT solve leaves b as it was')

      ! 3. the Krylov solve from zero
      PetscCallA(VecCopy(rhs, work, ierr))
      PetscCallA(VecSet(x, 0.0_dp, ierr))
      PetscCallA(solver_solve(krylov, work, x, ierr))
      PetscCallA(KSPGetIterationNumber(krylov%ksp, its, ierr))
      err = relative_difference(x, exact)
      write(what, '(6a,i0,a)') scene, ', ', field_names(f), ': Krylov solve (rtol 1e-14) |x - x*|/|x*| (', &
           trim(krylov_name(krylov)), ', ', its, ' iterations)'
      call check_below(trim(what), err, tol_solve)
      PetscCallA(solver_destroy(direct, ierr))
      PetscCallA(solver_destroy(krylov, ierr))
      PetscCallA(VecDestroy(exact, ierr))
      PetscCallA(VecDestroy(rhs, ierr))
      PetscCallA(VecDestroy(x, ierr))
      PetscCallA(VecDestroy(work, ierr))
    end do

    if (.not. grid%walls) return
    ! 4. the transform kinds against the boundary kinds: the Helmholtz system of field f with the
    ! boundary of f, solved with the transforms made for field g (u: DST-II, p: DCT-II)
    call kinds(grid, scene, FIELD_U, FIELD_U, .true.)
    call kinds(grid, scene, FIELD_P, FIELD_P, .true.)
    call kinds(grid, scene, FIELD_U, FIELD_P, .false.)
    call kinds(grid, scene, FIELD_P, FIELD_U, .false.)
  end subroutine test_scene

  ! The Helmholtz system of field f with f's boundary, solved with the transforms made for field g.
  subroutine kinds(grid, scene, f, g, match)
      type(grid_t), intent(in) :: grid
      character(len=*), intent(in) :: scene
      integer, intent(in) :: f, g
      logical, intent(in) :: match
      type(fft_solver_t) :: fft
      Vec :: exact, rhs, x
      real(dp) :: mean, err
      character(len=200) :: what
      mean = 0.0_dp
      if (f == FIELD_P) mean = field_mean(grid, f)
      PetscCallA(DMCreateGlobalVector(grid%da(f), exact, ierr))
      PetscCallA(VecDuplicate(exact, rhs, ierr))
      PetscCallA(VecDuplicate(exact, x, ierr))
      call fill(grid, f, f, exact, .false., mass, diffusion, mean)
      call fill(grid, f, f, rhs, .true., mass, diffusion, mean)
      PetscCallA(fft_create(grid, g, mass, diffusion, fft_planner_flags(), fft, ierr))
      PetscCallA(fft_solve(fft, rhs, x, ierr))
      err = relative_difference(x, exact)
      write(what, '(*(a))') scene, ': Helmholtz system with ', field_names(f), '''s boundary (', &
           trim(kind_name(grid, f)), ') solved with ', field_names(g), '''s transforms (', trim(kind_name(grid, g)), ')'
      if (match) then
        call check_below(trim(what)//': |x - x*|/|x*|', err, tol_solve)
      else
        call check(err > 0.1_dp, trim(what)//': misses x* by O(1), as it must')
        if (rank == 0) print '(a,es10.3)', '#   its relative error ', err
      end if
      PetscCallA(fft_destroy(fft, ierr))
      PetscCallA(VecDestroy(exact, ierr))
      PetscCallA(VecDestroy(rhs, ierr))
      PetscCallA(VecDestroy(x, ierr))
  end subroutine kinds

  function kind_name(grid, f) result(name)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: f
    character(len=40) :: name
    if (.not. grid%walls) then
      name = 'R2HC in x, y, z'
    else if (f == FIELD_P) then
      name = 'DCT-II in y'
    else if (f == FIELD_V) then
      name = 'DST-I in y'
    else
      name = 'DST-II in y'
    end if
  end function kind_name

  function krylov_name(s) result(name)
    type(solver_t), intent(in) :: s
    character(len=40) :: name
    PC :: pc
    PCType :: pc_type
    PetscCallA(KSPGetPC(s%ksp, pc, ierr))
    PetscCallA(PCGetType(pc, pc_type, ierr))
    name = 'CG + '//trim(pc_type)
  end function krylov_name

  ! 6. Lees-Edwards: the direct solves at several offsets, and the row shift itself.
  subroutine test_sliding(grid, scene)
    type(grid_t), intent(in) :: grid
    character(len=*), intent(in) :: scene
    real(dp), parameter :: shifts(4) = [0.0_dp, 1.3_dp, 2.71_dp, -0.2_dp]
    type(solver_t) :: direct, krylov
    Vec :: exact, rhs, x, work
    Mat :: A, P
    PetscInt :: its
    integer :: f, n, i, r
    real(dp) :: m, d, mean, err, worst_shift, worst_inverse
    real(dp), allocatable :: rows(:, :), hand(:, :)
    character(len=200) :: what

    do n = 1, size(shifts)
      shift = shifts(n)
      if (shift < 0.0_dp) shift = shift + grid%n(1)
      call solver_set_sliding_shift(shift)
      do f = FIELD_U, FIELD_P
        m = merge(0.0_dp, mass, f == FIELD_P)
        d = merge(1.0_dp, diffusion, f == FIELD_P)
        mean = field_mean(grid, f)
        PetscCallA(DMCreateGlobalVector(grid%da(f), exact, ierr))
        PetscCallA(VecDuplicate(exact, rhs, ierr))
        PetscCallA(VecDuplicate(exact, x, ierr))
        call fill(grid, f, f, exact, .false., m, d, mean)
        call fill(grid, f, f, rhs, .true., m, d, mean)
        PetscCallA(solver_create(grid, f, krylov_rtol, 0.0_dp, mass, diffusion, direct, ierr))
        PetscCallA(VecSet(x, 0.0_dp, ierr))
        PetscCallA(solver_solve(direct, rhs, x, ierr))
        err = relative_difference(x, exact)
        write(what, '(3a,f0.2,3a)') scene, ', offset ', '', shift, ' h, ', field_names(f), &
             ': FFT solve of the twisted system |x - x*|/|x*|'
        call check_below(trim(what), err, tol_solve)
        if (n == 2) then
          ! the solve must see the offset: told delta = 0 it misses the twisted x* at O(1)
          call solver_set_sliding_shift(0.0_dp)
          PetscCallA(VecSet(x, 0.0_dp, ierr))
          PetscCallA(solver_solve(direct, rhs, x, ierr))
          call solver_set_sliding_shift(shift)
          err = relative_difference(x, exact)
          write(what, '(3a)') scene, ', ', field_names(f)//': the solve told offset 0 misses the x* of 1.30 h '// &
               '(> 0.01 relative)'
          call check(err > 0.01_dp, trim(what))
        end if
        ! the Krylov path: its operator, then its solve from zero
        PetscCallA(solver_create(grid, f, krylov_rtol, 0.0_dp, mass, diffusion, krylov, ierr, krylov=.true.))
        PetscCallA(VecDuplicate(exact, work, ierr))
        PetscCallA(KSPGetOperators(krylov%ksp, A, P, ierr))
        PetscCallA(MatMult(A, exact, work, ierr))
        PetscCallA(VecScale(work, 1.0_dp / grid%h**3, ierr))
        write(what, '(3a,f0.2,3a)') scene, ', offset ', '', shift, ' h, ', field_names(f), &
             ': Krylov operator (twisted shell) x* = hand stencil b (relative, 2-norm)'
        call check_below(trim(what), relative_difference(work, rhs), tol_operator)
        if (n == 2) then
          call solver_set_sliding_shift(0.0_dp)
          PetscCallA(MatMult(A, exact, work, ierr))
          call solver_set_sliding_shift(shift)
          PetscCallA(VecScale(work, 1.0_dp / grid%h**3, ierr))
          write(what, '(3a)') scene, ', ', field_names(f)//': the Krylov operator told offset 0 misses b '// &
               'of 1.30 h (> 0.01 relative)'
          call check(relative_difference(work, rhs) > 0.01_dp, trim(what))
        end if
        PetscCallA(VecCopy(rhs, work, ierr))
        PetscCallA(VecSet(x, 0.0_dp, ierr))
        PetscCallA(solver_solve(krylov, work, x, ierr))
        PetscCallA(KSPGetIterationNumber(krylov%ksp, its, ierr))
        err = relative_difference(x, exact)
        write(what, '(3a,f0.2,5a,i0,a)') scene, ', offset ', '', shift, ' h, ', field_names(f), &
             ': Krylov solve (rtol 1e-14) |x - x*|/|x*| (', trim(krylov_name(krylov)), ', ', its, ' iterations)'
        call check_below(trim(what), err, tol_solve)
        PetscCallA(solver_destroy(krylov, ierr))
        PetscCallA(VecDestroy(work, ierr))
        PetscCallA(solver_destroy(direct, ierr))
        PetscCallA(VecDestroy(exact, ierr))
        PetscCallA(VecDestroy(rhs, ierr))
        PetscCallA(VecDestroy(x, ierr))
      end do
    end do

    ! the shift of rows (every rank the same rows: a pure kernel)
    allocate(rows(grid%n(1), 3), hand(grid%n(1), 3))
    worst_shift = 0.0_dp
    worst_inverse = 0.0_dp
    do n = 1, size(shifts)
      do r = 1, 3
        do i = 1, grid%n(1)
          rows(i, r) = exact_value(grid, FIELD_U, i - 1, r, 0, 0.0_dp)
          hand(i, r) = shifted_value(grid, FIELD_U, i - 1, r, 0, shifts(n), 0.0_dp)
        end do
      end do
      call sliding_shift_rows(rows, shifts(n))
      worst_shift = max(worst_shift, maxval(abs(rows - hand)) / maxval(abs(hand)))
      call sliding_shift_rows(rows, -shifts(n))
      do r = 1, 3
        do i = 1, grid%n(1)
          hand(i, r) = exact_value(grid, FIELD_U, i - 1, r, 0, 0.0_dp)
        end do
      end do
      worst_inverse = max(worst_inverse, maxval(abs(rows - hand)) / maxval(abs(hand)))
    end do
    call check_below(scene//': mod_sliding_boundary''s row shift = the direct Fourier sum (max relative)', &
                     worst_shift, 1.0e-13_dp)
    call check_below(scene//': the shift by -delta undoes the shift by delta (max relative)', worst_inverse, 1.0e-13_dp)
  end subroutine test_sliding

  ! The exact field of f in row (j, k) read at x_i + s h by trigonometric interpolation: the direct
  ! Fourier sum (1/n) sum_a x_a [1 + 2 sum_{m=1}^{(n-1)/2} cos(2 pi m (i + s - a)/n) + N], the
  ! Nyquist term N = cos(pi (i - a)) for even n (unshifted: doc/METHOD.md §2.4).
  real(dp) function shifted_value(grid, f, i, j, k, s, mean)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: f, i, j, k
    real(dp), intent(in) :: s, mean
    integer :: a, m, n
    real(dp) :: kernel
    n = grid%n(1)
    shifted_value = 0.0_dp
    do a = 0, n - 1
      kernel = 1.0_dp
      do m = 1, (n - 1) / 2
        kernel = kernel + 2.0_dp * cos(2.0_dp * pi * m * (i + s - a) / n)
      end do
      if (mod(n, 2) == 0) kernel = kernel + cos(pi * (i - a))
      shifted_value = shifted_value + exact_value(grid, f, a, j, k, mean) * kernel
    end do
    shifted_value = shifted_value / n
  end function shifted_value

  ! The exact field of f at global (i, j, k), wrapped periodically: pseudo-random in [-1, 1) minus
  ! mean; v is 0 on the wall face j = 0 (= n_y).
  real(dp) function exact_value(grid, f, i, j, k, mean)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: f, i, j, k
    real(dp), intent(in) :: mean
    integer :: a, b, c
    real(dp) :: t
    a = modulo(i, grid%n(1))
    b = modulo(j, grid%n(2))
    c = modulo(k, grid%n(3))
    if (grid%walls .and. f == FIELD_V .and. b == 0) then
      exact_value = 0.0_dp
      return
    end if
    t = sin(12.9898_dp * a + 78.233_dp * b + 37.719_dp * c + 4.1_dp * f) * 43758.5453_dp
    exact_value = 2.0_dp * (t - floor(t)) - 1.0_dp - mean
  end function exact_value

  ! The mean of the raw pseudo-random field of f (subtracted for p: the Poisson solution has zero
  ! mean). Every rank sums every cell: the grid is tiny.
  real(dp) function field_mean(grid, f)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: f
    integer :: i, j, k
    field_mean = 0.0_dp
    do k = 0, grid%n(3) - 1
      do j = 0, grid%n(2) - 1
        do i = 0, grid%n(1) - 1
          field_mean = field_mean + exact_value(grid, f, i, j, k, 0.0_dp)
        end do
      end do
    end do
    field_mean = field_mean / product(grid%n)
  end function field_mean

  ! (A x*)(i, j, k) by the hand stencil, A = m I - d lap with the boundary of field f (bc).
  real(dp) function hand_operator(grid, f, i, j, k, m, d, mean)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: f, i, j, k
    real(dp), intent(in) :: m, d, mean
    real(dp) :: x0, below, above, lap
    x0 = exact_value(grid, f, i, j, k, mean)
    lap = exact_value(grid, f, i + 1, j, k, mean) + exact_value(grid, f, i - 1, j, k, mean) - 2.0_dp * x0 + &
          exact_value(grid, f, i, j, k + 1, mean) + exact_value(grid, f, i, j, k - 1, mean) - 2.0_dp * x0
    below = exact_value(grid, f, i, j - 1, k, mean)
    above = exact_value(grid, f, i, j + 1, k, mean)
    if (grid%lees_edwards) then
      ! across the sliding boundary: the row read at x + delta below, x - delta above
      if (j == 0) below = shifted_value(grid, f, i, grid%n(2) - 1, k, shift, mean)
      if (j == grid%n(2) - 1) above = shifted_value(grid, f, i, 0, k, -shift, mean)
    end if
    if (grid%walls) then
      select case (f)
      case (FIELD_V)
        if (j == 0) then          ! the wall face: a fixed row, b = 0
          hand_operator = 0.0_dp
          return
        end if                    ! j = 1 and n_y - 1 see the wall's v = 0 through the wrap
      case (FIELD_P)              ! zero flux: the neighbour across the wall is dropped
        if (j == 0) below = x0
        if (j == grid%n(2) - 1) above = x0
      case default                ! u, w: ghost -x_0 (wall speed 0)
        if (j == 0) below = -x0
        if (j == grid%n(2) - 1) above = -x0
      end select
    end if
    lap = lap + below + above - 2.0_dp * x0
    hand_operator = m * x0 - d * lap / grid%h**2
  end function hand_operator

  ! Vec of field f's layout: the exact field of f (rhs false) or the hand stencil's A x* (rhs true).
  ! fbc: the field whose exact field and boundary are used (f's layout is the same for all).
  subroutine fill(grid, f, fbc, vec, rhs, m, d, mean)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: f, fbc
    Vec, intent(inout) :: vec
    logical, intent(in) :: rhs
    real(dp), intent(in) :: m, d, mean
    PetscScalar, pointer :: a(:, :, :)
    integer :: i, j, k
    PetscCallA(DMDAVecGetArrayF90(grid%da(f), vec, a, ierr))
    do k = grid%lo(3), grid%hi(3)
      do j = grid%lo(2), grid%hi(2)
        do i = grid%lo(1), grid%hi(1)
          if (rhs) then
            a(i, j, k) = hand_operator(grid, fbc, i, j, k, m, d, mean)
          else
            a(i, j, k) = exact_value(grid, fbc, i, j, k, mean)
          end if
        end do
      end do
    end do
    PetscCallA(DMDAVecRestoreArrayF90(grid%da(f), vec, a, ierr))
  end subroutine fill

  ! |x - y|_2 / |y|_2 over all ranks.
  real(dp) function relative_difference(x, y)
    Vec, intent(in) :: x, y
    Vec :: d
    PetscReal :: e, r
    PetscCallA(VecDuplicate(x, d, ierr))
    PetscCallA(VecWAXPY(d, -1.0_dp, y, x, ierr))
    PetscCallA(VecNorm(d, NORM_2, e, ierr))
    PetscCallA(VecNorm(y, NORM_2, r, ierr))
    PetscCallA(VecDestroy(d, ierr))
    relative_difference = e / r
  end function relative_difference

  logical function rhs_unchanged(x, y)
    Vec, intent(in) :: x, y
    PetscBool :: same
    PetscCallA(VecEqual(x, y, same, ierr))
    rhs_unchanged = same
  end function rhs_unchanged

  ! An upper bound on the 2-norm condition number of A (on the complement of p's constants): the
  ! largest eigenvalue of -lap is below 12/h^2; the smallest (nonzero for p) is the smallest of the
  ! three directions' first nonzero eigenvalue (mod_fft_solver's header).
  real(dp) function condition_bound(grid, f, m, d)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: f
    real(dp), intent(in) :: m, d
    real(dp) :: low
    if (f /= FIELD_P) then
      condition_bound = (m + d * 12.0_dp / grid%h**2) / m
      return
    end if
    low = 4.0_dp * min(sin(pi / grid%n(1))**2, sin(pi / grid%n(3))**2) / grid%h**2
    if (grid%walls) then
      low = min(low, 4.0_dp * sin(pi / (2.0_dp * grid%n(2)))**2 / grid%h**2)
    else
      low = min(low, 4.0_dp * sin(pi / grid%n(2))**2 / grid%h**2)
    end if
    condition_bound = 12.0_dp / grid%h**2 / low
  end function condition_bound
end program test_fluid_solvers
