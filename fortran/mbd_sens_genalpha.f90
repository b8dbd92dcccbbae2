!> mbd_sens_genalpha: design sensitivities of generalized-alpha's solution, by
!! differentiating its discrete equations (the derivative of the numerical solution itself).
!!
!! A step of generalized-alpha (mbd_integrators) solves, for q_{n+1} and lambda_{n+1},
!!   M q_ddot_{n+1} + J^T lambda_{n+1} = Q(q_{n+1}, q_dot_{n+1}, t_{n+1}),  Phi(q_{n+1}) = 0,
!! with q_{n+1} = q* + d, q_dot_{n+1} = v* + g' d, q_ddot_{n+1} = a* + b' d, where (q*, v*, a*)
!! is the predictor, linear in the step's start (q_n, q_dot_n, q_ddot_n, a_n). Differentiated
!! along a parameter p, with the start's sensitivities carried through the same predictor
!! (S*, V*, A*) and S = S* + D, S_dot = V* + g' D, S_ddot = A* + b' D:
!!   [M b' + K + g' C, J^T; J, 0] [D; dlambda] = [r1; -(J S* + Phi_p)],
!!   r1 = dQ(S*, V*) - M_p q_ddot - K_lambda S* - J_p^T lambda - M A*,
!! K = K_lambda - Q_q, C = -Q_q_dot (the exact tangents; dQ = Q_q S + Q_q_dot S_dot + Q_p).
!! The right-hand sides are those of the dopri5 sensitivities (mbd_sens_dynamics
!! sens_dyn_rows) at the converged state, every parameter at once; the matrix is the
!! step's own iteration matrix S, whose K and C are differences and may be some steps old,
!! so the solve is refined against the exact residual, x += S^-1 (b - A_exact x), until the
!! error left is below a share of the run's tolerances (ga_step; about one solve a step,
!! 1.26 on the free slider-crank at h = 1 ms). The auxiliary acceleration's
!! sensitivity follows a_{n+1} = (af q_ddot_n + (1 - af) q_ddot_{n+1} - am a_n) / (1 - am).
!! The result is the exact derivative of the discrete solution at fixed step sizes: with a
!! fixed h, central differences of runs; as h -> 0, the sensitivity of the motion (order 2).
!! With error control the step sizes are taken as given (not differentiated), and the
!! sensitivities' local error, (6 beta - 1) (S_{n+1} - S_n - h S_dot_n - h^2 S_ddot_n / 2)
!! like the state's, joins the state's in the step size control.
module mbd_sens_genalpha
  use mbd_kinds, only: wp, zero, one, half
  use mbd_status, only: MBD_OK, MBD_NO_CONVERGENCE, MBD_NO_MEMORY, MSG_LEN
  use mbd_model, only: model_t
  use mbd_assemble, only: blocks_jv_rows, blocks_jtv_rows_sub
  use mbd_saddle, only: saddle_t, saddle_solve_rows
  use mbd_dynamics, only: dyn_work_t
  use mbd_sensitivity, only: sens_t
  use mbd_sens_dynamics, only: proj_work_t, proj_init, sens_accel, sens_dyn_rows, &
                               cols_to_rows, rows_to_cols
  use mbd_integrators, only: ga_hook_t, GA_NCOEF
  use mbd_interp, only: hermite5
  implicit none
  private
  public :: ga_sens_t, ga_sens_init

  !> refinement solves per step before fresh K and C are asked for
  integer, parameter :: REFINE_MAXIT = 8
  !> the refinement has converged when its correction is this small against S (relative)
  real(wp), parameter :: REFINE_TOL = 1.0e-13_wp
  !> a correction that no longer halves is at the rounding of S when below this (relative)
  real(wp), parameter :: REFINE_FLOOR = 1.0e-9_wp
  !> the refinement stops where its remaining error is below this share of the run's
  !! tolerances (atol + rtol |S|), a tenth of the state's Newton's 1e-3 (atol + rtol |q|)
  !! (the state's own convergence moves S more: q_ddot carries b' times q's last correction)
  real(wp), parameter :: REFINE_SHARE = 1.0e-4_wp
  !> steps that take the contraction measured before, before it is measured again
  integer, parameter :: REFINE_REMEASURE = 8

  !> The sensitivities stepped with generalized-alpha: S, S_dot, S_ddot and the auxiliary
  !! acceleration's (as rows (npd, n), flat) at the step's start (0) and end (1), the
  !! multipliers' (npd, neq), and the outputs they are written to (nq, np, rows; model units).
  type, extends(ga_hook_t) :: ga_sens_t
    type(sens_t), pointer :: s => null()
    type(proj_work_t) :: pw
    integer :: n = 0, np = 0, npd = 0
    real(wp), allocatable :: s0(:), v0(:), a0(:), c0(:), s1(:), v1(:), a1(:), c1(:)
    real(wp), allocatable :: l0(:, :), l1(:, :)     !! dlambda/dp as rows (npd, neq)
    real(wp), allocatable :: xt(:, :), x(:)         !! solutions as rows (npd, nq + na); work
    real(wp), allocatable :: zq(:), zv(:), za(:)    !! an output's interpolated rows
    real(wp), pointer, contiguous :: so(:, :, :) => null(), sdo(:, :, :) => null()
    real(wp), pointer, contiguous :: sddo(:, :, :) => null()
    !> the refinement's last measured contraction (huge: none yet) and the steps since
    real(wp) :: rho = huge(1.0_wp)
    integer :: since = 0
  contains
    procedure :: rescale => ga_rescale
    procedure :: step => ga_step
    procedure :: emit => ga_emit
    procedure :: commit => ga_commit
  end type ga_sens_t

contains

  !> Set up g for a run from the consistent state (q, qd) at t and its sensitivities (sq,
  !! sqd) (nq, np; sens_initial): S_ddot from the index-1 equations there (as the state's
  !! q_ddot, the auxiliary acceleration's start), output row 1 written. so, sdo, sddo (nq,
  !! np, rows) must stay in place for the run (g points to them).
  subroutine ga_sens_init(g, m, w, s, q, qd, t, sq, sqd, so, sdo, sddo, status, msg)
    type(ga_sens_t), intent(out) :: g
    type(model_t), intent(in) :: m                !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w          !! dynamics work arrays (dyn_init done)
    type(sens_t), intent(inout), target :: s      !! parameters and blocks
    real(wp), intent(in) :: q(:), qd(:), t        !! consistent state
    real(wp), intent(in) :: sq(:, :), sqd(:, :)   !! its sensitivities (nq, np)
    real(wp), intent(inout), target, contiguous :: so(:, :, :), sdo(:, :, :), sddo(:, :, :)
    integer, intent(out) :: status                !! MBD_OK or a failure
    character(len=MSG_LEN), intent(out) :: msg    !! explanation
    real(wp), allocatable :: aa(:), lam(:)
    integer :: st, nz
    status = MBD_OK; msg = ''
    g%s => s; g%so => so; g%sdo => sdo; g%sddo => sddo
    g%n = m%nq; g%np = s%np; g%npd = 4 * ((s%np + 3) / 4)
    nz = g%npd * g%n
    allocate (g%s0(nz), g%v0(nz), g%a0(nz), g%c0(nz), g%s1(nz), g%v1(nz), g%a1(nz), g%c1(nz), &
              g%l0(g%npd, m%neq), g%l1(g%npd, m%neq), g%xt(g%npd, m%nq + w%na), &
              g%x(m%nq + w%na), g%zq(nz), g%zv(nz), g%za(nz), &
              aa(m%nq), lam(m%neq), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the sensitivities of generalized-alpha'
      return
    end if
    call proj_init(m, w, s%np, g%pw, status, msg)
    if (status /= MBD_OK) return
    call cols_to_rows(g%n, g%np, g%npd, g%n, sq, g%s0)
    call cols_to_rows(g%n, g%np, g%npd, g%n, sqd, g%v0)
    call sens_accel(m, w, s, g%pw, q, qd, t, g%npd, g%s0, g%v0, aa, lam, status, g%a0)
    if (status /= MBD_OK) then
      msg = 'the mass matrix and constraints give a singular system at the start'; return
    end if
    g%c0 = g%a0
    g%l0 = zero; g%l1 = zero
    call put_row(g, 1, g%s0, g%v0, g%a0)
  end subroutine ga_sens_init

  !> On a change of step size the auxiliary acceleration's shift scales like the state's:
  !! a' <- S_ddot + f (a' - S_ddot).
  subroutine ga_rescale(self, f)
    class(ga_sens_t), intent(inout) :: self
    real(wp), intent(in) :: f
    integer :: e
    do e = 1, size(self%c0)
      self%c0(e) = self%a0(e) + f * (self%c0(e) - self%a0(e))
    end do
  end subroutine ga_rescale

  !> The sensitivities at the end of the step to tn (size h) from the converged state (qn,
  !! vn, an, lamn), whose assembly is in w, with the factors of the step's iteration
  !! matrix sg: the predictor, then the refined solve (module comment), stopped when the
  !! correction is at the rounding of S (REFINE_TOL), or when the error left, estimated
  !! from the contraction rho as rho / (1 - rho) times the last correction, is below
  !! REFINE_SHARE of the run's tolerances (a tight run: REFINE_TOL). After one solve the
  !! rho measured at an earlier step is taken (measured again every REFINE_REMEASURE
  !! steps): one solve a step as a rule. status MBD_NO_CONVERGENCE asks for S with fresh K
  !! and C (the refinement does not contract).
  subroutine ga_step(self, m, w, sg, tn, h, coef, qn, vn, an, lamn, rtol, atol, esq, ne, &
                     status)
    class(ga_sens_t), intent(inout) :: self
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    type(saddle_t), intent(inout) :: sg
    real(wp), intent(in) :: tn, h, coef(GA_NCOEF), rtol, atol
    real(wp), intent(in), contiguous :: qn(:), vn(:), an(:), lamn(:)
    real(wp), intent(out) :: esq
    integer, intent(out) :: ne, status
    real(wp) :: bp, gp, dn, sn, dprev, rho, tolr
    integer :: it, n, npd, nz
    bp = coef(5); gp = coef(6)
    n = self%n; npd = self%npd; nz = npd * n
    esq = zero; ne = 0
    call ga_predict(nz, h, coef, self%s0, self%v0, self%a0, self%c0, self%s1, self%v1, &
                    self%a1, self%c1)
    self%l1 = self%l0
    dprev = huge(one)
    status = MBD_NO_CONVERGENCE
    do it = 1, REFINE_MAXIT
      ! the residual as the rows of rt: dQ - M_p q_ddot - K_lambda S - J_p^T lambda (the
      ! dopri5 rows) - M S_ddot - J^T dlambda, and b' (-Phi_p - J S) on the active rows
      call sens_dyn_rows(m, w, self%s, self%pw, qn, vn, an, lamn, tn, npd, self%s1, self%v1, &
                         it == 1)
      call blocks_jtv_rows_sub(m, w%asm, npd, self%l1, self%pw%rt)
      call blocks_jv_rows(m, w%asm, npd, self%s1, self%pw%jst)
      call ga_residual(n, npd, m%neq, w%na, w%rows, bp, m%mdiag, self%a1, self%s%mphip, &
                       self%pw%jst, self%pw%rt)
      call saddle_solve_rows(sg, self%pw%rt, self%np, n + w%na, npd, self%xt, .false., &
                             self%x, status)
      if (status /= MBD_OK) return
      call ga_correct(n, npd, m%neq, w%na, w%rows, bp, gp, self%xt, self%s1, self%v1, &
                      self%a1, self%l1, dn, sn)
      status = MBD_OK
      if (dn <= REFINE_TOL * sn) exit
      tolr = max(REFINE_TOL * sn, REFINE_SHARE * (atol + rtol * sn))
      if (it == 1) then                       ! (the rate of an earlier step)
        if (self%since < REFINE_REMEASURE .and. self%rho < half) then
          if (self%rho / (1 - self%rho) * dn <= tolr) then
            self%since = self%since + 1
            exit
          end if
        end if
      else
        rho = dn / dprev
        self%rho = rho; self%since = 0
        if (rho < half) then
          if (rho / (1 - rho) * dn <= tolr) exit   ! (the error left)
        else                                  ! no longer contracting: rounding, or an old S
          if (dn > REFINE_FLOOR * sn) status = MBD_NO_CONVERGENCE
          exit
        end if
      end if
      dprev = dn
      if (it == REFINE_MAXIT) status = MBD_NO_CONVERGENCE
    end do
    if (status /= MBD_OK) return
    call ga_finish(nz, h, coef, rtol, atol, self%s0, self%v0, self%a0, self%s1, self%a1, &
                   self%c1, esq)
    ne = n * self%np
  end subroutine ga_step

  !> The predictor of the state applied to the sensitivities (rows, flat, nz entries):
  !! A* = S_ddot_n, a'* = (af S_ddot_n - am a'_n) / (1 - am), S* and V* from them
  !! (mbd_integrators run_genalpha).
  pure subroutine ga_predict(nz, h, coef, s0, v0, a0, c0, s1, v1, a1, c1)
    integer, intent(in) :: nz
    real(wp), intent(in) :: h, coef(GA_NCOEF), s0(nz), v0(nz), a0(nz), c0(nz)
    real(wp), intent(out) :: s1(nz), v1(nz), a1(nz), c1(nz)
    real(wp) :: cf, ap, wa, wc, h2c, h2b, hgc, hg
    integer :: e
    ! (the weights once: a'* = wa S_ddot_n + wc a'_n)
    wa = coef(2) / (1 - coef(1)); wc = -coef(1) / (1 - coef(1))
    cf = (1 - coef(2)) / (1 - coef(1))
    h2c = h * h * (half - coef(4)); h2b = h * h * coef(4)
    hgc = h * (1 - coef(3)); hg = h * coef(3)
    do e = 1, nz
      a1(e) = a0(e)
      c1(e) = wa * a0(e) + wc * c0(e)
      ap = c1(e) + cf * a0(e)
      s1(e) = s0(e) + h * v0(e) + h2c * c0(e) + h2b * ap
      v1(e) = v0(e) + hgc * c0(e) + hg * ap
    end do
  end subroutine ga_predict

  !> The residual's last terms: rt(:, i) -= M_ii S_ddot(:, i) (i <= n), and on the active
  !! rows rt(:, n + i) = b' (-Phi_p - J S)(:, rows(i)) (mphip = -Phi_p, jst = J S).
  pure subroutine ga_residual(n, npd, neq, na, rows, bp, mdiag, a1, mphip, jst, rt)
    integer, intent(in) :: n, npd, neq, na, rows(na)
    real(wp), intent(in) :: bp, mdiag(n), a1(npd, n), mphip(npd, neq), jst(npd, neq)
    real(wp), intent(inout) :: rt(npd, n + na)
    integer :: i, k, r
    do i = 1, n
      do k = 1, npd
        rt(k, i) = rt(k, i) - mdiag(i) * a1(k, i)
      end do
    end do
    do i = 1, na
      r = rows(i)
      do k = 1, npd
        rt(k, n + i) = bp * (mphip(k, r) - jst(k, r))
      end do
    end do
  end subroutine ga_residual

  !> S += D, S_dot += g' D, S_ddot += b' D, dlambda += b' (the multiplier part) from the
  !! solution rows xt (npd, n + na); dn the largest |D|, sn the largest |S|.
  pure subroutine ga_correct(n, npd, neq, na, rows, bp, gp, xt, s1, v1, a1, l1, dn, sn)
    integer, intent(in) :: n, npd, neq, na, rows(na)
    real(wp), intent(in) :: bp, gp, xt(npd, n + na)
    real(wp), intent(inout) :: s1(npd, n), v1(npd, n), a1(npd, n), l1(npd, neq)
    real(wp), intent(out) :: dn, sn
    integer :: i, k
    dn = zero; sn = zero
    do i = 1, n
      do k = 1, npd
        s1(k, i) = s1(k, i) + xt(k, i)
        v1(k, i) = v1(k, i) + gp * xt(k, i)
        a1(k, i) = a1(k, i) + bp * xt(k, i)
        dn = max(dn, abs(xt(k, i))); sn = max(sn, abs(s1(k, i)))
      end do
    end do
    do i = 1, na
      do k = 1, npd
        l1(k, rows(i)) = l1(k, rows(i)) + bp * xt(k, n + i)
      end do
    end do
  end subroutine ga_correct

  !> The auxiliary acceleration at the end, a' += (1 - af)/(1 - am) S_ddot, and the local
  !! error's weighted squares esq (the padding rows are zero and add nothing).
  pure subroutine ga_finish(nz, h, coef, rtol, atol, s0, v0, a0, s1, a1, c1, esq)
    integer, intent(in) :: nz
    real(wp), intent(in) :: h, coef(GA_NCOEF), rtol, atol, s0(nz), v0(nz), a0(nz), s1(nz), &
                            a1(nz)
    real(wp), intent(inout) :: c1(nz)
    real(wp), intent(out) :: esq
    real(wp) :: cf, e6, d
    integer :: e
    cf = (1 - coef(2)) / (1 - coef(1)); e6 = 6 * coef(4) - 1
    esq = zero
    do e = 1, nz
      c1(e) = c1(e) + cf * a1(e)
      d = e6 * (s1(e) - s0(e) - h * v0(e) - half * h * h * a0(e))
      esq = esq + (d / (atol + rtol * max(abs(s0(e)), abs(s1(e)))))**2
    end do
  end subroutine ga_finish

  !> Output row r at tk in (ta, tb]: quintic Hermite interpolation of S between the step's
  !! ends, as the state's (mbd_integrators emit).
  subroutine ga_emit(self, r, tk, ta, tb)
    class(ga_sens_t), intent(inout) :: self
    integer, intent(in) :: r
    real(wp), intent(in) :: tk, ta, tb
    call hermite5(ta, self%s0, self%v0, self%a0, tb, self%s1, self%v1, self%a1, tk, self%zq, &
                  self%zv, self%za)
    call put_row(self, r, self%zq, self%zv, self%za)
  end subroutine ga_emit

  !> The step's end becomes the next step's start (the arrays swapped, not copied: the next
  !! step's predictor writes every entry of the end's).
  subroutine ga_commit(self)
    class(ga_sens_t), intent(inout) :: self
    call swap(self%s0, self%s1); call swap(self%v0, self%v1)
    call swap(self%a0, self%a1); call swap(self%c0, self%c1)
    self%l0 = self%l1
  contains
    subroutine swap(a, b)
      real(wp), allocatable, intent(inout) :: a(:), b(:)
      real(wp), allocatable :: tmp(:)
      call move_alloc(a, tmp); call move_alloc(b, a); call move_alloc(tmp, b)
    end subroutine swap
  end subroutine ga_commit

  !> Output row r from rows (npd, n) of S, S_dot, S_ddot, in model units (s%ounit).
  subroutine put_row(g, r, zs, zv, za)
    type(ga_sens_t), intent(inout) :: g
    integer, intent(in) :: r
    real(wp), intent(in), contiguous :: zs(:), zv(:), za(:)
    call rows_to_cols(g%n, g%np, g%npd, zs, g%so(:, :, r), g%s%ounit)
    call rows_to_cols(g%n, g%np, g%npd, zv, g%sdo(:, :, r), g%s%ounit)
    call rows_to_cols(g%n, g%np, g%npd, za, g%sddo(:, :, r), g%s%ounit)
  end subroutine put_row

end module mbd_sens_genalpha
