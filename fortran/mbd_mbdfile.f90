!> mbd_mbdfile: read the plain-text model file written by `mbd2d export` (docs/mbd-format.md).
!!
!! Format 3 (whitespace separated; '#' starts a comment line; names have no spaces; format 1,
!! the kinematics-only subset, and format 2, whose functions of time had no steps, are read
!! too: upgrade_functions):
!!   mbd2d 3
!!   name <model name>
!!   analysis kinematics | inverse-dynamics | dynamics | statics | modes | frf | linearize |
!!            check
!!   t0 <time>   t_end <time>   steps <n>   every <k>                  (one per line)
!!   tol <x>   maxit <n>   tmin <x>   solver auto|dense|banded           (kinematic runs)
!!   positions_only 0|1                       (kinematics: 1 = positions alone, optional)
!!   method generalized-alpha|dopri5|baumgarte-rk4|partitioned   rtol <x>   atol <x>   h <x>
!!   rho_inf <x>   alpha <x>   beta <x>   max_steps <n>                  (dynamics)
!!   t <time>                                    (statics, modes, frf, linearize, check)
!!   count <k>   at_q0 0|1        (modes: the lowest k (0: every free motion); 1 = about q0;
!!                              at_q0 also frf and linearize, whose inputs: sensitivities)
!!   frequencies <nw>                         (frf: then nw frequencies in Hz, >= 0, any
!!   <nw reals>                               number per line; the inputs: sensitivities)
!!   outputs <energy | multipliers | reactions | efforts ...>           (optional columns;
!!                              modes: "damped" writes the damped eigenvalues instead;
!!                              linearize: "velocities" the velocities' outputs too)
!!   gravity <gx> <gy>
!!   bodies <nb>
!!   <name> <x0> <y0> <theta0> [<mass> <inertia> <vx0> <vy0> <omega0>]   (nb lines)
!!   constraints <nc>
!!   <name> <kind> <body i> <body j> <sub a> <sub b> <offset> <length>   (nc lines)
!!   params <np>
!!   <np reals, any number per line, no comments inside this block>
!!   labels <neq>
!!   <neq row labels NAME.WORD, any number per line>
!!   forces <nf>
!!   <name> <kind> <body i> <body j> <offset> <length> [<joint>]        (nf lines; the
!!                              contacts and joint frictions too: <joint> is a friction's joint)
!!   fparams <np>
!!   <np reals>
!!   sensitivities <npar>                     (optional: design parameters)
!!   <name> <table> <index>                   (npar lines; table 1 params, 2 masses,
!!                              3 gravity, 4 fparams; index 1-based in that list)
!!   measures <nm>                            (optional: measure columns)
!!   <spec> angle <kind> <b1> <x> <y> <b2> <x> <y> <b3> <x> <y> [<ix1> <iy1> ... <iy3>]
!!                              (transmission angle; the optional indices: the params
!!                              entries of the points, 0 the number given)
!!   <spec> ratio|advantage <ref> <xkind> <xindex> <ykind> <yindex>  (influence ratios)
!!   <spec> conditioning                      (distance to a dead centre)
!!   cases <np> <nv> <ncase>                  (optional: a sweep, `mbd2d.export_sweep`)
!!   <name>                                   (np lines: the swept parameters)
!!   <table> <index>                          (nv lines: the entries each case sets)
!!   <(np + nv) * ncase reals>                (per case: the parameters' values, then the
!!                              entries'; any number per line)
!!   opens <no>                               (with cases: phases set again from q0)
!!   <rpar index> <row of Phi>                (no lines)
!!   end
!! The constraint and force columns are the flat tables of mbd_model; tol, maxit, tmin, rtol,
!! atol, h and max_steps = 0 and rho_inf, alpha, beta = -1 mean the core's defaults.
!!
!! Nothing in the file is trusted: every line has exactly its fields, every number is finite
!! and in range (steps 1..MAX_STEPS, maxit 0..MAX_ITER, tol 0 or MIN_TOL..1, tmin >= 0, as the
!! Python front end requires), and a count (bodies, constraints, params) is checked against the
!! lines and characters left in the file and against the memory before anything is allocated.
!! Every failure is MBD_BAD_INPUT (MBD_NO_MEMORY for a count the memory cannot hold) with a
!! message "FILE:LINE: what".
module mbd_mbdfile
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_BAD_INPUT, MBD_NO_MEMORY, MSG_LEN
  use mbd_model, only: NCT, NFT
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail
  use mbd_measures, only: MEAS_ANGLE, MEAS_RATIO, MEAS_ADVANTAGE, MEAS_CONDITIONING
  use mbd_drivers, only: DRV_ABS, DRV_REL_DIST
  use mbd_forces, only: FRC_SPRING, FRC_TORQUE, FRC_POINT, FRC_ROTSPRING
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use, intrinsic :: iso_fortran_env, only: int64
  implicit none
  private
  public :: NAME_LEN, PNAME_LEN, MAX_STEPS, mbd_spec_t, mbd_read, ANALYSES, METHOD_WORDS
  public :: MEAS_ANGLE, MEAS_RATIO, MEAS_ADVANTAGE, MEAS_CONDITIONING

  integer, parameter :: NAME_LEN = 64             !! longest body or constraint name
  integer, parameter :: PNAME_LEN = 256           !! longest design parameter name
  integer, parameter :: LINE_LEN = 4096           !! longest line
  integer, parameter :: MAX_STEPS = 1000000000    !! output intervals (as the Python front end)
  integer, parameter :: MAX_ITER = 1000000        !! Newton iterations (as the Python front end)
  real(wp), parameter :: MIN_TOL = 1.0e-15_wp     !! smallest tolerance (as the Python front end)
  integer, parameter :: INT32_MAX = huge(1)       !! largest step limit
  !> the analyses a file can hold
  character(len=16), parameter :: ANALYSES(8) = [character(len=16) :: 'kinematics', &
    'inverse-dynamics', 'dynamics', 'statics', 'modes', 'frf', 'linearize', 'check']
  !> linear solvers (codes 0, 1, 2) and dynamics methods (codes 1 .. 4) by name
  character(len=8), parameter :: SOLVER_WORDS(0:2) = [character(len=8) :: 'auto', 'dense', &
    'banded']
  character(len=20), parameter :: METHOD_WORDS(4) = [character(len=20) :: &
    'generalized-alpha', 'dopri5', 'baumgarte-rk4', 'partitioned']

  !> The contents of a model file (and where each part was read, for messages).
  type :: mbd_spec_t
    character(len=NAME_LEN) :: name = ''
    character(len=NAME_LEN) :: analysis = 'kinematics'
    real(wp) :: t0 = zero, t_end = zero, tol = zero, tmin = zero
    integer :: steps = 0, maxit = 0, nb = 0, nc = 0
    integer :: steps_line = 0             !! line of "steps" (0: not given)
    integer :: bodies_line = 0            !! line of "bodies"
    character(len=NAME_LEN), allocatable :: body_names(:), con_names(:)
    real(wp), allocatable :: q0(:, :)     !! (3, nb)
    integer, allocatable :: ctab(:, :)    !! (NCT, nc)
    integer, allocatable :: con_line(:)   !! line of each constraint
    real(wp), allocatable :: rpar(:)
    integer :: version = 1                !! format version
    ! settings of the analyses (0 or -1: the core's default)
    integer :: every = 1                  !! keep every k-th output
    integer :: solver = 0                 !! 0 auto, 1 dense, 2 banded
    integer :: method = 2                 !! 1 generalized-alpha, 2 dopri5, 3 rk4, 4 partitioned
    integer :: max_steps = 0              !! integrator step limit (0: default)
    real(wp) :: rtol = zero, atol = zero, h = zero
    real(wp) :: rho_inf = -one, alpha = -one, beta = -one
    real(wp) :: tstat = zero              !! statics, modes: the time of loads and drivers
    integer :: count = 0                  !! modes: the lowest count (0: all)
    logical :: at_q0 = .false.            !! modes: about q0 (no equilibrium sought)
    logical :: out_damped = .false.       !! modes: the damped eigenvalues' table
    real(wp), allocatable :: freq(:)      !! frf: the frequencies (Hz)
    integer :: freq_line = 0              !! line of "frequencies" (0: not given)
    real(wp) :: grav(2) = zero            !! gravity
    !> optional output columns
    logical :: out_energy = .false., out_lam = .false., out_reac = .false., out_eff = .false.
    logical :: out_vel = .false.          !! linearize: the velocities' outputs too
    logical :: positions_only = .false.   !! kinematics: positions alone
    ! masses, forces and row labels (dynamic analyses)
    logical :: have_masses = .false.      !! body lines carry mass, inertia and v0
    real(wp), allocatable :: bmass(:, :)  !! (2, nb) mass, inertia
    real(wp), allocatable :: v0(:, :)     !! (3, nb) initial velocities
    integer :: nf = 0
    character(len=NAME_LEN), allocatable :: force_names(:)
    integer, allocatable :: ftab(:, :)    !! (NFT, nf)
    real(wp), allocatable :: fpar(:)
    integer :: nlabels = -1               !! row labels given (-1: none)
    character(len=NAME_LEN), allocatable :: labels(:)
    ! design parameters (sensitivities)
    integer :: npar = 0
    character(len=PNAME_LEN), allocatable :: par_names(:)
    integer, allocatable :: ptab(:, :)    !! (2, npar) table and index (mbd_sensitivity)
    integer, allocatable :: par_line(:)   !! line of each design parameter
    integer :: sens_line = 0              !! line of "sensitivities" (0: not given)
    ! measure columns: spec (the column's name), kind, integers and reals of the recipe
    integer :: nmeas = 0
    character(len=PNAME_LEN), allocatable :: meas_names(:)
    integer, allocatable :: meas_kind(:)      !! MEAS_ANGLE ... MEAS_CONDITIONING
    !> angle: kind (1 turning, 2 sliding), bodies b1, b2, b3; ratio, advantage: the
    !! reference row, kind (1 coordinate, 2 driver) and index of X, then of Y
    integer, allocatable :: meas_int(:, :)    !! (5, nmeas)
    real(wp), allocatable :: meas_pts(:, :, :)  !! (2, 3, nmeas) an angle's points
    !> (2, 3, nmeas) the params entries of an angle's points (0: the number given), for a
    !! sweep that moves them
    integer, allocatable :: meas_ref(:, :, :)
    integer, allocatable :: meas_line(:)
    ! a sweep (mbd_batch): its parameters, the entries each case sets, their values
    integer :: ncase = 0, ncp = 0, nv = 0
    integer :: cases_line = 0             !! line of "cases" (0: not given)
    character(len=PNAME_LEN), allocatable :: case_names(:)  !! (ncp) the swept parameters
    integer, allocatable :: vtab(:, :)    !! (2, nv) table and index of each set entry
    real(wp), allocatable :: cvals(:, :)  !! (ncp + nv, ncase) values per case
    integer, allocatable :: opens(:, :)   !! (2, no) open phases: rpar index, row of Phi
  end type mbd_spec_t

contains

  !> Read a model file.
  subroutine mbd_read(path, spec, status, msg)
    character(len=*), intent(in) :: path        !! file to read
    type(mbd_spec_t), intent(out) :: spec       !! contents
    integer, intent(out) :: status              !! MBD_OK, MBD_BAD_INPUT or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer :: u, ios, lineno, i, k, ierr, ndata, nread, ntok, pos, n, ntf
    integer(int64) :: chars_left, big
    character(len=LINE_LEN) :: line
    character(len=NAME_LEN) :: key
    character(len=LINE_LEN) :: tok
    logical :: have_header, done, seen_b, seen_c, seen_p, seen_f, seen_fp, seen_l, seen_s
    logical :: seen_k, seen_o, seen_m, seen_w
    real(wp) :: x
    status = MBD_OK; msg = ''
    ! first pass: the data lines (not blank, not comments) and their characters
    open (newunit=u, file=path, status='old', action='read', iostat=ios)
    if (ios /= 0) then
      status = MBD_BAD_INPUT; msg = 'cannot open model file ' // trim(path); return
    end if
    ndata = 0; chars_left = 0; lineno = 0
    do
      read (u, '(a)', iostat=ios) line
      if (ios /= 0) exit
      lineno = lineno + 1
      line = adjustl(line)
      if (len_trim(line) == 0 .or. line(1:1) == '#') cycle
      ndata = ndata + 1
      chars_left = chars_left + len_trim(line) + 1
    end do
    if (.not. is_iostat_end(ios)) then
      call fail('cannot read the file (not a text file?)'); close (u); return
    end if
    if (ndata == 0) then
      call fail('the file is empty (or not a regular file)'); close (u); return
    end if
    rewind (u)
    lineno = 0; nread = 0
    have_header = .false.; done = .false.; seen_b = .false.; seen_c = .false.
    seen_p = .false.; seen_f = .false.; seen_fp = .false.; seen_l = .false.; seen_s = .false.
    seen_k = .false.; seen_o = .false.; seen_m = .false.; seen_w = .false.
    allocate (spec%body_names(0), spec%con_names(0), spec%q0(3, 0), stat=ierr)
    if (ierr == 0) allocate (spec%ctab(NCT, 0), spec%con_line(0), spec%rpar(0), stat=ierr)
    if (ierr == 0) allocate (spec%bmass(2, 0), spec%v0(3, 0), spec%force_names(0), &
                             spec%ftab(NFT, 0), spec%fpar(0), spec%labels(0), stat=ierr)
    if (ierr == 0) allocate (spec%par_names(0), spec%ptab(2, 0), spec%par_line(0), &
                             spec%freq(0), stat=ierr)
    if (ierr == 0) allocate (spec%case_names(0), spec%vtab(2, 0), spec%cvals(0, 0), &
                             spec%opens(2, 0), stat=ierr)
    if (ierr == 0) allocate (spec%meas_names(0), spec%meas_kind(0), spec%meas_int(5, 0), &
                             spec%meas_pts(2, 3, 0), spec%meas_ref(2, 3, 0), &
                             spec%meas_line(0), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(zero, 'the model file', 'free some memory', status, msg); close (u); return
    end if
    do
      call next_line(ios)
      if (ios /= 0) exit
      ntok = count_tokens(line)
      pos = 1
      call next_token(line, pos, tok)
      key = tok(1:NAME_LEN)
      if (.not. have_header .and. key /= 'mbd2d') then
        call fail('not an mbd2d model file (first line must be "mbd2d 1")'); exit
      end if
      select case (key)
      case ('mbd2d')
        if (ntok /= 2) then
          call fail('the header line is "mbd2d 1"'); exit
        end if
        call next_token(line, pos, tok)
        if (.not. read_int(tok, big)) big = -1
        if (big < 1 .or. big > 3) then
          call fail('unsupported format version "' // trim(tok) // '" (this reader knows 1, '// &
                    '2 and 3)')
          exit
        end if
        spec%version = int(big)
        have_header = .true.
      case ('name', 'analysis')
        if (ntok /= 2) then
          call fail('"' // trim(key) // '" takes one word'); exit
        end if
        call next_token(line, pos, tok)
        if (key == 'name') spec%name = tok(1:NAME_LEN)
        if (key == 'analysis') then
          if (.not. any(ANALYSES == tok(1:16)) .or. len_trim(tok) > 16) then
            call fail('unknown analysis "' // trim(tok(1:40)) // '"; one of kinematics, '// &
                      'inverse-dynamics, dynamics, statics, modes, frf, check')
            exit
          end if
          spec%analysis = tok(1:NAME_LEN)
        end if
      case ('t0', 't_end', 'tol', 'tmin')
        if (.not. one_real(spec_real(key))) exit
      case ('rtol', 'atol', 'h', 'rho_inf', 'alpha', 'beta', 't')
        if (.not. setting_real(x)) exit
        select case (key)
        case ('rtol'); spec%rtol = x
        case ('atol'); spec%atol = x
        case ('h'); spec%h = x
        case ('rho_inf'); spec%rho_inf = x
        case ('alpha'); spec%alpha = x
        case ('beta'); spec%beta = x
        case default; spec%tstat = x
        end select
      case ('positions_only')
        if (.not. one_int(big)) exit
        if (big < 0 .or. big > 1) then
          call fail_int('positions_only must be 0 or ', 1_int64, '', big)
          exit
        end if
        spec%positions_only = big == 1
      case ('at_q0')
        if (.not. one_int(big)) exit
        if (big < 0 .or. big > 1) then
          call fail_int('at_q0 must be 0 or ', 1_int64, '', big)
          exit
        end if
        spec%at_q0 = big == 1
      case ('count')
        if (.not. one_int(big)) exit
        if (big < 0 .or. big > INT32_MAX) then
          call fail_int('count must be a whole number from 0 (every mode) to ', &
                        int(INT32_MAX, int64), '', big)
          exit
        end if
        spec%count = int(big)
      case ('every')
        if (.not. one_int(big)) exit
        if (big < 1 .or. big > MAX_STEPS) then
          call fail_int('every must be a whole number from 1 to ', int(MAX_STEPS, int64), &
                        '', big)
          exit
        end if
        spec%every = int(big)
      case ('max_steps')
        if (.not. one_int(big)) exit
        if (big < 0 .or. big > INT32_MAX) then
          call fail_int('max_steps must be a whole number from 0 (default) to ', &
                        int(INT32_MAX, int64), '', big)
          exit
        end if
        spec%max_steps = int(big)
      case ('solver', 'method')
        if (ntok /= 2) then
          call fail('"' // trim(key) // '" takes one word'); exit
        end if
        call next_token(line, pos, tok)
        if (key == 'solver') then
          k = word_index(SOLVER_WORDS, tok)
          if (k < 1) then
            call fail('unknown solver "' // trim(tok(1:40)) // '"; auto, dense or banded'); exit
          end if
          spec%solver = k - 1
        else
          k = word_index(METHOD_WORDS, tok)
          if (k < 1) then
            call fail('unknown method "' // trim(tok(1:40)) // '"; generalized-alpha, '// &
                      'dopri5, baumgarte-rk4 or partitioned')
            exit
          end if
          spec%method = k
        end if
      case ('gravity')
        if (ntok /= 3) then
          call fail('"gravity" takes two numbers'); exit
        end if
        do k = 1, 2
          call next_token(line, pos, tok)
          if (.not. real_ok(tok, spec%grav(k))) exit
        end do
      case ('outputs')
        do k = 2, ntok
          call next_token(line, pos, tok)
          select case (tok)
          case ('energy'); spec%out_energy = .true.
          case ('multipliers'); spec%out_lam = .true.
          case ('reactions'); spec%out_reac = .true.
          case ('efforts'); spec%out_eff = .true.
          case ('damped'); spec%out_damped = .true.
          case ('velocities'); spec%out_vel = .true.
          case default
            call fail('unknown output "' // trim(tok(1:40)) // '"; energy, multipliers, '// &
                      'reactions, efforts, damped or velocities')
            exit
          end select
        end do
      case ('steps')
        if (.not. one_int(big)) exit
        if (big < 1 .or. big > MAX_STEPS) then
          call fail_int('steps must be a whole number from 1 to ', int(MAX_STEPS, int64), &
                        ' (the number of output intervals)', big)
          exit
        end if
        spec%steps = int(big); spec%steps_line = lineno
      case ('maxit')
        if (.not. one_int(big)) exit
        if (big < 0 .or. big > MAX_ITER) then
          call fail_int('maxit must be a whole number from 0 (default) to ', &
                        int(MAX_ITER, int64), '', big)
          exit
        end if
        spec%maxit = int(big)
      case ('bodies')
        if (.not. first_time(seen_b)) exit
        if (.not. count_ok(n, 'body', 1)) exit
        spec%nb = n; spec%bodies_line = lineno
        call mem_check(real(n, wp) * (NAME_LEN + 3 * REAL_BYTES), 'the bodies', &
                       'give fewer bodies', status, msg)
        if (status /= MBD_OK) then
          call where_prefix(); exit
        end if
        deallocate (spec%body_names, spec%q0)
        allocate (spec%body_names(n), spec%q0(3, n), stat=ierr)
        if (ierr /= 0) then
          call mem_fail(real(n, wp) * (NAME_LEN + 3 * REAL_BYTES), 'the bodies', &
                        'give fewer bodies', status, msg)
          call where_prefix(); exit
        end if
        spec%q0 = zero
        deallocate (spec%bmass, spec%v0)
        allocate (spec%bmass(2, n), spec%v0(3, n), stat=ierr)
        if (ierr /= 0) then
          call mem_fail(real(n, wp) * 5 * REAL_BYTES, 'the bodies', 'give fewer bodies', &
                        status, msg)
          call where_prefix(); exit
        end if
        spec%bmass = zero; spec%v0 = zero
        do i = 1, n
          call next_line(ios)
          if (ios /= 0) exit
          ntok = count_tokens(line)
          if (i == 1) spec%have_masses = ntok == 9
          if (ntok /= merge(9, 4, spec%have_masses)) then
            call fail('bad body line: NAME X0 Y0 THETA0 expected, or NAME X0 Y0 THETA0 MASS '// &
                      'INERTIA VX0 VY0 OMEGA0 on every body line')
            exit
          end if
          pos = 1
          call next_token(line, pos, tok)
          spec%body_names(i) = tok(1:NAME_LEN)
          do k = 1, 3
            call next_token(line, pos, tok)
            if (.not. real_ok(tok, spec%q0(k, i))) exit
          end do
          if (status /= MBD_OK) exit
          if (.not. spec%have_masses) cycle
          do k = 1, 2
            call next_token(line, pos, tok)
            if (.not. real_ok(tok, spec%bmass(k, i))) exit
          end do
          do k = 1, 3
            if (status /= MBD_OK) exit
            call next_token(line, pos, tok)
            if (.not. real_ok(tok, spec%v0(k, i))) exit
          end do
          if (status /= MBD_OK) exit
        end do
      case ('constraints')
        if (.not. first_time(seen_c)) exit
        if (.not. count_ok(n, 'constraint', 0)) exit
        spec%nc = n
        call mem_check(real(n, wp) * (NAME_LEN + 4 * NCT + 4), 'the constraints', &
                       'give fewer constraints', status, msg)
        if (status /= MBD_OK) then
          call where_prefix(); exit
        end if
        deallocate (spec%con_names, spec%ctab, spec%con_line)
        allocate (spec%con_names(n), spec%ctab(NCT, n), spec%con_line(n), stat=ierr)
        if (ierr /= 0) then
          call mem_fail(real(n, wp) * (NAME_LEN + 4 * NCT + 4), 'the constraints', &
                        'give fewer constraints', status, msg)
          call where_prefix(); exit
        end if
        spec%ctab = 0; spec%con_line = 0
        do i = 1, n
          call next_line(ios)
          if (ios /= 0) exit
          spec%con_line(i) = lineno
          if (count_tokens(line) /= 8) then
            call fail('bad constraint line: NAME KIND BODY_I BODY_J SUB_A SUB_B OFFSET '// &
                      'LENGTH expected')
            exit
          end if
          pos = 1
          call next_token(line, pos, tok)
          spec%con_names(i) = tok(1:NAME_LEN)
          do k = 1, 7
            call next_token(line, pos, tok)
            if (.not. read_int(tok, big)) then
              call fail('"' // trim(tok) // '" is not a whole number'); exit
            end if
            if (abs(big) > huge(1)) then
              call fail('"' // trim(tok(1:40)) // '": a constraint entry must lie within '// &
                        '+-2147483647')
              exit
            end if
            spec%ctab(k, i) = int(big)
          end do
          if (status /= MBD_OK) exit
        end do
      case ('params')
        if (.not. first_time(seen_p)) exit
        if (.not. count_ok(n, 'parameter', 0)) exit
        call mem_check(REAL_BYTES * n, 'the parameters', 'give fewer parameters', status, msg)
        if (status /= MBD_OK) then
          call where_prefix(); exit
        end if
        deallocate (spec%rpar)
        allocate (spec%rpar(n), stat=ierr)
        if (ierr /= 0) then
          call mem_fail(REAL_BYTES * n, 'the parameters', 'give fewer parameters', status, msg)
          call where_prefix(); exit
        end if
        i = 0
        do while (i < n)
          call next_line(ios)
          if (ios /= 0) exit
          pos = 1
          do
            call next_token(line, pos, tok)
            if (len_trim(tok) == 0) exit
            if (i == n) then
              call fail('more numbers than the parameter count'); exit
            end if
            i = i + 1
            if (.not. real_ok(tok, spec%rpar(i))) exit
          end do
          if (status /= MBD_OK) exit
        end do
      case ('fparams')
        if (.not. first_time(seen_fp)) exit
        if (.not. count_ok(n, 'force parameter', 0)) exit
        call mem_check(REAL_BYTES * n, 'the force parameters', 'give fewer forces', status, msg)
        if (status /= MBD_OK) then
          call where_prefix(); exit
        end if
        deallocate (spec%fpar)
        allocate (spec%fpar(n), stat=ierr)
        if (ierr /= 0) then
          call mem_fail(REAL_BYTES * n, 'the force parameters', 'give fewer forces', status, msg)
          call where_prefix(); exit
        end if
        if (.not. read_reals(spec%fpar)) exit
      case ('frequencies')
        if (.not. first_time(seen_w)) exit
        if (.not. count_ok(n, 'frequency value', 1)) exit
        spec%freq_line = lineno
        call mem_check(REAL_BYTES * n, 'the frequencies', 'give fewer frequencies', status, msg)
        if (status /= MBD_OK) then
          call where_prefix(); exit
        end if
        deallocate (spec%freq)
        allocate (spec%freq(n), stat=ierr)
        if (ierr /= 0) then
          call mem_fail(REAL_BYTES * n, 'the frequencies', 'give fewer frequencies', status, &
                        msg)
          call where_prefix(); exit
        end if
        if (.not. read_reals(spec%freq)) exit
        if (any(spec%freq < zero)) then
          call fail('the frequencies must be >= 0 (Hz)'); exit
        end if
      case ('labels')
        if (.not. first_time(seen_l)) exit
        if (.not. count_ok(n, 'label', 0)) exit
        call mem_check(real(n, wp) * NAME_LEN, 'the row labels', 'give fewer constraints', &
                       status, msg)
        if (status /= MBD_OK) then
          call where_prefix(); exit
        end if
        deallocate (spec%labels)
        allocate (spec%labels(n), stat=ierr)
        if (ierr /= 0) then
          call mem_fail(real(n, wp) * NAME_LEN, 'the row labels', 'give fewer constraints', &
                        status, msg)
          call where_prefix(); exit
        end if
        spec%nlabels = n
        i = 0
        do while (i < n)
          call next_line(ios)
          if (ios /= 0) exit
          pos = 1
          do
            call next_token(line, pos, tok)
            if (len_trim(tok) == 0) exit
            if (i == n) then
              call fail('more labels than the label count'); exit
            end if
            i = i + 1
            spec%labels(i) = tok(1:NAME_LEN)
          end do
          if (status /= MBD_OK) exit
        end do
      case ('forces')
        if (.not. first_time(seen_f)) exit
        if (.not. count_ok(n, 'force', 0)) exit
        spec%nf = n
        call mem_check(real(n, wp) * (NAME_LEN + 4 * NFT), 'the forces', 'give fewer forces', &
                       status, msg)
        if (status /= MBD_OK) then
          call where_prefix(); exit
        end if
        deallocate (spec%force_names, spec%ftab)
        allocate (spec%force_names(n), spec%ftab(NFT, n), stat=ierr)
        if (ierr /= 0) then
          call mem_fail(real(n, wp) * (NAME_LEN + 4 * NFT), 'the forces', 'give fewer forces', &
                        status, msg)
          call where_prefix(); exit
        end if
        spec%ftab = 0
        do i = 1, n
          call next_line(ios)
          if (ios /= 0) exit
          ntf = count_tokens(line)
          if (ntf /= NFT .and. ntf /= NFT + 1) then
            call fail('bad force line: NAME KIND BODY_I BODY_J OFFSET LENGTH [JOINT] '// &
                      'expected'); exit
          end if
          pos = 1
          call next_token(line, pos, tok)
          spec%force_names(i) = tok(1:NAME_LEN)
          do k = 1, ntf - 1          ! JOINT (column NFT): a joint friction's constraint
            call next_token(line, pos, tok)
            if (.not. read_int(tok, big)) then
              call fail('"' // trim(tok) // '" is not a whole number'); exit
            end if
            if (abs(big) > huge(1)) then
              call fail('"' // trim(tok(1:40)) // '": a force entry must lie within '// &
                        '+-2147483647')
              exit
            end if
            spec%ftab(k, i) = int(big)
          end do
          if (status /= MBD_OK) exit
        end do
      case ('sensitivities')
        if (.not. first_time(seen_s)) exit
        if (.not. read_sensitivities()) exit
      case ('measures')
        if (.not. first_time(seen_m)) exit
        if (.not. read_measures()) exit
      case ('cases')
        if (.not. first_time(seen_k)) exit
        if (.not. read_cases()) exit
      case ('opens')
        if (.not. first_time(seen_o)) exit
        if (.not. read_opens()) exit
      case ('end')
        if (ntok /= 1) then
          call fail('"end" stands alone'); exit
        end if
        done = .true.
      case default
        call fail('unknown keyword "' // trim(key) // '"')
      end select
      if (status /= MBD_OK .or. done) exit
      if (ios /= 0) exit
    end do
    close (u)
    if (status == MBD_OK .and. .not. done) then
      status = MBD_BAD_INPUT
      write (msg, '(a,a,i0,a)') trim(path), ':', lineno, ': missing "end" line: the file ends '// &
        'before it (truncated?)'
    end if
    if (status == MBD_OK .and. spec%version < 3) call upgrade_functions(spec, status, msg)
  contains

    !> The next data line into `line` (comments and blank lines skipped); iostat /= 0 at the
    !! end of the file, where status is set unless a block is still open.
    subroutine next_line(iostat)
      integer, intent(out) :: iostat
      do
        read (u, '(a)', iostat=iostat) line
        if (iostat /= 0) return
        lineno = lineno + 1
        line = adjustl(line)
        if (len_trim(line) == 0 .or. line(1:1) == '#') cycle
        nread = nread + 1
        chars_left = chars_left - len_trim(line) - 1
        if (len_trim(line) >= LINE_LEN) then
          write (tok, '(a,i0,a)') 'line longer than ', LINE_LEN - 1, ' characters'
          call fail(trim(tok)); iostat = 1
        end if
        return
      end do
    end subroutine next_line

    !> A count on the current line: a whole number >= lo, no more than the lines left (one per
    !! item; for parameters, every number takes at least two characters).
    logical function count_ok(nn, what, lo)
      integer, intent(out) :: nn
      character(len=*), intent(in) :: what
      integer, intent(in) :: lo
      integer(int64) :: c, room
      count_ok = .false.; nn = 0
      if (.not. one_int(c)) return
      if (what == 'parameter' .or. what == 'force parameter' .or. what == 'label' .or. &
          what == 'frequency value') then
        room = (chars_left + 1) / 2
      else
        room = ndata - nread
      end if
      if (c < lo) then
        call fail_int('the ' // what // ' count must be at least ', int(lo, int64), '', c)
        return
      end if
      if (c > room) then
        if (what == 'parameter' .or. what == 'force parameter' .or. what == 'label' .or. &
            what == 'frequency value') then
          call fail_int('more ' // what // 's than the rest of the file can hold (at most ', &
                        room, '): the count does not match the file (truncated or edited?)', c)
        else
          call fail_int('more ' // what // ' lines than the file has left (', room, &
                        '): the count does not match the file (truncated or edited?)', c)
        end if
        return
      end if
      nn = int(c)
      count_ok = .true.
    end function count_ok

    !> The keyword's one whole-number value.
    logical function one_int(v)
      integer(int64), intent(out) :: v
      one_int = .false.; v = 0
      if (ntok /= 2) then
        call fail('"' // trim(key) // '" takes one whole number'); return
      end if
      call next_token(line, pos, tok)
      if (.not. read_int(tok, v)) then
        call fail('"' // trim(key) // '": "' // trim(tok(1:40)) // '" is not a whole number')
        return
      end if
      one_int = .true.
    end function one_int

    !> The keyword's one real value, checked and stored.
    logical function one_real(which)
      integer, intent(in) :: which
      real(wp) :: x
      one_real = .false.
      if (ntok /= 2) then
        call fail('"' // trim(key) // '" takes one number'); return
      end if
      call next_token(line, pos, tok)
      if (.not. real_ok(tok, x)) return
      select case (which)
      case (1); spec%t0 = x
      case (2); spec%t_end = x
      case (3)
        if (.not. (x <= zero .and. x >= zero) .and. .not. (x >= MIN_TOL .and. x < one)) then
          call fail('tol must be 0 (default) or from 1e-15 to below 1'); return
        end if
        spec%tol = x
      case (4)
        if (x < zero) then
          call fail('tmin must be >= 0 (0: default)'); return
        end if
        spec%tmin = x
      end select
      one_real = .true.
    end function one_real

    !> The keyword's one finite real, in the range of its setting (0 or -1 for the default).
    logical function setting_real(v)
      real(wp), intent(out) :: v
      logical :: dflt
      setting_real = .false.; v = zero
      if (ntok /= 2) then
        call fail('"' // trim(key) // '" takes one number'); return
      end if
      call next_token(line, pos, tok)
      if (.not. real_ok(tok, v)) return
      select case (key)
      case ('rtol')
        if (.not. (is_zero(v) .or. (v >= 1.0e-14_wp .and. v <= one))) then
          call fail('rtol must be 0 (default) or from 1e-14 to 1'); return
        end if
      case ('atol')
        if (.not. (is_zero(v) .or. (v >= 1.0e-16_wp .and. v <= 1.0e6_wp))) then
          call fail('atol must be 0 (default) or from 1e-16 to 1e6'); return
        end if
      case ('h')
        if (.not. (is_zero(v) .or. v >= 1.0e-12_wp)) then
          call fail('h must be 0 (none) or at least 1e-12'); return
        end if
      case ('rho_inf')
        dflt = v <= -one .and. v >= -one
        if (.not. (dflt .or. (v >= zero .and. v <= one))) then
          call fail('rho_inf must be -1 (default) or from 0 to 1'); return
        end if
      case ('alpha', 'beta')
        dflt = v <= -one .and. v >= -one
        if (.not. (dflt .or. (v >= zero .and. v <= 1.0e9_wp))) then
          call fail(trim(key) // ' must be -1 (default) or from 0 to 1e9'); return
        end if
      end select
      setting_real = .true.
    end function setting_real

    !> True the first time a block's keyword comes (marking it seen); a failure after.
    logical function first_time(seen)
      logical, intent(inout) :: seen
      first_time = .not. seen
      if (seen) call fail('"' // trim(key) // '" is given twice')
      seen = .true.
    end function first_time

    !> The "sensitivities" block: a count, then NAME TABLE INDEX per design parameter.
    logical function read_sensitivities()
      integer :: j
      read_sensitivities = .false.
      if (.not. count_ok(n, 'sensitivity', 1)) return
      call mem_check(real(n, wp) * (PNAME_LEN + 12), 'the design parameters', &
                     'give fewer sensitivities', status, msg)
      if (status /= MBD_OK) then
        call where_prefix(); return
      end if
      deallocate (spec%par_names, spec%ptab, spec%par_line)
      allocate (spec%par_names(n), spec%ptab(2, n), spec%par_line(n), stat=ierr)
      if (ierr /= 0) then
        call mem_fail(real(n, wp) * (PNAME_LEN + 12), 'the design parameters', &
                      'give fewer sensitivities', status, msg)
        call where_prefix(); return
      end if
      spec%npar = n; spec%sens_line = lineno; spec%ptab = 0
      do j = 1, n
        call next_line(ios)
        if (ios /= 0) return
        spec%par_line(j) = lineno
        if (count_tokens(line) /= 3) then
          call fail('bad sensitivity line: NAME TABLE INDEX expected'); return
        end if
        pos = 1
        call next_token(line, pos, tok)
        if (len_trim(tok) > PNAME_LEN) then
          call fail('a design parameter name is longer than 256 characters'); return
        end if
        spec%par_names(j) = tok(1:PNAME_LEN)
        if (.not. table_entry(spec%ptab(:, j))) return
      end do
      read_sensitivities = .true.
    end function read_sensitivities

    !> The "cases" block: "cases NP NV NCASE", NP parameter names, NV lines TABLE INDEX,
    !! then (NP + NV) * NCASE reals.
    logical function read_cases()
      integer(int64) :: c(3), room
      integer :: j
      read_cases = .false.
      if (ntok /= 4) then
        call fail('"cases" takes three whole numbers: NP NV NCASE'); return
      end if
      do j = 1, 3
        call next_token(line, pos, tok)
        if (.not. read_int(tok, c(j))) then
          call fail('"cases": "' // trim(tok(1:40)) // '" is not a whole number'); return
        end if
      end do
      if (c(1) < 1 .or. c(2) < 0 .or. c(3) < 1) then
        call fail('"cases NP NV NCASE": NP and NCASE must be at least 1, NV at least 0')
        return
      end if
      room = ndata - nread
      if (c(1) + c(2) > room .or. (c(1) + c(2)) * c(3) > (chars_left + 1) / 2) then
        call fail('more cases than the rest of the file can hold: the counts do not match '// &
                  'the file (truncated or edited?)'); return
      end if
      call mem_check(real(c(1), wp) * PNAME_LEN + 8 * real(c(2), wp) + &
                     REAL_BYTES * real(c(1) + c(2), wp) * real(c(3), wp), 'the cases', &
                     'give fewer cases', status, msg)
      if (status /= MBD_OK) then
        call where_prefix(); return
      end if
      spec%ncp = int(c(1)); spec%nv = int(c(2)); spec%ncase = int(c(3))
      spec%cases_line = lineno
      deallocate (spec%case_names, spec%vtab, spec%cvals)
      allocate (spec%case_names(spec%ncp), spec%vtab(2, spec%nv), &
                spec%cvals(spec%ncp + spec%nv, spec%ncase), stat=ierr)
      if (ierr /= 0) then
        call mem_fail(REAL_BYTES * real(c(1) + c(2), wp) * real(c(3), wp), 'the cases', &
                      'give fewer cases', status, msg)
        call where_prefix(); return
      end if
      spec%vtab = 0
      do j = 1, spec%ncp
        call next_line(ios)
        if (ios /= 0) return
        if (count_tokens(line) /= 1) then
          call fail('bad case parameter line: one NAME expected'); return
        end if
        pos = 1
        call next_token(line, pos, tok)
        if (len_trim(tok) > PNAME_LEN) then
          call fail('a parameter name is longer than 256 characters'); return
        end if
        spec%case_names(j) = tok(1:PNAME_LEN)
      end do
      do j = 1, spec%nv
        call next_line(ios)
        if (ios /= 0) return
        if (count_tokens(line) /= 2) then
          call fail('bad case entry line: TABLE INDEX expected'); return
        end if
        pos = 1
        if (.not. table_entry(spec%vtab(:, j))) return
      end do
      read_cases = read_reals_2d(spec%cvals)
    end function read_cases

    !> The next two tokens as an entry of the core's tables: TABLE (1 params, 2 masses,
    !! 3 gravity, 4 fparams) and a 1-based INDEX.
    logical function table_entry(e)
      integer, intent(out) :: e(2)
      integer :: it
      integer(int64) :: v
      table_entry = .false.; e = 0
      do it = 1, 2
        call next_token(line, pos, tok)
        if (.not. read_int(tok, v)) v = -1
        if (it == 1 .and. (v < 1 .or. v > 4)) then
          call fail('"' // trim(tok(1:40)) // '": TABLE is 1 (params), 2 (masses), '// &
                    '3 (gravity) or 4 (fparams)'); return
        end if
        if (it == 2 .and. (v < 1 .or. v > huge(1))) then
          call fail('"' // trim(tok(1:40)) // '": INDEX is a whole number from 1'); return
        end if
        e(it) = int(v)
      end do
      table_entry = .true.
    end function table_entry

    !> The "measures" block: a count, then a recipe line per measure column.
    logical function read_measures()
      integer :: j, it, nt
      integer(int64) :: v
      character(len=16) :: word
      read_measures = .false.
      if (.not. count_ok(n, 'measure', 1)) return
      deallocate (spec%meas_names, spec%meas_kind, spec%meas_int, spec%meas_pts, &
                  spec%meas_ref, spec%meas_line)
      allocate (spec%meas_names(n), spec%meas_kind(n), spec%meas_int(5, n), &
                spec%meas_pts(2, 3, n), spec%meas_ref(2, 3, n), spec%meas_line(n), stat=ierr)
      if (ierr /= 0) then
        call mem_fail(real(n, wp) * (PNAME_LEN + 100), 'the measures', 'give fewer measures', &
                      status, msg)
        call where_prefix(); return
      end if
      spec%nmeas = n; spec%meas_int = 0; spec%meas_pts = zero; spec%meas_ref = 0
      do j = 1, n
        call next_line(ios)
        if (ios /= 0) return
        spec%meas_line(j) = lineno
        nt = count_tokens(line)
        pos = 1
        call next_token(line, pos, tok)
        if (len_trim(tok) > PNAME_LEN) then
          call fail('a measure name is longer than 256 characters'); return
        end if
        spec%meas_names(j) = tok(1:PNAME_LEN)
        call next_token(line, pos, tok)
        word = tok(1:16)
        select case (word)
        case ('angle')
          if (nt /= 12 .and. nt /= 18) then
            call fail('bad measure line: SPEC angle KIND B1 X Y B2 X Y B3 X Y [IX1 IY1 IX2 '// &
                      'IY2 IX3 IY3] expected'); return
          end if
          spec%meas_kind(j) = MEAS_ANGLE
          call next_token(line, pos, tok)
          if (.not. read_int(tok, v)) v = -1
          if (v < 1 .or. v > 2) then
            call fail('"' // trim(tok(1:40)) // '": an angle KIND is 1 (turning) or 2 '// &
                      '(sliding)'); return
          end if
          spec%meas_int(1, j) = int(v)
          do it = 1, 3
            call next_token(line, pos, tok)
            if (.not. read_int(tok, v)) v = -1
            if (v < 0 .or. v > huge(1)) then
              call fail('"' // trim(tok(1:40)) // '": a body number is a whole number '// &
                        'from 0 (ground)'); return
            end if
            spec%meas_int(1 + it, j) = int(v)
            call next_token(line, pos, tok)
            if (.not. real_ok(tok, spec%meas_pts(1, it, j))) return
            call next_token(line, pos, tok)
            if (.not. real_ok(tok, spec%meas_pts(2, it, j))) return
          end do
          do it = 1, merge(6, 0, nt == 18)    ! the points' params entries (0: as given)
            call next_token(line, pos, tok)
            if (.not. read_int(tok, v)) v = -1
            if (v < 0 .or. v > huge(1)) then
              call fail('"' // trim(tok(1:40)) // '": a point''s entry is a whole number '// &
                        'from 0 (the number given)'); return
            end if
            spec%meas_ref(2 - mod(it, 2), (it + 1) / 2, j) = int(v)
          end do
        case ('ratio', 'advantage')
          if (nt /= 7) then
            call fail('bad measure line: SPEC ' // trim(word) // ' REF XKIND XINDEX YKIND '// &
                      'YINDEX expected'); return
          end if
          spec%meas_kind(j) = merge(MEAS_RATIO, MEAS_ADVANTAGE, word == 'ratio')
          do it = 1, 5
            call next_token(line, pos, tok)
            if (.not. read_int(tok, v)) v = -1
            if (v < 1 .or. v > huge(1) .or. ((it == 2 .or. it == 4) .and. v > 2)) then
              call fail('"' // trim(tok(1:40)) // '": REF and the indices are whole numbers '// &
                        'from 1, the kinds 1 (coordinate) or 2 (driver)'); return
            end if
            spec%meas_int(it, j) = int(v)
          end do
        case ('conditioning')
          if (nt /= 2) then
            call fail('bad measure line: SPEC conditioning expected'); return
          end if
          spec%meas_kind(j) = MEAS_CONDITIONING
        case default
          call fail('unknown measure "' // trim(tok(1:40)) // '"; angle, ratio, advantage '// &
                    'or conditioning'); return
        end select
      end do
      read_measures = .true.
    end function read_measures

    !> The "opens" block: a count, then RPAR_INDEX ROW per open phase.
    logical function read_opens()
      integer :: j, it
      integer(int64) :: v
      read_opens = .false.
      if (.not. count_ok(n, 'open phase', 0)) return
      deallocate (spec%opens)
      allocate (spec%opens(2, n), stat=ierr)
      if (ierr /= 0) then
        call mem_fail(real(n, wp) * 8, 'the open phases', 'give fewer joints', status, msg)
        call where_prefix(); return
      end if
      do j = 1, n
        call next_line(ios)
        if (ios /= 0) return
        if (count_tokens(line) /= 2) then
          call fail('bad open phase line: RPAR_INDEX ROW expected'); return
        end if
        pos = 1
        do it = 1, 2
          call next_token(line, pos, tok)
          if (.not. read_int(tok, v)) v = -1
          if (v < 1 .or. v > huge(1)) then
            call fail('"' // trim(tok(1:40)) // '": an open phase entry is a whole number '// &
                      'from 1'); return
          end if
          spec%opens(it, j) = int(v)
        end do
      end do
      read_opens = .true.
    end function read_opens

    !> The numbers of a block into a 2-D array, column by column (any number per line).
    logical function read_reals_2d(xs)
      real(wp), intent(out), contiguous, target :: xs(:, :)
      real(wp), pointer :: flat(:)
      flat(1:size(xs)) => xs
      read_reals_2d = read_reals(flat)
    end function read_reals_2d

    !> The numbers of a block (any number per line) into x, exactly size(x) of them.
    logical function read_reals(xs)
      real(wp), intent(out) :: xs(:)
      integer :: j
      read_reals = .false.
      xs = zero
      j = 0
      do while (j < size(xs))
        call next_line(ios)
        if (ios /= 0) return
        pos = 1
        do
          call next_token(line, pos, tok)
          if (len_trim(tok) == 0) exit
          if (j == size(xs)) then
            call fail('more numbers than the count'); return
          end if
          j = j + 1
          if (.not. real_ok(tok, xs(j))) return
        end do
      end do
      read_reals = .true.
    end function read_reals

    integer function spec_real(k2)
      character(len=*), intent(in) :: k2
      select case (k2)
      case ('t0'); spec_real = 1
      case ('t_end'); spec_real = 2
      case ('tol'); spec_real = 3
      case default; spec_real = 4
      end select
    end function spec_real

    !> A finite real number from a token, or fail.
    logical function real_ok(t, x)
      character(len=*), intent(in) :: t
      real(wp), intent(out) :: x
      integer :: i2, io
      real_ok = .false.; x = zero
      do i2 = 1, len_trim(t)
        if (index('0123456789+-.eEdD', t(i2:i2)) == 0) then
          call fail('"' // trim(t(1:40)) // '" is not a number'); return
        end if
      end do
      read (t, *, iostat=io) x
      if (io /= 0) then
        call fail('"' // trim(t(1:40)) // '" is not a number'); return
      end if
      if (.not. ieee_is_finite(x)) then
        call fail('"' // trim(t(1:40)) // '" is not a finite number'); return
      end if
      real_ok = .true.
    end function real_ok

    !> '"KEY VALUE": what LIMIT after' as a failure.
    subroutine fail_int(what, limit, after, v)
      character(len=*), intent(in) :: what, after
      integer(int64), intent(in) :: limit, v
      character(len=MSG_LEN) :: s
      write (s, '(a,a,a,i0,a,a,i0,a)') '"', trim(key), ' ', v, '": ', what, limit, after
      call fail(trim(s))
    end subroutine fail_int

    subroutine fail(what)
      character(len=*), intent(in) :: what
      status = MBD_BAD_INPUT
      write (msg, '(a,a,i0,a,a)') trim(path), ':', lineno, ': ', what
    end subroutine fail

    !> "FILE:LINE: " in front of a memory message.
    subroutine where_prefix()
      character(len=MSG_LEN) :: s
      write (s, '(a,a,i0,a,a)') trim(path), ':', lineno, ': ', trim(msg)
      msg = s
    end subroutine where_prefix
  end subroutine mbd_read

  !> Formats 1 and 2 wrote functions of time without their steps and table ([np, c, nh,
  !! harmonics]): each driver's and force's function gets its counts of steps and table
  !! points, 0 and 0, and every index into
  !! params and fparams (design parameters, sweep entries, measure points, open phases)
  !! moves with its entry. Slices out of range are left as they are (the model's checks
  !! name them).
  subroutine upgrade_functions(spec, status, msg)
    type(mbd_spec_t), intent(inout) :: spec      !! contents read
    integer, intent(inout) :: status             !! MBD_OK, or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(inout) :: msg !! what is wrong
    integer, allocatable :: rmap(:), fmap(:)
    real(wp), allocatable :: rnew(:), fnew(:)
    integer :: ierr, c, f, k, i, j, nr, nf2
    allocate (rmap(size(spec%rpar)), fmap(size(spec%fpar)), &
              rnew(size(spec%rpar) + 2 * spec%nc), fnew(size(spec%fpar) + 4 * spec%nf), &
              stat=ierr)
    if (ierr /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory reading the model file'; return
    end if
    rmap = [(k, k = 1, size(rmap))]; fmap = [(k, k = 1, size(fmap))]
    nr = 0
    do c = 1, spec%nc                     ! each constraint's slice, a driver's with ns = 0
      if (.not. slice_ok(spec%ctab(6, c), spec%ctab(7, c), size(spec%rpar))) return
      call copy_slice(spec%rpar, spec%ctab(6, c), spec%ctab(7, c), rnew, nr, rmap)
      if (spec%ctab(1, c) >= DRV_ABS .and. spec%ctab(1, c) <= DRV_REL_DIST) &
        call put_counts(rnew, nr, spec%ctab(7, c))
      spec%ctab(6, c) = nr - spec%ctab(7, c) + 1
    end do
    nf2 = 0
    do f = 1, spec%nf                     ! each force's slice, its functions with ns = 0
      if (.not. slice_ok(spec%ftab(4, f), spec%ftab(5, f), size(spec%fpar))) return
      i = spec%ftab(4, f); j = i + spec%ftab(5, f) - 1
      select case (spec%ftab(1, f))
      case (FRC_POINT)                    ! point s(2) fx fy: fx ends at i + 1 + its length
        k = old_length(spec%fpar(i + 2:j))
        if (k < 0) return
        call copy_slice(spec%fpar, i, k + 2, fnew, nf2, fmap)
        call put_counts(fnew, nf2, spec%ftab(5, f))
        call copy_slice(spec%fpar, i + k + 2, j - i - k - 1, fnew, nf2, fmap)
        call put_counts(fnew, nf2, spec%ftab(5, f))
      case (FRC_SPRING, FRC_TORQUE, FRC_ROTSPRING)   ! the function last
        call copy_slice(spec%fpar, i, j - i + 1, fnew, nf2, fmap)
        call put_counts(fnew, nf2, spec%ftab(5, f))
      case default
        call copy_slice(spec%fpar, i, j - i + 1, fnew, nf2, fmap)
      end select
      spec%ftab(4, f) = nf2 - spec%ftab(5, f) + 1
    end do
    call move_alloc(rnew, spec%rpar); call move_alloc(fnew, spec%fpar)
    spec%rpar = spec%rpar(1:nr); spec%fpar = spec%fpar(1:nf2)
    do k = 1, spec%npar                   ! the indices that point into the lists
      call remap(spec%ptab(1, k), spec%ptab(2, k))
    end do
    do k = 1, spec%nv
      call remap(spec%vtab(1, k), spec%vtab(2, k))
    end do
    do k = 1, spec%nmeas
      do j = 1, 3
        do i = 1, 2
          call remap(1, spec%meas_ref(i, j, k))
        end do
      end do
    end do
    do k = 1, size(spec%opens, 2)
      call remap(1, spec%opens(1, k))
    end do
  contains
    logical function slice_ok(off, n, size_all)
      integer, intent(in) :: off, n, size_all
      slice_ok = off >= 1 .and. n >= 0 .and. off <= size_all - n + 1
    end function slice_ok
    subroutine copy_slice(a, off, n, b, nb, map)
      real(wp), intent(in) :: a(:)
      integer, intent(in) :: off, n
      real(wp), intent(inout) :: b(:)
      integer, intent(inout) :: nb, map(:)
      integer :: e
      do e = 0, n - 1
        nb = nb + 1; b(nb) = a(off + e); map(off + e) = nb
      end do
    end subroutine copy_slice
    subroutine put_counts(b, nb, n)         ! ns = 0, nt = 0
      real(wp), intent(inout) :: b(:)
      integer, intent(inout) :: nb, n
      b(nb + 1:nb + 2) = zero; nb = nb + 2; n = n + 2
    end subroutine put_counts
    integer function old_length(a)      ! [np, c, nh, (A, w, phi) x nh], -1 when malformed
      real(wp), intent(in) :: a(:)
      integer :: np
      old_length = -1
      if (size(a) < 2) return
      if (.not. small_count(a(1))) return
      np = nint(a(1))
      if (size(a) < np + 2) return
      if (.not. small_count(a(np + 2))) return
      old_length = np + 2 + 3 * nint(a(np + 2))
      if (old_length > size(a)) old_length = -1
    end function old_length
    logical function small_count(x)
      real(wp), intent(in) :: x
      small_count = ieee_is_finite(x)
      if (small_count) small_count = x >= zero .and. x < 1.0e6_wp
    end function small_count
    subroutine remap(table, idx)
      integer, intent(in) :: table
      integer, intent(inout) :: idx
      if (table == 1 .and. idx >= 1 .and. idx <= size(rmap)) idx = rmap(idx)
      if (table == 4 .and. idx >= 1 .and. idx <= size(fmap)) idx = fmap(idx)
    end subroutine remap
  end subroutine upgrade_functions

  !> Position of a word in a list (0: not there).
  pure integer function word_index(words, w) result(k)
    character(len=*), intent(in) :: words(:)   !! the list
    character(len=*), intent(in) :: w          !! the word
    integer :: i
    k = 0
    if (len_trim(w) > len(words)) return
    do i = 1, size(words)
      if (words(i) == w) then
        k = i; return
      end if
    end do
  end function word_index

  pure logical function is_zero(x)
    real(wp), intent(in) :: x
    is_zero = x <= zero .and. x >= zero
  end function is_zero

  !> Number of whitespace-separated tokens in a line.
  pure integer function count_tokens(line) result(n)
    character(len=*), intent(in) :: line   !! the line
    integer :: i
    logical :: inside
    n = 0; inside = .false.
    do i = 1, len_trim(line)
      if (line(i:i) == ' ' .or. line(i:i) == achar(9) .or. line(i:i) == achar(13)) then
        inside = .false.
      else if (.not. inside) then
        inside = .true.; n = n + 1
      end if
    end do
  end function count_tokens

  !> The next whitespace-separated token from line(pos:), pos moved past it ('' at the end).
  pure subroutine next_token(line, pos, tok)
    character(len=*), intent(in) :: line    !! the line
    integer, intent(inout) :: pos           !! where to start; after the token on return
    character(len=*), intent(out) :: tok    !! the token
    integer :: i0, n
    n = len_trim(line)
    tok = ''
    do while (pos <= n)
      if (.not. blank(line(pos:pos))) exit
      pos = pos + 1
    end do
    i0 = pos
    do while (pos <= n)
      if (blank(line(pos:pos))) exit
      pos = pos + 1
    end do
    if (pos > i0) tok = line(i0:pos - 1)
  contains
    pure logical function blank(c)
      character, intent(in) :: c
      blank = c == ' ' .or. c == achar(9) .or. c == achar(13)
    end function blank
  end subroutine next_token

  !> A whole number (digits with an optional sign) from a token; beyond 18 digits the value
  !! is +-huge(v), so that it fails every range check as the number it is.
  logical function read_int(t, v)
    character(len=*), intent(in) :: t     !! token
    integer(int64), intent(out) :: v      !! its value
    integer :: i, i0, n, d
    logical :: neg
    read_int = .false.; v = 0
    n = len_trim(t)
    if (n == 0) return
    neg = t(1:1) == '-'
    i0 = 1
    if (t(1:1) == '-' .or. t(1:1) == '+') i0 = 2
    if (n < i0) return
    do i = i0, n
      d = index('0123456789', t(i:i)) - 1
      if (d < 0) return
      if (v < 10_int64**17) v = 10 * v + d
      if (i - i0 + 1 > 18) v = huge(v)
    end do
    if (neg) v = -v
    read_int = .true.
  end function read_int

end module mbd_mbdfile
