!> mbd_splu: LU of a small sparse square matrix, the pivot order planned once and replayed.
!!
!! The constraint Jacobian of a small mechanism is square, sparse (the four-bar: 25 to 37
!! non-zeros of 81) and changes slowly along a motion, so the pivot order chosen at one
!! configuration serves many steps (Duff, Erisman & Reid, Direct Methods for Sparse Matrices,
!! ch. 7 and 10: analyse once, factorize many times).
!!   plan    on the numeric matrix A: the pattern is every entry of A's structure that has been
!!           non-zero at some plan (it only grows); threshold Markowitz pivoting: at step k the
!!           pivot (i, j) of the active submatrix with |a_ij| >= TAU max_r |a_rj| that has the
!!           smallest (r_i - 1)(c_j - 1) (r_i, c_j: non-zeros in its row and column). Records the
!!           row and column orders, the pattern of L and U with its fill, and the updates.
!!   factor  P A Q = L U by the recorded updates:
!!             l_ik = a_ik / u_kk (i in L(:, k)),  a_ij <- a_ij - l_ik u_kj (i, j > k)
!!           and reports max |l_ik| (the caller plans again when it exceeds LMAX: bounded
!!           multipliers keep the growth, hence the backward error, bounded), the sign of
!!           det A and min |u_kk| / max |u_kk|.
!!           U's columns are then divided by their pivots, U = U1 diag(u_kk) (U1 unit upper).
!!   solve   A x = b: y = P b, L z = y, U1 v = z, x = Q diag(1/u_kk) v: one flat loop over the
!!           entries of L (by columns), one over U1 (by columns, last first), the pivots
!!           applied with the output permutation (no pass of their own); no BLAS calls.
!! No allocation after splu_init; the values live in val(:), indexed by at(i, j) for A(i, j).
module mbd_splu
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_SINGULAR, MBD_NO_MEMORY, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_fail
  implicit none
  private
  public :: splu_t, splu_init, splu_plan, splu_factor, splu_solve, splu_solve2, splu_solve_rows, &
            splu_solve_rows_h, &
            splu_solve_rows_t, splu_pos, LMAX, TAU

  real(wp), parameter :: TAU = 0.5_wp   !! pivot threshold of a plan (|l_ik| <= 1/TAU = 2)
  real(wp), parameter :: LMAX = 4.0_wp  !! largest multiplier a replayed factorization keeps

  !> Plan, values and factors of one matrix.
  type :: splu_t
    integer :: n = 0                      !! order
    integer :: nnz = 0                    !! stored entries of L + U (fill included)
    integer :: nops = 0                   !! update operations of a factorization
    integer :: nfill = 0                  !! fill entries (zeroed before each factorization)
    integer :: sgn = 1                    !! sign of the permutations P and Q
    logical :: planned = .false.          !! a plan exists
    logical, allocatable :: struct(:, :)  !! (n, n) the entries A may have
    logical, allocatable :: seen(:, :)    !! (n, n) the entries planned on (non-zero once)
    integer, allocatable :: at(:, :)      !! (n, n) position of A(i, j) in val (0: not stored)
    real(wp), allocatable :: val(:)       !! (n**2) values: A before factor, L and U after
    real(wp), allocatable :: rinv(:)      !! (n) 1 / u_kk
    real(wp), allocatable :: y(:), y2(:)  !! (n) work vectors of the solves
    real(wp), allocatable :: y4(:, :)     !! (4, n) work of the solves by rows (splu_solve_rows)
    integer, allocatable :: prow(:), pcol(:)  !! (n) step k pivots on A(prow(k), pcol(k))
    integer, allocatable :: diag(:)       !! (n) position of u_kk
    integer, allocatable :: lptr(:), lpos(:), lrow(:)  !! L by columns: entries, step rows
    integer, allocatable :: lcol(:)       !! step column of each L entry
    integer, allocatable :: uptr(:), upos(:), urow(:)  !! U above the diagonal by columns
    integer :: nu = 0                     !! entries of U above the diagonal
    !> U1 entries by columns, last column first: position, step row, step column
    integer, allocatable :: bpos(:), brow(:), bcol(:)
    !> L by rows (entries lrptr(a):lrptr(a+1)-1 of step row a, step columns c < a ascending)
    !! and U1 by rows (urptr, step columns c > a descending): position and step column
    integer, allocatable :: lrptr(:), lrpos(:), lrcol(:), urptr(:), urpos(:), urcol(:)
    integer, allocatable :: optr(:), otgt(:), ol(:), ou(:)  !! updates of step k: tgt -= l u
    integer, allocatable :: fill(:)       !! positions of the fill entries
    real(wp), allocatable :: a(:, :)      !! (n, n) work of the plan
    logical, allocatable :: s(:, :)       !! (n, n) work of the plan (pattern with fill)
  end type splu_t

