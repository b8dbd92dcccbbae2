!> mbd_frf: the frequency response of the linearized motion about an equilibrium to a design
!! parameter varied harmonically, p = p0 + Re(P e^(i Omega t)) (a shaker's force amplitude, a
!! spring's free length as a displacement input, gravity as a base acceleration, a pivot's
!! place as a base motion).
!!
!! About the equilibrium q*, lambda* (drivers held at t) the motion obeys to first order
!! (Geradin and Cardona ch. 11; the statics sensitivities' linearization, mbd_sens_dynamics)
!!   M dq'' + C dq' + K dq + J_a^T dlambda = (r + i Omega Q_p_dot) P e^(i Omega t),
!!   J_a dq = -Phi_p,a P e^(i Omega t)
!! with r = Q_p - J_p^T lambda*, K = K_lambda - Q_q and C = -Q_q_dot, all exact
!! (mbd_sensitivity); Q_p_dot the forces' change per unit rate of p (a damper whose point
!! moves: a road under a damped tyre; sens_force_rate), carried below with C s_n (cs). The steady response dq = H(Omega) P e^(i Omega t) is H = s_n + N z:
!! J_a s_n = -Phi_p,a (the minimum-norm solution), N a basis of J_a's null space, and
!!   (K_r - Omega^2 M_r + i Omega C_r) z = N^T (r - (K - Omega^2 M + i Omega C) s_n),
!! K_r = N^T K N, M_r = N^T M N, C_r = N^T C N; Omega = 0 gives the statics sensitivity dq*/dp.
!! Each frequency solves the real form [A, -B; B, A] [z_re; z_im] = [b_re; b_im],
!! A = K_r - Omega^2 M_r, B = Omega C_r (one dgetrf for every parameter). With many free
!! motions and frequencies (Laub 1981) the first-order form x' = F x + [0; M_r^-1 g],
!! F = [0, I; -M_r^-1 K_r, -M_r^-1 C_r], is reduced once to Hessenberg form F = Q T Q^T
!! (dgehrd, dorghr); each frequency then solves (i Omega I - T) y = Q^T [0; M_r^-1 g] in
!! O(nfree^2) (a Hessenberg LU, pivoting between neighbouring rows) and z = [I 0] Q y, with
!! g = g0 + Omega^2 g2 + i Omega g1 from the parameters' fixed parts; then one step of
!! iterative refinement on the second-order system: rho = g - (K_r - Omega^2 M_r +
!! i Omega C_r) z, solved the same way (the LU kept) and added to z. (The first-order form is
!! worse conditioned than the second-order one: without the step a lightly damped chain of
!! 40 blocks was good to 1.4e-11 where the dense path and numpy give 1e-13.) The multipliers'
!! response, when asked for: J_a^T dlambda = r - (K - Omega^2 M + i Omega C) H, real and
!! imaginary parts by the least squares of the projection's factors (as the statics
!! sensitivities; K H from K s_n + (K N) z).
!! Memory: N, K N, C N, M N (nq x nfree), four nq x np arrays, three nfree x nfree and one
!! 2 nfree x 2 nfree matrix, checked and allocated once per call (MBD_NO_MEMORY otherwise).
module mbd_frf
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_SINGULAR, MBD_LAPACK, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail
  use mbd_model, only: model_t
  use mbd_lapack, only: dgemm, dgetrf, dgetrs, dgehrd, dorghr
  use mbd_sensitivity, only: sens_t
  use mbd_sens_dynamics, only: statics_load, sens_stiffness_mul, sens_damping_mul, sens_at_rest, &
                               proj_particular, proj_multipliers, sens_tangent_pattern
  use mbd_sensitivity, only: sens_force_rate
  use mbd_dynamics, only: dyn_work_t, dyn_null_basis, dyn_factor_projection, dyn_pattern_mul
  implicit none
  private
  public :: frf_solve, linear_parts, massless, mass_lu

  character(len=*), parameter :: HINT = 'the frequency response uses dense matrices of the ' &
    // 'number of free motions: use a model with fewer free motions'
  !> the Hessenberg form from this many free motions and frequencies on (below, a dense LU
  !! per frequency costs less than the reduction)
  integer, parameter :: HESS_MIN_FREE = 16, HESS_MIN_FREQ = 8
  !> a pivot of M_r's factors at most this fraction of its largest diagonal entry: a free
  !! motion without mass (massless)
  real(wp), parameter :: MASS_TOL = 1.0e-12_wp
  character(len=*), parameter :: SINGULAR_MSG = 'frequency response: K_r - Omega^2 M_r + ' // &
    'i Omega C_r is singular (an undamped natural frequency, or 0 Hz with a motion without ' // &
    'stiffness)'

