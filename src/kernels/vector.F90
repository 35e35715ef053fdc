! Vector algebra in three dimensions shared by the physics kernels and pairtraj. Pure Fortran.
module mod_vector
  use mod_kinds, only: dp
  implicit none
  private
  public :: cross, outer

contains

  !> The cross product a x b.
  pure function cross(a, b) result(c)
    real(dp), intent(in) :: a(3), b(3)
    real(dp) :: c(3)
    c = [a(2) * b(3) - a(3) * b(2), a(3) * b(1) - a(1) * b(3), a(1) * b(2) - a(2) * b(1)]
  end function cross

  !> The dyad a b: c(i, j) = a(i) b(j).
  pure function outer(a, b) result(c)
    real(dp), intent(in) :: a(3), b(3)
    real(dp) :: c(3, 3)
    integer :: j
    do j = 1, 3
      c(:, j) = a * b(j)
    end do
  end function outer

end module mod_vector
