! mbd_f2py: the only file f2py reads. Plain subroutines with C kinds (f2py maps real(real64)
! to float), no derived types; each forwards to mbd_api. Status 0 ok, < 0 bad input,
! > 0 numerical failure; msg explains.

subroutine core_sizes(nb, nc, ctab, np, rpar, nq, neq, status, msg, bad)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_sizes
  implicit none
  integer(c_int), intent(in) :: nb, nc, np
  integer(c_int), intent(in) :: ctab(8, nc)
  real(c_double), intent(in) :: rpar(np)
  integer(c_int), intent(out) :: nq, neq, status, bad
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np
  call api_sizes(nb, ctab, rpar, nq, neq, status, msg, bad)
end subroutine core_sizes

subroutine core_eval(nb, nc, ctab, np, rpar, nq, neq, q, qd, t, phi, jac, nu, gam, &
                     status, msg, bad)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_eval
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, neq
  integer(c_int), intent(in) :: ctab(8, nc)
  real(c_double), intent(in) :: rpar(np), q(nq), qd(nq), t
  real(c_double), intent(out) :: phi(neq), jac(neq, nq), nu(neq), gam(neq)
  integer(c_int), intent(out) :: status, bad
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq
  call api_eval(nb, ctab, rpar, q, qd, t, phi, jac, nu, gam, status, msg, bad)
end subroutine core_eval

