! fdsusp-pack: random hard-sphere configurations for fdsusp (doc/PACKING_INPUT.md).
!   bin/fdsusp-pack DECK
! Reads the &packing group of DECK, builds the packing (mod_packing: compression, then hard-sphere
! Monte Carlo) and writes DIRECTORY/FILE (HDF5): dataset particles/position (N x 3, units of a)
! with attribute box (Lx, Ly, Lz), the layout fdsusp's &particles position_file reads, and
! particles/radius (N; equal spheres too), with the species as attributes. Serial: on
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
  use mod_packing, only: random_packing_mixture, packing_report_t
  use mod_packing_deck, only: pack_config_t, read_pack_deck, pack_deck_lines, max_line
  implicit none

  PetscErrorCode :: ierr
  type(pack_config_t) :: cfg
  type(packing_report_t) :: rep
  real(dp), allocatable :: x(:,:), radius(:)
  character(len=max_line) :: deck, path
  character(len=max_line), allocatable :: echo(:)
  character(len=300) :: msg, text
  character(len=16) :: seconds
  integer :: info, err, nargs, l, k
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

  ! the spheres species by species (their order is immaterial: the positions are random)
  allocate(radius(0))
  do k = 1, cfg%n_species
    radius = [radius, spread(cfg%packing%radius(k), 1, cfg%counts(k))]
  end do
  if (cfg%n_species == 1) then
    write(text, '(a,i0,a,3(f0.4,1x),a,a)') 'packing ', cfg%n, ' spheres of radius 1 in a box ', &
      cfg%packing%box, 'a, y: ', trim(cfg%packing%y_boundary)
  else
    write(text, '(a,i0,a,i0,a,3(f0.4,1x),a,a)') 'packing ', cfg%n, ' spheres of ', cfg%n_species, &
      ' species in a box ', cfg%packing%box, 'a, y: ', trim(cfg%packing%y_boundary)
  end if
  call log_line(text)
  do k = 1, merge(cfg%n_species, 0, cfg%n_species > 1)
    write(text, '(a,i0,a,f0.4,a,i0,a)') '  species ', k, ': radius ', cfg%packing%radius(k), ' a, ', &
      cfg%counts(k), ' spheres'
    call log_line(text)
  end do
  call random_packing_mixture(radius, cfg%packing%box, cfg%periodic, cfg%packing%min_gap, cfg%packing%seed, &
                              cfg%packing%mc_sweeps, x, info, msg, rep)
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
    integer :: e(15), st
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
    ! the unit of length (the smallest radius), as before the mixtures; the radii follow
    call write_attribute(group, 'radius', [1.0_dp], e(7))
    call write_attribute(group, 'species_radius', cfg%packing%radius(1:cfg%n_species), e(11))
    call write_attribute(group, 'species_count', cfg%counts(1:cfg%n_species), e(12))
    dims(1) = size(radius, kind=HSIZE_T)
    call h5screate_simple_f(1, dims(1:1), space, e(13))
    call h5dcreate_f(group, 'radius', H5T_NATIVE_DOUBLE, space, dset, e(14))
    call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, radius, dims(1:1), e(15))
    call h5dclose_f(dset, st)
    call h5sclose_f(space, st)
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
