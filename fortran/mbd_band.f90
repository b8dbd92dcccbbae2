!> mbd_band: a banded direct solver for the square constraint Jacobian J (n x n) of large
!! mechanisms. The structure is planned once (band_plan: ordering, band widths, storage); the
!! values are then assembled, factored and solved any number of times without allocation.
!!
!!   ordering   B = P_r J P_c^T,  B(prow(i), pcol(j)) = J(i, j)
!!              columns: reverse Cuthill-McKee on the graph of J^T J (columns j, k adjacent
!!              when a row touches both), each component started at a pseudo-peripheral
!!              node (George & Liu), neighbours visited by increasing degree
!!              rows: stably sorted by (lo, hi), (hi, lo) or (lo + hi, lo), where lo and hi
!!              are the first and last new column a row touches; the candidate with the
!!              smallest kl + ku (then the smallest kl) is kept. Sorting by lo minimizes kl
!!              and sorting by hi minimizes ku (an earliest-due-date exchange argument)
!!   widths     kl = max(prow(i) - pcol(j)),  ku = max(pcol(j) - prow(i))  over the nonzeros
!!   storage    B(p, q) in ab(kl + ku + 1 + p - q, q),  ldab = 2 kl + ku + 1 (dgbtrf layout;
!!              rows 1..kl are dgbtrf's room for the fill of the row swaps)
!!   factor     B = P L U (dgbtrf);  det J = det(P_r) det(P_c) det(P) prod u_ii
!!   solve      J x = b    <=>  B (P_c x) = P_r b          (dgbtrs 'N')
!!              J^T y = c  <=>  B^T (P_r y) = P_c c        (dgbtrs 'T')
!!   rcond      1 / (||B||_1 ||B^-1||_1), ||B^-1||_1 estimated by Hager-Higham (dlacn2) from
!!              solves (dgbtrs), or dgbcon on request; permutations keep both norms, so it
!!              is the rcond of J
!! Cost: factor ~ 2 n kl (kl + ku) flops, a solve ~ 2 n (2 kl + ku), storage n (2 kl + ku + 1).
!!
!! Usage: band_plan once per structure; then per Jacobian band_zero, add each nonzero of the
!! planned structure into ab by the storage rule above (the caller's assembly loop does it),
!! band_norm1 if rcond is wanted, band_factor, band_solve as often as needed (the factors are
!! kept), band_rcond.
!!
!! References: E. Cuthill, J. McKee, Reducing the bandwidth of sparse symmetric matrices (1969);
!! A. George, J. W. H. Liu, Computer Solution of Large Sparse Positive Definite Systems
!! (1981), ch. 4 (RCM and the pseudo-peripheral node); LAPACK Users' Guide, band storage.
module mbd_band
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_BAD_INPUT, MBD_SINGULAR, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_fail, mem_check
  use mbd_lapack, only: dgbtrf, dgbtrs, dgbcon, dlacn2
  use mbd_linsolve, only: lapack_status
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: band_t, band_plan, band_move, band_zero, band_norm1, band_factor, band_rcond, &
            band_solve, band_plan_perm, band_graph, band_rcm, band_matvec

  !> A planned band matrix: the ordering, the band storage, the factors and all workspace.
  type :: band_t
    integer :: n = 0, kl = 0, ku = 0, ldab = 0
    integer, allocatable :: prow(:)     !! prow(i): position of original row i in band order
    integer, allocatable :: pcol(:)     !! pcol(j): position of original column j
    real(wp), allocatable :: ab(:, :)   !! band storage (ldab, n), dgbtrf layout
    integer, allocatable :: ipiv(:)     !! dgbtrf's row interchanges (n)
    real(wp), allocatable :: work(:)    !! rcond workspace (3 n)
    integer, allocatable :: iwork(:)    !! rcond workspace (n)
    real(wp), allocatable :: rhs(:)     !! permuted right-hand side (n)
    integer :: perm_sign = 1            !! sign of the two permutations (det P_r det P_c)
    logical :: factored = .false.       !! ab holds the LU factors
    !> factor and solve in plain loops (band_lu, same pivoting and storage as dgbtf2 and
    !! dgbtrs): for narrow bands, where the BLAS calls per column cost more than the work
    logical :: plain = .false.
    integer :: kvu = 0                  !! upper width of U used by the last band_lu (<= kl+ku)
  end type band_t

contains

  !> Plan the band structure of J from its structural nonzeros: the ordering, kl and ku,
  !! and all storage. Allocates (once per structure, not in time loops).
  subroutine band_plan(n, rows, cols, b, status, msg)
    integer, intent(in) :: n                    !! size of the square J
    integer, intent(in) :: rows(:)              !! row of each nonzero (1-based, repeats allowed)
    integer, intent(in) :: cols(:)              !! column of each nonzero (same length)
    type(band_t), intent(out) :: b              !! the plan; n = 0 on failure
    integer, intent(out) :: status              !! MBD_OK, MBD_BAD_INPUT or MBD_SINGULAR
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, allocatable :: rptr(:), rcol(:), cptr(:), crow(:), aptr(:), adj(:), order(:)
    integer, allocatable :: prow(:), pcol(:)
    integer :: k, kl, ku, ierr
    character(len=*), parameter :: HINT = 'use a smaller model'
    status = MBD_OK; msg = ''
    if (n < 1) then
      status = MBD_BAD_INPUT
      write (msg, '(a,i0)') 'band_plan: the matrix size must be at least 1, got ', n
      return
    end if
    if (size(rows) /= size(cols)) then
      status = MBD_BAD_INPUT
      write (msg, '(a,i0,a,i0,a)') 'band_plan: ', size(rows), ' row indices but ', &
        size(cols), ' column indices'
      return
    end if
    do k = 1, size(rows)
      if (rows(k) < 1 .or. rows(k) > n .or. cols(k) < 1 .or. cols(k) > n) then
        status = MBD_BAD_INPUT
        write (msg, '(a,i0,a,i0,a,i0,a,i0)') 'band_plan: nonzero ', k, ' at (', rows(k), &
          ', ', cols(k), ') is outside 1..', n
        return
      end if
    end do

    ! structure by rows and by columns, repeats removed
    call compress(n, rows, cols, rptr, rcol, ierr)
    if (ierr == 0) call compress(n, cols, rows, cptr, crow, ierr)
    if (ierr /= 0) then
      call mem_fail(16 * (real(n, wp) + size(rows)), 'the band plan (structure of J)', HINT, &
                    status, msg)
      return
    end if
    do k = 1, n
      if (rptr(k + 1) == rptr(k)) then
        status = MBD_SINGULAR
        write (msg, '(a,i0,a)') 'Jacobian is structurally singular: row ', k, &
          ' has no nonzero'
        return
      end if
      if (cptr(k + 1) == cptr(k)) then
        status = MBD_SINGULAR
        write (msg, '(a,i0,a)') 'Jacobian is structurally singular: column ', k, &
          ' has no nonzero'
        return
      end if
    end do

    ! columns: reverse Cuthill-McKee on the structure of J^T J
    call column_graph(n, rptr, rcol, cptr, crow, aptr, adj, ierr)
    if (ierr == 0) allocate (order(n), pcol(n), prow(n), stat=ierr)
    if (ierr == 0) call rcm(n, aptr, adj, order, ierr)
    if (ierr /= 0) then
      call mem_fail(4 * (8 * real(n, wp) + size(rows)), 'the band ordering (graph of J^T J)', &
                    HINT, status, msg)
      return
    end if
    do k = 1, n
      pcol(order(k)) = k
    end do
    ! rows: follow their columns
    call order_rows(n, rptr, rcol, pcol, prow, kl, ku, ierr)
    if (ierr /= 0) then
      call mem_fail(4 * 8 * real(n, wp), 'the band ordering (rows)', HINT, status, msg)
      return
    end if

    call band_storage(n, kl, ku, prow, pcol, b, status, msg)
  end subroutine band_plan

  !> Plan a band matrix with a given ordering: B(prow(i), pcol(j)) = A(i, j) for the
  !! structural nonzeros (rows(k), cols(k)) of A; kl and ku follow from them. For a
  !! symmetric ordering of a structurally symmetric matrix (the saddle-point matrices of
  !! mbd_saddle) pass the same permutation twice. Allocates (once per structure).
  subroutine band_plan_perm(n, rows, cols, prow, pcol, b, status, msg)
    integer, intent(in) :: n                    !! size of the square A
    integer, intent(in) :: rows(:), cols(:)     !! structural nonzeros (1-based, repeats allowed)
    integer, intent(in) :: prow(:), pcol(:)     !! positions of the rows and columns (n each)
    type(band_t), intent(out) :: b              !! the plan; n = 0 on failure
    integer, intent(out) :: status              !! MBD_OK, MBD_BAD_INPUT or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, allocatable :: pr(:), pc(:)
    integer :: k, kl, ku, ierr
    status = MBD_OK; msg = ''
    if (n < 1 .or. size(rows) /= size(cols) .or. size(prow) /= n .or. size(pcol) /= n) then
      status = MBD_BAD_INPUT
      write (msg, '(a,i0)') 'band_plan_perm: inconsistent sizes for a matrix of size ', n
      return
    end if
    kl = 0; ku = 0
    do k = 1, size(rows)
      if (rows(k) < 1 .or. rows(k) > n .or. cols(k) < 1 .or. cols(k) > n) then
        status = MBD_BAD_INPUT
        write (msg, '(a,i0,a,i0,a,i0,a,i0)') 'band_plan_perm: nonzero ', k, ' at (', &
          rows(k), ', ', cols(k), ') is outside 1..', n
        return
      end if
      kl = max(kl, prow(rows(k)) - pcol(cols(k)))
      ku = max(ku, pcol(cols(k)) - prow(rows(k)))
    end do
    allocate (pr(n), pc(n), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(8 * real(n, wp), 'the band ordering', 'use a smaller model', status, msg)
      return
    end if
    pr = prow; pc = pcol
    call band_storage(n, kl, ku, pr, pc, b, status, msg)
  end subroutine band_plan_perm

  !> The storage and workspace of a planned band matrix (the permutations are moved in).
  subroutine band_storage(n, kl, ku, prow, pcol, b, status, msg)
    integer, intent(in) :: n, kl, ku
    integer, allocatable, intent(inout) :: prow(:), pcol(:)
    type(band_t), intent(inout) :: b
    integer, intent(out) :: status
    character(len=MSG_LEN), intent(inout) :: msg
    integer :: ldab, ierr, k
    ldab = 2 * kl + ku + 1
    ! storage (ldab, n) for the factors and 3 n + n + n reals, n + n integers of workspace
    call mem_check(REAL_BYTES * (real(ldab, wp) + 5) * n, 'the band storage of J', &
                   'the structure is not banded enough: use a smaller model', status, msg)
    if (status /= MBD_OK) return
    allocate (b%ab(ldab, n), b%ipiv(n), b%work(3 * n), b%iwork(n), b%rhs(n), stat=ierr)
    if (ierr /= 0) then
      write (msg, '(a,i0,a,i0,a,i0,a,i0,a)') 'the band storage of J (', ldab, ' x ', n, &
        '; kl = ', kl, ', ku = ', ku, ')'
      call mem_fail(REAL_BYTES * (real(ldab, wp) + 5) * n, trim(msg), &
                    'the structure is not banded enough: use a smaller model', status, msg)
      return
    end if
    b%ab = zero
    b%ipiv = 0
    b%n = n; b%kl = kl; b%ku = ku; b%ldab = ldab
    call perm_parity(prow, b%iwork, ierr)
    call perm_parity(pcol, b%iwork, k)
    b%perm_sign = ierr * k
    call move_alloc(prow, b%prow)
    call move_alloc(pcol, b%pcol)
  end subroutine band_storage

  !> Move a plan (and its storage) from one band_t to another without copying: an intrinsic
  !! assignment would allocate, and could not report a failure.
  pure subroutine band_move(from, to)
    type(band_t), intent(inout) :: from   !! plan; empty on return
    type(band_t), intent(inout) :: to     !! receives it
    to%n = from%n; to%kl = from%kl; to%ku = from%ku; to%ldab = from%ldab
    to%perm_sign = from%perm_sign; to%factored = from%factored; to%plain = from%plain
    to%kvu = from%kvu
    if (allocated(to%prow)) deallocate (to%prow)
    if (allocated(to%pcol)) deallocate (to%pcol)
    if (allocated(to%ab)) deallocate (to%ab)
    if (allocated(to%ipiv)) deallocate (to%ipiv)
    if (allocated(to%work)) deallocate (to%work)
    if (allocated(to%iwork)) deallocate (to%iwork)
    if (allocated(to%rhs)) deallocate (to%rhs)
    if (allocated(from%prow)) call move_alloc(from%prow, to%prow)
    if (allocated(from%pcol)) call move_alloc(from%pcol, to%pcol)
    if (allocated(from%ab)) call move_alloc(from%ab, to%ab)
    if (allocated(from%ipiv)) call move_alloc(from%ipiv, to%ipiv)
    if (allocated(from%work)) call move_alloc(from%work, to%work)
    if (allocated(from%iwork)) call move_alloc(from%iwork, to%iwork)
    if (allocated(from%rhs)) call move_alloc(from%rhs, to%rhs)
    from%n = 0; from%factored = .false.
  end subroutine band_move

  !> Clear the matrix before an assembly: the whole storage, the fill rows 1..kl included
  !! (band_lu relies on them being zero), in one contiguous pass (a section of rows kl+1..ldab
  !! is cleared column by column, a memset call per column, and band_lu cleared the fill rows
  !! column by column again).
  pure subroutine band_zero(b)
    type(band_t), intent(inout) :: b   !! planned band matrix
    if (.not. allocated(b%ab)) return
    b%ab = zero
    b%factored = .false.
  end subroutine band_zero

  !> ||J||_1 = max_j sum_i |J(i, j)| of the assembled matrix, for band_rcond. Call it before
  !! band_factor; on factors it returns -1 (and band_rcond refuses that).
  pure real(wp) function band_norm1(b) result(anorm)
    type(band_t), intent(in) :: b   !! assembled band matrix
    integer :: q
    anorm = zero
    if (b%factored) then
      anorm = -one
      return
    end if
    do q = 1, b%n
      anorm = max(anorm, sum(abs(b%ab(b%kl + 1:b%ldab, q))))
    end do
  end function band_norm1

  !> LU factorization in place, B = P L U (dgbtrf). On success the factors stay in b for
  !! band_solve and band_rcond until the next band_zero.
  !! With regularize, an exactly singular U (MBD_SINGULAR) is still kept as factors, its zero
  !! pivots replaced by eps max |u_ii|: solves with it then give the inverse-iteration
  !! direction of the null space (for a diagnosis, not for a solution).
  subroutine band_factor(b, status, msg, detsign, pivratio, regularize)
    type(band_t), intent(inout) :: b             !! assembled band matrix; factors on return
    integer, intent(out) :: status               !! MBD_OK, MBD_SINGULAR, MBD_BAD_INPUT or
                                                 !! MBD_LAPACK
    character(len=MSG_LEN), intent(out) :: msg   !! explanation
    integer, intent(out), optional :: detsign    !! sign of det J (original order); 0 if singular
    real(wp), intent(out), optional :: pivratio  !! min |u_ii| / max |u_ii|; 0 if singular
    logical, intent(in), optional :: regularize  !! keep singular factors (zero pivots lifted)
    integer :: info, k, sgn, d
    real(wp) :: u, umin, umax
    status = MBD_OK; msg = ''
    if (present(detsign)) detsign = 0
    if (present(pivratio)) pivratio = zero
    if (b%n < 1) then
      status = MBD_BAD_INPUT
      msg = 'band_factor: the band matrix has not been planned (band_plan)'
      return
    end if
    if (b%factored) then
      status = MBD_BAD_INPUT
      msg = 'band_factor: already factored; band_zero and assemble again first'
      return
    end if
    if (b%plain) then
      call band_lu(b%n, b%kl, b%ku, b%ab, b%ldab, b%ipiv, info, b%kvu)
    else
      call dgbtrf(b%n, b%n, b%kl, b%ku, b%ab, b%ldab, b%ipiv, info)
    end if
    if (info > 0) then
      ! U(info, info) = 0 exactly; name the original column of that pivot
      status = MBD_SINGULAR
      write (msg, '(a,i0,a,i0,a)') 'Jacobian is singular: band pivot ', info, &
        ' (column ', findloc(b%pcol, info, dim=1), ') is zero'
      if (.not. present(regularize)) return
      if (.not. regularize) return
      d = b%kl + b%ku + 1
      umax = maxval(abs(b%ab(d, :)))
      if (.not. umax > zero) umax = one
      do k = 1, b%n
        if (abs(b%ab(d, k)) < epsilon(one) * umax) b%ab(d, k) = epsilon(one) * umax
      end do
      b%factored = .true.
      return
    end if
    call lapack_status('dgbtrf', info, status, msg)
    if (status /= MBD_OK) return
    b%factored = .true.
    ! det B = (-1)**(row swaps) prod u_ii;  det J = det B det(P_r) det(P_c)
    d = b%kl + b%ku + 1
    sgn = b%perm_sign
    umin = huge(one); umax = zero
    do k = 1, b%n
      u = b%ab(d, k)
      if (u < zero) sgn = -sgn
      if (b%ipiv(k) /= k) sgn = -sgn
      umin = min(umin, abs(u)); umax = max(umax, abs(u))
    end do
    if (present(detsign)) detsign = sgn
    if (present(pivratio)) pivratio = umin / umax
  end subroutine band_factor

  !> Reciprocal condition number of J in the 1-norm, estimated from the factors:
  !! ||J^-1||_1 by Hager-Higham (dlacn2) with plain solves (dgbtrs), O(n (kl + ku)).
  !! dgbcon (careful) guards each solve against overflow, but its growth bound underflows
  !! after about a thousand columns, and it then takes O(n**2) (90 ms at n = 6000).
  !! Without careful, a solve that overflows (cond(J) > ~1e300) gives rcond = 0.
  subroutine band_rcond(b, anorm, rcond, status, msg, careful)
    type(band_t), intent(inout) :: b            !! factored band matrix (its workspace is used)
    real(wp), intent(in) :: anorm               !! ||J||_1 from band_norm1 before factoring
    real(wp), intent(out) :: rcond              !! 1 / (||J||_1 ||J^-1||_1) estimate
    integer, intent(out) :: status              !! MBD_OK, MBD_BAD_INPUT or MBD_LAPACK
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    logical, intent(in), optional :: careful    !! use dgbcon (default .false.)
    integer :: info, kase, isave(3), n
    real(wp) :: ainvnm
    logical :: use_gbcon
    status = MBD_OK; msg = ''
    rcond = zero
    if (.not. b%factored) then
      status = MBD_BAD_INPUT
      msg = 'band_rcond: the band matrix is not factored (band_factor)'
      return
    end if
    if (.not. (ieee_is_finite(anorm) .and. anorm >= zero)) then
      status = MBD_BAD_INPUT
      msg = 'band_rcond: anorm must be the finite band_norm1 taken before band_factor'
      return
    end if
    use_gbcon = .false.
    if (present(careful)) use_gbcon = careful
    if (use_gbcon) then
      call dgbcon('1', b%n, b%kl, b%ku, b%ab, b%ldab, b%ipiv, anorm, rcond, b%work, &
                  b%iwork, info)
      call lapack_status('dgbcon', info, status, msg)
      return
    end if
    if (anorm <= zero) return
    ! ||B^-1||_1 = ||J^-1||_1: kase 1 asks for B^-1 x, kase 2 for B^-T x
    n = b%n
    ainvnm = zero
    kase = 0
    isave = 0
    do
      call dlacn2(n, b%work(1:n), b%work(n + 1:2 * n), b%iwork, ainvnm, kase, isave)
      if (kase == 0) exit
      if (b%plain) then                       ! band_lu's factors: plain loops
        call band_lu_solve(n, b%kl, b%ku, b%ab, b%ldab, b%ipiv, b%work(n + 1:2 * n), b%kvu, &
                           trans=kase == 2)
      else
        call dgbtrs(merge('N', 'T', kase == 1), n, b%kl, b%ku, 1, b%ab, b%ldab, b%ipiv, &
                    b%work(n + 1:2 * n), n, info)
        call lapack_status('dgbtrs', info, status, msg)
        if (status /= MBD_OK) return
      end if
      if (.not. all(ieee_is_finite(b%work(n + 1:2 * n)))) return   ! overflow: rcond = 0
    end do
    if (ainvnm > zero .and. ieee_is_finite(ainvnm)) rcond = (one / ainvnm) / anorm
  end subroutine band_rcond

  !> Solve J x = b (or J^T x = b with transpose) with the factors; x is overwritten.
  subroutine band_solve(b, x, status, msg, transpose)
    type(band_t), intent(inout) :: b            !! factored band matrix (its rhs is used)
    real(wp), intent(inout) :: x(:)             !! in: right-hand side, indexed like the rows
                                                !! of J (its columns for transpose);
                                                !! out: solution, indexed like the columns
    integer, intent(out) :: status              !! MBD_OK, MBD_BAD_INPUT or MBD_LAPACK
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    logical, intent(in), optional :: transpose  !! solve J^T x = b (default .false.)
    integer :: info, i
    logical :: trans
    status = MBD_OK; msg = ''
    if (.not. b%factored) then
      status = MBD_BAD_INPUT
      msg = 'band_solve: the band matrix is not factored (band_factor)'
      return
    end if
    if (size(x) /= b%n) then
      status = MBD_BAD_INPUT
      write (msg, '(a,i0,a,i0)') 'band_solve: right-hand side of length ', size(x), &
        ', expected ', b%n
      return
    end if
    trans = .false.
    if (present(transpose)) trans = transpose
    ! (loops, not vector subscripts: those make gfortran allocate temporaries)
    if (trans) then
      ! B^T (P_r x) = P_c b
      do i = 1, b%n
        b%rhs(b%pcol(i)) = x(i)
      end do
      call dgbtrs('T', b%n, b%kl, b%ku, 1, b%ab, b%ldab, b%ipiv, b%rhs, b%n, info)
      do i = 1, b%n
        x(i) = b%rhs(b%prow(i))
      end do
    else
      ! B (P_c x) = P_r b
      do i = 1, b%n
        b%rhs(b%prow(i)) = x(i)
      end do
      if (b%plain) then
        call band_lu_solve(b%n, b%kl, b%ku, b%ab, b%ldab, b%ipiv, b%rhs, b%kvu)
        info = 0
      else
        call dgbtrs('N', b%n, b%kl, b%ku, 1, b%ab, b%ldab, b%ipiv, b%rhs, b%n, info)
      end if
      do i = 1, b%n
        x(i) = b%rhs(b%pcol(i))
      end do
    end if
    call lapack_status('dgbtrs', info, status, msg)
  end subroutine band_solve


  !> y = A x for an assembled (not factored) band matrix held in ab (a copy of b%ab taken
  !! before band_factor, or b%ab itself before it). A(i, j) = B(prow(i), pcol(j)).
  pure subroutine band_matvec(b, ab, x, y, xw)
    type(band_t), intent(in) :: b        !! the plan (permutations and widths)
    real(wp), intent(in) :: ab(:, :)     !! assembled band storage (ldab, n)
    real(wp), intent(in) :: x(:)         !! vector, indexed like the columns of A (n)
    real(wp), intent(out) :: y(:)        !! A x, indexed like the rows of A (n)
    real(wp), intent(inout) :: xw(:)     !! workspace (n)
    integer :: i, j, p, q, d
    real(wp) :: acc
    d = b%kl + b%ku + 1
    do j = 1, b%n                        ! x by column positions
      xw(b%pcol(j)) = x(j)
    end do
    do i = 1, b%n                        ! y_i = sum_q B(p, q) xw(q),  p = prow(i)
      p = b%prow(i)
      acc = zero
      do q = max(1, p - b%kl), min(b%n, p + b%ku)
        acc = acc + ab(d + p - q, q) * xw(q)
      end do
      y(i) = acc
    end do
  end subroutine band_matvec

  !> Symmetric adjacency lists of the graph of A + A^T (no self loops) from the structural
  !! nonzeros of A: the neighbours of node k are adj(aptr(k):aptr(k+1)-1).
  pure subroutine band_graph(n, rows, cols, aptr, adj, ierr)
    integer, intent(in) :: n                       !! number of nodes
    integer, intent(in) :: rows(:), cols(:)        !! structural nonzeros (1..n)
    integer, allocatable, intent(out) :: aptr(:)   !! n + 1 pointers
    integer, allocatable, intent(out) :: adj(:)    !! neighbours
    integer, intent(out) :: ierr                   !! allocation status (0 ok)
    integer, allocatable :: key(:), val(:), ptr(:), idx(:)
    integer :: k, m, w, i
    m = 0
    do k = 1, size(rows)
      if (rows(k) /= cols(k)) m = m + 2
    end do
    allocate (key(m), val(m), stat=ierr)
    if (ierr /= 0) return
    m = 0
    do k = 1, size(rows)
      if (rows(k) == cols(k)) cycle
      key(m + 1) = rows(k); val(m + 1) = cols(k)
      key(m + 2) = cols(k); val(m + 2) = rows(k)
      m = m + 2
    end do
    call compress(n, key, val, ptr, idx, ierr)
    if (ierr /= 0) return
    allocate (aptr(n + 1), adj(max(ptr(n + 1) - 1, 0)), stat=ierr)
    if (ierr /= 0) return
    w = 0
    do i = 1, n
      aptr(i) = w + 1
      do k = ptr(i), ptr(i + 1) - 1
        w = w + 1
        adj(w) = idx(k)
      end do
    end do
    aptr(n + 1) = w + 1
  end subroutine band_graph

  !> Reverse Cuthill-McKee ordering of a symmetric graph (band_graph): order(k) is the node
  !! placed k-th (each component from a pseudo-peripheral node).
  pure subroutine band_rcm(n, aptr, adj, order, ierr)
    integer, intent(in) :: n                 !! number of nodes
    integer, intent(in) :: aptr(:), adj(:)   !! adjacency
    integer, intent(out) :: order(:)         !! the ordering (n)
    integer, intent(out) :: ierr             !! allocation status (0 ok)
    call rcm(n, aptr, adj, order, ierr)
  end subroutine band_rcm

  !> LU factorization with partial pivoting of a band matrix in plain loops: dgbtf2's
  !! algorithm, storage and pivots (so dgbtrs and dgbcon read its factors), without its
  !! BLAS calls per column. info > 0: U(info, info) is exactly zero. kvu: the upper width
  !! of U the row interchanges actually filled (ku without any, at most kl + ku), so that
  !! band_lu_solve reads no more of U than it holds. The fill rows 1..kl of ab must be zero
  !! on entry (band_storage and band_zero clear the whole storage; dgbtf2 clears them itself).
  pure subroutine band_lu(n, kl, ku, ab, ldab, ipiv, info, kvu)
    integer, intent(in) :: n, kl, ku, ldab    !! size, widths, leading dimension (2kl+ku+1)
    real(wp), intent(inout) :: ab(ldab, n)    !! band matrix, then its factors
    integer, intent(out) :: ipiv(n)           !! row interchanges
    integer, intent(out) :: info              !! 0, or the first zero pivot
    integer, intent(out) :: kvu               !! upper width of U used
    integer :: kv, i, j, c, jp, km, ju, d
    real(wp) :: piv, f, tmp
    ! A(r, c) sits in ab(kv + 1 + r - c, c), kv = kl + ku (rows 1..kl: room for the fill)
    kv = ku + kl
    info = 0
    kvu = ku
    ju = 1
    do j = 1, n
      km = min(kl, n - j)
      jp = 0; piv = abs(ab(kv + 1, j))        ! pivot: the first largest |a_ij|, i >= j
      do i = 1, km
        if (abs(ab(kv + 1 + i, j)) > piv) then
          jp = i; piv = abs(ab(kv + 1 + i, j))
        end if
      end do
      ipiv(j) = j + jp
      if (.not. piv > zero) then
        if (info == 0) info = j
        cycle
      end if
      ju = max(ju, min(j + ku + jp, n))
      kvu = max(kvu, ju - j)
      if (jp /= 0) then                       ! swap rows j and j + jp in columns j..ju
        do c = j, ju
          d = kv + 1 + j - c
          tmp = ab(d, c); ab(d, c) = ab(d + jp, c); ab(d + jp, c) = tmp
        end do
      end if
      f = one / ab(kv + 1, j)                 ! l_ij = a_ij / u_jj
      do i = 1, km
        ab(kv + 1 + i, j) = ab(kv + 1 + i, j) * f
      end do
      do c = j + 1, ju                        ! a_ic -= l_ij u_jc
        d = kv + 1 + j - c
        f = ab(d, c)
        if (abs(f) <= zero) cycle
        do i = 1, km
          ab(d + i, c) = ab(d + i, c) - ab(kv + 1 + i, j) * f
        end do
      end do
    end do
  end subroutine band_lu

  !> Solve B x = r (or, with trans, B^T x = r: dgbtrs 'T') with the factors of band_lu (or
  !! dgbtrf) in plain loops; r becomes x. B x = r: the row interchanges and L forward, then U
  !! (upper width kvu) backward; B^T x = r: U^T forward, then L^T backward with the
  !! interchanges in reverse.
  pure subroutine band_lu_solve(n, kl, ku, ab, ldab, ipiv, r, kvu, trans)
    integer, intent(in) :: n, kl, ku, ldab    !! size, widths, leading dimension
    real(wp), intent(in) :: ab(ldab, n)       !! factors
    integer, intent(in) :: ipiv(n)            !! row interchanges
    real(wp), intent(inout) :: r(n)           !! right-hand side, then solution
    integer, intent(in) :: kvu                !! upper width of U (band_lu's)
    logical, intent(in), optional :: trans    !! solve B^T x = r (default .false.)
    integer :: kv, i, j, p
    real(wp) :: tmp, f
    kv = ku + kl
    if (present(trans)) then
      if (trans) then
        do j = 1, n                           ! U^T y = r: y_j = (r_j - sum_i u_ij y_i) / u_jj
          f = r(j)
          do i = max(1, j - kvu), j - 1
            f = f - ab(kv + 1 + i - j, j) * r(i)
          end do
          r(j) = f / ab(kv + 1, j)
        end do
        do j = n - 1, 1, -1                   ! L^T x = y, then P^T: x_j -= sum_i l_ij x_i
          f = r(j)
          do i = 1, min(kl, n - j)
            f = f - ab(kv + 1 + i, j) * r(j + i)
          end do
          r(j) = f
          p = ipiv(j)
          if (p /= j) then
            tmp = r(j); r(j) = r(p); r(p) = tmp
          end if
        end do
        return
      end if
    end if
    do j = 1, n - 1
      p = ipiv(j)
      if (p /= j) then
        tmp = r(j); r(j) = r(p); r(p) = tmp
      end if
      f = r(j)
      if (abs(f) <= zero) cycle
      do i = 1, min(kl, n - j)
        r(j + i) = r(j + i) - ab(kv + 1 + i, j) * f
      end do
    end do
    do j = n, 1, -1
      r(j) = r(j) / ab(kv + 1, j)
      f = r(j)
      if (abs(f) <= zero) cycle
      do i = max(1, j - kvu), j - 1
        r(i) = r(i) - ab(kv + 1 + i - j, j) * f
      end do
    end do
  end subroutine band_lu_solve

  ! ---------------------------------------------------------------------------------------
  ! ordering

  !> Compressed lists from (key, val) pairs: the distinct vals of key k are
  !! idx(ptr(k):ptr(k+1)-1), in first-seen order. Indices are in 1..n.
  pure subroutine compress(n, key, val, ptr, idx, ierr)
    integer, intent(in) :: n                       !! number of keys
    integer, intent(in) :: key(:), val(:)          !! pairs
    integer, allocatable, intent(out) :: ptr(:)    !! n + 1 pointers
    integer, allocatable, intent(out) :: idx(:)    !! values, repeats removed
    integer, intent(out) :: ierr                   !! allocation status (0 ok)
    integer, allocatable :: next(:), mark(:)
    integer :: k, i, k0, w
    allocate (ptr(n + 1), idx(size(key)), next(n), mark(n), stat=ierr)
    if (ierr /= 0) return
    ptr = 0
    do k = 1, size(key)
      ptr(key(k) + 1) = ptr(key(k) + 1) + 1
    end do
    ptr(1) = 1
    do i = 1, n
      ptr(i + 1) = ptr(i + 1) + ptr(i)
    end do
    next = ptr(1:n)
    do k = 1, size(key)
      idx(next(key(k))) = val(k)
      next(key(k)) = next(key(k)) + 1
    end do
    ! drop repeats in place (w <= k throughout)
    mark = 0
    w = 1
    do i = 1, n
      k0 = ptr(i)
      ptr(i) = w
      do k = k0, ptr(i + 1) - 1
        if (mark(idx(k)) /= i) then
          mark(idx(k)) = i
          idx(w) = idx(k)
          w = w + 1
        end if
      end do
    end do
    ptr(n + 1) = w
  end subroutine compress

  !> Adjacency of the column graph (the structure of J^T J without its diagonal).
  pure subroutine column_graph(n, rptr, rcol, cptr, crow, aptr, adj, ierr)
    integer, intent(in) :: n                      !! number of columns
    integer, intent(in) :: rptr(:), rcol(:)       !! columns of each row
    integer, intent(in) :: cptr(:), crow(:)       !! rows of each column
    integer, allocatable, intent(out) :: aptr(:)  !! n + 1 pointers
    integer, allocatable, intent(out) :: adj(:)   !! neighbours of each column
    integer, intent(out) :: ierr                  !! allocation status (0 ok)
    integer, allocatable :: mark(:)
    integer :: c, k, m, d, pass, w
    allocate (aptr(n + 1), mark(n), adj(0), stat=ierr)
    if (ierr /= 0) return
    do pass = 1, 2
      mark = 0
      w = 1
      do c = 1, n
        aptr(c) = w
        mark(c) = c
        do k = cptr(c), cptr(c + 1) - 1
          do m = rptr(crow(k)), rptr(crow(k) + 1) - 1
            d = rcol(m)
            if (mark(d) /= c) then
              mark(d) = c
              if (pass == 2) adj(w) = d
              w = w + 1
            end if
          end do
        end do
      end do
      aptr(n + 1) = w
      if (pass == 1) then
        deallocate (adj)
        allocate (adj(w - 1), stat=ierr)
        if (ierr /= 0) return
      end if
    end do
  end subroutine column_graph

  !> Reverse Cuthill-McKee: order(k) is the node placed k-th.
  pure subroutine rcm(n, aptr, adj, order, ierr)
    integer, intent(in) :: n                 !! number of nodes
    integer, intent(in) :: aptr(:), adj(:)   !! adjacency
    integer, intent(out) :: order(:)         !! the ordering (n)
    integer, intent(out) :: ierr             !! allocation status (0 ok)
    integer, allocatable :: deg(:), lvl(:), queue(:)
    logical, allocatable :: done(:)
    integer :: s, root, last, head, first, k, w, v, i, j
    allocate (deg(n), lvl(n), queue(n), done(n), stat=ierr)
    if (ierr /= 0) return
    deg = aptr(2:n + 1) - aptr(1:n)
    lvl = 0
    done = .false.
    last = 0
    do s = 1, n
      if (done(s)) cycle
      call peripheral(s, aptr, adj, deg, lvl, queue, root)
      ! Cuthill-McKee: breadth first, unnumbered neighbours by increasing degree
      last = last + 1
      order(last) = root
      done(root) = .true.
      head = last
      do while (head <= last)
        v = order(head)
        head = head + 1
        first = last + 1
        do k = aptr(v), aptr(v + 1) - 1
          w = adj(k)
          if (.not. done(w)) then
            done(w) = .true.
            last = last + 1
            order(last) = w
          end if
        end do
        do i = first + 1, last   ! stable insertion sort by degree
          w = order(i)
          j = i - 1
          do while (j >= first)
            if (deg(order(j)) <= deg(w)) exit
            order(j + 1) = order(j)
            j = j - 1
          end do
          order(j + 1) = w
        end do
      end do
    end do
    do i = 1, n / 2   ! reverse
      w = order(i); order(i) = order(n + 1 - i); order(n + 1 - i) = w
    end do
  end subroutine rcm

  !> A pseudo-peripheral node of the component of s (George & Liu): from the last level of
  !! the rooted level structure take a node of least degree; repeat while the number of
  !! levels (the eccentricity) grows.
  pure subroutine peripheral(s, aptr, adj, deg, lvl, queue, root)
    integer, intent(in) :: s                  !! a node of the component
    integer, intent(in) :: aptr(:), adj(:)    !! adjacency
    integer, intent(in) :: deg(:)             !! degrees
    integer, intent(inout) :: lvl(:)          !! zero on entry and on return
    integer, intent(inout) :: queue(:)        !! workspace
    integer, intent(out) :: root              !! the pseudo-peripheral node
    integer :: nlev, nlev_x, x, y
    root = s
    call levels(root, aptr, adj, deg, lvl, queue, nlev, x)
    do
      call levels(x, aptr, adj, deg, lvl, queue, nlev_x, y)
      if (nlev_x <= nlev) exit
      root = x; nlev = nlev_x; x = y
    end do
  end subroutine peripheral

  !> Rooted level structure: its number of levels and a least-degree node of the last one.
  pure subroutine levels(root, aptr, adj, deg, lvl, queue, nlev, x)
    integer, intent(in) :: root               !! root node
    integer, intent(in) :: aptr(:), adj(:)    !! adjacency
    integer, intent(in) :: deg(:)             !! degrees
    integer, intent(inout) :: lvl(:)          !! zero on entry and on return
    integer, intent(inout) :: queue(:)        !! workspace
    integer, intent(out) :: nlev              !! number of levels
    integer, intent(out) :: x                 !! least-degree node of the last level
    integer :: head, nq, v, w, k
    lvl(root) = 1
    queue(1) = root
    nq = 1
    head = 1
    do while (head <= nq)
      v = queue(head)
      head = head + 1
      do k = aptr(v), aptr(v + 1) - 1
        w = adj(k)
        if (lvl(w) == 0) then
          lvl(w) = lvl(v) + 1
          nq = nq + 1
          queue(nq) = w
        end if
      end do
    end do
    nlev = lvl(queue(nq))
    x = queue(nq)
    do k = nq - 1, 1, -1
      if (lvl(queue(k)) < nlev) exit
      if (deg(queue(k)) < deg(x)) x = queue(k)
    end do
    lvl(queue(1:nq)) = 0
  end subroutine levels

  !> Row positions from the column positions: the best of three stable sorts by the first
  !! (lo) and last (hi) new column of each row, by kl + ku and then kl.
  pure subroutine order_rows(n, rptr, rcol, pcol, prow, kl, ku, ierr)
    integer, intent(in) :: n                  !! number of rows
    integer, intent(in) :: rptr(:), rcol(:)   !! columns of each row
    integer, intent(in) :: pcol(:)            !! column positions
    integer, intent(out) :: prow(:)           !! row positions
    integer, intent(out) :: kl, ku            !! resulting band widths
    integer, intent(out) :: ierr              !! allocation status (0 ok)
    integer, allocatable :: lo(:), hi(:), mid(:), idx(:), tmp(:), cnt(:)
    integer :: r, k, cand, l, u
    kl = 0; ku = 0
    allocate (lo(n), hi(n), mid(n), idx(n), tmp(n), cnt(0:2 * n + 1), stat=ierr)
    if (ierr /= 0) return
    do r = 1, n
      lo(r) = n; hi(r) = 1
      do k = rptr(r), rptr(r + 1) - 1
        lo(r) = min(lo(r), pcol(rcol(k)))
        hi(r) = max(hi(r), pcol(rcol(k)))
      end do
      mid(r) = lo(r) + hi(r)
    end do
    kl = n; ku = n   ! above any candidate's (kl, ku <= n - 1)
    do cand = 1, 3
      do r = 1, n
        idx(r) = r
      end do
      select case (cand)
      case (1)   ! (lo, hi)
        call sort_stable(hi, idx, tmp, cnt)
        call sort_stable(lo, idx, tmp, cnt)
      case (2)   ! (hi, lo)
        call sort_stable(lo, idx, tmp, cnt)
        call sort_stable(hi, idx, tmp, cnt)
      case default   ! (lo + hi, lo)
        call sort_stable(lo, idx, tmp, cnt)
        call sort_stable(mid, idx, tmp, cnt)
      end select
      l = 0; u = 0
      do k = 1, n
        l = max(l, k - lo(idx(k)))
        u = max(u, hi(idx(k)) - k)
      end do
      if (l + u < kl + ku .or. (l + u == kl + ku .and. l < kl)) then
        kl = l; ku = u
        do k = 1, n
          prow(idx(k)) = k
        end do
      end if
    end do
  end subroutine order_rows

  !> Stable counting sort of idx by key(idx); keys in 0..size(cnt)-2.
  pure subroutine sort_stable(key, idx, tmp, cnt)
    integer, intent(in) :: key(:)          !! sort keys of the items
    integer, intent(inout) :: idx(:)       !! items, sorted on return
    integer, intent(inout) :: tmp(:)       !! workspace (size(idx))
    integer, intent(inout) :: cnt(0:)      !! workspace (largest key + 2)
    integer :: k, c
    cnt = 0
    do k = 1, size(idx)
      cnt(key(idx(k)) + 1) = cnt(key(idx(k)) + 1) + 1
    end do
    do c = 1, ubound(cnt, 1)
      cnt(c) = cnt(c) + cnt(c - 1)
    end do
    ! cnt(c) is now the number of keys below c
    do k = 1, size(idx)
      c = key(idx(k))
      cnt(c) = cnt(c) + 1
      tmp(cnt(c)) = idx(k)
    end do
    idx = tmp
  end subroutine sort_stable

  !> Sign of a permutation: (-1)**(n - number of cycles).
  pure subroutine perm_parity(p, seen, sgn)
    integer, intent(in) :: p(:)        !! a permutation of 1..size(p)
    integer, intent(inout) :: seen(:)  !! workspace (size(p)): 1 for the elements visited
    integer, intent(out) :: sgn        !! the sign
    integer :: i, j
    seen(1:size(p)) = 0
    sgn = 1
    do i = 1, size(p)
      if (seen(i) == 1) cycle
      j = p(i)
      seen(i) = 1
      do while (j /= i)   ! each further element of the cycle is one transposition
        seen(j) = 1
        sgn = -sgn
        j = p(j)
      end do
    end do
  end subroutine perm_parity

end module mbd_band
