! series.h5: one record per output step, one dataset per quantity (doc/DESIGN.md "Files"): scalars
! as 1-D datasets (records), per-particle quantities with a per-record shape, e.g. (3, N) in
! Fortran order, which C and Python see as records x N x 3 (particles/velocity) or, for (3, 3, N),
! records x N x 3 x 3 (particles/stresslet_hydro).
! The columns are named once, by one routine of the program that calls series_column for each
! (name and value; the value's shape is the column's): called before series_open it declares them,
! afterwards it fills the record that series_record adds. So the file's header and its records
! come from the same lines and cannot fall out of step.
!
! Written by every rank together (issue 45, doc/DESIGN.md "Parallelism" and "Files"): a per-sphere
! column (mod_columns sphere_column: the particles/ datasets, whose last dimension is the number of
! spheres N) comes from each rank for its own spheres only, given as global indices that may change
! from record to record, and each rank buffers only those rows; the other columns are buffered on
! every rank (they are replicated) and written from rank 0's. Every file is opened by every rank
! through MPI-IO (mod_h5_parallel) and every metadata call is made on every rank with the same
! values. At a flush the buffered rows go, in one all-to-all, to the rank that writes their sphere
! in the file (rank r writes the contiguous range of spheres r N / P + 1 .. (r + 1) N / P), so that
! each rank writes one box (its spheres x the records) of each per-sphere dataset in one
! collective transfer, filled column by column from the rows (no dense copy of them); consolidation
! moves the records the same way, each rank its range (reading the parts, which are only read,
! through its own serial open, so without collective calls; the part a flush has just published
! from memory). One rank exchanges nothing and opens the files with HDF5's serial driver
! (doc/BENCHMARKS.md §20). The layout is one writer's: the same datasets, shapes, types and chunks
! on any number of ranks.
! Every decision that leads to a collective call is the same on every rank: the wall-clock interval
! of progress flushes is rank 0's, broadcast; the parts, the steps and the files' problems are
! rank 0's, broadcast; every HDF5 failure is agreed by all ranks.
!
! Crash safety (doc/DESIGN.md "series.h5: immutable parts, atomic consolidation"): no file the
! series has published is ever modified in place, so a kill at any instant leaves every published
! record whole. A flush (progress lines, checkpoints, a full buffer) writes the buffered records as
! a part, series.parts/<first step>.h5, through a .tmp file that rank 0 flushes to disk and renames
! once every rank has closed it. Consolidation copies series.h5 to series.h5.tmp (rank 0), appends
! the parts' records after its last step (every rank), and renames the copy over series.h5; only
! then are the parts removed. It runs at every flush while series.h5 is small, when the parts reach
! half the size of series.h5 (so the copies cost at most about twice the data once), at the end of
! a run, and when a run starts from a checkpoint: then it keeps only the records up to the
! checkpoint's step, so that the continued run writes exactly the records an uninterrupted one
! would, on any number of ranks. Every write is checked: a failure stops every rank with one
! message (abort_if_any) naming the file and the cause; the published series stays whole.
#include <petsc/finclude/petscsys.h>
module mod_series
  use petscsys
  use hdf5
  use mod_kinds, only: dp
  use mod_columns, only: column_t
  use mod_sorting, only: ascending_order
  use mod_h5util, only: has_object, write_attribute
  use mod_h5_parallel, only: h5_parallel_create, h5_parallel_open, h5_parallel_close, h5_parallel_agree
  use mod_errors, only: is_root, warn_line, log_line, abort_run, abort_if_any
  use mod_os_services, only: publish_file, make_directory
  use mod_file_services, only: list_directory, copy_file, remove_file, rename_file, errno_text, write_failure_cause, &
                               free_bytes, directory_of, require_free_space
  implicit none
  private
  public :: series_t, series_column, series_add, series_open, series_record, series_flush, series_close, series_attributes

  type :: series_t
    character(len=1024) :: path = ''           ! OUTDIR/series.h5
    character(len=1024) :: parts_dir = ''      ! OUTDIR/series.parts
    character(len=64), allocatable :: names(:)
    integer, allocatable :: shapes(:, :)     ! (3, column): per-record shape, 0 where unused
    logical, allocatable :: per_sphere(:)    ! a per-sphere column (its last dimension the spheres)
    integer, allocatable :: first(:)         ! offset of each column in a record's other values, or
                                             ! (per-sphere) in a sphere's values
    integer, allocatable :: width(:)         ! its values in a record, or (per-sphere) per sphere
    integer :: scalar_values = 0             ! a record's values of the other columns
    integer :: sphere_values = 0             ! a sphere's values of the per-sphere columns
    integer :: spheres = 0                   ! N, the per-sphere columns' last dimension
    integer :: sphere_lo = 1, sphere_hi = 0  ! the spheres this rank writes into a file
    logical :: alone = .false.               ! one rank: its buffer written as it is, through HDF5's
                                             ! serial driver (mod_h5_parallel serial_alone)
    integer :: record_length = 0             ! the values of one record over all ranks
    real(dp), allocatable :: buffer(:, :)    ! (value of the other columns, record), every rank
    integer :: nbuf = 0
    real(dp), allocatable :: sphere_buffer(:, :)  ! (a sphere's values, row): this rank's spheres
    integer, allocatable :: sphere_place(:, :)    ! (2, row): the row's sphere and record (in buffer)
    integer :: nrows = 0
    integer :: max_records = 0               ! records of one part: its buffer's bound (part_bytes)
    logical :: open = .false.                ! series_open done: series_column fills, not declares
    integer :: filled = 0                    ! columns of the record being assembled
    real(dp), allocatable :: row(:)          ! the record being assembled: its other columns
    integer, allocatable :: row_spheres(:)   ! its spheres (global indices), set by its first
                                             ! per-sphere column
    real(dp), allocatable :: sphere_row(:, :) ! (a sphere's values, row_spheres)
    character(len=32), allocatable :: attribute_names(:)
    real(dp), allocatable :: attribute_values(:)
    integer :: parts = 0                     ! parts published since the last consolidation
    real(dp) :: parts_bytes = 0.0_dp         ! their size
    real(dp) :: consolidated_bytes = 0.0_dp  ! the size of series.h5
    real(dp) :: flush_seconds = 5.0_dp        ! progress lines flush at most this often (wall time)
    integer(kind=8) :: last_flush = 0         ! system_clock count of the last flush (rank 0's counts)
  end type series_t

  ! One column: its value, a scalar or an array whose shape is the column's per-record shape
  ! (an integer scalar, the step or a count, is stored as real like every value of a record)
  interface series_column
    module procedure column_int, column_real, column_vector, column_matrix, column_tensor
  end interface series_column

  integer(HSIZE_T), parameter :: chunk = 1024
  ! a part holds at most this many bytes of records: the bound of the buffers (-series_part_mb)
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
  ! filled into the record being assembled afterwards. A per-sphere column (its rows set) holds
  ! this rank's spheres.
  subroutine series_add(s, columns)
    type(series_t), intent(inout) :: s
    type(column_t), intent(in) :: columns(:)
    integer :: k
    do k = 1, size(columns)
      ! an unallocated rows is an absent argument: a column of the whole record
      call column(s, trim(columns(k)%name), columns(k)%shape, columns(k)%values, columns(k)%rows)
    end do
  end subroutine series_add

  ! Before series_open: add the column (name, per-record shape; per-sphere when rows is present).
  ! After: put its values (in Fortran order) into the record being assembled, the next of the
  ! declared columns; a per-sphere column's values are those of the spheres rows (global indices,
  ! the same for every per-sphere column of a record).
  subroutine column(s, name, shape, values, rows)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: name
    integer, intent(in) :: shape(3)
    real(dp), intent(in) :: values(:)
    integer, intent(in), optional :: rows(:)
    integer :: c, m
    if (.not. s%open) then
      if (.not. allocated(s%names)) allocate(s%names(0), s%shapes(3, 0), s%per_sphere(0))
      s%names = [character(len=64) :: s%names, name]
      s%shapes = reshape([s%shapes, shape], [3, size(s%names)])
      s%per_sphere = [s%per_sphere, present(rows)]
      return
    end if
    c = s%filled + 1
    ! the columns are declared and filled by the same calls; another order is a programming error
    if (c > size(s%names)) call abort_run('series.h5: a record has more columns than declared ('//name//')')
    if (s%names(c) /= name .or. (present(rows) .neqv. s%per_sphere(c))) &
      call abort_run('series.h5: column '//name//' does not match the declared '//trim(s%names(c)))
    if (present(rows)) then
      m = size(rows)
      if (.not. allocated(s%row_spheres)) then
        allocate(s%row_spheres(m), s%sphere_row(s%sphere_values, m))
        s%row_spheres = rows
      else if (size(s%row_spheres) /= m) then
        call abort_run('series.h5: column '//name//' holds other spheres than the record''s other per-sphere columns')
      else if (any(s%row_spheres /= rows)) then
        call abort_run('series.h5: column '//name//' holds other spheres than the record''s other per-sphere columns')
      end if
      if (size(values) /= s%width(c) * m) &
        call abort_run('series.h5: column '//name//' does not match the declared '//trim(s%names(c)))
      s%sphere_row(s%first(c):s%first(c) + s%width(c) - 1, :) = reshape(values, [s%width(c), m])
    else
      if (size(values) /= s%width(c)) &
        call abort_run('series.h5: column '//name//' does not match the declared '//trim(s%names(c)))
      s%row(s%first(c):s%first(c) + s%width(c) - 1) = values
    end if
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
  ! Collective.
  subroutine series_open(s, outdir, restart_step, records_to_come)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: outdir
    integer, intent(in) :: restart_step, records_to_come
    integer :: c, r, err, ranks, rank
    PetscReal :: part_megabytes
    PetscBool :: set
    PetscErrorCode :: ierr

    if (.not. allocated(s%names)) call abort_run('series.h5: no columns declared')
    if (s%names(1) /= 'step') call abort_run('series.h5: the first column must be the step')
    if (.not. allocated(s%attribute_names)) allocate(s%attribute_names(0), s%attribute_values(0))
    ! each column's place: in a record's other values, or in a sphere's values
    allocate(s%first(size(s%names)), s%width(size(s%names)))
    s%scalar_values = 0
    s%sphere_values = 0
    s%spheres = 0
    do c = 1, size(s%names)
      r = count(s%shapes(:, c) > 0)
      if (s%per_sphere(c)) then
        if (s%spheres > 0 .and. s%shapes(r, c) /= s%spheres) &
          call abort_run('series.h5: the per-sphere column '//trim(s%names(c))//' has another number of spheres')
        s%spheres = s%shapes(r, c)
        s%width(c) = product(max(1, s%shapes(1:r - 1, c)))
        s%first(c) = s%sphere_values + 1
        s%sphere_values = s%sphere_values + s%width(c)
      else
        s%width(c) = product(max(1, s%shapes(:, c)))
        s%first(c) = s%scalar_values + 1
        s%scalar_values = s%scalar_values + s%width(c)
      end if
    end do
    s%record_length = s%scalar_values + s%sphere_values * s%spheres
    ! the spheres this rank writes into a file: a contiguous range, ranks in order
    PetscCallMPIA(MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr))
    PetscCallMPIA(MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr))
    s%sphere_lo = int(int(rank, 8) * s%spheres / ranks) + 1
    s%sphere_hi = int(int(rank + 1, 8) * s%spheres / ranks)
    s%alone = ranks == 1
    ! -series_flush_seconds: how often at most progress lines publish the records (checkpoints, a
    ! full buffer and the end always do): a part and, while series.h5 is small, its copy per flush
    ! would cost more than the step itself in a run with a progress line every step
    PetscCallA(PetscOptionsGetReal(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-series_flush_seconds', s%flush_seconds, set, ierr))
    call system_clock(s%last_flush)
    ! -series_part_mb: the bound of a part, and so of the buffers, in MiB (of all ranks' records)
    part_megabytes = part_bytes / 1048576.0_dp
    PetscCallA(PetscOptionsGetReal(PETSC_NULL_OPTIONS, PETSC_NULL_CHARACTER, '-series_part_mb', part_megabytes, set, ierr))
    s%max_records = max(1, int(min(part_megabytes * 1048576.0_dp / (8.0_dp * s%record_length), 1.0e9_dp)))
    allocate(s%buffer(s%scalar_values, min(256, s%max_records)), s%row(s%scalar_values))
    allocate(s%sphere_buffer(s%sphere_values, 256), s%sphere_place(2, 256))
    s%nbuf = 0
    s%nrows = 0
    s%filled = 0
    s%open = .true.
    s%path = trim(outdir)//'/series.h5'
    s%parts_dir = trim(outdir)//'/series.parts'

    if (is_root()) then
      err = make_directory(s%parts_dir)
      if (err /= 0) call abort_run('cannot create '//trim(s%parts_dir)//': '//errno_text(err))
      call remove_partial_writes(s)
      if (restart_step < 0) call remove_in_parts(s, '.h5')   ! an earlier run's
    end if
    if (restart_step >= 0) then
      call consolidate(s, restart_step)
    else
      call start_empty(s)
    end if
    if (is_root()) call project_size(s, outdir, 8.0_dp * s%record_length * max(records_to_come, 0))
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

  ! Add the record assembled by series_column since the last one (all the declared columns): its
  ! other columns, and the rows of this rank's spheres. A full buffer is flushed as a part.
  ! Collective (every rank adds every record).
  subroutine series_record(s)
    type(series_t), intent(inout) :: s
    real(dp), allocatable :: bigger(:, :)
    integer, allocatable :: places(:, :)
    integer :: m, capacity
    if (s%filled /= size(s%names)) call abort_run('series.h5: a record misses columns of the declared ones')
    s%filled = 0
    if (s%nbuf == size(s%buffer, 2)) then
      allocate(bigger(size(s%buffer, 1), min(2 * size(s%buffer, 2), s%max_records)))
      bigger(:, 1:s%nbuf) = s%buffer(:, 1:s%nbuf)
      call move_alloc(bigger, s%buffer)
    end if
    s%nbuf = s%nbuf + 1
    s%buffer(:, s%nbuf) = s%row
    if (allocated(s%row_spheres)) then
      m = size(s%row_spheres)
      if (s%nrows + m > size(s%sphere_buffer, 2)) then
        capacity = max(2 * size(s%sphere_buffer, 2), s%nrows + m)
        allocate(bigger(s%sphere_values, capacity), places(2, capacity))
        bigger(:, 1:s%nrows) = s%sphere_buffer(:, 1:s%nrows)
        places(:, 1:s%nrows) = s%sphere_place(:, 1:s%nrows)
        call move_alloc(bigger, s%sphere_buffer)
        call move_alloc(places, s%sphere_place)
      end if
      s%sphere_buffer(:, s%nrows + 1:s%nrows + m) = s%sphere_row
      s%sphere_place(1, s%nrows + 1:s%nrows + m) = s%row_spheres
      s%sphere_place(2, s%nrows + 1:s%nrows + m) = s%nbuf
      s%nrows = s%nrows + m
      deallocate(s%row_spheres, s%sphere_row)
    end if
    if (s%nbuf == s%max_records) call series_flush(s)
  end subroutine series_record

  ! Publish the buffered records as a part; consolidate series.h5 when that is due. progress,
  ! optional: the flush of a progress line, done only when -series_flush_seconds have passed since
  ! the last one (by rank 0's clock, so that every rank takes the same branch). Collective.
  subroutine series_flush(s, progress)
    type(series_t), intent(inout) :: s
    logical, intent(in), optional :: progress
    character(len=1100) :: part
    integer(kind=8) :: now, rate
    logical :: due
    real(dp), allocatable :: rows(:, :)
    integer, allocatable :: place(:, :)
    PetscErrorCode :: ierr
    if (.not. s%open .or. s%nbuf == 0) return
    call system_clock(now, rate)
    due = .true.
    if (present(progress)) then
      if (progress) due = real(now - s%last_flush, dp) >= s%flush_seconds * rate
    end if
    PetscCallMPIA(MPI_Bcast(due, 1, MPI_LOGICAL, 0, PETSC_COMM_WORLD, ierr))
    if (.not. due) return
    s%last_flush = now
    write(part, '(a,i10.10,a)') trim(s%parts_dir)//'/', nint(s%buffer(1, 1)), '.h5'
    ! a full disk must stop every rank before the collective write, not inside it
    call require_free_space(directory_of(s%path), 8.0_dp * s%record_length * s%nbuf, trim(part))
    if (s%alone) then
      ! one rank writes every sphere: its rows as they are, not a copy (doc/BENCHMARKS.md §20)
      call check_places(s, s%sphere_place(:, 1:s%nrows))
      call publish_records(s, part, s%sphere_buffer(:, 1:s%nrows), s%sphere_place(:, 1:s%nrows))
    else
      call spheres_by_range(s, rows, place)
      call publish_records(s, part, rows, place)
    end if
    s%nbuf = 0
    s%nrows = 0
  end subroutine series_flush

  ! The buffered records as the part `part` (its per-sphere columns: rows(:, j) the values of the
  ! sphere and record place(:, j), every sphere of this rank's range and record once), and
  ! series.h5 consolidated when that is due, these records appended from memory. Collective.
  subroutine publish_records(s, part, rows, place)
    type(series_t), intent(inout) :: s
    character(len=*), intent(in) :: part
    real(dp), intent(in) :: rows(:, :)
    integer, intent(in) :: place(:, :)
    integer(HID_T) :: file
    call create_file(s, trim(part)//'.tmp', file)
    call append_records(s, file, trim(part)//'.tmp', s%buffer(:, 1:s%nbuf), rows=rows, place=place, record0=0)
    call close_file(s, file, trim(part)//'.tmp')
    call publish(s, trim(part)//'.tmp', part)
    s%parts = s%parts + 1
    s%parts_bytes = s%parts_bytes + file_bytes(part)
    if (s%consolidated_bytes + s%parts_bytes <= small_series_bytes .or. s%parts >= max_parts .or. &
        s%parts_bytes >= 0.5_dp * s%consolidated_bytes) call consolidate(s, no_limit, part, rows, place)
  end subroutine publish_records

  ! The end of a run: the buffered records and the parts, all in series.h5. Collective.
  subroutine series_close(s)
    type(series_t), intent(inout) :: s
    if (.not. s%open) return
    call series_flush(s)
    if (s%parts > 0) call consolidate(s, no_limit)
  end subroutine series_close

  ! The buffered rows of every rank, each sent to the rank that writes its sphere into the files
  ! (one all-to-all): rows(:, j) the values of the sphere and buffered record place(:, j), for
  ! every sphere of sphere_lo .. sphere_hi and every buffered record exactly once (checked). The
  ! rows are not put in order: append_records places each where it belongs, so that no dense copy
  ! of them is held beside the buffer and the exchanged rows (doc/BENCHMARKS.md §20). Collective.
  subroutine spheres_by_range(s, rows, place)
    type(series_t), intent(in) :: s
    real(dp), allocatable, intent(out) :: rows(:, :)
    integer, allocatable, intent(out) :: place(:, :)
    integer :: ranks, j, k, r, n
    integer, allocatable :: owner(:), order(:), send_count(:), send_displs(:), recv_count(:), recv_displs(:), &
                            send_place(:, :)
    real(dp), allocatable :: send(:, :)
    PetscErrorCode :: ierr
    allocate(rows(s%sphere_values, 0), place(2, 0))
    if (s%sphere_values == 0) return
    call abort_if_any(any(s%sphere_place(1, 1:s%nrows) < 1 .or. s%sphere_place(1, 1:s%nrows) > s%spheres), &
                      'internal error: series.h5: a per-sphere row names no sphere of the run')
    PetscCallMPIA(MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr))
    ! the rows sorted by the rank that writes their sphere
    allocate(owner(s%nrows), send(s%sphere_values, s%nrows), send_place(2, s%nrows), send_count(0:ranks - 1), &
             send_displs(0:ranks - 1), recv_count(0:ranks - 1), recv_displs(0:ranks - 1))
    do j = 1, s%nrows
      ! the largest r whose range starts at or before the sphere: r N / P <= sphere - 1
      owner(j) = int((int(s%sphere_place(1, j) - 1, 8) * ranks + ranks - 1) / s%spheres)
    end do
    order = ascending_order(owner)
    send_count = 0
    do k = 1, s%nrows
      j = order(k)
      send_place(:, k) = s%sphere_place(:, j)
      send(:, k) = s%sphere_buffer(:, j)
      send_count(owner(j)) = send_count(owner(j)) + 1
    end do
    PetscCallMPIA(MPI_Alltoall(send_count, 1, MPI_INTEGER, recv_count, 1, MPI_INTEGER, PETSC_COMM_WORLD, ierr))
    send_displs(0) = 0
    recv_displs(0) = 0
    do r = 1, ranks - 1
      send_displs(r) = send_displs(r - 1) + send_count(r - 1)
      recv_displs(r) = recv_displs(r - 1) + recv_count(r - 1)
    end do
    n = sum(recv_count)
    deallocate(rows, place)
    allocate(rows(s%sphere_values, n), place(2, n))
    PetscCallMPIA(MPI_Alltoallv(send_place, 2 * send_count, 2 * send_displs, MPI_INTEGER, place, 2 * recv_count, 2 * recv_displs, MPI_INTEGER, PETSC_COMM_WORLD, ierr))
    PetscCallMPIA(MPI_Alltoallv(send, s%sphere_values * send_count, s%sphere_values * send_displs, MPI_DOUBLE_PRECISION, rows, s%sphere_values * recv_count, s%sphere_values * recv_displs, MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, ierr))
    deallocate(send)
    call check_places(s, place)
  end subroutine spheres_by_range

  ! Whether place(:, j) (sphere, buffered record) of the rows gives every sphere of this rank's
  ! range and every buffered record exactly once; else a programming error, stopped on every
  ! rank. Collective.
  subroutine check_places(s, place)
    type(series_t), intent(in) :: s
    integer, intent(in) :: place(:, :)
    integer, allocatable :: times(:, :)
    integer :: j
    logical :: wrong
    if (s%sphere_values == 0) return
    wrong = any(place(1, :) < s%sphere_lo .or. place(1, :) > s%sphere_hi .or. place(2, :) < 1 .or. place(2, :) > s%nbuf)
    if (.not. wrong) then
      allocate(times(s%sphere_lo:s%sphere_hi, s%nbuf))
      times = 0
      do j = 1, size(place, 2)
        times(place(1, j), place(2, j)) = times(place(1, j), place(2, j)) + 1
      end do
      wrong = any(times /= 1)
    end if
    call abort_if_any(wrong, 'internal error: series.h5: a sphere''s values of a record were given '// &
                      'by no rank or by more than one')
  end subroutine check_places

  ! A new, empty series.h5 (the columns and attributes), published whole. Collective.
  subroutine start_empty(s)
    type(series_t), intent(inout) :: s
    integer(HID_T) :: file
    call create_file(s, trim(s%path)//'.tmp', file)
    call close_file(s, file, trim(s%path)//'.tmp')
    call publish(s, trim(s%path)//'.tmp', s%path)
    s%consolidated_bytes = file_bytes(s%path)
    s%parts = 0
    s%parts_bytes = 0.0_dp
  end subroutine start_empty

  ! tmp, closed by every rank, renamed over name by rank 0 (flushed to disk first). Collective.
  subroutine publish(s, tmp, name)
    type(series_t), intent(in) :: s
    character(len=*), intent(in) :: tmp, name
    integer :: err
    err = 0
    if (is_root()) err = publish_file(tmp, name)
    call from_root(err)
    if (err /= 0) call write_failed(s, name, 'cannot be published ('//errno_text(err)//')')
  end subroutine publish

  ! The size of a file in bytes as rank 0 sees it (0 if it has none), on every rank. Collective.
  real(dp) function file_bytes(name)
    character(len=*), intent(in) :: name
    integer(kind=8) :: bytes(1)
    PetscErrorCode :: ierr
    bytes = 0
    if (is_root()) inquire(file=trim(name), size=bytes(1))
    PetscCallMPIA(MPI_Bcast(bytes, 1, MPI_INTEGER8, 0, PETSC_COMM_WORLD, ierr))
    file_bytes = real(max(bytes(1), 0_8), dp)
  end function file_bytes

  ! value becomes rank 0's on every rank. Collective.
  subroutine from_root(value)
    integer, intent(inout) :: value
    PetscErrorCode :: ierr
    PetscCallMPIA(MPI_Bcast(value, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr))
  end subroutine from_root

  ! problem (a file's, '' when none) becomes rank 0's on every rank. Collective.
  subroutine problem_from_root(problem)
    character(len=*), intent(inout) :: problem
    PetscErrorCode :: ierr
    PetscCallMPIA(MPI_Bcast(problem, len(problem), MPI_CHARACTER, 0, PETSC_COMM_WORLD, ierr))
  end subroutine problem_from_root

  ! series.h5 and the parts merged into series.h5.tmp, renamed over series.h5, then the parts
  ! removed: the records of series.h5 (its longest sound prefix: every column that long, steps
  ! increasing), then each part's records after the last step so far, up to step `limit`. Rank 0
  ! lists the parts, copies series.h5 and renames and removes files; every rank moves the records
  ! of its range of spheres (and rank 0 those of the other columns). fresh, optional: the part a
  ! flush has just published from the buffered records, whose per-sphere rows it gives as rows and
  ! place (publish_records): they are appended from memory, not read back from the part (the same
  ! values; the read was a fifth of a flush's cost, doc/BENCHMARKS.md §20). Collective.
  subroutine consolidate(s, limit, fresh, rows, place)
    type(series_t), intent(inout) :: s
    integer, intent(in) :: limit
    character(len=*), intent(in), optional :: fresh
    real(dp), intent(in), optional :: rows(:, :)
    integer, intent(in), optional :: place(:, :)
    character(len=256), allocatable :: parts(:)
    character(len=1100) :: tmp, part
    character(len=400) :: problem
    integer(HID_T) :: file, source
    integer :: err, e, k, last, n_source, i0, i1, first, slice
    integer, allocatable :: steps(:)
    real(dp), allocatable :: scalars(:, :), dense(:, :, :)
    logical :: exists
    PetscErrorCode :: ierr

    call list_parts(s, parts)
    tmp = trim(s%path)//'.tmp'
    ! the copy and the parts' records: a full disk must stop every rank before the collective writes
    call require_free_space(directory_of(s%path), file_bytes(s%path) + s%parts_bytes, trim(tmp))
    last = -huge(1)
    exists = .false.
    if (is_root()) inquire(file=trim(s%path), exist=exists)
    PetscCallMPIA(MPI_Bcast(exists, 1, MPI_LOGICAL, 0, PETSC_COMM_WORLD, ierr))
    problem = ''
    if (exists) then
      err = 0
      if (is_root()) err = copy_file(s%path, tmp)
      call from_root(err)
      if (err /= 0) call write_failed(s, tmp, 'cannot be written as a copy of series.h5 ('//errno_text(err)//')')
      call h5_parallel_open(trim(tmp), file, err, serial_alone=.true.)
      if (err /= 0) then
        problem = 'it cannot be read as HDF5'
      else
        call sound_prefix(s, file, limit, problem, last)
        if (len_trim(problem) > 0) call h5_parallel_close(file, err)
      end if
      if (len_trim(problem) > 0) then
        if (is_root()) then
          err = remove_file(tmp)
          call keep_aside(s%path, problem)
        end if
      end if
    end if
    if (.not. exists .or. len_trim(problem) > 0) then
      call create_file(s, tmp, file)
      last = -huge(1)
    end if
    ! in slices of at most 256 records and a part's bound: the copy holds little memory whatever
    ! the part's size
    slice = min(256, s%max_records)
    do k = 1, size(parts)
      part = trim(s%parts_dir)//'/'//trim(parts(k))
      if (present(fresh)) then
        if (part == fresh) then
          ! its records after the last step so far, up to the limit, from the buffer
          steps = nint(s%buffer(1, 1:s%nbuf))
          i0 = findloc(steps > last, .true., 1)
          i1 = count(steps <= limit)
          if (i0 > 0 .and. i1 >= i0) then
            call append_records(s, file, tmp, s%buffer(:, i0:i1), rows=rows, place=place, record0=i0 - 1)
            last = steps(i1)
          end if
          cycle
        end if
      end if
      ! a part is only read: each rank opens it by itself (no collective call), and reads its share
      call h5fopen_f(trim(part), H5F_ACC_RDONLY_F, source, err)
      call h5_parallel_agree(err)
      problem = ''
      if (err /= 0) then
        problem = 'it cannot be read as HDF5'
      else
        call read_steps(s, source, steps, problem)
      end if
      if (len_trim(problem) > 0) then
        if (err == 0) call h5fclose_f(source, e)
        PetscCallMPIA(MPI_Barrier(PETSC_COMM_WORLD, ierr))
        if (is_root()) call keep_aside(part, problem)
        cycle
      end if
      ! the records after the last step so far, up to the limit (steps increase within a part)
      i0 = findloc(steps > last, .true., 1)
      i1 = count(steps <= limit)
      if (i0 > 0 .and. i1 >= i0) then
        do first = i0, i1, slice
          n_source = min(slice, i1 - first + 1)
          allocate(scalars(s%scalar_values, n_source), dense(s%sphere_values, s%sphere_hi - s%sphere_lo + 1, n_source))
          call read_records(s, source, part, first, scalars, dense)
          call append_records(s, file, tmp, scalars, dense)
          deallocate(scalars, dense)
        end do
        last = steps(i1)
      end if
      call h5fclose_f(source, e)
    end do
    call write_attributes(s, file, tmp)
    call close_file(s, file, tmp)
    call publish(s, tmp, s%path)
    ! series.h5 now holds every record: the parts go (a kill before they are gone leaves records
    ! that the next consolidation finds at or before series.h5's last step, and skips)
    if (is_root()) then
      do k = 1, size(parts)
        err = remove_file(trim(s%parts_dir)//'/'//trim(parts(k)))
        if (err /= 0) call abort_run('cannot remove '//trim(s%parts_dir)//'/'//trim(parts(k))//': '//errno_text(err))
      end do
    end if
    s%consolidated_bytes = file_bytes(s%path)
    s%parts = 0
    s%parts_bytes = 0.0_dp
  end subroutine consolidate

  ! The parts in series.parts (rank 0's listing, in the order of their first steps), on every rank.
  ! Collective.
  subroutine list_parts(s, parts)
    type(series_t), intent(in) :: s
    character(len=256), allocatable, intent(out) :: parts(:)
    integer :: err, n
    PetscErrorCode :: ierr
    err = 0
    n = 0
    if (is_root()) then
      call list_directory(s%parts_dir, '.h5', parts, err)
      n = size(parts)
    end if
    call from_root(err)
    if (err /= 0) call abort_if_any(.true., 'cannot list '//trim(s%parts_dir)//': '//errno_text(err))
    call from_root(n)
    if (.not. is_root()) allocate(parts(n))
    if (n > 0) then
      PetscCallMPIA(MPI_Bcast(parts, len(parts) * n, MPI_CHARACTER, 0, PETSC_COMM_WORLD, ierr))
    end if
  end subroutine list_parts

  ! Cut the open copy of series.h5 to its longest sound prefix up to step `limit`: every column
  ! that long and the steps increasing. problem: why the file cannot be continued ('' if it can).
  ! Collective: rank 0's findings hold.
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
        exit
      end if
      keep = min(keep, int(dims(rank)))
    end do
    call problem_from_root(problem)
    if (len_trim(problem) > 0) return
    call from_root(keep)
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
      ! every rank extends every dataset together (HDF5's metadata calls are collective)
      if (dims(rank) /= keep) then
        dims(rank) = keep
        call h5dopen_f(file, trim(s%names(c)), dset, err)
        call h5dset_extent_f(dset, dims(1:rank), e)
        err = max(err, abs(e))
        call h5dclose_f(dset, e)
        err = max(err, abs(e))
        call h5_parallel_agree(err)
        if (err /= 0) call write_failed(s, trim(s%path)//'.tmp', 'column '//trim(s%names(c))//' cannot be cut back')
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

  ! The step column of an open file whose columns must be this run's. Collective: rank 0's steps
  ! and problem hold on every rank.
  subroutine read_steps(s, file, steps, problem)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    integer, allocatable, intent(out) :: steps(:)
    character(len=*), intent(out) :: problem
    integer(HID_T) :: dset, space
    integer(HSIZE_T) :: dims(1), maxdims(1)
    integer :: c, err, n
    PetscErrorCode :: ierr
    problem = ''
    n = 0
    do c = 1, size(s%names)
      if (.not. has_object(file, trim(s%names(c)))) then
        problem = 'it does not hold the column '//trim(s%names(c))//' of this run'
        exit
      end if
    end do
    if (len_trim(problem) == 0) then
      call h5dopen_f(file, 'step', dset, err)
      call h5dget_space_f(dset, space, err)
      call h5sget_simple_extent_dims_f(space, dims, maxdims, err)
      call h5sclose_f(space, err)
      n = int(dims(1))
      allocate(steps(n))
      if (n > 0) call h5dread_f(dset, H5T_NATIVE_INTEGER, steps, dims, err)
      call h5dclose_f(dset, err)
      if (err /= 0) problem = 'its step column cannot be read'
    end if
    call problem_from_root(problem)
    call from_root(n)
    if (allocated(steps)) then
      if (size(steps) /= n) deallocate(steps)
    end if
    if (.not. allocated(steps)) allocate(steps(n))
    if (n > 0) then
      PetscCallMPIA(MPI_Bcast(steps, n, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr))
    end if
  end subroutine read_steps

  ! Records i0.. of every column of a file open on every rank (by itself: each rank reads its
  ! share independently): scalars(value, record) of the other columns (rank 0's), dense(value,
  ! sphere, record) of the per-sphere ones for this rank's range of spheres. Collective (a failure
  ! is agreed once, at the end).
  subroutine read_records(s, file, name, i0, scalars, dense)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: name
    integer, intent(in) :: i0
    real(dp), intent(out) :: scalars(:, :), dense(:, :, :)
    integer(HID_T) :: dset
    integer(HSIZE_T) :: offset(4), count(4)
    integer :: c, rank, err, e, w, failed
    logical :: selected
    real(dp), allocatable :: values(:)
    scalars = 0.0_dp
    dense = 0.0_dp
    failed = 0
    do c = 1, size(s%names)
      call box(s, c, i0 - 1, size(scalars, 2), rank, offset, count, selected)
      if (.not. selected) cycle
      allocate(values(product(count(1:rank))))
      call h5dopen_f(file, trim(s%names(c)), dset, err)
      call transfer(dset, .false., .false., selected, offset(1:rank), count(1:rank), values, e)
      err = max(err, abs(e))
      call h5dclose_f(dset, e)
      if (err /= 0 .and. failed == 0) failed = c
      w = s%width(c)
      if (selected .and. s%per_sphere(c)) then
        dense(s%first(c):s%first(c) + w - 1, :, :) = reshape(values, [w, size(dense, 2), size(dense, 3)])
      else if (selected) then
        scalars(s%first(c):s%first(c) + w - 1, :) = reshape(values, [w, size(scalars, 2)])
      end if
      deallocate(values)
    end do
    ! the largest failing column of any rank
    call h5_parallel_agree(failed)
    if (failed /= 0) call abort_if_any(.true., 'cannot read '//trim(s%names(failed))//' from '//trim(name))
  end subroutine read_records

  ! Append records to every column of a file open on every rank: scalars(value, record) of the
  ! other columns from rank 0; the per-sphere ones from every rank for its range of spheres, either
  ! dense(value, sphere, record), or rows(:, j) the values of the sphere and record place(:, j)
  ! (records record0 + 1 .. record0 + size(scalars, 2) taken, the others not). Collective.
  subroutine append_records(s, file, filename, scalars, dense, rows, place, record0)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: filename
    real(dp), intent(in) :: scalars(:, :)
    real(dp), intent(in), optional :: dense(:, :, :), rows(:, :)
    integer, intent(in), optional :: place(:, :), record0
    integer(HID_T) :: dset, fspace
    integer(HSIZE_T) :: dims(4), maxdims(4), offset(4), count(4)
    integer :: err, e, c, rank, w, n, m, j, i, r
    logical :: selected
    real(dp), allocatable :: values(:)
    n = size(scalars, 2)
    m = s%sphere_hi - s%sphere_lo + 1
    do c = 1, size(s%names)
      rank = column_rank(s%shapes(:, c))
      call h5dopen_f(file, trim(s%names(c)), dset, err)
      call h5dget_space_f(dset, fspace, e)
      err = max(err, abs(e))
      call h5sget_simple_extent_dims_f(fspace, dims(1:rank), maxdims(1:rank), e)
      call h5sclose_f(fspace, e)
      call box(s, c, int(dims(rank)), n, rank, offset, count, selected)
      dims(rank) = dims(rank) + n
      call h5dset_extent_f(dset, dims(1:rank), e)
      err = max(err, abs(e))
      w = s%width(c)
      if (s%per_sphere(c) .and. present(dense)) then
        values = reshape(dense(s%first(c):s%first(c) + w - 1, :, :), [w * size(dense, 2) * size(dense, 3)])
      else if (s%per_sphere(c)) then
        ! in the box's order (value, sphere, record)
        if (allocated(values)) deallocate(values)
        allocate(values(w * m * n))
        do j = 1, size(place, 2)
          r = place(2, j) - record0
          if (r < 1 .or. r > n) cycle
          i = (int(r - 1) * m + place(1, j) - s%sphere_lo) * w
          values(i + 1:i + w) = rows(s%first(c):s%first(c) + w - 1, j)
        end do
      else
        values = reshape(scalars(s%first(c):s%first(c) + w - 1, :), [w * n])
      end if
      if (size(values) == 0) values = [0.0_dp]
      ! one rank alone moves every value by itself; several move the per-sphere boxes together
      call transfer(dset, .true., s%per_sphere(c) .and. .not. s%alone, selected, offset(1:rank), count(1:rank), values, e)
      err = max(err, abs(e))
      ! closing writes the dataset's cached chunks: a full disk may show only here
      call h5dclose_f(dset, e)
      err = max(err, abs(e))
      call h5_parallel_agree(err)
      if (err /= 0) call write_failed(s, filename, 'cannot take the records of '//trim(s%names(c)))
    end do
  end subroutine append_records

  ! What this rank moves of column c for `records` records from record0 (0-based) on: the box
  ! offset(1:rank), count(1:rank) of the dataset (records last); selected: whether it moves any
  ! (rank 0 the other columns, each rank its range of spheres of the per-sphere ones).
  subroutine box(s, c, record0, records, rank, offset, count, selected)
    type(series_t), intent(in) :: s
    integer, intent(in) :: c, record0, records
    integer, intent(out) :: rank
    integer(HSIZE_T), intent(out) :: offset(4), count(4)
    logical, intent(out) :: selected
    rank = column_rank(s%shapes(:, c))
    offset = 0
    count = 0
    count(1:rank - 1) = s%shapes(1:rank - 1, c)
    offset(rank) = record0
    count(rank) = records
    if (s%per_sphere(c)) then
      offset(rank - 1) = s%sphere_lo - 1
      count(rank - 1) = s%sphere_hi - s%sphere_lo + 1
      selected = s%sphere_hi >= s%sphere_lo
    else
      selected = is_root()
    end if
    selected = selected .and. records > 0
  end subroutine box

  ! One transfer (writing, else reading) between values and the box offset, count of the dataset
  ! dset. collective: every rank takes part, a rank not selected moving nothing (the per-sphere
  ! columns); else the selected rank alone moves its values (rank 0 the other columns: a collective
  ! call per column would cost more than their few values). values are doubles (the step column,
  ! an integer dataset, is converted by HDF5, exactly).
  subroutine transfer(dset, writing, collective, selected, offset, count, values, err)
    integer(HID_T), intent(in) :: dset
    logical, intent(in) :: writing, collective, selected
    integer(HSIZE_T), intent(in) :: offset(:), count(:)
    real(dp), intent(inout) :: values(:)
    integer, intent(out) :: err
    integer(HID_T) :: file_space, memory_space, dxpl
    integer(HSIZE_T) :: n(1)
    integer :: e
    err = 0
    if (.not. (collective .or. selected)) return
    n(1) = size(values, kind=HSIZE_T)
    call h5dget_space_f(dset, file_space, err)
    call h5screate_simple_f(1, n, memory_space, e)
    err = max(err, abs(e))
    if (selected) then
      call h5sselect_hyperslab_f(file_space, H5S_SELECT_SET_F, offset, count, e)
    else
      call h5sselect_none_f(file_space, e)
      if (e == 0) call h5sselect_none_f(memory_space, e)
    end if
    err = max(err, abs(e))
    call h5pcreate_f(H5P_DATASET_XFER_F, dxpl, e)
    err = max(err, abs(e))
    if (collective) call h5pset_dxpl_mpio_f(dxpl, H5FD_MPIO_COLLECTIVE_F, e)
    err = max(err, abs(e))
    ! a rank whose selections failed still takes part (selecting nothing), so that a collective
    ! transfer completes on every rank; the failure is agreed by the caller
    if (err /= 0) then
      call h5sselect_none_f(file_space, e)
      call h5sselect_none_f(memory_space, e)
    end if
    if (writing) then
      call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, values, n, e, memory_space, file_space, dxpl)
    else
      call h5dread_f(dset, H5T_NATIVE_DOUBLE, values, n, e, memory_space, file_space, dxpl)
    end if
    err = max(err, abs(e))
    call h5pclose_f(dxpl, e)
    call h5sclose_f(memory_space, e)
    call h5sclose_f(file_space, e)
  end subroutine transfer

  ! Create a file with the series' columns (no records) and its attributes, open on every rank.
  ! Collective.
  subroutine create_file(s, name, file)
    type(series_t), intent(in) :: s
    character(len=*), intent(in) :: name
    integer(HID_T), intent(out) :: file
    integer :: err, c
    call h5_parallel_create(trim(name), file, err, serial_alone=.true.)
    if (err /= 0) call write_failed(s, name, 'cannot be created')
    do c = 1, size(s%names)
      call create_column(s, file, name, trim(s%names(c)), c == 1, s%shapes(:, c))
    end do
    call write_attributes(s, file, name)
  end subroutine create_file

  ! The root attributes, written by every rank with the same values. Collective.
  subroutine write_attributes(s, file, name)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: name
    integer :: k, err
    do k = 1, size(s%attribute_names)
      call write_attribute(file, trim(s%attribute_names(k)), s%attribute_values(k:k), err)
      call h5_parallel_agree(err)
      if (err /= 0) call write_failed(s, name, 'its attribute '//trim(s%attribute_names(k))//' cannot be written')
    end do
  end subroutine write_attributes

  ! Close a file the series wrote; closing writes HDF5's metadata, so it can fail as a write can.
  ! Collective.
  subroutine close_file(s, file, name)
    type(series_t), intent(in) :: s
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: name
    integer :: err
    call h5_parallel_close(file, err)
    if (err /= 0) call write_failed(s, name, 'cannot be completed (closing it failed)')
  end subroutine close_file

  ! A write of the series failed (agreed by every rank): stop the run, naming the file and the
  ! cause, one message from rank 0. What the series published before is whole (nothing published is
  ! modified in place). Collective.
  subroutine write_failed(s, name, what)
    type(series_t), intent(in) :: s
    character(len=*), intent(in) :: name, what
    integer :: err
    real(dp) :: needed
    ! a partial .tmp would only hold space the user needs back; what it was to replace is whole
    if (index(name, '.tmp', back=.true.) == len_trim(name) - 3) then
      if (is_root()) err = remove_file(name)
    end if
    needed = 8.0_dp * s%record_length * max(1, s%nbuf)
    call abort_if_any(.true., trim(name)//' '//what//': '//write_failure_cause(directory_of(s%path), needed)// &
         '; the records published before, and the last checkpoint, are kept')
  end subroutine write_failed
  ! Move a file the series cannot use aside with a warning (rank 0): NAME.damaged (.damaged-2, ...) when it
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

  ! Partial files of a killed write: series.h5.tmp and the .tmp files of series.parts (rank 0).
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

  ! Collective: every rank makes the same calls.
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
    call h5pset_fill_time_f(plist, H5D_FILL_TIME_NEVER_F, e)
    err = max(err, abs(e))
    call h5dcreate_f(file, name, dtype, space, dset, e, plist)
    err = max(err, abs(e))
    call h5dclose_f(dset, e)
    err = max(err, abs(e))
    call h5pclose_f(plist, e)
    call h5sclose_f(space, e)
    call h5_parallel_agree(err)
    if (err /= 0) call write_failed(s, filename, 'cannot hold the dataset '//name)
  end subroutine create_column


end module mod_series
