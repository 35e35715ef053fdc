! The contact history in checkpoints (doc/CONTACT.md, "Checkpoint format"): the group /contacts
! with attributes np (particle count) and count (open contacts with a spring), and, when
! count > 0, the datasets ids (count x 2 integers as seen from C/Python: owner, partner; partner
! -1 / -2 is the lower / upper wall) and spring (count x 3 doubles: Upsilon in units of a), in
! the canonical order of history_pack. Written by rank 0 into the open checkpoint, or, when each
! rank holds the springs of its own spheres' pairs, by every rank through MPI-IO
! (contacts_write_shares: each rank a run of the rows); read by rank 0 and broadcast, every rank
! then unpacks the same history.
#include <petsc/finclude/petscsys.h>
module mod_contacts_io
  use hdf5
  use petscsys
  use mod_kinds, only: dp
  use mod_contact, only: contact_history_t, history_size, history_pack, history_unpack, history_clear
  use mod_sorting, only: sorted_position, ascending_order
  use mod_h5_parallel, only: h5_parallel_write_columns, h5_parallel_write_int_columns, h5_parallel_agree
  use mod_h5util, only: write_attribute, read_attribute, has_object, write_dataset, read_dataset
  use mod_errors, only: is_root, file_error, file_error_from_root, abort_run, warn_line
  implicit none
  private
  public :: contacts_write, contacts_write_shares, contacts_read

