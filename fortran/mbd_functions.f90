!> mbd_functions: driver functions of time, f(t) = sum_k c_k t**k + sum_h A_h sin(omega_h t + phi_h).
!!
!! Encoding in a real array p: [np, c_0 .. c_{np-1}, nh, (A, omega, phi) x nh].
!! Returns f, df/dt and d2f/dt2 (the driver's nu = f' and its time term in gamma = f'').
module mbd_functions
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use mbd_kinds, only: wp, zero, half
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MSG_LEN
  implicit none
  private
  public :: fun_eval, fun_check, fun_length, fun_exponents, fun_eval_d, fun_is_count

  real(wp), parameter :: FMAX = 1.0e100_wp   !! largest coefficient
  real(wp), parameter :: OMAX = 1.0e12_wp    !! largest angular frequency
  real(wp), parameter :: PMAX = 1.0e6_wp     !! largest phase

contains

  !> Length of the encoded function starting at p(1), or -1 when malformed.
  pure integer function fun_length(p)
    real(wp), intent(in) :: p(:)   !! encoded function (possibly followed by other data)
    integer :: np, nh
    fun_length = -1
    if (size(p) < 2) return
    if (.not. is_count(p(1))) return
    np = nint(p(1))
    if (size(p) < np + 2) return
    if (.not. is_count(p(np + 2))) return
    nh = nint(p(np + 2))
    if (size(p) < np + 2 + 3 * nh) return
    fun_length = np + 2 + 3 * nh
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
      msg = 'function of time is malformed (expected [np, coefficients, nh, (A, omega, phase)...])'
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
  end subroutine fun_eval

  !> True when entry i (1-based) of the encoded function p is a count (np or nh), which no
  !! derivative can be taken with respect to.
  pure logical function fun_is_count(p, i)
    real(wp), intent(in) :: p(:)   !! encoded function
    integer, intent(in) :: i       !! entry
    fun_is_count = i == 1 .or. i == nint(p(1)) + 2
  end function fun_is_count

  !> Changes tf, tf1, tf2 of f(t), f'(t), f''(t) when the coefficients change by tp (the
  !! counts must not change). Polynomial terms are linear; a harmonic A sin(w t + phi) gives
  !!   d/dA   = (s, w c, -w**2 s),   d/dphi = (A c, -A w s, -A w**2 c),
  !!   d/dw   = (A t c, A c - A w t s, -2 A w s - A w**2 t c),   s, c = sin, cos(w t + phi).
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
  end subroutine fun_eval_d

end module mbd_functions
