"""The banded LU path of the kinematic loop and output decimation (every=k).

Oracles: the closed form of the driven N-four-bar (every crank turns with the driver,
theta = pi/2 - t, every coupler translates), the toggle time of the seed four-bar, and the
dense path (the same analysis with another linear solver)."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.errors import ModelError, SingularConfigurationError

EX = Path(__file__).resolve().parents[1] / "examples"
sys.path.insert(0, str(EX))
from nfourbar import build as nfourbar  # noqa: E402
TOGGLE_T = math.acos((9 + 36 - 7.6**2) / 36) - math.pi / 3    # closed form (seed four-bar)


def closed_form(n: int, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, q_dot, q_ddot of the N-four-bar: theta = pi/2 - t for every crank."""
    th = math.pi / 2 - t
    c, s = np.cos(th), np.sin(th)
    q, qd, qdd = (np.zeros((len(t), 3 * (2 * n + 1))) for _ in range(3))
    for k in range(n + 1):           # crank k: centre (k + c/2, s/2)
        i = 3 * k
        q[:, i:i + 3] = np.column_stack([k + 0.5 * c, 0.5 * s, th])
        qd[:, i:i + 3] = np.column_stack([0.5 * s, -0.5 * c, -np.ones_like(t)])
        qdd[:, i:i + 3] = np.column_stack([-0.5 * c, -0.5 * s, np.zeros_like(t)])
    for k in range(n):               # coupler k: centre (k + 1/2 + c, s), no rotation
        i = 3 * (n + 1 + k)
        q[:, i:i + 3] = np.column_stack([k + 0.5 + c, s, np.zeros_like(t)])
        qd[:, i:i + 3] = np.column_stack([s, -c, np.zeros_like(t)])
        qdd[:, i:i + 3] = np.column_stack([-c, -s, np.zeros_like(t)])
    return q, qd, qdd


@pytest.mark.parametrize("n,solver", [(3, "banded"), (40, "banded"), (40, "auto"),
                                      (40, "dense")])
def test_nfourbar_matches_the_closed_form(n, solver):
    res = nfourbar(n).kinematics(t_end=1.2, steps=60, solver=solver)
    q, qd, qdd = closed_form(n, res.t)
    assert np.abs(res.q - q).max() < 1e-11
    assert np.abs(res.qd - qd).max() < 1e-10
    assert np.abs(res.qdd - qdd).max() < 1e-9


def test_auto_picks_the_band_for_large_chains_and_dense_for_small_models():
    big = nfourbar(40).kinematics(t_end=0.1, steps=2)
    assert big.stats["solver"] == "banded"
    kl, ku = big.stats["band"]
    assert kl + ku + 1 <= 10, "reverse Cuthill-McKee keeps the chain's band narrow"
    small = mbd2d.load(EX / "fourbar_grashof.toml").kinematics(t_end=0.1, steps=2)
    assert small.stats["solver"] == "dense"


def test_banded_solver_finds_the_toggle_like_the_dense_one():
    model = mbd2d.load(EX / "fourbar_seed.toml")
    times = {}
    for solver in ("dense", "banded"):
        with pytest.raises(SingularConfigurationError) as ei:
            model.kinematics(t_end=2.0, steps=200, solver=solver)
        times[solver] = ei.value.t
        assert abs(ei.value.t - TOGGLE_T) < 1e-8
        assert ei.value.driver is not None
    assert abs(times["dense"] - times["banded"]) < 1e-9


def test_banded_solver_refuses_redundant_constraints():
    with pytest.warns(mbd2d.RedundantConstraintWarning):
        mbd2d.load(EX / "fourbar_redundant.toml").kinematics(t_end=0.1, steps=2)
    with pytest.raises(ModelError, match="banded solver needs as many equations"):
        mbd2d.load(EX / "fourbar_redundant.toml").kinematics(t_end=0.1, steps=2,
                                                             solver="banded")


def test_unknown_solver_is_a_model_error():
    with pytest.raises(ModelError, match="unknown solver 'sparse'"):
        nfourbar(2).kinematics(t_end=0.1, steps=2, solver="sparse")


@pytest.mark.parametrize("steps,every", [(100, 10), (100, 7), (5, 100), (9, 1)])
def test_every_keeps_the_rows_of_the_full_run(steps, every):
    model = mbd2d.load(EX / "fourbar_grashof.toml")
    full = model.kinematics(t_end=1.0, steps=steps, maxit=25)
    part = model.kinematics(t_end=1.0, steps=steps, every=every)
    idx = sorted(set(range(0, steps + 1, every)) | {steps})
    assert len(part.t) == len(idx)
    assert np.array_equal(part.t, full.t[idx])
    assert part.t[-1] == 1.0
    for a, b in ((part.q, full.q), (part.qd, full.qd), (part.qdd, full.qdd)):
        assert np.abs(a - b[idx]).max() < 1e-13


def test_every_keeps_partial_results_up_to_a_toggle():
    model = mbd2d.load(EX / "fourbar_seed.toml")
    with pytest.raises(SingularConfigurationError) as ei:
        model.kinematics(t_end=2.0, steps=200, every=10)
    part = ei.value.results
    assert len(part.t) == 9                       # t = 0, 0.1, ..., 0.8 < 0.886
    assert np.allclose(part.t, np.arange(9) * 0.1, atol=1e-15)


@pytest.mark.parametrize("every", [0, -1, 1.5, "2"])
def test_bad_every_is_a_model_error(every):
    with pytest.raises(ModelError, match="every"):
        nfourbar(2).kinematics(t_end=0.1, steps=2, every=every)
