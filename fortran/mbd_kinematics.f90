!> mbd_kinematics: assembly, Newton-Raphson on Phi(q, t) = 0, velocities and accelerations,
!! the time loop, and the location of singular (dead-centre) configurations.
!!
!! Per output time (Haug, ch. 3-4; Nikravesh, ch. 5):
!!   predictor    q = q_k + h q_dot_k + h**2/2 q_ddot_k + h**3/6 q_dddot_k,
!!                q_dddot_k from the last two accelerations
!!   position     J(q) dq = -Phi(q, t),  q <- q + dq   until ||Phi||_inf <= tol   (dgetrf/dgetrs)
!!   velocity     J q_dot = nu                              (the last factorization is reused)
!!   acceleration J q_ddot = gamma(q, q_dot, t)             (same factorization)
!! A step whose Newton solve fails, or whose det J changes sign (the solution would pass a
!! singular configuration or jump to another assembly branch), is halved. When the step falls
!! below tmin the run stops: the configuration is singular there, and the SVD of J names
!! the dependent rows and the driver that can no longer be met.
module mbd_kinematics
  use mbd_kinds, only: wp, zero, one, half
  use mbd_status, only: MBD_OK, MBD_BAD_SETTING, MBD_SINGULAR, MBD_NO_CONVERGENCE, &
                        MBD_SINGULAR_CONFIG, MBD_ASSEMBLY_FAILED, MBD_LAPACK, MSG_LEN
  use mbd_points, only: NLOC, MAXROW
  use mbd_model, only: model_t
  use mbd_constraints, only: con_is_driver, con_name
  use mbd_assemble, only: assemble_blocks, assemble_dense, init_extras
  use mbd_linsolve, only: lu_factor, lu_solve, lu_det_sign, svd_null
  use mbd_lapack, only: dgels
  implicit none
  private
  public :: kin_opts_t, kin_work_t, kin_report_t, DEP_TOL
  public :: kin_work_init, kin_assemble, kin_vel_acc, kin_newton, kin_run, kin_singular_report

  real(wp), parameter :: DEP_TOL = 1.0e-3_wp  !! |u_r| / max|u| above which a row is dependent
  !> sigma_min / sigma_max of the column-scaled J below which a configuration is singular
  real(wp), parameter :: SING_RATIO = 1.0e-3_wp

  !> Settings of a kinematic analysis.
  type :: kin_opts_t
    real(wp) :: tol = 1.0e-12_wp    !! ||Phi||_inf tolerance, relative to the model length scale
    integer :: maxit = 25           !! Newton iterations per step
    real(wp) :: tmin = 1.0e-10_wp   !! time resolution of a singular configuration
    integer :: assembly_maxit = 400 !! damped iterations for the initial assembly
  end type kin_opts_t

  !> Work arrays, allocated once per analysis.
  type :: kin_work_t
    real(wp), allocatable :: phi(:), nu(:), gam(:), jac(:, :), jb(:, :, :), qz(:)
    integer, allocatable :: ipiv(:)
    integer :: detsign = 0          !! sign of det J at the last factorization
    real(wp) :: tol = zero          !! absolute ||Phi|| tolerance in use
    integer :: newton_its = 0       !! Newton corrections taken
    integer :: lu_count = 0         !! LU factorizations
  end type kin_work_t

  !> What happened: counters, and the singular or failed configuration.
  type :: kin_report_t
    integer :: ndone = 0            !! output times computed
    integer :: driver = 0           !! driver that can no longer be met (constraint index)
    integer :: worst = 0            !! constraint with the largest residual at a failure
    integer :: deficiency = 0       !! rank deficiency of J at the singular configuration
    integer :: rejected = 0         !! rejected (halved) steps
    real(wp) :: t_fail = zero       !! time of the singular configuration or failure
    real(wp) :: smin = zero, smax = zero  !! extreme singular values of J there
    real(wp) :: resid = zero        !! ||Phi||_inf at a failure
    integer :: newton_its = 0       !! Newton corrections taken
    integer :: lu_count = 0         !! LU factorizations
    real(wp), allocatable :: qsing(:)     !! configuration there
    integer, allocatable :: dep(:)        !! 1 for each row in the dependent set
  end type kin_report_t

