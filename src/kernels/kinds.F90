! Kinds shared by every fdsusp module. Pure Fortran: no PETSc, no MPI.
module mod_kinds
  use, intrinsic :: iso_fortran_env, only: real64, int32, int64
  implicit none
  private
  public :: dp, i4, i8, pi

  integer, parameter :: dp = real64   ! matches PetscReal of Debian's petsc-dev (real, double)
  integer, parameter :: i4 = int32
  integer, parameter :: i8 = int64
  real(dp), parameter :: pi = 3.14159265358979323846264338327950288_dp
end module mod_kinds
