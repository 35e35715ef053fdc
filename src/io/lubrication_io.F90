! Reading the lubrication model of a run (doc/LUBRICATION.md): the &lubrication choice and, for
! the 'full' model, the table of the resolved resistance that scripts/calibrate.py measured at
! this resolution (resolved_a<N>.h5: in $FDSUSP_TABLE_DIR, beside an installed program in
! PREFIX/share/fdsusp/lubrication, in the build tree's input/lubrication; or &lubrication table). Everything is checked before any work: a resolution
! with no table, a table calibrated with another fictitious-domain set-up (radius_offset,
! slip_kappa) or an unreadable file stops the run with one message. Collective.
! A mixture (&particles radius lists several species) with the full model reads one table per
! species, resolved_a<N r_s>.h5 (pair part for pairs of that species, wall part for its wall
! links), and one per pair of species s < t, resolved_a<N r_s>_ratio<r_t/r_s>.h5, the numbers in
! their shortest decimal form (table_tag); all looked for as the equal table is, all checked
! (cells_per_radius, size_ratio, radius_offset, slip_kappa) before any work (doc/LUBRICATION.md
! "Tables for mixtures").
#include <petsc/finclude/petscsys.h>
module mod_lubrication_io
  use hdf5
  use petscsys
  use mod_kinds, only: dp
  use mod_params, only: config_t
  use mod_lubrication, only: lubrication_t, lub_setup, lub_wall_floor, model_code, LUB_FULL, LUB_NONE, LUB_EXACT, &
       LUB_SIMPLE, n_wall_scalars
  use mod_pair_resistance, only: n_pair_scalars
  use mod_h5util, only: read_attribute, read_dataset, dataset_dims, has_attribute
  use mod_errors, only: is_root, input_error, file_error_from_root, log_line
  use mod_os_services, only: executable_dir
  implicit none
  private
  public :: lubrication_load, table_path, table_tag

#ifndef FDSUSP_TABLE_DIR
#define FDSUSP_TABLE_DIR "input/lubrication"
#endif
  character(len=*), parameter :: table_dir = FDSUSP_TABLE_DIR

contains

  !> A table file by name (resolved_a<tag>.h5, table_tag), looked for in $FDSUSP_TABLE_DIR when it
  !> is set (then only there), else in PREFIX/share/fdsusp/lubrication beside an installed program
  !> (its bin/../share), in bin/../input/lubrication of a build tree, and last in the build tree
  !> compiled in (FDSUSP_TABLE_DIR): the first that holds it (the last place when none does: the
  !> message names it).
  function table_path(name) result(path)
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: path, bin
    character(len=1024) :: env
    integer :: length, status, k
    logical :: exists
    call get_environment_variable('FDSUSP_TABLE_DIR', env, length, status)
    if (status == 0 .and. length > 0) then
      path = trim(env)//'/'//name
      return
    end if
    bin = executable_dir()
    do k = 1, 3
      select case (k)
      case (1)
        path = bin//'/../share/fdsusp/lubrication/'//name
      case (2)
        path = bin//'/../input/lubrication/'//name
      case default
        path = table_dir//'/'//name
      end select
      if (len(bin) == 0 .and. k < 3) cycle
      inquire(file=path, exist=exists)
      if (exists) return
    end do
  end function table_path

  !> A resolution or size ratio as the table names write it: rounded to 6 decimals, trailing zeros
  !> and point dropped (4, 5.6, 7, 10, 1.4; Python: ('%.6f' % x).rstrip('0').rstrip('.')), so that
  !> 4 x 1.4 = 5.6000000000000005 and 3 x 1.4 = 4.199999999999999 name the tables 5.6 and 4.2.
  function table_tag(x) result(tag)
    real(dp), intent(in) :: x
    character(len=:), allocatable :: tag
    character(len=32) :: text
    integer :: n
    write(text, '(f0.6)') x
    n = len_trim(text)
    do while (n > 1 .and. text(n:n) == '0')
      n = n - 1
    end do
    if (text(n:n) == '.') n = n - 1
    tag = text(1:n)
    if (tag(1:1) == '.') tag = '0'//tag
  end function table_tag

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
    real(dp) :: resolution
    logical :: exists

    ! equal spheres of radius a sit at a/Delta = cells_per_radius a (a = 1, the unit of length,
    ! but for studies of the discrete sphere): their table is the one of that resolution
    resolution = cfg%domain%cells_per_radius * cfg%radius
    model = model_code(trim(cfg%lubrication%model))
    if (.not. needed) model = LUB_NONE
    ! lubrication dynamics (&fluid model = 'none'): nothing is resolved, so 'full' is the exact
    ! two-body functions themselves and needs no table (mod_lubrication_dynamics)
    if (.not. cfg%resolved .and. model == LUB_FULL) then
      model = LUB_EXACT
      if (len_trim(cfg%lubrication%table) > 0) &
        call log_line('lubrication: &lubrication table is not used with &fluid model = ''none'' (exact functions)')
    end if
    if (cfg%species > 1 .and. model == LUB_SIMPLE) &
      call input_error(cfg%deck_file, 'lubrication', 'model', '''simple'' is for equal spheres; a mixture '// &
           '(&particles radius) takes ''full'' (a table per pair of species in the resolved fluid, the exact '// &
           'functions in lubrication dynamics) or ''none''')
    if (cfg%species > 1 .and. model == LUB_FULL) then
      call load_mixture_tables(cfg, lub)
    else if (model == LUB_FULL) then
      path = trim(cfg%lubrication%table)
      if (len(path) == 0) then
        path = table_path('resolved_a'//table_tag(resolution)//'.h5')
        inquire(file=path, exist=exists)
        if (.not. exists) then
          if (cfg%radius == 1.0_dp) then
            call input_error(cfg%deck_file, 'lubrication', 'model', 'the full model has no table for '// &
                 'cells_per_radius = '//trim(number(cfg%domain%cells_per_radius))//' ('//path//' is missing): '// &
                 'calibrate it (make calibrate CELLS_PER_RADIUS=n), use a calibrated resolution, '// &
                 'or model = ''simple''')
          else
            call input_error(cfg%deck_file, 'lubrication', 'model', 'the full model has no table for '// &
                 'spheres of radius '//trim(number(cfg%radius))//' at cells_per_radius = '// &
                 trim(number(cfg%domain%cells_per_radius))//', a/Delta = '//trim(number(resolution))//' ('//path// &
                 ' is missing): calibrate it (scripts/calibrate.py), or model = ''simple''')
          end if
        end if
      else
        inquire(file=path, exist=exists)
        if (.not. exists) call input_error(cfg%deck_file, 'lubrication', 'table', '"'//path//'" does not exist')
      end if
      message = ''
      dims = 0
      call log_line('lubrication table: '//path)
      if (is_root()) then
        if (cfg%radius == 1.0_dp) then
          call read_table(path, cfg, pair, wall, message)
        else
          call read_table(path, cfg, pair, wall, message, cells_per_radius=resolution)
        end if
      end if
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
    call lub_setup(lub, model, cfg%radius, 1.0_dp, resolution, cfg%lubrication%outer_cutoff, cfg%lubrication%inner_cutoff)
    lub%wall_floor = lub_wall_floor(cfg%fluid%reynolds, cfg%time%dt, cfg%radius)
  end subroutine lubrication_load

  ! The full model of a mixture: every table it needs (doc/LUBRICATION.md "Tables for mixtures"),
  ! each species' equal table at its own resolution N r_s and each unequal pair's table, looked
  ! for, checked and read before any work; lub's species tables filled (lub_setup follows).
  subroutine load_mixture_tables(cfg, lub)
    type(config_t), intent(in) :: cfg
    type(lubrication_t), intent(inout) :: lub
    character(len=:), allocatable :: path, how
    character(len=400) :: message
    real(dp), allocatable :: pair(:, :), wall(:, :)
    real(dp) :: r(cfg%species), n_s, ratio
    integer :: ns, s, t, pass, ierr
    logical :: exists
    if (len_trim(cfg%lubrication%table) > 0) &
      call input_error(cfg%deck_file, 'lubrication', 'table', 'names one table, which is for equal spheres: a '// &
           'mixture (&particles radius) reads a table per pair of species from the table directory '// &
           '($FDSUSP_TABLE_DIR or the shipped input/lubrication; doc/LUBRICATION.md "Tables for mixtures")')
    ns = cfg%species
    r = cfg%particles%radius(1:ns)
    lub%species_radius = cfg%radius * r
    allocate(lub%species_pair(ns, ns), lub%species_wall(ns))
    ! pass 1: every table exists (the first missing one refused); pass 2: read and checked
    do pass = 1, 2
      do s = 1, ns
        n_s = cfg%domain%cells_per_radius * r(s)
        do t = s, ns
          ratio = r(t) / r(s)
          if (t == s) then
            path = table_path('resolved_a'//table_tag(n_s)//'.h5')
            how = 'make calibrate CELLS_PER_RADIUS='//table_tag(n_s)//' (scripts/calibrate.py '//table_tag(n_s)//')'
          else
            path = table_path('resolved_a'//table_tag(n_s)//'_ratio'//table_tag(ratio)//'.h5')
            how = 'scripts/calibrate.py '//table_tag(n_s)//' --size-ratio '//table_tag(ratio)
          end if
          if (pass == 1) then
            inquire(file=path, exist=exists)
            if (.not. exists) then
              if (t == s) then
                how = 'the table of its spheres of radius '//table_tag(r(s))//' at their a/Delta = '//table_tag(n_s)// &
                      ': '//path//' is missing: make it with '//how
              else
                how = 'the table of its pairs of radii '//table_tag(r(s))//' and '//table_tag(r(t))//' at a/Delta = '// &
                      table_tag(n_s)//' of the smaller: '//path//' is missing: make it with '//how
              end if
              call input_error(cfg%deck_file, 'lubrication', 'model', 'the full model of this mixture '// &
                               '(&particles radius) needs '//how//', or model = ''none''')
            end if
            cycle
          end if
          call log_line('lubrication table: '//path)
          message = ''
          if (is_root()) call read_table(path, cfg, pair, wall, message, n_s, ratio, t == s)
          call MPI_Bcast(message, len(message), MPI_CHARACTER, 0, PETSC_COMM_WORLD, ierr)
          if (len_trim(message) > 0) call input_error(cfg%deck_file, 'lubrication', 'model', 'the table '//path// &
               ' of the mixture (&particles radius) is unusable: '//trim(message))
          call broadcast_rows(pair, merge(1 + n_pair_scalars, 1 + 2 * n_pair_scalars, t == s))
          lub%species_pair(s, t)%gap = pair(1, :)
          lub%species_pair(s, t)%resolved = transpose(pair(2:, :))
          if (t == s) then
            call broadcast_rows(wall, 1 + n_wall_scalars)
            lub%species_wall(s)%gap = wall(1, :)
            lub%species_wall(s)%resolved = transpose(wall(2:, :))
          end if
        end do
      end do
    end do
  end subroutine load_mixture_tables

  ! rows read on rank 0 (width x n) to every rank
  subroutine broadcast_rows(rows, width)
    real(dp), allocatable, intent(inout) :: rows(:, :)
    integer, intent(in) :: width
    integer :: n(1), ierr
    n = 0
    if (is_root()) n = size(rows, 2)
    call MPI_Bcast(n, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
    if (.not. is_root()) then
      if (allocated(rows)) deallocate(rows)
      allocate(rows(width, n(1)))
    end if
    call MPI_Bcast(rows, size(rows), MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
  end subroutine broadcast_rows

  ! One table read on rank 0 and checked against the deck: its attributes (cells_per_radius: the
  ! run's, or a mixture's cells_per_radius for this table; size_ratio: 1, or the mixture's pair's,
  ! absent allowed for 1 only, since the equal tables before mixtures have none; radius_offset,
  ! slip_kappa) and its datasets (pair/resolved with 23 columns, or 45 for an unequal pair, and
  ! wall/resolved, which an unequal pair's table has none of). message: empty when sound.
  subroutine read_table(path, cfg, pair, wall, message, cells_per_radius, size_ratio, equal)
    character(len=*), intent(in) :: path
    type(config_t), intent(in) :: cfg
    real(dp), allocatable, intent(out) :: pair(:, :), wall(:, :)
    character(len=*), intent(out) :: message
    real(dp), intent(in), optional :: cells_per_radius, size_ratio
    logical, intent(in), optional :: equal
    integer(HID_T) :: file
    integer :: err
    real(dp) :: value(1)
    logical :: equal_pair
    equal_pair = .true.
    if (present(equal)) equal_pair = equal
    message = ''
    call h5fopen_f(path, H5F_ACC_RDONLY_F, file, err)
    if (err /= 0) then
      message = 'cannot be opened as HDF5'
      return
    end if
    block
      character(len=16), parameter :: names(4) = [character(len=16) :: 'cells_per_radius', 'radius_offset', &
                                                  'slip_kappa', 'size_ratio']
      real(dp) :: expected(4)
      integer :: k
      ! a mixture's resolution and size ratio are those its table names write, to 6 decimals
      ! (table_tag: a ratio 2/1.4 is calibrated as 1.428571)
      logical :: named(4)
      expected = [cfg%domain%cells_per_radius, cfg%particles%radius_offset, cfg%particles%slip_kappa, 1.0_dp]
      named = .false.
      if (present(cells_per_radius)) expected(1) = cells_per_radius
      if (present(size_ratio)) expected(4) = size_ratio
      named(1) = present(cells_per_radius)
      named(4) = present(size_ratio)
      do k = 1, 4
        if (.not. has_attribute(file, trim(names(k)))) then
          ! the equal tables made before mixtures carry no size_ratio
          if (k == 4 .and. expected(4) == 1.0_dp) cycle
          message = 'attribute '//trim(names(k))//' missing'
        else
          call read_attribute(file, trim(names(k)), value, err)
          if (err /= 0) then
            message = 'attribute '//trim(names(k))//' unreadable'
          else if (abs(value(1) - expected(k)) > 1.0e-9_dp * max(1.0_dp, abs(expected(k))) .and. &
                   .not. (named(k) .and. table_tag(value(1)) == table_tag(expected(k)))) then
            message = 'calibrated with '//trim(names(k))//' = '//trim(number(value(1)))// &
                      ', the deck has '//trim(number(expected(k)))//' (recalibrate: scripts/calibrate.py)'
            if (k == 4 .or. (k == 1 .and. present(cells_per_radius))) &
              message = 'calibrated with '//trim(names(k))//' = '//trim(number(value(1)))// &
                        ', this pair of species needs '//trim(number(expected(k)))//' (recalibrate: scripts/calibrate.py)'
          end if
        end if
        if (len_trim(message) > 0) exit
      end do
    end block
    if (equal_pair) then
      if (len_trim(message) == 0) call read_rows(file, 'pair/resolved', 1 + n_pair_scalars, pair, message)
      if (len_trim(message) == 0) call read_rows(file, 'wall/resolved', 1 + n_wall_scalars, wall, message)
    else
      if (len_trim(message) == 0) call read_rows(file, 'pair/resolved', 1 + 2 * n_pair_scalars, pair, message)
    end if
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
