! Invariants of the full subgrid model for spheres of several sizes (mod_lubrication
! lub_sized_scalars with a table per pair of species; doc/LUBRICATION.md "Tables for mixtures"),
! without the DNS. The tables are synthetic, made here.
!  1. lambda = 1: an unequal table made from an equal table (sphere 2's columns exchange_sign
!     times sphere 1's, the M sums already folded, the factor (a1 + a2)^3/(8 a1^3) being 1) gives
!     the equal full model's pair block, drive and stresslets, at radius 1 and 1.4; so does the
!     equal table used as a species' own (s = t) table. Tolerance 1e-13 of the largest entry: the
!     same scalars (bitwise, up to exact sign flips) contracted by two different assemblies (the
!     sized one scales by 3 pi eta (2a) where the equal one scales by 6 pi eta a, and the
!     strain part is summed over a 12x3x3 array instead of written out): a few ulps of
!     the largest term, ~1e-16 x the number of terms;
!  2. a table equal to the exact theory (sized_pair_scalars minus one-body, folded) at its gaps
!     gives a correction of 0 at those gaps (1e-12 of the largest theory scalar, ~1e3 at gap 1e-3:
!     the same numbers subtracted, only the theory's evaluation order can differ), also for a
!     pair whose sphere 1 is the larger (the table's columns swapped: a wrong swap leaves O(1)
!     errors); between the gaps the interpolation error alone remains (printed, not bounded);
!  3. folding: the sized stresslets from folded scalars equal those from unfolded ones for any
!     strain E and velocities w (1e-13 relative: one product and sum regrouped), at lambda 1.4,
!     2, 4; R_FU and R_FE, which hold no M function, are bitwise unchanged;
!  4. swapping the spheres of an unequal pair (sphere 1 the larger, d reversed) permutes its
!     12x12 block, drive and stresslets (1e-13 relative: same scalars, the blocks' arithmetic
!     in another order) with a table that is not the theory;
!  5. the sized full blocks are symmetric PSD (smallest eigenvalue >= -1e-10 of the largest
!     entry, dsyev's accuracy) over gaps 1e-6 .. outer, also with a table that over-resolves
!     (1.3 x theory: clip_to_psd at work);
!  6. default outer cut-off: the smallest of the tables' last gaps (exact);
!  7. mod_particle_lubrication wiring: a mixture of radii 1, 1.4 with model 'full' takes, for each
!     pair, the blocks of lub_sized_scalars / lub_pair_link_sized of its species (exact: the
!     same calls), for a pair of radius-1 spheres the equal full model's block (1e-13, as 1), and
!     for a wall link of the 1.4 sphere the wall part of species 2's table, its own radius and
!     the wall floor scaled by a^5 (exact); a radius no table is for, mixture tables with equal
!     spheres, and model 'full' of a mixture without tables are refused (info /= 0).
program test_lubrication_mixture
  use mod_kinds, only: dp
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars, i_xa11, i_ya11, i_xc11, i_yc11, &
       i_xm11, i_ym11, i_zm11, i_xm12, i_ym12, i_zm12
  use mod_pair_resistance_unequal, only: sized_pair_scalars, sized_pair_scalars_22, exchange_sign
  use mod_lubrication, only: lubrication_t, lub_setup, lub_pair_scalars, lub_pair_link, lub_pair_stresslets, &
       lub_sized_scalars, lub_pair_link_sized, lub_pair_stresslets_sized, lub_fold_strain, lub_wall_scalars, &
       lub_wall_link, lub_species_wall_floor, LUB_FULL
  use mod_resistance_blocks, only: pair_resistance_fu_sized, pair_resistance_fe_sized, pair_stresslets_sized
  use mod_particle_lubrication, only: particle_lubrication_t, particle_lubrication_create, particle_lubrication_links
  use mod_unit_checks, only: check, check_below, finish, min_eig
  implicit none
  integer, parameter :: ng = 8
  real(dp), parameter :: table_gaps(ng) = [0.001_dp, 0.01_dp, 0.05_dp, 0.1_dp, 0.2_dp, 0.35_dp, 0.6_dp, 1.0_dp]
  integer, parameter :: one_body(7) = [i_xa11, i_ya11, i_xc11, i_yc11, i_xm11, i_ym11, i_zm11]
  real(dp) :: d(3), u_inf(3, 2), om_inf(3), e_inf(3, 3), w(12)
  character(len=200) :: msg

  d = [1.0_dp, 2.0_dp, 2.0_dp] / 3.0_dp
  u_inf = reshape([0.3_dp, -0.1_dp, 0.2_dp, -0.4_dp, 0.5_dp, 0.1_dp], [3, 2])
  om_inf = [0.1_dp, -0.2_dp, -0.5_dp]
  e_inf = reshape([0.2_dp, 0.5_dp, -0.1_dp, 0.5_dp, -0.3_dp, 0.25_dp, -0.1_dp, 0.25_dp, 0.1_dp], [3, 3])
  w = [0.3_dp, -0.7_dp, 0.2_dp, 0.1_dp, 0.4_dp, -0.3_dp, -0.2_dp, 0.5_dp, 0.6_dp, -0.1_dp, 0.2_dp, 0.3_dp]

  call equal_as_unequal()
  call theory_table()
  call folding()
  call swap()
  call psd()
  call outer_cutoff()
  call wiring()
  call finish('test_lubrication_mixture')

contains

  ! A synthetic equal table: 0.6 x the exact pair part plus a smooth offset, M folded (sums in
  ! the 11 slots), so that the correction is neither zero nor the theory.
  function equal_row(gap) result(t)
    real(dp), intent(in) :: gap
    real(dp) :: t(n_pair_scalars)
    integer :: k
    t = resistance_scalars(gap)
    t(one_body) = t(one_body) - 1.0_dp
    t([i_xm11, i_ym11, i_zm11]) = t([i_xm11, i_ym11, i_zm11]) + t([i_xm12, i_ym12, i_zm12])
    t([i_xm12, i_ym12, i_zm12]) = 0.0_dp
    do k = 1, n_pair_scalars
      t(k) = 0.6_dp * t(k) + 0.05_dp * sin(1.3_dp * k) / (1.0_dp + gap)
    end do
    t([i_xm12, i_ym12, i_zm12]) = 0.0_dp
  end function equal_row

  ! The exact pair part of spheres 1 (small) and lambda (large) at gap, folded: the 44 columns of
  ! an unequal table that resolves everything.
  function theory_row(gap, lambda) result(t)
    real(dp), intent(in) :: gap, lambda
    real(dp) :: t(2 * n_pair_scalars), f(n_pair_scalars), f2(n_pair_scalars)
    f = sized_pair_scalars(gap, lambda)
    f2 = sized_pair_scalars_22(gap, lambda)
    f(one_body) = f(one_body) - 1.0_dp
    f2(one_body) = f2(one_body) - 1.0_dp
    call lub_fold_strain(f, f2, 1.0_dp, lambda)
    t(1:n_pair_scalars) = f
    t(n_pair_scalars + 1:) = f2
  end function theory_row

  ! A two-species mixture lub (radii r(1) < r(2) or equal, see 1.) with its tables filled:
  ! species_pair(1,1), (2,2) from equal_row (22 columns) and (1,2) as given (44 columns).
  subroutine mixture(lub, r, unequal, outer)
    type(lubrication_t), intent(out) :: lub
    real(dp), intent(in) :: r(2), unequal(:, :)
    real(dp), intent(in), optional :: outer
    integer :: s, k
    lub%species_radius = r
    allocate(lub%species_pair(2, 2), lub%species_wall(2))
    do s = 1, 2
      lub%species_pair(s, s)%gap = table_gaps
      allocate(lub%species_pair(s, s)%resolved(ng, n_pair_scalars))
      do k = 1, ng
        lub%species_pair(s, s)%resolved(k, :) = equal_row(table_gaps(k))
      end do
      lub%species_wall(s)%gap = table_gaps
      allocate(lub%species_wall(s)%resolved(ng, 5))
      do k = 1, ng
        lub%species_wall(s)%resolved(k, :) = [0.4_dp, 0.1_dp, 0.02_dp, 0.05_dp, 0.0_dp] * s / table_gaps(k)**0.5_dp
      end do
    end do
    lub%species_pair(1, 2)%gap = table_gaps
    lub%species_pair(1, 2)%resolved = unequal
    call lub_setup(lub, LUB_FULL, 1.0_dp, 1.0_dp, 5.0_dp, 0.0_dp, 1.0e-4_dp)
    if (present(outer)) lub%outer_cutoff = outer
  end subroutine mixture

  ! An equal full model on the equal_row table at radius a.
  subroutine equal_full(lub, a)
    type(lubrication_t), intent(out) :: lub
    real(dp), intent(in) :: a
    integer :: k
    lub%pair_gap = table_gaps
    lub%wall_gap = table_gaps
    allocate(lub%pair_resolved(ng, n_pair_scalars), lub%wall_resolved(ng, 5))
    lub%wall_resolved = 0
    do k = 1, ng
      lub%pair_resolved(k, :) = equal_row(table_gaps(k))
    end do
    call lub_setup(lub, LUB_FULL, a, 1.0_dp, 5.0_dp, 0.0_dp, 1.0e-4_dp)
  end subroutine equal_full

  ! the sized link and stresslets of species s1, s2 (radii a1, a2) at gap
  subroutine sized_link(lub, s1, s2, gap, dd, r, drive, st)
    type(lubrication_t), intent(in) :: lub
    integer, intent(in) :: s1, s2
    real(dp), intent(in) :: gap, dd(3)
    real(dp), intent(out) :: r(12, 12), drive(12), st(3, 3, 2)
    real(dp) :: f(n_pair_scalars), f2(n_pair_scalars), a1, a2, xi
    a1 = lub%species_radius(s1)
    a2 = lub%species_radius(s2)
    xi = max(gap, lub%inner_cutoff)
    f = sized_pair_scalars(xi, a2 / a1)
    f2 = exchange_sign * sized_pair_scalars(xi, a1 / a2)
    call lub_sized_scalars(lub, gap, f, f2, s1, s2)
    call lub_pair_link_sized(lub, f, f2, dd, a1, a2, u_inf, om_inf, e_inf, spread(1.0_dp, 1, 12), r, drive)
    st = lub_pair_stresslets_sized(lub, f, f2, dd, a1, a2, w, e_inf)
  end subroutine sized_link

  ! 1. lambda = 1
  subroutine equal_as_unequal()
    type(lubrication_t) :: mix, eq
    real(dp) :: unequal(ng, 2 * n_pair_scalars), r_eq(12, 12), d_eq(12), s_eq(3, 3, 2), r(12, 12), drive(12), &
                st(3, 3, 2), worst_r, worst_d, worst_s, a, gap
    integer :: k, m, pairing
    do k = 1, ng
      unequal(k, 1:n_pair_scalars) = equal_row(table_gaps(k))
      unequal(k, n_pair_scalars + 1:) = exchange_sign * equal_row(table_gaps(k))
    end do
    do m = 1, 2
      a = merge(1.0_dp, 1.4_dp, m == 1)
      call mixture(mix, [a, a], unequal)
      call equal_full(eq, a)
      do pairing = 1, 2
        worst_r = 0
        worst_d = 0
        worst_s = 0
        do k = 0, 40
          gap = 1.0e-5_dp * (0.99_dp / 1.0e-5_dp)**(k / 40.0_dp)
          call lub_pair_link(eq, lub_pair_scalars(eq, gap), d, u_inf, om_inf, e_inf, r_eq, d_eq)
          s_eq = lub_pair_stresslets(eq, lub_pair_scalars(eq, gap), d, w, e_inf)
          ! pairing 1: species 1 with species 2 (the unequal table at lambda = 1); 2: species 1 with itself
          call sized_link(mix, 1, 3 - pairing, gap, d, r, drive, st)
          worst_r = max(worst_r, maxval(abs(r - r_eq)) / maxval(abs(r_eq)))
          worst_d = max(worst_d, maxval(abs(drive - d_eq)) / maxval(abs(d_eq)))
          worst_s = max(worst_s, maxval(abs(st - s_eq)) / maxval(abs(s_eq)))
        end do
        write(msg, '(a,f3.1,a)') 'lambda = 1, radius ', a, merge(', unequal table made from the equal one', &
                                                                 ', the species'' own equal table         ', pairing == 1)
        call check_below(trim(msg)//': block', worst_r, 1.0e-13_dp)
        call check_below(trim(msg)//': drive', worst_d, 1.0e-13_dp)
        call check_below(trim(msg)//': stresslets', worst_s, 1.0e-13_dp)
      end do
    end do
  end subroutine equal_as_unequal

  ! 2. a table equal to the theory
  subroutine theory_table()
    type(lubrication_t) :: mix
    real(dp), parameter :: lambdas(3) = [1.4_dp, 2.0_dp, 4.0_dp]
    real(dp) :: unequal(ng, 2 * n_pair_scalars), f(n_pair_scalars), f2(n_pair_scalars), worst, between, big, gap
    integer :: k, m, order, s1, s2
    do m = 1, 3
      do k = 1, ng
        unequal(k, :) = theory_row(table_gaps(k), lambdas(m))
      end do
      call mixture(mix, [1.0_dp, lambdas(m)], unequal, outer=5.0_dp)
      do order = 1, 2
        s1 = order
        s2 = 3 - order
        worst = 0
        big = 0
        do k = 1, ng
          call theory_scalars(mix, s1, s2, table_gaps(k), f, f2)
          big = max(big, maxval(abs(theory_row(table_gaps(k), lambdas(m)))))
          worst = max(worst, maxval(abs(f)), maxval(abs(f2)))
        end do
        between = 0
        do k = 1, ng - 1
          gap = sqrt(table_gaps(k) * table_gaps(k + 1))
          call theory_scalars(mix, s1, s2, gap, f, f2)
          between = max(between, maxval(abs(f)), maxval(abs(f2)))
        end do
        write(msg, '(a,f3.1,a,a,es9.2,a)') 'theory table, lambda ', lambdas(m), &
             merge(' (sphere 1 the smaller)', ' (sphere 1 the larger) ', order == 1), &
             ': correction at the table gaps / largest scalar (between gaps: ', between, ', interpolation)'
        call check_below(trim(msg), worst / big, 1.0e-12_dp)
      end do
    end do
  end subroutine theory_table

  ! the full sized scalars of species s1, s2 at gap (exact theory in)
  subroutine theory_scalars(lub, s1, s2, gap, f, f2)
    type(lubrication_t), intent(in) :: lub
    integer, intent(in) :: s1, s2
    real(dp), intent(in) :: gap
    real(dp), intent(out) :: f(n_pair_scalars), f2(n_pair_scalars)
    real(dp) :: a1, a2
    a1 = lub%species_radius(s1)
    a2 = lub%species_radius(s2)
    f = sized_pair_scalars(gap, a2 / a1)
    f2 = exchange_sign * sized_pair_scalars(gap, a1 / a2)
    call lub_sized_scalars(lub, gap, f, f2, s1, s2)
  end subroutine theory_scalars

  ! 3. folding
  subroutine folding()
    real(dp), parameter :: lambdas(3) = [1.4_dp, 2.0_dp, 4.0_dp]
    real(dp) :: f(n_pair_scalars), f2(n_pair_scalars), g(n_pair_scalars), g2(n_pair_scalars), e(3, 3), &
                s_un(3, 3, 2), s_fo(3, 3, 2), worst
    integer :: m, k, q, n
    logical :: same
    worst = 0
    same = .true.
    do m = 1, 3
      do k = 1, 4
        f = sized_pair_scalars(0.03_dp * k, lambdas(m))
        f2 = sized_pair_scalars_22(0.03_dp * k, lambdas(m))
        g = f
        g2 = f2
        call lub_fold_strain(g, g2, 1.3_dp, 1.3_dp * lambdas(m))
        same = same .and. all(pair_resistance_fu_sized(f, f2, d, 1.3_dp, 1.3_dp * lambdas(m), 1.0_dp) == &
                              pair_resistance_fu_sized(g, g2, d, 1.3_dp, 1.3_dp * lambdas(m), 1.0_dp)) &
                    .and. all(pair_resistance_fe_sized(f, f2, d, 1.3_dp, 1.3_dp * lambdas(m), 1.0_dp) == &
                              pair_resistance_fe_sized(g, g2, d, 1.3_dp, 1.3_dp * lambdas(m), 1.0_dp))
        do q = 1, 5
          ! a symmetric traceless strain of its own for each case
          e = reshape([(sin(1.7_dp * q + 0.9_dp * n + 0.4_dp * m + 0.61_dp * k * n * n), n = 1, 9)], [3, 3])
          e = 0.5_dp * (e + transpose(e))
          e(3, 3) = -e(1, 1) - e(2, 2)
          s_un = pair_stresslets_sized(f, f2, d, w, e, 1.3_dp, 1.3_dp * lambdas(m), 1.0_dp)
          s_fo = pair_stresslets_sized(g, g2, d, w, e, 1.3_dp, 1.3_dp * lambdas(m), 1.0_dp)
          worst = max(worst, maxval(abs(s_fo - s_un)) / maxval(abs(s_un)))
        end do
      end do
    end do
    call check_below('folding: stresslets of folded and unfolded M functions, any strain', worst, 1.0e-13_dp)
    call check(same, 'folding: R_FU and R_FE bitwise unchanged')
  end subroutine folding

  ! 4. swapping the spheres
  subroutine swap()
    type(lubrication_t) :: mix
    real(dp) :: unequal(ng, 2 * n_pair_scalars), r12(12, 12), r21(12, 12), d12(12), d21(12), s12(3, 3, 2), &
                s21(3, 3, 2), worst_r, worst_d, worst_s, gap, u_save(3, 2)
    integer :: k, q, p(12)
    do k = 1, ng
      ! not the theory: 0.7 of it plus an offset different for each column
      unequal(k, :) = 0.7_dp * theory_row(table_gaps(k), 2.0_dp) + [(0.03_dp * cos(0.7_dp * q + k), q = 1, 44)]
    end do
    call mixture(mix, [1.0_dp, 2.0_dp], unequal)
    p = [7, 8, 9, 10, 11, 12, 1, 2, 3, 4, 5, 6]
    worst_r = 0
    worst_d = 0
    worst_s = 0
    u_save = u_inf
    do k = 0, 30
      gap = 1.0e-4_dp * (0.95_dp / 1.0e-4_dp)**(k / 30.0_dp)
      u_inf = u_save
      call sized_link(mix, 1, 2, gap, d, r12, d12, s12)
      ! the same pair seen from the larger sphere: d reversed, the ambient velocities and w swapped
      u_inf = u_save(:, [2, 1])
      w = w(p)
      call sized_link(mix, 2, 1, gap, -d, r21, d21, s21)
      w = w(p)
      worst_r = max(worst_r, maxval(abs(r21 - r12(p, p))) / maxval(abs(r12)))
      worst_d = max(worst_d, maxval(abs(d21 - d12(p))) / maxval(abs(d12)))
      worst_s = max(worst_s, maxval(abs(s21 - s12(:, :, [2, 1]))) / maxval(abs(s12)))
    end do
    u_inf = u_save
    call check_below('swap (lambda 2, a table not the theory): block permuted', worst_r, 1.0e-13_dp)
    call check_below('swap: drive permuted', worst_d, 1.0e-13_dp)
    call check_below('swap: stresslets exchanged', worst_s, 1.0e-13_dp)
  end subroutine swap

  ! 5. PSD blocks
  subroutine psd()
    type(lubrication_t) :: mix
    real(dp) :: unequal(ng, 2 * n_pair_scalars), r(12, 12), drive(12), st(3, 3, 2), lowest, gap
    integer :: k, c, order
    do c = 1, 2
      do k = 1, ng
        unequal(k, :) = merge(0.5_dp, 1.3_dp, c == 1) * theory_row(table_gaps(k), 1.4_dp)
      end do
      call mixture(mix, [1.0_dp, 1.4_dp], unequal)
      lowest = huge(1.0_dp)
      do order = 1, 2
        do k = 0, 60
          gap = 1.0e-6_dp * (mix%outer_cutoff / 1.0e-6_dp)**(k / 60.0_dp)
          call sized_link(mix, order, 3 - order, gap, d, r, drive, st)
          if (maxval(abs(r)) > 0) lowest = min(lowest, min_eig(r) / maxval(abs(r)))
          if (maxval(abs(r - transpose(r))) > 1.0e-13_dp * maxval(abs(r))) lowest = -1
        end do
      end do
      write(msg, '(a,a,es10.2,a)') merge('table 0.5 x theory    ', 'table 1.3 x theory    ', c == 1), &
           ': sized full blocks symmetric, PSD (smallest eigenvalue / largest entry ', lowest, ')'
      call check(lowest >= -1.0e-10_dp, trim(msg))
    end do
  end subroutine psd

  ! 6. outer cut-off
  subroutine outer_cutoff()
    type(lubrication_t) :: mix
    real(dp) :: unequal(ng, 2 * n_pair_scalars)
    integer :: k
    do k = 1, ng
      unequal(k, :) = theory_row(table_gaps(k), 1.4_dp)
    end do
    call mixture(mix, [1.0_dp, 1.4_dp], unequal)
    call check(mix%outer_cutoff == 1.0_dp, 'outer cut-off: the tables'' last gap')
    mix%species_pair(1, 2)%gap(ng) = 0.8_dp
    call lub_setup(mix, LUB_FULL, 1.0_dp, 1.0_dp, 5.0_dp, 0.0_dp, 1.0e-4_dp)
    call check(mix%outer_cutoff == 0.8_dp, 'outer cut-off: the smallest of the tables'' last gaps')
  end subroutine outer_cutoff

  ! 7. mod_particle_lubrication
  subroutine wiring()
    type(lubrication_t) :: mix, eq
    type(particle_lubrication_t) :: pl
    real(dp) :: unequal(ng, 2 * n_pair_scalars), x(3, 4), box(3), r(12, 12), drive(12), r_eq(12, 12), &
                d_eq(12), rw(6, 6), dw(6), dd(3), gap, om0(3), e0(3, 3), u(3, 2)
    integer :: info, k, l, i, j, found
    logical :: ok
    do k = 1, ng
      unequal(k, :) = 0.5_dp * theory_row(table_gaps(k), 1.4_dp)
    end do
    call mixture(mix, [1.0_dp, 1.4_dp], unequal)
    mix%wall_floor = -0.3_dp
    call equal_full(eq, 1.0_dp)
    box = [12.0_dp, 12.0_dp, 12.0_dp]
    ! radii 1, 1, 1.4, 1: sphere 3 at gap 0.071 from the wall y = 0, sphere 4 at 0.5; pairs (1, 2)
    ! at xi 0.05, (2, 3) at 0.1, (1, 3) at 0.71, (3, 4) at 0.05 (sphere 1 of the pair the larger)
    x(:, 3) = [5.0_dp, 1.5_dp, 6.0_dp]
    x(:, 2) = [5.0_dp, 4.02_dp, 6.0_dp]
    x(:, 1) = [2.95_dp, 4.02_dp, 6.0_dp]
    x(:, 4) = [7.52_dp, 1.5_dp, 6.0_dp]
    call particle_lubrication_create(pl, mix, 4, box, .true., 1.0_dp, 0.2_dp, info, msg, &
                                     radii=[1.0_dp, 1.0_dp, 1.4_dp, 1.0_dp])
    call check(info == 0, 'wiring: a mixture of radii 1, 1.4 with model full is accepted ('//trim(msg)//')')
    call particle_lubrication_links(pl, x)
    write(msg, '(a,i0,a,i0,a)') 'wiring: the links in reach (', pl%npairs, ' pairs, ', pl%nwalls, ' wall links; 4 and 2)'
    call check(pl%npairs == 4 .and. pl%nwalls == 2, trim(msg))
    call check(any([(pl%radii(pl%pair(1, l)) > pl%radii(pl%pair(2, l)), l = 1, pl%npairs)]), &
               'wiring: a pair whose sphere 1 is the larger is among them')
    om0 = [0.0_dp, 0.0_dp, -0.5_dp]
    e0 = 0
    e0(1, 2) = 0.5_dp
    e0(2, 1) = 0.5_dp
    ok = .true.
    do l = 1, pl%npairs
      i = pl%pair(1, l)
      j = pl%pair(2, l)
      dd = pl%pair_d(:, l)
      gap = 2.0_dp * norm2(x(:, j) - x(:, i)) / (pl%radii(i) + pl%radii(j)) - 2.0_dp
      u(:, 1) = [x(2, i) - 6.0_dp, 0.0_dp, 0.0_dp]
      u(:, 2) = [x(2, j) - 6.0_dp, 0.0_dp, 0.0_dp]
      call direct(mix, pl%species(i), pl%species(j), gap, dd, u, om0, e0, r, drive)
      ok = ok .and. all(r == pl%pair_r(:, :, l)) .and. all(drive == pl%pair_drive(:, l))
      if (i + j == 3) then
        call lub_pair_link(eq, lub_pair_scalars(eq, gap), dd, u, om0, e0, r_eq, d_eq)
        call check_below('wiring: a pair of radius-1 spheres takes the equal full block', &
                         maxval(abs(pl%pair_r(:, :, l) - r_eq)) / maxval(abs(r_eq)), 1.0e-13_dp)
      end if
    end do
    call check(ok, 'wiring: each pair''s block and drive are those of its species'' table (exact)')
    found = 0
    do l = 1, pl%nwalls
      i = pl%wall_part(l)
      if (i /= 3) cycle
      found = found + 1
      gap = (x(2, 3) - 1.4_dp) / 1.4_dp
      call lub_wall_link(mix, lub_wall_scalars(mix, gap, 2), [0.0_dp, 1.0_dp, 0.0_dp], [-6.0_dp, 0.0_dp, 0.0_dp], &
                         rw, dw, floor=-0.3_dp * 1.4_dp**5, radius=1.4_dp)
      call check(all(rw == pl%wall_r(:, :, l)) .and. all(dw == pl%wall_drive(:, l)), &
                 'wiring: the 1.4 sphere''s wall link takes species 2''s wall table, its radius and floor (exact)')
    end do
    call check(found == 1 .and. lub_species_wall_floor(mix, 1.4_dp) == -0.3_dp * 1.4_dp**5, &
               'wiring: the wall floor of a sphere of radius a is lub%wall_floor a^5')
    ! refusals
    call particle_lubrication_create(pl, mix, 4, box, .true., 1.0_dp, 0.2_dp, info, msg, &
                                     radii=[1.0_dp, 1.0_dp, 1.3_dp, 1.4_dp])
    call check(info /= 0 .and. index(msg, 'no table') > 0, 'wiring: a radius no table is for is refused: '//trim(msg))
    call particle_lubrication_create(pl, mix, 4, box, .true., 1.0_dp, 0.2_dp, info, msg)
    call check(info /= 0, 'wiring: mixture tables with equal spheres are refused: '//trim(msg))
    call lub_setup(eq, LUB_FULL, 1.0_dp, 1.0_dp, 5.0_dp, 0.0_dp, 1.0e-4_dp)
    call particle_lubrication_create(pl, eq, 4, box, .true., 1.0_dp, 0.2_dp, info, msg, &
                                     radii=[1.0_dp, 1.0_dp, 1.4_dp, 1.4_dp])
    call check(info /= 0, 'wiring: model full of a mixture without its tables is refused: '//trim(msg))
  end subroutine wiring

  ! the block and drive of a pair of species s1, s2 at gap as particle_lubrication_links makes them
  subroutine direct(mix, s1, s2, gap, dd, u, om, e, r, drive)
    type(lubrication_t), intent(in) :: mix
    integer, intent(in) :: s1, s2
    real(dp), intent(in) :: gap, dd(3), u(3, 2), om(3), e(3, 3)
    real(dp), intent(out) :: r(12, 12), drive(12)
    real(dp) :: f(n_pair_scalars), f2(n_pair_scalars), a1, a2, xi
    a1 = mix%species_radius(s1)
    a2 = mix%species_radius(s2)
    xi = max(gap, mix%inner_cutoff)
    if (s1 == s2) then
      f = resistance_scalars(xi)
      f2 = exchange_sign * f
    else
      f = sized_pair_scalars(xi, a2 / a1)
      f2 = exchange_sign * sized_pair_scalars(xi, a1 / a2)
    end if
    call lub_sized_scalars(mix, gap, f, f2, s1, s2)
    call lub_pair_link_sized(mix, f, f2, dd, a1, a2, u, om, e, spread(1.0_dp, 1, 12), r, drive)
  end subroutine direct

end program test_lubrication_mixture
