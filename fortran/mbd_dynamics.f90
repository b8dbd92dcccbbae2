!> mbd_dynamics: the constrained equations of motion and what the integrators need from them.
!!
!!   M q_ddot + J^T lambda = Q(q, q_dot, t),   Phi(q, t) = 0            (Haug ch. 6)
!! Index 1 (accelerations and multipliers at a state):
!!   [ M    s J^T ] [ q_ddot     ]   [ Q     ]
!!   [ s J  0     ] [ lambda / s ] = [ gamma ]      s: a mass scale, for conditioning
!! Only an independent set of constraint rows enters (redundant rows, found by the rank
!! analysis at the start, carry no multiplier of their own); the reported lambda is the
!! minimum-norm solution of J^T lambda = Q - M q_ddot over all rows. Near a singular
!! configuration (J momentarily rank deficient, as a parallelogram at its collinear
!! position) the LU is nearly singular although q_ddot is still well defined; there the
!! system is solved by a rank-revealing minimum-norm least-squares solve (dgelsy) instead.
!! Also here: applied forces and energies, consistent initial velocities (the kinetic-energy
!! projection [M J^T; J 0][q_dot; mu] = [M v0; nu]), the projection of positions onto Phi = 0
!! (minimum-norm Newton steps), joint reactions and driver efforts.
module mbd_dynamics
  use mbd_kinds, only: wp, zero, one, half
  use mbd_status, only: MBD_OK, MBD_SINGULAR, MBD_NO_CONVERGENCE, MBD_LAPACK, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail
  use mbd_points, only: NLOC, rot
  use mbd_model, only: model_t, model_slots
  use mbd_constraints, only: con_is_driver
  use mbd_forces, only: force_eval, FRC_SPRING, FRC_ROTSPRING
  use mbd_assemble, only: asm_work_t, asm_init, assemble_blocks, assemble_dense
  use mbd_linsolve, only: lu_factor, lu_solve, row_rank, lapack_status, ls_small
  use mbd_lapack, only: dgelsy, dgecon
  implicit none
  private
  public :: dyn_work_t, dyn_init, dyn_memory_check, gen_forces, kinetic_energy, dyn_accel, &
            dyn_velocity, &
            dyn_project_pos, dyn_multipliers, dyn_reactions, dyn_tangent, dyn_solve, &
            dyn_jt_lam, dyn_damped

  !> 1/cond_1 of the augmented matrix below which it is solved by rank-revealing least squares
  real(wp), parameter :: AUG_RCOND = 1.0e-9_wp
  !> what to change when the dense dynamics does not fit
  character(len=*), parameter :: DYN_HINT = 'dynamics, statics and inverse dynamics solve ' // &
    'with dense matrices of the size of J: use a model with fewer coordinates'

  !> Work arrays and the active (independent) constraint rows.
  type :: dyn_work_t
    integer :: n = 0, neq = 0, na = 0     !! coordinates, equations, active rows
    integer, allocatable :: rows(:)       !! active rows
    real(wp) :: s = one                   !! constraint scale in the augmented matrix
    real(wp) :: tol = 1.0e-12_wp          !! position tolerance ||Phi||_inf
    real(wp), allocatable :: phi(:), nu(:), gam(:), jac(:, :), qz(:)
    type(asm_work_t) :: asm               !! assembly work arrays
    real(wp), allocatable :: aug(:, :), rhs(:), force(:), ja(:, :)
    integer, allocatable :: apiv(:)
    !> workspace, so that no solve allocates: dgecon (cw 4 (nq + na), iw), the metric (nq),
    !! the multipliers' J^T (jt), right-hand side (bls) and pivots (jpvt), and the copy of the
    !! augmented matrix a rank-revealing solve works on (acopy, lswork for dgelsy, jp)
    real(wp), allocatable :: cw(:), metric(:), jt(:, :), bls(:), acopy(:, :), lswork(:)
    integer, allocatable :: iw(:), jpvt(:), jp(:)
    integer :: nsolve = 0                 !! augmented factorizations
    integer :: nrank = 0                  !! rank-revealing fallback solves
    logical :: lsq = .false.              !! the last factorization was nearly singular
  end type dyn_work_t

