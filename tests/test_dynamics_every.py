"""Output decimation of forward dynamics, Model.dynamics(..., every=k).

A consistency test: the decimated run is the same computation as the full one (same time
grid, same steps), so its rows must equal rows 0, k, 2k, ... and the last of the full run.
"""
from __future__ import annotations

import sys

import numpy as np
import pytest

import mbd2d
from conftest import EXAMPLES

sys.path.insert(0, str(EXAMPLES))
import free_fourbar as free_fourbar_example  # noqa: E402

def free_fourbar() -> mbd2d.Model:
    """The free four-bar of examples/free_fourbar.py."""
    return free_fourbar_example.build()


METHODS = {"generalized-alpha": {"h": 2e-3}, "generalized-alpha adaptive": {},
           "dopri5": {}, "baumgarte-rk4": {"h": 2e-3}, "partitioned": {}}
FIELDS = ("q", "qd", "qdd", "lam", "kinetic", "potential", "drift_position", "drift_velocity")


def expected_rows(steps: int, every: int) -> list[int]:
    """0, every, 2 every, ... and steps (independently of the package's helper)."""
    rows = [k for k in range(steps + 1) if k % every == 0]
    return rows if rows[-1] == steps else rows + [steps]


def run(model: mbd2d.Model, label: str, steps: int, **kw: object) -> mbd2d.DynamicsResult:
    method = label.split()[0]
    return model.dynamics(t_end=1.0, steps=steps, method=method, **METHODS[label], **kw)


@pytest.mark.parametrize("label", list(METHODS))
@pytest.mark.parametrize("steps, every", [(100, 10), (100, 7), (100, 1), (100, 100),
                                          (100, 250), (1, 3)])
def test_decimated_rows_equal_the_full_run(label: str, steps: int, every: int) -> None:
    model = free_fourbar()
    full = run(model, label, steps)
    dec = run(model, label, steps, every=every)
    rows = expected_rows(steps, every)
    assert len(dec.t) == len(rows) and dec.q.shape == (len(rows), full.q.shape[1])
    np.testing.assert_array_equal(dec.t, full.t[rows])
    assert dec.t[0] == 0.0 and dec.t[-1] == 1.0
    for name in FIELDS:
        a, b = np.asarray(getattr(dec, name)), np.asarray(getattr(full, name))[rows]
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-14 * max(1.0, np.abs(b).max()),
                                   err_msg=name)
    assert dec.stats["steps"] == full.stats["steps"]
    assert dec.complete


def test_default_is_every_output() -> None:
    model = free_fourbar()
    res = model.dynamics(t_end=1.0, steps=50, method="generalized-alpha", h=1e-2)
    assert len(res.t) == 51
    np.testing.assert_allclose(res.t, np.linspace(0.0, 1.0, 51), rtol=0, atol=1e-15)


def test_decimated_partial_results_on_failure() -> None:
    """rho_inf = 1 fails (an undamped sawtooth, see test_failure_modes); the kept rows of a
    decimated run are the decimated rows of the full run up to the failure."""
    model = free_fourbar()
    kw = dict(method="generalized-alpha", h=1e-2, rho_inf=1.0)
    with pytest.raises(mbd2d.IntegrationError) as full_info:
        model.dynamics(10.0, 1000, **kw)
    with pytest.raises(mbd2d.IntegrationError) as dec_info:
        model.dynamics(10.0, 1000, every=40, **kw)
    full, dec = full_info.value.results, dec_info.value.results
    assert dec_info.value.t == full_info.value.t
    rows = [k for k in range(len(full.t)) if k % 40 == 0]
    assert len(dec.t) == len(rows) > 1
    np.testing.assert_array_equal(dec.t, full.t[rows])
    np.testing.assert_allclose(dec.q, full.q[rows], rtol=0, atol=1e-14 * np.abs(full.q).max())


@pytest.mark.parametrize("every", [0, -3, 2.5, True, "4", None, np.float64(2.0)])
def test_bad_every_is_a_model_error(every: object) -> None:
    with pytest.raises(mbd2d.ModelError, match="every"):
        free_fourbar().dynamics(t_end=1.0, steps=10, method="generalized-alpha", h=0.1,
                                every=every)


def test_numpy_integer_every_is_accepted() -> None:
    res = free_fourbar().dynamics(t_end=1.0, steps=10, method="generalized-alpha", h=0.1,
                                  every=np.int64(5))
    assert len(res.t) == 3
