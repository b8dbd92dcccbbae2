!> mbd_constraints: the one interface every constraint family answers.
!!
!! How many rows and extra coordinates it has, how its raw parameters are checked and
!! prepared, its rows of Phi, J, nu and gamma at a state, and a starting value for its
!! extra coordinates. The assembly loop calls only these; a new joint adds a case here.
!! Kind codes (the flat model table, column 1):
!!   1 revolute  2 translational  3 cam (and point on curve)  4 distance
!!   5 point on line (pin in slot)  6 weld  7 gear pair  8 rack and pinion  9 rolling disc
!!   10 absolute constraint (fix x, y or theta of a body)
!!   101 absolute driver  102 relative-angle driver  103 relative-distance driver
module mbd_constraints
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use mbd_kinds, only: wp
  use mbd_status, only: MBD_OK, MBD_BAD_INPUT, MBD_BAD_PARAM, MBD_NO_MEMORY, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, kloc
  use mbd_dual, only: dloc
  use mbd_functions, only: fun_length, fun_check, fun_exponents, fun_is_count, fun_next_break
  use mbd_profiles, only: profile_exponents
  use mbd_joint_revolute, only: revolute_prepare, revolute_eval, revolute_eval_d
  use mbd_joint_translational, only: translational_prepare, translational_eval, &
                                     translational_prepare_d, translational_eval_d
  use mbd_joint_cam, only: cam_raw_length, cam_prepare, cam_eval, cam_init_alpha, ALPHA_SLOT, &
                           cam_prepare_d, cam_eval_d, cam_is_count
  use mbd_joint_distance, only: distance_prepare, distance_eval, distance_eval_d
  use mbd_joint_point_line, only: point_line_prepare, point_line_eval, point_line_prepare_d, &
                                  point_line_eval_d
  use mbd_joint_weld, only: weld_prepare, weld_eval, weld_eval_d
  use mbd_joint_gear, only: gear_prepare, gear_eval, GEAR_RAW_LEN, gear_prepare_d, gear_eval_d
  use mbd_joint_rolling, only: rolling_prepare, rolling_eval, rolling_prepare_d, rolling_eval_d
  use mbd_drivers, only: driver_eval, driver_eval_d, DRV_ABS, DRV_REL_ANGLE, DRV_REL_DIST, &
                         TRANS_PREP_LEN
  implicit none
  private
  public :: CON_REVOLUTE, CON_TRANSLATIONAL, CON_CAM, CON_DISTANCE, CON_POINT_LINE, CON_WELD, &
            CON_GEAR, CON_RACK, CON_ROLLING, CON_ABSOLUTE, DRV_ABS, DRV_REL_ANGLE, DRV_REL_DIST
  public :: con_known, con_nrow, con_nextra, con_is_driver, con_raw_length, con_prepare
  public :: con_eval, con_init_extra, con_name, con_exponents, con_row_power
  public :: con_is_count, con_prepare_d, con_eval_d, con_linear, con_affine_r, con_next_break

  integer, parameter :: CON_REVOLUTE = 1, CON_TRANSLATIONAL = 2, CON_CAM = 3, CON_DISTANCE = 4
  integer, parameter :: CON_POINT_LINE = 5, CON_WELD = 6, CON_GEAR = 7, CON_RACK = 8
  integer, parameter :: CON_ROLLING = 9, CON_ABSOLUTE = 10

