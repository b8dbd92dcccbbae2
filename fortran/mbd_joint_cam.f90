!> mbd_joint_cam: a cam profile c(alpha) on body i in contact with a follower on body j.
!!
!! The contact parameter alpha is an extra coordinate (local slot 7).
!! Point (knife-edge) and roller followers: the follower point F = r_j + A_j f' stays on the
!! profile offset by the roller radius rho along the outward normal n(alpha):
!!   Phi = r_i + A_i (c + rho n)(alpha) - r_j - A_j f' = 0                       (2 rows)
!! Flat-faced follower, face through f' with normal m' (pointing toward the cam):
!!   Phi_1 = (A_j m') . (r_i + A_i c(alpha) - r_j - A_j f') = 0   contact point on the face
!!   Phi_2 = (A_j m') . (A_i c'(alpha)) = 0                        profile tangent along the face
!! J and gamma come from the product rule on curve points (mbd_points).
!! Raw parameters: [follower(4), profile raw...]; follower = point [fx, fy, 0, 0],
!! roller [fx, fy, rho, 0], flat [fx, fy, mx, my]. Sub-kinds: profile kind, follower kind.
module mbd_joint_cam
  use mbd_kinds, only: wp, zero, two, pi
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MBD_NO_MEMORY, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, kloc, local_state, kvec, body_point, body_vector, &
                        curve_point, curve_vector, vsub, vdot, put_vec, put_scal
  use mbd_profiles, only: profile_raw_length, profile_prepare, profile_eval, profile_normal, &
                          profile_check, profile_c4, profile_normal3, profile_eval_d, &
                          profile_normal_d, profile_prepare_d, profile_is_count
  use mbd_dual, only: dloc, dvec, body_point, body_vector, curve_point, curve_vector, vsub, &
                      vdot, put_vec, put_scal
  implicit none
  private
  public :: FOL_POINT, FOL_ROLLER, FOL_FLAT, ALPHA_SLOT
  public :: cam_raw_length, cam_prepare, cam_eval, cam_init_alpha, cam_outward_normal
  public :: cam_prepare_d, cam_eval_d, cam_is_count

  integer, parameter :: FOL_POINT = 1, FOL_ROLLER = 2, FOL_FLAT = 3
  integer, parameter :: ALPHA_SLOT = 7
  integer, parameter :: NSAMPLE = 720   !! samples of alpha for the starting estimate