contains

  !> Bytes of the dense dynamics of a model with nq coordinates and neq equations: J, its
  !! transpose, [M J^T; J 0] and a copy, and the integrators' tangent and iteration matrices
  !! (K, C: nq x nq; generalized-alpha: nq + neq square).
  pure real(wp) function dyn_bytes(nq, neq) result(b)
    integer, intent(in) :: nq, neq   !! coordinates, equations
    real(wp) :: n, e
    n = real(nq, wp); e = real(neq, wp)
    b = REAL_BYTES * (2 * n * e + 3 * (n + e)**2 + 2 * n**2 + 12 * (n + e))
  end function dyn_bytes

  !> MBD_NO_MEMORY (and what to change) when the dense dynamics of m (dyn_bytes) cannot fit.
  subroutine dyn_memory_check(m, status, msg)
    type(model_t), intent(in) :: m                 !! model
    integer, intent(out) :: status                 !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(inout) :: msg   !! explanation (on a failure)
    character(len=MSG_LEN) :: what
    write (what, '(a,i0,a,i0,a)') 'the dense dynamics (', m%neq, ' equations, ', m%nq, &
      ' coordinates)'
    call mem_check(dyn_bytes(m%nq, m%neq), trim(what), DYN_HINT, status, msg)
  end subroutine dyn_memory_check

  !> Allocate, and choose the active rows by the rank of J at q (redundant rows out).
  !! The whole dense footprint (dyn_bytes) is checked against the memory first.
  subroutine dyn_init(m, w, q, t, tol, status, msg)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(out) :: w          !! work arrays
    real(wp), intent(in) :: q(:)                !! configuration
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(in) :: tol                 !! absolute position tolerance
    integer, intent(out) :: status              !! MBD_OK, MBD_LAPACK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, allocatable :: red(:)
    integer :: rank, r, na, ierr, nt, info
    real(wp) :: wq(1), rdum(1)
    character(len=MSG_LEN) :: what
    msg = ''
    w%n = m%nq; w%neq = m%neq; w%tol = tol
    write (what, '(a,i0,a,i0,a)') 'the dense dynamics (', m%neq, ' equations, ', m%nq, &
      ' coordinates)'
    call dyn_memory_check(m, status, msg)
    if (status /= MBD_OK) return
    allocate (w%phi(m%neq), w%nu(m%neq), w%gam(m%neq), w%jac(m%neq, m%nq), stat=ierr)
    if (ierr == 0) allocate (w%qz(m%nq), w%force(m%nq), red(m%neq), w%metric(m%nq), stat=ierr)
    if (ierr == 0) allocate (w%jt(m%nq, m%neq), w%bls(max(m%nq, m%neq)), w%jpvt(m%neq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * 2 * real(m%neq, wp) * m%nq, trim(what), DYN_HINT, status, msg)
      return
    end if
    call asm_init(m, w%asm, status, msg)
    if (status /= MBD_OK) return
    w%qz = zero
    call assemble_dense(m, q, w%qz, t, w%phi, w%nu, w%gam, w%asm, w%jac)
    call row_rank(w%jac, rank, red, status, msg)
    if (status /= MBD_OK) return
    na = count(red == 0)
    w%na = na
    nt = m%nq + na
    call dgelsy(nt, nt, 1, rdum, nt, rdum, nt, red, AUG_RCOND, rank, wq, -1, info)
    allocate (w%rows(na), w%aug(nt, nt), w%rhs(nt), w%apiv(nt), w%ja(na, m%nq), stat=ierr)
    if (ierr == 0) allocate (w%cw(4 * nt), w%iw(nt), w%jp(nt), w%acopy(nt, nt), stat=ierr)
    if (ierr == 0) allocate (w%lswork(max(1, int(wq(1)))), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * (real(nt, wp)**2 + real(na, wp) * m%nq), trim(what), DYN_HINT, &
                    status, msg)
      return
    end if
    na = 0
    do r = 1, m%neq
      if (red(r) /= 0) cycle
      na = na + 1
      w%rows(na) = r
    end do
    w%s = one
    if (any(m%mdiag > zero)) w%s = sum(m%mdiag, mask=m%mdiag > zero) / count(m%mdiag > zero)
  end subroutine dyn_init

  !> Applied generalized forces Q(q, q_dot, t) and the potential energy V (gravity, springs);
  !! vload adds the potential of the loads frozen at t (statics).
  pure subroutine gen_forces(m, q, qd, t, force, v, vload)
    type(model_t), intent(in) :: m        !! model
    real(wp), intent(in) :: q(:), qd(:)   !! state
    real(wp), intent(in) :: t             !! time
    real(wp), intent(out) :: force(:)     !! Q (nq)
    real(wp), intent(out) :: v            !! potential energy
    real(wp), intent(out), optional :: vload  !! potential of the loads at t
    real(wp) :: ql(NLOC), qdl(NLOC), fl(NLOC), vk, vl, vls
    integer :: k, s, si, sj
    force = zero; v = zero; vls = zero
    do k = 1, m%nb
      force(3 * k - 2:3 * k - 1) = m%mdiag(3 * k - 2) * m%grav
      v = v - m%mdiag(3 * k - 2) * dot_product(m%grav, q(3 * k - 2:3 * k - 1))
    end do
    do k = 1, m%nf
      do s = 1, NLOC
        ql(s) = zero; qdl(s) = zero
        if (m%floc(s, k) > 0) then
          ql(s) = q(m%floc(s, k)); qdl(s) = qd(m%floc(s, k))
        end if
      end do
      si = merge(1, 0, m%fbi(k) > 0); sj = merge(2, 0, m%fbj(k) > 0)
      call force_eval(m%fkind(k), m%fp(m%fpo(k):m%fpo(k) + m%fpn(k) - 1), si, sj, ql, qdl, t, &
                      fl, vk, vl)
      do s = 1, NLOC
        if (m%floc(s, k) > 0) force(m%floc(s, k)) = force(m%floc(s, k)) + fl(s)
      end do
      v = v + vk; vls = vls + vl
    end do
    if (present(vload)) vload = vls
  end subroutine gen_forces

  !> T = q_dot^T M q_dot / 2.
  pure real(wp) function kinetic_energy(m, qd)
    type(model_t), intent(in) :: m      !! model
    real(wp), intent(in) :: qd(:)       !! velocities
    kinetic_energy = half * sum(m%mdiag * qd**2)
  end function kinetic_energy

  !> Factor [M s Ja^T; s Ja 0] with Ja = J(rows) from w%jac. Nearly singular (1/cond_1 below
  !! AUG_RCOND, or an exact zero pivot): w%lsq is set and solve_aug uses dgelsy.
  subroutine factor_aug(m, w, metric, status)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    real(wp), intent(in) :: metric(:)     ! diagonal of the upper-left block
    integer, intent(out) :: status
    character(len=MSG_LEN) :: msg
    real(wp) :: anorm, rc, pr, umin, umax
    integer :: info, k, nt
    call build_aug(m, w, metric)
    nt = m%nq + w%na
    anorm = zero
    do k = 1, nt
      anorm = max(anorm, sum(abs(w%aug(:, k))))
    end do
    call lu_factor(w%aug, w%apiv, status, msg)
    w%nsolve = w%nsolve + 1
    w%lsq = status /= MBD_OK
    if (.not. w%lsq) then
      umin = huge(one); umax = zero
      do k = 1, nt
        umin = min(umin, abs(w%aug(k, k))); umax = max(umax, abs(w%aug(k, k)))
      end do
      pr = umin / umax
      if (pr < 1.0e-6_wp) then
        call dgecon('1', nt, w%aug, nt, anorm, rc, w%cw, w%iw, info)
        w%lsq = rc < AUG_RCOND
      end if
    end if
    if (w%lsq) then
      call build_aug(m, w, metric)        ! keep the matrix itself for dgelsy
      status = MBD_OK
    end if
  end subroutine factor_aug

  !> The augmented matrix itself.
  subroutine build_aug(m, w, metric)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    real(wp), intent(in) :: metric(:)
    integer :: i, j, n
    n = m%nq
    do j = 1, n          ! (loops: a vector subscript or transpose() would make temporaries)
      do i = 1, w%na
        w%ja(i, j) = w%jac(w%rows(i), j)
      end do
    end do
    w%aug = zero
    do i = 1, n
      w%aug(i, i) = metric(i)
    end do
    do j = 1, w%na
      do i = 1, n
        w%aug(i, n + j) = w%s * w%ja(j, i)
      end do
    end do
    do j = 1, n
      do i = 1, w%na
        w%aug(n + i, j) = w%s * w%ja(i, j)
      end do
    end do
  end subroutine build_aug

  !> Another right-hand side with the last augmented matrix (Baumgarte's modified gamma).
  subroutine dyn_solve(w, rhs, status)
    type(dyn_work_t), intent(inout) :: w     !! work arrays with the last augmented matrix
    real(wp), intent(inout) :: rhs(:)        !! right-hand side, then solution
    integer, intent(out) :: status           !! MBD_OK or MBD_LAPACK
    call solve_aug(w, rhs, status)
  end subroutine dyn_solve

  !> Solve with the factored augmented matrix, or by the minimum-norm least-squares solve
  !! when it is nearly singular (the matrix then is unfactored; dgelsy works on a copy).
  subroutine solve_aug(w, rhs, status)
    type(dyn_work_t), intent(inout) :: w
    real(wp), intent(inout) :: rhs(:)
    integer, intent(out) :: status
    character(len=MSG_LEN) :: msg
    integer :: rank, info, nt
    if (.not. w%lsq) then
      call lu_solve(w%aug, w%apiv, rhs, status, msg)
      return
    end if
    nt = size(rhs)
    w%acopy = w%aug
    w%jp = 0
    call dgelsy(nt, nt, 1, w%acopy, nt, rhs, nt, w%jp, AUG_RCOND, rank, w%lswork, &
                size(w%lswork), info)
    call lapack_status('dgelsy', info, status, msg)
    w%nrank = w%nrank + 1
  end subroutine solve_aug

  !> Accelerations and multipliers: [M J^T; J 0][q_ddot; lambda] = [Q; gamma] (active rows).
  !! lam is filled on the active rows (zero elsewhere); dyn_multipliers gives the
  !! minimum-norm multipliers over all rows.
  subroutine dyn_accel(m, w, q, qd, t, qdd, lam, status)
    type(model_t), intent(in) :: m           !! model
    type(dyn_work_t), intent(inout) :: w     !! work arrays
    real(wp), intent(in) :: q(:), qd(:)      !! state
    real(wp), intent(in) :: t                !! time
    real(wp), intent(out) :: qdd(:)          !! accelerations
    real(wp), intent(out) :: lam(:)          !! multipliers (neq)
    integer, intent(out) :: status           !! MBD_OK or MBD_SINGULAR
    real(wp) :: v
    integer :: n, k
    n = m%nq
    call assemble_dense(m, q, qd, t, w%phi, w%nu, w%gam, w%asm, w%jac)
    call gen_forces(m, q, qd, t, w%force, v)
    call factor_aug(m, w, m%mdiag, status)
    if (status /= MBD_OK) return
    w%rhs(1:n) = w%force
    call gather_rows(w, w%gam, w%s)
    call solve_aug(w, w%rhs, status)
    qdd = w%rhs(1:n)
    lam = zero
    do k = 1, w%na                 ! (loops: vector subscripts make heap temporaries)
      lam(w%rows(k)) = w%s * w%rhs(n + k)
    end do
  end subroutine dyn_accel

  !> w%rhs(nq + k) = f x(rows(k)) over the active rows (a loop: a vector subscript would
  !! make a heap temporary at every call).
  pure subroutine gather_rows(w, x, f)
    type(dyn_work_t), intent(inout) :: w
    real(wp), intent(in) :: x(:)
    real(wp), intent(in) :: f
    integer :: k
    do k = 1, w%na
      w%rhs(w%n + k) = f * x(w%rows(k))
    end do
  end subroutine gather_rows

  !> Velocities consistent with J q_dot = nu, nearest to v0 in kinetic energy:
  !! [M J^T; J 0][q_dot; mu] = [M v0; nu]. Massless coordinates get the unit metric.
  subroutine dyn_velocity(m, w, q, t, v0, qd, status)
    type(model_t), intent(in) :: m           !! model
    type(dyn_work_t), intent(inout) :: w     !! work arrays
    real(wp), intent(in) :: q(:)             !! configuration
    real(wp), intent(in) :: t                !! time
    real(wp), intent(in) :: v0(:)            !! velocity estimate
    real(wp), intent(out) :: qd(:)           !! consistent velocities
    integer, intent(out) :: status           !! MBD_OK or MBD_SINGULAR
    integer :: n
    n = m%nq
    w%metric = merge(m%mdiag, w%s, m%mdiag > zero)
    call assemble_dense(m, q, w%qz, t, w%phi, w%nu, w%gam, w%asm, w%jac)
    call factor_aug(m, w, w%metric, status)
    if (status /= MBD_OK) return
    w%rhs(1:n) = w%metric * v0
    call gather_rows(w, w%nu, w%s)
    call solve_aug(w, w%rhs, status)
    qd = w%rhs(1:n)
  end subroutine dyn_velocity

  !> Project q onto Phi(q, t) = 0 by minimum-norm Newton steps:
  !! [I J^T; J 0][dq; mu] = [0; -Phi] (active rows), to ||Phi||_inf <= w%tol.
  subroutine dyn_project_pos(m, w, q, t, status)
    type(model_t), intent(in) :: m           !! model
    type(dyn_work_t), intent(inout) :: w     !! work arrays
    real(wp), intent(inout) :: q(:)          !! configuration, projected
    real(wp), intent(in) :: t                !! time
    integer, intent(out) :: status           !! MBD_OK, MBD_NO_CONVERGENCE or MBD_SINGULAR
    integer :: it, n
    n = m%nq
    w%metric = one
    do it = 1, 20
      call assemble_dense(m, q, w%qz, t, w%phi, w%nu, w%gam, w%asm, w%jac)
      status = MBD_OK
      if (maxval(abs(w%phi)) <= w%tol) return
      call factor_aug(m, w, w%metric, status)
      if (status /= MBD_OK) return
      w%rhs(1:n) = zero
      call gather_rows(w, w%phi, -w%s)
      call solve_aug(w, w%rhs, status)
      q = q + w%rhs(1:n)
    end do
    status = MBD_NO_CONVERGENCE
  end subroutine dyn_project_pos

  !> Minimum-norm multipliers over all rows: lambda = argmin ||l|| with J^T l = Q - M q_ddot.
  !! With independent rows this is the unique lambda (Householder least squares, ls_small);
  !! with redundant rows, or J^T numerically rank deficient, the reactions are statically
  !! indeterminate and this is the smallest set (LAPACK dgelsy).
  subroutine dyn_multipliers(m, w, q, qd, qdd, t, lam, status, msg)
    type(model_t), intent(in) :: m            !! model
    type(dyn_work_t), intent(inout) :: w      !! work arrays
    real(wp), intent(in) :: q(:), qd(:), qdd(:)  !! state and accelerations
    real(wp), intent(in) :: t                 !! time
    real(wp), intent(out) :: lam(:)           !! multipliers (neq)
    integer, intent(out) :: status            !! MBD_OK, MBD_LAPACK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    real(wp) :: v, wq(1)
    real(wp), allocatable :: work(:)
    integer :: rank, info, lwork, ierr
    logical :: full
    call assemble_dense(m, q, qd, t, w%phi, w%nu, w%gam, w%asm, w%jac)
    call gen_forces(m, q, qd, t, w%force, v)
    w%jt = transpose(w%jac)
    w%bls = zero
    w%bls(1:m%nq) = w%force - m%mdiag * qdd
    status = MBD_OK
    if (w%na == m%neq .and. m%neq <= m%nq) then
      ! independent rows: the unique solution, by a plain Householder QR (no allocation)
      call ls_small(w%jt, w%bls, full)
      if (full) then
        lam = w%bls(1:m%neq); return
      end if
      w%jt = transpose(w%jac)
      w%bls = zero
      w%bls(1:m%nq) = w%force - m%mdiag * qdd
    end if
    w%jpvt = 0
    call dgelsy(m%nq, m%neq, 1, w%jt, m%nq, w%bls, size(w%bls), w%jpvt, 1.0e-10_wp, rank, wq, &
                -1, info)
    lwork = max(1, int(wq(1)))
    allocate (work(lwork), stat=ierr)
    if (ierr /= 0) then
      lam = zero
      call mem_fail(REAL_BYTES * lwork, 'the least-squares multipliers', 'use a smaller model', &
                    status, msg)
      return
    end if
    call dgelsy(m%nq, m%neq, 1, w%jt, m%nq, w%bls, size(w%bls), w%jpvt, 1.0e-10_wp, rank, work, &
                lwork, info)
    call lapack_status('dgelsy', info, status, msg)
    lam = w%bls(1:m%neq)
  end subroutine dyn_multipliers

  !> Reactions of each constraint on its two bodies, from lambda: the generalized constraint
  !! force -J_k^T lambda_k on body i and on body j: (Fx, Fy, Mz) global, Mz about the centre
  !! of mass; and the same forces in each body's frame (A^T F, Mz).
  !! reac(1:6, k) = [Fx_i, Fy_i, Mz_i, Fx_j, Fy_j, Mz_j] global; rloc likewise local.
  subroutine dyn_reactions(m, w, q, t, lam, reac, rloc)
    type(model_t), intent(in) :: m            !! model
    type(dyn_work_t), intent(inout) :: w      !! work arrays
    real(wp), intent(in) :: q(:)              !! configuration
    real(wp), intent(in) :: t                 !! time
    real(wp), intent(in) :: lam(:)            !! multipliers (neq)
    real(wp), intent(out) :: reac(:, :)       !! (6, nc) global
    real(wp), intent(out) :: rloc(:, :)       !! (6, nc) in the body frames
    real(wp) :: g(NLOC), a(2, 2)
    integer :: k, r0, nr
    call assemble_blocks(m, q, w%qz, t, w%phi, w%nu, w%gam, w%asm)
    do k = 1, m%nc
      r0 = m%row0(k); nr = m%nrow(k)
      g = -matmul(lam(r0:r0 + nr - 1), w%asm%jb(1:nr, :, k))
      reac(:, k) = g(1:6)
      rloc(:, k) = g(1:6)
      if (m%bi(k) > 0) then
        a = rot(q(3 * m%bi(k)))
        rloc(1:2, k) = matmul(transpose(a), g(1:2))
      else
        reac(1:3, k) = zero; rloc(1:3, k) = zero
      end if
      if (m%bj(k) > 0) then
        a = rot(q(3 * m%bj(k)))
        rloc(4:5, k) = matmul(transpose(a), g(4:5))
      else
        reac(4:6, k) = zero; rloc(4:6, k) = zero
      end if
    end do
  end subroutine dyn_reactions

  !> Tangent matrices of the residual r = J^T lambda - Q(q, q_dot, t) by differences:
  !! kt = dr/dq = d(J^T lambda)/dq - dQ/dq (the geometric term included), ct = dr/dq_dot =
  !! -dQ/dq_dot. Central differences (4 nq residuals), or with fast = .true. forward
  !! differences (nq + 1 residuals) and ct only when a force is damped (otherwise ct = 0):
  !! enough for an iteration matrix, which only steers Newton. Allocation-free.
  subroutine dyn_tangent(m, w, q, qd, t, lam, kt, ct, fast)
    type(model_t), intent(in) :: m            !! model
    type(dyn_work_t), intent(inout) :: w      !! work arrays
    real(wp), intent(in) :: q(:), qd(:)       !! state
    real(wp), intent(in) :: t                 !! time
    real(wp), intent(in) :: lam(:)            !! multipliers (neq)
    real(wp), intent(out) :: kt(:, :), ct(:, :)  !! (nq, nq) tangent stiffness and damping
    logical, intent(in), optional :: fast     !! forward differences, ct only if damped
    real(wp), parameter :: SQEPS = 1.5e-8_wp  ! ~ sqrt(machine epsilon)
    real(wp) :: qp(m%nq), r0(m%nq), rp(m%nq), rm(m%nq), hk
    integer :: k
    logical :: fwd
    fwd = .false.
    if (present(fast)) fwd = fast
    if (fwd) then
      ! forward: K e_k = (r(q + h e_k) - r(q)) / h
      call residual(q, qd, r0)
      qp = q
      do k = 1, m%nq
        hk = SQEPS * max(one, abs(q(k)))
        qp(k) = q(k) + hk
        hk = qp(k) - q(k)                      ! the step actually taken
        call residual(qp, qd, rp)
        qp(k) = q(k)
        kt(:, k) = (rp - r0) / hk
      end do
      ct = zero
      if (.not. dyn_damped(m)) return
      qp = qd
      do k = 1, m%nq
        hk = SQEPS * max(one, abs(qd(k)))
        qp(k) = qd(k) + hk
        hk = qp(k) - qd(k)
        call residual(q, qp, rp)
        qp(k) = qd(k)
        ct(:, k) = (rp - r0) / hk
      end do
      return
    end if
    qp = q
    do k = 1, m%nq
      hk = 1.0e-7_wp * max(one, abs(q(k)))
      qp(k) = q(k) + hk
      call residual(qp, qd, rp)
      qp(k) = q(k) - hk
      call residual(qp, qd, rm)
      qp(k) = q(k)
      kt(:, k) = (rp - rm) / (2 * hk)
    end do
    qp = qd
    do k = 1, m%nq
      hk = 1.0e-7_wp * max(one, abs(qd(k)))
      qp(k) = qd(k) + hk
      call residual(q, qp, rp)
      qp(k) = qd(k) - hk
      call residual(q, qp, rm)
      qp(k) = qd(k)
      ct(:, k) = (rp - rm) / (2 * hk)
    end do
  contains
    subroutine residual(qa, qda, r)
      real(wp), intent(in) :: qa(:), qda(:)
      real(wp), intent(out) :: r(:)
      real(wp) :: v
      integer :: j
      call assemble_blocks(m, qa, qda, t, w%phi, w%nu, w%gam, w%asm)
      call gen_forces(m, qa, qda, t, w%force, v)
      call dyn_jt_lam(m, w%asm%jb, lam, r)
      do j = 1, m%nq
        r(j) = r(j) - w%force(j)
      end do
    end subroutine residual
  end subroutine dyn_tangent

  !> r = J^T lambda from the local Jacobian blocks (no dense J): each constraint adds
  !! jb_k^T lambda_k to the coordinates of its slots.
  pure subroutine dyn_jt_lam(m, jb, lam, r)
    type(model_t), intent(in) :: m            !! model
    real(wp), intent(in) :: jb(:, :, :)       !! local blocks (MAXROW, NLOC, nc)
    real(wp), intent(in) :: lam(:)            !! multipliers (neq)
    real(wp), intent(out) :: r(:)             !! J^T lambda (nq)
    integer :: k, s, c, r0, i
    real(wp) :: acc
    r = zero
    do k = 1, m%nc
      r0 = m%row0(k) - 1
      do s = 1, NLOC
        c = m%loc(s, k)
        if (c == 0) cycle
        acc = zero
        do i = 1, m%nrow(k)
          acc = acc + jb(i, s, k) * lam(r0 + i)
        end do
        r(c) = r(c) + acc
      end do
    end do
  end subroutine dyn_jt_lam

  !> A force depends on q_dot: a damped spring or rotational spring.
  pure logical function dyn_damped(m)
    type(model_t), intent(in) :: m           !! model
    integer :: k, o
    dyn_damped = .false.
    do k = 1, m%nf
      o = m%fpo(k)
      select case (m%fkind(k))
      case (FRC_SPRING)
        if (abs(m%fp(o + 5)) > zero) dyn_damped = .true.
      case (FRC_ROTSPRING)
        if (abs(m%fp(o + 1)) > zero) dyn_damped = .true.
      end select
    end do
  end function dyn_damped

end module mbd_dynamics
