!> mbd_lapack: explicit interfaces to the LAPACK routines the library calls.
module mbd_lapack
  use mbd_kinds, only: wp
  implicit none
  private
  public :: dgetrf, dgetf2, dgetrs, dgesvd, dgels, dgtsv

  interface
    !> LU factorization with partial pivoting.
    pure subroutine dgetrf(m, n, a, lda, ipiv, info)
      import :: wp
      integer, intent(in) :: m, n, lda
      real(wp), intent(inout) :: a(lda, *)
      integer, intent(out) :: ipiv(*)
      integer, intent(out) :: info
    end subroutine dgetrf
    !> Unblocked LU factorization (faster for small matrices).
    pure subroutine dgetf2(m, n, a, lda, ipiv, info)
      import :: wp
      integer, intent(in) :: m, n, lda
      real(wp), intent(inout) :: a(lda, *)
      integer, intent(out) :: ipiv(*)
      integer, intent(out) :: info
    end subroutine dgetf2
    !> Solve with the LU factors.
    pure subroutine dgetrs(trans, n, nrhs, a, lda, ipiv, b, ldb, info)
      import :: wp
      character(len=1), intent(in) :: trans
      integer, intent(in) :: n, nrhs, lda, ldb
      real(wp), intent(in) :: a(lda, *)
      integer, intent(in) :: ipiv(*)
      real(wp), intent(inout) :: b(ldb, *)
      integer, intent(out) :: info
    end subroutine dgetrs
    !> Singular value decomposition.
    pure subroutine dgesvd(jobu, jobvt, m, n, a, lda, s, u, ldu, vt, ldvt, work, lwork, info)
      import :: wp
      character(len=1), intent(in) :: jobu, jobvt
      integer, intent(in) :: m, n, lda, ldu, ldvt, lwork
      real(wp), intent(inout) :: a(lda, *)
      real(wp), intent(out) :: s(*), u(ldu, *), vt(ldvt, *), work(*)
      integer, intent(out) :: info
    end subroutine dgesvd
    !> Least squares by QR.
    pure subroutine dgels(trans, m, n, nrhs, a, lda, b, ldb, work, lwork, info)
      import :: wp
      character(len=1), intent(in) :: trans
      integer, intent(in) :: m, n, nrhs, lda, ldb, lwork
      real(wp), intent(inout) :: a(lda, *), b(ldb, *)
      real(wp), intent(out) :: work(*)
      integer, intent(out) :: info
    end subroutine dgels
    !> Tridiagonal solve.
    pure subroutine dgtsv(n, nrhs, dl, d, du, b, ldb, info)
      import :: wp
      integer, intent(in) :: n, nrhs, ldb
      real(wp), intent(inout) :: dl(*), d(*), du(*), b(ldb, *)
      integer, intent(out) :: info
    end subroutine dgtsv
  end interface
end module mbd_lapack
