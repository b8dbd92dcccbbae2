!> mbd_assemble: stack every constraint's rows into Phi, J, nu and gamma.
!!
!! Phi(q, t) = [Phi^K(q); Phi^D(q, t)],  J = Phi_q,  nu = -Phi_t,
!! gamma = -(J q_dot)_q q_dot - 2 Phi_qt q_dot - Phi_tt.
!! Each constraint writes its rows into slices of phi, nu, gam and its local Jacobian block
!! into jb(:, :, k); scatter_dense then places the blocks in a dense J through a map built
!! once (asm_init). No allocation here.
module mbd_assemble
  use mbd_kinds, only: wp, zero, one, half
  use mbd_status, only: MBD_OK, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_fail
  use mbd_points, only: NLOC, MAXROW, kloc
  use mbd_model, only: model_t, model_slots
  use mbd_constraints, only: con_eval, con_init_extra, CON_REVOLUTE
  use mbd_joint_revolute, only: revolute_rows, revolute_gamma_all, revolute_phi_all
  use mbd_drivers, only: DRV_ABS, driver_abs_row
  use mbd_functions, only: fun_eval
  implicit none
  private
  public :: asm_work_t, asm_init, assemble_blocks, scatter_dense, assemble_dense, init_extras, &
            gather_local, blocks_jv, blocks_jv_rows, blocks_jtv, blocks_jtv_rows_sub, &
            scatter_values, asm_turn, &
            assemble_gamma, assemble_phi

  !> Work arrays of the assembly, allocated once per analysis.
  type :: asm_work_t
    real(wp), allocatable :: jb(:, :, :)   !! local Jacobian blocks (MAXROW, NLOC, nc)
    real(wp), allocatable :: cb(:), sb(:)  !! cos and sin of each body's angle (0:nb; 0 ground)
    !> assemble_phi's anchors: an angle of each body and its cos and sin from the library
    !! (0:nb), from which nearby angles' cos and sin are turned (trig_near)
    real(wp), allocatable :: ta(:), ca(:), sa(:)
    real(wp), allocatable :: qx(:), qdx(:) !! q and q_dot with a zero in front (0:nq): slot
                                           !! loc = 0 reads the zero
    real(wp), allocatable :: fv(:)         !! absolute drivers' f(t) of assemble_phi (drv)
    !> assemble_phi's and assemble_gamma's lists: the revolutes (parameter offset, bodies,
    !! first row), the absolute drivers and the other constraints
    integer, allocatable :: rtab(:, :), drv(:), gen(:)
    !> the absolute drivers' row, driven coordinate, parameter offset and count (4, drv)
    integer, allocatable :: dtab(:, :)
    !> the nonzeros of the blocks: jb(src(i)) goes to J(dst(i)) and column col(i) (flat
    !! column-major indices into jb and the dense neq x nq J; dst = 0 when J has more than
    !! huge(1) entries)
    integer, allocatable :: src(:), dst(:), col(:)
  end type asm_work_t

