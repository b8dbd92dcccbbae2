!> mbd_kinematics: assembly, Newton-Raphson on Phi(q, t) = 0, velocities and accelerations,
!! the time loop, redundant constraints, and singular configurations.
!!
!! Per output time (Haug, ch. 3-4; Nikravesh, ch. 5):
!!   predictor    q = q_k + h q_dot_k + (the acceleration's Newton polynomial through the last
!!                four accelerations, integrated twice): error O(h**6)
!!   position     J(q) dq = -Phi(q, t),  q <- q + dq   until ||Phi||_inf <= tol
!!   velocity     J q_dot = nu                    (the last factorization is reused)
!!   acceleration J q_ddot = gamma(q, q_dot, t)   (same factorization)
!! Square, full-rank J: LU (dgetf2/dgetrf). Redundant constraints (more equations than the
!! rank): least squares by QR with column pivoting (dgeqp3), with the residual checked, so
!! consistent redundant constraints are satisfied exactly and contradicting ones are named.
!!
!! J is factored with its columns scaled to unit length at assembly (lengths and angles weigh
!! alike). A step is rejected and halved when Newton fails, when det J changes sign (LU mode),
!! when J is nearly singular (smallest/largest pivot < NEAR_SING), or when the solution leaves
!! its branch: the Newton correction exceeds half the predicted motion, or the velocity jumps
!! against its Taylor prediction (a switch of branch through a singular point). When the step falls
!! below tmin the configuration is singular. If the motion continues through it (a bifurcation,
!! as in a parallelogram at its collinear position), a step across it that lands on the
!! predicted branch is taken and the passage recorded. Outputs near the passage, where J is too
!! ill-conditioned for accurate accelerations (errors grow like cond**3 tol), are interpolated
!! (quintic Hermite) between regular anchor states d either side, d doubled from h/64 until
!! the pivot ratio there reaches ANCHOR_PIV. Otherwise (a dead centre) the run
!! stops, and the SVD of the column-scaled J names the dependent rows and the driver that can
!! no longer be met.
module mbd_kinematics
  use mbd_kinds, only: wp, zero, one, half
  use mbd_status, only: MBD_OK, MBD_BAD_SETTING, MBD_BAD_COUNT, MBD_SINGULAR, &
                        MBD_NO_CONVERGENCE, MBD_SINGULAR_CONFIG, MBD_ASSEMBLY_FAILED, &
                        MBD_LAPACK, MBD_INCONSISTENT, MBD_NO_MEMORY, MBD_USER_ABORT, &
                        MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail
  use mbd_points, only: NLOC, MAXROW
  use mbd_model, only: model_t, model_next_break
  use mbd_constraints, only: con_is_driver, con_name
  use mbd_assemble, only: asm_work_t, asm_init, assemble_blocks, assemble_gamma, assemble_dense, &
                          scatter_dense, init_extras, blocks_jv, blocks_jtv, scatter_values, &
                          asm_turn, assemble_phi
  use mbd_joint_revolute, only: revolute_curvature_all
  use mbd_band, only: band_t, band_plan, band_move, band_zero, band_norm1, band_factor, &
                      band_rcond, band_solve
  use mbd_linsolve, only: lu_factor, lu_solve, lu_det_sign, svd_null, row_rank, qr_factor, &
                          qr_solve, qr_lwork, lu_solve_rows, lu_factor_small, lu_solve_small, &
                          RANK_TOL
  use mbd_saddle, only: saddle_row_rank
  use mbd_assembly, only: band_lm_assemble
  use mbd_splu, only: splu_t, splu_init, splu_plan, splu_factor, splu_solve, splu_solve2, &
                      splu_solve_rows, splu_solve_rows_h, splu_pos, LMAX
  use mbd_lapack, only: dgels, dgecon, dtrcon
  use mbd_interp, only: hermite5
  use mbd_sensitivity, only: sens_t, sens_states, sens_hessian, sens_params, sens_kin_rhs
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: kin_opts_t, kin_work_t, kin_report_t, DEP_TOL, SING_RATIO, MAXPASS
  public :: SOLVER_AUTO, SOLVER_DENSE, SOLVER_BANDED
  public :: kin_work_init, kin_assemble, kin_rank, kin_rank_band, kin_newton, kin_vel_acc, &
            kin_run, &
            kin_singular_report, kin_out_count

  real(wp), parameter :: DEP_TOL = 1.0e-3_wp  !! |u_r| / max|u| above which a row is dependent
  !> sigma_min / sigma_max of the column-scaled J below which a configuration is singular
  real(wp), parameter :: SING_RATIO = 1.0e-3_wp
  real(wp), parameter :: JUMP_RATIO = half     !! largest Newton correction / predicted motion
  real(wp), parameter :: NEAR_SING = 1.0e-8_wp  !! 1/cond_1 of the scaled J: nearly singular
  real(wp), parameter :: ANCHOR_PIV = 1.0e-3_wp !! 1/cond_1 wanted at outputs and anchors
  !> LU pivot ratio below which the condition number is estimated (dgecon)
  real(wp), parameter :: COND_CHECK = 0.1_wp
  real(wp), parameter :: VJUMP_RATIO = 0.2_wp   !! largest velocity jump / velocity scale
  integer, parameter :: MAXPASS = 64           !! singular passages recorded
  integer, parameter :: MAX_SUBSTEPS = 100000  !! internal steps allowed per output interval
  integer, parameter :: SOLVER_AUTO = 0, SOLVER_DENSE = 1, SOLVER_BANDED = 2  !! linear solvers
  !> auto: banded LU when J is square, n >= BAND_MIN_N and the band (kl + ku + 1) is at most
  !! n / BAND_RATIO wide
  integer, parameter :: BAND_MIN_N = 60, BAND_RATIO = 4
  integer, parameter :: BAND_ASSEMBLY_MAXIT = 50  !! Newton iterations of a banded assembly
  !> the assembly's Newton start (square J, dense mode): iterations, and the largest step
  !! taken (lengths in units of the model's length scale, angles in rad)
  integer, parameter :: START_NEWTON_MAXIT = 12
  real(wp), parameter :: START_NEWTON_STEP = 0.25_wp
  !> plain-loop LU up to this order, LAPACK beyond
  integer, parameter :: SMALL_LU_N = 32
  !> dense mode, square J up to this order: sparse LU with a replayed pivot order (mbd_splu)
  integer, parameter :: SPARSE_MAX_N = 60
  !> divided differences of the accelerations in the predictor (its error O(h**(order + 3)))
  integer, parameter :: PRED_ORDER = 5
  !> positions-only runs (kin_opts_t%positions): chord steps (simplified Newton on the last
  !! factorization) while its pivot ratio is at least FAST_PIV and the coordinates have moved
  !! less than FAST_DRIFT times it (lengths in units of the length scale, angles in rad)
  !! since; at most CHORD_MAXIT corrections, each at most CHORD_RATE of the one before
  real(wp), parameter :: FAST_PIV = COND_CHECK, FAST_DRIFT = 0.1_wp, CHORD_RATE = 0.1_wp
  integer, parameter :: CHORD_MAXIT = 6
  !> accepted full steps in a row with a pivot ratio >= FAST_PIV before chord steps again,
  !! after leaving them; doubled (up to FAST_REENTER_MAX) each time they are left before one
  !! chord step was taken
  integer, parameter :: FAST_REENTER = 8, FAST_REENTER_MAX = 1024
  !> a chord correction of the angles up to this is turned into the bodies' cos and sin
  !! (asm_turn: first order, exact to rounding); a larger one takes cos and sin anew
  real(wp), parameter :: TURN_MAX = 1.0e-9_wp
  !> chord steps of a model of revolutes and absolute drivers alone (J's columns other than
  !! the angles' constant), dense or sparse LU, at most LIN_MAXB bodies: after a chord
  !! correction dq, the rest of the Newton step from J(q) - J(qf) in closed form
  !! (lin_correction), taken as the step's end when c = |J(qf)^-1 (J(qf) - J(q))| <= LIN_CMAX
  !! and LIN_SAFETY times the bound of its error, (sum_b 1 + |g_b|) |dq|**2 (1 + c) /
  !! (1 - c)**3, is below half the resolution
  integer, parameter :: LIN_MAXB = 4
  real(wp), parameter :: LIN_SAFETY = 2.0_wp, LIN_CMAX = 0.9_wp
  !> those steps' predictor order (the positions' divided differences used, from PRED_ORDER
  !! down to POS_ORDER_MIN): one lower after a step whose prediction's last term was below
  !! its error (the first correction: the term no longer helps), one higher after a step
  !! whose first correction was too large for the closed-form rest
  integer, parameter :: POS_ORDER_MIN = PRED_ORDER - 2
  !> dense-mode models with this many coordinates and more assemble by Levenberg-Marquardt in
  !! band storage when their structure allows (a dense iteration: a QR of (neq + n) x n);
  !! where it does not, their dense iterations end once a window of STALL_WINDOW of them
  !! reduces ||Phi||_2 by less than STALL_DECREASE of itself (the least squares crawl
  !! towards a point where the constraints cannot all hold: 400 dense iterations took 105 s
  !! at 603 coordinates for 0.6%; small models keep crawling, cheaply, to where J's rank
  !! tells contradicting constraints)
  integer, parameter :: LM_BAND_MIN_N = 200, STALL_WINDOW = 20
  real(wp), parameter :: STALL_DECREASE = 1.0e-3_wp
  !> a start is taken without a correction when the correction is below RES_ULPS units in the
  !! last place of every coordinate (of max(|q_i|, 1, L |theta|): below_resolution)
  real(wp), parameter :: RES_ULPS = 4.0_wp
  !> what to change when the dense J does not fit
  character(len=*), parameter :: DENSE_HINT = 'the dense solver keeps J as a full matrix: ' // &
    'for kinematics of a large square model use the banded solver (solver="banded"), ' // &
    'otherwise a smaller model'

  !> Settings of a kinematic analysis.
  type :: kin_opts_t
    real(wp) :: tol = 1.0e-12_wp    !! ||Phi||_inf tolerance, relative to the model length scale
    integer :: maxit = 25           !! Newton iterations per step
    real(wp) :: tmin = 1.0e-10_wp   !! time resolution of a singular configuration
    integer :: assembly_maxit = 400 !! damped iterations for the initial assembly
    integer :: solver = SOLVER_AUTO !! SOLVER_AUTO, SOLVER_DENSE or SOLVER_BANDED
    integer :: every = 1            !! store every k-th output (and the last)
    !> positions only: q_dot and q_ddot are not returned (qdout and qddout are work space)
    !! and, where J is well conditioned, the steps are chord steps without them
    logical :: positions = .false.
  end type kin_opts_t

  !> Work arrays, allocated once per analysis.
  type :: kin_work_t
    real(wp), allocatable :: phi(:), nu(:), gam(:), jac(:, :), qz(:)
    type(asm_work_t) :: asm         !! assembly work arrays
    real(wp), allocatable :: rhs(:), dq(:), tau(:), qrwork(:)
    real(wp), allocatable :: cs(:)  !! column scale of J (1/|J_k| at assembly)
    real(wp), allocatable :: cwork(:)   !! dgecon / dtrcon workspace (4 n)
    integer, allocatable :: ipiv(:), jpvt(:), iwork(:)
    logical :: lsq = .false.        !! least-squares mode (redundant constraints)
    real(wp) :: pivratio = one      !! 1/cond_1 estimate of the scaled J (dgecon, dtrcon)
    integer :: detsign = 0          !! sign of det J at the last LU factorization
    real(wp) :: tol = zero          !! absolute ||Phi|| tolerance in use
    real(wp) :: resid = zero        !! least-squares residual of the last solve
    integer :: newton_its = 0       !! Newton corrections taken
    integer :: lu_count = 0         !! factorizations
    logical :: banded = .false.     !! J is factored in band storage (no dense J but for a
                                    !! small model's Levenberg-Marquardt assembly)
    type(band_t) :: band            !! band plan, storage and factors
    real(wp) :: anorm = zero        !! ||J D||_1 of the band matrix before factoring
    !> small square J in dense mode: J D assembled straight into the sparse LU's values and
    !! factored in its planned pivot order; LAPACK's dense LU where that order is no longer
    !! stable (replanned) or J D is poorly conditioned (pivot ratio below COND_CHECK)
    logical :: sparse = .false.
    logical :: spfact = .false.     !! the factors in use are the sparse ones
    type(splu_t) :: sp              !! sparse LU plan, values and factors
    !> the blocks' entries for the sparse values: flat index into the blocks, column, place
    !! in sp%val; the first snon are in the pattern, the others must be zero
    integer, allocatable :: ssrc(:), scol(:), spos(:)
    integer :: snon = 0
    real(wp) :: offpat = zero       !! sum |entries| outside the sparse pattern (must be 0)
    !> the velocity J q_dot = nu solved together with the Newton correction of a start taken
    !! (kin_newton); kin_vel_acc uses it while the factors stay
    real(wp), allocatable :: qdp(:)
    logical :: vel_ready = .false.
  end type kin_work_t

  !> What happened: counters, redundancy, and the singular or failed configuration.
  type :: kin_report_t
    integer :: ndone = 0            !! output times computed
    integer :: driver = 0           !! driver that can no longer be met (constraint index)
    integer :: worst = 0            !! constraint with the largest residual at a failure
    integer :: deficiency = 0       !! rank deficiency of J at the singular configuration
    integer :: rejected = 0         !! rejected (halved) steps
    integer :: rank = 0             !! rank of J at the assembled configuration
    integer :: npass = 0            !! singular configurations passed through
    real(wp) :: t_fail = zero       !! time of the singular configuration or failure
    real(wp) :: smin = zero, smax = zero  !! extreme singular values of J there
    real(wp) :: resid = zero        !! ||Phi||_inf at a failure
    integer :: newton_its = 0       !! Newton corrections taken
    integer :: lu_count = 0         !! factorizations
    integer :: solver = SOLVER_DENSE  !! linear solver used
    integer :: kl = 0, ku = 0       !! band widths (banded solver)
    real(wp) :: tpass(MAXPASS) = zero     !! times of the passages
    real(wp), allocatable :: qsing(:)     !! configuration at a singularity or failure
    integer, allocatable :: dep(:)        !! 1 for each row in the dependent set there
    integer, allocatable :: redundant(:)  !! 1 for each redundant row at assembly
  end type kin_report_t

contains

  !> Allocate work arrays for model m; with a band plan J is kept in band storage (the plan
  !! is moved into w) and no n x n array is allocated. A dense J is checked against the
  !! memory first (mem_check); a failed allocation is MBD_NO_MEMORY.
  subroutine kin_work_init(m, w, status, msg, band, sparse)
    type(model_t), intent(in) :: m                 !! model
    type(kin_work_t), intent(out) :: w             !! work arrays
    integer, intent(out) :: status                 !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(inout) :: msg   !! explanation (on a failure)
    type(band_t), intent(inout), optional :: band  !! band plan of J (square J only), moved
    !> the sparse LU may serve a small square J (default); .false. for a single step, where
    !! planning its pivot order would cost more than the dense LU it replaces
    logical, intent(in), optional :: sparse
    integer :: nr, ierr, lq
    real(wp) :: bytes
    character(len=MSG_LEN) :: what
    status = MBD_OK
    nr = max(m%neq, m%nq)
    if (present(band)) then
      w%banded = band%n == m%nq .and. m%neq == m%nq
    end if
    ! vectors: phi, nu, gam (neq); qz, rhs, dq, tau, cs, cwork (4) (<= nr); 3 integer ones
    bytes = REAL_BYTES * (3 * real(m%neq, wp) + 11 * real(nr, wp))
    lq = 1
    write (what, '(a,i0,a,i0,a)') 'the dense constraint Jacobian J (', m%neq, ' x ', m%nq, ')'
    if (.not. w%banded) then
      lq = qr_lwork(m%neq, m%nq)
      bytes = bytes + REAL_BYTES * (real(m%neq, wp) * m%nq + lq)
      call mem_check(bytes, trim(what), DENSE_HINT, status, msg)
      if (status /= MBD_OK) return
    end if
    allocate (w%phi(m%neq), w%nu(m%neq), w%gam(m%neq), w%qz(m%nq), w%ipiv(m%nq), stat=ierr)
    if (ierr == 0) allocate (w%rhs(nr), w%dq(m%nq), w%tau(m%nq), w%jpvt(m%nq), stat=ierr)
    if (ierr == 0) allocate (w%cs(m%nq), w%cwork(4 * m%nq), w%iwork(m%nq), stat=ierr)
    if (ierr == 0) allocate (w%qrwork(lq), stat=ierr)
    if (ierr == 0 .and. .not. w%banded) allocate (w%jac(m%neq, m%nq), stat=ierr)
    if (ierr /= 0) then
      if (w%banded) what = 'the kinematic work arrays'
      call mem_fail(bytes, trim(what), DENSE_HINT, status, msg)
      return
    end if
    if (w%banded) call band_move(band, w%band)
    call asm_init(m, w%asm, status, msg)
    if (status /= MBD_OK) return
    w%qz = zero
    w%cs = one
    if (present(sparse)) then
      if (.not. sparse) return
    end if
    if (.not. w%banded .and. m%neq == m%nq .and. m%nq <= SPARSE_MAX_N) then
      call sparse_init(m, w, status, msg)
    end if
  end subroutine kin_work_init

  !> The sparse LU of J (structure from the blocks' map); an entry written twice keeps the
  !! dense LU (status MBD_OK, w%sparse false).
  subroutine sparse_init(m, w, status, msg)
    type(model_t), intent(in) :: m                 !! model (square J)
    type(kin_work_t), intent(inout) :: w           !! work arrays (assembly map set)
    integer, intent(out) :: status                 !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(inout) :: msg   !! explanation (on a failure)
    integer, allocatable :: rows(:), cols(:)
    integer :: ne, ierr
    ne = size(w%asm%src)
    allocate (rows(ne), cols(ne), w%ssrc(ne), w%scol(ne), w%spos(ne), w%qdp(m%nq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(12 * real(ne, wp), 'the sparse LU of J', DENSE_HINT, status, msg)
      return
    end if
    rows = mod(w%asm%dst - 1, m%neq) + 1
    cols = w%asm%col
    w%spos = 0; w%ssrc = w%asm%src; w%scol = w%asm%col; w%snon = 0
    call splu_init(m%nq, rows, cols, w%sp, status, msg)
    w%sparse = status == MBD_OK
    if (status == MBD_SINGULAR) then
      status = MBD_OK; msg = ''
    end if
    if (w%sparse) call probe_pattern(m, w, rows, cols)
  end subroutine sparse_init

  !> The entries of J that are non-zero at a generic configuration (no angle a multiple of
  !! 90 degrees, no coordinate zero) join the pattern the first plan is made on: an entry
  !! that happens to vanish at the start (a crank along x: its B s' has a zero) would
  !! otherwise be left out and force a second plan once it moves. Depends on the model only.
  subroutine probe_pattern(m, w, rows, cols)
    type(model_t), intent(in) :: m                 !! model
    type(kin_work_t), intent(inout) :: w           !! work arrays (sparse LU initialized)
    integer, intent(in) :: rows(:), cols(:)        !! the blocks' entries in J
    real(wp) :: qg(m%nq), v
    integer :: i, e, f, r, sl, k
    do i = 1, m%nq
      qg(i) = 0.37_wp + 0.113_wp * i               ! extra coordinates as they are
    end do
    do i = 1, m%nb
      qg(3 * i - 2) = qg(3 * i - 2) * m%lscale; qg(3 * i - 1) = qg(3 * i - 1) * m%lscale
      qg(3 * i) = 0.37_wp + 0.211_wp * i           ! angles 0.58, 0.79, ... rad
    end do
    call assemble_blocks(m, qg, w%qz, zero, w%phi, w%nu, w%gam, w%asm)
    do e = 1, size(w%asm%src)
      f = w%asm%src(e) - 1                         ! flat index into jb(MAXROW, NLOC, nc)
      r = mod(f, MAXROW) + 1; sl = mod(f / MAXROW, NLOC) + 1; k = f / (MAXROW * NLOC) + 1
      v = w%asm%jb(r, sl, k)
      if (ieee_is_finite(v) .and. abs(v) > zero) w%sp%seen(rows(e), cols(e)) = .true.
    end do
  end subroutine probe_pattern

  !> Band plan of J from its structure (the nonzeros of the constraint blocks).
  subroutine kin_band_plan(m, band, status, msg)
    type(model_t), intent(in) :: m              !! model (square J)
    type(band_t), intent(out) :: band           !! plan
    integer, intent(out) :: status              !! MBD_OK or the failure of band_plan
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, allocatable :: rows(:), cols(:)
    integer :: k, s, r, n, ierr
    msg = ''
    n = 0
    do k = 1, m%nc
      n = n + m%nrow(k) * count(m%loc(:, k) > 0)
    end do
    allocate (rows(n), cols(n), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(8 * real(n, wp), 'the structure of J', 'use a smaller model', status, msg)
      return
    end if
    n = 0
    do k = 1, m%nc
      do s = 1, NLOC
        if (m%loc(s, k) == 0) cycle
        do r = 1, m%nrow(k)
          n = n + 1
          rows(n) = m%row0(k) + r - 1
          cols(n) = m%loc(s, k)
        end do
      end do
    end do
    call band_plan(m%nq, rows, cols, band, status, msg)
  end subroutine kin_band_plan

  !> Phi, nu, gamma at (q, q_dot, t) and J D in the solver's storage: dense J in w%jac
  !! (scaled in factor), or J D scattered into the band (D = diag(w%cs)) with its 1-norm.
  subroutine assemble_j(m, w, q, qd, t)
    type(model_t), intent(in) :: m          !! model
    type(kin_work_t), intent(inout) :: w    !! work arrays
    real(wp), intent(in) :: q(:), qd(:)     !! coordinates and velocities
    real(wp), intent(in) :: t               !! time
    integer :: k, s, r, c, r0, d0, jc, ir
    call assemble_blocks(m, q, qd, t, w%phi, w%nu, w%gam, w%asm)
    if (w%sparse) then
      call scatter_values(w%asm, w%ssrc, w%scol, w%spos, w%snon, w%cs, w%sp%val, w%offpat)
      return
    end if
    if (.not. w%banded) then
      call scatter_dense(w%asm, w%jac, w%cs)      ! J D, scaled here
      return
    end if
    ! J(i, j) D(j) -> ab(kl + ku + 1 + prow(i) - pcol(j), pcol(j))  (the planned structure:
    ! band_plan saw every (row, column) of the blocks, so no entry falls outside)
    call band_zero(w%band)
    d0 = w%band%kl + w%band%ku + 1
    do k = 1, m%nc
      r0 = m%row0(k) - 1
      do s = 1, NLOC
        c = m%loc(s, k)
        if (c == 0) cycle
        jc = w%band%pcol(c)
        do r = 1, m%nrow(k)
          ir = d0 + w%band%prow(r0 + r) - jc
          w%band%ab(ir, jc) = w%band%ab(ir, jc) + w%asm%jb(r, s, k) * w%cs(c)
        end do
      end do
    end do
    w%anorm = band_norm1(w%band)
  end subroutine assemble_j

  !> Phi, nu, gamma and the dense, unscaled J in w%jac (dense mode only: the band path
  !! has no n x n array and makes its diagnoses from the band and the blocks).
  subroutine dense_j(m, w, q, qd, t)
    type(model_t), intent(in) :: m          !! model
    type(kin_work_t), intent(inout) :: w    !! work arrays (dense mode)
    real(wp), intent(in) :: q(:), qd(:)     !! coordinates and velocities
    real(wp), intent(in) :: t               !! time
    call assemble_dense(m, q, qd, t, w%phi, w%nu, w%gam, w%asm, w%jac)
  end subroutine dense_j

  !> Factor J D (in w%jac or the band, from assemble_j) by LU or, in least-squares mode, QR.
  subroutine factor(w, status)
    type(kin_work_t), intent(inout) :: w   !! work arrays
    integer, intent(out) :: status         !! MBD_OK or MBD_SINGULAR
    character(len=MSG_LEN) :: msg
    integer :: i, k, n, info
    real(wp) :: anorm, colsum, umin, umax
    w%lu_count = w%lu_count + 1
    w%spfact = .false.; w%vel_ready = .false.
    if (w%sparse .and. .not. w%lsq) then
      call sparse_factor(w, status)
      if (w%spfact .or. status == MBD_NO_MEMORY) return
      call scatter_dense(w%asm, w%jac, w%cs)      ! the dense LU below, of the same J D
    end if
    if (w%banded) then
      ! B = P_r J D P_c^T = P L U (dgbtrf); 1/cond_1 estimated only where it may matter
      call band_factor(w%band, status, msg, w%detsign, w%pivratio)
      if (status == MBD_OK .and. w%pivratio < COND_CHECK) &
        call band_rcond(w%band, w%anorm, w%pivratio, info, msg)
      return
    end if
    n = size(w%cs)
    anorm = zero        ! ||J D||_1 (assemble_j scaled the columns)
    do k = 1, n
      colsum = zero
      do i = 1, size(w%jac, 1)
        colsum = colsum + abs(w%jac(i, k))
      end do
      anorm = max(anorm, colsum)
    end do
    w%pivratio = zero
    if (w%lsq) then
      call qr_factor(w%jac, w%jpvt, w%tau, w%qrwork, status, msg)
      if (status == MBD_OK) call dtrcon('1', 'U', 'N', n, w%jac, size(w%jac, 1), w%pivratio, &
                                        w%cwork, w%iwork, info)
    else
      call lu_factor(w%jac, w%ipiv, status, msg)
      if (status == MBD_OK) then
        w%detsign = lu_det_sign(w%jac, w%ipiv)
        ! cheap pivot ratio first; the condition estimate only where it may matter
        umin = huge(one); umax = zero
        do k = 1, n
          umin = min(umin, abs(w%jac(k, k))); umax = max(umax, abs(w%jac(k, k)))
        end do
        w%pivratio = umin / umax
        if (w%pivratio < COND_CHECK) call dgecon('1', n, w%jac, n, anorm, w%pivratio, &
                                                 w%cwork, w%iwork, info)
      end if
    end if
  end subroutine factor

  !> Factor J D (assembled into w%sp%val) in the planned pivot order; plan again (on the
  !! dense J D) when there is no plan, an entry outside the pattern is non-zero, a pivot is
  !! zero or a multiplier exceeds LMAX. w%spfact: the sparse factors are good (pivot ratio
  !! >= COND_CHECK); otherwise the caller factors densely (status MBD_OK) or MBD_NO_MEMORY.
  subroutine sparse_factor(w, status)
    type(kin_work_t), intent(inout) :: w   !! work arrays
    integer, intent(out) :: status         !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN) :: msg
    real(wp) :: lmax
    integer :: st, e, r, p, pass, ne
    status = MBD_OK
    st = MBD_SINGULAR
    lmax = zero
    if (w%sp%planned .and. w%offpat <= zero) &
      call splu_factor(w%sp, st, lmax, w%detsign, w%pivratio)
    if (st /= MBD_OK .or. .not. lmax <= LMAX) then
      call scatter_dense(w%asm, w%jac, w%cs)
      call splu_plan(w%sp, w%jac, st, msg)
      if (st == MBD_NO_MEMORY) status = st
      if (st /= MBD_OK) return
      ! the map: the entries the pattern holds first
      w%snon = 0
      do pass = 1, 2
        do e = 1, size(w%spos)
          r = mod(w%asm%dst(e) - 1, size(w%jac, 1)) + 1
          p = splu_pos(w%sp, r, w%asm%col(e))
          if ((p > 0) .neqv. (pass == 1)) cycle
          w%snon = w%snon + 1
          w%ssrc(w%snon) = w%asm%src(e); w%scol(w%snon) = w%asm%col(e); w%spos(w%snon) = p
        end do
        if (pass == 1) ne = w%snon
      end do
      w%snon = ne
      call splu_factor(w%sp, st, lmax, w%detsign, w%pivratio)
      if (st /= MBD_OK) return
    end if
    w%spfact = w%pivratio >= COND_CHECK
  end subroutine sparse_factor

  !> Solve J x = b with the factors (least squares in QR mode; w%resid is its residual).
  subroutine solve(w, b, x)
    type(kin_work_t), intent(inout) :: w   !! work arrays with the factors
    real(wp), intent(in) :: b(:)           !! right-hand side (neq)
    real(wp), intent(out) :: x(:)          !! solution (nq)
    integer :: st
    character(len=MSG_LEN) :: msg
    if (w%spfact) then
      call splu_solve(w%sp, b, x, w%cs)       ! x = D (J D)^-1 b
      w%resid = zero
      return
    end if
    if (w%lsq) then
      w%rhs(1:size(b)) = b
      call qr_solve(w%jac, w%jpvt, w%tau, w%rhs(1:size(b)), x, w%resid, w%qrwork)
    else if (w%banded) then
      x = b
      call band_solve(w%band, x, st, msg)
      w%resid = zero
    else
      x = b
      call lu_solve(w%jac, w%ipiv, x, st, msg)
      w%resid = zero
    end if
    x = x * w%cs
  end subroutine solve

  !> Solve J X = B for several right-hand sides with the dense, band or QR factors (as solve;
  !! kin_sens calls the sparse factors' solve itself), B given as rows
  !! bt = B^T (n rounded up to a multiple of 4, neq; padding rows zero) and overwritten; the
  !! dense LU by plain loops over all of them at once. X is returned as columns x (nq, n) and
  !! as rows xt (n rounded up, nq; padding rows zero).
  subroutine solve_cols(w, bt, x, b, xt)
    type(kin_work_t), intent(inout) :: w   !! work arrays with the factors
    real(wp), intent(inout) :: bt(:, :)    !! right-hand sides as rows (4 k, neq), spoiled
    real(wp), intent(out) :: x(:, :)       !! solutions (nq, n)
    real(wp), intent(out) :: b(:)          !! work (neq): one right-hand side at a time
    real(wp), intent(inout) :: xt(:, :)    !! solutions as rows (4 k, nq)
    integer :: k
    if (w%lsq .or. w%banded) then
      do k = 1, size(x, 2)
        b = bt(k, :)
        call solve(w, b, x(:, k))
        xt(k, :) = x(:, k)
      end do
      return
    end if
    call lu_solve_rows(w%jac, w%ipiv, bt)
    do k = 1, size(x, 2)
      x(:, k) = bt(k, :) * w%cs
      xt(k, :) = x(:, k)
    end do
  end subroutine solve_cols

  !> The Newton correction w%dq from J dq = -Phi with the factors (Phi negated in place and
  !! back: an expression argument -w%phi would be a heap temporary at every iteration).
  subroutine solve_newton(w)
    type(kin_work_t), intent(inout) :: w   !! work arrays with the factors and Phi
    w%phi = -w%phi
    call solve(w, w%phi, w%dq)
    w%phi = -w%phi
  end subroutine solve_newton

  !> Newton-Raphson on Phi(q, t) = 0 from q. On success w holds the factors of J(q) at the
  !! returned q and w%nu = nu(q, t). In least-squares mode a correction that no longer
  !! reduces Phi while ||Phi|| > tol means the redundant constraints contradict:
  !! MBD_INCONSISTENT.
  subroutine kin_newton(m, w, q, t, maxit, status)
    type(model_t), intent(in) :: m          !! model
    type(kin_work_t), intent(inout) :: w    !! work arrays
    real(wp), intent(inout) :: q(:)         !! start, then solution
    real(wp), intent(in) :: t               !! time
    integer, intent(in) :: maxit            !! iteration limit
    integer, intent(out) :: status          !! MBD_OK, MBD_NO_CONVERGENCE, MBD_SINGULAR, ...
    real(wp) :: res, res0
    integer :: it
    res0 = huge(one)
    do it = 0, maxit
      call assemble_j(m, w, q, w%qz, t)
      res = maxval(abs(w%phi))
      if (.not. (res <= huge(one))) exit                 ! NaN or overflow
      if (it > 0 .and. res > 1.0e3_wp * res0 .and. res > w%tol) exit   ! diverging
      if (it == 0) res0 = res
      call factor(w, status)
      if (status /= MBD_OK) return
      if (it > 0 .and. res <= w%tol) return
      if (it == maxit) exit
      if (it == 0 .and. res <= w%tol .and. w%spfact) then
        ! the correction and the velocity in one pass (the velocity kept if the start is)
        call splu_solve2(w%sp, w%phi, w%nu, w%dq, w%qdp, w%cs)
        w%vel_ready = .true.
      else
        call solve_newton(w)
      end if
      ! a start that meets tol is taken only when a Newton correction would not move it:
      ! within RES_ULPS units in the last place of each coordinate, so that the positions
      ! keep the accuracy of a correction (quadratic: far below tol), not just tol
      if (it == 0 .and. res <= w%tol) then
        if (below_resolution(size(q), m%nb, m%lscale, q, w%dq)) then
          ! taken with its correction: J, nu and the factors of the start serve (they differ
          ! in the last places); the angles' cos and sin turned by the correction
          q = q + w%dq
          call asm_turn(m, w%asm, w%dq)
          return
        end if
      end if
      w%vel_ready = .false.
      if (w%lsq .and. maxval(abs(w%dq)) <= 1.0e-3_wp * w%tol .and. res > w%tol) then
        status = MBD_INCONSISTENT; return
      end if
      q = q + w%dq
      w%newton_its = w%newton_its + 1
    end do
    status = MBD_NO_CONVERGENCE
  end subroutine kin_newton

  !> Velocities and accelerations at a converged q: J q_dot = nu, J q_ddot = gamma, with the
  !! factors kin_newton left in w. status MBD_INCONSISTENT when a least-squares residual
  !! shows the redundant constraints disagree at velocity (level 1) or acceleration (level 2)
  !! level; w%phi then holds the residual J x - b of that level.
  subroutine kin_vel_acc(m, w, q, t, qd, qdd, status, level)
    type(model_t), intent(in) :: m          !! model
    type(kin_work_t), intent(inout) :: w    !! work arrays (factors of J(q), nu(q, t))
    real(wp), intent(in) :: q(:)            !! converged coordinates
    real(wp), intent(in) :: t               !! time
    real(wp), intent(out) :: qd(:)          !! velocities
    real(wp), intent(out) :: qdd(:)         !! accelerations
    integer, intent(out) :: status          !! MBD_OK or MBD_INCONSISTENT
    integer, intent(out), optional :: level !! 1 velocity, 2 acceleration (when inconsistent)
    status = MBD_OK
    if (w%vel_ready) then
      qd = w%qdp                 ! solved with kin_newton's last correction
      w%vel_ready = .false.
    else
      call solve(w, w%nu, qd)
    end if
    if (w%lsq) then
      if (w%resid > 1.0e-8_wp * (one + maxval(abs(w%nu)))) status = MBD_INCONSISTENT
    end if
    if (status == MBD_INCONSISTENT) then
      if (present(level)) level = 1
      call dense_j(m, w, q, w%qz, t)
      w%phi = matmul(w%jac, qd) - w%nu
      return
    end if
    call assemble_gamma(m, q, qd, t, w%gam, w%asm)      ! J (its factors) and nu stay
    call solve(w, w%gam, qdd)
    if (w%lsq) then
      if (w%resid > 1.0e-8_wp * (one + maxval(abs(w%gam)))) status = MBD_INCONSISTENT
    end if
    if (status == MBD_INCONSISTENT) then
      if (present(level)) level = 2
      call dense_j(m, w, q, qd, t)
      w%phi = matmul(w%jac, qdd) - w%gam
    end if
  end subroutine kin_vel_acc

  !> The assembly's first try for a square J in dense mode: Newton, J dq = -Phi, from the
  !! estimates, each step accepted as Levenberg-Marquardt accepts one (||Phi||_2 falls) and
  !! only while it is short (max |dq| <= START_NEWTON_STEP: no jump to another branch where
  !! the damped steps would stay near the estimates). True when ||Phi||_inf <= tol; false
  !! (q then is wherever it stopped) on a longer step, a rise, a singular J or no
  !! convergence within START_NEWTON_MAXIT iterations.
  logical function start_newton(m, w, q, t) result(ok)
    type(model_t), intent(in) :: m          !! model
    type(kin_work_t), intent(inout) :: w    !! work arrays (dense mode, w%jac n x n)
    real(wp), intent(inout) :: q(:)         !! estimates, then the iterate
    real(wp), intent(in) :: t               !! time
    real(wp) :: f, fprev
    integer :: it, st
    character(len=MSG_LEN) :: msg
    ok = .false.
    fprev = huge(one)
    do it = 0, START_NEWTON_MAXIT
      call dense_j(m, w, q, w%qz, t)
      f = norm2(w%phi)
      if (.not. f < fprev) return                      ! a rise, NaN or overflow
      if (maxval(abs(w%phi)) <= w%tol) then
        ok = .true.; return
      end if
      if (it == START_NEWTON_MAXIT) return
      w%dq = -w%phi
      if (size(q) <= SMALL_LU_N) then
        call lu_factor_small(w%jac, w%ipiv, st)
        if (st /= MBD_OK) return
        call lu_solve_small(w%jac, w%ipiv, w%dq)
      else
        call lu_factor(w%jac, w%ipiv, st, msg)
        if (st /= MBD_OK) return
        call lu_solve(w%jac, w%ipiv, w%dq, st, msg)
        if (st /= MBD_OK) return
      end if
      if (.not. maxval(abs(w%dq)) <= START_NEWTON_STEP) return
      q = q + w%dq
      fprev = f
    end do
  end function start_newton

  !> Assemble: from rough estimates q (extras are estimated here) minimize ||Phi(q, t)||^2 by
  !! Levenberg-Marquardt (steps from the least-squares problem [J; sqrt(mu) I] dq = [-Phi; 0],
  !! dgels), to ||Phi||_inf <= tol. Works for any number of equations. On failure the
  !! residual and the constraint with the largest residual are reported; if J is rank
  !! deficient there, the rows that contradict each other (those with a residual: at the
  !! minimum Phi is orthogonal to the range of J) are flagged in rep%dep, MBD_INCONSISTENT.
  !! Band mode: Newton from the estimates; if it fails, the same Levenberg-Marquardt in band
  !! storage (mbd_assembly band_lm_assemble, no n x n array) and on a failure the band rank
  !! diagnosis (band_failure). Both end early on a least-squares crawl (STALL_WINDOW).
  subroutine kin_assemble(m, w, q, t, opts, rep, status, msg)
    type(model_t), intent(in) :: m           !! model
    type(kin_work_t), intent(inout) :: w     !! work arrays
    real(wp), intent(inout) :: q(:)          !! estimates, then the assembled configuration
    real(wp), intent(in) :: t                !! time
    type(kin_opts_t), intent(in) :: opts     !! settings
    type(kin_report_t), intent(inout) :: rep !! failure details
    integer, intent(out) :: status           !! MBD_OK, MBD_ASSEMBLY_FAILED, MBD_INCONSISTENT
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    real(wp), allocatable :: aug(:, :), rhs(:), work(:), qt(:), phit(:)
    real(wp) :: mu, f, ft, wq(1), dmax, pmax, bytes
    integer :: it, n, neq, info, lwork, i, k, rank, st, ierr
    integer, allocatable :: flags(:)
    real(wp) :: fwin
    character(len=*), parameter :: WHAT = 'the assembly (Levenberg-Marquardt on the dense J)'

    status = MBD_OK; msg = ''
    n = m%nq; neq = m%neq
    call init_extras(m, q)
    allocate (qt(n), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * n, WHAT, DENSE_HINT, status, msg); return
    end if
    call dgels('N', neq + n, n, 1, wq, neq + n, wq, neq + n, wq, -1, info)
    lwork = max(1, int(wq(1)))
    bytes = REAL_BYTES * ((real(neq, wp) + n) * (n + 1) + neq + lwork)
    if (w%banded) then
      ! square models in band storage: plain Newton first, then Levenberg-Marquardt in band
      ! storage (no n x n array; the dense one took 105 s at 603 coordinates), then on a
      ! failure the band rank diagnosis
      qt = q
      call kin_newton(m, w, q, t, BAND_ASSEMBLY_MAXIT, st)
      if (st == MBD_OK) return
      q = qt
      call band_lm_assemble(m, q, t, w%tol, opts%assembly_maxit, status, msg, k, pmax)
      if (status == MBD_ASSEMBLY_FAILED) call band_failure(m, w, q, t, rep, status, msg)
      return
    end if
    if (.not. w%banded .and. .not. w%lsq .and. neq == n) then
      ! square J: the Newton steps Levenberg-Marquardt would take as mu -> 0, while they
      ! are short and reduce ||Phi||_2; otherwise Levenberg-Marquardt from the estimates
      qt = q
      if (start_newton(m, w, q, t)) return
      q = qt
    end if
    if (n >= LM_BAND_MIN_N) then
      ! a large dense-mode model (J not square: redundant rows): Levenberg-Marquardt in band
      ! storage where its structure allows (each dense iteration is a QR of (neq + n) x n)
      qt = q
      call band_lm_assemble(m, q, t, w%tol, opts%assembly_maxit, status, msg, k, pmax)
      if (status == MBD_OK) return
      if (status == MBD_ASSEMBLY_FAILED) then
        call band_failure(m, w, q, t, rep, status, msg)
        return
      end if
      q = qt                                    ! (no band plan: the dense one below)
    end if
    call mem_check(bytes, WHAT, DENSE_HINT, status, msg)
    if (status /= MBD_OK) return
    allocate (aug(neq + n, n), rhs(neq + n), phit(neq), work(lwork), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(bytes, WHAT, DENSE_HINT, status, msg); return
    end if
    call dense_j(m, w, q, w%qz, t)
    f = norm2(w%phi)
    dmax = zero
    do k = 1, n
      dmax = max(dmax, sum(w%jac(:, k)**2))
    end do
    mu = 1.0e-3_wp * max(dmax, one)
    fwin = f
    do it = 1, opts%assembly_maxit
      if (maxval(abs(w%phi)) <= w%tol) exit
      ! a large model crawling towards a least-squares point (LM_BAND_MIN_N)
      if (mod(it, STALL_WINDOW) == 0 .and. n >= LM_BAND_MIN_N) then
        if (f > (one - STALL_DECREASE) * fwin) exit
        fwin = f
      end if
      aug = zero
      aug(1:neq, :) = w%jac
      do i = 1, n
        aug(neq + i, i) = sqrt(mu)
      end do
      rhs = zero; rhs(1:neq) = -w%phi
      call dgels('N', neq + n, n, 1, aug, neq + n, rhs, neq + n, work, lwork, info)
      if (info /= 0) then
        mu = mu * 10.0_wp; cycle
      end if
      qt = q + rhs(1:n)
      call assemble_dense(m, qt, w%qz, t, phit, w%nu, w%gam, w%asm, w%jac)
      ft = norm2(phit)
      if (ft < f) then
        q = qt; f = ft; w%phi = phit
        mu = max(mu / 10.0_wp, 1.0e-20_wp * max(dmax, one))
      else
        call dense_j(m, w, q, w%qz, t)
        mu = mu * 10.0_wp
        if (mu > 1.0e20_wp * max(dmax, one)) exit
      end if
    end do
    pmax = maxval(abs(w%phi))
    if (pmax <= 1.0e3_wp * w%tol) return
    rep%resid = pmax
    rep%worst = m%con_of_row(maxloc(abs(w%phi), 1))
    rep%t_fail = t
    rep%qsing = q
    allocate (flags(neq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(4 * real(neq, wp), WHAT, DENSE_HINT, status, msg); return
    end if
    call row_rank(w%jac, rank, flags, st, msg)
    if (st == MBD_NO_MEMORY) then
      status = st; return
    end if
    if (st == MBD_OK .and. rank < neq) then
      status = MBD_INCONSISTENT
      rep%rank = rank
      rep%dep = merge(1, 0, abs(w%phi) > DEP_TOL * pmax)
      rep%redundant = flags
      write (msg, '(a,es10.3,a)') 'assembly failed: redundant constraints contradict each '// &
        'other (smallest residual ||Phi|| = ', pmax, ')'
    else
      status = MBD_ASSEMBLY_FAILED
      write (msg, '(a,es10.3,a,i0,a)') 'assembly failed: no configuration satisfies the '// &
        'constraints near the estimates; smallest residual ||Phi|| = ', pmax, &
        ', largest in constraint ', rep%worst, ' ('//trim(con_name(m%kind(rep%worst)))//')'
    end if
  end subroutine kin_assemble

  !> A failed assembly in band mode, at the best configuration q found (band_lm_assemble):
  !! rep names the residual and its largest constraint; the band rank analysis of J's rows
  !! (saddle_row_rank) tells constraints that contradict each other (MBD_INCONSISTENT, as
  !! kin_assemble's dense diagnosis) from no configuration near (MBD_ASSEMBLY_FAILED).
  subroutine band_failure(m, w, q, t, rep, status, msg)
    type(model_t), intent(in) :: m           !! model
    type(kin_work_t), intent(inout) :: w     !! work arrays (band mode)
    real(wp), intent(in) :: q(:)             !! the best configuration found
    real(wp), intent(in) :: t                !! time
    type(kin_report_t), intent(inout) :: rep !! failure details
    integer, intent(out) :: status           !! MBD_INCONSISTENT, MBD_ASSEMBLY_FAILED or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer :: rank, st
    call assemble_blocks(m, q, w%qz, t, w%phi, w%nu, w%gam, w%asm)
    rep%resid = maxval(abs(w%phi))
    rep%worst = m%con_of_row(maxloc(abs(w%phi), 1))
    rep%t_fail = t
    rep%qsing = q
    ! (row_rank: |R_kk| / |R_11| < RANK_TOL of unit rows; here the squared distance)
    call saddle_row_rank(m, w%asm%jb, RANK_TOL**2, rep%redundant, rank, st, msg)
    if (st == MBD_NO_MEMORY) then
      status = st; return
    end if
    if (st == MBD_OK .and. rank < m%neq) then
      status = MBD_INCONSISTENT
      rep%rank = rank
      rep%dep = merge(1, 0, abs(w%phi) > DEP_TOL * rep%resid)
      write (msg, '(a,es10.3,a)') 'assembly failed: redundant constraints contradict each '// &
        'other (smallest residual ||Phi|| = ', rep%resid, ')'
    else
      rep%redundant = 0
      status = MBD_ASSEMBLY_FAILED
      write (msg, '(a,es10.3,a,i0,a)') 'assembly failed: no configuration satisfies the '// &
        'constraints near the estimates (banded solver); smallest residual ||Phi|| = ', &
        rep%resid, ', largest in constraint ', rep%worst, &
        ' ('//trim(con_name(m%kind(rep%worst)))//')'
    end if
  end subroutine band_failure

  !> Rank of J at q and the redundant rows (1 in redundant: rows that repeat what the rows
  !! before them impose, see row_rank). Dense mode only.
  !! mobility: nq minus the rank of the kinematic (non-driver) rows.
  subroutine kin_rank(m, w, q, t, rank, mobility, redundant, status, msg)
    type(model_t), intent(in) :: m           !! model
    type(kin_work_t), intent(inout) :: w     !! work arrays (dense mode)
    real(wp), intent(in) :: q(:)             !! configuration
    real(wp), intent(in) :: t                !! time
    integer, intent(out) :: rank             !! rank of J
    integer, intent(out) :: mobility         !! degrees of freedom of the joints alone
    integer, intent(out) :: redundant(:)     !! 1 for a redundant row (neq)
    integer, intent(out) :: status           !! MBD_OK, MBD_LAPACK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, allocatable :: flags(:)
    real(wp), allocatable :: jk(:, :)
    integer :: r, nk, rk, ierr
    mobility = 0
    call dense_j(m, w, q, w%qz, t)
    call row_rank(w%jac, rank, redundant, status, msg)
    if (status /= MBD_OK) return
    nk = 0
    do r = 1, m%neq
      if (.not. con_is_driver(m%kind(m%con_of_row(r)))) nk = nk + 1
    end do
    if (nk == 0) then
      mobility = m%nq
      return
    end if
    ! the kinematic rows of J, copied (a vector subscript would be an unchecked temporary)
    allocate (flags(nk), jk(nk, m%nq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * nk * real(m%nq, wp), 'the rank analysis of J (dense)', &
                    DENSE_HINT, status, msg)
      return
    end if
    nk = 0
    do r = 1, m%neq
      if (con_is_driver(m%kind(m%con_of_row(r)))) cycle
      nk = nk + 1
      jk(nk, :) = w%jac(r, :)
    end do
    call row_rank(jk, rk, flags, status, msg)
    mobility = m%nq - rk
  end subroutine kin_rank

  !> kin_rank without a dense J (large models): the band rank analysis of J's rows
  !! (saddle_row_rank, the ordered selection of row_rank in the rows' band order), of all
  !! rows for the rank and the redundant ones, of the joints' rows for the mobility.
  subroutine kin_rank_band(m, q, t, rank, mobility, redundant, status, msg)
    type(model_t), intent(in) :: m           !! model
    real(wp), intent(in) :: q(:)             !! configuration
    real(wp), intent(in) :: t                !! time
    integer, intent(out) :: rank             !! rank of J
    integer, intent(out) :: mobility         !! degrees of freedom of the joints alone
    integer, intent(out) :: redundant(:)     !! 1 for a redundant row (neq)
    integer, intent(out) :: status           !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(asm_work_t) :: aw
    real(wp), allocatable :: phi(:), nu(:), gam(:), qz(:)
    logical, allocatable :: joints(:)
    integer, allocatable :: flags(:)
    integer :: r, rk, ierr
    rank = 0; mobility = 0; redundant = 0
    allocate (phi(m%neq), nu(m%neq), gam(m%neq), qz(m%nq), joints(m%neq), flags(m%neq), &
              stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * (5 * real(m%neq, wp) + m%nq), 'the rank analysis of J (band)', &
                    'use a smaller model', status, msg)
      return
    end if
    call asm_init(m, aw, status, msg)
    if (status /= MBD_OK) return
    qz = zero
    call assemble_blocks(m, q, qz, t, phi, nu, gam, aw)
    ! (row_rank: |R_kk| / |R_11| < RANK_TOL of unit rows; here the squared distance)
    call saddle_row_rank(m, aw%jb, RANK_TOL**2, redundant, rank, status, msg)
    if (status /= MBD_OK) return
    do r = 1, m%neq
      joints(r) = .not. con_is_driver(m%kind(m%con_of_row(r)))
    end do
    call saddle_row_rank(m, aw%jb, RANK_TOL**2, flags, rk, status, msg, use=joints)
    mobility = m%nq - rk
  end subroutine kin_rank_band

  !> SVD of the column-scaled J at q: which rows became dependent and which driver can no
  !! longer be met. Band mode: the smallest singular triple by inverse iteration and the
  !! largest by power iteration (band_singular), one dependent set (deficiency 1).
  subroutine kin_singular_report(m, w, q, t, rep, status, msg)
    type(model_t), intent(in) :: m           !! model
    type(kin_work_t), intent(inout) :: w     !! work arrays
    real(wp), intent(in) :: q(:)             !! configuration
    real(wp), intent(in) :: t                !! time
    type(kin_report_t), intent(inout) :: rep !! filled: smin, smax, dep, driver, qsing
    integer, intent(out) :: status           !! MBD_OK, MBD_LAPACK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! description
    real(wp), allocatable :: sv(:), u(:), v(:)
    real(wp) :: umax, best
    integer :: r, k, ierr
    character(len=MSG_LEN) :: rows, before
    msg = ''
    allocate (sv(min(m%neq, m%nq)), u(m%neq), v(m%nq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * 3 * real(max(m%neq, m%nq), wp), 'the singular report', &
                    'use a smaller model', status, msg)
      return
    end if
    if (w%banded) then
      call band_singular(m, w, q, t, sv(size(sv)), sv(1), u, v, status, msg)
      if (status /= MBD_OK) return
      rep%deficiency = 1
    else
      call dense_j(m, w, q, w%qz, t)
      ! columns to unit length, so lengths and angles weigh alike: J D, D = diag(1/|J_k|)
      do k = 1, m%nq
        umax = norm2(w%jac(:, k))
        if (umax > zero) w%jac(:, k) = w%jac(:, k) / umax
      end do
      call svd_null(w%jac, sv, u, v, status, msg)
      if (status /= MBD_OK) return
      rep%deficiency = max(1, count(sv < DEP_TOL * sv(1)))
    end if
    rep%qsing = q
    rep%t_fail = t
    rep%smax = sv(1); rep%smin = sv(size(sv))
    umax = maxval(abs(u))
    rep%dep = merge(1, 0, abs(u) > DEP_TOL * umax)
    rep%driver = 0; best = zero
    do r = 1, m%neq
      k = m%con_of_row(r)
      if (con_is_driver(m%kind(k)) .and. rep%dep(r) == 1 .and. abs(u(r)) > best) then
        best = abs(u(r)); rep%driver = k
      end if
    end do
    rows = ''
    do r = 1, m%neq
      if (rep%dep(r) == 1 .and. len_trim(rows) < MSG_LEN - 12) then
        before = rows                         ! (a write's output list may not hold its file)
        write (rows, '(a,1x,i0)') trim(before), r
      end if
    end do
    if (rep%driver > 0) then
      write (msg, '(a,es22.15,a,i0,a,a,a,es9.2)') 'singular configuration (dead centre) at t = ', &
        t, ': driver constraint ', rep%driver, ' can no longer be met; dependent rows:', &
        trim(rows), '; sigma_min/sigma_max = ', rep%smin / rep%smax
    else
      write (msg, '(a,es22.15,a,a,a,es9.2)') 'singular configuration at t = ', t, &
        ': the kinematic constraints became dependent; dependent rows:', trim(rows), &
        '; sigma_min/sigma_max = ', rep%smin / rep%smax
    end if
  end subroutine kin_singular_report

  !> Band-mode diagnosis of a (nearly) singular J at q without a dense J. A = J D, the columns
  !! of J at q scaled to unit length (D, from the blocks), factored in the band (an exactly
  !! zero pivot lifted to eps max |u_ii|). The smallest singular triple A v = s u, A^T u = s v
  !! by inverse iteration, v <- A^-1 u, u <- A^-T v (each normalized), s_min = ||A v||; the
  !! largest by power iteration on A^T A, s_max = ||A x||, the products from the blocks.
  !! w%cs is restored; the band holds the factors of A at q on return.
  subroutine band_singular(m, w, q, t, smin, smax, u, v, status, msg)
    type(model_t), intent(in) :: m           !! model (square J, band mode)
    type(kin_work_t), intent(inout) :: w     !! work arrays
    real(wp), intent(in) :: q(:)             !! configuration
    real(wp), intent(in) :: t                !! time
    real(wp), intent(out) :: smin, smax      !! extreme singular values of A (estimates)
    real(wp), intent(out) :: u(:), v(:)      !! left and right vectors of smin (neq, nq)
    integer, intent(out) :: status           !! MBD_OK, MBD_LAPACK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, parameter :: INV_IT = 8, POW_IT = 30
    real(wp), allocatable :: cs0(:), x(:), y(:)
    real(wp) :: nrm
    integer :: i, it, ierr, st
    msg = ''
    smin = zero; smax = zero; u = zero; v = zero
    allocate (cs0(m%nq), x(m%nq), y(m%nq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(3 * REAL_BYTES * m%nq, 'the singular report', 'use a smaller model', &
                    status, msg)
      return
    end if
    status = MBD_OK
    cs0 = w%cs
    call column_scale(m, w, q, t)
    call assemble_j(m, w, q, w%qz, t)
    call band_factor(w%band, st, msg, regularize=.true.)
    if (.not. w%band%factored) then
      w%cs = cs0
      status = MBD_LAPACK
      msg = 'the band factorization of J failed at the singular configuration: ' // trim(msg)
      return
    end if
    msg = ''
    ! largest: power iteration on A^T A with products from the blocks (assembled at q)
    do i = 1, m%nq
      x(i) = one + half * sin(real(i, wp))
    end do
    x = x / norm2(x)
    do it = 1, POW_IT
      y = w%cs * x
      call blocks_jv(m, w%asm, y, u)
      call blocks_jtv(m, w%asm, u, y)
      y = w%cs * y
      nrm = norm2(y)
      if (.not. (nrm > zero .and. nrm <= huge(one))) exit
      x = y / nrm
    end do
    y = w%cs * x
    call blocks_jv(m, w%asm, y, u)
    smax = norm2(u)
    ! smallest: inverse iteration with the band factors
    do i = 1, m%neq
      u(i) = one + half * cos(real(i, wp))
    end do
    u = u / norm2(u)
    do it = 1, INV_IT
      v = u
      call band_solve(w%band, v, st, msg)
      nrm = norm2(v)
      if (st /= MBD_OK .or. .not. (nrm > zero .and. nrm <= huge(one))) exit
      v = v / nrm
      u = v
      call band_solve(w%band, u, st, msg, transpose=.true.)
      nrm = norm2(u)
      if (st /= MBD_OK .or. .not. (nrm > zero .and. nrm <= huge(one))) exit
      u = u / nrm
    end do
    msg = ''
    y = w%cs * v
    call blocks_jv(m, w%asm, y, x)
    smin = norm2(x)
    w%cs = cs0
  end subroutine band_singular

  !> Kinematic analysis at nsteps + 1 uniform times from t0 to t1, the whole loop here.
  !! q0: estimates of the body coordinates (extras are estimated). Outputs k = 0, e, 2e, ...
  !! and nsteps (e = opts%every) are stored, in columns 1, 2, ... (kin_out_count of them).
  !! On a singular configuration the outputs up to it are filled (rep%ndone columns) and
  !! status is MBD_SINGULAR_CONFIG with rep describing the configuration.
  subroutine kin_run(m, q0, t0, t1, nsteps, opts, qout, qdout, qddout, rep, status, msg, &
                     sens, sq, sqd, sqdd, ssum, ctl)
    type(model_t), intent(in) :: m             !! model
    real(wp), intent(in) :: q0(:)              !! estimates (nq)
    real(wp), intent(in) :: t0, t1             !! time span
    integer, intent(in) :: nsteps              !! output intervals
    type(kin_opts_t), intent(in) :: opts       !! settings
    real(wp), intent(out) :: qout(:, :)        !! coordinates (nq, kin_out_count)
    !> velocities and accelerations (as qout; (nq, 0) with opts%positions: not returned)
    real(wp), intent(out) :: qdout(:, :), qddout(:, :)
    type(kin_report_t), intent(out) :: rep     !! what happened
    integer, intent(out) :: status             !! MBD_OK or the failure
    character(len=MSG_LEN), intent(out) :: msg !! explanation
    !> design parameters (mbd_sensitivity): with them, sq, sqd, sqdd (nq, np, outputs) get
    !! dq/dp, dq_dot/dp and dq_ddot/dp at every stored output (in model units, sens%ounit)
    type(sens_t), intent(inout), optional :: sens
    real(wp), intent(out), optional, contiguous :: sq(:, :, :), sqd(:, :, :), sqdd(:, :, :)
    !> with them, each output's sum of its sensitivities (kin_sens; (outputs))
    real(wp), intent(out), optional :: ssum(:)
    !> progress, shared with a caller in another thread: ctl(1) gets the outputs stored so
    !! far, ctl(2) /= 0 asks the run to stop (MBD_USER_ABORT, the outputs so far kept; seen at
    !! the next output time)
    integer, intent(inout), optional, volatile :: ctl(:)
    integer :: c0
    ! (absent contiguous arrays are not passed on: gfortran reads their descriptors, and
    ! UBSan flags the loads)
    if (present(sq)) then
      call kin_loop(m, q0, t0, t1, nsteps, opts, qout, qdout, qddout, rep, status, msg, &
                    sens, sq, sqd, sqdd, ssum, ctl)
    else
      call kin_loop(m, q0, t0, t1, nsteps, opts, qout, qdout, qddout, rep, status, msg, &
                    sens=sens, ssum=ssum, ctl=ctl)
    end if
    ! the outputs not computed are zero (set here, not before the loop: no pass over them)
    c0 = max(rep%ndone, 0)
    if (c0 < size(qout, 2)) then
      qout(:, c0 + 1:) = zero; qdout(:, c0 + 1:) = zero; qddout(:, c0 + 1:) = zero
      if (present(ssum)) ssum(c0 + 1:) = zero
    end if
  end subroutine kin_run

  !> kin_run's work (the outputs beyond rep%ndone are left as they are).
  subroutine kin_loop(m, q0, t0, t1, nsteps, opts, qout, qdout, qddout, rep, status, msg, &
                     sens, sq, sqd, sqdd, ssum, ctl)
    type(model_t), intent(in) :: m             !! model
    real(wp), intent(in) :: q0(:)              !! estimates (nq)
    real(wp), intent(in) :: t0, t1             !! time span
    integer, intent(in) :: nsteps              !! output intervals
    type(kin_opts_t), intent(in) :: opts       !! settings
    real(wp), intent(out) :: qout(:, :)        !! coordinates (nq, kin_out_count)
    !> velocities and accelerations (as qout; (nq, 0) with opts%positions: not returned)
    real(wp), intent(out) :: qdout(:, :), qddout(:, :)
    type(kin_report_t), intent(out) :: rep     !! what happened
    integer, intent(out) :: status             !! MBD_OK or the failure
    character(len=MSG_LEN), intent(out) :: msg !! explanation
    !> design parameters (mbd_sensitivity): with them, sq, sqd, sqdd (nq, np, outputs) get
    !! dq/dp, dq_dot/dp and dq_ddot/dp at every stored output (in model units, sens%ounit)
    type(sens_t), intent(inout), optional :: sens
    real(wp), intent(out), optional, contiguous :: sq(:, :, :), sqd(:, :, :), sqdd(:, :, :)
    !> with them, each output's sum of its sensitivities (kin_sens; (outputs))
    real(wp), intent(out), optional :: ssum(:)
    !> progress (see kin_run)
    integer, intent(inout), optional, volatile :: ctl(:)
    type(kin_work_t) :: w
    type(band_t) :: band
    logical, allocatable :: post(:)   ! outputs whose sensitivities are computed at the end
    real(wp), allocatable :: q(:), qd(:), qdd(:), qn(:), qp(:), qddn(:), qdn(:)
    !> divided differences d_j = a[t_k, ..., t_(k-j)] of the accelerations (PRED_ORDER, nq)
    real(wp), allocatable :: dd(:, :)
    real(wp) :: tau(0:PRED_ORDER)  ! tau_j = t_k - t_(k-j) (tau_0 = 0)
    ! the predictor's weights and the step and tau they were computed for
    real(wp) :: wt(PRED_ORDER), wt_h, wt_tau(0:PRED_ORDER)
    real(wp), allocatable :: qa(:), qda(:), qdda(:), qb(:), qdb(:), qddb(:)
    real(wp) :: t, h, hcur, hh, tt, target, lscale, ts, ta, d, corr, motion, tb, tend
    real(wp) :: pcur, phist(2), thist(2)   ! pivot ratios and times of the last accepted states
    integer :: nhist
    integer :: k, j, c, st, detprev, mobility, lev, nsub, nderiv, ierr
    ! (a report's detail, read while msg is written: an internal write's output list may
    ! not hold its own file)
    character(len=MSG_LEN) :: detail
    logical :: last, ok
    logical :: halt        ! ctl(2) asked the run to stop (store saw it)
    ! positions only: chord steps (fast), the positions' divided differences pd (as dd) at
    ! the times ptau back, the coordinates qf and pivot ratio pivf of the factorization in
    ! use, full steps since the chord steps were left
    logical :: fast
    real(wp), allocatable :: pd(:, :), qf(:)
    real(wp), allocatable :: wd(:)    ! the drift's weights: 1 / L for x and y, 1 otherwise
    real(wp) :: ptau(0:PRED_ORDER), pivf
    integer :: npd, nfull, nreq, nchord
    ! models of revolutes and absolute drivers (lin): g_b = J(qf)^-1 u_b (nq, nb), u_b the
    ! change of J's column theta_b with theta_b at qf (lin_prepare), |g_b| (max norm), work
    logical :: lin
    real(wp), allocatable :: gb(:, :), gn(:), ub(:), xl(:)
    ! the positions predictor's order (pmax), the first correction's size, the number of
    ! corrections of the last chord step and its last c (lin_correction) (dfirst, ncorr,
    ! clast)
    integer :: pmax, ncorr
    real(wp) :: dfirst, clast
    real(wp) :: gk(LIN_MAXB, LIN_MAXB)      ! gk(a, b) = g_b(theta_a)

    status = MBD_OK; msg = ''
    if (present(sens)) then
      allocate (post(size(qout, 2)), stat=ierr)
      if (ierr /= 0) then
        call mem_fail(4.0_wp * size(qout, 2), 'the sensitivity bookkeeping', &
                      'use fewer outputs (every)', status, msg)
        return
      end if
      post = .false.
    end if
    allocate (rep%qsing(m%nq), rep%dep(m%neq), rep%redundant(m%neq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * (real(m%nq, wp) + m%neq), 'the kinematic report', &
                    'use a smaller model', status, msg)
      return
    end if
    rep%qsing = zero; rep%dep = 0; rep%redundant = 0
    if (nsteps < 0 .or. .not. (abs(t1 - t0) <= huge(one)) .or. .not. (opts%tol > zero)) then
      status = MBD_BAD_SETTING; msg = 'steps must be >= 0, times finite, tolerance > 0'; return
    end if
    if (nsteps > 0 .and. .not. (t1 > t0)) then
      status = MBD_BAD_SETTING; msg = 't_end must be greater than the start time'; return
    end if
    if (opts%positions .and. present(sens)) then
      status = MBD_BAD_SETTING; msg = 'sensitivities need the velocities and accelerations: '// &
        'do not ask for positions only'
      return
    end if
    if (size(qdout, 2) /= size(qout, 2) .and. .not. (opts%positions .and. size(qdout, 2) == 0) &
        .or. size(qddout, 2) /= size(qdout, 2)) then
      status = MBD_BAD_SETTING; msg = 'the derivatives'' output arrays do not match the outputs'
      return
    end if
    if (opts%every < 1 .or. size(qout, 2) /= kin_out_count(nsteps, opts%every)) then
      status = MBD_BAD_SETTING; msg = 'every must be >= 1 (and the output arrays sized for it)'
      return
    end if
    ! the linear solver: band LU for large square J with a narrow band (after RCM)
    rep%solver = SOLVER_DENSE
    if (opts%solver == SOLVER_BANDED .and. m%neq /= m%nq) then
      status = MBD_BAD_SETTING
      msg = 'the banded solver needs as many equations as coordinates (no redundant '// &
            'constraints); use the dense solver'
      return
    end if
    if (opts%solver /= SOLVER_DENSE .and. m%neq == m%nq .and. &
        (opts%solver == SOLVER_BANDED .or. m%nq >= BAND_MIN_N)) then
      call kin_band_plan(m, band, st, msg)
      if (st == MBD_OK) then
        if (opts%solver == SOLVER_BANDED .or. &
            BAND_RATIO * (band%kl + band%ku + 1) <= m%nq) rep%solver = SOLVER_BANDED
        rep%kl = band%kl; rep%ku = band%ku
      else if (opts%solver == SOLVER_BANDED .or. st == MBD_NO_MEMORY) then
        status = merge(MBD_NO_MEMORY, MBD_SINGULAR, st == MBD_NO_MEMORY); return
      end if
      msg = ''
    end if
    if (rep%solver == SOLVER_BANDED) then
      call kin_work_init(m, w, status, msg, band)
    else
      call kin_work_init(m, w, status, msg)
    end if
    if (status /= MBD_OK) return
    lscale = m%lscale
    w%tol = opts%tol * lscale
    allocate (q(m%nq), qd(m%nq), qdd(m%nq), qn(m%nq), qp(m%nq), stat=ierr)
    if (ierr == 0) allocate (dd(PRED_ORDER, m%nq), qddn(m%nq), qdn(m%nq), stat=ierr)
    if (ierr == 0) allocate (qa(m%nq), qda(m%nq), qdda(m%nq), qb(m%nq), stat=ierr)
    if (ierr == 0) allocate (qdb(m%nq), qddb(m%nq), stat=ierr)
    if (ierr == 0 .and. opts%positions) allocate (pd(PRED_ORDER, m%nq), qf(m%nq), wd(m%nq), &
                                                  stat=ierr)
    if (ierr == 0 .and. opts%positions) then
      wd = one
      do j = 1, m%nb
        wd(3 * j - 2:3 * j - 1) = one / m%lscale
      end do
    end if
    lin = opts%positions .and. .not. w%banded .and. size(w%asm%gen) == 0 .and. &
          m%nb <= LIN_MAXB .and. m%neq == m%nq
    if (ierr == 0 .and. lin) allocate (gb(m%nq, LIN_MAXB), gn(m%nb), ub(m%neq), xl(m%nq), &
                                       stat=ierr)
    if (ierr == 0 .and. lin) gb = zero
    if (ierr /= 0) then
      call mem_fail(23 * REAL_BYTES * m%nq, 'the kinematic state vectors', &
                    'use a smaller model', status, msg)
      return
    end if
    q = q0
    call kin_assemble(m, w, q, t0, opts, rep, status, msg)
    if (status /= MBD_OK) then
      call count_work(); return
    end if
    ! column scale from J at the assembled configuration: D = diag(1/|J_k|)
    call column_scale(m, w, q, t0)
    ! square: a regular LU proves full rank; otherwise find the rank and the redundant rows
    w%lsq = .false.
    st = MBD_SINGULAR
    if (m%neq == m%nq) call kin_newton(m, w, q, t0, opts%maxit, st)
    if (st == MBD_OK .and. w%pivratio >= NEAR_SING) then
      rep%rank = m%nq
    else if (w%banded) then
      ! no dense rank analysis in band mode: the singular report estimates the deficiency
      call kin_singular_report(m, w, q, t0, rep, st, msg)
      if (st /= MBD_OK) then
        status = st; call count_work(); return
      end if
      rep%rank = m%nq - rep%deficiency
      status = MBD_SINGULAR
      detail = msg
      write (msg, '(a,es9.2,a,a)') 'the assembled configuration is singular (banded solver: '// &
        'sigma_min/sigma_max of the column-scaled J about ', rep%smin / rep%smax, '): ', &
        trim(detail)
      call count_work(); return
    else
      call kin_rank(m, w, q, t0, rep%rank, mobility, rep%redundant, status, msg)
      if (status /= MBD_OK) then
        call count_work(); return
      end if
      if (rep%rank < m%nq .and. m%neq > m%nq) then
        status = MBD_BAD_COUNT
        write (msg, '(a,i0,a,i0,a,i0,a)') 'the model is not kinematically determined: J has '// &
          'rank ', rep%rank, ' for ', m%nq, ' coordinates (', m%nq - rep%rank, &
          ' degrees of freedom left)'
        call count_work(); return
      end if
      w%lsq = m%neq > m%nq
      if (w%lsq) call kin_newton(m, w, q, t0, opts%maxit, st)
      if (st /= MBD_OK .or. w%pivratio < NEAR_SING) then
        call kin_singular_report(m, w, q, t0, rep, k, msg)
        if (k == MBD_NO_MEMORY) then
          status = k; call count_work(); return
        end if
        status = MBD_SINGULAR
        detail = msg
        write (msg, '(a,i0,a,i0,a,a)') 'the assembled configuration is singular (J has rank ', &
          rep%rank, ' for ', m%nq, ' coordinates): ', trim(detail)
        call count_work(); return
      end if
    end if
    call kin_vel_acc(m, w, q, t0, qd, qdd, st, lev)
    if (st /= MBD_OK) then
      call inconsistent(t0, lev); return
    end if
    if (.not. (all(ieee_is_finite(qd)) .and. all(ieee_is_finite(qdd)))) then
      status = MBD_NO_CONVERGENCE; rep%t_fail = t0
      msg = 'velocities or accelerations overflow at the start: a driver is far too fast'
      call count_work(); return
    end if
    if (size(qdout, 2) == 0) then
      call copy1(size(q), q, qout(:, 1))
    else
      call copy3(size(q), q, qd, qdd, qout(:, 1), qdout(:, 1), qddout(:, 1))
    end if
    fast = .false.; nfull = FAST_REENTER; nreq = FAST_REENTER; halt = .false.
    pmax = PRED_ORDER; ncorr = 0; dfirst = zero; clast = zero
    if (opts%positions) call reenter(w%pivratio)
    if (present(sens)) call kin_sens(m, w, sens, q, qd, qdd, t0, sq(:, :, 1), sqd(:, :, 1), &
                                     sqdd(:, :, 1), ssum(1))
    rep%ndone = 1
    detprev = w%detsign
    call forget_derivatives()
    t = t0
    if (nsteps == 0) then
      call count_work(); return
    end if
    h = (t1 - t0) / nsteps
    hcur = h
    k = 1
    nsub = 0
    tb = model_next_break(m, t, .false.)   ! (the drivers')
    do while (k <= nsteps)
      nsub = nsub + 1
      if (nsub > MAX_SUBSTEPS) then
        status = MBD_NO_CONVERGENCE
        rep%t_fail = t
        write (msg, '(a,i0,a,es12.5,a)') 'the motion needs more than ', MAX_SUBSTEPS, &
          ' internal steps between output times after t = ', t, &
          ': give more output steps (or a slower driver)'
        call count_work(); return
      end if
      target = out_time(k)
      ! land exactly on the output time, or on a driver's breakpoint before it (no sliver
      ! step from rounding of t)
      tend = min(target, tb)
      last = hcur >= (tend - t) * (one - 1.0e-9_wp)
      hh = merge(tend - t, hcur, last)
      tt = merge(tend, t + hh, last)
      last = last .and. tb >= target
      if (fast) then
        call fast_step(hh, ok)
        if (ok) then
          call accept_fast()
          if (last) call store(k)
          if (halt) return
          if (t >= tb) call past_break()
          hcur = min(2 * hh, h)
          cycle
        end if
        call leave_fast()
      end if
      call predict(hh)
      call kin_newton(m, w, qn, tt, opts%maxit, st)
      call max_diffs(size(q), qn, qp, q, corr, motion)
      ok = st == MBD_OK .and. same_branch(corr, motion, JUMP_RATIO, w%tol) .and. &
           w%pivratio >= NEAR_SING
      if (ok .and. .not. w%lsq) ok = w%detsign == detprev
      if (ok .and. w%pivratio < ANCHOR_PIV) call polish(tt)
      if (ok) then
        call kin_vel_acc(m, w, qn, tt, qdn, qddn, st, lev)
        if (st /= MBD_OK) then
          call inconsistent(tt, lev); return
        end if
        ok = smooth_velocity(hh)
      end if
      if (ok) then
        pcur = w%pivratio
        call accept()
        if (last) call store(k)
        if (halt) return
        if (t >= tb) call past_break()
        call quiet_passage()
        if (opts%positions) call reenter(pcur)
        hcur = min(2 * hh, h)
        cycle
      end if
      if (st == MBD_INCONSISTENT) then
        call inconsistent(tt, 0); return
      end if
      rep%rejected = rep%rejected + 1
      call forget_derivatives()
      hcur = half * hh
      if (hcur >= opts%tmin * max(one, abs(t))) cycle
      ! the configuration at t is singular (to tmin): pass through it or stop
      call kin_singular_report(m, w, q, t, rep, st, msg)
      if (st /= MBD_OK) then
        status = merge(MBD_NO_MEMORY, MBD_LAPACK, st == MBD_NO_MEMORY)
        call count_work(); return
      end if
      if (rep%smin > SING_RATIO * rep%smax) then
        ! J is regular here: not a dead centre but a failed step
        status = MBD_NO_CONVERGENCE
        rep%dep = 0; rep%driver = 0; rep%deficiency = 0
        write (msg, '(a,es22.15,a,es9.2,a)') 'no solution could be followed past t = ', t, &
          ' although J is regular there (sigma_min/sigma_max = ', rep%smin / rep%smax, &
          '): a driver may jump or grow too fast for the step'
        call count_work(); return
      end if
      ! a bifurcation lets the motion continue: regular anchors d either side of ts, far
      ! enough out that J is well conditioned there (pivot ratio >= ANCHOR_PIV)
      ts = t
      d = h / 64
      do
        if (.not. anchor(ts + d)) then
          status = MBD_SINGULAR_CONFIG; call count_work(); return   ! no motion beyond
        end if
        if (w%pivratio >= ANCHOR_PIV .or. d >= 64 * h) exit
        d = 2 * d
      end do
      qb = qn; qdb = qdn; qddb = qddn
      detprev = w%detsign
      ta = ts - d
      if (.not. anchor(ta)) then
        status = MBD_SINGULAR_CONFIG; call count_work(); return
      end if
      qa = qn; qda = qdn; qdda = qddn
      qn = qb; qdn = qdb; qddn = qddb
      rep%npass = rep%npass + 1
      if (rep%npass <= MAXPASS) rep%tpass(rep%npass) = ts
      rep%dep = 0; rep%driver = 0; rep%deficiency = 0; msg = ''
      ! outputs inside (ta, ts + d]: interpolate; earlier ones there are replaced
      do j = 0, nsteps
        if (out_time(j) > ta .and. out_time(j) <= ts + d) then
          c = column(j)
          if (c > 0) then
            call interp_out(ta, ts + d, out_time(j), c)
            rep%ndone = max(rep%ndone, c)
            if (present(sens)) post(c) = .true.
          end if
          if (j >= k) k = j + 1
        end if
      end do
      tt = ts + d
      call forget_derivatives()
      call accept()
      call forget_derivatives()
      hcur = h
    end do
    call count_work()

  contains

    !> Output column of output kk (0: not stored).
    integer function column(kk)
      integer, intent(in) :: kk
      column = 0
      if (mod(kk, opts%every) == 0) column = kk / opts%every + 1
      if (kk == nsteps) column = size(qout, 2)
    end function column

    !> Output time k (exact at both ends).
    real(wp) function out_time(kk)
      integer, intent(in) :: kk
      out_time = t0 + (t1 - t0) * (real(kk, wp) / nsteps)
      if (kk == nsteps) out_time = t1
    end function out_time

    !> The predictor qp at t + hs: the acceleration extrapolated by its Newton polynomial
    !! through the last PRED_ORDER + 1 accelerations, a(s) = a + sum_j d_j w_j(s) with
    !! w_j(s) = s (s + tau_1) ... (s + tau_(j-1)), integrated twice:
    !! qp = q + hs q_dot + hs**2/2 a + sum_j W_j d_j, W_j = int_0^hs (hs - s) w_j(s) ds
    !! = sum_n c_jn hs**(n+2) / ((n + 1)(n + 2)) (c_jn: the coefficients of w_j). Error
    !! O(hs**(PRED_ORDER + 3)) once the divided differences are known.
    subroutine predict(hs)
      real(wp), intent(in) :: hs
      !> 1 / ((n + 1)(n + 2)), n = 0, 1, ...
      real(wp), parameter :: RDEN(0:7) = one / [2, 6, 12, 20, 30, 42, 56, 72]
      real(wp) :: c(0:PRED_ORDER), hp(0:PRED_ORDER), x, hpow
      integer :: jj, n
      ! the weights depend on hs and the last steps only: kept while those stay (to 1e-10;
      ! any predictor is a start for Newton, whose tolerance decides)
      if (abs(hs - wt_h) <= 1.0e-10_wp * hs .and. &
          all(abs(tau - wt_tau) <= 1.0e-10_wp * hs)) then
        call pred_sum(size(q), hs, half * hs * hs, wt, q, qd, qdd, dd, qp, qn)
        return
      end if
      wt_h = hs; wt_tau = tau
      hpow = hs * hs
      do n = 0, PRED_ORDER                      ! hs**(n+2) / ((n + 1)(n + 2))
        hp(n) = hpow * RDEN(n); hpow = hpow * hs
      end do
      c = zero; c(0) = one                      ! w_0 = 1
      do jj = 1, PRED_ORDER                     ! w_j = w_(j-1) (s + tau_(j-1))
        do n = jj, 1, -1
          c(n) = c(n - 1) + tau(jj - 1) * c(n)
        end do
        c(0) = tau(jj - 1) * c(0)
        x = zero
        do n = 0, jj
          x = x + c(n) * hp(n)
        end do
        wt(jj) = x
      end do
      call pred_sum(size(q), hs, hp(0), wt, q, qd, qdd, dd, qp, qn)
    end subroutine predict

    !> The new velocity continues the old one: at a switch to another branch through a
    !! singular point the velocity jumps by O(|q_dot|), in smooth motion it differs from its
    !! Taylor prediction by O(h**3).
    logical function smooth_velocity(hs)
      real(wp), intent(in) :: hs
      real(wp) :: jump, dv, vmax, fin
      call velocity_jump(size(q), hs, qd, qdd, dd, qdn, qddn, jump, dv, vmax, fin)
      smooth_velocity = jump <= VJUMP_RATIO * (vmax + dv) + 1.0e3_wp * w%tol .and. &
                        fin == zero
    end function smooth_velocity

    !> One more Newton correction at tp (when J is poorly conditioned).
    subroutine polish(tp)
      real(wp), intent(in) :: tp
      integer :: st2
      call solve_newton(w)
      qn = qn + w%dq
      call assemble_j(m, w, qn, w%qz, tp)
      call factor(w, st2)
      if (st2 /= MBD_OK) w%pivratio = zero
    end subroutine polish

    !> A regular state (qn, qdn, qddn) at time ta2 on the predicted branch from (t, q).
    !! First-order predictor: next to the singular point q_dot is still accurate (error
    !! ~ cond eps) but q_ddot is not (~ cond**2 eps).
    logical function anchor(ta2)
      real(wp), intent(in) :: ta2
      real(wp) :: hj
      integer :: st2
      hj = ta2 - t
      qp = q + hj * qd
      qn = qp
      call kin_newton(m, w, qn, ta2, opts%maxit, st2)
      call max_diffs(size(q), qn, qp, q, corr, motion)
      anchor = st2 == MBD_OK .and. same_branch(corr, motion, 0.25_wp, w%tol)
      if (.not. anchor) return
      ! one more correction: errors grow like cond, cond**2, cond**3 in q, q_dot, q_ddot
      call polish(ta2)
      anchor = w%pivratio > zero
      if (anchor) call kin_vel_acc(m, w, qn, ta2, qdn, qddn, st2)
      anchor = anchor .and. st2 == MBD_OK
    end function anchor

    !> The outputs stored so far to ctl(1); when ctl(2) asks the run to stop, halt, with
    !! MBD_USER_ABORT (the outputs so far kept).
    subroutine report_progress()
      ctl(1) = rep%ndone
      if (ctl(2) == 0) return
      halt = .true.
      status = MBD_USER_ABORT; rep%t_fail = tt
      write (msg, '(a,es12.5,a)') 'stopped on request at t = ', tt, ' (the outputs so far are kept)'
      call count_work()
    end subroutine report_progress

    !> Positions only: chord steps again from the accepted state (q, q_dot, q_ddot) once
    !! nreq full steps in a row were well conditioned (square J). The positions'
    !! Newton polynomial starts as the Taylor polynomial q + q_dot s + q_ddot s**2 / 2 (nodes
    !! t, t, t), and the first chord step factors J anew (the factors in w may be another
    !! time's, from the passage search or an output's refinement).
    subroutine reenter(piv)
      real(wp), intent(in) :: piv     ! pivot ratio of the accepted state's factorization
      nfull = nfull + 1
      if (piv < FAST_PIV) nfull = 0
      if (w%lsq .or. nfull < nreq) return
      fast = .true.; nchord = 0
      qf = q
      pd = zero; pd(1, :) = qd; pd(2, :) = half * qdd
      ptau = zero; npd = 2; pmax = PRED_ORDER
      pivf = -one       ! (a factorization first)
    end subroutine reenter

    !> Positions only: the full steps from the accepted q, whose q_dot and q_ddot the chord
    !! steps did not compute: Newton from q (converged: one factorization), J q_dot = nu,
    !! J q_ddot = gamma, and the accelerations' history anew. Left before a chord step was
    !! taken, the full step's state at q still holds.
    subroutine leave_fast()
      integer :: st2
      fast = .false.; nfull = 0
      nreq = merge(min(2 * nreq, FAST_REENTER_MAX), FAST_REENTER, nchord == 0)
      if (nchord == 0) return
      qn = q
      call kin_newton(m, w, qn, t, opts%maxit, st2)
      if (st2 == MBD_OK) call kin_vel_acc(m, w, qn, t, qd, qdd, st2)
      if (st2 == MBD_OK) then
        detprev = w%detsign
      else
        qd = zero; qdd = zero    ! (the full steps start from q alone)
      end if
      call forget_derivatives()
    end subroutine leave_fast

    !> Positions only: a step to tt without q_dot and q_ddot. The positions' Newton polynomial
    !! predicts, chord corrections J(qf) dq = -Phi(q, tt) correct (simplified Newton: each
    !! contracts the error by about |J(qf)^-1 (J(q) - J(qf))|). J is factored anew at the
    !! prediction when q has moved more than FAST_DRIFT pivf from qf or the chord does not
    !! converge. ok: a correction below resolution (as kin_newton's test of a start), on the
    !! predicted branch, with det J of unchanged sign and a pivot ratio >= FAST_PIV at any
    !! new factorization.
    subroutine fast_step(hs, ok)
      real(wp), intent(in) :: hs
      logical, intent(out) :: ok
      logical :: fresh
      integer :: st2
      real(wp) :: motion, corr, mtop, drift
      ok = .false.
      call pos_predict(size(q), pmax, hs, ptau, q, pd, qf, wd, qp, qn, motion, mtop, drift)
      fresh = .not. (drift <= FAST_DRIFT * pivf)
      if (.not. fresh) then
        call chord(.true., ok, corr)
        if (.not. ok) qn = qp
        fresh = .not. ok
      end if
      if (fresh) then
        call assemble_j(m, w, qn, w%qz, tt)
        call factor(w, st2)
        if (st2 /= MBD_OK .or. w%lsq) return
        if (w%pivratio < FAST_PIV .or. w%detsign /= detprev) return
        qf = qn; pivf = w%pivratio
        if (lin) call lin_prepare()
        call chord(.false., ok, corr)
        if (.not. ok) return
      end if
      ok = same_branch(corr, motion, JUMP_RATIO, w%tol)
      if (ok .and. lin) call adapt_order(mtop)
    end subroutine fast_step

    !> Positions only (lin): the predictor's order for the next step from this one's chord
    !! step (ncorr, dfirst) and its prediction's last term (mtop).
    subroutine adapt_order(mtop)
      real(wp), intent(in) :: mtop
      if (ncorr > 1) then
        if (clast <= LIN_CMAX .and. pmax < PRED_ORDER) pmax = pmax + 1
      else if (npd >= pmax .and. pmax > POS_ORDER_MIN .and. mtop <= dfirst) then
        pmax = pmax - 1; npd = min(npd, pmax)
      end if
    end subroutine adapt_order

    !> Chord corrections of qn at tt with the factors in w, from Phi(qn) (evaluated when
    !! need, else assemble_j's) until one is below resolution with ||Phi|| <= tol (conv);
    !! false after CHORD_MAXIT, on a correction larger than CHORD_RATE times the one before,
    !! or on a non-finite Phi. corr: the sum of the corrections' max norms (>= max |qn - qp|).
    subroutine chord(need, conv, corr)
      logical, intent(in) :: need
      logical, intent(out) :: conv
      real(wp), intent(out) :: corr
      real(wp) :: dmax, dprev, ref, xmax
      logical :: fresh, kept, sound
      integer :: it
      conv = .false.; fresh = .true.; dprev = huge(one); corr = zero; clast = zero
      kept = .false.          ! assemble_phi's drivers' f(tt) are known
      do it = 1, CHORD_MAXIT
        if (need .or. it > 1) then
          call assemble_phi(m, qn, tt, fresh .or. .not. kept, w%phi, w%asm)
          kept = .true.
        end if
        call solve(w, w%phi, w%dq)                   ! J(qf)^-1 Phi: the correction's negative
        call chord_update(size(q), m%nb, lscale, w%tol, w%phi, w%dq, qn, conv, dmax, sound, &
                          ref)
        w%newton_its = w%newton_its + 1
        corr = corr + dmax
        ncorr = it
        if (it == 1) dfirst = dmax
        if (conv) return
        if (lin .and. sound) then
          call lin_correction(size(q), m%nb, qn, qf, w%dq, gb, gk, gn, dmax, ref, xl, conv, &
                              xmax, clast)
          if (conv) then
            corr = corr + xmax; return
          end if
        end if
        if (.not. (dmax <= CHORD_RATE * dprev)) return      ! (NaN too)
        fresh = dmax > TURN_MAX
        if (.not. fresh) call asm_turn(m, w%asm, w%dq)
        dprev = dmax
      end do
    end subroutine chord

    !> g_b = J(qf)^-1 u_b for every body b (the factors of J(qf) in w), u_b = dJ/dtheta_b's
    !! column theta_b at qf (revolute_curvature_all), and their max norms.
    subroutine lin_prepare()
      integer :: a, b
      do b = 1, m%nb
        ub = zero
        call revolute_curvature_all(size(w%asm%rtab, 2), w%asm%rtab, m%p, b, cos(qf(3 * b)), &
                                    sin(qf(3 * b)), ub)
        call solve(w, ub, gb(:, b))
        gn(b) = maxval(abs(gb(:, b)))
      end do
      gk = zero
      do b = 1, m%nb
        do a = 1, m%nb
          gk(a, b) = gb(3 * a, b)
        end do
      end do
    end subroutine lin_prepare

    !> Take the chord step to (tt, qn): the positions' divided differences with the new q
    !! (as accept does with the accelerations).
    subroutine accept_fast()
      real(wp) :: rden(PRED_ORDER)
      call new_node(tt - t, npd, pmax, ptau, rden)
      call newton_update(size(q), pmax, rden, qn, q, pd)
      npd = min(npd + 1, pmax)
      nchord = nchord + 1
      t = tt
    end subroutine accept_fast

    !> On a driver's breakpoint (a step's t0 or t1): the accelerations may jump here, so the
    !! predictor's history before it is dropped (q_ddot at t is the value after the instant,
    !! the driver functions being right-continuous); positions-only leaves its chord steps
    !! for a full step from here.
    subroutine past_break()
      if (fast) then
        call leave_fast()
      else
        call forget_derivatives()
      end if
      tb = model_next_break(m, t, .false.)   ! (the drivers')
    end subroutine past_break

    subroutine forget_derivatives()
      dd = zero; tau = zero; nderiv = 0; wt_h = -one
      nhist = 0
    end subroutine forget_derivatives

    !> A passage that leaves det J's sign unchanged (an even number of singular values
    !! vanishing together, as in the N-four-bar with even N) rejects no step. It shows as a
    !! local minimum of the pivot ratio below COND_CHECK at the last-but-one accepted state:
    !! golden-section search for the minimum over the bracket of the accepted states either
    !! side, each point a converged configuration (anchor); a minimum below NEAR_SING is a
    !! singular configuration passed through, and is recorded.
    subroutine quiet_passage()
      real(wp), parameter :: GR = 0.6180339887498949_wp   ! (sqrt(5) - 1) / 2
      real(wp) :: a, b, x1, x2, f1, f2
      if (nhist == 2 .and. phist(2) < COND_CHECK .and. phist(2) <= phist(1) .and. &
          phist(2) < pcur) then
        a = thist(1); b = t
        x1 = b - GR * (b - a); x2 = a + GR * (b - a)
        f1 = pivot_at(x1); f2 = pivot_at(x2)
        do while (b - a > opts%tmin * max(one, abs(t)))
          if (f1 <= f2) then
            b = x2; x2 = x1; f2 = f1
            x1 = b - GR * (b - a); f1 = pivot_at(x1)
          else
            a = x1; x1 = x2; f1 = f2
            x2 = a + GR * (b - a); f2 = pivot_at(x2)
          end if
        end do
        if (min(f1, f2) < NEAR_SING) then
          rep%npass = rep%npass + 1
          if (rep%npass <= MAXPASS) rep%tpass(rep%npass) = half * (a + b)
        end if
        nhist = 0
      end if
      if (nhist == 2) then
        phist(1) = phist(2); thist(1) = thist(2)
      end if
      nhist = min(nhist + 1, 2)
      phist(nhist) = pcur; thist(nhist) = t
    end subroutine quiet_passage

    !> Pivot ratio of J at the configuration at time tx on the current branch (huge where
    !! no configuration is found there: a failed solve is no evidence of a singular one).
    real(wp) function pivot_at(tx)
      real(wp), intent(in) :: tx
      pivot_at = huge(one)
      if (anchor(tx)) pivot_at = w%pivratio
    end function pivot_at

    !> Take the step to (tt, qn, qdn, qddn): the divided differences of the accelerations with
    !! the new one, d_j <- (d_(j-1)new - d_(j-1)old) / (t_(k+1) - t_(k+1-j)) (d_0 = q_ddot),
    !! each once j + 1 accelerations are known; tau_j <- hs + tau_(j-1).
    subroutine accept()
      real(wp) :: rden(PRED_ORDER)
      call new_node(tt - t, nderiv, PRED_ORDER, tau, rden)
      call accept_state(size(q), rden, qn, qdn, qddn, q, qd, qdd, dd)
      nderiv = nderiv + 1
      t = tt
    end subroutine accept

    !> Output time kk reached with the accepted state: its column (if kept) gets it, the
    !! progress goes to ctl (a stop asked there halts the run), kk moves on.
    subroutine store(kk)
      integer, intent(inout) :: kk
      integer :: cc
      nsub = 0
      cc = column(kk)
      if (cc > 0 .and. (fast .or. size(qdout, 2) == 0)) then
        ! q alone: a chord step (no q_dot, q_ddot, J(q) unfactored), or no columns for them
        call copy1(size(q), q, qout(:, cc))
        rep%ndone = cc
      else if (cc > 0) then
        call copy3(size(q), q, qd, qdd, qout(:, cc), qdout(:, cc), qddout(:, cc))
        if (present(sens)) call kin_sens(m, w, sens, q, qd, qdd, t, sq(:, :, cc), &
                                         sqd(:, :, cc), sqdd(:, :, cc), ssum(cc))
        if (w%pivratio < ANCHOR_PIV) call refine_output(cc)
        rep%ndone = cc
      end if
      kk = kk + 1
      if (present(ctl)) call report_progress()
    end subroutine store

    !> Output column cc at time tx by quintic Hermite interpolation between the anchors
    !! (ta; qa, qda, qdda) and (tb; qn, qdn, qddn) (its q alone when the derivatives'
    !! outputs have no columns; qdb, qddb are free then).
    subroutine interp_out(ta2, tb2, tx, cc)
      real(wp), intent(in) :: ta2, tb2, tx
      integer, intent(in) :: cc
      if (size(qdout, 2) == 0) then
        call hermite5(ta2, qa, qda, qdda, tb2, qn, qdn, qddn, tx, qout(:, cc), qdb, qddb)
      else
        call hermite5(ta2, qa, qda, qdda, tb2, qn, qdn, qddn, tx, qout(:, cc), qdout(:, cc), &
                      qddout(:, cc))
      end if
    end subroutine interp_out

    !> Output column cc sits where J is poorly conditioned (near a singular point): its q_ddot
    !! (error ~ cond**3 tol) is replaced by quintic Hermite interpolation between regular anchors at
    !! t -+ d, d doubled from h/64 until J is well conditioned at both. The stepping state
    !! is left as it is. If no regular anchor exists on one side (a dead centre), the direct
    !! values stay.
    subroutine refine_output(cc)
      integer, intent(in) :: cc
      real(wp) :: dd
      dd = h / 64
      do
        if (.not. anchor(t - dd)) return
        if (w%pivratio >= ANCHOR_PIV) then
          qa = qn; qda = qdn; qdda = qddn
          if (.not. anchor(t + dd)) return
          if (w%pivratio >= ANCHOR_PIV) exit
        end if
        if (dd >= 64 * h) return
        dd = 2 * dd
      end do
      call interp_out(t - dd, t + dd, t, cc)
      if (present(sens)) post(cc) = .true.
    end subroutine refine_output

    !> Redundant constraints disagree at position (0), velocity (1) or acceleration (2)
    !! level; w%phi holds the residual of that level.
    subroutine inconsistent(tf, lv)
      real(wp), intent(in) :: tf
      integer, intent(in) :: lv
      character(len=*), parameter :: what(0:2) = [character(len=12) :: 'position', &
                                                   'velocity', 'acceleration']
      status = MBD_INCONSISTENT
      rep%t_fail = tf; rep%qsing = qn
      rep%resid = maxval(abs(w%phi))
      rep%deficiency = lv
      rep%dep = merge(1, 0, abs(w%phi) > DEP_TOL * rep%resid)
      write (msg, '(a,a,a,es22.15)') 'redundant constraints contradict each other at ', &
        trim(what(lv)), ' level at t = ', tf
      call count_work()
    end subroutine inconsistent

    subroutine count_work()
      integer :: cc, st3
      rep%newton_its = w%newton_its; rep%lu_count = w%lu_count
      if (.not. allocated(post)) return
      ! interpolated outputs: sensitivities from a factorization at the output itself
      do cc = 1, min(rep%ndone, size(post))
        if (.not. post(cc)) cycle
        tt = t0 + (t1 - t0) * (real(min((cc - 1) * opts%every, nsteps), wp) / max(nsteps, 1))
        if (cc == size(qout, 2)) tt = t1
        call assemble_j(m, w, qout(:, cc), w%qz, tt)
        call factor(w, st3)
        if (st3 == MBD_OK) then
          call kin_sens(m, w, sens, qout(:, cc), qdout(:, cc), qddout(:, cc), tt, sq(:, :, cc), &
                        sqd(:, :, cc), sqdd(:, :, cc), ssum(cc))
        else                                  ! (every output is written: the arrays come
          sq(:, :, cc) = zero; sqd(:, :, cc) = zero; sqdd(:, :, cc) = zero   ! unset)
          ssum(cc) = zero
        end if
      end do
      post = .false.
    end subroutine count_work

  end subroutine kin_loop

  !> Sensitivities at a converged state (q, q_dot, q_ddot) whose J factors are in w:
  !! J s = -Phi_p, J s_dot = nu_p - J_p q_dot - Hv s, J s_ddot = gamma_p - J_p q_ddot - Ha s
  !! - 2 Hv s_dot (mbd_sensitivity), three solves with the same factors per parameter;
  !! returned in model units (s%ounit: the core works in the model's length scale).
  subroutine kin_sens(m, w, s, q, qd, qdd, t, sq, sqd, sqdd, ssum)
    type(model_t), intent(in) :: m           !! model
    type(kin_work_t), intent(inout) :: w     !! work arrays with the factors of J(q)
    type(sens_t), intent(inout) :: s         !! parameters and blocks
    real(wp), intent(in), contiguous :: q(:), qd(:), qdd(:)  !! state and accelerations
    real(wp), intent(in) :: t                !! time
    !> (nq, np); contiguous down from the f2py layer's arrays: their sections reach the
    !! solves' explicit shapes with no run-time contiguity checks (~390 instructions a step)
    real(wp), intent(out), contiguous :: sq(:, :), sqd(:, :), sqdd(:, :)
    !> the sum of all three's entries: finite exactly when every entry is, barring an
    !! overflow of the sum itself (the caller's check of the outputs, taken here for free)
    real(wp), intent(out) :: ssum
    call sens_states(m, s, w%asm%cb, w%asm%sb, qd, qdd)   ! (cos, sin of the assembly at q)
    call sens_hessian(m, s, q, qd, qdd, t, states=.false., push=.false.)
    call sens_params(m, s, q, qd, qdd, t, states=.false.)
    ssum = zero
    if (w%spfact .and. size(s%rhs, 1) == 4 .and. s%nnz == 2 * size(s%rsb)) then
      ! four parameters, second derivatives from revolutes alone: each solve forms its
      ! right-hand side's rows as it goes (nu_p - Hv s, gamma_p - Ha s - 2 Hv s_dot)
      call splu_solve_rows(w%sp, s%mphip, sq, w%cs, s%ounit, ssum, s%st)
      call splu_solve_rows_h(w%sp, s%vp, s%rwp, s%rwe, s%rwc, s%rsv, s%rsv, .false., s%st, &
                             s%st, sqd, w%cs, s%ounit, ssum, s%sdt)
      call splu_solve_rows_h(w%sp, s%ap, s%rwp, s%rwe, s%rwc, s%rsa, s%rsv, .true., s%st, &
                             s%sdt, sqdd, w%cs, s%ounit, ssum)
      return
    end if
    if (w%spfact) then                        ! the sparse factors: straight to their solves
      call splu_solve_rows(w%sp, s%mphip, sq, w%cs, s%ounit, ssum, s%st)
      call sens_kin_rhs(s, 2, s%rhs)
      call splu_solve_rows(w%sp, s%rhs, sqd, w%cs, s%ounit, ssum, s%sdt)
      call sens_kin_rhs(s, 3, s%rhs)
      call splu_solve_rows(w%sp, s%rhs, sqdd, w%cs, s%ounit, ssum)
      return
    end if
    s%rhs(:, :) = s%mphip                     ! (the dense solves overwrite their right sides)
    call solve_cols(w, s%rhs, sq, s%work, s%st)
    call sens_kin_rhs(s, 2, s%rhs)
    call solve_cols(w, s%rhs, sqd, s%work, s%sdt)
    call sens_kin_rhs(s, 3, s%rhs)
    call solve_cols(w, s%rhs, sqdd, s%work, s%st)
    sq = sq * s%ounit; sqd = sqd * s%ounit; sqdd = sqdd * s%ounit   ! (in model units)
    ssum = sum(sq) + sum(sqd) + sum(sqdd)
  end subroutine kin_sens

  !> The predictor's sum qp = q + hs q_dot + hp0 q_ddot + sum_j wt_j d_j; qn = qp (explicit
  !! shapes: the loops of the time step see plain arrays).
  pure subroutine pred_sum(n, hs, hp0, wt, q, qd, qdd, dd, qp, qn)
    integer, intent(in) :: n
    real(wp), intent(in) :: hs, hp0, wt(PRED_ORDER), q(n), qd(n), qdd(n), dd(PRED_ORDER, n)
    real(wp), intent(out) :: qp(n), qn(n)
    real(wp) :: x
    integer :: i, j
    do i = 1, n
      x = hs * qd(i) + hp0 * qdd(i)
      !GCC$ unroll 8
      do j = 1, PRED_ORDER                     ! (all of it: a short loop in a hot one)
        x = x + wt(j) * dd(j, i)
      end do
      qp(i) = q(i) + x; qn(i) = qp(i)
    end do
  end subroutine pred_sum

  !> The accepted state (qn, qdn, qddn) becomes (q, qd, qdd); the divided differences take the
  !! new acceleration: d_j <- (d_(j-1)new - d_(j-1)old) rden_j (d_0 = q_ddot).
  pure subroutine accept_state(n, rden, qn, qdn, qddn, q, qd, qdd, dd)
    integer, intent(in) :: n
    real(wp), intent(in) :: rden(PRED_ORDER), qn(n), qdn(n), qddn(n)
    real(wp), intent(inout) :: q(n), qd(n), qdd(n), dd(PRED_ORDER, n)
    integer :: i
    call newton_update(n, PRED_ORDER, rden, qddn, qdd, dd)
    do i = 1, n
      q(i) = qn(i); qd(i) = qdn(i)
    end do
  end subroutine accept_state

  !> A new node hs after the last (known: divided differences known so far): the
  !! reciprocals rden_j = 1 / (hs + tau_(j-1)) of the new differences (zero while d_j stays
  !! unknown: until j + 1 values are known), then tau_j <- hs + tau_(j-1).
  pure subroutine new_node(hs, known, nlev, tau, rden)
    real(wp), intent(in) :: hs
    integer, intent(in) :: known, nlev
    real(wp), intent(inout) :: tau(0:PRED_ORDER)
    real(wp), intent(out) :: rden(PRED_ORDER)
    integer :: j
    do j = 1, PRED_ORDER
      rden(j) = zero
      if (j <= known + 1 .and. j <= nlev) rden(j) = one / (hs + tau(j - 1))
    end do
    do j = PRED_ORDER, 1, -1
      tau(j) = hs + tau(j - 1)
    end do
  end subroutine new_node

  !> A new value xn at a new node enters the divided differences of x:
  !! d_j <- (d_(j-1)new - d_(j-1)old) rden_j (d_0 = the value; rden_j = 1 / (t_new - t_(j-1)),
  !! zero while d_j is not yet known), and x <- xn.
  pure subroutine newton_update(n, nlev, rden, xn, x, dd)
    integer, intent(in) :: n, nlev
    real(wp), intent(in) :: rden(PRED_ORDER), xn(n)
    real(wp), intent(inout) :: x(n), dd(PRED_ORDER, n)
    real(wp) :: dn, dnew, dold
    integer :: i, j
    do i = 1, n
      dnew = xn(i); dold = x(i)
      !GCC$ unroll 8
      do j = 1, nlev
        dn = (dnew - dold) * rden(j)
        dold = dd(j, i); dd(j, i) = dn; dnew = dn
      end do
      x(i) = xn(i)
    end do
  end subroutine newton_update

  !> The positions' Newton polynomial at hs after its last node (positions-only steps):
  !! qp = q + sum_j w_j d_j, w_1 = hs, w_j = w_(j-1) (hs + tau_(j-1)) (d_j = q[t, ..., t_j]
  !! at the nodes tau_j back, j <= nlev); qn = qp; motion = max |qp - q|. Error
  !! O(hs**(nlev + 1)) once the divided differences are known, about the size of the next
  !! term; mtop, the last term's, is the error of the order below.
  pure subroutine pos_predict(n, nlev, hs, tau, q, dd, qf, wd, qp, qn, motion, mtop, drift)
    integer, intent(in) :: n, nlev
    real(wp), intent(in) :: hs, tau(0:PRED_ORDER), q(n), dd(PRED_ORDER, n)
    real(wp), intent(in) :: qf(n), wd(n)      !! the factorization's q, the drift's weights
    real(wp), intent(out) :: qp(n), qn(n)
    real(wp), intent(out) :: motion           !! max |qp - q|
    real(wp), intent(out) :: mtop             !! max |w_nlev d_nlev|: the last term's size
    !> max wd_i |qp_i - qf_i|: how far qp is from qf (lengths in units of the length scale)
    real(wp), intent(out) :: drift
    real(wp) :: wt(PRED_ORDER), x
    integer :: i, j
    wt(1) = hs
    do j = 2, nlev
      wt(j) = wt(j - 1) * (hs + tau(j - 1))
    end do
    motion = zero; mtop = zero; drift = zero
    do i = 1, n
      x = wt(nlev) * dd(nlev, i)
      if (abs(x) > mtop) mtop = abs(x)
      ! the smallest terms first; the cases written out, so that each order's loop is
      ! unrolled (the orders used: PRED_ORDER - 2 .. PRED_ORDER = 5)
      select case (nlev)
      case (3)
        x = x + wt(2) * dd(2, i)
      case (4)
        x = x + wt(3) * dd(3, i); x = x + wt(2) * dd(2, i)
      case (5)
        x = x + wt(4) * dd(4, i); x = x + wt(3) * dd(3, i); x = x + wt(2) * dd(2, i)
      case default
        do j = nlev - 1, 2, -1
          x = x + wt(j) * dd(j, i)
        end do
      end select
      if (nlev > 1) x = x + wt(1) * dd(1, i)
      qp(i) = q(i) + x; qn(i) = qp(i)
      if (abs(x) > motion) motion = abs(x)
      x = wd(i) * abs(qp(i) - qf(i))
      if (x > drift) drift = x
    end do
  end subroutine pos_predict

  !> The Newton correction corr is small against the predicted motion: the same branch.
  pure logical function same_branch(corr, motion, ratio, tol)
    real(wp), intent(in) :: corr, motion, ratio, tol
    same_branch = corr <= max(ratio * motion, 1.0e3_wp * tol)
  end function same_branch

  !> corr = max |qn - qp| (the Newton correction), motion = max |qp - q| (the predicted one).
  pure subroutine max_diffs(n, qn, qp, q, corr, motion)
    integer, intent(in) :: n
    real(wp), intent(in) :: qn(n), qp(n), q(n)
    real(wp), intent(out) :: corr, motion
    integer :: i
    corr = zero; motion = zero
    do i = 1, n
      corr = max(corr, abs(qn(i) - qp(i))); motion = max(motion, abs(qp(i) - q(i)))
    end do
  end subroutine max_diffs

  !> The velocity against its prediction v_p = q_dot + h (q_ddot + h/2 d_1): jump =
  !! max |qdn - v_p|, dv = max |v_p - q_dot|, vmax = max |q_dot|; fin is 0 when qdn and qddn
  !! are finite, NaN otherwise.
  pure subroutine velocity_jump(n, hs, qd, qdd, dd, qdn, qddn, jump, dv, vmax, fin)
    integer, intent(in) :: n
    real(wp), intent(in) :: hs, qd(n), qdd(n), dd(PRED_ORDER, n), qdn(n), qddn(n)
    real(wp), intent(out) :: jump, dv, vmax, fin
    real(wp) :: vp
    integer :: i
    jump = zero; dv = zero; vmax = zero; fin = zero
    do i = 1, n
      vp = qd(i) + hs * (qdd(i) + (half * hs) * dd(1, i))
      jump = max(jump, abs(qdn(i) - vp)); dv = max(dv, abs(vp - qd(i)))
      vmax = max(vmax, abs(qd(i)))
      fin = fin + (qdn(i) - qdn(i)) + (qddn(i) - qddn(i))    ! 0, or NaN if not finite
    end do
  end subroutine velocity_jump

  !> The Newton correction dq is within RES_ULPS units in the last place of each coordinate
  !! or of what the angles resolve: a point at distance L from a body's origin moves by
  !! L ulp(theta) when theta changes by one unit in its last place, so positions are known
  !! no better than L eps |theta| (L: the model's length scale). With
  !! ref = max(1, L max_b |theta_b|):  |dq_i| <= RES_ULPS eps max(|q_i|, ref).
  pure logical function below_resolution(n, nb, lscale, q, dq) result(below)
    integer, intent(in) :: n, nb
    real(wp), intent(in) :: lscale
    real(wp), intent(in) :: q(n), dq(n)
    real(wp), parameter :: ULP = RES_ULPS * epsilon(one)
    real(wp) :: ref
    integer :: i
    below = .false.
    ref = zero
    do i = 1, nb
      ref = max(ref, abs(q(3 * i)))
    end do
    ref = max(one, lscale * ref)
    do i = 1, n
      if (abs(dq(i)) > ULP * max(abs(q(i)), ref)) return
    end do
    below = .true.
  end function below_resolution

  !> One chord correction of q: dq = -x (x = J^-1 Phi, overwritten with dq), q <- q + dq.
  !! conv: ||Phi||_inf <= tol and dq below resolution at the q before (below_resolution's
  !! test: |dq_i| <= RES_ULPS eps max(|q_i|, ref)); dmax = max |dq| (NaN when dq is not
  !! finite).
  pure subroutine chord_update(n, nb, lscale, tol, phi, x, q, conv, dmax, sound, ref)
    integer, intent(in) :: n, nb
    real(wp), intent(in) :: lscale, tol, phi(n)
    real(wp), intent(inout) :: x(n), q(n)
    logical, intent(out) :: conv, sound
    real(wp), intent(out) :: dmax, ref
    real(wp), parameter :: ULP = RES_ULPS * epsilon(one)
    real(wp) :: res, d, a, fin
    integer :: i
    ref = zero
    do i = 1, nb
      a = abs(q(3 * i))
      if (a > ref) ref = a
    end do
    ref = ULP * max(one, lscale * ref)
    conv = .true.
    res = zero; dmax = zero; fin = zero
    do i = 1, n                  ! (comparisons, not max: NaN goes to fin)
      a = abs(phi(i))
      if (a > res) res = a
      d = -x(i); x(i) = d
      a = abs(d)
      if (a > dmax) dmax = a
      if (a > ULP * abs(q(i)) .and. a > ref) conv = .false.   ! |dq_i| > ULP max(|q_i|, ref)
      fin = fin + (d - d)                                  ! 0, or NaN if not finite
      q(i) = q(i) + d
    end do
    dmax = dmax + fin
    sound = res <= tol .and. fin == zero
    conv = conv .and. sound
  end subroutine chord_update

  !> The rest of a Newton step after a chord correction dq (q = q_0 + dq, J(qf) dq =
  !! -Phi(q_0)) for a model whose J changes only in the angles' columns (revolutes and
  !! absolute drivers). Column theta_b of J(q) - J(qf) is (cos d_b - 1) J(qf)_b + sin d_b u_b
  !! (d_b = theta_b - thetaf_b; B(thetaf + d) = cos d B - sin d A), so
  !! C = J(qf)^-1 (J(qf) - J(q)) = sum_b c_b e_b^T, c_b = -((cos d_b - 1) e_b + sin d_b g_b).
  !! The chord leaves the error e = q - q* = -(I - C)^-1 C dq (to second order), so
  !! x = (I - C)^-1 C dq: x = sum_b c_b z_b with (I - K) z = dq_theta, K_ab = c_b(theta_a)
  !! (nb x nb, |K| <= c < 1: a Neumann sum of three terms). With the chord's C0 (the secant's J
  !! between q* and q - dq), q + x - q* = (I - C)^-1 (C - C0) (I - C0)^-1 dq, and column b of
  !! C - C0 is at most (|e0| + |e|) (1 + |g_b|) (to first order), |e0| <= |dq| / (1 - c),
  !! |e| <= c |dq| / (1 - c): the rest is at most (sum_b 1 + |g_b|) |dq|**2 (1 + c) /
  !! (1 - c)**3 (max norms; c = sum_b |cos d_b - 1| + |sin d_b| |g_b| >= |C|), and the
  !! Neumann sum's terms left out add c**4 |dq| / (1 - c). conv: q + x taken (q updated,
  !! xmax = |x|) when c <= LIN_CMAX and LIN_SAFETY times those is below ref / 2; else q
  !! unchanged.
  pure subroutine lin_correction(n, nb, q, qf, dq, g, gk, gn, dmax, ref, x, conv, xmax, c)
    integer, intent(in) :: n, nb
    real(wp), intent(inout) :: q(n)
    !> g_b (n, LIN_MAXB; zero past nb), its angle rows gk(a, b) = g_b(theta_a), |g_b|
    real(wp), intent(in) :: qf(n), dq(n), g(n, LIN_MAXB), gk(LIN_MAXB, LIN_MAXB), gn(nb)
    real(wp), intent(in) :: dmax, ref
    real(wp), intent(out) :: x(n)
    logical, intent(out) :: conv
    real(wp), intent(out) :: xmax
    real(wp), intent(out) :: c                !! the bound of |C| (below)
    real(wp), parameter :: S3 = one / 6, S5 = one / 20, C4 = one / 12, C6 = one / 30
    real(wp) :: cm(LIN_MAXB), sn(LIN_MAXB), z(LIN_MAXB), v(LIN_MAXB), y(LIN_MAXB)
    real(wp) :: d, d2, s2
    integer :: a, b, i
    conv = .false.; xmax = zero
    c = zero; s2 = zero
    cm = zero; sn = zero; z = zero
    do b = 1, nb
      d = q(3 * b) - qf(3 * b); d2 = d * d
      sn(b) = d * (one - d2 * S3 * (one - d2 * S5))               ! sin d
      cm(b) = -half * d2 * (one - d2 * C4 * (one - d2 * C6))      ! cos d - 1
      c = c + abs(cm(b)) + abs(sn(b)) * gn(b)
      s2 = s2 + one + gn(b)
      z(b) = dq(3 * b)
    end do
    if (.not. c <= LIN_CMAX) return                                      ! (NaN too)
    if (.not. LIN_SAFETY * (s2 * dmax * (one + c) + c**4 * (one - c)**2) * dmax <= &
        half * ref * (one - c)**3) return
    ! (I - K) z = dq_theta, K_ab = -(cm_b delta_ab + sn_b g_b(theta_a)), by the Neumann sum
    ! z = (I + K + K**2) dq_theta (the bodies past nb: zero): |K| <= c, so x's error from
    ! the terms left out is at most c**4 |dq| / (1 - c), within the bound above
    v = z
    do i = 1, 2
      do a = 1, LIN_MAXB
        d = v(a) - cm(a) * z(a)
        do b = 1, LIN_MAXB
          d = d - sn(b) * gk(a, b) * z(b)
        end do
        y(a) = d
      end do
      z = y
    end do
    do b = 1, LIN_MAXB                        ! the weights z_b sn_b and z_b cm_b
      sn(b) = z(b) * sn(b); cm(b) = z(b) * cm(b)
    end do
    do i = 1, n                               ! x = -sum_b z_b (cm_b e_b + sn_b g_b)
      d = zero
      do b = 1, LIN_MAXB
        d = d - sn(b) * g(i, b)
      end do
      x(i) = d
    end do
    do b = 1, nb
      x(3 * b) = x(3 * b) - cm(b)
    end do
    do i = 1, n
      xmax = max(xmax, abs(x(i)))
      q(i) = q(i) + x(i)
    end do
    conv = .true.
  end subroutine lin_correction

  !> x = a.
  pure subroutine copy1(n, a, x)
    integer, intent(in) :: n
    real(wp), intent(in) :: a(n)
    real(wp), intent(out) :: x(n)
    integer :: i
    do i = 1, n
      x(i) = a(i)
    end do
  end subroutine copy1

  !> x = a, y = b, z = c.
  pure subroutine copy3(n, a, b, c, x, y, z)
    integer, intent(in) :: n
    real(wp), intent(in) :: a(n), b(n), c(n)
    real(wp), intent(out) :: x(n), y(n), z(n)
    integer :: i
    do i = 1, n
      x(i) = a(i); y(i) = b(i); z(i) = c(i)
    end do
  end subroutine copy3

  !> Stored outputs of a run of nsteps intervals keeping every e-th (and the last).
  pure integer function kin_out_count(nsteps, e) result(n)
    integer, intent(in) :: nsteps   !! output intervals
    integer, intent(in) :: e        !! every
    n = nsteps / max(e, 1) + 1
    if (mod(nsteps, max(e, 1)) /= 0) n = n + 1
  end function kin_out_count

  !> Column scale D = diag(1/|J_k|) from J at q (columns of J summed from the blocks).
  subroutine column_scale(m, w, q, t)
    type(model_t), intent(in) :: m          !! model
    type(kin_work_t), intent(inout) :: w    !! work arrays; w%cs set
    real(wp), intent(in) :: q(:)            !! configuration
    real(wp), intent(in) :: t               !! time
    integer :: k, s, c
    if (.not. w%banded) then
      call dense_j(m, w, q, w%qz, t)
      do k = 1, m%nq
        w%cs(k) = norm2(w%jac(:, k))
      end do
    else
      ! J square with its rows split among the constraints: |J_k|^2 sums over blocks
      call assemble_blocks(m, q, w%qz, t, w%phi, w%nu, w%gam, w%asm)
      w%cs = zero
      do k = 1, m%nc
        do s = 1, NLOC
          c = m%loc(s, k)
          if (c > 0) w%cs(c) = w%cs(c) + sum(w%asm%jb(1:m%nrow(k), s, k)**2)
        end do
      end do
      w%cs = sqrt(w%cs)
    end if
    where (w%cs > zero)
      w%cs = one / w%cs
    elsewhere
      w%cs = one
    end where
  end subroutine column_scale

end module mbd_kinematics
