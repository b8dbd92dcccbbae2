!> mbd_sens_dynamics: design sensitivities of the multipliers (inverse dynamics, reactions,
!! driver efforts) and of static equilibria, from the blocks of mbd_sensitivity.
!!
!! Inverse dynamics, J^T lambda = Q(q, q_dot, t; p) - M(p) q_ddot, differentiated along a
!! kinematic sensitivity (s, s_dot, s_ddot) of parameter p:
!!   J^T dlambda = Q_q s + Q_q_dot s_dot + Q_p - M_p q_ddot - M s_ddot - K_lam s - J_p^T lambda
!! with K_lam = (J^T lambda)_q = sum_r lambda_r (Phi_r)_qq. Solved like the multipliers
!! (minimum norm; with independent rows the unique dlambda).
!! Reactions g_k = -J_k^T lambda_k (mbd_dynamics) change by -(dJ_k^T lambda_k + J_k^T
!! dlambda_k), dJ_k = J_k,q s + J_k,p, and their body-frame components A^T g by
!! A^T dg + dA^T g, dA = B(theta) dtheta.
!! Statics, J^T lambda = Q(q, 0, t; p), Phi(q, t; p) = 0, differentiated at the equilibrium:
!!   [K_lam - Q_q, J_a^T; J_a, 0] [s; dlambda_a] = [Q_p - J_p^T lambda; -Phi_p,a]
!! over the independent rows a (redundant rows keep dlambda = 0).
module mbd_sens_dynamics
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_SINGULAR, MBD_NO_MEMORY, MSG_LEN
  use mbd_points, only: NLOC, MAXROW, rot, drot
  use mbd_model, only: model_t
  use mbd_assemble, only: asm_work_t, asm_init, assemble_blocks, assemble_dense
  use mbd_sensitivity, only: sens_t, sens_trig, sens_hessian, sens_params, sens_klam, &
                             sens_jpt_lam, sens_force_d, sens_force_jac
  use mbd_linsolve, only: lu_factor, lu_solve, lapack_status
  use mbd_lapack, only: dgelsy
  implicit none
  private
  public :: sens_multipliers, sens_reactions, sens_statics

