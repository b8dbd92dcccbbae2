"""Passing through singular configurations where the motion continues: the IFToMM
N-four-bar (benchmark A02) driven through its collinear positions, theta = pi/2 - t.

Every crank must stay parallel to the first (the parallelogram branch) and the couplers
translate: coupler k has x = k + 1/2 + cos(theta), y = sin(theta), angle 0.

Tolerances follow from conditioning, not from fitting: near a singular configuration
errors grow like cond(J) tol, cond^2 tol and cond^3 tol in q, q_dot, q_ddot. The engine
computes outputs there by interpolation between anchors where cond(J) <= 1e3, so
accelerations within about 0.1 s of a passage are good to ~1e-7, and everything else to the
usual 1e-9.
"""
from __future__ import annotations

import math
import sys
import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from conftest import EXAMPLES

sys.path.insert(0, str(EXAMPLES))
import nfourbar  # noqa: E402


def run(n: int, steps: int, t_end: float = 4 * math.pi) -> mbd2d.KinematicsResult:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mbd2d.SingularPassageWarning)
        return nfourbar.build(n).kinematics(t_end=t_end, steps=steps)


# 1000 steps put outputs exactly on the collinear times pi/2 + k pi; 997 and 37 do not
@pytest.mark.parametrize("steps", [1000, 997, 37])
@pytest.mark.parametrize("n", [1, 2, 5])
def test_stays_on_the_parallelogram_branch(n: int, steps: int) -> None:
    res = run(n, steps)
    th = np.pi / 2 - res.t
    near = np.abs(((res.t - np.pi / 2) + np.pi / 2) % np.pi - np.pi / 2) < 0.1
    for k in range(n + 1):
        c = res.body(f"crank{k}")
        assert_allclose(c.theta, th, rtol=0, atol=1e-10)
        assert_allclose(c.theta_dot, -1.0, rtol=0, atol=1e-9)
        assert_allclose(c.theta_ddot[~near], 0.0, atol=1e-9)
        assert_allclose(c.theta_ddot[near], 0.0, atol=1e-7)
    for k in range(n):
        c = res.body(f"coupler{k}")
        assert_allclose(c.x, k + 0.5 + np.cos(th), rtol=0, atol=1e-10)
        assert_allclose(c.y, np.sin(th), rtol=0, atol=1e-10)
        assert_allclose(c.theta, 0.0, atol=1e-10)
        assert_allclose(c.x_dot, np.sin(th), rtol=0, atol=1e-9)
        assert_allclose(c.x_ddot[~near], -np.cos(th[~near]), rtol=0, atol=1e-9)
        assert_allclose(c.x_ddot[near], -np.cos(th[near]), rtol=0, atol=1e-7)


@pytest.mark.parametrize("n", [1, 2, 5])
def test_passages_are_reported(n: int) -> None:
    with pytest.warns(mbd2d.SingularPassageWarning, match="passed through 4 singular"):
        res = nfourbar.build(n).kinematics(t_end=4 * math.pi, steps=1000)
    t_pass = np.array(res.stats["singular_passages"])
    assert_allclose(t_pass, np.pi / 2 + np.pi * np.arange(4), atol=1e-6)


def test_a_driven_crank_at_a_dead_centre_still_stops() -> None:
    """Unlike the parallelogram, the seed four-bar has no motion beyond its toggle."""
    with pytest.raises(mbd2d.SingularConfigurationError, match="dead centre"):
        mbd2d.load(EXAMPLES / "fourbar_seed.toml").kinematics(t_end=1.0, steps=1000)


def test_even_n_passage_is_found_without_a_rejected_step() -> None:
    """At the passage N singular values of J vanish together; for even N det J touches zero
    without changing sign (N = 2: det J < 0 at theta = +-0.01), so no step is rejected. The
    passage shows as a local minimum of the pivot ratio between accepted steps, is located by
    a golden-section search on it, and recorded; the motion stays on the branch."""
    with pytest.warns(mbd2d.SingularPassageWarning, match="passed through 1 singular"):
        res = nfourbar.build(2).kinematics(t_end=3.0, steps=2000)
    assert res.stats["rejected_steps"] == 0
    assert_allclose(res.stats["singular_passages"], [np.pi / 2], atol=1e-6)
    th = math.pi / 2 - res.t
    for k in range(3):
        assert_allclose(res.body(f"crank{k}").theta, th, rtol=0, atol=1e-10)
    for k in range(2):
        c = res.body(f"coupler{k}")
        assert_allclose(c.x, k + 0.5 + np.cos(th), rtol=0, atol=1e-10)
        assert_allclose(c.x_ddot, -np.cos(th), rtol=0, atol=1e-7)


def test_a_regular_minimum_of_the_conditioning_is_not_a_passage() -> None:
    """The Grashof four-bar's J is best and worst conditioned somewhere in each turn, but never
    singular: no passage is recorded."""
    res = mbd2d.load(EXAMPLES / "fourbar_grashof.toml").kinematics(t_end=2.0, steps=2000,
                                                                     maxit=25)
    assert res.stats["singular_passages"] == []


@pytest.mark.parametrize("gap", [1e-3, 1e-7])
@pytest.mark.parametrize("steps", [3000, 31])
def test_turning_back_just_short_of_a_dead_centre_is_not_a_passage(gap: float, steps: int) -> None:
    """The seed four-bar's crank swung up to `gap` rad short of its toggle and back (theta =
    pi/3 + A sin t): J comes close to singular but never is; no passage is recorded."""
    th_toggle = math.acos((9 + 36 - 7.6**2) / 36)          # crank angle at the toggle
    amp = th_toggle - math.pi / 3 - gap
    text = (EXAMPLES / "fourbar_seed.toml").read_text().replace(
        "f = { poly = [1.0471975511965976, 1.0] }",
        f"f = {{ poly = [1.0471975511965976], harmonic = [{{ amplitude = {amp!r}, "
        "omega = 1.0, phase = 0.0 }] }")
    res = mbd2d.loads(text).kinematics(t_end=3.0, steps=steps, maxit=25)
    assert res.complete
    assert res.stats["singular_passages"] == []
