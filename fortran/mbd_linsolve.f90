!> mbd_linsolve: the LAPACK calls, and the one place LAPACK's info becomes a status.
!!
!!   lu_factor   A = P L U               (dgetf2 up to SMALL_N, else dgetrf)
!!   lu_solve    A x = b from the factors (dgetrs' steps: row interchanges, two dtrsv)
!!   lu_factor_small, lu_solve_small   the same in plain loops, for the small iteration
!!               matrices factored and solved in the generalized-alpha time loop
!!   ls_small    min ||A x - b|| for a small A of full column rank (Householder QR, plain loops)
!!   lu_det_sign sign of det A from the factors: prod(sign U_ii) * (-1)**(row swaps)
!!   svd_null    singular values of A and the singular vectors of the smallest one (dgesvd)
!!   row_rank    rank of A (QR with column pivoting of the row-normalized A^T, dgeqp3) and the
!!               redundant rows in file order: a row is redundant when it lies in the span of
!!               the rows before it (Gram-Schmidt, twice)
!!   qr_factor   A = Q R P^T for least squares (dgeqp3), A m x n with m >= n
!!   qr_solve    x = argmin ||A x - b|| for full column rank: R x_p = (Q^T b)(1:n) (dormqr,
!!               dtrtrs), x = P x_p; also returns the residual ||(Q^T b)(n+1:m)||
module mbd_linsolve
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_SINGULAR, MBD_LAPACK, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail
  use mbd_lapack, only: dgetrf, dgetf2, dtrsv, dgesvd, dgeqp3, dormqr, dtrtrs
  implicit none
  private
  public :: lapack_status, lu_factor, lu_solve, lu_det_sign, svd_null, row_rank
  public :: lu_factor_small, lu_solve_small, ls_small, lu_solve_rows, ls_small_cols
  public :: qr_factor, qr_solve, qr_lwork, RANK_TOL, LS_RTOL

  integer, parameter :: SMALL_N = 48   !! below this the unblocked dgetf2 is faster
  !> |R_kk| / |R_11| of the row-normalized matrix below which a row is dependent
  real(wp), parameter :: RANK_TOL = 1.0e-8_wp
  !> least squares of full column rank: min |R_kk| / max |R_kk| of the QR at least this
  real(wp), parameter :: LS_RTOL = 1.0e-8_wp

contains

  !> Translate a LAPACK info into a status and message.
  !! info < 0: argument -info was illegal (a bug here, reported as MBD_LAPACK);
  !! info > 0 from a factorization: U(info, info) is exactly zero (MBD_SINGULAR);
  !! info > 0 from dgesvd: the SVD did not converge (MBD_LAPACK).
  !! msg is written only on a failure (it is left as it was on success: no 512-byte fill
  !! per call in the time loop).
  subroutine lapack_status(routine, info, status, msg)
    character(len=*), intent(in) :: routine      !! LAPACK routine name
    integer, intent(in) :: info                  !! its info
    integer, intent(out) :: status               !! MBD_OK, MBD_SINGULAR or MBD_LAPACK
    character(len=MSG_LEN), intent(inout) :: msg !! explanation (on a failure)
    status = MBD_OK
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
    character(len=MSG_LEN), intent(inout) :: msg  !! explanation (on a failure)
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
    integer, intent(out) :: status              !! MBD_OK, or MBD_SINGULAR on overflow
    character(len=MSG_LEN), intent(inout) :: msg  !! explanation (on a failure)
    integer :: n, i
    real(wp) :: s
    ! dgetrs with one right-hand side, by its steps: b <- P^T b (the row interchanges in
    ! order), L y = b, U x = y (dtrsv: level 2, cheaper than dgetrs' dtrsm for small n)
    n = size(a, 1)
    do i = 1, n
      if (ipiv(i) /= i) then
        s = b(i); b(i) = b(ipiv(i)); b(ipiv(i)) = s
      end if
    end do
    call dtrsv('L', 'N', 'U', n, a, n, b, 1)
    call dtrsv('U', 'N', 'N', n, a, n, b, 1)
    status = MBD_OK
    do i = 1, n
      if (.not. abs(b(i)) <= huge(s)) then
        status = MBD_SINGULAR
        msg = 'the solution overflows: the matrix is singular to working precision'
        return
      end if
    end do
  end subroutine lu_solve

  !> LU with partial pivoting in place, A = P L U, for the small dense iteration matrices of
  !! the time loop (plain loops, column oriented: no BLAS call overhead). Same pivoting rule as
  !! dgetf2 (largest |a_ik| in the column). An exactly zero pivot gives MBD_SINGULAR.
  pure subroutine lu_factor_small(a, ipiv, status)
    real(wp), intent(inout) :: a(:, :)          !! square matrix; factors on return
    integer, intent(out) :: ipiv(:)             !! pivot rows
    integer, intent(out) :: status              !! MBD_OK or MBD_SINGULAR
    integer :: n, i, j, k, p
    real(wp) :: piv, tmp, f
    n = size(a, 1)
    status = MBD_OK
    do k = 1, n
      p = k; piv = abs(a(k, k))
      do j = k + 1, n
        if (abs(a(j, k)) > piv) then
          p = j; piv = abs(a(j, k))
        end if
      end do
      ipiv(k) = p
      if (.not. abs(piv) > zero) then
        status = MBD_SINGULAR; return
      end if
      if (p /= k) then
        do j = 1, n
          tmp = a(k, j); a(k, j) = a(p, j); a(p, j) = tmp
        end do
      end if
      f = 1 / a(k, k)
      do i = k + 1, n                                   ! l_ik = a_ik / u_kk
        a(i, k) = a(i, k) * f
      end do
      do j = k + 1, n                                   ! a_ij -= l_ik u_kj
        f = a(k, j)
        if (abs(f) <= zero) cycle
        do i = k + 1, n
          a(i, j) = a(i, j) - f * a(i, k)
        end do
      end do
    end do
  end subroutine lu_factor_small

  !> Solve A x = b with the factors of lu_factor_small: P L U x = b; b is overwritten by x.
  pure subroutine lu_solve_small(a, ipiv, b)
    real(wp), intent(in) :: a(:, :)             !! LU factors
    integer, intent(in) :: ipiv(:)              !! pivot rows
    real(wp), intent(inout) :: b(:)             !! right-hand side, then solution
    integer :: n, i, k, p
    real(wp) :: tmp
    n = size(a, 1)
    do k = 1, n                                 ! P b (the row interchanges in order)
      p = ipiv(k)
      if (p /= k) then
        tmp = b(k); b(k) = b(p); b(p) = tmp
      end if
    end do
    do k = 1, n                                 ! L y = P b (column oriented)
      tmp = b(k)
      if (abs(tmp) <= zero) cycle
      do i = k + 1, n
        b(i) = b(i) - tmp * a(i, k)
      end do
    end do
    do k = n, 1, -1                             ! U x = y
      b(k) = b(k) / a(k, k)
      tmp = b(k)
      if (abs(tmp) <= zero) cycle
      do i = 1, k - 1
        b(i) = b(i) - tmp * a(i, k)
      end do
    end do
  end subroutine lu_solve_small

  !> ls_small for several right-hand sides at once: min ||A X - B|| column by column, B
  !! (m, nrhs) overwritten by X in its first n rows; ok false (A, B spoiled) when A is
  !! numerically rank deficient.
  pure subroutine ls_small_cols(a, b, ok)
    real(wp), intent(inout) :: a(:, :)          !! A, overwritten by the factorization
    real(wp), intent(inout) :: b(:, :)          !! B (m, nrhs), then X in b(1:n, :)
    logical, intent(out) :: ok                  !! A had full column rank
    integer :: mm, n, k, j
    real(wp) :: alpha, nrm, vtv, f, rmax, rmin
    mm = size(a, 1); n = size(a, 2)
    ok = .false.
    do k = 1, n
      nrm = norm2(a(k:mm, k))
      alpha = -sign(nrm, a(k, k))
      if (nrm <= zero) return
      a(k, k) = a(k, k) - alpha
      vtv = dot_product(a(k:mm, k), a(k:mm, k))
      do j = k + 1, n
        f = 2 * dot_product(a(k:mm, k), a(k:mm, j)) / vtv
        a(k:mm, j) = a(k:mm, j) - f * a(k:mm, k)
      end do
      do j = 1, size(b, 2)
        f = 2 * dot_product(a(k:mm, k), b(k:mm, j)) / vtv
        b(k:mm, j) = b(k:mm, j) - f * a(k:mm, k)
      end do
      a(k, k) = alpha
    end do
    rmin = minval([(abs(a(k, k)), k=1, n)]); rmax = maxval([(abs(a(k, k)), k=1, n)])
    if (rmin < LS_RTOL * rmax) return
    do j = 1, size(b, 2)
      do k = n, 1, -1
        b(k, j) = (b(k, j) - dot_product(a(k, k + 1:n), b(k + 1:n, j))) / a(k, k)
      end do
    end do
    ok = .true.
  end subroutine ls_small_cols

  !> Solve A X = B for several right-hand sides with LU factors (dgetf2/dgetrf or
  !! lu_factor_small), the right-hand sides stored as rows: bt = B^T (4 k, n), so each step
  !! of the substitutions is a vector operation over 4 of them at a time (fixed length: the
  !! compiler unrolls it). bt is overwritten by X^T; its row count is a multiple of 4 (pad
  !! with zero rows).
  pure subroutine lu_solve_rows(a, ipiv, bt)
    real(wp), intent(in) :: a(:, :)             !! LU factors
    integer, intent(in) :: ipiv(:)              !! pivot rows
    real(wp), intent(inout) :: bt(:, :)         !! B^T (4 k, n), then X^T
    integer :: n, i, k, p, c
    real(wp) :: tmp(4), f
    n = size(a, 1)
    do c = 1, size(bt, 1) - 3, 4
      do k = 1, n                               ! P B (the row interchanges in order)
        p = ipiv(k)
        if (p /= k) then
          tmp = bt(c:c + 3, k); bt(c:c + 3, k) = bt(c:c + 3, p); bt(c:c + 3, p) = tmp
        end if
      end do
      do k = 1, n                               ! L Y = P B (zero multipliers skipped)
        do i = k + 1, n
          f = a(i, k)
          if (abs(f) <= zero) cycle
          bt(c:c + 3, i) = bt(c:c + 3, i) - f * bt(c:c + 3, k)
        end do
      end do
      do k = n, 1, -1                           ! U X = Y
        f = one / a(k, k)
        bt(c:c + 3, k) = bt(c:c + 3, k) * f
        do i = 1, k - 1
          f = a(i, k)
          if (abs(f) <= zero) cycle
          bt(c:c + 3, i) = bt(c:c + 3, i) - f * bt(c:c + 3, k)
        end do
      end do
    end do
  end subroutine lu_solve_rows

  !> Least squares min ||A x - b|| for A (m x n), m >= n, of full column rank, by Householder
  !! QR in plain loops (A = Q R, x = R^-1 (Q^T b)(1:n)); no allocation. ok is false (and a, b
  !! are spoiled) when min |R_kk| < LS_RTOL max |R_kk|: use a rank-revealing solve then.
  pure subroutine ls_small(a, b, ok)
    real(wp), intent(inout) :: a(:, :)          !! A, overwritten by the factorization
    real(wp), intent(inout) :: b(:)             !! b (m), then x in b(1:n)
    logical, intent(out) :: ok                  !! A had full column rank
    integer :: mm, n, k, j
    real(wp) :: alpha, nrm, vtv, f, rmax, rmin
    mm = size(a, 1); n = size(a, 2)
    ok = .false.
    rmax = zero; rmin = huge(one)
    do k = 1, n
      ! Householder reflector H = I - 2 v v^T / v^T v zeroing a(k+1:m, k); v stored in a(k:m, k)
      nrm = norm2(a(k:mm, k))
      alpha = -sign(nrm, a(k, k))
      rmax = max(rmax, nrm); rmin = min(rmin, nrm)
      if (nrm <= zero) return
      a(k, k) = a(k, k) - alpha
      vtv = dot_product(a(k:mm, k), a(k:mm, k))
      do j = k + 1, n
        f = 2 * dot_product(a(k:mm, k), a(k:mm, j)) / vtv
        a(k:mm, j) = a(k:mm, j) - f * a(k:mm, k)
      end do
      f = 2 * dot_product(a(k:mm, k), b(k:mm)) / vtv
      b(k:mm) = b(k:mm) - f * a(k:mm, k)
      a(k, k) = alpha                           ! R_kk (v no longer needed below the diagonal)
    end do
    rmin = minval([(abs(a(k, k)), k=1, n)]); rmax = maxval([(abs(a(k, k)), k=1, n)])
    if (rmin < LS_RTOL * rmax) return
    do k = n, 1, -1                             ! R x = (Q^T b)(1:n)
      b(k) = (b(k) - dot_product(a(k, k + 1:n), b(k + 1:n))) / a(k, k)
    end do
    ok = .true.
  end subroutine ls_small

  !> Sign of det A from its LU factors (zero if a pivot is zero).
  pure integer function lu_det_sign(a, ipiv) result(sgn)
    real(wp), intent(in) :: a(:, :)   !! LU factors
    integer, intent(in) :: ipiv(:)    !! pivots
    integer :: i
    sgn = 1
    do i = 1, size(a, 1)
      if (.not. abs(a(i, i)) > zero) then
        sgn = 0; return
      end if
      if (a(i, i) < zero) sgn = -sgn
      if (ipiv(i) /= i) sgn = -sgn
    end do
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
    real(wp) :: wq(1), bytes
    integer :: m, n, info, lwork, ierr
    character(len=*), parameter :: WHAT = 'the singular value decomposition of J (a dense ' // &
      'diagnosis of the singular configuration)', HINT = 'use a smaller model'
    m = size(a, 1); n = size(a, 2)
    bytes = REAL_BYTES * (2 * real(m, wp) * n + real(m, wp) * m + real(n, wp) * n)
    call mem_check(bytes, WHAT, HINT, status, msg)
    if (status /= MBD_OK) return
    allocate (w(m, n), um(m, m), vt(n, n), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(bytes, WHAT, HINT, status, msg); return
    end if
    w = a
    call dgesvd('A', 'A', m, n, w, m, sv, um, m, vt, n, wq, -1, info)
    lwork = max(1, int(wq(1)))
    allocate (work(lwork), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * lwork, WHAT, HINT, status, msg); return
    end if
    call dgesvd('A', 'A', m, n, w, m, sv, um, m, vt, n, work, lwork, info)
    call lapack_status('dgesvd', info, status, msg)
    if (status /= MBD_OK) return
    u = um(:, min(m, n))
    v = vt(min(m, n), :)
  end subroutine svd_null

  !> Rank of A (m x n) and its redundant rows: redundant(i) = 1 when row i is (to RANK_TOL)
  !! a combination of rows 1..i-1, so of equal rows the later ones are called redundant.
  !! The rank comes from a pivoted QR of the row-normalized A^T (dgeqp3); if the ordered
  !! selection disagrees with it (an ill-conditioned case), the rows dgeqp3 pivots last are
  !! flagged instead. Rows are scaled to unit length, so units do not matter.
  !! Allocates: not for time loops.
  subroutine row_rank(a, rank, redundant, status, msg)
    real(wp), intent(in) :: a(:, :)             !! matrix (unchanged)
    integer, intent(out) :: rank                !! numerical rank
    integer, intent(out) :: redundant(:)        !! 1 for a redundant row (m)
    integer, intent(out) :: status              !! MBD_OK or MBD_LAPACK
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    real(wp), allocatable :: at(:, :), tau(:), work(:), basis(:, :), v(:)
    real(wp) :: wq(1), nrm, r11, bytes
    integer, allocatable :: order(:)
    integer :: m, n, i, info, lwork, r, pass, ierr
    character(len=*), parameter :: WHAT = 'the rank analysis of J (dense)', &
      HINT = 'use a smaller model'
    m = size(a, 1); n = size(a, 2)
    rank = 0; redundant = 0
    bytes = REAL_BYTES * (real(n, wp) * m + real(n, wp) * min(m, n) + 2 * (m + n))
    call mem_check(bytes, WHAT, HINT, status, msg)
    if (status /= MBD_OK) return
    allocate (at(n, m), tau(min(m, n)), order(m), basis(n, min(m, n)), v(n), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(bytes, WHAT, HINT, status, msg); return
    end if
    do i = 1, m
      nrm = norm2(a(i, :))
      at(:, i) = zero
      if (nrm > zero) at(:, i) = a(i, :) / nrm
    end do
    ! ordered selection: Gram-Schmidt against the rows kept so far
    redundant = 0
    r = 0
    do i = 1, m
      v = at(:, i)
      do pass = 1, 2
        if (r > 0) v = v - matmul(basis(:, 1:r), matmul(v, basis(:, 1:r)))
      end do
      nrm = norm2(v)
      if (nrm > sqrt(RANK_TOL) .and. r < n) then
        r = r + 1
        basis(:, r) = v / nrm
      else
        redundant(i) = 1
      end if
    end do
    ! the rank from a pivoted QR
    order = 0
    call dgeqp3(n, m, at, n, order, tau, wq, -1, info)
    lwork = max(1, int(wq(1)))
    allocate (work(lwork), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * lwork, WHAT, HINT, status, msg); return
    end if
    call dgeqp3(n, m, at, n, order, tau, work, lwork, info)
    call lapack_status('dgeqp3', info, status, msg)
    if (status /= MBD_OK) return
    rank = 0
    r11 = zero
    if (min(m, n) > 0) r11 = abs(at(1, 1))      ! (no rows: rank 0)
    do i = 1, min(m, n)
      if (abs(at(i, i)) > RANK_TOL * r11) rank = rank + 1
    end do
    if (r /= rank) then
      redundant = 0
      redundant(order(rank + 1:m)) = 1
    end if
  end subroutine row_rank

  !> Workspace length for qr_factor and qr_solve on an m x n matrix.
  integer function qr_lwork(m, n) result(lwork)
    integer, intent(in) :: m, n   !! matrix size
    real(wp) :: a(1, 1), tau(1), wq(1), c(1, 1)
    integer :: jp(1), info
    call dgeqp3(m, n, a, max(1, m), jp, tau, wq, -1, info)
    lwork = int(wq(1))
    ! dormqr needs k = n <= m (the least-squares case); never pass LAPACK an illegal size
    if (m >= n) then
      call dormqr('L', 'T', m, 1, n, a, max(1, m), tau, c, max(1, m), wq, -1, info)
      lwork = max(lwork, int(wq(1)))
    end if
    lwork = max(lwork, 1)
  end function qr_lwork

  !> QR factorization with column pivoting, A = Q R P^T, in place.
  subroutine qr_factor(a, jpvt, tau, work, status, msg)
    real(wp), intent(inout) :: a(:, :)          !! m x n, m >= n; factors on return
    integer, intent(out) :: jpvt(:)             !! column permutation
    real(wp), intent(out) :: tau(:)             !! reflector scalars
    real(wp), intent(inout) :: work(:)          !! workspace (qr_lwork)
    integer, intent(out) :: status              !! MBD_OK or MBD_SINGULAR
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer :: m, n, info, i
    m = size(a, 1); n = size(a, 2)
    jpvt = 0
    call dgeqp3(m, n, a, m, jpvt, tau, work, size(work), info)
    call lapack_status('dgeqp3', info, status, msg)
    if (status /= MBD_OK) return
    do i = 1, n
      if (.not. (abs(a(i, i)) > RANK_TOL * abs(a(1, 1)))) then
        status = MBD_SINGULAR
        write (msg, '(a,i0,a,i0,a)') 'Jacobian has rank ', i - 1, ' < ', n, ' coordinates'
        return
      end if
    end do
  end subroutine qr_factor

  !> Least-squares solution from qr_factor: b(1:n) becomes x, resid = ||A x - b||.
  subroutine qr_solve(a, jpvt, tau, b, x, resid, work)
    real(wp), intent(in) :: a(:, :)             !! factors (m x n)
    integer, intent(in) :: jpvt(:)              !! column permutation
    real(wp), intent(in) :: tau(:)              !! reflector scalars
    real(wp), intent(inout) :: b(:)             !! right-hand side (m), overwritten
    real(wp), intent(out) :: x(:)               !! solution (n)
    real(wp), intent(out) :: resid              !! residual norm
    real(wp), intent(inout) :: work(:)          !! workspace
    integer :: m, n, info
    m = size(a, 1); n = size(a, 2)
    call dormqr('L', 'T', m, 1, n, a, m, tau, b, m, work, size(work), info)
    call dtrtrs('U', 'N', 'N', n, 1, a, m, b, m, info)
    x(jpvt(1:n)) = b(1:n)
    resid = zero
    if (m > n) resid = norm2(b(n + 1:m))
  end subroutine qr_solve

end module mbd_linsolve
