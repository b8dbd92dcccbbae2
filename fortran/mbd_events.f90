!> mbd_events: the modes of contacts and stick-slip joints, and the location in time of the
!! events that change them (onset and separation of a contact, stick, slip and reversal of
!! a joint), for the integrators.
!!
!! Each element with modes has an event function g that is <= 0 while its mode holds:
!!   open contact      g = delta                  (onset when the surfaces touch)
!!   closed contact    g = -delta                 (separation)
!!   sliding joint     g = -s u_dot               (s: the sliding sign; the slip stops)
!!   stuck joint       g = |f_lock| - mu_s N      (the lock needs more than static friction)
!! A step from ta to tb is searched with the quintic Hermite dense output of its two end
!! states (mbd_interp): a sign change of g, or for a contact an extremum of delta inside the
!! step (delta_dot changes sign: a short impact or a short separation that the end points
!! miss), and for a contact within reach of the step (the bounding test delta(ta) +
!! 2 h max|delta_dot| > 0) NSAMPLE points inside it; the crossing is bracketed by the Illinois method (regula falsi with halving, a
!! bisection every third iteration) to the width the dead-centre search of kinematics
!! reaches, 1e-10 max(1, |t|) s. events_find returns the right end of the earliest bracket
!! (on the new side): the integrator takes its step again to there, then events_switch
!! changes the modes and records the events. A joint that stops sliding sticks when the
!! locked joint needs at most mu_s N (its velocities are then projected onto u_dot = 0),
!! otherwise it slides back; a stuck joint slips in the direction its lock force resisted.
!! Event records: [t, element, kind, value]; value: the impact speed delta_dot (onset), the
!! separation speed -delta_dot (separation), the friction force (stick, slip, reversal).
module mbd_events
  use mbd_kinds, only: wp, zero, one, two, half
  use mbd_status, only: MBD_OK, MBD_NO_MEMORY, MSG_LEN
  use mbd_model, only: model_t
  use mbd_points, only: kloc, kscal
  use mbd_forces, only: force_is_contact, FRC_CONTACT0, FRC_FRICTION
  use mbd_contact, only: contact_gap, V0_MIN, FRIC_STICK_SLIP
  use mbd_dynamics, only: dyn_work_t, dyn_accel, dyn_velocity, dyn_solve, element_state, &
                          element_slip, MODE_STUCK
  use mbd_interp, only: hermite5
  implicit none
  private
  public :: ev_log_t, EV_ONSET, EV_SEPARATION, EV_STICK, EV_SLIP, EV_REVERSAL
  public :: events_active, events_init, events_find, events_switch, ev_log_init, event_tol

  integer, parameter :: EV_ONSET = 1, EV_SEPARATION = 2, EV_STICK = 3, EV_SLIP = 4
  integer, parameter :: EV_REVERSAL = 5
  !> relative slip speed below which a joint starts stuck (L / s)
  real(wp), parameter :: V_REST = 1.0e-9_wp
  integer, parameter :: MAXIT = 200    !! root-finding iterations
  integer, parameter :: NSAMPLE = 7    !! interior samples of a step for a contact in reach

  !> The event log: records beyond its capacity are counted, not kept.
  type :: ev_log_t
    integer :: n = 0                          !! events that happened
    real(wp), allocatable :: rec(:, :)        !! (4, capacity) [t, element, kind, value]
  end type ev_log_t

