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
  use mbd_status, only: MBD_OK, MBD_BAD_COUNT, MBD_BAD_PARAM, MBD_INCONSISTENT, MSG_LEN
  use mbd_points, only: NLOC, MAXROW
  use mbd_model, only: model_t, model_build, model_add_dynamics, model_force_size
  use mbd_dynamics, only: dyn_work_t, dyn_init, dyn_velocity, dyn_multipliers, dyn_reactions, &
                          gen_forces, kinetic_energy, dyn_element_outputs
  use mbd_events, only: ev_log_t, ev_log_init, events_switch, events_active
  use mbd_forces, only: force_is_contact, FRC_FRICTION
  use mbd_contact, only: NEO
  use mbd_constraints, only: CON_CAM
  use mbd_joint_cam, only: cam_outward_normal
  use mbd_points, only: local_state
  use mbd_integrators, only: dyn_opts_t, dyn_stats_t, integrate, output_rows, output_index
  use mbd_statics, only: statics_solve
  use mbd_assemble, only: assemble_dense, asm_work_t, asm_init
  use mbd_kinematics, only: kin_opts_t, kin_report_t, kin_work_t, kin_run, kin_work_init, &
                            kin_assemble, kin_rank, kin_out_count, MAXPASS, SOLVER_AUTO, &
                            SOLVER_BANDED, kin_newton, kin_vel_acc
  use mbd_status, only: MBD_BAD_SETTING
  use mbd_profiles, only: profile_raw_length, profile_prepare, profile_eval
  implicit none
  private
  public :: NINFO, api_sizes, api_eval, api_kinematics, api_profile, api_analyze, api_kin_step
  public :: api_inverse, api_dynamics, api_statics, api_reactions, api_cam_forces

  integer, parameter :: NINFO = 10   !! length of the report arrays

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
    call asm_init(m, aw)
    call assemble_dense(m, q, qd, t, phi, nu, gam, aw, jac)
    if (.not. (finite(phi) .and. finite(jac) .and. finite(nu) .and. finite(gam))) then
      status = MBD_BAD_PARAM
      msg = 'the constraint equations overflow at this state (a parameter or state too large)'
    end if
  end subroutine api_eval

  !> Kinematic analysis: the whole time loop in one call.
  subroutine api_kinematics(nb, ctab, rpar, q0, t0, t1, nsteps, tol, maxit, tmin, every, &
                            solver, qout, qdout, qddout, iinfo, rinfo, qsing, dep, redundant, &
                            tpass, status, msg)
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
    !> outputs (nq, kin_out_count(nsteps, every))
    real(wp), intent(out) :: qout(:, :), qdout(:, :), qddout(:, :)
    integer, intent(out) :: iinfo(NINFO)        !! integer report
    real(wp), intent(out) :: rinfo(NINFO)       !! real report
    real(wp), intent(out) :: qsing(:)           !! configuration at a singularity (nq)
    integer, intent(out) :: dep(:)              !! dependent rows there (neq)
    integer, intent(out) :: redundant(:)        !! redundant rows at assembly (neq)
    real(wp), intent(out) :: tpass(:)           !! times of singular passages (MAXPASS)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(model_t) :: m
    type(kin_opts_t) :: opts
    type(kin_report_t) :: rep
    integer :: bad
    iinfo = 0; rinfo = zero; qsing = zero; dep = 0; redundant = 0; tpass = zero
    qout = zero; qdout = zero; qddout = zero
    call model_build(nb, ctab, rpar, m, status, msg, bad, nondim=.true.)
    iinfo(2) = bad
    if (status /= MBD_OK) return
    if (.not. (finite(q0) .and. finite(t0) .and. finite(t1) .and. finite(tol) .and. &
               finite(tmin))) then
      call not_finite('q0, the times and the tolerances', status, msg); return
    end if
    if (.not. (finite(t1 - t0))) then
      call not_finite('the time span', status, msg); return
    end if
    if (m%neq < m%nq) then
      status = MBD_BAD_COUNT
      write (msg, '(a,i0,a,i0,a,i0,a)') 'the model is not kinematically determined: ', m%neq, &
        ' equations for ', m%nq, ' coordinates (', m%nq - m%neq, ' degrees of freedom left)'
      return
    end if
    if (size(q0) /= m%nq .or. size(qsing) /= m%nq .or. size(dep) /= m%neq .or. &
        size(redundant) /= m%neq .or. size(tpass) /= MAXPASS .or. &
        size(qout, 1) /= m%nq .or. size(qout, 2) /= kin_out_count(nsteps, max(every, 1))) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    if (every < 1 .or. solver < SOLVER_AUTO .or. solver > SOLVER_BANDED) then
      status = MBD_BAD_SETTING; msg = 'every must be >= 1 and solver 0 (auto), 1 (dense) '// &
        'or 2 (banded)'; return
    end if
    opts%every = every; opts%solver = solver
    if (tol > zero) opts%tol = tol
    if (maxit > 0) opts%maxit = maxit
    if (tmin > zero) opts%tmin = tmin
    call kin_run(m, q0 / m%cunit, t0, t1, nsteps, opts, qout, qdout, qddout, rep, status, msg)
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
    integer :: bad, lev
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
    call kin_work_init(m, w)
    w%tol = opts%tol * m%lscale
    q = q / m%cunit; qd = qd / m%cunit; qdd = qdd / m%cunit
    call step()
    q = q * m%cunit; qd = qd * m%cunit; qdd = qdd * m%cunit
  contains
    subroutine step()
      if (assemble == 1) then
        allocate (rep%qsing(m%nq), rep%dep(m%neq), rep%redundant(m%neq))
        call kin_assemble(m, w, q, t, opts, rep, status, msg)
        if (status /= MBD_OK) return
      else
        h = t - t_prev
        q = q + h * (qd + (0.5_wp * h) * qdd)     ! q(t) ~ q + h q_dot + h**2/2 q_ddot
      end if
      call kin_newton(m, w, q, t, opts%maxit, status)
      if (status /= MBD_OK) then
        write (msg, '(a,es22.15)') 'Newton-Raphson failed (or J is singular) at t = ', t
        return
      end if
      call kin_vel_acc(m, w, q, t, qd, qdd, status, lev)
      if (status /= MBD_OK) msg = 'velocities or accelerations could not be solved'
    end subroutine step
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
    integer :: bad
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
    call kin_work_init(m, w)
    w%tol = opts%tol * m%lscale
    allocate (rep%qsing(m%nq), rep%dep(m%neq), rep%redundant(m%neq))
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
    call assemble_dense(m, q, w%qz, t, w%phi, w%nu, w%gam, w%asm, w%jac)
    e(3) = maxval(abs(w%phi) * m%rowunit)
    e(4) = maxval(abs(matmul(w%jac, qd) - w%nu) * m%rowunit)
    call gen_forces(m, q, qd, t, w%force, v)
    e(1) = kinetic_energy(m, qd); e(2) = v
  end subroutine state_measures

  !> Inverse dynamics: a kinematic run, then at every output the multipliers
  !! lambda (minimum norm over all rows) of J^T lambda = Q - M q_ddot, and the energies.
  !! iinfo/rinfo as api_kinematics; iinfo(2) = -force index for a bad force.
  !! Contacts are force elements at the kinematic states; their onsets and separations are
  !! found at the outputs (evo, nev as api_dynamics); joint friction (regularized) enters
  !! the multipliers; eo(NEO, nf, rows) the element outputs.
  subroutine api_inverse(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t0, t1, nsteps, tol, &
                         every, solver, qout, qdout, qddout, lamout, eout, iinfo, rinfo, qsing, &
                         dep, redundant, tpass, status, msg, eo, evo, nev)
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
    real(wp), intent(out) :: eo(:, :, :)        !! (NEO, nf, rows) element outputs
    real(wp), intent(out) :: evo(:, :)          !! (4, maxev) contact events
    integer, intent(out) :: nev                 !! events found
    type(model_t) :: m
    type(dyn_work_t) :: w
    type(ev_log_t) :: log
    integer :: bad, badf, k, st
    real(wp) :: t
    logical :: changed
    character(len=MSG_LEN) :: lmsg
    lamout = zero; eout = zero; eo = zero; evo = zero; nev = 0
    call build_dynamic(nb, ctab, rpar, bmass, grav, ftab, fpar, m, status, msg, bad, badf)
    if (status /= MBD_OK) then
      qout = zero; qdout = zero; qddout = zero; iinfo = 0; rinfo = zero
      iinfo(2) = bad; if (badf /= 0) iinfo(2) = -1000000 - badf
      qsing = zero; dep = 0; redundant = 0; tpass = zero
      return
    end if
    call api_kinematics(nb, ctab, rpar, q0, t0, t1, nsteps, tol, 0, zero, every, solver, qout, &
                        qdout, qddout, iinfo, rinfo, qsing, dep, redundant, tpass, status, msg)
    if (iinfo(1) < 1) return
    ! the multipliers in the core's units (so the rank decisions do not depend on the unit)
    call units(m, qout, m%cunit, .true.); call units(m, qdout, m%cunit, .true.)
    call units(m, qddout, m%cunit, .true.)
    call dyn_init(m, w, qout(:, 1), t0, 1.0e-12_wp, st, lmsg)
    if (st == MBD_OK) call ev_log_init(log, size(evo, 2), st)
    if (st == MBD_OK) then
      do k = 1, iinfo(1)
        ! column k holds output min((k - 1) every, nsteps)
        t = t0 + (t1 - t0) * (real(min((k - 1) * every, nsteps), wp) / max(nsteps, 1))
        if (k == size(qout, 2)) t = t1
        ! contacts open and close at the outputs (the motion is given)
        if (events_active(m)) call events_switch(m, w, t, qout(:, k), qdout(:, k), log, &
                                                 changed, st)
        call dyn_multipliers(m, w, qout(:, k), qdout(:, k), qddout(:, k), t, lamout(:, k), &
                             st, lmsg)
        call state_measures(m, w, qout(:, k), qdout(:, k), t, eout(:, k))
        if (m%nf > 0) call dyn_element_outputs(m, w, qout(:, k), qdout(:, k), t, eo(:, :, k))
      end do
      call events_out(m, log, evo, nev)
    end if
    call units(m, qout, m%cunit, .false.); call units(m, qdout, m%cunit, .false.)
    call units(m, qddout, m%cunit, .false.); call units(m, lamout, m%rowunit, .true.)
    call element_units(m, eo)
  end subroutine api_inverse

  !> Forward dynamics: assembly of q0, the velocity v0 projected onto J q_dot = nu (kinetic
  !! energy metric), integration with the chosen method, outputs at nsteps + 1 times of which
  !! rows k = 0, every, 2 every, ... and nsteps are stored (output_rows(nsteps, every)).
  !! iinfo: 1 outputs, 2 bad entry, 3 steps, 4 rejected, 5 Newton iterations, 6 right-hand
  !! sides, 7 iteration matrices (K, C evaluations), 8 partitions, 9 active (independent)
  !! constraint rows, 10 LU factorizations of the generalized-alpha iteration matrix.
  !! rinfo: 1 time of a failure, 2 smallest step, 3 largest step.
  subroutine api_dynamics(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, v0, t0, t1, nsteps, &
                          method, rtol, atol, h, rho_inf, balpha, bbeta, every, qout, qdout, &
                          qddout, lamout, eout, iinfo, rinfo, redundant, status, msg, max_steps, &
                          eo, evo, nev)
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
    type(model_t) :: m
    type(dyn_work_t) :: w
    type(kin_work_t) :: kw
    type(kin_opts_t) :: kopts
    type(kin_report_t) :: rep
    type(dyn_opts_t) :: opts
    type(dyn_stats_t) :: dst
    real(wp), allocatable :: q(:), qd(:)
    real(wp) :: t, lscale
    integer :: bad, badf, k, ko, nout
    iinfo = 0; rinfo = zero; redundant = 0
    qout = zero; qdout = zero; qddout = zero; lamout = zero; eout = zero
    eo = zero; evo = zero; nev = 0
    call build_dynamic(nb, ctab, rpar, bmass, grav, ftab, fpar, m, status, msg, bad, badf)
    iinfo(2) = bad; if (badf /= 0) iinfo(2) = -1000000 - badf
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
    ! assembly at t0 (Levenberg-Marquardt; any number of equations)
    call kin_work_init(m, kw)
    lscale = m%lscale
    kw%tol = kopts%tol * lscale
    allocate (q(m%nq), qd(m%nq), rep%qsing(m%nq), rep%dep(m%neq), rep%redundant(m%neq))
    q = q0 / m%cunit
    call kin_assemble(m, kw, q, t0, kopts, rep, status, msg)
    if (status /= MBD_OK) then
      rinfo(1) = t0; return
    end if
    call dyn_init(m, w, q, t0, kw%tol, status, msg)
    if (status /= MBD_OK) return
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
                   dst, status, msg, log, eo)
    call events_out(m, log, evo, nev)
    iinfo(1) = nout; iinfo(3) = dst%steps; iinfo(4) = dst%rejected; iinfo(5) = dst%newton
    iinfo(6) = dst%rhs; iinfo(7) = dst%jacobians; iinfo(8) = dst%partitions
    iinfo(10) = dst%factorizations
    rinfo(2) = dst%hmin; rinfo(3) = dst%hmax
    if (status /= MBD_OK) rinfo(1) = dst%t_fail
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

  !> Static equilibrium near the assembled q0 at time t, its multipliers and stability
  !! (1 stable, 0 unstable, -1 neutral, 2 no free motion).
  subroutine api_statics(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, q, lam, stable, resid, &
                         iinfo, status, msg)
    integer, intent(in) :: nb, ctab(:, :), ftab(:, :)
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:), q0(:), t
    real(wp), intent(out) :: q(:), lam(:), resid
    integer, intent(out) :: stable, iinfo(NINFO)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(model_t) :: m
    type(dyn_work_t) :: w
    type(kin_work_t) :: kw
    type(kin_opts_t) :: kopts
    type(kin_report_t) :: rep
    real(wp) :: lscale
    integer :: bad, badf
    q = zero; lam = zero; stable = 0; resid = zero; iinfo = 0
    call build_dynamic(nb, ctab, rpar, bmass, grav, ftab, fpar, m, status, msg, bad, badf)
    iinfo(2) = bad; if (badf /= 0) iinfo(2) = -1000000 - badf
    if (status /= MBD_OK) return
    if (.not. (finite(q0) .and. finite(t))) then
      call not_finite('q0 and t', status, msg); return
    end if
    if (size(q0) /= m%nq .or. size(q) /= m%nq .or. size(lam) /= m%neq) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    call kin_work_init(m, kw)
    lscale = m%lscale
    kw%tol = kopts%tol * lscale
    allocate (rep%qsing(m%nq), rep%dep(m%neq), rep%redundant(m%neq))
    q = q0 / m%cunit
    call kin_assemble(m, kw, q, t, kopts, rep, status, msg)
    if (status == MBD_OK) call dyn_init(m, w, q, t, kw%tol, status, msg)
    if (status == MBD_OK) call statics_solve(m, w, q, t, lam, stable, resid, status, msg)
    q = q * m%cunit; lam = lam / m%rowunit
  end subroutine api_statics

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
    integer :: bad, k
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
    allocate (w%phi(m%neq), w%nu(m%neq), w%gam(m%neq), w%qz(m%nq))
    call asm_init(m, w%asm)
    w%qz = zero
    do k = 1, size(t)
      call dyn_reactions(m, w, q(:, k), t(k), lam(:, k), reac(:, :, k), rloc(:, :, k))
    end do
  end subroutine api_reactions

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
    integer :: bad, k, i, s
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
    allocate (w%phi(m%neq), w%nu(m%neq), w%gam(m%neq), w%qz(m%nq))
    call asm_init(m, w%asm)
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
