! Unit test of mod_rheology (the core statistics of doc/RHEOLOGY.md) on constructed cases whose
! answers are known exactly.
! Invariants checked:
!  1. slab volumes: the slices of a sphere over any partition of y sum to (4/3) pi a^3, and a
!     slab covering the sphere gives it whole (to 1e-13 relative; rounding only);
!  2. the profile phi(y) integrated over the gap, times Lx Lz, is the volume of all spheres;
!  3. spheres of identical stresslet S, one cut by the core boundary: Sigma = phi_core S / v_p
!     exactly (the same weights enter both), and the pooled velocity fit of u_x = 0.7 (y - 3)
!     returns the slope 0.7 for any weights;
!  4. the summary of hand-made block means: eta_r = 1 + S_xy/gamma_dot etc. from the definitions,
!     N1, N2, Pi and mu(I_v) from the written-out formulas, I_v and mu undefined (NaN) without
!     contact pressure;
!  5. pair angles: a pair along +x, one along +y (in the core), one out of the shear plane: the
!     counts fall in the bins of theta = 0 and pi (pair 1), pi/2 and 3 pi/2 (pair 2), none for
!     pair 3; only core centres are references; samples between neighbour-list rebuilds count the
!     same pairs (the counts do not depend on when the list was built, so a restart repeats them);
!  6. blocks: records after discard_step go to blocks of block_steps, none outside the window;
!     the accumulators survive rheo_state/rheo_restore bit for bit;
!  7. order: a face-centred cubic crystal of 256 spheres (nearest distance 2.2 a, phi 0.55) in a
!     Lees-Edwards box gives Steinhardt's Q6 = 0.57452 (published to 5 digits: tolerance 5e-6),
!     its 12 nearest neighbours within the bond range and its second shell (3.11 a) beyond it, and
!     every sphere's q6 the same; the crystal displaced at random by up to 0.8 a loses its order
!     (Q6 < 0.2; a liquid of ~1500 bonds is near 0.03);
!     a box below twice the bond search range measures no order and writes no order columns.
program test_rheology
  use mod_kinds, only: dp, pi
  use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
  use mod_rheology, only: rheology_settings_t, rheology_t, rheo_create, rheo_sample, rheo_sample_flow, &
                          rheo_accumulate, rheo_quantities, &
                          rheo_block_of, rheo_state, rheo_restore, rheo_columns, slab_volume, NQ, NSUMMARY, summary_names
  use mod_unit_checks, only: check, check_below, finish
  use mod_lees_edwards, only: le_create
  implicit none
  ! the statistics of a 48-bin, 8-angle, 3-block window (pair shell 2.1 a, contact shell 0.01 a)
  type(rheology_settings_t), parameter :: settings = rheology_settings_t(blocks=3, profile_bins=48, angle_bins=8, &
                                                                         contact_shell=0.01_dp)
  integer :: info, k, n
  type(rheology_t) :: r, r2
  real(dp) :: v, vp, box(3), m(NQ), q(NSUMMARY), gd, s_sum
  real(dp), allocatable :: x(:, :), u(:, :), sh(:, :, :), sc(:, :, :), state(:)

  vp = 4.0_dp / 3.0_dp * pi
  ! 1. slab volumes
  v = 0
  do k = 0, 99
    v = v + slab_volume(3.3_dp, 1.0_dp, -1.0_dp + 0.07_dp * k, -1.0_dp + 0.07_dp * (k + 1))
  end do
  call check(abs(v / vp - 1) < 1e-13_dp, 'slices of a sphere sum to its volume')
  call check(abs(slab_volume(3.3_dp, 1.0_dp, 0.0_dp, 9.0_dp) / vp - 1) < 1e-14_dp, 'a covering slab holds the sphere')
  call check(abs(slab_volume(3.0_dp, 1.0_dp, 3.0_dp, 9.0_dp) / vp - 0.5_dp) < 1e-14_dp, 'half a sphere')

  ! 2.-3. four spheres in a 6 x 12 x 6 cell, core [3, 9]; the one at y = 3.4 is cut by y_lo
  box = [6.0_dp, 12.0_dp, 6.0_dp]
  n = 4
  allocate(x(3, n), u(3, n), sh(3, 3, n), sc(3, 3, n))
  x(:, 1) = [1.0_dp, 3.4_dp, 1.0_dp]
  x(:, 2) = [4.0_dp, 6.0_dp, 1.5_dp]
  x(:, 3) = [1.0_dp, 8.0_dp, 4.0_dp]
  x(:, 4) = [4.0_dp, 1.2_dp, 4.5_dp]       ! outside the core
  u = 0
  u(1, :) = 0.7_dp * (x(2, :) - 3.0_dp)
  sh = 0
  sc = 0
  do k = 1, n
    sh(:, :, k) = reshape([1.0_dp, 2.0_dp, 0.0_dp, 2.0_dp, -3.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.5_dp], [3, 3])
    sc(:, :, k) = reshape([-1.0_dp, 0.5_dp, 0.0_dp, 0.5_dp, -2.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, -1.0_dp], [3, 3])
  end do
  call rheo_create(r, n, box, 1.0_dp, 1.0_dp, settings, 10, 5, info)
  call check(info == 0, 'set-up')
  call rheo_sample(r, x, u, sh, sc)
  s_sum = sum(r%profile(:, 1)) * (box(2) / 48) * box(1) * box(3)
  call check(abs(s_sum / (n * vp) - 1) < 1e-13_dp, 'the profile phi(y) integrates to the spheres'' volume')
  v = (slab_volume(3.4_dp, 1.0_dp, 3.0_dp, 9.0_dp) + 2 * vp) / (box(1) * box(3) * 6.0_dp)   ! phi_core
  call check(abs(r%values(11) / v - 1) < 1e-13_dp, 'phi_core from exact slab volumes')
  call check(all(abs(r%values(1:5) - v / vp * [1.0_dp, -3.0_dp, 0.5_dp, 2.0_dp, -1.5_dp]) < 1e-13_dp), &
       'Sigma^h = phi_core S^h / v_p (same weights)')
  call check(all(abs(r%values(6:10) - v / vp * [-1.0_dp, -2.0_dp, -1.0_dp, 0.5_dp, -4.0_dp]) < 1e-13_dp), &
       'Sigma^c = phi_core S^c / v_p')
  call check(abs(r%shear_rate_core - 0.7_dp) < 1e-12_dp, 'weighted fit of a linear u_x(y) returns its slope')
  call check(abs(r%references - 3) < 0.5_dp, 'three centres in the core are references')

  ! 4. summary quantities from block means
  m = 0
  m(1:5) = [0.3_dp, -0.2_dp, -0.1_dp, 1.5_dp, 0.0_dp]       ! hydrodynamic xx yy zz xy tr
  m(6:10) = [-0.8_dp, -1.2_dp, -0.6_dp, 0.9_dp, -2.6_dp]    ! contact
  m(11) = 0.4_dp
  m(12:16) = [2.0_dp, 12.0_dp, 1.8_dp, 80.0_dp, 20.0_dp]    ! particle fit sums: slope (2*20-12*1.8)/(2*80-144) = 1.15
  gd = (2 * 20.0_dp - 12 * 1.8_dp) / (2 * 80.0_dp - 144.0_dp)
  m(17:21) = [3.0_dp, 3.0_dp, 0.0_dp, 5.0_dp, 1.4_dp]       ! flow fit: slope (3*1.4-0)/(15-9) = 0.7
  q = rheo_quantities(m, 2.0_dp)
  call check(abs(q(idx('eta_r')) - (1 + 2.4_dp / gd)) < 1e-14_dp, 'eta_r = 1 + Sigma^p_xy/gamma_dot_core')
  call check(abs(q(idx('eta_h')) - (1 + 1.5_dp / gd)) < 1e-14_dp, 'eta_h includes the solvent')
  call check(abs(q(idx('eta_c')) - 0.9_dp / gd) < 1e-14_dp, 'eta_c')
  call check(abs(q(idx('N1/tau')) - (-0.5_dp - (-1.4_dp)) / (gd + 2.4_dp)) < 1e-14_dp, 'N1/tau')
  call check(abs(q(idx('N2/tau')) - (-1.4_dp - (-0.7_dp)) / (gd + 2.4_dp)) < 1e-14_dp, 'N2/tau')
  call check(abs(q(idx('Pi/tau')) - 2.6_dp / 3 / (gd + 2.4_dp)) < 1e-14_dp, 'Pi/tau = -tr Sigma^p/(3 tau)')
  call check(abs(q(idx('I_v')) - gd / 1.2_dp) < 1e-14_dp, 'I_v = gamma_dot/(-Sigma^c_yy)')
  call check(abs(q(idx('mu')) - (gd + 2.4_dp) / 1.2_dp) < 1e-14_dp, 'mu = tau/(-Sigma^c_yy)')
  call check(abs(q(idx('mu_h')) + q(idx('mu_c')) - q(idx('mu'))) < 1e-13_dp, 'mu = mu_h + mu_c')
  call check(abs(q(idx('lambda_2_c')) - 1.5_dp) < 1e-14_dp, 'lambda_2^c = Sigma^c_yy/Sigma^c_xx')
  call check(abs(q(idx('gamma_dot_core')) - gd / 2) < 1e-14_dp, 'gamma_dot_core (particle phase) over the imposed rate')
  call check(abs(q(idx('gamma_dot_flow')) - 0.35_dp) < 1e-14_dp, 'gamma_dot_flow (suspension mean velocity)')
  m(6:10) = 0
  q = rheo_quantities(m, 1.0_dp)
  call check(ieee_is_nan(q(idx('I_v'))) .and. ieee_is_nan(q(idx('mu'))), 'no contact pressure: I_v, mu undefined')

  ! the suspension's mean flow u = 0.3 (y - 2) + 1 on rows y_j = (j + 1/2) h: slope 0.3 over the core rows
  allocate(state(0:47))
  do k = 0, 47
    state(k) = 0.3_dp * ((k + 0.5_dp) * 0.25_dp - 2) + 1
  end do
  call rheo_sample_flow(r, state, 0.25_dp)
  call check(abs(r%values(17) - 24) < 0.5_dp, 'the 24 rows of the core enter the flow fit')
  q = rheo_quantities(r%values, 1.0_dp)
  call check(abs(q(idx('gamma_dot_flow')) - 0.3_dp) < 1e-12_dp, 'flow fit of a linear profile returns its slope')
  deallocate(state)

  ! 5. pair angles (8 bins of pi/4; theta = 0 falls in bin 1, pi/2 in bin 3, pi in 5, 3 pi/2 in 7)
  x(:, 1) = [1.0_dp, 5.0_dp, 3.0_dp]
  x(:, 2) = [3.05_dp, 5.0_dp, 3.0_dp]          ! +x of 1 at r = 2.05: in the shell, not at contact
  x(:, 3) = [4.5_dp, 7.0_dp, 3.0_dp]
  x(:, 4) = [4.5_dp, 9.008_dp, 3.0_dp]         ! +y of 3 at r = 2.008: contact (2.01); its centre is outside the core
  call rheo_sample(r, x, u, sh, sc)
  call check(r%angles(1, 1) == 1 .and. r%angles(5, 1) == 1, 'pair along x: theta = 0 and pi, both references')
  call check(r%angles(3, 1) == 1 .and. r%angles(7, 1) == 0, 'pair along y: only the core centre counts (theta = pi/2)')
  call check(r%angles(3, 2) == 1 .and. sum(r%angles(:, 2)) == 1, 'contact shell: the pair at r = 2.008 only')
  call check(abs(r%min_pair_gap - 0.008_dp) < 1e-12_dp, 'smallest pair gap')
  x(:, 4) = [4.5_dp, 7.0_dp, 5.05_dp]          ! partner of 3 along z: out of the shear plane
  call rheo_sample(r, x, u, sh, sc)
  call check(sum(r%angles(:, 1)) == 2, 'pair along the vorticity axis is not in the shear plane')
  ! the next samples reuse the neighbour list (nothing moved beyond skin/2): the same pairs count
  ! (they were counted only on the records that rebuilt it, which a restart shifts)
  call rheo_sample(r, x, u, sh, sc)
  call check(sum(r%angles(:, 1)) == 2 .and. r%angles(1, 1) == 1 .and. r%angles(5, 1) == 1, &
             'a sample that reuses the neighbour list counts the same pairs')
  x(1, 2) = 3.07_dp                            ! 0.02 a further: still listed, still in the shell
  call rheo_sample(r, x, u, sh, sc)
  call check(sum(r%angles(:, 1)) == 2 .and. r%angles(1, 1) == 1 .and. abs(r%min_pair_gap - 0.05_dp) < 1e-12_dp, &
             'a pair that moved less than skin/2 is still counted (smallest gap: the z pair''s 0.05)')
  x(1, 2) = 3.05_dp

  ! 6. blocks and the checkpoint round trip
  call check(rheo_block_of(r, 10) == -1 .and. rheo_block_of(r, 11) == 0 .and. rheo_block_of(r, 15) == 0 .and. &
             rheo_block_of(r, 16) == 1 .and. rheo_block_of(r, 25) == 2 .and. rheo_block_of(r, 26) == -1, &
             'records 11-15, 16-20, 21-25 form blocks 1-3')
  do k = 1, 30
    call rheo_accumulate(r, k)
  end do
  call check(all(r%block_records == 5), 'five records per block')
  state = rheo_state(r)
  call rheo_create(r2, n, box, 1.0_dp, 1.0_dp, settings, 10, 5, info)
  call rheo_restore(r2, state, info)
  call check(info == 0 .and. all(rheo_state(r2) == state), 'accumulators survive a checkpoint bit for bit')
  call rheo_restore(r2, state(2:), info)
  call check(info == 1, 'accumulators of another set-up are refused')

  call crystal_order()

  call finish('test_rheology')

