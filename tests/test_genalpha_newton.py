"""Generalized-alpha: the fast modified Newton in the core gives the solution of the discrete
equations, checked against an independent full-Newton implementation of the same scheme.

Oracle: index-3 generalized-alpha (Arnold & Bruls 2007) written here in NumPy,
  a_{n+1} = (af q_ddot_n + (1 - af) q_ddot_{n+1} - am a_n) / (1 - am)
  q_{n+1} = q_n + h q_dot_n + h^2 ((1/2 - beta) a_n + beta a_{n+1})
  q_dot_{n+1} = q_dot_n + h ((1 - gamma) a_n + gamma a_{n+1})
  M q_ddot_{n+1} + J(q_{n+1})^T lambda_{n+1} = Q,   Phi(q_{n+1}) = 0,
solved for (q_ddot_{n+1}, lambda_{n+1}) by full Newton with a fresh tangent every iteration
(the geometric term d(J^T lambda)/dq by central differences of model.jacobian), to a
residual at roundoff. The core keeps its iteration matrix across steps and stops on a
residual test; the two must agree to far below the method's own error (1e-4 at h = 1e-2).
The model has gravity only (Q = M g); Phi and J come from the public model.phi and
model.jacobian; the initial accelerations from [M J^T; J 0][q_ddot; lambda] = [Q; gamma].
"""
from __future__ import annotations

import sys

import numpy as np
import pytest

import mbd2d
from conftest import EXAMPLES, model_from_toml
from test_translational_sensitivity import INVERTED

sys.path.insert(0, str(EXAMPLES))
import free_fourbar as free_fourbar_example  # noqa: E402
import nfourbar  # noqa: E402

G = 9.81
RHO_INF = 0.9


def free_fourbar() -> mbd2d.Model:
    """The free four-bar of examples/free_fourbar.py."""
    return free_fourbar_example.build()


def mass_and_load(model: mbd2d.Model) -> tuple[np.ndarray, np.ndarray]:
    """Diagonal of M and the gravity load Q = M g (x, y, theta per body)."""
    mdiag = np.array([[b.mass, b.mass, b.inertia] for b in model.bodies]).ravel()
    load = np.array([[0.0, -G * b.mass, 0.0] for b in model.bodies]).ravel()
    return mdiag, load


def oracle_genalpha(model: mbd2d.Model, q0: np.ndarray, v0: np.ndarray, h: float,
                    steps: int, rho_inf: float = RHO_INF) -> tuple[np.ndarray, ...]:
    """Full-Newton index-3 generalized-alpha; returns q, q_dot, q_ddot at every step."""
    am = (2 * rho_inf - 1) / (rho_inf + 1)
    af = rho_inf / (rho_inf + 1)
    gam = 0.5 + af - am
    bet = 0.25 * (gam + 0.5) ** 2
    mdiag, load = mass_and_load(model)
    n = len(q0)
    # consistent initial accelerations: [M J^T; J 0][q_ddot; lambda] = [Q; gamma]
    jac = model.jacobian(q0)
    ne = jac.shape[0]
    aug = np.block([[np.diag(mdiag), jac.T], [jac, np.zeros((ne, ne))]])
    sol = np.linalg.solve(aug, np.concatenate([load, model.gamma(q0, v0)]))
    q, v, qdd, lam = q0.copy(), v0.copy(), sol[:n], sol[n:]
    acc = qdd.copy()
    cq = h * h * bet * (1 - af) / (1 - am)       # d q_{n+1} / d q_ddot_{n+1}
    out_q, out_v, out_a = [q.copy()], [v.copy()], [qdd.copy()]
    for _ in range(steps):
        a_old = (af * qdd - am * acc) / (1 - am)    # a_{n+1} without the q_ddot_{n+1} term
        base_q = q + h * v + h * h * (0.5 - bet) * acc + h * h * bet * a_old
        base_v = v + h * (1 - gam) * acc + h * gam * a_old
        x_a, x_l = qdd.copy(), lam.copy()
        small = 0
        for _it in range(50):
            qn = base_q + cq * x_a
            jn = model.jacobian(qn)
            r = np.concatenate([mdiag * x_a + jn.T @ x_l - load, model.phi(qn) / cq])
            # tangent: d/dq (J^T lambda) by central differences
            kgeo = np.zeros((n, n))
            for k in range(n):
                dq = np.zeros(n)
                dq[k] = 1e-6
                kgeo[:, k] = (model.jacobian(qn + dq).T @ x_l
                              - model.jacobian(qn - dq).T @ x_l) / 2e-6
            tangent = np.block([[np.diag(mdiag) + cq * kgeo, jn.T],
                                [jn, np.zeros((ne, ne))]])
            step = np.linalg.solve(tangent, -r)
            x_a += step[:n]
            x_l += step[n:]
            # quadratic convergence: one more iteration once the step is at 1e-8 (the
            # roundoff of Phi / cq alone moves q_ddot by about 1e-10 at h = 2e-3)
            small += np.max(np.abs(step[:n])) <= 1e-8 * max(1.0, np.max(np.abs(x_a)))
            if small == 2:
                break
        else:  # pragma: no cover - the oracle itself failed
            raise AssertionError("oracle Newton did not converge")
        acc_new = (af * qdd + (1 - af) * x_a - am * acc) / (1 - am)
        q, v = base_q + cq * x_a, base_v + h * gam * (1 - af) / (1 - am) * x_a
        qdd, lam, acc = x_a, x_l, acc_new
        out_q.append(q.copy()); out_v.append(v.copy()); out_a.append(qdd.copy())
    return np.array(out_q), np.array(out_v), np.array(out_a)


