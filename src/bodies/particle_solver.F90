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
! is still the faster, ~7x at 500 spheres (doc/BENCHMARKS.md §11). The sparse solve is shared out
! (since 2026-11-28, issue 45): the matrix and vectors live on PETSC_COMM_WORLD, each rank owns the
! block rows of the spheres in its z-slab (mod_sphere_ownership, since 2026-11-29; before, a
! contiguous range of indices) and sets only those, CG runs in parallel, and the shares of the
! solution are gathered (doc/DESIGN.md "Parallelism"); on a rank's local set
! (particle_solver_set_local, lubrication dynamics since 2026-11-29) nothing is gathered: the own
! spheres' velocities come back, their ghosts' from the halo. Each
! rank's system holds every block of its own rows: the one-body and contact blocks are replicated,
! and a rank holds the lubrication links of its own spheres (mod_lubrication_links); the blocks of
! other rows it may hold are ignored. One rank gives the same numbers as before, bitwise; more
! ranks agree to the solver's tolerance (test_ld_rank_independence). The sparse Cholesky by CHOLMOD runs on one
! rank only; -particles_pc_factor_mat_solver_type mumps factors the distributed aij matrix.
#include <petsc/finclude/petscksp.h>
module mod_particle_solver
  use petscksp
  use mod_kinds, only: dp
  use mod_particles, only: particles_t
  use mod_particle_system, only: particle_system_t, particle_system_solve
  use mod_petsc_options, only: set_default_option
  use mod_errors, only: fatal_error
  use mod_sphere_ownership, only: sphere_ownership_t, sphere_ownership_of
  implicit none
  private
  public :: particle_solver_t, particle_solver_create, particle_solver_solve, particle_solver_destroy, &
            particle_solver_set_local

  type :: particle_solver_t
    type(particle_system_t) :: system   ! the 6N system of the step, assembled by the caller
    integer :: iterations = 0           ! of the last solve
    KSP :: ksp
    logical :: created = .false.
    integer :: solves = 0               ! sparse (KSP) solves
    integer :: owned_rows = -1          ! this rank's rows in the last sparse solve (-1: none yet)
    real(dp) :: seconds = 0.0_dp        ! their assembly + solve, summed over the run
    ! a rank's local set (particle_solver_set_local; not allocated: every sphere, on every rank)
    integer, allocatable :: rows(:)     ! (n) the 0-based block row of each local sphere
    logical, allocatable :: owned(:)    ! (n) the spheres this rank owns (and whose rows it sets)
    integer :: total = 0                ! spheres of the whole system
  end type particle_solver_t

