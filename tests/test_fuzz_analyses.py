"""Property-based fuzzing of every analysis, beyond the kinematics test_hostile.py covers:
statics, forward and inverse dynamics and the one-step stepper, on malformed and degenerate
models (through the TOML loader and the builder), with hostile settings and step times, and
models of absurd size.

The contract: each case ends in a typed mbd2d error (a ModelError naming the entry, an
AnalysisError whose partial results are finite, an InsufficientMemoryError with the size and
the advice) or in finite results; never a crash (segfault, Fortran runtime abort), a hang, a
raw Python exception, a CoreError (a bug by its own definition) or a non-finite number.

It reuses test_hostile.py: its strategies (mutations, hostile values, profiles), its checks
and its worker process, in which every case runs so that a crash or a hang fails the test with
the case instead of killing pytest. Example counts are small in the suite (the file runs in
well under a minute); MBD2D_FUZZ_EXAMPLES=N raises every property test to N examples.
"""
from __future__ import annotations

import atexit
import math
import re
import warnings
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest
from hypothesis import given, note
from hypothesis import strategies as st

import mbd2d
import test_hostile as H
from mbd2d.model import from_dict
from test_hostile import (BASE, BASE_NAMES, EXTREME, HOSTILE_ARG, NONFINITE, _deepcopy,
                          _finite, hostile_settings, mutate_structure, ping, to_toml)

WORKER = H.Worker(Path(__file__))
atexit.register(WORKER.stop)
COUNTS: dict[str, int] = {}


def _worker_loop(inp: Any, out: Any) -> None:
    """Worker side: run this file's check functions."""
    H._worker_loop(inp, out, globals())


@pytest.fixture(scope="module", autouse=True)
def _fuzz_summary():
    """Print the number of cases per test, then stop the worker."""
    yield
    WORKER.stop()
    print()
    for test, n in COUNTS.items():
        print(f"fuzz cases run: {n:5d}  {test}")


def _count(test: str) -> None:
    COUNTS[test] = COUNTS.get(test, 0) + 1


__all__ = ["ping"]        # the worker answers ping from this module

# ------------------------------------------------------------------------------------------
# models with masses: every base model of test_hostile, each body given a mass and inertia
# ------------------------------------------------------------------------------------------


def with_masses(data: dict[str, Any]) -> dict[str, Any]:
    d = _deepcopy(data)
    for b in d.get("body", []):
        if isinstance(b, dict):
            b.setdefault("mass", 1.5)
            b.setdefault("inertia", 0.2)
    return d


MASSIVE = {name: with_masses(BASE[name]) for name in BASE_NAMES}
MASSIVE["pendulum_spring"] = H.tomllib.loads(
    (H.EXAMPLES / "pendulum_spring.toml").read_text())
MASSIVE_NAMES = sorted(MASSIVE)

# ------------------------------------------------------------------------------------------
# checks (run in the worker)
# ------------------------------------------------------------------------------------------
TYPED = "ModelError", "AnalysisError", "InsufficientMemoryError"


def _typed(what: str, call: Callable[[], Any], names: set[str], bounds: dict[str, int],
           check: Callable[[Any], None]) -> str:
    """Run one public call: a typed error (checked as test_hostile checks it) or a value that
    passes ``check``; returns 'what:outcome'."""
    try:
        value = call()
    except mbd2d.ModelError as exc:
        H.assert_names_entry(exc, names, bounds)
        return f"{what}:ModelError"
    except mbd2d.AnalysisError as exc:
        H._analysis_error(exc, what)
        res = exc.results
        if res is not None and hasattr(res, "lam"):
            _finite(f"the partial multipliers of {what}", res.lam, res.kinetic, res.potential)
        return f"{what}:{type(exc).__name__}"
    except mbd2d.InsufficientMemoryError as exc:
        H._memory_error(exc, what)
        return f"{what}:InsufficientMemoryError"
    check(value)
    return f"{what}:ok"


