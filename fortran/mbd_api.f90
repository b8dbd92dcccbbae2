!> mbd_api: whole analyses behind flat arguments (plain arrays, integers, a status and a
!! message). The f2py layer and the standalone program both call these; derived types stay
!! inside. Report arrays:
!!   iinfo(NINFO): 1 output rows computed, 2 offending constraint (bad input), 3 driver that
!!                 can no longer be met, 4 constraint with the largest residual, 5 rank
!!                 deficiency, 6 Newton corrections, 7 factorizations, 8 rejected steps,
!!                 9 rank of J at assembly, 10 singular configurations passed through
!!   rinfo(NINFO): 1 time of the singular configuration or failure, 2 sigma_min, 3 sigma_max,
!!                 4 residual
module mbd_api
  use mbd_kinds, only: wp, zero
  use mbd_status, only: MBD_OK, MBD_BAD_COUNT, MBD_INCONSISTENT, MSG_LEN
  use mbd_points, only: NLOC, MAXROW
  use mbd_model, only: model_t, model_build
  use mbd_assemble, only: assemble_dense
  use mbd_kinematics, only: kin_opts_t, kin_report_t, kin_work_t, kin_run, kin_work_init, &
                            kin_assemble, kin_rank, MAXPASS
  use mbd_profiles, only: profile_raw_length, profile_prepare, profile_eval
  implicit none
  private
  public :: NINFO, api_sizes, api_eval, api_kinematics, api_profile, api_analyze

  integer, parameter :: NINFO = 10   !! length of the report arrays

