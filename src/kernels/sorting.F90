! Sorting of index lists (pure; no PETSc, MPI or files).
module mod_sorting
  implicit none
  private
  public :: ascending_order, sorted_position

contains

  !> The permutation that sorts key ascending, equal keys in their given order (a merge sort:
  !> n log n whatever the input, e.g. spheres gathered from several ranks in blocks).
  pure function ascending_order(key) result(order)
    integer, intent(in) :: key(:)
    integer :: order(size(key))
    integer :: work(size(key)), n, width, lo, mid, hi, i, j, k
    n = size(key)
    order = [(i, i = 1, n)]
    width = 1
    do while (width < n)
      lo = 1
      do while (lo <= n)
        mid = min(lo + width - 1, n)
        hi = min(lo + 2 * width - 1, n)
        i = lo
        j = mid + 1
        do k = lo, hi
          if (j > hi) then
            work(k) = order(i)
            i = i + 1
          else if (i > mid) then
            work(k) = order(j)
            j = j + 1
          else if (key(order(j)) < key(order(i))) then
            work(k) = order(j)
            j = j + 1
          else
            work(k) = order(i)
            i = i + 1
          end if
        end do
        lo = hi + 1
      end do
      order = work
      width = 2 * width
    end do
  end function ascending_order


  !> The position of g in the ascending list ids (a bisection); 0 when g is not in it.
  pure integer function sorted_position(ids, g) result(position)
    integer, intent(in) :: ids(:), g
    integer :: lo, hi, mid
    position = 0
    lo = 1
    hi = size(ids)
    do while (lo <= hi)
      mid = (lo + hi) / 2
      if (ids(mid) == g) then
        position = mid
        return
      else if (ids(mid) < g) then
        lo = mid + 1
      else
        hi = mid - 1
      end if
    end do
  end function sorted_position

end module mod_sorting
