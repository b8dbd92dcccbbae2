"""The calls into the compiled core (``mbd2d._core``, built by f2py from
``fortran/mbd_f2py.f90``): the only module that touches it.

Each function passes the flat tables and settings as the f2py wrapper wants them and returns
the core's outputs by name (``out.status``, ``out.msg`` as text, ...). The outputs are the
core's own arrays (Fortran order, one column per output time); turning them into results
and status codes into exceptions is the caller's job.
"""
from __future__ import annotations

from types import SimpleNamespace
from typing import Any, Callable

import numpy as np

from .. import _core
from ..errors import InsufficientMemoryError
from .status import MEMORY_ADVICE
from .tables import BatchTables, DynamicTables, MeasureTables, Packed, decode

#: length of the core's report arrays iinfo and rinfo (NINFO of fortran/mbd_api.f90)
NINFO = 12


def _named(names: str, fn: Callable[..., tuple[Any, ...]], *args: Any, numbers: float = 0,
           **kwargs: Any) -> SimpleNamespace:
    """Call the core and name its output tuple; ``msg`` decoded to text. The arrays f2py
    allocates for the call (its outputs, about ``numbers`` float64 values) failing to fit in
    memory is an InsufficientMemoryError naming their size."""
    try:
        out = fn(*args, **kwargs)
    except InsufficientMemoryError:
        raise
    except MemoryError:
        what = getattr(fn, "__name__", "the core")
        nbytes = 8.0 * numbers
        raise InsufficientMemoryError(f"allocating the core's arrays for {what} (about "
                                      f"{nbytes / 2**20:.1f} MiB) failed; {MEMORY_ADVICE}",
                                      nbytes) from None
    fields = dict(zip(names.split(), out, strict=True))
    if "msg" in fields:
        if np.ndim(fields["msg"]):       # a batch: one message per case
            fields["msg"] = [decode(m) for m in fields["msg"]]
        else:
            fields["msg"] = decode(fields["msg"])
    if np.ndim(fields["status"]) == 0:
        fields["status"] = int(fields["status"])
    return SimpleNamespace(**fields)


def sizes(nb: int, ctab: np.ndarray, rpar: np.ndarray) -> SimpleNamespace:
    """Check the tables; ``nq``, ``neq``, ``status``, ``msg``, ``bad`` (1-based constraint)."""
    return _named("nq neq status msg bad", _core.core_sizes, nb, ctab, rpar,
                  numbers=np.size(rpar) + np.size(ctab) / 2)   # the inputs, if copied


def evaluate(nb: int, ctab: np.ndarray, rpar: np.ndarray, neq: int, q: np.ndarray,
             qd: np.ndarray, t: float) -> SimpleNamespace:
    """Phi, J, nu and gamma at a state: ``phi``, ``jac``, ``nu``, ``gam``, ``status``, ``msg``,
    ``bad``."""
    return _named("phi jac nu gam status msg bad", _core.core_eval, nb, ctab, rpar, neq, q, qd,
                  float(t), numbers=neq * (len(q) + 3))


def new_ctl() -> np.ndarray:
    """The progress array a time loop shares while it runs (read and written from another
    thread): [0] outputs done so far, [1] set to 1 to ask the run to stop."""
    return np.zeros(2, dtype=np.int32)


def kinematics(p: Packed, t0: float, t1: float, steps: int, tol: float, maxit: int,
               tmin: float, every: int, solver: int, nout: int,
               ctl: np.ndarray | None = None, positions: bool = False) -> SimpleNamespace:
    """The whole kinematic run: ``q``, ``qd``, ``qdd`` (nq, nout; (nq, 0) with
    ``positions``), ``iinfo``, ``rinfo``, ``qsing``, ``dep``, ``red``, ``tpass``,
    ``status``, ``msg``. ``ctl``: see :func:`new_ctl` (the core releases the GIL while it
    runs)."""
    nd = 0 if positions else nout
    return _named("q qd qdd iinfo rinfo qsing dep red tpass status msg", _core.core_kinematics,
                  p.nb, p.ctab, p.rpar, p.neq, p.q0, t0, t1, steps, tol, maxit, tmin, every,
                  solver, nout, int(positions), nd, new_ctl() if ctl is None else ctl,
                  numbers=p.nq * (nout + 2 * nd) + p.nq + 2 * p.neq)


