!> mbd_joint_revolute: the revolute (pin) joint.
!!
!! Phi = r_i + A_i s'_i - r_j - A_j s'_j = 0                       (2 rows)
!! J   = [I, B_i s'_i, -I, -B_j s'_j]
!! gamma = A_i s'_i thd_i**2 - A_j s'_j thd_j**2                    (Haug 3.3; the seed lesson)
!! Raw parameters: [s'_i(2), s'_j(2)] (a ground point is global).
module mbd_joint_revolute
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, kloc
  use mbd_dual, only: dloc, point_terms_d
  implicit none
  private
  public :: revolute_prepare, revolute_eval, revolute_eval_d, revolute_rows, &
            revolute_gamma_all, revolute_phi_all, revolute_curvature_all, &
            revolute_second_sides, revolute_second_rows, revolute_param_sides

contains

  !> Check and copy the parameters.
  subroutine revolute_prepare(raw, prep, status, msg)
    real(wp), intent(in) :: raw(:)                 !! [s'_i, s'_j]
    real(wp), allocatable, intent(out) :: prep(:)  !! same
    integer, intent(out) :: status                 !! MBD_OK
    character(len=MSG_LEN), intent(out) :: msg     !! empty
    status = MBD_OK; msg = ''
    prep = raw(1:4)
  end subroutine revolute_prepare

  !> Rows of Phi, J (local block) and gamma from the local state (revolute_kernel).
  pure subroutine revolute_eval(p, si, sj, x, phi, jl, gam)
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the two bodies (0 = ground)
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(inout) :: phi(MAXROW)  !! rows of Phi (2 written)
    real(wp), intent(inout) :: jl(MAXROW, NLOC)  !! local block of J (2 rows written)
    real(wp), intent(inout) :: gam(MAXROW)  !! rows of gamma (2 written)
    real(wp) :: ph(2), ga(2)
    call revolute_kernel(p(1:4), si > 0, sj > 0, x%q(1:2), x%c(1), x%s(1), x%qd(3), &
                         x%q(4:5), x%c(2), x%s(2), x%qd(6), ph, jl, ga)
    phi(1:2) = ph; gam(1:2) = ga
  end subroutine revolute_eval

  !> Changes of the rows of Phi, J and gamma along a direction (x) and a change tp of the
  !! parameters (mbd_dual), from the two points' terms and their changes:
  !! dPhi = dP_i - dP_j, dJ = [0, d(B_i s'_i), 0, -d(B_j s'_j)], dgamma = d(ar_j) - d(ar_i).
  pure subroutine revolute_eval_d(p, tp, si, sj, x, tphi, tjl, tgam)
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the two bodies (0 = ground)
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(inout) :: tphi(MAXROW), tjl(MAXROW, NLOC), tgam(MAXROW)  !! 2 rows
    real(wp) :: pi(2), bi(2), ai(2), pj(2), bj(2), aj(2), tpi(2), tbi(2), tai(2), tpj(2), &
                tbj(2), taj(2)
    call point_terms_d(x, si, p(1:2), tp(1:2), pi, bi, ai, tpi, tbi, tai)
    call point_terms_d(x, sj, p(3:4), tp(3:4), pj, bj, aj, tpj, tbj, taj)
    tphi(1:2) = tpi - tpj
    tjl(1:2, :) = zero
    if (si > 0) tjl(1:2, 3) = tbi
    if (sj > 0) tjl(1:2, 6) = -tbj
    tgam(1:2) = taj - tai
  end subroutine revolute_eval_d

  !> The same rows straight from the bodies' states (the assembly's path for the commonest
  !! joint: no local state gathered, no assumed-shape arguments). Body b (0 ground) has
  !! q(3b-2:3b) and q_dot(3b-2:3b), cos and sin c(b), s(b) (c(0) = 1, s(0) = 0).
  pure subroutine revolute_rows(p, bi, bj, q, qd, c, s, phi, jl, gam)
    real(wp), intent(in) :: p(4)            !! [s'_i, s'_j]
    integer, intent(in) :: bi, bj           !! bodies (0 ground)
    real(wp), intent(in) :: q(*), qd(*)     !! coordinates and velocities
    real(wp), intent(in) :: c(0:*), s(0:*)  !! cos and sin of the bodies' angles
    real(wp), intent(out) :: phi(2)         !! rows of Phi
    real(wp), intent(inout) :: jl(MAXROW, NLOC)  !! local block of J (rows 1 and 2 written)
    real(wp), intent(out) :: gam(2)         !! rows of gamma
    integer :: i3, j3
    i3 = max(3 * bi, 3); j3 = max(3 * bj, 3)      ! ground: any body's numbers, unused
    call revolute_kernel(p, bi > 0, bj > 0, q(i3 - 2:i3 - 1), c(bi), s(bi), qd(i3), &
                         q(j3 - 2:j3 - 1), c(bj), s(bj), qd(j3), phi, jl, gam)
  end subroutine revolute_rows

  !> The Phi rows of revolute_kernel alone (the same operations) for n revolutes at once,
  !! for the chord steps of positions-only kinematics: Phi = r_i + A_i s'_i - r_j - A_j s'_j.
  !! Revolute e has its [s'_i, s'_j] at p(tab(1, e)), bodies tab(2, e), tab(3, e) (0 ground)
  !! and its rows from tab(4, e).
  pure subroutine revolute_phi_all(n, tab, p, q, c, s, phi)
    integer, intent(in) :: n                !! revolutes
    integer, intent(in) :: tab(4, n)        !! parameter offset, bodies, first row
    real(wp), intent(in) :: p(*)            !! prepared parameter pool
    real(wp), intent(in) :: q(*)            !! coordinates
    real(wp), intent(in) :: c(0:*), s(0:*)  !! cos and sin of the bodies' angles
    real(wp), intent(inout) :: phi(*)       !! Phi (their rows written)
    real(wp) :: p1, p2
    integer :: e, o, b, r
    do e = 1, n
      o = tab(1, e); b = tab(2, e); r = tab(4, e)
      if (b > 0) then
        p1 = q(3 * b - 2) + (c(b) * p(o) - s(b) * p(o + 1))
        p2 = q(3 * b - 1) + (s(b) * p(o) + c(b) * p(o + 1))
      else
        p1 = p(o); p2 = p(o + 1)
      end if
      b = tab(3, e)
      if (b > 0) then
        p1 = p1 - (q(3 * b - 2) + (c(b) * p(o + 2) - s(b) * p(o + 3)))
        p2 = p2 - (q(3 * b - 1) + (s(b) * p(o + 2) + c(b) * p(o + 3)))
      else
        p1 = p1 - p(o + 2); p2 = p2 - p(o + 3)
      end if
      phi(r) = p1; phi(r + 1) = p2
    end do
  end subroutine revolute_phi_all

  !> u = d/d theta_b of J's column theta_b for n revolutes (tab as revolute_phi_all) at body
  !! b's angle (c = cos, s = sin): that column holds B_b s'_i on the side i of each revolute
  !! on b and -B_b s'_j on its side j, and dB/dtheta = -A, so u = -A_b s'_i there and
  !! +A_b s'_j; the revolutes' other columns are constant. u's other rows are left as given.
  pure subroutine revolute_curvature_all(n, tab, p, b, c, s, u)
    integer, intent(in) :: n                !! revolutes
    integer, intent(in) :: tab(4, n)        !! parameter offset, bodies, first row
    real(wp), intent(in) :: p(*)            !! prepared parameter pool
    integer, intent(in) :: b                !! body
    real(wp), intent(in) :: c, s            !! cos and sin of its angle
    real(wp), intent(inout) :: u(*)         !! rows of the revolutes on b written
    integer :: e, o, r
    do e = 1, n
      o = tab(1, e); r = tab(4, e)
      if (tab(2, e) == b) then
        u(r) = u(r) - (c * p(o) - s * p(o + 1))
        u(r + 1) = u(r + 1) - (s * p(o) + c * p(o + 1))
      end if
      if (tab(3, e) == b) then
        u(r) = u(r) + (c * p(o + 2) - s * p(o + 3))
        u(r + 1) = u(r + 1) + (s * p(o + 2) + c * p(o + 3))
      end if
    end do
  end subroutine revolute_curvature_all

  !> The gamma rows of revolute_kernel alone for n revolutes at once (tab as
  !! revolute_phi_all), for the second pass of a kinematic step (new velocities at the same
  !! q): gamma = A_i s'_i thd_i**2 - A_j s'_j thd_j**2.
  pure subroutine revolute_gamma_all(n, tab, p, qd, c, s, gam)
    integer, intent(in) :: n                !! revolutes
    integer, intent(in) :: tab(4, n)        !! parameter offset, bodies, first row
    real(wp), intent(in) :: p(*)            !! prepared parameter pool
    real(wp), intent(in) :: qd(*)           !! velocities
    real(wp), intent(in) :: c(0:*), s(0:*)  !! cos and sin of the bodies' angles
    real(wp), intent(inout) :: gam(*)       !! gamma (their rows written)
    real(wp) :: w2, g1, g2
    integer :: e, o, b, r
    do e = 1, n
      o = tab(1, e); b = tab(2, e); r = tab(4, e)
      g1 = zero; g2 = zero
      if (b > 0) then
        w2 = qd(3 * b)**2
        g1 = (c(b) * p(o) - s(b) * p(o + 1)) * w2; g2 = (s(b) * p(o) + c(b) * p(o + 1)) * w2
      end if
      b = tab(3, e)
      if (b > 0) then
        w2 = qd(3 * b)**2
        g1 = g1 - (c(b) * p(o + 2) - s(b) * p(o + 3)) * w2
        g2 = g2 - (s(b) * p(o + 2) + c(b) * p(o + 3)) * w2
      end if
      gam(r) = g1; gam(r + 1) = g2
    end do
  end subroutine revolute_gamma_all

  !> The revolute's rows from each body's position r, cos, sin and angular velocity w (g:
  !! the body moves; a ground point p(1:2) or p(3:4) is global):
  !! Phi = P_i - P_j, J = [I, B_i s'_i, -I, -B_j s'_j], gamma = A_i s'_i w_i**2 - A_j s'_j w_j**2.
  pure subroutine revolute_kernel(p, gi, gj, ri, ci, si, wi, rj, cj, sj, wj, phi, jl, gam)
    real(wp), intent(in) :: p(4)                  !! [s'_i, s'_j]
    logical, intent(in) :: gi, gj                 !! body i, body j moves
    real(wp), intent(in) :: ri(2), ci, si, wi     !! body i: r, cos, sin, theta_dot
    real(wp), intent(in) :: rj(2), cj, sj, wj     !! body j: the same
    real(wp), intent(out) :: phi(2), gam(2)       !! rows of Phi and gamma
    real(wp), intent(inout) :: jl(MAXROW, NLOC)   !! local block of J (rows 1 and 2 written)
    real(wp) :: ax, ay, w2, px, py
    jl(1:2, :) = zero
    if (gi) then
      ax = ci * p(1) - si * p(2); ay = si * p(1) + ci * p(2)     ! A_i s'_i
      w2 = wi**2
      phi(1) = ri(1) + ax; phi(2) = ri(2) + ay
      gam(1) = ax * w2; gam(2) = ay * w2
      jl(1, 1) = one; jl(2, 2) = one; jl(1, 3) = -ay; jl(2, 3) = ax        ! [I, B_i s'_i]
    else
      phi(1) = p(1); phi(2) = p(2); gam(1) = zero; gam(2) = zero
    end if
    if (gj) then
      ax = cj * p(3) - sj * p(4); ay = sj * p(3) + cj * p(4)     ! A_j s'_j
      w2 = wj**2
      px = rj(1) + ax; py = rj(2) + ay
      phi(1) = phi(1) - px; phi(2) = phi(2) - py
      gam(1) = gam(1) - ax * w2; gam(2) = gam(2) - ay * w2
      jl(1, 4) = -one; jl(2, 5) = -one; jl(1, 6) = ay; jl(2, 6) = -ax      ! [-I, -B_j s'_j]
    else
      phi(1) = phi(1) - p(3); phi(2) = phi(2) - p(4)
    end if
  end subroutine revolute_kernel

  !> Second derivatives for the sensitivity equations, in closed form (the rows of
  !! revolute_eval_d along d theta_i and d theta_j): for side 1 (body i, theta slot 3) and
  !! side 2 (body j, slot 6), with u_i = A_i s'_i, u_j = A_j s'_j,
  !!   dJ(:, 3)/dtheta_i = -u_i,           dgamma/dtheta_i = B_i s'_i thd_i**2 = perp(u_i) thd_i**2
  !!   dJ(:, 6)/dtheta_j = +u_j,           dgamma/dtheta_j = -perp(u_j) thd_j**2
  !! and hv = (dJ/dtheta) q_dot, ha = (dJ/dtheta) q_ddot - dgamma/dtheta (mbd_sensitivity):
  !! with sg = -1 on side 1 and +1 on side 2, u = A s' of the side's body,
  !!   hcol = sg u,  hv = sg u thd,  ha = sg (u thdd - perp(u) thd**2).
  !! For n moving sides at once (the sensitivities' per-output loop; a ground side has no
  !! theta column): side e is body b(e) with its point s' at p(o(e)), p(o(e) + 1), sign
  !! sg(e), and the body's [cos, sin, theta_dot, theta_ddot] in bst(:, b(e)).
  pure subroutine revolute_second_sides(n, nb, o, b, sg, p, bst, hcol, hv, ha)
    integer, intent(in) :: n, nb                !! sides, bodies
    integer, intent(in) :: o(n), b(n)           !! point offsets and bodies
    real(wp), intent(in) :: sg(n)               !! signs
    real(wp), intent(in) :: p(*)                !! prepared parameter pool
    real(wp), intent(in) :: bst(4, 0:nb)        !! body states
    real(wp), intent(out) :: hcol(2, n)         !! d(theta column of J)/dtheta
    real(wp), intent(out) :: hv(2, n), ha(2, n)
    integer :: e, i, k
    !GCC$ novector
    do e = 1, n                                  ! (a few sides: no vector set-up)
      i = b(e); k = o(e)
      call revolute_second_side(bst(:, i), p(k), p(k + 1), sg(e), hcol(:, e), hv(:, e), ha(:, e))
    end do
  end subroutine revolute_second_sides

  !> revolute_second_sides for one side: body state st = [cos, sin, theta_dot, theta_ddot],
  !! point s' = (px, py), sign g.
  pure subroutine revolute_second_side(st, px, py, g, hcol, hv, ha)
    real(wp), intent(in) :: st(4), px, py, g
    real(wp), intent(out) :: hcol(2), hv(2), ha(2)
    real(wp) :: ux, uy, w, a, w2
    ux = st(1) * px - st(2) * py; uy = st(2) * px + st(1) * py
    w = st(3); a = st(4); w2 = w**2
    hcol(1) = g * ux; hcol(2) = g * uy
    hv(1) = g * (ux * w); hv(2) = g * (uy * w)
    ha(1) = g * (ux * a - uy * w2); ha(2) = g * (uy * a + ux * w2)
  end subroutine revolute_second_side

  !> revolute_second_sides' values applied to the dopri5 sensitivities' right-hand sides as
  !! rows (mbd_sensitivity sens_revolute_rows), side e with angle coordinate cq(e) and rows
  !! r0(e), r0(e) + 1: rt(:, c) -= (lambda_r0 h_1 + lambda_r0+1 h_2) S(c, :) (K_lambda S),
  !! wk(:, r0 + i) -= ha_i S(c, :) + 2 hv_i S_dot(c, :) (Ha S + 2 Hv S_dot); S, S_dot as rows
  !! st, sdt (npd, nq), npd a multiple of 4.
  pure subroutine revolute_second_rows(n, nb, npd, o, b, sg, cq, r0, p, bst, lam, st, sdt, &
                                       rt, wk)
    integer, intent(in) :: n, nb, npd           !! sides, bodies, rows
    integer, intent(in) :: o(n), b(n), cq(n), r0(n)  !! offsets, bodies, coordinates, rows
    real(wp), intent(in) :: sg(n), p(*), bst(4, 0:nb)  !! signs, pool, body states
    real(wp), intent(in) :: lam(*), st(npd, *), sdt(npd, *)  !! multipliers, S, S_dot
    real(wp), intent(inout) :: rt(npd, *), wk(npd, *)        !! the rows
    integer :: e, c, r, j
    real(wp) :: h(2), hv(2), ha(2), kl
    do e = 1, n
      c = cq(e); r = r0(e)
      call revolute_second_side(bst(:, b(e)), p(o(e)), p(o(e) + 1), sg(e), h, hv, ha)
      kl = lam(r) * h(1) + lam(r + 1) * h(2)
      do j = 0, npd - 4, 4                       ! (four rows at a time, written out)
        call row4(kl, zero, st(j + 1, c), sdt(j + 1, c), rt(j + 1, c))
        call row4(ha(1), 2 * hv(1), st(j + 1, c), sdt(j + 1, c), wk(j + 1, r))
        call row4(ha(2), 2 * hv(2), st(j + 1, c), sdt(j + 1, c), wk(j + 1, r + 1))
      end do
    end do
  contains
    !> y(1:4) -= a x(1:4) + bb z(1:4).
    pure subroutine row4(a, bb, x, z, y)
      real(wp), intent(in) :: a, bb, x(4), z(4)
      real(wp), intent(inout) :: y(4)
      y(1) = y(1) - a * x(1) - bb * z(1); y(2) = y(2) - a * x(2) - bb * z(2)
      y(3) = y(3) - a * x(3) - bb * z(3); y(4) = y(4) - a * x(4) - bb * z(4)
    end subroutine row4
  end subroutine revolute_second_rows

  !> The parameter parts for a change t of [s'_i, s'_j] in closed form (revolute_eval_d
  !! with dq = 0; the rows are linear in s', so p itself does not enter): with u = A t s'
  !! and v = B t s' = perp(u) of each body,
  !!   Phi_p = u_i - u_j  (a ground point: its change itself),
  !!   nu_p - J_p q_dot = -v_i thd_i + v_j thd_j,
  !!   gamma_p - J_p q_ddot = u_i thd_i**2 - v_i thdd_i - u_j thd_j**2 + v_j thdd_j,
  !! each a sum over the two sides of sg (u, -perp(u) thd, u thd**2 - perp(u) thdd) with
  !! sg = +1 on side i and -1 on side j. For n (side, parameter) entries at once, each a
  !! side whose point the parameter moves: entry e is body b(e) (0: ground, whose state
  !! 1, 0, 0, 0 gives the point's change itself and nothing else), the change
  !! t(o(e)), t(o(e) + 1) of column k(e) of tp, sign sg(e).
  pure subroutine revolute_param_sides(n, nb, ldt, ntp, o, k, b, sg, tp, bst, tphi, vp, ap)
    integer, intent(in) :: n, nb, ldt, ntp      !! entries, bodies, shape of tp
    integer, intent(in) :: o(n), k(n), b(n)     !! offsets, parameters, bodies
    real(wp), intent(in) :: sg(n)               !! signs
    real(wp), intent(in) :: tp(ldt, ntp)        !! changes of the prepared pool
    real(wp), intent(in) :: bst(4, 0:nb)        !! body states
    real(wp), intent(out) :: tphi(2, n), vp(2, n), ap(2, n)
    integer :: e, i, j, c
    real(wp) :: ux, uy, w, a, w2, g
    !GCC$ novector
    do e = 1, n                                  ! (a few entries: no vector set-up)
      i = b(e); j = o(e); c = k(e); g = sg(e)
      ux = g * (bst(1, i) * tp(j, c) - bst(2, i) * tp(j + 1, c))
      uy = g * (bst(2, i) * tp(j, c) + bst(1, i) * tp(j + 1, c))
      w = bst(3, i); a = bst(4, i); w2 = w**2
      tphi(1, e) = ux; tphi(2, e) = uy
      vp(1, e) = uy * w; vp(2, e) = -ux * w                        ! -perp(u) thd
      ap(1, e) = ux * w2 + uy * a; ap(2, e) = uy * w2 - ux * a     ! u thd**2 - perp(u) thdd
    end do
  end subroutine revolute_param_sides

end module mbd_joint_revolute
