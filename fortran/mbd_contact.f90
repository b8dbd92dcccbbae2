!> mbd_contact: penalty contact between body surfaces, its normal-force laws, regularized
!! Coulomb friction, and the friction of revolute and translational joints.
!!
!! A contact measures the penetration delta(q) >= 0 of two surfaces (a kscal: value,
!! gradient, rate) and applies the normal force Fn(delta, delta_dot) >= 0 as the generalized
!! force Q = -Fn d(delta)/dq (so the elastic part derives from V(delta) and its power is
!! -Fn delta_dot), and a friction force Ft t at the contact point X, Ft = -mu(v_t) Fn, with
!! t = perp(n), v_t = (v_i(X) - v_j(X)) . t the sliding speed, n the direction of the
!! normal force on body i:  Q_b = +-Ft [t, (X - r_b) x t].
!! Geometries (body i first):
!!   circle-line       circle (c', R) on i, line (p', n') on j, solid opposite n':
!!                     delta = R - n . (C - P)
!!   circle-circle     outer surfaces: delta = R_i + R_j - |C_i - C_j|
!!   circle-in-circle  pin (R_i) on i in a hole (R_j > R_i) on j: delta = |C_i - C_j| -
!!                     (R_j - R_i) (the revolute joint with clearance)
!!   follower-profile  cam profile c(alpha) on i, follower on j (point, roller of radius rho,
!!                     flat face through f' with normal m' toward the cam): delta = rho -
!!                     (F - C(a*)) . N(a*) at the profile point nearest the follower point, or
!!                     -m . (C(a*) - P) at the profile point deepest into the face; a* is a
!!                     stationary point, so the gradient is taken at fixed a* (envelope).
!! Laws (delta > 0; Fn = 0 otherwise; the force is clamped at 0: no adhesion):
!!   linear              Fn = k delta + c delta_dot, c = 2 zeta sqrt(k m_eff), zeta such
!!                       that the clamped spring-dashpot rebounds with e exactly (docs)
!!   hertz               Fn = k delta**n                         (elastic, e = 1)
!!   hunt-crossley       Fn = k delta**n (1 + 3 (1 - e) / 2 delta_dot / v0)
!!                       (Hunt & Crossley 1975)
!!   lankarani-nikravesh Fn = k delta**n (1 + 3 (1 - e**2) / 4 delta_dot / v0)
!!                       (Lankarani & Nikravesh 1990)
!!   flores              Fn = k delta**n (1 + 8 (1 - e) / (5 e) delta_dot / v0)
!!                       (Flores, Machado, Silva & Martins 2011)
!!   v0: the penetration rate at the onset of the contact (its state, set by the event
!!   location of the integrators; max(|delta_dot|, V0_MIN) where no mode is tracked).
!! Regularized Coulomb (mu, mu_s, threshold v_e, an Adams-like C1 curve):
!!   |v| <= v_e: mu(v) = mu_s (3 a - a**3) / 2, a = v / v_e;  v_e < |v| < 2 v_e: mu_s blends
!!   to mu (smoothstep);  |v| >= 2 v_e: mu sign(v).
!! Joint friction: a force along the slip coordinate u (translational: the slide s; revolute:
!! rho_pin (theta_j - theta_i), the pin surface), Q = F du/dq, F = -mu N sign(u_dot), with
!! the normal load N from the joint's multipliers: |lambda_normal| (translational),
!! |(lambda_x, lambda_y)| (revolute, the friction circle). Modes: regularized, sliding with a
!! fixed sign (exact Coulomb), or stuck (no force here: a lock row u_ddot = 0 instead).
!! Raw parameters (force table, mbd_forces): contacts [law, k, n, e, mu, mu_s, v_e, geometry]
!!   circle-line [cx, cy, R, px, py, nx, ny]; circle-circle and circle-in-circle
!!   [c1x, c1y, R1, c2x, c2y, R2]; follower-profile [follower kind, f(4), profile kind,
!!   profile raw...] (the cam joint's follower and profile forms);
!!   joint friction [mu, mu_s, model (0 regularized, 1 stick-slip), v_e, rho_pin].
!! Prepared contacts: [law, k, n, e, mu, mu_s, v_e, damping, geometry prepared].
module mbd_contact
  use mbd_kinds, only: wp, zero, one, two, half, pi
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MSG_LEN
  use mbd_points, only: NLOC, kloc, kvec, kscal, body_point, body_vector, curve_point, &
                        curve_vector, body_angle, vsub, vdot, ssub, ssqrt, sconst, sscale, perp
  use mbd_profiles, only: profile_raw_length, profile_prepare, profile_eval, profile_normal, &
                          profile_exponents, profile_check
  implicit none
  private
  public :: GEO_CIRCLE_LINE, GEO_CIRCLE_CIRCLE, GEO_CIRCLE_IN_CIRCLE, GEO_FOLLOWER_PROFILE
  public :: LAW_LINEAR, LAW_HERTZ, LAW_HUNT_CROSSLEY, LAW_LANKARANI, LAW_FLORES
  public :: NCS, NEO, V0_MIN, VTH_DEFAULT, FRIC_STICK_SLIP
  public :: contact_raw_length, contact_prepare, contact_exponents, contact_eval, contact_gap
  public :: contact_damped, friction_raw_length, friction_prepare, friction_exponents
  public :: joint_slip, joint_normal_load, joint_friction_force, reg_mu, linear_zeta
  public :: clamped_restitution

  integer, parameter :: GEO_CIRCLE_LINE = 1, GEO_CIRCLE_CIRCLE = 2, GEO_CIRCLE_IN_CIRCLE = 3
  integer, parameter :: GEO_FOLLOWER_PROFILE = 4
  integer, parameter :: LAW_LINEAR = 1, LAW_HERTZ = 2, LAW_HUNT_CROSSLEY = 3, LAW_LANKARANI = 4
  integer, parameter :: LAW_FLORES = 5
  integer, parameter :: FRIC_STICK_SLIP = 1
  integer, parameter :: NCS = 2      !! state columns of an element: [mode, v0]
  integer, parameter, public :: MODE_UNTRACKED = -1   !! a contact without a tracked mode
  integer, parameter :: NEO = 6      !! output columns of an element (see contact_eval)
  integer, parameter :: NHEAD = 8    !! prepared head [law, k, n, e, mu, mu_s, v_e, damping]
  integer, parameter :: NRAWHEAD = 7 !! raw head
  !> smallest impact speed of the hysteresis laws (L / s; grazing contacts)
  real(wp), parameter :: V0_MIN = 1.0e-3_wp
  !> default friction threshold velocity (L / s: from the model's length scale L)
  real(wp), parameter :: VTH_DEFAULT = 1.0e-4_wp
  integer, parameter :: NSEARCH = 96  !! samples of the profile search
  integer, parameter :: NBOUND = 512  !! samples of the profile's bounding circle

contains

  ! ------------------------------------------------------------------ parameters
  !> Raw length of a contact of geometry geo, or -1 when malformed.
  pure integer function contact_raw_length(geo, raw)
    integer, intent(in) :: geo         !! geometry kind
    real(wp), intent(in) :: raw(:)     !! raw parameters
    integer :: n
    contact_raw_length = -1
    select case (geo)
    case (GEO_CIRCLE_LINE)
      contact_raw_length = NRAWHEAD + 7
    case (GEO_CIRCLE_CIRCLE, GEO_CIRCLE_IN_CIRCLE)
      contact_raw_length = NRAWHEAD + 6
    case (GEO_FOLLOWER_PROFILE)
      if (size(raw) < NRAWHEAD + 7) return
      if (.not. (raw(NRAWHEAD + 6) >= 1 .and. raw(NRAWHEAD + 6) <= 3)) return
      n = profile_raw_length(nint(raw(NRAWHEAD + 6)), raw(NRAWHEAD + 7:))
      if (n > 0) contact_raw_length = NRAWHEAD + 6 + n
    end select
  end function contact_raw_length

  !> Length exponents (mbd_model): a parameter p becomes p L**(ex + fr). Lengths -1; the
  !! stiffness k L**(1 + n) (forces F L, penetrations delta / L); the threshold velocity -1.
  pure subroutine contact_exponents(geo, raw, ex, fr)
    integer, intent(in) :: geo         !! geometry kind
    real(wp), intent(in) :: raw(:)     !! raw parameters (well formed)
    integer, intent(out) :: ex(:)      !! integer exponents
    real(wp), intent(out) :: fr(:)     !! fractional exponents added to ex
    ex = 0; fr = zero
    ex(2) = 1; fr(2) = raw(3)                       ! k: L**(1 + n)
    if (nint(raw(1)) == LAW_LINEAR) fr(2) = one     ! linear: n = 1
    ex(7) = -1                                      ! threshold velocity
    select case (geo)
    case (GEO_CIRCLE_LINE)
      ex(NRAWHEAD + 1:NRAWHEAD + 5) = -1            ! circle and line point (normal: 0)
    case (GEO_CIRCLE_CIRCLE, GEO_CIRCLE_IN_CIRCLE)
      ex(NRAWHEAD + 1:NRAWHEAD + 6) = -1
    case (GEO_FOLLOWER_PROFILE)
      ex(NRAWHEAD + 2:NRAWHEAD + 3) = -1            ! follower point
      if (nint(raw(NRAWHEAD + 1)) == 2) ex(NRAWHEAD + 4) = -1   ! roller radius
      call profile_exponents(nint(raw(NRAWHEAD + 6)), raw(NRAWHEAD + 7:), ex(NRAWHEAD + 7:))
    end select
  end subroutine contact_exponents

  !> Check and prepare a contact (raw parameters in the core's units); meff: the effective
  !! mass of the pair (linear law).
  subroutine contact_prepare(geo, raw, meff, prep, status, msg)
    integer, intent(in) :: geo                     !! geometry kind
    real(wp), intent(in) :: raw(:)                 !! raw parameters (exact length)
    real(wp), intent(in) :: meff                   !! effective mass m_i m_j / (m_i + m_j)
    real(wp), allocatable, intent(out) :: prep(:)  !! prepared parameters
    integer, intent(out) :: status                 !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    real(wp) :: head(NHEAD), nn
    real(wp), allocatable :: geom(:)
    integer :: law
    status = MBD_BAD_PARAM; msg = ''
    law = nint(raw(1))
    head(1:NRAWHEAD) = raw(1:NRAWHEAD)
    if (law < LAW_LINEAR .or. law > LAW_FLORES) then
      msg = 'unknown contact law'; return
    end if
    if (law == LAW_LINEAR) head(3) = one
    if (.not. (head(2) > zero)) then
      msg = 'contact stiffness must be positive'; return
    end if
    if (.not. (head(3) >= one .and. head(3) <= 3.0_wp)) then
      msg = 'contact exponent must be from 1 to 3'; return
    end if
    if (.not. (head(4) > zero .and. head(4) <= one)) then
      msg = 'restitution must be in (0, 1]'; return
    end if
    if (law == LAW_HERTZ .and. head(4) < one) then
      msg = 'the hertz law is elastic (restitution 1); for e < 1 use hunt-crossley, '// &
            'lankarani-nikravesh, flores or linear'
      return
    end if
    if (.not. (head(5) >= zero .and. head(6) >= zero)) then
      msg = 'friction coefficients must be >= 0'; return
    end if
    if (.not. (head(7) >= zero)) then
      msg = 'friction threshold velocity must be >= 0'; return
    end if
    if (.not. (head(7) > zero)) head(7) = VTH_DEFAULT
    select case (law)
    case (LAW_LINEAR)
      head(8) = zero
      if (head(4) < one) then
        if (.not. (meff > zero)) then
          msg = 'the linear law with restitution < 1 needs masses on the contacting bodies'
          return
        end if
        head(8) = two * linear_zeta(head(4)) * sqrt(head(2) * meff)
      end if
    case (LAW_HERTZ)
      head(8) = zero
    case (LAW_HUNT_CROSSLEY)
      head(8) = 1.5_wp * (one - head(4))
    case (LAW_LANKARANI)
      head(8) = 0.75_wp * (one - head(4)**2)
    case (LAW_FLORES)
      head(8) = 1.6_wp * (one - head(4)) / head(4)
    end select
    associate (g => raw(NRAWHEAD + 1:))
      select case (geo)
      case (GEO_CIRCLE_LINE)
        nn = hypot(g(6), g(7))
        if (.not. (g(3) > zero)) then
          msg = 'circle radius must be positive'; return
        end if
        if (.not. (nn > zero)) then
          msg = 'line normal has zero length'; return
        end if
        geom = [g(1:5), g(6:7) / nn]
      case (GEO_CIRCLE_CIRCLE)
        if (.not. (g(3) > zero .and. g(6) > zero)) then
          msg = 'circle radii must be positive'; return
        end if
        geom = g(1:6)
      case (GEO_CIRCLE_IN_CIRCLE)
        if (.not. (g(3) > zero .and. g(6) > g(3))) then
          msg = 'the pin radius must be positive and smaller than the hole radius'; return
        end if
        geom = g(1:6)
      case (GEO_FOLLOWER_PROFILE)
        call profile_geometry(g, geom, status, msg)
        if (status /= MBD_OK) return
        status = MBD_BAD_PARAM
      case default
        msg = 'unknown contact geometry'; return
      end select
    end associate
    prep = [head, geom]
    status = MBD_OK
  end subroutine contact_prepare

  !> Follower-profile geometry: [fol, f(4), prof, centre(2), r_bound, profile prepared...].
  subroutine profile_geometry(g, geom, status, msg)
    real(wp), intent(in) :: g(:)
    real(wp), allocatable, intent(out) :: geom(:)
    integer, intent(out) :: status
    character(len=MSG_LEN), intent(out) :: msg
    real(wp), allocatable :: pp(:)
    real(wp) :: f(4), nm, c0(2), c1(2), c2(2), c3(2), cen(2), rb, pts(2, NBOUND)
    integer :: fol, prof, k
    status = MBD_BAD_PARAM; msg = ''
    fol = nint(g(1)); prof = nint(g(6)); f = g(2:5)
    select case (fol)
    case (1)
      f(3:4) = zero
    case (2)
      if (.not. (f(3) > zero)) then
        msg = 'roller follower radius must be positive'; return
      end if
      f(4) = zero
    case (3)
      nm = hypot(f(3), f(4))
      if (.not. (nm > zero)) then
        msg = 'flat follower normal has zero length'; return
      end if
      f(3:4) = f(3:4) / nm
    case default
      msg = 'unknown follower kind'; return
    end select
    call profile_prepare(prof, g(7:), pp, status, msg)
    if (status /= MBD_OK) return
    call profile_check(prof, pp, zero, status, msg)
    if (status /= MBD_OK) return
    do k = 1, NBOUND
      call profile_eval(prof, pp, two * pi * (k - 1) / NBOUND, c0, c1, c2, c3)
      pts(:, k) = c0
    end do
    cen = [sum(pts(1, :)), sum(pts(2, :))] / NBOUND
    rb = zero
    do k = 1, NBOUND
      rb = max(rb, hypot(pts(1, k) - cen(1), pts(2, k) - cen(2)))
    end do
    rb = 1.05_wp * rb                ! sampled maximum, with a margin for the chords
    geom = [real(fol, wp), f, real(prof, wp), cen, rb, pp]
    status = MBD_OK
  end subroutine profile_geometry

  !> The effective restitution of the clamped linear spring-dashpot (Fn = max(0, k delta +
  !! c delta_dot)) at damping ratio zeta: the free motion delta = v/wd e^(-zeta w t) sin(wd t)
  !! loses its force when tan(wd t) = -2 zeta s / (1 - 2 zeta**2), s = sqrt(1 - zeta**2),
  !! and then leaves with the speed it has there (overdamped: the same with real roots).
  pure real(wp) function clamped_restitution(zeta) result(e)
    real(wp), intent(in) :: zeta          !! damping ratio c / (2 sqrt(k m))
    real(wp) :: s, tau, z, r, r1, r2, t
    z = zeta
    if (abs(z - one) < 1.0e-6_wp) z = one - 1.0e-6_wp
    if (z < one) then
      s = sqrt(one - z * z)
      tau = atan2(-two * z * s, one - two * z * z) + pi
      e = exp(-z * tau / s) * abs(cos(tau) - z / s * sin(tau))
    else
      r = sqrt(z * z - one); r1 = -z + r; r2 = -z - r       ! omega = 1
      t = log((one + two * z * r2) / (one + two * z * r1)) / (r1 - r2)
      e = abs((r1 * exp(r1 * t) - r2 * exp(r2 * t)) / (r1 - r2))
    end if
  end function clamped_restitution

  !> The damping ratio at which the clamped linear law rebounds with e (bisection on the
  !! monotone clamped_restitution, in log(zeta)).
  pure real(wp) function linear_zeta(e) result(z)
    real(wp), intent(in) :: e             !! restitution in (0, 1]
    real(wp) :: lo, hi, mid
    integer :: it
    z = zero
    if (e >= one) return
    lo = -12.0_wp; hi = 8.0_wp            ! log10(zeta)
    do it = 1, 200
      mid = half * (lo + hi)
      if (clamped_restitution(10.0_wp**mid) > e) then
        lo = mid
      else
        hi = mid
      end if
      if (hi - lo < 1.0e-14_wp) exit
    end do
    z = 10.0_wp**(half * (lo + hi))
  end function linear_zeta

  !> Joint friction raw length (always 5).
  pure integer function friction_raw_length()
    friction_raw_length = 5
  end function friction_raw_length

  !> Joint friction exponents: threshold velocity and pin radius are lengths.
  pure subroutine friction_exponents(ex)
    integer, intent(out) :: ex(:)   !! exponents (5)
    ex = 0; ex(4) = -1; ex(5) = -1
  end subroutine friction_exponents

  !> Check joint friction [mu, mu_s, model, v_e, rho_pin] for a joint of kind ckind
  !! (revolute: rho_pin > 0).
  subroutine friction_prepare(revolute, raw, prep, status, msg)
    logical, intent(in) :: revolute                !! the joint is a revolute
    real(wp), intent(in) :: raw(:)                 !! raw parameters (5)
    real(wp), allocatable, intent(out) :: prep(:)  !! prepared
    integer, intent(out) :: status                 !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    status = MBD_BAD_PARAM; msg = ''
    if (.not. (raw(1) >= zero .and. raw(2) >= zero)) then
      msg = 'friction coefficients must be >= 0'; return
    end if
    if (.not. (nint(raw(3)) == 0 .or. nint(raw(3)) == FRIC_STICK_SLIP)) then
      msg = 'friction model must be regularized or stick-slip'; return
    end if
    if (.not. (raw(4) >= zero)) then
      msg = 'friction threshold velocity must be >= 0'; return
    end if
    if (revolute .and. .not. (raw(5) > zero)) then
      msg = 'revolute friction needs a pin radius > 0 (pin_radius)'; return
    end if
    prep = raw(1:5)
    if (.not. (prep(4) > zero)) prep(4) = VTH_DEFAULT
    status = MBD_OK
  end subroutine friction_prepare

  !> Whether a contact's force depends on velocities (damping or friction).
  pure logical function contact_damped(p)
    real(wp), intent(in) :: p(:)      !! prepared parameters
    contact_damped = abs(p(8)) > zero .or. p(5) > zero .or. p(6) > zero
  end function contact_damped

  ! ------------------------------------------------------------------ friction curve
  !> Regularized Coulomb coefficient (with sign) at sliding speed v: mu_s ramps in with
  !! (3a - a**3)/2 up to v_e, blends to mu by 2 v_e (C1 throughout).
  pure real(wp) function reg_mu(v, mu, mus, ve) result(f)
    real(wp), intent(in) :: v, mu, mus, ve   !! speed, coefficients, threshold
    real(wp) :: a, s
    a = abs(v) / ve
    if (a >= two) then
      f = mu
    else if (a >= one) then
      s = a - one
      f = mus + (mu - mus) * s * s * (3.0_wp - two * s)
    else
      f = mus * half * a * (3.0_wp - a * a)
    end if
    f = sign(f, v)
  end function reg_mu

  ! ------------------------------------------------------------------ contact geometry
  !> Penetration delta (kscal: value, gradient, rate), the unit direction n of the normal
  !! force on body i, the contact point X (global) and far (the bounding test: no contact
  !! possible, delta%v is then only a negative bound).
  pure subroutine geometry(geo, p, si, sj, x, dl, n, xp, far, exact)
    integer, intent(in) :: geo, si, sj
    real(wp), intent(in) :: p(:)
    type(kloc), intent(in) :: x
    type(kscal), intent(out) :: dl
    real(wp), intent(out) :: n(2), xp(2)
    logical, intent(out) :: far
    logical, intent(in), optional :: exact     ! no bounding test: the gap itself
    type(kvec) :: ci, cj, d, nv
    real(wp) :: dd, r1, r2, u(2)
    far = .false.; n = [one, zero]; xp = zero
    associate (g => p(NHEAD + 1:))
      select case (geo)
      case (GEO_CIRCLE_LINE)
        ci = body_point(x, si, g(1:2))
        cj = body_point(x, sj, g(4:5))
        nv = body_vector(x, sj, g(6:7))
        dl = ssub(sconst(g(3)), vdot(nv, vsub(ci, cj)))     ! R - n . (C - P)
        n = nv%v
        xp = ci%v - (g(3) - half * dl%v) * n
      case (GEO_CIRCLE_CIRCLE, GEO_CIRCLE_IN_CIRCLE)
        ci = body_point(x, si, g(1:2))
        cj = body_point(x, sj, g(4:5))
        d = vsub(ci, cj)
        dd = hypot(d%v(1), d%v(2))
        r1 = g(3); r2 = g(6)
        if (geo == GEO_CIRCLE_CIRCLE) then
          if (dd > 1.0e-12_wp * (r1 + r2)) then
            dl = ssub(sconst(r1 + r2), ssqrt(vdot(d, d)))
            u = d%v / dd
          else
            dl = sconst(r1 + r2); u = [one, zero]; far = .true.   ! concentric: no normal
          end if
          n = u
          xp = cj%v + (r2 - half * dl%v) * u
        else
          if (dd <= half * (r2 - r1)) then
            dl = sconst(dd - (r2 - r1)); far = .true.          ! well inside the clearance
            if (dd > zero) dl%vd = dot_product(d%v, d%vd) / dd  ! (its rate, for the events)
            return
          end if
          dl = ssub(ssqrt(vdot(d, d)), sconst(r2 - r1))
          u = d%v / dd
          n = -u
          xp = cj%v + (r2 + half * dl%v) * u
        end if
      case (GEO_FOLLOWER_PROFILE)
        call follower_profile(g, si, sj, x, dl, n, xp, far, exact)
      end select
    end associate
  end subroutine geometry

  !> The follower-profile penetration (see the banner); g = the geometry part.
  pure subroutine follower_profile(g, si, sj, x, dl, n, xp, far, exact)
    real(wp), intent(in) :: g(:)
    integer, intent(in) :: si, sj
    type(kloc), intent(in) :: x
    type(kscal), intent(out) :: dl
    real(wp), intent(out) :: n(2), xp(2)
    logical, intent(out) :: far
    logical, intent(in), optional :: exact
    type(kvec) :: fp, cp, nv, mv
    real(wp) :: fc(2), mc(2), ri(2), ca, sa, a, c0(2), c1(2), c2(2), c3(2), n0(2), n1(2), n2(2)
    real(wp) :: rho, gap
    integer :: fol, prof
    fol = nint(g(1)); prof = nint(g(6)); rho = g(4)
    far = .false.; n = [one, zero]; xp = zero
    associate (cen => g(7:8), rb => g(9), pp => g(10:))
      ! the follower point (and face normal) in the cam's frame
      fp = body_point(x, sj, g(2:3))
      mv = body_vector(x, sj, g(4:5))
      if (si > 0) then
        ca = x%c(si); sa = x%s(si); ri = x%q(3 * si - 2:3 * si - 1)
      else
        ca = one; sa = zero; ri = zero
      end if
      fc = [ca * (fp%v(1) - ri(1)) + sa * (fp%v(2) - ri(2)), &
            -sa * (fp%v(1) - ri(1)) + ca * (fp%v(2) - ri(2))]
      mc = [ca * mv%v(1) + sa * mv%v(2), -sa * mv%v(1) + ca * mv%v(2)]
      ! bounding circle of the profile first
      if (fol == 3) then
        gap = dot_product(mc, cen - fc) - rb
      else
        gap = hypot(fc(1) - cen(1), fc(2) - cen(2)) - rb - merge(rho, zero, fol == 2)
      end if
      if (gap > zero) then
        far = .true.; dl = sconst(-gap)
        if (.not. present(exact)) return
        if (.not. exact) return
      end if
      a = nearest_alpha(prof, pp, fol, fc, mc)
      call profile_eval(prof, pp, a, c0, c1, c2, c3)
      cp = curve_point(x, si, 0, c0, c1, c2)          ! at fixed alpha (envelope theorem)
      if (fol == 3) then
        dl = sscale(-one, vdot(mv, vsub(cp, body_point(x, sj, g(2:3)))))
        n = mv%v
        xp = cp%v + half * dl%v * n
      else
        call profile_normal(c1, c2, c3, n0, n1, n2)
        nv = curve_vector(x, si, 0, n0, n1, n2)
        dl = ssub(sconst(merge(rho, zero, fol == 2)), vdot(vsub(fp, cp), nv))
        n = -nv%v
        xp = cp%v - half * dl%v * nv%v
      end if
    end associate
  end subroutine follower_profile

  !> The profile parameter nearest the follower point fc (or deepest along -mc for a flat
  !! face): the best of NSEARCH samples, then Newton on the stationarity condition.
  pure real(wp) function nearest_alpha(prof, pp, fol, fc, mc) result(a)
    integer, intent(in) :: prof, fol
    real(wp), intent(in) :: pp(:), fc(2), mc(2)
    real(wp) :: b, best, val, c0(2), c1(2), c2(2), c3(2), gr, hs, da
    integer :: k
    a = zero; best = huge(one)
    do k = 0, NSEARCH - 1
      b = two * pi * k / NSEARCH
      call profile_eval(prof, pp, b, c0, c1, c2, c3)
      if (fol == 3) then
        val = dot_product(mc, c0)
      else
        val = sum((fc - c0)**2)
      end if
      if (val < best) then
        best = val; a = b
      end if
    end do
    do k = 1, 12
      call profile_eval(prof, pp, a, c0, c1, c2, c3)
      if (fol == 3) then
        gr = dot_product(mc, c1); hs = dot_product(mc, c2)
      else
        gr = -dot_product(fc - c0, c1); hs = dot_product(c1, c1) - dot_product(fc - c0, c2)
      end if
      if (.not. (hs > zero)) exit
      da = -gr / hs
      da = max(-pi / NSEARCH, min(pi / NSEARCH, da))
      a = a + da
      if (abs(da) < 1.0e-14_wp) exit
    end do
  end function nearest_alpha

  !> The penetration of a circle contact from the positions alone (no derivatives): the
  !! cheap first test of contact_eval.
  pure real(wp) function plain_penetration(geo, p, si, sj, x) result(d)
    integer, intent(in) :: geo, si, sj
    real(wp), intent(in) :: p(:)
    type(kloc), intent(in) :: x
    real(wp) :: dr
    call plain_gap(geo, p, si, sj, x, d, dr)
  end function plain_penetration

  !> Penetration and its rate of a circle contact from positions and velocities (no
  !! Jacobians): circle-line d = R - n . (C - P), d_dot = -n_dot . (C - P) - n . (C - P)_dot;
  !! circle pairs from e = C_i - C_j, |e|_dot = e . e_dot / |e|.
  pure subroutine plain_gap(geo, p, si, sj, x, d, dr)
    integer, intent(in) :: geo, si, sj
    real(wp), intent(in) :: p(:)
    type(kloc), intent(in) :: x
    real(wp), intent(out) :: d, dr
    real(wp) :: ci(2), cj(2), vi(2), vj(2), nv(2), nd(2), e(2), ed(2), le
    associate (g => p(NHEAD + 1:))
      call place(si, g(1:2), ci, vi)
      call place(sj, g(4:5), cj, vj)
      e = ci - cj; ed = vi - vj
      select case (geo)
      case (GEO_CIRCLE_LINE)
        call place(sj, g(6:7), nv, nd, direction=.true.)
        d = g(3) - dot_product(nv, e)
        dr = -dot_product(nd, e) - dot_product(nv, ed)
      case (GEO_CIRCLE_CIRCLE)
        le = hypot(e(1), e(2))
        d = g(3) + g(6) - le
        dr = zero
        if (le > zero) dr = -dot_product(e, ed) / le
      case default
        le = hypot(e(1), e(2))
        d = le - (g(6) - g(3))
        dr = zero
        if (le > zero) dr = dot_product(e, ed) / le
      end select
    end associate
  contains
    !> A body point (or direction) u and its velocity.
    pure subroutine place(slot, u, w, wd, direction)
      integer, intent(in) :: slot
      real(wp), intent(in) :: u(2)
      real(wp), intent(out) :: w(2), wd(2)
      logical, intent(in), optional :: direction
      w = u; wd = zero
      if (slot == 0) return
      w = [x%c(slot) * u(1) - x%s(slot) * u(2), x%s(slot) * u(1) + x%c(slot) * u(2)]
      wd = perp(w) * x%qd(3 * slot)
      if (present(direction)) return
      w = w + x%q(3 * slot - 2:3 * slot - 1)
      wd = wd + x%qd(3 * slot - 2:3 * slot - 1)
    end subroutine place
  end subroutine plain_gap

  !> The penetration of a contact and its rate (for event location): far contacts return a
  !! negative bound (and its rate where known, else 0).
  pure subroutine contact_gap(geo, p, si, sj, x, dv, dr)
    integer, intent(in) :: geo                !! geometry kind
    real(wp), intent(in) :: p(:)              !! prepared parameters
    integer, intent(in) :: si, sj             !! slot ids
    type(kloc), intent(in) :: x               !! local state
    real(wp), intent(out) :: dv, dr           !! penetration and its rate
    type(kscal) :: dl
    real(wp) :: n(2), xp(2)
    logical :: far
    if (geo /= GEO_FOLLOWER_PROFILE) then
      call plain_gap(geo, p, si, sj, x, dv, dr)
      return
    end if
    call geometry(geo, p, si, sj, x, dl, n, xp, far)
    dv = dl%v; dr = dl%vd
  end subroutine contact_gap

  !! Generalized force, potential energy and outputs of a contact at a local state.
  !! st = [mode, v0]: mode 1 closed (v0 its impact speed); 0 open (the integrators track the
  !! modes: no force until the onset is located and the mode changed, so that the forces
  !! are smooth within a step); -1 untracked (statics: a force wherever delta > 0, with
  !! v0 = max(|delta_dot|, V0_MIN)). out = [Fn, Ft, delta, v_t, X(2)].
  pure subroutine contact_eval(geo, p, si, sj, x, st, ql_force, v, out, exact)
    integer, intent(in) :: geo                !! geometry kind
    real(wp), intent(in) :: p(:)              !! prepared parameters
    integer, intent(in) :: si, sj             !! slot ids
    type(kloc), intent(in) :: x               !! local state
    real(wp), intent(in) :: st(NCS)           !! contact state
    real(wp), intent(out) :: ql_force(NLOC)   !! generalized force on the local slots
    real(wp), intent(out) :: v                !! potential energy
    real(wp), intent(out) :: out(NEO)         !! outputs
    logical, intent(in), optional :: exact    !! the gap itself even when far (outputs)
    type(kscal) :: dl
    real(wp) :: n(2), xp(2), t(2), vrel(2), vt, fn, ft, v0, fe, dd, kk, ex
    logical :: far
    integer :: law
    ql_force = zero; v = zero; out = zero
    if (geo /= GEO_FOLLOWER_PROFILE) then
      ! the bounding test: the gap from the plain positions, before any derivative
      out(3) = plain_penetration(geo, p, si, sj, x)
      if (.not. (out(3) > zero)) return
    end if
    call geometry(geo, p, si, sj, x, dl, n, xp, far, exact)
    out(3) = dl%v
    if (far .or. .not. (dl%v > zero)) return
    if (nint(st(1)) == 0) return             ! open (tracked): no force until the onset
    out(5:6) = xp
    law = nint(p(1)); kk = p(2); ex = p(3); dd = dl%v
    ! normal force
    if (law == LAW_LINEAR) then
      fe = kk * dd
      fn = fe + p(8) * dl%vd
      v = half * kk * dd * dd
    else
      fe = kk * dd**ex
      fn = fe
      if (law /= LAW_HERTZ) then
        if (nint(st(1)) == 1) then
          v0 = max(st(2), V0_MIN)
        else
          v0 = max(abs(dl%vd), V0_MIN)
        end if
        fn = fe * (one + p(8) * dl%vd / v0)
      end if
      v = kk * dd**(ex + one) / (ex + one)
    end if
    fn = max(fn, zero)
    ql_force = -fn * dl%d
    out(1) = fn
    ! friction at the contact point
    t = perp(n)
    vrel = point_velocity(x, si, xp) - point_velocity(x, sj, xp)
    vt = dot_product(vrel, t)
    out(4) = vt
    if (.not. (p(5) > zero .or. p(6) > zero) .or. .not. (fn > zero)) return
    ft = -reg_mu(vt, p(5), p(6), p(7)) * fn
    out(2) = ft
    call add_point_force(x, si, xp, ft * t, ql_force)
    call add_point_force(x, sj, xp, -ft * t, ql_force)
  end subroutine contact_eval

  !> Velocity of the material point of body slot (0 ground) at the global point xp.
  pure function point_velocity(x, slot, xp) result(vp)
    type(kloc), intent(in) :: x
    integer, intent(in) :: slot
    real(wp), intent(in) :: xp(2)
    real(wp) :: vp(2)
    integer :: c
    vp = zero
    if (slot == 0) return
    c = 3 * (slot - 1)
    vp = x%qd(c + 1:c + 2) + perp(xp - x%q(c + 1:c + 2)) * x%qd(c + 3)
  end function point_velocity

  !> Add the generalized force of a force f at the global point xp on body slot.
  pure subroutine add_point_force(x, slot, xp, f, ql)
    type(kloc), intent(in) :: x
    integer, intent(in) :: slot
    real(wp), intent(in) :: xp(2), f(2)
    real(wp), intent(inout) :: ql(NLOC)
    integer :: c
    if (slot == 0) return
    c = 3 * (slot - 1)
    ql(c + 1:c + 2) = ql(c + 1:c + 2) + f
    ql(c + 3) = ql(c + 3) + dot_product(perp(xp - x%q(c + 1:c + 2)), f)
  end subroutine add_point_force

  ! ------------------------------------------------------------------ joint friction
  !> The slip coordinate u of a joint (value irrelevant; gradient, rate and acceleration
  !! remainder): translational the slide (P_j - P_i) . A_i u'_i, revolute
  !! rho_pin (theta_j - theta_i). cp: the joint's prepared parameters.
  pure function joint_slip(revolute, cp, rpin, si, sj, x) result(u)
    logical, intent(in) :: revolute           !! revolute (else translational)
    real(wp), intent(in) :: cp(:)             !! the joint's prepared parameters
    real(wp), intent(in) :: rpin              !! pin radius (revolute)
    integer, intent(in) :: si, sj             !! slot ids
    type(kloc), intent(in) :: x               !! local state
    type(kscal) :: u
    if (revolute) then
      u = sscale(rpin, ssub(body_angle(x, sj), body_angle(x, si)))
    else
      u = vdot(body_vector(x, si, cp(5:6)), &
               vsub(body_point(x, sj, cp(3:4)), body_point(x, si, cp(1:2))))
    end if
  end function joint_slip

  !> Normal load of a joint from its multipliers: revolute |(l1, l2)| (friction circle),
  !! translational |l1| (the normal row).
  pure real(wp) function joint_normal_load(revolute, lam) result(fn)
    logical, intent(in) :: revolute           !! revolute (else translational)
    real(wp), intent(in) :: lam(:)            !! the joint's multipliers
    if (revolute) then
      fn = hypot(lam(1), lam(2))
    else
      fn = abs(lam(1))
    end if
  end function joint_normal_load

  !> Friction force along the slip coordinate: regularized (mode 0) or exact Coulomb with a
  !! fixed direction (mode +-1: sliding with sign(u_dot) = mode); fp = [mu, mu_s, model, v_e].
  pure real(wp) function joint_friction_force(fp, mode, ud, fn) result(f)
    real(wp), intent(in) :: fp(:)             !! prepared friction parameters
    integer, intent(in) :: mode               !! 0, +1 or -1
    real(wp), intent(in) :: ud                !! slip rate u_dot
    real(wp), intent(in) :: fn                !! normal load
    if (mode == 0) then
      f = -reg_mu(ud, fp(1), fp(2), fp(4)) * fn
    else
      f = -fp(1) * fn * mode
    end if
  end function joint_friction_force

end module mbd_contact