def kin_step(p: Packed, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, t_prev: float,
             t: float, tol: float, maxit: int, assemble: bool) -> SimpleNamespace:
    """One kinematic step (or the assembly at t): ``q``, ``qd``, ``qdd``, ``status``,
    ``msg``. q, qd and qdd may be overwritten (f2py passes them in and out)."""
    return _named("q qd qdd status msg", _core.core_kin_step, p.nb, p.ctab, p.rpar, q, qd, qdd,
                  t_prev, t, tol, maxit, int(assemble))


def analyze(p: Packed, t: float, tol: float) -> SimpleNamespace:
    """Rank and redundancy at the assembled configuration: ``q``, ``rank``, ``mobility``,
    ``red``, ``dep``, ``resid``, ``worst``, ``status``, ``msg``."""
    return _named("q rank mobility red dep resid worst status msg", _core.core_analyze, p.nb,
                  p.ctab, p.rpar, p.neq, p.q0, t, tol, numbers=p.nq + 2 * p.neq)


def profile(kind: int, raw: np.ndarray, alphas: np.ndarray) -> SimpleNamespace:
    """Points c(alpha) of a closed profile curve: ``pts`` (2, n), ``status``, ``msg``."""
    return _named("pts status msg", _core.core_profile, kind, raw, alphas,
                  numbers=2 * len(alphas))


def inverse(p: Packed, d: DynamicTables, t0: float, t1: float, steps: int, tol: float,
            every: int, solver: int, nout: int, maxev: int = 1,
            ctl: np.ndarray | None = None) -> SimpleNamespace:
    """Kinematics plus multipliers and energies: ``q``, ``qd``, ``qdd``, ``lam``, ``e``,
    ``iinfo``, ``rinfo``, ``qsing``, ``dep``, ``red``, ``tpass``, ``status``, ``msg``, the
    force elements' outputs ``eo`` (6, nf, nout) and the contact events ``evo`` (4, maxev),
    ``nev`` (found at the outputs). ``ctl``: see :func:`new_ctl`; ctl[0] runs to 2 nout
    (kinematics, then multipliers)."""
    return _named("q qd qdd lam e iinfo rinfo qsing dep red tpass status msg eo evo nev",
                  _core.core_inverse, ctab=p.ctab, rpar=p.rpar, bmass=d.bmass, grav=d.grav,
                  ftab=d.ftab, fpar=d.fpar, neq=p.neq, q0=p.q0, t0=t0, t1=t1, nsteps=steps,
                  tol=tol, every=every, solver=solver, nout=nout, maxev=max(1, maxev),
                  ctl=new_ctl() if ctl is None else ctl,
                  numbers=(3 * p.nq + p.neq + 4 + 6 * d.ftab.shape[1]) * nout + p.nq
                  + 2 * p.neq + 4 * maxev)


def dynamics(p: Packed, d: DynamicTables, t0: float, t1: float, steps: int, method: int,
             rtol: float, atol: float, h: float, rho_inf: float, alpha: float, beta: float,
             every: int, nrow: int, max_steps: int, maxev: int = 1,
             ctl: np.ndarray | None = None, solver: int = 0) -> SimpleNamespace:
    """Forward dynamics: ``q``, ``qd``, ``qdd``, ``lam``, ``e``, ``iinfo``, ``rinfo``, ``red``,
    ``status``, ``msg``, the force elements' outputs ``eo`` (6, nf, nrow) and the events
    ``evo`` (4, maxev: t, element, kind, value), ``nev`` (how many happened). max_steps: the
    limit on accepted plus rejected steps. ``ctl``: see :func:`new_ctl`; solver: 0 auto,
    1 dense, 2 banded."""
    return _named("q qd qdd lam e iinfo rinfo red status msg eo evo nev", _core.core_dynamics,
                  ctab=p.ctab, rpar=p.rpar, bmass=d.bmass, grav=d.grav, ftab=d.ftab,
                  fpar=d.fpar, neq=p.neq, q0=p.q0, v0=d.v0, t0=t0, t1=t1, nsteps=steps,
                  method=method, rtol=rtol, atol=atol, h=h, rho_inf=rho_inf, balpha=alpha,
                  bbeta=beta, every=every, nrow=nrow, max_steps=max_steps,
                  maxev=max(1, maxev), ctl=new_ctl() if ctl is None else ctl, solver=solver,
                  numbers=(3 * p.nq + p.neq + 4 + 6 * d.ftab.shape[1]) * nrow + p.neq
                  + 4 * maxev)


