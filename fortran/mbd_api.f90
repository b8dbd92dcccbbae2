!> mbd_api: whole analyses behind flat arguments (plain arrays, integers, a status and a
!! message). The f2py layer and the standalone program both call these; derived types stay
!! inside. Report arrays:
!!   iinfo(NINFO): 1 output rows computed, 2 offending constraint (bad input), 3 driver that
!!                 can no longer be met, 4 constraint with the largest residual, 5 rank
!!                 deficiency, 6 Newton corrections, 7 factorizations, 8 rejected steps,
!!                 9 rank of J at assembly, 10 singular configurations passed through
!!   rinfo(NINFO): 1 time of the singular configuration or failure, 2 sigma_min, 3 sigma_max,
!!                 4 residual
!! The analyses run on the nondimensional model (mbd_model: lengths in units of the model's
!! length scale, a power of 2, so the conversions are exact); their inputs and outputs are
!! converted here, so callers see model units throughout. Evaluations (api_eval) and reactions
!! (api_reactions) need no tolerance and use the model as given.
module mbd_api
  use mbd_kinds, only: wp, zero, one
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use mbd_status, only: MBD_OK, MBD_BAD_COUNT, MBD_BAD_PARAM, MBD_INCONSISTENT, MBD_NO_MEMORY, &
                        MBD_NO_CONVERGENCE, MBD_BAD_INPUT, &
                        MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_fail
  use mbd_points, only: NLOC, MAXROW
  use mbd_model, only: model_t, model_build, model_add_dynamics, model_force_size
  use mbd_assembly, only: band_lm_assemble
  use mbd_dynamics, only: dyn_work_t, dyn_init, dyn_memory_check, dyn_velocity, &
                          dyn_multipliers, dyn_reactions, dyn_choose, dyn_jv, &
                          gen_forces, kinetic_energy, dyn_element_outputs, SOLVER_DENSE
  use mbd_events, only: ev_log_t, ev_log_init, events_switch, events_active
  use mbd_forces, only: force_is_contact, FRC_FRICTION
  use mbd_contact, only: NEO
  use mbd_constraints, only: CON_CAM
  use mbd_joint_cam, only: cam_outward_normal
  use mbd_points, only: local_state
  use mbd_integrators, only: dyn_opts_t, dyn_stats_t, integrate, output_rows, output_index, &
                              METH_PARTITIONED, METH_GENALPHA, METH_DOPRI5
  use mbd_statics, only: statics_solve
  use mbd_modes, only: modes_solve, unit_largest
  use mbd_frf, only: frf_solve
  use mbd_linear, only: linear_state_space
  use mbd_assemble, only: assemble_dense, assemble_blocks, asm_work_t, asm_init
  use mbd_kinematics, only: kin_opts_t, kin_report_t, kin_work_t, kin_run, kin_work_init, &
                            kin_assemble, kin_rank, kin_rank_band, kin_out_count, MAXPASS, &
                            SOLVER_AUTO, &
                            SOLVER_BANDED, kin_newton, kin_vel_acc
  use mbd_status, only: MBD_BAD_SETTING, MBD_USER_ABORT, MBD_SINGULAR
  use mbd_profiles, only: profile_raw_length, profile_prepare, profile_eval
  use mbd_sensitivity, only: sens_t, sens_setup, sens_eval_d, sens_trig, sens_force_dm, &
                             sens_force_rows
  use mbd_assemble, only: scatter_dense
  use mbd_sens_dynamics, only: sens_multipliers, sens_reactions, sens_statics, sens_dopri5, &
                               sens_statics_band, &
                               sens_initial, lam_work_t, lam_init, sens_out_multipliers, &
                               sens_at_rest, sens_stiffness_at, sens_tangent_pattern, &
                               sens_stiffness_mul, sens_damping_mul
  use mbd_sens_genalpha, only: ga_sens_t, ga_sens_init
  implicit none
  private
  public :: NINFO, api_sizes, api_eval, api_kinematics, api_profile, api_analyze, api_kin_step
  public :: api_inverse, api_dynamics, api_statics, api_modes, api_frf, api_reactions, &
            api_linearize, &
            api_cam_forces
  public :: api_eval_d, api_reactions_dp, api_dynamics_sens, api_forces_d, api_stiffness

  integer, parameter :: NINFO = 12   !! length of the report arrays

  interface finite
    module procedure finite_scalar, finite_vector, finite_matrix
  end interface finite

