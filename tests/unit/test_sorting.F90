! Invariants of mod_sorting, checked against lists written out by hand:
!  1. ascending_order sorts, and keeps equal keys in their given order (stable: the lexicographic
!     order of the contacts' springs sorts by the second key, then stably by the first);
!  2. sorted_position finds every entry of an ascending list at its place, and answers 0 for a
!     value that is not in it (below, between, above its entries; a wall's negative id; an empty
!     list) -- the bisection the ranks' local sets use to find their own spheres (mod_ld_local,
!     mod_contacts_io).
! Exact comparisons: integers.
program test_sorting
  use mod_sorting, only: ascending_order, sorted_position
  use mod_unit_checks, only: check, finish
  implicit none
  integer, parameter :: ids(7) = [2, 3, 5, 8, 13, 21, 34]
  integer :: first(6), second(6), order(6), k
  logical :: all_found

  call check(all(ascending_order([5, 1, 4, 1, 3]) == [2, 4, 5, 3, 1]), &
             'ascending_order: 5 1 4 1 3 sorted, the two 1s in their given order')
  ! pairs (first, second): sorted by second, then stably by first
  first = [3, 1, 2, 1, 3, 2]
  second = [9, 7, -1, 4, 2, 8]
  order = ascending_order(second)
  order = order(ascending_order(first(order)))
  call check(all(first(order) == [1, 1, 2, 2, 3, 3]) .and. all(second(order) == [4, 7, -1, 8, 2, 9]), &
             'ascending_order twice: pairs in lexicographic order')

  all_found = .true.
  do k = 1, size(ids)
    all_found = all_found .and. sorted_position(ids, ids(k)) == k
  end do
  call check(all_found, 'sorted_position: each of 7 entries at its place')
  call check(sorted_position(ids, 1) == 0 .and. sorted_position(ids, 4) == 0 .and. sorted_position(ids, 35) == 0, &
             'sorted_position: 0 below, between and above the entries')
  call check(sorted_position(ids, -1) == 0 .and. sorted_position([integer ::], 3) == 0, &
             'sorted_position: 0 for a wall''s id and in an empty list')
  call finish('test_sorting')
end program test_sorting
