! Field snapshots for viewing: p and the velocity interpolated to the cell centres, written in
! parallel by PETSc's HDF5 viewer (datasets /u /v /w /p of shape nz x ny x nx), each with an XDMF
! file that ParaView opens, plus fields.xmf, a time series of this run's snapshots.
! Also the progress line of the run log.
#include <petsc/finclude/petscdmda.h>
module mod_output
  use petscdmda
  use mod_kinds, only: dp
  use mod_grid, only: grid_t, field_names, FIELD_U, FIELD_V, FIELD_W, FIELD_P
  use mod_fluid, only: fluid_t, fluid_ghosted
  use mod_errors, only: is_root, abort_run, abort_if_any
  use mod_os_services, only: publish_file
  use mod_file_services, only: errno_text, write_failure_cause, require_free_space, directory_of
  implicit none
  private
  public :: write_fields, progress_line

  integer, parameter :: max_snapshots = 100000
  integer, save :: nsnap = 0
  integer, save, allocatable :: snap_step(:)
  real(dp), save, allocatable :: snap_time(:)

contains

  subroutine write_fields(outdir, grid, fl, step, time, ierr)
    character(len=*), intent(in) :: outdir
    type(grid_t), intent(in) :: grid
    type(fluid_t), intent(inout) :: fl
    integer, intent(in) :: step
    real(dp), intent(in) :: time
    PetscErrorCode, intent(out) :: ierr
    Vec :: centre, loc
    PetscViewer :: viewer
    PetscScalar, pointer :: a(:,:,:), c(:,:,:)
    character(len=32) :: base
    character(len=1100) :: path
    integer :: f, e(3), i, j, k
    logical :: failed

    ! one cell-centred component at a time, in a work vector borrowed from the layout (with the
    ! direct solves every field's DMDA is one: doc/BENCHMARKS.md §14)
    write(base, '(a,i8.8)') 'fields_', step
    ! written to .tmp and renamed: a snapshot on disk is whole. A failed write (a full disk) stops
    ! the run on every rank with one message naming the file and the cause, not PETSc's alone.
    path = trim(outdir)//'/'//trim(base)//'.h5'
    call require_free_space(outdir, 32.0_dp * product(real(grid%n, dp)), path)
    call PetscViewerHDF5Open(PETSC_COMM_WORLD, trim(path)//'.tmp', FILE_MODE_WRITE, viewer, ierr)
    failed = ierr /= 0
    ! every rank writes its slab in one collective MPI-IO transfer (issue 45; doc/DESIGN.md "Files")
    if (.not. failed) then
      call PetscViewerHDF5SetCollective(viewer, PETSC_TRUE, ierr)
      failed = ierr /= 0
    end if
    PetscCall(DMGetGlobalVector(grid%da(FIELD_P), centre, ierr))
    do f = 1, 3
      e = 0
      e(f) = 1
      PetscCall(DMGetLocalVector(grid%da(f), loc, ierr))
      ! (the ghosts across a Lees-Edwards boundary are its images: mod_fluid)
      PetscCall(fluid_ghosted(grid, fl, f, fl%vel(f), loc, ierr))
      PetscCall(DMDAVecGetArrayReadF90(grid%da(f), loc, a, ierr))
      PetscCall(DMDAVecGetArrayF90(grid%da(FIELD_P), centre, c, ierr))
      ! mean of the two faces of each cell (with walls, v(n) is the wall face v(0) = 0)
      do k = grid%lo(3), grid%hi(3)
        do j = grid%lo(2), grid%hi(2)
          do i = grid%lo(1), grid%hi(1)
            c(i, j, k) = 0.5_dp * (a(i, j, k) + a(i + e(1), j + e(2), k + e(3)))
          end do
        end do
      end do
      PetscCall(DMDAVecRestoreArrayF90(grid%da(FIELD_P), centre, c, ierr))
      PetscCall(DMDAVecRestoreArrayReadF90(grid%da(f), loc, a, ierr))
      PetscCall(DMRestoreLocalVector(grid%da(f), loc, ierr))
      PetscCall(PetscObjectSetName(centre, field_names(f), ierr))
      if (.not. failed) then
        call VecView(centre, viewer, ierr)
        failed = ierr /= 0
      end if
    end do
    PetscCall(PetscObjectSetName(centre, 'work', ierr))
    PetscCall(DMRestoreGlobalVector(grid%da(FIELD_P), centre, ierr))
    if (.not. failed) then
      call VecView(fl%pressure, viewer, ierr)
      failed = ierr /= 0
    end if
    if (.not. failed) then
      call PetscViewerDestroy(viewer, ierr)
      failed = ierr /= 0
    end if
    call abort_if_any(failed, trim(path)//' cannot be written: '// &
                      write_failure_cause(outdir, 32.0_dp * product(real(grid%n, dp))))
    if (is_root()) then
      e(1) = publish_file(trim(path)//'.tmp', path)
      if (e(1) /= 0) call abort_run(trim(path)//' cannot be published ('//errno_text(e(1))//'): '// &
                                    write_failure_cause(outdir, 0.0_dp))
    end if

    if (.not. allocated(snap_step)) allocate(snap_step(max_snapshots), snap_time(max_snapshots))
    if (nsnap < max_snapshots) nsnap = nsnap + 1
    snap_step(nsnap) = step
    snap_time(nsnap) = time
    if (is_root()) then
      call write_xdmf(trim(outdir)//'/'//trim(base)//'.xmf', grid, snap_step(nsnap:nsnap), snap_time(nsnap:nsnap))
      call write_xdmf(trim(outdir)//'/fields.xmf', grid, snap_step(1:nsnap), snap_time(1:nsnap))
    end if
  end subroutine write_fields

  ! XDMF 2 for ParaView: a co-rectilinear mesh of cell corners, fields on the cells.
  subroutine write_xdmf(path, grid, steps, times)
    character(len=*), intent(in) :: path
    type(grid_t), intent(in) :: grid
    integer, intent(in) :: steps(:)
    real(dp), intent(in) :: times(:)
    character(len=*), parameter :: names(4) = ['u', 'v', 'w', 'p']
    character(len=64) :: nodes, cells, h5
    character(len=200) :: line
    character(len=:), allocatable :: doc
    character(len=1) :: nl
    integer :: unit, s, f, err
    write(nodes, '(3(i0,1x))') grid%n(3) + 1, grid%n(2) + 1, grid%n(1) + 1
    write(cells, '(3(i0,1x))') grid%n(3), grid%n(2), grid%n(1)
    nl = new_line('a')
    doc = '<?xml version="1.0" ?>'//nl//'<Xdmf Version="2.0">'//nl//' <Domain>'//nl// &
          '  <Grid Name="fields" GridType="Collection" CollectionType="Temporal">'//nl
    do s = 1, size(steps)
      write(h5, '(a,i8.8,a)') 'fields_', steps(s), '.h5'
      write(line, '(a,i0,a)') '   <Grid Name="step ', steps(s), '" GridType="Uniform">'
      doc = doc//trim(line)//nl
      write(line, '(a,es23.15,a)') '    <Time Value="', times(s), '"/>'
      doc = doc//trim(line)//nl//'    <Topology TopologyType="3DCoRectMesh" Dimensions="'//trim(nodes)//'"/>'//nl// &
            '    <Geometry GeometryType="ORIGIN_DXDYDZ">'//nl// &
            '     <DataItem Dimensions="3" Format="XML">0 0 0</DataItem>'//nl
      write(line, '(a,3es23.15,a)') '     <DataItem Dimensions="3" Format="XML">', grid%h, grid%h, grid%h, '</DataItem>'
      doc = doc//trim(line)//nl//'    </Geometry>'//nl
      do f = 1, 4
        doc = doc//'    <Attribute Name="'//names(f)//'" AttributeType="Scalar" Center="Cell">'//nl// &
              '     <DataItem Dimensions="'//trim(cells)//'" NumberType="Float" Precision="8" Format="HDF">'// &
              trim(h5)//':/'//names(f)//'</DataItem>'//nl//'    </Attribute>'//nl
      end do
      doc = doc//'   </Grid>'//nl
    end do
    doc = doc//'  </Grid>'//nl//' </Domain>'//nl//'</Xdmf>'//nl
    ! written whole to .tmp, checked, and renamed
    open(newunit=unit, file=path//'.tmp', status='replace', action='write', access='stream', form='unformatted', &
         iostat=err)
    if (err == 0) write(unit, iostat=err) doc
    if (err == 0) flush(unit, iostat=err)
    close(unit, iostat=s)
    if (err == 0) err = s
    if (err == 0) err = publish_file(path//'.tmp', path)
    if (err /= 0) call abort_run(path//' cannot be written: '//write_failure_cause(directory_of(path), 0.0_dp))
  end subroutine write_xdmf

  ! step, strain, wall time, estimated time left, iterations of each solver, divergence (fl
  ! absent, lubrication dynamics: the first four).
  subroutine progress_line(step, last_step, strain, wall, wall_per_step, fl)
    integer, intent(in) :: step, last_step
    real(dp), intent(in) :: strain, wall, wall_per_step
    type(fluid_t), intent(in), optional :: fl
    if (.not. is_root()) return
    if (.not. present(fl)) then
      write(*, '(a,i9,a,f10.4,a,f9.1,a,f9.1,a)') 'step', step, '  strain', strain, &
           '  wall', wall, ' s  left', wall_per_step * (last_step - step), ' s'
      flush(6)
      return
    end if
    write(*, '(a,i9,a,f10.4,a,f9.1,a,f9.1,a,3(i0,"/"),i0,a,es8.1)') 'step', step, '  strain', strain, &
         '  wall', wall, ' s  left', wall_per_step * (last_step - step), ' s  its u/v/w/p ', &
         fl%solver(FIELD_U)%iterations, fl%solver(FIELD_V)%iterations, fl%solver(FIELD_W)%iterations, &
         fl%solver(FIELD_P)%iterations, '  div', fl%divergence
    flush(6)
  end subroutine progress_line

end module mod_output
