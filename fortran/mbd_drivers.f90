!> mbd_drivers: driving constraints Phi^D(q, t) = g(q) - f(t) = 0.
!!
!! nu = -Phi_t = f'(t);  gamma = -(ar of g) + f''(t).
!!   absolute           g = x, y or theta of one body             (sub-kind 1, 2, 3)
!!   relative-angle     g = theta_j - theta_i
!!   relative-distance  g = (P_j - P_i) . A_i u'_i, the slide along a translational joint
!! Raw parameters: the encoded function (mbd_functions); the distance driver is prepared
!! with the joint's prepared parameters in front: [joint prep(9), function].
module mbd_drivers
  use mbd_kinds, only: wp
  use mbd_points, only: NLOC, MAXROW, kloc, kscal, body_angle, ssub, put_scal
  use mbd_functions, only: fun_eval, fun_eval_d
  use mbd_joint_translational, only: slide_distance, slide_distance_d
  use mbd_dual, only: dloc, dscal, slot_value, body_angle, ssub, put_scal
  implicit none
  private
  public :: DRV_ABS, DRV_REL_ANGLE, DRV_REL_DIST, TRANS_PREP_LEN
  public :: driver_eval, driver_eval_d, driver_abs_row

  integer, parameter :: DRV_ABS = 101, DRV_REL_ANGLE = 102, DRV_REL_DIST = 103
  integer, parameter :: TRANS_PREP_LEN = 9   !! length of a prepared translational joint

contains

  !> Row of Phi, J (local block), nu and gamma of a driver.
  pure subroutine driver_eval(kind, sub, p, si, sj, x, t, phi, jl, nu, gam)
    integer, intent(in) :: kind, sub        !! driver kind; absolute: coordinate 1..3
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of the bodies
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(in) :: t               !! time
    real(wp), intent(inout) :: phi(MAXROW)  !! rows of Phi (the first written)
    real(wp), intent(inout) :: jl(MAXROW, NLOC)  !! local block of J (row 1 written)
    real(wp), intent(inout) :: nu(MAXROW)   !! rows of nu
    real(wp), intent(inout) :: gam(MAXROW)  !! rows of gamma
    type(kscal) :: g
    real(wp) :: f, f1, f2
    select case (kind)
    case (DRV_ABS)
      g%v = x%q(sub); g%d(sub) = 1.0_wp; g%vd = x%qd(sub)
      call fun_eval(p, t, f, f1, f2)
    case (DRV_REL_ANGLE)
      g = ssub(body_angle(x, sj), body_angle(x, si))
      call fun_eval(p, t, f, f1, f2)
    case default  ! DRV_REL_DIST
      g = slide_distance(p(1:TRANS_PREP_LEN), si, sj, x)
      call fun_eval(p(TRANS_PREP_LEN + 1:), t, f, f1, f2)
    end select
    call put_scal(g, phi(1), jl(1, :), gam(1))
    phi(1) = phi(1) - f
    nu(1) = f1
    gam(1) = gam(1) + f2
  end subroutine driver_eval

  !> Changes of the driver's row along a direction and a change tp of its parameters
  !! (mbd_dual): Phi = g - f, nu = f', gamma = -ar_g + f'' with the function's changes
  !! from fun_eval_d.
  pure subroutine driver_eval_d(kind, sub, p, tp, si, sj, x, t, tphi, tjl, tnu, tgam)
    integer, intent(in) :: kind, sub        !! driver kind; absolute: coordinate 1..3
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of the bodies
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(in) :: t               !! time
    real(wp), intent(inout) :: tphi(MAXROW), tjl(MAXROW, NLOC)  !! changes (row 1)
    real(wp), intent(inout) :: tnu(MAXROW), tgam(MAXROW)        !! changes (row 1)
    type(dscal) :: g
    real(wp) :: tf, tf1, tf2
    select case (kind)
    case (DRV_ABS)
      g = slot_value(x, sub)
      call fun_eval_d(p, tp, t, tf, tf1, tf2)
    case (DRV_REL_ANGLE)
      g = ssub(body_angle(x, sj), body_angle(x, si))
      call fun_eval_d(p, tp, t, tf, tf1, tf2)
    case default  ! DRV_REL_DIST
      g = slide_distance_d(p(1:TRANS_PREP_LEN), tp(1:TRANS_PREP_LEN), si, sj, x)
      call fun_eval_d(p(TRANS_PREP_LEN + 1:), tp(TRANS_PREP_LEN + 1:), t, tf, tf1, tf2)
    end select
    call put_scal(g, tphi(1), tjl(1, :), tgam(1))
    tphi(1) = tphi(1) - tf
    tnu(1) = tf1
    tgam(1) = tgam(1) + tf2
  end subroutine driver_eval_d

  !> The absolute driver's row straight from its coordinate (the assembly's path; the row
  !! driver_eval writes for DRV_ABS, in the same operations): Phi = q_c - f(t), J = e_sub
  !! (slot sub of the body), nu = f'(t), gamma = f''(t).
  pure subroutine driver_abs_row(sub, p, qc, t, phi, jl, nu, gam)
    integer, intent(in) :: sub              !! coordinate slot 1, 2, 3 (x, y, theta)
    real(wp), intent(in) :: p(:)            !! the encoded function
    real(wp), intent(in) :: qc, t           !! the coordinate's value, time
    real(wp), intent(out) :: phi, nu, gam   !! the row of Phi, nu, gamma
    real(wp), intent(inout) :: jl(MAXROW, NLOC)  !! local block of J (row 1 written)
    real(wp) :: f, f1, f2
    call fun_eval(p, t, f, f1, f2)
    jl(1, :) = 0.0_wp; jl(1, sub) = 1.0_wp
    phi = qc - f; nu = f1; gam = f2
  end subroutine driver_abs_row

end module mbd_drivers
