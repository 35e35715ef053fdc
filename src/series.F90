! series.h5: one record per output step, one 1-D dataset per quantity (design.md "Files").
! Rank 0 buffers the records and appends them when flushed (at progress lines, checkpoints and
! the end of the run), opening and closing the file each time, so that a killed run leaves a
! readable file. On restart the file is cut back to the checkpoint's step, so that a continued
! run writes exactly the records an uninterrupted one would.
module mod_series
  use hdf5
  use mod_kinds, only: dp
  use mod_h5util, only: has_object
  use mod_errors, only: is_root, warn_line, abort_run
  implicit none
  private
  public :: series_t, series_open, series_record, series_flush

  type :: series_t
    character(len=1024) :: path = ''
    character(len=64), allocatable :: names(:)
    real(dp), allocatable :: buffer(:, :)    ! (quantity, record)
    integer :: nbuf = 0
  end type series_t

  integer(HSIZE_T), parameter :: chunk = 1024

contains

  ! Create OUTDIR/series.h5 with the given quantities, or, when restarting from step
  ! restart_step (>= 0), keep the records up to that step. names(1) must be 'step'.
  subroutine series_open(s, outdir, names, restart_step)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: outdir
    character(len=*), intent(in) :: names(:)
    integer, intent(in) :: restart_step
    integer(HID_T) :: file
    logical :: exists, fits
    integer :: err, c

    allocate(s%names(size(names)))
    s%names = names
    allocate(s%buffer(size(names), 256))
    s%nbuf = 0
    s%path = trim(outdir)//'/series.h5'
    if (.not. is_root()) return

    inquire(file=trim(s%path), exist=exists)
    if (restart_step >= 0 .and. exists) then
      call h5fopen_f(trim(s%path), H5F_ACC_RDWR_F, file, err)
      fits = (err == 0)
      if (fits) then
        do c = 1, size(names)
          if (.not. has_object(file, trim(names(c)))) fits = .false.
        end do
        if (fits) call cut_back(file, restart_step, s%names)
        call h5fclose_f(file, err)
      end if
      if (fits) return
      call warn_line(trim(s%path)//' does not hold the quantities of this run: starting it anew')
    end if
    call h5fcreate_f(trim(s%path), H5F_ACC_TRUNC_F, file, err)
    if (err /= 0) call abort_run('cannot create '//trim(s%path))
    do c = 1, size(names)
      call create_column(file, trim(names(c)), c == 1)
    end do
    call h5fclose_f(file, err)
  end subroutine series_open

  subroutine create_column(file, name, is_integer)
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: name
    logical, intent(in) :: is_integer
    integer(HID_T) :: space, plist, dset, dtype
    integer(HSIZE_T) :: dims(1), maxdims(1), chunks(1)
    integer :: err
    dims = 0
    maxdims = H5S_UNLIMITED_F
    chunks = chunk
    dtype = H5T_NATIVE_DOUBLE
    if (is_integer) dtype = H5T_NATIVE_INTEGER
    call h5screate_simple_f(1, dims, space, err, maxdims)
    call h5pcreate_f(H5P_DATASET_CREATE_F, plist, err)
    call h5pset_chunk_f(plist, 1, chunks, err)
    call h5dcreate_f(file, name, dtype, space, dset, err, plist)
    if (err /= 0) call abort_run('cannot create dataset '//name//' in series.h5')
    call h5dclose_f(dset, err)
    call h5pclose_f(plist, err)
    call h5sclose_f(space, err)
  end subroutine create_column

  ! Keep the records with step <= last_step.
  subroutine cut_back(file, last_step, names)
    integer(HID_T), intent(in) :: file
    integer, intent(in) :: last_step
    character(len=*), intent(in) :: names(:)
    integer(HID_T) :: dset, space
    integer(HSIZE_T) :: dims(1), maxdims(1), keep(1)
    integer, allocatable :: steps(:)
    integer :: err, c
    call h5dopen_f(file, 'step', dset, err)
    call h5dget_space_f(dset, space, err)
    call h5sget_simple_extent_dims_f(space, dims, maxdims, err)
    call h5sclose_f(space, err)
    allocate(steps(dims(1)))
    if (dims(1) > 0) call h5dread_f(dset, H5T_NATIVE_INTEGER, steps, dims, err)
    call h5dclose_f(dset, err)
    keep = count(steps <= last_step)
    do c = 1, size(names)
      call h5dopen_f(file, trim(names(c)), dset, err)
      call h5dset_extent_f(dset, keep, err)
      call h5dclose_f(dset, err)
    end do
  end subroutine cut_back

  ! Add one record (values in the order of names; values(1) is the step).
  subroutine series_record(s, values)
    type(series_t), intent(inout) :: s
    real(dp), intent(in) :: values(:)
    real(dp), allocatable :: bigger(:, :)
    if (.not. is_root()) return
    if (s%nbuf == size(s%buffer, 2)) then
      allocate(bigger(size(s%buffer, 1), 2 * size(s%buffer, 2)))
      bigger(:, 1:s%nbuf) = s%buffer(:, 1:s%nbuf)
      call move_alloc(bigger, s%buffer)
    end if
    s%nbuf = s%nbuf + 1
    s%buffer(:, s%nbuf) = values
  end subroutine series_record

  ! Append the buffered records to the file.
  subroutine series_flush(s)
    type(series_t), intent(inout) :: s
    integer(HID_T) :: file, dset, fspace, mspace
    integer(HSIZE_T) :: dims(1), maxdims(1), newdims(1), offset(1), count(1)
    integer :: err, c
    if (.not. is_root() .or. s%nbuf == 0) return
    call h5fopen_f(trim(s%path), H5F_ACC_RDWR_F, file, err)
    if (err /= 0) call abort_run('cannot open '//trim(s%path)//' to append the series')
    count = s%nbuf
    do c = 1, size(s%names)
      call h5dopen_f(file, trim(s%names(c)), dset, err)
      call h5dget_space_f(dset, fspace, err)
      call h5sget_simple_extent_dims_f(fspace, dims, maxdims, err)
      call h5sclose_f(fspace, err)
      offset = dims
      newdims = dims + count
      call h5dset_extent_f(dset, newdims, err)
      call h5dget_space_f(dset, fspace, err)
      call h5sselect_hyperslab_f(fspace, H5S_SELECT_SET_F, offset, count, err)
      call h5screate_simple_f(1, count, mspace, err)
      if (c == 1) then
        call h5dwrite_f(dset, H5T_NATIVE_INTEGER, nint(s%buffer(c, 1:s%nbuf)), count, err, mspace, fspace)
      else
        call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, s%buffer(c, 1:s%nbuf), count, err, mspace, fspace)
      end if
      if (err /= 0) call abort_run('cannot write '//trim(s%names(c))//' to '//trim(s%path))
      call h5sclose_f(mspace, err)
      call h5sclose_f(fspace, err)
      call h5dclose_f(dset, err)
    end do
    call h5fclose_f(file, err)
    s%nbuf = 0
  end subroutine series_flush

end module mod_series
