! Invariant: the contact springs written by every rank from its share (contacts_write_shares: each
! rank holds the springs of the pairs with one of its own spheres) make the same /contacts group as
! rank 0 writing the whole history (contacts_write): the attributes np and count, and the datasets
! ids and spring, value for value and in the canonical order (first sphere, then partner; a wall's
! partner -1/-2 first). Checked exactly: the values travel as doubles (the pairs as doubles below
! 2^53) and are only moved, never computed.
! The history: 300 spheres, 900 random pairs (partner > first sphere) and 60 wall springs, random
! springs (a fixed Fortran seed), the same on every rank. The ranks' shares are not slabs: sphere g
! is own to rank mod(7 g + 3, P), so every writer's run of rows gathers springs from every rank,
! and a pair whose spheres are both own on one rank is held once. Also: an empty history (count 0,
! no datasets) from every rank. Singleton here; on 3 ranks in tests/regression/test_unit_petsc_ranks.sh.
#include <petsc/finclude/petscsys.h>
program test_contacts_shares
  use hdf5
  use petscsys
  use mod_kinds, only: dp
  use mod_contact, only: contact_history_t, history_unpack, history_size, wall_lower, wall_upper
  use mod_contacts_io, only: contacts_write, contacts_write_shares
  use mod_h5_parallel, only: h5_parallel_create, h5_parallel_close
  use mod_h5util, only: read_dataset, read_attribute
  use mod_unit_checks, only: check, finish
  use mod_unit_start, only: unit_start
  implicit none

  integer, parameter :: spheres = 300, pairs = 900, walls = 60
  PetscErrorCode :: ierr
  PetscMPIInt :: rank, nranks
  type(contact_history_t) :: every, share
  integer :: ids(2, pairs + walls), info, i, k, seed_size
  integer, allocatable :: seed(:), local_id(:), mine(:)
  logical, allocatable :: own(:)
  real(dp) :: ups(3, pairs + walls), r(2)
  character(len=512) :: dir
  character(len=200) :: message
  character(len=40) :: scene

  call unit_start('test_contacts_shares', rank, nranks, dir)
  write(scene, '(i0,a)') nranks, ' rank(s)'

  ! the whole history, the same on every rank (distinct pairs: history_unpack refuses repeats)
  call random_seed(size=seed_size)
  allocate(seed(seed_size))
  seed = 4511
  call random_seed(put=seed)
  k = 0
  do while (k < pairs)
    call random_number(r)
    ids(1, k + 1) = 1 + int(r(1) * (spheres - 1))
    ids(2, k + 1) = ids(1, k + 1) + 1 + int(r(2) * min(12, spheres - ids(1, k + 1)))
    if (ids(2, k + 1) > spheres) cycle
    if (any(ids(1, 1:k) == ids(1, k + 1) .and. ids(2, 1:k) == ids(2, k + 1))) cycle
    k = k + 1
  end do
  do i = 1, walls
    ids(:, pairs + i) = [5 * i, merge(wall_lower, wall_upper, mod(i, 2) == 0)]
  end do
  call random_number(ups)
  ups = 1.0e-3_dp * (ups - 0.5_dp)
  call history_unpack(every, spheres, pairs + walls, ids, ups, info)
  call check(info == 0, 'the whole history is built: 900 pairs and 60 wall springs (history_unpack)')

  ! this rank's share: its own spheres (not a slab), the partners of their pairs as ghosts, and the
  ! springs of the pairs with an own sphere
  allocate(own(spheres))
  own = [(mod(7 * i + 3, nranks) == rank, i = 1, spheres)]
  mine = pack([(i, i = 1, pairs + walls)], [(own(ids(1, i)) .or. (ids(2, i) > 0 .and. own(max(1, ids(2, i)))), &
                                              i = 1, pairs + walls)])
  local_id = pack([(i, i = 1, spheres)], own .or. [(any(ids(1, mine) == i .or. ids(2, mine) == i), i = 1, spheres)])
  call history_unpack(share, spheres, size(mine), ids(:, mine), ups(:, mine), info)
  call check(info == 0, trim(scene)//': each rank''s share is a history (its own spheres'' pairs)')

  call write_both('full', every, share)
  ! nobody holds a spring
  call history_unpack(every, spheres, 0, ids, ups, info)
  call history_unpack(share, spheres, 0, ids, ups, info)
  call write_both('empty', every, share)

  call MPI_Barrier(PETSC_COMM_WORLD, ierr)
  if (rank == 0) call execute_command_line('rm -rf '''//trim(dir)//'''')
  call finish('test_contacts_shares')
  PetscCallA(PetscFinalize(ierr))

contains

  ! The group from the shares (every rank, MPI-IO) and from the whole history (rank 0), compared.
  subroutine write_both(name, whole, part)
    character(len=*), intent(in) :: name
    type(contact_history_t), intent(in) :: whole, part
    integer(HID_T) :: file
    integer :: err, e
    character(len=600) :: shares_path, whole_path
    shares_path = trim(dir)//'/'//name//'_shares.h5'
    whole_path = trim(dir)//'/'//name//'_whole.h5'
    call h5_parallel_create(trim(shares_path), file, err)
    call check(err == 0, trim(scene)//', '//name//': the file is made on every rank')
    call contacts_write_shares(file, part, local_id, [(own(local_id(i)), i = 1, size(local_id))], spheres, message)
    call check(len_trim(message) == 0, trim(scene)//', '//name//': contacts_write_shares writes the group '//trim(message))
    call h5_parallel_close(file, err)
    if (rank == 0) then
      call h5fcreate_f(trim(whole_path), H5F_ACC_TRUNC_F, file, e)
      call contacts_write(file, whole, spheres)
      call h5fclose_f(file, e)
      call compare(name, trim(shares_path), trim(whole_path), history_size(whole))
    end if
  end subroutine write_both

  ! Rank 0: the two files' /contacts, attribute for attribute, dataset for dataset.
  subroutine compare(name, shares_path, whole_path, count)
    character(len=*), intent(in) :: name, shares_path, whole_path
    integer, intent(in) :: count
    integer(HID_T) :: f(2), g(2)
    integer :: e, j, a(1), np(2), counts(2)
    integer, allocatable :: pairs_read(:, :, :)
    real(dp), allocatable :: springs_read(:, :, :)
    character(len=16) :: text
    allocate(pairs_read(2, max(1, count), 2), springs_read(3, max(1, count), 2))
    call h5fopen_f(shares_path, H5F_ACC_RDONLY_F, f(1), e)
    call h5fopen_f(whole_path, H5F_ACC_RDONLY_F, f(2), e)
    do j = 1, 2
      call h5gopen_f(f(j), 'contacts', g(j), e)
      call read_attribute(g(j), 'np', a, e)
      np(j) = a(1)
      call read_attribute(g(j), 'count', a, e)
      counts(j) = a(1)
      if (count > 0) then
        call read_dataset(g(j), 'ids', pairs_read(:, :, j), e)
        call read_dataset(g(j), 'spring', springs_read(:, :, j), e)
      end if
      call h5gclose_f(g(j), e)
      call h5fclose_f(f(j), e)
    end do
    write(text, '(i0)') count
    call check(all(np == spheres) .and. all(counts == count), trim(scene)//', '//name//': np 300 and count '// &
               trim(text)//' in both files')
    if (count == 0) return
    call check(all(pairs_read(:, :, 1) == pairs_read(:, :, 2)), trim(scene)//', '//name// &
               ': /contacts/ids from the shares is the whole history''s, in its order')
    call check(all(springs_read(:, :, 1) == springs_read(:, :, 2)), trim(scene)//', '//name// &
               ': /contacts/spring from the shares is the whole history''s, bitwise')
  end subroutine compare

end program test_contacts_shares
