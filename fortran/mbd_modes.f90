!> mbd_modes: small vibrations about an equilibrium (drivers held at t), linearized.
!!
!! Near an equilibrium q* with multipliers lambda* (statics), a motion q = q* + N z (N a basis
!! of the null space of the active rows of J, J N = 0) obeys to first order (Geradin and
!! Cardona ch. 11; Haug ch. 6, the null-space form of the linearized equations of motion)
!!   M_r z'' + C_r z' + K_r z = 0,   M_r = N^T M N,  C_r = N^T C N,  K_r = N^T K N,
!! K = d(J^T lambda - Q)/dq (the constraints' curvature weighted by lambda*, and the loads'
!! stiffness) and C = -dQ/dq_dot: exact, from the design sensitivities' second derivatives
!! (sens_stiffness_mul, sens_damping_mul, as the frequency response takes them) when the caller
!! gives their blocks (a model without contacts or joint friction); else from dyn_tangent
!! (central differences on the sparse pattern, step FD_STEP: contacts and friction, whose
!! exact derivatives are not written). N^T (J^T lambda - Q) = 0 at q*, so the change of N
!! does not enter.
!! Undamped modes: K_s v = omega^2 M_r v, K_s = (K_r + K_r^T) / 2 (dsygvd; v^T M_r v = 1), the
!! shapes phi = N v (phi^T M phi = 1). Damped: the eigenvalues s of the first-order form
!!   [0, I; -M_r^-1 K_r, -M_r^-1 C_r]  (dgeev),  s = -zeta omega +- i omega sqrt(1 - zeta^2),
!! sorted by |s|, then by the imaginary part, largest first; without damping (C_r = 0) and
!! with a symmetric K_r they are s = +-sqrt(-omega^2), taken from the undamped modes.
!! Damped (complex) shapes, when asked for: psi = N u, u the position half of the first-order
!! form's right eigenvector [u; s u] (dgeev; without damping u = v), each scaled so that its
!! largest entry is 1 (unit_largest, in model units): the other entries' moduli and phases
!! are relative to it (a phase of 180 degrees: opposite, 90: a quarter period behind).
!! Memory: N, K N, C N, M N (nq x nfree) and five nfree x nfree arrays plus the
!! 2 nfree x 2 nfree first-order matrix, checked and allocated once per call (MBD_NO_MEMORY
!! when they cannot be had).
module mbd_modes
  use mbd_kinds, only: wp, zero, one, half
  use mbd_status, only: MBD_OK, MBD_SINGULAR, MBD_NO_CONVERGENCE, MBD_LAPACK, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail, mem_grow
  use mbd_model, only: model_t
  use mbd_lapack, only: dsygvd, dgeev, dgetrs, dgemm
  use mbd_dynamics, only: dyn_work_t, dyn_tangent, dyn_null_basis, dyn_pattern_mul
  use mbd_frf, only: massless, mass_lu
  use mbd_sensitivity, only: sens_t
  use mbd_sens_dynamics, only: sens_stiffness_mul, sens_damping_mul, sens_tangent_pattern
  implicit none
  private
  public :: modes_solve, unit_largest

  !> |omega^2| at most this fraction of the largest: a motion without stiffness (kind 0)
  real(wp), parameter :: RIGID_FRACTION = 1.0e-9_wp
  !> K's and C's central differences: the step eps**(1/3) that balances truncation and
  !! rounding (K to about 1e-11 relative on the closed-form tests, against 5e-10 at 1e-7)
  real(wp), parameter :: FD_STEP = 6.0e-6_wp
  !> |K_r - K_s| at most this fraction of |K_r|: symmetric (the differences' noise is 1e-11;
  !! exact K: round-off)
  real(wp), parameter :: SYM_TOL = 1.0e-8_wp
  character(len=*), parameter :: HINT = 'the modes use dense matrices of the number of free ' &
    // 'motions: ask for fewer modes or use a model with fewer free motions'