contains

  subroutine particle_solver_create(ps, ierr)
    type(particle_solver_t), intent(inout) :: ps
    PetscErrorCode, intent(out) :: ierr
    PetscCall(set_default_option('-particles_ksp_type', 'cg', ierr))
    PetscCall(set_default_option('-particles_pc_type', 'pbjacobi', ierr))
    PetscCall(set_default_option('-particles_ksp_rtol', '1e-12', ierr))
    PetscCall(set_default_option('-particles_ksp_max_it', '10000', ierr))
    PetscCall(KSPCreate(PETSC_COMM_WORLD, ps%ksp, ierr))
    PetscCall(KSPSetOptionsPrefix(ps%ksp, 'particles_', ierr))
    PetscCall(KSPSetFromOptions(ps%ksp, ierr))
    ps%created = .true.
  end subroutine particle_solver_create

  !> The spheres this rank holds from now on (doc/DESIGN.md "Spheres held by their slab"): rows (n)
  !> the global 0-based block row of each local sphere (an owned sphere's its own, a ghost's its
  !> owner's), owned (n) those whose rows this rank owns, total the spheres of the whole system.
  !> The rows of a rank are contiguous, numbered rank by rank. A solve then sets the owned rows
  !> and writes back the velocities of the owned spheres only (the caller forwards them to their
  !> ghosts): nothing of size N is gathered.
  subroutine particle_solver_set_local(ps, rows, owned, total)
    type(particle_solver_t), intent(inout) :: ps
    integer, intent(in) :: rows(:), total
    logical, intent(in) :: owned(:)
    ps%rows = rows
    ps%owned = owned
    ps%total = total
  end subroutine particle_solver_set_local

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
    logical :: ok, coupled
    character(len=300) :: text
    real(dp) :: t0
    ierr = 0
    allocate(x(6, parts%n))
    x(1:3, :) = parts%velocity
    x(4:6, :) = parts%omega
    ! a rank holds only the lubrication links of its spheres (mod_lubrication_links): the system is
    ! coupled when any rank's is, and every rank must take the same (collective) branch
    coupled = ps%system%npairs > 0
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, coupled, 1, MPI_LOGICAL, MPI_LOR, PETSC_COMM_WORLD, ierr))
    if (.not. coupled) then
      call particle_system_solve(ps%system, rhs, x, 1.0e-12_dp, ps%iterations, ok)
      if (.not. ok) then
        write(text, '(a,i0,2a)') 'fdsusp: fatal: the particle system is not positive definite or did not '// &
             'converge (', ps%iterations, ' iterations)', hint
        call fatal_error(text, 4)
      end if
    else
      t0 = MPI_Wtime()
      PetscCall(ksp_solve(ps, rhs, x, reason, ierr))
      if (reason == KSP_DIVERGED_DTOL) then
        ! a right-hand side far below the residual of the last step's velocities (an imposed rate
        ! through zero, doc/INPUT.md "&shear"): the divergence test measures against |rhs|, so the
        ! solve starts again from zero
        x = 0.0_dp
        PetscCall(ksp_solve(ps, rhs, x, reason, ierr))
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
  !> iterations as KSP counts them. owned_rows: this rank's rows in the last solve, updated.
  subroutine ksp_solve(ps, rhs, x, reason, ierr)
    type(particle_solver_t), intent(inout) :: ps
    real(dp), intent(in) :: rhs(:, :)
    real(dp), intent(inout) :: x(:, :)
    KSPConvergedReason, intent(out) :: reason
    PetscErrorCode, intent(out) :: ierr
    Mat :: a
    Vec :: vx, vb
    PetscInt :: n6, row(1), col(1), its, owned
    PetscInt, parameter :: one = 1, six = 6
    PetscInt, allocatable :: diagonal(:), off(:), upper(:), upper_off(:)
    PetscBool :: sbaij, sbaij_parallel
    KSPType :: ksp_type
    PetscScalar, pointer :: p(:)
    integer :: q, i, j, e, rank, ranks, n, total
    integer, allocatable :: mine(:), rows_of(:)
    logical, allocatable :: is_mine(:)
    real(dp), allocatable :: rows(:, :)
    type(sphere_ownership_t) :: o
    logical :: reshared, local

    ! This rank owns the block rows of the spheres `mine` (mod_sphere_ownership: its z-slab's),
    ! numbered rank by rank. Its system holds every block of those rows (the header), so each rank
    ! sets its own rows and nothing crosses ranks in the assembly; the solve then runs on every
    ! rank's share. The spheres of the system are every sphere (replicated) or this rank's local
    ! set (particle_solver_set_local: its own spheres and their ghosts).
    associate(sys => ps%system)
    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr))
    PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr))
    n = sys%n
    local = allocated(ps%rows)
    if (local) then
      total = ps%total
      is_mine = ps%owned
      rows_of = ps%rows
    else
      total = n
      o = sphere_ownership_of(n)
      is_mine = o%owner == rank
      rows_of = o%row
    end if
    n6 = 6 * total
    owned = count(is_mine)
    allocate(mine(owned))
    mine = pack([(q, q = 1, n)], is_mine)
    ! block rows of this rank's spheres: the diagonal block and one block per pair, in the columns
    ! this rank owns (diagonal) or not (off); a pair may come more than once (lubrication and
    ! contact stiffness): its blocks add up in one, and a row never holds more blocks than there
    ! are columns. The upper triangle alone (sbaij): the pairs whose other sphere's row is later.
    allocate(diagonal(n), off(n), upper(n), upper_off(n))
    diagonal = 1
    off = 0
    upper = 1
    upper_off = 0
    do q = 1, sys%npairs
      do e = 1, 2
        i = sys%pair(e, q)
        j = sys%pair(3 - e, q)
        if (.not. is_mine(i)) cycle
        if (is_mine(j)) then
          diagonal(i) = diagonal(i) + 1
          if (rows_of(j) > rows_of(i)) upper(i) = upper(i) + 1
        else
          off(i) = off(i) + 1
          if (rows_of(j) > rows_of(i)) upper_off(i) = upper_off(i) + 1
        end if
      end do
    end do
    diagonal = min(diagonal, owned)
    upper = min(upper, owned)
    off = min(off, total - owned)
    upper_off = min(upper_off, total - owned)
    ! BAIJ (sequential on one rank, distributed on more) unless -particles_mat_type says otherwise
    ! (sbaij or aij for a sparse Cholesky on one rank: PETSc's CHOLMOD factors only those; sbaij
    ! keeps the upper triangle, the lower is ignored)
    PetscCall(MatCreate(PETSC_COMM_WORLD, a, ierr))
    PetscCall(MatSetSizes(a, 6 * owned, 6 * owned, n6, n6, ierr))
    PetscCall(MatSetBlockSize(a, six, ierr))
    PetscCall(MatSetType(a, MATBAIJ, ierr))
    PetscCall(MatSetOptionsPrefix(a, 'particles_', ierr))
    PetscCall(MatSetFromOptions(a, ierr))
    PetscCall(MatXAIJSetPreallocation(a, six, diagonal(mine), off(mine), upper(mine), upper_off(mine), ierr))
    PetscCall(MatSetOption(a, MAT_SYMMETRIC, PETSC_TRUE, ierr))
    PetscCall(PetscObjectTypeCompare(a, MATSEQSBAIJ, sbaij, ierr))
    PetscCall(PetscObjectTypeCompare(a, MATMPISBAIJ, sbaij_parallel, ierr))
    if (sbaij .or. sbaij_parallel) then
      PetscCall(MatSetOption(a, MAT_IGNORE_LOWER_TRIANGULAR, PETSC_TRUE, ierr))
    end if
    do q = 1, int(owned)
      row(1) = rows_of(mine(q))
      PetscCall(MatSetValuesBlocked(a, one, row, one, row, row_major(sys%diag(:, :, mine(q))), ADD_VALUES, ierr))
    end do
    do q = 1, sys%npairs
      i = sys%pair(1, q)
      j = sys%pair(2, q)
      row(1) = rows_of(i)
      col(1) = rows_of(j)
      if (is_mine(i)) then
        PetscCall(MatSetValuesBlocked(a, one, row, one, col, row_major(sys%block(:, :, q)), ADD_VALUES, ierr))
      end if
      if (is_mine(j)) then
        PetscCall(MatSetValuesBlocked(a, one, col, one, row, row_major(transpose(sys%block(:, :, q))), ADD_VALUES, ierr))
      end if
    end do
    PetscCall(MatAssemblyBegin(a, MAT_FINAL_ASSEMBLY, ierr))
    PetscCall(MatAssemblyEnd(a, MAT_FINAL_ASSEMBLY, ierr))
    PetscCall(MatCreateVecs(a, vx, vb, ierr))
    PetscCall(VecGetArrayF90(vb, p, ierr))
    p = reshape(rhs(:, mine), [6 * owned])
    PetscCall(VecRestoreArrayF90(vb, p, ierr))
    PetscCall(VecGetArrayF90(vx, p, ierr))
    p = reshape(x(:, mine), [6 * owned])
    PetscCall(VecRestoreArrayF90(vx, p, ierr))
    ! a direct solve (preonly) takes no guess
    PetscCall(KSPGetType(ps%ksp, ksp_type, ierr))
    if (trim(ksp_type) == trim(KSPPREONLY)) then
      PetscCall(KSPSetInitialGuessNonzero(ps%ksp, PETSC_FALSE, ierr))
    else
      PetscCall(KSPSetInitialGuessNonzero(ps%ksp, PETSC_TRUE, ierr))
    end if
    ! a sphere that crossed a slab face since the last solve changes the ranks' shares of rows,
    ! which a set-up solver cannot take (PCSetOperators): it is reset to its options first, on
    ! every rank (collective) when any rank's share changed
    reshared = ps%owned_rows >= 0 .and. ps%owned_rows /= 6 * owned
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, reshared, 1, MPI_LOGICAL, MPI_LOR, PETSC_COMM_WORLD, ierr))
    if (reshared) then
      PetscCall(KSPReset(ps%ksp, ierr))
    end if
    ps%owned_rows = 6 * owned
    PetscCall(KSPSetOperators(ps%ksp, a, a, ierr))
    PetscCall(KSPSolve(ps%ksp, vb, vx, ierr))
    PetscCall(KSPGetConvergedReason(ps%ksp, reason, ierr))
    PetscCall(KSPGetIterationNumber(ps%ksp, its, ierr))
    ps%iterations = int(its)
    ! a local set keeps the velocities of its own spheres (the caller forwards them to their
    ! ghosts); a replicated one holds every sphere's, so the shares are gathered in row order
    ! (6 N doubles, doc/DESIGN.md "Parallelism") and put back by sphere
    PetscCall(VecGetArrayReadF90(vx, p, ierr))
    if (local .or. ranks == 1) then
      x(:, mine) = reshape(p, [6, int(owned)])
    else
      allocate(rows(6, sys%n))
      rows(:, o%displs(rank + 1) + 1:o%displs(rank + 1) + owned) = reshape(p, [6, int(owned)])
    end if
    PetscCall(VecRestoreArrayReadF90(vx, p, ierr))
    if (ranks > 1 .and. .not. local) then
      PetscCallMPI(MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, rows, 6 * o%counts, 6 * o%displs, MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, ierr))
      x(:, o%sphere) = rows
    end if
    PetscCall(VecDestroy(vx, ierr))
    PetscCall(VecDestroy(vb, ierr))
    PetscCall(MatDestroy(a, ierr))
    end associate
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
