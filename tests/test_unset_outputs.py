"""The kinematic runs' output arrays come from f2py unset (``intent(out, cache)``: no pass
that zeroes them before the core writes them), so the core must write every entry it
returns. Memory left full of NaN by freed arrays of the same sizes must not show through:
on a clean run, on a run through singular passages (outputs interpolated there, their
sensitivities computed at the end), with positions only, and on a run that fails part way.
The reference is the same run on memory that was not poisoned.
"""
from __future__ import annotations

import math
import sys
import warnings

import numpy as np
import pytest

import mbd2d
from conftest import EXAMPLES, load_example

sys.path.insert(0, str(EXAMPLES))
import nfourbar  # noqa: E402

FIELDS = ("q", "qd", "qdd", "dq_dp", "dqd_dp", "dqdd_dp")


def poison(sizes: list[int], copies: int = 6) -> None:
    """Allocate and free NaN-filled arrays of these float counts: the allocator hands the
    same blocks to the next arrays of those sizes."""
    junk = [np.full(n, np.nan) for n in sizes for _ in range(copies)]
    del junk


def sizes(nq: int, rows: int, npar: int) -> list[int]:
    """The float counts of a run's arrays: q, q_dot, q_ddot each, the sensitivities' block
    and their sums."""
    return [nq * rows, 3 * nq * rows * max(npar, 1), rows]


def test_poisoned_memory_reaches_new_arrays() -> None:
    """The premise: a freed block comes back to the next array of its size, unset."""
    hits = 0
    for n in (99, 396, 4000):
        poison([n])
        hits += int(np.isnan(np.empty(n)).any())
    assert hits >= 2


def run_twice(run, nq: int, rows: int, npar: int):
    clean = run()
    poison(sizes(nq, rows, npar))
    return clean, run()


def same(a, b) -> None:
    for f in FIELDS:
        x, y = getattr(a, f, None), getattr(b, f, None)
        if x is None:
            assert y is None
            continue
        assert np.all(np.isfinite(y)), f
        np.testing.assert_array_equal(x, y, err_msg=f)


@pytest.mark.parametrize("npar", [0, 3, 5])
def test_clean_run_writes_every_entry(npar: int) -> None:
    m = load_example("fourbar_grashof.toml")
    names = [n for n in m.parameters() if n.startswith("joint.")][:npar] or None
    clean, again = run_twice(lambda: m.kinematics(0.5, 40, sensitivities=names), 9, 41, npar)
    same(clean, again)


def test_passages_interpolated_outputs_and_their_sensitivities() -> None:
    """The parallelogram through its collinear positions: outputs on a passage (every 25th
    of these) are interpolated and their sensitivities computed after the loop."""
    m = nfourbar.build(1)
    names = [n for n in m.parameters() if n.startswith("joint.")][:2]

    def run():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", mbd2d.SingularPassageWarning)
            return m.kinematics(t_end=4 * math.pi, steps=200, sensitivities=names)

    clean, again = run_twice(run, 3 * len(m.bodies), 201, 2)
    assert clean.stats["singular_passage_count"] == 4
    same(clean, again)


def test_positions_only() -> None:
    m = load_example("slider_crank.toml")
    clean, again = run_twice(lambda: m.kinematics(0.5, 40, positions_only=True), 9, 41, 0)
    same(clean, again)


def test_a_failed_run_keeps_written_rows_only() -> None:
    """A non-Grashof four-bar driven into its dead centre: the rows kept are the core's."""
    m = load_example("fourbar_grashof.toml").with_params({"joint.O4.points.1.0": 5.5})

    def run():
        with pytest.raises(mbd2d.SingularConfigurationError) as err:
            m.kinematics(1.0, 100, sensitivities=["joint.B.points.0.0"])
        return err.value.results

    clean, again = run_twice(run, 9, 101, 1)
    assert 2 < len(clean.t) < 101
    same(clean, again)
