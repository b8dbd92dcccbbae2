!> mbd_linsolve: the LAPACK calls, and the one place LAPACK's info becomes a status.
!!
!!   lu_factor   A = P L U               (dgetf2 up to SMALL_N, else dgetrf)
!!   lu_solve    A x = b from the factors (dgetrs)
!!   lu_det_sign sign of det A from the factors: prod(sign U_ii) * (-1)**(row swaps)
!!   svd_null    singular values of A and the singular vectors of the smallest one (dgesvd)
module mbd_linsolve
  use mbd_kinds, only: wp, zero
  use mbd_status, only: MBD_OK, MBD_SINGULAR, MBD_LAPACK, MSG_LEN
  use mbd_lapack, only: dgetrf, dgetf2, dgetrs, dgesvd
  implicit none
  private
  public :: lapack_status, lu_factor, lu_solve, lu_det_sign, svd_null

  integer, parameter :: SMALL_N = 48   !! below this the unblocked dgetf2 is faster

contains

  !> Translate a LAPACK info into a status and message.
  !! info < 0: argument -info was illegal (a bug here, reported as MBD_LAPACK);
  !! info > 0 from a factorization: U(info, info) is exactly zero (MBD_SINGULAR);
  !! info > 0 from dgesvd: the SVD did not converge (MBD_LAPACK).
  subroutine lapack_status(routine, info, status, msg)
    character(len=*), intent(in) :: routine      !! LAPACK routine name
    integer, intent(in) :: info                  !! its info
    integer, intent(out) :: status               !! MBD_OK, MBD_SINGULAR or MBD_LAPACK
    character(len=MSG_LEN), intent(out) :: msg   !! explanation
    status = MBD_OK; msg = ''
    if (info == 0) return
    if (info < 0) then
      status = MBD_LAPACK
      write (msg, '(a,a,i0,a)') routine, ': argument ', -info, ' had an illegal value'
    else if (routine == 'dgetrf' .or. routine == 'dgetf2') then
      status = MBD_SINGULAR
      write (msg, '(a,i0,a)') 'Jacobian is singular: pivot ', info, ' is zero'
    else
      status = MBD_LAPACK
      write (msg, '(a,a,i0)') routine, ' failed to converge, info = ', info
    end if
  end subroutine lapack_status

  !> LU factorization in place, A = P L U.
  subroutine lu_factor(a, ipiv, status, msg)
    real(wp), intent(inout) :: a(:, :)          !! square matrix; factors on return
    integer, intent(out) :: ipiv(:)             !! pivot indices
    integer, intent(out) :: status              !! MBD_OK or MBD_SINGULAR
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer :: n, info
    n = size(a, 1)
    if (n <= SMALL_N) then
      call dgetf2(n, n, a, n, ipiv, info)
      call lapack_status('dgetf2', info, status, msg)
    else
      call dgetrf(n, n, a, n, ipiv, info)
      call lapack_status('dgetrf', info, status, msg)
    end if
  end subroutine lu_factor

  !> Solve A x = b with the LU factors; b is overwritten by x.
  subroutine lu_solve(a, ipiv, b, status, msg)
    real(wp), intent(in) :: a(:, :)             !! LU factors
    integer, intent(in) :: ipiv(:)              !! pivots
    real(wp), intent(inout) :: b(:)             !! right-hand side, then solution
    integer, intent(out) :: status              !! MBD_OK
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer :: n, info
    n = size(a, 1)
    call dgetrs('N', n, 1, a, n, ipiv, b, n, info)
    call lapack_status('dgetrs', info, status, msg)
  end subroutine lu_solve

  !> Sign of det A from its LU factors (zero if a pivot is zero).
  pure integer function lu_det_sign(a, ipiv) result(sgn)
    real(wp), intent(in) :: a(:, :)   !! LU factors
    integer, intent(in) :: ipiv(:)    !! pivots
    integer :: i
    sgn = 1
    do i = 1, size(a, 1)
      if (a(i, i) < zero) sgn = -sgn
      if (ipiv(i) /= i) sgn = -sgn
    end do
    if (.not. all(abs([(a(i, i), i=1, size(a, 1))]) > zero)) sgn = 0
  end function lu_det_sign

  !> Singular values of A (m x n) and the left/right singular vectors of the smallest.
  !! The pair belongs to sv(min(m, n)). Allocates: not for time loops.
  subroutine svd_null(a, sv, u, v, status, msg)
    real(wp), intent(in) :: a(:, :)             !! matrix (unchanged)
    real(wp), intent(out) :: sv(:)              !! singular values, descending (min(m, n))
    real(wp), intent(out) :: u(:)               !! left vector of the smallest (m)
    real(wp), intent(out) :: v(:)               !! right vector of the smallest (n)
    integer, intent(out) :: status              !! MBD_OK or MBD_LAPACK
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    real(wp), allocatable :: w(:, :), um(:, :), vt(:, :), work(:)
    real(wp) :: wq(1)
    integer :: m, n, info, lwork
    m = size(a, 1); n = size(a, 2)
    allocate (w(m, n), um(m, m), vt(n, n))
    w = a
    call dgesvd('A', 'A', m, n, w, m, sv, um, m, vt, n, wq, -1, info)
    lwork = max(1, int(wq(1)))
    allocate (work(lwork))
    call dgesvd('A', 'A', m, n, w, m, sv, um, m, vt, n, work, lwork, info)
    call lapack_status('dgesvd', info, status, msg)
    if (status /= MBD_OK) return
    u = um(:, min(m, n))
    v = vt(min(m, n), :)
  end subroutine svd_null

end module mbd_linsolve
