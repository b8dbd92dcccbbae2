!> mbd_joint_revolute: the revolute (pin) joint.
!!
!! Phi = r_i + A_i s'_i - r_j - A_j s'_j = 0                       (2 rows)
!! J   = [I, B_i s'_i, -I, -B_j s'_j]
!! gamma = A_i s'_i thd_i**2 - A_j s'_j thd_j**2                    (Haug 3.3; the seed lesson)
!! Raw parameters: [s'_i(2), s'_j(2)] (a ground point is global).
module mbd_joint_revolute
  use mbd_kinds, only: wp
  use mbd_status, only: MBD_OK, MSG_LEN
  use mbd_points, only: NLOC, kvec, body_point, vsub, put_vec
  implicit none
  private
  public :: revolute_prepare, revolute_eval

contains

  !> Check and copy the parameters.
  subroutine revolute_prepare(raw, prep, status, msg)
    real(wp), intent(in) :: raw(:)                 !! [s'_i, s'_j]
    real(wp), allocatable, intent(out) :: prep(:)  !! same
    integer, intent(out) :: status                 !! MBD_OK
    character(len=MSG_LEN), intent(out) :: msg     !! empty
    status = MBD_OK; msg = ''
    prep = raw(1:4)
  end subroutine revolute_prepare

  !> Rows of Phi, J (local block) and gamma.
  pure subroutine revolute_eval(p, si, sj, ql, qdl, phi, jl, gam)
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the two bodies (0 = ground)
    real(wp), intent(in) :: ql(NLOC)        !! local coordinates
    real(wp), intent(in) :: qdl(NLOC)       !! local velocities
    real(wp), intent(inout) :: phi(:)       !! 2 rows of Phi
    real(wp), intent(inout) :: jl(:, :)     !! 2 x NLOC block of J
    real(wp), intent(inout) :: gam(:)       !! 2 rows of gamma
    call put_vec(vsub(body_point(ql, qdl, si, p(1:2)), body_point(ql, qdl, sj, p(3:4))), &
                 phi, jl, gam)
  end subroutine revolute_eval

end module mbd_joint_revolute
