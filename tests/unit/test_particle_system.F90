! Invariants of the 6N particle system solver (mod_particle_system):
!  1. with only diagonal blocks the solve is direct: one iteration, residual at round-off;
!  2. with symmetric positive semi-definite pair blocks added (the form lubrication and contact
!     stiffness take: for a pair, +K on both diagonals and -K off the diagonal, K SPD), the CG
!     solution satisfies A x = b to the requested 1e-12 relative residual, checked by an
!     independent dense Gaussian elimination on the assembled 6N x 6N matrix (agreement 1e-9,
!     which allows for the condition number ~1e3 of the test matrix);
!  3. particle_system_apply is symmetric: x1.(A x2) = x2.(A x1) to 1e-12 relative;
!  4. a block that is not positive definite is reported (ok = .false.), not solved.
program test_particle_system
  use mod_kinds, only: dp
  use mod_particle_system, only: particle_system_t, particle_system_reset, particle_system_add_diagonal, &
                                 particle_system_add_pair, particle_system_solve, particle_system_apply
  use mod_unit_checks, only: check, finish
  implicit none
  integer, parameter :: n = 7
  type(particle_system_t) :: sys
  real(dp) :: b(6, n), x(6, n), y(6, n), dense(6 * n, 6 * n), xd(6 * n), d(6, 6), k(6, 6), x2(6, n), y2(6, n)
  integer :: p, q, its, i, j
  logical :: ok

  call particle_system_reset(sys, n)
  dense = 0.0_dp
  do p = 1, n
    d = spd(p, 3.0_dp)
    call particle_system_add_diagonal(sys, p, d)
    dense(6*p-5:6*p, 6*p-5:6*p) = d
    b(:, p) = [(sin(1.3_dp * p + i), i = 1, 6)]
  end do
  call particle_system_solve(sys, b, x, 1.0e-12_dp, its, ok)
  call particle_system_apply(sys, x, y)
  call check(ok .and. its == 1, 'diagonal system: solved in one iteration')
  call check(norm2(y - b) < 1.0e-13_dp * norm2(b), 'diagonal system: residual at round-off')

  ! pairs (1,2), (2,3), (5,7), (7,1) with K SPD: +K on both diagonals, -K off the diagonal
  do q = 1, 4
    select case (q)
    case (1); i = 1; j = 2
    case (2); i = 2; j = 3
    case (3); i = 5; j = 7
    case (4); i = 7; j = 1
    end select
    k = spd(10 + q, 50.0_dp)
    call particle_system_add_diagonal(sys, i, k)
    call particle_system_add_diagonal(sys, j, k)
    call particle_system_add_pair(sys, i, j, -k)
    dense(6*i-5:6*i, 6*i-5:6*i) = dense(6*i-5:6*i, 6*i-5:6*i) + k
    dense(6*j-5:6*j, 6*j-5:6*j) = dense(6*j-5:6*j, 6*j-5:6*j) + k
    dense(6*i-5:6*i, 6*j-5:6*j) = dense(6*i-5:6*i, 6*j-5:6*j) - k
    dense(6*j-5:6*j, 6*i-5:6*i) = dense(6*j-5:6*j, 6*i-5:6*i) - transpose(k)
  end do
  call particle_system_solve(sys, b, x, 1.0e-12_dp, its, ok)
  call particle_system_apply(sys, x, y)
  call check(ok, 'coupled system: CG converged')
  call check(norm2(y - b) <= 1.0e-12_dp * norm2(b), 'coupled system: relative residual <= 1e-12')
  xd = gauss(dense, reshape(b, [6 * n]))
  write(*, '(a,i0,a,es10.2)') 'CG iterations ', its, ', difference from dense elimination ', &
       norm2(reshape(x, [6 * n]) - xd) / norm2(xd)
  call check(norm2(reshape(x, [6 * n]) - xd) < 1.0e-9_dp * norm2(xd), 'coupled system: equals dense elimination')
  x2 = cos(3.0_dp * b)
  call particle_system_apply(sys, x2, y2)
  call check(abs(sum(x * y2) - sum(x2 * y)) < 1.0e-12_dp * norm2(x) * norm2(y2), 'the operator is symmetric')

  call particle_system_reset(sys, 1)
  d = spd(1, 1.0_dp)
  d(3, 3) = -1.0_dp
  call particle_system_add_diagonal(sys, 1, d)
  call particle_system_solve(sys, b(:, 1:1), x(:, 1:1), 1.0e-12_dp, its, ok)
  call check(.not. ok, 'an indefinite block is reported')

  call finish('test_particle_system')

contains

  ! A deterministic SPD 6x6 matrix: G G^T + shift I.
  function spd(seed, shift) result(a)
    integer, intent(in) :: seed
    real(dp), intent(in) :: shift
    real(dp) :: a(6, 6), g(6, 6)
    integer :: r, c
    do c = 1, 6
      do r = 1, 6
        g(r, c) = sin(0.7_dp * seed + 1.1_dp * r + 2.3_dp * c)
      end do
    end do
    a = matmul(g, transpose(g))
    do r = 1, 6
      a(r, r) = a(r, r) + shift
    end do
  end function spd

  ! Gaussian elimination with partial pivoting, then back substitution.
  function gauss(a_in, rhs) result(x)
    real(dp), intent(in) :: a_in(:, :), rhs(:)
    real(dp) :: x(size(rhs)), a(size(rhs), size(rhs)), r(size(rhs)), t(size(rhs)), s, f
    integer :: m, i, piv, row
    a = a_in
    r = rhs
    m = size(rhs)
    do i = 1, m
      piv = maxloc(abs(a(i:, i)), 1) + i - 1
      t = a(i, :); a(i, :) = a(piv, :); a(piv, :) = t
      s = r(i); r(i) = r(piv); r(piv) = s
      do row = i + 1, m
        f = a(row, i) / a(i, i)
        a(row, i:) = a(row, i:) - f * a(i, i:)
        r(row) = r(row) - f * r(i)
      end do
    end do
    do i = m, 1, -1
      x(i) = (r(i) - sum(a(i, i+1:) * x(i+1:))) / a(i, i)
    end do
  end function gauss


end program test_particle_system
