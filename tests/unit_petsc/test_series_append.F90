! Invariant: series.h5 holds exactly the records series_record was given, in order, whatever the
! flushes, and a run continued from a checkpoint at step k keeps the records of steps <= k and
! appends its own after them (mod_series).
! Columns of every kind series_column declares: step (integer, the one integer dataset), a real
! scalar, an integer scalar stored as real, a vector of 4, a 3 x N matrix and a 3 x 3 x N tensor
! (N = 5 particles), plus two root attributes; each value a distinct function of (step, column,
! index). In a temporary directory:
!   1. a run from the start records steps 0, 2, .., 22 in three flushes and closes: series.h5
!      holds 12 records, every value bitwise equal to what was recorded (read back with HDF5's own
!      API here, not through mod_series), the per-record shapes as documented ((3, N, records) in
!      Fortran order), the step column an integer dataset, the attributes; no part (series.parts/N.h5)
!      and no .tmp file remain;
!   2. reopened with restart_step = 10 (a recorded step): series.h5 at once holds steps 0 .. 10
!      only; records 12 .. 30 in two flushes then append after them: 16 records, equal to an
!      uninterrupted run's;
!   3. reopened with restart_step = 25 (between records): steps <= 24 are kept, 26 and 28 follow;
!   4. reopened from the start (restart_step = -1): an empty series.h5 with the columns.
!   5. memory of a flush: a series of 1000 spheres (velocity, omega, stresslet: 15 values a sphere)
!      whose 128 buffered records (15 MiB) are flushed as a part and consolidated: on one rank the
!      flush raises the peak resident size (VmHWM) by less than the buffered rows' size (each
!      column's box is made from the buffer as it is written, 9 of 15 values at most; before
!      2026-11-29 the rows were copied three times, +45 MiB; doc/BENCHMARKS.md §20). On several
!      ranks the figure is printed, not checked (the exchange holds a copy of the rank's rows).
! The two per-sphere columns (sphere_column) are given by every rank for its own spheres only,
! and which spheres a rank owns changes from record to record (sphere i at step k belongs to rank
! mod(i + k / 2, ranks)), as spheres change owner in a run: the file must not depend on it.
! Exact comparisons (the values are stored as doubles, no tolerance). Every rank writes the series
! together (parallel HDF5, mod_series); on 3 ranks (tests/regression/test_unit_petsc_ranks.sh) rank
! 0 reads it back and every rank learns every verdict from rank 0.
#include <petsc/finclude/petscsys.h>
program test_series_append
  use, intrinsic :: iso_fortran_env, only: output_unit
  use petscsys
  use hdf5
  use mod_kinds, only: dp
  use mod_h5util, only: read_attribute
  use mod_columns, only: sphere_column
  use mod_series, only: series_t, series_column, series_add, series_open, series_record, series_flush, &
                        series_close, series_attributes
  use mod_os_services, only: make_directory, peak_resident_kb
  use mod_file_services, only: list_directory
  use mod_unit_checks, only: check, finish
  use mod_unit_start, only: unit_start
  implicit none

  integer, parameter :: n_particles = 5, n_columns = 6
  character(len=*), parameter :: names(n_columns) = [character(len=24) :: 'step', 'time', 'contacts', &
       'wall/force', 'particles/velocity', 'particles/stresslet']
  integer, parameter :: lengths(n_columns) = [1, 1, 1, 4, 3 * n_particles, 9 * n_particles]
  PetscErrorCode :: ierr
  PetscMPIInt :: rank, ranks
  character(len=512) :: dir
  type(series_t) :: s
  integer :: step, status
  integer, allocatable :: expected(:)

  call unit_start('test_series_append', rank, ranks, dir)

  ! 1. from the start: steps 0, 2, .., 22, flushed after 4 and 9 records, then closed
  call declare(s)
  call series_open(s, dir, -1, 12)
  do step = 0, 22, 2
    call columns(s, step)
    call series_record(s)
    if (step == 6 .or. step == 16) call series_flush(s)
  end do
  call series_close(s)
  expected = [(step, step = 0, 22, 2)]
  call verify('from the start, 3 flushes', expected)
  call verify_layout()

  ! 2. continued from step 10
  call reopen(s, 10)
  call verify('restart_step 10, right after series_open', [(step, step = 0, 10, 2)])
  do step = 12, 30, 2
    call columns(s, step)
    call series_record(s)
    if (step == 20) call series_flush(s)
  end do
  call series_close(s)
  call verify('restart_step 10, then steps 12 .. 30 in 2 flushes', [(step, step = 0, 30, 2)])

  ! 3. continued from step 25, between two records
  call reopen(s, 25)
  call verify('restart_step 25 (no record there), right after series_open', [(step, step = 0, 24, 2)])
  do step = 26, 28, 2
    call columns(s, step)
    call series_record(s)
  end do
  call series_close(s)
  call verify('restart_step 25, then steps 26, 28', [(step, step = 0, 28, 2)])

  ! 4. from the start again
  call reopen(s, -1)
  call series_close(s)
  expected = [integer ::]
  call verify('a new run from the start (restart_step -1)', expected)

  ! 5. the memory of a flush
  call flush_memory()

  if (rank == 0) call execute_command_line('rm -rf '''//trim(dir)//'''')
  call finish('test_series_append')
  PetscCallA(PetscFinalize(ierr))

contains

  ! The value of column c at step, index i (1-based, Fortran order within the record).
  pure real(dp) function value(step, c, i)
    integer, intent(in) :: step, c, i
    value = sin(0.37_dp * step + 1.1_dp * c + 0.013_dp * i) * 10.0_dp**(c - 3)
  end function value

  function values(step, c) result(v)
    integer, intent(in) :: step, c
    real(dp) :: v(lengths(c))
    integer :: i
    v = [(value(step, c, i), i = 1, lengths(c))]
  end function values

  ! Every column of the record of step, as a program does it: declares before series_open, fills after.
  subroutine columns(s, step)
    type(series_t), intent(inout) :: s
    integer, intent(in) :: step
    real(dp) :: velocity(3, n_particles), stresslet(3, 3, n_particles)
    integer, allocatable :: mine(:)
    integer :: i
    call series_column(s, 'step', step)
    call series_column(s, 'time', value(step, 2, 1))
    call series_column(s, 'contacts', nint(value(step, 3, 1) * 1000))
    call series_column(s, 'wall/force', values(step, 4))
    ! this rank's spheres at this step (another set at the next step but one)
    mine = pack([(i, i = 1, n_particles)], [(mod(i + step / 2, ranks) == rank, i = 1, n_particles)])
    velocity = reshape(values(step, 5), [3, n_particles])
    stresslet = reshape(values(step, 6), [3, 3, n_particles])
    call series_add(s, [sphere_column('particles/velocity', n_particles, mine, velocity(:, mine))])
    call series_add(s, [sphere_column('particles/stresslet', n_particles, mine, stresslet(:, :, mine))])
  end subroutine columns

  subroutine declare(s)
    type(series_t), intent(inout) :: s
    call columns(s, 0)
    call series_attributes(s, [character(len=16) :: 'shear_rate', 'radius'], [1.5_dp, 0.75_dp])
  end subroutine declare

  subroutine reopen(s, restart_step)
    type(series_t), intent(inout) :: s
    integer, intent(in) :: restart_step
    type(series_t) :: fresh
    s = fresh
    call declare(s)
    call series_open(s, dir, restart_step, 10)
  end subroutine reopen

  ! Section 5: 128 records of 1000 spheres buffered, then flushed (a part and its consolidation);
  ! the rise of this rank's peak resident size during the flush against the size of its rows.
  subroutine flush_memory()
    integer, parameter :: spheres = 1000, records = 128
    type(series_t) :: big
    real(dp) :: velocity(3, spheres), omega(3, spheres), stresslet(3, 3, spheres), rows_mib, rise_mib
    integer, allocatable :: mine(:)
    integer :: i, k, before(1), after(1)
    character(len=200) :: text
    mine = pack([(i, i = 1, spheres)], [(mod(i, ranks) == rank, i = 1, spheres)])
    do k = 0, records
      velocity = real(k, dp)
      omega = -real(k, dp)
      stresslet = 0.5_dp * k
      call series_column(big, 'step', k)
      call series_add(big, [sphere_column('particles/velocity', spheres, mine, velocity(:, mine))])
      call series_add(big, [sphere_column('particles/omega', spheres, mine, omega(:, mine))])
      call series_add(big, [sphere_column('particles/stresslet', spheres, mine, stresslet(:, :, mine))])
      if (k == 0) then
        ! the columns declared (record 0 is not recorded), the files made before the measure
        if (rank == 0) status = make_directory(trim(dir)//'/big')
        call MPI_Barrier(PETSC_COMM_WORLD, ierr)
        call series_open(big, trim(dir)//'/big', -1, records)
      else
        call series_record(big)
      end if
    end do
    rows_mib = 15.0_dp * 8.0_dp * size(mine) * records / 1048576.0_dp
    before = peak_resident_kb()
    call series_close(big)
    after = peak_resident_kb()
    rise_mib = (after(1) - before(1)) / 1024.0_dp
    write(text, '(a,f0.1,a,f0.1,a)') 'a flush of ', rows_mib, ' MiB of buffered rows raises the peak by ', rise_mib, ' MiB'
    if (ranks == 1) then
      call check(before(1) > 0 .and. rise_mib < rows_mib, trim(text)//' (less than the rows, one rank)')
    else
      write(output_unit, '(a)') '  '//trim(text)//' on rank 0 (not checked on several ranks)'
    end if
  end subroutine flush_memory

  ! series.h5 holds the records of `steps`, each equal to what columns() gives for its step; no
  ! part and no partial write is left.
  subroutine verify(stage, steps)
    character(len=*), intent(in) :: stage
    integer, intent(in) :: steps(:)
    logical :: ok(4)
    character(len=300) :: why
    ok = .false.
    why = ''
    if (rank == 0) call inspect(steps, ok, why)
    call MPI_Bcast(ok, size(ok), MPI_LOGICAL, 0, PETSC_COMM_WORLD, ierr)
    call MPI_Bcast(why, len(why), MPI_CHARACTER, 0, PETSC_COMM_WORLD, ierr)
    call check(ok(1), stage//': series.h5 opens and holds every column, each with one record per step '// &
               '(the step column as recorded)'//trim(why))
    call check(ok(2), stage//': every value of every record bitwise equal to the one recorded')
    call check(ok(3), stage//': the root attributes shear_rate = 1.5, radius = 0.75')
    call check(ok(4), stage//': no part (series.parts/N.h5), no .tmp in series.parts/ and no series.h5.tmp left')
  end subroutine verify

  subroutine inspect(steps, ok, why)
    integer, intent(in) :: steps(:)
    logical, intent(out) :: ok(4)
    character(len=*), intent(inout) :: why
    integer(HID_T) :: file, dset, space
    integer(HSIZE_T) :: dims(4), maxdims(4)
    integer :: c, r, rank_c, err, n
    integer, allocatable :: got_steps(:)
    real(dp), allocatable :: got(:)
    real(dp) :: attr(1)
    character(len=256), allocatable :: left(:)
    logical :: exists
    ok = .false.
    call h5fopen_f(trim(dir)//'/series.h5', H5F_ACC_RDONLY_F, file, err)
    if (err /= 0) then
      why = ' (cannot open it)'
      return
    end if
    ok(1:3) = .true.
    n = size(steps)
    do c = 1, n_columns
      call h5dopen_f(file, trim(names(c)), dset, err)
      if (err /= 0) then
        ok(1:2) = .false.
        why = ' (no dataset '//trim(names(c))//')'
        cycle
      end if
      call h5dget_space_f(dset, space, err)
      call h5sget_simple_extent_ndims_f(space, rank_c, err)
      call h5sget_simple_extent_dims_f(space, dims(1:rank_c), maxdims(1:rank_c), err)
      call h5sclose_f(space, err)
      if (dims(rank_c) /= n .or. product(dims(1:rank_c - 1)) /= lengths(c)) then
        ok(1:2) = .false.
        write(why, '(a,i0,a,i0)') ' ('//trim(names(c))//': ', dims(rank_c), ' records, expected ', n
      else if (n > 0) then
        if (c == 1) then
          allocate(got_steps(n))
          call h5dread_f(dset, H5T_NATIVE_INTEGER, got_steps, dims(1:1), err)
          if (err /= 0 .or. any(got_steps /= steps)) then
            ok(1) = .false.
            why = ' (the step column differs)'
          end if
        else
          allocate(got(lengths(c) * n))
          call h5dread_f(dset, H5T_NATIVE_DOUBLE, got, dims(1:rank_c), err)
          if (err /= 0) ok(2) = .false.
          do r = 1, n
            if (c == 3) then      ! an integer column stored as real
              if (got(r) /= real(nint(value(steps(r), 3, 1) * 1000), dp)) ok(2) = .false.
            else if (any(got((r - 1) * lengths(c) + 1:r * lengths(c)) /= values(steps(r), c))) then
              ok(2) = .false.
            end if
          end do
          deallocate(got)
        end if
      end if
      call h5dclose_f(dset, err)
    end do
    call read_attribute(file, 'shear_rate', attr, err)
    ok(3) = err == 0 .and. attr(1) == 1.5_dp
    call read_attribute(file, 'radius', attr, err)
    ok(3) = ok(3) .and. err == 0 .and. attr(1) == 0.75_dp
    call h5fclose_f(file, err)
    call list_directory(trim(dir)//'/series.parts', '.h5', left, err)
    ok(4) = err == 0 .and. size(left) == 0
    call list_directory(trim(dir)//'/series.parts', '.tmp', left, err)
    ok(4) = ok(4) .and. err == 0 .and. size(left) == 0
    inquire(file=trim(dir)//'/series.h5.tmp', exist=exists)
    ok(4) = ok(4) .and. .not. exists
  end subroutine inspect

  ! The documented layout: per-record shape first (Fortran order), records last; the step an
  ! integer dataset, the other columns doubles.
  subroutine verify_layout()
    logical :: ok(2), shapes(4)
    integer(HID_T) :: file, dset, dtype
    integer :: err, class
    ok = .false.
    if (rank == 0) then
      call h5fopen_f(trim(dir)//'/series.h5', H5F_ACC_RDONLY_F, file, err)
      ok = .true.
      shapes(1) = shape_is(file, 'particles/velocity', [3_HSIZE_T, int(n_particles, HSIZE_T), 12_HSIZE_T])
      shapes(2) = shape_is(file, 'particles/stresslet', [3_HSIZE_T, 3_HSIZE_T, int(n_particles, HSIZE_T), 12_HSIZE_T])
      shapes(3) = shape_is(file, 'wall/force', [4_HSIZE_T, 12_HSIZE_T])
      shapes(4) = shape_is(file, 'time', [12_HSIZE_T])
      ok(1) = all(shapes)
      call h5dopen_f(file, 'step', dset, err)
      call h5dget_type_f(dset, dtype, err)
      call h5tget_class_f(dtype, class, err)
      ok(2) = class == H5T_INTEGER_F
      call h5tclose_f(dtype, err)
      call h5dclose_f(dset, err)
      call h5dopen_f(file, 'contacts', dset, err)
      call h5dget_type_f(dset, dtype, err)
      call h5tget_class_f(dtype, class, err)
      ok(2) = ok(2) .and. class == H5T_FLOAT_F
      call h5tclose_f(dtype, err)
      call h5dclose_f(dset, err)
      call h5fclose_f(file, err)
    end if
    call MPI_Bcast(ok, size(ok), MPI_LOGICAL, 0, PETSC_COMM_WORLD, ierr)
    call check(ok(1), 'series.h5 layout: time (12), wall/force (4, 12), particles/velocity (3, 5, 12), '// &
               'particles/stresslet (3, 3, 5, 12) in Fortran order')
    call check(ok(2), 'series.h5 layout: step an integer dataset, an integer column (contacts) a double one')
  end subroutine verify_layout

  logical function shape_is(file, name, expected)
    integer(HID_T), intent(in) :: file
    character(len=*), intent(in) :: name
    integer(HSIZE_T), intent(in) :: expected(:)
    integer(HID_T) :: dset, space
    integer(HSIZE_T) :: dims(4), maxdims(4)
    integer :: err, r
    shape_is = .false.
    call h5dopen_f(file, name, dset, err)
    if (err /= 0) return
    call h5dget_space_f(dset, space, err)
    call h5sget_simple_extent_ndims_f(space, r, err)
    if (r == size(expected)) then
      call h5sget_simple_extent_dims_f(space, dims(1:r), maxdims(1:r), err)
      shape_is = all(dims(1:r) == expected)
    end if
    call h5sclose_f(space, err)
    call h5dclose_f(dset, err)
  end function shape_is
end program test_series_append
