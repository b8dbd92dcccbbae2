!> mbd2d-solve: run a model file written by `mbd2d export`, without Python.
!!
!!   mbd2d-solve MODEL.mbd OUT.csv
!! Runs the file's analysis (kinematics, inverse dynamics, dynamics or statics, with its
!! settings) and writes the CSV the Python path writes for it: t, then NAME.x ... NAME.theta_ddot
!! per body (statics: NAME.x, NAME.y, NAME.theta, stable, residual), then the optional columns
!! the file's "outputs" line asks for (energy, multipliers, reactions, efforts), then each
!! contact's and joint friction's columns (dynamic runs), then with a "sensitivities" block,
!! for each design parameter P in turn, d(COLUMN)/d(P) of the motion columns and (inverse
!! dynamics, statics) of the multiplier, reaction and effort columns asked for; every number
!! as Python's "%.16e" (docs/mbd-format.md).
!! Exit codes: 0 ok, 2 bad input (a malformed file, or counts too large for the memory),
!! 3 singular configuration (partial output written), 4 other numerical failure (partial
!! output written when there is any). Messages go to standard error, each starting
!! "mbd2d-solve: ". Nothing is allocated before the counts are checked (mbd_read) and the
!! outputs, held in memory, are checked against it (mem_check).
program mbd2d_solve
  use, intrinsic :: iso_fortran_env, only: error_unit
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
  use mbd_kinds, only: wp
  use mbd_status, only: MBD_OK, MBD_SINGULAR_CONFIG, MBD_NO_MEMORY, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check
  use mbd_mbdfile, only: mbd_spec_t, mbd_read
  use mbd_model, only: NFT
  use mbd_constraints, only: con_nrow, con_is_driver
  use mbd_api, only: NINFO, api_sizes, api_kinematics, api_inverse, api_dynamics, api_statics, &
                     api_reactions, api_dynamics_sens, api_reactions_dp
  use mbd_kinematics, only: MAXPASS, kin_out_count
  use mbd_integrators, only: output_index
  use mbd_contact, only: NEO
  use mbd_forces, only: force_is_contact, FRC_FRICTION
  use iso_c_binding, only: c_char, c_double, c_int
  implicit none
  interface
    !> x as "%.16e" into buf(len); the length written (number_format.c)
    function format_e16(x, buf, len) result(n) bind(C, name='mbd_format_e16')
      import :: c_char, c_double, c_int
      real(c_double), value :: x
      character(kind=c_char), intent(out) :: buf(*)
      integer(c_int), value :: len
      integer(c_int) :: n
    end function format_e16
  end interface
  type(mbd_spec_t) :: spec
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
  dynamic = spec%analysis /= 'kinematics'
  if (spec%analysis /= 'statics' .and. spec%steps_line == 0) &
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
    if (sens) then                 ! dopri5 with the variational equations
      call api_dynamics_sens(spec%nb, spec%ctab, spec%rpar, spec%bmass, spec%grav, ftab, &
                             fpar, q0, v0, spec%t0, spec%t_end, spec%steps, spec%rtol, &
                             spec%atol, spec%every, spec%max_steps, spec%ptab, qout, qdout, &
                             qddout, lamout, eout, sq, sqd, sqdd, iinfo, rinfo, redundant, &
                             status, msg)
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
  if (status < 0) then
    if (iinfo(2) <= -2000000) then
      call die(2, param_where(-2000000 - iinfo(2), msg))
    else if (iinfo(2) <= -1000000) then
      call die(2, force_where(-1000000 - iinfo(2), msg))
    else if (iinfo(2) < 0) then
      call die(2, trim(model_path) // ': body "' // &
               trim(spec%body_names(min(spec%nb, -iinfo(2)))) // '": ' // trim(msg))
    end if
    call die(2, where(iinfo(2), msg))
  end if
  if (status == MBD_NO_MEMORY) call die(2, trim(msg))
  if (spec%analysis == 'statics' .and. status /= MBD_OK) call die(4, trim(msg) // &
    ' (no equilibrium written)')
  nout = max(0, min(nout, nrows))
  call times()
  if (sens) call finite_rows()
  if (spec%out_reac .and. nout > 0) call reactions()
  call write_csv(trim(out_path))
  if (status == MBD_SINGULAR_CONFIG) then
    call die(3, trim(singular_message()))
  else if (status == NONFINITE) then
    call die(4, trim(msg) // ' ' // trim(rows_written()))
  else if (status /= MBD_OK) then
    call die(4, trim(msg) // trim(worst()) // '. ' // trim(rows_written()))
  end if

contains

  !> The output times: row k holds output output_index(steps, every, k), as the core.
  subroutine times()
    integer :: k, ko
    if (spec%analysis == 'statics') then
      tout = spec%tstat; return
    end if
    do k = 1, nrows
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
    lam_sens = sens .and. (spec%analysis == 'inverse-dynamics' .or. spec%analysis == 'statics')
    if (.not. sens) return
    if (spec%positions_only) call die(2, trim(model_path) // ':' // &
      trim(itoa(spec%sens_line)) // ': sensitivities need the velocities and accelerations '// &
      'of every step: give positions_only 0')
    if (spec%analysis == 'dynamics' .and. spec%method /= 2) call die(2, trim(model_path) // &
      ':' // trim(itoa(spec%sens_line)) // ': sensitivities are integrated with dopri5 '// &
      '(the variational equations with the state); give method dopri5')
    do c = 1, spec%nf
      if (force_is_contact(spec%ftab(1, c)) .or. spec%ftab(1, c) == FRC_FRICTION) &
        call die(2, trim(model_path) // ':' // trim(itoa(spec%sens_line)) // ': design '// &
                 'sensitivities do not carry contacts or joint friction ("' // &
                 trim(spec%force_names(c)) // '"): their events make the motion non-smooth '// &
                 'in the parameters')
    end do
  end subroutine check_sensitivities

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
    character(len=2 * MSG_LEN) :: names
    character(len=32) :: ts
    integer :: c, r0, nr
    names = ''
    r0 = 1
    do c = 1, spec%nc
      nr = con_nrow(spec%ctab(1, c))
      if (any(dep(r0:r0 + nr - 1) == 1)) names = trim(names) // ' ' // trim(spec%con_names(c))
      r0 = r0 + nr
    end do
    write (ts, '(f0.10)') rinfo(1)
    if (ts(1:1) == '.') ts = '0' // trim(ts)
    if (ts(1:2) == '-.') ts = '-0' // ts(2:)
    s = 'Singular configuration (dead centre) at t = ' // trim(ts) // ' s: '
    if (iinfo(3) > 0 .and. iinfo(3) <= spec%nc) then
      s = trim(s) // ' driver "' // trim(spec%con_names(iinfo(3))) // &
          '" can no longer be met, because the constraints' // trim(names) // &
          ' became dependent (J lost rank).'
    else
      s = trim(s) // ' the constraints' // trim(names) // ' became dependent (J lost rank).'
    end if
    s = trim(s) // ' The mechanism cannot move further as driven; change the driver range or ' // &
        'the link lengths. ' // trim(rows_written()) // '.'
  end function singular_message

  !> A number as Python's "%.16e": 17 significant digits, a lower-case e and an exponent of
  !! at least two digits (-1.2345678901234567e-05, 0.0000000000000000e+00, 1.0e+100 style);
  !! nan, inf and -inf as Python writes them. C's snprintf writes the digits (number_format.c):
  !! a Fortran internal write would allocate on every call.
  !! s(1:n) gets the text (no trim of a function result: that allocates too).
  subroutine num(x, s, n)
    real(wp), intent(in) :: x
    character(len=32), intent(out) :: s
    integer, intent(out) :: n
    character(kind=c_char) :: buf(32)
    integer :: i
    if (ieee_is_nan(x)) then
      s = 'nan'; n = 3; return
    else if (.not. ieee_is_finite(x)) then
      s = merge('inf ', '-inf', x > 0.0_wp); n = merge(3, 4, x > 0.0_wp); return
    end if
    n = max(0, min(int(format_e16(real(x, c_double), buf, 32_c_int)), 31))
    s = ''
    do i = 1, n
      s(i:i) = buf(i)
    end do
  end subroutine num

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
    ncols = 1 + 9 * spec%nb + 5 + neq + 6 * spec%nc + spec%nc + 4 * spec%nf + &
            spec%npar * (9 * spec%nb + neq + 6 * spec%nc + spec%nc)
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
    do j = 1, spec%npar
      call motion_header(u, ios, j)
      if (lam_sens) call lam_header(u, ios, j)
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
        if (spec%nlabels == neq) then
          call put_col(u, ios, 'lambda.' // trim(spec%labels(r)), j)
        else
          call put_col(u, ios, 'lambda.row' // trim(itoa(r)), j)
        end if
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
    do j = 1, spec%npar
      call motion_values(sq(:, j, k), sqd(:, j, k), sqdd(:, j, k), v, n)
      if (.not. lam_sens) cycle
      if (spec%out_reac) then
        call lam_values(slam(:, j, k), dreac(:, :, j, k), v, n)
      else
        call lam_values(slam(:, j, k), none, v, n)
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
    integer :: c, r0, nr
    if (spec%out_lam) then
      v(n + 1:n + neq) = lam; n = n + neq
    end if
    if (spec%out_reac) then
      do c = 1, spec%nc
        v(n + 1:n + 6) = rc(:, c); n = n + 6
      end do
    end if
    if (spec%out_eff) then
      r0 = 1
      do c = 1, spec%nc
        nr = con_nrow(spec%ctab(1, c))
        if (con_is_driver(spec%ctab(1, c))) then
          v(n + 1) = -lam(r0); n = n + 1
        end if
        r0 = r0 + nr
      end do
    end if
  end subroutine lam_values

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