def _dynamic_finite(res: mbd2d.DynamicsResult) -> None:
    _finite("dynamics results", res.t, res.q, res.qd, res.qdd, res.lam, res.kinetic,
            res.potential, res.drift_position, res.drift_velocity)


def _statics_finite(st_: mbd2d.StaticsResult) -> None:
    _finite("the equilibrium", st_.q, st_.lam, [st_.residual])


def _stepper_outcome(model: mbd2d.Model, times: list[Any], names: set[str],
                     bounds: dict[str, int]) -> list[str]:
    """A stepper through the given times: each step finite or a typed error that leaves the
    state as it was (finite, at the same time)."""
    out = []
    try:
        s = mbd2d.KinematicStepper(model)
    except mbd2d.ModelError as exc:
        H.assert_names_entry(exc, names, bounds)
        return ["stepper:ModelError"]
    except mbd2d.AnalysisError as exc:
        H._analysis_error(exc, "KinematicStepper")
        return [f"stepper:{type(exc).__name__}"]
    _finite("the stepper's assembled state", s.q, s.qd, s.qdd)
    for t in times:
        before = (s.t, s.q.copy(), s.qd.copy(), s.qdd.copy())
        try:
            q, qd, qdd = s.step(t)
        except mbd2d.ModelError as exc:
            H.assert_names_entry(exc, names | {"stepping"}, bounds)
            out.append("step:ModelError")
        except mbd2d.AnalysisError as exc:
            assert str(exc).strip()
            out.append(f"step:{type(exc).__name__}")
        else:
            _finite(f"step({t!r})", q, qd, qdd)
            out.append("step:ok")
            continue
        assert s.t == before[0] and all(np.array_equal(a, b) for a, b in
                                        zip((s.q, s.qd, s.qdd), before[1:])), \
            f"a failed step({t!r}) changed the state"
    return out


def _linear_outcome(model: mbd2d.Model, names: set[str], bounds: dict[str, int]
                    ) -> list[str]:
    """The linear analyses about the equilibrium: the modes, and with the model's first
    design parameter as the input the frequency response and the linearized system."""
    out = [_typed("modes", lambda: model.modes(count=2), names, bounds,
                  lambda r: _finite("the modes", r.omega2, r.shapes, r.eigenvalues.real,
                                    r.eigenvalues.imag))]
    try:
        inputs = list(model.parameters())[:1]
    except mbd2d.ModelError as exc:
        H.assert_names_entry(exc, names, bounds)
        return out + ["parameters:ModelError"]
    if not inputs:
        return out
    out.append(_typed("frf", lambda: model.frequency_response(inputs, [0.0, 1.3]), names,
                      bounds, lambda r: _finite("the response", r.response.real,
                                                r.response.imag, r.q, r.lam)))
    out.append(_typed("linearize", lambda: model.linearize(inputs), names, bounds,
                      lambda r: _finite("the state matrices", r.a, r.b, r.c, r.d, r.q)))
    out.append(_typed("linearize efforts", lambda: model.linearize(inputs, efforts=True),
                      names, bounds,
                      lambda r: _finite("the state matrices", r.a, r.b, r.c, r.d, r.q)))
    return out


def exercise_all(model: mbd2d.Model, names: set[str], bounds: dict[str, int]) -> tuple[str, ...]:
    """test_hostile's exercise (counts, kinematics, DOF, Phi...), then statics, inverse and
    forward dynamics (fixed steps: each case's work is bounded) and the stepper; only
    redundancy and singular-passage warnings may be emitted."""
    out = list(H.exercise(model, names, bounds))
    if out and out[0] == "counts:ModelError":
        return tuple(out)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out.append(_typed("statics", model.statics, names, bounds, _statics_finite))
        out.append(_typed("inverse", lambda: model.inverse_dynamics(t_end=0.05, steps=2),
                          names, bounds, _dynamic_finite))
        for method in ("generalized-alpha", "baumgarte-rk4"):
            out.append(_typed(method, lambda: model.dynamics(t_end=0.05, steps=2, method=method,
                                                             h=0.01), names, bounds,
                              _dynamic_finite))
        out += _stepper_outcome(model, [0.01, 0.02], names, bounds)
        out += _linear_outcome(model, names, bounds)
    bad = [f"{w.category.__name__}: {w.message}" for w in caught
           if not issubclass(w.category, H.ALLOWED_WARNINGS)]
    assert not bad, f"unexpected warnings: {bad}"
    return tuple(out)