contains

  !> All finite (no NaN or infinity).
  pure logical function finite_scalar(x)
    real(wp), intent(in) :: x
    finite_scalar = ieee_is_finite(x)
  end function finite_scalar

  pure logical function finite_vector(x)
    real(wp), intent(in) :: x(:)
    finite_vector = all(ieee_is_finite(x))
  end function finite_vector

  pure logical function finite_matrix(x)
    real(wp), intent(in) :: x(:, :)
    finite_matrix = all(ieee_is_finite(x))
  end function finite_matrix

  !> Status and message for a non-finite input.
  subroutine not_finite(what, status, msg)
    character(len=*), intent(in) :: what
    integer, intent(out) :: status
    character(len=MSG_LEN), intent(out) :: msg
    status = MBD_BAD_PARAM
    msg = what // ' must be finite (no NaN or infinity)'
  end subroutine not_finite

  !> Build the model; return its sizes.
  subroutine api_sizes(nb, ctab, rpar, nq, neq, status, msg, bad)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    integer, intent(out) :: nq, neq             !! coordinates, equations
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer, intent(out) :: bad                 !! offending constraint, or 0
    type(model_t) :: m
    call model_build(nb, ctab, rpar, m, status, msg, bad, nondim=.true.)
    nq = m%nq; neq = m%neq
  end subroutine api_sizes

  !> a(:, k) = a(:, k) * u for every column (model units from the core's: u = cunit), or
  !! with divide, a(:, k) / u (multipliers: u = rowunit). Nothing to do when L = 1.
  subroutine units(m, a, u, divide)
    type(model_t), intent(in) :: m              !! model (its length unit lref)
    real(wp), intent(inout) :: a(:, :)          !! columns to convert
    real(wp), intent(in) :: u(:)                !! unit of each row (cunit or rowunit)
    logical, intent(in) :: divide               !! divide by u instead of multiplying
    integer :: k
    if (.not. (m%lref > one .or. m%lref < one)) return
    do k = 1, size(a, 2)
      if (divide) then
        a(:, k) = a(:, k) / u
      else
        a(:, k) = a(:, k) * u
      end if
    end do
  end subroutine units

  !> Sensitivities (rows, np[, outputs]) in model units: with p' = p L**e the core's
  !! derivatives d(.)'/dp' become d(.)/dp = u d(.)'/dp' dp'/dp (dp'/dp = sens%pscale; u the
  !! unit of each row, multiplied, or with divide divided); with back, the inverse.
  subroutine sens_units(m, sens, a, u, divide, back)
    type(model_t), intent(in) :: m              !! model (its length unit lref)
    type(sens_t), intent(in) :: sens            !! parameters (pscale)
    real(wp), intent(inout) :: a(:, :, :)       !! (rows, np, outputs)
    real(wp), intent(in) :: u(:)                !! unit of each row
    logical, intent(in) :: divide               !! divide by u
    logical, intent(in), optional :: back       !! the inverse conversion
    real(wp) :: f(size(a, 1), size(a, 2))
    integer :: k, j
    logical :: inv
    if (.not. (m%lref > one .or. m%lref < one)) return
    inv = .false.
    if (present(back)) inv = back
    do k = 1, size(a, 2)          ! one factor per row and parameter (exact: powers of 2)
      if (divide .neqv. inv) then
        f(:, k) = sens%pscale(k) / u
      else
        f(:, k) = sens%pscale(k) * u
      end if
      if (inv) f(:, k) = (one / sens%pscale(k)**2) * f(:, k)
    end do
    do j = 1, size(a, 3)
      a(:, :, j) = a(:, :, j) * f
    end do
  end subroutine sens_units

  !> sens_units for one output (rows, np).
  subroutine sens_units2(m, sens, a, u, divide)
    type(model_t), intent(in) :: m              !! model
    type(sens_t), intent(in) :: sens            !! parameters (pscale)
    real(wp), intent(inout) :: a(:, :)          !! (rows, np)
    real(wp), intent(in) :: u(:)                !! unit of each row
    logical, intent(in) :: divide               !! divide by u
    real(wp) :: b(size(a, 1), size(a, 2), 1)
    b(:, :, 1) = a
    call sens_units(m, sens, b, u, divide)
    a = b(:, :, 1)
  end subroutine sens_units2

  !> The residual rep%resid in model units (that of the worst constraint's first row).
  pure real(wp) function resid_units(m, resid, worst)
    type(model_t), intent(in) :: m              !! model
    real(wp), intent(in) :: resid               !! residual in the core's units
    integer, intent(in) :: worst                !! constraint it belongs to (0: unknown)
    resid_units = resid * m%lref
    if (worst > 0 .and. worst <= m%nc) resid_units = resid * m%rowunit(m%row0(worst))
  end function resid_units

  !> Element outputs eo(NEO, nf, rows) in model units: contacts [Fn, Ft, penetration,
  !! sliding speed, contact point]; joint friction [normal load, friction force, 0, slip
  !! speed, stuck flag, friction moment]. Forces are F L in the core, lengths x / L.
  subroutine element_units(m, eo)
    type(model_t), intent(in) :: m
    real(wp), intent(inout) :: eo(:, :, :)
    integer :: k
    real(wp) :: l
    l = m%lref
    if (.not. (l > one .or. l < one)) return
    do k = 1, size(eo, 2)
      if (force_is_contact(m%fkind(k))) then
        eo(1:2, k, :) = eo(1:2, k, :) / l; eo(3:6, k, :) = eo(3:6, k, :) * l
      else if (m%fkind(k) == FRC_FRICTION) then
        eo(1:2, k, :) = eo(1:2, k, :) / l; eo(4, k, :) = eo(4, k, :) * l
      end if
    end do
  end subroutine element_units

  !> The event log as records evo(4, :) [t, element, kind, value] in model units (contact
  !! speeds x L, friction forces / L); nev the number of events (more than size(evo, 2):
  !! the later ones were not kept).
  subroutine events_out(m, log, evo, nev)
    type(model_t), intent(in) :: m
    type(ev_log_t), intent(in) :: log
    real(wp), intent(out) :: evo(:, :)
    integer, intent(out) :: nev
    integer :: r, k
    evo = zero
    nev = log%n
    do r = 1, min(log%n, size(evo, 2), size(log%rec, 2))
      evo(:, r) = log%rec(:, r)
      k = nint(evo(2, r))
      if (k < 1 .or. k > m%nf) cycle
      if (force_is_contact(m%fkind(k))) then
        evo(4, r) = evo(4, r) * m%lref
      else
        evo(4, r) = evo(4, r) / m%lref
      end if
    end do
  end subroutine events_out

  !> Phi, J, nu and gamma at (q, q_dot, t).
  subroutine api_eval(nb, ctab, rpar, q, qd, t, phi, jac, nu, gam, status, msg, bad)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q(:), qd(:)         !! state (nq)
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(out) :: phi(:)             !! Phi (neq)
    real(wp), intent(out) :: jac(:, :)          !! J (neq x nq)
    real(wp), intent(out) :: nu(:), gam(:)      !! nu, gamma (neq)
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer, intent(out) :: bad                 !! offending constraint, or 0
    type(model_t) :: m
    type(asm_work_t) :: aw
    phi = zero; jac = zero; nu = zero; gam = zero
    call model_build(nb, ctab, rpar, m, status, msg, bad)
    if (status /= MBD_OK) return
    if (.not. (finite(q) .and. finite(qd) .and. finite(t))) then
      call not_finite('the state (q, q_dot, t)', status, msg); return
    end if
    if (size(q) /= m%nq .or. size(qd) /= m%nq .or. size(phi) /= m%neq .or. &
        size(jac, 1) /= m%neq .or. size(jac, 2) /= m%nq) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    call asm_init(m, aw, status, msg)
    if (status /= MBD_OK) return
    call assemble_dense(m, q, qd, t, phi, nu, gam, aw, jac)
    if (.not. (finite(phi) .and. finite(jac) .and. finite(nu) .and. finite(gam))) then
      status = MBD_BAD_PARAM
      msg = 'the constraint equations overflow at this state (a parameter or state too large)'
    end if
  end subroutine api_eval

  !> Kinematic analysis: the whole time loop in one call.
  subroutine api_kinematics(nb, ctab, rpar, q0, t0, t1, nsteps, tol, maxit, tmin, every, &
                            solver, qout, qdout, qddout, iinfo, rinfo, qsing, dep, redundant, &
                            tpass, status, msg, ptab, sq, sqd, sqdd, ctl, positions, ssum)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q0(:)               !! estimates (nq; extras are estimated)
    real(wp), intent(in) :: t0, t1              !! time span
    integer, intent(in) :: nsteps               !! output intervals
    real(wp), intent(in) :: tol                 !! Newton tolerance (<= 0: default)
    integer, intent(in) :: maxit                !! Newton iterations (<= 0: default)
    real(wp), intent(in) :: tmin                !! singular-time resolution (<= 0: default)
    integer, intent(in) :: every                !! store every k-th output (and the last)
    integer, intent(in) :: solver               !! 0 auto, 1 dense, 2 banded LU
    !> outputs (nq, kin_out_count(nsteps, every); q_dot and q_ddot (nq, 0) with positions)
    real(wp), intent(out) :: qout(:, :), qdout(:, :), qddout(:, :)
    integer, intent(out) :: iinfo(NINFO)        !! integer report
    real(wp), intent(out) :: rinfo(NINFO)       !! real report
    real(wp), intent(out) :: qsing(:)           !! configuration at a singularity (nq)
    integer, intent(out) :: dep(:)              !! dependent rows there (neq)
    integer, intent(out) :: redundant(:)        !! redundant rows at assembly (neq)
    real(wp), intent(out) :: tpass(:)           !! times of singular passages (MAXPASS)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    !> design parameters (mbd_sensitivity; (2, np)) and, with them, dq/dp, dq_dot/dp,
    !! dq_ddot/dp at the outputs, each (nq, np, kin_out_count(nsteps, every))
    integer, intent(in), optional :: ptab(:, :)
    real(wp), intent(out), optional, contiguous :: sq(:, :, :), sqd(:, :, :), sqdd(:, :, :)
    !> progress, shared with a caller in another thread (2): ctl(1) the outputs stored so
    !! far, ctl(2) /= 0 asks the run to stop (MBD_USER_ABORT, the outputs so far kept)
    integer, intent(inout), optional, volatile :: ctl(:)
    !> 1: positions only (chord steps where J is well conditioned; q_dot, q_ddot not returned)
    integer, intent(in), optional :: positions
    !> with ptab: each output's sum of its sensitivities, finite exactly when they all are
    !! (barring an overflow of the sum), for the caller's check (kin_out_count(nsteps, every))
    real(wp), intent(out), optional :: ssum(:)
    real(wp), allocatable :: ss(:)
    type(model_t) :: m
    type(kin_opts_t) :: opts
    type(kin_report_t) :: rep
    type(sens_t) :: sens
    integer :: bad
    iinfo = 0; rinfo = zero; qsing = zero; dep = 0; redundant = 0; tpass = zero
    checks: block                             ! (a failed check leaves the outputs zero)
      call model_build(nb, ctab, rpar, m, status, msg, bad, nondim=.true.)
      iinfo(2) = bad
      if (status /= MBD_OK) exit checks
      if (present(ptab)) then
        if (any(shape(sq) /= [m%nq, size(ptab, 2), size(qout, 2)]) .or. &
            any(shape(sqd) /= shape(sq)) .or. any(shape(sqdd) /= shape(sq))) then
          status = MBD_BAD_COUNT; msg = 'sensitivity arrays do not match the model'; exit checks
        end if
        call sens_setup(m, ctab, rpar, ptab, sens, status, msg, bad)
        if (status /= MBD_OK) then
          iinfo(2) = -2000000 - bad; exit checks
        end if
      end if
      if (.not. (finite(q0) .and. finite(t0) .and. finite(t1) .and. finite(tol) .and. &
                 finite(tmin))) then
        call not_finite('q0, the times and the tolerances', status, msg); exit checks
      end if
      if (.not. (finite(t1 - t0))) then
        call not_finite('the time span', status, msg); exit checks
      end if
      if (m%neq < m%nq) then
        status = MBD_BAD_COUNT
        write (msg, '(a,i0,a,i0,a,i0,a)') 'the model is not kinematically determined: ', m%neq, &
          ' equations for ', m%nq, ' coordinates (', m%nq - m%neq, ' degrees of freedom left)'
        exit checks
      end if
      if (size(q0) /= m%nq .or. size(qsing) /= m%nq .or. size(dep) /= m%neq .or. &
          size(redundant) /= m%neq .or. size(tpass) /= MAXPASS .or. &
          size(qout, 1) /= m%nq .or. size(qout, 2) /= kin_out_count(nsteps, max(every, 1))) then
        status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; exit checks
      end if
      if (every < 1 .or. solver < SOLVER_AUTO .or. solver > SOLVER_BANDED) then
        status = MBD_BAD_SETTING; msg = 'every must be >= 1 and solver 0 (auto), 1 (dense) '// &
          'or 2 (banded)'; exit checks
      end if
    end block checks
    if (status /= MBD_OK) then
      qout = zero; qdout = zero; qddout = zero
      if (present(ptab)) then
        sq = zero; sqd = zero; sqdd = zero
      end if
      if (present(ssum)) ssum = zero
      return
    end if
    ! (kin_run fills the outputs: those it does not reach with zeros)
    opts%every = every; opts%solver = solver
    if (tol > zero) opts%tol = tol
    if (maxit > 0) opts%maxit = maxit
    if (tmin > zero) opts%tmin = tmin
    if (present(positions)) opts%positions = positions == 1
    if (present(ptab)) then
      if (present(ssum)) then                  ! (in model units: sens%ounit)
        call kin_run(m, q0 / m%cunit, t0, t1, nsteps, opts, qout, qdout, qddout, rep, status, &
                     msg, sens, sq, sqd, sqdd, ssum, ctl=ctl)
      else
        allocate (ss(size(qout, 2)), stat=bad)
        if (bad /= 0) then
          call mem_fail(REAL_BYTES * size(qout, 2), 'the sensitivity sums', &
                        'fewer outputs (every) or steps', status, msg)
          qout = zero; qdout = zero; qddout = zero; sq = zero; sqd = zero; sqdd = zero
          return
        end if
        call kin_run(m, q0 / m%cunit, t0, t1, nsteps, opts, qout, qdout, qddout, rep, status, &
                     msg, sens, sq, sqd, sqdd, ss, ctl=ctl)
      end if
      if (rep%ndone < size(sq, 3)) then        ! (the rows after a failure: zero)
        sq(:, :, rep%ndone + 1:) = zero; sqd(:, :, rep%ndone + 1:) = zero
        sqdd(:, :, rep%ndone + 1:) = zero
      end if
    else
      call kin_run(m, q0 / m%cunit, t0, t1, nsteps, opts, qout, qdout, qddout, rep, status, &
                   msg, ctl=ctl)
    end if
    call units(m, qout, m%cunit, .false.); call units(m, qdout, m%cunit, .false.)
    call units(m, qddout, m%cunit, .false.)
    iinfo(1) = rep%ndone; iinfo(3) = rep%driver; iinfo(4) = rep%worst
    iinfo(5) = rep%deficiency; iinfo(6) = rep%newton_its; iinfo(7) = rep%lu_count
    iinfo(8) = rep%rejected; iinfo(9) = rep%rank; iinfo(10) = rep%npass
    rinfo(1) = rep%t_fail; rinfo(2) = rep%smin; rinfo(3) = rep%smax
    rinfo(4) = resid_units(m, rep%resid, rep%worst)
    rinfo(5) = rep%solver; rinfo(6) = rep%kl; rinfo(7) = rep%ku
    if (allocated(rep%qsing)) qsing = rep%qsing * m%cunit
    if (allocated(rep%dep)) dep = rep%dep
    if (allocated(rep%redundant)) redundant = rep%redundant
    tpass = rep%tpass
  end subroutine api_kinematics

  !> One kinematic step per call (for time loops driven from outside): from the state
  !! (q, q_dot, q_ddot) at t_prev, the predictor q + h q_dot + h**2/2 q_ddot (h = t - t_prev),
  !! Newton-Raphson on Phi(q, t) = 0, then J q_dot = nu and J q_ddot = gamma. With assemble,
  !! q holds rough estimates at t and is assembled first (q_dot, q_ddot, t_prev unused).
  !! No step control: a Newton failure or a singular J is returned as the status.
  subroutine api_kin_step(nb, ctab, rpar, q, qd, qdd, t_prev, t, tol, maxit, assemble, &
                          status, msg)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(inout) :: q(:)             !! coordinates at t_prev, then at t (nq)
    real(wp), intent(inout) :: qd(:), qdd(:)    !! velocities and accelerations, likewise
    real(wp), intent(in) :: t_prev, t           !! previous and new time
    real(wp), intent(in) :: tol                 !! Newton tolerance (<= 0: default)
    integer, intent(in) :: maxit                !! Newton iterations (<= 0: default)
    integer, intent(in) :: assemble             !! 1: assemble q from estimates at t
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(model_t) :: m
    type(kin_opts_t) :: opts
    type(kin_report_t) :: rep
    type(kin_work_t) :: w
    real(wp) :: h
    integer :: bad, lev, ierr
    call model_build(nb, ctab, rpar, m, status, msg, bad, nondim=.true.)
    if (status /= MBD_OK) return
    if (size(q) /= m%nq .or. size(qd) /= m%nq .or. size(qdd) /= m%nq .or. m%neq /= m%nq) then
      status = MBD_BAD_COUNT
      msg = 'array sizes do not match the model, or J is not square (stepping needs as '// &
            'many equations as coordinates)'
      return
    end if
    if (.not. (finite(q) .and. finite(qd) .and. finite(qdd) .and. finite(t) .and. &
               finite(t_prev) .and. finite(tol))) then
      call not_finite('the state, the times and tol', status, msg); return
    end if
    if (tol > zero) opts%tol = tol
    if (maxit > 0) opts%maxit = maxit
    call kin_work_init(m, w, status, msg, sparse=.false.)     ! one step: the dense LU
    if (status /= MBD_OK) return
    w%tol = opts%tol * m%lscale
    q = q / m%cunit; qd = qd / m%cunit; qdd = qdd / m%cunit
    step: block                                ! in the core's units; any exit converts back
      if (assemble == 1) then
        allocate (rep%qsing(m%nq), rep%dep(m%neq), rep%redundant(m%neq), stat=ierr)
        if (ierr /= 0) then
          call mem_fail(REAL_BYTES * (real(m%nq, wp) + m%neq), 'the assembly report', &
                        'use a smaller model', status, msg)
          exit step
        end if
        call kin_assemble(m, w, q, t, opts, rep, status, msg)
        if (status /= MBD_OK) exit step
      else
        h = t - t_prev
        q = q + h * (qd + (0.5_wp * h) * qdd)     ! q(t) ~ q + h q_dot + h**2/2 q_ddot
        if (.not. finite(q)) then
          status = MBD_NO_CONVERGENCE
          write (msg, '(a,es22.15,a)') 'the start predicted for t = ', t, &
            ' is non-finite (a step far too long for Newton-Raphson)'
          exit step
        end if
      end if
      call kin_newton(m, w, q, t, opts%maxit, status)
      if (status /= MBD_OK) then
        write (msg, '(a,es22.15)') 'Newton-Raphson failed (or J is singular) at t = ', t
        exit step
      end if
      call kin_vel_acc(m, w, q, t, qd, qdd, status, lev)
      if (status /= MBD_OK) msg = 'velocities or accelerations could not be solved'
    end block step
    q = q * m%cunit; qd = qd * m%cunit; qdd = qdd * m%cunit
  end subroutine api_kin_step

  !> Degrees of freedom and redundancy at the configuration assembled from q0 at time t:
  !! the rank of J, the mobility of the joints alone, and the redundant rows. On a failed
  !! assembly, q is the best configuration found, resid its residual and dep the rows that
  !! contradict each other (MBD_INCONSISTENT) or status MBD_ASSEMBLY_FAILED.
  subroutine api_analyze(nb, ctab, rpar, q0, t, tol, q, rank, mobility, redundant, dep, &
                         resid, worst, status, msg)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q0(:)               !! estimates (nq)
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(in) :: tol                 !! tolerance (<= 0: default)
    real(wp), intent(out) :: q(:)               !! assembled configuration (nq)
    integer, intent(out) :: rank, mobility      !! rank of J; DOF of the joints alone
    integer, intent(out) :: redundant(:)        !! redundant rows (neq)
    integer, intent(out) :: dep(:)              !! contradicting rows on failure (neq)
    real(wp), intent(out) :: resid              !! ||Phi||_inf at the end
    integer, intent(out) :: worst               !! constraint with the largest residual
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(model_t) :: m
    type(kin_opts_t) :: opts
    type(kin_report_t) :: rep
    type(kin_work_t) :: w
    integer :: bad, ierr, path, kl, ku
    q = zero; rank = 0; mobility = 0; redundant = 0; dep = 0; resid = zero; worst = 0
    call model_build(nb, ctab, rpar, m, status, msg, bad, nondim=.true.)
    worst = bad
    if (status /= MBD_OK) return
    if (.not. (finite(q0) .and. finite(t) .and. finite(tol))) then
      call not_finite('q0, t and tol', status, msg); return
    end if
    if (size(q0) /= m%nq .or. size(q) /= m%nq .or. size(redundant) /= m%neq .or. &
        size(dep) /= m%neq) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    if (tol > zero) opts%tol = tol
    ! a large model with the band structure: the band assembly and rank analysis (no n x n
    ! array; the dense ones cost O(n^3): 44 s at 2403 coordinates)
    call dyn_choose(m, SOLVER_AUTO, path, kl, ku, status, msg)
    if (status /= MBD_OK) return
    if (path /= SOLVER_DENSE) then
      q = q0 / m%cunit
      call band_lm_assemble(m, q, t, opts%tol * m%lscale, opts%assembly_maxit, status, msg, worst, &
                        resid)
      resid = resid_units(m, resid, worst)
      if (status == MBD_OK) call kin_rank_band(m, q, t, rank, mobility, redundant, status, msg)
      q = q * m%cunit
      return
    end if
    call kin_work_init(m, w, status, msg)
    if (status /= MBD_OK) return
    w%tol = opts%tol * m%lscale
    allocate (rep%qsing(m%nq), rep%dep(m%neq), rep%redundant(m%neq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * (real(m%nq, wp) + m%neq), 'the assembly report', &
                    'use a smaller model', status, msg)
      return
    end if
    rep%qsing = zero; rep%dep = 0; rep%redundant = 0
    q = q0 / m%cunit
    call kin_assemble(m, w, q, t, opts, rep, status, msg)
    resid = maxval(abs(w%phi) * m%rowunit); worst = rep%worst; dep = rep%dep
    if (status == MBD_INCONSISTENT) then
      rank = rep%rank; redundant = rep%redundant
    end if
    if (status == MBD_OK) call kin_rank(m, w, q, t, rank, mobility, redundant, status, msg)
    q = q * m%cunit
  end subroutine api_analyze

  !> Points c(alpha) of a cam profile in its body frame (for drawing), from raw parameters.
  subroutine api_profile(kind, raw, alpha, pts, status, msg)
    integer, intent(in) :: kind                 !! profile kind
    real(wp), intent(in) :: raw(:)              !! raw parameters
    real(wp), intent(in) :: alpha(:)            !! parameters to evaluate at
    real(wp), intent(out) :: pts(:, :)          !! (2, size(alpha)) points
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    real(wp), allocatable :: prep(:)
    real(wp) :: c1(2), c2(2), c3(2)
    integer :: i
    pts = zero
    if (.not. (finite(raw) .and. finite(alpha))) then
      call not_finite('profile parameters and alpha', status, msg); return
    end if
    if (profile_raw_length(kind, raw) /= size(raw)) then
      status = MBD_BAD_COUNT; msg = 'profile parameters are malformed'; return
    end if
    call profile_prepare(kind, raw, prep, status, msg)
    if (status /= MBD_OK) return
    do i = 1, size(alpha)
      call profile_eval(kind, prep, alpha(i), pts(:, i), c1, c2, c3)
    end do
  end subroutine api_profile

  !> The report's iinfo(2) after a failed build: the offending constraint (> 0), body
  !! (-body) or force (-1000000 - force); 0 when none.
  pure integer function bad_code(bad, badf)
    integer, intent(in) :: bad                  !! offending constraint (model_build)
    integer, intent(in) :: badf                 !! force (> 0) or -body (model_add_dynamics)
    bad_code = bad
    if (badf > 0) bad_code = -1000000 - badf
    if (badf < 0) bad_code = badf
  end function bad_code

  !> Build a model with masses and forces (bad: offending constraint > 0 or force > 0 with
  !! kind flag; body errors come back as bad = -body).
  subroutine build_dynamic(nb, ctab, rpar, bmass, grav, ftab, fpar, m, status, msg, bad, badf)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :)
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:)
    type(model_t), intent(out) :: m
    integer, intent(out) :: status, bad, badf
    character(len=MSG_LEN), intent(out) :: msg
    badf = 0
    call model_build(nb, ctab, rpar, m, status, msg, bad, nondim=.true., &
                     lforce=model_force_size(ftab, fpar))
    if (status /= MBD_OK) return
    call model_add_dynamics(m, bmass, grav, ftab, fpar, status, msg, badf)
  end subroutine build_dynamic

  !> Energies and constraint residuals at a state: [kinetic, potential, ||Phi||, ||J q_dot - nu||]
  !! (the state in the core's units, the residuals in model units).
  subroutine state_measures(m, w, q, qd, t, e)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    real(wp), intent(in) :: q(:), qd(:), t
    real(wp), intent(out) :: e(4)
    real(wp) :: v
    call assemble_blocks(m, q, w%qz, t, w%phi, w%nu, w%gam, w%asm)
    e(3) = maxval(abs(w%phi) * m%rowunit)
    call dyn_jv(m, w, qd)        ! J q_dot from the blocks (no dense J)
    e(4) = maxval(abs(w%jv - w%nu) * m%rowunit)
    call gen_forces(m, q, qd, t, w%force, v)
    e(1) = kinetic_energy(m, qd); e(2) = v
  end subroutine state_measures

  !> Inverse dynamics: a kinematic run, then at every output the multipliers
  !! lambda (minimum norm over all rows) of J^T lambda = Q - M q_ddot, and the energies.
  !! iinfo/rinfo as api_kinematics; iinfo(2) = -force index for a bad force; rinfo(8) the
  !! multipliers' path (1 dense, 2 band: saddle-point solves, dyn_multipliers), chosen by
  !! solver as for dynamics (dyn_choose).
  subroutine api_inverse(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t0, t1, nsteps, tol, &
                         every, solver, qout, qdout, qddout, lamout, eout, iinfo, rinfo, qsing, &
                         dep, redundant, tpass, status, msg, ptab, sq, sqd, sqdd, slam, eo, &
                         evo, nev, ctl)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :), nsteps
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:), q0(:), t0, t1, tol
    integer, intent(in) :: every                !! store every k-th output (and the last)
    integer, intent(in) :: solver               !! 0 auto, 1 dense, 2 banded LU
    !> outputs (nq, kin_out_count(nsteps, every)) and likewise
    real(wp), intent(out) :: qout(:, :), qdout(:, :), qddout(:, :)
    real(wp), intent(out) :: lamout(:, :)       !! (neq, ...)
    real(wp), intent(out) :: eout(:, :)         !! (4, ...)
    integer, intent(out) :: iinfo(NINFO)
    real(wp), intent(out) :: rinfo(NINFO), qsing(:), tpass(:)
    integer, intent(out) :: dep(:), redundant(:)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    !> design parameters (2, np) and, with them, dq/dp, dq_dot/dp, dq_ddot/dp (nq, np, rows)
    !! and dlambda/dp (neq, np, rows) at the outputs
    integer, intent(in), optional :: ptab(:, :)
    real(wp), intent(out), optional, contiguous :: sq(:, :, :), sqd(:, :, :), sqdd(:, :, :), &
                                                    slam(:, :, :)
    !> contacts and friction: the element outputs (NEO, nf, rows) and the contact events found
    !! at the outputs (4, capacity), their number
    real(wp), intent(out), optional :: eo(:, :, :), evo(:, :)
    integer, intent(out), optional :: nev
    !> progress as in api_kinematics: the kinematic pass counts the outputs, the multipliers'
    !! pass counts on from there (2 x outputs in all)
    integer, intent(inout), optional, volatile :: ctl(:)
    type(model_t) :: m
    type(dyn_work_t) :: w
    type(sens_t) :: sens
    type(ev_log_t) :: log
    integer :: bad, badf, k, st, path, kl, ku
    real(wp) :: t
    logical :: changed
    character(len=MSG_LEN) :: lmsg
    lamout = zero; eout = zero
    if (present(eo)) eo = zero
    if (present(evo)) evo = zero
    if (present(nev)) nev = 0
    if (present(ptab)) then
      sq = zero; sqd = zero; sqdd = zero; slam = zero
    end if
    call build_dynamic(nb, ctab, rpar, bmass, grav, ftab, fpar, m, status, msg, bad, badf)
    if (status /= MBD_OK) then
      qout = zero; qdout = zero; qddout = zero; iinfo = 0; rinfo = zero
      iinfo(2) = bad_code(bad, badf)
      qsing = zero; dep = 0; redundant = 0; tpass = zero
      return
    end if
    ! the multipliers' path (dense or band, as dynamics; solver as for the kinematics);
    ! a dense one must fit: check before the (possibly long) kinematic run
    ! (the multipliers' sensitivities take the same path: dense J^T, or the band saddle-point
    ! factors of each output's multipliers)
    call dyn_choose(m, solver, path, kl, ku, status, msg)
    if (status == MBD_OK .and. path == SOLVER_DENSE) call dyn_memory_check(m, status, msg)
    if (status /= MBD_OK) then
      qout = zero; qdout = zero; qddout = zero; iinfo = 0; rinfo = zero
      qsing = zero; dep = 0; redundant = 0; tpass = zero
      return
    end if
    if (present(ptab)) then
      if (size(slam, 1) /= m%neq .or. any(shape(slam) /= [m%neq, shape(sq(1, :, :))])) then
        status = MBD_BAD_COUNT; msg = 'sensitivity arrays do not match the model'; return
      end if
      call sens_setup(m, ctab, rpar, ptab, sens, status, msg, bad, ftab, fpar)
      if (status /= MBD_OK) then
        iinfo = 0; iinfo(2) = -2000000 - bad; return
      end if
      call api_kinematics(nb, ctab, rpar, q0, t0, t1, nsteps, tol, 0, zero, every, solver, &
                          qout, qdout, qddout, iinfo, rinfo, qsing, dep, redundant, tpass, &
                          status, msg, ptab, sq, sqd, sqdd)
    else
      call api_kinematics(nb, ctab, rpar, q0, t0, t1, nsteps, tol, 0, zero, every, solver, &
                          qout, qdout, qddout, iinfo, rinfo, qsing, dep, redundant, tpass, &
                          status, msg, ctl=ctl)
    end if
    rinfo(8) = path
    if (iinfo(1) < 1) return
    ! the multipliers in the core's units (so the rank decisions do not depend on the unit)
    call units(m, qout, m%cunit, .true.); call units(m, qdout, m%cunit, .true.)
    call units(m, qddout, m%cunit, .true.)
    call dyn_init(m, w, qout(:, 1), t0, 1.0e-12_wp, st, lmsg, path)
    if (present(ptab)) then
      call sens_units(m, sens, sq, m%cunit, .false., back=.true.)
      call sens_units(m, sens, sqd, m%cunit, .false., back=.true.)
      call sens_units(m, sens, sqdd, m%cunit, .false., back=.true.)
    end if
    if (st == MBD_OK) then
      k = 1
      if (present(evo)) k = size(evo, 2)
      call ev_log_init(log, k, st)
      if (st /= MBD_OK) lmsg = 'not enough memory for the event log'
    end if
    if (st == MBD_NO_MEMORY) then
      status = st; msg = lmsg
    else if (st == MBD_OK) then
      do k = 1, iinfo(1)
        ! column k holds output min((k - 1) every, nsteps)
        t = t0 + (t1 - t0) * (real(min((k - 1) * every, nsteps), wp) / max(nsteps, 1))
        if (k == size(qout, 2)) t = t1
        ! contacts open and close at the outputs (the motion is given)
        if (events_active(m)) call events_switch(m, w, t, qout(:, k), qdout(:, k), log, &
                                                 changed, st)
        call dyn_multipliers(m, w, qout(:, k), qdout(:, k), qddout(:, k), t, lamout(:, k), &
                             st, lmsg)
        if (st == MBD_NO_MEMORY) then
          status = st; msg = lmsg; exit
        end if
        call state_measures(m, w, qout(:, k), qdout(:, k), t, eout(:, k))
        if (present(ctl)) then
          ctl(1) = size(qout, 2) + k
          if (ctl(2) /= 0 .and. k < iinfo(1)) then
            status = MBD_USER_ABORT; iinfo(1) = k; rinfo(1) = t
            write (msg, '(a,es12.5,a)') 'stopped on request at t = ', t, &
              ' (the outputs so far are kept)'
            exit
          end if
        end if
        if (present(eo) .and. m%nf > 0) call dyn_element_outputs(m, w, qout(:, k), &
                                                                 qdout(:, k), t, eo(:, :, k))
        if (present(ptab) .and. w%solver /= SOLVER_DENSE) then
          call sens_multipliers(m, sens, qout(:, k), qdout(:, k), qddout(:, k), t, lam= &
                                lamout(:, k), sq=sq(:, :, k), sqd=sqd(:, :, k), &
                                sqdd=sqdd(:, :, k), slam=slam(:, :, k), status=st, msg=lmsg, &
                                sw=w)
        else if (present(ptab)) then
          if (w%jt_lu) then                    ! (the LU of J^T dyn_multipliers just took)
            call sens_multipliers(m, sens, qout(:, k), qdout(:, k), qddout(:, k), t, w%jac, &
                                  lamout(:, k), sq(:, :, k), sqd(:, :, k), sqdd(:, :, k), &
                                  slam(:, :, k), st, lmsg, w%acopy, w%jpvt)
          else
            call sens_multipliers(m, sens, qout(:, k), qdout(:, k), qddout(:, k), t, w%jac, &
                                  lamout(:, k), sq(:, :, k), sqd(:, :, k), sqdd(:, :, k), &
                                  slam(:, :, k), st, lmsg)
          end if
        end if
        if (present(ptab) .and. st /= MBD_OK) then   ! (the rows before are kept)
          status = st; iinfo(1) = k - 1; rinfo(1) = t
          write (msg, '(a,es12.5,a)') 'at t = ', t, ': '//trim(lmsg)
          exit
        end if
      end do
      if (present(evo) .and. present(nev)) call events_out(m, log, evo, nev)
    end if
    call units(m, qout, m%cunit, .false.); call units(m, qdout, m%cunit, .false.)
    call units(m, qddout, m%cunit, .false.); call units(m, lamout, m%rowunit, .true.)
    if (present(ptab)) then
      call sens_units(m, sens, sq, m%cunit, .false.)
      call sens_units(m, sens, sqd, m%cunit, .false.)
      call sens_units(m, sens, sqdd, m%cunit, .false.)
      call sens_units(m, sens, slam, m%rowunit, .true.)
    end if
    if (present(eo)) call element_units(m, eo)
  end subroutine api_inverse

  !> Forward dynamics: assembly of q0, the velocity v0 projected onto J q_dot = nu (kinetic
  !! energy metric), integration with the chosen method, outputs at nsteps + 1 times of which
  !! rows k = 0, every, 2 every, ... and nsteps are stored (output_rows(nsteps, every)).
  !! iinfo: 1 outputs, 2 bad entry, 3 steps, 4 rejected, 5 Newton iterations, 6 right-hand
  !! sides, 7 iteration matrices (K, C evaluations), 8 partitions, 9 active (independent)
  !! constraint rows, 10 LU factorizations of the generalized-alpha iteration matrix, 11 1
  !! when dopri5's (partitioned's) steps became limited by stability (stiff; rinfo 11 when).
  !! rinfo: 1 time of a failure, 2 smallest step, 3 largest step, 4 factorizations of the
  !! index-1 saddle-point matrix, 5 linear solver (1 dense, 2 banded), 6 and 7 the band
  !! widths kl and ku of the saddle-point matrix (of generalized-alpha's iteration matrix
  !! for that method), 8 of the index-1 factorizations those through the Schur complement
  !! (mbd_schur; band path), 9 and 10 the partitioned method's worst rcond of J_u and when,
  !! 11 the time from which the run was stiff (iinfo 11).
  !! solver: 0 auto, 1 dense, 2 banded (dyn_choose); the band path assembles q0 by
  !! Levenberg-Marquardt in band storage (band_lm_assemble) and never allocates n x n.
  subroutine api_dynamics(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, v0, t0, t1, nsteps, &
                          method, rtol, atol, h, rho_inf, balpha, bbeta, every, qout, qdout, &
                          qddout, lamout, eout, iinfo, rinfo, redundant, status, msg, max_steps, &
                          eo, evo, nev, ctl, solver)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :), nsteps, method
    integer, intent(in) :: every                !! store every every-th output (and the last)
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:), q0(:), v0(:), t0, t1
    real(wp), intent(in) :: rtol, atol, h, rho_inf, balpha, bbeta  !! method settings
    real(wp), intent(out) :: qout(:, :), qdout(:, :), qddout(:, :)  !! (nq, rows)
    real(wp), intent(out) :: lamout(:, :)       !! (neq, rows)
    real(wp), intent(out) :: eout(:, :)         !! (4, rows) energies, drift
    integer, intent(out) :: iinfo(NINFO)
    real(wp), intent(out) :: rinfo(NINFO)
    integer, intent(out) :: redundant(:)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(in) :: max_steps            !! step limit (accepted + rejected); 0: default
    real(wp), intent(out) :: eo(:, :, :)        !! (NEO, nf, rows) element outputs
    !> (4, capacity) events [t, element (force index), kind (1 onset, 2 separation, 3 stick,
    !! 4 slip, 5 reversal), value (impact or separation speed; friction force)]
    real(wp), intent(out) :: evo(:, :)
    integer, intent(out) :: nev                 !! events (beyond size(evo, 2): not kept)
    type(ev_log_t) :: log
    !> progress as in api_kinematics (the rows stored so far; a request to stop)
    integer, intent(inout), optional, volatile :: ctl(:)
    integer, intent(in), optional :: solver     !! 0 auto (default), 1 dense, 2 banded
    type(model_t) :: m
    type(dyn_work_t) :: w
    type(kin_opts_t) :: kopts
    type(dyn_opts_t) :: opts
    type(dyn_stats_t) :: dst
    real(wp), allocatable :: q(:), qd(:)
    real(wp) :: t, lscale
    integer :: bad, badf, k, ko, nout, ierr, path, kl, ku
    iinfo = 0; rinfo = zero; redundant = 0
    qout = zero; qdout = zero; qddout = zero; lamout = zero; eout = zero
    eo = zero; evo = zero; nev = 0
    call build_dynamic(nb, ctab, rpar, bmass, grav, ftab, fpar, m, status, msg, bad, badf)
    iinfo(2) = bad_code(bad, badf)
    if (status /= MBD_OK) return
    if (.not. (finite(q0) .and. finite(v0) .and. finite(t0) .and. finite(t1) .and. &
               finite([rtol, atol, h, rho_inf, balpha, bbeta]))) then
      call not_finite('q0, v0, the times and the settings', status, msg); return
    end if
    if (nsteps < 0 .or. .not. (t1 > t0) .or. every < 1 .or. max_steps < 0) then
      status = MBD_BAD_SETTING
      msg = 'steps must be >= 0, every >= 1, max_steps >= 0 and t_end > t0'; return
    end if
    if (size(q0) /= m%nq .or. size(v0) /= m%nq .or. size(qout, 1) /= m%nq .or. &
        size(qout, 2) /= output_rows(nsteps, every) .or. size(lamout, 1) /= m%neq .or. &
        size(redundant) /= m%neq) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    call dyn_choose(m, solver_or_auto(solver), path, kl, ku, status, msg)
    if (status /= MBD_OK) return
    rinfo(5) = path; rinfo(6) = kl; rinfo(7) = ku
    ! the dense dynamics must fit (checked before the assembly allocates its dense J)
    if (path == SOLVER_DENSE) call dyn_memory_check(m, status, msg)
    if (status /= MBD_OK) return
    lscale = m%lscale
    allocate (q(m%nq), qd(m%nq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * 2 * real(m%nq, wp), 'the state vectors', &
                    'use a smaller model', status, msg)
      return
    end if
    q = q0 / m%cunit
    ! assembly at t0 (Levenberg-Marquardt; any number of equations)
    call assemble_start(m, path, q, t0, kopts, status, msg)
    if (status /= MBD_OK) then
      rinfo(1) = t0; return
    end if
    ! partitioned: the method for runs through singular configurations keeps the LU of the
    ! saddle-point matrix, whose error grows like cond, not cond^2 as the Schur complement's
    call dyn_init(m, w, q, t0, kopts%tol * lscale, status, msg, path, &
                  schur=method /= METH_PARTITIONED)
    if (status /= MBD_OK) return
    rinfo(6) = w%sd%kl; rinfo(7) = w%sd%ku
    iinfo(9) = w%na
    redundant = 1                            ! (a loop over the active rows: O(neq))
    do k = 1, w%na
      redundant(w%rows(k)) = 0
    end do
    call dyn_velocity(m, w, q, t0, v0 / m%cunit, qd, status)
    if (status /= MBD_OK) then
      msg = 'the initial velocities cannot be made consistent: the mass matrix is singular '// &
            'on the motions the constraints allow (a body without mass or inertia?)'
      return
    end if
    opts%method = method
    if (rtol > zero) opts%rtol = rtol
    if (atol > zero) opts%atol = atol
    opts%h = max(h, zero)
    if (rho_inf >= zero) opts%rho_inf = min(rho_inf, one)
    if (balpha >= zero) opts%balpha = balpha
    if (bbeta >= zero) opts%bbeta = bbeta
    if (max_steps > 0) opts%max_steps = max_steps
    if (size(eo, 1) /= NEO .or. size(eo, 2) /= m%nf .or. size(eo, 3) /= size(qout, 2)) then
      status = MBD_BAD_COUNT; msg = 'element output array sizes do not match the model'; return
    end if
    call ev_log_init(log, size(evo, 2), status)
    if (status /= MBD_OK) then
      msg = 'not enough memory for the event log'; return
    end if
    call integrate(m, w, q, qd, t0, t1, nsteps, every, opts, qout, qdout, qddout, lamout, nout, &
                   dst, status, msg, log, eo, ctl)
    call events_out(m, log, evo, nev)
    call dyn_info(w, dst, nout, status, iinfo, rinfo)
    do k = 1, nout
      ko = output_index(nsteps, every, k)
      t = t0 + (t1 - t0) * (real(ko, wp) / max(nsteps, 1))
      if (ko == nsteps) t = t1
      call state_measures(m, w, qout(:, k), qdout(:, k), t, eout(:, k))
    end do
    call units(m, qout, m%cunit, .false.); call units(m, qdout, m%cunit, .false.)
    call units(m, qddout, m%cunit, .false.); call units(m, lamout, m%rowunit, .true.)
    call element_units(m, eo)
  end subroutine api_dynamics

  !> The integrator's counters into iinfo and rinfo (api_dynamics' layout).
  subroutine dyn_info(w, dst, nout, status, iinfo, rinfo)
    type(dyn_work_t), intent(in) :: w
    type(dyn_stats_t), intent(in) :: dst
    integer, intent(in) :: nout, status
    integer, intent(inout) :: iinfo(NINFO)
    real(wp), intent(inout) :: rinfo(NINFO)
    iinfo(1) = nout; iinfo(3) = dst%steps; iinfo(4) = dst%rejected; iinfo(5) = dst%newton
    iinfo(6) = dst%rhs; iinfo(7) = dst%jacobians; iinfo(8) = dst%partitions
    iinfo(10) = dst%factorizations
    rinfo(2) = dst%hmin; rinfo(3) = dst%hmax
    ! saddle-point factorizations (index-1, and generalized-alpha's when they go through S),
    ! of them through the Schur complement
    rinfo(4) = w%sd%nfactor; rinfo(8) = w%sd%nschur
    if (dst%schur > 0) then
      rinfo(4) = rinfo(4) + dst%factorizations; rinfo(8) = rinfo(8) + dst%schur
    end if
    if (dst%rc_min < huge(one)) then          ! partitioned: J_u's worst conditioning
      rinfo(9) = dst%rc_min; rinfo(10) = dst%t_rc_min
    end if
    if (dst%t_stiff < huge(one)) then         ! dopri5, partitioned: steps set by stability
      iinfo(11) = 1; rinfo(11) = dst%t_stiff
    end if
    if (dst%kl > 0) then                      ! generalized-alpha: its iteration matrix's
      rinfo(6) = dst%kl; rinfo(7) = dst%ku
    end if
    if (status /= MBD_OK) rinfo(1) = dst%t_fail
  end subroutine dyn_info

  !> The assembly at the start of dynamics and statics: Levenberg-Marquardt from the q0
  !! estimates to ||Phi||_inf <= tol (relative to the length scale), with a dense J
  !! (kin_assemble, with its diagnosis of contradicting redundant constraints) or in band
  !! storage (band_lm_assemble).
  subroutine assemble_start(m, path, q, t, kopts, status, msg)
    type(model_t), intent(in) :: m              !! model
    integer, intent(in) :: path                 !! SOLVER_DENSE or SOLVER_BANDED
    real(wp), intent(inout) :: q(:)             !! estimates, then assembled (core units)
    real(wp), intent(in) :: t                   !! time
    type(kin_opts_t), intent(in) :: kopts       !! settings (tol, assembly_maxit)
    integer, intent(out) :: status              !! MBD_OK or the assembly's failure
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(kin_work_t) :: kw
    type(kin_report_t) :: rep
    integer :: ierr, worst
    real(wp) :: resid
    msg = ''
    if (path /= SOLVER_DENSE) then
      call band_lm_assemble(m, q, t, kopts%tol * m%lscale, kopts%assembly_maxit, status, msg, &
                        worst, resid)
      return
    end if
    call kin_work_init(m, kw, status, msg)
    if (status /= MBD_OK) return
    kw%tol = kopts%tol * m%lscale
    allocate (rep%qsing(m%nq), rep%dep(m%neq), rep%redundant(m%neq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * (real(m%nq, wp) + m%neq), 'the assembly report', &
                    'use a smaller model', status, msg)
      return
    end if
    call kin_assemble(m, kw, q, t, kopts, rep, status, msg)
  end subroutine assemble_start

  !> Static equilibrium near the assembled q0 at time t, its multipliers and stability
  !! (1 stable, 0 unstable, -1 neutral, 2 no free motion). solver: 0 auto, 1 dense,
  !! 2 banded (dyn_choose); iinfo(5) the path taken (1 dense, 2 banded), iinfo(6), iinfo(7)
  !! the band widths of the saddle-point matrix.
  subroutine api_statics(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, q, lam, stable, resid, &
                         iinfo, status, msg, ptab, sq, slam, solver)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :)
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:), q0(:), t
    real(wp), intent(out) :: q(:), lam(:), resid
    integer, intent(out) :: stable, iinfo(NINFO)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    !> design parameters (2, np) and, with them, dq/dp (nq, np) and dlambda/dp (neq, np) at
    !! the equilibrium
    integer, intent(in), optional :: ptab(:, :)
    real(wp), intent(out), optional :: sq(:, :), slam(:, :)
    integer, intent(in), optional :: solver     !! 0 auto (default), 1 dense, 2 banded
    type(model_t) :: m
    type(dyn_work_t) :: w
    !> the design sensitivities' blocks: the parameters' (ptab) and the exact stiffness of
    !! the statics' Newton steps (no contacts; not allocated: K by differences)
    type(sens_t), allocatable :: sens
    integer :: bad
    q = zero; lam = zero; stable = 0; resid = zero
    call static_start(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, m, w, q, lam, iinfo, &
                      status, msg, solver)
    if (status == MBD_OK .and. present(ptab)) then
      sq = zero; slam = zero
      if (any(shape(sq) /= [m%nq, size(ptab, 2)]) .or. &
          any(shape(slam) /= [m%neq, size(ptab, 2)])) then
        status = MBD_BAD_COUNT; msg = 'sensitivity arrays do not match the model'; return
      end if
      allocate (sens, stat=bad)
      if (bad /= 0) then
        status = MBD_NO_MEMORY; msg = 'statics: out of memory for the sensitivities'; return
      end if
      call sens_setup(m, ctab, rpar, ptab, sens, status, msg, bad, ftab, fpar)
      if (status /= MBD_OK) then
        iinfo(2) = -2000000 - bad; return
      end if
    else if (status == MBD_OK) then
      call stiffness_blocks(m, ctab, rpar, ftab, fpar, sens)
    end if
    if (status == MBD_OK) then
      if (smooth_forces(ftab) .and. allocated(sens)) then
        call statics_solve(m, w, q, t, lam, stable, resid, status, msg, s=sens)
      else
        call statics_solve(m, w, q, t, lam, stable, resid, status, msg)
      end if
    end if
    if (status == MBD_OK .and. present(ptab)) then
      if (w%solver == SOLVER_DENSE) then
        call sens_statics(m, sens, w%rows, q, t, lam, sq, slam, status, msg)
      else                                      ! (null-space form, no n x n array)
        call sens_statics_band(m, w, sens, q, t, lam, sq, slam, status, msg)
      end if
      call sens_units2(m, sens, sq, m%cunit, .false.)
      call sens_units2(m, sens, slam, m%rowunit, .true.)
    end if
    if (allocated(m%cunit)) then
      q = q * m%cunit; lam = lam / m%rowunit
    end if
  end subroutine api_statics

  !> The start of statics and modes: the model built, q0 assembled at t (core units in q),
  !! the dynamics work arrays on the chosen path (iinfo(2) a bad entry, iinfo(5) the path,
  !! iinfo(6), iinfo(7) the band widths).
  subroutine static_start(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, m, w, q, lam, &
                          iinfo, status, msg, solver)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :)
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:), q0(:), t
    type(model_t), intent(out) :: m
    type(dyn_work_t), intent(out) :: w
    real(wp), intent(inout) :: q(:)             !! (nq) the assembled q0 (core units)
    real(wp), intent(in) :: lam(:)              !! (neq) the caller's multipliers (sizes)
    integer, intent(out) :: iinfo(NINFO)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(in), optional :: solver     !! 0 auto (default), 1 dense, 2 banded
    type(kin_opts_t) :: kopts
    integer :: bad, badf, path, kl, ku
    iinfo = 0
    call build_dynamic(nb, ctab, rpar, bmass, grav, ftab, fpar, m, status, msg, bad, badf)
    iinfo(2) = bad_code(bad, badf)
    if (status /= MBD_OK) return
    if (.not. (finite(q0) .and. finite(t))) then
      call not_finite('q0 and t', status, msg); return
    end if
    if (size(q0) /= m%nq .or. size(q) /= m%nq .or. size(lam) /= m%neq) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    call dyn_choose(m, solver_or_auto(solver), path, kl, ku, status, msg)
    if (status /= MBD_OK) return
    iinfo(5) = path; iinfo(6) = kl; iinfo(7) = ku
    if (path == SOLVER_DENSE) call dyn_memory_check(m, status, msg)
    if (status /= MBD_OK) return
    q = q0 / m%cunit
    call assemble_start(m, path, q, t, kopts, status, msg)
    if (status == MBD_OK) call dyn_init(m, w, q, t, kopts%tol * m%lscale, status, msg, path)
    if (status == MBD_OK) then
      iinfo(6) = w%sd%kl; iinfo(7) = w%sd%ku
    end if
  end subroutine static_start

  !> Small vibrations about the equilibrium near q0 at t (equilibrium 1; 0: about the
  !! assembled q0 itself, with its least-squares multipliers): the lowest kmax undamped
  !! omega^2 and mode shapes (model units, phi^T M phi = 1), 2 kmax damped eigenvalues
  !! (mbd_modes), the configuration, multipliers, stability and residual as api_statics;
  !! iinfo(1) the number of free motions.
  subroutine api_modes(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, equilibrium, kmax, q, &
                       lam, stable, resid, omega2, kinds, sre, sim, shapes, iinfo, status, msg, &
                       solver, zre, zim)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :), equilibrium, kmax
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:), q0(:), t
    real(wp), intent(out) :: q(:), lam(:), resid, omega2(:), sre(:), sim(:), shapes(:, :)
    integer, intent(out) :: kinds(:)            !! (kmax) 1 vibration, 0 rigid, -1 unstable
    integer, intent(out) :: stable, iinfo(NINFO)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(in), optional :: solver     !! 0 auto (default), 1 dense, 2 banded
    !> (nq, 2 kmax) the damped shapes of the sorted eigenvalues, real and imaginary parts,
    !! each scaled so that its largest entry is 1 (model units)
    real(wp), intent(out), optional :: zre(:, :), zim(:, :)
    type(model_t) :: m
    type(dyn_work_t) :: w
    type(sens_t), allocatable :: sens
    integer :: nfree, i
    logical :: cshapes
    q = zero; lam = zero; stable = 0; resid = zero
    omega2 = zero; sre = zero; sim = zero; shapes = zero; kinds = 0
    cshapes = present(zre) .and. present(zim)
    if (cshapes) then
      zre = zero; zim = zero
    end if
    if (kmax < 0 .or. size(omega2) < kmax .or. size(kinds) < kmax .or. size(sre) < 2 * kmax .or. &
        size(sim) < 2 * kmax .or. size(shapes, 2) < kmax) then
      status = MBD_BAD_COUNT; msg = 'modes: the output arrays do not hold kmax modes'
      iinfo = 0; return
    end if
    call static_start(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, m, w, q, lam, iinfo, &
                      status, msg, solver)
    if (status == MBD_OK .and. size(shapes, 1) /= m%nq) then
      status = MBD_BAD_COUNT; msg = 'modes: the shapes array does not match the model'
    end if
    if (status == MBD_OK .and. cshapes) then
      if (size(zre, 1) /= m%nq .or. size(zim, 1) /= m%nq .or. size(zre, 2) < 2 * kmax .or. &
          size(zim, 2) < 2 * kmax) then
        status = MBD_BAD_COUNT; msg = 'modes: the damped shapes'' arrays do not match the model'
      end if
    end if
    ! K and C exact (the design sensitivities' blocks) unless contacts or friction (not
    ! allocated: absent, K and C by differences), in the statics' steps and then at rest
    if (status == MBD_OK) call stiffness_blocks(m, ctab, rpar, ftab, fpar, sens)
    if (status == MBD_OK) call linear_point(m, w, q, t, equilibrium, lam, stable, resid, &
                                            status, msg, sens)
    if (status == MBD_OK .and. allocated(sens)) call sens_at_rest(m, sens, q, t, lam, w%qz)
    if (status == MBD_OK) then
      if (cshapes) then
        call modes_solve(m, w, q, t, lam, kmax, nfree, omega2, kinds, sre, sim, &
                         shapes(:, 1:kmax), status, msg, zre(:, 1:2 * kmax), &
                         zim(:, 1:2 * kmax), s=sens)
      else
        call modes_solve(m, w, q, t, lam, kmax, nfree, omega2, kinds, sre, sim, &
                         shapes(:, 1:kmax), status, msg, s=sens)
      end if
    end if
    if (status == MBD_OK) iinfo(1) = nfree
    if (allocated(m%cunit)) then
      q = q * m%cunit; lam = lam / m%rowunit
      do i = 1, m%nq
        shapes(i, :) = shapes(i, :) * m%cunit(i)
        if (cshapes) then
          zre(i, :) = zre(i, :) * m%cunit(i); zim(i, :) = zim(i, :) * m%cunit(i)
        end if
      end do
    end if
    if (status == MBD_OK .and. cshapes) call unit_largest(zre(:, 1:2 * kmax), zim(:, 1:2 * kmax))
  end subroutine api_modes

  !> The design sensitivities' blocks without parameters (sens allocated and set up), for the
  !! exact stiffness and damping, when the forces are smooth (no contact, no joint friction)
  !! and the blocks can be had; else sens stays unallocated, and K and C are taken by
  !! differences.
  subroutine stiffness_blocks(m, ctab, rpar, ftab, fpar, sens)
    type(model_t), intent(in) :: m              !! model with dynamics data
    integer, intent(in) :: ctab(:, :), ftab(:, :)
    real(wp), intent(in) :: rpar(:), fpar(:)
    type(sens_t), allocatable, intent(inout) :: sens
    integer :: ptab0(2, 0), bad, st
    character(len=MSG_LEN) :: text
    if (.not. smooth_forces(ftab)) return
    allocate (sens, stat=bad)
    if (bad /= 0) return
    call sens_setup(m, ctab, rpar, ptab0, sens, st, text, bad, ftab, fpar)
    if (st /= MBD_OK) deallocate (sens)
  end subroutine stiffness_blocks

  !> No contact and no joint friction among the forces (ftab (NFT, nf)): the design
  !! sensitivities' exact derivatives cover them.
  pure logical function smooth_forces(ftab)
    integer, intent(in) :: ftab(:, :)
    integer :: c
    smooth_forces = .true.
    do c = 1, size(ftab, 2)
      if (force_is_contact(ftab(1, c)) .or. ftab(1, c) == FRC_FRICTION) smooth_forces = .false.
    end do
  end function smooth_forces

  !> The frequency response about the equilibrium near q0 at t (equilibrium 1; 0: about the
  !! assembled q0, with its least-squares multipliers) to each design parameter of ptab
  !! (2, np) varied harmonically at each angular frequency omega (rad/s): dq = (hre + i him)
  !! times the parameter's amplitude (nq, np, nomega; model units, mbd_frf), with the
  !! configuration, multipliers, stability and residual as api_statics. iinfo(1) the number of
  !! free motions, iinfo(8) the frequency at which the response is unbounded (MBD_SINGULAR).
  !! lre + i lim (neq, np, nomega): the multipliers' response, when asked for.
  subroutine api_frf(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, equilibrium, ptab, omega, &
                     q, lam, stable, resid, hre, him, iinfo, status, msg, solver, lre, lim)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :), equilibrium, ptab(:, :)
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:), q0(:), t, omega(:)
    real(wp), intent(out) :: q(:), lam(:), resid, hre(:, :, :), him(:, :, :)
    integer, intent(out) :: stable, iinfo(NINFO)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(in), optional :: solver     !! 0 auto (default), 1 dense, 2 banded
    real(wp), intent(out), optional :: lre(:, :, :), lim(:, :, :)
    type(model_t) :: m
    type(dyn_work_t) :: w
    type(sens_t) :: sens
    integer :: ibad
    logical :: mult
    q = zero; lam = zero; stable = 0; resid = zero; hre = zero; him = zero
    mult = present(lre) .and. present(lim)
    if (mult) then
      lre = zero; lim = zero
    end if
    call static_start(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, m, w, q, lam, iinfo, &
                      status, msg, solver)
    if (status == MBD_OK) then
      if (any(shape(hre) /= [m%nq, size(ptab, 2), size(omega)]) .or. &
          any(shape(him) /= shape(hre))) then
        status = MBD_BAD_COUNT; msg = 'frequency response: the output arrays do not match'
      else if (.not. finite(omega)) then
        call not_finite('the frequencies', status, msg)
      end if
      if (mult .and. status == MBD_OK) then
        if (any(shape(lre) /= [m%neq, size(ptab, 2), size(omega)]) .or. &
            any(shape(lim) /= shape(lre))) then
          status = MBD_BAD_COUNT; msg = 'frequency response: the output arrays do not match'
        end if
      end if
    end if
    if (status == MBD_OK) call linear_setup(m, w, sens, ctab, rpar, ftab, fpar, ptab, q, t, &
                                            equilibrium, lam, stable, resid, iinfo, status, msg)
    if (status == MBD_OK) then
      if (mult) then
        call frf_solve(m, w, sens, q, t, lam, omega, hre, him, ibad, status, msg, lre, lim)
      else
        call frf_solve(m, w, sens, q, t, lam, omega, hre, him, ibad, status, msg)
      end if
      iinfo(1) = m%nq - w%na; iinfo(8) = ibad
    end if
    if (allocated(m%cunit)) then
      q = q * m%cunit; lam = lam / m%rowunit
      if (status == MBD_OK) then
        call sens_units(m, sens, hre, m%cunit, .false.)
        call sens_units(m, sens, him, m%cunit, .false.)
        if (mult) then
          call sens_units(m, sens, lre, m%rowunit, .true.)
          call sens_units(m, sens, lim, m%rowunit, .true.)
        end if
      end if
    end if
  end subroutine api_frf

  !> The linearized motion about the equilibrium (or q0) as a state-space system with the
  !! design parameters of ptab as inputs and the coordinates as outputs (mbd_linear):
  !! x' = A x + B p, dq = C x + D p, in the leading 2 nfree states of a, b, c (model units:
  !! C's rows and D in the coordinates' units, B and D per unit of each parameter; the states
  !! are not scaled). iinfo(1) = nfree; MBD_BAD_COUNT when the arrays hold fewer states than
  !! 2 nfree (call again with that many). With velocities /= 0, c and d have 2 nq rows: the
  !! coordinates', then their velocities' (C A, C B; MBD_BAD_SETTING naming the input in
  !! iinfo(2) when D /= 0: that input moves the mechanism directly, its velocities by p').
  !! With multipliers /= 0, neq rows more (after those): the drivers' multipliers (a driver's
  !! effort is -lambda on its row; the other rows 0; MBD_BAD_SETTING naming the input whose
  !! rate or acceleration moves them: it acts on the constraints directly).
  subroutine api_linearize(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, equilibrium, ptab, &
                           q, lam, stable, resid, a, b, c, d, iinfo, status, msg, solver, &
                           velocities, multipliers)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :), equilibrium, ptab(:, :)
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:), q0(:), t
    real(wp), intent(out) :: q(:), lam(:), resid, a(:, :), b(:, :), c(:, :), d(:, :)
    integer, intent(out) :: stable, iinfo(NINFO)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(in), optional :: solver     !! 0 auto (default), 1 dense, 2 banded
    integer, intent(in), optional :: velocities !! 1: the velocities' outputs too
    integer, intent(in), optional :: multipliers !! 1: the multipliers' outputs too
    type(model_t) :: m
    type(dyn_work_t) :: w
    type(sens_t) :: sens
    real(wp), allocatable :: ones(:)
    integer :: bad, nfree, i, ns, nqo, nv, improper
    logical :: vel, mult
    q = zero; lam = zero; stable = 0; resid = zero; a = zero; b = zero; c = zero; d = zero
    call static_start(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, m, w, q, lam, iinfo, &
                      status, msg, solver)
    ns = size(a, 1)
    vel = .false.
    if (present(velocities)) vel = velocities /= 0
    mult = .false.
    if (present(multipliers)) mult = multipliers /= 0
    nv = merge(2, 1, vel) * size(q)              ! the coordinates' (and velocities') rows
    nqo = nv + merge(size(lam), 0, mult)
    if (status == MBD_OK) then
      if (size(a, 2) /= ns .or. size(b, 1) /= ns .or. size(c, 2) /= ns .or. &
          size(b, 2) /= size(ptab, 2) .or. size(c, 1) /= nqo .or. &
          any(shape(d) /= [nqo, size(ptab, 2)])) then
        status = MBD_BAD_COUNT; msg = 'linearized system: the output arrays do not match'
      end if
    end if
    if (status == MBD_OK) call linear_setup(m, w, sens, ctab, rpar, ftab, fpar, ptab, q, t, &
                                            equilibrium, lam, stable, resid, iinfo, status, msg)
    if (status == MBD_OK .and. mult) then
      if (vel) then
        call linear_state_space(m, w, sens, q, t, lam, a, b, c(1:m%nq, :), d(1:m%nq, :), &
                                nfree, status, msg, c(m%nq + 1:nv, :), d(m%nq + 1:nv, :), &
                                c(nv + 1:, :), d(nv + 1:, :), improper)
      else
        call linear_state_space(m, w, sens, q, t, lam, a, b, c(1:m%nq, :), d(1:m%nq, :), &
                                nfree, status, msg, cl=c(nv + 1:, :), dl=d(nv + 1:, :), &
                                improper=improper)
      end if
      iinfo(1) = nfree
      if (status == MBD_OK .and. improper > 0) then
        status = MBD_BAD_SETTING; iinfo(2) = -2000000 - improper
        msg = 'effort outputs: this input moves the constraints directly, so the efforts '// &
              'would need its rate or acceleration; take the positions alone, or an input '// &
              'that acts through a force'
      end if
      if (vel) call velocities_need_no_d()
    else if (status == MBD_OK .and. vel) then
      call linear_state_space(m, w, sens, q, t, lam, a, b, c(1:m%nq, :), d(1:m%nq, :), &
                              nfree, status, msg, c(m%nq + 1:, :), d(m%nq + 1:, :))
      iinfo(1) = nfree
      call velocities_need_no_d()
    else if (status == MBD_OK) then
      call linear_state_space(m, w, sens, q, t, lam, a, b, c, d, nfree, status, msg)
      iinfo(1) = nfree
    end if
    if (allocated(m%cunit)) then
      q = q * m%cunit; lam = lam / m%rowunit
      if (status == MBD_OK) then
        allocate (ones(ns), source=one, stat=bad)
        if (bad /= 0) then
          call mem_fail(REAL_BYTES * ns, 'the linearized system''s units', &
                        'use a model with fewer free motions', status, msg)
          return
        end if
        call sens_units2(m, sens, b, ones, .false.)         ! per unit of each parameter
        call sens_units2(m, sens, d(1:m%nq, :), m%cunit, .false.)
        if (vel) call sens_units2(m, sens, d(m%nq + 1:nv, :), m%cunit, .false.)
        if (mult) call sens_units2(m, sens, d(nv + 1:, :), m%rowunit, .true.)
        do i = 1, ns
          c(1:m%nq, i) = c(1:m%nq, i) * m%cunit
          if (vel) c(m%nq + 1:nv, i) = c(m%nq + 1:nv, i) * m%cunit
          if (mult) c(nv + 1:, i) = c(nv + 1:, i) / m%rowunit
        end do
      end if
    end if
  contains
    !> MBD_BAD_SETTING naming the first input with D /= 0 (the velocities need D = 0).
    subroutine velocities_need_no_d()
      integer :: kk
      do kk = 1, size(ptab, 2)
        if (status == MBD_OK .and. any(abs(d(1:m%nq, kk)) > zero)) then
          status = MBD_BAD_SETTING; iinfo(2) = -2000000 - kk
          msg = 'velocity outputs: this input moves the mechanism directly (D /= 0), so '// &
                'its velocities would need the input''s rate; take the positions alone, '// &
                'or an input that acts through a force'
        end if
      end do
    end subroutine velocities_need_no_d
  end subroutine api_linearize

  !> The inputs of the frequency response and the linearized system as design parameters
  !! (sens_setup; a refused one named in iinfo(2)), then the point they linearize about
  !! (linear_point; the statics' steps with the exact stiffness when the forces are smooth).
  subroutine linear_setup(m, w, sens, ctab, rpar, ftab, fpar, ptab, q, t, equilibrium, lam, &
                          stable, resid, iinfo, status, msg)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! work arrays (dyn_init done)
    type(sens_t), intent(inout) :: sens         !! the inputs, set up here
    integer, intent(in) :: ctab(:, :), ftab(:, :), ptab(:, :), equilibrium
    real(wp), intent(in) :: rpar(:), fpar(:), t
    real(wp), intent(inout) :: q(:)             !! q0 assembled, then the point (core units)
    real(wp), intent(out) :: lam(:), resid      !! multipliers, statics' residual
    integer, intent(out) :: stable              !! as linear_point
    integer, intent(inout) :: iinfo(NINFO)      !! iinfo(2): a refused input
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer :: bad
    stable = 0; resid = zero; lam = zero
    call sens_setup(m, ctab, rpar, ptab, sens, status, msg, bad, ftab, fpar)
    if (status /= MBD_OK) then
      iinfo(2) = -2000000 - bad; return
    end if
    if (smooth_forces(ftab)) then
      call linear_point(m, w, q, t, equilibrium, lam, stable, resid, status, msg, sens)
    else
      call linear_point(m, w, q, t, equilibrium, lam, stable, resid, status, msg)
    end if
  end subroutine linear_setup

  !> The point modes and the frequency response linearize about: the equilibrium near q
  !! (equilibrium /= 0, statics), or q itself with its least-squares multipliers (stable -2:
  !! not examined).
  subroutine linear_point(m, w, q, t, equilibrium, lam, stable, resid, status, msg, s)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! work arrays (dyn_init done)
    real(wp), intent(inout) :: q(:)             !! q0 assembled, then the point (core units)
    real(wp), intent(in) :: t                   !! time
    integer, intent(in) :: equilibrium          !! 1: seek the equilibrium; 0: q as given
    real(wp), intent(out) :: lam(:), resid      !! multipliers, statics' residual
    integer, intent(out) :: stable              !! as api_statics; -2 not examined
    integer, intent(out) :: status              !! MBD_OK or the solvers' status
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    !> the design sensitivities' blocks (no contacts): the statics' stiffness exact
    type(sens_t), intent(inout), optional :: s
    resid = zero
    if (equilibrium /= 0) then
      call statics_solve(m, w, q, t, lam, stable, resid, status, msg, s)
    else
      stable = -2
      call dyn_multipliers(m, w, q, w%qz, w%qz, t, lam, status, msg)
    end if
  end subroutine linear_point

  !> An optional solver argument: 0 (auto) when absent.
  pure integer function solver_or_auto(solver)
    integer, intent(in), optional :: solver     !! 0 auto, 1 dense, 2 banded
    solver_or_auto = SOLVER_AUTO
    if (present(solver)) solver_or_auto = solver
  end function solver_or_auto

  !> Reactions of every constraint at many states: reac(6, nc, nt) global
  !! [Fx_i, Fy_i, Mz_i, Fx_j, Fy_j, Mz_j], rloc the same in the body frames.
  subroutine api_reactions(nb, ctab, rpar, q, t, lam, reac, rloc, status, msg)
    integer, intent(in) :: nb, ctab(:, :)
    real(wp), intent(in) :: rpar(:), q(:, :), t(:), lam(:, :)
    real(wp), intent(out) :: reac(:, :, :), rloc(:, :, :)
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(model_t) :: m
    type(dyn_work_t) :: w
    integer :: bad, k, ierr
    reac = zero; rloc = zero
    call model_build(nb, ctab, rpar, m, status, msg, bad)
    if (status /= MBD_OK) return
    if (.not. (finite(q) .and. finite(t) .and. finite(lam))) then
      call not_finite('q, t and lambda', status, msg); return
    end if
    if (size(q, 1) /= m%nq .or. size(lam, 1) /= m%neq .or. size(reac, 2) /= m%nc .or. &
        size(q, 2) /= size(t) .or. size(lam, 2) /= size(t) .or. size(reac, 3) /= size(t)) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    allocate (w%phi(m%neq), w%nu(m%neq), w%gam(m%neq), w%qz(m%nq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * (3 * real(m%neq, wp) + m%nq), 'the reaction work arrays', &
                    'use a smaller model', status, msg)
      return
    end if
    call asm_init(m, w%asm, status, msg)
    if (status /= MBD_OK) return
    w%qz = zero
    do k = 1, size(t)
      call dyn_reactions(m, w, q(:, k), t(k), lam(:, k), reac(:, :, k), rloc(:, :, k))
    end do
  end subroutine api_reactions

  !> Changes of Phi, J, nu and gamma along a direction (dq, dq_dot) and one design parameter
  !! (ptab(:, 1); an empty table: none) at (q, q_dot, t), each evaluated analytically on dual
  !! numbers (mbd_dual): Phi_q dq + Phi_p, J_q dq + J_p, nu_p, gamma_q dq + gamma_q_dot dq_dot
  !! + gamma_p. For checks by finite differences.
  subroutine api_eval_d(nb, ctab, rpar, q, qd, t, dq, dqd, ptab, tphi, tjac, tnu, tgam, status, &
                        msg, bad)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q(:), qd(:)         !! state (nq)
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(in) :: dq(:), dqd(:)       !! direction (nq)
    integer, intent(in) :: ptab(:, :)           !! (2, 0 or 1) the parameter
    real(wp), intent(out) :: tphi(:)            !! change of Phi (neq)
    real(wp), intent(out) :: tjac(:, :)         !! change of J (neq x nq)
    real(wp), intent(out) :: tnu(:), tgam(:)    !! changes of nu, gamma (neq)
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer, intent(out) :: bad                 !! offending constraint, or 0
    type(model_t) :: m
    type(asm_work_t) :: aw
    type(sens_t) :: sens
    integer :: k
    tphi = zero; tjac = zero; tnu = zero; tgam = zero
    call model_build(nb, ctab, rpar, m, status, msg, bad)
    if (status /= MBD_OK) return
    if (.not. (finite(q) .and. finite(qd) .and. finite(t) .and. finite(dq) .and. &
               finite(dqd))) then
      call not_finite('the state and the direction', status, msg); return
    end if
    if (size(q) /= m%nq .or. size(qd) /= m%nq .or. size(dq) /= m%nq .or. &
        size(dqd) /= m%nq .or. size(tphi) /= m%neq .or. size(tjac, 1) /= m%neq .or. &
        size(tjac, 2) /= m%nq .or. size(ptab, 2) > 1) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    call sens_setup(m, ctab, rpar, ptab, sens, status, msg, bad)
    if (status /= MBD_OK) return
    k = size(ptab, 2)
    call asm_init(m, aw, status, msg)
    if (status /= MBD_OK) return
    call sens_trig(m, sens, q)
    call sens_eval_d(m, sens, k, q, qd, dq, dqd, t, tphi, tnu, tgam, aw%jb)
    call scatter_dense(aw, tjac)
  end subroutine api_eval_d

  !> The applied generalized forces Q(q, q_dot, t) and their changes along nk directions
  !! (columns of dq, dqd), direction k together with design parameter k (column k of ptab),
  !! by both of the core's paths: dcol as inverse dynamics and statics take them
  !! (sens_force_dm, direction by direction), drow as the dopri5 sensitivities (sens_force_rows,
  !! the directions as rows). The model in its own units (no length scale).
  subroutine api_forces_d(nb, ctab, rpar, bmass, grav, ftab, fpar, q, qd, t, dq, dqd, ptab, &
                          qf, dcol, drow, status, msg, bad)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :)  !! bodies, constraint and force tables
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:)
    real(wp), intent(in) :: q(:), qd(:), t      !! state (nq), time
    real(wp), intent(in) :: dq(:, :), dqd(:, :) !! directions (nq, nk)
    integer, intent(in) :: ptab(:, :)           !! (2, nk) the parameters
    real(wp), intent(out) :: qf(:)              !! Q (nq)
    real(wp), intent(out) :: dcol(:, :), drow(:, :)  !! changes of Q (nq, nk)
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer, intent(out) :: bad                 !! offending entry, or 0
    type(model_t) :: m
    type(sens_t) :: sens
    real(wp), allocatable :: st(:, :), sdt(:, :), rt(:, :)
    real(wp) :: v
    integer :: badf, nk, npd, k, ist
    qf = zero; dcol = zero; drow = zero; bad = 0
    call model_build(nb, ctab, rpar, m, status, msg, bad, lforce=model_force_size(ftab, fpar))
    if (status /= MBD_OK) return
    call model_add_dynamics(m, bmass, grav, ftab, fpar, status, msg, badf)
    if (status /= MBD_OK) then
      bad = -badf; return
    end if
    if (.not. (finite(q) .and. finite(qd) .and. finite(t) .and. finite(dq) .and. &
               finite(dqd))) then
      call not_finite('the state and the directions', status, msg); return
    end if
    nk = size(ptab, 2)
    if (size(q) /= m%nq .or. size(qd) /= m%nq .or. any(shape(dq) /= [m%nq, nk]) .or. &
        any(shape(dqd) /= [m%nq, nk]) .or. size(qf) /= m%nq .or. &
        any(shape(dcol) /= [m%nq, nk]) .or. any(shape(drow) /= [m%nq, nk]) .or. nk < 1) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    call sens_setup(m, ctab, rpar, ptab, sens, status, msg, bad, ftab, fpar)
    if (status /= MBD_OK) return
    call gen_forces(m, q, qd, t, qf, v)
    call sens_force_dm(m, sens, 1, nk, q, qd, m%nq, dq, dqd, t, dcol)
    npd = 4 * ((nk + 3) / 4)
    allocate (st(npd, m%nq), sdt(npd, m%nq), rt(npd, m%nq), stat=ist)
    if (ist /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory'; return
    end if
    st = zero; sdt = zero; rt = zero
    st(1:nk, :) = transpose(dq); sdt(1:nk, :) = transpose(dqd)
    call sens_trig(m, sens, q)                   ! (the bodies' cos and sin it takes)
    call sens_force_rows(m, sens, q, qd, t, npd, st, sdt, rt)
    do k = 1, nk
      drow(:, k) = rt(k, :)
    end do
  end subroutine api_forces_d

  !> K = d(J^T lambda - Q)/dq and C = -dQ/dq_dot at (q, t) with the multipliers lam, exact
  !! (the design sensitivities' blocks; a model without contacts or joint friction), as dense
  !! (nq, nq) arrays by the core's two paths: kpat, cpat read off one product per colour group
  !! of the tangent's sparse pattern (sens_tangent_pattern: the statics' Newton matrix), kcol,
  !! ccol a product per column (sens_stiffness_mul, sens_damping_mul: the modes and the
  !! frequency response). For checks by finite differences.
  subroutine api_stiffness(nb, ctab, rpar, bmass, grav, ftab, fpar, q, t, lam, kpat, cpat, &
                           kcol, ccol, status, msg, bad)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :)  !! bodies, constraint and force tables
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:)
    real(wp), intent(in) :: q(:), t, lam(:)     !! state (nq), time, multipliers (neq)
    real(wp), intent(out) :: kpat(:, :), cpat(:, :), kcol(:, :), ccol(:, :)  !! (nq, nq)
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer, intent(out) :: bad                 !! offending entry, or 0
    type(model_t) :: m
    type(dyn_work_t) :: w
    type(sens_t) :: sens
    real(wp), allocatable :: kv(:), cv(:), x(:), y(:), z(:)
    integer :: badf, n, ptab0(2, 0), j, p, ist
    kpat = zero; cpat = zero; kcol = zero; ccol = zero; bad = 0
    call model_build(nb, ctab, rpar, m, status, msg, bad, lforce=model_force_size(ftab, fpar))
    if (status /= MBD_OK) return
    call model_add_dynamics(m, bmass, grav, ftab, fpar, status, msg, badf)
    if (status /= MBD_OK) then
      bad = -badf; return
    end if
    if (.not. (finite(q) .and. finite(t) .and. finite(lam))) then
      call not_finite('the state and the multipliers', status, msg); return
    end if
    n = m%nq
    if (size(q) /= n .or. size(lam) /= m%neq .or. any(shape(kpat) /= [n, n]) .or. &
        any(shape(cpat) /= [n, n]) .or. any(shape(kcol) /= [n, n]) .or. &
        any(shape(ccol) /= [n, n])) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    if (.not. smooth_forces(ftab)) then
      status = MBD_BAD_INPUT
      msg = 'stiffness: contacts and joint friction have no exact stiffness'; return
    end if
    call dyn_init(m, w, q, t, 1.0e-10_wp * m%lscale, status, msg, SOLVER_DENSE)
    if (status == MBD_OK) call sens_setup(m, ctab, rpar, ptab0, sens, status, msg, bad, ftab, &
                                          fpar)
    if (status /= MBD_OK) return
    allocate (kv(w%kptr(n + 1) - 1), cv(w%kptr(n + 1) - 1), x(n), y(n), z(n), stat=ist)
    if (ist /= 0) then
      status = MBD_NO_MEMORY; msg = 'stiffness: out of memory'; return
    end if
    call sens_stiffness_at(m, sens, q, t, lam, w%qz)
    call sens_tangent_pattern(m, w, sens, q, t, w%qz, kv, x, y, z, cv)
    do j = 1, n
      do p = w%kptr(j), w%kptr(j + 1) - 1
        kpat(w%krow(p), j) = kv(p); cpat(w%krow(p), j) = cv(p)
      end do
      x = zero; x(j) = one
      call sens_stiffness_mul(m, sens, q, t, w%qz, x, kcol(:, j), y)
      call sens_damping_mul(m, sens, q, t, w%qz, x, ccol(:, j))
    end do
  end subroutine api_stiffness

  !> Changes of the reactions (as api_reactions) along design parameters at many states:
  !! dreac, drloc (6, nc, np, nt), from dq/dp (nq, np, nt) and dlambda/dp (neq, np, nt).
  subroutine api_reactions_dp(nb, ctab, rpar, ptab, q, t, lam, sq, slam, dreac, drloc, status, &
                              msg)
    integer, intent(in) :: nb, ctab(:, :)
    real(wp), intent(in) :: rpar(:)
    integer, intent(in) :: ptab(:, :)
    real(wp), intent(in) :: q(:, :), t(:), lam(:, :), sq(:, :, :), slam(:, :, :)
    real(wp), intent(out) :: dreac(:, :, :, :), drloc(:, :, :, :)
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(model_t) :: m
    type(sens_t) :: sens
    integer :: bad, k
    dreac = zero; drloc = zero
    call model_build(nb, ctab, rpar, m, status, msg, bad)
    if (status /= MBD_OK) return
    if (.not. (finite(q) .and. finite(t) .and. finite(lam))) then
      call not_finite('q, t and lambda', status, msg); return
    end if
    if (size(q, 1) /= m%nq .or. size(lam, 1) /= m%neq .or. size(q, 2) /= size(t) .or. &
        size(lam, 2) /= size(t) .or. any(shape(sq) /= [m%nq, size(ptab, 2), size(t)]) .or. &
        any(shape(slam) /= [m%neq, size(ptab, 2), size(t)]) .or. &
        any(shape(dreac) /= [6, m%nc, size(ptab, 2), size(t)]) .or. &
        any(shape(drloc) /= shape(dreac))) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    call sens_setup(m, ctab, rpar, ptab, sens, status, msg, bad)
    if (status /= MBD_OK) return
    do k = 1, size(t)
      call sens_reactions(m, sens, q(:, k), t(k), lam(:, k), sq(:, :, k), slam(:, :, k), &
                          dreac(:, :, :, k), drloc(:, :, :, k))
    end do
  end subroutine api_reactions_dp

  !> Forward dynamics with design sensitivities: as api_dynamics (iinfo 1 outputs, 2 bad
  !! entry, 3 steps, 4 rejected, 6 right-hand sides, 9 active rows; rinfo 1 failure time, 2
  !! and 3 smallest and largest step) plus sq, sqd, sqdd (nq, np, rows), the sensitivities of
  !! q, q_dot and q_ddot. method dopri5 (default): the variational equations integrated with
  !! the state (mbd_sens_dynamics); generalized-alpha (h, rho_inf as in api_dynamics): its
  !! discrete equations differentiated (mbd_sens_genalpha; its counters as api_dynamics').
  subroutine api_dynamics_sens(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, v0, t0, t1, &
                               nsteps, rtol, atol, every, max_steps, ptab, qout, qdout, qddout, &
                               lamout, eout, sq, sqd, sqdd, slam, iinfo, rinfo, redundant, &
                               status, msg, solver, method, h, rho_inf)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :), nsteps, every, max_steps
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:), q0(:), v0(:), t0, t1
    real(wp), intent(in) :: rtol, atol          !! tolerances (<= 0: defaults 1e-6, 1e-8)
    integer, intent(in) :: ptab(:, :)           !! design parameters (2, np)
    real(wp), intent(out) :: qout(:, :), qdout(:, :), qddout(:, :)  !! (nq, rows)
    real(wp), intent(out) :: lamout(:, :)       !! (neq, rows)
    real(wp), intent(out) :: eout(:, :)         !! (4, rows) energies, drift
    !> (nq, np, rows); generalized-alpha writes them as it steps
    real(wp), intent(out), target, contiguous :: sq(:, :, :), sqd(:, :, :), sqdd(:, :, :)
    !> (neq, np, rows) dlambda/dp: the derivatives of the outputs' multipliers (those of the
    !! index-1 equations at the output's state, or their minimum-norm set) along (S, S_dot)
    real(wp), intent(out), contiguous :: slam(:, :, :)
    integer, intent(out) :: iinfo(NINFO)
    real(wp), intent(out) :: rinfo(NINFO)
    integer, intent(out) :: redundant(:)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(in), optional :: solver     !! 0 auto (default), 1 dense, 2 banded
    integer, intent(in), optional :: method     !! METH_DOPRI5 (default) or METH_GENALPHA
    real(wp), intent(in), optional :: h, rho_inf  !! generalized-alpha's step (0: adaptive), rho
    type(model_t) :: m
    type(dyn_work_t) :: w
    type(kin_opts_t) :: kopts
    type(dyn_opts_t) :: opts
    type(dyn_stats_t) :: dst
    type(ga_sens_t) :: gh
    type(lam_work_t) :: lw
    type(sens_t), target :: sens
    real(wp), allocatable :: q(:), qd(:), s0(:, :), sd0(:, :)
    logical, allocatable :: lok(:)
    real(wp) :: t, r_tol, a_tol, hmm(2), tfail, tstiff
    integer :: bad, badf, k, ko, nout, st, stats(3), path, kl, ku, meth
    character(len=MSG_LEN) :: lmsg
    iinfo = 0; rinfo = zero; redundant = 0
    meth = METH_DOPRI5
    if (present(method)) meth = method
    qout = zero; qdout = zero; qddout = zero; lamout = zero; eout = zero
    sq = zero; sqd = zero; sqdd = zero; slam = zero
    call build_dynamic(nb, ctab, rpar, bmass, grav, ftab, fpar, m, status, msg, bad, badf)
    iinfo(2) = bad_code(bad, badf)
    if (status /= MBD_OK) return
    if (.not. (finite(q0) .and. finite(v0) .and. finite(t0) .and. finite(t1) .and. &
               finite([rtol, atol]))) then
      call not_finite('q0, v0, the times and the settings', status, msg); return
    end if
    if (nsteps < 0 .or. .not. (t1 > t0) .or. every < 1 .or. max_steps < 1) then
      status = MBD_BAD_SETTING
      msg = 'steps must be >= 0, every >= 1, max_steps >= 1 and t_end > t0'; return
    end if
    if (meth /= METH_DOPRI5 .and. meth /= METH_GENALPHA) then
      status = MBD_BAD_SETTING
      msg = 'sensitivities are integrated by dopri5 or generalized-alpha'; return
    end if
    if (meth == METH_GENALPHA .and. .not. (present(h) .and. present(rho_inf))) then
      status = MBD_BAD_SETTING; msg = 'generalized-alpha needs h and rho_inf'; return
    end if
    if (meth == METH_GENALPHA) then
      if (.not. finite([h, rho_inf])) then
        call not_finite('h and rho_inf', status, msg); return
      end if
    end if
    if (size(q0) /= m%nq .or. size(v0) /= m%nq .or. size(qout, 1) /= m%nq .or. &
        size(qout, 2) /= output_rows(nsteps, every) .or. size(lamout, 1) /= m%neq .or. &
        size(redundant) /= m%neq .or. &
        any(shape(sq) /= [m%nq, size(ptab, 2), size(qout, 2)]) .or. &
        any(shape(sqd) /= shape(sq)) .or. any(shape(sqdd) /= shape(sq)) .or. &
        any(shape(slam) /= [m%neq, size(ptab, 2), size(qout, 2)])) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    call sens_setup(m, ctab, rpar, ptab, sens, status, msg, bad, ftab, fpar)
    if (status /= MBD_OK) then
      iinfo(2) = -2000000 - bad; return
    end if
    ! the path as for dynamics (auto: the band, Schur complement included, for a large model;
    ! nothing of the sensitivities needs a dense J)
    call dyn_choose(m, solver_or_auto(solver), path, kl, ku, status, msg)
    if (status /= MBD_OK) return
    rinfo(5) = path; rinfo(6) = kl; rinfo(7) = ku
    if (path == SOLVER_DENSE) call dyn_memory_check(m, status, msg)
    if (status /= MBD_OK) return
    allocate (q(m%nq), qd(m%nq), s0(m%nq, sens%np), sd0(m%nq, sens%np), stat=st)
    if (st /= 0) then
      call mem_fail(REAL_BYTES * (3 * real(m%nq, wp) * (1 + sens%np) + m%neq), &
                    'the state and its sensitivities', 'use fewer parameters', status, msg)
      return
    end if
    q = q0 / m%cunit
    call assemble_start(m, path, q, t0, kopts, status, msg)
    if (status /= MBD_OK) then
      rinfo(1) = t0; return
    end if
    call dyn_init(m, w, q, t0, kopts%tol * m%lscale, status, msg, path)
    if (status /= MBD_OK) return
    rinfo(6) = w%sd%kl; rinfo(7) = w%sd%ku
    iinfo(9) = w%na
    do k = 1, m%neq
      if (.not. any(w%rows == k)) redundant(k) = 1
    end do
    call dyn_velocity(m, w, q, t0, v0 / m%cunit, qd, status)
    if (status /= MBD_OK) then
      msg = 'the initial velocities cannot be made consistent: the mass matrix is singular '// &
            'on the motions the constraints allow (a body without mass or inertia?)'
      return
    end if
    call sens_initial(m, w, sens, q, qd, v0 / m%cunit, t0, s0, sd0, status, msg)
    if (status /= MBD_OK) return
    r_tol = 1.0e-6_wp; a_tol = 1.0e-8_wp
    if (rtol > zero) r_tol = rtol
    if (atol > zero) a_tol = atol
    allocate (lok(size(qout, 2)), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the outputs'; return
    end if
    call lam_init(m, w, sens, lw, status, msg)
    if (status /= MBD_OK) return
    if (meth == METH_GENALPHA) then
      ! (the multipliers of every output row from integrate, at the output's state; their
      ! sensitivities below)
      lok = .false.
      call ga_sens_init(gh, m, w, sens, q, qd, t0, s0, sd0, sq, sqd, sqdd, status, msg)
      if (status /= MBD_OK) return
      opts%method = METH_GENALPHA; opts%rtol = r_tol; opts%atol = a_tol
      opts%h = max(h, zero); opts%max_steps = max_steps
      if (rho_inf >= zero) opts%rho_inf = min(rho_inf, one)
      call integrate(m, w, q, qd, t0, t1, nsteps, every, opts, qout, qdout, qddout, lamout, &
                     nout, dst, status, msg, hook=gh)
      call dyn_info(w, dst, nout, status, iinfo, rinfo)
    else
      call sens_dopri5(m, w, sens, q, qd, s0, sd0, t0, t1, nsteps, every, r_tol, a_tol, &
                       max_steps, qout, qdout, qddout, sq, sqd, sqdd, lamout, lok, nout, stats, &
                       hmm, tfail, tstiff, status, msg, slam, lw%lunit)
      iinfo(1) = nout; iinfo(3) = stats(1); iinfo(4) = stats(2); iinfo(6) = stats(3)
      rinfo(2) = hmm(1); rinfo(3) = hmm(2)
      if (tstiff < huge(one)) then             ! steps set by stability (dyn_info's layout)
        iinfo(11) = 1; rinfo(11) = tstiff
      end if
      if (status /= MBD_OK) rinfo(1) = tfail
    end if
    do k = 1, nout
      ko = output_index(nsteps, every, k)
      t = t0 + (t1 - t0) * (real(ko, wp) / max(nsteps, 1))
      if (ko == nsteps) t = t1
      ! the multipliers and their sensitivities where the integration left them (dopri5:
      ! redundant rows; generalized-alpha: every output, its q_ddot is its own)
      if (.not. lok(k)) then
        call sens_out_multipliers(m, w, sens, lw, qout(:, k), qdout(:, k), t, sq(:, :, k), &
                                  sqd(:, :, k), lamout(:, k), slam(:, :, k), st, lmsg)
        if (st /= MBD_OK) then
          if (status == MBD_OK) then
            status = MBD_SINGULAR; rinfo(1) = t
            write (msg, '(a,es12.5,a)') 'the multipliers'' sensitivities at t = ', t, &
              ': '//trim(lmsg)//' there (the outputs before are kept)'
          end if
          nout = k - 1; iinfo(1) = nout; exit
        end if
      end if
      call state_measures(m, w, qout(:, k), qdout(:, k), t, eout(:, k))
    end do
    call units(m, qout, m%cunit, .false.); call units(m, qdout, m%cunit, .false.)
    call units(m, qddout, m%cunit, .false.); call units(m, lamout, m%rowunit, .true.)
    ! (sq, sqd, sqdd and slam: written in model units)
  end subroutine api_dynamics_sens

  !> Normal force of each cam joint on its follower at many states: fn(nc, nt), positive
  !! when the profile pushes the follower away, negative when the joint must pull it onto
  !! the profile (a real follower would lift off); zero for other constraints.
  !! fn = F_j . n, F_j the reaction on the follower, n the profile's outward normal at the
  !! contact (for a flat face -m).
  subroutine api_cam_forces(nb, ctab, rpar, q, t, lam, fn, status, msg)
    integer, intent(in) :: nb, ctab(:, :)
    real(wp), intent(in) :: rpar(:), q(:, :), t(:), lam(:, :)
    real(wp), intent(out) :: fn(:, :)
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(model_t) :: m
    type(dyn_work_t) :: w
    real(wp) :: reac(6, size(ctab, 2)), rloc(6, size(ctab, 2)), ql(NLOC), nv(2)
    integer :: bad, k, i, s, ierr
    fn = zero
    call model_build(nb, ctab, rpar, m, status, msg, bad)
    if (status /= MBD_OK) return
    if (.not. (finite(q) .and. finite(t) .and. finite(lam))) then
      call not_finite('q, t and lambda', status, msg); return
    end if
    if (size(q, 1) /= m%nq .or. size(lam, 1) /= m%neq .or. size(fn, 1) /= m%nc .or. &
        size(q, 2) /= size(t) .or. size(lam, 2) /= size(t) .or. size(fn, 2) /= size(t)) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    allocate (w%phi(m%neq), w%nu(m%neq), w%gam(m%neq), w%qz(m%nq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * (3 * real(m%neq, wp) + m%nq), 'the reaction arrays', &
                    'use a smaller model', status, msg)
      return
    end if
    call asm_init(m, w%asm, status, msg)
    if (status /= MBD_OK) return
    w%qz = zero
    do i = 1, size(t)
      call dyn_reactions(m, w, q(:, i), t(i), lam(:, i), reac, rloc)
      do k = 1, m%nc
        if (m%kind(k) /= CON_CAM) cycle
        do s = 1, NLOC
          ql(s) = zero
          if (m%loc(s, k) > 0) ql(s) = q(m%loc(s, k), i)
        end do
        nv = cam_outward_normal(m%suba(k), m%subb(k), m%p(m%po(k):m%po(k) + m%pn(k) - 1), &
                                merge(1, 0, m%bi(k) > 0), merge(2, 0, m%bj(k) > 0), &
                                local_state(ql, ql * zero))
        if (m%bj(k) > 0) then
          fn(k, i) = dot_product(reac(4:5, k), nv)
        else
          fn(k, i) = -dot_product(reac(1:2, k), nv)
        end if
      end do
    end do
  end subroutine api_cam_forces

end module mbd_api
