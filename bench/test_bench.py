"""Tests of the benchmark bookkeeping (no timing assertions): interpolation at equal
accuracy, slope fit, run planning, targets and the report on synthetic results.

    python -m pytest bench/test_bench.py
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parent
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))

import memory  # noqa: E402
import peers_exudyn  # noqa: E402
import report  # noqa: E402
import scaling  # noqa: E402


def wp_row(method: str, sweep: str, error: float, cpu_s: float) -> dict:
    return {"method": method, "sweep": sweep, "error": error, "cpu_s": cpu_s, "ok": True}


def test_time_at_error_interpolates_log_log() -> None:
    pts = [(-6.0, -1.0), (-2.0, -3.0)]            # error 1e-6 at 0.1 s, 1e-2 at 1 ms
    assert peers_exudyn.time_at_error(pts, -4.0) == pytest.approx(1e-2)
    assert peers_exudyn.time_at_error(pts, -6.0) == pytest.approx(0.1)
    assert peers_exudyn.time_at_error(pts, -1.0) is None      # no extrapolation
    assert peers_exudyn.time_at_error(pts, -7.0) is None


def test_equal_accuracy_takes_the_fastest_line() -> None:
    wp = [wp_row("dopri5", "rtol", 1e-2, 1e-3), wp_row("dopri5", "rtol", 1e-6, 1e-2),
          wp_row("baumgarte-rk4", "h", 1e-2, 1e-2), wp_row("baumgarte-rk4", "h", 1e-6, 1e-1),
          {"method": "partitioned", "sweep": "rtol", "error": None, "cpu_s": 1.0, "ok": False}]
    exu = [{"h": 1e-3, "error": 1e-4, "cpu_s": 0.5}, {"h": 1e-2, "error": 1.0, "cpu_s": 0.1},
           {"h": 1e-1, "error": None, "cpu_s": None}]
    out = peers_exudyn.equal_accuracy(exu, wp)
    assert out[0]["mbd2d_method"] == "dopri5 (rtol)"
    assert out[0]["mbd2d_cpu_s"] == pytest.approx(10 ** -2.5)
    assert out[0]["ratio"] == pytest.approx(0.5 / 10 ** -2.5)
    assert out[1]["ratio"] is None and out[2]["ratio"] is None


def test_fit_slope_of_a_power_law() -> None:
    rows = [{"n": n, "us_per_step": 3.0 * n ** 1.1} for n in (1, 10, 100, 1000)]
    assert scaling.fit_slope(rows) == pytest.approx(1.1)
    assert scaling.fit_slope(rows[:1]) is None
    assert scaling.fit_slope([{"n": 10, "us_per_step": None}, {"n": 20}]) is None


@pytest.mark.parametrize("per_step", [1e-9, 1e-6, 1e-3, 10.0])
def test_plan_stays_in_bounds(per_step: float) -> None:
    steps = scaling.plan(per_step, 1.0)
    assert 10 <= steps <= scaling.MAX_STEPS
    assert steps * scaling.H < math.pi / 2          # the cranks stay off the change point


def synthetic_results(stepper: bool = True, exudyn: bool = True) -> dict:
    """A results dict of the shape bench/run.py assembles."""
    loop = {"us_per_step": 0.8}
    kin_row = {"fortran_loop": loop, "fortran_loop_h1e-4": {"us_per_step": 0.5},
               "numpy": {"us_per_step": 120.0}, "ratio_numpy_over_loop": 150.0,
               "python_stepper": {"available": stepper, "us_per_step": 3.0} if stepper
               else {"available": False, "message": "no KinematicStepper"}}
    peers = {"exudyn_available": exudyn, "exudyn": "1.0" if exudyn else None,
             "exudyn_unavailable_reason": None if exudyn else "import failed",
             "dynamics": {"rho_inf": 0.9, "side_by_side": [
                 {"h": 1e-3, "exudyn_error": 1e-4, "exudyn_cpu_s": 0.4, "mbd2d_error": 1e-4,
                  "mbd2d_cpu_s": 0.2, "time_ratio_exudyn_over_mbd2d": 2.0}],
                 "equal_accuracy": [{"h": 1e-3, "exudyn_error": 1e-4, "exudyn_cpu_s": 0.4,
                                     "mbd2d_method": "dopri5 (rtol)", "mbd2d_cpu_s": 0.01,
                                     "ratio": 40.0}] if exudyn else []},
             "kinematics": {"steps": 100, "t_end": 1.0, "ratio": 20.0 if exudyn else None,
                            "ratio_positions": 40.0 if exudyn else None,
                            "exudyn_best": "loop", "mbd2d": {"us_per_step": 2.0},
                            "mbd2d_positions": {"us_per_step": 1.0}}}
    return {"environment": {"cpu_model": "cpu", "cores": 2, "os": "os (kernel)",
                            "git": {"commit": "abc"}, "load_average_start": (0.1, 0, 0)},
            "kinematics": {"rows": {report.FOURBAR: kin_row, report.SLIDER: dict(kin_row)},
                           "callgrind": {"available": True, "valgrind": "valgrind-3.19.0",
                                         "rows": [{"h": 1e-3, "instructions_per_step": 9000.0,
                                                   "newton_corrections_per_step": 0.02,
                                                   "lu_per_step": 1.02,
                                                   "parts": {"assembly": 5000.0, "LU": 700.0,
                                                             "solves": 1300.0,
                                                             "loop": 2000.0}}]}},
            "peers": peers,
            "scaling": {"banded_slope": 1.02, "dense_slope": 2.9, "banded_available": True,
                        "rows": {"dense": [], "banded": []},
                        "target": {"path": "banded", "ms_per_step": 1.5, "met": True}},
            "memory": {"rows": [{"analysis": "kinematics", "every": 1000, "steps": 10,
                                 "run_mib": 1.0, "available": True}]},
            "work_precision": {"failed": True, "error": "RuntimeError: boom"},
            "sweep": {"per_variant": {"ratio_loop_over_batched": 12.0, "steps": 10,
                                      "us_per_variant": {"loop": 840.0, "batched": 70.0,
                                                         "core": 65.0}},
                      "throughput": {"cases": 10, "steps": 200, "rows": [
                          {"runner": "Dask LocalCluster, 2 worker(s)", "seconds": 1.0,
                           "variants_per_s": 10.0, "identical_to_serial": True}]},
                      "standalone": [{"cases": 10, "steps": 10, "every": 1, "solve_s": 0.1,
                                      "python_s": 0.25, "ratio": 2.5, "same_csv": True},
                                     {"unavailable": "mbd2d-solve not found"}]},
            "sensitivities": {"steps": 100, "repeats": 1, "rows": [
                {"case": "kinematics four-bar, 4 parameters", "base_us_per_step": 1.0,
                 "sens_us_per_step": 2.5, "ratio": 2.5, "instruction_ratio": 2.1}]},
            "dynamics_scaling": {"model": "free N-four-bar", "settings": {}, "rows": {
                "generalized-alpha/banded": [
                    {"n": 100, "coordinates": 603, "ms_per_step": 0.3, "setup_s": 0.01,
                     "steps": 50},
                    {"n": 1000, "coordinates": 6003, "ms_per_step": 3.0, "setup_s": 0.06,
                     "steps": 50}]},
                "slopes": {"generalized-alpha": 1.0},
                "n1000": {"generalized-alpha": {"ms_per_step": 3.0, "setup_s": 0.06}}},
            "peers_chain": {"model": "free N-four-bar", "t_end": 0.5, "rho_inf": 0.9,
                            "exudyn_version": "1.13.6", "meets_target": True, "rows": [
                {"n": n, "h": 1e-3, "ratio": 7.0,
                 "mbd2d": {"ms_per_step": 0.2 * n / 100, "error": 4.6e-7,
                           "newton_iterations": 990},
                 "exudyn": {"ms_per_step": 1.4 * n / 100, "error": 4.6e-7,
                            "newton_iterations": 2770}} for n in (100, 1000)]},
            "meta": {"total_runtime_s": 300.0, "quick": False, "command": "python bench/run.py"}}


def test_targets_on_synthetic_results() -> None:
    tg = {t["target"]: t for t in report.targets(synthetic_results())}
    met = {name: t["met"] for name, t in tg.items()}
    kin = "kinematics, four-bar, Fortran loop: <= 1 us/step (h = 1 ms and 0.1 ms)"
    assert met[kin] is True
    assert "9.0k instructions at h = 1 ms" in tg[kin]["figure"]
    assert met["kinematics: Fortran loop >= 100x faster than plain NumPy"] is True
    assert met["free four-bar: >= 5x faster than Exudyn at equal accuracy"] is True
    assert met["kinematic stepping: >= 50x faster than Exudyn"] is False
    assert tg["kinematic stepping: >= 50x faster than Exudyn"]["figure"].startswith(
        "40x positions only (like for like), 20x with q_dot and q_ddot")
    assert met["kinematics, N-four-bar N = 1000: <= 2 ms per step"] is True
    assert met["sweep, 10-step kinematics: per-variant cost >= 10x below a with_params "
               "loop"] is True
    assert met["sensitivities of 4 parameters: <= 2x the analysis alone"] is False
    assert "2.50x (2.10x instructions)" in tg["sensitivities of 4 parameters: <= 2x the "
                                              "analysis alone"]["figure"]
    assert met["free N-four-bar, generalized-alpha h = 1 ms, N = 1000: <= 5 ms/step"] is True
    assert met["dynamics (generalized-alpha): log-log slope <= 1.15, N = 100 to 10,000"] is True
    assert met["free N-four-bar, generalized-alpha: >= 3x faster than Exudyn at N = 100 and "
               "1000"] is True
    assert all(v is not None for v in met.values())


def test_targets_without_exudyn_are_not_measured() -> None:
    tg = report.peer_targets(synthetic_results(exudyn=False))
    assert [t["met"] for t in tg] == [None, None]
    assert all("Exudyn unavailable" in t["figure"] for t in tg)


def test_missing_sections_are_not_measured(tmp_path: Path) -> None:
    res = {"meta": {"total_runtime_s": 1.0, "command": "python bench/run.py"}}
    tg = report.targets(res)
    assert [t["met"] for t in tg][:-1] == [None] * (len(tg) - 1)
    md = report.results_markdown(res, {}, tmp_path / "RESULTS.md", tmp_path / "results")
    assert md.count("Failed: not run") == 9


def test_report_renders_failures_and_missing_stepper(tmp_path: Path) -> None:
    res = synthetic_results(stepper=False)
    md = report.results_markdown(res, {}, tmp_path / "RESULTS.md", tmp_path / "results")
    assert "## Targets" in md and "Failed: RuntimeError: boom" in md
    assert "not available (no KinematicStepper)" in md
    assert "Section **work_precision failed**" in md
    assert "## Design sweeps" in md and "Loop / batched: **12.0x**" in md
    assert "| 10 x 10 (every 1) | 0.100 | 0.250 | 2.5x | yes |" in md
    assert "## Sensitivity cost" in md
    head = report.headline_markdown(res, {}, tmp_path)
    assert head.startswith("## Performance") and "| target |" in head


def test_memory_chart_with_an_unavailable_case(tmp_path: Path) -> None:
    data = {"rows": [{"analysis": "kinematics", "every": 1, "steps": 10, "run_mib": 3.0},
                     {"analysis": "dynamics", "every": 1000, "steps": 10, "available": False}]}
    assert memory.chart(data, tmp_path / "m.png").stat().st_size > 0


def test_kinematic_target_needs_both_step_sizes() -> None:
    """<= 1 us/step is met only when h = 0.1 ms meets it too."""
    res = synthetic_results()
    res["kinematics"]["rows"][report.FOURBAR]["fortran_loop_h1e-4"]["us_per_step"] = 1.2
    tg = {t["target"]: t["met"] for t in report.targets(res)}
    assert tg["kinematics, four-bar, Fortran loop: <= 1 us/step (h = 1 ms and 0.1 ms)"] is False


def test_callgrind_table_in_report() -> None:
    """The instructions per step and their parts appear in the kinematics section."""
    res = synthetic_results()
    md = report.kinematics_section(res)
    assert "Instructions per step (callgrind)" in md
    assert "| 1 ms | 9,000 | 5,000 (56%) | 700 (8%) | 1,300 (14%) | 2,000 (22%) |" in md
    res["kinematics"]["callgrind"] = {"available": False, "reason": "valgrind is not installed"}
    assert "not measured (valgrind is not installed)" in report.kinematics_section(res)


def test_callgrind_parts_count_each_function_once() -> None:
    """Own instructions per function: every function in one part, the rest is the loop."""
    import callgrind
    d1 = {"__mbd_assemble_MOD_assemble_blocks": 100, "__sincos_fma": 10,
          "__mbd_splu_MOD_splu_factor": 50, "__mbd_splu_MOD_splu_solve2": 20,
          "__mbd_kinematics_MOD_kin_loop.constprop.0": 30}
    d2 = {k: 3 * v for k, v in d1.items()}
    parts = callgrind._parts(d1, d2, 2, total=(3 - 1) * 210 / 2)
    assert parts == {"assembly": 110.0, "LU": 50.0, "solves": 20.0, "loop": 30.0}


def test_pictures_table_in_report() -> None:
    """The pictures' rows and ratios appear in their section; a failed or missing section
    says so."""
    pic = {"model": "driven N-four-bar", "picture": "6 snapshots", "gif": "21 frames",
           "rows": [{"n": 100, "batched": True, "artists": 175, "picture_s": 0.5,
                     "gif_s": 1.0, "picture_ratio": 6.0, "gif_ratio": 3.0},
                    {"n": 100, "batched": False, "artists": 4531, "picture_s": 3.0,
                     "gif_s": 3.0}]}
    md = report.pictures_section({"pictures": pic})
    assert "| 100 | one per look | 175 | 0.50 | 6.0 | 1.00 | 3.0 |" in md
    assert "| 100 | one per part | 4531 | 3.00 | – | 3.00 | – |" in md
    assert report.pictures_section({}) == "Not run.\n"
    assert "Failed" in report.pictures_section({"pictures": {"failed": True, "error": "x"}})


def test_modes_table_in_report() -> None:
    """The modes' rows (errors, times, the ratio) appear in their section; without Exudyn its
    columns are empty; a failed or missing section says so."""
    rows = [{"model": "double pendulum (omega^2)", "n_free": 2, "mbd2d_error": 1.9e-11,
             "exudyn_error": 1.0, "mbd2d_s": 3e-4, "mbd2d_q0_s": 1.7e-4, "exudyn_s": 2e-4,
             "time_ratio": 0.85},
            {"model": "spring chain n = 40 (omega)", "n_free": 40, "mbd2d_error": 1.1e-12,
             "mbd2d_s": 1.2e-2, "mbd2d_q0_s": 3.9e-3}]
    md = report.modes_section({"modes": {"exudyn_available": True, "exudyn": "1.13.6",
                                         "rows": rows}})
    assert "| double pendulum (omega^2) | 2 | 1.9e-11 | 1.0e+00 | 0.3 | 0.17 | 0.2 | 0.85 |" \
        in md
    assert "| spring chain n = 40 (omega) | 40 | 1.1e-12 | – | 12 | 3.9 | – | – |" in md
    assert "Exudyn 1.13.6" in md
    assert report.modes_section({}) == "Not run.\n"
    assert "Failed" in report.modes_section({"modes": {"failed": True, "error": "x"}})


def test_frf_table_in_report() -> None:
    """The frequency response's rows appear in their section; a failed or missing section
    says so."""
    chains = [{"n": 12, "frequencies": 50, "solver": "dense", "error": 7.1e-15,
               "mbd2d_s": 7.2e-3, "numpy_s": 1.0e-3, "ratio": 7.2,
               "mbd2d_per_frequency_s": 6.6e-5, "numpy_per_frequency_s": 1.7e-5}]
    sweeps = [{"cases": 200, "frequencies": 10, "batched_per_case_s": 6.2e-4,
               "loop_per_case_s": 1.3e-3, "ratio": 2.1, "identical": True}]
    md = report.frf_section({"frf": {"chains": chains, "sweeps": sweeps}})
    assert "| 12 | 50 | dense | 7.1e-15 | – | 7.2 | 1 | 7.2 | 0.066 | 0.017 |" in md
    assert "| 200 | 10 | 0.62 | 1.3 | 2.1 | yes |" in md
    assert report.frf_section({}) == "Not run.\n"
    assert "Failed" in report.frf_section({"frf": {"failed": True, "error": "x"}})


def test_frf_study_runs_quick() -> None:
    """The bench's frequency response study (quick): the chain against numpy's solve of its
    hand-written system, and the sweep identical to the loop."""
    import frf
    res = frf.study(quick=True)
    assert res["chains"][0]["error"] < max(1e-12, 10 * res["chains"][0]["cond_eps"])
    assert all(r["identical"] for r in res["sweeps"])


def test_modes_study_runs_quick() -> None:
    """The bench's modes study (quick) measures mbd2d against the closed forms (and Exudyn
    where it is installed)."""
    import peers_modes
    res = peers_modes.study(quick=True)
    assert res["rows"][0]["mbd2d_error"] < 1e-9 and res["rows"][1]["mbd2d_error"] < 1e-9
    if res["exudyn_available"]:
        assert res["rows"][1]["exudyn_error"] < 1e-9