def check_all_analyses(data: Any) -> tuple[str, ...]:
    """A (malformed) model through from_dict, then every analysis."""
    names, bounds = H._data_names(data)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            model = from_dict(data)
    except mbd2d.ModelError as exc:
        H.assert_names_entry(exc, names, bounds)
        return ("build:ModelError",)
    return ("build:ok",) + exercise_all(model, names, bounds)


def check_builder_all(calls: list[tuple[str, dict[str, Any]]]) -> tuple[str, ...]:
    """Hostile builder calls on a model with masses, then every analysis."""
    names = {"hostile"} | {n for n, _ in H.BUILDER_BODIES} | \
        {kw["name"] for _, kw in calls if isinstance(kw.get("name"), str)}
    bounds = {"body": len(H.BUILDER_BODIES) + sum(m == "add_body" for m, _ in calls),
              "joint": sum(m not in ("add_body", "add_driver") for m, _ in calls),
              "driver": sum(m == "add_driver" for m, _ in calls)}
    model = mbd2d.Model("hostile")
    for name, q0 in H.BUILDER_BODIES:
        model.add_body(name, q0, mass=1.0, inertia=0.1)
    out = []
    for method, kw in calls:
        try:
            getattr(model, method)(**kw)
        except mbd2d.ModelError as exc:
            H.assert_names_entry(exc, names, bounds)
            out.append(f"{method}:ModelError")
        else:
            out.append(f"{method}:ok")
    return tuple(out) + exercise_all(model, names, bounds)


def check_settings(base: str, call: str, kw: dict[str, Any]) -> tuple[str, ...]:
    """A valid model with masses, one analysis with hostile settings."""
    model = from_dict(MASSIVE[base])
    names = {model.name} | {c.name for c in model.constraints} | {b.name for b in model.bodies}
    bounds = {"body": len(model.bodies), "joint": len(model.joints),
              "driver": len(model.drivers)}
    check = {"statics": _statics_finite}.get(call, _dynamic_finite)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = _typed(call, lambda: getattr(model, call)(**kw), names, bounds, check)
    bad = [f"{w.category.__name__}: {w.message}" for w in caught
           if not issubclass(w.category, H.ALLOWED_WARNINGS)]
    assert not bad, f"unexpected warnings: {bad}"
    return (out,)


def check_stepper(base: str, times: list[Any]) -> tuple[str, ...]:
    """A valid model's stepper through hostile times."""
    model = from_dict(BASE[base])
    names = {model.name} | {c.name for c in model.constraints} | {b.name for b in model.bodies}
    bounds = {"body": len(model.bodies), "joint": len(model.joints),
              "driver": len(model.drivers)}
    return tuple(_stepper_outcome(model, times, names, bounds))


# ------------------------------------------------------------------------------------------
# 1. malformed models through every analysis
# ------------------------------------------------------------------------------------------
@hostile_settings(150)
@given(st.data())
def test_malformed_models_through_every_analysis(data: st.DataObject) -> None:
    """test_hostile's structural mutations (missing and unknown keys, wrong types, self-joints,
    zero axes, duplicate and unknown names, crossing profiles ...) of models with masses, then
    statics, inverse and forward dynamics and the stepper."""
    _count("test_malformed_models_through_every_analysis")
    base = data.draw(st.sampled_from(MASSIVE_NAMES), label="base")
    model = _deepcopy(MASSIVE[base])
    ops = [mutate_structure(data.draw, model) for _ in range(data.draw(st.integers(1, 2)))]
    note(f"mutations: {ops}")
    WORKER.call("check_all_analyses", model)


