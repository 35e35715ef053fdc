! The subgrid lubrication correction (doc/METHOD.md §5; doc/LUBRICATION.md): what the grid cannot
! resolve of the two-sphere and sphere-wall resistance, added pairwise to the particle problem.
!
!   R_sub = [R_theo - R_theo(one body)] - [R~ - R~(one body)]          (doc/METHOD.md §5.3)
!
! per pair (12x12 in (U_1, Om_1, U_2, Om_2)) and per sphere-wall link (6x6), so that
!   (F, T)_lub = R_sub_FU . (U_inf - U) + R_sub_FE : E_inf     (forces on the spheres)
!   S_lub      = R_sub_SU . (U_inf - U) + R_sub_SE : E_inf + trace part (doc/METHOD.md §5.9)
! Models:
!   none    no correction.
!   simple  singular terms only, as in lattice-Boltzmann practice (doc/METHOD.md §5.5; Nguyen & Ladd
!           2002, Dance & Maxey 2003): f(max(xi, xi_sat)) - f(xi_c) for xi < xi_c, f the g1/xi +
!           g2 ln(1/xi) part of each scalar, xi_c from Grains3D's rule (0.185 at a/Delta = 5) for
!           translation, 0.05 for rotation, and a saturation gap xi_sat = 0.02 below which the
!           singular terms are held.
!   full    the exact functions (mod_pair_resistance, mod_wall_resistance) minus the resolved part measured by fdsusp
!           itself at this resolution (scripts/calibrate.py, tables in input/lubrication),
!           interpolated linearly in ln(gap); below the smallest calibrated gap the resolved part
!           is held (it saturates once the gap is below the grid spacing). A mixture (spheres of
!           several sizes) takes one table per pair of species and the wall part of each
!           species' equal table (lub_sized_scalars, doc/LUBRICATION.md "Tables for mixtures").
!   exact   the same exact functions minus the one-body part, nothing resolved to
!           subtract: the pair and wall hydrodynamics of the lubrication dynamics mode (&fluid
!           model = 'none', mod_lubrication_dynamics), where no grid resolves anything. Its blocks
!           are not clipped at 0 but at a floor per link set by the caller (lub_pair_link's floor),
!           since R_2B - R_1B has negative eigenvalues at every gap (XA11 - 1 + XA12 < 0 far apart).
! Safeguards (doc/METHOD.md §5.6): gaps below inner_cutoff are evaluated at inner_cutoff; a C1 taper takes the
! correction to zero at outer_cutoff over its last 30 %; every pair block of R_sub_FU is made
! positive semi-definite by clipping its negative eigenvalues (LAPACK dsyev), so the implicit
! 6N system stays symmetric positive definite. Wall blocks may keep eigenvalues down to
! wall_floor < 0, a quarter of the smallest fictitious-fluid mass eigenvalue (rho/dt) J_p: the grid
! over-resolves the tangential wall resistance by ~6 % at gaps 0.35-1 (doc/VALIDATION.md), which
! only a negative correction removes, and a particle has at most two wall links.
! Pure: no PETSc, MPI or files (the tables are read by mod_lubrication_io).
module mod_lubrication
  use mod_kinds, only: dp, pi
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use mod_pair_resistance, only: n_pair_scalars, resistance_scalars, leading_singular_part, i_xa11, &
       i_ya11, i_xc11, i_yc11, i_xm11, i_ym11, i_zm11, i_xm12, i_ym12, i_zm12, i_xa12, i_xg11, &
       i_xg12, i_yh11, i_yh12, i_xc12, i_yc12
  use mod_wall_resistance, only: wall_normal_resistance, wall_tangential_resistance, &
       wall_twist_resistance
  use mod_pair_resistance_unequal, only: exchange_sign
  use mod_resistance_blocks, only: pair_resistance_fu, pair_force_torque_from_strain, &
       pair_stresslets, wall_resistance_block, pair_resistance_fu_sized, pair_resistance_fe_sized, &
       pair_stresslets_sized
  implicit none
  private
  public :: lubrication_t, lub_description, lub_setup, lub_wall_floor, lub_pair_scalars, lub_wall_scalars, lub_pair_link, lub_wall_link, &
            lub_pair_stresslets, lub_wall_stresslet, clip_to_psd, lub_taper, model_code, grains3d_cutoff, &
            lub_sized_scalars, lub_pair_link_sized, lub_pair_stresslets_sized, clip_scaled, &
            lub_fold_strain, lub_species_wall_floor
  integer, parameter, public :: LUB_NONE = 0, LUB_SIMPLE = 1, LUB_FULL = 2, LUB_EXACT = 3
  ! outer cut-off of the exact model when the deck gives none [a]
  real(dp), parameter, public :: exact_default_cutoff = 1.0_dp
  integer, parameter, public :: n_wall_scalars = 5    ! lambda_perp, f_tt, f_tr, f_rr, x_w

  !> One calibrated table of the full model: its gaps (ascending) and the resolved part on them.
  type, public :: lub_table_t
    real(dp), allocatable :: gap(:), resolved(:, :)            ! (ng), (ng, columns)
  end type lub_table_t

  type :: lubrication_t
    integer :: model = LUB_NONE
    real(dp) :: radius = 1.0_dp, viscosity = 1.0_dp
    real(dp) :: outer_cutoff = 0.0_dp          ! gap [a] where the correction has tapered to zero
    real(dp) :: inner_cutoff = 1.0e-4_dp       ! gaps below are evaluated here [a]
    real(dp) :: simple_cutoff = 0.185_dp       ! simple model: xi_c of translation
    real(dp) :: simple_cutoff_rotation = 0.05_dp
    real(dp) :: simple_saturation = 0.02_dp
    ! lowest eigenvalue a wall block may keep (<= 0): where the grid over-resolves the wall
    ! resistance the correction must be negative; set by the caller from the fictitious-fluid
    ! mass so that (rho/dt) M_p + the wall blocks stays positive definite (doc/LUBRICATION.md)
    real(dp) :: wall_floor = 0.0_dp
    ! full model: resolved pair and wall parts on their gap grids (ascending)
    real(dp), allocatable :: pair_gap(:), pair_resolved(:, :)    ! (ng), (ng, 22)
    real(dp), allocatable :: wall_gap(:), wall_resolved(:, :)    ! (ng), (ng, 5)
    ! full model of a mixture (doc/LUBRICATION.md "Tables for mixtures"; unallocated for equal
    ! spheres): the species' radii in the units of radius, ascending; species_pair(s, t), s <= t,
    ! the resolved pair part of a pair of species s and t: s = t the equal table's 22 columns,
    ! s < t the unequal table's 44 (22 of sphere s, then 22 of sphere t with the exchange
    ! signs, the M functions folded, lub_fold_strain); species_wall(s) the wall part (5 columns)
    ! of species s's equal table
    real(dp), allocatable :: species_radius(:)
    type(lub_table_t), allocatable :: species_pair(:, :), species_wall(:)
  end type lubrication_t

  real(dp), parameter :: taper_fraction = 0.3_dp
  ! the scalars whose one-body (isolated sphere) value is 1
  integer, parameter :: one_body_scalars(7) = [i_xa11, i_ya11, i_xc11, i_yc11, i_xm11, i_ym11, i_zm11]