contains

  !> The lowest kmax undamped modes and 2 kmax damped eigenvalues at the equilibrium q.
  !! nfree: the number of free motions (n - the active rows); the outputs past
  !! min(kmax, nfree) (2 min(kmax, nfree) for the damped) are zero. kinds: 1 a vibration
  !! (omega^2 > 0), 0 a motion without stiffness (|omega^2| <= RIGID_FRACTION times the
  !! largest), -1 unstable (omega^2 < 0).
  subroutine modes_solve(m, w, q, t, lam, kmax, nfree, omega2, kinds, sre, sim, shapes, &
                         status, msg, zre, zim, s)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! work arrays (dyn_init done)
    real(wp), intent(in) :: q(:)                !! equilibrium (core units)
    real(wp), intent(in) :: t                   !! time (drivers and loads held here)
    real(wp), intent(in) :: lam(:)              !! its multipliers (neq)
    integer, intent(in) :: kmax                 !! modes wanted (the lowest)
    integer, intent(out) :: nfree               !! free motions
    real(wp), intent(out) :: omega2(:)          !! (kmax) undamped omega^2, ascending
    integer, intent(out) :: kinds(:)            !! (kmax) 1 vibration, 0 rigid, -1 unstable
    real(wp), intent(out) :: sre(:), sim(:)     !! (2 kmax) damped eigenvalues s
    real(wp), intent(out) :: shapes(:, :)       !! (nq, kmax) phi = N v (core units)
    integer, intent(out) :: status  !! MBD_OK, MBD_SINGULAR, MBD_NO_CONVERGENCE, ...
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    !> (nq, 2 kmax) the damped shapes psi of the sorted eigenvalues, real and imaginary parts
    !! (core units, not yet scaled: unit_largest does that in model units)
    real(wp), intent(out), optional :: zre(:, :), zim(:, :)
    !> the design sensitivities' blocks at the rest state (q, t, lam) (sens_at_rest done, no
    !! contacts or friction): K and C exact; absent, by central differences
    type(sens_t), intent(in), optional :: s
    ! N, K N, C N, M N; M_r, K_r, C_r, K_s (then the eigenvectors v); the first-order matrix,
    ! its eigenvalues, the undamped ones, dgeev's unused eigenvectors, LAPACK's workspace, and
    ! K and C on the sparse pattern
    real(wp), allocatable :: nb(:, :), kn(:, :), cn(:, :), mn(:, :), mr(:, :), kr(:, :), &
                             cr(:, :), ks(:, :), a(:, :), wr(:), wi(:), ev(:), vl(:, :), &
                             vr(:, :), work(:), kv(:), cv(:), zv(:), xv(:), yv(:), wv(:)
    integer, allocatable :: ipiv(:), order(:), iwork(:)
    integer :: iwq(1)
    real(wp) :: bytes, wq(1)
    integer :: n, f, nnz, ist, info, j, k, nk
    logical :: plain, damped, cshapes, bypattern
    character(len=MSG_LEN) :: what
    status = MBD_OK; msg = ''
    omega2 = zero; sre = zero; sim = zero; shapes = zero; kinds = 0
    cshapes = present(zre) .and. present(zim)
    if (cshapes) then
      zre = zero; zim = zero
    end if
    n = m%nq
    nfree = n - w%na
    f = nfree
    if (f <= 0 .or. kmax <= 0) return
    nk = min(kmax, f)
    nnz = w%kptr(n + 1) - 1
    bytes = REAL_BYTES * (4 * real(n, wp) * f + 5 * real(f, wp)**2 + 4 * real(2 * f, wp)**2 &
                          + 2 * real(nnz, wp) + 8 * real(f, wp) + 4 * real(n, wp))
    if (cshapes) bytes = bytes + REAL_BYTES * real(2 * f, wp)**2     ! dgeev's eigenvectors
    write (what, '(a,i0,a)') 'the modes'' work arrays (', f, ' free motions)'
    call mem_check(bytes, trim(what), HINT, status, msg)
    if (status /= MBD_OK) return
    allocate (nb(n, f), kn(n, f), cn(n, f), mn(n, f), mr(f, f), kr(f, f), cr(f, f), ks(f, f), &
              a(2 * f, 2 * f), wr(2 * f), wi(2 * f), ev(f), vl(1, 1), &
              vr(merge(2 * f, 1, cshapes), merge(2 * f, 1, cshapes)), kv(nnz), &
              cv(nnz), ipiv(f), order(2 * f), work(1), zv(n), xv(n), yv(n), wv(n), stat=ist)
    if (ist /= 0) then
      call mem_fail(bytes, trim(what), HINT, status, msg); return
    end if
    call dyn_null_basis(m, w, q, t, nb, status)
    if (status /= MBD_OK) then
      status = MBD_SINGULAR; msg = 'modes: no basis of the free motions (J is singular)'
      return
    end if
    bypattern = .true.
    if (present(s)) then                          ! K N = K_lambda N - Q_q N, C N = -Q_q_dot N
      zv = zero
      bypattern = w%ncolor < f                    ! (exact K and C on the pattern: fewer
      if (bypattern) then                         ! products, one per colour group)
        call sens_tangent_pattern(m, w, s, q, t, zv, kv, xv, yv, wv, cv)
        damped = maxval(abs(cv)) > zero
      else
        do j = 1, f
          call sens_stiffness_mul(m, s, q, t, zv, nb(:, j), kn(:, j), xv)
          call sens_damping_mul(m, s, q, t, zv, nb(:, j), cn(:, j))
        end do
        damped = maxval(abs(cn)) > zero
      end if
    else
      call dyn_tangent(m, w, q, w%qz, t, lam, kv, cv, step=FD_STEP)
      damped = maxval(abs(cv)) > zero
    end if
    do j = 1, f                                   ! K N, C N and M N, column by column
      if (bypattern) then
        call dyn_pattern_mul(w, kv, nb(:, j), kn(:, j))
        if (damped) call dyn_pattern_mul(w, cv, nb(:, j), cn(:, j))
      end if
      do k = 1, n
        mn(k, j) = m%mdiag(k) * nb(k, j)
      end do
    end do
    call dgemm('T', 'N', f, f, n, one, nb, n, kn, n, zero, kr, f)   ! K_r = N^T K N (BLAS)
    cr = zero
    if (damped) call dgemm('T', 'N', f, f, n, one, nb, n, cn, n, zero, cr, f)   ! C_r = N^T C N
    call dgemm('T', 'N', f, f, n, one, nb, n, mn, n, zero, mr, f)   ! M_r = N^T M N
    ! undamped: K_s v = omega^2 M_r v
    ks = half * (kr + transpose(kr))
    ! no damping and a symmetric K_r (a conservative equilibrium, to the differences' noise):
    ! the first-order form's eigenvalues are +-i omega, no dgeev needed
    plain = .not. damped .and. &
            maxval(abs(kr - ks)) <= SYM_TOL * max(maxval(abs(kr)), tiny(one))
    a(1:f, 1:f) = mr
    call dsygvd(1, 'V', 'U', f, ks, f, a, 2 * f, ev, wq, -1, iwq, -1, info)
    call grow(max(1, int(wq(1))), status)
    if (status /= MBD_OK) return
    allocate (iwork(max(1, iwq(1))), stat=ist)
    if (ist /= 0) then
      call mem_fail(bytes, trim(what), HINT, status, msg); return
    end if
    call dsygvd(1, 'V', 'U', f, ks, f, a, 2 * f, ev, work, size(work), iwork, size(iwork), info)
    if (info == 0) then                           ! (a holds M_r's Cholesky factor U)
      if (massless([(a(j, j)**2, j = 1, f)], maxval([(mr(j, j), j = 1, f)]))) info = f + 1
    end if
    if (info > f) then
      status = MBD_SINGULAR
      msg = 'modes: a free motion carries no mass (M_r is not positive definite): give ' // &
            'every moving body a mass and an inertia'
      return
    else if (info > 0) then
      status = MBD_NO_CONVERGENCE
      write (msg, '(a,i0,a)') 'modes: the undamped eigenvalues did not converge (dsygvd info ', &
        info, ')'
      return
    else if (info /= 0) then
      status = MBD_LAPACK; write (msg, '(a,i0)') 'modes: dsygvd failed, info ', info; return
    end if
    omega2(1:nk) = ev(1:nk)
    do k = 1, nk
      if (abs(ev(k)) <= RIGID_FRACTION * maxval(abs(ev(1:f)))) then
        kinds(k) = 0
      else
        kinds(k) = merge(1, -1, ev(k) > zero)
      end if
    end do
    call dgemm('N', 'N', n, nk, f, one, nb, n, ks, f, zero, shapes, size(shapes, 1))   ! phi = N v
    do k = 1, nk                                  ! sign: the largest entry positive
      j = maxloc(abs(shapes(:, k)), 1)
      if (shapes(j, k) < zero) shapes(:, k) = -shapes(:, k)
    end do
    if (plain) then
      do k = 1, f                                 ! s = +-sqrt(-omega^2)
        if (ev(k) >= zero) then
          wr(2 * k - 1:2 * k) = zero; wi(2 * k - 1:2 * k) = [sqrt(ev(k)), -sqrt(ev(k))]
        else
          wr(2 * k - 1:2 * k) = [sqrt(-ev(k)), -sqrt(-ev(k))]; wi(2 * k - 1:2 * k) = zero
        end if
      end do
    else
      call damped_eigenvalues(status)
      if (status /= MBD_OK) return
    end if
    call sort_eigen(wr, wi, order)
    do k = 1, 2 * nk
      sre(k) = wr(order(k)); sim(k) = wi(order(k))
    end do
    if (cshapes) then
      do k = 1, 2 * nk
        call damped_shape(order(k), zre(:, k), zim(:, k))
      end do
    end if
  contains
    !> psi = N u of eigenvalue j (before sorting): u = v_k of the undamped mode k = (j + 1)/2
    !! without damping; else dgeev's column j (a real s), or columns j, j + 1 as u_re, u_im
    !! (s with Im s > 0, the first of its pair) or j - 1, j conjugated (the second).
    subroutine damped_shape(j, pre, pim)
      integer, intent(in) :: j
      real(wp), intent(out) :: pre(:), pim(:)
      if (plain) then
        pre = matmul(nb, ks(:, (j + 1) / 2)); pim = zero
      else if (abs(wi(j)) <= zero) then                ! (a real s)
        pre = matmul(nb, vr(1:f, j)); pim = zero
      else if (wi(j) > zero) then
        pre = matmul(nb, vr(1:f, j)); pim = matmul(nb, vr(1:f, j + 1))
      else
        pre = matmul(nb, vr(1:f, j - 1)); pim = -matmul(nb, vr(1:f, j))
      end if
    end subroutine damped_shape


    !> wr, wi: the eigenvalues of [0, I; -M_r^-1 K_r, -M_r^-1 C_r] (dgeev), and vr its right
    !! eigenvectors for the damped shapes.
    subroutine damped_eigenvalues(st)
      integer, intent(out) :: st
      character :: jobvr
      st = MBD_OK
      jobvr = merge('V', 'N', cshapes)
      call mass_lu(f, mr, f, ipiv, info)
      if (info /= 0) then
        st = MBD_SINGULAR; msg = 'modes: M_r is singular (a free motion carries no mass)'
        return
      end if
      call dgetrs('N', f, f, mr, f, ipiv, kr, f, info)
      call dgetrs('N', f, f, mr, f, ipiv, cr, f, info)
      a = zero
      do j = 1, f
        a(j, f + j) = one
      end do
      a(f + 1:2 * f, 1:f) = -kr
      a(f + 1:2 * f, f + 1:2 * f) = -cr
      call dgeev('N', jobvr, 2 * f, a, 2 * f, wr, wi, vl, 1, vr, size(vr, 1), wq, -1, info)
      call grow(max(1, int(wq(1))), st)
      if (st /= MBD_OK) return
      call dgeev('N', jobvr, 2 * f, a, 2 * f, wr, wi, vl, 1, vr, size(vr, 1), work, &
                 size(work), info)
      if (info /= 0) then
        st = merge(MBD_NO_CONVERGENCE, MBD_LAPACK, info > 0)
        write (msg, '(a,i0,a)') 'modes: the damped eigenvalues did not converge (dgeev info ', &
          info, ')'
      end if
    end subroutine damped_eigenvalues

    !> work has at least lw entries (MBD_NO_MEMORY when it cannot grow).
    subroutine grow(lw, st)
      integer, intent(in) :: lw
      integer, intent(out) :: st
      call mem_grow(work, lw, 'the LAPACK workspace of the modes', HINT, st, msg)
    end subroutine grow
  end subroutine modes_solve

  !> Each column (re, im) of a complex shape divided by its largest entry (the first of
  !! largest modulus), which becomes 1 + 0i; a zero column stays zero.
  pure subroutine unit_largest(re, im)
    real(wp), intent(inout) :: re(:, :), im(:, :)
    real(wp) :: a, b, d, r
    integer :: k, i, j
    do k = 1, size(re, 2)
      i = 1
      do j = 2, size(re, 1)
        if (hypot(re(j, k), im(j, k)) > hypot(re(i, k), im(i, k))) i = j
      end do
      a = re(i, k); b = im(i, k)
      d = a * a + b * b
      if (d <= zero) cycle
      do j = 1, size(re, 1)                     ! (x + iy) / (a + ib) = (x + iy)(a - ib) / d
        r = (re(j, k) * a + im(j, k) * b) / d + zero       ! (+ zero: no -0.0)
        im(j, k) = (im(j, k) * a - re(j, k) * b) / d + zero
        re(j, k) = r
      end do
      re(i, k) = one; im(i, k) = zero
    end do
  end subroutine unit_largest

  !> order: the eigenvalues (re, im) by |s| ascending, then by im descending (insertion sort;
  !! 2 nfree entries).
  pure subroutine sort_eigen(re, im, order)
    real(wp), intent(in) :: re(:), im(:)
    integer, intent(out) :: order(:)
    integer :: i, j, k
    do i = 1, size(order)
      order(i) = i
    end do
    do i = 2, size(order)
      k = order(i)
      j = i - 1
      do while (j >= 1)
        if (.not. before(k, order(j))) exit
        order(j + 1) = order(j)
        j = j - 1
      end do
      order(j + 1) = k
    end do
  contains
    pure logical function before(a, b)
      integer, intent(in) :: a, b
      real(wp) :: ma, mb
      ma = hypot(re(a), im(a)); mb = hypot(re(b), im(b))
      if (abs(ma - mb) > 1.0e-12_wp * max(ma, mb)) then
        before = ma < mb
      else
        before = im(a) > im(b)
      end if
    end function before
  end subroutine sort_eigen

end module mbd_modes
