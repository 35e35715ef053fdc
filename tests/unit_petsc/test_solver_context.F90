! Invariant: every solver of mod_solvers assembles its operator from its own coefficients (its
! operator_context_t, the context of PETSc's compute-operators callback), on every multigrid
! level, while other solvers of other coefficients exist on the same grid. Two Krylov Helmholtz
! solvers of u (A = mass I - diffusion lap; mass 10 and 40, diffusion 0.5 and 2) are created one
! after the other on the same DMDA of a periodic 16^3 grid, with the multigrid preconditioner
! (-u_pc_type mg on the 3 levels the grid allows). Then:
!   1. on every level l of each solver's multigrid (fine to coarsest, h_l = L/n_l), the operator
!      times the constant field is mass h_l^3 (the rows are scaled by the cell volume, the
!      Laplacian of a constant is 0): each solver's own mass, not the other's, to 1e-13 relative (7 terms of size <= (mass + 6 diffusion/h^2) h^3 per row, a few
!      ulps of that against mass h^3);
!   2. on the fine level the operator times x* = sin(2 pi x/L) is (mass + diffusion 4/h^2
!      sin^2(pi h/L)) h^3 x* (x* is an eigenvector of the 7-point Laplacian), each solver's
!      own diffusion, to 1e-13 relative (2-norm) for the same reason.
! Every check is of a global quantity; the program runs as an MPI singleton (tests/run_tests.sh).
#include <petsc/finclude/petscksp.h>
program test_solver_context
  use, intrinsic :: iso_fortran_env, only: output_unit
  use petscksp
  use petscdmda
  use mod_kinds, only: dp, pi
  use mod_params, only: config_t
  use mod_grid, only: grid_t, grid_create, grid_destroy, FIELD_U
  use mod_solvers, only: solver_t, solver_create, solver_destroy
  use mod_unit_checks, only: check, check_below, finish
  implicit none

  integer, parameter :: n = 16
  real(dp), parameter :: h = 0.25_dp, masses(2) = [10.0_dp, 40.0_dp], diffusions(2) = [0.5_dp, 2.0_dp]
  PetscErrorCode :: ierr
  PetscMPIInt :: rank
  type(config_t) :: cfg
  type(grid_t) :: grid
  type(solver_t) :: solvers(2)
  integer :: s
  character(len=8) :: text

  PetscCallA(PetscInitialize(ierr))
  call MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr)
  if (rank /= 0) open(unit=output_unit, file='/dev/null')     ! one copy of the verdicts
  cfg%cells = n
  cfg%h = h
  cfg%domain%box = n * h
  cfg%walls = .false.
  cfg%domain%y_boundary = 'periodic'
  PetscCallA(grid_create(cfg, grid, ierr))
  ! multigrid on the levels the grid allows (mod_solvers would pick Jacobi for these coefficients)
  PetscCallA(PetscOptionsSetValue(PETSC_NULL_OPTIONS, '-u_pc_type', 'mg', ierr))
  write(text, '(i0)') grid%mg_levels
  PetscCallA(PetscOptionsSetValue(PETSC_NULL_OPTIONS, '-u_pc_mg_levels', trim(text), ierr))
  do s = 1, 2
    PetscCallA(solver_create(grid, FIELD_U, 1.0e-10_dp, 0.0_dp, masses(s), diffusions(s), solvers(s), ierr, krylov=.true.))
  end do
  do s = 1, 2
    call check_levels(solvers(s), masses(s))
    call check_fine(solvers(s), masses(s), diffusions(s))
  end do
  do s = 1, 2
    PetscCallA(solver_destroy(solvers(s), ierr))
  end do
  PetscCallA(grid_destroy(grid, ierr))
  call finish('test_solver_context')
  PetscCallA(PetscFinalize(ierr))

