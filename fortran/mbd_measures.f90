!> mbd_measures: quantities a linkage is judged by, evaluated at the states of a finished run
!! (one call for all of them).
!!
!!   conditioning  c = sigma_min(J D) / sigma_max(J D), J = Phi_q with lengths in units of the
!!                 model's length scale L (the core's units), D = diag(1/|J_k|) (columns to unit
!!                 length, so lengths and angles weigh alike): the measure the kinematics uses
!!                 to call a configuration singular (SING_RATIO). c = 0 at a dead centre and
!!                 near a fold (toggle) falls like sqrt(t* - t).
!!   influence     u = dq/ds_r from J u = e_r: the change of every coordinate per unit change
!!                 of the quantity driven by row r of Phi (a driver's row), the other rows held
!!                 (Haug, ch. 3: kinematic influence coefficients). By virtual work the
!!                 mechanical advantage between two quantities X and Y moved by that driver is
!!                 u_X / u_Y. Square J: LU; more rows than coordinates (redundant, consistent
!!                 constraints): least squares by pivoted QR, exact while they agree.
!!   fun_values    f(t), f'(t), f''(t) of an encoded function of time at many times (the
!!                 applied loads drawn as arrows).
!!
!! Work arrays are allocated once per call (with stat=), none in the loop over states.
module mbd_measures
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_BAD_COUNT, MBD_BAD_PARAM, MSG_LEN
  use mbd_model, only: model_t, model_build
  use mbd_assemble, only: asm_work_t, asm_init, assemble_dense
  use mbd_memory, only: mem_fail, REAL_BYTES
  use mbd_linsolve, only: lapack_status, lu_factor, lu_solve, qr_factor, qr_solve, qr_lwork
  use mbd_lapack, only: dgesvd
  use mbd_functions, only: fun_check, fun_eval, fun_length
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: api_conditioning, api_influence, api_fun_values

