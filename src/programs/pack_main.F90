! fdsusp-pack: random hard-sphere configurations for fdsusp (doc/PACKING_INPUT.md).
!   bin/fdsusp-pack DECK
! Reads the &packing group of DECK, builds the packing (mod_packing: compression, then hard-sphere
! Monte Carlo) and writes DIRECTORY/FILE (HDF5): dataset particles/position (N x 3, units of a)
! with attribute box (Lx, Ly, Lz), the layout fdsusp's &particles position_file reads. Serial: on
! several ranks every rank builds the same packing and rank 0 writes it. The file is written
! under a temporary name and renamed, so an interrupted run never leaves a half-written packing.
program fdsusp_pack
#include <petsc/finclude/petscsys.h>
  use petscsys
  use hdf5
  use mod_kinds, only: dp
  use mod_errors, only: input_error, fatal_error, log_line, is_root, abort_run
  use mod_h5util, only: h5util_init, write_attribute, write_string_attribute
  use mod_os_services, only: make_directory, probe_directory, publish_file
  use mod_packing, only: random_packing, packing_report_t
  use mod_packing_deck, only: pack_config_t, read_pack_deck, pack_deck_lines, max_line
  implicit none

  PetscErrorCode :: ierr
  type(pack_config_t) :: cfg
  type(packing_report_t) :: rep
  real(dp), allocatable :: x(:,:)
  character(len=max_line) :: deck, path
  character(len=max_line), allocatable :: echo(:)
  character(len=300) :: msg, text
  character(len=16) :: seconds
  integer :: info, err, nargs, l
  real(dp) :: t0

  PetscCallA(PetscInitialize(ierr))
  t0 = MPI_Wtime()
  call h5util_init()
  nargs = command_argument_count()
  if (nargs < 1) call fatal_error('usage: fdsusp-pack DECK   (see doc/PACKING_INPUT.md)', 2)
  call get_command_argument(1, deck)

  call read_pack_deck(deck, cfg)
  call log_line('fdsusp-pack: random hard-sphere packing')
  call log_line('# effective deck (file '//trim(deck)//', defaults included)')
  call pack_deck_lines(cfg, echo)
  do l = 1, size(echo)
    call log_line(echo(l))
  end do
  call log_line('# end of effective deck')
  err = make_directory(cfg%packing%directory)
  if (err == 0) err = probe_directory(cfg%packing%directory)
  if (err /= 0) then
    write(text, '(a,i0,a)') 'cannot be created or written (errno ', err, ')'
    call input_error(deck, 'packing', 'directory', trim(text))
  end if
  path = trim(cfg%packing%directory)//'/'//trim(cfg%packing%file)

  write(text, '(a,i0,a,3(f0.4,1x),a,a)') 'packing ', cfg%n, ' spheres of radius 1 in a box ', &
    cfg%packing%box, 'a, y: ', trim(cfg%packing%y_boundary)
  call log_line(text)
  call random_packing(cfg%n, cfg%packing%box, cfg%periodic, 1.0_dp, cfg%packing%min_gap, cfg%packing%seed, cfg%packing%mc_sweeps, &
                      x, info, msg, rep)
  select case (info)
  case (0)
  case (1)
    call input_error(deck, 'packing', 'phi', trim(msg))
  case (2)
    call input_error(deck, 'packing', 'box', trim(msg))
  case default
    call fatal_error('fdsusp-pack: '//trim(msg), 3)
  end select

  write(text, '(a,f8.6,a,i0,a,i0,a)') 'phi = ', rep%phi, ' reached in ', rep%stages, &
    ' compression stages (', rep%relax_sweeps, ' relaxation sweeps)'
  call log_line(text)
  write(text, '(i0,a,f6.4,a,f5.3,a)') cfg%packing%mc_sweeps, ' Monte Carlo sweeps, step ', rep%step, &
    ' a, acceptance ', rep%acceptance, ' (fixed-step half)'
  call log_line(text)
  if (cfg%periodic(2)) then
    write(text, '(a,es10.3,a)') 'smallest gap: pairs ', rep%min_pair_gap, ' a'
  else
    write(text, '(a,es10.3,a,es10.3,a)') 'smallest gap: pairs ', rep%min_pair_gap, ' a, walls ', &
      rep%min_wall_gap, ' a'
  end if
  call log_line(text)

  if (is_root()) call write_packing(path)
  write(seconds, '(f12.2)') MPI_Wtime() - t0
  call log_line('wrote '//trim(path)//' ('//trim(adjustl(seconds))//' s)')
  PetscCallA(PetscFinalize(ierr))

contains

  subroutine write_packing(final)
    character(len=*), intent(in) :: final
    character(len=max_line) :: tmp
    integer(HID_T) :: file, group, space, dset
    integer(HSIZE_T) :: dims(2)
    integer :: e(10), st
    tmp = trim(final)//'.tmp'
    e = 0
    call h5fcreate_f(trim(tmp), H5F_ACC_TRUNC_F, file, st)
    if (st /= 0) call abort_run('cannot create '//trim(tmp))
    call h5gcreate_f(file, 'particles', group, e(1))
    dims = shape(x, kind=HSIZE_T)                       ! (3, N) here: N x 3 in C order
    call h5screate_simple_f(2, dims, space, e(2))
    call h5dcreate_f(group, 'position', H5T_NATIVE_DOUBLE, space, dset, e(3))
    call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, x, dims, e(4))
    call write_attribute(dset, 'box', cfg%packing%box, e(5))
    call h5dclose_f(dset, st)
    call h5sclose_f(space, st)
    call write_attribute(group, 'box', cfg%packing%box, e(6))
    call write_attribute(group, 'radius', [1.0_dp], e(7))
    call h5gclose_f(group, st)
    call write_attribute(file, 'phi', [rep%phi], e(8))
    call write_attribute(file, 'seed', [cfg%packing%seed], e(9))
    call write_string_attribute(file, 'y_boundary', trim(cfg%packing%y_boundary), e(10))
    call write_attribute(file, 'mc_sweeps', [cfg%packing%mc_sweeps], st)
    call write_attribute(file, 'min_gap', [cfg%packing%min_gap], st)
    call write_string_attribute(file, 'generator', 'fdsusp-pack', st)
    call h5fclose_f(file, st)
    if (any(e /= 0) .or. st /= 0) call abort_run('writing '//trim(tmp)//' failed')
    st = publish_file(tmp, final)
    if (st /= 0) call abort_run('cannot rename '//trim(tmp)//' to '//trim(final))
  end subroutine write_packing

end program fdsusp_pack