contains

  !> Number of raw parameters, or -1 when malformed.
  pure integer function cam_raw_length(prof, raw)
    integer, intent(in) :: prof      !! profile kind
    real(wp), intent(in) :: raw(:)   !! raw parameters
    integer :: n
    cam_raw_length = -1
    if (size(raw) < 5) return
    n = profile_raw_length(prof, raw(5:))
    if (n > 0) cam_raw_length = 4 + n
  end function cam_raw_length

  !> Check the follower, prepare the profile, check the contact curve.
  subroutine cam_prepare(prof, fol, raw, prep, status, msg)
    integer, intent(in) :: prof, fol               !! profile and follower kinds
    real(wp), intent(in) :: raw(:)                 !! raw parameters (exact length)
    real(wp), allocatable, intent(out) :: prep(:)  !! prepared parameters
    integer, intent(out) :: status                 !! MBD_OK or MBD_BAD_PARAM
    character(len=MSG_LEN), intent(out) :: msg     !! what is wrong
    real(wp), allocatable :: pp(:)
    real(wp) :: f(4), nm
    status = MBD_OK; msg = ''
    f = raw(1:4)
    select case (fol)
    case (FOL_POINT)
      f(3:4) = zero
    case (FOL_ROLLER)
      if (.not. (f(3) > zero)) then
        status = MBD_BAD_PARAM; msg = 'roller follower radius must be positive'; return
      end if
    case (FOL_FLAT)
      nm = hypot(f(3), f(4))
      if (.not. (nm > zero)) then
        status = MBD_BAD_PARAM; msg = 'flat follower normal has zero length'; return
      end if
      f(3:4) = f(3:4) / nm
    case default
      status = MBD_BAD_PARAM; msg = 'unknown follower kind'; return
    end select
    call profile_prepare(prof, raw(5:), pp, status, msg)
    if (status /= MBD_OK) return
    call profile_check(prof, pp, zero, status, msg)
    if (status /= MBD_OK) return
    if (fol == FOL_ROLLER) then
      call profile_check(prof, pp, f(3), status, msg)
      if (status /= MBD_OK) return
    end if
    prep = [f, pp]
  end subroutine cam_prepare

  !> Contact curve point and its alpha derivatives (profile offset by the roller radius).
  pure subroutine contact_curve(prof, fol, p, alpha, d0, d1, d2, c3)
    integer, intent(in) :: prof, fol
    real(wp), intent(in) :: p(:), alpha
    real(wp), intent(out) :: d0(2), d1(2), d2(2), c3(2)
    real(wp) :: n0(2), n1(2), n2(2)
    call profile_eval(prof, p(5:), alpha, d0, d1, d2, c3)
    if (fol == FOL_ROLLER) then
      call profile_normal(d1, d2, c3, n0, n1, n2)
      d0 = d0 + p(3) * n0; d1 = d1 + p(3) * n1; d2 = d2 + p(3) * n2
    end if
  end subroutine contact_curve

  !> Rows of Phi, J (local block) and gamma.
  pure subroutine cam_eval(prof, fol, p, si, sj, x, phi, jl, gam)
    integer, intent(in) :: prof, fol        !! profile and follower kinds
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids of cam and follower bodies
    type(kloc), intent(in) :: x             !! local state
    real(wp), intent(inout) :: phi(MAXROW)  !! rows of Phi (2 written)
    real(wp), intent(inout) :: jl(MAXROW, NLOC)  !! local block of J (2 rows written)
    real(wp), intent(inout) :: gam(MAXROW)  !! rows of gamma (2 written)
    real(wp) :: c0(2), c1(2), c2(2), c3(2)
    type(kvec) :: cp, m
    call contact_curve(prof, fol, p, x%q(ALPHA_SLOT), c0, c1, c2, c3)
    cp = curve_point(x, si, ALPHA_SLOT, c0, c1, c2)
    if (fol == FOL_FLAT) then
      m = body_vector(x, sj, p(3:4))
      call put_scal(vdot(m, vsub(cp, body_point(x, sj, p(1:2)))), phi(1), jl(1, :), gam(1))
      call put_scal(vdot(m, curve_vector(x, si, ALPHA_SLOT, c1, c2, c3)), &
                    phi(2), jl(2, :), gam(2))
    else
      call put_vec(vsub(cp, body_point(x, sj, p(1:2))), phi, jl, gam)
    end if
  end subroutine cam_eval

  !> Starting estimate of alpha at the local coordinates ql (slot 7 ignored):
  !! the nearest contact-curve point to the follower point, or for a flat face the
  !! profile point deepest along -m (where the outward normal is -m).
  pure real(wp) function cam_init_alpha(prof, fol, p, si, sj, ql) result(alpha)
    integer, intent(in) :: prof, fol        !! profile and follower kinds
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids
    real(wp), intent(in) :: ql(NLOC)        !! local coordinates
    real(wp) :: qz(NLOC), a, best, val, c0(2), c1(2), c2(2), c3(2), fpt(2), mv(2)
    type(kvec) :: cp, fk
    type(kloc) :: x
    integer :: k
    qz = zero
    x = local_state(ql, qz)
    fk = body_point(x, sj, p(1:2)); fpt = fk%v
    fk = body_vector(x, sj, p(3:4)); mv = fk%v
    alpha = zero; best = huge(1.0_wp)
    do k = 0, NSAMPLE - 1
      a = two * pi * k / NSAMPLE
      call contact_curve(prof, fol, p, a, c0, c1, c2, c3)
      cp = curve_point(x, si, 0, c0, c1, c2)
      if (fol == FOL_FLAT) then
        val = dot_product(mv, cp%v)
      else
        val = sum((cp%v - fpt)**2)
      end if
      if (val < best) then
        best = val; alpha = a
      end if
    end do
  end function cam_init_alpha

  !> The profile's outward unit normal (global) at the contact of the local state x: point
  !! and roller followers A_i n(alpha); a flat face -A_j m'.
  pure function cam_outward_normal(prof, fol, p, si, sj, x) result(nv)
    integer, intent(in) :: prof, fol        !! profile and follower kinds
    real(wp), intent(in) :: p(:)            !! prepared parameters
    integer, intent(in) :: si, sj           !! slot ids
    type(kloc), intent(in) :: x             !! local state
    real(wp) :: nv(2), c0(2), c1(2), c2(2), c3(2), n0(2), n1(2), n2(2)
    type(kvec) :: a
    if (fol == FOL_FLAT) then
      a = body_vector(x, sj, p(3:4))
      nv = -a%v
    else
      call profile_eval(prof, p(5:), x%q(ALPHA_SLOT), c0, c1, c2, c3)
      call profile_normal(c1, c2, c3, n0, n1, n2)
      a = curve_vector(x, si, 0, n0, n1, n2)
      nv = a%v
    end if
  end function cam_outward_normal

  !> True when raw entry j is a count of the profile (no derivative with respect to it).
  pure logical function cam_is_count(prof, j)
    integer, intent(in) :: prof     !! profile kind
    integer, intent(in) :: j        !! raw entry
    cam_is_count = .false.
    if (j > 4) cam_is_count = profile_is_count(prof, j - 4)
  end function cam_is_count

  !> Change of the prepared parameters when raw(j) changes by one: the follower part
  !! (a point follower ignores entries 3 and 4; a flat face's unit normal m^ = m/|m|
  !! changes by (e - m^ (m^ . e))/|m|), then the profile's (profile_prepare_d).
  subroutine cam_prepare_d(prof, fol, raw, j, tprep, status, msg)
    integer, intent(in) :: prof, fol               !! profile and follower kinds
    real(wp), intent(in) :: raw(:)                 !! raw parameters (exact length)
    integer, intent(in) :: j                       !! raw entry
    real(wp), allocatable, intent(out) :: tprep(:) !! change of the prepared parameters
    integer, intent(out) :: status                 !! MBD_OK or the failure
    character(len=MSG_LEN), intent(out) :: msg     !! what went wrong
    real(wp), allocatable :: pp(:), tpp(:)
    real(wp) :: f(4), nm, mh(2), e(2)
    status = MBD_OK; msg = ''
    call profile_prepare(prof, raw(5:), pp, status, msg)
    if (status /= MBD_OK) return
    f = zero
    if (j > 4) then
      call profile_prepare_d(prof, raw(5:), j - 4, tpp, status, msg)
      if (status /= MBD_OK) return
      tprep = [f, tpp]
      return
    end if
    if (fol == FOL_FLAT .and. j >= 3) then
      nm = hypot(raw(3), raw(4)); mh = raw(3:4) / nm
      e = zero; e(j - 2) = 1.0_wp
      f(3:4) = (e - mh * dot_product(mh, e)) / nm
    else if (.not. (fol == FOL_POINT .and. j >= 3)) then
      f(j) = 1.0_wp
    end if
    allocate (tprep(4 + size(pp)), stat=status)
    if (status /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory'; return
    end if
    tprep = zero; tprep(1:4) = f
  end subroutine cam_prepare_d

  !> The contact curve (profile offset by the roller radius rho along its normal n), its
  !! alpha derivatives d0 .. d3 and the changes td0 .. td2 for a parameter change tp:
  !! d_k = c_k + rho n_k,  td_k = tc_k + t_rho n_k + rho tn_k.
  pure subroutine contact_curve_d(prof, fol, p, tp, alpha, d, td)
    integer, intent(in) :: prof, fol
    real(wp), intent(in) :: p(:), tp(:), alpha
    real(wp), intent(out) :: d(2, 0:4), td(2, 0:3)
    real(wp) :: n0(2), n1(2), n2(2), tn0(2), tn1(2), tn2(2)
    call profile_eval(prof, p(5:), alpha, d(:, 0), d(:, 1), d(:, 2), d(:, 3))
    d(:, 4) = profile_c4(prof, p(5:), alpha)
    call profile_eval_d(prof, p(5:), tp(5:), alpha, td(:, 0), td(:, 1), td(:, 2), td(:, 3))
    if (fol == FOL_ROLLER) then
      call profile_normal(d(:, 1), d(:, 2), d(:, 3), n0, n1, n2)
      call profile_normal_d(d(:, 1), d(:, 2), d(:, 3), td(:, 1), td(:, 2), td(:, 3), &
                            tn0, tn1, tn2)
      td(:, 0) = td(:, 0) + tp(3) * n0 + p(3) * tn0
      td(:, 1) = td(:, 1) + tp(3) * n1 + p(3) * tn1
      td(:, 2) = td(:, 2) + tp(3) * n2 + p(3) * tn2
      d(:, 3) = d(:, 3) + p(3) * profile_normal3(d(:, 1), d(:, 2), d(:, 3), d(:, 4))
      d(:, 0) = d(:, 0) + p(3) * n0; d(:, 1) = d(:, 1) + p(3) * n1
      d(:, 2) = d(:, 2) + p(3) * n2
    end if
  end subroutine contact_curve_d

  !> Changes of the rows along a direction and a parameter change tp (mbd_dual).
  pure subroutine cam_eval_d(prof, fol, p, tp, si, sj, x, tphi, tjl, tgam)
    integer, intent(in) :: prof, fol        !! profile and follower kinds
    real(wp), intent(in) :: p(:), tp(:)     !! prepared parameters and their change
    integer, intent(in) :: si, sj           !! slot ids of cam and follower bodies
    type(dloc), intent(in) :: x             !! local state and direction
    real(wp), intent(inout) :: tphi(MAXROW), tjl(MAXROW, NLOC), tgam(MAXROW)  !! 2 rows
    real(wp) :: d(2, 0:4), td(2, 0:3)
    type(dvec) :: cp, m
    call contact_curve_d(prof, fol, p, tp, x%x%q(ALPHA_SLOT), d, td)
    cp = curve_point(x, si, ALPHA_SLOT, d(:, 0), d(:, 1), d(:, 2), d(:, 3), td(:, 0), &
                     td(:, 1), td(:, 2))
    if (fol == FOL_FLAT) then
      m = body_vector(x, sj, p(3:4), tp(3:4))
      call put_scal(vdot(m, vsub(cp, body_point(x, sj, p(1:2), tp(1:2)))), tphi(1), &
                    tjl(1, :), tgam(1))
      call put_scal(vdot(m, curve_vector(x, si, ALPHA_SLOT, d(:, 1), d(:, 2), d(:, 3), &
                                         d(:, 4), td(:, 1), td(:, 2), td(:, 3))), &
                    tphi(2), tjl(2, :), tgam(2))
    else
      call put_vec(vsub(cp, body_point(x, sj, p(1:2), tp(1:2))), tphi, tjl, tgam)
    end if
  end subroutine cam_eval_d

end module mbd_joint_cam
