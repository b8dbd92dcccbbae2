!> mbd_dynamics: the constrained equations of motion and what the integrators need from them.
!!
!!   M q_ddot + J^T lambda = Q(q, q_dot, t),   Phi(q, t) = 0            (Haug ch. 6)
!! Index 1 (accelerations and multipliers at a state):
!!   [ M    s J^T ] [ q_ddot     ]   [ Q     ]
!!   [ s J  0     ] [ lambda / s ] = [ gamma ]      s: a mass scale, for conditioning
!! Only an independent set of constraint rows enters (redundant rows, found by the rank
!! analysis at the start, carry no multiplier of their own); the reported lambda is the
!! minimum-norm solution of J^T lambda = Q - M q_ddot over all rows (dense path) or the
!! least-squares one over the active rows (band path, zero on redundant rows). Near a
!! singular configuration (J momentarily rank deficient, as a parallelogram at its collinear
!! position) the LU is nearly singular although q_ddot is still well defined; there the
!! system is solved as a damped least squares, refined (both paths); see mbd_saddle, which
!! holds both paths of every saddle-point solve.
!! Also here: applied forces and energies, consistent initial velocities (the kinetic-energy
!! projection [M J^T; J 0][q_dot; mu] = [M v0; nu]), the projection of positions onto Phi = 0
!! (minimum-norm Newton steps), the assembly of a large model by Levenberg-Marquardt in
!! band storage, joint reactions and driver efforts, and the tangent stiffness and damping
!! K = d(J^T lambda - Q)/dq, C = -dQ/dq_dot by differences over column groups (a colouring).
!!
!! Linear algebra path (dyn_init's solver): dense (n x n matrices: J, the rank analysis by
!! QR, LU of the saddle-point matrices) for small models, band (mbd_saddle, mbd_band: no
!! n x n array; the rank analysis by a band Cholesky of J J^T) for large ones; auto picks
!! the band for at least SADDLE_BAND_MIN_N coordinates whose saddle-point band is narrow.
!!
!! Contacts and joint friction (mbd_contact): contact forces are part of Q (they read the
!! contact state w%cst: open or closed, impact speed). A joint's friction force a_b along its
!! slip direction g_b = du/dq depends on the multipliers through the normal load N(lambda),
!! which is homogeneous of degree 1 (N = grad N . lambda), so with the direction of grad N
!! fixed the friction is linear in lambda and is solved exactly with the factored matrix A:
!!   x = y0 + sum_b a_b z_b,  A y0 = [Q; s gamma],  A z_b = [g_b; 0],
!!   sliding b:  a_b = c_b grad N_b . lambda(x)     (c_b = -mu(u_dot), or -mu sign)
!!   stuck b:    g_b . q_ddot(x) = -u_ar           (a locked constraint; a_b its force)
!! a small dense system in a; only the directions of grad N are iterated (revolute: the
!! direction of the pin force; translational: the sign of the normal force).
module mbd_dynamics
  use, intrinsic :: iso_fortran_env, only: int64
  use mbd_kinds, only: wp, zero, one, half
  use mbd_status, only: MBD_OK, MBD_SINGULAR, MBD_NO_CONVERGENCE, MBD_LAPACK, MBD_NO_MEMORY, &
                        MBD_ASSEMBLY_FAILED, MBD_BAD_SETTING, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail
  use mbd_points, only: NLOC, rot
  use mbd_model, only: model_t, model_slots
  use mbd_constraints, only: con_is_driver, con_name, con_affine_r, CON_REVOLUTE
  use mbd_forces, only: force_eval, FRC_SPRING, FRC_ROTSPRING, FRC_FRICTION, force_is_contact
  use mbd_contact, only: NCS, NEO, MODE_UNTRACKED, joint_slip, joint_normal_load, &
                         joint_friction_force, reg_mu, contact_damped
  use mbd_points, only: kloc, kscal, local_state
  use mbd_assemble, only: asm_work_t, asm_init, assemble_blocks, assemble_dense, blocks_jv, &
                          blocks_jtv, init_extras
  use mbd_linsolve, only: row_rank, lapack_status, ls_small, RANK_TOL, lu_factor_small, &
                          lu_solve_small, LS_RTOL
  use mbd_lapack, only: dgelsy
  use mbd_saddle, only: saddle_t, saddle_plan, saddle_factor, saddle_solve, saddle_row_rank, &
                        saddle_solve_rows, &
                        SADDLE_BAND_MIN_N, SADDLE_BAND_RATIO
  implicit none
  private
  public :: dyn_work_t, dyn_init, dyn_memory_check, gen_forces, kinetic_energy, dyn_accel, &
            dyn_velocity, &
            dyn_project_pos, dyn_multipliers, dyn_reactions, dyn_tangent, dyn_solve, &
            dyn_solve_rows, &
            dyn_jt_lam, dyn_damped, dyn_choose, dyn_jv, dyn_null_basis, dyn_pattern_mul, &
            dyn_factor_projection, SOLVER_AUTO, SOLVER_DENSE, SOLVER_BANDED, friction_forces, &
            dyn_element_outputs, element_state, element_slip
  public :: MODE_STUCK

  integer, parameter :: MODE_STUCK = 2   !! friction mode of a stuck joint (w%cst(1, k))
  integer, parameter :: FRIC_MAXIT = 30  !! iterations on the directions of the normal loads

  integer, parameter :: SOLVER_AUTO = 0, SOLVER_DENSE = 1, SOLVER_BANDED = 2  !! as kinematics
  !> what to change when the dense dynamics does not fit
  character(len=*), parameter :: DYN_HINT = 'the dense solver keeps matrices of the size ' // &
    'of J: use the banded solver (solver="banded") for a large chain-like model, or a ' // &
    'model with fewer coordinates'

  !> Work arrays, the active (independent) constraint rows, the saddle-point solver and the
  !! pattern of the tangent K with its column groups.
  type :: dyn_work_t
    integer :: n = 0, neq = 0, na = 0     !! coordinates, equations, active rows
    integer :: solver = SOLVER_DENSE      !! path in use: SOLVER_DENSE or SOLVER_BANDED
    integer, allocatable :: rows(:)       !! active rows
    real(wp) :: s = one                   !! constraint scale in the augmented matrix
    real(wp) :: tol = 1.0e-12_wp          !! position tolerance ||Phi||_inf
    real(wp), allocatable :: phi(:), nu(:), gam(:), qz(:)
    real(wp), allocatable :: jac(:, :)    !! dense J (dense path only)
    type(asm_work_t) :: asm               !! assembly work arrays
    real(wp), allocatable :: rhs(:), force(:), jv(:), rsave(:), rres(:)
    type(saddle_t) :: sd                  !! the index-1 saddle-point matrix (both paths)
    !> dense multipliers' workspace: J^T (jt), right-hand side (bls), pivots (jpvt); the
    !! metric (nq)
    real(wp), allocatable :: metric(:), jt(:, :), bls(:)
    real(wp), allocatable :: acopy(:, :)  !! a copy of jt (dense multipliers with friction)
    integer, allocatable :: jpvt(:)
    !> the last dyn_multipliers solved with the LU of J^T in acopy, jpvt (a square J, no
    !! friction): the multipliers' sensitivities reuse it
    logical :: jt_lu = .false.
    !> pattern of K by columns (rows krow(kptr(c):kptr(c+1)-1) of column c) and the column
    !! groups of the differences (columns gcol(gptr(g):gptr(g+1)-1) of group g)
    integer, allocatable :: kptr(:), krow(:), gptr(:), gcol(:)
    integer :: ncolor = 0
    real(wp), allocatable :: tq(:), tr0(:), trp(:), trm(:), th(:)   !! tangent workspace (nq)
    integer :: nsolve = 0                 !! augmented factorizations
    integer :: nrank = 0                  !! rank-revealing fallback solves
    logical :: lsq = .false.              !! the last factorization was nearly singular
    ! contacts and friction
    !> state of each force element (NCS, nf): contact [1 closed / 0 open, impact speed];
    !! joint friction [mode: 0 regularized, +-1 sliding with that sign, 2 stuck]
    real(wp), allocatable :: cst(:, :)
    real(wp), allocatable :: fnl(:), ffr(:)   !! (nf) normal load and friction force
    integer, allocatable :: fidx(:)           !! (nfric) force index of each friction element
    real(wp), allocatable :: gf(:, :), zf(:, :), y0(:), gaf(:)  !! directions, responses
    real(wp), allocatable :: amat(:, :), avec(:), cf(:), dn(:, :)
    integer, allocatable :: fpiv(:)
    integer, allocatable :: fpos(:, :)        !! (2, nfric) active positions of the joint rows
    !> the last friction solve found no solution: its small system singular or the directions
    !! of the normal loads not settling (self-locking)
    logical :: locked = .false.
  end type dyn_work_t

