"""Progress bars: the run with a bar is the same single core call as without (results bit for
bit equal for every analysis and method), the bar counts to the end, the core publishes its
count and stops when asked, Ctrl-C stops the run, and short or unwatched runs make the plain
call."""
from __future__ import annotations

import threading
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import mbd2d
from mbd2d.analysis import progress as P
from mbd2d.binding import core
from mbd2d.binding.pack import pack, pack_dynamics
from mbd2d.binding.status import USER_ABORT

EX = Path(__file__).resolve().parents[1] / "examples"


class Recorder:
    """A stand-in for tqdm that records what it is told."""

    made: list["Recorder"] = []

    def __init__(self, total: int, label: str) -> None:
        self.total, self.label, self.n, self.closed = total, label, 0, False
        Recorder.made.append(self)

    def update(self, k: int) -> None:
        self.n += k

    def close(self) -> None:
        self.closed = True


@pytest.fixture
def recorder(monkeypatch: pytest.MonkeyPatch) -> type[Recorder]:
    Recorder.made = []
    monkeypatch.setattr(P, "_bar", Recorder)
    return Recorder


def same(a: Any, b: Any) -> None:
    for f in ("t", "q", "qd", "qdd", "lam", "kinetic", "potential", "drift_position",
              "drift_velocity"):
        if hasattr(a, f):
            assert np.array_equal(getattr(a, f), getattr(b, f)), f
    assert a.stats == b.stats


def test_kinematics_with_a_bar_is_the_same_call(recorder):
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    plain = m.kinematics(20.0, 20000, every=10, progress=False)
    barred = m.kinematics(20.0, 20000, every=10, progress=True)
    same(plain, barred)
    (bar,) = recorder.made
    assert bar.total == bar.n == len(plain.t) == 2001 and bar.closed
    assert bar.label == "kinematics"


def test_inverse_dynamics_with_a_bar_is_the_same_call(recorder):
    m = mbd2d.load(EX / "fourbar_masses.toml")
    same(m.inverse_dynamics(5.0, 5000, progress=False), m.inverse_dynamics(5.0, 5000,
                                                                            progress=True))
    (bar,) = recorder.made
    assert bar.total == bar.n == 2 * 5001          # kinematics, then the multipliers


@pytest.mark.parametrize("method, kw", [("dopri5", {}), ("partitioned", {}),
                                        ("generalized-alpha", {"h": 1e-3}),
                                        ("baumgarte-rk4", {"h": 1e-3})])
def test_dynamics_with_a_bar_is_the_same_call(recorder, method, kw):
    m = mbd2d.load(EX / "pendulum_spring.toml")
    same(m.dynamics(10.0, 1000, method=method, progress=False, **kw),
         m.dynamics(10.0, 1000, method=method, progress=True, **kw))
    (bar,) = recorder.made
    assert bar.total == bar.n == 1001


def test_the_core_publishes_its_count_and_stops_when_asked():
    """ctl[0] holds the outputs stored; with ctl[1] set the run stops after its first step's
    output, with the status of a stop on request and the outputs so far."""
    p = pack(mbd2d.load(EX / "fourbar_grashof.toml"))
    ctl = core.new_ctl()
    out = core.kinematics(p, 0.0, 1.0, 100, 0.0, 0, 0.0, 1, 0, 101, ctl)
    assert out.status == 0 and ctl[0] == 101
    ctl = core.new_ctl()
    ctl[1] = 1
    out = core.kinematics(p, 0.0, 1.0, 100, 0.0, 0, 0.0, 1, 0, 101, ctl)
    assert out.status == USER_ABORT and out.iinfo[0] == 2 and "on request" in out.msg
    m = mbd2d.load(EX / "pendulum_spring.toml")
    p = pack(m)
    d = pack_dynamics(m, p)
    ctl = core.new_ctl()
    ctl[1] = 1
    out = core.dynamics(p, d, 0.0, 1.0, 100, 2, 0.0, 0.0, 0.0, -1.0, -1.0, -1.0, 1, 101, 0,
                        ctl=ctl)
    assert out.status == USER_ABORT and 1 <= out.iinfo[0] < 101   # stops after a step
    assert out.iinfo[0] == ctl[0]
    mm = mbd2d.load(EX / "fourbar_masses.toml")
    p = pack(mm)
    d = pack_dynamics(mm, p)
    ctl = core.new_ctl()
    out = core.inverse(p, d, 0.0, 1.0, 100, 0.0, 1, 0, 101, ctl=ctl)
    assert out.status == 0 and ctl[0] == 202


def test_ctrl_c_stops_the_run(monkeypatch):
    """A KeyboardInterrupt while the core runs sets the stop flag; the core stops at its next
    output (long before the end) and the interrupt reaches the caller."""
    seen: dict[str, Any] = {}
    real = core.kinematics

    def spy(*args: Any) -> Any:
        out = real(*args)
        seen["status"], seen["rows"] = out.status, int(out.iinfo[0])
        return out

    class Interrupting(Recorder):
        def update(self, k: int) -> None:
            raise KeyboardInterrupt

    monkeypatch.setattr(core, "kinematics", spy)
    monkeypatch.setattr(P, "_bar", Interrupting)
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    with pytest.raises(KeyboardInterrupt):
        m.kinematics(1000.0, 10**6, every=1000, progress=True)
    assert seen["status"] == USER_ABORT and seen["rows"] < 1001


def test_short_or_unwatched_runs_make_the_plain_call(monkeypatch, recorder):
    threads: list[Any] = []
    real = threading.Thread

    def counting(*args: Any, **kw: Any) -> Any:
        threads.append(1)
        return real(*args, **kw)

    monkeypatch.setattr(P.threading, "Thread", counting)
    m = mbd2d.load(EX / "fourbar_grashof.toml")
    m.kinematics(1.0, 100)                         # small: plain call
    monkeypatch.setattr(P, "_interactive", lambda: False)
    m.kinematics(100.0, 10**5, every=100)          # large but nobody watching
    assert threads == [] and recorder.made == []
    monkeypatch.setattr(P, "_interactive", lambda: True)
    monkeypatch.setattr(P, "DELAY", 0.0)
    # watched: a thread, and the bar once the run outlasts the first poll (10**6 steps,
    # about 0.5 s; 10**5 steps now end within POLL)
    m.kinematics(1000.0, 10**6, every=1000)
    assert threads == [1] and len(recorder.made) == 1


def test_errors_in_the_worker_reach_the_caller(recorder):
    with pytest.raises(mbd2d.SingularConfigurationError) as info:
        mbd2d.load(EX / "fourbar_seed.toml").kinematics(1.0, 1000, progress=True)
    assert len(info.value.results.t) == 886


def test_progress_must_be_a_bool_or_none():
    with pytest.raises(mbd2d.ModelError, match="progress must be"):
        mbd2d.load(EX / "fourbar_grashof.toml").kinematics(1.0, 10, progress="yes")
