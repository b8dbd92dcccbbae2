"""One table maps each core status to its exception class for every analysis, and every
front door goes through it.

* The table (mbd2d.binding.status.ERRORS) is compared with the contract written out here,
  status by status, analysis by analysis; its codes with fortran/mbd_status.f90.
* Each front door is walked through every status: the core call is replaced by one that
  answers that status, and the public call must raise exactly the table's class, with a
  message (and the entry, time or size it carries).
* Real failures that used to reach the wrong class: statics and dynamics on contradicting
  redundant constraints (before: CoreError "internal error ... a bug" and ConvergenceError),
  KinematicStepper.step("x") (before: a bare ValueError), step(1e300) (before: q with +-inf,
  q_dot NaN, no error), kinematics(steps=10**9) (before: a 7.45 GiB index array allocated
  before the memory check: MemoryError from NumPy, or the memory used).
"""
from __future__ import annotations

import re
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d import _core
from mbd2d.binding import status as S
from mbd2d.binding.core import NINFO
from mbd2d.binding.pack import pack
from mbd2d.errors import (AssemblyError, ConvergenceError, CoreError,
                          InconsistentConstraintsError, InsufficientMemoryError,
                          IntegrationError, ModelError, SingularConfigurationError,
                          SingularJacobianError)

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"

ANALYSES = ["kinematics", "inverse", "dynamics", "statics", "modes", "frf", "stepper",
            "stepper-start", "dof", "eval"]
UNKNOWN = [11, 99, -6, -99]          # codes the core does not define

# ----------------------------------------------------------------------------- the contract
NEG = {s: ModelError for s in (-1, -2, -3, -4, -5)}
BUG = {5: CoreError, 7: CoreError, 9: CoreError}       # LAPACK, branch switch, user abort
MEM = {10: InsufficientMemoryError}
KIN = {**NEG, **BUG, **MEM, 1: SingularJacobianError, 2: ConvergenceError,
       3: SingularConfigurationError, 4: AssemblyError, 6: InconsistentConstraintsError,
       8: CoreError}
ASM = {**NEG, **BUG, **MEM, 1: SingularJacobianError, 2: AssemblyError,
       3: SingularJacobianError, 4: AssemblyError, 6: InconsistentConstraintsError,
       8: CoreError}
CONTRACT = {
    "kinematics": KIN,
    "inverse": KIN,
    "dynamics": {**KIN, 3: SingularJacobianError, 8: IntegrationError},
    "statics": {**ASM, 2: ConvergenceError},
    "modes": {**ASM, 2: ConvergenceError},
    "frf": {**ASM, 2: ConvergenceError},
    "stepper": {**KIN, 1: ConvergenceError, 3: ConvergenceError},
    "stepper-start": ASM,
    "dof": ASM,
    "eval": {**NEG, **BUG, **MEM, **{s: CoreError for s in (1, 2, 3, 4, 6, 8)}},
}


def fortran_codes() -> dict[str, int]:
    """MBD_* status codes as fortran/mbd_status.f90 defines them."""
    text = (ROOT / "fortran" / "mbd_status.f90").read_text()
    return {name: int(v) for name, v in
            re.findall(r"integer, parameter :: (MBD_\w+) = (-?\d+)", text)}


def test_codes_match_the_fortran_status_module():
    names = {v: k for k, v in S.STATUS_NAMES.items()}
    for name, code in fortran_codes().items():
        if name != "MBD_OK":
            assert names.get(name) == code, f"{name} = {code} in Fortran"
    assert S.NO_MEMORY == 10 and S.STATUS_NAMES[10] == "MBD_NO_MEMORY"


@pytest.mark.parametrize("analysis", ANALYSES)
def test_the_table_is_the_contract(analysis):
    for status in sorted(S.STATUS_NAMES) + UNKNOWN:
        cls = S.error_class(analysis, status)
        assert issubclass(cls, mbd2d.MbdError)
        expected = CONTRACT[analysis].get(status, CoreError)
        assert cls is expected, f"{analysis}, status {status}: {cls.__name__}"


# ----------------------------------------------------------------------------- the walk
MASSES = 'mass = 2.0\ninertia = 0.3'


def massive_fourbar() -> mbd2d.Model:
    text = (EXAMPLES / "fourbar_grashof.toml").read_text()
    text = re.sub(r"(q0 = \[[^\]]*\])", rf"\1\n{MASSES}", text)
    return mbd2d.loads(text)