def statics(p: Packed, d: DynamicTables, t: float, solver: int = 0) -> SimpleNamespace:
    """Static equilibrium: ``q``, ``lam``, ``stable``, ``resid``, ``iinfo``, ``status``,
    ``msg``; solver: 0 auto, 1 dense, 2 banded."""
    return _named("q lam stable resid iinfo status msg", _core.core_statics, ctab=p.ctab,
                  rpar=p.rpar, bmass=d.bmass, grav=d.grav, ftab=d.ftab, fpar=d.fpar,
                  neq=p.neq, q0=p.q0, t=t, solver=solver, numbers=p.nq + p.neq)


def modes(p: Packed, d: DynamicTables, t: float, equilibrium: bool, kmax: int,
          solver: int = 0) -> SimpleNamespace:
    """Small vibrations about the equilibrium near q0 (or about the assembled q0): ``q``,
    ``lam``, ``stable``, ``resid``, ``omega2`` and ``kinds`` (kmax; 1 vibration, 0 rigid,
    -1 unstable), ``sre``, ``sim`` (2 kmax), ``shapes`` (nq, kmax), ``zre``, ``zim`` (nq,
    2 kmax: the damped shapes, largest entry 1), ``iinfo`` (iinfo[0]: the free motions),
    ``status``, ``msg``."""
    return _named("q lam stable resid omega2 kinds sre sim shapes zre zim iinfo status msg",
                  _core.core_modes,
                  ctab=p.ctab, rpar=p.rpar, bmass=d.bmass, grav=d.grav, ftab=d.ftab,
                  fpar=d.fpar, neq=p.neq, q0=p.q0, t=t, equilibrium=int(equilibrium),
                  kmax=kmax, solver=solver, numbers=p.nq * (5 * kmax + 1) + p.neq + 5 * kmax)


def frf(p: Packed, d: DynamicTables, t: float, equilibrium: bool, ptab: np.ndarray,
        omega: np.ndarray, solver: int = 0) -> SimpleNamespace:
    """The frequency response about the equilibrium near q0 (or about the assembled q0) to
    the parameters of ptab at the angular frequencies omega: ``q``, ``lam``, ``stable``,
    ``resid``, ``hre``, ``him`` (nq, np, nw), ``lre``, ``lim`` (neq, np, nw: the multipliers'
    response), ``iinfo`` (iinfo[0]: the free motions,
    iinfo[7]: a frequency at which the response is unbounded, 1-based), ``status``,
    ``msg``."""
    nw = int(np.size(omega))
    return _named("q lam stable resid hre him lre lim iinfo status msg", _core.core_frf,
                  ctab=p.ctab, rpar=p.rpar, bmass=d.bmass, grav=d.grav, ftab=d.ftab,
                  fpar=d.fpar, neq=p.neq, q0=p.q0, t=t, equilibrium=int(equilibrium),
                  ptab=ptab, omega=np.asarray(omega, dtype=float), solver=solver,
                  numbers=2.0 * (p.nq + p.neq) * ptab.shape[1] * nw + p.nq + p.neq)


