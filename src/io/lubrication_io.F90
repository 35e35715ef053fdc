! Reading the lubrication model of a run (doc/LUBRICATION.md): the &lubrication choice and, for
! the 'full' model, the table of the resolved resistance that scripts/calibrate.py measured at
! this resolution (resolved_a<N>.h5: in $FDSUSP_TABLE_DIR, beside an installed program in
! PREFIX/share/fdsusp/lubrication, in the build tree's input/lubrication; or &lubrication table). Everything is checked before any work: a resolution
! with no table, a table calibrated with another fictitious-domain set-up (radius_offset,
! slip_kappa) or an unreadable file stops the run with one message. Collective.
#include <petsc/finclude/petscsys.h>
module mod_lubrication_io
  use hdf5
  use petscsys
  use mod_kinds, only: dp
  use mod_params, only: config_t
  use mod_lubrication, only: lubrication_t, lub_setup, lub_wall_floor, model_code, LUB_FULL, LUB_NONE, LUB_EXACT, n_wall_scalars
  use mod_pair_resistance, only: n_pair_scalars
  use mod_h5util, only: read_attribute, read_dataset, dataset_dims, has_attribute
  use mod_errors, only: is_root, input_error, file_error_from_root, log_line
  use mod_os_services, only: executable_dir
  implicit none
  private
  public :: lubrication_load, default_table_path

#ifndef FDSUSP_TABLE_DIR
#define FDSUSP_TABLE_DIR "input/lubrication"
#endif
  character(len=*), parameter :: table_dir = FDSUSP_TABLE_DIR

contains

  !> The shipped table for a/Delta = n, looked for in $FDSUSP_TABLE_DIR when it is set (then only
  !> there), else in PREFIX/share/fdsusp/lubrication beside an installed program (its bin/../share),
  !> in bin/../input/lubrication of a build tree, and last in the build tree compiled in
  !> (FDSUSP_TABLE_DIR): the first that holds it (the last place when none does: the message names it).
  function default_table_path(cells_per_radius) result(path)
    real(dp), intent(in) :: cells_per_radius
    character(len=:), allocatable :: path, bin
    character(len=16) :: tag
    character(len=1024) :: env
    integer :: length, status, k
    logical :: exists
    write(tag, '(i0)') nint(cells_per_radius)
    call get_environment_variable('FDSUSP_TABLE_DIR', env, length, status)
    if (status == 0 .and. length > 0) then
      path = trim(env)//'/resolved_a'//trim(tag)//'.h5'
      return
    end if
    bin = executable_dir()
    do k = 1, 3
      select case (k)
      case (1)
        path = bin//'/../share/fdsusp/lubrication/resolved_a'//trim(tag)//'.h5'
      case (2)
        path = bin//'/../input/lubrication/resolved_a'//trim(tag)//'.h5'
      case default
        path = table_dir//'/resolved_a'//trim(tag)//'.h5'
      end select
      if (len(bin) == 0 .and. k < 3) cycle
      inquire(file=path, exist=exists)
      if (exists) return
    end do
  end function default_table_path

  !> lub configured from cfg. needed: the run has pairs or walls to lubricate (else 'none' is
  !> used silently, whatever the deck says, since there is nothing to correct).
  subroutine lubrication_load(cfg, needed, lub)
    type(config_t), intent(in) :: cfg
    logical, intent(in) :: needed
    type(lubrication_t), intent(inout) :: lub
    character(len=:), allocatable :: path
    character(len=300) :: message
    integer :: model, dims(2), ierr
    real(dp), allocatable :: pair(:, :), wall(:, :)
    logical :: exists

    model = model_code(trim(cfg%lubrication%model))
    if (.not. needed) model = LUB_NONE
    ! lubrication dynamics (&fluid model = 'none'): nothing is resolved, so 'full' is the exact
    ! two-body functions themselves and needs no table (mod_lubrication_dynamics)
    if (.not. cfg%resolved .and. model == LUB_FULL) then
      model = LUB_EXACT
      if (len_trim(cfg%lubrication%table) > 0) &
        call log_line('lubrication: &lubrication table is not used with &fluid model = ''none'' (exact functions)')
    end if
    if (model == LUB_FULL) then
      path = trim(cfg%lubrication%table)
      if (len(path) == 0) then
        path = default_table_path(cfg%domain%cells_per_radius)
        inquire(file=path, exist=exists)
        if (abs(cfg%domain%cells_per_radius - nint(cfg%domain%cells_per_radius)) > 1.0e-9_dp .or. .not. exists) &
          call input_error(cfg%deck_file, 'lubrication', 'model', 'the full model has no table for '// &
               'cells_per_radius = '//trim(number(cfg%domain%cells_per_radius))//' ('//path//' is missing): '// &
               'calibrate it (make calibrate CELLS_PER_RADIUS=n), use a calibrated resolution, '// &
               'or model = ''simple''')
      else
        inquire(file=path, exist=exists)
        if (.not. exists) call input_error(cfg%deck_file, 'lubrication', 'table', '"'//path//'" does not exist')
      end if
      message = ''
      dims = 0
      call log_line('lubrication table: '//path)
      if (is_root()) call read_table(path, cfg, pair, wall, message)
      call file_error_from_root(path, 'lubrication table', message)
      if (is_root()) dims = [size(pair, 2), size(wall, 2)]
      call MPI_Bcast(dims, 2, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
      if (.not. is_root()) allocate(pair(1 + n_pair_scalars, dims(1)), wall(1 + n_wall_scalars, dims(2)))
      call MPI_Bcast(pair, size(pair), MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
      call MPI_Bcast(wall, size(wall), MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
      lub%pair_gap = pair(1, :)
      lub%pair_resolved = transpose(pair(2:, :))
      lub%wall_gap = wall(1, :)
      lub%wall_resolved = transpose(wall(2:, :))
    end if
    call lub_setup(lub, model, cfg%radius, 1.0_dp, cfg%domain%cells_per_radius, cfg%lubrication%outer_cutoff, cfg%lubrication%inner_cutoff)
    lub%wall_floor = lub_wall_floor(cfg%fluid%reynolds, cfg%time%dt, cfg%radius)
  end subroutine lubrication_load

  subroutine read_table(path, cfg, pair, wall, message)
    character(len=*), intent(in) :: path
    type(config_t), intent(in) :: cfg
    real(dp), allocatable, intent(out) :: pair(:, :), wall(:, :)
    character(len=*), intent(out) :: message
    integer(HID_T) :: file
    integer :: err
    real(dp) :: value(1)
    message = ''
    call h5fopen_f(path, H5F_ACC_RDONLY_F, file, err)
    if (err /= 0) then
      message = 'cannot be opened as HDF5'
      return
    end if
    block
      character(len=16), parameter :: names(3) = [character(len=16) :: 'cells_per_radius', 'radius_offset', &
                                                  'slip_kappa']
      real(dp) :: expected(3)
      integer :: k
      expected = [cfg%domain%cells_per_radius, cfg%particles%radius_offset, cfg%particles%slip_kappa]
      do k = 1, 3
        if (.not. has_attribute(file, trim(names(k)))) then
          message = 'attribute '//trim(names(k))//' missing'
        else
          call read_attribute(file, trim(names(k)), value, err)
          if (err /= 0) then
            message = 'attribute '//trim(names(k))//' unreadable'
          else if (abs(value(1) - expected(k)) > 1.0e-9_dp * max(1.0_dp, abs(expected(k)))) then
            message = 'calibrated with '//trim(names(k))//' = '//trim(number(value(1)))// &
                      ', the deck has '//trim(number(expected(k)))//' (recalibrate: scripts/calibrate.py)'
          end if
        end if
        if (len_trim(message) > 0) exit
      end do
    end block
    if (len_trim(message) == 0) call read_rows(file, 'pair/resolved', 1 + n_pair_scalars, pair, message)
    if (len_trim(message) == 0) call read_rows(file, 'wall/resolved', 1 + n_wall_scalars, wall, message)
    call h5fclose_f(file, err)
  end subroutine read_table

  ! One table: n >= 2 rows of width columns, a positive increasing gap first (HDF5 n x width,
  ! read as (width, n)).
  subroutine read_rows(file, name, width, rows, message)
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: name
    integer, intent(in) :: width
    real(dp), allocatable, intent(out) :: rows(:, :)
    character(len=*), intent(inout) :: message
    integer(HSIZE_T) :: d(2)
    integer :: rank, err, n
    call dataset_dims(file, name, rank, d)
    if (rank /= 2 .or. d(1) /= width .or. d(2) < 2) then
      write(message, '(a,i0,a)') name//' must be an n x ', width, ' dataset with n >= 2'
      return
    end if
    allocate(rows(d(1), d(2)))
    call read_dataset(file, name, rows, err)
    if (err /= 0) then
      message = name//' cannot be read'
      return
    end if
    n = size(rows, 2)
    if (rows(1, 1) <= 0 .or. any(rows(1, 2:) <= rows(1, :n - 1))) &
      message = name//': the gaps must be positive and increasing'
  end subroutine read_rows

  function number(x) result(text)
    real(dp), intent(in) :: x
    character(len=24) :: text
    write(text, '(g0.6)') x
  end function number

end module mod_lubrication_io
