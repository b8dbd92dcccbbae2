!> mbd_saddle: the saddle-point systems of the dynamics, behind one interface with two paths,
!! dense LU for small models and band LU for large ones.
!!
!!   [ A        s J_a^T ] [ x ]   [ b ]
!!   [ s J_a    -e I    ] [ y ] = [ c ]           (n coordinates, na active rows)
!!
!! A is diagonal, d (the index-1 systems: M q_ddot + J^T lambda = Q with d = M; the velocity
!! and position projections with d = M or 1), or, with a tangent pattern (full), d + K on
!! the pattern of K = d(J^T lambda - Q)/dq (the generalized-alpha iteration matrix
!! M b' + K + g' C). J_a are the active rows of J, placed from the constraint blocks (jb of
!! mbd_assemble) through a map built once, s scales them (a mass scale, or b'). e >= 0 on
!! the constraint diagonal is 0 for a saddle point, 1 for Levenberg-Marquardt's augmented
!! form [mu I, J^T; J, -I] (its step minimizes ||J dx + Phi||^2 + mu ||dx||^2).
!!
!! Dense path: the matrix (n + na)^2; index-1 systems by LU (dgetf2/dgetrf) and, when nearly
!! singular (1/cond_1 < AUG_RCOND, as at the collinear position of a parallelogram), with
!! the constraint block regularized and refined as on the band path (below; dgelsy's
!! minimum-norm solve should that LU fail); the generalized-alpha matrix by
!! a sparse LU replayed in a pivot order planned on its values (mbd_splu; K is non-zero
!! only in the angle columns), planned again when an entry outside the plan turns non-zero,
!! a pivot vanishes or a multiplier grows past LMAX, and the plain-loop LU (lu_factor_small)
!! when a plan fails.
!! Band path (mbd_band): the rows and columns of the saddle matrix ordered by one symmetric
!! permutation, the narrower of two (the smaller kl + ku):
!!   interleaved  the coordinate groups (a body's x, y, theta; each extra coordinate) in
!!                reverse Cuthill-McKee order of the graph in which two groups are adjacent
!!                when a constraint (or, full, a force) couples them, and after each group
!!                the active rows of the constraints that touch it and are not yet placed:
!!                every row sits next to its bodies, as in a chain body-row-body-row;
!!   rcm          reverse Cuthill-McKee on the graph of the whole saddle matrix.
!! LU with partial pivoting of the band (band_lu in plain loops while the band is narrow,
!! dgbtrf beyond; zero diagonal entries of the constraint block are pivoted away within the
!! band). A nearly singular index-1 matrix is solved with the constraint block regularized,
!! -eps I with eps = AUG_RCOND ||A||_1 (a damped least-squares solve: directions of J_a
!! with sigma^2 below about eps are damped where dgelsy would drop them: smooth in q, where
!! a dropped direction jumps as the condition crosses the threshold), refined against the
!! unregularized matrix (NREFINE times dense, NREFINE_BAND band). Nothing of size n^2 is
!! allocated on the band path.
!! Cost per factorization: dense ~ (2/3)(n + na)^3, band ~ 2 (n + na) kl (kl + ku).
!!
!! Usage: saddle_plan once per structure (allocates); then saddle_factor with the current
!! d, jb, s (and K) and saddle_solve for any number of right-hand sides; no allocation.
module mbd_saddle
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_BAD_INPUT, MBD_SINGULAR, MBD_NO_MEMORY, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail
  use mbd_points, only: NLOC, MAXROW
  use mbd_model, only: model_t
  use mbd_band, only: band_t, band_plan_perm, band_graph, band_rcm, band_zero, band_norm1, &
                      band_factor, band_rcond, band_solve
  use mbd_schur, only: schur_t, schur_plan, schur_factor, schur_solve, rows_rcm, &
                       rows_by_coordinate
  use mbd_splu, only: splu_solve_rows_t, splu_t, splu_init, splu_plan, splu_factor, splu_solve, splu_solve_rows, &
                      splu_pos, LMAX
  use mbd_linsolve, only: lu_factor, lu_solve, lu_factor_small, lu_solve_small, lapack_status
  use mbd_lapack, only: dgecon, dgelsy
  implicit none
  private
  public :: saddle_t, saddle_plan, saddle_factor, saddle_solve, saddle_solve_rows, &
            saddle_bytes, AUG_RCOND
  public :: saddle_row_rank
  public :: SADDLE_BAND_MIN_N, SADDLE_BAND_RATIO

  !> 1/cond_1 of an index-1 matrix below which it is solved as nearly singular
  real(wp), parameter :: AUG_RCOND = 1.0e-9_wp
  !> refinements of a nearly singular index-1 solve against the matrix itself, dense and band
  !! (each damps the regularization's error by eps / (sigma^2 + eps) along a direction of
  !! J_a). Dense: the stabilized Baumgarte N-four-bar's crank spread through the passages
  !! at N = 5, h = 1e-2, 1.4e-5 with 2, 1.2e-7 with 6, 1.2e-9 with 12, no better with 30
  !! (2.2e-8 with dgelsy before). Band: 12 also halves dopri5's rejected steps through the
  !! passages at N = 2 to 6, rtol 1e-9 to 1e-12, but on the N = 1 chain at rtol 1e-12 (a
  !! band it never takes by itself) one run in eleven ends 3.8e-6 off and one more
  !! underflows: 2 kept there
  integer, parameter :: NREFINE = 12, NREFINE_BAND = 2
  !> the band rank analysis leaves out the heaviest row of a dependency instead of its last
  !! in the order when that weighs more than SWAP_RATIO times as much (at most MAX_SWAPS
  !! times per analysis, each a new factorization)
  real(wp), parameter :: SWAP_RATIO = 1.0e2_wp
  integer, parameter :: MAX_SWAPS = 8
  !> auto choice: the band path for at least SADDLE_BAND_MIN_N coordinates when the band
  !! (kl + ku + 1) is at most (n + na) / SADDLE_BAND_RATIO wide (as kinematics)
  integer, parameter :: SADDLE_BAND_MIN_N = 60, SADDLE_BAND_RATIO = 4
  !> bands up to this kl + ku are factored in plain loops (band_lu), wider ones by dgbtrf
  integer, parameter :: PLAIN_MAX = 64
  !> small dense iteration matrices up to this order take the sparse LU (mbd_splu: its plan
  !! keeps several arrays of nt^2 entries), index-1 ones up to SPARSE_INDEX1_MAX: beyond, the
  !! Schur complement costs less (dopri5 on the free N-four-bar, callgrind: N = 5, 65 rows,
  !! 33.0M through S against 49.3M; N = 8, 113 rows, 54.2M against 144.0M), while for
  !! generalized-alpha the sparse LU still beats the plain-loop LU (N = 5: 135.7M against
  !! 338.1M; N = 8: 247.8M against 713.5M)
  integer, parameter :: SPARSE_MAX = 128, SPARSE_INDEX1_MAX = 64
  character(len=*), parameter :: HINT = 'use a model with fewer coordinates'

  !> A planned saddle-point matrix: the map from the constraint blocks, the storage and
  !! factors of one path, and the workspace of its solves.
  type :: saddle_t
    integer :: n = 0, na = 0, nt = 0     !! coordinates, active rows, n + na
    logical :: banded = .false.          !! band path
    logical :: full = .false.            !! A has the tangent pattern (not only its diagonal)
    logical :: lsq = .false.             !! the last index-1 factorization was nearly singular
    !> dense, nearly singular: factored with the constraint block regularized, the matrix
    !! itself in acopy for the refinement (else, the regularized LU failing, dgelsy's solve)
    logical :: reg = .false.
    logical :: plain = .false.           !! factored without the near-singularity check
    logical :: schur = .false.           !! the last factorization is the Schur complement's
    logical :: use_schur = .true.        !! index-1 systems may take the Schur complement
    integer :: nfactor = 0               !! factorizations
    integer :: nschur = 0                !! of them through the Schur complement
    integer :: nrank = 0                 !! nearly singular solves
    integer :: kl = 0, ku = 0            !! band widths (band path)
    !> the constraint blocks' nonzeros of active rows: jb(esrc(i)) goes to the flat storage
    !! positions epos(i) (s J_a) and etpos(i) (s J_a^T); the diagonal (nt) and the tangent
    !! pattern entries (full) likewise
    integer, allocatable :: esrc(:), epos(:), etpos(:), dpos(:), kpos(:)
    ! dense path
    real(wp), allocatable :: a(:, :)     !! (nt, nt) matrix, then its factors
    integer, allocatable :: ipiv(:)
    real(wp), allocatable :: acopy(:, :), lswork(:), cw(:)
    integer, allocatable :: iw(:), jp(:)
    ! band path
    type(band_t) :: b                    !! plan, storage, factors
    type(schur_t) :: sc                  !! index-1 systems with diagonal A: mbd_schur
    ! small dense path (plain): a sparse LU replayed in a planned pivot order (mbd_splu)
    type(splu_t) :: sp
    logical :: sparse = .false.          !! the sparse LU is planned for
    logical :: spfact = .false.          !! the last factorization is the sparse one
    !> the pieces' places in the plan's storage (dpos, epos, etpos, kpos there; 0: not held)
    integer, allocatable :: sdp(:), sep(:), setp(:), skp(:)
    real(wp), allocatable :: ones(:), xs(:)  !! unit column scale, solution of the sparse solves
    !> the unregularized matrix of a nearly singular band one, as its pieces (the refinement's
    !! products): the diagonal of A, -e, s J_a's values lval in esrc's order, at (n + erow, ecol)
    real(wp), allocatable :: ld(:), lval(:)
    real(wp) :: le = zero
    integer, allocatable :: erow(:), ecol(:)
    real(wp), allocatable :: r(:), x(:), xw(:)  !! refinement workspace (nt)
  end type saddle_t

contains

  !> Bytes of a saddle-point matrix of nt = n + na: dense nt^2 (with the copy for the
  !! rank-revealing solve when check), band nt (2 kl + ku + 1), vectors and (check) the
  !! pieces of J_a.
  pure real(wp) function saddle_bytes(nt, banded, kl, ku, check) result(bytes)
    integer, intent(in) :: nt          !! n + na
    logical, intent(in) :: banded      !! band path
    integer, intent(in) :: kl, ku      !! band widths (band path)
    logical, intent(in) :: check       !! index-1 (nearly singular solves possible)
    real(wp) :: t
    t = real(nt, wp)
    if (banded) then      ! (check: the pieces, at most NLOC entries of J_a a row)
      bytes = REAL_BYTES * t * ((2 * kl + ku + 1) + 12 + merge(2 * NLOC + 1, 0, check))
    else
      bytes = REAL_BYTES * (t * t * merge(2, 1, check) + 8 * t)
    end if
  end function saddle_bytes

  !> Plan the saddle-point matrix of model m with the active rows `rows` (equation numbers):
  !! the ordering and storage of the chosen path and the maps from the constraint blocks.
  !! kptr, krow: the pattern of the tangent K by columns (rows krow(kptr(c):kptr(c+1)-1) of
  !! column c), for a full matrix. solver: 1 dense, 2 banded. small: the dense path factors
  !! in plain loops (a small iteration matrix, no near-singularity check). index1: allocate
  !! the workspace of nearly singular solves (saddle_factor's check). Allocates.
  subroutine saddle_plan(m, rows, solver, sd, status, msg, kptr, krow, small, index1, schur)
    type(model_t), intent(in) :: m                 !! model
    integer, intent(in) :: rows(:)                 !! active rows (na), increasing
    integer, intent(in) :: solver                  !! 1 dense, 2 banded
    type(saddle_t), intent(out) :: sd              !! the plan
    integer, intent(out) :: status                 !! MBD_OK, MBD_BAD_INPUT or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg     !! explanation
    integer, intent(in), optional :: kptr(:), krow(:)  !! tangent pattern (full)
    logical, intent(in), optional :: small         !! dense: sparse / plain LU for iterations
    logical, intent(in), optional :: index1        !! workspace of nearly singular solves
    !> plan the Schur complement for a full matrix too (its K pattern diagonal: A stays
    !! diagonal, K folded into d by the caller; saddle_factor's schur)
    logical, intent(in), optional :: schur
    integer, allocatable :: arow(:), sr(:), sc(:), perm(:), cptr(:), crow(:), csrc(:)
    integer :: n, na, nt, ne, nk, c, a, i, ierr, ldab
    real(wp) :: bytes
    logical :: chk
    status = MBD_OK; msg = ''
    chk = .false.; if (present(index1)) chk = index1
    n = m%nq; na = size(rows); nt = n + na
    sd%n = n; sd%na = na; sd%nt = nt
    sd%full = present(kptr) .and. present(krow)
    sd%banded = solver == 2
    if (present(small)) sd%plain = small .and. .not. sd%banded
    allocate (arow(m%neq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(4 * real(m%neq, wp), 'the saddle-point map', HINT, status, msg); return
    end if
    arow = 0
    do a = 1, na
      arow(rows(a)) = a
    end do
    ! the nonzeros of the active rows' blocks, by coordinate
    call rows_by_coordinate(m, arow, cptr, crow, csrc, ierr)
    if (ierr /= 0) then
      call mem_fail(12 * real(n, wp), 'the saddle-point map', HINT, status, msg); return
    end if
    ne = size(crow)
    nk = 0
    if (sd%full) nk = kptr(n + 1) - 1
    allocate (sd%epos(ne), sd%etpos(ne), sd%dpos(nt), sd%kpos(nk), &
              sr(nt + 2 * ne + nk), sc(nt + 2 * ne + nk), perm(nt), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(4 * (3 * real(ne, wp) + 3 * nt + 5 * ne + 3 * nk), 'the saddle-point map', &
                    HINT, status, msg)
      return
    end if
    call move_alloc(csrc, sd%esrc)
    ! the structure: the diagonal, s J_a and s J_a^T, the tangent pattern
    do i = 1, nt
      sr(i) = i; sc(i) = i
    end do
    do c = 1, n
      do i = cptr(c), cptr(c + 1) - 1
        sr(nt + 2 * i - 1) = n + crow(i); sc(nt + 2 * i - 1) = c
        sr(nt + 2 * i) = c; sc(nt + 2 * i) = n + crow(i)
      end do
    end do
    if (sd%full) then
      do c = 1, n
        do i = kptr(c), kptr(c + 1) - 1
          sr(nt + 2 * ne + i) = krow(i); sc(nt + 2 * ne + i) = c
        end do
      end do
    end if
    if (sd%banded) then
      call order(m, arow, n, na, sr, sc, perm, status, msg)
      if (status /= MBD_OK) return
      call band_plan_perm(nt, sr, sc, perm, perm, sd%b, status, msg)
      if (status /= MBD_OK) return
      sd%kl = sd%b%kl; sd%ku = sd%b%ku
      sd%b%plain = sd%kl + sd%ku <= PLAIN_MAX
      ldab = sd%b%ldab
      bytes = saddle_bytes(nt, .true., sd%kl, sd%ku, chk)
      call mem_check(bytes, 'the band saddle-point matrix', HINT, status, msg)
      if (status /= MBD_OK) return
      allocate (sd%r(nt), sd%x(nt), sd%xw(nt), stat=ierr)
      if (ierr == 0 .and. chk) allocate (sd%ld(n), sd%lval(ne), sd%erow(ne), sd%ecol(ne), &
                                         stat=ierr)
      if (ierr == 0 .and. chk) then
        do c = 1, n
          sd%ecol(cptr(c):cptr(c + 1) - 1) = c
        end do
        sd%erow = crow
      end if
      if (ierr /= 0) then
        call mem_fail(bytes, 'the band saddle-point workspace', HINT, status, msg); return
      end if
    else
      ldab = nt
      perm = [(i, i=1, nt)]
      bytes = saddle_bytes(nt, .false., 0, 0, chk)
      call mem_check(bytes, 'the dense saddle-point matrix', HINT, status, msg)
      if (status /= MBD_OK) return
      allocate (sd%a(nt, nt), sd%ipiv(nt), stat=ierr)
      if (ierr == 0 .and. chk) call dense_work(sd, ierr)
      if (ierr /= 0) then
        call mem_fail(bytes, 'the dense saddle-point matrix', HINT, status, msg); return
      end if
      sd%a = zero
      if (sd%plain .and. nt <= merge(SPARSE_INDEX1_MAX, SPARSE_MAX, chk)) &
        call sparse_plan(sd, sr, sc)
    end if
    ! diagonal A (index-1, or an iteration matrix with a diagonal K): the Schur complement
    if ((chk .and. .not. sd%full) .or. present_and(schur)) then
      call schur_plan(m, rows, sd%sc, status, msg)
      if (status /= MBD_OK) return
    end if
    ! flat positions in the storage
    do i = 1, nt
      sd%dpos(i) = flat(i, i)
    end do
    do i = 1, ne
      sd%epos(i) = flat(sr(nt + 2 * i - 1), sc(nt + 2 * i - 1))
      sd%etpos(i) = flat(sr(nt + 2 * i), sc(nt + 2 * i))
    end do
    do i = 1, nk
      sd%kpos(i) = flat(sr(nt + 2 * ne + i), sc(nt + 2 * ne + i))
    end do
  contains
    !> Column-major position of entry (i, j) in the storage of the path.
    integer function flat(i, j)
      integer, intent(in) :: i, j
      if (sd%banded) then
        flat = sd%b%kl + sd%b%ku + 1 + perm(i) - perm(j) + ldab * (perm(j) - 1)
      else
        flat = i + ldab * (j - 1)
      end if
    end function flat
  end subroutine saddle_plan

  !> The symmetric ordering of the band path: the narrower of the interleaved and the plain
  !! reverse Cuthill-McKee orderings (module banner). perm(i): position of saddle index i.
  subroutine order(m, arow, n, na, sr, sc, perm, status, msg)
    type(model_t), intent(in) :: m
    integer, intent(in) :: arow(:), n, na, sr(:), sc(:)
    integer, intent(out) :: perm(:)
    integer, intent(out) :: status
    character(len=MSG_LEN), intent(inout) :: msg
    integer, allocatable :: aptr(:), adj(:), ord(:), p2(:)
    integer :: nt, ierr, w1, w2, i
    nt = n + na
    status = MBD_OK
    allocate (ord(nt), p2(nt), stat=ierr)
    if (ierr == 0) call interleaved(m, arow, n, na, sr, sc, perm, ierr)
    if (ierr == 0) call band_graph(nt, sr, sc, aptr, adj, ierr)
    if (ierr == 0) call band_rcm(nt, aptr, adj, ord, ierr)
    if (ierr /= 0) then
      call mem_fail(4 * 12 * real(size(sr), wp), 'the band ordering of the saddle-point matrix', &
                    HINT, status, msg)
      return
    end if
    do i = 1, nt
      p2(ord(i)) = i
    end do
    w1 = width(perm); w2 = width(p2)
    if (w2 < w1) perm = p2
  contains
    integer function width(p)
      integer, intent(in) :: p(:)
      integer :: k
      width = 0
      do k = 1, size(sr)
        width = max(width, abs(p(sr(k)) - p(sc(k))))
      end do
    end function width
  end subroutine order

  !> The interleaved ordering (module banner): coordinate groups in reverse Cuthill-McKee
  !! order of their coupling graph, each followed by the active rows of the constraints that
  !! touch it and are not yet placed.
  subroutine interleaved(m, arow, n, na, sr, sc, perm, ierr)
    type(model_t), intent(in) :: m
    integer, intent(in) :: arow(:), n, na, sr(:), sc(:)
    integer, intent(out) :: perm(:)
    integer, intent(out) :: ierr
    integer, allocatable :: grp(:), gr(:), gc(:), aptr(:), adj(:), gord(:), cptr(:), ccon(:), &
                            cnt(:)
    logical, allocatable :: placed(:)
    integer :: ng, k, s, c, g, i, nn, pos, r, a, ks, ne
    ierr = 0
    ! coordinate groups: body b holds 3b-2..3b; each extra coordinate is a group of its own
    ng = m%nb + (n - 3 * m%nb)
    allocate (grp(n), stat=ierr)
    if (ierr /= 0) return
    do c = 1, n
      if (c <= 3 * m%nb) then
        grp(c) = (c + 2) / 3
      else
        grp(c) = m%nb + c - 3 * m%nb
      end if
    end do
    ! group coupling from the coordinate-coordinate entries the structure implies: two
    ! coordinates of one constraint row, and the tangent pattern
    ne = 0
    do k = 1, size(sr)
      if (sr(k) <= n .and. sc(k) <= n .and. sr(k) /= sc(k)) ne = ne + 1
    end do
    do k = 1, m%nc
      nn = count(m%loc(:, k) > 0)
      ne = ne + nn * nn
    end do
    allocate (gr(ne), gc(ne), gord(ng), placed(m%nc), cptr(ng + 1), cnt(ng), stat=ierr)
    if (ierr /= 0) return
    ne = 0
    do k = 1, size(sr)
      if (sr(k) <= n .and. sc(k) <= n .and. sr(k) /= sc(k)) then
        ne = ne + 1
        gr(ne) = grp(sr(k)); gc(ne) = grp(sc(k))
      end if
    end do
    do k = 1, m%nc
      if (.not. any([(arow(m%row0(k) + r - 1) > 0, r=1, m%nrow(k))])) cycle
      do s = 1, NLOC
        if (m%loc(s, k) == 0) cycle
        do i = 1, NLOC
          if (m%loc(i, k) == 0) cycle
          ne = ne + 1
          gr(ne) = grp(m%loc(s, k)); gc(ne) = grp(m%loc(i, k))
        end do
      end do
    end do
    call band_graph(ng, gr(1:ne), gc(1:ne), aptr, adj, ierr)
    if (ierr == 0) call band_rcm(ng, aptr, adj, gord, ierr)
    if (ierr /= 0) return
    ! the constraints touching each group (counting sort)
    cnt = 0
    do k = 1, m%nc
      do s = 1, NLOC
        if (m%loc(s, k) > 0) cnt(grp(m%loc(s, k))) = cnt(grp(m%loc(s, k))) + 1
      end do
    end do
    cptr(1) = 1
    do g = 1, ng
      cptr(g + 1) = cptr(g) + cnt(g)
    end do
    allocate (ccon(cptr(ng + 1) - 1), stat=ierr)
    if (ierr /= 0) return
    cnt = 0
    do k = 1, m%nc
      do s = 1, NLOC
        if (m%loc(s, k) == 0) cycle
        g = grp(m%loc(s, k))
        ccon(cptr(g) + cnt(g)) = k
        cnt(g) = cnt(g) + 1
      end do
    end do
    ! emit
    perm = 0
    placed = .false.
    pos = 0
    do i = 1, ng
      g = gord(i)
      if (g <= m%nb) then                       ! a body: x, y, theta
        do c = 3 * g - 2, 3 * g
          pos = pos + 1; perm(c) = pos
        end do
      else                                      ! an extra coordinate
        pos = pos + 1; perm(3 * m%nb + g - m%nb) = pos
      end if
      do ks = cptr(g), cptr(g + 1) - 1
        k = ccon(ks)
        if (placed(k)) cycle
        placed(k) = .true.
        do r = 1, m%nrow(k)
          a = arow(m%row0(k) + r - 1)
          if (a == 0) cycle
          pos = pos + 1; perm(n + a) = pos
        end do
      end do
    end do
    do i = 1, n + na                ! anything left (not expected): at the end
      if (perm(i) == 0) then
        pos = pos + 1; perm(i) = pos
      end if
    end do
  end subroutine interleaved

  !> Fill the matrix from d (n), the blocks jb and s (and K values kv on the pattern, e on
  !! the constraint diagonal) and factor it. check: index-1 (a nearly singular matrix is
  !! detected and solved as such, sd%lsq; the plan needs index1); otherwise a plain
  !! factorization (status MBD_SINGULAR on an exactly zero pivot).
  subroutine saddle_factor(sd, d, jb, s, status, kv, e, check, schur)
    type(saddle_t), intent(inout) :: sd        !! planned matrix; factors on return
    real(wp), intent(in) :: d(:)               !! diagonal of A (n)
    real(wp), intent(in) :: jb(:, :, :)        !! constraint blocks (MAXROW, NLOC, nc)
    real(wp), intent(in) :: s                  !! scale of J_a
    integer, intent(out) :: status             !! MBD_OK, MBD_SINGULAR or MBD_LAPACK
    real(wp), intent(in), optional :: kv(:)    !! K on its pattern (full)
    real(wp), intent(in), optional :: e        !! constraint diagonal -e (default 0)
    logical, intent(in), optional :: check     !! index-1: nearly singular solves
    !> try the Schur complement without the index-1 checks (A diagonal: an iteration matrix
    !! whose K is diagonal, folded into d); refused, the LU of the path as without it
    logical, intent(in), optional :: schur
    real(wp) :: ee, anorm, rc, pr
    logical :: chk, refused
    character(len=MSG_LEN) :: msg
    integer :: info, k
    ee = zero; if (present(e)) ee = e
    chk = .false.; if (present(check)) chk = check
    sd%nfactor = sd%nfactor + 1
    sd%lsq = .false.
    sd%reg = .false.
    sd%schur = .false.
    refused = .false.
    if ((chk .or. present_and(schur)) .and. sd%use_schur .and. .not. present(kv) .and. &
        .not. abs(ee) > zero) then
      ! diagonal, positive A and a well-conditioned Schur complement: its Cholesky
      call schur_factor(sd%sc, d, jb, s, sd%schur)
      status = MBD_OK
      if (sd%schur) then
        sd%nschur = sd%nschur + 1
        return
      end if
      refused = .true.
    end if
    if (sd%banded) then
      call fill(ee)
      if (.not. chk) then
        call band_factor(sd%b, status, msg)
        return
      end if
      ! ||A||_1 only where it is used (a small pivot ratio): the matrix is filled again and,
      ! for the condition estimate, factored again (the same factors), which keeps a pass
      ! over the whole band out of every well-conditioned factorization; after a refused
      ! Schur complement (a small pivot ratio of S: the condition estimate is likely needed)
      ! the norm is taken at once, one pass instead of a second fill and factorization
      anorm = zero
      if (refused) anorm = band_norm1(sd%b)
      call band_factor(sd%b, status, msg, pivratio=pr)
      if (status == MBD_OK .and. pr < 1.0e-6_wp) then
        if (.not. anorm > zero) then
          call fill(ee)
          anorm = band_norm1(sd%b)
          call band_factor(sd%b, status, msg)
        end if
        sd%lsq = status /= MBD_OK
        if (status == MBD_OK) then
          call band_rcond(sd%b, anorm, rc, info, msg)
          sd%lsq = info == MBD_OK .and. rc < AUG_RCOND
        end if
      else
        sd%lsq = status /= MBD_OK
      end if
      if (.not. allocated(sd%lval) .or. present(kv)) sd%lsq = .false.
      if (sd%lsq) then
        ! keep the matrix as its pieces, then factor it with the constraint block regularized
        if (anorm <= zero) then
          call fill(ee)
          anorm = band_norm1(sd%b)
        end if
        sd%ld = d; sd%le = ee
        call keep_values(sd%lval, sd%esrc, jb, size(jb), s)
        call fill(ee + AUG_RCOND * anorm)
        call band_factor(sd%b, status, msg)
      end if
      return
    end if
    sd%spfact = .false.
    if (sd%plain .and. sd%sparse) then
      ! the pieces straight into the planned storage (no dense matrix) while the plan holds
      ! them and its pivots stay good; else the dense fill below and a new plan on it
      call direct_factor(sd%spfact, pr)
      status = MBD_OK
      if (sd%spfact .and. (pr >= 1.0e-6_wp .or. .not. chk)) return
    end if
    call fill(ee)
    if (sd%plain) then
      if (sd%sparse .and. .not. sd%spfact) call sparse_factor(sd, sd%spfact, pr)
      status = MBD_OK
      if (chk .and. sd%spfact) sd%spfact = pr >= 1.0e-6_wp
      if (sd%spfact) return
      ! no sparse factors: the plain-loop LU, or, index-1 (a small pivot ratio: nearly
      ! singular?), the LU with the condition estimate below (fill left sd%a as it was)
      if (.not. (chk .and. allocated(sd%acopy))) then
        call lu_factor_small(sd%a, sd%ipiv, status)
        return
      end if
    end if
    if (.not. (chk .and. allocated(sd%acopy))) then
      call lu_factor(sd%a, sd%ipiv, status, msg)
      return
    end if
    anorm = zero
    do k = 1, sd%nt
      anorm = max(anorm, sum(abs(sd%a(:, k))))
    end do
    call lu_factor(sd%a, sd%ipiv, status, msg)
    sd%lsq = status /= MBD_OK
    if (.not. sd%lsq) then
      pr = pivot_ratio(sd%a)
      if (pr < 1.0e-6_wp) then
        call dgecon('1', sd%nt, sd%a, sd%nt, anorm, rc, sd%cw, sd%iw, info)
        sd%lsq = rc < AUG_RCOND
      end if
    end if
    status = MBD_OK
    if (.not. sd%lsq) return
    ! as the band path: the matrix kept (acopy) and factored with the constraint block
    ! regularized, -eps I (eps = AUG_RCOND ||A||_1: a damped least squares, smooth in q where
    ! dgelsy's dropped directions jump), the solves refined against the matrix itself;
    ! should that LU fail, dgelsy on the matrix (sd%a)
    call fill(ee)
    sd%acopy = sd%a
    call fill(ee + AUG_RCOND * anorm)
    call lu_factor(sd%a, sd%ipiv, status, msg)
    sd%reg = status == MBD_OK
    if (.not. sd%reg) sd%a = sd%acopy
    status = MBD_OK
  contains
    !> The sparse LU of the pieces put into the plan's storage: ok when the plan holds every
    !! non-zero piece, no pivot vanishes and no multiplier exceeds LMAX.
    subroutine direct_factor(ok, ratio)
      logical, intent(out) :: ok
      real(wp), intent(out) :: ratio
      real(wp) :: lmax
      integer :: st, sgn
      logical :: off
      ok = .false.; ratio = zero
      if (.not. sd%sp%planned) return
      call put_sparse(sd%sp%val, sd%sp%nnz, sd%n, sd%nt, sd%sdp, sd%skp, sd%esrc, sd%sep, &
                      sd%setp, d, jb, size(jb), s, ee, off, kv)
      if (off) return
      call splu_factor(sd%sp, st, lmax, sgn, ratio)
      ok = st == MBD_OK .and. lmax <= LMAX
    end subroutine direct_factor

    !> The matrix into the storage of the path: zero, then the pieces (put).
    subroutine fill(ediag)
      real(wp), intent(in) :: ediag
      if (sd%banded) then
        call band_zero(sd%b)
        call put(sd%b%ab, size(sd%b%ab), sd%n, sd%nt, sd%dpos, sd%kpos, sd%esrc, sd%epos, &
                 sd%etpos, d, jb, size(jb), s, ediag, kv)
      else
        sd%a = zero
        call put(sd%a, size(sd%a), sd%n, sd%nt, sd%dpos, sd%kpos, sd%esrc, sd%epos, &
                 sd%etpos, d, jb, size(jb), s, ediag, kv)
      end if
    end subroutine fill
  end subroutine saddle_factor

  !> The sparse LU of a small iteration matrix: its structural entries (the pieces' lists
  !! sr, sc, repeats merged) and their places in the dense storage. Nothing is planned yet
  !! (the first factorization plans on the values); a failure leaves the dense LU.
  subroutine sparse_plan(sd, sr, sc)
    type(saddle_t), intent(inout) :: sd
    integer, intent(in) :: sr(:), sc(:)          ! rows and columns of the pieces
    logical, allocatable :: seen(:, :)
    integer, allocatable :: tr(:), tc(:)
    integer :: i, nu, nt, ierr, st
    character(len=MSG_LEN) :: msg
    nt = sd%nt
    allocate (seen(nt, nt), tr(size(sr)), tc(size(sr)), stat=ierr)
    if (ierr /= 0) return
    seen = .false.
    nu = 0
    do i = 1, size(sr)
      if (seen(sr(i), sc(i))) cycle
      seen(sr(i), sc(i)) = .true.
      nu = nu + 1
      tr(nu) = sr(i); tc(nu) = sc(i)
    end do
    allocate (sd%ones(nt), sd%xs(nt), &
              sd%sdp(nt), sd%sep(size(sd%epos)), sd%setp(size(sd%epos)), &
              sd%skp(size(sd%kpos)), stat=ierr)
    if (ierr /= 0) return
    sd%ones = one
    msg = ''
    call splu_init(nt, tr(1:nu), tc(1:nu), sd%sp, st, msg)
    sd%sparse = st == MBD_OK
  end subroutine sparse_plan

  !> A new plan of the sparse LU on the filled dense matrix sd%a (there is none yet, or the
  !! last one no longer held a non-zero piece, met a zero pivot or a multiplier past LMAX:
  !! direct_factor), the pieces' places in it, and its factorization of sd%a. ok false: the
  !! plan or its factorization failed (the caller factors densely).
  subroutine sparse_factor(sd, ok, ratio)
    type(saddle_t), intent(inout) :: sd
    logical, intent(out) :: ok
    real(wp), intent(out) :: ratio               ! min |u_kk| / max |u_kk|
    real(wp) :: lmax
    integer :: st, sgn
    character(len=MSG_LEN) :: msg
    ok = .false.
    lmax = zero; ratio = zero
    msg = ''
    call splu_plan(sd%sp, sd%a, st, msg)        ! (the plan loads sd%a's values)
    if (st /= MBD_OK) return
    call positions()
    call splu_factor(sd%sp, st, lmax, sgn, ratio)
    ok = st == MBD_OK .and. lmax <= LMAX
  contains
    !> The places of the pieces in the new plan.
    subroutine positions()
      sd%sdp = held(sd%dpos); sd%sep = held(sd%epos); sd%setp = held(sd%etpos)
      sd%skp = held(sd%kpos)
    end subroutine positions
    !> Plan positions of dense flat positions f (column-major, nt rows).
    pure function held(f) result(pos)
      integer, intent(in) :: f(:)
      integer :: pos(size(f)), i
      do i = 1, size(f)
        pos(i) = splu_pos(sd%sp, mod(f(i) - 1, sd%nt) + 1, (f(i) - 1) / sd%nt + 1)
      end do
    end function held
  end subroutine sparse_factor

  !> Place the pieces into flat storage: K on its pattern, += d on the diagonal of A, -e on
  !! the constraint diagonal, s J_a and s J_a^T (the order of the dense matrices before, so
  !! the dense path's sums are the same).
  pure subroutine put(f, nf, n, nt, dpos, kpos, esrc, epos, etpos, d, jb, nj, s, e, kv)
    integer, intent(in) :: nf, n, nt, nj
    real(wp), intent(inout) :: f(nf)
    integer, intent(in) :: dpos(:), kpos(:), esrc(:), epos(:), etpos(:)
    real(wp), intent(in) :: d(:), jb(nj), s, e
    real(wp), intent(in), optional :: kv(:)
    integer :: i
    real(wp) :: v
    if (present(kv)) then
      do i = 1, size(kpos)
        f(kpos(i)) = kv(i)
      end do
    end if
    do i = 1, n
      f(dpos(i)) = f(dpos(i)) + d(i)
    end do
    if (abs(e) > zero) then
      do i = n + 1, nt
        f(dpos(i)) = -e
      end do
    end if
    do i = 1, size(esrc)
      v = s * jb(esrc(i))
      f(epos(i)) = f(epos(i)) + v
      f(etpos(i)) = f(etpos(i)) + v
    end do
  end subroutine put

  !> y = A x of the unregularized matrix kept as its pieces (saddle_factor, nearly singular
  !! band): [diag(d), s J_a^T; s J_a, -e I] x, no pass over the band storage.
  pure subroutine pieces_matvec(sd, x, y)
    type(saddle_t), intent(in) :: sd
    real(wp), intent(in) :: x(:)
    real(wp), intent(out) :: y(:)
    integer :: i, c, r, n
    real(wp) :: v
    n = sd%n
    do c = 1, n
      y(c) = sd%ld(c) * x(c)
    end do
    do r = n + 1, sd%nt
      y(r) = -sd%le * x(r)
    end do
    do i = 1, size(sd%lval)
      v = sd%lval(i); c = sd%ecol(i); r = n + sd%erow(i)
      y(c) = y(c) + v * x(r)
      y(r) = y(r) + v * x(c)
    end do
  end subroutine pieces_matvec

  !> lval = s jb(esrc) over a flat view of the blocks.
  pure subroutine keep_values(lval, esrc, jb, nj, s)
    integer, intent(in) :: nj, esrc(:)
    real(wp), intent(out) :: lval(:)
    real(wp), intent(in) :: jb(nj), s
    integer :: i
    do i = 1, size(esrc)
      lval(i) = s * jb(esrc(i))
    end do
  end subroutine keep_values

  !> put into a sparse plan's storage val: its nnz entries zeroed (one flat fill; the fill
  !! entries among them are zeroed by the factorization anyway), then the pieces in put's
  !! order at their plan positions (so the sums are put's); off: a non-zero piece the plan
  !! does not hold.
  pure subroutine put_sparse(val, nnz, n, nt, sdp, skp, esrc, sep, setp, d, jb, nj, s, e, &
                             off, kv)
    real(wp), intent(inout) :: val(:)
    integer, intent(in) :: nnz, n, nt, nj
    integer, intent(in) :: sdp(:), skp(:), esrc(:), sep(:), setp(:)
    real(wp), intent(in) :: d(:), jb(nj), s, e
    logical, intent(out) :: off
    real(wp), intent(in), optional :: kv(:)
    integer :: i
    real(wp) :: v
    off = .false.
    val(1:nnz) = zero
    if (present(kv)) then
      do i = 1, size(skp)
        call put_add(val, off, skp(i), kv(i))
      end do
    end if
    do i = 1, n
      call put_add(val, off, sdp(i), d(i))
    end do
    if (abs(e) > zero) then
      do i = n + 1, nt
        call put_add(val, off, sdp(i), -e)
      end do
    end if
    do i = 1, size(esrc)
      v = s * jb(esrc(i))
      call put_add(val, off, sep(i), v)
      call put_add(val, off, setp(i), v)
    end do
  end subroutine put_sparse

  !> val(p) += x at a held position p; off when x /= 0 has no place (p = 0).
  pure subroutine put_add(val, off, p, x)
    real(wp), intent(inout) :: val(:)
    logical, intent(inout) :: off
    integer, intent(in) :: p
    real(wp), intent(in) :: x
    if (p > 0) then
      val(p) = val(p) + x
    else if (abs(x) > zero) then
      off = .true.
    end if
  end subroutine put_add

  !> An optional flag, .false. when absent.
  pure logical function present_and(flag)
    logical, intent(in), optional :: flag
    present_and = .false.
    if (present(flag)) present_and = flag
  end function present_and

  !> min |u_ii| / max |u_ii| of dense LU factors.
  pure real(wp) function pivot_ratio(a) result(pr)
    real(wp), intent(in) :: a(:, :)
    real(wp) :: umin, umax
    integer :: k
    umin = huge(one); umax = zero
    do k = 1, size(a, 1)
      umin = min(umin, abs(a(k, k))); umax = max(umax, abs(a(k, k)))
    end do
    pr = umin / umax
  end function pivot_ratio

  !> The workspace of the dense nearly singular solves.
  subroutine dense_work(sd, ierr)
    type(saddle_t), intent(inout) :: sd
    integer, intent(out) :: ierr              ! allocation status (0 ok)
    real(wp) :: wq(1), rdum(1)
    integer :: nt, rank, info
    integer :: idum(1)
    nt = sd%nt
    call dgelsy(nt, nt, 1, rdum, nt, rdum, nt, idum, AUG_RCOND, rank, wq, -1, info)
    allocate (sd%acopy(nt, nt), sd%cw(4 * nt), sd%iw(nt), sd%jp(nt), &
              sd%lswork(max(1, int(wq(1)))), sd%r(nt), sd%x(nt), stat=ierr)
  end subroutine dense_work

  !> y = A x of a dense matrix (a plain loop by columns: no temporary).
  pure subroutine dense_matvec(a, x, y)
    real(wp), intent(in) :: a(:, :)          !! matrix
    real(wp), intent(in) :: x(:)             !! vector (size(a, 2))
    real(wp), intent(out) :: y(:)            !! product (size(a, 1))
    integer :: k
    y = zero
    do k = 1, size(a, 2)
      y = y + a(:, k) * x(k)
    end do
  end subroutine dense_matvec

  !> Solve with the factored matrix: [x; y] overwrites the right-hand side [b; c].
  subroutine saddle_solve(sd, rhs, status)
    type(saddle_t), intent(inout) :: sd      !! factored matrix
    real(wp), intent(inout) :: rhs(:)        !! right-hand side (nt), then solution
    integer, intent(out) :: status           !! MBD_OK, MBD_SINGULAR or MBD_LAPACK
    character(len=MSG_LEN) :: msg
    integer :: rank, info, it
    if (size(rhs) /= sd%nt) then
      status = MBD_BAD_INPUT; return
    end if
    if (sd%schur) then
      call schur_solve(sd%sc, rhs)
      status = MBD_OK
      return
    end if
    if (sd%banded .and. .not. sd%lsq) then
      call band_solve(sd%b, rhs, status, msg)
      return
    end if
    if (sd%banded .or. sd%reg) then
      ! regularized solve, refined against the matrix itself: x += A_eps^-1 (b - A x)
      sd%r = rhs
      call reg_solve(rhs)
      do it = 1, merge(NREFINE_BAND, NREFINE, sd%banded)
        if (status /= MBD_OK) return
        if (sd%banded) then
          call pieces_matvec(sd, rhs, sd%x)
        else
          call dense_matvec(sd%acopy, rhs, sd%x)
        end if
        sd%x = sd%r - sd%x
        call reg_solve(sd%x)
        rhs = rhs + sd%x
      end do
      sd%nrank = sd%nrank + 1
      return
    end if
    if (sd%plain .and. .not. sd%lsq) then   ! (lu_solve_small: dgetrf's factors too)
      if (sd%spfact) then
        call splu_solve(sd%sp, rhs, sd%xs, sd%ones)
        rhs = sd%xs
      else
        call lu_solve_small(sd%a, sd%ipiv, rhs)
      end if
      status = MBD_OK
      return
    end if
    if (.not. sd%lsq) then
      call lu_solve(sd%a, sd%ipiv, rhs, status, msg)
      return
    end if
    sd%acopy = sd%a
    sd%jp = 0
    call dgelsy(sd%nt, sd%nt, 1, sd%acopy, sd%nt, rhs, sd%nt, sd%jp, AUG_RCOND, rank, &
                sd%lswork, size(sd%lswork), info)
    call lapack_status('dgelsy', info, status, msg)
    sd%nrank = sd%nrank + 1
  contains
    !> y <- A_eps^-1 y with the regularized factors of the path.
    subroutine reg_solve(y)
      real(wp), intent(inout) :: y(:)
      if (sd%banded) then
        call band_solve(sd%b, y, status, msg)
      else
        call lu_solve(sd%a, sd%ipiv, y, status, msg)
      end if
    end subroutine reg_solve
  end subroutine saddle_solve

  !> Several right-hand sides as the rows of bt (4 k, nt), ncol of them: the first nkeep
  !! entries of each solution as a row of xt (ldt, nkeep), written or (add) added. The
  !! plain sparse LU solves four at a time; the other paths column by column.
  subroutine saddle_solve_rows(sd, bt, ncol, nkeep, ldt, xt, add, x, status)
    type(saddle_t), intent(inout) :: sd      !! factored matrix
    real(wp), intent(in) :: bt(:, :)         !! right-hand sides as rows (4 k, nt)
    integer, intent(in) :: ncol, nkeep, ldt  !! right-hand sides, entries kept, xt's rows
    real(wp), intent(inout) :: xt(ldt, *)    !! solutions as rows
    logical, intent(in) :: add               !! add to xt (else overwrite)
    real(wp), intent(inout) :: x(:)          !! work (nt)
    integer, intent(out) :: status           !! MBD_OK, MBD_SINGULAR or MBD_LAPACK
    integer :: k
    status = MBD_OK
    if (sd%plain .and. sd%spfact .and. .not. (sd%schur .or. sd%banded .or. sd%lsq)) then
      call splu_solve_rows_t(sd%sp, bt, nkeep, ldt, xt, add)   ! (plain: no column scale)
      return
    end if
    do k = 1, ncol
      x = bt(k, :)
      call saddle_solve(sd, x, status)
      if (status /= MBD_OK) return
      if (add) then
        xt(k, 1:nkeep) = xt(k, 1:nkeep) + x(1:nkeep)
      else
        xt(k, 1:nkeep) = x(1:nkeep)
      end if
    end do
    if (add) return
    do k = ncol + 1, ldt                     ! (the padding rows' solutions: zero)
      xt(k, 1:nkeep) = zero
    end do
  end subroutine saddle_solve_rows

  !> Redundant rows of J without a dense matrix: a Cholesky factorization of the Gram matrix
  !! G = D J J^T D of the rows scaled to unit length (D), in band storage after a reverse
  !! Cuthill-McKee ordering of the rows (two rows adjacent when they share a coordinate), in
  !! which a row whose pivot (the squared distance of its unit row from the span of the
  !! rows before it) is at most tol2 is redundant and left out, the ordered Gram-Schmidt
  !! selection of row_rank (mbd_linsolve) in the band order. Cost O(neq kd^2), kd the band
  !! width of the rows. redundant(r) = 1 for a redundant row; rank = neq - their number.
  !! With use, the rows where it is false are left out (not redundant, not counted).
  subroutine saddle_row_rank(m, jb, tol2, redundant, rank, status, msg, use)
    type(model_t), intent(in) :: m                !! model
    real(wp), intent(in) :: jb(:, :, :)           !! constraint blocks at the configuration
    real(wp), intent(in) :: tol2                  !! pivot tolerance (squared distance)
    integer, intent(out) :: redundant(:)          !! (neq) 1 for a redundant row
    integer, intent(out) :: rank                  !! number of independent rows
    integer, intent(out) :: status                !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg    !! explanation
    logical, intent(in), optional :: use(:)       !! (neq) the rows taken
    integer, allocatable :: arow(:), cptr(:), crow(:), csrc(:), pos(:), rowof(:), dropped(:)
    real(wp), allocatable :: g(:, :), rnorm(:), cdep(:)
    integer :: neq, n, i, j, kd, ne, ierr, l, w, attempt, r
    real(wp) :: v, dj
    logical :: swapped
    status = MBD_OK; msg = ''
    neq = m%neq; n = m%nq
    redundant = 0; rank = 0
    if (neq == 0) return
    ! the rows touching each coordinate and their block entries; the rows' lengths
    allocate (arow(neq), rnorm(neq), pos(neq), rowof(neq), dropped(neq), cdep(neq), stat=ierr)
    if (ierr /= 0) goto 90
    arow = [(i, i=1, neq)]
    call rows_by_coordinate(m, arow, cptr, crow, csrc, ierr)
    if (ierr /= 0) goto 90
    ne = size(crow)
    rnorm = zero
    do i = 1, ne
      rnorm(crow(i)) = rnorm(crow(i)) + jbf(csrc(i))**2
    end do
    rnorm = sqrt(rnorm)
    if (present(use)) then                     ! (a row left out: no entries in G)
      where (.not. use) rnorm = zero
    end if
    ! the rows in reverse Cuthill-McKee order of the graph of rows sharing a coordinate
    call rows_rcm(neq, cptr, crow, pos, kd, ierr)
    if (ierr /= 0) goto 90
    do i = 1, neq
      rowof(pos(i)) = i
    end do
    ! G in lower band storage: G(p, q) (p >= q, band positions) in g(1 + p - q, q)
    call mem_check(REAL_BYTES * real(kd + 1, wp) * neq, 'the rank analysis of J (band)', HINT, &
                   status, msg)
    if (status /= MBD_OK) return
    allocate (g(kd + 1, neq), stat=ierr)
    if (ierr /= 0) goto 90
    dropped = 0
    do attempt = 1, MAX_SWAPS + 1
      call gram()
      ! right-looking Cholesky; a pivot <= tol2 marks its row redundant (left out), or,
      ! when the dependency weighs another row far more (the row last in the order can
      ! carry a tiny weight, as cos(theta) ~ 4e-6 at a crank set upright: leaving it out
      ! would leave the rest nearly dependent), that row is left out instead and the
      ! factorization starts again
      redundant = dropped
      swapped = .false.
      do j = 1, neq
        dj = g(1, j)
        l = min(kd, neq - j)
        if (.not. dj > tol2) then
          if (attempt <= MAX_SWAPS .and. rnorm(rowof(j)) > zero .and. &
              dropped(rowof(j)) == 0) then
            r = heaviest(j)
            if (r /= j) then
              dropped(rowof(r)) = 1
              swapped = .true.
              exit
            end if
          end if
          redundant(rowof(j)) = 1
          g(:, j) = zero
          cycle
        end if
        dj = sqrt(dj)
        g(1, j) = dj
        do i = 2, l + 1
          g(i, j) = g(i, j) / dj
        end do
        do w = 1, l                            ! G(j+w, j+i) -= L(j+w, j) L(j+i, j), i <= w
          v = g(w + 1, j)
          if (abs(v) <= zero) cycle
          do i = 1, w
            g(w - i + 1, j + i) = g(w - i + 1, j + i) - v * g(i + 1, j)
          end do
        end do
      end do
      if (.not. swapped) exit
    end do
    if (present(use)) then
      where (.not. use) redundant = 0
      rank = count(use) - count(redundant == 1)
    else
      rank = neq - count(redundant == 1)
    end if
    return
90  call mem_fail(REAL_BYTES * 8 * (real(neq, wp) + 6 * n), 'the rank analysis of J (band)', &
                  HINT, status, msg)
  contains
    !> The block entry at flat position f of jb (MAXROW, NLOC, nc).
    pure real(wp) function jbf(f)
      integer, intent(in) :: f
      jbf = jb(mod(f - 1, MAXROW) + 1, mod((f - 1) / MAXROW, NLOC) + 1, &
               (f - 1) / (MAXROW * NLOC) + 1)
    end function jbf

    !> G of the unit rows taken (rnorm > 0, not dropped) in the band storage g.
    subroutine gram()
      integer :: c, ii, jj, a, b
      g = zero
      do c = 1, n
        do ii = cptr(c), cptr(c + 1) - 1
          a = crow(ii)
          if (.not. rnorm(a) > zero .or. dropped(a) == 1) cycle
          do jj = cptr(c), cptr(c + 1) - 1
            b = crow(jj)
            if (pos(a) < pos(b) .or. .not. rnorm(b) > zero .or. dropped(b) == 1) cycle
            g(1 + pos(a) - pos(b), pos(b)) = g(1 + pos(a) - pos(b), pos(b)) + &
              jbf(csrc(ii)) * jbf(csrc(jj)) / (rnorm(a) * rnorm(b))
          end do
        end do
      end do
    end subroutine gram

    !> The order position of the row with the largest weight in the dependency of the row at
    !! jj (its pivot zero): u_jj = sum_i c_i u_i over the rows before it, L^T c = L(jj, :)
    !! by back substitution (stopped once kd weights in a row are negligible: a dependency
    !! is a loop, local in the order); jj itself (weight 1) unless a weight passes
    !! SWAP_RATIO.
    integer function heaviest(jj) result(best)
      integer, intent(in) :: jj
      integer :: ii, k, quiet
      real(wp) :: cmax, x
      best = jj
      cmax = SWAP_RATIO
      quiet = 0
      do ii = jj - 1, 1, -1
        x = zero
        if (ii >= jj - kd) x = g(1 + jj - ii, ii)
        do k = ii + 1, min(ii + kd, jj - 1)
          x = x - g(1 + k - ii, ii) * cdep(k)
        end do
        cdep(ii) = zero
        if (g(1, ii) > zero) cdep(ii) = x / g(1, ii)
        if (abs(cdep(ii)) > cmax) then
          cmax = abs(cdep(ii)); best = ii
        end if
        quiet = merge(quiet + 1, 0, abs(cdep(ii)) <= 1.0e-14_wp * cmax)
        if (ii < jj - kd .and. quiet >= kd) exit
      end do
    end function heaviest
  end subroutine saddle_row_rank

end module mbd_saddle
