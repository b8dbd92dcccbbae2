"""The fast kinematic step keeps the closed-form accuracy at h = 1 ms and h = 0.1 ms.

The kinematic loop factors J once per step (a sparse LU with a pivot order planned once and
replayed) and reuses that factorization for the Newton correction of the predicted start, for
J q_dot = nu and for J q_ddot = gamma; a predicted start is taken with its correction only when
the correction is below a few units in the last place. This holds the loop, at both step sizes
of issue 11, to the closed forms of tests/test_closed_forms.py (hand-derived loop closure,
Cramer's rule for the rates, the cams' lift laws), with the error bounds of the README's
accuracy table as it stood before the faster step (360 steps, every step with a Newton
correction): each quantity's worst error over a full turn at most the table's value for that
mechanism, or 100 units in the last place of the quantity's largest magnitude where the table's
value is below that rounding floor.
"""
from __future__ import annotations

import numpy as np
import pytest

import test_closed_forms as cf
from conftest import load_example, wrap_angle

H_VALUES = (1e-3, 1e-4)
ULPS = 100.0
#: README accuracy table: worst position, velocity, acceleration error
README = {"four-bar": (9.0e-13, 2.6e-12, 4.8e-11), "slider-crank": (1.0e-13, 3.6e-14, 5.0e-14),
          "cam roller": (4.4e-16, 1.8e-15, 4.3e-14), "cam flat": (4.4e-16, 8.9e-16, 1.4e-14),
          "cam point": (8.7e-15, 3.6e-15, 2.3e-13)}


def bound(table: float, ref: np.ndarray) -> float:
    """The README value, or the rounding floor of the quantity when that is larger."""
    return max(table, ULPS * np.finfo(float).eps * float(np.max(np.abs(ref))))


def check(label: str, level: int, pairs: list[tuple[np.ndarray, np.ndarray, bool]]) -> None:
    """Worst error over (actual, reference, is_angle) against the bound of that level."""
    errs, limit = [], 0.0
    for actual, ref, angle in pairs:
        d = np.asarray(actual) - np.asarray(ref)
        errs.append(float(np.max(np.abs(wrap_angle(d) if angle else d))))
        limit = max(limit, bound(README[label][level], ref))
    err = max(errs)
    print(f"\n[kinematic step] {label:14s} level {level}: worst {err:.2e} (bound {limit:.1e})",
          end="")
    assert err <= limit, f"{label}, derivative {level}: {err:.3e} > {limit:.3e}"


def run(model, h: float):
    steps = int(round(1.0 / h))
    res = model.kinematics(t_end=1.0, steps=steps)
    assert res.complete and len(res.t) == steps + 1
    return res, steps


def check_fourbar(res, steps: int) -> None:
    """Coupler and rocker angles, rates and accelerations against the closed form; one
    factorization per step serves the correction, J q_dot = nu and J q_ddot = gamma, and
    corrections are rare (the predictor's start is taken with its correction)."""
    ref = cf.fourbar_closed_form(res.t)
    bodies = (("coupler", "th3", "w3", "al3"), ("rocker", "th4", "w4", "al4"))
    check("four-bar", 0, [(res.body(b).theta, ref[th], True) for b, th, _, _ in bodies])
    check("four-bar", 1, [(res.body(b).theta_dot, ref[w], False) for b, _, w, _ in bodies])
    check("four-bar", 2, [(res.body(b).theta_ddot, ref[a], False) for b, _, _, a in bodies])
    assert res.stats["factorizations"] <= 1.1 * steps
    assert res.stats["newton_corrections"] <= 0.1 * steps


@pytest.mark.parametrize("h", H_VALUES)
def test_fourbar_at_both_steps(h):
    res, steps = run(load_example("fourbar_grashof.toml"), h)
    check_fourbar(res, steps)


@pytest.mark.parametrize("h", H_VALUES)
def test_slider_crank_at_both_steps(h):
    res, _ = run(load_example("slider_crank.toml"), h)
    ref = cf.slider_crank_closed_form(res.t)
    s = res.body("slider")
    check("slider-crank", 0, [(s.x, ref["x"], False)])
    check("slider-crank", 1, [(s.x_dot, ref["x1"], False)])
    check("slider-crank", 2, [(s.x_ddot, ref["x2"], False)])


@pytest.mark.parametrize("kind", ["roller", "flat", "point"])
@pytest.mark.parametrize("h", H_VALUES)
def test_cam_at_both_steps(h, kind):
    res, _ = run(cf.cam_model(kind), h)
    y, y1, y2 = cf.cam_lift(res.t, kind)
    f = res.body("follower")
    check(f"cam {kind}", 0, [(f.y, y, False)])
    check(f"cam {kind}", 1, [(f.y_dot, y1, False)])
    check(f"cam {kind}", 2, [(f.y_ddot, y2, False)])


def test_fourbar_over_many_turns():
    """Fifty crank turns at h = 1 ms: the crank angle grows to 314 rad, so each angle carries an
    absolute rounding of ulp(theta) and the points a noise of L ulp(theta) that no Newton
    correction removes. The start is still taken with its correction (corrections stay rare),
    and the closed-form errors stay within the same bounds over every turn."""
    h, steps = 1e-3, 50_000
    res = load_example("fourbar_grashof.toml").kinematics(t_end=steps * h, steps=steps)
    assert res.complete
    check_fourbar(res, steps)