contains

  !> Build the model; return its sizes.
  subroutine api_sizes(nb, ctab, rpar, nq, neq, status, msg, bad)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    integer, intent(out) :: nq, neq             !! coordinates, equations
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer, intent(out) :: bad                 !! offending constraint, or 0
    type(model_t) :: m
    call model_build(nb, ctab, rpar, m, status, msg, bad)
    nq = m%nq; neq = m%neq
  end subroutine api_sizes

  !> Phi, J, nu and gamma at (q, q_dot, t).
  subroutine api_eval(nb, ctab, rpar, q, qd, t, phi, jac, nu, gam, status, msg, bad)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q(:), qd(:)         !! state (nq)
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(out) :: phi(:)             !! Phi (neq)
    real(wp), intent(out) :: jac(:, :)          !! J (neq x nq)
    real(wp), intent(out) :: nu(:), gam(:)      !! nu, gamma (neq)
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer, intent(out) :: bad                 !! offending constraint, or 0
    type(model_t) :: m
    real(wp), allocatable :: jb(:, :, :)
    phi = zero; jac = zero; nu = zero; gam = zero
    call model_build(nb, ctab, rpar, m, status, msg, bad)
    if (status /= MBD_OK) return
    if (size(q) /= m%nq .or. size(qd) /= m%nq .or. size(phi) /= m%neq .or. &
        size(jac, 1) /= m%neq .or. size(jac, 2) /= m%nq) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    allocate (jb(MAXROW, NLOC, m%nc))
    call assemble_dense(m, q, qd, t, phi, nu, gam, jb, jac)
  end subroutine api_eval

  !> Kinematic analysis: the whole time loop in one call.
  subroutine api_kinematics(nb, ctab, rpar, q0, t0, t1, nsteps, tol, maxit, tmin, &
                            qout, qdout, qddout, iinfo, rinfo, qsing, dep, redundant, tpass, &
                            status, msg)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q0(:)               !! estimates (nq; extras are estimated)
    real(wp), intent(in) :: t0, t1              !! time span
    integer, intent(in) :: nsteps               !! output intervals
    real(wp), intent(in) :: tol                 !! Newton tolerance (<= 0: default)
    integer, intent(in) :: maxit                !! Newton iterations (<= 0: default)
    real(wp), intent(in) :: tmin                !! singular-time resolution (<= 0: default)
    real(wp), intent(out) :: qout(:, :), qdout(:, :), qddout(:, :)  !! (nq, nsteps + 1)
    integer, intent(out) :: iinfo(NINFO)        !! integer report
    real(wp), intent(out) :: rinfo(NINFO)       !! real report
    real(wp), intent(out) :: qsing(:)           !! configuration at a singularity (nq)
    integer, intent(out) :: dep(:)              !! dependent rows there (neq)
    integer, intent(out) :: redundant(:)        !! redundant rows at assembly (neq)
    real(wp), intent(out) :: tpass(:)           !! times of singular passages (MAXPASS)
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(model_t) :: m
    type(kin_opts_t) :: opts
    type(kin_report_t) :: rep
    integer :: bad
    iinfo = 0; rinfo = zero; qsing = zero; dep = 0; redundant = 0; tpass = zero
    qout = zero; qdout = zero; qddout = zero
    call model_build(nb, ctab, rpar, m, status, msg, bad)
    iinfo(2) = bad
    if (status /= MBD_OK) return
    if (m%neq < m%nq) then
      status = MBD_BAD_COUNT
      write (msg, '(a,i0,a,i0,a,i0,a)') 'the model is not kinematically determined: ', m%neq, &
        ' equations for ', m%nq, ' coordinates (', m%nq - m%neq, ' degrees of freedom left)'
      return
    end if
    if (size(q0) /= m%nq .or. size(qsing) /= m%nq .or. size(dep) /= m%neq .or. &
        size(redundant) /= m%neq .or. size(tpass) /= MAXPASS .or. &
        size(qout, 1) /= m%nq .or. size(qout, 2) /= nsteps + 1) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    if (tol > zero) opts%tol = tol
    if (maxit > 0) opts%maxit = maxit
    if (tmin > zero) opts%tmin = tmin
    call kin_run(m, q0, t0, t1, nsteps, opts, qout, qdout, qddout, rep, status, msg)
    iinfo(1) = rep%ndone; iinfo(3) = rep%driver; iinfo(4) = rep%worst
    iinfo(5) = rep%deficiency; iinfo(6) = rep%newton_its; iinfo(7) = rep%lu_count
    iinfo(8) = rep%rejected; iinfo(9) = rep%rank; iinfo(10) = rep%npass
    rinfo(1) = rep%t_fail; rinfo(2) = rep%smin; rinfo(3) = rep%smax; rinfo(4) = rep%resid
    if (allocated(rep%qsing)) qsing = rep%qsing
    if (allocated(rep%dep)) dep = rep%dep
    if (allocated(rep%redundant)) redundant = rep%redundant
    tpass = rep%tpass
  end subroutine api_kinematics

  !> Degrees of freedom and redundancy at the configuration assembled from q0 at time t:
  !! the rank of J, the mobility of the joints alone, and the redundant rows. On a failed
  !! assembly, q is the best configuration found, resid its residual and dep the rows that
  !! contradict each other (MBD_INCONSISTENT) or status MBD_ASSEMBLY_FAILED.
  subroutine api_analyze(nb, ctab, rpar, q0, t, tol, q, rank, mobility, redundant, dep, &
                         resid, worst, status, msg)
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    real(wp), intent(in) :: q0(:)               !! estimates (nq)
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(in) :: tol                 !! tolerance (<= 0: default)
    real(wp), intent(out) :: q(:)               !! assembled configuration (nq)
    integer, intent(out) :: rank, mobility      !! rank of J; DOF of the joints alone
    integer, intent(out) :: redundant(:)        !! redundant rows (neq)
    integer, intent(out) :: dep(:)              !! contradicting rows on failure (neq)
    real(wp), intent(out) :: resid              !! ||Phi||_inf at the end
    integer, intent(out) :: worst               !! constraint with the largest residual
    integer, intent(out) :: status              !! MBD_OK, < 0 input, > 0 numerical
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(model_t) :: m
    type(kin_opts_t) :: opts
    type(kin_report_t) :: rep
    type(kin_work_t) :: w
    integer :: bad, k
    q = zero; rank = 0; mobility = 0; redundant = 0; dep = 0; resid = zero; worst = 0
    call model_build(nb, ctab, rpar, m, status, msg, bad)
    worst = bad
    if (status /= MBD_OK) return
    if (size(q0) /= m%nq .or. size(q) /= m%nq .or. size(redundant) /= m%neq .or. &
        size(dep) /= m%neq) then
      status = MBD_BAD_COUNT; msg = 'array sizes do not match the model'; return
    end if
    if (tol > zero) opts%tol = tol
    call kin_work_init(m, w)
    w%tol = opts%tol * max(m%lscale, maxval(abs(q0(1:3 * nb)), &
                                            mask=mod([(k, k=1, 3 * nb)], 3) /= 0))
    allocate (rep%qsing(m%nq), rep%dep(m%neq), rep%redundant(m%neq))
    rep%qsing = zero; rep%dep = 0; rep%redundant = 0
    q = q0
    call kin_assemble(m, w, q, t, opts, rep, status, msg)
    resid = maxval(abs(w%phi)); worst = rep%worst; dep = rep%dep
    if (status == MBD_INCONSISTENT) then
      rank = rep%rank; redundant = rep%redundant
    end if
    if (status /= MBD_OK) return
    call kin_rank(m, w, q, t, rank, mobility, redundant, status, msg)
  end subroutine api_analyze

  !> Points c(alpha) of a cam profile in its body frame (for drawing), from raw parameters.
  subroutine api_profile(kind, raw, alpha, pts, status, msg)
    integer, intent(in) :: kind                 !! profile kind
    real(wp), intent(in) :: raw(:)              !! raw parameters
    real(wp), intent(in) :: alpha(:)            !! parameters to evaluate at
    real(wp), intent(out) :: pts(:, :)          !! (2, size(alpha)) points
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    real(wp), allocatable :: prep(:)
    real(wp) :: c1(2), c2(2), c3(2)
    integer :: i
    pts = zero
    if (profile_raw_length(kind, raw) /= size(raw)) then
      status = MBD_BAD_COUNT; msg = 'profile parameters are malformed'; return
    end if
    call profile_prepare(kind, raw, prep, status, msg)
    if (status /= MBD_OK) return
    do i = 1, size(alpha)
      call profile_eval(kind, prep, alpha(i), pts(:, i), c1, c2, c3)
    end do
  end subroutine api_profile

end module mbd_api
