"""The assembly from rough estimates: the branch nearest the estimates, to the accuracy of a
Newton correction, whether the Newton start takes it (short steps that reduce ||Phi||) or
Levenberg-Marquardt does (estimates far off, or a singular J at the estimates).

Reference: the crank-rocker of examples/fourbar_grashof.toml at t = 0 (crank along x) by
loop closure, both branches, computed here without mbd2d.
"""
from __future__ import annotations

import numpy as np
import pytest

import mbd2d
from conftest import EXAMPLES

CRANK, COUPLER, ROCKER, GROUND = 1.0, 3.5, 2.5, 3.0


def closed_form(sign: float) -> np.ndarray:
    """(x, y, theta) of crank, coupler and rocker at crank angle 0, open (+1) or crossed
    (-1) branch."""
    a = np.array([CRANK, 0.0])
    o4 = np.array([GROUND, 0.0])
    d = o4 - a
    ell = np.hypot(*d)
    along = (ell**2 + COUPLER**2 - ROCKER**2) / (2 * ell)
    h = np.sqrt(COUPLER**2 - along**2)
    u = d / ell
    b = a + along * u + sign * h * np.array([-u[1], u[0]])
    cpl = (a + b) / 2, np.arctan2(*(b - a)[::-1])
    rck = (b + o4) / 2, np.arctan2(*(o4 - b)[::-1])
    return np.array([CRANK / 2, 0.0, 0.0, *cpl[0], cpl[1], *rck[0], rck[1]])


def with_estimates(q: np.ndarray) -> mbd2d.Model:
    text = (EXAMPLES / "fourbar_grashof.toml").read_text()
    for k, old in enumerate(("[0.5, 0.0, 0.0]", "[2.25, 1.2, 0.78]", "[3.25, 1.2, -1.77]")):
        text = text.replace(f"q0 = {old}", "q0 = [" + ", ".join(
            repr(float(v)) for v in q[3 * k:3 * k + 3]) + "]")
    return mbd2d.loads(text)


def assembled(q_est: np.ndarray) -> np.ndarray:
    return np.asarray(with_estimates(q_est).kinematics(t_end=0.01, steps=1).q[0])


def angle_diff(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = a - b
    d[2::3] = (d[2::3] + np.pi) % (2 * np.pi) - np.pi
    return d


@pytest.mark.parametrize("sign", [1.0, -1.0])
@pytest.mark.parametrize("scatter", [0.0, 1e-6, 0.02, 0.1, 0.3])
def test_the_branch_of_the_estimates_to_newton_accuracy(sign: float, scatter: float) -> None:
    exact = closed_form(sign)
    rng = np.random.default_rng(7 + int(1e3 * scatter))
    for _ in range(6):
        est = exact + scatter * rng.uniform(-1.0, 1.0, exact.size)
        q = assembled(est)
        assert np.max(np.abs(angle_diff(q, exact))) < 1e-12


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_estimates_far_off_still_assemble_on_a_branch(sign: float) -> None:
    """Angles off by up to 1 rad and positions by 1 m: Levenberg-Marquardt's territory; the
    result closes the loop (one of the two branches, to 1e-12)."""
    exact = closed_form(sign)
    rng = np.random.default_rng(11)
    both = (closed_form(1.0), closed_form(-1.0))
    for _ in range(8):
        q = assembled(exact + rng.uniform(-1.0, 1.0, exact.size))
        assert min(np.max(np.abs(angle_diff(q, b))) for b in both) < 1e-12


def test_a_singular_start_is_left_to_levenberg_marquardt() -> None:
    """Estimates at which J is singular (every body on the x axis, coupler and rocker
    folded): no Newton step exists there, and the assembly still finds a branch."""
    est = np.array([0.5, 0.0, 0.0, 2.75, 0.0, 0.0, 3.0 + 1.25, 0.0, np.pi])
    q = assembled(est)
    both = (closed_form(1.0), closed_form(-1.0))
    assert min(np.max(np.abs(angle_diff(q, b))) for b in both) < 1e-12


def test_no_configuration_is_still_reported() -> None:
    """A coupler too short to close the loop: the assembly fails with the residual named."""
    m = mbd2d.load(EXAMPLES / "fourbar_grashof.toml")
    m2 = m.with_params({"joint.A.points.1.0": -0.2, "joint.B.points.0.0": 0.2})
    with pytest.raises(mbd2d.AssemblyError):
        m2.kinematics(t_end=0.01, steps=1)


# ------------------------------------------------------------------- large models

def chain(n: int, scatter: float = 0.0, seed: int = 0) -> mbd2d.Model:
    """The driven N-four-bar (examples/nfourbar.py), its q0 estimates scattered by up to
    `scatter` (positions and angles)."""
    import sys
    sys.path.insert(0, str(EXAMPLES))
    from nfourbar import build
    m = build(n)
    rng = np.random.default_rng(seed)
    for b in m.bodies:
        b.q0 = [float(v) for v in np.asarray(b.q0) + rng.uniform(-scatter, scatter, 3)]
    return m


@pytest.mark.parametrize("n", [100, 400])
def test_large_chain_assembles_from_scattered_estimates(n: int) -> None:
    """603 and 2403 coordinates (band mode), estimates off by up to 0.3: the assembled
    configuration is the chain's closed form at t = 0 (cranks upright at x = k, couplers
    level at height 1)."""
    res = chain(n, scatter=0.3).kinematics(0.0 + 1e-3, 1)
    q = res.q[0]
    k = np.arange(n + 1)
    assert np.abs(q[0:3 * (n + 1):3] - k).max() < 1e-10            # cranks' x
    assert np.abs(q[1:3 * (n + 1):3] - 0.5).max() < 1e-10
    assert np.abs(q[2:3 * (n + 1):3] - np.pi / 2).max() < 1e-10
    cpl = q[3 * (n + 1):]
    assert np.abs(cpl[0::3] - (np.arange(n) + 0.5)).max() < 1e-10
    assert np.abs(cpl[1::3] - 1.0).max() < 1e-10 and np.abs(cpl[2::3]).max() < 1e-10


@pytest.mark.parametrize("n", [100, 400])
def test_large_chain_that_cannot_close_is_reported(n: int) -> None:
    """A crank pin moved so no loop closes: AssemblyError naming a joint and the residual
    (Levenberg-Marquardt in band storage, stopped where it crawls; the dense one took 105 s
    at 603 coordinates); a middle crank of the wrong length (a redundant, contradicting
    link): InconsistentConstraintsError naming the loop's constraints."""
    m = chain(n)
    m.joints[5].points = ((0.3, 0.0), (-0.5, 0.0))
    with pytest.raises(mbd2d.AssemblyError, match=r"smallest residual .* largest in joint"):
        m.kinematics(0.1, 2)
    m = chain(n)
    m.add_body("mid", q0=[0.5, 0.5, np.pi / 2])
    m.add_revolute(["ground", "mid"], [[0.5, 0.0], [-0.5, 0.0]], name="M")
    m.add_revolute(["mid", "coupler0"], [[0.52, 0.0], [0.0, 0.0]], name="NN")
    with pytest.raises(mbd2d.InconsistentConstraintsError,
                       match=r"O0, O1, L0, R0, M, NN cannot all hold"):
        m.kinematics(0.1, 2)
