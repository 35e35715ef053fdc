! Particles in HDF5 files (doc/DESIGN.md "Files, restart and signals"): the group /particles with the dataset position
! (N x 3 as seen from C/Python, units of a) and the attribute box (Lx, Ly, Lz) in every file that
! holds particles, plus in checkpoints the state an exact restart needs (velocity, omega, the
! Adams-Bashforth history). Reading is done by rank 0 and broadcast; a bad file stops the run
! with one message naming the file and the item. Writing is collective (issue 45): every rank
! writes the rows of the spheres it owns into the same datasets through parallel HDF5
! (mod_h5_parallel), so that the writers already take only what a rank owns.
#include <petsc/finclude/petscsys.h>
module mod_particles_io
  use hdf5
  use petscsys
  use mod_kinds, only: dp
  use mod_params, only: config_t
  use mod_particles, only: particles_t, sphere_share_t, particles_init, motion_code, configuration_fault
  use mod_h5util, only: read_values, write_attribute, read_attribute, has_object, read_dataset, dataset_dims
  use mod_h5_parallel, only: h5_parallel_create, h5_parallel_close, h5_parallel_write_columns, h5_parallel_agree
  use mod_errors, only: is_root, input_error, file_error, file_error_from_root, abort_run, abort_if_any
  use mod_os_services, only: publish_file
  use mod_file_services, only: errno_text, write_failure_cause, directory_of, require_free_space
  implicit none
  private
  public :: particles_load, particles_write, particles_read_state, particles_snapshot, owned_spheres, owned_spheres_rule

  ! The spheres this rank writes, given the particles' positions x (3, n) in a box of height lz:
  ! their global indices (1-based, ascending). Every sphere is written by exactly one rank. The
  ! program sets the rule (mod_sphere_ownership: the rank whose z-slab holds the sphere's centre);
  ! without one, rank 0 writes every sphere (owned_spheres).
  abstract interface
    function owned_spheres_rule(x, lz) result(owned)
      import :: dp
      real(dp), intent(in) :: x(:, :), lz
      integer, allocatable :: owned(:)
    end function owned_spheres_rule
  end interface

contains

  ! The particles of the deck: inline (&particles number, position, ...) or from position_file (a
  ! deck with solid_fraction > 0 packs them instead: mod_initial_packing). Collective. Checks the
  ! configuration (inside the box, off the walls, no overlap).
  subroutine particles_load(cfg, parts)
    type(config_t), intent(in) :: cfg
    type(particles_t), intent(out) :: parts
    real(dp), allocatable :: position(:, :), radii(:)
    character(len=400) :: message
    integer :: n, culprit, ierr
    character(len=32) :: item

    if (len_trim(cfg%particles%position_file) == 0) then
      n = cfg%particles%number
      call particles_init(parts, n, cfg%radius, motion_code(cfg%particles%motion))
      parts%position = cfg%particles%position(:, 1:n)
      parts%prescribed_velocity = cfg%particles%velocity(:, 1:n)
      parts%prescribed_omega = cfg%particles%omega(:, 1:n)
      parts%external_force = cfg%particles%external_force(:, 1:n)
      parts%external_torque = cfg%particles%external_torque(:, 1:n)
      parts%radii = cfg%particles%radius(cfg%particles%species(1:n))
      message = configuration_fault(parts%position, parts%radii, cfg%domain%box, cfg%walls, culprit, start_gap_roughness(cfg))
      if (len_trim(message) > 0) then
        write(item, '(a,i0,a)') 'position(:,', culprit, ')'
        call input_error(cfg%deck_file, 'particles', trim(item), trim(message))
      end if
      return
    end if

    message = ''
    n = 0
    if (is_root()) call read_positions(trim(cfg%particles%position_file), position, radii, message)
    call file_error_from_root(trim(cfg%particles%position_file), 'particles/position', message)
    if (is_root()) n = size(position, 2)
    call MPI_Bcast(n, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
    if (.not. is_root()) allocate(position(3, n))
    call MPI_Bcast(position, 3 * n, MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
    call particles_init(parts, n, cfg%radius, motion_code(cfg%particles%motion))
    parts%position = position
    ! each sphere's radius: the file's (particles/radius), one of the deck's species
    if (is_root()) message = radii_fault(cfg, radii)
    call file_error_from_root(trim(cfg%particles%position_file), 'particles/radius', message)
    if (is_root() .and. allocated(radii)) parts%radii = radii
    call MPI_Bcast(parts%radii, n, MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
    message = configuration_fault(parts%position, parts%radii, cfg%domain%box, cfg%walls, culprit, start_gap_roughness(cfg))
    if (len_trim(message) > 0) call file_error(trim(cfg%particles%position_file), 'particles/position', trim(message))
  end subroutine particles_load

  ! '' when the radii of a position file (absent: not given) are the deck's (doc/INPUT.md
  ! "Mixtures"): each one of &particles radius, and every species there; without radii in the file
  ! the deck must list one radius, which every sphere takes.
  function radii_fault(cfg, radii) result(message)
    type(config_t), intent(in) :: cfg
    real(dp), allocatable, intent(in) :: radii(:)
    character(len=400) :: message
    ! the file's radii are the deck's to round-off (a radius written and read as a double)
    real(dp), parameter :: tolerance = 1.0e-12_dp
    integer :: q, k
    message = ''
    associate(species => cfg%particles%radius(1:cfg%species))
      if (.not. allocated(radii)) then
        if (cfg%species > 1) message = 'missing: the deck lists a mixture (&particles radius), the file must give '// &
                                       'each sphere''s radius'
        return
      end if
      do q = 1, size(radii)
        if (all(abs(radii(q) - species) > tolerance * species)) then
          write(message, '(a,i0,a,es13.6,a)') 'sphere ', q, ' has radius ', radii(q), &
               ', not one of the deck''s &particles radius'
          return
        end if
      end do
      do k = 1, size(species)
        if (all(abs(radii - species(k)) > tolerance * species(k))) then
          write(message, '(a,es13.6,a)') 'holds no sphere of the deck''s radius ', species(k), &
               ' (&particles radius lists a species the file lacks)'
          return
        end if
      end do
    end associate
  end function radii_fault

  ! '' when the checkpoint's spheres (its /particles group) have the radii of parts, the run's:
  ! a mixture's checkpoint holds them (/particles/radius), equal spheres' the attribute radius.
  function radii_change(group, parts) result(message)
    integer(HID_T), intent(in) :: group
    type(particles_t), intent(in) :: parts
    character(len=200) :: message
    real(dp) :: stored(parts%n)
    integer :: err
    message = ''
    if (has_object(group, 'radius')) then
      call read_values(group, 'radius', stored, err)
      if (err /= 0) then
        message = 'dataset /particles/radius unreadable or of another size'
      else if (any(stored /= parts%radii)) then
        message = 'its spheres have other radii than the run''s (&particles radius, position_file): a restart '// &
                  'continues the checkpoint''s spheres'
      end if
    else if (any(parts%radii /= parts%radius)) then
      message = 'its spheres are of one size, the run''s a mixture (&particles radius)'
    end if
  end function radii_change

  ! h_r when the run has rough contacts (their start-gap rule), else 0.
  pure real(dp) function start_gap_roughness(cfg) result(h_r)
    type(config_t), intent(in) :: cfg
    h_r = 0.0_dp
    if (cfg%contact_group) h_r = cfg%contact%roughness * cfg%radius
  end function start_gap_roughness

  ! particles/position (N x 3) of an HDF5 file and, when the file has it, particles/radius (N).
  subroutine read_positions(path, position, radii, message)
    character(len=*), intent(in) :: path
    real(dp), allocatable, intent(out) :: position(:, :), radii(:)
    character(len=*), intent(out) :: message
    integer(HID_T) :: file
    integer(HSIZE_T) :: dims(2)
    integer :: err, rank
    logical :: exists
    message = ''
    call h5fopen_f(path, H5F_ACC_RDONLY_F, file, err)
    if (err /= 0) then
      message = 'cannot be opened as HDF5'
      return
    end if
    exists = has_object(file, 'particles')
    if (exists) exists = has_object(file, 'particles/position')
    if (.not. exists) then
      message = 'dataset missing'
      call h5fclose_f(file, err)
      return
    end if
    call dataset_dims(file, 'particles/position', rank, dims)
    if (rank /= 2 .or. dims(1) /= 3) then
      message = 'must be an N x 3 dataset'
    else
      allocate(position(3, dims(2)))
      call read_dataset(file, 'particles/position', position, err)
      if (err /= 0) message = 'cannot be read'
    end if
    if (len_trim(message) == 0) then
      if (has_object(file, 'particles/radius')) then
        allocate(radii(size(position, 2)))
        call read_values(file, 'particles/radius', radii, err)
        if (err /= 0) message = 'particles/radius must hold one radius per sphere of particles/position'
      end if
    end if
    call h5fclose_f(file, err)
  end subroutine read_positions

  ! Write /particles into a file open on every rank through MPI-IO (mod_h5_parallel; doc/DESIGN.md
  ! "Files"): position with attribute box, and with state = .true. everything an exact restart
  ! needs. Collective: every rank makes the same metadata calls (the group, the datasets and
  ! their attributes, with the replicated values), and each writes the columns of the spheres
  ! OWNED (global indices, unique over the ranks: owned_spheres) in one collective transfer per
  ! dataset; share (a rank's local set): its own spheres instead, under their global indices.
  ! message: '' or what failed, the same on every rank.
  subroutine particles_write(file, parts, box, state, owned, message, share)
    integer(HID_T), intent(in) :: file
    type(particles_t), intent(in) :: parts
    real(dp), intent(in) :: box(3)
    logical, intent(in) :: state
    integer, intent(in) :: owned(:)
    character(len=*), intent(out) :: message
    type(sphere_share_t), intent(in), optional :: share
    integer, allocatable :: slots(:)
    integer :: i
    if (present(share)) then
      slots = pack([(i, i = 1, share%set%n)], share%own)
      call write_group(share%set, slots, share%id(slots), share%total)
    else
      call write_group(parts, owned, owned, parts%n)
    end if
  contains
    ! The group from the spheres slots of p, rows (global indices) of n.
    subroutine write_group(p, slots, rows, n)
      type(particles_t), intent(in) :: p
      integer, intent(in) :: slots(:), rows(:), n
      integer(HID_T) :: group, dset
      integer :: err, e, attributes, mixture
      PetscErrorCode :: ierr
      message = ''
      call check_partition(rows, n)
      call h5gcreate_f(file, 'particles', group, err)
      call h5_parallel_agree(err)
      if (err /= 0) then
        message = 'cannot take the group /particles'
        return
      end if
      ! the attributes' failures, agreed once at the end (they are metadata, which every rank
      ! writes alike in its cache and rank 0 writes to the file)
      attributes = 0
      call particle_columns(group, 'position', p%position(:, slots), n, rows, message)
      if (len_trim(message) == 0) then
        call h5dopen_f(group, 'position', dset, err)
        attributes = max(attributes, abs(err))
        if (err == 0) then
          call write_attribute(dset, 'box', box, e)
          attributes = max(attributes, abs(e))
          call h5dclose_f(dset, e)
        end if
        call write_attribute(group, 'box', box, e)
        attributes = max(attributes, abs(e))
        call write_attribute(group, 'radius', [p%radius], e)
        attributes = max(attributes, abs(e))
      end if
      if (state .and. len_trim(message) == 0) then
        call particle_columns(group, 'velocity', p%velocity(:, slots), n, rows, message)
        call particle_columns(group, 'omega', p%omega(:, slots), n, rows, message)
        call particle_columns(group, 'velocity_prev', p%velocity_prev(:, slots), n, rows, message)
        call write_attribute(group, 'have_prev', [merge(1, 0, p%have_prev)], e)
        attributes = max(attributes, abs(e))
        call write_attribute(group, 'motion', [p%motion], e)
        attributes = max(attributes, abs(e))
        ! a mixture's radii, which a restart checks against its deck's (equal spheres: the
        ! attribute); every rank must take the same branch (a share may hold one species only)
        mixture = merge(1, 0, any(p%radii(slots) /= p%radius))
        call MPI_Allreduce(MPI_IN_PLACE, mixture, 1, MPI_INTEGER, MPI_MAX, PETSC_COMM_WORLD, ierr)
        if (mixture > 0) &
          call particle_columns(group, 'radius', reshape(p%radii(slots), [1, size(slots)]), n, rows, message)
        ! the ranks' local sets (a share: every rank's set holds them), for an exact restart on as
        ! many ranks (mod_particles)
        if (present(share) .and. p%sets_made_ranks > 0) then
          call particle_columns(group, 'sets_made_z', reshape(p%sets_made_z(slots), [1, size(slots)]), n, rows, &
                                message)
          call write_attribute(group, 'sets_made_ranks', [p%sets_made_ranks], e)
          attributes = max(attributes, abs(e))
        end if
      end if
      call h5gclose_f(group, err)
      attributes = max(attributes, abs(err))
      call h5_parallel_agree(attributes)
      if (attributes /= 0 .and. len_trim(message) == 0) message = 'cannot take the attributes of /particles'
    end subroutine write_group
  end subroutine particles_write

  ! The dataset /particles/NAME (k, n) from this rank's columns VALUES of the spheres OWNED, unless
  ! an earlier dataset failed (message set). Collective.
  subroutine particle_columns(group, name, values, n, owned, message)
    integer(HID_T), intent(in) :: group
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: values(:, :)
    integer, intent(in) :: n, owned(:)
    character(len=*), intent(inout) :: message
    integer :: err
    if (len_trim(message) > 0) return
    call h5_parallel_write_columns(group, name, n, owned, values, err)
    if (err /= 0) message = 'cannot take /particles/'//name
  end subroutine particle_columns

  ! Every one of the n spheres is written by exactly one rank: the ranks' counts add up to n
  ! (always: one reduction of an integer), and in a debug build (make debug) each sphere is
  ! counted once over the ranks (a reduction of n integers). A fault is the program's: stop.
  ! Collective.
  subroutine check_partition(owned, n)
    integer, intent(in) :: owned(:), n
    integer :: total
    PetscErrorCode :: ierr
#ifdef FDSUSP_DEBUG
    integer :: times(n)
#endif
    call MPI_Allreduce(size(owned), total, 1, MPI_INTEGER, MPI_SUM, PETSC_COMM_WORLD, ierr)
    call abort_if_any(total /= n .or. any(owned < 1 .or. owned > n), &
                      'internal error: the ranks own other spheres than the n of the particles (mod_particles_io)')
#ifdef FDSUSP_DEBUG
    times = 0
    times(owned) = times(owned) + 1
    call MPI_Allreduce(MPI_IN_PLACE, times, n, MPI_INTEGER, MPI_SUM, PETSC_COMM_WORLD, ierr)
    call abort_if_any(any(times /= 1), 'internal error: a sphere is written by more than one rank or by none '// &
                      '(mod_particles_io)')
#endif
  end subroutine check_partition

  ! The spheres this rank writes: RULE's (set by the program: checkpoint_state_t%owned_spheres) at
  ! the particles' positions, or, without a rule, every sphere on rank 0 and none elsewhere.
  function owned_spheres(rule, parts, box) result(owned)
    procedure(owned_spheres_rule), pointer, intent(in) :: rule
    type(particles_t), intent(in) :: parts
    real(dp), intent(in) :: box(3)
    integer, allocatable :: owned(:)
    integer :: i
    if (associated(rule)) then
      owned = rule(parts%position, box(3))
    else if (is_root()) then
      owned = [(i, i = 1, parts%n)]
    else
      allocate(owned(0))
    end if
  end function owned_spheres

  ! A particle snapshot for viewing: OUTDIR/particles_NNNNNNNN.h5 (/particles: position,
  ! velocity, omega, and radius per sphere for glyph scaling), written by every rank, each the
  ! spheres OWNED (owned_spheres; share, a rank's local set: its own spheres instead), and
  ! OUTDIR/particles.xmf, the XDMF time series of the snapshots written so far by this run
  ! (ParaView: open it, apply Glyph Sphere scaled by radius), written by rank 0. Collective.
  subroutine particles_snapshot(outdir, parts, box, step, time, owned, share)
    character(len=*), intent(in) :: outdir
    type(particles_t), intent(in) :: parts
    real(dp), intent(in) :: box(3)
    integer, intent(in) :: step
    real(dp), intent(in) :: time
    integer, intent(in) :: owned(:)
    type(sphere_share_t), intent(in), optional :: share
    integer, save :: nsnap = 0
    integer, allocatable, save :: steps(:)
    real(dp), allocatable, save :: times(:)
    integer(HID_T) :: file, group
    integer :: err, unit, k
    integer, allocatable :: slots(:)
    character(len=32) :: h5
    character(len=64) :: dims
    character(len=1100) :: path
    character(len=200) :: line, message
    character(len=:), allocatable :: doc
    character(len=1) :: nl
    ! (every rank keeps the list of snapshots, so that every rank skips the same ones)
    if (.not. allocated(steps)) allocate(steps(0), times(0))
    if (nsnap > 0) then
      if (steps(nsnap) == step) return          ! already written (last record of the run)
    end if
    write(h5, '(a,i8.8,a)') 'particles_', step, '.h5'
    ! written to .tmp and renamed: a snapshot on disk is whole (a full disk stops the run, naming it)
    path = trim(outdir)//'/'//trim(h5)
    ! a full disk stops every rank here, before the parallel write (mod_file_services)
    call require_free_space(outdir, 8.0_dp * 10 * parts%n, trim(path)//'.tmp')
    call h5_parallel_create(trim(path)//'.tmp', file, err)
    if (err /= 0) call write_failed_everywhere(path, 'cannot be created')
    if (present(share)) then
      slots = pack([(k, k = 1, share%set%n)], share%own)
      call particles_write(file, parts, box, .false., owned, message, share)
      if (len_trim(message) == 0) call more_columns(share%set, slots, share%id(slots))
    else
      call particles_write(file, parts, box, .false., owned, message)
      if (len_trim(message) == 0) call more_columns(parts, owned, owned)
    end if
    if (len_trim(message) > 0) call write_failed_everywhere(path, trim(message))
    call h5_parallel_close(file, err)
    if (err /= 0) call write_failed_everywhere(path, 'cannot be completed (closing it failed)')
    nsnap = nsnap + 1
    steps = [steps, step]
    times = [times, time]
    ! every rank has closed the file: rank 0 publishes it and writes the index
    if (.not. is_root()) return
    err = publish_file(trim(path)//'.tmp', path)
    if (err /= 0) call write_failed(path, 'cannot be published ('//errno_text(err)//')')
    write(dims, '(i0,a)') parts%n, ' 3'
    ! the XDMF index, assembled whole and written with one checked statement
    nl = new_line('a')
    doc = '<?xml version="1.0" ?>'//nl//'<Xdmf Version="2.0">'//nl//' <Domain>'//nl// &
          '  <Grid Name="particles" GridType="Collection" CollectionType="Temporal">'//nl
    do k = 1, nsnap
      write(h5, '(a,i8.8,a)') 'particles_', steps(k), '.h5'
      write(line, '(a,i0,a)') '   <Grid Name="step ', steps(k), '" GridType="Uniform">'
      doc = doc//trim(line)//nl
      write(line, '(a,es23.15,a)') '    <Time Value="', times(k), '"/>'
      doc = doc//trim(line)//nl
      write(line, '(a,i0,a)') '    <Topology TopologyType="Polyvertex" NumberOfElements="', parts%n, '"/>'
      doc = doc//trim(line)//nl//'    <Geometry GeometryType="XYZ">'//nl
      doc = doc//'     <DataItem Dimensions="'//trim(dims)//'" NumberType="Float" Precision="8" Format="HDF">'// &
            trim(h5)//':/particles/position</DataItem>'//nl//'    </Geometry>'//nl
      call attribute('velocity', 'Vector', dims)
      call attribute('omega', 'Vector', dims)
      write(line, '(i0,a)') parts%n, ' 1'
      call attribute('radius', 'Scalar', line)
      doc = doc//'   </Grid>'//nl
    end do
    doc = doc//'  </Grid>'//nl//' </Domain>'//nl//'</Xdmf>'//nl
    path = trim(outdir)//'/particles.xmf'
    open(newunit=unit, file=trim(path)//'.tmp', status='replace', action='write', access='stream', &
         form='unformatted', iostat=err)
    if (err /= 0) call write_failed(path, 'cannot be created')
    write(unit, iostat=err) doc
    if (err == 0) flush(unit, iostat=err)
    close(unit, iostat=k)
    if (err /= 0 .or. k /= 0) call write_failed(path, 'cannot be written')
    err = publish_file(trim(path)//'.tmp', path)
    if (err /= 0) call write_failed(path, 'cannot be published ('//errno_text(err)//')')
  contains
    subroutine attribute(name, kind, shape)
      character(len=*), intent(in) :: name, kind, shape
      doc = doc//'    <Attribute Name="'//name//'" AttributeType="'//kind//'" Center="Node">'//nl// &
            '     <DataItem Dimensions="'//trim(shape)//'" NumberType="Float" Precision="8" Format="HDF">'// &
            trim(h5)//':/particles/'//name//'</DataItem>'//nl//'    </Attribute>'//nl
    end subroutine attribute

    ! velocity, omega and radius of the spheres slots of p, rows (global indices) of parts%n
    subroutine more_columns(p, slots, rows)
      type(particles_t), intent(in) :: p
      integer, intent(in) :: slots(:), rows(:)
      call h5gopen_f(file, 'particles', group, err)
      call h5_parallel_agree(err)
      if (err /= 0) message = 'cannot take /particles'
      call particle_columns(group, 'velocity', p%velocity(:, slots), parts%n, rows, message)
      call particle_columns(group, 'omega', p%omega(:, slots), parts%n, rows, message)
      call particle_columns(group, 'radius', reshape(p%radii(slots), [1, size(slots)]), parts%n, rows, message)
      if (err == 0) call h5gclose_f(group, err)
    end subroutine more_columns
  end subroutine particles_snapshot

  ! A write of a particle file failed: stop the run naming the file and the cause.
  subroutine write_failed(path, what)
    character(len=*), intent(in) :: path, what
    call abort_run(trim(path)//' '//what//': '//write_failure_cause(directory_of(path), 0.0_dp))
  end subroutine write_failed

  ! A collective write of a particle file failed (every rank knows it): stop the run naming the
  ! file and the cause (rank 0 prints, every rank stops).
  subroutine write_failed_everywhere(path, what)
    character(len=*), intent(in) :: path, what
    call abort_if_any(.true., trim(path)//' '//what//': '//write_failure_cause(directory_of(path), 0.0_dp))
  end subroutine write_failed_everywhere

  ! Restart: positions, velocities and history from a checkpoint (collective). The particle count
  ! must match the deck's.
  subroutine particles_read_state(path, parts)
    character(len=*), intent(in) :: path
    type(particles_t), intent(inout) :: parts
    integer(HID_T) :: file, group
    integer(HSIZE_T) :: fdims(2)
    real(dp) :: buffer(3, parts%n, 4), sets_z(1, parts%n)
    integer :: err, e, flag(1), ierr, rank, sets_ranks(1)
    character(len=200) :: message
    character(len=16), parameter :: names(4) = [character(len=16) :: 'position', 'velocity', 'omega', &
         'velocity_prev']
    message = ''
    flag = 0
    sets_ranks = 0
    sets_z = 0.0_dp
    if (is_root()) then
      call h5fopen_f(path, H5F_ACC_RDONLY_F, file, err)
      if (.not. has_object(file, 'particles')) then
        message = 'the checkpoint holds no particles but the deck has some'
      else
        call h5gopen_f(file, 'particles', group, err)
        do e = 1, 4
          call dataset_dims(group, trim(names(e)), rank, fdims)
          if (rank == 0) then
            message = 'dataset /particles/'//trim(names(e))//' missing'
            exit
          end if
          if (rank /= 2 .or. any(fdims /= [3_HSIZE_T, int(parts%n, HSIZE_T)])) then
            write(message, '(a,i0,a,i0)') 'the checkpoint has ', fdims(2), ' particles, the deck ', parts%n
            exit
          end if
          call read_dataset(group, trim(names(e)), buffer(:, :, e), err)
          if (err /= 0) message = 'cannot read /particles/'//trim(names(e))
        end do
        call read_attribute(group, 'have_prev', flag, err)
        if (len_trim(message) == 0) message = radii_change(group, parts)
        ! the ranks' local sets of the run that wrote it (absent: none, or an older checkpoint)
        if (len_trim(message) == 0) then
          call dataset_dims(group, 'sets_made_z', rank, fdims)
          if (rank == 2 .and. all(fdims == [1_HSIZE_T, int(parts%n, HSIZE_T)])) then
            call read_dataset(group, 'sets_made_z', sets_z, err)
            if (err == 0) call read_attribute(group, 'sets_made_ranks', sets_ranks, err)
            if (err /= 0) message = 'cannot read /particles/sets_made_z'
          end if
        end if
        call h5gclose_f(group, err)
      end if
      call h5fclose_f(file, err)
    end if
    call file_error_from_root(path, 'particles', message)
    call MPI_Bcast(buffer, size(buffer), MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
    call MPI_Bcast(flag, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
    call MPI_Bcast(sets_ranks, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
    parts%sets_made_ranks = sets_ranks(1)
    if (allocated(parts%sets_made_z)) deallocate(parts%sets_made_z)
    if (sets_ranks(1) > 0) then
      call MPI_Bcast(sets_z, size(sets_z), MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
      parts%sets_made_z = sets_z(1, :)
    end if
    parts%position = buffer(:, :, 1)
    parts%velocity = buffer(:, :, 2)
    parts%omega = buffer(:, :, 3)
    parts%velocity_prev = buffer(:, :, 4)
    parts%have_prev = (flag(1) == 1)
  end subroutine particles_read_state

end module mod_particles_io
