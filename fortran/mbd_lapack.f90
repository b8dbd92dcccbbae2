!> mbd_lapack: explicit interfaces to the LAPACK routines the library calls.
module mbd_lapack
  use mbd_kinds, only: wp
  implicit none
  private
  public :: dgetrf, dgetf2, dgetrs, dtrsv, dgesvd, dgels, dgelsy, dgtsv, dgeqp3, dormqr, dtrtrs, &
            dgecon, dtrcon, dsyev, dsygvd, dgeev, dgehrd, dorghr, dgemm
  public :: dgbtrf, dgbtrs, dgbcon, dlacn2

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
    !> QR factorization with column pivoting (rank revealing).
    pure subroutine dgeqp3(m, n, a, lda, jpvt, tau, work, lwork, info)
      import :: wp
      integer, intent(in) :: m, n, lda, lwork
      real(wp), intent(inout) :: a(lda, *)
      integer, intent(inout) :: jpvt(*)
      real(wp), intent(out) :: tau(*), work(*)
      integer, intent(out) :: info
    end subroutine dgeqp3
    !> Apply Q or Q^T from a QR factorization.
    pure subroutine dormqr(side, trans, m, n, k, a, lda, tau, c, ldc, work, lwork, info)
      import :: wp
      character(len=1), intent(in) :: side, trans
      integer, intent(in) :: m, n, k, lda, ldc, lwork
      real(wp), intent(in) :: a(lda, *), tau(*)
      real(wp), intent(inout) :: c(ldc, *)
      real(wp), intent(out) :: work(*)
      integer, intent(out) :: info
    end subroutine dormqr
    !> Triangular solve.
    pure subroutine dtrtrs(uplo, trans, diag, n, nrhs, a, lda, b, ldb, info)
      import :: wp
      character(len=1), intent(in) :: uplo, trans, diag
      integer, intent(in) :: n, nrhs, lda, ldb
      real(wp), intent(in) :: a(lda, *)
      real(wp), intent(inout) :: b(ldb, *)
      integer, intent(out) :: info
    end subroutine dtrtrs
    !> Reciprocal condition number estimate from LU factors.
    pure subroutine dgecon(norm, n, a, lda, anorm, rcond, work, iwork, info)
      import :: wp
      character(len=1), intent(in) :: norm
      integer, intent(in) :: n, lda
      real(wp), intent(in) :: a(lda, *), anorm
      real(wp), intent(out) :: rcond, work(*)
      integer, intent(out) :: iwork(*), info
    end subroutine dgecon
    !> Reciprocal condition number estimate of a triangular matrix.
    pure subroutine dtrcon(norm, uplo, diag, n, a, lda, rcond, work, iwork, info)
      import :: wp
      character(len=1), intent(in) :: norm, uplo, diag
      integer, intent(in) :: n, lda
      real(wp), intent(in) :: a(lda, *)
      real(wp), intent(out) :: rcond, work(*)
      integer, intent(out) :: iwork(*), info
    end subroutine dtrcon
    !> Minimum-norm least squares by complete orthogonal factorization.
    pure subroutine dgelsy(m, n, nrhs, a, lda, b, ldb, jpvt, rcond, rank, work, lwork, info)
      import :: wp
      integer, intent(in) :: m, n, nrhs, lda, ldb, lwork
      real(wp), intent(inout) :: a(lda, *), b(ldb, *)
      integer, intent(inout) :: jpvt(*)
      real(wp), intent(in) :: rcond
      integer, intent(out) :: rank, info
      real(wp), intent(out) :: work(*)
    end subroutine dgelsy
    !> Eigenvalues of a symmetric matrix.
    pure subroutine dsyev(jobz, uplo, n, a, lda, w, work, lwork, info)
      import :: wp
      character(len=1), intent(in) :: jobz, uplo
      integer, intent(in) :: n, lda, lwork
      real(wp), intent(inout) :: a(lda, *)
      real(wp), intent(out) :: w(*), work(*)
      integer, intent(out) :: info
    end subroutine dsyev
    !> Symmetric-definite generalized eigenproblem A x = lambda B x (itype 1), the
    !! tridiagonal eigenvectors by divide and conquer (dstedc).
    pure subroutine dsygvd(itype, jobz, uplo, n, a, lda, b, ldb, w, work, lwork, iwork, &
                           liwork, info)
      import :: wp
      integer, intent(in) :: itype, n, lda, ldb, lwork, liwork
      character(len=1), intent(in) :: jobz, uplo
      real(wp), intent(inout) :: a(lda, *), b(ldb, *)
      real(wp), intent(out) :: w(*), work(*)
      integer, intent(out) :: iwork(*)
      integer, intent(out) :: info
    end subroutine dsygvd
    !> Eigenvalues (and right eigenvectors) of a general matrix.
    pure subroutine dgeev(jobvl, jobvr, n, a, lda, wr, wi, vl, ldvl, vr, ldvr, work, lwork, &
                          info)
      import :: wp
      character(len=1), intent(in) :: jobvl, jobvr
      integer, intent(in) :: n, lda, ldvl, ldvr, lwork
      real(wp), intent(inout) :: a(lda, *)
      real(wp), intent(out) :: wr(*), wi(*), vl(ldvl, *), vr(ldvr, *), work(*)
      integer, intent(out) :: info
    end subroutine dgeev
    !> Tridiagonal solve.
    pure subroutine dgtsv(n, nrhs, dl, d, du, b, ldb, info)
      import :: wp
      integer, intent(in) :: n, nrhs, ldb
      real(wp), intent(inout) :: dl(*), d(*), du(*), b(ldb, *)
      integer, intent(out) :: info
    end subroutine dgtsv
  end interface
  interface
    !> Reduction to upper Hessenberg form A = Q H Q^T (Q as reflectors in a below the
    !! first subdiagonal and tau).
    pure subroutine dgehrd(n, ilo, ihi, a, lda, tau, work, lwork, info)
      import :: wp
      integer, intent(in) :: n, ilo, ihi, lda, lwork
      real(wp), intent(inout) :: a(lda, *)
      real(wp), intent(out) :: tau(*), work(*)
      integer, intent(out) :: info
    end subroutine dgehrd
    !> The orthogonal Q of dgehrd, formed from its reflectors.
    pure subroutine dorghr(n, ilo, ihi, a, lda, tau, work, lwork, info)
      import :: wp
      integer, intent(in) :: n, ilo, ihi, lda, lwork
      real(wp), intent(inout) :: a(lda, *)
      real(wp), intent(in) :: tau(*)
      real(wp), intent(out) :: work(*)
      integer, intent(out) :: info
    end subroutine dorghr
    !> C = alpha op(A) op(B) + beta C (BLAS level 3; op: 'N' or 'T').
    pure subroutine dgemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc)
      import :: wp
      character(len=1), intent(in) :: transa, transb
      integer, intent(in) :: m, n, k, lda, ldb, ldc
      real(wp), intent(in) :: alpha, beta, a(lda, *), b(ldb, *)
      real(wp), intent(inout) :: c(ldc, *)
    end subroutine dgemm
    !> Triangular solve A x = b (BLAS level 2), x overwrites b.
    pure subroutine dtrsv(uplo, trans, diag, n, a, lda, x, incx)
      import :: wp
      character(len=1), intent(in) :: uplo, trans, diag
      integer, intent(in) :: n, lda, incx
      real(wp), intent(in) :: a(lda, *)
      real(wp), intent(inout) :: x(*)
    end subroutine dtrsv
    !> LU factorization of a band matrix with partial pivoting (ldab >= 2 kl + ku + 1).
    pure subroutine dgbtrf(m, n, kl, ku, ab, ldab, ipiv, info)
      import :: wp
      integer, intent(in) :: m, n, kl, ku, ldab
      real(wp), intent(inout) :: ab(ldab, *)
      integer, intent(out) :: ipiv(*)
      integer, intent(out) :: info
    end subroutine dgbtrf
    !> Solve with the band LU factors.
    pure subroutine dgbtrs(trans, n, kl, ku, nrhs, ab, ldab, ipiv, b, ldb, info)
      import :: wp
      character(len=1), intent(in) :: trans
      integer, intent(in) :: n, kl, ku, nrhs, ldab, ldb
      real(wp), intent(in) :: ab(ldab, *)
      integer, intent(in) :: ipiv(*)
      real(wp), intent(inout) :: b(ldb, *)
      integer, intent(out) :: info
    end subroutine dgbtrs
    !> Reciprocal condition number estimate from band LU factors.
    pure subroutine dgbcon(norm, n, kl, ku, ab, ldab, ipiv, anorm, rcond, work, iwork, info)
      import :: wp
      character(len=1), intent(in) :: norm
      integer, intent(in) :: n, kl, ku, ldab
      real(wp), intent(in) :: ab(ldab, *), anorm
      integer, intent(in) :: ipiv(*)
      real(wp), intent(out) :: rcond, work(*)
      integer, intent(out) :: iwork(*), info
    end subroutine dgbcon
    !> 1-norm estimate of a matrix known only through products (reverse communication):
    !! start with kase = 0; while kase /= 0 on return, overwrite x by A x (kase = 1) or
    !! A^T x (kase = 2) and call again; est is then ||A||_1 (Hager, Higham).
    pure subroutine dlacn2(n, v, x, isgn, est, kase, isave)
      import :: wp
      integer, intent(in) :: n
      real(wp), intent(inout) :: v(*), x(*), est
      integer, intent(inout) :: isgn(*), kase, isave(3)
    end subroutine dlacn2
  end interface
end module mbd_lapack
