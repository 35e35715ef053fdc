! series.h5: one record per output step, one dataset per quantity (design.md "Files"): scalars
! as 1-D datasets (records), per-particle quantities with a per-record shape, e.g. (3, N) in
! Fortran order, which C and Python see as records x N x 3 (particles/velocity) or, for (3, 3, N),
! records x N x 3 x 3 (particles/stresslet_hydro).
! The columns are named once, by one routine of the program that calls series_column for each
! (name and value; the value's shape is the column's): called before series_open it declares them,
! afterwards it fills the record that series_record adds. So the file's header and its records
! come from the same lines and cannot fall out of step.
! Rank 0 buffers the records and appends them when flushed (at progress lines, checkpoints and
! the end of the run), opening and closing the file each time, so that a killed run leaves a
! readable file. On restart the file is cut back to the checkpoint's step, so that a continued
! run writes exactly the records an uninterrupted one would.
module mod_series
  use hdf5
  use mod_kinds, only: dp
  use mod_h5util, only: has_object, write_attribute
  use mod_errors, only: is_root, warn_line, abort_run
  implicit none
  private
  public :: series_t, series_column, series_open, series_record, series_flush, series_attributes

  type :: series_t
    character(len=1024) :: path = ''
    character(len=64), allocatable :: names(:)
    integer, allocatable :: shapes(:, :)     ! (3, column): per-record shape, 0 where unused
    integer, allocatable :: first(:)         ! offset of each column in a record
    real(dp), allocatable :: buffer(:, :)    ! (value, record)
    integer :: nbuf = 0
    logical :: open = .false.                ! series_open done: series_column fills, not declares
    integer :: filled = 0                    ! columns of the record being assembled
    real(dp), allocatable :: row(:)          ! the record being assembled (rank 0)
  end type series_t

  ! One column: its value, a scalar or an array whose shape is the column's per-record shape
  ! (an integer scalar, the step or a count, is stored as real like every value of a record)
  interface series_column
    module procedure column_int, column_real, column_vector, column_matrix, column_tensor
  end interface series_column

  integer(HSIZE_T), parameter :: chunk = 1024