contains

  !> Bytes of the dense dynamics of a model with nq coordinates and neq equations: J, its
  !! transpose, [M J^T; J 0] and a copy, and the integrators' iteration matrix
  !! (generalized-alpha: nq + neq square).
  pure real(wp) function dyn_bytes(nq, neq) result(b)
    integer, intent(in) :: nq, neq   !! coordinates, equations
    real(wp) :: n, e
    n = real(nq, wp); e = real(neq, wp)
    b = REAL_BYTES * (3 * n * e + 3 * (n + e)**2 + 12 * (n + e))
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

  !> The path of a dynamics analysis: SOLVER_DENSE or SOLVER_BANDED. solver SOLVER_AUTO
  !! picks the band for at least SADDLE_BAND_MIN_N coordinates when the band of the
  !! saddle-point matrix (all rows; kl + ku + 1) is at most (nq + neq) / SADDLE_BAND_RATIO
  !! wide. kl, ku: its widths (0 when not planned).
  subroutine dyn_choose(m, solver, path, kl, ku, status, msg)
    type(model_t), intent(in) :: m              !! model (with dynamics data)
    integer, intent(in) :: solver               !! SOLVER_AUTO, SOLVER_DENSE, SOLVER_BANDED
    integer, intent(out) :: path                !! SOLVER_DENSE or SOLVER_BANDED
    integer, intent(out) :: kl, ku              !! band widths
    integer, intent(out) :: status              !! MBD_OK, MBD_BAD_SETTING, MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    type(saddle_t) :: sd
    integer :: r
    status = MBD_OK; msg = ''
    kl = 0; ku = 0
    path = SOLVER_DENSE
    if (solver < SOLVER_AUTO .or. solver > SOLVER_BANDED) then
      status = MBD_BAD_SETTING
      msg = 'solver must be 0 (auto), 1 (dense) or 2 (banded)'; return
    end if
    if (solver == SOLVER_DENSE) return
    if (solver == SOLVER_AUTO .and. m%nq < SADDLE_BAND_MIN_N) return
    call saddle_plan(m, [(r, r=1, m%neq)], SOLVER_BANDED, sd, status, msg)
    if (status /= MBD_OK) then
      if (solver == SOLVER_AUTO .and. status /= MBD_NO_MEMORY) status = MBD_OK
      return
    end if
    kl = sd%kl; ku = sd%ku
    if (solver == SOLVER_BANDED .or. &
        SADDLE_BAND_RATIO * (kl + ku + 1) <= m%nq + m%neq) path = SOLVER_BANDED
  end subroutine dyn_choose

  !> Allocate, choose the active rows by the rank of J at q (redundant rows out), plan the
  !! saddle-point solver on the path (SOLVER_DENSE or SOLVER_BANDED; dyn_choose) and the
  !! pattern and column groups of the tangent. The dense path's footprint (dyn_bytes) is
  !! checked against the memory first.
  subroutine dyn_init(m, w, q, t, tol, status, msg, solver, schur)
    type(model_t), intent(in) :: m              !! model with dynamics data
    type(dyn_work_t), intent(out) :: w          !! work arrays
    real(wp), intent(in) :: q(:)                !! configuration
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(in) :: tol                 !! absolute position tolerance
    integer, intent(out) :: status              !! MBD_OK, MBD_LAPACK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    integer, intent(in), optional :: solver     !! path: SOLVER_DENSE (default) or _BANDED
    !> index-1 systems through the cheaper factorizations where they apply (default): a small
    !! dense matrix's sparse LU, else the Schur complement; .false. keeps the saddle-point LU
    !! with partial pivoting (backward stable next to singular configurations)
    logical, intent(in), optional :: schur
    integer, allocatable :: red(:)
    integer :: rank, r, na, ierr, nt
    logical :: fast
    character(len=MSG_LEN) :: what
    msg = ''
    w%n = m%nq; w%neq = m%neq; w%tol = tol
    w%solver = SOLVER_DENSE
    if (present(solver)) w%solver = solver
    write (what, '(a,i0,a,i0,a)') 'the dynamics work arrays (', m%neq, ' equations, ', m%nq, &
      ' coordinates)'
    if (w%solver == SOLVER_DENSE) then
      call dyn_memory_check(m, status, msg)
      if (status /= MBD_OK) return
    end if
    allocate (w%phi(m%neq), w%nu(m%neq), w%gam(m%neq), w%jv(m%neq), stat=ierr)
    if (ierr == 0) allocate (w%qz(m%nq), w%force(m%nq), red(m%neq), w%metric(m%nq), stat=ierr)
    if (ierr == 0) allocate (w%tq(m%nq), w%tr0(m%nq), w%trp(m%nq), w%trm(m%nq), w%th(m%nq), &
                             stat=ierr)
    if (ierr == 0 .and. w%solver == SOLVER_DENSE) &
      allocate (w%jac(m%neq, m%nq), w%jt(m%nq, m%neq), w%bls(max(m%nq, m%neq)), &
                w%jpvt(m%neq), w%acopy(m%nq, m%neq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * 2 * real(m%neq, wp) * m%nq, trim(what), DYN_HINT, status, msg)
      return
    end if
    call asm_init(m, w%asm, status, msg)
    if (status /= MBD_OK) return
    w%qz = zero
    if (w%solver == SOLVER_DENSE) then
      call assemble_dense(m, q, w%qz, t, w%phi, w%nu, w%gam, w%asm, w%jac)
      call row_rank(w%jac, rank, red, status, msg)
    else
      ! (row_rank: |R_kk| / |R_11| < RANK_TOL of unit rows; here the squared distance)
      call assemble_blocks(m, q, w%qz, t, w%phi, w%nu, w%gam, w%asm)
      call saddle_row_rank(m, w%asm%jb, RANK_TOL**2, red, rank, status, msg)
    end if
    if (status /= MBD_OK) return
    na = count(red == 0)
    w%na = na
    nt = m%nq + na
    allocate (w%rows(na), w%rhs(nt), w%rsave(nt), w%rres(nt), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * real(nt, wp), trim(what), DYN_HINT, status, msg)
      return
    end if
    na = 0
    do r = 1, m%neq
      if (red(r) /= 0) cycle
      na = na + 1
      w%rows(na) = r
    end do
    call alloc_elements(m, w, status, msg)
    if (status /= MBD_OK) return
    w%s = one
    if (any(m%mdiag > zero)) w%s = sum(m%mdiag, mask=m%mdiag > zero) / count(m%mdiag > zero)
    fast = .true.
    if (present(schur)) fast = schur
    ! a small dense matrix: the sparse LU in a fixed pivot order (mbd_splu; the free
    ! slider-crank's dopri5 run 41.8M instructions against 46.3M through S, 134M against 175M
    ! with 4 sensitivities; and at a singular passage its rounding stays smooth in q, where
    ! the Schur complement's cond^2 eps noise makes dopri5's steps underflow); otherwise
    ! (the band path, a large dense matrix) the Schur complement
    call saddle_plan(m, w%rows, w%solver, w%sd, status, msg, index1=.true., small=fast)
    if (status /= MBD_OK) return
    w%sd%use_schur = fast .and. .not. w%sd%sparse
    call tangent_pattern(m, w, status, msg)
  end subroutine dyn_init

  !> The pattern of K = d(J^T lambda - Q)/dq and C = -dQ/dq_dot: entry (i, c) when a
  !! constraint or a force element holds both coordinates (a pin, a weld, a line fixed in
  !! ground: only its bodies' angles, each with itself; see pair). The column groups: greedy
  !! colouring in which two columns share a group only when no row has both in its pattern
  !! (no element couples them to a common coordinate), so one residual evaluation with the
  !! whole group perturbed gives each column's entries exactly as perturbing it alone would.
  subroutine tangent_pattern(m, w, status, msg)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    integer, intent(out) :: status
    character(len=MSG_LEN), intent(inout) :: msg
    integer, allocatable :: cnt(:), color(:), mark(:), nxt(:)
    integer :: n, k, s, i, c, e, nnz, p, pp, g, ierr, ne
    status = MBD_OK
    n = m%nq
    ! count, with repeats, then dedupe per column
    ne = 0
    do k = 1, m%nc
      ne = ne + count(m%loc(:, k) > 0)**2
    end do
    do k = 1, m%nf
      ne = ne + count(m%floc(:, k) > 0)**2
    end do
    allocate (cnt(n + 1), w%krow(ne), mark(n), color(n), nxt(n), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(4 * (real(ne, wp) + 4 * n), 'the pattern of the tangent stiffness', &
                    'use a smaller model', status, msg)
      return
    end if
    cnt = 0
    do e = 1, m%nc + m%nf
      do s = 1, NLOC
        c = slot(e, s)
        if (c > 0) cnt(c + 1) = cnt(c + 1) + count([(pair(e, s, i), i=1, NLOC)])
      end do
    end do
    cnt(1) = 1
    do c = 1, n
      cnt(c + 1) = cnt(c + 1) + cnt(c)
    end do
    nxt = cnt(1:n)
    do e = 1, m%nc + m%nf
      do s = 1, NLOC
        c = slot(e, s)
        if (c == 0) cycle
        do i = 1, NLOC
          if (.not. pair(e, s, i)) cycle
          w%krow(nxt(c)) = slot(e, i)
          nxt(c) = nxt(c) + 1
        end do
      end do
    end do
    ! dedupe in place, column by column
    allocate (w%kptr(n + 1), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(4 * real(n, wp), 'the pattern of the tangent stiffness', &
                    'use a smaller model', status, msg)
      return
    end if
    mark = 0
    nnz = 0
    do c = 1, n
      w%kptr(c) = nnz + 1
      do p = cnt(c), cnt(c + 1) - 1
        i = w%krow(p)
        if (mark(i) == c) cycle
        mark(i) = c
        nnz = nnz + 1
        w%krow(nnz) = i
      end do
    end do
    w%kptr(n + 1) = nnz + 1
    ! greedy distance-2 colouring (K is structurally symmetric: row i's columns are column
    ! i's rows)
    color = 0
    mark = 0
    w%ncolor = 0
    do c = 1, n
      do p = w%kptr(c), w%kptr(c + 1) - 1
        i = w%krow(p)
        do pp = w%kptr(i), w%kptr(i + 1) - 1
          if (color(w%krow(pp)) > 0) mark(color(w%krow(pp))) = c
        end do
      end do
      g = 1
      do while (g <= w%ncolor)
        if (mark(g) /= c) exit
        g = g + 1
      end do
      color(c) = g
      w%ncolor = max(w%ncolor, g)
    end do
    allocate (w%gptr(w%ncolor + 1), w%gcol(n), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(8 * real(n, wp), 'the column groups of the tangent stiffness', &
                    'use a smaller model', status, msg)
      return
    end if
    w%gptr = 0
    do c = 1, n
      w%gptr(color(c) + 1) = w%gptr(color(c) + 1) + 1
    end do
    w%gptr(1) = 1
    do g = 1, w%ncolor
      w%gptr(g + 1) = w%gptr(g + 1) + w%gptr(g)
    end do
    nxt(1:w%ncolor) = w%gptr(1:w%ncolor)
    do c = 1, n
      w%gcol(nxt(color(c))) = c
      nxt(color(c)) = nxt(color(c)) + 1
    end do
  contains
    !> Coordinate of slot s of element e (constraints 1..nc, then forces), 0 if none.
    pure integer function slot(e, s)
      integer, intent(in) :: e, s
      if (e <= m%nc) then
        slot = m%loc(s, e)
      else
        slot = m%floc(s, e - m%nc)
      end if
    end function slot

    !> Slots a and b of element e can couple in K: both present; a constraint affine in the
    !! positions with each body's angle apart (con_affine_r: pins, welds, a line fixed in
    !! ground, linear ones) only on each angle with itself (a pin's J^T lambda: lambda on
    !! x, y, lambda . B(theta) s on theta, so d/dq is -lambda . A(theta) s on the theta
    !! diagonal and zero elsewhere).
    pure logical function pair(e, a, b)
      integer, intent(in) :: e, a, b
      pair = slot(e, a) > 0 .and. slot(e, b) > 0
      if (.not. pair .or. e > m%nc) return
      if (con_affine_r(m%kind(e), m%bi(e))) pair = a == b .and. (a == 3 .or. a == 6)
    end function pair
  end subroutine tangent_pattern

  !> The work arrays of contacts and friction (element states, friction solve).
  subroutine alloc_elements(m, w, status, msg)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    integer, intent(out) :: status
    character(len=MSG_LEN), intent(out) :: msg
    integer :: nf, nr, k, j, ist, i, r
    nf = m%nf; nr = m%nfric
    allocate (w%cst(NCS, nf), w%fnl(nf), w%ffr(nf), w%fidx(nr), w%gf(m%nq, nr), &
              w%zf(m%nq + w%na, nr), w%y0(m%nq + w%na), w%gaf(nr), w%amat(nr, nr), &
              w%avec(nr), w%cf(nr), w%dn(2, nr), w%fpiv(nr), w%fpos(2, nr), stat=ist)
    status = MBD_OK; msg = ''
    if (ist /= 0) then
      call mem_fail(REAL_BYTES * (real(nr, wp) * (2 * m%nq + w%na + nr + 8) + 4 * nf), &
                    'the contact and friction arrays', DYN_HINT, status, msg)
      return
    end if
    w%cst = zero; w%fnl = zero; w%ffr = zero
    do k = 1, nf
      if (force_is_contact(m%fkind(k))) w%cst(1, k) = MODE_UNTRACKED
    end do
    j = 0
    do k = 1, nf
      if (m%fkind(k) == FRC_FRICTION) then
        j = j + 1; w%fidx(j) = k
        w%fpos(:, j) = 0
        do i = 1, 2
          do r = 1, w%na
            if (w%rows(r) == m%row0(m%fref(k)) + i - 1) w%fpos(i, j) = r
          end do
        end do
      end if
    end do
  end subroutine alloc_elements

  !> The local state of force element k (its slots' coordinates and velocities).
  pure function element_state(m, k, q, qd) result(x)
    type(model_t), intent(in) :: m        !! model
    integer, intent(in) :: k              !! force element
    real(wp), intent(in) :: q(:), qd(:)   !! state
    type(kloc) :: x
    real(wp) :: ql(NLOC), qdl(NLOC)
    integer :: s
    do s = 1, NLOC
      ql(s) = zero; qdl(s) = zero
      if (m%floc(s, k) > 0) then
        ql(s) = q(m%floc(s, k)); qdl(s) = qd(m%floc(s, k))
      end if
    end do
    x = local_state(ql, qdl)
  end function element_state

  !> Slip coordinate of joint friction element k (mbd_contact joint_slip).
  pure function element_slip(m, k, x) result(u)
    type(model_t), intent(in) :: m
    integer, intent(in) :: k
    type(kloc), intent(in) :: x
    type(kscal) :: u
    integer :: jc, o
    jc = m%fref(k); o = m%fpo(k)
    u = joint_slip(m%kind(jc) == CON_REVOLUTE, m%p(m%po(jc):m%po(jc) + m%pn(jc) - 1), &
                   m%fp(o + 4), merge(1, 0, m%fbi(k) > 0), merge(2, 0, m%fbj(k) > 0), x)
  end function element_slip

  !> Add the joint friction forces at multipliers lam to force (elements not stuck; mode
  !! from cst, regularized without it); fnl, ffr return each element's normal load and
  !! friction force.
  pure subroutine friction_forces(m, q, qd, lam, force, cst, fnl, ffr)
    type(model_t), intent(in) :: m              !! model
    real(wp), intent(in) :: q(:), qd(:)         !! state
    real(wp), intent(in) :: lam(:)              !! multipliers (neq)
    real(wp), intent(inout) :: force(:)         !! Q (nq), friction added
    real(wp), intent(in), optional :: cst(:, :) !! element states
    real(wp), intent(inout), optional :: fnl(:), ffr(:)  !! (nf) loads and forces
    type(kloc) :: x
    type(kscal) :: u
    real(wp) :: fn, f
    integer :: k, jc, mode, s
    do k = 1, m%nf
      if (m%fkind(k) /= FRC_FRICTION) cycle
      mode = 0
      if (present(cst)) mode = nint(cst(1, k))
      if (mode == MODE_STUCK) cycle
      jc = m%fref(k)
      x = element_state(m, k, q, qd)
      u = element_slip(m, k, x)
      fn = joint_normal_load(m%kind(jc) == CON_REVOLUTE, lam(m%row0(jc):m%row0(jc) + 1))
      f = joint_friction_force(m%fp(m%fpo(k):m%fpo(k) + 4), mode, u%vd, fn)
      do s = 1, NLOC
        if (m%floc(s, k) > 0) force(m%floc(s, k)) = force(m%floc(s, k)) + f * u%d(s)
      end do
      if (present(fnl)) fnl(k) = fn
      if (present(ffr)) ffr(k) = f
    end do
  end subroutine friction_forces

  !> Outputs of every force element at a state (core units), eo(NEO, nf): contacts [Fn, Ft,
  !! penetration, sliding speed, contact point]; joint friction [normal load, friction force
  !! along the slip, 0, slip speed, 1 when stuck, friction moment (revolute)] from the last
  !! solve's loads (w%fnl, w%ffr); other elements zero.
  subroutine dyn_element_outputs(m, w, q, qd, t, eo)
    type(model_t), intent(in) :: m              !! model
    type(dyn_work_t), intent(inout) :: w        !! work arrays (states, last loads)
    real(wp), intent(in) :: q(:), qd(:)         !! state
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(out) :: eo(:, :)           !! (NEO, nf)
    real(wp) :: ql(NLOC), qdl(NLOC), fl(NLOC), vk, vl
    type(kloc) :: x
    type(kscal) :: u
    integer :: k, s, jc
    eo = zero
    do k = 1, m%nf
      if (force_is_contact(m%fkind(k))) then
        do s = 1, NLOC
          ql(s) = zero; qdl(s) = zero
          if (m%floc(s, k) > 0) then
            ql(s) = q(m%floc(s, k)); qdl(s) = qd(m%floc(s, k))
          end if
        end do
        call force_eval(m%fkind(k), m%fp(m%fpo(k):m%fpo(k) + m%fpn(k) - 1), &
                        merge(1, 0, m%fbi(k) > 0), merge(2, 0, m%fbj(k) > 0), ql, qdl, t, &
                        fl, vk, vl, st=w%cst(:, k), out=eo(:, k))
      else if (m%fkind(k) == FRC_FRICTION) then
        jc = m%fref(k)
        x = element_state(m, k, q, qd)
        u = element_slip(m, k, x)
        eo(1, k) = w%fnl(k); eo(2, k) = w%ffr(k); eo(4, k) = u%vd
        if (nint(w%cst(1, k)) == MODE_STUCK) eo(5, k) = one
        if (m%kind(jc) == CON_REVOLUTE) eo(6, k) = w%ffr(k) * m%fp(m%fpo(k) + 4)
      end if
    end do
  end subroutine dyn_element_outputs

  !> Applied generalized forces Q(q, q_dot, t) and the potential energy V (gravity, springs,
  !! contacts); vload adds the potential of the loads frozen at t (statics). Contacts read
  !! their states cst (absent: open); joint friction is added only when the multipliers lam
  !! are given (friction_forces).
  pure subroutine gen_forces(m, q, qd, t, force, v, vload, cst, lam, fmag)
    type(model_t), intent(in) :: m        !! model
    real(wp), intent(in) :: q(:), qd(:)   !! state
    real(wp), intent(in) :: t             !! time
    real(wp), intent(out) :: force(:)     !! Q (nq)
    real(wp), intent(out) :: v            !! potential energy
    real(wp), intent(out), optional :: vload  !! potential of the loads at t
    real(wp), intent(in), optional :: cst(:, :)  !! element states (NCS, nf)
    real(wp), intent(in), optional :: lam(:)     !! multipliers: add joint friction
    !> the largest generalized force of one element or weight (a scale of the loads, which
    !! may cancel in Q: a body resting on a contact)
    real(wp), intent(out), optional :: fmag
    real(wp) :: ql(NLOC), qdl(NLOC), fl(NLOC), vk, vl, vls, fm
    integer :: k, s, si, sj
    force = zero; v = zero; vls = zero; fm = zero
    do k = 1, m%nb
      force(3 * k - 2:3 * k - 1) = m%mdiag(3 * k - 2) * m%grav
      v = v - m%mdiag(3 * k - 2) * dot_product(m%grav, q(3 * k - 2:3 * k - 1))
    end do
    do k = 1, m%nf
      if (m%fkind(k) == FRC_FRICTION) cycle
      do s = 1, NLOC
        ql(s) = zero; qdl(s) = zero
        if (m%floc(s, k) > 0) then
          ql(s) = q(m%floc(s, k)); qdl(s) = qd(m%floc(s, k))
        end if
      end do
      si = merge(1, 0, m%fbi(k) > 0); sj = merge(2, 0, m%fbj(k) > 0)
      if (present(cst)) then
        call force_eval(m%fkind(k), m%fp(m%fpo(k):m%fpo(k) + m%fpn(k) - 1), si, sj, ql, qdl, &
                        t, fl, vk, vl, st=cst(:, k))
      else
        call force_eval(m%fkind(k), m%fp(m%fpo(k):m%fpo(k) + m%fpn(k) - 1), si, sj, ql, qdl, &
                        t, fl, vk, vl)
      end if
      do s = 1, NLOC
        if (m%floc(s, k) > 0) force(m%floc(s, k)) = force(m%floc(s, k)) + fl(s)
      end do
      fm = max(fm, maxval(abs(fl)))
      v = v + vk; vls = vls + vl
    end do
    if (present(vload)) vload = vls
    if (present(fmag)) fmag = max(fm, maxval(abs(force)))
    if (present(lam) .and. m%nfric > 0) call friction_forces(m, q, qd, lam, force, cst)
  end subroutine gen_forces

  !> T = q_dot^T M q_dot / 2.
  pure real(wp) function kinetic_energy(m, qd)
    type(model_t), intent(in) :: m      !! model
    real(wp), intent(in) :: qd(:)       !! velocities
    kinetic_energy = half * sum(m%mdiag * qd**2)
  end function kinetic_energy

  !> Factor [M s Ja^T; s Ja 0] (the diagonal metric, Ja = J(rows) from the blocks of the
  !! last assembly). Nearly singular: w%lsq is set and the solves are least squares.
  subroutine factor_aug(w, metric, status, exact)
    type(dyn_work_t), intent(inout) :: w
    real(wp), intent(in) :: metric(:)     ! diagonal of the upper-left block
    integer, intent(out) :: status
    !> no index-1 check: the plain factorization (the active rows independent by their
    !! choice, so the matrix is regular however ill-conditioned; the check's regularized
    !! least squares would bend the multipliers: a long chain's motor torque 98% off at
    !! 6603 coordinates, where the condition estimate passed 1e9)
    logical, intent(in), optional :: exact
    logical :: chk
    chk = .true.
    if (present(exact)) chk = .not. exact
    ! (exact: the Schur complement where it is well conditioned, else the plain LU)
    call saddle_factor(w%sd, metric, w%asm%jb, w%s, status, check=chk, schur=.not. chk)
    w%nsolve = w%nsolve + 1
    w%lsq = w%sd%lsq
  end subroutine factor_aug

  !> Another right-hand side with the last augmented matrix (Baumgarte's modified gamma).
  subroutine dyn_solve(w, rhs, status)
    type(dyn_work_t), intent(inout) :: w     !! work arrays with the last augmented matrix
    real(wp), intent(inout) :: rhs(:)        !! right-hand side, then solution
    integer, intent(out) :: status           !! MBD_OK or MBD_LAPACK
    call saddle_solve(w%sd, rhs, status)
    if (w%sd%lsq) w%nrank = w%nrank + 1
  end subroutine dyn_solve

  !> Several right-hand sides (ncol of them) with the last augmented matrix, as the rows of
  !! bt (4 k, nt): the first nkeep entries of each solution as a row of xt (ldt, nkeep),
  !! written or (add) added (saddle_solve_rows; w%rhs its work).
  subroutine dyn_solve_rows(w, bt, ncol, nkeep, ldt, xt, add, status)
    type(dyn_work_t), intent(inout) :: w     !! work arrays with the last augmented matrix
    real(wp), intent(in) :: bt(:, :)         !! right-hand sides as rows
    integer, intent(in) :: ncol, nkeep, ldt  !! right-hand sides, entries kept, xt's rows
    real(wp), intent(inout) :: xt(ldt, *)    !! solutions as rows
    logical, intent(in) :: add               !! add to xt (else overwrite)
    integer, intent(out) :: status           !! MBD_OK or MBD_LAPACK
    call saddle_solve_rows(w%sd, bt, ncol, nkeep, ldt, xt, add, w%rhs, status)
    if (w%sd%lsq) w%nrank = w%nrank + ncol
  end subroutine dyn_solve_rows

  !> Phi, nu, gamma and the constraint blocks at (q, q_dot, t); the dense J too on the
  !! dense path.
  subroutine assemble(m, w, q, qd, t)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    real(wp), intent(in) :: q(:), qd(:), t
    if (w%solver == SOLVER_DENSE) then
      call assemble_dense(m, q, qd, t, w%phi, w%nu, w%gam, w%asm, w%jac)
    else
      call assemble_blocks(m, q, qd, t, w%phi, w%nu, w%gam, w%asm)
    end if
  end subroutine assemble

  !> w%jv = J x from the blocks of the last assembly (all rows).
  subroutine dyn_jv(m, w, x)
    type(model_t), intent(in) :: m           !! model
    type(dyn_work_t), intent(inout) :: w     !! work arrays (blocks assembled)
    real(wp), intent(in) :: x(:)             !! vector (nq)
    call blocks_jv(m, w%asm, x, w%jv)
  end subroutine dyn_jv

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
    if (m%nfric > 0) then
      call assemble(m, w, q, qd, t)       ! (friction's least squares takes the dense J)
    else                                  ! the blocks are all the factorization takes
      call assemble_blocks(m, q, qd, t, w%phi, w%nu, w%gam, w%asm)
    end if
    call gen_forces(m, q, qd, t, w%force, v, cst=w%cst)
    call factor_aug(w, m%mdiag, status)
    if (status /= MBD_OK) return
    w%rhs(1:n) = w%force
    call gather_rows(w, w%gam, w%s)
    call dyn_solve(w, w%rhs, status)
    if (status /= MBD_OK) return
    if (m%nfric > 0) then
      call friction_solve(m, w, q, qd, status)
      if (status /= MBD_OK) return
    end if
    qdd = w%rhs(1:n)
    lam = zero
    do k = 1, w%na                 ! (loops: vector subscripts make heap temporaries)
      lam(w%rows(k)) = w%s * w%rhs(n + k)
    end do
  end subroutine dyn_accel

  !> The joint friction forces with the factored augmented matrix (see the banner): on entry
  !! w%rhs holds y0 (the solution without joint friction), on return the solution with it;
  !! w%force gains the friction forces, w%fnl and w%ffr the loads and forces. An iteration
  !! on the directions of the normal loads that does not settle is MBD_NO_CONVERGENCE (a
  !! self-locking joint: the friction cannot be resolved, Painleve's paradox).
  subroutine friction_solve(m, w, q, qd, status)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    real(wp), intent(in) :: q(:), qd(:)
    integer, intent(out) :: status
    real(wp) :: lamb(2), nr
    integer :: b, k, n, jc, nb
    logical :: settled
    n = m%nq; nb = m%nfric
    status = MBD_OK
    w%locked = .false.
    w%y0 = w%rhs
    ! directions g_b, lock right-hand sides, responses z_b = A^-1 [g_b; 0]
    do b = 1, nb
      call fric_direction(m, w, b, q, qd)
      w%zf(1:n, b) = w%gf(:, b); w%zf(n + 1:, b) = zero
      call dyn_solve(w, w%zf(:, b), status)
      if (status /= MBD_OK) return
      ! the starting direction of grad N from the frictionless multipliers
      w%dn(:, b) = fric_grad(m, w, b, w%y0)
    end do
    call fric_amplitudes(m, w, .true., settled, status)
    if (status /= MBD_OK .or. .not. settled) then
      w%locked = .true.
      status = MBD_NO_CONVERGENCE; return
    end if
    do b = 1, nb
      k = w%fidx(b); jc = m%fref(k)
      lamb = fric_lam(w, b, w%rhs)
      nr = joint_normal_load(m%kind(jc) == CON_REVOLUTE, lamb)
      w%fnl(k) = nr; w%ffr(k) = w%avec(b)
      w%force = w%force + w%avec(b) * w%gf(:, b)
    end do
  end subroutine friction_solve

  !> The friction amplitudes a (w%avec) and the solution x = y0 + sum_b a_b z_b (w%rhs) from
  !! w%y0, the responses w%zf, w%cf, w%gf, w%gaf and the starting directions w%dn of grad N,
  !! the directions iterated to FRIC_MAXIT: a sliding joint's row a_b - c_b grad N_b .
  !! lambda_b(x) = 0; a stuck one's, with lock, its lock g_b . q_ddot(x) = -u_ar (a_b its
  !! force), else a_b = 0 (its force a known load). status MBD_SINGULAR when the small
  !! system is; settled when the directions settled.
  subroutine fric_amplitudes(m, w, lock, settled, status)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    logical, intent(in) :: lock
    logical, intent(out) :: settled
    integer, intent(out) :: status
    real(wp) :: dnew(2)
    integer :: b, d, it, n, nb
    n = m%nq; nb = m%nfric
    settled = .false.
    status = MBD_OK
    do it = 1, FRIC_MAXIT
      do b = 1, nb
        if (nint(w%cst(1, w%fidx(b))) /= MODE_STUCK) then
          do d = 1, nb
            w%amat(b, d) = -w%cf(b) * dot_product(w%dn(:, b), fric_lam(w, b, w%zf(:, d)))
          end do
          w%amat(b, b) = w%amat(b, b) + one
          w%avec(b) = w%cf(b) * dot_product(w%dn(:, b), fric_lam(w, b, w%y0))
        else if (lock) then
          do d = 1, nb
            w%amat(b, d) = dot_product(w%gf(:, b), w%zf(1:n, d))
          end do
          w%avec(b) = w%gaf(b) - dot_product(w%gf(:, b), w%y0(1:n))
        else
          w%amat(b, :) = zero; w%amat(b, b) = one; w%avec(b) = zero
        end if
      end do
      call lu_factor_small(w%amat, w%fpiv, status)
      if (status /= MBD_OK) return
      call lu_solve_small(w%amat, w%fpiv, w%avec)
      w%rhs = w%y0
      do d = 1, nb
        w%rhs = w%rhs + w%avec(d) * w%zf(:, d)
      end do
      ! the directions of the normal loads at the new multipliers
      settled = .true.
      do b = 1, nb
        dnew = fric_grad(m, w, b, w%rhs)
        if (maxval(abs(dnew - w%dn(:, b))) > 1.0e-12_wp) settled = .false.
        w%dn(:, b) = dnew
      end do
      if (settled) exit
    end do
  end subroutine fric_amplitudes

  !> Friction element b's slip direction g_b = du/dq (w%gf(:, b)), its lock's right-hand
  !! side -u_ar (w%gaf(b)) and its coefficient c_b in a_b = c_b N_b (w%cf(b)): -mu(u_dot)
  !! regularized, -mu sign sliding, 0 stuck.
  subroutine fric_direction(m, w, b, q, qd)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    integer, intent(in) :: b
    real(wp), intent(in) :: q(:), qd(:)
    type(kloc) :: x
    type(kscal) :: u
    integer :: k, s, mode
    k = w%fidx(b)
    x = element_state(m, k, q, qd)
    u = element_slip(m, k, x)
    w%gf(:, b) = zero
    do s = 1, NLOC
      if (m%floc(s, k) > 0) w%gf(m%floc(s, k), b) = w%gf(m%floc(s, k), b) + u%d(s)
    end do
    w%gaf(b) = -u%ar
    mode = nint(w%cst(1, k))
    if (mode == 0) then
      w%cf(b) = -reg_mu(u%vd, m%fp(m%fpo(k)), m%fp(m%fpo(k) + 1), m%fp(m%fpo(k) + 3))
    else if (mode /= MODE_STUCK) then
      w%cf(b) = -m%fp(m%fpo(k)) * mode
    else
      w%cf(b) = zero
    end if
  end subroutine fric_direction

  !> The multipliers (2) of friction element b's joint from a solution vector xs of the
  !! augmented system (zero on rows not active).
  pure function fric_lam(w, b, xs) result(l)
    type(dyn_work_t), intent(in) :: w
    integer, intent(in) :: b
    real(wp), intent(in) :: xs(:)
    real(wp) :: l(2)
    integer :: i
    l = zero
    do i = 1, 2
      if (w%fpos(i, b) > 0) l(i) = w%s * xs(w%n + w%fpos(i, b))
    end do
  end function fric_lam

  !> grad N of friction element b at its joint's multipliers l: revolute l / |l| (the
  !! friction circle), translational (sign(l_1), 0).
  pure function fric_dir(m, w, b, l) result(g)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(in) :: w
    integer, intent(in) :: b
    real(wp), intent(in) :: l(2)
    real(wp) :: g(2), a
    g = zero
    if (m%kind(m%fref(w%fidx(b))) == CON_REVOLUTE) then
      a = hypot(l(1), l(2))
      if (a > zero) g = l / a
    else
      if (l(1) > zero) g(1) = one
      if (l(1) < zero) g(1) = -one
    end if
  end function fric_dir

  !> grad N of friction element b at the multipliers of a solution vector xs.
  pure function fric_grad(m, w, b, xs) result(g)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(in) :: w
    integer, intent(in) :: b
    real(wp), intent(in) :: xs(:)
    real(wp) :: g(2)
    g = fric_dir(m, w, b, fric_lam(w, b, xs))
  end function fric_grad

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

  !> Assemble at q and factor the matrix of a projection, s [D J^T; J 0] (active rows) with
  !! D = I (minimum-norm changes, as dyn_project_pos) or, with kinetic, D = M (massless
  !! coordinates: the unit metric, as dyn_velocity); dyn_solve then solves with it and
  !! w%jv = J x comes from dyn_jv (the blocks are assembled).
  subroutine dyn_factor_projection(m, w, q, t, kinetic, status, assembled)
    type(model_t), intent(in) :: m           !! model
    type(dyn_work_t), intent(inout) :: w     !! work arrays
    real(wp), intent(in) :: q(:)             !! configuration
    real(wp), intent(in) :: t                !! time
    logical, intent(in) :: kinetic           !! D = M (else the identity)
    integer, intent(out) :: status           !! MBD_OK or MBD_SINGULAR
    logical, intent(in), optional :: assembled  !! the blocks are already those at (q, t)
    if (kinetic) then
      w%metric = merge(m%mdiag, w%s, m%mdiag > zero)
    else
      w%metric = w%s
    end if
    if (.not. present(assembled)) then
      call assemble(m, w, q, w%qz, t)
    else if (.not. assembled) then
      call assemble(m, w, q, w%qz, t)
    end if
    call factor_aug(w, w%metric, status)
  end subroutine dyn_factor_projection

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
    call dyn_factor_projection(m, w, q, t, .true., status)
    if (status /= MBD_OK) return
    w%rhs(1:n) = w%metric * v0
    call gather_rows(w, w%nu, w%s)
    call dyn_solve(w, w%rhs, status)
    qd = w%rhs(1:n)
  end subroutine dyn_velocity

  !> Project q onto Phi(q, t) = 0 by minimum-norm Newton steps:
  !! s [I J^T; J 0][dq; mu] = [0; -s Phi] (active rows; the factor s, the constraint scale,
  !! keeps the matrix as well scaled as the index-1 ones), to ||Phi||_inf <= w%tol.
  subroutine dyn_project_pos(m, w, q, t, status)
    type(model_t), intent(in) :: m           !! model
    type(dyn_work_t), intent(inout) :: w     !! work arrays
    real(wp), intent(inout) :: q(:)          !! configuration, projected
    real(wp), intent(in) :: t                !! time
    integer, intent(out) :: status           !! MBD_OK, MBD_NO_CONVERGENCE or MBD_SINGULAR
    integer :: it, n
    n = m%nq
    do it = 1, 20
      call assemble(m, w, q, w%qz, t)
      status = MBD_OK
      if (maxval(abs(w%phi)) <= w%tol) return
      call dyn_factor_projection(m, w, q, t, .false., status, assembled=.true.)
      if (status /= MBD_OK) return
      w%rhs(1:n) = zero
      call gather_rows(w, w%phi, -w%s)
      call dyn_solve(w, w%rhs, status)
      q = q + w%rhs(1:n)
    end do
    status = MBD_NO_CONVERGENCE
  end subroutine dyn_project_pos

  !> Minimum-norm multipliers over all rows: lambda = argmin ||l|| with J^T l = Q - M q_ddot.
  !! With independent rows this is the unique lambda (Householder least squares, ls_small);
  !! with redundant rows, or J^T numerically rank deficient, the reactions are statically
  !! indeterminate and this is the smallest set (LAPACK dgelsy). Band path: the least-squares
  !! lambda of the active rows (band_multipliers), zero on the redundant rows.
  !! Joint friction (not stuck) depends on lambda: with the directions of the normal loads
  !! fixed it is linear, J^T l - sum_b g_b c_b grad N_b . l_b = Q - M q_ddot, and the
  !! directions are iterated; a stuck joint's friction is the last solve's (w%ffr).
  subroutine dyn_multipliers(m, w, q, qd, qdd, t, lam, status, msg)
    type(model_t), intent(in) :: m            !! model
    type(dyn_work_t), intent(inout) :: w      !! work arrays
    real(wp), intent(in) :: q(:), qd(:), qdd(:)  !! state and accelerations
    real(wp), intent(in) :: t                 !! time
    real(wp), intent(out) :: lam(:)           !! multipliers (neq)
    integer, intent(out) :: status            !! MBD_OK, MBD_LAPACK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg  !! explanation
    real(wp) :: v, rhs0(m%nq), dn(2, max(1, m%nfric)), dnew(2), fn
    integer :: it, bb, k, jc
    logical :: settled
    msg = ''
    w%jt_lu = .false.
    call assemble(m, w, q, qd, t)
    call gen_forces(m, q, qd, t, w%force, v, cst=w%cst)
    rhs0 = w%force - m%mdiag * qdd
    ! the friction directions; stuck joints: their last friction force is a known load
    do bb = 1, m%nfric
      call fric_direction(m, w, bb, q, qd)
      k = w%fidx(bb)
      if (nint(w%cst(1, k)) == MODE_STUCK) rhs0 = rhs0 + w%ffr(k) * w%gf(:, bb)
    end do
    if (w%solver == SOLVER_BANDED) then
      call band_multipliers(m, w, rhs0, lam, status, msg)
      return
    end if
    w%jt = transpose(w%jac)
    call solve_ls(lam, status)
    if (status /= MBD_OK .or. m%nfric == 0) return
    dn = zero
    do bb = 1, m%nfric
      dn(:, bb) = grad_dir(bb, lam)
    end do
    do it = 1, FRIC_MAXIT
      w%jt = transpose(w%jac)
      do bb = 1, m%nfric
        k = w%fidx(bb); jc = m%fref(k)
        if (nint(w%cst(1, k)) == MODE_STUCK) cycle
        ! J^T l - g_b c_b grad N_b . l_b: the joint's two columns
        w%jt(:, m%row0(jc)) = w%jt(:, m%row0(jc)) - w%cf(bb) * dn(1, bb) * w%gf(:, bb)
        w%jt(:, m%row0(jc) + 1) = w%jt(:, m%row0(jc) + 1) - w%cf(bb) * dn(2, bb) * w%gf(:, bb)
      end do
      call solve_ls(lam, status)
      if (status /= MBD_OK) return
      settled = .true.
      do bb = 1, m%nfric
        dnew = grad_dir(bb, lam)
        if (maxval(abs(dnew - dn(:, bb))) > 1.0e-12_wp) settled = .false.
        dn(:, bb) = dnew
      end do
      if (settled) exit
    end do
    do bb = 1, m%nfric
      k = w%fidx(bb); jc = m%fref(k)
      fn = joint_normal_load(m%kind(jc) == CON_REVOLUTE, lam(m%row0(jc):m%row0(jc) + 1))
      w%fnl(k) = fn
      if (nint(w%cst(1, k)) /= MODE_STUCK) w%ffr(k) = w%cf(bb) * fn
    end do
  contains
    !> lambda from w%jt (destroyed) and rhs0.
    subroutine solve_ls(l, st)
      real(wp), intent(out) :: l(:)
      integer, intent(out) :: st
      real(wp) :: wq(1)
      real(wp), allocatable :: work(:)
      integer :: rank, info, lwork, ierr
      logical :: full
      st = MBD_OK
      w%bls = zero
      w%bls(1:m%nq) = rhs0
      if (w%na == m%neq .and. m%neq == m%nq) then
        ! square J of independent rows (a driven mechanism): J^T lambda = r by an LU of J^T
        ! with partial pivoting, a quarter of the QR's work, trusted when its pivot ratio is
        ! above the QR's rank threshold (otherwise the QR, then dgelsy, as below)
        w%acopy(1:m%nq, 1:m%neq) = w%jt
        call lu_factor_small(w%acopy, w%jpvt, st)
        if (st == MBD_OK) then
          if (diag_ratio(w%acopy) >= LS_RTOL) then
            call lu_solve_small(w%acopy, w%jpvt, w%bls(1:m%nq))
            w%jt_lu = m%nfric == 0
            l = w%bls(1:m%neq); return
          end if
        end if
        st = MBD_OK
      end if
      if (w%na == m%neq .and. m%neq <= m%nq) then
        ! independent rows: the unique solution, by a plain Householder QR (no allocation);
        ! ls_small spoils w%jt, which is rebuilt by the caller for the next solve
        w%acopy(1:m%nq, 1:m%neq) = w%jt
        call ls_small(w%jt, w%bls, full)
        if (full) then
          l = w%bls(1:m%neq); return
        end if
        w%jt = w%acopy(1:m%nq, 1:m%neq)
        w%bls = zero
        w%bls(1:m%nq) = rhs0
      end if
      w%jpvt = 0
      call dgelsy(m%nq, m%neq, 1, w%jt, m%nq, w%bls, size(w%bls), w%jpvt, 1.0e-10_wp, rank, &
                  wq, -1, info)
      lwork = max(1, int(wq(1)))
      allocate (work(lwork), stat=ierr)
      if (ierr /= 0) then
        l = zero
        call mem_fail(REAL_BYTES * lwork, 'the least-squares multipliers', &
                      'use a smaller model', st, msg)
        return
      end if
      call dgelsy(m%nq, m%neq, 1, w%jt, m%nq, w%bls, size(w%bls), w%jpvt, 1.0e-10_wp, rank, &
                  work, lwork, info)
      call lapack_status('dgelsy', info, st, msg)
      l = w%bls(1:m%neq)
    end subroutine solve_ls
    !> min |a_kk| / max |a_kk| of square LU factors.
    pure real(wp) function diag_ratio(a) result(r)
      real(wp), intent(in) :: a(:, :)
      integer :: k
      real(wp) :: amin, amax
      amin = huge(one); amax = zero
      do k = 1, size(a, 1)
        amin = min(amin, abs(a(k, k))); amax = max(amax, abs(a(k, k)))
      end do
      r = zero
      if (amax > zero) r = amin / amax
    end function diag_ratio
    !> grad N of friction element bx at multipliers l (all rows).
    function grad_dir(bx, l) result(g)
      integer, intent(in) :: bx
      real(wp), intent(in) :: l(:)
      real(wp) :: g(2)
      integer :: j0
      j0 = m%row0(m%fref(w%fidx(bx)))
      g = fric_dir(m, w, bx, l(j0:j0 + 1))
    end function grad_dir
  end subroutine dyn_multipliers

  !> The band path of dyn_multipliers: the least-squares multipliers of the active rows,
  !! [s I, s Ja^T; s Ja, 0][x; lambda_a / s] = [r; 0] (x the part of the load r no
  !! multiplier balances), zero on the redundant rows. Joint friction not stuck as in
  !! friction_solve with this matrix: x = y0 + sum_b a_b z_b, [s I, s Ja^T; s Ja, 0] z_b =
  !! [g_b; 0], a_b = c_b grad N_b . lambda_b(x), the directions of grad N iterated.
  subroutine band_multipliers(m, w, rhs0, lam, status, msg)
    type(model_t), intent(in) :: m              !! model
    type(dyn_work_t), intent(inout) :: w        !! work arrays (friction directions set)
    real(wp), intent(in) :: rhs0(:)             !! load r = Q - M q_ddot (+ stuck friction)
    real(wp), intent(out) :: lam(:)             !! multipliers (neq)
    integer, intent(out) :: status              !! MBD_OK, MBD_SINGULAR or MBD_LAPACK
    character(len=MSG_LEN), intent(inout) :: msg  !! explanation
    integer :: n, k, b, nb
    logical :: settled
    n = m%nq; nb = m%nfric
    lam = zero
    w%metric = w%s
    call factor_aug(w, w%metric, status, exact=.true.)
    if (status /= MBD_OK) then
      msg = 'the multipliers: the band saddle-point matrix is singular'; return
    end if
    w%rhs(1:n) = rhs0
    w%rhs(n + 1:) = zero
    call dyn_solve(w, w%rhs, status)
    if (status /= MBD_OK) return
    if (nb > 0) then
      w%y0 = w%rhs
      do b = 1, nb
        w%zf(:, b) = zero
        if (stuck(b)) cycle
        w%zf(1:n, b) = w%gf(:, b)
        call dyn_solve(w, w%zf(:, b), status)
        if (status /= MBD_OK) return
        w%dn(:, b) = fric_grad(m, w, b, w%y0)
      end do
      call fric_amplitudes(m, w, .false., settled, status)
      if (status /= MBD_OK) then
        status = MBD_NO_CONVERGENCE
        msg = 'the multipliers: the joint friction cannot be resolved (self-locking)'
        return
      end if
      do b = 1, nb
        k = w%fidx(b)
        w%fnl(k) = joint_normal_load(m%kind(m%fref(k)) == CON_REVOLUTE, fric_lam(w, b, w%rhs))
        if (.not. stuck(b)) w%ffr(k) = w%avec(b)
      end do
    end if
    do k = 1, w%na
      lam(w%rows(k)) = w%s * w%rhs(n + k)
    end do
  contains
    pure logical function stuck(bb)
      integer, intent(in) :: bb
      stuck = nint(w%cst(1, w%fidx(bb))) == MODE_STUCK
    end function stuck
  end subroutine band_multipliers

  !> An orthonormal basis nb (nq x ni, ni = nq - na) of the null space of J_a at q: the
  !! projections x = r - D^2 J_a^T (J_a D^2 J_a^T)^-1 J_a r of ni fixed pseudo-random
  !! vectors r, each a solve [s D^-2, s J_a^T; s J_a, 0][x; mu] = [s D^-2 r; 0] (D = the
  !! inverse column norms of J_a, so that J_a D is well scaled: in the units of a long
  !! chain's length scale a body angle's column is small) with one factorization on the path
  !! of w, refined twice with the residual from the blocks, then orthonormalized by
  !! Gram-Schmidt against the columns before it (twice where the first pass cancels more
  !! than 1 - 1/sqrt(2) of the norm). The vectors r are one xorshift64
  !! stream (Marsaglia 2003: nonlinear over the reals, so no lattice among them; the linear
  !! congruential vectors seeded k apart used before were affine in k modulo 2^31, and on
  !! the free coordinates of a 60-block chain exactly dependent: no basis, no modes); a
  !! projection that keeps less than KEEP of its norm after Gram-Schmidt (its component in
  !! the new direction too small for J_a x = 0 to hold to round-off once it is scaled up) is
  !! replaced by the stream's next vector, at most MAX_DRAWS times. The span is that of P, so
  !! whatever uses only P = nb nb^T (the partitioned method's choice of coordinates) does not
  !! depend on the vectors r. status MBD_SINGULAR when no draw gives a new direction.
  subroutine dyn_null_basis(m, w, q, t, nb, status)
    type(model_t), intent(in) :: m           !! model
    type(dyn_work_t), intent(inout) :: w     !! work arrays
    real(wp), intent(in) :: q(:)             !! configuration
    real(wp), intent(in) :: t                !! time
    real(wp), intent(out) :: nb(:, :)        !! basis (nq, ni)
    integer, intent(out) :: status           !! MBD_OK or MBD_SINGULAR
    !> a projection's norm kept after Gram-Schmidt, at least (else the next draw)
    real(wp), parameter :: KEEP = 1.0e-3_wp
    integer, parameter :: MAX_DRAWS = 16         !! draws per column
    real(wp), parameter :: REORTH = 0.7071067811865476_wp  !! a second pass below this
    integer(int64) :: x                          ! xorshift64 state
    integer :: n, k, i, j, pass, draw
    real(wp) :: d, nrm0, nrm
    n = m%nq
    call assemble(m, w, q, w%qz, t)
    ! metric s D^-2 with D = 1 / |column of J_a|: J_a D has unit columns (a body angle's
    ! column holds lengths, small in units of a long chain's length scale)
    w%metric = zero
    do k = 1, m%nc
      do i = 1, NLOC
        j = m%loc(i, k)
        if (j == 0) cycle
        do pass = 1, m%nrow(k)
          if (arow_active(m%row0(k) + pass - 1)) w%metric(j) = w%metric(j) + &
            w%asm%jb(pass, i, k)**2
        end do
      end do
    end do
    ! a column of round-off size is an empty one (a pendulum's rod through its lowest point:
    ! the x column 1e-17; as a weight it made the matrix singular)
    d = maxval(w%metric(1:n))
    do i = 1, n
      if (.not. w%metric(i) > 1.0e-16_wp * d) w%metric(i) = one
      w%metric(i) = w%s * w%metric(i)
    end do
    call factor_aug(w, w%metric, status)
    if (status /= MBD_OK) return
    x = 88172645463325252_int64                    ! (Marsaglia's seed: a fixed stream)
    do k = 1, size(nb, 2)
      do draw = 1, MAX_DRAWS
        do i = 1, n                                  ! r in [-1, 1), 53 bits
          x = ieor(x, ishft(x, 13)); x = ieor(x, ishft(x, -7)); x = ieor(x, ishft(x, 17))
          w%rhs(i) = w%metric(i) * (real(ishft(x, -11), wp) * 2.0_wp**(-52) - one)
        end do
        w%rhs(n + 1:) = zero
        w%rsave = w%rhs
        call dyn_solve(w, w%rhs, status)
        if (status /= MBD_OK) return
        do pass = 1, 2                                ! iterative refinement
          call residual(w%rhs, w%rres)
          call dyn_solve(w, w%rres, status)
          if (status /= MBD_OK) return
          w%rhs = w%rhs + w%rres
        end do
        nb(:, k) = w%rhs(1:n)
        nrm0 = norm2(nb(:, k))
        nrm = nrm0
        ! Gram-Schmidt, a second pass only if the first left less than 1/sqrt(2) of the
        ! norm (Daniel, Gragg, Kaufman and Stewart 1976: orthogonal to round-off either way)
        do pass = 1, 2
          do j = 1, k - 1
            d = dot_product(nb(:, j), nb(:, k))
            nb(:, k) = nb(:, k) - d * nb(:, j)
          end do
          d = nrm
          nrm = norm2(nb(:, k))
          if (nrm >= REORTH * d) exit
        end do
        if (nrm > KEEP * nrm0) exit
      end do
      if (.not. nrm > KEEP * nrm0) then
        status = MBD_SINGULAR; return
      end if
      nb(:, k) = nb(:, k) / nrm
    end do
  contains
    !> Row r is active (a binary search in the increasing w%rows).
    logical function arow_active(r)
      integer, intent(in) :: r
      integer :: lo, hi, mid
      arow_active = .false.
      lo = 1; hi = w%na
      do while (lo <= hi)
        mid = (lo + hi) / 2
        if (w%rows(mid) == r) then
          arow_active = .true.; return
        else if (w%rows(mid) < r) then
          lo = mid + 1
        else
          hi = mid - 1
        end if
      end do
    end function arow_active

    !> res = rsave - A z for A = [s D^-2, s J_a^T; s J_a, 0] from the blocks (z = [x; y]).
    subroutine residual(z, res)
      real(wp), intent(in) :: z(:)
      real(wp), intent(out) :: res(:)
      integer :: i
      w%jv = zero
      do i = 1, w%na
        w%jv(w%rows(i)) = z(n + i)
      end do
      call blocks_jtv(m, w%asm, w%jv, w%tr0)         ! J_a^T y
      call blocks_jv(m, w%asm, z(1:n), w%jv)         ! J x
      do i = 1, n
        res(i) = w%rsave(i) - w%metric(i) * z(i) - w%s * w%tr0(i)
      end do
      do i = 1, w%na
        res(n + i) = -w%s * w%jv(w%rows(i))
      end do
    end subroutine residual
  end subroutine dyn_null_basis

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

  !> Tangent matrices of the residual r = J^T lambda - Q by differences, on the pattern of
  !! tangent_pattern: kv(p) = K(krow(p), c) = dr_i/dq_c (the geometric term included), and
  !! cv likewise for C = dr/dq_dot = -dQ/dq_dot. The columns of a group are perturbed
  !! together (one residual per group and side instead of one per column), which gives each
  !! entry exactly as perturbing its column alone. Central differences, or with fast =
  !! .true. forward ones and cv only when a force is damped (otherwise cv = 0): enough for
  !! an iteration matrix, which only steers Newton. Allocation-free.
  subroutine dyn_tangent(m, w, q, qd, t, lam, kv, cv, fast, step)
    type(model_t), intent(in) :: m            !! model
    type(dyn_work_t), intent(inout) :: w      !! work arrays (pattern from dyn_init)
    real(wp), intent(in) :: q(:), qd(:)       !! state
    real(wp), intent(in) :: t                 !! time
    real(wp), intent(in) :: lam(:)            !! multipliers (neq)
    real(wp), intent(out) :: kv(:), cv(:)     !! K and C on the pattern
    logical, intent(in), optional :: fast     !! forward differences, cv only if damped
    !> the central differences' relative step (default 1e-7; eps**(1/3) = 6e-6 balances
    !! their truncation and rounding errors, about 1e-11 relative, where K is needed exactly)
    real(wp), intent(in), optional :: step
    logical :: fwd
    real(wp) :: hrel
    fwd = .false.
    if (present(fast)) fwd = fast
    hrel = 1.0e-7_wp
    if (present(step)) hrel = step
    if (fwd) then
      call residual(q, qd, w%tr0)
      call groups(.true., kv)
      cv = zero
      if (dyn_damped(m)) call groups(.false., cv)
      return
    end if
    call groups(.true., kv)
    call groups(.false., cv)
  contains
    !> One group at a time: perturb its columns of q (wrt_q) or q_dot, difference, scatter.
    subroutine groups(wrt_q, val)
      logical, intent(in) :: wrt_q
      real(wp), intent(out) :: val(:)
      real(wp), parameter :: SQEPS = 1.5e-8_wp  ! ~ sqrt(machine epsilon)
      integer :: g, i, c, p
      if (wrt_q) then
        w%tq = q
      else
        w%tq = qd
      end if
      do g = 1, w%ncolor
        do i = w%gptr(g), w%gptr(g + 1) - 1
          c = w%gcol(i)
          if (fwd) then
            w%th(c) = SQEPS * max(one, abs(w%tq(c)))
          else
            w%th(c) = hrel * max(one, abs(w%tq(c)))
          end if
          w%tq(c) = w%tq(c) + w%th(c)
          if (fwd) w%th(c) = w%tq(c) - merge(q(c), qd(c), wrt_q)   ! the step taken
        end do
        call eval(wrt_q, w%trp)
        if (.not. fwd) then
          do i = w%gptr(g), w%gptr(g + 1) - 1
            c = w%gcol(i)
            w%tq(c) = merge(q(c), qd(c), wrt_q) - w%th(c)
          end do
          call eval(wrt_q, w%trm)
        end if
        do i = w%gptr(g), w%gptr(g + 1) - 1
          c = w%gcol(i)
          w%tq(c) = merge(q(c), qd(c), wrt_q)
          if (fwd) then
            do p = w%kptr(c), w%kptr(c + 1) - 1
              val(p) = (w%trp(w%krow(p)) - w%tr0(w%krow(p))) / w%th(c)
            end do
          else
            do p = w%kptr(c), w%kptr(c + 1) - 1
              val(p) = (w%trp(w%krow(p)) - w%trm(w%krow(p))) / (2 * w%th(c))
            end do
          end if
        end do
      end do
    end subroutine groups

    subroutine eval(wrt_q, r)
      logical, intent(in) :: wrt_q
      real(wp), intent(out) :: r(:)
      if (wrt_q) then
        call residual(w%tq, qd, r)
      else
        call residual(q, w%tq, r)
      end if
    end subroutine eval

    subroutine residual(qa, qda, r)
      real(wp), intent(in) :: qa(:), qda(:)
      real(wp), intent(out) :: r(:)
      real(wp) :: v
      integer :: j
      call assemble_blocks(m, qa, qda, t, w%phi, w%nu, w%gam, w%asm)
      call gen_forces(m, qa, qda, t, w%force, v, cst=w%cst, lam=lam)
      call dyn_jt_lam(m, w%asm%jb, lam, r)
      do j = 1, m%nq
        r(j) = r(j) - w%force(j)
      end do
    end subroutine residual
  end subroutine dyn_tangent

  !> y = A x for A on the pattern of K (w%kptr, w%krow; values av, as dyn_tangent gives them).
  pure subroutine dyn_pattern_mul(w, av, x, y)
    type(dyn_work_t), intent(in) :: w         !! work arrays (pattern from dyn_init)
    real(wp), intent(in) :: av(:)             !! values on the pattern
    real(wp), intent(in) :: x(:)              !! (nq)
    real(wp), intent(out) :: y(:)             !! (nq)
    integer :: j, p
    y = zero
    do j = 1, size(x)
      if (abs(x(j)) <= zero) cycle
      do p = w%kptr(j), w%kptr(j + 1) - 1
        y(w%krow(p)) = y(w%krow(p)) + av(p) * x(j)
      end do
    end do
  end subroutine dyn_pattern_mul

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
        if (m%nrow(k) == 2) then              ! (most joints; the sum of the loop below)
          acc = jb(1, s, k) * lam(r0 + 1) + jb(2, s, k) * lam(r0 + 2)
        else
          acc = zero
          !GCC$ novector
          do i = 1, m%nrow(k)
            acc = acc + jb(i, s, k) * lam(r0 + i)
          end do
        end if
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
      case (FRC_FRICTION)
        dyn_damped = .true.
      case default
        if (force_is_contact(m%fkind(k))) then
          if (contact_damped(m%fp(o:o + m%fpn(k) - 1))) dyn_damped = .true.
        end if
      end select
    end do
  end function dyn_damped

end module mbd_dynamics
