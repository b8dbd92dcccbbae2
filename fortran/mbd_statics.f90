!> mbd_statics: static equilibrium under gravity, springs and applied loads.
!!
!! An equilibrium is a stationary point of the total potential V(q) (gravity, springs, and
!! the loads frozen at time t) on the constraint manifold Phi(q, t) = 0:
!!   J^T lambda = Q(q, 0, t),  Phi(q, t) = 0.
!! The search is a saddle-free Newton method on the manifold: with N an orthonormal basis of
!! the null space of J (SVD) and K = d(J^T lambda - Q)/dq (central differences), the reduced
!! Hessian H = N^T K N has its eigenvalues replaced by their absolute values (bounded away
!! from zero), the step N dz with H dz = N^T Q is projected back onto Phi = 0, and a
!! backtracking line search keeps V decreasing. So it converges to a stable equilibrium from
!! any start on the manifold; the signs of the eigenvalues of H there give the stability.
module mbd_statics
  use mbd_kinds, only: wp, zero, one, half
  use mbd_status, only: MBD_OK, MBD_NO_CONVERGENCE, MBD_SINGULAR, MBD_NO_MEMORY, MSG_LEN
  use mbd_model, only: model_t
  use mbd_assemble, only: assemble_dense
  use mbd_lapack, only: dgesvd, dsyev
  use mbd_dynamics, only: dyn_work_t, gen_forces, dyn_tangent, dyn_project_pos, &
                          dyn_multipliers
  implicit none
  private
  public :: statics_solve

