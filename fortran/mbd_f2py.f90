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
                           maxit, tmin, qout, qdout, qddout, iinfo, rinfo, qsing, dep, &
                           redundant, tpass, status, msg)
  use iso_c_binding, only: c_double, c_int
  use mbd_api, only: api_kinematics
  implicit none
  integer(c_int), intent(in) :: nb, nc, np, nq, neq, nsteps, maxit
  integer(c_int), intent(in) :: ctab(8, nc)
  real(c_double), intent(in) :: rpar(np), q0(nq), t0, t1, tol, tmin
  real(c_double), intent(out) :: qout(nq, nsteps + 1), qdout(nq, nsteps + 1)
  real(c_double), intent(out) :: qddout(nq, nsteps + 1)
  integer(c_int), intent(out) :: iinfo(10)
  real(c_double), intent(out) :: rinfo(10)
  real(c_double), intent(out) :: qsing(nq)
  integer(c_int), intent(out) :: dep(neq), redundant(neq)
  real(c_double), intent(out) :: tpass(64)
  integer(c_int), intent(out) :: status
  character(len=512), intent(out) :: msg
  !f2py intent(hide) :: nc, np, nq
  !f2py threadsafe
  call api_kinematics(nb, ctab, rpar, q0, t0, t1, nsteps, tol, maxit, tmin, qout, qdout, &
                      qddout, iinfo, rinfo, qsing, dep, redundant, tpass, status, msg)
end subroutine core_kinematics

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
