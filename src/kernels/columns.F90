! A column of the run's series (series.h5): a name and one record's value, a scalar or an array whose
! shape is the column's per-record shape. Each physics module names its own columns by a function
! returning them (particles_columns, particle_contacts_columns, ...); the series (src/io/series.F90)
! takes them in order, declaring them on the first call and filling records afterwards. Pure data:
! no I/O here (doc/DESIGN.md "Files, restart and signals").
! A per-sphere column (sphere_column: particles/velocity, ...) holds the values of some spheres only,
! those of `rows` (global indices): each rank gives its own spheres' rows, and the series writes
! every rank's rows into the one dataset of all N spheres (mod_series).
module mod_columns
  use mod_kinds, only: dp
  implicit none
  private
  public :: column_t, column, sphere_column, sphere_rows

  type :: column_t
    character(len=64) :: name = ''
    integer :: shape(3) = 0                  ! per-record shape, 0 where unused (a scalar: all 0)
    real(dp), allocatable :: values(:)       ! in Fortran order
    ! a per-sphere column only: the global indices (1-based) of the spheres whose values it holds
    ! (the last dimension of values; shape's last used dimension is the number of all spheres)
    integer, allocatable :: rows(:)
  end type column_t

  ! column(name, value): an integer or real scalar, a vector, a matrix (3 x N) or a tensor (3 x 3 x N)
  interface column
    module procedure column_int, column_real, column_vector, column_matrix, column_tensor
  end interface column

  ! sphere_column(name, n, rows, value): the values value(:, j) (3) or value(:, :, j) (3 x 3) of
  ! sphere rows(j) of n, the rows a rank gives (its own spheres)
  interface sphere_column
    module procedure sphere_column_matrix, sphere_column_tensor
  end interface sphere_column

contains

  pure function column_int(name, value) result(c)
    character(len=*), intent(in) :: name
    integer, intent(in) :: value
    type(column_t) :: c
    c%name = name
    c%values = [real(value, dp)]
  end function column_int

  pure function column_real(name, value) result(c)
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value
    type(column_t) :: c
    c%name = name
    c%values = [value]
  end function column_real

  pure function column_vector(name, value) result(c)
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value(:)
    type(column_t) :: c
    c%name = name
    c%shape = [size(value), 0, 0]
    c%values = value
  end function column_vector

  pure function column_matrix(name, value) result(c)
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value(:, :)
    type(column_t) :: c
    c%name = name
    c%shape = [shape(value), 0]
    c%values = reshape(value, [size(value)])
  end function column_matrix

  pure function column_tensor(name, value) result(c)
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value(:, :, :)
    type(column_t) :: c
    c%name = name
    c%shape = shape(value)
    c%values = reshape(value, [size(value)])
  end function column_tensor

  pure function sphere_column_matrix(name, n, rows, value) result(c)
    character(len=*), intent(in) :: name
    integer, intent(in) :: n, rows(:)
    real(dp), intent(in) :: value(:, :)
    type(column_t) :: c
    c%name = name
    c%shape = [size(value, 1), n, 0]
    c%values = reshape(value, [size(value)])
    c%rows = rows
  end function sphere_column_matrix

  pure function sphere_column_tensor(name, n, rows, value) result(c)
    character(len=*), intent(in) :: name
    integer, intent(in) :: n, rows(:)
    real(dp), intent(in) :: value(:, :, :)
    type(column_t) :: c
    c%name = name
    c%shape = [size(value, 1), size(value, 2), n]
    c%values = reshape(value, [size(value)])
    c%rows = rows
  end function sphere_column_tensor

  !> The global indices and the number of all spheres of a per-sphere column given for the spheres
  !> owned of a set of whole spheres: owned itself and whole when the set is every sphere; rows and
  !> total, when given, for a rank's local set (mod_ld_local), whose indices are not global.
  pure subroutine sphere_rows(owned, whole, r, n, rows, total)
    integer, intent(in) :: owned(:), whole
    integer, allocatable, intent(out) :: r(:)
    integer, intent(out) :: n
    integer, intent(in), optional :: rows(:), total
    if (present(rows)) then
      r = rows
    else
      r = owned
    end if
    n = whole
    if (present(total)) n = total
  end subroutine sphere_rows

end module mod_columns
