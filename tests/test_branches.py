"""Assembly keeps the branch nearest q0, and a run never switches branch silently."""
from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

import mbd2d
from conftest import EXAMPLES

W = 2.0 * np.pi
CROSSED = {"coupler": "[2.25, -1.2, -0.78]", "rocker": "[3.25, -1.2, 1.77]"}


def four_bar(branch: str) -> mbd2d.Model:
    text = (EXAMPLES / "fourbar_grashof.toml").read_text()
    if branch == "crossed":
        text = text.replace("q0 = [2.25, 1.2, 0.78]", f"q0 = {CROSSED['coupler']}")
        text = text.replace("q0 = [3.25, 1.2, -1.77]", f"q0 = {CROSSED['rocker']}")
    return mbd2d.loads(text)


def rocker_tip(t: np.ndarray, sign: float) -> np.ndarray:
    """Coupler-rocker joint B of the crank-rocker (crank 1, coupler 3.5, rocker 2.5,
    ground 3) on the open (+1) or crossed (-1) branch, by loop closure."""
    a = np.column_stack([np.cos(W * t), np.sin(W * t)])
    d = np.array([3.0, 0.0]) - a
    L = np.hypot(*d.T)
    along = (L**2 + 3.5**2 - 2.5**2) / (2 * L)
    h = np.sqrt(3.5**2 - along**2)
    u = d / L[:, None]
    return a + along[:, None] * u + sign * h[:, None] * np.column_stack([-u[:, 1], u[:, 0]])


@pytest.mark.parametrize("branch, sign", [("open", 1.0), ("crossed", -1.0)])
@pytest.mark.parametrize("steps", [360, 12])
def test_each_branch_kept_for_a_full_turn(branch: str, sign: float, steps: int) -> None:
    res = four_bar(branch).kinematics(t_end=1.0, steps=steps)
    r = res.body("rocker")
    tip = np.column_stack([r.x - 1.25 * np.cos(r.theta), r.y - 1.25 * np.sin(r.theta)])
    assert_allclose(tip, rocker_tip(res.t, sign), atol=1e-10)


def test_the_two_branches_differ() -> None:
    a = four_bar("open").kinematics(t_end=1.0, steps=4).q
    b = four_bar("crossed").kinematics(t_end=1.0, steps=4).q
    assert np.all(np.abs(a[:, 4] - b[:, 4]) > 1.0)   # coupler y on opposite sides


def test_coarse_steps_through_a_dead_centre_still_stop() -> None:
    """The seed four-bar with one output step across its toggle: located, not jumped."""
    with pytest.raises(mbd2d.SingularConfigurationError) as err:
        mbd2d.load(EXAMPLES / "fourbar_seed.toml").kinematics(t_end=2.0, steps=2)
    t_star = np.arccos((9 + 36 - 7.6**2) / 36) - np.pi / 3
    assert abs(err.value.t - t_star) < 1e-8
