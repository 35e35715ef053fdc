! The implicit 6N system of the particle sub-problem (doc/METHOD.md §3.2, equation (1)):
!   [ (rho/dt) M + K ] U = rhs
! with U = (U_p, Omega_p) per particle, M block-diagonal (the discrete rigid-body matrices M_p of
! the fictitious domain) and K the sparse symmetric coupling that later models add (lubrication
! R_sub_FU, contact stiffness): 6x6 blocks on the diagonal and one 6x6 block per coupled pair.
! The matrix is symmetric positive definite when every added pair contribution is positive
! semi-definite. Solved by conjugate gradients preconditioned with the exact inverse of each 6x6
! diagonal block (Cholesky); with no pair blocks that is a direct solve in one iteration.
! This module is the system's assembly in plain arrays; in a run the system belongs to
! mod_particle_solver (bodies), which holds it, lets the kernels add their blocks and solves it
! (this block solve when no pair couples it, else PETSc's KSP). Nothing else outside src/kernels/
! solves it; the unit tests call the block solve directly.
! Pure: the same data sits on every rank, so every rank computes the same answer.
module mod_particle_system
  use mod_kinds, only: dp
  implicit none
  private
  public :: particle_system_t, particle_system_reset, particle_system_add_diagonal, &
            particle_system_add_pair, particle_system_solve, particle_system_apply

  type :: particle_system_t
    integer :: n = 0                          ! particles
    real(dp), allocatable :: diag(:, :, :)    ! (6, 6, n)
    integer :: npairs = 0
    integer, allocatable :: pair(:, :)        ! (2, npairs): particles i /= j
    real(dp), allocatable :: block(:, :, :)   ! (6, 6, npairs): A(i, j); A(j, i) is its transpose
  end type particle_system_t

contains

  subroutine particle_system_reset(sys, n)
    type(particle_system_t), intent(inout) :: sys
    integer, intent(in) :: n
    if (allocated(sys%diag)) then
      if (size(sys%diag, 3) /= n) deallocate(sys%diag)
    end if
    if (.not. allocated(sys%diag)) allocate(sys%diag(6, 6, n))
    sys%n = n
    sys%diag = 0.0_dp
    sys%npairs = 0
    if (.not. allocated(sys%pair)) allocate(sys%pair(2, 64), sys%block(6, 6, 64))
  end subroutine particle_system_reset

  subroutine particle_system_add_diagonal(sys, p, a)
    type(particle_system_t), intent(inout) :: sys
    integer, intent(in) :: p
    real(dp), intent(in) :: a(6, 6)
    sys%diag(:, :, p) = sys%diag(:, :, p) + a
  end subroutine particle_system_add_diagonal

  ! Add A(i,j) = a_ij (and A(j,i) = transpose(a_ij)).
  subroutine particle_system_add_pair(sys, i, j, a_ij)
    type(particle_system_t), intent(inout) :: sys
    integer, intent(in) :: i, j
    real(dp), intent(in) :: a_ij(6, 6)
    integer, allocatable :: pair(:, :)
    real(dp), allocatable :: block(:, :, :)
    if (sys%npairs == size(sys%pair, 2)) then
      allocate(pair(2, 2 * sys%npairs), block(6, 6, 2 * sys%npairs))
      pair(:, 1:sys%npairs) = sys%pair(:, 1:sys%npairs)
      block(:, :, 1:sys%npairs) = sys%block(:, :, 1:sys%npairs)
      call move_alloc(pair, sys%pair)
      call move_alloc(block, sys%block)
    end if
    sys%npairs = sys%npairs + 1
    sys%pair(:, sys%npairs) = [i, j]
    sys%block(:, :, sys%npairs) = a_ij
  end subroutine particle_system_add_pair

  pure subroutine particle_system_apply(sys, x, y)
    type(particle_system_t), intent(in) :: sys
    real(dp), intent(in) :: x(6, sys%n)
    real(dp), intent(out) :: y(6, sys%n)
    integer :: p, q, i, j
    do p = 1, sys%n
      y(:, p) = matmul(sys%diag(:, :, p), x(:, p))
    end do
    do q = 1, sys%npairs
      i = sys%pair(1, q)
      j = sys%pair(2, q)
      y(:, i) = y(:, i) + matmul(sys%block(:, :, q), x(:, j))
      y(:, j) = y(:, j) + matmul(transpose(sys%block(:, :, q)), x(:, i))
    end do
  end subroutine particle_system_apply

  ! Solve to relative residual rtol from x = 0. ok is false when a diagonal block is not positive
  ! definite or CG did not converge in 10*6n iterations.
  subroutine particle_system_solve(sys, rhs, x, rtol, iterations, ok)
    type(particle_system_t), intent(in) :: sys
    real(dp), intent(in) :: rhs(6, sys%n), rtol
    real(dp), intent(out) :: x(6, sys%n)
    integer, intent(out) :: iterations
    logical, intent(out) :: ok
    real(dp) :: chol(6, 6, sys%n), r(6, sys%n), z(6, sys%n), d(6, sys%n), q(6, sys%n)
    real(dp) :: rz, rz_new, step, bnorm
    integer :: p

    x = 0.0_dp
    iterations = 0
    ok = .true.
    do p = 1, sys%n
      call cholesky6(sys%diag(:, :, p), chol(:, :, p), ok)
      if (.not. ok) return
    end do
    bnorm = norm2(rhs)
    if (bnorm == 0.0_dp) return
    r = rhs
    call precondition(chol, r, z)
    d = z
    rz = sum(r * z)
    do while (iterations < 60 * sys%n)
      iterations = iterations + 1
      call particle_system_apply(sys, d, q)
      step = rz / sum(d * q)
      x = x + step * d
      r = r - step * q
      if (norm2(r) <= rtol * bnorm) return
      call precondition(chol, r, z)
      rz_new = sum(r * z)
      d = z + (rz_new / rz) * d
      rz = rz_new
    end do
    ok = .false.
  end subroutine particle_system_solve

  pure subroutine precondition(chol, r, z)
    real(dp), intent(in) :: chol(:, :, :), r(:, :)
    real(dp), intent(out) :: z(:, :)
    integer :: p
    do p = 1, size(r, 2)
      z(:, p) = cholesky6_solve(chol(:, :, p), r(:, p))
    end do
  end subroutine precondition

  ! Lower Cholesky factor L of a symmetric 6x6 matrix (A = L L^T).
  pure subroutine cholesky6(a, l, ok)
    real(dp), intent(in) :: a(6, 6)
    real(dp), intent(out) :: l(6, 6)
    logical, intent(out) :: ok
    integer :: i, j
    real(dp) :: s
    l = 0.0_dp
    ok = .true.
    do j = 1, 6
      s = a(j, j) - sum(l(j, 1:j-1)**2)
      if (.not. (s > 0.0_dp)) then
        ok = .false.
        return
      end if
      l(j, j) = sqrt(s)
      do i = j + 1, 6
        l(i, j) = (a(i, j) - sum(l(i, 1:j-1) * l(j, 1:j-1))) / l(j, j)
      end do
    end do
  end subroutine cholesky6

  pure function cholesky6_solve(l, b) result(x)
    real(dp), intent(in) :: l(6, 6), b(6)
    real(dp) :: x(6), y(6)
    integer :: i
    do i = 1, 6
      y(i) = (b(i) - sum(l(i, 1:i-1) * y(1:i-1))) / l(i, i)
    end do
    do i = 6, 1, -1
      x(i) = (y(i) - sum(l(i+1:6, i) * x(i+1:6))) / l(i, i)
    end do
  end function cholesky6_solve

end module mod_particle_system