contains

  !> Equilibrium near q (assembled), least-squares multipliers lam, stability.
  !! stable: 1 stable, 0 unstable, -1 neutral (a zero reduced stiffness), 2 fully constrained.
  subroutine statics_solve(m, w, q, t, lam, stable, resid, status, msg)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! work arrays (dyn_init done)
    real(wp), intent(inout) :: q(:)             !! start, then the equilibrium
    real(wp), intent(in) :: t                   !! time (drivers and loads are held here)
    real(wp), intent(out) :: lam(:)             !! multipliers (neq)
    integer, intent(out) :: stable              !! stability of the equilibrium
    real(wp), intent(out) :: resid              !! final ||N^T Q||
    integer, intent(out) :: status              !! MBD_OK, MBD_NO_CONVERGENCE, MBD_SINGULAR
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    real(wp), allocatable :: nb(:, :), h(:, :), ev(:), g(:), dz(:)
    real(wp) :: kt(m%nq, m%nq), ct(m%nq, m%nq), qt(m%nq), v0, vt, alpha, gscale, emax
    integer :: it, ls, nfree, i, stp
    character(len=MSG_LEN) :: lmsg
    logical :: nomem                          ! an allocation in null_space or eigen failed
    status = MBD_OK; msg = ''; stable = 2; resid = zero
    nomem = .false.
    gscale = max(one, maxval(abs(m%mdiag)) * max(one, norm2(m%grav)))
    call dyn_project_pos(m, w, q, t, status)
    if (status /= MBD_OK) then
      msg = 'statics: the constraints cannot be satisfied near the estimates'; return
    end if
    do it = 1, 200
      call null_space(nb, nfree)
      if (nomem) exit
      if (nfree == 0) exit                   ! nothing can move: q is the equilibrium
      v0 = potential(q)
      g = matmul(transpose(nb), w%force)     ! reduced load N^T Q (= -reduced gradient of V)
      resid = maxval(abs(g))
      if (resid <= 1.0e-11_wp * gscale) exit
      call dyn_multipliers(m, w, q, w%qz, w%qz, t, lam, stp, lmsg)
      call dyn_tangent(m, w, q, w%qz, t, lam, kt, ct)
      h = matmul(transpose(nb), matmul(half * (kt + transpose(kt)), nb))
      call eigen(h, ev, .true.)
      if (nomem) exit
      ! saddle-free: |eigenvalues|, bounded below (a flat direction gets a gradient step
      ! of about the model's length scale)
      emax = max(1.0e-8_wp * maxval(abs(ev)), norm2(g) / m%lscale)
      dz = matmul(transpose(h), g)
      do i = 1, nfree
        dz(i) = dz(i) / max(abs(ev(i)), emax)
      end do
      dz = matmul(h, dz)
      alpha = one
      do ls = 1, 40
        qt = q + alpha * matmul(nb, dz)
        call dyn_project_pos(m, w, qt, t, stp)
        if (stp == MBD_OK) then
          vt = potential(qt)
          if (vt < v0 - 1.0e-4_wp * alpha * dot_product(g, dz) .or. &
              vt <= v0 + 1.0e-14_wp * abs(v0) .and. ls > 30) exit
        end if
        alpha = half * alpha
      end do
      if (ls > 40) exit
      q = qt
    end do
    if (.not. nomem) call null_space(nb, nfree)
    if (nomem) then
      status = MBD_NO_MEMORY
      msg = 'not enough memory for the statics (null space and reduced stiffness, dense): '// &
            'use a model with fewer coordinates'
      return
    end if
    call dyn_multipliers(m, w, q, w%qz, w%qz, t, lam, stp, lmsg)
    if (nfree == 0) then
      stable = 2; resid = zero; return
    end if
    g = matmul(transpose(nb), w%force)
    resid = maxval(abs(g))
    if (resid > 1.0e-8_wp * gscale) then
      status = MBD_NO_CONVERGENCE
      write (msg, '(a,es10.3)') 'statics: no equilibrium found near the estimates; '// &
        'unbalanced load ', resid
      return
    end if
    call dyn_tangent(m, w, q, w%qz, t, lam, kt, ct)
    h = matmul(transpose(nb), matmul(half * (kt + transpose(kt)), nb))
    call eigen(h, ev, .false.)
    if (nomem) then
      status = MBD_NO_MEMORY
      msg = 'not enough memory for the stability analysis (dense): use a model with fewer '// &
            'coordinates'
      return
    end if
    emax = max(maxval(abs(ev)), tiny(one))
    if (minval(ev) > 1.0e-9_wp * emax) then
      stable = 1
    else if (minval(ev) < -1.0e-9_wp * emax) then
      stable = 0
    else
      stable = -1
    end if
  contains
    !> V at qa: gravity, springs and the loads frozen at t (also fills w%force at qa).
    real(wp) function potential(qa)
      real(wp), intent(in) :: qa(:)
      real(wp) :: v, vl
      call gen_forces(m, qa, w%qz, t, w%force, v, vl)
      potential = v + vl
    end function potential

    !> Orthonormal basis of the null space of J at q (columns of nb); also loads w%force.
    subroutine null_space(basis, nfr)
      real(wp), allocatable, intent(out) :: basis(:, :)
      integer, intent(out) :: nfr
      real(wp) :: ja(w%na, m%nq), sv(min(w%na, m%nq)), u(1, 1), vt(m%nq, m%nq), wq(1), v
      real(wp), allocatable :: work(:)
      integer :: info, rk
      call assemble_dense(m, q, w%qz, t, w%phi, w%nu, w%gam, w%asm, w%jac)
      call gen_forces(m, q, w%qz, t, w%force, v)
      ja = w%jac(w%rows, :)
      call dgesvd('N', 'A', w%na, m%nq, ja, w%na, sv, u, 1, vt, m%nq, wq, -1, info)
      allocate (work(max(1, int(wq(1)))), stat=info)
      if (info /= 0) then
        nomem = .true.; nfr = 0; return
      end if
      call dgesvd('N', 'A', w%na, m%nq, ja, w%na, sv, u, 1, vt, m%nq, work, size(work), info)
      rk = 0
      if (size(sv) > 0) rk = count(sv > 1.0e-10_wp * maxval(sv))
      nfr = m%nq - rk
      basis = transpose(vt(rk + 1:m%nq, :))
    end subroutine null_space

    !> Eigenvalues (and, when vectors, the vectors in a) of a symmetric matrix.
    subroutine eigen(a, e, vectors)
      real(wp), intent(inout) :: a(:, :)
      real(wp), allocatable, intent(out) :: e(:)
      logical, intent(in) :: vectors
      real(wp) :: wq(1)
      real(wp), allocatable :: work(:)
      integer :: nn, info
      character(len=1) :: job
      nn = size(a, 1)
      allocate (e(nn), stat=info)
      if (info /= 0) then
        nomem = .true.; return
      end if
      job = merge('V', 'N', vectors)
      call dsyev(job, 'U', nn, a, nn, e, wq, -1, info)
      allocate (work(max(1, int(wq(1)))), stat=info)
      if (info /= 0) then
        nomem = .true.; return
      end if
      call dsyev(job, 'U', nn, a, nn, e, work, size(work), info)
    end subroutine eigen
  end subroutine statics_solve

end module mbd_statics
