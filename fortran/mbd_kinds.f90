!> mbd_kinds: the one working precision and the named constants every module uses.
module mbd_kinds
  use iso_fortran_env, only: real64
  implicit none
  private
  public :: wp, zero, one, two, half, pi, eps

  integer, parameter :: wp = real64           !! working precision
  real(wp), parameter :: zero = 0.0_wp, one = 1.0_wp, two = 2.0_wp, half = 0.5_wp
  real(wp), parameter :: pi = 3.14159265358979323846264338327950288_wp
  real(wp), parameter :: eps = epsilon(1.0_wp)
end module mbd_kinds
