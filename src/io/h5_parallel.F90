! Parallel HDF5 (MPI-IO) for the files every rank writes together (doc/DESIGN.md "Files", issue 45):
! open or create a file collectively, and write a (k, N) dataset of doubles (or integers), one
! column per sphere (or contact), from the columns each rank owns, given their global indices (any
! set: a rank with none takes part all the same). The dataset is the one write_dataset_2d
! (mod_h5util) makes: chunks of at most 2^16 values (checked_chunk) with HDF5's Fletcher-32
! checksum. HDF5 1.10.2 and later (Debian bookworm has 1.10.8) write filtered datasets in
! parallel, collectively only: every transfer here is collective (H5FD_MPIO_COLLECTIVE), and the
! ranks send their columns to the rank that owns each chunk, which filters and writes it.
! Every call is collective and returns an err agreed by all ranks (the largest): a failure seen by
! one rank is seen by every rank, so that no rank waits in the next collective call for ever.
! In parallel HDF5 every rank must make the same metadata calls (groups, datasets, attributes)
! with the same values: the callers make them on every rank with the replicated values.
! serial_alone (create, open): on a run of one rank the file goes through HDF5's default (sec2)
! driver instead: the same file for a reader, without MPI-IO's cost per call (series.h5's flushes,
! doc/BENCHMARKS.md §20). Only for a caller whose transfers do not ask for MPI-IO (mod_series;
! h5_parallel_write_columns always does).
#include <petsc/finclude/petscsys.h>
module mod_h5_parallel
  use hdf5
  use petscsys
  use, intrinsic :: iso_c_binding, only: c_loc, c_ptr
  use mod_kinds, only: dp
  use mod_sorting, only: ascending_order
  use mod_h5util, only: checked_chunk
  implicit none
  private
  public :: h5_parallel_create, h5_parallel_open, h5_parallel_close, h5_parallel_write_columns, &
            h5_parallel_write_int_columns, h5_parallel_agree

  ! the most runs of consecutive columns selected as a union of hyperslabs (more: element by
  ! element; h5_parallel_write_columns): few enough that both ways serve in the tests'
  ! small scenes (tests/regression/test_particles_parallel_io.py: 2 to 6 runs a rank)
  integer, parameter :: max_hyperslabs = 4