@hostile_settings(120)
@given(st.data())
def test_extreme_and_nonfinite_numbers_through_every_analysis(data: st.DataObject) -> None:
    """NaN, infinities, huge, tiny and zero numbers anywhere a number goes (masses, inertias,
    stiffnesses, points, radii ...), then every analysis."""
    _count("test_extreme_and_nonfinite_numbers_through_every_analysis")
    base = data.draw(st.sampled_from(MASSIVE_NAMES), label="base")
    model = _deepcopy(MASSIVE[base])
    paths = H._numeric_paths(model)
    for p in data.draw(st.lists(st.sampled_from(paths), min_size=1, max_size=2), label="at"):
        H._set(model, p, data.draw(EXTREME | NONFINITE, label=f"value at {p}"))
    WORKER.call("check_all_analyses", model)


@hostile_settings(100)
@given(calls=st.lists(H.builder_call(), min_size=1, max_size=5))
def test_builder_hostile_calls_through_every_analysis(calls: list[Any]) -> None:
    """test_hostile's hostile builder calls on bodies with masses, then every analysis."""
    _count("test_builder_hostile_calls_through_every_analysis")
    WORKER.call("check_builder_all", calls)


# ------------------------------------------------------------------------------------------
# 2. hostile settings and step times on valid models
# ------------------------------------------------------------------------------------------
#: values that are invalid, or valid with bounded work (so that no valid case is a long run)
SPAN = st.sampled_from([(0.0, 0.05), (0.0, 5e-324), (-1.0, -0.95), (1e15, 1e15 + 0.05)])
HOSTILE_SETTINGS = {
    "t_end": st.sampled_from([math.nan, math.inf, -1.0, 0.0, "1", None, 10**400, [0.1], True]),
    "steps": st.sampled_from([0, -1, 1.5, "2", None, 10**9, 10**9 + 1, 2**31, np.int64(2),
                              True, np.nan]),
    "every": st.sampled_from([0, -1, 1.5, "2", None, 2**63, np.int64(2), 10**9]),
    "method": st.sampled_from(["", "euler", None, 3, "DOPRI5", "generalized-alpha",
                               "partitioned", "baumgarte-rk4"]),
    "rtol": st.sampled_from([0.0, -1.0, math.nan, math.inf, 2.0, 1e-20, "1e-6", 1e-14, 1.0]),
    "atol": st.sampled_from([0.0, -1.0, math.nan, 1e-20, 1e7, "x", 1e6]),
    "h": st.sampled_from([0.0, -1e-3, math.nan, math.inf, 1e-13, "1e-3", 1e300, 0.05]),
    "rho_inf": st.sampled_from([-0.1, 1.1, math.nan, "0.5", 0.0, 1.0, 0.5]),
    "alpha": st.sampled_from([-1.0, math.nan, 1e10, "10", 0.0, 1e9]),
    "beta": st.sampled_from([-1.0, math.inf, 1e10, None, 0.0, 1e9]),
    "tol": st.sampled_from([0.0, -1.0, math.nan, 2.0, 1e-300, "1e-9", 1e-15, 0.5]),
    "solver": st.sampled_from(["", "lu", None, 1, "dense", "banded", "auto"]),
    "t": st.sampled_from([math.nan, math.inf, -math.inf, "0", None, 1e300, -1e308, 10**400]),
}
CALL_KEYS = {
    "dynamics": ["t_end", "steps", "every", "method", "rtol", "atol", "h", "rho_inf", "alpha",
                 "beta"],
    "inverse_dynamics": ["t_end", "steps", "every", "tol", "solver"],
    "statics": ["t"],
}


@st.composite
def settings_call(draw: Any) -> tuple[str, str, dict[str, Any]]:
    base = draw(st.sampled_from(MASSIVE_NAMES))
    call = draw(st.sampled_from(sorted(CALL_KEYS)))
    kw: dict[str, Any] = {}
    if call != "statics":
        t0, t1 = draw(SPAN)
        kw = {"t0": t0, "t_end": t1, "steps": 2}
        if call == "dynamics":
            kw.update(method="generalized-alpha", h=0.01)
    for key in draw(st.lists(st.sampled_from(CALL_KEYS[call]), min_size=1, max_size=3,
                             unique=True)):
        kw[key] = draw(HOSTILE_SETTINGS[key])
    if call == "dynamics" and kw.get("method") in ("dopri5", "partitioned") and \
            kw.get("rtol") in (1e-14,):
        kw["rtol"] = 1e-10              # valid and bounded: tight enough, not a long run
    return base, call, kw


