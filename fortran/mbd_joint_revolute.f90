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
  public :: revolute_prepare, revolute_eval, revolute_eval_d, revolute_rows, &
            revolute_gamma

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

  !> The same rows as revolute_eval straight from the bodies' states (the assembly's path
  !! for the commonest joint: no local state gathered, no assumed-shape arguments). Body b
  !! (0 ground) has q(3b-2:3b) and q_dot(3b-2:3b), cos and sin c(b), s(b); ground's point
  !! p(1:2) or p(3:4) is global.
  !! Phi = P_i - P_j, J = [I, B_i s'_i, -I, -B_j s'_j], gamma = A_i s'_i thd_i**2 - A_j s'_j thd_j**2.
  pure subroutine revolute_rows(p, bi, bj, q, qd, c, s, phi, jl, gam)
    real(wp), intent(in) :: p(4)            !! [s'_i, s'_j]
    integer, intent(in) :: bi, bj           !! bodies (0 ground)
    real(wp), intent(in) :: q(0:*), qd(0:*) !! coordinates and velocities (q(0) unused)
    real(wp), intent(in) :: c(0:*), s(0:*)  !! cos and sin of the bodies' angles
    real(wp), intent(out) :: phi(2)         !! rows of Phi
    real(wp), intent(inout) :: jl(MAXROW, NLOC)  !! local block of J (rows 1 and 2 written)
    real(wp), intent(out) :: gam(2)         !! rows of gamma
    real(wp) :: ax, ay, w2, px, py
    integer :: i3
    ! the operations of revolute_eval in its order (P_i - P_j, aj - ai): the same rounding
    jl(1:2, :) = zero
    if (bi > 0) then
      i3 = 3 * bi
      ax = c(bi) * p(1) - s(bi) * p(2); ay = s(bi) * p(1) + c(bi) * p(2)     ! A_i s'_i
      w2 = qd(i3)**2
      phi(1) = q(i3 - 2) + ax; phi(2) = q(i3 - 1) + ay
      gam(1) = ax * w2; gam(2) = ay * w2
      jl(1, 1) = one; jl(2, 2) = one; jl(1, 3) = -ay; jl(2, 3) = ax        ! [I, B_i s'_i]
    else
      phi(1) = p(1); phi(2) = p(2); gam(1) = zero; gam(2) = zero
    end if
    if (bj > 0) then
      i3 = 3 * bj
      ax = c(bj) * p(3) - s(bj) * p(4); ay = s(bj) * p(3) + c(bj) * p(4)     ! A_j s'_j
      w2 = qd(i3)**2
      px = q(i3 - 2) + ax; py = q(i3 - 1) + ay
      phi(1) = phi(1) - px; phi(2) = phi(2) - py
      gam(1) = gam(1) - ax * w2; gam(2) = gam(2) - ay * w2
      jl(1, 4) = -one; jl(2, 5) = -one; jl(1, 6) = ay; jl(2, 6) = -ax      ! [-I, -B_j s'_j]
    else
      phi(1) = phi(1) - p(3); phi(2) = phi(2) - p(4)
    end if
  end subroutine revolute_rows

  !> gamma of the revolute alone (the velocities changed, q did not):
  !! gamma = A_i s'_i thd_i**2 - A_j s'_j thd_j**2.
  pure subroutine revolute_gamma(p, bi, bj, qd, c, s, gam)
    real(wp), intent(in) :: p(4)            !! [s'_i, s'_j]
    integer, intent(in) :: bi, bj           !! bodies (0 ground)
    real(wp), intent(in) :: qd(0:*)         !! velocities
    real(wp), intent(in) :: c(0:*), s(0:*)  !! cos and sin of the bodies' angles
    real(wp), intent(out) :: gam(2)         !! rows of gamma
    real(wp) :: w2
    gam(1) = zero; gam(2) = zero
    if (bi > 0) then
      w2 = qd(3 * bi)**2
      gam(1) = (c(bi) * p(1) - s(bi) * p(2)) * w2; gam(2) = (s(bi) * p(1) + c(bi) * p(2)) * w2
    end if
    if (bj > 0) then
      w2 = qd(3 * bj)**2
      gam(1) = gam(1) - (c(bj) * p(3) - s(bj) * p(4)) * w2
      gam(2) = gam(2) - (s(bj) * p(3) + c(bj) * p(4)) * w2
    end if
  end subroutine revolute_gamma

end module mbd_joint_revolute