contains

  !> dlambda/dp (neq, np) at one output of an inverse dynamics run, from the kinematic
  !! sensitivities sq, sqd, sqdd (nq, np) there.
  subroutine sens_multipliers(m, s, q, qd, qdd, t, lam, sq, sqd, sqdd, slam, status, msg)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    real(wp), intent(in) :: q(:), qd(:), qdd(:) !! state and accelerations
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(in) :: lam(:)              !! multipliers (neq)
    real(wp), intent(in) :: sq(:, :), sqd(:, :), sqdd(:, :)  !! (nq, np)
    real(wp), intent(out) :: slam(:, :)         !! (neq, np)
    integer, intent(out) :: status              !! MBD_OK or MBD_LAPACK / MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(asm_work_t) :: a
    real(wp), allocatable :: jt(:, :), b(:, :), y(:), jpb(:, :, :), work(:), phi(:), nu(:), &
                             gam(:), jac(:, :)
    real(wp) :: wq(1)
    integer, allocatable :: jpvt(:)
    integer :: k, nq, neq, np, rank, info, st
    status = MBD_OK; msg = ''
    nq = m%nq; neq = m%neq; np = s%np
    slam = zero
    if (np == 0) return
    allocate (jt(nq, neq), b(max(nq, neq), np), y(nq), jpb(MAXROW, NLOC, m%nc), jpvt(neq), &
              phi(neq), nu(neq), gam(neq), jac(neq, nq), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the multiplier sensitivities'; return
    end if
    call asm_init(m, a)
    call assemble_dense(m, q, qd, t, phi, nu, gam, a, jac)
    call sens_trig(m, s, q)
    call sens_hessian(m, s, q, qd, qdd, t)
    b = zero
    do k = 1, np
      call sens_force_d(m, s, k, q, qd, sq(:, k), sqd(:, k), t, y)   ! Q_q s + Q_qd s_dot + Q_p
      b(1:nq, k) = y - s%tmass(:, k) * qdd - m%mdiag * sqdd(:, k)
      call sens_klam(m, s, lam, sq(:, k), y)
      b(1:nq, k) = b(1:nq, k) - y
      call sens_jpt_lam(m, s, k, q, t, lam, y, jpb)
      b(1:nq, k) = b(1:nq, k) - y
    end do
    jt = transpose(jac)
    jpvt = 0
    call dgelsy(nq, neq, np, jt, nq, b, size(b, 1), jpvt, 1.0e-10_wp, rank, wq, -1, info)
    allocate (work(max(1, int(wq(1)))), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the multiplier sensitivities'; return
    end if
    call dgelsy(nq, neq, np, jt, nq, b, size(b, 1), jpvt, 1.0e-10_wp, rank, work, size(work), &
                info)
    call lapack_status('dgelsy', info, status, msg)
    slam = b(1:neq, :)
  end subroutine sens_multipliers

  !> Changes of the reactions (mbd_dynamics dyn_reactions) of every constraint at one state
  !! along each parameter: dreac, drloc (6, nc, np), from dq/dp (sq) and dlambda/dp (slam).
  subroutine sens_reactions(m, s, q, t, lam, sq, slam, dreac, drloc)
    type(model_t), intent(in) :: m              !! model
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    real(wp), intent(in) :: q(:), t             !! configuration, time
    real(wp), intent(in) :: lam(:)              !! multipliers (neq)
    real(wp), intent(in) :: sq(:, :)            !! dq/dp (nq, np)
    real(wp), intent(in) :: slam(:, :)          !! dlambda/dp (neq, np)
    real(wp), intent(out) :: dreac(:, :, :), drloc(:, :, :)  !! (6, nc, np)
    type(asm_work_t) :: a
    real(wp) :: phi(m%neq), nu(m%neq), gam(m%neq), y(m%nq), g(NLOC), dg(NLOC), sl(NLOC), &
                jpb(MAXROW, NLOC, m%nc), dj(MAXROW, NLOC), th, dth
    integer :: k, c, r0, nr, j, b, off
    call asm_init(m, a)
    call assemble_blocks(m, q, q * zero, t, phi, nu, gam, a)
    call sens_trig(m, s, q)
    call sens_hessian(m, s, q, q * zero, q * zero, t)
    dreac = zero; drloc = zero
    do k = 1, s%np
      call sens_jpt_lam(m, s, k, q, t, lam, y, jpb)
      do c = 1, m%nc
        r0 = m%row0(c); nr = m%nrow(c)
        ! dJ_c = sum over slots of hs(:, :, j) s_j + J_p
        do j = 1, NLOC
          sl(j) = zero
          if (m%loc(j, c) > 0) sl(j) = sq(m%loc(j, c), k)
        end do
        dj = jpb(:, :, c)
        do j = 1, NLOC
          if (sl(j) /= zero) dj = dj + s%hs(:, :, j, c) * sl(j)
        end do
        g = -matmul(lam(r0:r0 + nr - 1), a%jb(1:nr, :, c))
        dg = -matmul(slam(r0:r0 + nr - 1, k), a%jb(1:nr, :, c)) - &
             matmul(lam(r0:r0 + nr - 1), dj(1:nr, :))
        dreac(:, c, k) = dg(1:6)
        drloc(:, c, k) = dg(1:6)
        do j = 1, 2
          b = m%bi(c); off = 0
          if (j == 2) then
            b = m%bj(c); off = 3
          end if
          if (b > 0) then
            th = q(3 * b); dth = sq(3 * b, k)
            drloc(off + 1:off + 2, c, k) = matmul(transpose(rot(th)), dg(off + 1:off + 2)) + &
              dth * matmul(transpose(drot(th)), g(off + 1:off + 2))
          else
            dreac(off + 1:off + 3, c, k) = zero; drloc(off + 1:off + 3, c, k) = zero
          end if
        end do
      end do
    end do
  end subroutine sens_reactions

  !> dq/dp (nq, np) and dlambda/dp (neq, np) at a static equilibrium (q, lam) at time t;
  !! rows: the independent constraint rows (the others get dlambda = 0).
  subroutine sens_statics(m, s, rows, q, t, lam, sq, slam, status, msg)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    integer, intent(in) :: rows(:)              !! independent constraint rows
    real(wp), intent(in) :: q(:), t             !! equilibrium and time
    real(wp), intent(in) :: lam(:)              !! multipliers (neq)
    real(wp), intent(out) :: sq(:, :)           !! dq/dp (nq, np)
    real(wp), intent(out) :: slam(:, :)         !! dlambda/dp (neq, np)
    integer, intent(out) :: status              !! MBD_OK or MBD_SINGULAR
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(asm_work_t) :: a
    real(wp), allocatable :: kk(:, :), kq(:, :), aug(:, :), rhs(:), y(:), e(:), jpb(:, :, :), &
                             phi(:), nu(:), gam(:), jac(:, :), z(:)
    integer, allocatable :: ipiv(:)
    integer :: n, na, i, k, st
    status = MBD_OK; msg = ''
    n = m%nq; na = size(rows)
    sq = zero; slam = zero
    allocate (kk(n, n), kq(n, n), aug(n + na, n + na), rhs(n + na), y(n), e(n), &
              jpb(MAXROW, NLOC, m%nc), phi(m%neq), nu(m%neq), gam(m%neq), jac(m%neq, n), &
              z(n), ipiv(n + na), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the statics sensitivities'; return
    end if
    z = zero
    call asm_init(m, a)
    call assemble_dense(m, q, z, t, phi, nu, gam, a, jac)
    call sens_trig(m, s, q)
    call sens_hessian(m, s, q, z, z, t)
    call sens_params(m, s, q, z, z, t)
    ! K = K_lam - Q_q, column by column
    call sens_force_jac(m, q, z, t, kq)
    do i = 1, n
      e = zero; e(i) = one
      call sens_klam(m, s, lam, e, y)
      kk(:, i) = y - kq(:, i)
    end do
    aug = zero
    aug(1:n, 1:n) = kk
    aug(1:n, n + 1:) = transpose(jac(rows, :))
    aug(n + 1:, 1:n) = jac(rows, :)
    call lu_factor(aug, ipiv, status, msg)
    if (status /= MBD_OK) then
      msg = 'statics sensitivities: the equilibrium is not isolated (singular stiffness on '// &
            'the free motions)'
      return
    end if
    do k = 1, s%np
      call sens_force_d(m, s, k, q, z, z, z, t, y)          ! Q_p
      rhs(1:n) = y
      call sens_jpt_lam(m, s, k, q, t, lam, y, jpb)
      rhs(1:n) = rhs(1:n) - y
      rhs(n + 1:) = -s%phip(k, rows)
      call lu_solve(aug, ipiv, rhs, status, msg)
      if (status /= MBD_OK) return
      sq(:, k) = rhs(1:n)
      slam(rows, k) = rhs(n + 1:)
    end do
  end subroutine sens_statics

end module mbd_sens_dynamics
