! series.h5: one record per output step, one dataset per quantity (doc/DESIGN.md "Files"): scalars
! as 1-D datasets (records), per-particle quantities with a per-record shape, e.g. (3, N) in
! Fortran order, which C and Python see as records x N x 3 (particles/velocity) or, for (3, 3, N),
! records x N x 3 x 3 (particles/stresslet_hydro).
! The columns are named once, by one routine of the program that calls series_column for each
! (name and value; the value's shape is the column's): called before series_open it declares them,
! afterwards it fills the record that series_record adds. So the file's header and its records
! come from the same lines and cannot fall out of step.
!
! Crash safety (doc/DESIGN.md "series.h5: immutable parts, atomic consolidation"): no file the
! series has published is ever modified in place, so a kill at any instant leaves every published
! record whole. Rank 0 buffers the records; a flush (progress lines, checkpoints, a full buffer)
! writes them as a part, series.parts/<first step>.h5, through a .tmp file flushed to disk and
! renamed. Consolidation copies series.h5 to series.h5.tmp, appends the parts' records after its
! last step, and renames the copy over series.h5; only then are the parts removed. It runs when the
! parts reach half the size of series.h5 (so the copies cost at most about twice the data once),
! at the end of a run, and when a run starts from a checkpoint: then it keeps only the records up to
! the checkpoint's step, so that the continued run writes exactly the records an uninterrupted one
! would. Every write is checked: a failure stops the run (abort_run) naming the file and the cause.
#include <petsc/finclude/petscsys.h>
module mod_series
  use petscsys
  use hdf5
  use mod_kinds, only: dp
  use mod_columns, only: column_t
  use mod_h5util, only: has_object, write_attribute
  use mod_errors, only: is_root, warn_line, log_line, abort_run
  use mod_os_services, only: publish_file, make_directory
  use mod_file_services, only: list_directory, copy_file, remove_file, rename_file, errno_text, write_failure_cause, &
                               free_bytes, directory_of
  implicit none
  private
  public :: series_t, series_column, series_add, series_open, series_record, series_flush, series_close, series_attributes

  type :: series_t
    character(len=1024) :: path = ''           ! OUTDIR/series.h5
    character(len=1024) :: parts_dir = ''      ! OUTDIR/series.parts
    character(len=64), allocatable :: names(:)
    integer, allocatable :: shapes(:, :)     ! (3, column): per-record shape, 0 where unused
    integer, allocatable :: first(:)         ! offset of each column in a record
    real(dp), allocatable :: buffer(:, :)    ! (value, record)
    integer :: nbuf = 0
    integer :: max_records = 0               ! records of one part: its buffer's bound (part_bytes)
    logical :: open = .false.                ! series_open done: series_column fills, not declares
    integer :: filled = 0                    ! columns of the record being assembled
    real(dp), allocatable :: row(:)          ! the record being assembled (rank 0)
    character(len=32), allocatable :: attribute_names(:)
    real(dp), allocatable :: attribute_values(:)
    integer :: parts = 0                     ! parts published since the last consolidation
    real(dp) :: parts_bytes = 0.0_dp         ! their size
    real(dp) :: consolidated_bytes = 0.0_dp  ! the size of series.h5
    real(dp) :: flush_seconds = 5.0_dp        ! progress lines flush at most this often (wall time)
    integer(kind=8) :: last_flush = 0         ! system_clock count of the last flush
  end type series_t

  ! One column: its value, a scalar or an array whose shape is the column's per-record shape
  ! (an integer scalar, the step or a count, is stored as real like every value of a record)
  interface series_column
    module procedure column_int, column_real, column_vector, column_matrix, column_tensor
  end interface series_column

  integer(HSIZE_T), parameter :: chunk = 1024
  ! a part holds at most this many bytes of records: the bound of rank 0's buffer (-series_part_mb)
  real(dp), parameter :: part_bytes = 64.0_dp * 1048576.0_dp
  ! series.h5 is consolidated at every flush while it is this small (it stays current for readers)
  real(dp), parameter :: small_series_bytes = 64.0_dp * 1048576.0_dp
  ! more parts than this are consolidated whatever their size (bounded file count)
  integer, parameter :: max_parts = 64
  integer, parameter :: no_limit = huge(1)

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

  ! The columns a physics module names (mod_columns), in their order: declared before series_open,
  ! filled into the record being assembled afterwards.
  subroutine series_add(s, columns)
    type(series_t), intent(inout) :: s
    type(column_t), intent(in) :: columns(:)
    integer :: k
    do k = 1, size(columns)
      call column(s, trim(columns(k)%name), columns(k)%shape, columns(k)%values)
    end do
  end subroutine series_add

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

  ! Attributes of the file's root: values(k) under names(k). Called before series_open; every file
  ! the series writes carries them.
  subroutine series_attributes(s, names, values)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: names(:)
    real(dp), intent(in) :: values(:)
    if (s%open) call abort_run('series.h5: attributes must be set before the series is opened')
    s%attribute_names = names
    s%attribute_values = values
  end subroutine series_attributes

  ! Open the series of OUTDIR with the columns declared by series_column (the first must be
  ! 'step'). A run from the start (restart_step < 0) begins an empty series.h5 (an earlier run's
  ! series is replaced, as its checkpoint is). A run from a checkpoint at restart_step keeps the
  ! records up to that step, from series.h5 and from the parts a killed run left. Partial files of a
  ! killed write (.tmp) are removed. A series.h5 that cannot be read, or that holds other columns,
  ! is kept aside under another name, with a warning, never replaced.
  ! records_to_come: the records this run will add, for the projection of the file's size.
  subroutine series_open(s, outdir, restart_step, records_to_come)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: outdir
    integer, intent(in) :: restart_step, records_to_come
    integer :: c, record_length, err
    PetscReal :: part_megabytes
    PetscBool :: set
    PetscErrorCode :: ierr

    if (.not. allocated(s%names)) call abort_run('series.h5: no columns declared')
    if (s%names(1) /= 'step') call abort_run('series.h5: the first column must be the step')
    if (.not. allocated(s%attribute_names)) allocate(s%attribute_names(0), s%attribute_values(0))
    allocate(s%first(size(s%names) + 1))
    s%first(1) = 1
    do c = 1, size(s%names)
      s%first(c + 1) = s%first(c) + product(max(1, s%shapes(:, c)))
    end do
    record_length = s%first(size(s%names) + 1) - 1
    ! -series_flush_seconds: how often at most progress lines publish the records (checkpoints, a
    ! full buffer and the end always do): a part and, while series.h5 is small, its copy per flush
    ! would cost more than the step itself in a run with a progress line every step
    call PetscOptionsGetReal(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-series_flush_seconds', s%flush_seconds, &
                             set, ierr)
    call system_clock(s%last_flush)
    ! -series_part_mb: the bound of a part, and so of the buffer, in MiB
    part_megabytes = part_bytes / 1048576.0_dp
    call PetscOptionsGetReal(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-series_part_mb', part_megabytes, set, ierr)
    s%max_records = max(1, int(min(part_megabytes * 1048576.0_dp / (8.0_dp * record_length), 1.0e9_dp)))
    allocate(s%buffer(record_length, min(256, s%max_records)), s%row(record_length))
    s%nbuf = 0
    s%filled = 0
    s%open = .true.
    s%path = trim(outdir)//'/series.h5'
    s%parts_dir = trim(outdir)//'/series.parts'
    if (.not. is_root()) return

    err = make_directory(s%parts_dir)
    if (err /= 0) call abort_run('cannot create '//trim(s%parts_dir)//': '//errno_text(err))
    call remove_partial_writes(s)
    if (restart_step >= 0) then
      call consolidate(s, restart_step)
    else
      call remove_in_parts(s, '.h5')   ! an earlier run's
      call start_empty(s)
    end if
    call project_size(s, outdir, 8.0_dp * record_length * max(records_to_come, 0))
  end subroutine series_open

  ! The size series.h5 will reach, on the log; a warning when the disk cannot hold it and the copy
  ! that consolidation makes (a run is not refused: space may be freed while it runs).
  subroutine project_size(s, outdir, added)
    type(series_t), intent(in) :: s
    character(len=*), intent(in) :: outdir
    real(dp), intent(in) :: added
    character(len=300) :: text
    real(dp) :: final, free
    final = s%consolidated_bytes + added
    free = free_bytes(outdir)
    write(text, '(a,f0.3,a,f0.3,a)') 'series.h5: about ', final / 1.0e9_dp, ' GB at the end of this run (', &
         free / 1.0e9_dp, ' GB free on its file system)'
    call log_line(text)
    if (free >= 0.0_dp .and. added + final > free) then
      write(text, '(a,f0.3,a,f0.3,a)') 'series.h5 will need about ', (added + final) / 1.0e9_dp, &
           ' GB (the records and a copy while consolidating) but ', free / 1.0e9_dp, ' GB are free in '// &
           trim(outdir)//': the run will stop when the disk is full (raise &output series_every, or free space)'
      call warn_line(text)
    end if
  end subroutine project_size

  ! Add the record assembled by series_column since the last one (all the declared columns).
  ! A full buffer is flushed as a part.
  subroutine series_record(s)
    type(series_t), intent(inout) :: s
    real(dp), allocatable :: bigger(:, :)
    if (.not. is_root()) return
    if (s%filled /= size(s%names)) call abort_run('series.h5: a record misses columns of the declared ones')
    s%filled = 0
    if (s%nbuf == size(s%buffer, 2)) then
      allocate(bigger(size(s%buffer, 1), min(2 * size(s%buffer, 2), s%max_records)))
      bigger(:, 1:s%nbuf) = s%buffer(:, 1:s%nbuf)
      call move_alloc(bigger, s%buffer)
    end if
    s%nbuf = s%nbuf + 1
    s%buffer(:, s%nbuf) = s%row
    if (s%nbuf == s%max_records) call series_flush(s)
  end subroutine series_record

  ! Publish the buffered records as a part; consolidate series.h5 when that is due. progress,
  ! optional: the flush of a progress line, done only when -series_flush_seconds have passed since
  ! the last one.
  subroutine series_flush(s, progress)
    type(series_t), intent(inout) :: s
    logical, intent(in), optional :: progress
    character(len=1100) :: part
    integer(HID_T) :: file
    integer :: err
    integer(kind=8) :: bytes, now, rate
    if (.not. is_root() .or. s%nbuf == 0) return
    call system_clock(now, rate)
    if (present(progress)) then
      if (progress .and. real(now - s%last_flush, dp) < s%flush_seconds * rate) return
    end if
    s%last_flush = now
    write(part, '(a,i10.10,a)') trim(s%parts_dir)//'/', nint(s%buffer(1, 1)), '.h5'
    call create_file(s, trim(part)//'.tmp', file)
    call append_records(s, file, trim(part)//'.tmp', s%buffer(:, 1:s%nbuf))
    call close_file(s, file, trim(part)//'.tmp')
    err = publish_file(trim(part)//'.tmp', part)
    if (err /= 0) call write_failed(s, part, 'cannot be published ('//errno_text(err)//')')
    inquire(file=trim(part), size=bytes)
    s%nbuf = 0
    s%parts = s%parts + 1
    s%parts_bytes = s%parts_bytes + real(max(bytes, 0_8), dp)
    if (s%consolidated_bytes + s%parts_bytes <= small_series_bytes .or. s%parts >= max_parts .or. &
        s%parts_bytes >= 0.5_dp * s%consolidated_bytes) call consolidate(s, no_limit)
  end subroutine series_flush

  ! The end of a run: the buffered records and the parts, all in series.h5.
  subroutine series_close(s)
    type(series_t), intent(inout) :: s
    if (.not. is_root() .or. .not. s%open) return
    call series_flush(s)
    if (s%parts > 0) call consolidate(s, no_limit)
  end subroutine series_close

  ! A new, empty series.h5 (the columns and attributes), published whole.
  subroutine start_empty(s)
    type(series_t), intent(inout) :: s
    integer(HID_T) :: file
    integer :: err
    integer(kind=8) :: bytes
    call create_file(s, trim(s%path)//'.tmp', file)
    call close_file(s, file, trim(s%path)//'.tmp')
    err = publish_file(trim(s%path)//'.tmp', s%path)
    if (err /= 0) call write_failed(s, s%path, 'cannot be published ('//errno_text(err)//')')
    inquire(file=trim(s%path), size=bytes)
    s%consolidated_bytes = real(max(bytes, 0_8), dp)
    s%parts = 0
    s%parts_bytes = 0.0_dp
  end subroutine start_empty

  ! series.h5 and the parts merged into series.h5.tmp, renamed over series.h5, then the parts
  ! removed: the records of series.h5 (its longest sound prefix: every column that long, steps
  ! increasing), then each part's records after the last step so far, up to step `limit`.
  subroutine consolidate(s, limit)
    type(series_t), intent(inout) :: s
    integer, intent(in) :: limit
    character(len=256), allocatable :: parts(:)
    character(len=1100) :: tmp, part
    character(len=400) :: problem
    integer(HID_T) :: file, source
    integer :: err, k, last, n_source, i0, i1, first
    integer, allocatable :: steps(:)
    integer(kind=8) :: bytes
    real(dp), allocatable :: block(:, :)
    logical :: exists

    call list_directory(s%parts_dir, '.h5', parts, err)
    if (err /= 0) call abort_run('cannot list '//trim(s%parts_dir)//': '//errno_text(err))
    tmp = trim(s%path)//'.tmp'
    last = -huge(1)
    inquire(file=trim(s%path), exist=exists)
    problem = ''
    if (exists) then
      err = copy_file(s%path, tmp)
      if (err /= 0) call write_failed(s, tmp, 'cannot be written as a copy of series.h5 ('//errno_text(err)//')')
      call h5fopen_f(trim(tmp), H5F_ACC_RDWR_F, file, err)
      if (err /= 0) then
        problem = 'it cannot be read as HDF5'
      else
        call sound_prefix(s, file, limit, problem, last)
        if (len_trim(problem) > 0) call h5fclose_f(file, err)
      end if
      if (len_trim(problem) > 0) then
        err = remove_file(tmp)
        call keep_aside(s%path, problem)
      end if
    end if
    if (.not. exists .or. len_trim(problem) > 0) then
      call create_file(s, tmp, file)
      last = -huge(1)
    end if
    do k = 1, size(parts)
      part = trim(s%parts_dir)//'/'//trim(parts(k))
      call h5fopen_f(trim(part), H5F_ACC_RDONLY_F, source, err)
      problem = ''
      if (err /= 0) then
        problem = 'it cannot be read as HDF5'
      else
        call read_steps(s, source, steps, problem)
      end if
      if (len_trim(problem) > 0) then
        if (err == 0) call h5fclose_f(source, err)
        call keep_aside(part, problem)
        cycle
      end if
      ! the records after the last step so far, up to the limit (steps increase within a part)
      i0 = findloc(steps > last, .true., 1)
      i1 = count(steps <= limit)
      if (i0 > 0 .and. i1 >= i0) then
        ! in slices of at most 256 records: the copy holds little memory whatever the part's size
        do first = i0, i1, 256
          n_source = min(256, i1 - first + 1)
          allocate(block(size(s%row), n_source))
          call read_records(s, source, part, first, block)
          call append_records(s, file, tmp, block)
          deallocate(block)
        end do
        last = steps(i1)
      end if
      call h5fclose_f(source, err)
    end do
    call write_attributes(s, file, tmp)
    call close_file(s, file, tmp)
    err = publish_file(tmp, s%path)
    if (err /= 0) call write_failed(s, s%path, 'cannot be published ('//errno_text(err)//')')
    ! series.h5 now holds every record: the parts go (a kill before they are gone leaves records
    ! that the next consolidation finds at or before series.h5's last step, and skips)
    do k = 1, size(parts)
      err = remove_file(trim(s%parts_dir)//'/'//trim(parts(k)))
      if (err /= 0) call abort_run('cannot remove '//trim(s%parts_dir)//'/'//trim(parts(k))//': '//errno_text(err))
    end do
    inquire(file=trim(s%path), size=bytes)
    s%consolidated_bytes = real(max(bytes, 0_8), dp)
    s%parts = 0
    s%parts_bytes = 0.0_dp
  end subroutine consolidate

  ! Cut the open copy of series.h5 to its longest sound prefix up to step `limit`: every column
  ! that long and the steps increasing. problem: why the file cannot be continued ('' if it can).
  subroutine sound_prefix(s, file, limit, problem, last)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    integer, intent(in) :: limit
    character(len=*), intent(out) :: problem
    integer, intent(out) :: last
    integer(HID_T) :: dset
    integer(HSIZE_T) :: dims(4)
    integer, allocatable :: steps(:)
    integer :: err, e, c, rank, keep, k
    last = -huge(1)
    call read_steps(s, file, steps, problem)
    if (len_trim(problem) > 0) return
    keep = size(steps)
    do c = 1, size(s%names)
      call column_extent(s, file, c, rank, dims, err)
      if (err /= 0 .or. rank /= column_rank(s%shapes(:, c)) .or. &
          any(dims(1:rank - 1) /= s%shapes(1:rank - 1, c))) then
        problem = 'its column '//trim(s%names(c))//' has another shape than this run''s'
        return
      end if
      keep = min(keep, int(dims(rank)))
    end do
    do k = 2, keep
      if (steps(k) <= steps(k - 1)) then
        keep = k - 1
        exit
      end if
    end do
    keep = count(steps(1:keep) <= limit)
    if (keep < size(steps)) call log_line('series.h5: records after step '//trim(step_text(steps, keep))// &
         ' are not kept (beyond the checkpoint, or an unfinished write)')
    do c = 1, size(s%names)
      call column_extent(s, file, c, rank, dims, err)
      if (dims(rank) /= keep) then
        dims(rank) = keep
        call h5dopen_f(file, trim(s%names(c)), dset, err)
        call h5dset_extent_f(dset, dims(1:rank), e)
        err = max(err, abs(e))
        call h5dclose_f(dset, e)
        if (max(err, abs(e)) /= 0) call write_failed(s, trim(s%path)//'.tmp', 'column '//trim(s%names(c))// &
                                                     ' cannot be cut back')
      end if
    end do
    if (keep > 0) last = steps(keep)
  end subroutine sound_prefix

  function step_text(steps, keep) result(text)
    integer, intent(in) :: steps(:), keep
    character(len=20) :: text
    if (keep > 0) then
      write(text, '(i0)') steps(keep)
    else
      text = '0'
    end if
  end function step_text

  ! The step column of an open file whose columns must be this run's.
  subroutine read_steps(s, file, steps, problem)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    integer, allocatable, intent(out) :: steps(:)
    character(len=*), intent(out) :: problem
    integer(HID_T) :: dset, space
    integer(HSIZE_T) :: dims(1), maxdims(1)
    integer :: c, err
    problem = ''
    allocate(steps(0))
    do c = 1, size(s%names)
      if (.not. has_object(file, trim(s%names(c)))) then
        problem = 'it does not hold the column '//trim(s%names(c))//' of this run'
        return
      end if
    end do
    call h5dopen_f(file, 'step', dset, err)
    call h5dget_space_f(dset, space, err)
    call h5sget_simple_extent_dims_f(space, dims, maxdims, err)
    call h5sclose_f(space, err)
    deallocate(steps)
    allocate(steps(dims(1)))
    if (dims(1) > 0) call h5dread_f(dset, H5T_NATIVE_INTEGER, steps, dims, err)
    call h5dclose_f(dset, err)
    if (err /= 0) problem = 'its step column cannot be read'
  end subroutine read_steps

  ! Records i0.. of every column of an open file, into block (value, record).
  subroutine read_records(s, file, name, i0, block)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: name
    integer, intent(in) :: i0
    real(dp), intent(out) :: block(:, :)
    integer(HID_T) :: dset, fspace, mspace
    integer(HSIZE_T) :: dims(4), maxdims(4), offset(4), count(4), total(1)
    integer :: c, rank, err, e
    integer, allocatable :: steps(:)
    do c = 1, size(s%names)
      rank = column_rank(s%shapes(:, c))
      call h5dopen_f(file, trim(s%names(c)), dset, err)
      call h5dget_space_f(dset, fspace, e)
      err = max(err, abs(e))
      call h5sget_simple_extent_dims_f(fspace, dims(1:rank), maxdims(1:rank), e)
      offset = 0
      offset(rank) = i0 - 1
      count(1:rank) = dims(1:rank)
      count(rank) = size(block, 2)
      total(1) = product(count(1:rank))
      call h5sselect_hyperslab_f(fspace, H5S_SELECT_SET_F, offset(1:rank), count(1:rank), e)
      err = max(err, abs(e))
      call h5screate_simple_f(1, total, mspace, e)
      if (c == 1) then
        allocate(steps(total(1)))
        call h5dread_f(dset, H5T_NATIVE_INTEGER, steps, total, e, mspace, fspace)
        block(1, :) = real(steps, dp)
      else
        call h5dread_f(dset, H5T_NATIVE_DOUBLE, block(s%first(c):s%first(c + 1) - 1, :), total, e, mspace, fspace)
      end if
      err = max(err, abs(e))
      call h5sclose_f(mspace, e)
      call h5sclose_f(fspace, e)
      call h5dclose_f(dset, e)
      if (err /= 0) call abort_run('cannot read '//trim(s%names(c))//' from '//trim(name))
    end do
  end subroutine read_records

  ! Create a file with the series' columns (no records) and its attributes.
  subroutine create_file(s, name, file)
    type(series_t), intent(in) :: s
    character(len=*), intent(in) :: name
    integer(HID_T), intent(out) :: file
    integer :: err, c
    call h5fcreate_f(trim(name), H5F_ACC_TRUNC_F, file, err)
    if (err /= 0) call write_failed(s, name, 'cannot be created')
    do c = 1, size(s%names)
      call create_column(s, file, name, trim(s%names(c)), c == 1, s%shapes(:, c))
    end do
    call write_attributes(s, file, name)
  end subroutine create_file

  subroutine write_attributes(s, file, name)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: name
    integer :: k, err
    do k = 1, size(s%attribute_names)
      call write_attribute(file, trim(s%attribute_names(k)), s%attribute_values(k:k), err)
      if (err /= 0) call write_failed(s, name, 'its attribute '//trim(s%attribute_names(k))//' cannot be written')
    end do
  end subroutine write_attributes

  ! Close a file the series wrote; closing writes HDF5's metadata, so it can fail as a write can.
  subroutine close_file(s, file, name)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: name
    integer :: err
    call h5fclose_f(file, err)
    if (err /= 0) call write_failed(s, name, 'cannot be completed (closing it failed)')
  end subroutine close_file

  ! A write of the series failed: stop the run, naming the file and the cause. What the series
  ! published before is whole (nothing published is modified in place).
  subroutine write_failed(s, name, what)
    type(series_t), intent(in) :: s
    character(len=*), intent(in) :: name, what
    integer :: err
    real(dp) :: needed
    ! a partial .tmp would only hold space the user needs back; what it was to replace is whole
    if (index(name, '.tmp', back=.true.) == len_trim(name) - 3) err = remove_file(name)
    needed = 0.0_dp
    if (allocated(s%buffer)) needed = 8.0_dp * size(s%buffer, 1) * max(1, s%nbuf)
    call abort_run(trim(name)//' '//what//': '//write_failure_cause(directory_of(s%path), needed)// &
         '; the records published before, and the last checkpoint, are kept')
  end subroutine write_failed

  ! Move a file the series cannot use aside with a warning: NAME.damaged (.damaged-2, ...) when it
  ! cannot be read, NAME.other-columns when it is another run's or holds other quantities (the
  ! problems that say so name 'this run').
  subroutine keep_aside(name, problem)
    character(len=*), intent(in) :: name, problem
    character(len=1100) :: aside
    character(len=:), allocatable :: suffix
    integer :: k, err
    logical :: exists
    suffix = '.damaged'
    if (index(problem, 'this run') > 0) suffix = '.other-columns'
    aside = trim(name)//suffix
    k = 1
    do
      inquire(file=trim(aside), exist=exists)
      if (.not. exists) exit
      k = k + 1
      write(aside, '(a,i0)') trim(name)//suffix//'-', k
    end do
    err = rename_file(name, aside)
    if (err /= 0) call abort_run('cannot move '//trim(name)//' aside to '//trim(aside)//': '//errno_text(err))
    call warn_line(trim(name)//': '//trim(problem)//'; kept as '//trim(aside)// &
         ' (nothing is deleted), the series goes on without its records')
  end subroutine keep_aside

  ! Partial files of a killed write: series.h5.tmp and the .tmp files of series.parts.
  subroutine remove_partial_writes(s)
    type(series_t), intent(in) :: s
    integer :: err
    err = remove_file(trim(s%path)//'.tmp')
    if (err /= 0) call abort_run('cannot remove '//trim(s%path)//'.tmp: '//errno_text(err))
    call remove_in_parts(s, '.tmp')
  end subroutine remove_partial_writes

  ! Remove the files of series.parts whose names end in suffix ('.h5': the parts).
  subroutine remove_in_parts(s, suffix)
    type(series_t), intent(in) :: s
    character(len=*), intent(in) :: suffix
    character(len=256), allocatable :: names(:)
    integer :: k, err
    call list_directory(s%parts_dir, suffix, names, err)
    do k = 1, size(names)
      err = remove_file(trim(s%parts_dir)//'/'//trim(names(k)))
      if (err /= 0) call abort_run('cannot remove '//trim(s%parts_dir)//'/'//trim(names(k))//': '//errno_text(err))
    end do
  end subroutine remove_in_parts

  ! The per-record rank + 1 and the dimensions (records last) of column c in an open file.
  subroutine column_extent(s, file, c, rank, dims, err)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    integer, intent(in) :: c
    integer, intent(out) :: rank, err
    integer(HSIZE_T), intent(out) :: dims(4)
    integer(HID_T) :: dset, space
    integer(HSIZE_T) :: maxdims(4)
    integer :: e
    dims = 0
    rank = 0
    call h5dopen_f(file, trim(s%names(c)), dset, err)
    if (err /= 0) return
    call h5dget_space_f(dset, space, err)
    call h5sget_simple_extent_ndims_f(space, rank, e)
    if (rank >= 1 .and. rank <= 4) call h5sget_simple_extent_dims_f(space, dims(1:rank), maxdims(1:rank), e)
    call h5sclose_f(space, e)
    call h5dclose_f(dset, e)
  end subroutine column_extent

  ! Rank of a column's dataset: its per-record dimensions (those > 0) plus records.
  pure integer function column_rank(shape)
    integer, intent(in) :: shape(3)
    column_rank = count(shape > 0) + 1
  end function column_rank

  subroutine create_column(s, file, filename, name, is_integer, shape)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: filename, name
    logical, intent(in) :: is_integer
    integer, intent(in) :: shape(3)
    integer(HID_T) :: space, plist, dset, dtype, group
    integer(HSIZE_T) :: dims(4), maxdims(4), chunks(4)
    integer :: err, e, rank, slash
    rank = column_rank(shape)
    dims(1:rank - 1) = shape(1:rank - 1)
    dims(rank) = 0
    maxdims = dims
    maxdims(rank) = H5S_UNLIMITED_F
    chunks = dims
    chunks(rank) = max(1_HSIZE_T, chunk / product(max(1_HSIZE_T, dims(1:rank - 1))))
    dtype = H5T_NATIVE_DOUBLE
    if (is_integer) dtype = H5T_NATIVE_INTEGER
    err = 0
    ! a name with a '/' lives in a group (particles/velocity)
    slash = index(name, '/')
    if (slash > 0) then
      if (.not. has_object(file, name(1:slash - 1))) then
        call h5gcreate_f(file, name(1:slash - 1), group, err)
        call h5gclose_f(group, e)
      end if
    end if
    call h5screate_simple_f(rank, dims(1:rank), space, e, maxdims(1:rank))
    err = max(err, abs(e))
    call h5pcreate_f(H5P_DATASET_CREATE_F, plist, e)
    call h5pset_chunk_f(plist, rank, chunks(1:rank), e)
    err = max(err, abs(e))
    call h5dcreate_f(file, name, dtype, space, dset, e, plist)
    err = max(err, abs(e))
    call h5dclose_f(dset, e)
    err = max(err, abs(e))
    call h5pclose_f(plist, e)
    call h5sclose_f(space, e)
    if (err /= 0) call write_failed(s, filename, 'cannot hold the dataset '//name)
  end subroutine create_column

  ! Append records (value, record) to every column of an open file.
  subroutine append_records(s, file, filename, records)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: filename
    real(dp), intent(in) :: records(:, :)
    integer(HID_T) :: dset, fspace, mspace
    integer(HSIZE_T) :: dims(4), maxdims(4), offset(4), count(4)
    integer :: err, e, c, rank
    real(dp), allocatable :: block(:, :)
    do c = 1, size(s%names)
      rank = column_rank(s%shapes(:, c))
      call h5dopen_f(file, trim(s%names(c)), dset, err)
      call h5dget_space_f(dset, fspace, e)
      err = max(err, abs(e))
      call h5sget_simple_extent_dims_f(fspace, dims(1:rank), maxdims(1:rank), e)
      call h5sclose_f(fspace, e)
      offset = 0
      offset(rank) = dims(rank)
      count(1:rank) = dims(1:rank)
      count(rank) = size(records, 2)
      dims(rank) = dims(rank) + size(records, 2)
      call h5dset_extent_f(dset, dims(1:rank), e)
      err = max(err, abs(e))
      call h5dget_space_f(dset, fspace, e)
      call h5sselect_hyperslab_f(fspace, H5S_SELECT_SET_F, offset(1:rank), count(1:rank), e)
      err = max(err, abs(e))
      call h5screate_simple_f(rank, count(1:rank), mspace, e)
      block = records(s%first(c):s%first(c + 1) - 1, :)
      if (c == 1) then
        call h5dwrite_f(dset, H5T_NATIVE_INTEGER, nint(block(1, :)), count(1:1), e, mspace, fspace)
      else
        call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, block, count(1:rank), e, mspace, fspace)
      end if
      err = max(err, abs(e))
      call h5sclose_f(mspace, e)
      call h5sclose_f(fspace, e)
      ! closing writes the dataset's cached chunks: a full disk may show only here
      call h5dclose_f(dset, e)
      err = max(err, abs(e))
      if (err /= 0) call write_failed(s, filename, 'cannot take the records of '//trim(s%names(c)))
    end do
  end subroutine append_records

end module mod_series