def linearize(p: Packed, d: DynamicTables, t: float, equilibrium: bool, ptab: np.ndarray,
              nstates: int, solver: int = 0, velocities: bool = False,
              multipliers: bool = False) -> SimpleNamespace:
    """The linearized motion about the equilibrium near q0 (or about the assembled q0) as a
    state-space system with the parameters of ptab as inputs: ``q``, ``lam``, ``stable``,
    ``resid``, ``a`` (nstates, nstates), ``b`` (nstates, np), ``c`` (nq, nstates), ``d``
    (nq, np) in their leading 2 nfree states (with velocities 2 nq rows of c and d: the
    velocities' outputs after the coordinates'; with multipliers neq rows more after those:
    the multipliers'), ``iinfo`` (iinfo[0]: nfree), ``status`` (MBD_BAD_COUNT when nstates
    < 2 nfree), ``msg``."""
    ns, npar = max(int(nstates), 1), ptab.shape[1]
    nqo = (2 if velocities else 1) * p.nq + (p.neq if multipliers else 0)
    return _named("q lam stable resid a b c d iinfo status msg", _core.core_linearize,
                  ctab=p.ctab, rpar=p.rpar, bmass=d.bmass, grav=d.grav, ftab=d.ftab,
                  fpar=d.fpar, neq=p.neq, q0=p.q0, t=t, equilibrium=int(equilibrium),
                  ptab=ptab, ns=ns, solver=solver, vel=int(velocities),
                  mult=int(multipliers), nqo=nqo,
                  numbers=float(ns + nqo) * (ns + npar) + p.nq + p.neq)


def cam_forces(p: Packed, q: np.ndarray, t: np.ndarray, lam: np.ndarray) -> SimpleNamespace:
    """Normal force of every cam joint on its follower at states q (nq, nt), times t and
    multipliers lam (neq, nt): ``fn`` (nc, nt; negative: the joint pulls), ``status``,
    ``msg``."""
    return _named("fn status msg", _core.core_cam_forces, p.nb, p.ctab, p.rpar, q, t, lam)


def reactions(p: Packed, q: np.ndarray, t: np.ndarray, lam: np.ndarray) -> SimpleNamespace:
    """Joint reactions at states q (nq, nt), times t (nt) and multipliers lam (neq, nt):
    ``reac`` and ``rloc`` (6, nc, nt), ``status``, ``msg``."""
    return _named("reac rloc status msg", _core.core_reactions, p.nb, p.ctab, p.rpar, q, t,
                  lam, numbers=12 * p.ctab.shape[1] * len(np.atleast_1d(t)))


def conditioning(p: Packed, q: np.ndarray, t: np.ndarray) -> SimpleNamespace:
    """sigma_min / sigma_max of the column-scaled J (the core's units) at states q (nq, nt)
    and times t (nt): ``cond`` (nt), ``status``, ``msg``."""
    return _named("cond status msg", _core.core_conditioning, p.nb, p.ctab, p.rpar, q, t,
                  numbers=np.size(t))


def ratio(p: Packed, q: np.ndarray, t: np.ndarray, kind: int, ref: int, x: tuple[int, int],
          y: tuple[int, int]) -> SimpleNamespace:
    """The velocity ratio (kind 1) or mechanical advantage (kind 2) of quantities x and y
    (kind 1 coordinate / 2 driver row, 1-based index) by the influence coefficients of row
    ``ref`` (1-based) at states q (nq, nt): ``ratio`` (nt), ``bad`` (1 or 2: the quantity
    that does not move), ``status``, ``msg``."""
    return _named("ratio bad status msg", _core.core_ratio, p.nb, p.ctab, p.rpar, q, t,
                  int(kind), int(ref), np.asarray(x, dtype=np.int32),
                  np.asarray(y, dtype=np.int32), numbers=np.size(q) + 4 * np.size(t))


def link_angle(q: np.ndarray, kind: int, bodies: np.ndarray, points: np.ndarray
               ) -> SimpleNamespace:
    """The transmission angle at states q (nq, nt) from the recipe of
    :func:`mbd2d.results.measures.angle_recipe` (kind 1 turning, 2 sliding; bodies (3),
    1-based, 0 ground; points (2, 3)): ``mu`` (nt), ``status``, ``msg``."""
    return _named("mu status msg", _core.core_link_angle, q, int(kind),
                  np.asarray(bodies, dtype=np.int32), np.asfortranarray(points, dtype=float),
                  numbers=q.shape[1])


