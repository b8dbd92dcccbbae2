!> mbd_points: kinematic quantities that every joint is built from.
!!
!! A constraint sees a few "local" coordinates: slots 1-3 are (x, y, theta) of its first body,
!! slots 4-6 those of its second body, slot 7 an extra coordinate of its own (a cam's contact
!! parameter alpha). Ground has no slots (slot id 0).
!!
!! A `kvec` is a 2-vector v(q) carried with everything the constraint rows need:
!!   v        value
!!   d        dv/dq_loc                       (2 x NLOC, a block of J)
!!   vd       dv/dt = d q_dot                 (velocity)
!!   ar       d2v/dt2 - d q_ddot              (quadratic velocity remainder)
!! For a body point P = r + A(theta) s' (Haug, Computer-Aided Kinematics and Dynamics, ch. 3):
!!   d = [I, B s'],  vd = r_dot + B s' theta_dot,  ar = -A s' theta_dot**2.
!! A constraint Phi = f(v, ...) then has J = df, gamma = -(ar of Phi) (+ time terms for drivers).
!! A `kscal` is the same for a scalar. The operations below are the product rules.
!! A `kloc` is what a constraint reads: its slots' coordinates and velocities and the cosine
!! and sine of its two bodies' angles, computed once per body and assembly (mbd_assemble).
module mbd_points
  use mbd_kinds, only: wp, zero, one, two, half
  implicit none
  private
  public :: NLOC, MAXROW, kvec, kscal, kloc
  public :: rot, drot, perp, local_state
  public :: point_terms, body_point, body_vector, curve_point, curve_vector, body_angle, slot_value, const_vec
  public :: vsub, vadd, vscale, vdot, vcross, ssub, sadd, sscale, ssqrt, sconst
  public :: put_vec, put_scal

  ! generic names: mbd_dual adds the directional-derivative versions
  interface body_point
    module procedure body_point_k
  end interface body_point
  interface body_vector
    module procedure body_vector_k
  end interface body_vector
  interface curve_point
    module procedure curve_point_k
  end interface curve_point
  interface curve_vector
    module procedure curve_vector_k
  end interface curve_vector
  interface body_angle
    module procedure body_angle_k
  end interface body_angle
  interface slot_value
    module procedure slot_value_k
  end interface slot_value
  interface const_vec
    module procedure const_vec_k
  end interface const_vec
  interface vsub
    module procedure vsub_k
  end interface vsub
  interface vadd
    module procedure vadd_k
  end interface vadd
  interface vscale
    module procedure vscale_k
  end interface vscale
  interface vdot
    module procedure vdot_k
  end interface vdot
  interface vcross
    module procedure vcross_k
  end interface vcross
  interface ssub
    module procedure ssub_k
  end interface ssub
  interface sadd
    module procedure sadd_k
  end interface sadd
  interface sscale
    module procedure sscale_k
  end interface sscale
  interface ssqrt
    module procedure ssqrt_k
  end interface ssqrt
  interface sconst
    module procedure sconst_k
  end interface sconst
  interface put_vec
    module procedure put_vec_k
  end interface put_vec
  interface put_scal
    module procedure put_scal_k
  end interface put_scal

  integer, parameter :: NLOC = 7    !! local coordinate slots: body i (1-3), body j (4-6), extra (7)
  integer, parameter :: MAXROW = 3  !! most rows any constraint writes

  !> A 2-vector quantity and its derivatives.
  type :: kvec
    real(wp) :: v(2) = zero         !! value
    real(wp) :: d(2, NLOC) = zero   !! Jacobian with respect to the local slots
    real(wp) :: vd(2) = zero        !! time derivative
    real(wp) :: ar(2) = zero        !! acceleration remainder: v_ddot = d q_ddot + ar
  end type kvec

  !> The local state of a constraint.
  type :: kloc
    real(wp) :: q(NLOC) = zero      !! coordinates of the slots
    real(wp) :: qd(NLOC) = zero     !! velocities of the slots
    real(wp) :: c(2) = one          !! cos(theta) of the first and second body (ground: 1)
    real(wp) :: s(2) = zero         !! sin(theta) of the first and second body (ground: 0)
  end type kloc

  !> A scalar quantity and its derivatives.
  type :: kscal
    real(wp) :: v = zero
    real(wp) :: d(NLOC) = zero
    real(wp) :: vd = zero
    real(wp) :: ar = zero
  end type kscal

contains

  !> A(theta), the planar rotation matrix.
  pure function rot(th) result(a)
    real(wp), intent(in) :: th  !! angle
    real(wp) :: a(2, 2)
    real(wp) :: c, s
    c = cos(th); s = sin(th)
    a(1, 1) = c; a(2, 1) = s; a(1, 2) = -s; a(2, 2) = c
  end function rot

  !> B(theta) = dA/dtheta.
  pure function drot(th) result(b)
    real(wp), intent(in) :: th  !! angle
    real(wp) :: b(2, 2)
    real(wp) :: c, s
    c = cos(th); s = sin(th)
    b(1, 1) = -s; b(2, 1) = c; b(1, 2) = -c; b(2, 2) = -s
  end function drot

  !> The vector turned by +90 degrees: perp(u) = (-u_y, u_x).
  pure function perp(u) result(w)
    real(wp), intent(in) :: u(2)  !! vector
    real(wp) :: w(2)
    w = [-u(2), u(1)]
  end function perp

  !> The local state from slot coordinates and velocities (the angles sit in slots 3 and 6).
  pure function local_state(ql, qdl) result(x)
    real(wp), intent(in) :: ql(NLOC)   !! local coordinates
    real(wp), intent(in) :: qdl(NLOC)  !! local velocities
    type(kloc) :: x
    x%q = ql; x%qd = qdl
    x%c = [cos(ql(3)), cos(ql(6))]; x%s = [sin(ql(3)), sin(ql(6))]
  end function local_state

  !> A constant vector (a point or a direction fixed in ground).
  pure function const_vec_k(u) result(a)
    real(wp), intent(in) :: u(2)  !! global components
    type(kvec) :: a
    a%v = u
  end function const_vec_k

  !> Body vector A(theta) u(alpha) with u depending on the extra slot (aslot > 0) or not.
  !! v = A u, d_theta = B u = perp(A u), d_alpha = A u1,
  !! ar = -A u thd**2 + 2 B u1 thd ald + A u2 ald**2.
  pure function curve_vector_k(x, slot, aslot, u, u1, u2) result(a)
    type(kloc), intent(in) :: x        !! local state
    integer, intent(in) :: slot        !! 0 ground, 1 first body, 2 second body
    integer, intent(in) :: aslot       !! 0, or the slot of the curve parameter
    real(wp), intent(in) :: u(2)       !! vector in the body frame
    real(wp), intent(in) :: u1(2)      !! du/dalpha
    real(wp), intent(in) :: u2(2)      !! d2u/dalpha2
    type(kvec) :: a
    real(wp) :: cs, sn, thd, ald, au(2), bu(2), au1(2), au2(2)
    integer :: c
    if (slot == 0) then
      a%v = u
      if (aslot > 0) then
        ald = x%qd(aslot)
        a%d(:, aslot) = u1
        a%vd = u1 * ald
        a%ar = u2 * ald**2
      end if
      return
    end if
    c = 3 * (slot - 1)
    cs = x%c(slot); sn = x%s(slot); thd = x%qd(c + 3)
    au = [cs * u(1) - sn * u(2), sn * u(1) + cs * u(2)]       ! A u
    bu = [-au(2), au(1)]                                       ! B u = perp(A u)
    a%v = au
    a%d(:, c + 3) = bu
    a%vd = bu * thd
    a%ar = -au * thd**2
    if (aslot > 0) then
      ald = x%qd(aslot)
      au1 = [cs * u1(1) - sn * u1(2), sn * u1(1) + cs * u1(2)]
      au2 = [cs * u2(1) - sn * u2(2), sn * u2(1) + cs * u2(2)]
      a%d(:, aslot) = au1
      a%vd = a%vd + au1 * ald
      a%ar = a%ar + two * [-au1(2), au1(1)] * thd * ald + au2 * ald**2
    end if
  end function curve_vector_k

  !> Body point r + A(theta) s(alpha) on a curve fixed in the body.
  pure function curve_point_k(x, slot, aslot, s, s1, s2) result(a)
    type(kloc), intent(in) :: x        !! local state
    integer, intent(in) :: slot        !! 0 ground, 1 first body, 2 second body
    integer, intent(in) :: aslot       !! slot of the curve parameter
    real(wp), intent(in) :: s(2)       !! point in the body frame
    real(wp), intent(in) :: s1(2)      !! ds/dalpha
    real(wp), intent(in) :: s2(2)      !! d2s/dalpha2
    type(kvec) :: a
    integer :: c
    a = curve_vector(x, slot, aslot, s, s1, s2)
    if (slot == 0) return
    c = 3 * (slot - 1)
    a%v = a%v + x%q(c + 1:c + 2)
    a%d(1, c + 1) = one; a%d(2, c + 2) = one
    a%vd = a%vd + x%qd(c + 1:c + 2)
  end function curve_point_k

  !> A body point's terms without the product-rule algebra (the joints that only compare
  !! points use these): P = r + A s', the theta column of its Jacobian [I, B s'], its
  !! velocity P_dot = r_dot + B s' thd and its acceleration remainder ar = -A s' thd**2.
  !! A ground point (slot 0) is the global point s: bs = vd = ar = 0.
  pure subroutine point_terms(x, slot, s, p, bs, vd, ar)
    type(kloc), intent(in) :: x        !! local state
    integer, intent(in) :: slot        !! 0 ground, 1 or 2
    real(wp), intent(in) :: s(2)       !! point in the body frame (global for ground)
    real(wp), intent(out) :: p(2)      !! P
    real(wp), intent(out) :: bs(2)     !! B s' = perp(A s')
    real(wp), intent(out) :: vd(2)     !! P_dot
    real(wp), intent(out) :: ar(2)     !! -A s' thd**2
    real(wp) :: au(2), thd
    integer :: c
    if (slot == 0) then
      p = s; bs = zero; vd = zero; ar = zero
      return
    end if
    c = 3 * (slot - 1)
    thd = x%qd(c + 3)
    au = [x%c(slot) * s(1) - x%s(slot) * s(2), x%s(slot) * s(1) + x%c(slot) * s(2)]   ! A s'
    p = x%q(c + 1:c + 2) + au
    bs = [-au(2), au(1)]
    vd = x%qd(c + 1:c + 2) + bs * thd
    ar = -au * thd**2
  end subroutine point_terms

  !> Body point P = r + A s':  d = [I, B s'], vd = r_dot + B s' thd, ar = -A s' thd**2.
  pure function body_point_k(x, slot, s) result(a)
    type(kloc), intent(in) :: x        !! local state
    integer, intent(in) :: slot        !! 0 ground (s is global), 1 or 2
    real(wp), intent(in) :: s(2)       !! point in the body frame
    type(kvec) :: a
    real(wp) :: au(2), thd
    integer :: c
    if (slot == 0) then
      a%v = s
      return
    end if
    c = 3 * (slot - 1)
    thd = x%qd(c + 3)
    au = [x%c(slot) * s(1) - x%s(slot) * s(2), x%s(slot) * s(1) + x%c(slot) * s(2)]   ! A s'
    a%v = x%q(c + 1:c + 2) + au
    a%d(1, c + 1) = one; a%d(2, c + 2) = one
    a%d(1, c + 3) = -au(2); a%d(2, c + 3) = au(1)                ! B s' = perp(A s')
    a%vd = x%qd(c + 1:c + 2) + [-au(2), au(1)] * thd
    a%ar = -au * thd**2
  end function body_point_k

  !> Body-fixed direction u = A u':  d_theta = B u', ar = -A u' thd**2.
  pure function body_vector_k(x, slot, u) result(a)
    type(kloc), intent(in) :: x        !! local state
    integer, intent(in) :: slot        !! 0 ground, 1 or 2
    real(wp), intent(in) :: u(2)       !! vector in the body frame
    type(kvec) :: a
    a = curve_vector(x, slot, 0, u, [zero, zero], [zero, zero])
  end function body_vector_k

  !> The absolute angle theta of a body (zero for ground).
  pure function body_angle_k(x, slot) result(a)
    type(kloc), intent(in) :: x        !! local state
    integer, intent(in) :: slot        !! 0 ground, 1 or 2
    type(kscal) :: a
    integer :: c
    if (slot == 0) return
    c = 3 * (slot - 1)
    a%v = x%q(c + 3); a%d(c + 3) = one; a%vd = x%qd(c + 3)
  end function body_angle_k

  !> A local coordinate as a scalar quantity (0 when the slot maps to nothing).
  pure function slot_value_k(x, s) result(a)
    type(kloc), intent(in) :: x        !! local state
    integer, intent(in) :: s           !! slot
    type(kscal) :: a
    a%v = x%q(s); a%d(s) = one; a%vd = x%qd(s)
  end function slot_value_k

  !> a - b.
  pure function vsub_k(a, b) result(c)
    type(kvec), intent(in) :: a, b  !! operands
    type(kvec) :: c
    c%v = a%v - b%v; c%d = a%d - b%d; c%vd = a%vd - b%vd; c%ar = a%ar - b%ar
  end function vsub_k

  !> a + b.
  pure function vadd_k(a, b) result(c)
    type(kvec), intent(in) :: a, b  !! operands
    type(kvec) :: c
    c%v = a%v + b%v; c%d = a%d + b%d; c%vd = a%vd + b%vd; c%ar = a%ar + b%ar
  end function vadd_k

  !> s a for a constant s.
  pure function vscale_k(s, a) result(c)
    real(wp), intent(in) :: s      !! constant factor
    type(kvec), intent(in) :: a    !! vector
    type(kvec) :: c
    c%v = s * a%v; c%d = s * a%d; c%vd = s * a%vd; c%ar = s * a%ar
  end function vscale_k

  !> a . b:  d = a^T db + b^T da,  ar = a.ar_b + b.ar_a + 2 a_dot.b_dot.
  pure function vdot_k(a, b) result(c)
    type(kvec), intent(in) :: a, b  !! operands
    type(kscal) :: c
    c%v = dot_product(a%v, b%v)
    c%d = a%v(1) * b%d(1, :) + a%v(2) * b%d(2, :) + b%v(1) * a%d(1, :) + b%v(2) * a%d(2, :)
    c%vd = dot_product(a%v, b%vd) + dot_product(a%vd, b%v)
    c%ar = dot_product(a%v, b%ar) + dot_product(b%v, a%ar) + two * dot_product(a%vd, b%vd)
  end function vdot_k

  !> a x b = a1 b2 - a2 b1, with the same product rule.
  pure function vcross_k(a, b) result(c)
    type(kvec), intent(in) :: a, b  !! operands
    type(kscal) :: c
    c%v = cross(a%v, b%v)
    c%d = a%v(1) * b%d(2, :) - a%v(2) * b%d(1, :) + b%v(2) * a%d(1, :) - b%v(1) * a%d(2, :)
    c%vd = cross(a%v, b%vd) + cross(a%vd, b%v)
    c%ar = cross(a%v, b%ar) + cross(a%ar, b%v) + two * cross(a%vd, b%vd)
  contains
    pure real(wp) function cross(x, y)
      real(wp), intent(in) :: x(2), y(2)
      cross = x(1) * y(2) - x(2) * y(1)
    end function cross
  end function vcross_k

  !> a - b for scalars.
  pure function ssub_k(a, b) result(c)
    type(kscal), intent(in) :: a, b  !! operands
    type(kscal) :: c
    c%v = a%v - b%v; c%d = a%d - b%d; c%vd = a%vd - b%vd; c%ar = a%ar - b%ar
  end function ssub_k

  !> a + b for scalars.
  pure function sadd_k(a, b) result(c)
    type(kscal), intent(in) :: a, b  !! operands
    type(kscal) :: c
    c%v = a%v + b%v; c%d = a%d + b%d; c%vd = a%vd + b%vd; c%ar = a%ar + b%ar
  end function sadd_k

  !> s a for a constant s.
  pure function sscale_k(s, a) result(c)
    real(wp), intent(in) :: s      !! constant factor
    type(kscal), intent(in) :: a   !! scalar
    type(kscal) :: c
    c%v = s * a%v; c%d = s * a%d; c%vd = s * a%vd; c%ar = s * a%ar
  end function sscale_k

  !> A constant scalar.
  pure function sconst_k(s) result(c)
    real(wp), intent(in) :: s   !! value
    type(kscal) :: c
    c%v = s
  end function sconst_k

  !> sqrt(a):  d = a_d / (2 v),  ar = a_ar / (2 v) - a_dot**2 / (4 v**3).
  pure function ssqrt_k(a) result(c)
    type(kscal), intent(in) :: a   !! argument (> 0)
    type(kscal) :: c
    c%v = sqrt(a%v)
    c%d = a%d * (half / c%v)
    c%vd = a%vd * (half / c%v)
    c%ar = a%ar * (half / c%v) - a%vd**2 / (4.0_wp * c%v**3)
  end function ssqrt_k

  !> Write a vector quantity as two constraint rows: Phi = v, J = d, gamma = -ar.
  pure subroutine put_vec_k(a, phi, jl, gam)
    type(kvec), intent(in) :: a           !! the constraint vector
    real(wp), intent(inout) :: phi(:)     !! rows of Phi (2)
    real(wp), intent(inout) :: jl(:, :)   !! local Jacobian rows (2 x NLOC)
    real(wp), intent(inout) :: gam(:)     !! rows of gamma (2)
    phi(1:2) = a%v; jl(1:2, :) = a%d; gam(1:2) = -a%ar
  end subroutine put_vec_k

  !> Write a scalar quantity as one constraint row.
  pure subroutine put_scal_k(a, phi, jl, gam)
    type(kscal), intent(in) :: a          !! the constraint scalar
    real(wp), intent(inout) :: phi        !! row of Phi
    real(wp), intent(inout) :: jl(:)      !! local Jacobian row (NLOC)
    real(wp), intent(inout) :: gam        !! row of gamma
    phi = a%v; jl = a%d; gam = -a%ar
  end subroutine put_scal_k

end module mbd_points
