! The Lees-Edwards boundary of the resolved fluid (doc/METHOD.md §2.4): the shift in x that maps a
! grid row onto its image across the sliding boundary.
!
! The image above the box is the box shifted by (delta, Ly, 0) and moving faster by gamma_dot Ly in
! x (mod_lees_edwards has the same convention for the spheres), so a field read across y = 0 or
! y = Ly is a row of the box read at x + delta (below) or x - delta (above). delta is not a whole
! number of cells, so the row is interpolated: trigonometrically, every Fourier mode of the row
! multiplied by its phase exp(i k delta). Chosen over local (linear or cubic) interpolation
! because the fluid's direct solves diagonalise exactly that operator (mod_fft_solver: in x-Fourier
! space the boundary is a twist of each mode, which a phase ramp in y turns into an ordinary
! periodic problem), so the explicit stencils and the implicit solve describe one discrete
! problem, and the projection leaves div u = 0 to round-off across the boundary. The shift is
! unitary, and the shift by -delta is its inverse and its transpose, which the composition
! div(grad) needs: the highest mode of an even row (the Nyquist mode, a checkerboard in x) is
! real, and its trigonometric shift, cos(k delta), is neither; it is left unshifted instead (it
! carries no smooth part of a resolved flow).
!
! Rows are shifted on the rank that holds them (the boundary rows of a z-slab are local when
! neither x nor y is split among ranks: mod_grid picks that layout with Lees-Edwards). FFTW
! (R2HC/HC2R, FFTW 3.3 manual §4.8) plans once per row length and count. No PETSc.
module mod_sliding_boundary
  use, intrinsic :: iso_c_binding
  use mod_kinds, only: dp, pi
  implicit none
  private
  include 'fftw3.f03'
  public :: sliding_shift_rows, sliding_twist, sliding_boundary_release

  type(C_PTR), save :: plan_forward = C_NULL_PTR, plan_backward = C_NULL_PTR
  integer, save :: planned_n = 0, planned_rows = 0
  real(C_DOUBLE), pointer, contiguous, save :: work(:, :) => null()
  type(C_PTR), save :: work_memory = C_NULL_PTR

contains

  ! rows(:, r) := the periodic row r read at x + shift, shift in cells (any real number):
  ! trigonometric interpolation, the Nyquist mode of an even row unshifted (see the top).
  subroutine sliding_shift_rows(rows, shift)
    real(dp), intent(inout) :: rows(:, :)
    real(dp), intent(in) :: shift
    integer :: n, m, r
    real(dp) :: phase, c, s, re, im
    n = size(rows, 1)
    if (size(rows, 2) == 0) return
    call plan(n, size(rows, 2))
    work(:, 1:size(rows, 2)) = rows
    call fftw_execute_r2r(plan_forward, work, work)
    ! halfcomplex: mode m has its real part at m and its imaginary part at n - m (0-based)
    do m = 1, (n - 1) / 2
      phase = 2.0_dp * pi * m * shift / n
      c = cos(phase)
      s = sin(phase)
      do r = 1, size(rows, 2)
        re = work(m + 1, r)
        im = work(n - m + 1, r)
        work(m + 1, r) = re * c - im * s
        work(n - m + 1, r) = re * s + im * c
      end do
    end do
    call fftw_execute_r2r(plan_backward, work, work)
    rows = work(:, 1:size(rows, 2)) / n
  end subroutine sliding_shift_rows

  ! The twist theta of x-mode m (0-based, the DFT's exp(-2 pi i m x/Lx)) of a field read across
  ! the top of the box: f(x, y + Ly) = exp(i theta) f(x, y) in Fourier space, theta = -2 pi m
  ! delta/Lx; 0 for the mean and the Nyquist mode (unshifted, see the top). shift: delta in cells.
  pure real(dp) function sliding_twist(m, n, shift)
    integer, intent(in) :: m, n
    real(dp), intent(in) :: shift
    sliding_twist = 0.0_dp
    if (m >= 1 .and. m <= (n - 1) / 2) sliding_twist = -2.0_dp * pi * m * shift / n
  end function sliding_twist

  ! Plans for count rows of n points, in place on the work array (FFTW_ESTIMATE: the plan, and so
  ! the bits of the result, do not depend on timing).
  subroutine plan(n, count)
    integer, intent(in) :: n, count
    integer(C_INT) :: length(1)
    integer(C_FFTW_R2R_KIND) :: kind(1)
    real(C_DOUBLE), pointer, contiguous :: result(:, :)
    if (n == planned_n .and. count <= planned_rows) return
    call sliding_boundary_release()
    work_memory = fftw_alloc_real(int(n, C_SIZE_T) * int(count, C_SIZE_T))
    call c_f_pointer(work_memory, work, [n, count])
    result => work    ! in place (FFTW's arguments are two names for one array)
    length = n
    kind = FFTW_R2HC
    plan_forward = fftw_plan_many_r2r(1, length, count, work, length, 1, n, result, length, 1, n, kind, FFTW_ESTIMATE)
    kind = FFTW_HC2R
    plan_backward = fftw_plan_many_r2r(1, length, count, work, length, 1, n, result, length, 1, n, kind, FFTW_ESTIMATE)
    planned_n = n
    planned_rows = count
  end subroutine plan

  ! Frees the plans and the work array (made again by the next shift).
  subroutine sliding_boundary_release()
    if (c_associated(plan_forward)) call fftw_destroy_plan(plan_forward)
    if (c_associated(plan_backward)) call fftw_destroy_plan(plan_backward)
    if (c_associated(work_memory)) call fftw_free(work_memory)
    plan_forward = C_NULL_PTR
    plan_backward = C_NULL_PTR
    work_memory = C_NULL_PTR
    work => null()
    planned_n = 0
    planned_rows = 0
  end subroutine sliding_boundary_release

end module mod_sliding_boundary