def _fake(model: mbd2d.Model, fn: str, status: int, nout: int = 3, finite: bool = True):
    """A stand-in for _core.<fn> that answers ``status`` with outputs of the right shapes
    (non-finite from the second output row on when ``finite`` is false)."""
    p = pack(model)
    nq, neq = p.nq, p.neq
    msg = f"fake status {status}".encode()
    i10 = np.zeros(NINFO, dtype=np.int32)
    i10[0] = nout if status == S.OK else 0
    r10 = np.zeros(NINFO)
    rows = np.tile(pack(model).q0[:, None], (1, nout))
    if not finite:
        rows[:, 1:] = np.nan
    ivec = np.zeros(neq, dtype=np.int32)

    def answer(*args, **kwargs):
        if fn == "core_kinematics":
            return (rows, rows * 0, rows * 0, i10, r10, np.zeros(nq), ivec, ivec, np.zeros(64),
                    status, msg)
        if fn == "core_inverse":
            return (rows, rows * 0, rows * 0, np.zeros((neq, nout)), np.zeros((4, nout)), i10,
                    r10, np.zeros(nq), ivec, ivec, np.zeros(64), status, msg,
                    np.zeros((6, 0, nout)), np.zeros((4, 1)), 0)
        if fn == "core_dynamics":
            return (rows, rows * 0, rows * 0, np.zeros((neq, nout)), np.zeros((4, nout)), i10,
                    r10, ivec, status, msg, np.zeros((6, 0, nout)), np.zeros((4, 1)), 0)
        if fn == "core_statics":
            return p.q0, np.zeros(neq), 1, 0.0, i10, status, msg
        if fn == "core_modes":
            k = kwargs["kmax"]
            return (p.q0, np.zeros(neq), 1, 0.0, np.zeros(k), np.zeros(k, dtype=np.int32),
                    np.zeros(2 * k), np.zeros(2 * k), np.zeros((nq, k)), np.zeros((nq, 2 * k)),
                    np.zeros((nq, 2 * k)), i10, status, msg)
        if fn == "core_frf":
            h = np.zeros((nq, kwargs["ptab"].shape[1], kwargs["omega"].size))
            hl = np.zeros((neq, kwargs["ptab"].shape[1], kwargs["omega"].size))
            return p.q0, np.zeros(neq), 1, 0.0, h, h, hl, hl, i10, status, msg
        if fn == "core_kin_step":
            q = args[3] if finite else np.full(nq, np.inf)
            return q, args[4], args[5], status, msg
        if fn == "core_analyze":
            return p.q0, nq, 1, ivec, ivec, 0.0, 0, status, msg
        if fn == "core_eval":
            return (np.zeros(neq), np.zeros((neq, nq)), np.zeros(neq), np.zeros(neq), status,
                    msg, 0)
        raise AssertionError(fn)

    return answer


CALLS = {   # analysis: (the _core function, the public call)
    "kinematics": ("core_kinematics",
                   lambda m: m.kinematics(t_end=1.0, steps=2, maxit=25)),
    "inverse": ("core_inverse", lambda m: m.inverse_dynamics(t_end=1.0, steps=2)),
    "dynamics": ("core_dynamics", lambda m: m.dynamics(t_end=1.0, steps=2)),
    "statics": ("core_statics", lambda m: m.statics()),
    "modes": ("core_modes", lambda m: m.modes()),
    "frf": ("core_frf", lambda m: m.frequency_response("model.gravity.1", [1.0])),
    "stepper-start": ("core_kin_step", lambda m: mbd2d.KinematicStepper(m)),
    "dof": ("core_analyze", lambda m: m.analyze_dof()),
    "eval": ("core_eval", lambda m: m.phi(pack(m).q0)),
}


@pytest.mark.parametrize("analysis", ANALYSES)
def test_every_front_door_raises_the_tables_class(analysis, monkeypatch):
    model = massive_fourbar()
    fn, call = CALLS.get(analysis, ("core_kin_step", None))
    stepper = mbd2d.KinematicStepper(model) if analysis == "stepper" else None
    for status in sorted(S.STATUS_NAMES) + UNKNOWN:
        monkeypatch.setattr(_core, fn, _fake(model, fn, status))
        with pytest.raises(mbd2d.MbdError) as err:
            if stepper is not None:
                stepper.step(0.01)
            else:
                call(model)
        e = err.value
        cls = S.error_class(analysis, status)
        assert type(e) is cls, f"{analysis}, status {status}: {type(e).__name__}: {e}"
        assert str(e).strip()
        if isinstance(e, ModelError):
            assert e.entry
        if isinstance(e, mbd2d.AnalysisError):
            assert e.status == status
        if isinstance(e, InsufficientMemoryError):
            assert isinstance(e, MemoryError)
            assert "every=" in str(e) and "banded" in str(e) and "fake status" in str(e)
        if cls is CoreError:
            assert "a bug" in str(e) and str(status) in str(e)
        monkeypatch.undo()
    if stepper is not None:       # a failed step leaves the state as it was
        assert stepper.t == 0.0 and np.isfinite(stepper.q).all()