contains

  subroutine crystal_order()
    type(rheology_t) :: rc
    real(dp), allocatable :: xc(:, :), zero(:, :), zeros3(:, :, :), shift(:, :)
    real(dp) :: cell, side(3)
    real(dp), parameter :: basis(3, 4) = reshape([0, 0, 0, 0, 1, 1, 1, 0, 1, 1, 1, 0] * 0.5_dp, [3, 4])
    integer :: i, j, k, b, m
    character(len=100) :: text
    cell = 2.2_dp * sqrt(2.0_dp)
    allocate(xc(3, 256))
    m = 0
    do k = 0, 3
      do j = 0, 3
        do i = 0, 3
          do b = 1, 4
            m = m + 1
            xc(:, m) = ([i, j, k] + basis(:, b) + 0.25_dp) * cell
          end do
        end do
      end do
    end do
    side = 4 * cell
    allocate(zero(3, 256), zeros3(3, 3, 256), shift(3, 256))
    zero = 0
    zeros3 = 0
    call rheo_create(rc, 256, side, 1.0_dp, 1.0_dp, settings, 10, 5, info, le_create(side, 1.0_dp, 0.0_dp))
    call check(info == 0 .and. rc%order, 'order: a 12.4 a box measures Q6 (bonds below 2.8 a)')
    call rheo_sample(rc, xc, zero, zeros3, offset=0.0_dp)
    call check_below('order: fcc crystal |Q6 - 0.57452|', abs(rc%q6 - 0.57452_dp), 5.0e-6_dp)
    call check_below('order: fcc crystal |mean local q6 - Q6|', abs(rc%q6_local - rc%q6), 1.0e-12_dp)
    call check(size(rheo_columns(rc)) == 14, 'order: two columns structure/q6, structure/q6_local')
    ! a liquid-like disorder: each sphere displaced by up to 0.8 a per axis (a fixed seed)
    call random_seed(size=m)
    call random_seed(put=[(7919 * i, i = 1, m)])
    call random_number(shift)
    call rheo_sample(rc, modulo(xc + 1.6_dp * (shift - 0.5_dp), side(1)), zero, zeros3, offset=0.0_dp)
    write(text, '(a,f6.3,a)') 'order: the crystal shaken by up to 0.8 a per axis loses its order (Q6 = ', rc%q6, &
         ' < 0.2)'
    call check(rc%q6 < 0.2_dp, trim(text))
    call rheo_create(rc, 2, [6.0_dp, 6.0_dp, 6.0_dp], 1.0_dp, 1.0_dp, settings, 10, 5, info, &
                     le_create([6.0_dp, 6.0_dp, 6.0_dp], 1.0_dp, 0.0_dp))
    call check(info == 0 .and. .not. rc%order .and. size(rheo_columns(rc)) == 12, &
               'order: a 6 a box (below 2 x 3.1 a) measures none and writes no order columns')
  end subroutine crystal_order

  integer function idx(name)
    character(len=*), intent(in) :: name
    idx = findloc(summary_names, name, 1)
  end function idx


end program test_rheology