def measures_dp(p: Packed, q: np.ndarray, sq: np.ndarray, t: np.ndarray, m: MeasureTables,
                ptab: np.ndarray) -> SimpleNamespace:
    """Every measure of the tables m (as a sweep's, the angles' points with their entries)
    and its design derivatives at states q (nq, nt) with their sensitivities sq (nq, np, nt)
    against the parameter table ptab (2, np): ``vals`` (nm, nt), ``dvals`` (nm, np, nt),
    ``bad`` (the failing measure, a ratio's quantity that does not move; 1-based),
    ``status``, ``msg``."""
    return _named("vals dvals bad status msg", _core.core_measures_dp, p.nb, p.ctab, p.rpar, q,
                  np.asfortranarray(sq, dtype=float), t, m.kind, m.mint, m.mpts, m.mref,
                  np.asfortranarray(ptab, dtype=np.int32),
                  numbers=len(m.kind) * (sq.shape[1] + 1) * q.shape[1])


def fun_values(p: np.ndarray, t: np.ndarray) -> SimpleNamespace:
    """f(t), f'(t), f''(t) of an encoded function of time (``TimeFunction.encode()``) at the
    times t: ``f``, ``f1``, ``f2``, ``status``, ``msg``."""
    return _named("f f1 f2 status msg", _core.core_fun_values, p, t, numbers=3 * np.size(t))
# ------------------------------------------------------------------ design sensitivities
# ptab: int32 (2, np), Fortran order: per design parameter its table (1 rpar, 2 bmass
# flattened (2, nb), 3 grav, 4 fpar) and 1-based index (see fortran/mbd_sensitivity.f90).

def eval_d(p: Packed, rpar: np.ndarray, q: np.ndarray, qd: np.ndarray, t: float,
           dq: np.ndarray, dqd: np.ndarray, ptab: np.ndarray) -> SimpleNamespace:
    """Changes of Phi, J, nu and gamma along a direction (dq, dqd) and at most one design
    parameter: ``tphi``, ``tjac``, ``tnu``, ``tgam``, ``status``, ``msg``, ``bad``."""
    return _named("tphi tjac tnu tgam status msg bad", _core.core_eval_d, p.nb, p.ctab, rpar,
                  p.neq, q, qd, float(t), dq, dqd, ptab)


def forces_d(p: Packed, d: DynamicTables, rpar: np.ndarray, bmass: np.ndarray,
             grav: np.ndarray, fpar: np.ndarray, q: np.ndarray, qd: np.ndarray, t: float,
             dq: np.ndarray, dqd: np.ndarray, ptab: np.ndarray) -> SimpleNamespace:
    """The applied generalized forces ``qf`` at (q, qd, t) and their changes along the
    columns of dq, dqd, each with the design parameter of the same column of ptab, by the
    core's two paths: ``dcol`` (inverse dynamics, statics) and ``drow`` (dopri5
    sensitivities); ``status``, ``msg``, ``bad``. The parameter arrays are given (a test
    changes them by differences); the tables' shapes come from p and d."""
    return _named("qf dcol drow status msg bad", _core.core_forces_d, ctab=p.ctab, rpar=rpar,
                  bmass=bmass, grav=grav, ftab=d.ftab, fpar=fpar, q=q, qd=qd, t=float(t),
                  dq=np.asfortranarray(dq), dqd=np.asfortranarray(dqd), ptab=ptab)


def stiffness(p: Packed, d: DynamicTables, q: np.ndarray, t: float,
              lam: np.ndarray) -> SimpleNamespace:
    """K = d(J^T lambda - Q)/dq and C = -dQ/dq_dot at (q, t) with the multipliers lam, exact,
    by the core's two paths: ``kpat``, ``cpat`` (read off the tangent's sparse pattern, the
    statics' Newton matrix) and ``kcol``, ``ccol`` (a product per column, the modes'); each
    (nq, nq); ``status``, ``msg``, ``bad``. For checks by finite differences."""
    return _named("kpat cpat kcol ccol status msg bad", _core.core_stiffness, ctab=p.ctab,
                  rpar=p.rpar, bmass=d.bmass, grav=d.grav, ftab=d.ftab, fpar=d.fpar, nb=p.nb,
                  q=q, t=float(t), lam=lam, numbers=4.0 * p.nq**2)


