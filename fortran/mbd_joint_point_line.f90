!> mbd_joint_point_line: a point of body j on a line fixed in body i (point on line; the
!! revolute-translational composite, a pin in a straight slot).
!!
!! h_i = A_i perp(u'_i) (unit normal of the line),  d = P_j - P_i
!! Phi = h_i . d - c = 0        c: offset of the pin from the slot centre line   (1 row)
!! J and gamma by the product rule, as in the translational joint's first row (Haug 3.4.3).
!! Raw parameters: [s'_i(2), s'_j(2), u'_i(2), c]; prepared: [s'_i, s'_j, perp(unit u'_i), c].
module mbd_joint_point_line
  use mbd_kinds, only: wp, zero
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, kloc, body_point, body_vector, vsub, vdot, ssub, sconst, &
                        put_scal, perp
  use mbd_dual, only: dloc, body_point, body_vector, vsub, vdot, ssub, sconst, put_scal
  implicit none
  private
  public :: point_line_prepare, point_line_eval, point_line_prepare_d, point_line_eval_d

contains

  !> Normalize the line direction and store its normal.
  subroutine point_line_prepare(raw, prep, status, msg)
    real(wp), intent(in) :: raw(:)                 !! [s'_i, s'_j, u'_i, c]
    real(wp), allocatable, intent(out) :: prep(:)  !! [s'_i, s'_j, h'_i, c]
    integer, intent(out) :: status                 !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    real(wp) :: n
    status = MBD_OK; msg = ''
    n = hypot(raw(5), raw(6))
    if (.not. (n > zero)) then
      status = MBD_BAD_PARAM; msg = 'line direction has zero length'; return
    end if
    prep = [raw(1:4), perp(raw(5:6) / n), raw(7)]
  end subroutine point_line_prepare

  !> Row of Phi, J (local block) and gamma.
  pure subroutine point_line_eval(p, si, sj, x, phi, jl, gam)
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids (i carries the line)
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(inout) :: phi(MAXROW), jl(MAXROW, NLOC), gam(MAXROW)  !! 1 row written
    call put_scal(ssub(vdot(body_vector(x, si, p(5:6)), &
                            vsub(body_point(x, sj, p(3:4)), body_point(x, si, p(1:2)))), &
                       sconst(p(7))), phi(1), jl(1, :), gam(1))
  end subroutine point_line_eval

  !> Change of the prepared parameters when raw(j) changes by one: the normal
  !! h' = perp(u/|u|) changes by perp((e - u^ (u^ . e)) / |u|) for u changing by e.
  pure subroutine point_line_prepare_d(raw, j, tprep)
    real(wp), intent(in) :: raw(:)          !! [s'_i, s'_j, u'_i, c]
    integer, intent(in) :: j                !! raw entry
    real(wp), intent(out) :: tprep(:)       !! change of [s'_i, s'_j, h'_i, c] (7)
    real(wp) :: n, uh(2), e(2)
    tprep = zero
    select case (j)
    case (5, 6)
      n = hypot(raw(5), raw(6)); uh = raw(5:6) / n
      e = zero; e(j - 4) = 1.0_wp
      tprep(5:6) = perp((e - uh * dot_product(uh, e)) / n)
    case default
      tprep(j) = 1.0_wp
    end select
  end subroutine point_line_prepare_d

  !> Change of the row along a direction and a parameter change tp (mbd_dual).
  pure subroutine point_line_eval_d(p, tp, si, sj, x, tphi, tjl, tgam)
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids (i carries the line)
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(inout) :: tphi(MAXROW), tjl(MAXROW, NLOC), tgam(MAXROW)  !! 1 row
    call put_scal(ssub(vdot(body_vector(x, si, p(5:6), tp(5:6)), &
                            vsub(body_point(x, sj, p(3:4), tp(3:4)), &
                                 body_point(x, si, p(1:2), tp(1:2)))), &
                       sconst(p(7), tp(7))), tphi(1), tjl(1, :), tgam(1))
  end subroutine point_line_eval_d

end module mbd_joint_point_line
