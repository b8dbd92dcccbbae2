!> mbd_joint_revolute: the revolute (pin) joint.
!!
!! Phi = r_i + A_i s'_i - r_j - A_j s'_j = 0                       (2 rows)
!! J   = [I, B_i s'_i, -I, -B_j s'_j]
!! gamma = A_i s'_i thd_i**2 - A_j s'_j thd_j**2                    (Haug 3.3; the seed lesson)
!! Raw parameters: [s'_i(2), s'_j(2)] (a ground point is global).
module mbd_joint_revolute
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, kloc, point_terms
  use mbd_dual, only: dloc, point_terms_d
  implicit none
  private
  public :: revolute_prepare, revolute_eval, revolute_eval_d

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

  !> Rows of Phi, J (local block) and gamma, from the two points' terms.
  pure subroutine revolute_eval(p, si, sj, x, phi, jl, gam)
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the two bodies (0 = ground)
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(inout) :: phi(MAXROW)  !! rows of Phi (2 written)
    real(wp), intent(inout) :: jl(MAXROW, NLOC)  !! local block of J (2 rows written)
    real(wp), intent(inout) :: gam(MAXROW)  !! rows of gamma (2 written)
    real(wp) :: pi(2), bi(2), vi(2), ai(2), pj(2), bj(2), vj(2), aj(2)
    integer :: c
    call point_terms(x, si, p(1:2), pi, bi, vi, ai)
    call point_terms(x, sj, p(3:4), pj, bj, vj, aj)
    phi(1:2) = pi - pj                                 ! Phi = P_i - P_j
    jl(1:2, :) = zero                                  ! J = [I, B_i s'_i, -I, -B_j s'_j]
    if (si > 0) then
      c = 3 * (si - 1)
      jl(1, c + 1) = one; jl(2, c + 2) = one; jl(1:2, c + 3) = bi
    end if
    if (sj > 0) then
      c = 3 * (sj - 1)
      jl(1, c + 1) = -one; jl(2, c + 2) = -one; jl(1:2, c + 3) = -bj
    end if
    gam(1:2) = aj - ai                      ! gamma = A_i s'_i thd_i**2 - A_j s'_j thd_j**2
  end subroutine revolute_eval

  !> Changes of the rows of Phi, J and gamma along a direction (x) and a change tp of the
  !! parameters (mbd_dual), from the two points' terms and their changes:
  !! dPhi = dP_i - dP_j, dJ = [0, d(B_i s'_i), 0, -d(B_j s'_j)], dgamma = d(ar_j) - d(ar_i).
  pure subroutine revolute_eval_d(p, tp, si, sj, x, tphi, tjl, tgam)
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the two bodies (0 = ground)
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(inout) :: tphi(MAXROW), tjl(MAXROW, NLOC), tgam(MAXROW)  !! 2 rows
    real(wp) :: pi(2), bi(2), ai(2), pj(2), bj(2), aj(2), tpi(2), tbi(2), tai(2), tpj(2), &
                tbj(2), taj(2)
    call point_terms_d(x, si, p(1:2), tp(1:2), pi, bi, ai, tpi, tbi, tai)
    call point_terms_d(x, sj, p(3:4), tp(3:4), pj, bj, aj, tpj, tbj, taj)
    tphi(1:2) = tpi - tpj
    tjl(1:2, :) = zero
    if (si > 0) tjl(1:2, 3) = tbi
    if (sj > 0) tjl(1:2, 6) = -tbj
    tgam(1:2) = taj - tai
  end subroutine revolute_eval_d

end module mbd_joint_revolute
