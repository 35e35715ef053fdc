! Invariants of the series' columns (mod_columns, and the functions by which the physics modules
! name theirs):
!  1. a column keeps its value exactly, in Fortran order, with the value's shape as its per-record
!     shape (0 where unused): scalars (integer and real), a vector, a 3 x N matrix, a 3 x 3 x N
!     tensor; an integer is stored as the real of the same value;
!  2. the spheres' columns are the six of doc/INPUT.md "&particles", in the file's order, each with
!     shape (3, N) or (3, 3, N) and the particle data unchanged;
!  3. a per-sphere column (sphere_column) of some spheres holds their rows only, with their global
!     indices, and the shape of all N spheres; the spheres' columns are per-sphere columns;
!  4. of a rank's local set (mod_ld_local: its spheres' own indices are not global), the spheres'
!     columns of the own spheres carry the global indices given and the shape of all the spheres.
! Exact comparisons: the values are copied, not computed.
program test_columns
  use mod_kinds, only: dp
  use mod_columns, only: column_t, column, sphere_column
  use mod_particles, only: particles_t, particles_init, particles_columns, MOTION_FREE
  use mod_unit_checks, only: check, finish
  implicit none
  type(column_t) :: c
  type(column_t), allocatable :: cs(:)
  type(particles_t) :: p
  real(dp) :: m(3, 4), t(3, 3, 2)
  integer :: k

  c = column('step', 42)
  call check(c%name == 'step' .and. all(c%shape == 0) .and. size(c%values) == 1 .and. c%values(1) == 42.0_dp, &
             'an integer scalar: shape 0, its value as a real')
  c = column('time', 0.125_dp)
  call check(all(c%shape == 0) .and. c%values(1) == 0.125_dp, 'a real scalar')
  c = column('core/stress_hydro', [1.0_dp, 2.0_dp, 3.0_dp, 4.0_dp, 5.0_dp])
  call check(all(c%shape == [5, 0, 0]) .and. all(c%values == [1, 2, 3, 4, 5]), 'a vector: shape (5), values in order')
  m = reshape([(real(k, dp), k = 1, 12)], [3, 4])
  c = column('particles/velocity', m)
  call check(all(c%shape == [3, 4, 0]) .and. all(c%values == [(real(k, dp), k = 1, 12)]), &
             'a 3 x N matrix: shape (3, N), Fortran order')
  t = reshape([(real(k, dp), k = 1, 18)], [3, 3, 2])
  c = column('particles/stresslet_hydro', t)
  call check(all(c%shape == [3, 3, 2]) .and. all(c%values == [(real(k, dp), k = 1, 18)]), &
             'a 3 x 3 x N tensor: shape (3, 3, N), Fortran order')

  call particles_init(p, 4, 1.0_dp, MOTION_FREE)
  p%position = m
  p%velocity = 2 * m
  allocate(cs(6))
  cs = particles_columns(p, [1, 2, 3, 4])
  call check(size(cs) == 6, 'the spheres name six columns')
  call check(cs(1)%name == 'particles/position' .and. cs(2)%name == 'particles/velocity' .and. &
             cs(3)%name == 'particles/omega' .and. cs(4)%name == 'particles/force_hydro' .and. &
             cs(5)%name == 'particles/torque_hydro' .and. cs(6)%name == 'particles/stresslet_hydro', &
             'in the order of doc/INPUT.md: position, velocity, omega, force_hydro, torque_hydro, stresslet_hydro')
  call check(all(cs(1)%values == reshape(m, [12])) .and. all(cs(2)%values == reshape(2 * m, [12])) .and. &
             all(cs(6)%shape == [3, 3, 4]), 'their values are the particle data, the stresslet 3 x 3 x N')
  call check(all([(allocated(cs(k)%rows), k = 1, 6)]), 'the spheres'' columns are per-sphere columns')
  c = sphere_column('particles/velocity', 4, [4, 2], m(:, [4, 2]))
  call check(all(c%shape == [3, 4, 0]) .and. all(c%rows == [4, 2]) .and. &
             all(c%values == [10, 11, 12, 4, 5, 6]), 'a per-sphere column of spheres 4 and 2: their rows, '// &
             'their indices, the shape of all 4')
  cs = particles_columns(p, [3])
  call check(all(cs(1)%shape == [3, 4, 0]) .and. all(cs(1)%values == m(:, 3)) .and. all(cs(6)%shape == [3, 3, 4]) &
             .and. size(cs(6)%values) == 9, 'the spheres'' columns of sphere 3 only: its rows, the shapes of all 4')
  ! the 4 spheres as a local set whose slots 2 and 4 are own, global spheres 7 and 9 of 10
  cs = particles_columns(p, [2, 4], [7, 9], 10)
  call check(all(cs(1)%shape == [3, 10, 0]) .and. all(cs(1)%rows == [7, 9]) .and. &
             all(cs(2)%values == reshape(2 * m(:, [2, 4]), [6])) .and. all(cs(6)%shape == [3, 3, 10]), &
             'a local set''s own spheres 2 and 4: their values under global indices 7 and 9, the shapes of all 10')
  call finish('test_columns')
end program test_columns
