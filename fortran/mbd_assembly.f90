!> mbd_assembly: assembly of a model from rough estimates of its coordinates in band storage
!! (no n x n array), by Levenberg-Marquardt on ||Phi(q, t)||^2 with the saddle-point solver of
!! mbd_saddle. The kinematics' band mode and the band path of dynamics and statics take it;
!! the dense Levenberg-Marquardt with its rank diagnosis is mbd_kinematics' kin_assemble.
module mbd_assembly
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_ASSEMBLY_FAILED, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_fail
  use mbd_points, only: NLOC
  use mbd_model, only: model_t
  use mbd_constraints, only: con_name
  use mbd_assemble, only: asm_work_t, asm_init, assemble_blocks, init_extras
  use mbd_saddle, only: saddle_t, saddle_plan, saddle_factor, saddle_solve
  implicit none
  private
  public :: band_lm_assemble

  integer, parameter :: BANDED = 2            !! saddle_plan's band solver

contains

  !> Assemble a model in band storage: from rough estimates q (extras estimated here)
  !! minimize ||Phi(q, t)||^2 by Levenberg-Marquardt, as kin_assemble does with a dense J,
  !! each step from the augmented system [mu I, J^T; J, -I][dq; y] = [0; -Phi] (the normal
  !! equations (J^T J + mu I) dq = -J^T Phi of [J; sqrt(mu) I] dq = [-Phi; 0]) in band
  !! storage over all rows, to ||Phi||_inf <= tol. MBD_ASSEMBLY_FAILED (worst: the
  !! constraint with the largest residual, resid its size) when the residual stays above
  !! 1000 tol.
  subroutine band_lm_assemble(m, q, t, tol, maxit, status, msg, worst, resid)
    type(model_t), intent(in) :: m              !! model
    real(wp), intent(inout) :: q(:)             !! estimates, then the assembled configuration
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(in) :: tol                 !! ||Phi||_inf tolerance (absolute)
    integer, intent(in) :: maxit                !! iterations
    integer, intent(out) :: status              !! MBD_OK, MBD_ASSEMBLY_FAILED, MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(out) :: worst               !! constraint with the largest residual
    real(wp), intent(out) :: resid              !! ||Phi||_inf at the end
    type(saddle_t) :: sd
    type(asm_work_t) :: aw
    real(wp), allocatable :: phi(:), phit(:), nu(:), gam(:), qz(:), qt(:), rhs(:), dmu(:), cs(:)
    real(wp) :: mu, f, ft, dmax
    integer :: it, n, neq, ierr, r, k, s, c, st
    status = MBD_OK; msg = ''
    worst = 0; resid = zero
    n = m%nq; neq = m%neq
    call init_extras(m, q)
    allocate (phi(neq), phit(neq), nu(neq), gam(neq), qz(n), qt(n), rhs(n + neq), dmu(n), &
              cs(n), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * (4 * real(neq, wp) + 5 * n), 'the assembly work arrays', &
                    'use a smaller model', status, msg)
      return
    end if
    call asm_init(m, aw, status, msg)
    if (status /= MBD_OK) return
    call saddle_plan(m, [(r, r=1, neq)], BANDED, sd, status, msg)
    if (status /= MBD_OK) return
    qz = zero
    call assemble_blocks(m, q, qz, t, phi, nu, gam, aw)
    f = norm2(phi)
    ! the largest squared column norm of J (kin_assemble's scale of mu)
    cs = zero
    do k = 1, m%nc
      do s = 1, NLOC
        c = m%loc(s, k)
        if (c > 0) cs(c) = cs(c) + sum(aw%jb(1:m%nrow(k), s, k)**2)
      end do
    end do
    dmax = zero
    if (n > 0) dmax = maxval(cs)
    mu = 1.0e-3_wp * max(dmax, one)
    do it = 1, maxit
      if (maxval(abs(phi)) <= tol) exit
      dmu = mu
      call saddle_factor(sd, dmu, aw%jb, one, st, e=one)
      rhs(1:n) = zero; rhs(n + 1:) = -phi
      if (st == MBD_OK) call saddle_solve(sd, rhs, st)
      if (st /= MBD_OK) then
        mu = mu * 10.0_wp; cycle
      end if
      qt = q + rhs(1:n)
      call assemble_blocks(m, qt, qz, t, phit, nu, gam, aw)
      ft = norm2(phit)
      if (ft < f) then
        q = qt; f = ft; phi = phit
        mu = max(mu / 10.0_wp, 1.0e-20_wp * max(dmax, one))
      else
        call assemble_blocks(m, q, qz, t, phi, nu, gam, aw)
        mu = mu * 10.0_wp
        if (mu > 1.0e20_wp * max(dmax, one)) exit
      end if
    end do
    resid = maxval(abs(phi))
    worst = m%con_of_row(maxloc(abs(phi), 1))
    if (resid <= 1.0e3_wp * tol) return
    status = MBD_ASSEMBLY_FAILED
    write (msg, '(a,es10.3,a,i0,a)') 'assembly failed: no configuration satisfies the '// &
      'constraints near the estimates (banded solver); smallest residual ||Phi|| = ', resid, &
      ', largest in constraint ', worst, ' ('//trim(con_name(m%kind(worst)))//')'
  end subroutine band_lm_assemble

end module mbd_assembly
