! fdsusp-resistance: the exact two-sphere and sphere-wall resistance functions (mod_pair_resistance,
! mod_wall_resistance, mod_pair_mobility; the ones the lubrication correction and bin/pairtraj use)
! at the gaps given, for scripts and tests that compare fdsusp with theory (doc/RESISTANCE.md).
!   bin/fdsusp-resistance pair GAP [GAP ...]   one line per gap: gap XA11 YA11 ... ZM12 (22 scalars,
!                                              Kim & Karrila normalisation, order of the header)
!   bin/fdsusp-resistance pair GAP [GAP ...] --size-ratio LAMBDA
!                                              the same 22 columns for sphere 1 of radius a1 and
!                                              sphere 2 of radius LAMBDA a1, GAP = 2r/(a1+a2) - 2,
!                                              Jeffrey & Onishi's scaling (mod_pair_resistance_unequal;
!                                              LAMBDA = 1 prints the line above, bitwise)
!   bin/fdsusp-resistance wall GAP [GAP ...]   one line per gap: gap lambda_perp f_tt f_tr f_rr x_w
!   bin/fdsusp-resistance shear GAP [GAP ...]  one line per gap: gap A B C K L M, the mobility and
!                                              stresslet functions of a free pair in a linear flow
!                                              (pair_shear_functions, the ones bin/pairtraj integrates)
program fdsusp_resistance
  use mod_kinds, only: dp
  use mod_pair_resistance, only: resistance_scalars, pair_scalar_names, n_pair_scalars
  use mod_wall_resistance, only: wall_normal_resistance, wall_tangential_resistance, &
       wall_twist_resistance
  use mod_pair_mobility, only: pair_shear_functions
  use mod_pair_resistance_unequal, only: sized_pair_scalars
  implicit none
  character(len=64) :: kind, arg
  real(dp) :: gap, f_tt, f_tr, f_rr, bg(6), lambda
  integer :: k, stat, n_args
  logical, allocatable :: is_gap(:)
  logical :: sized
  call get_command_argument(1, kind)
  ! --size-ratio LAMBDA (pair only) may stand anywhere after the kind; every other argument is a gap
  n_args = command_argument_count()
  allocate(is_gap(max(n_args, 1)))
  is_gap = .true.
  is_gap(1) = .false.
  sized = .false.
  lambda = 1.0_dp
  do k = 2, n_args
    call get_command_argument(k, arg)
    if (arg == '--size-ratio' .and. is_gap(k)) then
      sized = .true.
      is_gap(k) = .false.
      if (k < n_args) then
        is_gap(k + 1) = .false.
        call get_command_argument(k + 1, arg)
        read(arg, *, iostat=stat) lambda
      else
        stat = 1
      end if
      if (stat /= 0 .or. .not. (lambda > 0)) then
        write(0, '(a)') 'fdsusp-resistance: --size-ratio needs a positive number, not '//trim(arg)
        stop 2
      end if
    end if
  end do
  if (count(is_gap) < 1 .or. (kind /= 'pair' .and. kind /= 'wall' .and. kind /= 'shear') &
      .or. (sized .and. kind /= 'pair')) then
    write(0, '(a)') 'usage: fdsusp-resistance pair|wall|shear GAP [GAP ...] (pair: [--size-ratio LAMBDA])'
    stop 2
  end if
  if (kind == 'pair') then
    write(*, '(a,22(1x,a))') '# gap', (trim(pair_scalar_names(k)), k = 1, n_pair_scalars)
  else if (kind == 'wall') then
    write(*, '(a)') '# gap lambda_perp f_tt f_tr f_rr x_w'
  else
    write(*, '(a)') '# gap A B C K L M'
  end if
  do k = 2, n_args
    if (.not. is_gap(k)) cycle
    call get_command_argument(k, arg)
    read(arg, *, iostat=stat) gap
    if (stat /= 0 .or. .not. (gap > 0)) then
      write(0, '(a)') 'fdsusp-resistance: a gap must be a positive number, not '//trim(arg)
      stop 2
    end if
    if (kind == 'pair') then
      if (sized) then
        write(*, '(23es24.15e3)') gap, sized_pair_scalars(gap, lambda)
      else
        write(*, '(23es24.15e3)') gap, resistance_scalars(gap)
      end if
    else if (kind == 'shear') then
      call pair_shear_functions(gap, bg(1), bg(2), bg(3), bg(4), bg(5), bg(6))
      write(*, '(7es24.15e3)') gap, bg
    else
      call wall_tangential_resistance(gap, f_tt, f_tr, f_rr)
      write(*, '(6es24.15e3)') gap, wall_normal_resistance(gap), f_tt, f_tr, f_rr, wall_twist_resistance(gap)
    end if
  end do
end program fdsusp_resistance
