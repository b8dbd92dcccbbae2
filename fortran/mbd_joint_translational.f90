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
  public :: translational_second, translational_param

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

  !> Second derivatives of the first row for the sensitivity equations, in closed form.
  !! Over the slots (r_i, theta_i, r_j, theta_j), with h = A_i n (n = perp(u'_i)), b = B_i n
  !! = perp(h), u_i = A_i s'_i, u_j = A_j s'_j, d = r_j + u_j - r_i - u_i, the Hessian
  !! H = Phi_1,qq is symmetric with
  !!   H(r_i, theta_i) = -b,  H(r_j, theta_i) = b,  H(theta_i, theta_i) = -h.d - n.s'_i,
  !!   H(theta_i, theta_j) = b.perp(u_j),  H(theta_j, theta_j) = -h.u_j,  the rest 0;
  !! hm(a, c) = dJ_a/dq_c = H(a, c); hv = H q_dot; and as gamma_1 = -q_dot' H q_dot,
  !! ha = H q_ddot - dgamma_1/dq = H q_ddot + g, g_c = q_dot' (dH/dq_c) q_dot:
  !!   g(theta_i) = 2 thd_i h.(v_i - v_j) - thd_i**2 J(theta_i) - 2 thd_i thd_j h.perp(u_j)
  !!                - thd_j**2 b.u_j,            J(theta_i) = b.d - h.perp(u_i),
  !!   g(theta_j) = -(thd_i**2 + thd_j**2) h.perp(u_j) - 2 thd_i thd_j b.u_j,
  !!   g(r_i) = thd_i**2 h,  g(r_j) = -thd_i**2 h        (v = r_dot of each body).
  !! The second row (the angles) is linear. A ground body's slots come with zero state and
  !! cos 1, sin 0; the caller keeps only the moving ones.
  pure subroutine translational_second(p, ci, si, cj, sj, ql, qdl, qddl, hm, hv, ha)
    real(wp), intent(in) :: p(9)            !! prepared parameters
    real(wp), intent(in) :: ci, si, cj, sj  !! cos and sin of theta_i, theta_j
    real(wp), intent(in) :: ql(6), qdl(6), qddl(6)  !! slot coordinates, velocities, accel.
    real(wp), intent(out) :: hm(6, 6)       !! dJ_a/dq_c of the first row
    real(wp), intent(out) :: hv(6), ha(6)   !! H q_dot, H q_ddot + g
    real(wp) :: h(2), b(2), ui(2), uj(2), pui(2), puj(2), d(2), jti, hpj, buj, wi, wj
    h = rot(ci, si, p(7:8)); b = [-h(2), h(1)]
    ui = rot(ci, si, p(1:2)); uj = rot(cj, sj, p(3:4))
    pui = [-ui(2), ui(1)]; puj = [-uj(2), uj(1)]
    d = ql(4:5) + uj - ql(1:2) - ui
    jti = dot_product(b, d) - dot_product(h, pui)
    hpj = dot_product(h, puj)
    buj = dot_product(b, uj)
    hm = zero
    hm(1:2, 3) = -b; hm(3, 1:2) = -b; hm(4:5, 3) = b; hm(3, 4:5) = b
    hm(3, 3) = -dot_product(h, d) - (p(7) * p(1) + p(8) * p(2))
    hm(3, 6) = dot_product(b, puj); hm(6, 3) = hm(3, 6)
    hm(6, 6) = -dot_product(h, uj)
    wi = qdl(3); wj = qdl(6)
    call hprod(qdl, hv)                                 ! H q_dot
    call hprod(qddl, ha)                                ! H q_ddot + g
    ha(1:2) = ha(1:2) + wi**2 * h; ha(4:5) = ha(4:5) - wi**2 * h
    ha(3) = ha(3) + (2 * wi * dot_product(h, qdl(1:2) - qdl(4:5)) - wi**2 * jti &
                     - 2 * wi * wj * hpj - wj**2 * buj)
    ha(6) = ha(6) + (-(wi**2 + wj**2) * hpj - 2 * wi * wj * buj)
  contains
    !> y = H v from H's nonzeros (hm holds them too, for the callers that need the blocks).
    pure subroutine hprod(v, y)
      real(wp), intent(in) :: v(6)
      real(wp), intent(out) :: y(6)
      y(1:2) = -b * v(3); y(4:5) = b * v(3)
      y(3) = dot_product(b, v(4:5) - v(1:2)) + hm(3, 3) * v(3) + hm(3, 6) * v(6)
      y(6) = hm(3, 6) * v(3) + hm(6, 6) * v(6)
    end subroutine hprod
  end subroutine translational_second

  !> The parameter parts for a change tp of the prepared parameters in closed form
  !! (translational_eval_d with dq = 0): with t(.) the change of each p-dependent quantity
  !! (t h = A_i t n, t b = perp(t h), t u_i = A_i t s'_i, t u_j = A_j t s'_j, t d =
  !! t u_j - t u_i) and the first row's time derivatives
  !!   Phi_1 = h.d,  dPhi_1/dt = h_dot.d + h.d_dot,
  !!   d2Phi_1/dt2 = h_ddot.d + 2 h_dot.d_dot + h.d_ddot,
  !!   h_dot = b thd_i, h_ddot = b thdd_i - h thd_i**2,
  !!   d_dot = v_j + perp(u_j) thd_j - v_i - perp(u_i) thd_i,
  !!   d_ddot = a_j + perp(u_j) thdd_j - u_j thd_j**2 - (a_i + perp(u_i) thdd_i - u_i thd_i**2),
  !! the parts are Phi_p = t(Phi_1), nu_p - J_p q_dot = -t(dPhi_1/dt), gamma_p - J_p q_ddot
  !! = -t(d2Phi_1/dt2) (no explicit time), and for the second row -t theta0, 0, 0.
  pure subroutine translational_param(p, tp, ci, si, cj, sj, ql, qdl, qddl, tphi, tv, ta)
    real(wp), intent(in) :: p(9), tp(9)     !! prepared parameters and their change
    real(wp), intent(in) :: ci, si, cj, sj  !! cos and sin of theta_i, theta_j
    real(wp), intent(in) :: ql(6), qdl(6), qddl(6)  !! slot coordinates, velocities, accel.
    real(wp), intent(out) :: tphi(2), tv(2), ta(2)  !! the two rows' parts
    real(wp) :: h(2), b(2), ui(2), uj(2), d(2), dd(2), ddd(2), hd(2), hdd(2)
    real(wp) :: th(2), tb(2), tui(2), tuj(2), td(2), tdd(2), tddd(2), thd(2), thdd(2)
    real(wp) :: wi, wj, ai, aj
    wi = qdl(3); wj = qdl(6); ai = qddl(3); aj = qddl(6)
    h = rot(ci, si, p(7:8)); b = [-h(2), h(1)]
    ui = rot(ci, si, p(1:2)); uj = rot(cj, sj, p(3:4))
    d = ql(4:5) + uj - ql(1:2) - ui
    dd = qdl(4:5) + [-uj(2), uj(1)] * wj - qdl(1:2) - [-ui(2), ui(1)] * wi
    ddd = qddl(4:5) + [-uj(2), uj(1)] * aj - uj * wj**2 &
          - (qddl(1:2) + [-ui(2), ui(1)] * ai - ui * wi**2)
    hd = b * wi; hdd = b * ai - h * wi**2
    th = rot(ci, si, tp(7:8)); tb = [-th(2), th(1)]
    tui = rot(ci, si, tp(1:2)); tuj = rot(cj, sj, tp(3:4))
    td = tuj - tui
    tdd = [-tuj(2), tuj(1)] * wj - [-tui(2), tui(1)] * wi
    tddd = [-tuj(2), tuj(1)] * aj - tuj * wj**2 - ([-tui(2), tui(1)] * ai - tui * wi**2)
    thd = tb * wi; thdd = tb * ai - th * wi**2
    tphi(1) = dot_product(th, d) + dot_product(h, td)
    tv(1) = -(dot_product(thd, d) + dot_product(hd, td) + dot_product(th, dd) &
              + dot_product(h, tdd))
    ta(1) = -(dot_product(thdd, d) + dot_product(hdd, td) + 2 * dot_product(thd, dd) &
              + 2 * dot_product(hd, tdd) + dot_product(th, ddd) + dot_product(h, tddd))
    tphi(2) = -tp(9); tv(2) = zero; ta(2) = zero
  end subroutine translational_param

  !> A v for the angle with cos c, sin s.
  pure function rot(c, s, v) result(w)
    real(wp), intent(in) :: c, s, v(2)
    real(wp) :: w(2)
    w = [c * v(1) - s * v(2), s * v(1) + c * v(2)]
  end function rot

end module mbd_joint_translational
