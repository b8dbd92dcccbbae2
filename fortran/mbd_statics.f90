!> mbd_statics: static equilibrium under gravity, springs and applied loads.
!!
!! An equilibrium solves the equilibrium equations on the constraint manifold
!!   Q(q, 0, t) - J^T lambda = 0,   Phi(q, t) = 0,
!! i.e. the reduced load g = N^T Q vanishes (N an orthonormal basis of the null space of J,
!! by SVD; N^T J^T = 0, so lambda drops out). Convergence is decided on g and Phi, never on
!! the potential V(q) (gravity, springs, the loads frozen at t): near an equilibrium V changes
!! by less than its own rounding error (about eps |V|, which grows with any constant added
!! to V), while g keeps resolving the equilibrium to round-off.
!! Each step is a Newton step of the equilibrium equations (Haug ch. 6; Nocedal and Wright
!! ch. 18, the null-space method): with K = d(J^T lambda - Q)/dq (lambda the least-squares
!! multipliers) and H = N^T K_sym N the reduced stiffness, K_sym = (K + K^T) / 2,
!!   dq = dq_n + N dz,  dq_n = -J^+ Phi (minimum-norm),  H dz = g - N^T K_sym dq_n.
!! K is exact when the caller gives the design sensitivities' blocks (a model without contacts:
!! K x = K_lambda x - Q_q x, sens_stiffness_mul, the blocks at each iterate by
!! sens_stiffness_at), and N^T K_sym dq_n = (N^T K dq_n + (K N)^T dq_n) / 2; else from
!! central differences on K's sparse pattern (dyn_tangent).
!! Globalisation (saddle-free): far from an equilibrium H's eigenvalues are replaced by their
!! absolute values (bounded away from zero), the step is projected onto Phi = 0 and a
!! backtracking line search keeps V decreasing, so the search goes downhill to a stable
!! equilibrium from any start. Once the decrease of V a full step predicts, g^T dz, is within
!! 100 times V's rounding error (V can no longer judge a step), full Newton steps follow while
!! they reduce the residual of the equilibrium equations, ||g|| / F + ||Phi|| / l (F the
!! force scale, l the model's length scale), and stop where it no longer halves: round-off.
!! The signs of the eigenvalues of H at the end give the stability.
!! Band path (w%solver, large models; no n x n array): the active rows are independent
!! (dyn_init's band rank analysis), so N has n - na columns, taken from projections of fixed
!! vectors onto the null space (dyn_null_basis) instead of the SVD; dq_n and the multipliers
!! from saddle-point solves [s I, s J^T; s J, 0]; K on its sparse pattern (differences over
!! column groups), K N column by column. The work is O(n nfree^2 + n nfree bw), linear in n
!! for a fixed number of free motions.
!! Memory: the dense work arrays (five n x n; band path: three n x nfree) are checked and
!! allocated once per call, with MBD_NO_MEMORY when they cannot be had; the iterations
!! allocate nothing.
module mbd_statics
  use mbd_kinds, only: wp, zero, one, half, eps
  use mbd_status, only: MBD_OK, MBD_NO_CONVERGENCE, MBD_LAPACK, MBD_SINGULAR, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail, mem_grow
  use mbd_model, only: model_t
  use mbd_assemble, only: blocks_jtv
  use mbd_lapack, only: dgesvd, dsyev
  use mbd_dynamics, only: dyn_work_t, gen_forces, dyn_tangent, dyn_project_pos, &
                          dyn_multipliers, dyn_null_basis, dyn_solve, dyn_pattern_mul, &
                          SOLVER_DENSE
  use mbd_sensitivity, only: sens_t
  use mbd_sens_dynamics, only: sens_stiffness_at, sens_stiffness_mul, sens_tangent_pattern
  implicit none
  private
  public :: statics_solve

  integer, parameter :: MAXIT = 200          !! steps in all
  integer, parameter :: MAXLS = 40           !! halvings of a line search
  real(wp), parameter :: ARMIJO = 1.0e-4_wp  !! sufficient decrease of V
  real(wp), parameter :: V_NOISE = 64 * eps  !! rounding error of V, relative to its terms
  !> ||g|| / F above which no equilibrium was found (F: the largest load, Q or J^T lambda)
  real(wp), parameter :: RESID_FAIL = 1.0e-8_wp
  real(wp), parameter :: RANK_TOL = 1.0e-10_wp  !! singular values of J taken as zero
  character(len=*), parameter :: HINT = 'statics solves with dense matrices of the size of ' &
    // 'J: use a model with fewer coordinates'

contains

  !> Equilibrium near q (assembled), least-squares multipliers lam, stability.
  !! stable: 1 stable, 0 unstable, -1 neutral (a zero reduced stiffness), 2 fully constrained.
  subroutine statics_solve(m, w, q, t, lam, stable, resid, status, msg, s)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! work arrays (dyn_init done)
    real(wp), intent(inout) :: q(:)             !! start, then the equilibrium
    real(wp), intent(in) :: t                   !! time (drivers and loads are held here)
    real(wp), intent(out) :: lam(:)             !! multipliers (neq)
    integer, intent(out) :: stable              !! stability of the equilibrium
    !> final ||N^T Q||_inf / max(F, |H| l) (F: the loads, |H| l: the stiffness over the length
    !! scale)
    real(wp), intent(out) :: resid
    integer, intent(out) :: status  !! MBD_OK, MBD_NO_CONVERGENCE, MBD_LAPACK, MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    !> the design sensitivities' blocks (sens_setup done; no contacts): K exact; absent, K by
    !! central differences
    type(sens_t), intent(inout), optional :: s
    ! work arrays, allocated once: h holds H, then its eigenvectors; r, c, dqz and qt are
    ! vectors of the steps; work is LAPACK's workspace (grown when a query asks for more)
    real(wp), allocatable :: nb(:, :), h(:, :), ev(:), g(:), dz(:), dqn(:), kt(:, :), &
                             ct(:, :), qt(:), ja(:, :), sv(:), u(:, :), vt(:, :), work(:), &
                             r(:), c(:), dqz(:), kv(:), cv(:)
    integer, allocatable :: ktr(:)
    real(wp) :: v0, vt1, alpha, emax, fscale, vnoise, e0, e1, gn, pn, slope, bytes, fmag, &
                gq, fq
    integer :: it, ls, nfree, n, na, stp, ist, nu, nnz, nn, nf0, nfq
    ! fresh: the arrays (N, g, H, lam, ...) hold q's reduction (a Newton step's trial point
    ! became q); eig_q: ev holds H(q)'s eigenvalues (the last Newton step's), with q's
    ! ||g||_inf in gq, force scale in fq and free motions in nfq
    logical :: local, band, exact, bycols, fresh, eig_q
    character(len=MSG_LEN) :: lmsg, what
    status = MBD_OK; msg = ''; stable = 2; resid = zero
    n = m%nq; na = w%na; nu = min(na, n)
    band = w%solver /= SOLVER_DENSE
    exact = present(s)
    nnz = w%kptr(n + 1) - 1
    if (band) then
      nf0 = max(n - na, 1); nn = nf0
      bytes = REAL_BYTES * (3 * real(n, wp) * nf0 + real(nf0, wp)**2 + 10 * real(n, wp) + &
                            2 * real(nnz, wp))
      write (what, '(a,i0,a,i0,a)') 'the statics work arrays (', n, ' coordinates, ', &
        n - na, ' free motions, band path)'
    else
      nf0 = n; nn = n
      bytes = REAL_BYTES * (5 * real(n, wp)**2 + real(max(na, 1), wp) * (n + max(nu, 1)) &
                            + 10 * real(n, wp) + max(nu, 1) + 2 * real(nnz, wp))
      write (what, '(a,i0,a)') 'the statics work arrays (', n, ' coordinates, dense)'
    end if
    call mem_check(bytes, trim(what), HINT, status, msg)
    if (status /= MBD_OK) return
    allocate (nb(n, nf0), h(nf0, nf0), ct(n, nf0), kv(nnz), cv(nnz), ktr(nnz), stat=ist)
    if (ist == 0 .and. .not. band) allocate (kt(n, n), vt(n, n), stat=ist)
    if (ist == 0) allocate (ev(n), g(n), dz(n), dqn(n), qt(n), r(n), c(n), dqz(n), stat=ist)
    if (ist == 0 .and. .not. band) &
      allocate (ja(max(na, 1), n), sv(max(nu, 1)), u(max(na, 1), max(nu, 1)), stat=ist)
    if (ist == 0) allocate (work(1), stat=ist)
    if (ist /= 0) then
      call mem_fail(bytes, trim(what), HINT, status, msg)
      return
    end if
    call transpose_map()
    call dyn_project_pos(m, w, q, t, status)
    if (status /= MBD_OK) then
      msg = 'statics: the constraints cannot be satisfied near the estimates'; return
    end if
    local = .false.
    fresh = .false.
    eig_q = .false.
    e0 = huge(one)
    do it = 1, MAXIT
      if (.not. fresh) call reduce(q, status) ! N, g, lam, dq_n, H at q
      if (status /= MBD_OK) return
      fresh = .true.; eig_q = .false.
      if (nfree == 0) exit                    ! nothing can move: q is the equilibrium
      gn = maxval(abs(g(1:nfree)))
      if (.not. (gn > zero .or. maxval(abs(dqn)) > zero)) exit   ! exactly balanced
      call newton_step(status)                ! (H's eigenvalues at q in ev)
      if (status /= MBD_OK) return
      fresh = .false.                         ! (h holds H's eigenvectors now)
      eig_q = .true.; gq = gn; fq = fscale; nfq = nfree
      call null_mul(dz, dqz)                   ! the step in q: N dz
      if (.not. local) then
        ! V can judge a step only while the decrease it predicts exceeds its rounding
        slope = dot_product(g(1:nfree), dz(1:nfree))
        if (slope <= 100 * vnoise) then
          local = .true.
        else
          alpha = one
          do ls = 1, MAXLS
            qt = q + alpha * dqz
            call dyn_project_pos(m, w, qt, t, stp)
            if (stp == MBD_OK) then
              vt1 = potential(qt)
              if (vt1 < v0 - ARMIJO * alpha * slope) exit
            end if
            alpha = half * alpha
          end do
          if (ls > MAXLS) then
            local = .true.                    ! no decrease V can resolve: polish by Newton
          else
            q = qt; eig_q = .false.
          end if
          cycle
        end if
      end if
      ! local Newton on the equilibrium equations: full steps while the residual falls
      e0 = merit(gn, pn)
      qt = q + dqn + dqz
      call reduce(qt, status)
      if (status /= MBD_OK) return
      eig_q = eig_q .and. nfree == nfq         ! (ev: q's, the arrays: qt's)
      if (nfree == 0) then
        q = qt; fresh = .true.; exit
      end if
      e1 = merit(maxval(abs(g(1:nfree))), pn)
      if (.not. (e1 < e0)) exit                ! no progress: round-off reached (q kept)
      q = qt
      fresh = .true.; eig_q = .false.          ! (the arrays are q's: no reduce at the top)
      if (e1 > half * e0) exit                 ! progress stalls: round-off reached
    end do
    ! the stability and the residual at q: from the arrays when they are q's, from the last
    ! Newton step's eigenvalues (those of H(q) with its vectors: the same to rounding) when
    ! q was kept, else from q's reduction again
    if (eig_q .and. .not. fresh) then          ! q kept: its multipliers again (lam is qt's)
      nfree = nfq
      call dyn_multipliers(m, w, q, w%qz, w%qz, t, lam, stp, lmsg)
    else
      if (.not. fresh) call reduce(q, status)
      if (status /= MBD_OK) return
      if (nfree == 0) then
        stable = 2; resid = zero; return
      end if
      call eigen(.false., status)
      if (status /= MBD_OK) return
      gq = maxval(abs(g(1:nfree))); fq = fscale
    end if
    emax = max(maxval(abs(ev(1:nfree))), tiny(one))
    ! the unbalanced load against the loads, or against the stiffness over the model's size
    ! (loads of round-off size: springs at their natural lengths in an equilibrium)
    resid = gq / max(fq, emax * m%lscale)
    if (.not. (resid <= RESID_FAIL)) then
      status = MBD_NO_CONVERGENCE
      write (msg, '(a,es10.3,a)') 'statics: no equilibrium found near the estimates; the '// &
        'unbalanced load is ', resid, ' times the loads'
      return
    end if
    if (minval(ev(1:nfree)) > 1.0e-9_wp * emax) then
      stable = 1
    else if (minval(ev(1:nfree)) < -1.0e-9_wp * emax) then
      stable = 0
    else
      stable = -1
    end if
  contains
    !> At qa: the null-space basis N (nb), the reduced load g = N^T Q, the least-squares
    !! multipliers lam, the minimum-norm correction dq_n = -J^+ Phi (pn = ||Phi||_inf),
    !! the force scale, V and its rounding error, and the reduced stiffness H (in h).
    subroutine reduce(qa, st)
      real(wp), intent(in) :: qa(:)
      integer, intent(out) :: st
      real(wp) :: wq(1)
      integer :: info, rk, k, lw, i, j, p
      st = MBD_OK
      call dyn_multipliers(m, w, qa, w%qz, w%qz, t, lam, stp, lmsg)  ! also J and Q at qa
      call blocks_jtv(m, w%asm, lam, r)                ! J^T lambda
      fscale = max(maxval(abs(w%force)), maxval(abs(r)), tiny(one))
      pn = zero
      do i = 1, na                                     ! row gathers as loops (no temporary)
        pn = max(pn, abs(w%phi(w%rows(i))))
      end do
      dqn = zero
      rk = 0
      if (band) then
        ! dq_n = -J^+ Phi from the factors dyn_multipliers left: [s I, s J^T; s J, 0]
        if (na > 0) then
          w%rhs(1:n) = zero
          do i = 1, na
            w%rhs(n + i) = -w%s * w%phi(w%rows(i))
          end do
          call dyn_solve(w, w%rhs, st)
          if (st /= MBD_OK) return
          dqn = w%rhs(1:n)
        end if
        v0 = potential(qa)
        vnoise = V_NOISE * (abs(v0) + scale_of_v(qa))
        nfree = n - na
        if (nfree == 0) return
        call dyn_null_basis(m, w, qa, t, nb(:, 1:nfree), st)
        if (st /= MBD_OK) then
          st = MBD_SINGULAR; msg = 'statics: no basis of the free motions (J is singular)'
          return
        end if
        g(1:nfree) = matmul(w%force, nb(:, 1:nfree))   ! N^T Q (= -reduced gradient of V)
        call tangent(qa)
        if (bycols) return
        do p = 1, nnz                                  ! K_sym = (K + K^T) / 2
          if (ktr(p) > p) then
            kv(p) = half * (kv(p) + kv(ktr(p))); kv(ktr(p)) = kv(p)
          end if
        end do
        do j = 1, nfree                                ! K N, column by column
          call kmul(nb(:, j), ct(:, j))
        end do
        h(1:nfree, 1:nfree) = matmul(transpose(nb(:, 1:nfree)), ct(:, 1:nfree))
        return
      end if
      v0 = potential(qa)
      fscale = max(fscale, fmag)           ! loads that balance each other (a contact)
      vnoise = V_NOISE * (abs(v0) + scale_of_v(qa))
      ! SVD of the active rows: J_a = U S V^T; N = the last columns of V
      if (na > 0) then
        do i = 1, na
          ja(i, :) = w%jac(w%rows(i), :)
        end do
        call dgesvd('S', 'A', na, n, ja, size(ja, 1), sv, u, size(u, 1), vt, n, wq, -1, info)
        lw = max(1, int(wq(1)))
        call grow_work(lw, st)
        if (st /= MBD_OK) return
        call dgesvd('S', 'A', na, n, ja, size(ja, 1), sv, u, size(u, 1), vt, n, work, &
                    size(work), info)
        if (info /= 0) then
          st = MBD_LAPACK; write (msg, '(a,i0)') 'statics: the SVD of J failed, info ', info
          return
        end if
        rk = count(sv(1:nu) > RANK_TOL * maxval(sv(1:nu)))
        ! dq_n = -V_r S_r^-1 U_r^T Phi_a
        do k = 1, rk
          c(k) = zero
          do i = 1, na
            c(k) = c(k) - u(i, k) * w%phi(w%rows(i))
          end do
          c(k) = c(k) / sv(k)
        end do
        do k = 1, rk
          dqn = dqn + c(k) * vt(k, :)
        end do
      else
        vt = zero
        do k = 1, n
          vt(k, k) = one
        end do
      end if
      nfree = n - rk
      if (nfree == 0) return
      nb(:, 1:nfree) = transpose(vt(rk + 1:n, :))
      g(1:nfree) = matmul(w%force, nb(:, 1:nfree))     ! N^T Q (= -reduced gradient of V)
      call tangent(qa)
      if (bycols) return
      kt = zero
      do j = 1, n
        do p = w%kptr(j), w%kptr(j + 1) - 1
          kt(w%krow(p), j) = kv(p)
        end do
      end do
      do j = 1, n                                      ! K_sym = (K + K^T) / 2
        do i = 1, j - 1
          kt(i, j) = half * (kt(i, j) + kt(j, i)); kt(j, i) = kt(i, j)
        end do
      end do
      ct(:, 1:nfree) = matmul(kt, nb(:, 1:nfree))      ! K N
      h(1:nfree, 1:nfree) = matmul(transpose(nb(:, 1:nfree)), ct(:, 1:nfree))
    end subroutine reduce

    !> K at qa: exact (the blocks at (qa, t, lam)) or by differences (dyn_tangent) on the
    !! sparse pattern (kv); exact with fewer free motions than the pattern's colour groups,
    !! K N (in ct) and H = (N^T K N + (N^T K N)^T) / 2 by a product per column instead
    !! (bycols).
    subroutine tangent(qa)
      real(wp), intent(in) :: qa(:)
      integer :: i, j
      bycols = .false.
      if (.not. exact) then
        call dyn_tangent(m, w, qa, w%qz, t, lam, kv, cv); return
      end if
      call sens_stiffness_at(m, s, qa, t, lam, w%qz)
      if (w%ncolor < nfree) then
        call sens_tangent_pattern(m, w, s, qa, t, w%qz, kv, c, dqz, r); return
      end if
      bycols = .true.
      do j = 1, nfree
        call sens_stiffness_mul(m, s, qa, t, w%qz, nb(:, j), ct(:, j), c)
      end do
      h(1:nfree, 1:nfree) = matmul(transpose(nb(:, 1:nfree)), ct(:, 1:nfree))
      do j = 1, nfree
        do i = 1, j - 1
          h(i, j) = half * (h(i, j) + h(j, i)); h(j, i) = h(i, j)
        end do
      end do
    end subroutine tangent

    !> y = K x on the sparse pattern (band path; kv holds K_sym).
    subroutine kmul(x, y)
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: y(:)
      call dyn_pattern_mul(w, kv, x, y)
    end subroutine kmul

    !> ktr(p): the entry (c, i) of the pattern entry p = (i, c) (the pattern is symmetric).
    subroutine transpose_map()
      integer :: j, p, i, pp
      do j = 1, n
        do p = w%kptr(j), w%kptr(j + 1) - 1
          i = w%krow(p)
          ktr(p) = p
          do pp = w%kptr(i), w%kptr(i + 1) - 1
            if (w%krow(pp) == j) then
              ktr(p) = pp; exit
            end if
          end do
        end do
      end do
    end subroutine transpose_map

    !> y = N dz (the first nfree columns of nb).
    subroutine null_mul(x, y)
      real(wp), intent(in) :: x(:)       !! (>= nfree) reduced step
      real(wp), intent(out) :: y(:)      !! (n) the step in q
      integer :: k
      y = zero
      do k = 1, nfree
        y = y + x(k) * nb(:, k)
      end do
    end subroutine null_mul

    !> work has at least lw entries (MBD_NO_MEMORY when it cannot grow).
    subroutine grow_work(lw, st)
      integer, intent(in) :: lw
      integer, intent(out) :: st
      call mem_grow(work, lw, 'the LAPACK workspace of the statics', HINT, st, msg)
    end subroutine grow_work

    !> dz from H dz = g - N^T K dq_n, saddle-free: |eigenvalues| bounded below (a flat
    !! direction gets a gradient step of about the model's length scale).
    !! H is overwritten by its eigenvectors (reduce computes it again).
    subroutine newton_step(st)
      integer, intent(out) :: st      !! MBD_OK or MBD_NO_MEMORY
      integer :: k
      if (bycols) then                                   ! N^T K_sym dq_n
        call sens_stiffness_mul(m, s, q, t, w%qz, dqn, qt, c)
        r(1:nfree) = half * (matmul(qt, nb(:, 1:nfree)) + matmul(dqn, ct(:, 1:nfree)))
      else
        if (band) then
          call kmul(dqn, qt)                             ! K dq_n
        else
          qt = matmul(dqn, kt)                           ! (K dq_n)^T, K symmetric
        end if
        r(1:nfree) = matmul(qt, nb(:, 1:nfree))
      end if
      r(1:nfree) = g(1:nfree) - r(1:nfree)
      call eigen(.true., st)
      if (st /= MBD_OK) return
      emax = max(1.0e-8_wp * maxval(abs(ev(1:nfree))), norm2(g(1:nfree)) / m%lscale, &
                 tiny(one))
      dz(1:nfree) = matmul(transpose(h(1:nfree, 1:nfree)), r(1:nfree))
      do k = 1, nfree
        r(k) = dz(k) / max(abs(ev(k)), emax)
      end do
      dz(1:nfree) = matmul(h(1:nfree, 1:nfree), r(1:nfree))
    end subroutine newton_step

    !> Residual of the equilibrium equations, relative to the force and length scales.
    real(wp) function merit(ga, pa)
      real(wp), intent(in) :: ga, pa
      merit = ga / fscale + pa / m%lscale
    end function merit

    !> V at qa: gravity, springs and the loads frozen at t (fills w%force at qa).
    real(wp) function potential(qa)
      real(wp), intent(in) :: qa(:)
      real(wp) :: v, vl
      call gen_forces(m, qa, w%qz, t, w%force, v, vl, fmag=fmag)
      potential = v + vl
    end function potential

    !> Size of the gravity terms of V, whose sum may cancel: sum m |g . r|.
    real(wp) function scale_of_v(qa)
      real(wp), intent(in) :: qa(:)
      integer :: k
      scale_of_v = zero
      do k = 1, m%nb
        scale_of_v = scale_of_v + &
          m%mdiag(3 * k - 2) * abs(dot_product(m%grav, qa(3 * k - 2:3 * k - 1)))
      end do
    end function scale_of_v

    !> Eigenvalues of H (h(1:nfree, 1:nfree)) in ev(1:nfree), and when vectors, the
    !! eigenvectors in h. st: MBD_OK or MBD_NO_MEMORY (the workspace); a dsyev that does not
    !! converge leaves what it has (the step or stability test uses it as it is).
    subroutine eigen(vectors, st)
      logical, intent(in) :: vectors
      integer, intent(out) :: st
      real(wp) :: wq(1)
      integer :: info
      character(len=1) :: job
      job = merge('V', 'N', vectors)
      call dsyev(job, 'U', nfree, h, size(h, 1), ev, wq, -1, info)
      call grow_work(max(1, int(wq(1))), st)
      if (st /= MBD_OK) return
      call dsyev(job, 'U', nfree, h, size(h, 1), ev, work, size(work), info)
    end subroutine eigen
  end subroutine statics_solve

end module mbd_statics
