"""The result rows handed over from the core: views of whole runs, the first non-finite row."""
from __future__ import annotations

import numpy as np

import mbd2d
from conftest import load_example
from mbd2d.analysis.outputs import first_nonfinite_row, rows


def test_first_nonfinite_row_sees_through_a_sum_that_overflows():
    big = np.full((4, 3), 1.0e308)              # every entry finite, the sum is not
    assert first_nonfinite_row(big) is None
    for bad in (np.nan, np.inf, -np.inf):
        a = big.copy()
        a[2, 1] = bad
        assert first_nonfinite_row(big, a) == 2
    b = np.zeros((5, 2))
    b[3, 0] = np.inf
    b[4, 1] = -np.inf                           # inf - inf: the sum is NaN
    assert first_nonfinite_row(b) == 3


def test_rows_is_a_view_of_a_whole_run_and_a_copy_of_a_part():
    core = np.asfortranarray(np.arange(12.0).reshape(3, 4))     # (coordinates, outputs)
    whole = rows(core, 4)
    assert whole.base is core and whole.flags.c_contiguous
    np.testing.assert_array_equal(whole, core.T)
    part = rows(core, 2)
    assert part.base is None
    np.testing.assert_array_equal(part, core.T[:2])


def test_a_kinematic_result_holds_its_rows_once():
    res = load_example("fourbar_grashof.toml").kinematics(t_end=1.0, steps=100)
    assert isinstance(res, mbd2d.KinematicsResult)
    assert res.q.shape == (101, 9) and res.q.flags.c_contiguous
