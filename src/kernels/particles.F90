! The particles: state of the inertialess rigid spheres (every sphere, replicated on every rank at
! the start; a rank's local set once the ranks' local sets hold the state: doc/DESIGN.md
! "Parallelism"), their motion mode, and the Adams-Bashforth position update (doc/METHOD.md §7.3).
! Pure: no PETSc, MPI or files.
module mod_particles
  use mod_kinds, only: dp
  use mod_neighbours, only: min_image
  use mod_columns, only: column_t, sphere_column, sphere_rows
  implicit none
  private
  public :: particles_t, sphere_share_t, particles_init, particles_release, advance_positions, displacements, &
            configuration_fault, impose_motion, particles_columns
  public :: MOTION_FREE, MOTION_PRESCRIBED, MOTION_FROZEN, MOTION_RESISTANCE, MOTION_FIXED, motion_code

  ! resistance: velocities imposed as for prescribed, but the configuration is held where it is
  ! (a quasi-static resistance calculation: the force at this configuration and these velocities)
  ! free: force- and torque-free, moving; frozen: force- and torque-free velocities, configuration held
  ! (the high-frequency viscosity eta_inf); prescribed/resistance: velocities imposed, moving/held;
  ! fixed: at rest (obstacles)
  integer, parameter :: MOTION_FREE = 1, MOTION_PRESCRIBED = 2, MOTION_FROZEN = 3, MOTION_RESISTANCE = 4, &
                        MOTION_FIXED = 5

  type :: particles_t
    integer :: n = 0
    integer :: motion = MOTION_FREE
    real(dp) :: radius = 1.0_dp                    ! of equal spheres; of a mixture the smallest (the unit)
    real(dp), allocatable :: radii(:)              ! (n) each sphere's radius [a]
    real(dp), allocatable :: position(:, :)        ! (3, n) centres [a], wrapped into the box
    real(dp), allocatable :: velocity(:, :)        ! (3, n) U^n [a gamma_dot]
    real(dp), allocatable :: omega(:, :)           ! (3, n) Omega^n [gamma_dot]
    real(dp), allocatable :: velocity_prev(:, :)   ! (3, n) U^(n-1), Adams-Bashforth history
    logical :: have_prev = .false.                 ! false until one step has been taken
    real(dp), allocatable :: prescribed_velocity(:, :), prescribed_omega(:, :)
    real(dp), allocatable :: external_force(:, :), external_torque(:, :)
    ! resolved hydrodynamics from lambda (doc/METHOD.md §3.7), on the particle
    real(dp), allocatable :: force_hydro(:, :)     ! (3, n) [eta gamma_dot a^2]
    real(dp), allocatable :: torque_hydro(:, :)    ! (3, n) [eta gamma_dot a^3]
    real(dp), allocatable :: stresslet_hydro(:, :, :)   ! (3, 3, n) [eta gamma_dot a^3]
    ! the ranks' local sets (mod_ld_local): each sphere's z when they were last made, and the rank
    ! count they were made for (0: none). A checkpoint keeps them, so that a restart on as many
    ! ranks makes the very sets the run held: which rank owns a sphere (and so the order of its
    ! sums and of the solver's rows) depends on when the sets were made, not only on where the
    ! sphere is, and the restart then repeats the run's arithmetic bitwise
    real(dp), allocatable :: sets_made_z(:)
    integer :: sets_made_ranks = 0
  end type particles_t

  ! A rank's share of the spheres when each rank holds its own spheres and their ghosts (the local
  ! set of lubrication dynamics, mod_ld_local) rather than every sphere: the output writes the own
  ! spheres' rows of the set under their global indices (mod_run_output, mod_checkpoint).
  type :: sphere_share_t
    type(particles_t), pointer :: set => null()    ! own spheres and ghosts
    integer, allocatable :: id(:)                  ! (set%n) each one's global index, ascending
    logical, allocatable :: own(:)                 ! (set%n) this rank's own
    integer :: total = 0                           ! spheres of the whole system
  end type sphere_share_t