@pytest.mark.parametrize("analysis", ["kinematics", "inverse", "dynamics"])
def test_no_front_door_returns_non_finite_rows(analysis, monkeypatch):
    """The core answers OK with NaN from the second row on: the front door raises (a
    ConvergenceError for a kinematic run, an IntegrationError for dynamics) and keeps only
    the finite rows."""
    model = massive_fourbar()
    fn, call = CALLS[analysis]
    monkeypatch.setattr(_core, fn, _fake(model, fn, S.OK, finite=False))
    expected = IntegrationError if analysis == "dynamics" else ConvergenceError
    with pytest.raises(expected, match="non-finite") as err:
        call(model)
    res = err.value.results
    assert len(res.t) == 1 and not res.complete
    assert np.isfinite(res.q).all() and np.isfinite(res.qd).all()


def test_a_failed_allocation_for_the_core_is_insufficient_memory(monkeypatch):
    def no_memory(*args, **kwargs):
        raise MemoryError
    monkeypatch.setattr(_core, "core_kinematics", no_memory)
    with pytest.raises(InsufficientMemoryError, match="every=.*banded"):
        mbd2d.load(EXAMPLES / "fourbar_grashof.toml").kinematics(t_end=1.0, steps=10)


# ----------------------------------------------------------------------------- real failures
def contradicting_tie() -> mbd2d.Model:
    """The redundant crank-rocker with masses and its tie (a distance repeating the coupler,
    3.5) set to 3.8: the tie and the coupler cannot both hold, at any configuration."""
    text = (EXAMPLES / "fourbar_redundant.toml").read_text().replace("distance = 3.5",
                                                                      "distance = 3.8")
    return mbd2d.loads(re.sub(r"(q0 = \[[^\]]*\])", rf"\1\n{MASSES}", text))


@pytest.mark.parametrize("call", ["statics", "dynamics", "inverse_dynamics", "kinematics",
                                  "analyze_dof"])
def test_contradicting_constraints_are_one_error_everywhere(call):
    model = contradicting_tie()
    kw = {} if call in ("statics", "analyze_dof") else {"t_end": 0.1, "steps": 2}
    with warnings.catch_warnings():     # inverse dynamics also names the redundant row
        warnings.simplefilter("ignore", mbd2d.RedundantConstraintWarning)
        with pytest.raises(InconsistentConstraintsError, match=r"tie\.distance.*A, B, tie "
                                                               r"cannot all hold") as err:
            getattr(model, call)(**kw)
    assert err.value.status == S.INCONSISTENT
    assert err.value.constraints == ["A", "B", "tie"]


def test_stepper_refuses_a_time_that_is_not_a_number():
    s = mbd2d.KinematicStepper(mbd2d.load(EXAMPLES / "cam_follower.toml"))
    for bad in ("x", None, [0.1], float("nan"), float("inf"), 10**400):
        with pytest.raises(ModelError, match="stepping: t must be"):
            s.step(bad)


def test_stepper_giant_step_raises_and_keeps_the_state():
    """cam_follower.step(1e300): the predictor overflows. Before: q with +-inf and q_dot
    NaN returned, and the next call blamed the state. Now a ConvergenceError, the state
    unchanged, and the next step agrees with a fresh stepper (the closed form is the
    follower on its circular cam, checked in test_joint_library; here the same call twice)."""
    model = mbd2d.load(EXAMPLES / "cam_follower.toml")
    s = mbd2d.KinematicStepper(model)
    q0 = s.q.copy()
    with pytest.raises(ConvergenceError, match="non-finite.*state stays at t = 0"):
        s.step(1e300)
    assert s.t == 0.0 and np.array_equal(s.q, q0)
    q, qd, qdd = s.step(0.01)
    fresh = mbd2d.KinematicStepper(model).step(0.01)
    for a, b in zip((q, qd, qdd), fresh):
        assert np.isfinite(a).all()
        np.testing.assert_array_equal(a, b)


def test_gamma_at_an_overflowing_velocity_is_an_error(monkeypatch):
    """The core reports overflow itself (status < 0); should it ever answer OK with a
    non-finite value, the front door still raises."""
    model = mbd2d.load(EXAMPLES / "fourbar_grashof.toml")
    q = pack(model).q0
    qd = np.full_like(q, 1e200)          # theta_dot**2 * L overflows a double
    with pytest.raises(ModelError, match="overflow"):
        model.gamma(q, qd)
    real = _core.core_eval

    def inf_gamma(*args):
        phi, jac, nu, gam, status, msg, bad = real(*args)
        return phi, jac, nu, np.full_like(gam, np.inf), status, msg, bad
    monkeypatch.setattr(_core, "core_eval", inf_gamma)
    with pytest.raises(ModelError, match="state: .*non-finite"):
        model.gamma(q, np.ones_like(q))


