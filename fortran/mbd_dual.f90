!> mbd_dual: directional derivatives of the point quantities (forward mode, one direction).
!!
!! A direction is a change (dq, dq_dot) of the local state and dp of the parameters. Every
!! quantity of mbd_points (a kvec: value v, Jacobian d, velocity vd, acceleration remainder
!! ar) gets its derivative along the direction, which is again a kvec of the same fields:
!!   dvec%a  the quantity itself,  dvec%t  d/de of each of its fields at (q + e dq,
!!           q_dot + e dq_dot, p + e dp).
!! So a constraint row evaluated on dual quantities gives, besides Phi, J and gamma,
!!   t%v  = Phi_q dq + Phi_p dp          t%d  = (J_q dq + J_p dp)  (a local block of J's change)
!!   t%ar = ar_q dq + ar_q_dot dq_dot + ar_p dp,   gamma's change = -t%ar (+ time terms).
!! With dq = e_k (a slot) t%d is a column of the local Hessian of Phi; with dp = e_k (a
!! parameter) t%v, t%d, -t%ar are Phi_p, J_p and gamma_p (Haug, ch. 6 on design sensitivity).
!!
!! Every operation of mbd_points is bilinear in the fields of its operands (products) or
!! linear (sums), so its derivative is the same operation applied to (t_a, b) plus (a, t_b):
!! the joints write their dual rows with the same generic names as their plain rows.
!! Body-fixed quantities A(theta) w turn with the body: d/dtheta of every field is perp of
!! that field; the rates enter vd and ar through theta_dot and alpha_dot.
module mbd_dual
  use mbd_kinds, only: wp, zero, one, two, half
  use mbd_points, only: NLOC, MAXROW, kvec, kscal, kloc, &
                        curve_vector, curve_point, body_point, body_vector, body_angle, &
                        slot_value, const_vec, vsub, vadd, vscale, vdot, vcross, ssub, sadd, &
                        sscale, ssqrt, sconst, put_vec, put_scal
  implicit none
  private
  public :: dloc, dvec, dscal, dual_state, point_terms_d, point_values, point_changes
  public :: curve_vector, curve_point, body_point, body_vector, body_angle, slot_value, &
            const_vec, vsub, vadd, vscale, vdot, vcross, ssub, sadd, sscale, ssqrt, sconst, &
            put_vec, put_scal

  !> A local state and a direction in it.
  type :: dloc
    type(kloc) :: x                  !! the state
    real(wp) :: tq(NLOC) = zero      !! direction in the coordinates
    real(wp) :: tqd(NLOC) = zero     !! direction in the velocities
  end type dloc

  !> A 2-vector quantity and its derivative along the direction.
  type :: dvec
    type(kvec) :: a                  !! value, Jacobian, velocity, remainder
    type(kvec) :: t                  !! their derivatives along the direction
  end type dvec

  !> A scalar quantity and its derivative along the direction.
  type :: dscal
    type(kscal) :: a
    type(kscal) :: t
  end type dscal

  interface curve_vector
    module procedure curve_vector_d
  end interface curve_vector
  interface curve_point
    module procedure curve_point_d
  end interface curve_point
  interface body_point
    module procedure body_point_d
  end interface body_point
  interface body_vector
    module procedure body_vector_d
  end interface body_vector
  interface body_angle
    module procedure body_angle_d
  end interface body_angle
  interface slot_value
    module procedure slot_value_d
  end interface slot_value
  interface const_vec
    module procedure const_vec_d
  end interface const_vec
  interface vsub
    module procedure vsub_d
  end interface vsub
  interface vadd
    module procedure vadd_d
  end interface vadd
  interface vscale
    module procedure vscale_d, vscale_dd
  end interface vscale
  interface vdot
    module procedure vdot_d
  end interface vdot
  interface vcross
    module procedure vcross_d
  end interface vcross
  interface ssub
    module procedure ssub_d
  end interface ssub
  interface sadd
    module procedure sadd_d
  end interface sadd
  interface sscale
    module procedure sscale_d, sscale_dd
  end interface sscale
  interface ssqrt
    module procedure ssqrt_d
  end interface ssqrt
  interface sconst
    module procedure sconst_d
  end interface sconst
  interface put_vec
    module procedure put_vec_d
  end interface put_vec
  interface put_scal
    module procedure put_scal_d
  end interface put_scal

contains

  !> A local state with a direction.
  pure function dual_state(x, tq, tqd) result(xd)
    type(kloc), intent(in) :: x          !! state
    real(wp), intent(in) :: tq(NLOC)     !! direction in q
    real(wp), intent(in) :: tqd(NLOC)    !! direction in q_dot
    type(dloc) :: xd
    xd%x = x; xd%tq = tq; xd%tqd = tqd
  end function dual_state

  !> Body vector A(theta) u(alpha) and its derivative along (dtheta, dalpha, dtheta_dot,
  !! dalpha_dot) and the parameter change (tu, tu1, tu2) of u, u', u''.
  !! The fields are linear in (u, u', u''): their change through alpha and the parameters is
  !! the same vector with u <- u' dalpha + tu, u' <- u'' dalpha + tu1, u'' <- u''' dalpha + tu2;
  !! the turn dtheta adds perp of every field; the rates add
  !!   vd: B u dthd + A u' dald,   ar: -2 A u thd dthd + 2 B u' (dthd ald + thd dald)
  !!                                   + 2 A u'' ald dald.
  pure function curve_vector_d(x, slot, aslot, u, u1, u2, u3, tu, tu1, tu2) result(a)
    type(dloc), intent(in) :: x          !! local state and direction
    integer, intent(in) :: slot          !! 0 ground, 1 first body, 2 second body
    integer, intent(in) :: aslot         !! 0, or the slot of the curve parameter
    real(wp), intent(in) :: u(2), u1(2), u2(2), u3(2)  !! u and its alpha derivatives
    real(wp), intent(in) :: tu(2), tu1(2), tu2(2)      !! parameter changes of u, u', u''
    type(dvec) :: a
    real(wp) :: dal, dald, ald, thd, dth, dthd, cs, sn, au(2), au1(2), au2(2), bu(2), bu1(2)
    integer :: c, k
    dal = zero; dald = zero; ald = zero
    if (aslot > 0) then
      dal = x%tq(aslot); dald = x%tqd(aslot); ald = x%x%qd(aslot)
    end if
    a%a = curve_vector(x%x, slot, aslot, u, u1, u2)
    a%t = curve_vector(x%x, slot, aslot, u1 * dal + tu, u2 * dal + tu1, u3 * dal + tu2)
    if (slot == 0) then
      if (aslot > 0) then
        a%t%vd = a%t%vd + u1 * dald
        a%t%ar = a%t%ar + two * u2 * ald * dald
      end if
      return
    end if
    c = 3 * (slot - 1)
    thd = x%x%qd(c + 3); dth = x%tq(c + 3); dthd = x%tqd(c + 3)
    cs = x%x%c(slot); sn = x%x%s(slot)
    ! the turn: d/dtheta (A w) = perp(A w), for every field of the value
    a%t%v = a%t%v + dth * [-a%a%v(2), a%a%v(1)]
    do k = 1, NLOC
      a%t%d(1, k) = a%t%d(1, k) - dth * a%a%d(2, k)
      a%t%d(2, k) = a%t%d(2, k) + dth * a%a%d(1, k)
    end do
    a%t%vd = a%t%vd + dth * [-a%a%vd(2), a%a%vd(1)]
    a%t%ar = a%t%ar + dth * [-a%a%ar(2), a%a%ar(1)]
    ! the rates
    au = [cs * u(1) - sn * u(2), sn * u(1) + cs * u(2)]
    bu = [-au(2), au(1)]
    a%t%vd = a%t%vd + bu * dthd
    a%t%ar = a%t%ar - two * au * thd * dthd
    if (aslot > 0) then
      au1 = [cs * u1(1) - sn * u1(2), sn * u1(1) + cs * u1(2)]
      au2 = [cs * u2(1) - sn * u2(2), sn * u2(1) + cs * u2(2)]
      bu1 = [-au1(2), au1(1)]
      a%t%vd = a%t%vd + au1 * dald
      a%t%ar = a%t%ar + two * bu1 * (dthd * ald + thd * dald) + two * au2 * ald * dald
    end if
  end function curve_vector_d

  !> Body point r + A(theta) s(alpha) on a curve, and its derivative: the change of r and
  !! r_dot adds to v and vd.
  pure function curve_point_d(x, slot, aslot, s, s1, s2, s3, ts, ts1, ts2) result(a)
    type(dloc), intent(in) :: x          !! local state and direction
    integer, intent(in) :: slot          !! 0 ground, 1 first body, 2 second body
    integer, intent(in) :: aslot         !! slot of the curve parameter (or 0)
    real(wp), intent(in) :: s(2), s1(2), s2(2), s3(2)  !! s and its alpha derivatives
    real(wp), intent(in) :: ts(2), ts1(2), ts2(2)      !! parameter changes of s, s', s''
    type(dvec) :: a
    integer :: c
    a = curve_vector_d(x, slot, aslot, s, s1, s2, s3, ts, ts1, ts2)
    if (slot == 0) return
    c = 3 * (slot - 1)
    a%a%v = a%a%v + x%x%q(c + 1:c + 2)
    a%a%d(1, c + 1) = one; a%a%d(2, c + 2) = one
    a%a%vd = a%a%vd + x%x%qd(c + 1:c + 2)
    a%t%v = a%t%v + x%tq(c + 1:c + 2)
    a%t%vd = a%t%vd + x%tqd(c + 1:c + 2)
  end function curve_point_d

  !> Body point P = r + A s' whose s' changes by ts (written out: the most used leaf).
  !! With a = A s', b = perp(a) = B s', e = A ts:
  !!   t_v = dr + b dth + e,   t_d(:, theta) = -a dth + perp(e),
  !!   t_vd = dr_dot + (-a dth + perp(e)) thd + b dthd,  t_ar = -(b dth + e) thd**2 - 2 a thd dthd.
  pure function body_point_d(x, slot, s, ts) result(a)
    type(dloc), intent(in) :: x          !! local state and direction
    integer, intent(in) :: slot          !! 0 ground (s global), 1 or 2
    real(wp), intent(in) :: s(2), ts(2)  !! point in the body frame and its change
    type(dvec) :: a
    real(wp) :: au(2), bu(2), tdt(2)
    integer :: c
    if (slot == 0) then
      a%a%v = s; a%t%v = ts
      return
    end if
    c = 3 * (slot - 1)
    call point_values(x%x, slot, s, a%a%v, bu, a%a%ar, au)
    call point_changes(x, slot, ts, au, bu, a%t%v, tdt, a%t%ar)
    a%a%d(1, c + 1) = one; a%a%d(2, c + 2) = one
    a%a%d(:, c + 3) = bu
    a%a%vd = x%x%qd(c + 1:c + 2) + bu * x%x%qd(c + 3)
    a%t%d(:, c + 3) = tdt
    a%t%vd = x%tqd(c + 1:c + 2) + tdt * x%x%qd(c + 3) + bu * x%tqd(c + 3)
  end function body_point_d

  !> The fields of body_point_d without the product-rule types (the joints that only compare
  !! points use these, as point_terms in mbd_points): the value P, its theta column bs of J,
  !! its velocity and acceleration remainder, and their changes tp, tbs, tvd, tar.
  pure subroutine point_terms_d(x, slot, s, ts, p, bs, ar, tp, tbs, tar)
    type(dloc), intent(in) :: x          !! local state and direction
    integer, intent(in) :: slot          !! 0 ground (s global), 1 or 2
    real(wp), intent(in) :: s(2), ts(2)  !! point in the body frame and its change
    real(wp), intent(out) :: p(2), bs(2), ar(2)      !! P, B s', -A s' thd**2
    real(wp), intent(out) :: tp(2), tbs(2), tar(2)   !! their changes
    real(wp) :: au(2)
    call point_values(x%x, slot, s, p, bs, ar, au)
    call point_changes(x, slot, ts, au, bs, tp, tbs, tar)
  end subroutine point_terms_d

  !> The values of point_terms_d: P = r + A s', B s', -A s' thd**2 and A s' (au).
  pure subroutine point_values(x, slot, s, p, bs, ar, au)
    type(kloc), intent(in) :: x          !! local state
    integer, intent(in) :: slot          !! 0 ground (s global), 1 or 2
    real(wp), intent(in) :: s(2)         !! point in the body frame
    real(wp), intent(out) :: p(2), bs(2), ar(2), au(2)
    real(wp) :: cs, sn, thd
    integer :: c
    if (slot == 0) then
      p = s; bs = zero; ar = zero; au = zero
      return
    end if
    c = 3 * (slot - 1)
    cs = x%c(slot); sn = x%s(slot)
    thd = x%qd(c + 3)
    au = [cs * s(1) - sn * s(2), sn * s(1) + cs * s(2)]
    bs = [-au(2), au(1)]
    p = x%q(c + 1:c + 2) + au
    ar = -au * thd**2
  end subroutine point_values

  !> The changes of point_terms_d along x's direction and the change ts of s', from the
  !! values au = A s' and bs = B s' (point_values).
  pure subroutine point_changes(x, slot, ts, au, bs, tp, tbs, tar)
    type(dloc), intent(in) :: x          !! local state and direction
    integer, intent(in) :: slot          !! 0 ground (s global), 1 or 2
    real(wp), intent(in) :: ts(2)        !! change of the point
    real(wp), intent(in) :: au(2), bs(2) !! A s', B s'
    real(wp), intent(out) :: tp(2), tbs(2), tar(2)
    real(wp) :: cs, sn, thd, dth, dthd, e(2)
    integer :: c
    if (slot == 0) then
      tp = ts; tbs = zero; tar = zero
      return
    end if
    c = 3 * (slot - 1)
    cs = x%x%c(slot); sn = x%x%s(slot)
    thd = x%x%qd(c + 3); dth = x%tq(c + 3); dthd = x%tqd(c + 3)
    e = [cs * ts(1) - sn * ts(2), sn * ts(1) + cs * ts(2)]
    tp = x%tq(c + 1:c + 2) + bs * dth + e
    tbs = [-e(2), e(1)] - au * dth
    tar = -(bs * dth + e) * thd**2 - two * au * thd * dthd
  end subroutine point_changes

  !> Body-fixed direction A u' whose u' changes by tu (body_point_d without r).
  pure function body_vector_d(x, slot, u, tu) result(a)
    type(dloc), intent(in) :: x          !! local state and direction
    integer, intent(in) :: slot          !! 0 ground, 1 or 2
    real(wp), intent(in) :: u(2), tu(2)  !! vector in the body frame and its change
    type(dvec) :: a
    real(wp) :: cs, sn, thd, dth, dthd, au(2), bu(2), e(2), pe(2), tdt(2)
    integer :: c
    if (slot == 0) then
      a%a%v = u; a%t%v = tu
      return
    end if
    c = 3 * (slot - 1)
    cs = x%x%c(slot); sn = x%x%s(slot)
    thd = x%x%qd(c + 3); dth = x%tq(c + 3); dthd = x%tqd(c + 3)
    au = [cs * u(1) - sn * u(2), sn * u(1) + cs * u(2)]
    bu = [-au(2), au(1)]
    e = [cs * tu(1) - sn * tu(2), sn * tu(1) + cs * tu(2)]
    pe = [-e(2), e(1)]
    a%a%v = au
    a%a%d(:, c + 3) = bu
    a%a%vd = bu * thd
    a%a%ar = -au * thd**2
    tdt = pe - au * dth
    a%t%v = bu * dth + e
    a%t%d(:, c + 3) = tdt
    a%t%vd = tdt * thd + bu * dthd
    a%t%ar = -(bu * dth + e) * thd**2 - two * au * thd * dthd
  end function body_vector_d

  !> A constant vector u (changing by tu).
  pure function const_vec_d(u, tu) result(a)
    real(wp), intent(in) :: u(2), tu(2)  !! value and change
    type(dvec) :: a
    a%a%v = u; a%t%v = tu
  end function const_vec_d

  !> The angle theta of a body: changes by dtheta, its rate by dtheta_dot.
  pure function body_angle_d(x, slot) result(a)
    type(dloc), intent(in) :: x          !! local state and direction
    integer, intent(in) :: slot          !! 0 ground, 1 or 2
    type(dscal) :: a
    integer :: c
    if (slot == 0) return
    c = 3 * (slot - 1)
    a%a = body_angle(x%x, slot)
    a%t%v = x%tq(c + 3); a%t%vd = x%tqd(c + 3)
  end function body_angle_d

  !> A local coordinate as a scalar quantity.
  pure function slot_value_d(x, s) result(a)
    type(dloc), intent(in) :: x          !! local state and direction
    integer, intent(in) :: s             !! slot
    type(dscal) :: a
    a%a = slot_value(x%x, s)
    a%t%v = x%tq(s); a%t%vd = x%tqd(s)
  end function slot_value_d

  !> a - b.
  pure function vsub_d(a, b) result(c)
    type(dvec), intent(in) :: a, b   !! operands
    type(dvec) :: c
    c%a = vsub(a%a, b%a); c%t = vsub(a%t, b%t)
  end function vsub_d

  !> a + b.
  pure function vadd_d(a, b) result(c)
    type(dvec), intent(in) :: a, b   !! operands
    type(dvec) :: c
    c%a = vadd(a%a, b%a); c%t = vadd(a%t, b%t)
  end function vadd_d

  !> s a for a constant s.
  pure function vscale_d(s, a) result(c)
    real(wp), intent(in) :: s        !! constant factor
    type(dvec), intent(in) :: a      !! vector
    type(dvec) :: c
    c%a = vscale(s, a%a); c%t = vscale(s, a%t)
  end function vscale_d

  !> s a for a parameter s changing by ts:  t = s t_a + ts a.
  pure function vscale_dd(s, ts, a) result(c)
    real(wp), intent(in) :: s, ts    !! factor and its change
    type(dvec), intent(in) :: a      !! vector
    type(dvec) :: c
    c%a = vscale(s, a%a); c%t = vadd(vscale(s, a%t), vscale(ts, a%a))
  end function vscale_dd

  !> a . b:  t = t_a . b + a . t_b (every field of the product is bilinear).
  pure function vdot_d(a, b) result(c)
    type(dvec), intent(in) :: a, b   !! operands
    type(dscal) :: c
    c%a = vdot(a%a, b%a); c%t = sadd(vdot(a%t, b%a), vdot(a%a, b%t))
  end function vdot_d

  !> a x b:  t = t_a x b + a x t_b.
  pure function vcross_d(a, b) result(c)
    type(dvec), intent(in) :: a, b   !! operands
    type(dscal) :: c
    c%a = vcross(a%a, b%a); c%t = sadd(vcross(a%t, b%a), vcross(a%a, b%t))
  end function vcross_d

  !> a - b for scalars.
  pure function ssub_d(a, b) result(c)
    type(dscal), intent(in) :: a, b  !! operands
    type(dscal) :: c
    c%a = ssub(a%a, b%a); c%t = ssub(a%t, b%t)
  end function ssub_d

  !> a + b for scalars.
  pure function sadd_d(a, b) result(c)
    type(dscal), intent(in) :: a, b  !! operands
    type(dscal) :: c
    c%a = sadd(a%a, b%a); c%t = sadd(a%t, b%t)
  end function sadd_d

  !> s a for a constant s.
  pure function sscale_d(s, a) result(c)
    real(wp), intent(in) :: s        !! constant factor
    type(dscal), intent(in) :: a     !! scalar
    type(dscal) :: c
    c%a = sscale(s, a%a); c%t = sscale(s, a%t)
  end function sscale_d

  !> s a for a parameter s changing by ts.
  pure function sscale_dd(s, ts, a) result(c)
    real(wp), intent(in) :: s, ts    !! factor and its change
    type(dscal), intent(in) :: a     !! scalar
    type(dscal) :: c
    c%a = sscale(s, a%a); c%t = sadd(sscale(s, a%t), sscale(ts, a%a))
  end function sscale_dd

  !> A parameter s changing by ts.
  pure function sconst_d(s, ts) result(c)
    real(wp), intent(in) :: s, ts    !! value and change
    type(dscal) :: c
    c%a%v = s; c%t%v = ts
  end function sconst_d

  !> sqrt(a): with y = sqrt(v), g = 1/(2 y), the value fields are a_d g, a_vd g and
  !! a_ar g - 2 a_vd**2 g**3 (mbd_points); their changes follow with dy = g t_v,
  !! dg = -g dy / y.
  pure function ssqrt_d(a) result(c)
    type(dscal), intent(in) :: a     !! argument (> 0)
    type(dscal) :: c
    real(wp) :: y, g, dy, dg
    c%a = ssqrt(a%a)
    y = c%a%v
    g = half / y
    dy = g * a%t%v
    dg = -g * dy / y
    c%t%v = dy
    c%t%d = a%t%d * g + a%a%d * dg
    c%t%vd = a%t%vd * g + a%a%vd * dg
    c%t%ar = a%t%ar * g + a%a%ar * dg - 4.0_wp * a%a%vd * a%t%vd * g**3 &
             - 6.0_wp * a%a%vd**2 * g**2 * dg
  end function ssqrt_d

  !> The changes of two constraint rows: Phi, the local J block and gamma = -ar.
  pure subroutine put_vec_d(a, tphi, tjl, tgam)
    type(dvec), intent(in) :: a            !! the constraint vector
    real(wp), intent(inout) :: tphi(:)     !! change of Phi (2)
    real(wp), intent(inout) :: tjl(:, :)   !! change of the local J rows (2 x NLOC)
    real(wp), intent(inout) :: tgam(:)     !! change of gamma (2)
    tphi(1:2) = a%t%v; tjl(1:2, :) = a%t%d; tgam(1:2) = -a%t%ar
  end subroutine put_vec_d

  !> The changes of one constraint row.
  pure subroutine put_scal_d(a, tphi, tjl, tgam)
    type(dscal), intent(in) :: a           !! the constraint scalar
    real(wp), intent(inout) :: tphi        !! change of Phi
    real(wp), intent(inout) :: tjl(:)      !! change of the local J row (NLOC)
    real(wp), intent(inout) :: tgam        !! change of gamma
    tphi = a%t%v; tjl = a%t%d; tgam = -a%t%ar
  end subroutine put_scal_d

end module mbd_dual
