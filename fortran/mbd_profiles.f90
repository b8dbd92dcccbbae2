!> mbd_profiles: closed smooth curves c(alpha) in a body frame, for cams and curved slots.
!!
!! Each profile returns c, c' = dc/dalpha, c'' and c''' at a parameter alpha (period 2 pi),
!! and the unit outward normal n = perp_-(c')/|c'| with n' and n'' (for roller offsets).
!! Kinds (raw parameters as packed by the front end):
!!   1 circle   [cx, cy, R]                    c = c0 + R (cos a, sin a)
!!   2 spline   [n, x1, y1, ..., xn, yn]       periodic cubic spline, chord-length parameter
!!                                             scaled to [0, 2 pi)
!!   3 fourier  [cx, cy, K, a0, a1, b1, ..., aK, bK]
!!              polar r(a) = a0 + sum a_k cos(k a) + b_k sin(k a),  c = c0 + r (cos a, sin a)
!! Curves run counterclockwise (a clockwise spline is reversed when prepared), so the outward
!! normal is c' turned by -90 degrees.
module mbd_profiles
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use mbd_kinds, only: wp, zero, one, two, half, pi
  use mbd_lapack, only: dgtsv
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MBD_LAPACK, MBD_NO_MEMORY, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_fail
  implicit none
  private
  public :: PROF_CIRCLE, PROF_SPLINE, PROF_FOURIER
  public :: profile_raw_length, profile_prepare, profile_eval, profile_normal, profile_check
  public :: profile_exponents
  public :: profile_c4, profile_normal3, profile_eval_d, profile_normal_d, profile_prepare_d, &
            profile_is_count

  integer, parameter :: PROF_CIRCLE = 1, PROF_SPLINE = 2, PROF_FOURIER = 3
  integer, parameter :: NCHECK = 512   !! samples for the validity checks

contains

  !> Number of raw parameters of a profile whose data start at p(1); -1 if malformed.
  pure integer function profile_raw_length(kind, p)
    integer, intent(in) :: kind     !! profile kind
    real(wp), intent(in) :: p(:)    !! raw parameters (and possibly more after them)
    integer :: n
    profile_raw_length = -1
    select case (kind)
    case (PROF_CIRCLE)
      if (size(p) >= 3) profile_raw_length = 3
    case (PROF_SPLINE)
      if (size(p) < 1) return
      if (.not. (p(1) >= 3 .and. p(1) < 1.0e6_wp)) return
      n = nint(p(1))
      if (size(p) >= 1 + 2 * n) profile_raw_length = 1 + 2 * n
    case (PROF_FOURIER)
      if (size(p) < 3) return
      if (.not. (p(3) >= 0 .and. p(3) < 1.0e5_wp)) return
      n = nint(p(3))
      if (size(p) >= 4 + 2 * n) profile_raw_length = 4 + 2 * n
    end select
  end function profile_raw_length

  !> Length exponents of the raw parameters (-1: a length; 0: a count). alpha is an angle in
  !! every kind, so a profile scales with its parameters.
  pure subroutine profile_exponents(kind, p, ex)
    integer, intent(in) :: kind     !! profile kind
    real(wp), intent(in) :: p(:)    !! raw parameters (well formed, exact length)
    integer, intent(out) :: ex(:)   !! exponents (size(p))
    ex = -1
    select case (kind)
    case (PROF_SPLINE)
      ex(1) = 0
    case (PROF_FOURIER)
      if (size(p) >= 3) ex(3) = 0
    end select
  end subroutine profile_exponents

  !> Turn raw parameters into the prepared form profile_eval reads.
  !! Circle and Fourier are used as given; a spline gets its periodic cubic coefficients:
  !! prepared = [n, s(1:n+1), x(1:n+1), Mx(1:n+1), y(1:n+1), My(1:n+1)] (s knots in [0, 2 pi]).
  subroutine profile_prepare(kind, raw, prep, status, msg)
    integer, intent(in) :: kind                    !! profile kind
    real(wp), intent(in) :: raw(:)                 !! raw parameters (exact length)
    real(wp), allocatable, intent(out) :: prep(:)  !! prepared parameters
    integer, intent(out) :: status                 !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    integer :: n, i
    real(wp), allocatable :: x(:), y(:), s(:), mx(:), my(:), h(:)
    real(wp) :: area, total
    status = MBD_OK; msg = ''
    select case (kind)
    case (PROF_CIRCLE)
      if (.not. (raw(3) > zero)) then
        status = MBD_BAD_PARAM; msg = 'circle profile radius must be positive'; return
      end if
      prep = raw
    case (PROF_FOURIER)
      prep = raw
    case (PROF_SPLINE)
      n = nint(raw(1))
      allocate (x(n + 1), y(n + 1), s(n + 1), h(n), mx(n + 1), my(n + 1), stat=i)
      if (i /= 0) then
        call mem_fail(REAL_BYTES * 6 * (n + 1), 'the spline profile', 'use fewer spline points', &
                      status, msg)
        return
      end if
      x(1:n) = raw(2:2 * n:2); y(1:n) = raw(3:2 * n + 1:2)
      ! shoelace area: reverse a clockwise loop so the outward normal is perp_-(c')
      area = half * (sum(x(1:n - 1) * y(2:n) - x(2:n) * y(1:n - 1)) + x(n) * y(1) - x(1) * y(n))
      if (area < zero) then
        x(1:n) = x(n:1:-1); y(1:n) = y(n:1:-1)
      end if
      x(n + 1) = x(1); y(n + 1) = y(1)
      do i = 1, n
        h(i) = hypot(x(i + 1) - x(i), y(i + 1) - y(i))
      end do
      if (any(.not. (h > zero))) then
        status = MBD_BAD_PARAM; msg = 'spline profile has two consecutive equal points'; return
      end if
      total = sum(h)
      h = h * (two * pi / total)
      s(1) = zero
      do i = 1, n
        s(i + 1) = s(i) + h(i)
      end do
      s(n + 1) = two * pi
      call periodic_spline(n, h, x, y, mx, my, status, msg)
      if (status /= MBD_OK) return
      prep = [real(n, wp), s, x, mx, y, my]
    case default
      status = MBD_BAD_PARAM; msg = 'unknown profile kind'
    end select
  end subroutine profile_prepare

  !> Second derivatives M of periodic cubic splines through (s, x) and (s, y).
  !! h(i-1) M(i-1) + 2 (h(i-1) + h(i)) M(i) + h(i) M(i+1) = 6 (dx(i)/h(i) - dx(i-1)/h(i-1)),
  !! cyclic; solved by Sherman-Morrison around LAPACK dgtsv (cyclic_solve).
  subroutine periodic_spline(n, h, x, y, mx, my, status, msg)
    integer, intent(in) :: n                     !! number of distinct points
    real(wp), intent(in) :: h(n)                 !! knot spacings
    real(wp), intent(in) :: x(n + 1), y(n + 1)   !! values, x(n+1) = x(1)
    real(wp), intent(out) :: mx(n + 1), my(n + 1) !! second derivatives at the knots
    integer, intent(out) :: status               !! MBD_OK or MBD_LAPACK
    character(len=MSG_LEN), intent(out) :: msg   !! what went wrong
    real(wp) :: b(n, 2)
    integer :: i, im
    do i = 1, n
      im = i - 1; if (im == 0) im = n
      b(i, 1) = 6.0_wp * ((x(i + 1) - x(i)) / h(i) - (x(i) - x(im)) / h(im))
      b(i, 2) = 6.0_wp * ((y(i + 1) - y(i)) / h(i) - (y(i) - y(im)) / h(im))
    end do
    call cyclic_solve(n, h, b, status, msg)
    mx(1:n) = b(:, 1); my(1:n) = b(:, 2)
    mx(n + 1) = mx(1); my(n + 1) = my(1)
  end subroutine periodic_spline

  !> Solve the cyclic tridiagonal system of periodic_spline, A(h) M = b, for two right-hand
  !! sides (b is overwritten by M).
  subroutine cyclic_solve(n, h, b, status, msg)
    integer, intent(in) :: n                     !! size
    real(wp), intent(in) :: h(n)                 !! knot spacings
    real(wp), intent(inout) :: b(n, 2)           !! right-hand sides, then solutions
    integer, intent(out) :: status               !! MBD_OK or MBD_LAPACK
    character(len=MSG_LEN), intent(out) :: msg   !! what went wrong
    real(wp) :: dl(n - 1), d(n), du(n - 1), bz(n, 3), gam, corner, fx, fy
    integer :: i, im, info
    status = MBD_OK; msg = ''
    do i = 1, n
      im = i - 1; if (im == 0) im = n
      d(i) = two * (h(im) + h(i))
    end do
    bz(:, 1:2) = b
    do i = 1, n - 1
      du(i) = h(i); dl(i) = h(i)
    end do
    ! cyclic corners A(1, n) = A(n, 1) = h(n)
    corner = h(n)
    gam = -d(1)
    d(1) = d(1) - gam
    d(n) = d(n) - corner * corner / gam
    bz(:, 3) = zero; bz(1, 3) = gam; bz(n, 3) = corner
    call dgtsv(n, 3, dl, d, du, bz, n, info)
    if (info /= 0) then
      status = MBD_LAPACK; msg = 'spline profile: dgtsv failed (degenerate points)'; return
    end if
    ! x = y - (v.y)/(1 + v.z) z, with v = (1, 0, ..., 0, corner/gam)
    fx = (bz(1, 1) + corner / gam * bz(n, 1)) / (one + bz(1, 3) + corner / gam * bz(n, 3))
    fy = (bz(1, 2) + corner / gam * bz(n, 2)) / (one + bz(1, 3) + corner / gam * bz(n, 3))
    b(:, 1) = bz(:, 1) - fx * bz(:, 3)
    b(:, 2) = bz(:, 2) - fy * bz(:, 3)
  end subroutine cyclic_solve

  !> c(alpha) and its first three derivatives, in the body frame.
  pure subroutine profile_eval(kind, p, alpha, c0, c1, c2, c3)
    integer, intent(in) :: kind      !! profile kind
    real(wp), intent(in) :: p(:)     !! prepared parameters
    real(wp), intent(in) :: alpha    !! curve parameter
    real(wp), intent(out) :: c0(2), c1(2), c2(2), c3(2)  !! c, c', c'', c'''
    real(wp) :: e(2), t(2), r, r1, r2, r3, ca, sa, ck, sk, rk
    integer :: k, nk
    select case (kind)
    case (PROF_CIRCLE)
      ca = cos(alpha); sa = sin(alpha)
      r = p(3)
      c0 = p(1:2) + r * [ca, sa]
      c1 = r * [-sa, ca]
      c2 = -r * [ca, sa]
      c3 = r * [sa, -ca]
    case (PROF_FOURIER)
      nk = nint(p(3))
      r = p(4); r1 = zero; r2 = zero; r3 = zero
      do k = 1, nk
        rk = real(k, wp)                ! (k**3 overflows a default integer past k = 1290)
        ck = cos(rk * alpha); sk = sin(rk * alpha)
        r = r + p(3 + 2 * k) * ck + p(4 + 2 * k) * sk
        r1 = r1 + rk * (-p(3 + 2 * k) * sk + p(4 + 2 * k) * ck)
        r2 = r2 - rk**2 * (p(3 + 2 * k) * ck + p(4 + 2 * k) * sk)
        r3 = r3 + rk**3 * (p(3 + 2 * k) * sk - p(4 + 2 * k) * ck)
      end do
      e = [cos(alpha), sin(alpha)]; t = [-e(2), e(1)]
      ! c = r e;  c' = r' e + r t;  c'' = r'' e + 2 r' t - r e;  c''' = r''' e + 3 r'' t - 3 r' e - r t
      c0 = p(1:2) + r * e
      c1 = r1 * e + r * t
      c2 = r2 * e + two * r1 * t - r * e
      c3 = r3 * e + 3.0_wp * r2 * t - 3.0_wp * r1 * e - r * t
    case (PROF_SPLINE)
      call spline_eval(p, alpha, c0, c1, c2, c3)
    case default
      c0 = zero; c1 = zero; c2 = zero; c3 = zero
    end select
  end subroutine profile_eval

  !> Periodic cubic spline at alpha (any real; wrapped into [0, 2 pi)).
  pure subroutine spline_eval(p, alpha, c0, c1, c2, c3)
    real(wp), intent(in) :: p(:), alpha
    real(wp), intent(out) :: c0(2), c1(2), c2(2), c3(2)
    integer :: n, lo, hi, mid, os, ox, omx, oy, omy
    real(wp) :: a, h, t, ya(2), yb(2), ma(2), mb(2), b(2)
    n = nint(p(1))
    os = 1; ox = os + n + 1; omx = ox + n + 1; oy = omx + n + 1; omy = oy + n + 1
    a = modulo(alpha, two * pi)
    lo = 1; hi = n + 1
    do while (hi - lo > 1)
      mid = (lo + hi) / 2
      if (p(os + mid) <= a) then
        lo = mid
      else
        hi = mid
      end if
    end do
    h = p(os + lo + 1) - p(os + lo)
    t = a - p(os + lo)
    ya = [p(ox + lo), p(oy + lo)]; yb = [p(ox + lo + 1), p(oy + lo + 1)]
    ma = [p(omx + lo), p(omy + lo)]; mb = [p(omx + lo + 1), p(omy + lo + 1)]
    ! S = y_i + b t + M_i t^2/2 + (M_{i+1} - M_i) t^3 / (6 h)
    b = (yb - ya) / h - h * (two * ma + mb) / 6.0_wp
    c0 = ya + t * (b + t * (half * ma + t * (mb - ma) / (6.0_wp * h)))
    c1 = b + t * (ma + t * (mb - ma) / (two * h))
    c2 = ma + t * (mb - ma) / h
    c3 = (mb - ma) / h
  end subroutine spline_eval

  !> Unit outward normal n = (c'_y, -c'_x)/|c'| and its derivatives n', n''.
  !! With g = |c'|, u = c'/g:  g' = c'.c''/g,  u' = (c'' - u g')/g,
  !! g'' = (c''.c'' + c'.c''')/g - g'^2/g,  u'' = (c''' - 2 u' g' - u g'')/g.
  pure subroutine profile_normal(c1, c2, c3, n0, n1, n2)
    real(wp), intent(in) :: c1(2), c2(2), c3(2)   !! c', c'', c'''
    real(wp), intent(out) :: n0(2), n1(2), n2(2)  !! n, n', n''
    real(wp) :: g, g1, g2, u(2), u1(2), u2(2)
    g = hypot(c1(1), c1(2))
    u = c1 / g
    g1 = dot_product(c1, c2) / g
    u1 = (c2 - u * g1) / g
    g2 = (dot_product(c2, c2) + dot_product(c1, c3)) / g - g1**2 / g
    u2 = (c3 - two * u1 * g1 - u * g2) / g
    n0 = [u(2), -u(1)]; n1 = [u1(2), -u1(1)]; n2 = [u2(2), -u2(1)]
  end subroutine profile_normal

  !> Check that a prepared profile is a simple closed curve with a regular parameter.
  !! offset > 0 also checks the roller's offset curve (radius below the smallest
  !! concave curvature radius is required there, so the roller does not undercut).
  subroutine profile_check(kind, p, offset, status, msg)
    integer, intent(in) :: kind                 !! profile kind
    real(wp), intent(in) :: p(:)                !! prepared parameters
    real(wp), intent(in) :: offset              !! roller radius, or zero
    integer, intent(out) :: status              !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    real(wp) :: pts(2, NCHECK), c0(2), c1(2), c2(2), c3(2), n0(2), n1(2), n2(2), a, speed
    real(wp) :: lo(2, NCHECK), hi(2, NCHECK), area, diag
    integer :: i, k, ip, kp
    status = MBD_OK; msg = ''
    if (.not. all(ieee_is_finite(p))) then
      status = MBD_BAD_PARAM; msg = 'profile has a non-finite parameter'; return
    end if
    do i = 1, NCHECK
      a = two * pi * (i - 1) / NCHECK
      call profile_eval(kind, p, a, c0, c1, c2, c3)
      speed = hypot(c1(1), c1(2))
      if (.not. (speed > 1.0e-12_wp * max(one, maxval(abs(c0))))) then
        status = MBD_BAD_PARAM
        msg = 'profile is degenerate (zero tangent) somewhere; for a Fourier profile keep r(alpha) > 0'
        return
      end if
      if (kind == PROF_FOURIER) then
        if (.not. (polar_radius(p, a) > zero)) then
          status = MBD_BAD_PARAM; msg = 'Fourier profile radius r(alpha) must stay positive'; return
        end if
      end if
      if (offset > zero) then
        call profile_normal(c1, c2, c3, n0, n1, n2)
        pts(:, i) = c0 + offset * n0
      else
        pts(:, i) = c0
      end if
    end do
    ! a simple closed curve run counterclockwise encloses a positive area (shoelace)
    area = zero
    do i = 1, NCHECK
      ip = mod(i, NCHECK) + 1
      area = area + half * (pts(1, i) * pts(2, ip) - pts(1, ip) * pts(2, i))
      lo(:, i) = min(pts(:, i), pts(:, ip)); hi(:, i) = max(pts(:, i), pts(:, ip))
    end do
    diag = hypot(maxval(pts(1, :)) - minval(pts(1, :)), maxval(pts(2, :)) - minval(pts(2, :)))
    if (.not. (area > 1.0e-6_wp * diag**2)) then
      status = MBD_BAD_PARAM
      msg = 'profile encloses no area (points on a line, or running back over itself)'
      return
    end if
    do i = 1, NCHECK
      ip = mod(i, NCHECK) + 1
      do k = i + 2, NCHECK
        if (i == 1 .and. k == NCHECK) cycle
        ! bounding boxes first: most pairs are far apart
        if (any(lo(:, k) > hi(:, i)) .or. any(hi(:, k) < lo(:, i))) cycle
        kp = mod(k, NCHECK) + 1
        if (segments_cross(pts(:, i), pts(:, ip), pts(:, k), pts(:, kp))) then
          status = MBD_BAD_PARAM
          if (offset > zero) then
            msg = 'the roller''s path around the profile crosses itself: the roller is larger '// &
                  'than the smallest concave radius of the profile'
          else
            msg = 'profile crosses itself'
          end if
          return
        end if
      end do
    end do
  contains
    pure real(wp) function polar_radius(pp, aa)
      real(wp), intent(in) :: pp(:), aa
      integer :: kk
      polar_radius = pp(4)
      do kk = 1, nint(pp(3))
        polar_radius = polar_radius + pp(3 + 2 * kk) * cos(kk * aa) + pp(4 + 2 * kk) * sin(kk * aa)
      end do
    end function polar_radius
  end subroutine profile_check

  pure logical function segments_cross(a, b, c, d)
    real(wp), intent(in) :: a(2), b(2), c(2), d(2)
    real(wp) :: d1, d2, d3, d4
    d1 = orient(c, d, a); d2 = orient(c, d, b); d3 = orient(a, b, c); d4 = orient(a, b, d)
    segments_cross = (d1 * d2 < zero) .and. (d3 * d4 < zero)
  contains
    pure real(wp) function orient(p, q, r)
      real(wp), intent(in) :: p(2), q(2), r(2)
      orient = (q(1) - p(1)) * (r(2) - p(2)) - (q(2) - p(2)) * (r(1) - p(1))
    end function orient
  end function segments_cross

  ! ------------------------------------------------------------ derivatives (sensitivities)

  !> True when raw entry j of a profile is a count (spline n, Fourier K).
  pure logical function profile_is_count(kind, j)
    integer, intent(in) :: kind     !! profile kind
    integer, intent(in) :: j        !! raw entry (1-based within the profile)
    profile_is_count = (kind == PROF_SPLINE .and. j == 1) .or. (kind == PROF_FOURIER .and. j == 3)
  end function profile_is_count

  !> The fourth alpha derivative of c (for the rate of a roller's offset curve):
  !! circle R (cos a, sin a); Fourier r4 e + 4 r3 t - 6 r2 e - 4 r1 t + r e (Leibniz with
  !! e' = t, t' = -e, rk the k-th derivative of r); spline 0 (piecewise cubic).
  pure function profile_c4(kind, p, alpha) result(c4)
    integer, intent(in) :: kind      !! profile kind
    real(wp), intent(in) :: p(:)     !! prepared parameters
    real(wp), intent(in) :: alpha    !! curve parameter
    real(wp) :: c4(2)
    real(wp) :: e(2), t(2), r, r1, r2, r3, r4, ck, sk, rk
    integer :: k
    c4 = zero
    select case (kind)
    case (PROF_CIRCLE)
      c4 = p(3) * [cos(alpha), sin(alpha)]
    case (PROF_FOURIER)
      r = p(4); r1 = zero; r2 = zero; r3 = zero; r4 = zero
      do k = 1, nint(p(3))
        rk = real(k, wp)                ! (k**4 overflows a default integer past k = 215)
        ck = cos(rk * alpha); sk = sin(rk * alpha)
        r = r + p(3 + 2 * k) * ck + p(4 + 2 * k) * sk
        r1 = r1 + rk * (-p(3 + 2 * k) * sk + p(4 + 2 * k) * ck)
        r2 = r2 - rk**2 * (p(3 + 2 * k) * ck + p(4 + 2 * k) * sk)
        r3 = r3 + rk**3 * (p(3 + 2 * k) * sk - p(4 + 2 * k) * ck)
        r4 = r4 + rk**4 * (p(3 + 2 * k) * ck + p(4 + 2 * k) * sk)
      end do
      e = [cos(alpha), sin(alpha)]; t = [-e(2), e(1)]
      c4 = (r4 - 6.0_wp * r2 + r) * e + (4.0_wp * r3 - 4.0_wp * r1) * t
    end select
  end function profile_c4

  !> Third alpha derivative n3 of the unit outward normal (profile_normal's recurrence
  !! continued): g3 = (3 c2.c3 + c1.c4 - 3 g1 g2)/g,  u3 = (c4 - g3 u - 3 g2 u1 - 3 g1 u2)/g.
  pure function profile_normal3(c1, c2, c3, c4) result(n3)
    real(wp), intent(in) :: c1(2), c2(2), c3(2), c4(2)   !! first to fourth derivatives of c
    real(wp) :: n3(2)
    real(wp) :: g, g1, g2, g3, u(2), u1(2), u2(2), u3(2)
    g = hypot(c1(1), c1(2))
    u = c1 / g
    g1 = dot_product(c1, c2) / g
    u1 = (c2 - u * g1) / g
    g2 = (dot_product(c2, c2) + dot_product(c1, c3)) / g - g1**2 / g
    u2 = (c3 - two * u1 * g1 - u * g2) / g
    g3 = (3.0_wp * dot_product(c2, c3) + dot_product(c1, c4) - 3.0_wp * g1 * g2) / g
    u3 = (c4 - g3 * u - 3.0_wp * g2 * u1 - 3.0_wp * g1 * u2) / g
    n3 = [u3(2), -u3(1)]
  end function profile_normal3

  !> Changes tn0, tn1, tn2 of the normal and its alpha derivatives when the first three
  !! derivatives of c change by tc1, tc2, tc3 (profile_normal's recurrence differentiated).
  pure subroutine profile_normal_d(c1, c2, c3, tc1, tc2, tc3, tn0, tn1, tn2)
    real(wp), intent(in) :: c1(2), c2(2), c3(2)        !! first three derivatives of c
    real(wp), intent(in) :: tc1(2), tc2(2), tc3(2)     !! their changes
    real(wp), intent(out) :: tn0(2), tn1(2), tn2(2)    !! changes of n, n', n''
    real(wp) :: g, g1, g2, u(2), u1(2), u2(2), tg, tg1, tg2, tu(2), tu1(2), tu2(2), q
    g = hypot(c1(1), c1(2))
    u = c1 / g
    g1 = dot_product(c1, c2) / g
    u1 = (c2 - u * g1) / g
    q = dot_product(c2, c2) + dot_product(c1, c3)
    g2 = q / g - g1**2 / g
    u2 = (c3 - two * u1 * g1 - u * g2) / g
    tg = dot_product(c1, tc1) / g
    tu = (tc1 - u * tg) / g
    tg1 = (dot_product(tc1, c2) + dot_product(c1, tc2)) / g - g1 * tg / g
    tu1 = (tc2 - tu * g1 - u * tg1) / g - u1 * tg / g
    tg2 = (two * dot_product(c2, tc2) + dot_product(tc1, c3) + dot_product(c1, tc3)) / g &
          - q * tg / g**2 - two * g1 * tg1 / g + g1**2 * tg / g**2
    tu2 = (tc3 - two * tu1 * g1 - two * u1 * tg1 - tu * g2 - u * tg2) / g - u2 * tg / g
    tn0 = [tu(2), -tu(1)]; tn1 = [tu1(2), -tu1(1)]; tn2 = [tu2(2), -tu2(1)]
  end subroutine profile_normal_d

  !> Changes tc0 .. tc3 of c and its first three alpha derivatives at a fixed alpha when
  !! the prepared parameters change by tp. Circle and Fourier profiles are linear in their
  !! parameters (the count K stays); the spline's knots s, values y and second derivatives M
  !! enter c = y_i + b t + M_i t**2/2 + (M_i+1 - M_i) t**3/(6 h), t = alpha - s_i,
  !! h = s_i+1 - s_i, b = (y_i+1 - y_i)/h - h (2 M_i + M_i+1)/6, differentiated term by term.
  pure subroutine profile_eval_d(kind, p, tp, alpha, tc0, tc1, tc2, tc3)
    integer, intent(in) :: kind      !! profile kind
    real(wp), intent(in) :: p(:)     !! prepared parameters
    real(wp), intent(in) :: tp(:)    !! their change
    real(wp), intent(in) :: alpha    !! curve parameter
    real(wp), intent(out) :: tc0(2), tc1(2), tc2(2), tc3(2)  !! changes of c and derivatives
    real(wp) :: q(size(p))
    select case (kind)
    case (PROF_CIRCLE)
      call profile_eval(kind, tp, alpha, tc0, tc1, tc2, tc3)
    case (PROF_FOURIER)
      q = tp; q(3) = p(3)
      call profile_eval(kind, q, alpha, tc0, tc1, tc2, tc3)
    case (PROF_SPLINE)
      call spline_eval_d(p, tp, alpha, tc0, tc1, tc2, tc3)
    case default
      tc0 = zero; tc1 = zero; tc2 = zero; tc3 = zero
    end select
  end subroutine profile_eval_d

  !> The spline part of profile_eval_d.
  pure subroutine spline_eval_d(p, tp, alpha, tc0, tc1, tc2, tc3)
    real(wp), intent(in) :: p(:), tp(:), alpha
    real(wp), intent(out) :: tc0(2), tc1(2), tc2(2), tc3(2)
    integer :: n, lo, hi, mid, os, ox, omx, oy, omy
    real(wp) :: a, h, t, ya(2), yb(2), ma(2), mb(2), b(2), dm(2)
    real(wp) :: th, tt, tya(2), tyb(2), tma(2), tmb(2), tb(2), tdm(2)
    n = nint(p(1))
    os = 1; ox = os + n + 1; omx = ox + n + 1; oy = omx + n + 1; omy = oy + n + 1
    a = modulo(alpha, two * pi)
    lo = 1; hi = n + 1
    do while (hi - lo > 1)
      mid = (lo + hi) / 2
      if (p(os + mid) <= a) then
        lo = mid
      else
        hi = mid
      end if
    end do
    h = p(os + lo + 1) - p(os + lo); th = tp(os + lo + 1) - tp(os + lo)
    t = a - p(os + lo); tt = -tp(os + lo)
    ya = [p(ox + lo), p(oy + lo)]; yb = [p(ox + lo + 1), p(oy + lo + 1)]
    ma = [p(omx + lo), p(omy + lo)]; mb = [p(omx + lo + 1), p(omy + lo + 1)]
    tya = [tp(ox + lo), tp(oy + lo)]; tyb = [tp(ox + lo + 1), tp(oy + lo + 1)]
    tma = [tp(omx + lo), tp(omy + lo)]; tmb = [tp(omx + lo + 1), tp(omy + lo + 1)]
    b = (yb - ya) / h - h * (two * ma + mb) / 6.0_wp
    tb = (tyb - tya) / h - (yb - ya) * th / h**2 - th * (two * ma + mb) / 6.0_wp &
         - h * (two * tma + tmb) / 6.0_wp
    dm = (mb - ma) / h
    tdm = (tmb - tma) / h - (mb - ma) * th / h**2
    ! c0 = ya + b t + ma t**2/2 + dm t**3/6,  c1 = b + ma t + dm t**2/2,  c2 = ma + dm t,  c3 = dm
    tc0 = tya + tb * t + b * tt + tma * t**2 / two + ma * t * tt + tdm * t**3 / 6.0_wp &
          + dm * t**2 * tt / two
    tc1 = tb + tma * t + ma * tt + tdm * t**2 / two + dm * t * tt
    tc2 = tma + tdm * t + dm * tt
    tc3 = tdm
  end subroutine spline_eval_d

  !> Change tprep of the prepared parameters when raw(j) changes by one (j not a count).
  !! Circle and Fourier: prepared = raw. Spline: through the orientation (a clockwise loop
  !! is reversed), the chords h_i = |P_i+1 - P_i|, the knots scaled to [0, 2 pi]
  !! (h~ = 2 pi h / sum h) and the cyclic system A(h~) M = b(h~, x):  A dM = db - dA M.
  subroutine profile_prepare_d(kind, raw, j, tprep, status, msg)
    integer, intent(in) :: kind                     !! profile kind
    real(wp), intent(in) :: raw(:)                  !! raw parameters (exact length)
    integer, intent(in) :: j                        !! raw entry that changes
    real(wp), allocatable, intent(out) :: tprep(:)  !! change of the prepared parameters
    integer, intent(out) :: status                  !! MBD_OK or the failure
    character(len=MSG_LEN), intent(out) :: msg      !! what went wrong
    integer :: n, i, im, ip, pos, st
    real(wp), allocatable :: x(:), y(:), hr(:), ht(:), mx(:), my(:), dx(:), dy(:), dhr(:), &
                             dht(:), ds(:), r(:, :)
    real(wp) :: area, total, dtotal
    status = MBD_OK; msg = ''
    if (kind /= PROF_SPLINE) then
      allocate (tprep(size(raw)), stat=st)
      if (st /= 0) then
        status = MBD_NO_MEMORY; msg = 'out of memory'; return
      end if
      tprep = zero; tprep(j) = one
      return
    end if
    n = nint(raw(1))
    allocate (x(n + 1), y(n + 1), hr(n), ht(n), mx(n + 1), my(n + 1), dx(n + 1), dy(n + 1), &
              dhr(n), dht(n), ds(n + 1), r(n, 2), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory'; return
    end if
    x(1:n) = raw(2:2 * n:2); y(1:n) = raw(3:2 * n + 1:2)
    area = half * (sum(x(1:n - 1) * y(2:n) - x(2:n) * y(1:n - 1)) + x(n) * y(1) - x(1) * y(n))
    pos = j / 2                                 ! raw(2 i) = x_i, raw(2 i + 1) = y_i
    if (area < zero) then
      x(1:n) = x(n:1:-1); y(1:n) = y(n:1:-1)
      pos = n + 1 - pos
    end if
    x(n + 1) = x(1); y(n + 1) = y(1)
    dx = zero; dy = zero
    if (mod(j, 2) == 0) then
      dx(pos) = one
    else
      dy(pos) = one
    end if
    dx(n + 1) = dx(1); dy(n + 1) = dy(1)
    do i = 1, n
      hr(i) = hypot(x(i + 1) - x(i), y(i + 1) - y(i))
      dhr(i) = ((x(i + 1) - x(i)) * (dx(i + 1) - dx(i)) + &
                (y(i + 1) - y(i)) * (dy(i + 1) - dy(i))) / hr(i)
    end do
    total = sum(hr); dtotal = sum(dhr)
    ht = hr * (two * pi / total)
    dht = two * pi * (dhr / total - hr * dtotal / total**2)
    ds(1) = zero
    do i = 1, n
      ds(i + 1) = ds(i) + dht(i)
    end do
    ds(n + 1) = zero
    call periodic_spline(n, ht, x, y, mx, my, status, msg)
    if (status /= MBD_OK) return
    do i = 1, n
      im = i - 1; if (im == 0) im = n
      ip = i + 1
      r(i, 1) = 6.0_wp * ((dx(ip) - dx(i)) / ht(i) - (x(ip) - x(i)) * dht(i) / ht(i)**2 &
                          - (dx(i) - dx(im)) / ht(im) + (x(i) - x(im)) * dht(im) / ht(im)**2) &
                - (dht(im) * mx(im) + two * (dht(im) + dht(i)) * mx(i) + dht(i) * mx(ip))
      r(i, 2) = 6.0_wp * ((dy(ip) - dy(i)) / ht(i) - (y(ip) - y(i)) * dht(i) / ht(i)**2 &
                          - (dy(i) - dy(im)) / ht(im) + (y(i) - y(im)) * dht(im) / ht(im)**2) &
                - (dht(im) * my(im) + two * (dht(im) + dht(i)) * my(i) + dht(i) * my(ip))
    end do
    call cyclic_solve(n, ht, r, status, msg)
    if (status /= MBD_OK) return
    tprep = [zero, ds, dx, r(:, 1), r(1, 1), dy, r(:, 2), r(1, 2)]
  end subroutine profile_prepare_d

end module mbd_profiles
