!> mbd2d-solve: run a model file written by `mbd2d export`, without Python.
!!
!!   mbd2d-solve MODEL.mbd OUT.csv
!! Runs the file's analysis (kinematics, inverse dynamics, dynamics, statics, modes or frf,
!! with its settings) and writes the CSV the Python path writes for it: t, then NAME.x ...
!! NAME.theta_ddot per body (statics: NAME.x, NAME.y, NAME.theta, stable, residual), then the
!! optional columns the file's "outputs" line asks for (energy, multipliers, reactions,
!! efforts), then each
!! contact's and joint friction's columns (dynamic runs), then with a "sensitivities" block,
!! for each design parameter P in turn, d(COLUMN)/d(P) of the motion columns and (inverse
!! dynamics, statics) of the multiplier, reaction and effort columns asked for; every number
!! as Python's "%.16e" (docs/mbd-format.md). A file with a "cases" block (mbd2d.export_sweep)
!! runs the analysis for every case in one batch call (mbd_batch) and writes the CSV of
!! mbd2d.write_sweep: case, the parameters, t, status, message, then q, q_dot, q_ddot per
!! coordinate, the drivers' efforts, the file's measures and, for each design parameter P,
!! d(COLUMN)/d(P) of the motion and (inverse dynamics, statics) of the efforts, one row per
!! case and output time (numbers as "%.17g"); a failing case keeps its rows and says why, and
!! the exit code is 0.
!! Exit codes: 0 ok, 2 bad input (a malformed file, or counts too large for the memory),
!! 3 singular configuration (partial output written), 4 other numerical failure (partial
!! output written when there is any). Messages go to standard error, each starting
!! "mbd2d-solve: ". Nothing is allocated before the counts are checked (mbd_read) and the
!! outputs, held in memory, are checked against it (mem_check).
program mbd2d_solve
  use, intrinsic :: iso_fortran_env, only: error_unit, int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_value, ieee_quiet_nan
  use mbd_kinds, only: wp
  use mbd_status, only: MBD_OK, MBD_SINGULAR_CONFIG, MBD_NO_MEMORY, MBD_BAD_COUNT, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check
  use mbd_mbdfile, only: mbd_spec_t, mbd_read, NAME_LEN, METHOD_WORDS, MEAS_ANGLE, &
                         MEAS_RATIO, MEAS_ADVANTAGE
  use mbd_measures, only: api_measures
  use mbd_model, only: NFT
  use mbd_constraints, only: con_nrow, con_is_driver
  use mbd_api, only: NINFO, api_sizes, api_kinematics, api_inverse, api_dynamics, api_statics, &
                     api_reactions, api_dynamics_sens, api_reactions_dp, api_analyze, api_modes, &
                     api_frf, api_linearize
  use mbd_batch, only: batch_run, NISET, NRSET
  use mbd_status, only: MBD_NO_CONVERGENCE, MBD_INTEGRATOR_FAILED, MBD_INCONSISTENT, &
                        MBD_ASSEMBLY_FAILED
  use mbd_constraints, only: con_nextra
  use mbd_kinematics, only: MAXPASS, kin_out_count
  use mbd_integrators, only: output_index, METH_PARTITIONED
  use mbd_contact, only: NEO
  use mbd_forces, only: force_is_contact, FRC_FRICTION
  use iso_c_binding, only: c_char, c_double, c_int
  use solve_text, only: FMT_G6, FMT_E1, FMT_F10, FMT_G3, format_num, num, sput, bput, bnum, &
                        quoted, cnum
  implicit none
  type(mbd_spec_t) :: spec
  !> the coordinates' names in the CSV columns
  character(len=*), parameter :: XYT(3) = ['x    ', 'y    ', 'theta']
  character(len=1024) :: model_path, out_path
  character(len=MSG_LEN) :: msg
  integer :: status, bad, nq, neq, nrows, nout, iinfo(NINFO), ierr, stable
  real(wp) :: rinfo(NINFO), bytes, resid
  real(wp), allocatable :: q0(:), v0(:), qout(:, :), qdout(:, :), qddout(:, :), qsing(:), &
                           tpass(:), lamout(:, :), eout(:, :), tout(:), reac(:, :, :), &
                           rloc(:, :, :), fpar(:), eo(:, :, :), sq(:, :, :), sqd(:, :, :), &
                           sqdd(:, :, :), slam(:, :, :), dreac(:, :, :, :), drloc(:, :, :, :)
  real(wp) :: evo(4, 1)
  integer :: nev
  integer, allocatable :: dep(:), redundant(:), ftab(:, :)
  logical :: dynamic, elements, sens, lam_sens
  ! a sweep (run_sweep): the batch call's outputs per case and each case's outcome
  real(wp), allocatable :: bq(:, :, :), bqd(:, :, :), bqdd(:, :, :), blam(:, :, :), &
                           be(:, :, :), brinfo(:, :), bqsing(:, :), bmv(:, :, :)
  !> a sweep's sensitivities (nq, npar, rows, cases) and the multipliers' (nsl, ...)
  real(wp), allocatable :: bsq(:, :, :, :), bsqd(:, :, :, :), bsqdd(:, :, :, :), &
                           bslam(:, :, :, :)
  !> a sweep's measures' design derivatives (nmeas, npar, rows, cases)
  real(wp), allocatable :: bdm(:, :, :, :)
  integer, allocatable :: biinfo(:, :), bdep(:, :), bred(:, :), bstat(:), nkeep(:), cstat(:)
  integer, allocatable :: bmbad(:, :)                 !! a case's failed measure (mbd_batch)
  character(len=MSG_LEN), allocatable :: bmsg(:)
  character(len=4 * MSG_LEN), allocatable :: cmsg(:)
  integer :: code = 0, nrow = 0, nd = 0, nlam = 0   !! batch analysis, rows, rows of q_dot, lambda
  integer, allocatable :: drow(:)                   !! the drivers' rows of Phi (an effort: -lambda)
  real(wp), allocatable :: mvals(:, :)                !! the measures (nmeas, rows written)
  !> with sensitivities: the measures' design derivatives (nmeas, npar, rows written)
  real(wp), allocatable :: mdp(:, :, :)
  !> the run's status when sensitivities turn non-finite (rows cut there, exit code 4)
  integer, parameter :: NONFINITE = 100
  integer :: nsr

  if (command_argument_count() /= 2) then
    if (command_argument_count() == 1) then
      call get_command_argument(1, model_path)
      if (model_path == '-h' .or. model_path == '--help') then
        write (*, '(a)') 'usage: mbd2d-solve MODEL.mbd OUT.csv'
        write (*, '(a)') '  runs the analysis in a model file written by `mbd2d export` and '// &
          'writes a CSV'
        write (*, '(a)') '  (kinematics, inverse dynamics, dynamics, statics, modes, frf or '// &
          'check; '// &
          'with the file''s sensitivities and measures; a sweep file runs every case, on '// &
          'every core)'
        write (*, '(a)') '  exit codes: 0 ok, 2 bad input, 3 singular configuration, 4 other '// &
          'numerical failure (docs/mbd-format.md)'
        stop
      end if
    end if
    call die(2, 'usage: mbd2d-solve MODEL.mbd OUT.csv (runs the analysis in a model file '// &
             'written by `mbd2d export` and writes a CSV)')
  end if
  call get_command_argument(1, model_path)
  call get_command_argument(2, out_path)

  call mbd_read(trim(model_path), spec, status, msg)
  if (status /= MBD_OK) call die(2, trim(msg))
  call api_sizes(spec%nb, spec%ctab, spec%rpar, nq, neq, status, msg, bad)
  if (status /= MBD_OK) call die(2, where(bad, msg))
  drow = driver_rows()
  if (spec%out_vel .and. spec%analysis /= 'linearize') call die(2, trim(model_path) // &
    ': the output "velocities" is linearize''s (a run''s CSV has the velocities already)')
  if (spec%analysis == 'check') then
    call run_check()
    stop 0, quiet=.true.
  end if
  if (spec%analysis == 'modes' .and. spec%ncase == 0) then
    call run_modes()
    stop 0, quiet=.true.
  end if
  if (spec%analysis == 'frf' .and. spec%ncase == 0) then
    call run_frf()
    stop 0, quiet=.true.
  end if
  if (spec%analysis == 'linearize') then
    call run_linearize()
    stop 0, quiet=.true.
  end if
  dynamic = spec%analysis /= 'kinematics'
  if (spec%analysis /= 'statics' .and. spec%analysis /= 'modes' .and. &
      spec%analysis /= 'frf' .and. spec%steps_line == 0) &
    call die(2, trim(model_path) // ': the file gives no "steps" line')
  if (dynamic .and. .not. spec%have_masses) call die(2, trim(model_path) // ': ' // &
    trim(spec%analysis) // ' needs the masses: body lines NAME X0 Y0 THETA0 MASS INERTIA '// &
    'VX0 VY0 OMEGA0')
  if (.not. dynamic .and. (spec%out_energy .or. spec%out_lam .or. spec%out_reac .or. &
                           spec%out_eff)) &
    call die(2, trim(model_path) // ': the outputs energy, multipliers, reactions and '// &
             'efforts need inverse-dynamics, dynamics or statics')
  if (spec%positions_only .and. spec%analysis /= 'kinematics') call die(2, &
    trim(model_path) // ': positions_only is a setting of kinematics')
  if (spec%nlabels >= 0 .and. spec%nlabels /= neq) call die(2, trim(model_path) // &
    ': ' // trim(itoa(spec%nlabels)) // ' labels for ' // trim(itoa(neq)) // ' rows of Phi')
  if (spec%analysis == 'statics' .and. spec%out_energy) call die(2, trim(model_path) // &
    ': statics has no energy output')
  call check_sensitivities()
  call check_measures()
  if (spec%ncase > 0) then
    call run_sweep()
    stop 0, quiet=.true.
  end if

  ! the states (q, q_dot, q_ddot), multipliers, energies and reactions of every output are
  ! held in memory until the CSV is written
  nrows = 1
  if (spec%analysis /= 'statics') nrows = kin_out_count(spec%steps, spec%every)
  bytes = REAL_BYTES * (real(nrows, wp) * (3 * real(nq, wp) + merge(neq + 5, 0, dynamic)) + &
                        2 * nq + 2 * neq)
  if (spec%out_reac) bytes = bytes + REAL_BYTES * 12 * real(spec%nc, wp) * nrows
  ! the sensitivities: dq/dp, dq_dot/dp, dq_ddot/dp, dlambda/dp, the reactions' changes
  nsr = merge(nrows, 0, sens)
  bytes = bytes + REAL_BYTES * real(spec%npar, wp) * nsr * (3 * real(nq, wp) + neq)
  if (spec%out_reac .and. lam_sens) bytes = bytes + &
    REAL_BYTES * 12 * real(spec%nc, wp) * spec%npar * nsr
  call mem_check(bytes, 'the outputs (3 x ' // trim(itoa(nq)) // ' numbers at ' // &
                 trim(itoa(spec%steps)) // ' + 1 times)', 'give fewer steps', status, msg)
  if (status /= MBD_OK) call die(2, trim(model_path) // ':' // trim(itoa(spec%steps_line)) // &
                                 ': ' // trim(msg))
  allocate (q0(nq), v0(nq), qsing(nq), dep(neq), redundant(neq), tpass(MAXPASS), &
            tout(nrows), lamout(neq, merge(nrows, 1, dynamic)), &
            eout(4, merge(nrows, 1, dynamic)), stat=ierr)
  if (ierr == 0) allocate (qout(nq, nrows), qdout(nq, nrows), qddout(nq, nrows), stat=ierr)
  if (ierr == 0) allocate (ftab(NFT, spec%nf), fpar(max(1, size(spec%fpar))), stat=ierr)
  ! the outputs of the force elements (contacts, joint frictions): dynamic runs over time
  elements = spec%analysis == 'dynamics' .or. spec%analysis == 'inverse-dynamics'
  if (ierr == 0) allocate (eo(NEO, spec%nf, merge(nrows, 0, elements)), stat=ierr)
  if (ierr == 0) allocate (sq(nq, spec%npar, nsr), sqd(nq, spec%npar, nsr), &
                           sqdd(nq, spec%npar, nsr), slam(neq, spec%npar, nsr), stat=ierr)
  if (ierr /= 0) call die(2, trim(model_path) // ':' // trim(itoa(spec%steps_line)) // &
                          ': not enough memory for the outputs of ' // trim(itoa(spec%steps)) // &
                          ' steps; give fewer steps')
  q0 = 0.0_wp; v0 = 0.0_wp
  q0(1:3 * spec%nb) = reshape(spec%q0, [3 * spec%nb])
  v0(1:3 * spec%nb) = reshape(spec%v0, [3 * spec%nb])
  ftab = spec%ftab
  fpar = 0.0_wp
  fpar(1:size(spec%fpar)) = spec%fpar
  qout = 0.0_wp; qdout = 0.0_wp; qddout = 0.0_wp; lamout = 0.0_wp; eout = 0.0_wp
  sq = 0.0_wp; sqd = 0.0_wp; sqdd = 0.0_wp; slam = 0.0_wp
  iinfo = 0; rinfo = 0.0_wp

  select case (spec%analysis)
  case ('kinematics')
    if (sens) then
      call api_kinematics(spec%nb, spec%ctab, spec%rpar, q0, spec%t0, spec%t_end, spec%steps, &
                          spec%tol, spec%maxit, spec%tmin, spec%every, spec%solver, qout, qdout, &
                          qddout, iinfo, rinfo, qsing, dep, redundant, tpass, status, msg, &
                          spec%ptab, sq, sqd, sqdd)
    else
      call api_kinematics(spec%nb, spec%ctab, spec%rpar, q0, spec%t0, spec%t_end, spec%steps, &
                          spec%tol, spec%maxit, spec%tmin, spec%every, spec%solver, qout, qdout, &
                          qddout, iinfo, rinfo, qsing, dep, redundant, tpass, status, msg, &
                          positions=merge(1, 0, spec%positions_only))
    end if
    nout = iinfo(1)
  case ('inverse-dynamics')
    if (sens) then
      call api_inverse(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftab, fpar, q0, &
                       spec%t0, spec%t_end, spec%steps, spec%tol, spec%every, spec%solver, &
                       qout, qdout, qddout, lamout, eout, iinfo, rinfo, qsing, dep, redundant, &
                       tpass, status, msg, spec%ptab, sq, sqd, sqdd, slam)
    else
      call api_inverse(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftab, fpar, q0, &
                       spec%t0, spec%t_end, spec%steps, spec%tol, spec%every, spec%solver, &
                       qout, qdout, qddout, lamout, eout, iinfo, rinfo, qsing, dep, redundant, &
                       tpass, status, msg, eo=eo, evo=evo, nev=nev)
    end if
    nout = iinfo(1)
  case ('dynamics')
    if (sens) then                 ! dopri5 or generalized-alpha with the sensitivities
      call api_dynamics_sens(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftab, &
                             fpar, q0, v0, spec%t0, spec%t_end, spec%steps, spec%rtol, &
                             spec%atol, spec%every, spec%max_steps, spec%ptab, qout, qdout, &
                             qddout, lamout, eout, sq, sqd, sqdd, slam, iinfo, rinfo, redundant, &
                             status, msg, method=spec%method, h=spec%h, rho_inf=spec%rho_inf)
    else
      call api_dynamics(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftab, fpar, q0, &
                        v0, spec%t0, spec%t_end, spec%steps, spec%method, spec%rtol, spec%atol, &
                        spec%h, spec%rho_inf, spec%alpha, spec%beta, spec%every, qout, qdout, &
                        qddout, lamout, eout, iinfo, rinfo, redundant, status, msg, &
                        spec%max_steps, eo, evo, nev)
    end if
    nout = iinfo(1)
  case default   ! statics
    if (sens) then
      call api_statics(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftab, fpar, q0, &
                       spec%tstat, qout(:, 1), lamout(:, 1), stable, resid, iinfo, status, &
                       msg, spec%ptab, sq(:, :, 1), slam(:, :, 1))
    else
      call api_statics(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftab, fpar, q0, &
                       spec%tstat, qout(:, 1), lamout(:, 1), stable, resid, iinfo, status, msg)
    end if
    nout = merge(1, 0, status == MBD_OK)
  end select
  if (status < 0) call die_input(iinfo(2), msg)
  if (status == MBD_NO_MEMORY) call die(2, trim(msg))
  if (spec%analysis == 'statics' .and. status /= MBD_OK) call die(4, trim(msg) // &
    ' (no equilibrium written)')
  nout = max(0, min(nout, nrows))
  call times()
  if (sens) call finite_rows()
  if (spec%out_reac .and. nout > 0) call reactions()
  call eval_measures()
  call write_csv(trim(out_path))
  call run_warnings()
  if (spec%analysis == 'dynamics' .and. iinfo(11) == 1) call stiff_warning()
  if (status == MBD_SINGULAR_CONFIG) then
    call die(3, trim(singular_message()))
  else if (status == NONFINITE) then
    call die(4, trim(msg) // ' ' // trim(rows_written()))
  else if (status == MBD_INCONSISTENT .and. any(dep == 1)) then
    call die(4, trim(msg) // ': the constraints' // trim(dep_names(dep)) // ' cannot all '// &
             'hold; check their points and dimensions. ' // trim(rows_written()))
  else if (status /= MBD_OK) then
    call die(4, trim(msg) // trim(worst()) // '. ' // trim(rows_written()))
  end if

contains

  !> The Python path's warnings of a run, on standard error: redundant constraints (their
  !! row labels), singular passages (kinematics, inverse dynamics; up to five times) and a
  !! partitioned step that ended next to a singular configuration (J_u's reciprocal
  !! condition below sqrt(eps / 1e-3), the Python path's RCOND_WARN).
  subroutine run_warnings()
    character(len=2 * MSG_LEN) :: text
    integer :: r, npass
    if (spec%analysis == 'dynamics' .and. spec%method == METH_PARTITIONED .and. &
        iinfo(3) > 0 .and. rinfo(10) > 0.0_wp) then
      if (rinfo(9) < sqrt(epsilon(1.0_wp) / 1.0e-3_wp)) write (error_unit, '(a)') &
        'mbd2d-solve: warning: partitioned: a step at t = ' // cnum(rinfo(10), FMT_G6) // &
        " ended next to a singular configuration (J_u's reciprocal condition " // &
        cnum(rinfo(9), FMT_E1) // '): the accelerations there, and the motion after it, ' // &
        'may be inaccurate; check the energy, or use rtol >= 1e-8'
    end if
    if (spec%analysis /= 'statics' .and. any(redundant /= 0)) then
      text = ''
      do r = 1, size(redundant)
        if (redundant(r) == 0) cycle
        if (len_trim(text) > 0) text = trim(text) // ','
        text = trim(text) // ' ' // trim(row_label(r))
      end do
      write (error_unit, '(a)') 'mbd2d-solve: warning: redundant constraints:' // trim(text) // &
        ' repeat what the other constraints impose; they are solved in least squares (the ' // &
        'reactions are statically indeterminate)'
    end if
    npass = 0
    if (spec%analysis == 'kinematics' .or. spec%analysis == 'inverse-dynamics') npass = iinfo(10)
    if (npass <= 0) return
    text = ''
    do r = 1, min(npass, 5, size(tpass))
      if (r > 1) text = trim(text) // ','
      text = trim(text) // ' ' // cnum(tpass(r), FMT_G6)
    end do
    if (npass > 5) text = trim(text) // ' ...'
    write (error_unit, '(a)') 'mbd2d-solve: warning: passed through ' // trim(itoa(npass)) // &
      ' singular configuration(s) (bifurcation points, J lost rank) at t =' // trim(text) // &
      ' s and stayed on the branch the run started on'
  end subroutine run_warnings

  !> dopri5's (partitioned's) steps became limited by stability: say so, as the Python
  !! path's StiffnessWarning.
  subroutine stiff_warning()
    write (error_unit, '(a)') 'mbd2d-solve: warning: from t = ' // cnum(rinfo(11), FMT_G6) // &
      ' s the steps were limited by stability, not accuracy: the model is stiff (a stiff ' // &
      'spring, damper or contact); method = "generalized-alpha" takes steps set by accuracy'
  end subroutine stiff_warning

  !> The output times: row k holds output output_index(steps, every, k), as the core.
  subroutine times()
    integer :: k, ko
    if (spec%analysis == 'statics') then
      tout = spec%tstat; return
    end if
    do k = 1, size(tout)
      ko = output_index(spec%steps, spec%every, k)
      tout(k) = spec%t0 + (spec%t_end - spec%t0) * (real(ko, wp) / spec%steps)
      if (ko == spec%steps) tout(k) = spec%t_end
    end do
  end subroutine times

  !> The reactions of every constraint at the written rows (the core, as the Python path),
  !! and with the multipliers' sensitivities the reactions' changes along each parameter.
  subroutine reactions()
    integer :: st
    allocate (reac(6, spec%nc, nout), rloc(6, spec%nc, nout), stat=ierr)
    if (ierr /= 0) call die(2, 'not enough memory for the reactions; give fewer steps')
    call api_reactions(spec%nb, spec%ctab, spec%rpar, qout(:, 1:nout), tout(1:nout), &
                       lamout(:, 1:nout), reac, rloc, st, msg)
    if (st /= MBD_OK) call die(4, 'the reactions could not be computed: ' // trim(msg))
    if (.not. lam_sens) return
    allocate (dreac(6, spec%nc, spec%npar, nout), drloc(6, spec%nc, spec%npar, nout), stat=ierr)
    if (ierr /= 0) call die(2, 'not enough memory for the reactions; give fewer steps')
    call api_reactions_dp(spec%nb, spec%ctab, spec%rpar, spec%ptab, qout(:, 1:nout), &
                          tout(1:nout), lamout(:, 1:nout), sq(:, :, 1:nout), &
                          slam(:, :, 1:nout), dreac, drloc, st, msg)
    if (st /= MBD_OK) call die(4, "the reactions' changes could not be computed: " // trim(msg))
  end subroutine reactions

  !> The file's design parameters, checked against the analysis as the Python path checks
  !! them; sets sens (a "sensitivities" block) and lam_sens (the multipliers' too).
  subroutine check_sensitivities()
    integer :: c
    sens = spec%npar > 0
    lam_sens = sens .and. spec%analysis /= 'kinematics' .and. spec%analysis /= 'frf'
    if (.not. sens) return
    if (spec%positions_only) call die(2, trim(model_path) // ':' // &
      trim(itoa(spec%sens_line)) // ': sensitivities need the velocities and accelerations '// &
      'of every step: give positions_only 0')
    if (spec%analysis == 'dynamics' .and. spec%method /= 2 .and. spec%method /= 1) &
      call die(2, trim(model_path) // ':' // trim(itoa(spec%sens_line)) // ': '// &
               'sensitivities are integrated with dopri5 (the variational equations with the '// &
               'state) or generalized-alpha (its discrete equations differentiated); give '// &
               'method dopri5 or generalized-alpha')
    do c = 1, spec%nf
      if (force_is_contact(spec%ftab(1, c)) .or. spec%ftab(1, c) == FRC_FRICTION) &
        call die(2, trim(model_path) // ':' // trim(itoa(spec%sens_line)) // ': design '// &
                 'sensitivities do not carry contacts or joint friction ("' // &
                 trim(spec%force_names(c)) // '"): their events make the motion non-smooth '// &
                 'in the parameters')
    end do
  end subroutine check_sensitivities

  !> The measures' recipes lie in the model (bodies, rows of Phi, coordinates) and the
  !! analysis has rows over time.
  subroutine check_measures()
    integer :: j, k, lim
    do j = 1, spec%nmeas
      if (spec%analysis == 'statics') call die(2, trim(model_path) // ':' // &
        trim(itoa(spec%meas_line(j))) // ': measures are columns of a run over time, not of '// &
        'statics')
      select case (spec%meas_kind(j))
      case (MEAS_ANGLE)
        if (any(spec%meas_int(2:4, j) > spec%nb)) call die(2, trim(model_path) // ':' // &
          trim(itoa(spec%meas_line(j))) // ': measure "' // trim(spec%meas_names(j)) // &
          '": a body number beyond the ' // trim(itoa(spec%nb)) // ' bodies')
        if (any(spec%meas_ref(:, :, j) > size(spec%rpar))) call die(2, trim(model_path) // &
          ':' // trim(itoa(spec%meas_line(j))) // ': measure "' // trim(spec%meas_names(j)) // &
          '": a point''s entry beyond the ' // trim(itoa(size(spec%rpar))) // ' params')
      case (MEAS_RATIO, MEAS_ADVANTAGE)
        if (spec%meas_int(1, j) > neq) call bad_measure(j)
        do k = 2, 4, 2                   ! X, then Y: a coordinate (1) or a driver's row (2)
          lim = merge(nq, neq, spec%meas_int(k, j) == 1)
          if (spec%meas_int(k + 1, j) > lim) call bad_measure(j)
        end do
      end select
    end do
  end subroutine check_measures

  subroutine bad_measure(j)
    integer, intent(in) :: j
    call die(2, trim(model_path) // ':' // trim(itoa(spec%meas_line(j))) // ': measure "' // &
             trim(spec%meas_names(j)) // '": a row or coordinate beyond the model (' // &
             trim(itoa(neq)) // ' rows of Phi, ' // trim(itoa(nq)) // ' coordinates)')
  end subroutine bad_measure

  !> The measures at the rows written (the core, as the Python path's table): the
  !! conditioning of J, the transmission angle, and the ratios of influence coefficients;
  !! with sensitivities also their design derivatives (the d(SPEC)/d(P) columns).
  subroutine eval_measures()
    integer :: st, bad(2)
    if (spec%nmeas == 0 .or. nout == 0) return
    allocate (mvals(spec%nmeas, nout), mdp(spec%nmeas, spec%npar, nout), stat=ierr)
    if (ierr /= 0) call die(2, 'not enough memory for the measures; give fewer steps')
    if (sens) then
      call api_measures(spec%nb, spec%ctab, spec%rpar, qout(:, 1:nout), tout(1:nout), &
                        spec%meas_kind, spec%meas_int, spec%meas_pts, spec%meas_ref, mvals, &
                        bad, st, msg, spec%ptab, sq(:, :, 1:nout), mdp)
    else
      call api_measures(spec%nb, spec%ctab, spec%rpar, qout(:, 1:nout), tout(1:nout), &
                        spec%meas_kind, spec%meas_int, spec%meas_pts, spec%meas_ref, mvals, &
                        bad, st, msg)
    end if
    if (st == MBD_OK) return
    if (bad(2) /= 0) call die(2, 'measure "' // trim(spec%meas_names(bad(1))) // '": ' // &
                              trim(msg))
    call die(4, 'measure "' // trim(spec%meas_names(max(1, bad(1)))) // &
             '" could not be computed: ' // trim(msg))
  end subroutine eval_measures

  !> Keep the rows before the first one with a non-finite sensitivity (as the Python path:
  !! no result leaves with a non-finite number); status NONFINITE when rows are cut.
  subroutine finite_rows()
    integer :: k
    do k = 1, nout
      if (all(ieee_is_finite(sq(:, :, k))) .and. all(ieee_is_finite(sqd(:, :, k))) .and. &
          all(ieee_is_finite(sqdd(:, :, k))) .and. all(ieee_is_finite(slam(:, :, k)))) cycle
      if (spec%analysis == 'statics') then
        status = NONFINITE; nout = 0
        msg = 'the sensitivities of the equilibrium are not finite (the equilibrium is not '// &
              'isolated)'
        call die(4, trim(msg) // ' (no equilibrium written)')
      end if
      if (status == MBD_OK) then
        write (msg, '(a,es14.6,a)') 'the run gave non-finite sensitivities at t =', tout(k), ' s'
        status = NONFINITE
      end if
      nout = k - 1
      return
    end do
  end subroutine finite_rows

  !> "FILE:LINE: constraint "NAME": TEXT" for constraint k (TEXT alone for k outside 1..nc).
  function where(k, text) result(s)
    integer, intent(in) :: k
    character(len=*), intent(in) :: text
    character(len=2 * MSG_LEN) :: s
    s = text
    if (k > 0 .and. k <= spec%nc) s = trim(model_path) // ':' // &
      trim(itoa(spec%con_line(k))) // ': constraint "' // trim(spec%con_names(k)) // '": ' // &
      trim(text)
  end function where

  !> Exit 2 naming what a bad-input status points at: iinfo(2) code a design parameter
  !! (<= -2000000), a force (<= -1000000), a body (< 0) or a constraint.
  subroutine die_input(code, text)
    integer, intent(in) :: code
    character(len=*), intent(in) :: text
    if (code <= -2000000) call die(2, param_where(-2000000 - code, text))
    if (code <= -1000000) call die(2, force_where(-1000000 - code, text))
    if (code < 0) call die(2, trim(model_path) // ': body "' // &
                           trim(spec%body_names(min(spec%nb, -code))) // '": ' // trim(text))
    call die(2, where(code, text))
  end subroutine die_input

  !> "FILE: force "NAME": TEXT" for force k.
  function force_where(k, text) result(s)
    integer, intent(in) :: k
    character(len=*), intent(in) :: text
    character(len=2 * MSG_LEN) :: s
    s = trim(model_path) // ': ' // trim(text)
    if (k > 0 .and. k <= spec%nf) s = trim(model_path) // ': force "' // &
      trim(spec%force_names(k)) // '": ' // trim(text)
  end function force_where

  !> "FILE:LINE: sensitivity "NAME": TEXT" for design parameter k.
  function param_where(k, text) result(s)
    integer, intent(in) :: k
    character(len=*), intent(in) :: text
    character(len=2 * MSG_LEN) :: s
    s = trim(model_path) // ': ' // trim(text)
    if (k > 0 .and. k <= spec%npar) s = trim(model_path) // ':' // &
      trim(itoa(spec%par_line(k))) // ': sensitivity "' // trim(spec%par_names(k)) // &
      '": ' // trim(text)
  end function param_where

  function itoa(i) result(s)
    integer, intent(in) :: i
    character(len=16) :: s
    write (s, '(i0)') i
  end function itoa

  function worst() result(s)
    character(len=MSG_LEN) :: s
    s = ''
    if (spec%analysis == 'dynamics') return
    if (iinfo(4) > 0 .and. iinfo(4) <= spec%nc) s = ' ("' // trim(spec%con_names(iinfo(4))) // '")'
  end function worst

  function rows_written() result(s)
    character(len=MSG_LEN) :: s
    write (s, '(a,i0,a,a)') 'Wrote ', nout, ' rows to ', trim(out_path)
  end function rows_written

  !> One paragraph: when, which driver, which constraints, what to do.
  function singular_message() result(s)
    character(len=4 * MSG_LEN) :: s
    s = trim(singular_text(rinfo(1), iinfo(3), dep)) // ' ' // trim(rows_written()) // '.'
  end function singular_message

  !> " NAME NAME ...": the constraints that own a row flagged in dp (neq), in their order;
  !! with commas, " NAME, NAME, ..." (as the Python messages join them).
  function dep_names(dp, commas) result(names)
    integer, intent(in) :: dp(:)
    logical, intent(in), optional :: commas
    character(len=2 * MSG_LEN) :: names
    integer :: c, r0, nr
    names = ''
    r0 = 1
    do c = 1, spec%nc
      nr = con_nrow(spec%ctab(1, c))
      if (any(dp(r0:r0 + nr - 1) == 1)) then
        if (len_trim(names) > 0 .and. present(commas)) then
          if (commas) names = trim(names) // ','
        end if
        names = trim(names) // ' ' // trim(spec%con_names(c))
      end if
      r0 = r0 + nr
    end do
  end function dep_names

  !> The dead centre at time ts of driver drv (0: none named) with the dependent rows dp.
  function singular_text(tsing, drv, dp) result(s)
    real(wp), intent(in) :: tsing
    integer, intent(in) :: drv, dp(:)
    character(len=4 * MSG_LEN) :: s
    character(len=2 * MSG_LEN) :: names
    character(len=32) :: ts
    names = dep_names(dp)
    write (ts, '(f0.10)') tsing
    if (ts(1:1) == '.') ts = '0' // trim(ts)
    if (ts(1:2) == '-.') ts = '-0' // ts(2:)
    s = 'Singular configuration (dead centre) at t = ' // trim(ts) // ' s: '
    if (drv > 0 .and. drv <= spec%nc) then
      s = trim(s) // ' driver "' // trim(spec%con_names(drv)) // &
          '" can no longer be met, because the constraints' // trim(names) // &
          ' became dependent (J lost rank).'
    else
      s = trim(s) // ' the constraints' // trim(names) // ' became dependent (J lost rank).'
    end if
    s = trim(s) // ' The mechanism cannot move further as driven; change the driver range or ' // &
        'the link lengths.'
  end function singular_text

  subroutine write_csv(path)
    character(len=*), intent(in) :: path
    integer :: u, ios, i, k, c, j, ncols
    character(len=*), parameter :: ew(5) = [character(len=16) :: 'kinetic', 'potential', &
      'energy', 'drift_position', 'drift_velocity']
    ! each contact's and joint friction's columns (the Python table's, always written)
    character(len=*), parameter :: cw(4) = [character(len=16) :: 'normal_force', &
      'friction_force', 'penetration', 'sliding_speed']
    character(len=*), parameter :: fw(3) = [character(len=16) :: 'normal_load', &
      'friction_force', 'sliding_speed']
    real(wp), allocatable :: v(:)
    character(len=32) :: word
    integer :: nw
    ncols = 1 + 9 * spec%nb + 5 + neq + 6 * spec%nc + spec%nc + 4 * spec%nf + spec%nmeas + &
            spec%npar * (9 * spec%nb + neq + 6 * spec%nc + spec%nc + spec%nmeas)
    allocate (v(ncols), stat=ierr)
    if (ierr /= 0) call die(2, 'not enough memory to write ' // path)
    open (newunit=u, file=path, status='replace', action='write', iostat=ios)
    if (ios /= 0) call die(2, 'cannot write ' // path)
    ! header
    write (u, '(a)', advance='no', iostat=ios) 't'
    call motion_header(u, ios, 0)
    if (spec%analysis == 'statics') call put(u, ios, ',stable,residual')
    if (spec%out_energy) then
      do i = 1, 5
        call put(u, ios, ',' // trim(ew(i)))
      end do
    end if
    call lam_header(u, ios, 0)
    if (elements) then
      do c = 1, spec%nf
        if (force_is_contact(spec%ftab(1, c))) then
          do i = 1, 4
            call put(u, ios, ',' // trim(spec%force_names(c)) // '.' // trim(cw(i)))
          end do
        else if (spec%ftab(1, c) == FRC_FRICTION) then
          do i = 1, 3
            call put(u, ios, ',' // trim(spec%force_names(c)) // '.' // trim(fw(i)))
          end do
        end if
      end do
    end if
    do j = 1, spec%nmeas
      call put(u, ios, ',' // trim(spec%meas_names(j)))
    end do
    do j = 1, spec%npar
      call motion_header(u, ios, j)
      if (lam_sens) call lam_header(u, ios, j)
      do c = 1, spec%nmeas               ! the measures' derivatives
        call put_col(u, ios, trim(spec%meas_names(c)), j)
      end do
    end do
    if (ios == 0) write (u, '(a)', iostat=ios) ''
    ! rows
    do k = 1, nout
      if (ios /= 0) exit
      call row_values(k, v, i)
      call num(v(1), word, nw)
      write (u, '(a)', advance='no', iostat=ios) word(1:nw)
      do c = 2, i
        call num(v(c), word, nw)
        if (ios == 0) write (u, '(a,a)', advance='no', iostat=ios) ',', word(1:nw)
      end do
      if (ios == 0) write (u, '(a)', iostat=ios) ''
    end do
    close (u)
    if (ios /= 0) call die(2, 'cannot write ' // path // ' (disk full?)')
  end subroutine write_csv

  !> Write text without a newline (nothing once a write has failed).
  subroutine put(u, ios, text)
    integer, intent(in) :: u
    integer, intent(inout) :: ios
    character(len=*), intent(in) :: text
    if (ios == 0) write (u, '(a)', advance='no', iostat=ios) text
  end subroutine put

  !> A column's name: ",NAME" (j = 0), or ",d(NAME)/d(P)" of design parameter j.
  subroutine put_col(u, ios, name, j)
    integer, intent(in) :: u, j
    integer, intent(inout) :: ios
    character(len=*), intent(in) :: name
    if (j == 0) then
      call put(u, ios, ',' // name)
    else
      call put(u, ios, ',d(' // name // ')/d(' // trim(spec%par_names(j)) // ')')
    end if
  end subroutine put_col

  !> The motion columns NAME.x ... NAME.theta_ddot per body (statics and positions-only
  !! kinematics: NAME.x, NAME.y, NAME.theta), or their derivatives along parameter j.
  subroutine motion_header(u, ios, j)
    integer, intent(in) :: u, j
    integer, intent(inout) :: ios
    character(len=*), parameter :: sfx(9) = [character(len=12) :: '.x', '.y', '.theta', &
      '.x_dot', '.y_dot', '.theta_dot', '.x_ddot', '.y_ddot', '.theta_ddot']
    integer :: b, i
    do b = 1, spec%nb
      do i = 1, merge(3, 9, positions_alone())
        call put_col(u, ios, trim(spec%body_names(b)) // trim(sfx(i)), j)
      end do
    end do
  end subroutine motion_header

  !> The optional columns from the multipliers (lambda.LABEL, NAME.fx ... NAME.mz_j,
  !! NAME.effort), or their derivatives along parameter j.
  subroutine lam_header(u, ios, j)
    integer, intent(in) :: u, j
    integer, intent(inout) :: ios
    character(len=*), parameter :: rw(6) = [character(len=6) :: 'fx', 'fy', 'mz', 'fx_j', &
      'fy_j', 'mz_j']
    integer :: r, c, i
    if (spec%out_lam) then
      do r = 1, neq
        call put_col(u, ios, 'lambda.' // trim(row_label(r)), j)
      end do
    end if
    if (spec%out_reac) then
      do c = 1, spec%nc
        do i = 1, 6
          call put_col(u, ios, trim(spec%con_names(c)) // '.' // trim(rw(i)), j)
        end do
      end do
    end if
    if (spec%out_eff) then
      do c = 1, spec%nc
        if (con_is_driver(spec%ctab(1, c))) &
          call put_col(u, ios, trim(spec%con_names(c)) // '.effort', j)
      end do
    end if
  end subroutine lam_header

  !> Statics and positions-only kinematics write x, y, theta per body alone.
  logical function positions_alone()
    positions_alone = spec%analysis == 'statics' .or. spec%positions_only
  end function positions_alone

  !> The numbers of row k, in the order of the header; n of them.
  subroutine row_values(k, v, n)
    integer, intent(in) :: k
    real(wp), intent(out) :: v(:)
    integer, intent(out) :: n
    real(wp) :: none(6, 0)
    integer :: c, j
    n = 1
    v(1) = tout(k)
    call motion_values(qout(:, k), qdout(:, k), qddout(:, k), v, n)
    if (spec%analysis == 'statics') then
      v(n + 1) = real(stable, wp); v(n + 2) = resid; n = n + 2
    end if
    if (spec%out_energy) then
      ! kinetic, potential, their sum, the drift of positions and velocities
      v(n + 1) = eout(1, k); v(n + 2) = eout(2, k); v(n + 3) = eout(1, k) + eout(2, k)
      v(n + 4) = eout(3, k); v(n + 5) = eout(4, k); n = n + 5
    end if
    if (spec%out_reac) then
      call lam_values(lamout(:, k), reac(:, :, k), v, n)
    else
      call lam_values(lamout(:, k), none, v, n)
    end if
    if (elements) then
      do c = 1, spec%nf
        if (force_is_contact(spec%ftab(1, c))) then
          v(n + 1:n + 4) = eo(1:4, c, k); n = n + 4
        else if (spec%ftab(1, c) == FRC_FRICTION) then
          v(n + 1) = eo(1, c, k); v(n + 2) = eo(2, c, k); v(n + 3) = eo(4, c, k); n = n + 3
        end if
      end do
    end if
    if (spec%nmeas > 0) then
      v(n + 1:n + spec%nmeas) = mvals(:, k); n = n + spec%nmeas
    end if
    do j = 1, spec%npar
      call motion_values(sq(:, j, k), sqd(:, j, k), sqdd(:, j, k), v, n)
      if (lam_sens) then
        if (spec%out_reac) then
          call lam_values(slam(:, j, k), dreac(:, :, j, k), v, n)
        else
          call lam_values(slam(:, j, k), none, v, n)
        end if
      end if
      if (spec%nmeas > 0) then
        v(n + 1:n + spec%nmeas) = mdp(:, j, k); n = n + spec%nmeas
      end if
    end do
  end subroutine row_values

  !> The motion columns from q, q_dot, q_ddot (or their derivatives), after v(n).
  subroutine motion_values(q, qd, qdd, v, n)
    real(wp), intent(in) :: q(:), qd(:), qdd(:)
    real(wp), intent(inout) :: v(:)
    integer, intent(inout) :: n
    integer :: b
    do b = 1, spec%nb
      v(n + 1:n + 3) = q(3 * b - 2:3 * b); n = n + 3
      if (positions_alone()) cycle
      v(n + 1:n + 3) = qd(3 * b - 2:3 * b)
      v(n + 4:n + 6) = qdd(3 * b - 2:3 * b)
      n = n + 6
    end do
  end subroutine motion_values

  !> The columns from the multipliers lam (neq) and the reactions rc (6, nc; asked for when
  !! the reactions are), or their derivatives, after v(n); an effort is -lambda of its row.
  subroutine lam_values(lam, rc, v, n)
    real(wp), intent(in) :: lam(:), rc(:, :)
    real(wp), intent(inout) :: v(:)
    integer, intent(inout) :: n
    integer :: c
    if (spec%out_lam) then
      v(n + 1:n + neq) = lam; n = n + neq
    end if
    if (spec%out_reac) then
      do c = 1, spec%nc
        v(n + 1:n + 6) = rc(:, c); n = n + 6
      end do
    end if
    if (spec%out_eff) then
      do c = 1, size(drow)
        v(n + 1) = -lam(drow(c)); n = n + 1
      end do
    end if
  end subroutine lam_values

  !> Degrees of freedom and redundancy at the configuration assembled from q0 at time t:
  !! the report `mbd2d check` prints (on standard output) and DofReport.to_csv's CSV.
  subroutine run_check()
    integer :: rank, mobility, worst, r, nw, u, ios, j
    real(wp) :: resid, counts(5)
    real(wp), allocatable :: qa(:)
    integer, allocatable :: red(:), dp(:)
    character(len=32) :: word, ts
    character(kind=c_char) :: cb(32)
    if (spec%nlabels >= 0 .and. spec%nlabels /= neq) call die(2, trim(model_path) // &
      ': ' // trim(itoa(spec%nlabels)) // ' labels for ' // trim(itoa(neq)) // ' rows of Phi')
    if (spec%out_energy .or. spec%out_lam .or. spec%out_reac .or. spec%out_eff .or. &
        spec%npar > 0 .or. spec%ncase > 0 .or. spec%positions_only .or. spec%nmeas > 0) &
      call die(2, &
      trim(model_path) // ': check takes no outputs, sensitivities, cases or positions_only')
    allocate (q0(nq), qa(nq), red(neq), dp(neq), stat=ierr)
    if (ierr /= 0) call die(2, 'not enough memory for the model')
    q0 = 0.0_wp
    q0(1:3 * spec%nb) = reshape(spec%q0, [3 * spec%nb])
    call api_analyze(spec%nb, spec%ctab, spec%rpar, q0, spec%tstat, spec%tol, qa, rank, &
                     mobility, red, dp, resid, worst, status, msg)
    if (status < 0) call die(2, where(worst, msg))
    if (status == MBD_INCONSISTENT) call die(4, trim(msg) // ': the constraints' // &
      trim(dep_names(dp)) // ' cannot all hold; check their points and dimensions')
    if (status /= MBD_OK) then
      if (worst > 0 .and. worst <= spec%nc) call die(4, trim(msg) // ' ("' // &
        trim(spec%con_names(worst)) // '")')
      call die(4, trim(msg))
    end if
    ! the report, as str(DofReport)
    nw = max(0, min(int(format_num(real(spec%tstat, c_double), FMT_G6, cb, 32_c_int)), 31))
    ts = ''
    do j = 1, nw
      ts(j:j) = cb(j)
    end do
    write (*, '(a)') "model '" // trim(spec%name) // "' at t = " // trim(ts)
    write (*, '(a,i0)') '  coordinates        ', nq
    write (*, '(a,i0)') '  equations          ', neq
    write (*, '(a,i0)') '  rank of J          ', rank
    write (*, '(a,i0,a)') '  degrees of freedom ', nq - rank, '   (coordinates - rank)'
    write (*, '(a,i0,a)') '  mobility           ', mobility, '   (joints alone, without drivers)'
    write (*, '(a,i0,a)') '  redundant          ', count(red /= 0), ' equation(s)'
    do r = 1, neq
      if (red(r) /= 0) write (*, '(a)') '    ' // trim(row_label(r))
    end do
    if (any(red /= 0)) write (*, '(a)') '  redundant equations repeat what the others impose: '// &
      'kinematics solves them in least squares; reactions are statically indeterminate'
    ! the CSV, as DofReport.to_csv (numpy.savetxt: "%.16e", lines ending in LF)
    open (newunit=u, file=trim(out_path), status='replace', action='write', access='stream', &
          form='unformatted', iostat=ios)
    if (ios /= 0) call die(2, 'cannot write ' // trim(out_path))
    call sput(u, ios, 't')
    call coordinate_header(u, ios, '', 0)
    call sput(u, ios, ',coordinates,equations,rank,dof,mobility')
    do r = 1, neq
      call sput(u, ios, ',redundant.' // trim(row_label(r)))
    end do
    call sput(u, ios, achar(10))
    call num(spec%tstat, word, nw)
    call sput(u, ios, word(1:nw))
    counts = real([nq, neq, rank, nq - rank, mobility], wp)
    do j = 1, nq + 5 + neq
      if (j <= nq) then
        call num(qa(j), word, nw)
      else if (j <= nq + 5) then
        call num(counts(j - nq), word, nw)
      else
        call num(merge(1.0_wp, 0.0_wp, red(j - nq - 5) /= 0), word, nw)
      end if
      call sput(u, ios, ',' // word(1:nw))
    end do
    call sput(u, ios, achar(10))
    close (u)
    if (ios /= 0) call die(2, 'cannot write ' // trim(out_path) // ' (disk full?)')
  end subroutine run_check

  !> Modes: the small vibrations about the equilibrium (Model.modes) written as
  !! ModesResult.to_csv writes them: one row per mode (mode, omega2, frequency_hz, kind, the
  !! shape NAME.x, NAME.y, NAME.theta per body), or with "outputs damped" one row per damped
  !! eigenvalue (s_real, s_imag, frequency_hz, damped_frequency_hz, damping_ratio, then its
  !! complex shape NAME.x.re, NAME.x.im, NAME.y.re, ... per body).
  subroutine run_modes()
    real(wp), parameter :: TWO_PI = 2 * 3.141592653589793_wp
    real(wp), allocatable :: qe(:), lam(:), w2(:), sre(:), sim(:), shp(:, :), fpm(:), &
                             zre(:, :), zim(:, :)
    integer, allocatable :: kinds(:), ftm(:, :)
    integer :: kmax, nk, u, ios, k, j, nw, nz
    real(wp) :: mag, row(5)
    character(len=32) :: word
    call linear_checks('modes')
    if (spec%out_energy .or. spec%out_lam .or. spec%out_reac .or. spec%out_eff .or. &
        spec%npar > 0 .or. spec%ncase > 0 .or. spec%positions_only .or. spec%nmeas > 0) &
      call die(2, trim(model_path) // ': modes takes no outputs but "damped", and no '// &
               'sensitivities, cases, measures or positions_only')
    kmax = nq
    if (spec%count > 0) kmax = min(spec%count, nq)
    nz = merge(2 * kmax, 0, spec%out_damped)       ! the damped shapes' columns
    call mem_check(REAL_BYTES * (real(nq, wp) * (kmax + 2 * nz + 3) + 6 * real(kmax, wp)), &
                   'the modes (' // trim(itoa(kmax)) // ' of ' // trim(itoa(nq)) // &
                   ' coordinates)', 'give a smaller count', status, msg)
    if (status /= MBD_OK) call die(2, trim(model_path) // ': ' // trim(msg))
    allocate (qe(nq), lam(neq), w2(kmax), kinds(kmax), sre(2 * kmax), sim(2 * kmax), &
              shp(nq, kmax), zre(nq, nz), zim(nq, nz), stat=ierr)
    if (ierr /= 0) call die(2, 'not enough memory for the modes')
    call linear_inputs(ftm, fpm)
    if (spec%out_damped) then
      call api_modes(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftm, fpm, q0, &
                     spec%tstat, merge(0, 1, spec%at_q0), kmax, qe, lam, stable, resid, w2, &
                     kinds, sre, sim, shp, iinfo, status, msg, spec%solver, zre, zim)
    else
      call api_modes(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftm, fpm, q0, &
                     spec%tstat, merge(0, 1, spec%at_q0), kmax, qe, lam, stable, resid, w2, &
                     kinds, sre, sim, shp, iinfo, status, msg, spec%solver)
    end if
    if (status < 0) call die_input(iinfo(2), msg)
    if (status == MBD_NO_MEMORY) call die(2, trim(msg))
    if (status /= MBD_OK) call die(4, trim(msg) // ' (no modes written)')
    nk = min(kmax, iinfo(1))
    open (newunit=u, file=trim(out_path), status='replace', action='write', access='stream', &
          form='unformatted', iostat=ios)
    if (ios /= 0) call die(2, 'cannot write ' // trim(out_path))
    if (spec%out_damped) then
      call sput(u, ios, 's_real,s_imag,frequency_hz,damped_frequency_hz,damping_ratio')
      do k = 1, spec%nb
        do j = 1, 3
          call sput(u, ios, ',' // trim(spec%body_names(k)) // '.' // trim(XYT(j)) // '.re,' // &
                    trim(spec%body_names(k)) // '.' // trim(XYT(j)) // '.im')
        end do
      end do
      call sput(u, ios, achar(10))
      do k = 1, 2 * nk
        mag = hypot(sre(k), sim(k))                  ! as numpy's abs of a complex
        row = [sre(k), sim(k), mag / TWO_PI, abs(sim(k)) / TWO_PI, 0.0_wp]
        if (mag > 0.0_wp) row(5) = -sre(k) / mag + 0.0_wp
        do j = 1, 5
          call num(row(j), word, nw)
          if (j > 1) call sput(u, ios, ',')
          call sput(u, ios, word(1:nw))
        end do
        do j = 1, 3 * spec%nb                          ! the shape: re, im per coordinate
          call num(zre(j, k), word, nw)
          call sput(u, ios, ',' // word(1:nw))
          call num(zim(j, k), word, nw)
          call sput(u, ios, ',' // word(1:nw))
        end do
        call sput(u, ios, achar(10))
      end do
    else
      call sput(u, ios, 'mode,omega2,frequency_hz,kind')
      do k = 1, spec%nb
        call sput(u, ios, ',' // trim(spec%body_names(k)) // '.x,' // &
                  trim(spec%body_names(k)) // '.y,' // trim(spec%body_names(k)) // '.theta')
      end do
      call sput(u, ios, achar(10))
      do k = 1, nk
        row(1:4) = [real(k - 1, wp), w2(k), sqrt(max(w2(k), 0.0_wp)) / TWO_PI, &
                    real(kinds(k), wp)]
        do j = 1, 4 + 3 * spec%nb
          if (j <= 4) then
            call num(row(j), word, nw)
          else
            call num(shp(j - 4, k), word, nw)
          end if
          if (j > 1) call sput(u, ios, ',')
          call sput(u, ios, word(1:nw))
        end do
        call sput(u, ios, achar(10))
      end do
    end if
    close (u)
    if (ios /= 0) call die(2, 'cannot write ' // trim(out_path) // ' (disk full?)')
  end subroutine run_modes

  !> The two CSV header columns ",d(NAME)/d(PAR).re,d(NAME)/d(PAR).im" (frf).
  subroutine pair_header(u, ios, name, par)
    integer, intent(in) :: u
    integer, intent(inout) :: ios
    character(len=*), intent(in) :: name, par
    call sput(u, ios, ',d(' // name // ')/d(' // par // ').re,d(' // name // ')/d(' // par // &
              ').im')
  end subroutine pair_header

  !> ",RE,IM" of one complex number (+ 0: no -0.0, as the Python table).
  subroutine put_pair(u, ios, re, im)
    integer, intent(in) :: u
    integer, intent(inout) :: ios
    real(wp), intent(in) :: re, im
    character(len=32) :: word
    integer :: nw
    call num(re + 0.0_wp, word, nw)
    call sput(u, ios, ',' // word(1:nw))
    call num(im + 0.0_wp, word, nw)
    call sput(u, ios, ',' // word(1:nw))
  end subroutine put_pair

  !> What modes and frf need from the file (exit 2 otherwise): the masses, and as many row
  !! labels as rows of Phi.
  subroutine linear_checks(what)
    character(len=*), intent(in) :: what
    if (.not. spec%have_masses) call die(2, trim(model_path) // ': ' // what // ' needs the '// &
      'masses: body lines NAME X0 Y0 THETA0 MASS INERTIA VX0 VY0 OMEGA0')
    if (spec%nlabels >= 0 .and. spec%nlabels /= neq) call die(2, trim(model_path) // &
      ': ' // trim(itoa(spec%nlabels)) // ' labels for ' // trim(itoa(neq)) // ' rows of Phi')
  end subroutine linear_checks

  !> q0 from the body lines, and the force table and parameters (at least one entry) as the
  !! core takes them (modes, frf).
  subroutine linear_inputs(ftm, fpm)
    integer, allocatable, intent(out) :: ftm(:, :)
    real(wp), allocatable, intent(out) :: fpm(:)
    allocate (q0(nq), ftm(NFT, spec%nf), fpm(max(1, size(spec%fpar))), stat=ierr)
    if (ierr /= 0) call die(2, 'not enough memory for the model''s tables')
    q0 = 0.0_wp
    q0(1:3 * spec%nb) = reshape(spec%q0, [3 * spec%nb])
    ftm = spec%ftab
    fpm = 0.0_wp
    fpm(1:size(spec%fpar)) = spec%fpar
  end subroutine linear_inputs

  !> The linearized system (Model.linearize) written as LinearizedSystem.to_csv writes it:
  !! matrix,row,column,value for every entry of A (states by states), B (states by inputs),
  !! C (outputs by states) and D (outputs by inputs), row by row; the states z1 .. zf,
  !! v1 .. vf, the inputs the sensitivities block's names, the outputs the coordinates (with
  !! "outputs velocities" their velocities, with "outputs efforts" each driver's effort.NAME,
  !! -lambda on its row).
  subroutine run_linearize()
    real(wp), allocatable :: qe(:), lam(:), fpm(:), a(:, :), b(:, :), c(:, :), d(:, :)
    integer, allocatable :: ftm(:, :)
    integer :: ns, f, u, ios, i, j, k, pass, nqo, nv
    call linear_checks('linearize')
    if (spec%out_energy .or. spec%out_lam .or. spec%out_reac .or. &
        spec%out_damped .or. spec%ncase > 0 .or. spec%positions_only .or. &
        spec%nmeas > 0 .or. spec%freq_line > 0) &
      call die(2, trim(model_path) // ': linearize takes no outputs but "velocities" and '// &
               '"efforts", and no cases, measures, frequencies or positions_only')
    if (spec%out_eff .and. size(drow) == 0) call die(2, trim(model_path) // ': the output '// &
      '"efforts": the model has no drivers (an effort is what a driver holding its motion '// &
      'exerts)')
    nv = merge(2, 1, spec%out_vel) * nq          ! the coordinates' (and velocities') rows
    nqo = nv + merge(neq, 0, spec%out_eff)
    if (spec%npar == 0) call die(2, trim(model_path) // ': linearize needs its inputs: a '// &
      '"sensitivities" block naming the design parameters varied')
    call check_sensitivities()
    call linear_inputs(ftm, fpm)
    ns = max(2 * (nq - neq), 1)
    do pass = 1, 2                                ! again with 2 nfree states (redundancy)
      call mem_check(REAL_BYTES * (real(ns + nqo, wp) * (ns + spec%npar) + nq), &
                     'the linearized system (' // trim(itoa(ns)) // ' states)', &
                     'use a model with fewer free motions', status, msg)
      if (status /= MBD_OK) call die(2, trim(model_path) // ': ' // trim(msg))
      if (allocated(a)) deallocate (a, b, c, d)
      allocate (qe(nq), lam(neq), a(ns, ns), b(ns, spec%npar), c(nqo, ns), &
                d(nqo, spec%npar), stat=ierr)
      if (ierr /= 0) call die(2, 'not enough memory for the linearized system')
      call api_linearize(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftm, fpm, q0, &
                         spec%tstat, merge(0, 1, spec%at_q0), spec%ptab, qe, lam, stable, &
                         resid, a, b, c, d, iinfo, status, msg, spec%solver, &
                         merge(1, 0, spec%out_vel), merge(1, 0, spec%out_eff))
      f = iinfo(1)
      if (status /= MBD_BAD_COUNT .or. 2 * f <= ns) exit
      ns = 2 * f
      deallocate (qe, lam)
    end do
    if (status < 0) call die_input(iinfo(2), msg)
    if (status == MBD_NO_MEMORY) call die(2, trim(msg))
    if (status /= MBD_OK) call die(4, trim(msg) // ' (no system written)')
    open (newunit=u, file=trim(out_path), status='replace', action='write', access='stream', &
          form='unformatted', iostat=ios)
    if (ios /= 0) call die(2, 'cannot write ' // trim(out_path))
    call sput(u, ios, 'matrix,row,column,value' // achar(10))
    do i = 1, 2 * f                               ! A: states by states
      do j = 1, 2 * f
        call lin_entry(u, ios, 'A', state_label(i, f), state_label(j, f), a(i, j))
      end do
    end do
    do i = 1, 2 * f                               ! B: states by inputs
      do k = 1, spec%npar
        call lin_entry(u, ios, 'B', state_label(i, f), trim(spec%par_names(k)), b(i, k))
      end do
    end do
    do i = 1, nv                                  ! C: outputs by states
      do j = 1, 2 * f
        call lin_entry(u, ios, 'C', output_label(i), state_label(j, f), c(i, j))
      end do
    end do
    do i = 1, merge(size(drow), 0, spec%out_eff)  ! (the efforts: -lambda)
      do j = 1, 2 * f
        call lin_entry(u, ios, 'C', effort_label(i), state_label(j, f), -c(nv + drow(i), j))
      end do
    end do
    do i = 1, nv                                  ! D: outputs by inputs
      do k = 1, spec%npar
        call lin_entry(u, ios, 'D', output_label(i), trim(spec%par_names(k)), d(i, k))
      end do
    end do
    do i = 1, merge(size(drow), 0, spec%out_eff)
      do k = 1, spec%npar
        call lin_entry(u, ios, 'D', effort_label(i), trim(spec%par_names(k)), &
                       -d(nv + drow(i), k))
      end do
    end do
    close (u)
    if (ios /= 0) call die(2, 'cannot write ' // trim(out_path) // ' (disk full?)')
  end subroutine run_linearize

  !> One line of the linearized system's CSV: matrix,row,column,value.
  subroutine lin_entry(u, ios, mat, row, col, v)
    integer, intent(in) :: u
    integer, intent(inout) :: ios
    character(len=*), intent(in) :: mat, row, col
    real(wp), intent(in) :: v
    character(len=32) :: word
    integer :: nl
    call num(v + 0.0_wp, word, nl)
    call sput(u, ios, mat // ',' // row // ',' // col // ',' // word(1:nl) // achar(10))
  end subroutine lin_entry

  !> The label of the i-th driver's effort: effort.NAME.
  function effort_label(i) result(label)
    integer, intent(in) :: i
    character(len=:), allocatable :: label
    integer :: j, r
    r = 1
    label = 'effort.'
    do j = 1, spec%nc
      if (r == drow(i)) then
        label = 'effort.' // trim(spec%con_names(j)); return
      end if
      r = r + con_nrow(spec%ctab(1, j))
    end do
  end function effort_label

  !> The label of state i of f free motions: z1 .. zf, then v1 .. vf.
  function state_label(i, f) result(label)
    integer, intent(in) :: i, f
    character(len=:), allocatable :: label
    if (i <= f) then
      label = 'z' // trim(itoa(i))
    else
      label = 'v' // trim(itoa(i - f))
    end if
  end function state_label

  !> The label of output i: BODY.x, BODY.y, BODY.theta, then (past nq) their velocities
  !! BODY.x_dot, ...
  function output_label(i) result(label)
    integer, intent(in) :: i
    character(len=:), allocatable :: label
    integer :: j
    j = mod(i - 1, nq) + 1
    label = trim(spec%body_names((j - 1) / 3 + 1)) // '.' // trim(XYT(mod(j - 1, 3) + 1))
    if (i > nq) label = label // '_dot'
  end function output_label

  !> The frequency response (Model.frequency_response) written as
  !! FrequencyResponseResult.to_csv writes it: one row per frequency, frequency_hz, then for
  !! each input (the sensitivities block) and body d(NAME.x)/d(INPUT).re, .im, then y, theta;
  !! with "outputs reactions" after each input's bodies every constraint's reaction response
  !! d(NAME.fx)/d(INPUT).re, .im, ... mz_j (the reactions' derivatives along Re and Im of the
  !! response, the input's own term in the real part only).
  subroutine run_frf()
    real(wp), parameter :: TWO_PI = 2 * 3.141592653589793_wp
    character(len=4), parameter :: WORDS(6) = ['fx  ', 'fy  ', 'mz  ', 'fx_j', 'fy_j', 'mz_j']
    real(wp), allocatable :: qe(:), lam(:), hre(:, :, :), him(:, :, :), fpm(:), lre(:, :, :), &
                             lim(:, :, :), gre(:, :, :, :), gim(:, :, :, :), gp(:, :, :, :), &
                             gloc(:, :, :, :), qq(:, :), ll(:, :), tt(:), zq(:, :, :), &
                             zl(:, :, :)
    integer, allocatable :: ftm(:, :)
    integer :: nw, u, ios, j, k, b, c, nr, nl, nm
    logical :: mult
    character(len=32) :: word
    call linear_checks('frf')
    if (spec%out_energy .or. spec%out_lam .or. spec%out_eff .or. &
        spec%out_damped .or. spec%ncase > 0 .or. spec%positions_only .or. spec%nmeas > 0) &
      call die(2, trim(model_path) // ': frf takes no outputs but "reactions", and no '// &
               'cases, measures or positions_only')
    if (spec%npar == 0) call die(2, trim(model_path) // ': frf needs its inputs: a '// &
      '"sensitivities" block naming the design parameters varied')
    if (spec%freq_line == 0) call die(2, trim(model_path) // ': frf needs a "frequencies" '// &
      'block (Hz)')
    call check_sensitivities()
    nw = size(spec%freq)
    call mem_check(REAL_BYTES * (2 * real(nq, wp) * spec%npar * nw + 2 * nq + neq), &
                   'the frequency response (' // trim(itoa(nw)) // ' frequencies)', &
                   'give fewer frequencies or inputs', status, msg)
    if (status /= MBD_OK) call die(2, trim(model_path) // ': ' // trim(msg))
    nr = merge(nw, 0, spec%out_reac)              ! the reactions' frequencies
    mult = spec%out_reac .or. size(drow) > 0      ! the multipliers' response: the efforts
    nm = merge(nw, 0, mult)
    call mem_check(REAL_BYTES * spec%npar * (real(nm, wp) * 2 * neq + &
                                             real(nr, wp) * (24 * spec%nc + 2 * nq)), &
                   'the reaction responses (' // trim(itoa(nw)) // ' frequencies)', &
                   'give fewer frequencies or inputs', status, msg)
    if (status /= MBD_OK) call die(2, trim(model_path) // ': ' // trim(msg))
    allocate (qe(nq), lam(neq), hre(nq, spec%npar, nw), him(nq, spec%npar, nw), &
              lre(neq, spec%npar, nm), lim(neq, spec%npar, nm), &
              gre(6, spec%nc, spec%npar, nr), gim(6, spec%nc, spec%npar, nr), &
              gp(6, spec%nc, spec%npar, 1), gloc(6, spec%nc, spec%npar, max(nr, 1)), stat=ierr)
    if (ierr /= 0) call die(2, 'not enough memory for the frequency response')
    call linear_inputs(ftm, fpm)
    if (mult) then
      call api_frf(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftm, fpm, q0, &
                   spec%tstat, merge(0, 1, spec%at_q0), spec%ptab, TWO_PI * spec%freq, qe, &
                   lam, stable, resid, hre, him, iinfo, status, msg, spec%solver, lre, lim)
    else
      call api_frf(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftm, fpm, q0, &
                   spec%tstat, merge(0, 1, spec%at_q0), spec%ptab, TWO_PI * spec%freq, qe, &
                   lam, stable, resid, hre, him, iinfo, status, msg, spec%solver)
    end if
    if (status < 0) call die_input(iinfo(2), msg)
    if (status == MBD_NO_MEMORY) call die(2, trim(msg))
    if (status /= MBD_OK .and. iinfo(8) > 0) then
      call num(spec%freq(iinfo(8)), word, nl)
      call die(4, trim(msg) // ': the response at ' // word(1:nl) // ' Hz is unbounded; '// &
               'leave that frequency out or give the mode damping (no response written)')
    end if
    if (status /= MBD_OK) call die(4, trim(msg) // ' (no response written)')
    if (spec%out_reac) then        ! the reactions' derivatives along (Re H, Re dlambda),
      allocate (qq(nq, nw), ll(neq, nw), tt(nw), zq(nq, spec%npar, 1), &   ! (Im H, Im dlambda)
                zl(neq, spec%npar, 1), stat=ierr)                         ! and nothing
      if (ierr /= 0) call die(2, 'not enough memory for the reaction responses')
      qq = spread(qe, 2, nw); ll = spread(lam, 2, nw); tt = spec%tstat
      zq = 0.0_wp; zl = 0.0_wp
      call api_reactions_dp(spec%nb, spec%ctab, spec%rpar, spec%ptab, qq, tt, ll, hre, lre, &
                            gre, gloc, status, msg)
      if (status == MBD_OK) call api_reactions_dp(spec%nb, spec%ctab, spec%rpar, spec%ptab, &
                                                  qq, tt, ll, him, lim, gim, gloc, status, msg)
      if (status == MBD_OK) call api_reactions_dp(spec%nb, spec%ctab, spec%rpar, spec%ptab, &
                                                  qq(:, 1:1), tt(1:1), ll(:, 1:1), zq, zl, &
                                                  gp, gloc(:, :, :, 1:1), status, msg)
      if (status /= MBD_OK) call die(4, trim(msg) // ' (no response written)')
    end if
    open (newunit=u, file=trim(out_path), status='replace', action='write', access='stream', &
          form='unformatted', iostat=ios)
    if (ios /= 0) call die(2, 'cannot write ' // trim(out_path))
    call sput(u, ios, 'frequency_hz')
    do k = 1, spec%npar
      do b = 1, spec%nb
        do c = 1, 3
          call pair_header(u, ios, trim(spec%body_names(b)) // '.' // trim(XYT(c)), &
                           trim(spec%par_names(k)))
        end do
      end do
      do b = 1, spec%nc                           ! the drivers' efforts: -lambda
        if (con_is_driver(spec%ctab(1, b))) call pair_header(u, ios, 'effort.' // &
          trim(spec%con_names(b)), trim(spec%par_names(k)))
      end do
      if (.not. spec%out_reac) cycle
      do b = 1, spec%nc
        do c = 1, 6
          call pair_header(u, ios, trim(spec%con_names(b)) // '.' // trim(WORDS(c)), &
                           trim(spec%par_names(k)))
        end do
      end do
    end do
    call sput(u, ios, achar(10))
    do j = 1, nw
      call num(spec%freq(j), word, nl)
      call sput(u, ios, word(1:nl))
      do k = 1, spec%npar
        do b = 1, 3 * spec%nb
          call put_pair(u, ios, hre(b, k, j), him(b, k, j))
        end do
        do b = 1, size(drow)
          call put_pair(u, ios, -lre(drow(b), k, j), -lim(drow(b), k, j))
        end do
        if (.not. spec%out_reac) cycle
        do b = 1, spec%nc                         ! Im: without the input's own term
          do c = 1, 6
            call put_pair(u, ios, gre(c, b, k, j), gim(c, b, k, j) - gp(c, b, k, 1))
          end do
        end do
      end do
      call sput(u, ios, achar(10))
    end do
    close (u)
    if (ios /= 0) call die(2, 'cannot write ' // trim(out_path) // ' (disk full?)')
  end subroutine run_frf

  !> The label of row r of Phi (lambda's column name): the file's labels, else rowR.
  function row_label(r) result(s)
    integer, intent(in) :: r
    character(len=NAME_LEN + 8) :: s
    if (spec%nlabels == neq) then
      s = spec%labels(r)
    else
      s = 'row' // trim(itoa(r))
    end if
  end function row_label

  !> A sweep: every case of the "cases" block in one batch call (as mbd2d.sweep makes it),
  !! written as mbd2d.write_sweep writes a sweep's CSV.
  subroutine run_sweep()
    integer :: iset(NISET), c, nfail, ne, nchunk, ic, c0, c1, nsl
    real(wp) :: rset(NRSET), bytes
    real(wp), allocatable :: bm(:, :), bv0(:), bfp(:)
    integer, allocatable :: bft(:, :)
    if (spec%out_energy .or. spec%out_lam .or. spec%out_reac .or. spec%out_eff) &
      call die(2, trim(model_path) // ': a sweep writes its own columns (q, q_dot, q_ddot, '// &
               'efforts, measures): give no "outputs" line with "cases"')
    call check_case_entries()
    iset = 0; rset = 0.0_wp
    if (spec%analysis == 'modes' .and. (spec%npar > 0 .or. spec%nmeas > 0 .or. &
        spec%positions_only .or. spec%out_damped .or. .not. spec%have_masses)) &
      call die(2, trim(model_path) // ': a sweep of modes takes the masses, and no '// &
               'sensitivities, measures, positions_only or outputs')
    if (spec%analysis == 'frf' .and. (spec%npar == 0 .or. spec%freq_line == 0 .or. &
        spec%nmeas > 0 .or. spec%out_damped)) &
      call die(2, trim(model_path) // ': a sweep of frf takes its inputs (a "sensitivities" '// &
               'block) and a "frequencies" block, and no measures or outputs')
    select case (spec%analysis)
    case ('kinematics')
      code = 1
      iset(1:7) = [spec%steps, spec%maxit, spec%every, spec%solver, 0, 0, &
                   merge(1, 0, spec%positions_only)]
      rset(1:4) = [spec%t0, spec%t_end, spec%tol, spec%tmin]
    case ('inverse-dynamics')
      code = 2
      iset(1:4) = [spec%steps, 0, spec%every, spec%solver]
      rset(1:3) = [spec%t0, spec%t_end, spec%tol]
    case ('statics')
      code = 3
      rset(11) = spec%tstat
    case ('modes', 'frf')
      code = merge(5, 6, spec%analysis == 'modes')
      iset(4) = spec%solver; iset(8) = merge(1, 0, spec%at_q0)
      rset(11) = spec%tstat
    case default
      code = 4
      iset(1:6) = [spec%steps, 0, spec%every, 0, spec%method, spec%max_steps]
      rset(1:10) = [spec%t0, spec%t_end, 0.0_wp, 0.0_wp, spec%rtol, spec%atol, spec%h, &
                    spec%rho_inf, spec%alpha, spec%beta]
    end select
    nrow = 1
    if (code == 1 .or. code == 2 .or. code == 4) nrow = kin_out_count(spec%steps, spec%every)
    if (code == 5) nrow = merge(min(spec%count, nq), nq, spec%count > 0)   ! the modes
    if (code == 6) nrow = size(spec%freq)                    ! the frequencies
    nd = merge(0, nrow, (code == 1 .and. spec%positions_only) .or. code >= 5)
    nlam = merge(0, neq, code == 1 .or. code >= 5); ne = merge(0, 4, code == 1 .or. code == 6)
    if (code == 5) ne = 6
    nsl = merge(neq, 0, lam_sens)
    if (code == 6) nsl = 2 * neq                 ! (the multipliers' response: re, im)
    bytes = REAL_BYTES * real(spec%ncase, wp) * (real(nrow, wp) * (nq + nlam + ne + &
            spec%nmeas + real(spec%npar, wp) * (3 * nq + nsl + spec%nmeas)) + &
            2.0_wp * nq * nd + 2 * NINFO + nq) + 4.0_wp * spec%ncase * (2 * neq + NINFO + 3)
    call mem_check(bytes, 'the outputs of ' // trim(itoa(spec%ncase)) // ' cases', &
                   'give fewer cases or steps', status, msg)
    if (status /= MBD_OK) call die(2, trim(model_path) // ':' // trim(itoa(spec%cases_line)) &
                                   // ': ' // trim(msg))
    allocate (bq(nq, nrow, spec%ncase), bqd(nq, nd, spec%ncase), bqdd(nq, nd, spec%ncase), &
              blam(nlam, nrow, spec%ncase), be(ne, nrow, spec%ncase), &
              brinfo(NINFO, spec%ncase), bqsing(nq, spec%ncase), biinfo(NINFO, spec%ncase), &
              bdep(neq, spec%ncase), bred(neq, spec%ncase), bstat(spec%ncase), &
              bmsg(spec%ncase), nkeep(spec%ncase), cstat(spec%ncase), cmsg(spec%ncase), &
              tout(nrow), q0(nq), bmv(spec%nmeas, nrow, spec%ncase), &
              bmbad(3, spec%ncase), bsq(nq, spec%npar, nrow, spec%ncase), &
              bsqd(nq, spec%npar, nrow, spec%ncase), bsqdd(nq, spec%npar, nrow, spec%ncase), &
              bslam(nsl, spec%npar, nrow, spec%ncase), &
              bdm(spec%nmeas, spec%npar, nrow, spec%ncase), stat=ierr)
    ! the dynamic tables (a kinematic sweep takes none: zeros, as the Python sweep passes)
    if (ierr == 0) allocate (bm(2, spec%nb), bv0(nq), bft(NFT, merge(0, spec%nf, code == 1)), &
                             bfp(max(1, size(spec%fpar))), stat=ierr)
    if (ierr /= 0) call die(2, 'not enough memory for the outputs of ' // &
                            trim(itoa(spec%ncase)) // ' cases; give fewer cases or steps')
    q0 = 0.0_wp; bv0 = 0.0_wp; bm = 0.0_wp; bfp = 0.0_wp
    q0(1:3 * spec%nb) = reshape(spec%q0, [3 * spec%nb])
    if (code /= 1) then
      bm = spec%bmass; bft = spec%ftab; bfp(1:size(spec%fpar)) = spec%fpar
      bv0(1:3 * spec%nb) = reshape(spec%v0, [3 * spec%nb])
    end if
    if (code == 6) then              ! (the frequency response's times: its omega, rad/s)
      tout = 2 * 3.141592653589793_wp * spec%freq
    else
      call times()
    end if
    ! the cases in chunks, run in parallel (OpenMP) where the build has it: each case's
    ! numbers depend on its own values alone, so any split gives the same bytes
    nchunk = min(spec%ncase, 64)
    !$omp parallel do schedule(dynamic, 1) private(c0, c1)
    do ic = 1, nchunk
      c0 = int((int(ic - 1, int64) * spec%ncase) / nchunk) + 1
      c1 = int((int(ic, int64) * spec%ncase) / nchunk)
      call batch_run(code, spec%nb, spec%ctab, spec%rpar, bm, &
                     merge(spec%grav, 0.0_wp, code /= 1), bft, bfp, q0, bv0, spec%vtab, &
                     spec%cvals(spec%ncp + 1:, c0:c1), spec%opens, iset, rset, &
                     bq(:, :, c0:c1), bqd(:, :, c0:c1), bqdd(:, :, c0:c1), &
                     blam(:, :, c0:c1), be(:, :, c0:c1), biinfo(:, c0:c1), brinfo(:, c0:c1), &
                     bqsing(:, c0:c1), bdep(:, c0:c1), bred(:, c0:c1), bstat(c0:c1), &
                     bmsg(c0:c1), tout, spec%meas_kind, spec%meas_int, spec%meas_pts, &
                     spec%meas_ref, bmv(:, :, c0:c1), bmbad(:, c0:c1), spec%ptab, &
                     bsq(:, :, :, c0:c1), bsqd(:, :, :, c0:c1), bsqdd(:, :, :, c0:c1), &
                     bslam(:, :, :, c0:c1), bdm(:, :, :, c0:c1))
    end do
    !$omp end parallel do
    do c = 1, spec%ncase             ! a design parameter the core refused: the file's fault
      if (bstat(c) < 0 .and. biinfo(2, c) <= -2000000) &
        call die(2, param_where(-2000000 - biinfo(2, c), bmsg(c)))
    end do
    nfail = 0
    do c = 1, spec%ncase
      call case_outcome(c)
      if (cstat(c) /= 0) then
        nfail = nfail + 1
        if (nfail <= 5) write (error_unit, '(a,i0,a,a)') 'mbd2d-solve: case ', c - 1, ': ', &
          trim(cmsg(c))
      end if
    end do
    call write_sweep_csv(trim(out_path))
    if (spec%analysis == 'dynamics') call stiff_cases()
  end subroutine run_sweep

  !> The cases whose dopri5 (partitioned) steps were limited by stability, on one line (the
  !! Python sweep's StiffnessWarning).
  subroutine stiff_cases()
    integer :: c, ns
    character(len=200) :: list
    ns = 0; list = ''
    do c = 1, spec%ncase
      if (biinfo(11, c) /= 1) cycle
      ns = ns + 1
      if (ns == 1) then
        list = ' ' // trim(itoa(c - 1))
      else if (ns <= 8) then
        list = trim(list) // ', ' // trim(itoa(c - 1))
      end if
    end do
    if (ns == 0) return
    if (ns > 8) list = trim(list) // ', ...'
    write (error_unit, '(a)') 'mbd2d-solve: warning: ' // trim(itoa(ns)) // ' of ' // &
      trim(itoa(spec%ncase)) // ' cases (case' // trim(list) // ') ran with steps ' // &
      'limited by stability, not accuracy: stiff variants; method = "generalized-alpha" ' // &
      'takes steps set by accuracy'
  end subroutine stiff_cases

  !> The entries the cases set and the open phases lie in the model's tables (a kinematic
  !! run takes the constraints' parameters alone).
  subroutine check_case_entries()
    integer :: j, n(4)
    n = [size(spec%rpar), 2 * spec%nb, 2, size(spec%fpar)]
    if (spec%analysis == 'kinematics') n(2:4) = 0
    do j = 1, spec%nv
      if (spec%vtab(2, j) > n(spec%vtab(1, j))) call die(2, trim(model_path) // ':' // &
        trim(itoa(spec%cases_line + spec%ncp + j)) // ': the case entry "' // &
        trim(itoa(spec%vtab(1, j))) // ' ' // trim(itoa(spec%vtab(2, j))) // &
        '" lies outside its table (' // trim(itoa(n(spec%vtab(1, j)))) // ' entries' // &
        trim(merge(' in kinematics', '              ', n(spec%vtab(1, j)) == 0)) // ')')
    end do
    do j = 1, size(spec%opens, 2)
      if (spec%opens(1, j) > size(spec%rpar) .or. spec%opens(2, j) > neq) call die(2, &
        trim(model_path) // ': open phase ' // trim(itoa(j)) // ' lies outside the '// &
        'parameters (' // trim(itoa(size(spec%rpar))) // ') or the rows of Phi (' // &
        trim(itoa(neq)) // ')')
    end do
  end subroutine check_case_entries

  !> Rows kept, status and message of case c, as the Python sweep decides them: a case
  !! that completed keeps its rows; any other keeps the rows before its failure (or before
  !! its first non-finite row) and has the status of the failure.
  subroutine case_outcome(c)
    integer, intent(in) :: c
    integer :: n, k
    logical :: clean
    if (code == 3 .or. code == 6) then        ! (frf: every frequency, or none)
      n = merge(merge(1, nrow, code == 3), 0, bstat(c) == MBD_OK)
    else                             ! (modes: the free motions, at most the modes asked for)
      n = max(0, min(biinfo(1, c), nrow))
    end if
    k = first_bad(c, n)
    clean = bstat(c) == MBD_OK .and. k > n
    if (code >= 5 .or. code == 3) clean = clean .and. ieee_is_finite(brinfo(1, c))
    cstat(c) = 0; cmsg(c) = ''; nkeep(c) = n
    if (bmbad(1, c) /= MBD_OK) then               ! its rows, without its measures
      bmv(:, :, c) = ieee_value(0.0_wp, ieee_quiet_nan)
      bdm(:, :, :, c) = ieee_value(0.0_wp, ieee_quiet_nan)
      if (clean) then
        cstat(c) = bmbad(1, c)
        cmsg(c) = 'measure "' // trim(spec%meas_names(bmbad(2, c))) // '": ' // trim(bmsg(c))
      end if
    end if
    if (clean) return
    nkeep(c) = min(n, k - 1)
    cstat(c) = bstat(c)
    if (bstat(c) < 0 .or. code == 3 .or. code >= 5) nkeep(c) = 0
    if (bstat(c) == MBD_OK) cstat(c) = merge(MBD_INTEGRATOR_FAILED, MBD_NO_CONVERGENCE, code == 4)
    if (code == 4) then                      ! dynamics: the Python words where they fit
      cmsg(c) = dynamics_text(c, k)
      if (len_trim(cmsg(c)) > 0) return
    end if
    if (bstat(c) == MBD_OK) then
      cstat(c) = merge(MBD_INTEGRATOR_FAILED, MBD_NO_CONVERGENCE, code == 4)
      write (cmsg(c), '(a,es14.6,a)') 'the run gave non-finite values at t =', &
        tout(max(1, min(k, nrow))), ' s'
    else if (bstat(c) == MBD_SINGULAR_CONFIG .and. code <= 2) then
      cmsg(c) = dead_centre_text(c)
    else if (bstat(c) == MBD_SINGULAR_CONFIG) then
      cmsg(c) = singular_text(brinfo(1, c), biinfo(3, c), bdep(:, c))
    else if (bstat(c) == MBD_INCONSISTENT .and. code <= 2) then
      cmsg(c) = inconsistent_text(c)
    else if (bstat(c) == MBD_INCONSISTENT .and. any(bdep(:, c) == 1)) then
      cmsg(c) = trim(bmsg(c)) // ': the constraints' // trim(dep_names(bdep(:, c))) // &
                ' cannot all hold; check their points and dimensions'
    else
      cmsg(c) = bmsg(c)
      if (code /= 4 .and. biinfo(4, c) > 0 .and. biinfo(4, c) <= spec%nc) cmsg(c) = &
        trim(bmsg(c)) // ' ("' // trim(spec%con_names(biinfo(4, c))) // '")'
      if (bstat(c) == MBD_ASSEMBLY_FAILED .and. code <= 2) then
        if (len_trim(assembly_text(c)) > 0) cmsg(c) = assembly_text(c)
      end if
    end if
  end subroutine case_outcome

  !> A kinematic or inverse-dynamics case's dead centre in the words of the exception the
  !! Python sweep records (mbd2d.analysis.failures.kinematic_failure), with its kept rows.
  function dead_centre_text(c) result(s)
    integer, intent(in) :: c
    character(len=4 * MSG_LEN) :: s
    character(len=2 * MSG_LEN) :: names
    integer :: drv
    real(wp) :: ratio
    names = dep_names(bdep(:, c), .true.)
    ratio = 0.0_wp
    if (brinfo(3, c) > 0.0_wp) ratio = brinfo(2, c) / brinfo(3, c)
    drv = biinfo(3, c)
    s = 'Singular configuration (dead centre) at t = ' // cnum(brinfo(1, c), FMT_F10) // ' s:'
    if (drv > 0 .and. drv <= spec%nc) s = trim(s) // " driver '" // &
      trim(spec%con_names(drv)) // "' can no longer be met, because"
    s = trim(s) // ' the constraints' // trim(names) // ' became dependent (J lost rank; ' // &
        'sigma_min/sigma_max = ' // cnum(ratio, FMT_E1) // '). The mechanism cannot move ' // &
        'further as driven: end the run before this time, or change the driver or the link ' &
        // 'lengths. Results up to ' // trim(kept_until(c)) // ' (' // trim(itoa(nkeep(c))) // &
        " rows) are kept in the exception's .results."
  end function dead_centre_text

  !> A kinematic or inverse-dynamics case's contradicting redundant constraints in the words
  !! of the exception the Python sweep records (mbd2d.analysis.failures.inconsistent).
  function inconsistent_text(c) result(s)
    integer, intent(in) :: c
    character(len=4 * MSG_LEN) :: s
    character(len=*), parameter :: what(0:2) = [character(len=20) :: '||Phi||', &
      '||J q_dot - nu||', '||J q_ddot - gamma||']
    character(len=*), parameter :: lvl(0:2) = [character(len=24) :: '', &
      ' at velocity level', ' at acceleration level']
    character(len=2 * MSG_LEN) :: rows
    integer :: r, nred, level
    level = max(0, min(2, biinfo(5, c)))
    rows = ''; nred = 0
    do r = 1, neq                            ! the redundant rows' labels, ", " between
      if (bred(r, c) /= 1) cycle
      if (nred > 0) rows = trim(rows) // ','
      rows = trim(rows) // ' ' // trim(row_label(r)); nred = nred + 1
    end do
    s = 'Redundant constraints contradict each other' // trim(lvl(level)) // ' at t = ' // &
        cnum(brinfo(1, c), FMT_G6) // ' s:'
    if (nred > 0 .and. biinfo(9, c) /= 0) s = trim(s) // trim(rows) // ' (' // &
      trim(itoa(nred)) // ' redundant equation(s): ' // trim(itoa(neq)) // ' equations, ' // &
      'rank ' // trim(itoa(biinfo(9, c))) // ') contradict(s) the other constraints;'
    s = trim(s) // trim(dep_names(bdep(:, c), .true.)) // &
        ' cannot all hold (smallest residual ' // trim(what(level)) // ' = ' // &
        cnum(brinfo(4, c), FMT_G3) // '). Check their points and dimensions, or remove the ' // &
        'one that repeats another.'
  end function inconsistent_text

  !> A kinematic or inverse-dynamics case that does not assemble, in the words of the
  !! exception the Python sweep records (mbd2d.analysis.failures.assembly_failed); '' where
  !! the worst constraint's name in those words is not in the file's tables (a cam or a
  !! point-on-curve joint, a point-on-line or a revolute-translational joint: one kind each).
  function assembly_text(c) result(s)
    integer, intent(in) :: c
    character(len=4 * MSG_LEN) :: s
    character(len=*), parameter :: types(10) = [character(len=16) :: 'revolute', &
      'translational', '', 'distance', '', 'weld', 'gear', 'rack-pinion', 'rolling-disc', &
      'absolute']
    character(len=2 * MSG_LEN) :: who
    integer :: w, kind
    s = ''
    w = biinfo(4, c)
    who = '?'
    if (w >= 1 .and. w <= spec%nc) then
      kind = spec%ctab(1, w)
      if (con_is_driver(kind)) then
        who = "driver '" // trim(spec%con_names(w)) // "'"
      else if (kind >= 1 .and. kind <= size(types)) then
        if (len_trim(types(kind)) == 0) return
        who = "joint '" // trim(spec%con_names(w)) // "' (" // trim(types(kind)) // ')'
      else
        return
      end if
    end if
    s = assembly_words(brinfo(1, c), brinfo(4, c), who)
  end function assembly_text

  !> Python's words for a failed assembly at t: the smallest residual and where it is largest.
  function assembly_words(t, resid, who) result(s)
    real(wp), intent(in) :: t, resid
    character(len=*), intent(in) :: who
    character(len=4 * MSG_LEN) :: s
    s = 'Assembly failed at t = ' // cnum(t, FMT_G6) // ' s: no configuration satisfies ' // &
        'the constraints near the q0 estimates (smallest residual ' // cnum(resid, FMT_G3) // &
        ', largest in ' // trim(who) // '). Check the link lengths and joint points, and ' // &
        'give q0 closer to the intended configuration.'
  end function assembly_words

  !> "t = T s" of case c's last kept row, or "no output rows" (Python's "Results up to").
  function kept_until(c) result(s)
    integer, intent(in) :: c
    character(len=64) :: s
    s = 'no output rows'
    if (nkeep(c) > 0) s = 't = ' // cnum(tout(nkeep(c)), FMT_G6) // ' s'
  end function kept_until

  !> A dynamics case's failure in the words of the exception the Python sweep records
  !! (mbd2d.analysis.dynamics.dynamics_error): "METHOD: what" with the rows kept where the
  !! integrator failed or the solution became non-finite (at row k), the failed assembly at
  !! t0; '' where that exception's text needs more than the file holds (bad input, a
  !! contradiction before the first row).
  function dynamics_text(c, k) result(s)
    integer, intent(in) :: c, k
    character(len=4 * MSG_LEN) :: s
    character(len=2 * MSG_LEN) :: kept
    character(len=20) :: method
    s = ''
    method = METHOD_WORDS(max(1, min(size(METHOD_WORDS), spec%method)))
    kept = 'Results up to ' // trim(kept_until(c)) // " are kept in the exception's .results."
    select case (bstat(c))
    case (MBD_OK)
      s = trim(method) // ': the solution became non-finite at t = ' // &
          cnum(tout(max(1, min(k, nrow))), FMT_G6) // ' s (a blow-up: try a smaller rtol ' // &
          'or h, or another method). ' // trim(kept)
    case (MBD_ASSEMBLY_FAILED)                ! (Python names neither residual nor constraint)
      s = assembly_words(spec%t0, 0.0_wp, '?')
    case (MBD_INTEGRATOR_FAILED)
      s = trim(method) // ': ' // trim(bmsg(c)) // '. ' // trim(kept)
    case (MBD_INCONSISTENT)
      if (nkeep(c) > 0) s = trim(method) // ': ' // trim(bmsg(c))
    case default
      if (bstat(c) > 0) s = trim(method) // ': ' // trim(bmsg(c))
    end select
  end function dynamics_text

  !> The first of the rows 1..n of case c with a non-finite number (n + 1: none).
  integer function first_bad(c, n) result(k)
    integer, intent(in) :: c, n
    do k = 1, n
      if (.not. all(ieee_is_finite(bq(:, k, c)))) return
      if (nd > 0) then
        if (.not. (all(ieee_is_finite(bqd(:, k, c))) .and. &
                   all(ieee_is_finite(bqdd(:, k, c))))) return
      end if
      if (.not. (all(ieee_is_finite(blam(:, k, c))) .and. all(ieee_is_finite(be(:, k, c))))) &
        return
      if (.not. (all(ieee_is_finite(bsq(:, :, k, c))) .and. &
                 all(ieee_is_finite(bsqd(:, :, k, c))) .and. &
                 all(ieee_is_finite(bsqdd(:, :, k, c))) .and. &
                 all(ieee_is_finite(bslam(:, :, k, c))))) return
    end do
    k = n + 1
  end function first_bad

  !> The CSV of mbd2d.write_sweep (Python's csv module: fields quoted when they hold a
  !! comma, a quote or a line break; lines end in CR LF). Each row is built in one buffer and
  !! written at once; a case's leading fields (case, parameters) and its status and message
  !! are formatted once per case.
  subroutine write_sweep_csv(path)
    character(len=*), intent(in) :: path
    character(len=*), parameter :: crlf = achar(13) // achar(10)
    character(len=*), parameter :: lev(3) = [character(len=6) :: '', '_dot', '_ddot']
    character(len=:), allocatable :: line, head, tail
    integer :: u, ios, j, k, l, nlev, c, lp, nh, nt, width, p, nsl
    logical :: done
    if (code == 5) then
      call write_modes_sweep_csv(path)
      return
    end if
    if (code == 6) then
      call write_frf_sweep_csv(path)
      return
    end if
    nlev = merge(3, 1, nd > 0)
    nsl = size(bslam, 1)
    ! at most 26 characters a number ("%.17g": -1.2345678901234567e-308) with its comma; a
    ! row also holds the case's status and message (tail: the message quoted, every quote
    ! doubled at most)
    width = 26 * (spec%ncp + 2 + 3 * nq + spec%nc + spec%nmeas + &
                  spec%npar * (3 * nq + spec%nc + spec%nmeas)) + 32
    call open_sweep_csv(path, width, u, ios, head, tail, line)
    call sput(u, ios, ',t,status,message')
    do l = 1, nlev
      call coordinate_header(u, ios, trim(lev(l)), 0)
    end do
    if (nlam > 0) then
      do j = 1, spec%nc
        if (con_is_driver(spec%ctab(1, j))) &
          call sput(u, ios, ',effort.' // trim(spec%con_names(j)))
      end do
    end if
    do j = 1, spec%nmeas
      call sput(u, ios, ',' // quoted(trim(spec%meas_names(j))))
    end do
    do p = 1, spec%npar        ! d(COLUMN)/d(P): the motion, the efforts, the measures
      do l = 1, nlev
        call coordinate_header(u, ios, trim(lev(l)), p)
      end do
      if (nsl > 0) then
        do j = 1, spec%nc
          if (con_is_driver(spec%ctab(1, j))) call sput(u, ios, ',d(effort.' // &
            trim(spec%con_names(j)) // ')/d(' // trim(spec%par_names(p)) // ')')
        end do
      end if
      do j = 1, spec%nmeas
        call sput(u, ios, ',' // quoted('d(' // trim(spec%meas_names(j)) // ')/d(' // &
                                        trim(spec%par_names(p)) // ')'))
      end do
    end do
    call sput(u, ios, crlf)
    do c = 1, spec%ncase
      call case_fields(c, u, ios, head, nh, tail, nt, done)
      if (done) cycle
      do k = 1, nkeep(c)
        lp = 0
        call bput(line, lp, head(1:nh))
        call bnum(line, lp, tout(k))
        call bput(line, lp, tail(1:nt))
        do j = 1, nq
          call bnum(line, lp, bq(j, k, c))
        end do
        if (nd > 0) then
          do j = 1, nq
            call bnum(line, lp, bqd(j, k, c))
          end do
          do j = 1, nq
            call bnum(line, lp, bqdd(j, k, c))
          end do
        end if
        if (nlam > 0) then
          do j = 1, size(drow)
            call bnum(line, lp, -blam(drow(j), k, c))
          end do
        end if
        do j = 1, spec%nmeas
          call bnum(line, lp, bmv(j, k, c))
        end do
        do p = 1, spec%npar
          call sens_fields(line, lp, k, c, p, nlev, nsl)
        end do
        call bput(line, lp, crlf)
        call sput(u, ios, line(1:lp))
      end do
    end do
    close (u)
    if (ios /= 0) call die(2, 'cannot write ' // path // ' (disk full?)')
  end subroutine write_sweep_csv

  !> A sweep's CSV opened at path, its first column names written (case, the parameters),
  !! and the row buffers: head (case and parameters) and line of width characters, tail
  !! (status and quoted message).
  subroutine open_sweep_csv(path, width, u, ios, head, tail, line)
    character(len=*), intent(in) :: path
    integer, intent(in) :: width
    integer, intent(out) :: u, ios
    character(len=:), allocatable, intent(out) :: head, tail, line
    integer :: j
    allocate (character(len=width) :: head, stat=ierr)
    if (ierr == 0) allocate (character(len=2 * len(cmsg) + 40) :: tail, stat=ierr)
    if (ierr == 0) allocate (character(len=width + len(tail)) :: line, stat=ierr)
    if (ierr /= 0) call die(2, 'not enough memory to write ' // path)
    open (newunit=u, file=path, status='replace', action='write', access='stream', &
          form='unformatted', iostat=ios)
    if (ios /= 0) call die(2, 'cannot write ' // path)
    call sput(u, ios, 'case')
    do j = 1, spec%ncp
      call sput(u, ios, ',' // trim(spec%case_names(j)))
    end do
  end subroutine open_sweep_csv

  !> Case c's leading fields (head: case and parameters) and its status and message (tail);
  !! a case without rows gets its one row (head, an empty field, tail) written to u: done.
  subroutine case_fields(c, u, ios, head, nh, tail, nt, done)
    integer, intent(in) :: c, u
    integer, intent(inout) :: ios
    character(len=*), intent(inout) :: head, tail
    integer, intent(out) :: nh, nt
    logical, intent(out) :: done
    integer :: j
    nh = 0
    call bput(head, nh, trim(itoa(c - 1)))
    do j = 1, spec%ncp
      call bnum(head, nh, spec%cvals(j, c))
    end do
    nt = 0
    call bput(tail, nt, ',' // trim(itoa(cstat(c))) // ',' // quoted(trim(cmsg(c))))
    done = nkeep(c) == 0
    if (done) call sput(u, ios, head(1:nh) // ',' // tail(1:nt) // achar(13) // achar(10))
  end subroutine case_fields

  !> The CSV of mbd2d.write_sweep for a modes sweep: one row per case and mode (case, the
  !! parameters, mode, status, message, omega2, frequency_hz, kind, the shape per
  !! coordinate); a case without modes, one row with its status and message.
  subroutine write_modes_sweep_csv(path)
    character(len=*), intent(in) :: path
    character(len=*), parameter :: crlf = achar(13) // achar(10)
    real(wp), parameter :: TWO_PI = 2 * 3.141592653589793_wp
    character(len=:), allocatable :: line, head, tail
    integer :: u, ios, j, k, c, lp, nh, nt, width
    logical :: done
    width = 26 * (spec%ncp + 6 + nq) + 32
    call open_sweep_csv(path, width, u, ios, head, tail, line)
    call sput(u, ios, ',mode,status,message,omega2,frequency_hz,kind')
    call coordinate_header(u, ios, '', 0)
    call sput(u, ios, crlf)
    do c = 1, spec%ncase
      call case_fields(c, u, ios, head, nh, tail, nt, done)
      if (done) cycle
      do k = 1, nkeep(c)
        lp = 0
        call bput(line, lp, head(1:nh) // ',' // trim(itoa(k - 1)))
        call bput(line, lp, tail(1:nt))
        ! be(:, k, c) = [omega^2, kind, ...]: frequency = sqrt(max(omega^2, 0)) / (2 pi)
        call bnum(line, lp, be(1, k, c))
        call bnum(line, lp, sqrt(max(be(1, k, c), 0.0_wp)) / TWO_PI)
        call bnum(line, lp, be(2, k, c))
        do j = 1, nq
          call bnum(line, lp, bq(j, k, c))
        end do
        call bput(line, lp, crlf)
        call sput(u, ios, line(1:lp))
      end do
    end do
    close (u)
    if (ios /= 0) call die(2, 'cannot write ' // path // ' (disk full?)')
  end subroutine write_modes_sweep_csv

  !> The CSV of mbd2d.write_sweep for a frequency response sweep: one row per case and
  !! frequency (case, the parameters, frequency_hz, status, message, then for each input
  !! d(NAME)/d(INPUT).re, .im of each coordinate and of each driver's effort.DRIVER, -dlambda
  !! of its row); a failed case, one row with its status and message.
  subroutine write_frf_sweep_csv(path)
    character(len=*), intent(in) :: path
    character(len=*), parameter :: crlf = achar(13) // achar(10)
    character(len=:), allocatable :: line, head, tail
    integer :: u, ios, j, k, c, p, lp, nh, nt, width
    logical :: done
    width = 26 * (spec%ncp + 1 + 2 * (nq + spec%nc) * spec%npar) + 32
    call open_sweep_csv(path, width, u, ios, head, tail, line)
    call sput(u, ios, ',frequency_hz,status,message')
    do p = 1, spec%npar
      call coordinate_header(u, ios, '', p, pair=.true.)
      do j = 1, spec%nc
        if (con_is_driver(spec%ctab(1, j))) call pair_header(u, ios, 'effort.' // &
          trim(spec%con_names(j)), trim(spec%par_names(p)))
      end do
    end do
    call sput(u, ios, crlf)
    do c = 1, spec%ncase
      call case_fields(c, u, ios, head, nh, tail, nt, done)
      if (done) cycle
      do k = 1, nkeep(c)
        lp = 0
        call bput(line, lp, head(1:nh))
        call bnum(line, lp, spec%freq(k))
        call bput(line, lp, tail(1:nt))
        do p = 1, spec%npar          ! (+ 0: no negative zero, as the Python writer)
          do j = 1, nq
            call bnum(line, lp, bsq(j, p, k, c) + 0.0_wp)
            call bnum(line, lp, bsqd(j, p, k, c) + 0.0_wp)
          end do
          do j = 1, size(drow)
            call bnum(line, lp, -bslam(drow(j), p, k, c) + 0.0_wp)
            call bnum(line, lp, -bslam(neq + drow(j), p, k, c) + 0.0_wp)
          end do
        end do
        call bput(line, lp, crlf)
        call sput(u, ios, line(1:lp))
      end do
    end do
    close (u)
    if (ios /= 0) call die(2, 'cannot write ' // path // ' (disk full?)')
  end subroutine write_frf_sweep_csv

  !> The drivers' first rows of Phi, in the constraints' order (an effort is -lambda there).
  function driver_rows() result(rows)
    integer, allocatable :: rows(:)
    integer :: j, r
    rows = [integer ::]
    r = 1
    do j = 1, spec%nc
      if (con_is_driver(spec%ctab(1, j))) rows = [rows, r]
      r = r + con_nrow(spec%ctab(1, j))
    end do
  end function driver_rows

  !> Row k of case c's derivatives along parameter p: the motion's, the efforts'
  !! (-dlambda/dp of the driver rows), then the measures'.
  subroutine sens_fields(buf, n, k, c, p, nlev, nsl)
    character(len=*), intent(inout) :: buf
    integer, intent(inout) :: n
    integer, intent(in) :: k, c, p, nlev, nsl
    integer :: j
    do j = 1, nq
      call bnum(buf, n, bsq(j, p, k, c))
    end do
    if (nlev > 1) then
      do j = 1, nq
        call bnum(buf, n, bsqd(j, p, k, c))
      end do
      do j = 1, nq
        call bnum(buf, n, bsqdd(j, p, k, c))
      end do
    end if
    if (nsl > 0) then
      do j = 1, size(drow)
        call bnum(buf, n, -bslam(drow(j), p, k, c))
      end do
    end if
    do j = 1, spec%nmeas
      call bnum(buf, n, bdm(j, p, k, c))
    end do
  end subroutine sens_fields

  !> The coordinates' names NAME.x, NAME.y, NAME.theta per body, then NAME.alpha per extra
  !! coordinate of a cam or curve joint, each with the suffix sfx.
  subroutine coordinate_header(u, ios, sfx, p, pair)
    integer, intent(in) :: u
    integer, intent(inout) :: ios
    character(len=*), intent(in) :: sfx
    integer, intent(in) :: p           !! 0, or d(NAME)/d(P) of design parameter p
    !> d(NAME)/d(P).re,d(NAME)/d(P).im (a frequency response's pair; p > 0)
    logical, intent(in), optional :: pair
    character(len=*), parameter :: w(3) = [character(len=6) :: '.x', '.y', '.theta']
    integer :: b, i, j
    logical :: pr
    pr = .false.
    if (present(pair)) pr = pair
    do b = 1, spec%nb
      do i = 1, 3
        call header_col(u, ios, trim(spec%body_names(b)) // trim(w(i)) // sfx, p, pr)
      end do
    end do
    do j = 1, spec%nc
      do i = 1, con_nextra(spec%ctab(1, j))
        call header_col(u, ios, trim(spec%con_names(j)) // '.alpha' // sfx, p, pr)
      end do
    end do
  end subroutine coordinate_header

  !> One coordinate's column name: sweep_col's, or pair_header's pair (pr).
  subroutine header_col(u, ios, name, p, pr)
    integer, intent(in) :: u, p
    integer, intent(inout) :: ios
    character(len=*), intent(in) :: name
    logical, intent(in) :: pr
    if (pr) then
      call pair_header(u, ios, name, trim(spec%par_names(p)))
    else
      call sweep_col(u, ios, name, p)
    end if
  end subroutine header_col

  !> A sweep column's name: ",NAME" (p = 0), or ",d(NAME)/d(P)" of design parameter p.
  subroutine sweep_col(u, ios, name, p)
    integer, intent(in) :: u, p
    integer, intent(inout) :: ios
    character(len=*), intent(in) :: name
    if (p > 0) then
      call sput(u, ios, ',d(' // name // ')/d(' // trim(spec%par_names(p)) // ')')
    else
      call sput(u, ios, ',' // name)
    end if
  end subroutine sweep_col

  subroutine die(code, text)
    integer, intent(in) :: code
    character(len=*), intent(in) :: text
    write (error_unit, '(a)') 'mbd2d-solve: ' // trim(text)
    select case (code)
    case (2); stop 2, quiet=.true.
    case (3); stop 3, quiet=.true.
    case default; stop 4, quiet=.true.
    end select
  end subroutine die

end program mbd2d_solve
