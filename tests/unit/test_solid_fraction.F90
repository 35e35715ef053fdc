! Invariants of the solid fraction (mod_solid_fraction, doc/METHOD.md §3.1):
!  1. limits: 1 for a control volume wholly inside the sphere, 0 wholly outside, in [0, 1] always;
!  2. volume: summed over a grid of cubes, alpha h^3 equals the sphere volume 4/3 pi R^3. The
!     planar ramp of each sub-sample misses the curvature at O((h/4)^2/R) per cut cell, i.e. a
!     relative volume error ~ (h/4)^2/R^2; at h = 0.2 R that is 2.5e-3, so the tolerance is 3e-3
!     (measured below: printed); the error must also fall as h^2 (ratio > 3 for h halved);
!  3. continuity: alpha changes by at most O(displacement/s), s = h/4, when the sphere moves: a
!     shift of 1e-9 h changes no alpha by more than 1e-7 (no jumps when a sphere crosses a grid
!     line), tested at shifts that put the centre exactly on grid lines and sample lines;
!  4. relaxation: gamma = kappa (1 - alpha) beta h^2 / eta vanishes on fully covered faces.
program test_solid_fraction
  use mod_kinds, only: dp
  use mod_solid_fraction, only: cube_fraction, relaxation_gamma
  use mod_unit_checks, only: failures, check, finish
  implicit none
  real(dp), parameter :: pi = acos(-1.0_dp)
  real(dp) :: h, err(2), a, b, centre(3), worst
  integer :: k, i, j, l, level, n

  call check(cube_fraction([0.0_dp, 0.0_dp, 0.0_dp], 1.0_dp, 0.2_dp) == 1.0_dp, 'inside gives 1')
  call check(cube_fraction([1.3_dp, 0.0_dp, 0.0_dp], 1.0_dp, 0.2_dp) == 0.0_dp, 'outside gives 0')

  ! 2. volume on two grids, several centre positions
  do level = 1, 2
    h = 0.2_dp / level
    err(level) = 0.0_dp
    do k = 0, 4
      centre = [0.37_dp, 0.11_dp, 0.73_dp] * h * k / 4.0_dp
      a = 0.0_dp
      n = ceiling(1.5_dp / h)
      do l = -n, n
        do j = -n, n
          do i = -n, n
            b = cube_fraction([i, j, l] * h - centre, 1.0_dp, h)
            if (b < 0.0_dp .or. b > 1.0_dp) failures = failures + 1
            a = a + b * h**3
          end do
        end do
      end do
      err(level) = max(err(level), abs(a / (4.0_dp / 3.0_dp * pi) - 1.0_dp))
    end do
  end do
  write(*, '(a,2es10.2)') 'relative volume error at h = 0.2, 0.1:', err
  call check(err(1) < 3.0e-3, 'volume within 3e-3 at h = a/5')
  call check(err(1) / max(err(2), 1.0e-300_dp) > 3.0_dp, 'volume error falls as h^2')

  ! 3. continuity across grid and sample lines
  h = 0.2_dp
  worst = 0.0_dp
  do k = 0, 8
    centre = [k * h / 8.0_dp, 0.5_dp * h, 0.0_dp]    ! k = 0, 8: on grid lines; others on sample lines
    do l = -7, 7
      do j = -7, 7
        do i = -7, 7
          a = cube_fraction([i, j, l] * h - centre, 1.0_dp, h)
          b = cube_fraction([i, j, l] * h - centre - [1.0e-9_dp * h, 0.0_dp, 0.0_dp], 1.0_dp, h)
          worst = max(worst, abs(a - b))
        end do
      end do
    end do
  end do
  write(*, '(a,es10.2)') 'largest alpha change for a 1e-9 h shift:', worst
  call check(worst < 1.0e-7_dp, 'alpha is continuous in the position')

  call check(relaxation_gamma(1.0_dp, 0.5_dp, 10.0_dp, 0.2_dp, 1.0_dp) == 0.0_dp, 'gamma = 0 on covered faces')
  call check(abs(relaxation_gamma(0.25_dp, 0.5_dp, 10.0_dp, 0.2_dp, 1.0_dp) - 0.15_dp) < 1e-15_dp, &
             'gamma = kappa (1-alpha) beta h^2 / eta')

  call finish('test_solid_fraction')

end program test_solid_fraction