contains

  pure logical function con_known(kind)
    integer, intent(in) :: kind   !! kind code
    select case (kind)
    case (CON_REVOLUTE:CON_ABSOLUTE, DRV_ABS, DRV_REL_ANGLE, DRV_REL_DIST)
      con_known = .true.
    case default
      con_known = .false.
    end select
  end function con_known

  !> A short name of the kind, for messages.
  pure function con_name(kind) result(name)
    integer, intent(in) :: kind   !! kind code
    character(len=24) :: name
    select case (kind)
    case (CON_REVOLUTE); name = 'revolute'
    case (CON_TRANSLATIONAL); name = 'translational'
    case (CON_CAM); name = 'cam'
    case (CON_DISTANCE); name = 'distance'
    case (CON_POINT_LINE); name = 'point-on-line'
    case (CON_WELD); name = 'weld'
    case (CON_GEAR); name = 'gear'
    case (CON_RACK); name = 'rack-and-pinion'
    case (CON_ROLLING); name = 'rolling disc'
    case (CON_ABSOLUTE); name = 'absolute constraint'
    case (DRV_ABS); name = 'absolute driver'
    case (DRV_REL_ANGLE); name = 'relative-angle driver'
    case (DRV_REL_DIST); name = 'relative-distance driver'
    case default; name = 'unknown'
    end select
  end function con_name

  !> Number of constraint rows.
  pure integer function con_nrow(kind)
    integer, intent(in) :: kind   !! kind code
    select case (kind)
    case (CON_REVOLUTE, CON_TRANSLATIONAL, CON_CAM, CON_ROLLING); con_nrow = 2
    case (CON_WELD); con_nrow = 3
    case default; con_nrow = 1
    end select
  end function con_nrow

  !> Number of extra coordinates the constraint adds.
  pure integer function con_nextra(kind)
    integer, intent(in) :: kind   !! kind code
    con_nextra = 0
    if (kind == CON_CAM) con_nextra = 1
  end function con_nextra

  pure logical function con_is_driver(kind)
    integer, intent(in) :: kind   !! kind code
    con_is_driver = kind > 100
  end function con_is_driver

  !> A driver's first breakpoint after t (a step's t0 or t1 in its function of time, where
  !! its acceleration may jump), from its prepared parameters p; huge for other constraints.
  pure real(wp) function con_next_break(kind, p, t) result(tb)
    integer, intent(in) :: kind        !! constraint kind
    real(wp), intent(in) :: p(:)       !! prepared parameters
    real(wp), intent(in) :: t          !! time
    select case (kind)
    case (DRV_ABS, DRV_REL_ANGLE); tb = fun_next_break(p, t)
    case (DRV_REL_DIST); tb = fun_next_break(p(TRANS_PREP_LEN + 1:), t)
    case default; tb = huge(t)
    end select
  end function con_next_break

  !> Expected raw length given the data, or -1 when malformed.
  pure integer function con_raw_length(kind, suba, raw)
    integer, intent(in) :: kind, suba  !! kind and first sub-kind
    real(wp), intent(in) :: raw(:)     !! the raw parameter slice
    select case (kind)
    case (CON_REVOLUTE); con_raw_length = 4
    case (CON_TRANSLATIONAL); con_raw_length = 8
    case (CON_CAM); con_raw_length = cam_raw_length(suba, raw)
    case (CON_DISTANCE, CON_WELD); con_raw_length = 5
    case (CON_POINT_LINE); con_raw_length = 7
    case (CON_GEAR); con_raw_length = GEAR_RAW_LEN
    case (CON_RACK, CON_ROLLING); con_raw_length = 8
    case (CON_ABSOLUTE); con_raw_length = 1
    case default; con_raw_length = fun_length(raw)
    end select
  end function con_raw_length

  !> Length exponents of the raw parameters (a nondimensional model, mbd_model, divides each
  !! length by L: p L**ex with ex = -1 for a length, 0 for an angle, a direction or a count),
  !! and which of them are the model's geometry (points, sizes, positions: they set L).
  !! Driver functions scale with what they drive; extra coordinates (cam alpha) are angles.
  pure subroutine con_exponents(kind, suba, subb, raw, ex, geom)
    integer, intent(in) :: kind, suba, subb  !! kind and sub-kinds
    real(wp), intent(in) :: raw(:)           !! raw parameters (well formed, exact length)
    integer, intent(out) :: ex(:)            !! exponents (size(raw))
    logical, intent(out) :: geom(:)          !! geometry entries (size(raw))
    ex = 0
    select case (kind)
    case (CON_REVOLUTE, CON_DISTANCE)
      ex = -1
    case (CON_TRANSLATIONAL)
      ex(1:4) = -1
    case (CON_CAM)
      ex(1:2) = -1
      if (subb == 2) ex(3) = -1                      ! roller radius
      call profile_exponents(suba, raw(5:), ex(5:))
    case (CON_POINT_LINE)
      ex(1:4) = -1; ex(7) = -1
    case (CON_WELD)
      ex(1:4) = -1
    case (CON_GEAR)
      ex = -1; ex(4) = 0                             ! [R_i, R_j, phase, angle, centres]
    case (CON_RACK, CON_ROLLING)
      ex = -1; ex(5:6) = 0                           ! [c, p, u (a direction), R, phase]
    case (CON_ABSOLUTE)
      if (suba <= 2) ex = -1
    case (DRV_ABS)
      if (suba <= 2) call fun_exponents(raw, -1, ex)
    case (DRV_REL_DIST)
      call fun_exponents(raw, -1, ex)
    end select
    geom = ex == -1 .and. .not. con_is_driver(kind)
    if (kind == CON_GEAR) geom(3) = .false.          ! phases are not sizes
    if (kind == CON_RACK .or. kind == CON_ROLLING) geom(8) = .false.
  end subroutine con_exponents

  !> Length power of row r (1-based) of a constraint: Phi scales as L**power.
  pure integer function con_row_power(kind, suba, r)
    integer, intent(in) :: kind, suba, r   !! kind, first sub-kind, row
    select case (kind)
    case (CON_TRANSLATIONAL)
      con_row_power = merge(1, 0, r == 1)
    case (CON_DISTANCE)
      con_row_power = 2                              ! d . d - L**2
    case (CON_WELD)
      con_row_power = merge(1, 0, r <= 2)
    case (CON_ABSOLUTE, DRV_ABS)
      con_row_power = merge(1, 0, suba <= 2)
    case (DRV_REL_ANGLE)
      con_row_power = 0
    case default
      con_row_power = 1
    end select
  end function con_row_power

  !> Check raw parameters and build the prepared ones. ref: the prepared parameters of
  !! the translational joint a relative-distance driver refers to.
  subroutine con_prepare(kind, suba, subb, raw, ref, prep, status, msg)
    integer, intent(in) :: kind, suba, subb        !! kind and sub-kinds
    real(wp), intent(in) :: raw(:)                 !! raw parameters (exact length)
    real(wp), intent(in) :: ref(:)                 !! referenced joint (or empty)
    real(wp), allocatable, intent(out) :: prep(:)  !! prepared parameters
    integer, intent(out) :: status                 !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    status = MBD_OK; msg = ''
    if (.not. all(ieee_is_finite(raw))) then
      status = MBD_BAD_PARAM; msg = 'a parameter is not a finite number'; return
    end if
    select case (kind)
    case (CON_REVOLUTE)
      call revolute_prepare(raw, prep, status, msg)
    case (CON_TRANSLATIONAL)
      call translational_prepare(raw, prep, status, msg)
    case (CON_CAM)
      call cam_prepare(suba, subb, raw, prep, status, msg)
    case (CON_DISTANCE)
      call distance_prepare(raw, prep, status, msg)
    case (CON_POINT_LINE)
      call point_line_prepare(raw, prep, status, msg)
    case (CON_WELD)
      call weld_prepare(raw, prep, status, msg)
    case (CON_GEAR)
      call gear_prepare(subb, raw, prep, status, msg)
    case (CON_RACK, CON_ROLLING)
      call rolling_prepare(raw, prep, status, msg)
    case (CON_ABSOLUTE)
      prep = [1.0_wp, raw(1), 0.0_wp, 0.0_wp, 0.0_wp]   ! the constant f = value
    case (DRV_ABS, DRV_REL_ANGLE)
      call fun_check(raw, status, msg)
      if (status == MBD_OK) prep = raw
    case (DRV_REL_DIST)
      call fun_check(raw, status, msg)
      if (status == MBD_OK) prep = [ref, raw]
    case default
      status = MBD_BAD_INPUT; msg = 'unknown constraint kind'
    end select
  end subroutine con_prepare

  !> Rows of Phi, the local J block, nu and gamma.
  pure subroutine con_eval(kind, suba, subb, p, si, sj, x, t, phi, jl, nu, gam)
    integer, intent(in) :: kind, suba, subb  !! kind and sub-kinds
    real(wp), intent(in) :: p(:)             !! prepared parameters
    integer, intent(in) :: si, sj            !! slot ids of the two bodies (0 = ground)
    type(kloc), intent(in) :: x              !! local state
    real(wp), intent(in) :: t                !! time
    real(wp), intent(inout) :: phi(MAXROW)   !! rows of Phi (con_nrow of them written)
    real(wp), intent(inout) :: jl(MAXROW, NLOC)  !! local block of J (the same rows)
    real(wp), intent(inout) :: nu(MAXROW)    !! rows of nu
    real(wp), intent(inout) :: gam(MAXROW)   !! rows of gamma
    select case (kind)
    case (CON_REVOLUTE)
      call revolute_eval(p, si, sj, x, phi, jl, gam)
      nu(1:2) = 0.0_wp
    case (CON_TRANSLATIONAL)
      call translational_eval(p, si, sj, x, phi, jl, gam)
      nu(1:2) = 0.0_wp
    case (CON_CAM)
      call cam_eval(suba, subb, p, si, sj, x, phi, jl, gam)
      nu(1:2) = 0.0_wp
    case (CON_DISTANCE)
      call distance_eval(p, si, sj, x, phi, jl, gam)
      nu(1) = 0.0_wp
    case (CON_POINT_LINE)
      call point_line_eval(p, si, sj, x, phi, jl, gam)
      nu(1) = 0.0_wp
    case (CON_WELD)
      call weld_eval(p, si, sj, x, phi, jl, gam)
      nu(1:3) = 0.0_wp
    case (CON_GEAR)
      call gear_eval(subb, p, si, sj, x, phi, jl, gam)
      nu(1) = 0.0_wp
    case (CON_RACK)
      call rolling_eval(.false., p, si, sj, x, phi, jl, gam)
      nu(1) = 0.0_wp
    case (CON_ROLLING)
      call rolling_eval(.true., p, si, sj, x, phi, jl, gam)
      nu(1:2) = 0.0_wp
    case (CON_ABSOLUTE)
      call driver_eval(DRV_ABS, suba, p, si, sj, x, t, phi, jl, nu, gam)
    case default
      call driver_eval(kind, suba, p, si, sj, x, t, phi, jl, nu, gam)
    end select
  end subroutine con_eval

  !> Starting values of the extra coordinates in ql (slot 7), from the body slots.
  pure subroutine con_init_extra(kind, suba, subb, p, si, sj, ql)
    integer, intent(in) :: kind, suba, subb  !! kind and sub-kinds
    real(wp), intent(in) :: p(:)             !! prepared parameters
    integer, intent(in) :: si, sj            !! slot ids
    real(wp), intent(inout) :: ql(NLOC)      !! local coordinates
    if (kind == CON_CAM) ql(ALPHA_SLOT) = cam_init_alpha(suba, subb, p, si, sj, ql)
  end subroutine con_init_extra

  !> Phi is linear in q (J constant, gamma free of q): absolute constraints and drivers,
  !! relative-angle drivers. Their second derivatives in q vanish.
  pure logical function con_linear(kind)
    integer, intent(in) :: kind   !! kind code
    select case (kind)
    case (CON_ABSOLUTE, DRV_ABS, DRV_REL_ANGLE)
      con_linear = .true.
    case default
      con_linear = .false.
    end select
  end function con_linear

  !> Phi is affine in the body positions r_i, r_j, so no second derivative involves a
  !! position slot: points compared (revolute, weld: r_i + A_i s'_i - r_j - A_j s'_j), or a
  !! line fixed in ground (translational, point on line with body i ground: h . (P_j - P_i)
  !! with a constant h).
  pure logical function con_affine_r(kind, bi)
    integer, intent(in) :: kind   !! kind code
    integer, intent(in) :: bi     !! first body (0 ground)
    con_affine_r = kind == CON_REVOLUTE .or. kind == CON_WELD .or. con_linear(kind) .or. &
                   ((kind == CON_TRANSLATIONAL .or. kind == CON_POINT_LINE) .and. bi == 0)
  end function con_affine_r

  !> True when raw entry j of a constraint is a count (a function's or a profile's), which
  !! no derivative can be taken with respect to.
  pure logical function con_is_count(kind, suba, raw, j)
    integer, intent(in) :: kind, suba  !! kind and first sub-kind
    real(wp), intent(in) :: raw(:)     !! raw parameters
    integer, intent(in) :: j           !! raw entry
    select case (kind)
    case (CON_CAM)
      con_is_count = cam_is_count(suba, j)
    case (DRV_ABS, DRV_REL_ANGLE, DRV_REL_DIST)
      con_is_count = fun_is_count(raw, j)
    case default
      con_is_count = .false.
    end select
  end function con_is_count

  !> Change tprep of the prepared parameters when raw(j) changes by one (the derivative of
  !! con_prepare; j must not be a count). A relative-distance driver's own entries come after
  !! the TRANS_PREP_LEN prepared entries of its joint (whose changes mbd_sensitivity adds).
  subroutine con_prepare_d(kind, suba, subb, raw, j, tprep, status, msg)
    integer, intent(in) :: kind, suba, subb        !! kind and sub-kinds
    real(wp), intent(in) :: raw(:)                 !! raw parameters (exact length)
    integer, intent(in) :: j                       !! raw entry
    real(wp), allocatable, intent(out) :: tprep(:) !! change of the prepared parameters
    integer, intent(out) :: status                 !! MBD_OK or the failure
    character(len=MSG_LEN), intent(out) :: msg     !! what went wrong
    integer :: n
    status = MBD_OK; msg = ''
    select case (kind)
    case (CON_CAM)
      call cam_prepare_d(suba, subb, raw, j, tprep, status, msg)
      return
    case (CON_TRANSLATIONAL); n = 9
    case (CON_GEAR); n = 12
    case (CON_POINT_LINE); n = 7
    case (CON_RACK, CON_ROLLING); n = 8
    case (CON_ABSOLUTE); n = 5
    case (DRV_REL_DIST); n = TRANS_PREP_LEN + size(raw)
    case default; n = size(raw)
    end select
    allocate (tprep(n), stat=status)
    if (status /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory'; return
    end if
    tprep = 0.0_wp
    select case (kind)
    case (CON_TRANSLATIONAL)
      call translational_prepare_d(raw, j, tprep)
    case (CON_GEAR)
      call gear_prepare_d(subb, raw, j, tprep)
    case (CON_POINT_LINE)
      call point_line_prepare_d(raw, j, tprep)
    case (CON_RACK, CON_ROLLING)
      call rolling_prepare_d(raw, j, tprep)
    case (CON_ABSOLUTE)
      tprep(2) = 1.0_wp                   ! prepared [1, value, 0, 0, 0]: the constant
    case (DRV_REL_DIST)
      tprep(TRANS_PREP_LEN + j) = 1.0_wp
    case default
      tprep(j) = 1.0_wp
    end select
  end subroutine con_prepare_d

  !> Changes of the rows of Phi, the local J block, nu and gamma along the direction in x
  !! and the change tp of the prepared parameters (mbd_dual).
  pure subroutine con_eval_d(kind, suba, subb, p, tp, si, sj, x, t, tphi, tjl, tnu, tgam)
    integer, intent(in) :: kind, suba, subb  !! kind and sub-kinds
    real(wp), intent(in) :: p(:), tp(:)      !! prepared parameters and their change
    integer, intent(in) :: si, sj            !! slot ids of the two bodies (0 = ground)
    type(dloc), intent(in) :: x              !! local state and direction
    real(wp), intent(in) :: t                !! time
    real(wp), intent(inout) :: tphi(MAXROW)  !! changes of the rows of Phi
    real(wp), intent(inout) :: tjl(MAXROW, NLOC)  !! change of the local block of J
    real(wp), intent(inout) :: tnu(MAXROW)   !! changes of the rows of nu
    real(wp), intent(inout) :: tgam(MAXROW)  !! changes of the rows of gamma
    tnu = 0.0_wp
    select case (kind)
    case (CON_REVOLUTE)
      call revolute_eval_d(p, tp, si, sj, x, tphi, tjl, tgam)
    case (CON_TRANSLATIONAL)
      call translational_eval_d(p, tp, si, sj, x, tphi, tjl, tgam)
    case (CON_CAM)
      call cam_eval_d(suba, subb, p, tp, si, sj, x, tphi, tjl, tgam)
    case (CON_DISTANCE)
      call distance_eval_d(p, tp, si, sj, x, tphi, tjl, tgam)
    case (CON_POINT_LINE)
      call point_line_eval_d(p, tp, si, sj, x, tphi, tjl, tgam)
    case (CON_WELD)
      call weld_eval_d(p, tp, si, sj, x, tphi, tjl, tgam)
    case (CON_GEAR)
      call gear_eval_d(subb, p, tp, si, sj, x, tphi, tjl, tgam)
    case (CON_RACK)
      call rolling_eval_d(.false., p, tp, si, sj, x, tphi, tjl, tgam)
    case (CON_ROLLING)
      call rolling_eval_d(.true., p, tp, si, sj, x, tphi, tjl, tgam)
    case (CON_ABSOLUTE)
      call driver_eval_d(DRV_ABS, suba, p, tp, si, sj, x, t, tphi, tjl, tnu, tgam)
    case default
      call driver_eval_d(kind, suba, p, tp, si, sj, x, t, tphi, tjl, tnu, tgam)
    end select
  end subroutine con_eval_d

end module mbd_constraints
