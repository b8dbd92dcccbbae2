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
  use mbd_model, only: model_t
  use mbd_forces, only: FRC_FRICTION
  use mbd_assemble, only: assemble_dense, assemble_blocks, scatter_dense
  use mbd_linsolve, only: lu_factor, lu_solve, lapack_status, lu_factor_small, lu_solve_small
  use mbd_lapack, only: dgeqp3, dgecon
  use mbd_interp, only: hermite5
  use mbd_dynamics, only: dyn_work_t, dyn_accel, dyn_velocity, dyn_project_pos, gen_forces, &
                          kinetic_energy, dyn_tangent, dyn_solve, dyn_jt_lam, dyn_multipliers, &
                          dyn_element_outputs
  use mbd_events, only: ev_log_t, events_active, events_init, events_find, events_switch, &
                        event_tol
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: dyn_opts_t, dyn_stats_t, METH_GENALPHA, METH_DOPRI5, METH_RK4, METH_PARTITIONED
  public :: integrate, output_rows, output_index, MAX_STEPS_DEFAULT
  ! the Dormand-Prince 5(4) tableau, also used by the sensitivity integrator (mbd_sens_dynamics)
  public :: C2, C3, C4, C5, A21, A31, A32, A41, A42, A43, A51, A52, A53, A54, A61, A62, A63, &
            A64, A65, A71, A73, A74, A75, A76, E1, E3, E4, E5, E6, E7

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
    real(wp) :: hmin = huge(one), hmax = zero
    real(wp) :: t_fail = zero         !! time reached when a method failed
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
    real(wp), allocatable :: qf(:), vf(:), af(:), lam(:)   !! last full state
    real(wp) :: ts = zero                   !! start of the current step
    real(wp), allocatable :: qs(:), vs(:), as(:)          !! full state there
    logical :: events = .false.             !! contacts or stick-slip joints: track modes
    type(ev_log_t) :: log                   !! events
    real(wp), allocatable :: cso(:, :, :)   !! (NCS, nf, rows) element modes at the outputs
  end type itg_t

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

