!> mbd_joint_translational: the translational (prismatic) joint.
!!
!! With d = P_j - P_i (P = r + A s'), h_i = A_i perp(u'_i) the normal to the axis on body i:
!! Phi_1 = h_i . d = 0                    the point of body j stays on the line of body i
!! Phi_2 = theta_j - theta_i - theta0 = 0  the axes stay parallel (relative rotation locked)
!! theta0 = angle(u'_i) - angle(u'_j), so the two given axes are aligned.    (Haug 3.3.2)
!! J and gamma follow from the product rule (mbd_points):
!! gamma_1 = -(h_i . ar_d + d . ar_h + 2 h_dot . d_dot),  gamma_2 = 0.
!! Raw parameters: [s'_i(2), s'_j(2), u'_i(2), u'_j(2)].
!! Prepared: [s'_i(2), s'_j(2), unit u'_i(2), perp(u'_i)(2), theta0].
module mbd_joint_translational
  use mbd_kinds, only: wp, zero
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, kloc, kscal, body_point, body_vector, body_angle, vsub, &
                        vdot, ssub, sconst, put_scal, perp
  implicit none
  private
  public :: translational_prepare, translational_eval, slide_distance

contains

  !> Normalize the axes and compute theta0.
  subroutine translational_prepare(raw, prep, status, msg)
    real(wp), intent(in) :: raw(:)                 !! [s'_i, s'_j, u'_i, u'_j]
    real(wp), allocatable, intent(out) :: prep(:)  !! prepared parameters
    integer, intent(out) :: status                 !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    real(wp) :: ni, nj, ui(2)
    status = MBD_OK; msg = ''
    ni = hypot(raw(5), raw(6)); nj = hypot(raw(7), raw(8))
    if (.not. (ni > zero .and. nj > zero)) then
      status = MBD_BAD_PARAM; msg = 'translational joint axis has zero length'; return
    end if
    ui = raw(5:6) / ni
    prep = [raw(1:4), ui, perp(ui), atan2(raw(6), raw(5)) - atan2(raw(8), raw(7))]
  end subroutine translational_prepare

  !> The slide s = (P_j - P_i) . A_i u'_i along the axis (used by the distance driver).
  pure function slide_distance(p, si, sj, x) result(s)
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the two bodies
    type(kloc), intent(in) :: x             !! local state
    type(kscal) :: s
    s = relative_along(p, p(5:6), si, sj, x)
  end function slide_distance

  !> (P_j - P_i) . A_i u' for a direction u' fixed in body i.
  pure function relative_along(p, u, si, sj, x) result(s)
    real(wp), intent(in) :: p(:), u(2)
    integer, intent(in) :: si, sj
    type(kloc), intent(in) :: x
    type(kscal) :: s
    s = vdot(body_vector(x, si, u), &
             vsub(body_point(x, sj, p(3:4)), body_point(x, si, p(1:2))))
  end function relative_along

  !> Rows of Phi, J (local block) and gamma.
  pure subroutine translational_eval(p, si, sj, x, phi, jl, gam)
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the two bodies (0 = ground)
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(inout) :: phi(MAXROW)  !! rows of Phi (2 written)
    real(wp), intent(inout) :: jl(MAXROW, NLOC)  !! local block of J (2 rows written)
    real(wp), intent(inout) :: gam(MAXROW)  !! rows of gamma (2 written)
    type(kscal) :: s1, s2
    s1 = relative_along(p, p(7:8), si, sj, x)
    s2 = ssub(ssub(body_angle(x, sj), body_angle(x, si)), sconst(p(9)))
    call put_scal(s1, phi(1), jl(1, :), gam(1))
    call put_scal(s2, phi(2), jl(2, :), gam(2))
  end subroutine translational_eval

end module mbd_joint_translational
