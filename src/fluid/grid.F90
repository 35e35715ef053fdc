! The staggered (MAC) grid and its PETSc layout: the only module that knows where each unknown
! lives.
!
! Cells are cubes of side h = a/cells_per_radius; there are n(1) x n(2) x n(3) of them. Unknowns,
! with 0-based indices (i, j, k):
!   u(i,j,k) at (i h, (j+1/2) h, (k+1/2) h)         x-faces
!   v(i,j,k) at ((i+1/2) h, j h, (k+1/2) h)         y-faces
!   w(i,j,k) at ((i+1/2) h, (j+1/2) h, k h)         z-faces
!   p(i,j,k) at ((i+1/2) h, (j+1/2) h, (k+1/2) h)   cell centres
! Every field is stored on its own scalar DMDA of n(1) x n(2) x n(3) points, all four with the
! same decomposition, and every DMDA is periodic in x, y and z. With walls in y the walls are
! enforced by the operators, not by the layout: the bottom wall y = 0 is the face j = 0 of v
! (v = 0 there, a fixed row), and the top wall y = Ly is the face j = n(2), which the periodic
! layout identifies with j = 0, so it holds the same zero. Cell-centred fields see the walls
! between j = n(2)-1 and j = 0 and never couple across them. This keeps one layout for all
! fields and lets PETSc's periodic DMDA coarsening (n -> n/2) build the multigrid hierarchy.
!
! Stencils (doc/DESIGN.md "Ghost layers"): a ghost exchange fills only the ghosts its DMDA's stencil
! names. The four field DMDAs have a star stencil of width 1: every operator of the fluid step (the
! 7-point Laplacian, the one-sided gradient and divergence, the wall ghosts, the cell-centre
! averages of the output) reads the six face neighbours only, never an edge or corner ghost, and
! a box stencil would make DMCreateMatrix preallocate and store 27 entries per row instead of 7 in
! every Krylov operator and multigrid level. A read that interpolates across cells diagonally,
! the trilinear Lambda carry of mod_fictitious_domain, needs the edge and corner ghosts as well:
! it gets its own box-stencil DMDA with the same decomposition (grid_create_box_layout), made
! only when there are particles. With a star stencil those ghosts are never filled (they keep
! whatever the local vector held), so faces within a cell of an edge of a rank's block (where two
! of its sides meet, each a rank or a periodic boundary) read stale values, and as the edges move
! with the rank layout, so did the answer.
!
! Memory (doc/BENCHMARKS.md §14, doc/DESIGN.md "One layout with the direct solves"): with the
! direct (FFT) solves of the default path no matrix is ever made from the layout, so the star
! stencil buys nothing there: the four fields and the carry then share ONE box-stencil DMDA
! (grid%da(1:4) and grid_create_box_layout hand out the same DM, referenced once per handle).
! One DMDA instead of five holds one local-to-global map and one ghost scatter instead of five
! (about 25 B per cell each, summed over ranks), and the borrowed work vectors of every field
! come from one cache. The extra edge and corner ghosts it fills are never read by the fluid's
! operators, so the fields are bitwise the same. The Krylov path (-fluid_solver krylov) keeps four
! star DMDAs: each KSP keeps its operator callback and multigrid options on its own DM. fdsusp
! itself builds no application ordering (AO): the FFT scatter and the Krylov path's cell-centred
! prolongation number points from the ownership ranges (ownership_index). Should anything else ask
! (a natural-order viewer), every DMDA's AO is memory-scalable: the default is a copy of the
! global ordering on every rank (16 B per cell of the whole grid on each rank, 32 GB per rank at
! 1e9 cells).
#include <petsc/finclude/petscdmda.h>
module mod_grid
  use petscdmda
  use mod_kinds, only: dp
  use mod_params, only: config_t
  use mod_errors, only: log_line, fatal_error
  implicit none
  private
  public :: grid_t, grid_create, grid_destroy, grid_position, grid_fixed_row, direct_solves_wanted
  public :: grid_create_box_layout, grid_create_star_layout, grid_petsc_index, ownership_index
  public :: FIELD_U, FIELD_V, FIELD_W, FIELD_P, field_names

  integer, parameter :: FIELD_U = 1, FIELD_V = 2, FIELD_W = 3, FIELD_P = 4
  character(len=1), parameter :: field_names(4) = ['u', 'v', 'w', 'p']

  type :: grid_t
    integer :: n(3) = 0           ! cells in x, y, z
    real(dp) :: h = 0.0_dp        ! cell size [a]
    real(dp) :: box(3) = 0.0_dp   ! box lengths [a]
    logical :: walls = .true.     ! walls at y = 0 and y = Ly
    logical :: lees_edwards = .false.   ! sliding periodic in y (doc/METHOD.md §2.4): x and y never split
    integer :: mg_levels = 1      ! levels the decomposition allows for geometric multigrid
    integer :: nprocs(3) = 1      ! process grid
    DM :: da(4)                   ! u, v, w, p (star stencil, width 1; with the direct solves one shared box DMDA)
    logical :: shared_layout = .false.  ! da(1:4) are one DMDA (box stencil): the direct-solve path
    ! cells owned by each rank of the process grid along x, y, z (the same for every field)
    PetscInt, allocatable :: rank_cells_x(:), rank_cells_y(:), rank_cells_z(:)
    integer :: lo(3) = 0, hi(3) = -1    ! owned index range (inclusive, 0-based)
    integer :: glo(3) = 0, ghi(3) = -1  ! owned range with one layer of ghosts
  end type grid_t

