!> mbd_functions: driver functions of time,
!!   f(t) = sum_k c_k t**k + sum_h A_h sin(omega_h t + phi_h) + sum_s h_s L_s(u_s),
!! the last sum of steps (motion laws): u = (t - t0)/(t1 - t0) clamped to [0, 1], L(0) = 0,
!! L(1) = 1, L'(0) = L'(1) = 0 (dwell, rise by h, dwell):
!!   1 cubic      L = 3u**2 - 2u**3                  (Adams' STEP)
!!   2 quintic    L = 10u**3 - 15u**4 + 6u**5        (the 3-4-5 polynomial, Adams' STEP5)
!!   3 cycloidal  L = u - sin(2 pi u)/(2 pi)
!!   4 harmonic   L = (1 - cos(pi u))/2
!!   5 modified sine        L'' = C sin(4 pi u) on [0, 1/8], C cos(4 pi/3 (u - 1/8)) on
!!                          [1/8, 7/8], -C sin(4 pi (1 - u)) on [7/8, 1]; C = 4 pi**2/(pi + 4)
!!   6 modified trapezoid   L'' = C sin(4 pi u), C, C cos(4 pi (u - 3/8)), -C,
!!                          -C sin(4 pi (1 - u)) on the eighths 0-1-3-5-7-8; C = 8 pi/(2 + pi)
!! (Norton, Cam Design and Manufacturing Handbook, ch. 3; quintic, cycloidal and the modified
!! laws have L'' = 0 at both ends, cubic and harmonic jump in acceleration there; the
!! modified laws' L and L' are their accelerations integrated twice in closed form).
!!
!! A table adds y(t) through points (t_k, y_k) (measured motion, a force history): on each
!! interval the quintic Hermite with values y_k and derivatives d_k, c_k at the points, those
!! of the polynomial through the five points around t_k (Fornberg's weights; fewer in a
!! table of fewer points): twice continuously differentiable, exact on quartics, errors
!! O(h^5), O(h^4), O(h^3) in f, f', f'' for smooth data, local (y_k moves f on three
!! intervals either side) and linear in the y_k; outside [t_1, t_n] the line through the end
!! with the end's slope (f'' jumps there).
!!
!! Encoding in a real array p: [np, c_0 .. c_{np-1}, nh, (A, omega, phi) x nh,
!! ns, (law, t0, t1, h) x ns, nt, t_1 .. t_nt, y_1 .. y_nt].
!! Returns f, df/dt and d2f/dt2 (the driver's nu = f' and its time term in gamma = f'').
module mbd_functions
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use mbd_kinds, only: wp, zero, one, half
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MSG_LEN
  implicit none
  private
  public :: fun_eval, fun_check, fun_length, fun_exponents, fun_eval_d, fun_is_count, &
            fun_next_break

  real(wp), parameter :: FMAX = 1.0e100_wp   !! largest coefficient
  real(wp), parameter :: OMAX = 1.0e12_wp    !! largest angular frequency
  real(wp), parameter :: PMAX = 1.0e6_wp     !! largest phase
  real(wp), parameter :: TMAX = 1.0e12_wp    !! largest step time
  real(wp), parameter :: TREL = 1.0e-9_wp    !! shortest step: TREL max(1, |t0|, |t1|)
  real(wp), parameter :: PI = 3.14159265358979323846_wp
  integer, parameter :: NLAW = 6             !! motion laws (codes 1 .. NLAW)

contains

  !> Length of the encoded function starting at p(1), or -1 when malformed.
  pure integer function fun_length(p)
    real(wp), intent(in) :: p(:)   !! encoded function (possibly followed by other data)
    integer :: np, nh, ns, nt
    fun_length = -1
    if (size(p) < 2) return
    if (.not. is_count(p(1))) return
    np = nint(p(1))
    if (size(p) < np + 2) return
    if (.not. is_count(p(np + 2))) return
    nh = nint(p(np + 2))
    if (size(p) < np + 3 + 3 * nh) return
    if (.not. is_count(p(np + 3 + 3 * nh))) return
    ns = nint(p(np + 3 + 3 * nh))
    if (size(p) < np + 4 + 3 * nh + 4 * ns) return
    if (.not. is_count(p(np + 4 + 3 * nh + 4 * ns))) return
    nt = nint(p(np + 4 + 3 * nh + 4 * ns))
    if (size(p) < np + 4 + 3 * nh + 4 * ns + 2 * nt) return
    fun_length = np + 4 + 3 * nh + 4 * ns + 2 * nt
  end function fun_length

  pure logical function is_count(x)
    real(wp), intent(in) :: x
    is_count = ieee_is_finite(x)
    if (is_count) is_count = x >= zero .and. x < 1.0e6_wp .and. abs(x - anint(x)) <= 1.0e-9_wp
  end function is_count

  !> Check an encoded function: well formed and all values finite.
  subroutine fun_check(p, status, msg)
    real(wp), intent(in) :: p(:)              !! encoded function
    integer, intent(out) :: status            !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg !! what is wrong
    integer :: n
    status = MBD_OK; msg = ''
    n = fun_length(p)
    if (n < 0) then
      status = MBD_BAD_PARAM
      msg = 'function of time is malformed (expected [np, coefficients, nh, (A, omega, '// &
            'phase)..., ns, (law, t0, t1, h)..., nt, t_1 .. t_nt, y_1 .. y_nt])'
      return
    end if
    if (.not. all(ieee_is_finite(p(1:n)))) then
      status = MBD_BAD_PARAM; msg = 'function of time has a non-finite coefficient'
    else if (any(abs(p(1:n)) > FMAX)) then
      status = MBD_BAD_PARAM
      write (msg, '(a,es8.1)') 'function of time: every coefficient must be within +-', FMAX
    else if (.not. harmonics_ok()) then
      status = MBD_BAD_PARAM
      write (msg, '(a,es8.1,a,es8.1,a)') 'function of time: a harmonic needs |omega| <= ', &
        OMAX, ' and |phase| <= ', PMAX, ' (beyond that its values lose all precision)'
    else
      call steps_check(p, status, msg)
      if (status == MBD_OK) call table_check(p, status, msg)
    end if
  contains
    logical function harmonics_ok()
      integer :: np, nh, k, o
      np = nint(p(1)); nh = nint(p(np + 2))
      harmonics_ok = .true.
      do k = 1, nh
        o = np + 2 + 3 * (k - 1)
        if (abs(p(o + 2)) > OMAX .or. abs(p(o + 3)) > PMAX) harmonics_ok = .false.
      end do
    end function harmonics_ok
  end subroutine fun_check

  !> Check the steps of a well-formed, finite encoded function: a law code 1 .. NLAW,
  !! |t0|, |t1| <= TMAX and t1 - t0 > TREL max(1, |t0|, |t1|).
  subroutine steps_check(p, status, msg)
    real(wp), intent(in) :: p(:)              !! encoded function
    integer, intent(out) :: status            !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg !! what is wrong
    integer :: k, o, ns
    real(wp) :: t0, t1
    status = MBD_OK; msg = ''
    o = steps_at(p)
    ns = nint(p(o))
    do k = 1, ns
      t0 = p(o + 4 * k - 2); t1 = p(o + 4 * k - 1)
      if (p(o + 4 * k - 3) < half .or. p(o + 4 * k - 3) > NLAW + half .or. &
          abs(p(o + 4 * k - 3) - anint(p(o + 4 * k - 3))) > 1.0e-9_wp) then
        status = MBD_BAD_PARAM
        write (msg, '(a,i0,a)') 'function of time: step ', k - 1, ' has an unknown law '// &
          '(1 cubic, 2 quintic, 3 cycloidal, 4 harmonic, 5 modified sine, 6 modified trapezoid)'
      else if (max(abs(t0), abs(t1)) > TMAX) then
        status = MBD_BAD_PARAM
        write (msg, '(a,i0,a,es8.1)') 'function of time: step ', k - 1, &
          ' needs |t0| and |t1| <= ', TMAX
      else if (t1 - t0 <= TREL * max(1.0_wp, abs(t0), abs(t1))) then
        status = MBD_BAD_PARAM
        write (msg, '(a,i0,a,es9.2,a,es9.2,a)') 'function of time: step ', k - 1, &
          ' needs t1 > t0 (got t0 = ', t0, ', t1 = ', t1, '); a jump is not a motion'
      end if
      if (status /= MBD_OK) return
    end do
  end subroutine steps_check

  !> The first breakpoint of f after t: the smallest step time t0 or t1, or table end, above
  !! t (huge when there is none). f'' may jump there; the kinematic loop ends a step on it.
  pure real(wp) function fun_next_break(p, t) result(tb)
    real(wp), intent(in) :: p(:)   !! encoded function
    real(wp), intent(in) :: t      !! time
    integer :: k, o
    tb = huge(one)
    o = steps_at(p)
    do k = 1, int(p(o) + half)
      if (p(o + 4 * k - 2) > t) tb = min(tb, p(o + 4 * k - 2))
      if (p(o + 4 * k - 1) > t) tb = min(tb, p(o + 4 * k - 1))
    end do
    o = table_at(p); k = int(p(o) + half)               ! a table's ends
    if (k > 0) then
      if (p(o + 1) > t) tb = min(tb, p(o + 1))
      if (p(o + k) > t) tb = min(tb, p(o + k))
    end if
  end function fun_next_break

  !> Position of ns (the count of steps) in a well-formed encoded function.
  pure integer function steps_at(p)
    real(wp), intent(in) :: p(:)   !! encoded function
    integer :: np
    np = int(p(1) + half)
    steps_at = np + 3 + 3 * int(p(np + 2) + half)
  end function steps_at

  !> Check the table of a well-formed, finite encoded function: none or at least 2 points,
  !! times within TMAX, each above the one before by TREL max(1, |t|).
  subroutine table_check(p, status, msg)
    real(wp), intent(in) :: p(:)              !! encoded function
    integer, intent(out) :: status            !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg !! what is wrong
    integer :: k, o, nt
    status = MBD_OK; msg = ''
    o = table_at(p)
    nt = nint(p(o))
    if (nt == 1) then
      status = MBD_BAD_PARAM; msg = 'function of time: a table needs at least 2 points'
      return
    end if
    do k = 1, nt
      if (abs(p(o + k)) > TMAX) then
        status = MBD_BAD_PARAM
        write (msg, '(a,i0,a,es8.1)') 'function of time: table time ', k - 1, &
          ' must be within +-', TMAX
        return
      end if
      if (k == 1) cycle
      if (p(o + k) - p(o + k - 1) <= TREL * max(1.0_wp, abs(p(o + k)))) then
        status = MBD_BAD_PARAM
        write (msg, '(a,i0,a,i0,a)') 'function of time: table times must increase (time ', &
          k - 1, ' is not above time ', k - 2, ')'
        return
      end if
    end do
  end subroutine table_check

  !> Position of nt (the count of table points) in a well-formed encoded function.
  pure integer function table_at(p)
    real(wp), intent(in) :: p(:)   !! encoded function
    integer :: o
    o = steps_at(p)
    table_at = o + 1 + 4 * int(p(o) + half)
  end function table_at

  !> Adds the table's f, f', f'' at t (the module header) for the points tk, values yk.
  pure subroutine table_eval(tk, yk, t, f, f1, f2)
    real(wp), intent(in) :: tk(:), yk(:)   !! times (increasing) and values, n >= 2
    real(wp), intent(in) :: t              !! time
    real(wp), intent(inout) :: f, f1, f2
    integer :: n, i, lo, hi, mid
    real(wp) :: d0, c0, d1, c1, hh, u, b(6), b1(6), b2(6), v(6)
    n = size(tk)
    if (t < tk(1) .or. t >= tk(n)) then        ! the line through the end
      i = merge(1, n, t < tk(1))
      call knot_derivs(tk, yk, i, d0, c0)
      f = f + yk(i) + d0 * (t - tk(i)); f1 = f1 + d0
      return
    end if
    lo = 1; hi = n                             ! tk(lo) <= t < tk(hi)
    do while (hi - lo > 1)
      mid = (lo + hi) / 2
      if (t >= tk(mid)) then
        lo = mid
      else
        hi = mid
      end if
    end do
    call knot_derivs(tk, yk, lo, d0, c0)
    call knot_derivs(tk, yk, hi, d1, c1)
    hh = tk(hi) - tk(lo); u = (t - tk(lo)) / hh
    call hermite5(u, b, b1, b2)
    v = [yk(lo), hh * d0, hh * hh * c0, yk(hi), hh * d1, hh * hh * c1]
    f = f + dot_product(v, b)
    f1 = f1 + dot_product(v, b1) / hh
    f2 = f2 + dot_product(v, b2) / (hh * hh)
  end subroutine table_eval

  !> d_i, c_i of the table at point i: the slope and second derivative at t_i of the
  !! polynomial through the (at most) five points around it (a window kept inside the
  !! table), by Fornberg's weights.
  pure subroutine knot_derivs(tk, yk, i, d, c)
    real(wp), intent(in) :: tk(:), yk(:)
    integer, intent(in) :: i
    real(wp), intent(out) :: d, c
    integer :: j0, nw
    real(wp) :: w(0:4, 0:2)
    nw = min(size(tk), 5)
    j0 = min(max(i - 2, 1), size(tk) - nw + 1)
    call fd_weights(tk(i), tk(j0:j0 + nw - 1), w(0:nw - 1, :))
    d = dot_product(w(0:nw - 1, 1), yk(j0:j0 + nw - 1))
    c = dot_product(w(0:nw - 1, 2), yk(j0:j0 + nw - 1))
  end subroutine knot_derivs

  !> Weights c(k, m) of the m-th derivative (m = 0, 1, 2) at z of the polynomial through the
  !! nodes x (Fornberg, Math. Comp. 51 (1988) 699-706): f^(m)(z) = sum_k c(k, m) f(x_k).
  pure subroutine fd_weights(z, x, c)
    real(wp), intent(in) :: z, x(0:)
    real(wp), intent(out) :: c(0:, 0:)
    integer :: i, j, k, nd, mn
    real(wp) :: c1, c2, c3, c4, c5
    nd = size(x) - 1
    c = zero; c(0, 0) = 1
    c1 = 1; c4 = x(0) - z
    do i = 1, nd
      mn = min(i, 2); c2 = 1; c5 = c4; c4 = x(i) - z
      do j = 0, i - 1
        c3 = x(i) - x(j); c2 = c2 * c3
        if (j == i - 1) then
          do k = mn, 1, -1
            c(i, k) = c1 * (k * c(i - 1, k - 1) - c5 * c(i - 1, k)) / c2
          end do
          c(i, 0) = -c1 * c5 * c(i - 1, 0) / c2
        end if
        do k = mn, 1, -1
          c(j, k) = (c4 * c(j, k) - k * c(j, k - 1)) / c3
        end do
        c(j, 0) = c4 * c(j, 0) / c3
      end do
      c1 = c2
    end do
  end subroutine fd_weights

  !> The quintic Hermite basis at u in [0, 1] and its first two derivatives, in the order
  !! of the weights (y0, H d0, H**2 c0, y1, H d1, H**2 c1).
  pure subroutine hermite5(u, b, b1, b2)
    real(wp), intent(in) :: u
    real(wp), intent(out) :: b(6), b1(6), b2(6)
    real(wp) :: u2, u3, u4, u5
    u2 = u * u; u3 = u2 * u; u4 = u3 * u; u5 = u4 * u
    b = [1 - 10 * u3 + 15 * u4 - 6 * u5, u - 6 * u3 + 8 * u4 - 3 * u5, &
         half * (u2 - 3 * u3 + 3 * u4 - u5), 10 * u3 - 15 * u4 + 6 * u5, &
         -4 * u3 + 7 * u4 - 3 * u5, half * (u3 - 2 * u4 + u5)]
    b1 = [-30 * u2 + 60 * u3 - 30 * u4, 1 - 18 * u2 + 32 * u3 - 15 * u4, &
          half * (2 * u - 9 * u2 + 12 * u3 - 5 * u4), 30 * u2 - 60 * u3 + 30 * u4, &
          -12 * u2 + 28 * u3 - 15 * u4, half * (3 * u2 - 8 * u3 + 5 * u4)]
    b2 = [-60 * u + 180 * u2 - 120 * u3, -36 * u + 96 * u2 - 60 * u3, &
          half * (2 - 18 * u + 36 * u2 - 20 * u3), 60 * u - 180 * u2 + 120 * u3, &
          -24 * u + 84 * u2 - 60 * u3, half * (6 * u - 24 * u2 + 20 * u3)]
  end subroutine hermite5

  !> A motion law and its first three derivatives at u in [0, 1] (see the module header).
  pure subroutine law_eval(law, u, l0, l1, l2, l3)
    integer, intent(in) :: law      !! 1 cubic, 2 quintic, 3 cycloidal, 4 harmonic
    real(wp), intent(in) :: u       !! normalized time
    real(wp), intent(out) :: l0, l1, l2, l3  !! L, L', L'', L'''
    real(wp) :: s, c
    select case (law)
    case (1)                        ! 3u^2 - 2u^3
      l0 = u * u * (3 - 2 * u); l1 = 6 * u * (1 - u); l2 = 6 - 12 * u; l3 = -12
    case (2)                        ! 10u^3 - 15u^4 + 6u^5
      l0 = u**3 * (10 + u * (-15 + 6 * u)); l1 = 30 * u * u * (1 + u * (-2 + u))
      l2 = u * (60 + u * (-180 + 120 * u)); l3 = 60 + u * (-360 + 360 * u)
    case (3)                        ! u - sin(2 pi u)/(2 pi)
      s = sin(2 * PI * u); c = cos(2 * PI * u)
      l0 = u - s / (2 * PI); l1 = 1 - c; l2 = 2 * PI * s; l3 = 4 * PI * PI * c
    case (4)                        ! (1 - cos(pi u))/2
      s = sin(PI * u); c = cos(PI * u)
      l0 = half * (1 - c); l1 = half * PI * s; l2 = half * PI * PI * c; l3 = -half * PI**3 * s
    case (5)
      call modified_sine(u, l0, l1, l2, l3)
    case default
      call modified_trapezoid(u, l0, l1, l2, l3)
    end select
  end subroutine law_eval

  !> The modified sine law (module header) and its derivatives, K = pi + 4:
  !!   ends   L = (pi u - sin(4 pi u)/4 [+ 4 on the last eighth])/K, L' = pi (1 - cos 4 pi u)/K
  !!   middle L = (pi u - 9/4 sin w + 2)/K, L' = pi (1 - 3 cos w)/K, w = pi (4u/3 + 1/3).
  pure subroutine modified_sine(u, l0, l1, l2, l3)
    real(wp), intent(in) :: u
    real(wp), intent(out) :: l0, l1, l2, l3
    real(wp) :: k, s, c, w
    k = PI + 4
    if (u < 0.125_wp .or. u >= 0.875_wp) then
      s = sin(4 * PI * u); c = cos(4 * PI * u)
      l0 = (PI * u - 0.25_wp * s + merge(4.0_wp, zero, u >= 0.875_wp)) / k
      l1 = PI * (1 - c) / k; l2 = 4 * PI**2 * s / k; l3 = 16 * PI**3 * c / k
    else
      w = PI * (4 * u + 1) / 3
      s = sin(w); c = cos(w)
      l0 = (PI * u - 2.25_wp * s + 2) / k; l1 = PI * (1 - 3 * c) / k
      l2 = 4 * PI**2 * s / k; l3 = 16 * PI**3 * c / (3 * k)
    end if
  end subroutine modified_sine

  !> The modified trapezoid law (module header) and its derivatives, K = 2 + pi, on the
  !! eighths [0, 1], [1, 3], [3, 5], [5, 7], [7, 8] (the accelerations integrated twice).
  pure subroutine modified_trapezoid(u, l0, l1, l2, l3)
    real(wp), intent(in) :: u
    real(wp), intent(out) :: l0, l1, l2, l3
    real(wp) :: k, s, c
    k = 2 + PI
    s = sin(4 * PI * u); c = cos(4 * PI * u)
    if (u < 0.125_wp) then
      l0 = (4 * PI * u - s) / (2 * PI * k); l1 = 2 * (1 - c) / k
      l2 = 8 * PI * s / k; l3 = 32 * PI**2 * c / k
    else if (u < 0.375_wp) then
      l0 = (16 * PI * u * (4 * PI * u - PI + 2) - 8 + PI**2) / (16 * PI * k)
      l1 = (8 * PI * u - PI + 2) / k; l2 = 8 * PI / k; l3 = zero
    else if (u < 0.625_wp) then
      l0 = (4 * PI * u + 4 * PI**2 * u + s - PI**2) / (2 * PI * k)
      l1 = 2 * (c + 1 + PI) / k; l2 = -8 * PI * s / k; l3 = -32 * PI**2 * c / k
    else if (u < 0.875_wp) then
      l0 = (16 * PI * u * (-4 * PI * u + 2 + 7 * PI) - 33 * PI**2 + 8) / (16 * PI * k)
      l1 = (-8 * PI * u + 2 + 7 * PI) / k; l2 = -8 * PI / k; l3 = zero
    else
      l0 = (2 * PI * u - half * s + PI**2) / (PI * k); l1 = 2 * (1 - c) / k
      l2 = 8 * PI * s / k; l3 = 32 * PI**2 * c / k
    end if
  end subroutine modified_trapezoid

  !> Length exponents of an encoded function (see mbd_model, nondimensional models): e on
  !! the coefficients c_k and the amplitudes A_h (f is scaled as a whole), 0 on the counts,
  !! the frequencies and the phases. Entries past the function are left as they are.
  pure subroutine fun_exponents(p, e, ex)
    real(wp), intent(in) :: p(:)       !! encoded function (well formed)
    integer, intent(in) :: e           !! exponent of f
    integer, intent(inout) :: ex(:)    !! exponents (size(p))
    integer :: np, nh, k, o
    np = nint(p(1))
    ex(1) = 0; ex(2:np + 1) = e; ex(np + 2) = 0
    nh = nint(p(np + 2))
    do k = 1, nh
      o = np + 2 + 3 * (k - 1)
      ex(o + 1) = e; ex(o + 2:o + 3) = 0
    end do
    o = steps_at(p)                  ! the count, each law and its times: 0; its rise h: e
    ex(o) = 0
    do k = 1, nint(p(o))
      ex(o + 4 * k - 3:o + 4 * k - 1) = 0; ex(o + 4 * k) = e
    end do
    o = table_at(p)                  ! the count and the times: 0; the values: e
    ex(o:o + nint(p(o))) = 0; ex(o + nint(p(o)) + 1:o + 2 * nint(p(o))) = e
  end subroutine fun_exponents

  !> f(t), f'(t), f''(t).
  pure subroutine fun_eval(p, t, f, f1, f2)
    real(wp), intent(in) :: p(:)   !! encoded function
    real(wp), intent(in) :: t      !! time
    real(wp), intent(out) :: f     !! f(t)
    real(wp), intent(out) :: f1    !! df/dt
    real(wp), intent(out) :: f2    !! d2f/dt2
    integer :: np, nh, k, o
    real(wp) :: a, w, ph, s, c
    np = int(p(1) + half)          ! the counts are whole numbers >= 0 (fun_check): nint
    f = zero; f1 = zero; f2 = zero
    ! Horner for c_0 + c_1 t + ... and its two derivatives
    do k = np, 1, -1
      f2 = f2 * t + 2 * f1
      f1 = f1 * t + f
      f = f * t + p(1 + k)
    end do
    nh = int(p(np + 2) + half)
    do k = 1, nh
      o = np + 2 + 3 * (k - 1)
      a = p(o + 1); w = p(o + 2); ph = p(o + 3)
      s = sin(w * t + ph); c = cos(w * t + ph)
      f = f + a * s
      f1 = f1 + a * w * c
      f2 = f2 - a * w * w * s
    end do
    o = np + 3 + 3 * nh                 ! ns (steps_at), then nt (table_at)
    if (p(o) > half) then
      do k = 1, int(p(o) + half)
        call step_eval(p(o + 4 * k - 3:o + 4 * k), t, f, f1, f2)
      end do
      o = o + 4 * int(p(o) + half)
    end if
    o = o + 1; k = int(p(o) + half)
    if (k > 0) call table_eval(p(o + 1:o + k), p(o + k + 1:o + 2 * k), t, f, f1, f2)
  end subroutine fun_eval

  !> Adds a step's h L(u), h L'(u)/T, h L''(u)/T**2 to f, f', f'' (T = t1 - t0; before t0
  !! nothing, from t1 on h alone). Right-continuous: at t0 and t1, where f'' may jump (cubic,
  !! harmonic), the values after the instant (what a step starting there continues from).
  pure subroutine step_eval(st, t, f, f1, f2)
    real(wp), intent(in) :: st(4)   !! law, t0, t1, h
    real(wp), intent(in) :: t       !! time
    real(wp), intent(inout) :: f, f1, f2
    real(wp) :: tt, u, l0, l1, l2, l3
    if (t < st(2)) return
    if (t >= st(3)) then
      f = f + st(4); return
    end if
    tt = st(3) - st(2); u = (t - st(2)) / tt
    call law_eval(int(st(1) + half), u, l0, l1, l2, l3)
    f = f + st(4) * l0
    f1 = f1 + st(4) * l1 / tt
    f2 = f2 + st(4) * l2 / (tt * tt)
  end subroutine step_eval

  !> True when entry i (1-based) of the encoded function p is a count (np, nh, ns, nt) or
  !! another entry no derivative is taken with respect to (a law code, a table's times).
  pure logical function fun_is_count(p, i)
    real(wp), intent(in) :: p(:)   !! encoded function
    integer, intent(in) :: i       !! entry
    integer :: o, ot
    o = steps_at(p); ot = table_at(p)
    fun_is_count = i == 1 .or. i == nint(p(1)) + 2 .or. i == o
    if (i > o .and. i < ot) fun_is_count = mod(i - o, 4) == 1   ! a step's law code
    if (i >= ot) fun_is_count = i <= ot + nint(p(ot))          ! nt and the table's times
  end function fun_is_count

  !> Changes tf, tf1, tf2 of f(t), f'(t), f''(t) when the coefficients change by tp (the
  !! counts must not change). Polynomial terms are linear; a harmonic A sin(w t + phi) gives
  !!   d/dA   = (s, w c, -w**2 s),   d/dphi = (A c, -A w s, -A w**2 c),
  !!   d/dw   = (A t c, A c - A w t s, -2 A w s - A w**2 t c),   s, c = sin, cos(w t + phi);
  !! a step h L(u), u = (t - t0)/T, T = t1 - t0, with du = ((u - 1) dt0 - u dt1)/T and
  !! dT = dt1 - dt0:
  !!   d(h L)        = dh L + h L' du,
  !!   d(h L'/T)     = dh L'/T + h (L'' du/T - L' dT/T**2),
  !!   d(h L''/T**2) = dh L''/T**2 + h (L''' du/T**2 - 2 L'' dT/T**3);   from t1 on: dh;
  !! a table (linear in its values y_k) by its interpolation of the values' changes (its
  !! times are not differentiated: fun_is_count).
  pure subroutine fun_eval_d(p, tp, t, tf, tf1, tf2)
    real(wp), intent(in) :: p(:)   !! encoded function
    real(wp), intent(in) :: tp(:)  !! change of its coefficients
    real(wp), intent(in) :: t      !! time
    real(wp), intent(out) :: tf, tf1, tf2  !! changes of f, f', f''
    integer :: np, nh, k, o
    real(wp) :: a, w, s, c, ta, tw, tph
    np = nint(p(1))
    tf = zero; tf1 = zero; tf2 = zero
    do k = np, 1, -1
      tf2 = tf2 * t + 2 * tf1
      tf1 = tf1 * t + tf
      tf = tf * t + tp(1 + k)
    end do
    nh = nint(p(np + 2))
    do k = 1, nh
      o = np + 2 + 3 * (k - 1)
      a = p(o + 1); w = p(o + 2)
      ta = tp(o + 1); tw = tp(o + 2); tph = tp(o + 3)
      s = sin(w * t + p(o + 3)); c = cos(w * t + p(o + 3))
      tf = tf + ta * s + a * c * (t * tw + tph)
      tf1 = tf1 + ta * w * c + a * tw * c - a * w * s * (t * tw + tph)
      tf2 = tf2 - ta * w * w * s - 2 * a * w * tw * s - a * w * w * c * (t * tw + tph)
    end do
    o = steps_at(p)
    do k = 1, nint(p(o))
      call step_eval_d(p(o + 4 * k - 3:o + 4 * k), tp(o + 4 * k - 3:o + 4 * k), t, tf, tf1, &
                       tf2)
    end do
    ! the table is linear in its values: their changes through the same interpolation
    o = table_at(p); k = nint(p(o))
    if (k > 0) call table_eval(p(o + 1:o + k), tp(o + k + 1:o + 2 * k), t, tf, tf1, tf2)
  end subroutine fun_eval_d

  !> Adds a step's changes (fun_eval_d's header) to tf, tf1, tf2.
  pure subroutine step_eval_d(st, tst, t, tf, tf1, tf2)
    real(wp), intent(in) :: st(4), tst(4)   !! law, t0, t1, h and their changes
    real(wp), intent(in) :: t               !! time
    real(wp), intent(inout) :: tf, tf1, tf2
    real(wp) :: tt, u, du, dt, h, l0, l1, l2, l3
    if (t < st(2)) return
    if (t >= st(3)) then
      tf = tf + tst(4); return
    end if
    tt = st(3) - st(2); u = (t - st(2)) / tt; h = st(4)
    du = ((u - 1) * tst(2) - u * tst(3)) / tt
    dt = tst(3) - tst(2)
    call law_eval(int(st(1) + half), u, l0, l1, l2, l3)
    tf = tf + tst(4) * l0 + h * l1 * du
    tf1 = tf1 + tst(4) * l1 / tt + h * (l2 * du / tt - l1 * dt / tt**2)
    tf2 = tf2 + tst(4) * l2 / tt**2 + h * (l3 * du / tt**2 - 2 * l2 * dt / tt**3)
  end subroutine step_eval_d

end module mbd_functions