@pytest.mark.parametrize("h, steps", [(1e-2, 100), (2e-3, 150)])
def test_modified_newton_equals_full_newton(h: float, steps: int) -> None:
    """Every step of the core (outputs at the step times) equals the full-Newton oracle."""
    model = free_fourbar()
    res = model.dynamics(t_end=h * steps, steps=steps, method="generalized-alpha", h=h,
                         rho_inf=RHO_INF)
    assert res.stats["steps"] == steps
    oq, ov, oa = oracle_genalpha(model, np.asarray(res.q[0]), np.asarray(res.qd[0]), h, steps)
    # measured: q 3e-12 / 3e-14, q_dot 1e-11 / 7e-12, q_ddot 3e-9 / 1.5e-7 (h = 1e-2 / 2e-3;
    # q_ddot = (q - q*) / (h^2 beta (1 - af) / (1 - am)) magnifies the roundoff of q by 1e6
    # at h = 2e-3, in the oracle as in the core); the method's own error is 1e-2 rad at
    # h = 1e-2 over 10 s
    np.testing.assert_allclose(res.q, oq, rtol=0, atol=1e-11)
    np.testing.assert_allclose(res.qd, ov, rtol=0, atol=1e-9)
    np.testing.assert_allclose(res.qdd, oa, rtol=0, atol=1e-6)
    # and it got there without a tangent per step (K, C are kept across steps)
    assert res.stats["iteration_matrices"] < steps / 10
    assert res.stats["factorizations"] <= res.stats["newton_iterations"]


def test_adaptive_generalized_alpha_still_controls_its_error() -> None:
    """The error-controlled variant on the same model: the angles against a tight dopri5
    run improve more than 10x as rtol tightens 100x (measured 4.4e-3 -> 2.3e-4 rad)."""
    model = free_fourbar()
    ref = model.dynamics(t_end=2.0, steps=20, method="dopri5", rtol=1e-12, atol=1e-14)
    errs = []
    for rtol in (1e-4, 1e-6):
        res = model.dynamics(t_end=2.0, steps=20, method="generalized-alpha", rtol=rtol,
                             atol=rtol * 1e-2)
        errs.append(np.max(np.abs(np.asarray(res.q)[:, 2::3] - np.asarray(ref.q)[:, 2::3])))
    assert errs[1] < errs[0] / 10


def geometric_stiffness(model: mbd2d.Model, q: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """d(J(q)^T lambda)/dq by central differences of model.jacobian."""
    n = len(q)
    k = np.zeros((n, n))
    for c in range(n):
        dq = np.zeros(n)
        dq[c] = 1e-6
        k[:, c] = (model.jacobian(q + dq).T @ lam - model.jacobian(q - dq).T @ lam) / 2e-6
    return k


def test_pin_joints_stiffen_only_their_angles() -> None:
    """The pattern of generalized-alpha's tangent K: a revolute joint's J^T lambda depends
    on q only through each body's angle (lambda . B(theta) s on theta), so its K has entries
    on the theta diagonal alone (so has a slider on a guide fixed in ground), and the
    iteration matrix of a pin-jointed chain is as narrow as the index-1 saddle-point matrix
    (band (6, 6) for the N-four-bar). Checked from central differences of model.jacobian
    with arbitrary multipliers; a translational joint between two moving bodies couples
    more (off-diagonal entries), so it keeps the full pattern."""
    rng = np.random.default_rng(3)
    model = free_fourbar()
    res = model.dynamics(0.01, 1, method="dopri5")
    q = res.q[-1]
    lam = rng.normal(size=model.jacobian(q).shape[0])
    k = geometric_stiffness(model, q, lam)
    theta = np.zeros(k.shape, dtype=bool)
    for b in range(len(model.bodies)):
        theta[3 * b + 2, 3 * b + 2] = True
    assert np.abs(k[~theta]).max() < 1e-8 * np.abs(k).max()
    assert np.abs(k[theta]).min() > 1e-3 * np.abs(k).max()
    guided = mbd2d.load(EXAMPLES / "slider_crank.toml")      # pins and a guide in ground
    qg = guided.kinematics(0.1, 1).q[-1]
    kg = geometric_stiffness(guided, qg, rng.normal(size=guided.jacobian(qg).shape[0]))
    diag = np.zeros(kg.shape, dtype=bool)
    for b in range(len(guided.bodies)):
        diag[3 * b + 2, 3 * b + 2] = True
    assert np.abs(kg[~diag]).max() < 1e-8 * np.abs(kg).max()
    slider = model_from_toml(INVERTED)                # a slider between two moving bodies
    qs = slider.kinematics(0.1, 1).q[-1]
    ks = geometric_stiffness(slider, qs, rng.normal(size=slider.jacobian(qs).shape[0]))
    off = ~np.eye(len(qs), dtype=bool)
    assert np.abs(ks[off]).max() > 1e-3 * np.abs(ks).max()
    chain = nfourbar.build(100, driven=False, omega0=1.0)
    ga = chain.dynamics(0.002, 1, method="generalized-alpha", h=1e-3, solver="banded")
    dp = chain.dynamics(0.002, 1, method="dopri5", solver="banded")
    assert ga.stats["band"] == dp.stats["band"] == (6, 6)