contains

  integer function motion_code(name)
    character(len=*), intent(in) :: name
    select case (name)
    case ('prescribed'); motion_code = MOTION_PRESCRIBED
    case ('frozen');     motion_code = MOTION_FROZEN
    case ('resistance'); motion_code = MOTION_RESISTANCE
    case ('fixed');      motion_code = MOTION_FIXED
    case default;        motion_code = MOTION_FREE
    end select
  end function motion_code

  subroutine particles_init(p, n, radius, motion)
    type(particles_t), intent(out) :: p
    integer, intent(in) :: n, motion
    real(dp), intent(in) :: radius
    p%n = n
    p%radius = radius
    p%motion = motion
    allocate(p%radii(n))
    p%radii = radius
    allocate(p%position(3, n), p%velocity(3, n), p%omega(3, n), p%velocity_prev(3, n), &
             p%prescribed_velocity(3, n), p%prescribed_omega(3, n), p%external_force(3, n), &
             p%external_torque(3, n), p%force_hydro(3, n), p%torque_hydro(3, n), &
             p%stresslet_hydro(3, 3, n))
    p%position = 0.0_dp
    p%velocity = 0.0_dp
    p%omega = 0.0_dp
    p%velocity_prev = 0.0_dp
    p%have_prev = .false.
    p%prescribed_velocity = 0.0_dp
    p%prescribed_omega = 0.0_dp
    p%external_force = 0.0_dp
    p%external_torque = 0.0_dp
    p%force_hydro = 0.0_dp
    p%torque_hydro = 0.0_dp
    p%stresslet_hydro = 0.0_dp
  end subroutine particles_init

  !> The per-sphere arrays of p released: what is left describes the system (n, the unit radius,
  !> the motion, have_prev) and holds no sphere. Once the ranks' local sets hold the state
  !> (mod_ld_local), the replicated particles are released so: a rank then holds its own spheres
  !> and their ghosts only.
  !> Returns the bytes released.
  subroutine particles_release(p, bytes)
    type(particles_t), intent(inout) :: p
    integer(kind=8), intent(out) :: bytes
    bytes = 8_8 * (size(p%radii, kind=8) + size(p%position, kind=8) + size(p%velocity, kind=8) &
                   + size(p%omega, kind=8) + size(p%velocity_prev, kind=8) + size(p%prescribed_velocity, kind=8) &
                   + size(p%prescribed_omega, kind=8) + size(p%external_force, kind=8) &
                   + size(p%external_torque, kind=8) + size(p%force_hydro, kind=8) + size(p%torque_hydro, kind=8) &
                   + size(p%stresslet_hydro, kind=8))
    deallocate(p%radii, p%position, p%velocity, p%omega, p%velocity_prev, p%prescribed_velocity, &
               p%prescribed_omega, p%external_force, p%external_torque, p%force_hydro, p%torque_hydro, &
               p%stresslet_hydro)
    if (allocated(p%sets_made_z)) then
      bytes = bytes + 8_8 * size(p%sets_made_z, kind=8)
      deallocate(p%sets_made_z)
    end if
  end subroutine particles_release

  !> The velocities of the motions that are not solved for: prescribed and resistance take the
  !> prescribed ones, fixed spheres are at rest. Free and frozen spheres are left as they are.
  subroutine impose_motion(p)
    type(particles_t), intent(inout) :: p
    select case (p%motion)
    case (MOTION_PRESCRIBED, MOTION_RESISTANCE)
      p%velocity = p%prescribed_velocity
      p%omega = p%prescribed_omega
    case (MOTION_FIXED)
      p%velocity = 0.0_dp
      p%omega = 0.0_dp
    end select
  end subroutine impose_motion

  ! X^{n+1} = X^n + dt (3/2 U^n - 1/2 U^{n-1}), forward Euler on the first step; wrap the
  ! periodic directions into [0, L).
  subroutine advance_positions(p, dt, box, periodic)
    type(particles_t), intent(inout) :: p
    real(dp), intent(in) :: dt, box(3)
    logical, intent(in) :: periodic(3)
    integer :: d
    if (any(p%motion == [MOTION_FROZEN, MOTION_RESISTANCE, MOTION_FIXED])) return
    if (p%have_prev) then
      p%position = p%position + dt * (1.5_dp * p%velocity - 0.5_dp * p%velocity_prev)
    else
      p%position = p%position + dt * p%velocity
    end if
    p%velocity_prev = p%velocity
    p%have_prev = .true.
    do d = 1, 3
      if (periodic(d)) p%position(d, :) = modulo(p%position(d, :), box(d))
    end do
  end subroutine advance_positions

  ! X^{n+1} - X^n for each sphere, across periodic boundaries (positions are wrapped into the box).
  pure function displacements(position, before, box, periodic) result(d)
    real(dp), intent(in) :: position(:, :), before(:, :), box(3)
    logical, intent(in) :: periodic(3)
    real(dp) :: d(3, size(position, 2))
    integer :: q
    do q = 1, size(position, 2)
      d(:, q) = min_image(position(:, q) - before(:, q), box, periodic)
    end do
  end function displacements

  ! '' if the configuration is acceptable, else what is wrong (and the particle at fault):
  ! a centre outside the box, a sphere crossing a wall, or two spheres overlapping by more than
  ! 5 % of the smallest radius (an O(N^2) check, done once at start-up); radii: each sphere's.
  ! With rough contacts, roughness = h_r > 0: every surface gap, pair or wall, must be at least h_r/2, since an overlap
  ! |delta'| = h_r - gap beyond h_r/2 is outside what the contact model is stable for (the
  ! extreme scenes of doc/VALIDATION.md §6) and would start the run with a force of
  ! k_n (h_r/2)^(3/2), some 30 times the force scale.
  function configuration_fault(position, radii, box, walls, culprit, roughness) result(message)
    real(dp), intent(in) :: position(:, :), radii(:), box(3)
    logical, intent(in) :: walls
    integer, intent(out) :: culprit
    real(dp), intent(in), optional :: roughness
    character(len=200) :: message
    logical :: periodic(3)
    integer :: i, j, d
    real(dp) :: dist, min_gap
    message = ''
    culprit = 0
    periodic = [.true., .not. walls, .true.]
    min_gap = -0.05_dp * minval(radii)
    if (present(roughness)) then
      if (roughness > 0.0_dp) min_gap = 0.5_dp * roughness
    end if
    do i = 1, size(position, 2)
      do d = 1, 3
        if (position(d, i) < 0.0_dp .or. position(d, i) > box(d) .or. position(d, i) /= position(d, i)) then
          write(message, '(a,i0,a,3f12.5,a)') 'particle ', i, ' at (', position(:, i), ') is outside the box'
          culprit = i
          return
        end if
      end do
      if (walls .and. (position(2, i) < radii(i) .or. position(2, i) > box(2) - radii(i))) then
        write(message, '(a,i0,a,f12.5,a)') 'particle ', i, ' at y = ', position(2, i), ' crosses a wall'
        culprit = i
        return
      end if
      if (walls .and. min_gap > 0.0_dp .and. min(position(2, i), box(2) - position(2, i)) - radii(i) < min_gap) then
        write(message, '(a,i0,a,es10.3,a,es10.3,a)') 'particle ', i, ' starts at a wall gap of ', &
             min(position(2, i), box(2) - position(2, i)) - radii(i), ' a: rough contacts need >= h_r/2 = ', &
             min_gap, ' a at the start'
        culprit = i
        return
      end if
    end do
    do i = 1, size(position, 2)
      do j = i + 1, size(position, 2)
        dist = norm2(min_image(position(:, j) - position(:, i), box, periodic))
        if (dist - (radii(i) + radii(j)) < min_gap) then
          if (min_gap > 0.0_dp) then
            write(message, '(a,i0,a,i0,a,es10.3,a,es10.3,a)') 'particles ', i, ' and ', j, ' start at a gap of ', &
                 dist - (radii(i) + radii(j)), ' a: rough contacts need >= h_r/2 = ', min_gap, ' a at the start'
          else
            write(message, '(a,i0,a,i0,a,f10.5,a)') 'particles ', i, ' and ', j, ' overlap (centre distance ', &
                 2 * dist / (radii(i) + radii(j)), ' radii)'
          end if
          culprit = i
          return
        end if
      end do
    end do
  end function configuration_fault

  ! The spheres' columns of the series: their state after the step and the hydrodynamic force, torque
  ! and stresslet of the fluid on them (doc/INPUT.md "&particles").
  function particles_columns(p, owned, rows, total) result(c)
    type(particles_t), intent(in) :: p
    integer, intent(in) :: owned(:)           ! the spheres of p whose rows this rank gives (mod_columns)
    ! (a rank's local set, mod_ld_local: the global indices of owned and the number of all spheres;
    ! absent, p holds every sphere and owned are global indices)
    integer, intent(in), optional :: rows(:), total
    type(column_t), allocatable :: c(:)
    integer, allocatable :: r(:)
    integer :: n
    call sphere_rows(owned, p%n, r, n, rows, total)
    ! element by element: an array constructor of column_t leaks their values (gfortran 12)
    allocate(c(6))
    c(1) = sphere_column('particles/position', n, r, p%position(:, owned))
    c(2) = sphere_column('particles/velocity', n, r, p%velocity(:, owned))
    c(3) = sphere_column('particles/omega', n, r, p%omega(:, owned))
    c(4) = sphere_column('particles/force_hydro', n, r, p%force_hydro(:, owned))
    c(5) = sphere_column('particles/torque_hydro', n, r, p%torque_hydro(:, owned))
    c(6) = sphere_column('particles/stresslet_hydro', n, r, p%stresslet_hydro(:, :, owned))
  end function particles_columns

end module mod_particles