contains

  ! 1. the constant field on every level
  subroutine check_levels(solver, mass)
    type(solver_t), intent(in) :: solver
    real(dp), intent(in) :: mass
    PC :: pc
    KSP :: smoother
    Mat :: A, P
    Vec :: x, y
    PetscInt :: levels, l, size_l
    PetscReal :: ymax, ymin
    real(dp) :: hl, worst
    character(len=120) :: what
    PetscCallA(KSPGetPC(solver%ksp, pc, ierr))
    PetscCallA(PCMGGetLevels(pc, levels, ierr))
    call check(levels >= 2, 'the Helmholtz solver has a multigrid hierarchy (-u_pc_type mg)')
    worst = 0.0_dp
    do l = 0, levels - 1
      PetscCallA(PCMGGetSmoother(pc, l, smoother, ierr))
      PetscCallA(KSPGetOperators(smoother, A, P, ierr))
      PetscCallA(MatCreateVecs(A, x, y, ierr))
      PetscCallA(VecGetSize(x, size_l, ierr))
      hl = n * h / nint(real(size_l, dp)**(1.0_dp / 3.0_dp))
      PetscCallA(VecSet(x, 1.0_dp, ierr))
      PetscCallA(MatMult(A, x, y, ierr))
      PetscCallA(VecMax(y, PETSC_NULL_INTEGER, ymax, ierr))
      PetscCallA(VecMin(y, PETSC_NULL_INTEGER, ymin, ierr))
      worst = max(worst, abs(ymax - mass * hl**3), abs(ymin - mass * hl**3)) / (mass * hl**3)
      PetscCallA(VecDestroy(x, ierr))
      PetscCallA(VecDestroy(y, ierr))
    end do
    write(what, '(a,f0.1,a,i0,a)') 'mass ', mass, ': A 1 = mass h^3 on all ', levels, ' levels (relative)'
    call check_below(trim(what), worst, 1.0e-13_dp)
  end subroutine check_levels

  ! 2. the eigenvector sin(2 pi x/L) on the fine level
  subroutine check_fine(solver, mass, diffusion)
    type(solver_t), intent(in) :: solver
    real(dp), intent(in) :: mass, diffusion
    Mat :: A, P
    Vec :: x, y
    PetscScalar, pointer :: a3(:, :, :)
    PetscReal :: e, r
    real(dp) :: lambda
    integer :: i, j, k
    character(len=120) :: what
    PetscCallA(KSPGetOperators(solver%ksp, A, P, ierr))
    PetscCallA(DMCreateGlobalVector(grid%da(FIELD_U), x, ierr))
    PetscCallA(VecDuplicate(x, y, ierr))
    PetscCallA(DMDAVecGetArrayF90(grid%da(FIELD_U), x, a3, ierr))
    do k = grid%lo(3), grid%hi(3)
      do j = grid%lo(2), grid%hi(2)
        do i = grid%lo(1), grid%hi(1)
          a3(i, j, k) = sin(2.0_dp * pi * i / n)
        end do
      end do
    end do
    PetscCallA(DMDAVecRestoreArrayF90(grid%da(FIELD_U), x, a3, ierr))
    PetscCallA(MatMult(A, x, y, ierr))
    lambda = (mass + diffusion * 4.0_dp / h**2 * sin(pi / n)**2) * h**3
    PetscCallA(VecAXPY(y, -lambda, x, ierr))
    PetscCallA(VecNorm(y, NORM_2, e, ierr))
    PetscCallA(VecNorm(x, NORM_2, r, ierr))
    write(what, '(a,f0.1,a,f0.1,a)') 'mass ', mass, ', diffusion ', diffusion, &
         ': A sin(2 pi x/L) = (mass + diffusion 4/h^2 sin^2(pi h/L)) h^3 sin (relative)'
    call check_below(trim(what), e / (lambda * r), 1.0e-13_dp)
    PetscCallA(VecDestroy(x, ierr))
    PetscCallA(VecDestroy(y, ierr))
  end subroutine check_fine

end program test_solver_context
