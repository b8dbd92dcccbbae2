!> mbd_joint_gear: a gear pair whose centres are carried by one body (ground or a carrier c).
!!
!! Rolling of the pitch circles, with the line of centres fixed in the carrier:
!!   external  Phi = R_i (theta_i - theta_c) + R_j (theta_j - theta_c) - phase = 0
!!   internal  Phi = R_i (theta_i - theta_c) - R_j (theta_j - theta_c) - phase = 0   (j: ring)
!! (Haug 3.5; linear in q, so J is constant and gamma = 0.) The carrier angle sits in local
!! slot 7; with ground as carrier the slot maps to nothing and theta_c = 0.
!! The gear centres are held by the joints of each gear to the carrier.
!! Raw parameters: [R_i, R_j, phase]; sub-kinds: a = carrier body (0 ground), b = 1 external,
!! 2 internal.
module mbd_joint_gear
  use mbd_kinds, only: wp, zero
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, kloc, kscal, body_angle, slot_value, ssub, sadd, sscale, &
                        sconst, put_scal
  use mbd_dual, only: dloc, dscal, body_angle, slot_value, ssub, sadd, sscale, sconst, put_scal
  implicit none
  private
  public :: GEAR_EXTERNAL, GEAR_INTERNAL, CARRIER_SLOT, gear_prepare, gear_eval, gear_eval_d

  integer, parameter :: GEAR_EXTERNAL = 1, GEAR_INTERNAL = 2
  integer, parameter :: CARRIER_SLOT = 7

contains

  !> Check the radii.
  subroutine gear_prepare(kind, raw, prep, status, msg)
    integer, intent(in) :: kind                    !! GEAR_EXTERNAL or GEAR_INTERNAL
    real(wp), intent(in) :: raw(:)                 !! [R_i, R_j, phase]
    real(wp), allocatable, intent(out) :: prep(:)  !! same
    integer, intent(out) :: status                 !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    status = MBD_OK; msg = ''
    if (.not. (raw(1) > zero .and. raw(2) > zero)) then
      status = MBD_BAD_PARAM; msg = 'gear pitch radii must be positive'; return
    end if
    if (kind /= GEAR_EXTERNAL .and. kind /= GEAR_INTERNAL) then
      status = MBD_BAD_PARAM; msg = 'gear kind must be 1 (external) or 2 (internal)'; return
    end if
    if (kind == GEAR_INTERNAL .and. .not. (raw(2) > raw(1))) then
      status = MBD_BAD_PARAM
      msg = 'an internal gear (ring, second body) needs a larger radius than its pinion'
      return
    end if
    prep = raw(1:3)
  end subroutine gear_prepare

  !> Row of Phi, J (local block) and gamma.
  pure subroutine gear_eval(kind, p, si, sj, x, phi, jl, gam)
    integer, intent(in) :: kind             !! GEAR_EXTERNAL or GEAR_INTERNAL
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the gears
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(inout) :: phi(MAXROW), jl(MAXROW, NLOC), gam(MAXROW)  !! 1 row written
    type(kscal) :: ai, aj, c
    real(wp) :: sgn
    c = slot_value(x, CARRIER_SLOT)
    ai = ssub(body_angle(x, si), c)
    aj = ssub(body_angle(x, sj), c)
    sgn = 1.0_wp
    if (kind == GEAR_INTERNAL) sgn = -1.0_wp
    call put_scal(ssub(sadd(sscale(p(1), ai), sscale(sgn * p(2), aj)), sconst(p(3))), &
                  phi(1), jl(1, :), gam(1))
  end subroutine gear_eval

  !> Change of the row along a direction and a parameter change tp (mbd_dual).
  pure subroutine gear_eval_d(kind, p, tp, si, sj, x, tphi, tjl, tgam)
    integer, intent(in) :: kind             !! GEAR_EXTERNAL or GEAR_INTERNAL
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the gears
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(inout) :: tphi(MAXROW), tjl(MAXROW, NLOC), tgam(MAXROW)  !! 1 row
    type(dscal) :: ai, aj, c
    real(wp) :: sgn
    c = slot_value(x, CARRIER_SLOT)
    ai = ssub(body_angle(x, si), c)
    aj = ssub(body_angle(x, sj), c)
    sgn = 1.0_wp
    if (kind == GEAR_INTERNAL) sgn = -1.0_wp
    call put_scal(ssub(sadd(sscale(p(1), tp(1), ai), sscale(sgn * p(2), sgn * tp(2), aj)), &
                       sconst(p(3), tp(3))), tphi(1), tjl(1, :), tgam(1))
  end subroutine gear_eval_d

end module mbd_joint_gear
