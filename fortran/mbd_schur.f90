!> mbd_schur: the index-1 saddle-point system with a diagonal, positive upper-left block
!! solved through its Schur complement, a band Cholesky factorization of na x na instead of
!! a band LU of (n + na) x (n + na).
!!
!!   [ D     s J^T ] [ x ]   [ b ]        S = s^2 J D^-1 J^T      (symmetric positive
!!   [ s J   0     ] [ y ] = [ c ]        S y = s J D^-1 b - c     definite when J has full
!!                                        x = D^-1 (b - s J^T y)   row rank and D > 0)
!!
!! J are the active rows of the constraint Jacobian (from the blocks jb of mbd_assemble). The
!! rows are ordered by reverse Cuthill-McKee on the graph in which two rows are adjacent when
!! they share a coordinate, so S is a band of half width kd (a chain: the rows of two
!! neighbouring joints). J is kept by groups of coordinates that the same rows touch (a
!! body's x, y, theta), each group a dense block stored row by row; S is formed group by
!! group, S(p, q) += sum_c s J(p, c) s J(q, c) / d_c over the pairs p >= q of its rows,
!! and factored S = L L^T in plain loops (narrow bands: a BLAS call per column costs more
!! than its work; the band's short loops are not vectorized, whose set-up costs more than
!! their work: 2x fewer instructions at kd = 5). Cost per factorization ~ na kd^2 + sum_c r_c^2 (r_c rows at coordinate c),
!! against ~ 2 (n + na) kl (kl + ku) for the band LU of the saddle-point matrix, and the band
!! is kd + 1 rows of na, not 2 kl + ku + 1 of n + na: a chain's factorization stays in cache.
!!
!! The squared condition: the error of y is about eps cond(S) and cond(S) ~ cond(J D^-1/2)^2.
!! So schur_factor refuses (ok = .false., the caller takes the saddle-point LU) a D with a
!! non-positive entry and a factorization whose pivot ratio min L_jj^2 / max L_jj^2 is below
!! SCHUR_PIVOT, and every solve is refined once against the constraint equations (the
!! correction from the residual c - s J x), which takes the error from eps cond(S) (for a
!! chain of N loops cond(S) grows like N^2) to about the saddle-point LU's.
!!
!! Usage: schur_plan once per structure (allocates); schur_factor with the current d, jb, s;
!! schur_solve for any number of right-hand sides; no allocation after the plan.
module mbd_schur
  use mbd_kinds, only: wp, zero, one
  use mbd_status, only: MBD_OK, MBD_NO_MEMORY, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check, mem_fail, zero_fill
  use mbd_points, only: NLOC, MAXROW
  use mbd_model, only: model_t
  use mbd_band, only: band_graph, band_rcm
  implicit none
  private
  public :: schur_t, schur_plan, schur_factor, schur_solve, rows_rcm, rows_by_coordinate, &
            SCHUR_PIVOT

  !> min L_jj^2 / max L_jj^2 below which the Schur complement is not used
  real(wp), parameter :: SCHUR_PIVOT = 1.0e-8_wp
  character(len=*), parameter :: HINT = 'use a model with fewer coordinates'

  !> A planned Schur complement: J's active entries by groups of coordinates, the row order
  !! and the band.
  type :: schur_t
    integer :: n = 0, na = 0, kd = 0, ng = 0  !! coordinates, active rows, half band, groups
    logical :: planned = .false.
    !> group g: coordinates gc(g):gc(g+1)-1 (w of them), rows gr(g):gr(g+1)-1 of rp (their
    !! band positions, r of them), entries ge(g) + (a - 1) w + (k - 1) for row a and
    !! coordinate k (row by row)
    integer, allocatable :: gc(:), gr(:), ge(:), rp(:)
    integer, allocatable :: esrc(:)           !! flat index of each entry in jb
    integer, allocatable :: pos(:)            !! (na) band position of active row a
    !> the pairs of rows p >= q of each group (pairs pptr(g):pptr(g+1)-1): the first entries
    !! pa, pb of the two rows and the flat position pf of S(p, q) in g
    integer, allocatable :: pptr(:), pa(:), pb(:), pf(:)
    real(wp), allocatable :: ev(:)            !! s J by entry, of the last factorization
    real(wp), allocatable :: wv(:)            !! s J / d by entry
    real(wp), allocatable :: d(:), dinv(:)    !! (n) d and 1 / d of the last factorization
    real(wp), allocatable :: g(:, :)          !! (kd + 1, na) S(p, q) in g(1 + p - q, q), then L
    real(wp), allocatable :: z(:), y(:)     !! solve workspace (na)
  end type schur_t

contains

  !> Plan the Schur complement of the saddle-point matrix of model m with the active rows
  !! `rows` (equation numbers, na): J's entries by groups, the row order and the band.
  !! Allocates (once per structure).
  subroutine schur_plan(m, rows, sc, status, msg)
    type(model_t), intent(in) :: m                 !! model
    integer, intent(in) :: rows(:)                 !! active rows, increasing
    type(schur_t), intent(out) :: sc               !! the plan
    integer, intent(out) :: status                 !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(out) :: msg     !! explanation
    integer, allocatable :: arow(:), cptr(:), crow(:), csrc(:)
    integer :: n, na, ne, a, ierr
    status = MBD_OK; msg = ''
    n = m%nq; na = size(rows)
    sc%n = n; sc%na = na
    allocate (arow(m%neq), sc%pos(na), stat=ierr)
    if (ierr /= 0) goto 90
    arow = 0
    do a = 1, na
      arow(rows(a)) = a
    end do
    call rows_by_coordinate(m, arow, cptr, crow, csrc, ierr)
    if (ierr /= 0) goto 90
    ne = size(crow)
    call rows_rcm(na, cptr, crow, sc%pos, sc%kd, ierr)
    if (ierr /= 0) goto 90
    call plan_groups(sc, cptr, crow, csrc, ierr)
    if (ierr /= 0) goto 90
    call mem_check(REAL_BYTES * (real(sc%kd + 4, wp) * na + 3 * n + 2 * ne), &
                   'the Schur complement (band)', HINT, status, msg)
    if (status /= MBD_OK) return
    allocate (sc%g(sc%kd + 1, na), sc%d(n), sc%dinv(n), sc%ev(ne), sc%wv(ne), sc%z(na), &
              sc%y(na), stat=ierr)
    if (ierr /= 0) goto 90
    sc%planned = .true.
    return
90  status = MBD_NO_MEMORY
    call mem_fail(REAL_BYTES * 4 * (36 * real(n, wp) + na), 'the Schur complement plan', HINT, &
                  status, msg)
  end subroutine schur_plan

  !> J's entries of the rows arow marks (arow(equation) = its number among them, 0 not
  !! taken) by coordinate: coordinate c has the entries cptr(c):cptr(c+1)-1, crow their
  !! row numbers, csrc their flat positions in the blocks jb (MAXROW, NLOC, nc).
  subroutine rows_by_coordinate(m, arow, cptr, crow, csrc, ierr)
    type(model_t), intent(in) :: m                    !! model
    integer, intent(in) :: arow(:)                    !! (neq) row numbers, 0 not taken
    integer, allocatable, intent(out) :: cptr(:)      !! (nq + 1) pointers
    integer, allocatable, intent(out) :: crow(:), csrc(:)  !! row and block position
    integer, intent(out) :: ierr                      !! allocation status (0 ok)
    integer, allocatable :: nxt(:)
    integer :: k, s, c, r, a, n
    n = m%nq
    allocate (cptr(n + 1), nxt(n), stat=ierr)
    if (ierr /= 0) return
    cptr = 0
    do k = 1, m%nc
      do s = 1, NLOC
        c = m%loc(s, k)
        if (c == 0) cycle
        do r = 1, m%nrow(k)
          if (arow(m%row0(k) + r - 1) > 0) cptr(c + 1) = cptr(c + 1) + 1
        end do
      end do
    end do
    cptr(1) = 1
    do c = 1, n
      cptr(c + 1) = cptr(c + 1) + cptr(c)
    end do
    allocate (crow(cptr(n + 1) - 1), csrc(cptr(n + 1) - 1), stat=ierr)
    if (ierr /= 0) return
    nxt = cptr(1:n)
    do k = 1, m%nc
      do s = 1, NLOC
        c = m%loc(s, k)
        if (c == 0) cycle
        do r = 1, m%nrow(k)
          a = arow(m%row0(k) + r - 1)
          if (a == 0) cycle
          crow(nxt(c)) = a
          csrc(nxt(c)) = r + MAXROW * (s - 1 + NLOC * (k - 1))
          nxt(c) = nxt(c) + 1
        end do
      end do
    end do
  end subroutine rows_by_coordinate

  !> Reverse Cuthill-McKee order of nr rows in the graph where two rows are adjacent when
  !! they share a coordinate (the rows at coordinate c: crow(cptr(c):cptr(c+1)-1)): pos(r)
  !! the place of row r, kd the half band width of a matrix coupling such rows (J J^T).
  subroutine rows_rcm(nr, cptr, crow, pos, kd, ierr)
    integer, intent(in) :: nr                 !! rows
    integer, intent(in) :: cptr(:), crow(:)   !! rows by coordinate (n + 1 pointers)
    integer, intent(out) :: pos(:)            !! (nr) place of each row
    integer, intent(out) :: kd                !! half band width
    integer, intent(out) :: ierr              !! allocation status (0 ok)
    integer, allocatable :: pr(:), pc(:), aptr(:), adj(:), ord(:)
    integer :: c, i, j, np
    kd = 0
    np = 0
    do c = 1, size(cptr) - 1
      np = np + (cptr(c + 1) - cptr(c))**2
    end do
    allocate (pr(max(np, 1)), pc(max(np, 1)), ord(nr), stat=ierr)
    if (ierr /= 0) return
    np = 0
    do c = 1, size(cptr) - 1
      do i = cptr(c), cptr(c + 1) - 1
        do j = cptr(c), cptr(c + 1) - 1
          np = np + 1
          pr(np) = crow(i); pc(np) = crow(j)
        end do
      end do
    end do
    if (nr > 0) then
      call band_graph(nr, pr(1:np), pc(1:np), aptr, adj, ierr)
      if (ierr == 0) call band_rcm(nr, aptr, adj, ord, ierr)
      if (ierr /= 0) return
    end if
    do i = 1, nr
      pos(ord(i)) = i
    end do
    do i = 1, np
      kd = max(kd, abs(pos(pr(i)) - pos(pc(i))))
    end do
  end subroutine rows_rcm

  !> The coordinate groups (runs of coordinates whose entries name the same rows in the same
  !! order), J's entries in their layout (row by row), and the pairs of rows of each group
  !! with p >= q as flat positions in g.
  subroutine plan_groups(sc, cptr, crow, csrc, ierr)
    type(schur_t), intent(inout) :: sc
    integer, intent(in) :: cptr(:), crow(:), csrc(:)  ! J by coordinate: rows, jb positions
    integer, intent(out) :: ierr                      ! allocation status
    integer :: c, g, np, e, r, w, a, b, k, p, q, nr
    allocate (sc%gc(sc%n + 1), stat=ierr)
    if (ierr /= 0) return
    sc%ng = 0
    c = 1
    do while (c <= sc%n)
      sc%ng = sc%ng + 1
      sc%gc(sc%ng) = c
      c = c + 1
      do while (c <= sc%n)
        if (.not. same_rows(sc%gc(sc%ng), c)) exit
        c = c + 1
      end do
    end do
    sc%gc(sc%ng + 1) = sc%n + 1
    nr = 0; np = 0
    do g = 1, sc%ng
      r = cptr(sc%gc(g) + 1) - cptr(sc%gc(g))
      nr = nr + r
      np = np + r * (r + 1) / 2
    end do
    allocate (sc%gr(sc%ng + 1), sc%ge(sc%ng + 1), sc%rp(nr), sc%esrc(size(csrc)), &
              sc%pptr(sc%ng + 1), sc%pa(np), sc%pb(np), sc%pf(np), stat=ierr)
    if (ierr /= 0) return
    nr = 0; np = 0; e = 0
    do g = 1, sc%ng
      sc%gr(g) = nr + 1; sc%ge(g) = e + 1; sc%pptr(g) = np + 1
      r = cptr(sc%gc(g) + 1) - cptr(sc%gc(g))
      w = sc%gc(g + 1) - sc%gc(g)
      do a = 0, r - 1
        sc%rp(nr + 1 + a) = sc%pos(crow(cptr(sc%gc(g)) + a))
        do k = 0, w - 1
          sc%esrc(e + 1 + a * w + k) = csrc(cptr(sc%gc(g) + k) + a)
        end do
      end do
      do a = 0, r - 1
        do b = 0, r - 1
          p = sc%rp(nr + 1 + a); q = sc%rp(nr + 1 + b)
          if (q > p .or. (q == p .and. b > a)) cycle
          np = np + 1
          sc%pa(np) = e + 1 + a * w; sc%pb(np) = e + 1 + b * w
          sc%pf(np) = 1 + p - q + (sc%kd + 1) * (q - 1)
        end do
      end do
      nr = nr + r; e = e + r * w
    end do
    sc%gr(sc%ng + 1) = nr + 1; sc%ge(sc%ng + 1) = e + 1; sc%pptr(sc%ng + 1) = np + 1
  contains
    !> Coordinate c has the rows of coordinate c0, in the same order.
    logical function same_rows(c0, c)
      integer, intent(in) :: c0, c
      integer :: r0, i
      r0 = cptr(c0 + 1) - cptr(c0)
      same_rows = cptr(c + 1) - cptr(c) == r0
      if (.not. same_rows) return
      do i = 0, r0 - 1
        if (crow(cptr(c) + i) /= crow(cptr(c0) + i)) then
          same_rows = .false.; return
        end if
      end do
    end function same_rows
  end subroutine plan_groups

  !> Form S = s^2 J D^-1 J^T from d, the blocks jb and s, and factor S = L L^T. ok: the
  !! factors are usable (every d > 0, every pivot > 0, pivot ratio >= SCHUR_PIVOT);
  !! otherwise the caller solves the saddle-point matrix another way.
  pure subroutine schur_factor(sc, d, jb, s, ok)
    type(schur_t), intent(inout) :: sc       !! planned; factors on return
    real(wp), intent(in) :: d(:)             !! diagonal of D (n)
    real(wp), intent(in) :: jb(:, :, :)      !! constraint blocks (MAXROW, NLOC, nc)
    real(wp), intent(in) :: s                !! scale of J
    logical, intent(out) :: ok               !! factors usable
    ok = .false.
    if (.not. sc%planned) return
    if (.not. all(d(1:sc%n) > zero)) return
    sc%d = d(1:sc%n)
    call form(sc, size(jb), jb, s)
    call cholesky(sc%na, sc%kd, sc%g, ok)
  end subroutine schur_factor

  !> S in lower band storage: S(p, q) = sum_c s J(p, c) s J(q, c) / d_c, group by group
  !! (each pair of a group's rows once, summed over its coordinates; two entries of one row
  !! make two pairs, so repeated entries sum correctly).
  pure subroutine form(sc, nj, jb, s)
    type(schur_t), intent(inout) :: sc
    integer, intent(in) :: nj
    real(wp), intent(in) :: jb(nj), s
    integer :: c, e, g, pp, w, k, ia, ib
    real(wp) :: acc, d1, d2, d3
    do c = 1, sc%n
      sc%dinv(c) = one / sc%d(c)
    end do
    do e = 1, size(sc%esrc)
      sc%ev(e) = s * jb(sc%esrc(e))
    end do
    call zero_fill(size(sc%g), sc%g)        ! (one memset, not one per column)
    do g = 1, sc%ng
      w = sc%gc(g + 1) - sc%gc(g)
      c = sc%gc(g) - 1
      if (w == 3) then
        d1 = sc%dinv(c + 1); d2 = sc%dinv(c + 2); d3 = sc%dinv(c + 3)
        do e = sc%ge(g), sc%ge(g + 1) - 1, 3
          sc%wv(e) = sc%ev(e) * d1
          sc%wv(e + 1) = sc%ev(e + 1) * d2
          sc%wv(e + 2) = sc%ev(e + 2) * d3
        end do
      else
        do e = sc%ge(g), sc%ge(g + 1) - 1, max(w, 1)
          do k = 1, w
            sc%wv(e + k - 1) = sc%ev(e + k - 1) * sc%dinv(c + k)
          end do
        end do
      end if
      if (w == 3) then                      ! a body: x, y, theta
        do pp = sc%pptr(g), sc%pptr(g + 1) - 1
          ia = sc%pa(pp); ib = sc%pb(pp)
          acc = sc%wv(ia) * sc%ev(ib) + sc%wv(ia + 1) * sc%ev(ib + 1) + &
                sc%wv(ia + 2) * sc%ev(ib + 2)
          call add(sc%g, sc%pf(pp), acc)
        end do
      else
        do pp = sc%pptr(g), sc%pptr(g + 1) - 1
          ia = sc%pa(pp) - 1; ib = sc%pb(pp) - 1
          acc = zero
          do k = 1, w
            acc = acc + sc%wv(ia + k) * sc%ev(ib + k)
          end do
          call add(sc%g, sc%pf(pp), acc)
        end do
      end if
    end do
  end subroutine form

  !> g(f) += v on the flat storage of g.
  pure subroutine add(g, f, v)
    real(wp), intent(inout) :: g(*)
    integer, intent(in) :: f
    real(wp), intent(in) :: v
    g(f) = g(f) + v
  end subroutine add

  !> S = L L^T in place (lower band, right-looking: column j scaled, then the trailing
  !! triangle S(k:, k) -= L(k:, j) L(k, j), contiguous in the storage); the diagonal keeps
  !! 1 / l_jj (the solves multiply: no division on their dependency chain). ok: every pivot
  !! S_jj > 0 and min / max of them >= SCHUR_PIVOT.
  pure subroutine cholesky(na, kd, g, ok)
    integer, intent(in) :: na, kd
    real(wp), intent(inout) :: g(kd + 1, *)
    logical, intent(out) :: ok
    integer :: j, l, w, t
    real(wp) :: dj, rj, v, dmin, dmax
    ok = .false.
    dmin = huge(one); dmax = zero
    do j = 1, na
      dj = g(1, j)
      if (.not. dj > zero) return
      dmin = min(dmin, dj); dmax = max(dmax, dj)
      dj = sqrt(dj)
      rj = one / dj
      g(1, j) = rj
      l = min(kd, na - j)
      !GCC$ novector
      do t = 2, l + 1
        g(t, j) = g(t, j) * rj
      end do
      do w = 1, l                              ! column j + w of the trailing triangle
        v = g(w + 1, j)
        !GCC$ novector
        do t = 0, l - w
          g(1 + t, j + w) = g(1 + t, j + w) - v * g(w + 1 + t, j)
        end do
      end do
    end do
    ok = na == 0 .or. dmin >= SCHUR_PIVOT * dmax
  end subroutine cholesky

  !> Solve the saddle-point system with the factored Schur complement: [x; y] overwrites
  !! [b; c] (x the n coordinates, y the na active rows in their given order), refined once
  !! against the constraint equations: x = D^-1 (b - s J^T y) satisfies the first block to
  !! rounding, so the correction of the residual [0; c - s J x] is
  !! S dy = s J x - c,  dx = -D^-1 s J^T dy.
  pure subroutine schur_solve(sc, rhs)
    type(schur_t), intent(inout) :: sc       !! factored
    real(wp), intent(inout) :: rhs(:)        !! (n + na) right-hand side, then solution
    integer :: n, a
    n = sc%n
    do a = 1, sc%na
      sc%y(sc%pos(a)) = rhs(n + a)           ! c, in band order
    end do
    call solve_once(sc, rhs)
    sc%z = -sc%y
    call jv_add(sc, rhs, sc%z)               ! s J x - c
    call chol_solve(sc%na, sc%kd, sc%g, sc%z)
    call jtv_sub(sc, sc%wv, sc%z, rhs)       ! x -= D^-1 s J^T dy
    do a = 1, sc%na
      rhs(n + a) = rhs(n + a) + sc%z(sc%pos(a))
    end do
  end subroutine schur_solve

  !> One Schur solve: L L^T y = s J D^-1 b - c, then x = D^-1 (b - s J^T y).
  pure subroutine solve_once(sc, rhs)
    type(schur_t), intent(inout) :: sc
    real(wp), intent(inout) :: rhs(:)
    integer :: n, a, c
    n = sc%n
    do c = 1, n
      rhs(c) = rhs(c) * sc%dinv(c)
    end do
    do a = 1, sc%na
      sc%z(sc%pos(a)) = -rhs(n + a)
    end do
    call jv_add(sc, rhs, sc%z)               ! z += s J (D^-1 b)
    call chol_solve(sc%na, sc%kd, sc%g, sc%z)
    call jtv_sub(sc, sc%wv, sc%z, rhs)      ! D^-1 b -= D^-1 s J^T y
    do a = 1, sc%na
      rhs(n + a) = sc%z(sc%pos(a))
    end do
  end subroutine solve_once

  !> z(band order) += s J x.
  pure subroutine jv_add(sc, x, z)
    type(schur_t), intent(in) :: sc
    real(wp), intent(in) :: x(:)
    real(wp), intent(inout) :: z(:)
    integer :: g, w, c, e, i, k
    real(wp) :: acc, x1, x2, x3
    do g = 1, sc%ng
      w = sc%gc(g + 1) - sc%gc(g)
      c = sc%gc(g) - 1
      e = sc%ge(g) - 1
      if (w == 3) then                        ! a body: x, y, theta
        x1 = x(c + 1); x2 = x(c + 2); x3 = x(c + 3)
        do i = sc%gr(g), sc%gr(g + 1) - 1
          z(sc%rp(i)) = z(sc%rp(i)) + (sc%ev(e + 1) * x1 + sc%ev(e + 2) * x2 + &
                                       sc%ev(e + 3) * x3)
          e = e + 3
        end do
        cycle
      end if
      do i = sc%gr(g), sc%gr(g + 1) - 1
        acc = zero
        do k = 1, w
          acc = acc + sc%ev(e + k) * x(c + k)
        end do
        z(sc%rp(i)) = z(sc%rp(i)) + acc
        e = e + w
      end do
    end do
  end subroutine jv_add

  !> x -= v J^T y (y in band order) with v = wv (s J / d) or ev (s J).
  pure subroutine jtv_sub(sc, v, y, x)
    type(schur_t), intent(in) :: sc
    real(wp), intent(in) :: v(:)
    real(wp), intent(in) :: y(:)
    real(wp), intent(inout) :: x(:)
    integer :: g, w, c, e, i, k
    real(wp) :: yi, x1, x2, x3
    do g = 1, sc%ng
      w = sc%gc(g + 1) - sc%gc(g)
      c = sc%gc(g) - 1
      e = sc%ge(g) - 1
      if (w == 3) then                        ! a body: x, y, theta
        x1 = x(c + 1); x2 = x(c + 2); x3 = x(c + 3)
        do i = sc%gr(g), sc%gr(g + 1) - 1
          yi = y(sc%rp(i))
          x1 = x1 - v(e + 1) * yi
          x2 = x2 - v(e + 2) * yi
          x3 = x3 - v(e + 3) * yi
          e = e + 3
        end do
        x(c + 1) = x1; x(c + 2) = x2; x(c + 3) = x3
        cycle
      end if
      do i = sc%gr(g), sc%gr(g + 1) - 1
        yi = y(sc%rp(i))
        do k = 1, w
          x(c + k) = x(c + k) - v(e + k) * yi
        end do
        e = e + w
      end do
    end do
  end subroutine jtv_sub


  !> L L^T z = z in place (lower band factor, its diagonal held as 1 / l_jj).
  pure subroutine chol_solve(na, kd, g, z)
    integer, intent(in) :: na, kd
    real(wp), intent(in) :: g(kd + 1, *)
    real(wp), intent(inout) :: z(:)
    integer :: j, l, t
    real(wp) :: v
    do j = 1, na                              ! L v = z
      v = z(j) * g(1, j)
      z(j) = v
      l = min(kd, na - j)
      !GCC$ novector
      do t = 1, l
        z(j + t) = z(j + t) - g(t + 1, j) * v
      end do
    end do
    do j = na, 1, -1                          ! L^T z = v
      l = min(kd, na - j)
      v = z(j)
      !GCC$ novector
      do t = 1, l
        v = v - g(t + 1, j) * z(j + t)
      end do
      z(j) = v * g(1, j)
    end do
  end subroutine chol_solve

end module mbd_schur