contains

  subroutine column_int(s, name, value)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: name
    integer, intent(in) :: value
    call column(s, name, [0, 0, 0], [real(value, dp)])
  end subroutine column_int

  subroutine column_real(s, name, value)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value
    call column(s, name, [0, 0, 0], [value])
  end subroutine column_real

  subroutine column_vector(s, name, value)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value(:)
    call column(s, name, [size(value), 0, 0], value)
  end subroutine column_vector

  subroutine column_matrix(s, name, value)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value(:, :)
    call column(s, name, [shape(value), 0], reshape(value, [size(value)]))
  end subroutine column_matrix

  subroutine column_tensor(s, name, value)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value(:, :, :)
    call column(s, name, shape(value), reshape(value, [size(value)]))
  end subroutine column_tensor

  ! Before series_open: add the column (name, per-record shape). After: put its values (in
  ! Fortran order) into the record being assembled, the next of the declared columns.
  subroutine column(s, name, shape, values)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: name
    integer, intent(in) :: shape(3)
    real(dp), intent(in) :: values(:)
    integer :: c
    if (.not. s%open) then
      if (.not. allocated(s%names)) allocate(s%names(0), s%shapes(3, 0))
      s%names = [character(len=64) :: s%names, name]
      s%shapes = reshape([s%shapes, shape], [3, size(s%names)])
      return
    end if
    if (.not. is_root()) return
    c = s%filled + 1
    ! the columns are declared and filled by the same calls; another order is a programming error
    if (c > size(s%names)) call abort_run('series.h5: a record has more columns than declared ('//name//')')
    if (s%names(c) /= name .or. size(values) /= s%first(c + 1) - s%first(c)) &
      call abort_run('series.h5: column '//name//' does not match the declared '//trim(s%names(c)))
    s%row(s%first(c):s%first(c + 1) - 1) = values
    s%filled = c
  end subroutine column

  ! Create OUTDIR/series.h5 with the columns declared by series_column, or, when restarting from
  ! step restart_step (>= 0), keep the records up to that step. The first column must be 'step'.
  subroutine series_open(s, outdir, restart_step)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: outdir
    integer, intent(in) :: restart_step
    integer(HID_T) :: file
    logical :: exists, fits
    integer :: err, c

    if (.not. allocated(s%names)) call abort_run('series.h5: no columns declared')
    if (s%names(1) /= 'step') call abort_run('series.h5: the first column must be the step')
    allocate(s%first(size(s%names) + 1))
    s%first(1) = 1
    do c = 1, size(s%names)
      s%first(c + 1) = s%first(c) + product(max(1, s%shapes(:, c)))
    end do
    allocate(s%buffer(s%first(size(s%names) + 1) - 1, 256), s%row(s%first(size(s%names) + 1) - 1))
    s%nbuf = 0
    s%filled = 0
    s%open = .true.
    s%path = trim(outdir)//'/series.h5'
    if (.not. is_root()) return

    inquire(file=trim(s%path), exist=exists)
    if (restart_step >= 0 .and. exists) then
      call h5fopen_f(trim(s%path), H5F_ACC_RDWR_F, file, err)
      fits = (err == 0)
      if (fits) then
        do c = 1, size(s%names)
          if (.not. has_object(file, trim(s%names(c)))) fits = .false.
        end do
        if (fits) call cut_back(file, restart_step, s%names)
        call h5fclose_f(file, err)
      end if
      if (fits) return
      call warn_line(trim(s%path)//' does not hold the quantities of this run: starting it anew')
    end if
    call h5fcreate_f(trim(s%path), H5F_ACC_TRUNC_F, file, err)
    if (err /= 0) call abort_run('cannot create '//trim(s%path))
    do c = 1, size(s%names)
      call create_column(file, trim(s%names(c)), c == 1, s%shapes(:, c))
    end do
    call h5fclose_f(file, err)
  end subroutine series_open

  ! Attributes of the file's root (rank 0): values(k) under names(k), replacing earlier ones.
  subroutine series_attributes(s, names, values)
    type(series_t), intent(in) :: s
    character(len=*), intent(in) :: names(:)
    real(dp), intent(in) :: values(:)
    integer(HID_T) :: file
    integer :: err, e, k
    if (.not. is_root()) return
    call h5fopen_f(trim(s%path), H5F_ACC_RDWR_F, file, err)
    if (err /= 0) call abort_run('cannot open '//trim(s%path)//' to write its attributes')
    e = 0
    do k = 1, size(names)
      call write_attribute(file, trim(names(k)), values(k:k), err)
      e = max(e, abs(err))
    end do
    call h5fclose_f(file, err)
    if (e /= 0) call abort_run('cannot write the attributes of '//trim(s%path))
  end subroutine series_attributes

  ! Rank of a column's dataset: its per-record dimensions (those > 0) plus records.
  pure integer function column_rank(shape)
    integer, intent(in) :: shape(3)
    column_rank = count(shape > 0) + 1
  end function column_rank

  subroutine create_column(file, name, is_integer, shape)
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: name
    logical, intent(in) :: is_integer
    integer, intent(in) :: shape(3)
    integer(HID_T) :: space, plist, dset, dtype, group
    integer(HSIZE_T) :: dims(4), maxdims(4), chunks(4)
    integer :: err, rank, slash
    rank = column_rank(shape)
    dims(1:rank - 1) = shape(1:rank - 1)
    dims(rank) = 0
    maxdims = dims
    maxdims(rank) = H5S_UNLIMITED_F
    chunks = dims
    chunks(rank) = max(1_HSIZE_T, chunk / product(max(1_HSIZE_T, dims(1:rank - 1))))
    dtype = H5T_NATIVE_DOUBLE
    if (is_integer) dtype = H5T_NATIVE_INTEGER
    ! a name with a '/' lives in a group (particles/velocity)
    slash = index(name, '/')
    if (slash > 0) then
      if (.not. has_object(file, name(1:slash - 1))) then
        call h5gcreate_f(file, name(1:slash - 1), group, err)
        call h5gclose_f(group, err)
      end if
    end if
    call h5screate_simple_f(rank, dims(1:rank), space, err, maxdims(1:rank))
    call h5pcreate_f(H5P_DATASET_CREATE_F, plist, err)
    call h5pset_chunk_f(plist, rank, chunks(1:rank), err)
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
    integer(HSIZE_T) :: dims(1), maxdims(1), keep(1), cdims(4), cmax(4)
    integer, allocatable :: steps(:)
    integer :: err, c, rank
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
      call h5dget_space_f(dset, space, err)
      call h5sget_simple_extent_ndims_f(space, rank, err)
      call h5sget_simple_extent_dims_f(space, cdims(1:rank), cmax(1:rank), err)
      call h5sclose_f(space, err)
      cdims(rank) = keep(1)
      call h5dset_extent_f(dset, cdims(1:rank), err)
      call h5dclose_f(dset, err)
    end do
  end subroutine cut_back

  ! Add the record assembled by series_column since the last one (all the declared columns).
  subroutine series_record(s)
    type(series_t), intent(inout) :: s
    real(dp), allocatable :: bigger(:, :)
    if (.not. is_root()) return
    if (s%filled /= size(s%names)) call abort_run('series.h5: a record misses columns of the declared ones')
    s%filled = 0
    if (s%nbuf == size(s%buffer, 2)) then
      allocate(bigger(size(s%buffer, 1), 2 * size(s%buffer, 2)))
      bigger(:, 1:s%nbuf) = s%buffer(:, 1:s%nbuf)
      call move_alloc(bigger, s%buffer)
    end if
    s%nbuf = s%nbuf + 1
    s%buffer(:, s%nbuf) = s%row
  end subroutine series_record

  ! Append the buffered records to the file.
  subroutine series_flush(s)
    type(series_t), intent(inout) :: s
    integer(HID_T) :: file, dset, fspace, mspace
    integer(HSIZE_T) :: dims(4), maxdims(4), offset(4), count(4)
    integer :: err, c, rank
    real(dp), allocatable :: block(:, :)
    if (.not. is_root() .or. s%nbuf == 0) return
    call h5fopen_f(trim(s%path), H5F_ACC_RDWR_F, file, err)
    if (err /= 0) call abort_run('cannot open '//trim(s%path)//' to append the series')
    do c = 1, size(s%names)
      rank = column_rank(s%shapes(:, c))
      call h5dopen_f(file, trim(s%names(c)), dset, err)
      call h5dget_space_f(dset, fspace, err)
      call h5sget_simple_extent_dims_f(fspace, dims(1:rank), maxdims(1:rank), err)
      call h5sclose_f(fspace, err)
      offset = 0
      offset(rank) = dims(rank)
      count(1:rank) = dims(1:rank)
      count(rank) = s%nbuf
      dims(rank) = dims(rank) + s%nbuf
      call h5dset_extent_f(dset, dims(1:rank), err)
      call h5dget_space_f(dset, fspace, err)
      call h5sselect_hyperslab_f(fspace, H5S_SELECT_SET_F, offset(1:rank), count(1:rank), err)
      call h5screate_simple_f(rank, count(1:rank), mspace, err)
      block = s%buffer(s%first(c):s%first(c + 1) - 1, 1:s%nbuf)
      if (c == 1) then
        call h5dwrite_f(dset, H5T_NATIVE_INTEGER, nint(block(1, :)), count(1:1), err, mspace, fspace)
      else
        call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, block, count(1:rank), err, mspace, fspace)
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
