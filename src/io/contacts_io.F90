! The contact history in checkpoints (doc/CONTACT.md, "Checkpoint format"): the group /contacts
! with attributes np (particle count) and count (open contacts with a spring), and, when
! count > 0, the datasets ids (count x 2 integers as seen from C/Python: owner, partner; partner
! -1 / -2 is the lower / upper wall) and spring (count x 3 doubles: Upsilon in units of a), in
! the canonical order of history_pack. Written by rank 0 into the open checkpoint (when each rank
! holds the springs of its own spheres' pairs, contacts_gather first collects them on rank 0); read
! by rank 0 and broadcast, every rank then unpacks the same history.
#include <petsc/finclude/petscsys.h>
module mod_contacts_io
  use hdf5
  use petscsys
  use mod_kinds, only: dp
  use mod_contact, only: contact_history_t, history_size, history_pack, history_unpack, history_clear
  use mod_sorting, only: sorted_position
  use mod_h5util, only: write_attribute, read_attribute, has_object, write_dataset, read_dataset
  use mod_errors, only: is_root, file_error, file_error_from_root, abort_run, warn_line
  implicit none
  private
  public :: contacts_write, contacts_read, contacts_gather

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

  ! The history of every pair on rank 0 (all), from h on each rank holding the springs of the pairs
  ! with one of its own spheres (a rank's local set, mod_ld_local: the global indices id of its
  ! spheres, ascending, which of them are its own, total spheres): each pair from the owner of its
  ! first sphere, so each once. Other ranks' all is empty. Collective (one gather to rank 0, 5
  ! values a spring).
  subroutine contacts_gather(h, id, own, total, all)
    type(contact_history_t), intent(in) :: h
    integer, intent(in) :: id(:), total
    logical, intent(in) :: own(:)
    type(contact_history_t), intent(inout) :: all
    integer, allocatable :: keys(:, :), counts(:), displs(:)
    real(dp), allocatable :: ups(:, :), mine(:, :), every(:, :)
    integer :: n, np, k, i, p, r, ranks, rank, info, ierr
    n = history_size(h)
    allocate(keys(2, n), ups(3, n), mine(5, n))
    if (n > 0) call history_pack(h, np, keys, ups)
    k = 0
    do i = 1, n
      ! each pair from the owner of its first sphere (a sphere, never a wall)
      p = sorted_position(id, keys(1, i))
      if (p == 0) cycle
      if (.not. own(p)) cycle
      k = k + 1
      mine(:, k) = [real(keys(:, i), dp), ups(:, i)]
    end do
    call MPI_Comm_size(PETSC_COMM_WORLD, ranks, ierr)
    call MPI_Comm_rank(PETSC_COMM_WORLD, rank, ierr)
    allocate(counts(ranks), displs(ranks))
    call MPI_Gather(5 * k, 1, MPI_INTEGER, counts, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
    displs(1) = 0
    do r = 2, ranks
      displs(r) = displs(r - 1) + counts(r - 1)
    end do
    allocate(every(5, merge(sum(counts) / 5, 0, rank == 0)))
    call MPI_Gatherv(mine, 5 * k, MPI_DOUBLE_PRECISION, every, counts, displs, MPI_DOUBLE_PRECISION, 0, &
                     PETSC_COMM_WORLD, ierr)
    call history_clear(all)
    if (rank /= 0) return
    call history_unpack(all, total, size(every, 2), nint(every(1:2, :)), every(3:5, :), info)
    if (info /= 0) call abort_run('internal error: the springs gathered from the ranks do not form a '// &
                                  'contact history (mod_contacts_io)')
  end subroutine contacts_gather

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