@hostile_settings(150)
@given(call=settings_call())
def test_dynamics_and_statics_settings(call: tuple[str, str, dict[str, Any]]) -> None:
    """dynamics, inverse dynamics and statics with hostile time spans, step counts (10**9:
    refused for memory), decimation, methods, tolerances, steps, damping and Baumgarte
    coefficients: a ModelError naming "analysis" or "dynamics", a typed numerical error, an
    InsufficientMemoryError, or finite results."""
    _count("test_dynamics_and_statics_settings")
    WORKER.call("check_settings", *call)


STEP_TIME = st.one_of(st.sampled_from([1e300, -1e300, 1e308, 1e15, 1e8, -1e8, 5e-324, 0.0,
                                       math.nan, math.inf, -math.inf, "0.1", None, [0.1],
                                       10**400, True, np.float64(0.02), np.array(0.03)]),
                      st.floats(-2.0, 2.0))


@hostile_settings(100)
@given(base=st.sampled_from(["slider_crank.toml", "cam_follower.toml", "fourbar_grashof.toml",
                             "gears", "rolling", "spline_cam", "fourier_cam"]),
       times=st.lists(STEP_TIME, min_size=1, max_size=5))
def test_stepper_hostile_times(base: str, times: list[Any]) -> None:
    """KinematicStepper.step with huge, tiny, non-finite and non-number times: finite q, q_dot,
    q_ddot, or a typed error that leaves the state as it was (before: step(1e300) on the cam
    follower returned +-inf and NaN; step("x") raised a bare ValueError)."""
    _count("test_stepper_hostile_times")
    WORKER.call("check_stepper", base, times)


# ------------------------------------------------------------------------------------------
# 3. absurd sizes
# ------------------------------------------------------------------------------------------
def _chain(n: int) -> dict[str, Any]:
    """n links pinned end to end from ground, the first one driven: a long open chain."""
    bodies = [{"name": f"b{i}", "q0": [i + 0.5, 0.0, 0.0], "mass": 1.0, "inertia": 0.1}
              for i in range(n)]
    joints = [{"type": "revolute", "bodies": ["ground" if i == 0 else f"b{i - 1}", f"b{i}"],
               "points": [[0.0, 0.0] if i == 0 else [0.5, 0.0], [-0.5, 0.0]]} for i in range(n)]
    drivers = [{"type": "relative-angle", "bodies": ["ground" if i == 0 else f"b{i - 1}",
                                                     f"b{i}"], "f": {"poly": [0.0, 0.1]}}
               for i in range(n)]
    return {"model": {"name": f"chain{n}"}, "body": bodies, "joint": joints, "driver": drivers}


#: sizes of each absurd case (small, large). Whole-model costs grow as n^3 (3 n coordinates,
#: dense matrices): the DOF analysis of 200 free bodies takes 0.5 s, of 1000 of them 105 s;
#: every analysis of a 200-link chain 29 s. A limit of the core rather than a hang, so bodies
#: and chains stay at a few hundred here.
ABSURD_SIZES = {"spline": (1000, 5000), "fourier": (1000, 3000), "poly": (1000, 10000),
                "harmonics": (1000, 5000), "steps": (300, 2000), "chain": (30, 100),
                "name": (1000, 100000),
                "q0": (1000, 10**6), "bodies": (100, 200)}