contains

  !> Create (truncate) the file PATH for every rank through MPI-IO on PETSC_COMM_WORLD (see
  !> serial_alone above). Collective.
  subroutine h5_parallel_create(path, file, err, serial_alone)
    character(len=*), intent(in) :: path
    integer(HID_T), intent(out) :: file
    integer, intent(out) :: err
    logical, intent(in), optional :: serial_alone
    integer(HID_T) :: fapl
    call mpio_access(fapl, err, serial_alone)
    if (err == 0) call h5fcreate_f(path, H5F_ACC_TRUNC_F, file, err, access_prp=fapl)
    call close_plist(fapl)
    call h5_parallel_agree(err)
  end subroutine h5_parallel_create

  !> Open the existing file PATH read-write (read_only: read only) for every rank through MPI-IO
  !> (see serial_alone above). Collective.
  subroutine h5_parallel_open(path, file, err, read_only, serial_alone)
    character(len=*), intent(in) :: path
    integer(HID_T), intent(out) :: file
    integer, intent(out) :: err
    logical, intent(in), optional :: read_only, serial_alone
    integer(HID_T) :: fapl
    integer :: mode
    mode = H5F_ACC_RDWR_F
    if (present(read_only)) then
      if (read_only) mode = H5F_ACC_RDONLY_F
    end if
    call mpio_access(fapl, err, serial_alone)
    if (err == 0) call h5fopen_f(path, mode, file, err, access_prp=fapl)
    call close_plist(fapl)
    call h5_parallel_agree(err)
  end subroutine h5_parallel_open

  !> Close a file opened by h5_parallel_create or h5_parallel_open (its metadata are written
  !> now). Collective.
  subroutine h5_parallel_close(file, err)
    integer(HID_T), intent(in) :: file
    integer, intent(out) :: err
    call h5fclose_f(file, err)
    call h5_parallel_agree(err)
  end subroutine h5_parallel_close

  !> The dataset NAME (k, n) in LOC, of doubles, chunks with Fletcher-32 (as mod_h5util's
  !> write_dataset): this rank writes its columns values(:, j) into the file's columns
  !> columns(j) (1-based global indices, unique over all ranks, in any order; none: size 0), in
  !> one collective transfer. Collective; every rank passes the same name, k and n.
  subroutine h5_parallel_write_columns(loc, name, n, columns, values, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: n
    integer, intent(in) :: columns(:)
    real(dp), intent(in) :: values(:, :)
    integer, intent(out) :: err
    integer, allocatable :: order(:)
    real(dp), allocatable, target :: buffer(:, :)
    ! (the columns by ascending index, the order HDF5 transfers them in)
    order = ascending_order(columns)
    allocate(buffer(size(values, 1), max(1, size(columns))))
    buffer = 0.0_dp
    if (size(columns) > 0) buffer(:, 1:size(columns)) = values(:, order)
    call write_sorted_columns(loc, name, n, columns(order), size(values, 1), H5T_NATIVE_DOUBLE, c_loc(buffer), err)
  end subroutine h5_parallel_write_columns

  !> As h5_parallel_write_columns, for a dataset of integers (the contacts' pairs).
  subroutine h5_parallel_write_int_columns(loc, name, n, columns, values, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: n
    integer, intent(in) :: columns(:)
    integer, intent(in) :: values(:, :)
    integer, intent(out) :: err
    integer, allocatable :: order(:)
    integer, allocatable, target :: buffer(:, :)
    order = ascending_order(columns)
    allocate(buffer(size(values, 1), max(1, size(columns))))
    buffer = 0
    if (size(columns) > 0) buffer(:, 1:size(columns)) = values(:, order)
    call write_sorted_columns(loc, name, n, columns(order), size(values, 1), H5T_NATIVE_INTEGER, c_loc(buffer), err)
  end subroutine h5_parallel_write_int_columns

  ! The dataset NAME (k, n) of type dtype: this rank's columns, ascending, from the buffer at data
  ! (k values a column, in the same order; at least one column's room). Collective.
  subroutine write_sorted_columns(loc, name, n, columns, k, dtype, data, err)
    integer(HID_T), intent(in) :: loc, dtype
    character(len=*), intent(in) :: name
    integer, intent(in) :: n, k
    integer, intent(in) :: columns(:)
    type(c_ptr), intent(in) :: data
    integer, intent(out) :: err
    integer(HID_T) :: file_space, memory_space, dcpl, dxpl, dset
    integer(HSIZE_T) :: dims(2)
    integer :: e, m, j, c, first, runs
    integer(HSIZE_T), allocatable :: points(:, :)

    m = size(columns)
    dims = [int(k, HSIZE_T), int(n, HSIZE_T)]
    dset = -1
    call h5screate_simple_f(2, dims, file_space, err)
    ! chunks with Fletcher-32, as a dataset of mod_h5util (a dataset of no elements cannot be
    ! chunked); HDF5 allocates the chunks of a parallel file when the dataset is created, and a
    ! collective write gathers each chunk on one rank, which filters and writes it
    call h5pcreate_f(H5P_DATASET_CREATE_F, dcpl, e)
    err = max(err, abs(e))
    if (err == 0 .and. all(dims > 0)) then
      call h5pset_chunk_f(dcpl, 2, checked_chunk(dims), err)
      if (err == 0) call h5pset_fletcher32_f(dcpl, err)
    end if
    if (err == 0) call h5dcreate_f(loc, name, dtype, file_space, dset, err, dcpl)
    call close_plist(dcpl)
    call h5_parallel_agree(err)
    if (err /= 0) then
      if (dset >= 0) call h5dclose_f(dset, e)
      call h5sclose_f(file_space, e)
      return
    end if

    ! the file's columns of this rank, selected as a union of hyperslabs (one per run of
    ! consecutive indices) when the runs are few, else element by element: HDF5 1.10's union of
    ! hyperslabs costs about quadratically in the runs (1934 spheres in z-slabs on 2 ranks, ~970
    ! runs a rank: 72 ms a step of a checkpoint and a snapshot, by elements 16 ms;
    ! doc/BENCHMARKS.md §19), while the elements cost in proportion to the values (all spheres on
    ! one rank, 1 run: 21 ms a step by elements, 13 ms by one hyperslab).
    runs = 0
    do j = 1, m
      if (j == 1) then
        runs = 1
      else if (columns(j) /= columns(j - 1) + 1) then
        runs = runs + 1
      end if
    end do
    call h5sselect_none_f(file_space, err)
    if (runs > max_hyperslabs) then
      allocate(points(2, k * m))
      do j = 1, m
        do c = 1, k
          points(:, (j - 1) * k + c) = [int(c, HSIZE_T), int(columns(j), HSIZE_T)]
        end do
      end do
      call h5sselect_elements_f(file_space, H5S_SELECT_SET_F, 2, size(points, 2, kind=SIZE_T), points, err)
    else
      first = 1
      do j = 1, m
        if (err /= 0) exit
        if (j < m) then
          if (columns(j + 1) == columns(j) + 1) cycle
        end if
        ! the run columns(first:j)
        call h5sselect_hyperslab_f(file_space, H5S_SELECT_OR_F, [0_HSIZE_T, int(columns(first) - 1, HSIZE_T)], &
                                   [dims(1), int(j - first + 1, HSIZE_T)], err)
        first = j + 1
      end do
    end if
    call h5screate_simple_f(1, [int(k, HSIZE_T) * max(1, m)], memory_space, e)
    err = max(err, abs(e))
    if (m == 0) call h5sselect_none_f(memory_space, e)
    err = max(err, abs(e))
    call h5pcreate_f(H5P_DATASET_XFER_F, dxpl, e)
    err = max(err, abs(e))
    call h5pset_dxpl_mpio_f(dxpl, H5FD_MPIO_COLLECTIVE_F, e)
    err = max(err, abs(e))
    ! a rank whose selections failed still takes part (selecting nothing), so that the
    ! collective transfer completes on every rank; the failure is agreed after it
    if (err /= 0) then
      call h5sselect_none_f(file_space, e)
      call h5sselect_none_f(memory_space, e)
    end if
    call h5dwrite_f(dset, dtype, data, e, mem_space_id=memory_space, file_space_id=file_space, xfer_prp=dxpl)
    err = max(err, abs(e))
    call close_plist(dxpl)
    call h5sclose_f(memory_space, e)
    call h5sclose_f(file_space, e)
    call h5dclose_f(dset, e)
    err = max(err, abs(e))
    call h5_parallel_agree(err)
  end subroutine write_sorted_columns

  !> err becomes the largest of all ranks' (0 when no rank failed). Collective.
  subroutine h5_parallel_agree(err)
    integer, intent(inout) :: err
    integer :: mine
    PetscErrorCode :: ierr
    mine = abs(err)
    call MPI_Allreduce(mine, err, 1, MPI_INTEGER, MPI_MAX, PETSC_COMM_WORLD, ierr)
    if (ierr /= 0) err = max(1, mine)
  end subroutine h5_parallel_agree

  ! A file access list for MPI-IO on PETSC_COMM_WORLD; with serial_alone on one rank, HDF5's
  ! default driver.
  subroutine mpio_access(fapl, err, serial_alone)
    integer(HID_T), intent(out) :: fapl
    integer, intent(out) :: err
    logical, intent(in), optional :: serial_alone
    integer :: ranks
    PetscErrorCode :: ierr
    call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, err)
    if (err /= 0) return
    if (present(serial_alone)) then
      if (serial_alone) then
        call MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr)
        if (ierr /= 0) then
          err = 1
          return
        end if
        if (ranks == 1) return
      end if
    end if
    call h5pset_fapl_mpio_f(fapl, PETSC_COMM_WORLD, MPI_INFO_NULL, err)
  end subroutine mpio_access

  subroutine close_plist(plist)
    integer(HID_T), intent(in) :: plist
    integer :: e
    call h5pclose_f(plist, e)
  end subroutine close_plist

end module mod_h5_parallel
