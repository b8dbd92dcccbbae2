"""Finite-difference oracles for the derivatives the design sensitivities are built from.

For every constraint and driver type (the models of test_derivatives.py) and random states,
the core's dual-number evaluation (``core_eval_d``) gives

* along a design parameter p (each raw entry of the constraint table that is not a count):
  Phi_p, J_p, nu_p and gamma_p, compared with central differences of Phi, J, nu and gamma
  evaluated by the core at p + h and p - h;
* along a state direction (dq, dqd): J_q dq, and gamma_q dq + gamma_qd dqd, compared with
  central differences of J and gamma at (q +- h dq, qd +- h dqd); Phi_q dq must equal J dq.

The second set is what the sensitivity equations use for their Hessian terms (Hv, Ha,
K_lambda). Counts (a function's number of terms, a spline's number of points) are refused
with a typed status.
"""
from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from test_derivatives import CASES, random_states

from mbd2d.binding import core
from mbd2d.binding.pack import pack

H = 1e-6
RTOL = 1e-6


def _values(p, rpar, q, qd, t):
    out = core.evaluate(p.nb, p.ctab, rpar, p.neq, q, qd, t)
    assert out.status == 0, out.msg
    return [out.phi, out.jac, out.nu, out.gam]


def _dual(p, q, qd, t, dq, dqd, ptab):
    return core.eval_d(p, p.rpar, q, qd, t, dq, dqd,
                       np.asfortranarray(np.array(ptab, dtype=np.int32).reshape(2, -1)))


def _close(got, fd, what):
    scale = max(1.0, float(np.abs(fd).max()))
    assert_allclose(got, fd, rtol=0.0, atol=RTOL * scale, err_msg=what)


@pytest.fixture(scope="module", params=sorted(CASES))
def case(request):
    c = CASES[request.param]
    m = c.build()
    return request.param, pack(m), random_states(m, c, 11)


def test_parameter_derivatives(case):
    """Phi_p, J_p, nu_p, gamma_p of every non-count raw parameter against differences."""
    name, p, states = case
    checked = 0
    for q, qd, t in states[:2]:
        z = np.zeros_like(q)
        for i in range(len(p.rpar)):
            out = _dual(p, q, qd, t, z, z, [1, i + 1])
            if out.status != 0:
                assert out.status < 0 and "count" in out.msg, out.msg
                continue
            h = H * max(1.0, abs(p.rpar[i]))
            up, dn = p.rpar.copy(), p.rpar.copy()
            up[i] += h
            dn[i] -= h
            fd = [(a - b) / (2 * h) for a, b in zip(_values(p, up, q, qd, t),
                                                    _values(p, dn, q, qd, t))]
            for got, f, what in zip([out.tphi, out.tjac, out.tnu, out.tgam], fd,
                                    ["Phi_p", "J_p", "nu_p", "gamma_p"]):
                _close(got, f, f"{name}: {what} of raw parameter {i + 1}")
            checked += 1
    assert checked > 0


def test_state_directions(case):
    """J_q dq and the change of gamma along (dq, dqd) against differences; Phi_q dq = J dq."""
    name, p, states = case
    rng = np.random.default_rng(5)
    for q, qd, t in states:
        dq, dqd = rng.normal(size=q.size), rng.normal(size=q.size)
        out = _dual(p, q, qd, t, dq, dqd, [])
        assert out.status == 0, out.msg
        fd = [(a - b) / (2 * H) for a, b in zip(_values(p, p.rpar, q + H * dq, qd + H * dqd, t),
                                                _values(p, p.rpar, q - H * dq, qd - H * dqd, t))]
        jac = _values(p, p.rpar, q, qd, t)[1]
        _close(out.tphi, jac @ dq, f"{name}: Phi_q dq")
        _close(out.tjac, fd[1], f"{name}: J_q dq")
        _close(out.tgam, fd[3], f"{name}: gamma_q dq + gamma_qd dqd")
        assert_allclose(out.tnu, 0.0, atol=0.0, err_msg=f"{name}: nu does not depend on q")


def test_counts_are_refused():
    """A count (a driver function's number of coefficients) is no design parameter."""
    p = pack(CASES["driver-absolute-x"].build())
    q = np.zeros(p.nq)
    # the driver's function starts at its table offset: entry 1 is the coefficient count
    off = int(p.ctab[5, p.nc - 1])
    out = _dual(p, q, q, 0.5, q, q, [1, off])
    assert out.status < 0 and "count" in out.msg
