!> mbd_joint_gear: a gear pair whose centres are carried by one body (ground or a carrier c),
!! with the tooth force at the pitch point along the line of action as its reaction.
!!
!! Rolling of the pitch circles, with the line of centres fixed in the carrier (Haug 3.5):
!!   external  Phi_0 = R_i (theta_i - theta_c) + R_j (theta_j - theta_c) - phase
!!   internal  Phi_0 = R_i (theta_i - theta_c) - R_j (theta_j - theta_c) - phase   (j: ring)
!! Phi_0 alone is angle-only: its multiplier would be a pure moment, and the gear pivots
!! would carry no tooth force. The row is therefore written with the gear centres
!! C_i = r_i + A_i c'_i, C_j = r_j + A_j c'_j, w = C_j - C_i, and the carrier-fixed unit
!! vector e = A_c u' of the line of centres (u' = (a'_j - a'_i) / d0, a' the centres in
!! the carrier frame, d0 = |a'_j - a'_i|; t = perp(e)):
!!   Phi = Phi_0 - (kappa / d0) (e x w) + rho (e . w - d0),   kappa = R_i +- R_j,
!!   rho = -sign(kappa) tan(pressure angle).
!! Where the joints of the gears hold the centres at a'_i, a'_j in the carrier, w = d0 e,
!! so e x w = 0 and e . w = d0: the added terms vanish and Phi has the zero set of Phi_0 (the
!! same kinematics). Their gradient turns the reaction -lambda J^T into the tooth force at
!! the pitch point P (on the line of centres, R_i from C_i): on gear i, for radii that match
!! the centre distance (d0 = |kappa|), a tangential part whose moment about C_i is
!! -lambda R_i, plus a radial part lambda tan(pressure angle) that pushes the gears apart
!! (external: F_i = -lambda (t + tan e), internal: F_i = lambda (t + tan e)); gear j takes
!! -F_i. The carrier angle drops out of J on the manifold (-kappa + kappa = 0), so the
!! carrier is loaded only through the pivots. The line of action is fixed: with a positive
!! pressure angle it is the flank that carries a positive lambda (a clockwise moment of the
!! mesh on gear i); a load the other way needs the other flank, a negative pressure angle.
!! The carrier angle sits in local slot 7; with ground as carrier the slot maps to nothing.
!! Raw parameters: [R_i, R_j, phase, pressure angle, c'_i(2), c'_j(2), a'_i(2), a'_j(2)]
!! (c': the centres in the gear frames, a': in the carrier frame; ground: global).
!! Prepared: [R_i, R_j, phase, kappa / d0, rho, c'_i(2), c'_j(2), u'(2), d0].
!! Sub-kinds: a = carrier body (0 ground), b = 1 external, 2 internal.
module mbd_joint_gear
  use mbd_kinds, only: wp, zero, one, pi
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, kloc, kvec, kscal, body_angle, body_point, slot_value, &
                        ssub, sadd, sscale, sconst, vsub, vdot, vcross, put_scal
  use mbd_dual, only: dloc, dvec, dscal, body_angle, body_point, slot_value, ssub, sadd, sscale, &
                      sconst, vsub, vdot, vcross, put_scal
  implicit none
  private
  public :: GEAR_EXTERNAL, GEAR_INTERNAL, CARRIER_SLOT, GEAR_RAW_LEN, gear_prepare, gear_eval
  public :: gear_prepare_d, gear_eval_d

  integer, parameter :: GEAR_EXTERNAL = 1, GEAR_INTERNAL = 2
  integer, parameter :: CARRIER_SLOT = 7
  integer, parameter :: GEAR_RAW_LEN = 12   !! raw parameters

contains

  !> Check the radii, the pressure angle and the centres; prepare the line of centres.
  subroutine gear_prepare(kind, raw, prep, status, msg)
    integer, intent(in) :: kind                    !! GEAR_EXTERNAL or GEAR_INTERNAL
    real(wp), intent(in) :: raw(:)                 !! raw parameters (GEAR_RAW_LEN)
    real(wp), allocatable, intent(out) :: prep(:)  !! prepared parameters
    integer, intent(out) :: status                 !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    real(wp) :: kappa, d0, u(2)
    status = MBD_OK; msg = ''
    if (.not. (raw(1) > zero .and. raw(2) > zero)) then
      status = MBD_BAD_PARAM; msg = 'gear pitch radii must be positive'; return
    end if
    if (kind /= GEAR_EXTERNAL .and. kind /= GEAR_INTERNAL) then
      status = MBD_BAD_PARAM; msg = 'gear kind must be 1 (external) or 2 (internal)'; return
    end if
    if (kind == GEAR_INTERNAL .and. .not. (raw(2) > raw(1))) then
      status = MBD_BAD_PARAM
      msg = 'an internal gear (ring, second body) needs a larger radius than its pinion'
      return
    end if
    if (.not. (abs(raw(4)) < 0.5_wp * pi)) then
      status = MBD_BAD_PARAM
      msg = 'gear pressure angle must lie between -pi/2 and pi/2 (radians)'; return
    end if
    u = raw(11:12) - raw(9:10)
    d0 = hypot(u(1), u(2))
    if (.not. (d0 > 1.0e-9_wp * max(raw(1), raw(2)))) then
      status = MBD_BAD_PARAM
      msg = 'the gear centres coincide: give the centers, or pivot the gears on the carrier'
      return
    end if
    kappa = raw(1) + raw(2)
    if (kind == GEAR_INTERNAL) kappa = raw(1) - raw(2)
    prep = [raw(1:3), kappa / d0, -sign(one, kappa) * tan(raw(4)), raw(5:8), u / d0, d0]
  end subroutine gear_prepare

  !> Row of Phi, J (local block) and gamma.
  pure subroutine gear_eval(kind, p, si, sj, x, phi, jl, gam)
    integer, intent(in) :: kind             !! GEAR_EXTERNAL or GEAR_INTERNAL
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the gears
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(inout) :: phi(MAXROW), jl(MAXROW, NLOC), gam(MAXROW)  !! 1 row written
    type(kscal) :: ai, aj, c, angles
    type(kvec) :: w, e
    real(wp) :: sgn
    c = slot_value(x, CARRIER_SLOT)
    ai = ssub(body_angle(x, si), c)
    aj = ssub(body_angle(x, sj), c)
    sgn = one
    if (kind == GEAR_INTERNAL) sgn = -one
    angles = ssub(sadd(sscale(p(1), ai), sscale(sgn * p(2), aj)), sconst(p(3)))
    w = vsub(body_point(x, sj, p(8:9)), body_point(x, si, p(6:7)))   ! C_j - C_i
    e = carrier_vector(x, p(10:11))
    call put_scal(sadd(sadd(angles, sscale(-p(4), vcross(e, w))), &
                       sscale(p(5), ssub(vdot(e, w), sconst(p(12))))), phi(1), jl(1, :), gam(1))
  end subroutine gear_eval

  !> A vector u' fixed in the carrier, whose angle is in CARRIER_SLOT:
  !! v = A_c u',  d_c = B_c u' = perp(v),  ar = -v thd_c**2.
  pure function carrier_vector(x, u) result(a)
    type(kloc), intent(in) :: x     !! local state
    real(wp), intent(in) :: u(2)    !! vector in the carrier frame
    type(kvec) :: a
    real(wp) :: cs, sn, thd
    cs = cos(x%q(CARRIER_SLOT)); sn = sin(x%q(CARRIER_SLOT)); thd = x%qd(CARRIER_SLOT)
    a%v = [cs * u(1) - sn * u(2), sn * u(1) + cs * u(2)]
    a%d(:, CARRIER_SLOT) = [-a%v(2), a%v(1)]
    a%vd = a%d(:, CARRIER_SLOT) * thd
    a%ar = -a%v * thd**2
  end function carrier_vector

  !> Change of the prepared parameters when raw(j) changes by one: kappa / d0 with
  !! kappa = R_i +- R_j; rho = -sign(kappa) tan(psi) changes by -sign(kappa) (1 + tan**2);
  !! the centres a' move d0 = |a'_j - a'_i| by u' . da and u' by (da - u' (u' . da)) / d0.
  pure subroutine gear_prepare_d(kind, raw, j, tprep)
    integer, intent(in) :: kind             !! GEAR_EXTERNAL or GEAR_INTERNAL
    real(wp), intent(in) :: raw(:)          !! raw parameters (GEAR_RAW_LEN)
    integer, intent(in) :: j                !! raw entry
    real(wp), intent(out) :: tprep(:)       !! change of the prepared parameters (12)
    real(wp) :: kappa, d0, u(2), da(2), dd0, sgn
    sgn = one
    if (kind == GEAR_INTERNAL) sgn = -one
    kappa = raw(1) + sgn * raw(2)
    u = raw(11:12) - raw(9:10)
    d0 = hypot(u(1), u(2)); u = u / d0
    tprep = zero
    select case (j)
    case (1)
      tprep(1) = one; tprep(4) = one / d0
    case (2)
      tprep(2) = one; tprep(4) = sgn / d0
    case (3)
      tprep(3) = one
    case (4)
      tprep(5) = -sign(one, kappa) * (one + tan(raw(4))**2)
    case (5:8)
      tprep(j + 1) = one
    case (9:12)
      da = zero
      if (j <= 10) then
        da(j - 8) = -one
      else
        da(j - 10) = one
      end if
      dd0 = dot_product(u, da)
      tprep(10:11) = (da - u * dd0) / d0
      tprep(12) = dd0
      tprep(4) = -kappa * dd0 / d0**2
    end select
  end subroutine gear_prepare_d

  !> Change of the row along a direction and a parameter change tp (mbd_dual).
  pure subroutine gear_eval_d(kind, p, tp, si, sj, x, tphi, tjl, tgam)
    integer, intent(in) :: kind             !! GEAR_EXTERNAL or GEAR_INTERNAL
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the gears
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(inout) :: tphi(MAXROW), tjl(MAXROW, NLOC), tgam(MAXROW)  !! 1 row
    type(dscal) :: ai, aj, c, angles
    type(dvec) :: w, e
    real(wp) :: sgn
    c = slot_value(x, CARRIER_SLOT)
    ai = ssub(body_angle(x, si), c)
    aj = ssub(body_angle(x, sj), c)
    sgn = one
    if (kind == GEAR_INTERNAL) sgn = -one
    angles = ssub(sadd(sscale(p(1), tp(1), ai), sscale(sgn * p(2), sgn * tp(2), aj)), &
                  sconst(p(3), tp(3)))
    w = vsub(body_point(x, sj, p(8:9), tp(8:9)), body_point(x, si, p(6:7), tp(6:7)))
    e = carrier_vector_d(x, p(10:11), tp(10:11))
    call put_scal(sadd(sadd(angles, sscale(-p(4), -tp(4), vcross(e, w))), &
                       sscale(p(5), tp(5), ssub(vdot(e, w), sconst(p(12), tp(12))))), &
                  tphi(1), tjl(1, :), tgam(1))
  end subroutine gear_eval_d

  !> carrier_vector and its change (as a body vector of mbd_dual, turning with the carrier
  !! angle in CARRIER_SLOT): with v = A_c u', e = A_c tu',
  !! t_v = perp(v) dth + e, t_d = -v dth + perp(e), t_vd = t_d thd + perp(v) dthd,
  !! t_ar = -(perp(v) dth + e) thd**2 - 2 v thd dthd.
  pure function carrier_vector_d(x, u, tu) result(a)
    type(dloc), intent(in) :: x     !! local state and direction
    real(wp), intent(in) :: u(2)    !! vector in the carrier frame
    real(wp), intent(in) :: tu(2)   !! its change
    type(dvec) :: a
    real(wp) :: cs, sn, thd, dth, dthd, e(2), pv(2)
    a%a = carrier_vector(x%x, u)
    cs = cos(x%x%q(CARRIER_SLOT)); sn = sin(x%x%q(CARRIER_SLOT))
    thd = x%x%qd(CARRIER_SLOT); dth = x%tq(CARRIER_SLOT); dthd = x%tqd(CARRIER_SLOT)
    e = [cs * tu(1) - sn * tu(2), sn * tu(1) + cs * tu(2)]
    pv = [-a%a%v(2), a%a%v(1)]
    a%t%v = pv * dth + e
    a%t%d(:, CARRIER_SLOT) = -a%a%v * dth + [-e(2), e(1)]
    a%t%vd = a%t%d(:, CARRIER_SLOT) * thd + pv * dthd
    a%t%ar = -(pv * dth + e) * thd**2 - 2 * a%a%v * thd * dthd
  end function carrier_vector_d

end module mbd_joint_gear