contains

  !> Contacts or stick-slip joints: the integrators track modes and events.
  pure logical function events_active(m)
    type(model_t), intent(in) :: m           !! model
    events_active = m%ncontact > 0 .or. m%nstick > 0
  end function events_active

  !> The width to which an event in (ta, tb] is bracketed: that of the dead-centre search,
  !! 1e-10 max(1, |t|), or a few roundoffs of t.
  pure real(wp) function event_tol(ta, tb)
    real(wp), intent(in) :: ta, tb            !! step ends
    event_tol = max(1.0e-10_wp * max(one, abs(tb)), 64 * epsilon(one) * max(abs(ta), abs(tb)))
  end function event_tol

  !> An empty log of a given capacity.
  subroutine ev_log_init(log, cap, status)
    type(ev_log_t), intent(out) :: log       !! the log
    integer, intent(in) :: cap               !! capacity (records kept)
    integer, intent(out) :: status           !! MBD_OK or MBD_NO_MEMORY
    integer :: ist
    allocate (log%rec(4, max(cap, 0)), stat=ist)
    status = MBD_OK
    if (ist /= 0) status = MBD_NO_MEMORY
    log%n = 0
  end subroutine ev_log_init

  subroutine record(log, t, k, kind, val)
    type(ev_log_t), intent(inout) :: log
    real(wp), intent(in) :: t, val
    integer, intent(in) :: k, kind
    log%n = log%n + 1
    if (log%n <= size(log%rec, 2)) log%rec(:, log%n) = [t, real(k, wp), real(kind, wp), val]
  end subroutine record

  !> Is element k an element with modes (a contact or a stick-slip joint)?
  pure logical function has_modes(m, k)
    type(model_t), intent(in) :: m
    integer, intent(in) :: k
    has_modes = force_is_contact(m%fkind(k))
    if (m%fkind(k) == FRC_FRICTION) has_modes = nint(m%fp(m%fpo(k) + 2)) == FRIC_STICK_SLIP
  end function has_modes

  !> The modes at the start (q, q_dot) at t: contacts penetrating are closed (impact speed
  !! max(delta_dot, V0_MIN)); a stick-slip joint at rest sticks when the locked joint needs
  !! at most mu_s N, else slides the way the lock resisted; a moving one slides. The
  !! velocities of stuck joints are projected onto u_dot = 0 (qd changes by round-off).
  subroutine events_init(m, w, q, qd, t, status)
    type(model_t), intent(in) :: m           !! model
    type(dyn_work_t), intent(inout) :: w     !! work arrays (their states are set)
    real(wp), intent(in) :: q(:)             !! configuration
    real(wp), intent(inout) :: qd(:)         !! velocities (stuck joints projected)
    real(wp), intent(in) :: t                !! time
    integer, intent(out) :: status           !! MBD_OK or a solve's failure
    real(wp) :: dv, dr, ud, qdd(m%nq), lam(m%neq)
    type(kloc) :: x
    type(kscal) :: u
    integer :: k
    logical :: any_stuck
    status = MBD_OK
    any_stuck = .false.
    do k = 1, m%nf
      if (.not. has_modes(m, k)) cycle
      x = element_state(m, k, q, qd)
      if (force_is_contact(m%fkind(k))) then
        call contact_gap(m%fkind(k) - FRC_CONTACT0 + 1, m%fp(m%fpo(k):m%fpo(k) + m%fpn(k) - 1), &
                         merge(1, 0, m%fbi(k) > 0), merge(2, 0, m%fbj(k) > 0), x, dv, dr)
        w%cst(:, k) = zero
        if (dv > zero) w%cst(:, k) = [one, max(dr, V0_MIN)]
      else
        u = element_slip(m, k, x)
        ud = u%vd
        if (abs(ud) <= V_REST) then
          w%cst(1, k) = MODE_STUCK; any_stuck = .true.
        else
          w%cst(1, k) = sign(one, ud)
        end if
      end if
    end do
    if (.not. any_stuck) return
    ! stuck joints that cannot hold slide the way their lock resisted
    call dyn_accel(m, w, q, qd, t, qdd, lam, status)
    if (status /= MBD_OK) return
    do k = 1, m%nf
      if (m%fkind(k) /= FRC_FRICTION) cycle
      if (nint(w%cst(1, k)) /= MODE_STUCK) cycle
      if (abs(w%ffr(k)) > m%fp(m%fpo(k) + 1) * w%fnl(k)) w%cst(1, k) = -sign(one, w%ffr(k))
    end do
    call project_stuck(m, w, q, qd, t, status)
  end subroutine events_init

  !> Velocities with u_dot = 0 on the stuck joints and J q_dot = nu, nearest in kinetic
  !! energy: the projection of dyn_velocity, then the stuck rows by their responses through
  !! the same factored matrix (a small dense system).
  subroutine project_stuck(m, w, q, qd, t, status)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    real(wp), intent(in) :: q(:), t
    real(wp), intent(inout) :: qd(:)
    integer, intent(out) :: status
    real(wp) :: v0(m%nq), g(m%nq, m%nfric), z(m%nq + w%na, m%nfric), a(m%nfric, m%nfric)
    real(wp) :: r(m%nfric)
    integer :: ks(m%nfric), ns, b, d, k, s
    type(kloc) :: x
    type(kscal) :: u
    status = MBD_OK
    ns = 0
    do k = 1, m%nf
      if (m%fkind(k) /= FRC_FRICTION) cycle
      if (nint(w%cst(1, k)) /= MODE_STUCK) cycle
      ns = ns + 1; ks(ns) = k
    end do
    if (ns == 0) return
    v0 = qd
    call dyn_velocity(m, w, q, t, v0, qd, status)
    if (status /= MBD_OK) return
    do b = 1, ns
      x = element_state(m, ks(b), q, qd)
      u = element_slip(m, ks(b), x)
      g(:, b) = zero
      do s = 1, size(m%floc, 1)
        if (m%floc(s, ks(b)) > 0) g(m%floc(s, ks(b)), b) = g(m%floc(s, ks(b)), b) + u%d(s)
      end do
      z(:, b) = zero; z(1:m%nq, b) = g(:, b)
      call dyn_solve(w, z(:, b), status)
      if (status /= MBD_OK) return
      r(b) = -dot_product(g(:, b), qd)
    end do
    do b = 1, ns
      do d = 1, ns
        a(b, d) = dot_product(g(:, b), z(1:m%nq, d))
      end do
    end do
    call small_solve(a(1:ns, 1:ns), r(1:ns))
    do d = 1, ns
      qd = qd + r(d) * z(1:m%nq, d)
    end do
  end subroutine project_stuck

  !> Solve a small dense system by Gaussian elimination with partial pivoting (a singular
  !! pivot leaves the component zero).
  pure subroutine small_solve(a, b)
    real(wp), intent(inout) :: a(:, :), b(:)
    integer :: n, i, k, p
    real(wp) :: f, tmp(size(a, 2)), tb
    n = size(b)
    do k = 1, n
      p = k - 1 + maxloc(abs(a(k:n, k)), 1)
      if (p /= k) then
        tmp = a(k, :); a(k, :) = a(p, :); a(p, :) = tmp
        tb = b(k); b(k) = b(p); b(p) = tb
      end if
      if (.not. abs(a(k, k)) > zero) cycle
      do i = k + 1, n
        f = a(i, k) / a(k, k)
        a(i, k:n) = a(i, k:n) - f * a(k, k:n)
        b(i) = b(i) - f * b(k)
      end do
    end do
    do k = n, 1, -1
      if (abs(a(k, k)) > zero) then
        b(k) = (b(k) - dot_product(a(k, k + 1:n), b(k + 1:n))) / a(k, k)
      else
        b(k) = zero
      end if
    end do
  end subroutine small_solve

  !> Event function values g (and for contacts their rates gd) of every element at a
  !! state; elements without modes get -1. stuck joints need the forces of a solve at the
  !! state (done here when one is stuck).
  subroutine values(m, w, q, qd, t, g, gd, status)
    type(model_t), intent(in) :: m
    type(dyn_work_t), intent(inout) :: w
    real(wp), intent(in) :: q(:), qd(:), t
    real(wp), intent(out) :: g(:), gd(:)
    integer, intent(out) :: status
    real(wp) :: dv, dr, qdd(m%nq), lam(m%neq)
    type(kloc) :: x
    type(kscal) :: u
    integer :: k, mode
    logical :: solved
    g = -one; gd = zero; status = MBD_OK; solved = .false.
    do k = 1, m%nf
      if (.not. has_modes(m, k)) cycle
      x = element_state(m, k, q, qd)
      if (force_is_contact(m%fkind(k))) then
        call contact_gap(m%fkind(k) - FRC_CONTACT0 + 1, m%fp(m%fpo(k):m%fpo(k) + m%fpn(k) - 1), &
                         merge(1, 0, m%fbi(k) > 0), merge(2, 0, m%fbj(k) > 0), x, dv, dr)
        if (nint(w%cst(1, k)) == 1) then
          g(k) = -dv; gd(k) = -dr
        else
          g(k) = dv; gd(k) = dr
        end if
      else
        mode = nint(w%cst(1, k))
        if (mode == MODE_STUCK) then
          if (.not. solved) then
            call dyn_accel(m, w, q, qd, t, qdd, lam, status)
            if (status /= MBD_OK) return
            solved = .true.
          end if
          g(k) = abs(w%ffr(k)) - m%fp(m%fpo(k) + 1) * w%fnl(k)
        else
          u = element_slip(m, k, x)
          g(k) = -mode * u%vd
        end if
      end if
    end do
  end subroutine values

  !> The earliest event in (ta, tb] of the step with end states a and b: te is the right
  !! end of its bracket (on the new side of the crossing) and kev its element (0: none,
  !! te = tb). status: a failed solve while evaluating a stuck joint.
  subroutine events_find(m, w, ta, qa, va, aa, tb, qb, vb, ab, te, kev, status)
    type(model_t), intent(in) :: m              !! model
    type(dyn_work_t), intent(inout) :: w        !! work arrays (modes)
    real(wp), intent(in) :: ta, tb              !! step ends
    real(wp), intent(in) :: qa(:), va(:), aa(:), qb(:), vb(:), ab(:)  !! states there
    real(wp), intent(out) :: te                 !! event time (bracket's right end)
    integer, intent(out) :: kev                 !! element, or 0
    integer, intent(out) :: status              !! MBD_OK or a solve's failure
    real(wp) :: ga(m%nf), gda(m%nf), gb(m%nf), gdb(m%nf), tol, tr, tm, gm
    integer :: k
    te = tb; kev = 0; status = MBD_OK
    if (.not. events_active(m)) return
    tol = event_tol(ta, tb)
    call values(m, w, qa, va, ta, ga, gda, status)
    if (status /= MBD_OK) return
    call values(m, w, qb, vb, tb, gb, gdb, status)
    if (status /= MBD_OK) return
    do k = 1, m%nf
      if (.not. has_modes(m, k)) cycle
      if (ga(k) > zero) cycle             ! already on the new side at the start: settled
      tr = huge(one)
      if (gb(k) > zero) then
        call locate(k, ta, ga(k), tb, gb(k), tr)
      else if (force_is_contact(m%fkind(k)) .and. gda(k) > zero .and. gdb(k) < zero) then
        ! an extremum of delta inside the step: is the contact crossed there?
        call rate_root(k, ta, tb, tm, gm)
        if (status /= MBD_OK) return
        if (gm > zero) call locate(k, ta, ga(k), tm, gm, tr)
      end if
      if (tr > tb .and. force_is_contact(m%fkind(k)) .and. &
          ga(k) + two * (tb - ta) * max(abs(gda(k)), abs(gdb(k))) > zero) then
        ! within reach in this step (the bounding test passed): sample the dense output, so
        ! that a contact crossed and left between the samples of the ends is not missed
        call sample(k, tm, gm)
        if (status /= MBD_OK) return
        if (gm > zero) call locate(k, ta, ga(k), tm, gm, tr)
      end if
      if (status /= MBD_OK) return
      if (tr <= tb .and. (kev == 0 .or. tr < te)) then
        te = tr; kev = k
      end if
    end do
  contains
    !> g of element kk at time t on the dense output (a contact or a sliding joint alone; a
    !! stuck joint needs the solve of the whole system).
    real(wp) function g_at(kk, t, gdt)
      integer, intent(in) :: kk
      real(wp), intent(in) :: t
      real(wp), intent(out) :: gdt
      real(wp) :: q(m%nq), v(m%nq), a(m%nq), gg(m%nf), gd(m%nf)
      type(kloc) :: x
      type(kscal) :: u
      call hermite5(ta, qa, va, aa, tb, qb, vb, ab, t, q, v, a)
      gdt = zero
      if (force_is_contact(m%fkind(kk))) then
        x = element_state(m, kk, q, v)
        call contact_gap(m%fkind(kk) - FRC_CONTACT0 + 1, &
                         m%fp(m%fpo(kk):m%fpo(kk) + m%fpn(kk) - 1), &
                         merge(1, 0, m%fbi(kk) > 0), merge(2, 0, m%fbj(kk) > 0), x, g_at, gdt)
        if (nint(w%cst(1, kk)) == 1) then
          g_at = -g_at; gdt = -gdt
        end if
      else if (nint(w%cst(1, kk)) /= MODE_STUCK) then
        x = element_state(m, kk, q, v)
        u = element_slip(m, kk, x)
        g_at = -nint(w%cst(1, kk)) * u%vd
      else
        call values(m, w, q, v, t, gg, gd, status)
        g_at = gg(kk); gdt = gd(kk)
      end if
    end function g_at

    !> Bracket the crossing of g_kk in [t0, t1] (g(t0) <= 0 < g(t1)) to width tol.
    subroutine locate(kk, t0, g0, t1, g1, tright)
      integer, intent(in) :: kk
      real(wp), intent(in) :: t0, g0, t1, g1
      real(wp), intent(out) :: tright
      real(wp) :: lo, hi, glo, ghi, tt, gt, gdt
      integer :: it, side
      lo = t0; hi = t1; glo = min(g0, zero); ghi = g1; side = 0
      do it = 1, MAXIT
        if (hi - lo <= tol) exit
        if (mod(it, 3) == 0 .or. .not. (ghi - glo > zero)) then
          tt = half * (lo + hi)
        else
          tt = (lo * ghi - hi * glo) / (ghi - glo)
          tt = max(lo + 0.01_wp * (hi - lo), min(hi - 0.01_wp * (hi - lo), tt))
        end if
        gt = g_at(kk, tt, gdt)
        if (status /= MBD_OK) exit
        if (gt > zero) then
          hi = tt; ghi = gt
          if (side == 1) glo = half * glo      ! Illinois
          side = 1
        else
          lo = tt; glo = gt
          if (side == -1) ghi = half * ghi
          side = -1
        end if
      end do
      tright = hi
    end subroutine locate

    !> The first of NSAMPLE interior points of the step where g_kk > 0 (tfirst, gfirst);
    !! gfirst <= 0 when there is none.
    subroutine sample(kk, tfirst, gfirst)
      integer, intent(in) :: kk
      real(wp), intent(out) :: tfirst, gfirst
      real(wp) :: gdt
      integer :: i
      gfirst = -one; tfirst = tb
      do i = 1, NSAMPLE
        tfirst = ta + (tb - ta) * i / (NSAMPLE + 1)
        gfirst = g_at(kk, tfirst, gdt)
        if (status /= MBD_OK .or. gfirst > zero) return
      end do
    end subroutine sample

    !> The zero of a contact's rate in [t0, t1] (gd(t0) > 0 > gd(t1)) by bisection, and g
    !! there.
    subroutine rate_root(kk, t0, t1, tmid, gmid)
      integer, intent(in) :: kk
      real(wp), intent(in) :: t0, t1
      real(wp), intent(out) :: tmid, gmid
      real(wp) :: lo, hi, gdt, rate
      integer :: it
      lo = t0; hi = t1
      rate = max(abs(gda(kk)), abs(gdb(kk)))
      do it = 1, MAXIT
        tmid = half * (lo + hi)
        gmid = g_at(kk, tmid, gdt)
        if (status /= MBD_OK) return
        if (gmid > zero .or. hi - lo <= tol) exit
        if (gmid + (hi - lo) * max(rate, abs(gdt)) < zero) exit   ! out of reach here
        if (gdt > zero) then
          lo = tmid
        else
          hi = tmid
        end if
      end do
    end subroutine rate_root
  end subroutine events_find

  !> Change the modes of the elements whose event function is positive at the state (q, qd)
  !! at t, and record the events. Velocities of joints that stick are projected onto
  !! u_dot = 0 (qd changes). changed: some mode changed.
  subroutine events_switch(m, w, t, q, qd, log, changed, status, trec)
    type(model_t), intent(in) :: m              !! model
    type(dyn_work_t), intent(inout) :: w        !! work arrays (modes)
    real(wp), intent(in) :: t                   !! time
    real(wp), intent(in) :: q(:)                !! configuration
    real(wp), intent(inout) :: qd(:)            !! velocities
    type(ev_log_t), intent(inout) :: log        !! event log
    logical, intent(out) :: changed             !! some mode changed
    integer, intent(out) :: status              !! MBD_OK or a solve's failure
    real(wp), intent(in), optional :: trec      !! time to record (default t)
    real(wp) :: g(m%nf), gd(m%nf), dv, dr, qdd(m%nq), lam(m%neq), f, tr
    type(kloc) :: x
    integer :: k, mode
    logical :: stick
    changed = .false.; stick = .false.
    tr = t
    if (present(trec)) tr = trec
    call values(m, w, q, qd, t, g, gd, status)
    if (status /= MBD_OK) return
    do k = 1, m%nf
      if (.not. has_modes(m, k) .or. .not. g(k) > zero) cycle
      changed = .true.
      if (force_is_contact(m%fkind(k))) then
        x = element_state(m, k, q, qd)
        call contact_gap(m%fkind(k) - FRC_CONTACT0 + 1, m%fp(m%fpo(k):m%fpo(k) + m%fpn(k) - 1), &
                         merge(1, 0, m%fbi(k) > 0), merge(2, 0, m%fbj(k) > 0), x, dv, dr)
        if (nint(w%cst(1, k)) == 1) then
          w%cst(:, k) = zero
          call record(log, tr, k, EV_SEPARATION, -dr)
        else
          w%cst(:, k) = [one, max(dr, V0_MIN)]
          call record(log, tr, k, EV_ONSET, dr)
        end if
        cycle
      end if
      mode = nint(w%cst(1, k))
      if (mode == MODE_STUCK) then
        ! slips the way the lock resisted
        f = w%ffr(k)
        w%cst(1, k) = -sign(one, f)
        call record(log, tr, k, EV_SLIP, f)
      else
        ! the slip stopped: stick if the locked joint holds, else slide back
        w%cst(1, k) = MODE_STUCK
        call dyn_accel(m, w, q, qd, t, qdd, lam, status)
        if (status /= MBD_OK) return
        f = w%ffr(k)
        if (abs(f) <= m%fp(m%fpo(k) + 1) * w%fnl(k)) then
          stick = .true.
          call record(log, tr, k, EV_STICK, f)
        else
          w%cst(1, k) = -sign(one, f)
          call record(log, tr, k, EV_REVERSAL, f)
        end if
      end if
    end do
    if (stick) call project_stuck(m, w, q, qd, t, status)
  end subroutine events_switch

end module mbd_events
