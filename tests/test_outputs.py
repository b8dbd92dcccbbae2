"""The result rows handed over from the core: views of whole runs, the first non-finite row."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import mbd2d
from conftest import load_example
from mbd2d.analysis.outputs import finite_part, first_nonfinite_row, rows


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


def sensitivity_run(name: str, npar: int, solver: int):
    """The core's kinematic run with sensitivities of the first npar joint parameters."""
    from mbd2d.analysis.sensitivities import requested, table
    from mbd2d.analysis.settings import check_solver
    from mbd2d.binding import core
    from mbd2d.binding.pack import pack
    m = load_example(name)
    names = [n for n in m.parameters() if n.startswith("joint.")][:npar]
    p = pack(m)
    ptab = table(p, requested(m, names))
    tol, maxit = check_solver(None, None)
    return core.kinematics_sens(p, 0.0, 0.5, 40, tol, maxit, 0.0, 1, solver, 41, ptab)


@pytest.mark.parametrize("name, npar, solver", [("fourbar_grashof.toml", 4, 0),
                                                ("fourbar_grashof.toml", 5, 0),
                                                ("slider_crank.toml", 3, 2),
                                                ("cam_follower.toml", 2, 0)])
def test_core_sums_of_the_sensitivities_cover_all_three(name: str, npar: int,
                                                         solver: int) -> None:
    """Each output's sum the core returns is that of dq/dp, dq_dot/dp and dq_ddot/dp (summed
    here from the returned block), on the sparse path (four parameters at a time and a
    partial group) and the band path."""
    out = sensitivity_run(name, npar, solver)
    assert out.status == 0
    expected = out.s3.sum(axis=(0, 1, 3))
    scale = np.abs(out.s3).sum(axis=(0, 1, 3))
    np.testing.assert_allclose(out.ssum, expected, rtol=0, atol=1e-13 * scale.max())


def test_finite_part_trusts_finite_sums_and_checks_the_rest() -> None:
    """Finite sums spare the covered fields; a non-finite one (a NaN, or finite entries whose
    sum overflowed) sends them through the entry-by-entry check."""
    res = load_example("fourbar_grashof.toml").kinematics(
        t_end=0.2, steps=20, sensitivities=["joint.A.points.0.0"])
    n = len(res.t)
    same, k = finite_part(res, np.zeros(n), ("dq_dp", "dqd_dp", "dqdd_dp"))
    assert k is None and same is res
    big = res.dq_dp.copy()
    big[:] = 1.0e308                      # finite entries, their sum overflows
    over = dataclasses.replace(res, dq_dp=big)
    sums = np.full(n, np.inf)
    assert finite_part(over, sums, ("dq_dp", "dqd_dp", "dqdd_dp"))[1] is None
    bad = res.dqdd_dp.copy()
    bad[7, 2, 0] = np.nan
    nan = dataclasses.replace(res, dqdd_dp=bad)
    sums = np.zeros(n)
    sums[7] = np.nan
    cut, k = finite_part(nan, sums, ("dq_dp", "dqd_dp", "dqdd_dp"))
    assert k == 7 and len(cut.t) == 7 and not cut.complete