MEMORY_SCRIPT = textwrap.dedent("""
    import resource, sys, tracemalloc
    resource.setrlimit(resource.RLIMIT_AS, (4 * 2**30, 4 * 2**30))
    import mbd2d
    model = mbd2d.load(sys.argv[1])
    tracemalloc.start()
    for call in ("kinematics", "inverse_dynamics", "dynamics"):
        try:
            getattr(model, call)(t_end=1.0, steps=10**9)
        except mbd2d.InsufficientMemoryError as exc:
            assert isinstance(exc, MemoryError) and exc.nbytes > 8 * 10**9, exc
            assert "GiB" in str(exc) and "every=" in str(exc), exc
            print(call, "InsufficientMemoryError")
        except BaseException as exc:
            print(call, type(exc).__name__, exc)
    print("peak", tracemalloc.get_traced_memory()[1])
""")


def test_a_billion_steps_are_refused_before_anything_big_is_allocated(tmp_path):
    """steps = 10**9 with every row kept: 27 numbers a row for a four-bar are over 200 GB.
    The refusal comes from the estimate before anything is allocated (run with a 4 GiB
    address-space limit; before, NumPy's 7.45 GiB index array failed first with a bare
    MemoryError)."""
    text = (EXAMPLES / "fourbar_grashof.toml").read_text()
    path = tmp_path / "fourbar.toml"
    path.write_text(re.sub(r"(q0 = \[[^\]]*\])", rf"\1\n{MASSES}", text))
    out = subprocess.run([sys.executable, "-c", MEMORY_SCRIPT, str(path)], capture_output=True,
                         text=True, timeout=120, cwd=str(tmp_path))
    lines = out.stdout.splitlines()
    assert out.returncode == 0, out.stderr
    assert lines[:3] == ["kinematics InsufficientMemoryError",
                         "inverse_dynamics InsufficientMemoryError",
                         "dynamics InsufficientMemoryError"], out.stdout
    assert int(lines[3].split()[1]) < 10 * 2**20        # peak traced memory under 10 MB


# ----------------------------------------------------------------------------- arguments
def _fourbar() -> mbd2d.Model:
    return mbd2d.load(EXAMPLES / "fourbar_grashof.toml")


BAD_CALLS = {   # before: TypeError, AttributeError, IsADirectoryError, FileNotFoundError,
    # ValueError from list.index or float(), or a model named "[1]"
    "load(123)": lambda tmp: mbd2d.load(123),
    "loads(bytes)": lambda tmp: mbd2d.loads(b"[model]"),
    "loads(None)": lambda tmp: mbd2d.loads(None),
    "Model(name=[1])": lambda tmp: mbd2d.Model(name=[1]),
    "KinematicStepper('x')": lambda tmp: mbd2d.KinematicStepper("x"),
    "export into a directory": lambda tmp: _fourbar().export(tmp, t_end=1.0, steps=10),
    "save into a missing directory": lambda tmp: _fourbar().kinematics(1.0, 10).save(
        tmp / "missing" / "out.csv"),
    "to_npz into a missing directory": lambda tmp: _fourbar().kinematics(1.0, 10).to_npz(
        tmp / "missing" / "out.npz"),
    "point with s = 'ab'": lambda tmp: _fourbar().kinematics(1.0, 10).point("crank", "ab"),
    "plot_mechanism(times=['a'])": lambda tmp: __import__(
        "mbd2d.plots", fromlist=["plot_mechanism"]).plot_mechanism(
            _fourbar().kinematics(1.0, 10), times=["a"]),
}


@pytest.mark.parametrize("what", sorted(BAD_CALLS))
def test_public_calls_check_their_arguments(what, tmp_path):
    with pytest.raises(ModelError) as err:
        BAD_CALLS[what](tmp_path)
    assert err.value.entry and str(err.value).strip()


def test_unknown_names_in_results_are_key_errors():
    model = massive_fourbar()
    res = model.inverse_dynamics(t_end=0.1, steps=2)
    st = model.statics()
    for call in (lambda: res.multiplier("nope.x"), lambda: res.reaction("nope"),
                 lambda: res.effort("O2"), lambda: st.multiplier("nope.x"),
                 lambda: st.body("nope"), lambda: res.body("nope")):
        with pytest.raises(KeyError, match="nope|no driver"):
            call()