contains

  ! The lubrication part of the run log's 'models:' line; resolved: the fluid is resolved (else
  ! the model is lubrication dynamics' pair hydrodynamics).
  function lub_description(lub, resolved) result(line)
    type(lubrication_t), intent(in) :: lub
    logical, intent(in) :: resolved
    character(len=200) :: line
    select case (lub%model)
    case (LUB_NONE)
      line = 'no lubrication correction'
      if (.not. resolved) line = 'no pair hydrodynamics (one-body drag only)'
    case (LUB_EXACT)
      write(line, '(a,f7.3,a)') 'exact two-body pair and wall resistance minus one-body (outer cut-off ', &
           lub%outer_cutoff, ' a)'
    case (LUB_SIMPLE)
      write(line, '(a,f6.3,a)') 'lubrication simple (singular terms, outer cut-off ', lub%outer_cutoff, ' a)'
    case default
      if (allocated(lub%species_pair)) then
        write(line, '(a,i0,a,f6.3,a)') 'lubrication full (calibrated, a mixture of ', size(lub%species_radius), &
             ' species: a table per pair of species, outer cut-off ', lub%outer_cutoff, ' a)'
      else
        write(line, '(a,f6.3,a,i0,a)') 'lubrication full (calibrated, outer cut-off ', lub%outer_cutoff, &
             ' a, ', size(lub%pair_gap), ' tabulated gaps)'
      end if
    end select
  end function lub_description

  integer function model_code(name)
    character(len=*), intent(in) :: name
    select case (name)
    case ('simple'); model_code = LUB_SIMPLE
    case ('full');   model_code = LUB_FULL
    case ('exact');  model_code = LUB_EXACT
    case default;    model_code = LUB_NONE
    end select
  end function model_code

  !> Grains3D's cut-off of the simple model (doc/METHOD.md §5.5): xi_c = (Delta/a)[1 + (2a/Delta - 16) 0.1/8].
  pure real(dp) function grains3d_cutoff(cells_per_radius)
    real(dp), intent(in) :: cells_per_radius
    grains3d_cutoff = (1.0_dp + (2.0_dp * cells_per_radius - 16.0_dp) * 0.1_dp / 8.0_dp) / cells_per_radius
  end function grains3d_cutoff

  !> model: LUB_*; outer_cutoff 0 = the model's default (simple: xi_c; full: the last calibrated
  !> gap, where the resolved part has met the theory within its scatter; a mixture's tables, set
  !> before (species_pair), the smallest of their last pair gaps, so that no pair is corrected
  !> beyond its own table).
  subroutine lub_setup(lub, model, radius, viscosity, cells_per_radius, outer_cutoff, inner_cutoff)
    type(lubrication_t), intent(inout) :: lub
    integer, intent(in) :: model
    real(dp), intent(in) :: radius, viscosity, cells_per_radius, outer_cutoff, inner_cutoff
    lub%model = model
    lub%radius = radius
    lub%viscosity = viscosity
    lub%inner_cutoff = inner_cutoff
    lub%simple_cutoff = grains3d_cutoff(cells_per_radius)
    select case (model)
    case (LUB_SIMPLE)
      lub%outer_cutoff = lub%simple_cutoff
    case (LUB_FULL)
      if (allocated(lub%species_pair)) then
        lub%outer_cutoff = mixture_outer_cutoff(lub)
      else
        lub%outer_cutoff = lub%pair_gap(size(lub%pair_gap))
      end if
    case (LUB_EXACT)
      lub%outer_cutoff = exact_default_cutoff
    case default
      lub%outer_cutoff = 0.0_dp
    end select
    if (outer_cutoff > 0.0_dp) lub%outer_cutoff = outer_cutoff
  end subroutine lub_setup

  ! the smallest of the last pair gaps of a mixture's tables
  pure real(dp) function mixture_outer_cutoff(lub) result(cut)
    type(lubrication_t), intent(in) :: lub
    integer :: s, t
    cut = huge(1.0_dp)
    do t = 1, size(lub%species_radius)
      do s = 1, t
        cut = min(cut, lub%species_pair(s, t)%gap(size(lub%species_pair(s, t)%gap)))
      end do
    end do
  end function mixture_outer_cutoff

  !> C1 taper: 1 below (1 - taper_fraction) outer, 0 at and beyond outer (smoothstep between).
  pure real(dp) function lub_taper(gap, outer)
    real(dp), intent(in) :: gap, outer
    real(dp) :: s
    s = (outer - gap) / (taper_fraction * outer)
    if (s >= 1.0_dp) then
      lub_taper = 1.0_dp
    else if (s <= 0.0_dp) then
      lub_taper = 0.0_dp
    else
      lub_taper = s * s * (3.0_dp - 2.0_dp * s)
    end if
  end function lub_taper

  !> Linear interpolation of table rows in ln(gap), held constant outside the grid.
  pure function interpolate(gaps, rows, gap) result(v)
    real(dp), intent(in) :: gaps(:), rows(:, :), gap
    real(dp) :: v(size(rows, 2)), w
    integer :: k, n
    n = size(gaps)
    if (gap <= gaps(1)) then
      v = rows(1, :)
    else if (gap >= gaps(n)) then
      v = rows(n, :)
    else
      k = 1
      do while (gaps(k + 1) < gap)
        k = k + 1
      end do
      w = log(gap / gaps(k)) / log(gaps(k + 1) / gaps(k))
      v = (1.0_dp - w) * rows(k, :) + w * rows(k + 1, :)
    end if
  end function interpolate

  !> The 22 subgrid scalars at this gap (tapered; zero beyond the outer cut-off). The M functions
  !> enter R_SE only through the sums M11 + M12, which 'full' carries in the 11 slots.
  function lub_pair_scalars(lub, gap) result(f)
    type(lubrication_t), intent(in) :: lub
    real(dp), intent(in) :: gap
    real(dp) :: f(n_pair_scalars), xi, taper
    f = 0.0_dp
    if (lub%model == LUB_NONE .or. gap >= lub%outer_cutoff) return
    xi = max(gap, lub%inner_cutoff)
    taper = lub_taper(gap, lub%outer_cutoff)
    select case (lub%model)
    case (LUB_SIMPLE)
      f = simple_difference(leading_singular_part(max(xi, lub%simple_saturation)), &
                            leading_singular_part(lub%simple_cutoff), &
                            leading_singular_part(lub%simple_cutoff_rotation), &
                            xi < lub%simple_cutoff, xi < lub%simple_cutoff_rotation)
    case (LUB_FULL)
      f = resistance_scalars(xi)
      f(one_body_scalars) = f(one_body_scalars) - 1.0_dp
      f([i_xm11, i_ym11, i_zm11]) = f([i_xm11, i_ym11, i_zm11]) + f([i_xm12, i_ym12, i_zm12])
      f([i_xm12, i_ym12, i_zm12]) = 0.0_dp
      f = f - interpolate(lub%pair_gap, lub%pair_resolved, xi)
    case (LUB_EXACT)
      ! R_2B - R_1B (doc/METHOD.md §5.3, nothing resolved)
      f = resistance_scalars(xi)
      f(one_body_scalars) = f(one_body_scalars) - 1.0_dp
      f([i_xm11, i_ym11, i_zm11]) = f([i_xm11, i_ym11, i_zm11]) + f([i_xm12, i_ym12, i_zm12])
      f([i_xm12, i_ym12, i_zm12]) = 0.0_dp
    end select
    f = taper * f
  end function lub_pair_scalars

  ! simple model: rotation scalars (XC, YC, YH) use their own cut-off (Grains3D).
  pure function simple_difference(at_gap, at_cut, at_cut_rot, inside, inside_rot) result(f)
    real(dp), intent(in) :: at_gap(n_pair_scalars), at_cut(n_pair_scalars), at_cut_rot(n_pair_scalars)
    logical, intent(in) :: inside, inside_rot
    real(dp) :: f(n_pair_scalars)
    integer, parameter :: rotation(6) = [i_xc11, i_yc11, i_yh11, i_xc12, i_yc12, i_yh12]
    f = 0.0_dp
    if (inside) f = at_gap - at_cut
    f(rotation) = 0.0_dp
    if (inside_rot) f(rotation) = at_gap(rotation) - at_cut_rot(rotation)
  end function simple_difference

  !> The subgrid sphere-wall scalars (lambda_perp, f_tt, f_tr, f_rr, x_w) at this gap. The twist
  !> x_w is not singular and is left to the grid (doc/METHOD.md §5.8).
  !> species (optional): a mixture's sphere of that species (lub%species_radius), gap over its own
  !> radius: model 'full' takes the wall part of that species' table.
  function lub_wall_scalars(lub, gap, species) result(w)
    type(lubrication_t), intent(in) :: lub
    real(dp), intent(in) :: gap
    integer, intent(in), optional :: species
    real(dp) :: w(n_wall_scalars), eps, e, ec
    w = 0.0_dp
    if (lub%model == LUB_NONE .or. gap >= lub%outer_cutoff) return
    eps = max(gap, lub%inner_cutoff)
    select case (lub%model)
    case (LUB_SIMPLE)
      if (eps < lub%simple_cutoff) then
        e = max(eps, lub%simple_saturation)
        ec = lub%simple_cutoff
        w(1) = (1.0_dp / e + 0.2_dp * log(1.0_dp / e)) - (1.0_dp / ec + 0.2_dp * log(1.0_dp / ec))
        w(2:4) = [8.0_dp / 15, 2.0_dp / 15, 0.4_dp] * log(ec / e)
      end if
    case (LUB_FULL)
      w(1) = wall_normal_resistance(eps) - 1.0_dp
      call wall_tangential_resistance(eps, w(2), w(3), w(4))
      w(2) = w(2) - 1.0_dp
      w(4) = w(4) - 1.0_dp
      if (present(species)) then
        w(1:4) = w(1:4) - interpolate(lub%species_wall(species)%gap, lub%species_wall(species)%resolved(:, 1:4), eps)
      else
        w(1:4) = w(1:4) - interpolate(lub%wall_gap, lub%wall_resolved(:, 1:4), eps)
      end if
    case (LUB_EXACT)
      w(1) = wall_normal_resistance(eps) - 1.0_dp
      call wall_tangential_resistance(eps, w(2), w(3), w(4))
      w(2) = w(2) - 1.0_dp
      w(4) = w(4) - 1.0_dp
      ! the twist, which no grid resolves here
      w(5) = wall_twist_resistance(eps) - 1.0_dp
      w = lub_taper(gap, lub%outer_cutoff) * w
      return
    end select
    w(5) = 0.0_dp
    w = lub_taper(gap, lub%outer_cutoff) * w
  end function lub_wall_scalars

  !> One lubricating pair: d unit vector from sphere 1 to 2, f its subgrid scalars, u_inf (3, 2)
  !> the undisturbed velocity at the two centres, om_inf and e_inf the undisturbed rotation and
  !> strain rate. r (12x12): R_sub_FU made positive semi-definite; drive (12): the part of the
  !> correction that does not depend on the particle velocities, R.U_inf + R_FE : E_inf, so that
  !> (F_1, T_1, F_2, T_2)_lub = drive - r . (U_1, Om_1, U_2, Om_2).
  !> info (optional): 0, or LAPACK's code when the block could not be decomposed (non-finite input);
  !> the caller reports it with the pair (the kernel does not stop the run).
  !> floor (optional, <= 0): the lowest eigenvalue the block may keep (default 0: made PSD).
  subroutine lub_pair_link(lub, f, d, u_inf, om_inf, e_inf, r, drive, info, floor)
    type(lubrication_t), intent(in) :: lub
    real(dp), intent(in) :: f(n_pair_scalars), d(3), u_inf(3, 2), om_inf(3), e_inf(3, 3)
    real(dp), intent(out) :: r(12, 12), drive(12)
    integer, intent(out), optional :: info
    real(dp), intent(in), optional :: floor
    r = clip_to_psd(pair_resistance_fu(f, d, lub%radius, lub%viscosity), floor, info)
    drive = matmul(r, [u_inf(:, 1), om_inf, u_inf(:, 2), om_inf]) &
          + pair_force_torque_from_strain(f, d, e_inf, lub%radius, lub%viscosity)
  end subroutine lub_pair_link

  !> One sphere-wall link: normal n from the wall into the fluid, w the subgrid wall scalars,
  !> u_wall the wall velocity. (F, T)_lub = drive - r . (U, Om), drive = r . (u_wall, 0).
  !> info (optional): as for lub_pair_link. floor (optional): replaces lub%wall_floor.
  !> radius (optional): the sphere's own radius (a mixture; w at its own gap over radius), else lub%radius.
  subroutine lub_wall_link(lub, w, normal, u_wall, r, drive, info, floor, radius)
    type(lubrication_t), intent(in) :: lub
    real(dp), intent(in) :: w(n_wall_scalars), normal(3), u_wall(3)
    real(dp), intent(out) :: r(6, 6), drive(6)
    integer, intent(out), optional :: info
    real(dp), intent(in), optional :: floor, radius
    real(dp) :: lowest, a
    lowest = lub%wall_floor
    if (present(floor)) lowest = floor
    a = lub%radius
    if (present(radius)) a = radius
    r = clip_to_psd(wall_resistance_block(w(1), w(2), w(3), w(4), w(5), normal, a, lub%viscosity), &
                    lowest, info)
    drive = matmul(r(:, 1:3), u_wall)
  end subroutine lub_wall_link

  !> Stresslet corrections of a pair (3, 3, 2): R_sub_SU . w + R_sub_SE : E (deviatoric, doc/METHOD.md §5.7)
  !> plus the particle-pressure part (doc/METHOD.md §5.9): the near-contact traction sits in the gap, at a d
  !> from sphere 1 and -a d from sphere 2, so tr S_alpha = a n_alpha . F^X_alpha with F^X the
  !> squeeze (X-type) part of the corrected force. w = (U_inf - U, Om_inf - Om) of both spheres.
  function lub_pair_stresslets(lub, f, d, w, e_inf) result(s)
    type(lubrication_t), intent(in) :: lub
    real(dp), intent(in) :: f(n_pair_scalars), d(3), w(12), e_inf(3, 3)
    real(dp) :: s(3, 3, 2), squeeze, ded
    integer :: k
    s = pair_stresslets(f, d, w, e_inf, lub%radius, lub%viscosity)
    ded = dot_product(d, matmul(e_inf, d))
    ! d . F^X_1 = -d . F^X_2 (XA, XG parts; XA21 = XA12, XG21 = -XG12)
    squeeze = 6.0_dp * pi * lub%viscosity * lub%radius * (f(i_xa11) * dot_product(d, w(1:3)) &
              + f(i_xa12) * dot_product(d, w(7:9))) &
              + 4.0_dp * pi * lub%viscosity * lub%radius**2 * (f(i_xg11) - f(i_xg12)) * ded
    do k = 1, 3
      s(k, k, 1) = s(k, k, 1) + lub%radius * squeeze / 3.0_dp
    end do
    ! sphere 2: d . F^X_2 with its own velocities: the same form with 1 <-> 2 and d -> -d
    squeeze = 6.0_dp * pi * lub%viscosity * lub%radius * (f(i_xa11) * dot_product(-d, w(7:9)) &
              + f(i_xa12) * dot_product(-d, w(1:3))) &
              + 4.0_dp * pi * lub%viscosity * lub%radius**2 * (f(i_xg11) - f(i_xg12)) * ded
    do k = 1, 3
      s(k, k, 2) = s(k, k, 2) + lub%radius * squeeze / 3.0_dp
    end do
  end function lub_pair_stresslets

  !> Stresslet of a sphere-wall correction force f_lub acting at the gap point -a n:
  !> S = -a sym(n f_n) with f_n the normal (squeeze) part, so tr S = -a n . f_lub.
  !> radius (optional): the sphere's own radius (a mixture), else lub%radius.
  pure function lub_wall_stresslet(lub, normal, f_lub, radius) result(s)
    type(lubrication_t), intent(in) :: lub
    real(dp), intent(in) :: normal(3), f_lub(3)
    real(dp), intent(in), optional :: radius
    real(dp) :: s(3, 3), fn(3), a
    a = lub%radius
    if (present(radius)) a = radius
    fn = dot_product(normal, f_lub) * normal
    s = -0.5_dp * a * (spread(normal, 2, 3) * spread(fn, 1, 3) + spread(fn, 2, 3) * spread(normal, 1, 3))
  end function lub_wall_stresslet

  ! ---------------------------------------------------------------------------------------------
  ! Two spheres of different sizes: model 'exact' (lubrication dynamics of a mixture) and model
  ! 'full' with a table per pair of species (the DNS of a mixture; doc/LUBRICATION.md "Spheres of
  ! several sizes" and "Tables for mixtures")
  ! ---------------------------------------------------------------------------------------------

  !> f (11, 12 scalars) and f2 (22, 21 scalars, exchange signs applied) of two unequal spheres at
  !> gap xi = 2r/(a_1 + a_2) - 2 (mod_pair_resistance_unequal, Jeffrey & Onishi's scaling, in which
  !> each sphere's self scalars X^A, Y^A, X^C, Y^C, X^M, Y^M, Z^M of one isolated sphere are 1):
  !> made the subgrid scalars of both spheres and tapered to zero at the outer cut-off (over the
  !> same xi), in place. The caller evaluates them at max(gap, inner_cutoff). Zero beyond the
  !> cut-off and for the models other than 'exact' and 'full'.
  !>   exact  R_2B - R_1B (nothing resolved).
  !>   full   [R_2B - R_1B] - [R~_2B - R~_1B] (doc/METHOD.md §5.3): species1, species2 (required)
  !>          are the spheres' species, indices into lub%species_radius; the M functions are
  !>          folded first (lub_fold_strain, as the tables hold them) and the resolved part is
  !>          interpolated in ln(xi) from lub%species_pair of the two species: an equal pair's
  !>          table (22 columns) gives f2 as exchange_sign times its row, so that a pair of one
  !>          species equals the equal-sphere 'full' model (to rounding); an unequal pair's table
  !>          (44 columns) is laid out with the smaller sphere first, so a pair whose sphere 1 is
  !>          the larger takes the columns swapped (sphere 1's are the table's sphere 2 ones with
  !>          the exchange signs undone: f = exchange_sign t(23:44), f2 = exchange_sign t(1:22)).
  pure subroutine lub_sized_scalars(lub, gap, f, f2, species1, species2)
    type(lubrication_t), intent(in) :: lub
    real(dp), intent(in) :: gap
    real(dp), intent(inout) :: f(n_pair_scalars), f2(n_pair_scalars)
    integer, intent(in), optional :: species1, species2
    real(dp) :: taper, xi
    real(dp) :: t(2 * n_pair_scalars)
    integer :: s1, s2
    if ((lub%model /= LUB_EXACT .and. lub%model /= LUB_FULL) .or. gap >= lub%outer_cutoff) then
      f = 0.0_dp
      f2 = 0.0_dp
      return
    end if
    taper = lub_taper(gap, lub%outer_cutoff)
    f(one_body_scalars) = f(one_body_scalars) - 1.0_dp
    f2(one_body_scalars) = f2(one_body_scalars) - 1.0_dp
    if (lub%model == LUB_FULL) then
      s1 = species1
      s2 = species2
      xi = max(gap, lub%inner_cutoff)
      call lub_fold_strain(f, f2, lub%species_radius(s1), lub%species_radius(s2))
      if (s1 == s2) then
        t(1:n_pair_scalars) = interpolate(lub%species_pair(s1, s1)%gap, lub%species_pair(s1, s1)%resolved, xi)
        f = f - t(1:n_pair_scalars)
        f2 = f2 - exchange_sign * t(1:n_pair_scalars)
      else if (s1 < s2) then
        t = interpolate(lub%species_pair(s1, s2)%gap, lub%species_pair(s1, s2)%resolved, xi)
        f = f - t(1:n_pair_scalars)
        f2 = f2 - t(n_pair_scalars + 1:)
      else
        t = interpolate(lub%species_pair(s2, s1)%gap, lub%species_pair(s2, s1)%resolved, xi)
        f = f - exchange_sign * t(n_pair_scalars + 1:)
        f2 = f2 - exchange_sign * t(1:n_pair_scalars)
      end if
    end if
    f = taper * f
    f2 = taper * f2
  end subroutine lub_sized_scalars

  !> The strain (M) functions of two spheres of radii a1 and a2 folded into each sphere's own slot,
  !> in place: R_SE enters the stresslet of sphere 1 only as M11 (5/6) pi eta (2 a1)^3 + M12 (5/6)
  !> pi eta (a1 + a2)^3 (mod_resistance_blocks pair_resistance_se_sized), so the 11 slots of f
  !> take M11 + M12 ((a1 + a2)/(2 a1))^3 and the 12 slots 0; likewise the 22 slots of f2 take
  !> M22 + M21 ((a1 + a2)/(2 a2))^3 and the 21 slots 0. The stresslets are unchanged for every
  !> strain (test_lubrication_mixture); the calibrated tables of a mixture hold the M functions
  !> so folded (their measured stresslet separates no further). For a1 = a2 the factor is 1
  !> exactly: the sums M11 + M12 of the equal-sphere tables.
  pure subroutine lub_fold_strain(f, f2, a1, a2)
    real(dp), intent(inout) :: f(n_pair_scalars), f2(n_pair_scalars)
    real(dp), intent(in) :: a1, a2
    integer, parameter :: m11(3) = [i_xm11, i_ym11, i_zm11], m12(3) = [i_xm12, i_ym12, i_zm12]
    f(m11) = f(m11) + f(m12) * ((a1 + a2) / (2.0_dp * a1))**3
    f(m12) = 0.0_dp
    f2(m11) = f2(m11) + f2(m12) * ((a1 + a2) / (2.0_dp * a2))**3
    f2(m12) = 0.0_dp
  end subroutine lub_fold_strain

  !> The wall floor (lub%wall_floor, that of a sphere of radius lub%radius) of a sphere of radius
  !> a: lub_wall_floor scales with the fictitious-fluid moment of inertia, a^5 (doc/METHOD.md §5.8).
  pure real(dp) function lub_species_wall_floor(lub, a) result(floor)
    type(lubrication_t), intent(in) :: lub
    real(dp), intent(in) :: a
    floor = lub%wall_floor * (a / lub%radius)**5
  end function lub_species_wall_floor

  !> One lubricating pair of unequal spheres, radii a1, a2 (as lub_pair_link): r = R_FU of the
  !> sized blocks, drive = r . (U_inf, Om_inf) + R_FE : E_inf. Model 'exact': its eigenvalues
  !> clipped in the metric of scale (clip_scaled: r >= -diag(scale^2), scale (12) set by the caller
  !> from each sphere's one-body block). Model 'full' (the DNS): made positive semi-definite
  !> (clip_to_psd) as the equal-sphere full model's blocks, scale unused: the fictitious-fluid
  !> mass carries each sphere's one-body resistance, so no link may take any of it.
  subroutine lub_pair_link_sized(lub, f, f2, d, a1, a2, u_inf, om_inf, e_inf, scale, r, drive, info)
    type(lubrication_t), intent(in) :: lub
    real(dp), intent(in) :: f(n_pair_scalars), f2(n_pair_scalars), d(3), a1, a2, u_inf(3, 2), om_inf(3), &
                            e_inf(3, 3), scale(12)
    real(dp), intent(out) :: r(12, 12), drive(12)
    integer, intent(out), optional :: info
    if (lub%model == LUB_FULL) then
      r = clip_to_psd(pair_resistance_fu_sized(f, f2, d, a1, a2, lub%viscosity), info=info)
    else
      r = clip_scaled(pair_resistance_fu_sized(f, f2, d, a1, a2, lub%viscosity), scale, info)
    end if
    drive = matmul(r, [u_inf(:, 1), om_inf, u_inf(:, 2), om_inf]) + strain_part(f, f2, d, a1, a2, lub%viscosity, e_inf)
  end subroutine lub_pair_link_sized

  ! R_FE : E of two unequal spheres
  pure function strain_part(f, f2, d, a1, a2, viscosity, e) result(ft)
    real(dp), intent(in) :: f(n_pair_scalars), f2(n_pair_scalars), d(3), a1, a2, viscosity, e(3, 3)
    real(dp) :: ft(12), rfe(12, 3, 3)
    integer :: m
    rfe = pair_resistance_fe_sized(f, f2, d, a1, a2, viscosity)
    do m = 1, 12
      ft(m) = sum(rfe(m, :, :) * e)
    end do
  end function strain_part

  !> Stresslet corrections of a pair of unequal spheres (3, 3, 2), as lub_pair_stresslets: the
  !> deviatoric R_SU . w + R_SE : E of the sized blocks, and the particle-pressure trace with each
  !> sphere's own lever, tr S_alpha = a_alpha n_alpha . F_alpha (n_1 = d, n_2 = -d; d . F_alpha is
  !> the squeeze part, from the unclipped blocks as for equal spheres).
  function lub_pair_stresslets_sized(lub, f, f2, d, a1, a2, w, e_inf) result(s)
    type(lubrication_t), intent(in) :: lub
    real(dp), intent(in) :: f(n_pair_scalars), f2(n_pair_scalars), d(3), a1, a2, w(12), e_inf(3, 3)
    real(dp) :: s(3, 3, 2), ft(12)
    integer :: k
    s = pair_stresslets_sized(f, f2, d, w, e_inf, a1, a2, lub%viscosity)
    ft = matmul(pair_resistance_fu_sized(f, f2, d, a1, a2, lub%viscosity), w) &
         + strain_part(f, f2, d, a1, a2, lub%viscosity, e_inf)
    do k = 1, 3
      s(k, k, 1) = s(k, k, 1) + a1 * dot_product(d, ft(1:3)) / 3.0_dp
      s(k, k, 2) = s(k, k, 2) - a2 * dot_product(d, ft(7:9)) / 3.0_dp
    end do
  end function lub_pair_stresslets_sized

  !> The symmetric a with its eigenvalues in the metric S = diag(scale) clipped at -1:
  !> b = S clip_to_psd(S^-1 a S^-1, -1) S, so that b + S^2 is positive semi-definite. With S^2 a
  !> share of the two spheres' one-body blocks, each sphere's links cannot lower its one-body
  !> resistance by more than that share, whatever its size (doc/LUBRICATION.md).
  function clip_scaled(a, scale, info) result(b)
    real(dp), intent(in) :: a(:, :), scale(:)
    integer, intent(out), optional :: info
    real(dp) :: b(size(a, 1), size(a, 2)), c(size(a, 1), size(a, 2))
    integer :: i, j
    do j = 1, size(a, 2)
      do i = 1, size(a, 1)
        c(i, j) = a(i, j) / (scale(i) * scale(j))
      end do
    end do
    c = clip_to_psd(c, -1.0_dp, info)
    do j = 1, size(a, 2)
      do i = 1, size(a, 1)
        b(i, j) = c(i, j) * scale(i) * scale(j)
      end do
    end do
  end function clip_scaled

  !> The nearest positive semi-definite matrix (Frobenius norm) of a symmetric matrix: negative
  !> eigenvalues set to zero; with floor (<= 0), eigenvalues below floor set to floor instead.
  !> info (optional): 0, or dsyev's code when the decomposition failed (non-finite a); the result
  !> is then NaN, so that a caller without info still cannot go on with a wrong block unseen.
  function clip_to_psd(a, floor, info) result(b)
    real(dp), intent(in) :: a(:, :)
    real(dp), intent(in), optional :: floor
    integer, intent(out), optional :: info
    real(dp) :: b(size(a, 1), size(a, 2)), lowest
    real(dp) :: v(size(a, 1), size(a, 1)), ev(size(a, 1)), work(64 * size(a, 1))
    integer :: n, status, k
    external :: dsyev, dpotrf, dsyr
    n = size(a, 1)
    b = 0.5_dp * (a + transpose(a))
    lowest = 0.0_dp
    if (present(floor)) lowest = min(floor, 0.0_dp)
    ! Most links are positive definite above the floor already, and then b is the answer: a
    ! Cholesky factorisation of b - lowest I proves it at ~1/20 of an eigen-decomposition's cost.
    v = b
    do k = 1, n
      v(k, k) = v(k, k) - lowest
    end do
    if (present(info)) info = 0
    call dpotrf('U', n, v, n, status)
    if (status == 0) return
    ! Otherwise b = sum_k max(ev_k, lowest) v_k v_k^T = b - sum_{ev_k < lowest} (ev_k - lowest) v_k v_k^T:
    ! a rank-one update per clipped eigenvalue (LAPACK's dsyevr with a range was measured no faster
    ! than dsyev on these blocks, whose spectra span 1e4 with pairs of equal eigenvalues).
    v = b
    call dsyev('V', 'U', n, v, n, ev, work, size(work), status)
    if (status /= 0) then
      b = ieee_value(1.0_dp, ieee_quiet_nan)
      if (present(info)) info = status
      return
    end if
    if (ev(1) >= lowest) return
    do k = 1, n
      if (ev(k) >= lowest) exit
      call dsyr('U', n, -(ev(k) - lowest), v(:, k), 1, b, n)
    end do
    ! dsyr updates the upper triangle only
    do k = 1, n - 1
      b(k + 1:n, k) = b(k, k + 1:n)
    end do
  end function clip_to_psd

  !> The floor of a wall block's eigenvalues in the resolved DNS: a quarter of the smallest
  !> eigenvalue of the fictitious-fluid mass (rho/dt) J, J = (2/5) a^2 (4/3) pi a^3 the moment of
  !> inertia of a sphere of radius a (rho = Re in fdsusp's units; doc/METHOD.md §5.8).
  pure real(dp) function lub_wall_floor(reynolds, dt, radius)
    real(dp), intent(in) :: reynolds, dt, radius
    lub_wall_floor = -0.25_dp * (reynolds / dt) * 0.4_dp * radius**2 * (4.0_dp / 3.0_dp) * pi * radius**3
  end function lub_wall_floor

end module mod_lubrication
