! Invariant: the contact springs written by every rank from its share (contacts_write_shares: each
! rank holds the springs of the pairs with one of its own spheres) make the same /contacts group as
! rank 0 writing the whole history (contacts_write): the attributes np and count, and the datasets
! ids and spring, value for value and in the canonical order (first sphere, then partner; a wall's
! partner -1/-2 first). Checked exactly: the values travel as doubles (the pairs as doubles below
! 2^53) and are only moved, never computed.
! Two histories, the same on every rank: 300 spheres with 900 random pairs (partner > first
! sphere) and 60 wall springs, random springs (a fixed Fortran seed); and 30000 spheres with 60000
! pairs (g, g + 1) and (g, g + 2) and 60 wall springs, whose datasets span several chunks (at most
! 2^16 values a chunk, mod_h5util's checked_chunk; a parallel write gathers each chunk on one rank).
! The ranks' shares are not slabs: sphere g is own to rank mod(7 g + 3, P), so every writer's run
! of rows gathers springs from every rank, and a pair whose spheres are both own on one rank is
! held once. Also: an empty history (count 0, no datasets) from every rank. Singleton here; on 3
! ranks in tests/regression/test_unit_petsc_ranks.sh.
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

  integer, parameter :: walls = 60
  PetscErrorCode :: ierr
  PetscMPIInt :: rank, nranks
  type(contact_history_t) :: every, share
  integer :: info, i, k, seed_size, spheres
  integer, allocatable :: ids(:, :), seed(:), local_id(:), mine(:)
  logical, allocatable :: own(:), held(:)
  real(dp), allocatable :: ups(:, :)
  real(dp) :: r(2)
  character(len=512) :: dir
  character(len=200) :: message
  character(len=40) :: scene

  call unit_start('test_contacts_shares', rank, nranks, dir)
  call random_seed(size=seed_size)
  allocate(seed(seed_size))
  seed = 4511
  call random_seed(put=seed)

  ! the random history (distinct pairs: history_unpack refuses repeats)
  spheres = 300
  allocate(ids(2, 900 + walls))
  k = 0
  do while (k < 900)
    call random_number(r)
    ids(1, k + 1) = 1 + int(r(1) * (spheres - 1))
    ids(2, k + 1) = ids(1, k + 1) + 1 + int(r(2) * min(12, spheres - ids(1, k + 1)))
    if (ids(2, k + 1) > spheres) cycle
    if (any(ids(1, 1:k) == ids(1, k + 1) .and. ids(2, 1:k) == ids(2, k + 1))) cycle
    k = k + 1
  end do
  call add_walls(900)
  call run_scene('random')

  ! the large history: pairs (g, g + 1) and (g, g + 2), several chunks a dataset
  spheres = 30000
  deallocate(ids)
  allocate(ids(2, 60000 + walls))
  k = 0
  do i = 1, spheres - 2
    ids(:, k + 1) = [i, i + 1]
    ids(:, k + 2) = [i, i + 2]
    k = k + 2
  end do
  ! (and four across the periodic ends, 60000 in all)
  ids(:, k + 1) = [spheres - 1, spheres]
  ids(:, k + 2) = [1, spheres]
  ids(:, k + 3) = [1, spheres - 1]
  ids(:, k + 4) = [2, spheres]
  call add_walls(60000)
  call run_scene('large')

  call MPI_Barrier(PETSC_COMM_WORLD, ierr)
  if (rank == 0) call execute_command_line('rm -rf '''//trim(dir)//'''')
  call finish('test_contacts_shares')
  PetscCallA(PetscFinalize(ierr))

contains

  ! The wall springs after the pairs ids(:, 1:pairs): spheres 5, 10, ..., 300 on the walls in turn;
  ! then random springs for all.
  subroutine add_walls(pairs)
    integer, intent(in) :: pairs
    integer :: j
    do j = 1, walls
      ids(:, pairs + j) = [5 * j, merge(wall_lower, wall_upper, mod(j, 2) == 0)]
    end do
    if (allocated(ups)) deallocate(ups)
    allocate(ups(3, size(ids, 2)))
    call random_number(ups)
    ups = 1.0e-3_dp * (ups - 0.5_dp)
  end subroutine add_walls

  ! The scene NAME: the whole history and this rank's share (its own spheres, not a slab; the
  ! partners of their pairs as ghosts; the springs of the pairs with an own sphere), written both
  ! ways and compared; then both emptied and compared again.
  subroutine run_scene(name)
    character(len=*), intent(in) :: name
    integer :: n, j
    n = size(ids, 2)
    write(scene, '(i0,a)') nranks, ' rank(s)'
    call history_unpack(every, spheres, n, ids, ups, info)
    call check(info == 0, trim(scene)//', '//name//': the whole history is built (history_unpack)')
    if (allocated(own)) deallocate(own, held)
    allocate(own(spheres), held(spheres))
    own = [(mod(7 * j + 3, nranks) == rank, j = 1, spheres)]
    mine = pack([(j, j = 1, n)], [(own(ids(1, j)) .or. (ids(2, j) > 0 .and. own(max(1, ids(2, j)))), j = 1, n)])
    held = own
    held(ids(1, mine)) = .true.
    held(pack(ids(2, mine), ids(2, mine) > 0)) = .true.
    local_id = pack([(j, j = 1, spheres)], held)
    call history_unpack(share, spheres, size(mine), ids(:, mine), ups(:, mine), info)
    call check(info == 0, trim(scene)//', '//name//': each rank''s share is a history (its own spheres'' pairs)')
    call write_both(name, every, share)
    ! nobody holds a spring
    call history_unpack(every, spheres, 0, ids, ups, info)
    call history_unpack(share, spheres, 0, ids, ups, info)
    call write_both(name//'_empty', every, share)
  end subroutine run_scene

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
    integer(HID_T) :: dset, plist
    integer(HSIZE_T) :: chunk(2)
    integer, allocatable :: pairs_read(:, :, :)
    real(dp), allocatable :: springs_read(:, :, :)
    character(len=40) :: text
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
        if (j == 1) then
          ! the chunks of the springs written in parallel (checked_chunk)
          call h5dopen_f(g(j), 'spring', dset, e)
          call h5dget_create_plist_f(dset, plist, e)
          call h5pget_chunk_f(plist, 2, chunk, e)
          call h5pclose_f(plist, e)
          call h5dclose_f(dset, e)
        end if
      end if
      call h5gclose_f(g(j), e)
      call h5fclose_f(f(j), e)
    end do
    write(text, '(a,i0,a,i0)') 'np ', spheres, ' and count ', count
    call check(all(np == spheres) .and. all(counts == count), trim(scene)//', '//name//': '//trim(text)// &
               ' in both files')
    if (count == 0) return
    write(text, '(i0,a,i0,a)') chunk(2), ' springs a chunk, ', (count + chunk(2) - 1) / chunk(2), ' chunks'
    call check(chunk(1) == 3 .and. 3 * chunk(2) <= 2**16 .and. (count <= 21845 .or. chunk(2) < count), &
               trim(scene)//', '//name//': /contacts/spring in chunks of at most 2^16 values ('//trim(text)//')')
    call check(all(pairs_read(:, :, 1) == pairs_read(:, :, 2)), trim(scene)//', '//name// &
               ': /contacts/ids from the shares is the whole history''s, in its order')
    call check(all(springs_read(:, :, 1) == springs_read(:, :, 2)), trim(scene)//', '//name// &
               ': /contacts/spring from the shares is the whole history''s, bitwise')
  end subroutine compare

end program test_contacts_shares
