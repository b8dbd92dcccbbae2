!> mbd_joint_rolling: rolling without slip on a straight line: rack and pinion, and a disc
!! rolling on a line.
!!
!! The line is fixed in body j: point P_j, unit direction U = A_j u'_j, normal h = perp(U).
!! The circle (pinion or disc) has centre C on body i and radius R. With d = C - P_j,
!!   s = U . d        travel of the centre along the line
!!   e = h . d        height of the centre above the line, sigma = sign(e)
!! no slip:  Phi_slip    = s + sigma R (theta_i - theta_j) - phase = 0
!! contact:  Phi_contact = sigma e - R = 0           (rolling disc only; the rack and pinion
!!                                                  keeps its centre distance by other joints)
!! A centre moving +s along U on the +h side turns the circle by -s/R relative to the line.
!! Raw parameters: [c'_i(2), p'_j(2), u'_j(2), R, phase].
!! Prepared: [c'_i, p'_j, unit u'_j, R, phase].
module mbd_joint_rolling
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, kloc, kvec, kscal, body_point, body_vector, body_angle, &
                        vsub, vdot, vcross, ssub, sadd, sscale, sconst, put_scal
  use mbd_dual, only: dloc, dvec, dscal, body_point, body_vector, body_angle, vsub, vdot, &
                      vcross, ssub, sadd, sscale, sconst, put_scal
  implicit none
  private
  public :: rolling_prepare, rolling_eval, rolling_prepare_d, rolling_eval_d

contains

  !> Normalize the line direction, check R.
  subroutine rolling_prepare(raw, prep, status, msg)
    real(wp), intent(in) :: raw(:)                 !! raw parameters
    real(wp), allocatable, intent(out) :: prep(:)  !! prepared parameters
    integer, intent(out) :: status                 !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    real(wp) :: n
    status = MBD_OK; msg = ''
    n = hypot(raw(5), raw(6))
    if (.not. (n > zero)) then
      status = MBD_BAD_PARAM; msg = 'line direction has zero length'; return
    end if
    if (.not. (raw(7) > zero)) then
      status = MBD_BAD_PARAM; msg = 'radius must be positive'; return
    end if
    prep = [raw(1:4), raw(5:6) / n, raw(7:8)]
  end subroutine rolling_prepare

  !> Rows of Phi, J (local block) and gamma: the no-slip row, then (contact) the contact row.
  pure subroutine rolling_eval(contact, p, si, sj, x, phi, jl, gam)
    logical, intent(in) :: contact          !! add the contact row (rolling disc)
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids: circle body, line body
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(inout) :: phi(MAXROW), jl(MAXROW, NLOC), gam(MAXROW)  !! 1 or 2 rows written
    type(kvec) :: u, d
    type(kscal) :: e, rel
    real(wp) :: sgn
    u = body_vector(x, sj, p(5:6))
    d = vsub(body_point(x, si, p(1:2)), body_point(x, sj, p(3:4)))
    e = vcross(u, d)                       ! h . d with h = perp(U)
    sgn = merge(-one, one, e%v < zero)
    rel = ssub(body_angle(x, si), body_angle(x, sj))
    call put_scal(ssub(sadd(vdot(u, d), sscale(sgn * p(7), rel)), sconst(p(8))), &
                  phi(1), jl(1, :), gam(1))
    if (contact) call put_scal(ssub(sscale(sgn, e), sconst(p(7))), phi(2), jl(2, :), gam(2))
  end subroutine rolling_eval

  !> Change of the prepared parameters when raw(j) changes by one: the unit direction
  !! u^ = u/|u| changes by (e - u^ (u^ . e))/|u|.
  pure subroutine rolling_prepare_d(raw, j, tprep)
    real(wp), intent(in) :: raw(:)          !! raw parameters
    integer, intent(in) :: j                !! raw entry
    real(wp), intent(out) :: tprep(:)       !! change of the prepared parameters (8)
    real(wp) :: n, uh(2), e(2)
    tprep = zero
    select case (j)
    case (5, 6)
      n = hypot(raw(5), raw(6)); uh = raw(5:6) / n
      e = zero; e(j - 4) = one
      tprep(5:6) = (e - uh * dot_product(uh, e)) / n
    case default
      tprep(j) = one
    end select
  end subroutine rolling_prepare_d

  !> Changes of the rows along a direction and a parameter change tp (mbd_dual); the side
  !! sigma = sign(e) is held.
  pure subroutine rolling_eval_d(contact, p, tp, si, sj, x, tphi, tjl, tgam)
    logical, intent(in) :: contact          !! add the contact row (rolling disc)
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids: circle body, line body
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(inout) :: tphi(MAXROW), tjl(MAXROW, NLOC), tgam(MAXROW)  !! 1 or 2 rows
    type(dvec) :: u, d
    type(dscal) :: e, rel
    real(wp) :: sgn
    u = body_vector(x, sj, p(5:6), tp(5:6))
    d = vsub(body_point(x, si, p(1:2), tp(1:2)), body_point(x, sj, p(3:4), tp(3:4)))
    e = vcross(u, d)
    sgn = merge(-one, one, e%a%v < zero)
    rel = ssub(body_angle(x, si), body_angle(x, sj))
    call put_scal(ssub(sadd(vdot(u, d), sscale(sgn * p(7), sgn * tp(7), rel)), &
                       sconst(p(8), tp(8))), tphi(1), tjl(1, :), tgam(1))
    if (contact) call put_scal(ssub(sscale(sgn, e), sconst(p(7), tp(7))), tphi(2), tjl(2, :), &
                               tgam(2))
  end subroutine rolling_eval_d

end module mbd_joint_rolling
