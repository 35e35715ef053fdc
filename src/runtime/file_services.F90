! File-system services for output that must survive a kill or a full disk, the Fortran side of
! src/runtime/file_services_c.c: list a directory, copy a file durably, remove or move a file,
! and name the cause of a failed write (doc/DESIGN.md "series.h5: immutable parts, atomic
! consolidation").
#include <petsc/finclude/petscsys.h>
module mod_file_services
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_double, c_null_char
  use petscsys
  use mod_kinds, only: dp
  use mod_errors, only: is_root, abort_if_any
  implicit none
  private
  public :: list_directory, copy_file, remove_file, rename_file, free_bytes, errno_text, write_failure_cause, &
            require_free_space, directory_of

  interface
    integer(c_int) function fdsusp_list_directory(dir, suffix, buf, len) bind(C, name='fdsusp_list_directory')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: dir(*), suffix(*)
      character(kind=c_char), intent(out) :: buf(*)
      integer(c_int), value :: len
    end function fdsusp_list_directory
    integer(c_int) function fdsusp_copy_file(src, dst) bind(C, name='fdsusp_copy_file')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: src(*), dst(*)
    end function fdsusp_copy_file
    integer(c_int) function fdsusp_remove_file(path) bind(C, name='fdsusp_remove_file')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
    end function fdsusp_remove_file
    integer(c_int) function fdsusp_rename_file(from, to) bind(C, name='fdsusp_rename_file')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: from(*), to(*)
    end function fdsusp_rename_file
    real(c_double) function fdsusp_free_bytes(path) bind(C, name='fdsusp_free_bytes')
      import :: c_double, c_char
      character(kind=c_char), intent(in) :: path(*)
    end function fdsusp_free_bytes
    subroutine fdsusp_errno_text(code, buf, len) bind(C, name='fdsusp_errno_text')
      import :: c_int, c_char
      integer(c_int), value :: code
      character(kind=c_char), intent(out) :: buf(*)
      integer(c_int), value :: len
    end subroutine fdsusp_errno_text
  end interface

contains

  ! The names in DIR ending in SUFFIX (not hidden), sorted; status 0, or an errno (names empty).
  ! A missing directory holds no names.
  subroutine list_directory(dir, suffix, names, status)
    character(len=*), intent(in) :: dir, suffix
    character(len=256), allocatable, intent(out) :: names(:)
    integer, intent(out) :: status
    character(kind=c_char), allocatable :: buf(:)
    integer :: n, k, start, length, c
    length = 65536
    do
      allocate(buf(length))
      n = int(fdsusp_list_directory(trim(dir)//c_null_char, suffix//c_null_char, buf, int(length, c_int)))
      if (n /= -1) exit
      deallocate(buf)
      length = 4 * length
    end do
    allocate(names(max(n, 0)))
    status = 0
    if (n < 0) then
      status = -n
      return
    end if
    start = 1
    do k = 1, n
      names(k) = ''
      c = 0
      do while (buf(start + c) /= achar(10))
        if (c < len(names(k))) names(k)(c + 1:c + 1) = buf(start + c)
        c = c + 1
      end do
      start = start + c + 1
    end do
  end subroutine list_directory

  ! Copy SRC to DST and flush DST to disk; 0 or an errno.
  integer function copy_file(src, dst)
    character(len=*), intent(in) :: src, dst
    copy_file = int(fdsusp_copy_file(trim(src)//c_null_char, trim(dst)//c_null_char))
  end function copy_file

  ! Remove a file (a missing one is no error); 0 or an errno.
  integer function remove_file(path)
    character(len=*), intent(in) :: path
    remove_file = int(fdsusp_remove_file(trim(path)//c_null_char))
  end function remove_file

  ! Rename FROM to TO; 0 or an errno.
  integer function rename_file(from, to)
    character(len=*), intent(in) :: from, to
    rename_file = int(fdsusp_rename_file(trim(from)//c_null_char, trim(to)//c_null_char))
  end function rename_file

  ! Bytes free to this user on the file system holding PATH (-1 if unknown).
  real(dp) function free_bytes(path)
    character(len=*), intent(in) :: path
    free_bytes = real(fdsusp_free_bytes(trim(path)//c_null_char), dp)
  end function free_bytes

  function errno_text(code) result(text)
    integer, intent(in) :: code
    character(len=:), allocatable :: text
    character(kind=c_char) :: buf(200)
    integer :: k
    call fdsusp_errno_text(int(code, c_int), buf, int(size(buf), c_int))
    text = ''
    do k = 1, size(buf)
      if (buf(k) == c_null_char) exit
      text = text//buf(k)
    end do
  end function errno_text

  ! The directory holding the file PATH ('.' for a bare name).
  function directory_of(path) result(dir)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: dir
    integer :: slash
    slash = index(trim(path), '/', back=.true.)
    if (slash == 0) then
      dir = '.'
    else
      dir = path(1:max(slash - 1, 1))
    end if
  end function directory_of

  ! Why a write into directory DIR failed, for a message: a full disk is named as such (the
  ! libraries that wrote, HDF5 or PETSc, report no errno), else an I/O error. NEEDED: the bytes
  ! the write wanted (0 if unknown); a disk with less than that, or less than 1 MiB, is full.
  function write_failure_cause(dir, needed) result(cause)
    character(len=*), intent(in) :: dir
    real(dp), intent(in) :: needed
    character(len=:), allocatable :: cause
    character(len=40) :: amount
    real(dp) :: free
    free = free_bytes(dir)
    if (free < 0.0_dp) then
      cause = 'an I/O error (the file system of '//trim(dir)//' cannot be queried)'
    else if (free < max(needed, 1048576.0_dp)) then
      write(amount, '(i0)') int(free, kind=8)
      cause = 'the disk is full ('//trim(amount)//' bytes free on the file system of '//trim(dir)//')'
    else
      cause = 'an I/O error (the disk is not full)'
    end if
  end function write_failure_cause

  ! Before a parallel write of about BYTES into PATH (in directory DIR): stop the run on every rank,
  ! naming the file and the full disk, when the disk cannot hold it. Collective. Why before: in a
  ! parallel HDF5 write rank 0 alone writes the metadata, so a full disk fails there only and the
  ! other ranks would wait for it in the next collective call for ever.
  subroutine require_free_space(dir, bytes, path)
    character(len=*), intent(in) :: dir, path
    real(dp), intent(in) :: bytes
    real(dp) :: free(1)
    character(len=40) :: amount
    PetscErrorCode :: ierr
    free = -1.0_dp
    if (is_root()) free(1) = free_bytes(dir)
    call MPI_Bcast(free, 1, MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
    write(amount, '(i0)') int(bytes, kind=8)
    call abort_if_any(free(1) >= 0.0_dp .and. free(1) < bytes + 1048576.0_dp, trim(path)//' cannot be written ('// &
                      trim(amount)//' bytes): '//write_failure_cause(dir, bytes + 1048576.0_dp))
  end subroutine require_free_space

end module mod_file_services
