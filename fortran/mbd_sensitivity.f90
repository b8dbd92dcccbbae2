!> mbd_sensitivity: design parameters and the derivatives the sensitivity equations need.
!!
!! A parameter is an entry of one of the flat tables the front end hands over, named in a
!! table ptab(2, np) by (table, index):  1 rpar (a constraint's raw parameter), 2 bmass
!! (flattened (2, nb): mass of body b at 2 b - 1, inertia at 2 b), 3 grav (1 x, 2 y), 4 fpar
!! (a force's raw parameter). sens_setup turns each into the change of the prepared
!! parameter pools (the chain rule through each joint's prepare: axis normalisation, spline
!! coefficients, ...), of the mass matrix and of gravity. Masses, gravity and forces do not
!! enter the kinematics: without dynamics data their columns are zero (and force indices are
!! checked only with the force table).
!!
!! Differentiating Phi(q, t; p) = 0, J q_dot = nu and J q_ddot = gamma along a motion gives,
!! with s = dq/dp (Haug, Computer-Aided Kinematics and Dynamics, sec. 6.5):
!!   J s       = -Phi_p
!!   J s_dot   = nu_p - J_p q_dot - Hv s                           Hv = (J q_dot)_q
!!   J s_ddot  = gamma_p - J_p q_ddot - Ha s - 2 Hv s_dot           Ha = (J q_ddot - gamma)_q
!! (gamma_q_dot = -2 Hv for constraints quadratic in q_dot). Hv and Ha come from the local
!! Hessian of each constraint, hs(:, :, j) = dJ_loc/dq_slot_j, evaluated by dual numbers
!! (mbd_dual) along each slot of the constraint; Phi_p, J_p, nu_p, gamma_p along each
!! parameter's change of the prepared pool. All are local blocks in the layout of J's
!! blocks (MAXROW x NLOC per constraint); products with them go through the slot map.
module mbd_sensitivity
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_BAD_PARAM, MBD_BAD_INPUT, MBD_NO_MEMORY, MSG_LEN
  use mbd_memory, only: zero_fill
  use mbd_points, only: NLOC, MAXROW, kloc, local_state
  use mbd_dual, only: dloc
  use mbd_model, only: model_t, NCT, NFT
  use mbd_constraints, only: con_eval_d, con_prepare_d, con_is_count, con_name, con_linear, &
                             con_affine_r, con_exponents, &
                             CON_TRANSLATIONAL, DRV_REL_DIST, CON_REVOLUTE
  use mbd_joint_revolute, only: revolute_second_sides, revolute_second_rows, revolute_param_sides
  use mbd_joint_translational, only: translational_second, translational_param
  use mbd_forces, only: force_eval_d, force_eval_dm, force_rate_d, force_is_count, &
                        force_exponents, &
                        force_rows_d, FRC_SPRING
  implicit none
  private
  public :: sens_t, PT_RPAR, PT_MASS, PT_GRAV, PT_FPAR
  public :: sens_setup, sens_trig, sens_states, sens_hessian, sens_params, sens_kin_rhs, &
            block_apply, block_apply_t, block_apply_cols, &
            sens_klam, sens_klam_list, sens_jpt_lam, sens_force_d, sens_force_dm, sens_force_jac, &
            sens_force_rows, sens_revolute_rows, sens_translational_rows, sens_rows_rhs, &
            sens_eval_d, sens_force_rate

  integer, parameter :: PT_RPAR = 1, PT_MASS = 2, PT_GRAV = 3, PT_FPAR = 4  !! table ids

  !> The parameters and the work arrays of the sensitivity equations.
  type :: sens_t
    integer :: np = 0                        !! parameters
    integer, allocatable :: ptab(:, :)       !! (2, np) table and index of each
    !> (np) dp'/dp: a nondimensional model (mbd_model) works with p' = p L**e; the
    !! sensitivities the core computes are with respect to p'
    real(wp), allocatable :: pscale(:)
    !> (nq, np) ds/dp = ounit ds'/dp': a sensitivity of q in model units from the core's
    !! (cunit of the row times pscale; kinematics writes its outputs with it)
    real(wp), allocatable :: ounit(:, :)
    real(wp), allocatable :: tp(:, :)        !! (size(m%p), np) change of the prepared pool
    logical, allocatable :: caff(:, :)       !! (nc, np) the constraint's parameters change
    real(wp), allocatable :: tfp(:, :)       !! (size(m%fp), np) change of the force pool
    logical, allocatable :: faff(:, :)       !! (nf, np) the force's parameters change
    logical, allocatable :: kgrav(:)         !! (np) the parameter changes a mass or gravity
    logical, allocatable :: kcon(:)          !! (np) the parameter changes a constraint
    !> (np, nf) how parameter k changes force f: 0 not, 1 a spring's tension only (not its
    !! points), 2 otherwise (force_rows_d)
    integer, allocatable :: fcode(:, :)
    !> (nq, np) the change of the gravity loads m g (with the masses and g: constant), and
    !! as rows (npad, nq)
    real(wp), allocatable :: qg(:, :), qgr(:, :)
    logical :: anyg = .false.                !! some parameter changes m g
    !> the mass matrix's changes as a list: coordinate, parameter, value (tmass's nonzeros)
    integer :: nmz = 0
    integer, allocatable :: mzc(:), mzk(:)
    real(wp), allocatable :: mzv(:)
    real(wp), allocatable :: tmass(:, :)     !! (nq, np) change of the mass matrix diagonal
    real(wp), allocatable :: tgrav(:, :)     !! (2, np) change of gravity
    ! local blocks at the current state (sens_hessian)
    real(wp), allocatable :: hs(:, :, :, :)  !! (MAXROW, NLOC, NLOC, nc) dJ_loc / dq_slot
    ! parameter parts at the current state (sens_params), (npad, neq): a row per parameter
    ! (the padding rows and the pairs a parameter does not change stay zero)
    real(wp), allocatable :: mphip(:, :)     !! -Phi_p (the first level's right-hand side)
    real(wp), allocatable :: vp(:, :)        !! nu_p - J_p q_dot
    real(wp), allocatable :: ap(:, :)        !! gamma_p - J_p q_ddot
    real(wp), allocatable :: work(:)         !! (neq)
    !> (npad, neq) right-hand sides as rows, npad = np rounded up to a multiple of 4 (the
    !! padding rows stay zero: lu_solve_rows works on 4 at a time)
    real(wp), allocatable :: rhs(:, :)
    real(wp), allocatable :: st(:, :), sdt(:, :)  !! (npad, nq) s and s_dot as rows (sens_kin_rhs)
    !> the revolutes' moving sides (closed forms): body, point offset in the pool, sign,
    !! constraint, theta slot (3, 6), and their blocks (2, nside) at the current state
    integer, allocatable :: rsb(:), rso(:), rsc(:), rss(:)
    integer, allocatable :: rsq(:), rsr(:)   !! each side's angle coordinate and first row
    !> the sides' entries by row (sens_kin_rhs): row r's are rwe(rwp(r) .. rwp(r + 1) - 1),
    !! each a place in rsv, rsa (seen flat: 2 (e - 1) + i for row rsr(e) + i - 1), in the
    !! order of the sides, with its angle column rwc
    integer, allocatable :: rwp(:), rwe(:), rwc(:)
    real(wp), allocatable :: rsg(:)
    real(wp), allocatable :: rsh(:, :), rsv(:, :), rsa(:, :)
    integer, allocatable :: tlc(:)           !! the translationals (closed forms)
    !> a state at rest at the origin: a constraint linear in q (con_linear) has J free of the
    !! parameters and parameter parts that depend on t only, evaluated here
    type(dloc) :: x0
    logical :: gathers = .true.              !! some pair or constraint needs gather (cb, sb)
    ! work of the multipliers' sensitivities (mbd_sens_dynamics, allocated at its first call)
    real(wp), allocatable :: mjt(:, :), mb(:, :), mbb(:, :), my(:), myf(:, :)
    integer, allocatable :: mpiv(:)
    integer, allocatable :: gen(:)           !! the other constraints not linear in q
    !> the (revolute side, parameter) entries whose point the parameter moves: parameter,
    !! body, offset in tp's column, sign, first row, first entry of its pair, and their parts
    !! (2, n) at the current state
    integer, allocatable :: psk(:), psb(:), pso(:), psr(:)
    real(wp), allocatable :: psg(:)
    logical, allocatable :: psfirst(:)
    real(wp), allocatable :: psphi(:, :), psv(:, :), psa(:, :)
    !> the other pairs (constraint gpc(e), parameter gpk(e)), by constraint; with the
    !! revolute entries, the only entries of mphip, vp, ap sens_params writes
    integer, allocatable :: gpc(:), gpk(:)
    real(wp), allocatable :: cb(:), sb(:)    !! (0:nb) cos and sin of the body angles (sens_trig)
    real(wp), allocatable :: bst(:, :)       !! (4, 0:nb) cos, sin, theta_dot, theta_ddot
    ! the nonzeros of Hv and Ha (sens_hessian): row, column, values
    integer :: nnz = 0
    integer :: nrvz = 0                      !! the first nrvz: the revolutes' (fixed places)
    integer, allocatable :: nzr(:), nzc(:)
    real(wp), allocatable :: nzv(:), nza(:)
    ! the nonzeros of K_lambda (sens_klam_list): row, column, value
    integer :: kln = 0
    integer, allocatable :: klr(:), klc(:)
    real(wp), allocatable :: klv(:)
    real(wp), allocatable :: zp(:)           !! zeros, the longest prepared slice
    real(wp), allocatable :: zfp(:, :)       !! (size(m%fp), 1) zeros: no parameter's change
    real(wp), allocatable :: zq(:)           !! zeros (nq)
  end type sens_t

contains

  !> Check the parameter table and build the changes of the prepared pools.
  !! bad returns the offending parameter (column of ptab), 0 when none.
  subroutine sens_setup(m, ctab, rpar, ptab, s, status, msg, bad, ftab, fpar)
    type(model_t), intent(in) :: m              !! built model
    integer, intent(in) :: ctab(:, :)           !! constraint table (NCT, nc)
    real(wp), intent(in) :: rpar(:)             !! raw constraint parameters
    integer, intent(in) :: ptab(:, :)           !! (2, np) parameter table
    type(sens_t), intent(out) :: s              !! parameters and work arrays
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer, intent(out) :: bad                 !! offending parameter
    integer, intent(in), optional :: ftab(:, :) !! force table (NFT, nf), for dynamics
    real(wp), intent(in), optional :: fpar(:)   !! raw force parameters
    real(wp), allocatable :: tprep(:), raw(:)
    integer :: k, i, c, d, j, off, len, st, nfp, npad
    integer, allocatable :: fe(:)
    logical :: dyn
    status = MBD_OK; msg = ''; bad = 0
    if (size(ptab, 1) /= 2) then
      status = MBD_BAD_INPUT; msg = 'the parameter table must have 2 rows'; return
    end if
    dyn = allocated(m%mdiag) .and. present(ftab) .and. present(fpar)
    s%np = size(ptab, 2)
    npad = 4 * ((s%np + 3) / 4)
    nfp = 0
    if (dyn) nfp = size(m%fp)
    allocate (s%ptab(2, s%np), s%pscale(s%np), s%tp(size(m%p), s%np), s%caff(m%nc, s%np), &
              s%tfp(nfp, s%np), s%faff(m%nf, s%np), s%tmass(m%nq, s%np), s%tgrav(2, s%np), &
              s%hs(MAXROW, NLOC, NLOC, m%nc), s%mphip(npad, m%neq), s%vp(npad, m%neq), &
              s%ap(npad, m%neq), s%work(m%neq), s%rhs(npad, m%neq), &
              s%st(npad, m%nq), s%sdt(npad, m%nq), &
              s%zp(maxval(m%pn)), s%zq(m%nq), s%zfp(nfp, 1), &
              s%cb(0:m%nb), s%sb(0:m%nb), s%bst(4, 0:m%nb), s%nzr(NLOC * m%neq), &
              s%nzc(NLOC * m%neq), &
              s%nzv(NLOC * m%neq), s%nza(NLOC * m%neq), s%klr(NLOC * NLOC * m%nc), &
              s%klc(NLOC * NLOC * m%nc), s%klv(NLOC * NLOC * m%nc), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the sensitivity arrays'; return
    end if
    s%ptab = ptab
    s%tp = zero; s%caff = .false.; s%tfp = zero; s%faff = .false.; s%tmass = zero
    s%tgrav = zero; s%hs = zero; s%zp = zero; s%zfp = zero
    s%cb = one; s%sb = zero; s%rhs = zero; s%pscale = one; s%zq = zero
    s%mphip = zero; s%vp = zero; s%ap = zero   ! entries of unaffected pairs stay zero
    s%st = zero; s%sdt = zero                 ! (padding rows stay zero)
    s%bst = zero; s%bst(1, 0) = one
    do k = 1, s%np
      bad = k
      i = ptab(2, k)
      select case (ptab(1, k))
      case (PT_RPAR)
        if (i < 1 .or. i > size(rpar)) then
          call fail('constraint parameter index out of range'); return
        end if
        c = owner(ctab(6, :), ctab(7, :), i)
        if (c == 0) then
          call fail('the constraint parameter belongs to no constraint'); return
        end if
        off = ctab(6, c); len = ctab(7, c); j = i - off + 1
        if (con_is_count(ctab(1, c), ctab(4, c), rpar(off:off + len - 1), j)) then
          call fail('is a count, not a continuous parameter'); return
        end if
        raw = scaled_raw(ctab(1, c), ctab(4, c), ctab(5, c), rpar(off:off + len - 1), j, &
                         s%pscale(k))
        call con_prepare_d(ctab(1, c), ctab(4, c), ctab(5, c), raw, j, tprep, status, msg)
        if (status /= MBD_OK) return
        call put_prep(c, tprep, k)
        if (ctab(1, c) == CON_TRANSLATIONAL) then
          ! relative-distance drivers on this joint carry its prepared parameters in front
          do d = 1, m%nc
            if (ctab(1, d) == DRV_REL_DIST .and. ctab(4, d) == c) then
              s%tp(m%po(d):m%po(d) + size(tprep) - 1, k) = tprep
              s%caff(d, k) = .true.
            end if
          end do
        end if
      case (PT_MASS)
        if (i < 1 .or. i > 2 * m%nb) then
          call fail('mass table index out of range'); return
        end if
        c = (i + 1) / 2
        if (mod(i, 2) == 1) then
          s%tmass(3 * c - 2:3 * c - 1, k) = one
          s%pscale(k) = m%lref**2                  ! masses x L**2
        else
          s%tmass(3 * c, k) = one
        end if
      case (PT_GRAV)
        if (i < 1 .or. i > 2) then
          call fail('gravity index must be 1 or 2'); return
        end if
        s%tgrav(i, k) = one
        s%pscale(k) = one / m%lref                 ! gravity / L
      case (PT_FPAR)
        if (.not. dyn) cycle            ! no forces in a kinematic model: no change
        if (i < 1 .or. i > size(fpar)) then
          call fail('force parameter index out of range'); return
        end if
        c = owner(ftab(4, :), ftab(5, :), i)
        if (c == 0) then
          call fail('the force parameter belongs to no force'); return
        end if
        j = i - ftab(4, c) + 1
        if (force_is_count(ftab(1, c), fpar(ftab(4, c):ftab(4, c) + ftab(5, c) - 1), j)) then
          call fail('is a count, not a continuous parameter'); return
        end if
        s%tfp(m%fpo(c) + j - 1, k) = one          ! forces: prepared = raw
        s%faff(c, k) = .true.
        allocate (fe(ftab(5, c)), stat=st)
        if (st /= 0) then
          status = MBD_NO_MEMORY; msg = 'out of memory'; return
        end if
        call force_exponents(ftab(1, c), fpar(ftab(4, c):ftab(4, c) + ftab(5, c) - 1), fe)
        s%pscale(k) = m%lref**fe(j)
        deallocate (fe)
      case default
        call fail('unknown parameter table (1 constraints, 2 masses, 3 gravity, 4 forces)')
        return
      end select
    end do
    bad = 0
    allocate (s%kgrav(s%np), s%kcon(s%np), s%qg(m%nq, s%np), s%qgr(npad, m%nq), &
              s%fcode(s%np, m%nf), &
              s%mzc(count(abs(s%tmass) > zero)), s%mzk(count(abs(s%tmass) > zero)), &
              s%mzv(count(abs(s%tmass) > zero)), stat=st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the sensitivity arrays'; return
    end if
    s%qg = zero; s%qgr = zero; s%nmz = 0
    s%fcode = 0
    do c = 1, m%nf
      do k = 1, s%np
        if (.not. s%faff(c, k)) cycle
        s%fcode(k, c) = 2
        if (m%fkind(c) == FRC_SPRING) then
          if (.not. any(abs(s%tfp(m%fpo(c):m%fpo(c) + 3, k)) > zero)) s%fcode(k, c) = 1
        end if
      end do
    end do
    do k = 1, s%np
      do i = 1, m%nq
        if (.not. abs(s%tmass(i, k)) > zero) cycle
        s%nmz = s%nmz + 1
        s%mzc(s%nmz) = i; s%mzk(s%nmz) = k; s%mzv(s%nmz) = s%tmass(i, k)
      end do
    end do
    do k = 1, s%np
      s%kgrav(k) = any(abs(s%tmass(:, k)) > zero) .or. any(abs(s%tgrav(:, k)) > zero)
      s%kcon(k) = any(s%caff(:, k))
      if (.not. (dyn .and. s%kgrav(k))) cycle
      do i = 1, m%nb                              ! d(m g) = dm g + m dg
        s%qg(3 * i - 2, k) = s%tmass(3 * i - 2, k) * m%grav(1) + m%mdiag(3 * i - 2) * &
                             s%tgrav(1, k)
        s%qg(3 * i - 1, k) = s%tmass(3 * i - 2, k) * m%grav(2) + m%mdiag(3 * i - 2) * &
                             s%tgrav(2, k)
      end do
      s%qgr(k, :) = s%qg(:, k)
    end do
    s%anyg = any(s%kgrav) .and. dyn
    call sens_lists(m, s, st)
    if (st /= 0) then
      status = MBD_NO_MEMORY; msg = 'out of memory for the sensitivity arrays'; return
    end if
  contains
    !> A constraint's raw parameters as the nondimensional model has them (p L**e), and the
    !! factor dp'/dp = L**e of entry jj.
    function scaled_raw(kd, sa, sb, rw, jj, f) result(rs)
      integer, intent(in) :: kd, sa, sb, jj
      real(wp), intent(in) :: rw(:)
      real(wp), intent(out) :: f
      real(wp) :: rs(size(rw))
      integer :: e(size(rw))
      logical :: g(size(rw))
      rs = rw; f = one
      if (.not. (m%lref > one .or. m%lref < one)) return
      call con_exponents(kd, sa, sb, rw, e, g)
      rs = rw * m%lref**e
      f = m%lref**e(jj)
    end function scaled_raw

    !> The element whose slice [off, off + len) holds index ii (0 when none).
    pure integer function owner(offs, lens, ii)
      integer, intent(in) :: offs(:), lens(:), ii
      integer :: e
      owner = 0
      do e = 1, size(offs)
        if (ii >= offs(e) .and. ii < offs(e) + lens(e)) then
          owner = e; return
        end if
      end do
    end function owner

    subroutine put_prep(cc, tpr, kk)
      integer, intent(in) :: cc, kk
      real(wp), intent(in) :: tpr(:)
      if (size(tpr) /= m%pn(cc)) then
        status = MBD_BAD_PARAM
        msg = trim(con_name(m%kind(cc))) // ': prepared parameter change has the wrong length'
        return
      end if
      s%tp(m%po(cc):m%po(cc) + m%pn(cc) - 1, kk) = tpr
      s%caff(cc, kk) = .true.
    end subroutine put_prep

    subroutine fail(what)
      character(len=*), intent(in) :: what
      status = MBD_BAD_PARAM
      write (msg, '(a,i0,a,i0,a,i0,a,a)') 'parameter ', k, ' (table ', ptab(1, k), ', entry ', &
        ptab(2, k), '): ', what
    end subroutine fail
  end subroutine sens_setup

  !> What the per-output loops visit: the revolutes' moving sides and the translationals
  !! (and their fixed places in the list of nonzeros), the (revolute side, parameter) entries
  !! whose point a parameter moves, the other constraints not linear in q and the other
  !! (constraint, parameter) pairs a parameter changes.
  pure subroutine sens_lists(m, s, st)
    type(model_t), intent(in) :: m           !! model
    type(sens_t), intent(inout) :: s         !! caff set (in); the lists (out)
    integer, intent(out) :: st               !! allocation status
    integer :: c, k, side, ns, ngen, nps, ngp, o, ntr, j
    logical :: rev(m%nc), curv(m%nc), tra(m%nc)
    do c = 1, m%nc
      rev(c) = m%kind(c) == CON_REVOLUTE
      tra(c) = m%kind(c) == CON_TRANSLATIONAL
      curv(c) = .not. con_linear(m%kind(c))
    end do
    ns = 0; ngen = count(curv .and. .not. (rev .or. tra)); nps = 0; ngp = 0
    do c = 1, m%nc
      if (rev(c)) then
        ns = ns + count(m%loc([3, 6], c) > 0)
        do k = 1, s%np
          if (.not. s%caff(c, k)) cycle
          do side = 0, 1
            o = m%po(c) + 2 * side
            if (any(abs(s%tp(o:o + 1, k)) > zero)) nps = nps + 1
          end do
        end do
      else
        ngp = ngp + count(s%caff(c, :))
      end if
    end do
    allocate (s%rsb(ns), s%rso(ns), s%rsc(ns), s%rss(ns), s%rsq(ns), s%rsr(ns), s%rsg(ns), &
              s%rsh(2, ns), &
              s%rsv(2, ns), s%rsa(2, ns), s%gen(ngen), s%psk(nps), s%psb(nps), s%pso(nps), &
              s%psr(nps), s%psg(nps), s%psfirst(nps), s%psphi(2, nps), s%psv(2, nps), &
              s%psa(2, nps), s%gpc(ngp), s%gpk(ngp), s%ounit(m%nq, s%np), &
              s%tlc(count(tra)), s%rwp(m%neq + 1), s%rwe(2 * ns), s%rwc(2 * ns), stat=st)
    if (st /= 0) return
    do k = 1, s%np
      s%ounit(:, k) = s%pscale(k) * m%cunit
    end do
    s%rsh = zero; s%rsv = zero; s%rsa = zero
    s%nrvz = 0
    ns = 0; ngen = 0; nps = 0; ngp = 0; ntr = 0
    s%gathers = size(s%gen) > 0
    do c = 1, m%nc
      if (rev(c)) then
        do side = 1, 2                           ! moving sides; two fixed list entries each
          if (m%loc(3 * side, c) == 0) cycle
          ns = ns + 1
          s%rsb(ns) = merge(m%bi(c), m%bj(c), side == 1); s%rso(ns) = m%po(c) + 2 * (side - 1)
          s%rsg(ns) = merge(-one, one, side == 1); s%rsc(ns) = c; s%rss(ns) = 3 * side
          s%rsq(ns) = m%loc(3 * side, c); s%rsr(ns) = m%row0(c)
          s%nzr(s%nrvz + 1) = m%row0(c); s%nzr(s%nrvz + 2) = m%row0(c) + 1
          s%nzc(s%nrvz + 1:s%nrvz + 2) = m%loc(3 * side, c)
          s%nzv(s%nrvz + 1:s%nrvz + 2) = zero; s%nza(s%nrvz + 1:s%nrvz + 2) = zero
          s%nrvz = s%nrvz + 2
        end do
        do k = 1, s%np
          if (.not. s%caff(c, k)) cycle
          do side = 0, 1                         ! the sides whose point parameter k moves
            o = m%po(c) + 2 * side
            if (.not. any(abs(s%tp(o:o + 1, k)) > zero)) cycle
            nps = nps + 1
            s%psk(nps) = k; s%psb(nps) = merge(m%bi(c), m%bj(c), side == 0); s%pso(nps) = o
            s%psg(nps) = merge(one, -one, side == 0); s%psr(nps) = m%row0(c)
            s%psfirst(nps) = .true.
            if (nps > 1) s%psfirst(nps) = s%psk(nps - 1) /= k .or. s%psr(nps - 1) /= m%row0(c)
          end do
        end do
      else
        if (curv(c) .and. .not. tra(c)) then
          ngen = ngen + 1; s%gen(ngen) = c
        end if
        do k = 1, s%np
          if (.not. s%caff(c, k)) cycle
          ngp = ngp + 1; s%gpc(ngp) = c; s%gpk(ngp) = k
        end do
        if (any(s%caff(c, :)) .and. .not. (tra(c) .or. con_linear(m%kind(c)))) s%gathers = .true.
      end if
    end do
    call side_rows(m%neq, ns, s%rsr, s%rsq, s%rwp, s%rwe, s%rwc)
    do c = 1, m%nc                               ! the translationals' first rows, after
      if (.not. tra(c)) cycle                    ! the revolutes' entries
      ntr = ntr + 1; s%tlc(ntr) = c
      do j = 1, 6
        if (m%loc(j, c) == 0) cycle
        s%nrvz = s%nrvz + 1
        s%nzr(s%nrvz) = m%row0(c); s%nzc(s%nrvz) = m%loc(j, c)
        s%nzv(s%nrvz) = zero; s%nza(s%nrvz) = zero
      end do
    end do
  end subroutine sens_lists

  !> The revolute sides' entries gathered by row (counting sort, stable: within a row in
  !! the order of the sides): side e has row r0(e) (value 2 e - 1) and r0(e) + 1 (2 e), both
  !! in column cq(e).
  pure subroutine side_rows(neq, ns, r0, cq, rwp, rwe, rwc)
    integer, intent(in) :: neq, ns, r0(ns), cq(ns)
    integer, intent(out) :: rwp(neq + 1), rwe(2 * ns), rwc(2 * ns)
    integer :: e, i, r, nxt(neq)
    rwp = 0
    do e = 1, ns
      rwp(r0(e)) = rwp(r0(e)) + 1; rwp(r0(e) + 1) = rwp(r0(e) + 1) + 1
    end do
    nxt(1) = 1
    do r = 2, neq
      nxt(r) = nxt(r - 1) + rwp(r - 1)
    end do
    rwp(1:neq) = nxt; rwp(neq + 1) = 2 * ns + 1
    do e = 1, ns
      do i = 0, 1
        r = r0(e) + i
        rwe(nxt(r)) = 2 * e - 1 + i; rwc(nxt(r)) = cq(e)
        nxt(r) = nxt(r) + 1
      end do
    end do
  end subroutine side_rows

  !> cos and sin of every body angle at q, for the evaluations that follow at the same q.
  pure subroutine sens_trig(m, s, q)
    type(model_t), intent(in) :: m           !! model
    type(sens_t), intent(inout) :: s         !! cache (out)
    real(wp), intent(in) :: q(:)             !! configuration
    integer :: b
    do b = 1, m%nb
      s%cb(b) = cos(q(3 * b)); s%sb(b) = sin(q(3 * b))
    end do
  end subroutine sens_trig

  !> The local state of constraint k at (q, q_dot) and its slots' accelerations (cos and sin
  !! from sens_trig).
  pure subroutine gather(m, s, k, q, qd, qdd, xd, qddl)
    type(model_t), intent(in) :: m
    type(sens_t), intent(in) :: s
    integer, intent(in) :: k
    real(wp), intent(in) :: q(:), qd(:), qdd(:)
    type(dloc), intent(out) :: xd          ! the state, with a zero direction
    real(wp), intent(out) :: qddl(NLOC)
    integer :: j, c
    do j = 1, NLOC
      c = m%loc(j, k)
      xd%x%q(j) = zero; xd%x%qd(j) = zero; qddl(j) = zero
      if (c > 0) then
        xd%x%q(j) = q(c); xd%x%qd(j) = qd(c); qddl(j) = qdd(c)
      end if
    end do
    xd%x%c(1) = s%cb(m%bi(k)); xd%x%c(2) = s%cb(m%bj(k))
    xd%x%s(1) = s%sb(m%bi(k)); xd%x%s(2) = s%sb(m%bj(k))
    xd%tq = zero; xd%tqd = zero
  end subroutine gather

  !> Local Hessian blocks at (q, q_dot, q_ddot, t): for each constraint and each of its
  !! slots j, hs(:, :, j) = dJ_loc/dq_j, hv(:, j) = hs(:, :, j) q_dot_loc and
  !! ha(:, j) = hs(:, :, j) q_ddot_loc - dgamma/dq_j, in the list of nonzeros: revolutes and
  !! translationals in closed form (revolute_second_sides, translational_second, in fixed
  !! places of the list), the others by the dual evaluation along dq = e_j.
  !! sens_trig first (or sens_states, with states = .false.).
  pure subroutine sens_hessian(m, s, q, qd, qdd, t, states, closed, push)
    type(model_t), intent(in) :: m             !! model
    type(sens_t), intent(inout) :: s           !! blocks (out)
    real(wp), intent(in) :: q(m%nq), qd(m%nq), qdd(m%nq)  !! state, accelerations
    real(wp), intent(in) :: t                  !! time
    logical, intent(in), optional :: states    !! .false.: sens_states has set the state
    !> .false.: leave the revolutes and translationals out (their blocks, entries and closed
    !! forms stale; sens_revolute_rows and sens_translational_rows take them)
    logical, intent(in), optional :: closed
    !> .false.: the revolutes' closed forms only in s%rsh, rsv, rsa (their blocks and list
    !! entries stale: the kinematic right-hand sides, sens_kin_rhs, read them there)
    logical, intent(in), optional :: push
    type(dloc) :: x
    real(wp) :: qddl(NLOC), tphi(MAXROW), tnu(MAXROW), tgam(MAXROW), hv, ha
    real(wp) :: qloc(NLOC), qdl(NLOC), hm(6, 6), hvt(6), hat(6)
    integer :: k, j, nr, si, sj, r, e, n
    logical :: revs
    if (.not. present(states)) then
      call body_states(m, s, qd, qdd)
    else if (states) then
      call body_states(m, s, qd, qdd)
    end if
    s%nnz = s%nrvz                              ! the revolutes' entries first, in fixed places
    revs = .true.
    if (present(closed)) revs = closed
    if (size(s%rsb) > 0 .and. revs) then        ! the revolutes in closed form
      call revolute_second_sides(size(s%rsb), m%nb, s%rso, s%rsb, s%rsg, m%p, s%bst, s%rsh, &
                                 s%rsv, s%rsa)
      if (.not. present(push)) then
        call revolute_push(size(s%rsb), m%nc, s%rsc, s%rss, s%rsh, s%rsv, s%rsa, s%hs, s%nzv, &
                           s%nza)
      else if (push) then
        call revolute_push(size(s%rsb), m%nc, s%rsc, s%rss, s%rsh, s%rsv, s%rsa, s%hs, s%nzv, &
                           s%nza)
      end if
    end if
    n = 2 * size(s%rsb)                         ! the translationals' entries follow
    do e = 1, merge(size(s%tlc), 0, revs)
      k = s%tlc(e)
      call slot_values(m, k, q, qd, qdd, qloc, qdl, qddl)
      call translational_second(m%p(m%po(k):m%po(k) + 8), s%bst(1, m%bi(k)), &
                                s%bst(2, m%bi(k)), s%bst(1, m%bj(k)), s%bst(2, m%bj(k)), &
                                qloc(1:6), qdl(1:6), qddl(1:6), hm, hvt, hat)
      do j = 1, 6
        if (m%loc(j, k) == 0) cycle
        s%hs(1, 1:6, j, k) = hm(:, j)
        n = n + 1
        s%nzv(n) = hvt(j); s%nza(n) = hat(j)
      end do
    end do
    do e = 1, size(s%gen)                       ! (the linear ones' blocks stay zero)
      k = s%gen(e)
      call gather(m, s, k, q, qd, qdd, x, qddl)
      si = merge(1, 0, m%bi(k) > 0); sj = merge(2, 0, m%bj(k) > 0)
      nr = m%nrow(k)
      do j = 1, NLOC
        if (m%loc(j, k) == 0) cycle
        if (con_affine_r(m%kind(k), m%bi(k)) .and. j /= 3 .and. j /= 6) cycle   ! zero blocks
        x%tq(j) = one
        call con_eval_d(m%kind(k), m%suba(k), m%subb(k), m%p(m%po(k):m%po(k) + m%pn(k) - 1), &
                        s%zp(1:m%pn(k)), si, sj, x, t, tphi, s%hs(:, :, j, k), tnu, tgam)
        x%tq(j) = zero
        do r = 1, nr
          hv = dot_product(s%hs(r, :, j, k), x%x%qd)
          ha = dot_product(s%hs(r, :, j, k), qddl) - tgam(r)
          if (abs(hv) > zero .or. abs(ha) > zero) then
            s%nnz = s%nnz + 1
            s%nzr(s%nnz) = m%row0(k) + r - 1; s%nzc(s%nnz) = m%loc(j, k)
            s%nzv(s%nnz) = hv; s%nza(s%nnz) = ha
          end if
        end do
      end do
    end do
  end subroutine sens_hessian

  !> The revolutes' moving sides' blocks (revolute_second_sides) into hs and their values
  !! into the list of nonzeros (its first entries, two per side, whose rows and columns
  !! sens_lists set, zero or not): only the theta slots (3, 6) of a revolute have second
  !! derivatives (the blocks' other entries stay zero from sens_setup).
  pure subroutine revolute_push(ns, nc, rsc, rss, h, hv, ha, hs, nzv, nza)
    integer, intent(in) :: ns, nc                        !! sides, constraints
    integer, intent(in) :: rsc(ns), rss(ns)              !! constraint and slot of each side
    real(wp), intent(in) :: h(2, ns), hv(2, ns), ha(2, ns)
    real(wp), intent(inout) :: hs(MAXROW, NLOC, NLOC, nc)
    real(wp), intent(inout) :: nzv(2, *), nza(2, *)
    integer :: e, k, j
    !GCC$ novector
    do e = 1, ns
      k = rsc(e); j = rss(e)
      hs(1, j, j, k) = h(1, e); hs(2, j, j, k) = h(2, e)
      nzv(1, e) = hv(1, e); nzv(2, e) = hv(2, e)
      nza(1, e) = ha(1, e); nza(2, e) = ha(2, e)
    end do
  end subroutine revolute_push

  !> Parameter parts at (q, q_dot, q_ddot, t): Phi_p, nu_p - J_p q_dot and
  !! gamma_p - J_p q_ddot, each a row per parameter, written for the pairs (constraint,
  !! parameter) of the lists only (the other entries stay zero from sens_setup): the
  !! revolutes' and translationals' in closed form, the others by the dual evaluation along
  !! the parameter's change (dq = 0).
  pure subroutine sens_params(m, s, q, qd, qdd, t, states)
    type(model_t), intent(in) :: m             !! model
    type(sens_t), intent(inout) :: s           !! parameter parts (out)
    real(wp), intent(in) :: q(m%nq), qd(m%nq), qdd(m%nq)  !! state, accelerations
    real(wp), intent(in) :: t                  !! time
    logical, intent(in), optional :: states    !! .false.: sens_states has set the state
    type(dloc) :: x
    real(wp) :: qddl(NLOC), tphi(MAXROW), tjl(MAXROW, NLOC), tnu(MAXROW), tgam(MAXROW)
    real(wp) :: qloc(NLOC), qdl(NLOC)
    integer :: e, k, c, cprev, nr, si, sj, r, r0
    if (.not. present(states)) then
      call body_states(m, s, qd, qdd)
    else if (states) then
      call body_states(m, s, qd, qdd)
    end if
    if (size(s%psk) > 0) then                   ! the revolutes' in closed form
      call revolute_param_sides(size(s%psk), m%nb, size(s%tp, 1), s%np, s%pso, s%psk, s%psb, &
                                s%psg, s%tp, s%bst, s%psphi, s%psv, s%psa)
      call pairs_put(size(s%psk), size(s%mphip, 1), size(s%mphip, 2), s%psk, s%psr, &
                     s%psfirst, s%psphi, s%psv, s%psa, s%mphip, s%vp, s%ap)
    end if
    cprev = 0
    do e = 1, size(s%gpc)
      c = s%gpc(e); k = s%gpk(e); r0 = m%row0(c) - 1
      if (m%kind(c) == CON_TRANSLATIONAL) then  ! in closed form too
        if (c /= cprev) call slot_values(m, c, q, qd, qdd, qloc, qdl, qddl)
        cprev = c
        call translational_param(m%p(m%po(c):m%po(c) + 8), s%tp(m%po(c):m%po(c) + 8, k), &
                                 s%bst(1, m%bi(c)), s%bst(2, m%bi(c)), s%bst(1, m%bj(c)), &
                                 s%bst(2, m%bj(c)), qloc(1:6), qdl(1:6), qddl(1:6), &
                                 tphi(1:2), tnu(1:2), tgam(1:2))
        do r = 1, 2
          s%mphip(k, r0 + r) = -tphi(r); s%vp(k, r0 + r) = tnu(r); s%ap(k, r0 + r) = tgam(r)
        end do
        cycle
      end if
      si = merge(1, 0, m%bi(c) > 0); sj = merge(2, 0, m%bj(c) > 0)
      nr = m%nrow(c)
      if (con_linear(m%kind(c))) then           ! J_p = 0: the parts of t alone, no state
        call con_eval_d(m%kind(c), m%suba(c), m%subb(c), &
                        m%p(m%po(c):m%po(c) + m%pn(c) - 1), &
                        s%tp(m%po(c):m%po(c) + m%pn(c) - 1, k), si, sj, s%x0, t, tphi, tjl, &
                        tnu, tgam)
        do r = 1, nr
          s%mphip(k, r0 + r) = -tphi(r); s%vp(k, r0 + r) = tnu(r); s%ap(k, r0 + r) = tgam(r)
        end do
        cycle
      end if
      if (c /= cprev) call gather(m, s, c, q, qd, qdd, x, qddl)
      cprev = c
      call con_eval_d(m%kind(c), m%suba(c), m%subb(c), m%p(m%po(c):m%po(c) + m%pn(c) - 1), &
                      s%tp(m%po(c):m%po(c) + m%pn(c) - 1, k), si, sj, x, &
                      t, tphi, tjl, tnu, tgam)
      do r = 1, nr
        s%mphip(k, r0 + r) = -tphi(r)
        s%vp(k, r0 + r) = tnu(r) - dot_product(tjl(r, :), x%x%qd)
        s%ap(k, r0 + r) = tgam(r) - dot_product(tjl(r, :), qddl)
      end do
    end do
  end subroutine sens_params

  !> The two-row parts of n entries (parameter k(e), first row r0(e)) into mphip (negated),
  !! vp, ap: an entry that is the first of its pair writes, the others add.
  pure subroutine pairs_put(n, npad, neq, k, r0, first, tphi, tv, ta, mphip, vp, ap)
    integer, intent(in) :: n, npad, neq, k(n), r0(n)
    logical, intent(in) :: first(n)
    real(wp), intent(in) :: tphi(2, n), tv(2, n), ta(2, n)
    real(wp), intent(inout) :: mphip(npad, neq), vp(npad, neq), ap(npad, neq)
    integer :: e, i, r
    !GCC$ novector
    do e = 1, n
      i = k(e); r = r0(e)
      if (first(e)) then
        mphip(i, r) = -tphi(1, e); mphip(i, r + 1) = -tphi(2, e)
        vp(i, r) = tv(1, e); vp(i, r + 1) = tv(2, e)
        ap(i, r) = ta(1, e); ap(i, r + 1) = ta(2, e)
      else
        mphip(i, r) = mphip(i, r) - tphi(1, e); mphip(i, r + 1) = mphip(i, r + 1) - tphi(2, e)
        vp(i, r) = vp(i, r) + tv(1, e); vp(i, r + 1) = vp(i, r + 1) + tv(2, e)
        ap(i, r) = ap(i, r) + ta(1, e); ap(i, r + 1) = ap(i, r + 1) + ta(2, e)
      end if
    end do
  end subroutine pairs_put

  !> Coordinates, velocities and accelerations of constraint k's slots (0 for a ground slot).
  pure subroutine slot_values(m, k, q, qd, qdd, ql, qdl, qddl)
    type(model_t), intent(in) :: m              !! model
    integer, intent(in) :: k                    !! constraint
    real(wp), intent(in) :: q(:), qd(:), qdd(:) !! state and accelerations
    real(wp), intent(out) :: ql(NLOC), qdl(NLOC), qddl(NLOC)  !! by slot
    integer :: j, c
    do j = 1, NLOC
      c = m%loc(j, k)
      ql(j) = zero; qdl(j) = zero; qddl(j) = zero
      if (c > 0) then
        ql(j) = q(c); qdl(j) = qd(c); qddl(j) = qdd(c)
      end if
    end do
  end subroutine slot_values

  !> Each body's [cos, sin, theta_dot, theta_ddot] in s%bst (the ground's 1, 0, 0, 0; cos and
  !! sin from sens_trig), as the revolute's closed forms take them.
  pure subroutine body_states(m, s, qd, qdd)
    type(model_t), intent(in) :: m              !! model
    type(sens_t), intent(inout) :: s            !! bst (out)
    real(wp), intent(in) :: qd(:), qdd(:)       !! velocities and accelerations
    call states_kernel(m%nb, s%cb, s%sb, qd, qdd, s%bst)
  end subroutine body_states

  !> The state sens_hessian and sens_params work at, from the cos and sin of the body angles
  !! cb, sb (0:nb) at q (instead of sens_trig; they are copied only when a dual evaluation
  !! needs the local state, s%gathers); both then called with states = .false.
  pure subroutine sens_states(m, s, cb, sb, qd, qdd)
    type(model_t), intent(in) :: m              !! model
    type(sens_t), intent(inout) :: s            !! bst (and cb, sb) (out)
    real(wp), intent(in) :: cb(0:m%nb), sb(0:m%nb)  !! cos and sin of the body angles
    real(wp), intent(in) :: qd(m%nq), qdd(m%nq)  !! velocities, accelerations
    if (s%gathers) then
      s%cb(:) = cb; s%sb(:) = sb
    end if
    call states_kernel(m%nb, cb, sb, qd, qdd, s%bst)
  end subroutine sens_states

  !> bst(:, b) = [cos, sin, theta_dot, theta_ddot] of body b = 1 .. nb.
  pure subroutine states_kernel(nb, cb, sb, qd, qdd, bst)
    integer, intent(in) :: nb
    real(wp), intent(in) :: cb(0:nb), sb(0:nb), qd(3 * nb), qdd(3 * nb)
    real(wp), intent(inout) :: bst(4, 0:nb)
    integer :: b
    !GCC$ novector
    do b = 1, nb
      bst(1, b) = cb(b); bst(2, b) = sb(b); bst(3, b) = qd(3 * b); bst(4, b) = qdd(3 * b)
    end do
  end subroutine states_kernel

  !> Changes of Phi, nu, gamma (neq) and of the local J blocks (MAXROW, NLOC, nc) along a
  !! direction (dq, dq_dot) and parameter k (k = 0: none): every constraint evaluated on
  !! dual numbers. sens_trig first.
  pure subroutine sens_eval_d(m, s, k, q, qd, dq, dqd, t, tphi, tnu, tgam, tjb)
    type(model_t), intent(in) :: m             !! model
    type(sens_t), intent(in) :: s              !! parameters
    integer, intent(in) :: k                   !! parameter, or 0
    real(wp), intent(in) :: q(:), qd(:)        !! state
    real(wp), intent(in) :: dq(:), dqd(:)      !! direction
    real(wp), intent(in) :: t                  !! time
    real(wp), intent(out) :: tphi(:), tnu(:), tgam(:)  !! (neq)
    real(wp), intent(out) :: tjb(:, :, :)      !! (MAXROW, NLOC, nc)
    type(dloc) :: x
    real(wp) :: qddl(NLOC), ph(MAXROW), nv(MAXROW), ga(MAXROW)
    integer :: c, si, sj, r0, nr
    tjb = zero
    do c = 1, m%nc
      call gather(m, s, c, q, qd, qd, x, qddl)
      call gather_dir(c, x%tq, x%tqd)
      si = merge(1, 0, m%bi(c) > 0); sj = merge(2, 0, m%bj(c) > 0)
      ph = zero; nv = zero; ga = zero
      if (k > 0) then
        call con_eval_d(m%kind(c), m%suba(c), m%subb(c), m%p(m%po(c):m%po(c) + m%pn(c) - 1), &
                        s%tp(m%po(c):m%po(c) + m%pn(c) - 1, k), si, sj, &
                        x, t, ph, tjb(:, :, c), nv, ga)
      else
        call con_eval_d(m%kind(c), m%suba(c), m%subb(c), m%p(m%po(c):m%po(c) + m%pn(c) - 1), &
                        s%zp(1:m%pn(c)), si, sj, x, t, ph, &
                        tjb(:, :, c), nv, ga)
      end if
      r0 = m%row0(c) - 1; nr = m%nrow(c)
      tphi(r0 + 1:r0 + nr) = ph(1:nr); tnu(r0 + 1:r0 + nr) = nv(1:nr)
      tgam(r0 + 1:r0 + nr) = ga(1:nr)
    end do
  contains
    pure subroutine gather_dir(cc, a, b)
      integer, intent(in) :: cc
      real(wp), intent(out) :: a(NLOC), b(NLOC)
      integer :: jj
      do jj = 1, NLOC
        a(jj) = zero; b(jj) = zero
        if (m%loc(jj, cc) > 0) then
          a(jj) = dq(m%loc(jj, cc)); b(jj) = dqd(m%loc(jj, cc))
        end if
      end do
    end subroutine gather_dir
  end subroutine sens_eval_d

  !> y = B x for local blocks B (MAXROW, NLOC, nc) in J's layout (y: neq, x: nq).
  pure subroutine block_apply(m, b, x, y)
    type(model_t), intent(in) :: m           !! model
    real(wp), intent(in) :: b(:, :, :)       !! local blocks
    real(wp), intent(in) :: x(:)             !! (nq)
    real(wp), intent(out) :: y(:)            !! (neq)
    integer :: k, j, c, r, r0
    y = zero
    do k = 1, m%nc
      r0 = m%row0(k) - 1
      do j = 1, NLOC
        c = m%loc(j, k)
        if (c == 0) cycle
        do r = 1, m%nrow(k)
          y(r0 + r) = y(r0 + r) + b(r, j, k) * x(c)
        end do
      end do
    end do
  end subroutine block_apply

  !> y = B^T l for local blocks B in J's layout (y: nq, l: neq).
  pure subroutine block_apply_t(m, b, l, y)
    type(model_t), intent(in) :: m           !! model
    real(wp), intent(in) :: b(:, :, :)       !! local blocks
    real(wp), intent(in) :: l(:)             !! (neq)
    real(wp), intent(out) :: y(:)            !! (nq)
    integer :: k, j, c, r, r0
    y = zero
    do k = 1, m%nc
      r0 = m%row0(k) - 1
      do j = 1, NLOC
        c = m%loc(j, k)
        if (c == 0) cycle
        do r = 1, m%nrow(k)
          y(c) = y(c) + b(r, j, k) * l(r0 + r)
        end do
      end do
    end do
  end subroutine block_apply_t

  !> Y = B X for local blocks B in J's layout, X (nq, n), Y (neq, n): block_apply on n
  !! columns at once.
  pure subroutine block_apply_cols(m, b, x, y)
    type(model_t), intent(in) :: m           !! model
    real(wp), intent(in) :: b(:, :, :)       !! local blocks
    real(wp), intent(in) :: x(:, :)          !! (nq, n)
    real(wp), intent(inout) :: y(:, :)       !! (neq, n), added to
    integer :: k, j, c, r, r0, i
    do k = 1, m%nc
      r0 = m%row0(k) - 1
      do j = 1, NLOC
        c = m%loc(j, k)
        if (c == 0) cycle
        do r = 1, m%nrow(k)
          if (abs(b(r, j, k)) <= zero) cycle
          do i = 1, size(x, 2)
            y(r0 + r, i) = y(r0 + r, i) + b(r, j, k) * x(c, i)
          end do
        end do
      end do
    end do
  end subroutine block_apply_cols

  !> Right-hand sides of the sensitivity equations of all parameters at one level, a row per
  !! parameter (npad, neq), given the solutions of the levels before as rows in s%st, s%sdt
  !! (npad, nq; the solves write them, padding rows zero): level 2 nu_p - J_p q_dot - Hv s;
  !! 3 gamma_p - J_p q_ddot - Ha s - 2 Hv s_dot (level 1's, -Phi_p, is s%mphip itself).
  !! sens_hessian and sens_params first.
  pure subroutine sens_kin_rhs(s, level, rhs)
    type(sens_t), intent(in) :: s            !! blocks, parameter parts, s and s_dot as rows
    integer, intent(in) :: level             !! 2 velocity, 3 acceleration
    real(wp), intent(inout), contiguous :: rhs(:, :)  !! (npad, neq)
    if (level == 2) then
      call kin_rhs_kernel(size(rhs, 1), size(rhs, 2), size(s%st, 2), s%nnz, size(s%rsb), &
                          s%rwp, s%rwe, s%rwc, s%rsv, s%rsv, s%nzr, s%nzc, s%nzv, s%nzv, &
                          .false., s%vp, s%st, s%sdt, rhs)
    else
      call kin_rhs_kernel(size(rhs, 1), size(rhs, 2), size(s%st, 2), s%nnz, size(s%rsb), &
                          s%rwp, s%rwe, s%rwc, s%rsa, s%rsv, s%nzr, s%nzc, s%nza, s%nzv, &
                          .true., s%ap, s%st, s%sdt, rhs)
    end if
  end subroutine sens_kin_rhs

  !> sens_kin_rhs on explicit shapes (the loops see plain arrays): rhs = base - H1 s
  !! (- 2 H2 s_dot when both). The parameter parts and rhs share the padded layout
  !! (npad, neq), seen here flat; s and s_dot come as rows (st, sdt: (npad, nq)), so each
  !! nonzero updates a row of rhs from a row of them, four parameters at a time. The
  !! revolutes' sides (npair of them, the list's first 2 npair entries) come from their
  !! closed forms' values p1, p2 (2, npair) by row (rwp, rwe, rwc: side_rows): with four
  !! parameters each row of rhs is then written once, its sums kept in registers.
  pure subroutine kin_rhs_kernel(npad, neq, nq, nnz, npair, rwp, rwe, rwc, p1, p2, nzr, nzc, &
                                 h1, h2, both, base, st, sdt, rhs)
    integer, intent(in) :: npad, neq, nq, nnz, npair
    integer, intent(in) :: rwp(neq + 1), rwe(*), rwc(*), nzr(*), nzc(*)
    real(wp), intent(in) :: p1(*), p2(*)       !! the sides' values (2 npair, flat)
    real(wp), intent(in) :: h1(*), h2(*)       !! values of the nonzeros (Hv or Ha, Hv)
    logical, intent(in) :: both                !! the s_dot term too
    real(wp), intent(in) :: base(npad * neq), st(npad * nq), sdt(npad * nq)
    real(wp), intent(inout) :: rhs(npad * neq)
    integer :: g, n, e, c, r, p, j
    real(wp) :: v, a
    n = 2 * npair + 1                          ! (the list's entries after the sides')
    if (npad == 4 .and. npair > 0) then        ! (up to four parameters: no inner loop)
      call rhs_rows(neq, rwp, rwe, rwc, p1, p2, both, base, st, sdt, rhs)
      call rhs_four(nnz - 2 * npair, nzr(n), nzc(n), h1(n), h2(n), both, st, sdt, rhs)
      return
    end if
    do e = 1, npad * neq
      rhs(e) = base(e)
    end do
    if (npad == 4) then
      call rhs_four(nnz, nzr, nzc, h1, h2, both, st, sdt, rhs)
      return
    end if
    do r = 1, merge(neq, 0, npair > 0)         ! the sides, by row
      e = npad * (r - 1)
      do p = rwp(r), rwp(r + 1) - 1
        j = rwe(p); c = npad * (rwc(p) - 1); a = p1(j)
        if (both) then
          v = 2 * p2(j)
          do g = 1, npad
            rhs(e + g) = rhs(e + g) - a * st(c + g) - v * sdt(c + g)
          end do
        else
          do g = 1, npad
            rhs(e + g) = rhs(e + g) - a * st(c + g)
          end do
        end if
      end do
    end do
    if (.not. both) then                       ! nu_p - J_p q_dot - Hv s
      do n = n, nnz
        e = npad * (nzr(n) - 1); c = npad * (nzc(n) - 1); v = h1(n)
        do g = 0, npad - 4, 4
          rhs(e + g + 1) = rhs(e + g + 1) - v * st(c + g + 1)
          rhs(e + g + 2) = rhs(e + g + 2) - v * st(c + g + 2)
          rhs(e + g + 3) = rhs(e + g + 3) - v * st(c + g + 3)
          rhs(e + g + 4) = rhs(e + g + 4) - v * st(c + g + 4)
        end do
      end do
      return
    end if
    do n = n, nnz                              ! gamma_p - J_p q_ddot - Ha s - 2 Hv s_dot
      e = npad * (nzr(n) - 1); c = npad * (nzc(n) - 1); a = h1(n); v = 2 * h2(n)
      do g = 0, npad - 4, 4
        rhs(e + g + 1) = rhs(e + g + 1) - a * st(c + g + 1) - v * sdt(c + g + 1)
        rhs(e + g + 2) = rhs(e + g + 2) - a * st(c + g + 2) - v * sdt(c + g + 2)
        rhs(e + g + 3) = rhs(e + g + 3) - a * st(c + g + 3) - v * sdt(c + g + 3)
        rhs(e + g + 4) = rhs(e + g + 4) - a * st(c + g + 4) - v * sdt(c + g + 4)
      end do
    end do
  end subroutine kin_rhs_kernel

  !> kin_rhs_kernel's sides for npad = 4, row by row: rhs(:, r) = base(:, r) - the sum over
  !! the row's entries of h1 s(:, c) (+ 2 h2 s_dot(:, c) when both), kept in registers.
  pure subroutine rhs_rows(neq, rwp, rwe, rwc, h1, h2, both, base, st, sdt, rhs)
    integer, intent(in) :: neq, rwp(neq + 1), rwe(*), rwc(*)
    real(wp), intent(in) :: h1(*), h2(*), base(4, neq), st(4, *), sdt(4, *)
    logical, intent(in) :: both
    real(wp), intent(out) :: rhs(4, neq)
    integer :: r, p, j, c
    real(wp) :: a, v, t1, t2, t3, t4
    if (.not. both) then                       ! nu_p - J_p q_dot - Hv s
      do r = 1, neq
        t1 = base(1, r); t2 = base(2, r); t3 = base(3, r); t4 = base(4, r)
        do p = rwp(r), rwp(r + 1) - 1
          j = rwe(p); c = rwc(p); a = h1(j)
          t1 = t1 - a * st(1, c); t2 = t2 - a * st(2, c)
          t3 = t3 - a * st(3, c); t4 = t4 - a * st(4, c)
        end do
        rhs(1, r) = t1; rhs(2, r) = t2; rhs(3, r) = t3; rhs(4, r) = t4
      end do
      return
    end if
    do r = 1, neq                              ! gamma_p - J_p q_ddot - Ha s - 2 Hv s_dot
      t1 = base(1, r); t2 = base(2, r); t3 = base(3, r); t4 = base(4, r)
      do p = rwp(r), rwp(r + 1) - 1
        j = rwe(p); c = rwc(p); a = h1(j); v = 2 * h2(j)
        t1 = t1 - a * st(1, c) - v * sdt(1, c); t2 = t2 - a * st(2, c) - v * sdt(2, c)
        t3 = t3 - a * st(3, c) - v * sdt(3, c); t4 = t4 - a * st(4, c) - v * sdt(4, c)
      end do
      rhs(1, r) = t1; rhs(2, r) = t2; rhs(3, r) = t3; rhs(4, r) = t4
    end do
  end subroutine rhs_rows

  !> kin_rhs_kernel's nonzeros for npad = 4.
  pure subroutine rhs_four(nnz, nzr, nzc, h1, h2, both, st, sdt, rhs)
    integer, intent(in) :: nnz, nzr(*), nzc(*)
    real(wp), intent(in) :: h1(*), h2(*), st(4, *), sdt(4, *)
    logical, intent(in) :: both
    real(wp), intent(inout) :: rhs(4, *)
    integer :: n, r, c
    real(wp) :: v, a
    if (.not. both) then
      do n = 1, nnz
        r = nzr(n); c = nzc(n); v = h1(n)
        rhs(1, r) = rhs(1, r) - v * st(1, c); rhs(2, r) = rhs(2, r) - v * st(2, c)
        rhs(3, r) = rhs(3, r) - v * st(3, c); rhs(4, r) = rhs(4, r) - v * st(4, c)
      end do
      return
    end if
    do n = 1, nnz
      r = nzr(n); c = nzc(n); a = h1(n); v = 2 * h2(n)
      rhs(1, r) = rhs(1, r) - a * st(1, c) - v * sdt(1, c)
      rhs(2, r) = rhs(2, r) - a * st(2, c) - v * sdt(2, c)
      rhs(3, r) = rhs(3, r) - a * st(3, c) - v * sdt(3, c)
      rhs(4, r) = rhs(4, r) - a * st(4, c) - v * sdt(4, c)
    end do
  end subroutine rhs_four

  !> rhs = base - sum over the nonzeros n >= first of h1 S (- 2 h2 S_dot when both), a
  !! row per parameter (npd, neq; S, S_dot as rows st, sdt (npd, nq)): sens_kin_rhs on
  !! explicit arrays, from entry first (first = 2 ns + 1 leaves the ns revolute sides'
  !! entries, the first ones, to sens_revolute_rows).
  pure subroutine sens_rows_rhs(s, both, first, npd, nq, st, sdt, rhs)
    type(sens_t), intent(in) :: s            !! the nonzeros, the parameter parts
    logical, intent(in) :: both              !! level 3 (else 2: nu_p - J_p q_dot - Hv S)
    integer, intent(in) :: first, npd, nq    !! first entry, rows, coordinates
    real(wp), intent(in) :: st(npd * nq), sdt(npd * nq)  !! S, S_dot as rows
    real(wp), intent(inout) :: rhs(npd, *)   !! (npd, neq)
    integer :: n0
    n0 = first - 1
    if (both) then
      call kin_rhs_kernel(npd, size(s%ap, 2), nq, s%nnz - n0, 0, s%rwp, s%rwe, s%rwc, s%rsa, &
                          s%rsv, s%nzr(first:), s%nzc(first:), s%nza(first:), s%nzv(first:), &
                          .true., s%ap, st, sdt, rhs)
    else
      call kin_rhs_kernel(npd, size(s%vp, 2), nq, s%nnz - n0, 0, s%rwp, s%rwe, s%rwc, s%rsv, &
                          s%rsv, s%nzr(first:), s%nzc(first:), s%nzv(first:), s%nzv(first:), &
                          .false., s%vp, st, sdt, rhs)
    end if
  end subroutine sens_rows_rhs

  !> The revolutes' share of the dopri5 sensitivities' right-hand sides, every moving side
  !! at once from its closed form (revolute_second_side: h = d(theta column)/dtheta, hv, ha
  !! from the body states s%bst of sens_hessian): for side e (angle coordinate c, rows r0,
  !! r0 + 1),
  !!   rt(:, c) -= (lambda_r0 h_1 + lambda_r0+1 h_2) S(c, :)        (K_lambda S)
  !!   wk(:, r0 + i) -= ha_i S(c, :) + 2 hv_i S_dot(c, :),  i = 0, 1   (Ha S + 2 Hv S_dot)
  !! (S, S_dot as rows st, sdt (npd, nq); rt (npd, nq + ...), wk (npd, neq)).
  pure subroutine sens_revolute_rows(m, s, lam, npd, st, sdt, rt, wk)
    type(model_t), intent(in) :: m           !! model
    type(sens_t), intent(in) :: s            !! the sides, the body states
    real(wp), intent(in) :: lam(:)           !! multipliers (neq)
    integer, intent(in) :: npd               !! rows (a multiple of 4)
    real(wp), intent(in) :: st(npd, *), sdt(npd, *)  !! S, S_dot as rows
    real(wp), intent(inout) :: rt(npd, *), wk(npd, *)
    call revolute_second_rows(size(s%rsb), m%nb, npd, s%rso, s%rsb, s%rsg, s%rsq, s%rsr, m%p, &
                              s%bst, lam, st, sdt, rt, wk)
  end subroutine sens_revolute_rows

  !> The translationals' share of the dopri5 sensitivities' right-hand sides, from their
  !! closed forms (translational_second at the state: the first row's Hessian hm over the
  !! slots, hv = hm q_dot, ha = hm q_ddot - dgamma/dq; the second row is linear): with
  !! lambda the first row's multiplier and r that row,
  !!   rt(:, c_i) -= lambda hm(i, j) S(c_j, :)                 (K_lambda S)
  !!   wk(:, r) -= ha_j S(c_j, :) + 2 hv_j S_dot(c_j, :)         (Ha S + 2 Hv S_dot)
  !! over the slots i, j with a coordinate (S, S_dot as rows st, sdt (npd, nq)).
  pure subroutine sens_translational_rows(m, s, q, qd, qdd, lam, npd, st, sdt, rt, wk)
    type(model_t), intent(in) :: m           !! model
    type(sens_t), intent(in) :: s            !! the translationals, the body states
    real(wp), intent(in) :: q(:), qd(:), qdd(:)  !! state and accelerations
    real(wp), intent(in) :: lam(:)           !! multipliers (neq)
    integer, intent(in) :: npd               !! rows (a multiple of 4)
    real(wp), intent(in) :: st(npd, *), sdt(npd, *)  !! S, S_dot as rows
    real(wp), intent(inout) :: rt(npd, *), wk(npd, *)
    real(wp) :: qloc(NLOC), qdl(NLOC), qddl(NLOC), hm(6, 6), hvt(6), hat(6), la, kl, a1, v1
    integer :: e, k, r, i, j, ci, cj, g
    do e = 1, size(s%tlc)
      k = s%tlc(e); r = m%row0(k)
      call slot_values(m, k, q, qd, qdd, qloc, qdl, qddl)
      call translational_second(m%p(m%po(k):m%po(k) + 8), s%bst(1, m%bi(k)), &
                                s%bst(2, m%bi(k)), s%bst(1, m%bj(k)), s%bst(2, m%bj(k)), &
                                qloc(1:6), qdl(1:6), qddl(1:6), hm, hvt, hat)
      la = lam(r)
      do j = 1, 6
        cj = m%loc(j, k)
        if (cj == 0) cycle
        a1 = hat(j); v1 = 2 * hvt(j)
        do g = 0, npd - 4, 4
          call row4(a1, v1, st(g + 1, cj), sdt(g + 1, cj), wk(g + 1, r))
        end do
        do i = 1, 6
          ci = m%loc(i, k)
          if (ci == 0) cycle
          kl = la * hm(i, j)
          if (abs(kl) <= zero) cycle
          do g = 0, npd - 4, 4
            call row4(kl, zero, st(g + 1, cj), sdt(g + 1, cj), rt(g + 1, ci))
          end do
        end do
      end do
    end do
  end subroutine sens_translational_rows

  !> y(1:4) -= a x(1:4) + b z(1:4).
  pure subroutine row4(a, b, x, z, y)
    real(wp), intent(in) :: a, b, x(4), z(4)
    real(wp), intent(inout) :: y(4)
    y(1) = y(1) - a * x(1) - b * z(1); y(2) = y(2) - a * x(2) - b * z(2)
    y(3) = y(3) - a * x(3) - b * z(3); y(4) = y(4) - a * x(4) - b * z(4)
  end subroutine row4

  !> K_lambda = (J^T lambda)_q = sum over rows of lambda_r (Phi_r)_qq as a list of its
  !! nonzeros (row, column, value), from the local Hessian blocks (sens_hessian at the same q):
  !! each revolute side's (theta, theta) entry from its closed form (rsh), a translational's
  !! first row (its second is linear in q), the other constraints not linear in q in full.
  pure subroutine sens_klam_list(m, s, lam, closed)
    type(model_t), intent(in) :: m           !! model
    type(sens_t), intent(inout) :: s         !! Hessian blocks; the list (out)
    real(wp), intent(in) :: lam(:)           !! multipliers (neq)
    !> .false.: leave the revolutes and translationals out (sens_hessian's closed = .false.)
    logical, intent(in), optional :: closed
    integer :: k, e, r0, ns, nt
    real(wp) :: acc
    s%kln = 0
    ns = size(s%rsc); nt = size(s%tlc)
    if (present(closed)) then
      if (.not. closed) then
        ns = 0; nt = 0
      end if
    end if
    do e = 1, ns                               ! the revolutes' moving sides
      k = s%rsc(e); r0 = m%row0(k) - 1
      acc = lam(r0 + 1) * s%rsh(1, e) + lam(r0 + 2) * s%rsh(2, e)
      if (abs(acc) <= zero) cycle
      s%kln = s%kln + 1
      s%klr(s%kln) = m%loc(s%rss(e), k); s%klc(s%kln) = s%klr(s%kln); s%klv(s%kln) = acc
    end do
    do e = 1, nt
      call block_entries(m, s, lam, s%tlc(e), 1)
    end do
    do e = 1, size(s%gen)
      call block_entries(m, s, lam, s%gen(e), m%nrow(s%gen(e)))
    end do
  end subroutine sens_klam_list

  !> sens_klam_list's entries of constraint kk's block from its first nr rows.
  pure subroutine block_entries(m, s, lam, kk, nr)
    type(model_t), intent(in) :: m           !! model
    type(sens_t), intent(inout) :: s         !! Hessian blocks; the list (added)
    real(wp), intent(in) :: lam(:)           !! multipliers (neq)
    integer, intent(in) :: kk, nr            !! constraint, rows
    integer :: i, j, r, ci, cj, q0, na, ia, ja, act(NLOC)
    real(wp) :: a
    q0 = m%row0(kk) - 1
    na = 0
    do j = 1, NLOC                             ! the slots with a coordinate
      if (m%loc(j, kk) == 0) cycle
      na = na + 1; act(na) = j
    end do
    do ja = 1, na
      j = act(ja); cj = m%loc(j, kk)
      do ia = 1, na
        i = act(ia); ci = m%loc(i, kk)
        a = lam(q0 + 1) * s%hs(1, i, j, kk)
        do r = 2, nr
          a = a + lam(q0 + r) * s%hs(r, i, j, kk)
        end do
        if (abs(a) <= zero) cycle
        s%kln = s%kln + 1
        s%klr(s%kln) = ci; s%klc(s%kln) = cj; s%klv(s%kln) = a
      end do
    end do
  end subroutine block_entries

  !> y = K_lambda x from the list of sens_klam_list.
  pure subroutine sens_klam(s, x, y)
    type(sens_t), intent(in) :: s            !! the list
    real(wp), intent(in) :: x(:)             !! direction (nq)
    real(wp), intent(out) :: y(:)            !! (nq)
    integer :: n
    y = zero
    do n = 1, s%kln
      y(s%klr(n)) = y(s%klr(n)) + s%klv(n) * x(s%klc(n))
    end do
  end subroutine sens_klam

  !> y = J_p^T lambda for parameter k at (q, t), and (optionally) jpb, the change of the local
  !! J blocks (MAXROW, NLOC, nc) along the parameter (zero for unaffected constraints).
  pure subroutine sens_jpt_lam(m, s, k, q, t, lam, y, jpb)
    type(model_t), intent(in) :: m           !! model
    type(sens_t), intent(in) :: s            !! parameters
    integer, intent(in) :: k                 !! parameter
    real(wp), intent(in) :: q(:), t          !! configuration, time
    real(wp), intent(in) :: lam(:)           !! multipliers (neq)
    real(wp), intent(out) :: y(:)            !! (nq)
    real(wp), intent(out), contiguous, optional :: jpb(:, :, :)    !! (MAXROW, NLOC, nc)
    type(dloc) :: x
    real(wp) :: qddl(NLOC), tphi(MAXROW), tnu(MAXROW), tgam(MAXROW), jl(MAXROW, NLOC)
    integer :: c, si, sj, j, r, o
    if (present(jpb)) call zero_fill(size(jpb), jpb)   ! (one flat fill, not column fills)
    y = zero
    do c = 1, m%nc
      if (.not. s%caff(c, k)) cycle
      jl = zero
      if (m%kind(c) == CON_REVOLUTE) then      ! J = [I, B_i s'_i, -I, -B_j s'_j]: J_p has
        o = m%po(c)                            ! B_i t s'_i, -B_j t s'_j (perp(A t s'))
        if (m%bi(c) > 0) jl(1:2, 3) = rperp(s%cb(m%bi(c)), s%sb(m%bi(c)), s%tp(o:o + 1, k))
        if (m%bj(c) > 0) jl(1:2, 6) = -rperp(s%cb(m%bj(c)), s%sb(m%bj(c)), &
                                             s%tp(o + 2:o + 3, k))
      else
        call gather(m, s, c, q, s%zq, s%zq, x, qddl)
        si = merge(1, 0, m%bi(c) > 0); sj = merge(2, 0, m%bj(c) > 0)
        call con_eval_d(m%kind(c), m%suba(c), m%subb(c), m%p(m%po(c):m%po(c) + m%pn(c) - 1), &
                        s%tp(m%po(c):m%po(c) + m%pn(c) - 1, k), si, sj, x, t, &
                        tphi, jl, tnu, tgam)
      end if
      do j = 1, NLOC
        if (m%loc(j, c) == 0) cycle
        do r = 1, m%nrow(c)
          y(m%loc(j, c)) = y(m%loc(j, c)) + jl(r, j) * lam(m%row0(c) + r - 1)
        end do
      end do
      if (present(jpb)) jpb(:, :, c) = jl
    end do
  contains
    !> perp(A v) = B v for the angle with cos cc, sin ss.
    pure function rperp(cc, ss, v) result(w)
      real(wp), intent(in) :: cc, ss, v(2)
      real(wp) :: w(2)
      w = [-(ss * v(1) + cc * v(2)), cc * v(1) - ss * v(2)]
    end function rperp
  end subroutine sens_jpt_lam

  !> Change of the applied generalized force Q along (dq, dq_dot) and parameter k
  !! (k = 0: no parameter change): forces by dual evaluation, gravity m g by the changes of
  !! the masses and of g.
  pure subroutine sens_force_d(m, s, k, q, qd, dq, dqd, t, y)
    type(model_t), intent(in) :: m           !! model with dynamics data
    type(sens_t), intent(in) :: s            !! parameters
    integer, intent(in) :: k                 !! parameter, or 0
    real(wp), intent(in) :: q(:), qd(:)      !! state
    real(wp), intent(in) :: dq(:), dqd(:)    !! direction
    real(wp), intent(in) :: t                !! time
    real(wp), intent(out) :: y(:)            !! (nq)
    call sens_force_dm(m, s, k, 1, q, qd, m%nq, dq, dqd, t, y)
  end subroutine sens_force_d

  !> The change of the applied generalized forces per unit rate of parameter k, Q_p_dot
  !! (force_rate_d: a spring-damper's points moving in their bodies; zero for every other
  !! parameter): the frequency response's and the linearized system's rate forcing.
  pure subroutine sens_force_rate(m, s, k, q, qd, t, y)
    type(model_t), intent(in) :: m           !! model with dynamics data
    type(sens_t), intent(in) :: s            !! parameters
    integer, intent(in) :: k                 !! parameter
    real(wp), intent(in) :: q(:), qd(:)      !! state
    real(wp), intent(in) :: t                !! time
    real(wp), intent(out) :: y(:)            !! (nq) Q_p_dot
    real(wp) :: ql(NLOC), qdl(NLOC), fl(NLOC)
    integer :: f, j, c, si, sj, n0, n1
    y = zero
    do f = 1, m%nf
      if (.not. s%faff(f, k)) cycle
      n0 = m%fpo(f); n1 = n0 + m%fpn(f) - 1
      si = merge(1, 0, m%fbi(f) > 0); sj = merge(2, 0, m%fbj(f) > 0)
      call force_slots(m, f, q, qd, ql, qdl)
      call force_rate_d(m%fkind(f), m%fp(n0:n1), s%tfp(n0:n1, k), si, sj, ql, qdl, t, fl)
      do j = 1, NLOC
        c = m%floc(j, f)
        if (c > 0) y(c) = y(c) + fl(j)
      end do
    end do
  end subroutine sens_force_rate

  !> sens_force_d along nk directions at one state, column j of dq, dqd with the parameter
  !! k0 + j - 1 (k0 = 0: no parameter, nk = 1): each force's state gathered once and a
  !! spring's values computed once for up to four directions (force_eval_dm).
  pure subroutine sens_force_dm(m, s, k0, nk, q, qd, nq, dq, dqd, t, y)
    type(model_t), intent(in) :: m           !! model with dynamics data
    type(sens_t), intent(in) :: s            !! parameters
    integer, intent(in) :: k0, nk            !! first parameter (or 0), directions
    real(wp), intent(in) :: q(:), qd(:)      !! state
    integer, intent(in) :: nq                !! coordinates
    real(wp), intent(in) :: dq(nq, nk), dqd(nq, nk)  !! directions
    real(wp), intent(in) :: t                !! time
    real(wp), intent(out) :: y(nq, nk)       !! changes of Q
    integer, parameter :: KB = 4             ! directions per force evaluation
    real(wp) :: ql(NLOC), qdl(NLOC), tql(NLOC, KB), tqdl(NLOC, KB), fl(NLOC, KB)
    logical, parameter :: none(KB) = .false.
    integer :: f, j, c, si, sj, k, n0, n1, g, ng
    if (k0 > 0) then                           ! m g changes with the masses and g (qg)
      y = s%qg(:, k0:k0 + nk - 1)
    else
      y = zero
    end if
    do f = 1, m%nf
      n0 = m%fpo(f); n1 = n0 + m%fpn(f) - 1
      si = merge(1, 0, m%fbi(f) > 0); sj = merge(2, 0, m%fbj(f) > 0)
      call force_slots(m, f, q, qd, ql, qdl)
      do g = 1, nk, KB
        ng = min(KB, nk - g + 1)
        tql = zero; tqdl = zero
        do j = 1, NLOC
          c = m%floc(j, f)
          if (c == 0) cycle
          do k = 1, ng
            tql(j, k) = dq(c, g + k - 1); tqdl(j, k) = dqd(c, g + k - 1)
          end do
        end do
        if (k0 > 0) then
          call force_eval_dm(m%fkind(f), m%fp(n0:n1), s%tfp(n0:n1, k0 + g - 1:k0 + g + ng - 2), &
                             s%faff(f, k0 + g - 1:k0 + g + ng - 2), si, sj, ql, qdl, &
                             tql(:, 1:ng), tqdl(:, 1:ng), t, fl(:, 1:ng))
        else
          call force_eval_dm(m%fkind(f), m%fp(n0:n1), s%zfp(n0:n1, 1:ng), none(1:ng), si, sj, &
                             ql, qdl, tql(:, 1:ng), tqdl(:, 1:ng), t, fl(:, 1:ng))
        end if
        do j = 1, NLOC
          c = m%floc(j, f)
          if (c == 0) cycle
          do k = 1, ng
            y(c, g + k - 1) = y(c, g + k - 1) + fl(j, k)
          end do
        end do
      end do
    end do
  end subroutine sens_force_dm

  !> The changes of the applied generalized forces along every parameter's sensitivity,
  !! added to rt(:, 1:nq) (a row per parameter, npad rows, a multiple of 4; the rows past
  !! np stay as they are): along (S, S_dot) given as rows st, sdt (npad, nq) and by the
  !! parameters' own changes (force_rows_d, four parameters at a time), and the change of
  !! m g (qg). The bodies' cos and sin at q from s%cb, s%sb (sens_trig or the assembly's).
  pure subroutine sens_force_rows(m, s, q, qd, t, npad, st, sdt, rt, grav)
    type(model_t), intent(in) :: m           !! model with dynamics data
    type(sens_t), intent(in) :: s            !! parameters
    real(wp), intent(in) :: q(:), qd(:)      !! state
    real(wp), intent(in) :: t                !! time
    integer, intent(in) :: npad              !! rows
    real(wp), intent(in) :: st(npad, *), sdt(npad, *)  !! S, S_dot as rows
    real(wp), intent(inout) :: rt(npad, *)   !! right-hand sides as rows
    logical, intent(in), optional :: grav    !! .false.: leave d(m g) out (the caller has it)
    real(wp) :: ql(NLOC), qdl(NLOC), tqr(4, NLOC), tqdr(4, NLOC), tfr(4, NLOC), cs(2), sn(2)
    integer :: f, j, c, si, sj, n0, n1, g, ng
    logical :: addg
    addg = s%anyg
    if (present(grav)) addg = addg .and. grav
    if (addg) call add_flat(npad * m%nq, s%qgr, rt)   ! d(m g): the masses' and g's changes
    do f = 1, m%nf
      n0 = m%fpo(f); n1 = n0 + m%fpn(f) - 1
      si = merge(1, 0, m%fbi(f) > 0); sj = merge(2, 0, m%fbj(f) > 0)
      cs(1) = s%cb(m%fbi(f)); cs(2) = s%cb(m%fbj(f))
      sn(1) = s%sb(m%fbi(f)); sn(2) = s%sb(m%fbj(f))
      call force_slots(m, f, q, qd, ql, qdl)
      tqr = zero; tqdr = zero                  ! (the slots without a coordinate stay zero)
      do g = 0, npad - 4, 4
        ng = min(4, s%np - g)
        do j = 1, NLOC
          c = m%floc(j, f)
          if (c == 0) cycle
          tqr(1, j) = st(g + 1, c); tqr(2, j) = st(g + 2, c)
          tqr(3, j) = st(g + 3, c); tqr(4, j) = st(g + 4, c)
          tqdr(1, j) = sdt(g + 1, c); tqdr(2, j) = sdt(g + 2, c)
          tqdr(3, j) = sdt(g + 3, c); tqdr(4, j) = sdt(g + 4, c)
        end do
        call force_rows_d(m%fkind(f), m%fp(n0:n1), s%tfp(n0:n1, g + 1:g + ng), &
                          s%fcode(g + 1:g + ng, f), si, sj, ql, qdl, ng, tqr, tqdr, t, tfr, &
                          cs, sn)
        do j = 1, NLOC
          c = m%floc(j, f)
          if (c == 0) cycle
          rt(g + 1, c) = rt(g + 1, c) + tfr(1, j); rt(g + 2, c) = rt(g + 2, c) + tfr(2, j)
          rt(g + 3, c) = rt(g + 3, c) + tfr(3, j); rt(g + 4, c) = rt(g + 4, c) + tfr(4, j)
        end do
      end do
    end do
  end subroutine sens_force_rows

  !> Force f's local coordinates and velocities (zero in the slots without a coordinate).
  pure subroutine force_slots(m, f, q, qd, ql, qdl)
    type(model_t), intent(in) :: m           !! model with dynamics data
    integer, intent(in) :: f                 !! force
    real(wp), intent(in) :: q(:), qd(:)      !! state
    real(wp), intent(out) :: ql(NLOC), qdl(NLOC)
    integer :: j, c
    do j = 1, NLOC
      c = m%floc(j, f)
      ql(j) = zero; qdl(j) = zero
      if (c > 0) then
        ql(j) = q(c); qdl(j) = qd(c)
      end if
    end do
  end subroutine force_slots

  !> b(1:n) += a(1:n), flat.
  pure subroutine add_flat(n, a, b)
    integer, intent(in) :: n
    real(wp), intent(in) :: a(n)
    real(wp), intent(inout) :: b(n)
    integer :: i
    do i = 1, n
      b(i) = b(i) + a(i)
    end do
  end subroutine add_flat

  !> Dense Jacobians of the applied forces, kq = dQ/dq and (optionally) kv = dQ/dq_dot,
  !! from the dual evaluation of each force along its slots (nq x nq each).
  pure subroutine sens_force_jac(m, q, qd, t, kq, kv)
    type(model_t), intent(in) :: m           !! model with dynamics data
    real(wp), intent(in) :: q(:), qd(:)      !! state
    real(wp), intent(in) :: t                !! time
    real(wp), intent(out) :: kq(:, :)        !! dQ/dq
    real(wp), intent(out), optional :: kv(:, :)  !! dQ/dq_dot
    real(wp) :: ql(NLOC), qdl(NLOC), e(NLOC), fl(NLOC), tpz(size(m%fp))
    real(wp), parameter :: z(NLOC) = zero
    integer :: f, i, j, c, si, sj
    kq = zero
    if (present(kv)) kv = zero
    tpz = zero
    do f = 1, m%nf
      call force_slots(m, f, q, qd, ql, qdl)
      si = merge(1, 0, m%fbi(f) > 0); sj = merge(2, 0, m%fbj(f) > 0)
      do j = 1, NLOC
        c = m%floc(j, f)
        if (c == 0) cycle
        e = zero; e(j) = one
        call force_eval_d(m%fkind(f), m%fp(m%fpo(f):m%fpo(f) + m%fpn(f) - 1), &
                          tpz(m%fpo(f):m%fpo(f) + m%fpn(f) - 1), si, sj, ql, qdl, e, z, t, fl)
        do i = 1, NLOC
          if (m%floc(i, f) > 0) kq(m%floc(i, f), c) = kq(m%floc(i, f), c) + fl(i)
        end do
        if (present(kv)) then
          call force_eval_d(m%fkind(f), m%fp(m%fpo(f):m%fpo(f) + m%fpn(f) - 1), &
                            tpz(m%fpo(f):m%fpo(f) + m%fpn(f) - 1), si, sj, ql, qdl, z, e, t, fl)
          do i = 1, NLOC
            if (m%floc(i, f) > 0) kv(m%floc(i, f), c) = kv(m%floc(i, f), c) + fl(i)
          end do
        end if
      end do
    end do
  end subroutine sens_force_jac

end module mbd_sensitivity