contains

  !> H(Omega) of every parameter of s at each frequency omega (rad/s): hre + i him
  !! (nq, np, nomega), core units. MBD_SINGULAR when K_r - Omega^2 M_r + i Omega C_r is
  !! singular (an undamped natural frequency, or 0 with a motion without stiffness); ibad
  !! is then that frequency's index.
  subroutine frf_solve(m, w, s, q, t, lam, omega, hre, him, ibad, status, msg, lre, lim)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! work arrays (dyn_init done)
    type(sens_t), intent(inout) :: s            !! the parameters (sens_setup done)
    real(wp), intent(in) :: q(:), t             !! equilibrium (core units), time
    real(wp), intent(in) :: lam(:)              !! its multipliers (neq)
    real(wp), intent(in) :: omega(:)            !! angular frequencies (rad/s)
    real(wp), intent(out), contiguous :: hre(:, :, :), him(:, :, :)  !! (nq, np, nomega)
    integer, intent(out) :: ibad                !! the singular frequency (0: none)
    integer, intent(out) :: status              !! MBD_OK, MBD_SINGULAR, MBD_NO_MEMORY, ...
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    !> (neq, np, nomega) the multipliers' response dlambda (core units; redundant rows 0)
    real(wp), intent(out), optional :: lre(:, :, :), lim(:, :, :)
    ! N, K N, C N, M N; s_n, K s_n, C s_n, M s_n and r per parameter; K_r, C_r, M_r, the real
    ! form of the reduced matrix, its right-hand sides; work vectors
    real(wp), allocatable :: nb(:, :), kn(:, :), cn(:, :), mn(:, :), sn(:, :), ks(:, :), &
                             cs(:, :), ms(:, :), rr(:, :), kr(:, :), cr(:, :), mr(:, :), &
                             a(:, :), b(:, :), y(:)
    ! the Hessenberg path: Q, T, the right-hand sides' parts Q^T [0; M_r^-1 g_k], work
    ! and for the refinement g0, g1, g2, the residual's parts, the LU's multipliers and swaps
    real(wp), allocatable :: qh(:, :), th(:, :), c0(:, :), c1(:, :), c2(:, :), work(:), &
                             g0(:, :), g1(:, :), g2(:, :), rre(:, :), rim(:, :), &
                             qlt(:, :), yre(:, :), yim(:, :)
    complex(wp), allocatable :: tc(:, :), yc(:, :), lm(:)
    ! the multipliers' response by parts (pre): P x, the least squares J_a^T mu = x, of K N,
    ! M N, C N (neq, f) and of r - K s_n, M s_n, C s_n (neq, np); a frequency's (neq, np)
    real(wp), allocatable :: pk(:, :), pm(:, :), pc(:, :), p0(:, :), p2(:, :), p1(:, :), &
                             lw(:, :)
    logical, allocatable :: sw(:)
    integer, allocatable :: ipiv(:)
    real(wp) :: bytes, om, toff
    integer :: n, f, np, na, i, j, k, ist, info
    logical :: hess, pre
    character(len=MSG_LEN) :: what
    status = MBD_OK; msg = ''; ibad = 0
    hre = zero; him = zero
    if (present(lre)) lre = zero
    if (present(lim)) lim = zero
    n = m%nq; na = w%na; f = n - na; np = s%np
    if (np == 0 .or. size(omega) == 0) return
    bytes = REAL_BYTES * (4 * real(n, wp) * max(f, 1) + 5 * real(n, wp) * np &
                          + 7 * real(max(f, 1), wp)**2 + 2 * real(max(f, 1), wp) * np + 3 * n)
    hess = f >= HESS_MIN_FREE .and. size(omega) >= HESS_MIN_FREQ
    if (hess) bytes = bytes + REAL_BYTES * (18 * real(f, wp)**2 + 15 * real(f, wp) * np &
                                            + 72 * real(f, wp))
    write (what, '(a,i0,a)') 'the frequency response''s work arrays (', f, ' free motions)'
    call mem_check(bytes, trim(what), HINT, status, msg)
    if (status /= MBD_OK) return
    allocate (a(2 * f, 2 * f), b(2 * f, np), y(n), ipiv(2 * f), stat=ist)
    if (ist /= 0) then
      call mem_fail(bytes, trim(what), HINT, status, msg); return
    end if
    call linear_parts(m, w, s, q, t, lam, nb, kn, cn, mn, kr, cr, mr, sn, ks, cs, ms, rr, &
                      status, msg)
    if (status /= MBD_OK) then
      msg = 'frequency response: ' // msg(1:MSG_LEN - len('frequency response: ')); return
    end if
    if (hess) call hess_setup(hess, status)       ! (hess false: M_r singular, the dense LU)
    if (status /= MBD_OK) return
    ! the multipliers' response is linear in the parts P(K N), ... : solved once when that
    ! costs fewer solves than two per input and frequency (many frequencies, few free motions)
    pre = present(lre) .and. present(lim) .and. 2 * size(omega) * np > 3 * (f + np)
    if (pre) call parts_setup(pre, status)
    if (status /= MBD_OK) then
      msg = 'frequency response: the multipliers'' least squares failed'; return
    end if
    do j = 1, size(omega)
      om = omega(j)
      do k = 1, np
        hre(:, k, j) = sn(:, k)
      end do
      if (hess) then
        call hess_solve(om, info)
        if (info /= 0) then
          ibad = j; status = MBD_SINGULAR; msg = SINGULAR_MSG; return
        end if
        call response(j)
      else if (f > 0) then                        ! (every motion driven: dq = s_n)
        a(1:f, 1:f) = kr - om**2 * mr; a(f + 1:, f + 1:) = a(1:f, 1:f)
        a(f + 1:, 1:f) = om * cr; a(1:f, f + 1:) = -om * cr
        ! b = N^T (r - (K - Omega^2 M) s_n) - i Omega N^T C s_n
        call dgemm('T', 'N', f, np, n, one, nb, n, rr - ks + om**2 * ms, n, zero, b, 2 * f)
        call dgemm('T', 'N', f, np, n, -om, nb, n, cs, n, zero, b(f + 1, 1), 2 * f)
        call dgetrf(2 * f, 2 * f, a, 2 * f, ipiv, info)
        if (info > 0) then
          ibad = j; status = MBD_SINGULAR; msg = SINGULAR_MSG; return
        else if (info /= 0) then
          status = MBD_LAPACK; write (msg, '(a,i0)') 'frequency response: dgetrf info ', info
          return
        end if
        call dgetrs('N', 2 * f, np, a, 2 * f, ipiv, b, 2 * f, info)
        call response(j)
      end if
      if (pre) then
        call multipliers_by_parts(j, om)
      else if (present(lre) .and. present(lim)) then
        call multipliers(j, om, status)
        if (status /= MBD_OK) then
          msg = 'frequency response: the multipliers'' least squares failed'; return
        end if
      end if
    end do
  contains
    !> H at frequency j: hre = s_n + N Re z (hre holds s_n), him = N Im z (z in b).
    subroutine response(j)
      integer, intent(in) :: j
      call dgemm('N', 'N', n, np, f, one, nb, n, b, 2 * f, one, hre(:, :, j), n)
      call dgemm('N', 'N', n, np, f, one, nb, n, b(f + 1, 1), 2 * f, zero, him(:, :, j), n)
    end subroutine response

    !> The Hessenberg path's setup: F = [0, I; -M_r^-1 K_r, -M_r^-1 C_r] = Q T Q^T and
    !! c_k = Q^T [0; M_r^-1 g_k] for g0 = N^T (r - K s_n), g1 = -N^T C s_n, g2 = N^T M s_n.
    !! use false (and MBD_OK) when M_r is singular: the dense path is taken instead.
    subroutine hess_setup(use, st)
      logical, intent(out) :: use
      integer, intent(out) :: st
      integer :: lw, f2
      real(wp) :: wq(1)
      real(wp), allocatable :: tau(:)
      st = MBD_OK; use = .false.; f2 = 2 * f
      allocate (qh(f2, f2), th(f2, f2), c0(f2, np), c1(f2, np), c2(f2, np), tc(f2, f2), &
                yc(f2, np), tau(f2), g0(f, np), g1(f, np), g2(f, np), rre(f, np), &
                rim(f, np), lm(f2), sw(f2), qlt(f2, f), yre(f2, np), yim(f2, np), stat=ist)
      if (ist /= 0) then
        call mem_fail(bytes, trim(what), HINT, st, msg); return
      end if
      a(1:f, 1:f) = mr                            ! M_r's LU in a's corner
      call mass_lu(f, a, f2, ipiv, info)
      if (info /= 0) return
      th = zero
      do i = 1, f
        th(i, f + i) = one
      end do
      th(f + 1:, 1:f) = kr; th(f + 1:, f + 1:) = cr
      call dgemm('T', 'N', f, np, n, one, nb, n, rr - ks, n, zero, c0, f2)   ! N^T (r - K s_n)
      call dgemm('T', 'N', f, np, n, -one, nb, n, cs, n, zero, c1, f2)     ! -N^T C s_n
      call dgemm('T', 'N', f, np, n, one, nb, n, ms, n, zero, c2, f2)      ! N^T M s_n
      g0 = c0(1:f, :); g1 = c1(1:f, :); g2 = c2(1:f, :)   ! (M_r's LU stays in a's corner)
      call dgetrs('N', f, f, a, f2, ipiv, th(f + 1:, 1:f), f, info)
      call dgetrs('N', f, f, a, f2, ipiv, th(f + 1:, f + 1:), f, info)
      call dgetrs('N', f, np, a, f2, ipiv, c0, f2, info)
      call dgetrs('N', f, np, a, f2, ipiv, c1, f2, info)
      call dgetrs('N', f, np, a, f2, ipiv, c2, f2, info)
      th(f + 1:, :) = -th(f + 1:, :)
      call dgehrd(f2, 1, f2, th, f2, tau, wq, -1, info)
      lw = max(1, int(wq(1)))
      call dorghr(f2, 1, f2, th, f2, tau, wq, -1, info)
      lw = max(lw, int(wq(1)))
      allocate (work(lw), stat=ist)
      if (ist /= 0) then
        call mem_fail(bytes, trim(what), HINT, st, msg); return
      end if
      call dgehrd(f2, 1, f2, th, f2, tau, work, lw, info)
      qh = th
      call dorghr(f2, 1, f2, qh, f2, tau, work, lw, info)
      if (info /= 0) then
        st = MBD_LAPACK; write (msg, '(a,i0)') 'frequency response: dorghr info ', info
        return
      end if
      do i = 1, f2                                ! T: zero below the first subdiagonal
        th(i + 2:, i) = zero
      end do
      toff = zero                                 ! the largest |T_ik| off the diagonal
      do i = 1, f2
        toff = max(toff, maxval(abs(th(:i - 1, i))), maxval(abs(th(i + 1:, i))))
      end do
      th = transpose(th)           ! kept as T^T: a row of T is a column (contiguous)
      ! c_k = Q^T [0; M_r^-1 g_k]: the lower half of Q's rows (kept transposed, contiguous)
      qlt = transpose(qh(f + 1:, :))
      c0 = matmul(qlt, c0(1:f, :))
      c1 = matmul(qlt, c1(1:f, :))
      c2 = matmul(qlt, c2(1:f, :))
      use = .true.
    end subroutine hess_setup

    !> b = [Re z; Im z] at om: (i om I - T) y = c0 + om^2 c2 + i om c1 by an LU that pivots
    !! between neighbouring rows (T is upper Hessenberg), z = Q(1:f, :) y. flag 1: a pivot at
    !! most 2 nfree eps max|i om I - T| (singular to working precision). The matrix is held
    !! transposed (tc(:, k) its row k: the row operations run down contiguous columns), and
    !! max|i om I - T| comes from T's largest off-diagonal entry and the diagonal.
    subroutine hess_solve(om, flag)
      real(wp), intent(in) :: om
      integer, intent(out) :: flag
      integer :: kk, f2, ierr
      complex(wp) :: l, piv(size(yc, 2)), rowt(2 * f)
      real(wp) :: tiny_piv
      flag = 0; f2 = 2 * f
      do kk = 1, f2                               ! (i om I - T)^T: its entries on and below
        tc(max(kk - 1, 1):, kk) = cmplx(-th(max(kk - 1, 1):, kk), zero, wp)   ! the superdiagonal
        tc(kk, kk) = tc(kk, kk) + cmplx(zero, om, wp)                  ! (the rest is never read)
      end do
      ! a pivot at round-off of the matrix: singular (as an exact zero on the dense path)
      tiny_piv = toff
      do kk = 1, f2
        tiny_piv = max(tiny_piv, abs(tc(kk, kk)))
      end do
      tiny_piv = f2 * epsilon(one) * tiny_piv
      yc = cmplx(c0 + om**2 * c2, om * c1, wp)
      do kk = 1, f2 - 1                           ! eliminate the subdiagonal
        sw(kk) = abs(tc(kk, kk + 1)) > abs(tc(kk, kk))
        if (sw(kk)) then
          rowt(kk:) = tc(kk:, kk); tc(kk:, kk) = tc(kk:, kk + 1); tc(kk:, kk + 1) = rowt(kk:)
          piv = yc(kk, :); yc(kk, :) = yc(kk + 1, :); yc(kk + 1, :) = piv
        end if
        if (abs(tc(kk, kk)) <= tiny_piv) then
          flag = 1; return
        end if
        l = tc(kk, kk + 1) / tc(kk, kk)
        lm(kk) = l
        tc(kk + 1:, kk + 1) = tc(kk + 1:, kk + 1) - l * tc(kk + 1:, kk)
        yc(kk + 1, :) = yc(kk + 1, :) - l * yc(kk, :)
      end do
      if (abs(tc(f2, f2)) <= tiny_piv) then
        flag = 1; return
      end if
      call back_substitute()
      yre = real(yc, wp); yim = aimag(yc)         ! z = [I 0] Q y
      call dgemm('N', 'N', f, np, f2, one, qh, f2, yre, f2, zero, b, f2)
      call dgemm('N', 'N', f, np, f2, one, qh, f2, yim, f2, zero, b(f + 1, 1), f2)
      ! refinement: rho = g - (K_r - om^2 M_r + i om C_r) z, z = b(1:f) + i b(f + 1:)
      rre = g0 + om**2 * g2
      call dgemm('N', 'N', f, np, f, -one, kr, f, b, f2, one, rre, f)
      call dgemm('N', 'N', f, np, f, om**2, mr, f, b, f2, one, rre, f)
      call dgemm('N', 'N', f, np, f, om, cr, f, b(f + 1, 1), f2, one, rre, f)
      rim = om * g1
      call dgemm('N', 'N', f, np, f, -one, kr, f, b(f + 1, 1), f2, one, rim, f)
      call dgemm('N', 'N', f, np, f, om**2, mr, f, b(f + 1, 1), f2, one, rim, f)
      call dgemm('N', 'N', f, np, f, -om, cr, f, b, f2, one, rim, f)
      call dgetrs('N', f, np, a, f2, ipiv, rre, f, ierr)   ! M_r^-1 rho
      call dgetrs('N', f, np, a, f2, ipiv, rim, f, ierr)
      call dgemm('N', 'N', f2, np, f, one, qlt, f2, rre, f, zero, yre, f2)   ! Q^T [0; M_r^-1 rho]
      call dgemm('N', 'N', f2, np, f, one, qlt, f2, rim, f, zero, yim, f2)
      yc = cmplx(yre, yim, wp)
      do kk = 1, f2 - 1                           ! the elimination replayed
        if (sw(kk)) then
          piv = yc(kk, :); yc(kk, :) = yc(kk + 1, :); yc(kk + 1, :) = piv
        end if
        yc(kk + 1, :) = yc(kk + 1, :) - lm(kk) * yc(kk, :)
      end do
      call back_substitute()
      yre = real(yc, wp); yim = aimag(yc)
      call dgemm('N', 'N', f, np, f2, one, qh, f2, yre, f2, one, b, f2)
      call dgemm('N', 'N', f, np, f2, one, qh, f2, yim, f2, one, b(f + 1, 1), f2)
    end subroutine hess_solve

    !> yc = U^-1 yc with U the upper triangle of the eliminated tc (held transposed).
    subroutine back_substitute()
      integer :: kk, r
      do kk = 2 * f, 1, -1
        do r = 1, np
          yc(kk, r) = (yc(kk, r) - sum(tc(kk + 1:, kk) * yc(kk + 1:, r))) / tc(kk, kk)
        end do
      end do
    end subroutine back_substitute

    !> lre, lim at frequency j: J_a^T dlambda = r - (K - om^2 M) H_re + om C H_im (real part)
    !! and -(K - om^2 M) H_im - om C H_re (imaginary), H = s_n + N z (z in b).
    subroutine multipliers(j, om, st)
      integer, intent(in) :: j
      real(wp), intent(in) :: om
      integer, intent(out) :: st
      integer :: kk
      st = MBD_OK
      do kk = 1, np                               ! b_re = r - (K - om^2 M) H_re + om C H_im
        y = rr(:, kk) - ks(:, kk) + om**2 * ms(:, kk)
        if (f > 0) then
          call dgemm('N', 'N', n, 1, f, -one, kn, n, b(1, kk), 2 * f, one, y, n)
          call dgemm('N', 'N', n, 1, f, om**2, mn, n, b(1, kk), 2 * f, one, y, n)
          call dgemm('N', 'N', n, 1, f, om, cn, n, b(f + 1, kk), 2 * f, one, y, n)
        end if
        call proj_multipliers(w, y, lre(:, kk, j), st)
        if (st /= MBD_OK) return
        y = -om * cs(:, kk)                       ! b_im = -(K - om^2 M) H_im - om C H_re
        if (f > 0) then
          call dgemm('N', 'N', n, 1, f, -one, kn, n, b(f + 1, kk), 2 * f, one, y, n)
          call dgemm('N', 'N', n, 1, f, om**2, mn, n, b(f + 1, kk), 2 * f, one, y, n)
          call dgemm('N', 'N', n, 1, f, -om, cn, n, b(1, kk), 2 * f, one, y, n)
        end if
        call proj_multipliers(w, y, lim(:, kk, j), st)
        if (st /= MBD_OK) return
      end do
    end subroutine multipliers

    !> P(K N), P(M N), P(C N) and P(r - K s_n), P(M s_n), P(C s_n) (multipliers_by_parts);
    !! use false (and no failure) when their memory cannot be had: the solves per frequency.
    subroutine parts_setup(use, st)
      logical, intent(inout) :: use
      integer, intent(out) :: st
      integer :: nq, kk
      st = MBD_OK; nq = size(lam)
      allocate (pk(nq, f), pm(nq, f), pc(nq, f), p0(nq, np), p2(nq, np), p1(nq, np), &
                lw(nq, np), stat=ist)
      if (ist /= 0) then
        use = .false.; return
      end if
      pk = zero; pm = zero; pc = zero; p0 = zero; p2 = zero; p1 = zero
      do kk = 1, f
        call proj_multipliers(w, kn(:, kk), pk(:, kk), st)
        if (st == MBD_OK) call proj_multipliers(w, mn(:, kk), pm(:, kk), st)
        if (st == MBD_OK) call proj_multipliers(w, cn(:, kk), pc(:, kk), st)
        if (st /= MBD_OK) return
      end do
      do kk = 1, np
        y = rr(:, kk) - ks(:, kk)
        call proj_multipliers(w, y, p0(:, kk), st)
        if (st == MBD_OK) call proj_multipliers(w, ms(:, kk), p2(:, kk), st)
        if (st == MBD_OK) call proj_multipliers(w, cs(:, kk), p1(:, kk), st)
        if (st /= MBD_OK) return
      end do
    end subroutine parts_setup

    !> lre, lim at frequency j as multipliers' from the parts (H = s_n + N z, z in b):
    !! Re = P(r - K s_n) + om^2 P(M s_n) - P(K N) z_re + om^2 P(M N) z_re + om P(C N) z_im,
    !! Im = -om P(C s_n) - P(K N) z_im + om^2 P(M N) z_im - om P(C N) z_re.
    subroutine multipliers_by_parts(j, om)
      integer, intent(in) :: j
      real(wp), intent(in) :: om
      integer :: nq
      nq = size(lam)
      lw = p0 + om**2 * p2
      if (f > 0) then
        call dgemm('N', 'N', nq, np, f, -one, pk, nq, b, 2 * f, one, lw, nq)
        call dgemm('N', 'N', nq, np, f, om**2, pm, nq, b, 2 * f, one, lw, nq)
        call dgemm('N', 'N', nq, np, f, om, pc, nq, b(f + 1, 1), 2 * f, one, lw, nq)
      end if
      lre(:, :, j) = lw
      lw = -om * p1
      if (f > 0) then
        call dgemm('N', 'N', nq, np, f, -one, pk, nq, b(f + 1, 1), 2 * f, one, lw, nq)
        call dgemm('N', 'N', nq, np, f, om**2, pm, nq, b(f + 1, 1), 2 * f, one, lw, nq)
        call dgemm('N', 'N', nq, np, f, -om, pc, nq, b, 2 * f, one, lw, nq)
      end if
      lim(:, :, j) = lw
    end subroutine multipliers_by_parts
  end subroutine frf_solve

  !> M_r's factors show a free motion without mass: a pivot (piv(k): |u_kk| of an LU, or
  !! u_kk^2 of a Cholesky factor) at most MASS_TOL times M_r's largest diagonal entry dmax
  !! (NaN too). A zero mass leaves pivots of round-off size, about eps dmax, and an exact
  !! zero only by chance: the null basis' vectors decide which.
  pure logical function massless(piv, dmax)
    real(wp), intent(in) :: piv(:)              !! the factors' pivots
    real(wp), intent(in) :: dmax                !! max diag(M_r)
    massless = any(.not. (piv > MASS_TOL * dmax))
  end function massless

  !> M_r = P L U in place (dgetrf), info /= 0 also where a pivot shows a free motion without
  !! mass (massless; f >= 1).
  subroutine mass_lu(f, a, lda, ipiv, info)
    integer, intent(in) :: f, lda               !! free motions, a's leading dimension
    real(wp), intent(inout) :: a(lda, *)        !! M_r, then its LU factors
    integer, intent(out) :: ipiv(:)             !! (f) row interchanges
    integer, intent(out) :: info                !! 0, or dgetrf's info, or f + 1: massless
    real(wp) :: dmax
    integer :: i
    dmax = maxval([(a(i, i), i = 1, f)])
    call dgetrf(f, f, a, lda, ipiv, info)
    if (info == 0) then
      if (massless([(abs(a(i, i)), i = 1, f)], dmax)) info = f + 1
    end if
  end subroutine mass_lu

  !> The linearized motion's parts about the rest state (q, t, lam), every one exact: N, a
  !! basis of J_a's null space (dyn_null_basis), K N, C N, M N and the reduced K_r = N^T K N,
  !! C_r = N^T C N, M_r = N^T M N; per parameter r = Q_p - J_p^T lambda, the minimum-norm
  !! s_n (J_a s_n = -Phi_p,a) and K s_n, M s_n, and C s_n - Q_p_dot in cs: the parameter's
  !! rate forces the motion by (Q_p_dot - C s_n) p_dot (a damper whose point moves, and the
  !! damping of the motion s_n p imposes), which enters each equation as -C s_n alone did. Leaves s at rest (sens_at_rest) and the
  !! projection factored (dyn_factor_projection) for the multipliers' least squares.
  subroutine linear_parts(m, w, s, q, t, lam, nb, kn, cn, mn, kr, cr, mr, sn, ks, cs, ms, &
                          rr, status, msg)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(inout) :: w        !! work arrays (dyn_init done)
    type(sens_t), intent(inout) :: s            !! the parameters (sens_setup done)
    real(wp), intent(in) :: q(:), t             !! rest state (core units), time
    real(wp), intent(in) :: lam(:)              !! its multipliers (neq)
    !> (nq, max(f, 1)) N, K N, C N, M N (f = nq - the active rows), allocated here
    real(wp), allocatable, intent(out) :: nb(:, :), kn(:, :), cn(:, :), mn(:, :)
    !> (f, f) K_r, C_r, M_r, allocated here
    real(wp), allocatable, intent(out) :: kr(:, :), cr(:, :), mr(:, :)
    !> (nq, np) s_n, K s_n, C s_n, M s_n and r, allocated here
    real(wp), allocatable, intent(out) :: sn(:, :), ks(:, :), cs(:, :), ms(:, :), rr(:, :)
    integer, intent(out) :: status  !! MBD_OK, MBD_SINGULAR, MBD_NO_MEMORY or the solves'
    character(len=MSG_LEN), intent(out) :: msg  !! explanation (the caller names itself)
    real(wp) :: x(m%nq), y(m%nq), z(m%nq)
    ! K and C on the sparse pattern (exact, one product per colour group) when that takes
    ! fewer products than the columns of N and s_n
    real(wp), allocatable :: kv(:), cv(:), wk(:)
    integer :: n, f, np, j, k, ist, nnz
    logical :: bypattern
    status = MBD_OK; msg = ''
    n = m%nq; f = n - w%na; np = s%np
    nnz = w%kptr(n + 1) - 1
    bypattern = w%ncolor < f + np
    allocate (nb(n, max(f, 1)), kn(n, max(f, 1)), cn(n, max(f, 1)), mn(n, max(f, 1)), &
              sn(n, np), ks(n, np), cs(n, np), ms(n, np), rr(n, np), kr(f, f), cr(f, f), &
              mr(f, f), kv(merge(nnz, 0, bypattern)), cv(merge(nnz, 0, bypattern)), &
              wk(merge(n, 0, bypattern)), stat=ist)
    if (ist /= 0) then
      call mem_fail(REAL_BYTES * (4 * real(n, wp) * max(f, 1) + 5 * real(n, wp) * np + &
                                  3 * real(f, wp)**2 + 2 * real(nnz, wp) + n), &
                    'the linearized motion''s parts', HINT, status, msg)
      return
    end if
    nb = zero; kn = zero; cn = zero; mn = zero
    z = zero
    call sens_at_rest(m, s, q, t, lam, z)
    if (bypattern) call sens_tangent_pattern(m, w, s, q, t, z, kv, x, y, wk, cv)
    if (f > 0) then                               ! N, K N, C N, M N
      call dyn_null_basis(m, w, q, t, nb(:, 1:f), status)
      if (status /= MBD_OK) then
        status = MBD_SINGULAR; msg = 'no basis of the free motions (J is singular)'; return
      end if
      do j = 1, f
        call kmul(nb(:, j), kn(:, j))
        call cmul(nb(:, j), cn(:, j))
        mn(:, j) = m%mdiag * nb(:, j)
      end do
      call dgemm('T', 'N', f, f, n, one, nb, n, kn, n, zero, kr, f)   ! K_r = N^T (K N), ...
      call dgemm('T', 'N', f, f, n, one, nb, n, cn, n, zero, cr, f)
      call dgemm('T', 'N', f, f, n, one, nb, n, mn, n, zero, mr, f)
    end if
    call dyn_factor_projection(m, w, q, t, .false., status)
    if (status /= MBD_OK) then
      msg = 'the projection onto the constraints is singular'; return
    end if
    do k = 1, s%np                                ! r, s_n (J_a s_n = -Phi_p,a) and its products
      call statics_load(m, s, k, q, t, lam, z, y, rr(:, k))
      call proj_particular(w, s, k, sn(:, k), status)
      if (status /= MBD_OK) then
        msg = 'a saddle-point solve failed'; return
      end if
      call kmul(sn(:, k), ks(:, k))
      call cmul(sn(:, k), cs(:, k))
      call sens_force_rate(m, s, k, q, z, t, y)   ! the rate forcing Q_p_dot, with C s_n's
      cs(:, k) = cs(:, k) - y
      ms(:, k) = m%mdiag * sn(:, k)
    end do
  contains
    !> kx = K x (exact: on the pattern, or sens_stiffness_mul).
    subroutine kmul(xx, kx)
      real(wp), intent(in) :: xx(:)
      real(wp), intent(out) :: kx(:)
      if (bypattern) then
        call dyn_pattern_mul(w, kv, xx, kx)
      else
        call sens_stiffness_mul(m, s, q, t, z, xx, kx, x)
      end if
    end subroutine kmul

    !> cx = C x = -Q_q_dot x (exact: on the pattern, or sens_damping_mul).
    subroutine cmul(xx, cx)
      real(wp), intent(in) :: xx(:)
      real(wp), intent(out) :: cx(:)
      if (bypattern) then
        call dyn_pattern_mul(w, cv, xx, cx)
      else
        call sens_damping_mul(m, s, q, t, z, xx, cx)
      end if
    end subroutine cmul
  end subroutine linear_parts

end module mbd_frf