subroutine core_kinematics(nb, nc, ctab, np, rpar, nq, neq, q0, t0, t1, nsteps, tol, &
                           maxit, tmin, every, solver, nout, positions, nd, ctl, qout, qdout, &
                           qddout, iinfo, rinfo, qsing, dep, redundant, tpass, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_kinematics
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, neq, nsteps, maxit, every, solver, nout
  !> 1: positions only, with nd = 0 (q_dot and q_ddot not returned); 0: nd = nout
  integer(c_int), intent(in) :: positions, nd
  integer(c_int), intent(in) :: ctab(8, nc)
  !> progress: ctl(1) outputs stored so far, ctl(2) /= 0 stops the run (read and written
  !! while the call runs, from another thread)
  integer(c_int), intent(inout) :: ctl(2)
  real(c_double), intent(in) :: rpar(np), q0(nq), t0, t1, tol, tmin
  real(c_double), intent(out) :: qout(nq, nout), qdout(nq, nd), qddout(nq, nd)
  integer(c_int), intent(out) :: iinfo(12)
  real(c_double), intent(out) :: rinfo(12)
  real(c_double), intent(out) :: qsing(nq)
  integer(c_int), intent(out) :: dep(neq), redundant(neq)
  real(c_double), intent(out) :: tpass(64)
  integer(c_int), intent(out) :: status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq
  !f2py intent(out, cache) :: qout, qdout, qddout
  ! (out, cache: f2py leaves the arrays unset, not zeroed: the core writes every entry)
  !f2py threadsafe
  call api_kinematics(nb, ctab, rpar, q0, t0, t1, nsteps, tol, maxit, tmin, every, solver, &
                      qout, qdout, qddout, iinfo, rinfo, qsing, dep, redundant, tpass, &
                      status, msg, ctl=ctl, positions=positions)
end subroutine core_kinematics

subroutine core_kin_step(nb, nc, ctab, np, rpar, nq, q, qd, qdd, t_prev, t, tol, maxit, &
                         assemble, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_kin_step
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, maxit, assemble
  integer(c_int), intent(in) :: ctab(8, nc)
  real(c_double), intent(in) :: rpar(np), t_prev, t, tol
  real(c_double), intent(inout) :: q(nq), qd(nq), qdd(nq)
  integer(c_int), intent(out) :: status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq
  !f2py intent(in,out) :: q, qd, qdd
  !f2py threadsafe
  call api_kin_step(nb, ctab, rpar, q, qd, qdd, t_prev, t, tol, maxit, assemble, status, msg)
end subroutine core_kin_step

subroutine core_analyze(nb, nc, ctab, np, rpar, nq, neq, q0, t, tol, q, rank, mobility, &
                        redundant, dep, resid, worst, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_analyze
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, neq
  integer(c_int), intent(in) :: ctab(8, nc)
  real(c_double), intent(in) :: rpar(np), q0(nq), t, tol
  real(c_double), intent(out) :: q(nq), resid
  integer(c_int), intent(out) :: rank, mobility, worst, status
  integer(c_int), intent(out) :: redundant(neq), dep(neq)
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq
  call api_analyze(nb, ctab, rpar, q0, t, tol, q, rank, mobility, redundant, dep, resid, &
                   worst, status, msg)
end subroutine core_analyze

subroutine core_profile(kind, np, raw, na, alpha, pts, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_profile
  implicit none
  integer(c_int), intent(in) :: kind, np, na
  real(c_double), intent(in) :: raw(np), alpha(na)
  real(c_double), intent(out) :: pts(2, na)
  integer(c_int), intent(out) :: status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: np, na
  call api_profile(kind, raw, alpha, pts, status, msg)
end subroutine core_profile

subroutine core_inverse(nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, neq, q0, &
                        t0, t1, nsteps, tol, every, solver, nout, ctl, qout, qdout, qddout, &
                        lamout, eout, iinfo, rinfo, qsing, dep, redundant, tpass, status, &
                        msg, maxev, eo, evo, nev)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_inverse
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nf, nfp, nq, neq, nsteps, every, solver, nout
  integer(c_int), intent(in) :: maxev
  !f2py integer(c_int) optional, intent(in) :: maxev = 1
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf)
  !> progress: ctl(1) outputs stored so far, ctl(2) /= 0 stops the run (read and written
  !! while the call runs, from another thread)
  integer(c_int), intent(inout) :: ctl(2)
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q0(nq), t0, t1, tol
  real(c_double), intent(out) :: qout(nq, nout), qdout(nq, nout)
  real(c_double), intent(out) :: qddout(nq, nout), lamout(neq, nout)
  real(c_double), intent(out) :: eout(4, nout)
  integer(c_int), intent(out) :: iinfo(12), dep(neq), redundant(neq), status
  real(c_double), intent(out) :: rinfo(12), qsing(nq), tpass(64)
  character(len=512), intent(out) :: msg
  real(c_double), intent(out) :: eo(6, nf, nout), evo(4, maxev)
  integer(c_int), intent(out) :: nev
  !f2py intent(hide) :: nc, np, nf, nfp, nq
  !f2py threadsafe
  call api_inverse(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t0, t1, nsteps, tol, every, &
                   solver, qout, qdout, qddout, lamout, eout, iinfo, rinfo, qsing, dep, &
                   redundant, tpass, status, msg, ctl=ctl, eo=eo, evo=evo, nev=nev)
end subroutine core_inverse

! every >= 1: only the outputs k = 0, every, 2 every, ... and k = nsteps are stored; nrow is
! their count, nsteps / every + 1, plus 1 when every does not divide nsteps.
! max_steps: the limit on accepted plus rejected steps (0, the default: the core's default).
! solver: 0 auto (the default), 1 dense, 2 banded linear algebra.
! maxev: the events kept (evo(4, maxev): t, force element, kind, value; nev: how many
! happened); eo(6, nf, nrow): the outputs of each force element (contacts, joint friction).
subroutine core_dynamics(nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, neq, &
                         q0, v0, t0, t1, nsteps, method, rtol, atol, h, rho_inf, balpha, bbeta, &
                         every, nrow, ctl, qout, qdout, qddout, lamout, eout, iinfo, &
                         rinfo, redundant, status, msg, max_steps, maxev, eo, evo, nev, solver)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_dynamics
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nf, nfp, nq, neq, nsteps, method, every, nrow
  integer(c_int), intent(in) :: max_steps, maxev, solver
  !f2py integer(c_int) optional, intent(in) :: max_steps = 0
  !f2py integer(c_int) optional, intent(in) :: maxev = 1
  !f2py integer(c_int) optional, intent(in) :: solver = 0
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf)
  !> progress: ctl(1) outputs stored so far, ctl(2) /= 0 stops the run (read and written
  !! while the call runs, from another thread)
  integer(c_int), intent(inout) :: ctl(2)
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q0(nq), v0(nq)
  real(c_double), intent(in) :: t0, t1, rtol, atol, h, rho_inf, balpha, bbeta
  real(c_double), intent(out) :: qout(nq, nrow), qdout(nq, nrow)
  real(c_double), intent(out) :: qddout(nq, nrow), lamout(neq, nrow)
  real(c_double), intent(out) :: eout(4, nrow)
  integer(c_int), intent(out) :: iinfo(12), redundant(neq), status
  real(c_double), intent(out) :: rinfo(12)
  character(len=512), intent(out) :: msg
  real(c_double), intent(out) :: eo(6, nf, nrow), evo(4, maxev)
  integer(c_int), intent(out) :: nev
  !f2py intent(hide) :: nc, np, nf, nfp, nq
  !f2py threadsafe
  call api_dynamics(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, v0, t0, t1, nsteps, method, &
                    rtol, atol, h, rho_inf, balpha, bbeta, every, qout, qdout, qddout, lamout, &
                    eout, iinfo, rinfo, redundant, status, msg, max_steps, eo, evo, nev, &
                    ctl=ctl, solver=solver)
end subroutine core_dynamics

! solver: 0 auto (the default), 1 dense, 2 banded linear algebra.
subroutine core_statics(nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, neq, q0, &
                        t, q, lam, stable, resid, iinfo, status, msg, solver)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_statics
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nf, nfp, nq, neq
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf)
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q0(nq), t
  real(c_double), intent(out) :: q(nq), lam(neq), resid
  integer(c_int), intent(out) :: stable, iinfo(12), status
  character(len=512), intent(out) :: msg
  integer(c_int), intent(in) :: solver
  !f2py integer(c_int) optional, intent(in) :: solver = 0
  !f2py intent(hide) :: nc, np, nf, nfp, nq
  call api_statics(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, q, lam, stable, resid, &
                   iinfo, status, msg, solver=solver)
end subroutine core_statics

! Small vibrations about the equilibrium near q0 (equilibrium 1; 0: about the assembled q0):
! the lowest kmax undamped omega^2, kinds (1 vibration, 0 rigid, -1 unstable) and shapes,
! 2 kmax damped eigenvalues and their shapes (zre + i zim, the largest entry 1); iinfo(1) the
! number of free motions. solver: 0 auto, 1 dense, 2 banded.
subroutine core_modes(nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, neq, q0, &
                      t, equilibrium, kmax, solver, q, lam, stable, resid, omega2, kinds, sre, &
                      sim, shapes, zre, zim, iinfo, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_modes
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nf, nfp, nq, neq, equilibrium, kmax, solver
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf)
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q0(nq), t
  real(c_double), intent(out) :: q(nq), lam(neq), resid, omega2(kmax), sre(2 * kmax), &
                                 sim(2 * kmax), shapes(nq, kmax), zre(nq, 2 * kmax), &
                                 zim(nq, 2 * kmax)
  integer(c_int), intent(out) :: stable, kinds(kmax), iinfo(12), status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nf, nfp, nq
  call api_modes(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, equilibrium, kmax, q, lam, &
                 stable, resid, omega2, kinds, sre, sim, shapes, iinfo, status, msg, solver, &
                 zre, zim)
end subroutine core_modes

! The frequency response about the equilibrium near q0 (equilibrium 1; 0: about the assembled
! q0) to each design parameter of ptab varied harmonically at each angular frequency omega:
! dq = (hre + i him) per unit amplitude (nq, npar, nw); iinfo(1) the free motions, iinfo(8)
! the frequency at which it is unbounded; lre + i lim the multipliers' response (neq, npar,
! nw). solver: 0 auto, 1 dense, 2 banded.
subroutine core_frf(nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, neq, q0, t, &
                    equilibrium, npar, ptab, nw, omega, solver, q, lam, stable, resid, hre, him, &
                    lre, lim, iinfo, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_frf
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nf, nfp, nq, neq, equilibrium, npar, nw, solver
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf), ptab(2, npar)
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q0(nq), t, omega(nw)
  real(c_double), intent(out) :: q(nq), lam(neq), resid, hre(nq, npar, nw), him(nq, npar, nw), &
                                 lre(neq, npar, nw), lim(neq, npar, nw)
  integer(c_int), intent(out) :: stable, iinfo(12), status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nf, nfp, nq, npar, nw
  call api_frf(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, equilibrium, ptab, omega, q, lam, &
               stable, resid, hre, him, iinfo, status, msg, solver, lre, lim)
end subroutine core_frf

subroutine core_linearize(nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, neq, q0, &
                          t, equilibrium, npar, ptab, ns, solver, vel, mult, nqo, q, lam, &
                          stable, resid, a, b, c, d, iinfo, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_linearize
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nf, nfp, nq, neq, equilibrium, npar, ns, solver
  integer(c_int), intent(in) :: vel, mult           ! 1: the velocities', the multipliers' too
  integer(c_int), intent(in) :: nqo                 ! nq (+ nq with vel) (+ neq with mult)
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf), ptab(2, npar)
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q0(nq), t
  real(c_double), intent(out) :: q(nq), lam(neq), resid, a(ns, ns), b(ns, npar), c(nqo, ns), &
                                 d(nqo, npar)
  integer(c_int), intent(out) :: stable, iinfo(12), status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nf, nfp, nq, npar
  call api_linearize(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, equilibrium, ptab, q, lam, &
                     stable, resid, a, b, c, d, iinfo, status, msg, solver, vel, mult)
end subroutine core_linearize

subroutine core_reactions(nb, nc, ctab, np, rpar, nq, neq, nt, q, t, lam, reac, rloc, status, &
                          msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_reactions
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, neq, nt
  integer(c_int), intent(in) :: ctab(8, nc)
  real(c_double), intent(in) :: rpar(np), q(nq, nt), t(nt), lam(neq, nt)
  real(c_double), intent(out) :: reac(6, nc, nt), rloc(6, nc, nt)
  integer(c_int), intent(out) :: status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq, neq, nt
  call api_reactions(nb, ctab, rpar, q, t, lam, reac, rloc, status, msg)
end subroutine core_reactions

subroutine core_conditioning(nb, nc, ctab, np, rpar, nq, nt, q, t, cond, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_measures, only: api_conditioning
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, nt
  integer(c_int), intent(in) :: ctab(8, nc)
  real(c_double), intent(in) :: rpar(np), q(nq, nt), t(nt)
  real(c_double), intent(out) :: cond(nt)
  integer(c_int), intent(out) :: status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq, nt
  call api_conditioning(nb, ctab, rpar, q, t, cond, status, msg)
end subroutine core_conditioning

subroutine core_ratio(nb, nc, ctab, np, rpar, nq, nt, q, t, kind, ref, x, y, ratio, bad, &
                      status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_measures, only: api_ratio
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, nt, kind, ref
  integer(c_int), intent(in) :: ctab(8, nc), x(2), y(2)
  real(c_double), intent(in) :: rpar(np), q(nq, nt), t(nt)
  real(c_double), intent(out) :: ratio(nt)
  integer(c_int), intent(out) :: bad, status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq, nt
  call api_ratio(nb, ctab, rpar, q, t, kind, ref, x, y, ratio, bad, status, msg)
end subroutine core_ratio

subroutine core_link_angle(nq, nt, q, kind, b, s, mu, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_measures, only: api_link_angle
  implicit none
  integer(c_int), intent(in) :: nq, nt, kind
  integer(c_int), intent(in) :: b(3)
  real(c_double), intent(in) :: q(nq, nt), s(2, 3)
  real(c_double), intent(out) :: mu(nt)
  integer(c_int), intent(out) :: status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nq, nt
  call api_link_angle(q, kind, b, s, mu, status, msg)
end subroutine core_link_angle

! Every measure of a list (kind, mint, spts, pref as api_measures takes them) and its design
! derivatives at the states q (nq, nt) with their sensitivities sq (nq, npar, nt) against the
! parameter table ptab (2, npar): vals (nm, nt), dvals (nm, npar, nt), bad (measure,
! quantity).
subroutine core_measures_dp(nb, nc, ctab, np, rpar, nq, nt, q, sq, t, nm, kind, mint, spts, &
                            pref, npar, ptab, vals, dvals, bad, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_measures, only: api_measures
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, nt, nm, npar
  integer(c_int), intent(in) :: ctab(8, nc), kind(nm), mint(5, nm), pref(2, 3, nm)
  integer(c_int), intent(in) :: ptab(2, npar)
  real(c_double), intent(in) :: rpar(np), q(nq, nt), sq(nq, npar, nt), t(nt), spts(2, 3, nm)
  real(c_double), intent(out) :: vals(nm, nt), dvals(nm, npar, nt)
  integer(c_int), intent(out) :: bad(2), status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq, nt, nm, npar
  call api_measures(nb, ctab, rpar, q, t, kind, mint, spts, pref, vals, bad, status, msg, &
                    ptab, sq, dvals)
end subroutine core_measures_dp

subroutine core_fun_values(np, p, nt, t, f, f1, f2, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_measures, only: api_fun_values
  implicit none
  integer(c_int), intent(in) :: np, nt
  real(c_double), intent(in) :: p(np), t(nt)
  real(c_double), intent(out) :: f(nt), f1(nt), f2(nt)
  integer(c_int), intent(out) :: status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: np, nt
  call api_fun_values(p, t, f, f1, f2, status, msg)
end subroutine core_fun_values
! ------------------------------------------------------------------ design sensitivities
! A design parameter is a column (table, index) of ptab: table 1 rpar, 2 bmass (flattened
! (2, nb)), 3 grav, 4 fpar (mbd_sensitivity).

subroutine core_eval_d(nb, nc, ctab, np, rpar, nq, neq, q, qd, t, dq, dqd, npar, ptab, tphi, &
                       tjac, tnu, tgam, status, msg, bad)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_eval_d
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, neq, npar
  integer(c_int), intent(in) :: ctab(8, nc), ptab(2, npar)
  real(c_double), intent(in) :: rpar(np), q(nq), qd(nq), t, dq(nq), dqd(nq)
  real(c_double), intent(out) :: tphi(neq), tjac(neq, nq), tnu(neq), tgam(neq)
  integer(c_int), intent(out) :: status, bad
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq, npar
  call api_eval_d(nb, ctab, rpar, q, qd, t, dq, dqd, ptab, tphi, tjac, tnu, tgam, status, msg, &
                  bad)
end subroutine core_eval_d

subroutine core_forces_d(nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, q, qd, &
                         t, nk, dq, dqd, ptab, qf, dcol, drow, status, msg, bad)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_forces_d
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nf, nfp, nq, nk
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf), ptab(2, nk)
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q(nq), qd(nq), t
  real(c_double), intent(in) :: dq(nq, nk), dqd(nq, nk)
  real(c_double), intent(out) :: qf(nq), dcol(nq, nk), drow(nq, nk)
  integer(c_int), intent(out) :: status, bad
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nf, nfp, nq, nk
  call api_forces_d(nb, ctab, rpar, bmass, grav, ftab, fpar, q, qd, t, dq, dqd, ptab, qf, dcol, &
                    drow, status, msg, bad)
end subroutine core_forces_d

subroutine core_stiffness(nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, neq, q, &
                          t, lam, kpat, cpat, kcol, ccol, status, msg, bad)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_stiffness
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nf, nfp, nq, neq
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf)
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q(nq), t, lam(neq)
  real(c_double), intent(out) :: kpat(nq, nq), cpat(nq, nq), kcol(nq, nq), ccol(nq, nq)
  integer(c_int), intent(out) :: status, bad
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nf, nfp, nq, neq
  call api_stiffness(nb, ctab, rpar, bmass, grav, ftab, fpar, q, t, lam, kpat, cpat, kcol, ccol, &
                     status, msg, bad)
end subroutine core_stiffness

subroutine core_kinematics_sens(nb, nc, ctab, np, rpar, nq, neq, q0, t0, t1, nsteps, tol, &
                                maxit, tmin, every, solver, nout, npar, ptab, qout, qdout, &
                                qddout, s3, ssum, iinfo, rinfo, qsing, dep, redundant, &
                                tpass, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_kinematics
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, neq, nsteps, maxit, every, solver, nout, npar
  integer(c_int), intent(in) :: ctab(8, nc), ptab(2, npar)
  real(c_double), intent(in) :: rpar(np), q0(nq), t0, t1, tol, tmin
  real(c_double), intent(out) :: qout(nq, nout), qdout(nq, nout), qddout(nq, nout)
  !> dq/dp, dq_dot/dp and dq_ddot/dp in one block (one allocation: repeated runs reuse it
  !! rather than map and fault in three)
  real(c_double), intent(out) :: s3(nq, npar, nout, 3)
  !> each output's sum of its sensitivities: finite exactly when they all are (barring an
  !! overflow of the sum), so the caller need not read the block to check it
  real(c_double), intent(out) :: ssum(nout)
  integer(c_int), intent(out) :: iinfo(12)
  real(c_double), intent(out) :: rinfo(12)
  real(c_double), intent(out) :: qsing(nq)
  integer(c_int), intent(out) :: dep(neq), redundant(neq)
  real(c_double), intent(out) :: tpass(64)
  integer(c_int), intent(out) :: status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq, npar
  !f2py intent(out, cache) :: qout, qdout, qddout, s3, ssum
  ! (out, cache: f2py leaves the arrays unset, not zeroed: the core writes every entry)
  !f2py threadsafe
  call api_kinematics(nb, ctab, rpar, q0, t0, t1, nsteps, tol, maxit, tmin, every, solver, &
                      qout, qdout, qddout, iinfo, rinfo, qsing, dep, redundant, tpass, &
                      status, msg, ptab, s3(:, :, :, 1), s3(:, :, :, 2), s3(:, :, :, 3), &
                      ssum=ssum)
end subroutine core_kinematics_sens

subroutine core_inverse_sens(nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, neq, &
                             q0, t0, t1, nsteps, tol, every, solver, nout, npar, ptab, qout, &
                             qdout, qddout, lamout, eout, sq, sqd, sqdd, slam, iinfo, rinfo, &
                             qsing, dep, redundant, tpass, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_inverse
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nf, nfp, nq, neq, nsteps, every, solver, nout, npar
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf), ptab(2, npar)
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q0(nq), t0, t1, tol
  real(c_double), intent(out) :: qout(nq, nout), qdout(nq, nout)
  real(c_double), intent(out) :: qddout(nq, nout), lamout(neq, nout)
  real(c_double), intent(out) :: eout(4, nout)
  real(c_double), intent(out) :: sq(nq, npar, nout), sqd(nq, npar, nout), sqdd(nq, npar, nout)
  real(c_double), intent(out) :: slam(neq, npar, nout)
  integer(c_int), intent(out) :: iinfo(12), dep(neq), redundant(neq), status
  real(c_double), intent(out) :: rinfo(12), qsing(nq), tpass(64)
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nf, nfp, nq, npar
  call api_inverse(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t0, t1, nsteps, tol, every, &
                   solver, qout, qdout, qddout, lamout, eout, iinfo, rinfo, qsing, dep, &
                   redundant, tpass, status, msg, ptab, sq, sqd, sqdd, slam)
end subroutine core_inverse_sens

subroutine core_statics_sens(nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, neq, &
                             q0, t, npar, ptab, solver, q, lam, sq, slam, stable, resid, iinfo, &
                             status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_statics
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nf, nfp, nq, neq, npar
  integer(c_int), intent(in) :: solver     ! 0 auto, 1 dense, 2 banded
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf), ptab(2, npar)
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q0(nq), t
  real(c_double), intent(out) :: q(nq), lam(neq), sq(nq, npar), slam(neq, npar), resid
  integer(c_int), intent(out) :: stable, iinfo(12), status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nf, nfp, nq, npar
  call api_statics(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, t, q, lam, stable, resid, &
                   iinfo, status, msg, ptab, sq, slam, solver)
end subroutine core_statics_sens

subroutine core_reactions_dp(nb, nc, ctab, np, rpar, nq, neq, nt, npar, ptab, q, t, lam, sq, &
                             slam, dreac, drloc, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_reactions_dp
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, neq, nt, npar
  integer(c_int), intent(in) :: ctab(8, nc), ptab(2, npar)
  real(c_double), intent(in) :: rpar(np), q(nq, nt), t(nt), lam(neq, nt)
  real(c_double), intent(in) :: sq(nq, npar, nt), slam(neq, npar, nt)
  real(c_double), intent(out) :: dreac(6, nc, npar, nt), drloc(6, nc, npar, nt)
  integer(c_int), intent(out) :: status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq, neq, nt, npar
  call api_reactions_dp(nb, ctab, rpar, ptab, q, t, lam, sq, slam, dreac, drloc, status, msg)
end subroutine core_reactions_dp

subroutine core_dynamics_sens(nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, neq, &
                              q0, v0, t0, t1, nsteps, rtol, atol, every, max_steps, solver, &
                              nrow, npar, ptab, method, h, rho_inf, qout, qdout, qddout, lamout, &
                              eout, sq, sqd, sqdd, slam, iinfo, rinfo, redundant, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_dynamics_sens
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nf, nfp, nq, neq, nsteps, every, max_steps, nrow
  integer(c_int), intent(in) :: npar, solver   ! solver: 0 auto, 1 dense, 2 banded
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf), ptab(2, npar)
  ! method: 2 dopri5, 1 generalized-alpha (its step h, 0 adaptive, and rho_inf)
  integer(c_int), intent(in) :: method
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q0(nq), v0(nq)
  real(c_double), intent(in) :: t0, t1, rtol, atol, h, rho_inf
  real(c_double), intent(out) :: qout(nq, nrow), qdout(nq, nrow)
  real(c_double), intent(out) :: qddout(nq, nrow), lamout(neq, nrow)
  real(c_double), intent(out) :: eout(4, nrow)
  real(c_double), intent(out) :: sq(nq, npar, nrow), sqd(nq, npar, nrow), sqdd(nq, npar, nrow)
  real(c_double), intent(out) :: slam(neq, npar, nrow)
  integer(c_int), intent(out) :: iinfo(12), redundant(neq), status
  real(c_double), intent(out) :: rinfo(12)
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nf, nfp, nq, npar
  call api_dynamics_sens(nb, ctab, rpar, bmass, grav, ftab, fpar, q0, v0, t0, t1, nsteps, rtol, &
                         atol, every, max_steps, ptab, qout, qdout, qddout, lamout, eout, sq, &
                         sqd, sqdd, slam, iinfo, rinfo, redundant, status, msg, solver, method, &
                         h, rho_inf)
end subroutine core_dynamics_sens

! ------------------------------------------------------------------ design sweeps
! One analysis (1 kinematics, 2 inverse dynamics, 3 statics, 4 dynamics) for ncase parameter
! sets: vtab (2, nv) names the entries each case sets (table 1 rpar, 2 bmass flattened, 3
! grav, 4 fpar; 1-based index), vals (nv, ncase) their values, opens (2, no) the open phases
! to set again from q0 (index in rpar, row of Phi); settings in iset, rset (mbd_batch). nlam
! is neq (0 for kinematics), ne 4 (0 for kinematics); nrow the output rows per case. With
! nm > 0 measures (mbd_measures: mkind, mint, mpts, mref, at the output times) go to mout
! (nm, nrow, ncase), their failures to mbad (3, ncase); with npar > 0 design parameters
! (ptab) their sensitivities to sq, sqd, sqdd (nq, npar, nrow, ncase) and slam (nsl = neq for
! inverse dynamics, statics and dynamics, 0 for kinematics); with both, the measures' design
! derivatives to dmout (nm, npar, nrow, ncase). The tables have nmp = max(nm, 1) and npp =
! max(npar, 1) columns (f2py takes no zero-length table).
subroutine core_batch(analysis, nb, nc, ctab, np, rpar, bmass, grav, nf, ftab, nfp, fpar, nq, &
                      q0, v0, nv, vtab, ncase, vals, no, opens, iset, rset, neq, nrow, nd, &
                      nlam, ne, times, nm, nmp, mkind, mint, mpts, mref, npar, npp, ptab, nsl, &
                      qout, qdout, qddout, lamout, eout, iinfo, rinfo, qsing, dep, redundant, &
                      mout, mbad, sq, sqd, sqdd, slam, dmout, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_batch, only: batch_run
  use mbd_status, only: MBD_BAD_INPUT
  implicit none
  integer(c_int), intent(in) :: analysis, nb, nc, np, nf, nfp, nq, nv, ncase, no, neq, nrow
  !> nd: rows of qdout and qddout (nrow; 0 for positions-only kinematics, iset(7) = 1)
  integer(c_int), intent(in) :: nlam, ne, nd, nm, nmp, npar, npp, nsl
  integer(c_int), intent(in) :: ctab(8, nc), ftab(6, nf), vtab(2, nv), opens(2, no), iset(8)
  real(c_double), intent(in) :: rpar(np), bmass(2, nb), grav(2), fpar(nfp), q0(nq), v0(nq)
  real(c_double), intent(in) :: vals(nv, ncase), rset(12), times(nrow), mpts(2, 3, nmp)
  integer(c_int), intent(in) :: mkind(nmp), mint(5, nmp), mref(2, 3, nmp), ptab(2, npp)
  real(c_double), intent(out) :: qout(nq, nrow, ncase), qdout(nq, nd, ncase)
  real(c_double), intent(out) :: qddout(nq, nd, ncase), lamout(nlam, nrow, ncase)
  real(c_double), intent(out) :: eout(ne, nrow, ncase), mout(nm, nrow, ncase)
  real(c_double), intent(out) :: sq(nq, npar, nrow, ncase), sqd(nq, npar, nrow, ncase)
  real(c_double), intent(out) :: sqdd(nq, npar, nrow, ncase), slam(nsl, npar, nrow, ncase)
  real(c_double), intent(out) :: dmout(nm, npar, nrow, ncase)
  integer(c_int), intent(out) :: iinfo(12, ncase), dep(neq, ncase), redundant(neq, ncase)
  integer(c_int), intent(out) :: mbad(3, ncase)
  real(c_double), intent(out) :: rinfo(12, ncase), qsing(nq, ncase)
  integer(c_int), intent(out) :: status(ncase)
  character(len=512), intent(out) :: msg(ncase)
  !f2py intent(hide) :: nc, np, nf, nfp, nq, nv, ncase, no, nmp, npp
  !f2py threadsafe
  if (nm > nmp .or. npar > npp) then
    qout = 0; qdout = 0; qddout = 0; lamout = 0; eout = 0; mout = 0; sq = 0; sqd = 0
    sqdd = 0; slam = 0; iinfo = 0; dep = 0; redundant = 0; mbad = 0; rinfo = 0; qsing = 0
    dmout = 0
    status = MBD_BAD_INPUT; msg = 'batch: more measures or parameters than their tables hold'
    return
  end if
  ! (an empty list of measures or parameters: the batch runs without them)
  call batch_run(analysis, nb, ctab, rpar, bmass, grav, ftab, fpar, q0, v0, vtab, vals, &
                 opens, iset, rset, qout, qdout, qddout, lamout, eout, iinfo, rinfo, qsing, &
                 dep, redundant, status, msg, times, mkind(1:nm), mint(:, 1:nm), &
                 mpts(:, :, 1:nm), mref(:, :, 1:nm), mout, mbad, ptab(:, 1:npar), sq, sqd, &
                 sqdd, slam, dmout)
end subroutine core_batch
! Normal force of each cam joint on its follower at states q (nq, nt), times t and
! multipliers lam: fn(nc, nt), negative where the joint must pull the follower onto its profile.
subroutine core_cam_forces(nb, nc, ctab, np, rpar, nq, neq, nt, q, t, lam, fn, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_cam_forces
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, neq, nt
  integer(c_int), intent(in) :: ctab(8, nc)
  real(c_double), intent(in) :: rpar(np), q(nq, nt), t(nt), lam(neq, nt)
  real(c_double), intent(out) :: fn(nc, nt)
  integer(c_int), intent(out) :: status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq, neq, nt
  call api_cam_forces(nb, ctab, rpar, q, t, lam, fn, status, msg)
end subroutine core_cam_forces
