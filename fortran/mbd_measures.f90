!> mbd_measures: quantities a linkage is judged by, evaluated at the states of a finished run
!! (one call for all of them).
!!
!!   conditioning  c = sigma_min(J D) / sigma_max(J D), J = Phi_q with lengths in units of the
!!                 model's length scale L (the core's units), D = diag(1/|J_k|) (columns to unit
!!                 length, so lengths and angles weigh alike): the measure the kinematics uses
!!                 to call a configuration singular (SING_RATIO). c = 0 at a dead centre and
!!                 near a fold (toggle) falls like sqrt(t* - t).
!!   influence     u = dq/ds_r from J u = e_r: the change of every coordinate per unit change
!!                 of the quantity driven by row r of Phi (a driver's row), the other rows held
!!                 (Haug, ch. 3: kinematic influence coefficients). By virtual work the
!!                 mechanical advantage between two quantities X and Y moved by that driver is
!!                 u_X / u_Y. Square J: LU; more rows than coordinates (redundant, consistent
!!                 constraints): least squares by pivoted QR, exact while they agree.
!!   fun_values    f(t), f'(t), f''(t) of an encoded function of time at many times (the
!!                 applied loads drawn as arrows).
!!   ratio         the velocity ratio dY/dX or the mechanical advantage dX/dY of two
!!                 quantities (coordinates, or the quantity a driver prescribes) from the
!!                 influence coefficients of one driver's row: dX/ds = u_X for a coordinate,
!!                 1 for that driver, 0 for another (held) one.
!!   link_angle    the transmission angle (Norton, Design of Machinery, ch. 4) from points and
!!                 an axis fixed in bodies: e = (A - B)/|A - B| along the coupler from the
!!                 joint B to its other joint A; an output turning about P: p = (P - B)/|P - B|,
!!                 mu = acos(e . p); an output sliding along the axis u: mu = asin(|e . u|).
!!                 The front end finds the joints; mbd2d-solve reads the same recipe.
!!   link_angle_dp its design derivative along the motion's sensitivities s = dq/dp and the
!!                 recipe's own points where a parameter is one: with a = A - B, w = P - B
!!                 (or the axis u), e = a/|a|, v = w/|w|, c = e . v:
!!                 de = (da - e (e . da))/|a|, dv likewise, dmu = -(de . v + e . dv)/sin(mu)
!!                 turning; dmu = sign(c) (de . v + e . dv)/cos(mu) sliding; a point's
!!                 change d(r + A s') = dr + B s' dtheta + A ds'.
!!   measures      a list of the three above (kind, integers, points) at every state in one
!!                 call: a table's columns and a sweep case's (mbd_batch), where the points
!!                 of an angle may come from the raw parameters a case sets; with the
!!                 states' sensitivities s = dq/dp, each measure's design derivatives too:
!!   influence_dp  J du = -(dJ) u, dJ = J_q s + J_p (every constraint on dual numbers along
!!                 (s, p): sens_eval_d), with J's factors reused; a ratio n/d by the
!!                 quotient rule (dn d - n dd)/d**2;
!!   conditioning_dp with J D = U S V^T (core units: s' = s / (cunit dp'/dp)): a simple
!!                 singular value changes by dsigma_i = u_i^T d(J D) v_i, d(J D)_k =
!!                 (dJ_k - (J D)_k ((J D)_k . dJ_k)) / |J_k|; dc = (dsigma_n sigma_1 - sigma_n
!!                 dsigma_1) / sigma_1**2. The values keep their own SVD without vectors.
!!
!! Work arrays are allocated once per call (with stat=), none in the loop over states.
module mbd_measures
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_BAD_COUNT, MBD_BAD_PARAM, MSG_LEN
  use mbd_model, only: model_t, model_build
  use mbd_assemble, only: asm_work_t, asm_init, assemble_dense, scatter_dense
  use mbd_sensitivity, only: sens_t, sens_setup, sens_trig, sens_eval_d, block_apply
  use mbd_memory, only: mem_fail, REAL_BYTES
  use mbd_linsolve, only: lapack_status, lu_factor, lu_solve, qr_factor, qr_solve, qr_lwork
  use mbd_lapack, only: dgesvd
  use mbd_functions, only: fun_check, fun_eval, fun_length
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_value, ieee_positive_inf, &
                                          ieee_copy_sign
  implicit none
  private
  public :: api_conditioning, api_influence, api_fun_values, api_link_angle, api_ratio, &
            api_measures
  !> ratio kinds: the velocity ratio dY/dX, the mechanical advantage dX/dY
  integer, parameter, public :: RATIO_VELOCITY = 1, RATIO_ADVANTAGE = 2
  !> quantity kinds: a coordinate (its column), a driver (its row of Phi)
  integer, parameter, public :: QTY_COORDINATE = 1, QTY_DRIVER = 2
  !> link_angle recipes: an output link turning about a second pivot, or sliding
  integer, parameter, public :: ANGLE_TURN = 1, ANGLE_SLIDE = 2
  !> measure kinds of a list (api_measures; the .mbd file's "measures" block)
  integer, parameter, public :: MEAS_ANGLE = 1, MEAS_RATIO = 2, MEAS_ADVANTAGE = 3, &
                                MEAS_CONDITIONING = 4

contains

  !> sigma_min / sigma_max of the column-scaled J (core units) at each state; with the
  !! parameter table ptab (2, np) and the states' sensitivities sq (nq, np, nt; model units),
  !! also its design derivatives dcond (np, nt) (the banner's conditioning_dp).
  subroutine api_conditioning(nb, ctab, rpar, q, t, cond, status, msg, ptab, sq, dcond)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q(:, :)             !! states (nq, nt), model units
    real(wp), intent(in) :: t(:)                !! times (nt)
    real(wp), intent(out) :: cond(:)            !! sigma_min / sigma_max (nt)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(in), optional :: ptab(:, :)       !! (2, np) design parameters
    real(wp), intent(in), optional :: sq(:, :, :)     !! dq/dp (nq, np, nt)
    real(wp), intent(out), optional :: dcond(:, :)    !! dc/dp (np, nt)
    type(model_t) :: m
    type(asm_work_t) :: aw
    type(sens_t) :: sens
    real(wp), allocatable :: phi(:), nu(:), gam(:), jac(:, :), qz(:), qc(:), sv(:), work(:)
    real(wp), allocatable :: jt(:, :), us(:, :), vt(:, :), cns(:), dj(:, :), dq(:), ev(:, :)
    real(wp) :: wq(1), cn, ds1, dsn
    integer :: bad, k, c, info, lwork, ist, ns, kp, ldu, ldv
    logical :: deriv
    cond = zero
    deriv = present(ptab) .and. present(sq) .and. present(dcond)
    if (deriv) dcond = zero
    call model_build(nb, ctab, rpar, m, status, msg, bad, nondim=.true.)
    if (status /= MBD_OK) return
    if (.not. check_states(m, q, t, size(cond), status, msg)) return
    if (deriv) then
      if (.not. check_sens(m, ctab, rpar, ptab, sq, size(t), size(dcond, 1) == size(ptab, 2) &
                           .and. size(dcond, 2) == size(t), sens, status, msg)) return
    end if
    ns = min(m%neq, m%nq)
    if (ns == 0) return                         ! no constraint: nothing to be singular
    ldu = 1; ldv = 1
    if (deriv) then
      ldu = m%neq; ldv = max(ns, 1)
    end if
    allocate (phi(m%neq), nu(m%neq), gam(m%neq), jac(m%neq, m%nq), qz(m%nq), qc(m%nq), &
              sv(max(ns, 1)), cns(m%nq), us(ldu, max(ns, 1)), vt(ldv, m%nq), stat=ist)
    if (ist == 0 .and. deriv) &
      allocate (jt(m%neq, m%nq), dj(m%neq, m%nq), dq(m%nq), ev(m%neq, 3), stat=ist)
    if (ist /= 0) then
      call no_memory(m, status, msg); return
    end if
    call asm_init(m, aw, status, msg)
    if (status /= MBD_OK) return
    qz = zero
    ! the values by singular values alone, with or without derivatives (the same numbers);
    ! the derivatives with the vectors, from a copy
    call dgesvd('N', 'N', m%neq, m%nq, jac, m%neq, sv, us, 1, vt, 1, wq, -1, info)
    lwork = max(1, int(wq(1)))
    if (deriv) then
      call dgesvd('S', 'S', m%neq, m%nq, jac, m%neq, sv, us, ldu, vt, ldv, wq, -1, info)
      lwork = max(lwork, int(wq(1)))
    end if
    allocate (work(lwork), stat=ist)
    if (ist /= 0) then
      call no_memory(m, status, msg); return
    end if
    do k = 1, size(t)
      qc = q(:, k) / m%cunit
      call assemble_dense(m, qc, qz, t(k), phi, nu, gam, aw, jac)
      ! columns to unit length: J D, D = diag(1/|J_k|)
      do c = 1, m%nq
        cn = norm2(jac(:, c))
        cns(c) = zero
        if (cn > zero) then
          jac(:, c) = jac(:, c) / cn; cns(c) = cn
        end if
      end do
      if (deriv) jt = jac
      call dgesvd('N', 'N', m%neq, m%nq, jac, m%neq, sv, us, 1, vt, 1, work, lwork, info)
      call lapack_status('dgesvd', info, status, msg)
      if (status /= MBD_OK) return
      if (.not. sv(1) > zero) cycle
      cond(k) = sv(ns) / sv(1)
      if (.not. deriv) cycle
      jac = jt
      call dgesvd('S', 'S', m%neq, m%nq, jac, m%neq, sv, us, ldu, vt, ldv, work, lwork, info)
      call lapack_status('dgesvd', info, status, msg)
      if (status /= MBD_OK) return
      call sens_trig(m, sens, qc)
      do kp = 1, size(ptab, 2)
        call jac_change(m, sens, kp, qc, sq(:, kp, k), t(k), qz, dq, ev, aw%jb)
        call scatter_dense(aw, dj)                    ! then d(J D) column by column
        do c = 1, m%nq
          if (cns(c) > zero) dj(:, c) = (dj(:, c) - jt(:, c) * dot_product(jt(:, c), &
                                         dj(:, c))) / cns(c)
        end do
        ds1 = bilinear(us(:, 1), dj, vt(1, :))          ! dsigma_i = u_i^T d(J D) v_i
        dsn = bilinear(us(:, ns), dj, vt(ns, :))
        dcond(kp, k) = (dsn * sv(1) - sv(ns) * ds1) / sv(1)**2 * sens%pscale(kp)
      end do
    end do
  end subroutine api_conditioning

  !> Influence coefficients u = dq/ds of the quantity driven by row r at each state:
  !! J u = e_r (model units: u(i) per unit of row r's quantity). ok(k) = 0 where J is
  !! singular (the quantity cannot be changed there: a dead centre of that driver). With the
  !! parameter table ptab (2, np) and the states' sensitivities sq (nq, np, nt), also their
  !! design derivatives du (nq, np, nt): J du = -(dJ) u, dJ = J_q dq/dp + J_p on dual
  !! numbers (sens_eval_d), J's factors reused.
  subroutine api_influence(nb, ctab, rpar, q, t, r, u, ok, status, msg, ptab, sq, du)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q(:, :)             !! states (nq, nt), model units
    real(wp), intent(in) :: t(:)                !! times (nt)
    integer, intent(in) :: r                    !! row of Phi (1-based) whose quantity moves
    real(wp), intent(out) :: u(:, :)            !! dq/ds (nq, nt)
    integer, intent(out) :: ok(:)               !! 1 solved, 0 singular J (nt)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(in), optional :: ptab(:, :)       !! (2, np) design parameters
    real(wp), intent(in), optional :: sq(:, :, :)     !! dq/dp (nq, np, nt)
    real(wp), intent(out), optional :: du(:, :, :)    !! du/dp (nq, np, nt)
    type(model_t) :: m
    type(asm_work_t) :: aw
    type(sens_t) :: sens
    real(wp), allocatable :: phi(:), nu(:), gam(:), jac(:, :), qz(:), b(:), tau(:), work(:), &
                             dq(:), w(:), ev(:, :)
    integer, allocatable :: ipiv(:), jpvt(:)
    real(wp) :: resid
    integer :: bad, k, ist, st, kp
    logical :: deriv
    character(len=MSG_LEN) :: lmsg
    u = zero; ok = 0
    deriv = present(ptab) .and. present(sq) .and. present(du)
    if (deriv) du = zero
    call model_build(nb, ctab, rpar, m, status, msg, bad)
    if (status /= MBD_OK) return
    if (.not. check_states(m, q, t, size(ok), status, msg)) return
    if (size(u, 1) /= m%nq .or. size(u, 2) /= size(t)) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    if (r < 1 .or. r > m%neq) then
      status = MBD_BAD_COUNT; msg = 'the row is not a row of Phi'; return
    end if
    if (m%neq < m%nq) then
      status = MBD_BAD_COUNT
      msg = 'fewer equations than coordinates: the motion is not determined by the drivers'
      return
    end if
    if (deriv) then
      if (.not. check_sens(m, ctab, rpar, ptab, sq, size(t), size(du, 1) == m%nq .and. &
                           size(du, 2) == size(ptab, 2) .and. size(du, 3) == size(t), &
                           sens, status, msg)) return
    end if
    allocate (phi(m%neq), nu(m%neq), gam(m%neq), jac(m%neq, m%nq), qz(m%nq), b(m%neq), &
              ipiv(m%nq), jpvt(m%nq), tau(m%nq), work(qr_lwork(m%neq, m%nq)), dq(m%nq), &
              w(m%neq), ev(m%neq, 3), stat=ist)
    if (ist /= 0) then
      call no_memory(m, status, msg); return
    end if
    call asm_init(m, aw, status, msg)
    if (status /= MBD_OK) return
    qz = zero
    do k = 1, size(t)
      call assemble_dense(m, q(:, k), qz, t(k), phi, nu, gam, aw, jac)
      b = zero; b(r) = one                      ! J u = e_r
      call solve(u(:, k), .true.)
      if (st == MBD_OK .and. all(ieee_is_finite(u(:, k)))) then
        ok(k) = 1
      else
        u(:, k) = zero; cycle
      end if
      if (.not. deriv) cycle
      call sens_trig(m, sens, q(:, k))
      do kp = 1, size(ptab, 2)                  ! J du = -(J_q dq + J_p) u
        call jac_change(m, sens, kp, q(:, k), sq(:, kp, k), t(k), qz, dq, ev, aw%jb)
        call block_apply(m, aw%jb, u(:, k), w)
        b = -w
        call solve(du(:, kp, k), .false.)
        du(:, kp, k) = du(:, kp, k) * sens%pscale(kp)
        if (st /= MBD_OK) du(:, kp, k) = zero
      end do
    end do
  contains
    !> x from J x = b: factor J first (first) or reuse its factors.
    subroutine solve(x, first)
      real(wp), intent(out) :: x(:)
      logical, intent(in) :: first
      if (m%neq == m%nq) then
        st = MBD_OK
        if (first) call lu_factor(jac, ipiv, st, lmsg)
        if (st == MBD_OK) call lu_solve(jac, ipiv, b, st, lmsg)
        x = b(1:m%nq)
      else
        st = MBD_OK; x = zero
        if (first) call qr_factor(jac, jpvt, tau, work, st, lmsg)
        if (st == MBD_OK) call qr_solve(jac, jpvt, tau, b, x, resid, work)
      end if
    end subroutine solve
  end subroutine api_influence

  !> The velocity ratio dY/dX (RATIO_VELOCITY; inf where J is singular for the driver) or
  !! the mechanical advantage dX/dY (RATIO_ADVANTAGE; 0 there) at each state, by the
  !! influence coefficients u of row ref (api_influence): dX/ds = u(X's column) for a
  !! coordinate, 1 for the driver of row ref itself, 0 for another driver (held); where only
  !! the denominator vanishes, +-inf with the numerator's sign; where both do, the singular
  !! value. A coordinate that does not move with the driver (|u_X| <= 1e-12 max |u|
  !! throughout) has no ratio: MBD_BAD_PARAM with bad = 1 (X) or 2 (Y). With the parameter
  !! table ptab (2, np) and the states' sensitivities sq (nq, np, nt), also the design
  !! derivatives dratio (np, nt) by the quotient rule on du/dp (api_influence): where the
  !! denominator vanishes, +-inf with the sign of the numerator's (0 where that is zero too);
  !! where J is singular, +inf (no derivative).
  subroutine api_ratio(nb, ctab, rpar, q, t, kind, ref, x, y, ratio, bad, status, msg, ptab, &
                       sq, dratio)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q(:, :)             !! states (nq, nt), model units
    real(wp), intent(in) :: t(:)                !! times (nt)
    integer, intent(in) :: kind                 !! RATIO_VELOCITY or RATIO_ADVANTAGE
    integer, intent(in) :: ref                  !! the driver's row of Phi (1-based)
    integer, intent(in) :: x(2), y(2)           !! QTY_COORDINATE or QTY_DRIVER, 1-based index
    real(wp), intent(out) :: ratio(:)           !! at each state (nt)
    integer, intent(out) :: bad                 !! 1 or 2: the quantity that does not move
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(in), optional :: ptab(:, :)       !! (2, np) design parameters
    real(wp), intent(in), optional :: sq(:, :, :)     !! dq/dp (nq, np, nt)
    real(wp), intent(out), optional :: dratio(:, :)   !! (np, nt)
    real(wp), allocatable :: u(:, :), dx(:), dy(:), du(:, :, :), ddx(:, :), ddy(:, :)
    integer, allocatable :: ok(:)
    real(wp) :: scale, num, den, sing, dnum, dden, top
    integer :: k, ist, np, kp
    logical :: deriv
    ratio = zero; bad = 0
    deriv = present(ptab) .and. present(sq) .and. present(dratio)
    np = 0
    if (deriv) then
      dratio = zero; np = size(ptab, 2)
    end if
    if ((kind /= RATIO_VELOCITY .and. kind /= RATIO_ADVANTAGE) .or. &
        any([x(1), y(1)] < QTY_COORDINATE) .or. any([x(1), y(1)] > QTY_DRIVER) .or. &
        size(ratio) /= size(t) .or. any([x(2), y(2)] < 1)) then
      status = MBD_BAD_PARAM; msg = 'ratio: unknown kind or quantity'; return
    end if
    if ((x(1) == QTY_COORDINATE .and. x(2) > size(q, 1)) .or. &
        (y(1) == QTY_COORDINATE .and. y(2) > size(q, 1))) then
      status = MBD_BAD_COUNT; msg = 'ratio: a coordinate beyond the model'; return
    end if
    if (deriv) then
      if (size(dratio, 1) /= np .or. size(dratio, 2) /= size(t)) then
        status = MBD_BAD_COUNT; msg = 'ratio: array sizes do not match'; return
      end if
    end if
    allocate (u(size(q, 1), size(t)), ok(size(t)), dx(size(t)), dy(size(t)), &
              du(size(q, 1), np, size(t)), ddx(np, size(t)), ddy(np, size(t)), stat=ist)
    if (ist /= 0) then
      call mem_fail(REAL_BYTES * (real(size(q, 1), wp) + 3) * (np + 1) * size(t), &
                    'the influence coefficients', 'keep fewer rows', status, msg)
      return
    end if
    if (deriv) then
      call api_influence(nb, ctab, rpar, q, t, ref, u, ok, status, msg, ptab, sq, du)
    else
      call api_influence(nb, ctab, rpar, q, t, ref, u, ok, status, msg)
    end if
    if (status /= MBD_OK) return
    scale = zero
    if (size(u) > 0) scale = maxval(abs(u))
    call rate(x, dx, ddx, 1)
    if (bad == 0) call rate(y, dy, ddy, 2)
    if (bad /= 0) then
      status = MBD_BAD_PARAM
      msg = 'the quantity does not move with the driver (its influence coefficient is zero '// &
            'throughout): no ratio to it'
      return
    end if
    sing = merge(ieee_value(zero, ieee_positive_inf), zero, kind == RATIO_VELOCITY)
    do k = 1, size(t)
      num = merge(dy(k), dx(k), kind == RATIO_VELOCITY)
      den = merge(dx(k), dy(k), kind == RATIO_VELOCITY)
      if (ok(k) /= 1 .or. (den == zero .and. num == zero)) then
        ratio(k) = sing
        if (deriv) dratio(:, k) = ieee_value(zero, ieee_positive_inf)
        cycle
      else if (den == zero) then
        ratio(k) = ieee_copy_sign(ieee_value(zero, ieee_positive_inf), num)
      else
        ratio(k) = num / den
      end if
      do kp = 1, np                             ! d(n/d) = (dn d - n dd) / d**2
        dnum = merge(ddy(kp, k), ddx(kp, k), kind == RATIO_VELOCITY)
        dden = merge(ddx(kp, k), ddy(kp, k), kind == RATIO_VELOCITY)
        top = dnum * den - num * dden
        if (den /= zero) then
          dratio(kp, k) = top / den**2
        else if (top /= zero) then
          dratio(kp, k) = ieee_copy_sign(ieee_value(zero, ieee_positive_inf), top)
        end if
      end do
    end do
  contains
    !> dQ/ds of quantity qq and its design derivatives; bad = which when a coordinate does
    !! not move at all.
    subroutine rate(qq, d, dd, which)
      integer, intent(in) :: qq(2), which
      real(wp), intent(out) :: d(:), dd(:, :)
      dd = zero
      if (qq(1) == QTY_COORDINATE) then
        d = u(qq(2), :)
        if (deriv) dd = du(qq(2), :, :)
        if (.not. (size(d) > 0 .and. maxval(abs(d)) > 1.0e-12_wp * scale)) bad = which
      else
        d = merge(one, zero, qq(2) == ref)
      end if
    end subroutine rate
  end subroutine api_ratio

  !> f(t), f'(t), f''(t) of the encoded function p at the times t.
  subroutine api_fun_values(p, t, f, f1, f2, status, msg)
    real(wp), intent(in) :: p(:)                !! encoded function (mbd_functions)
    real(wp), intent(in) :: t(:)                !! times
    real(wp), intent(out) :: f(:), f1(:), f2(:) !! values and two derivatives (size(t))
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer :: k
    f = zero; f1 = zero; f2 = zero
    status = MBD_OK; msg = ''
    if (size(f) /= size(t) .or. size(f1) /= size(t) .or. size(f2) /= size(t) .or. &
        fun_length(p) /= size(p)) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the function'; return
    end if
    call fun_check(p, status, msg)
    if (status /= MBD_OK) return
    if (.not. all(ieee_is_finite(t))) then
      status = MBD_BAD_PARAM; msg = 'the times must be finite'; return
    end if
    do k = 1, size(t)
      call fun_eval(p, t(k), f(k), f1(k), f2(k))
    end do
  end subroutine api_fun_values

  !> The transmission angle at every state q(:, k) (nq, nt): points s(:, 1) of body b(1) (B,
  !! the joint), s(:, 2) of body b(2) (A, the coupler's other joint) and, for ANGLE_TURN,
  !! s(:, 3) of body b(3) (P, the output's other pivot); for ANGLE_SLIDE, s(:, 3) the slide's
  !! axis in body b(3). Body 0 is ground (s global). Radians: [0, pi] turning, [0, pi/2]
  !! sliding (pi/2 - the acute angle between the coupler and the slide).
  subroutine api_link_angle(q, kind, b, s, mu, status, msg)
    real(wp), intent(in) :: q(:, :)             !! states (nq, nt)
    integer, intent(in) :: kind                 !! ANGLE_TURN or ANGLE_SLIDE
    integer, intent(in) :: b(3)                 !! bodies (0 ground)
    real(wp), intent(in) :: s(2, 3)             !! points (and the axis) in their bodies
    real(wp), intent(out) :: mu(:)              !! the angle at each state (nt)
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    real(wp) :: pb(2), pa(2), e(2), v(2), d
    integer :: k
    mu = zero; status = MBD_OK; msg = ''
    if (size(mu) /= size(q, 2)) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the states'; return
    end if
    if ((kind /= ANGLE_TURN .and. kind /= ANGLE_SLIDE) .or. any(b < 0) .or. &
        any(3 * b > size(q, 1))) then
      status = MBD_BAD_PARAM; msg = 'link angle: unknown kind or body out of range'; return
    end if
    if (.not. (all(ieee_is_finite(q)) .and. all(ieee_is_finite(s)))) then
      status = MBD_BAD_PARAM; msg = 'the states and points must be finite'; return
    end if
    do k = 1, size(q, 2)
      pb = point(b(1), s(:, 1), q(:, k))
      pa = point(b(2), s(:, 2), q(:, k))
      e = (pa - pb) / hypot(pa(1) - pb(1), pa(2) - pb(2))
      if (kind == ANGLE_TURN) then
        v = point(b(3), s(:, 3), q(:, k)) - pb
      else
        v = turned(b(3), s(:, 3), q(:, k))
      end if
      v = v / hypot(v(1), v(2))
      d = e(1) * v(1) + e(2) * v(2)
      if (kind == ANGLE_TURN) then
        mu(k) = acos(max(-one, min(one, d)))
      else
        mu(k) = asin(max(zero, min(one, abs(d))))
      end if
    end do
  end subroutine api_link_angle

  !> Every measure of a list at each state: vals(j, k) is measure j at state k. Measure j
  !! is kind(j) with the integers mint(:, j): MEAS_ANGLE its angle kind and three bodies
  !! (api_link_angle) with the points spts(:, :, j), an entry of which is rpar(pref(i, l, j))
  !! instead where pref(i, l, j) > 0 (a joint's point that a sweep case sets);
  !! MEAS_RATIO, MEAS_ADVANTAGE the driver's row, X's kind and index, Y's kind and index
  !! (api_ratio); MEAS_CONDITIONING none (api_conditioning). On a failure the rest of vals
  !! is zero, bad(1) names the measure and bad(2) a ratio's quantity that does not move
  !! (1 X, 2 Y; else 0). With the parameter table ptab (2, np) and the states'
  !! sensitivities sq (nq, np, nt; model units), also every measure's design derivatives
  !! dvals(j, :, k) (np) at state k (an angle's points move with the parameters that are
  !! their entries pref).
  subroutine api_measures(nb, ctab, rpar, q, t, kind, mint, spts, pref, vals, bad, status, &
                          msg, ptab, sq, dvals)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q(:, :)             !! states (nq, nt), model units
    real(wp), intent(in) :: t(:)                !! times (nt)
    integer, intent(in) :: kind(:)              !! (nm) MEAS_ANGLE ... MEAS_CONDITIONING
    integer, intent(in) :: mint(:, :)           !! (5, nm) each measure's integers
    real(wp), intent(in) :: spts(:, :, :)       !! (2, 3, nm) an angle's points
    integer, intent(in) :: pref(:, :, :)        !! (2, 3, nm) rpar entries of them, or 0
    real(wp), intent(out) :: vals(:, :)         !! (nm, nt)
    integer, intent(out) :: bad(2)              !! the failing measure, a ratio's quantity
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(in), optional :: ptab(:, :)       !! (2, np) design parameters
    real(wp), intent(in), optional :: sq(:, :, :)     !! dq/dp (nq, np, nt)
    real(wp), intent(out), optional :: dvals(:, :, :) !! (nm, np, nt)
    real(wp), allocatable :: col(:), dcol(:, :)
    real(wp) :: s(2, 3)
    integer :: j, ist, i, l, np
    logical :: deriv
    vals = zero; bad = 0; status = MBD_OK; msg = ''
    deriv = present(ptab) .and. present(sq) .and. present(dvals)
    np = 0
    if (deriv) then
      dvals = zero; np = size(ptab, 2)
    end if
    if (size(mint, 1) /= 5 .or. size(mint, 2) /= size(kind) .or. &
        any(shape(spts) /= [2, 3, size(kind)]) .or. any(shape(pref) /= shape(spts)) .or. &
        size(vals, 1) /= size(kind) .or. size(vals, 2) /= size(t)) then
      status = MBD_BAD_COUNT; msg = 'measures: array sizes do not match'; return
    end if
    if (deriv) then
      if (any(shape(dvals) /= [size(kind), np, size(t)])) then
        status = MBD_BAD_COUNT; msg = 'measures: array sizes do not match'; return
      end if
    end if
    if (any(pref < 0) .or. any(pref > size(rpar))) then
      status = MBD_BAD_PARAM; msg = 'measures: a point''s entry is beyond the parameters'
      return
    end if
    allocate (col(size(t)), dcol(np, size(t)), stat=ist)
    if (ist /= 0) then
      call mem_fail(REAL_BYTES * size(t) * (np + 1), 'a measure''s column', 'keep fewer rows', &
                    status, msg)
      return
    end if
    do j = 1, size(kind)
      bad(1) = j
      select case (kind(j))
      case (MEAS_CONDITIONING)
        if (deriv) then
          call api_conditioning(nb, ctab, rpar, q, t, col, status, msg, ptab, sq, dcol)
        else
          call api_conditioning(nb, ctab, rpar, q, t, col, status, msg)
        end if
      case (MEAS_ANGLE)
        s = spts(:, :, j)
        do l = 1, 3
          do i = 1, 2
            if (pref(i, l, j) > 0) s(i, l) = rpar(pref(i, l, j))
          end do
        end do
        call api_link_angle(q, mint(1, j), mint(2:4, j), s, col, status, msg)
        if (deriv .and. status == MBD_OK) &
          call api_link_angle_dp(q, sq, mint(1, j), mint(2:4, j), s, pref(:, :, j), ptab, &
                                 dcol, status, msg)
      case (MEAS_RATIO, MEAS_ADVANTAGE)
        if (deriv) then
          call api_ratio(nb, ctab, rpar, q, t, merge(RATIO_VELOCITY, RATIO_ADVANTAGE, &
                         kind(j) == MEAS_RATIO), mint(1, j), mint(2:3, j), mint(4:5, j), col, &
                         bad(2), status, msg, ptab, sq, dcol)
        else
          call api_ratio(nb, ctab, rpar, q, t, merge(RATIO_VELOCITY, RATIO_ADVANTAGE, &
                         kind(j) == MEAS_RATIO), mint(1, j), mint(2:3, j), mint(4:5, j), col, &
                         bad(2), status, msg)
        end if
      case default
        status = MBD_BAD_PARAM; msg = 'measures: unknown kind'
      end select
      if (status /= MBD_OK) then
        vals = zero
        if (deriv) dvals = zero
        return
      end if
      vals(j, :) = col
      if (deriv) dvals(j, :, :) = dcol
    end do
    bad = 0
  end subroutine api_measures

  !> The transmission angle's derivatives dmu(k, j) along design parameter k at state j:
  !! the recipe of api_link_angle, the sensitivities sq (nq, np, nt) of the states (model
  !! units), and the recipe's points' own entries: where pref(i, l) > 0 and parameter k is
  !! rpar entry pref(i, l) (ptab(:, k) = (1, pref(i, l))), entry i of point l moves with it.
  !! Where sin(mu) (turning) or cos(mu) (sliding) is zero the angle has no derivative:
  !! +-inf with the sign of the numerator (0 where that is zero too).
  subroutine api_link_angle_dp(q, sq, kind, b, s, pref, ptab, dmu, status, msg)
    real(wp), intent(in) :: q(:, :)             !! states (nq, nt)
    real(wp), intent(in) :: sq(:, :, :)         !! dq/dp (nq, np, nt)
    integer, intent(in) :: kind                 !! ANGLE_TURN or ANGLE_SLIDE
    integer, intent(in) :: b(3)                 !! bodies (0 ground)
    real(wp), intent(in) :: s(2, 3)             !! points (and the axis) in their bodies
    integer, intent(in) :: pref(2, 3)           !! rpar entries of the points (0: none)
    integer, intent(in) :: ptab(:, :)           !! (2, np) design parameters
    real(wp), intent(out) :: dmu(:, :)          !! (np, nt)
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    real(wp) :: mu(1), pb(2), a(2), w(2), e(2), v(2), da(2), dw(2), de(2), dv(2), c, den, num
    real(wp) :: ds(2, 3), na, nw
    integer :: j, k, i, l, np
    dmu = zero; np = size(ptab, 2)
    if (size(sq, 1) /= size(q, 1) .or. size(sq, 2) /= np .or. size(sq, 3) /= size(q, 2) .or. &
        size(ptab, 1) /= 2 .or. size(dmu, 1) /= np .or. size(dmu, 2) /= size(q, 2)) then
      status = MBD_BAD_COUNT; msg = 'link angle derivative: array sizes do not match'; return
    end if
    if (.not. all(ieee_is_finite(sq))) then
      status = MBD_BAD_PARAM; msg = 'the sensitivities must be finite'; return
    end if
    do j = 1, size(q, 2)
      call api_link_angle(q(:, j:j), kind, b, s, mu, status, msg)
      if (status /= MBD_OK) return
      pb = point(b(1), s(:, 1), q(:, j))
      a = point(b(2), s(:, 2), q(:, j)) - pb
      if (kind == ANGLE_TURN) then
        w = point(b(3), s(:, 3), q(:, j)) - pb
      else
        w = turned(b(3), s(:, 3), q(:, j))
      end if
      na = hypot(a(1), a(2)); nw = hypot(w(1), w(2))
      e = a / na; v = w / nw; c = e(1) * v(1) + e(2) * v(2)
      do k = 1, np
        ds = zero                       ! the recipe's own points that are parameter k
        do l = 1, 3
          do i = 1, 2
            if (pref(i, l) > 0 .and. ptab(1, k) == 1 .and. ptab(2, k) == pref(i, l)) &
              ds(i, l) = one
          end do
        end do
        da = dpoint(b(2), s(:, 2), ds(:, 2)) - dpoint(b(1), s(:, 1), ds(:, 1))
        if (kind == ANGLE_TURN) then
          dw = dpoint(b(3), s(:, 3), ds(:, 3)) - dpoint(b(1), s(:, 1), ds(:, 1))
        else
          dw = dturned(b(3), s(:, 3), ds(:, 3))
        end if
        de = (da - e * (e(1) * da(1) + e(2) * da(2))) / na     ! d(a/|a|)
        dv = (dw - v * (v(1) * dw(1) + v(2) * dw(2))) / nw
        num = de(1) * v(1) + de(2) * v(2) + e(1) * dv(1) + e(2) * dv(2)   ! dc
        if (kind == ANGLE_TURN) then
          num = -num; den = sin(mu(1))                          ! mu = acos(c)
        else
          num = sign(one, c) * num; den = cos(mu(1))            ! mu = asin(|c|)
        end if
        if (den /= zero) then
          dmu(k, j) = num / den
        else if (num /= zero) then
          dmu(k, j) = ieee_copy_sign(ieee_value(zero, ieee_positive_inf), num)
        end if
      end do
    end do
  contains
    !> d(r + A s') = dr + B s' dtheta + A ds' along parameter k at state j (ground: ds').
    function dpoint(bi, sl, dsl) result(r)
      integer, intent(in) :: bi
      real(wp), intent(in) :: sl(2), dsl(2)
      real(wp) :: r(2)
      r = dsl
      if (bi == 0) return
      r = sq(3 * bi - 2:3 * bi - 1, k, j) + dturned(bi, sl, dsl)
    end function dpoint
    !> d(A v') = B v' dtheta + A dv' (ground: dv').
    function dturned(bi, vl, dvl) result(r)
      integer, intent(in) :: bi
      real(wp), intent(in) :: vl(2), dvl(2)
      real(wp) :: r(2), cc, sn, dth
      r = dvl
      if (bi == 0) return
      cc = cos(q(3 * bi, j)); sn = sin(q(3 * bi, j)); dth = sq(3 * bi, k, j)
      r = [cc * dvl(1) - sn * dvl(2), sn * dvl(1) + cc * dvl(2)] + &
          dth * [-sn * vl(1) - cc * vl(2), cc * vl(1) - sn * vl(2)]
    end function dturned
  end subroutine api_link_angle_dp

  !> A point fixed in body bi at state qk: r_i + A(theta_i) s' (ground: s').
  pure function point(bi, sl, qk) result(r)
    integer, intent(in) :: bi
    real(wp), intent(in) :: sl(2), qk(:)
    real(wp) :: r(2)
    r = sl
    if (bi > 0) r = qk(3 * bi - 2:3 * bi - 1) + turned(bi, sl, qk)
  end function point

  !> A vector fixed in body bi at state qk: A(theta_i) v' (ground: v').
  pure function turned(bi, vl, qk) result(r)
    integer, intent(in) :: bi
    real(wp), intent(in) :: vl(2), qk(:)
    real(wp) :: r(2), c, sn
    r = vl
    if (bi == 0) return
    c = cos(qk(3 * bi)); sn = sin(qk(3 * bi))
    r = [c * vl(1) - sn * vl(2), sn * vl(1) + c * vl(2)]
  end function turned

  !> J's local blocks changed along design parameter kp at the state q (the model's units)
  !! with the state's sensitivity sqk (model units): every constraint on dual numbers along
  !! (dq', e_kp), dq' = sqk / (cunit dp'/dp), the change per unit p' = p dp'/dp (times
  !! sens%pscale(kp): per unit p). sens_trig first.
  subroutine jac_change(m, sens, kp, q, sqk, t, qz, dq, ev, jb)
    type(model_t), intent(in) :: m              !! model
    type(sens_t), intent(in) :: sens            !! the parameters' tables
    integer, intent(in) :: kp                   !! the parameter
    real(wp), intent(in) :: q(:), sqk(:), t     !! state, its sensitivity (nq), time
    real(wp), intent(in) :: qz(:)               !! zeros (nq)
    real(wp), intent(out) :: dq(:)              !! work (nq)
    real(wp), intent(out) :: ev(:, :)           !! work (neq, 3): Phi's, nu's, gamma's changes
    real(wp), intent(out) :: jb(:, :, :)        !! the blocks' changes (MAXROW, NLOC, nc)
    dq = sqk / (m%cunit * sens%pscale(kp))
    call sens_eval_d(m, sens, kp, q, qz, dq, qz, t, ev(:, 1), ev(:, 2), ev(:, 3), jb)
  end subroutine jac_change

  !> x^T A y.
  pure real(wp) function bilinear(x, a, y) result(r)
    real(wp), intent(in) :: x(:), a(:, :), y(:)   !! (m), (m, n), (n)
    integer :: i, j
    r = zero
    do j = 1, size(a, 2)
      do i = 1, size(a, 1)
        r = r + x(i) * a(i, j) * y(j)
      end do
    end do
  end function bilinear

  !> A measure's derivative inputs fit the model (ptab (2, np), sq (nq, np, nt) finite, and
  !! its output: fits) and the sensitivity tables are set up (sens_setup).
  logical function check_sens(m, ctab, rpar, ptab, sq, nt, fits, sens, status, msg) &
      result(good)
    type(model_t), intent(in) :: m              !! model
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    integer, intent(in) :: ptab(:, :)           !! (2, np) design parameters
    real(wp), intent(in) :: sq(:, :, :)         !! dq/dp (nq, np, nt)
    integer, intent(in) :: nt                   !! states
    logical, intent(in) :: fits                 !! the output's shape is right
    type(sens_t), intent(out) :: sens           !! the parameters' tables
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer :: bad
    good = .false.
    if (.not. fits .or. size(ptab, 1) /= 2 .or. size(sq, 1) /= m%nq .or. &
        size(sq, 2) /= size(ptab, 2) .or. size(sq, 3) /= nt) then
      status = MBD_BAD_COUNT; msg = 'measure derivatives: array sizes do not match'; return
    end if
    if (.not. all(ieee_is_finite(sq))) then
      status = MBD_BAD_PARAM; msg = 'the sensitivities must be finite'; return
    end if
    call sens_setup(m, ctab, rpar, ptab, sens, status, msg, bad)
    good = status == MBD_OK
  end function check_sens

  !> States and times finite and sized for the model.
  logical function check_states(m, q, t, nt, status, msg) result(good)
    type(model_t), intent(in) :: m              !! model
    real(wp), intent(in) :: q(:, :), t(:)       !! states (nq, nt) and times
    integer, intent(in) :: nt                   !! size of the caller's per-state output
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    good = .false.
    if (size(q, 1) /= m%nq .or. size(q, 2) /= size(t) .or. nt /= size(t)) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    if (.not. (all(ieee_is_finite(q)) .and. all(ieee_is_finite(t)))) then
      status = MBD_BAD_PARAM; msg = 'the states and times must be finite (no NaN or infinity)'
      return
    end if
    status = MBD_OK; msg = ''
    good = .true.
  end function check_states

  !> MBD_NO_MEMORY after a failed allocation of the work arrays (about a dense J and a few
  !! vectors).
  subroutine no_memory(m, status, msg)
    type(model_t), intent(in) :: m              !! model
    integer, intent(out) :: status              !! MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    msg = ''
    call mem_fail(REAL_BYTES * (real(m%neq, wp) * m%nq + 8.0_wp * (m%neq + m%nq)), &
                  'the work arrays of the mechanism measures (a dense J)', &
                  'the model is too large for a dense J', status, msg)
  end subroutine no_memory

end module mbd_measures
