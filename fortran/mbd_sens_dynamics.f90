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
!! Forward dynamics (index 1, dopri5) by direct differentiation: with the state (q, q_dot) the
!! sensitivities (S, S_dot) of every parameter are integrated, S_ddot from
!!   [M J^T; J 0] [S_ddot; dlambda] = [dQ - M_p q_ddot - K_lam S - J_p^T lambda;
!!                                     gamma_p - J_p q_ddot - Ha S - 2 Hv S_dot]
!! (dQ = Q_q S + Q_q_dot S_dot + Q_p) with the factors of the step's augmented matrix, every
!! parameter at once (S, S_dot held as rows; a spring's dQ from its closed-form derivative,
!! mbd_forces spring_rows), and the error control covers them (Dormand-Prince 5(4), RMS over
!! all components). After each step S is projected onto J S = -Phi_p and S_dot onto
!! J S_dot = nu_p - J_p q_dot - Hv S, both nearest in the kinetic-energy metric with the
!! factors of q_dot's projection (the linearized projection of q_dot; the initial S takes the
!! minimum-norm change, as the assembly of q0).
module mbd_sens_dynamics
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_SINGULAR, MBD_NO_MEMORY, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check
  use mbd_points, only: NLOC, MAXROW, rot, drot
  use mbd_model, only: model_t
  use mbd_assemble, only: asm_work_t, asm_init, assemble_blocks, assemble_dense, blocks_jv_rows
  use mbd_sensitivity, only: sens_t, sens_trig, sens_hessian, sens_params, sens_klam, &
                             sens_klam_list, sens_rows_rhs, sens_revolute_rows, &
                             sens_translational_rows, &
                             sens_jpt_lam, sens_force_d, sens_force_dm, sens_force_jac, &
                             sens_force_rows
  use mbd_linsolve, only: lu_factor, lu_solve, lapack_status, ls_small_cols, lu_factor_small, &
                          lu_solve_small, LS_RTOL
  use mbd_lapack, only: dgelsy
  use mbd_status, only: MBD_INTEGRATOR_FAILED, MBD_BAD_SETTING
  use mbd_dynamics, only: dyn_work_t, dyn_accel, dyn_project_pos, dyn_velocity, &
                          dyn_factor_projection, dyn_solve_rows, dyn_solve, dyn_multipliers, &
                          dyn_null_basis, SOLVER_DENSE
  use mbd_integrators, only: output_rows, dopri5_state, dopri5_error, DOPRI_C, stiffness_test, &
                             break_step
  use mbd_interp, only: hermite5
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: sens_multipliers, sens_reactions, sens_statics, sens_statics_band, sens_dopri5, &
            sens_initial
  ! (the frequency response, mbd_frf: the equilibrium's load along a parameter)
  public :: statics_load, sens_stiffness_mul, sens_damping_mul, sens_at_rest, proj_particular, &
            proj_multipliers
  ! (the statics' Newton steps: the stiffness' blocks at each iterate, K on the tangent's sparse
  ! pattern)
  public :: sens_stiffness_at, sens_tangent_pattern
  ! (generalized-alpha's sensitivities, mbd_sens_genalpha: the same right-hand sides)
  public :: proj_work_t, proj_init, sens_accel, sens_dyn_rows, cols_to_rows, rows_to_cols
  ! (the multipliers' sensitivities at the outputs of forward dynamics)
  public :: lam_work_t, lam_init, sens_out_multipliers

  !> a singular reduced stiffness at a statics sensitivity
  character(len=*), parameter :: NOT_ISOLATED = 'statics sensitivities: the equilibrium is '// &
    'not isolated (singular stiffness on the free motions)'

  !> Work of project_sens and of the dopri5 right-hand sides (allocated once per run by
  !! proj_init: no step allocates).
  type :: proj_work_t
    !> one saddle right-hand side per parameter as the rows of rt (4 k, nq + na; the rows past
    !! np stay zero; dyn_solve_rows)
    real(wp), allocatable :: rt(:, :)
    real(wp), allocatable :: jst(:, :)      !! J S as rows (4 k, neq)
    real(wp), allocatable :: y3(:)          !! (nq) one parameter's J_p^T lambda
    !> a whole solution [S_ddot; dlambda] as rows (4 k, nq + na) (an output's multipliers)
    real(wp), allocatable :: xl(:, :)
  end type proj_work_t

  !> Work of sens_out_multipliers (lam_init, once per run): S, S_dot, S_ddot as rows (flat,
  !! npd nq) and as columns (nq, np) in the core's units, q_ddot and lambda; lunit (neq, np)
  !! dlambda/dp in model units from the core's (pscale / rowunit, exact powers of 2).
  type :: lam_work_t
    type(proj_work_t) :: pw
    real(wp), allocatable :: st(:), sdt(:), cq(:, :), cqd(:, :), cqdd(:, :), aa(:), lam(:)
    real(wp), allocatable :: lunit(:, :)
  end type lam_work_t

contains

  !> Allocate project_sens's work for model m, the active rows of w and np parameters.
  subroutine proj_init(m, w, np, pw, status, msg)
    type(model_t), intent(in) :: m              !! model
    type(dyn_work_t), intent(in) :: w           !! dynamics work arrays (dyn_init done)
    integer, intent(in) :: np                   !! parameters
    type(proj_work_t), intent(out) :: pw        !! the work
    integer, intent(out) :: status              !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer :: st, nt
    status = MBD_OK; msg = ''
    nt = m%nq + w%na
    allocate (pw%rt(4 * ((np + 3) / 4), nt), pw%jst(4 * ((np + 3) / 4), m%neq), pw%y3(m%nq), &
              pw%xl(4 * ((np + 3) / 4), nt), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the sensitivity projections'
      return
    end if
    pw%rt = zero; pw%xl = zero
  end subroutine proj_init

  !> dlambda/dp (neq, np) at one output of an inverse dynamics run, from the kinematic
  !! sensitivities sq, sqd, sqdd (nq, np) there: J^T dlambda = b as the multipliers were
  !! solved. Dense path: jac is J at q (with jtlu, jtpiv the LU of J^T dyn_multipliers took);
  !! band path (sw, no dense J): the saddle-point factors dyn_multipliers left in sw at this
  !! state, [s I, s J_a^T; s J_a, 0][x; y] = [b; 0], dlambda = s y on the active rows (the
  !! multipliers' own solve: J_a square, x = 0 and J_a^T dlambda = b).
  subroutine sens_multipliers(m, s, q, qd, qdd, t, jac, lam, sq, sqd, sqdd, slam, status, msg, &
                              jtlu, jtpiv, sw)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    real(wp), intent(in) :: q(:), qd(:), qdd(:) !! state and accelerations
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(in), optional :: jac(:, :) !! J at q (neq, nq): the dense path
    real(wp), intent(in) :: lam(:)              !! multipliers (neq)
    real(wp), intent(in) :: sq(:, :), sqd(:, :), sqdd(:, :)  !! (nq, np)
    real(wp), intent(out) :: slam(:, :)         !! (neq, np)
    integer, intent(out) :: status              !! MBD_OK or MBD_LAPACK / MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    !> the LU of J^T with its pivots (dyn_multipliers' at the same state, when it took one)
    real(wp), intent(in), optional :: jtlu(:, :)
    integer, intent(in), optional :: jtpiv(:)
    type(dyn_work_t), intent(inout), optional :: sw  !! the band path's work (see above)
    real(wp), allocatable :: work(:)
    logical :: full
    real(wp) :: wq(1), umin, umax
    integer :: k, i, nq, neq, np, rank, info, st, nd, ed
    status = MBD_OK; msg = ''
    nq = m%nq; neq = m%neq; np = s%np
    slam = zero
    if (np == 0) return
    if (.not. allocated(s%mb)) then            ! (once: the work of every later output)
      nd = 1; ed = 1
      if (.not. present(sw)) then              ! (J^T dense: not on the band path)
        nd = nq; ed = neq
      end if
      allocate (s%mjt(nd, ed), s%mb(max(nq, neq), np), s%my(nq), s%myf(nq, np), &
                s%mpiv(max(nq, neq)), s%mbb(max(nq, neq), np), stat=st)
      if (st /= 0) then
        status = MBD_NO_MEMORY; msg = 'out of memory for the multiplier sensitivities'; return
      end if
    end if
    associate (jt => s%mjt, b => s%mb, y => s%my, yf => s%myf, jpvt => s%mpiv, bb => s%mbb)
      call sens_trig(m, s, q)
      call sens_hessian(m, s, q, qd, qdd, t)
      call sens_klam_list(m, s, lam)
      b = zero
      call sens_force_dm(m, s, 1, np, q, qd, nq, sq, sqd, t, yf)   ! Q_q s + Q_qd s_dot + Q_p
      do k = 1, np
        b(1:nq, k) = yf(:, k) - s%tmass(:, k) * qdd - m%mdiag * sqdd(:, k)
        call sens_klam(s, sq(:, k), y)
        b(1:nq, k) = b(1:nq, k) - y
        call sens_jpt_lam(m, s, k, q, t, lam, y)
        b(1:nq, k) = b(1:nq, k) - y
      end do
      if (present(sw)) then                    ! the band path: the saddle-point factors
        do k = 1, np
          sw%rhs(1:nq) = b(1:nq, k); sw%rhs(nq + 1:) = zero
          call dyn_solve(sw, sw%rhs, status)
          if (status /= MBD_OK) then
            msg = 'the multipliers'' sensitivities: the band saddle-point solve failed'; return
          end if
          do i = 1, sw%na
            slam(sw%rows(i), k) = sw%s * sw%rhs(nq + i)
          end do
        end do
        return
      end if
      if (present(jtlu) .and. present(jtpiv)) then   ! dyn_multipliers' LU, trusted there
        do k = 1, np
          call lu_solve_small(jtlu, jtpiv, b(1:nq, k))
        end do
        slam = b(1:neq, :); return
      end if
      if (neq == nq) then
        ! square J (a driven mechanism): J^T dlambda = b by an LU of J^T with partial
        ! pivoting, trusted when its pivot ratio is above the QR's rank threshold (as
        ! dyn_multipliers); otherwise the least squares below
        jt = transpose(jac)
        call lu_factor_small(jt, jpvt(1:nq), st)
        if (st == MBD_OK) then
          umin = huge(one); umax = zero
          do k = 1, nq
            umin = min(umin, abs(jt(k, k))); umax = max(umax, abs(jt(k, k)))
          end do
          if (umin >= LS_RTOL * umax) then
            do k = 1, np
              call lu_solve_small(jt, jpvt(1:nq), b(1:nq, k))
            end do
            slam = b(1:neq, :); return
          end if
        end if
      end if
      ! J^T dlambda = b: Householder least squares (independent rows, the unique solution),
      ! or the minimum-norm one by dgelsy when J^T is rank deficient (redundant rows)
      if (neq <= nq) then
        jt = transpose(jac)
        bb = b
        call ls_small_cols(jt, bb, full)
        if (full) then
          slam = bb(1:neq, :); return
        end if
      end if
      jt = transpose(jac)
      jpvt = 0
      call dgelsy(nq, neq, np, jt, nq, b, size(b, 1), jpvt, 1.0e-10_wp, rank, wq, -1, info)
      allocate (work(max(1, int(wq(1)))), stat=st)
      if (st /= 0) then
        status = MBD_NO_MEMORY; msg = 'out of memory for the multiplier sensitivities'; return
      end if
      call dgelsy(nq, neq, np, jt, nq, b, size(b, 1), jpvt, 1.0e-10_wp, rank, work, &
                  size(work), info)
      call lapack_status('dgelsy', info, status, msg)
      slam = b(1:neq, :)
    end associate
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
    integer :: k, c, r0, nr, j, b, off, st
    character(len=MSG_LEN) :: lmsg
    dreac = zero; drloc = zero
    call asm_init(m, a, st, lmsg)
    if (st /= MBD_OK) return
    call assemble_blocks(m, q, s%zq, t, phi, nu, gam, a)
    call sens_trig(m, s, q)
    call sens_hessian(m, s, q, s%zq, s%zq, t)
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
          dj = dj + s%hs(:, :, j, c) * sl(j)
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
    real(wp), allocatable :: kk(:, :), kq(:, :), aug(:, :), rhs(:), y(:), e(:), &
                             phi(:), nu(:), gam(:), jac(:, :), z(:)
    integer, allocatable :: ipiv(:)
    integer :: n, na, i, k, st
    status = MBD_OK; msg = ''
    n = m%nq; na = size(rows)
    sq = zero; slam = zero
    allocate (kk(n, n), kq(n, n), aug(n + na, n + na), rhs(n + na), y(n), e(n), &
              phi(m%neq), nu(m%neq), gam(m%neq), jac(m%neq, n), &
              z(n), ipiv(n + na), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the statics sensitivities'; return
    end if
    z = zero
    call asm_init(m, a, status, msg)
    if (status /= MBD_OK) return
    call assemble_dense(m, q, z, t, phi, nu, gam, a, jac)
    call sens_at_rest(m, s, q, t, lam, z)
    ! K = K_lam - Q_q, column by column
    call sens_force_jac(m, q, z, t, kq)
    do i = 1, n
      e = zero; e(i) = one
      call sens_klam(s, e, y)
      kk(:, i) = y - kq(:, i)
    end do
    aug = zero
    aug(1:n, 1:n) = kk
    aug(1:n, n + 1:) = transpose(jac(rows, :))
    aug(n + 1:, 1:n) = jac(rows, :)
    call lu_factor(aug, ipiv, status, msg)
    if (status /= MBD_OK) then
      msg = NOT_ISOLATED; return
    end if
    do k = 1, s%np
      call statics_load(m, s, k, q, t, lam, z, y, rhs(1:n))
      rhs(n + 1:) = s%mphip(k, rows)
      call lu_solve(aug, ipiv, rhs, status, msg)
      if (status /= MBD_OK) return
      sq(:, k) = rhs(1:n)
      slam(rows, k) = rhs(n + 1:)
    end do
  end subroutine sens_statics

  !> The equilibrium's load along parameter k: r = Q_p - J_p^T lambda (z: zeros, y: work).
  subroutine statics_load(m, s, k, q, t, lam, z, y, r)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    integer, intent(in) :: k                    !! parameter
    real(wp), intent(in) :: q(:), t, lam(:), z(:)  !! equilibrium, time, multipliers, zeros
    real(wp), intent(out) :: y(:), r(:)         !! work; the load (nq)
    call sens_force_d(m, s, k, q, z, z, z, t, r)          ! Q_p
    call sens_jpt_lam(m, s, k, q, t, lam, y)
    r = r - y
  end subroutine statics_load

  !> sens_statics on the band path (no n x n array): the differentiated equilibrium in its
  !! null-space form, N (nq, ni) an orthonormal basis of J_a's null space (dyn_null_basis):
  !!   s = s_n + N z,  J_a s_n = -Phi_p,a (minimum norm),
  !!   (N^T K N) z = N^T (r - K s_n),  r = Q_p - J_p^T lambda,  K = K_lambda - Q_q,
  !! then J_a^T dlambda_a = r - K s (in J_a^T's range at the solution). s_n and dlambda from
  !! the saddle-point factors of the minimum-norm projection s [I J_a^T; J_a 0]; K x exact:
  !! K_lambda x (sens_klam) - Q_q x (sens_force_d without a parameter). Work O(nq ni) and
  !! ni^3, as the band path's statics.
  subroutine sens_statics_band(m, w, s, q, t, lam, sq, slam, status, msg)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! dynamics work arrays on the band path
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    real(wp), intent(in) :: q(:), t             !! equilibrium and time
    real(wp), intent(in) :: lam(:)              !! multipliers (neq)
    real(wp), intent(out) :: sq(:, :)           !! dq/dp (nq, np)
    real(wp), intent(out) :: slam(:, :)         !! dlambda/dp (neq, np)
    integer, intent(out) :: status              !! MBD_OK, MBD_SINGULAR or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    real(wp), allocatable :: nb(:, :), kn(:, :), h(:, :), r(:), y(:), x(:), z(:), zz(:)
    integer, allocatable :: ipiv(:)
    integer :: n, ni, na, i, k, st
    status = MBD_OK; msg = ''
    n = m%nq; na = w%na; ni = n - na
    sq = zero; slam = zero
    call mem_check(REAL_BYTES * (2 * real(n, wp) * max(ni, 1) + real(ni, wp)**2), &
                   'the statics sensitivities (band path)', 'use fewer free motions', &
                   status, msg)
    if (status /= MBD_OK) return
    allocate (nb(n, max(ni, 1)), kn(n, max(ni, 1)), h(max(ni, 1), max(ni, 1)), r(n), y(n), &
              x(n), z(n), zz(max(ni, 1)), ipiv(max(ni, 1)), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the statics sensitivities'; return
    end if
    z = zero
    call sens_at_rest(m, s, q, t, lam, z)
    if (ni > 0) then                            ! H = N^T K N on the free motions
      call dyn_null_basis(m, w, q, t, nb, status)
      if (status /= MBD_OK) then
        msg = 'statics sensitivities: no basis of the free motions'; return
      end if
      do i = 1, ni
        call kmul(nb(:, i), kn(:, i))
      end do
      h = matmul(transpose(nb), kn)
      call lu_factor(h, ipiv, status, msg)
      if (status /= MBD_OK) then
        msg = NOT_ISOLATED; return
      end if
    end if
    call dyn_factor_projection(m, w, q, t, .false., status)
    if (status /= MBD_OK) then
      msg = 'statics sensitivities: the projection onto the constraints is singular'; return
    end if
    do k = 1, s%np
      ! r = Q_p - J_p^T lambda; s_n: J_a s_n = -Phi_p,a (minimum norm)
      call statics_load(m, s, k, q, t, lam, z, y, r)
      call proj_particular(w, s, k, sq(:, k), status)
      if (status /= MBD_OK) exit
      if (ni > 0) then                          ! + N z, (N^T K N) z = N^T (r - K s_n)
        call kmul(sq(:, k), y)
        zz = matmul(r - y, nb(:, 1:ni))
        call lu_solve(h, ipiv, zz, status, msg)
        if (status /= MBD_OK) return
        sq(:, k) = sq(:, k) + matmul(nb(:, 1:ni), zz)
      end if
      ! J_a^T dlambda = r - K s: the projection's least squares (x = 0 at the solution)
      call kmul(sq(:, k), y)
      call proj_multipliers(w, r - y, slam(:, k), status)
      if (status /= MBD_OK) exit
    end do
    if (status /= MBD_OK) msg = 'statics sensitivities: a band saddle-point solve failed'
  contains
    !> kx = K x (exact, sens_stiffness_mul).
    subroutine kmul(xx, kx)
      real(wp), intent(in) :: xx(:)
      real(wp), intent(out) :: kx(:)
      call sens_stiffness_mul(m, s, q, t, z, xx, kx, x)
    end subroutine kmul
  end subroutine sens_statics_band

  !> x: the minimum-norm solution of J_a x = -Phi_p,a for parameter k, by the factors of
  !! the projection [I J_a^T; J_a 0] (dyn_factor_projection with the unit metric done).
  subroutine proj_particular(w, s, k, x, status)
    type(dyn_work_t), intent(inout) :: w        !! work arrays with the projection's factors
    type(sens_t), intent(in) :: s               !! parameters (-Phi_p in mphip)
    integer, intent(in) :: k                    !! parameter
    real(wp), intent(out) :: x(:)               !! (nq) the solution
    integer, intent(out) :: status              !! MBD_OK or the solve's status
    integer :: i, n
    n = size(x)
    w%rhs(1:n) = zero
    do i = 1, w%na
      w%rhs(n + i) = w%s * s%mphip(k, w%rows(i))
    end do
    call dyn_solve(w, w%rhs, status)
    x = w%rhs(1:n)
  end subroutine proj_particular

  !> mu on the active rows (zero elsewhere untouched): the least squares of J_a^T mu = b by
  !! the projection's factors (the remainder b - J_a^T mu is the part of b in J_a's null
  !! space, zero when b lies in J_a^T's range).
  subroutine proj_multipliers(w, b, mu, status)
    type(dyn_work_t), intent(inout) :: w        !! work arrays with the projection's factors
    real(wp), intent(in) :: b(:)                !! (nq) the right-hand side
    real(wp), intent(inout) :: mu(:)            !! (neq) the multipliers (active rows set)
    integer, intent(out) :: status              !! MBD_OK or the solve's status
    integer :: i, n
    n = size(b)
    w%rhs(1:n) = b; w%rhs(n + 1:) = zero
    call dyn_solve(w, w%rhs, status)
    do i = 1, w%na
      mu(w%rows(i)) = w%s * w%rhs(n + i)
    end do
  end subroutine proj_multipliers

  !> The blocks of the linearization at a rest state q with multipliers lam: the trig
  !! factors, the constraints' Hessians, the parameters' derivatives and the K_lambda list
  !! (z: zeros, the velocities and accelerations).
  subroutine sens_at_rest(m, s, q, t, lam, z)
    type(model_t), intent(in) :: m              !! model
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    real(wp), intent(in) :: q(:), t, lam(:), z(:)  !! rest state, time, multipliers, zeros
    call sens_stiffness_at(m, s, q, t, lam, z)
    call sens_params(m, s, q, z, z, t)
  end subroutine sens_at_rest

  !> The blocks of the stiffness alone at the rest state (q, t, lam): the bodies' cos and sin,
  !! the constraints' second derivatives and K_lambda's list (sens_stiffness_mul's; no
  !! parameters' blocks, which sens_at_rest adds).
  subroutine sens_stiffness_at(m, s, q, t, lam, z)
    type(model_t), intent(in) :: m              !! model
    type(sens_t), intent(inout) :: s            !! blocks
    real(wp), intent(in) :: q(:), t, lam(:), z(:)  !! rest state, time, multipliers, zeros
    call sens_trig(m, s, q)
    call sens_hessian(m, s, q, z, z, t)
    call sens_klam_list(m, s, lam)
  end subroutine sens_stiffness_at

  !> kx = K x = K_lambda x - Q_q x at the rest state q (exact; sens_klam_list done; z zeros,
  !! work nq entries).
  subroutine sens_stiffness_mul(m, s, q, t, z, x, kx, work)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(sens_t), intent(in) :: s               !! parameters and blocks
    real(wp), intent(in) :: q(:), t, z(:), x(:) !! state, time, zeros, the vector
    real(wp), intent(out) :: kx(:), work(:)     !! K x; work
    call sens_klam(s, x, kx)
    call sens_force_d(m, s, 0, q, z, x, z, t, work)
    kx = kx - work
  end subroutine sens_stiffness_mul

  !> K and C exactly on the sparse pattern of dyn_tangent (w%kptr, w%krow), kv(p) =
  !! K(krow(p), c), cv likewise (absent: K alone): one product with K (and C) per colour group
  !! of the pattern, x = the sum of the group's unit vectors, whose columns do not share a row,
  !! so each entry is read off its own column (Curtis, Powell and Reid's grouping, applied to
  !! exact products: sens_stiffness_mul, sens_damping_mul). x, y, work: (nq); z zeros.
  !! The assembled K loses accuracy on smooth vectors that the element-wise product keeps
  !! (K x of a long spring chain's lowest shape: 2 x_i - x_(i-1) - x_(i+1) summed from
  !! entries, not k (x_i - x_(i-1)) per spring; its lowest frequency 3.7e-11 instead of
  !! 6.7e-12): for a Newton matrix (the statics' steps), not for the modes' K_r.
  subroutine sens_tangent_pattern(m, w, s, q, t, z, kv, x, y, work, cv)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(in) :: w           !! the pattern and its groups (dyn_init)
    type(sens_t), intent(in) :: s               !! blocks at the rest state (sens_stiffness_at)
    real(wp), intent(in) :: q(:), t, z(:)       !! state, time, zeros
    real(wp), intent(out) :: kv(:)              !! K on the pattern
    real(wp), intent(out) :: x(:), y(:), work(:)  !! work (nq)
    real(wp), intent(out), optional :: cv(:)    !! C on the pattern
    integer :: g, i
    kv = zero
    if (present(cv)) cv = zero
    x = zero
    do g = 1, w%ncolor
      do i = w%gptr(g), w%gptr(g + 1) - 1
        x(w%gcol(i)) = one
      end do
      call sens_stiffness_mul(m, s, q, t, z, x, y, work)
      call pattern_put(kv)
      if (present(cv)) then
        call sens_damping_mul(m, s, q, t, z, x, y)
        call pattern_put(cv)
      end if
      do i = w%gptr(g), w%gptr(g + 1) - 1
        x(w%gcol(i)) = zero
      end do
    end do
  contains
    !> av(p) = y(krow(p)) over the columns of group g.
    subroutine pattern_put(av)
      real(wp), intent(inout) :: av(:)
      integer :: i, c, p
      do i = w%gptr(g), w%gptr(g + 1) - 1
        c = w%gcol(i)
        do p = w%kptr(c), w%kptr(c + 1) - 1
          av(p) = y(w%krow(p))
        end do
      end do
    end subroutine pattern_put
  end subroutine sens_tangent_pattern

  !> cx = C x = -Q_q_dot x at the rest state q (exact; z zeros, nq entries).
  subroutine sens_damping_mul(m, s, q, t, z, x, cx)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(sens_t), intent(in) :: s               !! parameters and blocks
    real(wp), intent(in) :: q(:), t, z(:), x(:) !! state, time, zeros, the vector
    real(wp), intent(out) :: cx(:)              !! C x
    call sens_force_d(m, s, 0, q, z, z, x, t, cx)
    cx = -cx
  end subroutine sens_damping_mul

  !> Forward dynamics with sensitivities by dopri5 from the consistent state (q, qd) at t0 and
  !! its sensitivities (sq, sqd) (nq, np); outputs as mbd_integrators' integrate, with
  !! so, sdo, sddo (nq, np, rows) the sensitivities of q, q_dot, q_ddot (in model units,
  !! s%ounit; the state's outputs in the core's).
  !! stats: 1 steps, 2 rejected, 3 right-hand sides; hmm(1:2) smallest and largest step.
  subroutine sens_dopri5(m, w, s, q, qd, sq, sqd, t0, t1, nsteps, every, rtol, atol, &
                         max_steps, qo, vo, ao, so, sdo, sddo, lo, lok, nout, stats, hmm, &
                         t_fail, t_stiff, status, msg, slo, lunit)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! dynamics work arrays (dyn_init done)
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    real(wp), intent(inout) :: q(:), qd(:)      !! consistent state at t0, then final
    real(wp), intent(inout) :: sq(:, :), sqd(:, :)  !! its sensitivities (nq, np), then final
    real(wp), intent(in) :: t0, t1              !! time span
    integer, intent(in) :: nsteps, every        !! output intervals, decimation
    real(wp), intent(in) :: rtol, atol          !! tolerances (all components)
    integer, intent(in) :: max_steps            !! step limit
    !> the outputs (rows 1 .. nout written; the others left as the caller set them, its
    !! zeros: the output arrays are the run's largest, not filled twice)
    real(wp), intent(inout) :: qo(:, :), vo(:, :), ao(:, :)       !! (nq, rows)
    real(wp), intent(inout) :: so(:, :, :), sdo(:, :, :), sddo(:, :, :)  !! (nq, np, rows)
    !> multipliers at the outputs (neq, rows), those of the index-1 solve at the output's
    !! state where lok (independent rows, a regular solve); elsewhere the caller finds them
    real(wp), intent(inout) :: lo(:, :)
    logical, intent(out) :: lok(:)
    integer, intent(out) :: nout                !! rows written
    integer, intent(out) :: stats(3)            !! steps, rejected, right-hand sides
    real(wp), intent(out) :: hmm(2)             !! smallest, largest step
    real(wp), intent(out) :: t_fail             !! time reached at a failure
    !> the time from which the steps were limited by stability (stiffness_test; huge when
    !! they were not)
    real(wp), intent(out) :: t_stiff
    integer, intent(out) :: status              !! MBD_OK or a failure
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    !> dlambda/dp at the outputs (neq, np, rows; model units, each entry times lunit's
    !! (neq, np)) where lok (the others: sens_out_multipliers)
    real(wp), intent(inout), optional, contiguous :: slo(:, :, :)
    real(wp), intent(in), optional :: lunit(:, :)
    real(wp), allocatable :: y(:), yn(:), ys(:), k(:, :), e(:), zdda(:), lam(:), yt(:), &
                             zz(:), zzd(:), zzdd(:)
    ! the work of rhs and project (here, so that no step allocates)
    real(wp), allocatable :: qq(:), vv(:), aa(:), v0(:), fo(:)
    type(proj_work_t) :: pw
    real(wp) :: t, h, tnew, err, fac, sc, tend
    integer :: n, np, npd, nz, st, kout, nreal, hits, calm
    logical :: fsal, stiff, land
    status = MBD_OK; msg = ''; nout = 0; stats = 0; hmm = [huge(one), zero]; t_fail = t0
    t_stiff = huge(one); hits = 0; calm = 0
    lok = .false.
    ! the packed state (q, S, q_dot, S_dot) holds S and S_dot as rows (npd, n), npd = np
    ! rounded up to a multiple of 4 (the padding rows stay zero: no rate, no error)
    n = m%nq; np = s%np; npd = 4 * ((np + 3) / 4); nz = n * (1 + npd)
    nreal = 2 * n * (1 + np)
    if (.not. (rtol > zero .and. atol > zero) .or. every < 1 .or. &
        size(qo, 2) /= output_rows(nsteps, every)) then
      status = MBD_BAD_SETTING; msg = 'rtol, atol > 0, every >= 1 and outputs sized for it'
      return
    end if
    allocate (y(2 * nz), yn(2 * nz), ys(2 * nz), k(2 * nz, 7), e(2 * nz), &
              zdda(nz), lam(m%neq), zz(nz), zzd(nz), zzdd(nz), qq(n), vv(n), aa(n), v0(n), &
              fo(2 * nz), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the sensitivity integration'; return
    end if
    call proj_init(m, w, s%np, pw, status, msg)
    if (status /= MBD_OK) return
    y = zero
    y(1:n) = q; y(nz + 1:nz + n) = qd
    call cols_to_rows(n, np, npd, n, sq, y(n + 1:nz))
    call cols_to_rows(n, np, npd, n, sqd, y(nz + n + 1:))
    t = t0
    call rhs(t, y, k(:, 1), st)
    if (st == MBD_OK) then
      lo(:, 1) = lam; lok(1) = w%na == m%neq .and. .not. w%lsq
      ! (the start's multipliers' sensitivities: one whole solve more)
      if (lok(1) .and. present(slo)) call out_lambda(1, t, y(1:nz), y(nz + 1:), zzdd, st)
    end if
    if (st /= MBD_OK) then
      status = st; msg = 'the mass matrix and constraints give a singular system at the start'
      return
    end if
    zdda = k(nz + 1:, 1)
    call put(1, y(1:nz), y(nz + 1:), zdda)
    nout = 1; kout = 1
    fsal = .true.
    if (nsteps == 0) return
    sc = maxval(abs(zdda) / (atol + rtol * abs(y(1:nz))))
    h = (t1 - t0) / nsteps
    if (sc > zero) h = min(h, 0.1_wp * sqrt(one / sc))
    h = max(h, 1.0e-10_wp * abs(t1 - t0))
    do while (t < t1 - 1.0e-14_wp * abs(t1 - t0))
      if (stats(1) + stats(2) >= max_steps) then
        status = MBD_INTEGRATOR_FAILED
        write (msg, '(a,i0,a,es12.5)') 'more than ', max_steps, ' steps before t = ', t
        return
      end if
      t_fail = t
      h = min(h, t1 - t)
      tnew = t + h
      ! (a step ending on a breakpoint takes its stages there from the left)
      call break_step(m, t, t1, h, tnew, land)
      tend = merge(nearest(tnew, -one), tnew, land)
      call step(st)
      ! (a non-finite yn makes the norm non-finite: each stage that enters yn enters e, the
      ! 5th and 4th order weights differing on all of them; one test on err, not one per
      ! component of the five times longer state)
      err = 10.0_wp
      if (st == MBD_OK) err = sqrt(sum((e / (atol + rtol * max(abs(y), abs(yn))))**2) / nreal)
      if (.not. ieee_is_finite(err)) err = 10.0_wp
      if (err > one) then
        stats(2) = stats(2) + 1
        fsal = .false.
        h = h * max(0.2_wp, 0.9_wp * err**(-0.2_wp))
        if (h < 1.0e-14_wp * max(one, abs(t))) then
          status = MBD_INTEGRATOR_FAILED
          write (msg, '(a,es12.5)') 'step size underflow at t = ', t
          return
        end if
        cycle
      end if
      if (t_stiff >= huge(one)) then          ! (the stages as the step left them)
        call stiffness_test(stats(1), h, k, yn, ys, hits, calm, stiff)
        if (stiff) t_stiff = tnew
      end if
      ! accepted: project onto the constraints (state and sensitivities), then the rates
      call project(tnew, yn, st)
      if (st == MBD_OK) call rhs(tnew, yn, k(:, 1), st)
      if (st /= MBD_OK) then
        status = MBD_INTEGRATOR_FAILED
        write (msg, '(a,es12.5)') 'the constraints could not be satisfied after the step '// &
          'to t = ', tnew
        return
      end if
      fsal = .true.
      if (land) then
        ! the step's interpolant ends with the left limits of the accelerations (in e)
        call rhs(tend, yn, e, st)
        if (st /= MBD_OK) e = k(:, 1)
        call emit(t, tnew, e(nz + 1:))
      else
        call emit(t, tnew, k(nz + 1:, 1))
      end if
      zdda = k(nz + 1:, 1)
      stats(1) = stats(1) + 1
      hmm = [min(hmm(1), h), max(hmm(2), h)]
      t = tnew
      call move_alloc(y, yt); call move_alloc(yn, y); call move_alloc(yt, yn)   ! y = yn
      fac = min(5.0_wp, max(0.2_wp, 0.9_wp * max(err, 1.0e-10_wp)**(-0.2_wp)))
      h = h * fac
    end do
    q = y(1:n); qd = y(nz + 1:nz + n)
    call rows_to_cols(n, np, npd, y(n + 1:nz), sq)
    call rows_to_cols(n, np, npd, y(nz + n + 1:), sqd)
  contains

    !> One Dormand-Prince step from (t, y) with k(:, 1) = f(t, y) known: yn, e.
    subroutine step(stp)
      integer, intent(out) :: stp
      integer :: j
      if (.not. fsal) then
        call rhs(t, y, k(:, 1), stp)
        if (stp /= MBD_OK) return
      end if
      ! the stages' states in ys (expressions as arguments would be heap temporaries)
      do j = 2, 6
        call dopri5_state(j, y, h, k, ys)
        call rhs(merge(tend, t + DOPRI_C(j) * h, DOPRI_C(j) >= one), ys, k(:, j), stp)
        if (stp /= MBD_OK) return
      end do
      call dopri5_state(7, y, h, k, yn)
      call rhs(tend, yn, k(:, 7), stp)
      if (stp /= MBD_OK) return
      call dopri5_error(h, k, e)
    end subroutine step

    !> f(t, y): (z_dot, z_ddot), z = (q, S): q_ddot from the index-1 system, each S_ddot from
    !! its differentiation with the same factors (S, S_dot and S_ddot as rows; sens_accel's
    !! steps, written out: the stages' calls are the run's most frequent).
    subroutine rhs(tt, yy, f, stp)
      real(wp), intent(in) :: tt
      real(wp), intent(in), contiguous :: yy(:)
      real(wp), intent(out), contiguous :: f(:)
      integer, intent(out) :: stp
      stats(3) = stats(3) + 1
      associate (qs => yy(1:n), vs => yy(nz + 1:nz + n))
      call dyn_accel(m, w, qs, vs, tt, aa, lam, stp)
      if (stp /= MBD_OK) return
      f(1:nz) = yy(nz + 1:)
      f(nz + 1:nz + n) = aa
      call sens_dyn_rows(m, w, s, pw, qs, vs, aa, lam, tt, npd, yy(n + 1:nz), yy(nz + n + 1:), &
                         .true.)
      call constraint_rows(n, w%na, npd, m%neq, w%rows, w%s, s%rhs, pw%rt)
      call dyn_solve_rows(w, pw%rt, np, n, npd, f(nz + n + 1:), .false., stp)   ! S_ddot rows
      end associate
    end subroutine rhs

    !> Project q, q_dot (mbd_dynamics) and then S, S_dot (project_sens).
    subroutine project(tt, yy, stp)
      real(wp), intent(in) :: tt
      ! (contiguous as project_sens's: a plain yy(:) was packed into a heap copy each step)
      real(wp), intent(inout), contiguous :: yy(:)
      integer, intent(out) :: stp
      qq = yy(1:n); v0 = yy(nz + 1:nz + n)
      call dyn_project_pos(m, w, qq, tt, stp)
      if (stp /= MBD_OK) return
      call dyn_velocity(m, w, qq, tt, v0, vv, stp)
      if (stp /= MBD_OK) return
      yy(1:n) = qq; yy(nz + 1:nz + n) = vv
      call project_sens(m, w, s, tt, yy, pw, .true., stp)
    end subroutine project

    !> The stored outputs in (ta, tb] by quintic Hermite interpolation of z = (q, S) between
    !! the step's start (y, zdda) and end (yn, ab: k(:, 1)'s accelerations, or their left
    !! limits at a breakpoint the step ends on).
    subroutine emit(ta, tb, ab)
      real(wp), intent(in) :: ta, tb
      real(wp), intent(in) :: ab(:)   !! the accelerations the interpolant ends with
      real(wp) :: tk
      do while (kout <= nsteps)
        tk = t0 + (t1 - t0) * (real(kout, wp) / nsteps)
        if (kout == nsteps) tk = t1
        if (tk > tb + 1.0e-12_wp * abs(t1 - t0)) exit
        if (mod(kout, every) == 0 .or. kout == nsteps) then
          call hermite5(ta, y(1:nz), y(nz + 1:), zdda, tb, yn(1:nz), yn(nz + 1:), ab, tk, zz, &
                        zzd, zzdd)
          nout = nout + 1
          call at_state(nout, tk)
          call put(nout, zz, zzd, zzdd)
        end if
        kout = kout + 1
      end do
    end subroutine emit

    !> The accelerations (q_ddot and S_ddot) and multipliers of an output from the index-1
    !! equations at its interpolated state (zz, zzd), as mbd_integrators' finish_outputs
    !! for the state alone (an interpolant of the accelerations errs about 100x more); the
    !! interpolant's zzdd stays where the solve fails there.
    subroutine at_state(row, tk)
      integer, intent(in) :: row
      real(wp), intent(in) :: tk
      integer :: stp
      call out_lambda(row, tk, zz, zzd, fo, stp)
      if (stp /= MBD_OK) return
      zzdd(1:n) = aa; zzdd(n + 1:) = fo(1:nz - n)
    end subroutine at_state

    !> The index-1 solve at the output state (z, zd) (q and S as rows, flat), whole
    !! (sens_accel): q_ddot to aa, S_ddot's rows to sdd, the multipliers to lo, lok and,
    !! with independent rows, their sensitivities to slo.
    subroutine out_lambda(row, tk, z, zd, sdd, stp)
      integer, intent(in) :: row
      real(wp), intent(in) :: tk
      real(wp), intent(in), contiguous :: z(:), zd(:)
      real(wp), intent(inout), contiguous :: sdd(:)
      integer, intent(out) :: stp
      call sens_accel(m, w, s, pw, z(1:n), zd(1:n), tk, npd, z(n + 1:), zd(n + 1:), aa, &
                           lam, stp, sdd)
      if (stp /= MBD_OK) return
      lo(:, row) = lam; lok(row) = w%na == m%neq .and. .not. w%lsq
      if (lok(row) .and. present(slo)) &
        call lambda_cols(n, np, npd, w%na, m%neq, w%rows, w%s, pw%xl, lunit, slo(:, :, row))
    end subroutine out_lambda

    subroutine put(row, z1, z2, z3)
      integer, intent(in) :: row
      real(wp), intent(in) :: z1(:), z2(:), z3(:)
      qo(:, row) = z1(1:n); vo(:, row) = z2(1:n); ao(:, row) = z3(1:n)
      ! (the sensitivities in model units: ounit, exact powers of 2)
      call rows_to_cols(n, np, npd, z1(n + 1:), so(:, :, row), s%ounit)
      call rows_to_cols(n, np, npd, z2(n + 1:), sdo(:, :, row), s%ounit)
      call rows_to_cols(n, np, npd, z3(n + 1:), sddo(:, :, row), s%ounit)
    end subroutine put
  end subroutine sens_dopri5

  !> Allocate sens_out_multipliers' work for model m, the active rows of w and the
  !! parameters of s.
  subroutine lam_init(m, w, s, lw, status, msg)
    type(model_t), intent(in) :: m              !! model
    type(dyn_work_t), intent(in) :: w           !! dynamics work arrays (dyn_init done)
    type(sens_t), intent(in) :: s               !! parameters
    type(lam_work_t), intent(out) :: lw         !! the work
    integer, intent(out) :: status              !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer :: st, nz, np, k
    np = s%np
    call proj_init(m, w, np, lw%pw, status, msg)
    if (status /= MBD_OK) return
    nz = 4 * ((np + 3) / 4) * m%nq
    allocate (lw%st(nz), lw%sdt(nz), lw%cq(m%nq, np), lw%cqd(m%nq, np), lw%cqdd(m%nq, np), &
              lw%aa(m%nq), lw%lam(m%neq), lw%lunit(m%neq, np), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the multipliers'' sensitivities'
      return
    end if
    do k = 1, np
      lw%lunit(:, k) = s%pscale(k) / m%rowunit
    end do
  end subroutine lam_init

  !> The multipliers of a forward dynamics output at (q, qd, t) and their sensitivities
  !! along (S, S_dot) = (sq, sqd) (nq, np; model units, s%ounit): lambda as the outputs take
  !! it (the index-1 solve's with independent rows, else the minimum-norm set of
  !! dyn_multipliers), dlambda/dp (neq, np; model units) its derivative. From the whole
  !! solve of the sensitivities' saddle system (sens_accel); with redundant rows on the
  !! dense path the minimum-norm solution of J^T dlambda = b (sens_multipliers, as inverse
  !! dynamics), b from that solve's S_ddot. status: the solves' (MBD_OK or a failure).
  subroutine sens_out_multipliers(m, w, s, lw, q, qd, t, sq, sqd, lam, slam, status, msg)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! dynamics work arrays
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    type(lam_work_t), intent(inout) :: lw       !! work (lam_init)
    real(wp), intent(in), contiguous :: q(:), qd(:)  !! the output's state (core units)
    real(wp), intent(in) :: t                   !! its time
    real(wp), intent(in) :: sq(:, :), sqd(:, :) !! its sensitivities (nq, np), model units
    real(wp), intent(out) :: lam(:)             !! multipliers (neq)
    real(wp), intent(out) :: slam(:, :)         !! dlambda/dp (neq, np)
    integer, intent(out) :: status              !! MBD_OK or a failure
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer :: n, np, npd
    n = m%nq; np = s%np; npd = 4 * ((np + 3) / 4)
    msg = ''
    lw%cq = sq / s%ounit; lw%cqd = sqd / s%ounit
    call cols_to_rows(n, np, npd, n, lw%cq, lw%st)
    call cols_to_rows(n, np, npd, n, lw%cqd, lw%sdt)
    call sens_accel(m, w, s, lw%pw, q, qd, t, npd, lw%st, lw%sdt, lw%aa, lw%lam, status)
    if (status /= MBD_OK) then
      msg = 'the index-1 equations are singular'; return
    end if
    lam = lw%lam
    call lambda_cols(n, np, npd, w%na, m%neq, w%rows, w%s, lw%pw%xl, lw%lunit, slam)
    if (w%solver /= SOLVER_DENSE .or. (w%na == m%neq .and. .not. w%lsq)) return
    ! redundant rows: the minimum-norm multipliers and the minimum-norm dlambda
    call rows_to_cols(n, np, npd, lw%pw%xl, lw%cqdd)
    call dyn_multipliers(m, w, q, qd, lw%aa, t, lam, status, msg)
    if (status /= MBD_OK) return
    if (w%jt_lu) then
      call sens_multipliers(m, s, q, qd, lw%aa, t, w%jac, lam, lw%cq, lw%cqd, lw%cqdd, slam, &
                            status, msg, w%acopy, w%jpvt)
    else
      call sens_multipliers(m, s, q, qd, lw%aa, t, w%jac, lam, lw%cq, lw%cqd, lw%cqdd, slam, &
                            status, msg)
    end if
    slam = slam * lw%lunit
  end subroutine sens_out_multipliers

  !> The accelerations of the index-1 system at (qs, vs) and of the sensitivities (S, S_dot
  !! as rows st, sdt (npd, n)): [M J^T; J 0][q_ddot; lambda] = [Q; gamma] (dyn_accel), then
  !! [S_ddot; dlambda] from its differentiation with the same factors, every parameter in
  !! one solve (sens_dyn_rows, the constraint rows gamma_p - J_p q_ddot - Ha S - 2 Hv S_dot),
  !! as rows to pw%xl (npd, n + na), S_ddot's rows also to sddt when given.
  subroutine sens_accel(m, w, s, pw, qs, vs, tt, npd, st, sdt, aa, lam, stp, sddt)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! dynamics work arrays
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    type(proj_work_t), intent(inout) :: pw      !! work (proj_init)
    real(wp), intent(in), contiguous :: qs(:), vs(:)  !! state
    real(wp), intent(in) :: tt                  !! time
    integer, intent(in) :: npd                  !! rows of st, sdt (np rounded up to 4 k)
    real(wp), intent(in) :: st(npd, *), sdt(npd, *)   !! S, S_dot as rows (npd, n)
    real(wp), intent(out), contiguous :: aa(:), lam(:)  !! q_ddot, lambda (active rows)
    integer, intent(out) :: stp                 !! MBD_OK or the solve's failure
    real(wp), intent(out), optional :: sddt(*)  !! S_ddot as rows (npd n, flat)
    integer :: n
    n = m%nq
    call dyn_accel(m, w, qs, vs, tt, aa, lam, stp)
    if (stp /= MBD_OK) return
    call sens_dyn_rows(m, w, s, pw, qs, vs, aa, lam, tt, npd, st, sdt, .true.)
    call constraint_rows(n, w%na, npd, m%neq, w%rows, w%s, s%rhs, pw%rt)
    call dyn_solve_rows(w, pw%rt, s%np, n + w%na, npd, pw%xl, .false., stp)
    if (stp /= MBD_OK .or. .not. present(sddt)) return
    call copy_flat(npd * n, pw%xl, sddt)
  end subroutine sens_accel

  !> dlambda/dp as columns (neq, np) from a whole solution's rows xl (npd, n + na): on the
  !! active rows sc xl(k, n + i) (the matrix's constraint rows carry sc) times the unit u,
  !! zero elsewhere.
  pure subroutine lambda_cols(n, np, npd, na, neq, rows, sc, xl, u, slam)
    integer, intent(in) :: n, np, npd, na, neq, rows(na)
    real(wp), intent(in) :: sc, xl(npd, n + na), u(neq, np)
    real(wp), intent(out) :: slam(neq, np)
    integer :: i, k, r
    do k = 1, np
      do r = 1, neq
        slam(r, k) = zero
      end do
      do i = 1, na
        r = rows(i)
        slam(r, k) = sc * xl(k, n + i) * u(r, k)
      end do
    end do
  end subroutine lambda_cols

  !> b(1:nn) = a(1:nn), flat.
  pure subroutine copy_flat(nn, a, b)
    integer, intent(in) :: nn
    real(wp), intent(in) :: a(nn)
    real(wp), intent(out) :: b(nn)
    b = a
  end subroutine copy_flat

  !> The sensitivities' right-hand sides at a state (qs, vs) with accelerations aa and
  !! multipliers lam (whose assembly is in w), for S and S_dot as rows (npd, n):
  !!   pw%rt(:, 1:n) = dQ - M_p q_ddot - K_lambda S - J_p^T lambda,
  !!   s%rhs = gamma_p - J_p q_ddot - Ha S - 2 Hv S_dot (rows (npd, neq)),
  !! with dQ = Q_q S + Q_q_dot S_dot + Q_p. state: the state's blocks first (second
  !! derivatives, parameter parts, K_lambda); else those of the last call at this state.
  !! loads = .false.: without dQ (the forces' and gravity's changes).
  subroutine sens_dyn_rows(m, w, s, pw, qs, vs, aa, lam, tt, npd, st, sdt, state, loads)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(in) :: w           !! dynamics work arrays (assembled at qs)
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    type(proj_work_t), intent(inout) :: pw      !! work (proj_init)
    !> state, q_ddot, lambda (explicit shapes: no descriptors at the stages' calls), time
    real(wp), intent(in) :: qs(m%nq), vs(m%nq), aa(m%nq), lam(m%neq)
    real(wp), intent(in) :: tt
    integer, intent(in) :: npd                  !! rows of st, sdt
    real(wp), intent(in) :: st(npd, *), sdt(npd, *)   !! S, S_dot as rows (npd, n)
    logical, intent(in) :: state                !! evaluate the state's blocks
    logical, intent(in), optional :: loads      !! with dQ (default)
    integer :: kk, n
    logical :: withq, pcon
    n = m%nq
    pcon = any(s%kcon)
    withq = .true.
    if (present(loads)) withq = loads
    if (state) then
      ! cos and sin of the angles at qs: the assembly's (sens_trig's values, not computed again)
      call copy_trig(m%nb, w%asm%cb, w%asm%sb, s%cb, s%sb)
      ! (the revolutes' and translationals' second derivatives: their *_rows below)
      call sens_hessian(m, s, qs, vs, aa, tt, closed=.false.)
      ! (the parameter parts: only parameters that change a constraint have any)
      if (pcon) call sens_params(m, s, qs, vs, aa, tt, states=.false.)
      call sens_klam_list(m, s, lam, closed=.false.)
    end if
    ! the right-hand sides as the rows of rt, every parameter at once
    call accel_rows(n, npd, s%anyg .and. withq, s%qgr, s%nmz, s%mzc, s%mzk, s%mzv, aa, s%kln, &
                    s%klr, s%klc, s%klv, st, pw%rt)
    if (withq) call sens_force_rows(m, s, qs, vs, tt, npd, st, sdt, pw%rt, grav=.false.)
    do kk = 1, s%np
      if (.not. s%kcon(kk)) cycle             ! (J_p = 0 otherwise)
      call sens_jpt_lam(m, s, kk, qs, tt, lam, pw%y3)
      pw%rt(kk, 1:n) = pw%rt(kk, 1:n) - pw%y3
    end do
    ! gamma_p - J_p q_ddot - Ha S - 2 Hv S_dot; the revolutes' Ha, Hv and K_lambda
    if (pcon .or. s%nnz > s%nrvz) then
      call sens_rows_rhs(s, .true., s%nrvz + 1, npd, n, st, sdt, s%rhs)
    else                                      ! (no parameter part, no other nonzero)
      call zero_rows(npd * m%neq, s%rhs)
    end if
    call sens_revolute_rows(m, s, lam, npd, st, sdt, pw%rt, s%rhs)
    call sens_translational_rows(m, s, qs, vs, aa, lam, npd, st, sdt, pw%rt, s%rhs)
  end subroutine sens_dyn_rows

  !> Columns c (n of each of np; leading dimension ldc) as rows r (npd, n) (the padding rows
  !! zero). (The loops over parameters go by fours, written out, and a remainder: loops of
  !! a variable count this short cost several times their work.)
  pure subroutine cols_to_rows(n, np, npd, ldc, c, r)
    integer, intent(in) :: n, np, npd, ldc
    real(wp), intent(in) :: c(ldc, np)
    real(wp), intent(out) :: r(npd, n)
    integer :: i, k, g
    if (np == 4) then                          ! (the common case, no remainder)
      do i = 1, n
        r(1, i) = c(i, 1); r(2, i) = c(i, 2); r(3, i) = c(i, 3); r(4, i) = c(i, 4)
      end do
      return
    end if
    do i = 1, n
      do g = 0, np - 4, 4
        r(g + 1, i) = c(i, g + 1); r(g + 2, i) = c(i, g + 2)
        r(g + 3, i) = c(i, g + 3); r(g + 4, i) = c(i, g + 4)
      end do
      do k = 4 * (np / 4) + 1, npd
        r(k, i) = zero
        if (k <= np) r(k, i) = c(i, k)
      end do
    end do
  end subroutine cols_to_rows

  !> Rows r (npd, n) as columns c (n, np), each entry times u's when given.
  pure subroutine rows_to_cols(n, np, npd, r, c, u)
    integer, intent(in) :: n, np, npd
    real(wp), intent(in) :: r(npd, n)
    real(wp), intent(out) :: c(n, np)
    real(wp), intent(in), optional :: u(n, np)
    integer :: i, k
    if (present(u)) then
      do k = 1, np
        do i = 1, n
          c(i, k) = r(k, i) * u(i, k)
        end do
      end do
      return
    end if
    do k = 1, np
      do i = 1, n
        c(i, k) = r(k, i)
      end do
    end do
  end subroutine rows_to_cols

  !> The first n entries (the dynamic equations) of the sensitivities' right-hand sides as
  !! rows, but for the forces' changes (sens_force_rows adds them) and J_p^T lambda:
  !! rt(k, :) = - M_p q_ddot - K_lambda S_k (M_p: the list mzc, mzk, mzv of the mass
  !! matrix's changes; K_lambda: klr, klc, klv; S as rows st).
  pure subroutine accel_rows(n, npd, anyg, qgr, nmz, mzc, mzk, mzv, aa, kln, klr, klc, klv, &
                             st, rt)
    integer, intent(in) :: n, npd, nmz, kln
    logical, intent(in) :: anyg                 !! m g changes: start from qgr
    integer, intent(in) :: mzc(*), mzk(*), klr(*), klc(*)
    real(wp), intent(in) :: qgr(npd * n), mzv(*), aa(n), klv(*), st(npd, n)
    real(wp), intent(inout) :: rt(npd, *)
    integer :: e, r, c, g
    real(wp) :: v
    call start_rows(npd * n, anyg, qgr, rt)    ! d(m g), or zero
    do e = 1, nmz
      rt(mzk(e), mzc(e)) = rt(mzk(e), mzc(e)) - mzv(e) * aa(mzc(e))
    end do
    do e = 1, kln                               ! (the padding rows stay zero: st's are)
      r = klr(e); c = klc(e); v = klv(e)
      do g = 0, npd - 4, 4
        rt(g + 1, r) = rt(g + 1, r) - v * st(g + 1, c)
        rt(g + 2, r) = rt(g + 2, r) - v * st(g + 2, c)
        rt(g + 3, r) = rt(g + 3, r) - v * st(g + 3, c)
        rt(g + 4, r) = rt(g + 4, r) - v * st(g + 4, c)
      end do
    end do
  end subroutine accel_rows

  !> cb(1:nb), sb(1:nb) = ca(1:nb), sa(1:nb) (the bodies' cos and sin; index 0, ground, kept).
  pure subroutine copy_trig(nb, ca, sa, cb, sb)
    integer, intent(in) :: nb
    real(wp), intent(in) :: ca(0:nb), sa(0:nb)
    real(wp), intent(inout) :: cb(0:nb), sb(0:nb)
    integer :: b
    do b = 1, nb
      cb(b) = ca(b); sb(b) = sa(b)
    end do
  end subroutine copy_trig

  !> r(1:nn) = 0, flat.
  pure subroutine zero_rows(nn, r)
    integer, intent(in) :: nn
    real(wp), intent(out) :: r(nn)
    integer :: e
    do e = 1, nn
      r(e) = zero
    end do
  end subroutine zero_rows

  !> r(1:nn) = a (when use) or zero, flat.
  pure subroutine start_rows(nn, use, a, r)
    integer, intent(in) :: nn
    logical, intent(in) :: use
    real(wp), intent(in) :: a(nn)
    real(wp), intent(out) :: r(nn)
    integer :: e
    if (use) then
      do e = 1, nn
        r(e) = a(e)
      end do
    else
      do e = 1, nn
        r(e) = zero
      end do
    end if
  end subroutine start_rows

  !> The constraint rows of the sensitivities' right-hand sides: rt(:, n + i) = sc
  !! w(:, rows(i)), w = gamma_p - J_p q_ddot - Ha S - 2 Hv S_dot as rows (sens_kin_rhs).
  pure subroutine constraint_rows(n, na, npad, neq, rows, sc, wk, rt)
    integer, intent(in) :: n, na, npad, neq, rows(na)
    real(wp), intent(in) :: sc, wk(npad, neq)
    real(wp), intent(inout) :: rt(npad, *)
    integer :: i, g, r
    if (npad == 4) then                        ! (up to four parameters: no inner loop)
      do i = 1, na
        r = rows(i)
        rt(1, n + i) = sc * wk(1, r); rt(2, n + i) = sc * wk(2, r)
        rt(3, n + i) = sc * wk(3, r); rt(4, n + i) = sc * wk(4, r)
      end do
      return
    end if
    do i = 1, na
      r = rows(i)
      do g = 0, npad - 4, 4
        rt(g + 1, n + i) = sc * wk(g + 1, r); rt(g + 2, n + i) = sc * wk(g + 2, r)
        rt(g + 3, n + i) = sc * wk(g + 3, r); rt(g + 4, n + i) = sc * wk(g + 4, r)
      end do
    end do
  end subroutine constraint_rows

  !> Project the sensitivities in the packed state yy = (q, S, q_dot, S_dot) (q, q_dot
  !! consistent; S and S_dot as rows (npd, n), sens_dopri5) onto the linearized
  !! constraints: S onto J S = -Phi_p by the change nearest in the metric D,
  !! s [D J^T; J 0][dS; mu] = [0; -s (J S + Phi_p)], then S_dot onto
  !! J S_dot = nu_p - J_p q_dot - Hv S nearest in the kinetic metric,
  !! s [M J^T; J 0][S_dot; mu] = [M S_dot; s (nu_p - J_p q_dot - Hv S)], every parameter at
  !! once, with the matrices and solves of the state's projections (dyn_factor_projection:
  !! the Schur complement, the band or the dense LU as the model allows; no dense J).
  !! reuse: the factors of the kinetic matrix at yy's q are in w (dyn_velocity's, after a
  !! step): both projections take them (D = M); otherwise (the start) D = I, the
  !! minimum-norm change, as the assembly of q0 makes, and the kinetic matrix is factored
  !! after.
  subroutine project_sens(m, w, s, tt, yy, pw, reuse, stp)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! dynamics work arrays (its matrix is used)
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    real(wp), intent(in) :: tt                  !! time
    real(wp), intent(inout), contiguous :: yy(:)  !! packed state
    type(proj_work_t), intent(inout) :: pw      !! work (proj_init)
    logical, intent(in) :: reuse                !! w holds the kinetic matrix's factors at q
    integer, intent(out) :: stp                 !! MBD_OK or MBD_SINGULAR
    integer :: kk, i, n, nz, npd, np
    n = m%nq; np = s%np; npd = size(pw%rt, 1); nz = n * (1 + npd)
    associate (rt => pw%rt, z => w%qz)  ! (w%qz: a zero vector)
      if (reuse) then                           ! (the assembly's cos and sin at q)
        s%cb(1:m%nb) = w%asm%cb(1:m%nb); s%sb(1:m%nb) = w%asm%sb(1:m%nb)
      else
        call sens_trig(m, s, yy(1:n))
      end if
      call sens_hessian(m, s, yy(1:n), yy(nz + 1:nz + n), z, tt)
      if (any(s%kcon)) call sens_params(m, s, yy(1:n), yy(nz + 1:nz + n), z, tt, states=.false.)
      if (.not. reuse) then
        call dyn_factor_projection(m, w, yy(1:n), tt, .false., stp)
        if (stp /= MBD_OK) return
      end if
      call blocks_jv_rows(m, w%asm, npd, yy(n + 1:nz), pw%jst)   ! J S, every parameter
      do i = 1, n
        rt(:, i) = zero
      end do
      do i = 1, w%na                            ! S += dS (one solve for all parameters)
        do kk = 1, npd
          rt(kk, n + i) = w%s * (s%mphip(kk, w%rows(i)) - pw%jst(kk, w%rows(i)))
        end do
      end do
      call dyn_solve_rows(w, rt, np, n, npd, yy(n + 1:nz), .true., stp)   ! S += dS
      if (stp /= MBD_OK) return
      if (.not. reuse) then
        call dyn_factor_projection(m, w, yy(1:n), tt, .true., stp, assembled=.true.)
        if (stp /= MBD_OK) return
      end if
      ! S_dot, nearest in M: [M S_dot; s (nu_p - J_p q_dot - Hv S)]
      call sens_rows_rhs(s, .false., 1, npd, n, yy(n + 1:nz), yy(nz + n + 1:), s%rhs)
      call metric_rows(n, npd, w%metric, yy(nz + n + 1:), rt)
      call constraint_rows(n, w%na, npd, m%neq, w%rows, w%s, s%rhs, rt)
      call dyn_solve_rows(w, rt, np, n, npd, yy(nz + n + 1:), .false., stp)   ! S_dot
    end associate
  end subroutine project_sens

  !> rt(:, i) = metric(i) sd(:, i), i = 1 .. n (sd as rows (npd, n)).
  pure subroutine metric_rows(n, npd, metric, sd, rt)
    integer, intent(in) :: n, npd
    real(wp), intent(in) :: metric(n), sd(npd, n)
    real(wp), intent(inout) :: rt(npd, *)
    integer :: i, g
    do i = 1, n
      do g = 0, npd - 4, 4
        rt(g + 1, i) = metric(i) * sd(g + 1, i); rt(g + 2, i) = metric(i) * sd(g + 2, i)
        rt(g + 3, i) = metric(i) * sd(g + 3, i); rt(g + 4, i) = metric(i) * sd(g + 4, i)
      end do
    end do
  end subroutine metric_rows

  !> Sensitivities of the consistent initial state of forward dynamics: the assembled q
  !! changes by the minimum-norm solution of J S = -Phi_p; the velocity projected from the
  !! estimate v0, the solution of [W J^T; J 0][q_dot; mu] = [W v0; nu] (W: the kinetic
  !! metric, the masses, the mean mass on massless coordinates), by the derivative of that
  !! projection:
  !!   [W J^T; J 0][S_dot; dmu] = [W_p (v0 - q_dot) - (J_p + J_q S)^T mu;
  !!                               nu_p - J_p q_dot - Hv S],
  !! the constraint rows' part as the step's projection (project_sens), the first rows'
  !! (zero for a consistent v0, where mu = 0) added after: -(J_p + J_q S)^T mu from the
  !! dynamics rows with mu for lambda and no loads (sens_dyn_rows), mu from J^T mu =
  !! W (v0 - q_dot).
  subroutine sens_initial(m, w, s, q, qd, v0, t, sq, sqd, status, msg)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! dynamics work arrays (dyn_init done)
    type(sens_t), intent(inout) :: s            !! parameters and blocks
    real(wp), intent(in) :: q(:), qd(:), t      !! consistent state
    real(wp), intent(in) :: v0(:)               !! the velocity estimate qd was projected from
    real(wp), intent(out) :: sq(:, :), sqd(:, :)  !! (nq, np)
    integer, intent(out) :: status              !! MBD_OK, MBD_SINGULAR or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    real(wp), allocatable :: y(:), mu(:), zq(:), zs(:)
    real(wp) :: dmean                            ! the mean mass's change
    type(proj_work_t) :: pw
    integer :: n, nz, npd, i, k, nmass, st
    n = m%nq; npd = 4 * ((s%np + 3) / 4); nz = n * (1 + npd)
    allocate (y(2 * nz), mu(m%neq), zq(n), zs(npd * n), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the initial sensitivities'; return
    end if
    y = zero
    y(1:n) = q; y(nz + 1:nz + n) = qd
    call proj_init(m, w, s%np, pw, status, msg)
    if (status /= MBD_OK) return
    msg = ''
    ! mu of the velocity projection: [W J^T; J 0][x; mu] = [W (v0 - q_dot); 0] (x = 0)
    call dyn_factor_projection(m, w, q, t, .true., status)
    if (status == MBD_OK) then
      w%rhs = zero
      w%rhs(1:n) = w%metric * (v0 - qd)
      call dyn_solve(w, w%rhs, status)
    end if
    if (status /= MBD_OK) then
      msg = 'the initial sensitivities cannot be made consistent'; return
    end if
    mu = zero
    do i = 1, w%na
      mu(w%rows(i)) = w%s * w%rhs(n + i)       ! (the matrix's constraint rows carry s)
    end do
    call project_sens(m, w, s, t, y, pw, .false., status)   ! (ends with W's factors at q)
    if (status /= MBD_OK) then
      msg = 'the initial sensitivities cannot be made consistent'; return
    end if
    if (any(mu /= zero)) then
      ! first rows: -(J_p + J_q S)^T mu, then W_p (v0 - q_dot) (W_p: a mass's change on its
      ! coordinates; the mean mass's on the massless ones)
      zq = zero; zs = zero
      call sens_dyn_rows(m, w, s, pw, q, qd, zq, mu, t, npd, y(n + 1:nz), zs, .true., &
                         loads=.false.)
      nmass = count(m%mdiag > zero)
      do k = 1, s%np
        dmean = zero
        if (nmass > 0) dmean = sum(s%tmass(:, k), mask=m%mdiag > zero) / nmass
        do i = 1, n
          if (m%mdiag(i) > zero) then
            pw%rt(k, i) = pw%rt(k, i) + s%tmass(i, k) * (v0(i) - qd(i))
          else
            pw%rt(k, i) = pw%rt(k, i) + dmean * (v0(i) - qd(i))
          end if
        end do
      end do
      pw%rt(:, n + 1:) = zero
      call dyn_solve_rows(w, pw%rt, s%np, n, npd, y(nz + n + 1:), .true., status)
      if (status /= MBD_OK) then
        msg = 'the initial sensitivities cannot be made consistent'; return
      end if
    end if
    call rows_to_cols(n, s%np, npd, y(n + 1:nz), sq)
    call rows_to_cols(n, s%np, npd, y(nz + n + 1:), sqd)
  end subroutine sens_initial

end module mbd_sens_dynamics
