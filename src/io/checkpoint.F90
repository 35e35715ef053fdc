! Checkpoints: the complete state of a run in one HDF5 file, for an exact restart.
!   datasets  /u /v /w (face velocities u^n), /p (p^{n-1/2}), /phi (last pressure increment, the
!             warm start of the next Poisson solve: without it a restart would iterate from
!             another guess and differ at the solver tolerance)
!             /u_star /v_star /w_star, /u_star_old ... (the provisional velocities u*^n, u*^{n-1}
!             whose extrapolation starts the next viscous solves, mod_fluid; for the same reason)
!             with the attribute star_history (how many of them are set, 0-2); a checkpoint
!             without them (written before 2026-11-25) restarts from u^n, at the solver tolerance
!             with particles also /lambda_u /lambda_v /lambda_w (the fictitious-domain force
!             density Lambda^n, a source of the next fluid step) and the group /particles
!             (mod_particles_io: positions with attribute box, velocities, Adams-Bashforth history)
!             with contacts also the group /contacts (mod_contacts_io: the tangential springs)
!             with statistics (&rheology) also /rheology/accumulators (mod_rheology::rheo_state)
!             and the attributes rheology_window (discard_step, block_steps) and rheology_core
!             (y_lo, y_hi of the core [a]): the window the accumulators were taken over
!             and the attributes rheology_shells (the pair and contact shells of g(theta) [a]) and
!             rheology_sampling (series_every: the records the statistics take)
!   attributes format_version, step, time, cells, box, walls, reynolds, dt, shear_rate, star_history,
!             fluid_resolved (1, or 0 for lubrication dynamics, which writes no fields), and
!             with Lees-Edwards boundaries lees_edwards_offset (the boundary offset delta, exactly);
!             shear_protocol_state (mod_shear_protocol: time, strain, accumulated |strain|, sign,
!             reversals, last rate of the imposed shear, exactly; doc/INPUT.md "&shear")
!   group /deck: the deck's variables, one attribute each (mod_restart_deck), which a restart
!             compares with its own deck before any work (doc/INPUT.md "Restart")
! Checksums: every dataset written through mod_h5util or mod_h5_parallel (particles, contacts,
! statistics) carries HDF5's Fletcher-32 filter; the fields, written by PETSc's viewer (which sets
! no filter), carry the attribute checksum (checksum_continue, over the file's content, so
! independent of the number of
! ranks). A restart reads every dataset once before any work (verify_datasets): a flipped bit
! stops it naming the dataset. Checkpoints written before 2026-11-27 have no checksums: they are
! read, and the log says their data could not be verified.
! What a file holds is what the run has: one checkpoint_state_t, set up once by the program,
! names the pieces (fluid, Lambda, particles, contact history, statistics, offset) for the
! checkpoints, the restart and failed_state.h5 alike.
! Written in parallel to NAME.tmp: the fields by PETSc's HDF5 viewer, then the per-sphere datasets
! of /particles by every rank through MPI-IO (mod_particles_io, mod_h5_parallel), with the ranks'
! local sets the springs of /contacts too (mod_contacts_io, contacts_write_shares), and the fields'
! checksums with every rank reading a share of each field's rows (the sums of the shares joined in
! the file's order: joined_sums); completed by rank 0 (attributes, a replicated /contacts,
! /rheology), flushed to disk and renamed over NAME: the previous checkpoint survives until the new one is whole. A
! restart verifies the fields the same way, in parallel, before rank 0 inspects the rest.
#include <petsc/finclude/petscdmda.h>
module mod_checkpoint
  use petscdmda
  use hdf5
  use, intrinsic :: iso_c_binding, only: c_loc, c_ptr
  use, intrinsic :: iso_fortran_env, only: int64
  use mod_kinds, only: dp
  use mod_params, only: config_t
  use mod_grid, only: grid_t, FIELD_U, FIELD_V, FIELD_W, field_names
  use mod_fluid, only: fluid_t
  use mod_h5util, only: write_attribute, read_attribute, write_string_attribute, has_object, dataset_dims, &
                        write_dataset, read_dataset, has_attribute
  use mod_os_services, only: publish_file
  use mod_file_services, only: require_free_space, write_failure_cause, errno_text, remove_file, directory_of
  use mod_errors, only: is_root, abort_run, abort_if_any, file_error_from_root, input_error, log_line
  use mod_restart_deck, only: deck_record, deck_compare
  use mod_particles, only: particles_t, sphere_share_t
  use mod_particles_io, only: particles_write, particles_read_state, owned_spheres, owned_spheres_rule
  use mod_h5_parallel, only: h5_parallel_create, h5_parallel_open, h5_parallel_close
  use mod_contact, only: contact_history_t
  use mod_contacts_io, only: contacts_write, contacts_write_shares, contacts_read
  use mod_rheology, only: rheology_t, rheo_state, rheo_restore
  use mod_shear_protocol, only: shear_protocol_t, shear_protocol_state, shear_protocol_restore, shear_protocol_varies, &
                                PROTOCOL_STATE_SIZE
  implicit none
  private
  public :: checkpoint_state_t, checkpoint_write, checkpoint_check, checkpoint_read, checkpoint_format_version

  integer, parameter :: checkpoint_format_version = 1
  character(len=*), parameter :: field_datasets(5) = ['u  ', 'v  ', 'w  ', 'p  ', 'phi']

  ! The state of a run, as its checkpoints hold it: each piece associated when the run has it. One
  ! bundle, set up once by the program, serves the checkpoints, the restart and the failed state,
  ! so that all three carry the same pieces.
  type :: checkpoint_state_t
    type(fluid_t), pointer :: fl => null()                  ! the resolved fluid (none in lubrication dynamics)
    Vec, pointer :: lambda(:) => null()                     ! Lambda on the u, v, w faces (fluid and particles)
    type(particles_t), pointer :: parts => null()           ! the particles
    type(contact_history_t), pointer :: history => null()   ! the contacts' springs (with the particles)
    type(rheology_t), pointer :: rh => null()               ! &rheology: its accumulators (rheo_state)
    real(dp), pointer :: offset => null()                   ! the Lees-Edwards offset (y_boundary = 'lees-edwards')
    type(shear_protocol_t), pointer :: protocol => null()   ! the imposed shear's state (&shear)
    ! the spheres whose rows of the per-sphere datasets each rank writes (mod_particles_io;
    ! absent: rank 0 writes them all)
    procedure(owned_spheres_rule), pointer, nopass :: owned_spheres => null()
  end type checkpoint_state_t

