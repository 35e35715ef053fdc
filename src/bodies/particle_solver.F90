! The owner of the implicit 6N particle system (doc/METHOD.md §3.2 eq. (1)) and of its solution. A
! caller (mod_fictitious_domain, mod_ld_motion) resets the system it holds here (%system), lets the
! kernels add their blocks to it in plain arrays (mod_particle_system's assembly:
! particle_system_reset, particle_system_add_diagonal, particle_system_add_pair, which
! mod_particle_lubrication and mod_particle_contacts call), and solves it by particle_solver_solve,
! which starts from the spheres' velocities and writes the solution into them; nothing else
! outside src/kernels/ solves it. Without pair blocks the system is block diagonal and
! mod_particle_system's block solve is exact (one iteration); once lubrication or contact stiffness
! couples the spheres the blocks go into a sparse PETSc matrix and are solved by a KSP with the
! options prefix particles_. Defaults: CG preconditioned by the exact
! inverse of each 6x6 diagonal block (PCPBJACOBI), relative tolerance 1e-12, started from the
! velocities of the last step (since 2026-11-26: 44 -> 26 iterations per step on the paper scene), on a
! block-AIJ matrix (BAIJ, 6x6 blocks: one index per block, assembly and products ~2x faster than
! AIJ; -particles_mat_type aij or sbaij changes it). A sparse Cholesky ordered by METIS
! (SuiteSparse CHOLMOD's nested dissection) is one option away (PETSc's CHOLMOD factors aij, and
! sbaij of block size 1 only):
!   -particles_mat_type aij -particles_ksp_type preonly -particles_pc_type cholesky
!   -particles_pc_factor_mat_solver_type cholmod
! At 1000 spheres (phi = 0.4, ~2900 lubricating pairs) CG takes ~46 iterations and is ~20 times
! faster than the factorisation (doc/BENCHMARKS.md, scripts/bench_particle_solver.sh); in
! lubrication dynamics (no fluid mass on the diagonal) CG takes 64-97 iterations at 1000 spheres and
! is still the faster, ~7x at 500 spheres (doc/BENCHMARKS.md §11). Particle data is replicated, so every
! rank assembles and solves the same sequential system and gets the same answer.
#include <petsc/finclude/petscksp.h>
module mod_particle_solver
  use petscksp
  use mod_kinds, only: dp
  use mod_particles, only: particles_t
  use mod_particle_system, only: particle_system_t, particle_system_solve
  use mod_petsc_options, only: set_default_option
  use mod_errors, only: fatal_error
  implicit none
  private
  public :: particle_solver_t, particle_solver_create, particle_solver_solve, particle_solver_destroy

  type :: particle_solver_t
    type(particle_system_t) :: system   ! the 6N system of the step, assembled by the caller
    integer :: iterations = 0           ! of the last solve
    KSP :: ksp
    logical :: created = .false.
    integer :: solves = 0               ! sparse (KSP) solves
    real(dp) :: seconds = 0.0_dp        ! their assembly + solve, summed over the run
  end type particle_solver_t

