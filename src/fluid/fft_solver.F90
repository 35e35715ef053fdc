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
!
! Memory (doc/BENCHMARKS.md §14, issue 45): the four solvers of a fluid step run
! one after the other, so they share one FFTW buffer and one move to it (module state, counted by
! its users): with the 1 x 1 x P layout an MPI_Alltoallv of plane ranges, otherwise a slab vector
! on the buffer and one scatter. Every field moves as the whole n(1) x n(2) x n(3) block, and v
! between walls, whose transform skips the wall row j = 0, is compacted in the buffer after the
! move and expanded before the way back (copies, exact). The scatter's indices come from the
! DMDA's ownership ranges (grid_petsc_index), not from its application ordering, which would hold
! the global ordering. The operator's inverse eigenvalues are formed during the solve from the
! three 1D eigenvalue lists (the same expression as before, so the same bits) instead of a stored
! grid-sized array: four buffers, four scatters and four such arrays were about 130 B per cell.
!
! Lees-Edwards (doc/METHOD.md §2.4): y is periodic up to a twist of each x-mode, f(x, y + Ly) =
! f(x - delta, y), i.e. exp(i theta_m) per mode m (mod_sliding_boundary, which shifts the rows of
! the explicit stencils the same way). The twisted second difference in y is not diagonalised by a
! real transform, but the phase ramp d(j) = exp(-i theta_m j/ny) c(j) makes it periodic, with
! eigenvalues 4 sin^2((2 pi l + theta_m)/(2 ny))/h^2: so an r2c transform in x, the ramp, a
! complex 2D DFT in (z, y) for every x-mode at once (FFTW's MPI "many" transform, left transposed),
! the division, and back. All four fields share it (there are no wall rows), exact to round-off at
! any offset, in a complex buffer of about the size of the real one.
#include <petsc/finclude/petscdmda.h>
module mod_fft_solver
  use petscdmda
  use, intrinsic :: iso_c_binding
  use mod_kinds, only: dp, pi
  use mod_grid, only: grid_t, grid_petsc_index, FIELD_V, FIELD_P
  use mod_errors, only: fatal_error
  use mod_timers, only: event_begin, event_end, EVENT_FFT
  use mod_sliding_boundary, only: sliding_twist
  implicit none
  private
  include 'fftw3-mpi.f03'
  public :: fft_solver_t, fft_create, fft_solve, fft_destroy, fft_set_sliding_shift

  type :: fft_solver_t
    integer :: field = 0
    integer :: first_row = 0       ! 1 for v between walls: row j = 0 (the wall) is not an unknown
    integer :: nx = 0, ny = 0, nz = 0   ! points of the transform
    integer(C_INTPTR_T) :: local_nz = 0, z_start = 0, alloc_local = 0
    integer(C_INTPTR_T) :: local_ny = 0, y_start = 0   ! the y-slab of the transformed (transposed) layout
    integer :: local_n = 0         ! entries of this rank's z-slab
    integer :: local_spectral = 0  ! entries of this rank's y-slab of the transform
    logical :: made = .false.
    type(C_PTR) :: forward = C_NULL_PTR, backward = C_NULL_PTR
    ! the operator mass I - diffusion lap: its eigenvalues are mass + diffusion (eig_x(i) + eig_y(j)
    ! + eig_z(k)), formed during the solve; norm: the normalisation of the transform pair
    real(dp) :: mass = 0.0_dp, diffusion = 0.0_dp, norm = 1.0_dp
    real(dp) :: h_squared = 1.0_dp   ! Lees-Edwards: the y eigenvalues are formed per solve
    real(dp), allocatable :: eig_x(:), eig_y(:), eig_z(:)
  end type fft_solver_t

  logical, save :: fftw_ready = .false.

  ! Shared by every solver of one grid (see the top of this file): the FFTW buffer, the slab
  ! vector on it (this rank's z-slab of the whole n(1) x n(2) x n(3) block) and the scatter from
  ! the DMDA's global vector; made by the first fft_create, destroyed by the last fft_destroy.
  integer, save :: shared_users = 0
  integer, save :: shared_n(3) = 0
  integer(C_INTPTR_T), save :: shared_size = 0
  integer, save :: shared_local_full = 0   ! entries of the whole-block slab on this rank
  type(C_PTR), save :: shared_buffer = C_NULL_PTR
  real(C_DOUBLE), pointer, save :: shared_data(:) => null()
  Vec, save :: shared_slab
  VecScatter, save :: shared_scatter
  ! With a 1 x 1 x P process grid (what mod_grid picks for the direct solves) the DMDA's ranks own
  ! whole z-planes in rank order, so its global vector is in natural order, as FFTW's slabs are:
  ! the move is one MPI_Alltoallv of contiguous plane ranges (counts and offsets in entries, to
  ! and from each rank), with no per-point index (the scatter's graph and set-up were ~20 B per
  ! cell). Otherwise the VecScatter above.
  logical, save :: shared_planes = .false.
  integer, allocatable, save :: vec_counts(:), vec_offsets(:), slab_counts(:), slab_offsets(:)
  ! Lees-Edwards (see the top): the complex buffer of the x-modes [z][y][mode], its y-slab once
  ! transposed, the plans shared by the four fields, and the offset delta in cells
  logical, save :: shared_sliding = .false.
  integer, save :: sliding_modes = 0          ! n(1)/2 + 1
  integer(C_INTPTR_T), save :: sliding_local_ny = 0, sliding_y_start = 0, sliding_local_nz = 0
  type(C_PTR), save :: sliding_buffer = C_NULL_PTR
  complex(C_DOUBLE_COMPLEX), pointer, contiguous, save :: sliding_data(:) => null()
  type(C_PTR), save :: plan_x_forward = C_NULL_PTR, plan_x_backward = C_NULL_PTR
  type(C_PTR), save :: plan_yz_forward = C_NULL_PTR, plan_yz_backward = C_NULL_PTR
  real(dp), save :: sliding_shift = 0.0_dp

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
    real(C_DOUBLE), pointer :: data(:), result(:)
    integer :: m

    if (.not. fftw_ready) then
      call fftw_mpi_init()
      fftw_ready = .true.
    end if
    PetscCall(shared_acquire(grid, flags, ierr))
    s%field = field
    s%nx = grid%n(1)
    s%nz = grid%n(3)
    s%ny = grid%n(2)
    s%first_row = 0
    if (shared_sliding) then
      ! one transform for every field (see the top): only the operator is the solver's own
      s%mass = mass
      s%diffusion = diffusion
      allocate(s%eig_x(sliding_modes))
      do m = 0, sliding_modes - 1
        s%eig_x(m + 1) = 4.0_dp * sin(pi * m / real(s%nx, dp))**2 / grid%h**2
      end do
      s%eig_z = periodic_eigenvalues(s%nz, grid%h)
      allocate(s%eig_y(0))
      s%h_squared = grid%h**2
      s%norm = real(s%nx, dp) * real(s%ny, dp) * real(s%nz, dp)
      s%local_nz = sliding_local_nz
      s%made = .true.
      return
    end if
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

    ! The slab of this rank and the room FFTW needs for its transposes (within the shared buffer,
    ! which shared_acquire sized for every field). The transform is left
    ! transposed (y distributed instead of z: one global transpose fewer each way, FFTW 3.3 manual
    ! §6.4.3): the division by the eigenvalues does not care where a mode lives.
    s%alloc_local = fftw_mpi_local_size_3d_transposed(int(s%nz, C_INTPTR_T), int(s%ny, C_INTPTR_T), &
                        int(s%nx, C_INTPTR_T), PETSC_COMM_WORLD, s%local_nz, s%z_start, s%local_ny, s%y_start)
    if (s%alloc_local > shared_size) call fatal_error('fdsusp: internal error: the shared FFT buffer is too small', 4)
    data => shared_data
    result => shared_data     ! in place: the same buffer
    ! in place, C order [z][y][x] = Fortran (x, y, z): dimension 0 is z
    s%forward = fftw_mpi_plan_r2r_3d(int(s%nz, C_INTPTR_T), int(s%ny, C_INTPTR_T), int(s%nx, C_INTPTR_T), &
                                     data, result, PETSC_COMM_WORLD, FFTW_R2HC, kind_y, FFTW_R2HC, &
                                     ior(flags, FFTW_MPI_TRANSPOSED_OUT))
    s%backward = fftw_mpi_plan_r2r_3d(int(s%nz, C_INTPTR_T), int(s%ny, C_INTPTR_T), int(s%nx, C_INTPTR_T), &
                                      data, result, PETSC_COMM_WORLD, FFTW_HC2R, inverse_y, FFTW_HC2R, &
                                      ior(flags, FFTW_MPI_TRANSPOSED_IN))
    if (.not. (c_associated(s%forward) .and. c_associated(s%backward))) then
      ierr = PETSC_ERR_LIB
      SETERRQ(PETSC_COMM_SELF, ierr, 'FFTW could not plan the fluid transforms')
    end if

    ! eigenvalues of -lap per direction, in the transforms' output order
    s%mass = mass
    s%diffusion = diffusion
    s%eig_x = periodic_eigenvalues(s%nx, grid%h)
    s%eig_z = periodic_eigenvalues(s%nz, grid%h)
    s%norm = real(s%nx, dp) * real(s%nz, dp)
    if (.not. grid%walls) then
      s%eig_y = periodic_eigenvalues(s%ny, grid%h)
      s%norm = s%norm * s%ny
    else
      allocate(s%eig_y(s%ny))
      do m = 0, s%ny - 1
        select case (field)
        case (FIELD_P)
          s%eig_y(m + 1) = 4.0_dp * sin(pi * m / (2.0_dp * grid%n(2)))**2 / grid%h**2
        case default   ! DST-II for u, w; DST-I on n - 1 points for v: the same eigenvalues
          s%eig_y(m + 1) = 4.0_dp * sin(pi * (m + 1) / (2.0_dp * grid%n(2)))**2 / grid%h**2
        end select
      end do
      s%norm = s%norm * 2.0_dp * grid%n(2)
    end if
    s%local_n = int(s%local_nz) * s%ny * s%nx
    ! the transposed layout: C order [y][z][x], y from y_start
    s%local_spectral = int(s%local_ny) * s%nz * s%nx
    s%made = .true.
  end subroutine fft_create

  ! The first solver of a grid makes the shared buffer, slab vector and scatter; the others check
  ! that they solve on the same grid. The buffer holds this rank's z-slab of the whole block and
  ! whatever FFTW asks for the transforms of every field (v between walls has n(2) - 1 rows).
  ! The scatter: slab entry (x, y, z) is natural point (x, y, z_start + z) of the DMDA.
  subroutine shared_acquire(grid, flags, ierr)
    type(grid_t), intent(in) :: grid
    integer(C_INT), intent(in) :: flags
    PetscErrorCode, intent(out) :: ierr
    integer(C_INTPTR_T) :: local_nz, z_start, local_ny, y_start, need
    integer :: i, j, k, m, ny
    PetscInt, allocatable :: petsc_index(:)
    IS :: from
    Vec :: template

    ierr = 0
    if (shared_users > 0) then
      if (any(shared_n /= grid%n)) call fatal_error('fdsusp: internal error: FFT solvers of two grids at once', 4)
      shared_users = shared_users + 1
      return
    end if
    need = 1
    do ny = grid%n(2) - 1, grid%n(2)
      need = max(need, fftw_mpi_local_size_3d_transposed(int(grid%n(3), C_INTPTR_T), int(max(ny, 1), C_INTPTR_T), &
                 int(grid%n(1), C_INTPTR_T), PETSC_COMM_WORLD, local_nz, z_start, local_ny, y_start))
    end do
    ! local_nz and z_start depend on n(3) alone: the same slab for every field
    shared_local_full = int(local_nz) * grid%n(2) * grid%n(1)
    need = max(need, int(shared_local_full, C_INTPTR_T))
    shared_size = need
    shared_buffer = fftw_alloc_real(need)
    call c_f_pointer(shared_buffer, shared_data, [need])
    shared_n = grid%n
    shared_users = 1

    if (grid%lees_edwards) call sliding_acquire(grid, int(local_nz), flags)
    shared_planes = grid%nprocs(1) == 1 .and. grid%nprocs(2) == 1
    if (shared_planes) then
      call plane_exchange(grid, int(z_start), int(local_nz))
      return
    end if
    PetscCall(VecCreateMPIWithArray(PETSC_COMM_WORLD, 1, shared_local_full, PETSC_DECIDE, shared_data, shared_slab, ierr))
    allocate(petsc_index(max(shared_local_full, 1)))
    m = 0
    do k = int(z_start), int(z_start + local_nz) - 1
      do j = 0, grid%n(2) - 1
        do i = 0, grid%n(1) - 1
          m = m + 1
          petsc_index(m) = grid_petsc_index(grid, i, j, k)
        end do
      end do
    end do
    PetscCall(ISCreateGeneral(PETSC_COMM_WORLD, shared_local_full, petsc_index, PETSC_COPY_VALUES, from, ierr))
    deallocate(petsc_index)
    PetscCall(DMGetGlobalVector(grid%da(FIELD_P), template, ierr))
    PetscCall(VecScatterCreate(template, from, shared_slab, PETSC_NULL_IS, shared_scatter, ierr))
    PetscCall(DMRestoreGlobalVector(grid%da(FIELD_P), template, ierr))
    PetscCall(ISDestroy(from, ierr))
  end subroutine shared_acquire

  ! The Lees-Edwards transforms (see the top), on the shared buffer's z-slab of local_nz planes:
  ! r2c in x of every row of the slab into the complex buffer [z][y][mode], and the distributed
  ! complex DFT in (z, y) of every mode, left transposed ([y][z][mode], y in slabs).
  subroutine sliding_acquire(grid, local_nz, flags)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: local_nz
    integer(C_INT), intent(in) :: flags
    integer(C_INTPTR_T) :: dims(2), need, local_n0, start0
    integer(C_INT) :: length(1)
    complex(C_DOUBLE_COMPLEX), pointer :: transformed(:)
    shared_sliding = .true.
    sliding_modes = grid%n(1) / 2 + 1
    dims = [int(grid%n(3), C_INTPTR_T), int(grid%n(2), C_INTPTR_T)]
    need = fftw_mpi_local_size_many_transposed(2, dims, int(sliding_modes, C_INTPTR_T), FFTW_MPI_DEFAULT_BLOCK, &
               FFTW_MPI_DEFAULT_BLOCK, PETSC_COMM_WORLD, local_n0, start0, sliding_local_ny, sliding_y_start)
    if (local_n0 /= local_nz) call fatal_error('fdsusp: internal error: the Lees-Edwards transform splits z '// &
                                               'unlike the fluid''s slabs', 4)
    sliding_local_nz = local_n0
    sliding_buffer = fftw_alloc_complex(max(need, 1_C_INTPTR_T))
    call c_f_pointer(sliding_buffer, sliding_data, [max(need, 1_C_INTPTR_T)])
    transformed => sliding_data   ! in place: the same buffer
    length = grid%n(1)
    if (local_nz > 0) then
      plan_x_forward = fftw_plan_many_dft_r2c(1, length, local_nz * grid%n(2), shared_data, length, 1, grid%n(1), &
                                              sliding_data, [sliding_modes], 1, sliding_modes, flags)
      plan_x_backward = fftw_plan_many_dft_c2r(1, length, local_nz * grid%n(2), sliding_data, [sliding_modes], 1, &
                                               sliding_modes, shared_data, length, 1, grid%n(1), flags)
    end if
    plan_yz_forward = fftw_mpi_plan_many_dft(2, dims, int(sliding_modes, C_INTPTR_T), FFTW_MPI_DEFAULT_BLOCK, &
                          FFTW_MPI_DEFAULT_BLOCK, sliding_data, transformed, PETSC_COMM_WORLD, FFTW_FORWARD, &
                          ior(flags, FFTW_MPI_TRANSPOSED_OUT))
    plan_yz_backward = fftw_mpi_plan_many_dft(2, dims, int(sliding_modes, C_INTPTR_T), FFTW_MPI_DEFAULT_BLOCK, &
                           FFTW_MPI_DEFAULT_BLOCK, sliding_data, transformed, PETSC_COMM_WORLD, FFTW_BACKWARD, &
                           ior(flags, FFTW_MPI_TRANSPOSED_IN))
    if (.not. (c_associated(plan_yz_forward) .and. c_associated(plan_yz_backward)) .or. (local_nz > 0 .and. &
        .not. (c_associated(plan_x_forward) .and. c_associated(plan_x_backward)))) &
      call fatal_error('fdsusp: error: FFTW could not plan the Lees-Edwards transforms of the fluid', 4)
  end subroutine sliding_acquire

  ! The offset delta of the Lees-Edwards boundary, in cells, that the next solves take (every
  ! field's: the fluid sets it before each solve, doc/METHOD.md §2.4).
  subroutine fft_set_sliding_shift(shift)
    real(dp), intent(in) :: shift
    sliding_shift = shift
  end subroutine fft_set_sliding_shift

  ! The solve of fft_solve on the shared buffer, Lees-Edwards (see the top). The ramp and the y
  ! eigenvalues depend on the offset, so they are tabulated per solve (modes x rows, small).
  subroutine sliding_solve(s)
    type(fft_solver_t), intent(in) :: s
    complex(dp), allocatable :: ramp(:, :)
    real(dp), allocatable :: eig_y(:, :)
    real(dp) :: theta, eigenvalue
    integer :: i, j, k, m, l, nk
    nk = sliding_modes
    allocate(ramp(nk, 0:s%ny - 1), eig_y(nk, max(1, int(sliding_local_ny))))
    do i = 1, nk
      theta = sliding_twist(i - 1, s%nx, sliding_shift)
      do j = 0, s%ny - 1
        ramp(i, j) = cmplx(cos(theta * j / s%ny), -sin(theta * j / s%ny), dp)
      end do
      do j = 1, int(sliding_local_ny)
        l = j - 1 + int(sliding_y_start)
        eig_y(i, j) = 4.0_dp * sin((2.0_dp * pi * l + theta) / (2.0_dp * s%ny))**2 / s%h_squared
      end do
    end do
    if (sliding_local_nz > 0) call fftw_execute_dft_r2c(plan_x_forward, shared_data, sliding_data)
    ! d(j) = exp(-i theta j/ny) c(j): periodic in y
    m = 0
    do k = 1, int(sliding_local_nz)
      do j = 0, s%ny - 1
        sliding_data(m + 1:m + nk) = sliding_data(m + 1:m + nk) * ramp(:, j)
        m = m + nk
      end do
    end do
    call fftw_mpi_execute_dft(plan_yz_forward, sliding_data, sliding_data)
    ! transposed: [y][z][mode]
    m = 0
    do j = 1, int(sliding_local_ny)
      do k = 1, s%nz
        do i = 1, nk
          m = m + 1
          eigenvalue = s%mass + s%diffusion * (s%eig_x(i) + eig_y(i, j) + s%eig_z(k))
          if (eigenvalue > 0.0_dp) then
            sliding_data(m) = sliding_data(m) * (1.0_dp / (eigenvalue * s%norm))
          else
            sliding_data(m) = (0.0_dp, 0.0_dp)
          end if
        end do
      end do
    end do
    call fftw_mpi_execute_dft(plan_yz_backward, sliding_data, sliding_data)
    m = 0
    do k = 1, int(sliding_local_nz)
      do j = 0, s%ny - 1
        sliding_data(m + 1:m + nk) = sliding_data(m + 1:m + nk) * conjg(ramp(:, j))
        m = m + nk
      end do
    end do
    if (sliding_local_nz > 0) call fftw_execute_dft_c2r(plan_x_backward, sliding_data, shared_data)
  end subroutine sliding_solve

  ! The counts and offsets of the plane exchange (shared_planes): this rank's DMDA planes
  ! [a, a + lz) go to each rank's FFTW slab [c, c + nz), the overlap, and come back the same way.
  subroutine plane_exchange(grid, z_start, local_nz)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: z_start, local_nz
    integer :: nranks, me, r, plane, mpierr, mine(2), lo, hi, a, b
    integer, allocatable :: slabs(:, :), dmda_start(:)
    call MPI_Comm_size(PETSC_COMM_WORLD, nranks, mpierr)
    call MPI_Comm_rank(PETSC_COMM_WORLD, me, mpierr)
    allocate(slabs(2, nranks), dmda_start(nranks + 1))
    mine = [z_start, local_nz]
    call MPI_Allgather(mine, 2, MPI_INTEGER, slabs, 2, MPI_INTEGER, PETSC_COMM_WORLD, mpierr)
    dmda_start(1) = 0
    do r = 1, nranks
      dmda_start(r + 1) = dmda_start(r) + int(grid%rank_cells_z(r))
    end do
    plane = grid%n(1) * grid%n(2)
    allocate(vec_counts(nranks), vec_offsets(nranks), slab_counts(nranks), slab_offsets(nranks))
    a = dmda_start(me + 1)
    b = dmda_start(me + 2)
    do r = 1, nranks
      ! to rank r: my DMDA planes within its slab
      lo = max(a, slabs(1, r))
      hi = min(b, slabs(1, r) + slabs(2, r))
      vec_counts(r) = max(0, hi - lo) * plane
      vec_offsets(r) = max(0, lo - a) * plane
      ! from rank r: its DMDA planes within my slab
      lo = max(dmda_start(r), z_start)
      hi = min(dmda_start(r + 1), z_start + local_nz)
      slab_counts(r) = max(0, hi - lo) * plane
      slab_offsets(r) = max(0, lo - z_start) * plane
    end do
  end subroutine plane_exchange

  ! The plane exchange (shared_planes) of a global vector into the slab (forward) or back.
  subroutine move_planes(v, forward, ierr)
    Vec, intent(in) :: v
    logical, intent(in) :: forward
    PetscErrorCode, intent(out) :: ierr
    PetscScalar, pointer :: a(:)
    PetscInt :: n
    integer :: mpierr
    PetscCall(VecGetLocalSize(v, n, ierr))
    if (forward) then
      PetscCall(VecGetArrayReadF90(v, a, ierr))
      ! first elements, not arrays: the addresses, no copy (an empty block sends nothing)
      if (n > 0) then
        call MPI_Alltoallv(a(1), vec_counts, vec_offsets, MPI_DOUBLE_PRECISION, shared_data(1), slab_counts, &
                           slab_offsets, MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, mpierr)
      else
        call MPI_Alltoallv(shared_data(1), vec_counts, vec_offsets, MPI_DOUBLE_PRECISION, shared_data(1), slab_counts, &
                           slab_offsets, MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, mpierr)
      end if
      PetscCall(VecRestoreArrayReadF90(v, a, ierr))
    else
      PetscCall(VecGetArrayF90(v, a, ierr))
      if (n > 0) then
        call MPI_Alltoallv(shared_data(1), slab_counts, slab_offsets, MPI_DOUBLE_PRECISION, a(1), vec_counts, &
                           vec_offsets, MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, mpierr)
      else
        call MPI_Alltoallv(shared_data(1), slab_counts, slab_offsets, MPI_DOUBLE_PRECISION, shared_data(1), vec_counts, &
                           vec_offsets, MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, mpierr)
      end if
      PetscCall(VecRestoreArrayF90(v, a, ierr))
    end if
    ierr = mpierr
  end subroutine move_planes

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
  ! b and x may be the same vector (b is read whole before x is written).
  subroutine fft_solve(s, b, x, ierr)
    type(fft_solver_t), intent(inout) :: s
    Vec, intent(in) :: b
    Vec, intent(inout) :: x
    PetscErrorCode, intent(out) :: ierr
    real(C_DOUBLE), pointer :: data(:), result(:)
    real(dp) :: eigenvalue
    integer :: i, j, k, m, plane, row, full_ny
    PetscCall(event_begin(EVENT_FFT, ierr))
    data => shared_data
    result => shared_data
    full_ny = s%ny + s%first_row
    if (shared_planes) then
      PetscCall(move_planes(b, .true., ierr))
    else
      PetscCall(VecScatterBegin(shared_scatter, b, shared_slab, INSERT_VALUES, SCATTER_FORWARD, ierr))
      PetscCall(VecScatterEnd(shared_scatter, b, shared_slab, INSERT_VALUES, SCATTER_FORWARD, ierr))
    end if
    if (s%first_row > 0) then
      ! compact: drop the wall row of every plane (forward: each row moves to a lower address)
      m = 0
      do k = 0, int(s%local_nz) - 1
        do row = s%first_row, full_ny - 1
          plane = (k * full_ny + row) * s%nx
          data(m + 1:m + s%nx) = data(plane + 1:plane + s%nx)
          m = m + s%nx
        end do
      end do
    end if
    if (shared_sliding) then
      call sliding_solve(s)
    else
    call fftw_mpi_execute_r2r(s%forward, data, result)
    ! divide by the eigenvalues: the expression and the order of the stored inverse of before
    m = 0
    do j = 1, int(s%local_ny)
      do k = 1, s%nz
        do i = 1, s%nx
          m = m + 1
          eigenvalue = s%mass + s%diffusion * (s%eig_x(i) + s%eig_y(j + int(s%y_start)) + s%eig_z(k))
          if (eigenvalue > 0.0_dp) then
            data(m) = data(m) * (1.0_dp / (eigenvalue * s%norm))
          else
            data(m) = data(m) * 0.0_dp
          end if
        end do
      end do
    end do
    call fftw_mpi_execute_r2r(s%backward, data, result)
    end if
    if (s%first_row > 0) then
      ! expand (backward: each row moves to a higher address), the wall row zero
      m = s%local_n
      do k = int(s%local_nz) - 1, 0, -1
        do row = full_ny - 1, s%first_row, -1
          plane = (k * full_ny + row) * s%nx
          m = m - s%nx
          do i = s%nx, 1, -1
            data(plane + i) = data(m + i)
          end do
        end do
        plane = k * full_ny * s%nx
        data(plane + 1:plane + s%first_row * s%nx) = 0.0_dp
      end do
    end if
    if (shared_planes) then
      PetscCall(move_planes(x, .false., ierr))
    else
      PetscCall(VecScatterBegin(shared_scatter, shared_slab, x, INSERT_VALUES, SCATTER_REVERSE, ierr))
      PetscCall(VecScatterEnd(shared_scatter, shared_slab, x, INSERT_VALUES, SCATTER_REVERSE, ierr))
    end if
    PetscCall(event_end(EVENT_FFT, ierr))
  end subroutine fft_solve

  subroutine fft_destroy(s, ierr)
    type(fft_solver_t), intent(inout) :: s
    PetscErrorCode, intent(out) :: ierr
    ierr = 0
    if (.not. s%made) return
    if (c_associated(s%forward)) call fftw_destroy_plan(s%forward)
    if (c_associated(s%backward)) call fftw_destroy_plan(s%backward)
    deallocate(s%eig_x, s%eig_y, s%eig_z)    ! all fft_create made: the solver can be created again
    s%made = .false.
    shared_users = shared_users - 1
    if (shared_users > 0) return
    if (shared_planes) then
      deallocate(vec_counts, vec_offsets, slab_counts, slab_offsets)
    else
      PetscCall(VecScatterDestroy(shared_scatter, ierr))
      PetscCall(VecDestroy(shared_slab, ierr))
    end if
    shared_planes = .false.
    if (shared_sliding) then
      if (c_associated(plan_x_forward)) call fftw_destroy_plan(plan_x_forward)
      if (c_associated(plan_x_backward)) call fftw_destroy_plan(plan_x_backward)
      call fftw_destroy_plan(plan_yz_forward)
      call fftw_destroy_plan(plan_yz_backward)
      call fftw_free(sliding_buffer)
      plan_x_forward = C_NULL_PTR
      plan_x_backward = C_NULL_PTR
      sliding_buffer = C_NULL_PTR
      sliding_data => null()
      shared_sliding = .false.
    end if
    call fftw_free(shared_buffer)
    shared_buffer = C_NULL_PTR
    shared_data => null()
    shared_n = 0
  end subroutine fft_destroy

end module mod_fft_solver
