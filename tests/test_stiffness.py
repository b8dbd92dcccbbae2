"""Finite-difference oracle for the exact tangent stiffness and damping.

The statics' Newton steps, the modes and the frequency response take
K = d(J^T lambda - Q)/dq and C = -dQ/dq_dot exactly, from the design sensitivities' second
derivatives, by two paths: a product per colour group of the tangent's sparse pattern, read off
column by column (``kpat``, ``cpat``: the statics' Newton matrix), and a product per column
(``kcol``, ``ccol``: the modes and the frequency response). Both are compared here with central
differences of J(q)^T lambda - Q(q, q_dot) built from the core's plain evaluations (J from
``core_eval``, Q from ``core_forces_d``), for every constraint and driver type (the models of
test_derivatives.py), with random multipliers, and for every kind of force (the loaded
slider-crank of test_force_derivatives.py) at rest, as the linearizations take them.
"""
from __future__ import annotations

import numpy as np
import pytest
from test_derivatives import CASES, random_states
from test_force_derivatives import loaded_model

from mbd2d.binding import core
from mbd2d.binding.pack import pack, pack_dynamics
from mbd2d.binding.tables import DynamicTables

H = 1e-6          # central differences: truncation and rounding about 1e-10 relative
FD_RTOL = 1e-7    # of the largest entry
PATHS_RTOL = 1e-14  # the two exact paths: the same products summed in another order


def unloaded(model, p) -> DynamicTables:
    """Unit masses, gravity and no forces for a kinematic model of test_derivatives."""
    return DynamicTables(bmass=np.ones((2, p.nb), order="F"), grav=np.array([0.0, -9.81]),
                         ftab=np.zeros((6, 0), dtype=np.int32, order="F"),
                         fpar=np.zeros(0), v0=np.zeros(p.nq))


def residual(p, d, q: np.ndarray, qd: np.ndarray, t: float, lam: np.ndarray) -> np.ndarray:
    """J(q)^T lambda - Q(q, q_dot, t) from the core's evaluations (no derivatives)."""
    ev = core.evaluate(p.nb, p.ctab, p.rpar, p.neq, q, qd, t)
    assert ev.status == 0, ev.msg
    r = ev.jac.T @ lam
    if d.ftab.shape[1]:
        z = np.zeros((p.nq, 1), order="F")
        ptab = np.asfortranarray(np.array([[3], [1]], dtype=np.int32))   # (gravity x: any)
        out = core.forces_d(p, d, p.rpar, d.bmass, d.grav, d.fpar, q, qd, t, z, z, ptab)
        assert out.status == 0, out.msg
        r = r - out.qf
    return r


def differences(p, d, q, t, lam) -> tuple[np.ndarray, np.ndarray]:
    """K and C by central differences of the residual at rest, column by column."""
    n = len(q)
    z = np.zeros(n)
    k = np.empty((n, n))
    c = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = H
        k[:, j] = (residual(p, d, q + e, z, t, lam) - residual(p, d, q - e, z, t, lam)) / (2 * H)
        c[:, j] = (residual(p, d, q, e, t, lam) - residual(p, d, q, -e, t, lam)) / (2 * H)
    return k, c


def check(p, d, q, t, lam, what: str) -> None:
    out = core.stiffness(p, d, q, t, lam)
    assert out.status == 0, out.msg
    k, c = differences(p, d, q, t, lam)
    scale = max(1.0, np.abs(k).max())
    for name, got in (("kpat", out.kpat), ("kcol", out.kcol)):
        np.testing.assert_allclose(got, k, rtol=0, atol=FD_RTOL * scale, err_msg=f"{what} {name}")
    np.testing.assert_allclose(out.kpat, out.kcol, rtol=0, atol=PATHS_RTOL * scale, err_msg=what)
    cscale = max(1.0, np.abs(c).max())
    for name, got in (("cpat", out.cpat), ("ccol", out.ccol)):
        np.testing.assert_allclose(got, c, rtol=0, atol=FD_RTOL * cscale, err_msg=f"{what} {name}")
    np.testing.assert_allclose(out.cpat, out.ccol, rtol=0, atol=PATHS_RTOL * cscale,
                               err_msg=what)


@pytest.mark.parametrize("name", sorted(CASES))
def test_constraint_stiffness_against_differences(name: str) -> None:
    """K_lambda = sum lambda_i Phi_i,qq of every constraint and driver type, at random
    configurations and multipliers."""
    case = CASES[name]
    model = case.build()
    p = pack(model)
    d = unloaded(model, p)
    rng = np.random.default_rng(7)
    for q, _, t in random_states(model, case, 23)[:2]:
        lam = rng.normal(size=p.neq)
        check(p, d, q, t, lam, name)


def test_force_stiffness_and_damping_against_differences() -> None:
    """-Q_q and -Q_q_dot of springs (to ground and between bodies, damped, with an actuator),
    a torque, a point force and a rotational spring-damper, with the joints' K_lambda."""
    model = loaded_model()
    p = pack(model)
    d = pack_dynamics(model, p)
    rng = np.random.default_rng(11)
    q0 = np.concatenate([b.q0 for b in model.bodies])
    for _ in range(3):
        q = q0 + rng.uniform(-0.3, 0.3, p.nq)
        lam = rng.normal(size=p.neq)
        check(p, d, q, 0.7, lam, "loaded slider-crank")
    assert np.abs(core.stiffness(p, d, q0, 0.7, np.zeros(p.neq)).cpat).max() > 0   # damped


def test_contacts_have_no_exact_stiffness() -> None:
    """A model with a contact is refused with a typed status (its K is taken by
    differences where the engine needs it)."""
    from test_contact import ball
    model = ball("hertz", 1.0)
    p = pack(model)
    d = pack_dynamics(model, p)
    q0 = np.concatenate([b.q0 for b in model.bodies])
    out = core.stiffness(p, d, q0, 0.0, np.zeros(p.neq))
    assert out.status < 0 and "contact" in out.msg
