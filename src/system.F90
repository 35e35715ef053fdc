! Fortran side of src/system_c.c: signals and atomic file publication.
module mod_system
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
  implicit none
  private
  public :: install_signal_handlers, stop_signal, publish_file, make_directory, probe_directory

  interface
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
  end interface

contains

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

end module mod_system