contains

  ! Write /contacts into an open file (rank 0 only). np: the particle count of the run (the
  ! history may be empty, np = 0, before the first contact).
  subroutine contacts_write(file, h, np)
    integer(HID_T), intent(in) :: file
    type(contact_history_t), intent(in) :: h
    integer, intent(in) :: np
    integer(HID_T) :: group
    integer :: err, e(2), n, hnp
    integer, allocatable :: ids(:,:)
    real(dp), allocatable :: ups(:,:)
    n = history_size(h)
    allocate(ids(2, max(1, n)), ups(3, max(1, n)))
    call history_pack(h, hnp, ids, ups)
    call h5gcreate_f(file, 'contacts', group, err)
    if (err /= 0) call abort_run('cannot create the group /contacts')
    call write_attribute(group, 'np', [np], e(1))
    call write_attribute(group, 'count', [n], e(2))
    if (any(e /= 0)) call abort_run('cannot write the attributes of /contacts')
    if (n > 0) then
      call write_dataset(group, 'ids', ids(:, 1:n), err)
      if (err /= 0) call abort_run('cannot write /contacts/ids')
      call write_dataset(group, 'spring', ups(:, 1:n), err)
      if (err /= 0) call abort_run('cannot write /contacts/spring')
    end if
    call h5gclose_f(group, err)
  end subroutine contacts_write

  ! Write /contacts into a file open on every rank through MPI-IO (mod_h5_parallel), from h on each
  ! rank holding the springs of the pairs with one of its own spheres (a rank's local set,
  ! mod_ld_local: the global indices id of its spheres, ascending, which of them are its own, total
  ! spheres): the same group as contacts_write, in the same canonical order. Each pair is taken
  ! from the owner of its first sphere (so once) and sent to the rank that writes the range of
  ! first spheres it falls in (rank r: the first spheres of the r-th of P equal index ranges, one
  ! all-to-all, 5 values a spring), which sorts them and writes its run of rows, after the runs of
  ! the ranks before (an exclusive prefix sum of the counts). No rank holds every spring. message:
  ! '' or what failed, the same on every rank. Collective.
  subroutine contacts_write_shares(file, h, id, own, total, message)
    integer(HID_T), intent(in) :: file
    type(contact_history_t), intent(in) :: h
    integer, intent(in) :: id(:), total
    logical, intent(in) :: own(:)
    character(len=*), intent(out) :: message
    integer, allocatable :: keys(:, :), writer(:), send_count(:), recv_count(:), send_start(:), recv_start(:), &
                            order(:), rows(:), fill(:)
    real(dp), allocatable :: ups(:, :), send(:, :), received(:, :)
    integer :: n, np, k, i, p, ranks, first, count, err, e(2)
    integer(HID_T) :: group
    PetscErrorCode :: ierr, mpi_err(4)
    message = ''
    call MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr)
    n = history_size(h)
    allocate(keys(2, n), ups(3, n))
    if (n > 0) call history_pack(h, np, keys, ups)
    ! the springs of the pairs whose first sphere (never a wall) is own, and their writers
    allocate(writer(n))
    k = 0
    do i = 1, n
      p = sorted_position(id, keys(1, i))
      if (p == 0) cycle
      if (.not. own(p)) cycle
      k = k + 1
      keys(:, k) = keys(:, i)
      ups(:, k) = ups(:, i)
      writer(k) = int((int(keys(1, i) - 1, 8) * ranks) / total)
    end do
    allocate(send_count(ranks), recv_count(ranks), send_start(ranks), recv_start(ranks), fill(ranks))
    send_count = 0
    do i = 1, k
      send_count(writer(i) + 1) = send_count(writer(i) + 1) + 1
    end do
    send_start(1) = 0
    do p = 2, ranks
      send_start(p) = send_start(p - 1) + send_count(p - 1)
    end do
    allocate(send(5, k))
    fill = send_start
    do i = 1, k
      fill(writer(i) + 1) = fill(writer(i) + 1) + 1
      send(:, fill(writer(i) + 1)) = [real(keys(:, i), dp), ups(:, i)]
    end do
    call MPI_Alltoall(send_count, 1, MPI_INTEGER, recv_count, 1, MPI_INTEGER, PETSC_COMM_WORLD, mpi_err(1))
    recv_start(1) = 0
    do p = 2, ranks
      recv_start(p) = recv_start(p - 1) + recv_count(p - 1)
    end do
    allocate(received(5, sum(recv_count)))
    call MPI_Alltoallv(send, 5 * send_count, 5 * send_start, MPI_DOUBLE_PRECISION, received, 5 * recv_count, &
                       5 * recv_start, MPI_DOUBLE_PRECISION, PETSC_COMM_WORLD, mpi_err(2))
    ! this rank's run of rows: its springs in the canonical order (first sphere, then partner)
    deallocate(keys, ups)
    count = size(received, 2)
    keys = nint(received(1:2, :))
    order = ascending_order(keys(2, :))
    order = order(ascending_order(keys(1, order)))
    first = 0
    call MPI_Exscan(count, first, 1, MPI_INTEGER, MPI_SUM, PETSC_COMM_WORLD, mpi_err(3))
    call MPI_Comm_rank(PETSC_COMM_WORLD, p, ierr)
    if (p == 0) first = 0                  ! (MPI_Exscan leaves rank 0's undefined)
    rows = [(first + i, i = 1, count)]
    n = count
    call MPI_Allreduce(MPI_IN_PLACE, n, 1, MPI_INTEGER, MPI_SUM, PETSC_COMM_WORLD, mpi_err(4))
    err = maxval(abs(mpi_err))
    call h5_parallel_agree(err)
    if (err /= 0) then
      message = 'cannot take /contacts: the springs could not be sent to the ranks writing them (MPI)'
      return
    end if
    ! the group and its attributes on every rank alike (parallel HDF5's metadata), then the rows
    call h5gcreate_f(file, 'contacts', group, err)
    call h5_parallel_agree(err)
    if (err /= 0) then
      message = 'cannot take the group /contacts'
      return
    end if
    call write_attribute(group, 'np', [total], e(1))
    call write_attribute(group, 'count', [n], e(2))
    err = maxval(abs(e))
    call h5_parallel_agree(err)
    if (err /= 0) message = 'cannot write the attributes of /contacts'
    if (n > 0 .and. err == 0) then
      call h5_parallel_write_int_columns(group, 'ids', n, rows, keys(:, order), err)
      if (err /= 0) message = 'cannot take /contacts/ids'
      if (err == 0) call h5_parallel_write_columns(group, 'spring', n, rows, received(3:5, order), err)
      if (err /= 0 .and. len_trim(message) == 0) message = 'cannot take /contacts/spring'
    end if
    call h5gclose_f(group, err)
  end subroutine contacts_write_shares

  ! Restart: the history from the checkpoint PATH (collective). np: the particle count of the
  ! run. A checkpoint without /contacts (written by a run without contacts) gives an empty
  ! history and a warning; a damaged or inconsistent group stops the run.
  subroutine contacts_read(path, h, np)
    character(len=*), intent(in) :: path
    type(contact_history_t), intent(inout) :: h
    integer, intent(in) :: np
    integer(HID_T) :: file, group
    integer :: err, ierr, info, a(1), meta(3)
    integer, allocatable :: ids(:,:)
    real(dp), allocatable :: ups(:,:)
    character(len=200) :: message
    message = ''
    meta = 0          ! present, np, count
    if (is_root()) then
      call h5fopen_f(path, H5F_ACC_RDONLY_F, file, err)
      if (has_object(file, 'contacts')) then
        meta(1) = 1
        call h5gopen_f(file, 'contacts', group, err)
        call read_attribute(group, 'np', a, err)
        meta(2) = a(1)
        if (err == 0) call read_attribute(group, 'count', a, err)
        meta(3) = a(1)
        if (err /= 0) then
          message = 'attribute np or count missing'
        else if (meta(2) /= np .and. meta(3) > 0) then
          write(message, '(a,i0,a,i0)') 'the contact history is for ', meta(2), ' particles, the run has ', np
        else if (meta(3) < 0) then
          message = 'negative count'
        else if (meta(3) > 0) then
          allocate(ids(2, meta(3)), ups(3, meta(3)))
          call read_dataset(group, 'ids', ids, err)
          if (err == 0) call read_dataset(group, 'spring', ups, err)
          if (err /= 0) message = 'dataset ids or spring missing or of the wrong shape'
        end if
        call h5gclose_f(group, err)
      end if
      call h5fclose_f(file, err)
    end if
    call file_error_from_root(path, 'contacts', message)
    call MPI_Bcast(meta, 3, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
    call history_clear(h)
    if (meta(1) == 0) then
      call warn_line(trim(path)//' holds no contact history (/contacts): the tangential springs start at zero')
      return
    end if
    if (meta(3) == 0) return
    if (.not. is_root()) allocate(ids(2, meta(3)), ups(3, meta(3)))
    call MPI_Bcast(ids, 2 * meta(3), MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
    call MPI_Bcast(ups, 3 * meta(3), MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
    call history_unpack(h, np, meta(3), ids, ups, info)
    if (info /= 0) call file_error(path, 'contacts/ids', 'invalid or repeated contact ids')
  end subroutine contacts_read

end module mod_contacts_io