contains

  subroutine grid_create(cfg, grid, ierr)
    type(config_t), intent(in) :: cfg
    type(grid_t), intent(inout) :: grid
    PetscErrorCode, intent(out) :: ierr
    DM :: trial
    PetscInt :: dim, mx, my, mz, m(3), dof, sw, nlev, block, d, f
    PetscInt :: bt(3), st
    PetscInt, allocatable :: lx(:), ly(:), lz(:)
    PetscInt :: xs, ys, zs, xm, ym, zm
    character(len=200) :: text

    grid%n = cfg%cells
    grid%h = cfg%h
    grid%box = cfg%domain%box
    grid%walls = cfg%walls
    grid%lees_edwards = cfg%lees_edwards

    ! Let PETSc choose the process grid, then align each rank's share to the coarsest
    ! multigrid block so that every level coarsens with the same decomposition.
    PetscCall(DMDACreate3d(PETSC_COMM_WORLD, DM_BOUNDARY_PERIODIC, DM_BOUNDARY_PERIODIC, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_STAR, grid%n(1), grid%n(2), grid%n(3), PETSC_DECIDE, PETSC_DECIDE, PETSC_DECIDE, 1, 1, PETSC_NULL_INTEGER, PETSC_NULL_INTEGER, PETSC_NULL_INTEGER, trial, ierr))
    PetscCall(DMSetUp(trial, ierr))
    PetscCall(DMDAGetInfo(trial, dim, mx, my, mz, m(1), m(2), m(3), dof, sw, bt(1), bt(2), bt(3), st, ierr))
    PetscCall(DMDestroy(trial, ierr))
    ! The direct (FFT) solves of the fluid step move each field to z-slabs (mod_fft_solver): split
    ! the grid the same way, so that the move is a copy on each rank instead of an exchange between
    ! all of them (PETSc picked 1 x 2 x 1 for 100^3 on 2 ranks; doc/BENCHMARKS.md §8).
    if (direct_solves_wanted() .and. product(m) <= grid%n(3) / 2) m = [1, 1, product(m)]
    if (grid%lees_edwards) then
      ! the sliding boundary shifts whole rows in x across y = 0, Ly on the rank that holds them
      ! (mod_sliding_boundary): z-slabs only
      if (product(m) > grid%n(3)) call fatal_error('fdsusp: error: y_boundary = ''lees-edwards'' splits the grid in '// &
           'z-slabs only: at most one rank per cell in z', 2)
      m = [1, 1, product(m)]
    end if
    grid%nprocs = m

    nlev = 1
    do while (nlev < 8)
      block = 2**nlev
      if (any(mod(grid%n, block) /= 0)) exit
      if (any(grid%n / block < max(3, m))) exit
      nlev = nlev + 1
    end do
    grid%mg_levels = nlev
    block = 2**(nlev - 1)
    call shares(grid%n(1) / block, m(1), block, lx)
    call shares(grid%n(2) / block, m(2), block, ly)
    call shares(grid%n(3) / block, m(3), block, lz)

    grid%rank_cells_x = lx
    grid%rank_cells_y = ly
    grid%rank_cells_z = lz
    grid%shared_layout = direct_solves_wanted()
    if (grid%shared_layout) then
      ! the direct solves make no matrix: one box-stencil DMDA for the four fields and the carry
      ! (see the top of this file)
      PetscCall(DMDACreate3d(PETSC_COMM_WORLD, DM_BOUNDARY_PERIODIC, DM_BOUNDARY_PERIODIC, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_BOX, grid%n(1), grid%n(2), grid%n(3), m(1), m(2), m(3), 1, 1, lx, ly, lz, grid%da(1), ierr))
      PetscCall(DMDASetAOType(grid%da(1), AOMEMORYSCALABLE, ierr))
      PetscCall(DMSetUp(grid%da(1), ierr))
      do f = 2, 4
        grid%da(f) = grid%da(1)
        PetscCall(PetscObjectReference(grid%da(1), ierr))
      end do
    else
      ! star: the fluid's operators read face neighbours only (see the top of this file)
      do f = 1, 4
        PetscCall(grid_create_star_layout(grid, f, grid%da(f), ierr))
      end do
    end if
    PetscCall(DMDAGetCorners(grid%da(FIELD_P), xs, ys, zs, xm, ym, zm, ierr))
    grid%lo = [xs, ys, zs]
    grid%hi = grid%lo + [xm, ym, zm] - 1
    PetscCall(DMDAGetGhostCorners(grid%da(FIELD_P), xs, ys, zs, xm, ym, zm, ierr))
    grid%glo = [xs, ys, zs]
    grid%ghi = grid%glo + [xm, ym, zm] - 1

    write(text, '(a,3(i0,1x),a,es10.3,a,3(i0,1x),a,i0)') 'grid: cells ', grid%n, '  h = ', grid%h, &
         '  process grid ', m, '  multigrid levels ', nlev
    call log_line(text)
    do d = 1, 3
      if (grid%n(d) / 2**(nlev - 1) > 64) then
        call log_line('grid: note: the coarsest multigrid level is large in one direction; '// &
             'cell counts with more factors of 2 make the solves cheaper')
        exit
      end if
    end do
  end subroutine grid_create

  ! A scalar DMDA with the decomposition of the fields (the same owned and ghosted index ranges, so
  ! every vector of grid%da works with it) whose one layer of ghosts holds the edge and corner
  ! neighbours too (box stencil): for reads that interpolate trilinearly across a cell, the Lambda
  ! carry of mod_fictitious_domain. Width 1 is enough as a sphere moves less than a cell per step.
  ! The caller destroys it. With the shared layout of the direct solves it is grid%da(1) itself,
  ! referenced once more.
  subroutine grid_create_box_layout(grid, da, ierr)
    type(grid_t), intent(in) :: grid
    DM, intent(out) :: da
    PetscErrorCode, intent(out) :: ierr
    if (grid%shared_layout) then
      da = grid%da(1)
      PetscCall(PetscObjectReference(grid%da(1), ierr))
      return
    end if
    PetscCall(DMDACreate3d(PETSC_COMM_WORLD, DM_BOUNDARY_PERIODIC, DM_BOUNDARY_PERIODIC, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_BOX, grid%n(1), grid%n(2), grid%n(3), grid%nprocs(1), grid%nprocs(2), grid%nprocs(3), 1, 1, grid%rank_cells_x, grid%rank_cells_y, grid%rank_cells_z, da, ierr))
    PetscCall(DMDASetAOType(da, AOMEMORYSCALABLE, ierr))
    PetscCall(DMSetUp(da, ierr))
  end subroutine grid_create_box_layout

  ! The star-stencil DMDA of field f (options prefix u_, v_, w_ or p_) with the fields'
  ! decomposition: each field's own in the Krylov path, and a Krylov solver's own beside the shared
  ! layout of the direct solves (mod_solvers: a matrix made from the box layout would store 27
  ! entries per row instead of 7). The caller destroys it. Needs grid%nprocs and grid%rank_cells_*.
  subroutine grid_create_star_layout(grid, f, da, ierr)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: f
    DM, intent(out) :: da
    PetscErrorCode, intent(out) :: ierr
    PetscCall(DMDACreate3d(PETSC_COMM_WORLD, DM_BOUNDARY_PERIODIC, DM_BOUNDARY_PERIODIC, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_STAR, grid%n(1), grid%n(2), grid%n(3), grid%nprocs(1), grid%nprocs(2), grid%nprocs(3), 1, 1, grid%rank_cells_x, grid%rank_cells_y, grid%rank_cells_z, da, ierr))
    PetscCall(DMSetOptionsPrefix(da, field_names(f)//'_', ierr))
    PetscCall(DMDASetAOType(da, AOMEMORYSCALABLE, ierr))
    PetscCall(DMSetUp(da, ierr))
  end subroutine grid_create_star_layout

  ! The PETSc (global vector) index of the point (i, j, k), 0-based, of every field: what
  ! AOApplicationToPetsc of the DMDA's AO gives, without the AO (mod_fft_solver).
  pure function grid_petsc_index(grid, i, j, k) result(index)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: i, j, k
    PetscInt :: index
    index = ownership_index(grid%rank_cells_x, grid%rank_cells_y, grid%rank_cells_z, grid%n, i, j, k)
  end function grid_petsc_index

  ! The PETSc index of point (i, j, k), 0-based, of a DMDA of n(1) x n(2) x n(3) points whose
  ! ranks own lx(r) x ly(s) x lz(t) boxes (DMDAGetOwnershipRanges), numbered rank by rank (x
  ! fastest in the process grid) and x fastest within each: computed from the ownership ranges
  ! alone, where an application ordering (AO) would hold the global ordering (AOBASIC, on every
  ! rank) or need every rank in each call (AOMEMORYSCALABLE).
  pure function ownership_index(lx, ly, lz, n, i, j, k) result(index)
    PetscInt, intent(in) :: lx(:), ly(:), lz(:)
    integer, intent(in) :: n(3), i, j, k
    PetscInt :: index
    integer :: s(3), w(3)
    call owner_range(lx, i, s(1), w(1))
    call owner_range(ly, j, s(2), w(2))
    call owner_range(lz, k, s(3), w(3))
    ! the points of the ranks before in rank order: whole z-layers of ranks, then whole y-rows of
    ! ranks within the layer, then the ranks before in the row; then the place within the box
    index = int(n(1), kind(index)) * n(2) * s(3) + int(n(1), kind(index)) * s(2) * w(3) &
          + int(s(1), kind(index)) * w(2) * w(3) &
          + (i - s(1)) + w(1) * ((j - s(2)) + w(2) * (k - s(3)))
  end function ownership_index

  ! The first index start and the width of the rank's range (widths l) that holds index p.
  pure subroutine owner_range(l, p, start, width)
    PetscInt, intent(in) :: l(:)
    integer, intent(in) :: p
    integer, intent(out) :: start, width
    integer :: r
    start = 0
    width = int(l(size(l)))
    do r = 1, size(l)
      width = int(l(r))
      if (p < start + width) return
      start = start + width
    end do
  end subroutine owner_range

  ! Split nblocks blocks of size block over nproc ranks as evenly as possible.
  subroutine shares(nblocks, nproc, block, l)
    PetscInt, intent(in) :: nblocks, nproc, block
    PetscInt, allocatable, intent(out) :: l(:)
    integer :: r
    allocate(l(nproc))
    do r = 1, nproc
      l(r) = block * (nblocks / nproc)
      if (r <= mod(nblocks, nproc)) l(r) = l(r) + block
    end do
  end subroutine shares

  ! Position of unknown (i,j,k) of field f.
  pure function grid_position(grid, f, i, j, k) result(x)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: f, i, j, k
    real(dp) :: x(3)
    x = ([i, j, k] + 0.5_dp) * grid%h
    if (f <= 3) x(f) = x(f) - 0.5_dp * grid%h
  end function grid_position

  !> True for the rows that are not unknowns: v on the wall face j = 0 (periodic layout: the same
  !> face as j = n2, the top wall).
  pure logical function grid_fixed_row(grid, c, j)
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: c, j
    grid_fixed_row = grid%walls .and. c == FIELD_V .and. j == 0
  end function grid_fixed_row

  subroutine grid_destroy(grid, ierr)
    type(grid_t), intent(inout) :: grid
    PetscErrorCode, intent(out) :: ierr
    integer :: f
    do f = 1, 4
      PetscCall(DMDestroy(grid%da(f), ierr))
    end do
  end subroutine grid_destroy

  ! -fluid_solver fft (default): the four solves of a fluid step by fast transforms, exact to
  ! round-off (mod_fft_solver); -fluid_solver krylov: CG with multigrid or Jacobi, to the deck's
  ! tolerances, with every -u_/-v_/-w_/-p_ KSP option (doc/INPUT.md).
  logical function direct_solves_wanted()
    character(len=16) :: choice
    PetscBool :: found
    PetscErrorCode :: ierr
    choice = 'fft'
    PetscCallA(PetscOptionsGetString(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-fluid_solver', choice, found, ierr))
    select case (trim(choice))
    case ('fft')
      direct_solves_wanted = .true.
    case ('krylov')
      direct_solves_wanted = .false.
    case default
      call fatal_error('fdsusp: error: -fluid_solver '//trim(choice)//' is not known (fft or krylov)', 2)
      direct_solves_wanted = .false.
    end select
  end function direct_solves_wanted

end module mod_grid