def kinematics_sens(p: Packed, t0: float, t1: float, steps: int, tol: float, maxit: int,
                    tmin: float, every: int, solver: int, nout: int,
                    ptab: np.ndarray) -> SimpleNamespace:
    """A kinematic run with sensitivities: as :func:`kinematics` plus ``sq``, ``sqd``,
    ``sqdd`` (nq, np, nout), views of the core's one block (nq, np, nout, 3), and ``ssum``
    (nout), each output's sum of them (finite exactly when they all are, barring overflow)."""
    out = _named("q qd qdd s3 ssum iinfo rinfo qsing dep red tpass status msg",
                 _core.core_kinematics_sens, p.nb, p.ctab, p.rpar, p.neq, p.q0, t0, t1, steps,
                 tol, maxit, tmin, every, solver, nout, ptab,
                 numbers=3 * p.nq * nout * (1 + ptab.shape[1]))
    out.sq, out.sqd, out.sqdd = out.s3[..., 0], out.s3[..., 1], out.s3[..., 2]
    return out


def inverse_sens(p: Packed, d: DynamicTables, t0: float, t1: float, steps: int, tol: float,
                 every: int, solver: int, nout: int, ptab: np.ndarray) -> SimpleNamespace:
    """Inverse dynamics with sensitivities: as :func:`inverse` plus ``sq``, ``sqd``, ``sqdd``
    (nq, np, nout) and ``slam`` (neq, np, nout)."""
    return _named("q qd qdd lam e sq sqd sqdd slam iinfo rinfo qsing dep red tpass status msg",
                  _core.core_inverse_sens, ctab=p.ctab, rpar=p.rpar, bmass=d.bmass,
                  grav=d.grav, ftab=d.ftab, fpar=d.fpar, neq=p.neq, q0=p.q0, t0=t0, t1=t1,
                  nsteps=steps, tol=tol, every=every, solver=solver, nout=nout, ptab=ptab,
                  numbers=(3 * p.nq + p.neq) * nout * (1 + ptab.shape[1]))


def dynamics_sens(p: Packed, d: DynamicTables, t0: float, t1: float, steps: int, rtol: float,
                  atol: float, every: int, max_steps: int, nrow: int,
                  ptab: np.ndarray, solver: int = 0, method: int = 2, h: float = 0.0,
                  rho_inf: float = -1.0) -> SimpleNamespace:
    """Forward dynamics with sensitivities (solver 0 auto, 1 dense, 2 banded; method 2
    dopri5, 1 generalized-alpha with its step h, 0 adaptive, and rho_inf, < 0 its default):
    ``q``, ``qd``, ``qdd``, ``lam``, ``e``, ``sq``, ``sqd``, ``sqdd`` (nq, np, nrow), ``slam``
    (neq, np, nrow), ``iinfo``, ``rinfo``, ``red``, ``status``, ``msg``."""
    return _named("q qd qdd lam e sq sqd sqdd slam iinfo rinfo red status msg",
                  _core.core_dynamics_sens, ctab=p.ctab, rpar=p.rpar, bmass=d.bmass,
                  grav=d.grav, ftab=d.ftab, fpar=d.fpar, neq=p.neq, q0=p.q0, v0=d.v0, t0=t0,
                  t1=t1, nsteps=steps, rtol=rtol, atol=atol, every=every, max_steps=max_steps,
                  solver=solver, nrow=nrow, ptab=ptab, method=method, h=h, rho_inf=rho_inf,
                  numbers=(3 * p.nq + p.neq) * nrow * (1 + ptab.shape[1]))


def statics_sens(p: Packed, d: DynamicTables, t: float, ptab: np.ndarray,
                 solver: int = 0) -> SimpleNamespace:
    """Static equilibrium with sensitivities (solver 0 auto, 1 dense, 2 banded): ``q``,
    ``lam``, ``sq`` (nq, np), ``slam`` (neq, np), ``stable``, ``resid``, ``iinfo``,
    ``status``, ``msg``."""
    return _named("q lam sq slam stable resid iinfo status msg", _core.core_statics_sens,
                  ctab=p.ctab, rpar=p.rpar, bmass=d.bmass, grav=d.grav, ftab=d.ftab,
                  fpar=d.fpar, neq=p.neq, q0=p.q0, t=t, ptab=ptab, solver=solver)


