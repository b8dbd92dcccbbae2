!> mbd_frf: the frequency response of the linearized motion about an equilibrium to a design
!! parameter varied harmonically, p = p0 + Re(P e^(i Omega t)) (a shaker's force amplitude, a
!! spring's free length as a displacement input, gravity as a base acceleration, a pivot's
!! place as a base motion).
!!
!! About the equilibrium q*, lambda* (drivers held at t) the motion obeys to first order
!! (Geradin and Cardona ch. 11; the statics sensitivities' linearization, mbd_sens_dynamics)
!!   M dq'' + C dq' + K dq + J_a^T dlambda = r P e^(i Omega t),
!!   J_a dq = -Phi_p,a P e^(i Omega t)
!! with r = Q_p - J_p^T lambda*, K = K_lambda - Q_q and C = -Q_q_dot, all exact
!! (mbd_sensitivity). The steady response dq = H(Omega) P e^(i Omega t) is H = s_n + N z:
!! J_a s_n = -Phi_p,a (the minimum-norm solution), N a basis of J_a's null space, and
!!   (K_r - Omega^2 M_r + i Omega C_r) z = N^T (r - (K - Omega^2 M + i Omega C) s_n),
!! K_r = N^T K N, M_r = N^T M N, C_r = N^T C N; Omega = 0 gives the statics sensitivity dq*/dp.
!! Each frequency solves the real form [A, -B; B, A] [z_re; z_im] = [b_re; b_im],
!! A = K_r - Omega^2 M_r, B = Omega C_r (one dgetrf for every parameter). The multipliers'
!! response, when asked for: J_a^T dlambda = r - (K - Omega^2 M + i Omega C) H, real and
!! imaginary parts by the least squares of the projection's factors (as the statics
!! sensitivities; K H from K s_n + (K N) z).
!! Memory: N, K N, C N, M N (nq x nfree), four nq x np arrays, three nfree x nfree and one
!! 2 nfree x 2 nfree matrix, checked and allocated once per call (MBD_NO_MEMORY otherwise).
module mbd_frf
  use mbd_kinds, only: wp, zero
  use mbd_status, only: MBD_OK, MBD_SINGULAR, MBD_LAPACK, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail
  use mbd_model, only: model_t
  use mbd_lapack, only: dgetrf, dgetrs
  use mbd_sensitivity, only: sens_t, sens_trig, sens_hessian, sens_params, sens_klam, &
                             sens_klam_list, sens_force_d
  use mbd_sens_dynamics, only: statics_load
  use mbd_dynamics, only: dyn_work_t, dyn_null_basis, dyn_factor_projection, dyn_solve
  implicit none
  private
  public :: frf_solve

  character(len=*), parameter :: HINT = 'the frequency response uses dense matrices of the ' &
    // 'number of free motions: use a model with fewer free motions'

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
    real(wp), intent(out) :: hre(:, :, :), him(:, :, :)  !! (nq, np, nomega)
    integer, intent(out) :: ibad                !! the singular frequency (0: none)
    integer, intent(out) :: status              !! MBD_OK, MBD_SINGULAR, MBD_NO_MEMORY, ...
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    !> (neq, np, nomega) the multipliers' response dlambda (core units; redundant rows 0)
    real(wp), intent(out), optional :: lre(:, :, :), lim(:, :, :)
    ! N, K N, C N, M N; s_n, K s_n, C s_n, M s_n and r per parameter; K_r, C_r, M_r, the real
    ! form of the reduced matrix, its right-hand sides; work vectors
    real(wp), allocatable :: nb(:, :), kn(:, :), cn(:, :), mn(:, :), sn(:, :), ks(:, :), &
                             cs(:, :), ms(:, :), rr(:, :), kr(:, :), cr(:, :), mr(:, :), &
                             a(:, :), b(:, :), x(:), y(:), z(:)
    integer, allocatable :: ipiv(:)
    real(wp) :: bytes, om
    integer :: n, f, np, na, i, j, k, ist, info
    character(len=MSG_LEN) :: what
    status = MBD_OK; msg = ''; ibad = 0
    hre = zero; him = zero
    if (present(lre)) lre = zero
    if (present(lim)) lim = zero
    n = m%nq; na = w%na; f = n - na; np = s%np
    if (np == 0 .or. size(omega) == 0) return
    bytes = REAL_BYTES * (4 * real(n, wp) * max(f, 1) + 5 * real(n, wp) * np &
                          + 7 * real(max(f, 1), wp)**2 + 2 * real(max(f, 1), wp) * np + 3 * n)
    write (what, '(a,i0,a)') 'the frequency response''s work arrays (', f, ' free motions)'
    call mem_check(bytes, trim(what), HINT, status, msg)
    if (status /= MBD_OK) return
    allocate (nb(n, max(f, 1)), kn(n, max(f, 1)), cn(n, max(f, 1)), mn(n, max(f, 1)), &
              sn(n, np), ks(n, np), cs(n, np), ms(n, np), rr(n, np), kr(f, f), cr(f, f), &
              mr(f, f), a(2 * f, 2 * f), b(2 * f, np), x(n), y(n), z(n), ipiv(2 * f), &
              stat=ist)
    if (ist /= 0) then
      call mem_fail(bytes, trim(what), HINT, status, msg); return
    end if
    z = zero
    call sens_trig(m, s, q)
    call sens_hessian(m, s, q, z, z, t)
    call sens_params(m, s, q, z, z, t)
    call sens_klam_list(m, s, lam)
    if (f > 0) then                               ! N, K N, C N, M N
      call dyn_null_basis(m, w, q, t, nb, status)
      if (status /= MBD_OK) then
        status = MBD_SINGULAR
        msg = 'frequency response: no basis of the free motions (J is singular)'; return
      end if
      do j = 1, f
        call kmul(nb(:, j), kn(:, j))
        call cmul(nb(:, j), cn(:, j))
        mn(:, j) = m%mdiag * nb(:, j)
      end do
      kr = matmul(transpose(nb(:, 1:f)), kn(:, 1:f))
      cr = matmul(transpose(nb(:, 1:f)), cn(:, 1:f))
      mr = matmul(transpose(nb(:, 1:f)), mn(:, 1:f))
    end if
    call dyn_factor_projection(m, w, q, t, .false., status)
    if (status /= MBD_OK) then
      msg = 'frequency response: the projection onto the constraints is singular'; return
    end if
    do k = 1, np                                  ! r, s_n (J_a s_n = -Phi_p,a) and its products
      call statics_load(m, s, k, q, t, lam, z, y, rr(:, k))
      w%rhs(1:n) = zero
      do i = 1, na
        w%rhs(n + i) = w%s * s%mphip(k, w%rows(i))
      end do
      call dyn_solve(w, w%rhs, status)
      if (status /= MBD_OK) then
        msg = 'frequency response: a saddle-point solve failed'; return
      end if
      sn(:, k) = w%rhs(1:n)
      call kmul(sn(:, k), ks(:, k))
      call cmul(sn(:, k), cs(:, k))
      ms(:, k) = m%mdiag * sn(:, k)
    end do
    do j = 1, size(omega)
      om = omega(j)
      do k = 1, np
        hre(:, k, j) = sn(:, k)
      end do
      if (f > 0) then                             ! (every motion driven: dq = s_n)
        a(1:f, 1:f) = kr - om**2 * mr; a(f + 1:, f + 1:) = a(1:f, 1:f)
        a(f + 1:, 1:f) = om * cr; a(1:f, f + 1:) = -om * cr
        ! b = N^T (r - (K - Omega^2 M) s_n) - i Omega N^T C s_n
        b(1:f, :) = matmul(transpose(nb(:, 1:f)), rr - ks + om**2 * ms)
        b(f + 1:, :) = -om * matmul(transpose(nb(:, 1:f)), cs)
        call dgetrf(2 * f, 2 * f, a, 2 * f, ipiv, info)
        if (info > 0) then
          ibad = j; status = MBD_SINGULAR
          msg = 'frequency response: K_r - Omega^2 M_r + i Omega C_r is singular (an ' // &
                'undamped natural frequency, or 0 Hz with a motion without stiffness)'
          return
        else if (info /= 0) then
          status = MBD_LAPACK; write (msg, '(a,i0)') 'frequency response: dgetrf info ', info
          return
        end if
        call dgetrs('N', 2 * f, np, a, 2 * f, ipiv, b, 2 * f, info)
        hre(:, :, j) = hre(:, :, j) + matmul(nb(:, 1:f), b(1:f, :))
        him(:, :, j) = matmul(nb(:, 1:f), b(f + 1:, :))
      end if
      if (present(lre) .and. present(lim)) then
        call multipliers(j, om, status)
        if (status /= MBD_OK) then
          msg = 'frequency response: the multipliers'' least squares failed'; return
        end if
      end if
    end do
  contains
    !> lre, lim at frequency j: J_a^T dlambda = r - (K - om^2 M) H_re + om C H_im (real part)
    !! and -(K - om^2 M) H_im - om C H_re (imaginary), H = s_n + N z (z in b).
    subroutine multipliers(j, om, st)
      integer, intent(in) :: j
      real(wp), intent(in) :: om
      integer, intent(out) :: st
      integer :: kk, part
      st = MBD_OK
      do kk = 1, np
        do part = 1, 2
          if (part == 1) then                     ! b_re = r - (K - om^2 M) H_re + om C H_im
            w%rhs(1:n) = rr(:, kk) - ks(:, kk) + om**2 * ms(:, kk)
            if (f > 0) w%rhs(1:n) = w%rhs(1:n) - matmul(kn(:, 1:f) - om**2 * mn(:, 1:f), &
                                                        b(1:f, kk)) + om * matmul(cn(:, 1:f), &
                                                        b(f + 1:, kk))
          else                                    ! b_im = -(K - om^2 M) H_im - om C H_re
            w%rhs(1:n) = -om * cs(:, kk)
            if (f > 0) w%rhs(1:n) = w%rhs(1:n) - matmul(kn(:, 1:f) - om**2 * mn(:, 1:f), &
                                                        b(f + 1:, kk)) - om * matmul(cn(:, 1:f), &
                                                        b(1:f, kk))
          end if
          w%rhs(n + 1:) = zero
          call dyn_solve(w, w%rhs, st)
          if (st /= MBD_OK) return
          do i = 1, na
            if (part == 1) then
              lre(w%rows(i), kk, j) = w%s * w%rhs(n + i)
            else
              lim(w%rows(i), kk, j) = w%s * w%rhs(n + i)
            end if
          end do
        end do
      end do
    end subroutine multipliers

    !> kx = K x = K_lambda x - Q_q x (exact).
    subroutine kmul(xx, kx)
      real(wp), intent(in) :: xx(:)
      real(wp), intent(out) :: kx(:)
      call sens_klam(s, xx, kx)
      call sens_force_d(m, s, 0, q, z, xx, z, t, x)
      kx = kx - x
    end subroutine kmul

    !> cx = C x = -Q_q_dot x (exact).
    subroutine cmul(xx, cx)
      real(wp), intent(in) :: xx(:)
      real(wp), intent(out) :: cx(:)
      call sens_force_d(m, s, 0, q, z, z, xx, t, x)
      cx = -x
    end subroutine cmul
  end subroutine frf_solve

end module mbd_frf
