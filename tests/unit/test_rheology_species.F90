! Unit test of mod_rheology's per-species statistics of a mixture (doc/RHEOLOGY.md "Per species").
! Invariants checked:
!  1. sum rules of one record: six spheres of radii 1 and 1.4 (two cut by the core's edges) with
!     different stresslets: the species' core stresses and phi_core,s add up to the pooled ones, the
!     species' phi_s(y) to phi(y), the species' references to the pooled references; to 1e-14 of the
!     largest entry (a sum of at most six terms regrouped: a few roundings of 1.1e-16);
!  2. sum rules of the summary: over three blocks of records with changing stresslets, each
!     per-species quantity (eta_r - 1, eta_h - 1, eta_c, N1, N2, Pi and their hydrodynamic and
!     contact parts over tau, phi_core) adds up over the species to the pooled value of
!     rheo_summarise, to 1e-13 (the same regrouping, then a few divisions);
!  3. a rock-salt lattice (simple cubic, spacing d = 2.52 a, the two species alternating; 64 sites
!     in a Lees-Edwards box of 4 d): every small sphere has 6 large neighbours at d, 12 small at
!     sqrt(2) d, 8 large at sqrt(3) d (inside the 4.7 a range; 2 d is beyond it), and nothing else:
!     the partial counts are exactly these, in the bins of these distances;
!  4. an ideal mixture (40 spheres of radius 1 and 20 of 1.4 placed uniformly at random, overlaps
!     allowed, 400 configurations in 4 blocks, Lees-Edwards box 10 a): g_ab(r) -> 1. The counts
!     are counting statistics: the pooled G_ab (counts over the expected counts, all bins) is within
!     4 sigma of 1, sigma = sqrt(f / expected), f = 2 for a = b (each pair counted from both ends),
!     1 for a /= b; the bins with at least 20 expected counts have chi^2 / dof within 1 +- 5
!     sqrt(2 / dof). The wrong normalisation n_b = N_b / V (the reference counted among its own
!     partners) is shown to fail the same 4-sigma test (bias 1/N_b: 0.025 and 0.05 against
!     tolerances 0.011 and 0.022). g_12 = g_21 to 1e-12 (the same pairs from both ends and
!     N_1 N_2 / V both ways: rounding only);
!  5. between walls (10 x 12 x 10, core [3, 9]), an ideal mixture with each species' centres
!     uniform in [a_b, Ly - a_b]: with the sampled shell volumes, G_ab is within 4 sigma of 1; the
!     shells of whole spheres (R_a V_k, no account of the walls, which shells of references near the
!     core's edges cross beyond 3 - a_b) fail it;
!  6. the per-species accumulators survive rheo_state/rheo_restore bit for bit, and the restored
!     summary is the same; equal spheres keep their state and columns (no per-species entries).
program test_rheology_species
  use mod_kinds, only: dp, pi
  use mod_rheology, only: rheology_settings_t, rheology_t, rheo_create, rheo_sample, rheo_accumulate, &
                          rheo_summarise, rheo_summarise_species, species_summary_t, rheo_state, rheo_restore, &
                          rheo_columns, summary_names, species_names, NSUMMARY, NSPECIES_Q
  use mod_unit_checks, only: check, check_below, finish
  use mod_lees_edwards, only: le_create
  implicit none
  type(rheology_settings_t), parameter :: settings = rheology_settings_t(blocks=3, profile_bins=48, angle_bins=8, &
                                                                         contact_shell=0.01_dp)
  integer :: info

  call one_record_sums()
  call rock_salt()
  call ideal_mixture_periodic()
  call ideal_mixture_walls()
  call finish('test_rheology_species')

contains

  ! 1, 2 and 6: sum rules of a record and of the summary, and the checkpoint round trip
  subroutine one_record_sums()
    type(rheology_t) :: r, r2
    type(species_summary_t) :: ss, ss2
    real(dp) :: box(3), radii(6), x(3, 6), u(3, 6), sh(3, 3, 6), sc(3, 3, 6), value(NSUMMARY), err(NSUMMARY), scale
    real(dp) :: pooled(NSPECIES_Q), worst
    real(dp), allocatable :: profile(:, :), angles(:, :), state(:)
    integer :: i, k, step, complete
    box = [10.0_dp, 12.0_dp, 10.0_dp]
    radii = [1.0_dp, 1.4_dp, 1.0_dp, 1.4_dp, 1.0_dp, 1.4_dp]
    x(:, 1) = [1.0_dp, 3.4_dp, 1.0_dp]         ! cut by y_lo = 3
    x(:, 2) = [4.0_dp, 6.0_dp, 1.5_dp]
    x(:, 3) = [1.0_dp, 8.0_dp, 5.0_dp]
    x(:, 4) = [6.0_dp, 8.5_dp, 4.5_dp]         ! cut by y_hi = 9
    x(:, 5) = [4.0_dp, 1.2_dp, 8.0_dp]         ! outside the core
    x(:, 6) = [8.0_dp, 5.0_dp, 8.0_dp]
    call rheo_create(r, 6, box, 1.0_dp, 1.0_dp, settings, 0, 2, info, radii=radii)
    call check(info == 0 .and. r%nspecies == 2 .and. all(r%species_radius == [1.0_dp, 1.4_dp]) .and. &
               all(r%species_count == [3.0_dp, 3.0_dp]), 'two species, smallest first, three spheres each')
    worst = 0
    do step = 1, 6
      do i = 1, 6
        u(:, i) = [0.9_dp * (x(2, i) - 6) + 0.01_dp * step, 0.0_dp, 0.0_dp]
        do k = 1, 9
          sh(1 + mod(k - 1, 3), 1 + (k - 1) / 3, i) = sin(1.3_dp * k + 0.7_dp * i + 0.3_dp * step)
          sc(1 + mod(k - 1, 3), 1 + (k - 1) / 3, i) = cos(0.9_dp * k - 1.1_dp * i + 0.5_dp * step) - 0.4_dp
        end do
        sh(:, :, i) = 0.5_dp * (sh(:, :, i) + transpose(sh(:, :, i)))
        sc(:, :, i) = 0.5_dp * (sc(:, :, i) + transpose(sc(:, :, i)))
      end do
      call rheo_sample(r, x, u, sh, sc)
      scale = maxval(abs(r%values(1:11)))
      worst = max(worst, maxval(abs(sum(r%species_values(1:10, :), 2) - r%values(1:10))) / scale, &
                  abs(sum(r%species_values(11, :)) - r%values(11)) / scale, &
                  maxval(abs(sum(r%species_profile, 2) - r%profile(:, 1))) / maxval(r%profile(:, 1)))
      call rheo_accumulate(r, step)
    end do
    call check_below('record: species stresses, phi_core,s and phi_s(y) add up to the pooled ones (max rel.)', &
                     worst, 1.0e-14_dp)
    call check(sum(r%species_references) == r%references .and. r%references == 5, &
               'record: the species'' references add up to the pooled five (centres in [3, 9))')
    call rheo_summarise(r, 6, complete, value, err, profile, angles)
    call rheo_summarise_species(r, 6, ss)
    call check(complete == 3 .and. all(ss%error(1, :) == ss%error(1, :)), 'summary: three complete blocks, errors finite')
    pooled = [value(idx('eta_r')) - 1, value(idx('eta_h')) - 1, value(idx('eta_c')), value(idx('N1/tau')), &
              value(idx('N2/tau')), value(idx('Pi/tau')), value(idx('N1_h/tau')), &
              value(idx('N2/tau')) - value(idx('N2_c/tau')), value(idx('Pi_h/tau')), value(idx('N1_c/tau')), &
              value(idx('N2_c/tau')), value(idx('Pi_c/tau')), value(idx('phi_core'))]
    worst = 0
    do k = 1, NSPECIES_Q
      worst = max(worst, abs(sum(ss%value(k, :)) - pooled(k)) / max(abs(pooled(k)), 1.0_dp))
    end do
    call check_below('summary: the 13 per-species shares add up to the pooled quantities (max rel.)', worst, 1.0e-13_dp)
    call check_below('summary: sum of phi_s(y) = phi(y) (max abs.)', maxval(abs(sum(ss%phi, 2) - profile(:, 1))), &
                     1.0e-14_dp)
    ! 6. the checkpoint round trip
    state = rheo_state(r)
    call rheo_create(r2, 6, box, 1.0_dp, 1.0_dp, settings, 0, 2, info, radii=radii)
    call rheo_restore(r2, state, info)
    call rheo_summarise_species(r2, 6, ss2)
    call check(info == 0 .and. all(rheo_state(r2) == state) .and. all(ss2%value == ss%value) .and. &
               all(ss2%g == ss%g .or. (ss2%g /= ss2%g .and. ss%g /= ss%g)), &
               'restore: the per-species accumulators and summary survive a checkpoint bit for bit')
    call check(size(rheo_columns(r)) == 14 + 7, 'a mixture between walls writes 7 per-species columns')
    call rheo_create(r2, 6, box, 1.0_dp, 1.0_dp, settings, 0, 2, info)
    call check(r2%nspecies == 1 .and. size(rheo_state(r2)) == size(state) - size(r%block_species_values) &
               - size(r%block_species_profile) - size(r%block_species_references) - size(r%block_radial) &
               - size(r%block_radial_volume) .and. size(rheo_columns(r2)) == 14, &
               'equal spheres: no per-species accumulators in the state, no per-species columns')
  end subroutine one_record_sums

  ! 3. the rock-salt lattice: exact counts in the bins of d, sqrt(2) d, sqrt(3) d
  subroutine rock_salt()
    type(rheology_t) :: r
    real(dp), parameter :: d = 2.52_dp
    real(dp) :: x(3, 64), radii(64), zero(3, 64), zeros3(3, 3, 64), side(3), expect(94, 2, 2)
    integer :: i, j, k, m
    m = 0
    do k = 0, 3
      do j = 0, 3
        do i = 0, 3
          m = m + 1
          x(:, m) = ([i, j, k] + 0.5_dp) * d
          radii(m) = merge(1.0_dp, 1.4_dp, mod(i + j + k, 2) == 0)
        end do
      end do
    end do
    side = 4 * d
    zero = 0
    zeros3 = 0
    call rheo_create(r, 64, side, 1.0_dp, 1.0_dp, settings, 0, 2, info, le_create(side, 1.0_dp, 0.0_dp), radii)
    call check(info == 0 .and. r%nradial == 94, 'rock salt: 94 bins of 0.05 a up to 4.7 a (half of 10.08 a less 0.3 a)')
    call rheo_sample(r, x, zero, zeros3, offset=0.0_dp)
    expect = 0
    ! 32 spheres of each species; (k, partner, reference)
    expect(bin(d), 2, 1) = 6 * 32
    expect(bin(d), 1, 2) = 6 * 32
    expect(bin(sqrt(2.0_dp) * d), 1, 1) = 12 * 32
    expect(bin(sqrt(2.0_dp) * d), 2, 2) = 12 * 32
    expect(bin(sqrt(3.0_dp) * d), 2, 1) = 8 * 32
    expect(bin(sqrt(3.0_dp) * d), 1, 2) = 8 * 32
    call check(all(r%radial == expect), 'rock salt: 6 unlike neighbours at d, 12 like at sqrt(2) d, 8 unlike at '// &
               'sqrt(3) d, none elsewhere (every count exact)')
  end subroutine rock_salt

  integer function bin(dist)
    real(dp), intent(in) :: dist
    bin = int(dist / 0.05_dp) + 1
  end function bin

  ! 4. the ideal mixture in a periodic box
  subroutine ideal_mixture_periodic()
    type(rheology_t) :: r
    type(species_summary_t) :: ss
    integer, parameter :: n1 = 40, n2 = 20, n = n1 + n2, configurations = 400
    real(dp) :: x(3, n), radii(n), zero(3, n), zeros3(3, 3, n), side(3), ratio
    integer :: step, m, nseed
    character(len=120) :: text
    side = 10
    radii = [(1.0_dp, m = 1, n1), (1.4_dp, m = 1, n2)]
    zero = 0
    zeros3 = 0
    call rheo_create(r, n, side, 1.0_dp, 1.0_dp, rheology_settings_t(blocks=4, profile_bins=40), 0, 100, info, &
                     le_create(side, 1.0_dp, 0.0_dp), radii)
    call random_seed(size=nseed)
    call random_seed(put=[(104729 * m + 17, m = 1, nseed)])
    do step = 1, configurations
      call random_number(x)
      x = x * side(1)
      call rheo_sample(r, x, zero, zeros3, offset=0.0_dp)
      call rheo_accumulate(r, step)
    end do
    call rheo_summarise_species(r, configurations, ss)
    call ideal_checks(r, ss, 'periodic')
    ratio = maxval(abs(ss%g(:, 1, 2) - ss%g(:, 2, 1)) / max(ss%g(:, 1, 2), 1.0_dp), &
                   mask=ss%g(:, 1, 2) == ss%g(:, 1, 2))
    write(text, '(a)') 'periodic: g_12 = g_21 (max rel. difference)'
    call check_below(trim(text), ratio, 1.0e-12_dp)
  end subroutine ideal_mixture_periodic

  ! 5. the ideal mixture between walls: each species' centres uniform where they can be
  subroutine ideal_mixture_walls()
    type(rheology_t) :: r
    type(species_summary_t) :: ss
    integer, parameter :: n1 = 40, n2 = 20, n = n1 + n2, configurations = 400
    real(dp) :: x(3, n), radii(n), zero(3, n), zeros3(3, 3, n), box(3)
    integer :: step, m, nseed
    box = [10.0_dp, 12.0_dp, 10.0_dp]
    radii = [(1.0_dp, m = 1, n1), (1.4_dp, m = 1, n2)]
    zero = 0
    zeros3 = 0
    call rheo_create(r, n, box, 1.0_dp, 1.0_dp, rheology_settings_t(blocks=4, profile_bins=48), 0, 100, info, &
                     radii=radii)
    call check(info == 0 .and. r%nradial == 94 .and. r%nradial_volume == 94, &
               'walls: 94 bins, with the sampled shell volumes')
    call random_seed(size=nseed)
    call random_seed(put=[(7907 * m + 3, m = 1, nseed)])
    do step = 1, configurations
      call random_number(x)
      x(1, :) = x(1, :) * box(1)
      x(3, :) = x(3, :) * box(3)
      x(2, :) = radii + x(2, :) * (box(2) - 2 * radii)
      call rheo_sample(r, x, zero, zeros3)
      call rheo_accumulate(r, step)
    end do
    call rheo_summarise_species(r, configurations, ss)
    call ideal_checks(r, ss, 'walls')
  end subroutine ideal_mixture_walls

  ! The counting-statistics checks of an ideal mixture (4, 5): pooled G_ab within 4 sigma of 1,
  ! chi^2 per degree of freedom of the well-filled bins, and a wrong normalisation failing
  ! (periodic: n_b = N_b / V; walls: whole shells R_a V_k).
  subroutine ideal_checks(r, ss, what)
    type(rheology_t), intent(in) :: r
    type(species_summary_t), intent(in) :: ss
    character(len=*), intent(in) :: what
    real(dp), allocatable :: counts(:), expected(:), wrong(:), volumes(:)
    real(dp) :: density, f, tol, g_pooled, g_wrong, chi2, shell(r%nradial), refs(2), phi_core(2)
    integer :: a, b, k, dof
    character(len=200) :: text
    do k = 1, r%nradial
      shell(k) = 4.0_dp / 3.0_dp * pi * r%radial_width**3 * (real(k, dp)**3 - real(k - 1, dp)**3)
    end do
    refs = sum(r%block_species_references, 2)
    ! the mean of the block means, as rheo_summarise_species takes it
    phi_core = 0
    do k = 1, r%blocks
      phi_core = phi_core + r%block_species_values(11, :, k) / r%block_records(k)
    end do
    phi_core = phi_core / r%blocks
    do a = 1, 2
      do b = 1, 2
        counts = sum(r%block_radial(:, b, a, :), 2)
        density = phi_core(b) / (4.0_dp / 3.0_dp * pi * r%species_radius(b)**3)
        if (r%nradial_volume > 0) then
          volumes = sum(r%block_radial_volume(:, b, a, :), 2)
        else
          volumes = refs(a) * shell
        end if
        expected = density * (r%species_count(b) - merge(1, 0, a == b)) / r%species_count(b) * volumes
        f = merge(2.0_dp, 1.0_dp, a == b)
        g_pooled = sum(counts) / sum(expected)
        tol = 4 * sqrt(f / sum(expected))
        write(text, '(a,a,i0,i0,a,es10.3,a)') what, ': |G_', a, b, ' - 1| (', sum(expected), ' expected counts)'
        call check_below(trim(text), abs(g_pooled - 1), tol)
        ! the same quantity from the program's own g: expected-count weighted mean of g_ab
        write(text, '(a,a,i0,i0,a)') what, ': the summary''s g_', a, b, ' weighted by the expected counts is G (rel.)'
        call check_below(trim(text), abs(sum(ss%g(:, b, a) * expected) / sum(expected) / g_pooled - 1), 1.0e-12_dp)
        chi2 = 0
        dof = 0
        do k = 1, r%nradial
          if (expected(k) < 20) cycle
          chi2 = chi2 + (counts(k) - expected(k))**2 / (f * expected(k))
          dof = dof + 1
        end do
        write(text, '(a,a,i0,i0,a,i0,a,f6.3,a)') what, ': |chi^2/dof - 1| of g_', a, b, ' over ', dof, ' bins (chi^2/dof = ', &
             chi2 / dof, ')'
        call check_below(trim(text), abs(chi2 / dof - 1), 5 * sqrt(2.0_dp / dof))
        ! a deliberately wrong normalisation must fail the pooled test
        if (r%nradial_volume > 0) then
          wrong = density * (r%species_count(b) - merge(1, 0, a == b)) / r%species_count(b) * refs(a) * shell
        else
          wrong = density * volumes
        end if
        g_wrong = sum(counts) / sum(wrong)
        if (a == b .or. r%nradial_volume > 0) then
          write(text, '(a,a,i0,i0,a,f8.5,a,f8.5,a)') what, ': a wrong normalisation of g_', a, b, ' fails (|G - 1| = ', &
               abs(g_wrong - 1), ' > ', tol, ')'
          call check(abs(g_wrong - 1) > tol, trim(text))
        end if
      end do
    end do
  end subroutine ideal_checks

  integer function idx(name)
    character(len=*), intent(in) :: name
    idx = findloc(summary_names, name, 1)
  end function idx

end program test_rheology_species
