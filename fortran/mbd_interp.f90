!> mbd_interp: quintic Hermite interpolation of a motion from positions, velocities and
!! accelerations at two times (dense output across steps and singular passages).
!!
!! s = (t - ta)/H, H = tb - ta:
!!   q(t) = H0 qa + H1 H va + H2 H^2 aa + H3 qb + H4 H vb + H5 H^2 ab
!!   H0 = 1 - 10s^3 + 15s^4 - 6s^5      H3 = 10s^3 - 15s^4 + 6s^5
!!   H1 = s - 6s^3 + 8s^4 - 3s^5        H4 = -4s^3 + 7s^4 - 3s^5
!!   H2 = s^2/2 - 3s^3/2 + 3s^4/2 - s^5/2   H5 = s^3/2 - s^4 + s^5/2
module mbd_interp
  use mbd_kinds, only: wp, half
  implicit none
  private
  public :: hermite5

contains

  !> q, q_dot, q_ddot at t from the states at ta and tb.
  pure subroutine hermite5(ta, qa, va, aa, tb, qb, vb, ab, t, q, v, a)
    real(wp), intent(in) :: ta, tb, t             !! anchor times and the wanted time
    real(wp), intent(in) :: qa(:), va(:), aa(:)   !! state at ta
    real(wp), intent(in) :: qb(:), vb(:), ab(:)   !! state at tb
    real(wp), intent(out) :: q(:), v(:), a(:)     !! state at t
    real(wp) :: hh, s, b(6), d(6), e(6)
    hh = tb - ta
    s = (t - ta) / hh
    b = [1 - 10 * s**3 + 15 * s**4 - 6 * s**5, s - 6 * s**3 + 8 * s**4 - 3 * s**5, &
         half * s**2 - 1.5_wp * s**3 + 1.5_wp * s**4 - half * s**5, &
         10 * s**3 - 15 * s**4 + 6 * s**5, -4 * s**3 + 7 * s**4 - 3 * s**5, &
         half * s**3 - s**4 + half * s**5]
    d = [-30 * s**2 + 60 * s**3 - 30 * s**4, 1 - 18 * s**2 + 32 * s**3 - 15 * s**4, &
         s - 4.5_wp * s**2 + 6 * s**3 - 2.5_wp * s**4, 30 * s**2 - 60 * s**3 + 30 * s**4, &
         -12 * s**2 + 28 * s**3 - 15 * s**4, 1.5_wp * s**2 - 4 * s**3 + 2.5_wp * s**4]
    e = [-60 * s + 180 * s**2 - 120 * s**3, -36 * s + 96 * s**2 - 60 * s**3, &
         1 - 9 * s + 18 * s**2 - 10 * s**3, 60 * s - 180 * s**2 + 120 * s**3, &
         -24 * s + 84 * s**2 - 60 * s**3, 3 * s - 12 * s**2 + 10 * s**3]
    q = b(1) * qa + b(2) * hh * va + b(3) * hh**2 * aa + b(4) * qb + b(5) * hh * vb + &
        b(6) * hh**2 * ab
    v = (d(1) * qa + d(4) * qb) / hh + d(2) * va + d(5) * vb + hh * (d(3) * aa + d(6) * ab)
    a = (e(1) * qa + e(4) * qb) / hh**2 + (e(2) * va + e(5) * vb) / hh + e(3) * aa + e(6) * ab
  end subroutine hermite5

end module mbd_interp
