! Invariant: a checkpoint holds the whole state of a run: checkpoint_read of what checkpoint_write
! wrote restores, into a fresh state, every value bitwise (mod_checkpoint), and checkpoint_check
! accepts the file for the deck that wrote it and finds its step and time.
! The state (8 x 6 x 4 cells with walls, h = 1.25 a so that the box holds the &rheology pair
! search): every vector of the fluid (u, v, w, p, phi, the provisional velocities u*^n and u*^{n-1},
! star_history = 2), Lambda on the three faces, 4 particles (positions, velocities, angular
! velocities, Adams-Bashforth history, have_prev), a contact history of 4 springs (two pairs, one
! each wall) and the &rheology accumulators (3 blocks), all filled with random values (PETSc's
! random vectors, a fixed Fortran seed). Written at step 50, time 0.1234567890123 (not a short
! binary fraction) to a temporary directory, then:
!   1. checkpoint_check(path, cfg, 4, step, time, rh) passes (format, grid, deck, checksums of every
!      dataset, rheology window) and returns step 50 and the time bitwise;
!   2. checkpoint_read into a fresh fluid (fluid_create: zero vectors), fresh Lambda, particles
!      and rheology (rheo_create: zero accumulators) and an empty history restores every vector
!      entry, every particle array, the springs and the accumulators bitwise (differences exactly
!      0: the values travel as doubles, no tolerance), and the statistics are not started afresh.
! Not checkpointed, so not checked: the per-step particle quantities (hydrodynamic forces,
! stresslets, prescribed motion and external loads), which each step recomputes or the deck gives.
! The fluid runs the Krylov path (-fluid_solver krylov), the one that keeps u*^{n-1}.
! Singleton here; on 3 ranks (tests/regression/test_unit_petsc_ranks.sh) the fields go through
! PETSc's parallel HDF5 viewer, and each rank writes the /particles rows of the spheres in its
! z-slab (mod_particles_io), as the program does.
#include <petsc/finclude/petscdmda.h>
program test_checkpoint_roundtrip
  use petscdmda
  use mod_kinds, only: dp
  use mod_params, only: config_t
  use mod_grid, only: grid_t, grid_create, grid_destroy
  use mod_fluid, only: fluid_t, fluid_create, fluid_destroy
  use mod_particles, only: particles_t, particles_init, MOTION_FREE
  use mod_contact, only: contact_history_t, history_unpack, wall_lower, wall_upper
  use mod_rheology, only: rheology_t, rheo_create, rheo_state
  use mod_checkpoint, only: checkpoint_state_t, checkpoint_write, checkpoint_check, checkpoint_read
  use mod_sphere_ownership, only: sphere_ownership_mine
  use mod_unit_checks, only: check, finish
  use mod_unit_start, only: unit_start
  implicit none

  integer, parameter :: n_particles = 4, saved_step = 50
  real(dp), parameter :: saved_time = 0.1234567890123_dp
  PetscErrorCode :: ierr
  PetscMPIInt :: rank, nranks
  type(config_t) :: cfg
  type(grid_t) :: grid
  type(fluid_t), target :: fl, fl2
  Vec, target :: lambda(3), lambda2(3)
  type(particles_t), target :: parts, parts2
  type(contact_history_t), target :: history, history2
  type(rheology_t), target :: rh, rh2
  type(checkpoint_state_t) :: state, state2
  PetscRandom :: rnd
  character(len=512) :: dir, path
  character(len=200) :: scene
  integer :: info, c, step
  integer :: ids(2, 4)
  real(dp) :: ups(3, 4), time, values(3, n_particles, 4)
  real(dp), allocatable :: noise(:)
  logical :: afresh, same
  integer :: seed_size
  integer, allocatable :: seed(:)

  call unit_start('test_checkpoint_roundtrip', rank, nranks, dir)
  path = trim(dir)//'/checkpoint.h5'
  write(scene, '(a,i0,a)') '8 x 6 x 4 with walls, 4 particles, ', nranks, ' rank(s)'

  ! the scene, as a deck would give it
  cfg%deck_file = 'test_checkpoint_roundtrip (no deck)'
  cfg%cells = [8, 6, 4]
  cfg%domain%cells_per_radius = 0.8_dp
  cfg%h = 1.25_dp
  cfg%domain%box = cfg%cells * cfg%h
  cfg%walls = .true.
  cfg%particles%number = n_particles
  cfg%contact_group = .true.
  cfg%rheology_group = .true.
  cfg%discard_step = 2
  cfg%block_steps = 10
  cfg%rheology%blocks = 3
  cfg%rheology%profile_bins = 4
  cfg%rheology%angle_bins = 8
  cfg%rheology%contact_shell = 0.005_dp
  ! the provisional velocities u*^{n-1} exist in the Krylov path only: the direct solves keep none
  ! and their checkpoints hold zeros there (mod_fluid; tests/regression/test_restart.py and
  ! test_checkpoint_checksum.py restart the direct path)
  PetscCallA(PetscOptionsSetValue(PETSC_NULL_OPTIONS, '-fluid_solver', 'krylov', ierr))
  PetscCallA(grid_create(cfg, grid, ierr))

  ! the state written: random values everywhere (the same on every rank where it is not distributed)
  call random_seed(size=seed_size)
  allocate(seed(seed_size))
  seed = 20261127
  call random_seed(put=seed)
  PetscCallA(fluid_create(cfg, grid, fl, ierr))
  PetscCallA(PetscRandomCreate(PETSC_COMM_WORLD, rnd, ierr))
  PetscCallA(PetscRandomSetInterval(rnd, -1.0_dp, 1.0_dp, ierr))
  do c = 1, 3
    PetscCallA(VecSetRandom(fl%vel(c), rnd, ierr))
    PetscCallA(VecSetRandom(fl%vel_star(c), rnd, ierr))
    PetscCallA(VecSetRandom(fl%vel_star_old(c), rnd, ierr))
  end do
  PetscCallA(VecSetRandom(fl%pressure, rnd, ierr))
  PetscCallA(VecSetRandom(fl%phi, rnd, ierr))
  fl%star_history = 2
  call make_lambda(lambda, .true.)
  call particles_init(parts, n_particles, 1.0_dp, MOTION_FREE)
  call random_number(values)
  parts%position = values(:, :, 1) * spread(cfg%domain%box, 2, n_particles)
  parts%velocity = values(:, :, 2) - 0.5_dp
  parts%omega = values(:, :, 3) - 0.5_dp
  parts%velocity_prev = values(:, :, 4) - 0.5_dp
  parts%have_prev = .true.
  ids = reshape([1, 2, 2, 4, 1, wall_lower, 3, wall_upper], [2, 4])
  call random_number(ups)
  call history_unpack(history, n_particles, 4, ids, ups * 1.0e-3_dp, info)
  call check(info == 0, 'the contact history to write is built (history_unpack)')
  call rheo_create(rh, n_particles, cfg%domain%box, 1.0_dp, cfg%domain%shear_rate, cfg%rheology, cfg%discard_step, &
                   cfg%block_steps, info)
  call check(info == 0, 'the &rheology statistics are set up (rheo_create)')
  allocate(noise(size(rheo_state(rh))))
  call random_number(noise)
  rh%block_sums = reshape(noise(1:size(rh%block_sums)), shape(rh%block_sums))
  rh%block_profile = 1.0_dp + noise(2)
  rh%block_angles = 2.0_dp + noise(3)
  rh%block_references = noise(size(noise) - 5:size(noise) - 3)
  rh%block_records = [10.0_dp, 10.0_dp, 4.0_dp]

  state%fl => fl
  state%lambda => lambda
  state%parts => parts
  state%owned_spheres => sphere_ownership_mine
  state%history => history
  state%rh => rh
  PetscCallA(checkpoint_write(path, cfg, state, saved_step, saved_time, ierr))

  ! 1. the check a restart makes before any work
  call rheo_create(rh2, n_particles, cfg%domain%box, 1.0_dp, cfg%domain%shear_rate, cfg%rheology, cfg%discard_step, &
                   cfg%block_steps, info)
  step = -1
  time = -1.0_dp
  call checkpoint_check(path, cfg, n_particles, .false., step, time, rh2)
  call check(step == saved_step, trim(scene)//': checkpoint_check accepts the file and finds step 50')
  call check(time == saved_time, trim(scene)//': checkpoint_check finds the time 0.1234567890123 bitwise')

  ! 2. into a fresh state
  PetscCallA(fluid_create(cfg, grid, fl2, ierr))
  call make_lambda(lambda2, .false.)
  call particles_init(parts2, n_particles, 1.0_dp, MOTION_FREE)
  parts2%position = 0
  parts2%velocity = 0
  parts2%omega = 0
  parts2%velocity_prev = 0
  state2%fl => fl2
  state2%lambda => lambda2
  state2%parts => parts2
  state2%history => history2
  state2%rh => rh2
  PetscCallA(checkpoint_read(path, state2, afresh, ierr))
  call check(.not. afresh, trim(scene)//': the statistics are continued, not started afresh (step 50 > discard step 2)')
  do c = 1, 3
    call same_vec(fl%vel(c), fl2%vel(c), 'u^n, v^n, w^n')
    call same_vec(fl%vel_star(c), fl2%vel_star(c), 'u*^n')
    call same_vec(fl%vel_star_old(c), fl2%vel_star_old(c), 'u*^{n-1}')
    call same_vec(lambda(c), lambda2(c), 'Lambda')
  end do
  call same_vec(fl%pressure, fl2%pressure, 'p^{n-1/2}')
  call same_vec(fl%phi, fl2%phi, 'phi')
  call check(fl2%star_history == 2, trim(scene)//': star_history 2 restored')
  call check(all(parts2%position == parts%position) .and. all(parts2%velocity == parts%velocity) .and. &
             all(parts2%omega == parts%omega) .and. all(parts2%velocity_prev == parts%velocity_prev) .and. &
             parts2%have_prev, trim(scene)//': particle positions, velocities, angular velocities, '// &
             'Adams-Bashforth history and have_prev bitwise equal')
  same = history2%np == history%np .and. history2%n == history%n
  if (same) same = all(history2%owner == history%owner) .and. all(history2%partner == history%partner) .and. &
                   all(history2%ups == history%ups)
  call check(same, trim(scene)//': the contact history (4 springs, two of them on the walls) bitwise equal')
  call check(all(rheo_state(rh2) == rheo_state(rh)), trim(scene)//': the &rheology accumulators bitwise equal')

  call MPI_Barrier(PETSC_COMM_WORLD, ierr)
  if (rank == 0) call execute_command_line('rm -rf '''//trim(dir)//'''')
  do c = 1, 3
    PetscCallA(VecDestroy(lambda(c), ierr))
    PetscCallA(VecDestroy(lambda2(c), ierr))
  end do
  PetscCallA(PetscRandomDestroy(rnd, ierr))
  PetscCallA(fluid_destroy(fl, ierr))
  PetscCallA(fluid_destroy(fl2, ierr))
  PetscCallA(grid_destroy(grid, ierr))
  call finish('test_checkpoint_roundtrip')
  PetscCallA(PetscFinalize(ierr))

contains

  ! Lambda on the u, v, w faces, named as mod_fictitious_domain names them (the datasets'
  ! names): random, or zero.
  subroutine make_lambda(v, random)
    Vec, intent(inout) :: v(3)
    logical, intent(in) :: random
    character(len=8), parameter :: names(3) = ['lambda_u', 'lambda_v', 'lambda_w']
    integer :: c
    do c = 1, 3
      PetscCallA(DMCreateGlobalVector(grid%da(c), v(c), ierr))
      PetscCallA(PetscObjectSetName(v(c), names(c), ierr))
      if (random) then
        PetscCallA(VecSetRandom(v(c), rnd, ierr))
      else
        PetscCallA(VecSet(v(c), 0.0_dp, ierr))
      end if
    end do
  end subroutine make_lambda

  ! Two vectors equal entry by entry (bitwise; no NaN among them).
  subroutine same_vec(a, b, what)
    Vec, intent(in) :: a, b
    character(len=*), intent(in) :: what
    Vec :: d
    PetscReal :: diff, size_a
    PetscBool :: equal
    character(len=64) :: name
    PetscCallA(PetscObjectGetName(a, name, ierr))
    PetscCallA(VecDuplicate(a, d, ierr))
    PetscCallA(VecWAXPY(d, -1.0_dp, a, b, ierr))
    PetscCallA(VecNorm(d, NORM_INFINITY, diff, ierr))
    PetscCallA(VecNorm(a, NORM_INFINITY, size_a, ierr))
    PetscCallA(VecEqual(a, b, equal, ierr))
    PetscCallA(VecDestroy(d, ierr))
    call check(diff == 0.0_dp .and. equal .and. size_a > 0.0_dp, trim(scene)//': '//what//' ('//trim(name)// &
               ') restored bitwise (max |difference| 0, nonzero random values)')
  end subroutine same_vec
end program test_checkpoint_roundtrip
