!> mbd_forces: applied forces as generalized forces Q(q, q_dot, t), and their potential energy.
!!
!! Each force element writes Q over the local slots of its bodies (as joints do for J):
!!   spring     d = P_j - P_i, L = |d|, tension T = k (L - L0) + c L_dot - f(t)
!!              Q = -T dL/dq (pulls the points together when T > 0),  V = k (L - L0)**2 / 2
!!   torque     Q_theta_i = f(t)                       (reaction on ground)
!!   point      Q = J_P^T F, F = (fx(t), fy(t)) global, at body point s'
!!   rotational a = theta_j - theta_i, tau = -k (a - a0) - c a_dot + f(t) on body j,
!!              -tau on body i;  Q = tau da/dq,  V = k (a - a0)**2 / 2
!! Gravity adds m g to the x and y rows of every body, V = -m g . r.
!! vload is the potential of the loads held at their value at t (torque: -f theta_i,
!! point force: -F . P), for the equilibrium search in statics.
!! Raw parameters:
!!   spring     [s'_i(2), s'_j(2), k, c, L0, f...]      rotational [k, c, a0, f...]
!!   torque     [f...]                                  point      [s'(2), fx..., fy...]
!! (f: an encoded function of time, mbd_functions.)
!! Contacts (kinds 5-8: circle-line, circle-circle, circle-in-circle, follower-profile) and
!! joint friction (kind 9, the force table's row 6 names its joint) are force elements too;
!! their parameters, laws and geometry are in mbd_contact. A contact's force depends on its
!! state (open or closed, the impact speed), passed in st; joint friction needs the joint's
!! multipliers and is evaluated by mbd_dynamics (force_eval returns zero for it).
module mbd_forces
  use mbd_kinds, only: wp, zero, half, one
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MSG_LEN
  use mbd_points, only: NLOC, kloc, local_state, kvec, kscal, body_point, body_angle, vsub, &
                        vdot, ssqrt, ssub
  use mbd_functions, only: fun_eval, fun_length, fun_check, fun_exponents, fun_eval_d, &
                           fun_is_count, fun_next_break
  use mbd_dual, only: dloc, dvec, dscal, dual_state, point_values, point_changes, body_point, &
                      body_angle, ssub
  use mbd_contact, only: NCS, NEO, contact_raw_length, contact_prepare, contact_exponents, &
                         contact_eval, friction_raw_length, friction_exponents
  implicit none
  private
  public :: FRC_SPRING, FRC_TORQUE, FRC_POINT, FRC_ROTSPRING, FRC_CONTACT0, FRC_CONTACT1
  public :: FRC_FRICTION
  public :: force_known, force_raw_length, force_prepare, force_eval, force_exponents
  public :: force_next_break
  public :: force_is_contact, force_is_count, force_eval_d, force_eval_dm, force_rows_d
  public :: force_rate_d

  integer, parameter :: FRC_SPRING = 1, FRC_TORQUE = 2, FRC_POINT = 3, FRC_ROTSPRING = 4
  !> contacts: kind FRC_CONTACT0 + geometry - 1 (mbd_contact GEO_*), up to FRC_CONTACT1
  integer, parameter :: FRC_CONTACT0 = 5, FRC_CONTACT1 = 8
  integer, parameter :: FRC_FRICTION = 9   !! friction of a joint (force table row 6)


  !> The values of a spring-damper-actuator its changes are taken at (spring_values).
  type :: spring_v
    real(wp) :: aui(2) = zero, bi(2) = zero, auj(2) = zero, bj(2) = zero  !! A s', B s'
    real(wp) :: u(2) = zero, dd(2) = zero    !! direction j - i, relative velocity
    real(wp) :: l = zero, ldot = zero, tension = zero
  end type spring_v

contains

  !> The first breakpoint after t of a force's functions of time (fun_next_break: a motion
  !! law's t0 or t1, a table's ends; huge when none), where the force's second derivative in
  !! time may jump.
  pure real(wp) function force_next_break(kind, p, t) result(tb)
    integer, intent(in) :: kind        !! force kind
    real(wp), intent(in) :: p(:)       !! prepared parameters
    real(wp), intent(in) :: t          !! time
    integer :: nf
    select case (kind)
    case (FRC_SPRING); tb = fun_next_break(p(8:), t)
    case (FRC_TORQUE); tb = fun_next_break(p, t)
    case (FRC_POINT)
      nf = fun_length(p(3:))
      tb = min(fun_next_break(p(3:), t), fun_next_break(p(3 + nf:), t))
    case (FRC_ROTSPRING); tb = fun_next_break(p(4:), t)
    case default; tb = huge(t)
    end select
  end function force_next_break

  pure logical function force_known(kind)
    integer, intent(in) :: kind   !! force kind
    force_known = kind >= FRC_SPRING .and. kind <= FRC_FRICTION
  end function force_known

  pure logical function force_is_contact(kind)
    integer, intent(in) :: kind   !! force kind
    force_is_contact = kind >= FRC_CONTACT0 .and. kind <= FRC_CONTACT1
  end function force_is_contact

  !> Expected raw length given the data, or -1 when malformed.
  pure integer function force_raw_length(kind, raw)
    integer, intent(in) :: kind      !! force kind
    real(wp), intent(in) :: raw(:)   !! raw parameters
    integer :: n1, n2
    force_raw_length = -1
    select case (kind)
    case (FRC_SPRING)
      if (size(raw) < 8) return
      n1 = fun_length(raw(8:))
      if (n1 > 0) force_raw_length = 7 + n1
    case (FRC_TORQUE)
      force_raw_length = fun_length(raw)
    case (FRC_POINT)
      if (size(raw) < 3) return
      n1 = fun_length(raw(3:))
      if (n1 < 0) return
      n2 = fun_length(raw(3 + n1:))
      if (n2 > 0) force_raw_length = 2 + n1 + n2
    case (FRC_ROTSPRING)
      if (size(raw) < 4) return
      n1 = fun_length(raw(4:))
      if (n1 > 0) force_raw_length = 3 + n1
    case (FRC_CONTACT0:FRC_CONTACT1)
      force_raw_length = contact_raw_length(kind - FRC_CONTACT0 + 1, raw)
    case (FRC_FRICTION)
      force_raw_length = friction_raw_length()
    end select
  end function force_raw_length

  !> Check raw parameters (finite, k >= 0, c >= 0, L0 >= 0); prepared = raw. Contacts are
  !! prepared by mbd_contact (meff: the pair's effective mass, for the linear law); joint
  !! friction by mbd_model (it needs its joint).
  subroutine force_prepare(kind, raw, prep, status, msg, meff)
    integer, intent(in) :: kind                    !! force kind
    real(wp), intent(in) :: raw(:)                 !! raw parameters (exact length)
    real(wp), allocatable, intent(out) :: prep(:)  !! prepared parameters
    integer, intent(out) :: status                 !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    real(wp), intent(in), optional :: meff         !! effective mass of a contact pair
    integer :: nf
    real(wp) :: me
    status = MBD_OK; msg = ''
    select case (kind)
    case (FRC_CONTACT0:FRC_CONTACT1)
      me = zero
      if (present(meff)) me = meff
      call contact_prepare(kind - FRC_CONTACT0 + 1, raw, me, prep, status, msg)
      return
    case (FRC_FRICTION)
      prep = raw
      return
    case (FRC_SPRING)
      if (.not. (raw(5) >= zero .and. raw(6) >= zero .and. raw(7) >= zero)) then
        status = MBD_BAD_PARAM
        msg = 'spring stiffness, damping and free length must be >= 0'; return
      end if
      call fun_check(raw(8:), status, msg)
    case (FRC_TORQUE)
      call fun_check(raw, status, msg)
    case (FRC_POINT)
      nf = fun_length(raw(3:))
      call fun_check(raw(3:2 + nf), status, msg)
      if (status == MBD_OK) call fun_check(raw(3 + nf:), status, msg)
    case (FRC_ROTSPRING)
      if (.not. (raw(1) >= zero .and. raw(2) >= zero)) then
        status = MBD_BAD_PARAM; msg = 'rotational spring stiffness and damping must be >= 0'
        return
      end if
      call fun_check(raw(4:), status, msg)
    case default
      status = MBD_BAD_PARAM; msg = 'unknown force kind'
    end select
    if (status == MBD_OK) prep = raw
  end subroutine force_prepare

  !> Length exponents e of the raw parameters of a nondimensional model (mbd_model): a
  !! parameter p becomes p L**e. With lengths over L, masses m L**2 and forces F L (the
  !! generalized forces conjugate to x / L), stiffness and damping of a spring take L**2, its
  !! points and free length L**-1, its actuator force L; torques and rotational springs stay.
  !! Contact stiffnesses k (F = k delta**n) take L**(1 + n): fr returns the non-integer part
  !! n (the scale is p L**(ex + fr)).
  pure subroutine force_exponents(kind, raw, ex, fr)
    integer, intent(in) :: kind      !! force kind
    real(wp), intent(in) :: raw(:)   !! raw parameters (well formed, exact length)
    integer, intent(out) :: ex(:)    !! exponents (size(raw))
    real(wp), intent(out), optional :: fr(:)   !! fractional exponents added to ex
    real(wp) :: frl(size(raw))
    integer :: nf
    ex = 0
    frl = zero
    if (present(fr)) fr = zero
    select case (kind)
    case (FRC_CONTACT0:FRC_CONTACT1)
      call contact_exponents(kind - FRC_CONTACT0 + 1, raw, ex, frl)
      if (present(fr)) fr = frl
    case (FRC_FRICTION)
      call friction_exponents(ex)
    case (FRC_SPRING)
      ex(1:4) = -1; ex(5:6) = 2; ex(7) = -1
      call fun_exponents(raw(8:), 1, ex(8:))
    case (FRC_POINT)
      ex(1:2) = -1
      nf = fun_length(raw(3:))
      call fun_exponents(raw(3:), 1, ex(3:))
      call fun_exponents(raw(3 + nf:), 1, ex(3 + nf:))
    end select
  end subroutine force_exponents

  !> Generalized force over the local slots and potential energy of one element; a contact
  !! reads its state st (mbd_contact; absent: open) and returns its outputs in out.
  pure subroutine force_eval(kind, p, si, sj, ql, qdl, t, ql_force, v, vload, st, out)
    integer, intent(in) :: kind             !! force kind
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the bodies (0 = ground)
    real(wp), intent(in) :: ql(NLOC)        !! local coordinates
    real(wp), intent(in) :: qdl(NLOC)       !! local velocities
    real(wp), intent(in) :: t               !! time
    real(wp), intent(out) :: ql_force(NLOC) !! generalized force on the local slots
    real(wp), intent(out) :: v              !! potential energy
    real(wp), intent(out) :: vload          !! potential of the loads frozen at t
    real(wp), intent(in), optional :: st(NCS)    !! contact state
    real(wp), intent(out), optional :: out(NEO)  !! contact outputs
    real(wp) :: sto(NCS), oo(NEO)
    type(kvec) :: d, pt
    type(kscal) :: l, a
    type(kloc) :: x
    real(wp) :: f, f1, f2, fy, tension, tau
    integer :: nf
    ql_force = zero; v = zero; vload = zero
    if (present(out)) out = zero
    x = local_state(ql, qdl)
    select case (kind)
    case (FRC_SPRING)
      d = vsub(body_point(x, sj, p(3:4)), body_point(x, si, p(1:2)))
      call fun_eval(p(8:), t, f, f1, f2)
      if (dot_product(d%v, d%v) > zero) then
        l = ssqrt(vdot(d, d))
        tension = p(5) * (l%v - p(7)) + p(6) * l%vd - f
        ql_force = -tension * l%d
        v = half * p(5) * (l%v - p(7))**2
      else
        v = half * p(5) * p(7)**2
      end if
    case (FRC_TORQUE)
      call fun_eval(p, t, f, f1, f2)
      if (si > 0) ql_force(3) = f
      vload = -f * ql(3)
    case (FRC_POINT)
      pt = body_point(x, si, p(1:2))
      nf = fun_length(p(3:))
      call fun_eval(p(3:), t, f, f1, f2)
      call fun_eval(p(3 + nf:), t, fy, f1, f2)
      ql_force = f * pt%d(1, :) + fy * pt%d(2, :)
      vload = -(f * pt%v(1) + fy * pt%v(2))
    case (FRC_ROTSPRING)
      a = ssub(body_angle(x, sj), body_angle(x, si))
      call fun_eval(p(4:), t, f, f1, f2)
      tau = -p(1) * (a%v - p(3)) - p(2) * a%vd + f
      ql_force = tau * a%d
      v = half * p(1) * (a%v - p(3))**2
    case (FRC_CONTACT0:FRC_CONTACT1)
      sto = [-one, zero]                       ! untracked
      if (present(st)) sto = st
      if (present(out)) then
        call contact_eval(kind - FRC_CONTACT0 + 1, p, si, sj, x, sto, ql_force, v, out, &
                          exact=.true.)
      else
        call contact_eval(kind - FRC_CONTACT0 + 1, p, si, sj, x, sto, ql_force, v, oo)
      end if
    end select
  end subroutine force_eval

  !> True when raw entry j of a force is a count of one of its functions.
  pure logical function force_is_count(kind, raw, j)
    integer, intent(in) :: kind      !! force kind
    real(wp), intent(in) :: raw(:)   !! raw parameters
    integer, intent(in) :: j         !! raw entry
    integer :: nf
    force_is_count = .false.
    select case (kind)
    case (FRC_SPRING)
      if (j >= 8) force_is_count = fun_is_count(raw(8:), j - 7)
    case (FRC_TORQUE)
      force_is_count = fun_is_count(raw, j)
    case (FRC_POINT)
      nf = fun_length(raw(3:))
      if (j >= 3 .and. j < 3 + nf) force_is_count = fun_is_count(raw(3:), j - 2)
      if (j >= 3 + nf) force_is_count = fun_is_count(raw(3 + nf:), j - 2 - nf)
    case (FRC_ROTSPRING)
      if (j >= 4) force_is_count = fun_is_count(raw(4:), j - 3)
    end select
  end function force_is_count

  !> Change of the generalized force of one element along a direction (dq, dq_dot of the
  !! local slots) and a change tp of its parameters (prepared = raw), by the product rule
  !! on dual points (mbd_dual):
  !!   spring      Q = -T L_q,  dT = dk (L - L0) + k (dL - dL0) + dc L_dot + c dL_dot - df
  !!   torque      dQ_theta = df         point  dQ = dF J_P^T + F dJ_P^T
  !!   rotational  Q = tau a_q, dtau = -dk (a - a0) - k (da - da0) - dc a_dot - c da_dot + df
  pure subroutine force_eval_d(kind, p, tp, si, sj, ql, qdl, tq, tqd, t, tforce)
    integer, intent(in) :: kind             !! force kind
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the bodies (0 = ground)
    real(wp), intent(in) :: ql(NLOC), qdl(NLOC)  !! local coordinates and velocities
    real(wp), intent(in) :: tq(NLOC), tqd(NLOC)  !! direction
    real(wp), intent(in) :: t               !! time
    real(wp), intent(out) :: tforce(NLOC)   !! change of the generalized force
    type(dloc) :: x
    type(dvec) :: pt
    type(dscal) :: a
    real(wp) :: f, f1, f2, tf, tf1, tf2, fy, tfy, tau, ttau
    integer :: nf
    tforce = zero
    x = dual_state(local_state(ql, qdl), tq, tqd)
    select case (kind)
    case (FRC_SPRING)
      call spring_d(x, p, tp, si, sj, t, tforce)
    case (FRC_TORQUE)
      call fun_eval_d(p, tp, t, tf, tf1, tf2)
      if (si > 0) tforce(3) = tf
    case (FRC_POINT)
      pt = body_point(x, si, p(1:2), tp(1:2))
      nf = fun_length(p(3:))
      call fun_eval(p(3:), t, f, f1, f2)
      call fun_eval(p(3 + nf:), t, fy, f1, f2)
      call fun_eval_d(p(3:), tp(3:), t, tf, tf1, tf2)
      call fun_eval_d(p(3 + nf:), tp(3 + nf:), t, tfy, tf1, tf2)
      tforce = tf * pt%a%d(1, :) + f * pt%t%d(1, :) + tfy * pt%a%d(2, :) + fy * pt%t%d(2, :)
    case (FRC_ROTSPRING)
      a = ssub(body_angle(x, sj), body_angle(x, si))
      call fun_eval(p(4:), t, f, f1, f2)
      call fun_eval_d(p(4:), tp(4:), t, tf, tf1, tf2)
      tau = -p(1) * (a%a%v - p(3)) - p(2) * a%a%vd + f
      ttau = -tp(1) * (a%a%v - p(3)) - p(1) * (a%t%v - tp(3)) - tp(2) * a%a%vd - &
             p(2) * a%t%vd + tf
      tforce = ttau * a%a%d + tau * a%t%d
    end select
  end subroutine force_eval_d

  !> force_eval_d of a spring-damper-actuator in closed form (the dual types carry the
  !! point Jacobians' tangents through every operation: ~4x the work). d = P_j - P_i,
  !! l = |d|, u = d / l, T = k (l - l0) + c l_dot - f(t), Q = -T grad l with grad l =
  !! (-u, -u . B_i s_i; u, u . B_j s_j); along (dq, dq_dot, dp):
  !!   dl = u . dd,  du = (dd - u dl) / l,  dl_dot = du . d_dot + u . dd_dot,
  !!   dT = dk (l - l0) + k (dl - dl0) + dc l_dot + c dl_dot - df,
  !!   dQ = -dT grad l - T d(grad l),  d(u . B s) = du . B s + u . d(B s).
  pure subroutine spring_d(x, p, tp, si, sj, t, tforce)
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the bodies (0 = ground)
    real(wp), intent(in) :: t               !! time
    real(wp), intent(out) :: tforce(NLOC)   !! change of the generalized force
    type(spring_v) :: v
    tforce = zero
    call spring_values(x%x, p, si, sj, t, v)
    if (v%l > zero) call spring_change(x, v, p, tp, si, sj, t, tforce)
  end subroutine spring_d

  !> The values spring_d's changes are taken at: B s' and A s' of both points, u, l, the
  !! relative velocity dd = d_dot, l_dot and the tension T (l = 0: a spring of zero length,
  !! no direction; the rest is then not set).
  pure subroutine spring_values(x, p, si, sj, t, v)
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the bodies (0 = ground)
    real(wp), intent(in) :: t               !! time
    type(spring_v), intent(out) :: v        !! the values
    real(wp) :: pi(2), ari(2), pj(2), arj(2), vi(2), vj(2), d(2), l, f, f1, f2
    call point_values(x, si, p(1:2), pi, v%bi, ari, v%aui)
    call point_values(x, sj, p(3:4), pj, v%bj, arj, v%auj)
    vi = point_rate(x, si, v%bi); vj = point_rate(x, sj, v%bj)
    d = pj - pi
    l = dot_product(d, d)
    v%l = zero
    if (.not. l > zero) return
    v%l = sqrt(l); v%u = d / v%l
    v%dd = vj - vi
    v%ldot = dot_product(v%u, v%dd)
    call fun_eval(p(8:), t, f, f1, f2)
    v%tension = p(5) * (v%l - p(7)) + p(6) * v%ldot - f
  end subroutine spring_values

  !> spring_d's change of the generalized force along x's direction and tp from the values
  !! v (spring_values, l > 0).
  pure subroutine spring_change(x, v, p, tp, si, sj, t, tforce)
    type(dloc), intent(in) :: x             !! local state and direction
    type(spring_v), intent(in) :: v         !! the values at x
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the bodies (0 = ground)
    real(wp), intent(in) :: t               !! time
    real(wp), intent(out) :: tforce(NLOC)   !! change of the generalized force
    real(wp) :: tpi(2), tbi(2), tari(2), tvi(2), tpj(2), tbj(2), tarj(2), tvj(2)
    real(wp) :: tdd(2), td(2), tu(2), tl, tldot, tf, tf1, tf2, ttension
    tforce = zero
    call point_changes(x, si, tp(1:2), v%aui, v%bi, tpi, tbi, tari)
    call point_changes(x, sj, tp(3:4), v%auj, v%bj, tpj, tbj, tarj)
    tvi = rate_change(si, v%bi, tbi); tvj = rate_change(sj, v%bj, tbj)
    tdd = tvj - tvi; td = tpj - tpi
    tl = dot_product(v%u, td)
    tu = (td - v%u * tl) / v%l
    tldot = dot_product(tu, v%dd) + dot_product(v%u, tdd)
    call fun_eval_d(p(8:), tp(8:), t, tf, tf1, tf2)
    ttension = tp(5) * (v%l - p(7)) + p(5) * (tl - tp(7)) + tp(6) * v%ldot + p(6) * tldot - tf
    call spring_q_change(v, si, sj, ttension, tu, tbi, tbj, tforce)
  contains
    !> Change of a slot's point velocity r_dot + B s theta_dot (ground: zero).
    pure function rate_change(slot, bs, tbs) result(tv)
      integer, intent(in) :: slot
      real(wp), intent(in) :: bs(2), tbs(2)
      real(wp) :: tv(2)
      integer :: c
      tv = zero
      if (slot == 0) return
      c = 3 * (slot - 1)
      tv = x%tqd(c + 1:c + 2) + tbs * x%x%qd(c + 3) + bs * x%tqd(c + 3)
    end function rate_change
  end subroutine spring_change

  !> Velocity r_dot + B s theta_dot of a slot's point (ground: zero).
  pure function point_rate(x, slot, bs) result(v)
    type(kloc), intent(in) :: x
    integer, intent(in) :: slot
    real(wp), intent(in) :: bs(2)
    real(wp) :: v(2)
    integer :: c
    v = zero
    if (slot == 0) return
    c = 3 * (slot - 1)
    v = x%qd(c + 1:c + 2) + bs * x%qd(c + 3)
  end function point_rate

  !> force_eval_d along several directions (columns of tq, tqd, tp) at one state: a
  !! spring's values once (spring_values) and its change per direction, the other kinds
  !! direction by direction.
  pure subroutine force_eval_dm(kind, p, tp, aff, si, sj, ql, qdl, tq, tqd, t, tforce)
    integer, intent(in) :: kind             !! force kind
    real(wp), intent(in) :: p(:)            !! prepared parameters
    real(wp), intent(in) :: tp(:, :)        !! their changes (size(p), nk)
    logical, intent(in) :: aff(:)           !! (nk) tp(:, k) is not zero
    integer, intent(in) :: si, sj           !! slot ids of the bodies (0 = ground)
    real(wp), intent(in) :: ql(NLOC), qdl(NLOC)  !! local coordinates and velocities
    real(wp), intent(in) :: tq(:, :), tqd(:, :)  !! directions (NLOC, nk)
    real(wp), intent(in) :: t               !! time
    real(wp), intent(out) :: tforce(:, :)   !! changes of the generalized force (NLOC, nk)
    type(kloc) :: xs
    type(spring_v) :: v
    integer :: k
    if (kind /= FRC_SPRING) then
      do k = 1, size(tforce, 2)
        call force_eval_d(kind, p, tp(:, k), si, sj, ql, qdl, tq(:, k), tqd(:, k), t, &
                          tforce(:, k))
      end do
      return
    end if
    tforce = zero
    xs = local_state(ql, qdl)
    call spring_values(xs, p, si, sj, t, v)
    if (.not. v%l > zero) return
    do k = 1, size(tforce, 2)
      if (.not. aff(k)) then
        call spring_state_change(v, p, si, sj, qdl, tq(:, k), tqd(:, k), tforce(:, k))
      else if (.not. any(abs(tp(1:4, k)) > zero)) then   ! (the points stay: the tension's)
        call spring_state_change(v, p, si, sj, qdl, tq(:, k), tqd(:, k), tforce(:, k))
        call spring_tension_change(v, p, tp(:, k), si, sj, t, tforce(:, k))
      else
        call spring_change(dual_state(xs, tq(:, k), tqd(:, k)), v, p, tp(:, k), si, sj, t, &
                           tforce(:, k))
      end if
    end do
  end subroutine force_eval_dm

  !> The change of a force's generalized force per unit rate of its parameters' change tp
  !! (a parameter varied in time, p = p0 + P(t): the frequency response's and the
  !! linearized system's rate input). A spring-damper's points moving in their bodies at
  !! s'_dot = tp(1:2), tp(3:4) move its ends at A s'_dot (a ground point at s'_dot), which
  !! its damper sees:
  !!   dl_dot = u . (A_j s'_j_dot - A_i s'_i_dot),  dT = c dl_dot,  dQ = -grad l dT;
  !! no other parameter of any kind acts through its rate (a free length or an angle0 is
  !! not seen by the damper, a point force has no velocity).
  pure subroutine force_rate_d(kind, p, tp, si, sj, ql, qdl, t, tforce)
    integer, intent(in) :: kind             !! force kind
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their rate
    integer, intent(in) :: si, sj           !! slot ids of the bodies (0 = ground)
    real(wp), intent(in) :: ql(NLOC), qdl(NLOC)  !! local coordinates and velocities
    real(wp), intent(in) :: t               !! time
    real(wp), intent(out) :: tforce(NLOC)   !! change of the generalized force
    type(kloc) :: xs
    type(spring_v) :: v
    real(wp) :: dv(2), tt
    tforce = zero
    if (kind /= FRC_SPRING) return
    if (.not. (any(abs(tp(1:4)) > zero) .and. abs(p(6)) > zero)) return
    xs = local_state(ql, qdl)
    call spring_values(xs, p, si, sj, t, v)
    if (.not. v%l > zero) return
    dv = moved(sj, tp(3:4)) - moved(si, tp(1:2))
    tt = p(6) * dot_product(v%u, dv)
    if (si > 0) then
      tforce(1:2) = tt * v%u
      tforce(3) = tt * dot_product(v%u, v%bi)
    end if
    if (sj > 0) then
      tforce(4:5) = -tt * v%u
      tforce(6) = -tt * dot_product(v%u, v%bj)
    end if
  contains
    !> A s'_dot of a slot's point (ground: s'_dot itself, its frame the global one).
    pure function moved(slot, sd) result(w)
      integer, intent(in) :: slot
      real(wp), intent(in) :: sd(2)
      real(wp) :: w(2)
      w = sd
      if (slot == 0) return
      w = [xs%c(slot) * sd(1) - xs%s(slot) * sd(2), xs%s(slot) * sd(1) + xs%c(slot) * sd(2)]
    end function moved
  end subroutine force_rate_d

  !> force_eval_d along up to four directions given as rows (the local slots' tqr, tqdr
  !! (4, NLOC), the rows past np zero) with the parameters' changes tp (size(p), np;
  !! aff(k): 0 column k is zero, 1 a spring's points stay, 2 otherwise), the changes as rows
  !! tfr (4, NLOC). A spring's state part (spring_rows) takes the four rows at once, its
  !! parameters' part is added for the affected ones; the other kinds go direction by
  !! direction.
  pure subroutine force_rows_d(kind, p, tp, aff, si, sj, ql, qdl, np, tqr, tqdr, t, tfr, cs, sn)
    integer, intent(in) :: kind             !! force kind
    real(wp), intent(in) :: p(:)            !! prepared parameters
    real(wp), intent(in) :: tp(:, :)        !! their changes (size(p), np)
    integer, intent(in) :: aff(:)           !! (np) how tp(:, k) changes the force
    integer, intent(in) :: si, sj           !! slot ids of the bodies (0 = ground)
    real(wp), intent(in) :: ql(NLOC), qdl(NLOC)  !! local coordinates and velocities
    integer, intent(in) :: np               !! directions (at most 4)
    real(wp), intent(in) :: tqr(4, NLOC), tqdr(4, NLOC)  !! directions as rows
    real(wp), intent(in) :: t               !! time
    real(wp), intent(out) :: tfr(4, NLOC)   !! changes as rows
    !> cos and sin of the two slots' angles (1, 0 for ground), when the caller has them
    real(wp), intent(in), optional :: cs(2), sn(2)
    type(kloc) :: xs
    type(spring_v) :: v
    real(wp) :: tf(NLOC)
    real(wp), parameter :: z(NLOC) = zero
    integer :: k
    tfr = zero
    if (kind /= FRC_SPRING) then
      do k = 1, np
        call force_eval_d(kind, p, tp(:, k), si, sj, ql, qdl, tqr(k, :), tqdr(k, :), t, tf)
        tfr(k, :) = tf
      end do
      return
    end if
    if (present(cs) .and. present(sn)) then
      xs%q = ql; xs%qd = qdl; xs%c = cs; xs%s = sn
    else
      xs = local_state(ql, qdl)
    end if
    call spring_values(xs, p, si, sj, t, v)
    if (.not. v%l > zero) return
    call spring_rows(v, p, qdl, tqr, tqdr, tfr)
    do k = 1, np                            ! the parameters' own changes
      if (aff(k) == 0) cycle
      tf = zero
      if (aff(k) == 1) then                 ! the points stay: the tension's change only
        call spring_tension_change(v, p, tp(:, k), si, sj, t, tf)
      else
        call spring_change(dual_state(xs, z, z), v, p, tp(:, k), si, sj, t, tf)
      end if
      tfr(k, :) = tfr(k, :) + tf
    end do
  end subroutine force_rows_d

  !> A spring-damper-actuator's change of Q = -T grad l along four state directions at
  !! once (rows of tqr, tqdr (4, NLOC); a ground slot's entries zero, as its B s' and A s'
  !! in v). With D = dd/dq_loc = [-I, -B_i s'_i, I, B_j s'_j] (2 x 6), grad l = g = D^T u,
  !! l_dot = g . q_dot and H = dg/dq = D^T (I - u u^T) D / l + diag(0, 0, u . A_i s'_i, 0, 0,
  !! -u . A_j s'_j) (symmetric), along (dq, dq_dot):
  !!   dl = g . dq,  dl_dot = g . dq_dot + (H q_dot) . dq,  dT = k dl + c dl_dot,
  !!   dQ = -g dT - T H dq,  H dq = D^T ((I - u u^T) D dq) / l + diag dq;
  !! H q_dot = D^T ((I - u u^T) d_dot) / l + diag q_dot (d_dot = D q_dot, the points'
  !! relative velocity).
  pure subroutine spring_rows(v, p, qdl, tqr, tqdr, tfr)
    type(spring_v), intent(in) :: v         !! the values (spring_values, l > 0)
    real(wp), intent(in) :: p(:)            !! prepared parameters
    real(wp), intent(in) :: qdl(NLOC)       !! local velocities
    real(wp), intent(in) :: tqr(4, NLOC), tqdr(4, NLOC)  !! directions as rows
    real(wp), intent(inout) :: tfr(4, NLOC) !! changes as rows (added)
    real(wp) :: g(6), w(6), e(2), rl, ci, cj, dx, dy, dl, ex, ey, dt, th
    integer :: k
    rl = one / v%l
    ci = dot_product(v%u, v%aui); cj = dot_product(v%u, v%auj)
    g = [-v%u(1), -v%u(2), -dot_product(v%u, v%bi), v%u(1), v%u(2), dot_product(v%u, v%bj)]
    e = (v%dd - v%u * dot_product(v%u, v%dd)) * rl   ! (I - u u^T) d_dot / l
    w = [-e(1), -e(2), -dot_product(v%bi, e) + ci * qdl(3), e(1), e(2), &
         dot_product(v%bj, e) - cj * qdl(6)]
    th = v%tension
    do k = 1, 4
      ! D dq, dl = u . D dq, (I - u u^T) D dq / l
      dx = tqr(k, 4) - tqr(k, 1) - v%bi(1) * tqr(k, 3) + v%bj(1) * tqr(k, 6)
      dy = tqr(k, 5) - tqr(k, 2) - v%bi(2) * tqr(k, 3) + v%bj(2) * tqr(k, 6)
      dl = v%u(1) * dx + v%u(2) * dy
      ex = (dx - v%u(1) * dl) * rl; ey = (dy - v%u(2) * dl) * rl
      dt = p(5) * dl + p(6) * (g(1) * tqdr(k, 1) + g(2) * tqdr(k, 2) + g(3) * tqdr(k, 3) + &
                               g(4) * tqdr(k, 4) + g(5) * tqdr(k, 5) + g(6) * tqdr(k, 6) + &
                               w(1) * tqr(k, 1) + w(2) * tqr(k, 2) + w(3) * tqr(k, 3) + &
                               w(4) * tqr(k, 4) + w(5) * tqr(k, 5) + w(6) * tqr(k, 6))
      tfr(k, 1) = tfr(k, 1) - g(1) * dt + th * ex
      tfr(k, 2) = tfr(k, 2) - g(2) * dt + th * ey
      tfr(k, 3) = tfr(k, 3) - g(3) * dt - th * (ci * tqr(k, 3) - (v%bi(1) * ex + v%bi(2) * ey))
      tfr(k, 4) = tfr(k, 4) - g(4) * dt - th * ex
      tfr(k, 5) = tfr(k, 5) - g(5) * dt - th * ey
      tfr(k, 6) = tfr(k, 6) - g(6) * dt - th * (v%bj(1) * ex + v%bj(2) * ey - cj * tqr(k, 6))
    end do
  end subroutine spring_rows

  !> Add to tforce the change of a spring's generalized force by a change tp of its
  !! parameters that leaves its points alone: dT = dk (l - l0) - k dl0 + dc l_dot - df,
  !! dQ = -dT grad l.
  pure subroutine spring_tension_change(v, p, tp, si, sj, t, tforce)
    type(spring_v), intent(in) :: v         !! the values (spring_values, l > 0)
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the bodies (0 = ground)
    real(wp), intent(in) :: t               !! time
    real(wp), intent(inout) :: tforce(NLOC) !! change of the generalized force
    real(wp) :: tf, tf1, tf2, tt
    tf = zero
    if (any(abs(tp(8:)) > zero)) call fun_eval_d(p(8:), tp(8:), t, tf, tf1, tf2)
    tt = tp(5) * (v%l - p(7)) - p(5) * tp(7) + tp(6) * v%ldot - tf
    if (si > 0) then
      tforce(1:2) = tforce(1:2) + tt * v%u
      tforce(3) = tforce(3) + tt * dot_product(v%u, v%bi)
    end if
    if (sj > 0) then
      tforce(4:5) = tforce(4:5) - tt * v%u
      tforce(6) = tforce(6) - tt * dot_product(v%u, v%bj)
    end if
  end subroutine spring_tension_change

  !> spring_change along a direction of the state alone (no parameter change: the terms of
  !! tp vanish): a point changes by dr + B s' dtheta, B s' by -A s' dtheta, the point's
  !! velocity by dr_dot + d(B s') theta_dot + B s' dtheta_dot; then as spring_change with
  !! dT = k dl + c dl_dot.
  pure subroutine spring_state_change(v, p, si, sj, qdl, tq, tqd, tforce)
    type(spring_v), intent(in) :: v         !! the values (spring_values, l > 0)
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the bodies (0 = ground)
    real(wp), intent(in) :: qdl(NLOC)       !! local velocities
    real(wp), intent(in) :: tq(NLOC), tqd(NLOC)  !! direction
    real(wp), intent(out) :: tforce(NLOC)   !! change of the generalized force
    real(wp) :: td(2), tdd(2), tbi(2), tbj(2), tl, tu(2), tldot, tt
    td = zero; tdd = zero; tbi = zero; tbj = zero
    if (sj > 0) then                        ! d = P_j - P_i
      tbj = -v%auj * tq(6)
      td = tq(4:5) + v%bj * tq(6)
      tdd = tqd(4:5) + tbj * qdl(6) + v%bj * tqd(6)
    end if
    if (si > 0) then
      tbi = -v%aui * tq(3)
      td = td - (tq(1:2) + v%bi * tq(3))
      tdd = tdd - (tqd(1:2) + tbi * qdl(3) + v%bi * tqd(3))
    end if
    tl = dot_product(v%u, td)
    tu = (td - v%u * tl) / v%l
    tldot = dot_product(tu, v%dd) + dot_product(v%u, tdd)
    tt = p(5) * tl + p(6) * tldot
    tforce = zero
    call spring_q_change(v, si, sj, tt, tu, tbi, tbj, tforce)
  end subroutine spring_state_change

  !> The change of a spring's Q = -T grad l from those of its tension (tt), direction (tu)
  !! and points' B s' (tbi, tbj): on body i (tt u + T tu, tt u . B_i s' + T (tu . B_i s' +
  !! u . d(B_i s'))), on body j the same negated with B_j s'; a ground slot's entries left.
  pure subroutine spring_q_change(v, si, sj, tt, tu, tbi, tbj, tforce)
    type(spring_v), intent(in) :: v         !! the values (spring_values)
    integer, intent(in) :: si, sj           !! slot ids of the bodies (0 = ground)
    real(wp), intent(in) :: tt, tu(2), tbi(2), tbj(2)  !! the changes
    real(wp), intent(inout) :: tforce(NLOC) !! change of the generalized force
    if (si > 0) then
      tforce(1:2) = tt * v%u + v%tension * tu
      tforce(3) = tt * dot_product(v%u, v%bi) + &
                  v%tension * (dot_product(tu, v%bi) + dot_product(v%u, tbi))
    end if
    if (sj > 0) then
      tforce(4:5) = -tt * v%u - v%tension * tu
      tforce(6) = -tt * dot_product(v%u, v%bj) - &
                  v%tension * (dot_product(tu, v%bj) + dot_product(v%u, tbj))
    end if
  end subroutine spring_q_change

end module mbd_forces
