!> mbd_joint_weld: the weld (fixed) joint.
!!
!! Phi_1,2 = P_i - P_j = 0                    the points coincide (as the revolute joint)
!! Phi_3   = theta_j - theta_i - phi0 = 0      the relative angle is fixed      (3 rows)
!! Raw parameters: [s'_i(2), s'_j(2), phi0].
module mbd_joint_weld
  use mbd_kinds, only: wp
  use mbd_status, only: MBD_OK, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, kloc, body_angle, ssub, sconst, put_scal
  use mbd_joint_revolute, only: revolute_eval, revolute_eval_d
  use mbd_dual, only: dloc, body_angle, ssub, sconst, put_scal
  implicit none
  private
  public :: weld_prepare, weld_eval, weld_eval_d

contains

  !> Copy the parameters.
  subroutine weld_prepare(raw, prep, status, msg)
    real(wp), intent(in) :: raw(:)                 !! [s'_i, s'_j, phi0]
    real(wp), allocatable, intent(out) :: prep(:)  !! same
    integer, intent(out) :: status                 !! MBD_OK
    character(len=MSG_LEN), intent(out) :: msg     !! empty
    status = MBD_OK; msg = ''
    prep = raw(1:5)
  end subroutine weld_prepare

  !> Rows of Phi, J (local block) and gamma.
  pure subroutine weld_eval(p, si, sj, x, phi, jl, gam)
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(inout) :: phi(MAXROW), jl(MAXROW, NLOC), gam(MAXROW)  !! 3 rows written
    call revolute_eval(p(1:4), si, sj, x, phi, jl, gam)
    call put_scal(ssub(ssub(body_angle(x, sj), body_angle(x, si)), sconst(p(5))), &
                  phi(3), jl(3, :), gam(3))
  end subroutine weld_eval

  !> Changes of the rows along a direction and a parameter change tp (mbd_dual).
  pure subroutine weld_eval_d(p, tp, si, sj, x, tphi, tjl, tgam)
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(inout) :: tphi(MAXROW), tjl(MAXROW, NLOC), tgam(MAXROW)  !! 3 rows
    call revolute_eval_d(p(1:4), tp(1:4), si, sj, x, tphi, tjl, tgam)
    call put_scal(ssub(ssub(body_angle(x, sj), body_angle(x, si)), sconst(p(5), tp(5))), &
                  tphi(3), tjl(3, :), tgam(3))
  end subroutine weld_eval_d

end module mbd_joint_weld
