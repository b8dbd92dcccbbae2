!> mbd_joint_distance: the distance (revolute-revolute composite) constraint.
!!
!! d = P_j - P_i,   Phi = d . d - L**2 = 0                          (1 row)
!! J = 2 d^T (J_Pj - J_Pi),  gamma = -(2 d . ar_d + 2 d_dot . d_dot)   (Haug 3.4.1)
!! Raw parameters: [s'_i(2), s'_j(2), L], L > 0.
module mbd_joint_distance
  use mbd_kinds, only: wp, zero
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, kloc, kvec, body_point, vsub, vdot, sconst, ssub, put_scal
  use mbd_dual, only: dloc, dvec, body_point, vsub, vdot, sconst, ssub, put_scal
  implicit none
  private
  public :: distance_prepare, distance_eval, distance_eval_d

contains

  !> Check L > 0.
  subroutine distance_prepare(raw, prep, status, msg)
    real(wp), intent(in) :: raw(:)                 !! [s'_i, s'_j, L]
    real(wp), allocatable, intent(out) :: prep(:)  !! same
    integer, intent(out) :: status                 !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    status = MBD_OK; msg = ''
    if (.not. (raw(5) > zero)) then
      status = MBD_BAD_PARAM; msg = 'distance must be positive'; return
    end if
    prep = raw(1:5)
  end subroutine distance_prepare

  !> Row of Phi, J (local block) and gamma.
  pure subroutine distance_eval(p, si, sj, x, phi, jl, gam)
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the two bodies (0 = ground)
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(inout) :: phi(MAXROW), jl(MAXROW, NLOC), gam(MAXROW)  !! 1 row written
    type(kvec) :: d
    d = vsub(body_point(x, sj, p(3:4)), body_point(x, si, p(1:2)))
    call put_scal(ssub(vdot(d, d), sconst(p(5)**2)), phi(1), jl(1, :), gam(1))
  end subroutine distance_eval

  !> Change of the row along a direction and a parameter change tp (mbd_dual).
  pure subroutine distance_eval_d(p, tp, si, sj, x, tphi, tjl, tgam)
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the two bodies (0 = ground)
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(inout) :: tphi(MAXROW), tjl(MAXROW, NLOC), tgam(MAXROW)  !! 1 row
    type(dvec) :: d
    d = vsub(body_point(x, sj, p(3:4), tp(3:4)), body_point(x, si, p(1:2), tp(1:2)))
    call put_scal(ssub(vdot(d, d), sconst(p(5)**2, 2 * p(5) * tp(5))), tphi(1), tjl(1, :), &
                  tgam(1))
  end subroutine distance_eval_d

end module mbd_joint_distance