contains

  !> sigma_min / sigma_max of the column-scaled J (core units) at each state.
  subroutine api_conditioning(nb, ctab, rpar, q, t, cond, status, msg)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q(:, :)             !! states (nq, nt), model units
    real(wp), intent(in) :: t(:)                !! times (nt)
    real(wp), intent(out) :: cond(:)            !! sigma_min / sigma_max (nt)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(model_t) :: m
    type(asm_work_t) :: aw
    real(wp), allocatable :: phi(:), nu(:), gam(:), jac(:, :), qz(:), qc(:), sv(:), work(:)
    real(wp) :: wq(1), du(1, 1), dvt(1, 1), cn
    integer :: bad, k, c, info, lwork, ist, ns
    cond = zero
    call model_build(nb, ctab, rpar, m, status, msg, bad, nondim=.true.)
    if (status /= MBD_OK) return
    if (.not. check_states(m, q, t, size(cond), status, msg)) return
    ns = min(m%neq, m%nq)
    allocate (phi(m%neq), nu(m%neq), gam(m%neq), jac(m%neq, m%nq), qz(m%nq), qc(m%nq), &
              sv(max(ns, 1)), stat=ist)
    if (ist /= 0) then
      call no_memory(m, status, msg); return
    end if
    call asm_init(m, aw, status, msg)
    if (status /= MBD_OK) return
    qz = zero
    call dgesvd('N', 'N', m%neq, m%nq, jac, m%neq, sv, du, 1, dvt, 1, wq, -1, info)
    lwork = max(1, int(wq(1)))
    allocate (work(lwork), stat=ist)
    if (ist /= 0) then
      call no_memory(m, status, msg); return
    end if
    do k = 1, size(t)
      qc = q(:, k) / m%cunit
      call assemble_dense(m, qc, qz, t(k), phi, nu, gam, aw, jac)
      ! columns to unit length: J D, D = diag(1/|J_k|)
      do c = 1, m%nq
        cn = norm2(jac(:, c))
        if (cn > zero) jac(:, c) = jac(:, c) / cn
      end do
      call dgesvd('N', 'N', m%neq, m%nq, jac, m%neq, sv, du, 1, dvt, 1, work, lwork, info)
      call lapack_status('dgesvd', info, status, msg)
      if (status /= MBD_OK) return
      if (sv(1) > zero) cond(k) = sv(ns) / sv(1)
    end do
  end subroutine api_conditioning

  !> Influence coefficients u = dq/ds of the quantity driven by row r at each state:
  !! J u = e_r (model units: u(i) per unit of row r's quantity). ok(k) = 0 where J is
  !! singular (the quantity cannot be changed there: a dead centre of that driver).
  subroutine api_influence(nb, ctab, rpar, q, t, r, u, ok, status, msg)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q(:, :)             !! states (nq, nt), model units
    real(wp), intent(in) :: t(:)                !! times (nt)
    integer, intent(in) :: r                    !! row of Phi (1-based) whose quantity moves
    real(wp), intent(out) :: u(:, :)            !! dq/ds (nq, nt)
    integer, intent(out) :: ok(:)               !! 1 solved, 0 singular J (nt)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(model_t) :: m
    type(asm_work_t) :: aw
    real(wp), allocatable :: phi(:), nu(:), gam(:), jac(:, :), qz(:), b(:), tau(:), work(:)
    integer, allocatable :: ipiv(:), jpvt(:)
    real(wp) :: resid
    integer :: bad, k, ist, st
    character(len=MSG_LEN) :: lmsg
    u = zero; ok = 0
    call model_build(nb, ctab, rpar, m, status, msg, bad)
    if (status /= MBD_OK) return
    if (.not. check_states(m, q, t, size(ok), status, msg)) return
    if (size(u, 1) /= m%nq .or. size(u, 2) /= size(t)) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    if (r < 1 .or. r > m%neq) then
      status = MBD_BAD_COUNT; msg = 'the row is not a row of Phi'; return
    end if
    if (m%neq < m%nq) then
      status = MBD_BAD_COUNT
      msg = 'fewer equations than coordinates: the motion is not determined by the drivers'
      return
    end if
    allocate (phi(m%neq), nu(m%neq), gam(m%neq), jac(m%neq, m%nq), qz(m%nq), b(m%neq), &
              ipiv(m%nq), jpvt(m%nq), tau(m%nq), work(qr_lwork(m%neq, m%nq)), stat=ist)
    if (ist /= 0) then
      call no_memory(m, status, msg); return
    end if
    call asm_init(m, aw, status, msg)
    if (status /= MBD_OK) return
    qz = zero
    do k = 1, size(t)
      call assemble_dense(m, q(:, k), qz, t(k), phi, nu, gam, aw, jac)
      b = zero; b(r) = one                      ! J u = e_r
      if (m%neq == m%nq) then
        call lu_factor(jac, ipiv, st, lmsg)
        if (st == MBD_OK) call lu_solve(jac, ipiv, b, st, lmsg)
        if (st == MBD_OK) u(:, k) = b(1:m%nq)
      else
        call qr_factor(jac, jpvt, tau, work, st, lmsg)
        if (st == MBD_OK) call qr_solve(jac, jpvt, tau, b, u(:, k), resid, work)
      end if
      if (st == MBD_OK .and. all(ieee_is_finite(u(:, k)))) then
        ok(k) = 1
      else
        u(:, k) = zero
      end if
    end do
  end subroutine api_influence

  !> f(t), f'(t), f''(t) of the encoded function p at the times t.
  subroutine api_fun_values(p, t, f, f1, f2, status, msg)
    real(wp), intent(in) :: p(:)                !! encoded function (mbd_functions)
    real(wp), intent(in) :: t(:)                !! times
    real(wp), intent(out) :: f(:), f1(:), f2(:) !! values and two derivatives (size(t))
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer :: k
    f = zero; f1 = zero; f2 = zero
    status = MBD_OK; msg = ''
    if (size(f) /= size(t) .or. size(f1) /= size(t) .or. size(f2) /= size(t) .or. &
        fun_length(p) /= size(p)) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the function'; return
    end if
    call fun_check(p, status, msg)
    if (status /= MBD_OK) return
    if (.not. all(ieee_is_finite(t))) then
      status = MBD_BAD_PARAM; msg = 'the times must be finite'; return
    end if
    do k = 1, size(t)
      call fun_eval(p, t(k), f(k), f1(k), f2(k))
    end do
  end subroutine api_fun_values

  !> States and times finite and sized for the model.
  logical function check_states(m, q, t, nt, status, msg) result(good)
    type(model_t), intent(in) :: m              !! model
    real(wp), intent(in) :: q(:, :), t(:)       !! states (nq, nt) and times
    integer, intent(in) :: nt                   !! size of the caller's per-state output
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    good = .false.
    if (size(q, 1) /= m%nq .or. size(q, 2) /= size(t) .or. nt /= size(t)) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    if (.not. (all(ieee_is_finite(q)) .and. all(ieee_is_finite(t)))) then
      status = MBD_BAD_PARAM; msg = 'the states and times must be finite (no NaN or infinity)'
      return
    end if
    status = MBD_OK; msg = ''
    good = .true.
  end function check_states

  !> MBD_NO_MEMORY after a failed allocation of the work arrays (about a dense J and a few
  !! vectors).
  subroutine no_memory(m, status, msg)
    type(model_t), intent(in) :: m              !! model
    integer, intent(out) :: status              !! MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    msg = ''
    call mem_fail(REAL_BYTES * (real(m%neq, wp) * m%nq + 8.0_wp * (m%neq + m%nq)), &
                  'the work arrays of the mechanism measures (a dense J)', &
                  'the model is too large for a dense J', status, msg)
  end subroutine no_memory

end module mbd_measures