contains

  !> Allocate work arrays for model m.
  subroutine kin_work_init(m, w)
    type(model_t), intent(in) :: m       !! model
    type(kin_work_t), intent(out) :: w   !! work arrays
    allocate (w%phi(m%neq), w%nu(m%neq), w%gam(m%neq), w%jac(m%neq, m%nq), &
              w%jb(MAXROW, NLOC, m%nc), w%qz(m%nq), w%ipiv(m%nq))
    w%qz = zero
  end subroutine kin_work_init

  !> Newton-Raphson on Phi(q, t) = 0 from q. On success w%jac holds the LU factors of J(q)
  !! at the returned q, w%nu holds nu(q, t) and w%detsign the sign of det J.
  subroutine kin_newton(m, w, q, t, maxit, status)
    type(model_t), intent(in) :: m          !! model (square: neq = nq)
    type(kin_work_t), intent(inout) :: w    !! work arrays
    real(wp), intent(inout) :: q(:)         !! start, then solution
    real(wp), intent(in) :: t               !! time
    integer, intent(in) :: maxit            !! iteration limit
    integer, intent(out) :: status          !! MBD_OK, MBD_NO_CONVERGENCE or MBD_SINGULAR
    character(len=MSG_LEN) :: msg
    real(wp) :: res, res0
    integer :: it, st
    res0 = huge(one)
    do it = 0, maxit
      call assemble_dense(m, q, w%qz, t, w%phi, w%nu, w%gam, w%jb, w%jac)
      res = maxval(abs(w%phi))
      if (.not. (res <= huge(one))) exit                 ! NaN or overflow
      if (it > 0 .and. res > 1.0e3_wp * res0 .and. res > w%tol) exit   ! diverging
      if (it == 0) res0 = res
      call lu_factor(w%jac, w%ipiv, st, msg)
      w%lu_count = w%lu_count + 1
      if (st /= MBD_OK) then
        status = MBD_SINGULAR; return
      end if
      if (res <= w%tol) then
        w%detsign = lu_det_sign(w%jac, w%ipiv)
        status = MBD_OK; return
      end if
      if (it == maxit) exit
      w%phi = -w%phi
      call lu_solve(w%jac, w%ipiv, w%phi, st, msg)
      q = q + w%phi
      w%newton_its = w%newton_its + 1
    end do
    status = MBD_NO_CONVERGENCE
  end subroutine kin_newton

  !> Velocities and accelerations at a converged q: J q_dot = nu, J q_ddot = gamma.
  !! Uses the factorization kin_newton left in w.
  subroutine kin_vel_acc(m, w, q, t, qd, qdd)
    type(model_t), intent(in) :: m          !! model
    type(kin_work_t), intent(inout) :: w    !! work arrays (LU of J(q), nu(q, t))
    real(wp), intent(in) :: q(:)            !! converged coordinates
    real(wp), intent(in) :: t               !! time
    real(wp), intent(out) :: qd(:)          !! velocities
    real(wp), intent(out) :: qdd(:)         !! accelerations
    integer :: st
    character(len=MSG_LEN) :: msg
    qd = w%nu
    call lu_solve(w%jac, w%ipiv, qd, st, msg)
    call assemble_blocks(m, q, qd, t, w%phi, w%nu, w%gam, w%jb)
    qdd = w%gam
    call lu_solve(w%jac, w%ipiv, qdd, st, msg)
  end subroutine kin_vel_acc

  !> Assemble: from rough estimates q (extras are estimated here) find Phi(q, t) = 0 by a
  !! Levenberg-Marquardt iteration (min ||Phi||^2, steps from (J^T J + mu I) dq = -J^T Phi
  !! solved as least squares with dgels), then polish with Newton. On success w holds the
  !! LU factors of J(q) and nu, ready for kin_vel_acc.
  subroutine kin_assemble(m, w, q, t, opts, rep, status, msg)
    type(model_t), intent(in) :: m           !! model
    type(kin_work_t), intent(inout) :: w     !! work arrays
    real(wp), intent(inout) :: q(:)          !! estimates, then the assembled configuration
    real(wp), intent(in) :: t                !! time
    type(kin_opts_t), intent(in) :: opts     !! settings
    type(kin_report_t), intent(inout) :: rep !! failure details
    integer, intent(out) :: status           !! MBD_OK, MBD_ASSEMBLY_FAILED or MBD_SINGULAR
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    real(wp), allocatable :: aug(:, :), rhs(:), work(:), qt(:), phit(:)
    real(wp) :: mu, f, ft, wq(1), dmax
    integer :: it, n, neq, info, lwork, i, k, st

    status = MBD_OK; msg = ''
    n = m%nq; neq = m%neq
    call init_extras(m, q)
    allocate (aug(neq + n, n), rhs(neq + n), qt(n), phit(neq))
    call dgels('N', neq + n, n, 1, aug, neq + n, rhs, neq + n, wq, -1, info)
    lwork = max(1, int(wq(1)))
    allocate (work(lwork))
    call assemble_dense(m, q, w%qz, t, w%phi, w%nu, w%gam, w%jb, w%jac)
    f = norm2(w%phi)
    dmax = zero
    do k = 1, n
      dmax = max(dmax, sum(w%jac(:, k)**2))
    end do
    mu = 1.0e-3_wp * max(dmax, one)
    do it = 1, opts%assembly_maxit
      if (maxval(abs(w%phi)) <= w%tol) exit
      ! least squares [J; sqrt(mu) I] dq = [-Phi; 0]
      aug = zero
      aug(1:neq, :) = w%jac
      do i = 1, n
        aug(neq + i, i) = sqrt(mu)
      end do
      rhs = zero; rhs(1:neq) = -w%phi
      call dgels('N', neq + n, n, 1, aug, neq + n, rhs, neq + n, work, lwork, info)
      if (info /= 0) then
        mu = mu * 10.0_wp; cycle
      end if
      qt = q + rhs(1:n)
      call assemble_dense(m, qt, w%qz, t, phit, w%nu, w%gam, w%jb, w%jac)
      ft = norm2(phit)
      if (ft < f) then
        q = qt; f = ft; w%phi = phit
        mu = max(mu / 10.0_wp, 1.0e-20_wp * max(dmax, one))
      else
        call assemble_dense(m, q, w%qz, t, w%phi, w%nu, w%gam, w%jb, w%jac)
        mu = mu * 10.0_wp
        if (mu > 1.0e20_wp * max(dmax, one)) exit
      end if
    end do
    if (maxval(abs(w%phi)) > 1.0e3_wp * w%tol) then
      status = MBD_ASSEMBLY_FAILED
      rep%resid = maxval(abs(w%phi))
      rep%worst = m%con_of_row(maxloc(abs(w%phi), 1))
      rep%t_fail = t
      write (msg, '(a,es10.3,a,i0,a)') 'assembly failed: no configuration satisfies the '// &
        'constraints near the estimates; smallest residual ||Phi|| = ', rep%resid, &
        ', largest in constraint ', rep%worst, ' ('//trim(con_name(m%kind(rep%worst)))//')'
      return
    end if
    call kin_newton(m, w, q, t, opts%maxit, st)
    if (st /= MBD_OK) then
      status = MBD_SINGULAR
      rep%t_fail = t
      call kin_singular_report(m, w, q, t, rep, st, msg)
      status = MBD_SINGULAR
      msg = 'the assembled configuration is singular (J loses rank): ' // trim(msg)
    end if
  end subroutine kin_assemble

  !> SVD of J at q: which rows became dependent and which driver can no longer be met.
  subroutine kin_singular_report(m, w, q, t, rep, status, msg)
    type(model_t), intent(in) :: m           !! model
    type(kin_work_t), intent(inout) :: w     !! work arrays
    real(wp), intent(in) :: q(:)             !! configuration
    real(wp), intent(in) :: t                !! time
    type(kin_report_t), intent(inout) :: rep !! filled: smin, smax, dep, driver, qsing
    integer, intent(out) :: status           !! MBD_OK or MBD_LAPACK
    character(len=MSG_LEN), intent(out) :: msg  !! description
    real(wp), allocatable :: sv(:), u(:), v(:)
    real(wp) :: umax, best
    integer :: r, k
    character(len=MSG_LEN) :: rows
    allocate (sv(min(m%neq, m%nq)), u(m%neq), v(m%nq))
    call assemble_dense(m, q, w%qz, t, w%phi, w%nu, w%gam, w%jb, w%jac)
    ! columns to unit length, so lengths and angles weigh alike: J D, D = diag(1/|J_k|)
    do k = 1, m%nq
      umax = norm2(w%jac(:, k))
      if (umax > zero) w%jac(:, k) = w%jac(:, k) / umax
    end do
    call svd_null(w%jac, sv, u, v, status, msg)
    if (status /= MBD_OK) return
    rep%qsing = q
    rep%t_fail = t
    rep%smax = sv(1); rep%smin = sv(size(sv))
    rep%deficiency = max(1, count(sv < DEP_TOL * sv(1)))
    umax = maxval(abs(u))
    rep%dep = merge(1, 0, abs(u) > DEP_TOL * umax)
    rep%driver = 0; best = zero
    do r = 1, m%neq
      k = m%con_of_row(r)
      if (con_is_driver(m%kind(k)) .and. rep%dep(r) == 1 .and. abs(u(r)) > best) then
        best = abs(u(r)); rep%driver = k
      end if
    end do
    rows = ''
    do r = 1, m%neq
      if (rep%dep(r) == 1 .and. len_trim(rows) < MSG_LEN - 12) write (rows, '(a,1x,i0)') trim(rows), r
    end do
    if (rep%driver > 0) then
      write (msg, '(a,es22.15,a,i0,a,a,a,es9.2)') 'singular configuration (dead centre) at t = ', &
        t, ': driver constraint ', rep%driver, ' can no longer be met; dependent rows:', &
        trim(rows), '; sigma_min/sigma_max = ', rep%smin / rep%smax
    else
      write (msg, '(a,es22.15,a,a,a,es9.2)') 'singular configuration at t = ', t, &
        ': the kinematic constraints became dependent; dependent rows:', trim(rows), &
        '; sigma_min/sigma_max = ', rep%smin / rep%smax
    end if
  end subroutine kin_singular_report

  !> Kinematic analysis at nsteps + 1 uniform times from t0 to t1, the whole loop here.
  !! q0: estimates of the body coordinates (extras are estimated). On a singular
  !! configuration the outputs up to it are filled (rep%ndone) and status is
  !! MBD_SINGULAR_CONFIG with rep describing the configuration.
  subroutine kin_run(m, q0, t0, t1, nsteps, opts, qout, qdout, qddout, rep, status, msg)
    type(model_t), intent(in) :: m             !! model
    real(wp), intent(in) :: q0(:)              !! estimates (nq)
    real(wp), intent(in) :: t0, t1             !! time span
    integer, intent(in) :: nsteps              !! output intervals
    type(kin_opts_t), intent(in) :: opts       !! settings
    real(wp), intent(out) :: qout(:, :)        !! coordinates (nq, nsteps + 1)
    real(wp), intent(out) :: qdout(:, :)       !! velocities
    real(wp), intent(out) :: qddout(:, :)      !! accelerations
    type(kin_report_t), intent(out) :: rep     !! what happened
    integer, intent(out) :: status             !! MBD_OK or the failure
    character(len=MSG_LEN), intent(out) :: msg !! explanation
    type(kin_work_t) :: w
    real(wp), allocatable :: q(:), qd(:), qdd(:), qn(:), q3(:), qddn(:)
    real(wp) :: t, h, hcur, hh, tt, target, lscale
    integer :: k, st, detprev
    logical :: last

    status = MBD_OK; msg = ''
    qout = zero; qdout = zero; qddout = zero
    allocate (rep%qsing(m%nq), rep%dep(m%neq))
    rep%qsing = zero; rep%dep = 0
    if (nsteps < 0 .or. .not. (abs(t1 - t0) <= huge(one)) .or. .not. (opts%tol > zero)) then
      status = MBD_BAD_SETTING; msg = 'steps must be >= 0, times finite, tolerance > 0'; return
    end if
    if (nsteps > 0 .and. .not. (t1 > t0)) then
      status = MBD_BAD_SETTING; msg = 't_end must be greater than the start time'; return
    end if
    call kin_work_init(m, w)
    lscale = max(m%lscale, maxval(abs(q0(1:3 * m%nb)), mask=mod([(k, k=1, 3 * m%nb)], 3) /= 0))
    w%tol = opts%tol * lscale
    allocate (q(m%nq), qd(m%nq), qdd(m%nq), qn(m%nq), q3(m%nq), qddn(m%nq))
    q = q0
    call kin_assemble(m, w, q, t0, opts, rep, status, msg)
    if (status /= MBD_OK) then
      call count_work(); return
    end if
    call kin_vel_acc(m, w, q, t0, qd, qdd)
    qout(:, 1) = q; qdout(:, 1) = qd; qddout(:, 1) = qdd
    rep%ndone = 1
    detprev = w%detsign
    q3 = zero
    t = t0
    if (nsteps == 0) then
      call count_work(); return
    end if
    h = (t1 - t0) / nsteps
    hcur = h
    do k = 1, nsteps
      target = t0 + (t1 - t0) * (real(k, wp) / nsteps)
      if (k == nsteps) target = t1
      do
        ! land exactly on the output time (no sliver step from rounding of t)
        last = hcur >= (target - t) * (one - 1.0e-9_wp)
        hh = merge(target - t, hcur, last)
        tt = merge(target, t + hh, last)
        qn = q + hh * (qd + (half * hh) * (qdd + (hh / 3.0_wp) * q3))
        call kin_newton(m, w, qn, tt, opts%maxit, st)
        if (st == MBD_OK .and. w%detsign == detprev) then
          q = qn
          call kin_vel_acc(m, w, q, tt, qd, qddn)
          q3 = (qddn - qdd) / hh
          qdd = qddn; t = tt
          if (last) exit
          hcur = min(2 * hh, h)
        else
          rep%rejected = rep%rejected + 1
          q3 = zero
          hcur = half * hh
          if (hcur < opts%tmin * max(one, abs(t))) then
            call kin_singular_report(m, w, q, t, rep, st, msg)
            status = MBD_SINGULAR_CONFIG
            if (st /= MBD_OK) then
              status = MBD_LAPACK
            else if (rep%smin > SING_RATIO * rep%smax) then
              ! J is regular here: not a dead centre but a failed step
              status = MBD_NO_CONVERGENCE
              rep%dep = 0; rep%driver = 0; rep%deficiency = 0
              write (msg, '(a,es22.15,a,es9.2,a)') 'no solution could be followed past t = ', t, &
                ' although J is regular there (sigma_min/sigma_max = ', rep%smin / rep%smax, &
                '): a driver may jump or grow too fast for the step'
            end if
            call count_work(); return
          end if
        end if
      end do
      qout(:, k + 1) = q; qdout(:, k + 1) = qd; qddout(:, k + 1) = qdd
      rep%ndone = k + 1
    end do
    call count_work()
  contains
    subroutine count_work()
      rep%newton_its = w%newton_its; rep%lu_count = w%lu_count
    end subroutine count_work
  end subroutine kin_run

end module mbd_kinematics
