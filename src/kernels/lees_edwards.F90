! Lees-Edwards sliding periodic boundaries in y (Lees & Edwards 1972; Allen & Tildesley 1987,
! §11.3): the box [0,Lx) x [0,Ly) x [0,Lz) is periodic in x and z, and its images above and below
! slide with the imposed shear u_inf = gamma_dot (y - Ly/2) e_x. The image of a sphere at
! x + s Ly e_y (s = +-1, ...) sits at x + s Ly e_y + s delta e_x and moves with U + s gamma_dot Ly e_x,
! where the offset delta(t) = gamma_dot Ly t (mod Lx) is the boundary state (carried exactly by
! checkpoints). Used by the lubrication dynamics mode (&fluid model = 'none') only: the neighbour
! search (mod_neighbours), the contacts (mod_contact) and the pair hydrodynamics
! (mod_particle_lubrication) take their separations from le_separation, the time step wraps the
! spheres with le_wrap and advances the offset with le_advance.
! Pure: no PETSc, MPI or files.
module mod_lees_edwards
  use mod_kinds, only: dp
  use mod_columns, only: column_t, column
  implicit none
  private
  public :: lees_edwards_t, le_create, le_separation, le_wrap, le_advance, le_set_strain, le_columns

  type :: lees_edwards_t
    logical :: active = .false.
    real(dp) :: box(3) = 0.0_dp
    real(dp) :: shear_rate = 0.0_dp
    real(dp) :: offset = 0.0_dp          ! delta: x shift of the image above, in [0, Lx) [a]
  end type lees_edwards_t

contains

  !> An active boundary for this box and shear rate, offset delta (0 at the start of a run).
  pure function le_create(box, shear_rate, offset) result(le)
    real(dp), intent(in) :: box(3), shear_rate, offset
    type(lees_edwards_t) :: le
    le%active = .true.
    le%box = box
    le%shear_rate = shear_rate
    le%offset = offset
  end function le_create

  !> The minimum-image separation r of the pair (i, j) from d = x_j - x_i: the image of j shifted by
  !> s = -nint(d_y/Ly) boxes in y (and s delta in x), then the periodic minimum image in x and z.
  !> velocity_shift: what the image's velocity adds to U_j, s gamma_dot Ly e_x (the velocity of the
  !> image is U_j + velocity_shift).
  pure subroutine le_separation(le, d, r, velocity_shift)
    type(lees_edwards_t), intent(in) :: le
    real(dp), intent(in) :: d(3)
    real(dp), intent(out) :: r(3), velocity_shift(3)
    real(dp) :: s
    s = -anint(d(2) / le%box(2))
    r = d
    r(2) = d(2) + s * le%box(2)
    r(1) = d(1) + s * le%offset
    r(1) = r(1) - le%box(1) * anint(r(1) / le%box(1))
    r(3) = r(3) - le%box(3) * anint(r(3) / le%box(3))
    velocity_shift = [s * le%shear_rate * le%box(2), 0.0_dp, 0.0_dp]
  end subroutine le_separation

  !> Spheres that left through y = Ly (y = 0) re-enter at y - Ly (y + Ly), shifted by -delta
  !> (+delta) in x and by -gamma_dot Ly (+gamma_dot Ly) in their velocity and Adams-Bashforth
  !> history (the image they continue is the one below (above)); then x and z are wrapped into [0, L).
  !> position, velocity, velocity_prev: (3, n).
  pure subroutine le_wrap(le, position, velocity, velocity_prev)
    type(lees_edwards_t), intent(in) :: le
    real(dp), intent(inout) :: position(:, :), velocity(:, :), velocity_prev(:, :)
    integer :: q
    real(dp) :: s
    do q = 1, size(position, 2)
      s = floor(position(2, q) / le%box(2))
      if (s /= 0.0_dp) then
        position(2, q) = position(2, q) - s * le%box(2)
        position(1, q) = position(1, q) - s * le%offset
        velocity(1, q) = velocity(1, q) - s * le%shear_rate * le%box(2)
        velocity_prev(1, q) = velocity_prev(1, q) - s * le%shear_rate * le%box(2)
      end if
    end do
    position(1, :) = modulo(position(1, :), le%box(1))
    position(3, :) = modulo(position(3, :), le%box(3))
  end subroutine le_wrap

  !> delta(t + dt) = delta(t) + gamma_dot Ly dt, kept in [0, Lx).
  pure subroutine le_advance(le, dt)
    type(lees_edwards_t), intent(inout) :: le
    real(dp), intent(in) :: dt
    le%offset = modulo(le%offset + le%shear_rate * le%box(2) * dt, le%box(1))
  end subroutine le_advance

  !> delta = gamma Ly, kept in [0, Lx): the offset of an imposed strain gamma(t) known exactly (an
  !> oscillation, mod_shear_protocol), rather than summed step by step as le_advance does.
  pure subroutine le_set_strain(le, strain)
    type(lees_edwards_t), intent(inout) :: le
    real(dp), intent(in) :: strain
    le%offset = modulo(strain * le%box(2), le%box(1))
  end subroutine le_set_strain

  !> The boundaries' column of the series: the offset delta of the image above.
  function le_columns(le) result(c)
    type(lees_edwards_t), intent(in) :: le
    type(column_t), allocatable :: c(:)
    ! element by element: an array constructor of column_t leaks their values (gfortran 12)
    allocate(c(1))
    c(1) = column('lees_edwards_offset', le%offset)
  end function le_columns

end module mod_lees_edwards