contains

  ! The checkpoint of STATE at step and time, published as PATH once whole. share (lubrication
  ! dynamics on several ranks, mod_ld_local): the spheres are each rank's local set, not
  ! state%parts, and state%history holds the springs of its own spheres' pairs; the file is the
  ! same.
  subroutine checkpoint_write(path, cfg, state, step, time, ierr, share)
    character(len=*), intent(in) :: path
    type(config_t), intent(in) :: cfg
    type(checkpoint_state_t), intent(in) :: state
    integer, intent(in) :: step
    real(dp), intent(in) :: time
    PetscErrorCode, intent(out) :: ierr
    type(sphere_share_t), intent(in), optional :: share
    PetscViewer :: viewer
    integer(HID_T) :: file, group
    integer :: err, k, stars, unsigned
    logical :: failed
    character(len=400) :: item, message
    character(len=1100) :: tmp, dir
    PetscInt :: length
    real(dp) :: bytes, particle_bytes
    Vec, allocatable :: fields(:)
    character(len=16), allocatable :: stand_in(:)
    real(dp), allocatable :: statistics(:)

    tmp = trim(path)//'.tmp'
    dir = directory_of(path)
    stars = 0
    ! the per-sphere datasets (position, velocity, omega, velocity_prev, a mixture's radius)
    particle_bytes = 0.0_dp
    if (associated(state%parts)) particle_bytes = 8.0_dp * 13 * state%parts%n
    if (associated(state%fl)) then
      fields = field_vectors(state, .true., stand_in)
      ! a full disk must stop every rank here, before the parallel write (mod_file_services)
      bytes = particle_bytes
      do k = 1, size(fields)
        PetscCall(VecGetSize(fields(k), length, ierr))
        bytes = bytes + 8.0_dp * length
      end do
      call require_free_space(dir, bytes, tmp)
      PetscCall(PetscViewerHDF5Open(PETSC_COMM_WORLD, trim(tmp), FILE_MODE_WRITE, viewer, ierr))
      ! every rank writes its slab in one collective MPI-IO transfer (issue 45; doc/DESIGN.md "Files")
      PetscCall(PetscViewerHDF5SetCollective(viewer, PETSC_TRUE, ierr))
      do k = 1, size(fields)
        if (len_trim(stand_in(k)) > 0) then
          ! the zeros of u*^{n-1} of the direct solves, which keep none (mod_fluid)
          PetscCall(VecSet(fields(k), 0.0_dp, ierr))
          PetscCall(PetscObjectSetName(fields(k), trim(stand_in(k)), ierr))
        end if
        PetscCall(VecView(fields(k), viewer, ierr))
      end do
      PetscCall(PetscViewerDestroy(viewer, ierr))
      stars = state%fl%star_history
    else
      call require_free_space(dir, particle_bytes, tmp)
    end if

    ! The per-sphere datasets: every rank reopens the file through MPI-IO (or makes it, without
    ! fields) and writes the rows of the spheres it owns, collectively (doc/DESIGN.md "Files");
    ! the file is closed on every rank before rank 0 completes it below.
    if (associated(state%fl)) then
      call h5_parallel_open(trim(tmp), file, err)
      if (err /= 0) call write_failed_everywhere('cannot be reopened for the particles')
    else
      call h5_parallel_create(trim(tmp), file, err)
      if (err /= 0) call write_failed_everywhere('cannot be created')
    end if
    if (associated(state%parts)) then
      if (present(share)) then
        call particles_write(file, state%parts, cfg%domain%box, .true., [integer ::], message, share)
      else
        call particles_write(file, state%parts, cfg%domain%box, .true., &
                             owned_spheres(state%owned_spheres, state%parts, cfg%domain%box), message)
      end if
      if (len_trim(message) > 0) call write_failed_everywhere(trim(message))
      ! the springs: from the ranks' shares every rank writes a run of the rows (rank 0 writes the
      ! replicated history below)
      if (associated(state%history) .and. present(share)) then
        call contacts_write_shares(file, state%history, share%id, share%own, share%total, message)
        if (len_trim(message) > 0) call write_failed_everywhere(trim(message))
      end if
    end if
    ! the fields' checksums, each rank reading a share of their rows (no rank holds a field)
    unsigned = 0
    item = ''
    message = ''
    call walk_datasets(file, '/', .true., item, message, unsigned, fields=.true.)
    if (len_trim(message) > 0) call write_failed_everywhere('cannot sign '//trim(item)//': '//trim(message))
    call h5_parallel_close(file, err)
    if (err /= 0) call write_failed_everywhere('cannot be completed (closing it failed)')

    ! The rest by rank 0 alone: the signatures of the datasets, the attributes, the replicated
    ! contact history and the statistics; then the file is published.
    if (is_root()) then
      call h5fopen_f(trim(tmp), H5F_ACC_RDWR_F, file, err)
      if (err /= 0) call write_failed('cannot be reopened to complete the checkpoint')
      failed = .false.
      ! the other datasets: the particles', written with Fletcher-32, are read and so verified
      unsigned = 0
      item = ''
      message = ''
      call walk_datasets(file, '/', .true., item, message, unsigned, fields=.false.)
      if (len_trim(message) > 0) call abort_run('cannot sign '//trim(item)//' of '//trim(tmp)//': '//trim(message))
      call put_int('format_version', [checkpoint_format_version])
      call put_int('step', [step])
      call put_real('time', [time])
      call put_int('cells', cfg%cells)
      call put_real('box', cfg%domain%box)
      call put_int('walls', [merge(1, 0, cfg%walls)])
      call put_real('reynolds', [cfg%fluid%reynolds])
      call put_real('dt', [cfg%time%dt])
      call put_real('shear_rate', [cfg%domain%shear_rate])
      call write_string_attribute(file, 'program', 'fdsusp', err)
      failed = failed .or. err /= 0
      call put_int('star_history', [stars])
      call put_int('fluid_resolved', [merge(1, 0, associated(state%fl))])
      if (associated(state%offset)) call put_real('lees_edwards_offset', [state%offset])
      if (associated(state%protocol)) call put_real('shear_protocol_state', shear_protocol_state(state%protocol))
      if (associated(state%parts)) then
        call deck_record(file, cfg, state%parts%n, err)
      else
        call deck_record(file, cfg, 0, err)
      end if
      failed = failed .or. err /= 0
      if (associated(state%parts)) then
        if (associated(state%history) .and. .not. present(share)) &
          call contacts_write(file, state%history, state%parts%n)
      end if
      if (associated(state%rh)) then
        call put_int('rheology_window', [state%rh%discard_step, state%rh%block_steps])
        call put_real('rheology_core', state%rh%core)
        call put_real('rheology_shells', [state%rh%r_outer, state%rh%r_contact])
        call put_int('rheology_sampling', [cfg%output%series_every])
        statistics = rheo_state(state%rh)
        call h5gcreate_f(file, 'rheology', group, err)
        if (err == 0) call write_dataset(group, 'accumulators', reshape(statistics, [size(statistics), 1]), err)
        if (err /= 0) call write_failed('cannot take /rheology/accumulators')
        call h5gclose_f(group, err)
      end if
      call h5fclose_f(file, err)
      if (failed .or. err /= 0) call write_failed('cannot take its attributes (or closing it failed)')
      err = publish_file(tmp, path)
      if (err /= 0) call write_failed('cannot be renamed to '//trim(path)//' ('//errno_text(err)//')')
    end if
    call MPI_Barrier(PETSC_COMM_WORLD, ierr)

  contains

    ! A write of the checkpoint failed (rank 0): the partial .tmp goes, the last checkpoint stays.
    subroutine write_failed(what)
      character(len=*), intent(in) :: what
      integer :: e
      e = remove_file(tmp)
      call abort_run(trim(tmp)//' '//what//': '//write_failure_cause(dir, 0.0_dp)//'; the last checkpoint, '// &
                     trim(path)//', is kept')
    end subroutine write_failed

    ! A collective write of the checkpoint failed (every rank knows it): rank 0 removes the partial
    ! .tmp, the last checkpoint stays, every rank stops.
    subroutine write_failed_everywhere(what)
      character(len=*), intent(in) :: what
      integer :: e
      if (is_root()) e = remove_file(tmp)
      call abort_if_any(.true., trim(tmp)//' '//what//': '//write_failure_cause(dir, 0.0_dp)// &
                        '; the last checkpoint, '//trim(path)//', is kept')
    end subroutine write_failed_everywhere

    subroutine put_int(name, values)
      character(len=*), intent(in) :: name
      integer, intent(in) :: values(:)
      call write_attribute(file, name, values, err)
      failed = failed .or. err /= 0
    end subroutine put_int

    subroutine put_real(name, values)
      character(len=*), intent(in) :: name
      real(dp), intent(in) :: values(:)
      call write_attribute(file, name, values, err)
      failed = failed .or. err /= 0
    end subroutine put_real
  end subroutine checkpoint_write

  ! The vectors of the fluid in the file's order (the datasets are named by the vectors):
  ! u, v, w, p, phi, with stars the provisional velocities u*^n, u*^{n-1} of each component, and
  ! with particles Lambda. One list for the write and the read. The direct solves keep no u*^{n-1}
  ! (mod_fluid): its place holds the fluid's work vector div_star, and stand_in(k) names the
  ! dataset it stands in for (blank for the vectors that are themselves).
  function field_vectors(state, stars, stand_in) result(v)
    type(checkpoint_state_t), intent(in) :: state
    logical, intent(in) :: stars
    character(len=16), allocatable, intent(out) :: stand_in(:)
    Vec, allocatable :: v(:)
    integer :: c
    v = [state%fl%vel(FIELD_U:FIELD_W), state%fl%pressure, state%fl%phi]
    if (stars) then
      do c = FIELD_U, FIELD_W
        if (state%fl%direct) then
          v = [v, state%fl%vel_star(c), state%fl%div_star]
        else
          v = [v, state%fl%vel_star(c), state%fl%vel_star_old(c)]
        end if
      end do
    end if
    if (associated(state%lambda)) v = [v, state%lambda]
    allocate(stand_in(size(v)))
    stand_in = ''
    if (stars .and. state%fl%direct) then
      do c = FIELD_U, FIELD_W
        stand_in(5 + 2 * c) = field_names(c)//'_star_old'
      end do
    end if
  end function field_vectors

  ! Before any work: is PATH a checkpoint of this scene, run with this deck's physics (doc/INPUT.md
  ! "Restart")? Returns its step and time. Rank 0 inspects the file, every rank learns the verdict,
  ! and a bad file stops the run with a message naming the file and the item at fault, or the
  ! group and the variable of the deck that differs from the checkpoint's. rh: the run's
  ! statistics (&rheology), whose window must fit the checkpoint's accumulators.
  subroutine checkpoint_check(path, cfg, particles, branch, step, time, rh)
    character(len=*), intent(in) :: path
    type(config_t), intent(in) :: cfg
    integer, intent(in) :: particles        ! the run's particle count (0: none)
    logical, intent(in) :: branch           ! -branch: this deck's contact and lubrication physics
    integer, intent(out) :: step
    real(dp), intent(out) :: time
    type(rheology_t), intent(in), optional :: rh
    character(len=400) :: item
    character(len=2000) :: message
    character(len=16) :: group
    character(len=40) :: variable
    real(dp) :: values(2)
    PetscErrorCode :: ierr

    item = ''
    message = ''
    group = ''
    variable = ''
    values = 0.0_dp
    ! the fields against their checksums first, each rank reading a share of their rows (a file
    ! that cannot be opened so is left to inspect, which names what is wrong with it)
    call verify_fields(path, item, message)
    if (is_root() .and. len_trim(message) == 0) &
      call inspect(path, cfg, particles, branch, item, message, values, group, variable, rh)
    call MPI_Bcast(item, len(item), MPI_CHARACTER, 0, PETSC_COMM_WORLD, ierr)
    call MPI_Bcast(group, len(group), MPI_CHARACTER, 0, PETSC_COMM_WORLD, ierr)
    call MPI_Bcast(variable, len(variable), MPI_CHARACTER, 0, PETSC_COMM_WORLD, ierr)
    if (len_trim(group) > 0) then
      call MPI_Bcast(message, len(message), MPI_CHARACTER, 0, PETSC_COMM_WORLD, ierr)
      if (len_trim(message) > 0) call input_error(path, group, variable, message)
    end if
    call file_error_from_root(path, item, message)
    call MPI_Bcast(values, 2, MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
    step = nint(values(1))
    time = values(2)
  end subroutine checkpoint_check

  ! The grid fields of the checkpoint PATH against their checksum attributes, every rank reading
  ! a share of each field's rows (walk_datasets with fields): item and message say the first
  ! that fails, the same on every rank; nothing when the file cannot be opened through MPI-IO.
  ! Collective.
  subroutine verify_fields(path, item, message)
    character(len=*), intent(in) :: path
    character(len=*), intent(out) :: item, message
    integer(HID_T) :: file
    integer :: err, unverified
    item = ''
    message = ''
    call h5_parallel_open(path, file, err, read_only=.true.)
    if (err /= 0) return
    unverified = 0
    call walk_datasets(file, '/', .false., item, message, unverified, fields=.true.)
    call h5_parallel_close(file, err)
  end subroutine verify_fields

  subroutine inspect(path, cfg, particles, branch, item, message, values, group, variable, rh)
    character(len=*), intent(in) :: path
    type(config_t), intent(in) :: cfg
    integer, intent(in) :: particles
    logical, intent(in) :: branch
    character(len=*), intent(out) :: item, message
    real(dp), intent(out) :: values(2)
    character(len=*), intent(out) :: group, variable
    type(rheology_t), intent(in), optional :: rh
    integer(HID_T) :: file, dset, space
    integer(HSIZE_T) :: dims(3), maxdims(3), pdims(2)
    integer :: err, version(1), cells(3), walls(1), istep(1), rank, d, n_saved, resolved(1), afresh, unverified
    character(len=200) :: line
    real(dp) :: box(3), t(1)
    logical :: exists, springs

    item = ''
    message = ''
    group = ''
    variable = ''
    values = 0.0_dp
    inquire(file=path, exist=exists)
    if (.not. exists) then
      message = 'the checkpoint does not exist'
      return
    end if
    call h5fopen_f(path, H5F_ACC_RDONLY_F, file, err)
    if (err /= 0) then
      message = 'cannot be opened as HDF5: the file is truncated or is not a checkpoint'
      return
    end if
    call read_attribute(file, 'format_version', version, err)
    if (err /= 0) then
      item = 'format_version'
      message = 'missing: not an fdsusp checkpoint'
    else if (version(1) /= checkpoint_format_version) then
      item = 'format_version'
      write(message, '(a,i0,a,i0)') 'this program reads checkpoint format ', checkpoint_format_version, &
           ', the file has format ', version(1)
    end if
    if (len_trim(message) == 0) then
      resolved = 1
      if (has_attribute(file, 'fluid_resolved')) call read_attribute(file, 'fluid_resolved', resolved, err)
      if ((resolved(1) == 1) .neqv. cfg%resolved) then
        item = 'fluid_resolved'
        message = 'the checkpoint and the deck disagree on &fluid model (resolved or none)'
      else if (has_attribute(file, 'lees_edwards_offset') .neqv. cfg%lees_edwards) then
        item = 'lees_edwards_offset'
        message = 'the checkpoint and the deck disagree on &domain y_boundary = ''lees-edwards'''
      end if
    end if
    if (len_trim(message) == 0 .and. cfg%resolved) then
      call read_attribute(file, 'cells', cells, err)
      if (err /= 0) then
        item = 'cells'; message = 'missing'
      else if (any(cells /= cfg%cells)) then
        item = 'cells'
        write(message, '(a,3(i0,:,"x"),a,3(i0,:,"x"))') 'the checkpoint grid has ', cells, &
             ' cells, the deck asks for ', cfg%cells
      end if
    end if
    if (len_trim(message) == 0) then
      call read_attribute(file, 'box', box, err)
      if (err /= 0) then
        item = 'box'; message = 'missing'
      else if (any(abs(box - cfg%domain%box) > 1.0e-12_dp * cfg%domain%box)) then
        item = 'box'
        write(message, '(a,3f10.4,a,3f10.4)') 'the checkpoint box is', box, ', the deck asks for', cfg%domain%box
      end if
    end if
    if (len_trim(message) == 0) then
      call read_attribute(file, 'walls', walls, err)
      if (err /= 0) then
        item = 'walls'; message = 'missing'
      else if ((walls(1) == 1) .neqv. cfg%walls) then
        item = 'walls'; message = 'the checkpoint and the deck disagree on &domain y_boundary'
      end if
    end if
    if (len_trim(message) == 0) then
      call read_attribute(file, 'step', istep, err)
      if (err == 0) call read_attribute(file, 'time', t, err)
      if (err /= 0) then
        item = 'step'; message = 'step or time missing'
      else
        values = [real(istep(1), dp), t(1)]
      end if
    end if
    do d = 1, size(field_datasets)
      if (len_trim(message) > 0 .or. .not. cfg%resolved) exit
      if (.not. has_object(file, trim(field_datasets(d)))) then
        item = '/'//trim(field_datasets(d)); message = 'dataset missing'
        exit
      end if
      call h5dopen_f(file, trim(field_datasets(d)), dset, err)
      call h5dget_space_f(dset, space, err)
      call h5sget_simple_extent_ndims_f(space, rank, err)
      if (rank == 3) call h5sget_simple_extent_dims_f(space, dims, maxdims, err)
      call h5sclose_f(space, err)
      call h5dclose_f(dset, err)
      ! PETSc writes nz x ny x nx (C order), which HDF5's Fortran API reports reversed: nx, ny, nz
      if (rank /= 3 .or. any(dims /= int(cfg%cells, HSIZE_T))) then
        item = '/'//trim(field_datasets(d)); message = 'dataset of the wrong shape for this grid'
      end if
    end do
    ! the particles must be the deck's: the same count (the state, lambda and history follow them)
    if (len_trim(message) == 0) then
      n_saved = 0
      if (has_object(file, 'particles')) then
        call dataset_dims(file, 'particles/position', rank, pdims)
        if (rank == 2) n_saved = int(pdims(2))
      end if
      if (n_saved /= particles) then
        item = '/particles'
        write(message, '(a,i0,a,i0,a)') 'the checkpoint holds ', n_saved, ' particles, the deck ', particles, &
             ': restart with the deck that wrote it'
      end if
    end if
    ! contacts: the springs are there exactly when the checkpoint's run had contacts; a branch may
    ! add or drop them (its contacts start without springs, or the springs are not read)
    if (len_trim(message) == 0 .and. particles > 0) then
      springs = has_object(file, 'contacts')
      if (branch .and. (springs .neqv. cfg%contact_group)) then
        if (springs) call log_line('branch: the checkpoint''s run had contacts, this one has none (&contact absent)')
        if (.not. springs) call log_line('branch: the checkpoint''s run had no contacts; this one''s start '// &
                                         'without tangential springs')
      else if (springs .neqv. cfg%contact_group) then
        group = 'contact'
        if (springs) then
          message = 'the checkpoint''s run had contacts (its springs are in /contacts), the deck "'// &
                    trim(cfg%deck_file)//'" has no &contact group: a restart continues the checkpoint''s physics '// &
                    '(or branch from the checkpoint: -branch CHECKPOINT)'
        else
          message = 'the checkpoint''s run had no contacts (no /contacts), the deck "'//trim(cfg%deck_file)// &
                    '" has a &contact group: a restart continues the checkpoint''s physics (or branch from the '// &
                    'checkpoint: -branch CHECKPOINT)'
        end if
      end if
    end if
    ! every other input that sets the physics (mod_restart_deck)
    if (len_trim(message) == 0) call deck_compare(file, cfg, particles, branch, group, variable, message)
    ! the data: every dataset read once, against its checksum
    if (len_trim(message) == 0) then
      unverified = 0
      call walk_datasets(file, '/', .false., item, message, unverified, fields=.false.)
      if (len_trim(message) == 0 .and. unverified > 0) then
        write(line, '(i0,a)') unverified, ' datasets of the checkpoint carry no checksum (written before '// &
             '2026-11-27): their data cannot be verified'
        call log_line('restart: '//trim(line))
      end if
    end if
    ! the statistics: the deck's window against the checkpoint's accumulators
    if (len_trim(message) == 0 .and. present(rh)) then
      call rheology_verdict(file, rh, cfg%output%series_every, message, group, variable, afresh)
      if (len_trim(message) > 0 .and. len_trim(group) == 0) item = 'rheology/accumulators'
    else if (len_trim(message) == 0) then
      if (has_object(file, 'rheology')) &
        call log_line('restart: the checkpoint''s statistics are not continued: the deck has no &rheology')
    end if
    call h5fclose_f(file, err)
  end subroutine inspect

  ! Every dataset under GROUP (whose path is PREFIX), recursively, read through (in blocks of at
  ! most 2^16 values, check_dataset): the read verifies the Fletcher-32 checksum of a dataset that
  ! has one, and the values are compared with the checksum attribute of one that has it. sign:
  ! instead, give every dataset without Fletcher-32 its checksum attribute (checkpoint_write). A
  ! fault sets item (the dataset's path) and message; unverified counts the datasets with neither
  ! checksum. fields: only the arrays without Fletcher-32 (PETSc's grid fields), each rank reading
  ! a share of their rows, collectively: every rank of PETSC_COMM_WORLD walks the file opened
  ! through MPI-IO; else only the other datasets, by one rank (the fields without a checksum
  ! counted in unverified).
  recursive subroutine walk_datasets(group, prefix, sign, item, message, unverified, fields)
    integer(HID_T), intent(in) :: group
    character(len=*), intent(in) :: prefix
    logical, intent(in) :: sign
    character(len=*), intent(inout) :: item, message
    integer, intent(inout) :: unverified
    logical, intent(in) :: fields
    integer :: storage, nlinks, max_corder, err, k, kind
    integer(HSIZE_T) :: index
    integer(SIZE_T) :: length
    integer(HID_T) :: object
    character(len=256) :: name
    call h5gget_info_f(group, storage, nlinks, max_corder, err)
    if (err /= 0) then
      item = prefix
      message = 'cannot be listed: the file is damaged'
      return
    end if
    do k = 0, nlinks - 1
      if (len_trim(message) > 0) return
      index = k
      call h5lget_name_by_idx_f(group, '.', H5_INDEX_NAME_F, H5_ITER_INC_F, index, name, err, length)
      if (err == 0) call h5oopen_f(group, trim(name), object, err)
      if (err /= 0) then
        item = prefix//trim(name)
        message = 'cannot be opened: the file is damaged'
        return
      end if
      call h5iget_type_f(object, kind, err)
      if (kind == H5I_GROUP_F) then
        call walk_datasets(object, prefix//trim(name)//'/', sign, item, message, unverified, fields)
      else if (kind == H5I_DATASET_F) then
        call check_dataset(object, prefix//trim(name), sign, item, message, unverified, fields)
      end if
      call h5oclose_f(object, err)
    end do
  end subroutine walk_datasets

  subroutine check_dataset(dset, path, sign, item, message, unverified, fields)
    integer(HID_T), intent(in) :: dset
    character(len=*), intent(in) :: path
    logical, intent(in) :: sign
    character(len=*), intent(inout) :: item, message
    integer, intent(inout) :: unverified
    logical, intent(in) :: fields
    integer(HID_T) :: space, ftype
    integer(HSSIZE_T) :: npoints
    integer(HSIZE_T) :: dims(7), maxdims(7), lo, hi
    integer :: err, class, e, ndims, rank, ranks
    integer(int64) :: sums(2), words
    logical :: fletcher, numeric, field, signed
    real(dp) :: stored(2), computed(2)
    call h5dget_space_f(dset, space, err)
    call h5sget_simple_extent_npoints_f(space, npoints, e)
    call h5sget_simple_extent_ndims_f(space, ndims, e)
    dims = 1
    if (ndims > 0) call h5sget_simple_extent_dims_f(space, dims(1:ndims), maxdims(1:ndims), e)
    call h5dget_type_f(dset, ftype, e)
    call h5tget_class_f(ftype, class, e)
    call h5tclose_f(ftype, e)
    fletcher = has_fletcher32(dset)
    signed = has_attribute(dset, 'checksum')
    numeric = class == H5T_FLOAT_F .or. class == H5T_INTEGER_F
    ! the fields: arrays of numbers without Fletcher-32 (PETSc's), shared out by rows
    field = numeric .and. .not. fletcher .and. ndims >= 1 .and. err == 0
    if (fields .neqv. field) then
      ! another walk's dataset (a field without a checksum: counted by the walk of the others)
      if (field .and. .not. signed) unverified = unverified + 1
      call h5sclose_f(space, e)
      return
    end if
    if (.not. numeric .or. (fields .and. .not. sign .and. .not. signed)) then
      ! nothing to check (a field of a checkpoint written before checksums: counted above)
      call h5sclose_f(space, e)
      if (.not. fletcher .and. .not. fields) unverified = unverified + 1
      return
    end if
    ! the rows of the slowest dimension (the last in Fortran's order) this rank reads: all of
    ! them, or for the fields its share
    rank = 0
    ranks = 1
    if (fields) then
      call MPI_Comm_rank(PETSC_COMM_WORLD, rank, e)
      call MPI_Comm_size(PETSC_COMM_WORLD, ranks, e)
    end if
    lo = dims(max(1, ndims)) * rank / ranks
    hi = dims(max(1, ndims)) * (rank + 1) / ranks
    sums = 0
    if (err == 0 .and. npoints > 0) call dataset_sums(dset, space, ndims, dims, lo, hi, sums, err)
    call h5sclose_f(space, e)
    if (fields) then
      ! the ranks' sums joined in the file's order (every rank the same), a failed read agreed
      words = 2_int64 * product(dims(1:ndims - 1)) * int(hi - lo, int64)
      call joined_sums(sums, words, err)
    end if
    if (err /= 0) then
      item = path
      message = 'cannot be read: its data fail their Fletcher-32 checksum or the file is damaged (restart from '// &
                'an earlier checkpoint)'
      return
    end if
    computed = real(sums, dp)
    if (sign) then
      if (.not. fletcher) then
        ! (the fields: every rank writes the same attribute, as parallel HDF5 asks)
        call write_attribute(dset, 'checksum', computed, err)
        if (err /= 0) then
          item = path
          message = 'cannot write its checksum attribute'
        end if
      end if
    else if (signed) then
      call read_attribute(dset, 'checksum', stored, err)
      if (err /= 0 .or. any(stored /= computed)) then
        item = path
        message = 'its data do not match their checksum: the file is damaged (restart from an earlier checkpoint)'
      end if
    else if (.not. fletcher) then
      unverified = unverified + 1
    end if
  end subroutine check_dataset

  ! The checksum's running sums over rows lo..hi-1 of the slowest dimension of a dataset of ndims
  ! >= 1 dimensions dims (0: a scalar, read whole), read as doubles (integers of 32 bits convert
  ! exactly) in blocks of rows of at most 2^16 values, so that no rank holds a whole field (a
  ! 1000^3 field is 8 GB; issue 45). err /= 0: a read failed.
  subroutine dataset_sums(dset, space, ndims, dims, lo, hi, sums, err)
    integer(HID_T), intent(in) :: dset, space
    integer, intent(in) :: ndims
    integer(HSIZE_T), intent(in) :: dims(:), lo, hi
    integer(int64), intent(inout) :: sums(2)
    integer, intent(out) :: err
    integer(HSIZE_T), parameter :: BLOCK_VALUES = 2_HSIZE_T**16
    integer(HID_T) :: memspace
    integer(HSIZE_T) :: start(7), counts(7), plane, rows, first
    integer :: e
    real(dp), allocatable, target :: values(:)
    type(c_ptr) :: buffer
    err = 0
    if (ndims == 0) then
      allocate(values(1))
      buffer = c_loc(values)
      call h5dread_f(dset, H5T_NATIVE_DOUBLE, buffer, err)
      if (err == 0) call checksum_continue(values, sums)
      return
    end if
    plane = product(dims(1:ndims - 1))
    rows = max(1_HSIZE_T, BLOCK_VALUES / plane)
    allocate(values(max(1_HSIZE_T, min(hi - lo, rows) * plane)))
    buffer = c_loc(values)
    first = lo
    do while (first < hi .and. err == 0)
      start(1:ndims) = 0
      start(ndims) = first
      counts(1:ndims) = dims(1:ndims)
      counts(ndims) = min(rows, hi - first)
      call h5sselect_hyperslab_f(space, H5S_SELECT_SET_F, start(1:ndims), counts(1:ndims), err)
      if (err == 0) call h5screate_simple_f(ndims, counts(1:ndims), memspace, err)
      if (err /= 0) exit
      call h5dread_f(dset, H5T_NATIVE_DOUBLE, buffer, err, mem_space_id=memspace, file_space_id=space)
      call h5sclose_f(memspace, e)
      if (err == 0) call checksum_continue(values(1:counts(ndims) * plane), sums)
      first = first + counts(ndims)
    end do
  end subroutine dataset_sums

  ! Each rank's running sums, made from zero over its piece of `words` 32-bit words, become the
  ! sums of the whole in the ranks' order, on every rank: a piece of m words with sums (a, b)
  ! after a prefix with (A, B) gives (A + a, B + m A + b) (checksum_continue: every word adds the
  ! running a to b). err: the largest over the ranks. Collective.
  subroutine joined_sums(sums, words, err)
    integer(int64), intent(inout) :: sums(2)
    integer(int64), intent(in) :: words
    integer, intent(inout) :: err
    integer, parameter :: wide = selected_int_kind(30)
    integer(int64), parameter :: prime = 4294967291_int64
    integer(int64), allocatable :: all(:, :)
    integer(int64) :: mine(4)
    integer :: ranks, r, e
    call MPI_Comm_size(PETSC_COMM_WORLD, ranks, e)
    allocate(all(4, ranks))
    mine = [sums(1), sums(2), words, int(err, int64)]
    call MPI_Allgather(mine, 4, MPI_INTEGER8, all, 4, MPI_INTEGER8, PETSC_COMM_WORLD, e)
    err = max(int(maxval(all(4, :))), abs(e))
    sums = 0
    do r = 1, ranks
      sums(2) = int(mod(int(sums(2), wide) + int(mod(all(3, r), prime), wide) * sums(1) + all(2, r), &
                        int(prime, wide)), int64)
      sums(1) = mod(sums(1) + all(1, r), prime)
    end do
  end subroutine joined_sums

  ! Does the dataset carry HDF5's Fletcher-32 filter?
  logical function has_fletcher32(dset)
    integer(HID_T), intent(in) :: dset
    integer(HID_T) :: plist
    integer :: err, nfilters, k, flags, filter
    integer(SIZE_T) :: nvalues, namelen
    integer :: values(8)
    character(len=64) :: name
    has_fletcher32 = .false.
    call h5dget_create_plist_f(dset, plist, err)
    if (err /= 0) return
    call h5pget_nfilters_f(plist, nfilters, err)
    do k = 0, nfilters - 1
      nvalues = size(values, kind=SIZE_T)
      namelen = len(name, kind=SIZE_T)
      call h5pget_filter_f(plist, k, flags, nvalues, values, namelen, name, filter, err)
      if (err == 0 .and. filter == H5Z_FILTER_FLETCHER32_F) has_fletcher32 = .true.
    end do
    call h5pclose_f(plist, err)
  end function has_fletcher32

  ! The checksum of a dataset's values (attribute checksum): Fletcher's two running sums over the
  ! 32-bit halves of each value's IEEE bit pattern, modulo the prime 4294967291, as two exact
  ! doubles. A changed bit changes the first sum, the order of the values the second; computed on
  ! the file's content in its order, it does not depend on the number of ranks that wrote it.
  ! Running: sums (the two, from 0 at the first value) continue over the next values x, so a
  ! dataset read block by block in the file's order gives the sums of one read.
  pure subroutine checksum_continue(x, sums)
    real(dp), intent(in) :: x(:)
    integer(int64), intent(inout) :: sums(2)
    integer(int64), parameter :: prime = 4294967291_int64, low = 4294967295_int64
    integer(int64) :: a, b, bits
    integer :: i
    a = sums(1)
    b = sums(2)
    do i = 1, size(x)
      bits = transfer(x(i), bits)
      a = mod(a + iand(bits, low), prime)
      b = mod(b + a, prime)
      a = mod(a + iand(shiftr(bits, 32), low), prime)
      b = mod(b + a, prime)
    end do
    sums = [a, b]
  end subroutine checksum_continue

  ! The statistics of FILE against this run's &rheology (RH; doc/INPUT.md "&rheology"): afresh = 1
  ! when the deck's window begins after the checkpoint's step (the statistics start from zero,
  ! whatever the file holds); else the file must hold accumulators taken over the same window, with
  ! the same pair and contact shells, the same records (series_every; < 0: not checked) and the
  ! same bins. A fault sets message, and for a variable of the deck its group and name.
  subroutine rheology_verdict(file, rh, series_every, message, group, variable, afresh)
    integer(HID_T), intent(in) :: file
    type(rheology_t), intent(in) :: rh
    integer, intent(in) :: series_every
    character(len=*), intent(out) :: message, group, variable
    integer, intent(out) :: afresh
    integer :: rank, err, sampling(1)
    integer(HSIZE_T) :: dims(2)
    real(dp) :: shells(2)
    character(len=200) :: text
    group = ''
    variable = ''
    call compare_window(file, rh, message, afresh)
    if (afresh == 1 .or. len_trim(message) > 0) return
    if (.not. has_object(file, 'rheology')) then
      message = 'missing: the checkpoint was written by a run without &rheology, and this deck''s averaging '// &
                'window has begun (set discard_strain to begin after the checkpoint''s step)'
      return
    end if
    if (has_attribute(file, 'rheology_shells')) then
      call read_attribute(file, 'rheology_shells', shells, err)
      if (err == 0 .and. abs(shells(1) - rh%r_outer) > 1.0e-12_dp * rh%r_outer) then
        group = 'rheology'
        variable = 'pair_shell'
        write(text, '(a,f0.6,a,f0.6,a)') 'the checkpoint''s accumulators count pairs at r < ', shells(1), &
             ' a, this deck at r < ', rh%r_outer, ' a'
      else if (err == 0 .and. abs(shells(2) - rh%r_contact) > 1.0e-12_dp * rh%r_contact) then
        group = 'rheology'
        variable = 'contact_shell'
        write(text, '(a,f0.6,a,f0.6,a)') 'the checkpoint''s accumulators count contacts at r < ', shells(2), &
             ' a, this deck at r < ', rh%r_contact, ' a'
      end if
      if (len_trim(group) > 0) then
        message = trim(text)//': counts begun cannot be changed (or set discard_strain to begin after the '// &
                  'checkpoint''s step: the statistics then start afresh)'
        return
      end if
    end if
    sampling = series_every
    if (has_attribute(file, 'rheology_sampling')) call read_attribute(file, 'rheology_sampling', sampling, err)
    if (series_every > 0) then
      if (sampling(1) /= series_every) then
        group = 'output'
        variable = 'series_every'
        write(message, '(a,i0,a,i0,a)') 'the checkpoint''s statistics take every ', sampling(1), &
             '-th step, this deck every ', series_every, &
             '-th: an averaging window begun keeps its records (or set &rheology discard_strain to begin after '// &
             'the checkpoint''s step)'
        return
      end if
    end if
    call dataset_dims(file, 'rheology/accumulators', rank, dims)
    if (rank /= 2 .or. dims(1) /= size(rheo_state(rh)) .or. dims(2) /= 1) &
      message = 'does not fit this deck''s &rheology (blocks, profile_bins or angle_bins differ, or a mixture''s '// &
                'checkpoint predates the per-species statistics, doc/RHEOLOGY.md "Per species")'
  end subroutine rheology_verdict

  ! Restore STATE from the checkpoint PATH (checked before by checkpoint_check). The statistics of
  ! &rheology must fit the run's (a checkpoint without them, or of another size, stops the run),
  ! and so must their averaging window (compare_window): statistics_afresh is true when the deck's
  ! window begins after the checkpoint's step, and the statistics start from zero.
  subroutine checkpoint_read(path, state, statistics_afresh, ierr)
    character(len=*), intent(in) :: path
    type(checkpoint_state_t), intent(in) :: state
    logical, intent(out) :: statistics_afresh
    PetscErrorCode, intent(out) :: ierr
    PetscViewer :: viewer
    integer :: k, err, stars(1), info, afresh(1)
    real(dp) :: delta(1), protocol(PROTOCOL_STATE_SIZE)
    integer :: has_protocol
    integer(HID_T) :: file
    character(len=600) :: message
    character(len=40) :: group, variable
    real(dp), allocatable :: buffer(:, :)
    Vec, allocatable :: fields(:)
    character(len=16), allocatable :: stand_in(:)
    ! the Lees-Edwards offset, and how many provisional velocities the file holds (none in a
    ! checkpoint older than them)
    delta = 0.0_dp
    stars = 0
    statistics_afresh = .false.
    if (is_root()) then
      call h5fopen_f(trim(path), H5F_ACC_RDONLY_F, file, err)
      if (associated(state%offset)) call read_attribute(file, 'lees_edwards_offset', delta, err)
      if (associated(state%fl)) then
        if (has_object(file, 'u_star_old')) call read_attribute(file, 'star_history', stars, err)
        if (err /= 0) stars = 0
      end if
      call h5fclose_f(file, err)
    end if
    if (associated(state%offset)) then
      call MPI_Bcast(delta, 1, MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
      state%offset = delta(1)
    end if
    if (associated(state%protocol)) then
      ! the imposed shear's state; a checkpoint written before &shear has none, which only a
      ! steady protocol (its state is not used) can continue
      message = ''
      protocol = 0.0_dp
      has_protocol = 0
      if (is_root()) then
        call h5fopen_f(trim(path), H5F_ACC_RDONLY_F, file, err)
        if (has_attribute(file, 'shear_protocol_state')) then
          call read_attribute(file, 'shear_protocol_state', protocol, err)
          if (err /= 0) message = 'cannot be read'
          has_protocol = 1
        else if (shear_protocol_varies(state%protocol)) then
          message = 'is not in this checkpoint (written before &shear protocols): it cannot continue a protocol'
        end if
        call h5fclose_f(file, err)
      end if
      call file_error_from_root(path, 'shear_protocol_state', message)
      call MPI_Bcast(protocol, PROTOCOL_STATE_SIZE, MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
      call MPI_Bcast(has_protocol, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
      if (has_protocol == 1) call shear_protocol_restore(state%protocol, protocol)
    end if
    if (associated(state%fl)) then
      call MPI_Bcast(stars, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
      ! the direct solves use no earlier u* (a Krylov run's history is not read, and not kept)
      if (state%fl%direct) stars = 0
      state%fl%star_history = stars(1)
      fields = field_vectors(state, stars(1) > 0, stand_in)
      PetscCall(PetscViewerHDF5Open(PETSC_COMM_WORLD, trim(path), FILE_MODE_READ, viewer, ierr))
      PetscCall(PetscViewerHDF5SetCollective(viewer, PETSC_TRUE, ierr))
      do k = 1, size(fields)
        PetscCall(VecLoad(fields(k), viewer, ierr))
      end do
      PetscCall(PetscViewerDestroy(viewer, ierr))
    end if
    if (associated(state%parts)) then
      call particles_read_state(path, state%parts)
      if (associated(state%history)) call contacts_read(path, state%history, state%parts%n)
    end if
    if (associated(state%rh)) then
      allocate(buffer(size(rheo_state(state%rh)), 1))
      message = ''
      afresh = 0
      if (is_root()) then
        ! (checked before any work by checkpoint_check; here the verdict decides afresh)
        call h5fopen_f(trim(path), H5F_ACC_RDONLY_F, file, err)
        call rheology_verdict(file, state%rh, -1, message, group, variable, afresh(1))
        if (len_trim(message) == 0 .and. afresh(1) == 0) then
          call read_dataset(file, 'rheology/accumulators', buffer, err)
          if (err /= 0) message = 'cannot be read'
        end if
        call h5fclose_f(file, err)
      end if
      call file_error_from_root(path, 'rheology/accumulators', message)
      call MPI_Bcast(afresh, 1, MPI_INTEGER, 0, PETSC_COMM_WORLD, ierr)
      statistics_afresh = afresh(1) == 1
      if (.not. statistics_afresh) then
        call MPI_Bcast(buffer, size(buffer), MPI_DOUBLE_PRECISION, 0, PETSC_COMM_WORLD, ierr)
        ! (the size was checked above: info is 0)
        call rheo_restore(state%rh, buffer(:, 1), info)
      end if
    end if
  end subroutine checkpoint_read

  ! The averaging window the accumulators of FILE were taken over against this run's (&rheology
  ! discard_strain, average_strain, blocks, core). A window that begins after the checkpoint's step
  ! has accumulated nothing yet, whatever the checkpoint's own window: the statistics start from
  ! zero (afresh = 1), which extends a finished run with a later window. A window already begun
  ! must be the checkpoint's: blocks accumulated cannot be cut anew (message). A checkpoint written
  ! before the window was recorded (2026-11-26) is taken to have the run's.
  subroutine compare_window(file, rh, message, afresh)
    integer(HID_T), intent(in) :: file
    type(rheology_t), intent(in) :: rh
    character(len=*), intent(out) :: message
    integer, intent(out) :: afresh
    integer :: window(2), step(1), err
    real(dp) :: core(2)
    message = ''
    afresh = 0
    call read_attribute(file, 'step', step, err)
    if (err /= 0) then
      message = 'the attribute step cannot be read'
      return
    end if
    if (step(1) <= rh%discard_step) then
      afresh = 1
      return
    end if
    if (.not. has_attribute(file, 'rheology_window')) return
    call read_attribute(file, 'rheology_window', window, err)
    if (err == 0) call read_attribute(file, 'rheology_core', core, err)
    if (err /= 0) then
      message = 'the attributes rheology_window or rheology_core cannot be read'
    else if (any(window /= [rh%discard_step, rh%block_steps]) .or. any(abs(core - rh%core) > 1.0e-9_dp)) then
      write(message, '(a,i0,a,i0,a,2(f0.3,a),i0,a,i0,a,2(f0.3,a),i0,a)') &
           'they average from step ', window(1), ' in blocks of ', window(2), ' steps over the core y in [', &
           core(1), ', ', core(2), '], this deck''s &rheology (discard_strain, average_strain, blocks, core) from step ', &
           rh%discard_step, ' in blocks of ', rh%block_steps, ' over [', rh%core(1), ', ', rh%core(2), &
           ']: blocks begun cannot be cut anew. Keep &rheology, or set discard_strain to begin after the '// &
           'checkpoint''s step ', step(1), ' (the statistics then start afresh); scripts/rheology.py --window '// &
           'recomputes any window from series.h5'
    end if
  end subroutine compare_window

end module mod_checkpoint
