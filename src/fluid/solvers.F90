! Linear solvers of the fluid step: one KSP per field, each with its own options prefix
! (u_, v_, w_ for the Helmholtz solves of the viscous step, p_ for the pressure Poisson solve).
!
! Defaults (CG, geometric multigrid on the DMDA hierarchy, tolerances from the deck) go into the
! options database only where the user gave nothing, then KSPSetFromOptions runs: the command line
! always wins, e.g. -p_pc_type hypre or -u_ksp_rtol 1e-12. Operators are rediscretised on every
! multigrid level by compute_operator, which knows the walls (see mod_grid for the layout); what it
! needs comes with each solver (operator_context_t, the callback's context), so solvers of
! different coefficients coexist.
! With a Lees-Edwards boundary (doc/METHOD.md §2.4) the Krylov solvers' operator is the twisted one
! (twisted_mult: the periodic stencil plus the shifted rows across y = 0 and y = Ly), preconditioned
! by multigrid (or Jacobi) of the periodic operator assembled as above.
#include <petsc/finclude/petscksp.h>
module mod_solvers
  use petscksp
  use petscdmda
  use, intrinsic :: iso_c_binding, only: C_INT
  use mod_kinds, only: dp
  use mod_grid, only: grid_t, FIELD_V, FIELD_P, field_names, direct_solves_wanted, ownership_index, &
                      grid_create_star_layout
  use mod_errors, only: fatal_error, log_line
  use mod_petsc_options, only: set_default_option
  use mod_fft_solver, only: fft_solver_t, fft_create, fft_solve, fft_destroy, fft_set_sliding_shift
  use mod_sliding_boundary, only: sliding_shift_rows
  implicit none
  private
  public :: solver_t, solver_create, solver_solve, solver_destroy
  public :: solver_cold_solve, fft_planner_flags, solver_set_sliding_shift

  ! What compute_operator needs to assemble a solver's operator on any multigrid level: PETSc
  ! hands it to the callback as its context (KSPSetComputeOperators), and DMCoarsen passes it on
  ! to the coarse levels. Helmholtz: mass*I - diffusion*lap; Poisson: -lap.
  type :: operator_context_t
    integer :: field = 0
    real(dp) :: mass = 0.0_dp
    real(dp) :: diffusion = 0.0_dp
    real(dp) :: box(3) = 1.0_dp     ! box lengths: the cell size of a level is box(1)/cells
    logical :: walls = .true.       ! walls at y = 0 and y = Ly
    ! Lees-Edwards, Krylov path: the assembled periodic operator (the preconditioner's) and the
    ! layout the twisted operator reads its rows with (twisted_mult)
    Mat :: periodic
    DM :: dm
  end type operator_context_t

  ! The twisted operators alive, found by their handle when PETSc calls twisted_mult (PETSc's
  ! Fortran binding of MatShellGetContext has no typed interface)
  type :: twisted_entry
    Mat :: shell
    type(operator_context_t), pointer :: context => null()
  end type twisted_entry
  type(twisted_entry), save :: twisted(8)

  ! The Lees-Edwards offset delta/h of the solves to come (solver_set_sliding_shift)
  real(dp), save :: sliding_shift = 0.0_dp

  type :: solver_t
    KSP :: ksp
    integer :: field = 0
    integer :: iterations = 0       ! of the last solve
    logical :: singular = .false.   ! pressure: constant null space
    real(dp) :: cell_volume = 1.0_dp   ! rows are scaled by the cell volume (see compute_operator)
    MatNullSpace :: nullspace
    logical :: direct = .false.     ! solved by fast transforms (mod_fft_solver), no KSP
    ! a Krylov solver beside the direct solves' shared box layout has its own star DMDA (mod_grid)
    logical :: owns_dm = .false.
    DM :: dm
    logical :: sliding = .false.    ! Krylov with Lees-Edwards: the operator is the shell `twisted_op`
    Mat :: twisted_op
    type(fft_solver_t) :: fft
    ! the callback's context, on the heap: PETSc keeps its address, which must not move when the
    ! solver_t is copied or its holder reallocated
    type(operator_context_t), pointer :: context => null()
  end type solver_t

contains

  ! rtol: relative tolerance from the deck. atol: the residual norm at which the solve stops
  ! whatever |b| is; the caller sets it at round-off level of a physically sized right-hand side,
  ! so a right-hand side that is itself round-off (a steady state) costs no iterations.
  ! mass, diffusion: the Helmholtz operator mass*I - diffusion*lap of a velocity field (mass =
  ! Re/dt, diffusion = theta*eta: the implicit part of the viscous step, doc/METHOD.md §2.2; the
  ! pressure's Poisson operator does not use them). krylov, optional (its value is not read): a
  ! Krylov solver whatever -fluid_solver says (the multigrid yardstick of -bench_cold_poisson).
  subroutine solver_create(grid, field, rtol, atol, mass, diffusion, s, ierr, krylov)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: field
    real(dp), intent(in) :: rtol, atol, mass, diffusion
    type(solver_t), intent(inout) :: s
    PetscErrorCode, intent(out) :: ierr
    logical, intent(in), optional :: krylov
    character(len=3) :: prefix
    character(len=32) :: text

    if (.not. associated(s%context)) allocate(s%context)
    s%context = operator_context_t(field=field, mass=mass, diffusion=diffusion, box=grid%box, walls=grid%walls)
    s%field = field
    s%singular = (field == FIELD_P)
    s%cell_volume = grid%h**3
    s%direct = .false.
    if (.not. present(krylov)) then
      s%direct = direct_solves_wanted()
    end if
    if (s%direct) then
      ! the operators have constant coefficients on a uniform grid: solved exactly by transforms
      if (s%singular) then
        PetscCall(fft_create(grid, field, 0.0_dp, 1.0_dp, fft_planner_flags(), s%fft, ierr))
      else
        PetscCall(fft_create(grid, field, s%context%mass, s%context%diffusion, fft_planner_flags(), s%fft, ierr))
      end if
      return
    end if
    prefix = '-'//field_names(field)//'_'
    PetscCall(set_default_option(prefix//'ksp_type', 'cg', ierr))
    PetscCall(set_default_option(prefix//'ksp_norm_type', 'unpreconditioned', ierr))
    write(text, '(es12.5)') rtol
    PetscCall(set_default_option(prefix//'ksp_rtol', trim(adjustl(text)), ierr))
    write(text, '(es12.5)') atol * s%cell_volume
    PetscCall(set_default_option(prefix//'ksp_atol', trim(adjustl(text)), ierr))
    PetscCall(set_default_option(prefix//'ksp_max_it', '1000', ierr))
    ! The warm start can hold a residual far above |b| (decaying increments): no divergence test.
    PetscCall(set_default_option(prefix//'ksp_divtol', '1e100', ierr))
    if (.not. s%singular .and. jacobi_suffices(s%context, grid%h)) then
      ! A well-conditioned Helmholtz operator: point Jacobi CG beats multigrid (doc/BENCHMARKS.md §7)
      PetscCall(set_default_option(prefix//'pc_type', 'jacobi', ierr))
    else if (grid%mg_levels >= 2) then
      PetscCall(set_default_option(prefix//'pc_type', 'mg', ierr))
      ! One smoothing sweep per level instead of PETSc's two: the same number of V-cycles at half
      ! the smoothing cost (pressure: 15 iterations either way; doc/BENCHMARKS.md §7).
      PetscCall(set_default_option(prefix//'mg_levels_ksp_max_it', '1', ierr))
      ! The Chebyshev smoothers estimate eigenvalues with GMRES by default, which keeps ~12
      ! Krylov vectors per level and solver; the operators are SPD, so CG estimates as well with
      ! 4 (-20 % memory, same iterations: doc/BENCHMARKS.md). Not the singular pressure operator:
      ! CG's estimate on it broke down in 3 of 12 runs of test_fluid_solvers on 3 ranks (periodic
      ! and Lees-Edwards boxes; a division by zero in the debug build), GMRES's in none of 12.
      if (.not. s%singular) then
        PetscCall(set_default_option(prefix//'mg_levels_esteig_ksp_type', 'cg', ierr))
      end if
      write(text, '(i0)') grid%mg_levels
      PetscCall(set_default_option(prefix//'pc_mg_levels', trim(text), ierr))
    else
      ! No factor of 2 to coarsen by: algebraic multigrid instead.
      PetscCall(set_default_option(prefix//'pc_type', 'gamg', ierr))
    end if
    if (s%singular) then
      ! The pressure Poisson operator is singular (constants): the coarse LU needs a shift.
      PetscCall(set_default_option(prefix//'mg_coarse_pc_factor_shift_type', 'nonzero', ierr))
      PetscCall(set_default_option(prefix//'mg_coarse_redundant_pc_factor_shift_type', 'nonzero', ierr))
    end if

    ! the operators come from the DMDA's preallocation: a star one (7 entries per row), the
    ! solver's own where the fields share the box layout of the direct solves (doc/DESIGN.md "One
    ! layout with the direct solves"; e.g. the -bench_cold_poisson yardstick)
    s%owns_dm = grid%shared_layout
    if (s%owns_dm) then
      PetscCall(grid_create_star_layout(grid, field, s%dm, ierr))
    else
      s%dm = grid%da(field)
    end if
    PetscCall(KSPCreate(PETSC_COMM_WORLD, s%ksp, ierr))
    PetscCall(KSPSetOptionsPrefix(s%ksp, field_names(field)//'_', ierr))
    PetscCall(KSPSetDM(s%ksp, s%dm, ierr))
    PetscCall(KSPSetComputeOperators(s%ksp, compute_operator, s%context, ierr))
    PetscCall(KSPSetInitialGuessNonzero(s%ksp, PETSC_TRUE, ierr))
    PetscCall(KSPSetFromOptions(s%ksp, ierr))
    if (field == FIELD_P) then
      PetscCall(set_cell_centred_interpolation(s%ksp, s%dm, s%context%walls, ierr))
    end if
    if (s%singular) then
      PetscCall(MatNullSpaceCreate(PETSC_COMM_WORLD, PETSC_TRUE, 0, PETSC_NULL_VEC, s%nullspace, ierr))
    end if
    PetscCall(KSPSetUp(s%ksp, ierr))
    if (grid%lees_edwards) then
      PetscCall(use_twisted_operator(s, ierr))
    end if
  end subroutine solver_create

  ! The Lees-Edwards boundary on the Krylov path (doc/METHOD.md §2.4): the solver's operator becomes
  ! the twisted one (a shell, twisted_mult), while its preconditioner stays the one just set up from
  ! the periodic operator, which is not made again (KSPSetDMActive false, the preconditioner
  ! reused). Why this preconditions well: for x-mode m the twist only moves the y-wavenumbers by
  ! theta/Ly, |theta| <= pi, so the twisted and periodic operators are spectrally equivalent with
  ! a constant ~ 1 + (Lx/(2 m Ly))^2 that does not grow with the grid, and the twisted operator is
  ! symmetric (the shift by -delta is the transpose of the shift by delta), so CG applies. The
  ! offset changes every step; the preconditioner never has to.
  subroutine use_twisted_operator(s, ierr)
    type(solver_t), intent(inout) :: s
    PetscErrorCode, intent(out) :: ierr
    Mat :: A, P
    Vec :: v
    PetscInt :: nlocal, nglobal, dim, m(3), procs(3), dof, sw, bt(3), st
    integer :: slot
    PetscCall(DMDAGetInfo(s%dm, dim, m(1), m(2), m(3), procs(1), procs(2), procs(3), dof, sw, bt(1), bt(2), bt(3), st, ierr))
    if (procs(1) /= 1 .or. procs(2) /= 1) call fatal_error('fdsusp: internal: the Lees-Edwards operator '// &
         'needs whole x-y planes on each rank (mod_grid splits the grid in z only)', 4)
    PetscCall(KSPGetOperators(s%ksp, A, P, ierr))
    s%context%periodic = P
    s%context%dm = s%dm
    PetscCall(DMGetGlobalVector(s%dm, v, ierr))
    PetscCall(VecGetLocalSize(v, nlocal, ierr))
    PetscCall(VecGetSize(v, nglobal, ierr))
    PetscCall(DMRestoreGlobalVector(s%dm, v, ierr))
    PetscCall(MatCreateShell(PETSC_COMM_WORLD, nlocal, nlocal, nglobal, nglobal, 0, s%twisted_op, ierr))
    PetscCall(MatShellSetOperation(s%twisted_op, MATOP_MULT, twisted_mult, ierr))
    PetscCall(MatSetOption(s%twisted_op, MAT_SYMMETRIC, PETSC_TRUE, ierr))
    if (s%singular) then
      PetscCall(MatSetNullSpace(s%twisted_op, s%nullspace, ierr))
    end if
    slot = 1
    do while (slot <= size(twisted))
      if (.not. associated(twisted(slot)%context)) exit
      slot = slot + 1
    end do
    if (slot > size(twisted)) call fatal_error('fdsusp: internal: more than 8 Lees-Edwards Krylov solvers at once', 4)
    twisted(slot)%shell = s%twisted_op
    twisted(slot)%context => s%context
    PetscCall(KSPSetOperators(s%ksp, s%twisted_op, P, ierr))
    PetscCall(KSPSetDMActive(s%ksp, PETSC_FALSE, ierr))
    PetscCall(KSPSetReusePreconditioner(s%ksp, PETSC_TRUE, ierr))
    s%sliding = .true.
  end subroutine use_twisted_operator

  ! y := A x for the twisted operator of the shell A: the periodic stencil (its assembled matrix),
  ! then the rows across the boundary corrected. Periodic in y, row j = 0 reads the top row
  ! x(:, ny-1) as its neighbour below; across the sliding boundary it reads that row at x + delta
  ! instead (and row ny-1 reads the bottom row at x - delta above), the coupling off = -diffusion
  ! h (rows scaled by h^3 as in compute_operator): y += off (S(+-delta) row - row). The rows are
  ! this rank's (z-slabs). Called by PETSc.
  subroutine twisted_mult(A, x, y, ierr)
    Mat :: A
    Vec :: x, y
    PetscErrorCode :: ierr
    type(operator_context_t), pointer :: c
    PetscScalar, pointer :: xa(:,:,:), ya(:,:,:)
    PetscInt :: xs, ys, zs, xm, ym, zm
    real(dp), allocatable :: rows(:, :)
    real(dp) :: h, off
    integer :: slot, nx, ny, k
    c => null()
    do slot = 1, size(twisted)
      if (associated(twisted(slot)%context)) then
        if (twisted(slot)%shell%v == A%v) c => twisted(slot)%context
      end if
    end do
    if (.not. associated(c)) call fatal_error('fdsusp: internal: an unknown Lees-Edwards operator', 4)
    PetscCall(MatMult(c%periodic, x, y, ierr))
    PetscCall(DMDAGetCorners(c%dm, xs, ys, zs, xm, ym, zm, ierr))
    nx = xm
    ny = ym
    h = c%box(1) / nx
    off = -merge(1.0_dp, c%diffusion, c%field == FIELD_P) * h
    PetscCall(DMDAVecGetArrayReadF90(c%dm, x, xa, ierr))
    PetscCall(DMDAVecGetArrayF90(c%dm, y, ya, ierr))
    allocate(rows(0:nx - 1, zs:zs + zm - 1))
    do k = zs, zs + zm - 1
      rows(:, k) = xa(0:nx - 1, ny - 1, k)
    end do
    call sliding_shift_rows(rows, sliding_shift)
    do k = zs, zs + zm - 1
      ya(0:nx - 1, 0, k) = ya(0:nx - 1, 0, k) + off * (rows(:, k) - xa(0:nx - 1, ny - 1, k))
      rows(:, k) = xa(0:nx - 1, 0, k)
    end do
    call sliding_shift_rows(rows, -sliding_shift)
    do k = zs, zs + zm - 1
      ya(0:nx - 1, ny - 1, k) = ya(0:nx - 1, ny - 1, k) + off * (rows(:, k) - xa(0:nx - 1, 0, k))
    end do
    PetscCall(DMDAVecRestoreArrayF90(c%dm, y, ya, ierr))
    PetscCall(DMDAVecRestoreArrayReadF90(c%dm, x, xa, ierr))
    ierr = 0
  end subroutine twisted_mult

  ! The Lees-Edwards offset delta/h (in cells) of the solves to come, on both paths: the direct
  ! solves' twist (mod_fft_solver) and the Krylov path's twisted operator (twisted_mult).
  subroutine solver_set_sliding_shift(shift)
    real(dp), intent(in) :: shift
    sliding_shift = shift
    call fft_set_sliding_shift(shift)
  end subroutine solver_set_sliding_shift

  ! The pressure lives at cell centres, but the DMDA's own multigrid transfer is vertex-centred
  ! trilinear (Q1): it places each coarse unknown on a fine one, half a fine cell from where the
  ! coarse cell centre is, and on a periodic DMDA it interpolates across the walls in y. Here the
  ! prolongation is trilinear between cell centres (weights 3/4, 1/4 per direction) and, at a wall,
  ! constant towards it (zero normal gradient, as the Poisson operator); restriction is its
  ! transpose, which sums the volume-scaled residuals. Cold Poisson solve on 64^3 with walls: 20
  ! iterations with the DMDA transfer, 11 fully periodic (doc/BENCHMARKS.md §8). Only when the
  ! pressure preconditioner is PCMG; -p_mg_cell_centred 0 restores the DMDA transfer.
  subroutine set_cell_centred_interpolation(ksp, da, walls, ierr)
    KSP, intent(in) :: ksp
    DM, intent(in) :: da
    logical, intent(in) :: walls
    PetscErrorCode, intent(out) :: ierr
    PC :: pc
    PCType :: pc_type
    PetscBool :: wanted, found
    PetscInt :: levels, l
    DM :: fine, coarse
    Mat :: prolongation
    KSP :: smoother

    wanted = PETSC_TRUE
    PetscCall(PetscOptionsGetBool(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-p_mg_cell_centred', wanted, found, ierr))
    PetscCall(KSPGetPC(ksp, pc, ierr))
    PetscCall(PCGetType(pc, pc_type, ierr))
    if (.not. wanted .or. pc_type /= PCMG) return
    PetscCall(PCMGGetLevels(pc, levels, ierr))
    ! With every interpolation given, PCMG builds no coarse DMDAs: each level's smoother gets its
    ! own here, which carries compute_operator (DMCoarsen copies it), so the coarse operators are
    ! rediscretised as before.
    fine = da
    do l = levels - 1, 1, -1
      PetscCall(DMCoarsen(fine, PETSC_COMM_WORLD, coarse, ierr))
      PetscCall(cell_centred_prolongation(fine, coarse, walls, prolongation, ierr))
      PetscCall(PCMGSetInterpolation(pc, l, prolongation, ierr))
      PetscCall(MatDestroy(prolongation, ierr))
      PetscCall(PCMGGetSmoother(pc, l - 1, smoother, ierr))
      PetscCall(KSPSetDM(smoother, coarse, ierr))
      if (l < levels - 1) then
        PetscCall(DMDestroy(fine, ierr))
      end if
      fine = coarse
    end do
    if (levels > 1) then
      PetscCall(DMDestroy(fine, ierr))
    end if
  end subroutine set_cell_centred_interpolation

  ! P (fine x coarse) for cell-centred unknowns on DMDAs coarsened by 2 in every direction.
  subroutine cell_centred_prolongation(fine, coarse, walls, P, ierr)
    DM, intent(in) :: fine, coarse
    logical, intent(in) :: walls
    Mat, intent(out) :: P
    PetscErrorCode, intent(out) :: ierr
    PetscInt :: mf(3), mc(3), procs(3), dof, sw, bt(3), st, dim
    PetscInt :: xs, ys, zs, xm, ym, zm, cxs, cys, czs, cxm, cym, czm
    PetscInt :: i, j, k, a, b, c, n, row(1), cols(8)
    PetscScalar :: w(8)
    integer :: idx(2, 3), f(3), d
    real(dp) :: wt(2, 3)
    PetscInt, allocatable :: fx(:), fy(:), fz(:), cx(:), cy(:), cz(:)

    PetscCall(DMDAGetInfo(fine, dim, mf(1), mf(2), mf(3), procs(1), procs(2), procs(3), dof, sw, bt(1), bt(2), bt(3), st, ierr))
    PetscCall(DMDAGetInfo(coarse, dim, mc(1), mc(2), mc(3), procs(1), procs(2), procs(3), dof, sw, bt(1), bt(2), bt(3), st, ierr))
    PetscCall(DMDAGetCorners(fine, xs, ys, zs, xm, ym, zm, ierr))
    PetscCall(DMDAGetCorners(coarse, cxs, cys, czs, cxm, cym, czm, ierr))
    if (any(mf /= 2 * mc)) then
      ! e.g. -p_pc_mg_levels beyond what the grid allows (mod_grid picks the most that halve it)
      call fatal_error('fdsusp: error: cell-centred multigrid needs every level to halve the pressure grid; use '// &
                       'fewer -p_pc_mg_levels or -p_mg_cell_centred 0', 1)
    end if
    ! the PETSc numbering from the ownership ranges (mod_grid's ownership_index): the DMDAs' AOs are
    ! memory-scalable, and those map only in calls every rank makes together (doc/DESIGN.md "One
    ! layout with the direct solves")
    allocate(fx(procs(1)), fy(procs(2)), fz(procs(3)), cx(procs(1)), cy(procs(2)), cz(procs(3)))
    PetscCall(DMDAGetOwnershipRanges(fine, fx, fy, fz, ierr))
    PetscCall(DMDAGetOwnershipRanges(coarse, cx, cy, cz, ierr))
    PetscCall(MatCreateAIJ(PETSC_COMM_WORLD, xm * ym * zm, cxm * cym * czm, PETSC_DETERMINE, PETSC_DETERMINE, 8, PETSC_NULL_INTEGER, 8, PETSC_NULL_INTEGER, P, ierr))
    do k = zs, zs + zm - 1
      do j = ys, ys + ym - 1
        do i = xs, xs + xm - 1
          f = [i, j, k]
          do d = 1, 3
            ! fine cell f lies in coarse cell f/2, on its low side if f is even
            idx(1, d) = f(d) / 2
            idx(2, d) = idx(1, d) + merge(-1, 1, mod(f(d), 2) == 0)
            wt(:, d) = [0.75_dp, 0.25_dp]
            if (idx(2, d) < 0 .or. idx(2, d) >= mc(d)) then
              if (d == 2 .and. walls) then
                idx(2, d) = idx(1, d)          ! zero gradient towards the wall
              else
                idx(2, d) = modulo(idx(2, d), mc(d))
              end if
            end if
          end do
          n = 0
          do c = 1, 2
            do b = 1, 2
              do a = 1, 2
                n = n + 1
                cols(n) = ownership_index(cx, cy, cz, int(mc), idx(a, 1), idx(b, 2), idx(c, 3))
                w(n) = wt(a, 1) * wt(b, 2) * wt(c, 3)
              end do
            end do
          end do
          row(1) = ownership_index(fx, fy, fz, int(mf), int(i), int(j), int(k))
          ! ADD: at a wall two of the eight columns coincide
          PetscCall(MatSetValues(P, 1, row, 8, cols, w, ADD_VALUES, ierr))
        end do
      end do
    end do
    PetscCall(MatAssemblyBegin(P, MAT_FINAL_ASSEMBLY, ierr))
    PetscCall(MatAssemblyEnd(P, MAT_FINAL_ASSEMBLY, ierr))
  end subroutine cell_centred_prolongation

  ! -fluid_fft_plan estimate (default: FFTW picks its algorithms by rule, the same every run, so a
  ! run and its restart repeat the same round-off, bitwise), measure or patient (FFTW times
  ! candidates at start-up: no faster on 100^3 here, doc/BENCHMARKS.md §8, and the choice, hence
  ! the round-off, may differ from run to run).
  integer(C_INT) function fft_planner_flags()
    character(len=16) :: choice
    PetscBool :: found
    PetscErrorCode :: ierr
    integer(C_INT), parameter :: FFTW_MEASURE = 0, FFTW_PATIENT = 32, FFTW_ESTIMATE = 64   ! fftw3.f03
    choice = 'estimate'
    PetscCallA(PetscOptionsGetString(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-fluid_fft_plan', choice, found, ierr))
    select case (trim(choice))
    case ('measure')
      fft_planner_flags = FFTW_MEASURE
    case ('estimate')
      fft_planner_flags = FFTW_ESTIMATE
    case ('patient')
      fft_planner_flags = FFTW_PATIENT
    case default
      call fatal_error('fdsusp: error: -fluid_fft_plan '//trim(choice)//' is not known (measure, patient or estimate)', 2)
      fft_planner_flags = FFTW_MEASURE
    end select
  end function fft_planner_flags

  ! The Helmholtz operator m I - d lap with Jacobi has condition number at most 1 + r,
  ! r = 12 d / (m h^2) (Gershgorin: the 7-point Laplacian's eigenvalues lie in [0, 12/h^2]), so CG
  ! needs ~sqrt(r) iterations of one product each, against ~8 V-cycles of ~10 products for
  ! multigrid. Measured on the demo grid: Jacobi is faster up to r = 48 (dt = 5e-3), by 1.6x at
  ! r = 9.6 (dt = 1e-3); the switch is set below the crossover. m = 0 (no mass) has no bound.
  logical function jacobi_suffices(context, h)
    type(operator_context_t), intent(in) :: context
    real(dp), intent(in) :: h
    real(dp), parameter :: r_max = 50.0_dp
    jacobi_suffices = .false.
    if (context%mass > 0.0_dp) jacobi_suffices = 12.0_dp * context%diffusion / (context%mass * h**2) <= r_max
  end function jacobi_suffices

  ! Solve A x = b from the guess already in x (warm start), or from zero when that guess is
  ! worse than none (|b - A x| > |b|: a pressure increment decaying towards a steady state).
  ! settled: a second guess (mod_fluid: u^n beside the extrapolated guess in x), taken when both
  ! already meet the tolerance. Where nothing changes any more, the solve then stops at once on
  ! u^n and the field stays put, while an extrapolated guess accepted without iterations would
  ! repeat the last step's change, a drift of the size of the tolerance, for ever (a steady
  ! state would never be detected; tests/physics/test_couette_startup.py). It costs one product,
  ! and only when the extrapolation is already good enough.
  ! Stop the run if the solver did not converge.
  subroutine solver_solve(s, b, x, ierr, settled)
    type(solver_t), intent(inout) :: s
    Vec, intent(inout) :: b, x
    PetscErrorCode, intent(out) :: ierr
    Vec, intent(in), optional :: settled
    KSPConvergedReason :: reason
    PetscInt :: its, maxits
    PetscReal :: rnorm, bnorm, snorm, rtol, abstol, dtol
    Mat :: A, P
    Vec :: r
    DM :: dm
    character(len=200) :: text

    if (s%direct) then
      PetscCall(fft_solve(s%fft, b, x, ierr))
      s%iterations = 0
      return
    end if
    PetscCall(VecScale(b, s%cell_volume, ierr))
    if (s%singular) then
      PetscCall(MatNullSpaceRemove(s%nullspace, b, ierr))
    end if
    PetscCall(KSPGetOperators(s%ksp, A, P, ierr))
    ! the residual in a vector the DM keeps between calls, so the time loop allocates nothing
    ! (doc/BENCHMARKS.md §8)
    PetscCall(KSPGetDM(s%ksp, dm, ierr))
    PetscCall(DMGetGlobalVector(dm, r, ierr))
    PetscCall(MatMult(A, x, r, ierr))
    PetscCall(VecAYPX(r, -1.0_dp, b, ierr))
    PetscCall(VecNorm(r, NORM_2, rnorm, ierr))
    PetscCall(VecNorm(b, NORM_2, bnorm, ierr))
    if (present(settled)) then
      PetscCall(KSPGetTolerances(s%ksp, rtol, abstol, dtol, maxits, ierr))
      if (rnorm <= max(rtol * bnorm, abstol)) then
        PetscCall(MatMult(A, settled, r, ierr))
        PetscCall(VecAYPX(r, -1.0_dp, b, ierr))
        PetscCall(VecNorm(r, NORM_2, snorm, ierr))
        if (snorm <= max(rtol * bnorm, abstol)) then
          PetscCall(VecCopy(settled, x, ierr))
        end if
      end if
    end if
    PetscCall(DMRestoreGlobalVector(dm, r, ierr))
    if (rnorm > bnorm) then
      PetscCall(VecSet(x, 0.0_dp, ierr))
    end if
    PetscCall(KSPSolve(s%ksp, b, x, ierr))
    PetscCall(KSPGetConvergedReason(s%ksp, reason, ierr))
    PetscCall(KSPGetIterationNumber(s%ksp, its, ierr))
    s%iterations = its
    if (reason < 0) then
      PetscCall(KSPGetResidualNorm(s%ksp, rnorm, ierr))
      write(text, '(3a,i0,a,i0,a,es10.3,a)') 'fdsusp: fatal: the ', field_names(s%field), &
           ' solver diverged (KSPConvergedReason ', reason, ') after ', its, &
           ' iterations, residual ', rnorm, '; see -'//field_names(s%field)//'_ksp_converged_reason'
      call fatal_error(text, 3)
    end if
    if (s%singular) then
      PetscCall(MatNullSpaceRemove(s%nullspace, x, ierr))
    end if
  end subroutine solver_solve

  ! Benchmark: seconds for one solve from a zero initial guess to relative tolerance rtol, with a
  ! random consistent right-hand side (the operator and preconditioner are already set up).
  ! Returns the iteration count too. The solver's own tolerance is restored afterwards.
  subroutine solver_cold_solve(s, rtol, seconds, iterations, ierr)
    type(solver_t), intent(inout) :: s
    real(dp), intent(in) :: rtol
    real(dp), intent(out) :: seconds
    integer, intent(out) :: iterations
    PetscErrorCode, intent(out) :: ierr
    Vec :: b, x
    PetscReal :: old_rtol, abstol, dtol
    PetscInt :: maxit, its
    PetscRandom :: rnd
    DM :: dm
    real(dp) :: t0
    PetscCall(KSPGetDM(s%ksp, dm, ierr))
    PetscCall(DMCreateGlobalVector(dm, b, ierr))
    PetscCall(VecDuplicate(b, x, ierr))
    PetscCall(PetscRandomCreate(PETSC_COMM_WORLD, rnd, ierr))
    PetscCall(PetscRandomSetSeed(rnd, 20141107_8, ierr))
    PetscCall(PetscRandomSeed(rnd, ierr))
    PetscCall(VecSetRandom(b, rnd, ierr))
    PetscCall(PetscRandomDestroy(rnd, ierr))
    if (s%singular) then
      PetscCall(MatNullSpaceRemove(s%nullspace, b, ierr))
    end if
    PetscCall(VecSet(x, 0.0_dp, ierr))
    PetscCall(KSPGetTolerances(s%ksp, old_rtol, abstol, dtol, maxit, ierr))
    PetscCall(KSPSetTolerances(s%ksp, rtol, abstol, dtol, maxit, ierr))
    call MPI_Barrier(PETSC_COMM_WORLD, ierr)
    t0 = MPI_Wtime()
    PetscCall(KSPSolve(s%ksp, b, x, ierr))
    call MPI_Barrier(PETSC_COMM_WORLD, ierr)
    seconds = MPI_Wtime() - t0
    PetscCall(KSPGetIterationNumber(s%ksp, its, ierr))
    iterations = its
    PetscCall(KSPSetTolerances(s%ksp, old_rtol, abstol, dtol, maxit, ierr))
    PetscCall(VecDestroy(b, ierr))
    PetscCall(VecDestroy(x, ierr))
  end subroutine solver_cold_solve

  subroutine solver_destroy(s, ierr)
    type(solver_t), intent(inout) :: s
    PetscErrorCode, intent(out) :: ierr
    integer :: slot
    if (s%direct) then
      PetscCall(fft_destroy(s%fft, ierr))
    else
      PetscCall(KSPDestroy(s%ksp, ierr))
      if (s%sliding) then
        do slot = 1, size(twisted)
          if (associated(twisted(slot)%context)) then
            if (twisted(slot)%shell%v == s%twisted_op%v) twisted(slot)%context => null()
          end if
        end do
        PetscCall(MatDestroy(s%twisted_op, ierr))
        s%sliding = .false.
      end if
      if (s%owns_dm) then
        PetscCall(DMDestroy(s%dm, ierr))
      end if
      s%owns_dm = .false.
      if (s%singular) then
        PetscCall(MatNullSpaceDestroy(s%nullspace, ierr))
      end if
    end if
    ! after the KSP: it and its coarse levels' DMs hold the context's address until then
    if (associated(s%context)) deallocate(s%context)
  end subroutine solver_destroy

  ! Assemble the operator of field on the DMDA of whichever multigrid level asks.
  ! Every row is multiplied by the cell volume h^3 of its level (finite-volume scaling): with
  ! PETSc's interpolation P and restriction P^T, P^T A_h P then matches the rediscretised A_2h,
  ! which multigrid needs to converge at a rate independent of the grid (solver_solve scales the
  ! right-hand side to match). Measured on the 32^3 manufactured case: 38 CG iterations without
  ! the scaling, 9 with it.
  ! Helmholtz rows: (mass + diffusion*6/h^2) x_0 - diffusion/h^2 sum(neighbours).
  !   u, w with walls: the wall ghost is 2 U_wall - x_0, so the row at j = 0 (or n-1) loses its
  !   neighbour across the wall and gains diffusion/h^2 on the diagonal (the U_wall part goes
  !   to the right-hand side, see mod_fluid).
  !   v with walls: j = 0 is the wall face (v = 0): identity-like row, and no row couples to it.
  ! Poisson rows (-lap, SPD form): sum over neighbours of (x_0 - x_nb)/h^2; at the walls the
  !   neighbour across is dropped (zero normal flux, v = 0 on the wall).
  ! context: the solver's operator_context_t, which PETSc passes by reference.
  subroutine compute_operator(ksp, A, B, context, ierr)
    KSP :: ksp
    Mat :: A, B
    type(operator_context_t) :: context
    PetscErrorCode :: ierr
    DM :: da
    PetscInt :: dim, m(3), procs(3), dof, sw, bt(3), st
    PetscInt :: xs, ys, zs, xm, ym, zm, i, j, k, nc, d
    MatStencil :: row(4), col(4, 7)
    PetscScalar :: val(7)
    real(dp) :: h, idiag, off, mass, diff
    integer, parameter :: nb(3, 6) = reshape([-1,0,0, 1,0,0, 0,-1,0, 0,1,0, 0,0,-1, 0,0,1], [3, 6])
    logical :: poisson, cell_centred_y, wall_row
    MatNullSpace :: nullspace

    PetscCall(KSPGetDM(ksp, da, ierr))
    PetscCall(DMDAGetInfo(da, dim, m(1), m(2), m(3), procs(1), procs(2), procs(3), dof, sw, bt(1), bt(2), bt(3), st, ierr))
    PetscCall(DMDAGetCorners(da, xs, ys, zs, xm, ym, zm, ierr))
    h = context%box(1) / m(1)
    poisson = (context%field == FIELD_P)
    cell_centred_y = (context%field /= FIELD_V)
    if (poisson) then
      mass = 0.0_dp
      diff = 1.0_dp
    else
      mass = context%mass
      diff = context%diffusion
    end if
    off = -diff / h**2 * h**3

    do k = zs, zs + zm - 1
      do j = ys, ys + ym - 1
        do i = xs, xs + xm - 1
          row(MatStencil_i) = i; row(MatStencil_j) = j; row(MatStencil_k) = k; row(MatStencil_c) = 0
          idiag = mass
          nc = 1
          wall_row = context%walls .and. .not. cell_centred_y .and. j == 0
          if (wall_row) then
            ! v on the wall: v = 0, scaled like the other rows.
            col(:, 1) = row
            val(1) = (mass + 6.0_dp * diff / h**2) * h**3
            PetscCall(MatSetValuesStencil(B, 1, row, 1, col, val, INSERT_VALUES, ierr))
            cycle
          end if
          do d = 1, 6
            if (context%walls .and. nb(2, d) /= 0) then
              if (cell_centred_y) then
                ! neighbour across a wall
                if ((j == 0 .and. nb(2, d) < 0) .or. (j == m(2) - 1 .and. nb(2, d) > 0)) then
                  if (.not. poisson) idiag = idiag + 2.0_dp * diff / h**2   ! ghost = 2 U_w - x_0
                  cycle
                end if
              else
                ! v: the neighbour is the wall face j = 0 (or j = n, the same face): known zero
                if ((j == 1 .and. nb(2, d) < 0) .or. (j == m(2) - 1 .and. nb(2, d) > 0)) then
                  idiag = idiag + diff / h**2
                  cycle
                end if
              end if
            end if
            idiag = idiag + diff / h**2
            nc = nc + 1
            col(MatStencil_i, nc) = i + nb(1, d)
            col(MatStencil_j, nc) = j + nb(2, d)
            col(MatStencil_k, nc) = k + nb(3, d)
            col(MatStencil_c, nc) = 0
            val(nc) = off
          end do
          col(:, 1) = row
          val(1) = idiag * h**3
          PetscCall(MatSetValuesStencil(B, 1, row, nc, col, val, INSERT_VALUES, ierr))
        end do
      end do
    end do
    PetscCall(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY, ierr))
    PetscCall(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY, ierr))
    ! A is B unless the user asked for a matrix-free operator; assembling it again is harmless.
    PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY, ierr))
    PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY, ierr))
    if (poisson) then
      ! Constants are the null space (periodic and Neumann): KSP then projects them out of the
      ! preconditioned residual, which keeps CG on the consistent subspace.
      PetscCall(MatNullSpaceCreate(PETSC_COMM_WORLD, PETSC_TRUE, 0, PETSC_NULL_VEC, nullspace, ierr))
      PetscCall(MatSetNullSpace(A, nullspace, ierr))
      PetscCall(MatSetNullSpace(B, nullspace, ierr))
      PetscCall(MatNullSpaceDestroy(nullspace, ierr))
    end if
  end subroutine compute_operator

end module mod_solvers
