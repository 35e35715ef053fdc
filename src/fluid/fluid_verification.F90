! The verification norms of the fluid (doc/VALIDATION.md, &fluid manufactured_solution): the
! errors of the computed velocity and pressure against the manufactured Stokes solution of
! mod_manufactured, whose forcing mod_fluid applies. Apart from mod_fluid, which steps the flow:
! measuring it against an exact solution is another job. Collective (MPI reductions).
#include <petsc/finclude/petscdmda.h>
module mod_fluid_verification
  use petscdmda
  use mod_kinds, only: dp
  use mod_grid, only: grid_t, grid_position, grid_fixed_row, FIELD_U, FIELD_P
  use mod_fluid, only: fluid_t
  use mod_manufactured, only: mms_velocity, mms_pressure
  implicit none
  private
  public :: fluid_errors_vs_manufactured

contains

  !> err_vel: max |u - u_exact| over the velocity unknowns (u_exact plus the wall shear of
  !> shear_rate between walls); err_p_max, err_p_rms: the pressure error with both means removed.
  subroutine fluid_errors_vs_manufactured(grid, fl, shear_rate, err_vel, err_p_max, err_p_rms, ierr)
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(inout) :: fl
    real(dp), intent(in) :: shear_rate
    real(dp), intent(out) :: err_vel, err_p_max, err_p_rms
    PetscErrorCode, intent(out) :: ierr
    PetscScalar, pointer :: a(:,:,:)
    real(dp) :: x(3), exact, loc(3), tot(3), mean_h, mean_e, ncell
    PetscErrorCode :: mpierr
    integer :: c, i, j, k

    loc = 0.0_dp
    do c = 1, 3
      PetscCall(DMDAVecGetArrayReadF90(grid%da(c), fl%vel(c), a, ierr))
      do k = grid%lo(3), grid%hi(3)
        do j = grid%lo(2), grid%hi(2)
          do i = grid%lo(1), grid%hi(1)
            if (grid_fixed_row(grid, c, j)) cycle
            x = grid_position(grid, c, i, j, k)
            exact = mms_velocity(c, x, grid%box, grid%walls)
            if (c == FIELD_U .and. grid%walls) exact = exact + shear_rate * (x(2) - 0.5_dp * grid%box(2))
            loc(1) = max(loc(1), abs(a(i, j, k) - exact))
          end do
        end do
      end do
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(c), fl%vel(c), a, ierr))
    end do
    call MPI_Allreduce(loc(1), tot(1), 1, MPIU_REAL, MPI_MAX, PETSC_COMM_WORLD, mpierr)
    err_vel = tot(1)

    ! means of the computed and the exact pressure
    ncell = real(grid%n(1), dp) * grid%n(2) * grid%n(3)
    PetscCall(VecSum(fl%pressure, mean_h, ierr))
    mean_h = mean_h / ncell
    loc = 0.0_dp
    PetscCall(DMDAVecGetArrayReadF90(grid%da(FIELD_P), fl%pressure, a, ierr))
    do k = grid%lo(3), grid%hi(3)
      do j = grid%lo(2), grid%hi(2)
        do i = grid%lo(1), grid%hi(1)
          loc(1) = loc(1) + mms_pressure(grid_position(grid, FIELD_P, i, j, k), grid%box, grid%walls)
        end do
      end do
    end do
    call MPI_Allreduce(loc(1), mean_e, 1, MPIU_REAL, MPI_SUM, PETSC_COMM_WORLD, mpierr)
    mean_e = mean_e / ncell
    loc = 0.0_dp
    do k = grid%lo(3), grid%hi(3)
      do j = grid%lo(2), grid%hi(2)
        do i = grid%lo(1), grid%hi(1)
          exact = mms_pressure(grid_position(grid, FIELD_P, i, j, k), grid%box, grid%walls) - mean_e
          loc(2) = max(loc(2), abs(a(i, j, k) - mean_h - exact))
          loc(3) = loc(3) + (a(i, j, k) - mean_h - exact)**2
        end do
      end do
    end do
    PetscCall(DMDAVecRestoreArrayReadF90(grid%da(FIELD_P), fl%pressure, a, ierr))
    call MPI_Allreduce(loc(2), tot(2), 1, MPIU_REAL, MPI_MAX, PETSC_COMM_WORLD, mpierr)
    call MPI_Allreduce(loc(3), tot(3), 1, MPIU_REAL, MPI_SUM, PETSC_COMM_WORLD, mpierr)
    err_p_max = tot(2)
    err_p_rms = sqrt(tot(3) / ncell)
  end subroutine fluid_errors_vs_manufactured

end module mod_fluid_verification