def reactions_dp(p: Packed, ptab: np.ndarray, q: np.ndarray, t: np.ndarray, lam: np.ndarray,
                 sq: np.ndarray, slam: np.ndarray) -> SimpleNamespace:
    """Changes of the reactions along the parameters: ``dreac``, ``drloc``
    (6, nc, np, nt), ``status``, ``msg``."""
    return _named("dreac drloc status msg", _core.core_reactions_dp, p.nb, p.ctab, p.rpar,
                  ptab, q, t, lam, sq, slam,
                  numbers=12 * p.ctab.shape[1] * ptab.shape[1] * len(np.atleast_1d(t)))


# ------------------------------------------------------------------ design sweeps

#: the measure tables passed without measures (one unused column)
_ONE_MEASURE = MeasureTables(["-"], np.ones(1, dtype=np.int32),
                             np.zeros((5, 1), dtype=np.int32, order="F"),
                             np.zeros((2, 3, 1), order="F"),
                             np.zeros((2, 3, 1), dtype=np.int32, order="F"))


def batch(b: BatchTables, vals: np.ndarray) -> dict[str, Any]:
    """One analysis for every case (column) of vals (nv, ncase), in one core call
    (``fortran/mbd_batch.f90``). Returns the core's arrays by name, the case last: ``q``,
    ``qd``, ``qdd`` (nq, nrow, ncase; (nq, 0, ncase) for positions only), ``lam`` (nlam, nrow,
    ncase), ``e`` (ne, nrow, ncase),
    ``iinfo``, ``rinfo`` (NINFO, ncase), ``qsing`` (nq, ncase), ``dep``, ``red`` (neq, ncase),
    the measures ``m`` (nm, nrow, ncase) with ``mbad`` (3, ncase: status, measure, quantity of
    a case whose measures failed), the sensitivities ``sq``, ``sqd``, ``sqdd`` (nq, npar, nrow,
    ncase) and ``slam`` (nsl, npar, nrow, ncase), the measures' design derivatives ``dm`` (nm,
    npar, nrow, ncase), ``status`` (ncase) and ``msg`` (ncase, text). A module-level function
    of plain arrays, so
    that worker processes and Dask workers can run it."""
    vals = np.asfortranarray(vals, dtype=np.float64)
    ncase = vals.shape[1]
    m = b.measures if len(b.measures.specs) else _ONE_MEASURE    # (f2py: no zero-length table)
    # (the frequency response's times: its angular frequencies)
    times = b.times if len(b.measures.specs) or b.analysis == 6 else np.zeros(b.nrow)
    ptab = b.ptab if b.npar else np.ones((2, 1), dtype=np.int32, order="F")
    out = _named("q qd qdd lam e iinfo rinfo qsing dep red m mbad sq sqd sqdd slam dm status "
                 "msg",
                 _core.core_batch,
                 analysis=b.analysis, nb=b.nb, ctab=b.ctab, rpar=b.rpar, bmass=b.bmass,
                 grav=b.grav, ftab=b.ftab, fpar=b.fpar, q0=b.q0, v0=b.v0, vtab=b.vtab,
                 vals=vals, opens=b.opens, iset=b.iset, rset=b.rset, neq=b.neq, nrow=b.nrow,
                 nd=b.nd, nlam=b.nlam, ne=b.ne, times=times, nm=len(b.measures.specs),
                 mkind=m.kind, mint=m.mint,
                 mpts=m.mpts, mref=m.mref, npar=b.npar, ptab=ptab, nsl=b.nsl,
                 numbers=ncase * ((b.nq + b.nlam + b.ne + len(b.measures.specs)
                                   + b.npar * (3 * b.nq + b.nsl + len(b.measures.specs)))
                                  * b.nrow
                                  + 2 * b.nq * b.nd + 2 * b.neq + b.nq + 23))
    return vars(out)
