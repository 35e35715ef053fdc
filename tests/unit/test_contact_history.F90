! Unit test of the contact history of mod_contact (the history is keyed by pair
! identity, surviving neighbour-list rebuilds and periodic images; checkpoint pack/unpack).
! System: a hard-sphere packing (phi = 0.45, Couette cell 16 x 10 x 16 a, 275 spheres) with
! eps_r = 0.02, so that ~70 pairs and some wall contacts are closed; every sphere translates with
! U0 = (2, 0, 1.5) plus a random velocity of size 0.05 and spins at random (|Omega| ~ 1), so
! contacts persist for hundreds of steps, slide, and are carried across the periodic boundaries.
! Invariants:
!   1. Pair identity: run A (unwrapped positions, pair list rebuilt every step with no skin, in
!      the list's order) and run B (positions wrapped into the box every step, as the time step
!      does; a skin-0.5a list rebuilt only when a sphere has moved skin/2; every pair written as
!      (j, i) half the time and the list shuffled) hold the same contacts at every step (packed
!      ids identical) with the same springs and forces to 1e-10 relative. The runs differ only
!      by the rounding of x - L against x (~2e-15 a at x ~ 16 a) and by the order in which a
!      sphere's contact forces are summed; against overlaps of ~1e-3 a that perturbs
!      F ~ |delta'|^{3/2} by ~1e-12 relative (measured: ~1e-11 after 500 steps), so 1e-10 tests
!      the keying while leaving room for rounding. Contacts carried across a periodic boundary
!      while closed are counted and must occur.
!   2. Pack -> unpack round-trips exactly: the packed arrays of the unpacked history are
!      bitwise equal to the originals, also when the columns are given in another order; a run
!      continued from the unpacked history is bitwise identical to the original for 100 steps
!      (same springs, same forces): what an exact restart needs.
!   3. Unpack refuses invalid ids (owner outside 1..np, partner not above the owner and not a
!      wall, a duplicate contact) and leaves the history empty; contact_forces refuses a history
!      built for another particle count.
!   4. With mu_d = 0 the same run never allocates the history.
program test_contact_history
  use mod_kinds, only: dp
  use mod_contact, only: contact_params_t, contact_setup, contact_history_t, history_size, &
                         history_pack, history_unpack, contact_forces, contact_stats_t
  use mod_neighbours, only: nlist_t, nlist_init, nlist_build, nlist_needs_rebuild
  use mod_packing, only: rng_t, rng_seed, rng_uniform, random_packing, packing_report_t
  use mod_packing_geometry, only: packing_count
  use mod_unit_checks, only: check, fail, finish
  implicit none
  real(dp), parameter :: box(3) = [16.0_dp, 10.0_dp, 16.0_dp], dt = 1.0e-3_dp
  logical, parameter :: per(3) = [.true., .false., .true.]
  type(contact_params_t) :: p, p0
  type(contact_history_t) :: ha, hb, hc, hbad
  type(contact_stats_t) :: st
  type(nlist_t) :: nla, nlb
  type(packing_report_t) :: rep
  type(rng_t) :: g
  real(dp), allocatable :: x0(:,:), xa(:,:), xb(:,:), u(:,:), om(:,:)
  real(dp), allocatable :: fa(:,:), ta(:,:), sa(:,:,:), fb(:,:), tb(:,:), sb(:,:,:)
  real(dp), allocatable :: fc(:,:), tc(:,:), sc(:,:,:), upa(:,:), upb(:,:), upc(:,:)
  integer, allocatable :: pb(:,:), ida(:,:), idb(:,:), idc(:,:), perm(:)
  real(dp) :: vw(3, 2), err_ups, err_f, umax
  integer :: n, info, step, i, k, m, npa, npb, crossings, rebuilds, nmax, np_out, tmp
  character(len=200) :: msg
  logical :: identical, same_ids

  call contact_setup(p, 1.0_dp, 0.02_dp, 0.5_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  n = packing_count(0.45_dp, box, 1.0_dp)
  call random_packing(n, box, per, 1.0_dp, 0.0_dp, 21, 100, x0, info, msg, rep)
  if (info /= 0) then
    print '(2a)', 'FAIL packing: ', trim(msg)
    error stop 1
  end if
  allocate(u(3, n), om(3, n), fa(3, n), ta(3, n), sa(3, 3, n), fb(3, n), tb(3, n), sb(3, 3, n))
  allocate(fc(3, n), tc(3, n), sc(3, 3, n))
  call rng_seed(g, 5)
  do i = 1, n
    do k = 1, 3
      u(k, i) = 0.05_dp * (2 * rng_uniform(g) - 1)
      om(k, i) = 2 * rng_uniform(g) - 1
    end do
    u(:, i) = u(:, i) + [2.0_dp, 0.0_dp, 1.5_dp]
    u(2, i) = u(2, i) * 0.2_dp                    ! keep wall contacts alive longer
  end do
  vw = 0
  nmax = 4 * n
  allocate(ida(2, nmax), idb(2, nmax), idc(2, nmax), upa(3, nmax), upb(3, nmax), upc(3, nmax))
  call nlist_init(nla, n, box, per, 2 + p%h_r + 1.0e-9_dp, 1 + p%h_r + 1.0e-9_dp, 0.0_dp, info)
  call nlist_init(nlb, n, box, per, 2.5_dp + p%h_r, 1.5_dp + p%h_r, 0.5_dp, info)
  xa = x0
  xb = x0
  call nlist_build(nlb, xb)
  rebuilds = 0
  crossings = 0
  err_ups = 0
  err_f = 0
  same_ids = .true.

  ! ---- 1. two runs that differ in list, order and wrapping
  do step = 1, 500
    call nlist_build(nla, xa)
    call contact_forces(p, ha, xa, u, om, box, per, vw, nla%pair, nla%npairs, nla%wall, &
                        nla%nwalls, dt, fa, ta, sa, st, info)
    if (nlist_needs_rebuild(nlb, xb)) then
      call nlist_build(nlb, xb)
      rebuilds = rebuilds + 1
    end if
    call shuffled_pairs(nlb, pb)
    call contact_forces(p, hb, xb, u, om, box, per, vw, pb, nlb%npairs, nlb%wall, nlb%nwalls, &
                        dt, fb, tb, sb, st, info)
    npa = history_size(ha)
    npb = history_size(hb)
    call history_pack(ha, np_out, ida, upa)
    call history_pack(hb, np_out, idb, upb)
    if (npa /= npb) then
      same_ids = .false.
    else if (any(ida(:, 1:npa) /= idb(:, 1:npb))) then
      same_ids = .false.
    else
      umax = max(maxval(abs(upa(:, 1:npa))), tiny(1.0_dp))
      err_ups = max(err_ups, maxval(abs(upa(:, 1:npa) - upb(:, 1:npb))) / umax)
    end if
    err_f = max(err_f, maxval(abs(fa - fb)) / maxval(abs(fa)))
    ! advance; run B wraps into the box and counts closed contacts carried across a boundary
    xa = xa + u * dt
    xb = xb + u * dt
    do i = 1, n
      do k = 1, 3
        if (per(k) .and. (xb(k, i) >= box(k) .or. xb(k, i) < 0)) then
          xb(k, i) = xb(k, i) - box(k) * floor(xb(k, i) / box(k))
          do m = 1, npb
            if (idb(1, m) == i .or. idb(2, m) == i) crossings = crossings + 1
          end do
        end if
      end do
    end do
  end do
  print '(a,i0,a,i0,a,i0,a,i0)', '1. N = ', n, ', contacts now ', npb, ' (wall ', &
    count(idb(2, 1:npb) < 0), '), list rebuilds in run B ', rebuilds
  print '(a,l1,a,es9.2,a,es9.2,a,i0)', '   same contacts every step ', same_ids, &
    ', max spring difference ', err_ups, ', max force difference ', err_f, &
    ', contacts carried across a periodic boundary ', crossings
  call check(same_ids, 'the runs hold the same contacts')
  call check(err_ups <= 1.0e-10_dp .and. err_f <= 1.0e-10_dp, 'the runs agree (springs and forces to 1e-10)')
  call check(crossings > 0, 'a contact crossed a periodic boundary (the test is conclusive)')
  call check(count(idb(2, 1:npb) < 0) > 0 .and. count(idb(2, 1:npb) > 0) > 0, 'both pair and wall contacts')

  ! ---- 2. pack -> unpack -> pack, in order and shuffled; continue bitwise
  call history_pack(hb, np_out, idb, upb)
  npb = history_size(hb)
  call history_unpack(hc, np_out, npb, idb, upb, info)
  call history_pack(hc, np_out, idc, upc)
  identical = info == 0 .and. history_size(hc) == npb
  if (identical) identical = all(idc(:, 1:npb) == idb(:, 1:npb)) .and. &
                             all(upc(:, 1:npb) == upb(:, 1:npb))
  perm = [(m, m = 1, npb)]
  do m = npb, 2, -1                                   ! Fisher-Yates
    k = 1 + int(m * rng_uniform(g))
    tmp = perm(m)
    perm(m) = perm(k)
    perm(k) = tmp
  end do
  call history_unpack(hc, np_out, npb, idb(:, perm), upb(:, perm), info)
  call history_pack(hc, np_out, idc, upc)
  if (identical) identical = info == 0 .and. all(idc(:, 1:npb) == idb(:, 1:npb)) .and. &
                             all(upc(:, 1:npb) == upb(:, 1:npb))
  print '(a,i0,a,l1)', '2. pack/unpack of ', npb, ' contacts (in order and shuffled) exact: ', identical
  call check(identical, 'pack -> unpack -> pack is the identity')
  identical = .true.
  do step = 1, 100
    if (nlist_needs_rebuild(nlb, xb)) call nlist_build(nlb, xb)
    call contact_forces(p, hb, xb, u, om, box, per, vw, nlb%pair, nlb%npairs, nlb%wall, &
                        nlb%nwalls, dt, fb, tb, sb, st, info)
    call contact_forces(p, hc, xb, u, om, box, per, vw, nlb%pair, nlb%npairs, nlb%wall, &
                        nlb%nwalls, dt, fc, tc, sc, st, info)
    identical = identical .and. all(fb == fc) .and. all(tb == tc) .and. all(sb == sc)
    xb = xb + u * dt
    xb(1, :) = xb(1, :) - box(1) * floor(xb(1, :) / box(1))
    xb(3, :) = xb(3, :) - box(3) * floor(xb(3, :) / box(3))
  end do
  npb = history_size(hb)
  call history_pack(hb, np_out, idb, upb)
  call history_pack(hc, np_out, idc, upc)
  identical = identical .and. history_size(hc) == npb
  if (identical) identical = all(idc(:, 1:npb) == idb(:, 1:npb)) .and. all(upc(:, 1:npb) == upb(:, 1:npb))
  print '(a,l1)', '   100 steps continued from the unpacked history are bitwise identical: ', identical
  call check(identical, 'continuation from the unpacked history is bitwise identical')

  ! ---- 3. refusals
  call refuse('owner 0', reshape([0, 2], [2, 1]))
  call refuse('owner > np', reshape([n + 1, -1], [2, 1]))
  call refuse('partner = owner', reshape([3, 3], [2, 1]))
  call refuse('partner below owner', reshape([5, 2], [2, 1]))
  call refuse('partner > np', reshape([5, n + 1], [2, 1]))
  call refuse('wall id -3', reshape([5, -3], [2, 1]))
  call refuse('duplicate', reshape([5, 9, 5, 9], [2, 2]))
  call contact_forces(p, hb, xb(:, 1:n - 1), u, om, box, per, vw, nlb%pair, 0, nlb%wall, 0, dt, &
                      fb, tb, sb, st, info)
  print '(a,i0)', '3. contact_forces with a history for another N: info ', info
  call check(info == 1, 'a history for another particle count is refused')

  ! ---- 4. frictionless: no history at all
  call contact_setup(p0, 1.0_dp, 0.02_dp, 0.0_dp, 0.05_dp, 0.0_dp, 1.0_dp, 1.0_dp, info, msg)
  xa = x0
  do step = 1, 20
    call nlist_build(nla, xa)
    call contact_forces(p0, hbad, xa, u, om, box, per, vw, nla%pair, nla%npairs, nla%wall, &
                        nla%nwalls, dt, fa, ta, sa, st, info)
    xa = xa + u * dt
  end do
  print '(a,i0,a,l1)', '4. mu_d = 0: contacts ', st%pair_contacts + st%wall_contacts, &
    ', history allocated ', allocated(hbad%partner) .or. allocated(hbad%owner)
  call check(.not. (allocated(hbad%partner) .or. allocated(hbad%owner) .or. history_size(hbad) /= 0 .or. &
             st%pair_contacts == 0), 'mu_d = 0 allocates no history')

  call finish('test_contact_history')

contains

  !> The pairs of nl, every other one written (j, i), in a random order.
  subroutine shuffled_pairs(nl, out)
    type(nlist_t), intent(in) :: nl
    integer, allocatable, intent(out) :: out(:,:)
    integer :: mm, kk, t2(2)
    out = nl%pair(:, 1:nl%npairs)
    do mm = 1, nl%npairs, 2
      out(:, mm) = out([2, 1], mm)
    end do
    do mm = nl%npairs, 2, -1
      kk = 1 + int(mm * rng_uniform(g))
      t2 = out(:, mm)
      out(:, mm) = out(:, kk)
      out(:, kk) = t2
    end do
  end subroutine shuffled_pairs

  subroutine refuse(label, ids)
    character(len=*), intent(in) :: label
    integer, intent(in) :: ids(:,:)
    type(contact_history_t) :: hr
    real(dp) :: ups(3, size(ids, 2))
    integer :: inf
    ups = 1
    call history_unpack(hr, n, size(ids, 2), ids, ups, inf)
    print '(a,a20,a,i0,a,i0)', '3. unpack refuses ', label, ': info ', inf, ', size ', history_size(hr)
    call check(inf /= 0 .and. history_size(hr) == 0, 'unpack refuses '//label)
  end subroutine refuse

end program test_contact_history
