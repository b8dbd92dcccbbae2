!> mbd_linear: the linearized motion about an equilibrium as a state-space system
!!   x' = A x + B p,   dq = C x + D p
!! whose inputs p are design parameters (a force's amplitude, a spring's free length, a
!! pivot's place, gravity) and whose outputs are the coordinates' changes dq (Adams/Linear's
!! state matrices, Simulink's linmod; for control design and for scipy.signal).
!!
!! About the rest state q*, lambda* (drivers held at t) the motion obeys to first order (the
!! frequency response's equations, mbd_frf, in the time domain): dq = s_n p + N z,
!!   M_r z'' + C_r z' + K_r z = G0 p + G1 p' + G2 p'',
!! G0 = N^T (r - K s_n), G1 = N^T (Q_p_dot - C s_n), G2 = -N^T M s_n (mbd_frf's
!! linear_parts: N a basis of J_a's null space, s_n the minimum-norm solution of
!! J_a s_n = -Phi_p,a, r = Q_p - J_p^T lambda*, Q_p_dot the forces' change per unit rate of
!! p: a damper whose point moves). A base motion (s_n /= 0) forces through p' and p'' as well; two changes of
!! variable take them out (the standard realization of a proper transfer function):
!!   w = z - M_r^-1 G2 p:        M_r w'' + C_r w' + K_r w = E0 p + E1 p',
!!                               E0 = G0 - K_r M_r^-1 G2, E1 = G1 - C_r M_r^-1 G2;
!!   v = w' - M_r^-1 E1 p:       x = [w; v],
!!   A = [0, I; -M_r^-1 K_r, -M_r^-1 C_r],
!!   B = [M_r^-1 E1; M_r^-1 (E0 - C_r M_r^-1 E1)],
!!   C = [N, 0],   D = s_n + N M_r^-1 G2.
!! With forces alone as inputs (s_n = 0) w = z and v = z'. The velocities' outputs
!! dq' = C x' + D p' = C A x + C B p + D p' = [0, N] x + N M_r^-1 E1 p are proper only
!! where D = 0 (an input that moves the mechanism directly moves its velocities by p'):
!! cv = [0, N], dv = N M_r^-1 E1. The multipliers' outputs (a driver's effort is -lambda on
!! its row) from J_a^T dlambda = r p + Q_p_dot p' - M dq'' - C dq' - K dq (mbd_frf) with
!! dq = s_n p + N z, z = w + Y2 p, z' = v + Y1 p + Y2 p', z'' = v' + Y1 p' + Y2 p''
!! (Y2 = M_r^-1 G2, Y1 = M_r^-1 E1, v' the lower rows of A x + B p):
!!   dlambda = P(-K N + M N M_r^-1 K_r) w + P(-C N + M N M_r^-1 C_r) v
!!           + P(r - K s_n - K N Y2 - C N Y1 - M N B_v) p + P(x1) p' + P(x2) p'',
!!   x1 = -(C s_n - Q_p_dot) - C N Y2 - M N Y1,   x2 = -M s_n - M N Y2,
!! P the least squares J_a^T mu = x (exact: each x is orthogonal to N, N^T x1 = N^T x2 = 0).
!! Written for the drivers' rows (the others 0), proper only where x1 and x2 are zero there
!! (forces alone, or a rate forcing that the free motions and the other joints take); else
!! the input is named (improper). C (i Omega I - A)^-1 B + D is the
!! frequency response H(Omega) of mbd_frf. The states are coordinates on the basis N (its
!! columns orthonormal in the metric of dyn_null_basis): not unique, as any realization.
!! Memory: N, K N, C N, M N (nq x f), five nq x np arrays and three f x f matrices, checked
!! and allocated once per call (MBD_NO_MEMORY otherwise).
module mbd_linear
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_SINGULAR, MBD_BAD_COUNT, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail
  use mbd_model, only: model_t
  use mbd_lapack, only: dgemm, dgetrs
  use mbd_sensitivity, only: sens_t
  use mbd_dynamics, only: dyn_work_t
  use mbd_frf, only: linear_parts, mass_lu
  use mbd_sens_dynamics, only: proj_multipliers
  use mbd_constraints, only: con_is_driver
  implicit none
  private
  public :: linear_state_space

  !> |x1|, |x2| at most this fraction of the terms that cancel in them: zero (round-off)
  real(wp), parameter :: CANCEL = 1.0e-10_wp
  character(len=*), parameter :: HINT = 'the linearized system uses dense matrices of the ' &
    // 'number of free motions: use a model with fewer free motions'

contains

  !> A (2f, 2f), B (2f, np), C (nq, 2f), D (nq, np) of the linearized motion about (q, t,
  !! lam), core units, in the leading parts of the arrays (f the free motions; the arrays'
  !! state dimension at least 2f, else MBD_BAD_COUNT with nfree set).
  subroutine linear_state_space(m, w, s, q, t, lam, a, b, c, d, nfree, status, msg, cv, dv, &
                                cl, dl, improper)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! work arrays (dyn_init done)
    type(sens_t), intent(inout) :: s            !! the inputs (sens_setup done)
    real(wp), intent(in) :: q(:), t             !! rest state (core units), time
    real(wp), intent(in) :: lam(:)              !! its multipliers (neq)
    real(wp), intent(out) :: a(:, :)            !! (>= 2f, >= 2f) state matrix
    real(wp), intent(out) :: b(:, :)            !! (>= 2f, np) input matrix
    real(wp), intent(out) :: c(:, :)            !! (nq, >= 2f) output matrix
    real(wp), intent(out) :: d(:, :)            !! (nq, np) feedthrough
    integer, intent(out) :: nfree               !! f
    integer, intent(out) :: status  !! MBD_OK, MBD_SINGULAR, MBD_BAD_COUNT, MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    !> (nq, >= 2f), (nq, np): the velocities' output matrix C A and feedthrough C B
    real(wp), intent(out), optional :: cv(:, :), dv(:, :)
    !> (neq, >= 2f), (neq, np): the drivers' multipliers' output matrix and feedthrough (the
    !! other rows 0; with improper)
    real(wp), intent(out), optional :: cl(:, :), dl(:, :)
    !> the first input whose rate or acceleration moves a driver's multiplier (P(x1) or P(x2)
    !! /= 0 on its rows), else 0
    integer, intent(out), optional :: improper
    ! N, K N, C N, M N; s_n, K s_n, C s_n, M s_n, r; K_r, C_r, M_r (then M_r's LU); G and
    ! the solves' right-hand sides
    real(wp), allocatable :: nb(:, :), kn(:, :), cn(:, :), mn(:, :), sn(:, :), ks(:, :), &
                             cs(:, :), ms(:, :), rr(:, :), kr(:, :), cr(:, :), mr(:, :), &
                             y2(:, :), e0(:, :), e1(:, :), y1(:, :), mk(:, :), mc(:, :)
    integer, allocatable :: ipiv(:)
    real(wp) :: bytes
    integer :: n, f, np, i, ist, info
    character(len=MSG_LEN) :: what
    status = MBD_OK; msg = ''
    a = zero; b = zero; c = zero; d = zero
    if (present(cv)) cv = zero
    if (present(dv)) dv = zero
    if (present(cl)) cl = zero
    if (present(dl)) dl = zero
    if (present(improper)) improper = 0
    n = m%nq; f = n - w%na; np = s%np
    nfree = f
    if (size(a, 1) < 2 * f .or. size(a, 2) < 2 * f .or. size(b, 1) < 2 * f .or. &
        size(c, 2) < 2 * f) then
      status = MBD_BAD_COUNT
      write (msg, '(a,i0,a)') 'linearized system: the state arrays hold fewer than 2 x ', f, &
        ' free motions'
      return
    end if
    bytes = REAL_BYTES * (4 * real(n, wp) * max(f, 1) + 5 * real(n, wp) * np &
                          + 5 * real(max(f, 1), wp)**2 + 4 * real(max(f, 1), wp) * np + f)
    write (what, '(a,i0,a)') 'the linearized system''s work arrays (', f, ' free motions)'
    call mem_check(bytes, trim(what), HINT, status, msg)
    if (status /= MBD_OK) return
    call linear_parts(m, w, s, q, t, lam, nb, kn, cn, mn, kr, cr, mr, sn, ks, cs, ms, rr, &
                      status, msg)
    if (status /= MBD_OK) then
      msg = 'linearized system: ' // msg(1:MSG_LEN - len('linearized system: ')); return
    end if
    allocate (y2(f, np), e0(f, np), e1(f, np), y1(f, np), mk(f, f), mc(f, f), ipiv(f), &
              stat=ist)
    if (ist /= 0) then
      call mem_fail(bytes, trim(what), HINT, status, msg); return
    end if
    d(:, 1:np) = sn                               ! (every motion driven: dq = s_n p)
    if (f == 0) then                              ! (the multipliers: P(r - K s_n) p ...)
      if (present(cl) .and. present(dl) .and. present(improper)) call multipliers(status)
      return
    end if
    call mass_lu(f, mr, f, ipiv, info)            ! M_r = P L U
    if (info /= 0) then
      status = MBD_SINGULAR
      msg = 'linearized system: a free motion carries no mass (M_r is singular): give ' // &
            'every moving body a mass and an inertia'
      return
    end if
    ! G0 = N^T (r - K s_n) in e0, G1 = N^T (Q_p_dot - C s_n) in e1 (cs holds C s_n -
    ! Q_p_dot), G2 = -N^T M s_n in y2
    call dgemm('T', 'N', f, np, n, one, nb, n, rr - ks, n, zero, e0, f)
    call dgemm('T', 'N', f, np, n, -one, nb, n, cs, n, zero, e1, f)
    call dgemm('T', 'N', f, np, n, -one, nb, n, ms, n, zero, y2, f)
    call dgetrs('N', f, np, mr, f, ipiv, y2, f, info)            ! Y2 = M_r^-1 G2
    call dgemm('N', 'N', f, np, f, -one, kr, f, y2, f, one, e0, f)   ! E0 = G0 - K_r Y2
    call dgemm('N', 'N', f, np, f, -one, cr, f, y2, f, one, e1, f)   ! E1 = G1 - C_r Y2
    y1 = e1
    call dgetrs('N', f, np, mr, f, ipiv, y1, f, info)            ! Y1 = M_r^-1 E1
    call dgemm('N', 'N', f, np, f, -one, cr, f, y1, f, one, e0, f)   ! E0 - C_r Y1
    call dgetrs('N', f, np, mr, f, ipiv, e0, f, info)
    mk = kr; mc = cr
    call dgetrs('N', f, f, mr, f, ipiv, mk, f, info)             ! M_r^-1 K_r
    call dgetrs('N', f, f, mr, f, ipiv, mc, f, info)             ! M_r^-1 C_r
    do i = 1, f                                   ! A = [0, I; -M_r^-1 K_r, -M_r^-1 C_r]
      a(i, f + i) = one
    end do
    a(f + 1:2 * f, 1:f) = -mk
    a(f + 1:2 * f, f + 1:2 * f) = -mc
    b(1:f, 1:np) = y1                             ! B = [M_r^-1 E1; M_r^-1 (E0 - C_r Y1)]
    b(f + 1:2 * f, 1:np) = e0
    c(:, 1:f) = nb(:, 1:f)                        ! C = [N, 0]
    call dgemm('N', 'N', n, np, f, one, nb, n, y2, f, one, d, size(d, 1))   ! D = s_n + N Y2
    if (present(cv)) cv(:, f + 1:2 * f) = nb(:, 1:f)                     ! C A = [0, N]
    if (present(dv)) call dgemm('N', 'N', n, np, f, one, nb, n, y1, f, zero, dv, size(dv, 1))
    if (present(cl) .and. present(dl) .and. present(improper)) call multipliers(status)
  contains
    !> cl, dl and improper (the module's comment): each output column's force vector x in
    !! q-space, then P(x); the drivers' rows kept.
    subroutine multipliers(st)
      integer, intent(out) :: st
      real(wp) :: x(n), size1, size2, l1, l2, v(5)
      logical :: drv(size(lam))
      real(wp) :: xd(size(lam), 5)
      integer :: j, k, r, i
      st = MBD_OK
      do r = 1, size(lam)
        drv(r) = con_is_driver(m%kind(m%con_of_row(r)))
      end do
      do j = 1, f                                 ! w: -K N + M N M_r^-1 K_r
        x = -kn(:, j) + matmul(mn(:, 1:f), mk(:, j))
        call project(x, cl(:, j), st)
        if (st /= MBD_OK) return
        x = -cn(:, j) + matmul(mn(:, 1:f), mc(:, j))   ! v: -C N + M N M_r^-1 C_r
        call project(x, cl(:, f + j), st)
        if (st /= MBD_OK) return
      end do
      do k = 1, np
        x = rr(:, k) - ks(:, k) - matmul(kn(:, 1:f), y2(:, k)) - &
            matmul(cn(:, 1:f), y1(:, k)) - matmul(mn(:, 1:f), e0(:, k))
        call project(x, dl(:, k), st)
        if (st /= MBD_OK) return
        ! x1, x2 on the drivers' rows, against the terms that cancel in them (round-off)
        do i = 1, 5                               ! cs, C N Y2, M N Y1, ms, M N Y2
          select case (i)
          case (1); x = cs(:, k)
          case (2); x = matmul(cn(:, 1:f), y2(:, k))
          case (3); x = matmul(mn(:, 1:f), y1(:, k))
          case (4); x = ms(:, k)
          case default; x = matmul(mn(:, 1:f), y2(:, k))
          end select
          call drivers_part(x, drv, xd(:, i), st)
          if (st /= MBD_OK) return
          v(i) = norm2(xd(:, i))
        end do
        l1 = norm2(xd(:, 1) + xd(:, 2) + xd(:, 3)); size1 = v(1) + v(2) + v(3)
        l2 = norm2(xd(:, 4) + xd(:, 5)); size2 = v(4) + v(5)
        if (improper == 0 .and. (l1 > CANCEL * size1 .or. l2 > CANCEL * size2)) improper = k
      end do
      do r = 1, size(lam)                         ! the drivers' rows alone
        if (.not. drv(r)) then
          cl(r, :) = zero; dl(r, :) = zero
        end if
      end do
    end subroutine multipliers

    !> P(x) on the drivers' rows (drv), zero on the others.
    subroutine drivers_part(xx, drv, mu, st)
      real(wp), intent(in) :: xx(:)
      logical, intent(in) :: drv(:)
      real(wp), intent(out) :: mu(:)
      integer, intent(out) :: st
      call project(xx, mu, st)
      where (.not. drv) mu = zero
    end subroutine drivers_part

    !> mu = P(x): J_a^T mu = x by the projection's least squares (redundant rows 0).
    subroutine project(x, mu, st)
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: mu(:)
      integer, intent(out) :: st
      mu = zero
      call proj_multipliers(w, x, mu, st)
      if (st /= MBD_OK) msg = 'linearized system: the multipliers'' least squares failed'
    end subroutine project
  end subroutine linear_state_space
end module mbd_linear