contains

  !> Allocate the assembly work arrays for model m. The dense map (dst) is built only when
  !! the dense J has fewer than huge(1) entries (a larger one could not be allocated anyway).
  pure subroutine asm_init(m, a, status, msg)
    type(model_t), intent(in) :: m         !! model
    type(asm_work_t), intent(out) :: a     !! work arrays
    integer, intent(out) :: status         !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(inout) :: msg  !! explanation (on a failure)
    integer :: k, s, r, n, ierr
    logical :: dense_map
    status = MBD_OK
    n = 0
    do k = 1, m%nc
      n = n + m%nrow(k) * count(m%loc(:, k) > 0)
    end do
    allocate (a%jb(MAXROW, NLOC, m%nc), a%cb(0:m%nb), a%sb(0:m%nb), a%qx(0:m%nq), &
              a%qdx(0:m%nq), a%ta(0:m%nb), a%ca(0:m%nb), a%sa(0:m%nb), stat=ierr)
    if (ierr == 0) allocate (a%src(n), a%dst(n), a%col(n), stat=ierr)
    if (ierr == 0) allocate (a%rtab(4, count(m%kind(1:m%nc) == CON_REVOLUTE)), &
                             a%drv(count(m%kind(1:m%nc) == DRV_ABS)), &
                             a%dtab(4, count(m%kind(1:m%nc) == DRV_ABS)), &
                             a%fv(count(m%kind(1:m%nc) == DRV_ABS)), &
                             a%gen(count(m%kind(1:m%nc) /= CON_REVOLUTE .and. &
                                         m%kind(1:m%nc) /= DRV_ABS)), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * (MAXROW * NLOC * real(m%nc, wp) + 2 * real(m%nb, wp)) + &
                    12 * real(n, wp), 'the constraint blocks', 'use a smaller model', &
                    status, msg)
      return
    end if
    a%jb = zero
    a%cb = one; a%sb = zero; a%qx = zero; a%qdx = zero; a%fv = zero
    a%ta = huge(one); a%ca = one; a%sa = zero
    r = 0; s = 0; n = 0
    do k = 1, m%nc
      if (m%kind(k) == CON_REVOLUTE) then
        r = r + 1; a%rtab(:, r) = [m%po(k), m%bi(k), m%bj(k), m%row0(k)]
      else if (m%kind(k) == DRV_ABS) then
        s = s + 1; a%drv(s) = k
        a%dtab(:, s) = [m%row0(k), m%loc(m%suba(k), k), m%po(k), m%pn(k)]
      else
        n = n + 1; a%gen(n) = k
      end if
    end do
    dense_map = real(m%neq, wp) * real(m%nq, wp) < real(huge(n), wp)
    n = 0
    do k = 1, m%nc
      do s = 1, NLOC
        if (m%loc(s, k) == 0) cycle
        do r = 1, m%nrow(k)
          n = n + 1
          a%src(n) = r + MAXROW * (s - 1 + NLOC * (k - 1))
          a%col(n) = m%loc(s, k)
          a%dst(n) = 0
          if (dense_map) a%dst(n) = m%row0(k) + r - 1 + m%neq * (m%loc(s, k) - 1)
        end do
      end do
    end do
  end subroutine asm_init

  !> Local coordinates (and velocities) of constraint k.
  pure subroutine gather_local(m, k, q, ql)
    type(model_t), intent(in) :: m       !! model
    integer, intent(in) :: k             !! constraint
    real(wp), intent(in) :: q(:)         !! global vector
    real(wp), intent(out) :: ql(NLOC)    !! local vector
    integer :: s
    do s = 1, NLOC
      if (m%loc(s, k) > 0) then
        ql(s) = q(m%loc(s, k))
      else
        ql(s) = zero
      end if
    end do
  end subroutine gather_local

  !> Phi, nu, gamma and the local Jacobian blocks at (q, q_dot, t). The cosine and sine of
  !! each body's angle are computed once here (assemble_gamma reuses them at the same q).
  pure subroutine assemble_blocks(m, q, qd, t, phi, nu, gam, a)
    type(model_t), intent(in) :: m            !! model
    real(wp), intent(in) :: q(:)              !! coordinates (nq)
    real(wp), intent(in) :: qd(:)             !! velocities (nq), for gamma
    real(wp), intent(in) :: t                 !! time
    real(wp), intent(out) :: phi(:)           !! Phi (neq)
    real(wp), intent(out) :: nu(:)            !! nu (neq)
    real(wp), intent(out) :: gam(:)           !! gamma (neq)
    type(asm_work_t), intent(inout) :: a      !! work: blocks (out) and body cos, sin
    real(wp) :: ph(MAXROW), nv(MAXROW), ga(MAXROW)
    integer :: k, r0, nr, b
    do b = 1, m%nb
      a%cb(b) = cos(q(3 * b)); a%sb(b) = sin(q(3 * b))
    end do
    if (size(a%gen) > 0) call copy_state(m%nq, q, qd, a%qx, a%qdx)     ! (for eval_one)
    do k = 1, m%nc
      r0 = m%row0(k)
      if (m%kind(k) == CON_REVOLUTE) then
        ! the commonest joint from the bodies' states directly (the rows of revolute_eval)
        call revolute_rows(m%p(m%po(k)), m%bi(k), m%bj(k), q, qd, a%cb, a%sb, ph, &
                           a%jb(1, 1, k), ga)
        phi(r0) = ph(1); phi(r0 + 1) = ph(2); gam(r0) = ga(1); gam(r0 + 1) = ga(2)
        nu(r0) = zero; nu(r0 + 1) = zero
        cycle
      else if (m%kind(k) == DRV_ABS) then
        ! the commonest driver from its coordinate (the row of driver_eval)
        call driver_abs_row(m%suba(k), m%p(m%po(k):m%po(k) + m%pn(k) - 1), &
                            q(m%loc(m%suba(k), k)), t, phi(r0), a%jb(1, 1, k), nu(r0), &
                            gam(r0))
        cycle
      end if
      call eval_one(m, k, t, a, ph, nv, ga)
      nr = m%nrow(k)
      ! row by row (a slice copy of variable length would be three memcpy calls)
      phi(r0) = ph(1); nu(r0) = nv(1); gam(r0) = ga(1)
      if (nr >= 2) then
        phi(r0 + 1) = ph(2); nu(r0 + 1) = nv(2); gam(r0 + 1) = ga(2)
        if (nr >= 3) then
          phi(r0 + 2) = ph(3); nu(r0 + 2) = nv(3); gam(r0 + 2) = ga(3)
        end if
      end if
    end do
  end subroutine assemble_blocks

  !> a%qx = q, a%qdx = q_dot (the state eval_one gathers from: with a zero in front).
  pure subroutine copy_state(n, q, qd, qx, qdx)
    integer, intent(in) :: n
    real(wp), intent(in) :: q(n), qd(n)
    real(wp), intent(inout) :: qx(0:n), qdx(0:n)
    integer :: i
    do i = 1, n
      qx(i) = q(i); qdx(i) = qd(i)
    end do
  end subroutine copy_state

  !> Constraint k through con_eval, its local state gathered from the work arrays (q and
  !! q_dot with a zero in front, the bodies' cos and sin): its rows of Phi, nu, gamma and its
  !! block of J (each constraint writes whole rows of its block: no zero fill).
  pure subroutine eval_one(m, k, t, a, ph, nv, ga)
    type(model_t), intent(in) :: m                    !! model
    integer, intent(in) :: k                          !! constraint
    real(wp), intent(in) :: t                         !! time
    type(asm_work_t), intent(inout) :: a              !! work: state in, block k out
    real(wp), intent(out) :: ph(MAXROW), nv(MAXROW), ga(MAXROW)  !! its rows
    type(kloc) :: x
    integer :: s
    do s = 1, NLOC                   ! the constraint's slots (zero where it has none)
      x%q(s) = a%qx(m%loc(s, k)); x%qd(s) = a%qdx(m%loc(s, k))
    end do
    x%c(1) = a%cb(m%bi(k)); x%c(2) = a%cb(m%bj(k))
    x%s(1) = a%sb(m%bi(k)); x%s(2) = a%sb(m%bj(k))
    call con_eval(m%kind(k), m%suba(k), m%subb(k), m%p(m%po(k):m%po(k) + m%pn(k) - 1), &
                  merge(1, 0, m%bi(k) > 0), merge(2, 0, m%bj(k) > 0), x, t, ph, &
                  a%jb(:, :, k), nv, ga)          ! slot ids as model_slots
  end subroutine eval_one

  !> gamma alone at new velocities q_dot and the q of the last assembly (its cos and sin):
  !! J q_ddot = gamma after J q_dot = nu. The revolutes' gamma rows alone (revolute_gamma_all);
  !! every other constraint evaluated whole (its block of J rewritten with the same values).
  pure subroutine assemble_gamma(m, q, qd, t, gam, a)
    type(model_t), intent(in) :: m            !! model
    real(wp), intent(in) :: q(:)              !! coordinates of the last assembly (nq)
    real(wp), intent(in) :: qd(:)             !! velocities (nq)
    real(wp), intent(in) :: t                 !! time
    real(wp), intent(out) :: gam(:)           !! gamma (neq)
    type(asm_work_t), intent(inout) :: a      !! work: blocks and body cos, sin
    real(wp) :: ph, nv
    integer :: j, k
    call revolute_gamma_all(size(a%rtab, 2), a%rtab, m%p, qd, a%cb, a%sb, gam)
    do j = 1, size(a%drv)
      k = a%drv(j)
      call driver_abs_row(m%suba(k), m%p(m%po(k):m%po(k) + m%pn(k) - 1), &
                          q(m%loc(m%suba(k), k)), t, ph, a%jb(1, 1, k), nv, gam(m%row0(k)))
    end do
    if (size(a%gen) > 0) then
      call copy_state(m%nq, q, qd, a%qx, a%qdx)
      call general_rows(m, a%gen, t, 3, gam, a)
    end if
  end subroutine assemble_gamma

  !> The rows of Phi (lev 1) or gamma (lev 3) of the constraints in list, each evaluated
  !! whole (eval_one: its block of J rewritten, its other rows dropped).
  pure subroutine general_rows(m, list, t, lev, x, a)
    type(model_t), intent(in) :: m            !! model
    integer, intent(in) :: list(:)            !! constraints
    real(wp), intent(in) :: t                 !! time
    integer, intent(in) :: lev                !! 1 Phi, 3 gamma
    real(wp), intent(inout) :: x(:)           !! Phi or gamma (their rows written)
    type(asm_work_t), intent(inout) :: a      !! work: state in, blocks out
    real(wp) :: r(MAXROW, 3)                  ! rows of Phi, nu, gamma
    integer :: j, k, i
    do j = 1, size(list)
      k = list(j)
      call eval_one(m, k, t, a, r(:, 1), r(:, 2), r(:, 3))
      do i = 1, m%nrow(k)
        x(m%row0(k) + i - 1) = r(i, lev)
      end do
    end do
  end subroutine general_rows

  !> Phi alone at q (the chord steps of positions-only kinematics). fresh: a new q and t,
  !! the bodies' cos and sin from q (trig_near) and the absolute drivers' f(t) evaluated (kept
  !! in a);
  !! otherwise a correction of the last q at the same t, with the cos and sin in a (turned by
  !! asm_turn) and the kept f(t). The revolutes' Phi rows alone (revolute_phi_all), an absolute
  !! driver's Phi = q_c - f(t); every other constraint evaluated whole (its block of J
  !! rewritten, its nu and gamma rows dropped).
  pure subroutine assemble_phi(m, q, t, fresh, phi, a)
    type(model_t), intent(in) :: m            !! model
    real(wp), intent(in) :: q(:)              !! coordinates (nq)
    real(wp), intent(in) :: t                 !! time
    logical, intent(in) :: fresh              !! a new q and t (else a correction at the same t)
    real(wp), intent(out) :: phi(:)           !! Phi (neq)
    type(asm_work_t), intent(inout) :: a      !! work: blocks, body cos, sin, drivers' f(t)
    real(wp) :: f1, f2
    integer :: j, k, b
    if (fresh) then
      do b = 1, m%nb
        call trig_near(q(3 * b), a%ta(b), a%ca(b), a%sa(b), a%cb(b), a%sb(b))
      end do
    end if
    call revolute_phi_all(size(a%rtab, 2), a%rtab, m%p, q, a%cb, a%sb, phi)
    do j = 1, size(a%drv)
      if (fresh) then
        k = a%dtab(3, j)
        call fun_eval(m%p(k:k + a%dtab(4, j) - 1), t, a%fv(j), f1, f2)
      end if
      phi(a%dtab(1, j)) = q(a%dtab(2, j)) - a%fv(j)            ! (as driver_abs_row)
    end do
    if (size(a%gen) > 0) then
      a%qx(1:m%nq) = q          ! (for eval_one; its q_dot not used)
      call general_rows(m, a%gen, t, 1, phi, a)
    end if
  end subroutine assemble_phi

  !> Place the local blocks into a dense J (neq x nq), or J D (D = diag(cs)) with a column
  !! scale, through the map of asm_init.
  pure subroutine scatter_dense(a, jac, cs)
    type(asm_work_t), intent(in) :: a           !! blocks and their map
    real(wp), intent(out) :: jac(:, :)          !! dense J (D)
    real(wp), intent(in), optional :: cs(:)     !! column scale
    ! (an absent cs not passed on: gfortran builds a descriptor of it, and UBSan flags the
    ! negation of its garbage offset)
    if (present(cs)) then
      call scatter_flat(a%src, a%dst, a%col, a%jb, jac, size(a%jb), size(jac), cs)
    else
      call scatter_flat(a%src, a%dst, a%col, a%jb, jac, size(a%jb), size(jac))
    end if
  end subroutine scatter_dense

  !> jac(dst(i)) += jb(src(i)) [* cs(col(i))] over flat (column-major) views.
  pure subroutine scatter_flat(src, dst, col, jb, jac, nb, nj, cs)
    integer, intent(in) :: src(:), dst(:), col(:), nb, nj
    real(wp), intent(in) :: jb(nb)
    real(wp), intent(out) :: jac(nj)
    real(wp), intent(in), optional :: cs(:)
    integer :: i
    jac = zero
    if (present(cs)) then
      do i = 1, size(src)
        jac(dst(i)) = jac(dst(i)) + jb(src(i)) * cs(col(i))
      end do
    else
      do i = 1, size(src)
        jac(dst(i)) = jac(dst(i)) + jb(src(i))
      end do
    end if
  end subroutine scatter_flat

  !> The blocks' entries (times the column scale cs) written straight into a solver's value
  !! vector through a map of entries (src(i): flat index into the blocks, col(i): column of J,
  !! pos(i): place in val): val(pos(i)) = jb(src(i)) cs(col(i)) for i <= non; off: the sum of
  !! |jb(src(i))| over i > non (entries the solver's pattern leaves out, which must be zero;
  !! NaN propagates).
  pure subroutine scatter_values(a, src, col, pos, non, cs, val, off)
    type(asm_work_t), intent(in) :: a           !! blocks
    integer, intent(in) :: src(:), col(:), pos(:)  !! the map
    integer, intent(in) :: non                  !! entries written
    real(wp), intent(in) :: cs(:)               !! column scale
    real(wp), intent(inout) :: val(:)           !! values
    real(wp), intent(out) :: off                !! sum of the entries left out
    call scatter_pos(size(src), non, src, col, pos, a%jb, size(a%jb), cs, size(cs), val, off)
  end subroutine scatter_values

  !> scatter_values over a flat (column-major) view of the blocks.
  pure subroutine scatter_pos(ne, non, src, col, pos, jb, nb, cs, nc, val, off)
    integer, intent(in) :: ne, non, nb, nc
    integer, intent(in) :: src(ne), col(ne), pos(ne)
    real(wp), intent(in) :: jb(nb), cs(nc)
    real(wp), intent(inout) :: val(*)
    real(wp), intent(out) :: off
    integer :: i
    do i = 1, non
      val(pos(i)) = jb(src(i)) * cs(col(i))
    end do
    off = zero
    do i = non + 1, ne
      off = off + abs(jb(src(i)))
    end do
  end subroutine scatter_pos

  !> Phi, nu, gamma and the dense J in one call.
  pure subroutine assemble_dense(m, q, qd, t, phi, nu, gam, a, jac)
    type(model_t), intent(in) :: m            !! model
    real(wp), intent(in) :: q(:), qd(:)       !! coordinates and velocities
    real(wp), intent(in) :: t                 !! time
    real(wp), intent(out) :: phi(:), nu(:), gam(:)  !! Phi, nu, gamma
    type(asm_work_t), intent(inout) :: a      !! work arrays
    real(wp), intent(out) :: jac(:, :)        !! dense Jacobian
    call assemble_blocks(m, q, qd, t, phi, nu, gam, a)
    call scatter_dense(a, jac)
  end subroutine assemble_dense

  !> y = J x from the local blocks of the last assembly (no dense J).
  pure subroutine blocks_jv(m, a, x, y)
    type(model_t), intent(in) :: m        !! model
    type(asm_work_t), intent(in) :: a     !! work arrays with the blocks
    real(wp), intent(in) :: x(:)          !! vector (nq)
    real(wp), intent(out) :: y(:)         !! J x (neq)
    call jv_kernel(m%nc, m%loc, m%row0, m%nrow, a%jb, x, y)
  end subroutine blocks_jv

  !> blocks_jv on explicit shapes (no descriptor in the loops).
  pure subroutine jv_kernel(nc, loc, row0, nrow, jb, x, y)
    integer, intent(in) :: nc
    integer, intent(in) :: loc(NLOC, nc), row0(nc), nrow(nc)
    real(wp), intent(in) :: jb(MAXROW, NLOC, nc), x(*)
    real(wp), intent(inout) :: y(*)
    integer :: k, s, c, r0, i
    do k = 1, nc
      r0 = row0(k) - 1
      do i = 1, nrow(k)
        y(r0 + i) = zero
      end do
      do s = 1, NLOC
        c = loc(s, k)
        if (c == 0) cycle
        do i = 1, nrow(k)
          y(r0 + i) = y(r0 + i) + jb(i, s, k) * x(c)
        end do
      end do
    end do
  end subroutine jv_kernel

  !> Y = J X for several vectors held as rows (xt (npad, nq) -> yt (npad, neq), npad a
  !! multiple of 4), from the local blocks of the last assembly: each block entry read once.
  pure subroutine blocks_jv_rows(m, a, npad, xt, yt)
    type(model_t), intent(in) :: m        !! model
    type(asm_work_t), intent(in) :: a     !! work arrays with the blocks
    integer, intent(in) :: npad           !! rows of xt and yt
    real(wp), intent(in) :: xt(*)         !! vectors as rows (npad, nq)
    real(wp), intent(inout) :: yt(*)      !! J x as rows (npad, neq)
    call jv_rows_kernel(m%nc, m%loc, m%row0, m%nrow, a%jb, npad, xt, yt)
  end subroutine blocks_jv_rows

  !> blocks_jv_rows on explicit shapes.
  pure subroutine jv_rows_kernel(nc, loc, row0, nrow, jb, npad, xt, yt)
    integer, intent(in) :: nc, npad
    integer, intent(in) :: loc(NLOC, nc), row0(nc), nrow(nc)
    real(wp), intent(in) :: jb(MAXROW, NLOC, nc), xt(npad, *)
    real(wp), intent(inout) :: yt(npad, *)
    integer :: k, s, c, r, i, g
    real(wp) :: v
    do k = 1, nc
      do i = 0, nrow(k) - 1
        do g = 1, npad
          yt(g, row0(k) + i) = zero
        end do
      end do
      do s = 1, NLOC
        c = loc(s, k)
        if (c == 0) cycle
        do i = 1, nrow(k)
          r = row0(k) + i - 1; v = jb(i, s, k)
          if (npad == 4) then                  ! (up to four vectors: no inner loop)
            yt(1, r) = yt(1, r) + v * xt(1, c); yt(2, r) = yt(2, r) + v * xt(2, c)
            yt(3, r) = yt(3, r) + v * xt(3, c); yt(4, r) = yt(4, r) + v * xt(4, c)
            cycle
          end if
          do g = 0, npad - 4, 4
            yt(g + 1, r) = yt(g + 1, r) + v * xt(g + 1, c)
            yt(g + 2, r) = yt(g + 2, r) + v * xt(g + 2, c)
            yt(g + 3, r) = yt(g + 3, r) + v * xt(g + 3, c)
            yt(g + 4, r) = yt(g + 4, r) + v * xt(g + 4, c)
          end do
        end do
      end do
    end do
  end subroutine jv_rows_kernel

  !> X = X - J^T Y for several vectors held as rows (yt (npad, neq) -> xt (npad, nq), npad a
  !! multiple of 4), from the local blocks of the last assembly: each block entry read once.
  pure subroutine blocks_jtv_rows_sub(m, a, npad, yt, xt)
    type(model_t), intent(in) :: m        !! model
    type(asm_work_t), intent(in) :: a     !! work arrays with the blocks
    integer, intent(in) :: npad           !! rows of yt and xt
    real(wp), intent(in) :: yt(*)         !! vectors as rows (npad, neq)
    real(wp), intent(inout) :: xt(*)      !! X - J^T Y as rows (npad, nq)
    call jtv_rows_kernel(m%nc, m%loc, m%row0, m%nrow, a%jb, npad, yt, xt)
  end subroutine blocks_jtv_rows_sub

  !> blocks_jtv_rows_sub on explicit shapes.
  pure subroutine jtv_rows_kernel(nc, loc, row0, nrow, jb, npad, yt, xt)
    integer, intent(in) :: nc, npad
    integer, intent(in) :: loc(NLOC, nc), row0(nc), nrow(nc)
    real(wp), intent(in) :: jb(MAXROW, NLOC, nc), yt(npad, *)
    real(wp), intent(inout) :: xt(npad, *)
    integer :: k, s, c, r, i, g
    real(wp) :: v
    do k = 1, nc
      do s = 1, NLOC
        c = loc(s, k)
        if (c == 0) cycle
        do i = 1, nrow(k)
          r = row0(k) + i - 1; v = jb(i, s, k)
          if (npad == 4) then                  ! (up to four vectors: no inner loop)
            xt(1, c) = xt(1, c) - v * yt(1, r); xt(2, c) = xt(2, c) - v * yt(2, r)
            xt(3, c) = xt(3, c) - v * yt(3, r); xt(4, c) = xt(4, c) - v * yt(4, r)
            cycle
          end if
          do g = 0, npad - 4, 4
            xt(g + 1, c) = xt(g + 1, c) - v * yt(g + 1, r)
            xt(g + 2, c) = xt(g + 2, c) - v * yt(g + 2, r)
            xt(g + 3, c) = xt(g + 3, c) - v * yt(g + 3, r)
            xt(g + 4, c) = xt(g + 4, c) - v * yt(g + 4, r)
          end do
        end do
      end do
    end do
  end subroutine jtv_rows_kernel

  !> x = J^T y from the local blocks of the last assembly (no dense J).
  pure subroutine blocks_jtv(m, a, y, x)
    type(model_t), intent(in) :: m        !! model
    type(asm_work_t), intent(in) :: a     !! work arrays with the blocks
    real(wp), intent(in) :: y(:)          !! vector (neq)
    real(wp), intent(out) :: x(:)         !! J^T y (nq)
    integer :: k, s, c, r0, i
    x = zero
    do k = 1, m%nc
      r0 = m%row0(k) - 1
      do s = 1, NLOC
        c = m%loc(s, k)
        if (c == 0) cycle
        do i = 1, m%nrow(k)
          x(c) = x(c) + a%jb(i, s, k) * y(r0 + i)
        end do
      end do
    end do
  end subroutine blocks_jtv

  !> The bodies' cos and sin after their angles changed by dq(3 b), a change within a few units
  !! in the last place: cos(th + d) = c - s d, sin(th + d) = s + c d (the d**2 terms are below
  !! rounding).
  !> c, s = cos th, sin th from an anchor angle ta whose ca, sa came from the library, by the
  !! angle addition c = ca + (ca (cos d - 1) - sa sin d), s = sa + (sa (cos d - 1) + ca sin d),
  !! d = th - ta (exact where th and ta are within a factor 2), with sin d and cos d - 1 by
  !! their series to d**7 and d**8 (the next terms below 6e-18 for |d| <= NEAR_MAX): c and s
  !! carry the anchor's rounding plus at most half a unit in the last place. Farther than
  !! NEAR_MAX from it (or a NaN), cos and sin anew, and th the new anchor.
  pure subroutine trig_near(th, ta, ca, sa, c, s)
    real(wp), intent(in) :: th                !! angle
    real(wp), intent(inout) :: ta, ca, sa     !! anchor: angle, cos, sin
    real(wp), intent(out) :: c, s             !! cos th, sin th
    real(wp), parameter :: NEAR_MAX = 0.05_wp
    real(wp), parameter :: S3 = one / 6, S5 = one / 20, S7 = one / 42
    real(wp), parameter :: C4 = one / 12, C6 = one / 30, C8 = one / 56
    real(wp) :: d, d2, sn, cm
    d = th - ta
    if (abs(d) <= NEAR_MAX) then
      d2 = d * d
      sn = d * (one - d2 * S3 * (one - d2 * S5 * (one - d2 * S7)))
      cm = -half * d2 * (one - d2 * C4 * (one - d2 * C6 * (one - d2 * C8)))
      c = ca + (ca * cm - sa * sn)
      s = sa + (sa * cm + ca * sn)
    else
      c = cos(th); s = sin(th)
      ta = th; ca = c; sa = s
    end if
  end subroutine trig_near

  pure subroutine asm_turn(m, a, dq)
    type(model_t), intent(in) :: m            !! model
    type(asm_work_t), intent(inout) :: a      !! cos and sin of the angles
    real(wp), intent(in) :: dq(:)             !! change of the coordinates (tiny)
    real(wp) :: c, d
    integer :: b
    do b = 1, m%nb
      d = dq(3 * b); c = a%cb(b)
      a%cb(b) = c - a%sb(b) * d; a%sb(b) = a%sb(b) + c * d
    end do
  end subroutine asm_turn

  !> Starting values of the extra coordinates (cam contact parameters) from the bodies in q.
  pure subroutine init_extras(m, q)
    type(model_t), intent(in) :: m      !! model
    real(wp), intent(inout) :: q(:)     !! coordinates; extras are overwritten
    real(wp) :: ql(NLOC)
    integer :: k, si, sj
    do k = 1, m%nc
      if (m%loc(NLOC, k) == 0) cycle
      call gather_local(m, k, q, ql)
      call model_slots(m, k, si, sj)
      call con_init_extra(m%kind(k), m%suba(k), m%subb(k), m%p(m%po(k):m%po(k) + m%pn(k) - 1), &
                          si, sj, ql)
      q(m%loc(NLOC, k)) = ql(NLOC)
    end do
  end subroutine init_extras

end module mbd_assemble
