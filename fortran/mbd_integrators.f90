!> mbd_integrators: forward dynamics of M q_ddot + J^T lambda = Q, Phi = 0, the whole time
!! loop in one call, outputs at uniform times by quintic Hermite dense output.
!!
!! Methods (opts%method):
!!  1 generalized-alpha  index-3 implicit generalized-alpha (Arnold & Bruls 2007), Newton on
!!                       (dq, dlambda) with the Bottasso scaling; fixed step h or error
!!                       controlled (local error h^2 |beta - 1/6| |a_{n+1} - a_n|); rho_inf.
!!                       Iteration matrix [M b' + C g' + K, b' J^T; b' J, 0],
!!                       b' = (1 - am)/(beta h^2 (1 - af)), g' = gamma/(beta h), K and C by
!!                       differences of the residual, kept across steps (modified Newton);
!!                       S factored once per step with the current J.
!!  2 dopri5             index 1 ([M J^T; J 0][q_ddot; lambda] = [Q; gamma]) with Dormand-Prince
!!                       5(4), adaptive (rtol, atol), then projection of q onto Phi = 0 and of
!!                       q_dot onto J q_dot = nu after every step.
!!  3 baumgarte-rk4      index 1 with Baumgarte stabilization,
!!                       J q_ddot = gamma - 2 alpha (J q_dot - nu) - beta^2 Phi, classical RK4,
!!                       fixed step.
!!  4 partitioned        coordinate partitioning (Wehage-Haug): Dormand-Prince 5(4) on the
!!                       independent coordinates v; the dependent u from Phi(u, v) = 0, u_dot
!!                       from J_u u_dot = nu - J_v v_dot, at every stage; re-partitioned when
!!                       J_u becomes 4x worse conditioned than the choice of a QR with
!!                       column pivoting (dgeqp3) at the current state.
!! Breakpoints of the drivers' and forces' functions of time (a motion law's t0, t1, a table's
!! ends), where q_ddot may jump: dopri5, the partitioned method and baumgarte-rk4 end a step
!! on them (break_step; fixed steps: the step containing one is split there, grid_break),
!! its evaluations at the breakpoint taking the functions' left limits (the double below),
!! the next step starting from the right ones. Generalized-alpha steps over them: restarted
!! there from the index-1 q_ddot (a = q_ddot), its own accelerations converged but its
!! positions lost up to 2x in a rise of few steps (docs/motion.md).
!! Contacts and stick-slip joints (mbd_events): every method tracks their modes and records
!! their events; the error-controlled ones (dopri5, partitioned, generalized-alpha without h)
!! take a step that crosses an event again, to end at the event (located on the step's
!! dense output), and change the modes there; the fixed-step ones change them at the end of
!! the step that crossed (the event's located time is recorded). After a change the step
!! restarts (dopri5: no first-same-as-last; generalized-alpha: q_ddot and a from the new
!! modes). The modes at each output are kept for its multipliers and element outputs.
module mbd_integrators
  use mbd_kinds, only: wp, zero, one, half, two
  use mbd_status, only: MBD_OK, MBD_BAD_SETTING, MBD_SINGULAR, MBD_NO_CONVERGENCE, &
                        MBD_INTEGRATOR_FAILED, MBD_LAPACK, MBD_NO_MEMORY, MBD_USER_ABORT, &
                        MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_fail
  use mbd_model, only: model_t, model_next_break
  use mbd_points, only: NLOC, MAXROW
  use mbd_forces, only: FRC_FRICTION
  use mbd_assemble, only: assemble_dense, assemble_blocks, blocks_jv
  use mbd_linsolve, only: lu_factor, lu_solve, lapack_status
  use mbd_lapack, only: dgesvd, dgeqp3, dgecon
  use mbd_interp, only: hermite5
  use mbd_band, only: band_t, band_plan, band_zero, band_factor, band_solve
  use mbd_saddle, only: saddle_t, saddle_plan, saddle_factor, saddle_solve
  use mbd_dynamics, only: dyn_work_t, dyn_accel, dyn_velocity, dyn_project_pos, gen_forces, &
                          kinetic_energy, dyn_tangent, dyn_solve, dyn_jt_lam, dyn_multipliers, &
                          dyn_jv, dyn_null_basis, SOLVER_DENSE, dyn_element_outputs
  use mbd_events, only: ev_log_t, events_active, events_init, events_find, events_switch, &
                        event_tol
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: dyn_opts_t, dyn_stats_t, METH_GENALPHA, METH_DOPRI5, METH_RK4, METH_PARTITIONED
  public :: integrate, output_rows, output_index, MAX_STEPS_DEFAULT
  ! the Dormand-Prince 5(4) stages and error estimate, also used by the sensitivity integrator
  ! (mbd_sens_dynamics)
  public :: dopri5_state, dopri5_error, DOPRI_C, stiffness_test, break_step
  ! generalized-alpha's companion for quantities stepped with the state (mbd_sens_genalpha)
  public :: ga_hook_t, GA_NCOEF

  integer, parameter :: METH_GENALPHA = 1, METH_DOPRI5 = 2, METH_RK4 = 3, METH_PARTITIONED = 4
  !> Default step limit: it ends a run whose steps collapse without underflowing, after
  !! 10 s to 10 minutes at 1-80 us a step (small models); a long run raises it.
  integer, parameter :: MAX_STEPS_DEFAULT = 10000000

  !> Integrator settings.
  type :: dyn_opts_t
    integer :: method = METH_GENALPHA
    real(wp) :: rtol = 1.0e-6_wp      !! relative tolerance (adaptive methods)
    real(wp) :: atol = 1.0e-8_wp      !! absolute tolerance
    real(wp) :: h = zero              !! fixed step (0: adaptive; required for RK4)
    real(wp) :: rho_inf = 0.8_wp      !! generalized-alpha spectral radius at infinity
    real(wp) :: balpha = 10.0_wp      !! Baumgarte alpha
    real(wp) :: bbeta = 10.0_wp       !! Baumgarte beta
    integer :: max_steps = MAX_STEPS_DEFAULT  !! limit on accepted + rejected steps
  end type dyn_opts_t

  !> What the integrator did.
  type :: dyn_stats_t
    integer :: steps = 0, rejected = 0, newton = 0, rhs = 0, jacobians = 0, partitions = 0
    integer :: factorizations = 0     !! LU factorizations of the iteration matrix
    integer :: schur = 0              !! of them through the Schur complement (diagonal K)
    integer :: kl = 0, ku = 0         !! band widths of the iteration matrix (band path)
    real(wp) :: hmin = huge(one), hmax = zero
    real(wp) :: t_fail = zero         !! time reached when a method failed
    !> partitioned (dense J): the smallest reciprocal condition number of J_u at an
    !! accepted step and its time (a singular configuration passed close by)
    real(wp) :: rc_min = huge(one), t_rc_min = zero
    !> dopri5 and partitioned: the time from which the steps were limited by stability, not
    !! accuracy (stiffness_test; huge when they were not)
    real(wp) :: t_stiff = huge(one)
  end type dyn_stats_t

  !> Run context: settings, counters, the output grid, the form of the equations and the
  !! partition, and the last full state evaluated.
  type :: itg_t
    type(dyn_opts_t) :: opts
    type(dyn_stats_t) :: st
    real(wp) :: t0 = zero, t1 = zero
    integer :: nsteps = 0               !! output intervals
    integer :: every = 1                !! store outputs k with mod(k, every) = 0, and k = nsteps
    integer :: kout = 0                 !! next output index k (0 .. nsteps)
    integer :: nout = 0                 !! rows stored
    logical :: baumgarte = .false.
    integer :: ni = 0                       !! independent coordinates (partitioned)
    integer, allocatable :: iv(:), iu(:)    !! independent and dependent coordinates
    !> partitioned: null-space basis (nq, ni), the choice's workspace, J_u (dense, or in
    !! band storage with the map of the blocks into it) and the dependent solves' vectors
    real(wp), allocatable :: nb(:, :), gw(:, :), gn(:), nsq(:, :), sv(:), svw(:)
    integer, allocatable :: sel(:), mark(:)
    real(wp), allocatable :: ju(:, :), ub(:), px(:), qa(:, :), tau(:), qwork(:), cw(:)
    real(wp), allocatable :: vw(:)          !! (ni) an output's v_dot (complete_outputs)
    real(wp), allocatable :: qkeep(:), vkeep(:)  !! (nq) the state kept by complete_outputs
    integer, allocatable :: upiv(:), usrc(:), upos(:), jp(:), iw(:)
    type(band_t) :: bu
    real(wp), allocatable :: qf(:), vf(:), af(:), lam(:)   !! last full state
    real(wp) :: ts = zero                   !! start of the current step
    real(wp), allocatable :: qs(:), vs(:), as(:)          !! full state there
    logical :: events = .false.             !! contacts or stick-slip joints: track modes
    type(ev_log_t) :: log                   !! events
    real(wp), allocatable :: cso(:, :, :)   !! (NCS, nf, rows) element modes at the outputs
  end type itg_t

  !> generalized-alpha's coefficients handed to a hook's step: am, af, gamma, beta, b', g'
  integer, parameter :: GA_NCOEF = 6

  !> A companion of generalized-alpha (the design sensitivities, mbd_sens_genalpha): stepped
  !! with the state from each converged Newton iteration, with its iteration matrix S.
  type, abstract :: ga_hook_t
  contains
    !> the auxiliary acceleration's shift on a change of step size, a <- q_ddot + f (a - q_ddot)
    procedure(hook_rescale), deferred :: rescale
    !> the step to tn from the converged state (qn, vn, an, lamn), with S's factors; esq the
    !! sum of its squared weighted errors over ne components (accepted steps only use it)
    procedure(hook_step), deferred :: step
    !> an accepted step: output row r at tk in (ta, tb] (dense output between its ends)
    procedure(hook_emit), deferred :: emit
    !> an accepted step: its end becomes the next step's start
    procedure(hook_commit), deferred :: commit
  end type ga_hook_t

  abstract interface
    subroutine hook_rescale(self, f)
      import :: ga_hook_t, wp
      class(ga_hook_t), intent(inout) :: self
      real(wp), intent(in) :: f
    end subroutine hook_rescale
    subroutine hook_step(self, m, w, sg, tn, h, coef, qn, vn, an, lamn, rtol, atol, esq, ne, &
                         status)
      import :: ga_hook_t, wp, model_t, dyn_work_t, saddle_t, GA_NCOEF
      class(ga_hook_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(dyn_work_t), intent(inout) :: w
      type(saddle_t), intent(inout) :: sg
      real(wp), intent(in) :: tn, h, coef(GA_NCOEF), rtol, atol
      real(wp), intent(in), contiguous :: qn(:), vn(:), an(:), lamn(:)
      real(wp), intent(out) :: esq
      integer, intent(out) :: ne, status
    end subroutine hook_step
    subroutine hook_emit(self, r, tk, ta, tb)
      import :: ga_hook_t, wp
      class(ga_hook_t), intent(inout) :: self
      integer, intent(in) :: r
      real(wp), intent(in) :: tk, ta, tb
    end subroutine hook_emit
    subroutine hook_commit(self)
      import :: ga_hook_t
      class(ga_hook_t), intent(inout) :: self
    end subroutine hook_commit
  end interface

  !> fixed steps: a breakpoint this many steps after a grid time ends the step before it
  real(wp), parameter :: GRID_MERGE = 0.05_wp

  !> partitioned: re-partition when J_u is this many times worse conditioned than the best
  !! choice now (docs/dynamics.md: measured on a double pendulum and the N-four-bar)
  real(wp), parameter :: REPARTITION = 0.25_wp

  ! Dormand-Prince 5(4) tableau
  real(wp), parameter :: C2 = 0.2_wp, C3 = 0.3_wp, C4 = 0.8_wp, C5 = 8.0_wp / 9.0_wp
  real(wp), parameter :: A21 = 0.2_wp, A31 = 3.0_wp / 40, A32 = 9.0_wp / 40
  real(wp), parameter :: A41 = 44.0_wp / 45, A42 = -56.0_wp / 15, A43 = 32.0_wp / 9
  real(wp), parameter :: A51 = 19372.0_wp / 6561, A52 = -25360.0_wp / 2187
  real(wp), parameter :: A53 = 64448.0_wp / 6561, A54 = -212.0_wp / 729
  real(wp), parameter :: A61 = 9017.0_wp / 3168, A62 = -355.0_wp / 33, A63 = 46732.0_wp / 5247
  real(wp), parameter :: A64 = 49.0_wp / 176, A65 = -5103.0_wp / 18656
  real(wp), parameter :: A71 = 35.0_wp / 384, A73 = 500.0_wp / 1113, A74 = 125.0_wp / 192
  real(wp), parameter :: A75 = -2187.0_wp / 6784, A76 = 11.0_wp / 84
  real(wp), parameter :: E1 = 71.0_wp / 57600, E3 = -71.0_wp / 16695, E4 = 71.0_wp / 1920
  real(wp), parameter :: E5 = -17253.0_wp / 339200, E6 = 22.0_wp / 525, E7 = -1.0_wp / 40
  !> the nodes of stages 2 .. 6 (c_6 = 1)
  real(wp), parameter :: DOPRI_C(2:6) = [C2, C3, C4, C5, 1.0_wp]

contains

  !> MBD_INTEGRATOR_FAILED for a step size underflow at t, with the friction hint.
  subroutine underflow(m, w, t, status, msg)
    type(model_t), intent(in) :: m                 !! model
    type(dyn_work_t), intent(in) :: w              !! work arrays (the last friction solve)
    real(wp), intent(in) :: t                      !! time of the last accepted step
    integer, intent(out) :: status                 !! MBD_INTEGRATOR_FAILED
    character(len=MSG_LEN), intent(inout) :: msg   !! explanation
    status = MBD_INTEGRATOR_FAILED
    write (msg, '(a,es12.5)') 'step size underflow at t = ', t
    call friction_hint(m, w, msg)
  end subroutine underflow

  !> With joint friction, append to a failure's message where such failures come from: next
  !! to a dead centre or a singular position the joint loads grow like 1 / distance, and the
  !! friction on them can have several solutions or none (w%locked: the last solve found none).
  subroutine friction_hint(m, w, msg)
    type(model_t), intent(in) :: m                 !! model
    type(dyn_work_t), intent(in) :: w              !! work arrays (the last friction solve)
    character(len=MSG_LEN), intent(inout) :: msg   !! explanation, extended
    if (m%nfric == 0) return
    if (w%locked) then
      msg = trim(msg) // ': joint friction locks the mechanism (the last friction solve ' // &
        'found no solution)'
    else
      msg = trim(msg) // ': with joint friction'
    end if
    msg = trim(msg) // '; next to a dead centre or a singular position the joint loads ' // &
      'grow like 1 / distance and the friction on them can have several solutions or none ' // &
      '(a rigid linkage with Coulomb friction jams there, as its friction circles ' // &
      'predict): lower the friction, add compliance, or keep the motion away from it'
  end subroutine friction_hint

  !> Integrate from the consistent state (q, qd) at t0 to t1, with outputs at
  !! t0 + k (t1 - t0)/nsteps, k = 0..nsteps, of which those with mod(k, every) = 0 and the
  !! last (k = nsteps) are written into the columns of qo, vo, ao, lo (output_rows of them).
  !! nout returns the number of rows written (all, unless a failure stopped the run).
  !! The multipliers lo at every output are those of the index-1 equations at the output
  !! state (see finish_outputs).
  !! With contacts or stick-slip joints, log (allocated by ev_log_init) returns the events
  !! and eo(NEO, nf, rows) the element outputs at the stored rows (dyn_element_outputs).
  subroutine integrate(m, w, q, qd, t0, t1, nsteps, every, opts, qo, vo, ao, lo, nout, st, &
                       status, msg, log, eo, ctl, hook)
    type(model_t), intent(in) :: m               !! model
    type(dyn_work_t), intent(inout) :: w         !! dynamics work arrays (dyn_init done)
    real(wp), intent(inout) :: q(:), qd(:)       !! consistent initial state, then final
    real(wp), intent(in) :: t0, t1               !! time span
    integer, intent(in) :: nsteps                !! output intervals
    integer, intent(in) :: every                 !! store every every-th output (and the last)
    type(dyn_opts_t), intent(in) :: opts         !! settings
    real(wp), intent(out) :: qo(:, :), vo(:, :), ao(:, :)  !! outputs (nq, rows)
    real(wp), intent(out) :: lo(:, :)            !! multipliers at the outputs (neq, rows)
    integer, intent(out) :: nout                 !! rows written
    type(dyn_stats_t), intent(out) :: st         !! counters
    integer, intent(out) :: status               !! MBD_OK or a failure
    character(len=MSG_LEN), intent(out) :: msg   !! explanation
    type(ev_log_t), intent(inout), optional :: log  !! event log (capacity set by the caller)
    real(wp), intent(out), optional :: eo(:, :, :)  !! element outputs (NEO, nf, rows)
    !> progress, shared with a caller in another thread: ctl(1) gets the rows stored so far,
    !! ctl(2) /= 0 asks the run to stop (MBD_USER_ABORT, the rows so far kept)
    integer, intent(inout), optional, volatile :: ctl(:)
    !> generalized-alpha only: a companion stepped with the state (ga_hook_t)
    class(ga_hook_t), intent(inout), optional :: hook
    type(itg_t) :: c
    status = MBD_OK; msg = ''; nout = 0
    qo = zero; vo = zero; ao = zero; lo = zero
    if (present(eo)) eo = zero
    if (opts%method == METH_RK4 .and. .not. (opts%h > zero)) then
      status = MBD_BAD_SETTING; msg = 'baumgarte-rk4 needs a step h > 0'; return
    end if
    if (.not. (opts%rtol > zero .and. opts%atol > zero)) then
      status = MBD_BAD_SETTING; msg = 'rtol and atol must be positive'; return
    end if
    if (every < 1 .or. size(qo, 2) /= output_rows(nsteps, every)) then
      status = MBD_BAD_SETTING; msg = 'every must be >= 1 and the outputs sized for it'; return
    end if
    if (m%nstick > 0 .and. (opts%method == METH_GENALPHA .or. opts%method == METH_RK4)) then
      status = MBD_BAD_SETTING
      msg = 'stick-slip friction runs in dopri5 and partitioned; use the regularized '// &
            'friction model with generalized-alpha or baumgarte-rk4'
      return
    end if
    c%opts = opts; c%t0 = t0; c%t1 = t1; c%nsteps = nsteps; c%every = every
    allocate (c%qf(m%nq), c%vf(m%nq), c%af(m%nq), c%lam(m%neq), c%cso(size(w%cst, 1), &
              m%nf, merge(size(qo, 2), 0, m%ncontact + m%nfric > 0)), stat=status)
    if (status /= 0) then
      call mem_fail(REAL_BYTES * (3 * real(m%nq, wp) + m%neq + 2 * real(m%nf, wp) * &
                    merge(size(qo, 2), 0, m%ncontact + m%nfric > 0)), 'the integrator state', &
                    'use a smaller model', status, msg)
      return
    end if
    if (present(log)) c%log = log
    c%events = events_active(m)
    if (present(hook) .and. (opts%method /= METH_GENALPHA .or. c%events)) then
      status = MBD_BAD_SETTING
      msg = 'a companion of the state steps with generalized-alpha, without events'; return
    end if
    if (c%events) then
      call events_init(m, w, q, qd, t0, status)
      if (status /= MBD_OK) then
        msg = 'the contact and friction modes at the start cannot be resolved'; return
      end if
    end if
    c%qf = q; c%vf = qd
    call dyn_accel(m, w, q, qd, t0, c%af, c%lam, status)
    if (status /= MBD_OK) then
      msg = 'the mass matrix and constraints give a singular system at the start'; return
    end if
    qo(:, 1) = q; vo(:, 1) = qd; ao(:, 1) = c%af
    c%nout = 1; c%kout = 1
    call save_modes(w, c, 1)
    if (nsteps > 0) then
      select case (opts%method)
      case (METH_GENALPHA)
        call run_genalpha(m, w, c, qo, vo, ao, status, msg, ctl, hook)
      case (METH_DOPRI5, METH_RK4)
        call run_explicit(m, w, c, .false., qo, vo, ao, status, msg, ctl)
      case (METH_PARTITIONED)
        call run_explicit(m, w, c, .true., qo, vo, ao, status, msg, ctl)
      case default
        status = MBD_BAD_SETTING; msg = 'unknown integration method'
      end select
    end if
    nout = c%nout; st = c%st
    q = c%qf; qd = c%vf
    call finish_outputs(m, w, c, qo, vo, ao, lo, eo)
    if (present(log)) log = c%log
  end subroutine integrate

  !> Keep the element modes for the output rows r0 .. c%nout (just written).
  subroutine save_modes(w, c, r0)
    type(dyn_work_t), intent(in) :: w
    type(itg_t), intent(inout) :: c
    integer, intent(in) :: r0
    integer :: r
    if (size(c%cso, 3) == 0) return
    do r = r0, c%nout
      c%cso(:, :, r) = w%cst
    end do
  end subroutine save_modes

  !> The accelerations and multipliers at the stored outputs, from the index-1 equations at
  !! the output state (accel_at), for every method. For the explicit methods these are what
  !! the integrator itself evaluates at a step; between steps they belong to the
  !! interpolated state (q, q_dot), instead of an interpolant of the accelerations, whose
  !! error is 100x larger. (Projecting the interpolated state onto Phi = 0 and
  !! J q_dot = nu first made them less accurate: the kinetic-energy projection mixes the
  !! velocity errors of all coordinates.) generalized-alpha keeps its own q_ddot, but its
  !! lambda_{n+1} is a second difference of positions (q_ddot_{n+1} = (q_{n+1} - q*) /
  !! (beta' h^2)), which carries the rounding of q amplified by 1 / (beta' h^2); its
  !! reported multipliers are those of the state instead. With independent rows lambda is
  !! the solve's; otherwise (redundant rows, a rank-revealing solve near a singular
  !! position, Baumgarte's stabilized accelerations) the minimum-norm solution of
  !! J^T lambda = Q - M q_ddot over all rows. If the solve fails at a state, the row keeps
  !! its accelerations and lambda follows from them.
  subroutine finish_outputs(m, w, c, qo, vo, ao, lo, eo)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(in) :: c
    real(wp), intent(in) :: qo(:, :), vo(:, :)
    real(wp), intent(inout) :: ao(:, :), lo(:, :)
    real(wp), intent(inout), optional :: eo(:, :, :)
    real(wp) :: t, a1(m%nq), lam(m%neq), cfinal(size(w%cst, 1), size(w%cst, 2))
    integer :: r, stt
    character(len=MSG_LEN) :: lmsg
    cfinal = w%cst
    do r = 1, c%nout
      t = c%t0
      if (c%nsteps > 0) t = out_time(c, output_index(c%nsteps, c%every, r))
      if (size(c%cso, 3) > 0) w%cst = c%cso(:, :, r)   ! the modes of the output's step
      call accel_at(m, w, c%opts, qo(:, r), vo(:, r), t, a1, lam, stt)
      if (stt == MBD_OK) then
        if (c%opts%method /= METH_GENALPHA) ao(:, r) = a1
        if (w%na == m%neq .and. .not. w%lsq .and. c%opts%method /= METH_RK4) then
          lo(:, r) = lam                ! independent rows: the solve's lambda is the one
        else
          call dyn_multipliers(m, w, qo(:, r), vo(:, r), a1, t, lo(:, r), stt, lmsg)
        end if
      else
        a1 = ao(:, r)
        call dyn_multipliers(m, w, qo(:, r), vo(:, r), a1, t, lo(:, r), stt, lmsg)
      end if
      if (present(eo)) then
        if (size(eo, 2) > 0) call dyn_element_outputs(m, w, qo(:, r), vo(:, r), t, eo(:, :, r))
      end if
    end do
    w%cst = cfinal
  end subroutine finish_outputs

  !> More steps to take: fixed steps count to nfix, adaptive ones run to t1.
  logical function more(c, t, fixed, nfix)
    type(itg_t), intent(in) :: c
    real(wp), intent(in) :: t
    logical, intent(in) :: fixed
    integer, intent(in) :: nfix
    if (fixed) then
      more = c%st%steps < nfix
    else
      more = t < c%t1 - 1.0e-14_wp * abs(c%t1 - c%t0)
    end if
  end function more

  !> The run stops at the step limit (accepted plus rejected steps): say how to raise it.
  !! nfix > 0: a fixed-step run that needs nfix steps (stopped before it starts).
  subroutine step_limit(c, t, nfix, status, msg)
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t
    integer, intent(in) :: nfix
    integer, intent(out) :: status
    character(len=MSG_LEN), intent(out) :: msg
    status = MBD_INTEGRATOR_FAILED
    c%st%t_fail = t
    if (nfix > 0) then
      write (msg, '(a,es10.3,a,i0,a,i0,a)') 'the fixed step h = ', c%opts%h, ' needs ', nfix, &
        ' steps, more than the step limit max_steps = ', c%opts%max_steps, &
        ': raise max_steps (command line: --max-steps), or take a larger h'
    else
      write (msg, '(a,i0,a,es12.5,a)') 'the step limit max_steps = ', c%opts%max_steps, &
        ' (accepted and rejected steps) was reached at t = ', t, &
        ': raise max_steps (command line: --max-steps), or loosen rtol and atol'
    end if
  end subroutine step_limit

  !> The modes of contacts or stick-slip joints could not be resolved at t (a solve failed
  !! there, or the friction of a joint locks itself).
  subroutine event_failure(c, t, status, msg)
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t
    integer, intent(out) :: status
    character(len=MSG_LEN), intent(out) :: msg
    status = MBD_INTEGRATOR_FAILED
    c%st%t_fail = t
    write (msg, '(a,es12.5,a)') 'the contact and friction modes could not be resolved at t = ', &
      t, ' (the equations are singular there, or a joint''s friction locks it: '// &
      'a smaller friction coefficient)'
  end subroutine event_failure

  !> Number of fixed steps of about h that span (t0, t1) (capped at huge(0), not overflowing).
  integer function fixed_steps(c)
    type(itg_t), intent(in) :: c
    real(wp) :: r
    r = anint((c%t1 - c%t0) / c%opts%h)
    fixed_steps = huge(0)
    if (r < real(huge(0), wp)) fixed_steps = max(1, int(r))
  end function fixed_steps

  !> Time of fixed step k (exact at the end).
  pure real(wp) function step_time(c, k, nfix)
    type(itg_t), intent(in) :: c
    integer, intent(in) :: k, nfix
    step_time = c%t0 + (c%t1 - c%t0) * (real(k, wp) / nfix)
    if (k == nfix) step_time = c%t1
  end function step_time

  real(wp) function out_time(c, k)
    type(itg_t), intent(in) :: c
    integer, intent(in) :: k
    out_time = c%t0 + (c%t1 - c%t0) * (real(k, wp) / c%nsteps)
    if (k == c%nsteps) out_time = c%t1
  end function out_time

  !> Write the stored outputs in (ta, tb] by quintic Hermite interpolation of the two
  !! states; outputs between the stored ones (every > 1) are passed over, not computed.
  !! abl: the accelerations' left limit at tb for the outputs before it (a step ending on a
  !! breakpoint of the functions of time; ab, the right one, is an output's at tb itself).
  subroutine emit(c, qo, vo, ao, ta, qa, va, aa, tb, qb, vb, ab, abl)
    type(itg_t), intent(inout) :: c
    real(wp), intent(inout) :: qo(:, :), vo(:, :), ao(:, :)
    real(wp), intent(in) :: ta, tb, qa(:), va(:), aa(:), qb(:), vb(:), ab(:)
    real(wp), intent(in), optional :: abl(:)
    real(wp) :: tk, tol
    tol = 1.0e-12_wp * abs(c%t1 - c%t0)
    do while (c%kout <= c%nsteps)
      tk = out_time(c, c%kout)
      if (tk > tb + tol) exit
      if (mod(c%kout, c%every) == 0 .or. c%kout == c%nsteps) then
        if (present(abl) .and. tk < tb - tol) then
          call hermite5(ta, qa, va, aa, tb, qb, vb, abl, tk, qo(:, c%nout + 1), &
                        vo(:, c%nout + 1), ao(:, c%nout + 1))
        else
          call hermite5(ta, qa, va, aa, tb, qb, vb, ab, tk, qo(:, c%nout + 1), &
                        vo(:, c%nout + 1), ao(:, c%nout + 1))
        end if
        c%nout = c%nout + 1
      end if
      c%kout = c%kout + 1
    end do
  end subroutine emit

  !> Publish the rows stored so far in ctl(1); .true. (with MBD_USER_ABORT) when the caller
  !! asked the run to stop (ctl(2) /= 0). Without ctl, nothing.
  logical function stopped(c, t, status, msg, ctl)
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t
    integer, intent(inout) :: status
    character(len=MSG_LEN), intent(inout) :: msg
    integer, intent(inout), optional, volatile :: ctl(:)
    stopped = .false.
    if (.not. present(ctl)) return
    ctl(1) = c%nout
    if (ctl(2) == 0) return
    stopped = .true.
    status = MBD_USER_ABORT
    c%st%t_fail = t
    write (msg, '(a,es12.5,a)') 'stopped on request at t = ', t, ' (the rows so far are kept)'
  end function stopped

  !> Rows stored for nsteps output intervals, keeping k = 0, every, 2 every, ... and nsteps.
  pure integer function output_rows(nsteps, every)
    integer, intent(in) :: nsteps             !! output intervals
    integer, intent(in) :: every              !! decimation (>= 1)
    output_rows = nsteps / every + 1
    if (mod(nsteps, every) /= 0) output_rows = output_rows + 1
  end function output_rows

  !> Output index k (0 .. nsteps) of stored row r (1 .. output_rows).
  pure integer function output_index(nsteps, every, r)
    integer, intent(in) :: nsteps, every      !! output intervals, decimation
    integer, intent(in) :: r                  !! row
    output_index = min((r - 1) * every, nsteps)
  end function output_index

  !> Weighted RMS norm of an error estimate.
  real(wp) function err_norm(c, e, ya, yb)
    type(itg_t), intent(in) :: c
    real(wp), intent(in) :: e(:), ya(:), yb(:)
    err_norm = sqrt(sum((e / (c%opts%atol + c%opts%rtol * max(abs(ya), abs(yb))))**2) / size(e))
  end function err_norm

  !> A first step that makes h^2 |q_ddot| about atol + rtol |q| (at most the output spacing).
  real(wp) function initial_step(c)
    type(itg_t), intent(in) :: c
    real(wp) :: sc
    sc = maxval(abs(c%af) / (c%opts%atol + c%opts%rtol * abs(c%qf)))
    initial_step = (c%t1 - c%t0) / c%nsteps
    if (sc > zero) initial_step = min(initial_step, 0.1_wp * sqrt(one / sc))
    initial_step = max(initial_step, 1.0e-10_wp * abs(c%t1 - c%t0))
  end function initial_step

  ! -------------------------------------------------------------------- generalized-alpha
  !> Index-3 generalized-alpha (Arnold & Bruls 2007), Newton on (q_{n+1}, lambda_{n+1}) with
  !! the iteration matrix S = [M b' + C g' + K, b' J^T; b' J, 0]. The costly part, K and C
  !! by differences, is kept across steps and evaluated again only when Newton contracts
  !! slowly (|dq_k| > GA_RHO |dq_{k-1}|), takes GA_SLOW iterations, or fails (the step is
  !! then retried with fresh K, C). S itself is formed with the current J and factored once
  !! per step (cheaper than the extra iterations an older J costs), on the path of w
  !! (mbd_saddle: a plain-loop dense LU, or the band LU of a large model). K and C are
  !! differences over column groups (dyn_tangent), kept on their sparse pattern.
  !! Converged: |Phi| <= w%tol, the last correction below 1e-3 (atol + rtol |q|), and the
  !! residual of M q_ddot + J^T lambda = Q below GA_RTOL of its largest term, so that the
  !! result is that of full Newton (a stale S only changes the iteration count).
  !! A hook (ga_hook_t) steps from each converged state with S's factors (fresh K, C when it
  !! asks, MBD_NO_CONVERGENCE), and its error joins the state's in the step size control.
  subroutine run_genalpha(m, w, c, qo, vo, ao, status, msg, ctl, hook)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    integer, intent(inout), optional, volatile :: ctl(:)   !! progress (see integrate)
    real(wp), intent(inout) :: qo(:, :), vo(:, :), ao(:, :)
    integer, intent(out) :: status
    character(len=MSG_LEN), intent(out) :: msg
    class(ga_hook_t), intent(inout), optional :: hook
    real(wp), parameter :: GA_RHO = 0.1_wp       ! contraction rate that asks for new K, C
    real(wp), parameter :: GA_RTOL = 1.0e-11_wp  ! relative residual of the dynamic equations
    integer, parameter :: GA_SLOW = 6            ! iterations that ask for new K, C
    integer, parameter :: GA_MAXIT = 30          ! iterations before the step fails
    real(wp) :: am, af, gam, bet, bp, gp, h, t, err, tnew, facc, v, hprev, dqn, dqp, dtol, &
                dqpp
    real(wp) :: rtol_dyn, cf, kmax, cmax, fmax, qmax, vmax, rmax, te, mufric, esq
    real(wp) :: coef(GA_NCOEF)
    real(wp) :: q(m%nq), qd(m%nq), qdd(m%nq), acc(m%nq), lam(m%neq)
    real(wp) :: qn(m%nq), vn(m%nq), an(m%nq), accn(m%nq), lamn(m%neq), dq(m%nq), ap(m%nq)
    real(wp) :: res(m%nq + w%na), dg(m%nq), ew(m%nq)
    real(wp), allocatable :: kv(:), cv(:), kc(:)   ! K, C and K + g' C on the pattern
    type(saddle_t) :: sg                            ! the iteration matrix S
    integer :: it, n, stt, nfix, na, attempt, nkc, k, nnz, kev, nprev, i, ne
    logical :: fixed, conv, have_kc, new_kc, finite, changed, diagk
    status = MBD_OK; msg = ''
    n = m%nq; na = w%na
    ! S = [M b' + K + g' C, b' J^T; b' J, 0] on the path of w (dense: the sparse LU up to 128
    ! rows, the plain-loop LU beyond); on the band path a diagonal K pattern (pins, no force
    ! couples two coordinates) keeps the upper-left block diagonal, and S goes through its
    ! Schur complement like the index-1 systems (mbd_schur; on the dense path the sparse LU
    ! costs less: the free four-bar's step 17.9k instructions against 20.0k through S)
    diagk = w%solver /= SOLVER_DENSE .and. &
            all([(all(w%krow(w%kptr(k):w%kptr(k + 1) - 1) == k), k=1, m%nq)])
    call saddle_plan(m, w%rows, w%solver, sg, status, msg, kptr=w%kptr, krow=w%krow, &
                     small=.true., schur=diagk)
    if (status /= MBD_OK) return
    c%st%kl = sg%kl; c%st%ku = sg%ku
    nnz = w%kptr(n + 1) - 1
    allocate (kv(nnz), cv(nnz), kc(nnz), stat=stt)
    if (stt /= 0) then
      call mem_fail(REAL_BYTES * 3 * real(nnz, wp), 'the tangent stiffness and damping', &
                    'use a smaller model', status, msg)
      return
    end if
    am = (2 * c%opts%rho_inf - 1) / (c%opts%rho_inf + 1)        ! Arnold & Bruls (2007)
    af = c%opts%rho_inf / (c%opts%rho_inf + 1)
    gam = half + af - am
    bet = 0.25_wp * (gam + half)**2
    cf = (1 - af) / (1 - am)             ! weight of q_ddot_{n+1} in a_{n+1}
    coef(1:4) = [am, af, gam, bet]
    fixed = c%opts%h > zero
    have_kc = .false.; new_kc = .false.
    mufric = zero                        ! the largest friction coefficient of a joint
    do k = 1, m%nf
      if (m%fkind(k) == FRC_FRICTION) mufric = max(mufric, m%fp(m%fpo(k)), m%fp(m%fpo(k) + 1))
    end do
    kv = zero; cv = zero; kmax = zero; cmax = zero
    q = c%qf; qd = c%vf; qdd = c%af; lam = c%lam
    t = c%t0
    nfix = 0
    if (fixed) then
      nfix = fixed_steps(c)
      if (nfix > c%opts%max_steps) then
        call step_limit(c, t, nfix, status, msg); return
      end if
      h = (c%t1 - c%t0) / nfix                                      ! land on t1
    else
      h = initial_step(c)
    end if
    acc = qdd              ! the auxiliary acceleration a_0 = q_ddot_0
    hprev = zero
    err = zero
    do while (more(c, t, fixed, nfix))
      if (c%st%steps + c%st%rejected >= c%opts%max_steps) then
        call step_limit(c, t, 0, status, msg); return
      end if
      h = min(h, c%t1 - t)
      tnew = t + h
      if (fixed) then
        tnew = step_time(c, c%st%steps + 1, nfix)
        h = tnew - t
      end if
      c%st%t_fail = t
      bp = (1 - am) / (bet * h * h * (1 - af))
      gp = gam / (bet * h)
      ! the auxiliary acceleration is q_ddot shifted by (am - af) h: on a change of step size
      ! a - q_ddot scales with it, a <- q_ddot + (h / h_prev) (a - q_ddot)
      if (hprev > zero .and. abs(h - hprev) > zero) then
        acc = qdd + (h / hprev) * (acc - qdd)
        if (present(hook)) call hook%rescale(h / hprev)
      end if
      hprev = h
      do attempt = 1, 2
        ! predictor: q_ddot_{n+1} = q_ddot_n, lambda_{n+1} = lambda_n (not extrapolated:
        ! the index-3 accelerations carry a step-to-step oscillation);
        ! a_{n+1} = (af q_ddot_n + (1 - af) q_ddot_{n+1} - am a_n) / (1 - am);
        ! q_{n+1} = q_n + h q_dot_n + h^2 ((1/2 - beta) a_n + beta a_{n+1}),
        ! q_dot_{n+1} = q_dot_n + h ((1 - gamma) a_n + gamma a_{n+1})
        an = qdd
        lamn = lam
        accn = (af * qdd - am * acc) / (1 - am)
        ap = accn + cf * an
        qn = q + h * qd + h * h * (half - bet) * acc + h * h * bet * ap
        vn = qd + h * (1 - gam) * acc + h * gam * ap
        conv = .false.
        nkc = 0                         ! K, C evaluations in this attempt
        dq = zero; dqp = huge(one); dqpp = huge(one)
        do it = 1, GA_MAXIT
          call assemble_blocks(m, qn, vn, tnew, w%phi, w%nu, w%gam, w%asm)
          call gen_forces(m, qn, vn, tnew, w%force, v, cst=w%cst, lam=lamn)
          ! r = M q_ddot + J^T lambda - Q;  r_c = b' Phi
          call dyn_jt_lam(m, w%asm%jb, lamn, res(1:n))
          ! the residual tolerance is GA_RTOL of the largest term, but not below the change
          ! that rounding q, q_dot to working precision makes (K |q| + C |q_dot|) eps
          fmax = zero; qmax = zero; vmax = zero; rmax = zero; finite = .true.
          do k = 1, n
            fmax = max(fmax, abs(res(k)), abs(w%force(k)), abs(m%mdiag(k) * an(k)))
            res(k) = res(k) + m%mdiag(k) * an(k) - w%force(k)
            if (.not. abs(res(k)) <= huge(one)) finite = .false.      ! NaN or Inf
            rmax = max(rmax, abs(res(k)))
            qmax = max(qmax, abs(qn(k))); vmax = max(vmax, abs(vn(k)))
          end do
          rtol_dyn = max(GA_RTOL * fmax, 100 * epsilon(one) * (kmax * qmax + cmax * vmax))
          ! joint friction mu N(lambda): lambda_{n+1} carries the rounding of q amplified by
          ! b' (above), and so does the friction it loads
          if (mufric > zero) rtol_dyn = max(rtol_dyn, 100 * epsilon(one) * mufric * bp * &
                                            maxval(m%mdiag) * qmax)
          do k = 1, na
            res(n + k) = bp * w%phi(w%rows(k))
            if (.not. abs(res(n + k)) <= huge(one)) finite = .false.
          end do
          ! (not below the rounding of q: a tolerance tighter than that asks a correction
          ! no iteration can give)
          dtol = max(1.0e-3_wp * (c%opts%atol + c%opts%rtol * qmax), 100 * epsilon(one) * qmax)
          if (it > 1 .and. finite .and. maxval(abs(w%phi)) <= w%tol .and. &
              maxval(abs(dq)) <= dtol .and. rmax <= rtol_dyn) then
            conv = .true.; exit
          end if
          ! converged to the rounding: with fresh K and C the corrections no longer contract
          ! and stay below the step's error tolerance (a long chain's conditioning puts that
          ! rounding above dtol at tight tolerances: N-four-bar N = 300 at rtol 1e-12 stalled
          ! at 1.6x dtol, N = 3000 at 17x, and the fixed step failed)
          if (it > 3 .and. nkc > 0 .and. finite .and. maxval(abs(w%phi)) <= w%tol .and. &
              rmax <= rtol_dyn .and. dqp >= GA_RHO * dqpp .and. &
              dqp <= c%opts%atol + c%opts%rtol * qmax) then
            conv = .true.; exit
          end if
          if (.not. finite) exit
          if (it == GA_SLOW .and. nkc < 2) new_kc = .true.
          if (it == 1 .or. new_kc) then
            if (.not. have_kc .or. new_kc) call tangent()
            call factor_s(stt)
            if (stt /= MBD_OK) exit
          end if
          res = -res
          call saddle_solve(sg, res, stt)
          dq = res(1:n)
          qn = qn + dq
          vn = vn + gp * dq
          an = an + bp * dq
          do k = 1, na
            lamn(w%rows(k)) = lamn(w%rows(k)) + bp * res(n + k)
          end do
          c%st%newton = c%st%newton + 1
          ! slow contraction (above the roundoff of q): new K, C next iteration
          dqn = maxval(abs(dq))
          if (dqn > GA_RHO * dqp .and. dqn > 100 * epsilon(one) * maxval(abs(qn)) .and. &
              nkc < 2) new_kc = .true.
          dqpp = dqp; dqp = dqn
        end do
        if (conv .or. nkc > 0) exit
        new_kc = .true.                 ! failed with old K, C: retry with fresh ones
      end do
      ! local error estimate: the step's position error is (beta - 1/6) h^3 q''', and the
      ! distance of q_{n+1} from its second-order Taylor prediction is h^3 q'''/6, so
      ! e = (6 beta - 1) (q_{n+1} - q_n - h q_dot_n - h^2 q_ddot_n / 2)
      ne = 0; esq = zero
      if (conv .and. present(hook)) then
        coef(5:6) = [bp, gp]
        call hook%step(m, w, sg, tnew, h, coef, qn, vn, an, lamn, c%opts%rtol, c%opts%atol, &
                       esq, ne, stt)
        if (stt == MBD_NO_CONVERGENCE) then   ! (slow with an old K, C: fresh ones at qn)
          call tangent()
          call factor_s(stt)
          if (stt == MBD_OK) call hook%step(m, w, sg, tnew, h, coef, qn, vn, an, lamn, &
                                            c%opts%rtol, c%opts%atol, esq, ne, stt)
        end if
        if (stt /= MBD_OK) then
          status = MBD_INTEGRATOR_FAILED
          write (msg, '(a,es12.5,a)') 'the sensitivities of the step could not be solved at '// &
            't = ', tnew, ' (the iteration matrix does not converge them): take a smaller h, '// &
            'or integrate them by dopri5'
          return
        end if
      end if
      if (conv .and. .not. fixed) then
        ew = (6 * bet - 1) * (qn - q - h * qd - half * h * h * qdd)   ! (no heap temporary)
        err = err_norm(c, ew, q, qn)
        ! with a hook: the RMS over the state's and the hook's components
        if (ne > 0) err = sqrt((err * err * n + esq) / (n + ne))
      end if
      kev = 0
      if (conv .and. c%events) then
        ! an event inside the step: error-controlled steps are taken again to end there
        call events_find(m, w, t, q, qd, qdd, tnew, qn, vn, an, te, kev, stt)
        if (stt /= MBD_OK) then
          call event_failure(c, tnew, status, msg); return
        end if
        if (kev > 0 .and. .not. fixed .and. te < tnew - event_tol(t, tnew)) then
          c%st%rejected = c%st%rejected + 1
          h = te - t
          cycle
        end if
      end if
      if (.not. conv .or. (.not. fixed .and. err > one)) then
        c%st%rejected = c%st%rejected + 1
        if (fixed) then
          status = MBD_INTEGRATOR_FAILED
          write (msg, '(a,es12.5,a,es10.3,a)') 'Newton did not converge at t = ', &
            tnew, ' with the fixed step h = ', h, ': take a smaller h, or leave h out '// &
            'for error-controlled steps'
          return
        end if
        if (conv) then
          h = h * max(0.2_wp, 0.9_wp * err**(-one / 3))
        else
          h = h / 4
        end if
        if (h < 1.0e-14_wp * max(one, abs(t))) then
          call underflow(m, w, t, status, msg); return
        end if
        cycle
      end if
      accn = accn + (1 - af) / (1 - am) * an
      nprev = c%nout
      call emit(c, qo, vo, ao, t, q, qd, qdd, tnew, qn, vn, an)
      call save_modes(w, c, nprev + 1)
      if (present(hook)) then
        do i = nprev + 1, c%nout
          call hook%emit(i, out_time(c, output_index(c%nsteps, c%every, i)), t, tnew)
        end do
        call hook%commit()
      end if
      c%st%steps = c%st%steps + 1
      c%st%hmin = min(c%st%hmin, h); c%st%hmax = max(c%st%hmax, h)
      if (stopped(c, tnew, status, msg, ctl)) then
        c%qf = qn; c%vf = vn; c%af = an; c%lam = lamn
        return
      end if
      t = tnew; q = qn; qd = vn; qdd = an; acc = accn; lam = lamn
      if (kev > 0) then
        ! change the modes; restart from the accelerations of the new modes
        call events_switch(m, w, t, q, qd, c%log, changed, stt, trec=te)
        if (stt == MBD_OK .and. changed) then
          call dyn_accel(m, w, q, qd, t, qdd, lam, stt)
          acc = qdd; hprev = zero
        end if
        if (stt /= MBD_OK) then
          call event_failure(c, t, status, msg); return
        end if
      end if
      if (.not. fixed) then
        facc = min(1.5_wp, max(0.2_wp, 0.8_wp * max(err, 1.0e-10_wp)**(-one / 3)))
        h = h * facc
      end if
    end do
    c%qf = q; c%vf = qd; c%af = qdd; c%lam = lam
  contains

    !> K and C by differences at (qn, vn) (dyn_tangent), and the blocks at qn again.
    subroutine tangent()
      call dyn_tangent(m, w, qn, vn, tnew, lamn, kv, cv, fast=.true.)
      c%st%jacobians = c%st%jacobians + 1
      have_kc = .true.; new_kc = .false.; nkc = nkc + 1
      kmax = zero; cmax = zero
      if (nnz > 0) then
        kmax = maxval(abs(kv)); cmax = maxval(abs(cv))
      end if
      call assemble_blocks(m, qn, vn, tnew, w%phi, w%nu, w%gam, w%asm)
    end subroutine tangent

    !> S with the current J: K + g' C on the pattern, + M b' on the diagonal, b' J; factored.
    subroutine factor_s(stf)
      integer, intent(out) :: stf
      integer :: kk, ii
      do kk = 1, nnz
        kc(kk) = kv(kk) + gp * cv(kk)
      end do
      do kk = 1, n
        dg(kk) = m%mdiag(kk) * bp
      end do
      if (diagk) then                 ! K + g' C on the diagonal: A = diag(dg)
        do kk = 1, n
          do ii = w%kptr(kk), w%kptr(kk + 1) - 1
            dg(kk) = dg(kk) + kc(ii)
          end do
        end do
        call saddle_factor(sg, dg, w%asm%jb, bp, stf, schur=.true.)
        if (sg%schur) c%st%schur = c%st%schur + 1
      else
        call saddle_factor(sg, dg, w%asm%jb, bp, stf, kv=kc)
      end if
      c%st%factorizations = c%st%factorizations + 1
    end subroutine factor_s
  end subroutine run_genalpha

  ! -------------------------------------------------------------------- explicit methods
  subroutine run_explicit(m, w, c, partitioned, qo, vo, ao, status, msg, ctl)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    logical, intent(in) :: partitioned
    real(wp), intent(inout) :: qo(:, :), vo(:, :), ao(:, :)
    integer, intent(out) :: status
    character(len=MSG_LEN), intent(out) :: msg
    integer, intent(inout), optional, volatile :: ctl(:)   !! progress (see integrate)
    real(wp), allocatable :: y(:), ynew(:), k(:, :), e(:), ys(:)   ! ys: a stage's state
    real(wp) :: t, h, tnew, err, fac, qa(m%nq), va(m%nq), aa(m%nq), te, dev, move
    real(wp) :: al(m%nq), ar(m%nq)           ! a step ending on a breakpoint: left, right q_ddot
    real(wp) :: qr(m%nq), vr(m%nq)           ! (and the state there: partitioned solves it again)
    integer :: stt, nprev, kev
    logical :: fixed, fsal, changed, land
    logical :: to_event                      ! the step is taken again to end at an event
    integer :: nfix, kgrid                   ! fixed steps: their number, the grid times passed
    integer :: hits, calm                    ! stiffness_test's counters
    logical :: stiff
    status = MBD_OK; msg = ''
    hits = 0; calm = 0
    c%baumgarte = c%opts%method == METH_RK4
    if (partitioned) then
      call partition(m, w, c, c%t0, stt)
      if (stt /= MBD_OK) then
        status = stt; msg = 'partitioned: cannot choose independent coordinates'
        if (stt == MBD_NO_MEMORY) msg = 'not enough memory for the partition (QR of J)'
        return
      end if
    end if
    fixed = c%opts%method == METH_RK4
    t = c%t0
    nfix = 0
    if (fixed) then
      nfix = fixed_steps(c)
      if (nfix > c%opts%max_steps) then
        call step_limit(c, t, nfix, status, msg); return
      end if
      h = (c%t1 - c%t0) / nfix
    else
      h = initial_step(c)
    end if
    call pack_state(c, y, ynew, k, e, ys, stt)
    if (stt /= 0) then
      call mem_fail(REAL_BYTES * 10 * size(c%qf), 'the integrator stages', &
                    'use a smaller model', status, msg)
      return
    end if
    fsal = .false.
    qa = c%qf; va = c%vf; aa = c%af          ! the state at the start of the step
    c%qs = qa; c%vs = va; c%as = aa; c%ts = t
    err = zero
    kgrid = 0
    to_event = .false.
    do while (merge(kgrid < nfix, more(c, t, fixed, nfix), fixed))
      if (c%st%steps + c%st%rejected >= c%opts%max_steps) then
        call step_limit(c, t, 0, status, msg); return
      end if
      c%st%t_fail = t
      h = min(h, c%t1 - t)
      tnew = t + h
      if (fixed) then
        tnew = step_time(c, kgrid + 1, nfix)
        call grid_break(m, c, t, nfix, tnew, land)
        h = tnew - t
      else
        call break_step(m, t, c%t1, h, tnew, land, to_event)
      end if
      if (fixed .and. land) then
        call rk4_step(m, w, c, t, y, h, ynew, k, ys, fsal, stt, nearest(tnew, -one))
        err = zero
      else if (fixed) then
        call rk4_step(m, w, c, t, y, h, ynew, k, ys, fsal, stt)
        err = zero
      else if (land) then
        ! (the stages at the breakpoint from the left: the functions give their right
        ! limits there, which belong to the next step, whose first stage is taken at tb)
        call dopri5_step(m, w, c, t, y, h, ynew, k, e, ys, fsal, stt, nearest(tnew, -one))
        if (stt == MBD_OK) err = err_norm(c, e, y, ynew)
      else
        call dopri5_step(m, w, c, t, y, h, ynew, k, e, ys, fsal, stt)
        if (stt == MBD_OK) err = err_norm(c, e, y, ynew)
      end if
      if (stt == MBD_OK .and. partitioned) then
        ! the dependent coordinates are outside the error estimate: reject a step that
        ! moved them off their Taylor prediction (a switch of branch at a singular point)
        call rhs(m, w, c, tnew, ynew, e, stt)
        if (stt == MBD_OK) then
          call prediction_gaps(c, tnew, dev, move)
          if (dev > half * move + 1.0e3_wp * w%tol) err = 10.0_wp
        end if
        fsal = .false.
      end if
      if (stt /= MBD_OK .or. .not. all(ieee_is_finite(ynew))) then
        if (fixed) then
          status = MBD_INTEGRATOR_FAILED
          write (msg, '(a,es12.5,a)') 'the solution blew up or the equations became singular '// &
            'at t = ', t, ' (try a smaller step)'
          return
        end if
        err = 10.0_wp
      else if (c%events .and. .not. fixed) then
        ! an event inside the trial step (its end state is the last stage's): take the step
        ! again to end at the event, whatever its error (the modes, and so the forces, are
        ! fixed within a step: the part before the event is smooth)
        call events_find(m, w, t, qa, va, aa, tnew, c%qf, c%vf, c%af, te, kev, stt)
        if (stt /= MBD_OK) then
          err = 10.0_wp
        else if (kev > 0 .and. te < tnew - event_tol(t, tnew)) then
          c%st%rejected = c%st%rejected + 1
          h = te - t; fsal = .false.; to_event = .true.
          cycle
        end if
      end if
      if (err > one) then
        c%st%rejected = c%st%rejected + 1
        fsal = .false.
        h = h * max(0.2_wp, 0.9_wp * err**(-0.2_wp))
        if (h < 1.0e-14_wp * max(one, abs(t))) then
          call underflow(m, w, t, status, msg); return
        end if
        cycle
      end if
      if (.not. fixed .and. c%st%t_stiff >= huge(one)) then
        call stiffness_test(c%st%steps, h, k, ynew, ys, hits, calm, stiff)
        if (stiff) c%st%t_stiff = tnew
      end if
      ! accepted: the full state at the end, projected (dopri5) or completed (partitioned)
      call finish_step(m, w, c, partitioned, tnew, ynew, fsal, e, ys, stt)
      if (stt /= MBD_OK) then
        status = MBD_INTEGRATOR_FAILED
        write (msg, '(a,es12.5)') 'the constraints could not be satisfied after the ' // &
          'step to t = ', tnew
        call friction_hint(m, w, msg)
        return
      end if
      if (c%opts%method == METH_DOPRI5 .or. c%opts%method == METH_RK4 .or. partitioned) then
        ! y' at the new (dopri5: projected) state, finish_step's in e, is the next step's
        ! first stage
        k(:, 1) = e; fsal = .true.
      end if
      if (c%baumgarte) then
        ! an unstable run shows first as growing constraint violation
        if (maxval(abs(w%phi)) > 1.0e-3_wp * m%lscale) then
          status = MBD_INTEGRATOR_FAILED
          write (msg, '(a,es10.3,a,es12.5,a)') 'the constraint violation reached ', &
            maxval(abs(w%phi)), ' at t = ', tnew, ': unstable (a smaller step h, or '// &
            'smaller Baumgarte alpha and beta)'
          c%st%t_fail = tnew
          return
        end if
      end if
      kev = 0
      if (c%events) then
        ! events of the accepted step (fixed steps: at its end; adaptive: at most at its end)
        call events_find(m, w, t, qa, va, aa, tnew, c%qf, c%vf, c%af, te, kev, stt)
        if (stt /= MBD_OK) then
          call event_failure(c, tnew, status, msg); return
        end if
      end if
      nprev = c%nout
      if (land) then
        ! the step's interpolant ends with the left limit of q_ddot at the breakpoint (the
        ! functions give the right one there, the next step's start and an output at tb)
        ar = c%af; qr = c%qf; vr = c%vf
        call rhs(m, w, c, nearest(tnew, -one), ynew, ys, stt)
        al = c%af; c%af = ar; c%qf = qr; c%vf = vr
        if (stt /= MBD_OK) al = ar
        call emit(c, qo, vo, ao, t, qa, va, aa, tnew, c%qf, c%vf, c%af, al)
      else
        call emit(c, qo, vo, ao, t, qa, va, aa, tnew, c%qf, c%vf, c%af)
      end if
      if (partitioned) call complete_outputs(m, w, c, qo, vo, nprev + 1)
      call save_modes(w, c, nprev + 1)
      if (kev > 0) then
        ! change the modes at the end of the step (located time recorded) and restart
        call events_switch(m, w, tnew, c%qf, c%vf, c%log, changed, stt, trec=te)
        if (stt == MBD_OK .and. changed) then
          if (partitioned) then
            ynew(1:c%ni) = c%qf(c%iv); ynew(c%ni + 1:) = c%vf(c%iv)
          else
            ynew(1:m%nq) = c%qf; ynew(m%nq + 1:) = c%vf
          end if
          call accel(m, w, c, tnew, stt)
          fsal = .false.
        end if
        if (stt /= MBD_OK) then
          call event_failure(c, tnew, status, msg); return
        end if
      end if
      qa = c%qf; va = c%vf; aa = c%af
      c%qs = qa; c%vs = va; c%as = aa; c%ts = tnew
      if (fixed) call grid_passed(c, nfix, tnew, land, kgrid)
      to_event = .false.
      c%st%steps = c%st%steps + 1
      c%st%hmin = min(c%st%hmin, h); c%st%hmax = max(c%st%hmax, h)
      if (stopped(c, tnew, status, msg, ctl)) return
      t = tnew
      y = ynew
      if (.not. fixed) then
        fac = min(5.0_wp, max(0.2_wp, 0.9_wp * max(err, 1.0e-10_wp)**(-0.2_wp)))
        h = h * fac
      end if
      if (partitioned) then
        if (needs_partition(m, w, c, t)) then
          call partition(m, w, c, t, stt)
          if (stt /= MBD_OK) then
            status = MBD_INTEGRATOR_FAILED
            write (msg, '(a,es12.5)') 'partitioned: no well-conditioned partition at t = ', t
            return
          end if
          call pack_state(c, y, ynew, k, e, ys, stt)
          if (stt /= 0) then
            call mem_fail(REAL_BYTES * 10 * size(c%qf), 'the integrator stages', &
                          'use a smaller model', status, msg)
            return
          end if
          fsal = .false.
        end if
      end if
    end do
  end subroutine run_explicit

  !> An adaptive step from t of size h (ending at t1 at the latest) that would cross a
  !! breakpoint of the drivers' or forces' functions of time, where q_ddot may jump, or end
  !! within a tenth of a step of it, ends on it (h and tnew shortened, land): no rejections
  !! shrinking the step onto the kink. The step's stages at the breakpoint are to take the
  !! functions' left limits (the double just below it). A step taken again to end at an
  !! event (to_event) is not lengthened: the breakpoint beyond would cross the event again.
  pure subroutine break_step(m, t, t1, h, tnew, land, to_event)
    type(model_t), intent(in) :: m              !! model with dynamics data
    real(wp), intent(in) :: t, t1               !! the step's start, the run's end
    real(wp), intent(inout) :: h, tnew          !! the step and its end (t + h)
    logical, intent(out) :: land                !! the step ends on a breakpoint
    logical, intent(in), optional :: to_event   !! h ends on an event: only shortened
    real(wp) :: tb, reach
    reach = 1.1_wp
    if (present(to_event)) then
      if (to_event) reach = one
    end if
    tb = break_after(m, t, h)
    land = tb <= t1 .and. t + reach * h >= tb
    if (land) then
      h = tb - t; tnew = tb
    end if
  end subroutine break_step

  !> The first breakpoint of the drivers' and forces' functions of time after t by more than
  !! 1e-9 h (two breakpoints apart by rounding are one: no step of the rounding's size).
  pure real(wp) function break_after(m, t, h) result(tb)
    type(model_t), intent(in) :: m              !! model with dynamics data
    real(wp), intent(in) :: t, h                !! the time, the step
    tb = model_next_break(m, t, .true.)
    do while (tb - t <= 1.0e-9_wp * h)
      tb = model_next_break(m, tb, .true.)
    end do
  end function break_after

  !> A fixed step from t to the grid time tnew ends instead on a breakpoint of the drivers'
  !! and forces' functions of time inside it, or after it by less than GRID_MERGE steps
  !! (the next step then runs to the first grid time GRID_MERGE steps beyond: no step
  !! shorter than that but where two breakpoints are closer). A breakpoint at t1 (to
  !! rounding) is landed on; one closer to t1 than GRID_MERGE steps is stepped over.
  pure subroutine grid_break(m, c, t, nfix, tnew, land)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(itg_t), intent(in) :: c                !! the run (t0, t1)
    real(wp), intent(in) :: t                   !! the step's start
    integer, intent(in) :: nfix                 !! the fixed steps
    real(wp), intent(inout) :: tnew             !! the step's end: a grid time, or tb
    logical, intent(out) :: land                !! the step ends on a breakpoint
    real(wp) :: hn, tb
    hn = (c%t1 - c%t0) / nfix
    tb = break_after(m, t, hn)
    land = tb <= tnew + GRID_MERGE * hn
    if (.not. land) return
    if (abs(tb - c%t1) <= 4 * spacing(abs(c%t1)) + 1.0e-14_wp * hn) then
      tnew = c%t1
    else if (tb < c%t1 - GRID_MERGE * hn) then
      tnew = tb
    else
      land = .false.
    end if
  end subroutine grid_break

  !> After a fixed step to tb: kgrid counts the grid time it ended on or, when it landed on a
  !! breakpoint, every grid time up to tb + GRID_MERGE steps (those the step passed or made
  !! too close to take).
  pure subroutine grid_passed(c, nfix, tb, land, kgrid)
    type(itg_t), intent(in) :: c
    integer, intent(in) :: nfix
    real(wp), intent(in) :: tb
    logical, intent(in) :: land
    integer, intent(inout) :: kgrid
    real(wp) :: hn
    if (.not. land) then
      kgrid = kgrid + 1; return
    end if
    hn = (c%t1 - c%t0) / nfix
    if (tb >= c%t1) kgrid = nfix
    do while (kgrid < nfix)
      if (step_time(c, kgrid + 1, nfix) > tb + GRID_MERGE * hn) exit
      kgrid = kgrid + 1
    end do
  end subroutine grid_passed

  !> The integrated state y from the full state: (q, q_dot), or (v, v_dot) when partitioned.
  subroutine pack_state(c, y, ynew, k, e, ys, ierr)
    type(itg_t), intent(in) :: c
    real(wp), allocatable, intent(inout) :: y(:), ynew(:), k(:, :), e(:), ys(:)
    integer, intent(out) :: ierr          ! allocation status (0 ok)
    integer :: ny, nh
    nh = size(c%qf)
    if (c%ni > 0) nh = c%ni
    ny = 2 * nh
    if (allocated(y)) deallocate (y, ynew, k, e, ys)
    allocate (y(ny), ynew(ny), k(ny, 7), e(ny), ys(ny), stat=ierr)
    if (ierr /= 0) return
    if (c%ni > 0) then
      y(1:nh) = c%qf(c%iv); y(nh + 1:) = c%vf(c%iv)
    else
      y(1:nh) = c%qf; y(nh + 1:) = c%vf
    end if
  end subroutine pack_state

  !> After an accepted step: the full consistent state at tn in c (dopri5: projected).
  subroutine finish_step(m, w, c, partitioned, tn, yn, fsal, f, ys, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    logical, intent(in) :: partitioned
    real(wp), intent(in) :: tn
    real(wp), intent(inout) :: yn(:)
    logical, intent(inout) :: fsal
    real(wp), intent(inout) :: f(:)               !! y' at (tn, yn) (partitioned without
                                                  !! events: already, from the step's check)
    real(wp), intent(inout) :: ys(:)              !! workspace (size(yn))
    integer, intent(out) :: stf
    if (partitioned) then
      ! solves u, u_dot and the accelerations; without events the step's check of the
      ! dependent coordinates has just done so at this state (f and c%qf, c%vf, c%af hold it)
      stf = MBD_OK
      if (c%events) call rhs(m, w, c, tn, yn, f, stf)
      return
    end if
    c%qf = yn(1:m%nq); c%vf = yn(m%nq + 1:)
    stf = MBD_OK
    if (c%opts%method == METH_DOPRI5) then
      call dyn_project_pos(m, w, c%qf, tn, stf)
      ys(1:m%nq) = c%vf                          ! the velocity before its projection
      if (stf == MBD_OK) call dyn_velocity(m, w, c%qf, tn, ys(1:m%nq), c%vf, stf)
      yn(1:m%nq) = c%qf; yn(m%nq + 1:) = c%vf
      fsal = .false.
    end if
    if (stf == MBD_OK) call rhs(m, w, c, tn, yn, f, stf)
  end subroutine finish_step

  !> y' = f(t, y). Full: y = (q, q_dot). Partitioned: y = (v, v_dot) and the dependent
  !! coordinates are solved here. Leaves the full state in c%qf, c%vf, c%af.
  subroutine rhs(m, w, c, t, y, f, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t, y(:)
    real(wp), intent(out) :: f(:)
    integer, intent(out) :: stf
    integer :: nn, k
    c%st%rhs = c%st%rhs + 1
    nn = m%nq
    if (c%ni > 0) then
      ! (loops: vector subscripts and an array function would be heap temporaries per call)
      do k = 1, c%ni
        c%qf(c%iv(k)) = y(k)
      end do
      if (allocated(c%qs)) call predict_dependent(c, t)   ! Newton starts on the branch
      call solve_dependent(m, w, c, t, y(c%ni + 1:), stf)
      if (stf /= MBD_OK) return
    else
      c%qf = y(1:nn); c%vf = y(nn + 1:)
    end if
    call accel(m, w, c, t, stf)
    if (stf /= MBD_OK) return
    if (c%ni > 0) then
      do k = 1, c%ni
        f(k) = c%vf(c%iv(k)); f(c%ni + k) = c%af(c%iv(k))
      end do
    else
      f(1:nn) = c%vf; f(nn + 1:) = c%af
    end if
  end subroutine rhs

  !> Taylor prediction of the dependent coordinates at t from the step's start state,
  !! u = u_s + dt (u_dot_s + dt/2 u_ddot_s), into c%qf.
  pure subroutine predict_dependent(c, t)
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t
    real(wp) :: dt
    integer :: k, i
    dt = t - c%ts
    do k = 1, size(c%iu)
      i = c%iu(k)
      c%qf(i) = c%qs(i) + dt * (c%vs(i) + half * dt * c%as(i))
    end do
  end subroutine predict_dependent

  !> dev = max |u - u_pred(t)| (the dependent coordinates against their Taylor prediction)
  !! and move = max |u_pred(t) - u_s| (the predicted motion).
  pure subroutine prediction_gaps(c, t, dev, move)
    type(itg_t), intent(in) :: c
    real(wp), intent(in) :: t
    real(wp), intent(out) :: dev, move
    real(wp) :: dt, u
    integer :: k, i
    dt = t - c%ts
    dev = zero; move = zero
    do k = 1, size(c%iu)
      i = c%iu(k)
      u = c%qs(i) + dt * (c%vs(i) + half * dt * c%as(i))
      dev = max(dev, abs(c%qf(i) - u)); move = max(move, abs(u - c%qs(i)))
    end do
  end subroutine prediction_gaps

  !> Accelerations at c's full state; Baumgarte-stabilized for RK4.
  subroutine accel(m, w, c, t, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t
    integer, intent(out) :: stf
    call accel_at(m, w, c%opts, c%qf, c%vf, t, c%af, c%lam, stf)
  end subroutine accel

  !> Accelerations and multipliers (active rows) of the index-1 equations at a state:
  !! [M J^T; J 0][q_ddot; lambda] = [Q; gamma]; for baumgarte-rk4 the stabilized
  !! J q_ddot = gamma - 2 alpha (J q_dot - nu) - beta^2 Phi (lam then is the plain one).
  subroutine accel_at(m, w, opts, q, qd, t, qdd, lam, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(dyn_opts_t), intent(in) :: opts
    real(wp), intent(in) :: q(:), qd(:), t
    real(wp), intent(out) :: qdd(:), lam(:)
    integer, intent(out) :: stf
    integer :: nn, k, r
    call dyn_accel(m, w, q, qd, t, qdd, lam, stf)
    if (stf /= MBD_OK .or. opts%method /= METH_RK4) return
    nn = m%nq
    call dyn_jv(m, w, qd)                     ! J q_dot from the blocks (no dense J)
    w%rhs(1:nn) = w%force
    do k = 1, w%na
      r = w%rows(k)
      w%rhs(nn + k) = w%s * (w%gam(r) - two * opts%balpha * (w%jv(r) - w%nu(r)) - &
                             opts%bbeta**2 * w%phi(r))
    end do
    call dyn_solve(w, w%rhs, stf)
    qdd = w%rhs(1:nn)
  end subroutine accel_at

  !> partitioned: the outputs r0 .. c%nout just interpolated keep their independent
  !! (v, v_dot), and the dependent (u, u_dot) are solved from them as at a stage, so every
  !! output is a consistent state whose error is that of v's interpolant. An output where
  !! the solve fails keeps the interpolant.
  subroutine complete_outputs(m, w, c, qo, vo, r0)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(inout) :: qo(:, :), vo(:, :)
    integer, intent(in) :: r0
    integer :: r, stt, newton, k
    c%qkeep = c%qf; c%vkeep = c%vf; newton = c%st%newton
    do r = r0, c%nout
      c%qf = qo(:, r); c%vf = vo(:, r)
      do k = 1, c%ni
        c%vw(k) = vo(c%iv(k), r)
      end do
      call solve_dependent(m, w, c, out_time(c, output_index(c%nsteps, c%every, r)), &
                           c%vw, stt)
      if (stt == MBD_OK) then
        qo(:, r) = c%qf; vo(:, r) = c%vf
      end if
    end do
    c%qf = c%qkeep; c%vf = c%vkeep; c%st%newton = newton
  end subroutine complete_outputs

  !> Dependent coordinates u from Phi(u, v) = 0 (Newton with J_u), then u_dot from
  !! J_u u_dot = nu - J_v v_dot. J_u is dense, or in band storage on the band path (its
  !! plan made by partition).
  subroutine solve_dependent(m, w, c, t, vdot, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t, vdot(:)
    integer, intent(out) :: stf
    integer :: it, k, j
    real(wp) :: acc
    character(len=MSG_LEN) :: lmsg
    stf = MBD_OK
    ! (loops throughout: vector subscripts would be heap temporaries at every call)
    if (w%na == 0) then
      call put_v(); return
    end if
    if (w%solver /= SOLVER_DENSE) then
      call solve_dependent_band()
      return
    end if
    do it = 1, 25
      call assemble_dense(m, c%qf, w%qz, t, w%phi, w%nu, w%gam, w%asm, w%jac)
      do j = 1, w%na
        do k = 1, w%na
          c%ju(k, j) = w%jac(w%rows(k), c%iu(j))
        end do
      end do
      call lu_factor(c%ju, c%upiv, stf, lmsg)
      if (stf /= MBD_OK) return
      if (maxval(abs(w%phi)) <= w%tol) exit
      do k = 1, w%na
        c%ub(k) = -w%phi(w%rows(k))
      end do
      call lu_solve(c%ju, c%upiv, c%ub, stf, lmsg)
      do k = 1, w%na
        c%qf(c%iu(k)) = c%qf(c%iu(k)) + c%ub(k)
      end do
      c%st%newton = c%st%newton + 1
    end do
    if (maxval(abs(w%phi)) > w%tol) then
      stf = MBD_NO_CONVERGENCE; return
    end if
    call put_v()
    do k = 1, w%na
      acc = zero
      do j = 1, c%ni
        acc = acc + w%jac(w%rows(k), c%iv(j)) * vdot(j)
      end do
      c%ub(k) = w%nu(w%rows(k)) - acc
    end do
    call lu_solve(c%ju, c%upiv, c%ub, stf, lmsg)
    do k = 1, w%na
      c%vf(c%iu(k)) = c%ub(k)
    end do
  contains
    !> v_dot into the full velocity.
    subroutine put_v()
      do k = 1, c%ni
        c%vf(c%iv(k)) = vdot(k)
      end do
    end subroutine put_v
    !> The same with J_u in band storage, J_v v_dot from the blocks (no dense J).
    subroutine solve_dependent_band()
      do it = 1, 25
        call assemble_blocks(m, c%qf, w%qz, t, w%phi, w%nu, w%gam, w%asm)
        call band_zero(c%bu)
        call scatter_add(c%bu%ab, size(c%bu%ab), c%upos, c%usrc, w%asm%jb, size(w%asm%jb))
        call band_factor(c%bu, stf, lmsg)
        if (stf /= MBD_OK) return
        if (maxval(abs(w%phi)) <= w%tol) exit
        do k = 1, w%na
          c%ub(k) = -w%phi(w%rows(k))
        end do
        call band_solve(c%bu, c%ub, stf, lmsg)
        do k = 1, w%na
          c%qf(c%iu(k)) = c%qf(c%iu(k)) + c%ub(k)
        end do
        c%st%newton = c%st%newton + 1
      end do
      if (maxval(abs(w%phi)) > w%tol) then
        stf = MBD_NO_CONVERGENCE; return
      end if
      call put_v()
      c%px = zero                                ! J_v v_dot = J x, x = v_dot on v, 0 on u
      do k = 1, c%ni
        c%px(c%iv(k)) = vdot(k)
      end do
      call dyn_jv(m, w, c%px)
      do k = 1, w%na
        c%ub(k) = w%nu(w%rows(k)) - w%jv(w%rows(k))
      end do
      call band_solve(c%bu, c%ub, stf, lmsg)
      do k = 1, w%na
        c%vf(c%iu(k)) = c%ub(k)
      end do
    end subroutine solve_dependent_band
  end subroutine solve_dependent

  !> f(pos(i)) += jb(src(i)) over flat (column-major) views.
  pure subroutine scatter_add(f, nf, pos, src, jb, nj)
    integer, intent(in) :: nf, nj
    real(wp), intent(inout) :: f(nf)
    integer, intent(in) :: pos(:), src(:)
    real(wp), intent(in) :: jb(nj)
    integer :: i
    do i = 1, size(pos)
      f(pos(i)) = f(pos(i)) + jb(src(i))
    end do
  end subroutine scatter_add

  !> Choose the dependent coordinates u and the independent v.
  !! Dense path: u = the first na columns of a QR with column pivoting of J (the
  !! best-conditioned block J_u), v the rest.
  !! Band path (a QR of J would cost O(n^3)): v = the ni coordinates a pivoted Gram-Schmidt
  !! picks from the rows of N, an orthonormal basis of the null space of J
  !! (dyn_null_basis, linear in n). The motion the constraints allow is N z; with v = N_v z
  !! the dependent velocities are u_dot = N_u N_v^-1 v_dot (= -J_u^-1 J_v v_dot), so a good
  !! v makes N_v well conditioned (|det J_u| = |det N_v| vol(J) for orthonormal N: the same
  !! aim as the QR's), and the pivoting takes, one at a time, the coordinate along which the
  !! allowed motion not yet covered is largest; both sets in increasing order, and the band
  !! plan of J_u is made here.
  subroutine partition(m, w, c, t, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t
    integer, intent(out) :: stf
    integer :: ni, k, j, i
    character(len=MSG_LEN) :: lmsg
    ni = m%nq - w%na
    call partition_work(m, w, c, stf)
    if (stf /= MBD_OK) return
    if (w%solver == SOLVER_DENSE) then
      call qr_choice(m, w, c, t, c%jp, stf)
      if (stf /= MBD_OK) return
      c%iu = c%jp(1:w%na)
      c%iv = c%jp(w%na + 1:)
      c%ni = ni
      c%st%partitions = c%st%partitions + 1
      return
    end if
    call dyn_null_basis(m, w, c%qf, t, c%nb, stf)
    if (stf /= MBD_OK) return
    call select_coordinates(c, m%nb, c%sel)
    c%mark = 0
    c%mark(c%sel) = 1
    k = 0; j = 0
    do i = 1, m%nq
      if (c%mark(i) == 1) then
        k = k + 1; c%iv(k) = i
      else
        j = j + 1; c%iu(j) = i
      end if
    end do
    c%ni = ni
    c%st%partitions = c%st%partitions + 1
    call plan_ju(m, w, c, stf, lmsg)
  end subroutine partition

  !> Dense path: the column order jp of a QR with column pivoting of J (rows active) at the
  !! current state.
  subroutine qr_choice(m, w, c, t, jp, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t
    integer, intent(out) :: jp(:)
    integer, intent(out) :: stf
    integer :: info, k
    character(len=MSG_LEN) :: lmsg
    integer :: kk
    if (w%na == 0) then                       ! free bodies: every coordinate independent
      jp = [(kk, kk=1, m%nq)]
      stf = MBD_OK; return
    end if
    call assemble_dense(m, c%qf, w%qz, t, w%phi, w%nu, w%gam, w%asm, w%jac)
    do k = 1, w%na
      c%qa(k, :) = w%jac(w%rows(k), :)
    end do
    jp = 0
    call dgeqp3(w%na, m%nq, c%qa, w%na, jp, c%tau, c%qwork, size(c%qwork), info)
    call lapack_status('dgeqp3', info, stf, lmsg)
  end subroutine qr_choice

  !> Dense path: 1/cond_1 of J(rows, cols) at the last assembly (0 when singular).
  real(wp) function rcond_cols(w, c, cols) result(rc)
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    integer, intent(in) :: cols(:)
    real(wp) :: anorm, colsum
    integer :: stf, info, k, j
    character(len=MSG_LEN) :: lmsg
    anorm = zero                          ! ||J_u||_1 (loops: no heap temporaries)
    do j = 1, w%na
      colsum = zero
      do k = 1, w%na
        c%ju(k, j) = w%jac(w%rows(k), cols(j))
        colsum = colsum + abs(c%ju(k, j))
      end do
      anorm = max(anorm, colsum)
    end do
    rc = zero
    call lu_factor(c%ju, c%upiv, stf, lmsg)
    if (stf /= MBD_OK) return
    call dgecon('1', w%na, c%ju, w%na, anorm, rc, c%cw, c%iw, info)
  end function rcond_cols

  !> The partitioned method's work arrays (the first time).
  subroutine partition_work(m, w, c, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(in) :: w
    type(itg_t), intent(inout) :: c
    integer, intent(out) :: stf
    integer :: ni, na, lw, idum(1)
    real(wp) :: wq(1), adum(1), sdum(1), udum(1), vdum(1)
    stf = MBD_OK
    if (allocated(c%iv)) return
    na = w%na; ni = m%nq - na
    call dgesvd('N', 'N', ni, ni, adum, max(ni, 1), sdum, udum, 1, vdum, 1, wq, -1, stf)
    lw = max(1, int(wq(1)), 5 * ni)
    allocate (c%iv(ni), c%iu(na), c%ub(na), c%px(m%nq), c%vw(ni), c%qkeep(m%nq), &
              c%vkeep(m%nq), stat=stf)
    if (stf == 0 .and. w%solver == SOLVER_DENSE) then
      ! J_u, the QR's copy of J and its workspace, dgecon's
      call dgeqp3(na, m%nq, adum, max(na, 1), idum, sdum, wq, -1, stf)   ! (a query)
      lw = max(1, int(wq(1)))
      allocate (c%ju(na, na), c%upiv(na), c%jp(m%nq), c%qa(na, m%nq), c%tau(min(na, m%nq)), &
                c%qwork(lw), c%cw(4 * na), c%iw(na), stat=stf)
    else if (stf == 0) then
      allocate (c%nb(m%nq, ni), c%sel(ni), c%mark(m%nq), c%gw(ni, m%nq), c%gn(m%nq), &
                c%nsq(ni, ni), c%sv(ni), c%svw(lw), stat=stf)
    end if
    if (stf /= 0) stf = MBD_NO_MEMORY
  end subroutine partition_work

  !> Greedy pivoted Gram-Schmidt on the rows of c%nb: sel(k) is the coordinate whose row,
  !! less its parts along the rows chosen before, is longest. Ties within a relative 1e-6
  !! (rounding does not decide between equal candidates) go to a body's angle, the natural
  !! coordinate of a link that turns (its x and y oscillate), the first of them.
  subroutine select_coordinates(c, nbody, sel)
    type(itg_t), intent(inout) :: c
    integer, intent(in) :: nbody             ! moving bodies (angles are 3, 6, .. 3 nbody)
    integer, intent(out) :: sel(:)
    integer :: ni, n, k, j, best
    real(wp) :: gmax, u(size(c%nb, 2)), d
    n = size(c%nb, 1); ni = size(c%nb, 2)
    c%gw = transpose(c%nb)
    do j = 1, n
      c%gn(j) = sum(c%gw(:, j)**2)
    end do
    c%mark = 0
    do k = 1, ni
      gmax = -one
      do j = 1, n
        if (c%mark(j) == 0) gmax = max(gmax, c%gn(j))
      end do
      best = 0
      do j = 1, n                      ! the first tied body angle, else the first tied one
        if (c%mark(j) == 0 .and. c%gn(j) >= (one - 1.0e-6_wp) * gmax) then
          if (best == 0) best = j
          if (j <= 3 * nbody .and. mod(j, 3) == 0) then
            best = j; exit
          end if
        end if
      end do
      sel(k) = best
      c%mark(best) = 1
      u = c%gw(:, best) / sqrt(max(c%gn(best), tiny(one)))
      do j = 1, n
        if (c%mark(j) == 1) cycle
        d = dot_product(u, c%gw(:, j))
        c%gw(:, j) = c%gw(:, j) - d * u
        c%gn(j) = sum(c%gw(:, j)**2)
      end do
    end do
  end subroutine select_coordinates

  !> The smallest singular value of N_v = nb(v, :), the rows of the coordinates v: how well
  !! the independent coordinates v describe the allowed motion (0 when they cannot).
  real(wp) function smin_rows(c, v) result(sm)
    type(itg_t), intent(inout) :: c
    integer, intent(in) :: v(:)
    integer :: k, info, ni
    real(wp) :: udum(1, 1), vdum(1, 1)
    ni = size(v)
    do k = 1, ni
      c%nsq(k, :) = c%nb(v(k), :)
    end do
    call dgesvd('N', 'N', ni, ni, c%nsq, ni, c%sv, udum, 1, vdum, 1, c%svw, size(c%svw), info)
    sm = zero
    if (info == 0 .and. ni > 0) sm = c%sv(ni)
  end function smin_rows

  !> Band path: the band plan of J_u (active rows x dependent coordinates) and the map from
  !! the constraint blocks into it.
  subroutine plan_ju(m, w, c, stf, lmsg)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(in) :: w
    type(itg_t), intent(inout) :: c
    integer, intent(out) :: stf
    character(len=MSG_LEN), intent(out) :: lmsg
    integer, allocatable :: arow(:), ucol(:), rr(:), cc(:)
    integer :: k, s, r, a, u, ne, i, ldab
    allocate (arow(m%neq), ucol(m%nq), stat=stf)
    if (stf /= 0) then
      stf = MBD_NO_MEMORY; return
    end if
    arow = 0; ucol = 0
    do k = 1, w%na
      arow(w%rows(k)) = k
      ucol(c%iu(k)) = k
    end do
    ne = 0
    do k = 1, m%nc
      do s = 1, NLOC
        if (m%loc(s, k) == 0) cycle
        if (ucol(m%loc(s, k)) == 0) cycle
        do r = 1, m%nrow(k)
          if (arow(m%row0(k) + r - 1) > 0) ne = ne + 1
        end do
      end do
    end do
    if (allocated(c%usrc)) deallocate (c%usrc, c%upos)
    allocate (rr(ne), cc(ne), c%usrc(ne), c%upos(ne), stat=stf)
    if (stf /= 0) then
      stf = MBD_NO_MEMORY; return
    end if
    ne = 0
    do k = 1, m%nc
      do s = 1, NLOC
        if (m%loc(s, k) == 0) cycle
        u = ucol(m%loc(s, k))
        if (u == 0) cycle
        do r = 1, m%nrow(k)
          a = arow(m%row0(k) + r - 1)
          if (a == 0) cycle
          ne = ne + 1
          rr(ne) = a; cc(ne) = u
          c%usrc(ne) = r + MAXROW * (s - 1 + NLOC * (k - 1))
        end do
      end do
    end do
    call band_plan(w%na, rr, cc, c%bu, stf, lmsg)
    if (stf /= MBD_OK) return
    c%bu%plain = c%bu%kl + c%bu%ku <= 64       ! narrow: plain loops (mbd_band's band_lu)
    ldab = c%bu%ldab
    do i = 1, ne
      c%upos(i) = c%bu%kl + c%bu%ku + 1 + c%bu%prow(rr(i)) - c%bu%pcol(cc(i)) + &
                  ldab * (c%bu%pcol(cc(i)) - 1)
    end do
  end subroutine plan_ju

  !> Choose again when the current partition has become REPARTITION times worse than the
  !! choice partition would make now. Dense path: J_u's 1/cond_1 against that of the QR's
  !! choice. Band path: the smallest singular value of N_v (how well v describes the
  !! allowed motion) against that of the pivoted choice. Near a singular configuration,
  !! where every choice is poor (on the band path the projection that gives N is then itself
  !! nearly singular), nothing better exists and the partition is kept.
  logical function needs_partition(m, w, c, t)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t
    real(wp) :: now, best
    integer :: stt
    needs_partition = .false.
    if (c%ni <= 0 .or. w%na == 0) return
    if (w%solver == SOLVER_DENSE) then
      call qr_choice(m, w, c, t, c%jp, stt)
      now = rcond_cols(w, c, c%iu)
      if (now < c%st%rc_min) then
        c%st%rc_min = now; c%st%t_rc_min = t
      end if
      needs_partition = now <= zero
      if (stt /= MBD_OK) return
      needs_partition = now < REPARTITION * rcond_cols(w, c, c%jp(1:w%na))
      return
    end if
    call dyn_null_basis(m, w, c%qf, t, c%nb, stt)
    if (stt /= MBD_OK .or. w%lsq) return
    now = smin_rows(c, c%iv)
    call select_coordinates(c, m%nb, c%sel)
    best = smin_rows(c, c%sel)
    needs_partition = now < REPARTITION * best
  end function needs_partition

  !> One classical Runge-Kutta step.
  subroutine rk4_step(m, w, c, t, y, h, yn, k, ys, first, stf, tend)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t, y(:), h
    real(wp), intent(out) :: yn(:)
    real(wp), intent(inout) :: k(:, :)
    real(wp), intent(inout) :: ys(:)          !! a stage's state (workspace: expressions as
                                              !! arguments would be heap temporaries)
    logical, intent(in) :: first              !! k(:, 1) = f(t, y) is known
    integer, intent(out) :: stf
    !> the last stage's time (a step ending on a breakpoint: the double below it)
    real(wp), intent(in), optional :: tend
    real(wp) :: t1
    stf = MBD_OK
    t1 = t + h
    if (present(tend)) t1 = tend
    if (.not. first) call rhs(m, w, c, t, y, k(:, 1), stf)
    if (stf /= MBD_OK) return
    ys = y + half * h * k(:, 1)
    call rhs(m, w, c, t + half * h, ys, k(:, 2), stf)
    if (stf /= MBD_OK) return
    ys = y + half * h * k(:, 2)
    call rhs(m, w, c, t + half * h, ys, k(:, 3), stf)
    if (stf /= MBD_OK) return
    ys = y + h * k(:, 3)
    call rhs(m, w, c, t1, ys, k(:, 4), stf)
    if (stf /= MBD_OK) return
    yn = y + h / 6 * (k(:, 1) + 2 * k(:, 2) + 2 * k(:, 3) + k(:, 4))
  end subroutine rk4_step

  !> The state of Dormand-Prince stage j = 2 .. 7 from y and the rates k(:, 1:j-1) of the
  !! stages before: ys = y + h sum_i a_ji k_i (j = 7: the new state, the fifth-order
  !! solution; y and ys of equal length).
  pure subroutine dopri5_state(j, y, h, k, ys)
    integer, intent(in) :: j                  !! stage
    real(wp), intent(in) :: y(:), h           !! state at the step's start, step
    real(wp), intent(in) :: k(:, :)           !! rates of the stages (at least j - 1)
    real(wp), intent(out) :: ys(:)            !! the stage's state
    select case (j)
    case (2)
      ys = y + h * A21 * k(:, 1)
    case (3)
      ys = y + h * (A31 * k(:, 1) + A32 * k(:, 2))
    case (4)
      ys = y + h * (A41 * k(:, 1) + A42 * k(:, 2) + A43 * k(:, 3))
    case (5)
      ys = y + h * (A51 * k(:, 1) + A52 * k(:, 2) + A53 * k(:, 3) + A54 * k(:, 4))
    case (6)
      ys = y + h * (A61 * k(:, 1) + A62 * k(:, 2) + A63 * k(:, 3) + A64 * k(:, 4) + &
                    A65 * k(:, 5))
    case default
      ys = y + h * (A71 * k(:, 1) + A73 * k(:, 3) + A74 * k(:, 4) + A75 * k(:, 5) + &
                    A76 * k(:, 6))
    end select
  end subroutine dopri5_state

  !> The embedded error estimate of a Dormand-Prince step: e = h sum_i e_i k_i (fifth minus
  !! fourth order, the seven stages' rates in k).
  pure subroutine dopri5_error(h, k, e)
    real(wp), intent(in) :: h                 !! step
    real(wp), intent(in) :: k(:, :)           !! rates of the seven stages
    real(wp), intent(out) :: e(:)             !! estimate
    e = h * (E1 * k(:, 1) + E3 * k(:, 3) + E4 * k(:, 4) + E5 * k(:, 5) + E6 * k(:, 6) + &
             E7 * k(:, 7))
  end subroutine dopri5_error

  !> One Dormand-Prince 5(4) step; e is the embedded error estimate. k(:, 1) is reused from
  !! the last stage of the previous step when fsal is true (first same as last).
  !> Hairer's stiffness test of DOPRI5 (Hairer and Wanner, Solving ODEs II, sec. IV.2), after
  !! an accepted step: stages 6 and 7 are both at t + h, so
  !!   h |lambda| ~ h ||f(y7) - f(y6)|| / ||y7 - y6||,
  !! and past 3.25 (the stability boundary on the negative real axis is 3.3) the step is
  !! limited by stability, not accuracy. As in Hairer's DOPRI5, the test starts at every
  !! thousandth accepted step (a short run is cheap whatever limits its steps) and goes on
  !! while it finds such steps; the fifteenth of them before six in a row below makes the
  !! run stiff from then on (stiff). Used by run_explicit and the sensitivities' dopri5.
  pure subroutine stiffness_test(steps, h, k, yn, ys, hits, calm, stiff)
    integer, intent(in) :: steps            !! accepted steps before this one
    real(wp), intent(in) :: h, k(:, :), yn(:), ys(:)   !! step, stages, y7 and y6
    integer, intent(inout) :: hits, calm    !! steps past the boundary; in a row below it
    logical, intent(out) :: stiff           !! this step made the run stiff
    integer, parameter :: NSTIFF = 1000
    real(wp) :: num, den
    integer :: i
    stiff = .false.
    if (mod(steps + 1, NSTIFF) /= 0 .and. hits == 0) return
    num = zero; den = zero
    do i = 1, size(yn)
      num = num + (k(i, 7) - k(i, 6))**2
      den = den + (yn(i) - ys(i))**2
    end do
    if (den > zero .and. h * sqrt(num) > 3.25_wp * sqrt(den)) then
      calm = 0; hits = hits + 1
      stiff = hits == 15
    else
      calm = calm + 1
      if (calm == 6) hits = 0
    end if
  end subroutine stiffness_test

  subroutine dopri5_step(m, w, c, t, y, h, yn, k, e, ys, fsal, stf, tend)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t, y(:), h
    real(wp), intent(out) :: yn(:), e(:)
    real(wp), intent(inout) :: k(:, :)
    real(wp), intent(inout) :: ys(:)          !! a stage's state (workspace)
    logical, intent(inout) :: fsal
    integer, intent(out) :: stf
    !> the time of the stages at the step's end (c = 1; default t + h): just below a
    !! breakpoint the step ends on
    real(wp), intent(in), optional :: tend
    real(wp) :: t1
    integer :: j
    stf = MBD_OK
    t1 = t + h
    if (present(tend)) t1 = tend
    if (.not. fsal) then
      call rhs(m, w, c, t, y, k(:, 1), stf)
      if (stf /= MBD_OK) return
    end if
    ! the stages' states in ys (expressions as arguments would be heap temporaries)
    do j = 2, 6
      call dopri5_state(j, y, h, k, ys)
      call rhs(m, w, c, merge(t1, t + DOPRI_C(j) * h, DOPRI_C(j) >= one), ys, k(:, j), stf)
      if (stf /= MBD_OK) return
    end do
    call dopri5_state(7, y, h, k, yn)
    call rhs(m, w, c, t1, yn, k(:, 7), stf)
    if (stf /= MBD_OK) return
    call dopri5_error(h, k, e)
    k(:, 1) = k(:, 7)
    fsal = .true.
  end subroutine dopri5_step

end module mbd_integrators