contains

  !> Allocate for an n x n matrix whose entries (rows(e), cols(e)) may be non-zero.
  !! status MBD_SINGULAR (with msg) when an entry is listed twice (the caller then keeps a
  !! dense LU: the values are written, not summed), MBD_NO_MEMORY on a failed allocation.
  subroutine splu_init(n, rows, cols, sp, status, msg)
    integer, intent(in) :: n                      !! order
    integer, intent(in) :: rows(:), cols(:)       !! structure of A
    type(splu_t), intent(out) :: sp               !! plan and work arrays
    integer, intent(out) :: status                !! MBD_OK, MBD_SINGULAR or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(inout) :: msg  !! explanation (on a failure)
    integer :: e, ierr, nn
    status = MBD_OK
    sp%n = n
    nn = n * n
    allocate (sp%struct(n, n), sp%seen(n, n), sp%at(n, n), sp%val(nn), sp%rinv(n), &
              sp%y(n), sp%y2(n), sp%prow(n), sp%pcol(n), sp%diag(n), sp%lptr(n + 1), sp%lpos(nn), &
              sp%lrow(nn), sp%uptr(n + 1), sp%upos(nn), sp%urow(nn), sp%optr(n + 1), &
              sp%fill(nn), sp%a(n, n), sp%s(n, n), sp%lcol(nn), sp%bpos(nn), sp%brow(nn), &
              sp%bcol(nn), sp%y4(4, n), sp%lrptr(n + 1), sp%lrpos(nn), sp%lrcol(nn), &
              sp%urptr(n + 1), sp%urpos(nn), sp%urcol(nn), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * 4 * real(nn, wp), 'the sparse LU of J', &
                    'use a smaller model', status, msg)
      return
    end if
    sp%struct = .false.; sp%seen = .false.; sp%at = 0; sp%val = zero
    do e = 1, size(rows)
      if (sp%struct(rows(e), cols(e))) then
        status = MBD_SINGULAR; msg = 'an entry of J is written twice'; return
      end if
      sp%struct(rows(e), cols(e)) = .true.
    end do
  end subroutine splu_init

  !> Plan on the numeric matrix a (threshold Markowitz, see the module banner). The pattern
  !! grows by the structural entries non-zero in a. status MBD_SINGULAR when some step finds
  !! no non-zero pivot (the caller factors densely instead), MBD_NO_MEMORY when the updates
  !! need more room than one allocation gave.
  subroutine splu_plan(sp, a, status, msg)
    type(splu_t), intent(inout) :: sp             !! plan (replaced)
    real(wp), intent(in) :: a(:, :)               !! A (n x n)
    integer, intent(out) :: status                !! MBD_OK, MBD_SINGULAR or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(inout) :: msg  !! explanation (on a failure)
    integer :: n, k, i, j, r, c, bi, bj, cost, best, nr, nc, p, ierr, nops
    real(wp) :: cmax, f, brel
    logical, allocatable :: ract(:), cact(:)
    integer, allocatable :: otgt(:), ol(:), ou(:)
    integer :: srow(sp%n), scol(sp%n)    ! step of A's row i, column j
    integer :: rcnt(sp%n), ccnt(sp%n)    ! active entries of row i, column j in the pattern
    status = MBD_OK
    sp%planned = .false.
    n = sp%n
    allocate (ract(n), cact(n), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(8 * real(n, wp), 'the sparse LU plan', 'use a smaller model', status, msg)
      return
    end if
    sp%seen = sp%seen .or. (sp%struct .and. a /= zero)
    sp%s = sp%seen
    sp%a = a
    ract = .true.; cact = .true.
    sp%sgn = 1
    nops = 0
    do i = 1, n
      rcnt(i) = count(sp%s(i, :)); ccnt(i) = count(sp%s(:, i))
    end do
    ! elimination on the pattern (with fill) and the values, choosing the pivots
    do k = 1, n
      best = huge(1); bi = 0; bj = 0; brel = zero
      do j = 1, n
        if (.not. cact(j)) cycle
        cmax = zero
        do i = 1, n
          if (ract(i) .and. sp%s(i, j)) cmax = max(cmax, abs(sp%a(i, j)))
        end do
        if (.not. cmax > zero) cycle
        nc = ccnt(j) - 1
        do i = 1, n
          if (.not. (ract(i) .and. sp%s(i, j))) cycle
          if (abs(sp%a(i, j)) < TAU * cmax) cycle
          nr = rcnt(i) - 1
          cost = nr * nc
          ! ties: the larger pivot relative to its column
          if (cost < best .or. (cost == best .and. abs(sp%a(i, j)) / cmax > brel)) then
            best = cost; bi = i; bj = j; brel = abs(sp%a(i, j)) / cmax
          end if
        end do
      end do
      if (bi == 0) then
        status = MBD_SINGULAR; msg = 'no non-zero pivot'; return
      end if
      sp%prow(k) = bi; sp%pcol(k) = bj
      ract(bi) = .false.; cact(bj) = .false.
      ! the counts without the pivot's row and column (kept for the active ones only)
      do j = 1, n
        if (cact(j) .and. sp%s(bi, j)) ccnt(j) = ccnt(j) - 1
      end do
      do i = 1, n
        if (ract(i) .and. sp%s(i, bj)) rcnt(i) = rcnt(i) - 1
      end do
      do i = 1, n
        if (.not. (ract(i) .and. sp%s(i, bj))) cycle
        f = sp%a(i, bj) / sp%a(bi, bj)
        do j = 1, n
          if (.not. (cact(j) .and. sp%s(bi, j))) cycle
          if (.not. sp%s(i, j)) then        ! fill
            rcnt(i) = rcnt(i) + 1; ccnt(j) = ccnt(j) + 1
          end if
          sp%s(i, j) = .true.
          sp%a(i, j) = sp%a(i, j) - f * sp%a(bi, j)
          nops = nops + 1
        end do
      end do
    end do
    sp%sgn = perm_sign(sp%prow) * perm_sign(sp%pcol)
    do k = 1, n
      srow(sp%prow(k)) = k; scol(sp%pcol(k)) = k
    end do
    ! positions: step column by step column, U part (rows < k), diagonal, L part (rows > k)
    sp%at = 0
    p = 0
    sp%nfill = 0
    sp%lptr(1) = 1; sp%uptr(1) = 1
    do c = 1, n
      sp%lptr(c + 1) = sp%lptr(c); sp%uptr(c + 1) = sp%uptr(c)
      do r = 1, n
        i = sp%prow(r); j = sp%pcol(c)
        if (.not. sp%s(i, j)) cycle
        p = p + 1
        sp%at(i, j) = p
        if (.not. sp%seen(i, j)) then
          sp%nfill = sp%nfill + 1; sp%fill(sp%nfill) = p
        end if
        if (r < c) then
          sp%upos(sp%uptr(c + 1)) = p; sp%urow(sp%uptr(c + 1)) = r
          sp%uptr(c + 1) = sp%uptr(c + 1) + 1
        else if (r == c) then
          sp%diag(c) = p
        else
          sp%lpos(sp%lptr(c + 1)) = p; sp%lrow(sp%lptr(c + 1)) = r
          sp%lcol(sp%lptr(c + 1)) = c
          sp%lptr(c + 1) = sp%lptr(c + 1) + 1
        end if
      end do
    end do
    sp%nnz = p
    sp%nu = 0
    do c = n, 1, -1
      do p = sp%uptr(c), sp%uptr(c + 1) - 1
        sp%nu = sp%nu + 1
        sp%bpos(sp%nu) = sp%upos(p); sp%brow(sp%nu) = sp%urow(p); sp%bcol(sp%nu) = c
      end do
    end do
    call by_rows(n, sp%lptr(n + 1) - 1, sp%lrow, sp%lcol, sp%lpos, sp%lrptr, sp%lrcol, &
                 sp%lrpos)
    call by_rows(n, sp%nu, sp%brow, sp%bcol, sp%bpos, sp%urptr, sp%urcol, sp%urpos)
    ! the updates of step k: a(r, c) -= l(r, k) u(k, c) for r, c > k in the pattern
    if (allocated(sp%otgt)) deallocate (sp%otgt, sp%ol, sp%ou)
    allocate (otgt(max(nops, 1)), ol(max(nops, 1)), ou(max(nops, 1)), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(12 * real(nops, wp), 'the sparse LU plan', 'use a smaller model', &
                    status, msg)
      return
    end if
    call move_alloc(otgt, sp%otgt); call move_alloc(ol, sp%ol); call move_alloc(ou, sp%ou)
    nops = 0
    sp%optr(1) = 1
    do k = 1, n
      do c = k + 1, n
        if (sp%at(sp%prow(k), sp%pcol(c)) == 0) cycle
        do p = sp%lptr(k), sp%lptr(k + 1) - 1
          r = sp%lrow(p)
          nops = nops + 1
          sp%otgt(nops) = sp%at(sp%prow(r), sp%pcol(c))
          sp%ol(nops) = sp%lpos(p)
          sp%ou(nops) = sp%at(sp%prow(k), sp%pcol(c))
        end do
      end do
      sp%optr(k + 1) = nops + 1
    end do
    sp%nops = nops
    ! the values of a in place, ready for splu_factor
    do j = 1, n
      do i = 1, n
        if (sp%at(i, j) > 0) sp%val(sp%at(i, j)) = a(i, j)
      end do
    end do
    sp%planned = .true.
  end subroutine splu_plan

  !> The entries (row(e), col(e), pos(e)), e = 1 .. ne, grouped by row (a counting sort that
  !! keeps their order within a row): row a's are rptr(a) .. rptr(a + 1) - 1 of rcol, rpos.
  pure subroutine by_rows(n, ne, row, col, pos, rptr, rcol, rpos)
    integer, intent(in) :: n, ne
    integer, intent(in) :: row(:), col(:), pos(:)
    integer, intent(out) :: rptr(n + 1)
    integer, intent(inout) :: rcol(:), rpos(:)
    integer :: e, a, nxt(n)
    rptr = 0
    do e = 1, ne
      rptr(row(e) + 1) = rptr(row(e) + 1) + 1
    end do
    rptr(1) = 1
    do a = 1, n
      rptr(a + 1) = rptr(a + 1) + rptr(a)
    end do
    nxt = rptr(1:n)
    do e = 1, ne
      a = row(e)
      rcol(nxt(a)) = col(e); rpos(nxt(a)) = pos(e)
      nxt(a) = nxt(a) + 1
    end do
  end subroutine by_rows

  !> Factor the values in sp%val (A's entries at sp%at, written by the caller) in place.
  !! status MBD_SINGULAR on an exactly zero pivot. lmax: largest |l_ik|; detsign: sign of
  !! det A; ratio: min |u_kk| / max |u_kk|.
  pure subroutine splu_factor(sp, status, lmax, detsign, ratio)
    type(splu_t), intent(inout) :: sp     !! plan and values
    integer, intent(out) :: status        !! MBD_OK or MBD_SINGULAR
    real(wp), intent(out) :: lmax         !! largest multiplier
    integer, intent(out) :: detsign       !! sign of det A
    real(wp), intent(out) :: ratio        !! min |u_kk| / max |u_kk|
    integer :: nl
    nl = sp%lptr(sp%n + 1) - 1
    call factor_kernel(sp%n, nl, sp%nops, sp%nfill, sp%nu, sp%diag, sp%lptr, sp%lpos, &
                       sp%optr, sp%otgt, sp%ol, sp%ou, sp%fill, sp%bpos, sp%bcol, sp%val, &
                       sp%rinv, status, lmax, detsign, ratio)
    if (sp%sgn < 0) detsign = -detsign
  end subroutine splu_factor

  !> splu_factor on plain arrays (explicit shapes: no descriptors in the loops).
  pure subroutine factor_kernel(n, nl, nops, nfill, nu, diag, lptr, lpos, optr, otgt, ol, ou, &
                                fill, bpos, bcol, val, rinv, status, lmax, detsign, ratio)
    integer, intent(in) :: n, nl, nops, nfill, nu
    integer, intent(in) :: diag(n), lptr(n + 1), lpos(nl), optr(n + 1), otgt(nops), ol(nops)
    integer, intent(in) :: ou(nops), fill(nfill), bpos(nu), bcol(nu)
    real(wp), intent(inout) :: val(*)
    real(wp), intent(out) :: rinv(n)
    integer, intent(out) :: status, detsign
    real(wp), intent(out) :: lmax, ratio
    integer :: k, p, o
    real(wp) :: d, r, l, umin, umax
    status = MBD_OK
    lmax = zero; detsign = 1; umin = huge(one); umax = zero; ratio = zero
    do p = 1, nfill
      val(fill(p)) = zero
    end do
    do k = 1, n
      d = val(diag(k))
      if (.not. abs(d) > zero) then
        status = MBD_SINGULAR; return
      end if
      if (d < zero) detsign = -detsign
      umin = min(umin, abs(d)); umax = max(umax, abs(d))
      r = one / d
      rinv(k) = r
      do p = lptr(k), lptr(k + 1) - 1                ! l_ik = a_ik / u_kk
        l = val(lpos(p)) * r
        val(lpos(p)) = l
        lmax = max(lmax, abs(l))
      end do
      do o = optr(k), optr(k + 1) - 1                ! a_ij -= l_ik u_kj
        val(otgt(o)) = val(otgt(o)) - val(ol(o)) * val(ou(o))
      end do
    end do
    do p = 1, nu                                     ! U1 = U diag(1/u_kk)
      val(bpos(p)) = val(bpos(p)) * rinv(bcol(p))
    end do
    ratio = umin / umax
  end subroutine factor_kernel

  !> x = A^-1 b with the factors; x(j) is multiplied by cs(j) (the solution of a
  !! column-scaled A D: x = D (A D)^-1 b; cs = 1 for A itself).
  pure subroutine splu_solve(sp, b, x, cs)
    type(splu_t), intent(inout) :: sp                !! factors (and the work vector)
    real(wp), intent(in) :: b(:)                     !! right-hand side (A's rows)
    real(wp), intent(inout) :: x(:)                  !! solution (A's columns)
    real(wp), intent(in) :: cs(:)                    !! column scale
    call solve_kernel(sp%n, sp%lptr(sp%n + 1) - 1, sp%nu, sp%prow, sp%pcol, sp%lpos, &
                      sp%lrow, sp%lcol, sp%bpos, sp%brow, sp%bcol, sp%rinv, sp%val, sp%y, b, &
                      x, cs)
  end subroutine splu_solve

  !> splu_solve on plain arrays.
  pure subroutine solve_kernel(n, nl, nu, prow, pcol, lpos, lrow, lcol, bpos, brow, bcol, &
                               rinv, val, y, b, x, cs)
    integer, intent(in) :: n, nl, nu
    integer, intent(in) :: prow(n), pcol(n), lpos(nl), lrow(nl), lcol(nl)
    integer, intent(in) :: bpos(nu), brow(nu), bcol(nu)
    real(wp), intent(in) :: rinv(n), val(*), b(n), cs(n)
    real(wp), intent(out) :: y(n), x(n)
    integer :: k, p
    do k = 1, n                                      ! y = P b
      y(k) = b(prow(k))
    end do
    do p = 1, nl                                     ! L z = y (unit diagonal)
      y(lrow(p)) = y(lrow(p)) - val(lpos(p)) * y(lcol(p))
    end do
    do p = 1, nu                                     ! U1 v = z
      y(brow(p)) = y(brow(p)) - val(bpos(p)) * y(bcol(p))
    end do
    do k = 1, n                                      ! x = D Q diag(1/u_kk) v
      x(pcol(k)) = y(k) * (rinv(k) * cs(pcol(k)))
    end do
  end subroutine solve_kernel

  !> X = D A^-1 B for several right-hand sides given as rows, bt = B^T (a multiple of 4 rows,
  !! padding zero), four at a time through the factors (each column's operations those of
  !! splu_solve, in the same order); x (n, ncol) takes the first ncol of them, each entry
  !! multiplied by that of f (n, ncol), and xt (4 k, n), when present, all of them as rows
  !! (without f). acc gets the sum of x's entries added (a check of their finiteness taken
  !! while they are in registers).
  pure subroutine splu_solve_rows(sp, bt, x, cs, f, acc, xt)
    type(splu_t), intent(inout) :: sp                !! factors (and the work block)
    real(wp), intent(in), contiguous :: bt(:, :)     !! right-hand sides as rows (4 k, n)
    real(wp), intent(inout), contiguous :: x(:, :)   !! solutions (A's columns, ncol)
    real(wp), intent(in), contiguous :: cs(:)        !! column scale
    real(wp), intent(in), contiguous :: f(:, :)      !! output factors (n, ncol)
    real(wp), intent(inout) :: acc                   !! sum of the outputs (added to)
    !> solutions as rows (4 k, n)
    real(wp), intent(inout), contiguous, optional :: xt(:, :)
    integer :: g
    do g = 1, size(bt, 1) - 3, 4
      if (g > size(x, 2)) exit
      call rows_kernel(sp%n, sp%lptr(sp%n + 1) - 1, sp%nu, sp%prow, sp%lrptr, sp%lrpos, &
                       sp%lrcol, sp%urptr, sp%urpos, sp%urcol, sp%val, sp%y4, size(bt, 1), bt, g)
      if (present(xt)) then
        call rows_out(sp%n, size(x, 2), sp%pcol, sp%rinv, cs, sp%y4, size(xt, 1), xt, g, x, f, &
                      acc)
      else
        call cols_out(sp%n, size(x, 2), sp%pcol, sp%rinv, cs, sp%y4, g, x, f, acc)
      end if
    end do
  end subroutine splu_solve_rows

  !> splu_solve_rows for four right-hand sides B - H1 S (- 2 H2 S2 when both), B's rows in
  !! bt (4, n), S and S2 as rows st, sdt (4, *), H1 and H2 sparse by rows: row r's entries
  !! he(hp(r) .. hp(r + 1) - 1), values h1(he), h2(he), columns hc. Each row of the
  !! right-hand side is formed, in registers, as the forward pass reaches it (the same
  !! operations, in the same order, as forming it first).
  pure subroutine splu_solve_rows_h(sp, bt, hp, he, hc, h1, h2, both, st, sdt, x, cs, f, acc, &
                                    xt)
    type(splu_t), intent(inout) :: sp                !! factors (and the work block)
    real(wp), intent(in), contiguous :: bt(:, :)     !! B as rows (4, n)
    integer, intent(in), contiguous :: hp(:), he(:), hc(:)  !! H by rows
    real(wp), intent(in) :: h1(*), h2(*)             !! H's values (by he)
    logical, intent(in) :: both                      !! the H2 S2 term too
    real(wp), intent(in), contiguous :: st(:, :), sdt(:, :)  !! S, S2 as rows (4, *)
    real(wp), intent(inout), contiguous :: x(:, :)   !! solutions (A's columns, ncol <= 4)
    real(wp), intent(in), contiguous :: cs(:)        !! column scale
    real(wp), intent(in), contiguous :: f(:, :)      !! output factors (n, ncol)
    real(wp), intent(inout) :: acc                   !! sum of the outputs (added to)
    real(wp), intent(inout), contiguous, optional :: xt(:, :)  !! solutions as rows (4, n)
    call rows_kernel_h(sp%n, sp%lptr(sp%n + 1) - 1, sp%nu, sp%prow, sp%lrptr, sp%lrpos, &
                       sp%lrcol, sp%urptr, sp%urpos, sp%urcol, sp%val, sp%y4, bt, hp, he, hc, &
                       h1, h2, both, st, sdt)
    if (present(xt)) then
      call rows_out(sp%n, size(x, 2), sp%pcol, sp%rinv, cs, sp%y4, 4, xt, 1, x, f, acc)
    else
      call cols_out(sp%n, size(x, 2), sp%pcol, sp%rinv, cs, sp%y4, 1, x, f, acc)
    end if
  end subroutine splu_solve_rows_h

  !> rows_kernel with each row of the right-hand side formed where the forward pass takes
  !! it: b(:, r) - sum of h1 st(:, c) (+ 2 h2 sdt(:, c)) over H's row r (splu_solve_rows_h).
  !! (Its L and U passes are rows_kernel's written again on purpose: one kernel for both,
  !! called from two places, is no longer inlined: +430 instructions per kinematic output.)
  pure subroutine rows_kernel_h(n, nl, nu, prow, lrptr, lrpos, lrcol, urptr, urpos, urcol, &
                                val, y, bt, hp, he, hc, h1, h2, both, st, sdt)
    integer, intent(in) :: n, nl, nu
    integer, intent(in) :: prow(n), lrptr(n + 1), lrpos(nl), lrcol(nl)
    integer, intent(in) :: urptr(n + 1), urpos(nu), urcol(nu), hp(n + 1), he(*), hc(*)
    real(wp), intent(in) :: val(*), bt(4, n), h1(*), h2(*), st(4, *), sdt(4, *)
    logical, intent(in) :: both
    real(wp), intent(out) :: y(4, n)
    integer :: a, p, c, j, k
    real(wp) :: v, w, t1, t2, t3, t4
    do a = 1, n                                      ! L z = P (b - H s), by rows
      c = prow(a)
      t1 = bt(1, c); t2 = bt(2, c); t3 = bt(3, c); t4 = bt(4, c)
      do p = hp(c), hp(c + 1) - 1
        j = he(p); k = hc(p); v = h1(j)
        if (both) then
          w = 2 * h2(j)
          t1 = t1 - v * st(1, k) - w * sdt(1, k); t2 = t2 - v * st(2, k) - w * sdt(2, k)
          t3 = t3 - v * st(3, k) - w * sdt(3, k); t4 = t4 - v * st(4, k) - w * sdt(4, k)
        else
          t1 = t1 - v * st(1, k); t2 = t2 - v * st(2, k)
          t3 = t3 - v * st(3, k); t4 = t4 - v * st(4, k)
        end if
      end do
      do p = lrptr(a), lrptr(a + 1) - 1
        v = val(lrpos(p)); c = lrcol(p)
        t1 = t1 - v * y(1, c); t2 = t2 - v * y(2, c)
        t3 = t3 - v * y(3, c); t4 = t4 - v * y(4, c)
      end do
      y(1, a) = t1; y(2, a) = t2; y(3, a) = t3; y(4, a) = t4
    end do
    do a = n, 1, -1                                  ! U1 v = z, by rows
      t1 = y(1, a); t2 = y(2, a); t3 = y(3, a); t4 = y(4, a)
      do p = urptr(a), urptr(a + 1) - 1
        v = val(urpos(p)); c = urcol(p)
        t1 = t1 - v * y(1, c); t2 = t2 - v * y(2, c)
        t3 = t3 - v * y(3, c); t4 = t4 - v * y(4, c)
      end do
      y(1, a) = t1; y(2, a) = t2; y(3, a) = t3; y(4, a) = t4
    end do
  end subroutine rows_kernel_h

  !> Four right-hand sides (rows g .. g + 3 of bt) through L and U1: y (4, n) in step
  !! order, before the pivots and the column permutation (rows_out, cols_out).
  pure subroutine rows_kernel(n, nl, nu, prow, lrptr, lrpos, lrcol, urptr, urpos, urcol, &
                              val, y, ldb, bt, g)
    integer, intent(in) :: n, nl, nu, g, ldb
    integer, intent(in) :: prow(n), lrptr(n + 1), lrpos(nl), lrcol(nl)
    integer, intent(in) :: urptr(n + 1), urpos(nu), urcol(nu)
    real(wp), intent(in) :: val(*), bt(ldb, n)
    real(wp), intent(out) :: y(4, n)
    integer :: a, p, c
    real(wp) :: v, t1, t2, t3, t4
    ! (the four columns written out: array sections of extent 4 cost a loop each)
    do a = 1, n                                      ! L z = P b (unit diagonal), by rows
      c = prow(a)
      t1 = bt(g, c); t2 = bt(g + 1, c); t3 = bt(g + 2, c); t4 = bt(g + 3, c)
      do p = lrptr(a), lrptr(a + 1) - 1
        v = val(lrpos(p)); c = lrcol(p)
        t1 = t1 - v * y(1, c); t2 = t2 - v * y(2, c)
        t3 = t3 - v * y(3, c); t4 = t4 - v * y(4, c)
      end do
      y(1, a) = t1; y(2, a) = t2; y(3, a) = t3; y(4, a) = t4
    end do
    do a = n, 1, -1                                  ! U1 v = z, by rows
      t1 = y(1, a); t2 = y(2, a); t3 = y(3, a); t4 = y(4, a)
      do p = urptr(a), urptr(a + 1) - 1
        v = val(urpos(p)); c = urcol(p)
        t1 = t1 - v * y(1, c); t2 = t2 - v * y(2, c)
        t3 = t3 - v * y(3, c); t4 = t4 - v * y(4, c)
      end do
      y(1, a) = t1; y(2, a) = t2; y(3, a) = t3; y(4, a) = t4
    end do
  end subroutine rows_kernel

  !> x = D Q diag(1/u_kk) v of rows_kernel's four solutions as rows g .. g + 3 of xt and,
  !! times f, as columns g .. of x (as many as x has).
  pure subroutine rows_out(n, ncol, pcol, rinv, cs, y, ldt, xt, g, x, f, acc)
    integer, intent(in) :: n, ncol, pcol(n), ldt, g
    real(wp), intent(in) :: rinv(n), cs(n), y(4, n), f(n, ncol)
    real(wp), intent(inout) :: xt(ldt, n), x(n, ncol), acc
    integer :: k, c
    real(wp) :: v, z1, z2, z3, z4
    if (ncol - g < 3) then
      call rows_out_part(n, ncol, pcol, rinv, cs, y, ldt, xt, g, x, f, acc)
      return
    end if
    do k = 1, n
      c = pcol(k); v = rinv(k) * cs(c)
      z1 = y(1, k) * v; z2 = y(2, k) * v; z3 = y(3, k) * v; z4 = y(4, k) * v
      xt(g, c) = z1; xt(g + 1, c) = z2; xt(g + 2, c) = z3; xt(g + 3, c) = z4
      z1 = z1 * f(c, g); z2 = z2 * f(c, g + 1); z3 = z3 * f(c, g + 2); z4 = z4 * f(c, g + 3)
      x(c, g) = z1; x(c, g + 1) = z2; x(c, g + 2) = z3; x(c, g + 3) = z4
      acc = acc + ((z1 + z2) + (z3 + z4))
    end do
  end subroutine rows_out

  !> rows_out for a last group of fewer than four columns.
  pure subroutine rows_out_part(n, ncol, pcol, rinv, cs, y, ldt, xt, g, x, f, acc)
    integer, intent(in) :: n, ncol, pcol(n), ldt, g
    real(wp), intent(in) :: rinv(n), cs(n), y(4, n), f(n, ncol)
    real(wp), intent(inout) :: xt(ldt, n), x(n, ncol), acc
    integer :: k, c, i
    real(wp) :: v
    do k = 1, n
      c = pcol(k); v = rinv(k) * cs(c)
      xt(g, c) = y(1, k) * v; xt(g + 1, c) = y(2, k) * v
      xt(g + 2, c) = y(3, k) * v; xt(g + 3, c) = y(4, k) * v
    end do
    do i = 1, ncol - g + 1
      do c = 1, n
        x(c, g + i - 1) = xt(g + i - 1, c) * f(c, g + i - 1)
        acc = acc + x(c, g + i - 1)
      end do
    end do
  end subroutine rows_out_part

  !> Several right-hand sides as the rows of bt (4 k, n) with no column scale: the first
  !! nkeep entries of each solution as a row of xt (ldt, nkeep), written or (add) added.
  pure subroutine splu_solve_rows_t(sp, bt, nkeep, ldt, xt, add)
    type(splu_t), intent(inout) :: sp                !! factors (and the work block)
    real(wp), intent(in) :: bt(:, :)                 !! right-hand sides as rows (4 k, n)
    integer, intent(in) :: nkeep, ldt                !! entries kept, xt's leading dimension
    real(wp), intent(inout) :: xt(ldt, *)            !! solutions as rows
    logical, intent(in) :: add                       !! add to xt (else overwrite)
    integer :: g
    do g = 1, size(bt, 1) - 3, 4
      call rows_kernel_t(sp%n, sp%lptr(sp%n + 1) - 1, sp%nu, sp%prow, sp%lrptr, sp%lrpos, &
                         sp%lrcol, sp%urptr, sp%urpos, sp%urcol, sp%val, sp%y4, size(bt, 1), &
                         bt, g, nkeep, sp%pcol, sp%rinv, ldt, xt, add)
    end do
  end subroutine splu_solve_rows_t

  !> rows_kernel with the output of splu_solve_rows_t taken in its U pass: each row's four
  !! values, final there, go out (x = Q diag(1/u_kk) v, the entries c <= nkeep) as they are
  !! found. (A kernel of its own: rows_kernel, called only by splu_solve_rows, stays inlined
  !! there.)
  pure subroutine rows_kernel_t(n, nl, nu, prow, lrptr, lrpos, lrcol, urptr, urpos, urcol, &
                                val, y, ldb, bt, g, nkeep, pcol, rinv, ldt, xt, add)
    integer, intent(in) :: n, nl, nu, g, ldb, nkeep, ldt
    integer, intent(in) :: prow(n), lrptr(n + 1), lrpos(nl), lrcol(nl)
    integer, intent(in) :: urptr(n + 1), urpos(nu), urcol(nu), pcol(n)
    real(wp), intent(in) :: val(*), bt(ldb, n), rinv(n)
    real(wp), intent(out) :: y(4, n)
    real(wp), intent(inout) :: xt(ldt, *)
    logical, intent(in) :: add
    integer :: a, p, c
    real(wp) :: v, t1, t2, t3, t4
    do a = 1, n                                      ! L z = P b (unit diagonal), by rows
      c = prow(a)
      t1 = bt(g, c); t2 = bt(g + 1, c); t3 = bt(g + 2, c); t4 = bt(g + 3, c)
      do p = lrptr(a), lrptr(a + 1) - 1
        v = val(lrpos(p)); c = lrcol(p)
        t1 = t1 - v * y(1, c); t2 = t2 - v * y(2, c)
        t3 = t3 - v * y(3, c); t4 = t4 - v * y(4, c)
      end do
      y(1, a) = t1; y(2, a) = t2; y(3, a) = t3; y(4, a) = t4
    end do
    do a = n, 1, -1                                  ! U1 v = z, by rows, and out
      t1 = y(1, a); t2 = y(2, a); t3 = y(3, a); t4 = y(4, a)
      do p = urptr(a), urptr(a + 1) - 1
        v = val(urpos(p)); c = urcol(p)
        t1 = t1 - v * y(1, c); t2 = t2 - v * y(2, c)
        t3 = t3 - v * y(3, c); t4 = t4 - v * y(4, c)
      end do
      y(1, a) = t1; y(2, a) = t2; y(3, a) = t3; y(4, a) = t4
      c = pcol(a)
      if (c > nkeep) cycle
      v = rinv(a)
      if (add) then
        xt(g, c) = xt(g, c) + t1 * v; xt(g + 1, c) = xt(g + 1, c) + t2 * v
        xt(g + 2, c) = xt(g + 2, c) + t3 * v; xt(g + 3, c) = xt(g + 3, c) + t4 * v
      else
        xt(g, c) = t1 * v; xt(g + 1, c) = t2 * v; xt(g + 2, c) = t3 * v; xt(g + 3, c) = t4 * v
      end if
    end do
  end subroutine rows_kernel_t

  !> rows_out without the rows: columns g .. of x only (times f).
  pure subroutine cols_out(n, ncol, pcol, rinv, cs, y, g, x, f, acc)
    integer, intent(in) :: n, ncol, pcol(n), g
    real(wp), intent(in) :: rinv(n), cs(n), y(4, n), f(n, ncol)
    real(wp), intent(inout) :: x(n, ncol), acc
    integer :: k, c
    real(wp) :: v, z1, z2, z3, z4
    if (ncol - g < 3) then
      call cols_out_part(n, ncol, pcol, rinv, cs, y, g, x, f, acc)
      return
    end if
    do k = 1, n
      c = pcol(k); v = rinv(k) * cs(c)
      z1 = (y(1, k) * v) * f(c, g); z2 = (y(2, k) * v) * f(c, g + 1)
      z3 = (y(3, k) * v) * f(c, g + 2); z4 = (y(4, k) * v) * f(c, g + 3)
      x(c, g) = z1; x(c, g + 1) = z2; x(c, g + 2) = z3; x(c, g + 3) = z4
      acc = acc + ((z1 + z2) + (z3 + z4))
    end do
  end subroutine cols_out

  !> cols_out for a last group of fewer than four columns.
  pure subroutine cols_out_part(n, ncol, pcol, rinv, cs, y, g, x, f, acc)
    integer, intent(in) :: n, ncol, pcol(n), g
    real(wp), intent(in) :: rinv(n), cs(n), y(4, n), f(n, ncol)
    real(wp), intent(inout) :: x(n, ncol), acc
    integer :: k, c, i
    do i = 1, ncol - g + 1
      do k = 1, n
        c = pcol(k)
        x(c, g + i - 1) = (y(i, k) * (rinv(k) * cs(c))) * f(c, g + i - 1)
        acc = acc + x(c, g + i - 1)
      end do
    end do
  end subroutine cols_out_part

  !> x1 = -A^-1 b1 (a Newton correction from Phi = b1) and x2 = A^-1 b2 in one pass over the
  !! factors (as splu_solve, each x multiplied by the column scale cs).
  pure subroutine splu_solve2(sp, b1, b2, x1, x2, cs)
    type(splu_t), intent(inout) :: sp                !! factors (and the work vectors)
    real(wp), intent(in) :: b1(:), b2(:)             !! right-hand sides (A's rows)
    real(wp), intent(inout) :: x1(:), x2(:)          !! solutions (A's columns)
    real(wp), intent(in) :: cs(:)                    !! column scale
    call solve2_kernel(sp%n, sp%lptr(sp%n + 1) - 1, sp%nu, sp%prow, sp%pcol, sp%lpos, &
                       sp%lrow, sp%lcol, sp%bpos, sp%brow, sp%bcol, sp%rinv, sp%val, sp%y, &
                       sp%y2, b1, b2, x1, x2, cs)
  end subroutine splu_solve2

  !> splu_solve2 on plain arrays.
  pure subroutine solve2_kernel(n, nl, nu, prow, pcol, lpos, lrow, lcol, bpos, brow, bcol, &
                                rinv, val, y, z, b1, b2, x1, x2, cs)
    integer, intent(in) :: n, nl, nu
    integer, intent(in) :: prow(n), pcol(n), lpos(nl), lrow(nl), lcol(nl)
    integer, intent(in) :: bpos(nu), brow(nu), bcol(nu)
    real(wp), intent(in) :: rinv(n), val(*), b1(n), b2(n), cs(n)
    real(wp), intent(out) :: y(n), z(n), x1(n), x2(n)
    integer :: k, p
    real(wp) :: v
    do k = 1, n
      y(k) = -b1(prow(k)); z(k) = b2(prow(k))
    end do
    do p = 1, nl
      v = val(lpos(p))
      y(lrow(p)) = y(lrow(p)) - v * y(lcol(p)); z(lrow(p)) = z(lrow(p)) - v * z(lcol(p))
    end do
    do p = 1, nu
      v = val(bpos(p))
      y(brow(p)) = y(brow(p)) - v * y(bcol(p)); z(brow(p)) = z(brow(p)) - v * z(bcol(p))
    end do
    do k = 1, n
      v = rinv(k) * cs(pcol(k))
      x1(pcol(k)) = y(k) * v; x2(pcol(k)) = z(k) * v
    end do
  end subroutine solve2_kernel

  !> Position in sp%val that A(i, j) is written to, 0 when the plan does not hold it (the
  !! entry must then be zero: a fill position is zeroed before each factorization).
  pure integer function splu_pos(sp, i, j) result(p)
    type(splu_t), intent(in) :: sp   !! plan
    integer, intent(in) :: i, j      !! row and column of A
    p = 0
    if (sp%seen(i, j)) p = sp%at(i, j)
  end function splu_pos

  !> Sign of a permutation (cycle count).
  pure integer function perm_sign(p) result(sgn)
    integer, intent(in) :: p(:)   !! permutation of 1..n
    logical :: done(size(p))
    integer :: i, j, len
    sgn = 1
    done = .false.
    do i = 1, size(p)
      if (done(i)) cycle
      len = 0; j = i
      do while (.not. done(j))
        done(j) = .true.; j = p(j); len = len + 1
      end do
      if (mod(len, 2) == 0) sgn = -sgn
    end do
  end function perm_sign

end module mbd_splu
