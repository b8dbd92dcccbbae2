!> solve_text: mbd2d-solve's numbers and CSV fields as Python writes them, without Fortran
!! internal I/O (which allocates per statement in libgfortran): C's snprintf formats the
!! numbers (number_format.c), rows are built in caller-owned buffers, fields quoted as
!! Python's csv module quotes them.
module solve_text
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
  use iso_c_binding, only: c_char, c_double, c_int
  use mbd_kinds, only: wp
  implicit none
  private
  public :: FMT_E16, FMT_G17, FMT_G6, FMT_E1, FMT_F10, FMT_G3, format_num, num, sput, bput, bnum, &
            quoted, cnum

  interface
    !> x into buf(len) as "%.16e" (kind 1), "%.17g" (2), "%g" (3), "%.1e" (4), "%.10f" (5)
    !! or "%.3g" (6); the length written (number_format.c)
    function format_num(x, kind, buf, len) result(n) bind(C, name='mbd_format')
      import :: c_char, c_double, c_int
      real(c_double), value :: x
      integer(c_int), value :: kind
      character(kind=c_char), intent(out) :: buf(*)
      integer(c_int), value :: len
      integer(c_int) :: n
    end function format_num
  end interface
  !> the formats of format_num
  integer(c_int), parameter :: FMT_E16 = 1, FMT_G17 = 2, FMT_G6 = 3, FMT_E1 = 4, FMT_F10 = 5, &
                                FMT_G3 = 6

contains

  !> A number as Python's "%.16e": 17 significant digits, a lower-case e and an exponent of
  !! at least two digits (-1.2345678901234567e-05, 0.0000000000000000e+00, 1.0e+100 style);
  !! nan, inf and -inf as Python writes them. C's snprintf writes the digits (number_format.c):
  !! a Fortran internal write would allocate on every call.
  !! s(1:n) gets the text (no trim of a function result: that allocates too).
  subroutine num(x, s, n)
    real(wp), intent(in) :: x
    character(len=32), intent(out) :: s
    integer, intent(out) :: n
    character(kind=c_char) :: buf(32)
    integer :: i
    if (ieee_is_nan(x)) then
      s = 'nan'; n = 3; return
    else if (.not. ieee_is_finite(x)) then
      s = merge('inf ', '-inf', x > 0.0_wp); n = merge(3, 4, x > 0.0_wp); return
    end if
    n = max(0, min(int(format_num(real(x, c_double), FMT_E16, buf, 32_c_int)), 31))
    s = ''
    do i = 1, n
      s(i:i) = buf(i)
    end do
  end subroutine num

  !> x as C's printf (and Python's format) writes it in format kind (format_num), for
  !! messages.
  function cnum(x, kind) result(s)
    real(wp), intent(in) :: x
    integer(c_int), intent(in) :: kind
    character(len=:), allocatable :: s
    character(kind=c_char) :: cb(64)
    integer :: i, m
    m = max(0, min(int(format_num(real(x, c_double), kind, cb, 64_c_int)), 63))
    allocate (character(len=m) :: s)
    do i = 1, m
      s(i:i) = cb(i)
    end do
  end function cnum

  !> Write bytes to a stream unit (nothing once a write has failed).
  subroutine sput(u, ios, text)
    integer, intent(in) :: u
    integer, intent(inout) :: ios
    character(len=*), intent(in) :: text
    if (ios == 0) write (u, iostat=ios) text
  end subroutine sput

  !> Append text to buf(1:n).
  subroutine bput(buf, n, text)
    character(len=*), intent(inout) :: buf
    integer, intent(inout) :: n
    character(len=*), intent(in) :: text
    buf(n + 1:n + len(text)) = text
    n = n + len(text)
  end subroutine bput

  !> Append ",x" to buf(1:n), x as Python's format(x, ".17g") (NaN: an empty field).
  subroutine bnum(buf, n, x)
    character(len=*), intent(inout) :: buf
    integer, intent(inout) :: n
    real(wp), intent(in) :: x
    character(kind=c_char) :: cb(40)
    integer :: i, m
    n = n + 1
    buf(n:n) = ','
    if (ieee_is_nan(x)) return
    m = max(0, min(int(format_num(real(x, c_double), FMT_G17, cb, 40_c_int)), 39))
    do i = 1, m
      buf(n + i:n + i) = cb(i)
    end do
    n = n + m
  end subroutine bnum

  !> A CSV field as Python's csv module writes it: in quotes (inner quotes doubled) when it
  !! holds a comma, a quote or a line break.
  function quoted(text) result(s)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: s
    integer :: i
    if (scan(text, ',"' // achar(10) // achar(13)) == 0) then
      s = text; return
    end if
    s = '"'
    do i = 1, len(text)
      if (text(i:i) == '"') then
        s = s // '""'
      else
        s = s // text(i:i)
      end if
    end do
    s = s // '"'
  end function quoted

end module solve_text