def build_absurd(what: str, base: str, large: bool, k: int, x: float) -> dict[str, Any]:
    """The model of an absurd-size case (built in the worker, so that hypothesis reports the
    small description, not the model): ``what`` grows, to its ``large`` or small size from
    ABSURD_SIZES; ``k`` and ``x`` shape it."""
    n = ABSURD_SIZES[what][int(large)]
    data = _deepcopy(MASSIVE[base])
    cam = next(j for j in data["joint"] if j.get("type") == "cam")
    if what == "spline":
        t = np.linspace(0, 2 * np.pi, n, endpoint=False)
        r = 1.0 + x * np.sin(k * t)
        cam["profile"] = {"spline": {"points": np.column_stack([r * np.cos(t),
                                                                r * np.sin(t)]).tolist()}}
    elif what == "fourier":
        cam["profile"] = {"fourier": {"center": [0.0, 0.0],
                                      "a": [1.0] + [x / (j + 1) for j in range(n)]}}
    elif what == "poly":
        data["driver"][0]["f"] = {"poly": [0.0, 1.0] + [x] * n}
    elif what == "harmonics":
        data["driver"][0]["f"] = {"harmonic": [{"amplitude": 1e-3, "omega": float(j)}
                                               for j in range(n)]}
    elif what == "steps":      # breakpoints everywhere, overlapping rises for large k
        data["driver"][0]["f"] = {"poly": [0.0, 1.0], "step": [
            {"t0": j / n, "t1": (j + 0.1 + k / 50) / n, "h": 1e-3 * x * (-1)**j,
             "law": ("cubic", "quintic", "cycloidal", "harmonic")[j % 4]} for j in range(n)]}
    elif what == "chain":
        return _chain(n)
    elif what == "name":
        data["body"][0]["name"] = "b" * n
    elif what == "q0":
        data["body"][0]["q0"] = [0.0] * n
    else:       # many bodies that nothing constrains
        data["body"] += [{"name": f"extra{j}", "q0": [0.0, 0.0, 0.0]} for j in range(n)]
    return data


def check_absurd(what: str, base: str, large: bool, k: int, x: float) -> tuple[str, ...]:
    """A model of absurd size: a typed error or a model whose analyses behave."""
    return check_all_analyses(build_absurd(what, base, large, k, x))


#: a case of absurd size may take seconds (every analysis on a 5000-term profile), not minutes
ABSURD_SECONDS = 60.0


@hostile_settings(16)
@given(what=st.sampled_from(sorted(ABSURD_SIZES)),
       base=st.sampled_from(["cam_follower.toml", "spline_cam", "fourier_cam"]),
       large=st.booleans(), k=st.sampled_from([1, 7, 50, 200, 400]),
       x=st.sampled_from([0.0, 1e-6, 1e-3, 0.01, 0.3, 1.0]))
def test_absurd_sizes(what: str, base: str, large: bool, k: int, x: float) -> None:
    """Splines of thousands of points (smooth or wavy), Fourier profiles and polynomials of
    thousands of terms, chains of hundreds of links, names and lists of absurd length,
    thousands of free bodies: a typed error or a model whose every analysis behaves, within
    ABSURD_SECONDS."""
    _count("test_absurd_sizes")
    WORKER.call("check_absurd", what, base, large, k, x, limit=ABSURD_SECONDS)


def test_the_example_count_follows_the_environment(monkeypatch):
    monkeypatch.setenv("MBD2D_FUZZ_EXAMPLES", "5000")
    assert H.fuzz_examples(60) == 5000
    monkeypatch.setenv("MBD2D_FUZZ_EXAMPLES", "10")
    assert H.fuzz_examples(60) == 60
    monkeypatch.delenv("MBD2D_FUZZ_EXAMPLES")
    assert H.fuzz_examples(60) == 60


def test_a_crash_in_the_worker_is_caught():
    """The worker's guard works: a case that kills the worker fails the test with the signal,
    and the next case gets a fresh worker."""
    with pytest.raises(AssertionError, match="CRASH.*signal SIGSEGV"):
        WORKER.call("_crash")
    assert isinstance(WORKER.call("ping"), int)


def _crash() -> None:
    import ctypes
    ctypes.string_at(0)        # reads address 0: SIGSEGV


# keep flake8 quiet about names used only through the worker
_ = (HOSTILE_ARG, re, to_toml)
