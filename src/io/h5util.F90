! Small helpers over HDF5's Fortran API: attributes, and 2-D datasets written whole and read back
! with their shape checked (particles, contact history). The datasets carry HDF5's Fletcher-32
! checksum, so a damaged file fails its read instead of being used.
! Used by one rank at a time (series.h5 and checkpoint attributes are written by rank 0);
! parallel field I/O goes through PETSc's HDF5 viewer instead.
module mod_h5util
  use hdf5
  use mod_kinds, only: dp
  implicit none
  private
  public :: h5util_init, write_attribute, read_attribute, has_attribute, has_object
  public :: write_string_attribute, read_string_attribute, write_dataset, read_dataset, dataset_dims, read_values, &
            checked_chunk
  public :: HID_T, HSIZE_T

  interface write_attribute
    module procedure write_attr_real, write_attr_int
  end interface write_attribute
  interface read_attribute
    module procedure read_attr_real, read_attr_int
  end interface read_attribute
  interface write_dataset
    module procedure write_dataset_real, write_dataset_int
  end interface write_dataset
  interface read_dataset
    module procedure read_dataset_real, read_dataset_int
  end interface read_dataset

contains

  ! Open the library and silence its error stack: fdsusp reports failures itself.
  subroutine h5util_init()
    integer :: err
    call h5open_f(err)
    call h5eset_auto_f(0, err)
  end subroutine h5util_init

  subroutine write_attr_real(loc, name, values, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: values(:)
    integer, intent(out) :: err
    integer(HID_T) :: space, attr
    integer(HSIZE_T) :: dims(1)
    dims(1) = size(values)
    if (has_attribute(loc, name)) call h5adelete_f(loc, name, err)   ! an attribute is replaced
    call h5screate_simple_f(1, dims, space, err)
    if (err /= 0) return
    call h5acreate_f(loc, name, H5T_NATIVE_DOUBLE, space, attr, err)
    if (err == 0) then
      call h5awrite_f(attr, H5T_NATIVE_DOUBLE, values, dims, err)
      call h5aclose_f(attr, err)
    end if
    call h5sclose_f(space, err)
  end subroutine write_attr_real

  subroutine write_attr_int(loc, name, values, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: values(:)
    integer, intent(out) :: err
    integer(HID_T) :: space, attr
    integer(HSIZE_T) :: dims(1)
    dims(1) = size(values)
    if (has_attribute(loc, name)) call h5adelete_f(loc, name, err)   ! an attribute is replaced
    call h5screate_simple_f(1, dims, space, err)
    if (err /= 0) return
    call h5acreate_f(loc, name, H5T_NATIVE_INTEGER, space, attr, err)
    if (err == 0) then
      call h5awrite_f(attr, H5T_NATIVE_INTEGER, values, dims, err)
      call h5aclose_f(attr, err)
    end if
    call h5sclose_f(space, err)
  end subroutine write_attr_int

  subroutine write_string_attribute(loc, name, text, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name, text
    integer, intent(out) :: err
    integer(HID_T) :: space, attr, strtype
    integer(HSIZE_T) :: dims(1)
    character(len=max(1, len_trim(text))) :: stored      ! '' is stored as one blank
    stored = text
    dims(1) = 1
    call h5tcopy_f(H5T_FORTRAN_S1, strtype, err)
    call h5tset_size_f(strtype, int(len(stored), kind=8), err)
    call h5screate_f(H5S_SCALAR_F, space, err)
    call h5acreate_f(loc, name, strtype, space, attr, err)
    if (err == 0) then
      call h5awrite_f(attr, strtype, stored, dims, err)
      call h5aclose_f(attr, err)
    end if
    call h5sclose_f(space, err)
    call h5tclose_f(strtype, err)
  end subroutine write_string_attribute

  ! A fixed-length string attribute (write_string_attribute) into text, blank-padded; err /= 0 if
  ! it is absent, not a fixed-length string or longer than text.
  subroutine read_string_attribute(loc, name, text, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    character(len=*), intent(out) :: text
    integer, intent(out) :: err
    integer(HID_T) :: attr, ftype, mtype
    integer(SIZE_T) :: length
    integer(HSIZE_T) :: dims(1)
    integer :: class, e, k
    text = ''
    call h5aopen_f(loc, name, attr, err)
    if (err /= 0) return
    call h5aget_type_f(attr, ftype, err)
    call h5tget_class_f(ftype, class, e)
    call h5tget_size_f(ftype, length, e)
    call h5tclose_f(ftype, e)
    if (err /= 0 .or. class /= H5T_STRING_F .or. length > len(text) .or. length < 1) then
      err = -1
    else
      dims(1) = 1
      call h5tcopy_f(H5T_FORTRAN_S1, mtype, err)
      call h5tset_size_f(mtype, length, e)
      call h5aread_f(attr, mtype, text(1:length), dims, err)
      call h5tclose_f(mtype, e)
      do k = 1, int(length)
        if (text(k:k) == achar(0)) text(k:k) = ' '
      end do
    end if
    call h5aclose_f(attr, e)
  end subroutine read_string_attribute

  logical function has_attribute(loc, name)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer :: err
    call h5aexists_f(loc, name, has_attribute, err)
    if (err /= 0) has_attribute = .false.
  end function has_attribute

  logical function has_object(loc, name)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer :: err
    call h5lexists_f(loc, name, has_object, err)
    if (err /= 0) has_object = .false.
  end function has_object

  ! Read an attribute of exactly size(values) elements; err /= 0 if absent or of another size.
  subroutine read_attr_real(loc, name, values, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(out) :: values(:)
    integer, intent(out) :: err
    integer(HID_T) :: attr, space
    integer(HSIZE_T) :: dims(1), npoints
    integer :: e2
    call h5aopen_f(loc, name, attr, err)
    if (err /= 0) return
    call h5aget_space_f(attr, space, err)
    call h5sget_simple_extent_npoints_f(space, npoints, err)
    call h5sclose_f(space, e2)
    if (npoints /= size(values)) then
      err = -1
    else
      dims(1) = size(values)
      call h5aread_f(attr, H5T_NATIVE_DOUBLE, values, dims, err)
    end if
    call h5aclose_f(attr, e2)
  end subroutine read_attr_real

  subroutine read_attr_int(loc, name, values, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(out) :: values(:)
    integer, intent(out) :: err
    integer(HID_T) :: attr, space
    integer(HSIZE_T) :: dims(1), npoints
    integer :: e2
    call h5aopen_f(loc, name, attr, err)
    if (err /= 0) return
    call h5aget_space_f(attr, space, err)
    call h5sget_simple_extent_npoints_f(space, npoints, err)
    call h5sclose_f(space, e2)
    if (npoints /= size(values)) then
      err = -1
    else
      dims(1) = size(values)
      call h5aread_f(attr, H5T_NATIVE_INTEGER, values, dims, err)
    end if
    call h5aclose_f(attr, e2)
  end subroutine read_attr_int

  ! A whole 2-D dataset (Fortran shape (m, n); C and Python see n x m). err /= 0 on failure.
  subroutine write_dataset_real(loc, name, values, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: values(:, :)
    integer, intent(out) :: err
    call write_dataset_2d(loc, name, H5T_NATIVE_DOUBLE, shape(values, kind=HSIZE_T), err, real_values=values)
  end subroutine write_dataset_real

  subroutine write_dataset_int(loc, name, values, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: values(:, :)
    integer, intent(out) :: err
    call write_dataset_2d(loc, name, H5T_NATIVE_INTEGER, shape(values, kind=HSIZE_T), err, int_values=values)
  end subroutine write_dataset_int

  !> The chunk of a (k, n) dataset with Fletcher-32 (k values a column: a sphere's, a spring's):
  !> whole columns, at most 2^16 values, so that a read of a range of columns decodes only the
  !> chunks it touches. One chunk of the whole dataset made a reader that goes through it in
  !> blocks (the checksums' walk, 2^16 values a block) decode all of it for every block once it
  !> outgrew HDF5's chunk cache (1 MiB): quadratic in the spheres (doc/BENCHMARKS.md §25).
  pure function checked_chunk(dims) result(chunk)
    integer(HSIZE_T), intent(in) :: dims(2)
    integer(HSIZE_T) :: chunk(2)
    chunk = [dims(1), max(1_HSIZE_T, min(dims(2), 2_HSIZE_T**16 / max(1_HSIZE_T, dims(1))))]
  end function checked_chunk

  subroutine write_dataset_2d(loc, name, dtype, dims, err, real_values, int_values)
    integer(HID_T), intent(in) :: loc, dtype
    character(len=*), intent(in) :: name
    integer(HSIZE_T), intent(in) :: dims(2)
    integer, intent(out) :: err
    real(dp), intent(in), optional :: real_values(:, :)
    integer, intent(in), optional :: int_values(:, :)
    integer(HID_T) :: space, dset, plist
    integer :: e
    call h5screate_simple_f(2, dims, space, err)
    if (err /= 0) return
    ! chunks with HDF5's Fletcher-32 checksum, which every read verifies (a dataset of no
    ! elements has no data to protect, and cannot be chunked)
    call h5pcreate_f(H5P_DATASET_CREATE_F, plist, err)
    if (err == 0 .and. all(dims > 0)) then
      call h5pset_chunk_f(plist, 2, checked_chunk(dims), err)
      if (err == 0) call h5pset_fletcher32_f(plist, err)
    end if
    if (err == 0) call h5dcreate_f(loc, name, dtype, space, dset, err, plist)
    call h5pclose_f(plist, e)
    if (err == 0) then
      if (present(real_values)) call h5dwrite_f(dset, dtype, real_values, dims, err)
      if (present(int_values)) call h5dwrite_f(dset, dtype, int_values, dims, err)
      call h5dclose_f(dset, e)
      if (err == 0) err = e
    end if
    call h5sclose_f(space, e)
  end subroutine write_dataset_2d

  ! Rank and (Fortran-order) dimensions of dataset name; rank 0 when it does not exist.
  subroutine dataset_dims(loc, name, rank, dims)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(out) :: rank
    integer(HSIZE_T), intent(out) :: dims(2)
    integer(HID_T) :: dset, space
    integer(HSIZE_T) :: maxdims(2)
    integer :: err
    rank = 0
    dims = 0
    if (.not. has_object(loc, name)) return
    call h5dopen_f(loc, name, dset, err)
    if (err /= 0) return
    call h5dget_space_f(dset, space, err)
    call h5sget_simple_extent_ndims_f(space, rank, err)
    if (rank == 1 .or. rank == 2) call h5sget_simple_extent_dims_f(space, dims, maxdims, err)
    call h5sclose_f(space, err)
    call h5dclose_f(dset, err)
  end subroutine dataset_dims

  ! Read a whole 2-D dataset into values; err /= 0 when it is missing, not 2-D, of another shape
  ! than values, or unreadable.
  subroutine read_dataset_real(loc, name, values, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(out) :: values(:, :)
    integer, intent(out) :: err
    call read_dataset_2d(loc, name, H5T_NATIVE_DOUBLE, shape(values, kind=HSIZE_T), err, real_values=values)
  end subroutine read_dataset_real

  subroutine read_dataset_int(loc, name, values, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(out) :: values(:, :)
    integer, intent(out) :: err
    call read_dataset_2d(loc, name, H5T_NATIVE_INTEGER, shape(values, kind=HSIZE_T), err, int_values=values)
  end subroutine read_dataset_int

  ! The values of a dataset of rank 1 or 2 holding size(values) numbers, whatever its shape (a
  ! list written by h5py as (N), by Fortran as 1 x N): err /= 0 when it holds another count.
  subroutine read_values(loc, name, values, err)
    integer(HID_T), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(out) :: values(:)
    integer, intent(out) :: err
    integer(HID_T) :: dset
    integer(HSIZE_T) :: found(2)
    integer :: rank, e
    err = 1
    call dataset_dims(loc, name, rank, found)
    if (rank == 1) found(2) = 1
    if (rank < 1 .or. found(1) * found(2) /= size(values, kind=HSIZE_T)) return
    call h5dopen_f(loc, name, dset, err)
    if (err /= 0) return
    call h5dread_f(dset, H5T_NATIVE_DOUBLE, values, [size(values, kind=HSIZE_T)], err)
    call h5dclose_f(dset, e)
  end subroutine read_values

  subroutine read_dataset_2d(loc, name, dtype, dims, err, real_values, int_values)
    integer(HID_T), intent(in) :: loc, dtype
    character(len=*), intent(in) :: name
    integer(HSIZE_T), intent(in) :: dims(2)
    integer, intent(out) :: err
    real(dp), intent(out), optional :: real_values(:, :)
    integer, intent(out), optional :: int_values(:, :)
    integer(HID_T) :: dset
    integer(HSIZE_T) :: found(2)
    integer :: rank, e
    err = 1
    call dataset_dims(loc, name, rank, found)
    if (rank /= 2 .or. any(found /= dims)) return
    call h5dopen_f(loc, name, dset, err)
    if (err /= 0) return
    if (present(real_values)) call h5dread_f(dset, dtype, real_values, dims, err)
    if (present(int_values)) call h5dread_f(dset, dtype, int_values, dims, err)
    call h5dclose_f(dset, e)
  end subroutine read_dataset_2d

end module mod_h5util
