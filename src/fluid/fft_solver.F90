! Direct solves of the fluid step's constant-coefficient operators by fast transforms (doc/METHOD.md §2.3).
!
! Every operator of the fluid step (mod_solvers' compute_operator) is a 7-point stencil with
! constant coefficients on a uniform grid, periodic in x and z and periodic or bounded by walls in
! y: mass I - diffusion lap for u, v, w (Helmholtz) and -lap for the pressure increment (Poisson).
! Each 1D second difference with its boundary condition is diagonalised by a real trigonometric
! transform, so the 3D operator is diagonal in the tensor product of three of them (FFTW's r2r
! kinds, FFTW 3.3 manual §4.8):
!   periodic                      R2HC  (halfcomplex DFT), eigenvalue 4 sin^2(pi f/N)/h^2,
!                                       f = min(m, N - m) for output index m; inverse HC2R, norm N
!   cell-centred, zero gradient   REDFT10 (DCT-II), 4 sin^2(pi m/(2N))/h^2; inverse REDFT01, 2N
!     (p at the walls: the neighbour across a wall is dropped)
!   cell-centred, ghost = -x_0    RODFT10 (DST-II), 4 sin^2(pi (m+1)/(2N))/h^2; inverse RODFT01, 2N
!     (u, w at the walls: ghost 2 U_w - x_0, the U_w part on the right-hand side)
!   face-centred, x = 0 on j = 0, N   RODFT00 (DST-I) on j = 1 .. N-1, 4 sin^2(pi (m+1)/(2N))/h^2;
!     (v between walls; row j = 0 is the wall itself, v = 0)     inverse RODFT00, 2N
! A solve is a forward transform, a division by mass + diffusion * (sum of the three eigenvalues)
! and the inverse transform: exact to round-off, O(N log N), the same cost whatever the time step
! or the spheres. Poisson's zero eigenvalue (the constants) gets a zero coefficient: the solution
! has zero mean, as the Krylov path's null-space projection gives.
!
! Parallel layout: FFTW's MPI transforms distribute z in slabs; the DMDA may be split any way, so a
! VecScatter moves each field between the DMDA's global vector and a PETSc vector that wraps the
! FFTW buffer (no further copy). Slabs limit the ranks to the number of cells in z.
#include <petsc/finclude/petscdmda.h>
module mod_fft_solver
  use petscdmda
  use, intrinsic :: iso_c_binding
  use mod_kinds, only: dp, pi
  use mod_grid, only: grid_t, FIELD_V, FIELD_P
  use mod_timers, only: event_begin, event_end, EVENT_FFT
  implicit none
  private
  include 'fftw3-mpi.f03'
  public :: fft_solver_t, fft_create, fft_solve, fft_destroy

  type :: fft_solver_t
    integer :: field = 0
    integer :: first_row = 0       ! 1 for v between walls: row j = 0 (the wall) is not an unknown
    integer :: nx = 0, ny = 0, nz = 0   ! points of the transform
    integer(C_INTPTR_T) :: local_nz = 0, z_start = 0, alloc_local = 0
    integer(C_INTPTR_T) :: local_ny = 0, y_start = 0   ! the y-slab of the transformed (transposed) layout
    integer :: local_n = 0         ! entries of this rank's z-slab
    integer :: local_spectral = 0  ! entries of this rank's y-slab of the transform
    type(C_PTR) :: buffer = C_NULL_PTR, forward = C_NULL_PTR, backward = C_NULL_PTR
    real(C_DOUBLE), pointer :: data(:) => null()
    real(C_DOUBLE), pointer :: result(:) => null()   ! the same buffer: the transforms are in place
    ! 1 / (eigenvalue of the operator x normalisation of the transform pair) in slab order;
    ! 0 for Poisson's constant mode
    real(dp), allocatable :: inverse(:)
    Vec :: slab
    VecScatter :: scatter
  end type fft_solver_t

  logical, save :: fftw_ready = .false.

contains

  ! The solver of field (FIELD_U .. FIELD_P) for mass I - diffusion lap (Poisson: mass 0,
  ! diffusion 1, i.e. -lap). flags: FFTW planner flags (FFTW_MEASURE or FFTW_ESTIMATE).
  subroutine fft_create(grid, field, mass, diffusion, flags, s, ierr)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: field
    real(dp), intent(in) :: mass, diffusion
    integer(C_INT), intent(in) :: flags
    type(fft_solver_t), intent(inout) :: s
    PetscErrorCode, intent(out) :: ierr
    integer(C_FFTW_R2R_KIND) :: kind_y, inverse_y
    real(dp), allocatable :: eig_x(:), eig_y(:), eig_z(:)
    real(dp) :: norm, eigenvalue
    integer :: i, j, k, m, local_n
    PetscInt, allocatable :: natural(:)
    AO :: ao
    IS :: from
    Vec :: template

    if (.not. fftw_ready) then
      call fftw_mpi_init()
      fftw_ready = .true.
    end if
    s%field = field
    s%nx = grid%n(1)
    s%nz = grid%n(3)
    s%ny = grid%n(2)
    s%first_row = 0
    if (grid%walls) then
      select case (field)
      case (FIELD_P)
        kind_y = FFTW_REDFT10
        inverse_y = FFTW_REDFT01
      case (FIELD_V)
        kind_y = FFTW_RODFT00
        inverse_y = FFTW_RODFT00
        s%ny = grid%n(2) - 1
        s%first_row = 1
      case default
        kind_y = FFTW_RODFT10
        inverse_y = FFTW_RODFT01
      end select
    else
      kind_y = FFTW_R2HC
      inverse_y = FFTW_HC2R
    end if

    ! The slab of this rank and a buffer FFTW may use for its transposes. The transform is left
    ! transposed (y distributed instead of z: one global transpose fewer each way, FFTW 3.3 manual
    ! §6.4.3): the division by the eigenvalues does not care where a mode lives.
    s%alloc_local = fftw_mpi_local_size_3d_transposed(int(s%nz, C_INTPTR_T), int(s%ny, C_INTPTR_T), &
                        int(s%nx, C_INTPTR_T), PETSC_COMM_WORLD, s%local_nz, s%z_start, s%local_ny, s%y_start)
    s%buffer = fftw_alloc_real(max(s%alloc_local, 1_C_INTPTR_T))
    call c_f_pointer(s%buffer, s%data, [max(s%alloc_local, 1_C_INTPTR_T)])
    call c_f_pointer(s%buffer, s%result, [max(s%alloc_local, 1_C_INTPTR_T)])
    ! in place, C order [z][y][x] = Fortran (x, y, z): dimension 0 is z
    s%forward = fftw_mpi_plan_r2r_3d(int(s%nz, C_INTPTR_T), int(s%ny, C_INTPTR_T), int(s%nx, C_INTPTR_T), &
                                     s%data, s%result, PETSC_COMM_WORLD, FFTW_R2HC, kind_y, FFTW_R2HC, &
                                     ior(flags, FFTW_MPI_TRANSPOSED_OUT))
    s%backward = fftw_mpi_plan_r2r_3d(int(s%nz, C_INTPTR_T), int(s%ny, C_INTPTR_T), int(s%nx, C_INTPTR_T), &
                                      s%data, s%result, PETSC_COMM_WORLD, FFTW_HC2R, inverse_y, FFTW_HC2R, &
                                      ior(flags, FFTW_MPI_TRANSPOSED_IN))
    if (.not. (c_associated(s%forward) .and. c_associated(s%backward))) then
      ierr = PETSC_ERR_LIB
      SETERRQ(PETSC_COMM_SELF, ierr, 'FFTW could not plan the fluid transforms')
    end if

    ! eigenvalues of -lap per direction, in the transforms' output order
    eig_x = periodic_eigenvalues(s%nx, grid%h)
    eig_z = periodic_eigenvalues(s%nz, grid%h)
    norm = real(s%nx, dp) * real(s%nz, dp)
    if (.not. grid%walls) then
      eig_y = periodic_eigenvalues(s%ny, grid%h)
      norm = norm * s%ny
    else
      allocate(eig_y(s%ny))
      do m = 0, s%ny - 1
        select case (field)
        case (FIELD_P)
          eig_y(m + 1) = 4.0_dp * sin(pi * m / (2.0_dp * grid%n(2)))**2 / grid%h**2
        case default   ! DST-II for u, w; DST-I on n - 1 points for v: the same eigenvalues
          eig_y(m + 1) = 4.0_dp * sin(pi * (m + 1) / (2.0_dp * grid%n(2)))**2 / grid%h**2
        end select
      end do
      norm = norm * 2.0_dp * grid%n(2)
    end if
    local_n = int(s%local_nz) * s%ny * s%nx
    s%local_n = local_n
    ! the transposed layout: C order [y][z][x], y from y_start
    s%local_spectral = int(s%local_ny) * s%nz * s%nx
    allocate(s%inverse(max(s%local_spectral, 1)))
    m = 0
    do j = 1, int(s%local_ny)
      do k = 1, s%nz
        do i = 1, s%nx
          m = m + 1
          eigenvalue = mass + diffusion * (eig_x(i) + eig_y(j + int(s%y_start)) + eig_z(k))
          s%inverse(m) = 0.0_dp
          if (eigenvalue > 0.0_dp) s%inverse(m) = 1.0_dp / (eigenvalue * norm)
        end do
      end do
    end do

    ! the slab as a PETSc vector on FFTW's buffer, and the scatter from the DMDA's global vector:
    ! slab entry (x, y, z) is natural index x + nx (y + first_row + n_y z) of the DMDA
    PetscCall(VecCreateMPIWithArray(PETSC_COMM_WORLD, 1, local_n, PETSC_DECIDE, s%data, s%slab, ierr))
    allocate(natural(max(local_n, 1)))
    m = 0
    do k = int(s%z_start), int(s%z_start + s%local_nz) - 1
      do j = s%first_row, s%first_row + s%ny - 1
        do i = 0, s%nx - 1
          m = m + 1
          natural(m) = i + grid%n(1) * (j + grid%n(2) * k)
        end do
      end do
    end do
    PetscCall(DMDAGetAO(grid%da(field), ao, ierr))
    PetscCall(AOApplicationToPetsc(ao, local_n, natural, ierr))
    PetscCall(ISCreateGeneral(PETSC_COMM_WORLD, local_n, natural, PETSC_COPY_VALUES, from, ierr))
    PetscCall(DMGetGlobalVector(grid%da(field), template, ierr))
    PetscCall(VecScatterCreate(template, from, s%slab, PETSC_NULL_IS, s%scatter, ierr))
    PetscCall(DMRestoreGlobalVector(grid%da(field), template, ierr))
    PetscCall(ISDestroy(from, ierr))
  end subroutine fft_create

  ! 4 sin^2(pi f/n)/h^2 for the halfcomplex output index m = 0 .. n-1, f = min(m, n - m).
  pure function periodic_eigenvalues(n, h) result(eig)
    integer, intent(in) :: n
    real(dp), intent(in) :: h
    real(dp) :: eig(n)
    integer :: m
    do m = 0, n - 1
      eig(m + 1) = 4.0_dp * sin(pi * min(m, n - m) / real(n, dp))**2 / h**2
    end do
  end function periodic_eigenvalues

  ! x = A^{-1} b exactly (to round-off). For v between walls the wall row j = 0 is set to zero.
  subroutine fft_solve(s, b, x, ierr)
    type(fft_solver_t), intent(inout) :: s
    Vec, intent(in) :: b
    Vec, intent(inout) :: x
    PetscErrorCode, intent(out) :: ierr
    integer :: n
    PetscCall(event_begin(EVENT_FFT, ierr))
    PetscCall(VecScatterBegin(s%scatter, b, s%slab, INSERT_VALUES, SCATTER_FORWARD, ierr))
    PetscCall(VecScatterEnd(s%scatter, b, s%slab, INSERT_VALUES, SCATTER_FORWARD, ierr))
    n = s%local_spectral
    call fftw_mpi_execute_r2r(s%forward, s%data, s%result)
    s%data(1:n) = s%data(1:n) * s%inverse
    call fftw_mpi_execute_r2r(s%backward, s%data, s%result)
    if (s%first_row > 0) then
      PetscCall(VecSet(x, 0.0_dp, ierr))
    end if
    PetscCall(VecScatterBegin(s%scatter, s%slab, x, INSERT_VALUES, SCATTER_REVERSE, ierr))
    PetscCall(VecScatterEnd(s%scatter, s%slab, x, INSERT_VALUES, SCATTER_REVERSE, ierr))
    PetscCall(event_end(EVENT_FFT, ierr))
  end subroutine fft_solve

  subroutine fft_destroy(s, ierr)
    type(fft_solver_t), intent(inout) :: s
    PetscErrorCode, intent(out) :: ierr
    ierr = 0
    if (.not. c_associated(s%buffer)) return
    PetscCall(VecScatterDestroy(s%scatter, ierr))
    PetscCall(VecDestroy(s%slab, ierr))
    call fftw_destroy_plan(s%forward)
    call fftw_destroy_plan(s%backward)
    call fftw_free(s%buffer)
    s%buffer = C_NULL_PTR
    s%data => null()
    s%result => null()
    deallocate(s%inverse)      ! all fft_create made: the solver can be created again
  end subroutine fft_destroy

end module mod_fft_solver
