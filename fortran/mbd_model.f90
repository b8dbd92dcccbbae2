!> mbd_model: the model built from the flat tables that Python and the .mbd file hand over.
!!
!! Flat tables (the contract with the front ends):
!!   nb               number of moving bodies; q = [x1 y1 th1 ... x_nb y_nb th_nb, extras]
!!   ctab(NCT, nc)    one column per constraint (joints and drivers, in row order):
!!                    1 kind, 2 body i, 3 body j (1-based, 0 = ground), 4 sub-kind a,
!!                    5 sub-kind b, 6 offset of its raw parameters in rpar (1-based),
!!                    7 number of raw parameters, 8 reserved (0)
!!                    sub-kind a: cam profile kind; absolute driver or constraint: coordinate
!!                    (1 x, 2 y, 3 theta); relative-distance driver: the index of its
!!                    translational joint; gear: the carrier body (0 ground)
!!                    sub-kind b: cam follower kind; gear: 1 external, 2 internal
!!   rpar(:)          raw real parameters (layouts in each joint module's banner)
!! Extra coordinates (cam contact parameters) follow the body coordinates in constraint order.
!! For dynamics (model_add_dynamics):
!!   bmass(2, nb)     mass and moment of inertia about the centre of mass (>= 0)
!!   grav(2)          gravity vector
!!   ftab(NFT, nf)    one column per force element: 1 kind, 2 body i, 3 body j (0 = ground),
!!                    4 offset of its raw parameters in fpar, 5 their number, 6 the joint
!!                    (constraint index) of a joint friction element (kind FRC_FRICTION; its
!!                    bodies are the joint's), else 0
!!   fpar(:)          raw force parameters (layouts in mbd_forces)
!! Nondimensional models (model_build with nondim): the analyses work in units of the model's
!! length scale L (lref: the largest joint point, size or position, or with forces spring
!! point or length, rounded down to a power of 2; 1 when there is none), so every tolerance
!! and rank test is the same for a mechanism in micrometres or in
!! thousands of kilometres. Lengths are divided by L, masses multiplied by L**2, forces by L
!! (the generalized forces conjugate to x / L; each parameter p becomes p L**e, e from
!! con_exponents and force_exponents), gravity divided by L; angles, inertias, torques,
!! times and energies are unchanged. Back in model units: q = q' cunit, and lambda =
!! lambda' / rowunit (rowunit = L**power of each row's Phi). Powers of 2 make every
!! conversion exact. The largest length must lie in [LSCALE_MIN, LSCALE_MAX].
module mbd_model
  use mbd_kinds, only: wp, one
  use mbd_status, only: MBD_OK, MBD_BAD_INPUT, MBD_BAD_BODY, MBD_BAD_PARAM, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_fail
  use mbd_points, only: NLOC
  use mbd_constraints, only: con_known, con_nrow, con_nextra, con_raw_length, &
                             con_prepare, con_name, con_exponents, con_row_power, &
                             con_is_driver, con_next_break, &
                             CON_REVOLUTE, CON_TRANSLATIONAL, CON_CAM, &
                             CON_GEAR, CON_ABSOLUTE, CON_POINT_LINE, DRV_ABS, DRV_REL_DIST
  use mbd_joint_gear, only: CARRIER_SLOT
  use mbd_forces, only: force_known, force_raw_length, force_prepare, force_exponents, &
                        FRC_TORQUE, FRC_POINT, FRC_FRICTION, force_is_contact, force_next_break
  use mbd_contact, only: friction_prepare, FRIC_STICK_SLIP
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: NCT, NFT, model_t, model_build, model_slots, model_add_dynamics
  public :: LSCALE_MIN, LSCALE_MAX, model_force_size, model_next_break

  integer, parameter :: NCT = 8   !! rows of the constraint table
  integer, parameter :: NFT = 6   !! rows of the force table
  integer, parameter :: MAX_BODIES = 1000000   !! keeps 3 nb and the row counts in range
  character(len=*), parameter :: HINT = 'use a smaller model'
  !> the range of length scales a nondimensional model accepts (model units)
  real(wp), parameter :: LSCALE_MIN = 1.0e-12_wp, LSCALE_MAX = 1.0e12_wp

  !> A built model: constraint data in prepared form and the row and column maps.
  type :: model_t
    integer :: nb = 0                     !! moving bodies
    integer :: nc = 0                     !! constraints (joints and drivers)
    integer :: nq = 0                     !! coordinates, body and extra
    integer :: neq = 0                    !! constraint equations
    integer, allocatable :: kind(:)       !! kind code of each constraint
    integer, allocatable :: suba(:), subb(:)  !! sub-kinds
    integer, allocatable :: bi(:), bj(:)  !! body indices (0 = ground)
    integer, allocatable :: row0(:)       !! first row of each constraint
    integer, allocatable :: nrow(:)       !! rows of each constraint
    integer, allocatable :: loc(:, :)     !! (NLOC, nc) local slot -> global coordinate, 0 none
    integer, allocatable :: po(:), pn(:)  !! prepared parameters: offset and length in p
    integer, allocatable :: con_of_row(:) !! constraint owning each row
    real(wp), allocatable :: p(:)         !! prepared parameter pool
    real(wp) :: lscale = one              !! length scale of the model (tolerances)
    real(wp) :: lref = one                !! unit of the core's lengths in model units (L)
    real(wp), allocatable :: cunit(:)     !! (nq) unit of each coordinate: L for x, y; 1
    real(wp), allocatable :: rowunit(:)   !! (neq) unit of each row of Phi: L**power
    ! dynamics (model_add_dynamics)
    real(wp), allocatable :: mdiag(:)     !! diagonal mass matrix (nq; extras massless)
    real(wp) :: grav(2) = 0.0_wp          !! gravity
    integer :: nf = 0                     !! force elements
    integer, allocatable :: fkind(:), fbi(:), fbj(:)  !! kind and bodies of each force
    integer, allocatable :: floc(:, :)    !! (NLOC, nf) local slot -> global coordinate
    integer, allocatable :: fpo(:), fpn(:)  !! prepared force parameters: offset and length
    real(wp), allocatable :: fp(:)        !! prepared force parameter pool
    integer, allocatable :: fref(:)       !! joint of a joint friction element, else 0
    integer :: ncontact = 0               !! contact elements
    integer :: nfric = 0                  !! joint friction elements
    integer :: nstick = 0                 !! of which stick-slip
  end type model_t

contains

  !> The first time after t at which a driver's function of time, and with forces a force's,
  !! has a breakpoint (a motion law's start or end, a table's ends: the second derivative may
  !! jump there; huge when none). The kinematic loop (drivers) and the adaptive integrators
  !! (drivers and forces) end a step on it.
  pure real(wp) function model_next_break(m, t, forces) result(tb)
    type(model_t), intent(in) :: m     !! model
    real(wp), intent(in) :: t          !! time
    logical, intent(in) :: forces      !! the forces' functions too (a model with dynamics)
    integer :: c, f
    tb = huge(t)
    do c = 1, m%nc
      if (con_is_driver(m%kind(c))) &
        tb = min(tb, con_next_break(m%kind(c), m%p(m%po(c):m%po(c) + m%pn(c) - 1), t))
    end do
    if (.not. forces) return
    do f = 1, m%nf
      tb = min(tb, force_next_break(m%fkind(f), m%fp(m%fpo(f):m%fpo(f) + m%fpn(f) - 1), t))
    end do
  end function model_next_break

  !> Slot ids of a constraint's two bodies (0 = ground, 1, 2).
  pure subroutine model_slots(m, k, si, sj)
    type(model_t), intent(in) :: m    !! model
    integer, intent(in) :: k          !! constraint index
    integer, intent(out) :: si, sj    !! slot ids
    si = 0; sj = 0
    if (m%bi(k) > 0) si = 1
    if (m%bj(k) > 0) sj = 2
  end subroutine model_slots

  !> 1 <= off and off + len - 1 <= n, tested without overflow.
  pure logical function slice_ok(off, len, n)
    integer, intent(in) :: off, len, n
    slice_ok = off >= 1 .and. len >= 0 .and. len <= n
    if (slice_ok) slice_ok = off <= n - len + 1
  end function slice_ok

  !> Validate the flat tables and build the model.
  !! bad returns the 1-based index of the offending constraint (0 when none or global).
  subroutine model_build(nb, ctab, rpar, m, status, msg, bad, nondim, lforce)
    integer, intent(in) :: nb                   !! number of moving bodies
    integer, intent(in) :: ctab(:, :)           !! constraint table (NCT x nc)
    real(wp), intent(in) :: rpar(:)             !! raw parameters
    type(model_t), intent(out) :: m             !! the built model
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer, intent(out) :: bad                 !! offending constraint, or 0
    logical, intent(in), optional :: nondim     !! in units of the length scale (see banner)
    !> largest point or length of the force elements (model_force_size), also geometry
    real(wp), intent(in), optional :: lforce
    integer :: nc, k, kind, bi, bj, off, len, nexp, row, extra, ref, total, r, ierr
    real(wp), allocatable :: prep(:), pool(:), refp(:)
    ! work arrays for one constraint's raw parameters, allocated once (size(rpar) bounds
    ! every well-formed slice): exponents, geometry mask, parameters in the model's units
    real(wp), allocatable :: raw(:)
    integer, allocatable :: ex(:)
    logical, allocatable :: geom(:)
    real(wp) :: rref(8)
    character(len=MSG_LEN) :: sub

    status = MBD_OK; msg = ''; bad = 0
    if (size(ctab, 1) /= NCT) then
      status = MBD_BAD_INPUT; write (msg, '(a,i0,a)') 'constraint table must have ', NCT, ' rows'
      return
    end if
    nc = size(ctab, 2)
    if (nb < 1) then
      status = MBD_BAD_INPUT; msg = 'the model has no moving bodies'; return
    end if
    if (nb > MAX_BODIES .or. nc > 3 * MAX_BODIES) then
      status = MBD_BAD_INPUT; msg = 'the model is too large for the dense solver'; return
    end if
    ! no constraints at all: free bodies (a dynamic model held together by contacts); the
    ! front end allows it only then, and kinematics rejects it by its count of equations
    m%nb = nb; m%nc = nc
    allocate (m%kind(nc), m%suba(nc), m%subb(nc), m%bi(nc), m%bj(nc), stat=ierr)
    if (ierr == 0) allocate (m%row0(nc), m%nrow(nc), m%loc(NLOC, nc), stat=ierr)
    if (ierr == 0) allocate (m%po(nc), m%pn(nc), pool(8 * nc), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(4 * (NLOC + 9 + 16) * real(nc, wp), 'the constraint tables', HINT, &
                    status, msg)
      return
    end if
    allocate (raw(size(rpar)), ex(size(rpar)), geom(size(rpar)), stat=ierr)
    if (ierr /= 0) then
      call mem_fail((REAL_BYTES + 8) * size(rpar), 'the constraint parameters', HINT, &
                    status, msg)
      return
    end if
    if (present(nondim)) then
      if (nondim) call choose_lref(status)
      if (status /= MBD_OK) return
    end if
    row = 0; extra = 0; total = 0
    do k = 1, nc
      kind = ctab(1, k); bi = ctab(2, k); bj = ctab(3, k)
      off = ctab(6, k); len = ctab(7, k)
      bad = k
      if (.not. con_known(kind)) then
        status = MBD_BAD_INPUT; write (msg, '(a,i0)') 'unknown constraint kind ', kind; return
      end if
      ! bodies
      if (bi < 0 .or. bi > nb .or. bj < 0 .or. bj > nb) then
        status = MBD_BAD_BODY
        write (msg, '(a,i0,a,i0,a,i0)') 'body index out of range: ', bi, ', ', bj, &
          '; bodies are 0 (ground) to ', nb
        return
      end if
      select case (kind)
      case (DRV_ABS, CON_ABSOLUTE)
        if (bi == 0) then
          status = MBD_BAD_BODY; msg = trim(con_name(kind)) // ' needs a moving body, not ground'
          return
        end if
        if (ctab(4, k) < 1 .or. ctab(4, k) > 3) then
          status = MBD_BAD_PARAM
          msg = trim(con_name(kind)) // ' coordinate must be 1 (x), 2 (y) or 3 (theta)'
          return
        end if
        bj = 0
      case (DRV_REL_DIST)
        ref = ctab(4, k)
        if (ref < 1 .or. ref > nc) then
          status = MBD_BAD_INPUT; msg = 'relative-distance driver refers to no joint'; return
        end if
        if (ctab(1, ref) /= CON_TRANSLATIONAL) then
          status = MBD_BAD_INPUT
          msg = 'relative-distance driver must refer to a translational joint'; return
        end if
        if (ctab(7, ref) /= 8 .or. .not. slice_ok(ctab(6, ref), 8, size(rpar))) then
          status = MBD_BAD_INPUT
          msg = 'the translational joint of a relative-distance driver is malformed'; return
        end if
        bi = ctab(2, ref); bj = ctab(3, ref)
      case default
        if (bi == bj) then
          status = MBD_BAD_BODY
          if (bi == 0) then
            msg = 'both bodies are ground'
          else
            msg = 'a body is joined to itself'
          end if
          return
        end if
      end select
      if (kind == CON_GEAR) then
        if (ctab(4, k) < 0 .or. ctab(4, k) > nb) then
          status = MBD_BAD_BODY; msg = 'gear carrier body index out of range'; return
        end if
        if (ctab(4, k) > 0 .and. (ctab(4, k) == bi .or. ctab(4, k) == bj)) then
          status = MBD_BAD_BODY; msg = 'a gear cannot be its own carrier'; return
        end if
      end if
      if (kind == CON_CAM) then
        if (ctab(4, k) < 1 .or. ctab(4, k) > 3 .or. ctab(5, k) < 1 .or. ctab(5, k) > 3) then
          status = MBD_BAD_PARAM; msg = 'cam profile or follower kind out of range'; return
        end if
      end if
      ! parameters (written so that no sum can overflow)
      if (.not. slice_ok(off, len, size(rpar))) then
        status = MBD_BAD_INPUT; msg = 'parameter slice outside the parameter array'; return
      end if
      nexp = con_raw_length(kind, ctab(4, k), rpar(off:off + len - 1))
      if (nexp /= len) then
        status = MBD_BAD_PARAM
        write (msg, '(a,i0,a,i0,a)') 'has ', len, ' parameters, expected ', nexp, &
          ' (-1: malformed)'
        msg = trim(con_name(kind)) // ' ' // trim(msg)
        return
      end if
      call scale_raw(kind, ctab(4, k), ctab(5, k), rpar(off:off + len - 1), raw(1:len))
      if (kind == DRV_REL_DIST) then
        ! prepare the referenced joint again to read its prepared parameters
        call scale_raw(CON_TRANSLATIONAL, 0, 0, rpar(ctab(6, ref):ctab(6, ref) + 7), rref)
        call con_prepare(CON_TRANSLATIONAL, 0, 0, rref, [real(wp) ::], refp, status, sub)
        if (status == MBD_OK) then
          call con_prepare(kind, ctab(4, k), ctab(5, k), raw(1:len), refp, prep, status, sub)
        end if
      else
        call con_prepare(kind, ctab(4, k), ctab(5, k), raw(1:len), [real(wp) ::], prep, &
                         status, sub)
      end if
      if (status /= MBD_OK) then
        msg = trim(con_name(kind)) // ': ' // trim(sub); return
      end if
      ! length scale from joint points (cam: the follower point)
      if (kind == CON_REVOLUTE .or. kind == CON_TRANSLATIONAL .or. kind == CON_POINT_LINE) then
        m%lscale = max(m%lscale, maxval(abs(raw(1:4))))
      else if (kind == CON_CAM) then
        m%lscale = max(m%lscale, maxval(abs(raw(1:2))))
      end if
      m%kind(k) = kind; m%suba(k) = ctab(4, k); m%subb(k) = ctab(5, k)
      m%bi(k) = bi; m%bj(k) = bj
      m%row0(k) = row + 1; m%nrow(k) = con_nrow(kind); row = row + m%nrow(k)
      m%po(k) = total + 1; m%pn(k) = size(prep)
      call append(pool, total, prep, ierr)
      if (ierr /= 0) then
        bad = 0
        call mem_fail(2 * REAL_BYTES * (total + size(prep)), 'the constraint parameters', &
                      HINT, status, msg)
        return
      end if
      ! local slots -> global coordinates
      m%loc(:, k) = 0
      if (bi > 0) m%loc(1:3, k) = [3 * bi - 2, 3 * bi - 1, 3 * bi]
      if (bj > 0) m%loc(4:6, k) = [3 * bj - 2, 3 * bj - 1, 3 * bj]
      if (con_nextra(kind) > 0) then
        extra = extra + 1
        m%loc(7, k) = 3 * nb + extra
      end if
      if (kind == CON_GEAR .and. ctab(4, k) > 0) m%loc(CARRIER_SLOT, k) = 3 * ctab(4, k)
    end do
    bad = 0
    m%neq = row
    m%nq = 3 * nb + extra
    allocate (m%p(total), m%con_of_row(m%neq), m%rowunit(m%neq), m%cunit(m%nq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * (total + m%neq + m%nq) + 4 * real(m%neq, wp), &
                    'the constraint parameters', HINT, status, msg)
      return
    end if
    m%p = pool(1:total)
    do k = 1, nc
      m%con_of_row(m%row0(k):m%row0(k) + m%nrow(k) - 1) = k
      do r = 1, m%nrow(k)
        m%rowunit(m%row0(k) + r - 1) = m%lref**con_row_power(m%kind(k), m%suba(k), r)
      end do
    end do
    m%cunit = one
    do k = 1, nb
      m%cunit(3 * k - 2:3 * k - 1) = m%lref
    end do

  contains

    !> Raw parameters in the model's units: rs = rw L**e (rs = rw when L = 1); the
    !! exponents go to the host's ex (no allocation per call).
    subroutine scale_raw(kd, sa, sb, rw, rs)
      integer, intent(in) :: kd, sa, sb      !! constraint kind and sub-kinds
      real(wp), intent(in) :: rw(:)          !! raw parameters in model units
      real(wp), intent(out) :: rs(:)         !! (size(rw)) the same in the model's units
      integer :: n
      n = size(rw)
      rs = rw
      if (.not. (m%lref > one .or. m%lref < one)) return
      call con_exponents(kd, sa, sb, rw, ex(1:n), geom(1:n))
      rs = rw * m%lref**ex(1:n)
    end subroutine scale_raw

    !> L: the largest geometry entry of the well-formed constraints (and of the forces),
    !! rounded down to a power of 2 (1 when there is none); a largest entry outside
    !! [LSCALE_MIN, LSCALE_MAX] is a bad parameter (bad: the constraint that holds it).
    subroutine choose_lref(st)
      integer, intent(out) :: st
      real(wp) :: big
      character(len=12) :: bigtxt
      integer :: kk, o, n, kd, kbig
      st = MBD_OK; kbig = 0
      big = 0.0_wp
      do kk = 1, nc
        kd = ctab(1, kk); o = ctab(6, kk); n = ctab(7, kk)
        if (.not. con_known(kd) .or. .not. slice_ok(o, n, size(rpar))) cycle
        if (con_raw_length(kd, ctab(4, kk), rpar(o:o + n - 1)) /= n) cycle
        if (.not. all(ieee_is_finite(rpar(o:o + n - 1)))) cycle
        if (kd == CON_CAM .and. (ctab(4, kk) < 1 .or. ctab(4, kk) > 3)) cycle
        call con_exponents(kd, ctab(4, kk), ctab(5, kk), rpar(o:o + n - 1), ex(1:n), &
                           geom(1:n))
        if (any(geom(1:n))) then
          if (maxval(abs(rpar(o:o + n - 1)), mask=geom(1:n)) > big) then
            big = maxval(abs(rpar(o:o + n - 1)), mask=geom(1:n)); kbig = kk
          end if
        end if
      end do
      if (present(lforce)) then
        if (lforce > big) then
          big = lforce; kbig = 0
        end if
      end if
      if (.not. (big > 0.0_wp)) return
      if (big < LSCALE_MIN .or. big > LSCALE_MAX) then
        st = MBD_BAD_PARAM; bad = kbig
        ! (three exponent digits where needed: es9.2 writes 1e300 as "1.00+300")
        if (big >= 1.0e100_wp) then
          write (bigtxt, '(es10.2e3)') big
        else
          write (bigtxt, '(es9.2)') big
        end if
        write (msg, '(a,a,a,es8.1,a,es8.1,a)') 'the model''s length scale (its largest '// &
          'joint point, size or position) is ', trim(adjustl(bigtxt)), '; mbd2d works with '// &
          'length scales from ', LSCALE_MIN, ' to ', LSCALE_MAX, ': change the unit of length'
        return
      end if
      m%lref = 2.0_wp**(exponent(big) - 1)     ! L <= big < 2 L
    end subroutine choose_lref
  end subroutine model_build

  !> The largest point or length of the well-formed force elements (spring points and free
  !! lengths, points of point forces): geometry that sets a dynamic model's length scale.
  pure real(wp) function model_force_size(ftab, fpar) result(big)
    integer, intent(in) :: ftab(:, :)           !! (NFT, nf) force table
    real(wp), intent(in) :: fpar(:)             !! raw force parameters
    integer :: k, kind, off, len
    integer :: ex(size(fpar))
    big = 0.0_wp
    if (size(ftab, 1) /= NFT) return
    do k = 1, size(ftab, 2)
      kind = ftab(1, k); off = ftab(4, k); len = ftab(5, k)
      if (.not. force_known(kind) .or. .not. slice_ok(off, len, size(fpar))) cycle
      if (force_raw_length(kind, fpar(off:off + len - 1)) /= len) cycle
      if (.not. all(ieee_is_finite(fpar(off:off + len - 1)))) cycle
      call force_exponents(kind, fpar(off:off + len - 1), ex(1:len))
      if (force_is_contact(kind)) ex(7) = 0        ! a threshold velocity, not a length
      if (kind == FRC_FRICTION) ex(4) = 0
      if (any(ex(1:len) == -1)) &
        big = max(big, maxval(abs(fpar(off:off + len - 1)), mask=ex(1:len) == -1))
    end do
  end function model_force_size

  !> Add masses, gravity and force elements to a built model (for dynamics and statics).
  !! bad returns the 1-based index of the offending force (0 when none, -k for body k).
  subroutine model_add_dynamics(m, bmass, grav, ftab, fpar, status, msg, bad)
    type(model_t), intent(inout) :: m           !! built model
    real(wp), intent(in) :: bmass(:, :)         !! (2, nb) mass, inertia
    real(wp), intent(in) :: grav(2)             !! gravity
    integer, intent(in) :: ftab(:, :)           !! (NFT, nf) force table
    real(wp), intent(in) :: fpar(:)             !! raw force parameters
    integer, intent(out) :: status              !! MBD_OK or < 0
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer, intent(out) :: bad                 !! offending force (> 0) or body (< 0)
    integer :: k, nf, kind, bi, bj, off, len, total, ierr, jc
    real(wp), allocatable :: prep(:), pool(:)
    ! one force's exponents and parameters in the model's units, allocated once
    real(wp), allocatable :: sc(:), fr(:)
    integer, allocatable :: ex(:)
    real(wp) :: meff
    character(len=MSG_LEN) :: sub
    status = MBD_OK; msg = ''; bad = 0
    if (size(bmass, 1) /= 2 .or. size(bmass, 2) /= m%nb .or. size(ftab, 1) /= NFT) then
      status = MBD_BAD_INPUT; msg = 'mass or force table has the wrong shape'; return
    end if
    allocate (m%mdiag(m%nq), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * m%nq, 'the mass matrix', HINT, status, msg); return
    end if
    m%mdiag = 0.0_wp
    do k = 1, m%nb
      if (.not. all(ieee_is_finite(bmass(:, k))) .or. .not. all(bmass(:, k) >= 0.0_wp)) then
        status = MBD_BAD_PARAM; bad = -k
        msg = 'mass and inertia must be finite and >= 0'; return
      end if
      m%mdiag(3 * k - 2:3 * k - 1) = bmass(1, k) * m%lref**2
      m%mdiag(3 * k) = bmass(2, k)
      if (.not. ieee_is_finite(m%mdiag(3 * k - 2))) then
        status = MBD_BAD_PARAM
        write (msg, '(a,i0,a)') 'the mass of body ', k, ' is too large for the model''s '// &
          'length scale'
        return
      end if
    end do
    if (.not. all(ieee_is_finite(grav))) then
      status = MBD_BAD_PARAM; msg = 'gravity must be finite'; return
    end if
    m%grav = grav / m%lref
    if (.not. all(ieee_is_finite(m%grav))) then
      status = MBD_BAD_PARAM; msg = 'gravity is too large for the model''s length scale'; return
    end if
    nf = size(ftab, 2)
    m%nf = nf
    allocate (m%fkind(nf), m%fbi(nf), m%fbj(nf), m%floc(NLOC, nf), stat=ierr)
    if (ierr == 0) allocate (m%fpo(nf), m%fpn(nf), m%fref(nf), pool(8 * nf), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(4 * (NLOC + 5 + 16) * real(nf, wp), 'the force tables', HINT, status, msg)
      return
    end if
    allocate (sc(size(fpar)), ex(size(fpar)), fr(size(fpar)), stat=ierr)
    if (ierr /= 0) then
      call mem_fail((REAL_BYTES + 4) * size(fpar), 'the force parameters', HINT, status, msg)
      return
    end if
    total = 0
    do k = 1, nf
      bad = k
      kind = ftab(1, k); bi = ftab(2, k); bj = ftab(3, k); off = ftab(4, k); len = ftab(5, k)
      if (.not. force_known(kind)) then
        status = MBD_BAD_INPUT; write (msg, '(a,i0)') 'unknown force kind ', kind; return
      end if
      if (bi < 0 .or. bi > m%nb .or. bj < 0 .or. bj > m%nb) then
        status = MBD_BAD_BODY; msg = 'force body index out of range'; return
      end if
      jc = 0
      if (kind == FRC_FRICTION) then
        jc = ftab(6, k)
        if (jc < 1 .or. jc > m%nc) then
          status = MBD_BAD_INPUT; msg = 'joint friction refers to no joint'; return
        end if
        if (m%kind(jc) /= CON_REVOLUTE .and. m%kind(jc) /= CON_TRANSLATIONAL) then
          status = MBD_BAD_INPUT
          msg = 'friction is available on revolute and translational joints'; return
        end if
        bi = m%bi(jc); bj = m%bj(jc)
      end if
      if (kind == FRC_TORQUE .or. kind == FRC_POINT) then
        bj = 0
        if (bi == 0) then
          status = MBD_BAD_BODY; msg = 'a torque or point force needs a moving body'; return
        end if
      else if (bi == bj) then
        status = MBD_BAD_BODY; msg = 'a spring needs two different bodies'; return
      end if
      if (.not. slice_ok(off, len, size(fpar))) then
        status = MBD_BAD_INPUT; msg = 'force parameter slice outside the parameter array'; return
      end if
      if (.not. all(ieee_is_finite(fpar(off:off + len - 1)))) then
        status = MBD_BAD_PARAM; msg = 'a force parameter is not a finite number'; return
      end if
      if (force_raw_length(kind, fpar(off:off + len - 1)) /= len) then
        status = MBD_BAD_PARAM; msg = 'force parameters are malformed'; return
      end if
      call force_exponents(kind, fpar(off:off + len - 1), ex(1:len), fr(1:len))
      sc(1:len) = fpar(off:off + len - 1) * m%lref**ex(1:len)
      if (any(abs(fr(1:len)) > 0.0_wp)) sc(1:len) = sc(1:len) * m%lref**fr(1:len)
      if (.not. all(ieee_is_finite(sc(1:len)))) then
        status = MBD_BAD_PARAM
        msg = 'a force parameter is too large for the model''s length scale'; return
      end if
      if (kind == FRC_FRICTION) then
        call friction_prepare(m%kind(jc) == CON_REVOLUTE, sc(1:len), prep, status, sub)
      else
        ! effective mass of a contact pair (ground: infinite)
        meff = 0.0_wp
        if (bi > 0 .and. bj > 0) then
          if (m%mdiag(3 * bi - 2) > 0.0_wp .and. m%mdiag(3 * bj - 2) > 0.0_wp) meff = &
            m%mdiag(3 * bi - 2) * m%mdiag(3 * bj - 2) / (m%mdiag(3 * bi - 2) + m%mdiag(3 * bj - 2))
        else if (bi > 0) then
          meff = m%mdiag(3 * bi - 2)
        else if (bj > 0) then
          meff = m%mdiag(3 * bj - 2)
        end if
        call force_prepare(kind, sc(1:len), prep, status, sub, meff)
      end if
      if (status /= MBD_OK) then
        msg = sub; return
      end if
      m%fkind(k) = kind; m%fbi(k) = bi; m%fbj(k) = bj
      m%fpo(k) = total + 1; m%fpn(k) = size(prep)
      call append(pool, total, prep, ierr)
      if (ierr /= 0) then
        bad = 0
        call mem_fail(2 * REAL_BYTES * (total + size(prep)), 'the force parameters', HINT, &
                      status, msg)
        return
      end if
      m%floc(:, k) = 0
      if (bi > 0) m%floc(1:3, k) = [3 * bi - 2, 3 * bi - 1, 3 * bi]
      if (bj > 0) m%floc(4:6, k) = [3 * bj - 2, 3 * bj - 1, 3 * bj]
      m%fref(k) = jc
      if (force_is_contact(kind)) m%ncontact = m%ncontact + 1
      if (kind == FRC_FRICTION) then
        m%nfric = m%nfric + 1
        if (nint(prep(3)) == FRIC_STICK_SLIP) m%nstick = m%nstick + 1
      end if
    end do
    bad = 0
    allocate (m%fp(total), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * total, 'the force parameters', HINT, status, msg); return
    end if
    m%fp = pool(1:total)
  end subroutine model_add_dynamics

  !> pool(total + 1:total + size(x)) = x, the capacity doubled when it runs out (a pool built
  !! by concatenation would cost O(nc**2) copies).
  pure subroutine append(pool, total, x, ierr)
    real(wp), allocatable, intent(inout) :: pool(:)  !! the pool (its size is the capacity)
    integer, intent(inout) :: total                  !! entries in use
    real(wp), intent(in) :: x(:)                     !! entries to add
    integer, intent(out) :: ierr                     !! allocation status (0 ok)
    real(wp), allocatable :: bigger(:)
    ierr = 0
    if (total + size(x) > size(pool)) then
      allocate (bigger(max(2 * size(pool), total + size(x), 16)), stat=ierr)
      if (ierr /= 0) return
      bigger(1:total) = pool(1:total)
      call move_alloc(bigger, pool)
    end if
    pool(total + 1:total + size(x)) = x
    total = total + size(x)
  end subroutine append

end module mbd_model
