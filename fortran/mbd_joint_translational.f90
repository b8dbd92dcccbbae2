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
  use mbd_dual, only: dloc, dscal, body_point, body_vector, body_angle, vsub, vdot, ssub, &
                      sconst, put_scal
  implicit none
  private
  public :: translational_prepare, translational_eval, slide_distance
  public :: translational_prepare_d, translational_eval_d, slide_distance_d

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

  !> Change of the prepared parameters when raw(j) changes by one: the unit axis
  !! u^ = u/|u| changes by (e - u^ (u^ . e))/|u|, and theta0 = atan2(u_i) - atan2(u_j) by
  !! (u_x e_y - u_y e_x)/|u|**2 (with a minus for u_j).
  pure subroutine translational_prepare_d(raw, j, tprep)
    real(wp), intent(in) :: raw(:)          !! [s'_i, s'_j, u'_i, u'_j]
    integer, intent(in) :: j                !! raw entry
    real(wp), intent(out) :: tprep(:)       !! change of the prepared parameters (9)
    real(wp) :: n, uh(2), e(2), du(2)
    tprep = zero
    select case (j)
    case (1:4)
      tprep(j) = 1.0_wp
    case (5, 6)
      n = hypot(raw(5), raw(6)); uh = raw(5:6) / n
      e = zero; e(j - 4) = 1.0_wp
      du = (e - uh * dot_product(uh, e)) / n
      tprep(5:6) = du; tprep(7:8) = perp(du)
      tprep(9) = (raw(5) * e(2) - raw(6) * e(1)) / n**2
    case (7, 8)
      n = hypot(raw(7), raw(8))
      e = zero; e(j - 6) = 1.0_wp
      tprep(9) = -(raw(7) * e(2) - raw(8) * e(1)) / n**2
    end select
  end subroutine translational_prepare_d

  !> The slide and its change along a direction and a parameter change tp (mbd_dual).
  pure function slide_distance_d(p, tp, si, sj, x) result(s)
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the two bodies
    type(dloc), intent(in) :: x             !! local state and direction
    type(dscal) :: s
    s = relative_along_d(p, tp, p(5:6), tp(5:6), si, sj, x)
  end function slide_distance_d

  pure function relative_along_d(p, tp, u, tu, si, sj, x) result(s)
    real(wp), intent(in) :: p(:), tp(:), u(2), tu(2)
    integer, intent(in) :: si, sj
    type(dloc), intent(in) :: x
    type(dscal) :: s
    s = vdot(body_vector(x, si, u, tu), &
             vsub(body_point(x, sj, p(3:4), tp(3:4)), body_point(x, si, p(1:2), tp(1:2))))
  end function relative_along_d

  !> Changes of the rows along a direction and a parameter change tp (mbd_dual).
  pure subroutine translational_eval_d(p, tp, si, sj, x, tphi, tjl, tgam)
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the two bodies (0 = ground)
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(inout) :: tphi(MAXROW), tjl(MAXROW, NLOC), tgam(MAXROW)  !! 2 rows
    call put_scal(relative_along_d(p, tp, p(7:8), tp(7:8), si, sj, x), tphi(1), tjl(1, :), &
                  tgam(1))
    call put_scal(ssub(ssub(body_angle(x, sj), body_angle(x, si)), sconst(p(9), tp(9))), &
                  tphi(2), tjl(2, :), tgam(2))
  end subroutine translational_eval_d

end module mbd_joint_translational
