! Operating-system services, the Fortran side of src/runtime/os_services_c.c: signals, atomic file
! publication, directories, the output directory's lock, the directory of the executable and the
! resident memory (its peak and now).
module mod_os_services
  use, intrinsic :: iso_c_binding, only: c_int, c_long, c_char, c_null_char
  implicit none
  private
  public :: install_signal_handlers, stop_signal, publish_file, make_directory, probe_directory, &
            lock_directory, release_directory, executable_dir, peak_resident_kb, resident_kb

  interface
    integer(c_long) function fdsusp_peak_resident_kb() bind(C, name='fdsusp_peak_resident_kb')
      import :: c_long
    end function fdsusp_peak_resident_kb
    integer(c_long) function fdsusp_resident_kb() bind(C, name='fdsusp_resident_kb')
      import :: c_long
    end function fdsusp_resident_kb
    subroutine fdsusp_install_signal_handlers() bind(C, name='fdsusp_install_signal_handlers')
    end subroutine fdsusp_install_signal_handlers
    integer(c_int) function fdsusp_stop_signal() bind(C, name='fdsusp_stop_signal')
      import :: c_int
    end function fdsusp_stop_signal
    integer(c_int) function fdsusp_publish_file(tmp, final) bind(C, name='fdsusp_publish_file')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: tmp(*), final(*)
    end function fdsusp_publish_file
    integer(c_int) function fdsusp_make_directory(path) bind(C, name='fdsusp_make_directory')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
    end function fdsusp_make_directory
    integer(c_int) function fdsusp_probe_directory(path) bind(C, name='fdsusp_probe_directory')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
    end function fdsusp_probe_directory
    integer(c_int) function fdsusp_lock_directory(path, previous, length) bind(C, name='fdsusp_lock_directory')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      character(kind=c_char), intent(out) :: previous(*)
      integer(c_int), value :: length
    end function fdsusp_lock_directory
    integer(c_int) function fdsusp_executable_dir(buf, len) bind(C, name='fdsusp_executable_dir')
      import :: c_int, c_char
      character(kind=c_char), intent(out) :: buf(*)
      integer(c_int), value :: len
    end function fdsusp_executable_dir
    subroutine fdsusp_release_directory() bind(C, name='fdsusp_release_directory')
    end subroutine fdsusp_release_directory
  end interface

contains

  ! The directory of the running program ('' where it cannot be known).
  function executable_dir() result(dir)
    character(len=:), allocatable :: dir
    character(kind=c_char) :: buf(4096)
    integer :: n, k
    n = int(fdsusp_executable_dir(buf, size(buf)))
    allocate(character(len=max(n, 0)) :: dir)
    do k = 1, n
      dir(k:k) = buf(k)
    end do
  end function executable_dir

  subroutine install_signal_handlers()
    call fdsusp_install_signal_handlers()
  end subroutine install_signal_handlers

  ! The signal that asked the run to stop (SIGTERM or SIGUSR1), or 0.
  integer function stop_signal()
    stop_signal = int(fdsusp_stop_signal())
  end function stop_signal

  ! Rename tmp over final after flushing it to disk; returns 0 or an errno.
  integer function publish_file(tmp, final)
    character(len=*), intent(in) :: tmp, final
    publish_file = int(fdsusp_publish_file(trim(tmp)//c_null_char, trim(final)//c_null_char))
  end function publish_file

  integer function make_directory(path)
    character(len=*), intent(in) :: path
    make_directory = int(fdsusp_make_directory(trim(path)//c_null_char))
  end function make_directory

  integer function probe_directory(path)
    character(len=*), intent(in) :: path
    probe_directory = int(fdsusp_probe_directory(trim(path)//c_null_char))
  end function probe_directory

  ! Lock the output directory for this process (rank 0; src/runtime/os_services_c.c): 0 taken, -1 another live
  ! run holds it, -2 the file system offers no locks, else the errno of creating the lock file.
  ! holder: who holds it (refused) or held it last without releasing it (taken), '' if nobody.
  integer function lock_directory(path, holder)
    character(len=*), intent(in) :: path
    character(len=*), intent(out) :: holder
    character(kind=c_char) :: text(400)
    integer :: k
    lock_directory = int(fdsusp_lock_directory(trim(path)//c_null_char, text, int(size(text), c_int)))
    holder = ''
    do k = 1, min(len(holder), size(text))
      if (text(k) == c_null_char) exit
      holder(k:k) = text(k)
    end do
  end function lock_directory

  ! A clean end: the lock file emptied and the lock dropped (a no-op without a lock).
  subroutine release_directory()
    call fdsusp_release_directory()
  end subroutine release_directory

  ! This process's peak resident set size in kB (VmHWM), -1 where the system does not say.
  integer function peak_resident_kb()
    peak_resident_kb = int(fdsusp_peak_resident_kb())
  end function peak_resident_kb

  ! This process's resident set size now in kB (VmRSS), -1 where the system does not say.
  integer function resident_kb()
    resident_kb = int(fdsusp_resident_kb())
  end function resident_kb

end module mod_os_services