contains

  subroutine particle_solver_create(ps, ierr)
    type(particle_solver_t), intent(inout) :: ps
    PetscErrorCode, intent(out) :: ierr
    PetscCall(set_default_option('-particles_ksp_type', 'cg', ierr))
    PetscCall(set_default_option('-particles_pc_type', 'pbjacobi', ierr))
    PetscCall(set_default_option('-particles_ksp_rtol', '1e-12', ierr))
    PetscCall(set_default_option('-particles_ksp_max_it', '10000', ierr))
    PetscCall(KSPCreate(PETSC_COMM_SELF, ps%ksp, ierr))
    PetscCall(KSPSetOptionsPrefix(ps%ksp, 'particles_', ierr))
    PetscCall(KSPSetFromOptions(ps%ksp, ierr))
    ps%created = .true.
  end subroutine particle_solver_create

  !> The velocities of the spheres from ps%system (U, Omega) = rhs (6 x n): the solution starts
  !> from parts%velocity, parts%omega (the last step's: a restart, which reads them from the
  !> checkpoint, repeats the same iterations) and is written back there. Block by block when no
  !> pair couples the system (mod_particle_system), else by the KSP; ps%iterations as the solver
  !> counts them. A failure stops the run (status 4) with one message; hint, appended to the
  !> message of a failed block solve, says what may have caused it.
  subroutine particle_solver_solve(ps, rhs, parts, ierr, hint)
    type(particle_solver_t), intent(inout) :: ps
    real(dp), intent(in) :: rhs(:, :)
    type(particles_t), intent(inout) :: parts
    PetscErrorCode, intent(out) :: ierr
    character(len=*), intent(in) :: hint
    real(dp), allocatable :: x(:, :)
    KSPConvergedReason :: reason
    logical :: ok
    character(len=300) :: text
    real(dp) :: t0
    ierr = 0
    allocate(x(6, parts%n))
    x(1:3, :) = parts%velocity
    x(4:6, :) = parts%omega
    if (ps%system%npairs == 0) then
      call particle_system_solve(ps%system, rhs, x, 1.0e-12_dp, ps%iterations, ok)
      if (.not. ok) then
        write(text, '(a,i0,2a)') 'fdsusp: fatal: the particle system is not positive definite or did not '// &
             'converge (', ps%iterations, ' iterations)', hint
        call fatal_error(text, 4)
      end if
    else
      t0 = MPI_Wtime()
      PetscCall(ksp_solve(ps%ksp, ps%system, rhs, x, ps%iterations, reason, ierr))
      if (reason == KSP_DIVERGED_DTOL) then
        ! a right-hand side far below the residual of the last step's velocities (an imposed rate
        ! through zero, doc/INPUT.md "&shear"): the divergence test measures against |rhs|, so the
        ! solve starts again from zero
        x = 0.0_dp
        PetscCall(ksp_solve(ps%ksp, ps%system, rhs, x, ps%iterations, reason, ierr))
      end if
      ps%solves = ps%solves + 1
      ps%seconds = ps%seconds + (MPI_Wtime() - t0)
      if (reason < 0) then
        write(text, '(a,i0,a,i0,a)') 'fdsusp: fatal: the particle system solve failed (KSP converged reason ', &
             reason, ' after ', ps%iterations, ' iterations; see -particles_ksp_converged_reason)'
        call fatal_error(text, 4)
      end if
    end if
    parts%velocity = x(1:3, :)
    parts%omega = x(4:6, :)
  end subroutine particle_solver_solve

  !> Solve sys x = rhs (both 6 x n) by ksp, from the guess in x: assembly of the sparse matrix,
  !> then the solve. The converged reason is returned in reason (negative: not converged);
  !> iterations as KSP counts them.
  subroutine ksp_solve(ksp, sys, rhs, x, iterations, reason, ierr)
    KSP, intent(in) :: ksp
    type(particle_system_t), intent(in) :: sys
    real(dp), intent(in) :: rhs(:, :)
    real(dp), intent(inout) :: x(:, :)
    integer, intent(out) :: iterations
    KSPConvergedReason, intent(out) :: reason
    PetscErrorCode, intent(out) :: ierr
    Mat :: a
    Vec :: vx, vb
    PetscInt :: n6, row(1), col(1), its
    PetscInt, parameter :: one = 1, six = 6
    PetscInt, allocatable :: nnz(:), upper(:)
    PetscBool :: sbaij
    KSPType :: ksp_type
    PetscScalar, pointer :: p(:)
    integer :: q, i, j

    n6 = 6 * sys%n
    ! block row of particle i: its diagonal block and one block per pair it belongs to
    allocate(nnz(sys%n))
    nnz = 1
    do q = 1, sys%npairs
      do i = 1, 2
        j = sys%pair(i, q)
        nnz(j) = nnz(j) + 1
      end do
    end do
    ! a pair may come more than once (lubrication and contact stiffness): its blocks add up in
    ! one, and a row never holds more blocks than there are particles
    nnz = min(nnz, sys%n)
    ! the upper triangle alone (sbaij): the diagonal block and the pairs whose other particle is later
    allocate(upper(sys%n))
    upper = 1
    do q = 1, sys%npairs
      i = min(sys%pair(1, q), sys%pair(2, q))
      upper(i) = upper(i) + 1
    end do
    upper = min(upper, sys%n)
    ! BAIJ unless -particles_mat_type says otherwise (sbaij or aij for a sparse Cholesky:
    ! PETSc's CHOLMOD factors only those; sbaij keeps the upper triangle, the lower is ignored)
    PetscCall(MatCreate(PETSC_COMM_SELF, a, ierr))
    PetscCall(MatSetSizes(a, n6, n6, n6, n6, ierr))
    PetscCall(MatSetBlockSize(a, six, ierr))
    PetscCall(MatSetType(a, MATSEQBAIJ, ierr))
    PetscCall(MatSetOptionsPrefix(a, 'particles_', ierr))
    PetscCall(MatSetFromOptions(a, ierr))
    PetscCall(MatXAIJSetPreallocation(a, six, nnz, PETSC_NULL_INTEGER, upper, PETSC_NULL_INTEGER, ierr))
    PetscCall(MatSetOption(a, MAT_SYMMETRIC, PETSC_TRUE, ierr))
    PetscCall(PetscObjectTypeCompare(a, MATSEQSBAIJ, sbaij, ierr))
    if (sbaij) then
      PetscCall(MatSetOption(a, MAT_IGNORE_LOWER_TRIANGULAR, PETSC_TRUE, ierr))
    end if
    do q = 1, sys%n
      row(1) = q - 1
      PetscCall(MatSetValuesBlocked(a, one, row, one, row, row_major(sys%diag(:, :, q)), ADD_VALUES, ierr))
    end do
    do q = 1, sys%npairs
      row(1) = sys%pair(1, q) - 1
      col(1) = sys%pair(2, q) - 1
      PetscCall(MatSetValuesBlocked(a, one, row, one, col, row_major(sys%block(:, :, q)), ADD_VALUES, ierr))
      PetscCall(MatSetValuesBlocked(a, one, col, one, row, row_major(transpose(sys%block(:, :, q))), ADD_VALUES, ierr))
    end do
    PetscCall(MatAssemblyBegin(a, MAT_FINAL_ASSEMBLY, ierr))
    PetscCall(MatAssemblyEnd(a, MAT_FINAL_ASSEMBLY, ierr))
    PetscCall(VecCreateSeq(PETSC_COMM_SELF, n6, vb, ierr))
    PetscCall(VecDuplicate(vb, vx, ierr))
    PetscCall(VecGetArrayF90(vb, p, ierr))
    p = reshape(rhs(:, 1:sys%n), [6 * sys%n])
    PetscCall(VecRestoreArrayF90(vb, p, ierr))
    PetscCall(VecGetArrayF90(vx, p, ierr))
    p = reshape(x(:, 1:sys%n), [6 * sys%n])
    PetscCall(VecRestoreArrayF90(vx, p, ierr))
    ! a direct solve (preonly) takes no guess
    PetscCall(KSPGetType(ksp, ksp_type, ierr))
    if (trim(ksp_type) == trim(KSPPREONLY)) then
      PetscCall(KSPSetInitialGuessNonzero(ksp, PETSC_FALSE, ierr))
    else
      PetscCall(KSPSetInitialGuessNonzero(ksp, PETSC_TRUE, ierr))
    end if
    PetscCall(KSPSetOperators(ksp, a, a, ierr))
    PetscCall(KSPSolve(ksp, vb, vx, ierr))
    PetscCall(KSPGetConvergedReason(ksp, reason, ierr))
    PetscCall(KSPGetIterationNumber(ksp, its, ierr))
    iterations = int(its)
    PetscCall(VecGetArrayReadF90(vx, p, ierr))
    x(:, 1:sys%n) = reshape(p, [6, sys%n])
    PetscCall(VecRestoreArrayReadF90(vx, p, ierr))
    PetscCall(VecDestroy(vx, ierr))
    PetscCall(VecDestroy(vb, ierr))
    PetscCall(MatDestroy(a, ierr))
  end subroutine ksp_solve

  ! PETSc takes a block row by row
  pure function row_major(b) result(v)
    real(dp), intent(in) :: b(6, 6)
    PetscScalar :: v(36)
    v = reshape(transpose(b), [36])
  end function row_major

  subroutine particle_solver_destroy(ps, ierr)
    type(particle_solver_t), intent(inout) :: ps
    PetscErrorCode, intent(out) :: ierr
    ierr = 0
    if (ps%created) then
      PetscCall(KSPDestroy(ps%ksp, ierr))
    end if
    ps%created = .false.
  end subroutine particle_solver_destroy

end module mod_particle_solver