contains

  !> Integrate from the consistent state (q, qd) at t0 to t1, with outputs at
  !! t0 + k (t1 - t0)/nsteps, k = 0..nsteps, of which those with mod(k, every) = 0 and the
  !! last (k = nsteps) are written into the columns of qo, vo, ao, lo (output_rows of them).
  !! nout returns the number of rows written (all, unless a failure stopped the run).
  !! The multipliers lo at every output are those of the index-1 equations at the output
  !! state (see finish_outputs).
  !! With contacts or stick-slip joints, log (allocated by ev_log_init) returns the events
  !! and eo(NEO, nf, rows) the element outputs at the stored rows (dyn_element_outputs).
  subroutine integrate(m, w, q, qd, t0, t1, nsteps, every, opts, qo, vo, ao, lo, nout, st, &
                       status, msg, log, eo, ctl)
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
        call run_genalpha(m, w, c, qo, vo, ao, status, msg, ctl)
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
  real(wp) function step_time(c, k, nfix)
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
  subroutine emit(c, qo, vo, ao, ta, qa, va, aa, tb, qb, vb, ab)
    type(itg_t), intent(inout) :: c
    real(wp), intent(inout) :: qo(:, :), vo(:, :), ao(:, :)
    real(wp), intent(in) :: ta, tb, qa(:), va(:), aa(:), qb(:), vb(:), ab(:)
    do while (c%kout <= c%nsteps)
      if (out_time(c, c%kout) > tb + 1.0e-12_wp * abs(c%t1 - c%t0)) exit
      if (mod(c%kout, c%every) == 0 .or. c%kout == c%nsteps) then
        call hermite5(ta, qa, va, aa, tb, qb, vb, ab, out_time(c, c%kout), &
                      qo(:, c%nout + 1), vo(:, c%nout + 1), ao(:, c%nout + 1))
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
  !! per step (a small dense LU, cheaper than the extra iterations an older J costs).
  !! Converged: |Phi| <= w%tol, the last correction below 1e-3 (atol + rtol |q|), and the
  !! residual of M q_ddot + J^T lambda = Q below GA_RTOL of its largest term, so that the
  !! result is that of full Newton (a stale S only changes the iteration count).
  subroutine run_genalpha(m, w, c, qo, vo, ao, status, msg, ctl)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    integer, intent(inout), optional, volatile :: ctl(:)   !! progress (see integrate)
    real(wp), intent(inout) :: qo(:, :), vo(:, :), ao(:, :)
    integer, intent(out) :: status
    character(len=MSG_LEN), intent(out) :: msg
    real(wp), parameter :: GA_RHO = 0.1_wp       ! contraction rate that asks for new K, C
    real(wp), parameter :: GA_RTOL = 1.0e-11_wp  ! relative residual of the dynamic equations
    integer, parameter :: GA_SLOW = 6            ! iterations that ask for new K, C
    integer, parameter :: GA_MAXIT = 30          ! iterations before the step fails
    real(wp) :: am, af, gam, bet, bp, gp, h, t, err, tnew, facc, v, hprev, dqn, dqp, dtol
    real(wp) :: rtol_dyn, cf, kmax, cmax, fmax, qmax, vmax, rmax, te, mufric
    real(wp) :: q(m%nq), qd(m%nq), qdd(m%nq), acc(m%nq), lam(m%neq)
    real(wp) :: qn(m%nq), vn(m%nq), an(m%nq), accn(m%nq), lamn(m%neq), dq(m%nq), ap(m%nq)
    real(wp) :: res(m%nq + w%na), kt(m%nq, m%nq), ct(m%nq, m%nq)
    real(wp) :: s(m%nq + w%na, m%nq + w%na)
    integer :: piv(m%nq + w%na), it, n, stt, nfix, na, attempt, nkc, k, kev, nprev
    logical :: fixed, conv, have_kc, new_kc, finite, changed
    status = MBD_OK; msg = ''
    n = m%nq; na = w%na
    am = (2 * c%opts%rho_inf - 1) / (c%opts%rho_inf + 1)        ! Arnold & Bruls (2007)
    af = c%opts%rho_inf / (c%opts%rho_inf + 1)
    gam = half + af - am
    bet = 0.25_wp * (gam + half)**2
    cf = (1 - af) / (1 - am)             ! weight of q_ddot_{n+1} in a_{n+1}
    fixed = c%opts%h > zero
    have_kc = .false.; new_kc = .false.
    mufric = zero                        ! the largest friction coefficient of a joint
    do k = 1, m%nf
      if (m%fkind(k) == FRC_FRICTION) mufric = max(mufric, m%fp(m%fpo(k)), m%fp(m%fpo(k) + 1))
    end do
    kt = zero; ct = zero; kmax = zero; cmax = zero
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
      if (hprev > zero .and. abs(h - hprev) > zero) acc = qdd + (h / hprev) * (acc - qdd)
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
        dq = zero; dqp = huge(one)
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
          dtol = 1.0e-3_wp * (c%opts%atol + c%opts%rtol * qmax)
          if (it > 1 .and. finite .and. maxval(abs(w%phi)) <= w%tol .and. &
              maxval(abs(dq)) <= dtol .and. rmax <= rtol_dyn) then
            conv = .true.; exit
          end if
          if (.not. finite) exit
          if (it == GA_SLOW .and. nkc < 2) new_kc = .true.
          if (it == 1 .or. new_kc) then
            if (.not. have_kc .or. new_kc) then
              call dyn_tangent(m, w, qn, vn, tnew, lamn, kt, ct, fast=.true.)
              c%st%jacobians = c%st%jacobians + 1
              have_kc = .true.; new_kc = .false.; nkc = nkc + 1
              kmax = maxval(abs(kt)); cmax = maxval(abs(ct))
              call assemble_blocks(m, qn, vn, tnew, w%phi, w%nu, w%gam, w%asm)
            end if
            call form_s()
            call lu_factor_small(s, piv, stt)
            c%st%factorizations = c%st%factorizations + 1
            if (stt /= MBD_OK) exit
          end if
          res = -res
          call lu_solve_small(s, piv, res)
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
          dqp = dqn
        end do
        if (conv .or. nkc > 0) exit
        new_kc = .true.                 ! failed with old K, C: retry with fresh ones
      end do
      ! local error estimate: the step's position error is (beta - 1/6) h^3 q''', and the
      ! distance of q_{n+1} from its second-order Taylor prediction is h^3 q'''/6, so
      ! e = (6 beta - 1) (q_{n+1} - q_n - h q_dot_n - h^2 q_ddot_n / 2)
      if (conv .and. .not. fixed) err = err_norm(c, (6 * bet - 1) * &
                                                 (qn - q - h * qd - half * h * h * qdd), q, qn)
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
          write (msg, '(a,es12.5,a,es10.3)') 'Newton did not converge at t = ', &
            tnew, ' with the fixed step h = ', h
          return
        end if
        if (conv) then
          h = h * max(0.2_wp, 0.9_wp * err**(-one / 3))
        else
          h = h / 4
        end if
        if (h < 1.0e-14_wp * max(one, abs(t))) then
          status = MBD_INTEGRATOR_FAILED
          write (msg, '(a,es12.5)') 'step size underflow at t = ', t
          return
        end if
        cycle
      end if
      accn = accn + (1 - af) / (1 - am) * an
      nprev = c%nout
      call emit(c, qo, vo, ao, t, q, qd, qdd, tnew, qn, vn, an)
      call save_modes(w, c, nprev + 1)
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
    !> S = [M b' + C g' + K, b' J^T; b' J, 0] at the last assembly (J from its blocks).
    subroutine form_s()
      integer :: j
      call scatter_dense(w%asm, w%jac)
      do j = 1, n + na
        s(:, j) = zero
      end do
      do j = 1, n
        s(1:n, j) = kt(:, j) + gp * ct(:, j)
        s(j, j) = s(j, j) + m%mdiag(j) * bp
      end do
      do j = 1, na
        s(n + j, 1:n) = bp * w%jac(w%rows(j), :)
        s(1:n, n + j) = bp * w%jac(w%rows(j), :)
      end do
    end subroutine form_s
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
    real(wp), allocatable :: y(:), ynew(:), k(:, :), e(:)
    real(wp) :: t, h, tnew, err, fac, qa(m%nq), va(m%nq), aa(m%nq), te
    integer :: stt, nprev, kev
    logical :: fixed, fsal, changed
    integer :: nfix
    status = MBD_OK; msg = ''
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
    call pack_state(c, y, ynew, k, e, stt)
    if (stt /= 0) then
      call mem_fail(REAL_BYTES * 10 * size(c%qf), 'the integrator stages', &
                    'use a smaller model', status, msg)
      return
    end if
    fsal = .false.
    qa = c%qf; va = c%vf; aa = c%af          ! the state at the start of the step
    c%qs = qa; c%vs = va; c%as = aa; c%ts = t
    err = zero
    do while (more(c, t, fixed, nfix))
      if (c%st%steps + c%st%rejected >= c%opts%max_steps) then
        call step_limit(c, t, 0, status, msg); return
      end if
      c%st%t_fail = t
      h = min(h, c%t1 - t)
      tnew = t + h
      if (fixed) then
        tnew = step_time(c, c%st%steps + 1, nfix)
        h = tnew - t
      end if
      if (fixed) then
        call rk4_step(m, w, c, t, y, h, ynew, k, stt)
        err = zero
      else
        call dopri5_step(m, w, c, t, y, h, ynew, k, e, fsal, stt)
        if (stt == MBD_OK) err = err_norm(c, e, y, ynew)
      end if
      if (stt == MBD_OK .and. partitioned) then
        ! the dependent coordinates are outside the error estimate: reject a step that
        ! moved them off their Taylor prediction (a switch of branch at a singular point)
        call rhs(m, w, c, tnew, ynew, e, stt)
        if (stt == MBD_OK) then
          if (maxval(abs(c%qf(c%iu) - predicted(c, tnew))) > &
              half * maxval(abs(predicted(c, tnew) - c%qs(c%iu))) + 1.0e3_wp * w%tol) err = 10.0_wp
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
          h = te - t; fsal = .false.
          cycle
        end if
      end if
      if (err > one) then
        c%st%rejected = c%st%rejected + 1
        fsal = .false.
        h = h * max(0.2_wp, 0.9_wp * err**(-0.2_wp))
        if (h < 1.0e-14_wp * max(one, abs(t))) then
          status = MBD_INTEGRATOR_FAILED
          write (msg, '(a,es12.5)') 'step size underflow at t = ', t
          return
        end if
        cycle
      end if
      ! accepted: the full state at the end, projected (dopri5) or completed (partitioned)
      call finish_step(m, w, c, partitioned, tnew, ynew, fsal, stt)
      if (stt /= MBD_OK) then
        status = MBD_INTEGRATOR_FAILED
        write (msg, '(a,es12.5)') 'the constraints could not be satisfied after the step to t = ', &
          tnew
        return
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
      call emit(c, qo, vo, ao, t, qa, va, aa, tnew, c%qf, c%vf, c%af)
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
          call pack_state(c, y, ynew, k, e, stt)
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

  !> The integrated state y from the full state: (q, q_dot), or (v, v_dot) when partitioned.
  subroutine pack_state(c, y, ynew, k, e, ierr)
    type(itg_t), intent(in) :: c
    real(wp), allocatable, intent(inout) :: y(:), ynew(:), k(:, :), e(:)
    integer, intent(out) :: ierr          ! allocation status (0 ok)
    integer :: ny, nh
    nh = size(c%qf)
    if (c%ni > 0) nh = c%ni
    ny = 2 * nh
    if (allocated(y)) deallocate (y, ynew, k, e)
    allocate (y(ny), ynew(ny), k(ny, 7), e(ny), stat=ierr)
    if (ierr /= 0) return
    if (c%ni > 0) then
      y(1:nh) = c%qf(c%iv); y(nh + 1:) = c%vf(c%iv)
    else
      y(1:nh) = c%qf; y(nh + 1:) = c%vf
    end if
  end subroutine pack_state

  !> After an accepted step: the full consistent state at tn in c (dopri5: projected).
  subroutine finish_step(m, w, c, partitioned, tn, yn, fsal, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    logical, intent(in) :: partitioned
    real(wp), intent(in) :: tn
    real(wp), intent(inout) :: yn(:)
    logical, intent(inout) :: fsal
    integer, intent(out) :: stf
    real(wp) :: f(size(yn)), v0(m%nq)
    if (partitioned) then
      call rhs(m, w, c, tn, yn, f, stf)          ! solves u, u_dot and the accelerations
      return
    end if
    c%qf = yn(1:m%nq); c%vf = yn(m%nq + 1:)
    stf = MBD_OK
    if (c%opts%method == METH_DOPRI5) then
      call dyn_project_pos(m, w, c%qf, tn, stf)
      v0 = c%vf
      if (stf == MBD_OK) call dyn_velocity(m, w, c%qf, tn, v0, c%vf, stf)
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
    integer :: nn
    c%st%rhs = c%st%rhs + 1
    nn = m%nq
    if (c%ni > 0) then
      c%qf(c%iv) = y(1:c%ni)
      if (allocated(c%qs)) c%qf(c%iu) = predicted(c, t)   ! Newton starts on the branch
      call solve_dependent(m, w, c, t, y(c%ni + 1:), stf)
      if (stf /= MBD_OK) return
    else
      c%qf = y(1:nn); c%vf = y(nn + 1:)
    end if
    call accel(m, w, c, t, stf)
    if (stf /= MBD_OK) return
    if (c%ni > 0) then
      f(1:c%ni) = c%vf(c%iv); f(c%ni + 1:) = c%af(c%iv)
    else
      f(1:nn) = c%vf; f(nn + 1:) = c%af
    end if
  end subroutine rhs

  !> Taylor prediction of the dependent coordinates at t from the step's start state.
  pure function predicted(c, t) result(u)
    type(itg_t), intent(in) :: c
    real(wp), intent(in) :: t
    real(wp) :: u(size(c%iu)), dt
    dt = t - c%ts
    u = c%qs(c%iu) + dt * (c%vs(c%iu) + half * dt * c%as(c%iu))
  end function predicted

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
    integer :: nn
    call dyn_accel(m, w, q, qd, t, qdd, lam, stf)
    if (stf /= MBD_OK .or. opts%method /= METH_RK4) return
    nn = m%nq
    w%rhs(1:nn) = w%force
    w%rhs(nn + 1:) = w%s * (w%gam(w%rows) - two * opts%balpha * &
                            (matmul(w%jac(w%rows, :), qd) - w%nu(w%rows)) - &
                            opts%bbeta**2 * w%phi(w%rows))
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
    real(wp) :: qf(m%nq), vf(m%nq)
    integer :: r, stt, newton
    qf = c%qf; vf = c%vf; newton = c%st%newton
    do r = r0, c%nout
      c%qf = qo(:, r); c%vf = vo(:, r)
      call solve_dependent(m, w, c, out_time(c, output_index(c%nsteps, c%every, r)), &
                           vo(c%iv, r), stt)
      if (stt == MBD_OK) then
        qo(:, r) = c%qf; vo(:, r) = c%vf
      end if
    end do
    c%qf = qf; c%vf = vf; c%st%newton = newton
  end subroutine complete_outputs

  !> Dependent coordinates u from Phi(u, v) = 0 (Newton with J_u), then u_dot from
  !! J_u u_dot = nu - J_v v_dot.
  subroutine solve_dependent(m, w, c, t, vdot, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t, vdot(:)
    integer, intent(out) :: stf
    real(wp) :: ju(w%na, w%na), b(w%na)
    integer :: piv(w%na), it
    character(len=MSG_LEN) :: lmsg
    stf = MBD_OK
    if (w%na == 0) then
      c%vf(c%iv) = vdot; return
    end if
    do it = 1, 25
      call assemble_dense(m, c%qf, w%qz, t, w%phi, w%nu, w%gam, w%asm, w%jac)
      ju = w%jac(w%rows, c%iu)
      call lu_factor(ju, piv, stf, lmsg)
      if (stf /= MBD_OK) return
      if (maxval(abs(w%phi)) <= w%tol) exit
      b = -w%phi(w%rows)
      call lu_solve(ju, piv, b, stf, lmsg)
      c%qf(c%iu) = c%qf(c%iu) + b
      c%st%newton = c%st%newton + 1
    end do
    if (maxval(abs(w%phi)) > w%tol) then
      stf = MBD_NO_CONVERGENCE; return
    end if
    c%vf(c%iv) = vdot
    b = w%nu(w%rows) - matmul(w%jac(w%rows, c%iv), vdot)
    call lu_solve(ju, piv, b, stf, lmsg)
    c%vf(c%iu) = b
  end subroutine solve_dependent

  !> Choose the dependent coordinates: the first na columns of a QR with column pivoting of
  !! J (the best-conditioned block J_u); the rest are independent.
  subroutine partition(m, w, c, t, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t
    integer, intent(out) :: stf
    real(wp) :: a(w%na, m%nq), tau(min(w%na, m%nq)), wq(1)
    real(wp), allocatable :: work(:)
    integer :: jp(m%nq), info
    character(len=MSG_LEN) :: lmsg
    integer :: kk
    if (w%na == 0) then                       ! free bodies: every coordinate independent
      c%iu = [integer ::]; c%iv = [(kk, kk=1, m%nq)]; c%ni = m%nq
      c%st%partitions = c%st%partitions + 1
      stf = MBD_OK; return
    end if
    call assemble_dense(m, c%qf, w%qz, t, w%phi, w%nu, w%gam, w%asm, w%jac)
    a = w%jac(w%rows, :)
    jp = 0
    call dgeqp3(w%na, m%nq, a, w%na, jp, tau, wq, -1, info)
    allocate (work(max(1, int(wq(1)))), stat=stf)
    if (stf /= 0) then
      stf = MBD_NO_MEMORY; return
    end if
    call dgeqp3(w%na, m%nq, a, w%na, jp, tau, work, size(work), info)
    call lapack_status('dgeqp3', info, stf, lmsg)
    if (stf /= MBD_OK) return
    c%iu = jp(1:w%na)
    c%iv = jp(w%na + 1:)
    c%ni = m%nq - w%na
    c%st%partitions = c%st%partitions + 1
  end subroutine partition

  !> 1/cond_1 of J(rows, cols) at the last assembly (0 when singular).
  real(wp) function rcond_cols(w, cols) result(rc)
    type(dyn_work_t), intent(inout) :: w
    integer, intent(in) :: cols(:)
    real(wp) :: ju(w%na, w%na), anorm, cw(4 * w%na)
    integer :: piv(w%na), iw(w%na), stf, info
    character(len=MSG_LEN) :: lmsg
    ju = w%jac(w%rows, cols)
    anorm = maxval(sum(abs(ju), dim=1))
    rc = zero
    call lu_factor(ju, piv, stf, lmsg)
    if (stf /= MBD_OK) return
    call dgecon('1', w%na, ju, w%na, anorm, rc, cw, iw, info)
  end function rcond_cols

  !> Choose again when the current J_u has become REPARTITION times worse conditioned
  !! (1/cond_1) than the choice a QR with column pivoting of J would make now. Near a
  !! singular configuration, where every J_u is ill conditioned, nothing better exists and
  !! the partition is kept.
  logical function needs_partition(m, w, c, t)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(in) :: c
    real(wp), intent(in) :: t
    real(wp) :: rc, a(w%na, m%nq), tau(w%na), wq(1)
    real(wp), allocatable :: work(:)
    integer :: jp(m%nq), info, stat
    needs_partition = .false.
    if (w%na == 0) return
    call assemble_dense(m, c%qf, w%qz, t, w%phi, w%nu, w%gam, w%asm, w%jac)
    rc = rcond_cols(w, c%iu)
    a = w%jac(w%rows, :)
    jp = 0
    call dgeqp3(w%na, m%nq, a, w%na, jp, tau, wq, -1, info)
    allocate (work(max(1, int(wq(1)))), stat=stat)
    needs_partition = rc <= zero
    if (stat /= 0 .or. info /= 0) return
    call dgeqp3(w%na, m%nq, a, w%na, jp, tau, work, size(work), info)
    if (info /= 0) return
    needs_partition = rc < REPARTITION * rcond_cols(w, jp(1:w%na))
  end function needs_partition

  !> One classical Runge-Kutta step.
  subroutine rk4_step(m, w, c, t, y, h, yn, k, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t, y(:), h
    real(wp), intent(out) :: yn(:)
    real(wp), intent(inout) :: k(:, :)
    integer, intent(out) :: stf
    call rhs(m, w, c, t, y, k(:, 1), stf)
    if (stf /= MBD_OK) return
    call rhs(m, w, c, t + half * h, y + half * h * k(:, 1), k(:, 2), stf)
    if (stf /= MBD_OK) return
    call rhs(m, w, c, t + half * h, y + half * h * k(:, 2), k(:, 3), stf)
    if (stf /= MBD_OK) return
    call rhs(m, w, c, t + h, y + h * k(:, 3), k(:, 4), stf)
    if (stf /= MBD_OK) return
    yn = y + h / 6 * (k(:, 1) + 2 * k(:, 2) + 2 * k(:, 3) + k(:, 4))
  end subroutine rk4_step

  !> One Dormand-Prince 5(4) step; e is the embedded error estimate. k(:, 1) is reused from
  !! the last stage of the previous step when fsal is true (first same as last).
  subroutine dopri5_step(m, w, c, t, y, h, yn, k, e, fsal, stf)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(itg_t), intent(inout) :: c
    real(wp), intent(in) :: t, y(:), h
    real(wp), intent(out) :: yn(:), e(:)
    real(wp), intent(inout) :: k(:, :)
    logical, intent(inout) :: fsal
    integer, intent(out) :: stf
    stf = MBD_OK
    if (.not. fsal) then
      call rhs(m, w, c, t, y, k(:, 1), stf)
      if (stf /= MBD_OK) return
    end if
    call rhs(m, w, c, t + C2 * h, y + h * A21 * k(:, 1), k(:, 2), stf)
    if (stf /= MBD_OK) return
    call rhs(m, w, c, t + C3 * h, y + h * (A31 * k(:, 1) + A32 * k(:, 2)), k(:, 3), stf)
    if (stf /= MBD_OK) return
    call rhs(m, w, c, t + C4 * h, y + h * (A41 * k(:, 1) + A42 * k(:, 2) + A43 * k(:, 3)), &
             k(:, 4), stf)
    if (stf /= MBD_OK) return
    call rhs(m, w, c, t + C5 * h, y + h * (A51 * k(:, 1) + A52 * k(:, 2) + A53 * k(:, 3) + &
             A54 * k(:, 4)), k(:, 5), stf)
    if (stf /= MBD_OK) return
    call rhs(m, w, c, t + h, y + h * (A61 * k(:, 1) + A62 * k(:, 2) + A63 * k(:, 3) + &
             A64 * k(:, 4) + A65 * k(:, 5)), k(:, 6), stf)
    if (stf /= MBD_OK) return
    yn = y + h * (A71 * k(:, 1) + A73 * k(:, 3) + A74 * k(:, 4) + A75 * k(:, 5) + A76 * k(:, 6))
    call rhs(m, w, c, t + h, yn, k(:, 7), stf)
    if (stf /= MBD_OK) return
    e = h * (E1 * k(:, 1) + E3 * k(:, 3) + E4 * k(:, 4) + E5 * k(:, 5) + E6 * k(:, 6) + &
             E7 * k(:, 7))
    k(:, 1) = k(:, 7)
    fsal = .true.
  end subroutine dopri5_step

end module mbd_integrators
